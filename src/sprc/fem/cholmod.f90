!> Sparse Cholesky by CHOLMOD (supernodal, 64-bit indices) for symmetric
!> positive definite matrices.
!>
!> CHOLMOD reads the LOWER triangle of the CSR matrix (entries with column <=
!> row); the strict upper triangle is ignored and not checked for symmetry.
!> Pass the full symmetric matrix or just its lower triangle. A matrix that is
!> not positive definite gives `stat_not_positive_definite` naming the pivot
!> and the matrix column where the factorization broke down.
module sprc_fem_cholmod
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_int, c_int64_t, &
      & c_double, c_char
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_fem_sparse, only: csr_type
   use sprc_fem_linear_solver, only: linear_solver_type, backend_error, message_length
   implicit none
   private

   public :: cholmod_solver_type

   !> Supernodal Cholesky A = L L^T with a fill-reducing ordering: AMD, or
   !> METIS where AMD's factorization would be costly enough for METIS's
   !> dearer analysis to pay (3D systems from about 1.5e4 unknowns; the rule
   !> is in src/shim/sprc_suitesparse.c). `factor_nnz` is nnz(L) without
   !> supernodal padding; `peak_bytes` is CHOLMOD's peak during analysis and
   !> factorization.
   type, extends(linear_solver_type) :: cholmod_solver_type
      private
      type(c_ptr) :: handle = c_null_ptr
      !> The ordering of the current factor, 'AMD' or 'METIS' ('' without one); read-only.
      character(len=5), public :: ordering = ''
   contains
      procedure :: factorize_backend => cholmod_factorize
      procedure :: solve_backend => cholmod_solve
      procedure :: destroy_backend => cholmod_destroy
   end type cholmod_solver_type

   interface
      integer(c_int) function sprc_cholmod_new(handle, msg, len) bind(c)
         import :: c_ptr, c_int, c_int64_t, c_char
         type(c_ptr), intent(out) :: handle
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_cholmod_new

      subroutine sprc_cholmod_free(handle) bind(c)
         import :: c_ptr
         type(c_ptr), intent(inout) :: handle
      end subroutine sprc_cholmod_free

      integer(c_int) function sprc_cholmod_factorize(handle, n, rowptr, col, val, factor_nnz, peak_bytes, &
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
      end function sprc_cholmod_factorize

      integer(c_int) function sprc_cholmod_solve(handle, n, nrhs, b, x, msg, len) bind(c)
         import :: c_ptr, c_int, c_int64_t, c_double, c_char
         type(c_ptr), value :: handle
         integer(c_int64_t), value :: n, nrhs
         real(c_double), intent(in) :: b(*)
         real(c_double), intent(out) :: x(*)
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_cholmod_solve

      integer(c_int) function sprc_cholmod_ordering(handle) bind(c)
         import :: c_ptr, c_int
         type(c_ptr), value :: handle
      end function sprc_cholmod_ordering
   end interface

contains

   subroutine cholmod_factorize(self, a, error)
      class(cholmod_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status

      msg = ''
      if (.not. c_associated(self%handle)) then
         status = sprc_cholmod_new(self%handle, msg, int(len(msg), c_int64_t))
         call backend_error(status, msg, error)
         if (allocated(error)) return
      end if
      status = sprc_cholmod_factorize(self%handle, int(a%nrows, c_int64_t), a%rowptr, a%col, a%val, &
         self%factor_nnz, self%peak_bytes, self%pivot_ratio, msg, int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
      if (allocated(error)) return
      select case (sprc_cholmod_ordering(self%handle))
      case (1)
         self%ordering = 'AMD'
      case (2)
         self%ordering = 'METIS'
      end select
   end subroutine cholmod_factorize

   subroutine cholmod_solve(self, n, nrhs, b, x, transposed, error)
      class(cholmod_solver_type), intent(inout) :: self
      integer, intent(in) :: n, nrhs
      real(wp), intent(in) :: b(n, nrhs)
      real(wp), intent(out) :: x(n, nrhs)
      logical, intent(in) :: transposed
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status

      ! A is symmetric: A^T x = b is the same system.
      if (transposed) continue
      msg = ''
      status = sprc_cholmod_solve(self%handle, int(n, c_int64_t), int(nrhs, c_int64_t), b, x, msg, &
         int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
   end subroutine cholmod_solve

   subroutine cholmod_destroy(self)
      class(cholmod_solver_type), intent(inout) :: self
      call sprc_cholmod_free(self%handle)
      self%ordering = ''
   end subroutine cholmod_destroy

end module sprc_fem_cholmod
