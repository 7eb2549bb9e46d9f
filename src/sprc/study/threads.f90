!> How many OpenMP threads a level of a study runs on, by default: one for a
!> level estimated below `serial_dofs` dofs (its parallel regions are too
!> short to pay for the threads' synchronisation, which made small levels
!> slower on two threads than on one and the error-against-time curve run
!> backwards; figures in the commit that set it), the caller's count for the
!> others. The driver, the C API and Python choose alike. Same bits either way.
module sprc_study_threads
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_study_budget, only: level_memory
   use sprc_study_level, only: study_type
   implicit none
   private

   public :: serial_dofs, study_dofs, level_threads

   !> Below this many estimated dofs (all bodies) a level runs on one thread by default.
   real(wp), parameter :: serial_dofs = 5000.0_wp

contains

   !> The dofs of all bodies at `level`, as estimated before the level is built (sprc_study_budget).
   function study_dofs(study, level, error) result(total)
      type(study_type), intent(in) :: study
      integer, intent(in) :: level
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: total, cells, dofs, bytes
      integer :: b

      total = 0.0_wp
      do b = 1, size(study%bodies)
         call level_memory(study%scene, study%bodies(b)%geometry, level, cells, dofs, bytes, error)
         if (allocated(error)) return
         total = total + dofs
      end do
   end function study_dofs

   !> The threads for `level`: `requested` when positive, otherwise 1 below
   !> `serial_dofs` estimated dofs and `available` (the caller's count) above.
   integer function level_threads(study, level, requested, available, error) result(threads)
      type(study_type), intent(in) :: study
      integer, intent(in) :: level, requested, available
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: dofs

      threads = requested
      if (requested > 0) return
      dofs = study_dofs(study, level, error)
      threads = merge(1, max(1, available), dofs < serial_dofs)
   end function level_threads

end module sprc_study_threads
