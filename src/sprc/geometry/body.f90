!> A body: shapes combined in file order by CSG (doc/scene.md, `&shape`).
!>
!> body = (((s_1 op_2 s_2) op_3 s_3) ... ), op_1 = add; add is union (min of
!> the level sets), intersect is intersection (max), subtract is A minus B
!> (max(a, -b)). Every shape appears once in this read-once formula, so
!> three-valued (Kleene) logic on the shapes' classes of a box (inside,
!> outside, cut) is sound, and a shape's influence on the result can be tested
!> by setting it to inside and to outside in turn (`active_shapes`).
!>
!> Surfaces: boundary conditions and contact name surfaces. Surface ids
!> 1..nshape are the shapes (the whole surface of each); then come the named
!> facet groups of the faceted shapes, shape by shape, group by group
!> (`surface_index`, `surface_shape`, `group_surface`). A quadrature point on
!> a facet of a group carries the group's id; a condition on the whole shape
!> applies to its groups unless they have their own (sprc_fem_problem). A
!> body without faceted groups has exactly the shape ids.
!>
!> Round-off and snapping: a shape's class of a box comes from its certified
!> range [fmin, fmax] of phi with a snapping tolerance
!> tol = snap_ulps * epsilon * (largest |coordinate| of the box + shape%scale),
!> i.e. a few ulps of the coordinate magnitude X: fmax <= tol is inside,
!> fmin >= -tol is outside. A face computed a few ulps off a grid plane
!> therefore does not produce a sliver cut. tol ~ 1e-15 X, so a genuine
!> offset of 1e-12 of the cell size h is still a cut as long as h > ~1e-3 X
!> (about ten levels below a level-0 cell of size X). Contact of zero
!> measure (a circle tangent to a cell edge, a plane through a cell face)
!> gives fmin = 0: outside.
module sprc_geometry_body
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: fixed_text, itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_geometry_region, only: region_type, cell_outside, cell_inside, cell_cut
   use sprc_geometry_shape, only: shape_type, shape_kind_name, shape_facets
   implicit none
   private

   public :: body_type, new_body, check_body_in_box
   public :: csg_add, csg_subtract, csg_intersect, csg_op_name, csg_op_from_name
   public :: snap_ulps, snap_tolerance
   public :: body_name, shape_name

   !> CSG operations (values are stable): union (min of the level sets),
   integer, parameter :: csg_add = 1
   !> difference A minus B (max(a, -b)),
   integer, parameter :: csg_subtract = 2
   !> intersection (max).
   integer, parameter :: csg_intersect = 3

   character(len=*), parameter :: op_names(3) = [character(len=9) :: 'add', 'subtract', 'intersect']

   !> Snapping tolerance in ulps of the coordinate magnitude (module notes).
   real(wp), parameter :: snap_ulps = 4.0_wp
   !> Halvings of a box searched for material outside the scene's box (check_body_in_box).
   integer, parameter :: depth_limit = 8
   !> Bodies of up to this many shapes classify a box in fixed-size locals; larger ones
   !> allocate with stat= (gfortran's automatic arrays are unchecked heap allocations:
   !> out of memory, a segmentation fault).
   integer, parameter :: few_shapes = 64

   !> A named body: its shapes and their CSG operations, in file order.
   type, extends(region_type) :: body_type
      !> Name of the body.
      character(len=:), allocatable :: name
      !> Space dimension (from the first shape); 0 while empty.
      integer :: dim = 0
      !> Number of shapes.
      integer :: nshape = 0
      !> Shapes in file order, (nshape).
      type(shape_type), allocatable :: shapes(:)
      !> CSG operation of each shape, (nshape); ops(1) = csg_add.
      integer, allocatable :: ops(:)
   contains
      procedure :: add_shape
      procedure :: shape_index
      procedure :: phi => body_phi
      procedure :: classify_box
      procedure :: shape_classes
      procedure :: class_with
      procedure :: active_shapes
      procedure :: is_boundary_on
      procedure :: surface_at
      procedure :: outward_normal
      procedure :: nsurface
      procedure :: surface_index
      procedure :: surface_shape
      procedure :: surface_name
      procedure :: group_surface
      procedure :: surface_part
      procedure :: surface_parts
   end type body_type

contains

   !> An empty body with a name.
   subroutine new_body(self, name)
      type(body_type), intent(out) :: self
      character(len=*), intent(in) :: name
      self%name = name
      allocate (self%shapes(0), self%ops(0))
   end subroutine new_body

   !> Name of a CSG operation ('add', ...); '' for an unknown one.
   pure function csg_op_name(op) result(name)
      integer, intent(in) :: op
      character(len=:), allocatable :: name
      if (op >= 1 .and. op <= size(op_names)) then
         name = trim(op_names(op))
      else
         name = ''
      end if
   end function csg_op_name

   !> CSG operation of a name ('add' -> csg_add, ...); 0 for an unknown name.
   pure integer function csg_op_from_name(name) result(op)
      character(len=*), intent(in) :: name
      do op = 1, size(op_names)
         if (trim(adjustl(name)) == trim(op_names(op))) return
      end do
      op = 0
   end function csg_op_from_name

   !> Append a shape with its operation. Errors: unknown op, first op not add,
   !> a shape not constructed, a dimension different from the body's, a
   !> non-blank name already used in this body (boundary conditions would be
   !> ambiguous).
   subroutine add_shape(self, op, shape, error)
      class(body_type), intent(inout) :: self
      integer, intent(in) :: op
      type(shape_type), intent(in) :: shape
      type(error_type), allocatable, intent(out) :: error
      type(shape_type), allocatable :: shapes(:)
      integer, allocatable :: ops(:)
      character(len=:), allocatable :: where
      integer :: n

      where = "body '"//body_name(self)//"', shape '"//shape_name(shape)//"': "
      if (op < 1 .or. op > size(op_names)) then
         call fatal_error(error, where//'unknown op '//itoa(op)//' (expected add, subtract or intersect)', &
            & stat_invalid_input)
         return
      end if
      if (self%nshape == 0 .and. op /= csg_add) then
         call fatal_error(error, where//"the first shape's op must be 'add', got '"//csg_op_name(op)//"'", &
            & stat_invalid_input)
         return
      end if
      if (shape%kind == 0) then
         call fatal_error(error, where//'shape was not constructed', stat_invalid_input)
         return
      end if
      if (self%nshape > 0 .and. shape%dim /= self%dim) then
         call fatal_error(error, where//shape_kind_name(shape%kind)//' has dimension '//itoa(shape%dim)// &
            & ', the body has dimension '//itoa(self%dim), stat_invalid_input)
         return
      end if
      if (len_trim(shape_name(shape)) > 0) then
         if (self%shape_index(shape%name) > 0) then
            call fatal_error(error, where//'name already used by another shape of the body', stat_invalid_input)
            return
         end if
      end if

      n = self%nshape
      allocate (shapes(n + 1), ops(n + 1))
      if (n > 0) then
         shapes(1:n) = self%shapes(1:n)
         ops(1:n) = self%ops(1:n)
      end if
      shapes(n + 1) = shape
      ops(n + 1) = op
      call move_alloc(shapes, self%shapes)
      call move_alloc(ops, self%ops)
      self%nshape = n + 1
      self%dim = shape%dim
   end subroutine add_shape

   !> Index of the shape with this name; 0 if none.
   pure integer function shape_index(self, name) result(idx)
      class(body_type), intent(in) :: self
      character(len=*), intent(in) :: name
      do idx = 1, self%nshape
         if (shape_name(self%shapes(idx)) == name) return
      end do
      idx = 0
   end function shape_index

   !> Number of surfaces (module notes).
   pure integer function nsurface(self) result(n)
      class(body_type), intent(in) :: self
      integer :: k
      n = self%nshape
      do k = 1, self%nshape
         n = n + ngroup(self%shapes(k))
      end do
   end function nsurface

   !> Id of the surface named `name`: a shape's name first, then a facet group's
   !> (the first in surface order); 0 if none.
   pure integer function surface_index(self, name) result(id)
      class(body_type), intent(in) :: self
      character(len=*), intent(in) :: name
      integer :: k, g
      id = self%shape_index(name)
      if (id > 0 .or. len_trim(name) == 0) return
      do k = 1, self%nshape
         do g = 1, ngroup(self%shapes(k))
            if (trim(self%shapes(k)%solid%set%group_name(g)) /= trim(name)) cycle
            id = self%group_surface(k, g)
            return
         end do
      end do
   end function surface_index

   !> Shape of surface `id` (0 for an id out of range).
   pure integer function surface_shape(self, id) result(s)
      class(body_type), intent(in) :: self
      integer, intent(in) :: id
      integer :: first
      s = 0
      if (id < 1) return
      if (id <= self%nshape) then
         s = id
         return
      end if
      first = self%nshape
      do s = 1, self%nshape
         if (id <= first + ngroup(self%shapes(s))) return
         first = first + ngroup(self%shapes(s))
      end do
      s = 0
   end function surface_shape

   !> Name of surface `id` ('' out of range).
   pure function surface_name(self, id) result(name)
      class(body_type), intent(in) :: self
      integer, intent(in) :: id
      character(len=:), allocatable :: name
      integer :: s
      name = ''
      s = self%surface_shape(id)
      if (s == 0) return
      if (id == s) then
         name = shape_name(self%shapes(s))
      else
         name = trim(self%shapes(s)%solid%set%group_name(id - self%group_surface(s, 1) + 1))
      end if
   end function surface_name

   !> Id of group g (1-based, of the facet set) of shape s; s itself for g = 0.
   pure integer function group_surface(self, s, g) result(id)
      class(body_type), intent(in) :: self
      integer, intent(in) :: s, g
      integer :: k
      id = s
      if (g <= 0) return
      id = self%nshape
      do k = 1, s - 1
         id = id + ngroup(self%shapes(k))
      end do
      id = id + g
   end function group_surface

   !> Is surface `part` (the id a surface point carries) part of surface `id`:
   !> the same, or a group of shape `id`'s file?
   pure logical function surface_part(self, id, part)
      class(body_type), intent(in) :: self
      integer, intent(in) :: id, part
      surface_part = part == id
      if (surface_part .or. id < 1 .or. id > self%nshape) return
      surface_part = self%surface_shape(part) == id
   end function surface_part

   !> The ids of the points of surface `id` (`surface_part`): id, and for a
   !> faceted shape's whole surface the ids of its groups.
   pure function surface_parts(self, id) result(ids)
      class(body_type), intent(in) :: self
      integer, intent(in) :: id
      integer, allocatable :: ids(:)
      integer :: g
      ids = [id]
      if (id < 1 .or. id > self%nshape) return
      ids = [id, (self%group_surface(id, g), g=1, ngroup(self%shapes(id)))]
   end function surface_parts

   !> Named groups of a faceted shape (0 for the other kinds).
   pure integer function ngroup(shape)
      type(shape_type), intent(in) :: shape
      ngroup = 0
      if (shape%kind /= shape_facets) return
      if (.not. allocated(shape%solid)) return
      if (allocated(shape%solid%set%group_name)) ngroup = size(shape%solid%set%group_name)
   end function ngroup

   !> Level set of the body at x: union min, intersect max, subtract max(a, -b).
   !> An empty body is outside everywhere (huge).
   pure real(wp) function body_phi(self, x) result(f)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer :: k

      f = huge(1.0_wp)
      if (self%nshape == 0) return
      f = self%shapes(1)%phi(x)
      do k = 2, self%nshape
         select case (self%ops(k))
         case (csg_add)
            f = min(f, self%shapes(k)%phi(x))
         case (csg_intersect)
            f = max(f, self%shapes(k)%phi(x))
         case (csg_subtract)
            f = max(f, -self%shapes(k)%phi(x))
         end select
      end do
   end function body_phi

   !> Snapping tolerance of a shape's level set over the box [lo, hi] (module notes).
   pure real(wp) function snap_tolerance(shape, lo, hi) result(tol)
      type(shape_type), intent(in) :: shape
      real(wp), intent(in) :: lo(:), hi(:)
      tol = snap_ulps*epsilon(1.0_wp)*(max(maxval(abs(lo)), maxval(abs(hi))) + shape%scale)
   end function snap_tolerance

   !> Class (cell_inside / cell_outside / cell_cut) of each shape alone over
   !> the box [lo, hi], from its certified range with the snapping tolerance.
   !> classes has size >= nshape.
   pure subroutine shape_classes(self, lo, hi, classes)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(out) :: classes(:)
      real(wp) :: fmin, fmax, tol
      integer :: k

      do k = 1, self%nshape
         if (self%shapes(k)%kind == shape_facets) then
            classes(k) = self%shapes(k)%facet_class(lo, hi)
            cycle
         end if
         call self%shapes(k)%phi_range(lo, hi, fmin, fmax)
         tol = snap_tolerance(self%shapes(k), lo, hi)
         classes(k) = class_of_range(fmin, fmax, tol)
      end do
   end subroutine shape_classes

   !> Class of the box [lo, hi] (size dim each): the shapes' classes combined
   !> by three-valued CSG logic. Never misses a cut; may return cell_cut for a
   !> box covered only by a union of several shapes (none alone covering it).
   pure integer function classify_box(self, lo, hi) result(cls)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer :: few(few_shapes), st
      integer, allocatable :: many(:)

      if (self%nshape <= few_shapes) then
         call self%shape_classes(lo, hi, few(1:self%nshape))
         cls = evaluate(self%ops, few(1:self%nshape))
         return
      end if
      ! out of memory: cut, which never misses a cut
      cls = cell_cut
      allocate (many(self%nshape), stat=st)
      if (st /= 0) return
      call self%shape_classes(lo, hi, many)
      cls = evaluate(self%ops, many)
   end function classify_box

   !> Class of the body from the shapes' classes (`shape_classes`) with shape
   !> i's class replaced by ci.
   pure integer function class_with(self, classes, i, ci) result(cls)
      class(body_type), intent(in) :: self
      integer, intent(in) :: classes(:), i, ci
      cls = evaluate_with(self%ops, classes(1:self%nshape), i, ci)
   end function class_with

   !> Shapes whose surface may pass through the box [lo, hi] and matters
   !> there: the shape is cut by the box and the body's class is not decided
   !> without it (setting it to inside and to outside gives different or
   !> undecided results). list(1:n), in file order; size(list) >= nshape.
   pure subroutine active_shapes(self, lo, hi, list, n)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(out) :: list(:)
      integer, intent(out) :: n
      integer :: few(few_shapes), st, k
      integer, allocatable :: many(:)

      if (self%nshape <= few_shapes) then
         call self%shape_classes(lo, hi, few(1:self%nshape))
         call unmasked_cuts(self%ops, few(1:self%nshape), list, n)
         return
      end if
      allocate (many(self%nshape), stat=st)
      if (st /= 0) then
         ! out of memory: every shape (a superset; the quadrature drops the ones that do not matter)
         n = self%nshape
         list(1:n) = [(k, k=1, n)]
         return
      end if
      call self%shape_classes(lo, hi, many)
      call unmasked_cuts(self%ops, many, list, n)
   end subroutine active_shapes

   !> True if x lies on the part of shape i's surface that bounds the body:
   !> |phi_i(x)| <= tol and the body's membership near x depends on shape i
   !> (the same masking test as `active_shapes`, with the point classes of
   !> every shape: inside if phi < -tol, outside if phi > tol, else on).
   pure logical function is_boundary_on(self, x, i, tol) result(on)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer, intent(in) :: i
      real(wp), intent(in) :: tol
      integer :: classes(self%nshape)

      on = .false.
      if (i < 1 .or. i > self%nshape) return
      call point_classes(self, x, tol, classes)
      if (classes(i) /= cell_cut) return
      on = .not. masked(self%ops, classes, i)
   end function is_boundary_on

   !> All shapes on whose surface x lies as a boundary of the body (see
   !> `is_boundary_on`), in file order: list(1:n), n = 0 if x is not on the
   !> boundary, n >= 2 at a CSG edge or corner. The rule for a single answer
   !> is list(1), the first in file order. size(list) >= nshape.
   pure subroutine surface_at(self, x, tol, list, n)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(in) :: tol
      integer, intent(out) :: list(:)
      integer, intent(out) :: n
      integer :: classes(self%nshape)

      call point_classes(self, x, tol, classes)
      call unmasked_cuts(self%ops, classes, list, n)
   end subroutine surface_at

   !> Unit outward normal of the body at x on shape i's surface (1 <= i <= nshape,
   !> size(normal) >= size(x)): the shape's
   !> normalised gradient, flipped for a subtracted shape (its outside is the
   !> body's inside). Shape i's conventions apply on its own edges (box).
   pure subroutine outward_normal(self, x, i, normal)
      class(body_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer, intent(in) :: i
      real(wp), intent(out) :: normal(:)
      real(wp) :: g(3), length
      integer :: d

      d = size(x)
      g(1:d) = self%shapes(i)%gradient(x)
      length = norm2(g(1:d))
      if (length > 0.0_wp) then
         g(1:d) = g(1:d)/length
      else
         ! Only at an ellipsoid's center, which is never on its surface.
         g = 0.0_wp
         g(1) = 1.0_wp
      end if
      if (self%ops(i) == csg_subtract) g(1:d) = -g(1:d)
      normal(1:d) = g(1:d)
   end subroutine outward_normal

   ! ------------------------------------------------------------ three-valued logic

   pure integer function class_of_range(fmin, fmax, tol) result(cls)
      real(wp), intent(in) :: fmin, fmax, tol
      if (fmax <= tol) then
         cls = cell_inside
      else if (fmin >= -tol) then
         cls = cell_outside
      else
         cls = cell_cut
      end if
   end function class_of_range

   !> Point classes: inside (phi < -tol), outside (phi > tol), on (cell_cut) otherwise.
   pure subroutine point_classes(self, x, tol, classes)
      type(body_type), intent(in) :: self
      real(wp), intent(in) :: x(:), tol
      integer, intent(out) :: classes(:)
      real(wp) :: f
      integer :: k
      do k = 1, self%nshape
         f = self%shapes(k)%phi(x)
         if (f < -tol) then
            classes(k) = cell_inside
         else if (f > tol) then
            classes(k) = cell_outside
         else
            classes(k) = cell_cut
         end if
      end do
   end subroutine point_classes

   !> Class of the body from the shapes' classes.
   pure integer function evaluate(ops, classes) result(cls)
      integer, intent(in) :: ops(:), classes(:)
      cls = evaluate_with(ops, classes, 0, cell_outside)
   end function evaluate

   !> `evaluate` with shape i's class replaced by ci (i = 0: none), without a copy.
   pure integer function evaluate_with(ops, classes, i, ci) result(cls)
      integer, intent(in) :: ops(:), classes(:), i, ci
      integer :: k, c
      cls = cell_outside
      do k = 1, size(classes)
         c = classes(k)
         if (k == i) c = ci
         if (k == 1) then
            cls = c
         else
            cls = combine(cls, ops(k), c)
         end if
      end do
   end function evaluate_with

   pure integer function combine(a, op, b) result(cls)
      integer, intent(in) :: a, op, b
      select case (op)
      case (csg_add)
         cls = kleene_union(a, b)
      case (csg_intersect)
         cls = kleene_intersect(a, b)
      case default
         cls = kleene_intersect(a, complement(b))
      end select
   end function combine

   pure integer function kleene_union(a, b) result(cls)
      integer, intent(in) :: a, b
      if (a == cell_inside .or. b == cell_inside) then
         cls = cell_inside
      else if (a == cell_outside .and. b == cell_outside) then
         cls = cell_outside
      else
         cls = cell_cut
      end if
   end function kleene_union

   pure integer function kleene_intersect(a, b) result(cls)
      integer, intent(in) :: a, b
      cls = complement(kleene_union(complement(a), complement(b)))
   end function kleene_intersect

   pure integer function complement(a) result(cls)
      integer, intent(in) :: a
      select case (a)
      case (cell_inside)
         cls = cell_outside
      case (cell_outside)
         cls = cell_inside
      case default
         cls = cell_cut
      end select
   end function complement

   !> True if the body's class does not depend on shape i: inside and outside
   !> for shape i give the same decided class.
   pure logical function masked(ops, classes, i)
      integer, intent(in) :: ops(:), classes(:), i
      integer :: as_inside, as_outside

      as_inside = evaluate_with(ops, classes, i, cell_inside)
      as_outside = evaluate_with(ops, classes, i, cell_outside)
      masked = as_inside /= cell_cut .and. as_inside == as_outside
   end function masked

   pure subroutine unmasked_cuts(ops, classes, list, n)
      integer, intent(in) :: ops(:), classes(:)
      integer, intent(out) :: list(:), n
      integer :: k
      n = 0
      do k = 1, size(classes)
         if (classes(k) /= cell_cut) cycle
         if (masked(ops, classes, k)) cycle
         n = n + 1
         list(n) = k
      end do
   end subroutine unmasked_cuts

   !> Error (stat_invalid_input) naming the body and the box when the body has material
   !> outside the box [box_min, box_min + box_size]^dim: the grid would clip it silently.
   !> Searches slabs of width box_size/16 outside each face for a part of the body (a
   !> certified inside sub-box, or the centre of a cut one after `depth_limit` halvings
   !> with phi below minus the snapping tolerance). A body that crosses a face has material
   !> in the slab beyond it; one that only touches a face (a plane on the box boundary, a
   !> circle tangent to it) has none. Then a piece anywhere outside the box
   !> (`find_outside_piece`): a separate part of the body beyond the slabs. With
   !> `own_box`, the box is the body's own level-0 cell (`&body` box_min, box_size)
   !> and the message says so.
   subroutine check_body_in_box(self, box_min, box_size, error, own_box)
      type(body_type), intent(in) :: self
      real(wp), intent(in) :: box_min(:), box_size
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: own_box
      real(wp) :: lo(3), hi(3), x(3)
      integer :: d, k, side, piece
      logical :: found

      d = self%dim
      if (d < 2 .or. size(box_min) < d) return
      piece = 0
      found = .false.
      slabs: do k = 1, d
         do side = 0, 1
            lo(1:d) = box_min(1:d)
            hi(1:d) = box_min(1:d) + box_size
            if (side == 0) then
               hi(k) = lo(k)
               lo(k) = lo(k) - box_size/16.0_wp
            else
               lo(k) = hi(k)
               hi(k) = hi(k) + box_size/16.0_wp
            end if
            call find_inside(self, lo(1:d), hi(1:d), depth_limit, found, x(1:d))
            if (found) exit slabs
         end do
      end do slabs
      if (.not. found) then
         lo(1:d) = box_min(1:d)
         hi(1:d) = box_min(1:d) + box_size
         call find_outside_piece(self, lo(1:d), hi(1:d), found, x(1:d), piece)
      end if
      if (.not. found) return
      call outside_box_error(self, box_min(1:d), box_size, x(1:d), piece, error, own_box)
   end subroutine check_body_in_box

   !> The error of `check_body_in_box`: the body, the box, the point x of material
   !> outside it and, when known, the added shape `piece` it belongs to.
   subroutine outside_box_error(self, box_min, box_size, x, piece, error, own_box)
      type(body_type), intent(in) :: self
      real(wp), intent(in) :: box_min(:), box_size, x(:)
      integer, intent(in) :: piece
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: own_box
      character(len=:), allocatable :: where, whose, keys, piece_text
      integer :: j, d

      d = size(box_min)
      where = real_str(box_min(1))//'..'//real_str(box_min(1) + box_size)
      do j = 2, d
         where = where//' x '//real_str(box_min(j))//'..'//real_str(box_min(j) + box_size)
      end do
      whose = "the scene's box "
      keys = '&scene'
      if (present(own_box)) then
         if (own_box) then
            whose = 'its own box '
            keys = '&body'
         end if
      end if
      piece_text = ''
      if (piece > 0) piece_text = " (shape '"//shape_name(self%shapes(piece))//"')"
      call fatal_error(error, "body '"//body_name(self)//"' extends beyond "//whose//where// &
         & ' ('//keys//': box_min, box_size): it has material at ('//real_list(x)//')'//piece_text// &
         & ', which the grid would cut off; enlarge box_size or move box_min so that the box holds the '// &
         & 'whole body', stat_invalid_input)
   end subroutine outside_box_error

   !> A point x of the body outside the box [box_lo, box_hi], anywhere. The body lies in
   !> the union over its added shapes i (the first included) of the piece P_i: the bounds
   !> of shape i (`shape_type%bounds`) cut by those of every shape intersected after it
   !> (subtracting only removes material). Each P_i less the box is the union of up to
   !> 2 dim boxes (along axis k below or above the box, inside it along the axes before
   !> k), each searched with `find_inside`; `piece` is i. An unbounded side of P_i is
   !> cut at `far_boxes` box widths from the box.
   subroutine find_outside_piece(self, box_lo, box_hi, found, x, piece)
      type(body_type), intent(in) :: self
      real(wp), intent(in) :: box_lo(:), box_hi(:)
      logical, intent(out) :: found
      real(wp), intent(out) :: x(:)
      integer, intent(out) :: piece
      real(wp), parameter :: far_boxes = 1024.0_wp
      real(wp) :: plo(3), phi(3), slo(3), shi(3), far
      integer :: d, i, j, k, side

      d = size(box_lo)
      found = .false.
      far = far_boxes*maxval(box_hi - box_lo)
      do piece = 1, self%nshape
         if (self%ops(piece) /= csg_add .and. piece > 1) cycle
         call self%shapes(piece)%bounds(plo(1:d), phi(1:d))
         do i = piece + 1, self%nshape
            if (self%ops(i) /= csg_intersect) cycle
            call self%shapes(i)%bounds(slo(1:d), shi(1:d))
            plo(1:d) = max(plo(1:d), slo(1:d))
            phi(1:d) = min(phi(1:d), shi(1:d))
         end do
         plo(1:d) = max(plo(1:d), box_lo - far)
         phi(1:d) = min(phi(1:d), box_hi + far)
         do k = 1, d
            do side = 0, 1
               slo(1:d) = plo(1:d)
               shi(1:d) = phi(1:d)
               do j = 1, k - 1
                  slo(j) = max(slo(j), box_lo(j))
                  shi(j) = min(shi(j), box_hi(j))
               end do
               if (side == 0) then
                  shi(k) = min(shi(k), box_lo(k))
               else
                  slo(k) = max(slo(k), box_hi(k))
               end if
               if (any(slo(1:d) >= shi(1:d))) cycle
               call find_inside(self, slo(1:d), shi(1:d), depth_limit, found, x)
               if (found) return
            end do
         end do
      end do
      piece = 0
   end subroutine find_outside_piece

   !> A point x of the body in the box [lo, hi], by bisection of the cut boxes (module
   !> notes on the snapping tolerance).
   recursive subroutine find_inside(self, lo, hi, depth, found, x)
      type(body_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: depth
      logical, intent(out) :: found
      real(wp), intent(out) :: x(:)
      real(wp) :: clo(size(lo)), chi(size(lo)), mid(size(lo))
      integer :: child, k

      x = 0.5_wp*(lo + hi)
      found = .false.
      select case (self%classify_box(lo, hi))
      case (cell_inside)
         found = .true.
         return
      case (cell_outside)
         return
      end select
      if (depth == 0) then
         found = self%phi(x) < -snap_ulps*epsilon(1.0_wp)*(maxval(abs(lo)) + maxval(abs(hi)))
         return
      end if
      mid = x
      do child = 0, 2**size(lo) - 1
         do k = 1, size(lo)
            if (btest(child, k - 1)) then
               clo(k) = mid(k)
               chi(k) = hi(k)
            else
               clo(k) = lo(k)
               chi(k) = mid(k)
            end if
         end do
         call find_inside(self, clo, chi, depth - 1, found, x)
         if (found) return
      end do
   end subroutine find_inside

   ! ------------------------------------------------------------ text

   !> Six significant digits, trailing zeros dropped: 15, -7.5, 0.125, 1.5e+20.
   pure function real_str(v) result(s)
      real(wp), intent(in) :: v
      character(len=:), allocatable :: s
      character(len=32) :: buf
      integer :: n

      if (v /= 0.0_wp .and. (abs(v) >= 1.0e6_wp .or. abs(v) < 1.0e-3_wp)) then
         write (buf, '(es14.5e3)') v
         buf = adjustl(buf)
         n = index(buf, 'E')
         s = strip_zeros(buf(1:n - 1))//'e'//buf(n + 1:len_trim(buf))
      else
         s = strip_zeros(fixed_text(v, 6))
      end if
   end function real_str

   pure function strip_zeros(t) result(s)
      character(len=*), intent(in) :: t
      character(len=:), allocatable :: s
      s = t
      if (index(s, '.') == 0) return
      do while (s(len(s):len(s)) == '0')
         s = s(1:len(s) - 1)
      end do
      if (s(len(s):len(s)) == '.') s = s(1:len(s) - 1)
   end function strip_zeros

   pure function real_list(v) result(s)
      real(wp), intent(in) :: v(:)
      character(len=:), allocatable :: s
      integer :: i
      s = real_str(v(1))
      do i = 2, size(v)
         s = s//', '//real_str(v(i))
      end do
   end function real_list

   pure function body_name(self) result(name)
      type(body_type), intent(in) :: self
      character(len=:), allocatable :: name
      name = ''
      if (allocated(self%name)) name = self%name
   end function body_name

   pure function shape_name(shape) result(name)
      type(shape_type), intent(in) :: shape
      character(len=:), allocatable :: name
      name = ''
      if (allocated(shape%name)) name = shape%name
   end function shape_name

end module sprc_geometry_body
