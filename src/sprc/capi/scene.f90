!> C API, scenes: run the study of a scene file (doc/scene.md) and return its
!> report. The C run writes no files, whatever the scene's `output`; it
!> computes exactly what `sprc run` computes and reports, on the threads
!> the driver would use (`sprc_capi_study`).
module sprc_capi_scene
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int
   use sprc_capi_study, only: run_scene_report
   implicit none
   private

   public :: sprc_run_scene

contains

   !> Read the scene file `path` and analyse it at `levels[nlevels]` (NULL
   !> and 0 take the scene's own levels). Returns a new report, or NULL with
   !> the error set: bad arguments, an unreadable or invalid scene, a scene
   !> this version cannot run, a failed level. `sprc_run_scene_threads` with
   !> the driver's choice of threads.
   function sprc_run_scene(errh, path, levels, nlevels) result(reph) bind(C, name='sprc_run_scene')
      type(c_ptr), value :: errh, path, levels
      integer(c_int), value :: nlevels
      type(c_ptr) :: reph

      reph = run_scene_report(errh, 'sprc_run_scene', path, levels, nlevels, 0_c_int)
   end function sprc_run_scene

end module sprc_capi_scene
