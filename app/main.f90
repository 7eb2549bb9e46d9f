!> The sprc driver: the only place that prints and sets exit codes
!> (0 success, 2 bad input, 1 numerical failure or a capability not yet available).
program sprc_main
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use sprc_core_error, only: error_type
   use sprc_version, only: sprc_version_string
   use sprc_io_scene, only: scene_type, read_scene, read_scene_text, scene_summary, default_scene_text
   use sprc_io_study, only: mesh_row_type, mesh_study, format_mesh_row, study_levels
   use sprc_app_cli, only: cli_type, parse_cli, usage_text
   implicit none

   type(cli_type) :: cli
   character(len=:), allocatable :: message

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
      call run_default()
   case ('check')
      call check_scene(cli%scene_path)
   case ('mesh')
      call mesh_scene(cli)
   case ('run')
      call check_scene_quietly(cli%scene_path)
      call fail(1, 'sprc '//cli%command//': '//not_yet())
   end select

contains

   !> What this version can and cannot do, stated plainly (issue: never pretend).
   function not_yet() result(text)
      character(len=:), allocatable :: text
      text = 'this version ('//sprc_version_string//') reads and validates scenes and builds their '// &
         'grids (sprc mesh); the cut-cell quadrature, FE solve, SPR/SPR-C recovery and the error '// &
         'report are not implemented yet'
   end function not_yet

   subroutine run_default()
      type(scene_type) :: scene
      type(error_type), allocatable :: error

      write (output_unit, '(a)') 'sprc '//sprc_version_string
      write (output_unit, '(a)') 'Can do now:    sprc check SCENE.nml (read and validate a scene, '// &
         'list what it switches on and off), sprc mesh SCENE.nml (grid cell counts per level), '// &
         '--help, --version.'
      write (output_unit, '(a)') 'Cannot do yet: sprc run and this default study: '//not_yet()//'.'
      write (output_unit, '(a)') 'The built-in default scene (example/scenes/lame_cylinder.nml) validates as:'
      write (output_unit, '(a)') ''
      call read_scene_text(default_scene_text(), '<built-in default scene>', scene, error)
      if (allocated(error)) call fail(1, 'built-in default scene: '//error%message)
      write (output_unit, '(a)') scene_summary(scene)
   end subroutine run_default

   subroutine check_scene(path)
      character(len=*), intent(in) :: path
      type(scene_type) :: scene
      type(error_type), allocatable :: error

      call read_scene(path, scene, error)
      if (allocated(error)) call fail(2, error%message)
      write (output_unit, '(a)') scene_summary(scene)
   end subroutine check_scene

   !> `sprc mesh`: one line per level and body (SCENE.md).
   subroutine mesh_scene(cli)
      type(cli_type), intent(in) :: cli
      type(scene_type) :: scene
      type(error_type), allocatable :: error
      type(mesh_row_type), allocatable :: rows(:)
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
   end subroutine mesh_scene

   subroutine check_scene_quietly(path)
      character(len=*), intent(in) :: path
      type(scene_type) :: scene
      type(error_type), allocatable :: error

      call read_scene(path, scene, error)
      if (allocated(error)) call fail(2, error%message)
   end subroutine check_scene_quietly

   subroutine fail(status, text)
      integer, intent(in) :: status
      character(len=*), intent(in) :: text
      write (error_unit, '(a)') 'sprc: error: '//text
      flush (error_unit)
      ! `stop`, not `error stop`: gfortran prints a backtrace on error stop.
      select case (status)
      case (1)
         stop 1, quiet=.true.
      case default
         stop 2, quiet=.true.
      end select
   end subroutine fail

end program sprc_main
