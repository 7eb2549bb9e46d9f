!> Quadrature of a grid cell cut by a faceted solid (sprc_geometry_facet_solid),
!> exact for the polyhedron (polygon in 2D): the volume rule integrates over
!> cell ∩ solid, the surface rule over the facets clipped to the cell. The
!> construction and its round-off rules are in doc/theory.md, section 2a.
!>
!> - Volume: a solid-leaf binary space partition of the cell by the planes of
!>   the facet fragments crossing it (regions kept as convex polytopes, clipped
!>   face by face); inside regions are fanned into simplices with a collapsed
!>   (Duffy) Gauss rule of q + 1 points per direction: positive weights, exact
!>   for every total degree the tensor rule of q points integrates. A cell no
!>   fragment crosses gets the tensor rule.
!> - Compression (`compress_points`; the cell quadrature applies it to every
!>   cell a faceted solid cuts): at most M of the rule's own points with new
!>   positive weights keeping every moment of total degree 2q - 1 (Tchakaloff;
!>   Lawson-Hanson NNLS), kept when every moment matches within M^2 eps V.
!>   The points stay in the body; positive weights keep the stiffness of a
!>   small cut semi-definite. NNLS costs of order M^2 per candidate point,
!>   so it first draws from a spread subset of about 3M points and only if
!>   that cannot reach the moments from all of them.
!> - Surface: fragments crossing the cell are fanned with the same rule and
!>   carry the facet's exact normal; fragments in a face plane of the cell
!>   belong to the cell on the body side (`facet_face_rule`).
!> - Round-off: sides within the snapping length count as on the plane; pieces
!>   below the snapping measure are dropped, nearby points merged.
module sprc_grid_facet_rule
   use sprc_core_kinds, only: wp
   use sprc_core_gauss, only: max_gauss_points, gauss_legendre_nodes
   use sprc_core_dense, only: reflector, reflect, solve_upper
   use sprc_geometry_facet_solid, only: facet_solid_type, solid_query_box, solid_inside, clip_to_box, &
      & polygon_measure, snap_area, snap_length, on_face_plane, max_clip_vertices
   implicit none
   private

   public :: facet_rule_type, facet_cell_rule, facet_face_rule, compress_points, moment_count
   public :: compress_min_factor

   !> Candidates of the first compression solve, in multiples of the moments M.
   integer, parameter :: candidate_factor = 4
   !> The cell quadrature compresses rules of more than this many times M points.
   integer, parameter :: compress_min_factor = 8

   !> Points of one cell and the work arrays, reused across cells (one per thread).
   type :: facet_rule_type
      !> Volume points (3, nvol) and weights.
      integer :: nvol = 0
      real(wp), allocatable :: vol_x(:, :), vol_w(:)
      !> Surface points (3, nsurf), weights, unit outward normals of the body and facets.
      integer :: nsurf = 0
      real(wp), allocatable :: surf_x(:, :), surf_w(:), surf_n(:, :)
      integer, allocatable :: surf_facet(:)
      !> Planes that split a region (statistics).
      integer :: nsplit = 0
      !> Volume points before compression (statistics; nvol when not compressed).
      integer :: nvol_full = 0
      integer, allocatable, private :: cand(:)
      !> Polygon pool of the fragments and the regions' faces: vertices (3, :), per
      !> polygon its first vertex, vertex count and facet (0 for a region's face).
      real(wp), allocatable, private :: fv(:, :)
      integer, allocatable, private :: fstart(:), fcount(:), ffacet(:)
      integer, private :: nfv = 0, nfrag = 0
      !> The reference rules of the simplex (dim, nref) with weights, the triangle and the segment.
      integer, private :: dim = 0, qs = 0
      real(wp), allocatable, private :: ref_x(:, :), ref_w(:), tri_x(:, :), tri_w(:), seg_x(:), seg_w(:)
      !> Compression: the exponents of the moments' Legendre products (3, M).
      integer, allocatable, private :: cexp(:, :)
      integer, private :: cdeg = -1, cdim = 0
   end type facet_rule_type

   !> What the BSP needs besides the pools.
   type :: context_type
      real(wp) :: tol = 0.0_wp, min_vol = 0.0_wp, min_frag = 0.0_wp
      !> Points of a region closer than this are one.
      real(wp) :: merge = 0.0_wp
      logical :: member_in = .true., member_out = .false.
   end type context_type

contains

   !> Rule of the cell [lo, hi] cut by `solid` with q Gauss points per direction
   !> (module notes). member_in / member_out: is a point of the cell in the
   !> body where it is inside / outside the solid (the other shapes decided
   !> over the cell). Surface normals point out of the body. Face-plane
   !> fragments are left to `facet_face_rule`. compress = .true.: the volume
   !> rule compressed (module notes); off by default (the cell quadrature
   !> compresses once per cell, after all its boxes).
   pure subroutine facet_cell_rule(rule, solid, lo, hi, q, member_in, member_out, compress)
      type(facet_rule_type), intent(inout) :: rule
      type(facet_solid_type), intent(in) :: solid
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: q
      logical, intent(in) :: member_in, member_out
      logical, intent(in), optional :: compress
      type(context_type) :: ctx
      real(wp) :: poly(3, max_clip_vertices), h, x(3), sgn
      integer :: i, n, nv, m, side, f, face_class
      logical :: inside, on, squeeze

      call prepare(rule, solid%dim, q)
      d_block: associate (d => solid%dim)
         h = maxval(hi(1:d) - lo(1:d))
         ctx%tol = snap_length(solid, max(maxval(abs(lo(1:d))), maxval(abs(hi(1:d)))))
         ctx%min_frag = snap_area(d, h)
         ctx%min_vol = 16.0_wp*epsilon(1.0_wp)*h**d
         ctx%merge = 4.0_wp*ctx%tol
         ctx%member_in = member_in
         ctx%member_out = member_out
         sgn = merge(1.0_wp, -1.0_wp, member_in)
         call solid_query_box(solid, lo, hi, rule%cand, n)
         face_class = -1
         do i = 1, n
            f = rule%cand(i)
            call clip_to_box(solid, f, lo, hi, poly, nv)
            if (nv < d) cycle
            if (polygon_measure(d, poly, nv) <= ctx%min_frag) cycle
            call on_face_plane(solid, poly, nv, lo, hi, m, side)
            if (m > 0) then
               face_class = merge(1, 0, solid%normal(m, f)*side > 0.0_wp)
               cycle
            end if
            if (member_in .neqv. member_out) call fragment_surface(rule, d, poly, nv, sgn*solid%normal(:, f), f)
            call push_fragment(rule, poly(:, 1:nv), f)
         end do
         n = rule%nfrag
         call box_region(rule, d, lo, hi)
         if (n == 0) then
            if (face_class < 0) then
               x = 0.0_wp
               x(1:d) = 0.5_wp*(lo(1:d) + hi(1:d))
               call solid_inside(solid, x, inside, on)
               face_class = merge(1, 0, inside)
            end if
            if (merge(member_in, member_out, face_class == 1)) call box_points(rule, d, lo, hi, q)
         else
            call partition(rule, solid, ctx, n + 1, rule%nfrag, 1, n, face_class == 1)
         end if
         rule%nvol_full = rule%nvol
         squeeze = .false.
         if (present(compress)) squeeze = compress
         if (squeeze) call compress_volume(rule, lo, hi, 2*q - 1)
      end associate d_block
   end subroutine facet_cell_rule

   !> Tensor Gauss rule of q points per direction on the box [lo, hi].
   pure subroutine box_points(rule, d, lo, hi, q)
      type(facet_rule_type), intent(inout) :: rule
      integer, intent(in) :: d, q
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: t(max_gauss_points), w(max_gauss_points), x(3), wt
      integer :: i, j, k, nq

      nq = min(q, max_gauss_points)
      call gauss_legendre_nodes(nq, t, w)
      x = 0.0_wp
      do k = 1, merge(nq, 1, d == 3)
         do j = 1, nq
            do i = 1, nq
               x(1) = 0.5_wp*(lo(1) + hi(1)) + 0.5_wp*(hi(1) - lo(1))*t(i)
               x(2) = 0.5_wp*(lo(2) + hi(2)) + 0.5_wp*(hi(2) - lo(2))*t(j)
               wt = w(i)*w(j)*product(0.5_wp*(hi(1:d) - lo(1:d)))
               if (d == 3) then
                  x(3) = 0.5_wp*(lo(3) + hi(3)) + 0.5_wp*(hi(3) - lo(3))*t(k)
                  wt = wt*w(k)
               end if
               call push_volume(rule, x, wt)
            end do
         end do
      end do
   end subroutine box_points

   !> Surface points of the fragments of `solid` lying in the face planes of the
   !> cell [lo, hi], with the facet's outward normal and surf_facet = f where the
   !> solid's inside lies on the cell side of the plane, -f where it lies on
   !> the other side (the caller decides by CSG membership which it keeps).
   !> Faces marked in skip(side, m) (1 lower, 2 upper) are left out, and with the
   !> box [skip_lo, skip_hi], fragments in its face planes.
   pure subroutine facet_face_rule(rule, solid, lo, hi, q, skip, skip_lo, skip_hi)
      type(facet_rule_type), intent(inout) :: rule
      type(facet_solid_type), intent(in) :: solid
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: q
      logical, intent(in) :: skip(:, :)
      real(wp), intent(in), optional :: skip_lo(:), skip_hi(:)
      real(wp) :: poly(3, max_clip_vertices), h
      integer :: i, n, nv, m, side, f, d, m2, side2

      call prepare(rule, solid%dim, q)
      d = solid%dim
      h = maxval(hi(1:d) - lo(1:d))
      call solid_query_box(solid, lo, hi, rule%cand, n)
      do i = 1, n
         f = rule%cand(i)
         call clip_to_box(solid, f, lo, hi, poly, nv)
         if (nv < d) cycle
         if (polygon_measure(d, poly, nv) <= snap_area(d, h)) cycle
         call on_face_plane(solid, poly, nv, lo, hi, m, side)
         if (m == 0) cycle
         if (skip((side + 3)/2, m)) cycle
         if (present(skip_lo)) then
            call on_face_plane(solid, poly, nv, skip_lo, skip_hi, m2, side2)
            if (m2 > 0) cycle
         end if
         ! the cell lies on the solid's inside iff the outward normal leaves the cell
         call fragment_surface(rule, d, poly, nv, solid%normal(:, f), merge(f, -f, solid%normal(m, f)*side > 0.0_wp))
      end do
   end subroutine facet_face_rule

   ! ------------------------------------------------------------ set-up

   pure subroutine prepare(rule, dim, q)
      type(facet_rule_type), intent(inout) :: rule
      integer, intent(in) :: dim, q
      rule%nvol = 0
      rule%nsurf = 0
      rule%nsplit = 0
      rule%nfv = 0
      rule%nfrag = 0
      if (.not. allocated(rule%vol_x)) then
         allocate (rule%vol_x(3, 256), rule%vol_w(256), rule%surf_x(3, 64), rule%surf_w(64), rule%surf_n(3, 64), &
            & rule%surf_facet(64), rule%cand(64), rule%fv(3, 256), rule%fstart(64), &
            & rule%fcount(64), rule%ffacet(64))
      end if
      if (rule%dim /= dim .or. rule%qs /= min(q + 1, max_gauss_points)) call reference_rules(rule, dim, q)
   end subroutine prepare

   !> Collapsed Gauss rules on the reference simplex {y >= 0, sum y <= 1} (weights sum to its
   !> measure), on the reference triangle, and Gauss on [0, 1].
   pure subroutine reference_rules(rule, dim, q)
      type(facet_rule_type), intent(inout) :: rule
      integer, intent(in) :: dim, q
      real(wp) :: t(max_gauss_points), w(max_gauss_points), u(max_gauss_points), wu(max_gauss_points)
      integer :: qs, i, j, k, n

      qs = min(q + 1, max_gauss_points)
      rule%dim = dim
      rule%qs = qs
      call gauss_legendre_nodes(qs, t, w)
      u(1:qs) = 0.5_wp*(t(1:qs) + 1.0_wp)
      wu(1:qs) = 0.5_wp*w(1:qs)
      if (allocated(rule%ref_x)) deallocate (rule%ref_x, rule%ref_w, rule%tri_x, rule%tri_w, rule%seg_x, rule%seg_w)
      allocate (rule%ref_x(3, qs**dim), rule%ref_w(qs**dim), rule%tri_x(2, qs**2), rule%tri_w(qs**2), &
         & rule%seg_x(qs), rule%seg_w(qs))
      rule%seg_x = u(1:qs)
      rule%seg_w = wu(1:qs)
      n = 0
      do i = 1, qs
         do j = 1, qs
            n = n + 1
            rule%tri_x(:, n) = [u(i), (1.0_wp - u(i))*u(j)]
            rule%tri_w(n) = wu(i)*wu(j)*(1.0_wp - u(i))
         end do
      end do
      if (dim == 2) then
         rule%ref_x = 0.0_wp
         rule%ref_x(1:2, :) = rule%tri_x
         rule%ref_w = rule%tri_w
         return
      end if
      n = 0
      do i = 1, qs
         do j = 1, qs
            do k = 1, qs
               n = n + 1
               rule%ref_x(:, n) = [u(i), (1.0_wp - u(i))*u(j), (1.0_wp - u(i))*(1.0_wp - u(j))*u(k)]
               rule%ref_w(n) = wu(i)*wu(j)*wu(k)*(1.0_wp - u(i))**2*(1.0_wp - u(j))
            end do
         end do
      end do
   end subroutine reference_rules

   !> The cell as a region: its 6 faces (3D) or itself (2D).
   pure subroutine box_region(rule, d, lo, hi)
      type(facet_rule_type), intent(inout) :: rule
      integer, intent(in) :: d
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: v(3, 4), c(3, 8)
      integer, parameter :: quads(4, 6) = reshape([1, 3, 4, 2, 5, 6, 8, 7, 1, 2, 6, 5, 3, 7, 8, 4, 1, 5, 7, 3, &
         & 2, 4, 8, 6], [4, 6])
      integer :: i, f

      v = 0.0_wp
      if (d == 2) then
         v(1:2, 1) = lo(1:2)
         v(1:2, 2) = [hi(1), lo(2)]
         v(1:2, 3) = hi(1:2)
         v(1:2, 4) = [lo(1), hi(2)]
         call push_fragment(rule, v, 0)
         return
      end if
      do i = 1, 8
         c(:, i) = merge(hi(1:3), lo(1:3), [btest(i - 1, 0), btest(i - 1, 1), btest(i - 1, 2)])
      end do
      do f = 1, 6
         call push_fragment(rule, c(:, quads(:, f)), 0)
      end do
   end subroutine box_region

   ! ------------------------------------------------------------ partition

   !> Partition the region of faces r0 .. r1 with fragments k0 .. k1; `inside`:
   !> the class the last plane gave it.
   pure recursive subroutine partition(rule, solid, ctx, r0, r1, k0, k1, inside)
      type(facet_rule_type), intent(inout) :: rule
      type(facet_solid_type), intent(in) :: solid
      type(context_type), intent(in) :: ctx
      integer, intent(in) :: r0, r1, k0, k1
      logical, intent(in) :: inside
      real(wp) :: n(3), p0(3), smin, smax
      integer :: top_f, top_v, b0, b1, f0, f1, g, j, side

      if (k0 > k1) then
         call leaf(rule, ctx, r0, r1, inside)
         return
      end if
      g = rule%ffacet(k0)
      n = solid%normal(:, g)
      p0 = solid%set%vert(:, solid%set%facet(1, g))
      call side_range(rule, r0, r1, n, p0, smin, smax)
      if (.not. (smin < -ctx%tol .and. smax > ctx%tol)) then
         ! the fragment lies on the region's boundary: it only tells the class
         call partition(rule, solid, ctx, r0, r1, k0 + 1, k1, smax <= ctx%tol)
         return
      end if
      rule%nsplit = rule%nsplit + 1
      top_f = rule%nfrag
      top_v = rule%nfv
      do side = -1, 1, 2
         b0 = rule%nfrag + 1
         call clip_region(rule, ctx, solid%dim, r0, r1, n, p0, real(side, wp))
         b1 = rule%nfrag
         f0 = rule%nfrag + 1
         do j = k0 + 1, k1
            call split_fragment(rule, ctx, solid%dim, j, n, p0, real(side, wp))
         end do
         f1 = rule%nfrag
         if (b1 >= b0) call partition(rule, solid, ctx, b0, b1, f0, f1, side < 0)
         rule%nfrag = top_f
         rule%nfv = top_v
      end do
   end subroutine partition

   pure subroutine side_range(rule, r0, r1, n, p0, smin, smax)
      type(facet_rule_type), intent(in) :: rule
      integer, intent(in) :: r0, r1
      real(wp), intent(in) :: n(3), p0(3)
      real(wp), intent(out) :: smin, smax
      real(wp) :: s
      integer :: i
      smin = huge(1.0_wp)
      smax = -huge(1.0_wp)
      do i = rule%fstart(r0), rule%fstart(r1) + rule%fcount(r1) - 1
         s = dot_product(rule%fv(:, i) - p0, n)
         smin = min(smin, s)
         smax = max(smax, s)
      end do
   end subroutine side_range

   !> The part of the region r0 .. r1 on `side` of the plane (-1: back, s <= 0; +1:
   !> front; s the signed distance), pushed as faces: each face clipped, and in 3D
   !> the new face on the plane from the points of the clipped faces on it.
   pure subroutine clip_region(rule, ctx, d, r0, r1, n, p0, side)
      type(facet_rule_type), intent(inout) :: rule
      type(context_type), intent(in) :: ctx
      integer, intent(in) :: d, r0, r1
      real(wp), intent(in) :: n(3), p0(3), side
      real(wp), allocatable :: cap(:, :), v(:, :), out(:, :), s(:)
      real(wp) :: x(3)
      integer :: j, i, k, nv, nout, ncap

      allocate (cap(3, 16), v(3, 16), out(3, 17), s(16))
      ncap = 0
      do j = r0, r1
         nv = rule%fcount(j)
         if (nv + 1 > size(out, 2)) then
            deallocate (v, out, s)
            allocate (v(3, 2*nv), out(3, 2*nv + 1), s(2*nv))
         end if
         v(:, 1:nv) = rule%fv(:, rule%fstart(j):rule%fstart(j) + nv - 1)
         do i = 1, nv
            s(i) = -side*dot_product(v(:, i) - p0, n)
            if (abs(s(i)) <= ctx%tol) s(i) = 0.0_wp
         end do
         nout = 0
         do i = 1, nv
            k = mod(i, nv) + 1
            if (s(i) <= 0.0_wp) then
               call add_point(out, nout, v(:, i), ctx%merge)
               if (s(i) >= 0.0_wp) call add_cap(cap, ncap, v(:, i), ctx%merge)
            end if
            if ((s(i) < 0.0_wp .and. s(k) > 0.0_wp) .or. (s(i) > 0.0_wp .and. s(k) < 0.0_wp)) then
               x = v(:, i) + (s(i)/(s(i) - s(k)))*(v(:, k) - v(:, i))
               call add_point(out, nout, x, ctx%merge)
               call add_cap(cap, ncap, x, ctx%merge)
            end if
         end do
         if (nout > 1) then
            if (norm2(out(:, nout) - out(:, 1)) <= ctx%merge) nout = nout - 1
         end if
         if (nout < 3) cycle
         if (d == 3 .and. polygon_measure(3, out, nout) <= ctx%min_frag) cycle
         call push_fragment(rule, out(:, 1:nout), 0)
      end do
      if (d == 2 .or. ncap < 3) return
      call order_by_angle(cap(:, 1:ncap), n)
      if (polygon_measure(3, cap, ncap) > ctx%min_frag) call push_fragment(rule, cap(:, 1:ncap), 0)
   end subroutine clip_region

   !> Append x to the points of the new face unless one lies within `merge` of it
   !> (the same point reached from two faces, or a vertex on the plane).
   pure subroutine add_cap(cap, ncap, x, merge)
      real(wp), allocatable, intent(inout) :: cap(:, :)
      integer, intent(inout) :: ncap
      real(wp), intent(in) :: x(3), merge
      real(wp), allocatable :: t(:, :)
      integer :: i
      do i = 1, ncap
         if (norm2(cap(:, i) - x) <= merge) return
      end do
      if (ncap == size(cap, 2)) then
         allocate (t(3, 2*ncap))
         t(:, 1:ncap) = cap
         call move_alloc(t, cap)
      end if
      ncap = ncap + 1
      cap(:, ncap) = x
   end subroutine add_cap

   !> Append x to a clipped face loop unless it repeats the previous point within `merge`.
   pure subroutine add_point(out, nout, x, merge)
      real(wp), intent(inout) :: out(:, :)
      integer, intent(inout) :: nout
      real(wp), intent(in) :: x(3), merge
      if (nout > 0) then
         if (norm2(out(:, nout) - x) <= merge) return
      end if
      nout = nout + 1
      out(:, nout) = x
   end subroutine add_point

   !> Order the points p (a convex set in a plane of normal n, duplicates allowed)
   !> by angle around their centroid (insertion sort: a face has few points).
   pure subroutine order_by_angle(p, n)
      real(wp), intent(inout) :: p(:, :)
      real(wp), intent(in) :: n(3)
      real(wp) :: c(3), u(3), w(3), ang(size(p, 2)), key, kp(3)
      integer :: i, j

      c = sum(p, dim=2)/size(p, 2)
      u = 0.0_wp
      u(minloc(abs(n), 1)) = 1.0_wp
      u = u - dot_product(u, n)*n
      u = u/norm2(u)
      w = [n(2)*u(3) - n(3)*u(2), n(3)*u(1) - n(1)*u(3), n(1)*u(2) - n(2)*u(1)]
      do i = 1, size(p, 2)
         ang(i) = atan2(dot_product(p(:, i) - c, w), dot_product(p(:, i) - c, u))
      end do
      do i = 2, size(p, 2)
         key = ang(i)
         kp = p(:, i)
         j = i - 1
         do while (j >= 1)
            if (ang(j) <= key) exit
            ang(j + 1) = ang(j)
            p(:, j + 1) = p(:, j)
            j = j - 1
         end do
         ang(j + 1) = key
         p(:, j + 1) = kp
      end do
   end subroutine order_by_angle

   !> The part of fragment j on `side` of the plane (as `clip_region`), pushed if it has measure and is not in the plane.
   pure subroutine split_fragment(rule, ctx, d, j, n, p0, side)
      type(facet_rule_type), intent(inout) :: rule
      type(context_type), intent(in) :: ctx
      integer, intent(in) :: d, j
      real(wp), intent(in) :: n(3), p0(3), side
      real(wp) :: v(3, max_clip_vertices + 32), out(3, max_clip_vertices + 32), s(max_clip_vertices + 32)
      integer :: i, k, nv, nout, nedge

      nv = rule%fcount(j)
      if (nv + 1 > size(v, 2)) return
      v(:, 1:nv) = rule%fv(:, rule%fstart(j):rule%fstart(j) + nv - 1)
      do i = 1, nv
         s(i) = -side*dot_product(v(:, i) - p0, n)
         if (abs(s(i)) <= ctx%tol) s(i) = 0.0_wp
      end do
      if (all(s(1:nv) >= 0.0_wp)) return
      if (all(s(1:nv) <= 0.0_wp)) then
         call push_fragment(rule, v(:, 1:nv), rule%ffacet(j))
         return
      end if
      nout = 0
      nedge = merge(1, nv, d == 2)
      do i = 1, nedge
         k = merge(2, mod(i, nv) + 1, d == 2)
         if (s(i) <= 0.0_wp) then
            nout = nout + 1
            out(:, nout) = v(:, i)
         end if
         if ((s(i) < 0.0_wp .and. s(k) > 0.0_wp) .or. (s(i) > 0.0_wp .and. s(k) < 0.0_wp)) then
            nout = nout + 1
            out(:, nout) = v(:, i) + (s(i)/(s(i) - s(k)))*(v(:, k) - v(:, i))
         end if
      end do
      if (d == 2 .and. s(2) <= 0.0_wp) then
         nout = nout + 1
         out(:, nout) = v(:, 2)
      end if
      if (nout < d) return
      if (polygon_measure(d, out, nout) <= ctx%min_frag) return
      call push_fragment(rule, out(:, 1:nout), rule%ffacet(j))
   end subroutine split_fragment

   !> A region of one class (faces r0 .. r1): if it is in the body, the rules of
   !> its simplices (3D: a fan from the first vertex over the fanned faces; 2D:
   !> the fanned polygon).
   pure subroutine leaf(rule, ctx, r0, r1, inside)
      type(facet_rule_type), intent(inout) :: rule
      type(context_type), intent(in) :: ctx
      logical, intent(in) :: inside
      integer, intent(in) :: r0, r1
      real(wp) :: v(3, 4)
      integer :: j, i, first

      if (.not. merge(ctx%member_in, ctx%member_out, inside)) return
      v = 0.0_wp
      v(:, 1) = rule%fv(:, rule%fstart(r0))
      do j = r0, r1
         first = rule%fstart(j)
         do i = 1, rule%fcount(j) - 2
            if (rule%dim == 2) then
               v(:, 2) = rule%fv(:, first + i)
               v(:, 3) = rule%fv(:, first + i + 1)
            else
               v(:, 2) = rule%fv(:, first)
               v(:, 3) = rule%fv(:, first + i)
               v(:, 4) = rule%fv(:, first + i + 1)
            end if
            call simplex_points(rule, ctx, v)
         end do
      end do
   end subroutine leaf

   !> Collapsed Gauss points of simplex v unless it is a sliver below the snapping measure.
   pure subroutine simplex_points(rule, ctx, v)
      type(facet_rule_type), intent(inout) :: rule
      type(context_type), intent(in) :: ctx
      real(wp), intent(in) :: v(3, 4)
      real(wp) :: e(3, 3), det, m
      integer :: i, d

      d = rule%dim
      m = simplex_measure(d, v)
      if (m <= ctx%min_vol) return
      e = 0.0_wp
      do i = 1, d
         e(:, i) = v(:, i + 1) - v(:, 1)
      end do
      det = m*merge(2.0_wp, 6.0_wp, d == 2)
      do i = 1, size(rule%ref_w)
         call push_volume(rule, v(:, 1) + matmul(e, rule%ref_x(:, i)), det*rule%ref_w(i))
      end do
   end subroutine simplex_points

   !> Surface points of the fragment poly(:, 1:nv) with outward normal n.
   pure subroutine fragment_surface(rule, d, poly, nv, n, f)
      type(facet_rule_type), intent(inout) :: rule
      integer, intent(in) :: d, nv, f
      real(wp), intent(in) :: poly(:, :), n(3)
      real(wp) :: a, x(3)
      integer :: i, k

      if (d == 2) then
         a = norm2(poly(:, 2) - poly(:, 1))
         do k = 1, size(rule%seg_w)
            x = poly(:, 1) + rule%seg_x(k)*(poly(:, 2) - poly(:, 1))
            call push_surface(rule, x, a*rule%seg_w(k), n, f)
         end do
         return
      end if
      do i = 2, nv - 1
         a = 2.0_wp*polygon_measure(3, reshape([poly(:, 1), poly(:, i), poly(:, i + 1)], [3, 3]), 3)
         if (.not. a > 0.0_wp) cycle
         do k = 1, size(rule%tri_w)
            x = poly(:, 1) + rule%tri_x(1, k)*(poly(:, i) - poly(:, 1)) + rule%tri_x(2, k)*(poly(:, i + 1) - poly(:, 1))
            call push_surface(rule, x, a*rule%tri_w(k), n, f)
         end do
      end do
   end subroutine fragment_surface

   !> Measure (area, volume) of simplex v (d + 1 vertices).
   pure real(wp) function simplex_measure(d, v) result(m)
      integer, intent(in) :: d
      real(wp), intent(in) :: v(3, 4)
      real(wp) :: a(3), b(3), c(3)
      a = v(:, 2) - v(:, 1)
      b = v(:, 3) - v(:, 1)
      if (d == 2) then
         m = 0.5_wp*abs(a(1)*b(2) - a(2)*b(1))
      else
         c = v(:, 4) - v(:, 1)
         m = abs(a(1)*(b(2)*c(3) - b(3)*c(2)) - a(2)*(b(1)*c(3) - b(3)*c(1)) + a(3)*(b(1)*c(2) - b(2)*c(1)))/6.0_wp
      end if
   end function simplex_measure

   ! ------------------------------------------------------------ compression

   !> Replace the volume rule of the cell [lo, hi] by at most M of its points with
   !> the same moments up to total degree `degree` (module notes); unchanged where
   !> it has at most M points or the solve does not match the moments.
   pure subroutine compress_volume(rule, lo, hi, degree)
      type(facet_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: degree
      call compress_points(rule, rule%dim, lo, hi, degree, rule%vol_x, rule%vol_w, rule%nvol)
   end subroutine compress_volume

   !> The points x(:, 1:n) with weights w of a rule on (part of) the box [lo, hi]
   !> in `dim` dimensions replaced by at most M of them with new positive
   !> weights keeping every moment of total degree <= `degree` (module notes);
   !> `work` holds the moment matrix. The moments are Legendre products in the
   !> coordinates of the points' bounding box scaled to [-1, 1] (the cell's
   !> would be ill-conditioned for a thin piece). NNLS costs of order M^2 per
   !> candidate point: it draws first from f M of the points sampled by weight
   !> (`spread_picks`), f = candidate_factor, 4 f, 16 f, ... while below n/2,
   !> then from all n. Unchanged where n <= M or no solve matches.
   pure subroutine compress_points(work, dim, lo, hi, degree, x, w, n)
      type(facet_rule_type), intent(inout) :: work
      integer, intent(in) :: dim, degree
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp), intent(inout) :: x(:, :), w(:)
      integer, intent(inout) :: n
      real(wp), allocatable :: b(:), v(:), y(:, :), col(:, :)
      integer, allocatable :: list(:), pick(:)
      real(wp) :: tol, blo(3), bhi(3)
      integer :: m, k, i, nc
      logical :: ok

      call moment_exponents(work, dim, degree, m)
      if (n <= m) return
      blo(1:dim) = minval(x(1:dim, 1:n), dim=2)
      bhi(1:dim) = maxval(x(1:dim, 1:n), dim=2)
      do i = 1, dim
         if (.not. bhi(i) > blo(i)) then
            blo(i) = lo(i)
            bhi(i) = hi(i)
         end if
      end do
      allocate (b(m), col(m, 1), list(m), v(m))
      b = 0.0_wp
      do i = 1, n
         call moment_matrix(work, dim, x(:, i:i), blo, bhi, degree, col)
         b = b + w(i)*col(:, 1)
      end do
      tol = real(m, wp)**2*epsilon(1.0_wp)*sum(w(1:n))
      ok = .false.
      nc = candidate_factor*m
      do while (2*nc < n .and. .not. ok)
         call spread_picks(w(1:n), nc, pick)
         call solve_on(work, dim, degree, x, pick, blo, bhi, b, tol, list, v, k, ok)
         nc = 4*nc
      end do
      if (.not. ok) call solve_on(work, dim, degree, x, [(i, i=1, n)], blo, bhi, b, tol, list, v, k, ok)
      if (.not. ok) return
      allocate (y(3, k))
      do i = 1, k
         y(:, i) = x(:, list(i))
      end do
      x(:, 1:k) = y
      w(1:k) = v(1:k)
      n = k
   end subroutine compress_points

   !> `compress_points`' NNLS on the points x(:, cand); list(1:k) then indexes x.
   pure subroutine solve_on(work, dim, degree, x, cand, blo, bhi, b, tol, list, v, k, ok)
      type(facet_rule_type), intent(in) :: work
      integer, intent(in) :: dim, degree, cand(:)
      real(wp), intent(in) :: x(:, :), blo(:), bhi(:), b(:), tol
      integer, intent(out) :: list(:), k
      real(wp), intent(out) :: v(:)
      logical, intent(out) :: ok
      real(wp), allocatable :: col(:, :)

      allocate (col(size(b), size(cand)))
      call moment_matrix(work, dim, x(:, cand), blo, bhi, degree, col)
      call nnls(col, size(b), size(cand), b, tol, list, v, k, ok)
      if (ok) list(1:k) = cand(list(1:k))
   end subroutine solve_on

   !> About nc of the points 1..size(w), drawn in proportion to their weights
   !> (systematic sampling: the points where the running sum of w crosses
   !> (i - 1/2) W/nc, each once), ascending: a discrete copy of the rule's
   !> measure, whose cone holds the moments where the solve needs them.
   pure subroutine spread_picks(w, nc, pick)
      real(wp), intent(in) :: w(:)
      integer, intent(in) :: nc
      integer, allocatable, intent(out) :: pick(:)
      real(wp) :: total, run, next
      integer :: j, k

      allocate (pick(nc))
      total = sum(w)
      run = 0.0_wp
      k = 0
      next = 0.5_wp*total/nc
      do j = 1, size(w)
         run = run + w(j)
         if (run < next) cycle
         k = k + 1
         pick(k) = j
         do while (next <= run)
            next = next + total/nc
         end do
         if (k == nc) exit
      end do
      pick = pick(1:k)
   end subroutine spread_picks

   !> Exponents of the products of Legendre polynomials of total degree <= degree
   !> in `dim` dimensions (rule%cexp(:, 1:m)).
   pure subroutine moment_exponents(rule, dim, degree, m)
      type(facet_rule_type), intent(inout) :: rule
      integer, intent(in) :: dim, degree
      integer, intent(out) :: m
      integer :: a, b, c, pass

      if (rule%cdeg == degree .and. rule%cdim == dim) then
         m = size(rule%cexp, 2)
         return
      end if
      if (allocated(rule%cexp)) deallocate (rule%cexp)
      do pass = 1, 2
         m = 0
         do a = 0, degree
            do b = 0, degree - a
               do c = 0, merge(degree - a - b, 0, dim == 3)
                  m = m + 1
                  if (pass == 2) rule%cexp(:, m) = [a, b, c]
               end do
            end do
         end do
         if (pass == 1) allocate (rule%cexp(3, m))
      end do
      rule%cdeg = degree
      rule%cdim = dim
   end subroutine moment_exponents

   !> M: the number of monomials of total degree <= `degree` in `dim` variables.
   pure integer function moment_count(dim, degree) result(m)
      integer, intent(in) :: dim, degree
      m = merge((degree + 1)*(degree + 2)/2, (degree + 1)*(degree + 2)*(degree + 3)/6, dim == 2)
   end function moment_count

   !> col(i, j): the i-th Legendre product (rule%cexp) at point x(:, j), in the
   !> coordinates of the box [lo, hi] scaled to [-1, 1].
   pure subroutine moment_matrix(rule, d, x, lo, hi, degree, col)
      type(facet_rule_type), intent(in) :: rule
      real(wp), intent(in) :: x(:, :), lo(:), hi(:)
      integer, intent(in) :: d, degree
      real(wp), intent(out) :: col(:, :)
      real(wp) :: p(0:degree, 3), t
      integer :: j, k, l, i

      p = 1.0_wp
      do j = 1, size(x, 2)
         do k = 1, d
            t = (2.0_wp*x(k, j) - lo(k) - hi(k))/(hi(k) - lo(k))
            if (degree >= 1) p(1, k) = t
            do l = 1, degree - 1
               p(l + 1, k) = (real(2*l + 1, wp)*t*p(l, k) - real(l, wp)*p(l - 1, k))/real(l + 1, wp)
            end do
         end do
         do i = 1, size(col, 1)
            col(i, j) = p(rule%cexp(1, i), 1)*p(rule%cexp(2, i), 2)*p(rule%cexp(3, i), 3)
         end do
      end do
   end subroutine moment_matrix

   !> Lawson-Hanson non-negative least squares min |A v - b|, v >= 0, with A =
   !> a(1:m, 1:n): ok when every residual is at most tol, with the k <= m
   !> columns list(1:k) and their weights v(1:k) > 0. The passive columns' QR
   !> is kept in Householder form (qr, tau, qtb = Q^T b) and extended as a
   !> column enters; a column leaving rebuilds it.
   pure subroutine nnls(a, m, n, b, tol, list, v, k, ok)
      real(wp), intent(in) :: a(:, :), b(:), tol
      integer, intent(in) :: m, n
      integer, intent(out) :: list(:), k
      real(wp), intent(out) :: v(:)
      logical, intent(out) :: ok
      real(wp) :: qr(m, m), tau(m), qtb(m), z(m, 1), r(m), gbest, alpha
      real(wp), allocatable :: g(:)
      integer :: state(n), it, j, jbest, i, kk, imin, first
      logical :: solved, added

      ! state: 0 free, 1 passive, 2 set aside (entered with a non-positive weight)
      state = 0
      k = 0
      v = 0.0_wp
      r = b
      qtb = b
      ok = .false.
      do it = 1, 3*m
         if (maxval(abs(r)) <= tol) then
            ok = k > 0
            return
         end if
         if (k == m) return
         ! A^T r by matmul: the library's kernel, also in builds with run-time checks
         g = matmul(r, a(1:m, 1:n))
         jbest = 0
         gbest = 0.0_wp
         do j = 1, n
            if (state(j) /= 0) cycle
            if (g(j) > gbest) then
               gbest = g(j)
               jbest = j
            end if
         end do
         if (jbest == 0) return
         call add_column(a(1:m, jbest), m, k, qr, tau, qtb, added)
         if (.not. added) then
            state(jbest) = 2
            cycle
         end if
         list(k) = jbest
         state(jbest) = 1
         v(k) = 0.0_wp
         do
            z(1:k, 1) = qtb(1:k)
            call solve_upper(k, qr, 1, z, solved)
            if (.not. solved) return
            if (all(z(1:k, 1) > 0.0_wp)) then
               v(1:k) = z(1:k, 1)
               exit
            end if
            if (z(k, 1) <= 0.0_wp .and. list(k) == jbest .and. v(k) == 0.0_wp) then
               ! round-off let it in: set it aside, the others keep their weights
               ! (the QR of the columns before it is unchanged: drop its reflector)
               state(jbest) = 2
               k = k - 1
               call rebuild(a, m, list, v, state, k, k + 1, qr, tau, qtb, b)
               exit
            end if
            alpha = 1.0_wp
            imin = 0
            do i = 1, k
               if (z(i, 1) <= 0.0_wp) then
                  if (v(i)/(v(i) - z(i, 1)) < alpha) then
                     alpha = v(i)/(v(i) - z(i, 1))
                     imin = i
                  end if
               end if
            end do
            v(1:k) = v(1:k) + alpha*(z(1:k, 1) - v(1:k))
            if (imin > 0) v(imin) = 0.0_wp
            kk = 0
            first = k + 1
            do i = 1, k
               if (v(i) > 0.0_wp) then
                  kk = kk + 1
                  list(kk) = list(i)
                  v(kk) = v(i)
               else
                  state(list(i)) = 0
                  first = min(first, i)
               end if
            end do
            k = kk
            call rebuild(a, m, list, v, state, k, first, qr, tau, qtb, b)
            if (k == 0) exit
         end do
         r = b
         do i = 1, k
            r = r - v(i)*a(1:m, list(i))
         end do
      end do
   end subroutine nnls

   !> Append column c as column k + 1 of the Householder QR (qr, tau) and update
   !> qtb; not added (k unchanged) when c lies in the span of the first k
   !> columns to round-off.
   pure subroutine add_column(c, m, k, qr, tau, qtb, added)
      integer, intent(in) :: m
      real(wp), intent(in) :: c(m)
      integer, intent(inout) :: k
      real(wp), intent(inout) :: qr(m, m), tau(m), qtb(m)
      logical, intent(out) :: added
      integer :: i

      added = .false.
      if (k >= m) return
      qr(1:m, k + 1) = c(1:m)
      do i = 1, k
         call reflect(m - i + 1, qr(i + 1:m, i), tau(i), qr(i:m, k + 1))
      end do
      if (norm2(qr(k + 1:m, k + 1)) <= real(m, wp)*epsilon(1.0_wp)*norm2(c(1:m))) return
      k = k + 1
      call reflector(qr(k:m, k), tau(k))
      call reflect(m - k + 1, qr(k + 1:m, k), tau(k), qtb(k:m))
      added = .true.
   end subroutine add_column

   !> The QR of the columns list(1:k) of a from column `first` on (columns before
   !> it and their reflectors are unchanged: Householder QR's column j depends on
   !> columns 1..j only); a column that turns out dependent leaves the list (with
   !> its weight v) and is set aside (state 2).
   pure subroutine rebuild(a, m, list, v, state, k, first, qr, tau, qtb, b)
      real(wp), intent(in) :: a(:, :), b(:)
      integer, intent(in) :: m, first
      integer, intent(inout) :: list(:), state(:), k
      real(wp), intent(inout) :: v(:), qr(m, m), tau(m), qtb(m)
      integer :: i, kk
      logical :: added
      qtb = b(1:m)
      kk = min(first - 1, k)
      do i = 1, kk
         call reflect(m - i + 1, qr(i + 1:m, i), tau(i), qtb(i:m))
      end do
      do i = kk + 1, k
         call add_column(a(1:m, list(i)), m, kk, qr, tau, qtb, added)
         if (added) then
            list(kk) = list(i)
            v(kk) = v(i)
         else
            state(list(i)) = 2
         end if
      end do
      k = kk
   end subroutine rebuild

   ! ------------------------------------------------------------ growing arrays

   pure subroutine push_fragment(rule, v, f)
      type(facet_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: v(:, :)
      integer, intent(in) :: f
      real(wp), allocatable :: t(:, :)
      integer, allocatable :: a(:), b(:), c(:)
      integer :: nv, cap

      nv = size(v, 2)
      do while (rule%nfv + nv > size(rule%fv, 2))
         allocate (t(3, 2*size(rule%fv, 2)))
         t(:, 1:rule%nfv) = rule%fv(:, 1:rule%nfv)
         call move_alloc(t, rule%fv)
      end do
      cap = size(rule%ffacet)
      if (rule%nfrag == cap) then
         allocate (a(2*cap), b(2*cap), c(2*cap))
         a(1:cap) = rule%fstart
         b(1:cap) = rule%fcount
         c(1:cap) = rule%ffacet
         call move_alloc(a, rule%fstart)
         call move_alloc(b, rule%fcount)
         call move_alloc(c, rule%ffacet)
      end if
      rule%nfrag = rule%nfrag + 1
      rule%fstart(rule%nfrag) = rule%nfv + 1
      rule%fcount(rule%nfrag) = nv
      rule%ffacet(rule%nfrag) = f
      rule%fv(:, rule%nfv + 1:rule%nfv + nv) = v
      rule%nfv = rule%nfv + nv
   end subroutine push_fragment

   pure subroutine push_volume(rule, x, w)
      type(facet_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: x(3), w
      real(wp), allocatable :: tx(:, :), tw(:)
      integer :: cap
      cap = size(rule%vol_w)
      if (rule%nvol == cap) then
         allocate (tx(3, 2*cap), tw(2*cap))
         tx(:, 1:cap) = rule%vol_x
         tw(1:cap) = rule%vol_w
         call move_alloc(tx, rule%vol_x)
         call move_alloc(tw, rule%vol_w)
      end if
      rule%nvol = rule%nvol + 1
      rule%vol_x(:, rule%nvol) = x
      rule%vol_w(rule%nvol) = w
   end subroutine push_volume

   pure subroutine push_surface(rule, x, w, n, f)
      type(facet_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: x(3), w, n(3)
      integer, intent(in) :: f
      real(wp), allocatable :: tx(:, :), tw(:), tn(:, :)
      integer, allocatable :: tf(:)
      integer :: cap
      cap = size(rule%surf_w)
      if (rule%nsurf == cap) then
         allocate (tx(3, 2*cap), tw(2*cap), tn(3, 2*cap), tf(2*cap))
         tx(:, 1:cap) = rule%surf_x
         tw(1:cap) = rule%surf_w
         tn(:, 1:cap) = rule%surf_n
         tf(1:cap) = rule%surf_facet
         call move_alloc(tx, rule%surf_x)
         call move_alloc(tw, rule%surf_w)
         call move_alloc(tn, rule%surf_n)
         call move_alloc(tf, rule%surf_facet)
      end if
      rule%nsurf = rule%nsurf + 1
      rule%surf_x(:, rule%nsurf) = x
      rule%surf_w(rule%nsurf) = w
      rule%surf_n(:, rule%nsurf) = n
      rule%surf_facet(rule%nsurf) = f
   end subroutine push_surface

end module sprc_grid_facet_rule
