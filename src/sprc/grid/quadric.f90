!> Quadratic polynomials in three variables, the level-set algebra of the
!> cut-cell quadrature (sprc_grid_quadrature).
!>
!> Every scene shape is a quadric or an intersection of planes, so in the
!> cell's reference coordinates y in [-1, 1]^dim (x = center + half*y) each
!> shape surface is the zero set of
!>    p(y) = c + sum_i b_i y_i + sum_i A_ii y_i^2 + sum_{i<j} A_ij y_i y_j,
!> stored as p(0:9) = [c, b1, b2, b3, A11, A22, A33, A12, A13, A23].
!> This set is closed under the operations the dimension reduction needs:
!> restriction to a face y_k = v, substitution of an affine y_k(y'), and
!> restriction to an axis-parallel line (a quadratic in one variable, whose
!> roots have a closed form). The derivative along an axis is affine, so its
!> range over a box is exact; the range of p itself is exact for the
!> separable part and a sound interval bound for the mixed terms.
module sprc_grid_quadric
   use sprc_core_kinds, only: wp
   use sprc_geometry_shape, only: shape_type, shape_disk, shape_sphere, shape_ellipse, shape_ellipsoid, &
      & shape_box, shape_halfspace, shape_cylinder
   implicit none
   private

   public :: ncoef, max_shape_quadrics
   public :: quadric_eval, quadric_range, derivative_range, quadric_gradient, depends_on, is_affine
   public :: restrict, substitute, line_coefficients, quadratic_roots, normalize, shape_quadrics, crossing

   !> Coefficients per quadric, p(0:ncoef - 1).
   integer, parameter :: ncoef = 10
   !> Most quadrics one shape contributes (a box: its 2*3 face planes).
   integer, parameter :: max_shape_quadrics = 6

   !> Relative size below which a coefficient produced by cancellation is zero.
   real(wp), parameter :: cancel_tol = 64.0_wp*epsilon(1.0_wp)

contains

   !> Index of the coefficient of y_i y_j (i == j: of y_i^2).
   pure integer function iq(i, j)
      integer, intent(in) :: i, j
      if (i == j) then
         iq = 3 + i
      else
         iq = 4 + i + j
      end if
   end function iq

   !> p(y).
   pure real(wp) function quadric_eval(p, y) result(f)
      real(wp), intent(in) :: p(0:), y(3)
      f = p(0) + p(1)*y(1) + p(2)*y(2) + p(3)*y(3) + p(4)*y(1)**2 + p(5)*y(2)**2 + p(6)*y(3)**2 &
         & + p(7)*y(1)*y(2) + p(8)*y(1)*y(3) + p(9)*y(2)*y(3)
   end function quadric_eval

   !> Gradient of p at y.
   pure function quadric_gradient(p, y) result(g)
      real(wp), intent(in) :: p(0:), y(3)
      real(wp) :: g(3)
      integer :: k
      do k = 1, 3
         g(k) = derivative(p, k, y)
      end do
   end function quadric_gradient

   !> dp/dy_k at y (affine in y).
   pure real(wp) function derivative(p, k, y) result(d)
      real(wp), intent(in) :: p(0:), y(3)
      integer, intent(in) :: k
      integer :: m
      d = p(k) + 2.0_wp*p(iq(k, k))*y(k)
      do m = 1, 3
         if (m /= k) d = d + p(iq(k, m))*y(m)
      end do
   end function derivative

   !> Enclosure [pmin, pmax] of p over the box [lo, hi]: in centered form each
   !> g_i t_i + A_ii t_i^2 has its exact range, the mixed terms their interval
   !> bound (exact for separable quadrics). Not widened for rounding: a zero
   !> set touching the box only within a few ulps (a tangency at a point or
   !> along a line, e.g. a sphere's pole on a cell face) must count as not
   !> crossing it, and one missed by rounding has a measure of a few ulps.
   pure subroutine quadric_range(p, lo, hi, pmin, pmax)
      real(wp), intent(in) :: p(0:), lo(3), hi(3)
      real(wp), intent(out) :: pmin, pmax
      real(wp) :: mid(3), r(3), g(3), f0, a, e1, e2, vmin, vmax, t, cross
      integer :: i, j

      mid = 0.5_wp*(lo + hi)
      r = 0.5_wp*(hi - lo)
      f0 = quadric_eval(p, mid)
      g = quadric_gradient(p, mid)
      pmin = f0
      pmax = f0
      do i = 1, 3
         a = p(iq(i, i))
         e1 = -g(i)*r(i) + a*r(i)**2
         e2 = g(i)*r(i) + a*r(i)**2
         vmin = min(e1, e2)
         vmax = max(e1, e2)
         if (a /= 0.0_wp) then
            t = -g(i)/(2.0_wp*a)
            if (abs(t) < r(i)) then
               vmin = min(vmin, g(i)*t + a*t*t)
               vmax = max(vmax, g(i)*t + a*t*t)
            end if
         end if
         pmin = pmin + vmin
         pmax = pmax + vmax
      end do
      do i = 1, 2
         do j = i + 1, 3
            cross = abs(p(iq(i, j)))*r(i)*r(j)
            pmin = pmin - cross
            pmax = pmax + cross
         end do
      end do
   end subroutine quadric_range

   !> Range [dmin, dmax] of dp/dy_k over the box [lo, hi] (affine: exact, widened by a few ulps).
   pure subroutine derivative_range(p, k, lo, hi, dmin, dmax)
      real(wp), intent(in) :: p(0:), lo(3), hi(3)
      integer, intent(in) :: k
      real(wp), intent(out) :: dmin, dmax
      real(wp) :: mid(3), r(3), d0, spread, mag
      integer :: m

      mid = 0.5_wp*(lo + hi)
      r = 0.5_wp*(hi - lo)
      d0 = derivative(p, k, mid)
      spread = 2.0_wp*abs(p(iq(k, k)))*r(k)
      do m = 1, 3
         if (m /= k) spread = spread + abs(p(iq(k, m)))*r(m)
      end do
      mag = abs(d0) + spread + abs(p(k))
      dmin = d0 - spread - 8.0_wp*epsilon(1.0_wp)*mag
      dmax = d0 + spread + 8.0_wp*epsilon(1.0_wp)*mag
   end subroutine derivative_range

   !> True if p involves y_k at all (an exact test: coefficients set to zero
   !> by restriction or substitution, or by an axis-aligned shape, are zero).
   pure logical function depends_on(p, k)
      real(wp), intent(in) :: p(0:)
      integer, intent(in) :: k
      integer :: m
      depends_on = p(k) /= 0.0_wp .or. p(iq(k, k)) /= 0.0_wp
      do m = 1, 3
         if (m /= k) depends_on = depends_on .or. p(iq(k, m)) /= 0.0_wp
      end do
   end function depends_on

   !> True if p has no quadratic terms.
   pure logical function is_affine(p)
      real(wp), intent(in) :: p(0:)
      is_affine = all(p(4:9) == 0.0_wp)
   end function is_affine

   !> r(y') = p(y) with y_k = v (r does not depend on y_k).
   pure subroutine restrict(p, k, v, r)
      real(wp), intent(in) :: p(0:), v
      integer, intent(in) :: k
      real(wp), intent(out) :: r(0:)
      integer :: m

      r(0:ncoef - 1) = p(0:ncoef - 1)
      r(0) = p(0) + p(k)*v + p(iq(k, k))*v*v
      do m = 1, 3
         if (m /= k) r(m) = p(m) + p(iq(k, m))*v
      end do
      call drop(r, k)
   end subroutine restrict

   !> r(y') = p(y) with y_k = a0 + sum_{m /= k} a(m) y_m (r does not depend on y_k).
   pure subroutine substitute(p, k, a0, a, r)
      real(wp), intent(in) :: p(0:), a0, a(3)
      integer, intent(in) :: k
      real(wp), intent(out) :: r(0:)
      real(wp) :: akk
      integer :: m, n

      akk = p(iq(k, k))
      r(0:ncoef - 1) = p(0:ncoef - 1)
      r(0) = p(0) + p(k)*a0 + akk*a0*a0
      do m = 1, 3
         if (m == k) cycle
         r(m) = p(m) + p(k)*a(m) + 2.0_wp*akk*a0*a(m) + p(iq(k, m))*a0
         r(iq(m, m)) = p(iq(m, m)) + akk*a(m)**2 + p(iq(k, m))*a(m)
      end do
      do m = 1, 2
         do n = m + 1, 3
            if (m == k .or. n == k) cycle
            r(iq(m, n)) = p(iq(m, n)) + 2.0_wp*akk*a(m)*a(n) + p(iq(k, m))*a(n) + p(iq(k, n))*a(m)
         end do
      end do
      call drop(r, k)
   end subroutine substitute

   !> Zero every coefficient involving y_k.
   pure subroutine drop(r, k)
      real(wp), intent(inout) :: r(0:)
      integer, intent(in) :: k
      integer :: m
      r(k) = 0.0_wp
      do m = 1, 3
         r(iq(k, m)) = 0.0_wp
      end do
   end subroutine drop

   !> p on the line through y along y_k: a t^2 + b t + c with t = y_k.
   pure subroutine line_coefficients(p, k, y, a, b, c)
      real(wp), intent(in) :: p(0:), y(3)
      integer, intent(in) :: k
      real(wp), intent(out) :: a, b, c
      real(wp) :: y0(3)
      integer :: m

      a = p(iq(k, k))
      b = p(k)
      do m = 1, 3
         if (m /= k) b = b + p(iq(k, m))*y(m)
      end do
      y0 = y
      y0(k) = 0.0_wp
      c = quadric_eval(p, y0)
   end subroutine line_coefficients

   !> Real roots of a t^2 + b t + c (n = 0, 1 or 2 of them in t(1:n)), by the
   !> cancellation-free pair q/a, c/q with q = -(b + sign(b) sqrt(b^2 - 4ac))/2.
   !> A negative discriminant is no root (a tangency, measure zero); one at
   !> rounding level is one double root.
   pure subroutine quadratic_roots(a, b, c, t, n)
      real(wp), intent(in) :: a, b, c
      real(wp), intent(out) :: t(2)
      integer, intent(out) :: n
      real(wp) :: disc, q

      n = 0
      t = 0.0_wp
      if (a == 0.0_wp) then
         if (b /= 0.0_wp) then
            n = 1
            t(1) = -c/b
         end if
         return
      end if
      disc = b*b - 4.0_wp*a*c
      if (disc < 0.0_wp) return
      ! A discriminant at the rounding level of its terms is a double root (a
      ! surface tangent to a face): two roots sqrt(disc)/|a| apart would open a
      ! sliver of base between them whose height lines all lose their root to
      ! rounding. Roots closer than ~4e-8 of the reference interval merge.
      if (disc <= 16.0_wp*epsilon(1.0_wp)*max(b*b, 4.0_wp*abs(a)*max(abs(a), abs(b), abs(c)))) then
         n = 1
         t(1) = -b/(2.0_wp*a)
         return
      end if
      q = -0.5_wp*(b + sign(sqrt(disc), b))
      if (q == 0.0_wp) then
         ! b = 0 and c = 0: a double root at 0
         n = 1
         return
      end if
      n = 2
      t(1) = q/a
      t(2) = c/q
   end subroutine quadratic_roots

   !> Scale p to max |coefficient| = 1 (zero stays zero).
   pure subroutine normalize(p)
      real(wp), intent(inout) :: p(0:)
      real(wp) :: s
      s = maxval(abs(p(0:ncoef - 1)))
      if (s > 0.0_wp) p(0:ncoef - 1) = p(0:ncoef - 1)/s
   end subroutine normalize

   !> The quadrics of a shape in the reference coordinates of a cell (x = center
   !> + half*y, size 3, unused dimensions zero): one for a round, ellipsoidal
   !> or plane shape, and for a box the face planes passing strictly inside
   !> the x-box [lo, hi] by more than tol (faces on or outside the box
   !> boundary cannot split it). Each is normalized.
   pure subroutine shape_quadrics(shape, center, half, lo, hi, tol, polys, n)
      type(shape_type), intent(in) :: shape
      real(wp), intent(in) :: center(3), half(3), lo(3), hi(3), tol
      real(wp), intent(out) :: polys(0:, :)
      integer, intent(out) :: n
      real(wp) :: d(3), v(3), pm(3, 3), dist
      integer :: dim, i, j

      dim = shape%dim
      n = 0
      d = 0.0_wp
      d(1:dim) = center(1:dim)
      polys = 0.0_wp
      select case (shape%kind)
      case (shape_disk, shape_sphere)
         d(1:dim) = d(1:dim) - shape%center(1:dim)
         n = 1
         dist = norm2(d)
         ! (|d| - r)(|d| + r): no cancellation in the constant term near the surface
         polys(0, 1) = (dist - shape%radius)*(dist + shape%radius)
         do i = 1, dim
            polys(i, 1) = 2.0_wp*d(i)*half(i)
            polys(iq(i, i), 1) = half(i)**2
         end do
      case (shape_ellipse, shape_ellipsoid)
         d(1:dim) = d(1:dim) - shape%center(1:dim)
         n = 1
         polys(0, 1) = sum((d(1:dim)/shape%semi_axes(1:dim))**2) - 1.0_wp
         do i = 1, dim
            polys(i, 1) = 2.0_wp*d(i)*half(i)/shape%semi_axes(i)**2
            polys(iq(i, i), 1) = (half(i)/shape%semi_axes(i))**2
         end do
      case (shape_halfspace)
         d(1:dim) = d(1:dim) - shape%point(1:dim)
         n = 1
         polys(0, 1) = dot_product(d(1:dim), shape%normal(1:dim))
         do i = 1, dim
            polys(i, 1) = half(i)*shape%normal(i)
         end do
      case (shape_cylinder)
         d = d - shape%point
         do i = 1, 3
            do j = 1, 3
               pm(i, j) = -shape%axis(i)*shape%axis(j)
            end do
            pm(i, i) = pm(i, i) + 1.0_wp
         end do
         v = matmul(pm, d)
         n = 1
         dist = norm2(v)
         polys(0, 1) = (dist - shape%radius)*(dist + shape%radius)
         do i = 1, 3
            polys(i, 1) = 2.0_wp*v(i)*half(i)
            polys(iq(i, i), 1) = pm(i, i)*half(i)**2
            do j = i + 1, 3
               polys(iq(i, j), 1) = 2.0_wp*pm(i, j)*half(i)*half(j)
            end do
         end do
      case (shape_box)
         do i = 1, dim
            if (shape%lower(i) > lo(i) + tol .and. shape%lower(i) < hi(i) - tol) then
               n = n + 1
               polys(0, n) = shape%lower(i) - center(i)
               polys(i, n) = -half(i)
            end if
            if (shape%upper(i) > lo(i) + tol .and. shape%upper(i) < hi(i) - tol) then
               n = n + 1
               polys(0, n) = center(i) - shape%upper(i)
               polys(i, n) = half(i)
            end if
         end do
      end select
      do i = 1, n
         call normalize(polys(:, i))
      end do
   end subroutine shape_quadrics

   !> The crossing of the zero sets of p and r seen from the base of height
   !> direction k (both depend on y_k): a quadric c(y') whose zero set holds
   !> the base points above which the two surfaces meet.
   !> status = 1: c returned; 0: they cannot meet (or coincide); -1: not
   !> resolvable here (two non-proportional quadratic parts in y_k).
   !> Method: if one is affine, it is the plane q; otherwise q = A_r,kk p -
   !> A_p,kk r must be affine (equal quadratic parts up to a factor, e.g. two
   !> spheres: the radical plane). On q = 0 both surfaces meet where the
   !> other one vanishes: solve q for y_k and substitute (or, if q does not
   !> involve y_k, q itself is the base quadric).
   pure subroutine crossing(p, r, k, c, status)
      real(wp), intent(in) :: p(0:), r(0:)
      integer, intent(in) :: k
      real(wp), intent(out) :: c(0:)
      integer, intent(out) :: status
      real(wp) :: q(0:ncoef - 1), target(0:ncoef - 1), a(3), scale, beta
      integer :: m

      c(0:ncoef - 1) = 0.0_wp
      status = -1
      if (is_affine(r)) then
         q = r(0:ncoef - 1)
         target = p(0:ncoef - 1)
      else if (is_affine(p)) then
         q = p(0:ncoef - 1)
         target = r(0:ncoef - 1)
      else
         if (p(iq(k, k)) == 0.0_wp .and. r(iq(k, k)) == 0.0_wp) return
         q = r(iq(k, k))*p(0:ncoef - 1) - p(iq(k, k))*r(0:ncoef - 1)
         scale = abs(r(iq(k, k)))*maxval(abs(p(0:ncoef - 1))) + abs(p(iq(k, k)))*maxval(abs(r(0:ncoef - 1)))
         where (abs(q) <= cancel_tol*scale) q = 0.0_wp
         if (.not. is_affine(q)) return
         target = p(0:ncoef - 1)
         if (p(iq(k, k)) == 0.0_wp) target = r(0:ncoef - 1)
      end if
      status = 0
      scale = maxval(abs(q))
      if (.not. scale > 0.0_wp) return
      beta = q(k)
      if (abs(beta) <= cancel_tol*scale) then
         q(k) = 0.0_wp
         ! the surfaces can meet only above q(y') = 0
         if (all(abs(q(1:3)) <= cancel_tol*scale)) return
         c(0:ncoef - 1) = q
         call normalize(c)
         status = 1
         return
      end if
      a = 0.0_wp
      do m = 1, 3
         if (m /= k) a(m) = -q(m)/beta
      end do
      call substitute(target, k, -q(0)/beta, a, c)
      call normalize(c)
      status = 1
   end subroutine crossing

end module sprc_grid_quadric
