!> Tests of the recovery area (filled in by its issue work).
module sprc_test_recovery
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_recovery

contains

   subroutine collect_recovery(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_recovery

end module sprc_test_recovery
