!> Tests of the scene area (filled in by its issue work).
module sprc_test_scene
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_scene

contains

   subroutine collect_scene(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_scene

end module sprc_test_scene
