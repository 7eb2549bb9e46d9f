!> Sparse LU by UMFPACK (64-bit indices) for general square matrices.
!>
!> The CSR matrix is handed over as it is (UMFPACK sees its transpose in
!> compressed-column form and solves the transposed system), copied once, and
!> kept for the iterative refinement UMFPACK does in every solve. A zero pivot
!> gives `stat_singular`.
module sprc_fem_umfpack
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_int, c_int64_t, &
      & c_double, c_char
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_fem_sparse, only: csr_type
   use sprc_fem_linear_solver, only: linear_solver_type, backend_error, message_length
   implicit none
   private

   public :: umfpack_solver_type

   !> LU with partial pivoting, P R A Q = L U (R: UMFPACK's row scaling).
   !> `factor_nnz` is nnz(L) + nnz(U); `peak_bytes` is UMFPACK's peak during
   !> analysis and factorization plus the kept copy of the matrix.
   type, extends(linear_solver_type) :: umfpack_solver_type
      private
      type(c_ptr) :: handle = c_null_ptr
   contains
      procedure :: factorize_backend => umfpack_factorize
      procedure :: solve_backend => umfpack_solve
      procedure :: destroy_backend => umfpack_destroy
   end type umfpack_solver_type

   interface
      integer(c_int) function sprc_umfpack_new(handle, msg, len) bind(c)
         import :: c_ptr, c_int, c_int64_t, c_char
         type(c_ptr), intent(out) :: handle
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_umfpack_new

      subroutine sprc_umfpack_free(handle) bind(c)
         import :: c_ptr
         type(c_ptr), intent(inout) :: handle
      end subroutine sprc_umfpack_free

      integer(c_int) function sprc_umfpack_factorize(handle, n, rowptr, col, val, factor_nnz, peak_bytes, &
            & pivot_ratio, msg, len) bind(c)
         import :: c_ptr, c_int, c_int64_t, c_double, c_char
         type(c_ptr), value :: handle
         integer(c_int64_t), value :: n
         integer(c_int64_t), intent(in) :: rowptr(*)
         integer(c_int), intent(in) :: col(*)
         real(c_double), intent(in) :: val(*)
         integer(c_int64_t), intent(out) :: factor_nnz, peak_bytes
         real(c_double), intent(out) :: pivot_ratio
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_umfpack_factorize

      integer(c_int) function sprc_umfpack_solve(handle, n, nrhs, transposed, b, x, msg, len) bind(c)
         import :: c_ptr, c_int, c_int64_t, c_double, c_char
         type(c_ptr), value :: handle
         integer(c_int64_t), value :: n, nrhs
         integer(c_int), value :: transposed
         real(c_double), intent(in) :: b(*)
         real(c_double), intent(out) :: x(*)
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_umfpack_solve
   end interface

contains

   subroutine umfpack_factorize(self, a, error)
      class(umfpack_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status

      msg = ''
      if (.not. c_associated(self%handle)) then
         status = sprc_umfpack_new(self%handle, msg, int(len(msg), c_int64_t))
         call backend_error(status, msg, error)
         if (allocated(error)) return
      end if
      status = sprc_umfpack_factorize(self%handle, int(a%nrows, c_int64_t), a%rowptr, a%col, a%val, &
         self%factor_nnz, self%peak_bytes, self%pivot_ratio, msg, int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
   end subroutine umfpack_factorize

   subroutine umfpack_solve(self, n, nrhs, b, x, transposed, error)
      class(umfpack_solver_type), intent(inout) :: self
      integer, intent(in) :: n, nrhs
      real(wp), intent(in) :: b(n, nrhs)
      real(wp), intent(out) :: x(n, nrhs)
      logical, intent(in) :: transposed
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status

      msg = ''
      status = sprc_umfpack_solve(self%handle, int(n, c_int64_t), int(nrhs, c_int64_t), &
         merge(1_c_int, 0_c_int, transposed), b, x, msg, int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
   end subroutine umfpack_solve

   subroutine umfpack_destroy(self)
      class(umfpack_solver_type), intent(inout) :: self
      call sprc_umfpack_free(self%handle)
   end subroutine umfpack_destroy

end module sprc_fem_umfpack
