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
!> (`stabilize_recovered`, sprc_study_run_contact_recovery).
!> Coulomb friction follows the load path of `&bc stage` and `&contact
!> steps` (`load_path`, sprc_study_run_contact); other friction laws take all stages as one load.
!>
!> With an `&exact` group the closed form applies to every body, with that
!> body's material. The stages are the runners `sprc_study_run_bodies`,
!> `sprc_study_run_contact` and `sprc_study_run_estimate` (types: `sprc_study_level_types`).
module sprc_study_level
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_unsupported, stat_internal
   use sprc_core_timer, only: wall_time
   use sprc_core_blas_threads, only: blas_reserve_buffers
   use sprc_geometry_body, only: body_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, default_points
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_fem_dilatation, only: dilatation_choice
   use sprc_study_spec, only: scene_type, recovery_degree, contact_unsupported, contact_components
   use sprc_study_model, only: build_bodies, build_exact, body_conditions, analysis_kind, analysis_units_type, &
      & analysis_units, in_units
   use sprc_study_partition, only: start_partition
   use sprc_study_row, only: report_row_type
   use sprc_study_contact_row, only: fill_contact_exact, fill_contact_row
   use sprc_contact_pair_solve, only: contact_progress
   use sprc_study_level_types, only: study_body_type, mesh_source_type, study_type, body_level_type, level_type
   use sprc_study_run_bodies, only: run_body, nodal_fe_stress
   use sprc_study_run_contact, only: check_pairs_memory, in_contact, run_contact, run_assembly
   implicit none
   private

   public :: study_type, study_body_type, prepare_study, run_level, level_type, body_level_type, hold_starts
   public :: nodal_fe_stress, mesh_source_type, finest_cells

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

end module sprc_study_level
