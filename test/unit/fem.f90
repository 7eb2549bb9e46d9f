!> Tests of the FE layer: Q1/Q2 elements, constraints (hanging nodes, cell
!> aggregation, strong symmetry), immersed boundary conditions (Neumann by
!> surface quadrature, Nitsche), solve, post-processing and error paths.
!>
!> Independent references: closed-form Lagrange properties and finite
!> differences for the elements; polynomial displacement fields defined here
!> (`poly_field_type`, stress from the material law, body force from exact
!> differences of a linear stress) that the FE space contains, so the discrete
!> solution must equal them to round-off (patch tests); the Lame and Kirsch
!> analytical solutions (sprc_exact_*) for convergence rates; the known
!> number of rigid-body modes.
module sprc_test_fem
   !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: stat_invalid_input, stat_singular
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, material_matrix
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_halfspace, new_box
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_grid_nodes, only: element_node_index
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, default_points
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_exact_solution, only: exact_solution_type, init_exact_solution
   use sprc_exact_lame, only: lame_cylinder_type, new_lame_cylinder, lame_sphere_type, new_lame_sphere
   use sprc_exact_kirsch, only: kirsch_type, new_kirsch
   use sprc_fem_element, only: shape_functions
   use sprc_fem_bc, only: fe_bc_type, new_fe_bc, bc_free, bc_pressure, bc_traction, bc_displacement, &
      & bc_symmetry, bc_exact_traction, bc_exact_displacement
   use sprc_fem_problem, only: elasticity_problem_type, solve_on_grid
   use sprc_estimate_fe_input, only: fe_recovery_input
   use sprc_estimate_patches, only: recovery_input_type, rec_none => bc_none, rec_traction => bc_traction, &
      & rec_pressure => bc_pressure, rec_symmetry => bc_symmetry
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type, full_tier
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_shape, only: new_facet_shape
   use sprc_test_facets, only: facets_box, facets_polygon
   implicit none
   private

   public :: collect_fem
   ! shared with test_dilatation
   public :: poly_field_type, new_poly_field, polygon_2d, polygon_3d, lame_quarter, sphere_octant, make_body, &
      & field_errors, young, kirsch_quarter, small_cut_sweep, lame_cut, cut_body_builder

   real(wp), parameter :: young = 1000.0_wp, poisson = 0.3_wp

   !> Backward error of assembly plus Cholesky (or LU) solve, in units of eps ||K||: the
   !> computed u solves a K + dK with ||dK|| <= c_backward eps ||K||, so a field the FE space
   !> holds is reproduced to c_backward eps cond_1(K) relative (`solve_tolerance`). Measured
   !> over the patch tests under the Sandybridge, Haswell and SkylakeX kernels of OpenBLAS:
   !> error / (eps/rcond) <= 0.14; 10 also covers rcond, an upper bound of 1/cond_1 within 3x.
   real(wp), parameter :: c_backward = 10.0_wp

   !> Polynomial displacement u_c(x) = a_c + sum_j g(c, j) x_j + 1/2 sum_jk h(c, j, k) x_j x_k
   !> (h symmetric in j, k); stress from the material law, constant body force
   !> b = -div sigma (sigma is linear, so its differences are exact).
   type, extends(exact_solution_type) :: poly_field_type
      real(wp) :: a(3) = 0.0_wp, g(3, 3) = 0.0_wp, h(3, 3, 3) = 0.0_wp
      real(wp) :: d(6, 6) = 0.0_wp
   contains
      procedure :: stress => poly_stress
      procedure :: displacement => poly_displacement
      procedure :: body_force => poly_body_force
   end type poly_field_type

   abstract interface
      !> The body of a small-cut sweep cut at delta (cell sizes), its conditions
      !> and exact solution for the Poisson ratio nu.
      subroutine cut_body_builder(delta, nu, body, bcs, exact, error)
         import :: wp, body_type, fe_bc_type, exact_solution_type, error_type
         real(wp), intent(in) :: delta, nu
         type(body_type), intent(out) :: body
         type(fe_bc_type), allocatable, intent(out) :: bcs(:)
         class(exact_solution_type), allocatable, intent(out) :: exact
         type(error_type), allocatable, intent(out) :: error
      end subroutine cut_body_builder
   end interface

contains

   subroutine collect_fem(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('shape_functions', test_shape_functions), &
         new_unittest('patch_linear_2d', test_patch_2d), &
         new_unittest('patch_linear_3d', test_patch_3d), &
         new_unittest('patch_facets', test_patch_facets), &
         new_unittest('patch_strong_symmetry', test_patch_strong_symmetry), &
         new_unittest('patch_weak_symmetry', test_patch_weak_symmetry), &
         new_unittest('quadratic_q2', test_quadratic_q2), &
         new_unittest('q1_misses_quadratic', test_q1_misses_quadratic), &
         new_unittest('convergence_lame', test_convergence_lame), &
         new_unittest('convergence_kirsch', test_convergence_kirsch), &
         new_unittest('convergence_sphere', test_convergence_sphere), &
         new_unittest('small_cuts', test_small_cuts), &
         new_unittest('rigid_modes', test_rigid_modes), &
         new_unittest('bad_inputs', test_bad_inputs), &
         new_unittest('umfpack_fallback', test_umfpack_fallback), &
         new_unittest('threads', test_threads), &
         new_unittest('queries_and_api_errors', test_queries), &
         new_unittest('recovery_input_adapter', test_recovery_input), &
         new_unittest('solve_in_steps', test_solve_in_steps), &
         new_unittest('cut_mesh_handover', test_cut_mesh_handover) &
         ]
   end subroutine collect_fem

   ! ------------------------------------------------------------ fields

   subroutine new_poly_field(self, analysis, a, g, h, error, nu)
      type(poly_field_type), intent(out) :: self
      integer, intent(in) :: analysis
      real(wp), intent(in) :: a(:), g(:, :)
      real(wp), intent(in), optional :: h(:, :, :)
      type(error_type), allocatable, intent(out) :: error
      !> Poisson ratio (default the module's `poisson`).
      real(wp), intent(in), optional :: nu
      integer :: d, ns
      real(wp) :: v
      v = poisson
      if (present(nu)) v = nu
      call init_exact_solution(self, 'poly', analysis, [plane_stress, plane_strain, solid], young, v, error)
      if (allocated(error)) return
      d = self%dim
      ns = self%nstress
      self%a(1:d) = a
      self%g(1:d, 1:d) = g
      if (present(h)) self%h(1:d, 1:d, 1:d) = h
      call material_matrix(analysis, young, v, self%d(1:ns, 1:ns), error)
   end subroutine new_poly_field

   pure subroutine poly_displacement(self, x, v)
      class(poly_field_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      integer :: c, d
      d = self%dim
      do c = 1, d
         v(c) = self%a(c) + dot_product(self%g(c, 1:d), x(1:d)) + &
            & 0.5_wp*dot_product(x(1:d), matmul(self%h(c, 1:d, 1:d), x(1:d)))
      end do
   end subroutine poly_displacement

   pure subroutine poly_stress(self, x, v)
      class(poly_field_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: du(3, 3), eps(6)
      integer :: c, d
      d = self%dim
      do c = 1, d
         du(c, 1:d) = self%g(c, 1:d) + matmul(self%h(c, 1:d, 1:d), x(1:d))
      end do
      if (d == 2) then
         eps(1:3) = [du(1, 1), du(2, 2), du(1, 2) + du(2, 1)]
      else
         eps = [du(1, 1), du(2, 2), du(3, 3), du(1, 2) + du(2, 1), du(2, 3) + du(3, 2), du(1, 3) + du(3, 1)]
      end if
      v(1:self%nstress) = matmul(self%d(1:self%nstress, 1:self%nstress), eps(1:self%nstress))
   end subroutine poly_stress

   pure subroutine poly_body_force(self, x, b)
      class(poly_field_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: b(:)
      real(wp) :: s0(6), s1(6), ds(6, 3), e(3)
      integer :: j, d
      d = self%dim
      call self%stress(x, s0(1:self%nstress))
      do j = 1, d
         e = 0.0_wp
         e(j) = 1.0_wp
         call self%stress(x(1:d) + e(1:d), s1(1:self%nstress))
         ds(1:self%nstress, j) = s1(1:self%nstress) - s0(1:self%nstress)
      end do
      if (d == 2) then
         b(1) = -(ds(1, 1) + ds(3, 2))
         b(2) = -(ds(3, 1) + ds(2, 2))
      else
         b(1) = -(ds(1, 1) + ds(4, 2) + ds(6, 3))
         b(2) = -(ds(4, 1) + ds(2, 2) + ds(5, 3))
         b(3) = -(ds(6, 1) + ds(5, 2) + ds(3, 3))
      end if
   end subroutine poly_body_force

   ! ------------------------------------------------------------ bodies

   !> Body from shapes and ops.
   subroutine make_body(body, shapes, ops, error)
      type(body_type), intent(out) :: body
      type(shape_type), intent(in) :: shapes(:)
      integer, intent(in) :: ops(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      call new_body(body, 'test')
      do i = 1, size(shapes)
         call body%add_shape(ops(i), shapes(i), error)
         if (allocated(error)) return
      end do
   end subroutine make_body

   !> Max nodal |u_h - u_ex| over all nodes relative to max |u_ex|, and err_fe.
   subroutine field_errors(problem, field, unodal, err_fe, error)
      type(elasticity_problem_type), intent(in) :: problem
      class(exact_solution_type), intent(in) :: field
      real(wp), intent(out) :: unodal, err_fe
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: ee(:)
      real(wp) :: ue(3), umax, nfe, nex
      integer :: i, d
      d = problem%dim
      unodal = 0.0_wp
      umax = 0.0_wp
      do i = 1, problem%mesh%nodes%n_nodes
         call field%displacement(problem%mesh%nodes%x(:, i), ue(1:d))
         unodal = max(unodal, maxval(abs(problem%u(:, i) - ue(1:d))))
         umax = max(umax, maxval(abs(ue(1:d))))
      end do
      unodal = unodal/umax
      call problem%energy_error(err_fe, ee, nfe, nex, error)
   end subroutine field_errors

   ! ------------------------------------------------------------ tests

   !> Q1/Q2 shape functions in 2D and 3D: Kronecker property at the nodes
   !> (VTK order), partition of unity and zero gradient sum at a point outside
   !> the box, gradients against central differences (error O(delta^2) ~1e-10).
   subroutine test_shape_functions(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: lo(3), hi(3), x(3), n(27), dn(3, 27), np(27), nm(27), dtmp(3, 27)
      integer, allocatable :: idx(:, :)
      integer :: d, p, j, k, nen
      real(wp), parameter :: delta = 1.0e-5_wp

      lo = [0.5_wp, -1.0_wp, 2.0_wp]
      hi = [0.75_wp, -0.5_wp, 3.0_wp]
      do d = 2, 3
         do p = 1, 2
            nen = (p + 1)**d
            idx = element_node_index(d, p)
            do j = 1, nen
               x(1:d) = lo(1:d) + (hi(1:d) - lo(1:d))*real(idx(:, j), wp)/real(p, wp)
               call shape_functions(d, p, lo(1:d), hi(1:d), x(1:d), n(1:nen), dn(1:d, 1:nen))
               do k = 1, nen
                  call check(error, n(k), merge(1.0_wp, 0.0_wp, k == j), 1.0e-14_wp, 'Kronecker property')
                  if (allocated(error)) return
               end do
            end do
            x(1:d) = [1.1_wp, 0.3_wp, 1.7_wp]
            call shape_functions(d, p, lo(1:d), hi(1:d), x(1:d), n(1:nen), dn(1:d, 1:nen))
            call check(error, sum(n(1:nen)), 1.0_wp, 1.0e-12_wp, 'partition of unity')
            if (allocated(error)) return
            do k = 1, d
               call check(error, sum(dn(k, 1:nen)), 0.0_wp, 1.0e-10_wp, 'gradients sum to zero')
               if (allocated(error)) return
               x(k) = x(k) + delta
               call shape_functions(d, p, lo(1:d), hi(1:d), x(1:d), np(1:nen), dtmp(1:d, 1:nen))
               x(k) = x(k) - 2.0_wp*delta
               call shape_functions(d, p, lo(1:d), hi(1:d), x(1:d), nm(1:nen), dtmp(1:d, 1:nen))
               x(k) = x(k) + delta
               do j = 1, nen
                  call check(error, dn(k, j), (np(j) - nm(j))/(2.0_wp*delta), 1.0e-6_wp*max(1.0_wp, &
                     & abs(dn(k, j))), 'gradient vs central difference')
                  if (allocated(error)) return
               end do
            end do
         end do
      end do
   end subroutine test_shape_functions

   ! ------------------------------------------------------------ patch tests

   !> Solve on `body` and compare with the polynomial `field`: nodal values
   !> (all nodes, through T) and err_fe must be below `solve_tolerance`. The body force is
   !> the field's (constant).
   subroutine run_patch(body, bcs, field, degree, level, rb, what, error, points, gamma, problem_out)
      type(body_type), intent(in) :: body
      type(fe_bc_type), intent(in) :: bcs(:)
      type(poly_field_type), intent(in) :: field
      integer, intent(in) :: degree, level, rb
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: points
      real(wp), intent(in), optional :: gamma
      type(elasticity_problem_type), intent(out), optional :: problem_out
      type(elasticity_problem_type) :: problem
      real(wp) :: unodal, err, b(3), box_min(3), tol
      integer :: d

      d = field%dim
      call field%body_force(spread(0.0_wp, 1, d), b(1:d))
      box_min = -1.0_wp
      call solve_on_grid(problem, body, box_min(1:d), 2.0_wp, level, rb, degree, field%analysis, young, poisson, &
         & b(1:d), bcs, error, exact=field, points=points, gamma=gamma)
      if (allocated(error)) then
         error%message = what//': '//error%message
         return
      end if
      call field_errors(problem, field, unodal, err, error)
      if (allocated(error)) return
      tol = solve_tolerance(problem)
      call check(error, unodal, 0.0_wp, tol, what//': field at the nodes (relative)')
      if (allocated(error)) return
      call check(error, err, 0.0_wp, tol, what//': err_fe')
      if (allocated(error)) return
      if (present(problem_out)) problem_out = problem
   end subroutine run_patch

   !> Round-off bound of a solved field relative to its size: c_backward eps / rcond, with the
   !> solver's reciprocal condition estimate of the reduced stiffness. Also bounds the
   !> relative error of the stress: cond_1(K) grows as h^-2, the differentiation costs h^-1.
   real(wp) function solve_tolerance(problem) result(tol)
      type(elasticity_problem_type), intent(in) :: problem
      tol = 0.0_wp
      if (problem%rcond > 0.0_wp) tol = c_backward*epsilon(1.0_wp)/problem%rcond
   end function solve_tolerance

   !> 2D polygonal body: box cut by two inclined planes (planes are integrated
   !> exactly by the cut quadrature, so the patch test is exact to round-off).
   subroutine polygon_2d(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s(3)
      call new_box(s(1), 'box', [-0.83_wp, -0.77_wp], [0.79_wp, 0.81_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(2), 'cut1', [0.3_wp, 0.2_wp], [0.6_wp, 0.8_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(3), 'cut2', [-0.4_wp, 0.1_wp], [-0.8_wp, 0.6_wp], error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add, csg_intersect, csg_intersect], error)
   end subroutine polygon_2d

   subroutine polygon_3d(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s(3)
      call new_box(s(1), 'box', [-0.83_wp, -0.77_wp, -0.71_wp], [0.79_wp, 0.81_wp, 0.74_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(2), 'cut1', [0.3_wp, 0.2_wp, 0.1_wp], [0.48_wp, 0.6_wp, 0.64_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(3), 'cut2', [-0.4_wp, 0.1_wp, 0.0_wp], [-0.6_wp, 0.0_wp, 0.8_wp], error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add, csg_intersect, csg_intersect], error)
   end subroutine polygon_3d

   !> Patch test 2D, Q1 and Q2, cut grid with hanging nodes (refine_boundary 1):
   !> exact_displacement (Nitsche) on one cut plane, exact_traction elsewhere.
   !> Tolerance: `solve_tolerance` (eps/rcond is 1e-14 .. 1e-8 for these systems).
   !> The curved case (a disk with an off-centre hole tangent to a grid line)
   !> holds the same tolerance since the quadrature's double roots were fixed.
   subroutine test_patch_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s(2)
      type(poly_field_type) :: field
      integer :: p

      call new_poly_field(field, plane_strain, [0.01_wp, -0.02_wp], &
         & reshape([0.003_wp, -0.001_wp, 0.002_wp, 0.004_wp], [2, 2]), error=error)
      if (allocated(error)) return
      call polygon_2d(body, error)
      if (allocated(error)) return
      do p = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement), &
            & new_fe_bc(3, bc_exact_traction)], field, p, 3, 1, 'polygon 2D Q'//achar(48 + p), error)
         if (allocated(error)) return
      end do
      call new_disk(s(1), 'outer', [0.1_wp, 0.05_wp], 0.77_wp, error)
      if (allocated(error)) return
      call new_disk(s(2), 'hole', [0.02_wp, 0.1_wp], 0.23_wp, error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add, csg_subtract], error)
      if (allocated(error)) return
      do p = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement)], field, p, &
            & 2, 1, 'annulus 2D Q'//achar(48 + p), error, points=8)
         if (allocated(error)) return
      end do
   end subroutine test_patch_2d

   !> Patch test 3D, Q1 and Q2 (as test_patch_2d, polygonal body, level 2 + 1).
   subroutine test_patch_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(poly_field_type) :: field
      integer :: p

      call new_poly_field(field, solid, [0.01_wp, -0.02_wp, 0.005_wp], reshape([0.003_wp, -0.001_wp, 0.002_wp, &
         & 0.004_wp, 0.001_wp, -0.002_wp, 0.0015_wp, 0.0005_wp, -0.003_wp], [3, 3]), error=error)
      if (allocated(error)) return
      call polygon_3d(body, error)
      if (allocated(error)) return
      do p = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement), &
            & new_fe_bc(3, bc_exact_traction)], field, p, 2, 1, 'polygon 3D Q'//achar(48 + p), error)
         if (allocated(error)) return
      end do
   end subroutine test_patch_3d

   !> Patch test on faceted solids, Q1 and Q2: a bar rotated off the grid axes
   !> given as 12 triangles (3D) and as a polygon (2D, plus a non-convex one);
   !> the uniform-strain field imposed on the whole surface (Nitsche), so the
   !> volume rule, the surface rule and its normals must all be consistent
   !> for the FE solution to be the field to round-off (`solve_tolerance`).
   !> The bar with named ends (groups as surfaces) runs Q2 in the full tier
   !> only: the cheap tier has the 3D Q2 bar without groups and the groups at Q1.
   subroutine test_patch_facets(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      type(shape_type) :: s(1)
      type(body_type) :: body
      type(poly_field_type) :: field
      real(wp) :: p(2, 6), a
      integer :: deg, i

      call new_poly_field(field, solid, [0.01_wp, -0.02_wp, 0.005_wp], reshape([0.003_wp, -0.001_wp, 0.002_wp, &
         & 0.004_wp, 0.001_wp, -0.002_wp, 0.0015_wp, 0.0005_wp, -0.003_wp], [3, 3]), error=error)
      if (allocated(error)) return
      call facets_box(set, [0.03_wp, -0.02_wp, 0.01_wp], [0.8_wp, 0.25_wp, 0.3_wp], [0.2_wp, 0.35_wp, 0.4_wp])
      call new_facet_shape(s(1), 'bar', set, error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add], error)
      if (allocated(error)) return
      do deg = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_displacement)], field, deg, 3, 0, &
            & 'facet bar 3D Q'//achar(48 + deg), error)
         if (allocated(error)) return
      end do
      ! the ends (local x faces of facets_box) as named groups: the displacement on
      ! one end, traction on the rest of the bar (the shape's condition)
      set%group(9:10) = 1
      set%group(11:12) = 2
      set%group_name = [character(len=64) :: 'left', 'right']
      call new_facet_shape(s(1), 'bar', set, error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add], error)
      if (allocated(error)) return
      call check(error, body%surface_index('left') == 2 .and. body%surface_index('right') == 3 .and. &
         & body%surface_name(3) == 'right' .and. body%surface_shape(3) == 1 .and. body%nsurface() == 3, &
         & 'surface ids of the groups')
      if (allocated(error)) return
      ! the groups are surfaces whatever the degree: Q2 here in the full tier only
      do deg = 1, merge(2, 1, full_tier())
         call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(body%surface_index('left'), &
            & bc_exact_displacement)], field, deg, 3, 0, 'facet bar with named ends 3D Q'//achar(48 + deg), error)
         if (allocated(error)) return
      end do
      call new_poly_field(field, plane_strain, [0.01_wp, -0.02_wp], &
         & reshape([0.003_wp, -0.001_wp, 0.002_wp, 0.004_wp], [2, 2]), error=error)
      if (allocated(error)) return
      do i = 1, 4
         a = 0.4_wp + (i - 1)*acos(-1.0_wp)/2
         p(:, i) = merge(0.85_wp, 0.3_wp, mod(i, 2) == 1)*[cos(a), sin(a)]
      end do
      call facets_polygon(set, p(:, 1:4))
      call new_facet_shape(s(1), 'bar', set, error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add], error)
      if (allocated(error)) return
      do deg = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_displacement)], field, deg, 4, 1, &
            & 'facet bar 2D Q'//achar(48 + deg), error)
         if (allocated(error)) return
      end do
      call facets_polygon(set, reshape([-0.7_wp, -0.6_wp, 0.65_wp, -0.55_wp, 0.6_wp, 0.03_wp, 0.02_wp, 0.05_wp, &
         & 0.01_wp, 0.7_wp, -0.68_wp, 0.66_wp], [2, 6]))
      call new_facet_shape(s(1), 'L', set, error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add], error)
      if (allocated(error)) return
      do deg = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_displacement)], field, deg, 4, 1, &
            & 'facet L 2D Q'//achar(48 + deg), error)
         if (allocated(error)) return
      end do
   end subroutine test_patch_facets

   !> Strong symmetry: quarter (2D) / octant (3D) of the polygonal body with
   !> symmetry planes x = 0, y = 0 (, z = 0) on grid planes, all else
   !> exact_traction; the field u = diag(a) x has u_k = 0 on x_k = 0 and zero
   !> shear there. Also checks that the planes were imposed strongly (no
   !> Nitsche) and that u_k is exactly zero at nodes on the planes.
   subroutine test_patch_strong_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s(6)
      type(poly_field_type) :: field
      type(elasticity_problem_type) :: problem
      integer :: p, d, k, i
      real(wp) :: g(3, 3)

      do d = 2, 3
         g = 0.0_wp
         g(1, 1) = 0.003_wp
         g(2, 2) = -0.002_wp
         g(3, 3) = 0.001_wp
         if (d == 2) then
            call polygon_2d(body, error)
            call new_poly_field(field, plane_stress, [0.0_wp, 0.0_wp], g(1:2, 1:2), error=error)
         else
            call polygon_3d(body, error)
            call new_poly_field(field, solid, [0.0_wp, 0.0_wp, 0.0_wp], g, error=error)
         end if
         if (allocated(error)) return
         s(1:3) = body%shapes
         do k = 1, d
            g(:, 1) = 0.0_wp
            g(k, 1) = -1.0_wp
            call new_halfspace(s(3 + k), 'sym'//achar(119 + k), spread(0.0_wp, 1, d), g(1:d, 1), error)
            if (allocated(error)) return
         end do
         call make_body(body, s(1:3 + d), [csg_add, (csg_intersect, i = 2, 3 + d)], error)
         if (allocated(error)) return
         do p = 1, 4 - d
            call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_traction), &
               & new_fe_bc(3, bc_exact_traction), (new_fe_bc(3 + k, bc_symmetry), k = 1, d)], field, p, 5 - d, 1, &
               & 'strong symmetry '//achar(48 + d)//'D Q'//achar(48 + p), error, problem_out=problem)
            if (allocated(error)) return
            call check(error, all(problem%strong_shape(4:3 + d)), 'symmetry planes imposed strongly')
            if (allocated(error)) return
            do i = 1, problem%mesh%nodes%n_nodes
               do k = 1, d
                  if (problem%mesh%nodes%x(k, i) /= 0.0_wp) cycle
                  call check(error, problem%u(k, i) == 0.0_wp, 'u_k = 0 on the plane x_k = 0')
                  if (allocated(error)) return
               end do
            end do
         end do
      end do
   end subroutine test_patch_strong_symmetry

   !> Weak (Nitsche) symmetry on two inclined planes through the origin (a
   !> wedge, cut cells along both planes): the dilation u = a x has u.n = 0 on
   !> both and zero shear traction (isotropic stress), and they restrain all
   !> rigid modes. Q1, Q2; tolerance as test_patch_2d.
   subroutine test_patch_weak_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(shape_type) :: s(3)
      type(poly_field_type) :: field
      type(elasticity_problem_type) :: problem
      integer :: p

      call new_box(s(1), 'box', [-0.83_wp, -0.77_wp], [0.79_wp, 0.81_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(2), 'w1', [0.0_wp, 0.0_wp], [0.6_wp, -0.8_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(3), 'w2', [0.0_wp, 0.0_wp], [-0.8_wp, -0.6_wp], error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add, csg_intersect, csg_intersect], error)
      if (allocated(error)) return
      call new_poly_field(field, plane_strain, [0.0_wp, 0.0_wp], reshape([0.002_wp, 0.0_wp, 0.0_wp, 0.002_wp], &
         & [2, 2]), error=error)
      if (allocated(error)) return
      do p = 1, 2
         call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_symmetry), &
            & new_fe_bc(3, bc_symmetry)], field, p, 3, 1, 'weak symmetry Q'//achar(48 + p), error, &
            & problem_out=problem)
         if (allocated(error)) return
         call check(error, .not. any(problem%strong_shape), 'inclined planes are weak')
         if (allocated(error)) return
      end do
   end subroutine test_patch_weak_symmetry

   !> Q2 reproduces a quadratic field with its (constant) body force, 2D and 3D,
   !> cut grid with hanging nodes; Nitsche on one plane, exact traction elsewhere.
   !> 6 points per direction: on a planar cut the lifted integrand of the Q2
   !> stiffness has degree up to 9 in the base coordinates, beyond the default
   !> 4 points' exactness (7); with 6 (exact to 11) the test is round-off.
   subroutine test_quadratic_q2(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(poly_field_type) :: field
      real(wp) :: h(3, 3, 3)
      integer :: c, j, k

      do c = 1, 3
         do j = 1, 3
            do k = j, 3
               h(c, j, k) = 0.001_wp*real(mod(3*c + 5*j + 7*k, 11) - 5, wp)
               h(c, k, j) = h(c, j, k)
            end do
         end do
      end do
      call new_poly_field(field, plane_stress, [0.01_wp, -0.02_wp], &
         & reshape([0.003_wp, -0.001_wp, 0.002_wp, 0.004_wp], [2, 2]), h(1:2, 1:2, 1:2), error)
      if (allocated(error)) return
      call polygon_2d(body, error)
      if (allocated(error)) return
      call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement), &
         & new_fe_bc(3, bc_exact_traction)], field, 2, 3, 1, 'quadratic 2D Q2', error, points=6)
      if (allocated(error)) return
      call new_poly_field(field, solid, [0.01_wp, -0.02_wp, 0.005_wp], reshape([0.003_wp, -0.001_wp, 0.002_wp, &
         & 0.004_wp, 0.001_wp, -0.002_wp, 0.0015_wp, 0.0005_wp, -0.003_wp], [3, 3]), h, error)
      if (allocated(error)) return
      call polygon_3d(body, error)
      if (allocated(error)) return
      call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement), &
         & new_fe_bc(3, bc_exact_traction)], field, 2, 2, 1, 'quadratic 3D Q2', error, points=6)
   end subroutine test_quadratic_q2

   !> The Q1 space cannot hold a quadratic field: the same run must fail the
   !> patch tolerance (this guards against a patch test that cannot fail).
   subroutine test_q1_misses_quadratic(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(poly_field_type) :: field
      type(error_type), allocatable :: patch_error
      real(wp) :: h(2, 2, 2)

      h = 0.0_wp
      h(1, 2, 2) = 0.004_wp
      call new_poly_field(field, plane_stress, [0.0_wp, 0.0_wp], reshape([0.003_wp, -0.001_wp, 0.002_wp, &
         & 0.004_wp], [2, 2]), h, error)
      if (allocated(error)) return
      call polygon_2d(body, error)
      if (allocated(error)) return
      call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement), &
         & new_fe_bc(3, bc_exact_traction)], field, 1, 3, 1, 'quadratic Q1', patch_error)
      call check(error, allocated(patch_error), 'Q1 does not reproduce a quadratic field')
      if (allocated(error)) return
      call check(error, index(patch_error%message, 'field at the nodes') > 0, 'fails on the values')
   end subroutine test_q1_misses_quadratic

   !> The FE -> recovery adapter: the recovery kind of each shape follows its
   !> FE condition (Dirichlet: none; pressure and traction with their data),
   !> the points and weights are the problem's, the stresses the FE stresses
   !> at those points bit for bit; an unsolved problem is refused.
   subroutine test_recovery_input(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      type(elasticity_problem_type) :: problem
      type(recovery_input_type) :: input
      type(error_type), allocatable :: refused
      real(wp), allocatable :: x(:, :), w(:), sigma(:, :)
      integer :: e, q0, q1

      call fe_recovery_input(problem, input, refused)
      if (.not. allocated(refused)) then
         call test_failed(error, 'an unsolved problem was accepted')
         return
      end if
      call check(error, index(refused%message, 'not solved') > 0, 'an unsolved problem is refused: '//refused%message)
      if (allocated(error)) return
      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      bcs = [new_fe_bc(1, bc_exact_displacement), new_fe_bc(2, bc_pressure, value=1.5_wp), &
         & new_fe_bc(3, bc_symmetry), new_fe_bc(4, bc_traction, vector=[0.5_wp, -0.25_wp])]
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 2, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error, exact=exact)
      if (allocated(error)) return
      call fe_recovery_input(problem, input, error)
      if (allocated(error)) return
      call check(error, all(input%bc_kind == [rec_none, rec_pressure, rec_symmetry, rec_traction]), &
         & 'recovery kind of each shape')
      if (allocated(error)) return
      call check(error, input%bc_pressure(2) == 1.5_wp .and. all(input%bc_traction(1:2, 4) == [0.5_wp, -0.25_wp]) &
         & .and. all(input%bc_traction(:, 1:3) == 0.0_wp), 'pressure and traction data')
      if (allocated(error)) return
      call check(error, all(input%bshape == problem%mesh%surf_shape) .and. all(input%bw == problem%mesh%surf_w) .and. &
         & all(input%w == problem%mesh%vol_w) .and. input%young == young .and. input%analysis == plane_strain, &
         & 'points, weights and material are the problem''s')
      if (allocated(error)) return
      do e = 1, problem%mesh%grid%n_leaves
         call problem%element_points(e, x, w, sigma)
         q0 = input%elem_ptr(e)
         q1 = input%elem_ptr(e + 1) - 1
         if (any(input%stress(:, q0:q1) /= sigma) .or. any(input%x(:, q0:q1) /= x)) then
            call test_failed(error, 'the stresses are the FE stresses at the volume points')
            return
         end if
      end do
      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 2, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error, exact=exact)
      if (allocated(error)) return
      call fe_recovery_input(problem, input, error)
      if (allocated(error)) return
      call check(error, all(input%bc_kind == [rec_traction, rec_pressure, rec_symmetry, rec_symmetry]), &
         & 'a shape without a condition is a free (traction 0) surface')
   end subroutine test_recovery_input

   !> setup takes the cut mesh over without a copy: the caller's mesh is gone,
   !> the problem's has the same cells and rules, and the solution has the bits
   !> of solve_on_grid. A missing mesh, a mesh without cell rules and rules of
   !> another dimension are refused (a refused mesh stays with the caller).
   subroutine test_cut_mesh_handover(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      type(elasticity_problem_type) :: problem, reference
      type(cut_mesh_type), allocatable :: mesh
      type(cut_quadrature_type) :: quad, quad3
      type(error_type), allocatable :: refused
      integer :: n_leaves, n_points

      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      call problem%setup(mesh, plane_strain, young, poisson, [0.0_wp, 0.0_wp], bcs, refused, exact=exact)
      call check(error, allocated(refused), 'setup without a mesh is refused')
      if (allocated(error)) return
      call check(error, index(refused%message, 'no mesh') > 0 .and. refused%stat == stat_invalid_input, &
         & 'the message says there is no mesh: '//refused%message)
      if (allocated(error)) return
      allocate (mesh)
      call mesh%build(body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, error)
      if (allocated(error)) return
      deallocate (refused)
      call problem%setup(mesh, plane_strain, young, poisson, [0.0_wp, 0.0_wp], bcs, refused, exact=exact)
      call check(error, allocated(refused) .and. allocated(mesh), 'a mesh without cell rules is refused and kept')
      if (allocated(error)) return
      call check(error, index(refused%message, 'cut-cell rules') > 0, 'the message names the rules: '//refused%message)
      if (allocated(error)) return
      call new_cut_quadrature(quad3, 3, default_points(1), error)
      if (allocated(error)) return
      deallocate (refused)
      call mesh%integrate(quad3, refused)
      call check(error, allocated(refused), '3D rules on a 2D grid are refused')
      if (allocated(error)) return
      call check(error, refused%stat == stat_invalid_input .and. index(refused%message, 'dimension 3') > 0, &
         & 'the message names the dimensions: '//refused%message)
      if (allocated(error)) return
      call new_cut_quadrature(quad, 2, default_points(1), error)
      if (.not. allocated(error)) call mesh%integrate(quad, error)
      if (allocated(error)) return
      n_leaves = mesh%grid%n_leaves
      n_points = size(mesh%vol_w)
      call problem%setup(mesh, plane_strain, young, poisson, [0.0_wp, 0.0_wp], bcs, error, exact=exact)
      if (allocated(error)) return
      call check(error, .not. allocated(mesh) .and. allocated(problem%mesh), 'the problem holds the mesh')
      if (allocated(error)) return
      call check(error, problem%mesh%grid%n_leaves == n_leaves .and. size(problem%mesh%vol_w) == n_points, &
         & 'the same cells and points')
      if (allocated(error)) return
      call problem%solve(error)
      if (allocated(error)) return
      call solve_on_grid(reference, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error, exact=exact)
      if (allocated(error)) return
      call check(error, all(problem%u == reference%u), 'the bits of solve_on_grid')
   end subroutine test_cut_mesh_handover

   !> solve = assemble + solve_reduced + set_solution: the steps repeated on a
   !> solved problem give the same bits; set_solution(2 ubar) gives 2 u
   !> exactly (u = T ubar is linear and doubling is exact); misuse is refused.
   subroutine test_solve_in_steps(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      type(elasticity_problem_type) :: problem, empty
      type(error_type), allocatable :: refused
      real(wp), allocatable :: ubar(:), u(:, :)

      call empty%assemble(refused)
      call check(error, allocated(refused), 'assemble before setup is refused')
      if (allocated(error)) return
      deallocate (refused)
      call empty%solve_reduced(refused)
      call check(error, allocated(refused), 'solve_reduced before assemble is refused')
      if (allocated(error)) return
      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 2, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error, exact=exact)
      if (allocated(error)) return
      ubar = problem%ubar
      u = problem%u
      call problem%assemble(error)
      if (allocated(error)) return
      call check(error, .not. problem%solved, 'a new assembly is not solved yet')
      if (allocated(error)) return
      call problem%solve_reduced(error)
      if (allocated(error)) return
      call check(error, all(problem%ubar == ubar), 'the same reduced solution again')
      if (allocated(error)) return
      call problem%set_solution(2.0_wp*ubar, error)
      if (allocated(error)) return
      call check(error, problem%solved .and. all(problem%u == 2.0_wp*u), 'set_solution(2 ubar) gives 2 u')
      if (allocated(error)) return
      deallocate (refused)
      call problem%set_solution(ubar(2:), refused)
      call check(error, allocated(refused), 'a reduced solution of the wrong size is refused')
      if (allocated(error)) return
      call check(error, index(refused%message, 'unknowns') > 0, 'message: '//refused%message)
   end subroutine test_solve_in_steps

   ! ------------------------------------------------------------ benchmarks with exact solutions

   !> Lame cylinder quarter: disk r=20 minus disk r=5, x >= 0, y >= 0; pressure 1
   !> inside, symmetry planes.
   subroutine lame_quarter(body, bcs, exact, analysis, error, extra_offset, nu)
      type(body_type), intent(out) :: body
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      type(lame_cylinder_type), intent(out) :: exact
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: extra_offset
      !> Poisson ratio (default the module's `poisson`).
      real(wp), intent(in), optional :: nu
      type(shape_type) :: s(5)
      real(wp) :: v
      call new_disk(s(1), 'outer', [0.0_wp, 0.0_wp], 20.0_wp, error)
      if (allocated(error)) return
      call new_disk(s(2), 'inner', [0.0_wp, 0.0_wp], 5.0_wp, error)
      if (allocated(error)) return
      call new_halfspace(s(3), 'sym_x', [0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(4), 'sym_y', [0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], error)
      if (allocated(error)) return
      bcs = [new_fe_bc(2, bc_pressure, value=1.0_wp), new_fe_bc(3, bc_symmetry), new_fe_bc(4, bc_symmetry)]
      if (present(extra_offset)) then
         call new_halfspace(s(5), 'cut', [extra_offset, 0.0_wp], [1.0_wp, 0.0_wp], error)
         if (allocated(error)) return
         call make_body(body, s, [csg_add, csg_subtract, csg_intersect, csg_intersect, csg_intersect], error)
         bcs = [bcs, new_fe_bc(5, bc_exact_traction)]
      else
         call make_body(body, s(1:4), [csg_add, csg_subtract, csg_intersect, csg_intersect], error)
      end if
      if (allocated(error)) return
      v = poisson
      if (present(nu)) v = nu
      call new_lame_cylinder(exact, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, young, v, analysis, error)
   end subroutine lame_quarter

   !> Kirsch quarter plate: box [-10, 10]^2 minus the unit disk, x >= 0, y >= 0;
   !> exact traction on the outer edges (x = 10 and y = 10, on the level-0 box
   !> boundary), free hole, symmetry planes.
   subroutine kirsch_quarter(body, bcs, exact, analysis, error, nu)
      type(body_type), intent(out) :: body
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      type(kirsch_type), intent(out) :: exact
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      !> Poisson ratio (default the module's `poisson`).
      real(wp), intent(in), optional :: nu
      type(shape_type) :: s(4)
      real(wp) :: v
      call new_box(s(1), 'edges', [-10.0_wp, -10.0_wp], [10.0_wp, 10.0_wp], error)
      if (allocated(error)) return
      call new_disk(s(2), 'hole', [0.0_wp, 0.0_wp], 1.0_wp, error)
      if (allocated(error)) return
      call new_halfspace(s(3), 'sym_x', [0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      if (allocated(error)) return
      call new_halfspace(s(4), 'sym_y', [0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], error)
      if (allocated(error)) return
      call make_body(body, s, [csg_add, csg_subtract, csg_intersect, csg_intersect], error)
      if (allocated(error)) return
      bcs = [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_free), new_fe_bc(3, bc_symmetry), &
         & new_fe_bc(4, bc_symmetry)]
      v = poisson
      if (present(nu)) v = nu
      call new_kirsch(exact, [0.0_wp, 0.0_wp], 1.0_wp, 1.0_wp, young, v, analysis, error)
   end subroutine kirsch_quarter

   !> Lame sphere octant of example/scenes/lame_sphere.nml: r 10..20, pressure 1 inside.
   subroutine sphere_octant(body, bcs, exact, error, nu)
      type(body_type), intent(out) :: body
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      type(lame_sphere_type), intent(out) :: exact
      type(error_type), allocatable, intent(out) :: error
      !> Poisson ratio (default the module's `poisson`).
      real(wp), intent(in), optional :: nu
      type(shape_type) :: s(5)
      integer :: k
      real(wp) :: n(3), v
      call new_sphere(s(1), 'outer', [0.0_wp, 0.0_wp, 0.0_wp], 20.0_wp, error)
      if (allocated(error)) return
      call new_sphere(s(2), 'inner', [0.0_wp, 0.0_wp, 0.0_wp], 10.0_wp, error)
      if (allocated(error)) return
      do k = 1, 3
         n = 0.0_wp
         n(k) = -1.0_wp
         call new_halfspace(s(2 + k), 'sym'//achar(119 + k), [0.0_wp, 0.0_wp, 0.0_wp], n, error)
         if (allocated(error)) return
      end do
      call make_body(body, s, [csg_add, csg_subtract, csg_intersect, csg_intersect, csg_intersect], error)
      if (allocated(error)) return
      bcs = [new_fe_bc(2, bc_pressure, value=1.0_wp), (new_fe_bc(2 + k, bc_symmetry), k = 1, 3)]
      v = poisson
      if (present(nu)) v = nu
      call new_lame_sphere(exact, [0.0_wp, 0.0_wp, 0.0_wp], 10.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, young, v, error)
   end subroutine sphere_octant

   !> err_fe at the given levels; rate between the last two must reach
   !> 0.95 p (asymptotic rate p in the energy norm for a smooth solution).
   subroutine check_rate(body, bcs, exact, box_min, box_size, degree, analysis, levels, what, error)
      type(body_type), intent(in) :: body
      type(fe_bc_type), intent(in) :: bcs(:)
      class(exact_solution_type), intent(in) :: exact
      real(wp), intent(in) :: box_min(:), box_size
      integer, intent(in) :: degree, analysis, levels(:)
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      type(elasticity_problem_type) :: problem
      real(wp), allocatable :: ee(:)
      real(wp) :: err(size(levels)), nfe, nex, rate
      integer :: i

      do i = 1, size(levels)
         call solve_on_grid(problem, body, box_min, box_size, levels(i), 0, degree, analysis, young, poisson, &
            & spread(0.0_wp, 1, size(box_min)), bcs, error, exact=exact)
         if (allocated(error)) return
         call problem%energy_error(err(i), ee, nfe, nex, error)
         if (allocated(error)) return
      end do
      rate = log(err(size(levels) - 1)/err(size(levels)))/log(2.0_wp)
      call check(error, rate >= 0.95_wp*real(degree, wp), what//': rate of err_fe below 0.95 p')
   end subroutine check_rate

   !> Lame cylinder, plane strain and plane stress, Q1 and Q2, levels 4, 5 (the
   !> full study, levels 3..6, is in example/bench/fem_convergence.f90).
   subroutine test_convergence_lame(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      integer :: a, p
      integer, parameter :: analyses(2) = [plane_strain, plane_stress]

      do a = 1, 2
         call lame_quarter(body, bcs, exact, analyses(a), error)
         if (allocated(error)) return
         do p = 1, 2
            call check_rate(body, bcs, exact, [0.0_wp, 0.0_wp], 25.0_wp, p, analyses(a), [4, 5], &
               & 'Lame cylinder', error)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_convergence_lame

   !> Kirsch plate, Q1 and Q2, levels 5, 6 (below level 5 the hole of radius 1
   !> spans fewer than 4 cells of h = 0.3125 and the error is pre-asymptotic:
   !> rates 0.84 (Q1) and 0.97 (Q2) from level 4 to 5, then 1.04 and 2.04);
   !> the outer edges on the level-0 box boundary get boundary points: their
   !> measure is 20 (x = 10 and y = 10, 0..10).
   subroutine test_convergence_kirsch(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(kirsch_type) :: exact
      type(elasticity_problem_type) :: problem
      integer :: p

      call kirsch_quarter(body, bcs, exact, plane_stress, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 10.0_wp, 3, 0, 1, plane_stress, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error, exact=exact)
      if (allocated(error)) return
      call check(error, sum(problem%mesh%surf_w, mask=problem%mesh%surf_shape == 1), 20.0_wp, 1.0e-12_wp, &
         & 'measure of the outer edges', rel=.true.)
      if (allocated(error)) return
      do p = 1, 2
         call check_rate(body, bcs, exact, [0.0_wp, 0.0_wp], 10.0_wp, p, plane_stress, [5, 6], 'Kirsch', &
            & error)
         if (allocated(error)) return
      end do
   end subroutine test_convergence_kirsch

   !> Lame sphere octant, Q1, levels 2 and 3 (the study to level 4 is in
   !> example/bench/fem_convergence.f90).
   subroutine test_convergence_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact

      call sphere_octant(body, bcs, exact, error)
      if (allocated(error)) return
      call check_rate(body, bcs, exact, [0.0_wp, 0.0_wp, 0.0_wp], 25.0_wp, 1, solid, [2, 3], 'Lame sphere', error)
   end subroutine test_convergence_sphere

   !> Small cuts: the Lame quarter (level 4, Q1 and Q2) cut by the plane
   !> x = 10 h + delta h with exact traction on it; delta = 1e-1, 1e-6, 1e-12
   !> (cut fractions down to ~1e-12) against delta = 0 (plane on grid lines, no
   !> cut there): `small_cut_sweep`.
   subroutine test_small_cuts(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call small_cut_sweep(lame_cut, poisson, [0.0_wp, 1.0e-1_wp, 1.0e-6_wp, 1.0e-12_wp], [0.0_wp, 0.0_wp], &
            & 25.0_wp, 4, p, plane_strain, error)
         if (allocated(error)) return
      end do
   end subroutine test_small_cuts

   !> The Lame quarter (plane strain, Poisson ratio nu) cut by x = 10 h + delta h,
   !> h the cell of level 4 (a `cut_body_builder`).
   subroutine lame_cut(delta, nu, body, bcs, exact, error)
      real(wp), intent(in) :: delta, nu
      type(body_type), intent(out) :: body
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      class(exact_solution_type), allocatable, intent(out) :: exact
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: lame
      real(wp), parameter :: h = 25.0_wp/16.0_wp
      call lame_quarter(body, bcs, lame, plane_strain, error, extra_offset=10.0_wp*h + delta*h, nu=nu)
      if (allocated(error)) return
      allocate (exact, source=lame)
   end subroutine lame_cut

   !> Small-cut sweep: `build` gives the body cut at each of `deltas` (deltas(1)
   !> = 0: no cut there), solved at `level` with Q`degree`; against delta = 0 a
   !> cut as small as delta must exist, the diagonally scaled condition
   !> estimate stay within 10x and err_fe within 1%.
   subroutine small_cut_sweep(build, nu, deltas, box_min, box_size, level, degree, analysis, error)
      procedure(cut_body_builder) :: build
      real(wp), intent(in) :: nu, deltas(:), box_min(:), box_size
      integer, intent(in) :: level, degree, analysis
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      class(exact_solution_type), allocatable :: exact
      type(elasticity_problem_type) :: problem
      real(wp) :: rc(size(deltas)), err(size(deltas)), nfe, nex
      real(wp), allocatable :: ee(:)
      integer :: i

      do i = 1, size(deltas)
         call build(deltas(i), nu, body, bcs, exact, error)
         if (allocated(error)) return
         call solve_on_grid(problem, body, box_min, box_size, level, 0, degree, analysis, young, nu, &
            & spread(0.0_wp, 1, size(box_min)), bcs, error, exact=exact)
         if (allocated(error)) return
         call problem%energy_error(err(i), ee, nfe, nex, error)
         if (allocated(error)) return
         call problem%scaled_rcond(rc(i), error)
         if (allocated(error)) return
         if (i > 1) then
            call check(error, minval(problem%mesh%fraction) < 2.0_wp*deltas(i), 'a cut as small as delta exists')
            if (allocated(error)) return
            call check(error, rc(i) >= 0.1_wp*rc(1), 'scaled condition within 10x')
            if (allocated(error)) return
            call check(error, err(i), err(1), 0.01_wp, 'err_fe within 1%', rel=.true.)
            if (allocated(error)) return
         end if
      end do
   end subroutine small_cut_sweep

   ! ------------------------------------------------------------ errors

   !> Conditions that leave rigid motion free: a clear error naming it.
   subroutine test_rigid_modes(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      type(elasticity_problem_type) :: problem
      type(error_type), allocatable :: solve_error

      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      ! no symmetry at all: every rigid mode is free
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs(1:1), solve_error)
      call check(error, allocated(solve_error), 'free body rejected')
      if (allocated(error)) return
      call check(error, solve_error%stat, stat_singular, 'status')
      if (allocated(error)) return
      call check(error, index(solve_error%message, 'rigid-body motion free: translation x, translation y, '// &
         & 'rotation about z (3 independent motions); add') > 0, 'message names each mode once: '//solve_error%message)
      if (allocated(error)) return
      ! symmetry on x = 0 only: the body slides along y
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 2, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs(1:2), solve_error)
      call check(error, allocated(solve_error), 'sliding body rejected')
      if (allocated(error)) return
      call check(error, index(solve_error%message, 'translation y') > 0 .and. &
         & index(solve_error%message, 'translation x') == 0, 'message names translation y only: '// &
         & solve_error%message)
      if (allocated(error)) return
      ! both planes: restrained, solves; also for moduli whose energies overflow or
      ! underflow in the products of the test (it called these free below 1e-170 and
      ! above 1e170)
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, plane_strain, 1.0e200_wp, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, plane_strain, 1.0e-200_wp, poisson, &
         & [0.0_wp, 0.0_wp], bcs, error)
   end subroutine test_rigid_modes

   !> Bad boundary conditions and inputs give stat_invalid_input naming the problem.
   subroutine test_bad_inputs(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      type(elasticity_problem_type) :: problem

      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      call expect([bcs, new_fe_bc(9, bc_free)], 'unknown shape index 9', exact)
      if (allocated(error)) return
      call expect([bcs, new_fe_bc(1, bc_traction, vector=[1.0_wp, 2.0_wp, 3.0_wp])], &
         & 'needs a vector of 2 values, got 3', exact)
      if (allocated(error)) return
      call expect([bcs, new_fe_bc(1, bc_displacement)], 'needs a vector of 2 values, got 0', exact)
      if (allocated(error)) return
      call expect([bcs, new_fe_bc(1, bc_exact_traction)], 'needs an exact solution')
      if (allocated(error)) return
      call expect([bcs, new_fe_bc(2, bc_free)], 'already has a condition', exact)
      if (allocated(error)) return
      call expect([bcs, new_fe_bc(1, 42)], 'unknown kind 42', exact)
      if (allocated(error)) return
      ! exact solution for another analysis, analysis of another dimension, body force size
      call expect(bcs, 'exact solution is for plane_strain, the analysis is plane_stress', exact, plane_stress)
      if (allocated(error)) return
      call expect(bcs, 'does not fit dimension 2', analysis=solid)
      if (allocated(error)) return
      call expect(bcs, 'body_force has 3 values, expected 2', body_force=[0.0_wp, 0.0_wp, 0.0_wp])

   contains

      subroutine expect(bad, fragment, ex, analysis, body_force)
         type(fe_bc_type), intent(in) :: bad(:)
         character(len=*), intent(in) :: fragment
         class(exact_solution_type), intent(in), optional :: ex
         integer, intent(in), optional :: analysis
         real(wp), intent(in), optional :: body_force(:)
         type(error_type), allocatable :: e
         integer :: a
         a = plane_strain
         if (present(analysis)) a = analysis
         if (present(body_force)) then
            call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 2, 0, 1, a, young, poisson, &
               & body_force, bad, e, exact=ex)
         else
            call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 2, 0, 1, a, young, poisson, &
               & [0.0_wp, 0.0_wp], bad, e, exact=ex)
         end if
         call check(error, allocated(e), 'rejected: '//fragment)
         if (allocated(error)) return
         call check(error, e%stat, stat_invalid_input, 'status')
         if (allocated(error)) return
         call check(error, index(e%message, fragment) > 0, 'message "'//e%message//'" contains "'//fragment//'"')
      end subroutine expect

   end subroutine test_bad_inputs

   !> A penalty far too small makes the Nitsche system indefinite: CHOLMOD
   !> refuses, UMFPACK solves, the result says so, and the solution is still
   !> the exact linear field (Nitsche is consistent for any gamma).
   subroutine test_umfpack_fallback(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(poly_field_type) :: field
      type(elasticity_problem_type) :: problem

      call new_poly_field(field, plane_strain, [0.01_wp, -0.02_wp], &
         & reshape([0.003_wp, -0.001_wp, 0.002_wp, 0.004_wp], [2, 2]), error=error)
      if (allocated(error)) return
      call polygon_2d(body, error)
      if (allocated(error)) return
      call run_patch(body, [new_fe_bc(1, bc_exact_displacement), new_fe_bc(2, bc_exact_displacement), &
         & new_fe_bc(3, bc_exact_displacement)], field, 1, 3, 0, 'gamma 1e-3', error, gamma=1.0e-3_wp, &
         & problem_out=problem)
      if (allocated(error)) return
      call check(error, problem%solver_name, 'umfpack', 'fallback solver')
      if (allocated(error)) return
      call check(error, index(problem%solver_note, 'not positive definite') > 0, 'note: '//problem%solver_note)
   end subroutine test_umfpack_fallback

   !> Post-processing queries on a patch solution (stress is exact for a
   !> linear field: stress_at, element_points, element weights sum to the
   !> body's area), and the API's error paths.
   subroutine test_queries(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(poly_field_type) :: field
      type(elasticity_problem_type) :: problem, fresh
      type(error_type), allocatable :: e
      real(wp), allocatable :: x(:, :), w(:), sigma(:, :), ee(:)
      real(wp) :: s(3), sx(3), area, err, nfe, nex
      integer :: i

      call new_poly_field(field, plane_strain, [0.01_wp, -0.02_wp], &
         & reshape([0.003_wp, -0.001_wp, 0.002_wp, 0.004_wp], [2, 2]), error=error)
      if (allocated(error)) return
      call polygon_2d(body, error)
      if (allocated(error)) return
      call run_patch(body, [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_exact_displacement), &
         & new_fe_bc(3, bc_exact_traction)], field, 2, 3, 1, 'queries', error, problem_out=problem)
      if (allocated(error)) return
      call problem%stress_at([0.1_wp, -0.2_wp], s, error)
      if (allocated(error)) return
      call field%stress([0.1_wp, -0.2_wp], sx)
      call check(error, maxval(abs(s - sx)), 0.0_wp, solve_tolerance(problem)*maxval(abs(sx)), 'stress_at')
      if (allocated(error)) return
      area = 0.0_wp
      do i = 1, problem%mesh%grid%n_leaves
         call problem%element_points(i, x, w, sigma)
         area = area + sum(w)
         if (size(w) > 0) then
            call field%stress(x(:, 1), sx)
            call check(error, maxval(abs(sigma(:, 1) - sx)), 0.0_wp, solve_tolerance(problem)*maxval(abs(sx)), &
               & 'element_points')
            if (allocated(error)) return
         end if
      end do
      call check(error, area, polygon_area(), 1.0e-12_wp, 'sum of element weights = area', rel=.true.)
      if (allocated(error)) return

      call problem%stress_at([5.0_wp, 0.0_wp], s, e)
      call check(error, allocated(e), 'stress_at outside the grid rejected')
      if (allocated(error)) return
      call problem%stress_at([0.0_wp, 0.0_wp, 0.0_wp], s, e)
      call check(error, allocated(e), 'stress_at with 3 coordinates rejected')
      if (allocated(error)) return
      call fresh%solve(e)
      call check(error, allocated(e), 'solve before setup rejected')
      if (allocated(error)) return
      call fresh%energy_error(err, ee, nfe, nex, e)
      call check(error, allocated(e), 'energy_error before solve rejected')
      if (allocated(error)) return
      call fresh%scaled_rcond(err, e)
      call check(error, allocated(e), 'scaled_rcond before assembly rejected')
      if (allocated(error)) return
      call fresh%stress_at([0.0_wp, 0.0_wp], s, e)
      call check(error, allocated(e), 'stress_at before solve rejected')
      if (allocated(error)) return
      call solve_on_grid(fresh, body, [-1.0_wp, -1.0_wp], 2.0_wp, 2, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], [new_fe_bc(2, bc_displacement, vector=[0.0_wp, 0.0_wp])], e)
      if (allocated(e)) then
         call test_failed(error, 'plain displacement problem: '//e%message)
         return
      end if
      call fresh%energy_error(err, ee, nfe, nex, e)
      call check(error, allocated(e), 'energy_error without an exact solution rejected')
      if (allocated(error)) return
      call check(error, index(e%message, 'no exact solution') > 0, e%message)
      if (allocated(error)) return
      call solve_on_grid(fresh, body, [-1.0_wp, -1.0_wp], 2.0_wp, 2, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], [new_fe_bc(2, bc_displacement, vector=[0.0_wp, 0.0_wp])], e, eta=1.5_wp)
      call check(error, allocated(e), 'eta = 1.5 rejected')
      if (allocated(error)) return
      call solve_on_grid(fresh, body, [-1.0_wp, -1.0_wp], 2.0_wp, 2, 0, 1, plane_strain, young, poisson, &
         & [0.0_wp, 0.0_wp], [new_fe_bc(2, bc_displacement, vector=[0.0_wp, 0.0_wp])], e, gamma=-1.0_wp)
      call check(error, allocated(e), 'gamma = -1 rejected')

   contains

      !> Area of the box clipped by the two halfspaces n.(x - p) <= 0 (Sutherland-Hodgman, shoelace).
      real(wp) function polygon_area() result(a)
         real(wp) :: v(2, 16), u(2, 16), pt(2, 2), nr(2, 2), f0, f1
         integer :: n, m, k, c
         pt = reshape([0.3_wp, 0.2_wp, -0.4_wp, 0.1_wp], [2, 2])
         nr = reshape([0.6_wp, 0.8_wp, -0.8_wp, 0.6_wp], [2, 2])
         v(:, 1:4) = reshape([-0.83_wp, -0.77_wp, 0.79_wp, -0.77_wp, 0.79_wp, 0.81_wp, -0.83_wp, 0.81_wp], [2, 4])
         n = 4
         do c = 1, 2
            m = 0
            do k = 1, n
               f0 = dot_product(nr(:, c), v(:, k) - pt(:, c))
               f1 = dot_product(nr(:, c), v(:, mod(k, n) + 1) - pt(:, c))
               if (f0 <= 0.0_wp) then
                  m = m + 1
                  u(:, m) = v(:, k)
               end if
               if ((f0 < 0.0_wp .and. f1 > 0.0_wp) .or. (f0 > 0.0_wp .and. f1 < 0.0_wp)) then
                  m = m + 1
                  u(:, m) = v(:, k) + f0/(f0 - f1)*(v(:, mod(k, n) + 1) - v(:, k))
               end if
            end do
            n = m
            v(:, 1:n) = u(:, 1:n)
         end do
         a = 0.0_wp
         do k = 1, n
            a = a + v(1, k)*v(2, mod(k, n) + 1) - v(1, mod(k, n) + 1)*v(2, k)
         end do
         a = 0.5_wp*abs(a)
      end function polygon_area

   end subroutine test_queries

   !> Same bits with 1 and 2 OpenMP threads (parallel quadrature, element matrices
   !> written to their places in the triplet list), 2D Q2 (Lame quarter, level 4) and
   !> 3D Q1 (sphere octant, level 3): quadrature pointers, points, weights, normals,
   !> shape indices and volume fractions, matrix, load, displacements.
   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      type(lame_sphere_type) :: sphere
      type(elasticity_problem_type) :: run(2)
      integer :: nthreads, nt

      nthreads = 1
      !$ nthreads = omp_get_max_threads()
      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      do nt = 1, 2
         !$ call omp_set_num_threads(nt)
         call solve_on_grid(run(nt), body, [0.0_wp, 0.0_wp], 25.0_wp, 4, 1, 2, plane_strain, young, poisson, &
            & [0.0_wp, 0.0_wp], bcs, error, exact=exact)
         if (allocated(error)) exit
      end do
      !$ call omp_set_num_threads(nthreads)
      if (allocated(error)) return
      call check(error, same_bits(run(1), run(2)), '2D Q2: identical bits with 1 and 2 threads')
      if (allocated(error)) return
      call sphere_octant(body, bcs, sphere, error)
      if (allocated(error)) return
      do nt = 1, 2
         !$ call omp_set_num_threads(nt)
         call solve_on_grid(run(nt), body, [0.0_wp, 0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, solid, young, poisson, &
            & [0.0_wp, 0.0_wp, 0.0_wp], bcs, error, exact=sphere)
         if (allocated(error)) exit
      end do
      !$ call omp_set_num_threads(nthreads)
      if (allocated(error)) return
      call check(error, same_bits(run(1), run(2)), '3D Q1: identical bits with 1 and 2 threads')
   contains
      logical function same_bits(a, b)
         type(elasticity_problem_type), intent(in) :: a, b
         same_bits = size(a%mesh%vol_w) == size(b%mesh%vol_w) .and. size(a%mesh%surf_w) == size(b%mesh%surf_w) &
            & .and. size(a%k%val) == size(b%k%val) .and. size(a%mesh%fraction) == size(b%mesh%fraction)
         if (.not. same_bits) return
         same_bits = all(a%mesh%vol_ptr == b%mesh%vol_ptr) .and. all(a%mesh%surf_ptr == b%mesh%surf_ptr) .and. &
            & all(a%mesh%vol_x == b%mesh%vol_x) .and. all(a%mesh%vol_w == b%mesh%vol_w) .and. &
            & all(a%mesh%surf_x == b%mesh%surf_x) .and. all(a%mesh%surf_w == b%mesh%surf_w) .and. &
            & all(a%mesh%surf_n == b%mesh%surf_n) .and. all(a%mesh%surf_shape == b%mesh%surf_shape) .and. &
            & all(a%mesh%fraction == b%mesh%fraction) .and. a%mesh%n_cut == b%mesh%n_cut .and. &
            & all(a%k%col == b%k%col) .and. all(a%k%val == b%k%val) .and. all(a%f == b%f) .and. all(a%u == b%u)
      end function same_bits
   end subroutine test_threads

end module sprc_test_fem
