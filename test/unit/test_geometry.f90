!> Tests of the geometry area (filled in by its issue work).
module sprc_test_geometry
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_geometry

contains

   subroutine collect_geometry(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_geometry

end module sprc_test_geometry
