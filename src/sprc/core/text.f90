!> Text of numbers for messages and files.
module sprc_core_text
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: fixed_text

contains

   !> v in fixed notation with `decimals` decimals and the zero before the point that
   !> the f0.d edit descriptor drops (0.063, -0.5, 12.345).
   pure function fixed_text(v, decimals) result(text)
      real(wp), intent(in) :: v
      integer, intent(in) :: decimals
      character(len=:), allocatable :: text
      character(len=64) :: buf
      character(len=16) :: fmt

      write (fmt, '("(f0.",i0,")")') decimals
      write (buf, fmt) v
      text = trim(adjustl(buf))
      if (text(1:1) == '.') then
         text = '0'//text
      else if (len(text) > 1) then
         if (text(1:2) == '-.') text = '-0'//text(2:)
      end if
   end function fixed_text

end module sprc_core_text
