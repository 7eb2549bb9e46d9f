!> Tests of the contact surface: slave points from the cut-cell surface rules
!> and the initial gap along the slave normal to the master surface on its
!> exact implicit geometry (sprc_contact_surface, sprc_contact_ray).
!>
!> Every gap is compared with the closed-form intersection of the line with
!> the master surface (a quadratic for circles and ellipses, a linear equation
!> for planes), within the tolerance the root finder reports from its stopping
!> test plus the rounding of the closed form (16 eps times the coordinates);
!> the reported tolerance itself is checked to be small, so the comparison is
!> not vacuous.
module sprc_test_contact_surface
   use sprc_core_kinds, only: wp, i8
   use sprc_geometry_region, only: cell_cut
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_ellipse, new_box, new_halfspace, new_cylinder
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_grid_tree, only: grid_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature
   use sprc_contact_ray, only: ray_hit_type, nearest_crossing, facet_crossing, max_visits
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_shape, only: new_facet_shape
   use sprc_contact_surface, only: contact_surface_type, new_contact_surface, slave_surface_points, initial_gaps, &
      & linearized_gap
   use sprc_test_exact, only: expect_error, random => uniform
   use sprc_testsuite, only: unittest_type, new_unittest, check, error_type
   implicit none
   private

   public :: collect_contact_surface

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Rounding of a closed-form intersection, relative to the coordinates.
   real(wp), parameter :: closed_form_ulps = 16.0_wp*epsilon(1.0_wp)
   !> Gauss points per direction of the cut-cell rules here.
   integer, parameter :: q = 4

contains

   subroutine collect_contact_surface(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('slave_points_measure', test_slave_points), &
         new_unittest('circle_in_circle', test_circle_in_circle), &
         new_unittest('interference_fit', test_interference), &
         new_unittest('touching_surfaces', test_touching), &
         new_unittest('sphere_on_plane', test_sphere_on_plane), &
         new_unittest('search_distance', test_search_distance), &
         new_unittest('line_misses', test_line_misses), &
         new_unittest('back_facing_and_nearest', test_back_facing), &
         new_unittest('grazing_incidence', test_grazing), &
         new_unittest('ellipse_far_away', test_ellipse_far), &
         new_unittest('random_lines_box_cylinder', test_random_lines), &
         new_unittest('facet_lines', test_facet_lines), &
         new_unittest('facet_groups_and_csg', test_facet_groups), &
         new_unittest('line_in_the_surface', test_line_in_surface), &
         new_unittest('linearized_gap', test_linearized_gap), &
         new_unittest('errors', test_errors) &
         ]
   end subroutine collect_contact_surface

   ! ---------------------------------------------------------- slave points

   !> The slave points of a disk's circle carry its length 2 pi r, with unit
   !> normals e_r, each in the leaf it came from (and a box on grid planes its
   !> perimeter). The cut-cell rule's error
   !> is below rho^(-2q), rho >= 13.9 (sprc_grid_quadrature notes) relative.
   subroutine test_slave_points(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: shaft, block
      type(grid_type) :: grid
      type(contact_surface_type) :: surf
      type(shape_type) :: s
      integer :: i
      real(wp) :: lo(2), hi(2), r

      call make_disk_body(shaft, 'shaft', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call slave_points(shaft, [-1.25_wp, -1.25_wp], 2.5_wp, 4, 1, surf, grid, error)
      if (allocated(error)) return
      call check(error, sum(surf%weight), 2.0_wp*pi, 13.9_wp**(-2*q), 'slave surface length', rel=.true.)
      if (allocated(error)) return
      do i = 1, surf%npoint
         r = norm2(surf%x(:, i))
         call check(error, r, 1.0_wp, closed_form_ulps, 'slave point on the circle')
         if (allocated(error)) return
         call check(error, norm2(surf%normal(:, i) - surf%x(:, i)/r), 0.0_wp, closed_form_ulps, 'normal e_r')
         if (allocated(error)) return
         call grid%leaf_box(surf%slave_cell(i), lo, hi)
         call check(error, all(surf%x(:, i) >= lo) .and. all(surf%x(:, i) <= hi), 'slave point in its leaf')
         if (allocated(error)) return
      end do
      ! A box whose faces lie on grid planes (h = 0.5): its surface points come
      ! from the faces of inside leaves; perimeter 6, exact up to round-off.
      call new_body(block, 'block')
      call new_box(s, 'faces', [-1.0_wp, -1.0_wp], [1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call block%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call slave_points(block, [-2.0_wp, -2.0_wp], 4.0_wp, 3, 0, surf, grid, error)
      if (allocated(error)) return
      call check(error, sum(surf%weight), 6.0_wp, 64.0_wp*epsilon(1.0_wp), 'box on grid planes: perimeter', rel=.true.)
   end subroutine test_slave_points

   ! ---------------------------------------------------------------- circles

   !> Shaft r = 1 in the eccentric bore (center c, radius R = 1.3) of a hub:
   !> g0 = -cc/(b + sqrt(b^2 - cc)) with b = n.(x - c), cc = |x - c|^2 - R^2,
   !> the root of |x + t n - c| = R nearest to 0 (cancellation-free for b > 0;
   !> here b > 0.8);
   !> the master normal is -(x_m - c)/R and the master leaf holds x_m.
   subroutine test_circle_in_circle(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: c(2) = [0.1_wp, 0.05_wp], big_r = 1.3_wp

      call check_shaft_in_hub(error, 1.0_wp, c, big_r, 'circle in circle')
   end subroutine test_circle_in_circle

   !> Shaft r = 1.01 in a concentric bore R = 1: every slave point lies in the
   !> hub and g0 = R - |x| = -0.01 (interference), found behind the point.
   subroutine test_interference(error)
      type(error_type), allocatable, intent(out) :: error

      call check_shaft_in_hub(error, 1.01_wp, [0.0_wp, 0.0_wp], 1.0_wp, 'interference fit')
   end subroutine test_interference

   !> Shaft and bore of the same radius: the surfaces touch, g0 = 0 within
   !> the tolerance, whichever side of the bore rounding puts a slave point.
   !> Then points placed a few ulps off the bore on either side (radius
   !> 1 + k 4 eps, k = -3..3, outside and inside the hub within the side
   !> test's tolerance): g0 = 1 - r within the tolerance.
   subroutine test_touching(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: hub
      type(grid_type) :: hub_grid
      type(contact_surface_type) :: surf
      type(shape_type) :: s
      real(wp) :: x(2, 7), n(2, 7), r(7), angle
      integer :: k

      call check_shaft_in_hub(error, 1.0_wp, [0.0_wp, 0.0_wp], 1.0_wp, 'touching')
      if (allocated(error)) return
      do k = 1, 7
         r(k) = 1.0_wp + real(k - 4, wp)*4.0_wp*epsilon(1.0_wp)
         angle = 0.4_wp*k
         n(:, k) = [cos(angle), sin(angle)]
         x(:, k) = r(k)*n(:, k)
      end do
      call new_contact_surface(surf, x, spread(1.0_wp, 1, 7), n, [integer ::], error)
      if (allocated(error)) return
      call make_disk_body(hub, 'hub', 'outer', [0.0_wp, 0.0_wp], 2.0_wp, error)
      if (allocated(error)) return
      call new_disk(s, 'bore', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call hub%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call hub_grid%build(hub, 2, [-2.1_wp, -2.2_wp], 4.3_wp, 3, 0, error)
      if (allocated(error)) return
      call initial_gaps(surf, hub, 2, hub_grid, 1.0_wp, error)
      if (allocated(error)) return
      do k = 1, 7
         call check(error, surf%has_master(k), 'point a few ulps off the master surface has a master point')
         if (allocated(error)) return
         call check(error, surf%g0(k), 1.0_wp - r(k), surf%g0_tolerance(k) + closed_form_ulps, 'g0 of touching points')
         if (allocated(error)) return
      end do
   end subroutine test_touching

   subroutine check_shaft_in_hub(error, r_shaft, c, big_r, what)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in) :: r_shaft, c(2), big_r
      character(len=*), intent(in) :: what
      type(body_type) :: shaft, hub
      type(grid_type) :: grid, hub_grid
      type(contact_surface_type) :: surf
      type(shape_type) :: s
      real(wp) :: b, cc, expected, lo(2), hi(2), dx(2)
      integer :: i

      call make_disk_body(shaft, 'shaft', 'rim', [0.0_wp, 0.0_wp], r_shaft, error)
      if (allocated(error)) return
      call slave_points(shaft, [-1.3_wp, -1.3_wp], 2.6_wp, 4, 0, surf, grid, error)
      if (allocated(error)) return
      call make_disk_body(hub, 'hub', 'outer', [0.0_wp, 0.0_wp], 2.0_wp, error)
      if (allocated(error)) return
      call new_disk(s, 'bore', c, big_r, error)
      if (allocated(error)) return
      call hub%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call hub_grid%build(hub, 2, [-2.1_wp, -2.2_wp], 4.3_wp, 4, 0, error)
      if (allocated(error)) return
      call initial_gaps(surf, hub, 2, hub_grid, 1.0_wp, error)
      if (allocated(error)) return
      do i = 1, surf%npoint
         call check(error, surf%has_master(i), what//': every slave point has a master point')
         if (allocated(error)) return
         dx = surf%x(:, i) - c
         b = dot_product(surf%normal(:, i), dx)
         cc = dot_product(dx, dx) - big_r**2
         expected = -cc/(b + sqrt(b**2 - cc))
         call check(error, surf%g0_tolerance(i) < 1.0e-12_wp, what//': tolerance of the gap is small')
         if (allocated(error)) return
         call check(error, surf%g0(i), expected, surf%g0_tolerance(i) + closed_form_ulps*2.0_wp, what//': g0')
         if (allocated(error)) return
         call check(error, norm2(surf%master_x(:, i) - (surf%x(:, i) + surf%g0(i)*surf%normal(:, i))), 0.0_wp, &
            & closed_form_ulps*2.0_wp, what//': master point on the line')
         if (allocated(error)) return
         call check(error, norm2(surf%master_normal(:, i) + (surf%master_x(:, i) - c)/big_r), 0.0_wp, &
            & 1.0e-12_wp, what//': master normal')
         if (allocated(error)) return
         call hub_grid%leaf_box(surf%master_cell(i), lo, hi)
         call check(error, all(surf%master_x(:, i) >= lo) .and. all(surf%master_x(:, i) <= hi) .and. &
            & hub_grid%leaf_class(surf%master_cell(i)) == cell_cut, what//': master point in a cut master leaf')
         if (allocated(error)) return
      end do
   end subroutine check_shaft_in_hub

   ! ----------------------------------------------------------------- sphere

   !> Sphere r = 1 centered 0.1 above the plane z = 0 of a block (a box
   !> intersected with the halfspace 'top'): a slave point with n_z < 0 whose
   !> line meets the plane inside the block's top face (|x|, |y| < 3) has
   !> g0 = -z/n_z; every other point is open (its line meets the plane outside
   !> the face, where it does not bound the block, or not at all).
   subroutine test_sphere_on_plane(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_surface_type) :: surf
      type(body_type) :: block
      type(grid_type) :: block_grid
      integer :: i, nhit
      real(wp) :: t, xm(3)
      logical :: expect_hit

      call sphere_and_block(surf, block, block_grid, 100.0_wp, error)
      if (allocated(error)) return
      nhit = 0
      do i = 1, surf%npoint
         expect_hit = surf%normal(3, i) < 0.0_wp
         t = huge(1.0_wp)
         if (expect_hit) then
            t = -surf%x(3, i)/surf%normal(3, i)
            xm = surf%x(:, i) + t*surf%normal(:, i)
            ! Lines that meet the plane within round-off of the face's edge are not decided here.
            if (abs(3.0_wp - maxval(abs(xm(1:2)))) < 1.0e-9_wp) cycle
            expect_hit = maxval(abs(xm(1:2))) < 3.0_wp
         end if
         call check(error, surf%has_master(i) .eqv. expect_hit, 'sphere on plane: hit iff n_z < 0 and on the face')
         if (allocated(error)) return
         if (.not. expect_hit) then
            call check(error, surf%master_cell(i) == 0 .and. surf%g0(i) == huge(1.0_wp), 'open point: no master')
            if (allocated(error)) return
            cycle
         end if
         nhit = nhit + 1
         call check(error, surf%g0(i), t, surf%g0_tolerance(i) + closed_form_ulps*(3.0_wp + t), 'sphere on plane: g0')
         if (allocated(error)) return
         call check(error, norm2(surf%master_normal(:, i) - [0.0_wp, 0.0_wp, 1.0_wp]), 0.0_wp, 0.0_wp, &
            & 'sphere on plane: master normal e_z')
         if (allocated(error)) return
         call check(error, block_grid%leaf_class(surf%master_cell(i)) == cell_cut .or. &
            & abs(surf%master_x(3, i)) <= closed_form_ulps*3.0_wp, 'sphere on plane: master leaf')
         if (allocated(error)) return
      end do
      call check(error, nhit > 0 .and. nhit < surf%npoint, 'sphere on plane: some points hit, some are open')
      if (allocated(error)) return
      call check(error, minval(surf%g0), 0.1_wp, 1.0e-2_wp, 'sphere on plane: smallest gap near the pole')
   end subroutine test_sphere_on_plane

   !> A short search distance L = 0.3: points whose exact gap exceeds L are
   !> open, the others keep their gap.
   subroutine test_search_distance(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_surface_type) :: surf
      type(body_type) :: block
      type(grid_type) :: block_grid
      real(wp), parameter :: length = 0.3_wp
      real(wp) :: t
      integer :: i

      call sphere_and_block(surf, block, block_grid, length, error)
      if (allocated(error)) return
      do i = 1, surf%npoint
         if (surf%normal(3, i) >= 0.0_wp) cycle
         t = -surf%x(3, i)/surf%normal(3, i)
         if (abs(t - length) < 1.0e-9_wp) cycle
         call check(error, surf%has_master(i) .eqv. t < length, 'hit iff the gap is within the search distance')
         if (allocated(error)) return
      end do
   end subroutine test_search_distance

   subroutine sphere_and_block(surf, block, block_grid, search_distance, error)
      type(contact_surface_type), intent(out) :: surf
      type(body_type), intent(out) :: block
      type(grid_type), intent(out) :: block_grid
      real(wp), intent(in) :: search_distance
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: ball
      type(grid_type) :: grid
      type(shape_type) :: s

      call new_body(ball, 'ball')
      call new_sphere(s, 'surface', [0.0_wp, 0.0_wp, 1.1_wp], 1.0_wp, error)
      if (allocated(error)) return
      call ball%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call slave_points(ball, [-1.2_wp, -1.2_wp, -0.1_wp], 2.4_wp, 3, 0, surf, grid, error)
      if (allocated(error)) return
      call new_body(block, 'block')
      call new_box(s, 'sides', [-3.0_wp, -3.0_wp, -2.0_wp], [3.0_wp, 3.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call block%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'top', [0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call block%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call block_grid%build(block, 3, [-3.5_wp, -3.5_wp, -3.5_wp], 7.0_wp, 3, 0, error)
      if (allocated(error)) return
      call initial_gaps(surf, block, 2, block_grid, search_distance, error)
   end subroutine sphere_and_block

   ! ------------------------------------------------------------ single lines

   !> Lines that miss the master: passing above a disk, pointing away from
   !> it; through `initial_gaps` they are open (no master point, g0 = huge).
   subroutine test_line_misses(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: disk
      type(grid_type) :: grid
      type(contact_surface_type) :: surf
      type(ray_hit_type) :: hit
      real(wp) :: x(2, 2), n(2, 2)

      call make_disk_body(disk, 'disk', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call nearest_crossing(disk, 1, [-2.0_wp, 1.5_wp], [1.0_wp, 0.0_wp], 0.0_wp, 10.0_wp, .true., hit)
      call check(error, .not. hit%found .and. .not. hit%exhausted, 'line above the disk misses')
      if (allocated(error)) return
      call nearest_crossing(disk, 1, [-2.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], 0.0_wp, 10.0_wp, .true., hit)
      call check(error, .not. hit%found, 'line pointing away misses')
      if (allocated(error)) return
      call grid%build(disk, 2, [-1.5_wp, -1.5_wp], 3.0_wp, 3, 0, error)
      if (allocated(error)) return
      x = reshape([-2.0_wp, 1.5_wp, -2.0_wp, 0.0_wp], [2, 2])
      n = reshape([1.0_wp, 0.0_wp, 1.0_wp, 0.0_wp], [2, 2])
      call new_contact_surface(surf, x, [1.0_wp, 1.0_wp], n, [integer ::], error)
      if (allocated(error)) return
      call initial_gaps(surf, disk, 1, grid, 10.0_wp, error)
      if (allocated(error)) return
      call check(error, .not. surf%has_master(1) .and. surf%master_cell(1) == 0 .and. surf%g0(1) == huge(1.0_wp), &
         & 'missing line is open')
      if (allocated(error)) return
      call check(error, surf%has_master(2), 'line through the center hits')
      if (allocated(error)) return
      call check(error, surf%g0(2), 1.0_wp, surf%g0_tolerance(2) + closed_form_ulps*2.0_wp, 'gap to the near side')
   end subroutine test_line_misses

   !> The line from x = (-2, 0) along e_x crosses the unit circle at t = 1
   !> (entering: the outward normal opposes the line) and t = 3 (leaving).
   !> Without `facing` the nearest, t = 1, is returned, not the first found in
   !> another order; with `facing` from inside the disk, x = (0.5, 0), the
   !> only crossing ahead leaves the body and is refused. A shaft in a hub
   !> whose master surface is the hub's outer rim sees it only from behind:
   !> every slave point is open.
   subroutine test_back_facing(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: disk, shaft, hub
      type(grid_type) :: grid, hub_grid
      type(contact_surface_type) :: surf
      type(shape_type) :: s
      type(ray_hit_type) :: hit

      call make_disk_body(disk, 'disk', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call nearest_crossing(disk, 1, [-2.0_wp, 0.0_wp], [1.0_wp, 0.0_wp], 0.0_wp, 10.0_wp, .false., hit)
      call check(error, hit%found, 'crossing found without facing')
      if (allocated(error)) return
      call check(error, hit%t, 1.0_wp, hit%tolerance + closed_form_ulps*2.0_wp, 'nearest of two crossings')
      if (allocated(error)) return
      call nearest_crossing(disk, 1, [0.5_wp, 0.0_wp], [1.0_wp, 0.0_wp], 0.0_wp, 10.0_wp, .false., hit)
      call check(error, hit%found, 'leaving crossing found without facing')
      if (allocated(error)) return
      call check(error, hit%t, 0.5_wp, hit%tolerance + closed_form_ulps*2.0_wp, 'leaving crossing')
      if (allocated(error)) return
      call nearest_crossing(disk, 1, [0.5_wp, 0.0_wp], [1.0_wp, 0.0_wp], 0.0_wp, 10.0_wp, .true., hit)
      call check(error, .not. hit%found, 'leaving crossing refused with facing')
      if (allocated(error)) return
      call make_disk_body(shaft, 'shaft', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call slave_points(shaft, [-1.3_wp, -1.3_wp], 2.6_wp, 3, 0, surf, grid, error)
      if (allocated(error)) return
      call make_disk_body(hub, 'hub', 'outer', [0.0_wp, 0.0_wp], 2.0_wp, error)
      if (allocated(error)) return
      call new_disk(s, 'bore', [0.0_wp, 0.0_wp], 1.2_wp, error)
      if (allocated(error)) return
      call hub%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call hub_grid%build(hub, 2, [-2.1_wp, -2.2_wp], 4.3_wp, 3, 0, error)
      if (allocated(error)) return
      call initial_gaps(surf, hub, 1, hub_grid, 5.0_wp, error)
      if (allocated(error)) return
      call check(error, .not. any(surf%has_master), 'outer rim seen from behind: all open')
   end subroutine test_back_facing

   !> Shallow crossings of a unit circle, in a frame rotated by 0.3 rad so the
   !> segments' boxes are not flat: the line y' = 1 - eps from x' = -2 along
   !> e_x' crosses first at x' = -sqrt(2 eps - eps^2), t = 2 - sqrt(2 eps - eps^2)
   !> (found for eps = 1e-4 .. 1e-10; the tolerance grows like 1/sqrt(eps), the
   !> rounding of phi over the slope). eps = -1e-10 misses. The exact tangent
   !> (eps = 0) is within the position tolerance of both: it may be reported
   !> either way, but if found, at t = 2 within its tolerance.
   subroutine test_grazing(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: disk
      type(ray_hit_type) :: hit
      real(wp) :: rot(2, 2), eps, expected
      integer :: k

      call make_disk_body(disk, 'disk', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      rot = reshape([cos(0.3_wp), sin(0.3_wp), -sin(0.3_wp), cos(0.3_wp)], [2, 2])
      do k = 4, 10, 2
         eps = 10.0_wp**(-k)
         call nearest_crossing(disk, 1, matmul(rot, [-2.0_wp, 1.0_wp - eps]), rot(:, 1), 0.0_wp, 10.0_wp, &
            & .true., hit)
         expected = 2.0_wp - sqrt(2.0_wp*eps - eps**2)
         call check(error, hit%found, 'shallow crossing found')
         if (allocated(error)) return
         call check(error, hit%tolerance < 1.0e-9_wp, 'shallow crossing: tolerance stays small')
         if (allocated(error)) return
         call check(error, hit%t, expected, hit%tolerance + closed_form_ulps*2.0_wp, 'shallow crossing: t')
         if (allocated(error)) return
      end do
      call nearest_crossing(disk, 1, matmul(rot, [-2.0_wp, 1.0_wp + 1.0e-10_wp]), rot(:, 1), 0.0_wp, 10.0_wp, &
         & .true., hit)
      call check(error, .not. hit%found .and. .not. hit%exhausted, 'near miss is a miss')
      if (allocated(error)) return
      call nearest_crossing(disk, 1, matmul(rot, [-2.0_wp, 1.0_wp]), rot(:, 1), 0.0_wp, 10.0_wp, .true., hit)
      call check(error, .not. hit%exhausted, 'tangent line: search ends')
      if (allocated(error)) return
      if (hit%found) then
         call check(error, hit%t, 2.0_wp, hit%tolerance, 'tangent line: touching point')
      end if
   end subroutine test_grazing

   !> An ellipse (level set not Lipschitz-bounded far away) met from 500
   !> semi-axes away: x = (-1000, 0.5) along e_x hits (x/2)^2 + y^2 = 1 at
   !> x = -2 sqrt(1 - 0.25), t = 1000 - sqrt(3).
   subroutine test_ellipse_far(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(ray_hit_type) :: hit

      call new_body(body, 'ellipse')
      call new_ellipse(s, 'rim', [0.0_wp, 0.0_wp], [2.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call nearest_crossing(body, 1, [-1000.0_wp, 0.5_wp], [1.0_wp, 0.0_wp], 0.0_wp, 2000.0_wp, .true., hit)
      call check(error, hit%found, 'ellipse found from far away')
      if (allocated(error)) return
      call check(error, hit%t, 1000.0_wp - sqrt(3.0_wp), hit%tolerance + closed_form_ulps*1000.0_wp, 'ellipse: t')
      if (allocated(error)) return
      call check(error, hit%visits < 1000, 'ellipse: the isolation visits few segments')
      if (allocated(error)) return
      ! Newton from the middle of a monotone bracket converges quadratically:
      ! a dozen iterations, where bisection alone would need about 50.
      call check(error, hit%iterations <= 12, 'ellipse: safeguarded Newton converges fast')
   end subroutine test_ellipse_far

   !> 400 pseudo-random lines from outside against a 3D box (slab method:
   !> entry t = max over axes of the near-slab t, a hit if it is below the
   !> exit and in [0, L]) and against an oblique infinite cylinder (the
   !> smaller root of the quadratic in the components normal to the axis).
   !> The box's gradient enclosure is only sound (not exact) at its edges and
   !> the oblique cylinder's is an over-estimate: the isolation must still find
   !> every crossing and no other. Lines within 1e-9 of an edge or of
   !> tangency are not decided and skipped.
   subroutine test_random_lines(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: box_body, cyl_body
      type(shape_type) :: s
      type(ray_hit_type) :: hit
      real(wp), parameter :: length = 10.0_wp, lo(3) = [-1.0_wp, -0.5_wp, -2.0_wp], hi(3) = [1.5_wp, 0.5_wp, 1.0_wp]
      real(wp), parameter :: axis(3) = [1.0_wp, 2.0_wp, 2.0_wp]/3.0_wp, radius = 0.8_wp
      real(wp) :: x0(3), n(3), t_expected, margin
      integer(i8) :: seed
      integer :: k, body_kind, decided, nhit
      logical :: expect

      call new_body(box_body, 'box')
      call new_box(s, 'faces', lo, hi, error)
      if (allocated(error)) return
      call box_body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_body(cyl_body, 'cylinder')
      call new_cylinder(s, 'mantle', [0.1_wp, -0.2_wp, 0.3_wp], axis, radius, error)
      if (allocated(error)) return
      call cyl_body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      seed = 2024_i8
      decided = 0
      nhit = 0
      do k = 1, 400
         body_kind = mod(k, 2)
         x0 = 6.0_wp*[random(seed), random(seed), random(seed)] - 3.0_wp
         ! Aim at a random point of the same cube: many lines hit, many miss.
         n = 6.0_wp*[random(seed), random(seed), random(seed)] - 3.0_wp - x0
         n = n/norm2(n)
         if (body_kind == 0) then
            if (all(x0 > lo .and. x0 < hi)) cycle
            call box_entry(x0, n, lo, hi, t_expected, margin)
            call nearest_crossing(box_body, 1, x0, n, 0.0_wp, length, .true., hit)
         else
            if (norm2(perp(x0 - [0.1_wp, -0.2_wp, 0.3_wp])) <= radius) cycle
            call cylinder_entry(x0 - [0.1_wp, -0.2_wp, 0.3_wp], n, t_expected, margin)
            call nearest_crossing(cyl_body, 1, x0, n, 0.0_wp, length, .true., hit)
         end if
         if (margin < 1.0e-9_wp .or. abs(t_expected - length) < 1.0e-9_wp) cycle
         decided = decided + 1
         expect = t_expected <= length
         call check(error, .not. hit%exhausted .and. (hit%found .eqv. expect), 'random line: hit iff it crosses')
         if (allocated(error)) return
         if (.not. expect) cycle
         nhit = nhit + 1
         call check(error, hit%t, t_expected, hit%tolerance + closed_form_ulps*(3.0_wp + t_expected), &
            & 'random line: t of the entry')
         if (allocated(error)) return
      end do
      call check(error, decided > 300 .and. nhit > 80 .and. decided - nhit > 80, &
         & 'random lines: most lines decided, many hits and many misses')

   contains

      pure function perp(v) result(w)
         real(wp), intent(in) :: v(3)
         real(wp) :: w(3)
         w = v - dot_product(v, axis)*axis
      end function perp

      !> Entry of the line into the cylinder (huge if none ahead); margin: the
      !> discriminant's distance from tangency.
      pure subroutine cylinder_entry(d, n, t, margin)
         real(wp), intent(in) :: d(3), n(3)
         real(wp), intent(out) :: t, margin
         real(wp) :: pa, pb, pc, disc
         pa = dot_product(perp(n), perp(n))
         pb = dot_product(perp(n), perp(d))
         pc = dot_product(perp(d), perp(d)) - radius**2
         disc = pb**2 - pa*pc
         t = huge(1.0_wp)
         margin = abs(disc)
         if (disc <= 0.0_wp .or. pa <= 0.0_wp) return
         ! Outside (pc > 0): both roots share the sign of -pb; the entry is the smaller.
         if (pb < 0.0_wp) t = pc/(-pb + sqrt(disc))
      end subroutine cylinder_entry

   end subroutine test_random_lines

   !> A line that runs down the right face x = 1 of the square [0, 1]^2
   !> trimmed to y <= 0.5: phi = 0 along the whole face, which bounds the body
   !> only below y = 0.5. The first point that bounds it, t = 2.5, is found
   !> to the plateau resolution (2^-12 of the search length 10) with a
   !> bounded number of visits, not by enumerating t_tol-long pieces.
   subroutine test_line_in_surface(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s
      type(ray_hit_type) :: hit

      call new_body(body, 'square')
      call new_box(s, 'faces', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call new_halfspace(s, 'cut', [0.0_wp, 0.5_wp], [0.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call body%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      call nearest_crossing(body, 1, [1.0_wp, 3.0_wp], [0.0_wp, -1.0_wp], 0.0_wp, 10.0_wp, .true., hit)
      call check(error, hit%found .and. .not. hit%exhausted, 'line in the surface: found')
      if (allocated(error)) return
      call check(error, hit%t, 2.5_wp, 10.0_wp*2.0_wp**(-12), 'line in the surface: first bounding point')
      if (allocated(error)) return
      call check(error, hit%visits <= 2**13 .and. hit%visits < max_visits, 'line in the surface: bounded work')
   end subroutine test_line_in_surface

   !> Slab entry of the line x0 + t n into the box [lo, hi] for t >= 0 (huge
   !> if none); margin: how far the entry is from an edge (exit - entry and
   !> the gap to the second-latest slab).
   pure subroutine box_entry(x0, n, lo, hi, t, margin)
      real(wp), intent(in) :: x0(3), n(3), lo(3), hi(3)
      real(wp), intent(out) :: t, margin
      real(wp) :: t1(3), t2(3), t_in(3), t_out
      integer :: k

      do k = 1, 3
         if (abs(n(k)) < 1.0e-12_wp) then
            t_in(k) = merge(-huge(1.0_wp), huge(1.0_wp), x0(k) > lo(k) .and. x0(k) < hi(k))
            t2(k) = -t_in(k)
            cycle
         end if
         t1(k) = (lo(k) - x0(k))/n(k)
         t2(k) = (hi(k) - x0(k))/n(k)
         t_in(k) = min(t1(k), t2(k))
         t2(k) = max(t1(k), t2(k))
      end do
      t_out = minval(t2)
      t = maxval(t_in)
      margin = min(t_out - t, t - maxval(t_in, mask=t_in < t), abs(t))
      if (t > t_out .or. t < 0.0_wp) then
         margin = abs(t - t_out)
         t = huge(1.0_wp)
      end if
   end subroutine box_entry

   !> Lines against a box given as 12 facets (facet_crossing: ray-facet
   !> intersection through the hierarchy) and against the closed-form entry
   !> point: found iff the line enters the box within the search length, at
   !> the same t within the reported tolerance plus a few ulps (as
   !> random_lines_box_cylinder on the primitive box).
   subroutine test_facet_lines(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(ray_hit_type) :: hit
      real(wp), parameter :: length = 10.0_wp, lo(3) = [-1.0_wp, -0.5_wp, -2.0_wp], hi(3) = [1.5_wp, 0.5_wp, 1.0_wp]
      real(wp) :: x0(3), n(3), t_expected, margin
      integer(i8) :: seed
      integer :: k, decided, nhit
      logical :: expect

      call facet_box_body(body, lo, hi, error)
      if (allocated(error)) return
      seed = 2026_i8
      decided = 0
      nhit = 0
      do k = 1, 400
         x0 = 6.0_wp*[random(seed), random(seed), random(seed)] - 3.0_wp
         n = 6.0_wp*[random(seed), random(seed), random(seed)] - 3.0_wp - x0
         n = n/norm2(n)
         if (all(x0 > lo .and. x0 < hi)) cycle
         call box_entry(x0, n, lo, hi, t_expected, margin)
         call facet_crossing(body, 1, 1, x0, n, 0.0_wp, length, .true., hit)
         if (margin < 1.0e-9_wp .or. abs(t_expected - length) < 1.0e-9_wp) cycle
         decided = decided + 1
         expect = t_expected <= length
         call check(error, hit%found .eqv. expect, 'facet line: hit iff it crosses')
         if (allocated(error)) return
         if (.not. expect) cycle
         nhit = nhit + 1
         call check(error, hit%t, t_expected, hit%tolerance + closed_form_ulps*(3.0_wp + t_expected), &
            & 'facet line: t of the entry')
         if (allocated(error)) return
         call check(error, abs(dot_product(hit%normal, n)) > 0.0_wp .and. dot_product(hit%normal, n) <= 0.0_wp, &
            & 'facet line: the normal faces the line')
         if (allocated(error)) return
      end do
      call check(error, decided > 300 .and. nhit > 80 .and. decided - nhit > 80, &
         & 'facet lines: most lines decided, many hits and many misses')
   end subroutine test_facet_lines

   !> Surfaces of a faceted box with groups 'top' (z = hi), 'bottom' and
   !> 'side': a vertical line meets the group asked for only; a back-facing
   !> group only without `facing`; a line through the diagonal edge that
   !> splits the top face is met (closed facets); after an intersect with the
   !> halfspace x >= 0 the top at x < 0 no longer bounds the body; a box
   !> subtracted from a larger one (a cavity) has the flipped normals.
   !> Exact values: every coordinate is a dyadic rational, so t is exact.
   subroutine test_facet_groups(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body, cut, cavity
      type(shape_type) :: s
      type(ray_hit_type) :: hit
      real(wp), parameter :: lo(3) = [-0.5_wp, -0.5_wp, -0.5_wp], hi(3) = [0.5_wp, 0.5_wp, 0.25_wp]
      real(wp), parameter :: down(3) = [0.0_wp, 0.0_wp, -1.0_wp]
      integer :: top, bottom

      call facet_box_body(body, lo, hi, error)
      if (allocated(error)) return
      top = body%surface_index('top')
      bottom = body%surface_index('bottom')
      call check(error, top > 1 .and. bottom > 1 .and. top /= bottom, 'group surface ids')
      if (allocated(error)) return
      call facet_crossing(body, 1, top, [0.125_wp, 0.25_wp, 1.0_wp], down, 0.0_wp, 4.0_wp, .true., hit)
      call check(error, hit%found .and. hit%t == 0.75_wp .and. all(hit%normal == [0.0_wp, 0.0_wp, 1.0_wp]), &
         & 'top group met at z = 0.25')
      if (allocated(error)) return
      call facet_crossing(body, 1, bottom, [0.125_wp, 0.25_wp, 1.0_wp], down, 0.0_wp, 4.0_wp, .true., hit)
      call check(error, .not. hit%found, 'bottom group faces away from a line going down')
      if (allocated(error)) return
      call facet_crossing(body, 1, bottom, [0.125_wp, 0.25_wp, 1.0_wp], down, 0.0_wp, 4.0_wp, .false., hit)
      call check(error, hit%found .and. hit%t == 1.5_wp, 'bottom group met at z = -0.5 without facing')
      if (allocated(error)) return
      ! the top face's two triangles share the diagonal x = y
      call facet_crossing(body, 1, top, [0.375_wp, 0.375_wp, 1.0_wp], down, 0.0_wp, 4.0_wp, .true., hit)
      call check(error, hit%found .and. hit%t == 0.75_wp, 'a line through the edge between two facets')
      if (allocated(error)) return
      cut = body
      call new_halfspace(s, 'sym', [0.0_wp, 0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call cut%add_shape(csg_intersect, s, error)
      if (allocated(error)) return
      ! the group ids follow the shapes: the cut body's differ from the box's
      top = cut%surface_index('top')
      call facet_crossing(cut, 1, top, [-0.125_wp, 0.25_wp, 1.0_wp], down, 0.0_wp, 4.0_wp, .true., hit)
      call check(error, .not. hit%found, 'top cut away at x < 0 does not bound the body')
      if (allocated(error)) return
      call facet_crossing(cut, 1, top, [0.125_wp, 0.25_wp, 1.0_wp], down, 0.0_wp, 4.0_wp, .true., hit)
      call check(error, hit%found .and. hit%t == 0.75_wp, 'top kept at x > 0')
      if (allocated(error)) return
      call new_body(cavity, 'cavity')
      call new_box(s, 'outer', [-2.0_wp, -2.0_wp, -2.0_wp], [2.0_wp, 2.0_wp, 2.0_wp], error)
      if (allocated(error)) return
      call cavity%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call cavity%add_shape(csg_subtract, body%shapes(1), error)
      if (allocated(error)) return
      call facet_crossing(cavity, 2, cavity%surface_index('top'), [0.125_wp, 0.25_wp, 0.0_wp], -down, 0.0_wp, &
         & 4.0_wp, .true., hit)
      call check(error, hit%found .and. hit%t == 0.25_wp .and. all(hit%normal == [0.0_wp, 0.0_wp, -1.0_wp]), &
         & 'cavity roof met from inside with the flipped normal')
   end subroutine test_facet_groups

   !> A body of one faceted box [lo, hi] of 12 triangles, outward, in the
   !> groups 'top' (z = hi), 'bottom' (z = lo) and 'side'.
   subroutine facet_box_body(body, lo, hi, error)
      type(body_type), intent(out) :: body
      real(wp), intent(in) :: lo(3), hi(3)
      type(error_type), allocatable, intent(out) :: error
      ! corners: bit 0 x, bit 1 y, bit 2 z; each face counter-clockwise from outside
      integer, parameter :: quads(4, 6) = reshape([1, 3, 4, 2, 5, 6, 8, 7, 1, 2, 6, 5, 3, 7, 8, 4, 1, 5, 7, 3, &
         & 2, 4, 8, 6], [4, 6])
      integer, parameter :: face_group(6) = [2, 1, 3, 3, 3, 3]
      type(facet_set_type) :: set
      type(shape_type) :: s
      integer :: i, f

      set%dim = 3
      set%nvert = 8
      set%nfacet = 12
      allocate (set%vert(3, 8), set%facet(3, 12), set%group(12), set%file_index(12))
      do i = 1, 8
         set%vert(:, i) = merge(hi, lo, [btest(i - 1, 0), btest(i - 1, 1), btest(i - 1, 2)])
      end do
      do f = 1, 6
         set%facet(:, 2*f - 1) = quads([1, 2, 3], f)
         set%facet(:, 2*f) = quads([1, 3, 4], f)
         set%group(2*f - 1:2*f) = face_group(f)
      end do
      set%file_index = [(f - 1, f=1, 12)]
      set%group_name = [character(len=64) :: 'top', 'bottom', 'side']
      set%source = 'test box'
      call new_facet_shape(s, 'box', set, error)
      if (allocated(error)) return
      call new_body(body, 'faceted')
      call body%add_shape(csg_add, s, error)
   end subroutine facet_box_body

   !> g = g0 + (u_m - u_s).n_s on the shaft-in-hub pair: a common rigid
   !> translation leaves g = g0; the hub moved by d changes g by d.n_s; the
   !> shaft expanded radially by e (u_s = e x) closes the gap by e |x|; an
   !> open point keeps g = huge; wrong shapes and a missing initial_gaps are
   !> errors. Round-off tier on O(1) quantities.
   subroutine test_linearized_gap(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: shaft, hub
      type(grid_type) :: grid, hub_grid
      type(contact_surface_type) :: surf, fresh
      type(shape_type) :: s
      type(error_type), allocatable :: e
      real(wp), allocatable :: us(:, :), um(:, :), g(:)
      real(wp), parameter :: d(2) = [0.003_wp, -0.002_wp], expansion = 1.0e-3_wp, tol = 16.0_wp*epsilon(1.0_wp)
      integer :: i

      call make_disk_body(shaft, 'shaft', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call slave_points(shaft, [-1.3_wp, -1.3_wp], 2.6_wp, 3, 0, surf, grid, error)
      if (allocated(error)) return
      call make_disk_body(hub, 'hub', 'outer', [0.0_wp, 0.0_wp], 2.0_wp, error)
      if (allocated(error)) return
      call new_disk(s, 'bore', [0.0_wp, 0.0_wp], 1.1_wp, error)
      if (allocated(error)) return
      call hub%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call hub_grid%build(hub, 2, [-2.1_wp, -2.2_wp], 4.3_wp, 3, 0, error)
      if (allocated(error)) return
      fresh = surf
      call initial_gaps(surf, hub, 2, hub_grid, 1.0_wp, error)
      if (allocated(error)) return
      allocate (us(2, surf%npoint), um(2, surf%npoint), g(surf%npoint))
      us = spread(d, 2, surf%npoint)
      um = us
      call linearized_gap(surf, us, um, g, error)
      if (allocated(error)) return
      call check(error, maxval(abs(g - surf%g0)), 0.0_wp, tol, 'rigid translation of both: g = g0')
      if (allocated(error)) return
      us = 0.0_wp
      call linearized_gap(surf, us, um, g, error)
      if (allocated(error)) return
      do i = 1, surf%npoint
         call check(error, g(i), surf%g0(i) + dot_product(d, surf%normal(:, i)), tol, 'hub moved by d')
         if (allocated(error)) return
      end do
      us = expansion*surf%x
      um = 0.0_wp
      call linearized_gap(surf, us, um, g, error)
      if (allocated(error)) return
      do i = 1, surf%npoint
         call check(error, g(i), surf%g0(i) - expansion*norm2(surf%x(:, i)), tol, 'shaft expanded')
         if (allocated(error)) return
      end do
      surf%has_master(1) = .false.
      surf%g0(1) = huge(1.0_wp)
      call linearized_gap(surf, us, um, g, error)
      if (allocated(error)) return
      call check(error, g(1) == huge(1.0_wp), 'open point keeps g = huge')
      if (allocated(error)) return
      call linearized_gap(surf, us(:, 2:), um, g, e)
      call expect_error(error, e, 'displacements must be (2, ', 'wrong displacement shape')
      if (allocated(error)) return
      call linearized_gap(fresh, us, um, g, e)
      call expect_error(error, e, 'initial_gaps has not been called', 'no initial gaps')
   end subroutine test_linearized_gap

   ! ------------------------------------------------------------------ errors

   subroutine test_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_surface_type) :: surf
      type(body_type) :: disk, ball
      type(grid_type) :: grid
      type(shape_type) :: s
      type(cut_quadrature_type) :: quad
      type(error_type), allocatable :: e
      real(wp) :: x(2, 1), n(2, 1)

      x(:, 1) = [0.0_wp, 0.0_wp]
      n(:, 1) = [1.0_wp, 1.0_wp]
      call new_contact_surface(surf, x, [1.0_wp], n, [integer ::], e)
      call expect_error(error, e, 'normal of point 1 is not a unit vector', 'bad normal')
      if (allocated(error)) return
      n(:, 1) = [1.0_wp, 0.0_wp]
      call new_contact_surface(surf, x, [0.0_wp], n, [integer ::], e)
      call expect_error(error, e, 'finite and > 0', 'zero weight')
      if (allocated(error)) return
      call new_contact_surface(surf, x, [1.0_wp, 1.0_wp], n, [integer ::], e)
      call expect_error(error, e, '1 points but 2 weights', 'sizes')
      if (allocated(error)) return
      call new_contact_surface(surf, x, [1.0_wp], n, [integer ::], error)
      if (allocated(error)) return
      call make_disk_body(disk, 'disk', 'rim', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call grid%build(disk, 2, [-1.5_wp, -1.5_wp], 3.0_wp, 2, 0, error)
      if (allocated(error)) return
      call initial_gaps(surf, disk, 2, grid, 1.0_wp, e)
      call expect_error(error, e, "surface 2 of master body 'disk' does not exist", 'surface index')
      if (allocated(error)) return
      call initial_gaps(surf, disk, 1, grid, 0.0_wp, e)
      call expect_error(error, e, 'search_distance must be finite and > 0', 'distance 0')
      if (allocated(error)) return
      call new_body(ball, 'ball')
      call new_sphere(s, 'surface', [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call ball%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call initial_gaps(surf, ball, 1, grid, 1.0_wp, e)
      call expect_error(error, e, 'slave points are 2D, the master body 3D', 'dimensions')
      if (allocated(error)) return
      ! A subtracted disk far outside the body bounds nothing.
      call new_disk(s, 'far', [10.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call disk%add_shape(csg_subtract, s, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, q, error)
      if (allocated(error)) return
      call slave_surface_points(surf, grid, disk, quad, 2, e)
      call expect_error(error, e, "surface 'far' of body 'disk' has no quadrature points", &
         & 'surface without points')
      if (allocated(error)) return
      call slave_surface_points(surf, grid, disk, quad, 3, e)
      call expect_error(error, e, "surface 3 of body 'disk' does not exist", 'slave surface index')
      if (allocated(error)) return
   end subroutine test_errors

   ! ----------------------------------------------------------------- helpers

   subroutine make_disk_body(body, name, shape_name, center, radius, error)
      type(body_type), intent(out) :: body
      character(len=*), intent(in) :: name, shape_name
      real(wp), intent(in) :: center(2), radius
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, name)
      call new_disk(s, shape_name, center, radius, error)
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
   end subroutine make_disk_body

   !> The slave points of shape 1 of `body` on its grid.
   subroutine slave_points(body, box_min, box_size, level, refine, surf, grid, error)
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: box_min(:), box_size
      integer, intent(in) :: level, refine
      type(contact_surface_type), intent(out) :: surf
      type(grid_type), intent(out) :: grid
      type(error_type), allocatable, intent(out) :: error
      type(cut_quadrature_type) :: quad

      call grid%build(body, body%dim, box_min, box_size, level, refine, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, body%dim, q, error)
      if (allocated(error)) return
      call slave_surface_points(surf, grid, body, quad, 1, error)
   end subroutine slave_points

end module sprc_test_contact_surface
