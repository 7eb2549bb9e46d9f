!> The contract between geometry and the grid: a region answers, for an
!> axis-aligned box, whether the box lies inside it, outside it, or is cut.
!>
!> The answer must never miss a cut: `cell_inside` only when the region covers
!> the whole box, `cell_outside` only when box and region share zero measure.
!> `cell_cut` may be returned conservatively (the quadrature later finds the
!> true measure), but aligned cases (faces on grid planes) must be exact.
module sprc_geometry_region
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: region_type, cell_outside, cell_inside, cell_cut

   !> Classes of a box: outside the region (zero measure in common),
   integer, parameter :: cell_outside = 0
   !> inside it (the region covers the whole box),
   integer, parameter :: cell_inside = 1
   !> or cut by its boundary (possibly conservatively).
   integer, parameter :: cell_cut = 2

   !> Anything that can classify boxes: a body built from shapes, or a test region.
   type, abstract :: region_type
   contains
      procedure(classify_box_interface), deferred :: classify_box
   end type region_type

   abstract interface
      !> Class of the box [lo, hi] (size(lo) = size(hi) = dimension).
      pure integer function classify_box_interface(self, lo, hi)
         import :: region_type, wp
         class(region_type), intent(in) :: self
         real(wp), intent(in) :: lo(:), hi(:)
      end function classify_box_interface
   end interface

end module sprc_geometry_region
