!> The harness itself: `replaced` fails the test on a missing pattern, and a
!> `should_fail` test passes only by failing.
module sprc_test_testsuite
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, replaced, &
      & take_replace_failure, error_type
   implicit none
   private

   public :: collect_testsuite

contains

   subroutine collect_testsuite(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('replaced_first_occurrence', test_replaced_first), &
         new_unittest('replaced_missing_pattern', test_replaced_missing), &
         new_unittest('should_fail', test_negative, should_fail=.true.) &
         ]
   end subroutine collect_testsuite

   subroutine test_replaced_first(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, replaced('a=1 b=1', '=1', '=2'), 'a=2 b=1', 'first occurrence only')
   end subroutine test_replaced_first

   !> The missing pattern is recorded with its text (taken here, so this test
   !> passes; `run_testsuite` would otherwise fail it with that message).
   subroutine test_replaced_missing(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: message
      call check(error, replaced('order = 1', 'order=1', 'order=2'), 'order = 1', 'text unchanged')
      if (allocated(error)) return
      call take_replace_failure(message)
      call check(error, allocated(message), 'a missing pattern is recorded')
      if (allocated(error)) return
      call check(error, message, 'replaced: pattern not found "order=1"')
   end subroutine test_replaced_missing

   subroutine test_negative(error)
      type(error_type), allocatable, intent(out) :: error
      call test_failed(error, 'this test fails on purpose')
   end subroutine test_negative

end module sprc_test_testsuite
