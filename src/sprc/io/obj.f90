!> Wavefront OBJ files into a `facet_set_type` (not yet validated).
!>
!> Read: `v x y z [w]` (w ignored), `f i j k ...` (each index as `i`, `i/t`,
!> `i//n` or `i/t/n`; 1-based, negative counts back from the last vertex read
!> so far), `g NAME` and `o NAME` (the group of the faces that follow; a
!> bare `g` ends the group). Every other statement (vn, vt, s, usemtl, mtllib,
!> l, comments) is ignored. A face of more than three vertices is fanned from
!> its first vertex when it is planar (every vertex within sqrt(eps) times its
!> diameter of the plane of its Newell normal) and strictly convex; otherwise
!> it is refused with its number. Faces are numbered 0-based in file order;
!> every triangle of a fan keeps its face's number.
module sprc_io_obj
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_facet_check, only: cross
   use sprc_io_facet_file, only: file_size, check_facet_memory, read_bytes, next_line, next_word, to_real, grow, &
      & group_of
   implicit none
   private

   public :: read_obj

   !> Bytes of a short face or vertex statement ("f 11 12 13", "v 0 0.5 1"
   !> and a line end): the facet count estimated from the file size (files of
   !> one-digit indices hold up to twice as many; the bytes per facet of
   !> `facet_bytes` are themselves an upper estimate).
   integer, parameter :: obj_line_bytes = 16

   !> Faces as read: the vertex indices of all faces in one list.
   type :: face_list_type
      integer :: nface = 0, nindex = 0
      !> (3, nface): first index in `index`, number of vertices, group.
      integer, allocatable :: face(:, :)
      !> (1, nindex): the vertex indices, resolved to 1-based.
      integer, allocatable :: index(:, :)
      !> (1, nface): the line of each face.
      integer, allocatable :: line(:, :)
   end type face_list_type

contains

   subroutine read_obj(path, set, error)
      character(len=*), intent(in) :: path
      type(facet_set_type), intent(out) :: set
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      type(face_list_type) :: faces
      integer(i8) :: size

      set%source = path
      set%dim = 3
      call file_size(path, size, error)
      if (allocated(error)) return
      call check_facet_memory(path, size, size/obj_line_bytes + 1, error)
      if (allocated(error)) return
      call read_bytes(path, 1_i8, size, text, error)
      if (allocated(error)) return
      call read_statements(path, text, set, faces, error)
      if (allocated(error)) return
      if (faces%nface == 0) then
         call fatal_error(error, "'"//path//"': no faces (an empty or truncated file? an OBJ solid needs 'f' lines)")
         return
      end if
      call triangulate(path, faces, set, error)
   end subroutine read_obj

   subroutine read_statements(path, text, set, faces, error)
      character(len=*), intent(in) :: path, text
      type(facet_set_type), intent(inout) :: set
      type(face_list_type), intent(inout) :: faces
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: word
      integer :: pos, line, first, last, at, group, ng, i

      allocate (set%vert(3, 0), faces%face(3, 0), faces%index(1, 0), faces%line(1, 0), set%group_name(0))
      pos = 1
      line = 0
      ng = 0
      group = 0
      do while (next_line(text, pos, line, first, last))
         at = 1
         word = next_word(text(first:last), at)
         select case (word)
         case ('v')
            call grow(set%vert, set%nvert + 1, error)
            if (allocated(error)) return
            set%nvert = set%nvert + 1
            do i = 1, 3
               if (to_real(next_word(text(first:last), at), set%vert(i, set%nvert))) cycle
               call fatal_error(error, "'"//path//"':"//itoa(line)//': vertex '//itoa(set%nvert)// &
                  & ': expected three numbers: "'//text(first:last)//'"')
               return
            end do
         case ('f')
            call read_face(text(first:last), at, set%nvert, group, line, faces, error)
            if (allocated(error)) then
               error%message = "'"//path//"':"//itoa(line)//': face '//itoa(faces%nface)//': '//error%message
               return
            end if
         case ('g', 'o')
            word = trim(adjustl(text(first + at - 1:last)))
            if (len(word) > len(set%group_name)) then
               call fatal_error(error, "'"//path//"':"//itoa(line)//': the group name "'//word//'" is longer than '// &
                  & itoa(len(set%group_name))//' characters')
               return
            end if
            group = group_of(set%group_name, ng, word)
         end select
      end do
      set%group_name = set%group_name(1:ng)
      set%vert = set%vert(:, 1:set%nvert)
   end subroutine read_statements

   !> One `f` statement: its vertex indices resolved against the `nvert`
   !> vertices read so far (negative) or checked later (positive).
   subroutine read_face(line, at, nvert, group, line_no, faces, error)
      character(len=*), intent(in) :: line
      integer, intent(inout) :: at
      integer, intent(in) :: nvert, group, line_no
      type(face_list_type), intent(inout) :: faces
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: word
      integer :: n, v, ios, slash

      n = 0
      do
         word = next_word(line, at)
         if (len(word) == 0) exit
         slash = index(word, '/')
         if (slash > 0) word = word(1:slash - 1)
         read (word, *, iostat=ios) v
         if (ios /= 0 .or. len(word) == 0 .or. verify(word, '+-0123456789') > 0) then
            call fatal_error(error, 'expected vertex indices, found "'//word//'"')
            return
         end if
         if (v < 0) v = nvert + 1 + v
         if (v <= 0) then
            call fatal_error(error, 'vertex index '//word//' is out of range (1..'//itoa(nvert)// &
               & ' or -1..-'//itoa(nvert)//' with '//itoa(nvert)//' vertices read so far)')
            return
         end if
         call grow(faces%index, faces%nindex + 1, error)
         if (allocated(error)) return
         faces%nindex = faces%nindex + 1
         faces%index(1, faces%nindex) = v
         n = n + 1
      end do
      if (n < 3) then
         call fatal_error(error, itoa(n)//' vertices (a face needs at least three)')
         return
      end if
      call grow(faces%face, faces%nface + 1, error)
      if (.not. allocated(error)) call grow(faces%line, faces%nface + 1, error)
      if (allocated(error)) return
      faces%nface = faces%nface + 1
      faces%face(:, faces%nface) = [faces%nindex - n + 1, n, group]
      faces%line(1, faces%nface) = line_no
   end subroutine read_face

   !> Triangles of all faces: each face's indices checked against the vertex
   !> count, polygons fanned when planar and convex.
   subroutine triangulate(path, faces, set, error)
      character(len=*), intent(in) :: path
      type(face_list_type), intent(in) :: faces
      type(facet_set_type), intent(inout) :: set
      type(error_type), allocatable, intent(out) :: error
      integer :: f, ntri, j, t, stat

      ntri = sum(faces%face(2, 1:faces%nface) - 2)
      allocate (set%facet(3, ntri), set%group(ntri), set%file_index(ntri), stat=stat)
      call check_allocation(stat, "read '"//path//"'", 'triangles', int(ntri, i8), 20, error)
      if (allocated(error)) return
      t = 0
      do f = 1, faces%nface
         associate (ids => faces%index(1, faces%face(1, f):faces%face(1, f) + faces%face(2, f) - 1))
            if (maxval(ids) > set%nvert) then
               call fatal_error(error, "'"//path//"':"//itoa(faces%line(1, f))//': face '//itoa(f - 1)// &
                  & ': vertex index '//itoa(maxval(ids))//' is out of range (the file has '//itoa(set%nvert)// &
                  & ' vertices)')
               return
            end if
            if (size(ids) > 3) call check_planar_convex(set%vert, ids, error)
            if (allocated(error)) then
               error%message = "'"//path//"':"//itoa(faces%line(1, f))//': face '//itoa(f - 1)//': '// &
                  & error%message
               return
            end if
            do j = 2, size(ids) - 1
               t = t + 1
               set%facet(:, t) = [ids(1), ids(j), ids(j + 1)]
               set%group(t) = faces%face(3, f)
               set%file_index(t) = f - 1
            end do
         end associate
      end do
      set%nfacet = ntri
   end subroutine triangulate

   !> A polygon that can be fanned: planar within sqrt(eps) of its diameter
   !> and strictly convex about its Newell normal.
   subroutine check_planar_convex(vert, ids, error)
      real(wp), intent(in) :: vert(:, :)
      integer, intent(in) :: ids(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: normal(3), p(3), q(3), r(3), diameter
      integer :: i, n

      n = size(ids)
      normal = 0.0_wp
      diameter = 0.0_wp
      do i = 1, n
         p = vert(:, ids(i))
         q = vert(:, ids(mod(i, n) + 1))
         normal = normal + [(p(2) - q(2))*(p(3) + q(3)), (p(3) - q(3))*(p(1) + q(1)), (p(1) - q(1))*(p(2) + q(2))]
         diameter = max(diameter, norm2(q - vert(:, ids(1))))
      end do
      if (.not. norm2(normal) > 0.0_wp) then
         call fatal_error(error, 'a polygon of '//itoa(n)//' vertices with no area: cannot be split into triangles')
         return
      end if
      normal = normal/norm2(normal)
      do i = 1, n
         p = vert(:, ids(i))
         q = vert(:, ids(mod(i, n) + 1))
         r = vert(:, ids(mod(i + 1, n) + 1))
         if (abs(dot_product(p - vert(:, ids(1)), normal)) > sqrt(epsilon(1.0_wp))*diameter) then
            call fatal_error(error, 'a polygon of '//itoa(n)//' vertices that is not planar (vertex '//itoa(i)// &
               & ' lies off its plane): split it into triangles')
            return
         end if
         if (.not. dot_product(cross(q - p, r - q), normal) > 0.0_wp) then
            call fatal_error(error, 'a polygon of '//itoa(n)//' vertices that is not convex (at vertex '// &
               & itoa(mod(i, n) + 1)//'): split it into triangles')
            return
         end if
      end do
   end subroutine check_planar_convex

end module sprc_io_obj
