!> STL files, ASCII and binary, into a `facet_set_type` (not yet validated:
!> `sprc_geometry_facet_check` does that).
!>
!> Binary is recognised by its size, 84 + 50 n bytes with n the count at
!> bytes 81..84, never by its first word: CAD systems write binary files whose
!> 80-byte header starts with "solid". A file of another size is ASCII if it
!> starts with "solid", else a binary whose count does not match its size.
!> Binary numbers are little-endian (the format's definition), decoded from
!> bytes so the host's byte order does not matter. The normals in the file are
!> ignored: the vertex order defines the orientation. Each ASCII
!> `solid NAME ... endsolid` is the group NAME; a binary file has no groups.
module sprc_io_stl
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_geometry_facets, only: facet_set_type
   use sprc_io_facet_file, only: file_size, check_facet_memory, read_bytes, next_line, next_word, to_real, grow, &
      & group_of
   implicit none
   private

   public :: read_stl

   !> Fewest bytes of one ASCII facet ("facet normal 0 0 0", "outer loop",
   !> three "vertex 0 0 0", "endloop", "endfacet"): bounds the facet count.
   integer, parameter :: ascii_facet_bytes = 80
   !> Bytes no ASCII STL holds: the controls but tab, line feed, vertical tab,
   !> form feed and carriage return.
   character(len=*), parameter :: control_bytes = achar(0)//achar(1)//achar(2)//achar(3)//achar(4)//achar(5)// &
      & achar(6)//achar(7)//achar(8)//achar(14)//achar(15)//achar(16)//achar(17)//achar(18)//achar(19)// &
      & achar(20)//achar(21)//achar(22)//achar(23)//achar(24)//achar(25)//achar(26)//achar(27)//achar(28)// &
      & achar(29)//achar(30)//achar(31)//achar(127)

contains

   subroutine read_stl(path, set, error)
      character(len=*), intent(in) :: path
      type(facet_set_type), intent(out) :: set
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: size, count
      character(len=:), allocatable :: head

      set%source = path
      set%dim = 3
      call file_size(path, size, error)
      if (allocated(error)) return
      if (size == 0) then
         call fatal_error(error, "'"//path//"': empty file (an STL file has a header and facets)", stat_invalid_input)
         return
      end if
      call read_bytes(path, 1_i8, min(size, 84_i8), head, error)
      if (allocated(error)) return
      count = -1
      if (size >= 84) count = uint32(head(81:84))
      if (count >= 0 .and. size == 84 + 50*count) then
         call check_facet_memory(path, size, count, error)
         if (.not. allocated(error)) call read_binary(path, size, int(count), set, error)
      else if (starts_solid(head)) then
         call check_facet_memory(path, size, size/ascii_facet_bytes + 1, error)
         if (.not. allocated(error)) call read_ascii(path, size, set, error)
         if (allocated(error)) then
            if (error%stat == -1) call fatal_error(error, "'"//path//"': starts with ""solid"" but has bytes no "// &
               & 'ASCII STL has, and as a binary STL its size does not match: the header says '//itoa(count)// &
               & ' facets (84 + 50*'//itoa(count)//' = '//itoa(84 + 50*count)//' bytes), the file has '// &
               & itoa(size)//' bytes (truncated or padded)', stat_invalid_input)
         end if
      else if (size < 84) then
         call fatal_error(error, "'"//path//"': truncated: "//itoa(size)//' bytes, shorter than the 84-byte header '// &
            & 'of a binary STL, and not ASCII (it does not start with "solid")', stat_invalid_input)
      else
         call fatal_error(error, "'"//path//"': the facet count does not match the size: the binary header says "// &
            & itoa(count)//' facets (84 + 50*'//itoa(count)//' = '//itoa(84 + 50*count)//' bytes) but the file has '// &
            & itoa(size)//' bytes (truncated or padded; an ASCII STL starts with "solid")', stat_invalid_input)
      end if
   end subroutine read_stl

   logical function starts_solid(head)
      character(len=*), intent(in) :: head
      integer :: i
      i = verify(head, ' '//achar(9)//achar(10)//achar(13))
      starts_solid = .false.
      if (i == 0 .or. i + 4 > len(head)) return
      starts_solid = head(i:i + 4) == 'solid'
   end function starts_solid

   !> Unsigned little-endian integer of 4 bytes.
   pure integer(i8) function uint32(b)
      character(len=4), intent(in) :: b
      uint32 = int(ichar(b(1:1)), i8) + 256_i8*(int(ichar(b(2:2)), i8) + 256_i8*(int(ichar(b(3:3)), i8) + &
         & 256_i8*int(ichar(b(4:4)), i8)))
   end function uint32

   !> IEEE single of 4 little-endian bytes.
   pure real(wp) function float32(b)
      character(len=4), intent(in) :: b
      integer, parameter :: sp = selected_real_kind(6, 37)
      integer :: bits
      bits = ior(ior(ichar(b(1:1)), ishft(ichar(b(2:2)), 8)), ior(ishft(ichar(b(3:3)), 16), ishft(ichar(b(4:4)), 24)))
      float32 = real(transfer(bits, 1.0_sp), wp)
   end function float32

   subroutine read_binary(path, size, n, set, error)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: size
      integer, intent(in) :: n
      type(facet_set_type), intent(inout) :: set
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      integer :: k, j, i, at

      call read_bytes(path, 85_i8, size, text, error)
      if (allocated(error)) return
      call allocate_set(set, n, error)
      if (allocated(error)) return
      do k = 1, n
         at = 50*(k - 1) + 12
         do j = 1, 3
            do i = 1, 3
               set%vert(i, 3*(k - 1) + j) = float32(text(at + 1:at + 4))
               at = at + 4
            end do
            set%facet(j, k) = 3*(k - 1) + j
         end do
         set%file_index(k) = k - 1
      end do
      set%group = 0
      allocate (set%group_name(0))
   end subroutine read_binary

   subroutine allocate_set(set, n, error)
      type(facet_set_type), intent(inout) :: set
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer :: stat
      set%nfacet = n
      set%nvert = 3*n
      allocate (set%vert(3, 3*n), set%facet(3, n), set%group(n), set%file_index(n), stat=stat)
      call check_allocation(stat, "read '"//set%source//"'", 'facets', int(n, i8), 200, error)
   end subroutine allocate_set

   !> The ASCII form, line by line: `solid`, `facet`, `outer loop`, three
   !> `vertex x y z`, `endloop`, `endfacet`, `endsolid`.
   subroutine read_ascii(path, size, set, error)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: size
      type(facet_set_type), intent(inout) :: set
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, word
      real(wp), allocatable :: vert(:, :)
      integer, allocatable :: grp(:, :)
      character(len=64), allocatable :: names(:)
      integer :: pos, line, first, last, at, nv, nf, ng, group, state

      call read_bytes(path, 1_i8, size, text, error)
      if (allocated(error)) return
      ! Control bytes (other than tab, line and page ends) mark a binary file.
      if (scan(text, control_bytes) > 0) then
         call fatal_error(error, 'binary', -1)
         return
      end if
      allocate (vert(3, 0), grp(1, 0), names(0))
      pos = 1
      line = 0
      nv = 0
      nf = 0
      ng = 0
      group = -1
      ! state: 0 between solids, 1 in a solid, 2 in a facet, 3 in its loop, 4 loop closed
      state = 0
      do while (next_line(text, pos, line, first, last))
         at = 1
         word = next_word(text(first:last), at)
         if (len(word) == 0) cycle
         call ascii_line(text(first:last), at, word, state, vert, nv, grp, nf, names, ng, group, error)
         if (allocated(error)) then
            error%message = "'"//path//"':"//itoa(line)//': facet '//itoa(nf)//': '//error%message
            return
         end if
      end do
      if (state /= 0) then
         if (state >= 2) then
            call fatal_error(error, "'"//path//"': truncated: the file ends inside facet "//itoa(nf), stat_invalid_input)
         else
            call fatal_error(error, "'"//path//"': truncated: the file ends inside a solid (no endsolid)", &
               & stat_invalid_input)
         end if
         return
      end if
      set%nvert = nv
      set%nfacet = nf
      set%vert = vert(:, 1:nv)
      set%facet = reshape([(at, at=1, nv)], [3, nf])
      set%group = grp(1, 1:nf)
      set%file_index = [(at - 1, at=1, nf)]
      set%group_name = names(1:ng)
   end subroutine read_ascii

   !> One line of an ASCII STL whose first word is `word` (the rest from `at`).
   subroutine ascii_line(line, at, word, state, vert, nv, grp, nf, names, ng, group, error)
      character(len=*), intent(in) :: line, word
      integer, intent(inout) :: at, state, nv, nf, ng, group
      real(wp), allocatable, intent(inout) :: vert(:, :)
      integer, allocatable, intent(inout) :: grp(:, :)
      character(len=64), allocatable, intent(inout) :: names(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: expected(0:4) = [character(len=24) :: '"solid"', '"facet" or "endsolid"', &
         & '"outer loop"', '"vertex" or "endloop"', '"endfacet"']
      character(len=:), allocatable :: name
      integer :: i

      select case (state*100 + keyword(word))
      case (1)
         name = trim(adjustl(line(at:)))
         if (len(name) > len(names)) then
            call fatal_error(error, 'the solid name "'//name//'" is longer than '//itoa(len(names))//' characters')
            return
         end if
         group = group_of(names, ng, name)
         state = 1
      case (102); state = 2
      case (106); state = 0
      case (203); state = 3
      case (304)
         if (nv - 3*nf == 3) then
            call fatal_error(error, 'more than three vertices (STL facets are triangles)')
            return
         end if
         call grow(vert, nv + 1, error)
         if (allocated(error)) return
         nv = nv + 1
         do i = 1, 3
            if (to_real(next_word(line, at), vert(i, nv))) cycle
            call fatal_error(error, 'vertex: expected three numbers: "'//trim(line)//'"')
            return
         end do
      case (305)
         if (nv - 3*nf /= 3) then
            call fatal_error(error, itoa(nv - 3*nf)//' vertices (an STL facet has three)')
            return
         end if
         state = 4
      case (407)
         call grow(grp, nf + 1, error)
         if (allocated(error)) return
         nf = nf + 1
         grp(1, nf) = group
         state = 1
      case default
         call fatal_error(error, 'expected '//trim(expected(state))//', found "'//word//'"')
      end select
   end subroutine ascii_line

   pure integer function keyword(word)
      character(len=*), intent(in) :: word
      select case (word)
      case ('solid'); keyword = 1
      case ('facet'); keyword = 2
      case ('outer'); keyword = 3
      case ('vertex'); keyword = 4
      case ('endloop'); keyword = 5
      case ('endsolid'); keyword = 6
      case ('endfacet'); keyword = 7
      case default; keyword = 0
      end select
   end function keyword

end module sprc_io_stl
