!> Tests of the grid area (filled in by its issue work).
module sprc_test_grid
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_grid

contains

   subroutine collect_grid(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_grid

end module sprc_test_grid
