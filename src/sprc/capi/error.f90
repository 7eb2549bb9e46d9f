!> C API, error handles: `sprc_error` carries the status and message of the
!> last failed call that was given it. Every C entry that can fail takes an
!> error handle first; a NULL handle there makes the call do nothing and
!> return its failure value (nothing to report to).
module sprc_capi_error
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_null_ptr, c_associated, c_f_pointer, c_loc
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_success
   use sprc_capi_string, only: copy_to_buffer
   implicit none
   private

   public :: capi_error_type, get_capi_error, set_capi_error
   public :: sprc_new_error, sprc_check_error, sprc_get_error, sprc_get_error_status, sprc_clear_error, &
      & sprc_delete_error

   !> What an `sprc_error` handle points to.
   type :: capi_error_type
      !> Allocated after a failed call, deallocated by `sprc_clear_error`.
      type(error_type), allocatable :: error
   end type capi_error_type

   character(len=*), parameter :: null_error_message = 'sprc: the error handle is NULL (create one with sprc_new_error)'

contains

   !> A new error handle with no error, or NULL if it cannot be allocated.
   function sprc_new_error() result(handle) bind(C, name='sprc_new_error')
      type(c_ptr) :: handle
      type(capi_error_type), pointer :: err
      integer :: stat

      handle = c_null_ptr
      allocate (err, stat=stat)
      if (stat /= 0) return
      handle = c_loc(err)
   end function sprc_new_error

   !> 0 when the handle holds no error, 1 when it does, 2 for a NULL handle.
   function sprc_check_error(handle) result(status) bind(C, name='sprc_check_error')
      type(c_ptr), value :: handle
      integer(c_int) :: status
      type(capi_error_type), pointer :: err

      status = 2
      if (.not. get_capi_error(handle, err)) return
      status = merge(1, 0, allocated(err%error))
   end function sprc_check_error

   !> The status code of the error (sprc_core_error's stat_*: 0 none, 1
   !> invalid input, ..., 8 internal); stat_invalid_input for a NULL handle.
   function sprc_get_error_status(handle) result(status) bind(C, name='sprc_get_error_status')
      type(c_ptr), value :: handle
      integer(c_int) :: status
      type(capi_error_type), pointer :: err

      status = stat_invalid_input
      if (.not. get_capi_error(handle, err)) return
      status = stat_success
      if (allocated(err%error)) status = err%error%stat
   end function sprc_get_error_status

   !> The message into `buf` of `*size` bytes, truncated and NUL-terminated;
   !> "" without an error, a message saying so for a NULL handle. A NULL
   !> `buf` or `size`, or `*size` <= 0, writes nothing.
   subroutine sprc_get_error(handle, buf, size) bind(C, name='sprc_get_error')
      type(c_ptr), value :: handle, buf, size
      type(capi_error_type), pointer :: err

      if (.not. get_capi_error(handle, err)) then
         call copy_to_buffer(null_error_message, buf, size)
      else if (allocated(err%error)) then
         call copy_to_buffer(err%error%message, buf, size)
      else
         call copy_to_buffer('', buf, size)
      end if
   end subroutine sprc_get_error

   !> Forget the error the handle holds (a NULL handle is ignored).
   subroutine sprc_clear_error(handle) bind(C, name='sprc_clear_error')
      type(c_ptr), value :: handle
      type(capi_error_type), pointer :: err

      if (.not. get_capi_error(handle, err)) return
      if (allocated(err%error)) deallocate (err%error)
   end subroutine sprc_clear_error

   !> Free the handle `*ptr` and set it to NULL; NULL `ptr` or `*ptr` is a no-op.
   subroutine sprc_delete_error(ptr) bind(C, name='sprc_delete_error')
      type(c_ptr), value :: ptr
      type(c_ptr), pointer :: handle
      type(capi_error_type), pointer :: err

      if (.not. c_associated(ptr)) return
      call c_f_pointer(ptr, handle)
      if (.not. get_capi_error(handle, err)) return
      deallocate (err)
      handle = c_null_ptr
   end subroutine sprc_delete_error

   !> The error behind a handle; false for a NULL handle.
   logical function get_capi_error(handle, err) result(ok)
      type(c_ptr), intent(in) :: handle
      type(capi_error_type), pointer, intent(out) :: err

      err => null()
      ok = c_associated(handle)
      if (ok) call c_f_pointer(handle, err)
   end function get_capi_error

   !> Store an error in a handle (replacing any earlier one); either a
   !> library error (moved in) or a message with a status.
   subroutine set_capi_error(err, error, message, stat)
      type(capi_error_type), intent(inout) :: err
      type(error_type), allocatable, intent(inout), optional :: error
      character(len=*), intent(in), optional :: message
      integer, intent(in), optional :: stat

      if (allocated(err%error)) deallocate (err%error)
      if (present(error)) then
         if (allocated(error)) call move_alloc(error, err%error)
      else if (present(message)) then
         call fatal_error(err%error, message, stat)
      end if
   end subroutine set_capi_error

end module sprc_capi_error
