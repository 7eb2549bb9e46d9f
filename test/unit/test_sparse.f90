!> Tests of the sparse area (filled in by its issue work).
module sprc_test_sparse
   use sprc_testsuite, only: unittest_type
   implicit none
   private

   public :: collect_sparse

contains

   subroutine collect_sparse(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      allocate (testsuite(0))
   end subroutine collect_sparse

end module sprc_test_sparse
