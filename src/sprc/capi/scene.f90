!> C API, scenes: run the study of a scene file (SCENE.md) and return its
!> report. The C run writes no files, whatever the scene's `output`; it
!> computes exactly what `sprc run` computes and reports: a scene with
!> `&adapt` gives one row per adaptive step (`step`, `t_adapt` columns);
!> a run that a limit ended is a success, as for the driver (its last row
!> is the last step; the driver's warning is not repeated here).
module sprc_capi_scene
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_null_ptr, c_associated, c_f_pointer, c_loc
   use sprc_core_error, only: error_type, stat_invalid_input, stat_out_of_memory
   use sprc_io_scene, only: scene_type, read_scene
   use sprc_study_mesh, only: study_levels
   use sprc_study_level, only: study_type, prepare_study, run_level, level_type, hold_starts
   use sprc_study_adapt, only: adapt_run_type, start_adapt, adapt_step
   use sprc_fem_nested, only: fe_displacement_type
   use sprc_study_row, only: report_row_type
   use sprc_capi_error, only: capi_error_type, get_capi_error, set_capi_error
   use sprc_capi_report, only: capi_report_type
   use sprc_capi_string, only: c_string
   implicit none
   private

   public :: sprc_run_scene

contains

   !> Read the scene file `path` and analyse it at `levels[nlevels]` (NULL
   !> and 0 take the scene's own levels). Returns a new report, or NULL with
   !> the error set: bad arguments, an unreadable or invalid scene, a scene
   !> this version cannot run, a failed level.
   function sprc_run_scene(errh, path, levels, nlevels) result(reph) bind(C, name='sprc_run_scene')
      type(c_ptr), value :: errh, path, levels
      integer(c_int), value :: nlevels
      type(c_ptr) :: reph
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep
      type(report_row_type), allocatable :: rows(:)
      type(error_type), allocatable :: error
      character(len=:), allocatable :: file
      integer(c_int), pointer :: override(:)
      integer :: stat
      logical :: ok

      reph = c_null_ptr
      if (.not. get_capi_error(errh, err)) return
      call c_string(path, file, ok)
      if (.not. ok) then
         call set_capi_error(err, message='sprc_run_scene: the scene path is NULL', stat=stat_invalid_input)
         return
      end if
      if (nlevels < 0 .or. (nlevels > 0 .and. .not. c_associated(levels))) then
         call set_capi_error(err, message='sprc_run_scene: levels must be NULL with nlevels = 0, '// &
            'or point to nlevels > 0 levels', stat=stat_invalid_input)
         return
      end if
      if (nlevels > 0) then
         call c_f_pointer(levels, override, [nlevels])
         call run_study(file, rows, error, override)
      else
         call run_study(file, rows, error)
      end if
      if (allocated(error)) then
         call set_capi_error(err, error)
         return
      end if
      allocate (rep, stat=stat)
      if (stat /= 0) then
         call set_capi_error(err, message='sprc_run_scene: cannot allocate the report', stat=stat_out_of_memory)
         return
      end if
      call move_alloc(rows, rep%rows)
      reph = c_loc(rep)
   end function sprc_run_scene

   !> Read the scene and run each level (or adaptive step) of the study.
   subroutine run_study(path, rows, error, override)
      character(len=*), intent(in) :: path
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      integer(c_int), intent(in), optional :: override(:)
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result
      !> The previous level's displacements, where the iterative solves start.
      type(fe_displacement_type), allocatable :: starts(:)
      integer, allocatable :: levels(:)
      integer :: i

      call read_scene(path, scene, error)
      if (allocated(error)) return
      if (present(override)) then
         call study_levels(scene, int(override), levels, error)
      else
         call study_levels(scene, levels=levels, error=error)
      end if
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      if (scene%adapt%present) then
         call run_steps(study, levels(1), rows, error)
         return
      end if
      allocate (rows(size(levels)))
      do i = 1, size(levels)
         call run_level(study, levels(i), result, error, start=starts)
         if (allocated(error)) return
         rows(i) = result%row
         call hold_starts(result, starts, error)
         if (allocated(error)) return
      end do
   end subroutine run_study

   !> The adaptive study from `start_level`: one row per step.
   subroutine run_steps(study, start_level, rows, error)
      type(study_type), intent(in) :: study
      integer, intent(in) :: start_level
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      type(adapt_run_type) :: run
      type(level_type) :: result
      type(report_row_type), allocatable :: all(:)

      allocate (all(study%scene%adapt%max_steps))
      call start_adapt(study, start_level, run)
      do while (.not. run%finished)
         call adapt_step(study, run, result, error)
         if (allocated(error)) return
         all(run%step + 1) = result%row
      end do
      rows = all(:run%step + 1)
   end subroutine run_steps

end module sprc_capi_scene
