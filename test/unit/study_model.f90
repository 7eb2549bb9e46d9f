!> Tests of the scene -> geometry bodies and exact solution glue.
module sprc_test_model
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, stat_invalid_input
   use sprc_geometry_body, only: body_type
   use sprc_geometry_region, only: cell_inside, cell_outside, cell_cut
   use sprc_exact_solution, only: exact_solution_type
   use sprc_io_scene, only: scene_type, read_scene, read_scene_text, default_scene_text
   use sprc_study_model, only: build_bodies, build_exact
   use sprc_study_budget, only: level_memory, check_level_memory
   use sprc_core_memory, only: available_memory
   use sprc_grid_tree, only: grid_type
   use sprc_testsuite, only: unittest_type, new_unittest, check, replaced
   implicit none
   private

   public :: collect_model, replaced

contains

   subroutine collect_model(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('default_scene_body', test_default_body), &
         new_unittest('default_scene_exact_pressure', test_default_exact), &
         new_unittest('kirsch_example', test_kirsch_example), &
         new_unittest('lame_sphere_example', test_sphere_example), &
         new_unittest('no_exact_group', test_no_exact), &
         new_unittest('facade_reexports', test_facade), &
         new_unittest('grid_quarter_annulus', test_grid_annulus), &
         new_unittest('grid_sphere_octant', test_grid_octant), &
         new_unittest('body_beyond_box', test_body_beyond_box), &
         new_unittest('level_memory_estimate', test_level_memory), &
         new_unittest('level_memory_follows_solver', test_level_memory_solver), &
         new_unittest('auto_iterative_when_direct_does_not_fit', test_level_memory_fallback) &
         ]
   end subroutine collect_model

   subroutine load(path, scene, error)
      character(len=*), intent(in) :: path
      type(scene_type), intent(out) :: scene
      type(error_type), allocatable, intent(out) :: error
      if (len(path) == 0) then
         call read_scene_text(default_scene_text(), 'default', scene, error)
      else
         call read_scene(path, scene, error)
      end if
   end subroutine load

   !> Quarter annulus 5 < r < 20, x >= 0, y >= 0: points and boxes with known answers.
   subroutine test_default_body(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)

      call load('', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call check(error, size(bodies) == 1 .and. bodies(1)%nshape == 4, 'one body with four shapes')
      if (allocated(error)) return
      call check(error, bodies(1)%phi([10.0_wp, 10.0_wp]) < 0.0_wp, 'r = 14.1 in the first quadrant is inside')
      if (allocated(error)) return
      call check(error, bodies(1)%phi([1.0_wp, 1.0_wp]) > 0.0_wp .and. bodies(1)%phi([-10.0_wp, 10.0_wp]) > 0.0_wp &
         .and. bodies(1)%phi([15.0_wp, 15.0_wp]) > 0.0_wp, 'hole, mirrored quadrant and r = 21.2 are outside')
      if (allocated(error)) return
      call check(error, bodies(1)%classify_box([8.0_wp, 8.0_wp], [9.0_wp, 9.0_wp]), cell_inside, 'box inside')
      if (allocated(error)) return
      call check(error, bodies(1)%classify_box([-1.0_wp, 8.0_wp], [0.0_wp, 9.0_wp]), cell_outside, &
         'box beyond the symmetry plane x = 0')
      if (allocated(error)) return
      call check(error, bodies(1)%classify_box([19.0_wp, 0.0_wp], [21.0_wp, 1.0_wp]), cell_cut, 'box on r = 20')
   end subroutine test_default_body

   !> A body with material outside the box is an input error naming body and box (the grid
   !> would clip it: box 15 around the radius-20 quarter cylinder gave area 203.9, not
   !> 294.5); a body touching the box (quarter model on x = 0, y = 0; 3D octant; a disk
   !> tangent to the box edge x = 25) is accepted.
   subroutine test_body_beyond_box(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)
      type(error_type), allocatable :: e
      character(len=:), allocatable :: text

      text = default_scene_text()
      call read_scene_text(replaced(text, 'box_size = 25.0', 'box_size = 15.0'), 'small box', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, e)
      call check(error, allocated(e), 'box 15 around r = 20 rejected')
      if (allocated(error)) return
      call check(error, index(e%message, "body 'cylinder' extends beyond the scene's box 0..15 x 0..15") > 0 &
         & .and. index(e%message, 'enlarge box_size') > 0, 'message names body, box and remedy: '//e%message)
      if (allocated(error)) return
      call check(error, e%stat, stat_invalid_input, 'status')
      if (allocated(error)) return
      ! The body's own box is the one it must fit: box 25 of its own inside the scene's
      ! box 15 is accepted, its own box 15 inside the scene's 25 is refused naming it.
      call read_scene_text(replaced(replaced(text, 'box_size = 25.0', 'box_size = 15.0'), "young=1000.0", &
         & "box_min=0,0 box_size=25 young=1000.0"), 'own box', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call read_scene_text(replaced(text, "young=1000.0", "box_min=0,0 box_size=15 young=1000.0"), 'small own box', &
         & scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, e)
      call check(error, allocated(e), 'own box 15 around r = 20 rejected')
      if (allocated(error)) return
      call check(error, index(e%message, "body 'cylinder' extends beyond its own box 0..15 x 0..15 (&body: "// &
         & 'box_min, box_size)') > 0, 'message names the body''s own box: '//e%message)
      if (allocated(error)) return
      ! r = 20 shifted to touch x = 25: tangent, no material beyond
      call read_scene_text(replaced(replaced(text, 'center=0,0 radius=20', 'center=5,0 radius=20'), &
         & "point=0,0 normal=-1,0", "point=5,0 normal=-1,0"), 'tangent', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call load('example/scenes/lame_sphere.nml', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call load('example/scenes/kirsch_plate.nml', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
   end subroutine test_body_beyond_box

   !> The cell estimate of a level (sprc_io_budget) bounds the active cells of the grid
   !> built at that level from above, within 1.5x (Lame sphere octant level 5, cylinder
   !> quarter level 8 with refine_boundary 1); available_memory is known on Linux; a 3D
   !> level 9 (1e8 cells, terabytes) is refused naming the estimate and what is available.
   subroutine test_level_memory(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)
      type(grid_type) :: grid
      type(error_type), allocatable :: e
      real(wp) :: cells, dofs, bytes, actual
      integer(i8) :: avail
      character(len=:), allocatable :: source
      integer :: k

      call available_memory(avail, source)
      call check(error, avail > 0, 'available memory known on Linux, from '//source)
      if (allocated(error)) return
      do k = 1, 2
         if (k == 1) then
            call load('example/scenes/lame_sphere.nml', scene, error)
         else
            call read_scene_text(replaced(default_scene_text(), 'refine_boundary = 0', 'refine_boundary = 1'), &
               & 'rb1', scene, error)
         end if
         if (allocated(error)) return
         call build_bodies(scene, bodies, error)
         if (allocated(error)) return
         call level_memory(scene, bodies(1), merge(5, 8, k == 1), cells, dofs, bytes, error)
         if (allocated(error)) return
         call grid%build(bodies(1), scene%dim, scene%box_min, scene%box_size, merge(5, 8, k == 1), &
            & scene%refine_boundary, error)
         if (allocated(error)) return
         actual = real(sum(grid%n_inside) + sum(grid%n_cut), wp)
         call check(error, cells >= actual .and. cells <= 1.5_wp*actual, 'cell estimate within [1, 1.5] of the '// &
            & 'grid''s active cells')
         if (allocated(error)) return
         call check(error, bytes > 0.0_wp, 'positive estimate')
         if (allocated(error)) return
      end do
      call load('example/scenes/lame_sphere.nml', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call check_level_memory(scene, bodies(1), 9, e)
      call check(error, allocated(e), '3D level 9 refused')
      if (allocated(error)) return
      call check(error, index(e%message, 'needs about') > 0 .and. index(e%message, 'is available') > 0 .and. &
         & index(e%message, 'use a lower level') > 0, 'message: '//e%message)
   end subroutine test_level_memory

   !> A 3D level sent to the iterative solver is estimated without a Cholesky
   !> factor (sprc_study_budget: 32 MB + 8 kB per dof for Q1), a direct one with
   !> it (larger from 3e4 dofs on); 'auto' follows the size (iterative here).
   subroutine test_level_memory_solver(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)
      real(wp) :: cells, dofs, bytes(3)
      integer :: k
      character(len=9), parameter :: choice(3) = [character(len=9) :: 'direct', 'iterative', 'auto']

      call load('example/scenes/lame_sphere.nml', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      do k = 1, 3
         scene%solver = trim(choice(k))
         call level_memory(scene, bodies(1), 7, cells, dofs, bytes(k), error)
         if (allocated(error)) return
      end do
      call check(error, dofs > 1.0e5_wp, '3D level 7 above the auto threshold')
      if (allocated(error)) return
      call check(error, abs(bytes(2) - (32.0e6_wp + 8.0e3_wp*dofs)) <= 1.0e-12_wp*bytes(2), &
         & 'iterative: 32 MB + 8 kB per dof')
      if (allocated(error)) return
      call check(error, bytes(1) > 2.0_wp*bytes(2), 'direct estimate with the Cholesky fill')
      if (allocated(error)) return
      call check(error, bytes(3) == bytes(2), 'auto takes the iterative estimate at this size')
   end subroutine test_level_memory_solver

   !> 'auto' for 3D Q2 (direct at any size, `auto_min_dofs`; Lame sphere octant,
   !> level 4) takes the direct estimate when it fits in the memory given, and
   !> the iterative one (32 MB + 1.75 x 8 kB per dof) when one byte less is
   !> available; 'direct' keeps the direct estimate (the level is then refused
   !> by check_level_memory).
   subroutine test_level_memory_fallback(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)
      real(wp) :: cells, dofs, direct, bytes, iterative
      logical :: fits

      call load('example/scenes/lame_sphere.nml', scene, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      scene%order = 2
      scene%solver = 'auto'
      call level_memory(scene, bodies(1), 4, cells, dofs, direct, error, available=huge(1_i8), direct_fits=fits)
      if (allocated(error)) return
      iterative = 32.0e6_wp + 1.75_wp*8.0e3_wp*dofs
      call check(error, fits .and. direct > iterative, 'room for it: the direct estimate, above the iterative one')
      if (allocated(error)) return
      call level_memory(scene, bodies(1), 4, cells, dofs, bytes, error, available=int(direct, i8) - 1, &
         & direct_fits=fits)
      if (allocated(error)) return
      call check(error, .not. fits .and. abs(bytes - iterative) <= 1.0e-12_wp*bytes, &
         & 'no room for the direct solve: auto takes the iterative estimate')
      if (allocated(error)) return
      scene%solver = 'direct'
      call level_memory(scene, bodies(1), 4, cells, dofs, bytes, error, available=int(direct, i8) - 1)
      if (allocated(error)) return
      call check(error, bytes == direct, 'direct keeps its estimate')
   end subroutine test_level_memory_fallback

   !> t = sigma.n = -p_in n on the inner surface (n = (-1, 0) at (5, 0)): t = (1, 0).
   subroutine test_default_exact(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_solution_type), allocatable :: exact
      real(wp) :: t(2)

      call load('', scene, error)
      if (allocated(error)) return
      call build_exact(scene, 1, exact, error)
      if (allocated(error)) return
      call check(error, allocated(exact), 'exact solution built')
      if (allocated(error)) return
      call exact%traction([5.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], t)
      call check(error, abs(t(1) - 1.0_wp) + abs(t(2)), 0.0_wp, 1.0e-14_wp, 'inner pressure traction')
      if (allocated(error)) return
      call check(error, exact%young, 1000.0_wp, 0.0_wp, 'material of the first body')
   end subroutine test_default_exact

   !> Kirsch: sigma_xx = 3 s_inf at the top of the hole; the body excludes the hole.
   subroutine test_kirsch_example(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_solution_type), allocatable :: exact
      type(body_type), allocatable :: bodies(:)
      real(wp) :: sigma(3)

      call load('example/scenes/kirsch_plate.nml', scene, error)
      if (allocated(error)) return
      call build_exact(scene, 1, exact, error)
      if (allocated(error)) return
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call exact%stress([scene%exact%center(1), scene%exact%center(2) + scene%exact%radius], sigma)
      call check(error, sigma(1), 3.0_wp*scene%exact%s_inf, 1.0e-12_wp, 'stress concentration', rel=.true.)
      if (allocated(error)) return
      call check(error, bodies(1)%phi(scene%exact%center + 0.5_wp*scene%exact%radius) > 0.0_wp, &
         'the hole is outside the body')
   end subroutine test_kirsch_example

   !> Lame sphere: sigma.n = -p_in n at r_in along x.
   subroutine test_sphere_example(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_solution_type), allocatable :: exact
      real(wp) :: t(3), x(3)

      call load('example/scenes/lame_sphere.nml', scene, error)
      if (allocated(error)) return
      call build_exact(scene, 1, exact, error)
      if (allocated(error)) return
      x = scene%exact%center + [scene%exact%r_in, 0.0_wp, 0.0_wp]
      call exact%traction(x, [-1.0_wp, 0.0_wp, 0.0_wp], t)
      call check(error, maxval(abs(t - [scene%exact%p_in, 0.0_wp, 0.0_wp])), 0.0_wp, &
         1.0e-13_wp*abs(scene%exact%p_in), 'inner pressure traction')
   end subroutine test_sphere_example

   subroutine test_no_exact(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_solution_type), allocatable :: exact
      character(len=*), parameter :: text = &
         "&scene analysis='plane_stress' levels=2 box_min=0,0 box_size=1 /"//new_line('a')// &
         "&body name='b' young=1 poisson=0.2 /"//new_line('a')// &
         "&shape body='b' op='add' kind='box' name='sq' lower=0.1,0.1 upper=0.9,0.9 /"//new_line('a')

      call read_scene_text(text, 'inline', scene, error)
      if (allocated(error)) return
      call build_exact(scene, 1, exact, error)
      if (allocated(error)) return
      call check(error, .not. allocated(exact), 'no exact solution without &exact')
   end subroutine test_no_exact

   !> `use sprc` alone is enough to read a scene and build its objects.
   subroutine test_facade(error)
      use sprc, only: sprc_scene => scene_type, sprc_read => read_scene_text, sprc_text => default_scene_text, &
         & sprc_bodies => build_bodies, geometry_body_type, sprc_version_number, get_sprc_version
      type(error_type), allocatable, intent(out) :: error
      type(sprc_scene) :: scene
      type(geometry_body_type), allocatable :: bodies(:)
      integer :: major, minor, patch

      call sprc_read(sprc_text(), 'default', scene, error)
      if (allocated(error)) return
      call sprc_bodies(scene, bodies, error)
      if (allocated(error)) return
      call get_sprc_version(major, minor, patch)
      call check(error, sprc_version_number, 10000*major + 100*minor + patch, 'version number')
   end subroutine test_facade

   subroutine test_grid_annulus(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      call load('', scene, error)
      if (allocated(error)) return
      call check_scene_grid(scene, 5, 2, 2, error)
   end subroutine test_grid_annulus

   subroutine test_grid_octant(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      call load('example/scenes/lame_sphere.nml', scene, error)
      if (allocated(error)) return
      call check_scene_grid(scene, 3, 1, 2, error)
   end subroutine test_grid_octant

   !> The grid of a quarter/octant model against brute force: every leaf's
   !> class agrees with samples of the level set on a 6^dim lattice in its box
   !> (inside: no sample outside; cut: found so by the certified ranges, and
   !> only the curved shapes 1..ncurved may cut it — the symmetry planes lie on
   !> grid planes and must never produce a cut).
   subroutine check_scene_grid(scene, level, refine, ncurved, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: level, refine, ncurved
      type(error_type), allocatable, intent(out) :: error
      type(body_type), allocatable :: bodies(:)
      type(grid_type) :: grid
      real(wp) :: lo(3), hi(3), x(3), t(3)
      integer :: leaf, list(8), n, k, dim, ncut
      character(len=80) :: msg

      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      dim = scene%dim
      call grid%build(bodies(1), dim, scene%box_min, scene%box_size, level, refine, error)
      if (allocated(error)) return
      ncut = 0
      do leaf = 1, grid%n_leaves
         call grid%leaf_box(leaf, lo(1:dim), hi(1:dim))
         if (grid%leaf_class(leaf) == cell_cut) then
            ncut = ncut + 1
            call bodies(1)%active_shapes(lo(1:dim), hi(1:dim), list, n)
            write (msg, '("leaf ",i0," is cut by a symmetry plane")') leaf
            call check(error, n > 0 .and. all(list(1:n) <= ncurved), trim(msg))
            if (allocated(error)) return
            cycle
         end if
         do k = 0, 6**dim - 1
            t(1:dim) = real(mod([(k/6**(n - 1), n = 1, dim)], 6), wp)/5.0_wp
            x(1:dim) = lo(1:dim) + t(1:dim)*(hi(1:dim) - lo(1:dim))
            write (msg, '("internal leaf ",i0," has a sample outside the body")') leaf
            call check(error, bodies(1)%phi(x(1:dim)) <= 1.0e-12_wp*scene%box_size, trim(msg))
            if (allocated(error)) return
         end do
      end do
      call check(error, ncut > 0 .and. ncut == sum(grid%n_cut), 'cut leaves counted')
   end subroutine check_scene_grid

end module sprc_test_model
