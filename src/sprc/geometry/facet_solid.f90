!> A solid bounded by a closed oriented faceted surface (sprc_geometry_facets)
!> with a bounding-volume hierarchy over its facets: the queries the shape,
!> the classification of grid cells and the cut-cell quadrature need.
!>
!> Hierarchy: binary tree over the facets' bounding boxes, split at the median
!> centroid along the longest centroid extent (quickselect: O(n log n) build),
!> at most `leaf_size` facets per leaf. Queries: facets whose box meets a
!> box, facets whose box meets a segment (slab test: the cost grows with the
!> facets near the segment, not with all of them), nearest facet of a point
!> (branch and bound), crossings of a segment.
!>
!> Inside test (`solid_inside`): parity of the crossings of the segment from
!> the point to the centroid of its nearest facet f, combined with the side
!> of f's plane. A crossing near another facet's edge is ambiguous; the test
!> then aims at another point of f (a different barycentre) and, after
!> `max_aims`, at other facets, so edges and vertices never decide.
!>
!> Classification of a box (`solid_box_class`), with the snapping rule: a
!> facet fragment is the facet clipped to the closed box; fragments of area
!> (length in 2D) at most snap_area = 16 eps h^2 (16 eps h) are dropped, h the
!> box's largest extent, so a facet touching the box in an edge or a vertex
!> (exactly or to round-off) neither cuts it nor adds surface. A fragment
!> lying in a face plane of the box (every vertex within the snapping length
!> of the plane) is a boundary on a grid plane: not a cut; the box is inside
!> when the facet's outward normal points out of the box there. The box is
!> cut if any other fragment remains; otherwise inside or outside by the
!> inside test of its centre.
module sprc_geometry_facet_solid
   use sprc_core_kinds, only: wp
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_region, only: cell_outside, cell_inside, cell_cut
   implicit none
   private

   public :: facet_solid_type, new_facet_solid
   public :: solid_query_box, solid_query_segment, solid_line_facet, solid_nearest, solid_inside, solid_box_class
   public :: clip_to_box, polygon_measure, facet_points, snap_area, snap_length, on_face_plane, face_cover

   !> Facets per leaf of the hierarchy.
   integer, parameter :: leaf_size = 4
   !> The two kinds of hierarchy query (solid_walk).
   integer, parameter :: query_box = 1, query_segment = 2
   !> Aims of the inside test at one facet before trying another.
   integer, parameter :: max_aims = 4
   !> Most vertices of a facet clipped to a box (a triangle gains at most one per plane).
   integer, parameter, public :: max_clip_vertices = 12

   !> The faceted solid with its hierarchy.
   type :: facet_solid_type
      !> The surface (vertices, facets, groups).
      type(facet_set_type) :: set
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Unit outward normal of each facet (3, nfacet).
      real(wp), allocatable :: normal(:, :)
      !> Measure (area, length) of each facet.
      real(wp), allocatable :: measure(:)
      !> The hierarchy (number of nodes, node boxes (3, nnode), first facet and
      !> count in `order` (count > 0: leaf), right child; left child = node + 1).
      integer :: nnode = 0
      real(wp), allocatable :: lo(:, :), hi(:, :)
      integer, allocatable :: first(:), count(:), right(:)
      !> Facets in hierarchy order.
      integer, allocatable :: order(:)
      !> Largest coordinate magnitude of the vertices (for round-off tolerances).
      real(wp) :: scale = 0.0_wp
   end type facet_solid_type

contains

   ! ------------------------------------------------------------ construction

   !> The solid of a closed outward-oriented facet set with dim 2 or 3 and at
   !> least one facet (the caller checks): normals, measures and hierarchy.
   pure subroutine new_facet_solid(self, set)
      type(facet_solid_type), intent(out) :: self
      type(facet_set_type), intent(in) :: set
      real(wp), allocatable :: c(:, :), blo(:, :), bhi(:, :)
      real(wp) :: p(3, 3)
      integer :: f, n, node

      self%set = set
      self%dim = set%dim
      n = set%nfacet
      allocate (self%normal(3, n), self%measure(n), c(3, n), blo(3, n), bhi(3, n))
      do f = 1, n
         call facet_points(self, f, p)
         call facet_normal(self%dim, p, self%normal(:, f), self%measure(f))
         c(:, f) = sum(p(:, 1:self%dim), dim=2)/self%dim
         blo(:, f) = minval(p(:, 1:self%dim), dim=2)
         bhi(:, f) = maxval(p(:, 1:self%dim), dim=2)
      end do
      self%scale = maxval(abs(set%vert(:, 1:set%nvert)))
      allocate (self%order(n), self%lo(3, 2*n), self%hi(3, 2*n), self%first(2*n), self%count(2*n), &
         & self%right(2*n))
      self%order = [(f, f=1, n)]
      node = 0
      call build_node(self, c, blo, bhi, 1, n, node)
      self%nnode = node
   end subroutine new_facet_solid

   !> Vertices of facet f as columns of p (dim of them used).
   pure subroutine facet_points(self, f, p)
      type(facet_solid_type), intent(in) :: self
      integer, intent(in) :: f
      real(wp), intent(out) :: p(3, 3)
      integer :: i
      p = 0.0_wp
      do i = 1, self%dim
         p(:, i) = self%set%vert(:, self%set%facet(i, f))
      end do
   end subroutine facet_points

   pure subroutine facet_normal(dim, p, n, measure)
      integer, intent(in) :: dim
      real(wp), intent(in) :: p(3, 3)
      real(wp), intent(out) :: n(3), measure
      n = 0.0_wp
      if (dim == 2) then
         n(1:2) = [p(2, 2) - p(2, 1), p(1, 1) - p(1, 2)]
      else
         n = cross(p(:, 2) - p(:, 1), p(:, 3) - p(:, 1))
      end if
      measure = norm2(n)
      if (measure > 0.0_wp) n = n/measure
      if (dim == 3) measure = 0.5_wp*measure
   end subroutine facet_normal

   !> Node over order(i0:i1): its box, then a leaf or two children split at the median.
   pure recursive subroutine build_node(self, c, blo, bhi, i0, i1, node)
      type(facet_solid_type), intent(inout) :: self
      real(wp), intent(in) :: c(:, :), blo(:, :), bhi(:, :)
      integer, intent(in) :: i0, i1
      integer, intent(inout) :: node
      real(wp) :: cl(3), ch(3)
      integer :: me, i, f, axis, mid

      node = node + 1
      me = node
      self%lo(:, me) = huge(1.0_wp)
      self%hi(:, me) = -huge(1.0_wp)
      cl = huge(1.0_wp)
      ch = -huge(1.0_wp)
      do i = i0, i1
         f = self%order(i)
         self%lo(:, me) = min(self%lo(:, me), blo(:, f))
         self%hi(:, me) = max(self%hi(:, me), bhi(:, f))
         cl = min(cl, c(:, f))
         ch = max(ch, c(:, f))
      end do
      self%first(me) = i0
      self%count(me) = i1 - i0 + 1
      self%right(me) = 0
      if (i1 - i0 + 1 <= leaf_size) return
      self%count(me) = 0
      axis = maxloc(ch - cl, dim=1)
      mid = (i0 + i1)/2
      call select_kth(self%order(i0:i1), c(axis, :), mid - i0 + 1)
      call build_node(self, c, blo, bhi, i0, mid, node)
      self%right(me) = node + 1
      call build_node(self, c, blo, bhi, mid + 1, i1, node)
   end subroutine build_node

   !> Reorder idx so that key(idx(k)) is the k-th smallest, smaller ones before it
   !> and larger ones after (quickselect, median-of-three pivot; ties by index).
   pure subroutine select_kth(idx, key, k)
      integer, intent(inout) :: idx(:)
      real(wp), intent(in) :: key(:)
      integer, intent(in) :: k
      integer :: l, r, i, j, pivot, t

      l = 1
      r = size(idx)
      do while (r > l)
         pivot = median3(idx(l), idx((l + r)/2), idx(r))
         i = l
         j = r
         do while (i <= j)
            do while (less(idx(i), pivot))
               i = i + 1
            end do
            do while (less(pivot, idx(j)))
               j = j - 1
            end do
            if (i <= j) then
               t = idx(i); idx(i) = idx(j); idx(j) = t
               i = i + 1
               j = j - 1
            end if
         end do
         if (k <= j) then
            r = j
         else if (k >= i) then
            l = i
         else
            return
         end if
      end do
   contains
      pure logical function less(a, b)
         integer, intent(in) :: a, b
         less = key(a) < key(b) .or. (key(a) == key(b) .and. a < b)
      end function less
      pure integer function median3(a, b, c) result(m)
         integer, intent(in) :: a, b, c
         if (less(a, b)) then
            m = merge(b, merge(c, a, less(a, c)), less(b, c))
         else
            m = merge(a, merge(c, b, less(b, c)), less(a, c))
         end if
      end function median3
   end subroutine select_kth

   ! ------------------------------------------------------------ queries

   !> Facets whose bounding box meets the closed box [lo, hi] (size dim):
   !> list(1:n), grown as needed, in hierarchy order.
   pure subroutine solid_query_box(self, lo, hi, list, n)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, allocatable, intent(inout) :: list(:)
      integer, intent(out) :: n
      integer :: d

      d = self%dim
      call solid_walk(self, query_box, [lo(1:d), hi(1:d)], list, n)
   end subroutine solid_query_box

   !> Facets whose bounding box, padded by `pad`, meets the segment x0 + t n,
   !> t in [ta, tb] (ta <= tb; x0, n of size dim): list(1:n), grown as
   !> needed, in hierarchy order.
   pure subroutine solid_query_segment(self, x0, n, ta, tb, pad, list, nlist)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: x0(:), n(:), ta, tb, pad
      integer, allocatable, intent(inout) :: list(:)
      integer, intent(out) :: nlist
      integer :: d

      d = self%dim
      call solid_walk(self, query_segment, [x0(1:d), n(1:d), ta, tb, pad], list, nlist)
   end subroutine solid_query_segment

   !> The one hierarchy walk of both queries: the leaves' facets whose node
   !> box passes the query's test (`kind`, its data packed in q) in
   !> hierarchy order. A kind flag, not a procedure argument: an internal
   !> procedure passed as an argument needs an executable-stack trampoline.
   pure subroutine solid_walk(self, kind, q, list, n)
      type(facet_solid_type), intent(in) :: self
      integer, intent(in) :: kind
      real(wp), intent(in) :: q(:)
      integer, allocatable, intent(inout) :: list(:)
      integer, intent(out) :: n
      integer :: stack(128), top, node, i, d

      d = self%dim
      n = 0
      if (.not. allocated(list)) allocate (list(64))
      top = 1
      stack(1) = 1
      do while (top > 0)
         node = stack(top)
         top = top - 1
         if (.not. node_passes(node)) cycle
         if (self%count(node) > 0) then
            do i = self%first(node), self%first(node) + self%count(node) - 1
               call push_int(list, n, self%order(i))
            end do
         else
            stack(top + 1) = self%right(node)
            stack(top + 2) = node + 1
            top = top + 2
         end if
      end do
   contains
      pure logical function node_passes(k)
         integer, intent(in) :: k
         if (kind == query_box) then
            node_passes = .not. (any(self%lo(1:d, k) > q(d + 1:2*d)) .or. any(self%hi(1:d, k) < q(1:d)))
         else
            node_passes = segment_meets_box(d, q(1:d), q(d + 1:2*d), q(2*d + 1), q(2*d + 2), &
                                            self%lo(1:d, k) - q(2*d + 3), self%hi(1:d, k) + q(2*d + 3))
         end if
      end function node_passes
   end subroutine solid_walk

   !> Slab test: does x0 + t n, t in [ta, tb], meet the closed box [lo, hi]?
   pure logical function segment_meets_box(d, x0, n, ta, tb, lo, hi) result(meets)
      integer, intent(in) :: d
      real(wp), intent(in) :: x0(:), n(:), ta, tb, lo(:), hi(:)
      real(wp) :: t0, t1, a, b
      integer :: k

      t0 = ta
      t1 = tb
      meets = .false.
      do k = 1, d
         if (n(k) == 0.0_wp) then
            if (x0(k) < lo(k) .or. x0(k) > hi(k)) return
            cycle
         end if
         a = (lo(k) - x0(k))/n(k)
         b = (hi(k) - x0(k))/n(k)
         t0 = max(t0, min(a, b))
         t1 = min(t1, max(a, b))
         if (t0 > t1) return
      end do
      meets = .true.
   end function segment_meets_box

   !> Where the line x0 + t n (n unit, size dim) crosses facet f: `hit` if it
   !> meets the closed facet (barycentric coordinates >= -margin, margin a
   !> few ulps, so that a line through a shared edge or vertex meets every
   !> facet there) and is not parallel to its plane (|n . normal| above
   !> rounding); then t.
   pure subroutine solid_line_facet(self, f, x0, n, hit, t)
      type(facet_solid_type), intent(in) :: self
      integer, intent(in) :: f
      real(wp), intent(in) :: x0(:), n(:)
      logical, intent(out) :: hit
      real(wp), intent(out) :: t
      real(wp), parameter :: margin = 64.0_wp*epsilon(1.0_wp)
      real(wp) :: p(3, 3), y(3), m(3), x(3), b(3), cosine

      hit = .false.
      t = 0.0_wp
      call facet_points(self, f, p)
      y = 0.0_wp
      m = 0.0_wp
      y(1:self%dim) = x0(1:self%dim)
      m(1:self%dim) = n(1:self%dim)
      cosine = dot_product(m, self%normal(:, f))
      if (.not. abs(cosine) > margin) return
      t = dot_product(p(:, 1) - y, self%normal(:, f))/cosine
      x = y + t*m
      b = barycentric(self%dim, p, x)
      hit = all(b >= -margin)
   end subroutine solid_line_facet

   pure subroutine push_int(list, n, v)
      integer, allocatable, intent(inout) :: list(:)
      integer, intent(inout) :: n
      integer, intent(in) :: v
      integer, allocatable :: t(:)
      if (n == size(list)) then
         allocate (t(2*n))
         t(1:n) = list
         call move_alloc(t, list)
      end if
      n = n + 1
      list(n) = v
   end subroutine push_int

   !> Nearest facet f of x and the distance to it (branch and bound).
   pure subroutine solid_nearest(self, x, f, dist)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer, intent(out) :: f
      real(wp), intent(out) :: dist
      integer :: stack(128), top, node, i, g, a, b
      real(wp) :: y(3), d2, best, da, db

      y = 0.0_wp
      y(1:self%dim) = x(1:self%dim)
      best = huge(1.0_wp)
      f = 0
      top = 1
      stack(1) = 1
      do while (top > 0)
         node = stack(top)
         top = top - 1
         if (box_distance2(y, self%lo(:, node), self%hi(:, node)) >= best) cycle
         if (self%count(node) > 0) then
            do i = self%first(node), self%first(node) + self%count(node) - 1
               g = self%order(i)
               d2 = facet_distance2(self, g, y)
               if (d2 < best .or. (.not. d2 > best .and. g < f)) then
                  best = d2
                  f = g
               end if
            end do
         else
            ! nearer child last, so it is searched first
            a = node + 1
            b = self%right(node)
            da = box_distance2(y, self%lo(:, a), self%hi(:, a))
            db = box_distance2(y, self%lo(:, b), self%hi(:, b))
            if (da < db) then
               stack(top + 1) = b
               stack(top + 2) = a
            else
               stack(top + 1) = a
               stack(top + 2) = b
            end if
            top = top + 2
         end if
      end do
      dist = sqrt(best)
   end subroutine solid_nearest

   pure real(wp) function box_distance2(y, lo, hi) result(d2)
      real(wp), intent(in) :: y(3), lo(3), hi(3)
      d2 = sum(max(lo - y, 0.0_wp, y - hi)**2)
   end function box_distance2

   !> Squared distance from y to facet f.
   pure real(wp) function facet_distance2(self, f, y) result(d2)
      type(facet_solid_type), intent(in) :: self
      integer, intent(in) :: f
      real(wp), intent(in) :: y(3)
      real(wp) :: p(3, 3)
      call facet_points(self, f, p)
      if (self%dim == 2) then
         d2 = sum((y - closest_on_segment(p(:, 1), p(:, 2), y))**2)
      else
         d2 = sum((y - closest_on_triangle(p(:, 1), p(:, 2), p(:, 3), y))**2)
      end if
   end function facet_distance2

   pure function closest_on_segment(a, b, y) result(c)
      real(wp), intent(in) :: a(3), b(3), y(3)
      real(wp) :: c(3), t, l2
      l2 = sum((b - a)**2)
      t = 0.0_wp
      if (l2 > 0.0_wp) t = min(max(dot_product(y - a, b - a)/l2, 0.0_wp), 1.0_wp)
      c = a + t*(b - a)
   end function closest_on_segment

   !> Closest point of triangle abc to y (Ericson, Real-Time Collision Detection 5.1.5).
   pure function closest_on_triangle(a, b, c, y) result(q)
      real(wp), intent(in) :: a(3), b(3), c(3), y(3)
      real(wp) :: q(3), ab(3), ac(3), ap(3), bp(3), cp(3), d1, d2, d3, d4, d5, d6, va, vb, vc, v, w, den

      ab = b - a
      ac = c - a
      ap = y - a
      d1 = dot_product(ab, ap)
      d2 = dot_product(ac, ap)
      if (d1 <= 0.0_wp .and. d2 <= 0.0_wp) then
         q = a
         return
      end if
      bp = y - b
      d3 = dot_product(ab, bp)
      d4 = dot_product(ac, bp)
      if (d3 >= 0.0_wp .and. d4 <= d3) then
         q = b
         return
      end if
      vc = d1*d4 - d3*d2
      if (vc <= 0.0_wp .and. d1 >= 0.0_wp .and. d3 <= 0.0_wp) then
         q = a + d1/(d1 - d3)*ab
         return
      end if
      cp = y - c
      d5 = dot_product(ab, cp)
      d6 = dot_product(ac, cp)
      if (d6 >= 0.0_wp .and. d5 <= d6) then
         q = c
         return
      end if
      vb = d5*d2 - d1*d6
      if (vb <= 0.0_wp .and. d2 >= 0.0_wp .and. d6 <= 0.0_wp) then
         q = a + d2/(d2 - d6)*ac
         return
      end if
      va = d3*d6 - d5*d4
      if (va <= 0.0_wp .and. (d4 - d3) >= 0.0_wp .and. (d5 - d6) >= 0.0_wp) then
         q = b + (d4 - d3)/((d4 - d3) + (d5 - d6))*(c - b)
         return
      end if
      den = 1.0_wp/(va + vb + vc)
      v = vb*den
      w = vc*den
      q = a + ab*v + ac*w
   end function closest_on_triangle

   !> Inside test of x (module notes); `on` when x lies on the surface within
   !> the snapping length (then inside is .false.).
   pure subroutine solid_inside(self, x, inside, on)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      logical, intent(out) :: inside, on
      real(wp) :: y(3), dist, tol
      integer :: f, aim, try
      logical :: clean

      y = 0.0_wp
      y(1:self%dim) = x(1:self%dim)
      inside = .false.
      tol = snap_length(self, maxval(abs(y)))
      call solid_nearest(self, y, f, dist)
      on = dist <= tol
      if (on .or. f == 0) return
      do try = 0, self%set%nfacet - 1
         do aim = 1, max_aims
            call parity_to(self, y, 1 + mod(f - 1 + try, self%set%nfacet), aim, tol, inside, clean)
            if (clean) return
         end do
      end do
   end subroutine solid_inside

   !> Parity test along the segment from y to an aim point of facet f: clean = .false.
   !> when a crossing is within the snapping length of a facet's edge, or y lies in f's plane.
   pure subroutine parity_to(self, y, f, aim, tol, inside, clean)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: y(3), tol
      integer, intent(in) :: f, aim
      logical, intent(out) :: inside, clean
      real(wp), parameter :: bary(3, max_aims) = reshape([1.0_wp/3, 1.0_wp/3, 1.0_wp/3, 0.3_wp, 0.45_wp, 0.25_wp, &
         & 0.5_wp, 0.2_wp, 0.3_wp, 0.2_wp, 0.35_wp, 0.45_wp], [3, max_aims])
      real(wp) :: p(3, 3), t(3), s, lo(3), hi(3)
      integer :: stack(128), top, node, i, g, ncross
      logical :: hit, edge

      call facet_points(self, f, p)
      if (self%dim == 2) then
         t = (bary(1, aim) + 0.5_wp*bary(3, aim))*p(:, 1) + (bary(2, aim) + 0.5_wp*bary(3, aim))*p(:, 2)
      else
         t = matmul(p, bary(:, aim))
      end if
      s = dot_product(y - t, self%normal(:, f))
      inside = .false.
      clean = abs(s) > tol
      if (.not. clean) return
      lo = min(y, t)
      hi = max(y, t)
      ncross = 0
      top = 1
      stack(1) = 1
      do while (top > 0)
         node = stack(top)
         top = top - 1
         if (any(self%lo(1:self%dim, node) > hi(1:self%dim)) .or. &
            & any(self%hi(1:self%dim, node) < lo(1:self%dim))) cycle
         if (self%count(node) > 0) then
            do i = self%first(node), self%first(node) + self%count(node) - 1
               g = self%order(i)
               if (g == f) cycle
               call segment_crosses(self, g, y, t, hit, edge)
               if (edge) then
                  clean = .false.
                  return
               end if
               if (hit) ncross = ncross + 1
            end do
         else
            stack(top + 1) = self%right(node)
            stack(top + 2) = node + 1
            top = top + 2
         end if
      end do
      inside = (s < 0.0_wp) .neqv. (mod(ncross, 2) == 1)
   end subroutine parity_to

   !> Does the segment [y, t] cross facet g? edge: the crossing (or the segment's
   !> contact with g's plane) is too near to call: within a relative 1e-9 of an
   !> edge of g, or an end of the segment in g's plane.
   pure subroutine segment_crosses(self, g, y, t, hit, edge)
      type(facet_solid_type), intent(in) :: self
      integer, intent(in) :: g
      real(wp), intent(in) :: y(3), t(3)
      logical, intent(out) :: hit, edge
      real(wp), parameter :: margin = 1.0e-9_wp
      real(wp) :: p(3, 3), sy, st, r, x(3), b(3)

      hit = .false.
      edge = .false.
      call facet_points(self, g, p)
      sy = dot_product(y - p(:, 1), self%normal(:, g))
      st = dot_product(t - p(:, 1), self%normal(:, g))
      if ((sy > 0.0_wp .and. st > 0.0_wp) .or. (sy < 0.0_wp .and. st < 0.0_wp)) return
      if (.not. (sy < st .or. sy > st)) return
      r = sy/(sy - st)
      x = y + r*(t - y)
      b = barycentric(self%dim, p, x)
      if (any(b < -margin)) return
      if (any(b < margin) .or. min(abs(sy), abs(st)) <= margin*abs(sy - st)) then
         edge = .true.
         return
      end if
      hit = .true.
   end subroutine segment_crosses

   !> Barycentric coordinates of x (in the plane of the facet with vertices
   !> p) with respect to them; 2D: the segment's two, and 1 in the third (so
   !> that a test over all three reads the same in 2D and 3D).
   pure function barycentric(dim, p, x) result(b)
      integer, intent(in) :: dim
      real(wp), intent(in) :: p(3, 3), x(3)
      real(wp) :: b(3), e1(3), e2(3), nn(3), den
      e1 = p(:, 2) - p(:, 1)
      if (dim == 2) then
         b(2) = dot_product(x - p(:, 1), e1)/dot_product(e1, e1)
         b(1) = 1.0_wp - b(2)
         b(3) = 1.0_wp
      else
         e2 = p(:, 3) - p(:, 1)
         nn = cross(e1, e2)
         den = dot_product(nn, nn)
         b(2) = dot_product(cross(x - p(:, 1), e2), nn)/den
         b(3) = dot_product(cross(e1, x - p(:, 1)), nn)/den
         b(1) = 1.0_wp - b(2) - b(3)
      end if
   end function barycentric

   ! ------------------------------------------------------------ boxes

   !> Snapping length at coordinate magnitude xmax (module notes).
   pure real(wp) function snap_length(self, xmax) result(tol)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: xmax
      tol = 4.0_wp*epsilon(1.0_wp)*(xmax + self%scale)
   end function snap_length

   !> Smallest fragment measure that counts in a box of largest extent h (module notes).
   pure real(wp) function snap_area(dim, h) result(a)
      integer, intent(in) :: dim
      real(wp), intent(in) :: h
      a = 16.0_wp*epsilon(1.0_wp)*h**(dim - 1)
   end function snap_area

   !> Facet f clipped to the closed box [lo, hi]: vertices poly(:, 1:nv)
   !> (a polygon in 3D, a segment nv = 2 in 2D; nv = 0 if it degenerates to
   !> fewer than dim vertices).
   pure subroutine clip_to_box(self, f, lo, hi, poly, nv)
      type(facet_solid_type), intent(in) :: self
      integer, intent(in) :: f
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp), intent(out) :: poly(3, max_clip_vertices)
      integer, intent(out) :: nv
      real(wp) :: p(3, 3), work(3, max_clip_vertices)
      integer :: m, side

      call facet_points(self, f, p)
      nv = self%dim
      poly = 0.0_wp
      poly(:, 1:nv) = p(:, 1:nv)
      do m = 1, self%dim
         do side = -1, 1, 2
            work(:, 1:nv) = poly(:, 1:nv)
            if (side < 0) then
               call clip_axis(self%dim, work, nv, m, lo(m), -1.0_wp, poly)
            else
               call clip_axis(self%dim, work, nv, m, hi(m), 1.0_wp, poly)
            end if
            if (nv < self%dim) then
               nv = 0
               return
            end if
         end do
      end do
   end subroutine clip_to_box

   !> Keep the part of the polygon (segment in 2D) v(:, 1:nv) with side*(x_m - c) <= 0;
   !> new vertices lie exactly on the plane (their x_m is c).
   pure subroutine clip_axis(dim, v, nv, m, c, side, out)
      integer, intent(in) :: dim, m
      real(wp), intent(in) :: v(:, :), c, side
      integer, intent(inout) :: nv
      real(wp), intent(out) :: out(:, :)
      real(wp) :: s(max_clip_vertices), x(3)
      integer :: i, j, n, nedge

      do i = 1, nv
         s(i) = side*(v(m, i) - c)
      end do
      n = 0
      nedge = merge(1, nv, dim == 2)
      if (dim == 2 .and. s(1) <= 0.0_wp) then
         n = n + 1
         out(:, n) = v(:, 1)
      end if
      do i = 1, nedge
         j = merge(2, mod(i, nv) + 1, dim == 2)
         if (dim == 3 .and. s(i) <= 0.0_wp) then
            n = n + 1
            out(:, n) = v(:, i)
         end if
         if ((s(i) < 0.0_wp .and. s(j) > 0.0_wp) .or. (s(i) > 0.0_wp .and. s(j) < 0.0_wp)) then
            x = crossing_point(v(:, i), v(:, j), s(i), s(j))
            x(m) = c
            n = n + 1
            out(:, n) = x
         end if
      end do
      if (dim == 2 .and. s(2) <= 0.0_wp) then
         n = n + 1
         out(:, n) = v(:, 2)
      end if
      nv = n
   end subroutine clip_axis

   !> Point on segment ab where the signed value s (sa at a, sb at b, opposite signs)
   !> vanishes, computed from the end with the smaller |s| so it does not depend on
   !> the segment's direction.
   pure function crossing_point(a, b, sa, sb) result(x)
      real(wp), intent(in) :: a(3), b(3), sa, sb
      real(wp) :: x(3)
      if (abs(sa) < abs(sb) .or. (.not. abs(sa) > abs(sb) .and. lexless(a, b))) then
         x = a + (sa/(sa - sb))*(b - a)
      else
         x = b + (sb/(sb - sa))*(a - b)
      end if
   end function crossing_point

   pure logical function lexless(a, b)
      real(wp), intent(in) :: a(3), b(3)
      integer :: i
      lexless = .false.
      do i = 1, 3
         if (.not. (a(i) < b(i) .or. a(i) > b(i))) cycle
         lexless = a(i) < b(i)
         return
      end do
   end function lexless

   !> Area of the planar polygon v(:, 1:nv) (3D) or length of the segment (2D).
   pure real(wp) function polygon_measure(dim, v, nv) result(a)
      integer, intent(in) :: dim, nv
      real(wp), intent(in) :: v(:, :)
      real(wp) :: s(3)
      integer :: i
      a = 0.0_wp
      if (dim == 2) then
         if (nv == 2) a = norm2(v(:, 2) - v(:, 1))
         return
      end if
      s = 0.0_wp
      do i = 2, nv - 1
         s = s + cross(v(:, i) - v(:, 1), v(:, i + 1) - v(:, 1))
      end do
      a = 0.5_wp*norm2(s)
   end function polygon_measure

   !> Is the fragment v(:, 1:nv) in a face plane of the box [lo, hi]? m: its axis,
   !> side: -1 lower face, +1 upper face (0 if not on a face plane).
   pure subroutine on_face_plane(self, v, nv, lo, hi, m, side)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: v(:, :), lo(:), hi(:)
      integer, intent(in) :: nv
      integer, intent(out) :: m, side
      real(wp) :: tol

      tol = snap_length(self, max(maxval(abs(lo)), maxval(abs(hi))))
      do m = 1, self%dim
         if (all(abs(v(m, 1:nv) - lo(m)) <= tol)) then
            side = -1
            return
         end if
         if (all(abs(v(m, 1:nv) - hi(m)) <= tol)) then
            side = 1
            return
         end if
      end do
      m = 0
      side = 0
   end subroutine on_face_plane

   !> Does the solid's surface cover the whole face x_m = (lo_m or hi_m by side
   !> -1 / +1) of the box [lo, hi]? +1: covered by fragments in that plane whose
   !> solid lies on the box side, -1: on the other side, 0: not covered (no
   !> fragment, a partial cover, or both orientations). Covered: the fragments'
   !> measures sum to the face's within 64 eps relative (they do not overlap on
   !> a valid surface).
   pure integer function face_cover(self, lo, hi, m, side) result(cover)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: m, side
      real(wp) :: flo(3), fhi(3), poly(3, max_clip_vertices), total, face, h
      integer, allocatable :: list(:)
      integer :: i, n, nv, mm, ss, d
      logical :: inward, outward

      d = self%dim
      flo(1:d) = lo(1:d)
      fhi(1:d) = hi(1:d)
      if (side < 0) fhi(m) = lo(m)
      if (side > 0) flo(m) = hi(m)
      face = product(fhi(1:d) - flo(1:d), mask=[(i /= m, i=1, d)])
      h = maxval(hi(1:d) - lo(1:d))
      call solid_query_box(self, flo(1:d), fhi(1:d), list, n)
      total = 0.0_wp
      inward = .false.
      outward = .false.
      do i = 1, n
         call clip_to_box(self, list(i), lo, hi, poly, nv)
         if (nv < d) cycle
         if (polygon_measure(d, poly, nv) <= snap_area(d, h)) cycle
         call on_face_plane(self, poly, nv, flo(1:d), fhi(1:d), mm, ss)
         if (mm /= m) cycle
         total = total + polygon_measure(d, poly, nv)
         if (self%normal(m, list(i))*side > 0.0_wp) then
            inward = .true.
         else
            outward = .true.
         end if
      end do
      cover = 0
      if (inward .eqv. outward) return
      if (abs(total - face) > 64.0_wp*epsilon(1.0_wp)*face) return
      cover = merge(1, -1, inward)
   end function face_cover

   !> Class of the box [lo, hi] (module notes).
   pure integer function solid_box_class(self, lo, hi) result(cls)
      type(facet_solid_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, allocatable :: list(:)
      real(wp) :: poly(3, max_clip_vertices), h, x(3)
      integer :: n, i, nv, m, side, face_cls
      logical :: inside, on

      h = maxval(hi(1:self%dim) - lo(1:self%dim))
      call solid_query_box(self, lo, hi, list, n)
      face_cls = -1
      do i = 1, n
         call clip_to_box(self, list(i), lo, hi, poly, nv)
         if (nv < self%dim) cycle
         if (polygon_measure(self%dim, poly, nv) <= snap_area(self%dim, h)) cycle
         call on_face_plane(self, poly, nv, lo, hi, m, side)
         if (m == 0) then
            cls = cell_cut
            return
         end if
         face_cls = merge(cell_inside, cell_outside, self%normal(m, list(i))*side > 0.0_wp)
      end do
      if (face_cls >= 0) then
         cls = face_cls
         return
      end if
      x = 0.0_wp
      x(1:self%dim) = 0.5_wp*(lo(1:self%dim) + hi(1:self%dim))
      call solid_inside(self, x, inside, on)
      cls = merge(cell_inside, cell_outside, inside)
   end function solid_box_class

   pure function cross(a, b) result(c)
      real(wp), intent(in) :: a(3), b(3)
      real(wp) :: c(3)
      c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
   end function cross

end module sprc_geometry_facet_solid
