!> Tests of the output area (filled in by its issue work).
module sprc_test_output
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_output

contains

   subroutine collect_output(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_output

end module sprc_test_output
