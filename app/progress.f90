!> The driver's progress lines of the contact iterations on standard error
!> (the library tells, through sprc_contact_pair_solve's `contact_progress`).
module sprc_app_progress
   use, intrinsic :: iso_fortran_env, only: error_unit
   use sprc_core_text, only: itoa
   implicit none
   private

   public :: progress_level, progress_unit, print_contact_progress

   !> The level (or adaptive step) being run, for the lines.
   integer :: progress_level = 0
   !> 'level', or 'step' in an adaptive study.
   character(len=5) :: progress_unit = 'level'

contains

   !> 'sprc: level 6: contact iteration 3 (12 points switched)', with a load
   !> path of several increments 'sprc: level 6: contact increment 2 of 4,
   !> iteration 3 (12 points switched)'.
   subroutine print_contact_progress(increment, increments, iteration, switched)
      integer, intent(in) :: increment, increments, iteration, switched
      character(len=:), allocatable :: where

      where = ''
      if (increments > 1) where = 'increment '//itoa(increment)//' of '//itoa(increments)//', '
      write (error_unit, '(a)') 'sprc: '//trim(progress_unit)//' '//itoa(progress_level)//': contact '//where//'iteration '// &
         & itoa(iteration)//' ('//itoa(switched)//' points switched)'
      flush (error_unit)
   end subroutine print_contact_progress

end module sprc_app_progress
