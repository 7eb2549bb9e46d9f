!> Tests of the geometry area: implicit shapes, their certified ranges, CSG
!> bodies, box classification and boundary identification.
!>
!> The code classifies boxes from analytic ranges; these tests check it
!> independently by sampling lattices of points in each box (a classification
!> must never contradict a sample), by Lipschitz bounds (a certified exact
!> range must be attained within the lattice resolution), by exact areas and
!> volumes (inside measure <= true measure <= inside + cut measure), by finite
!> differences, and by hand-built degenerate configurations.
module sprc_test_geometry
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input
   use sprc_geometry_region, only: cell_outside, cell_inside, cell_cut
   use sprc_geometry_shape, only: shape_type, shape_disk, shape_sphere, shape_ellipse, shape_ellipsoid, &
      & shape_box, shape_halfspace, shape_cylinder, new_disk, new_sphere, new_ellipse, new_ellipsoid, &
      & new_box, new_halfspace, new_cylinder, shape_kind_name, shape_kind_from_name
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect, csg_op_name, &
      & csg_op_from_name, check_body_in_box
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_geometry

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Sampling slack for brute-force checks, relative to the coordinate
   !> magnitude: phi is evaluated with a few roundings of quantities of that
   !> size (~1e-16 each), and the classification snaps a few ulps; 1e-13 is
   !> far above both and far below every real offset the tests build (>= 1e-12).
   real(wp), parameter :: sample_slack = 1.0e-13_wp
   !> Number of shapes in the test catalogue (every kind, oblique and aligned).
   integer, parameter :: ncatalogue = 12

contains

   subroutine collect_geometry(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('phi_gradient_fd', test_phi_gradient_fd), &
         new_unittest('shape_normals_outward', test_shape_normals), &
         new_unittest('phi_range_certified_and_tight', test_phi_range), &
         new_unittest('classify_random_boxes', test_classify_random), &
         new_unittest('quarter_annulus_grid', test_quarter_annulus_grid), &
         new_unittest('quarter_annulus_aligned_planes', test_quarter_annulus_aligned), &
         new_unittest('active_shapes_masking', test_active_shapes), &
         new_unittest('boundary_through_nodes', test_through_nodes), &
         new_unittest('offset_1e-12_from_node', test_offset_from_node), &
         new_unittest('tangent_zero_measure', test_tangent), &
         new_unittest('body_inside_one_cell', test_small_body), &
         new_unittest('halfspace_on_grid_plane', test_halfspace_on_plane), &
         new_unittest('snapping_roundoff_vs_offset', test_snapping), &
         new_unittest('shell_octant_3d', test_shell_octant), &
         new_unittest('cube_with_void_3d', test_cube_void), &
         new_unittest('capped_cylinder_3d', test_capped_cylinder), &
         new_unittest('sphere_3d_through_nodes', test_sphere_nodes), &
         new_unittest('csg_corners', test_csg_corners), &
         new_unittest('body_normals_outward', test_body_normals), &
         new_unittest('kind_and_op_names', test_names), &
         new_unittest('shape_bounds_hold_and_tight', test_shape_bounds), &
         new_unittest('piece_outside_the_box', test_piece_outside_box), &
         new_unittest('shape_constructor_errors', test_constructor_errors), &
         new_unittest('body_errors', test_body_errors) &
         ]
   end subroutine collect_geometry

   ! ------------------------------------------------------------ shapes

   !> Finite differences: (phi(x+h e) - phi(x-h e))/(2h) has truncation error
   !> h^2/6 |phi'''| <= 1e-10 * (1/d^2) for the curved kinds (d = distance from
   !> a center or axis, kept >= 0.1), and round-off ~ eps |phi| / h ~ 1e-11,
   !> so 1e-7 is safe. Points within 10 h of a kink (box edges) are skipped.
   subroutine test_phi_gradient_fd(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shapes(ncatalogue)
      real(wp), parameter :: h = 1.0e-5_wp
      real(wp) :: x(3), e(3), g(3), fd
      integer :: s, k, i, d, ntested
      integer(i8) :: seed

      call catalogue(shapes, error)
      if (allocated(error)) return
      seed = 4711_i8
      do s = 1, size(shapes)
         d = shapes(s)%dim
         ntested = 0
         do k = 1, 60
            do i = 1, d
               x(i) = 8.0_wp*uniform(seed) - 4.0_wp
            end do
            if (near_singular(shapes(s), x(1:d), 10.0_wp*h)) cycle
            g(1:d) = shapes(s)%gradient(x(1:d))
            do i = 1, d
               e = 0.0_wp
               e(i) = h
               fd = (shapes(s)%phi(x(1:d) + e(1:d)) - shapes(s)%phi(x(1:d) - e(1:d)))/(2.0_wp*h)
               call check(error, g(i), fd, 1.0e-7_wp, 'gradient vs FD, '//shapes(s)%name)
               if (allocated(error)) return
            end do
            if (shapes(s)%kind /= shape_ellipse .and. shapes(s)%kind /= shape_ellipsoid) then
               call check(error, norm2(g(1:d)), 1.0_wp, 1.0e-14_wp, 'unit gradient, '//shapes(s)%name)
               if (allocated(error)) return
            end if
            ntested = ntested + 1
         end do
         call check(error, ntested >= 30, 'too few FD points for '//shapes(s)%name)
         if (allocated(error)) return
      end do
   end subroutine test_phi_gradient_fd

   !> On each shape's surface phi ~ 0 and the gradient points outwards: phi
   !> changes sign from - to + along it over +-1e-6 (curvature terms are
   !> ~1e-12, far below the 1e-6 change).
   subroutine test_shape_normals(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shapes(ncatalogue)
      real(wp), parameter :: delta = 1.0e-6_wp
      real(wp) :: x(3), n(3)
      integer :: s, k, d
      integer(i8) :: seed

      call catalogue(shapes, error)
      if (allocated(error)) return
      seed = 99_i8
      do s = 1, size(shapes)
         d = shapes(s)%dim
         do k = 1, 40
            x(1:d) = surface_point(shapes(s), seed, 4.0_wp)
            call check(error, shapes(s)%phi(x(1:d)), 0.0_wp, 1.0e-14_wp, 'surface point, '//shapes(s)%name)
            if (allocated(error)) return
            n(1:d) = shapes(s)%gradient(x(1:d))
            n(1:d) = n(1:d)/norm2(n(1:d))
            call check(error, shapes(s)%phi(x(1:d) + delta*n(1:d)) > 0.5_wp*delta*minimum_slope(shapes(s)) .and. &
               & shapes(s)%phi(x(1:d) - delta*n(1:d)) < -0.5_wp*delta*minimum_slope(shapes(s)), &
               & 'normal not outward, '//shapes(s)%name)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_shape_normals

   !> phi_range on 2000 random boxes per shape (some flat in one direction):
   !> no lattice sample lies outside [fmin, fmax] (beyond round-off, 64 ulps
   !> of the coordinate magnitude), and since every range is exact, the
   !> lattice's extremes come within L * (half a lattice cell diagonal) of it,
   !> L a Lipschitz bound of phi on the box. A loose but valid bound fails.
   !> phi is convex for every kind, so fmax is also checked against the
   !> largest corner value to rounding.
   subroutine test_phi_range(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shapes(ncatalogue)
      real(wp) :: lo(3), hi(3), x(3), fmin, fmax, smin, smax, f, rtol, reach, spacing(3), cmax
      integer :: s, k, j, d, m, nsample
      integer(i8) :: seed
      character(len=200) :: buf

      call catalogue(shapes, error)
      if (allocated(error)) return
      seed = 2024_i8
      do s = 1, size(shapes)
         d = shapes(s)%dim
         m = merge(9, 6, d == 2)
         nsample = m**d
         do k = 1, 2000
            call random_box(seed, d, 4.0_wp, lo, hi)
            call shapes(s)%phi_range(lo(1:d), hi(1:d), fmin, fmax)
            smin = huge(1.0_wp)
            smax = -huge(1.0_wp)
            do j = 0, nsample - 1
               x(1:d) = lattice_point(lo(1:d), hi(1:d), m, j)
               f = shapes(s)%phi(x(1:d))
               smin = min(smin, f)
               smax = max(smax, f)
            end do
            rtol = 64.0_wp*epsilon(1.0_wp)*(max(maxval(abs(lo(1:d))), maxval(abs(hi(1:d)))) + shapes(s)%scale)
            spacing(1:d) = (hi(1:d) - lo(1:d))/real(m - 1, wp)
            reach = lipschitz(shapes(s), lo(1:d), hi(1:d))*0.5_wp*norm2(spacing(1:d)) + rtol
            write (buf, '(a," box ",6es11.3," range ",2es12.4," samples ",2es12.4)') shapes(s)%name, &
               & lo(1:d), hi(1:d), fmin, fmax, smin, smax
            call check(error, smin >= fmin - rtol .and. smax <= fmax + rtol, 'not an enclosure: '//trim(buf))
            if (allocated(error)) return
            call check(error, smin <= fmin + reach .and. smax >= fmax - reach, 'not tight: '//trim(buf))
            if (allocated(error)) return
            ! every phi is convex, so its maximum is attained at a corner: to rounding
            cmax = -huge(1.0_wp)
            do j = 0, 2**d - 1
               x(1:d) = lattice_point(lo(1:d), hi(1:d), 2, j)
               cmax = max(cmax, shapes(s)%phi(x(1:d)))
            end do
            call check(error, abs(cmax - fmax) <= rtol, 'fmax not attained at a corner: '//trim(buf))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_phi_range

   ! ------------------------------------------------------------ classification

   !> 2000 random boxes per body; each class is checked against a lattice of
   !> samples (m^dim points). For bodies built only by subtraction and
   !> intersection of shapes whose product structure makes 3-valued logic
   !> exact on boxes ("tight"), a cut box must also reach the boundary.
   subroutine test_classify_random(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: bodies(6)
      real(wp) :: lo(3), hi(3), extent(6), middle(6)
      integer :: b, k, d, ncls(0:2)
      integer(i8) :: seed

      call quarter_annulus(bodies(1), error)
      if (allocated(error)) return
      call mixed_2d(bodies(2), error)
      if (allocated(error)) return
      call shell_octant(bodies(3), error)
      if (allocated(error)) return
      call cube_void(bodies(4), error)
      if (allocated(error)) return
      call capped_cylinder(bodies(5), [1.0_wp, 2.0_wp, 2.0_wp], error)
      if (allocated(error)) return
      call mixed_3d(bodies(6), error)
      if (allocated(error)) return
      ! the quarter bodies live in the positive quadrant/octant: boxes are centred there
      extent = [13.0_wp, 4.0_wp, 13.0_wp, 1.5_wp, 2.0_wp, 2.0_wp]
      middle = [12.0_wp, 0.0_wp, 12.0_wp, 0.0_wp, 0.0_wp, 0.5_wp]
      seed = 777_i8
      do b = 1, size(bodies)
         d = bodies(b)%dim
         ncls = 0
         do k = 1, 2000
            call random_box(seed, d, extent(b), lo, hi)
            lo = lo + middle(b)
            hi = hi + middle(b)
            call check_box(error, bodies(b), lo(1:d), hi(1:d), merge(9, 5, d == 2), .false., &
               & sample_slack*(extent(b) + middle(b)), ncls)
            if (allocated(error)) return
         end do
         ! the boxes must exercise all three classes, or the test proves little
         call check(error, all(ncls > 50), 'random boxes of body '//bodies(b)%name//' miss a class')
         if (allocated(error)) return
      end do
   end subroutine test_classify_random

   !> The SCENE.md quarter annulus on the scene's grid (box_min 0, size 25,
   !> level 6) and on a grid over [-25, 25]^2 whose lines include x = 0 and
   !> y = 0: every cell agrees with a 17 x 17 lattice of samples, every cut
   !> cell reaches the boundary, and the area pi (20^2 - 5^2)/4 lies between
   !> the inside area and the inside + cut area.
   subroutine test_quarter_annulus_grid(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      real(wp) :: vin, vcut, area
      integer :: ncls(0:2)

      call quarter_annulus(body, error)
      if (allocated(error)) return
      area = pi*(400.0_wp - 25.0_wp)/4.0_wp
      call check_grid(error, body, [0.0_wp, 0.0_wp], 25.0_wp/64.0_wp, 64, 17, 25.0_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= area .and. area <= vin + vcut, 'area bounds, level 6')
      if (allocated(error)) return
      ! A ring of width 15 on h = 25/64: the cut band is about the two arcs' length times ~1.3 h.
      call check(error, vcut < 0.1_wp*area, 'cut area too large on level 6')
      if (allocated(error)) return
      call check_grid(error, body, [-25.0_wp, -25.0_wp], 50.0_wp/16.0_wp, 16, 17, 25.0_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= area .and. area <= vin + vcut, 'area bounds, 16 x 16 over [-25, 25]^2')
   end subroutine test_quarter_annulus_grid

   !> Cells touching x = 0 or y = 0 from the body side have the class of the
   !> full annulus (the symmetry planes never cut); cells on the other side
   !> are outside; the halfspaces are never active on these grids.
   subroutine test_quarter_annulus_aligned(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: quarter, ring
      real(wp) :: lo(2), hi(2), h
      integer :: i, j, n, cls, list(4), nlist, grid, ntouch, i0
      real(wp) :: origin(2)

      call quarter_annulus(quarter, error)
      if (allocated(error)) return
      call annulus(ring, error)
      if (allocated(error)) return
      do grid = 1, 2
         if (grid == 1) then
            n = 16; h = 50.0_wp/16.0_wp; origin = -25.0_wp; i0 = 8
         else
            n = 64; h = 25.0_wp/64.0_wp; origin = 0.0_wp; i0 = 0
         end if
         ntouch = 0
         do j = 0, n - 1
            do i = 0, n - 1
               lo = origin + h*[real(i, wp), real(j, wp)]
               hi = lo + h
               cls = quarter%classify_box(lo, hi)
               call quarter%active_shapes(lo, hi, list, nlist)
               call check(error, .not. any(list(1:nlist) >= 3), 'symmetry plane active in a grid cell')
               if (allocated(error)) return
               ! cell index i0 - 1 ends on a symmetry plane, cell i0 starts on it
               if (i == i0 - 1 .or. j == i0 - 1) then
                  call check(error, cls, cell_outside, 'cell behind a symmetry plane')
                  if (allocated(error)) return
                  ntouch = ntouch + 1
               else if ((i == i0 .or. j == i0) .and. min(i, j) >= i0) then
                  call check(error, cls, ring%classify_box(lo, hi), 'cell on a symmetry plane vs annulus')
                  if (allocated(error)) return
                  ntouch = ntouch + 1
               end if
            end do
         end do
         call check(error, ntouch >= n, 'too few cells touching the symmetry planes')
         if (allocated(error)) return
      end do
      ! a cell on x = 0 in the ring, away from both arcs, is inside
      call check(error, quarter%classify_box([0.0_wp, 10.0_wp], [h, 10.0_wp + h]), cell_inside, 'inside on x = 0')
   end subroutine test_quarter_annulus_aligned

   !> Which shapes matter in a box: the masking rule of 3-valued CSG.
   subroutine test_active_shapes(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      integer :: list(4), n

      call quarter_annulus(body, error)
      if (allocated(error)) return
      ! across the outer arc, away from the planes: only 'outer'
      call body%active_shapes([13.0_wp, 13.0_wp], [15.0_wp, 15.0_wp], list, n)
      call check_list(error, list(1:n), [1], 'outer arc')
      if (allocated(error)) return
      ! around the origin: inner disk and both planes matter
      call body%active_shapes([-1.0_wp, -1.0_wp], [6.0_wp, 6.0_wp], list, n)
      call check_list(error, list(1:n), [2, 3, 4], 'around the origin')
      if (allocated(error)) return
      ! the inner circle crosses the box but x < 0 is already outside: masked
      call body%active_shapes([-6.0_wp, 1.0_wp], [-4.0_wp, 2.0_wp], list, n)
      call check_list(error, list(1:n), [integer ::], 'inner arc behind sym_x')
      if (allocated(error)) return
      call check(error, body%classify_box([-6.0_wp, 1.0_wp], [-4.0_wp, 2.0_wp]), cell_outside, 'behind sym_x')
      if (allocated(error)) return
      ! sym_y crosses the box but the box is inside the hole: masked
      call body%active_shapes([1.0_wp, -1.0_wp], [3.0_wp, 1.0_wp], list, n)
      call check_list(error, list(1:n), [integer ::], 'sym_y inside the hole')
      if (allocated(error)) return
      call check(error, body%classify_box([1.0_wp, -1.0_wp], [3.0_wp, 1.0_wp]), cell_outside, 'inside the hole')
      if (allocated(error)) return
      ! at the corner (20, 0): outer and sym_y
      call body%active_shapes([19.0_wp, -1.0_wp], [21.0_wp, 1.0_wp], list, n)
      call check_list(error, list(1:n), [1, 4], 'corner (20, 0)')
   end subroutine test_active_shapes

   !> Circle x^2 + y^2 = 25 through the nodes (3,4), (4,3), (5,0), (0,5) of
   !> the unit grid: a cell touching the circle only at a node from outside
   !> is outside, from inside is inside; all cells agree with samples.
   subroutine test_through_nodes(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: disk
      real(wp) :: vin, vcut
      integer :: ncls(0:2)

      call new_body(body, 'disk')
      call new_disk(disk, 'rim', [0.0_wp, 0.0_wp], 5.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, disk, error)
      if (allocated(error)) return
      call check(error, body%classify_box([4.0_wp, 3.0_wp], [5.0_wp, 4.0_wp]), cell_outside, 'node (4,3) from outside')
      if (allocated(error)) return
      call check(error, body%classify_box([3.0_wp, 2.0_wp], [4.0_wp, 3.0_wp]), cell_inside, 'node (4,3) from inside')
      if (allocated(error)) return
      call check(error, body%classify_box([3.0_wp, 3.0_wp], [4.0_wp, 4.0_wp]), cell_cut, 'chord (3,4)-(4,3)')
      if (allocated(error)) return
      call check(error, body%classify_box([5.0_wp, -1.0_wp], [6.0_wp, 0.0_wp]), cell_outside, 'node (5,0) outside')
      if (allocated(error)) return
      call check(error, body%classify_box([4.0_wp, 0.0_wp], [5.0_wp, 1.0_wp]), cell_cut, 'edge at (5,0)')
      if (allocated(error)) return
      call check_grid(error, body, [-6.0_wp, -6.0_wp], 1.0_wp, 12, 21, 6.0_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= 25.0_wp*pi .and. 25.0_wp*pi <= vin + vcut, 'disk area bounds')
   end subroutine test_through_nodes

   !> Radius 5 (1 +- 1e-12): the circle passes 5e-12 (relative 1e-12 of the
   !> unit cell) from the node (4,3). The sliver cell becomes cut, with both
   !> classes found by sampling at the node; the other side stays decided.
   subroutine test_offset_from_node(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: big, small
      type(shape_type) :: disk

      call new_body(big, 'big')
      call new_disk(disk, 'rim', [0.0_wp, 0.0_wp], 5.0_wp*(1.0_wp + 1.0e-12_wp), error)
      if (allocated(error)) return
      call big%add_shape(csg_add, disk, error)
      if (allocated(error)) return
      call check(error, big%classify_box([4.0_wp, 3.0_wp], [5.0_wp, 4.0_wp]), cell_cut, 'r = 5 + 5e-12, outer cell')
      if (allocated(error)) return
      call check(error, big%phi([4.0_wp, 3.0_wp]) < 0.0_wp .and. big%phi([5.0_wp, 4.0_wp]) > 0.0_wp, &
         & 'both classes sampled in the sliver cell')
      if (allocated(error)) return
      call check(error, big%classify_box([3.0_wp, 2.0_wp], [4.0_wp, 3.0_wp]), cell_inside, 'r = 5 + 5e-12, inner cell')
      if (allocated(error)) return

      call new_body(small, 'small')
      call new_disk(disk, 'rim', [0.0_wp, 0.0_wp], 5.0_wp*(1.0_wp - 1.0e-12_wp), error)
      if (allocated(error)) return
      call small%add_shape(csg_add, disk, error)
      if (allocated(error)) return
      call check(error, small%classify_box([3.0_wp, 2.0_wp], [4.0_wp, 3.0_wp]), cell_cut, 'r = 5 - 5e-12, inner cell')
      if (allocated(error)) return
      call check(error, small%phi([4.0_wp, 3.0_wp]) > 0.0_wp .and. small%phi([3.0_wp, 2.0_wp]) < 0.0_wp, &
         & 'both classes sampled in the inner cell')
      if (allocated(error)) return
      call check(error, small%classify_box([4.0_wp, 3.0_wp], [5.0_wp, 4.0_wp]), cell_outside, 'r = 5 - 5e-12, outer')
   end subroutine test_offset_from_node

   !> Contact of zero measure is not a cut: circle, ellipse, sphere and
   !> cylinder tangent to a cell edge or face from outside.
   subroutine test_tangent(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      type(body_type) :: body

      call new_disk(s, 'c', [0.5_wp, -1.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp]), cell_outside, 'circle tangent to edge')
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, -1.0_wp], [1.0_wp, 0.0_wp]), cell_cut, 'circle below the edge')
      if (allocated(error)) return
      ! tangent at a corner's edge from the side: circle centred (2.5, 0.5), r 0.5
      call new_disk(s, 'c', [2.5_wp, 0.5_wp], 0.5_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([1.0_wp, 0.0_wp], [2.0_wp, 1.0_wp]), cell_outside, 'circle tangent, x side')
      if (allocated(error)) return
      call check(error, body%classify_box([2.0_wp, 0.0_wp], [3.0_wp, 1.0_wp]), cell_cut, 'circle inside cell')
      if (allocated(error)) return
      call new_ellipse(s, 'e', [0.0_wp, 0.0_wp], [3.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([3.0_wp, -1.0_wp], [4.0_wp, 1.0_wp]), cell_outside, 'ellipse tangent')
      if (allocated(error)) return
      call check(error, body%classify_box([-1.0_wp, 1.0_wp], [1.0_wp, 2.0_wp]), cell_outside, 'ellipse tangent, y')
      if (allocated(error)) return
      call new_sphere(s, 's', [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([1.0_wp, -0.5_wp, -0.5_wp], [2.0_wp, 0.5_wp, 0.5_wp]), cell_outside, &
         & 'sphere tangent to a face')
      if (allocated(error)) return
      ! the cylinder's surface contains the cell edge x = 1, y = 0: contact along a line
      call new_cylinder(s, 'cyl', [0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 2.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([1.0_wp, 0.0_wp, 0.0_wp], [2.0_wp, 1.0_wp, 1.0_wp]), cell_outside, &
         & 'cylinder tangent along an edge')
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp]), cell_cut, &
         & 'cylinder through the cell')
      if (allocated(error)) return
      ! oblique axis (1, 1, 0) through the origin, radius 0.5: the face z = 0.5 of the box
      ! [0, 1]^2 x [0.5, 1] is tangent along the segment x = y (line-box distance 0.5 exactly)
      call new_cylinder(s, 'tilted', [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 0.0_wp], 0.5_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp, 0.5_wp], [1.0_wp, 1.0_wp, 1.0_wp]), cell_outside, &
         & 'oblique cylinder tangent to a face')
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp, 0.4999_wp], [1.0_wp, 1.0_wp, 1.0_wp]), cell_cut, &
         & 'oblique cylinder through the face')
      if (allocated(error)) return
   end subroutine test_tangent

   !> A body smaller than a cell is cut in its cell and outside elsewhere.
   subroutine test_small_body(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      type(body_type) :: body

      call new_disk(s, 'speck', [0.5_wp, 0.5_wp], 0.1_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp]), cell_cut, 'disk in one cell')
      if (allocated(error)) return
      call check(error, body%classify_box([1.0_wp, 0.0_wp], [2.0_wp, 1.0_wp]), cell_outside, 'neighbour cell')
      if (allocated(error)) return
      call new_sphere(s, 'dust', [0.3_wp, 0.7_wp, 0.2_wp], 1.0e-6_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp]), cell_cut, &
         & 'sphere of radius 1e-6 in one cell')
      if (allocated(error)) return
      ! a tiny box shape strictly inside a cell (no lattice sample may see it: analytic, not sampled)
      call new_box(s, 'chip', [0.31_wp, 0.32_wp, 0.33_wp], [0.31_wp + 1.0e-9_wp, 0.33_wp, 0.34_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp]), cell_cut, &
         & 'thin box in one cell')
   end subroutine test_small_body

   !> A halfspace (or a box) whose faces are grid planes cuts no cell; the
   !> normal's length and the point's position along the plane are irrelevant.
   subroutine test_halfspace_on_plane(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      type(body_type) :: body
      real(wp) :: lo(2), hi(2)
      integer :: i, j, cls

      call new_halfspace(s, 'wall', [2.0_wp, 7.3_wp], [3.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      do j = -3, 2
         do i = -3, 5
            lo = [real(i, wp), real(j, wp)]
            hi = lo + 1.0_wp
            cls = body%classify_box(lo, hi)
            call check(error, cls, merge(cell_inside, cell_outside, hi(1) <= 2.0_wp), 'halfspace x <= 2 on unit grid')
            if (allocated(error)) return
         end do
      end do
      call new_box(s, 'block', [-1.0_wp, 0.0_wp], [2.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      do j = -3, 2
         do i = -3, 5
            lo = [real(i, wp), real(j, wp)]
            hi = lo + 1.0_wp
            cls = body%classify_box(lo, hi)
            call check(error, cls, merge(cell_inside, cell_outside, all(lo >= [-1.0_wp, 0.0_wp]) .and. &
               & all(hi <= [2.0_wp, 1.0_wp])), 'box shape on unit grid')
            if (allocated(error)) return
         end do
      end do
      ! the same plane 2e-12 (relative 1e-12 of the coordinates) to the right cuts the next column
      call new_halfspace(s, 'wall', [2.0_wp + 2.0e-12_wp, 0.0_wp], [1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([2.0_wp, 0.0_wp], [3.0_wp, 1.0_wp]), cell_cut, 'plane 2e-12 off')
   end subroutine test_halfspace_on_plane

   !> Round-off of a few ulps (0.1 + 0.2 vs 0.3) snaps, a 1e-12 offset does not.
   subroutine test_snapping(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      type(body_type) :: body
      real(wp) :: plane

      plane = 0.1_wp
      plane = plane + 0.2_wp
      call check(error, abs(plane - 0.3_wp) > 0.0_wp, 'test premise: 0.1 + 0.2 /= 0.3 in binary')
      if (allocated(error)) return
      call new_halfspace(s, 'wall', [plane, 0.0_wp], [1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.3_wp, 0.0_wp], [1.0_wp, 1.0_wp]), cell_outside, 'ulps sliver snapped')
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 0.0_wp], [0.3_wp, 1.0_wp]), cell_inside, 'other side inside')
      if (allocated(error)) return
      call new_halfspace(s, 'wall', [0.3_wp + 0.7e-12_wp, 0.0_wp], [1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([0.3_wp, 0.0_wp], [1.0_wp, 1.0_wp]), cell_cut, '1e-12 of the cell is a cut')
   end subroutine test_snapping

   !> Octant of a spherical shell (R = 20, r = 5) with three symmetry planes
   !> on a 16^3 grid over [-25, 25]^3: samples, volume bounds, and the planes
   !> never cut (cells on them have the full shell's class).
   subroutine test_shell_octant(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: octant, shell
      real(wp) :: vin, vcut, volume, lo(3), hi(3), h
      integer :: ncls(0:2), i, j, k, n, list(5), nlist, cls

      call shell_octant(octant, error)
      if (allocated(error)) return
      call spherical_shell(shell, error)
      if (allocated(error)) return
      volume = (4.0_wp/3.0_wp)*pi*(20.0_wp**3 - 5.0_wp**3)/8.0_wp
      n = 16
      h = 50.0_wp/real(n, wp)
      call check_grid(error, octant, [-25.0_wp, -25.0_wp, -25.0_wp], h, n, 5, 25.0_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= volume .and. volume <= vin + vcut, 'shell octant volume bounds')
      if (allocated(error)) return
      do k = 0, n - 1
         do j = 0, n - 1
            do i = 0, n - 1
               lo = -25.0_wp + h*[real(i, wp), real(j, wp), real(k, wp)]
               hi = lo + h
               cls = octant%classify_box(lo, hi)
               call octant%active_shapes(lo, hi, list, nlist)
               call check(error, .not. any(list(1:nlist) >= 3), 'symmetry plane active in a 3D cell')
               if (allocated(error)) return
               ! cell index 7 ends on a symmetry plane, cell 8 starts on it
               if (any([i, j, k] == 7)) then
                  call check(error, cls, cell_outside, 'cell behind a symmetry plane (3D)')
               else if (any([i, j, k] == 8) .and. all([i, j, k] >= 8)) then
                  call check(error, cls, shell%classify_box(lo, hi), 'cell on a symmetry plane vs shell')
               end if
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_shell_octant

   !> Cube [-1, 1]^3 minus a ball of radius 0.5, grid h = 0.25 over
   !> [-1.5, 1.5]^3 (the cube's faces are grid planes): the only cut cells
   !> are those the sphere cuts.
   subroutine test_cube_void(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      real(wp) :: vin, vcut, volume, lo(3), hi(3), h, fmin, fmax
      integer :: ncls(0:2), i, j, k, n, sphere_cut

      call cube_void(body, error)
      if (allocated(error)) return
      volume = 8.0_wp - (4.0_wp/3.0_wp)*pi*0.125_wp
      n = 12
      h = 0.25_wp
      call check_grid(error, body, [-1.5_wp, -1.5_wp, -1.5_wp], h, n, 5, 1.5_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= volume .and. volume <= vin + vcut, 'cube with void volume bounds')
      if (allocated(error)) return
      sphere_cut = 0
      do k = 0, n - 1
         do j = 0, n - 1
            do i = 0, n - 1
               lo = -1.5_wp + h*[real(i, wp), real(j, wp), real(k, wp)]
               hi = lo + h
               call body%shapes(2)%phi_range(lo, hi, fmin, fmax)
               if (fmin < 0.0_wp .and. fmax > 0.0_wp) sphere_cut = sphere_cut + 1
            end do
         end do
      end do
      call check(error, ncls(cell_cut), sphere_cut, 'cut cells = cells cut by the void')
      if (allocated(error)) return
      call check(error, ncls(cell_inside) > 0 .and. ncls(cell_outside) > 0, 'both decided classes present')
   end subroutine test_cube_void

   !> Cylinder r = 1 along z capped by z <= 1 and z >= -1 on h = 0.25 over
   !> [-2, 2]^3: samples, volume 2 pi bracketed, caps never active.
   subroutine test_capped_cylinder(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      real(wp) :: vin, vcut, lo(3), hi(3), h
      integer :: ncls(0:2), i, j, k, n, list(3), nlist

      call capped_cylinder(body, [0.0_wp, 0.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      n = 16
      h = 0.25_wp
      call check_grid(error, body, [-2.0_wp, -2.0_wp, -2.0_wp], h, n, 5, 2.0_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= 2.0_wp*pi .and. 2.0_wp*pi <= vin + vcut, 'capped cylinder volume bounds')
      if (allocated(error)) return
      do k = 0, n - 1
         do j = 0, n - 1
            do i = 0, n - 1
               lo = -2.0_wp + h*[real(i, wp), real(j, wp), real(k, wp)]
               hi = lo + h
               call body%active_shapes(lo, hi, list, nlist)
               call check(error, .not. any(list(1:nlist) >= 2), 'cap active on an aligned grid')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_capped_cylinder

   !> Sphere x^2 + y^2 + z^2 = 9 through the nodes (1, 2, 2) etc. of the unit grid.
   subroutine test_sphere_nodes(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      type(body_type) :: body
      real(wp) :: vin, vcut
      integer :: ncls(0:2)

      call new_sphere(s, 'ball', [0.0_wp, 0.0_wp, 0.0_wp], 3.0_wp, error)
      if (allocated(error)) return
      call single(body, s, error)
      if (allocated(error)) return
      call check(error, body%classify_box([1.0_wp, 2.0_wp, 2.0_wp], [2.0_wp, 3.0_wp, 3.0_wp]), cell_outside, &
         & 'node (1,2,2) from outside')
      if (allocated(error)) return
      call check(error, body%classify_box([0.0_wp, 1.0_wp, 1.0_wp], [1.0_wp, 2.0_wp, 2.0_wp]), cell_inside, &
         & 'node (1,2,2) from inside')
      if (allocated(error)) return
      call check_grid(error, body, [-4.0_wp, -4.0_wp, -4.0_wp], 1.0_wp, 8, 9, 4.0_wp, vin, vcut, ncls)
      if (allocated(error)) return
      call check(error, vin <= 36.0_wp*pi .and. 36.0_wp*pi <= vin + vcut, 'ball volume bounds')
   end subroutine test_sphere_nodes

   ! ------------------------------------------------------------ boundary identification

   !> Points where two surfaces meet report both, in file order, each with
   !> its outward normal; interior points and masked surfaces report none.
   subroutine test_csg_corners(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      real(wp) :: n(3)
      real(wp), parameter :: tol = 1.0e-10_wp

      call quarter_annulus(body, error)
      if (allocated(error)) return
      call expect_surfaces(error, body, [5.0_wp, 0.0_wp], [2, 4], 'corner inner/sym_y')
      if (allocated(error)) return
      call expect_surfaces(error, body, [20.0_wp, 0.0_wp], [1, 4], 'corner outer/sym_y')
      if (allocated(error)) return
      call expect_surfaces(error, body, [0.0_wp, 5.0_wp], [2, 3], 'corner inner/sym_x')
      if (allocated(error)) return
      call expect_surfaces(error, body, [0.0_wp, 20.0_wp], [1, 3], 'corner outer/sym_x')
      if (allocated(error)) return
      call expect_surfaces(error, body, [12.0_wp, 0.0_wp], [4], 'sym_y alone')
      if (allocated(error)) return
      call expect_surfaces(error, body, 5.0_wp*[cos(0.3_wp), sin(0.3_wp)], [2], 'inner arc')
      if (allocated(error)) return
      call expect_surfaces(error, body, [0.0_wp, 0.0_wp], [integer ::], 'origin (in the hole)')
      if (allocated(error)) return
      call expect_surfaces(error, body, [-5.0_wp, 0.0_wp], [integer ::], 'inner circle behind sym_x')
      if (allocated(error)) return
      call expect_surfaces(error, body, [10.0_wp, 10.0_wp], [integer ::], 'interior point')
      if (allocated(error)) return
      call check(error, body%is_boundary_on([5.0_wp, 0.0_wp], 2, tol) .and. &
         & body%is_boundary_on([5.0_wp, 0.0_wp], 4, tol) .and. .not. body%is_boundary_on([5.0_wp, 0.0_wp], 1, tol), &
         & 'is_boundary_on at (5, 0)')
      if (allocated(error)) return
      call check(error, .not. body%is_boundary_on([0.0_wp, -3.0_wp], 3, tol), 'sym_x inside the hole is not boundary')
      if (allocated(error)) return
      call check(error, body%shapes(body%shape_index('inner'))%name, 'inner', 'names kept')
      if (allocated(error)) return
      call body%outward_normal([5.0_wp, 0.0_wp], 2, n(1:2))
      call check_vector(error, n(1:2), [-1.0_wp, 0.0_wp], 'normal of the subtracted inner disk at (5,0)')
      if (allocated(error)) return
      call body%outward_normal([5.0_wp, 0.0_wp], 4, n(1:2))
      call check_vector(error, n(1:2), [0.0_wp, -1.0_wp], 'normal of sym_y at (5,0)')
      if (allocated(error)) return
      call body%outward_normal([0.0_wp, 20.0_wp], 1, n(1:2))
      call check_vector(error, n(1:2), [0.0_wp, 1.0_wp], 'normal of outer at (0,20)')
      if (allocated(error)) return
      call body%outward_normal([0.0_wp, 20.0_wp], 3, n(1:2))
      call check_vector(error, n(1:2), [-1.0_wp, 0.0_wp], 'normal of sym_x at (0,20)')
      if (allocated(error)) return

      ! 3D rim of the capped cylinder: cylinder and top cap meet at (cos t, sin t, 1)
      call capped_cylinder(body, [0.0_wp, 0.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call expect_surfaces(error, body, [0.6_wp, 0.8_wp, 1.0_wp], [1, 2], 'rim of the capped cylinder')
      if (allocated(error)) return
      call body%outward_normal([0.6_wp, 0.8_wp, 1.0_wp], 1, n)
      call check_vector(error, n, [0.6_wp, 0.8_wp, 0.0_wp], 'cylinder normal at the rim')
      if (allocated(error)) return
      call body%outward_normal([0.6_wp, 0.8_wp, 1.0_wp], 2, n)
      call check_vector(error, n, [0.0_wp, 0.0_wp, 1.0_wp], 'cap normal at the rim')
      if (allocated(error)) return
      call body%outward_normal([0.6_wp, 0.8_wp, -1.0_wp], 3, n)
      call check_vector(error, n, [0.0_wp, 0.0_wp, -1.0_wp], 'bottom cap normal')
      if (allocated(error)) return
      call expect_surfaces(error, body, [0.6_wp, 0.8_wp, 1.5_wp], [integer ::], 'cylinder above the cap')
      if (allocated(error)) return

      ! a box's own edge is one surface; its normal follows the first-face rule
      call cube_void(body, error)
      if (allocated(error)) return
      call expect_surfaces(error, body, [1.0_wp, 1.0_wp, 0.3_wp], [1], 'box edge')
      if (allocated(error)) return
      call body%outward_normal([1.0_wp, 1.0_wp, 0.3_wp], 1, n)
      call check_vector(error, n, [1.0_wp, 0.0_wp, 0.0_wp], 'box edge normal: first face (x upper)')
      if (allocated(error)) return
      call body%outward_normal([0.0_wp, 0.0_wp, 0.5_wp], 2, n)
      call check_vector(error, n, [0.0_wp, 0.0_wp, -1.0_wp], 'void normal points into the void')
   end subroutine test_csg_corners

   !> On random points of each shape's surface that bound the body alone
   !> (a single surface reported), the body's outward normal is unit and the
   !> body's phi goes from - to + along it. Bodies with subtracted shapes check
   !> the flip. Each shape must be tested on at least 10 points.
   subroutine test_body_normals(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: bodies(5)
      real(wp) :: x(3), n(3), extent(5)
      real(wp), parameter :: delta = 1.0e-6_wp, tol = 1.0e-9_wp
      integer :: b, s, k, d, list(8), nlist, ntested
      integer(i8) :: seed

      call quarter_annulus(bodies(1), error)
      if (allocated(error)) return
      call mixed_2d(bodies(2), error)
      if (allocated(error)) return
      call shell_octant(bodies(3), error)
      if (allocated(error)) return
      call cube_void(bodies(4), error)
      if (allocated(error)) return
      call capped_cylinder(bodies(5), [1.0_wp, 2.0_wp, 2.0_wp], error)
      if (allocated(error)) return
      extent = [25.0_wp, 4.0_wp, 25.0_wp, 1.5_wp, 2.0_wp]
      seed = 31337_i8
      do b = 1, size(bodies)
         d = bodies(b)%dim
         do s = 1, bodies(b)%nshape
            ntested = 0
            do k = 1, 400
               x(1:d) = surface_point(bodies(b)%shapes(s), seed, extent(b))
               call bodies(b)%surface_at(x(1:d), tol, list, nlist)
               if (nlist /= 1) cycle
               call check(error, list(1), s, 'surface point reported on another shape, body '//bodies(b)%name)
               if (allocated(error)) return
               ! keep away from other surfaces so that +-delta stays on this one
               if (near_other_surface(bodies(b), s, x(1:d), 10.0_wp*delta)) cycle
               call bodies(b)%outward_normal(x(1:d), s, n(1:d))
               call check(error, norm2(n(1:d)), 1.0_wp, 1.0e-14_wp, 'unit normal')
               if (allocated(error)) return
               call check(error, bodies(b)%phi(x(1:d) + delta*n(1:d)) > 0.0_wp .and. &
                  & bodies(b)%phi(x(1:d) - delta*n(1:d)) < 0.0_wp, &
                  & 'body normal not outward on '//bodies(b)%shapes(s)%name//' of '//bodies(b)%name)
               if (allocated(error)) return
               ntested = ntested + 1
            end do
            call check(error, ntested >= 10, 'too few boundary points on '//bodies(b)%shapes(s)%name// &
               & ' of '//bodies(b)%name)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_body_normals

   subroutine test_names(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: k

      do k = shape_disk, shape_cylinder
         call check(error, shape_kind_from_name(shape_kind_name(k)), k, 'kind name round trip')
         if (allocated(error)) return
      end do
      call check(error, shape_kind_from_name('torus'), 0, 'unknown kind')
      if (allocated(error)) return
      call check(error, shape_kind_name(0), '', 'name of kind 0')
      if (allocated(error)) return
      call check(error, shape_kind_name(shape_halfspace), 'halfspace', 'halfspace name')
      if (allocated(error)) return
      do k = csg_add, csg_intersect
         call check(error, csg_op_from_name(csg_op_name(k)), k, 'op name round trip')
         if (allocated(error)) return
      end do
      call check(error, csg_op_from_name('xor'), 0, 'unknown op')
      if (allocated(error)) return
      call check(error, csg_op_name(csg_subtract), 'subtract', 'subtract name')
   end subroutine test_names

   subroutine test_constructor_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      type(error_type), allocatable :: e
      real(wp) :: nan, inf

      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      inf = ieee_value(1.0_wp, ieee_positive_inf)
      call new_disk(s, 'd', [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, e)
      call expect_error(error, e, s, "'d' (disk): center has 3 values, expected 2", 'disk center size')
      if (allocated(error)) return
      call new_disk(s, 'd', [0.0_wp, 0.0_wp], 0.0_wp, e)
      call expect_error(error, e, s, 'radius = 0.0', 'disk radius 0')
      if (allocated(error)) return
      call new_disk(s, 'd', [0.0_wp, 0.0_wp], -1.0_wp, e)
      call expect_error(error, e, s, 'radius = -1.0', 'disk radius < 0')
      if (allocated(error)) return
      call new_disk(s, 'd', [0.0_wp, 0.0_wp], nan, e)
      call expect_error(error, e, s, 'radius = NaN', 'disk radius NaN')
      if (allocated(error)) return
      call new_disk(s, 'd', [0.0_wp, nan], 1.0_wp, e)
      call expect_error(error, e, s, 'center(2) = NaN is not finite', 'disk center NaN')
      if (allocated(error)) return
      call new_sphere(s, 'b', [0.0_wp, 0.0_wp], 1.0_wp, e)
      call expect_error(error, e, s, "'b' (sphere): center has 2 values, expected 3", 'sphere center size')
      if (allocated(error)) return
      call new_sphere(s, 'b', [0.0_wp, 0.0_wp, 0.0_wp], inf, e)
      call expect_error(error, e, s, 'radius = Inf', 'sphere radius Inf')
      if (allocated(error)) return
      call new_ellipse(s, 'e', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], e)
      call expect_error(error, e, s, 'semi_axes has 3 values, expected 2', 'ellipse semi_axes size')
      if (allocated(error)) return
      call new_ellipse(s, 'e', [0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp], e)
      call expect_error(error, e, s, 'semi_axes = 0.0', 'ellipse semi_axes 0')
      if (allocated(error)) return
      call new_ellipsoid(s, 'e', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], e)
      call expect_error(error, e, s, 'center has 2 values, expected 3', 'ellipsoid center size')
      if (allocated(error)) return
      call new_ellipsoid(s, 'e', [inf, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], e)
      call expect_error(error, e, s, 'center(1) = Inf', 'ellipsoid center Inf')
      if (allocated(error)) return
      call new_box(s, 'k', [0.0_wp], [1.0_wp], e)
      call expect_error(error, e, s, 'lower has 1 values, expected 2 or 3', 'box 1D')
      if (allocated(error)) return
      call new_box(s, 'k', [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], e)
      call expect_error(error, e, s, 'lower has 4 values, expected 2 or 3', 'box 4D')
      if (allocated(error)) return
      call new_box(s, 'k', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], e)
      call expect_error(error, e, s, 'upper has 3 values, expected 2', 'box upper size')
      if (allocated(error)) return
      call new_box(s, 'k', [0.0_wp, 3.0_wp], [1.0_wp, 1.0_wp], e)
      call expect_error(error, e, s, 'lower(2) = 3.0', 'box lower > upper')
      if (allocated(error)) return
      call new_box(s, 'k', [0.0_wp, 0.0_wp, 2.0_wp], [0.0_wp, 1.0_wp, 3.0_wp], e)
      call expect_error(error, e, s, 'lower(1) = 0.0', 'box lower = upper')
      if (allocated(error)) return
      call new_box(s, 'k', [0.0_wp, 0.0_wp], [1.0_wp, nan], e)
      call expect_error(error, e, s, 'upper(2) = NaN', 'box upper NaN')
      if (allocated(error)) return
      call new_halfspace(s, 'h', [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], e)
      call expect_error(error, e, s, 'point has 4 values, expected 2 or 3', 'halfspace 4D')
      if (allocated(error)) return
      call new_halfspace(s, 'h', [0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp, 0.0_wp], e)
      call expect_error(error, e, s, 'normal has 3 values, expected 2', 'halfspace normal size')
      if (allocated(error)) return
      call new_halfspace(s, 'h', [0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp], e)
      call expect_error(error, e, s, 'normal = (0.0', 'halfspace zero normal')
      if (allocated(error)) return
      call new_halfspace(s, 'h', [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, nan, 0.0_wp], e)
      call expect_error(error, e, s, 'normal(2) = NaN', 'halfspace normal NaN')
      if (allocated(error)) return
      call new_halfspace(s, 'h', [nan, 0.0_wp], [1.0_wp, 0.0_wp], e)
      call expect_error(error, e, s, 'point(1) = NaN', 'halfspace point NaN')
      if (allocated(error)) return
      call new_cylinder(s, 'c', [0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], 1.0_wp, e)
      call expect_error(error, e, s, 'point has 2 values, expected 3', 'cylinder point size')
      if (allocated(error)) return
      call new_cylinder(s, 'c', [0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 1.0_wp], 1.0_wp, e)
      call expect_error(error, e, s, 'axis has 2 values, expected 3', 'cylinder axis size')
      if (allocated(error)) return
      call new_cylinder(s, 'c', [0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, e)
      call expect_error(error, e, s, 'axis = (0.0', 'cylinder zero axis')
      if (allocated(error)) return
      call new_cylinder(s, 'c', [0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], -2.0_wp, e)
      call expect_error(error, e, s, 'radius = -2.0', 'cylinder radius')
      if (allocated(error)) return
      call new_cylinder(s, 'c', [0.0_wp, inf, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], 1.0_wp, e)
      call expect_error(error, e, s, 'point(2) = Inf', 'cylinder point Inf')
   end subroutine test_constructor_errors

   subroutine test_body_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: disk, ball, bad
      type(error_type), allocatable :: e

      call new_disk(disk, 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call new_sphere(ball, 'ball', [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call new_body(body, 'part')
      call check(error, body%classify_box([0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp]), cell_outside, 'empty body')
      if (allocated(error)) return
      call check(error, body%phi([0.0_wp, 0.0_wp]) > 0.0_wp, 'empty body phi')
      if (allocated(error)) return
      call body%add_shape(csg_subtract, disk, e)
      call expect_body_error(error, e, body, 0, "body 'part', shape 'rim': the first shape's op must be 'add', " &
         & //"got 'subtract'", 'first op subtract')
      if (allocated(error)) return
      call body%add_shape(csg_intersect, disk, e)
      call expect_body_error(error, e, body, 0, "must be 'add', got 'intersect'", 'first op intersect')
      if (allocated(error)) return
      call body%add_shape(0, disk, e)
      call expect_body_error(error, e, body, 0, 'unknown op 0', 'op 0')
      if (allocated(error)) return
      call new_disk(bad, 'broken', [0.0_wp, 0.0_wp], -1.0_wp, e)
      call body%add_shape(csg_add, bad, e)
      call expect_body_error(error, e, body, 0, "shape 'broken': shape was not constructed", 'unconstructed shape')
      if (allocated(error)) return
      call body%add_shape(csg_add, disk, error)
      if (allocated(error)) return
      call body%add_shape(4, disk, e)
      call expect_body_error(error, e, body, 1, 'unknown op 4', 'op 4')
      if (allocated(error)) return
      call body%add_shape(csg_subtract, ball, e)
      call expect_body_error(error, e, body, 1, 'sphere has dimension 3, the body has dimension 2', 'dimension')
      if (allocated(error)) return
      call body%add_shape(csg_intersect, disk, e)
      call expect_body_error(error, e, body, 1, "shape 'rim': name already used", 'duplicate name')
   end subroutine test_body_errors

   ! ------------------------------------------------------------ bodies

   !> SCENE.md: disk r = 20 minus disk r = 5, intersected with x >= 0, y >= 0.
   subroutine quarter_annulus(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call annulus(body, error)
      if (allocated(error)) return
      call new_halfspace(s, 'sym_x', [0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'sym_y', [0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      body%name = 'quarter_annulus'
   end subroutine quarter_annulus

   subroutine annulus(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, 'annulus')
      call new_disk(s, 'outer', [0.0_wp, 0.0_wp], 20.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_disk(s, 'inner', [0.0_wp, 0.0_wp], 5.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
   end subroutine annulus

   !> (ellipse + box - disk) intersected with an oblique halfspace.
   subroutine mixed_2d(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, 'mixed_2d')
      call new_ellipse(s, 'oval', [-0.5_wp, 0.2_wp], [2.5_wp, 1.2_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_box(s, 'plate', [0.0_wp, -2.0_wp], [3.0_wp, 0.5_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_disk(s, 'hole', [1.0_wp, -0.5_wp], 0.7_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'cut', [0.0_wp, 0.5_wp], [1.0_wp, 2.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
   end subroutine mixed_2d

   subroutine spherical_shell(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, 'shell')
      call new_sphere(s, 'outer', [0.0_wp, 0.0_wp, 0.0_wp], 20.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_sphere(s, 'inner', [0.0_wp, 0.0_wp, 0.0_wp], 5.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
   end subroutine spherical_shell

   subroutine shell_octant(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      character(len=5), parameter :: names(3) = ['sym_x', 'sym_y', 'sym_z']
      real(wp) :: n(3)
      integer :: i

      call spherical_shell(body, error)
      if (allocated(error)) return
      do i = 1, 3
         n = 0.0_wp
         n(i) = -1.0_wp
         call new_halfspace(s, names(i), [0.0_wp, 0.0_wp, 0.0_wp], n, error)
         if (allocated(error)) return
         call body%add_shape(csg_intersect, s, error)
         if (allocated(error)) return
      end do
      body%name = 'shell_octant'
   end subroutine shell_octant

   subroutine cube_void(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, 'cube_void')
      call new_box(s, 'cube', [-1.0_wp, -1.0_wp, -1.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_sphere(s, 'void', [0.0_wp, 0.0_wp, 0.0_wp], 0.5_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
   end subroutine cube_void

   !> Cylinder of radius 1 along `axis` through the origin, capped at +-1
   !> along the axis by two halfspaces.
   subroutine capped_cylinder(body, axis, error)
      type(body_type), intent(out) :: body
      real(wp), intent(in) :: axis(3)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      real(wp) :: a(3)

      a = axis/norm2(axis)
      call new_body(body, 'capped_cylinder')
      call new_cylinder(s, 'mantle', [0.0_wp, 0.0_wp, 0.0_wp], axis, 1.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'top', a, a, error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'bottom', -a, -a, error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
   end subroutine capped_cylinder

   !> (ellipsoid + sphere - oblique cylinder) intersected with a box.
   subroutine mixed_3d(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, 'mixed_3d')
      call new_ellipsoid(s, 'egg', [0.0_wp, 0.0_wp, 0.0_wp], [2.0_wp, 1.0_wp, 1.5_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_sphere(s, 'knob', [1.5_wp, 1.0_wp, 0.5_wp], 1.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_cylinder(s, 'bore', [0.2_wp, 0.1_wp, 0.0_wp], [1.0_wp, -1.0_wp, 2.0_wp], 0.5_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call new_box(s, 'clip', [-1.5_wp, -2.0_wp, -1.0_wp], [3.0_wp, 2.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
   end subroutine mixed_3d

   subroutine single(body, shape, error)
      type(body_type), intent(out) :: body
      type(shape_type), intent(in) :: shape
      type(error_type), allocatable, intent(out) :: error
      call new_body(body, 'single')
      call body%add_shape(csg_add, shape, error)
   end subroutine single

   !> One shape of every kind, with oblique and axis-aligned directions.
   !> Every point of a catalogue shape sampled on a lattice over [-4, 4]^dim (inside:
   !> phi < 0) lies in its bounds; a bounded side is attained (the sample nearest to it
   !> lies within one lattice step, up to the rounding of the lattice coordinates); an
   !> unbounded side is one the shape really extends along: on the lattice over
   !> [-400, 400]^dim it has inside samples beyond 40 that way (every bounded
   !> catalogue shape lies within 3 of the origin).
   subroutine test_shape_bounds(error)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shapes(ncatalogue)
      integer, parameter :: n = 40
      real(wp), parameter :: span = 4.0_wp, far = 400.0_wp, step = 2.0_wp*span/n
      !> One lattice step, and the rounding of the lattice coordinates.
      real(wp), parameter :: reach = step + sample_slack*span
      real(wp) :: lo(3), hi(3), seen_lo(3), seen_hi(3), far_lo(3), far_hi(3)
      integer :: i, d, k
      logical :: attained
      character(len=160) :: buf

      call catalogue(shapes, error)
      if (allocated(error)) return
      do i = 1, ncatalogue
         d = shapes(i)%dim
         call shapes(i)%bounds(lo(1:d), hi(1:d))
         call sample(shapes(i), span, seen_lo, seen_hi)
         call sample(shapes(i), far, far_lo, far_hi)
         do k = 1, d
            write (buf, '(a," axis ",i0,": bounds ",2es10.2,", inside samples ",2es10.2)') &
               & shapes(i)%name, k, lo(k), hi(k), seen_lo(k), seen_hi(k)
            call check(error, lo(k) <= seen_lo(k) .and. seen_hi(k) <= hi(k), 'samples within the bounds: '//trim(buf))
            if (allocated(error)) return
            attained = merge(far_lo(k) < -0.1_wp*far, seen_lo(k) - lo(k) <= reach, lo(k) == -huge(1.0_wp)) .and. &
               & merge(far_hi(k) > 0.1_wp*far, hi(k) - seen_hi(k) <= reach, hi(k) == huge(1.0_wp))
            call check(error, attained, 'bounds attained: '//trim(buf))
            if (allocated(error)) return
         end do
      end do
   contains
      subroutine sample(shape, half, smin, smax)
         type(shape_type), intent(in) :: shape
         real(wp), intent(in) :: half
         real(wp), intent(out) :: smin(3), smax(3)
         real(wp) :: x(3)
         integer :: total, idx(3), d
         d = shape%dim
         smin = huge(1.0_wp)
         smax = -huge(1.0_wp)
         do total = 0, (n + 1)**d - 1
            idx = 0
            idx(1) = mod(total, n + 1)
            idx(2) = mod(total/(n + 1), n + 1)
            if (d == 3) idx(3) = total/(n + 1)**2
            x(1:d) = -half + (2.0_wp*half/n)*real(idx(1:d), wp)
            if (.not. (shape%phi(x(1:d)) < 0.0_wp)) cycle
            smin(1:d) = min(smin(1:d), x(1:d))
            smax(1:d) = max(smax(1:d), x(1:d))
         end do
      end subroutine sample
   end subroutine test_shape_bounds

   !> A separate piece of a body wholly outside the box, beyond the slabs next to its
   !> faces, is an input error naming the body and the piece (issue 15 defect 3: it was
   !> cut off silently): a disk at x = 1000, a sphere at z = -500, a halfspace x >= 1000
   !> (unbounded). Material that a later shape removes again is none: no error.
   subroutine test_piece_outside_box(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(body_type) :: body
      type(shape_type) :: near, far, cover

      call new_disk(near, 'near', [5.0_wp, 5.0_wp], 3.0_wp, error)
      if (allocated(error)) return
      call new_disk(far, 'far', [1000.0_wp, 0.0_wp], 2.0_wp, error)
      if (allocated(error)) return
      call two_shapes(body, 'two_disks', near, csg_add, far, error)
      if (allocated(error)) return
      call check_body_in_box(body, [0.0_wp, 0.0_wp], 15.0_wp, e)
      call check(error, allocated(e), 'a disk at x = 1000 outside the box 0..15 is found')
      if (allocated(error)) return
      call check(error, e%stat, stat_invalid_input, 'status')
      if (allocated(error)) return
      call check(error, index(e%message, "body 'two_disks' extends beyond the scene's box 0..15 x 0..15") > 0 .and. &
         & index(e%message, "(shape 'far')") > 0, 'message names body, box and piece: '//e%message)
      if (allocated(error)) return
      ! the far disk removed again by a larger one: no material outside
      call new_disk(cover, 'cover', [1000.0_wp, 0.0_wp], 5.0_wp, error)
      if (allocated(error)) return
      call body%add_shape(csg_subtract, cover, error)
      if (allocated(error)) return
      call check_body_in_box(body, [0.0_wp, 0.0_wp], 15.0_wp, e)
      call check(error, .not. allocated(e), 'a piece subtracted again is no material')
      if (allocated(error)) return
      call new_halfspace(far, 'far_half', [1000.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call two_shapes(body, 'half', near, csg_add, far, error)
      if (allocated(error)) return
      call check_body_in_box(body, [0.0_wp, 0.0_wp], 15.0_wp, e)
      call check(error, allocated(e), 'an unbounded piece x >= 1000 is found')
      if (allocated(error)) return
      call new_sphere(near, 'near', [5.0_wp, 5.0_wp, 5.0_wp], 3.0_wp, error)
      if (allocated(error)) return
      call new_sphere(far, 'far', [5.0_wp, 5.0_wp, -500.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call two_shapes(body, 'two_spheres', near, csg_add, far, error)
      if (allocated(error)) return
      call check_body_in_box(body, [0.0_wp, 0.0_wp, 0.0_wp], 15.0_wp, e)
      call check(error, allocated(e), 'a sphere at z = -500 outside the box is found')
      if (allocated(error)) return
      call check(error, index(e%message, "(shape 'far')") > 0, 'names the sphere: '//e%message)
   end subroutine test_piece_outside_box

   subroutine two_shapes(body, name, first, op, second, error)
      type(body_type), intent(out) :: body
      character(len=*), intent(in) :: name
      type(shape_type), intent(in) :: first, second
      integer, intent(in) :: op
      type(error_type), allocatable, intent(out) :: error
      call new_body(body, name)
      call body%add_shape(csg_add, first, error)
      if (allocated(error)) return
      call body%add_shape(op, second, error)
   end subroutine two_shapes

   subroutine catalogue(shapes, error)
      type(shape_type), intent(out) :: shapes(ncatalogue)
      type(error_type), allocatable, intent(out) :: error

      call new_disk(shapes(1), 'disk', [0.3_wp, -0.2_wp], 1.7_wp, error)
      if (allocated(error)) return
      call new_sphere(shapes(2), 'sphere', [0.1_wp, 0.2_wp, -0.3_wp], 2.0_wp, error)
      if (allocated(error)) return
      call new_ellipse(shapes(3), 'ellipse', [-0.2_wp, 0.4_wp], [2.5_wp, 0.8_wp], error)
      if (allocated(error)) return
      call new_ellipsoid(shapes(4), 'ellipsoid', [0.1_wp, -0.1_wp, 0.2_wp], [1.5_wp, 2.5_wp, 0.7_wp], error)
      if (allocated(error)) return
      call new_box(shapes(5), 'box2', [-1.0_wp, -0.5_wp], [2.0_wp, 1.5_wp], error)
      if (allocated(error)) return
      call new_box(shapes(6), 'box3', [-1.0_wp, -2.0_wp, -0.5_wp], [1.5_wp, 1.0_wp, 2.0_wp], error)
      if (allocated(error)) return
      call new_halfspace(shapes(7), 'half2', [0.5_wp, 0.2_wp], [1.0_wp, 2.0_wp], error)
      if (allocated(error)) return
      call new_halfspace(shapes(8), 'half3', [0.1_wp, 0.2_wp, 0.3_wp], [-1.0_wp, 0.5_wp, 2.0_wp], error)
      if (allocated(error)) return
      call new_halfspace(shapes(9), 'half3_aligned', [0.0_wp, 0.0_wp, 1.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call new_cylinder(shapes(10), 'cyl_oblique', [0.2_wp, -0.1_wp, 0.3_wp], [1.0_wp, 2.0_wp, -0.5_wp], 1.2_wp, &
         & error)
      if (allocated(error)) return
      call new_cylinder(shapes(11), 'cyl_aligned', [0.5_wp, 0.5_wp, 0.0_wp], [0.0_wp, 1.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call new_cylinder(shapes(12), 'cyl_planar_axis', [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 0.0_wp], 0.8_wp, &
         & error)
   end subroutine catalogue

   ! ------------------------------------------------------------ checkers

   !> Check a box's class against an m^dim lattice of samples of the body's
   !> phi (slack stol). With `tight`, a cut box must come within half a
   !> lattice cell diagonal of the boundary on both sides (phi is
   !> 1-Lipschitz for the bodies used so). ncls counts the classes.
   subroutine check_box(error, body, lo, hi, m, tight, stol, ncls)
      type(error_type), allocatable, intent(out) :: error
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:), stol
      integer, intent(in) :: m
      logical, intent(in) :: tight
      integer, intent(inout), optional :: ncls(0:2)
      real(wp) :: smin, smax, f, reach
      integer :: j, cls
      character(len=200) :: buf

      cls = body%classify_box(lo, hi)
      if (present(ncls)) ncls(cls) = ncls(cls) + 1
      smin = huge(1.0_wp)
      smax = -huge(1.0_wp)
      do j = 0, m**size(lo) - 1
         f = body%phi(lattice_point(lo, hi, m, j))
         smin = min(smin, f)
         smax = max(smax, f)
      end do
      write (buf, '(a," class ",i0," box ",6es12.4," samples ",2es12.4)') body%name, cls, lo, hi, smin, smax
      select case (cls)
      case (cell_inside)
         call check(error, smax <= stol, 'inside box has an outside sample: '//trim(buf))
      case (cell_outside)
         call check(error, smin >= -stol, 'outside box has an inside sample: '//trim(buf))
      case (cell_cut)
         if (.not. tight) return
         reach = 0.5_wp*norm2(hi - lo)/real(m - 1, wp) + stol
         call check(error, smin <= reach .and. smax >= -reach, 'cut box far from the boundary: '//trim(buf))
      case default
         call test_failed(error, 'unknown class: '//trim(buf))
      end select
   end subroutine check_box

   !> Check every cell of an n^dim grid (corner origin, cell h); return the
   !> inside and cut measures and the class counts.
   subroutine check_grid(error, body, origin, h, n, m, extent, vin, vcut, ncls)
      type(error_type), allocatable, intent(out) :: error
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: origin(:), h, extent
      integer, intent(in) :: n, m
      real(wp), intent(out) :: vin, vcut
      integer, intent(out) :: ncls(0:2)
      real(wp) :: lo(size(origin))
      integer :: c, i, r, d

      d = size(origin)
      ncls = 0
      do c = 0, n**d - 1
         r = c
         do i = 1, d
            lo(i) = origin(i) + h*real(mod(r, n), wp)
            r = r/n
         end do
         call check_box(error, body, lo, lo + h, m, .true., sample_slack*extent, ncls)
         if (allocated(error)) return
      end do
      vin = real(ncls(cell_inside), wp)*h**d
      vcut = real(ncls(cell_cut), wp)*h**d
      call check(error, ncls(cell_cut) > 0, 'grid of '//body%name//' has no cut cell')
   end subroutine check_grid

   subroutine expect_surfaces(error, body, x, expected, what)
      type(error_type), allocatable, intent(out) :: error
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: x(:)
      integer, intent(in) :: expected(:)
      character(len=*), intent(in) :: what
      integer :: list(8), n
      call body%surface_at(x, 1.0e-10_wp, list, n)
      call check_list(error, list(1:n), expected, what)
   end subroutine expect_surfaces

   subroutine check_list(error, actual, expected, what)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: actual(:), expected(:)
      character(len=*), intent(in) :: what
      character(len=120) :: buf
      if (size(actual) == size(expected)) then
         if (all(actual == expected)) return
      end if
      write (buf, '("got [",*(i0,:,","))') actual
      call test_failed(error, what//': '//trim(buf)//']')
   end subroutine check_list

   !> Unit vectors from exact data: 1e-14 covers the rounding of a normalisation.
   subroutine check_vector(error, actual, expected, what)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in) :: actual(:), expected(:)
      character(len=*), intent(in) :: what
      call check(error, maxval(abs(actual - expected)), 0.0_wp, 1.0e-14_wp, what)
   end subroutine check_vector

   subroutine expect_error(error, e, s, fragment, what)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable, intent(in) :: e
      type(shape_type), intent(in) :: s
      character(len=*), intent(in) :: fragment, what

      if (.not. allocated(e)) then
         call test_failed(error, what//': no error returned')
         return
      end if
      call check(error, e%stat, stat_invalid_input, what//': status')
      if (allocated(error)) return
      call check(error, index(e%message, fragment) > 0, what//': message "'//e%message//'" lacks "'//fragment//'"')
      if (allocated(error)) return
      call check(error, s%kind, 0, what//': failed shape must stay unconstructed')
   end subroutine expect_error

   subroutine expect_body_error(error, e, body, nshape, fragment, what)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable, intent(in) :: e
      type(body_type), intent(in) :: body
      integer, intent(in) :: nshape
      character(len=*), intent(in) :: fragment, what

      if (.not. allocated(e)) then
         call test_failed(error, what//': no error returned')
         return
      end if
      call check(error, e%stat, stat_invalid_input, what//': status')
      if (allocated(error)) return
      call check(error, index(e%message, fragment) > 0, what//': message "'//e%message//'" lacks "'//fragment//'"')
      if (allocated(error)) return
      call check(error, body%nshape, nshape, what//': body changed by a failed add')
   end subroutine expect_body_error

   ! ------------------------------------------------------------ sampling helpers

   real(wp) function uniform(seed)
      integer(i8), intent(inout) :: seed
      seed = mod(16807_i8*seed, 2147483647_i8)
      uniform = real(seed, wp)/2147483647.0_wp
   end function uniform

   !> A random box inside [-extent, extent]^d with log-uniform sizes from
   !> 1e-3 to 1 times extent; one box in ten is flat in its first direction.
   subroutine random_box(seed, d, extent, lo, hi)
      integer(i8), intent(inout) :: seed
      integer, intent(in) :: d
      real(wp), intent(in) :: extent
      real(wp), intent(out) :: lo(3), hi(3)
      real(wp) :: c, w
      integer :: i
      logical :: flat

      flat = uniform(seed) < 0.1_wp
      lo = 0.0_wp
      hi = 0.0_wp
      do i = 1, d
         c = extent*(2.0_wp*uniform(seed) - 1.0_wp)
         w = 0.5_wp*extent*10.0_wp**(-3.0_wp*uniform(seed))
         if (flat .and. i == 1) w = 0.0_wp
         lo(i) = c - w
         hi(i) = c + w
      end do
   end subroutine random_box

   !> Lattice point number k (0-based) of the m^d lattice on [lo, hi], corners included exactly.
   pure function lattice_point(lo, hi, m, k) result(x)
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: m, k
      real(wp) :: x(size(lo))
      integer :: i, r, j
      r = k
      do i = 1, size(lo)
         j = mod(r, m)
         r = r/m
         if (j == m - 1) then
            x(i) = hi(i)
         else
            x(i) = lo(i) + (hi(i) - lo(i))*real(j, wp)/real(m - 1, wp)
         end if
      end do
   end function lattice_point

   !> A random unit vector in d dimensions.
   function random_unit(seed, d) result(u)
      integer(i8), intent(inout) :: seed
      integer, intent(in) :: d
      real(wp) :: u(d)
      integer :: i
      do
         do i = 1, d
            u(i) = 2.0_wp*uniform(seed) - 1.0_wp
         end do
         if (norm2(u) > 0.1_wp .and. norm2(u) <= 1.0_wp) exit
      end do
      u = u/norm2(u)
   end function random_unit

   !> A random point on the shape's surface (within `extent` along unbounded surfaces).
   function surface_point(s, seed, extent) result(x)
      type(shape_type), intent(in) :: s
      integer(i8), intent(inout) :: seed
      real(wp), intent(in) :: extent
      real(wp) :: x(s%dim)
      real(wp) :: u(3), t
      integer :: d, i

      d = s%dim
      select case (s%kind)
      case (shape_disk, shape_sphere)
         x = s%center(1:d) + s%radius*random_unit(seed, d)
      case (shape_ellipse, shape_ellipsoid)
         x = s%center(1:d) + s%semi_axes(1:d)*random_unit(seed, d)
      case (shape_box)
         do i = 1, d
            x(i) = s%lower(i) + (s%upper(i) - s%lower(i))*uniform(seed)
         end do
         i = 1 + min(d - 1, int(d*uniform(seed)))
         x(i) = merge(s%lower(i), s%upper(i), uniform(seed) < 0.5_wp)
      case (shape_halfspace)
         u(1:d) = random_unit(seed, d)
         u(1:d) = u(1:d) - dot_product(u(1:d), s%normal(1:d))*s%normal(1:d)
         x = s%point(1:d) + extent*(2.0_wp*uniform(seed) - 1.0_wp)*u(1:d)/norm2(u(1:d))
         ! project exactly onto the plane where a coordinate is aligned with it
         x = x - dot_product(x - s%point(1:d), s%normal(1:d))*s%normal(1:d)
      case (shape_cylinder)
         u = random_unit(seed, 3)
         u = u - dot_product(u, s%axis)*s%axis
         t = extent*(2.0_wp*uniform(seed) - 1.0_wp)
         x = s%point + t*s%axis + s%radius*u/norm2(u)
      case default
         x = 0.0_wp
      end select
   end function surface_point

   !> Near a point where phi is not differentiable (center, axis, box edge).
   logical function near_singular(s, x, gap)
      type(shape_type), intent(in) :: s
      real(wp), intent(in) :: x(:), gap
      real(wp) :: faces(6), v(3), best
      integer :: d, k

      d = s%dim
      select case (s%kind)
      case (shape_disk, shape_sphere)
         near_singular = norm2(x - s%center(1:d)) < 0.1_wp
      case (shape_cylinder)
         v = x - s%point
         near_singular = norm2(v - dot_product(v, s%axis)*s%axis) < 0.1_wp
      case (shape_box)
         faces(1:d) = s%lower(1:d) - x
         faces(d + 1:2*d) = x - s%upper(1:d)
         k = maxloc(faces(1:2*d), 1)
         best = faces(k)
         faces(k) = -huge(1.0_wp)
         near_singular = best - maxval(faces(1:2*d)) < gap
      case default
         near_singular = .false.
      end select
   end function near_singular

   !> Another shape's surface within `gap` of x (phi of each is 1-Lipschitz or close to it).
   logical function near_other_surface(body, s, x, gap)
      type(body_type), intent(in) :: body
      integer, intent(in) :: s
      real(wp), intent(in) :: x(:), gap
      integer :: k
      near_other_surface = .false.
      do k = 1, body%nshape
         if (k == s) cycle
         if (abs(body%shapes(k)%phi(x)) < gap) near_other_surface = .true.
      end do
   end function near_other_surface

   !> Lower bound of |grad phi| on the surface (ellipse: a_min/a_max).
   real(wp) function minimum_slope(s)
      type(shape_type), intent(in) :: s
      minimum_slope = 1.0_wp
      if (s%kind == shape_ellipse .or. s%kind == shape_ellipsoid) &
         & minimum_slope = minval(s%semi_axes(1:s%dim))/maxval(s%semi_axes(1:s%dim))
   end function minimum_slope

   !> Lipschitz bound of phi on the box: 1 except for ellipses, where
   !> |grad phi| = a_min |(x - c)/a^2| <= a_min |far/a^2|, far the largest
   !> |x_i - c_i| on the box.
   real(wp) function lipschitz(s, lo, hi)
      type(shape_type), intent(in) :: s
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: far(3)
      integer :: d
      d = s%dim
      lipschitz = 1.0_wp
      if (s%kind /= shape_ellipse .and. s%kind /= shape_ellipsoid) return
      far(1:d) = max(abs(lo - s%center(1:d)), abs(hi - s%center(1:d)))
      lipschitz = minval(s%semi_axes(1:d))*norm2(far(1:d)/s%semi_axes(1:d)**2)
   end function lipschitz

end module sprc_test_geometry
