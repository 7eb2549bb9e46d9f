!> Numbers as text for messages and file formats: one implementation for
!> every layer.
module sprc_core_strings
   use sprc_core_kinds, only: wp, i4, i8
   implicit none
   private

   public :: itoa, rtoa

   !> An integer in its shortest decimal form (`i0`); with `digits`, padded
   !> with leading zeros to at least that many digits (`itoa(4, 2)` = '04',
   !> `itoa(123, 2)` = '123').
   interface itoa
      module procedure itoa_i4, itoa_i8
   end interface itoa

contains

   pure function itoa_i4(i, digits) result(s)
      integer(i4), intent(in) :: i
      integer, intent(in), optional :: digits
      character(len=:), allocatable :: s
      s = itoa_i8(int(i, i8), digits)
   end function itoa_i4

   pure function itoa_i8(i, digits) result(s)
      integer(i8), intent(in) :: i
      integer, intent(in), optional :: digits
      character(len=:), allocatable :: s
      character(len=32) :: buf, fmt
      if (present(digits)) then
         write (fmt, '("(i",i0,".",i0,")")') len(buf), min(max(1, digits), len(buf) - 1)
         write (buf, fmt) i
      else
         write (buf, '(i0)') i
      end if
      s = trim(adjustl(buf))
   end function itoa_i8

   !> A real with five significant digits (`es12.4`), for messages.
   pure function rtoa(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(es12.4)') x
      s = trim(adjustl(buf))
   end function rtoa

end module sprc_core_strings
