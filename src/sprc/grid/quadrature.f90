!> Quadrature of grid cells on the true curved geometry of a body: tensor
!> Gauss-Legendre for inside cells, and for cut cells a volume rule for
!> cell ∩ body and a surface rule for the body's boundary inside the cell,
!> with exact unit outward normals and the shape index (hence the surface
!> name) at every surface point. All weights are positive.
!>
!> Method (Saye 2015, dimension reduction; doc/theory.md, section 2): the
!> active shapes become quadrics in reference coordinates (sprc_grid_quadric);
!> a height direction k is sought in which every quadric is monotone and every
!> pair of surfaces meets in a quadric (CSG edges resolved exactly); the base
!> gets its rule one dimension lower and each base point is lifted through the
!> closed-form roots on its height line. Beyond Saye's condition the direction
!> must be strong, min |dp/dy_k| >= min_ratio * (variation of dp/dy_k), which
!> keeps the height function's square-root singularities min_ratio box widths
!> away, so Gauss converges geometrically on every level. A surface free of
!> y_k (a wall parallel to the height lines) gets its own pass in a direction
!> that crosses it. Where no direction qualifies the box is halved, up to
!> max_depth times (20 in 2D, 10 in 3D); beyond that the best direction is used
!> as is (`nunresolved`; error bounded by that box's measure); `nsplit` counts
!> the subdivisions.
!>
!> Boundaries on grid planes (a halfspace or box face on a cell face, within
!> the snapping tolerance) are never a cut: their face part enters only the
!> surface rule of the cell on the body side, decided by CSG membership with
!> that shape's one-sided value. `boundary_face_rule` gives only these points.
!>
!> Points per direction: `default_points(order)` = order + 2: exact for the
!> full-cell integrands (degree <= 2p needs p + 1), one more for error norms of
!> non-polynomial exact solutions (the `--points` option sets any other q).
!>
!> No module state; every procedure is pure. A `cell_rule_type` holds the
!> result and its work arrays, reused across cells: use one per thread.
module sprc_grid_quadrature
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa, rtoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_out_of_memory
   use sprc_core_gauss, only: max_gauss_points, gauss_legendre_nodes
   use sprc_geometry_region, only: cell_outside, cell_inside, cell_cut
   use sprc_geometry_shape, only: shape_halfspace, shape_box, shape_facets
   use sprc_grid_facet_rule, only: facet_rule_type, facet_cell_rule, facet_face_rule, compress_points, &
      & moment_count, compress_min_factor
   use sprc_geometry_facet_solid, only: facet_solid_type, face_cover, solid_nearest, solid_query_box
   use sprc_geometry_body, only: body_type, csg_add, csg_intersect, snap_tolerance
   use sprc_grid_quadric, only: ncoef, max_shape_quadrics, quadric_range, derivative_range, &
      & quadric_gradient, depends_on, restrict, line_coefficients, quadratic_roots, shape_quadrics, crossing
   implicit none
   private

   public :: cut_quadrature_type, new_cut_quadrature, default_points, default_max_depth, default_min_ratio
   public :: cell_rule_type, cell_rule, cut_cell_rule, boundary_face_rule, tensor_point

   !> Settings of the cut-cell quadrature: immutable once built, share it between threads.
   type :: cut_quadrature_type
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Gauss points per direction (per piece).
      integer :: q = 0
      !> Subdivision levels allowed before a box is integrated unresolved.
      integer :: max_depth = 0
      !> Strength of a height direction: min |dp/dy_k| over the box must be at
      !> least min_ratio times its variation over the box (module notes).
      real(wp) :: min_ratio = 0.0_wp
      !> Gauss nodes on [0, 1] and weights summing to 1.
      real(wp) :: node(max_gauss_points) = 0.0_wp
      real(wp) :: weight(max_gauss_points) = 0.0_wp
   end type cut_quadrature_type

   !> The quadrature of one cell. Result arrays are valid in 1:nvol and
   !> 1:nsurf; they and the private work arrays keep their capacity between
   !> calls.
   type :: cell_rule_type
      !> Space dimension.
      integer :: dim = 0
      !> Class of the cell (cell_inside, cell_cut, cell_outside) as used.
      integer :: cls = cell_outside
      !> Volume points: coordinates (3, :) (dim used) and weights (|J| included).
      integer :: nvol = 0
      real(wp), allocatable :: vol_x(:, :), vol_w(:)
      !> Surface points: coordinates, weights (surface measure), unit outward
      !> normals (3, :), and the body's surface id (sprc_geometry_body notes:
      !> the shape index, or a faceted shape's group).
      integer :: nsurf = 0
      real(wp), allocatable :: surf_x(:, :), surf_w(:), surf_n(:, :)
      integer, allocatable :: surf_shape(:)
      !> Boxes subdivided (fallback) while building this rule.
      integer :: nsplit = 0
      !> Boxes integrated at max_depth without a valid height direction.
      integer :: nunresolved = 0
      real(wp), allocatable, private :: sy(:, :), sw(:)
      integer, private :: ns = 0
      real(wp), allocatable, private :: poly(:, :)
      integer, allocatable, private :: owner(:), tag(:)
      integer, private :: np = 0
      !> Work of one level of the reduction (used before it recurses, or not recursive):
      !> the roots on a height line and their quadrics, the shapes of a box, the
      !> quadrics a surface pass requires.
      real(wp), allocatable, private :: roots(:)
      integer, allocatable, private :: root_owner(:), shapes(:)
      logical, allocatable, private :: require(:)
      !> An array could not grow (out of memory): the rule is incomplete.
      logical, private :: failed = .false.
      !> Work and points of the faceted-solid rule.
      type(facet_rule_type), private :: facets
   end type cell_rule_type

   !> Facets a box may meet before `mixed_box` halves it.
   integer, parameter :: max_box_facets = 32

   !> Default strength of a height direction (module notes, `min_ratio`).
   real(wp), parameter :: default_min_ratio = 3.0_wp

   !> What the top level of the reduction produces.
   type :: context_type
      integer :: dim = 0
      real(wp) :: center(3) = 0.0_wp, half(3) = 0.0_wp
      !> 0: cell volume and surface; else the shape on the cell face being integrated.
      integer :: face_shape = 0
      integer :: face_dim = 0
      !> +1: the cell's upper face along face_dim, -1: the lower one.
      real(wp) :: face_side = 0.0_wp
      !> The coinciding shape's inside lies on the cell side of the face.
      logical :: cell_side_inside = .false.
   end type context_type

contains

   ! ------------------------------------------------------------ settings

   !> Gauss points per direction for FE order p (1 or 2): p + 2 (module notes).
   pure integer function default_points(order) result(q)
      integer, intent(in) :: order
      q = max(order, 1) + 2
   end function default_points

   !> Default subdivision depth: 20 in 2D (a box 1e-6 of the cell), 10 in 3D.
   pure integer function default_max_depth(dim) result(depth)
      integer, intent(in) :: dim
      depth = merge(20, 10, dim == 2)
   end function default_max_depth

   !> Settings for dimension dim (2 or 3) with q points per direction
   !> (1..max_gauss_points), optionally a subdivision depth (0..30, default
   !> `default_max_depth(dim)`) and a height-direction strength min_ratio
   !> (0..100, default `default_min_ratio` = 3; 0 is Saye's plain condition).
   pure subroutine new_cut_quadrature(self, dim, q, error, max_depth, min_ratio)
      type(cut_quadrature_type), intent(out) :: self
      integer, intent(in) :: dim, q
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: max_depth
      real(wp), intent(in), optional :: min_ratio
      real(wp) :: t(max_gauss_points), w(max_gauss_points)

      if (dim /= 2 .and. dim /= 3) then
         call fatal_error(error, 'new_cut_quadrature: dim = '//itoa(dim)//', expected 2 or 3', stat_invalid_input)
         return
      end if
      if (q < 1 .or. q > max_gauss_points) then
         call fatal_error(error, 'new_cut_quadrature: q = '//itoa(q)//' points, expected 1 to '// &
            & itoa(max_gauss_points), stat_invalid_input)
         return
      end if
      self%max_depth = default_max_depth(dim)
      if (present(max_depth)) then
         if (max_depth < 0 .or. max_depth > 30) then
            call fatal_error(error, 'new_cut_quadrature: max_depth = '//itoa(max_depth)// &
               & ', expected 0 to 30', stat_invalid_input)
            return
         end if
         self%max_depth = max_depth
      end if
      self%min_ratio = default_min_ratio
      if (present(min_ratio)) then
         if (.not. (min_ratio >= 0.0_wp .and. min_ratio <= 100.0_wp)) then
            call fatal_error(error, 'new_cut_quadrature: min_ratio = '//rtoa(min_ratio, '(g0)')// &
               & ', expected 0 to 100', stat_invalid_input)
            return
         end if
         self%min_ratio = min_ratio
      end if
      call gauss_legendre_nodes(q, t, w)
      self%dim = dim
      self%q = q
      self%node(1:q) = 0.5_wp*(t(1:q) + 1.0_wp)
      self%weight(1:q) = 0.5_wp*w(1:q)
   end subroutine new_cut_quadrature

   ! ------------------------------------------------------------ entry points

   !> The rule of any cell [lo, hi]: classified by body%classify_box; inside:
   !> tensor Gauss plus boundary faces on grid planes; cut: `cut_cell_rule`;
   !> outside: empty.
   pure subroutine cell_rule(quad, body, lo, hi, rule, error)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      type(error_type), allocatable, intent(out) :: error

      call check_input(quad, body, lo, hi, 'cell_rule', error)
      if (allocated(error)) return
      call reset(rule, quad%dim)
      rule%cls = body%classify_box(lo, hi)
      if (rule%failed) rule%cls = cell_outside
      select case (rule%cls)
      case (cell_inside)
         call tensor_volume(quad, lo, hi, rule)
         call add_face_parts(quad, body, lo, hi, rule)
      case (cell_cut)
         call cut_rule(quad, body, lo, hi, rule)
      end select
      call check_failed(rule, 'cell_rule', lo, hi, error)
   end subroutine cell_rule

   !> Volume and surface rule of a cell [lo, hi] treated as cut (whatever its
   !> class; an inside cell gives the tensor rule the long way), including the
   !> boundary parts on its faces that it owns.
   pure subroutine cut_cell_rule(quad, body, lo, hi, rule, error)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      type(error_type), allocatable, intent(out) :: error

      call check_input(quad, body, lo, hi, 'cut_cell_rule', error)
      if (allocated(error)) return
      call reset(rule, quad%dim)
      rule%cls = cell_cut
      if (.not. rule%failed) call cut_rule(quad, body, lo, hi, rule)
      call check_failed(rule, 'cut_cell_rule', lo, hi, error)
   end subroutine cut_cell_rule

   !> Only the surface points of boundary parts lying on the faces of the cell
   !> [lo, hi] that this cell owns (module notes); nvol = 0. For a cell
   !> classified inside, whose volume rule is the tensor rule.
   pure subroutine boundary_face_rule(quad, body, lo, hi, rule, error)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      type(error_type), allocatable, intent(out) :: error

      call check_input(quad, body, lo, hi, 'boundary_face_rule', error)
      if (allocated(error)) return
      call reset(rule, quad%dim)
      rule%cls = body%classify_box(lo, hi)
      if (.not. rule%failed) call add_face_parts(quad, body, lo, hi, rule)
      call check_failed(rule, 'boundary_face_rule', lo, hi, error)
   end subroutine boundary_face_rule

   !> The error of a rule whose arrays could not grow (`failed`): out of memory, never
   !> a crash; the rule is then empty.
   pure subroutine check_failed(rule, where, lo, hi, error)
      type(cell_rule_type), intent(inout) :: rule
      character(len=*), intent(in) :: where
      real(wp), intent(in) :: lo(:), hi(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      character(len=:), allocatable :: box

      if (.not. rule%failed) return
      rule%nvol = 0
      rule%nsurf = 0
      box = ''
      do i = 1, size(lo)
         box = box//' ['//rtoa(lo(i))//', '//rtoa(hi(i))//']'
      end do
      call fatal_error(error, where//': out of memory for the quadrature points or work arrays of the cell'// &
         & box, stat_out_of_memory)
   end subroutine check_failed

   pure subroutine check_input(quad, body, lo, hi, where, error)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      character(len=*), intent(in) :: where
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      if (quad%dim == 0) then
         call fatal_error(error, where//': quadrature settings not built (new_cut_quadrature)', stat_invalid_input)
         return
      end if
      if (body%nshape == 0 .or. body%dim /= quad%dim) then
         call fatal_error(error, where//': body has dimension '//itoa(body%dim)//' and '// &
            & itoa(body%nshape)//' shapes, the quadrature dimension '//itoa(quad%dim), stat_invalid_input)
         return
      end if
      if (size(lo) /= quad%dim .or. size(hi) /= quad%dim) then
         call fatal_error(error, where//': lo and hi have '//itoa(size(lo))//' and '//itoa(size(hi))// &
            & ' values, expected '//itoa(quad%dim), stat_invalid_input)
         return
      end if
      do i = 1, quad%dim
         if (.not. (lo(i) < hi(i) .and. abs(hi(i) - lo(i)) < huge(1.0_wp))) then
            call fatal_error(error, where//': cell extent lo('//itoa(i)//') < hi('//itoa(i)// &
               & ') violated or not finite', stat_invalid_input)
            return
         end if
      end do
   end subroutine check_input

   pure subroutine reset(rule, dim)
      type(cell_rule_type), intent(inout) :: rule
      integer, intent(in) :: dim
      integer :: st
      rule%dim = dim
      rule%cls = cell_outside
      rule%nvol = 0
      rule%nsurf = 0
      rule%nsplit = 0
      rule%nunresolved = 0
      rule%ns = 0
      rule%np = 0
      rule%failed = .false.
      if (allocated(rule%roots)) return
      ! all or nothing: a failure leaves every array unallocated for the next reset
      if (allocated(rule%vol_x)) deallocate (rule%vol_x, rule%vol_w)
      if (allocated(rule%surf_x)) deallocate (rule%surf_x, rule%surf_w, rule%surf_n, rule%surf_shape)
      if (allocated(rule%sy)) deallocate (rule%sy, rule%sw, rule%poly, rule%owner, rule%tag)
      allocate (rule%vol_x(3, 64), rule%vol_w(64), stat=st)
      if (st == 0) allocate (rule%surf_x(3, 32), rule%surf_w(32), rule%surf_n(3, 32), rule%surf_shape(32), &
         & stat=st)
      if (st == 0) allocate (rule%sy(3, 64), rule%sw(64), rule%poly(0:ncoef - 1, 16), rule%owner(16), &
         & rule%tag(16), stat=st)
      if (st == 0) allocate (rule%roots(0:33), rule%root_owner(0:33), rule%shapes(16), rule%require(16), stat=st)
      rule%failed = st /= 0
   end subroutine reset

   !> Work arrays for n roots (indices 0 .. 2 n + 1), n quadrics to require and n shapes
   !> (grown, never shrunk; `failed` if they cannot grow).
   pure subroutine reserve_work(rule, n)
      type(cell_rule_type), intent(inout) :: rule
      integer, intent(in) :: n
      integer :: st

      if (size(rule%require) >= n) return
      deallocate (rule%roots, rule%root_owner, rule%shapes, rule%require)
      allocate (rule%roots(0:2*n + 1), rule%root_owner(0:2*n + 1), rule%shapes(n), rule%require(n), stat=st)
      if (st == 0) return
      ! back to the empty state: the next reset allocates afresh
      rule%failed = .true.
      if (allocated(rule%roots)) deallocate (rule%roots)
      if (allocated(rule%root_owner)) deallocate (rule%root_owner)
      if (allocated(rule%shapes)) deallocate (rule%shapes)
      if (allocated(rule%require)) deallocate (rule%require)
   end subroutine reserve_work

   !> Tensor rule of the whole cell.
   pure subroutine tensor_volume(quad, lo, hi, rule)
      type(cut_quadrature_type), intent(in) :: quad
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      real(wp) :: x(3), w
      integer :: ipt

      do ipt = 1, quad%q**quad%dim
         call tensor_point(quad, lo, hi, ipt, x, w)
         call push_volume(rule, x, w)
      end do
   end subroutine tensor_volume

   !> Point `ipt` (1 .. q**dim, first direction fastest) of the tensor Gauss rule of the
   !> box [lo, hi]: coordinates x(1:dim) (x(dim+1:) = 0) and weight w (|J| included).
   pure subroutine tensor_point(quad, lo, hi, ipt, x, w)
      type(cut_quadrature_type), intent(in) :: quad
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: ipt
      real(wp), intent(out) :: x(:), w
      integer :: i, d, idx

      i = ipt - 1
      w = 1.0_wp
      x = 0.0_wp
      do d = 1, quad%dim
         idx = mod(i, quad%q) + 1
         i = i/quad%q
         x(d) = lo(d) + (hi(d) - lo(d))*quad%node(idx)
         w = w*(hi(d) - lo(d))*quad%weight(idx)
      end do
   end subroutine tensor_point

   !> Cut rule proper: the active shapes' quadrics on the cell, then the faces.
   !> Where a faceted solid is active, the cell's volume rule (fanned simplices,
   !> thousands of points) is compressed once for the whole cell to at most M
   !> positive-weight points with the same moments up to degree 2q - 1, the
   !> degree the uncut cell's tensor rule integrates (sprc_grid_facet_rule,
   !> `compress_points`): assembly, recovery and estimate loop over them.
   !> Rules of at most compress_min_factor M points stay as they are: there
   !> the NNLS (M^2 per candidate, all points when the sampled solves miss the
   !> moments) costs more than the dropped points save downstream.
   pure subroutine cut_rule(quad, body, lo, hi, rule)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      integer :: n, active(body%nshape)

      call body%active_shapes(lo, hi, active, n)
      if (any(body%shapes(active(1:n))%kind == shape_facets)) then
         call mixed_box(quad, body, lo, hi, lo, hi, 0, rule)
         if (rule%nvol > compress_min_factor*moment_count(quad%dim, 2*quad%q - 1)) &
            & call compress_points(rule%facets, quad%dim, lo, hi, 2*quad%q - 1, rule%vol_x, rule%vol_w, rule%nvol)
         if (quad%dim == 3) call compress_planes(quad, rule)
      else
         call saye_rule(quad, body, lo, hi, rule, active(1:n))
      end if
      call add_face_parts(quad, body, lo, hi, rule)
   end subroutine cut_rule

   !> The surface points of a 3D cell a faceted solid cuts, compressed plane by
   !> plane: points of one surface id with one normal (the fragments of one
   !> facet, or of a halfspace in `mixed_box`'s boxes) lie in one plane, and
   !> where more than M of them do (M the moments of total degree 2q - 1 in two
   !> variables, 21 for q = 3; the NNLS is cheap at that size) `compress_points`
   !> keeps at most M of them,
   !> with positive weights and the same moments in the plane's coordinates:
   !> the degree the fanned Gauss rules integrate exactly. Without it a cell
   !> where a facet meets another surface keeps the points of every box
   !> `mixed_box` halved it into (thousands). Curved pieces (normals that
   !> differ point to point) stay as they are.
   pure subroutine compress_planes(quad, rule)
      type(cut_quadrature_type), intent(in) :: quad
      type(cell_rule_type), intent(inout) :: rule
      real(wp), allocatable :: y(:, :), w(:), x(:, :), nrm(:, :), wt(:)
      integer, allocatable :: members(:), shp(:)
      logical :: taken(rule%nsurf)
      real(wp) :: t1(3), t2(3), lo2(2), hi2(2)
      integer :: i, j, k, m2, ng, nout

      m2 = moment_count(2, 2*quad%q - 1)
      if (rule%nsurf <= m2) return
      taken = .false.
      allocate (x(3, rule%nsurf), wt(rule%nsurf), nrm(3, rule%nsurf), shp(rule%nsurf), members(rule%nsurf))
      nout = 0
      do i = 1, rule%nsurf
         if (taken(i)) cycle
         ng = 0
         do j = i, rule%nsurf
            if (taken(j) .or. rule%surf_shape(j) /= rule%surf_shape(i)) cycle
            if (any(rule%surf_n(:, j) /= rule%surf_n(:, i))) cycle
            taken(j) = .true.
            ng = ng + 1
            members(ng) = j
         end do
         if (ng > m2) then
            call plane_basis(rule%surf_n(:, i), t1, t2)
            allocate (y(3, ng), w(ng))
            do k = 1, ng
               y(:, k) = [dot_product(t1, rule%surf_x(:, members(k))), dot_product(t2, rule%surf_x(:, members(k))), &
                  & real(members(k), wp)]
               w(k) = rule%surf_w(members(k))
            end do
            lo2 = minval(y(1:2, :), dim=2)
            hi2 = maxval(y(1:2, :), dim=2)
            call compress_points(rule%facets, 2, lo2, hi2, 2*quad%q - 1, y, w, ng)
            members(1:ng) = nint(y(3, 1:ng))
         else
            allocate (w(ng))
            w = rule%surf_w(members(1:ng))
         end if
         do k = 1, ng
            nout = nout + 1
            x(:, nout) = rule%surf_x(:, members(k))
            wt(nout) = w(k)
            nrm(:, nout) = rule%surf_n(:, members(k))
            shp(nout) = rule%surf_shape(members(k))
         end do
         if (allocated(y)) deallocate (y)
         deallocate (w)
      end do
      rule%nsurf = nout
      rule%surf_x(:, 1:nout) = x(:, 1:nout)
      rule%surf_w(1:nout) = wt(1:nout)
      rule%surf_n(:, 1:nout) = nrm(:, 1:nout)
      rule%surf_shape(1:nout) = shp(1:nout)
   end subroutine compress_planes

   !> Two unit vectors spanning the plane of unit normal n (with n, right-handed).
   pure subroutine plane_basis(n, t1, t2)
      real(wp), intent(in) :: n(3)
      real(wp), intent(out) :: t1(3), t2(3)
      real(wp) :: e(3)
      e = 0.0_wp
      e(minloc(abs(n), dim=1)) = 1.0_wp
      t1 = [n(2)*e(3) - n(3)*e(2), n(3)*e(1) - n(1)*e(3), n(1)*e(2) - n(2)*e(1)]
      t1 = t1/norm2(t1)
      t2 = [n(2)*t1(3) - n(3)*t1(2), n(3)*t1(1) - n(1)*t1(3), n(1)*t1(2) - n(2)*t1(1)]
   end subroutine plane_basis

   !> Volume and surface rule of the box [lo, hi] by dimension reduction on the
   !> quadrics of the shapes `active` (no boundary parts on its faces).
   pure subroutine saye_rule(quad, body, lo, hi, rule, active)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      integer, intent(in) :: active(:)
      type(context_type) :: ctx
      real(wp) :: ylo(3), yhi(3)
      integer :: i, dim
      logical :: free(3)

      dim = quad%dim
      call new_context(ctx, dim, lo, hi)
      call reserve_work(rule, body%nshape)
      if (rule%failed) return
      rule%np = 0
      do i = 1, size(active)
         call add_shape_quadrics(body, active(i), ctx, lo, hi, rule)
      end do
      ylo = 0.0_wp
      yhi = 0.0_wp
      ylo(1:dim) = -1.0_wp
      yhi(1:dim) = 1.0_wp
      free = .false.
      free(1:dim) = .true.
      call reduce(ctx, quad, body, rule, ylo, yhi, free, 1, rule%np, .true., 0, 0)
      rule%np = 0
   end subroutine saye_rule

   !> Rule of the box [lo, hi] inside the cell [clo, chi] when a faceted solid is
   !> among its active shapes. One active shape, faceted: the exact polyhedral
   !> rule (sprc_grid_facet_rule), after halving the box while it meets more
   !> than `max_box_facets` facets (up to `mixed_depth` levels: the partition's
   !> depth and size grow with the facets of a box). Only primitives:
   !> dimension reduction. A
   !> faceted solid with other active shapes (a CSG edge between a faceted and
   !> another surface): the box is halved, up to `mixed_depth` levels; at that
   !> depth the box counts in `nunresolved` and gets its tensor rule with
   !> membership at each point (body%phi) and no surface points: the error is
   !> bounded by the measure and boundary measure of such boxes. Facet
   !> fragments on the faces of sub-boxes inside the cell enter the surface
   !> rule once, from the sub-box on the body side; those on the cell's faces
   !> are the cell's `add_face_parts`.
   pure recursive subroutine mixed_box(quad, body, clo, chi, lo, hi, depth, rule)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: clo(:), chi(:), lo(:), hi(:)
      integer, intent(in) :: depth
      type(cell_rule_type), intent(inout) :: rule
      real(wp) :: slo(size(lo)), shi(size(lo)), mid(size(lo))
      integer :: active(body%nshape), n, child, k, d

      d = size(lo)
      call body%active_shapes(lo, hi, active, n)
      if (depth > 0) call add_facet_face_parts(quad, body, lo, hi, rule, clo, chi)
      if (n == 0) then
         if (body%classify_box(lo, hi) == cell_inside) call tensor_volume(quad, lo, hi, rule)
         return
      end if
      if (.not. any(body%shapes(active(1:n))%kind == shape_facets)) then
         call saye_rule(quad, body, lo, hi, rule, active(1:n))
         return
      end if
      if (n == 1) then
         if (depth >= mixed_depth(d) .or. box_facets(body%shapes(active(1))%solid, lo, hi) <= max_box_facets) then
            call facet_box(quad, body, lo, hi, rule, active(1))
            return
         end if
      else if (depth >= mixed_depth(d)) then
         rule%nunresolved = rule%nunresolved + 1
         call member_tensor(quad, body, lo, hi, rule)
         return
      end if
      rule%nsplit = rule%nsplit + 1
      mid = 0.5_wp*(lo + hi)
      do child = 0, 2**d - 1
         do k = 1, d
            slo(k) = merge(mid(k), lo(k), btest(child, k - 1))
            shi(k) = merge(hi(k), mid(k), btest(child, k - 1))
         end do
         call mixed_box(quad, body, clo, chi, slo, shi, depth + 1, rule)
      end do
   end subroutine mixed_box

   !> Facets whose boxes meet the box [lo, hi].
   pure integer function box_facets(solid, lo, hi) result(n)
      type(facet_solid_type), intent(in) :: solid
      real(wp), intent(in) :: lo(:), hi(:)
      integer, allocatable :: list(:)
      call solid_query_box(solid, lo, hi, list, n)
   end function box_facets

   !> Halvings of a cell cut by a faceted and another surface (`mixed_box`).
   pure integer function mixed_depth(dim)
      integer, intent(in) :: dim
      mixed_depth = merge(8, 4, dim == 2)
   end function mixed_depth

   !> Tensor rule of the box keeping the points inside the body (phi < 0).
   pure subroutine member_tensor(quad, body, lo, hi, rule)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      real(wp) :: x(3), w
      integer :: ipt
      do ipt = 1, quad%q**quad%dim
         call tensor_point(quad, lo, hi, ipt, x, w)
         if (body%phi(x(1:quad%dim)) < 0.0_wp) call push_volume(rule, x, w)
      end do
   end subroutine member_tensor

   !> The exact polyhedral rule of the box [lo, hi] where the faceted shape s is
   !> the only active shape.
   pure subroutine facet_box(quad, body, lo, hi, rule, s)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      integer, intent(in) :: s
      integer :: classes(body%nshape), i
      logical :: member_in, member_out

      call body%shape_classes(lo, hi, classes)
      member_in = body%class_with(classes, s, cell_inside) == cell_inside
      member_out = body%class_with(classes, s, cell_outside) == cell_inside
      call facet_cell_rule(rule%facets, body%shapes(s)%solid, lo, hi, quad%q, member_in, member_out)
      rule%nsplit = rule%nsplit + rule%facets%nsplit
      do i = 1, rule%facets%nvol
         call push_volume(rule, rule%facets%vol_x(:, i), rule%facets%vol_w(i))
      end do
      call push_facet_surface(body, rule, s)
   end subroutine facet_box

   !> Append the facet rule's surface points of shape s with their surface ids.
   pure subroutine push_facet_surface(body, rule, s)
      class(body_type), intent(in) :: body
      type(cell_rule_type), intent(inout) :: rule
      integer, intent(in) :: s
      integer :: i, g, id
      do i = 1, rule%facets%nsurf
         g = 0
         if (allocated(body%shapes(s)%solid%set%group)) g = body%shapes(s)%solid%set%group(rule%facets%surf_facet(i))
         id = body%group_surface(s, g)
         call push_surface(rule, rule%facets%surf_x(:, i), rule%facets%surf_w(i), rule%facets%surf_n(:, i), id)
      end do
   end subroutine push_facet_surface

   !> Facet fragments in the face planes of the box [lo, hi] where it is on the
   !> body side: a point is kept where the body's membership just on the box
   !> side (the faceted shape's value replaced by inside or outside as its
   !> fragment says) is in and just across is out, as `face_member` does for
   !> the primitives; exact where no other surface crosses the fragment,
   !> point-sampled where one does. Faces the facets cover whole are left to
   !> the primitives' face rule (`on_face_plane`, exact with the other
   !> shapes' quadrics). With the cell [clo, chi] (a sub-box of it), fragments
   !> on the cell's own faces are left out (the cell adds them).
   pure subroutine add_facet_face_parts(quad, body, lo, hi, rule, clo, chi)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in), optional :: clo(:), chi(:)
      real(wp) :: v, x(3)
      integer :: s, i, d, g, f, m, iside
      logical :: here, there, covered(2, 3)

      if (.not. any(body%shapes%kind == shape_facets)) return
      d = quad%dim
      do s = 1, body%nshape
         if (body%shapes(s)%kind /= shape_facets) cycle
         do m = 1, d
            do iside = 1, 2
               covered(iside, m) = face_cover(body%shapes(s)%solid, lo, hi, m, 2*iside - 3) /= 0
            end do
         end do
         call facet_face_rule(rule%facets, body%shapes(s)%solid, lo, hi, quad%q, covered(:, 1:d), clo, chi)
         do i = 1, rule%facets%nsurf
            f = rule%facets%surf_facet(i)
            v = merge(-1.0_wp, 1.0_wp, f > 0)
            x = rule%facets%surf_x(:, i)
            here = csg_phi(body, x(1:d), s, v) < 0.0_wp
            there = csg_phi(body, x(1:d), s, -v) < 0.0_wp
            if (.not. here .or. there) cycle
            g = 0
            if (allocated(body%shapes(s)%solid%set%group)) g = body%shapes(s)%solid%set%group(abs(f))
            call push_surface(rule, x, rule%facets%surf_w(i), sign(1.0_wp, -v)*rule%facets%surf_n(:, i), &
               & body%group_surface(s, g))
         end do
      end do
   end subroutine add_facet_face_parts

   pure subroutine new_context(ctx, dim, lo, hi)
      type(context_type), intent(out) :: ctx
      integer, intent(in) :: dim
      real(wp), intent(in) :: lo(:), hi(:)
      ctx%dim = dim
      ctx%center(1:dim) = 0.5_wp*(lo(1:dim) + hi(1:dim))
      ctx%half(1:dim) = 0.5_wp*(hi(1:dim) - lo(1:dim))
   end subroutine new_context

   !> Push the quadrics of shape s for the x-box [lo, hi] (owner s).
   pure subroutine add_shape_quadrics(body, s, ctx, lo, hi, rule)
      class(body_type), intent(in) :: body
      integer, intent(in) :: s
      type(context_type), intent(in) :: ctx
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      real(wp) :: polys(0:ncoef - 1, max_shape_quadrics), xlo(3), xhi(3), tol
      integer :: n, j

      xlo = 0.0_wp
      xhi = 0.0_wp
      xlo(1:ctx%dim) = lo(1:ctx%dim)
      xhi(1:ctx%dim) = hi(1:ctx%dim)
      tol = snap_tolerance(body%shapes(s), lo, hi)
      call shape_quadrics(body%shapes(s), ctx%center, ctx%half, xlo, xhi, tol, polys, n)
      do j = 1, n
         call push_poly(rule, polys(:, j), s, rule%np + 1)
      end do
   end subroutine add_shape_quadrics

   ! ------------------------------------------------------------ faces on grid planes

   !> For each face of the cell and each shape whose surface lies on that face
   !> plane, the face part where this cell is on the body side (module notes).
   pure subroutine add_face_parts(quad, body, lo, hi, rule)
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      type(cell_rule_type), intent(inout) :: rule
      type(context_type) :: ctx
      real(wp) :: flo(3), fhi(3), ylo(3), yhi(3), xf, side
      integer :: m, iside, s, i, dim
      logical :: free(3), on, inside_on_cell_side, on_i, dummy

      dim = quad%dim
      call add_facet_face_parts(quad, body, lo, hi, rule)
      ! the shapes' classes on a face in rule%shapes (the reduction below only grows it)
      call reserve_work(rule, body%nshape)
      if (rule%failed) return
      do m = 1, dim
         do iside = 1, 2
            side = merge(-1.0_wp, 1.0_wp, iside == 1)
            xf = merge(lo(m), hi(m), iside == 1)
            flo(1:dim) = lo(1:dim)
            fhi(1:dim) = hi(1:dim)
            flo(m) = xf
            fhi(m) = xf
            do s = 1, body%nshape
               call on_face_plane(body, s, m, side, xf, flo(1:dim), fhi(1:dim), on, inside_on_cell_side)
               if (.not. on) cycle
               call new_context(ctx, dim, lo, hi)
               ctx%face_shape = s
               ctx%face_dim = m
               ctx%face_side = side
               ctx%cell_side_inside = inside_on_cell_side
               call body%shape_classes(flo(1:dim), fhi(1:dim), rule%shapes(1:body%nshape))
               rule%np = 0
               do i = 1, body%nshape
                  ! a box face on this plane bounds the face part (its own, or
                  ! another shape's one-sided value): its edges split the face
                  on_i = .false.
                  if (i /= s) call on_face_plane(body, i, m, side, xf, flo(1:dim), fhi(1:dim), on_i, dummy)
                  if (i == s .or. on_i) then
                     if (body%shapes(i)%kind == shape_box) &
                        & call add_shape_quadrics(body, i, ctx, flo(1:dim), fhi(1:dim), rule)
                  else if (rule%shapes(i) == cell_cut .and. body%shapes(i)%kind == shape_facets) then
                     ! another faceted surface crossing the face: membership by point
                     rule%nunresolved = rule%nunresolved + 1
                  else if (rule%shapes(i) == cell_cut) then
                     call add_shape_quadrics(body, i, ctx, flo(1:dim), fhi(1:dim), rule)
                  end if
               end do
               ylo = 0.0_wp
               yhi = 0.0_wp
               ylo(1:dim) = -1.0_wp
               yhi(1:dim) = 1.0_wp
               ylo(m) = side
               yhi(m) = side
               free = .false.
               free(1:dim) = .true.
               free(m) = .false.
               call reduce(ctx, quad, body, rule, ylo, yhi, free, 1, rule%np, .true., -1, 0)
               rule%np = 0
               if (rule%failed) return
            end do
         end do
      end do
   end subroutine add_face_parts

   !> True if shape s's surface lies on the plane x_m = xf (the cell face
   !> [flo, fhi] on `side`): a halfspace with normal +-e_m, or a box face,
   !> within the snapping tolerance, or facets covering the whole face with
   !> one orientation (`face_cover`; a partly covered face is left to
   !> `add_facet_face_parts`). inside_on_cell_side: the shape's inside
   !> lies on the cell side of the plane.
   pure subroutine on_face_plane(body, s, m, side, xf, flo, fhi, on, inside_on_cell_side)
      class(body_type), intent(in) :: body
      integer, intent(in) :: s, m
      real(wp), intent(in) :: side, xf, flo(:), fhi(:)
      logical, intent(out) :: on, inside_on_cell_side
      real(wp) :: tol, inner_sign
      integer :: cover

      on = .false.
      inside_on_cell_side = .false.
      tol = snap_tolerance(body%shapes(s), flo, fhi)
      associate (sh => body%shapes(s))
         select case (sh%kind)
         case (shape_facets)
            cover = face_cover(sh%solid, flo, fhi, m, nint(side))
            on = cover /= 0
            inside_on_cell_side = cover > 0
         case (shape_halfspace, shape_box)
            call plane_relation(body, s, m, xf, tol, on, inner_sign)
            inside_on_cell_side = on .and. inner_sign*side < 0.0_wp
         end select
      end associate
   end subroutine on_face_plane

   !> Body membership just on one side of the face plane at x (on the plane).
   !> Every shape whose surface lies on this plane takes its one-sided value,
   !> not only the face's own shape: where two shapes meet on the plane (two
   !> boxes of a union sharing a face) the face is inside the body, no boundary.
   pure logical function face_member(ctx, body, x, cell_side) result(inside)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: x(:)
      logical, intent(in) :: cell_side
      real(wp) :: toward, f, g
      integer :: k

      ! the cell lies on the side opposite to the face's outward direction
      toward = merge(-ctx%face_side, ctx%face_side, cell_side)
      do k = 1, body%nshape
         if (k == ctx%face_shape) then
            g = plane_value(body, k, ctx%face_dim, x, cell_side .eqv. ctx%cell_side_inside)
         else
            g = one_sided_phi(body, k, ctx%face_dim, x, toward)
         end if
         if (k == 1) then
            f = g
         else if (body%ops(k) == csg_add) then
            f = min(f, g)
         else if (body%ops(k) == csg_intersect) then
            f = max(f, g)
         else
            f = max(f, -g)
         end if
      end do
      inside = f < 0.0_wp
   end function face_member

   !> Shape k's level set at x just off the plane x_m = x(m) towards the sign of
   !> `toward`: its one-sided value if its surface lies on that plane, else phi(x).
   pure real(wp) function one_sided_phi(body, k, m, x, toward) result(g)
      class(body_type), intent(in) :: body
      integer, intent(in) :: k, m
      real(wp), intent(in) :: x(:), toward
      logical :: on
      real(wp) :: inner_sign

      call plane_relation(body, k, m, x(m), snap_tolerance(body%shapes(k), x, x), on, inner_sign)
      if (on) then
         g = plane_value(body, k, m, x, inner_sign*toward > 0.0_wp)
      else
         g = body%shapes(k)%phi(x)
      end if
   end function one_sided_phi

   !> Whether shape k's surface lies on the plane x_m = xm (a halfspace with
   !> normal +-e_m or a box face, within `tol`), and on which side its inside
   !> lies (inner_sign +1: towards +x_m).
   pure subroutine plane_relation(body, k, m, xm, tol, on, inner_sign)
      class(body_type), intent(in) :: body
      integer, intent(in) :: k, m
      real(wp), intent(in) :: xm, tol
      logical, intent(out) :: on
      real(wp), intent(out) :: inner_sign
      integer :: i

      on = .false.
      inner_sign = 0.0_wp
      associate (sh => body%shapes(k))
         select case (sh%kind)
         case (shape_halfspace)
            do i = 1, body%dim
               if (i /= m .and. sh%normal(i) /= 0.0_wp) return
            end do
            on = abs(sh%point(m) - xm) <= tol
            inner_sign = -sign(1.0_wp, sh%normal(m))
         case (shape_box)
            if (abs(sh%upper(m) - xm) <= tol) then
               on = .true.
               inner_sign = -1.0_wp
            else if (abs(sh%lower(m) - xm) <= tol) then
               on = .true.
               inner_sign = 1.0_wp
            end if
         end select
      end associate
   end subroutine plane_relation

   !> A point on the face plane belongs to the face shape's surface: within
   !> its face (a box's face rectangle) and not taken by another shape whose
   !> surface lies on the same plane there. doc/scene.md `&bc`: a box face
   !> takes it from a half-space; between shapes of one kind the later one in
   !> file order takes it, as off grid planes.
   pure logical function own_face(ctx, body, x) result(own)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: x(:)
      logical :: on, wins
      real(wp) :: inner_sign
      integer :: k, m, s

      m = ctx%face_dim
      s = ctx%face_shape
      own = plane_value(body, s, m, x, .true.) < 0.0_wp
      do k = 1, body%nshape
         if (.not. own) return
         if (k == s) cycle
         if (body%shapes(k)%kind == body%shapes(s)%kind) then
            wins = k > s
         else
            wins = body%shapes(k)%kind == shape_box
         end if
         if (.not. wins) cycle
         call plane_relation(body, k, m, x(m), snap_tolerance(body%shapes(k), x, x), on, inner_sign)
         if (on) own = .not. plane_value(body, k, m, x, .true.) < 0.0_wp
      end do
   end function own_face

   !> Value of shape k (its surface on the plane x_m = x(m)) just off the plane:
   !> outside (+1) on its outer side; on its inner side -1 for a halfspace, and
   !> for a box phi with x_m moved to the box's mid-plane (its other faces decide).
   pure real(wp) function plane_value(body, k, m, x, inner) result(g)
      class(body_type), intent(in) :: body
      integer, intent(in) :: k, m
      real(wp), intent(in) :: x(:)
      logical, intent(in) :: inner
      real(wp) :: xm(3)
      integer :: d

      if (.not. inner) then
         g = 1.0_wp
      else if (body%shapes(k)%kind == shape_box) then
         d = size(x)
         xm(1:d) = x
         xm(m) = 0.5_wp*(body%shapes(k)%lower(m) + body%shapes(k)%upper(m))
         g = body%shapes(k)%phi(xm(1:d))
      else
         g = -1.0_wp
      end if
   end function plane_value

   !> The body's level set at x with shape s's value replaced by v.
   pure real(wp) function csg_phi(body, x, s, v) result(f)
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: x(:), v
      integer, intent(in) :: s
      real(wp) :: g
      integer :: k

      do k = 1, body%nshape
         if (k == s) then
            g = v
         else
            g = body%shapes(k)%phi(x)
         end if
         if (k == 1) then
            f = g
         else if (body%ops(k) == csg_add) then
            f = min(f, g)
         else if (body%ops(k) == csg_intersect) then
            f = max(f, g)
         else
            f = max(f, -g)
         end if
      end do
   end function csg_phi

   ! ------------------------------------------------------------ dimension reduction

   !> Rule of the y-box [lo, hi] over its free dimensions for the quadrics
   !> rule%poly(:, p0:p0+np-1). Below the top: push base points (y, weight in
   !> y measure) onto the stack. At the top, `want` says what to emit: -1 the
   !> volume only (a face part), 0 volume and every surface, t > 0 only the
   !> surface of the top-level quadric tagged t.
   recursive pure subroutine reduce(ctx, quad, body, rule, lo, hi, free, p0, np, top, want, depth)
      type(context_type), intent(in) :: ctx
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: lo(3), hi(3)
      logical, intent(in) :: free(3)
      integer, intent(in) :: p0, np, want, depth
      logical, intent(in) :: top
      real(wp) :: pmin, pmax, p(0:ncoef - 1), c(0:ncoef - 1), clo(3), chi(3)
      integer :: k0, nk, i, j, k, m, s0, s1, b0, nnew, child, bit, d, status, owner, tag
      logical :: resolved, base_free(3), focus

      if (rule%failed) return
      k0 = rule%np + 1
      do i = p0, p0 + np - 1
         p = rule%poly(:, i)
         call quadric_range(p, lo, hi, pmin, pmax)
         ! owner and tag by value: push_poly may reallocate the arrays they live in
         owner = rule%owner(i)
         tag = rule%tag(i)
         if (pmin < 0.0_wp .and. pmax > 0.0_wp) call push_poly(rule, p, owner, tag)
      end do
      nk = rule%np - k0 + 1
      m = count(free)
      if (top .and. want > 0) then
         ! only the surface tagged `want`: nothing to do where it is not
         if (.not. any(rule%tag(k0:k0 + nk - 1) == want)) then
            rule%np = k0 - 1
            return
         end if
      end if

      if (nk == 0) then
         call tensor_piece(ctx, quad, body, rule, lo, hi, free, top)
         rule%np = k0 - 1
         return
      end if

      ! the surfaces wanted at the top must be crossed by the height lines (rule%require:
      ! used here only, before this level recurses)
      call reserve_work(rule, nk)
      if (rule%failed) return
      rule%require(1:nk) = top .and. want >= 0
      if (top .and. want > 0) rule%require(1:nk) = rule%tag(k0:k0 + nk - 1) == want
      call choose_direction(rule%poly(:, k0:k0 + nk - 1), rule%require(1:nk), top .and. want > 0, lo, hi, free, &
         & quad%min_ratio, k, resolved)
      if (.not. resolved .and. top .and. want == 0) then
         ! walls parallel to some direction: volume now, their surfaces in own passes
         rule%require(1:nk) = .false.
         call choose_direction(rule%poly(:, k0:k0 + nk - 1), rule%require(1:nk), .false., lo, hi, free, &
            & quad%min_ratio, k, resolved)
      end if
      if (.not. resolved .and. depth < quad%max_depth) then
         rule%nsplit = rule%nsplit + 1
         do child = 0, 2**m - 1
            clo = lo
            chi = hi
            bit = 0
            do d = 1, 3
               if (.not. free(d)) cycle
               if (btest(child, bit)) then
                  clo(d) = 0.5_wp*(lo(d) + hi(d))
               else
                  chi(d) = 0.5_wp*(lo(d) + hi(d))
               end if
               bit = bit + 1
            end do
            call reduce(ctx, quad, body, rule, clo, chi, free, k0, nk, top, want, depth + 1)
         end do
         rule%np = k0 - 1
         return
      end if
      if (.not. resolved) rule%nunresolved = rule%nunresolved + 1

      s0 = rule%ns
      if (m == 1) then
         call push_point(rule, 0.5_wp*(lo + hi), 1.0_wp)
      else
         b0 = rule%np + 1
         ! A pass for one surface needs in its base only where that surface's
         ! root leaves the box or meets another surface (choose_direction).
         focus = top .and. want > 0
         do i = k0, k0 + nk - 1
            p = rule%poly(:, i)
            if (focus .and. rule%tag(i) /= want .and. depends_on(p, k)) cycle
            if (depends_on(p, k)) then
               call face_restriction(ctx, body, p, rule%owner(i), k, lo(k), c)
               call push_poly(rule, c, 0, 0)
               call face_restriction(ctx, body, p, rule%owner(i), k, hi(k), c)
               call push_poly(rule, c, 0, 0)
            else
               call push_poly(rule, p, 0, 0)
            end if
         end do
         do i = k0, k0 + nk - 1
            if (.not. depends_on(rule%poly(:, i), k)) cycle
            do j = i + 1, k0 + nk - 1
               if (.not. depends_on(rule%poly(:, j), k)) cycle
               if (focus .and. rule%tag(i) /= want .and. rule%tag(j) /= want) cycle
               p = rule%poly(:, i)
               call crossing(p, rule%poly(:, j), k, c, status)
               if (status == 1) call push_poly(rule, c, 0, 0)
            end do
         end do
         base_free = free
         base_free(k) = .false.
         call reduce(ctx, quad, body, rule, lo, hi, base_free, b0, rule%np - b0 + 1, .false., 0, depth)
         rule%np = b0 - 1
      end if
      s1 = rule%ns
      do i = s0 + 1, s1
         call lift(ctx, quad, body, rule, i, k, lo(k), hi(k), k0, nk, free, top, want)
      end do
      if (top) then
         rule%ns = s0
         if (want == 0) then
            do i = k0, k0 + nk - 1
               tag = rule%tag(i)
               if (depends_on(rule%poly(:, i), k) .or. tag == 0) cycle
               call reduce(ctx, quad, body, rule, lo, hi, free, k0, nk, .true., tag, depth)
            end do
         end if
      else
         ! A loop, not overlapping sections: gfortran copies those through a heap
         ! temporary that it never checks, a crash when memory runs out.
         nnew = rule%ns - s1
         do i = 1, nnew
            rule%sy(:, s0 + i) = rule%sy(:, s1 + i)
            rule%sw(s0 + i) = rule%sw(s1 + i)
         end do
         rule%ns = s0 + nnew
      end if
      rule%np = k0 - 1
   end subroutine reduce

   !> Restriction of quadric p (of shape `owner`, 0 if derived) to y_k = v.
   !> For a curved shape it is rebuilt from the shape around the face point,
   !> x_k = center_k + half_k v: the constant term is then formed without
   !> cancellation ((|d| - r)(|d| + r) and the like), which keeps the split
   !> points of near-tangent restrictions (a sliver cut, a pole near a face)
   !> accurate to a few ulps instead of eps * h^2 / (their small value).
   pure subroutine face_restriction(ctx, body, p, owner, k, v, c)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: p(0:), v
      integer, intent(in) :: owner, k
      real(wp), intent(out) :: c(0:)
      real(wp) :: center(3), half(3), polys(0:ncoef - 1, max_shape_quadrics)
      integer :: n

      if (owner > 0) then
         if (body%shapes(owner)%kind /= shape_box .and. body%shapes(owner)%kind /= shape_halfspace) then
            center = ctx%center
            half = ctx%half
            center(k) = ctx%center(k) + ctx%half(k)*v
            half(k) = 0.0_wp
            call shape_quadrics(body%shapes(owner), center, half, center, center, 0.0_wp, polys, n)
            c(0:ncoef - 1) = polys(:, 1)
            return
         end if
      end if
      call restrict(p, k, v, c)
   end subroutine face_restriction

   !> Height direction among the free ones. Valid: every quadric either free
   !> of y_k (not allowed where `require`) or with dp/dy_k of one strict sign
   !> over the box and |dp/dy_k| >= min_ratio * (its variation over the box),
   !> which keeps the turning points of the height function at least min_ratio
   !> box widths away; and every pair involving y_k with a crossing quadric.
   !> With `focus` (a pass for the surface(s) marked in `require` only) the
   !> other quadrics need neither a sign of dp/dy_k nor crossings among
   !> themselves: the surface points are where a required root changes
   !> membership, which changes only where that root leaves the box or meets
   !> another surface (their crossing quadric), so a turning point of another
   !> surface (a sphere at a symmetry plane through its centre) does not
   !> matter; its roots are still found exactly in `lift`.
   !> Among valid ones the largest min |dp/dy_k|/|grad p| at the box center.
   !> A single free dimension is always resolved (all roots on a line are
   !> found). If none is valid: resolved = .false. and k is the direction with
   !> the best score.
   pure subroutine choose_direction(polys, require, focus, lo, hi, free, min_ratio, k, resolved)
      real(wp), intent(in) :: polys(0:, :), lo(3), hi(3), min_ratio
      logical, intent(in) :: require(:), focus, free(3)
      integer, intent(out) :: k
      logical, intent(out) :: resolved
      real(wp) :: score, best_valid, best_any, dmin, dmax, g(3), mid(3), c(0:ncoef - 1)
      integer :: d, i, j, status
      logical :: valid

      mid = 0.5_wp*(lo + hi)
      best_valid = -1.0_wp
      best_any = -1.0_wp
      k = 0
      resolved = .false.
      do d = 1, 3
         if (.not. free(d)) cycle
         if (count(free) == 1) then
            k = d
            resolved = .true.
            return
         end if
         valid = .true.
         score = 1.0_wp
         do i = 1, size(polys, 2)
            if (.not. depends_on(polys(:, i), d)) then
               if (require(i)) then
                  valid = .false.
                  score = 0.0_wp
               end if
               cycle
            end if
            if (focus .and. .not. require(i)) cycle
            g = quadric_gradient(polys(:, i), mid)
            if (norm2(g) > 0.0_wp) score = min(score, abs(g(d))/norm2(g))
            call derivative_range(polys(:, i), d, lo, hi, dmin, dmax)
            if (dmin > 0.0_wp) then
               if (dmin < min_ratio*(dmax - dmin)) valid = .false.
            else if (dmax < 0.0_wp) then
               if (-dmax < min_ratio*(dmax - dmin)) valid = .false.
            else
               valid = .false.
            end if
         end do
         if (score > best_any) then
            best_any = score
            if (best_valid < 0.0_wp) k = d
         end if
         if (.not. valid .or. score <= best_valid) cycle
         pairs: do i = 1, size(polys, 2)
            if (.not. depends_on(polys(:, i), d)) cycle
            do j = i + 1, size(polys, 2)
               if (.not. depends_on(polys(:, j), d)) cycle
               if (focus .and. .not. (require(i) .or. require(j))) cycle
               call crossing(polys(:, i), polys(:, j), d, c, status)
               if (status < 0) then
                  valid = .false.
                  exit pairs
               end if
            end do
         end do pairs
         if (.not. valid) cycle
         best_valid = score
         k = d
         resolved = .true.
      end do
   end subroutine choose_direction

   !> A box with no surface in it: at the top, all of it or nothing by the
   !> membership at its center; below, its tensor rule onto the stack.
   pure subroutine tensor_piece(ctx, quad, body, rule, lo, hi, free, top)
      type(context_type), intent(in) :: ctx
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: lo(3), hi(3)
      logical, intent(in) :: free(3)
      logical, intent(in) :: top
      real(wp) :: y(3), w
      integer :: ipt, i, d, idx, m

      if (top) then
         if (.not. member(ctx, body, 0.5_wp*(lo + hi))) return
      end if
      m = count(free)
      do ipt = 1, quad%q**m
         i = ipt - 1
         w = 1.0_wp
         y = 0.5_wp*(lo + hi)
         do d = 1, 3
            if (.not. free(d)) cycle
            idx = mod(i, quad%q) + 1
            i = i/quad%q
            y(d) = lo(d) + (hi(d) - lo(d))*quad%node(idx)
            w = w*(hi(d) - lo(d))*quad%weight(idx)
         end do
         if (top) then
            call emit_volume(ctx, body, rule, y, w, free)
         else
            call push_point(rule, y, w)
         end if
      end do
   end subroutine tensor_piece

   !> Lift base point number ip along y_k over [a, b] through the quadrics
   !> rule%poly(:, k0:k0+nk-1) (see the module notes, step 4).
   pure subroutine lift(ctx, quad, body, rule, ip, k, a, b, k0, nk, free, top, want)
      type(context_type), intent(in) :: ctx
      type(cut_quadrature_type), intent(in) :: quad
      class(body_type), intent(in) :: body
      type(cell_rule_type), intent(inout) :: rule
      integer, intent(in) :: ip, k, k0, nk, want
      real(wp), intent(in) :: a, b
      logical, intent(in) :: free(3), top
      real(wp) :: y(3), ym(3), wb, roots(2), ca, cb, cc, len, key
      integer :: nr, i, j, n, g, okey, owner
      logical :: inside, prev_in, have_prev

      ! the roots t and their quadrics rown in rule's work (lift does not recurse)
      call reserve_work(rule, nk)
      if (rule%failed) return
      associate (t => rule%roots, rown => rule%root_owner)
         y = rule%sy(:, ip)
         wb = rule%sw(ip)
         nr = 0
         do i = k0, k0 + nk - 1
            if (.not. depends_on(rule%poly(:, i), k)) cycle
            call line_coefficients(rule%poly(:, i), k, y, ca, cb, cc)
            call quadratic_roots(ca, cb, cc, roots, n)
            do j = 1, n
               if (roots(j) > a .and. roots(j) < b) then
                  nr = nr + 1
                  t(nr) = roots(j)
                  rown(nr) = i
               end if
            end do
         end do
         ! insertion sort of the roots with their owners
         do i = 2, nr
            key = t(i)
            okey = rown(i)
            j = i - 1
            do while (j >= 1)
               if (t(j) <= key) exit
               t(j + 1) = t(j)
               rown(j + 1) = rown(j)
               j = j - 1
            end do
            t(j + 1) = key
            rown(j + 1) = okey
         end do
         t(0) = a
         t(nr + 1) = b
         rown(0) = 0

         have_prev = .false.
         prev_in = .false.
         do j = 0, nr
            len = t(j + 1) - t(j)
            if (.not. len > 0.0_wp) cycle
            if (top) then
               ym = y
               ym(k) = t(j) + 0.5_wp*len
               inside = member(ctx, body, ym)
               if (have_prev .and. (inside .neqv. prev_in) .and. want >= 0) then
                  if (want == 0 .or. rule%tag(rown(j)) == want) then
                     ym(k) = t(j)
                     owner = rule%owner(rown(j))
                     call emit_surface(ctx, body, rule, ym, wb, k, free, owner)
                  end if
               end if
               have_prev = .true.
               prev_in = inside
               if (.not. inside .or. want > 0) cycle
            end if
            do g = 1, quad%q
               ym = y
               ym(k) = t(j) + len*quad%node(g)
               if (top) then
                  call emit_volume(ctx, body, rule, ym, wb*len*quad%weight(g), free)
               else
                  call push_point(rule, ym, wb*len*quad%weight(g))
               end if
            end do
         end do
      end associate
   end subroutine lift

   !> Membership of the reference point y at the top level.
   pure logical function member(ctx, body, y) result(inside)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: y(3)
      real(wp) :: x(3)
      integer :: d

      d = ctx%dim
      x(1:d) = ctx%center(1:d) + ctx%half(1:d)*y(1:d)
      if (ctx%face_shape == 0) then
         inside = body%phi(x(1:d)) < 0.0_wp
      else
         inside = own_face(ctx, body, x(1:d))
         if (inside) inside = face_member(ctx, body, x(1:d), .true.)
         if (inside) inside = .not. face_member(ctx, body, x(1:d), .false.)
      end if
   end function member

   !> A top-level volume point (y-measure weight w): a volume point of the
   !> cell, or in face mode a surface point on the face.
   pure subroutine emit_volume(ctx, body, rule, y, w, free)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: y(3), w
      logical, intent(in) :: free(3)
      real(wp) :: x(3), n(3)

      x = 0.0_wp
      x(1:ctx%dim) = ctx%center(1:ctx%dim) + ctx%half(1:ctx%dim)*y(1:ctx%dim)
      if (ctx%face_shape == 0) then
         call push_volume(rule, x, w*product(ctx%half, mask=free))
      else
         n = 0.0_wp
         n(ctx%face_dim) = ctx%face_side
         call push_surface(rule, x, w*product(ctx%half, mask=free), n, face_surface(ctx, body, x))
      end if
   end subroutine emit_volume

   !> Surface id of a face point: the face's shape, or for facets the group of the nearest facet.
   pure integer function face_surface(ctx, body, x) result(id)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      real(wp), intent(in) :: x(3)
      real(wp) :: dist
      integer :: f
      id = ctx%face_shape
      if (body%shapes(id)%kind /= shape_facets) return
      if (.not. allocated(body%shapes(id)%solid%set%group)) return
      call solid_nearest(body%shapes(id)%solid, x(1:ctx%dim), f, dist)
      id = body%group_surface(id, body%shapes(id)%solid%set%group(f))
   end function face_surface

   !> A surface point at y on shape s seen along y_k, base weight wb (y measure).
   pure subroutine emit_surface(ctx, body, rule, y, wb, k, free, s)
      type(context_type), intent(in) :: ctx
      class(body_type), intent(in) :: body
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: y(3), wb
      integer, intent(in) :: k, s
      logical, intent(in) :: free(3)
      real(wp) :: x(3), n(3), jac
      logical :: base(3)

      x = 0.0_wp
      n = 0.0_wp
      x(1:ctx%dim) = ctx%center(1:ctx%dim) + ctx%half(1:ctx%dim)*y(1:ctx%dim)
      call body%outward_normal(x(1:ctx%dim), s, n)
      ! n_k = 0 only on an unresolved box: a point of zero measure
      if (.not. abs(n(k)) > 1.0e-12_wp) return
      base = free
      base(k) = .false.
      jac = product(ctx%half, mask=base)
      call push_surface(rule, x, wb*jac/abs(n(k)), n, s)
   end subroutine emit_surface

   ! ------------------------------------------------------------ growing arrays

   !> Push a quadric with its shape (owner, 0 for a derived one) and its tag
   !> (1, 2, ... for the top-level quadrics of a cell, 0 for derived ones).
   pure subroutine push_poly(rule, p, owner, tag)
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: p(0:)
      integer, intent(in) :: owner, tag
      real(wp), allocatable :: tp(:, :)
      integer, allocatable :: to(:), tt(:)
      integer :: cap, st

      if (rule%failed) return
      cap = size(rule%poly, 2)
      if (rule%np == cap) then
         allocate (tp(0:ncoef - 1, 2*cap), to(2*cap), tt(2*cap), stat=st)
         if (st /= 0) then
            rule%failed = .true.
            return
         end if
         tp(:, 1:cap) = rule%poly
         to(1:cap) = rule%owner
         tt(1:cap) = rule%tag
         call move_alloc(tp, rule%poly)
         call move_alloc(to, rule%owner)
         call move_alloc(tt, rule%tag)
      end if
      rule%np = rule%np + 1
      rule%poly(:, rule%np) = p(0:ncoef - 1)
      rule%owner(rule%np) = owner
      rule%tag(rule%np) = tag
   end subroutine push_poly

   pure subroutine push_point(rule, y, w)
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: y(3), w
      if (.not. rule%failed) call push_weighted(rule%sy, rule%sw, rule%ns, y, w, rule%failed)
   end subroutine push_point

   pure subroutine push_volume(rule, x, w)
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: x(3), w
      if (.not. rule%failed) call push_weighted(rule%vol_x, rule%vol_w, rule%nvol, x, w, rule%failed)
   end subroutine push_volume

   !> Append (x, w) to a point list of n entries, doubling its capacity when full
   !> (`failed` and nothing appended if it cannot grow).
   pure subroutine push_weighted(xs, ws, n, x, w, failed)
      real(wp), allocatable, intent(inout) :: xs(:, :), ws(:)
      integer, intent(inout) :: n
      real(wp), intent(in) :: x(3), w
      logical, intent(inout) :: failed
      real(wp), allocatable :: tx(:, :), tw(:)
      integer :: cap, st

      cap = size(ws)
      if (n == cap) then
         allocate (tx(3, 2*cap), tw(2*cap), stat=st)
         if (st /= 0) then
            failed = .true.
            return
         end if
         tx(:, 1:cap) = xs
         tw(1:cap) = ws
         call move_alloc(tx, xs)
         call move_alloc(tw, ws)
      end if
      n = n + 1
      xs(:, n) = x
      ws(n) = w
   end subroutine push_weighted

   pure subroutine push_surface(rule, x, w, n, s)
      type(cell_rule_type), intent(inout) :: rule
      real(wp), intent(in) :: x(3), w, n(3)
      integer, intent(in) :: s
      real(wp), allocatable :: tx(:, :), tw(:), tn(:, :)
      integer, allocatable :: ts(:)
      integer :: cap, st

      if (rule%failed) return
      cap = size(rule%surf_w)
      if (rule%nsurf == cap) then
         allocate (tx(3, 2*cap), tw(2*cap), tn(3, 2*cap), ts(2*cap), stat=st)
         if (st /= 0) then
            rule%failed = .true.
            return
         end if
         tx(:, 1:cap) = rule%surf_x
         tw(1:cap) = rule%surf_w
         tn(:, 1:cap) = rule%surf_n
         ts(1:cap) = rule%surf_shape
         call move_alloc(tx, rule%surf_x)
         call move_alloc(tw, rule%surf_w)
         call move_alloc(tn, rule%surf_n)
         call move_alloc(ts, rule%surf_shape)
      end if
      rule%nsurf = rule%nsurf + 1
      rule%surf_x(:, rule%nsurf) = x
      rule%surf_w(rule%nsurf) = w
      rule%surf_n(:, rule%nsurf) = n
      rule%surf_shape(rule%nsurf) = s
   end subroutine push_surface

end module sprc_grid_quadrature
