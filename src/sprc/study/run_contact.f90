!> The contact components of a level (`sprc_study_level`): one pair
!> (`run_contact`, sprc_contact_pair_solve's `solve_contact_pair`) or
!> several pairs solved together (`run_assembly`), each pair's contact result
!> in scene units, the traction jump between its bodies, and the memory check
!> of the bodies solved together (`check_pairs_memory`).
module sprc_study_run_contact
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_timer, only: timer_type
   use sprc_core_alloc, only: check_allocation
   use sprc_estimate_patches, only: recovery_input_type
   use sprc_estimate_recovered_field, only: field_eval
   use sprc_recovery_contact_operators, only: contact_traction
   use sprc_estimate_contact_patches, only: grid_contact_type
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_estimate_fe_input, only: fe_recovery_input
   use sprc_study_spec, only: contact_spec_type
   use sprc_study_model, only: scene_surface
   use sprc_study_budget, only: check_coupled_memory, level_cells
   use sprc_study_partition, only: partition_type, assemble_pair_rows
   use sprc_grid_share, only: share_type
   use sprc_contact_result, only: contact_result_type, contact_open
   use sprc_contact_surface, only: contact_surface_type, slave_surface_points, initial_gaps
   use sprc_contact_pair_solve, only: contact_solution_type, solve_contact_pair, friction_kind, friction_coulomb, &
      & contact_progress, contact_body_type, contact_pair_type, solve_contact_assembly, multiplier_kind, &
      & pair_iterative
   use sprc_study_level_types, only: mesh_source_type, study_type, body_level_type
   use sprc_study_run_estimate, only: recover_body
   use sprc_study_run_bodies, only: exact_error, stage_load
   use sprc_study_run_contact_recovery, only: stabilize_recovered, finish_pair, pair_contact, &
      & recovered_tractions, contact_result, pair_edges_type, pair_edges
   implicit none
   private

   public :: check_pairs_memory, in_contact, run_contact, run_assembly

contains

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
      type(pair_edges_type), allocatable :: edges(:)
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
      ! each pair's contact edges once, for both of its sides
      allocate (edges(size(ks)))
      do p = 1, size(ks)
         call pair_edges(study, study%scene%contacts(ks(p)), pairs(p)%surface, results(ks(p)), &
            & bodies(members(pairs(p)%slave))%problem%mesh%nodes, inputs(pairs(p)%slave), inputs(pairs(p)%master), &
            & edges(p), error)
         if (allocated(error)) return
      end do
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
               & bodies(b)%problem%mesh%nodes, inputs(other), contacts(n), error, &
               & bodies(members(other))%problem%mesh%nodes, edges(p))
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

end module sprc_study_run_contact
