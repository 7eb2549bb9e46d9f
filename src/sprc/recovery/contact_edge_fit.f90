!> The edges of frictionless contact zones in 2D and the amplitude of their edge field
!> (sprc_recovery_contact_edge), for the SPR-C patches there: on a caller's meshes
!> (sprc_contact_caller_mesh_recovery) and on the grid (sprc_estimate_contact_patches, edges
!> found from the slave points' states by the study).
!>
!> 1. `find_contact_edges`: an edge is a vertex of the slave's contact facets shared by
!>    exactly one closed facet, frictionless, and an open one (the caller's states): the
!>    tangent t points along the closed facet towards the open side, the normal is the
!>    slave's outward one of that facet. Stick and slip edges are left to the polynomials
!>    (their edge fields differ).
!> 2. `fit_contact_edge`: the caller's states place the edge within a facet length L (a facet
!>    closed where any of it is in contact). The edge point x_e = v + s L t, s in
!>    [s_min, s_max] (v the vertex), and the amplitude K come from the data: the least squares
!>    fit of both bodies' FE stresses at their integration points within fit_facets L of v by
!>    K S (S of each body: the same point and tangent, its own outward normal) plus a
!>    quadratic polynomial per body and component; s minimises the residual (a scan of
!>    nscan values, then golden sections). The edge is kept when K > 0 (compression) and the
!>    S column lowers the residual by the factor keep_ratio at least; else K = 0.
!>    One scan over the bodies' points per edge (edges are few).
!> 3. `fit_edge_gap`: the edge point from the gap on the open side instead, where the caller
!>    has the deformed gaps of the open points: beyond the edge of a smooth frictionless contact
!>    the gap opens like the 3/2 power of the distance to the edge (the displacement of
!>    the edge field S: g = C xi^(3/2) (1 + O(xi))). The gap is the FE displacements', which
!>    converge an order faster than their stresses, and it is read where the FE states are
!>    settled (gap_window facet lengths beyond the vertex), while the stresses next to the
!>    edge carry the states' error (a contact zone closed per contact cell ends up to a cell
!>    off). The fit g = xi_+^(3/2) (c0 + c1 (xi - xi_v)/L) by least squares over s, as in 2.;
!>    kept when the gap opens (C > 0, C the coefficient of xi^(3/2) at the edge) on
!>    gap_min_points points at least.
!> 4. `gap_amplitude`: the amplitude of the edge field that opens the gap C xi^(3/2): the
!>    surface slope of an elastic half-plane under the pressure p (plane analysis, two
!>    bodies) is g' = 2/(pi E*) (principal value of the integral of p(t)/(x - t)); with
!>    p = K sqrt(-t) its part that varies with x beyond the edge is 2 K sqrt(xi)/E*, so
!>    g = (4 K/(3 E*)) xi^(3/2) and K = 3 E* C / 4, 1/E* = sum of the bodies' 1/E' (E' =
!>    E/(1 - nu^2) in plane strain, E in plane stress). The gap, a displacement, sets K where
!>    the stresses near the edge carry the states' error (Hertz: K = p0 sqrt(2/a) and C =
!>    (2 sqrt 2/3) sqrt(a)/R, Johnson 1985 eq. 4.45).
module sprc_recovery_contact_edge_fit
   use sprc_core_kinds, only: wp
   use sprc_core_dense, only: qr_pivoted, apply_qt
   use sprc_recovery_contact_edge, only: edge_stress
   implicit none
   private

   public :: contact_edge_type, find_contact_edges, fit_contact_edge, edge_subtract, fit_edge_gap, gap_amplitude
   public :: fit_facets, s_min, s_max

   !> Fit and enrichment radius, in facet lengths from the vertex.
   real(wp), parameter :: fit_facets = 4.0_wp
   !> Range of the edge point along t, in facet lengths from the vertex.
   real(wp), parameter :: s_min = -1.5_wp, s_max = 0.5_wp
   !> The edge field must lower the fit's residual to this fraction at least.
   real(wp), parameter :: keep_ratio = 0.95_wp
   integer, parameter :: nscan = 17, ngolden = 30
   !> The open points of the gap fit: from gap_window(1) to gap_window(2) facet lengths beyond
   !> the vertex along t (module notes, 3), at least gap_min_points of them.
   real(wp), parameter :: gap_window(2) = [1.5_wp, 6.0_wp]
   integer, parameter :: gap_min_points = 4
   !> Quadratic terms per component of the smooth part.
   integer, parameter :: nsmooth = 6

   !> One edge (module notes): vertex, facet length, fitted point, unit tangent (towards the
   !> open side), the slave's unit outward normal, amplitude (0: not enriched), radius.
   type :: contact_edge_type
      real(wp) :: vertex(2) = 0.0_wp, length = 0.0_wp
      real(wp) :: point(2) = 0.0_wp, tangent(2) = 0.0_wp, normal(2) = 0.0_wp
      real(wp) :: amplitude = 0.0_wp, radius = 0.0_wp
   end type contact_edge_type

   !> One body's points for the fit.
   type :: cloud_type
      real(wp), allocatable :: x(:, :), w(:), s(:, :)
      real(wp) :: sign = 1.0_wp
   end type cloud_type

   !> A function of one variable for `scan_minimum`. A type rather than a procedure argument:
   !> an internal procedure passed as an argument needs a trampoline on the stack, which
   !> marks the shared library as needing an executable stack, and loaders that refuse one
   !> (glibc 2.41 on) then refuse the library.
   type, abstract :: objective_type
   contains
      procedure(objective_value), deferred :: value
   end type objective_type

   abstract interface
      pure real(wp) function objective_value(self, s)
         import :: objective_type, wp
         class(objective_type), intent(in) :: self
         real(wp), intent(in) :: s
      end function objective_value
   end interface

   !> `fit_contact_edge`'s data: the edge, the two clouds, the factored polynomial columns
   !> (pivoted QR of rank r, m rows), the data orthogonal to them (rb(m, 1)) and the relative
   !> residual without the edge field.
   type, extends(objective_type) :: stress_fit_type
      type(contact_edge_type) :: edge
      type(cloud_type) :: c(2)
      real(wp), allocatable :: a(:, :), tau(:), rb(:, :)
      integer :: m = 0, r = 0
      real(wp) :: r0 = 0.0_wp
   contains
      procedure :: value => stress_fit_value
   end type stress_fit_type

   !> `fit_edge_gap`'s data: the open points' positions xi (in facet lengths) and gaps g
   !> (scaled to a largest of 1).
   type, extends(objective_type) :: gap_fit_type
      real(wp), allocatable :: xi(:), g(:)
   contains
      procedure :: value => gap_fit_value
   end type gap_fit_type

contains

   !> The edges of the slave's contact facets (module notes, 1). nodes(2, nnode); facets(nfn,
   !> nf) 1-based; law(nf) (0 open, law_frictionless closed and frictionless, other codes
   !> closed with friction); normal(2, nf) the outward normal of each facet.
   pure subroutine find_contact_edges(nodes, facets, law, law_frictionless, normal, edges)
      real(wp), intent(in) :: nodes(:, :), normal(:, :)
      integer, intent(in) :: facets(:, :), law(:), law_frictionless
      type(contact_edge_type), allocatable, intent(out) :: edges(:)
      integer, allocatable :: nclosed(:), nopen(:)
      type(contact_edge_type) :: buf(size(facets, 2))
      integer :: f, k, v(2), m

      allocate (nclosed(size(nodes, 2)), nopen(size(nodes, 2)))
      nclosed = 0
      nopen = 0
      do f = 1, size(facets, 2)
         v = vertices(f)
         if (law(f) == 0) then
            nopen(v) = nopen(v) + 1
         else
            nclosed(v) = nclosed(v) + 1
         end if
      end do
      m = 0
      do f = 1, size(facets, 2)
         if (law(f) /= law_frictionless) cycle
         v = vertices(f)
         do k = 1, 2
            if (nclosed(v(k)) /= 1 .or. nopen(v(k)) < 1) cycle
            m = m + 1
            buf(m)%vertex = nodes(1:2, v(k))
            buf(m)%length = norm2(nodes(1:2, v(k)) - nodes(1:2, v(3 - k)))
            buf(m)%tangent = (nodes(1:2, v(k)) - nodes(1:2, v(3 - k)))/buf(m)%length
            buf(m)%normal = normal(1:2, f)
            buf(m)%point = buf(m)%vertex
            buf(m)%radius = fit_facets*buf(m)%length
         end do
      end do
      edges = buf(1:m)
   contains
      !> The two vertices of facet f (of a quadratic facet the two nodes farthest apart).
      pure function vertices(f) result(vv)
         integer, intent(in) :: f
         integer :: vv(2), a, b
         real(wp) :: best
         vv = facets(1:2, f)
         best = -1.0_wp
         do a = 1, size(facets, 1)
            do b = a + 1, size(facets, 1)
               if (norm2(nodes(1:2, facets(a, f)) - nodes(1:2, facets(b, f))) > best) then
                  best = norm2(nodes(1:2, facets(a, f)) - nodes(1:2, facets(b, f)))
                  vv = [facets(a, f), facets(b, f)]
               end if
            end do
         end do
      end function vertices
   end subroutine find_contact_edges

   !> Point and amplitude of `edge` from the slave's and the master's FE data (module notes,
   !> 2): points x(2, n), weight*|J| w(n), stresses s(3, n) of each. The polynomial columns are
   !> factored once (pivoted QR, Q^T applied to the data); each trial point then costs the
   !> edge column's projection: with r_b, r_s the parts of the data and of the column
   !> orthogonal to the polynomials, K = r_s.r_b / |r_s|^2 and the squared residual is
   !> |r_b|^2 - (r_s.r_b)^2 / |r_s|^2.
   pure subroutine fit_contact_edge(edge, x1, w1, s1, x2, w2, s2, range)
      type(contact_edge_type), intent(inout) :: edge
      real(wp), intent(in) :: x1(:, :), w1(:), s1(:, :), x2(:, :), w2(:), s2(:, :)
      !> The range of s (module notes) when the states place the edge less closely than
      !> within a facet (default [s_min, s_max]).
      real(wp), intent(in), optional :: range(2)
      type(stress_fit_type) :: fit
      real(wp), allocatable :: vn(:, :)
      integer, allocatable :: jpvt(:)
      real(wp) :: best, sb, k, r0, s_lo, s_hi
      integer :: i, m, n

      s_lo = s_min
      s_hi = s_max
      if (present(range)) then
         s_lo = range(1)
         s_hi = range(2)
      end if
      call gather(edge, x1, w1, s1, 1.0_wp, fit%c(1))
      call gather(edge, x2, w2, s2, -1.0_wp, fit%c(2))
      m = 3*(size(fit%c(1)%w) + size(fit%c(2)%w))
      n = 2*3*nsmooth
      edge%amplitude = 0.0_wp
      if (m < 2*(n + 1)) return
      fit%edge = edge
      fit%m = m
      allocate (fit%a(m, n), fit%rb(m, 1), fit%tau(n), vn(n, 2), jpvt(n))
      call smooth_columns(edge, fit%c, fit%a, fit%rb(:, 1))
      if (.not. (norm2(fit%rb) > 0.0_wp)) return
      r0 = norm2(fit%rb)
      call qr_pivoted(m, n, fit%a, jpvt, fit%tau, vn)
      do i = 1, n
         if (abs(fit%a(i, i)) > 1.0e3_wp*epsilon(1.0_wp)*real(m, wp)*abs(fit%a(1, 1))) fit%r = i
      end do
      call apply_qt(m, fit%r, fit%a, fit%tau, 1, fit%rb)
      fit%rb(1:fit%r, 1) = 0.0_wp
      ! relative residual without the edge field
      fit%r0 = norm2(fit%rb(:, 1))/r0
      sb = scan_minimum(fit, s_lo, s_hi)
      call stress_fit_trial(fit, sb, best, k)
      edge%point = edge%vertex + sb*edge%length*edge%tangent
      if (k > 0.0_wp .and. best < keep_ratio*fit%r0) edge%amplitude = k
   end subroutine fit_contact_edge

   !> The relative residual with the edge at vertex + s L t.
   pure real(wp) function stress_fit_value(self, s) result(f)
      class(stress_fit_type), intent(in) :: self
      real(wp), intent(in) :: s
      real(wp) :: k

      call stress_fit_trial(self, s, f, k)
   end function stress_fit_value

   !> Relative residual f and amplitude k with the edge at vertex + s L t: with r_b, r_s the
   !> parts of the data and of the edge column orthogonal to the polynomials, k = r_s.r_b /
   !> |r_s|^2.
   pure subroutine stress_fit_trial(fit, s, f, k)
      type(stress_fit_type), intent(in) :: fit
      real(wp), intent(in) :: s
      real(wp), intent(out) :: f, k
      real(wp) :: rs(fit%m, 1), ss, sr, bb

      associate (edge => fit%edge)
         call edge_column(edge, fit%c, edge%vertex + s*edge%length*edge%tangent, rs(:, 1))
      end associate
      call apply_qt(fit%m, fit%r, fit%a, fit%tau, 1, rs)
      rs(1:fit%r, 1) = 0.0_wp
      ss = dot_product(rs(:, 1), rs(:, 1))
      sr = dot_product(rs(:, 1), fit%rb(:, 1))
      bb = dot_product(fit%rb(:, 1), fit%rb(:, 1))
      k = 0.0_wp
      f = fit%r0
      if (.not. (ss > 0.0_wp) .or. .not. (bb > 0.0_wp)) return
      k = sr/ss
      f = fit%r0*sqrt(max(0.0_wp, 1.0_wp - sr**2/(ss*bb)))
   end subroutine stress_fit_trial

   !> The edge point s (in facet lengths from the vertex along t) of the gap fit (module notes,
   !> 3) to the open surface points x(2, n) with their gaps gap(n), over [range(1), range(2)],
   !> and the coefficient c of xi^(3/2) at the edge (gap units per length^(3/2)); ok false
   !> (s = 0, c = 0) where the fit is not kept.
   pure subroutine fit_edge_gap(edge, x, gap, range, s, c, ok)
      type(contact_edge_type), intent(in) :: edge
      real(wp), intent(in) :: x(:, :), gap(:), range(2)
      real(wp), intent(out) :: s, c
      logical, intent(out) :: ok
      type(gap_fit_type) :: fit
      real(wp) :: f, c0, gmax
      logical :: inside(size(gap))
      integer :: i

      s = 0.0_wp
      c = 0.0_wp
      ok = .false.
      do i = 1, size(gap)
         f = dot_product(x(1:2, i) - edge%vertex, edge%tangent)/edge%length
         inside(i) = f >= gap_window(1) .and. f <= gap_window(2) .and. &
            & norm2(x(1:2, i) - edge%vertex) <= (gap_window(2) + 1.0_wp)*edge%length
      end do
      if (count(inside) < gap_min_points) return
      fit%xi = pack([(dot_product(x(1:2, i) - edge%vertex, edge%tangent)/edge%length, i=1, size(gap))], inside)
      fit%g = pack(gap, inside)
      gmax = maxval(abs(fit%g))
      if (.not. (gmax > 0.0_wp)) return
      fit%g = fit%g/gmax
      s = scan_minimum(fit, range(1), range(2))
      call gap_fit_trial(fit, s, f, c0)
      ok = c0 > 0.0_wp
      if (.not. ok) s = 0.0_wp
      if (ok) c = c0*gmax/edge%length**1.5_wp
   end subroutine fit_edge_gap

   !> The squared residual of the gap fit with the edge at st.
   pure real(wp) function gap_fit_value(self, s) result(f)
      class(gap_fit_type), intent(in) :: self
      real(wp), intent(in) :: s
      real(wp) :: c0

      call gap_fit_trial(self, s, f, c0)
   end function gap_fit_value

   !> Squared residual f and the coefficient c0 of xi^(3/2) at the edge (data units, xi in
   !> facet lengths) of the two-term fit with the edge at st.
   pure subroutine gap_fit_trial(fit, st, f, c0)
      type(gap_fit_type), intent(in) :: fit
      real(wp), intent(in) :: st
      real(wp), intent(out) :: f, c0
      real(wp) :: p0(size(fit%g)), p1(size(fit%g)), a11, a12, a22, b1, b2, det, c1

      p0 = max(fit%xi - st, 0.0_wp)**1.5_wp
      p1 = p0*fit%xi
      a11 = dot_product(p0, p0)
      a12 = dot_product(p0, p1)
      a22 = dot_product(p1, p1)
      b1 = dot_product(p0, fit%g)
      b2 = dot_product(p1, fit%g)
      det = a11*a22 - a12**2
      c0 = 0.0_wp
      f = dot_product(fit%g, fit%g)
      if (.not. (det > sqrt(epsilon(1.0_wp))*a11*a22)) return
      c0 = (a22*b1 - a12*b2)/det
      c1 = (a11*b2 - a12*b1)/det
      f = sum((c0*p0 + c1*p1 - fit%g)**2)
      c0 = c0 + c1*st
   end subroutine gap_fit_trial

   !> The minimiser of f over [lo, hi] (lo <= hi): a scan of nscan values, then ngolden golden
   !> sections in the bracket of one scan step either side of the best.
   pure real(wp) function scan_minimum(objective, lo, hi) result(s)
      class(objective_type), intent(in) :: objective
      real(wp), intent(in) :: lo, hi
      real(wp), parameter :: g = 0.6180339887498949_wp
      real(wp) :: best, a, b, x3, x4, f1, f2
      integer :: i, it

      best = huge(1.0_wp)
      s = lo
      do i = 0, nscan - 1
         x3 = lo + (hi - lo)*i/real(nscan - 1, wp)
         f1 = objective%value(x3)
         if (f1 < best) then
            best = f1
            s = x3
         end if
      end do
      a = max(lo, s - (hi - lo)/(nscan - 1))
      b = min(hi, s + (hi - lo)/(nscan - 1))
      x3 = b - g*(b - a)
      x4 = a + g*(b - a)
      f1 = objective%value(x3)
      f2 = objective%value(x4)
      do it = 1, ngolden
         if (f1 < f2) then
            b = x4
            x4 = x3
            f2 = f1
            x3 = b - g*(b - a)
            f1 = objective%value(x3)
         else
            a = x3
            x3 = x4
            f1 = f2
            x4 = a + g*(b - a)
            f2 = objective%value(x4)
         end if
      end do
      s = 0.5_wp*(a + b)
   end function scan_minimum

   !> The amplitude K = 3 E* c / 4 of the edge field that opens the gap c xi^(3/2) between two
   !> bodies of moduli young(1:2) and Poisson's ratios poisson(1:2) (module notes, 4); plane
   !> stress where `plane_stress`, else plane strain.
   pure real(wp) function gap_amplitude(c, young, poisson, plane_stress)
      real(wp), intent(in) :: c, young(2), poisson(2)
      logical, intent(in) :: plane_stress
      real(wp) :: compliance

      if (plane_stress) then
         compliance = sum(1.0_wp/young)
      else
         compliance = sum((1.0_wp - poisson**2)/young)
      end if
      gap_amplitude = 0.75_wp*c/compliance
   end function gap_amplitude

   !> The points of one body within the radius of the vertex.
   pure subroutine gather(edge, x, w, s, sgn, c)
      type(contact_edge_type), intent(in) :: edge
      real(wp), intent(in) :: x(:, :), w(:), s(:, :), sgn
      type(cloud_type), intent(out) :: c
      logical :: inside(size(w))
      integer :: i, n

      do i = 1, size(w)
         inside(i) = norm2(x(1:2, i) - edge%vertex) < edge%radius
      end do
      n = count(inside)
      c%x = reshape(pack(x(1:2, :), spread(inside, 1, 2)), [2, n])
      c%s = reshape(pack(s(1:3, :), spread(inside, 1, 3)), [3, n])
      c%w = pack(w, inside)
      c%sign = sgn
   end subroutine gather

   !> The weighted rows of the smooth part (a quadratic per body and component, in
   !> (x - vertex)/radius) and of the data, three rows per point.
   pure subroutine smooth_columns(edge, c, a, b)
      type(contact_edge_type), intent(in) :: edge
      type(cloud_type), intent(in) :: c(2)
      real(wp), intent(out) :: a(:, :), b(:)
      real(wp) :: t(2), p(nsmooth), sw
      integer :: bd, i, cc, j, o

      a = 0.0_wp
      j = 0
      do bd = 1, 2
         do i = 1, size(c(bd)%w)
            t = (c(bd)%x(:, i) - edge%vertex)/edge%radius
            p = [1.0_wp, t(1), t(2), t(1)**2, t(1)*t(2), t(2)**2]
            sw = sqrt(c(bd)%w(i))
            do cc = 1, 3
               j = j + 1
               o = ((bd - 1)*3 + cc - 1)*nsmooth
               a(j, o + 1:o + nsmooth) = sw*p
               b(j) = sw*c(bd)%s(cc, i)
            end do
         end do
      end do
   end subroutine smooth_columns

   !> The weighted rows of the edge field of unit amplitude at `point` (each body its normal).
   pure subroutine edge_column(edge, c, point, col)
      type(contact_edge_type), intent(in) :: edge
      type(cloud_type), intent(in) :: c(2)
      real(wp), intent(in) :: point(2)
      real(wp), intent(out) :: col(:)
      real(wp) :: se(3)
      integer :: bd, i, j

      j = 0
      do bd = 1, 2
         do i = 1, size(c(bd)%w)
            call edge_stress(point, edge%tangent, c(bd)%sign*edge%normal, 1.0_wp, c(bd)%x(:, i), se)
            col(j + 1:j + 3) = sqrt(c(bd)%w(i))*se
            j = j + 3
         end do
      end do
   end subroutine edge_column

   !> s(1:3, i) := s(1:3, i) - K S(x(:, i)) for the body whose outward normal is sgn times the
   !> edge's (1 the slave, -1 the master).
   pure subroutine edge_subtract(edge, sgn, x, s)
      type(contact_edge_type), intent(in) :: edge
      real(wp), intent(in) :: sgn, x(:, :)
      real(wp), intent(inout) :: s(:, :)
      real(wp) :: se(3)
      integer :: i

      do i = 1, size(x, 2)
         call edge_stress(edge%point, edge%tangent, sgn*edge%normal, edge%amplitude, x(1:2, i), se)
         s(1:3, i) = s(1:3, i) - se
      end do
   end subroutine edge_subtract

end module sprc_recovery_contact_edge_fit
