!> Tests of the grid producer of SPR / SPR-C patches and the recovered field
!> (sprc_estimate_patches, sprc_estimate_recovered_field, sprc_estimate_norms).
!>
!> Problems are real cut grids: a quarter annulus r in [5, 20] in the box [0, 25]^2 with
!> symmetry halfspaces x >= 0, y >= 0, and a spherical-shell octant r in [0.3, 0.9] in
!> [0, 1]^3, both with refine_boundary = 1 (so there are hanging nodes), volume and
!> surface rules from the cut-cell quadrature. The "FE stress" fed to the recovery is an
!> exact field sampled at the points:
!> - polynomial fields in the recovery space that satisfy every active constraint
!>   (`poly_field_type` below): linear sigma_ii with zero shear and the constant body
!>   force that equilibrates them; for degree 2 in 2D an Airy field phi = c40 x^4 +
!>   c22 x^2 y^2 + c04 y^4 with c22 = -3 (c40 + c04) (biharmonic: equilibrated and
!>   compatible; its shear -4 c22 x y vanishes on x = 0 and y = 0), in 3D the Hessian
!>   of the harmonic quartic a (x^4 + y^4 + z^4) - 3a (x^2 y^2 + y^2 z^2 + z^2 x^2)
!>   (divergence-free, trace-free hence compatible, shears vanish on the coordinate
!>   planes). The planes get symmetry, the curved surfaces no constraint (bc_none):
!>   recovery must then reproduce these to round-off (tol_exact), also with the field's own
!>   traction on the curved surfaces (tol_curved);
!>   traction and pressure data are checked to round-off on straight cut boundaries;
!> - Lame's cylinder (not polynomial) plus a known perturbation, for smoothing and
!>   boundary accuracy.
module sprc_test_patches
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input, stat_singular
   use sprc_core_material, only: plane_stress, plane_strain, solid
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_halfspace, new_box
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_geometry_region, only: cell_cut
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule
   use sprc_exact_solution, only: exact_solution_type, init_exact_solution
   use sprc_exact_lame, only: lame_cylinder_type, new_lame_cylinder
   use sprc_recovery_patch_solve, only: recovery_rank_tol
   use sprc_estimate_patches, only: recovery_input_type, recover_grid, bc_none, bc_traction, bc_pressure, &
      & bc_exact_traction, bc_symmetry
   use sprc_estimate_recovered_field, only: recovered_field_type, method_spr, method_sprc, interp_nodal, &
      & interp_union, field_eval, field_union_weights
   use sprc_estimate_norms, only: zz_estimate_type, estimate_error
   use sprc_fem_bc, only: fe_bc_type, new_fe_bc, fe_pressure => bc_pressure, fe_symmetry => bc_symmetry
   use sprc_fem_problem, only: elasticity_problem_type, solve_on_grid
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   use sprc_core_blas_threads, only: blas_threads, set_blas_threads
   !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
   implicit none
   private

   public :: collect_patches

   !> Round-off tier of values that pass through the patch solves (QR, KKT by dsysv), relative
   !> to the stress scale: sqrt(eps). The solves are backward stable, but the conditioning of a
   !> patch system is not estimated (rank decisions keep pivots down to recovery_rank_tol, so
   !> it is not bounded by a small number either); sqrt(eps) admits condition numbers up to
   !> 1/sqrt(eps) ~ 7e7 and is still 1e5 below the errors a wrong constraint or basis makes.
   real(wp), parameter :: tol_exact = sqrt(epsilon(1.0_wp))
   !> SPR-C with traction constraints on curved arcs, inside the body: the core's traction rows
   !> come from a QR of the weighted E per boundary face (pivots >= 1e-8 relative, at most the
   !> flat-boundary rank), so they carry their data to ~1e-14 (it was 3e-8 .. 1.2e-5 with the
   !> rank-reduced E^T E block).
   real(wp), parameter :: tol_curved = tol_exact
   !> Nodes just outside the body (of cut elements): SPR-C keeps constraint rows down to pivot
   !> ratios recovery_rank_tol, which carry their data to eps/recovery_rank_tol (2.2e-6);
   !> measured up to 5e-8 (3D Q2, SPR-C); SPR stays at 1e-12.
   real(wp), parameter :: tol_outside = epsilon(1.0_wp)/recovery_rank_tol
   !> The same with traction on the curved surfaces: the patch of an outside node farther than
   !> traction_reach h from the boundary's tangent plane gets no traction rows and extrapolates
   !> from small cut pieces with the equilibrium rows only; measured 1.2e-5.
   real(wp), parameter :: tol_outside_curved = 1.0e-4_wp

   !> Polynomial exact field (module notes); displacement is not needed here.
   type, extends(exact_solution_type) :: poly_field_type
      real(wp) :: a(6) = 0.0_wp, g(3, 3) = 0.0_wp, b(3) = 0.0_wp
      !> 2D Airy coefficients c40, c04; 3D harmonic amplitude (in q(1)).
      real(wp) :: q(2) = 0.0_wp
   contains
      procedure :: stress => poly_stress
      procedure :: displacement => poly_displacement
      procedure :: body_force => poly_body_force
   end type poly_field_type

   !> A problem: body, grid, nodes, constraints and the recovery input.
   type :: problem_type
      type(body_type) :: body
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hanging
      type(recovery_input_type) :: input
   end type problem_type

contains

   !> Collect all exported unit tests.
   subroutine collect_patches(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('exact_linear_2d_q1', test_linear_2d_q1), &
         new_unittest('exact_quadratic_2d_q1_p2', test_quadratic_2d_q1), &
         new_unittest('exact_quadratic_2d_q2', test_quadratic_2d_q2), &
         new_unittest('exact_linear_3d_q1', test_linear_3d_q1), &
         new_unittest('exact_quadratic_3d_q2', test_quadratic_3d_q2), &
         new_unittest('curved_traction_sprc', test_curved_traction), &
         new_unittest('traction_kinds_straight', test_traction_kinds), &
         new_unittest('hanging_vertices_union_weights', test_hanging), &
         new_unittest('lame_perturbed_smoothing', test_lame_perturbed), &
         new_unittest('lame_convergence', test_lame_convergence), &
         new_unittest('lame_fe_sprc_boundary', test_lame_fe), &
         new_unittest('expansion_box_count', test_expansion_box), &
         new_unittest('expansion_cut_cells', test_expansion_cut), &
         new_unittest('expansion_limit_error', test_expansion_limit), &
         new_unittest('expansion_3d_q1_q2', test_expansion_3d), &
         new_unittest('threads_bitwise', test_threads), &
         new_unittest('input_errors', test_input_errors), &
         new_unittest('eval_errors', test_eval_errors) &
         ]
   end subroutine collect_patches

   ! ------------------------------------------------------------------ fields

   pure subroutine poly_stress(self, x, v)
      class(poly_field_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: c22, a
      integer :: i

      v(1:self%nstress) = self%a(1:self%nstress)
      do i = 1, self%dim
         v(i) = v(i) + dot_product(self%g(i, 1:self%dim), x(1:self%dim))
      end do
      if (self%dim == 2) then
         c22 = -3.0_wp*(self%q(1) + self%q(2))
         v(1) = v(1) + 2.0_wp*c22*x(1)**2 + 12.0_wp*self%q(2)*x(2)**2
         v(2) = v(2) + 12.0_wp*self%q(1)*x(1)**2 + 2.0_wp*c22*x(2)**2
         v(3) = v(3) - 4.0_wp*c22*x(1)*x(2)
      else
         a = self%q(1)
         v(1) = v(1) + 12.0_wp*a*x(1)**2 - 6.0_wp*a*(x(2)**2 + x(3)**2)
         v(2) = v(2) + 12.0_wp*a*x(2)**2 - 6.0_wp*a*(x(1)**2 + x(3)**2)
         v(3) = v(3) + 12.0_wp*a*x(3)**2 - 6.0_wp*a*(x(1)**2 + x(2)**2)
         v(4) = v(4) - 12.0_wp*a*x(1)*x(2)
         v(5) = v(5) - 12.0_wp*a*x(2)*x(3)
         v(6) = v(6) - 12.0_wp*a*x(1)*x(3)
      end if
   end subroutine poly_stress

   pure subroutine poly_displacement(self, x, v)
      class(poly_field_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      associate (unused => x); end associate
      v(1:self%dim) = 0.0_wp
   end subroutine poly_displacement

   pure subroutine poly_body_force(self, x, b)
      class(poly_field_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: b(:)
      associate (unused => x); end associate
      b(1:self%dim) = self%b(1:self%dim)
   end subroutine poly_body_force

   !> Linear part with zero shear and its equilibrating body force b_i = -d sigma_ii / d x_i,
   !> plus a quadratic part of amplitude `quad` (times coordinate scale^-2).
   subroutine make_field(analysis, scale, quad, f, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: scale, quad
      type(poly_field_type), intent(out) :: f
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      call init_exact_solution(f, 'poly_field', analysis, [plane_stress, plane_strain, solid], 1000.0_wp, 0.3_wp, &
         & error)
      if (allocated(error)) return
      f%a(1:3) = [1.0_wp, -0.5_wp, 0.7_wp]
      if (f%dim == 2) f%a(3) = 0.0_wp
      f%g(1, 1:3) = [0.8_wp, -0.3_wp, 0.4_wp]/scale
      f%g(2, 1:3) = [0.2_wp, 0.6_wp, -0.5_wp]/scale
      f%g(3, 1:3) = [-0.4_wp, 0.3_wp, 0.9_wp]/scale
      do i = 1, f%dim
         f%b(i) = -f%g(i, i)
      end do
      f%q = quad*[0.02_wp, 0.035_wp]/scale**2
   end subroutine make_field

   ! ------------------------------------------------------------------ problems

   !> Quarter annulus (shapes: 1 outer, 2 inner, 3 sym_x, 4 sym_y).
   subroutine quarter_annulus(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s

      call new_body(body, 'quarter')
      call new_disk(s, 'outer', [0.0_wp, 0.0_wp], 20.0_wp, error)
      if (.not. allocated(error)) call body%add_shape(csg_add, s, error)
      if (.not. allocated(error)) call new_disk(s, 'inner', [0.0_wp, 0.0_wp], 5.0_wp, error)
      if (.not. allocated(error)) call body%add_shape(csg_subtract, s, error)
      if (.not. allocated(error)) call new_halfspace(s, 'sym_x', [0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      if (.not. allocated(error)) call body%add_shape(csg_intersect, s, error)
      if (.not. allocated(error)) call new_halfspace(s, 'sym_y', [0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], error)
      if (.not. allocated(error)) call body%add_shape(csg_intersect, s, error)
   end subroutine quarter_annulus

   !> Shell octant (shapes: 1 outer, 2 inner, 3..5 sym_x, sym_y, sym_z).
   subroutine shell_octant(body, error)
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      integer :: k
      real(wp) :: n(3)
      character(len=5), parameter :: names(3) = ['sym_x', 'sym_y', 'sym_z']

      call new_body(body, 'octant')
      call new_sphere(s, 'outer', [0.0_wp, 0.0_wp, 0.0_wp], 0.9_wp, error)
      if (.not. allocated(error)) call body%add_shape(csg_add, s, error)
      if (.not. allocated(error)) call new_sphere(s, 'inner', [0.0_wp, 0.0_wp, 0.0_wp], 0.3_wp, error)
      if (.not. allocated(error)) call body%add_shape(csg_subtract, s, error)
      do k = 1, 3
         if (allocated(error)) return
         n = 0.0_wp
         n(k) = -1.0_wp
         call new_halfspace(s, names(k), [0.0_wp, 0.0_wp, 0.0_wp], n, error)
         if (.not. allocated(error)) call body%add_shape(csg_intersect, s, error)
      end do
   end subroutine shell_octant

   !> Grid, nodes, constraints and input of `body`: the exact field `f` sampled at the
   !> volume points (plus `noise` times a deterministic perturbation in [-1, 1]).
   subroutine build_problem(pb, box_size, level, refine, degree, q, analysis, f, bc_kind, error, noise)
      type(problem_type), intent(inout) :: pb
      real(wp), intent(in) :: box_size
      integer, intent(in) :: level, refine, degree, q, analysis
      class(exact_solution_type), intent(in) :: f
      integer, intent(in) :: bc_kind(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: noise
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      real(wp) :: lo(3), hi(3), b(3)
      integer :: d, ns, e, k, j, np, nb
      integer(i8) :: st

      d = pb%body%dim
      ns = merge(3, 6, d == 2)
      call pb%grid%build(pb%body, d, [0.0_wp, 0.0_wp, 0.0_wp], box_size, level, refine, error)
      if (allocated(error)) return
      call pb%nodes%build(pb%grid, degree, error)
      if (allocated(error)) return
      call pb%hanging%build(pb%grid, pb%nodes, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, d, q, error)
      if (allocated(error)) return

      associate (inp => pb%input)
         inp%analysis = analysis
         inp%young = f%young
         inp%poisson = f%poisson
         call f%body_force([0.0_wp, 0.0_wp, 0.0_wp], b(1:d))
         inp%body_force = 0.0_wp
         inp%body_force(1:d) = b(1:d)
         allocate (inp%elem_ptr(pb%grid%n_leaves + 1), inp%belem_ptr(pb%grid%n_leaves + 1))
         allocate (inp%x(d, 0), inp%w(0), inp%stress(ns, 0), inp%bx(d, 0), inp%bw(0), inp%bn(d, 0), inp%bshape(0))
         inp%elem_ptr(1) = 1
         inp%belem_ptr(1) = 1
         st = 4242_i8
         do e = 1, pb%grid%n_leaves
            call pb%grid%leaf_box(e, lo(1:d), hi(1:d))
            call cell_rule(quad, pb%body, lo(1:d), hi(1:d), rule, error)
            if (allocated(error)) return
            np = size(inp%w)
            nb = size(inp%bw)
            inp%x = reshape([inp%x, rule%vol_x(1:d, 1:rule%nvol)], [d, np + rule%nvol])
            inp%w = [inp%w, rule%vol_w(1:rule%nvol)]
            inp%stress = reshape([inp%stress, [(0.0_wp, k=1, ns*rule%nvol)]], [ns, np + rule%nvol])
            do k = np + 1, np + rule%nvol
               call f%stress(inp%x(:, k), inp%stress(:, k))
               if (present(noise)) inp%stress(:, k) = inp%stress(:, k) + noise*[(urand(st), j=1, ns)]
            end do
            inp%bx = reshape([inp%bx, rule%surf_x(1:d, 1:rule%nsurf)], [d, nb + rule%nsurf])
            inp%bw = [inp%bw, rule%surf_w(1:rule%nsurf)]
            inp%bn = reshape([inp%bn, rule%surf_n(1:d, 1:rule%nsurf)], [d, nb + rule%nsurf])
            inp%bshape = [inp%bshape, rule%surf_shape(1:rule%nsurf)]
            inp%elem_ptr(e + 1) = size(inp%w) + 1
            inp%belem_ptr(e + 1) = size(inp%bw) + 1
         end do
         inp%bc_kind = bc_kind
         allocate (inp%bc_traction(3, size(bc_kind)), inp%bc_pressure(size(bc_kind)))
         inp%bc_traction = 0.0_wp
         inp%bc_pressure = 0.0_wp
      end associate
   end subroutine build_problem

   !> Deterministic uniform numbers in [-1, 1] (own LCG).
   real(wp) function urand(st)
      integer(i8), intent(inout) :: st
      st = modulo(st*6364136223846793005_i8 + 1442695040888963407_i8, huge(st))
      urand = 2.0_wp*real(modulo(st/1024_i8, 1048576_i8), wp)/1048576.0_wp - 1.0_wp
   end function urand

   ! ------------------------------------------------------------------ checks

   !> Recover with `method`/`degree` and compare with the exact field `f`: the nodal output at
   !> every node (or only free nodes if `free_only`), the union field (and the nodal field if
   !> `nodal_exact`) at random points of every element, and the ZZ estimate ~ 0.
   subroutine check_reproduction(pb, f, method, degree, nodal_exact, free_only, name, error, tolerance, outside)
      type(problem_type), intent(in) :: pb
      class(exact_solution_type), intent(in) :: f
      integer, intent(in) :: method, degree
      logical, intent(in) :: nodal_exact, free_only
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      !> Relative tolerance (default tol_exact); at nodes outside the body (default tol_outside).
      real(wp), intent(in), optional :: tolerance, outside
      type(recovered_field_type) :: field
      type(zz_estimate_type) :: est
      real(wp) :: smax, s(6), sx(6), x(3), lo(3), hi(3), dev_node, dev_union, dev_nodal, dev_out
      integer :: n, e, k, d, ns
      integer(i8) :: st
      real(wp) :: tol, tol_out

      tol = tol_exact
      if (present(tolerance)) tol = tolerance
      tol_out = tol_outside
      if (present(outside)) tol_out = outside
      d = f%dim
      ns = f%nstress
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method, degree, field, error, exact=f)
      if (allocated(error)) return
      call check(error, field%n_patches > 0, name//': patches')
      if (allocated(error)) return
      smax = maxval(abs(pb%input%stress))
      dev_node = 0.0_wp
      dev_out = 0.0_wp
      do n = 1, pb%nodes%n_nodes
         if (free_only .and. pb%hanging%free_index(n) == 0) cycle
         call f%stress(pb%nodes%x(:, n), sx(1:ns))
         if (pb%body%phi(pb%nodes%x(:, n)) <= 0.0_wp) then
            dev_node = max(dev_node, maxval(abs(field%nodal(:, n) - sx(1:ns))))
         else
            dev_out = max(dev_out, maxval(abs(field%nodal(:, n) - sx(1:ns))))
         end if
      end do
      call check(error, dev_node, 0.0_wp, tol*smax, name//': nodal output vs exact')
      if (allocated(error)) return
      ! Nodes outside the body: the patch polynomials extrapolated from small cut pieces, where
      ! SPR-C's constraint rows kept down to pivot ratios 1e-10 lose accuracy (tol_outside).
      call check(error, dev_out, 0.0_wp, max(tol, tol_out)*smax, name//': nodal output outside the body')
      if (allocated(error)) return
      st = 99_i8
      dev_union = 0.0_wp
      dev_nodal = 0.0_wp
      do e = 1, pb%grid%n_leaves
         call pb%grid%leaf_box(e, lo(1:d), hi(1:d))
         do k = 1, 3
            x(1:d) = lo(1:d) + 0.5_wp*(1.0_wp + [urand(st), urand(st), urand(st)])*(hi(1:d) - lo(1:d))
            if (pb%body%phi(x(1:d)) > 0.0_wp) cycle
            call f%stress(x(1:d), sx(1:ns))
            call field_eval(field, e, x(1:d), s(1:ns), error, interp_union)
            if (allocated(error)) return
            dev_union = max(dev_union, maxval(abs(s(1:ns) - sx(1:ns))))
            call field_eval(field, e, x(1:d), s(1:ns), error, interp_nodal)
            if (allocated(error)) return
            dev_nodal = max(dev_nodal, maxval(abs(s(1:ns) - sx(1:ns))))
         end do
      end do
      call check(error, dev_union, 0.0_wp, tol*smax, name//': union field at random points')
      if (allocated(error)) return
      if (nodal_exact) then
         call check(error, dev_nodal, 0.0_wp, tol*smax, name//': nodal field at random points')
         if (allocated(error)) return
      end if
      call estimate_error(pb%input, field, est, error, f)
      if (allocated(error)) return
      ! err is an energy norm of round-off-size differences: relative to norm_h as above.
      ! (SPR's nodal interpolation of a field of higher degree than the elements is not exact.)
      if (nodal_exact .or. method == method_sprc) then
         call check(error, est%err, 0.0_wp, tol*est%norm_h, name//': ZZ estimate of an exact field')
         if (allocated(error)) return
         call check(error, est%rel_err_star, 0.0_wp, tol, name//': relative error of sigma*')
         if (allocated(error)) return
      end if
      call check(error, est%err_ex, 0.0_wp, tol_exact*est%norm_ex, name//': sampled field is the exact one')
   end subroutine check_reproduction

   ! ------------------------------------------------------------------ tests

   !> Q1, degree 1, linear field: SPR and SPR-C reproduce it everywhere (nodal and union).
   subroutine test_linear_2d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call make_field(plane_stress, 20.0_wp, 0.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 3, 1, 1, 3, plane_stress, f, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry], error)
      if (allocated(error)) return
      call check(error, pb%hanging%n_hanging > 0, 'the grid has hanging nodes')
      if (allocated(error)) return
      call check_reproduction(pb, f, method_spr, 1, .true., .false., 'spr q1 p1', error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_sprc, 1, .true., .false., 'sprc q1 p1', error)
   end subroutine test_linear_2d_q1

   !> Q1 with degree p+1 = 2, quadratic Airy field: unions are exact everywhere; SPR's nodal
   !> values are exact at free nodes (hanging ones interpolate linearly, not exact).
   subroutine test_quadratic_2d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call make_field(plane_strain, 20.0_wp, 1.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 3, 1, 1, 3, plane_strain, f, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry], error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_spr, 2, .false., .true., 'spr q1 p2', error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_sprc, 2, .false., .false., 'sprc q1 p2', error)
   end subroutine test_quadratic_2d_q1

   !> Q2, degree 2, quadratic Airy field: SPR (Q2 nodal interpolation, mid-edge values from
   !> the vertex patches) and SPR-C reproduce it everywhere.
   subroutine test_quadratic_2d_q2(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call make_field(plane_stress, 20.0_wp, 1.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 3, 1, 2, 4, plane_stress, f, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry], error)
      if (allocated(error)) return
      call check(error, pb%hanging%n_hanging > 0, 'the Q2 grid has hanging nodes')
      if (allocated(error)) return
      call check_reproduction(pb, f, method_spr, 2, .true., .false., 'spr q2 p2', error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_sprc, 2, .true., .false., 'sprc q2 p2', error)
   end subroutine test_quadratic_2d_q2

   !> 3D shell octant, Q1, linear field with body force.
   subroutine test_linear_3d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f

      call shell_octant(pb%body, error)
      if (allocated(error)) return
      call make_field(solid, 1.0_wp, 0.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 1.0_wp, 2, 1, 1, 2, solid, f, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry, bc_symmetry], error)
      if (allocated(error)) return
      call check(error, pb%hanging%n_hanging > 0, 'the 3D grid has hanging nodes')
      if (allocated(error)) return
      call check_reproduction(pb, f, method_spr, 1, .true., .false., 'spr 3d q1 p1', error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_sprc, 1, .true., .false., 'sprc 3d q1 p1', error)
   end subroutine test_linear_3d_q1

   !> 3D shell octant, Q2, harmonic-Hessian quadratic field plus a linear part.
   subroutine test_quadratic_3d_q2(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f

      call shell_octant(pb%body, error)
      if (allocated(error)) return
      call make_field(solid, 1.0_wp, 1.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 1.0_wp, 2, 1, 2, 3, solid, f, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry, bc_symmetry], error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_spr, 2, .true., .false., 'spr 3d q2 p2', error)
      if (allocated(error)) return
      call check_reproduction(pb, f, method_sprc, 2, .true., .false., 'sprc 3d q2 p2', error)
   end subroutine test_quadratic_3d_q2

   !> SPR-C with the exact field's traction on the curved surfaces (2D Q1 / Q2, 3D Q1):
   !> reproduction within tol_curved (module constant, the core's constraint accuracy).
   subroutine test_curved_traction(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_field_type) :: f
      integer :: k

      do k = 1, 3
         block
            type(problem_type) :: pb
            if (k < 3) then
               call quarter_annulus(pb%body, error)
               if (allocated(error)) return
               call make_field(plane_stress, 20.0_wp, real(k - 1, wp), f, error)
               if (allocated(error)) return
               call build_problem(pb, 25.0_wp, 3, 1, k, k + 2, plane_stress, f, &
                  & [bc_exact_traction, bc_exact_traction, bc_symmetry, bc_symmetry], error)
            else
               call shell_octant(pb%body, error)
               if (allocated(error)) return
               call make_field(solid, 1.0_wp, 0.0_wp, f, error)
               if (allocated(error)) return
               call build_problem(pb, 1.0_wp, 2, 1, 1, 2, solid, f, &
                  & [bc_exact_traction, bc_exact_traction, bc_symmetry, bc_symmetry, bc_symmetry], error)
            end if
            if (allocated(error)) return
            call check_reproduction(pb, f, method_sprc, min(k, 2), .true., .false., 'sprc curved traction', error, &
               & tol_curved, tol_outside_curved)
            if (allocated(error)) return
         end block
      end do
   end subroutine test_curved_traction

   !> Straight cut boundaries (the rectangle [0.1, 0.9] x [0.15, 0.85] from four halfspaces,
   !> cutting a 4 x 4 grid) with every traction kind, data by hand: a constant stress
   !> (1, -0.5, 0.7) with left t = (-1, -0.7), bottom t = (-0.7, 0.5) (bc_traction), right
   !> and top from the field (bc_exact_traction); and the hydrostatic -2 I with bc_pressure 2
   !> on all sides. SPR-C reproduces both to tol_exact.
   subroutine test_traction_kinds(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_field_type) :: f
      type(shape_type) :: s
      integer :: k, side
      real(wp), parameter :: lo(2) = [0.1_wp, 0.15_wp], hi(2) = [0.9_wp, 0.85_wp]
      character(len=6), parameter :: names(4) = ['left  ', 'right ', 'bottom', 'top   ']

      do k = 1, 2
         block
            type(problem_type) :: pb
            call new_body(pb%body, 'rectangle')
            do side = 1, 4
               if (side <= 2) then
                  call new_halfspace(s, trim(names(side)), merge(lo, hi, side == 1), &
                     & merge([-1.0_wp, 0.0_wp], [1.0_wp, 0.0_wp], side == 1), error)
               else
                  call new_halfspace(s, trim(names(side)), merge(lo, hi, side == 3), &
                     & merge([0.0_wp, -1.0_wp], [0.0_wp, 1.0_wp], side == 3), error)
               end if
               if (allocated(error)) return
               call pb%body%add_shape(merge(csg_add, csg_intersect, side == 1), s, error)
               if (allocated(error)) return
            end do
            call make_field(plane_stress, 1.0_wp, 0.0_wp, f, error)
            if (allocated(error)) return
            f%g = 0.0_wp
            f%b = 0.0_wp
            if (k == 1) then
               f%a(1:3) = [1.0_wp, -0.5_wp, 0.7_wp]
               call build_problem(pb, 1.0_wp, 2, 0, 1, 3, plane_stress, f, &
                  & [bc_traction, bc_exact_traction, bc_traction, bc_exact_traction], error)
               if (allocated(error)) return
               pb%input%bc_traction(1:2, 1) = [-1.0_wp, -0.7_wp]
               pb%input%bc_traction(1:2, 3) = [-0.7_wp, 0.5_wp]
            else
               f%a(1:3) = [-2.0_wp, -2.0_wp, 0.0_wp]
               call build_problem(pb, 1.0_wp, 2, 0, 1, 3, plane_stress, f, [bc_pressure, bc_pressure, bc_pressure, &
                  & bc_pressure], error)
               if (allocated(error)) return
               pb%input%bc_pressure = 2.0_wp
            end if
            call check(error, count(pb%grid%leaf_class == cell_cut) >= 12, 'the sides cut the grid')
            if (allocated(error)) return
            call check(error, size(pb%input%bw) > 0, 'boundary points')
            if (allocated(error)) return
            call check_reproduction(pb, f, method_sprc, 1, .true., .false., 'traction kinds', error)
            if (allocated(error)) return
         end block
      end do
   end subroutine test_traction_kinds

   !> Hanging vertices get no patch; at random points of their elements the union weights
   !> sum to one (1e-14: a sum of a few products of O(1) numbers); both fields agree at a
   !> hanging node whichever element holding it evaluates them (continuity across coarse /
   !> fine faces, 1e-12 relative) for a non-polynomial input (Lame plus noise).
   subroutine test_hanging(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(lame_cylinder_type) :: lame
      type(recovered_field_type) :: field
      real(wp) :: x(2), lo(2), hi(2), wts(32), s(3), sref(3), smax
      integer :: pts(32), npt, n, e, k, j, nhang, m, interp, nchecked
      integer(i8) :: st

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call new_lame_cylinder(lame, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 3, 1, 1, 3, plane_strain, lame, &
         & [bc_traction, bc_pressure, bc_symmetry, bc_symmetry], error, noise=0.05_wp)
      if (allocated(error)) return
      pb%input%bc_pressure(2) = 1.0_wp
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_sprc, 1, field, error)
      if (allocated(error)) return
      nhang = 0
      do n = 1, pb%nodes%n_nodes
         if (pb%hanging%free_index(n) /= 0) cycle
         nhang = nhang + 1
         call check(error, field%patch_of_node(n), 0, 'a hanging vertex has no patch')
         if (allocated(error)) return
      end do
      call check(error, nhang, pb%hanging%n_hanging, 'hanging nodes counted')
      if (allocated(error)) return
      call check(error, nhang > 0, 'the grid has hanging nodes')
      if (allocated(error)) return
      call check(error, field%n_patches, pb%nodes%n_nodes - nhang, 'every free Q1 node is a vertex with a patch')
      if (allocated(error)) return

      st = 7_i8
      do e = 1, pb%grid%n_leaves
         if (all(pb%hanging%free_index(pb%nodes%connectivity(:, e)) /= 0)) cycle
         call pb%grid%leaf_box(e, lo, hi)
         do k = 1, 4
            x = lo + 0.5_wp*(1.0_wp + [urand(st), urand(st)])*(hi - lo)
            call field_union_weights(field, e, x, pts, wts, npt, error)
            if (allocated(error)) return
            call check(error, sum(wts(1:npt)), 1.0_wp, 1.0e-14_wp, 'union weights sum to one')
            if (allocated(error)) return
            call check(error, all(pts(1:npt) >= 1 .and. pts(1:npt) <= field%n_patches), 'weights reach patches')
            if (allocated(error)) return
         end do
      end do

      smax = maxval(abs(pb%input%stress))
      nchecked = 0
      do interp = interp_nodal, interp_union
         do n = 1, pb%nodes%n_nodes
            if (pb%hanging%free_index(n) /= 0) cycle
            m = 0
            do e = 1, pb%grid%n_leaves
               call pb%grid%leaf_box(e, lo, hi)
               if (any(pb%nodes%x(:, n) < lo .or. pb%nodes%x(:, n) > hi)) cycle
               call field_eval(field, e, pb%nodes%x(:, n), s, error, interp)
               if (allocated(error)) return
               m = m + 1
               if (m == 1) then
                  sref = s
               else
                  call check(error, maxval(abs(s - sref)), 0.0_wp, 1.0e-12_wp*smax, 'continuity at a hanging node')
                  if (allocated(error)) return
                  nchecked = nchecked + 1
               end if
            end do
            ! The coarse element and one or two fine ones hold a 2D hanging node.
            call check(error, m >= 2, 'elements holding a hanging node')
            if (allocated(error)) return
            if (interp == interp_union) then
               do j = 1, 3
                  call check(error, field%nodal(j, n), sref(j), 1.0e-12_wp*smax, 'SPR-C nodal output = union')
                  if (allocated(error)) return
               end do
            end if
         end do
      end do
      call check(error, nchecked > 0, 'continuity checked')
   end subroutine test_hanging

   !> Lame cylinder sampled with a known perturbation (uniform in [-0.2, 0.2] per component,
   !> pressure 1): both recoveries are at least twice closer to the exact field than the
   !> perturbed input (energy norm), their largest error at boundary nodes inside the body is
   !> below the perturbation, and SPR-C's largest error at the boundary points is at most
   !> SPR's (measured 0.146 vs 0.287). Only the symmetry planes are constrained: the core's
   !> traction constraints on curved arcs are not usable yet (SPR-C with the Lame pressure
   !> and free surface on the circles gives errors ~2 at the inner boundary and does not
   !> converge; see tol_curved), so the curved surfaces are bc_none here.
   subroutine test_lame_perturbed(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(lame_cylinder_type) :: lame
      type(recovered_field_type) :: field
      type(zz_estimate_type) :: est(2)
      logical, allocatable :: inside(:)
      integer :: method, n

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call new_lame_cylinder(lame, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 4, 1, 1, 3, plane_strain, lame, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry], error, noise=0.2_wp)
      if (allocated(error)) return
      pb%input%bc_pressure(2) = 1.0_wp
      inside = [(pb%body%phi(pb%nodes%x(:, n)) <= 0.0_wp, n=1, pb%nodes%n_nodes)]
      do method = method_spr, method_sprc
         call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method, 1, field, error)
         if (allocated(error)) return
         call estimate_error(pb%input, field, est(method), error, lame, inside)
         if (allocated(error)) return
         call check(error, est(method)%err_star < 0.5_wp*est(method)%err_ex, &
            & 'recovered field closer to the exact one than the perturbed input (by 2x)')
         if (allocated(error)) return
         call check(error, est(method)%n_boundary_nodes > 0, 'boundary nodes')
         if (allocated(error)) return
      end do
      do method = method_spr, method_sprc
         ! The input deviates by up to 0.2 sqrt(3) = 0.35 (Euclidean, per point).
         call check(error, est(method)%max_boundary_node_error < 0.2_wp, 'boundary nodes inside: smoothed')
         if (allocated(error)) return
      end do
      call check(error, est(2)%max_boundary_point_error <= est(1)%max_boundary_point_error, &
         & 'SPR-C boundary-point error at most SPR''s')
   end subroutine test_lame_perturbed

   !> Lame cylinder sampled exactly (not a polynomial): the relative error of sigma* falls
   !> at least like h^1.5 from level 3 to 4 (a degree-1 fit of a smooth field: O(h^2);
   !> measured ratios 4.4 SPR, 5.1 SPR-C). Pressure inside, free outside (it was 0.17 -> 0.046
   !> for SPR-C before the traction rows were reduced per face and limited to patches whose
   !> node is on the boundary).
   subroutine test_lame_convergence(error)
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: lame
      type(recovered_field_type) :: field
      type(zz_estimate_type) :: est
      real(wp) :: err(2, 2)
      integer :: level, method

      call new_lame_cylinder(lame, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      do level = 3, 4
         block
            type(problem_type) :: pb
            call quarter_annulus(pb%body, error)
            if (allocated(error)) return
            call build_problem(pb, 25.0_wp, level, 1, 1, 3, plane_strain, lame, &
               & [bc_traction, bc_pressure, bc_symmetry, bc_symmetry], error)
            if (allocated(error)) return
            pb%input%bc_pressure(2) = 1.0_wp
            do method = method_spr, method_sprc
               call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method, 1, field, error, exact=lame)
               if (allocated(error)) return
               call estimate_error(pb%input, field, est, error, lame)
               if (allocated(error)) return
               err(level - 2, method) = est%rel_err_star
            end do
         end block
      end do
      do method = method_spr, method_sprc
         call check(error, err(1, method)/err(2, method) > 2.0_wp**1.5_wp, 'convergence of sigma* with h')
         if (allocated(error)) return
      end do
   end subroutine test_lame_convergence

   !> Real FE solution (Lame quarter, plane strain, Q1, level 6, pressure 1 inside, outer free,
   !> strong symmetry): err_sprc < err_spr < err_fe (energy norm; measured 5.4e-3, 9.5e-3,
   !> 3.4e-2), SPR-C's largest stress error at boundary vertex nodes inside the body at most
   !> half SPR's (measured 0.042 vs 0.102) and its effectivity within 5% of 1 (measured 0.997).
   !> With traction rows in every patch touching the boundary SPR-C had 6.2e-3 and 0.040 here but lost to SPR
   !> at levels 3 and 4; see example/bench/recovery_study.f90 for the whole table.
   subroutine test_lame_fe(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(lame_cylinder_type) :: lame
      type(elasticity_problem_type) :: fe
      type(fe_bc_type), allocatable :: bcs(:)
      type(recovered_field_type) :: field
      type(zz_estimate_type) :: est(2)
      real(wp), allocatable :: x(:, :), w(:), sigma(:, :)
      logical, allocatable :: inside(:)
      integer :: method, e, n

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call new_lame_cylinder(lame, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      bcs = [new_fe_bc(2, fe_pressure, value=1.0_wp), new_fe_bc(3, fe_symmetry), new_fe_bc(4, fe_symmetry)]
      call solve_on_grid(fe, pb%body, [0.0_wp, 0.0_wp], 25.0_wp, 6, 0, 1, plane_strain, 1000.0_wp, 0.3_wp, &
         & [0.0_wp, 0.0_wp], bcs, error, exact=lame)
      if (allocated(error)) return
      call pb%hanging%build(fe%mesh%grid, fe%mesh%nodes, error)
      if (allocated(error)) return
      associate (inp => pb%input)
         inp%analysis = plane_strain
         inp%young = 1000.0_wp
         inp%poisson = 0.3_wp
         inp%elem_ptr = fe%mesh%vol_ptr
         inp%x = fe%mesh%vol_x
         inp%w = fe%mesh%vol_w
         allocate (inp%stress(3, size(fe%mesh%vol_w)))
         do e = 1, fe%mesh%grid%n_leaves
            call fe%element_points(e, x, w, sigma)
            inp%stress(:, fe%mesh%vol_ptr(e):fe%mesh%vol_ptr(e + 1) - 1) = sigma
         end do
         inp%belem_ptr = fe%mesh%surf_ptr
         inp%bx = fe%mesh%surf_x
         inp%bw = fe%mesh%surf_w
         inp%bn = fe%mesh%surf_n
         inp%bshape = fe%mesh%surf_shape
         inp%bc_kind = [bc_traction, bc_pressure, bc_symmetry, bc_symmetry]
         allocate (inp%bc_traction(3, 4), inp%bc_pressure(4))
         inp%bc_traction = 0.0_wp
         inp%bc_pressure = [0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp]
      end associate
      inside = [(pb%body%phi(fe%mesh%nodes%x(:, n)) <= 0.0_wp, n=1, fe%mesh%nodes%n_nodes)]
      do method = method_spr, method_sprc
         call recover_grid(pb%input, fe%mesh%grid, fe%mesh%nodes, pb%hanging, method, 1, field, error)
         if (allocated(error)) return
         call estimate_error(pb%input, field, est(method), error, lame, inside)
         if (allocated(error)) return
      end do
      call check(error, est(2)%rel_err_star < est(1)%rel_err_star .and. est(1)%rel_err_star < &
         & est(1)%err_ex/est(1)%norm_ex, 'err_sprc < err_spr < err_fe')
      if (allocated(error)) return
      call check(error, est(2)%max_boundary_node_error <= 0.5_wp*est(1)%max_boundary_node_error, &
         & 'SPR-C boundary-node error at most half SPR''s')
      if (allocated(error)) return
      call check(error, est(2)%theta, 1.0_wp, 0.05_wp, 'SPR-C effectivity')
   end subroutine test_lame_fe

   !> The box [0, 1]^2 on a 4 x 4 grid with one point per element: a boundary node's patch
   !> (1 or 2 elements, 1 or 2 points) lacks rank for degree 1 and needs exactly one ring;
   !> interior nodes (4 points, not aligned) need none. Hand count: 16 boundary nodes
   !> expanded, corner patches grow to 4 elements, edge patches to 6 (8 at the edge
   !> midpoints, whose ring spans four columns). The linear field is
   !> still reproduced.
   subroutine test_expansion_box(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f
      type(shape_type) :: s
      type(recovered_field_type) :: field
      integer :: ip, n, nb
      real(wp) :: x(2)

      call new_body(pb%body, 'box')
      call new_box(s, 'box', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call pb%body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call make_field(plane_stress, 1.0_wp, 0.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 1.0_wp, 2, 0, 1, 1, plane_stress, f, [bc_exact_traction], error)
      if (allocated(error)) return
      call check(error, pb%grid%n_leaves, 16, '4 x 4 leaves')
      if (allocated(error)) return
      do ip = 1, 2
         call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, ip, 1, field, error, exact=f)
         if (allocated(error)) return
         call check(error, field%n_expanded, 16, 'boundary patches expanded')
         if (allocated(error)) return
         call check(error, field%max_rounds_used, 1, 'one ring suffices')
         if (allocated(error)) return
         do n = 1, field%n_patches
            x = pb%nodes%x(:, field%patch_node(n))
            nb = count(x == 0.0_wp .or. x == 1.0_wp)
            if (nb == 2) then
               call check(error, field%patch_elements(n), 4, 'corner patch after one ring')
            else if (nb == 1 .and. any(x == 0.5_wp)) then
               ! nodes 0.25 .. 0.75 along the edge: 4 columns of 2 elements
               call check(error, field%patch_elements(n), 8, 'mid-edge patch after one ring')
            else if (nb == 1) then
               ! nodes 0 .. 0.5 (or 0.5 .. 1): 3 columns of 2 elements
               call check(error, field%patch_elements(n), 6, 'edge patch after one ring')
            else
               call check(error, field%patch_elements(n), 4, 'interior patch')
            end if
            if (allocated(error)) return
         end do
      end do
      call check_reproduction(pb, f, method_sprc, 1, .true., .false., 'expanded box', error)
   end subroutine test_expansion_box

   !> The quarter annulus with one Gauss point per direction: small cut elements at the
   !> boundary leave patches rank deficient for degree 2; expansion repairs them and the
   !> quadratic field is still reproduced by SPR-C.
   subroutine test_expansion_cut(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f
      type(recovered_field_type) :: field

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call make_field(plane_stress, 20.0_wp, 1.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 3, 1, 1, 1, plane_stress, f, &
         & [bc_none, bc_none, bc_symmetry, bc_symmetry], error)
      if (allocated(error)) return
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_sprc, 2, field, error, exact=f)
      if (allocated(error)) return
      call check(error, field%n_expanded > 0, 'some patches were expanded')
      if (allocated(error)) return
      call check(error, field%max_rounds_used >= 1, 'rounds recorded')
      if (allocated(error)) return
      call check_reproduction(pb, f, method_sprc, 2, .false., .false., 'expanded cut patches', error)
   end subroutine test_expansion_cut

   !> Rank-deficient patches in 3D: the box [0, 1]^3 on a 4^3 grid with one point per element,
   !> Q1 nodes with degree-1 patches (4 unknowns per component, boundary patches of 1 to 4
   !> points) and Q2 nodes with degree-2 patches (10 per component): the boundary patches
   !> are expanded, and SPR and SPR-C still reproduce the linear / quadratic field.
   subroutine test_expansion_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f
      type(shape_type) :: s
      type(recovered_field_type) :: field
      integer :: p, m
      integer, parameter :: methods(2) = [method_spr, method_sprc]

      call new_box(s, 'box', [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      do p = 1, 2
         pb = problem_type()
         call new_body(pb%body, 'box')
         call pb%body%add_shape(csg_add, s, error)
         if (allocated(error)) return
         call make_field(solid, 1.0_wp, real(p - 1, wp), f, error)
         if (allocated(error)) return
         call build_problem(pb, 1.0_wp, 2, 0, p, 1, solid, f, [bc_exact_traction], error)
         if (allocated(error)) return
         do m = 1, 2
            call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, methods(m), p, field, error, exact=f)
            if (allocated(error)) return
            call check(error, field%n_expanded > 0, 'boundary patches expanded (3D, degree '//achar(48 + p)//')')
            if (allocated(error)) return
         end do
         call check_reproduction(pb, f, method_sprc, p, p == 1, .false., 'expanded 3D box, degree '// &
            & achar(48 + p), error)
         if (allocated(error)) return
      end do
   end subroutine test_expansion_3d

   !> Expansion that cannot succeed: a single element with one point (no neighbours), and the
   !> 4 x 4 box with expansion switched off (max_rounds = 0): stat_singular naming the node.
   subroutine test_expansion_limit(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb1, pb2
      type(poly_field_type) :: f
      type(shape_type) :: s
      type(recovered_field_type) :: field

      call make_field(plane_stress, 1.0_wp, 0.0_wp, f, error)
      if (allocated(error)) return
      call new_box(s, 'box', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call new_body(pb1%body, 'box')
      call pb1%body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call build_problem(pb1, 1.0_wp, 0, 0, 1, 1, plane_stress, f, [bc_none], error)
      if (allocated(error)) return
      call recover_grid(pb1%input, pb1%grid, pb1%nodes, pb1%hanging, method_spr, 1, field, error)
      call expect_error(error, stat_singular, 'patch of node 1', 'single element')
      if (allocated(error)) return

      call new_body(pb2%body, 'box')
      call pb2%body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call build_problem(pb2, 1.0_wp, 2, 0, 1, 1, plane_stress, f, [bc_none], error)
      if (allocated(error)) return
      call recover_grid(pb2%input, pb2%grid, pb2%nodes, pb2%hanging, method_sprc, 1, field, error, max_rounds=0)
      call expect_error(error, stat_singular, 'rank deficient', 'max_rounds = 0')
   end subroutine test_expansion_limit

   !> 1 and 2 OpenMP threads give identical bits: patches (nodes, rounds, coefficients) and
   !> their counts, nodal output, estimate.
   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(lame_cylinder_type) :: lame
      type(recovered_field_type) :: field(2)
      type(zz_estimate_type) :: est(2)
      integer :: nt, k, nthreads0, blas0

      call quarter_annulus(pb%body, error)
      if (allocated(error)) return
      call new_lame_cylinder(lame, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      call build_problem(pb, 25.0_wp, 4, 1, 1, 3, plane_strain, lame, &
         & [bc_traction, bc_pressure, bc_symmetry, bc_symmetry], error, noise=0.05_wp)
      if (allocated(error)) return
      pb%input%bc_pressure(2) = 1.0_wp
      nthreads0 = 1
      !$ nthreads0 = omp_get_max_threads()
      ! A caller's OpenBLAS pool of 2: the patch loop runs BLAS in one thread and restores it.
      blas0 = blas_threads()
      if (blas0 > 0) call set_blas_threads(2)
      do nt = 1, 2
         !$ call omp_set_num_threads(nt)
         call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_sprc, 2, field(nt), error)
         if (allocated(error)) exit
         if (blas0 > 0 .and. blas_threads() /= 2) call test_failed(error, 'recover_grid did not restore the BLAS threads')
         if (allocated(error)) exit
         call estimate_error(pb%input, field(nt), est(nt), error, lame)
         if (allocated(error)) exit
      end do
      !$ call omp_set_num_threads(nthreads0)
      if (blas0 > 0) call set_blas_threads(blas0)
      if (allocated(error)) return
      call check(error, field(1)%n_patches == field(2)%n_patches .and. &
         & all(field(1)%patch_node == field(2)%patch_node) .and. all(field(1)%patch_of_node == field(2)%patch_of_node) &
         & .and. all(field(1)%patch_rounds == field(2)%patch_rounds) .and. &
         & all(field(1)%patch_elements == field(2)%patch_elements) .and. field(1)%n_expanded == field(2)%n_expanded &
         & .and. field(1)%max_rounds_used == field(2)%max_rounds_used .and. &
         & field(1)%n_tolerance_bites == field(2)%n_tolerance_bites, 'patches and their counts identical')
      if (allocated(error)) return
      do k = 1, field(1)%n_patches
         if (any(field(1)%recs(k)%coef /= field(2)%recs(k)%coef)) then
            call test_failed(error, 'patch coefficients differ between 1 and 2 threads')
            return
         end if
      end do
      call check(error, all(field(1)%nodal == field(2)%nodal), 'nodal output identical')
      if (allocated(error)) return
      call check(error, all(est(1)%elem_err2 == est(2)%elem_err2) .and. est(1)%err == est(2)%err .and. &
         & est(1)%err_star == est(2)%err_star, 'estimate identical')
   end subroutine test_threads

   !> Every input check names the offending field.
   subroutine test_input_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f
      type(recovery_input_type) :: bad
      type(recovered_field_type) :: field
      type(shape_type) :: s

      call new_body(pb%body, 'box')
      call new_box(s, 'box', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call pb%body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call make_field(plane_stress, 1.0_wp, 0.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 1.0_wp, 2, 0, 1, 2, plane_stress, f, [bc_exact_traction], error)
      if (allocated(error)) return

      bad = pb%input
      bad%stress = bad%stress(1:2, :)
      call run(bad, 'stress(3,', 'wrong stress rows')
      if (allocated(error)) return
      bad = pb%input
      bad%bshape(1) = 99
      call run(bad, 'bshape(1) = 99', 'unknown shape index')
      if (allocated(error)) return
      bad = pb%input
      bad%stress(2, 5) = ieee_nan()
      call run(bad, 'stress(:, 5) is not finite', 'NaN stress')
      if (allocated(error)) return
      bad = pb%input
      bad%elem_ptr = bad%elem_ptr(1:10)
      call run(bad, 'elem_ptr has 10 entries', 'short elem_ptr')
      if (allocated(error)) return
      bad = pb%input
      bad%w(3) = 0.0_wp
      call run(bad, 'w(3)', 'zero weight')
      if (allocated(error)) return
      bad = pb%input
      bad%bn(:, 2) = 2.0_wp*bad%bn(:, 2)
      call run(bad, 'bn(:, 2)', 'non-unit normal')
      if (allocated(error)) return
      bad = pb%input
      bad%bc_kind(1) = 7
      call run(bad, 'bc_kind(1) = 7', 'unknown boundary kind')
      if (allocated(error)) return
      bad = pb%input
      bad%analysis = solid
      call run(bad, 'does not fit dim', 'analysis of another dimension')
      if (allocated(error)) return
      bad = pb%input
      deallocate (bad%bx)
      call run(bad, 'must be allocated', 'missing boundary arrays')
      if (allocated(error)) return
      ! bc_exact_traction needs the exact solution
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_sprc, 1, field, error)
      call expect_error(error, stat_invalid_input, 'no exact solution', 'exact traction without exact')
      if (allocated(error)) return
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, 3, 1, field, error, exact=f)
      call expect_error(error, stat_invalid_input, 'method = 3', 'unknown method')
      if (allocated(error)) return
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_spr, 0, field, error, exact=f)
      call expect_error(error, stat_invalid_input, 'degree = 0', 'degree 0')
      if (allocated(error)) return
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_spr, 1, field, error, exact=f, max_rounds=-1)
      call expect_error(error, stat_invalid_input, 'max_rounds = -1', 'negative max_rounds')
   contains
      subroutine run(inp, text, what)
         type(recovery_input_type), intent(in) :: inp
         character(len=*), intent(in) :: text, what
         call recover_grid(inp, pb%grid, pb%nodes, pb%hanging, method_sprc, 1, field, error, exact=f)
         call expect_error(error, stat_invalid_input, text, what)
      end subroutine run
   end subroutine test_input_errors

   !> Evaluation and estimate errors: element out of range, short arrays, unbuilt field,
   !> unknown interpolation, input that does not belong to the field.
   subroutine test_eval_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(problem_type) :: pb
      type(poly_field_type) :: f
      type(recovered_field_type) :: field, empty
      type(zz_estimate_type) :: est
      type(recovery_input_type) :: bad
      type(shape_type) :: s
      real(wp) :: sig(3), short(2)

      call new_body(pb%body, 'box')
      call new_box(s, 'box', [0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp], error)
      if (allocated(error)) return
      call pb%body%add_shape(csg_add, s, error)
      if (allocated(error)) return
      call make_field(plane_stress, 1.0_wp, 0.0_wp, f, error)
      if (allocated(error)) return
      call build_problem(pb, 1.0_wp, 2, 0, 1, 2, plane_stress, f, [bc_none], error)
      if (allocated(error)) return
      call recover_grid(pb%input, pb%grid, pb%nodes, pb%hanging, method_spr, 1, field, error)
      if (allocated(error)) return
      call field_eval(field, 17, [0.5_wp, 0.5_wp], sig, error)
      call expect_error(error, stat_invalid_input, 'element 17', 'element out of range')
      if (allocated(error)) return
      call field_eval(field, 1, [0.5_wp, 0.5_wp], short, error)
      call expect_error(error, stat_invalid_input, 'sigma 2', 'short sigma')
      if (allocated(error)) return
      call field_eval(field, 1, [0.5_wp, ieee_nan()], sig, error)
      call expect_error(error, stat_invalid_input, 'not finite', 'NaN point')
      if (allocated(error)) return
      call field_eval(field, 1, [0.5_wp, 0.5_wp], sig, error, 5)
      call expect_error(error, stat_invalid_input, 'interpolation = 5', 'unknown interpolation')
      if (allocated(error)) return
      call field_eval(empty, 1, [0.5_wp, 0.5_wp], sig, error)
      call expect_error(error, stat_invalid_input, 'not built', 'empty field')
      if (allocated(error)) return
      call estimate_error(pb%input, empty, est, error)
      call expect_error(error, stat_invalid_input, 'not built', 'estimate of an empty field')
      if (allocated(error)) return
      call estimate_error(pb%input, field, est, error, f, [.true.])
      call expect_error(error, stat_invalid_input, 'node_inside', 'short node_inside')
      if (allocated(error)) return
      bad = pb%input
      bad%elem_ptr = bad%elem_ptr(1:5)
      call estimate_error(bad, field, est, error)
      call expect_error(error, stat_invalid_input, 'disagree', 'estimate with foreign input')
   end subroutine test_eval_errors

   subroutine expect_error(error, stat, text, what)
      type(error_type), allocatable, intent(inout) :: error
      integer, intent(in) :: stat
      character(len=*), intent(in) :: text, what

      if (.not. allocated(error)) then
         call test_failed(error, what//': expected an error')
         return
      end if
      if (error%stat /= stat .or. index(error%message, text) == 0) then
         error%message = what//': expected stat '//achar(48 + stat)//' and "'//text//'", got: '//error%message
         error%stat = stat_invalid_input
         return
      end if
      deallocate (error)
   end subroutine expect_error

   real(wp) function ieee_nan()
      use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
      ieee_nan = ieee_value(1.0_wp, ieee_quiet_nan)
   end function ieee_nan

end module sprc_test_patches
