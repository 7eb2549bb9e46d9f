!> What the readers of faceted geometry (STL, OBJ, polygon files) share:
!> opening a file with every failure named (missing, a directory, unreadable),
!> refusing one whose facets would not fit in memory before reading it, reading
!> its bytes, walking its lines and words, growing arrays, and placing the
!> result (scale, then translate).
module sprc_io_facet_file
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_out_of_memory
   use sprc_core_alloc, only: check_allocation
   use sprc_core_memory, only: available_memory
   use sprc_core_text, only: itoa, byte_text
   use sprc_geometry_facets, only: facet_set_type
   use sprc_study_budget, only: memory_check_wanted
   use sprc_io_file, only: file_size, read_bytes
   implicit none
   private

   public :: file_size, check_facet_memory, read_bytes, next_line, next_word, to_real, grow, place_facets
   public :: group_of, facet_bytes

   !> Bytes per facet while a surface is read and validated: vertices (three
   !> per facet before they are merged), facet, group and file index, the
   !> sort keys and orders of the vertex merge and of the edge matching.
   integer, parameter :: facet_bytes = 400

   interface grow
      module procedure grow_real, grow_int
   end interface grow

contains

   !> Refuse, before reading, a file whose `nfacet` facets (an upper estimate)
   !> and `size` bytes would not fit in the memory this process may use
   !> (`sprc_core_memory`; SPRC_MEMORY_CHECK=off skips the check).
   subroutine check_facet_memory(path, size, nfacet, error)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: size, nfacet
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: avail
      real(wp) :: need
      character(len=:), allocatable :: source
      logical :: wanted

      call memory_check_wanted(wanted, error)
      if (allocated(error) .or. .not. wanted) return
      call available_memory(avail, source)
      need = real(size, wp) + real(nfacet, wp)*real(facet_bytes, wp)
      if (avail < 0 .or. need <= real(avail, wp)) return
      call fatal_error(error, "'"//path//"': reading about "//itoa(nfacet)//' facets needs about '// &
         & byte_text(need)//' of memory, but '//byte_text(real(avail, wp))//' is available ('//source//')', &
         & stat_out_of_memory)
   end subroutine check_facet_memory

   !> The next line of `text` from `pos`: text(first:last), without the line
   !> end; `pos` moves past it and `line` counts. False at the end.
   logical function next_line(text, pos, line, first, last) result(found)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: pos, line
      integer, intent(out) :: first, last
      integer :: nl

      found = pos <= len(text)
      first = pos
      last = pos - 1
      if (.not. found) return
      nl = index(text(pos:), achar(10))
      if (nl == 0) then
         last = len(text)
      else
         last = pos + nl - 2
      end if
      pos = last + 2
      line = line + 1
      if (last >= first) then
         if (text(last:last) == achar(13)) last = last - 1
      end if
   end function next_line

   !> The next word of `line` from `pos` (blanks, tabs and commas separate
   !> words); '' at the end.
   function next_word(line, pos) result(word)
      character(len=*), intent(in) :: line
      integer, intent(inout) :: pos
      character(len=:), allocatable :: word
      character(len=*), parameter :: seps = ' ,'//achar(9)//achar(11)//achar(12)//achar(13)
      integer :: start

      do while (pos <= len(line))
         if (index(seps, line(pos:pos)) == 0) exit
         pos = pos + 1
      end do
      start = pos
      do while (pos <= len(line))
         if (index(seps, line(pos:pos)) > 0) exit
         pos = pos + 1
      end do
      word = line(start:pos - 1)
   end function next_word

   !> A real from a word; false unless the whole word is a number (NaN and
   !> Infinity are numbers here: validation names them with their facet).
   logical function to_real(word, x) result(ok)
      character(len=*), intent(in) :: word
      real(wp), intent(out) :: x
      integer :: ios
      x = 0.0_wp
      ok = len(word) > 0 .and. len(word) < 64 .and. verify(word, '0123456789+-.eEdDnNaAiIfFtTyY') == 0
      if (.not. ok) return
      read (word, *, iostat=ios) x
      ok = ios == 0
   end function to_real

   !> Grow the last dimension of `a` to at least `n` (doubling).
   subroutine grow_real(a, n, error)
      real(wp), allocatable, intent(inout) :: a(:, :)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: b(:, :)
      integer :: stat
      if (size(a, 2) >= n) return
      allocate (b(size(a, 1), max(n, 2*size(a, 2), 64)), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'geometry file reader', 'vertices', int(size(b, kind=i8), i8), 8, error)
      if (allocated(error)) return
      b(:, 1:size(a, 2)) = a
      call move_alloc(b, a)
   end subroutine grow_real

   subroutine grow_int(a, n, error)
      integer, allocatable, intent(inout) :: a(:, :)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: b(:, :)
      integer :: stat
      if (size(a, 2) >= n) return
      allocate (b(size(a, 1), max(n, 2*size(a, 2), 64)), source=0, stat=stat)
      call check_allocation(stat, 'geometry file reader', 'facets', int(size(b, kind=i8), i8), 4, error)
      if (allocated(error)) return
      b(:, 1:size(a, 2)) = a
      call move_alloc(b, a)
   end subroutine grow_int

   !> Index of group `name` in `names(1:n)`, added if new; 0 for ''.
   integer function group_of(names, n, name) result(g)
      character(len=64), allocatable, intent(inout) :: names(:)
      integer, intent(inout) :: n
      character(len=*), intent(in) :: name
      character(len=64), allocatable :: more(:)

      g = 0
      if (len_trim(name) == 0) return
      do g = 1, n
         if (names(g) == name) return
      end do
      if (n == size(names)) then
         allocate (more(max(8, 2*n)))
         more(1:n) = names(1:n)
         call move_alloc(more, names)
      end if
      n = n + 1
      names(n) = name
      g = n
   end function group_of

   !> x -> scale*x + translate on every vertex.
   pure subroutine place_facets(set, scale, translate)
      type(facet_set_type), intent(inout) :: set
      real(wp), intent(in) :: scale
      real(wp), intent(in) :: translate(:)
      integer :: i
      do i = 1, min(size(translate), 3)
         set%vert(i, 1:set%nvert) = scale*set%vert(i, 1:set%nvert) + translate(i)
      end do
   end subroutine place_facets

end module sprc_io_facet_file
