!> Tests of the iterative back end (`sprc_fem_petsc`: CG / GMRES + GAMG through
!> PETSc) against the direct one on the same assembled systems.
!>
!> Independent reference: CHOLMOD's solution of the same reduced system. The
!> iterative solve stops when its bound of the relative energy-norm error is
!> below tau (`iteration_tolerance`); the bound uses a condition estimate
!> from CG's Lanczos process, which approaches kappa(BA) from below, so the
!> check allows 2 tau. The direct solution itself is off by at most
!> c_backward eps / rcond relative in the same norm (backward stability:
!> ||e||_K / ||u||_K <= c eps kappa(K)).
module sprc_test_petsc
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: stat_invalid_input, stat_not_converged
   use sprc_core_material, only: plane_strain, solid
   use sprc_geometry_body, only: body_type
   use sprc_exact_lame, only: lame_cylinder_type, lame_sphere_type
   use sprc_fem_bc, only: fe_bc_type
   use sprc_fem_problem, only: elasticity_problem_type, solve_on_grid
   use sprc_fem_linear_solver, only: solver_direct, solver_iterative, solver_auto, use_iterative, &
      & auto_iterative_min_dofs, auto_never, solver_choice, set_solve_ranks
   use sprc_fem_petsc, only: petsc_solver_type, iteration_tolerance
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_fem_multigrid, only: prolongation_type, lattice_hierarchy, coarsen
   use sprc_test_fem, only: sphere_octant, lame_quarter, young
   use sprc_testsuite, only: unittest_type, new_unittest, check, error_type
   implicit none
   private

   public :: collect_petsc

   real(wp), parameter :: poisson = 0.3_wp
   !> Backward-error constant of the direct solve (as in test_fem).
   real(wp), parameter :: c_backward = 10.0_wp

contains

   subroutine collect_petsc(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('choice', test_choice), &
         new_unittest('sphere_weak_symmetry_hanging', test_sphere_weak), &
         new_unittest('sphere_strong_symmetry', test_sphere_strong), &
         new_unittest('lame_2d', test_lame_2d), &
         new_unittest('gmres', test_gmres), &
         new_unittest('not_converged', test_not_converged), &
         new_unittest('bad_layout', test_bad_layout), &
         new_unittest('nested_linear_field', test_nested_linear), &
         new_unittest('nested_start', test_nested_start), &
         new_unittest('multigrid_weights_by_hand', test_mg_by_hand), &
         new_unittest('multigrid_linear_fields_q1', test_mg_linear_q1), &
         new_unittest('multigrid_linear_fields_q2', test_mg_linear_q2), &
         new_unittest('multigrid_iterations', test_mg_iterations), &
         new_unittest('update_same_pattern', test_update), &
         new_unittest('multigrid_bad_lattice', test_mg_bad_lattice) &
         ]
   end subroutine collect_petsc

   !> 'auto' by dimension, degree and size (`auto_min_dofs`): 2D and 3D Q2
   !> stay direct, 3D Q1 goes iterative from its threshold on, and any system
   !> whose direct solve would not fit in memory goes iterative; explicit
   !> choices are kept.
   subroutine test_choice(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: q1

      call check(error, solver_choice('iterative') == solver_iterative .and. solver_choice('direct') == &
         & solver_direct .and. solver_choice('auto') == solver_auto .and. solver_choice('cg') == 0, 'names')
      if (allocated(error)) return
      call check(error, .not. use_iterative(solver_auto, 2, 1, 10**8) .and. .not. use_iterative(solver_auto, 2, 2, &
         & 10**8), '2D stays direct')
      if (allocated(error)) return
      q1 = auto_iterative_min_dofs(3, 1)
      call check(error, q1 < auto_never .and. .not. use_iterative(solver_auto, 3, 1, q1 - 1) .and. &
         & use_iterative(solver_auto, 3, 1, q1), '3D Q1 threshold')
      if (allocated(error)) return
      call check(error, .not. use_iterative(solver_auto, 3, 2, 10**8), '3D Q2 stays direct')
      if (allocated(error)) return
      call check(error, auto_iterative_min_dofs(4, 1) == auto_never .and. auto_iterative_min_dofs(3, 3) == &
         & auto_never, 'outside the table: direct')
      if (allocated(error)) return
      call check(error, use_iterative(solver_auto, 2, 1, 10, direct_fits=.false.) .and. &
         & use_iterative(solver_auto, 3, 2, 10, direct_fits=.false.) .and. &
         & .not. use_iterative(solver_auto, 3, 2, 10, direct_fits=.true.), 'auto: no room for a direct solve')
      if (allocated(error)) return
      call check(error, use_iterative(solver_iterative, 2, 1, 1) .and. .not. use_iterative(solver_direct, 3, 1, 10**8) &
         & .and. .not. use_iterative(solver_direct, 3, 1, 10**8, direct_fits=.false.), 'explicit choices')
      if (allocated(error)) return
      ! on several MPI ranks 'auto' distributes every solve; 'direct' stays direct
      call set_solve_ranks(2)
      call check(error, use_iterative(solver_auto, 2, 1, 10) .and. .not. use_iterative(solver_direct, 3, 1, 10**8), &
         & 'auto on 2 ranks')
      call set_solve_ranks(1)
   end subroutine test_choice

   !> Sphere octant, symmetry planes off the grid (Nitsche), one boundary
   !> refinement (hanging nodes) and aggregated small cuts.
   subroutine test_sphere_weak(error)
      type(error_type), allocatable, intent(out) :: error
      call sphere_case([-0.37_wp, -0.37_wp, -0.37_wp], 27.0_wp, 2, 1, 'weak symmetry', error)
   end subroutine test_sphere_weak

   !> Sphere octant with its planes on grid planes: strong symmetry, so some
   !> blocks have fixed components (identity rows in the padded system).
   subroutine test_sphere_strong(error)
      type(error_type), allocatable, intent(out) :: error
      call sphere_case([0.0_wp, 0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 'strong symmetry', error)
   end subroutine test_sphere_strong

   subroutine sphere_case(box_min, box_size, level, refine, what, error)
      real(wp), intent(in) :: box_min(3), box_size
      integer, intent(in) :: level, refine
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact
      call sphere_octant(body, bcs, exact, error)
      if (allocated(error)) return
      call compare_solvers(body, bcs, box_min, box_size, level, refine, solid, what, error)
   end subroutine sphere_case

   !> Lame quarter in plane strain: block size 2, three rigid modes.
   subroutine test_lame_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_cylinder_type) :: exact
      call lame_quarter(body, bcs, exact, plane_strain, error)
      if (allocated(error)) return
      call compare_solvers(body, bcs, [0.0_wp, 0.0_wp], 25.0_wp, 4, 1, plane_strain, 'Lame 2D', error)
   end subroutine test_lame_2d

   !> Solve directly, then iteratively on the same K and f: energy-norm
   !> difference within the bound of the module notes, Krylov iterations
   !> counted, and the same bits when the iterative solve is repeated.
   subroutine compare_solvers(body, bcs, box_min, box_size, level, refine, analysis, what, error)
      type(body_type), intent(in) :: body
      type(fe_bc_type), intent(in) :: bcs(:)
      real(wp), intent(in) :: box_min(:), box_size
      integer, intent(in) :: level, refine, analysis
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      type(elasticity_problem_type) :: problem
      real(wp), allocatable :: u_direct(:), u_iter(:)
      real(wp) :: tau, tol, rel
      integer :: its

      call solve_on_grid(problem, body, box_min, box_size, level, refine, 1, analysis, young, poisson, &
         & [(0.0_wp, its = 1, size(box_min))], bcs, error)
      if (allocated(error)) return
      call check(error, problem%solver_name == 'cholmod' .and. problem%solver_iterations == 0, &
         & what//': small systems are solved directly under auto')
      if (allocated(error)) return
      u_direct = problem%ubar
      tol = c_backward*epsilon(1.0_wp)/problem%rcond
      problem%solver = solver_iterative
      call problem%solve_reduced(error)
      if (allocated(error)) return
      call check(error, problem%solver_name == 'cg+gmg' .and. problem%solver_iterations > 0, &
         & what//': solved by CG + geometric multigrid, iterations counted')
      if (allocated(error)) return
      u_iter = problem%ubar
      its = problem%solver_iterations
      tau = iteration_tolerance(0.5_wp**(level + refine), 1)
      call energy_difference(problem, u_iter, u_direct, rel, error)
      if (allocated(error)) return
      call check(error, rel, 0.0_wp, 2.0_wp*tau + tol, what//': energy-norm difference to CHOLMOD')
      if (allocated(error)) return
      call problem%solve_reduced(error)
      if (allocated(error)) return
      call check(error, all(problem%ubar == u_iter) .and. problem%solver_iterations == its, &
         & what//': the same bits and iterations when repeated')
   end subroutine compare_solvers

   !> ||u - u_ref||_K / ||u_ref||_K with the problem's reduced stiffness K.
   subroutine energy_difference(problem, u, u_ref, rel, error)
      type(elasticity_problem_type), intent(in) :: problem
      real(wp), intent(in) :: u(:), u_ref(:)
      real(wp), intent(out) :: rel
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: ke(:), ku(:)

      rel = huge(1.0_wp)
      allocate (ke(size(u)), ku(size(u)))
      call problem%k%matvec(u - u_ref, ke, error)
      if (allocated(error)) return
      call problem%k%matvec(u_ref, ku, error)
      if (allocated(error)) return
      rel = sqrt(dot_product(u - u_ref, ke)/dot_product(u_ref, ku))
   end subroutine energy_difference

   !> GMRES + GAMG (the unsymmetric configuration) on an SPD system: the
   !> solution of CHOLMOD within 100 tau in the energy norm (GMRES bounds
   !> ||B r|| / ||B b|| by tau, and the error by about kappa(BA) times that;
   !> CG measures kappa(BA) near 4 on these systems, so 100 leaves margin), and
   !> a transposed solve, which this configuration cannot do, is refused.
   subroutine test_gmres(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact
      type(elasticity_problem_type) :: problem
      type(petsc_solver_type) :: krylov
      type(error_type), allocatable :: refused
      real(wp), allocatable :: x(:)
      real(wp) :: tau, rel

      call sphere_octant(body, bcs, exact, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, solid, young, poisson, &
         & [0.0_wp, 0.0_wp, 0.0_wp], bcs, error)
      if (allocated(error)) return
      call krylov%set_blocks(problem%constraints%dof, problem%mesh%nodes%x(:, problem%constraints%master_node), error)
      if (allocated(error)) return
      tau = iteration_tolerance(0.5_wp**3, 1)
      krylov%tolerance = tau
      krylov%symmetric = .false.
      call krylov%factorize(problem%k, error)
      if (allocated(error)) return
      allocate (x(size(problem%f)))
      call krylov%solve(problem%f, x, error)
      if (allocated(error)) return
      call krylov%solve(problem%f, x, refused, transposed=.true.)
      call krylov%destroy()
      call check(error, allocated(refused), 'a transposed GMRES solve is refused')
      if (allocated(error)) return
      call energy_difference(problem, x, problem%ubar, rel, error)
      if (allocated(error)) return
      call check(error, rel, 0.0_wp, 100.0_wp*tau + c_backward*epsilon(1.0_wp)/problem%rcond, &
         & 'GMRES: energy-norm difference to CHOLMOD')
   end subroutine test_gmres

   !> Too few iterations: stat_not_converged with the count and the residual.
   subroutine test_not_converged(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact
      type(elasticity_problem_type) :: problem
      type(petsc_solver_type) :: krylov
      type(error_type), allocatable :: failure
      real(wp), allocatable :: x(:)

      call sphere_octant(body, bcs, exact, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [0.0_wp, 0.0_wp, 0.0_wp], 25.0_wp, 3, 0, 1, solid, young, poisson, &
         & [0.0_wp, 0.0_wp, 0.0_wp], bcs, error)
      if (allocated(error)) return
      call krylov%set_blocks(problem%constraints%dof, problem%mesh%nodes%x(:, problem%constraints%master_node), error)
      if (allocated(error)) return
      krylov%max_iterations = 2
      krylov%tolerance = 1.0e-12_wp
      call krylov%factorize(problem%k, error)
      if (allocated(error)) return
      allocate (x(size(problem%f)))
      call krylov%solve(problem%f, x, failure)
      call krylov%destroy()
      call check(error, allocated(failure), 'two iterations do not reach 1e-12')
      if (allocated(error)) return
      call check(error, failure%stat == stat_not_converged, 'status: '//failure%message)
      if (allocated(error)) return
      call check(error, index(failure%message, 'after 2 iterations') > 0 .and. &
         & index(failure%message, 'relative residual') > 0, 'message: '//failure%message)
   end subroutine test_not_converged

   !> A layout that does not number every unknown once is refused.
   subroutine test_bad_layout(error)
      type(error_type), allocatable, intent(out) :: error
      type(petsc_solver_type) :: krylov
      type(error_type), allocatable :: refused
      real(wp) :: x(3, 2)

      x = 0.0_wp
      call krylov%set_blocks(reshape([1, 2, 3, 3, 4, 5], [3, 2]), x, refused)
      call check(error, allocated(refused), 'a repeated unknown is refused')
      if (allocated(error)) return
      call check(error, refused%stat == stat_invalid_input, 'status: '//refused%message)
      if (allocated(error)) return
      deallocate (refused)
      call krylov%set_blocks(reshape([1, 2, 3, 4, 5, 7], [3, 2]), x, refused)
      call check(error, allocated(refused), 'a gap in the numbering is refused')
   end subroutine test_bad_layout

   !> The held displacement of a grid reproduces a linear field exactly (Q1
   !> interpolates it) at the master nodes of the next level's grid, the
   !> nodes on faces next to external cells included: within 100 eps of the
   !> field's size.
   subroutine test_nested_linear(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact
      type(elasticity_problem_type) :: coarse, fine
      type(fe_displacement_type) :: held
      real(wp), allocatable :: x(:, :), v(:, :)
      real(wp), parameter :: a(3, 3) = reshape([1.0_wp, -2.0_wp, 0.5_wp, 3.0_wp, 0.25_wp, -1.0_wp, 2.0_wp, &
         & 1.5_wp, -0.75_wp], [3, 3]), c(3) = [0.3_wp, -0.2_wp, 0.1_wp]
      real(wp) :: scale
      integer :: n

      call nested_pair(body, bcs, exact, coarse, fine, error)
      if (allocated(error)) return
      do n = 1, size(coarse%u, 2)
         coarse%u(:, n) = matmul(a, coarse%mesh%nodes%x(:, n)) + c
      end do
      call coarse%hold_displacement(held, error)
      if (allocated(error)) return
      x = fine%mesh%nodes%x(:, fine%constraints%master_node)
      allocate (v(3, size(x, 2)))
      call held%values_at(x, v)
      scale = maxval(abs(coarse%u))
      do n = 1, size(x, 2)
         v(:, n) = v(:, n) - (matmul(a, x(:, n)) + c)
      end do
      call check(error, maxval(abs(v))/scale, 0.0_wp, 100.0_wp*epsilon(1.0_wp), &
         & 'the coarse grid''s linear field at the fine masters')
   end subroutine test_nested_linear

   !> Nested iteration: the fine solve started from the coarse solution
   !> (`start`) reaches CHOLMOD's solution within the same bound as from
   !> zero (compare_solvers), in fewer iterations, with the same bits when
   !> repeated.
   subroutine test_nested_start(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact
      type(elasticity_problem_type) :: coarse, fine
      real(wp), allocatable :: u_direct(:), u_start(:)
      real(wp) :: tau, rel
      integer :: its_zero, its_start

      call nested_pair(body, bcs, exact, coarse, fine, error)
      if (allocated(error)) return
      u_direct = fine%ubar
      fine%solver = solver_iterative
      call fine%solve_reduced(error)
      if (allocated(error)) return
      its_zero = fine%solver_iterations
      allocate (fine%start)
      call coarse%hold_displacement(fine%start, error)
      if (allocated(error)) return
      call fine%solve_reduced(error)
      if (allocated(error)) return
      its_start = fine%solver_iterations
      u_start = fine%ubar
      call check(error, its_start < its_zero, 'fewer iterations from the coarse solution: '// &
         & itoa(its_start)//' against '//itoa(its_zero))
      if (allocated(error)) return
      tau = iteration_tolerance(0.5_wp**fine%mesh%grid%max_level, 1)
      call energy_difference(fine, u_start, u_direct, rel, error)
      if (allocated(error)) return
      call check(error, rel, 0.0_wp, 2.0_wp*tau + c_backward*epsilon(1.0_wp)/fine%rcond, &
         & 'energy-norm difference to CHOLMOD from the coarse start')
      if (allocated(error)) return
      call fine%solve_reduced(error)
      if (allocated(error)) return
      call check(error, all(fine%ubar == u_start) .and. fine%solver_iterations == its_start, &
         & 'the same bits and iterations when repeated')
   end subroutine test_nested_start

   !> The sphere octant with its planes off the grid, solved (directly) at
   !> levels 2 and 3.
   subroutine nested_pair(body, bcs, exact, coarse, fine, error)
      type(body_type), intent(out) :: body
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      type(lame_sphere_type), intent(out) :: exact
      type(elasticity_problem_type), intent(out) :: coarse, fine
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: box_min(3) = [-0.37_wp, -0.53_wp, -0.29_wp], box_size = 27.5_wp

      call sphere_octant(body, bcs, exact, error)
      if (allocated(error)) return
      call solve_on_grid(coarse, body, box_min, box_size, 2, 0, 1, solid, young, poisson, [0.0_wp, 0.0_wp, 0.0_wp], &
         & bcs, error)
      if (allocated(error)) return
      call solve_on_grid(fine, body, box_min, box_size, 3, 0, 1, solid, young, poisson, [0.0_wp, 0.0_wp, 0.0_wp], &
         & bcs, error)
   end subroutine nested_pair

   !> One coarsening of eight 2D nodes (step 1) on a 3 x 3 lattice whose
   !> corner (2, 2) is missing, to spacing 2, against weights worked out by
   !> hand: C-points (0,0), (2,0), (0,2) (coarse nodes 1, 2, 3); (1,0) and
   !> (0,1) take the linear weights 1/2, 1/2; (1,1) misses its corner (2,2):
   !> the weights closest to (1/4, 1/4, 1/4) that reproduce linear fields on
   !> the three others are (0, 1/2, 1/2); (2,1) and (1,2) have one C-point
   !> in their cell and take the nearest neighbour C-points: the linear
   !> field through the three, u(2,1) = u(2,0) + (u(0,2) - u(0,0))/2 and
   !> u(1,2) = u(0,2) + (u(2,0) - u(0,0))/2. Within 10 eps (a 3 x 3 solve).
   subroutine test_mg_by_hand(error)
      type(error_type), allocatable, intent(out) :: error
      type(prolongation_type) :: p
      integer, parameter :: nodes(2, 8) = reshape([0, 0, 1, 0, 2, 0, 0, 1, 1, 1, 2, 1, 0, 2, 1, 2], [2, 8])
      real(wp), parameter :: expected(8, 3) = reshape([ &
         & 1.0_wp, 0.5_wp, 0.0_wp, 0.5_wp, 0.0_wp, -0.5_wp, 0.0_wp, -0.5_wp, &
         & 0.0_wp, 0.5_wp, 1.0_wp, 0.0_wp, 0.5_wp, 1.0_wp, 0.0_wp, 0.5_wp, &
         & 0.0_wp, 0.0_wp, 0.0_wp, 0.5_wp, 0.5_wp, 0.5_wp, 1.0_wp, 1.0_wp], [8, 3])
      real(wp) :: dense(8, 3)
      integer :: i, q

      call coarsen(nodes, 2, p, error)
      if (allocated(error)) return
      call check(error, p%n_fine == 8 .and. p%n_coarse == 3, 'eight nodes to three: '//itoa(p%n_coarse))
      if (allocated(error)) return
      call check(error, all(p%lattice == reshape([0, 0, 2, 0, 0, 2], [2, 3])), 'the C-points in node order')
      if (allocated(error)) return
      dense = 0.0_wp
      do i = 1, 8
         do q = p%rowptr(i), p%rowptr(i + 1) - 1
            dense(i, p%col(q)) = p%val(q)
         end do
      end do
      call check(error, maxval(abs(dense - expected)), 0.0_wp, 10.0_wp*epsilon(1.0_wp), 'weights by hand')
   end subroutine test_mg_by_hand

   !> Q1 sphere octant, planes off the grid, one boundary refinement (hanging
   !> nodes) and aggregated cuts: every level's prolongation reproduces
   !> linear fields (`mg_linear_fields`).
   subroutine test_mg_linear_q1(error)
      type(error_type), allocatable, intent(out) :: error
      call mg_linear_fields(1, 3, 1, error)
   end subroutine test_mg_linear_q1

   !> Q2: the first level is the p-coarsening to the vertex lattice.
   subroutine test_mg_linear_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call mg_linear_fields(2, 2, 0, error)
   end subroutine test_mg_linear_q2

   !> The masters' hierarchy of a sphere-octant grid has at least two levels
   !> that shrink, and P applied to a linear field at the coarse nodes gives
   !> that field at the fine ones within 100 eps of its size on every level
   !> (the weights are exact or the solution of a 4 x 4 system).
   subroutine mg_linear_fields(degree, level, refine, error)
      integer, intent(in) :: degree, level, refine
      type(error_type), allocatable, intent(out) :: error
      type(elasticity_problem_type) :: problem
      type(prolongation_type), allocatable :: p(:)
      integer, allocatable :: fine(:, :)
      real(wp), allocatable :: uc(:), uf(:)
      real(wp), parameter :: a(3) = [0.7_wp, -1.3_wp, 2.1_wp], c = 0.4_wp
      real(wp) :: worst
      integer :: l, i, q

      call off_grid_sphere(problem, level, refine, degree, error)
      if (allocated(error)) return
      fine = problem%mesh%nodes%lattice(:, problem%constraints%master_node)
      call lattice_hierarchy(fine, 2/degree, p, error, coarse=10)
      if (allocated(error)) return
      call check(error, size(p) >= 2, 'levels: '//itoa(size(p)))
      if (allocated(error)) return
      worst = 0.0_wp
      do l = 1, size(p)
         call check(error, p(l)%n_coarse < p(l)%n_fine, 'level '//itoa(l)//' shrinks')
         if (allocated(error)) return
         uc = matmul(a, real(p(l)%lattice, wp)) + c
         if (l == 1) then
            uf = matmul(a, real(fine, wp)) + c
         else
            uf = matmul(a, real(p(l - 1)%lattice, wp)) + c
         end if
         do i = 1, p(l)%n_fine
            q = p(l)%rowptr(i)
            worst = max(worst, abs(dot_product(p(l)%val(q:p(l)%rowptr(i + 1) - 1), uc(p(l)%col(q:p(l)%rowptr(i + 1) &
               & - 1))) - uf(i))/maxval(abs(uf)))
         end do
      end do
      call check(error, worst, 0.0_wp, 100.0_wp*epsilon(1.0_wp), 'linear fields through every level')
   end subroutine mg_linear_fields

   !> Iterations on a small 3D problem (sphere octant, planes off the grid,
   !> level 4: 11k unknowns, a hierarchy of three levels) from zero to the
   !> same tolerance: geometric multigrid needs fewer iterations than GAMG
   !> and at most 20 (measured: 16 against 24, with one Gauss-Seidel sweep
   !> on each side of the coarse correction; 8 with the two Chebyshev
   !> steps of symmetric sweeps, which cost more per iteration).
   subroutine test_mg_iterations(error)
      type(error_type), allocatable, intent(out) :: error
      type(elasticity_problem_type) :: problem
      integer :: its(2), pass
      real(wp), allocatable :: x(:)

      call off_grid_sphere(problem, 4, 0, 1, error)
      if (allocated(error)) return
      allocate (x(size(problem%f)))
      do pass = 1, 2
         block
            type(petsc_solver_type) :: krylov
            call krylov%set_blocks(problem%constraints%dof, problem%mesh%nodes%x(:, problem%constraints%master_node), &
               & error)
            if (allocated(error)) return
            if (pass == 2) call krylov%set_lattice(problem%mesh%nodes%lattice(:, problem%constraints%master_node), 2, &
               & error)
            if (allocated(error)) return
            krylov%tolerance = iteration_tolerance(0.5_wp**4, 1)
            call krylov%factorize(problem%k, error)
            if (allocated(error)) return
            call krylov%solve(problem%f, x, error)
            if (allocated(error)) return
            its(pass) = krylov%iterations
            call check(error, krylov%multigrid .eqv. (pass == 2), 'the preconditioner asked for')
            call krylov%destroy()
            if (allocated(error)) return
         end block
      end do
      call check(error, its(2) < its(1) .and. its(2) <= 20, 'geometric multigrid '//itoa(its(2))// &
         & ' iterations, GAMG '//itoa(its(1)))
   end subroutine test_mg_iterations

   !> `update` with new values on the same pattern (K + s I, s the mean
   !> diagonal: a change the old preconditioner does not scale away) gives
   !> what a solver factorized anew on them gives: the same iterations and
   !> the same solution to 1e-9 relative (the same Galerkin products and
   !> coarse factor up to the order of their sums; the solves stop at 1e-9).
   !> With the preconditioner of K kept (the matrix not marked changed),
   !> 14 iterations against 8.
   subroutine test_update(error)
      type(error_type), allocatable, intent(out) :: error
      type(elasticity_problem_type) :: problem
      type(petsc_solver_type) :: kept, fresh
      real(wp), allocatable :: x(:), xf(:)
      integer :: i, its
      real(wp) :: shift

      call off_grid_sphere(problem, 3, 0, 1, error)
      if (allocated(error)) return
      allocate (x(size(problem%f)), xf(size(problem%f)))
      call multigrid_solver(kept, problem, error)
      if (.not. allocated(error)) call multigrid_solver(fresh, problem, error)
      if (.not. allocated(error)) call kept%factorize(problem%k, error)
      if (allocated(error)) return
      shift = 0.0_wp
      do i = 1, problem%k%nrows
         shift = shift + sum(problem%k%val(problem%k%rowptr(i):problem%k%rowptr(i + 1) - 1), &
            & mask=problem%k%col(problem%k%rowptr(i):problem%k%rowptr(i + 1) - 1) == i)
      end do
      shift = shift/problem%k%nrows
      do i = 1, problem%k%nrows
         where (problem%k%col(problem%k%rowptr(i):problem%k%rowptr(i + 1) - 1) == i) &
            & problem%k%val(problem%k%rowptr(i):problem%k%rowptr(i + 1) - 1) = &
            & problem%k%val(problem%k%rowptr(i):problem%k%rowptr(i + 1) - 1) + shift
      end do
      call kept%update(problem%k, error)
      if (.not. allocated(error)) call kept%solve(problem%f, x, error)
      if (.not. allocated(error)) call fresh%factorize(problem%k, error)
      if (.not. allocated(error)) call fresh%solve(problem%f, xf, error)
      if (allocated(error)) return
      its = kept%iterations
      call check(error, its == fresh%iterations .and. maxval(abs(x - xf)) <= 1.0e-9_wp*maxval(abs(xf)), &
         & 'updated: '//itoa(its)//' iterations, anew: '//itoa(fresh%iterations)//', solutions differ by '// &
         & itoa(nint(1.0e12_wp*maxval(abs(x - xf))/maxval(abs(xf))))//'e-12 relative')
      call kept%destroy()
      call fresh%destroy()
   end subroutine test_update

   subroutine multigrid_solver(krylov, problem, error)
      type(petsc_solver_type), intent(inout) :: krylov
      type(elasticity_problem_type), intent(in) :: problem
      type(error_type), allocatable, intent(out) :: error
      call krylov%set_blocks(problem%constraints%dof, problem%mesh%nodes%x(:, problem%constraints%master_node), error)
      if (.not. allocated(error)) call krylov%set_lattice(problem%mesh%nodes%lattice(:, &
         & problem%constraints%master_node), 2, error)
      krylov%tolerance = 1.0e-9_wp
   end subroutine multigrid_solver

   !> Lattice points that do not fit the blocks, two blocks at one point,
   !> or a point off the node step: each a clear error, never a crash.
   subroutine test_mg_bad_lattice(error)
      type(error_type), allocatable, intent(out) :: error
      type(elasticity_problem_type) :: problem
      type(petsc_solver_type) :: krylov
      type(error_type), allocatable :: refused
      integer, allocatable :: lattice(:, :)

      call off_grid_sphere(problem, 3, 0, 1, error)
      if (allocated(error)) return
      call krylov%set_blocks(problem%constraints%dof, problem%mesh%nodes%x(:, problem%constraints%master_node), error)
      if (allocated(error)) return
      lattice = problem%mesh%nodes%lattice(:, problem%constraints%master_node)
      call krylov%set_lattice(lattice(:, 2:), 2, refused)
      call check(error, allocated(refused), 'one point too few is refused')
      if (allocated(error)) return
      call check(error, refused%stat == stat_invalid_input, 'status: '//refused%message)
      if (allocated(error)) return
      deallocate (refused)
      lattice(:, 2) = lattice(:, 1)
      call factorize_refused(krylov, problem, lattice, 2, 'share a lattice point', error)
      if (allocated(error)) return
      lattice = problem%mesh%nodes%lattice(:, problem%constraints%master_node)
      lattice(1, 1) = lattice(1, 1) + 1
      call factorize_refused(krylov, problem, lattice, 2, 'not on the node lattice', error)
   end subroutine test_mg_bad_lattice

   !> The sphere octant with its planes off the grid (Nitsche), solved
   !> directly at `level` with `refine` boundary refinements, Q`degree`.
   subroutine off_grid_sphere(problem, level, refine, degree, error)
      type(elasticity_problem_type), intent(out) :: problem
      integer, intent(in) :: level, refine, degree
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(fe_bc_type), allocatable :: bcs(:)
      type(lame_sphere_type) :: exact
      call sphere_octant(body, bcs, exact, error)
      if (allocated(error)) return
      call solve_on_grid(problem, body, [-0.37_wp, -0.53_wp, -0.29_wp], 27.5_wp, level, refine, degree, solid, &
         & young, poisson, [0.0_wp, 0.0_wp, 0.0_wp], bcs, error)
   end subroutine off_grid_sphere

   subroutine factorize_refused(krylov, problem, lattice, step, what, error)
      type(petsc_solver_type), intent(inout) :: krylov
      type(elasticity_problem_type), intent(in) :: problem
      integer, intent(in) :: lattice(:, :), step
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: refused
      call krylov%set_lattice(lattice, step, error)
      if (allocated(error)) return
      call krylov%factorize(problem%k, refused)
      call krylov%destroy()
      call check(error, allocated(refused), what//': refused')
      if (allocated(error)) return
      call check(error, refused%stat == stat_invalid_input .and. index(refused%message, what) > 0, &
         & 'status and message: '//refused%message)
   end subroutine factorize_refused

end module sprc_test_petsc
