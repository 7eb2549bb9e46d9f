!> Error handling: library procedures never stop or print; a procedure that can
!> fail ends with `type(error_type), allocatable, intent(out) :: error` and
!> allocates it on failure. The caller checks `if (allocated(error)) return`.
module sprc_core_error
   implicit none
   private

   public :: error_type, fatal_error, stat_name
   public :: stat_success, stat_invalid_input, stat_singular, stat_not_positive_definite, &
      & stat_not_converged, stat_io, stat_out_of_memory, stat_unsupported, stat_internal

   !> Named status codes. Values are part of the C API; never renumber.
   integer, parameter :: stat_success = 0
   !> Bad argument, bad scene field, bad shape of an array.
   integer, parameter :: stat_invalid_input = 1
   !> A matrix that is singular (or numerically so) where it must not be.
   integer, parameter :: stat_singular = 2
   !> A matrix that must be symmetric positive definite is not.
   integer, parameter :: stat_not_positive_definite = 3
   !> An iteration did not converge.
   integer, parameter :: stat_not_converged = 4
   !> A file could not be opened, read or written.
   integer, parameter :: stat_io = 5
   !> An allocation failed.
   integer, parameter :: stat_out_of_memory = 6
   !> A valid request that this version does not implement.
   integer, parameter :: stat_unsupported = 7
   !> A broken invariant inside sprc: a bug, please report it.
   integer, parameter :: stat_internal = 8

   !> An error: a status code and a message naming what was wrong and where.
   type :: error_type
      !> One of the `stat_*` codes; never `stat_success` in an allocated error.
      integer :: stat = stat_internal
      !> Human-readable message.
      character(len=:), allocatable :: message
   end type error_type

contains

   !> Allocate `error` with a message and a status (default `stat_invalid_input`).
   pure subroutine fatal_error(error, message, stat)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      integer, intent(in), optional :: stat

      allocate (error)
      error%message = message
      error%stat = stat_invalid_input
      if (present(stat)) error%stat = stat
   end subroutine fatal_error

   !> Short name of a status code, for messages and the C API.
   pure function stat_name(stat) result(name)
      integer, intent(in) :: stat
      character(len=:), allocatable :: name

      select case (stat)
      case (stat_success); name = 'success'
      case (stat_invalid_input); name = 'invalid input'
      case (stat_singular); name = 'singular'
      case (stat_not_positive_definite); name = 'not positive definite'
      case (stat_not_converged); name = 'not converged'
      case (stat_io); name = 'i/o error'
      case (stat_out_of_memory); name = 'out of memory'
      case (stat_unsupported); name = 'unsupported'
      case (stat_internal); name = 'internal error'
      case default; name = 'unknown status'
      end select
   end function stat_name

end module sprc_core_error
