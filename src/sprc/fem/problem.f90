!> Linear elasticity on one body's cut Cartesian grid: Q1 / Q2 elements, immersed boundary
!> conditions, small-cut robustness, sparse solves and the post-processing recovery needs.
!>
!> Use:
!> ```
!> call mesh%build(body, box_min, box_size, level, refine_boundary, degree, error)
!> call mesh%integrate(quad, error)
!> call problem%setup(mesh, analysis, young, poisson, body_force, bcs, error [, exact] [, eta] [, gamma])
!> call problem%solve(error)      ! = assemble, solve_reduced, set_solution(ubar)
!> ! problem%u(dim, n_nodes), problem%stress_at(x, sigma, error),
!> ! problem%element_points(e, x, w, sigma), problem%energy_error(...),
!> ! problem%mesh (grid, nodes, cell rules), problem%t_assembly, t_solve
!> ```
!> The inputs are the body's cut mesh (`sprc_grid_cut_mesh`), which setup takes over
!> without a copy (`move_alloc`), and plain data: the material, a constant body force,
!> boundary conditions by shape index (`sprc_fem_bc`), optionally an exact solution.
!>
!> Formulation (doc/theory.md, section 3): a(u, v) + N(u, v) = l(v) on V_h = {T ubar},
!> integrated over the true domain by the cut-cell rules; Dirichlet and off-grid symmetry
!> surfaces add the symmetric Nitsche terms with penalty gamma dmax/h (dmax the largest
!> diagonal entry of D: the material's stiffness scale). Symmetry on a halfspace lying on
!> grid planes (every quarter / octant scene) is strong: u_k = 0 at its nodes.
!> `default_gamma` = 10 (p + 1)^2 leaves a margin of 2 or more over twice the trace-inverse
!> constant, which aggregation makes independent of the cut; if the system still comes out
!> indefinite CHOLMOD says so and UMFPACK solves it (`solver_note`).
!>
!> Small cut cells: cell aggregation (`sprc_fem_aggregation`, threshold `eta`)
!> through the constraint machinery (`sprc_fem_constraints`).
!>
!> Nearly incompressible materials: with the projected dilatation
!> (`sprc_fem_dilatation`, optional `dilatation` of setup) D is replaced by its
!> deviatoric part in a, in the Nitsche terms and in the stresses, and each
!> aggregate adds its projected volumetric term (`add_aggregate_block`);
!> every stress this type returns is then sigma_bar.
!>
!> Determinism: quadrature and element matrices are computed in parallel
!> (OpenMP), each element's block written to the places its index fixes in a
!> block list, whose rows are then summed in parallel, each entry over the
!> blocks in element order (`sprc_fem_sparse`); reductions (norms, errors) are
!> summed serially in element order. The bits do not depend on the thread count.
module sprc_fem_problem
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular, &
      & stat_not_positive_definite
   use sprc_core_lapack, only: dsyev
   use sprc_core_blas_threads, only: blas_serial_begin, blas_serial_end
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, analysis_name, &
      & material_matrix, compliance_matrix
   use sprc_core_timer, only: timer_type
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_geometry_body, only: body_type
   use sprc_geometry_shape, only: shape_halfspace
   use sprc_geometry_region, only: cell_inside
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, default_points, tensor_point
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_grid_share, only: share_type, share_range
   use sprc_exact_solution, only: exact_solution_type
   use sprc_fem_sparse, only: block_list_type, csr_type
   use sprc_fem_cholmod, only: cholmod_solver_type
   use sprc_fem_umfpack, only: umfpack_solver_type
   use sprc_fem_linear_solver, only: linear_solver_type, solver_auto, use_iterative
   use sprc_fem_petsc, only: petsc_solver_type, iteration_tolerance, start_petsc
   use sprc_fem_multigrid, only: prolongation_type, lattice_hierarchy
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_fem_element, only: shape_functions, strain_matrix, traction_matrix, displacement_matrix, &
      & add_stiffness, mirror_upper, element_stress, element_strain
   use sprc_fem_bc, only: fe_bc_type, check_bcs, bc_free, bc_pressure, bc_traction, bc_displacement, &
      & bc_symmetry, bc_exact_traction, bc_exact_displacement
   use sprc_fem_aggregation, only: aggregate_cells, default_eta
   use sprc_fem_constraints, only: constraint_type
   use sprc_fem_dilatation, only: dilatation_type, dilatation_auto, resolve_dilatation
   implicit none
   private

   public :: elasticity_problem_type, default_gamma, rigid_tol, solve_on_grid, gamma_range, gamma_note
   public :: free_motions, motion_names, solve_spd_or_lu, master_hierarchy, lattice_step

   !> A rigid-body mode whose normalised energy (module notes of `check_rigid_modes`)
   !> is below this is free. Free modes give round-off, ~1e-15; the weakest
   !> restraint (one Nitsche point or one zeroed node row on a 1e6-node grid)
   !> gives >= ~1e-7.
   real(wp), parameter :: rigid_tol = 1.0e-10_wp

   !> The FE problem of one body (module notes).
   type :: elasticity_problem_type
      !> Dimension, element degree, analysis kind, Voigt size, nodes per element.
      integer :: dim = 0, degree = 0, analysis = 0, nstress = 0, nen = 0
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      !> Material matrix, compliance, largest diagonal entry of d.
      real(wp) :: d(6, 6) = 0.0_wp, compliance(6, 6) = 0.0_wp, dmax = 0.0_wp
      real(wp) :: body_force(3) = 0.0_wp
      !> Aggregation threshold and Nitsche penalty factor in use.
      real(wp) :: eta = 0.0_wp, gamma = 0.0_wp
      !> The cut mesh the problem is set up on (taken over from the caller by `setup`).
      type(cut_mesh_type), allocatable :: mesh
      type(fe_bc_type), allocatable :: bcs(:)
      class(exact_solution_type), allocatable :: exact
      !> Condition index of each surface id (0: free surface; sprc_geometry_body notes);
      !> symmetry imposed strongly.
      integer, allocatable :: bc_of_shape(:)
      logical, allocatable :: strong_shape(:)
      !> Aggregation root of each element (root(e) = e: well posed).
      integer, allocatable :: root(:)
      !> Aggregated (ill-posed) elements.
      integer :: n_aggregated = 0
      !> u = T ubar.
      type(constraint_type) :: constraints
      !> Projected dilatation (B-bar) when active (`sprc_fem_dilatation`).
      type(dilatation_type) :: dilatation
      !> Volume stiffness of the whole unit cell [0, 1]^dim under the inside cells' tensor
      !> rule, and the integrals of its shape functions (`whole_cell_terms`).
      real(wp), allocatable :: k_whole(:, :), n_whole(:)
      !> Reduced stiffness and load.
      type(csr_type) :: k
      real(wp), allocatable :: f(:)
      !> A level shared out among ranks (`sprc_study_partition`'s `solve_level`):
      !> `k` and `f` hold only this rank's reduced rows, row_bounds(r + 1) ..
      !> row_bounds(r + 2) - 1 for rank r of `rows_share` (the other rows of k
      !> are empty, of f zero; no rank holds the whole K), and only the
      !> iterative solve, distributed over the ranks, can solve them
      !> (`solve_level` frees them after it). Not allocated: k and f are whole.
      class(share_type), allocatable :: rows_share
      integer(i8), allocatable :: row_bounds(:)
      !> Reduced solution and nodal displacements (dim, n_nodes).
      real(wp), allocatable :: ubar(:), u(:, :)
      logical :: solved = .false.
      !> Linear solver choice (`sprc_fem_linear_solver`: solver_auto, solver_direct,
      !> solver_iterative); a setting, read by `solve_reduced`.
      integer :: solver = solver_auto
      !> 'cholmod', 'umfpack', 'cg+gmg', 'gmres+gmg' (geometric multigrid), 'cg+gamg' or 'gmres+gamg';
      !> why the fallback was taken ('' if not).
      character(len=:), allocatable :: solver_name, solver_note
      !> Krylov iterations of the last solve (0 for a direct solve).
      integer :: solver_iterations = 0
      !> This body's displacement on another grid of its study, where an
      !> iterative solve starts (nested iteration, `sprc_fem_nested`); the
      !> direct solvers ignore it. A setting, read by `solve_reduced`.
      type(fe_displacement_type), allocatable :: start
      !> Reciprocal 1-norm condition estimate of the reduced stiffness (from the solver).
      real(wp) :: rcond = -1.0_wp
      !> Wall-clock seconds of the phases.
      real(wp) :: t_assembly = 0.0_wp, t_solve = 0.0_wp
   contains
      procedure :: setup => problem_setup
      procedure :: solve => problem_solve
      procedure :: assemble => problem_assemble
      procedure :: solve_reduced => problem_solve_reduced
      procedure :: set_solution => problem_set_solution
      procedure :: n_dofs
      procedure :: element_box
      procedure :: element_displacements
      procedure :: stress_in_element
      procedure :: stress_at
      procedure :: element_points
      procedure :: energy_error
      procedure :: scaled_rcond
      procedure :: rigid_modes
      procedure :: hold_displacement
   end type elasticity_problem_type

contains

   !> Default Nitsche penalty factor for degree p: 10 (p + 1)^2 (module notes).
   pure real(wp) function default_gamma(degree)
      integer, intent(in) :: degree
      default_gamma = 10.0_wp*real((degree + 1)**2, wp)
   end function default_gamma

   !> Safe range [lo, hi] of the Nitsche factor for degree p: default / 2 to
   !> 100 default. Below, coercivity is no longer guaranteed by the estimate
   !> of the module notes (the default keeps a margin of 2); above, the
   !> condition number grows in proportion to gamma (the stiffness's rcond
   !> falls 10x per decade) and the method tends to a pure penalty. Inside,
   !> the errors move by less than the discretization error (stability_study).
   pure function gamma_range(degree) result(range)
      integer, intent(in) :: degree
      real(wp) :: range(2)
      range = [0.5_wp, 100.0_wp]*default_gamma(degree)
   end function gamma_range

   !> '' when gamma lies in `gamma_range(degree)`, else a sentence saying what
   !> to expect (for a warning).
   function gamma_note(degree, gamma) result(note)
      integer, intent(in) :: degree
      real(wp), intent(in) :: gamma
      character(len=:), allocatable :: note
      real(wp) :: range(2)
      character(len=16) :: b(3)
      range = gamma_range(degree)
      note = ''
      if (gamma >= range(1) .and. gamma <= range(2)) return
      write (b(1), '(es10.3)') gamma
      write (b(2), '(f0.1)') range(1)
      write (b(3), '(f0.1)') range(2)
      note = 'Nitsche gamma = '//trim(adjustl(b(1)))//' lies outside the safe range ['//trim(b(2))//', '// &
         & trim(b(3))//'] for Q'//achar(48 + degree)//': '
      if (gamma < range(1)) then
         note = note//'coercivity is not guaranteed (the stiffness may be indefinite, the weak conditions '// &
            & 'poorly held); raise it'
      else
         note = note//'the condition number grows in proportion to gamma; lower it'
      end if
   end function gamma_note

   !> A convenience: build the cut mesh of `body` (uniform `level`,
   !> `refine_boundary` extra levels on cut cells, Q`degree` nodes, hanging
   !> constraints, cut quadrature with `points` per direction, default
   !> `default_points`), then `setup` and `solve` the problem. `t_mesh`
   !> (optional) gets the grid, node and constraint build time.
   subroutine solve_on_grid(problem, body, box_min, box_size, level, refine_boundary, degree, analysis, young, &
         & poisson, body_force, bcs, error, exact, points, eta, gamma, t_mesh, dilatation)
      type(elasticity_problem_type), intent(out) :: problem
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: box_min(:), box_size
      integer, intent(in) :: level, refine_boundary, degree, analysis
      real(wp), intent(in) :: young, poisson, body_force(:)
      type(fe_bc_type), intent(in) :: bcs(:)
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      integer, intent(in), optional :: points
      real(wp), intent(in), optional :: eta, gamma
      real(wp), intent(out), optional :: t_mesh
      integer, intent(in), optional :: dilatation
      type(cut_mesh_type), allocatable :: mesh
      type(cut_quadrature_type) :: quad
      integer :: q

      allocate (mesh)
      call mesh%build(body, box_min, box_size, level, refine_boundary, degree, error)
      if (allocated(error)) return
      if (present(t_mesh)) t_mesh = mesh%t_mesh
      q = default_points(degree)
      if (present(points)) q = points
      call new_cut_quadrature(quad, body%dim, q, error)
      if (allocated(error)) return
      call mesh%integrate(quad, error)
      if (allocated(error)) return
      call problem%setup(mesh, analysis, young, poisson, body_force, bcs, error, exact, eta, gamma, dilatation)
      if (allocated(error)) return
      call problem%solve(error)
   end subroutine solve_on_grid

   !> Prepare the problem on `mesh` (built and integrated): validate, take the
   !> mesh over (`mesh` is deallocated on return unless an input was refused),
   !> aggregate small cells and build T (t_assembly). `body_force` has dim
   !> entries; `eta` defaults to `default_eta`, `gamma` to `default_gamma(degree)`.
   subroutine problem_setup(self, mesh, analysis, young, poisson, body_force, bcs, error, exact, eta, gamma, &
         & dilatation)
      class(elasticity_problem_type), intent(out) :: self
      type(cut_mesh_type), allocatable, intent(inout) :: mesh
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson, body_force(:)
      type(fe_bc_type), intent(in) :: bcs(:)
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      real(wp), intent(in), optional :: eta, gamma
      !> `sprc_fem_dilatation` choice (default `dilatation_auto`).
      integer, intent(in), optional :: dilatation
      type(timer_type) :: timer
      integer, allocatable :: plane_axis(:)
      real(wp), allocatable :: plane_coord(:)
      integer :: i

      if (.not. allocated(mesh)) then
         call fatal_error(error, 'elasticity setup: no mesh was given', stat_invalid_input)
         return
      end if
      call check_inputs(mesh%body, mesh%grid, mesh%nodes, mesh%hanging, mesh%quad, allocated(mesh%vol_ptr), analysis, &
         & body_force, error)
      if (allocated(error)) return
      call check_bcs(bcs, mesh%body%nsurface(), mesh%grid%dim, present(exact), error)
      if (allocated(error)) return
      if (present(exact)) then
         call check_exact(exact, analysis, young, poisson, error)
         if (allocated(error)) return
         allocate (self%exact, source=exact)
      end if
      self%dim = mesh%grid%dim
      self%degree = mesh%nodes%degree
      self%analysis = analysis
      self%nstress = voigt_size(analysis)
      self%nen = mesh%nodes%nodes_per_element
      self%young = young
      self%poisson = poisson
      call material_matrix(analysis, young, poisson, self%d(1:self%nstress, 1:self%nstress), error)
      if (allocated(error)) return
      call compliance_matrix(analysis, young, poisson, self%compliance(1:self%nstress, 1:self%nstress), error)
      if (allocated(error)) return
      self%dmax = 0.0_wp
      do i = 1, self%nstress
         self%dmax = max(self%dmax, self%d(i, i))
      end do
      self%body_force(1:self%dim) = body_force
      self%eta = default_eta
      if (present(eta)) self%eta = eta
      self%gamma = default_gamma(self%degree)
      if (present(gamma)) self%gamma = gamma
      if (.not. (self%eta >= 0.0_wp .and. self%eta <= 1.0_wp)) then
         call fatal_error(error, 'elasticity setup: eta must lie in [0, 1]', stat_invalid_input)
         return
      end if
      if (.not. (self%gamma > 0.0_wp .and. self%gamma < huge(1.0_wp))) then
         call fatal_error(error, 'elasticity setup: gamma must be finite and > 0', stat_invalid_input)
         return
      end if
      call move_alloc(mesh, self%mesh)
      self%bcs = bcs
      call classify_bcs(self, plane_axis, plane_coord)

      call timer%start()
      associate (grid => self%mesh%grid)
         call aggregate_cells(grid, grid%leaf_class == cell_inside, self%mesh%fraction, self%eta, self%root, error)
         if (.not. allocated(error)) then
            self%n_aggregated = count(self%root /= [(i, i = 1, grid%n_leaves)])
            call self%constraints%build(grid, self%mesh%nodes, self%mesh%hanging, self%root, plane_axis, &
               & plane_coord, plane_tol(grid), error)
         end if
      end associate
      if (.not. allocated(error)) call setup_dilatation(self, dilatation, error)
      call timer%stop()
      self%t_assembly = timer%elapsed
   end subroutine problem_setup

   !> The projected dilatation if `choice` (default auto) asks for it here.
   subroutine setup_dilatation(self, choice, error)
      type(elasticity_problem_type), intent(inout) :: self
      integer, intent(in), optional :: choice
      type(error_type), allocatable, intent(out) :: error
      integer :: c
      c = dilatation_auto
      if (present(choice)) c = choice
      if (.not. resolve_dilatation(c, self%analysis, self%poisson)) return
      call self%dilatation%build(self%analysis, self%d(1:self%nstress, 1:self%nstress), self%degree, self%mesh%grid, &
         & self%root, self%mesh%vol_ptr, self%mesh%vol_x, self%mesh%vol_w, error)
   end subroutine setup_dilatation

   pure real(wp) function plane_tol(grid)
      type(grid_type), intent(in) :: grid
      plane_tol = 1.0e-12_wp*(grid%box_size + maxval(abs(grid%box_min)))
   end function plane_tol

   subroutine check_inputs(body, grid, nodes, hanging, quad, rules, analysis, body_force, error)
      type(body_type), intent(in) :: body
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      type(cut_quadrature_type), intent(in) :: quad
      !> Whether the cut-cell rules were built.
      logical, intent(in) :: rules
      integer, intent(in) :: analysis
      real(wp), intent(in) :: body_force(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=200) :: buf

      if (grid%dim /= 2 .and. grid%dim /= 3) then
         call fatal_error(error, 'elasticity setup: the grid is not built', stat_invalid_input)
      else if (grid%n_leaves == 0) then
         call fatal_error(error, 'elasticity setup: the grid has no active cells (the body misses the box)', &
            & stat_invalid_input)
      else if (nodes%dim /= grid%dim .or. nodes%n_elements /= grid%n_leaves .or. &
         & nodes%lattice_level /= grid%max_level + 1) then
         call fatal_error(error, 'elasticity setup: the nodes were not built on this grid', stat_invalid_input)
      else if (hanging%n_all /= nodes%n_nodes .or. .not. allocated(hanging%t_ptr)) then
         call fatal_error(error, 'elasticity setup: the hanging-node constraints were not built on these nodes', &
            & stat_invalid_input)
      else if (.not. rules) then
         call fatal_error(error, 'elasticity setup: the cut-cell rules of the mesh were not built (mesh%integrate)', &
            & stat_invalid_input)
      else if (body%dim /= grid%dim .or. quad%dim /= grid%dim) then
         write (buf, '("elasticity setup: dimensions differ: grid ",i0,", body ",i0,", quadrature ",i0)') &
            & grid%dim, body%dim, quad%dim
         call fatal_error(error, trim(buf), stat_invalid_input)
      else if ((grid%dim == 2 .and. analysis /= plane_stress .and. analysis /= plane_strain) .or. &
         & (grid%dim == 3 .and. analysis /= solid)) then
         write (buf, '("elasticity setup: analysis ",i0," (",a,") does not fit dimension ",i0)') analysis, &
            & analysis_name(analysis), grid%dim
         call fatal_error(error, trim(buf), stat_invalid_input)
      else if (size(body_force) /= grid%dim) then
         write (buf, '("elasticity setup: body_force has ",i0," values, expected ",i0)') size(body_force), grid%dim
         call fatal_error(error, trim(buf), stat_invalid_input)
      else if (.not. all(abs(body_force) <= huge(1.0_wp))) then
         call fatal_error(error, 'elasticity setup: body_force must be finite', stat_invalid_input)
      end if
   end subroutine check_inputs

   !> The exact solution must describe this problem: same analysis and material.
   subroutine check_exact(exact, analysis, young, poisson, error)
      class(exact_solution_type), intent(in) :: exact
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      type(error_type), allocatable, intent(out) :: error
      character(len=200) :: buf

      if (exact%analysis /= analysis) then
         call fatal_error(error, 'elasticity setup: the exact solution is for '//analysis_name(exact%analysis)// &
            & ', the analysis is '//analysis_name(analysis), stat_invalid_input)
      else if (abs(exact%young - young) > 1.0e-12_wp*abs(young) .or. &
         & abs(exact%poisson - poisson) > 1.0e-12_wp) then
         write (buf, '("elasticity setup: the exact solution has young = ",es12.5,", poisson = ",f8.5, &
            & "; the problem ",es12.5,", ",f8.5)') exact%young, exact%poisson, young, poisson
         call fatal_error(error, trim(buf), stat_invalid_input)
      end if
   end subroutine check_exact

   !> Condition of each surface (sprc_geometry_body notes), and the strong
   !> symmetry planes: a symmetry halfspace with an axis normal that no cell
   !> straddles.
   subroutine classify_bcs(self, plane_axis, plane_coord)
      type(elasticity_problem_type), intent(inout) :: self
      integer, allocatable, intent(out) :: plane_axis(:)
      real(wp), allocatable, intent(out) :: plane_coord(:)
      integer :: i, s, a, e, d, nsurf
      real(wp) :: p, tol, lo(3), hi(3)
      logical :: straddled

      d = self%dim
      nsurf = self%mesh%body%nsurface()
      allocate (self%bc_of_shape(nsurf), self%strong_shape(nsurf), plane_axis(0), plane_coord(0))
      self%bc_of_shape = 0
      self%strong_shape = .false.
      tol = plane_tol(self%mesh%grid)
      do i = 1, size(self%bcs)
         s = self%bcs(i)%shape
         self%bc_of_shape(s) = i
      end do
      ! a faceted group without its own condition has its shape's
      do s = self%mesh%body%nshape + 1, nsurf
         if (self%bc_of_shape(s) == 0) self%bc_of_shape(s) = self%bc_of_shape(self%mesh%body%surface_shape(s))
      end do
      do i = 1, size(self%bcs)
         s = self%bcs(i)%shape
         if (s > self%mesh%body%nshape) cycle
         if (self%bcs(i)%kind /= bc_symmetry .or. self%mesh%body%shapes(s)%kind /= shape_halfspace) cycle
         a = maxloc(abs(self%mesh%body%shapes(s)%normal(1:d)), 1)
         if (abs(abs(self%mesh%body%shapes(s)%normal(a)) - 1.0_wp) > 1.0e-12_wp) cycle
         p = self%mesh%body%shapes(s)%point(a)
         straddled = .false.
         do e = 1, self%mesh%grid%n_leaves
            call self%mesh%grid%leaf_box(e, lo(1:d), hi(1:d))
            if (lo(a) < p - tol .and. hi(a) > p + tol) then
               straddled = .true.
               exit
            end if
         end do
         if (straddled) cycle
         self%strong_shape(s) = .true.
         plane_axis = [plane_axis, a]
         plane_coord = [plane_coord, p]
      end do
   end subroutine classify_bcs

   !> Number of reduced unknowns.
   pure integer function n_dofs(self)
      class(elasticity_problem_type), intent(in) :: self
      n_dofs = self%constraints%n_dofs
   end function n_dofs

   !> Box [lo, hi] (size dim) of element e.
   pure subroutine element_box(self, e, lo, hi)
      class(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(out) :: lo(:), hi(:)
      call self%mesh%grid%leaf_box(e, lo, hi)
   end subroutine element_box

   !> Assemble, solve and set the solution: `assemble`, `solve_reduced` and
   !> `set_solution` in turn (a coupled solve, e.g. contact, calls them
   !> separately).
   subroutine problem_solve(self, error)
      class(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error

      call self%assemble(error)
      if (allocated(error)) return
      call self%solve_reduced(error)
      if (allocated(error)) return
      call expand_solution(self, error)
   end subroutine problem_solve

   !> The reduced stiffness `k` and load `f` (t_assembly). After setup. With
   !> `rows` = [lo, hi] (a rank's rows of a partitioned level,
   !> `sprc_study_partition`) only the element and aggregate blocks that touch
   !> reduced rows lo..hi are computed, so only those rows of k and f are
   !> complete: each is summed over the same blocks in the same order as
   !> without `rows`, so it has the same bits.
   subroutine problem_assemble(self, error, rows)
      class(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: rows(2)
      type(timer_type) :: timer

      if (.not. allocated(self%root)) then
         call fatal_error(error, 'elasticity solve: setup was not called or failed', stat_invalid_input)
         return
      end if
      self%solved = .false.
      call timer%start()
      if (present(rows)) then
         call assemble(self, rows, error)
      else
         call assemble(self, [1, self%constraints%n_dofs], error)
      end if
      call timer%stop()
      self%t_assembly = self%t_assembly + timer%elapsed
   end subroutine problem_assemble

   !> Check the rigid-body modes of the assembled system, factorize and
   !> solve for the reduced solution `ubar` (t_solve). After assemble.
   subroutine problem_solve_reduced(self, error)
      class(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer

      if (.not. allocated(self%f)) then
         call fatal_error(error, 'elasticity solve: the system is not assembled', stat_invalid_input)
         return
      end if
      ! PETSc is loaded on first use. Its one-off start-up (the library and MPI, once per
      ! process) is a cost of the process, as loading the linked CHOLMOD is, not of this solve.
      if (use_iterative(self%solver, self%dim, self%degree, self%constraints%n_dofs)) call start_petsc(error)
      if (allocated(error)) return
      call timer%start()
      call check_rigid_modes(self, error)
      if (.not. allocated(error)) call factor_and_solve(self, error)
      call timer%stop()
      self%t_solve = timer%elapsed
   end subroutine problem_solve_reduced

   !> Take `ubar` (one value per reduced unknown) as the solution: the nodal
   !> displacements `u` follow (u = T ubar) and the problem counts as solved.
   subroutine problem_set_solution(self, ubar, error)
      class(elasticity_problem_type), intent(inout) :: self
      real(wp), intent(in) :: ubar(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      if (.not. allocated(self%root)) then
         call fatal_error(error, 'elasticity set_solution: setup was not called or failed', stat_invalid_input)
         return
      end if
      if (size(ubar) /= self%constraints%n_dofs) then
         call fatal_error(error, 'elasticity set_solution: ubar has '//itoa(size(ubar))//' values, the problem '// &
            & itoa(self%constraints%n_dofs)//' unknowns', stat_invalid_input)
         return
      end if
      if (allocated(self%ubar)) deallocate (self%ubar)
      allocate (self%ubar, source=ubar, stat=stat)
      call check_allocation(stat, 'elasticity set_solution', 'the reduced solution', size(ubar), 8, error)
      if (allocated(error)) return
      call expand_solution(self, error)
   end subroutine problem_set_solution

   !> u = T ubar; the problem counts as solved.
   subroutine expand_solution(self, error)
      class(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer :: stat
      if (allocated(self%u)) deallocate (self%u)
      allocate (self%u(self%dim, self%mesh%nodes%n_nodes), stat=stat)
      call check_allocation(stat, 'elasticity solve', 'the nodal displacements', self%mesh%nodes%n_nodes, 8*self%dim, error)
      if (allocated(error)) return
      call self%constraints%expand(self%ubar, self%u)
      call dilatation_coefficients(self)
      self%solved = .true.
   end subroutine expand_solution

   !> K and f: the reduced element systems in one parallel loop, each into its own block of
   !> a block list (the aggregates' dilatation blocks after them), summed row by row in
   !> parallel (`block_list_type`): the same sums, in element order, for any thread count.
   !> A block that touches no row of `rows` is left empty.
   subroutine assemble(self, rows, error)
      type(elasticity_problem_type), intent(inout) :: self
      integer, intent(in) :: rows(2)
      type(error_type), allocatable, intent(out) :: error
      type(block_list_type) :: blocks
      integer, allocatable :: mdof(:), bad(:), multi(:)
      integer :: nel, maxm, e, saved_blas, stat
      character(len=*), parameter :: who = 'elasticity assembly'

      nel = self%mesh%grid%n_leaves
      call whole_cell_terms(self)
      call multi_cell_aggregates(self, multi, error)
      if (allocated(error)) return
      ! distinct reduced dofs of each element and aggregate: the block sizes
      allocate (mdof(nel + size(multi)), bad(nel), stat=stat)
      call check_allocation(stat, who, 'the reduced dof count of each element', nel, 8, error)
      if (allocated(error)) return
      call element_dof_counts(self, rows, mdof(1:nel), maxm)
      call aggregate_dof_counts(self, maxm, rows, multi, mdof(nel + 1:))
      call blocks%init(self%constraints%n_dofs, mdof, error)
      if (allocated(error)) return
      ! The element kernels call no BLAS; the dilatation blocks do (small dgemm and
      ! dpotrs from every thread): OpenBLAS in one thread (sprc_core_blas_threads).
      saved_blas = blas_serial_begin()
      call element_blocks(self, maxm, blocks, bad)
      call blas_serial_end(saved_blas)
      if (any(bad /= 0)) then
         e = findloc(bad /= 0, .true., 1)
         call fatal_error(error, who//': the stiffness of cell '//itoa(e - 1)//' is not finite (NaN or Inf)', &
            & stat_invalid_input)
         return
      end if
      call aggregate_blocks(self, maxm, multi, nel, blocks)
      deallocate (mdof, bad)
      call blocks%to_csr(self%k, error, self%f)
   end subroutine assemble

   !> `k_whole`, `n_whole`: the volume terms of the unit cell. Every inside cell (a cube of
   !> edge h, integrated by the same tensor rule) has h^(dim-2) k_whole and h^dim n_whole:
   !> an affine map of the rule, so only the rounding differs from integrating the cell
   !> itself, and most of the cells of a level cost a copy. Not with the projected
   !> dilatation, whose moments need the points.
   subroutine whole_cell_terms(self)
      type(elasticity_problem_type), intent(inout) :: self
      real(wp) :: x(3), w, lo(3), hi(3), n(self%nen), dndx(self%dim, self%nen)
      real(wp) :: b(self%nstress, self%dim*self%nen), db(self%nstress, self%dim*self%nen)
      integer :: ipt, d, ns, nq

      if (allocated(self%k_whole)) deallocate (self%k_whole, self%n_whole)
      if (self%dilatation%active) return
      d = self%dim
      ns = self%nstress
      nq = self%mesh%quad%q
      allocate (self%k_whole(d*self%nen, d*self%nen), self%n_whole(self%nen))
      self%k_whole = 0.0_wp
      self%n_whole = 0.0_wp
      lo = 0.0_wp
      hi = 1.0_wp
      do ipt = 1, nq**d
         call tensor_point(self%mesh%quad, lo(1:d), hi(1:d), ipt, x, w)
         call shape_functions(d, self%degree, lo(1:d), hi(1:d), x(1:d), n, dndx)
         call strain_matrix(d, dndx, b)
         db = matmul(self%d(1:ns, 1:ns), b)
         call add_stiffness(b, db, w, self%k_whole)
         self%n_whole = self%n_whole + w*n
      end do
      call mirror_upper(self%k_whole)
   end subroutine whole_cell_terms

   !> Whether element e takes its volume terms from `k_whole` (module notes of
   !> `whole_cell_terms`): an inside cell with the tensor rule's points, a cube.
   pure logical function whole_cell(self, e, lo, hi) result(yes)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: width(size(lo))

      yes = .false.
      if (.not. allocated(self%k_whole)) return
      if (self%mesh%grid%leaf_class(e) /= cell_inside) return
      if (self%mesh%vol_ptr(e + 1) - self%mesh%vol_ptr(e) /= self%mesh%quad%q**self%dim) return
      width = hi - lo
      yes = maxval(width) - minval(width) <= 8*epsilon(1.0_wp)*maxval(width)
   end function whole_cell

   !> The aggregates of several cells (their dilatation blocks couple the members'
   !> dofs); none without the projected dilatation.
   subroutine multi_cell_aggregates(self, multi, error)
      type(elasticity_problem_type), intent(in) :: self
      integer, allocatable, intent(out) :: multi(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: a, n, stat

      n = 0
      if (self%dilatation%active) n = count(self%dilatation%ptr(2:) - self%dilatation%ptr(:self%dilatation%n_aggregates) > 1)
      allocate (multi(n), stat=stat)
      call check_allocation(stat, 'elasticity assembly', 'the aggregates of several cells', n, 4, error)
      if (allocated(error) .or. n == 0) return
      n = 0
      do a = 1, self%dilatation%n_aggregates
         if (self%dilatation%ptr(a + 1) - self%dilatation%ptr(a) == 1) cycle
         n = n + 1
         multi(n) = a
      end do
   end subroutine multi_cell_aggregates

   !> The number of distinct reduced dofs of every element (OpenMP over elements),
   !> 0 for an element with no dof in `rows`; `maxm` the largest count of all.
   subroutine element_dof_counts(self, rows, mdof, maxm)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: rows(2)
      integer, intent(out) :: mdof(:), maxm
      integer, allocatable :: dtmp(:)
      real(wp), allocatable :: ttmp(:, :)
      integer :: nd, e

      nd = self%dim*self%nen
      maxm = 0
      !$omp parallel default(shared) private(dtmp, ttmp, e) reduction(max:maxm)
      allocate (dtmp(nd*32), ttmp(nd, nd*32))
      !$omp do schedule(static)
      do e = 1, size(mdof)
         call self%constraints%element_map(self%mesh%nodes%connectivity(:, e), dtmp, ttmp, mdof(e))
         maxm = max(maxm, mdof(e))
         if (.not. any(dtmp(1:mdof(e)) >= rows(1) .and. dtmp(1:mdof(e)) <= rows(2))) mdof(e) = 0
      end do
      !$omp end do
      !$omp end parallel
   end subroutine element_dof_counts

   !> The reduced system of every element, in one parallel loop, into block e of
   !> `blocks` (its dofs, its m x m matrix column-major, its load). The places depend
   !> only on e, and a single parallel region has no serial step between chunks for a
   !> thread to wait at (each such barrier costs a scheduling delay on a loaded
   !> machine). bad(e) /= 0: the block of e is not finite.
   subroutine element_blocks(self, maxm, blocks, bad)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: maxm
      type(block_list_type), intent(inout) :: blocks
      integer, intent(out) :: bad(:)
      integer(i8) :: p, v
      integer :: e, m

      !$omp parallel do schedule(dynamic, 16) default(shared) private(e, m, p, v)
      do e = 1, size(bad)
         p = blocks%dof_ptr(e)
         v = blocks%val_ptr(e)
         m = int(blocks%dof_ptr(e + 1) - p)
         bad(e) = 0
         ! an empty block adds nothing: none of the element's dofs, or none of the rows assembled
         if (m == 0) cycle
         call reduced_element_system(self, e, maxm, blocks%dofs(p:p + m - 1), blocks%val(v:v + int(m, i8)**2 - 1), &
            & blocks%rhs(p:p + m - 1))
         bad(e) = count(.not. ieee_is_finite(blocks%val(v:v + int(m, i8)**2 - 1)))
      end do
      !$omp end parallel do
   end subroutine element_blocks

   !> The sizes of the dilatation blocks of the aggregates `multi`: the distinct reduced
   !> dofs of their members together (0 when none is in `rows`).
   subroutine aggregate_dof_counts(self, maxm, rows, multi, mdof)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: maxm, rows(2), multi(:)
      integer, intent(out) :: mdof(:)
      integer, allocatable :: union(:)
      integer :: i

      do i = 1, size(multi)
         call aggregate_union(self, maxm, multi(i), union, mdof(i))
         if (.not. any(union(1:mdof(i)) >= rows(1) .and. union(1:mdof(i)) <= rows(2))) mdof(i) = 0
      end do
   end subroutine aggregate_dof_counts

   !> union(1:nu): the distinct reduced dofs of the members of aggregate a, in order of
   !> first appearance (members in order, each element's dofs ascending).
   subroutine aggregate_union(self, maxm, a, union, nu)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: maxm, a
      integer, allocatable, intent(out) :: union(:)
      integer, intent(out) :: nu
      real(wp) :: tmat(self%dim*self%nen, maxm)
      integer :: dofs(maxm), j, i, m

      allocate (union(maxm*(self%dilatation%ptr(a + 1) - self%dilatation%ptr(a))))
      nu = 0
      do j = self%dilatation%ptr(a), self%dilatation%ptr(a + 1) - 1
         call self%constraints%element_map(self%mesh%nodes%connectivity(:, self%dilatation%member(j)), dofs, tmat, m)
         do i = 1, m
            if (any(union(1:nu) == dofs(i))) cycle
            nu = nu + 1
            union(nu) = dofs(i)
         end do
      end do
   end subroutine aggregate_union

   !> Dilatation blocks of the aggregates of several cells (serially, in aggregate
   !> order; blocks nel + 1 ..): the members' moments reduced by T_e and summed on
   !> the union of their reduced dofs.
   subroutine aggregate_blocks(self, maxm, multi, nel, blocks)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: maxm, multi(:), nel
      type(block_list_type), intent(inout) :: blocks
      real(wp) :: ke(self%dim*self%nen, self%dim*self%nen), fe(self%dim*self%nen)
      real(wp) :: tmat(self%dim*self%nen, maxm)
      real(wp) :: g(self%dim*self%nen, self%dilatation%np), h(self%dim*self%nen, self%dilatation%np)
      real(wp) :: sv(self%dilatation%np), svsum(self%dilatation%np)
      real(wp), allocatable :: gu(:, :), hu(:, :), ku(:, :), fu(:)
      integer, allocatable :: union(:)
      integer(i8) :: p, v
      integer :: dofs(maxm), a, j, e, m, nu, i, k, np, ia

      np = self%dilatation%np
      do ia = 1, size(multi)
         a = multi(ia)
         if (blocks%dof_ptr(nel + ia + 1) == blocks%dof_ptr(nel + ia)) cycle
         call aggregate_union(self, maxm, a, union, nu)
         allocate (gu(nu, np), hu(nu, np), ku(nu, nu), fu(nu))
         gu = 0.0_wp
         hu = 0.0_wp
         svsum = 0.0_wp
         do j = self%dilatation%ptr(a), self%dilatation%ptr(a + 1) - 1
            e = self%dilatation%member(j)
            call element_system(self, e, ke, fe, g, h, sv)
            call self%constraints%element_map(self%mesh%nodes%connectivity(:, e), dofs, tmat, m)
            svsum = svsum + sv
            do i = 1, m
               k = findloc(union(1:nu), dofs(i), 1)
               gu(k, :) = gu(k, :) + matmul(tmat(:, i), g)
               hu(k, :) = hu(k, :) + matmul(tmat(:, i), h)
            end do
         end do
         ku = 0.0_wp
         fu = 0.0_wp
         call self%dilatation%add_aggregate_block(a, gu, hu, svsum, ku, fu)
         p = blocks%dof_ptr(nel + ia)
         v = blocks%val_ptr(nel + ia)
         blocks%dofs(p:p + nu - 1) = union(1:nu)
         blocks%val(v:v + int(nu, i8)**2 - 1) = reshape(ku, [int(nu, i8)**2])
         blocks%rhs(p:p + nu - 1) = fu
         deallocate (gu, hu, ku, fu)
      end do
   end subroutine aggregate_blocks

   !> Reduced system of element e: kr = T_e^T k_e T_e (m x m, column-major in
   !> kr), fr = T_e^T f_e, on the reduced dofs dofs(1:m) (the sizes of dofs, kr and fr
   !> are the element's count m, from `element_dof_counts`). T_e has a few nonzeros per row (one, 1, where no
   !> constraint acts): the products run over them only, in a fixed order, and
   !> where T_e is a selection they copy k_e's entries exactly.
   subroutine reduced_element_system(self, e, maxm, dofs, kr, fr)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e, maxm
      integer, intent(out) :: dofs(:)
      real(wp), intent(out) :: kr(:), fr(:)
      real(wp) :: ke(self%dim*self%nen, self%dim*self%nen), fe(self%dim*self%nen)
      real(wp) :: tmat(self%dim*self%nen, maxm), kt(self%dim*self%nen, maxm)
      real(wp) :: g(self%dim*self%nen, self%dilatation%np), h(self%dim*self%nen, self%dilatation%np)
      real(wp) :: sv(self%dilatation%np)
      integer :: tpos(self%dim*self%nen, maxm), tcount(self%dim*self%nen)
      integer :: nd, a, i, j, k, c, m

      nd = self%dim*self%nen
      call element_system(self, e, ke, fe, g, h, sv)
      if (self%dilatation%active) then
         ! an aggregate of one cell: its dilatation terms live on this element's dofs
         a = self%dilatation%aggregate(e)
         if (self%dilatation%ptr(a + 1) - self%dilatation%ptr(a) == 1) &
            & call self%dilatation%add_aggregate_block(a, g, h, sv, ke, fe)
      end if
      call self%constraints%element_map(self%mesh%nodes%connectivity(:, e), dofs, tmat, m)
      if (m == 0) return
      ! the nonzeros of each row of T_e
      do i = 1, nd
         tcount(i) = 0
         do c = 1, m
            if (tmat(i, c) == 0.0_wp) cycle
            tcount(i) = tcount(i) + 1
            tpos(i, tcount(i)) = c
         end do
      end do
      ! kt = k_e T_e
      kt(:, 1:m) = 0.0_wp
      do j = 1, nd
         do k = 1, tcount(j)
            c = tpos(j, k)
            kt(:, c) = kt(:, c) + ke(:, j)*tmat(j, c)
         end do
      end do
      ! kr = T_e^T kt, fr = T_e^T f_e
      kr(1:m*m) = 0.0_wp
      fr(1:m) = 0.0_wp
      do c = 1, m
         do i = 1, nd
            do k = 1, tcount(i)
               a = tpos(i, k)
               kr(a + (c - 1)*m) = kr(a + (c - 1)*m) + tmat(i, a)*kt(i, c)
            end do
         end do
      end do
      do i = 1, nd
         do k = 1, tcount(i)
            a = tpos(i, k)
            fr(a) = fr(a) + tmat(i, a)*fe(i)
         end do
      end do
   end subroutine reduced_element_system

   !> Unreduced stiffness ke and load fe of element e: volume terms, Neumann
   !> loads and Nitsche terms of its surface points. With the projected
   !> dilatation, ke and fe hold the deviatoric part and gm, hm, sv the
   !> element's share of its aggregate's terms (`add_aggregate_block`).
   subroutine element_system(self, e, ke, fe, gm, hm, sv)
      type(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(out) :: ke(:, :), fe(:), gm(:, :), hm(:, :), sv(:)
      integer :: d, ns, nd, q, c, ib, kind, a
      real(wp) :: lo(3), hi(3), h, pen, t(3), g(3), p(3, 3), pb(4), dmat(6, 6), pn(3)
      real(wp) :: n(self%nen), dndx(self%dim, self%nen)
      real(wp) :: b(self%nstress, self%dim*self%nen), db(self%nstress, self%dim*self%nen)
      real(wp) :: nm(self%dim, self%dim*self%nen), tn(self%dim, self%nstress), s(self%dim, self%dim*self%nen)

      d = self%dim
      ns = self%nstress
      nd = d*self%nen
      call self%mesh%grid%leaf_box(e, lo(1:d), hi(1:d))
      h = minval(hi(1:d) - lo(1:d))
      pen = self%gamma*self%dmax/h
      ke = 0.0_wp
      fe = 0.0_wp
      hm = 0.0_wp
      sv = 0.0_wp
      dmat = self%d
      a = 0
      gm = 0.0_wp
      if (self%dilatation%active) then
         dmat = self%dilatation%d_dev
         a = self%dilatation%aggregate(e)
      end if
      if (whole_cell(self, e, lo(1:d), hi(1:d))) then
         ke = h**(d - 2)*self%k_whole
         do c = 1, d
            fe(c:nd:d) = (h**d*self%body_force(c))*self%n_whole
         end do
      else
         do q = self%mesh%vol_ptr(e), self%mesh%vol_ptr(e + 1) - 1
            call shape_functions(d, self%degree, lo(1:d), hi(1:d), self%mesh%vol_x(:, q), n, dndx)
            call strain_matrix(d, dndx, b)
            if (a > 0) call self%dilatation%add_moment(a, self%mesh%vol_x(:, q), self%mesh%vol_w(q), b, gm)
            db = matmul(dmat(1:ns, 1:ns), b)
            call add_stiffness(b, db, self%mesh%vol_w(q), ke)
            do c = 1, d
               fe(c:nd:d) = fe(c:nd:d) + self%mesh%vol_w(q)*self%body_force(c)*n
            end do
         end do
         call mirror_upper(ke)
      end if
      do q = self%mesh%surf_ptr(e), self%mesh%surf_ptr(e + 1) - 1
         ib = self%bc_of_shape(self%mesh%surf_shape(q))
         kind = bc_free
         if (ib > 0) kind = self%bcs(ib)%kind
         if (kind == bc_free) cycle
         if (kind == bc_symmetry .and. self%strong_shape(self%mesh%surf_shape(q))) cycle
         associate (x => self%mesh%surf_x(:, q), nrm => self%mesh%surf_n(:, q), w => self%mesh%surf_w(q))
            call shape_functions(d, self%degree, lo(1:d), hi(1:d), x, n, dndx)
            select case (kind)
            case (bc_pressure, bc_traction, bc_exact_traction)
               select case (kind)
               case (bc_pressure)
                  t(1:d) = -self%bcs(ib)%value*nrm
               case (bc_traction)
                  t(1:d) = self%bcs(ib)%vector
               case default
                  call self%exact%traction(x, nrm, t(1:d))
               end select
               do c = 1, d
                  fe(c:nd:d) = fe(c:nd:d) + w*t(c)*n
               end do
            case default
               ! Nitsche: P = I (displacement) or n n^T (symmetry), data g.
               g = 0.0_wp
               if (kind == bc_symmetry) then
                  p(1:d, 1:d) = spread(nrm, 2, d)*spread(nrm, 1, d)
               else
                  p = 0.0_wp
                  do c = 1, d
                     p(c, c) = 1.0_wp
                  end do
                  if (kind == bc_displacement) then
                     g(1:d) = self%bcs(ib)%vector
                  else
                     call self%exact%displacement(x, g(1:d))
                  end if
               end if
               call strain_matrix(d, dndx, b)
               call displacement_matrix(d, n, nm)
               call traction_matrix(d, nrm, tn)
               s = matmul(tn, matmul(dmat(1:ns, 1:ns), b))
               s = matmul(p(1:d, 1:d), s)
               ke = ke - w*(matmul(transpose(nm), s) + matmul(transpose(s), nm)) &
                  & + (w*pen)*matmul(transpose(nm), matmul(p(1:d, 1:d), nm))
               fe = fe - w*matmul(g(1:d), s) + (w*pen)*matmul(matmul(p(1:d, 1:d), g(1:d)), nm)
               if (a > 0) then
                  ! the dilatation's share of sigma_bar n: kappa theta_bar P n
                  call self%dilatation%basis(a, x, pb)
                  pn(1:d) = matmul(p(1:d, 1:d), nrm)
                  do c = 1, self%dilatation%np
                     hm(:, c) = hm(:, c) + (w*pb(c))*matmul(pn(1:d), nm)
                     sv(c) = sv(c) + w*pb(c)*dot_product(g(1:d), pn(1:d))
                  end do
               end if
            end select
         end associate
      end do
   end subroutine element_system

   !> Rigid-body modes the conditions leave free: `rigid_modes` gives the 3
   !> (2D) / 6 (3D) modes in the reduced space, `free_motions` the motions K
   !> does not resist among them. An error names the free motions.
   subroutine check_rigid_modes(self, error)
      type(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: r(:, :), vec(:, :)
      integer :: nfree, i
      logical :: involved(6)
      character(len=:), allocatable :: what
      character(len=32) :: count

      if (self%constraints%n_dofs == 0) then
         call fatal_error(error, 'elasticity solve: no unknowns are left (every dof is constrained)', &
            & stat_invalid_input)
         return
      end if
      call self%rigid_modes(r, error)
      if (allocated(self%rows_share)) then
         call self%rows_share%agree('the rigid-body check', error)
         if (.not. allocated(error)) call free_motions(self%k, r, vec, nfree, error, self%rows_share, self%row_bounds)
      else if (.not. allocated(error)) then
         call free_motions(self%k, r, vec, nfree, error)
      end if
      if (allocated(error) .or. nfree == 0) return
      ! Name every basic motion with a significant share in a free one, once.
      involved = .false.
      do i = 1, nfree
         involved(1:size(r, 2)) = involved(1:size(r, 2)) .or. abs(vec(:, i)) >= 0.2_wp*maxval(abs(vec(:, i)))
      end do
      what = motion_names(self%dim, involved(1:size(r, 2)))
      write (count, '(i0," independent motion",a)') nfree, trim(merge('s', ' ', nfree > 1))
      call fatal_error(error, 'the boundary conditions leave rigid-body motion free: '//what//' ('// &
         & trim(count)//'); add displacement or symmetry conditions that restrain it', stat_singular)
   end subroutine check_rigid_modes

   !> Comma-separated names of the basic rigid motions flagged in `involved`
   !> (3 in 2D, 6 in 3D, in the order of `rigid_modes`).
   pure function motion_names(dim, involved) result(what)
      integer, intent(in) :: dim
      logical, intent(in) :: involved(:)
      character(len=:), allocatable :: what
      character(len=*), parameter :: names2(3) = [character(len=16) :: 'translation x', 'translation y', &
         & 'rotation about z']
      character(len=*), parameter :: names3(6) = [character(len=16) :: 'translation x', 'translation y', &
         & 'translation z', 'rotation about x', 'rotation about y', 'rotation about z']
      integer :: i
      what = ''
      do i = 1, size(involved)
         if (.not. involved(i)) cycle
         if (len(what) > 0) what = what//', '
         if (dim == 2) then
            what = what//trim(names2(i))
         else
            what = what//trim(names3(i))
         end if
      end do
   end function motion_names

   !> The 3 (2D) / 6 (3D) rigid-body modes r(n_dofs, nm) in the reduced space:
   !> translations, rotations about the grid box centre scaled by 1/box size
   !> (all of unit magnitude), taken to the reduced space by restrict_field
   !> (nodal values at the masters, zeroed components dropped). A failed
   !> allocation is returned in `error`; without `error` the run time stops
   !> the program, as before `error` was added (contact/pair_solve.f90 still calls it so).
   pure subroutine rigid_modes(self, r, error)
      class(elasticity_problem_type), intent(in) :: self
      real(wp), allocatable, intent(out) :: r(:, :)
      type(error_type), allocatable, intent(out), optional :: error
      real(wp), allocatable :: field(:, :)
      real(wp) :: xc(3), y(3)
      integer :: nm, i, j, d, stat

      d = self%dim
      nm = merge(3, 6, d == 2)
      xc(1:d) = self%mesh%grid%box_min(1:d) + 0.5_wp*self%mesh%grid%box_size
      if (present(error)) then
         allocate (field(d, self%mesh%nodes%n_nodes), r(self%constraints%n_dofs, nm), stat=stat)
         call check_allocation(stat, 'rigid_modes', 'the rigid-body motions (values)', &
            & int(self%constraints%n_dofs, i8)*nm + int(self%mesh%nodes%n_nodes, i8)*d, 8, error)
         if (allocated(error)) return
      else
         allocate (field(d, self%mesh%nodes%n_nodes), r(self%constraints%n_dofs, nm))
      end if
      do i = 1, nm
         do j = 1, self%mesh%nodes%n_nodes
            y(1:d) = (self%mesh%nodes%x(:, j) - xc(1:d))/self%mesh%grid%box_size
            field(:, j) = 0.0_wp
            if (i <= d) then
               field(i, j) = 1.0_wp
            else if (d == 2) then
               field(:, j) = [-y(2), y(1)]
            else if (i == 4) then
               field(:, j) = [0.0_wp, -y(3), y(2)]
            else if (i == 5) then
               field(:, j) = [y(3), 0.0_wp, -y(1)]
            else
               field(:, j) = [-y(2), y(1), 0.0_wp]
            end if
         end do
         call self%constraints%restrict_field(field, r(:, i))
      end do
   end subroutine rigid_modes

   !> The motions among the columns of r (n, nm) that k does not resist:
   !> G = R^T K R normalised by the diagonal energies s_i = sum_j K_jj R_ji^2
   !> (K first divided by its largest diagonal entry, so that the energies
   !> neither overflow nor underflow for any representable E); the
   !> eigenvectors of G with eigenvalue below `rigid_tol` are the free motions,
   !> vec(nm, nfree) in the basis of the columns of r. With `share`, k holds
   !> this rank's rows of `bounds` (as `rows_share`, `row_bounds`): the rows
   !> of K R and diag K are gathered, so G has the bits of the whole k's.
   subroutine free_motions(k, r, vec, nfree, error, share, bounds)
      type(csr_type), intent(in) :: k
      real(wp), intent(in) :: r(:, :)
      real(wp), allocatable, intent(out) :: vec(:, :)
      integer, intent(out) :: nfree
      type(error_type), allocatable, intent(out) :: error
      class(share_type), intent(in), optional :: share
      integer(i8), intent(in), optional :: bounds(:)
      real(wp), allocatable :: kr(:, :), diag(:), work(:), g(:, :), s(:), lam(:)
      real(wp) :: kmax
      integer :: nm, nd, i, j, info, stat
      integer(kind(k%rowptr)) :: q

      nd = size(r, 1)
      nm = size(r, 2)
      nfree = 0
      allocate (kr(nd, nm), diag(nd), stat=stat)
      call check_allocation(stat, 'elasticity solve', 'the rigid-body check (K times each motion)', nd, 8*(nm + 1), error)
      allocate (g(nm, nm), s(nm), lam(nm), vec(nm, 0))
      if (.not. allocated(error)) call products(error)
      if (present(share) .and. present(bounds)) then
         call share%agree('the rigid-body check', error)
         do i = 1, nm
            if (.not. allocated(error)) call share%gather_slices(bounds, kr(:, i), error)
         end do
         if (.not. allocated(error)) call share%gather_slices(bounds, diag, error)
      end if
      if (allocated(error)) return
      kmax = maxval(abs(diag))
      if (.not. (kmax > 0.0_wp)) kmax = 1.0_wp
      diag = diag/kmax
      kr = kr/kmax
      do i = 1, nm
         s(i) = sqrt(max(sum(diag*r(:, i)**2), tiny(1.0_wp)))
      end do
      do j = 1, nm
         do i = 1, nm
            g(i, j) = dot_product(r(:, i), kr(:, j))/s(i)/s(j)
         end do
      end do
      g = 0.5_wp*(g + transpose(g))
      allocate (work(max(64, 3*nm)))
      call dsyev('V', 'U', nm, g, nm, lam, work, size(work), info)
      if (info /= 0) return
      do j = 1, nm
         if (lam(j) >= rigid_tol) exit
         nfree = nfree + 1
      end do
      vec = g(:, 1:nfree)
   contains
      !> kr = K r, every motion in one pass over K (each column summed in
      !> `matvec`'s order), and K's diagonal.
      subroutine products(error)
         type(error_type), allocatable, intent(out) :: error
         real(wp), allocatable :: rt(:, :)
         real(wp) :: acc(nm)
         character(len=96) :: buf

         if (k%nrows /= nd .or. k%ncols /= nd) then
            write (buf, '(i0," x ",i0," matrix, motions of size ",i0)') k%nrows, k%ncols, nd
            call fatal_error(error, 'rigid-body check: '//trim(buf), stat_invalid_input)
            return
         end if
         allocate (rt(nm, nd), stat=stat)
         call check_allocation(stat, 'elasticity solve', 'the rigid-body motions by row', nd, 8*nm, error)
         if (allocated(error)) return
         rt = transpose(r)
         diag = 0.0_wp
         do i = 1, nd
            acc = 0.0_wp
            do q = k%rowptr(i), k%rowptr(i + 1) - 1
               acc = acc + k%val(q)*rt(:, k%col(q))
               if (k%col(q) == i) diag(i) = k%val(q)
            end do
            kr(i, :) = acc
         end do
      end subroutine products
   end subroutine free_motions

   !> The iterative solver when `solver` asks for it at this size (`use_iterative`);
   !> else CHOLMOD, or UMFPACK when CHOLMOD finds K not positive definite.
   subroutine factor_and_solve(self, error)
      type(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      if (allocated(self%ubar)) deallocate (self%ubar)
      allocate (self%ubar(self%constraints%n_dofs), stat=stat)
      call check_allocation(stat, 'elasticity solve', 'the reduced solution', self%constraints%n_dofs, 8, error)
      if (allocated(error)) return
      self%solver_iterations = 0
      if (use_iterative(self%solver, self%dim, self%degree, self%constraints%n_dofs)) then
         call iterative_solve(self, error)
         return
      end if
      call solve_spd_or_lu(self%k, self%f, self%ubar, self%rcond, self%solver_name, self%solver_note, error)
      if (allocated(error)) error%message = 'elasticity solve'//error%message
   end subroutine factor_and_solve

   !> Solve k x = f with CHOLMOD, or with UMFPACK (LU) when CHOLMOD finds k
   !> not positive definite: `solver_name` 'cholmod' or 'umfpack', `note` why
   !> the fallback was taken ('' if not), `rcond` the solver's reciprocal
   !> condition estimate. An error message starts with the solver's part
   !> (': ...' or ' (UMFPACK fallback): ...') for the caller to prefix.
   subroutine solve_spd_or_lu(k, f, x, rcond, solver_name, note, error)
      type(csr_type), intent(in) :: k
      real(wp), intent(in) :: f(:)
      real(wp), intent(inout) :: x(:)
      real(wp), intent(inout) :: rcond
      character(len=:), allocatable, intent(out) :: solver_name, note
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: lu

      solver_name = 'cholmod'
      note = ''
      call solve_with(chol, k, f, x, rcond, error)
      if (.not. allocated(error)) return
      if (error%stat /= stat_not_positive_definite) then
         error%message = ': '//error%message
         return
      end if
      solver_name = 'umfpack'
      note = 'CHOLMOD found the stiffness not positive definite ('//error%message// &
         & '); solved by UMFPACK (LU). Raise gamma for an SPD system.'
      deallocate (error)
      call solve_with(lu, k, f, x, rcond, error)
      if (allocated(error)) error%message = ' (UMFPACK fallback): '//error%message
   end subroutine solve_spd_or_lu

   !> CG (`sprc_fem_petsc`) on the masters' blocks, preconditioned by
   !> geometric multigrid on the masters' node lattice (GAMG on several MPI
   !> ranks), stopped at `iteration_tolerance` of the finest cell; GMRES when
   !> CG finds K indefinite (the iterative counterpart of the UMFPACK fallback).
   subroutine iterative_solve(self, error)
      type(elasticity_problem_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      type(petsc_solver_type) :: krylov

      call krylov%set_blocks(self%constraints%dof, self%mesh%nodes%x(:, self%constraints%master_node), error)
      if (allocated(error)) return
      ! nodes without lattice coordinates (none are built so): GAMG
      associate (nodes => self%mesh%nodes)
         if (allocated(nodes%lattice)) call krylov%set_lattice(nodes%lattice(:, self%constraints%master_node), &
            & lattice_step(self), error)
      end associate
      if (allocated(error)) return
      if (allocated(self%start)) then
         call start_guess(self, krylov%guess, error)
         if (allocated(error)) return
      end if
      krylov%tolerance = iteration_tolerance(0.5_wp**self%mesh%grid%max_level, self%degree)
      self%solver_note = ''
      call solve_with(krylov, self%k, self%f, self%ubar, self%rcond, error)
      self%solver_name = 'cg+'//preconditioner_name(krylov)
      self%solver_iterations = krylov%iterations
      if (.not. allocated(error)) return
      if (error%stat /= stat_not_positive_definite) then
         error%message = 'elasticity solve (iterative): '//error%message
         return
      end if
      self%solver_name = 'gmres+'//preconditioner_name(krylov)
      self%solver_note = 'CG found the stiffness not positive definite ('//error%message// &
         & '); solved by GMRES. Raise gamma for an SPD system.'
      deallocate (error)
      krylov%symmetric = .false.
      call solve_with(krylov, self%k, self%f, self%ubar, self%rcond, error)
      self%solver_name = 'gmres+'//preconditioner_name(krylov)
      self%solver_iterations = self%solver_iterations + krylov%iterations
      if (allocated(error)) error%message = 'elasticity solve (GMRES fallback): '//error%message
   end subroutine iterative_solve

   !> The lattice step between neighbouring nodes of the finest elements
   !> (`sprc_fem_petsc`'s `set_lattice`).
   pure integer function lattice_step(self) result(step)
      type(elasticity_problem_type), intent(in) :: self
      step = 2**(self%mesh%nodes%lattice_level - self%mesh%grid%max_level)/self%degree
   end function lattice_step

   !> The geometric multigrid hierarchy of this body's reduced unknowns (its
   !> master nodes on the node lattice, `lattice_hierarchy`); `found` is false
   !> when the nodes have no lattice coordinates. `keep(m)`: master m is
   !> kept on every level (`lattice_hierarchy`).
   subroutine master_hierarchy(self, p, found, error, keep)
      type(elasticity_problem_type), intent(in) :: self
      type(prolongation_type), allocatable, intent(out) :: p(:)
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: keep(:)

      found = allocated(self%mesh%nodes%lattice)
      if (.not. found) return
      call lattice_hierarchy(self%mesh%nodes%lattice(:, self%constraints%master_node), lattice_step(self), p, error, &
         & keep=keep)
   end subroutine master_hierarchy

   !> 'gmg' (geometric multigrid on the node lattice) or 'gamg'.
   pure function preconditioner_name(krylov) result(name)
      type(petsc_solver_type), intent(in) :: krylov
      character(len=:), allocatable :: name
      name = merge('gmg ', 'gamg', krylov%multigrid)
      name = trim(name)
   end function preconditioner_name

   !> `start` at the masters: the reduced unknowns' initial guess.
   subroutine start_guess(self, guess, error)
      type(elasticity_problem_type), intent(in) :: self
      real(wp), allocatable, intent(out) :: guess(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: v(:, :)
      integer :: m, c, stat

      associate (con => self%constraints)
         allocate (v(self%dim, con%n_masters), guess(con%n_dofs), stat=stat)
         call check_allocation(stat, 'elasticity solve', 'the nested start', con%n_dofs, 16, error)
         if (allocated(error)) return
         call self%start%values_at(self%mesh%nodes%x(:, con%master_node), v)
         do m = 1, con%n_masters
            do c = 1, self%dim
               if (con%dof(c, m) > 0) guess(con%dof(c, m)) = v(c, m)
            end do
         end do
      end associate
   end subroutine start_guess

   !> The solved displacement, kept apart from the problem (`held`), to start
   !> an iterative solve of the same body on another grid (`start`).
   subroutine hold_displacement(self, held, error)
      class(elasticity_problem_type), intent(in) :: self
      type(fe_displacement_type), intent(inout) :: held
      type(error_type), allocatable, intent(out) :: error

      if (.not. self%solved) then
         call fatal_error(error, 'hold_displacement: the problem is not solved', stat_invalid_input)
         return
      end if
      call held%hold(self%mesh%grid, self%degree, self%mesh%nodes%connectivity, self%u, error)
   end subroutine hold_displacement

   !> theta_bar on every aggregate from the nodal displacements (projected dilatation only).
   subroutine dilatation_coefficients(self)
      type(elasticity_problem_type), intent(inout) :: self
      real(wp) :: g(self%dim*self%nen, self%dilatation%np), ue(self%dim*self%nen), gu(self%dilatation%np)
      real(wp) :: lo(3), hi(3)
      integer :: a, j, e, d

      if (.not. self%dilatation%active) return
      d = self%dim
      do a = 1, self%dilatation%n_aggregates
         gu = 0.0_wp
         do j = self%dilatation%ptr(a), self%dilatation%ptr(a + 1) - 1
            e = self%dilatation%member(j)
            call self%mesh%grid%leaf_box(e, lo(1:d), hi(1:d))
            call self%dilatation%element_moments(a, self%degree, lo(1:d), hi(1:d), &
               & self%mesh%vol_x(:, self%mesh%vol_ptr(e):self%mesh%vol_ptr(e + 1) - 1), &
               & self%mesh%vol_w(self%mesh%vol_ptr(e):self%mesh%vol_ptr(e + 1) - 1), g)
            call self%element_displacements(e, ue)
            gu = gu + matmul(ue, g)
         end do
         call self%dilatation%set_coefficients(a, gu)
      end do
   end subroutine dilatation_coefficients

   !> Factorize (or set up) k with `solver`, solve k x = f, release the factor;
   !> `rcond` gets the solver's condition estimate (-1 when it makes none).
   subroutine solve_with(solver, k, f, x, rcond, error)
      class(linear_solver_type), intent(inout) :: solver
      type(csr_type), intent(in) :: k
      real(wp), intent(in) :: f(:)
      real(wp), intent(inout) :: x(:)
      real(wp), intent(inout) :: rcond
      type(error_type), allocatable, intent(out) :: error

      call solver%factorize(k, error)
      if (.not. allocated(error)) then
         rcond = solver%rcond_estimate
         call solver%solve(f, x, error)
      end if
      call solver%destroy()
   end subroutine solve_with

   !> Nodal displacements ue(dim*nen) of element e, node-major.
   pure subroutine element_displacements(self, e, ue)
      class(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(out) :: ue(:)
      integer :: j
      do j = 1, self%nen
         ue((j - 1)*self%dim + 1:j*self%dim) = self%u(:, self%mesh%nodes%connectivity(j, e))
      end do
   end subroutine element_displacements

   !> FE stress sigma(nstress) of element e at the point x (any point; the
   !> element's polynomial is used, extrapolated outside its box). After solve.
   pure subroutine stress_in_element(self, e, x, sigma)
      class(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      real(wp) :: ue(self%dim*self%nen), lo(3), hi(3), eps(6)
      call self%element_displacements(e, ue)
      call self%mesh%grid%leaf_box(e, lo(1:self%dim), hi(1:self%dim))
      if (self%dilatation%active) then
         call element_strain(self%dim, self%degree, lo(1:self%dim), hi(1:self%dim), x, ue, eps(1:self%nstress))
         call self%dilatation%projected_stress(e, x, eps(1:self%nstress), sigma)
         return
      end if
      call element_stress(self%dim, self%degree, self%d(1:self%nstress, 1:self%nstress), lo(1:self%dim), &
         & hi(1:self%dim), x, ue, sigma)
   end subroutine stress_in_element

   !> FE stress at the point x, in the element that contains it (on a shared
   !> face: the element on the upper side). Error if no active element holds x.
   subroutine stress_at(self, x, sigma, error)
      class(elasticity_problem_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: e
      character(len=160) :: buf

      if (.not. self%solved) then
         call fatal_error(error, 'stress_at: the problem is not solved', stat_invalid_input)
         return
      end if
      if (size(x) /= self%dim .or. size(sigma) /= self%nstress) then
         write (buf, '("stress_at: x has ",i0," values and sigma ",i0,", expected ",i0," and ",i0)') &
            & size(x), size(sigma), self%dim, self%nstress
         call fatal_error(error, trim(buf), stat_invalid_input)
         return
      end if
      e = self%mesh%grid%locate_point(x)
      if (e == 0) then
         call fatal_error(error, 'stress_at: the point lies in no active element', stat_invalid_input)
         return
      end if
      call self%stress_in_element(e, x, sigma)
   end subroutine stress_at

   !> The volume integration points of element e (what a recovery patch
   !> needs): x(dim, n), weights w(n) (w |J| over the cut domain) and FE
   !> stresses sigma(nstress, n). After solve.
   pure subroutine element_points(self, e, x, w, sigma)
      class(elasticity_problem_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), allocatable, intent(out) :: x(:, :), w(:), sigma(:, :)
      integer :: q, q0, q1
      q0 = self%mesh%vol_ptr(e)
      q1 = self%mesh%vol_ptr(e + 1) - 1
      x = self%mesh%vol_x(:, q0:q1)
      w = self%mesh%vol_w(q0:q1)
      allocate (sigma(self%nstress, q1 - q0 + 1))
      do q = q0, q1
         call self%stress_in_element(e, self%mesh%vol_x(:, q), sigma(:, q - q0 + 1))
      end do
   end subroutine element_points

   !> Energy norms over the true domain (cut-cell volume rules), with
   !> ||s||_E^2 = int s^T D^-1 s: err_fe = ||sigma_ex - sigma_h||_E / ||sigma_ex||_E,
   !> element_error(e) = ||sigma_ex - sigma_h||_E on element e, norm_fe = ||sigma_h||_E,
   !> norm_exact = ||sigma_ex||_E and optionally err_norm = ||sigma_ex - sigma_h||_E
   !> (sums over several bodies add its square). Needs the exact solution given to setup.
   !> With `share` (a level shared out among ranks, `sprc_grid_share`) each rank
   !> integrates its range of elements and the terms are gathered before the sums.
   subroutine energy_error(self, err_fe, element_error, norm_fe, norm_exact, error, err_norm, share)
      class(elasticity_problem_type), intent(in) :: self
      real(wp), intent(out) :: err_fe
      real(wp), allocatable, intent(out) :: element_error(:)
      real(wp), intent(out) :: norm_fe, norm_exact
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(out), optional :: err_norm
      class(share_type), intent(in), optional :: share
      real(wp), allocatable :: parts(:, :)
      real(wp) :: sh(6), se(6), c(6, 6), de(6)
      integer, allocatable :: first(:)
      integer :: e, q, ns, nel, stat, lo, hi

      err_fe = 0.0_wp
      norm_fe = 0.0_wp
      norm_exact = 0.0_wp
      if (present(err_norm)) err_norm = 0.0_wp
      if (.not. self%solved) then
         call fatal_error(error, 'energy_error: the problem is not solved', stat_invalid_input)
         return
      end if
      if (.not. allocated(self%exact)) then
         call fatal_error(error, 'energy_error: no exact solution was given to setup', stat_invalid_input)
         return
      end if
      ns = self%nstress
      nel = self%mesh%grid%n_leaves
      c = self%compliance
      allocate (parts(3, nel), element_error(nel), stat=stat)
      call check_allocation(stat, 'energy_error', 'the error of each element', nel, 32, error)
      ! A rank that failed alone must not leave the others waiting in the gather.
      if (present(share)) call share%agree('energy_error', error)
      if (allocated(error)) return
      call share_range(share, self%mesh%vol_ptr(2:) - self%mesh%vol_ptr(:nel) + 1, first, lo, hi)
      !$omp parallel do schedule(dynamic, 16) default(shared) private(e, q, sh, se, de)
      do e = lo, hi
         parts(:, e) = 0.0_wp
         do q = self%mesh%vol_ptr(e), self%mesh%vol_ptr(e + 1) - 1
            call self%stress_in_element(e, self%mesh%vol_x(:, q), sh(1:ns))
            call self%exact%stress(self%mesh%vol_x(:, q), se(1:ns))
            de(1:ns) = se(1:ns) - sh(1:ns)
            parts(1, e) = parts(1, e) + self%mesh%vol_w(q)*dot_product(de(1:ns), matmul(c(1:ns, 1:ns), de(1:ns)))
            parts(2, e) = parts(2, e) + self%mesh%vol_w(q)*dot_product(sh(1:ns), matmul(c(1:ns, 1:ns), sh(1:ns)))
            parts(3, e) = parts(3, e) + self%mesh%vol_w(q)*dot_product(se(1:ns), matmul(c(1:ns, 1:ns), se(1:ns)))
         end do
      end do
      !$omp end parallel do
      if (present(share)) then
         call share%gather_slices(3*(int(first, i8) - 1) + 1, parts, error)
         if (allocated(error)) return
      end if
      element_error(:) = sqrt(parts(1, :))
      norm_fe = sqrt(sum(parts(2, :)))
      norm_exact = sqrt(sum(parts(3, :)))
      err_fe = sqrt(sum(parts(1, :)))/max(norm_exact, tiny(1.0_wp))
      if (present(err_norm)) err_norm = sqrt(sum(parts(1, :)))
   end subroutine energy_error

   !> Reciprocal 1-norm condition estimate of the diagonally scaled reduced
   !> stiffness S^-1/2 K S^-1/2 (S = diag K): one extra factorization, for
   !> studies of the conditioning. After solve (or assembly).
   subroutine scaled_rcond(self, value, error)
      class(elasticity_problem_type), intent(in) :: self
      real(wp), intent(out) :: value
      type(error_type), allocatable, intent(out) :: error
      type(csr_type) :: a
      type(cholmod_solver_type) :: chol
      real(wp), allocatable :: scale(:)
      integer :: i, stat
      integer(kind(self%k%rowptr)) :: q

      value = 0.0_wp
      if (.not. allocated(self%k%rowptr)) then
         call fatal_error(error, 'scaled_rcond: the stiffness is not assembled', stat_invalid_input)
         return
      end if
      call self%k%copy(a, error)
      if (allocated(error)) return
      allocate (scale(a%nrows), stat=stat)
      call check_allocation(stat, 'scaled_rcond', 'the diagonal scaling', a%nrows, 8, error)
      if (allocated(error)) return
      scale = 0.0_wp
      do i = 1, a%nrows
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            if (a%col(q) == i .and. a%val(q) > 0.0_wp) scale(i) = 1.0_wp/sqrt(a%val(q))
         end do
      end do
      do i = 1, a%nrows
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            a%val(q) = a%val(q)*scale(i)*scale(a%col(q))
         end do
      end do
      chol%rcond_tol = 0.0_wp
      call chol%factorize(a, error)
      if (allocated(error)) return
      call chol%rcond(a, value, error)
      call chol%destroy()
   end subroutine scaled_rcond

end module sprc_fem_problem
