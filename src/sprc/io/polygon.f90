!> 2D polygons into a `facet_set_type` of segments (not yet validated): from
!> the values of `points = x1,y1, x2,y2, ...` or from a file of one vertex per
!> line, `x y [name]` (blanks or commas between; `#` starts a comment), where
!> `name` names the edge that starts at that vertex (a surface of its own).
!> Vertex i and its edge (to vertex i+1, the last to the first) are numbered
!> i-1 in messages: the vertex's number in the list.
module sprc_io_polygon
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error
   use sprc_core_text, only: itoa
   use sprc_geometry_facets, only: facet_set_type
   use sprc_io_facet_file, only: file_size, check_facet_memory, read_bytes, next_line, next_word, to_real, grow, &
      & group_of
   implicit none
   private

   public :: read_polygon_file, polygon_from_points

   !> Fewest bytes of a vertex line ("0 0" and a line end).
   integer, parameter :: polygon_line_bytes = 4

contains

   !> The polygon of `points` (x1, y1, x2, y2, ...); `source` names it.
   subroutine polygon_from_points(points, source, set, error)
      real(wp), intent(in) :: points(:)
      character(len=*), intent(in) :: source
      type(facet_set_type), intent(out) :: set
      type(error_type), allocatable, intent(out) :: error
      integer :: n

      n = size(points)/2
      if (mod(size(points), 2) /= 0) then
         call fatal_error(error, "'"//source//"': "//itoa(size(points))//' values: expected pairs x, y')
         return
      end if
      allocate (set%group_name(0))
      call make_polygon(reshape(points(1:2*n), [2, n]), [(0, n=1, size(points)/2)], source, set, error)
   end subroutine polygon_from_points

   subroutine read_polygon_file(path, set, error)
      character(len=*), intent(in) :: path
      type(facet_set_type), intent(out) :: set
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, word, name
      real(wp), allocatable :: xy(:, :)
      integer, allocatable :: grp(:, :)
      integer(i8) :: size
      integer :: pos, line, first, last, at, n, ng, hash, i

      call file_size(path, size, error)
      if (allocated(error)) return
      call check_facet_memory(path, size, size/polygon_line_bytes + 1, error)
      if (.not. allocated(error)) call read_bytes(path, 1_i8, size, text, error)
      if (allocated(error)) return
      allocate (xy(2, 0), grp(1, 0), set%group_name(0))
      pos = 1
      line = 0
      n = 0
      ng = 0
      do while (next_line(text, pos, line, first, last))
         hash = index(text(first:last), '#')
         if (hash > 0) last = first + hash - 2
         at = 1
         if (len(next_word(text(first:last), at)) == 0) cycle
         call grow(xy, n + 1, error)
         if (.not. allocated(error)) call grow(grp, n + 1, error)
         if (allocated(error)) return
         n = n + 1
         at = 1
         do i = 1, 2
            word = next_word(text(first:last), at)
            if (to_real(word, xy(i, n))) cycle
            call fatal_error(error, "'"//path//"':"//itoa(line)//': vertex '//itoa(n - 1)// &
               & ': expected x y [edge name], found "'//text(first:last)//'"')
            return
         end do
         name = trim(adjustl(text(first + at - 1:last)))
         if (len(name) > 0) then
            if (name(1:1) == ',') name = trim(adjustl(name(2:)))
         end if
         if (len(name) > len(set%group_name)) then
            call fatal_error(error, "'"//path//"':"//itoa(line)//': vertex '//itoa(n - 1)//': the edge name "'// &
               & name//'" is longer than '//itoa(len(set%group_name))//' characters')
            return
         end if
         grp(1, n) = group_of(set%group_name, ng, name)
      end do
      set%group_name = set%group_name(1:ng)
      call make_polygon(xy(:, 1:n), grp(1, 1:n), path, set, error)
   end subroutine read_polygon_file

   !> Vertices `xy` joined in order and closed; edge i starts at vertex i and
   !> belongs to group `group(i)`.
   subroutine make_polygon(xy, group, source, set, error)
      real(wp), intent(in) :: xy(:, :)
      integer, intent(in) :: group(:)
      character(len=*), intent(in) :: source
      type(facet_set_type), intent(inout) :: set
      type(error_type), allocatable, intent(out) :: error
      integer :: n, i

      n = size(xy, 2)
      set%source = source
      set%dim = 2
      if (n < 3) then
         call fatal_error(error, "'"//source//"': "//itoa(n)//' vertices: a polygon needs at least three')
         return
      end if
      set%nvert = n
      set%nfacet = n
      allocate (set%vert(3, n), source=0.0_wp)
      set%vert(1:2, :) = xy
      set%facet = reshape([([i, mod(i, n) + 1], i=1, n)], [2, n])
      set%group = group
      set%file_index = [(i - 1, i=1, n)]
   end subroutine make_polygon

end module sprc_io_polygon
