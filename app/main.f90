!> The sprc driver: the only place that prints and sets exit codes
!> (0 success, 2 bad input, 1 numerical failure or a capability not yet available).
program sprc_main
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use, intrinsic :: iso_c_binding, only: c_int, c_char, c_null_char
   use omp_lib, only: omp_set_num_threads, omp_get_max_threads
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: fixed_text, itoa, byte_text
   use sprc_core_memory, only: peak_memory
   use sprc_core_error, only: error_type, stat_invalid_input, stat_io
   use sprc_version, only: sprc_version_string
   use sprc_io_scene, only: scene_type, read_scene, read_scene_text, scene_summary, default_scene_text
   use sprc_study_model, only: build_bodies, scene_warnings
   use sprc_study_threads, only: level_threads, study_dofs, serial_dofs
   use sprc_geometry_body, only: body_type
   use sprc_study_mesh_table, only: mesh_row_type, mesh_study, study_levels, check_surfaces
   use sprc_study_level, only: study_type, prepare_study, run_level, level_type, hold_starts
   use sprc_study_adapt, only: adapt_run_type, start_adapt, adapt_step, adapt_warning, step_eta
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_io_report, only: report_row_type, report_table, write_report_csv, format_mesh_row
   use sprc_io_fields, only: write_level_fields
   use sprc_io_svg, only: write_report_svg, write_contact_svg
   use sprc_io_contact_csv, only: contact_level_type, write_contact_csv
   use sprc_io_hdf5, only: h5_output_type
   use sprc_fem_petsc, only: start_ranks
   use sprc_study_partition, only: largest_over_ranks, fail_together
   use sprc_app_cli, only: cli_type, parse_cli, usage_text
   use sprc_app_progress, only: progress_level, progress_unit, print_contact_progress
   implicit none

   type(cli_type) :: cli
   character(len=:), allocatable :: message
   !> Output prefix of the run in progress: its files are written as
   !> PREFIX.EXT.partial and renamed when all are complete; `fail` removes them.
   character(len=:), allocatable :: partial_prefix
   !> The output files, in the order they are published; the last two only for a study with contact.
   character(len=*), parameter :: output_exts(6) = [character(len=12) :: '.csv', '.svg', '.h5', '.xdmf', &
      & '_contact.csv', '_contact.svg']
   character(len=*), parameter :: partial = '.partial'
   !> The level of the warm-up run (`warm_up`): cheap, but through every library the study calls.
   integer, parameter :: warm_level = 2
   !> The MPI ranks of this run (`mpirun -n R`; 1 without).
   integer :: world_ranks = 1
   !> How long a failed rank waits for the others to fail too (`fail`): a
   !> failure that all ranks know of brings them there within milliseconds.
   real(wp), parameter :: fail_wait = 10.0_wp

   interface
      !> C's rename(3) (stdio.h): replaces `new` atomically within a file system.
      integer(c_int) function c_rename(old, new) bind(C, name='rename')
         import :: c_int, c_char
         character(kind=c_char), intent(in) :: old(*), new(*)
      end function c_rename

      !> MPI_Abort of every rank (src/shim/sprc_mpi.c).
      subroutine sprc_mpi_abort(code) bind(C)
         import :: c_int
         integer(c_int), value :: code
      end subroutine sprc_mpi_abort
   end interface

   call parse_cli(cli, message)
   if (allocated(message)) call fail(2, message)

   select case (cli%command)
   case ('help')
      write (output_unit, '(a)') 'sprc '//sprc_version_string//': SPR / SPR-C stress recovery and ZZ error '// &
         'estimation for linear elasticity on cut Cartesian grids'
      write (output_unit, '(a)') usage_text()
   case ('version')
      write (output_unit, '(a)') 'sprc '//sprc_version_string
   case ('default')
      call run_default(cli)
   case ('check')
      call check_scene(cli%scene_path)
   case ('mesh')
      call mesh_scene(cli)
   case ('run')
      call run_scene_file(cli)
   end select

contains

   !> `sprc` with no arguments: the built-in default scene (Lame cylinder study).
   subroutine run_default(cli)
      type(cli_type), intent(in) :: cli
      type(scene_type) :: scene
      type(error_type), allocatable :: error

      call read_scene_text(default_scene_text(), '<built-in default scene>', scene, error)
      if (allocated(error)) call fail(1, 'built-in default scene: '//error%message)
      write (error_unit, '(a)') 'sprc: running the built-in default scene (example/scenes/lame_cylinder.nml); '// &
         'sprc --help lists the commands'
      call run_study(scene, cli)
   end subroutine run_default

   subroutine run_scene_file(cli)
      type(cli_type), intent(in) :: cli
      type(scene_type) :: scene
      type(error_type), allocatable :: error

      call read_scene(cli%scene_path, scene, error)
      if (allocated(error)) call fail(2, error%message)
      if (len(cli%solver) > 0) scene%solver = cli%solver
      call run_study(scene, cli)
   end subroutine run_scene_file

   !> One analysis per level; the report on standard output and, with an
   !> output prefix, PREFIX.csv, .svg, .h5 and .xdmf (and for a study with
   !> contact PREFIX_contact.csv and _contact.svg): written under temporary
   !> names and renamed when all are complete, so a run that fails leaves the
   !> results of an earlier run as they were.
   subroutine run_study(scene, cli)
      type(scene_type), intent(in) :: scene
      type(cli_type), intent(in) :: cli
      type(study_type) :: study
      type(level_type) :: result
      !> The previous level's displacements, where the iterative solves start.
      type(fe_displacement_type), allocatable :: starts(:)
      type(report_row_type), allocatable :: rows(:)
      type(contact_level_type), allocatable :: contact_levels(:)
      type(h5_output_type) :: h5
      type(error_type), allocatable :: error
      character(len=:), allocatable :: prefix, text
      integer, allocatable :: levels(:)
      integer :: i, threads, n_outputs, rank, ranks, n_contact
      character(len=16) :: buf
      real(wp) :: total_dofs
      logical :: quiet
      type(body_type), allocatable :: geometry(:)
      integer :: n_rows
      character(len=:), allocatable :: contact_title

      call study_levels(scene, cli%levels, levels, error)
      if (allocated(error)) call fail(2, error%message)
      ! Under mpirun every rank runs the study (the solves are distributed);
      ! rank 0 alone prints and writes the outputs.
      call start_ranks(rank, ranks, error)
      if (allocated(error)) call fail_with(error)
      world_ranks = ranks
      quiet = cli%quiet .or. rank > 0
      ! The thread count first: prepare_study takes OpenBLAS's buffer for each thread.
      if (cli%threads > 0) call omp_set_num_threads(cli%threads)
      call prepare_study(scene, cli%points, study, error)
      if (allocated(error)) call fail_with(error)
      ! A named copy: passing the strided component study%bodies%geometry made a hidden array temporary.
      geometry = study%bodies%geometry
      call check_surfaces(scene, geometry, minval(levels), cli%points, error)
      if (allocated(error)) call fail_with(error)
      if (rank == 0) call print_warnings(scene_warnings(scene, geometry))
      prefix = scene%output
      if (len(cli%output) > 0) prefix = cli%output
      if (rank > 0) prefix = ''
      if (len(prefix) > 0) then
         call make_parent_directory(prefix)
         partial_prefix = prefix
         call h5%create(prefix//'.h5'//partial, error)
         if (allocated(error)) call fail_with(error)
      end if
      n_contact = 0
      threads = omp_get_max_threads()
      if (scene%adapt%present) then
         call run_steps(study, levels(1), cli, quiet, rank, ranks, threads, h5, rows, n_rows, contact_levels, &
            & n_contact)
         rows = rows(:n_rows)
      else
         ! One slot per level: the levels' contact results move in, not copied (they are sized by the slave points).
         allocate (rows(size(levels)), contact_levels(size(levels)))
         do i = 1, size(levels)
            total_dofs = study_dofs(study, levels(i), error)
            if (.not. allocated(error)) call omp_set_num_threads(level_threads(study, levels(i), cli%threads, threads, &
               & error))
            if (allocated(error)) call fail_with(error)
            if (i == 1 .and. total_dofs < serial_dofs) call warm_up(study, min(levels(i), warm_level))
            if (.not. quiet) write (error_unit, '(a,i0,a,i0,a,i0,a)') 'sprc: level ', levels(i), &
               ' (', i, ' of ', size(levels), ')'
            if (cli%quiet) then
               call run_level(study, levels(i), result, error, start=starts)
            else
               progress_level = levels(i)
               call run_level(study, levels(i), result, error, progress=print_contact_progress, start=starts)
            end if
            if (.not. allocated(error)) call hold_starts(result, starts, error)
            if (.not. allocated(error)) then
               rows(i) = result%row
               if (h5%opened()) call write_level_fields(h5, study, result, error)
            end if
            if (.not. allocated(error) .and. rank == 0) call print_contact_warnings('level', levels(i), result)
            if (.not. allocated(error) .and. allocated(result%contacts)) then
               n_contact = n_contact + 1
               contact_levels(n_contact)%level = levels(i)
               call move_alloc(result%contacts, contact_levels(n_contact)%contacts)
            end if
            if (allocated(error)) then
               write (buf, '("level ",i0,":")') levels(i)
               error%message = trim(buf)//' '//error%message
               call fail_with(error)
            end if
            text = peak_text(study, ranks, error)
            if (allocated(error)) call fail_with(error)
            if (.not. quiet) write (error_unit, '(a,i0,a)') 'sprc: level ', levels(i), ' done in '// &
               fixed_text(rows(i)%t_total, 3)//' s'//text
         end do
         n_rows = size(levels)
      end if
      if (rank > 0) return
      write (output_unit, '(a)') scene%title
      write (output_unit, '(a)', advance='no') report_table(rows, wide=cli%wide)
      if (len(prefix) == 0) return
      call write_report_csv(prefix//'.csv'//partial, rows, error)
      if (.not. allocated(error)) call write_report_svg(prefix//'.svg'//partial, rows, scene%title, error, &
         & order=study%order, dim=study%dim)
      if (.not. allocated(error)) call h5%close(error)
      if (.not. allocated(error)) call h5%write_xdmf(prefix//'.xdmf'//partial, error, data_path=prefix//'.h5')
      n_outputs = 4
      if (n_contact > 0 .and. .not. allocated(error)) then
         n_outputs = 6
         call write_contact_csv(prefix//'_contact.csv'//partial, contact_levels(:n_contact), error)
         associate (finest => contact_levels(n_contact))
            contact_title = scene%title//', contact pressure at level '//itoa(finest%level)
            if (scene%adapt%present) contact_title = scene%title//', contact pressure at step '//itoa(finest%level)
            if (.not. allocated(error)) call write_contact_svg(prefix//'_contact.svg'//partial, finest%contacts, &
               & contact_title, error)
         end associate
      end if
      if (allocated(error)) call fail_with(error)
      do i = 1, n_outputs
         if (c_rename(prefix//trim(output_exts(i))//partial//c_null_char, &
            & prefix//trim(output_exts(i))//c_null_char) /= 0) &
            & call fail(2, 'cannot rename '//prefix//trim(output_exts(i))//partial//' to '// &
            & prefix//trim(output_exts(i)))
      end do
      deallocate (partial_prefix)
      if (quiet) return
      if (n_outputs == 6) then
         write (error_unit, '(a)') 'sprc: wrote '//prefix//'.csv, .svg, .h5, .xdmf, _contact.csv, _contact.svg'
      else
         write (error_unit, '(a)') 'sprc: wrote '//prefix//'.csv, .svg, .h5, .xdmf'
      end if
   end subroutine run_study

   !> The adaptive study (`&adapt`) from `start_level`: one row per step
   !> (sprc_study_adapt); progress names each step, its dofs and eta; a run
   !> that a limit ended warns, naming the limit and the best eta.
   subroutine run_steps(study, start_level, cli, quiet, rank, ranks, threads, h5, rows, n_rows, contact_levels, &
      & n_contact)
      type(study_type), intent(in) :: study
      integer, intent(in) :: start_level, rank, ranks, threads
      type(cli_type), intent(in) :: cli
      logical, intent(in) :: quiet
      type(h5_output_type), intent(inout) :: h5
      type(report_row_type), allocatable, intent(out) :: rows(:)
      integer, intent(out) :: n_rows
      type(contact_level_type), allocatable, intent(out) :: contact_levels(:)
      integer, intent(inout) :: n_contact
      type(adapt_run_type) :: run
      type(level_type) :: result
      type(error_type), allocatable :: error
      character(len=:), allocatable :: text, eta_name
      real(wp) :: total_dofs

      allocate (rows(study%scene%adapt%max_steps), contact_levels(study%scene%adapt%max_steps))
      eta_name = trim(merge('eta_sprc', 'eta_spr ', study%run(2)))
      call start_adapt(study, start_level, run)
      progress_unit = 'step'
      n_rows = 0
      do while (.not. run%finished)
         if (run%step < 0) then
            total_dofs = study_dofs(study, start_level, error)
            if (allocated(error)) call fail_with(error)
            if (total_dofs < serial_dofs) call warm_up(study, min(start_level, warm_level))
         else
            total_dofs = run%next_dofs
         end if
         if (cli%threads == 0) call omp_set_num_threads(merge(1, threads, total_dofs < serial_dofs))
         if (.not. quiet) write (error_unit, '(a,i0,a,i0,a)') 'sprc: step ', run%step + 1, ' (about ', &
            & nint(total_dofs, i8), ' dofs)'
         progress_level = run%step + 1
         if (cli%quiet) then
            call adapt_step(study, run, result, error)
         else
            call adapt_step(study, run, result, error, progress=print_contact_progress)
         end if
         if (allocated(error)) call fail_with(error)
         n_rows = n_rows + 1
         rows(n_rows) = result%row
         if (h5%opened()) call write_level_fields(h5, study, result, error, step=run%step)
         if (allocated(error)) call fail_with(error)
         if (rank == 0) call print_contact_warnings('step', run%step, result)
         if (allocated(result%contacts)) then
            n_contact = n_contact + 1
            contact_levels(n_contact)%level = run%step
            call move_alloc(result%contacts, contact_levels(n_contact)%contacts)
         end if
         text = peak_text(study, ranks, error)
         if (allocated(error)) call fail_with(error)
         if (.not. quiet) write (error_unit, '(a,i0,a,i0,a,i0,a)') 'sprc: step ', run%step, ' done: ', &
            & result%row%dofs, ' dofs, finest level ', result%row%level, ', '//eta_name//' = '// &
            & sci_text(step_eta(study, result))//' (target '//sci_text(study%scene%adapt%target)//') in '// &
            & fixed_text(result%row%t_total, 3)//' s'//text
      end do
      if (rank == 0 .and. len(adapt_warning(study, run)) > 0) &
         & write (error_unit, '(a)') 'sprc: warning: '//adapt_warning(study, run)
   end subroutine run_steps

   !> `x` as 1.234e-02.
   function sci_text(x) result(text)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: text
      character(len=16) :: buf
      write (buf, '(es10.3)') x
      text = trim(adjustl(buf))
   end function sci_text

   !> Runs `level` (a coarse one) once, untimed, and drops the result, so that the run's one-off
   !> costs (first calls into the shared libraries, cold caches) stay out of the first level's
   !> times; only before a small first level, where they are a material share of its time
   !> (figures in the commits that added it). Not the first level itself: a small level can still
   !> be expensive (Coulomb stages), and running it twice doubled a fuzzed run to 26 s. An error
   !> (a body smaller than a cell at that level) only ends the warm-up.
   subroutine warm_up(study, level)
      type(study_type), intent(in) :: study
      integer, intent(in) :: level
      type(level_type) :: result
      type(error_type), allocatable :: error
      call run_level(study, level, result, error)
   end subroutine warm_up

   !> ', peak memory 171 MB': the peak resident memory of the run so far (with levels
   !> in increasing order, that of the level just done); '' where unknown. Under
   !> mpirun the largest of the ranks' (each rank's own peak; every rank calls this).
   function peak_text(study, ranks, error) result(text)
      type(study_type), intent(in) :: study
      integer, intent(in) :: ranks
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      real(wp) :: bytes
      text = ''
      call largest_over_ranks(study%partition, real(peak_memory(), wp), bytes, error)
      if (bytes < 0.0_wp .or. allocated(error)) return
      text = ', peak memory '//byte_text(bytes)
      if (ranks > 1) text = text//' (largest rank of '//itoa(ranks)//')'
   end function peak_text

   !> mkdir -p of the directory part of an output prefix (the library does no
   !> file-system management); a path with quotes is left to fail on open.
   subroutine make_parent_directory(prefix)
      character(len=*), intent(in) :: prefix
      integer :: slash, stat
      slash = index(prefix, '/', back=.true.)
      if (slash <= 1) return
      if (scan(prefix, '"''`$\') > 0) return
      call execute_command_line('mkdir -p -- "'//prefix(1:slash - 1)//'"', exitstat=stat)
   end subroutine make_parent_directory

   !> Exit 2 for bad input or an unwritable file, 1 for everything else.
   subroutine fail_with(error)
      type(error_type), intent(in) :: error
      if (error%stat == stat_invalid_input .or. error%stat == stat_io) call fail(2, error%message)
      call fail(1, error%message)
   end subroutine fail_with

   subroutine check_scene(path)
      character(len=*), intent(in) :: path
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)
      type(error_type), allocatable :: error

      call read_scene(path, scene, error)
      if (allocated(error)) call fail(2, error%message)
      call build_bodies(scene, bodies, error)
      if (.not. allocated(error)) call check_surfaces(scene, bodies, minval(scene%levels), 0, error)
      if (allocated(error)) call fail_with(error)
      call print_warnings(scene_warnings(scene, bodies))
      write (output_unit, '(a)') scene_summary(scene)
   end subroutine check_scene

   !> `sprc mesh`: one line per level and body (SCENE.md).
   subroutine mesh_scene(cli)
      type(cli_type), intent(in) :: cli
      type(scene_type) :: scene
      type(error_type), allocatable :: error
      type(mesh_row_type), allocatable :: rows(:)
      type(body_type), allocatable :: bodies(:)
      integer, allocatable :: levels(:)
      integer :: i

      call read_scene(cli%scene_path, scene, error)
      if (allocated(error)) call fail(2, error%message)
      call study_levels(scene, cli%levels, levels, error)
      if (allocated(error)) call fail(2, error%message)
      call mesh_study(scene, levels, cli%points, rows, error)
      if (allocated(error)) call fail(1, error%message)
      do i = 1, size(rows)
         write (output_unit, '(a)') format_mesh_row(rows(i))
      end do
      ! After the rows, so that the measures show what is missing.
      call build_bodies(scene, bodies, error)
      if (.not. allocated(error)) call check_surfaces(scene, bodies, minval(levels), cli%points, error, grid_only=.true.)
      if (allocated(error)) call fail_with(error)
   end subroutine mesh_scene


   !> Lines 'warning: ...' on standard error, each as 'sprc: warning: ...'.
   !> The contact solves' warnings of a level (or adaptive step) `n`, each
   !> as 'sprc: warning: level n: ...'.
   subroutine print_contact_warnings(what, n, result)
      character(len=*), intent(in) :: what
      integer, intent(in) :: n
      type(level_type), intent(in) :: result
      integer :: p
      if (.not. allocated(result%contacts)) return
      do p = 1, size(result%contacts)
         if (.not. allocated(result%contacts(p)%warning)) cycle
         if (len(result%contacts(p)%warning) == 0) cycle
         write (error_unit, '(a,i0,a)') 'sprc: warning: '//what//' ', n, ': '//result%contacts(p)%warning
      end do
   end subroutine print_contact_warnings

   subroutine print_warnings(text)
      character(len=*), intent(in) :: text
      integer :: start, nl
      start = 1
      do while (start <= len(text))
         nl = index(text(start:), new_line('a'))
         if (nl == 0) nl = len(text) - start + 2
         write (error_unit, '(a)') 'sprc: '//text(start:start + nl - 2)
         start = start + nl
      end do
   end subroutine print_warnings

   subroutine fail(status, text)
      integer, intent(in) :: status
      character(len=*), intent(in) :: text
      integer :: i, unit, stat
      logical :: exists
      write (error_unit, '(a)') 'sprc: error: '//text
      flush (error_unit)
      if (allocated(partial_prefix)) then
         do i = 1, size(output_exts)
            inquire (file=partial_prefix//trim(output_exts(i))//partial, exist=exists)
            if (.not. exists) cycle
            open (newunit=unit, file=partial_prefix//trim(output_exts(i))//partial, status='old', iostat=stat)
            if (stat == 0) close (unit, status='delete', iostat=stat)
         end do
      end if
      ! Under mpirun: a rank that failed alone ends the run on every rank
      ! (the others may wait in a collective it will not enter).
      if (world_ranks > 1) then
         if (.not. fail_together(fail_wait)) call sprc_mpi_abort(int(status, c_int))
      end if
      ! `stop`, not `error stop`: gfortran prints a backtrace on error stop.
      select case (status)
      case (1)
         stop 1, quiet=.true.
      case default
         stop 2, quiet=.true.
      end select
   end subroutine fail

end program sprc_main
