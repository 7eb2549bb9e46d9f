!> Tests of the report area (filled in by its issue work).
module sprc_test_report
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_report

contains

   subroutine collect_report(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_report

end module sprc_test_report
