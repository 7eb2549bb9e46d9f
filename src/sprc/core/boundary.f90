!> The boundary kinds of sprc: one vocabulary for the scene's `&bc` types,
!> the FE conditions (`sprc_fem_bc`), the recovery input on a grid
!> (`sprc_estimate_patches`), the facets of a caller's mesh
!> (`sprc_recovery_caller_mesh`) and the boundary points of a patch
!> (`sprc_recovery_patch`). Each layer accepts the kinds that mean something
!> to it and says which in its checks.
!>
!> Values are stable: traction, symmetry, free and pressure are the C API's
!> SPRC_FACET_TRACTION, SPRC_FACET_SYMMETRY, SPRC_FACET_FREE, SPRC_FACET_PRESSURE
!> (include/sprc.h).
module sprc_core_boundary
   implicit none
   private

   public :: bc_none, bc_traction, bc_symmetry, bc_free, bc_pressure, bc_displacement, bc_exact_traction, &
      & bc_exact_displacement, bc_contact
   public :: bc_kind_name, bc_kind_from_name

   !> No condition (a recovery input's surfaces without constraint: Dirichlet ones).
   integer, parameter :: bc_none = 0
   !> Prescribed traction t (a constant vector; t = 0 is a free surface).
   integer, parameter :: bc_traction = 1
   !> Symmetry plane: u.n = 0 and zero shear traction.
   integer, parameter :: bc_symmetry = 2
   !> Traction-free surface, t = 0.
   integer, parameter :: bc_free = 3
   !> Pressure p: t = -p n.
   integer, parameter :: bc_pressure = 4
   !> Prescribed displacement.
   integer, parameter :: bc_displacement = 5
   !> Traction sigma_exact n and displacement u_exact of an exact solution.
   integer, parameter :: bc_exact_traction = 6
   !> Displacement u_exact of an exact solution (weakly).
   integer, parameter :: bc_exact_displacement = 7
   !> A contact surface (the contact layer's).
   integer, parameter :: bc_contact = 8

   !> Names, as the scene spells them, of the kinds 1..8.
   character(len=*), parameter :: kind_names(8) = [character(len=18) :: 'traction', 'symmetry', 'free', &
      & 'pressure', 'displacement', 'exact_traction', 'exact_displacement', 'contact']

contains

   !> Name of a kind ('none' for bc_none); '' for a value that is no kind.
   pure function bc_kind_name(kind) result(name)
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      name = ''
      if (kind == bc_none) name = 'none'
      if (kind >= 1 .and. kind <= size(kind_names)) name = trim(kind_names(kind))
   end function bc_kind_name

   !> Kind of a name (as the scene spells it, or 'none'); -1 for an unknown name.
   pure integer function bc_kind_from_name(name) result(kind)
      character(len=*), intent(in) :: name
      if (trim(adjustl(name)) == 'none') then
         kind = bc_none
         return
      end if
      do kind = 1, size(kind_names)
         if (trim(adjustl(name)) == trim(kind_names(kind))) return
      end do
      kind = -1
   end function bc_kind_from_name

end module sprc_core_boundary
