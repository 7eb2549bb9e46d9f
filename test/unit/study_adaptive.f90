!> Tests of the adaptive study (sprc_study_adapt, `&adapt`): convergence to a
!> target on the Kirsch plate (Q1, Q2) measured by the exact error, step 0 =
!> the uniform level bit for bit, a 3D run, a contact pair with both bodies
!> adapted, the limits that end a run, the same bits at 1 and 2 threads, and
!> the report's adaptive columns.
module sprc_test_adaptive
   !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_text, only: itoa
   use sprc_study_spec, only: scene_type
   use sprc_io_scene, only: read_scene_text
   use sprc_study_level, only: study_type, prepare_study, run_level, level_type
   use sprc_study_adapt, only: adapt_run_type, start_adapt, adapt_step, adapt_warning, reason_target, &
      & reason_max_dofs, reason_max_steps, reason_max_level
   use sprc_study_row, only: report_row_type
   use sprc_io_report, only: report_header, write_report_csv, read_report_csv, report_table
   use sprc_testsuite, only: unittest_type, new_unittest, check
   implicit none
   private

   public :: collect_adaptive

   character(len=*), parameter :: nl = new_line('a')

contains

   subroutine collect_adaptive(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('kirsch_q1_converges', test_kirsch_q1), &
         new_unittest('kirsch_q2_converges', test_kirsch_q2), &
         new_unittest('step0_is_uniform_level', test_step0), &
         new_unittest('fraction_converges', test_fraction), &
         new_unittest('max_dofs_stops', test_max_dofs), &
         new_unittest('max_steps_stops', test_max_steps), &
         new_unittest('max_level_stops', test_max_level), &
         new_unittest('sphere_3d_runs', test_sphere), &
         new_unittest('contact_adapts_both_bodies', test_contact), &
         new_unittest('same_bits_1_2_threads', test_threads), &
         new_unittest('report_columns', test_report_columns) &
         ]
   end subroutine collect_adaptive

   !> The Kirsch quarter plate (example/scenes/kirsch_plate.nml) of order
   !> `order` from `level`, with the `&adapt` group `adapt`.
   function kirsch_text(order, level, adapt) result(text)
      integer, intent(in) :: order, level
      character(len=*), intent(in) :: adapt
      character(len=:), allocatable :: text
      text = "&scene title='kirsch' analysis='plane_stress' order="//itoa(order)//" levels="//itoa(level)// &
         & " box_min=0,0 box_size=10 recovery='both' output='' /"//nl// &
         & "&body name='plate' young=1000 poisson=0.3 /"//nl// &
         & "&shape body='plate' op='add' kind='box' name='edges' lower=-10,-10 upper=10,10 /"//nl// &
         & "&shape body='plate' op='subtract' kind='disk' name='hole' center=0,0 radius=1 /"//nl// &
         & "&shape body='plate' op='intersect' kind='halfspace' name='sym_x' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='plate' op='intersect' kind='halfspace' name='sym_y' point=0,0 normal=0,-1 /"//nl// &
         & "&bc on='edges' type='exact_traction' /"//nl// &
         & "&bc on='sym_x' type='symmetry' /"//nl// &
         & "&bc on='sym_y' type='symmetry' /"//nl// &
         & "&exact kind='kirsch' center=0,0 radius=1 s_inf=1.0 /"//nl//adapt//nl
   end function kirsch_text

   !> Run the adaptive study of the scene `text` to its end: its rows and the run.
   subroutine run_adaptive(text, rows, run, error, results)
      character(len=*), intent(in) :: text
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(adapt_run_type), intent(out) :: run
      type(error_type), allocatable, intent(out) :: error
      !> Every step's result.
      type(level_type), allocatable, intent(out), optional :: results(:)
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result

      call read_scene_text(text, 'adaptive', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      allocate (rows(0))
      if (present(results)) allocate (results(0))
      call start_adapt(study, scene%levels(1), run)
      do while (.not. run%finished)
         call adapt_step(study, run, result, error)
         if (allocated(error)) return
         rows = [rows, result%row]
         if (present(results)) results = [results, result]
      end do
   end subroutine run_adaptive

   !> The run reached its target; err_fe fell at every step (eta too, after the first); the exact
   !> error at the end is within the target up to the effectivity theta_sprc
   !> of the last step (err_fe = eta / theta up to the difference between
   !> sigma* and the exact stress, which SPR-C makes of higher order).
   subroutine check_converged(rows, run, target, error)
      type(report_row_type), intent(in) :: rows(:)
      type(adapt_run_type), intent(in) :: run
      real(wp), intent(in) :: target
      type(error_type), allocatable, intent(out) :: error
      integer :: i, n

      n = size(rows)
      call check(error, run%reason == reason_target, 'reached the target, not: '//run%reason)
      if (allocated(error)) return
      call check(error, n >= 3, 'at least two adapted steps, got '//itoa(n - 1))
      if (allocated(error)) return
      ! eta from the second adapted step on: at a coarse start mesh the estimate is
      ! pre-asymptotic (Kirsch level 3: theta_sprc 0.46) and may rise once.
      do i = 2, n
         call check(error, rows(i)%err_fe < rows(i - 1)%err_fe .and. (i == 2 .or. &
            & rows(i)%eta_sprc < rows(i - 1)%eta_sprc), 'err_fe (and eta_sprc after step 1) fall at step '//itoa(i - 1))
         if (allocated(error)) return
         call check(error, rows(i)%step == i - 1 .and. rows(i)%t_adapt >= 0.0_wp .and. &
            & rows(i)%t_total >= rows(i)%t_adapt, 'step and t_adapt columns of step '//itoa(i - 1))
         if (allocated(error)) return
      end do
      call check(error, rows(n)%eta_sprc <= target, 'last eta <= target')
      if (allocated(error)) return
      call check(error, rows(n)%err_fe <= target/rows(n)%theta_sprc*1.1_wp, &
         & 'last err_fe within the target over theta_sprc')
   end subroutine check_converged

   subroutine test_kirsch_q1(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      call run_adaptive(kirsch_text(1, 3, '&adapt target=0.01 /'), rows, run, error)
      if (allocated(error)) return
      call check_converged(rows, run, 0.01_wp, error)
      if (allocated(error)) return
      ! The uniform study needs level 7 (about 33,000 dofs) for err_fe < 1 %
      ! (level 6: 8272 dofs, 1.22 %): local refinement needs a fraction of that.
      call check(error, rows(size(rows))%dofs < 8272, 'fewer dofs than uniform level 6: '// &
         & itoa(int(rows(size(rows))%dofs)))
   end subroutine test_kirsch_q1

   subroutine test_kirsch_q2(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      call run_adaptive(kirsch_text(2, 3, '&adapt target=0.002 /'), rows, run, error)
      if (allocated(error)) return
      call check_converged(rows, run, 0.002_wp, error)
   end subroutine test_kirsch_q2

   subroutine test_fraction(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      call run_adaptive(kirsch_text(1, 3, "&adapt target=0.03 strategy='fraction' fraction=0.6 /"), rows, run, &
         & error)
      if (allocated(error)) return
      call check_converged(rows, run, 0.03_wp, error)
   end subroutine test_fraction

   !> Step 0 is the uniform start level: its row is run_level's, bit for bit
   !> (every column but the times, and t_adapt = 0).
   subroutine test_step0(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: uniform

      call run_adaptive(kirsch_text(1, 4, '&adapt target=0.5 /'), rows, run, error)
      if (allocated(error)) return
      call check(error, size(rows) == 1 .and. run%reason == reason_target, 'eta <= 0.5 at the start: one step')
      if (allocated(error)) return
      call read_scene_text(kirsch_text(1, 4, ''), 'uniform', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      call run_level(study, 4, uniform, error)
      if (allocated(error)) return
      associate (a => rows(1), u => uniform%row)
         call check(error, a%level == u%level .and. a%dofs == u%dofs .and. a%elements == u%elements .and. &
            & a%h == u%h .and. a%err_fe == u%err_fe .and. a%eta_spr == u%eta_spr .and. a%eta_sprc == u%eta_sprc &
            & .and. a%theta_sprc == u%theta_sprc .and. a%step == 0 .and. a%t_adapt == 0.0_wp .and. u%step == -1, &
            & 'step 0 = uniform level 4')
      end associate
   end subroutine test_step0

   !> max_dofs: the run stops before a step predicted above it, with a
   !> warning naming the limit and the best eta.
   subroutine test_max_dofs(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      type(scene_type) :: scene
      type(study_type) :: study
      character(len=:), allocatable :: warning

      call run_adaptive(kirsch_text(1, 3, '&adapt target=0.001 max_dofs=1000 /'), rows, run, error)
      if (allocated(error)) return
      call check(error, run%reason == reason_max_dofs, 'stopped by max_dofs, not: '//run%reason)
      if (allocated(error)) return
      call check(error, all(rows%dofs <= 1000), 'no step above max_dofs')
      if (allocated(error)) return
      call read_scene_text(kirsch_text(1, 3, '&adapt target=0.001 max_dofs=1000 /'), 'adaptive', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      warning = adapt_warning(study, run)
      call check(error, index(warning, 'max_dofs') > 0 .and. index(warning, 'best eta_sprc') > 0, &
         & 'warning names the limit and the best eta: '//warning)
   end subroutine test_max_dofs

   subroutine test_max_steps(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      call run_adaptive(kirsch_text(1, 3, '&adapt target=0.001 max_steps=2 /'), rows, run, error)
      if (allocated(error)) return
      call check(error, run%reason == reason_max_steps .and. size(rows) == 2, &
         & 'two analyses, stopped by max_steps: '//run%reason)
      if (allocated(error)) return
      call check(error, run%best_eta == minval(rows%eta_sprc), 'best eta is the smallest')
   end subroutine test_max_steps

   !> max_level: once every cell the estimate would refine stands at it, the
   !> run stops (uniform level 4 everywhere, for a target far below its error).
   subroutine test_max_level(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      call run_adaptive(kirsch_text(1, 3, '&adapt target=0.001 max_level=4 /'), rows, run, error)
      if (allocated(error)) return
      call check(error, run%reason == reason_max_level .and. run%capped > 0 .and. all(rows%level <= 4), &
         & 'stopped by max_level with cells held back, not: '//run%reason)
   end subroutine test_max_level

   !> The Lame sphere octant (3D) from level 2: one adapted step refines
   !> where the estimate is, and the error falls.
   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(adapt_run_type) :: run
      character(len=:), allocatable :: text
      text = "&scene title='sphere' analysis='solid' order=1 levels=2 box_min=0,0,0 box_size=25 "// &
         & "recovery='both' output='' /"//nl// &
         & "&body name='sphere' young=1000 poisson=0.3 /"//nl// &
         & "&shape body='sphere' op='add' kind='sphere' name='outer' center=0,0,0 radius=20 /"//nl// &
         & "&shape body='sphere' op='subtract' kind='sphere' name='inner' center=0,0,0 radius=5 /"//nl// &
         & "&shape body='sphere' op='intersect' kind='halfspace' name='sym_x' point=0,0,0 normal=-1,0,0 /"//nl// &
         & "&shape body='sphere' op='intersect' kind='halfspace' name='sym_y' point=0,0,0 normal=0,-1,0 /"//nl// &
         & "&shape body='sphere' op='intersect' kind='halfspace' name='sym_z' point=0,0,0 normal=0,0,-1 /"//nl// &
         & "&bc on='inner' type='pressure' value=1.0 /"//nl// &
         & "&bc on='sym_x' type='symmetry' /"//nl//"&bc on='sym_y' type='symmetry' /"//nl// &
         & "&bc on='sym_z' type='symmetry' /"//nl// &
         & "&exact kind='lame_sphere' center=0,0,0 r_in=5 r_out=20 p_in=1.0 /"//nl// &
         & "&adapt target=0.01 max_steps=2 max_level=3 /"//nl
      call run_adaptive(text, rows, run, error)
      if (allocated(error)) return
      call check(error, size(rows) == 2 .and. rows(2)%level == 3, 'two steps, the second reaching max_level 3')
      if (allocated(error)) return
      call check(error, rows(2)%err_fe < rows(1)%err_fe .and. rows(2)%eta_sprc < rows(1)%eta_sprc, &
         & 'err_fe and eta fall')
   end subroutine test_sphere

   !> The shrink fit (a contact pair): both bodies' grids adapt, each from
   !> its own indicators, and the error falls.
   subroutine test_contact(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: rows(:)
      type(level_type), allocatable :: results(:)
      type(adapt_run_type) :: run
      character(len=:), allocatable :: text
      integer :: b

      text = "&scene title='shrink fit' analysis='plane_strain' order=1 levels=3 box_min=0,0 box_size=41 "// &
         & "recovery='both' output='' /"//nl// &
         & "&body name='shaft' young=210000 poisson=0.3 box_min=0,0 box_size=20.5 /"//nl// &
         & "&body name='hub' young=70000 poisson=0.33 /"//nl// &
         & "&shape body='shaft' op='add' kind='disk' name='shaft_out' center=0,0 radius=20.002 /"//nl// &
         & "&shape body='shaft' op='subtract' kind='disk' name='bore' center=0,0 radius=10 /"//nl// &
         & "&shape body='shaft' op='intersect' kind='halfspace' name='shaft_x' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='shaft' op='intersect' kind='halfspace' name='shaft_y' point=0,0 normal=0,-1 /"//nl// &
         & "&shape body='hub' op='add' kind='disk' name='hub_out' center=0,0 radius=40 /"//nl// &
         & "&shape body='hub' op='subtract' kind='disk' name='hub_in' center=0,0 radius=20 /"//nl// &
         & "&shape body='hub' op='intersect' kind='halfspace' name='hub_x' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='hub' op='intersect' kind='halfspace' name='hub_y' point=0,0 normal=0,-1 /"//nl// &
         & "&bc on='bore' type='pressure' value=10 /"//nl// &
         & "&bc on='shaft_x' type='symmetry' /"//nl//"&bc on='shaft_y' type='symmetry' /"//nl// &
         & "&bc on='hub_x' type='symmetry' /"//nl//"&bc on='hub_y' type='symmetry' /"//nl// &
         & "&contact slave='shaft' master='hub' slave_surface='shaft_out' master_surface='hub_in' "// &
         & "friction='frictionless' /"//nl// &
         & "&exact kind='compound_cylinder' center=0,0 r_in=10 r_contact=20 r_out=40 p_in=10.0 inner='shaft' "// &
         & "outer='hub' interference=0.002 /"//nl// &
         & "&adapt target=0.03 max_steps=2 /"//nl
      call run_adaptive(text, rows, run, error, results)
      if (allocated(error)) return
      call check(error, size(rows) == 2 .and. rows(2)%has_contact, 'two steps with contact')
      if (allocated(error)) return
      do b = 1, 2
         associate (grid => results(2)%bodies(b)%problem%mesh%grid)
            call check(error, grid%max_level > 3 .and. &
               & any(grid%leaf_level(1:grid%n_leaves) /= grid%leaf_level(1)), 'body '//itoa(b)//' adapted: levels '// &
               & itoa(minval(grid%leaf_level(1:grid%n_leaves)))//' to '//itoa(grid%max_level))
            if (allocated(error)) return
         end associate
      end do
      call check(error, rows(2)%eta_sprc < rows(1)%eta_sprc .and. rows(2)%err_fe < rows(1)%err_fe, &
         & 'eta and err_fe fall')
   end subroutine test_contact

   !> The same meshes and bits at 1 and 2 threads, every step.
   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: one(:), two(:)
      type(adapt_run_type) :: run
      integer :: threads, i

      threads = 1
      !$ threads = omp_get_max_threads()
      !$ call omp_set_num_threads(1)
      call run_adaptive(kirsch_text(2, 3, '&adapt target=0.003 /'), one, run, error)
      !$ call omp_set_num_threads(2)
      if (.not. allocated(error)) call run_adaptive(kirsch_text(2, 3, '&adapt target=0.003 /'), two, run, error)
      !$ call omp_set_num_threads(threads)
      if (allocated(error)) return
      call check(error, size(one) == size(two), 'same number of steps')
      if (allocated(error)) return
      do i = 1, size(one)
         call check(error, one(i)%dofs == two(i)%dofs .and. one(i)%elements == two(i)%elements .and. &
            & one(i)%err_fe == two(i)%err_fe .and. one(i)%eta_sprc == two(i)%eta_sprc .and. &
            & one(i)%eta_spr == two(i)%eta_spr, 'step '//itoa(i - 1)//' the same at 1 and 2 threads')
         if (allocated(error)) return
      end do
   end subroutine test_threads

   !> `step` and `t_adapt` only in an adaptive report; the CSV reads back.
   subroutine test_report_columns(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(2)
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = 'build/test_adaptive_report.csv'
      character(len=:), allocatable :: header

      rows%level = [3, 5]
      rows%dofs = [100, 400]
      rows%t_total = [0.5_wp, 1.5_wp]
      header = report_header(rows)
      call check(error, index(header, 'step') == 0 .and. index(report_table(rows), 't_adapt') == 0, &
         & 'a uniform report has no adaptive columns: '//header)
      if (allocated(error)) return
      rows%step = [0, 1]
      rows%t_adapt = [0.0_wp, 0.25_wp]
      header = report_header(rows)
      call check(error, header(len(header) - len(',solver_iterations,step,t_adapt') + 1:) == &
         & ',solver_iterations,step,t_adapt', 'adaptive columns last: '//header)
      if (allocated(error)) return
      call write_report_csv(path, rows, error)
      if (allocated(error)) return
      call read_report_csv(path, back, error)
      if (allocated(error)) return
      call check(error, all(back%step == rows%step) .and. all(back%t_adapt == rows%t_adapt), 'read back')
   end subroutine test_report_columns

end module sprc_test_adaptive
