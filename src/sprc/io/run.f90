!> `sprc run`: the analysis of a scene at each level of its study — grid,
!> cut-cell quadrature, FE solve, SPR / SPR-C recovery, ZZ estimate — giving
!> one report row per level (SCENE.md, "Report") and, on request, the fields
!> of the level in an HDF5 file.
!>
!> This version analyses scenes with one body and no contact; other scenes
!> are refused with stat_unsupported before any computation.
module sprc_io_run
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_unsupported, stat_internal, stat_invalid_input
   use sprc_core_timer, only: timer_type, wall_time
   use sprc_core_material, only: voigt_size
   use sprc_geometry_body, only: body_type
   use sprc_geometry_region, only: cell_cut
   use sprc_exact_solution, only: exact_solution_type
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, default_points
   use sprc_grid_patches, only: recovery_input_type, recover_grid
   use sprc_grid_recovered_field, only: recovered_field_type, method_spr, method_sprc
   use sprc_grid_recovered_estimate, only: zz_estimate_type, estimate_error
   use sprc_fem_bc, only: fe_bc_type, new_fe_bc, bc_kind_from_name
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_fem_dilatation, only: dilatation_choice
   use sprc_fem_recovery_input, only: fe_recovery_input
   use sprc_io_scene, only: scene_type, recovery_degree
   use sprc_io_model, only: build_bodies, build_exact, analysis_kind, analysis_units_type, analysis_units, in_units
   use sprc_io_budget, only: check_level_memory
   use sprc_io_report, only: report_row_type
   use sprc_io_hdf5, only: h5_output_type
   use sprc_io_xdmf, only: cell_quad4, cell_quad9, cell_hex8, cell_hex27
   implicit none
   private

   public :: run_model_type, prepare_run, run_level

   !> What a study needs across its levels, built once from the scene.
   type :: run_model_type
      !> Index of the analysed body in `scene%bodies`.
      integer :: b = 0
      type(body_type) :: body
      class(exact_solution_type), allocatable :: exact
      type(fe_bc_type), allocatable :: bcs(:)
      integer :: analysis = 0
      !> Gauss points per direction of the cut-cell rules.
      integer :: points = 0
      logical :: run_spr = .false., run_sprc = .false.
      !> The analysis runs in these units (sprc_io_model): the scaled modulus and body force.
      type(analysis_units_type) :: units
      real(wp) :: young = 0.0_wp
      real(wp), allocatable :: body_force(:)
      !> Nitsche penalty factor (the scene's `nitsche_gamma`; a study may change it).
      real(wp) :: gamma = 0.0_wp
   end type run_model_type

contains

   !> Check that this version can run the scene and build what every level
   !> shares. `points` = 0 takes the default for the scene's FE order.
   subroutine prepare_run(scene, points, model, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: points
      type(run_model_type), intent(out) :: model
      type(error_type), allocatable, intent(out) :: error
      type(body_type), allocatable :: bodies(:)
      type(scene_type) :: scaled

      if (size(scene%contacts) > 0) then
         call fatal_error(error, 'sprc run: &contact is not implemented in this version', stat_unsupported)
         return
      end if
      if (size(scene%bodies) /= 1) then
         call fatal_error(error, 'sprc run: this version analyses scenes with exactly one &body', stat_unsupported)
         return
      end if
      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      model%b = 1
      model%body = bodies(model%b)
      call analysis_units(scene, model%units, error)
      if (allocated(error)) return
      scaled = in_units(scene, model%units)
      model%young = scaled%bodies(model%b)%young
      model%body_force = scaled%bodies(model%b)%body_force
      call build_exact(scaled, model%b, model%exact, error)
      if (allocated(error)) return
      call fe_conditions(scaled, model%b, model%bcs)
      model%analysis = analysis_kind(scene)
      model%points = points
      if (points == 0) model%points = default_points(scene%order)
      model%run_spr = scene%recovery == 'spr' .or. scene%recovery == 'both'
      model%run_sprc = scene%recovery == 'sprc' .or. scene%recovery == 'both'
      model%gamma = scene%nitsche_gamma
   end subroutine prepare_run

   !> The &bc groups on the surfaces of body `b` as FE conditions on the
   !> body's own shape indices (its shapes in file order); surfaces without
   !> &bc are free.
   subroutine fe_conditions(scene, b, bcs)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: b
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      integer :: i, kind, n

      allocate (bcs(count(scene%shapes(scene%bcs%shape_index)%body_index == b)))
      n = 0
      do i = 1, size(scene%bcs)
         associate (bc => scene%bcs(i), shape => scene%shapes(scene%bcs(i)%shape_index))
            if (shape%body_index /= b) cycle
            n = n + 1
            kind = bc_kind_from_name(bc%type)
            if (allocated(bc%vector)) then
               bcs(n) = new_fe_bc(shape%body_shape, kind, bc%value, bc%vector)
            else
               bcs(n) = new_fe_bc(shape%body_shape, kind, bc%value)
            end if
         end associate
      end do
   end subroutine fe_conditions

   !> One level of the study: the report row and, if `h5` is open, the fields;
   !> `rcond`: the solver's reciprocal condition estimate of the stiffness.
   subroutine run_level(scene, model, level, row, error, h5, rcond)
      type(scene_type), intent(in) :: scene
      type(run_model_type), intent(in) :: model
      integer, intent(in) :: level
      type(report_row_type), intent(out) :: row
      type(error_type), allocatable, intent(out) :: error
      type(h5_output_type), intent(inout), optional :: h5
      real(wp), intent(out), optional :: rcond
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hanging
      type(cut_quadrature_type) :: quad
      type(elasticity_problem_type) :: problem
      type(recovery_input_type) :: input
      type(recovered_field_type) :: field(2)
      type(zz_estimate_type) :: est(2)
      type(timer_type) :: t_mesh
      real(wp), allocatable :: element_error(:)
      real(wp) :: t_start, norm_fe, norm_exact, err_fe
      logical :: done(2)
      integer :: m

      call check_level_memory(scene, model%body, level, error)
      if (allocated(error)) return
      t_start = wall_time()
      call t_mesh%start()
      call grid%build(model%body, scene%dim, scene%box_min, scene%box_size, level, scene%refine_boundary, error)
      if (.not. allocated(error)) call nodes%build(grid, scene%order, error)
      if (.not. allocated(error)) call hanging%build(grid, nodes, error)
      call t_mesh%stop()
      if (allocated(error)) return
      if ((model%run_spr .or. model%run_sprc) .and. sum(grid%n_inside) + sum(grid%n_cut) < 2) then
         call fatal_error(error, 'one cell holds the whole body at this level, so every recovery patch is that '// &
            & 'one element: the recovered stress is the FE stress and the estimate (eta = 0) says nothing; '// &
            & 'use a higher level (or a smaller box_size)', stat_invalid_input)
         return
      end if
      call new_cut_quadrature(quad, scene%dim, model%points, error)
      if (allocated(error)) return
      associate (mat => scene%bodies(model%b))
         if (allocated(model%exact)) then
            call problem%setup(model%body, grid, nodes, hanging, quad, model%analysis, model%young, mat%poisson, &
               model%body_force, model%bcs, error, exact=model%exact, gamma=model%gamma, &
               & dilatation=dilatation_choice(scene%dilatation))
         else
            call problem%setup(model%body, grid, nodes, hanging, quad, model%analysis, model%young, mat%poisson, &
               model%body_force, model%bcs, error, gamma=model%gamma, dilatation=dilatation_choice(scene%dilatation))
         end if
      end associate
      if (allocated(error)) return
      call problem%solve(error)
      if (allocated(error)) return
      if (present(rcond)) rcond = problem%rcond

      row%level = level
      row%h = scene%box_size/real(2**level, wp)
      row%elements = int(grid%n_leaves, i8)
      row%cut_elements = sum(grid%n_cut)
      row%dofs = int(problem%n_dofs(), i8)
      row%t_mesh = t_mesh%elapsed
      row%t_quadrature = problem%t_quadrature
      row%t_assembly = problem%t_assembly
      row%t_solve = problem%t_solve
      if (allocated(model%exact)) then
         call problem%energy_error(err_fe, element_error, norm_fe, norm_exact, error)
         if (allocated(error)) return
         row%err_fe = err_fe
      end if

      done = [model%run_spr, model%run_sprc]
      if (any(done)) then
         call fe_recovery_input(problem, input, error)
         if (allocated(error)) return
         row%t_recovery = 0.0_wp
         row%t_estimate = 0.0_wp
      end if
      do m = 1, 2
         if (.not. done(m)) cycle
         call recover_and_estimate(model, input, grid, nodes, hanging, m, recovery_degree(scene, m), field(m), est(m), &
            & error)
         if (allocated(error)) return
         row%t_recovery = row%t_recovery + field(m)%t_recovery
         row%t_estimate = row%t_estimate + est(m)%t_estimate
         call fill_method_columns(row, m, est(m), allocated(model%exact))
      end do
      row%t_total = wall_time() - t_start
      call check_row(row, allocated(model%exact), done, error)
      if (allocated(error)) return
      if (present(h5)) then
         if (h5%opened()) call write_fields(h5, level, scene, model%units, grid, nodes, problem, field, est, done, &
            & error)
      end if
   end subroutine run_level

   !> Recovery and estimate with one method (1 SPR, 2 SPR-C) at the patch degree `degree`.
   subroutine recover_and_estimate(model, input, grid, nodes, hanging, m, degree, field, est, error)
      type(run_model_type), intent(in) :: model
      type(recovery_input_type), intent(in) :: input
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      integer, intent(in) :: m, degree
      type(recovered_field_type), intent(out) :: field
      type(zz_estimate_type), intent(out) :: est
      type(error_type), allocatable, intent(out) :: error
      integer :: method

      method = merge(method_spr, method_sprc, m == 1)
      if (allocated(model%exact)) then
         call recover_grid(input, grid, nodes, hanging, method, degree, field, error, exact=model%exact)
         if (allocated(error)) return
         call estimate_error(input, field, est, error, exact=model%exact)
      else
         call recover_grid(input, grid, nodes, hanging, method, degree, field, error)
         if (allocated(error)) return
         call estimate_error(input, field, est, error)
      end if
   end subroutine recover_and_estimate

   subroutine fill_method_columns(row, m, est, have_exact)
      type(report_row_type), intent(inout) :: row
      integer, intent(in) :: m
      type(zz_estimate_type), intent(in) :: est
      logical, intent(in) :: have_exact

      if (m == 1) then
         row%eta_spr = est%eta
         if (have_exact) row%err_spr = est%rel_err_star
         if (have_exact) row%theta_spr = est%theta
      else
         row%eta_sprc = est%eta
         if (have_exact) row%err_sprc = est%rel_err_star
         if (have_exact) row%theta_sprc = est%theta
      end if
   end subroutine fill_method_columns

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

   !> The level's mesh and fields: displacement, FE nodal stresses (average of
   !> the elements at each node), recovered nodal stresses, element error
   !> indicators (ZZ per method; exact where known) and cell class. The analysis ran in
   !> `units`: the fields are written in the scene's units.
   subroutine write_fields(h5, level, scene, units, grid, nodes, problem, field, est, done, error)
      type(h5_output_type), intent(inout) :: h5
      integer, intent(in) :: level
      type(scene_type), intent(in) :: scene
      type(analysis_units_type), intent(in) :: units
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(elasticity_problem_type), intent(in) :: problem
      type(recovered_field_type), intent(in) :: field(2)
      type(zz_estimate_type), intent(in) :: est(2)
      logical, intent(in) :: done(2)
      type(error_type), allocatable, intent(out) :: error
      character(len=2), parameter :: c2(3) = ['xx', 'yy', 'xy'], c3(6) = ['xx', 'yy', 'zz', 'xy', 'yz', 'xz']
      character(len=4), parameter :: method_name(2) = ['spr ', 'sprc']
      real(wp), allocatable :: sigma_fe(:, :), elem(:, :), element_error(:)
      real(wp) :: err_fe, norm_fe, norm_exact, sunit, eunit
      integer, allocatable :: cls(:, :)
      integer :: cell_type, m

      if (scene%dim == 2) then
         cell_type = merge(cell_quad4, cell_quad9, scene%order == 1)
      else
         cell_type = merge(cell_hex8, cell_hex27, scene%order == 1)
      end if
      call h5%write_level(level, nodes%x, nodes%connectivity, cell_type, error)
      if (allocated(error)) return
      ! stress unit modulus*strain; energy norm sqrt(sigma D^-1 sigma): sqrt(modulus)*strain
      sunit = units%modulus*units%strain
      eunit = sqrt(units%modulus)*units%strain
      call h5%write_node_field(level, 'displacement', units%strain*problem%u, error)
      if (allocated(error)) return
      call nodal_fe_stress(problem, nodes, sigma_fe)
      call write_stress(h5, level, 'sigma_fe', sunit*sigma_fe, error)
      if (allocated(error)) return
      do m = 1, 2
         if (.not. done(m)) cycle
         call write_stress(h5, level, 'sigma_'//trim(method_name(m)), sunit*field(m)%nodal, error)
         if (allocated(error)) return
         elem = reshape(eunit*sqrt(est(m)%elem_err2), [1, size(est(m)%elem_err2)])
         call h5%write_cell_field(level, 'zz_error_'//trim(method_name(m)), elem, error)
         if (allocated(error)) return
      end do
      if (problem%solved .and. allocated(problem%exact)) then
         call problem%energy_error(err_fe, element_error, norm_fe, norm_exact, error)
         if (allocated(error)) return
         elem = reshape(eunit*element_error, [1, size(element_error)])
         call h5%write_cell_field(level, 'exact_error_fe', elem, error)
         if (allocated(error)) return
      end if
      allocate (cls(1, grid%n_leaves))
      cls(1, :) = merge(1, 0, grid%leaf_class(1:grid%n_leaves) == cell_cut)
      call h5%write_cell_field(level, 'cut', cls, error)
   contains
      subroutine write_stress(h5, level, name, values, error)
         type(h5_output_type), intent(inout) :: h5
         integer, intent(in) :: level
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: values(:, :)
         type(error_type), allocatable, intent(out) :: error
         if (size(values, 1) == 3) then
            call h5%write_node_field(level, name, values, error, components=c2)
         else
            call h5%write_node_field(level, name, values, error, components=c3)
         end if
      end subroutine write_stress
   end subroutine write_fields

   !> FE stress at each node: the average over the elements that hold it
   !> (the FE stress is discontinuous; this is only for viewing).
   subroutine nodal_fe_stress(problem, nodes, sigma)
      type(elasticity_problem_type), intent(in) :: problem
      type(grid_nodes_type), intent(in) :: nodes
      real(wp), allocatable, intent(out) :: sigma(:, :)
      real(wp) :: s(6)
      integer :: n, k, e, ns, count

      ns = problem%nstress
      allocate (sigma(ns, nodes%n_nodes))
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

end module sprc_io_run
