!> Text for messages and files: one implementation for every layer (integers, reals
!> in a given edit descriptor, shortest round-trip reals, fixed notation, lower case,
!> XML escapes).
module sprc_core_text
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite
   use sprc_core_kinds, only: wp, i4, i8
   implicit none
   private

   public :: fixed_text, itoa, rtoa, real_text, byte_text, lower, xml_escape

   !> An integer in its shortest decimal form (`i0`); with `digits`, padded
   !> with leading zeros to at least that many digits (`itoa(4, 2)` = '04',
   !> `itoa(123, 2)` = '123').
   interface itoa
      module procedure itoa_i4, itoa_i8
   end interface itoa

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

   !> A byte count for people, in decimal units: '850 kB', '171 MB', '6.9 GB'.
   pure function byte_text(bytes) result(text)
      real(wp), intent(in) :: bytes
      character(len=:), allocatable :: text
      character(len=24) :: buf
      if (bytes < 1.0e6_wp) then
         write (buf, '(i0," kB")') nint(bytes/1.0e3_wp)
      else if (bytes < 1.0e9_wp) then
         write (buf, '(i0," MB")') nint(bytes/1.0e6_wp)
      else if (bytes < 1.0e6_wp*huge(1)) then
         write (buf, '(f0.1," GB")') bytes/1.0e9_wp
      else
         write (buf, '(es8.1," GB")') bytes/1.0e9_wp
      end if
      text = trim(adjustl(buf))
   end function byte_text

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

   !> A real with five significant digits (`es12.4`), for messages, or in the
   !> edit descriptor `fmt` (e.g. '(g0)', '(es16.8)'; at most 48 characters out).
   pure function rtoa(x, fmt) result(s)
      real(wp), intent(in) :: x
      character(len=*), intent(in), optional :: fmt
      character(len=:), allocatable :: s
      character(len=48) :: buf
      if (present(fmt)) then
         write (buf, fmt) x
      else
         write (buf, '(es12.4)') x
      end if
      s = trim(adjustl(buf))
   end function rtoa

   !> Shortest decimal text that reads back as the same real: fixed notation
   !> for moderate exponents (`1000.0`, `0.3`), else `2.5e-7` style (`1.0e-300`);
   !> `NaN`, `Infinity`, `-Infinity` for the non-finite values.
   function real_text(x) result(text)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=40) :: buf
      character(len=16) :: fmt
      character(len=:), allocatable :: digits, sign
      real(wp) :: y
      integer :: d, ios, epos, e, n

      if (ieee_is_nan(x)) then
         text = 'NaN'
         return
      else if (.not. ieee_is_finite(x)) then
         text = merge('-Infinity', ' Infinity', x < 0.0_wp)
         text = trim(adjustl(text))
         return
      end if
      ! Three exponent digits (e3): with the default width a three-digit
      ! exponent is written without its 'E' (1.0+100).
      do d = 1, 17
         write (fmt, '("(es40.",i0,"e3)")') d - 1
         write (buf, fmt) x
         read (buf, *, iostat=ios) y
         ! Bitwise identity is what 'reads back as the same real' means.
         if (ios == 0 .and. transfer(y, 0_i8) == transfer(x, 0_i8)) exit
      end do
      buf = adjustl(buf)
      sign = ''
      if (buf(1:1) == '-') then
         sign = '-'
         buf = buf(2:)
      end if
      epos = index(buf, 'E')
      read (buf(epos + 1:), *) e
      digits = buf(1:1)//buf(3:epos - 1)
      if (buf(2:2) /= '.') digits = buf(1:1)
      n = len(digits)
      do while (n > 1)
         if (digits(n:n) /= '0') exit
         n = n - 1
      end do
      digits = digits(1:n)
      if (digits == '0') e = 0
      if (e >= 0 .and. e < 15) then
         if (n <= e + 1) then
            text = sign//digits//repeat('0', e + 1 - n)//'.0'
         else
            text = sign//digits(1:e + 1)//'.'//digits(e + 2:)
         end if
      else if (e < 0 .and. e >= -4) then
         text = sign//'0.'//repeat('0', -e - 1)//digits
      else
         if (n == 1) then
            text = sign//digits//'.0e'//itoa(e)
         else
            text = sign//digits(1:1)//'.'//digits(2:)//'e'//itoa(e)
         end if
      end if
   end function real_text

   !> text with the ASCII capitals A-Z in lower case (names are compared case-blind).
   pure function lower(text) result(low)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: low
      integer :: i
      low = text
      do i = 1, len(text)
         if (text(i:i) >= 'A' .and. text(i:i) <= 'Z') low(i:i) = achar(iachar(text(i:i)) + 32)
      end do
   end function lower

   !> s with the five XML special characters as entities, so that it is safe both as
   !> character data and inside an attribute in either kind of quotes.
   pure function xml_escape(s) result(t)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: t
      integer :: i
      t = ''
      do i = 1, len(s)
         select case (s(i:i))
         case ('&'); t = t//'&amp;'
         case ('<'); t = t//'&lt;'
         case ('>'); t = t//'&gt;'
         case ('"'); t = t//'&quot;'
         case ("'"); t = t//'&apos;'
         case default; t = t//s(i:i)
         end select
      end do
   end function xml_escape

end module sprc_core_text
