!> Tests of the quadrature area: Gauss-Legendre rules (sprc_core_gauss), the
!> certified gradient ranges of the shapes, the quadric algebra and the
!> cut-cell rules (sprc_grid_quadrature).
!>
!> Independent checks: closed-form nodes and exactness on monomials for Gauss;
!> brute-force sampling for gradient ranges; closed-form areas, volumes,
!> boundary measures and moments of bodies summed over a uniform grid built
!> here (2^(dim L) cells, classify_box, cell_rule); the divergence theorem
!> (sum w x.n over the boundary = dim * measure, sum w n = 0) for normals and
!> surface weights together; the geometric definition of the normal.
!> Tolerances: 1e-12 (2D) and 1e-10 (3D) relative are the acceptance bounds
!> for q >= 6 on level >= 3; they sit a decade or more above the observed
!> errors (example/bench/quadrature_table.f90) and far below any error a
!> wrong piece, a lost face or a polygonal boundary would cause (>= 1e-6).
module sprc_test_quadrature
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_value, ieee_quiet_nan
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input
   use sprc_core_gauss, only: max_gauss_points, gauss_legendre, tensor_gauss
   use sprc_geometry_region, only: cell_outside, cell_inside, cell_cut
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_ellipse, new_ellipsoid, new_box, &
      & new_halfspace, new_cylinder
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_grid_quadric, only: ncoef, max_shape_quadrics, quadric_eval, shape_quadrics
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule, &
      & cut_cell_rule, boundary_face_rule, default_points
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_quadrature

   real(wp), parameter :: pi = acos(-1.0_wp)
   real(wp), parameter :: tol2d = 1.0e-12_wp, tol3d = 1.0e-10_wp

   !> Sums over a uniform grid: measure, boundary measure, int x1, int x1^2,
   !> boundary sum of w x.n, |boundary sum of w n|, smallest weight; cut cells,
   !> cells subdivided, boxes unresolved; all values finite.
   type :: grid_sums_type
      real(wp) :: m(4) = 0.0_wp
      real(wp) :: div = 0.0_wp, flux = 0.0_wp, wmin = huge(1.0_wp)
      integer :: ncut = 0, nsplit = 0, nunresolved = 0, nsurf = 0
      logical :: finite = .true.
   end type grid_sums_type

contains

   subroutine collect_quadrature(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('gauss_closed_forms', test_gauss_closed_forms), &
         new_unittest('gauss_exactness', test_gauss_exactness), &
         new_unittest('tensor_gauss_monomials', test_tensor_gauss), &
         new_unittest('gauss_errors', test_gauss_errors), &
         new_unittest('gradient_range_certified_and_tight', test_gradient_range), &
         new_unittest('quadrics_match_shapes', test_quadrics_match), &
         new_unittest('accuracy_2d', test_accuracy_2d), &
         new_unittest('accuracy_3d', test_accuracy_3d), &
         new_unittest('order_2q_under_refinement', test_order), &
         new_unittest('divergence_theorem', test_divergence), &
         new_unittest('normals_and_shape_index', test_normals), &
         new_unittest('faces_on_grid_planes', test_grid_faces), &
         & new_unittest('shared_faces_inside', test_shared_faces), &
         new_unittest('planes_off_grid_through_centres', test_planes_off_grid), &
         new_unittest('degenerate_tiny_cut', test_tiny_cut), &
         new_unittest('degenerate_nodes_and_tangency', test_nodes_tangency), &
         new_unittest('degenerate_offcentre_tangent_hole', test_offcentre_tangent), &
         new_unittest('degenerate_csg_corners', test_csg_corners), &
         new_unittest('inside_outside_cells', test_inside_outside), &
         new_unittest('reuse_is_deterministic', test_reuse), &
         new_unittest('quadrature_errors', test_quadrature_errors) &
         ]
   end subroutine collect_quadrature

   ! ------------------------------------------------------------ Gauss

   !> n = 2, 3, 5 against their closed forms (round-off: a few ulps).
   subroutine test_gauss_closed_forms(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: x(max_gauss_points), w(max_gauss_points), a, b
      real(wp), parameter :: tol = 4.0_wp*epsilon(1.0_wp)

      call gauss_legendre(2, x, w, error)
      if (allocated(error)) return
      call check(error, x(2), 1.0_wp/sqrt(3.0_wp), tol, 'n=2 node')
      if (allocated(error)) return
      call check(error, x(1), -1.0_wp/sqrt(3.0_wp), tol, 'n=2 node')
      if (allocated(error)) return
      call check(error, w(1), 1.0_wp, tol, 'n=2 weight')
      if (allocated(error)) return
      call gauss_legendre(3, x, w, error)
      if (allocated(error)) return
      call check(error, x(3), sqrt(0.6_wp), tol, 'n=3 node')
      if (allocated(error)) return
      call check(error, x(2), 0.0_wp, tol, 'n=3 middle node')
      if (allocated(error)) return
      call check(error, w(2), 8.0_wp/9.0_wp, tol, 'n=3 middle weight')
      if (allocated(error)) return
      call check(error, w(1), 5.0_wp/9.0_wp, tol, 'n=3 weight')
      if (allocated(error)) return
      call gauss_legendre(5, x, w, error)
      if (allocated(error)) return
      a = sqrt(5.0_wp - 2.0_wp*sqrt(10.0_wp/7.0_wp))/3.0_wp
      b = sqrt(5.0_wp + 2.0_wp*sqrt(10.0_wp/7.0_wp))/3.0_wp
      call check(error, x(4), a, tol, 'n=5 node')
      if (allocated(error)) return
      call check(error, x(5), b, tol, 'n=5 node')
      if (allocated(error)) return
      call check(error, w(3), 128.0_wp/225.0_wp, tol, 'n=5 weight')
      if (allocated(error)) return
      call check(error, w(4), (322.0_wp + 13.0_wp*sqrt(70.0_wp))/900.0_wp, tol, 'n=5 weight')
      if (allocated(error)) return
      call check(error, w(5), (322.0_wp - 13.0_wp*sqrt(70.0_wp))/900.0_wp, tol, 'n=5 weight')
   end subroutine test_gauss_closed_forms

   !> n = 1..max: positive symmetric weights summing to 2, ascending nodes in
   !> (-1, 1), exact for x^j, j <= 2n - 1 (|error| <= 8 eps: each term is
   !> bounded by its weight), and for x^(2n) off by exactly the known remainder
   !> E_n = 2^(2n+1) (n!)^4 / ((2n+1) ((2n)!)^2) (checked to 1e-6 relative
   !> for n <= 10, where E_n >= 3e-6 dwarfs round-off).
   subroutine test_gauss_exactness(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: x(max_gauss_points), w(max_gauss_points), exact, got, remainder
      integer :: n, j

      do n = 1, max_gauss_points
         call gauss_legendre(n, x, w, error)
         if (allocated(error)) return
         call check(error, all(w(1:n) > 0.0_wp) .and. all(abs(x(1:n)) < 1.0_wp), 'weights positive, nodes inside')
         if (allocated(error)) return
         call check(error, all(x(2:n) > x(1:n - 1)), 'nodes ascending')
         if (allocated(error)) return
         call check(error, maxval(abs(x(1:n) + x(n:1:-1))), 0.0_wp, 2.0_wp*epsilon(1.0_wp), 'nodes symmetric')
         if (allocated(error)) return
         do j = 0, 2*n
            exact = merge(2.0_wp/(j + 1), 0.0_wp, mod(j, 2) == 0)
            got = sum(w(1:n)*x(1:n)**j)
            if (j < 2*n) then
               call check(error, got, exact, 8.0_wp*epsilon(1.0_wp), 'monomial degree < 2n')
            else if (n <= 10) then
               remainder = exp((2*n + 1)*log(2.0_wp) + 4.0_wp*log_gamma(n + 1.0_wp) - log(2.0_wp*n + 1.0_wp) &
                  & - 2.0_wp*log_gamma(2.0_wp*n + 1.0_wp))
               call check(error, exact - got, remainder, 1.0e-6_wp, 'remainder at degree 2n', rel=.true.)
            end if
            if (allocated(error)) return
         end do
      end do
   end subroutine test_gauss_exactness

   !> Tensor rules integrate x^a y^b (z^c) exactly for a, b, c <= 2n - 1 on a box.
   subroutine test_tensor_gauss(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: x(3, 64), w(64), lo(3), hi(3), exact, got
      integer :: a, b, c

      lo = [0.2_wp, -1.3_wp, 0.5_wp]
      hi = [1.1_wp, -0.4_wp, 2.0_wp]
      call tensor_gauss(4, lo, hi, x, w, error)
      if (allocated(error)) return
      do a = 0, 7
         do b = 0, 7, 3
            do c = 0, 7, 2
               exact = mono(a, 1)*mono(b, 2)*mono(c, 3)
               got = sum(w*x(1, :)**a*x(2, :)**b*x(3, :)**c)
               call check(error, got, exact, 1.0e-13_wp, '3D monomial', rel=.true.)
               if (allocated(error)) return
            end do
         end do
      end do
      call tensor_gauss(3, lo(1:2), hi(1:2), x, w, error)
      if (allocated(error)) return
      call check(error, sum(w(1:9)*x(1, 1:9)**5*x(2, 1:9)**4), mono(5, 1)*mono(4, 2), 1.0e-13_wp, '2D monomial', &
         & rel=.true.)
   contains
      real(wp) function mono(p, d)
         integer, intent(in) :: p, d
         mono = (hi(d)**(p + 1) - lo(d)**(p + 1))/(p + 1)
      end function mono
   end subroutine test_tensor_gauss

   subroutine test_gauss_errors(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: x(max_gauss_points + 1), w(max_gauss_points + 1), px(3, 8), pw(8)

      call gauss_legendre(0, x, w, error)
      call expect_invalid(error, 'n = 0')
      if (allocated(error)) return
      call gauss_legendre(max_gauss_points + 1, x, w, error)
      call expect_invalid(error, 'n too large')
      if (allocated(error)) return
      call gauss_legendre(4, x(1:3), w, error)
      call expect_invalid(error, 'x too short')
      if (allocated(error)) return
      call tensor_gauss(2, [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], px, pw, error)
      call expect_invalid(error, 'dim 4')
      if (allocated(error)) return
      call tensor_gauss(2, [0.0_wp, 0.0_wp], [1.0_wp], px, pw, error)
      call expect_invalid(error, 'hi size')
      if (allocated(error)) return
      call tensor_gauss(2, [0.0_wp, 1.0_wp], [1.0_wp, 0.0_wp], px, pw, error)
      call expect_invalid(error, 'lo > hi')
      if (allocated(error)) return
      call tensor_gauss(3, [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], px, pw, error)
      call expect_invalid(error, 'x too small')
   end subroutine test_gauss_errors

   ! ------------------------------------------------------------ gradient ranges

   !> For every kind and many boxes: every sampled gradient component lies in
   !> [gmin, gmax] (slack 1e-12 for rounding), and for the kinds documented as
   !> exact the bounds are approached by the samples (a 21^dim lattice of a box
   !> of edge <= 0.3 kept >= 0.15 from centers and axes: the unit gradient
   !> varies by <= edge/(20*0.15) = 0.1 between lattice points).
   subroutine test_gradient_range(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shapes(9)
      logical :: exact(9)
      real(wp) :: lo(3), hi(3), x(3), g(3), gmin, gmax, smin, smax, u(3), edge
      integer :: s, ibox, k, i, n, dim, ntight
      integer(i8) :: seed

      call shape_catalogue(shapes, exact, error)
      if (allocated(error)) return
      seed = 12345_i8
      ntight = 0
      do s = 1, size(shapes)
         dim = shapes(s)%dim
         do ibox = 1, 40
            call random3(seed, u)
            edge = 0.05_wp + 0.25_wp*u(1)
            call random3(seed, u)
            lo = -1.2_wp + 2.4_wp*u
            hi = lo + edge
            do k = 1, dim
               call shapes(s)%gradient_range(lo(1:dim), hi(1:dim), k, gmin, gmax)
               smin = huge(1.0_wp)
               smax = -huge(1.0_wp)
               n = 21**dim
               do i = 0, n - 1
                  x(1) = lo(1) + edge*mod(i, 21)/20.0_wp
                  x(2) = lo(2) + edge*mod(i/21, 21)/20.0_wp
                  x(3) = lo(3) + edge*mod(i/441, 21)/20.0_wp
                  g(1:dim) = shapes(s)%gradient(x(1:dim))
                  smin = min(smin, g(k))
                  smax = max(smax, g(k))
               end do
               call check(error, smin >= gmin - 1.0e-12_wp .and. smax <= gmax + 1.0e-12_wp, &
                  & 'gradient sample outside the certified range, shape '//shapes(s)%name)
               if (allocated(error)) return
               if (exact(s) .and. far_from_centre(shapes(s), lo, hi)) then
                  ntight = ntight + 1
                  call check(error, smin <= gmin + 0.1_wp .and. smax >= gmax - 0.1_wp, &
                     & 'exact gradient range not attained, shape '//shapes(s)%name)
                  if (allocated(error)) return
               end if
            end do
         end do
      end do
      call check(error, ntight > 100, 'too few boxes tested for tightness')
   end subroutine test_gradient_range

   !> Distance >= 0.15 between the box and the center (or axis) of round shapes.
   logical function far_from_centre(shape, lo, hi)
      type(shape_type), intent(in) :: shape
      real(wp), intent(in) :: lo(3), hi(3)
      real(wp) :: near(3)
      integer :: d
      d = shape%dim
      if (shape%kind == 7) then
         near(1:2) = min(max(shape%point(1:2), lo(1:2)), hi(1:2)) - shape%point(1:2)
         far_from_centre = norm2(near(1:2)) >= 0.15_wp
      else
         near(1:d) = min(max(shape%center(1:d), lo(1:d)), hi(1:d)) - shape%center(1:d)
         far_from_centre = norm2(near(1:d)) >= 0.15_wp
      end if
   end function far_from_centre

   !> The quadrics of a shape have the shape's sign at random points of a cell
   !> (where |phi| > 1e-9: away from the surface, rounding cannot flip it).
   subroutine test_quadrics_match(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shapes(9)
      logical :: exact(9)
      real(wp) :: polys(0:ncoef - 1, max_shape_quadrics), center(3), half(3), y(3), x(3), f, p
      integer :: s, n, i, dim, ntest
      integer(i8) :: seed

      call shape_catalogue(shapes, exact, error)
      if (allocated(error)) return
      seed = 777_i8
      ntest = 0
      center = [0.3_wp, -0.2_wp, 0.1_wp]
      half = [0.6_wp, 0.5_wp, 0.7_wp]
      do s = 1, size(shapes)
         if (shapes(s)%kind == 5) cycle
         dim = shapes(s)%dim
         call shape_quadrics(shapes(s), center, half, center - half, center + half, 0.0_wp, polys, n)
         call check(error, n, 1, 'one quadric per non-box shape')
         if (allocated(error)) return
         do i = 1, 200
            call random3(seed, y)
            y = 2.0_wp*y - 1.0_wp
            if (dim == 2) y(3) = 0.0_wp
            x = center + half*y
            f = shapes(s)%phi(x(1:dim))
            if (abs(f) <= 1.0e-9_wp) cycle
            p = quadric_eval(polys(:, 1), y)
            ntest = ntest + 1
            call check(error, (p < 0.0_wp) .eqv. (f < 0.0_wp), 'quadric sign differs from phi, shape '//shapes(s)%name)
            if (allocated(error)) return
         end do
      end do
      call check(error, ntest > 1000, 'too few points tested')
   end subroutine test_quadrics_match

   ! ------------------------------------------------------------ accuracy on grids

   !> q = 6, levels 3..5: relative errors of measure, boundary measure and
   !> the two moments <= 1e-12 for the four 2D bodies; no box unresolved.
   subroutine test_accuracy_2d(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: icase, level
      do icase = 1, 4
         do level = 3, 5
            call check_case(icase, level, 6, tol2d, error)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_accuracy_2d

   !> q = 6, levels 3..4 (and 2 for one body): <= 1e-10 for the five 3D bodies.
   subroutine test_accuracy_3d(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: icase, level
      do icase = 5, 9
         do level = 3, 4
            call check_case(icase, level, 6, tol3d, error)
            if (allocated(error)) return
         end do
      end do
      call check_case(7, 2, 6, tol3d, error)
   end subroutine test_accuracy_3d

   subroutine check_case(icase, level, q, tol, error, ratio)
      integer, intent(in) :: icase, level, q
      real(wp), intent(in) :: tol
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: ratio
      type(body_type) :: body
      type(grid_sums_type) :: sums
      character(len=:), allocatable :: name
      character(len=8) :: tag
      real(wp) :: exact(4)
      integer :: i

      call make_case(icase, body, name, exact, error)
      if (allocated(error)) return
      call integrate_grid(body, level, q, sums, error, ratio)
      if (allocated(error)) return
      write (tag, '(" L",i0," q",i0)') level, q
      call check_sane(sums, name//trim(tag), error)
      if (allocated(error)) return
      do i = 1, 4
         call check(error, sums%m(i), exact(i), tol, name//trim(tag)//' quantity '//achar(48 + i), rel=.true.)
         if (allocated(error)) return
      end do
   end subroutine check_case

   !> No NaN, positive weights, and (unless allowed) nothing integrated
   !> unresolved at the subdivision limit.
   subroutine check_sane(sums, name, error, allow_unresolved)
      type(grid_sums_type), intent(in) :: sums
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: allow_unresolved
      call check(error, sums%finite, name//': non-finite point or weight')
      if (allocated(error)) return
      call check(error, sums%wmin > 0.0_wp, name//': non-positive weight')
      if (allocated(error)) return
      if (present(allow_unresolved)) then
         if (allow_unresolved) return
      end if
      call check(error, sums%nunresolved, 0, name//': boxes unresolved at max depth')
   end subroutine check_sane

   !> Pure dimension reduction (min_ratio = 0, no strength subdivision): the
   !> error of the disk and the sphere falls at least like h^(2q - 1/2) for q =
   !> 2, 3 between the finest levels tested (the asymptotic order is 2q; half an
   !> order of slack for the pre-asymptotic mix of cut positions).
   subroutine test_order(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: q
      do q = 2, 3
         call check_order(1, 4, 5, q, error)
         if (allocated(error)) return
         call check_order(5, 3, 4, q, error)
         if (allocated(error)) return
      end do
   end subroutine test_order

   subroutine check_order(icase, level1, level2, q, error)
      integer, intent(in) :: icase, level1, level2, q
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(grid_sums_type) :: s1, s2
      character(len=:), allocatable :: name
      real(wp) :: exact(4), e1, e2, order

      call make_case(icase, body, name, exact, error)
      if (allocated(error)) return
      call integrate_grid(body, level1, q, s1, error, 0.0_wp)
      if (allocated(error)) return
      call integrate_grid(body, level2, q, s2, error, 0.0_wp)
      if (allocated(error)) return
      e1 = maxval(abs(s1%m - exact)/abs(exact))
      e2 = maxval(abs(s2%m - exact)/abs(exact))
      order = log(e1/e2)/log(2.0_wp)/(level2 - level1)
      call check(error, order >= 2*q - 0.5_wp, name//': observed order below 2q - 1/2')
   end subroutine check_order

   !> Divergence theorem on the annulus, the quarter annulus (face parts), the
   !> shell octant and the capped cylinder: sum w x.n = dim * measure and
   !> sum w n = 0, relative to the measures.
   subroutine test_divergence(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: cases(4) = [2, 4, 6, 9]
      type(body_type) :: body
      type(grid_sums_type) :: sums
      character(len=:), allocatable :: name
      real(wp) :: exact(4), tol
      integer :: i

      do i = 1, size(cases)
         call make_case(cases(i), body, name, exact, error)
         if (allocated(error)) return
         call integrate_grid(body, 3, 6, sums, error)
         if (allocated(error)) return
         ! a derived quantity (weights times normals times coordinates): ten times the bound of its parts
         tol = 10.0_wp*merge(tol2d, tol3d, body%dim == 2)
         call check(error, sums%div, body%dim*exact(1), tol, name//': sum w x.n', rel=.true.)
         if (allocated(error)) return
         call check(error, sums%flux, 0.0_wp, tol*exact(2), name//': |sum w n|')
         if (allocated(error)) return
      end do
   end subroutine test_divergence

   !> Annulus cells: every surface point lies on its shape's circle (1e-14),
   !> its normal is the exact outward normal of the body there (outer:
   !> (x - c)/R, inner: -(x - c)/r; 1e-14), unit length, and its shape index
   !> names the surface.
   subroutine test_normals(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      character(len=:), allocatable :: name
      real(wp) :: exact(4), lo(2), hi(2), c(2), r, sgn, d(2), h
      integer :: i, j, cell, ncheck

      call make_case(2, body, name, exact, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, 4, error)
      if (allocated(error)) return
      c = [0.51_wp, 0.47_wp]
      h = 1.0_wp/16
      ncheck = 0
      do cell = 0, 255
         lo = h*[mod(cell, 16), cell/16]
         hi = lo + h
         call cell_rule(quad, body, lo, hi, rule, error)
         if (allocated(error)) return
         do i = 1, rule%nsurf
            j = rule%surf_shape(i)
            call check(error, j == 1 .or. j == 2, 'shape index of an annulus surface')
            if (allocated(error)) return
            r = merge(0.4_wp, 0.15_wp, j == 1)
            sgn = merge(1.0_wp, -1.0_wp, body%shapes(j)%name == 'outer')
            call check(error, body%shapes(j)%name == merge('outer', 'inner', j == 1), 'surface name')
            if (allocated(error)) return
            d = rule%surf_x(1:2, i) - c
            call check(error, norm2(d), r, 1.0e-14_wp, 'point on its circle')
            if (allocated(error)) return
            call check(error, maxval(abs(rule%surf_n(1:2, i) - sgn*d/norm2(d))), 0.0_wp, 1.0e-14_wp, 'normal')
            if (allocated(error)) return
            call check(error, norm2(rule%surf_n(1:2, i)), 1.0_wp, 4.0_wp*epsilon(1.0_wp), 'unit normal')
            if (allocated(error)) return
            ncheck = ncheck + 1
         end do
      end do
      call check(error, ncheck > 200, 'too few surface points checked')
   end subroutine test_normals

   !> Boundaries on grid planes enter exactly once, on the body side:
   !> a box [1/4, 3/4]^2 (every cell inside or outside: the whole boundary
   !> comes from boundary faces of inside cells, via cell_rule and
   !> boundary_face_rule) has perimeter 2 and area 1/4; a 3D box likewise; a
   !> Shell octant whose symmetry planes pass through the sphere centres but
   !> cut cells (level 3, q = 6): the measures to 1e-10, and a plane's surface
   !> pass not subdivided where a sphere meets it at its equator (dp/dy_k = 0
   !> there is a turning point of the sphere, not of the plane's surface).
   !> Every cut cell then has at most 5 surfaces, each met by at most
   !> 2 q^2 base points per pass (two resolved height directions), so a
   !> cut cell has at most 5 * 2 * q^2 = 360 surface points.
   subroutine test_planes_off_grid(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(grid_sums_type) :: sums
      character(len=:), allocatable :: name
      real(wp) :: exact(4)
      integer :: i
      integer, parameter :: q = 6

      call make_case(10, body, name, exact, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, q, sums, error)
      if (allocated(error)) return
      call check_sane(sums, name, error)
      if (allocated(error)) return
      do i = 1, 4
         call check(error, sums%m(i), exact(i), tol3d, name//' quantity '//achar(48 + i), rel=.true.)
         if (allocated(error)) return
      end do
      call check(error, sums%nsurf <= sums%ncut*5*2*q**2, name//': surface points beyond 360 per cut cell')
   end subroutine test_planes_off_grid

   !> disk minus the halfspace x <= 1/2 (a subtracted plane on a grid plane)
   !> has the chord on the x > 1/2 side cells with normal -e_x.
   subroutine test_grid_faces(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(grid_sums_type) :: sums
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      real(wp) :: chord, exact_area, lo(2), hi(2), total
      integer :: cell

      call new_body(body, 'square')
      call new_box(s, 'square', [0.25_wp, 0.25_wp], [0.75_wp, 0.75_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 2, sums, error)
      if (allocated(error)) return
      call check(error, sums%ncut, 0, 'no cut cell for an aligned box')
      if (allocated(error)) return
      call check(error, sums%m(1), 0.25_wp, 1.0e-15_wp, 'square area')
      if (allocated(error)) return
      call check(error, sums%m(2), 2.0_wp, 1.0e-15_wp, 'square perimeter counted once')
      if (allocated(error)) return
      ! boundary_face_rule alone gives the same perimeter from the inside cells
      call new_cut_quadrature(quad, 2, 2, error)
      if (allocated(error)) return
      total = 0.0_wp
      do cell = 0, 63
         lo = 0.125_wp*[mod(cell, 8), cell/8]
         hi = lo + 0.125_wp
         call boundary_face_rule(quad, body, lo, hi, rule, error)
         if (allocated(error)) return
         call check(error, rule%nvol, 0, 'boundary_face_rule has no volume points')
         if (allocated(error)) return
         if (rule%nsurf > 0) then
            call check(error, rule%cls, cell_inside, 'boundary faces belong to inside cells')
            if (allocated(error)) return
         end if
         total = total + sum(rule%surf_w(1:rule%nsurf))
      end do
      call check(error, total, 2.0_wp, 1.0e-15_wp, 'perimeter from boundary_face_rule')
      if (allocated(error)) return

      call new_body(body, 'cube')
      call new_box(s, 'cube', [0.25_wp, 0.0_wp, 0.5_wp], [0.75_wp, 1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 2, 2, sums, error)
      if (allocated(error)) return
      call check(error, sums%m(1), 0.25_wp, 1.0e-15_wp, 'box volume')
      if (allocated(error)) return
      call check(error, sums%m(2), 2.0_wp*(0.5_wp + 0.25_wp + 0.5_wp), 1.0e-14_wp, 'box area counted once')
      if (allocated(error)) return

      call new_body(body, 'cut disk')
      call new_disk(s, 'disk', [0.45_wp, 0.52_wp], 0.3_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'plane', [0.5_wp, 0.0_wp], [1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 6, sums, error)
      if (allocated(error)) return
      call check_sane(sums, 'disk minus halfspace', error)
      if (allocated(error)) return
      chord = 2.0_wp*sqrt(0.3_wp**2 - 0.05_wp**2)
      exact_area = 0.3_wp**2*acos(0.05_wp/0.3_wp) - 0.05_wp*sqrt(0.3_wp**2 - 0.05_wp**2)
      call check(error, sums%m(1), exact_area, tol2d, 'segment area', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%m(2), chord + 2.0_wp*0.3_wp*acos(0.05_wp/0.3_wp), tol2d, 'segment boundary', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%flux, 0.0_wp, tol2d, 'closed boundary')
   end subroutine test_grid_faces

   !> Two boxes of a union sharing a face on a grid plane: the shared face is
   !> inside the body (no boundary), the step where their heights differ (off
   !> the grid lines) is boundary, counted once; 2D and 3D. Exact measures:
   !> the sums are of a few exact products, so the tolerance is ulps.
   subroutine test_shared_faces(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(grid_sums_type) :: sums
      integer :: dim

      do dim = 2, 3
         call two_boxes(body, dim, error)
         if (allocated(error)) return
         call integrate_grid(body, 3, 2, sums, error)
         if (allocated(error)) return
         if (dim == 2) then
            call check(error, sums%m(1), 0.125_wp, 1.0e-15_wp, 'union area')
            if (allocated(error)) return
            call check(error, sums%m(2), 1.7_wp, 1.0e-14_wp, 'union perimeter, shared edge inside')
         else
            call check(error, sums%m(1), 0.0625_wp, 1.0e-15_wp, 'union volume')
            if (allocated(error)) return
            call check(error, sums%m(2), 1.1_wp, 1.0e-14_wp, 'union area, shared face inside')
         end if
         if (allocated(error)) return
         call check(error, sums%flux, 0.0_wp, 1.0e-14_wp, 'closed boundary')
         if (allocated(error)) return
      end do
   end subroutine test_shared_faces

   !> [0.25, 0.5] x [0.25, 0.6] (x [0.25, 0.75]) added to [0.5, 0.75] x [0.25, 0.4] (x [0.25, 0.75]).
   subroutine two_boxes(body, dim, error)
      type(body_type), intent(out) :: body
      integer, intent(in) :: dim
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      real(wp) :: lo(3), hi(3)

      call new_body(body, 'union')
      lo = [0.25_wp, 0.25_wp, 0.25_wp]
      hi = [0.5_wp, 0.6_wp, 0.75_wp]
      if (dim == 3) hi = [0.5_wp, 0.75_wp, 0.6_wp]
      call new_box(s, 'left', lo(1:dim), hi(1:dim), error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      lo(1) = 0.5_wp
      hi(1) = 0.75_wp
      hi(dim) = 0.4_wp
      call new_box(s, 'right', lo(1:dim), hi(1:dim), error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
   end subroutine two_boxes

   !> A cut of 1e-12 of the cell size: a rectangle whose top lies 1e-12 h above
   !> a grid line, and a disk reaching 1e-12 h past a grid line.
   subroutine test_tiny_cut(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(grid_sums_type) :: sums
      real(wp) :: delta, r, a

      delta = 1.0e-12_wp/8
      call new_body(body, 'slab')
      call new_box(s, 'domain', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'top', [0.0_wp, 0.5_wp + delta], [0.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 6, sums, error)
      if (allocated(error)) return
      call check_sane(sums, 'slab', error)
      if (allocated(error)) return
      call check(error, sums%ncut > 0, 'the sliver cells are cut')
      if (allocated(error)) return
      call check(error, sums%m(1), 0.5_wp + delta, 1.0e-14_wp, 'slab area')
      if (allocated(error)) return
      call check(error, sums%m(2), 3.0_wp + 2.0_wp*delta, 1.0e-14_wp, 'slab perimeter')
      if (allocated(error)) return

      r = 0.25_wp + delta
      call new_body(body, 'disk')
      call new_disk(s, 'disk', [0.5_wp, 0.5_wp], r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 6, sums, error)
      if (allocated(error)) return
      call check_sane(sums, 'disk with sliver cuts', error)
      if (allocated(error)) return
      a = pi*r*r
      call check(error, sums%m(1), a, tol2d, 'area', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%m(2), 2.0_wp*pi*r, tol2d, 'perimeter', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%m(4), a*0.25_wp + pi*r**4/4.0_wp, tol2d, 'second moment', rel=.true.)
   end subroutine test_tiny_cut

   !> Boundaries through grid nodes, tangent to grid lines and planes, with
   !> the center on a node: a disk (0.5, 0.5; 0.25) and a sphere (center the
   !> cube center, radius 0.25) on levels 2 and 3.
   subroutine test_nodes_tangency(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(grid_sums_type) :: sums
      real(wp) :: r
      integer :: level

      r = 0.25_wp
      call new_body(body, 'disk')
      call new_disk(s, 'disk', [0.5_wp, 0.5_wp], r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      do level = 2, 3
         call integrate_grid(body, level, 6, sums, error)
         if (allocated(error)) return
         call check_sane(sums, 'disk through nodes', error)
         if (allocated(error)) return
         call check(error, sums%m(1), pi*r*r, tol2d, 'area', rel=.true.)
         if (allocated(error)) return
         call check(error, sums%m(2), 2.0_wp*pi*r, tol2d, 'perimeter', rel=.true.)
         if (allocated(error)) return
      end do
      call new_body(body, 'ball')
      call new_sphere(s, 'ball', [0.5_wp, 0.5_wp, 0.5_wp], r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      do level = 2, 3
         call integrate_grid(body, level, 6, sums, error)
         if (allocated(error)) return
         ! the pole touches a face at a node: the face restriction is a single
         ! point, a zero set no height direction resolves (boxes 2^-10 h wide)
         call check_sane(sums, 'sphere through nodes', error, allow_unresolved=.true.)
         if (allocated(error)) return
         call check(error, sums%m(1), 4.0_wp*pi*r**3/3.0_wp, tol3d, 'volume', rel=.true.)
         if (allocated(error)) return
         call check(error, sums%m(2), 4.0_wp*pi*r**2, tol3d, 'area', rel=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_nodes_tangency

   !> A disk with an off-centre hole whose circle is tangent to the grid line
   !> x = 0.625 from inside a cell (levels 3-5), away from any node: the face
   !> restriction there has a double root, which rounding once split into two
   !> roots ~1e-9 apart and lost the arc between them (5e-9 of the boundary
   !> length, whatever q). Boundary length and the closure sum w n = 0 to 1e-12.
   subroutine test_offcentre_tangent(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(grid_sums_type) :: sums
      real(wp), parameter :: c_out(2) = [0.55_wp, 0.525_wp], r_out = 0.385_wp, c_in(2) = [0.51_wp, 0.55_wp]
      real(wp) :: r_in
      integer :: level

      r_in = 0.625_wp - c_in(1)
      call new_body(body, 'holed')
      call new_disk(s, 'outer', c_out, r_out, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_disk(s, 'hole', c_in, r_in, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      do level = 3, 5
         call integrate_grid(body, level, 6, sums, error)
         if (allocated(error)) return
         call check_sane(sums, 'off-centre tangent hole', error)
         if (allocated(error)) return
         call check(error, sums%m(1), pi*(r_out**2 - r_in**2), tol2d, 'area', rel=.true.)
         if (allocated(error)) return
         call check(error, sums%m(2), 2.0_wp*pi*(r_out + r_in), tol2d, 'boundary length', rel=.true.)
         if (allocated(error)) return
      end do
   end subroutine test_offcentre_tangent

   !> CSG edges and corners inside cells: a disk cut by an oblique plane (a
   !> circular segment), the union of two overlapping disks (corners where the
   !> circles cross: the radical-line crossing), a sphere cut by an oblique
   !> plane (a spherical cap, edge circle inside cells).
   subroutine test_csg_corners(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(grid_sums_type) :: sums
      real(wp) :: n(3), c(3), r, d, a, lens, theta, capv, capa

      r = 0.3_wp
      c = [0.47_wp, 0.52_wp, 0.49_wp]
      n = [0.6_wp, 0.8_wp, 0.0_wp]
      d = 0.1234_wp
      ! disk ∩ {(x - c).n <= d}
      call new_body(body, 'segment')
      call new_disk(s, 'disk', c(1:2), r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'cut', c(1:2) + d*n(1:2), n(1:2), error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 6, sums, error)
      if (allocated(error)) return
      call check_sane(sums, 'disk and oblique plane', error)
      if (allocated(error)) return
      theta = acos(d/r)
      a = pi*r*r - (r*r*theta - d*sqrt(r*r - d*d))
      call check(error, sums%m(1), a, tol2d, 'segment area', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%m(2), 2.0_wp*r*(pi - theta) + 2.0_wp*sqrt(r*r - d*d), tol2d, 'segment boundary', &
         & rel=.true.)
      if (allocated(error)) return

      ! two disks of radius r, centers 2d apart along x
      call new_body(body, 'union')
      call new_disk(s, 'left', [c(1) - d, c(2)], r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_disk(s, 'right', [c(1) + d, c(2)], r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 6, sums, error)
      if (allocated(error)) return
      call check_sane(sums, 'union of disks', error)
      if (allocated(error)) return
      lens = 2.0_wp*(r*r*theta - d*sqrt(r*r - d*d))
      call check(error, sums%m(1), 2.0_wp*pi*r*r - lens, tol2d, 'union area', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%m(2), 2.0_wp*(2.0_wp*pi*r - 2.0_wp*r*theta), tol2d, 'union boundary', rel=.true.)
      if (allocated(error)) return

      ! sphere ∩ {(x - c).n <= d} with an oblique n
      n = [0.48_wp, 0.6_wp, 0.64_wp]
      call new_body(body, 'cap')
      call new_sphere(s, 'sphere', c, r, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'cut', c + d*n, n, error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call integrate_grid(body, 3, 6, sums, error)
      if (allocated(error)) return
      ! where the edge circle crosses a cell face, two derived conics meet in
      ! the base: left to subdivision (boxes 2^-10 h wide at the limit)
      call check_sane(sums, 'sphere and oblique plane', error, allow_unresolved=.true.)
      if (allocated(error)) return
      capv = pi*(r - d)**2*(2.0_wp*r + d)/3.0_wp
      capa = 2.0_wp*pi*r*(r - d)
      call check(error, sums%m(1), 4.0_wp*pi*r**3/3.0_wp - capv, tol3d, 'cut sphere volume', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%m(2), 4.0_wp*pi*r*r - capa + pi*(r*r - d*d), tol3d, 'cut sphere area', rel=.true.)
   end subroutine test_csg_corners

   !> An inside cell gets the tensor rule (q^dim points, weights of
   !> tensor_gauss) and so does cut_cell_rule on it; an outside cell gets nothing.
   subroutine test_inside_outside(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      real(wp) :: x(3, 64), w(64), lo(3), hi(3)

      call new_body(body, 'ball')
      call new_sphere(s, 'ball', [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, 3, 4, error)
      if (allocated(error)) return
      lo = [0.1_wp, 0.2_wp, -0.3_wp]
      hi = lo + 0.25_wp
      call cell_rule(quad, body, lo, hi, rule, error)
      if (allocated(error)) return
      call tensor_gauss(4, lo, hi, x, w, error)
      if (allocated(error)) return
      call check(error, rule%cls, cell_inside, 'inside class')
      if (allocated(error)) return
      call check(error, rule%nvol, 64, 'tensor points')
      if (allocated(error)) return
      call check(error, rule%nsurf, 0, 'no surface inside')
      if (allocated(error)) return
      call check(error, maxval(abs(rule%vol_w(1:64) - w)), 0.0_wp, 1.0e-17_wp, 'tensor weights')
      if (allocated(error)) return
      call check(error, maxval(abs(rule%vol_x(:, 1:64) - x)), 0.0_wp, 1.0e-15_wp, 'tensor points')
      if (allocated(error)) return
      call cut_cell_rule(quad, body, lo, hi, rule, error)
      if (allocated(error)) return
      call check(error, sum(rule%vol_w(1:rule%nvol)), 0.25_wp**3, 1.0e-14_wp, 'cut rule of an inside cell', rel=.true.)
      if (allocated(error)) return
      lo = [2.0_wp, 0.0_wp, 0.0_wp]
      hi = lo + 0.5_wp
      call cell_rule(quad, body, lo, hi, rule, error)
      if (allocated(error)) return
      call check(error, rule%cls == cell_outside .and. rule%nvol == 0 .and. rule%nsurf == 0, 'outside cell empty')
      if (allocated(error)) return
      call check(error, default_points(1) == 3 .and. default_points(2) == 4, 'default points per FE order')
   end subroutine test_inside_outside

   !> One rule object reused across cells gives the same bits as a fresh one.
   subroutine test_reuse(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: reused, fresh
      character(len=:), allocatable :: name
      real(wp) :: exact(4), lo(3), hi(3)
      integer :: cell

      call make_case(9, body, name, exact, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, 3, 3, error)
      if (allocated(error)) return
      do cell = 0, 63
         lo = 0.25_wp*[mod(cell, 4), mod(cell/4, 4), cell/16]
         hi = lo + 0.25_wp
         call cell_rule(quad, body, lo, hi, reused, error)
         if (allocated(error)) return
         block
            type(cell_rule_type) :: tmp
            fresh = tmp
         end block
         call cell_rule(quad, body, lo, hi, fresh, error)
         if (allocated(error)) return
         call check(error, reused%nvol == fresh%nvol .and. reused%nsurf == fresh%nsurf, 'same point counts')
         if (allocated(error)) return
         call check(error, all(reused%vol_w(1:reused%nvol) == fresh%vol_w(1:fresh%nvol)) .and. &
            & all(reused%surf_w(1:reused%nsurf) == fresh%surf_w(1:fresh%nsurf)) .and. &
            & all(reused%surf_x(:, 1:reused%nsurf) == fresh%surf_x(:, 1:fresh%nsurf)), 'same bits')
         if (allocated(error)) return
      end do
   end subroutine test_reuse

   subroutine test_quadrature_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(cut_quadrature_type) :: quad, unbuilt
      type(cell_rule_type) :: rule
      type(body_type) :: body, empty
      type(shape_type) :: s
      real(wp) :: nan

      call new_cut_quadrature(quad, 4, 3, error)
      call expect_invalid(error, 'dim 4')
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, 0, error)
      call expect_invalid(error, 'q = 0')
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, max_gauss_points + 1, error)
      call expect_invalid(error, 'q too large')
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, 3, error, max_depth=-1)
      call expect_invalid(error, 'max_depth < 0')
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, 3, error, min_ratio=-1.0_wp)
      call expect_invalid(error, 'min_ratio < 0')
      if (allocated(error)) return

      call new_body(body, 'disk')
      call new_disk(s, 'disk', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call cell_rule(unbuilt, body, [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], rule, error)
      call expect_invalid(error, 'settings not built')
      if (allocated(error)) return
      call new_cut_quadrature(quad, 3, 3, error)
      if (allocated(error)) return
      call cell_rule(quad, body, [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], rule, error)
      call expect_invalid(error, 'dimension mismatch')
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, 3, error)
      if (allocated(error)) return
      call new_body(empty, 'empty')
      call cut_cell_rule(quad, empty, [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], rule, error)
      call expect_invalid(error, 'empty body')
      if (allocated(error)) return
      call cut_cell_rule(quad, body, [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], rule, error)
      call expect_invalid(error, 'lo size')
      if (allocated(error)) return
      call boundary_face_rule(quad, body, [0.0_wp, 1.0_wp], [1.0_wp, 1.0_wp], rule, error)
      call expect_invalid(error, 'lo = hi')
      if (allocated(error)) return
      nan = ieee_value(nan, ieee_quiet_nan)
      call cell_rule(quad, body, [0.0_wp, nan], [1.0_wp, 1.0_wp], rule, error)
      call expect_invalid(error, 'NaN corner')
   end subroutine test_quadrature_errors

   ! ------------------------------------------------------------ helpers

   subroutine expect_invalid(error, what)
      type(error_type), allocatable, intent(inout) :: error
      character(len=*), intent(in) :: what
      if (.not. allocated(error)) then
         call test_failed(error, what//': expected an error')
         return
      end if
      if (error%stat /= stat_invalid_input .or. len(error%message) == 0) then
         deallocate (error)
         call test_failed(error, what//': expected stat_invalid_input with a message')
         return
      end if
      deallocate (error)
   end subroutine expect_invalid

   !> Integrate over the uniform grid of 2^(dim*level) cells on the unit square/cube.
   subroutine integrate_grid(body, level, q, sums, error, ratio)
      type(body_type), intent(in) :: body
      integer, intent(in) :: level, q
      type(grid_sums_type), intent(out) :: sums
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: ratio
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      real(wp) :: lo(3), hi(3), h, flux(3), w
      integer :: n, dim, cell, idx, d, i

      dim = body%dim
      if (present(ratio)) then
         call new_cut_quadrature(quad, dim, q, error, min_ratio=ratio)
      else
         call new_cut_quadrature(quad, dim, q, error)
      end if
      if (allocated(error)) return
      n = 2**level
      h = 1.0_wp/n
      flux = 0.0_wp
      do cell = 0, n**dim - 1
         idx = cell
         do d = 1, dim
            lo(d) = h*mod(idx, n)
            hi(d) = lo(d) + h
            idx = idx/n
         end do
         call cell_rule(quad, body, lo(1:dim), hi(1:dim), rule, error)
         if (allocated(error)) return
         if (rule%cls == cell_cut) then
            sums%ncut = sums%ncut + 1
            if (rule%nsplit > 0) sums%nsplit = sums%nsplit + 1
            sums%nunresolved = sums%nunresolved + rule%nunresolved
         end if
         do i = 1, rule%nvol
            w = rule%vol_w(i)
            sums%m(1) = sums%m(1) + w
            sums%m(3) = sums%m(3) + w*rule%vol_x(1, i)
            sums%m(4) = sums%m(4) + w*rule%vol_x(1, i)**2
            sums%wmin = min(sums%wmin, w)
            sums%finite = sums%finite .and. ieee_is_finite(w) .and. all(ieee_is_finite(rule%vol_x(:, i)))
         end do
         sums%nsurf = sums%nsurf + rule%nsurf
         do i = 1, rule%nsurf
            w = rule%surf_w(i)
            sums%m(2) = sums%m(2) + w
            sums%div = sums%div + w*dot_product(rule%surf_x(1:dim, i), rule%surf_n(1:dim, i))
            flux = flux + w*rule%surf_n(:, i)
            sums%wmin = min(sums%wmin, w)
            sums%finite = sums%finite .and. ieee_is_finite(w) .and. all(ieee_is_finite(rule%surf_x(:, i))) &
               & .and. all(ieee_is_finite(rule%surf_n(:, i)))
         end do
      end do
      sums%flux = norm2(flux)
   end subroutine integrate_grid

   !> Body number icase with its exact [measure, boundary measure, int x1, int x1^2].
   subroutine make_case(icase, body, name, exact, error)
      integer, intent(in) :: icase
      type(body_type), intent(out) :: body
      character(len=:), allocatable, intent(out) :: name
      real(wp), intent(out) :: exact(4)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s(5)
      integer :: ops(5), n, i
      real(wp) :: c(3), r1, r2, a, b, v, v2, h, zlo, zhi, o(2), rr

      ops = csg_intersect
      ops(1) = csg_add
      select case (icase)
      case (1)
         name = 'disk'
         c = [0.51_wp, 0.47_wp, 0.0_wp]
         r1 = 0.31_wp
         n = 1
         call new_disk(s(1), 'disk', c(1:2), r1, error)
         a = pi*r1**2
         exact = [a, 2.0_wp*pi*r1, a*c(1), a*c(1)**2 + pi*r1**4/4.0_wp]
      case (2)
         name = 'annulus'
         c = [0.51_wp, 0.47_wp, 0.0_wp]
         r1 = 0.4_wp
         r2 = 0.15_wp
         n = 2
         ops(2) = csg_subtract
         call new_disk(s(1), 'outer', c(1:2), r1, error)
         if (.not. allocated(error)) call new_disk(s(2), 'inner', c(1:2), r2, error)
         a = pi*(r1**2 - r2**2)
         exact = [a, 2.0_wp*pi*(r1 + r2), a*c(1), a*c(1)**2 + pi*(r1**4 - r2**4)/4.0_wp]
      case (3)
         name = 'ellipse with hole'
         c = [0.5_wp, 0.5_wp, 0.0_wp]
         a = 0.42_wp
         b = 0.27_wp
         o = [0.58_wp, 0.46_wp]
         rr = 0.1_wp
         n = 2
         ops(2) = csg_subtract
         call new_ellipse(s(1), 'ellipse', c(1:2), [a, b], error)
         if (.not. allocated(error)) call new_disk(s(2), 'hole', o, rr, error)
         v = pi*a*b
         v2 = pi*rr**2
         exact = [v - v2, ellipse_perimeter(a, b) + 2.0_wp*pi*rr, v*c(1) - v2*o(1), &
            & v*(c(1)**2 + a*a/4.0_wp) - (v2*o(1)**2 + pi*rr**4/4.0_wp)]
      case (4)
         name = 'quarter annulus'
         c = [0.25_wp, 0.25_wp, 0.0_wp]
         r1 = 0.7_wp
         r2 = 0.3_wp
         n = 4
         ops(2) = csg_subtract
         call new_disk(s(1), 'outer', c(1:2), r1, error)
         if (.not. allocated(error)) call new_disk(s(2), 'inner', c(1:2), r2, error)
         if (.not. allocated(error)) call new_halfspace(s(3), 'sym_x', c(1:2), [-1.0_wp, 0.0_wp], error)
         if (.not. allocated(error)) call new_halfspace(s(4), 'sym_y', c(1:2), [0.0_wp, -1.0_wp], error)
         a = pi*(r1**2 - r2**2)/4.0_wp
         v = (r1**3 - r2**3)/3.0_wp
         v2 = pi*(r1**4 - r2**4)/16.0_wp
         exact = [a, pi*(r1 + r2)/2.0_wp + 2.0_wp*(r1 - r2), v + c(1)*a, v2 + 2.0_wp*c(1)*v + c(1)**2*a]
      case (5)
         name = 'sphere'
         c = [0.51_wp, 0.47_wp, 0.49_wp]
         r1 = 0.33_wp
         n = 1
         call new_sphere(s(1), 'sphere', c, r1, error)
         v = 4.0_wp*pi*r1**3/3.0_wp
         exact = [v, 4.0_wp*pi*r1**2, v*c(1), v*c(1)**2 + 4.0_wp*pi*r1**5/15.0_wp]
      case (6, 10)
         name = 'shell octant'
         c = [0.25_wp, 0.25_wp, 0.25_wp]
         if (icase == 10) then
            ! symmetry planes through the sphere centres, cutting cells
            name = 'shell octant off grid'
            c = [0.2537_wp, 0.2419_wp, 0.2613_wp]
         end if
         r1 = 0.7_wp
         r2 = 0.3_wp
         n = 5
         ops(2) = csg_subtract
         call new_sphere(s(1), 'outer', c, r1, error)
         if (.not. allocated(error)) call new_sphere(s(2), 'inner', c, r2, error)
         if (.not. allocated(error)) call new_halfspace(s(3), 'sym_x', c, [-1.0_wp, 0.0_wp, 0.0_wp], error)
         if (.not. allocated(error)) call new_halfspace(s(4), 'sym_y', c, [0.0_wp, -1.0_wp, 0.0_wp], error)
         if (.not. allocated(error)) call new_halfspace(s(5), 'sym_z', c, [0.0_wp, 0.0_wp, -1.0_wp], error)
         v = pi*(r1**3 - r2**3)/6.0_wp
         a = pi*(r1**4 - r2**4)/16.0_wp
         v2 = pi*(r1**5 - r2**5)/30.0_wp
         exact = [v, pi*(r1**2 + r2**2)/2.0_wp + 0.75_wp*pi*(r1**2 - r2**2), a + c(1)*v, &
            & v2 + 2.0_wp*c(1)*a + c(1)**2*v]
      case (7)
         name = 'cube with void'
         c = [0.52_wp, 0.48_wp, 0.5_wp]
         r1 = 0.3_wp
         n = 2
         ops(2) = csg_subtract
         call new_box(s(1), 'cube', [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], error)
         if (.not. allocated(error)) call new_sphere(s(2), 'void', c, r1, error)
         v = 4.0_wp*pi*r1**3/3.0_wp
         exact = [1.0_wp - v, 6.0_wp + 4.0_wp*pi*r1**2, 0.5_wp - v*c(1), &
            & 1.0_wp/3.0_wp - (v*c(1)**2 + 4.0_wp*pi*r1**5/15.0_wp)]
      case default
         c = [0.5_wp, 0.47_wp, 0.0_wp]
         r1 = 0.3_wp
         if (icase == 8) then
            name = 'capped cylinder on grid'
            zlo = 0.25_wp
            zhi = 0.75_wp
         else
            name = 'capped cylinder off grid'
            zlo = 0.2131_wp
            zhi = 0.7731_wp
         end if
         n = 3
         call new_cylinder(s(1), 'mantle', c, [0.0_wp, 0.0_wp, 1.0_wp], r1, error)
         if (.not. allocated(error)) &
            & call new_halfspace(s(2), 'bottom', [0.0_wp, 0.0_wp, zlo], [0.0_wp, 0.0_wp, -1.0_wp], error)
         if (.not. allocated(error)) &
            & call new_halfspace(s(3), 'top', [0.0_wp, 0.0_wp, zhi], [0.0_wp, 0.0_wp, 1.0_wp], error)
         h = zhi - zlo
         v = pi*r1**2*h
         exact = [v, 2.0_wp*pi*r1*h + 2.0_wp*pi*r1**2, v*c(1), h*(pi*r1**2*c(1)**2 + pi*r1**4/4.0_wp)]
      end select
      if (allocated(error)) return
      call new_body(body, name)
      do i = 1, n
         call body%add_shape(ops(i), s(i), error)
         if (allocated(error)) return
      end do
   end subroutine make_case

   !> Perimeter of an ellipse by the arithmetic-geometric mean (quadratic
   !> convergence; checked against the circle and the series to 1e-16).
   pure real(wp) function ellipse_perimeter(a, b) result(p)
      real(wp), intent(in) :: a, b
      real(wp) :: x, y, s, t, pw
      integer :: it
      x = a
      y = b
      s = 0.5_wp*(a*a + b*b)
      pw = 1.0_wp
      do it = 1, 20
         t = 0.5_wp*(x - y)
         s = s - pw*t*t
         pw = 2.0_wp*pw
         t = sqrt(x*y)
         x = 0.5_wp*(x + y)
         y = t
         if (abs(x - y) <= 1.0e-17_wp*x) exit
      end do
      p = 2.0_wp*pi*s/x
   end function ellipse_perimeter

   !> Every shape kind, aligned and oblique; `exact` marks the kinds whose
   !> gradient range is documented as exact.
   subroutine shape_catalogue(shapes, exact, error)
      type(shape_type), intent(out) :: shapes(9)
      logical, intent(out) :: exact(9)
      type(error_type), allocatable, intent(out) :: error
      call new_disk(shapes(1), 'disk', [0.1_wp, -0.2_wp], 0.7_wp, error)
      if (allocated(error)) return
      call new_sphere(shapes(2), 'sphere', [0.1_wp, -0.2_wp, 0.3_wp], 0.7_wp, error)
      if (allocated(error)) return
      call new_ellipse(shapes(3), 'ellipse', [0.1_wp, -0.2_wp], [0.9_wp, 0.4_wp], error)
      if (allocated(error)) return
      call new_ellipsoid(shapes(4), 'ellipsoid', [0.1_wp, -0.2_wp, 0.3_wp], [0.9_wp, 0.4_wp, 0.6_wp], error)
      if (allocated(error)) return
      call new_halfspace(shapes(5), 'halfspace', [0.1_wp, -0.2_wp, 0.3_wp], [1.0_wp, -2.0_wp, 0.5_wp], error)
      if (allocated(error)) return
      call new_box(shapes(6), 'box', [-0.5_wp, -0.4_wp], [0.6_wp, 0.3_wp], error)
      if (allocated(error)) return
      call new_cylinder(shapes(7), 'cylinder', [0.1_wp, -0.2_wp, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], 0.5_wp, error)
      if (allocated(error)) return
      call new_cylinder(shapes(8), 'oblique_cylinder', [0.1_wp, -0.2_wp, 0.0_wp], [1.0_wp, 2.0_wp, 2.0_wp], &
         & 0.5_wp, error)
      if (allocated(error)) return
      call new_ellipse(shapes(9), 'round_ellipse', [0.0_wp, 0.0_wp], [0.5_wp, 0.5_wp], error)
      if (allocated(error)) return
      exact = [.true., .true., .true., .true., .true., .false., .true., .false., .true.]
   end subroutine shape_catalogue

   !> Three uniform numbers in [0, 1) from a 64-bit LCG (deterministic).
   subroutine random3(seed, u)
      integer(i8), intent(inout) :: seed
      real(wp), intent(out) :: u(3)
      integer :: i
      do i = 1, 3
         seed = seed*6364136223846793005_i8 + 1442695040888963407_i8
         u(i) = real(ishft(seed, -11), wp)/9007199254740992.0_wp
      end do
   end subroutine random3

end module sprc_test_quadrature
