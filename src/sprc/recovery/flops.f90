!> Nominal floating-point operation counts of the LAPACK/BLAS calls of the patch solves.
!>
!> Counts are multiplications plus additions after the operation-count tables of LAPACK
!> Working Note 41 ("Installation Guide for LAPACK"), for the call as made, not for what a
!> particular LAPACK/BLAS does: they measure the problem, so that flops / (time inside
!> LAPACK) is comparable between libraries. Leading terms only (the
!> usual convention), as listed; the last column is what LAWN 41's full count adds:
!>
!> | routine                  | count                        | LAWN 41 adds             |
!> |--------------------------|------------------------------|--------------------------|
!> | dgemm  C(m,n) = A B      | 2 m n k                      | (exact)                  |
!> | dgemv  A(m,n)            | 2 m n                        | + 2 m (alpha, beta)      |
!> | dsyrk  C(n,n), inner k   | k n (n + 1) = n^2 k + n k    | (exact, one triangle)    |
!> | dgeqrf/dgeqp3, m >= n    | 2 m n^2 - 2 n^3 / 3          | + m n + n^2 + 14 n / 3   |
!> | dgeqrf/dgeqp3, m < n     | 2 n m^2 - 2 m^3 / 3          | + 3 m n - m^2 + 14 m / 3 |
!> | dormqr 'L', C(m,n), k    | 4 m n k - 2 n k^2            | + 3 n k                  |
!> | dtrtrs n, nrhs           | n^2 nrhs                     | (exact, as xTRSM)        |
!> | dsysv  n, nrhs           | n^3 / 3 + 2 n^2 nrhs         | dsytrf + n^2/2 + 19 n/6, |
!> |                          |                              | dsytrs O(n nrhs)         |
!> | dpotrf n                 | n^3 / 3                      | + n^2 / 2 + n / 6        |
!> | dtrtri n                 | n^3 / 3                      | + 2 n / 3                |
!>
!> dgeqp3 is counted as dgeqrf: its column-norm updates add O(m n), lower order. Fractional
!> leading terms are rounded to the nearest integer. All arithmetic is in integer(i8): the
!> largest patch problems are a few hundred rows, far from overflow.
!>
!> `design_matrix_flops` is not LAPACK: it is the one hand-written loop of the solves that is
!> counted (the design matrix at the integration points), kept in a separate counter.
module sprc_recovery_flops
   use sprc_core_kinds, only: i8
   implicit none
   private

   public :: flops_gemm, flops_gemv, flops_syrk, flops_geqrf, flops_ormqr_left, flops_trtrs, flops_sysv
   public :: flops_potrf, flops_trtri
   public :: design_matrix_flops

contains

   !> dgemm: C(m, n) = A(m, k) B(k, n) (LAWN 41: m n k multiplications, m n k additions).
   pure integer(i8) function flops_gemm(m, n, k) result(f)
      integer, intent(in) :: m, n, k
      f = 2_i8*m*n*k
   end function flops_gemm

   !> dgemv with an m x n matrix (LAWN 41: m n multiplications, m n additions).
   pure integer(i8) function flops_gemv(m, n) result(f)
      integer, intent(in) :: m, n
      f = 2_i8*m*n
   end function flops_gemv

   !> dsyrk: one triangle of C(n, n) from an inner dimension k (LAWN 41: k n (n+1) / 2 each).
   pure integer(i8) function flops_syrk(n, k) result(f)
      integer, intent(in) :: n, k
      f = int(k, i8)*n*(n + 1)
   end function flops_syrk

   !> dgeqrf (and dgeqp3) of an m x n matrix, both shapes (LAWN 41 leading terms).
   pure integer(i8) function flops_geqrf(m, n) result(f)
      integer, intent(in) :: m, n
      integer(i8) :: big, small
      big = max(m, n)
      small = min(m, n)
      ! 2 big small^2 - 2 small^3 / 3 = (6 big small^2 - 2 small^3) / 3, which is >= 0;
      ! adding 1 before the integer division rounds a remainder of 2/3 up, 1/3 down.
      f = (6_i8*big*small**2 - 2_i8*small**3 + 1_i8)/3_i8
   end function flops_geqrf

   !> dormqr from the left: Q^T C or Q C with k reflectors, C m x n (LAWN 41 leading terms).
   pure integer(i8) function flops_ormqr_left(m, n, k) result(f)
      integer, intent(in) :: m, n, k
      f = 4_i8*m*n*k - 2_i8*n*k**2
   end function flops_ormqr_left

   !> dtrtrs: triangular solve of order n with nrhs right-hand sides (LAWN 41, as xTRSM).
   pure integer(i8) function flops_trtrs(n, nrhs) result(f)
      integer, intent(in) :: n, nrhs
      f = int(n, i8)**2*nrhs
   end function flops_trtrs

   !> dsysv: dsytrf n^3 / 3 plus dsytrs 2 n^2 nrhs (LAWN 41 leading terms).
   pure integer(i8) function flops_sysv(n, nrhs) result(f)
      integer, intent(in) :: n, nrhs
      f = (int(n, i8)**3 + 1_i8)/3_i8 + 2_i8*int(n, i8)**2*nrhs
   end function flops_sysv

   !> dpotrf of order n (LAWN 41 leading term n^3 / 3, rounded to the nearest integer).
   pure integer(i8) function flops_potrf(n) result(f)
      integer, intent(in) :: n
      f = (int(n, i8)**3 + 1_i8)/3_i8
   end function flops_potrf

   !> dtrtri of order n (LAWN 41 leading term n^3 / 3, rounded to the nearest integer).
   pure integer(i8) function flops_trtri(n) result(f)
      integer, intent(in) :: n
      f = (int(n, i8)**3 + 1_i8)/3_i8
   end function flops_trtri

   !> Hand count of the design matrix at np points (solve's `prepare`): scaling
   !> s = (x - x0)/h, 2 dim np; basis recurrence, one multiply per term after the first,
   !> np (nt - 1); if weighted, the weights sqrt(w / sum w), 3 np (sum, divide, sqrt), and
   !> the row scaling np nt.
   pure integer(i8) function design_matrix_flops(dim, np, nt, weighted) result(f)
      integer, intent(in) :: dim, np, nt
      logical, intent(in) :: weighted
      f = 2_i8*dim*np + int(np, i8)*(nt - 1)
      if (weighted) f = f + 3_i8*np + int(np, i8)*nt
   end function design_matrix_flops

end module sprc_recovery_flops
