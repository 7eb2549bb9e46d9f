!> One level of a study (`sprc run`): for every body its cut mesh (grid,
!> nodes, hanging-node constraints), cut-cell quadrature, FE solve, SPR /
!> SPR-C recovery and ZZ estimate, and the level's report row with the norms
!> summed over the bodies (doc/scene.md "The report": ||.||^2 added, then the ratio).
!>
!> ```fortran
!> call prepare_study(scene, points, study, error)   ! once: bodies, conditions, exact solutions
!> call run_level(study, level, result, error)        ! result%row, result%bodies(b)%problem, ...
!> ```
!> Bodies without `&contact` between them are independent problems: each
!> body's results are exactly those of a scene holding that body alone.
!> The bodies joined by `&contact` pairs (a component of the contact graph,
!> `contact_components`) are solved together (sprc_contact_pair_solve: one block
!> system, one active-set iteration over the cells of all its pairs) in one
!> unit system (the modulus unit of the slave of the component's first pair,
!> the largest strain unit of its bodies), and every pair's contact result
!> (`contacts`) comes in scene units. A component of one pair is
!> `solve_contact_pair`'s (every friction law and stabilization); one of
!> several pairs `solve_contact_assembly`'s (frictionless or stick, FE
!> stabilization; the rest is refused, stat_unsupported, before any
!> computation). A body of several pairs recovers with one contact
!> description per pair (sprc_estimate_patches: what a patch touching two
!> pairs takes). With
!> `stabilization = 'recovered'` the pair is solved with a zero
!> stabilization traction first (penalty), then re-solved with the slave
!> body's coupled SPR-C traction of the previous solution until it settles
!> (`stabilize_recovered`).
!> Coulomb friction follows the load path of `&bc stage` and `&contact
!> steps` (`load_path`); other friction laws take all stages as one load.
!>
!> With an `&exact` group the closed form applies to every body, with that
!> body's material.
module sprc_study_level
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_unsupported, stat_internal, stat_invalid_input, &
      & stat_not_converged
   use sprc_core_timer, only: timer_type, wall_time
   use sprc_core_alloc, only: check_allocation
   use sprc_core_blas_threads, only: blas_reserve_buffers
   use sprc_geometry_body, only: body_type
   use sprc_exact_solution, only: exact_solution_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_tree, only: grid_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, default_points
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_estimate_patches, only: recovery_input_type, recover_grid, boundary_points
   use sprc_recovery_patch, only: patch_type
   use sprc_estimate_recovered_field, only: recovered_field_type, method_spr, method_sprc, field_eval
   use sprc_recovery_contact_operators, only: contact_traction, contact_law_frictionless, contact_law_slip, &
      & contact_law_stick
   use sprc_recovery_operators, only: traction_operator
   use sprc_estimate_contact_patches, only: grid_contact_type, new_grid_contact, point_cells_type, new_point_cells, cells_box
   use sprc_estimate_norms, only: zz_estimate_type, estimate_error
   use sprc_fem_bc, only: fe_bc_type
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_estimate_fe_input, only: fe_recovery_input
   use sprc_fem_dilatation, only: dilatation_choice
   use sprc_study_spec, only: scene_type, contact_spec_type, recovery_degree, contact_unsupported, contact_components
   use sprc_study_model, only: scene_surface, build_bodies, build_exact, body_conditions, analysis_kind, analysis_units_type, &
      & analysis_units, in_units
   use sprc_study_budget, only: check_level_memory, check_coupled_memory, level_cells
   use sprc_study_partition, only: partition_type, start_partition, integrate_level, solve_level, assemble_pair_rows
   use sprc_grid_share, only: share_type
   use sprc_study_row, only: report_row_type
   use sprc_study_contact_row, only: fill_contact_exact, fill_contact_row
   use sprc_contact_result, only: contact_result_type, new_contact_result, contact_open, contact_stick, &
      & contact_slip
   use sprc_contact_surface, only: contact_surface_type, slave_surface_points, initial_gaps
   use sprc_contact_pair_solve, only: contact_solution_type, solve_contact_pair, friction_kind, friction_coulomb, &
      & friction_frictionless, contact_progress, default_max_iterations, contact_factor_type, contact_body_type, &
      & contact_pair_type, solve_contact_assembly, multiplier_kind, pair_iterative
   use sprc_fem_element, only: traction_matrix
   use sprc_core_text, only: itoa, real_text
   implicit none
   private

   public :: study_type, study_body_type, prepare_study, run_level, level_type, body_level_type, hold_starts
   public :: nodal_fe_stress, mesh_source_type, finest_cells

   !> What every level needs of one body, built once from the scene.
   type :: study_body_type
      character(len=:), allocatable :: name
      type(body_type) :: geometry
      !> The exact solution with this body's material (not allocated without `&exact`).
      class(exact_solution_type), allocatable :: exact
      !> FE conditions on the body's own shape indices.
      type(fe_bc_type), allocatable :: bcs(:)
      !> The body's analysis runs in these units (`sprc_study_model`): scaled
      !> modulus, body force, conditions and exact solution.
      type(analysis_units_type) :: units
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      real(wp), allocatable :: body_force(:)
      !> The level-0 cell of the body's grid.
      real(wp), allocatable :: box_min(:)
      real(wp) :: box_size = 0.0_wp
   end type study_body_type

   !> Where an adapted mesh of one body comes from (`run_level`'s `source`):
   !> the grid of the body's previous mesh and the level wanted for each of its
   !> leaves (sprc_grid_adapt), at most `max_level`; `dofs`, the dofs predicted
   !> for the new mesh (its memory estimate).
   type :: mesh_source_type
      type(grid_type) :: old
      integer, allocatable :: levels(:)
      integer :: max_level = 0
      real(wp) :: dofs = 0.0_wp
   end type mesh_source_type

   !> A prepared study: its bodies and the settings every level shares.
   type :: study_type
      !> The scene (for the memory estimate of a level).
      type(scene_type) :: scene
      type(study_body_type), allocatable :: bodies(:)
      integer :: dim = 0, order = 0, analysis = 0, refine_boundary = 0
      !> Gauss points per direction of the cut-cell rules; patch polynomial degree.
      integer :: points = 0, degree(2) = 0
      !> Nitsche penalty factor (the scene's `nitsche_gamma`) and volumetric formulation
      !> (`sprc_fem_dilatation`'s choice for the scene's `dilatation`).
      real(wp) :: gamma = 0.0_wp
      integer :: dilatation = 0
      !> Recoveries to run (1 SPR, 2 SPR-C) and whether the scene has an exact solution.
      logical :: run(2) = .false.
      logical :: have_exact = .false.
      !> The MPI ranks a level is shared out among (`sprc_study_partition`; one in a serial run).
      type(partition_type) :: partition
   end type study_type

   !> One body at one level. Its cut mesh (grid, nodes, hanging-node
   !> constraints, cell rules) is `problem%mesh`.
   type :: body_level_type
      type(elasticity_problem_type) :: problem
      !> Recovered fields and estimates per method (1 SPR, 2 SPR-C), where run.
      type(recovered_field_type) :: field(2)
      type(zz_estimate_type) :: est(2)
      !> With an exact solution: ||sigma_ex - sigma_h||_E, ||sigma_ex||_E and the
      !> error per element (energy norm) of the FE stress.
      real(wp) :: err_norm = 0.0_wp, norm_exact = 0.0_wp
      real(wp), allocatable :: element_error(:)
      !> Factor taking this body's squared energy norms to those of the first
      !> body's units (a power of two; 1 for the first body), for the sums.
      real(wp) :: norm2_scale = 1.0_wp
   end type body_level_type

   !> One level of a study: every body's results and the report row.
   type :: level_type
      integer :: level = 0
      !> Which recoveries ran (1 SPR, 2 SPR-C).
      logical :: done(2) = .false.
      type(body_level_type), allocatable :: bodies(:)
      !> One result per `&contact` pair (not allocated without `&contact`).
      type(contact_result_type), allocatable :: contacts(:)
      !> Per pair (columns) the jump of the normal traction between the two bodies over the
      !> closed slave points with a master point, relative (`traction_jump`): rows FE, SPR,
      !> SPR-C (negative where the recovery did not run).
      real(wp), allocatable :: traction_jump(:, :)
      type(report_row_type) :: row
   end type level_type

contains

   !> Check that this version can run the scene and build what every level
   !> shares. `points` = 0 takes the default for the scene's FE order. Takes
   !> OpenBLAS's buffer for each thread of the current OpenMP team
   !> (`blas_reserve_buffers`): set the thread count before.
   subroutine prepare_study(scene, points, study, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: points
      type(study_type), intent(out) :: study
      type(error_type), allocatable, intent(out) :: error
      type(body_type), allocatable :: bodies(:)
      type(scene_type) :: scaled
      integer :: b

      if (len(contact_unsupported(scene)) > 0) then
         call fatal_error(error, contact_unsupported(scene), stat_unsupported)
         return
      end if
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      allocate (study%bodies(size(bodies)))
      do b = 1, size(bodies)
         call analysis_units(scene, study%bodies(b)%units, error, b)
         if (allocated(error)) return
      end do
      call shared_units(scene, study%bodies)
      do b = 1, size(bodies)
         associate (sb => study%bodies(b), spec => scene%bodies(b))
            sb%name = spec%name
            sb%geometry = bodies(b)
            scaled = in_units(scene, sb%units)
            call build_exact(scaled, b, sb%exact, error)
            if (allocated(error)) return
            call body_conditions(scaled, b, sb%bcs)
            sb%young = scaled%bodies(b)%young
            sb%poisson = spec%poisson
            sb%body_force = scaled%bodies(b)%body_force
            sb%box_min = spec%box_min
            sb%box_size = spec%box_size
         end associate
      end do
      study%scene = scene
      study%dim = scene%dim
      study%order = scene%order
      study%analysis = analysis_kind(scene)
      study%refine_boundary = scene%refine_boundary
      study%gamma = scene%nitsche_gamma
      study%dilatation = dilatation_choice(scene%dilatation)
      study%points = points
      if (points == 0) study%points = default_points(scene%order)
      study%degree = [recovery_degree(scene, 1), recovery_degree(scene, 2)]
      study%run = [scene%recovery == 'spr' .or. scene%recovery == 'both', &
         & scene%recovery == 'sprc' .or. scene%recovery == 'both']
      ! The error columns need a stress field: an exact kind that gives the
      ! contact pressure only (hertz_*) leaves them empty (doc/scene.md).
      study%have_exact = .false.
      do b = 1, size(study%bodies)
         study%have_exact = study%have_exact .or. allocated(study%bodies(b)%exact)
      end do
      call start_partition(study%partition, error)
      if (allocated(error)) return
      ! Every path to run_level passes here: OpenBLAS's buffers are taken
      ! before the first level, while there is room (a failure is an error).
      call blas_reserve_buffers(error)
   end subroutine prepare_study

   !> The bodies of a component of the contact graph share one unit system:
   !> the modulus unit of the slave of the component's first pair and the
   !> largest of the bodies' strain units expressed in it (powers of two, so
   !> exact; for one pair the slave's modulus unit and the larger strain unit
   !> of the two). Other bodies keep their own units.
   subroutine shared_units(scene, bodies)
      type(scene_type), intent(in) :: scene
      type(study_body_type), intent(inout) :: bodies(:)
      type(analysis_units_type) :: u
      integer, allocatable :: comp(:)
      integer :: c, k, b, n

      call contact_components(scene, comp, n)
      do c = 1, n
         k = findloc(comp(scene%contacts%slave_index), c, 1)
         u%modulus = bodies(scene%contacts(k)%slave_index)%units%modulus
         u%strain = 0.0_wp
         do b = 1, size(bodies)
            if (comp(b) == c) u%strain = max(u%strain, bodies(b)%units%strain*(bodies(b)%units%modulus/u%modulus))
         end do
         do b = 1, size(bodies)
            if (comp(b) == c) bodies(b)%units = u
         end do
      end do
   end subroutine shared_units

   !> One level of the study: every body analysed, the report row summed.
   !> With `source` (one per body), each body's mesh is the adapted one it
   !> describes instead of the uniform `level`; the row's `level` is then
   !> the finest level present and `h` the smallest cell.
   subroutine run_level(study, level, result, error, progress, start, source)
      type(study_type), intent(in) :: study
      integer, intent(in) :: level
      type(level_type), intent(out), target :: result
      type(error_type), allocatable, intent(out) :: error
      !> Told after each contact iteration (sprc_contact_pair_solve's `contact_progress`).
      procedure(contact_progress), optional :: progress
      !> Per body, its displacement at another level (`hold_displacement`),
      !> where an iterative solve of the body starts (`sprc_fem_nested`).
      type(fe_displacement_type), intent(in), optional :: start(:)
      type(mesh_source_type), intent(in), optional :: source(:)
      type(cut_quadrature_type) :: quad
      real(wp) :: t_start, t_contact
      integer, allocatable :: comp(:), ks(:), pair_solver(:)
      integer :: b, k, c, ncomp

      t_start = wall_time()
      result%level = level
      result%done = study%run
      call new_cut_quadrature(quad, study%dim, study%points, error)
      if (allocated(error)) return
      call check_pairs_memory(study, level, pair_solver, error, source)
      if (allocated(error)) return
      allocate (result%bodies(size(study%bodies)))
      do b = 1, size(study%bodies)
         associate (u => study%bodies(b)%units, u1 => study%bodies(1)%units)
            result%bodies(b)%norm2_scale = (u%modulus/u1%modulus)*(u%strain/u1%strain)**2
         end associate
         if (starts_given(start, size(study%bodies))) then
            call run_body(study, study%bodies(b), level, quad, result%bodies(b), in_contact(study, b), error, &
               & start(b), source, b)
         else
            call run_body(study, study%bodies(b), level, quad, result%bodies(b), in_contact(study, b), error, &
               & source=source, b=b)
         end if
         if (allocated(error)) then
            if (size(study%bodies) > 1) error%message = 'body '''//study%bodies(b)%name//''': '//error%message
            return
         end if
      end do
      ! the solver each pair's memory estimate chose (check_pairs_memory)
      do b = 1, size(study%bodies)
         if (pair_solver(b) /= 0) result%bodies(b)%problem%solver = pair_solver(b)
      end do
      t_contact = 0.0_wp
      if (size(study%scene%contacts) > 0) allocate (result%contacts(size(study%scene%contacts)), &
         & result%traction_jump(3, size(study%scene%contacts)))
      call contact_components(study%scene, comp, ncomp)
      do c = 1, ncomp
         ks = pack([(k, k=1, size(study%scene%contacts))], comp(study%scene%contacts%slave_index) == c)
         if (size(ks) == 1) then
            k = ks(1)
            call run_contact(study, study%scene%contacts(k), result%bodies, result%contacts(k), t_contact, error, &
               & result%traction_jump(:, k), progress)
         else
            call run_assembly(study, ks, pack([(b, b=1, size(study%bodies))], comp == c), result%bodies, &
               & result%contacts, t_contact, error, result%traction_jump, progress)
         end if
         if (allocated(error)) return
      end do
      call sum_row(study, result, result%row)
      if (present(source)) call finest_cells(study, result)
      if (allocated(result%contacts)) then
         result%row%has_contact = .true.
         ! An assembly's pairs share its iterations: counted once per component.
         result%row%contact_iterations = 0
         do c = 1, ncomp
            k = findloc(comp(study%scene%contacts%slave_index), c, 1)
            result%row%contact_iterations = result%row%contact_iterations + result%contacts(k)%iterations
         end do
         result%row%t_contact = t_contact
         call fill_contact_exact(study%scene, result%contacts, error)
         if (allocated(error)) return
         call fill_contact_row(result%contacts, result%row, error, result%traction_jump)
         if (allocated(error)) return
      end if
      result%row%t_total = wall_time() - t_start
      call check_row(result%row, study%have_exact, result%done, error)
   end subroutine run_level

   !> Every body's solved displacement of `result`, for `run_level`'s `start`
   !> at the next level (a body that was not solved holds nothing: its
   !> solve there starts from zero).
   subroutine hold_starts(result, start, error)
      type(level_type), intent(in) :: result
      type(fe_displacement_type), allocatable, intent(inout) :: start(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: b

      if (allocated(start)) deallocate (start)
      allocate (start(size(result%bodies)))
      do b = 1, size(result%bodies)
         if (result%bodies(b)%problem%solved) call result%bodies(b)%problem%hold_displacement(start(b), error)
         if (allocated(error)) return
      end do
   end subroutine hold_starts

   !> An adapted level's `level` and row columns `level` and `h`: the finest
   !> level among the bodies' leaves and the smallest cell.
   subroutine finest_cells(study, result)
      type(study_type), intent(in) :: study
      type(level_type), intent(inout) :: result
      integer :: b

      result%level = 0
      result%row%h = huge(1.0_wp)
      do b = 1, size(result%bodies)
         associate (grid => result%bodies(b)%problem%mesh%grid)
            result%level = max(result%level, grid%max_level)
            result%row%h = min(result%row%h, study%bodies(b)%box_size/real(2**grid%max_level, wp))
         end associate
      end do
      result%row%level = result%level
   end subroutine finest_cells

   !> Whether `start` holds one displacement per body (run_level).
   pure logical function starts_given(start, n_bodies)
      type(fe_displacement_type), intent(in), optional :: start(:)
      integer, intent(in) :: n_bodies
      starts_given = .false.
      if (present(start)) starts_given = size(start) == n_bodies
   end function starts_given

   !> Mesh, FE solve, recoveries and estimates of one body at `level` (or, with
   !> `source`, on the adapted mesh `source(b)` describes); a body `in_contact`
   !> is only meshed and assembled (its pair solves it, `run_contact`).
   subroutine run_body(study, sb, level, quad, bl, in_contact, error, start, source, b)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      integer, intent(in) :: level
      type(cut_quadrature_type), intent(in) :: quad
      type(body_level_type), intent(inout) :: bl
      logical, intent(in) :: in_contact
      type(error_type), allocatable, intent(out) :: error
      type(fe_displacement_type), intent(in), optional :: start
      type(mesh_source_type), intent(in), optional :: source(:)
      integer, intent(in) :: b
      type(cut_mesh_type), allocatable :: mesh
      integer :: solver

      allocate (mesh)
      if (present(source)) then
         call check_level_memory(study%scene, sb%geometry, level, error, solver=solver, known_dofs=source(b)%dofs)
         if (allocated(error)) return
         call mesh%build_adapted(sb%geometry, source(b)%old, source(b)%levels, source(b)%max_level, study%order, &
            & error)
      else
         call check_level_memory(study%scene, sb%geometry, level, error, solver=solver)
         if (allocated(error)) return
         call mesh%build(sb%geometry, sb%box_min, sb%box_size, level, study%refine_boundary, study%order, error)
      end if
      if (allocated(error)) return
      if (any(study%run) .and. sum(mesh%grid%n_inside) + sum(mesh%grid%n_cut) < 2) then
         call fatal_error(error, 'one cell holds the whole body at this level, so every recovery patch is that '// &
            & 'one element: the recovered stress is the FE stress and the estimate (eta = 0) says nothing; '// &
            & 'use a higher level (or a smaller box_size)', stat_invalid_input)
         return
      end if
      call integrate_level(study%partition, mesh, quad, error)
      if (allocated(error)) return
      if (allocated(sb%exact)) then
         call bl%problem%setup(mesh, study%analysis, sb%young, sb%poisson, sb%body_force, sb%bcs, error, &
            & exact=sb%exact, gamma=study%gamma, dilatation=study%dilatation)
      else
         call bl%problem%setup(mesh, study%analysis, sb%young, sb%poisson, sb%body_force, sb%bcs, error, &
            & gamma=study%gamma, dilatation=study%dilatation)
      end if
      if (allocated(error)) return
      bl%problem%solver = solver
      if (in_contact) then
         ! shared out among ranks, the pair assembles it (`assemble_shared_pair`)
         if (.not. study%partition%shared()) call bl%problem%assemble(error)
         return
      end if
      if (present(start)) allocate (bl%problem%start, source=start)
      call solve_level(study%partition, bl%problem, error)
      if (allocated(error)) return
      call finish_body(study, sb, bl, error)
   end subroutine run_body

   !> After the FE solve of a body not in contact: the exact error, the recoveries and estimates.
   subroutine finish_body(study, sb, bl, error)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      type(body_level_type), intent(inout) :: bl
      type(error_type), allocatable, intent(out) :: error
      type(recovery_input_type) :: input

      call exact_error(study, sb, bl, error)
      if (allocated(error) .or. .not. any(study%run)) return
      call fe_recovery_input(bl%problem, input, error)
      if (.not. allocated(error)) call recover_body(study, sb, bl, input, error)
   end subroutine finish_body

   !> The energy error of the FE stress where there is an exact solution.
   subroutine exact_error(study, sb, bl, error)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      type(body_level_type), intent(inout) :: bl
      type(error_type), allocatable, intent(out) :: error
      type(partition_type), target :: part
      real(wp) :: err_fe, norm_fe

      if (.not. allocated(sb%exact)) return
      part = study%partition
      call bl%problem%energy_error(err_fe, bl%element_error, norm_fe, bl%norm_exact, error, bl%err_norm, &
         & share=level_share(study, part))
   end subroutine exact_error

   !> `part` (the study's partition) when the level's element work is shared
   !> out among ranks, else null: an absent `share`.
   function level_share(study, part) result(share)
      type(study_type), intent(in) :: study
      type(partition_type), intent(in), target :: part
      class(share_type), pointer :: share
      share => null()
      if (part%shared()) share => part
   end function level_share

   !> The recoveries and estimates of a body from its recovery input; `contacts` are its
   !> contact surfaces, one per pair (SPR-C's coupled contact patches, sprc_estimate_contact_patches).
   subroutine recover_body(study, sb, bl, input, error, contacts)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      type(body_level_type), intent(inout) :: bl
      type(recovery_input_type), intent(in) :: input
      type(error_type), allocatable, intent(out) :: error
      type(grid_contact_type), intent(in), optional :: contacts(:)
      integer :: m

      do m = 1, 2
         if (.not. study%run(m)) cycle
         call recover_and_estimate(study, sb, input, bl, m, study%degree(m), error, contacts)
         if (allocated(error)) return
      end do
   end subroutine recover_body

   !> The memory estimate of each contact pair's bodies solved together
   !> (sprc_study_budget's `check_coupled_memory`), before any body is built:
   !> a pair that does not fit is refused. `solver(b)`: the solver of body b's
   !> pair (0 for a body in no pair), iterative where 'auto' found that the
   !> pair's direct solve would not fit.
   subroutine check_pairs_memory(study, level, solver, error, source)
      type(study_type), intent(in) :: study
      integer, intent(in) :: level
      integer, allocatable, intent(out) :: solver(:)
      type(error_type), allocatable, intent(out) :: error
      type(mesh_source_type), intent(in), optional :: source(:)
      integer :: k, j, choice, members(2)
      real(wp) :: cells(2, 2)

      allocate (solver(size(study%bodies)), source=0)
      do k = 1, size(study%scene%contacts)
         members = [study%scene%contacts(k)%slave_index, study%scene%contacts(k)%master_index]
         if (present(source)) then
            call check_coupled_memory(study%scene, members=members, slaves=members(1:1), level=level, error=error, &
               & solver=choice, known_dofs=[source(members(1))%dofs, source(members(2))%dofs])
         else
            ! per member, not `study%bodies%geometry`: that would copy every body's geometry
            do j = 1, 2
               call level_cells(study%scene, study%bodies(members(j))%geometry, level, cells(1, j), cells(2, j), error)
               if (allocated(error)) exit
            end do
            if (.not. allocated(error)) call check_coupled_memory(study%scene, members=members, slaves=members(1:1), &
               & level=level, error=error, solver=choice, known_cells=cells)
         end if
         if (allocated(error)) then
            error%message = "&contact '"//study%scene%contacts(k)%slave//"' on '"//study%scene%contacts(k)%master// &
               & "': "//error%message
            return
         end if
         solver(members) = choice
      end do
   end subroutine check_pairs_memory

   !> Whether body b belongs to a `&contact` pair.
   pure logical function in_contact(study, b)
      type(study_type), intent(in) :: study
      integer, intent(in) :: b
      integer :: k
      in_contact = .false.
      do k = 1, size(study%scene%contacts)
         in_contact = in_contact .or. study%scene%contacts(k)%slave_index == b .or. &
            & study%scene%contacts(k)%master_index == b
      end do
   end function in_contact

   !> One contact pair at this level: slave points and gaps, the coupled
   !> solve (sprc_contact_pair_solve), then each body's errors and recoveries; the
   !> contact result in scene units. The block solves count in the slave
   !> body's t_solve; points, gaps and contact terms add to `t_contact`.
   subroutine run_contact(study, spec, bodies, result, t_contact, error, jump, progress)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(body_level_type), intent(inout) :: bodies(:)
      type(contact_result_type), intent(out) :: result
      real(wp), intent(inout) :: t_contact
      type(error_type), allocatable, intent(out) :: error
      !> The pair's `traction_jump` (FE, SPR, SPR-C).
      real(wp), intent(out) :: jump(3)
      procedure(contact_progress), optional :: progress
      type(contact_surface_type) :: surface
      type(contact_solution_type) :: sol
      type(timer_type) :: timer
      type(partition_type), target :: part
      class(share_type), pointer :: share
      real(wp), allocatable :: loads(:, :), tstar(:, :)
      integer(i8), allocatable :: bounds(:)
      integer :: s, m, b, k

      s = spec%slave_index
      m = spec%master_index
      call assemble_shared_pair(study, spec, bodies, bounds, error)
      if (allocated(error)) return
      part = study%partition
      share => null()
      if (allocated(bounds)) share => part
      call timer%start()
      call pair_surface(study, spec, bodies, surface, error)
      call timer%stop()
      if (allocated(error)) return
      if (friction_kind(spec%friction) == friction_coulomb) then
         call load_path(study, spec, bodies(s)%problem, bodies(m)%problem, loads, error)
         if (allocated(error)) return
      end if
      block
         character(len=max(len(spec%slave), len(spec%master))) :: names(2)
         names(1) = spec%slave
         names(2) = spec%master
         if (friction_kind(spec%friction) == friction_coulomb) then
            call solve_contact_pair(bodies(s)%problem, bodies(m)%problem, surface, friction_coulomb, spec%kappa, &
               & names, sol, error, mu=spec%mu, loads=loads, progress=progress, &
               & multiplier=multiplier_kind(spec%multiplier))
         else if (spec%stabilization == 'recovered') then
            call stabilize_recovered(study, spec, surface, names, bodies, sol, tstar, error)
         else
            call solve_contact_pair(bodies(s)%problem, bodies(m)%problem, surface, friction_kind(spec%friction), &
               & spec%kappa, names, sol, error, progress=progress, multiplier=multiplier_kind(spec%multiplier), &
               & share=share, bounds=bounds)
         end if
      end block
      if (allocated(error)) return
      ! Each rank's rows of K serve no one after the distributed solve: their room goes to the recovery.
      if (allocated(bounds)) then
         do b = 1, 2
            k = merge(s, m, b == 1)
            deallocate (bodies(k)%problem%k%rowptr, bodies(k)%problem%k%col, bodies(k)%problem%k%val, &
               & bodies(k)%problem%f)
         end do
      end if
      bodies(s)%problem%t_solve = sol%t_solve
      bodies(m)%problem%t_solve = 0.0_wp
      ! Both bodies were solved in the block system: its solver and condition estimate.
      do b = 1, 2
         k = merge(s, m, b == 1)
         bodies(k)%problem%rcond = sol%rcond
         bodies(k)%problem%solver_name = sol%solver_name
         bodies(k)%problem%solver_iterations = merge(sol%solver_iterations, 0, b == 1)
      end do
      call contact_result(surface, sol, spec, study%bodies(s)%units, result, error)
      if (allocated(error)) return
      ! p* = -n.t* (t* = 0 at a point without slave cell), in scene units as p_fe.
      if (allocated(tstar)) result%p_star = -sum(surface%normal*tstar, dim=1)* &
         & (study%bodies(s)%units%modulus*study%bodies(s)%units%strain)
      call finish_pair(study, spec, surface, result, bodies, error)
      if (.not. allocated(error)) &
         & call recovered_tractions(surface, bodies(s), study%run, study%bodies(s)%units, result, error)
      if (.not. allocated(error)) call traction_jump(surface, result, bodies(s), bodies(m), study%run, jump, error)
      if (allocated(error)) return
      t_contact = t_contact + timer%elapsed + sol%t_contact
   end subroutine run_contact

   !> A pair's bodies assembled when the level is shared out among ranks
   !> (`run_body` leaves them unassembled then): where the pair's solve is
   !> distributed (frictionless or stick with the FE stabilization, through
   !> the iterative solver) each rank assembles only its rows of the block
   !> system (`assemble_pair_rows`, `bounds` its rows' split); otherwise both
   !> bodies whole on every rank (`bounds` not allocated).
   subroutine assemble_shared_pair(study, spec, bodies, bounds, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(body_level_type), intent(inout) :: bodies(:)
      integer(i8), allocatable, intent(out) :: bounds(:)
      type(error_type), allocatable, intent(out) :: error

      if (.not. study%partition%shared()) return
      associate (slave => bodies(spec%slave_index)%problem, master => bodies(spec%master_index)%problem)
         if (friction_kind(spec%friction) /= friction_coulomb .and. spec%stabilization /= 'recovered' .and. &
            & pair_iterative(slave, master)) then
            call assemble_pair_rows(study%partition, slave, master, bounds, error)
         else
            call slave%assemble(error)
            if (.not. allocated(error)) call master%assemble(error)
         end if
      end associate
   end subroutine assemble_shared_pair

   !> A pair's slave points with their initial gaps to the master
   !> (sprc_contact_surface), the gaps in the pair's units.
   subroutine pair_surface(study, spec, bodies, surface, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(body_level_type), intent(in) :: bodies(:)
      type(contact_surface_type), intent(out) :: surface
      type(error_type), allocatable, intent(out) :: error
      integer :: s, m

      s = spec%slave_index
      m = spec%master_index
      associate (slave => bodies(s)%problem%mesh, master => bodies(m)%problem%mesh)
         call slave_surface_points(surface, slave%grid, slave%body, slave%quad, &
            & scene_surface(study%scene, spec%slave_surface_index, spec%slave_group), error, split_grid=master%grid)
         if (.not. allocated(error)) call initial_gaps(surface, master%body, &
            & scene_surface(study%scene, spec%master_surface_index, spec%master_group), master%grid, &
            & max(study%bodies(s)%box_size, study%bodies(m)%box_size), error)
      end associate
      if (allocated(error)) then
         error%message = "&contact '"//spec%slave//"' on '"//spec%master//"': "//error%message
         return
      end if
      ! The gaps are displacements: into the pair's units.
      where (surface%has_master) surface%g0 = surface%g0/study%bodies(s)%units%strain
   end subroutine pair_surface

   !> A component of several pairs at this level (`ks` its pairs in scene
   !> order, `members` its bodies ascending): every pair's slave points and
   !> gaps, one coupled solve of all the members (solve_contact_assembly),
   !> then every member's errors and recoveries, with one contact description
   !> per pair it belongs to (`finish_assembly`); each pair's contact result
   !> in scene units and its traction jump. The block solves count in the
   !> first member's t_solve; points, gaps and contact terms add to `t_contact`.
   subroutine run_assembly(study, ks, members, bodies, results, t_contact, error, jumps, progress)
      type(study_type), intent(in) :: study
      integer, intent(in) :: ks(:), members(:)
      type(body_level_type), intent(inout), target :: bodies(:)
      type(contact_result_type), intent(inout) :: results(:)
      real(wp), intent(inout) :: t_contact
      type(error_type), allocatable, intent(out) :: error
      !> Every pair's `traction_jump` (FE, SPR, SPR-C), columns in scene order.
      real(wp), intent(inout) :: jumps(:, :)
      procedure(contact_progress), optional :: progress
      type(contact_body_type), allocatable :: cb(:)
      type(contact_pair_type), allocatable :: pairs(:)
      type(contact_solution_type), allocatable :: sols(:)
      type(timer_type) :: timer
      integer :: j, p, stat

      allocate (cb(size(members)), pairs(size(ks)), stat=stat)
      call check_allocation(stat, 'contact assembly', 'its bodies and pairs', size(ks) + size(members), 64, error)
      if (allocated(error)) return
      do j = 1, size(members)
         ! a level shared out among ranks leaves them unassembled (`run_body`); the assembly's solve is direct
         if (study%partition%shared()) call bodies(members(j))%problem%assemble(error)
         if (allocated(error)) return
         cb(j)%problem => bodies(members(j))%problem
         cb(j)%name = study%bodies(members(j))%name
      end do
      call timer%start()
      do p = 1, size(ks)
         associate (spec => study%scene%contacts(ks(p)))
            pairs(p)%slave = findloc(members, spec%slave_index, 1)
            pairs(p)%master = findloc(members, spec%master_index, 1)
            pairs(p)%friction = friction_kind(spec%friction)
            pairs(p)%kappa = spec%kappa
            pairs(p)%multiplier = multiplier_kind(spec%multiplier)
            call pair_surface(study, spec, bodies, pairs(p)%surface, error)
         end associate
         if (allocated(error)) return
      end do
      call timer%stop()
      call solve_contact_assembly(cb, pairs, sols, error, progress=progress)
      if (allocated(error)) return
      do j = 1, size(members)
         bodies(members(j))%problem%t_solve = merge(sols(1)%t_solve, 0.0_wp, j == 1)
         bodies(members(j))%problem%rcond = sols(1)%rcond
         bodies(members(j))%problem%solver_name = sols(1)%solver_name
      end do
      do p = 1, size(ks)
         associate (spec => study%scene%contacts(ks(p)))
            call contact_result(pairs(p)%surface, sols(p), spec, study%bodies(spec%slave_index)%units, &
               & results(ks(p)), error)
         end associate
         if (allocated(error)) return
      end do
      call finish_assembly(study, ks, members, pairs, results, bodies, error)
      if (allocated(error)) return
      do p = 1, size(ks)
         associate (spec => study%scene%contacts(ks(p)))
            call recovered_tractions(pairs(p)%surface, bodies(spec%slave_index), study%run, &
               & study%bodies(spec%slave_index)%units, results(ks(p)), error)
            if (.not. allocated(error)) call traction_jump(pairs(p)%surface, results(ks(p)), &
               & bodies(spec%slave_index), bodies(spec%master_index), study%run, jumps(:, ks(p)), error)
         end associate
         if (allocated(error)) return
      end do
      t_contact = t_contact + timer%elapsed + sols(1)%t_contact
   end subroutine run_assembly

   !> After an assembly's FE solve: every member's exact error, recoveries and
   !> estimates, SPR-C with one contact description per pair the member
   !> belongs to (`pair_contact`, the pair's other body as body (2));
   !> sprc_estimate_patches says what a patch touching two pairs takes.
   subroutine finish_assembly(study, ks, members, pairs, results, bodies, error)
      type(study_type), intent(in) :: study
      integer, intent(in) :: ks(:), members(:)
      type(contact_pair_type), intent(in) :: pairs(:)
      type(contact_result_type), intent(in) :: results(:)
      type(body_level_type), intent(inout) :: bodies(:)
      type(error_type), allocatable, intent(out) :: error
      type(recovery_input_type), allocatable :: inputs(:)
      type(grid_contact_type), allocatable :: contacts(:)
      integer :: j, b, p, n, side, other

      allocate (inputs(size(members)))
      do j = 1, size(members)
         b = members(j)
         call exact_error(study, study%bodies(b), bodies(b), error)
         if (.not. allocated(error) .and. any(study%run)) call fe_recovery_input(bodies(b)%problem, inputs(j), error)
         if (allocated(error)) then
            error%message = 'body '''//study%bodies(b)%name//''': '//error%message
            return
         end if
      end do
      if (.not. any(study%run)) return
      do j = 1, size(members)
         b = members(j)
         allocate (contacts(count(pairs%slave == j) + count(pairs%master == j)))
         n = 0
         do p = 1, size(ks)
            if (pairs(p)%slave == j) then
               side = 1
               other = pairs(p)%master
            else if (pairs(p)%master == j) then
               side = 2
               other = pairs(p)%slave
            else
               cycle
            end if
            n = n + 1
            call pair_contact(study, study%scene%contacts(ks(p)), pairs(p)%surface, results(ks(p)), side, inputs(j), &
               & bodies(b)%problem%mesh%nodes, inputs(other), contacts(n), error)
            if (allocated(error)) exit
         end do
         if (.not. allocated(error)) call recover_body(study, study%bodies(b), bodies(b), inputs(j), error, contacts)
         if (allocated(error)) then
            error%message = 'body '''//study%bodies(b)%name//''': '//error%message
            return
         end if
         deallocate (contacts)
      end do
   end subroutine finish_assembly

   !> Tur's recovered stabilization (sprc_contact_pair_solve notes): the pair
   !> solved with a zero stabilization traction first (the penalty method,
   !> SPD for every kappa), then again and again with the slave body's
   !> recovered traction sigma* n of the previous solution at the slave
   !> points as the known stabilization traction, until an update leaves
   !> the active set as it was and moves the contact traction (pressure and tangential part, L2 over
   !> the slave surface) by at most sqrt(eps) of its norm: the fixed point's
   !> own round-off tier, as the update contracts by about C_I/kappa (the
   !> traction operator's bound over the penalty). `sol%iterations` sums every
   !> active-set iteration of every solve (doc/scene.md contact_iterations), and
   !> `sol%t_contact` the stabilization's recoveries (the stabilization
   !> traction is a contact term; t_recovery stays the reported fields'); an
   !> iteration that has not settled after default_max_iterations updates is
   !> stat_not_converged.
   subroutine stabilize_recovered(study, spec, surface, names, bodies, sol, pstar, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      character(len=*), intent(in) :: names(2)
      type(body_level_type), intent(inout) :: bodies(:)
      type(contact_solution_type), intent(out) :: sol
      !> The stabilization traction of the last solve (dim, npoint; pair units).
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(contact_factor_type) :: factor

      call recovered_updates(study, spec, surface, names, bodies, factor, sol, pstar, error)
      call factor%destroy()
   end subroutine stabilize_recovered

   !> The iteration of `stabilize_recovered` with the block factor kept
   !> between updates (sprc_contact_pair_solve: the matrix depends on the active
   !> set only).
   subroutine recovered_updates(study, spec, surface, names, bodies, factor, sol, pstar, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      character(len=*), intent(in) :: names(2)
      type(body_level_type), intent(inout) :: bodies(:)
      type(contact_factor_type), intent(inout) :: factor
      type(contact_solution_type), intent(out) :: sol
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(contact_solution_type) :: next
      type(timer_type) :: timer
      real(wp) :: change, size_, t_solve, t_contact
      integer :: s, m, it, iterations, stat

      s = spec%slave_index
      m = spec%master_index
      allocate (pstar(surface%dim, surface%npoint), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact pair', 'the recovered traction of each slave point', surface%npoint, &
         & 8*surface%dim, error)
      if (allocated(error)) return
      call solve_contact_pair(bodies(s)%problem, bodies(m)%problem, surface, friction_kind(spec%friction), &
         & spec%kappa, names, sol, error, recovered=pstar, factor=factor, multiplier=multiplier_kind(spec%multiplier))
      if (allocated(error)) return
      iterations = sol%iterations
      t_solve = sol%t_solve
      t_contact = sol%t_contact
      do it = 1, default_max_iterations
         call timer%reset()
         call timer%start()
         call slave_recovered_traction(study, spec, surface, sol, bodies, pstar, error)
         call timer%stop()
         t_contact = t_contact + timer%elapsed
         if (.not. allocated(error)) call solve_contact_pair(bodies(s)%problem, bodies(m)%problem, surface, &
            & friction_kind(spec%friction), spec%kappa, names, next, error, recovered=pstar, factor=factor, &
            & multiplier=multiplier_kind(spec%multiplier))
         if (allocated(error)) return
         iterations = iterations + next%iterations
         t_solve = t_solve + next%t_solve
         t_contact = t_contact + next%t_contact
         change = sqrt(sum(surface%weight*((next%pressure - sol%pressure)**2 + (next%tangential - sol%tangential)**2)))
         size_ = sqrt(sum(surface%weight*(next%pressure**2 + next%tangential**2)))
         if (all(next%closed .eqv. sol%closed) .and. change <= sqrt(epsilon(1.0_wp))*size_) exit
         if (it == default_max_iterations) then
            call fatal_error(error, "contact '"//trim(names(1))//"' on '"//trim(names(2))//"': the recovered "// &
               & 'stabilization did not settle in '//itoa(it)//' updates; the last moved the contact traction by '// &
               & real_text(change/max(size_, tiny(1.0_wp)))//' of its norm and switched '// &
               & itoa(count(next%closed .neqv. sol%closed))//' points (raise kappa)', stat_not_converged)
            return
         end if
         sol = next
      end do
      sol = next
      sol%iterations = iterations
      sol%t_solve = t_solve
      sol%t_contact = t_contact
   end subroutine recovered_updates

   !> The slave body's recovered traction sigma* n at every slave point
   !> (dim, npoint; zero where the point has no slave cell), in the pair's
   !> units: the slave's SPR-C recovery of the current solution `sol`, with
   !> the patch degree of the scene's SPR-C and the pair's coupled contact
   !> patches (`pair_contact` of sol's contact states, the master's FE
   !> stresses as body (2)): the field the report's p_sprc comes from, so
   !> that a settled iteration is stabilized by the recovered stress it
   !> reports. Open parts of the contact surface are free surfaces.
   subroutine slave_recovered_traction(study, spec, surface, sol, bodies, pstar, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_solution_type), intent(in) :: sol
      type(body_level_type), intent(in) :: bodies(:)
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(recovery_input_type) :: inputs(2)
      type(contact_result_type) :: result
      type(grid_contact_type) :: contact(1)
      type(recovered_field_type) :: field
      real(wp) :: sigma(6), tn(3, 6)
      integer :: i, d, s, stat

      d = surface%dim
      s = spec%slave_index
      call contact_result(surface, sol, spec, study%bodies(s)%units, result, error)
      if (.not. allocated(error)) call fe_recovery_input(bodies(s)%problem, inputs(1), error)
      if (.not. allocated(error)) call fe_recovery_input(bodies(spec%master_index)%problem, inputs(2), error)
      if (.not. allocated(error)) call pair_contact(study, spec, surface, result, 1, inputs(1), &
         & bodies(s)%problem%mesh%nodes, inputs(2), contact(1), error)
      if (allocated(error)) return
      associate (mesh => bodies(s)%problem%mesh)
         call recover_grid(inputs(1), mesh%grid, mesh%nodes, mesh%hanging, method_sprc, study%degree(2), field, &
            & error, contacts=contact)
      end associate
      if (allocated(error)) return
      allocate (pstar(d, surface%npoint), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact pair', 'the recovered traction of each slave point', surface%npoint, 8*d, error)
      if (allocated(error)) return
      do i = 1, surface%npoint
         if (surface%slave_cell(i) < 1 .or. .not. surface%has_master(i)) cycle
         call field_eval(field, surface%slave_cell(i), surface%x(:, i), sigma, error)
         if (allocated(error)) return
         call traction_matrix(d, surface%normal(:, i), tn(1:d, 1:bodies(s)%problem%nstress))
         pstar(:, i) = matmul(tn(1:d, 1:bodies(s)%problem%nstress), sigma(1:bodies(s)%problem%nstress))
      end do
   end subroutine slave_recovered_traction

   !> After a pair's FE solve: both bodies' exact errors, recoveries and estimates, SPR-C
   !> with each body's contact surface (`pair_contact`): the coupled contact patches of
   !> both bodies, each with the other as body (2) (sprc_estimate_contact_patches).
   subroutine finish_pair(study, spec, surface, result, bodies, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      type(body_level_type), intent(inout) :: bodies(:)
      type(error_type), allocatable, intent(out) :: error
      type(recovery_input_type) :: inputs(2)
      type(grid_contact_type) :: contacts(2)
      integer :: b, k(2)

      k = [spec%slave_index, spec%master_index]
      do b = 1, 2
         call exact_error(study, study%bodies(k(b)), bodies(k(b)), error)
         if (.not. allocated(error) .and. any(study%run)) call fe_recovery_input(bodies(k(b))%problem, inputs(b), error)
         if (allocated(error)) then
            error%message = 'body '''//study%bodies(k(b))%name//''': '//error%message
            return
         end if
      end do
      if (.not. any(study%run)) return
      do b = 1, 2
         call pair_contact(study, spec, surface, result, b, inputs(b), &
            & bodies(k(b))%problem%mesh%nodes, inputs(3 - b), contacts(b), error)
         if (.not. allocated(error)) &
            & call recover_body(study, study%bodies(k(b)), bodies(k(b)), inputs(b), error, contacts(b:b))
         if (allocated(error)) then
            error%message = 'body '''//study%bodies(k(b))%name//''': '//error%message
            return
         end if
      end do
   end subroutine finish_pair

   !> The contact surface of side b (1 slave, 2 master) for its recovery (sprc_estimate_contact_patches):
   !> each of the body's boundary points on its contact shape takes the state of the nearest
   !> slave point (side 2: nearest master point of a slave point) within the size of its
   !> element, else open; closed states give the law (frictionless; stick; Coulomb: stick
   !> or slip) and, for slip, the slip direction of the body relative to the other: opposed
   !> to the contact's FE tangential traction on the slave (`result%t_fe`) on the slave side,
   !> along it on the master side.
   !> The other body's volume points, FE stresses and boundary points (its contact surface
   !> left out) are `other`'s.
   subroutine pair_contact(study, spec, surface, result, side, input, nodes, other, contact, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      integer, intent(in) :: side
      type(recovery_input_type), intent(in) :: input, other
      type(grid_nodes_type), intent(in) :: nodes
      type(grid_contact_type), intent(out) :: contact
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: law(:)
      real(wp), allocatable :: slip(:, :)
      real(wp) :: t(3), size_e, dist, best
      type(patch_type) :: oboundary
      type(point_cells_type) :: cells
      real(wp), allocatable :: sx(:, :)
      integer, allocatable :: near(:), sel(:)
      integer, allocatable :: surfaces(:), osurfaces(:)
      integer :: nb, e, k, i, j, inear, d, o, nnear, stat

      d = study%dim
      nb = size(input%bw)
      o = merge(spec%master_index, spec%slave_index, side == 1)
      if (side == 1) then
         surfaces = study%bodies(spec%slave_index)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%slave_surface_index, spec%slave_group))
         osurfaces = study%bodies(o)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%master_surface_index, spec%master_group))
      else
         surfaces = study%bodies(spec%master_index)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%master_surface_index, spec%master_group))
         osurfaces = study%bodies(o)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%slave_surface_index, spec%slave_group))
      end if
      allocate (law(nb), slip(d, nb), stat=stat)
      call check_allocation(stat, 'pair_contact', 'the contact law of each boundary point', nb, 4 + 8*d, error)
      if (allocated(error)) return
      law = 0
      slip = 0.0_wp
      ! This side's points of the slave points (on the master side those with a master point), in cells.
      if (side == 1) then
         sel = [(i, i=1, surface%npoint)]
         sx = surface%x
      else
         sel = pack([(i, i=1, surface%npoint)], surface%has_master)
         sx = surface%master_x(:, sel)
      end if
      call new_point_cells(cells, sx, error)
      if (allocated(error)) return
      do e = 1, nodes%n_elements
         if (input%belem_ptr(e + 1) == input%belem_ptr(e)) cycle
         size_e = element_size(nodes, e)
         do k = input%belem_ptr(e), input%belem_ptr(e + 1) - 1
            if (.not. any(surfaces == input%bshape(k))) cycle
            best = huge(1.0_wp)
            inear = 0
            call cells_box(cells, sx, input%bx(:, k) - size_e, input%bx(:, k) + size_e, near, nnear)
            do j = 1, nnear
               i = sel(near(j))
               dist = norm2(sx(:, near(j)) - input%bx(:, k))
               if (dist < best .or. (dist == best .and. i < inear)) then
                  best = dist
                  inear = i
               end if
            end do
            if (inear == 0 .or. best > size_e) cycle
            if (result%state(inear) == contact_open) cycle
            select case (friction_kind(spec%friction))
            case (friction_frictionless)
               law(k) = contact_law_frictionless
            case (friction_coulomb)
               law(k) = merge(contact_law_slip, contact_law_stick, result%state(inear) == contact_slip)
            case default
               law(k) = contact_law_stick
            end select
            if (law(k) /= contact_law_slip) cycle
            ! The direction of the contact's own tangential traction at the slave point (the
            ! multiplier, of magnitude mu p_fe on a slipping point), not that of the slave's FE
            ! stress there: near the edge of the contact zone the stress of a cut cell gave a
            ! tangential traction of the wrong sign (Cattaneo-Mindlin).
            t(1:d) = result%t_fe(:, inear)
            ! No tangential traction to give a direction: then mu p ~ 0, and stick is safe.
            if (.not. (norm2(t(1:d)) > sqrt(epsilon(1.0_wp))*abs(result%p_fe(inear)))) then
               law(k) = contact_law_stick
            else
               slip(:, k) = merge(-1.0_wp, 1.0_wp, side == 1)*t(1:d)
            end if
         end do
      end do
      if (allocated(study%bodies(o)%exact)) then
         call boundary_points(other, d, osurfaces, oboundary, study%bodies(o)%exact)
      else
         call boundary_points(other, d, osurfaces, oboundary)
      end if
      call new_grid_contact(contact, surfaces, law, slip, spec%mu, other%x, other%w, other%stress, other%young, &
         & other%poisson, other%body_force(1:d), error, boundary=oboundary)
   end subroutine pair_contact

   !> The largest edge of element e's box.
   pure real(wp) function element_size(nodes, e)
      type(grid_nodes_type), intent(in) :: nodes
      integer, intent(in) :: e
      integer :: nv

      nv = 2**nodes%dim
      element_size = maxval(maxval(nodes%x(:, nodes%connectivity(1:nv, e)), dim=2) - &
         & minval(nodes%x(:, nodes%connectivity(1:nv, e)), dim=2))
   end function element_size

   !> The load path of a Coulomb pair (doc/scene.md `&bc stage`, `&contact
   !> steps`): the block load at the end of each increment, stage k's loads
   !> applied in `steps` equal increments once the stages before it are
   !> applied. Stage k's cumulative loads come from an assembly of each body
   !> with the loads of later stages set to zero (pressures, tractions and
   !> prescribed displacements; exact_* conditions belong to stage 1); the
   !> last assembly holds every load.
   subroutine load_path(study, spec, slave, master, loads, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(elasticity_problem_type), intent(inout) :: slave, master
      real(wp), allocatable, intent(out) :: loads(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: previous(:), current(:)
      integer :: stages, k, j, n, ns, nd, stat

      stages = 1
      do k = 1, size(study%scene%bcs)
         stages = max(stages, study%scene%bcs(k)%stage)
      end do
      ns = slave%n_dofs()
      nd = ns + master%n_dofs()
      allocate (loads(nd, stages*spec%steps), previous(nd), current(nd), stat=stat)
      call check_allocation(stat, 'contact load path', 'the loads of the increments', &
         & int(nd, i8)*(stages*spec%steps + 2), 8, error)
      if (allocated(error)) return
      previous = 0.0_wp
      n = 0
      do k = 1, stages
         call stage_load(study, spec%slave_index, k, slave, error)
         if (.not. allocated(error)) call stage_load(study, spec%master_index, k, master, error)
         if (allocated(error)) return
         current(1:ns) = slave%f
         current(ns + 1:) = master%f
         do j = 1, spec%steps
            n = n + 1
            loads(:, n) = previous + (real(j, wp)/real(spec%steps, wp))*(current - previous)
         end do
         previous = current
      end do
   end subroutine load_path

   !> Assemble body b with the loads of the stages up to `stage` only (its
   !> conditions restored afterwards).
   subroutine stage_load(study, b, stage, problem, error)
      type(study_type), intent(in) :: study
      integer, intent(in) :: b, stage
      type(elasticity_problem_type), intent(inout) :: problem
      type(error_type), allocatable, intent(out) :: error
      type(fe_bc_type), allocatable :: all_stages(:)

      all_stages = problem%bcs
      call body_conditions(in_units(study%scene, study%bodies(b)%units), b, problem%bcs, stage)
      call problem%assemble(error)
      problem%bcs = all_stages
   end subroutine stage_load

   !> The contact result of a pair in scene units (pressures times the stress
   !> unit, gaps times the displacement unit).
   subroutine contact_result(surface, sol, spec, units, result, error)
      type(contact_surface_type), intent(in) :: surface
      type(contact_solution_type), intent(in) :: sol
      type(contact_spec_type), intent(in) :: spec
      type(analysis_units_type), intent(in) :: units
      type(contact_result_type), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      integer :: closed_state

      call new_contact_result(result, surface%x, surface%weight, surface%normal, spec%slave_index, spec%master_index, &
         & error)
      if (allocated(error)) return
      closed_state = merge(contact_slip, contact_stick, friction_kind(spec%friction) == friction_frictionless)
      where (surface%has_master) result%gap = sol%gap*units%strain
      result%state = merge(closed_state, contact_open, sol%closed)
      where (sol%slipping) result%state = contact_slip
      result%p_fe = (sol%pressure*units%modulus)*units%strain
      result%ts_fe = (sol%tangential*units%modulus)*units%strain
      result%t_fe = (sol%traction_t*units%modulus)*units%strain
      result%iterations = sol%iterations
   end subroutine contact_result

   !> p_fe_stress, p_spr, p_sprc and ts_sprc of a contact result (scene units) from the slave
   !> body's FE stresses and recovered fields (SPR, SPR-C where run) at its slave points:
   !> p = -n.sigma.n, ts = |sigma n - (n.sigma n) n| (sprc_recovery_contact_operators).
   !> SPR-C's field there comes from the coupled contact patches (`finish_pair`).
   subroutine recovered_tractions(surface, bl, run, units, result, error)
      type(contact_surface_type), intent(in) :: surface
      type(body_level_type), intent(in) :: bl
      logical, intent(in) :: run(2)
      type(analysis_units_type), intent(in) :: units
      type(contact_result_type), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: sigma(6), p, ts, unit
      integer :: i, m, d

      d = surface%dim
      unit = units%modulus*units%strain
      if (size(surface%slave_cell) < surface%npoint) return
      do m = 0, 2
         if (m > 0) then
            if (.not. run(m)) cycle
         end if
         do i = 1, surface%npoint
            if (surface%slave_cell(i) < 1) cycle
            if (m == 0) then
               call bl%problem%stress_in_element(surface%slave_cell(i), surface%x(:, i), sigma(1:merge(3, 6, d == 2)))
            else
               call field_eval(bl%field(m), surface%slave_cell(i), surface%x(:, i), sigma, error)
               if (allocated(error)) return
            end if
            call contact_traction(d, surface%normal(:, i), sigma, p, ts)
            select case (m)
            case (0)
               result%p_fe_stress(i) = p*unit
            case (1)
               result%p_spr(i) = p*unit
            case default
               result%p_sprc(i) = p*unit
               result%ts_sprc(i) = ts*unit
            end select
         end do
      end do
   end subroutine recovered_tractions

   !> Action-reaction of a pair's stresses (thesis eq. 107): over the closed slave points i with
   !> a master point, jump = sqrt(sum w_i (t1_i - t2_i)^2) / sqrt(sum w_i t1_i^2), with t1 the
   !> slave's normal traction n.sigma1.n at x_i and t2 the master's n.sigma2.n at its master
   !> point (n the slave normal): for the FE stresses, SPR and SPR-C (jump(m + 1), -1 where
   !> method m did not run or no point is closed).
   subroutine traction_jump(surface, result, slave, master, run, jump, error)
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      type(body_level_type), intent(in) :: slave, master
      logical, intent(in) :: run(2)
      real(wp), intent(out) :: jump(3)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: s1(6), s2(6), t(2), num(3), den(3), ts
      integer :: i, m, d, ns

      d = surface%dim
      ns = merge(3, 6, d == 2)
      num = 0.0_wp
      den = 0.0_wp
      do i = 1, surface%npoint
         if (result%state(i) == contact_open .or. .not. surface%has_master(i) .or. surface%slave_cell(i) < 1) cycle
         do m = 0, 2
            if (m == 0) then
               call slave%problem%stress_in_element(surface%slave_cell(i), surface%x(:, i), s1(1:ns))
               call master%problem%stress_in_element(surface%master_cell(i), surface%master_x(:, i), s2(1:ns))
            else
               if (.not. run(m)) cycle
               call field_eval(slave%field(m), surface%slave_cell(i), surface%x(:, i), s1, error)
               if (.not. allocated(error)) &
                  & call field_eval(master%field(m), surface%master_cell(i), surface%master_x(:, i), s2, error)
               if (allocated(error)) return
            end if
            call contact_traction(d, surface%normal(:, i), s1, t(1), ts)
            call contact_traction(d, surface%normal(:, i), s2, t(2), ts)
            num(m + 1) = num(m + 1) + surface%weight(i)*(t(1) - t(2))**2
            den(m + 1) = den(m + 1) + surface%weight(i)*t(1)**2
         end do
      end do
      jump = -1.0_wp
      where (den > 0.0_wp) jump = sqrt(num/den)
   end subroutine traction_jump

   !> Recovery and estimate with one method (1 SPR, 2 SPR-C) at the patch degree `degree`.
   !> With `contacts` (one per pair of the body), SPR-C's contact patches (sprc_estimate_contact_patches).
   subroutine recover_and_estimate(study, sb, input, bl, m, degree, error, contacts)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      type(recovery_input_type), intent(in) :: input
      type(body_level_type), intent(inout) :: bl
      integer, intent(in) :: m, degree
      type(error_type), allocatable, intent(out) :: error
      type(grid_contact_type), intent(in), optional :: contacts(:)
      type(partition_type), target :: part
      integer :: method

      method = merge(method_spr, method_sprc, m == 1)
      part = study%partition
      if (allocated(sb%exact)) then
         call recover_grid(input, bl%problem%mesh%grid, bl%problem%mesh%nodes, bl%problem%mesh%hanging, method, &
            & degree, bl%field(m), error, exact=sb%exact, contacts=contacts, share=level_share(study, part))
         if (allocated(error)) return
         call estimate_error(input, bl%field(m), bl%est(m), error, exact=sb%exact, share=level_share(study, part))
      else
         call recover_grid(input, bl%problem%mesh%grid, bl%problem%mesh%nodes, bl%problem%mesh%hanging, method, &
            & degree, bl%field(m), error, contacts=contacts, share=level_share(study, part))
         if (allocated(error)) return
         call estimate_error(input, bl%field(m), bl%est(m), error, share=level_share(study, part))
      end if
   end subroutine recover_and_estimate

   !> The level's report row: counts and times added over the bodies; each
   !> energy norm over all bodies is sqrt(sum of the bodies' squares, taken to
   !> common units by norm2_scale), then the ratios (for one body exactly its own values: sqrt(x*x) = |x| in
   !> binary floating point).
   subroutine sum_row(study, result, row)
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      type(report_row_type), intent(out) :: row
      real(wp) :: err2, exact2
      integer :: b, m

      row%level = result%level
      ! The coarsest body's cell: with one box for all, that box's edge at this level.
      row%h = maxval([(study%bodies(b)%box_size, b=1, size(study%bodies))])/real(2**result%level, wp)
      row%t_mesh = 0.0_wp
      row%t_quadrature = 0.0_wp
      row%t_assembly = 0.0_wp
      row%t_solve = 0.0_wp
      do b = 1, size(result%bodies)
         associate (bl => result%bodies(b))
            row%elements = row%elements + int(bl%problem%mesh%grid%n_leaves, i8)
            row%cut_elements = row%cut_elements + sum(bl%problem%mesh%grid%n_cut)
            row%dofs = row%dofs + int(bl%problem%n_dofs(), i8)
            row%t_mesh = row%t_mesh + bl%problem%mesh%t_mesh
            row%t_quadrature = row%t_quadrature + bl%problem%mesh%t_quadrature
            row%t_assembly = row%t_assembly + bl%problem%t_assembly
            row%t_solve = row%t_solve + bl%problem%t_solve
            row%solver_iterations = row%solver_iterations + bl%problem%solver_iterations
         end associate
      end do
      if (study%have_exact) then
         err2 = 0.0_wp
         exact2 = 0.0_wp
         do b = 1, size(result%bodies)
            err2 = err2 + result%bodies(b)%norm2_scale*result%bodies(b)%err_norm**2
            exact2 = exact2 + result%bodies(b)%norm2_scale*result%bodies(b)%norm_exact**2
         end do
         row%err_fe = sqrt(err2)/max(sqrt(exact2), tiny(1.0_wp))
      end if
      if (any(result%done)) then
         row%t_recovery = 0.0_wp
         row%t_estimate = 0.0_wp
      end if
      do m = 1, 2
         if (.not. result%done(m)) cycle
         do b = 1, size(result%bodies)
            row%t_recovery = row%t_recovery + result%bodies(b)%field(m)%t_recovery
            row%t_estimate = row%t_estimate + result%bodies(b)%est(m)%t_estimate
         end do
         call sum_method_columns(row, m, result%bodies, study%have_exact)
      end do
   end subroutine sum_row

   !> eta, err and theta of method m (1 SPR, 2 SPR-C) from the bodies' norms,
   !> with the formulas of `sprc_estimate_norms`.
   subroutine sum_method_columns(row, m, bodies, have_exact)
      type(report_row_type), intent(inout) :: row
      integer, intent(in) :: m
      type(body_level_type), intent(in) :: bodies(:)
      logical, intent(in) :: have_exact
      real(wp) :: err, norm_h, err_star, norm_ex, err_ex, eta, rel_err_star, theta
      integer :: b

      err = 0.0_wp
      norm_h = 0.0_wp
      err_star = 0.0_wp
      norm_ex = 0.0_wp
      err_ex = 0.0_wp
      do b = 1, size(bodies)
         err = err + bodies(b)%norm2_scale*bodies(b)%est(m)%err**2
         norm_h = norm_h + bodies(b)%norm2_scale*bodies(b)%est(m)%norm_h**2
         err_star = err_star + bodies(b)%norm2_scale*bodies(b)%est(m)%err_star**2
         norm_ex = norm_ex + bodies(b)%norm2_scale*bodies(b)%est(m)%norm_ex**2
         err_ex = err_ex + bodies(b)%norm2_scale*bodies(b)%est(m)%err_ex**2
      end do
      err = sqrt(err)
      norm_h = sqrt(norm_h)
      err_star = sqrt(err_star)
      norm_ex = sqrt(norm_ex)
      err_ex = sqrt(err_ex)
      eta = 0.0_wp
      if (norm_h**2 + err**2 > 0.0_wp) eta = err/sqrt(norm_h**2 + err**2)
      rel_err_star = 0.0_wp
      if (norm_ex > 0.0_wp) rel_err_star = err_star/norm_ex
      theta = 0.0_wp
      if (err_ex > 0.0_wp) theta = err/err_ex
      if (m == 1) then
         row%eta_spr = eta
         if (have_exact) row%err_spr = rel_err_star
         if (have_exact) row%theta_spr = theta
      else
         row%eta_sprc = eta
         if (have_exact) row%err_sprc = rel_err_star
         if (have_exact) row%theta_sprc = theta
      end if
   end subroutine sum_method_columns

   !> No computed column may carry a NaN or an infinity: an empty cell means
   !> "does not apply", never "went wrong". Every column that was set (the
   !> times always; errors and estimates where they apply) must be finite.
   subroutine check_row(row, have_exact, done, error)
      type(report_row_type), intent(in) :: row
      logical, intent(in) :: have_exact, done(2)
      type(error_type), allocatable, intent(out) :: error
      character(len=16) :: bad

      bad = ''
      if (.not. all(ieee_is_finite([row%h, row%t_mesh, row%t_quadrature, row%t_assembly, row%t_solve, &
         row%t_total]))) bad = 'times'
      if (have_exact .and. .not. ieee_is_finite(row%err_fe)) bad = 'err_fe'
      if (done(1) .and. .not. all(ieee_is_finite([row%t_recovery, row%t_estimate, row%eta_spr]))) bad = 'spr'
      if (done(2) .and. .not. all(ieee_is_finite([row%t_recovery, row%t_estimate, row%eta_sprc]))) bad = 'sprc'
      if (have_exact .and. done(1) .and. .not. all(ieee_is_finite([row%err_spr, row%theta_spr]))) bad = 'spr'
      if (have_exact .and. done(2) .and. .not. all(ieee_is_finite([row%err_sprc, row%theta_sprc]))) bad = 'sprc'
      if (len_trim(bad) > 0) call fatal_error(error, 'level result: the '//trim(bad)// &
         ' columns are not finite (a NaN or an overflow in the computation)', stat_internal)
   end subroutine check_row

   !> FE stress at each node: the average over the elements that hold it
   !> (the FE stress is discontinuous; this is only for viewing).
   subroutine nodal_fe_stress(problem, nodes, sigma, error)
      type(elasticity_problem_type), intent(in) :: problem
      type(grid_nodes_type), intent(in) :: nodes
      real(wp), allocatable, intent(out) :: sigma(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: s(6)
      integer :: n, k, e, ns, count, stat

      ns = problem%nstress
      allocate (sigma(ns, nodes%n_nodes), stat=stat)
      call check_allocation(stat, 'nodal FE stress', 'the stress at each node', nodes%n_nodes, 8*ns, error)
      if (allocated(error)) return
      do n = 1, nodes%n_nodes
         sigma(:, n) = 0.0_wp
         count = 0
         do k = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
            e = nodes%node_element(k)
            call problem%stress_in_element(e, nodes%x(:, n), s(1:ns))
            sigma(:, n) = sigma(:, n) + s(1:ns)
            count = count + 1
         end do
         if (count > 0) sigma(:, n) = sigma(:, n)/real(count, wp)
      end do
   end subroutine nodal_fe_stress

end module sprc_study_level
