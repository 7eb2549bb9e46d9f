!> Explicit interfaces to the LAPACK and BLAS routines sprc calls (LP64:
!> default integers), and the one place where LAPACK's `info` becomes an error.
!>
!> Explicit interfaces let the compiler check every call's argument types;
!> fpm's debug profile rejects implicit ones.
module sprc_core_lapack
   use sprc_core_kinds, only: dp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular, &
      & stat_not_positive_definite, stat_not_converged
   implicit none
   private

   public :: dgesv, dgetrf, dgetrs, dgecon, dlange
   public :: dsysv, dsytrf, dsytrs
   public :: dpotrf, dpotrs, dpocon
   public :: dgeqrf, dgeqp3, dormqr, dorgqr, dtrtrs
   public :: dgesvd, dgelsd, dsyev
   public :: dgemm, dgemv, dsyrk, dlamch
   public :: lapack_info_error
   public :: dlacn2

   interface
      !> Solve A X = B by LU with partial pivoting (A overwritten by its factors).
      subroutine dgesv(n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgesv

      !> LU factorization with partial pivoting.
      subroutine dgetrf(m, n, a, lda, ipiv, info)
         import :: dp
         integer, intent(in) :: m, n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: ipiv(*), info
      end subroutine dgetrf

      !> Solve with the LU factors of dgetrf.
      subroutine dgetrs(trans, n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: trans
         integer, intent(in) :: n, nrhs, lda, ldb, ipiv(*)
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dgetrs

      !> Reciprocal condition number of an LU-factored matrix (1- or infinity-norm).
      subroutine dgecon(norm, n, a, lda, anorm, rcond, work, iwork, info)
         import :: dp
         character(len=1), intent(in) :: norm
         integer, intent(in) :: n, lda
         real(dp), intent(in) :: a(lda, *), anorm
         real(dp), intent(out) :: rcond, work(*)
         integer, intent(out) :: iwork(*), info
      end subroutine dgecon

      !> Norm of a general matrix (max, 1, infinity or Frobenius).
      function dlange(norm, m, n, a, lda, work) result(r)
         import :: dp
         character(len=1), intent(in) :: norm
         integer, intent(in) :: m, n, lda
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: work(*)
         real(dp) :: r
      end function dlange

      !> Solve a symmetric indefinite system by Bunch-Kaufman LDL^T.
      subroutine dsysv(uplo, n, nrhs, a, lda, ipiv, b, ldb, work, lwork, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, nrhs, lda, ldb, lwork
         real(dp), intent(inout) :: a(lda, *), b(ldb, *)
         integer, intent(out) :: ipiv(*), info
         real(dp), intent(inout) :: work(*)
      end subroutine dsysv

      !> Bunch-Kaufman LDL^T factorization of a symmetric matrix.
      subroutine dsytrf(uplo, n, a, lda, ipiv, work, lwork, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         integer, intent(out) :: ipiv(*), info
      end subroutine dsytrf

      !> Solve with the LDL^T factors of dsytrf.
      subroutine dsytrs(uplo, n, nrhs, a, lda, ipiv, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, nrhs, lda, ldb, ipiv(*)
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dsytrs

      !> Cholesky factorization of a symmetric positive definite matrix.
      subroutine dpotrf(uplo, n, a, lda, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(dp), intent(inout) :: a(lda, *)
         integer, intent(out) :: info
      end subroutine dpotrf

      !> Solve with the Cholesky factor of dpotrf.
      subroutine dpotrs(uplo, n, nrhs, a, lda, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dpotrs

      !> Reciprocal condition number of a Cholesky-factored matrix.
      subroutine dpocon(uplo, n, a, lda, anorm, rcond, work, iwork, info)
         import :: dp
         character(len=1), intent(in) :: uplo
         integer, intent(in) :: n, lda
         real(dp), intent(in) :: a(lda, *), anorm
         real(dp), intent(out) :: rcond, work(*)
         integer, intent(out) :: iwork(*), info
      end subroutine dpocon

      !> QR factorization (Householder).
      subroutine dgeqrf(m, n, a, lda, tau, work, lwork, info)
         import :: dp
         integer, intent(in) :: m, n, lda, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         real(dp), intent(out) :: tau(*)
         integer, intent(out) :: info
      end subroutine dgeqrf

      !> QR factorization with column pivoting (rank-revealing).
      subroutine dgeqp3(m, n, a, lda, jpvt, tau, work, lwork, info)
         import :: dp
         integer, intent(in) :: m, n, lda, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         integer, intent(inout) :: jpvt(*)
         real(dp), intent(out) :: tau(*)
         integer, intent(out) :: info
      end subroutine dgeqp3

      !> Multiply by Q (or Q^T) of a QR factorization.
      subroutine dormqr(side, trans, m, n, k, a, lda, tau, c, ldc, work, lwork, info)
         import :: dp
         character(len=1), intent(in) :: side, trans
         integer, intent(in) :: m, n, k, lda, ldc, lwork
         real(dp), intent(in) :: a(lda, *), tau(*)
         real(dp), intent(inout) :: c(ldc, *), work(*)
         integer, intent(out) :: info
      end subroutine dormqr

      !> Form the explicit Q of a QR factorization.
      subroutine dorgqr(m, n, k, a, lda, tau, work, lwork, info)
         import :: dp
         integer, intent(in) :: m, n, k, lda, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         real(dp), intent(in) :: tau(*)
         integer, intent(out) :: info
      end subroutine dorgqr

      !> Solve a triangular system.
      subroutine dtrtrs(uplo, trans, diag, n, nrhs, a, lda, b, ldb, info)
         import :: dp
         character(len=1), intent(in) :: uplo, trans, diag
         integer, intent(in) :: n, nrhs, lda, ldb
         real(dp), intent(in) :: a(lda, *)
         real(dp), intent(inout) :: b(ldb, *)
         integer, intent(out) :: info
      end subroutine dtrtrs

      !> Singular value decomposition.
      subroutine dgesvd(jobu, jobvt, m, n, a, lda, s, u, ldu, vt, ldvt, work, lwork, info)
         import :: dp
         character(len=1), intent(in) :: jobu, jobvt
         integer, intent(in) :: m, n, lda, ldu, ldvt, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         real(dp), intent(out) :: s(*), u(ldu, *), vt(ldvt, *)
         integer, intent(out) :: info
      end subroutine dgesvd

      !> Minimum-norm least squares by the SVD (divide and conquer), with rank by rcond.
      subroutine dgelsd(m, n, nrhs, a, lda, b, ldb, s, rcond, rank, work, lwork, iwork, info)
         import :: dp
         integer, intent(in) :: m, n, nrhs, lda, ldb, lwork
         real(dp), intent(inout) :: a(lda, *), b(ldb, *), work(*)
         real(dp), intent(out) :: s(*)
         real(dp), intent(in) :: rcond
         integer, intent(out) :: rank, iwork(*), info
      end subroutine dgelsd

      !> Eigenvalues (and vectors) of a symmetric matrix.
      subroutine dsyev(jobz, uplo, n, a, lda, w, work, lwork, info)
         import :: dp
         character(len=1), intent(in) :: jobz, uplo
         integer, intent(in) :: n, lda, lwork
         real(dp), intent(inout) :: a(lda, *), work(*)
         real(dp), intent(out) :: w(*)
         integer, intent(out) :: info
      end subroutine dsyev

      !> BLAS: C = alpha op(A) op(B) + beta C.
      subroutine dgemm(transa, transb, m, n, k, alpha, a, lda, b, ldb, beta, c, ldc)
         import :: dp
         character(len=1), intent(in) :: transa, transb
         integer, intent(in) :: m, n, k, lda, ldb, ldc
         real(dp), intent(in) :: alpha, beta, a(lda, *), b(ldb, *)
         real(dp), intent(inout) :: c(ldc, *)
      end subroutine dgemm

      !> BLAS: y = alpha op(A) x + beta y.
      subroutine dgemv(trans, m, n, alpha, a, lda, x, incx, beta, y, incy)
         import :: dp
         character(len=1), intent(in) :: trans
         integer, intent(in) :: m, n, lda, incx, incy
         real(dp), intent(in) :: alpha, beta, a(lda, *), x(*)
         real(dp), intent(inout) :: y(*)
      end subroutine dgemv

      !> BLAS: symmetric rank-k update C = alpha A A^T + beta C.
      subroutine dsyrk(uplo, trans, n, k, alpha, a, lda, beta, c, ldc)
         import :: dp
         character(len=1), intent(in) :: uplo, trans
         integer, intent(in) :: n, k, lda, ldc
         real(dp), intent(in) :: alpha, beta, a(lda, *)
         real(dp), intent(inout) :: c(ldc, *)
      end subroutine dsyrk

      !> Machine parameters (eps, safe minimum, ...).
      function dlamch(cmach) result(r)
         import :: dp
         character(len=1), intent(in) :: cmach
         real(dp) :: r
      end function dlamch
   end interface

   interface
      !> Hager/Higham 1-norm estimator by reverse communication: on each return
      !> with kase = 1 (2) overwrite x by A^-1 x (A^-T x) and call again.
      subroutine dlacn2(n, v, x, isgn, est, kase, isave)
         import :: dp
         integer, intent(in) :: n
         real(dp), intent(inout) :: v(*), x(*), est
         integer, intent(inout) :: isgn(*), kase, isave(3)
      end subroutine dlacn2
   end interface

contains

   !> Turn a LAPACK `info` into an error naming the routine and its meaning.
   !> `info < 0`: argument -info was illegal (a bug in sprc: shapes are checked
   !> before the call). `info > 0`: the routine's own failure, interpreted per
   !> routine family. `context` says what was being solved.
   subroutine lapack_info_error(routine, info, context, error)
      character(len=*), intent(in) :: routine, context
      integer, intent(in) :: info
      type(error_type), allocatable, intent(out) :: error
      character(len=24) :: num

      if (info == 0) return
      write (num, '(i0)') abs(info)
      if (info < 0) then
         call fatal_error(error, context//': '//routine//' rejected argument '//trim(num), stat_invalid_input)
         return
      end if
      select case (routine)
      case ('dpotrf', 'dpotrs', 'dpocon')
         call fatal_error(error, context//': '//routine//': leading minor '//trim(num)// &
            ' is not positive definite', stat_not_positive_definite)
      case ('dgesvd', 'dgelsd', 'dsyev')
         call fatal_error(error, context//': '//routine//': '//trim(num)// &
            ' superdiagonals did not converge', stat_not_converged)
      case default
         call fatal_error(error, context//': '//routine//': exactly zero pivot at '//trim(num)// &
            ', the matrix is singular', stat_singular)
      end select
   end subroutine lapack_info_error

end module sprc_core_lapack
