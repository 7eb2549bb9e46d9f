!> Tests of the quadrature area (filled in by its issue work).
module sprc_test_quadrature
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_quadrature

contains

   subroutine collect_quadrature(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_quadrature

end module sprc_test_quadrature
