!> The *empty* real value: a quiet NaN that marks a cell of a result that does
!> not apply (no exact solution, recovery not run). Results in every layer use
!> it (the report row, the contact result per slave point), so it lives here.
module sprc_core_empty
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
   use sprc_core_kinds, only: wp, i8
   implicit none
   private

   public :: report_empty, is_empty

   !> The value of an empty real cell: the default quiet NaN (bits 0x7FF8000000000000).
   real(wp), parameter :: report_empty = transfer(9221120237041090560_i8, 1.0_wp)

contains

   !> True when `x` is an empty cell (any NaN).
   elemental logical function is_empty(x)
      real(wp), intent(in) :: x
      is_empty = ieee_is_nan(x)
   end function is_empty

end module sprc_core_empty
