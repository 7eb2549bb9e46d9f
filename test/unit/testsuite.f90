!> A small unit-test harness modelled on test-drive's API: tests are
!> `subroutine test(error)` that allocate `error` on failure; suites collect
!> tests; `check` compares values with stated tolerances. A test registered
!> with `should_fail` passes only when it fails (a negative test).
!>
!> `replaced` builds the variants of a base text (a scene with one key
!> changed). A pattern that is not in the text is a defect of the test, not
!> a variant: the variant would silently rerun the base case. `replaced` then
!> returns the text unchanged and records the pattern, and `run_testsuite`
!> fails the test that called it, naming the pattern (also a `should_fail`
!> test: its expected failure must not come from a broken variant).
!>
!> Tiers: `make test` runs each test's cheap tier, which still decides the
!> test's claim (a coarser level, fewer variants); `unit --full` (`make
!> test-full`) adds the expensive variants. A test asks `full_tier()`.
module sprc_testsuite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_internal
   implicit none
   private

   public :: unittest_type, testsuite_type, new_unittest, new_testsuite
   public :: check, test_failed, run_testsuite, error_type, collect_interface, replaced
   public :: take_replace_failure, full_tier, set_full_tier

   abstract interface
      !> A test: allocates `error` when it fails.
      subroutine test_interface(error)
         import :: error_type
         type(error_type), allocatable, intent(out) :: error
      end subroutine test_interface
   end interface

   !> One named test.
   type :: unittest_type
      character(len=:), allocatable :: name
      procedure(test_interface), pointer, nopass :: test => null()
      !> A negative test: it passes when it fails.
      logical :: should_fail = .false.
   end type unittest_type

   abstract interface
      !> Fills the list of tests of a suite.
      subroutine collect_interface(testsuite)
         import :: unittest_type
         type(unittest_type), allocatable, intent(out) :: testsuite(:)
      end subroutine collect_interface
   end interface

   !> A named collection of tests.
   type :: testsuite_type
      character(len=:), allocatable :: name
      procedure(collect_interface), pointer, nopass :: collect => null()
   end type testsuite_type

   !> Compare an actual value with an expected one; allocate `error` on mismatch.
   interface check
      module procedure :: check_logical, check_int, check_int8, check_real, check_string
   end interface check

   !> Patterns that `replaced` did not find since the running test started
   !> (the harness runs tests one at a time; `replaced` is called outside
   !> parallel regions).
   character(len=:), allocatable, save :: replace_failure

   !> Whether the expensive variants run too (`unit --full`).
   logical, save :: full = .false.

contains

   !> Whether the tests run their expensive variants too (`unit --full`).
   logical function full_tier()
      full_tier = full
   end function full_tier

   subroutine set_full_tier(on)
      logical, intent(in) :: on
      full = on
   end subroutine set_full_tier

   function new_unittest(name, test, should_fail) result(self)
      character(len=*), intent(in) :: name
      procedure(test_interface) :: test
      logical, intent(in), optional :: should_fail
      type(unittest_type) :: self
      self%name = name
      self%test => test
      if (present(should_fail)) self%should_fail = should_fail
   end function new_unittest

   function new_testsuite(name, collect) result(self)
      character(len=*), intent(in) :: name
      procedure(collect_interface) :: collect
      type(testsuite_type) :: self
      self%name = name
      self%collect => collect
   end function new_testsuite

   !> Mark a test as failed with a message.
   subroutine test_failed(error, message)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      call fatal_error(error, message, stat_internal)
   end subroutine test_failed

   subroutine check_logical(error, condition, message)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: condition
      character(len=*), intent(in) :: message
      if (.not. condition) call test_failed(error, message)
   end subroutine check_logical

   subroutine check_int(error, actual, expected, message)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message
      character(len=64) :: buf
      if (actual == expected) return
      write (buf, '("expected ",i0,", got ",i0)') expected, actual
      call test_failed(error, prefixed(message, trim(buf)))
   end subroutine check_int

   subroutine check_int8(error, actual, expected, message)
      type(error_type), allocatable, intent(out) :: error
      integer(i8), intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message
      character(len=64) :: buf
      if (actual == expected) return
      write (buf, '("expected ",i0,", got ",i0)') expected, actual
      call test_failed(error, prefixed(message, trim(buf)))
   end subroutine check_int8

   !> Real comparison: |actual - expected| <= thr, or with `rel`,
   !> |actual - expected| <= thr*|expected|. NaN never passes.
   subroutine check_real(error, actual, expected, thr, message, rel)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in) :: actual, expected, thr
      character(len=*), intent(in), optional :: message
      logical, intent(in), optional :: rel
      character(len=160) :: buf
      real(wp) :: diff, bound
      logical :: relative

      relative = .false.
      if (present(rel)) relative = rel
      diff = abs(actual - expected)
      bound = thr
      if (relative) bound = thr*abs(expected)
      if (diff <= bound) return
      write (buf, '("expected ",es24.16,", got ",es24.16," (diff ",es9.2,", allowed ",es9.2,")")') &
         expected, actual, diff, bound
      call test_failed(error, prefixed(message, trim(buf)))
   end subroutine check_real

   subroutine check_string(error, actual, expected, message)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: actual, expected
      character(len=*), intent(in), optional :: message
      if (actual == expected) return
      call test_failed(error, prefixed(message, 'expected "'//expected//'", got "'//actual//'"'))
   end subroutine check_string

   pure function prefixed(message, detail) result(text)
      character(len=*), intent(in), optional :: message
      character(len=*), intent(in) :: detail
      character(len=:), allocatable :: text
      text = detail
      if (present(message)) text = message//': '//detail
   end function prefixed

   !> Run the tests of one suite whose names match `selection` ('' = all);
   !> print one line per test to `unit`; add to the pass/fail counters.
   subroutine run_testsuite(suite, selection, unit, npass, nfail)
      type(testsuite_type), intent(in) :: suite
      character(len=*), intent(in) :: selection
      integer, intent(in) :: unit
      integer, intent(inout) :: npass, nfail
      type(unittest_type), allocatable :: tests(:)
      character(len=:), allocatable :: failure
      character(len=16) :: seconds
      integer :: i
      integer(i8) :: start, finish, rate

      call suite%collect(tests)
      do i = 1, size(tests)
         if (len(selection) > 0 .and. selection /= tests(i)%name) cycle
         call system_clock(start, rate)
         call run_one(tests(i), failure)
         call system_clock(finish)
         ! The wall time goes to the log (tools/run-tests sums it per layer), never into a verdict.
         write (seconds, '(f10.2)') real(finish - start, wp)/real(max(rate, 1_i8), wp)
         if (allocated(failure)) then
            nfail = nfail + 1
            write (unit, '(a)') 'FAIL '//suite%name//'/'//tests(i)%name//': '//failure
            deallocate (failure)
         else
            npass = npass + 1
            write (unit, '(a)') 'ok   '//suite%name//'/'//tests(i)%name//' ['//trim(adjustl(seconds))//' s]'
         end if
         flush (unit)
      end do
   end subroutine run_testsuite

   !> Run one test; `failure` is allocated with the reason when it fails: its
   !> own error (or, for a `should_fail` test, none), or a pattern that
   !> `replaced` did not find.
   subroutine run_one(test, failure)
      type(unittest_type), intent(in) :: test
      character(len=:), allocatable, intent(out) :: failure
      type(error_type), allocatable :: error
      character(len=:), allocatable :: missing

      if (allocated(replace_failure)) deallocate (replace_failure)
      call test%test(error)
      call take_replace_failure(missing)
      if (allocated(missing)) then
         failure = missing
         if (allocated(error)) failure = failure//'; then: '//error%message
      else if (test%should_fail .and. .not. allocated(error)) then
         failure = 'a negative test (should_fail) that passed'
      else if (.not. test%should_fail .and. allocated(error)) then
         failure = error%message
      end if
   end subroutine run_one

   !> `text` with the first `old` replaced by `new`. When `old` is not in
   !> `text`, the text comes back unchanged and the running test fails with
   !> a message naming `old` (see the module comment).
   function replaced(text, old, new) result(out)
      character(len=*), intent(in) :: text, old, new
      character(len=:), allocatable :: out
      integer :: i
      i = index(text, old)
      out = text
      if (i > 0) then
         out = text(1:i - 1)//new//text(i + len(old):)
      else
         if (.not. allocated(replace_failure)) replace_failure = 'replaced: pattern not found'
         replace_failure = replace_failure//' "'//old//'"'
      end if
   end function replaced

   !> The patterns `replaced` missed since the test started, as a message
   !> (unallocated when none), and forget them.
   subroutine take_replace_failure(message)
      character(len=:), allocatable, intent(out) :: message
      if (allocated(replace_failure)) call move_alloc(replace_failure, message)
   end subroutine take_replace_failure

end module sprc_testsuite
