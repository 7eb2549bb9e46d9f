!> Tests of the exact area (filled in by its issue work).
module sprc_test_exact
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_exact

contains

   subroutine collect_exact(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_exact

end module sprc_test_exact
