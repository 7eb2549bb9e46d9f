!> Kind parameters used throughout sprc.
!>
!> Every real literal carries `_wp`, so sprc's arithmetic does not depend on
!> compiler flags such as `-fdefault-real-8` that legacy host codes often set.
module sprc_core_kinds
   implicit none
   private

   !> Double precision, by range and precision rather than by byte count.
   integer, parameter, public :: dp = selected_real_kind(15, 307)
   !> Working precision of every real in sprc.
   integer, parameter, public :: wp = dp
   !> Default index kind (counts below 2**31).
   integer, parameter, public :: i4 = selected_int_kind(9)
   !> Index kind for counts that may exceed 2**31 (nonzeros of large factors, memory).
   integer, parameter, public :: i8 = selected_int_kind(18)

end module sprc_core_kinds
