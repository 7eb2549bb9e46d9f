!> Small dense kernels of the patch solves: Householder QR with column pivoting, the
!> application of its Q, triangular solves.
!>
!> Why not LAPACK: a patch problem is tiny (2D p = 1 SPR: 16 x 3), and OpenBLAS 0.3.21 takes
!> a global lock for its buffer in every level-3 call and in dtrsv, so the per-call overhead
!> and the lock dominated the patch loop (perf, bench_mesh_recovery) and kept two threads
!> from scaling. These loops are plain column-oriented Fortran: their results depend only
!> on the values and sizes passed (not on leading dimensions, workspace sizes or threads).
!>
!> `qr_pivoted` is LAPACK's xGEQP3 in its unblocked form (xLAQP2): at step k the remaining
!> column of largest norm is moved to position k (the first one of the largest norm), then
!> annihilated below the diagonal by a Householder reflector H = I - tau v v^T (v(k) = 1,
!> stored below the diagonal; xLARFG's conventions: beta = -sign(alpha) |x|, tau =
!> (beta - alpha)/beta, and tau = 0 when the column below the diagonal is zero). The norms
!> of the remaining columns are downdated and recomputed when cancellation has eaten more
!> than half of their digits (the xLAQP2 test with tol3z = sqrt(eps)). Norms are plain
!> sqrt(sum(x^2)) (`vnorm`), not the overflow-safe NORM2 (a division per entry): the solves
!> pass patch-scaled rows of order one. |R_kk| is then
!> non-increasing, so the rank decisions of the solves (|R_kk| > tol |R_11|) are those of
!> dgeqp3.
module sprc_core_dense
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: qr_pivoted, apply_qt, apply_q, solve_upper, reflector, reflect

contains

   !> Pivoted Householder QR of a(1:m, 1:n) (module notes): R in the upper triangle, the
   !> reflectors below it with their tau(1:min(m, n)); column k of R is column jpvt(k) of a.
   !> With stop_ratio: once every remaining column's norm is at most stop_ratio |R_11|, the
   !> factorisation stops (tau = 0 from there: Q^T leaves those rows alone). The trailing
   !> block is then left unreduced, but each of its entries, diagonal ones included, is at
   !> most its column's norm: a rank decision |R_kk| > tol |R_11| with tol >= stop_ratio
   !> comes out as for the full factorisation. (Equilibrium rows of SPR-C have rank 2 of 9
   !> in 2D p = 1, 3 of 24 in 3D: the rest of the factorisation was round-off.)
   !> With max_steps: only the first max_steps steps (tau = 0 from there). Step k depends on
   !> the steps before it alone, so rows 1..max_steps of R, their pivots and reflectors are
   !> those of the full factorisation, bit for bit: a caller that keeps at most max_steps
   !> rows need not reduce the rest (the contact rows keep at most 9 of a 48-column block).
   pure subroutine qr_pivoted(m, n, a, jpvt, tau, vn, stop_ratio, max_steps)
      integer, intent(in) :: m, n
      real(wp), intent(inout), contiguous :: a(:, :)
      integer, intent(out) :: jpvt(:)
      real(wp), intent(out) :: tau(:)
      !> Work space for the column norms, vn(n, 2) at least (the caller's: an automatic
      !> array here would be a malloc per call in gfortran).
      real(wp), intent(out) :: vn(:, :)
      real(wp), intent(in), optional :: stop_ratio
      integer, intent(in), optional :: max_steps
      real(wp), parameter :: tol3z = sqrt(epsilon(1.0_wp))
      real(wp) :: t, t2
      integer :: i, j, k, p, it, steps

      do j = 1, n
         jpvt(j) = j
         vn(j, 1) = vnorm(a(1:m, j))
         vn(j, 2) = vn(j, 1)
      end do
      steps = min(m, n)
      if (present(max_steps)) steps = max(0, min(steps, max_steps))
      tau(steps + 1:min(m, n)) = 0.0_wp
      do k = 1, steps
         p = k - 1 + maxloc(vn(k:n, 1), dim=1)
         if (present(stop_ratio) .and. k > 1) then
            if (vn(p, 1) <= stop_ratio*abs(a(1, 1))) then
               tau(k:min(m, n)) = 0.0_wp
               return
            end if
         end if
         if (p /= k) then
            do i = 1, m
               t = a(i, p)
               a(i, p) = a(i, k)
               a(i, k) = t
            end do
            it = jpvt(p)
            jpvt(p) = jpvt(k)
            jpvt(k) = it
            vn(p, 1) = vn(k, 1)
            vn(p, 2) = vn(k, 2)
         end if
         call reflector(a(k:m, k), tau(k))
         if (tau(k) /= 0.0_wp) then
            do j = k + 1, n
               call reflect(m - k + 1, a(k + 1:m, k), tau(k), a(k:m, j))
            end do
         end if
         do j = k + 1, n
            if (vn(j, 1) == 0.0_wp) cycle
            t = 1.0_wp - (abs(a(k, j))/vn(j, 1))**2
            t = max(t, 0.0_wp)
            t2 = t*(vn(j, 1)/vn(j, 2))**2
            if (t2 <= tol3z) then
               if (k < m) then
                  vn(j, 1) = vnorm(a(k + 1:m, j))
               else
                  vn(j, 1) = 0.0_wp
               end if
               vn(j, 2) = vn(j, 1)
            else
               vn(j, 1) = vn(j, 1)*sqrt(t)
            end if
         end do
      end do
   end subroutine qr_pivoted

   !> Euclidean norm of a patch-scaled vector (module notes).
   pure real(wp) function vnorm(x)
      real(wp), intent(in), contiguous :: x(:)
      vnorm = sqrt(dot_product(x, x))
   end function vnorm

   !> Householder reflector of x (xLARFG): x(1) becomes beta, x(2:) the vector v(2:).
   pure subroutine reflector(x, tau)
      real(wp), intent(inout), contiguous :: x(:)
      real(wp), intent(out) :: tau
      real(wp) :: xnorm, alpha, beta

      tau = 0.0_wp
      if (size(x) < 2) return
      xnorm = vnorm(x(2:))
      if (xnorm == 0.0_wp) return
      alpha = x(1)
      beta = -sign(sqrt(alpha**2 + xnorm**2), alpha)
      tau = (beta - alpha)/beta
      x(2:) = x(2:)*(1.0_wp/(alpha - beta))
      x(1) = beta
   end subroutine reflector

   !> c(1:m) := H c for one column, H = I - tau v v^T with v = [1, v2(1:m-1)] (v2 = the
   !> stored tail). Explicit-shape: called per column of tiny matrices, without descriptors.
   pure subroutine reflect(m, v2, tau, c)
      integer, intent(in) :: m
      real(wp), intent(in) :: v2(m - 1), tau
      real(wp), intent(inout) :: c(m)
      real(wp) :: s
      integer :: i

      s = c(1)
      do i = 2, m
         s = s + v2(i - 1)*c(i)
      end do
      s = tau*s
      c(1) = c(1) - s
      do i = 2, m
         c(i) = c(i) - s*v2(i - 1)
      end do
   end subroutine reflect

   !> b(1:m, 1:nrhs) := Q^T b with Q = H_1 ... H_k from `qr_pivoted` (a(1:m, 1:k), tau).
   pure subroutine apply_qt(m, k, a, tau, nrhs, b)
      integer, intent(in) :: m, k, nrhs
      real(wp), intent(in), contiguous :: a(:, :)
      real(wp), intent(in) :: tau(:)
      real(wp), intent(inout), contiguous :: b(:, :)
      integer :: i

      do i = 1, k
         call reflect_columns(m, i, a, tau(i), nrhs, b)
      end do
   end subroutine apply_qt

   !> b(1:m, 1:nrhs) := Q b with Q = H_1 ... H_k from `qr_pivoted`.
   pure subroutine apply_q(m, k, a, tau, nrhs, b)
      integer, intent(in) :: m, k, nrhs
      real(wp), intent(in), contiguous :: a(:, :)
      real(wp), intent(in) :: tau(:)
      real(wp), intent(inout), contiguous :: b(:, :)
      integer :: i

      do i = k, 1, -1
         call reflect_columns(m, i, a, tau(i), nrhs, b)
      end do
   end subroutine apply_q

   !> b(i:m, 1:nrhs) := H_i b(i:m, 1:nrhs), H_i = I - tau v v^T, v = [1, a(i+1:m, i)]. Three
   !> columns at a time (2D: the three stress components; 3D: two groups): their sums are
   !> independent chains in scalars (one column's sum alone waits on each addition); each
   !> column's sum is still c(i) + v(i+1) c(i+1) + ... in that order, as in `reflect`.
   pure subroutine reflect_columns(m, i, a, tau, nrhs, b)
      integer, intent(in) :: m, i, nrhs
      real(wp), intent(in), contiguous :: a(:, :)
      real(wp), intent(in) :: tau
      real(wp), intent(inout), contiguous :: b(:, :)
      real(wp) :: s1, s2, s3, v
      integer :: j, r

      if (tau == 0.0_wp) return
      do j = 1, nrhs - 2, 3
         s1 = b(i, j)
         s2 = b(i, j + 1)
         s3 = b(i, j + 2)
         do r = i + 1, m
            v = a(r, i)
            s1 = s1 + v*b(r, j)
            s2 = s2 + v*b(r, j + 1)
            s3 = s3 + v*b(r, j + 2)
         end do
         s1 = tau*s1
         s2 = tau*s2
         s3 = tau*s3
         b(i, j) = b(i, j) - s1
         b(i, j + 1) = b(i, j + 1) - s2
         b(i, j + 2) = b(i, j + 2) - s3
         do r = i + 1, m
            v = a(r, i)
            b(r, j) = b(r, j) - s1*v
            b(r, j + 1) = b(r, j + 1) - s2*v
            b(r, j + 2) = b(r, j + 2) - s3*v
         end do
      end do
      do j = 3*(nrhs/3) + 1, nrhs
         call reflect(m - i + 1, a(i + 1:m, i), tau, b(i:m, j))
      end do
   end subroutine reflect_columns

   !> b(1:k, 1:nrhs) := R^-1 b, or R^-T b if `transposed`, R = the upper triangle of
   !> a(1:k, 1:k). ok = .false. (b partly overwritten) if a diagonal entry is zero or a
   !> result is not finite.
   pure subroutine solve_upper(k, a, nrhs, b, ok, transposed)
      integer, intent(in) :: k, nrhs
      real(wp), intent(in) :: a(:, :)
      real(wp), intent(inout) :: b(:, :)
      logical, intent(out) :: ok
      logical, intent(in), optional :: transposed
      real(wp) :: s
      integer :: i, j, l

      ! A loop, not all([(...)]): the constructor of run-time size was a heap temporary.
      ok = .true.
      do i = 1, k
         if (a(i, i) == 0.0_wp) ok = .false.
      end do
      if (.not. ok) return
      do j = 1, nrhs
         if (present(transposed)) then
            if (transposed) then
               do i = 1, k
                  ! dot_product's sum, in scalar loads: a paired load of b(i-2:i-1) just
                  ! after the scalar store of b(i-1) stalled on store forwarding (perf).
                  s = 0.0_wp
                  !GCC$ novector
                  do l = 1, i - 1
                     s = s + a(l, i)*b(l, j)
                  end do
                  b(i, j) = (b(i, j) - s)/a(i, i)
               end do
               cycle
            end if
         end if
         do i = k, 1, -1
            b(i, j) = b(i, j)/a(i, i)
            b(1:i - 1, j) = b(1:i - 1, j) - b(i, j)*a(1:i - 1, i)
         end do
      end do
      ok = all(abs(b(1:k, 1:nrhs)) <= huge(1.0_wp))
   end subroutine solve_upper

end module sprc_core_dense
