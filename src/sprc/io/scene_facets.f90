!> The faceted shapes of a scene (kinds 'stl', 'obj', 'polygon'): their
!> surface read from a file or from `points`, placed (scale, translate),
!> validated (`sprc_geometry_facet_check`); the groups of their files as
!> surfaces for `&bc on`; their lines in `sprc check`.
module sprc_io_scene_facets
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error
   use sprc_core_text, only: itoa, real_text
   use sprc_geometry_facet_check, only: check_facets, facet_measures, facet_bounds, group_measure
   use sprc_study_spec, only: shape_spec_type
   use sprc_io_stl, only: read_stl
   use sprc_io_obj, only: read_obj
   use sprc_io_polygon, only: read_polygon_file, polygon_from_points
   use sprc_io_facet_file, only: place_facets
   implicit none
   private

   public :: facet_kind, load_facets, group_surface, facet_summary, scene_relative

contains

   pure logical function facet_kind(kind)
      character(len=*), intent(in) :: kind
      facet_kind = kind == 'stl' .or. kind == 'obj' .or. kind == 'polygon'
   end function facet_kind

   !> `file` as seen from the directory of the scene file `scene_source`
   !> (unchanged when absolute or when the scene is in the working directory).
   pure function scene_relative(scene_source, file) result(path)
      character(len=*), intent(in) :: scene_source, file
      character(len=:), allocatable :: path
      integer :: slash
      path = file
      if (len(file) == 0) return
      if (file(1:1) == '/') return
      slash = index(scene_source, '/', back=.true.)
      if (slash > 0) path = scene_source(1:slash)//file
   end function scene_relative

   !> Read `shape%facets` as its kind and fields say, place and validate them;
   !> `shape%note` keeps what validation has to tell.
   subroutine load_facets(scene_source, shape, error)
      character(len=*), intent(in) :: scene_source
      type(shape_spec_type), intent(inout) :: shape
      type(error_type), allocatable, intent(out) :: error

      if (allocated(shape%points)) then
         call polygon_from_points(shape%points, 'points', shape%facets, error)
      else
         select case (shape%kind)
         case ('stl'); call read_stl(scene_relative(scene_source, shape%file), shape%facets, error)
         case ('obj'); call read_obj(scene_relative(scene_source, shape%file), shape%facets, error)
         case default; call read_polygon_file(scene_relative(scene_source, shape%file), shape%facets, error)
         end select
      end if
      if (allocated(error)) return
      call place_facets(shape%facets, shape%scale, shape%translate)
      call check_facets(shape%facets, shape%note, error)
   end subroutine load_facets

   !> The faceted shape and group that a surface name `name` means: a group
   !> of exactly one faceted shape's file; an error when none or several.
   subroutine group_surface(shapes, name, shape, group, error)
      type(shape_spec_type), intent(in) :: shapes(:)
      character(len=*), intent(in) :: name
      integer, intent(out) :: shape, group
      type(error_type), allocatable, intent(out) :: error
      integer :: k, g

      shape = 0
      group = 0
      do k = 1, size(shapes)
         if (.not. allocated(shapes(k)%facets%group_name)) cycle
         do g = 1, size(shapes(k)%facets%group_name)
            if (shapes(k)%facets%group_name(g) /= name) cycle
            if (shape /= 0) then
               call fatal_error(error, "is a group of the files of shapes '"//shapes(shape)%name//"' and '"// &
                  & shapes(k)%name//"': rename one in its file")
               return
            end if
            shape = k
            group = g
         end do
      end do
      if (shape /= 0) return
      if (any([(facet_kind(shapes(k)%kind), k=1, size(shapes))])) then
         call fatal_error(error, 'no &shape has this name, nor a group (solid, g, o, edge name) of a geometry file')
      else
         call fatal_error(error, 'no &shape has this name')
      end if
   end subroutine group_surface

   !> Lines of `sprc check` for a faceted shape: facets, box, measures, named
   !> surfaces with their areas, and whether the level-0 cell holds it.
   function facet_summary(shape, box_min, box_size) result(text)
      type(shape_spec_type), intent(in) :: shape
      real(wp), intent(in) :: box_min(:), box_size
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      real(wp) :: lo(3), hi(3), volume, area
      integer :: d, g

      associate (f => shape%facets)
         d = f%dim
         call facet_bounds(f, lo, hi)
         call facet_measures(f, volume, area)
         text = '    '//itoa(f%nfacet)//' '//trim(merge('facets  ', 'segments', d == 3))//', '//itoa(f%nvert)// &
            & ' vertices from '//f%source//nl
         text = text//'    bounding box '//point(lo(1:d))//' .. '//point(hi(1:d))//nl
         text = text//'    '//trim(merge('volume', 'area  ', d == 3))//' = '//real_text(volume)//', '// &
            & trim(merge('area     ', 'perimeter', d == 3))//' = '//real_text(area)//nl
         text = text//"    surfaces: '"//shape%name//"' (all, "//real_text(area)//')'
         do g = 1, size(f%group_name)
            text = text//", '"//trim(f%group_name(g))//"' ("//real_text(group_measure(f, g))//')'
         end do
         text = text//nl//'    inside the level-0 box: '
         if (all(lo(1:d) >= box_min(1:d)) .and. all(hi(1:d) <= box_min(1:d) + box_size)) then
            text = text//'yes'//nl
         else
            text = text//'no: it reaches beyond the box '//point(box_min(1:d))//' .. '// &
               & point(box_min(1:d) + box_size)//"; the body's other shapes must cut it to the box"//nl
         end if
      end associate
   end function facet_summary

   function point(x) result(text)
      real(wp), intent(in) :: x(:)
      character(len=:), allocatable :: text
      integer :: i
      text = '('
      do i = 1, size(x)
         if (i > 1) text = text//', '
         text = text//real_text(x(i))
      end do
      text = text//')'
   end function point

end module sprc_io_scene_facets
