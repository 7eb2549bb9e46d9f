!> Strings across the C boundary: NUL-terminated C strings in, Fortran
!> strings out into caller buffers. Used by the bind(C) modules only.
module sprc_capi_string
   use, intrinsic :: iso_c_binding, only: c_ptr, c_char, c_int, c_size_t, c_null_char, c_associated, &
      & c_f_pointer
   implicit none
   private

   public :: c_string, copy_to_buffer

   interface
      !> The C library's strlen.
      pure function c_strlen(s) result(n) bind(C, name='strlen')
         import :: c_ptr, c_size_t
         type(c_ptr), value, intent(in) :: s
         integer(c_size_t) :: n
      end function c_strlen
   end interface

contains

   !> The Fortran copy of a NUL-terminated C string; `ok` is false for a NULL pointer.
   subroutine c_string(ptr, str, ok)
      type(c_ptr), intent(in) :: ptr
      character(len=:), allocatable, intent(out) :: str
      logical, intent(out) :: ok
      character(kind=c_char), pointer :: chars(:)
      integer :: n, i

      ok = c_associated(ptr)
      if (.not. ok) then
         str = ''
         return
      end if
      n = int(c_strlen(ptr))
      call c_f_pointer(ptr, chars, [n])
      allocate (character(len=n) :: str)
      do i = 1, n
         str(i:i) = chars(i)
      end do
   end subroutine c_string

   !> Copy `str` into the C buffer `buf` of `size` bytes (pointer to int):
   !> truncated to size-1 characters and always NUL-terminated when size > 0.
   !> A NULL buffer, a NULL size or size <= 0 writes nothing.
   subroutine copy_to_buffer(str, buf, size)
      character(len=*), intent(in) :: str
      type(c_ptr), intent(in) :: buf, size
      integer(c_int), pointer :: n
      character(kind=c_char), pointer :: chars(:)
      integer :: m, i

      if (.not. (c_associated(buf) .and. c_associated(size))) return
      call c_f_pointer(size, n)
      if (n <= 0) return
      call c_f_pointer(buf, chars, [n])
      m = min(len(str), n - 1)
      do i = 1, m
         chars(i) = str(i:i)
      end do
      chars(m + 1) = c_null_char
   end subroutine copy_to_buffer

end module sprc_capi_string
