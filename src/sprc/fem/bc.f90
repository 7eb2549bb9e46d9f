!> Boundary conditions of the FE layer on a body's shape surfaces (doc/scene.md
!> `&bc`), as plain data: which shape, which kind (`sprc_core_boundary`'s
!> vocabulary, re-exported here), a value and a vector.
!>
!> Every surface quadrature point carries the index of the shape whose surface
!> it lies on; the condition of that shape applies there. A shape with no
!> condition is traction-free. Kinds and their data:
!> - free: t = 0;
!> - pressure (value): t = -value n, n the outward normal;
!> - traction (vector(dim)): t = vector;
!> - displacement (vector(dim)): u = vector, weakly (Nitsche);
!> - symmetry: u.n = 0 and zero shear traction; strongly on a halfspace that
!>   lies on grid planes, weakly (Nitsche on u.n) otherwise;
!> - exact_traction: t = sigma_exact n; exact_displacement: u = u_exact
!>   (weakly), both from an exact solution the caller supplies.
module sprc_fem_bc
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_boundary, only: bc_free, bc_pressure, bc_traction, bc_displacement, bc_symmetry, &
      & bc_exact_traction, bc_exact_displacement, bc_kind_name, bc_kind_from_name
   implicit none
   private

   public :: fe_bc_type, new_fe_bc, check_bcs, bc_kind_name, bc_kind_from_name
   public :: bc_free, bc_pressure, bc_traction, bc_displacement, bc_symmetry, bc_exact_traction, &
      & bc_exact_displacement

   !> One boundary condition on the surface of shape `shape` of the body.
   type :: fe_bc_type
      !> Surface of the body: a shape index (1..nshape) or a faceted group's
      !> surface id (sprc_geometry_body notes).
      integer :: shape = 0
      !> One of the kinds of `sprc_core_boundary` an FE condition can have:
      !> free, pressure, traction, displacement, symmetry, exact_traction, exact_displacement.
      integer :: kind = bc_free
      !> Pressure (kind pressure).
      real(wp) :: value = 0.0_wp
      !> Traction or displacement vector, size dim (kinds traction, displacement).
      real(wp), allocatable :: vector(:)
   end type fe_bc_type

contains

   !> A condition; `vector` is needed by traction and displacement only.
   pure function new_fe_bc(shape, kind, value, vector) result(bc)
      integer, intent(in) :: shape, kind
      real(wp), intent(in), optional :: value
      real(wp), intent(in), optional :: vector(:)
      type(fe_bc_type) :: bc
      bc%shape = shape
      bc%kind = kind
      if (present(value)) bc%value = value
      if (present(vector)) then
         bc%vector = vector
      else
         allocate (bc%vector(0))
      end if
   end function new_fe_bc

   !> Validate conditions for a body of `nshape` surfaces (its shapes, then its
   !> faceted groups: sprc_geometry_body notes) in dimension `dim`: surface index in range and not repeated, known kind, finite data, vector of
   !> size dim where needed, an exact solution (`have_exact`) for exact_* kinds.
   pure subroutine check_bcs(bcs, nshape, dim, have_exact, error)
      type(fe_bc_type), intent(in) :: bcs(:)
      integer, intent(in) :: nshape, dim
      logical, intent(in) :: have_exact
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: where
      integer :: i, nvec

      do i = 1, size(bcs)
         where = 'boundary condition '//itoa(i)//': '
         if (bcs(i)%shape < 1 .or. bcs(i)%shape > nshape) then
            call fatal_error(error, where//'unknown shape index '//itoa(bcs(i)%shape)//' (the body has '// &
               & itoa(nshape)//' shapes)', stat_invalid_input)
            return
         end if
         if (any(bcs(1:i - 1)%shape == bcs(i)%shape)) then
            call fatal_error(error, where//'shape '//itoa(bcs(i)%shape)//' already has a condition', &
               & stat_invalid_input)
            return
         end if
         if (.not. any(bcs(i)%kind == [bc_free, bc_pressure, bc_traction, bc_displacement, bc_symmetry, &
            & bc_exact_traction, bc_exact_displacement])) then
            call fatal_error(error, where//'unknown kind '//itoa(bcs(i)%kind), stat_invalid_input)
            return
         end if
         nvec = 0
         if (allocated(bcs(i)%vector)) nvec = size(bcs(i)%vector)
         select case (bcs(i)%kind)
         case (bc_traction, bc_displacement)
            if (nvec /= dim) then
               call fatal_error(error, where//bc_kind_name(bcs(i)%kind)//' needs a vector of '//itoa(dim)// &
                  & ' values, got '//itoa(nvec), stat_invalid_input)
               return
            end if
            if (.not. all(abs(bcs(i)%vector) <= huge(1.0_wp))) then
               call fatal_error(error, where//'vector must be finite', stat_invalid_input)
               return
            end if
         case (bc_pressure)
            if (.not. abs(bcs(i)%value) <= huge(1.0_wp)) then
               call fatal_error(error, where//'pressure value must be finite', stat_invalid_input)
               return
            end if
         case (bc_exact_traction, bc_exact_displacement)
            if (.not. have_exact) then
               call fatal_error(error, where//bc_kind_name(bcs(i)%kind)//' needs an exact solution, none given', &
                  & stat_invalid_input)
               return
            end if
         end select
      end do
   end subroutine check_bcs

end module sprc_fem_bc
