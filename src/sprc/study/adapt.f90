!> Error-driven h-adaptivity (`&adapt`, SCENE.md): a study whose steps are
!> adapted meshes instead of uniform levels.
!>
!> ```fortran
!> call start_adapt(study, start_level, run)
!> do while (.not. run%finished)
!>    call adapt_step(study, run, result, error)   ! result%row: one report row per step
!> end do
!> if (run%reason /= 'target') print *, adapt_warning(study, run)
!> ```
!> Step 0 is the uniform start level (with `refine_boundary`). After each
!> step the estimate that drives the run (SPR-C where it runs, else SPR:
!> `driving_method`) gives eta = sqrt(sum err^2 / sum (||sigma_h||^2 +
!> err^2)) over all bodies, their squared norms taken to the first body's
!> units as the report's sums are (`norm2_scale`): exactly the row's
!> eta_sprc (eta_spr). eta <= target ends the run (success). Otherwise the
!> element indicators of all bodies, concatenated in body order (element e
!> of a body is leaf e of its grid, aggregated small cuts included: the
!> aggregation ties dofs, not cells), give a wanted level per leaf
!> (sprc_grid_adapt: 'optimal' or 'fraction'), and each body's next mesh is
!> built from its own leaves' wanted levels (both bodies of a contact pair
!> independently). Before it is built, its dofs are predicted (each leaf
!> becomes 2^(d (wanted - level)) cells, at the body's present dofs per
!> cell); a prediction over `max_dofs`, or over the memory budget
!> (sprc_study_budget, on any rank), ends the run before the step; so do
!> `max_steps` analyses, and a size field that asks for the mesh already
!> there (`max_level` when cells wanted to be finer than it). A run ended
!> by a limit is not an error: `reason` names the limit, `best_eta` the best
!> estimate; the warning also counts the cells `max_level` held back.
!>
!> The iterative solver's start: every step starts from the previous step's
!> displacement evaluated at the new nodes (sprc_fem_nested's `values_at`,
!> which works on any two grids of the body: where the new mesh coarsened,
!> or a node lies outside every old element, the value is an interpolation
!> or 0, only a worse start). Under MPI every rank holds every element's
!> indicator (sprc_grid_share), so every rank builds the same meshes; the
!> memory decision is the ranks' common one.
module sprc_study_adapt
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_out_of_memory, stat_internal
   use sprc_core_timer, only: wall_time
   use sprc_core_text, only: itoa, real_text
   use sprc_grid_adapt, only: optimal_levels, fraction_levels
   use sprc_grid_tree, only: grid_type, grid_max_level
   use sprc_study_level, only: study_type, level_type, run_level, hold_starts, mesh_source_type, finest_cells
   use sprc_study_budget, only: check_level_memory
   use sprc_study_partition, only: largest_over_ranks
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_contact_pair_solve, only: contact_progress
   implicit none
   private

   public :: adapt_run_type, start_adapt, adapt_step, adapt_warning, driving_method, step_eta

   !> Why an adaptive run ended (`adapt_run_type%reason`).
   character(len=*), parameter, public :: reason_target = 'target', reason_max_steps = 'max_steps', &
      & reason_max_dofs = 'max_dofs', reason_max_level = 'max_level', reason_memory = 'memory budget', &
      & reason_unchanged = 'unchanged mesh'

   !> The state of an adaptive run between its steps.
   type :: adapt_run_type
      !> The start level (step 0, uniform) and the last step done (-1 before the first).
      integer :: start_level = 0, step = -1
      logical :: finished = .false.
      !> '' while the run goes on; then `reason_target` or the limit that ended it.
      character(len=:), allocatable :: reason
      !> A sentence on the limit (the memory estimate's message for `reason_memory`).
      character(len=:), allocatable :: detail
      !> The smallest driving eta so far and its step.
      real(wp) :: best_eta = huge(1.0_wp)
      integer :: best_step = -1
      !> Per body, what its next mesh is built from; the dofs predicted for it (all bodies).
      type(mesh_source_type), allocatable :: next(:)
      real(wp) :: next_dofs = 0.0_wp
      !> Per body, its last displacement (the next iterative solve's start).
      type(fe_displacement_type), allocatable :: starts(:)
      !> Seconds of the size field of the next step.
      real(wp) :: t_adapt = 0.0_wp
      !> Cells of the last size field that wanted to be finer than `max_level`.
      integer :: capped = 0
   end type adapt_run_type

contains

   !> A new run of `study` (a scene with `&adapt`) from the uniform `start_level`.
   subroutine start_adapt(study, start_level, run)
      type(study_type), intent(in) :: study
      integer, intent(in) :: start_level
      type(adapt_run_type), intent(out) :: run
      run%start_level = start_level
      run%reason = ''
      run%detail = ''
      if (.not. study%scene%adapt%present) run%finished = .true.
   end subroutine start_adapt

   !> 2 (SPR-C) where the study runs it, else 1 (SPR): the estimate that drives the run.
   pure integer function driving_method(study)
      type(study_type), intent(in) :: study
      driving_method = merge(2, 1, study%run(2))
   end function driving_method

   !> The driving eta of a step's row.
   pure real(wp) function step_eta(study, result)
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      step_eta = merge(result%row%eta_sprc, result%row%eta_spr, study%run(2))
   end function step_eta

   !> The next step of `run`: analysis, report row (`step`, `t_adapt` inside
   !> `t_total`, `level` the finest present, `h` the smallest cell), then the
   !> decision to stop or the next meshes.
   subroutine adapt_step(study, run, result, error, progress)
      type(study_type), intent(in) :: study
      type(adapt_run_type), intent(inout) :: run
      type(level_type), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      procedure(contact_progress), optional :: progress
      real(wp) :: eta, t0

      if (run%finished) then
         call fatal_error(error, 'adaptive run: a step after the run ended ('//run%reason//')', stat_internal)
         return
      end if
      run%step = run%step + 1
      if (run%step == 0) then
         call run_level(study, run%start_level, result, error, progress, start=run%starts)
      else
         call run_level(study, run%start_level, result, error, progress, start=run%starts, source=run%next)
      end if
      if (allocated(error)) then
         error%message = 'step '//itoa(run%step)//': '//error%message
         return
      end if
      call finest_cells(study, result)
      result%row%step = run%step
      result%row%t_adapt = run%t_adapt
      result%row%t_total = result%row%t_total + run%t_adapt
      call hold_starts(result, run%starts, error)
      if (allocated(error)) return
      eta = step_eta(study, result)
      if (eta < run%best_eta) then
         run%best_eta = eta
         run%best_step = run%step
      end if
      associate (a => study%scene%adapt)
         if (eta <= a%target) then
            call finish(run, reason_target, '')
         else if (run%step + 1 >= a%max_steps) then
            call finish(run, reason_max_steps, 'max_steps = '//itoa(a%max_steps)//' analyses')
         else
            t0 = wall_time()
            call next_meshes(study, run, result, error)
            run%t_adapt = wall_time() - t0
         end if
      end associate
   end subroutine adapt_step

   subroutine finish(run, reason, detail)
      type(adapt_run_type), intent(inout) :: run
      character(len=*), intent(in) :: reason, detail
      run%finished = .true.
      run%reason = reason
      run%detail = detail
   end subroutine finish

   !> The wanted level of every leaf of every body from the driving estimate,
   !> then each body's source of its next mesh, unless a limit ends the run.
   subroutine next_meshes(study, run, result, error)
      type(study_type), intent(in) :: study
      type(adapt_run_type), intent(inout) :: run
      type(level_type), intent(in) :: result
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: leaf_level(:), levels(:), free(:)
      real(wp), allocatable :: err_sq(:), dofs(:)
      real(wp) :: norm_sq, out_of_memory
      integer :: b, m, n, k, nb
      character(len=:), allocatable :: memory_message

      m = driving_method(study)
      nb = size(result%bodies)
      n = 0
      do b = 1, nb
         n = n + result%bodies(b)%problem%mesh%grid%n_leaves
      end do
      allocate (leaf_level(n), err_sq(n), dofs(nb))
      norm_sq = 0.0_wp
      k = 0
      do b = 1, nb
         associate (bl => result%bodies(b), grid => result%bodies(b)%problem%mesh%grid)
            leaf_level(k + 1:k + grid%n_leaves) = grid%leaf_level(1:grid%n_leaves)
            err_sq(k + 1:k + grid%n_leaves) = bl%norm2_scale*bl%est(m)%elem_err2(1:grid%n_leaves)
            norm_sq = norm_sq + bl%norm2_scale*(bl%est(m)%norm_h**2 + bl%est(m)%err**2)
            k = k + grid%n_leaves
         end associate
      end do
      associate (a => study%scene%adapt)
         call wanted_levels(study, leaf_level, err_sq, norm_sq, a%max_level, levels, error)
         ! The cells that max_level holds back: the levels wanted without it.
         run%capped = 0
         if (.not. allocated(error) .and. a%max_level < grid_max_level) then
            call wanted_levels(study, leaf_level, err_sq, norm_sq, grid_max_level, free, error)
            if (.not. allocated(error)) run%capped = count(free > a%max_level)
         end if
         if (allocated(error)) return
         if (same_meshes(study, result, levels, a%max_level, error)) then
            if (run%capped > 0) then
               call finish(run, reason_max_level, 'max_level = '//itoa(a%max_level)//': the cells the estimate '// &
                  & 'would refine stand at it')
            else
               call finish(run, reason_unchanged, 'the size field asks for the mesh of this step again')
            end if
            return
         end if
         ! Predicted dofs: each leaf becomes 2^(d (wanted - level)) cells, at the body's dofs per cell.
         k = 0
         do b = 1, nb
            associate (grid => result%bodies(b)%problem%mesh%grid)
               dofs(b) = real(result%bodies(b)%problem%n_dofs(), wp)/real(grid%n_leaves, wp)* &
                  & sum(2.0_wp**(study%dim*(levels(k + 1:k + grid%n_leaves) - leaf_level(k + 1:k + grid%n_leaves))))
               k = k + grid%n_leaves
            end associate
         end do
         if (a%max_dofs > 0 .and. sum(dofs) > real(a%max_dofs, wp)) then
            call finish(run, reason_max_dofs, 'max_dofs = '//itoa(a%max_dofs)//': the next mesh would have about '// &
               & itoa(nint(sum(dofs), i8))//' dofs')
            return
         end if
      end associate
      memory_message = ''
      do b = 1, nb
         call check_level_memory(study%scene, study%bodies(b)%geometry, run%start_level, error, known_dofs=dofs(b))
         if (allocated(error)) then
            if (error%stat /= stat_out_of_memory) return
            memory_message = "body '"//study%bodies(b)%name//"': the next mesh "//error%message
            ! the estimate's advice is for a uniform level
            if (index(memory_message, '; use a lower level') > 0) &
               & memory_message = memory_message(1:index(memory_message, '; use a lower level') - 1)
            deallocate (error)
            exit
         end if
      end do
      ! Every rank stops if one would run out of memory (the ranks' meshes stay the same).
      call largest_over_ranks(study%partition, merge(1.0_wp, 0.0_wp, len(memory_message) > 0), out_of_memory, error)
      if (allocated(error)) return
      if (out_of_memory > 0.0_wp) then
         if (len(memory_message) == 0) memory_message = 'another rank''s memory budget'
         call finish(run, reason_memory, memory_message)
         return
      end if
      if (allocated(run%next)) deallocate (run%next)
      allocate (run%next(nb))
      k = 0
      do b = 1, nb
         associate (grid => result%bodies(b)%problem%mesh%grid, next => run%next(b))
            call grid%copy(next%old, error)
            if (allocated(error)) return
            next%levels = levels(k + 1:k + grid%n_leaves)
            next%max_level = study%scene%adapt%max_level
            next%dofs = dofs(b)
            k = k + grid%n_leaves
         end associate
      end do
      run%next_dofs = sum(dofs)
   end subroutine next_meshes

   !> Whether the wanted `levels` (all bodies' leaves, concatenated) give every
   !> body its present grid again. Comparing the levels is not enough: a cell
   !> coarsens only when all its siblings want it, and the 2:1 balance can undo
   !> a coarsening, so wanted levels that differ from the present ones can still
   !> build the same grid (the run would then repeat one mesh until max_steps).
   !> The grids are built here to compare them; it is the grid alone, a small
   !> share of a step.
   logical function same_meshes(study, result, levels, max_level, error) result(same)
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      integer, intent(in) :: levels(:), max_level
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: trial
      integer :: b, k

      same = all(levels == [(result%bodies(b)%problem%mesh%grid%leaf_level( &
         & 1:result%bodies(b)%problem%mesh%grid%n_leaves), b = 1, size(result%bodies))])
      if (same) return
      same = .true.
      k = 0
      do b = 1, size(result%bodies)
         associate (old => result%bodies(b)%problem%mesh%grid)
            call trial%build_adapted(study%bodies(b)%geometry, old, levels(k + 1:k + old%n_leaves), max_level, &
               & error)
            if (allocated(error)) return
            same = trial%n_leaves == old%n_leaves
            if (same) same = all(trial%leaf_key(1:trial%n_leaves) == old%leaf_key(1:old%n_leaves)) .and. &
               & all(trial%leaf_level(1:trial%n_leaves) == old%leaf_level(1:old%n_leaves))
            k = k + old%n_leaves
         end associate
         if (.not. same) return
      end do
   end function same_meshes

   !> The level wanted per leaf by the scene's strategy, at most `max_level`.
   subroutine wanted_levels(study, leaf_level, err_sq, norm_sq, max_level, levels, error)
      type(study_type), intent(in) :: study
      integer, intent(in) :: leaf_level(:), max_level
      real(wp), intent(in) :: err_sq(:), norm_sq
      integer, allocatable, intent(out) :: levels(:)
      type(error_type), allocatable, intent(out) :: error
      associate (a => study%scene%adapt)
         if (a%strategy == 'fraction') then
            call fraction_levels(leaf_level, err_sq, a%fraction, max_level, levels, error)
         else
            call optimal_levels(leaf_level, err_sq, norm_sq, a%target, study%order, study%dim, max_level, levels, &
               & error)
         end if
      end associate
   end subroutine wanted_levels

   !> The warning of a run that a limit ended (empty when it reached its target):
   !> the limit and the best eta, e.g. "adaptive run stopped by max_steps = 10
   !> analyses before eta_sprc <= 1e-3; best eta_sprc = 2.1e-3 at step 9 (the
   !> report's last row is the last step)".
   function adapt_warning(study, run) result(text)
      type(study_type), intent(in) :: study
      type(adapt_run_type), intent(in) :: run
      character(len=:), allocatable :: text
      character(len=:), allocatable :: eta
      character(len=16) :: best

      text = ''
      if (.not. run%finished .or. run%reason == reason_target) return
      eta = merge('eta_sprc', 'eta_spr ', study%run(2))
      eta = trim(eta)
      write (best, '(es10.3)') run%best_eta
      text = 'adaptive run stopped by '//run%reason//' ('//run%detail//') before '//eta//' <= '// &
         & real_text(study%scene%adapt%target)//'; best '//eta//' = '//trim(adjustl(best))//' at step '// &
         & itoa(run%best_step)//' (the last row of the report is step '//itoa(run%step)//')'
      if (run%capped > 0 .and. run%reason /= reason_max_level) text = text//'; '//itoa(run%capped)// &
         & ' cells wanted to be finer than max_level = '//itoa(study%scene%adapt%max_level)
   end function adapt_warning

end module sprc_study_adapt
