!> C API, studies: run the study of a scene file (doc/scene.md) as `sprc run`
!> does and keep the fields of the levels the caller asks for, as arrays
!> (`sprc_study`). The arrays are those the driver writes to PREFIX.h5
!> (`sprc_io_fields` builds both), so a field read here has the bits of its
!> dataset. Also the thread count of a run (`sprc_run_scene_threads`).
module sprc_capi_study
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_null_ptr, c_associated, c_f_pointer, c_loc
   !$ use omp_lib, only: omp_set_num_threads, omp_get_max_threads
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_out_of_memory
   use sprc_core_text, only: itoa
   use sprc_io_scene, only: scene_type, read_scene
   use sprc_io_fields, only: level_fields_type, grid_fields_type, field_array_type, level_fields
   use sprc_study_mesh_table, only: study_levels, check_surfaces
   use sprc_geometry_body, only: body_type
   use sprc_study_level, only: study_type, prepare_study, run_level, level_type, hold_starts
   use sprc_study_threads, only: level_threads, serial_dofs
   use sprc_study_adapt, only: adapt_run_type, start_adapt, adapt_step
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_study_row, only: report_row_type
   use sprc_capi_error, only: capi_error_type, get_capi_error, set_capi_error
   use sprc_capi_report, only: capi_report_type
   use sprc_capi_string, only: c_string, copy_to_buffer
   implicit none
   private

   public :: run_scene_study, run_scene_report
   public :: sprc_run_scene_threads, sprc_run_study, sprc_get_study_report, sprc_get_study_grids, &
      & sprc_get_study_grid, sprc_get_study_fields, sprc_get_study_field_name, sprc_get_study_field_shape, &
      & sprc_get_study_field, sprc_get_study_field_int, sprc_delete_study

   !> Field types of `sprc_get_study_field_shape` (SPRC_FIELD_REAL, SPRC_FIELD_INT).
   integer(c_int), parameter :: field_real = 1, field_int = 2

   !> What an `sprc_study` handle points to: the report, and per row the
   !> fields of its level where they were kept (`kept`).
   type :: capi_study_type
      type(report_row_type), allocatable :: rows(:)
      logical, allocatable :: kept(:)
      type(level_fields_type), allocatable :: fields(:)
   end type capi_study_type

contains

   !> `sprc_run_scene` on `threads` OpenMP threads (0: as the driver chooses).
   function sprc_run_scene_threads(errh, path, levels, nlevels, threads) result(reph) &
      & bind(C, name='sprc_run_scene_threads')
      type(c_ptr), value :: errh, path, levels
      integer(c_int), value :: nlevels, threads
      type(c_ptr) :: reph
      reph = run_scene_report(errh, 'sprc_run_scene_threads', path, levels, nlevels, threads)
   end function sprc_run_scene_threads

   !> The report of a run from C, its errors naming `entry`.
   function run_scene_report(errh, entry, path, levels, nlevels, threads) result(reph)
      type(c_ptr), intent(in) :: errh, path, levels
      character(len=*), intent(in) :: entry
      integer(c_int), intent(in) :: nlevels, threads
      type(c_ptr) :: reph
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep
      type(capi_study_type) :: study
      integer :: stat

      reph = c_null_ptr
      if (.not. get_capi_error(errh, err)) return
      call run_from_c(err, entry, path, levels, nlevels, c_null_ptr, 0_c_int, threads, .false., study)
      if (.not. allocated(study%rows)) return
      allocate (rep, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message=entry//': cannot allocate the report', stat=stat_out_of_memory)
         return
      end if
      call move_alloc(study%rows, rep%rows)
      reph = c_loc(rep)
   end function run_scene_report

   !> Run the study and keep the fields of the levels `keep[nkeep]` (NULL and
   !> 0: every level run). NULL with the error set on failure.
   function sprc_run_study(errh, path, levels, nlevels, keep, nkeep, threads) result(studyh) &
      & bind(C, name='sprc_run_study')
      type(c_ptr), value :: errh, path, levels, keep
      integer(c_int), value :: nlevels, nkeep, threads
      type(c_ptr) :: studyh
      type(capi_error_type), pointer :: err
      type(capi_study_type), pointer :: study
      integer :: stat

      studyh = c_null_ptr
      if (.not. get_capi_error(errh, err)) return
      allocate (study, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message='sprc_run_study: cannot allocate the study', stat=stat_out_of_memory)
         return
      end if
      call run_from_c(err, 'sprc_run_study', path, levels, nlevels, keep, nkeep, threads, .true., study)
      if (.not. allocated(study%rows)) then
         deallocate (study)
         return
      end if
      studyh = c_loc(study)
   end function sprc_run_study

   !> The arguments of a run from C checked, then the run; `study%rows` not
   !> allocated (and the error set) on failure.
   subroutine run_from_c(err, entry, path, levels, nlevels, keep, nkeep, threads, fields, study)
      type(capi_error_type), intent(inout) :: err
      character(len=*), intent(in) :: entry
      type(c_ptr), intent(in) :: path, levels, keep
      integer(c_int), intent(in) :: nlevels, nkeep, threads
      logical, intent(in) :: fields
      type(capi_study_type), intent(inout) :: study
      type(error_type), allocatable :: error
      character(len=:), allocatable :: file
      integer(c_int), pointer :: lv(:), kp(:)
      logical :: ok

      call c_string(path, file, ok)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the scene path is NULL', stat=stat_invalid_input)
         return
      end if
      if (nlevels < 0 .or. (nlevels > 0 .and. .not. c_associated(levels))) then
         call set_capi_error(err, message=entry//': levels must be NULL with nlevels = 0, '// &
            'or point to nlevels > 0 levels', stat=stat_invalid_input)
         return
      end if
      if (nkeep < 0 .or. (nkeep > 0 .and. .not. c_associated(keep))) then
         call set_capi_error(err, message=entry//': keep must be NULL with nkeep = 0, '// &
            'or point to nkeep > 0 levels', stat=stat_invalid_input)
         return
      end if
      if (threads < 0) then
         call set_capi_error(err, message=entry//': threads = '//itoa(threads)//' (0 chooses as the driver does, '// &
            & 'n > 0 runs on n threads)', stat=stat_invalid_input)
         return
      end if
      lv => null()
      kp => null()
      if (nlevels > 0) call c_f_pointer(levels, lv, [nlevels])
      if (nkeep > 0) call c_f_pointer(keep, kp, [nkeep])
      if (nlevels > 0 .and. nkeep > 0) then
         call run_scene_study(file, threads, fields, study%rows, error, override=int(lv), keep=int(kp), &
            & kept=study%kept, kept_fields=study%fields)
      else if (nlevels > 0) then
         call run_scene_study(file, threads, fields, study%rows, error, override=int(lv), kept=study%kept, &
            & kept_fields=study%fields)
      else if (nkeep > 0) then
         call run_scene_study(file, threads, fields, study%rows, error, keep=int(kp), kept=study%kept, &
            & kept_fields=study%fields)
      else
         call run_scene_study(file, threads, fields, study%rows, error, kept=study%kept, kept_fields=study%fields)
      end if
      if (allocated(error)) then
         if (allocated(study%rows)) deallocate (study%rows)
         if (allocated(study%fields)) deallocate (study%fields)
         call set_capi_error(err, error)
      end if
   end subroutine run_from_c

   !> Read the scene `path` and run each level of its study (`override`: these
   !> levels) on `threads` threads (0: `level_threads`' default); with
   !> `fields`, keep the fields of the levels in `keep` (absent: all) in
   !> `level_fields`, one slot per row, filled where `kept`. The caller's
   !> OpenMP thread count is restored on return.
   subroutine run_scene_study(path, threads, fields, rows, error, override, keep, kept, kept_fields)
      character(len=*), intent(in) :: path
      integer, intent(in) :: threads
      logical, intent(in) :: fields
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: override(:), keep(:)
      logical, allocatable, intent(out) :: kept(:)
      type(level_fields_type), allocatable, intent(out) :: kept_fields(:)
      integer :: saved, available

      saved = 1
      !$ saved = omp_get_max_threads()
      !$ if (threads > 0) call omp_set_num_threads(threads)
      available = saved
      if (threads > 0) available = threads
      call run_levels(path, threads, available, fields, rows, error, override, keep, kept, kept_fields)
      !$ call omp_set_num_threads(saved)
   end subroutine run_scene_study

   subroutine run_levels(path, threads, available, fields, rows, error, override, keep, kept, kept_fields)
      character(len=*), intent(in) :: path
      integer, intent(in) :: threads, available
      logical, intent(in) :: fields
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: override(:), keep(:)
      logical, allocatable, intent(out) :: kept(:)
      type(level_fields_type), allocatable, intent(out) :: kept_fields(:)
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result
      !> The previous level's displacements, where the iterative solves start.
      type(fe_displacement_type), allocatable :: starts(:)
      integer, allocatable :: levels(:)
      type(body_type), allocatable :: geometry(:)
      integer :: i, j, n

      call read_scene(path, scene, error)
      if (allocated(error)) return
      if (present(override)) then
         call study_levels(scene, override, levels, error)
      else
         call study_levels(scene, levels=levels, error=error)
      end if
      if (allocated(error)) return
      if (scene%adapt%present) then
         call prepare_study(scene, 0, study, error)
         if (allocated(error)) return
         geometry = study%bodies%geometry
         call check_surfaces(scene, geometry, levels(1), 0, error)
         if (.not. allocated(error)) call run_steps(study, levels(1), threads, available, fields, rows, error, keep, &
            & kept, kept_fields)
         return
      end if
      allocate (kept(size(levels)), kept_fields(size(levels)))
      kept = fields
      if (fields .and. present(keep)) then
         do j = 1, size(keep)
            if (.not. any(levels == keep(j))) then
               call fatal_error(error, 'keep: level '//itoa(keep(j))//' is not one of the levels run ('// &
                  & level_list(levels)//')', stat_invalid_input)
               return
            end if
         end do
         do i = 1, size(levels)
            kept(i) = any(keep == levels(i))
         end do
      end if
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      geometry = study%bodies%geometry
      call check_surfaces(scene, geometry, minval(levels), 0, error)
      if (allocated(error)) return
      allocate (rows(size(levels)))
      do i = 1, size(levels)
         n = level_threads(study, levels(i), threads, available, error)
         if (allocated(error)) return
         !$ call omp_set_num_threads(n)
         call run_level(study, levels(i), result, error, start=starts)
         if (allocated(error)) return
         rows(i) = result%row
         if (kept(i)) call level_fields(study, result, kept_fields(i), error)
         if (allocated(error)) return
         call hold_starts(result, starts, error)
         if (allocated(error)) return
      end do
   end subroutine run_levels

   !> The adaptive study (`&adapt`) from `start_level`: one row per step; with
   !> `fields`, the fields of the steps in `keep` (step numbers, 0 the start
   !> mesh; absent: every step). A step in `keep` that the run did not reach
   !> is an error once the run has ended (the steps are not known before).
   subroutine run_steps(study, start_level, threads, available, fields, rows, error, keep, kept, kept_fields)
      type(study_type), intent(in) :: study
      integer, intent(in) :: start_level, threads, available
      logical, intent(in) :: fields
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: keep(:)
      logical, allocatable, intent(out) :: kept(:)
      type(level_fields_type), allocatable, intent(out) :: kept_fields(:)
      type(adapt_run_type) :: run
      type(level_type) :: result
      type(report_row_type), allocatable :: step_rows(:)
      type(level_fields_type), allocatable :: all_fields(:)
      logical, allocatable :: all_kept(:)
      integer :: m, s, n

      m = study%scene%adapt%max_steps
      allocate (step_rows(m), all_fields(m), all_kept(m))
      call start_adapt(study, start_level, run)
      do while (.not. run%finished)
         if (run%step < 0) then
            n = level_threads(study, start_level, threads, available, error)
            if (allocated(error)) return
         else
            n = threads
            if (n <= 0) n = merge(1, max(1, available), run%next_dofs < serial_dofs)
         end if
         !$ call omp_set_num_threads(n)
         call adapt_step(study, run, result, error)
         if (allocated(error)) return
         s = run%step + 1
         step_rows(s) = result%row
         all_kept(s) = fields
         if (fields .and. present(keep)) all_kept(s) = any(keep == run%step)
         if (all_kept(s)) call level_fields(study, result, all_fields(s), error)
         if (allocated(error)) return
      end do
      n = run%step + 1
      if (fields .and. present(keep)) then
         do s = 1, size(keep)
            if (keep(s) < 0 .or. keep(s) >= n) then
               call fatal_error(error, 'keep: step '//itoa(keep(s))//' is not one of the steps run (0 to '// &
                  & itoa(n - 1)//')', stat_invalid_input)
               return
            end if
         end do
      end if
      rows = step_rows(:n)
      kept = all_kept(:n)
      kept_fields = all_fields(:n)
   end subroutine run_steps

   function level_list(levels) result(s)
      integer, intent(in) :: levels(:)
      character(len=:), allocatable :: s
      integer :: i
      s = itoa(levels(1))
      do i = 2, size(levels)
         s = s//', '//itoa(levels(i))
      end do
   end function level_list

   !> A new report handle with the study's rows (free it with sprc_delete_report).
   function sprc_get_study_report(errh, studyh) result(reph) bind(C, name='sprc_get_study_report')
      type(c_ptr), value :: errh, studyh
      type(c_ptr) :: reph
      type(capi_error_type), pointer :: err
      type(capi_study_type), pointer :: study
      type(capi_report_type), pointer :: rep
      integer :: stat

      reph = c_null_ptr
      if (.not. get_study(errh, studyh, 'sprc_get_study_report', err, study)) return
      allocate (rep, stat=stat)
      if (stat == 0) allocate (rep%rows, source=study%rows, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message='sprc_get_study_report: cannot allocate the report', &
            & stat=stat_out_of_memory)
         if (associated(rep)) deallocate (rep)
         return
      end if
      reph = c_loc(rep)
   end function sprc_get_study_report

   !> Number of grids (bodies, then contact pairs) of report row `row`; -1 on error.
   function sprc_get_study_grids(errh, studyh, row) result(n) bind(C, name='sprc_get_study_grids')
      type(c_ptr), value :: errh, studyh
      integer(c_int), value :: row
      integer(c_int) :: n
      type(capi_error_type), pointer :: err
      type(capi_study_type), pointer :: study

      n = -1
      if (.not. get_study(errh, studyh, 'sprc_get_study_grids', err, study)) return
      if (.not. check_row(err, study, row, 'sprc_get_study_grids')) return
      n = size(study%fields(row + 1)%grids)
   end function sprc_get_study_grids

   !> The name of grid `index` of row `row` into `buf`; returns 0 for a body,
   !> 1 for a contact pair, -1 on error.
   function sprc_get_study_grid(errh, studyh, row, index, buf, size) result(kind) bind(C, name='sprc_get_study_grid')
      type(c_ptr), value :: errh, studyh
      integer(c_int), value :: row, index
      type(c_ptr), value :: buf, size
      integer(c_int) :: kind
      type(capi_error_type), pointer :: err
      type(capi_study_type), pointer :: study

      kind = -1
      if (.not. get_study(errh, studyh, 'sprc_get_study_grid', err, study)) return
      if (.not. check_row(err, study, row, 'sprc_get_study_grid')) return
      associate (grids => study%fields(row + 1)%grids)
         if (index < 0 .or. index >= n_grids(grids)) then
            call set_capi_error(err, message='sprc_get_study_grid: grid index '//itoa(index)// &
               ' is out of range 0..'//itoa(n_grids(grids) - 1), stat=stat_invalid_input)
            return
         end if
         call copy_to_buffer(grids(index + 1)%name, buf, size)
         kind = merge(1, 0, grids(index + 1)%is_contact)
      end associate
   end function sprc_get_study_grid

   !> Number of fields of the named grid of row `row` (the mesh arrays
   !> included); -1 on error.
   function sprc_get_study_fields(errh, studyh, row, grid) result(n) bind(C, name='sprc_get_study_fields')
      type(c_ptr), value :: errh, studyh, grid
      integer(c_int), value :: row
      integer(c_int) :: n
      type(capi_error_type), pointer :: err
      type(grid_fields_type), pointer :: g

      n = -1
      if (.not. get_grid(errh, studyh, row, grid, 'sprc_get_study_fields', err, g)) return
      n = size(field_names(g))
   end function sprc_get_study_fields

   !> The name of field `index` of the named grid of row `row` into `buf`.
   subroutine sprc_get_study_field_name(errh, studyh, row, grid, index, buf, size) &
      & bind(C, name='sprc_get_study_field_name')
      type(c_ptr), value :: errh, studyh, grid, buf, size
      integer(c_int), value :: row, index
      type(capi_error_type), pointer :: err
      type(grid_fields_type), pointer :: g
      character(len=64), allocatable :: names(:)

      if (.not. get_grid(errh, studyh, row, grid, 'sprc_get_study_field_name', err, g)) return
      names = field_names(g)
      if (index < 0 .or. index >= n_names(names)) then
         call set_capi_error(err, message='sprc_get_study_field_name: field index '//itoa(index)// &
            ' is out of range 0..'//itoa(n_names(names) - 1), stat=stat_invalid_input)
         return
      end if
      call copy_to_buffer(trim(names(index + 1)), buf, size)
   end subroutine sprc_get_study_field_name

   !> The shape of a field, shape[0] rows (nodes, cells or points) and
   !> shape[1] columns; returns SPRC_FIELD_REAL or SPRC_FIELD_INT, -1 on error.
   function sprc_get_study_field_shape(errh, studyh, row, grid, field, shape) result(type) &
      & bind(C, name='sprc_get_study_field_shape')
      type(c_ptr), value :: errh, studyh, grid, field, shape
      integer(c_int), value :: row
      integer(c_int) :: type
      type(capi_error_type), pointer :: err
      type(grid_fields_type), pointer :: g
      integer(c_int), pointer :: out(:)
      integer :: f, dims(2)

      type = -1
      if (.not. get_field(errh, studyh, row, grid, field, 'sprc_get_study_field_shape', err, g, f)) return
      if (.not. c_associated(shape)) then
         call set_capi_error(err, message='sprc_get_study_field_shape: shape is NULL', stat=stat_invalid_input)
         return
      end if
      call field_shape(g, f, dims, type)
      call c_f_pointer(shape, out, [2])
      out = int(dims, c_int)
   end function sprc_get_study_field_shape

   !> A real field into values[n] (n = rows * columns, row-major).
   subroutine sprc_get_study_field(errh, studyh, row, grid, field, values, n) bind(C, name='sprc_get_study_field')
      type(c_ptr), value :: errh, studyh, grid, field, values
      integer(c_int), value :: row, n
      type(capi_error_type), pointer :: err
      type(grid_fields_type), pointer :: g
      real(c_double), pointer :: out(:)
      integer :: f, dims(2), type

      if (.not. get_field(errh, studyh, row, grid, field, 'sprc_get_study_field', err, g, f)) return
      call field_shape(g, f, dims, type)
      if (.not. check_output(err, 'sprc_get_study_field', g, f, type, field_real, dims, values, n)) return
      call c_f_pointer(values, out, [n])
      if (f == -1) then
         out = reshape(g%nodes, [n])
      else
         out = reshape(g%fields(f)%reals, [n])
      end if
   end subroutine sprc_get_study_field

   !> An integer field into values[n] (n = rows * columns, row-major; `cells` 0-based).
   subroutine sprc_get_study_field_int(errh, studyh, row, grid, field, values, n) &
      & bind(C, name='sprc_get_study_field_int')
      type(c_ptr), value :: errh, studyh, grid, field, values
      integer(c_int), value :: row, n
      type(capi_error_type), pointer :: err
      type(grid_fields_type), pointer :: g
      integer(c_int), pointer :: out(:)
      integer :: f, dims(2), type

      if (.not. get_field(errh, studyh, row, grid, field, 'sprc_get_study_field_int', err, g, f)) return
      call field_shape(g, f, dims, type)
      if (.not. check_output(err, 'sprc_get_study_field_int', g, f, type, field_int, dims, values, n)) return
      call c_f_pointer(values, out, [n])
      if (f == -2) then
         out = reshape(g%cells - 1, [n])
      else
         out = reshape(g%fields(f)%ints, [n])
      end if
   end subroutine sprc_get_study_field_int

   !> Free the study `*ptr` and set it to NULL; NULL `ptr` or `*ptr` is a no-op.
   subroutine sprc_delete_study(ptr) bind(C, name='sprc_delete_study')
      type(c_ptr), value :: ptr
      type(c_ptr), pointer :: handle
      type(capi_study_type), pointer :: study

      if (.not. c_associated(ptr)) return
      call c_f_pointer(ptr, handle)
      if (.not. c_associated(handle)) return
      call c_f_pointer(handle, study)
      deallocate (study)
      handle = c_null_ptr
   end subroutine sprc_delete_study

   ! ------------------------------------------------------------------ helpers

   !> The field names of a grid: `nodes` (`points` for a contact pair), `cells`
   !> (bodies only), then its fields in the order of the HDF5 file.
   function field_names(g) result(names)
      type(grid_fields_type), intent(in) :: g
      character(len=64), allocatable :: names(:)
      integer :: f
      if (g%is_contact) then
         names = [character(len=64) :: 'points']
      else
         names = [character(len=64) :: 'nodes', 'cells']
      end if
      names = [character(len=64) :: names, (g%fields(f)%name, f=1, g%n_fields)]
   end function field_names

   !> The rows and columns of field f (-1 the nodes, -2 the cells) and its type.
   subroutine field_shape(g, f, dims, type)
      type(grid_fields_type), intent(in) :: g
      integer, intent(in) :: f
      integer, intent(out) :: dims(2), type
      select case (f)
      case (-1)
         dims = [size(g%nodes, 2), size(g%nodes, 1)]
         type = field_real
      case (-2)
         dims = [size(g%cells, 2), size(g%cells, 1)]
         type = field_int
      case default
         if (allocated(g%fields(f)%reals)) then
            dims = [size(g%fields(f)%reals, 2), size(g%fields(f)%reals, 1)]
            type = field_real
         else
            dims = [size(g%fields(f)%ints, 2), size(g%fields(f)%ints, 1)]
            type = field_int
         end if
      end select
   end subroutine field_shape

   logical function check_output(err, entry, g, f, type, wanted, dims, values, n) result(ok)
      type(capi_error_type), intent(inout) :: err
      character(len=*), intent(in) :: entry
      type(grid_fields_type), intent(in) :: g
      integer, intent(in) :: f, type, wanted, dims(2)
      type(c_ptr), intent(in) :: values
      integer(c_int), intent(in) :: n
      character(len=:), allocatable :: name

      select case (f)
      case (-1)
         name = merge('points', 'nodes ', g%is_contact)
         name = trim(name)
      case (-2)
         name = 'cells'
      case default
         name = g%fields(f)%name
      end select
      ok = .false.
      if (type /= wanted) then
         call set_capi_error(err, message=entry//': field "'//name//'" of "'//g%name//'" holds '// &
            & merge('integers', 'doubles ', type == field_int)//': read it with '// &
            & merge('sprc_get_study_field_int', 'sprc_get_study_field    ', type == field_int), stat=stat_invalid_input)
         return
      end if
      if (n /= dims(1)*dims(2)) then
         call set_capi_error(err, message=entry//': n = '//itoa(n)//' but field "'//name//'" of "'//g%name// &
            & '" has '//itoa(dims(1))//' x '//itoa(dims(2))//' = '//itoa(dims(1)*dims(2))//' values', &
            & stat=stat_invalid_input)
         return
      end if
      if (.not. c_associated(values)) then
         call set_capi_error(err, message=entry//': values is NULL', stat=stat_invalid_input)
         return
      end if
      ok = .true.
   end function check_output

   pure integer function n_names(names)
      character(len=*), intent(in) :: names(:)
      n_names = size(names)
   end function n_names

   pure integer function n_grids(grids)
      type(grid_fields_type), intent(in) :: grids(:)
      n_grids = size(grids)
   end function n_grids

   !> The objects behind an error and a study handle (false for a NULL one, reported).
   logical function get_study(errh, studyh, entry, err, study) result(ok)
      type(c_ptr), intent(in) :: errh, studyh
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(capi_study_type), pointer, intent(out) :: study

      study => null()
      ok = get_capi_error(errh, err)
      if (.not. ok) return
      ok = c_associated(studyh)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the study handle is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(studyh, study)
   end function get_study

   !> Row `row` (0-based) exists and its fields were kept.
   logical function check_row(err, study, row, entry) result(ok)
      type(capi_error_type), intent(inout) :: err
      type(capi_study_type), intent(in) :: study
      integer(c_int), intent(in) :: row
      character(len=*), intent(in) :: entry

      ok = row >= 0 .and. row < size(study%rows)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': row '//itoa(row)//' is out of range 0..'// &
            & itoa(size(study%rows) - 1)//' (one row per level run)', stat=stat_invalid_input)
         return
      end if
      ok = study%kept(row + 1)
      if (.not. ok) call set_capi_error(err, message=entry//': the fields of row '//itoa(row)//' (level '// &
         & itoa(study%rows(row + 1)%level)//') were not kept (sprc_run_study keep)', stat=stat_invalid_input)
   end function check_row

   !> The grid named by the C string `grid` at row `row`.
   logical function get_grid(errh, studyh, row, grid, entry, err, g) result(ok)
      type(c_ptr), intent(in) :: errh, studyh, grid
      integer(c_int), intent(in) :: row
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(grid_fields_type), pointer, intent(out) :: g
      type(capi_study_type), pointer :: study
      character(len=:), allocatable :: name, names
      integer :: k

      g => null()
      ok = get_study(errh, studyh, entry, err, study)
      if (.not. ok) return
      ok = check_row(err, study, row, entry)
      if (.not. ok) return
      call c_string(grid, name, ok)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the grid name is NULL', stat=stat_invalid_input)
         return
      end if
      names = ''
      do k = 1, size(study%fields(row + 1)%grids)
         associate (gk => study%fields(row + 1)%grids(k))
            if (len(gk%name) == len(name)) then
               if (gk%name == name) then
                  g => study%fields(row + 1)%grids(k)
                  return
               end if
            end if
            names = names//merge(', ', '  ', k > 1)//gk%name
         end associate
      end do
      ok = .false.
      call set_capi_error(err, message=entry//': row '//itoa(row)//' (level '//itoa(study%rows(row + 1)%level)// &
         & ') has no body or contact pair named "'//name//'" (grids: '//trim(adjustl(names))//')', &
         & stat=stat_invalid_input)
   end function get_grid

   !> The field named by the C string `field` of a grid: its index in
   !> `g%fields`, or -1 for `nodes` / `points`, -2 for `cells`.
   logical function get_field(errh, studyh, row, grid, field, entry, err, g, f) result(ok)
      type(c_ptr), intent(in) :: errh, studyh, grid, field
      integer(c_int), intent(in) :: row
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(grid_fields_type), pointer, intent(out) :: g
      integer, intent(out) :: f
      character(len=:), allocatable :: name, list
      character(len=64), allocatable :: names(:)
      integer :: k

      f = 0
      ok = get_grid(errh, studyh, row, grid, entry, err, g)
      if (.not. ok) return
      call c_string(field, name, ok)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the field name is NULL', stat=stat_invalid_input)
         return
      end if
      names = field_names(g)
      do k = 1, size(names)
         if (len_trim(names(k)) == len(name)) then
            if (trim(names(k)) == name) then
               f = k - (size(names) - g%n_fields)
               if (k == 1) f = -1
               if (k == 2 .and. .not. g%is_contact) f = -2
               return
            end if
         end if
      end do
      list = trim(names(1))
      do k = 2, size(names)
         list = list//', '//trim(names(k))
      end do
      ok = .false.
      call set_capi_error(err, message=entry//': "'//g%name//'" has no field "'//name//'" at row '//itoa(row)// &
         & ' (fields: '//list//')', stat=stat_invalid_input)
   end function get_field

end module sprc_capi_study
