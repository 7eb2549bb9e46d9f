!> Tests of the poly area (filled in by its issue work).
module sprc_test_poly
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_poly

contains

   subroutine collect_poly(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_poly

end module sprc_test_poly
