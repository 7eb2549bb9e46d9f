!> One body's recoveries (SPR, SPR-C) and ZZ estimates at a level
!> (`sprc_study_level`), shared out among the level's ranks (`level_share`),
!> with the contact descriptions of its pairs where it is in contact.
module sprc_study_run_estimate
   use sprc_core_error, only: error_type
   use sprc_estimate_patches, only: recovery_input_type, recover_grid
   use sprc_estimate_recovered_field, only: method_spr, method_sprc
   use sprc_estimate_contact_patches, only: grid_contact_type
   use sprc_estimate_norms, only: estimate_error
   use sprc_study_partition, only: partition_type
   use sprc_grid_share, only: share_type
   use sprc_study_level_types, only: study_body_type, study_type, body_level_type
   implicit none
   private

   public :: recover_body, level_share

contains

   !> The recoveries and estimates of a body from its recovery input; `contacts` are its
   !> contact surfaces, one per pair (SPR-C's coupled contact patches, sprc_estimate_contact_patches).
   subroutine recover_body(study, sb, bl, input, error, contacts)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      type(body_level_type), intent(inout) :: bl
      type(recovery_input_type), intent(in) :: input
      type(error_type), allocatable, intent(out) :: error
      type(grid_contact_type), intent(in), optional :: contacts(:)
      integer :: m

      do m = 1, 2
         if (.not. study%run(m)) cycle
         call recover_and_estimate(study, sb, input, bl, m, study%degree(m), error, contacts)
         if (allocated(error)) return
      end do
   end subroutine recover_body

   !> Recovery and estimate with one method (1 SPR, 2 SPR-C) at the patch degree `degree`.
   !> With `contacts` (one per pair of the body), SPR-C's contact patches (sprc_estimate_contact_patches).
   subroutine recover_and_estimate(study, sb, input, bl, m, degree, error, contacts)
      type(study_type), intent(in) :: study
      type(study_body_type), intent(in) :: sb
      type(recovery_input_type), intent(in) :: input
      type(body_level_type), intent(inout) :: bl
      integer, intent(in) :: m, degree
      type(error_type), allocatable, intent(out) :: error
      type(grid_contact_type), intent(in), optional :: contacts(:)
      type(partition_type), target :: part
      integer :: method

      method = merge(method_spr, method_sprc, m == 1)
      part = study%partition
      if (allocated(sb%exact)) then
         call recover_grid(input, bl%problem%mesh%grid, bl%problem%mesh%nodes, bl%problem%mesh%hanging, method, &
            & degree, bl%field(m), error, exact=sb%exact, contacts=contacts, share=level_share(study, part))
         if (allocated(error)) return
         call estimate_error(input, bl%field(m), bl%est(m), error, exact=sb%exact, share=level_share(study, part))
      else
         call recover_grid(input, bl%problem%mesh%grid, bl%problem%mesh%nodes, bl%problem%mesh%hanging, method, &
            & degree, bl%field(m), error, contacts=contacts, share=level_share(study, part))
         if (allocated(error)) return
         call estimate_error(input, bl%field(m), bl%est(m), error, share=level_share(study, part))
      end if
   end subroutine recover_and_estimate

   !> `part` (the study's partition) when the level's element work is shared
   !> out among ranks, else null: an absent `share`.
   function level_share(study, part) result(share)
      type(study_type), intent(in) :: study
      type(partition_type), intent(in), target :: part
      class(share_type), pointer :: share
      share => null()
      if (part%shared()) share => part
   end function level_share

end module sprc_study_run_estimate
