!> A closed faceted surface bounding a solid: triangles in 3D (STL, OBJ),
!> segments in 2D (polygons). The solid is the region the surface encloses.
!>
!> Orientation: the outward normal of a triangle (a, b, c) is along
!> (b - a) x (c - a) (counter-clockwise seen from outside); the outward normal
!> of a segment (a, b) is along (b_y - a_y, a_x - b_x), i.e. a polygon given
!> counter-clockwise has its normals pointing out.
!>
!> Facets may belong to named groups (an ASCII STL `solid NAME`, an OBJ `g`/`o`
!> group, a polygon edge name); each group is a surface of its own for
!> boundary conditions, next to the shape's name for the whole surface.
!> `source` and `file_index` let every message name the file and the facet as
!> the file numbers it (0-based), also after polygons were fanned to triangles.
module sprc_geometry_facets
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: facet_set_type

   !> Vertices and oriented facets of one closed surface.
   type :: facet_set_type
      !> Space dimension: 2 (segments) or 3 (triangles); 0 while empty.
      integer :: dim = 0
      !> Number of vertices.
      integer :: nvert = 0
      !> Vertex coordinates (3, nvert) (dim used, the rest zero).
      real(wp), allocatable :: vert(:, :)
      !> Number of facets.
      integer :: nfacet = 0
      !> Facet vertices (dim, nfacet), 1-based indices into `vert`, oriented
      !> as in the module notes.
      integer, allocatable :: facet(:, :)
      !> Group of each facet (nfacet): index into `group_name`, 0 for none.
      integer, allocatable :: group(:)
      !> Names of the groups, (ngroup).
      character(len=64), allocatable :: group_name(:)
      !> Facet number as the source numbers it (0-based), (nfacet).
      integer, allocatable :: file_index(:)
      !> Where the facets came from (a file name, or 'points' for inline input).
      character(len=:), allocatable :: source
   end type facet_set_type

end module sprc_geometry_facets
