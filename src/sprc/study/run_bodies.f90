!> One body at a level (`sprc_study_level`): its cut mesh, FE solve, error
!> against the exact solution, recoveries and estimates; a body in contact
!> is only meshed and assembled here (`sprc_study_run_contact` solves it).
module sprc_study_run_bodies
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_quadrature, only: cut_quadrature_type
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_estimate_patches, only: recovery_input_type
   use sprc_fem_bc, only: fe_bc_type
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_estimate_fe_input, only: fe_recovery_input
   use sprc_study_model, only: body_conditions, in_units
   use sprc_study_budget, only: check_level_memory
   use sprc_study_partition, only: partition_type, integrate_level, solve_level
   use sprc_study_level_types, only: study_body_type, mesh_source_type, study_type, body_level_type
   use sprc_study_run_estimate, only: recover_body, level_share
   implicit none
   private

   public :: run_body, exact_error, stage_load, nodal_fe_stress

contains

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

end module sprc_study_run_bodies
