!> Validation and measures of a faceted surface (`facet_set_type`), before
!> anything is built on it. `check_facets` rejects, naming the source and the
!> facet as the source numbers it (0-based):
!> - no facets; a NaN or infinite coordinate;
!> - a zero-area triangle or zero-length segment: one whose cross product (or
!>   length) rounding cannot tell from zero. The coordinates carry a rounding
!>   error of eps*M (M the largest coordinate magnitude), so the cross product
!>   of edges e1, e2 is uncertain by about 2*eps*M*(|e1| + |e2|); a facet
!>   below `degenerate_factor` times that bound is refused;
!> - an open surface (an edge of one facet only), a non-manifold edge (of more
!>   than two), an inconsistent orientation (an edge two facets traverse in
!>   the same direction); in 2D the "edges" are the vertices of the segments;
!> - a closed surface that encloses no volume (signed volume below sqrt(eps)
!>   times the sum of the magnitudes of its terms: both sides coincide).
!> A closed surface oriented inwards (negative volume) is flipped and a note
!> says so. Vertices are first merged exactly by coordinates (a lexicographic
!> sort, three stable passes), edges matched by a sort on their vertex pairs:
!> O(n log n) throughout. In 2D segments must not cross or touch except at
!> the vertex two neighbours share: segments are binned on a grid of about n
!> cells over the box and only segments of one cell are compared (linear for
!> segments of comparable length; a few long segments cost their cell count).
!>
!> Orientation is checked per edge, so it is consistent within each connected
!> piece; a piece given with the opposite sign to the whole (a cavity written
!> outwards) is not detected: that needs an inside test of one piece in another.
module sprc_geometry_facet_check
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_alloc, only: check_allocation
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_sort, only: sort_order
   use sprc_core_text, only: itoa, real_text
   use sprc_geometry_facets, only: facet_set_type
   implicit none
   private

   public :: check_facets, facet_measures, facet_bounds, merge_vertices, group_measure, cross

   !> Multiple of the rounding bound of a cross product below which a facet is
   !> refused as degenerate (see the module notes).
   real(wp), parameter :: degenerate_factor = 4.0_wp
   !> Largest coordinate magnitude accepted: cubes of coordinates (volume
   !> terms) stay far from overflow.
   real(wp), parameter :: max_coordinate = 1.0e100_wp

   !> Edge problems, by the order in which they are reported for one edge.
   integer, parameter :: edge_ok = 0, edge_open = 1, edge_nonmanifold = 2, edge_orientation = 3

contains

   !> Validate `set` and normalise it (vertices merged, orientation outward).
   !> `note` is '' or a sentence for the user (the surface was flipped).
   subroutine check_facets(set, note, error)
      type(facet_set_type), intent(inout) :: set
      character(len=:), allocatable, intent(out) :: note
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: volume, area, scale

      note = ''
      if (set%nfacet == 0) then
         call fatal_error(error, "'"//set%source//"': no facets (an empty or truncated file?)", stat_invalid_input)
         return
      end if
      call check_finite(set, error)
      if (allocated(error)) return
      call merge_vertices(set, error)
      if (.not. allocated(error)) call check_degenerate(set, error)
      if (allocated(error)) return
      call check_edges(set, error)
      if (set%dim == 2 .and. .not. allocated(error)) call check_crossings(set, error)
      if (allocated(error)) return
      call facet_measures(set, volume, area, scale)
      if (.not. abs(volume) > sqrt(epsilon(1.0_wp))*scale) then
         call fatal_error(error, "'"//set%source//"': the closed surface encloses no "//trim(merge('volume', &
            & 'area  ', set%dim == 3))//' (signed '//real_text(volume)//'): its sides coincide', stat_invalid_input)
         return
      end if
      if (volume < 0.0_wp) then
         call flip(set)
         note = "'"//set%source//"': the closed surface was oriented inwards (its normals pointed into the solid); "// &
            & 'it was flipped'
      end if
   end subroutine check_facets

   !> Volume and boundary area enclosed by a closed surface (2D: area and
   !> perimeter), by the divergence theorem about the centre of its box.
   !> `scale`: the sum of the magnitudes of the volume terms (rounding scale).
   subroutine facet_measures(set, volume, area, scale)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(out) :: volume, area
      real(wp), intent(out), optional :: scale
      real(wp) :: lo(3), hi(3), c(3), t, s
      integer :: k

      call facet_bounds(set, lo, hi)
      c = 0.5_wp*(lo + hi)
      volume = 0.0_wp
      area = 0.0_wp
      s = 0.0_wp
      do k = 1, set%nfacet
         t = volume_term(set, k, c)
         volume = volume + t
         s = s + abs(t)
         area = area + facet_size(set, k)
      end do
      if (present(scale)) scale = s
   end subroutine facet_measures

   !> Area (2D: length) of the facets of group `g` (0: the whole surface).
   pure real(wp) function group_measure(set, g) result(m)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: g
      integer :: k
      m = 0.0_wp
      do k = 1, set%nfacet
         if (g == 0 .or. set%group(k) == g) m = m + facet_size(set, k)
      end do
   end function group_measure

   !> Bounding box of the vertices used by facets (unused dimensions zero).
   pure subroutine facet_bounds(set, lo, hi)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(out) :: lo(3), hi(3)
      integer :: k, j
      lo = huge(1.0_wp)
      hi = -huge(1.0_wp)
      do k = 1, set%nfacet
         do j = 1, set%dim
            lo = min(lo, set%vert(:, set%facet(j, k)))
            hi = max(hi, set%vert(:, set%facet(j, k)))
         end do
      end do
      if (set%nfacet == 0) then
         lo = 0.0_wp
         hi = 0.0_wp
      end if
   end subroutine facet_bounds

   !> Signed volume (2D: area) of the simplex of facet `k` and point `c`.
   pure real(wp) function volume_term(set, k, c) result(t)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: k
      real(wp), intent(in) :: c(3)
      real(wp) :: a(3), b(3)
      a = set%vert(:, set%facet(1, k)) - c
      b = set%vert(:, set%facet(2, k)) - c
      if (set%dim == 2) then
         t = 0.5_wp*(a(1)*b(2) - a(2)*b(1))
      else
         t = dot_product(a, cross(b, set%vert(:, set%facet(3, k)) - c))/6.0_wp
      end if
   end function volume_term

   !> Area of triangle `k` (2D: length of segment `k`).
   pure real(wp) function facet_size(set, k) result(s)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: k
      real(wp) :: a(3)
      a = set%vert(:, set%facet(1, k))
      if (set%dim == 2) then
         s = norm2(set%vert(:, set%facet(2, k)) - a)
      else
         s = 0.5_wp*norm2(cross(set%vert(:, set%facet(2, k)) - a, set%vert(:, set%facet(3, k)) - a))
      end if
   end function facet_size

   !> The vector product a x b.
   pure function cross(a, b) result(c)
      real(wp), intent(in) :: a(3), b(3)
      real(wp) :: c(3)
      c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
   end function cross

   !> Every coordinate finite and below `max_coordinate` in magnitude.
   subroutine check_finite(set, error)
      type(facet_set_type), intent(in) :: set
      type(error_type), allocatable, intent(out) :: error
      integer :: k, j
      do k = 1, set%nfacet
         do j = 1, set%dim
            associate (x => set%vert(:, set%facet(j, k)))
               if (.not. all(ieee_is_finite(x))) then
                  call fatal_error(error, facet_where(set, k)//'a coordinate is NaN or infinite', stat_invalid_input)
               else if (maxval(abs(x)) > max_coordinate) then
                  call fatal_error(error, facet_where(set, k)//'a coordinate of magnitude '// &
                     & real_text(maxval(abs(x)))//' exceeds '//real_text(max_coordinate)// &
                     & ' (volumes would overflow)', stat_invalid_input)
               end if
            end associate
            if (allocated(error)) return
         end do
      end do
   end subroutine check_finite

   !> 'SOURCE': facet N: ' with N as the source numbers the facet.
   pure function facet_where(set, k) result(text)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: k
      character(len=:), allocatable :: text
      text = "'"//set%source//"': "//trim(merge('facet  ', 'segment', set%dim == 3))//' '// &
         & itoa(set%file_index(k))//': '
   end function facet_where

   !> Merge vertices of equal coordinates (exactly; -0 equals 0) and renumber
   !> the facets; vertices no facet uses are kept.
   subroutine merge_vertices(set, error)
      type(facet_set_type), intent(inout) :: set
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: order(:), id(:)
      real(wp), allocatable :: merged(:, :)
      integer :: i, n, stat

      call lexicographic_order(set%vert(:, 1:set%nvert), set%dim, order)
      allocate (id(set%nvert), stat=stat)
      call check_allocation(stat, 'facet vertex merge', 'vertex numbers', int(set%nvert, i8), 4, error)
      if (allocated(error)) return
      n = 0
      do i = 1, set%nvert
         if (i == 1) then
            n = 1
         else if (any(abs(set%vert(:, order(i)) - set%vert(:, order(i - 1))) > 0.0_wp)) then
            n = n + 1
         end if
         id(order(i)) = n
      end do
      allocate (merged(3, n), stat=stat)
      call check_allocation(stat, 'facet vertex merge', 'merged vertices', 3_i8*n, 8, error)
      if (allocated(error)) return
      merged(:, id) = set%vert(:, 1:set%nvert)
      call move_alloc(merged, set%vert)
      set%nvert = n
      set%facet = reshape(id(reshape(set%facet, [size(set%facet)])), shape(set%facet))
   end subroutine merge_vertices

   !> Order of the columns of `x` sorted by rows 1..dim (row 1 first): stable
   !> passes from the last row to the first.
   subroutine lexicographic_order(x, dim, order)
      real(wp), intent(in) :: x(:, :)
      integer, intent(in) :: dim
      integer, allocatable, intent(out) :: order(:)
      integer, allocatable :: pass(:), work(:)
      integer :: i, k

      allocate (pass(size(x, 2)), work(size(x, 2)))
      order = [(i, i=1, size(x, 2))]
      do k = dim, 1, -1
         call sort_order(x(k, order), pass, work)
         order = order(pass)
      end do
   end subroutine lexicographic_order

   subroutine check_degenerate(set, error)
      type(facet_set_type), intent(in) :: set
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: lo(3), hi(3), m, size, bound, e1(3), e2(3)
      integer :: k

      call facet_bounds(set, lo, hi)
      m = max(maxval(abs(lo)), maxval(abs(hi)))
      do k = 1, set%nfacet
         e1 = set%vert(:, set%facet(2, k)) - set%vert(:, set%facet(1, k))
         if (set%dim == 2) then
            size = norm2(e1)
            bound = degenerate_factor*epsilon(1.0_wp)*m
         else
            e2 = set%vert(:, set%facet(3, k)) - set%vert(:, set%facet(1, k))
            size = norm2(cross(e1, e2))
            bound = degenerate_factor*2.0_wp*epsilon(1.0_wp)*m*(norm2(e1) + norm2(e2))
         end if
         if (size > bound) cycle
         call fatal_error(error, facet_where(set, k)//trim(merge('zero area  ', 'zero length', set%dim == 3))// &
            & ' (its vertices coincide or are collinear within rounding: '//real_text(size)//' <= '// &
            & real_text(bound)//')', stat_invalid_input)
         return
      end do
   end subroutine check_degenerate

   !> Every edge (2D: vertex) shared by exactly two facets that traverse it in
   !> opposite directions. Of all failing edges the one of the lowest facet
   !> number as the source gives it is reported.
   subroutine check_edges(set, error)
      type(facet_set_type), intent(in) :: set
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: key(:, :), owner(:), dir(:), order(:)
      integer :: first, last, worst_kind, worst_facet, worst_run, problem

      call facet_edges(set, key, owner, dir, error)
      if (allocated(error)) return
      call lexicographic_order(real(key, wp), 2, order)
      worst_kind = edge_ok
      worst_facet = huge(1)
      worst_run = 0
      first = 1
      do while (first <= size(order))
         last = first
         do while (last < size(order))
            if (any(key(:, order(last + 1)) /= key(:, order(first)))) exit
            last = last + 1
         end do
         problem = edge_problem(dir(order(first:last)))
         if (problem /= edge_ok) then
            if (minval(set%file_index(owner(order(first:last)))) < worst_facet) then
               worst_facet = minval(set%file_index(owner(order(first:last))))
               worst_kind = problem
               worst_run = first
            end if
         end if
         first = last + 1
      end do
      if (worst_kind == edge_ok) return
      last = worst_run
      do while (last < size(order))
         if (any(key(:, order(last + 1)) /= key(:, order(worst_run)))) exit
         last = last + 1
      end do
      call edge_error(set, worst_kind, key(:, order(worst_run)), owner(order(worst_run:last)), error)
   end subroutine check_edges

   !> The edges of all facets: `key(:, e)` the sorted vertex pair (2D: the
   !> vertex and 0), `owner(e)` its facet, `dir(e)` +1 or -1 by direction.
   subroutine facet_edges(set, key, owner, dir, error)
      type(facet_set_type), intent(in) :: set
      integer, allocatable, intent(out) :: key(:, :), owner(:), dir(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: k, j, e, a, b, stat

      allocate (key(2, set%dim*set%nfacet), owner(set%dim*set%nfacet), dir(set%dim*set%nfacet), stat=stat)
      call check_allocation(stat, 'facet edge matching', 'edges', int(set%dim, i8)*set%nfacet, 16, error)
      if (allocated(error)) return
      e = 0
      do k = 1, set%nfacet
         do j = 1, set%dim
            e = e + 1
            owner(e) = k
            a = set%facet(j, k)
            if (set%dim == 2) then
               key(:, e) = [a, 0]
               dir(e) = 3 - 2*j
               cycle
            end if
            b = set%facet(mod(j, 3) + 1, k)
            key(:, e) = [min(a, b), max(a, b)]
            dir(e) = merge(1, -1, a < b)
         end do
      end do
   end subroutine facet_edges

   pure integer function edge_problem(dir) result(problem)
      integer, intent(in) :: dir(:)
      select case (size(dir))
      case (1); problem = edge_open
      case (2); problem = merge(edge_ok, edge_orientation, dir(1) /= dir(2))
      case default; problem = edge_nonmanifold
      end select
   end function edge_problem

   subroutine edge_error(set, problem, key, owners, error)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: problem, key(2), owners(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: what, text
      integer :: i, k

      k = owners(minloc(set%file_index(owners), 1))
      if (set%dim == 2) then
         what = 'the vertex at '//point_text(set, key(1))
      else
         what = 'the edge from '//point_text(set, key(1))//' to '//point_text(set, key(2))
      end if
      select case (problem)
      case (edge_open)
         text = what//' belongs to no other '//trim(merge('facet  ', 'segment', set%dim == 3))//': the surface is open'
      case (edge_orientation)
         text = 'inconsistent orientation: '//what//' is traversed in the same direction by '// &
            & trim(merge('facets  ', 'segments', set%dim == 3))//' '//itoa(set%file_index(owners(1)))//' and '// &
            & itoa(set%file_index(owners(2)))
      case default
         text = 'non-manifold: '//what//' is shared by '//itoa(size(owners))//' '// &
            & trim(merge('facets  ', 'segments', set%dim == 3))//' ('
         do i = 1, min(size(owners), 6)
            if (i > 1) text = text//', '
            text = text//itoa(set%file_index(owners(i)))
         end do
         text = text//')'
      end select
      call fatal_error(error, facet_where(set, k)//text, stat_invalid_input)
   end subroutine edge_error

   function point_text(set, v) result(text)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: v
      character(len=:), allocatable :: text
      integer :: i
      text = '('
      do i = 1, set%dim
         if (i > 1) text = text//', '
         text = text//real_text(set%vert(i, v))
      end do
      text = text//')'
   end function point_text

   !> No two segments cross, touch or overlap, except neighbours at their
   !> shared vertex.
   subroutine check_crossings(set, error)
      type(facet_set_type), intent(in) :: set
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: start(:), member(:)
      integer :: nb, b, i, j, si, sj
      real(wp) :: lo(3), hi(3)

      call facet_bounds(set, lo, hi)
      nb = max(1, int(sqrt(real(set%nfacet, wp))))
      call bin_segments(set, lo, hi, nb, start, member)
      do b = 1, nb*nb
         do i = start(b), start(b + 1) - 1
            do j = i + 1, start(b + 1) - 1
               si = min(member(i), member(j))
               sj = max(member(i), member(j))
               if (.not. segments_meet(set, si, sj)) cycle
               call fatal_error(error, facet_where(set, si)//'the polygon crosses itself: it meets segment '// &
                  & itoa(set%file_index(sj))//' (from '//point_text(set, set%facet(1, sj))//' to '// &
                  & point_text(set, set%facet(2, sj))//')', stat_invalid_input)
               return
            end do
         end do
      end do
   end subroutine check_crossings

   !> Segments of each of nb x nb bins over the box [lo, hi]: those of bin b are
   !> member(start(b):start(b+1)-1), in increasing order.
   subroutine bin_segments(set, lo, hi, nb, start, member)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(in) :: lo(3), hi(3)
      integer, intent(in) :: nb
      integer, allocatable, intent(out) :: start(:), member(:)
      integer :: k, pass, ix, iy, r(2, 2)

      allocate (start(nb*nb + 1), source=0)
      allocate (member(0))
      do pass = 1, 2
         do k = 1, set%nfacet
            r = bin_range(set, k, lo, hi, nb)
            do iy = r(1, 2), r(2, 2)
               do ix = r(1, 1), r(2, 1)
                  if (pass == 1) then
                     start(ix + nb*(iy - 1) + 1) = start(ix + nb*(iy - 1) + 1) + 1
                  else
                     member(start(ix + nb*(iy - 1))) = k
                     start(ix + nb*(iy - 1)) = start(ix + nb*(iy - 1)) + 1
                  end if
               end do
            end do
         end do
         if (pass == 1) then
            start(1) = 1
            do k = 2, nb*nb + 1
               start(k) = start(k) + start(k - 1)
            end do
            deallocate (member)
            allocate (member(start(nb*nb + 1) - 1))
         end if
      end do
      ! The second pass moved each start to the next bin's: shift back.
      start(2:nb*nb + 1) = start(1:nb*nb)
      start(1) = 1
   end subroutine bin_segments

   !> Bins (first and last in x, in y) the box of segment k overlaps.
   pure function bin_range(set, k, lo, hi, nb) result(r)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: k, nb
      real(wp), intent(in) :: lo(3), hi(3)
      integer :: r(2, 2), i
      real(wp) :: a, b, w
      do i = 1, 2
         a = min(set%vert(i, set%facet(1, k)), set%vert(i, set%facet(2, k)))
         b = max(set%vert(i, set%facet(1, k)), set%vert(i, set%facet(2, k)))
         w = max(hi(i) - lo(i), tiny(1.0_wp))
         r(1, i) = min(nb, max(1, 1 + int((a - lo(i))/w*nb)))
         r(2, i) = min(nb, max(1, 1 + int((b - lo(i))/w*nb)))
      end do
   end function bin_range

   !> Whether segments i and j meet anywhere but at a vertex they share.
   pure logical function segments_meet(set, i, j) result(meet)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: i, j
      real(wp) :: p(2), q(2), r(2), s(2)
      integer :: shared

      p = set%vert(1:2, set%facet(1, i))
      q = set%vert(1:2, set%facet(2, i))
      r = set%vert(1:2, set%facet(1, j))
      s = set%vert(1:2, set%facet(2, j))
      shared = count([set%facet(1, i) == set%facet(1, j), set%facet(1, i) == set%facet(2, j), &
         & set%facet(2, i) == set%facet(1, j), set%facet(2, i) == set%facet(2, j)])
      if (shared > 0) then
         ! Neighbours meet elsewhere only when they fold back along one line.
         meet = abs(orient(p, q, r)) <= 0.0_wp .and. abs(orient(p, q, s)) <= 0.0_wp .and. &
            & dot_product(q - p, s - r) < 0.0_wp .and. (set%facet(2, i) == set%facet(1, j) .or. &
            & set%facet(1, i) == set%facet(2, j))
         return
      end if
      meet = straddles(p, q, r, s) .and. straddles(r, s, p, q)
   end function segments_meet

   !> Whether r and s lie on different sides of line pq or on it within pq's span.
   pure logical function straddles(p, q, r, s)
      real(wp), intent(in) :: p(2), q(2), r(2), s(2)
      real(wp) :: o1, o2
      o1 = orient(p, q, r)
      o2 = orient(p, q, s)
      if (abs(o1) <= 0.0_wp .and. abs(o2) <= 0.0_wp) then
         straddles = max(dot_product(r - p, q - p), dot_product(s - p, q - p)) >= 0.0_wp .and. &
            & min(dot_product(r - p, q - p), dot_product(s - p, q - p)) <= dot_product(q - p, q - p)
      else
         straddles = .not. (o1*o2 > 0.0_wp)
      end if
   end function straddles

   pure real(wp) function orient(p, q, r)
      real(wp), intent(in) :: p(2), q(2), r(2)
      orient = (q(1) - p(1))*(r(2) - p(2)) - (q(2) - p(2))*(r(1) - p(1))
   end function orient

   subroutine flip(set)
      type(facet_set_type), intent(inout) :: set
      integer :: k, t
      do k = 1, set%nfacet
         t = set%facet(set%dim - 1, k)
         set%facet(set%dim - 1, k) = set%facet(set%dim, k)
         set%facet(set%dim, k) = t
      end do
   end subroutine flip

end module sprc_geometry_facet_check
