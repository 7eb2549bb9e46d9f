!> Tests of the mesh_recovery area (filled in by its issue work).
module sprc_test_mesh_recovery
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_mesh_recovery

contains

   subroutine collect_mesh_recovery(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_mesh_recovery

end module sprc_test_mesh_recovery
