!> Read a scene file through the `sprc` facade and print its summary.
!>
!>    gfortran read_scene.f90 $(pkg-config --cflags --libs sprc) -o read_scene
!>    ./read_scene example/scenes/lame_cylinder.nml
program read_scene_example
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use sprc, only: scene_type, read_scene, scene_summary, error_type, stat_name, sprc_version_string
   implicit none
   type(scene_type) :: scene
   type(error_type), allocatable :: error
   character(len=1024) :: path

   if (command_argument_count() /= 1) then
      write (error_unit, '(a)') 'usage: read_scene SCENE.nml'
      stop 2
   end if
   call get_command_argument(1, path)
   call read_scene(trim(path), scene, error)
   if (allocated(error)) then
      write (error_unit, '(a)') 'read_scene ('//stat_name(error%stat)//'): '//error%message
      stop 1
   end if
   write (output_unit, '(a)') 'sprc '//sprc_version_string
   write (output_unit, '(a)', advance='no') scene_summary(scene)
end program read_scene_example
