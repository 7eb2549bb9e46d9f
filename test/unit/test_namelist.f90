!> Tests of the namelist area (filled in by its issue work).
module sprc_test_namelist
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_namelist

contains

   subroutine collect_namelist(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_namelist

end module sprc_test_namelist
