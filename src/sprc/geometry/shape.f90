!> Implicit primitive shapes of the scene (`&shape` in doc/scene.md): disk/sphere,
!> ellipse/ellipsoid, axis-aligned box, halfspace and infinite cylinder.
!>
!> Each shape is a level set phi, negative inside; the closed set phi <= 0 is
!> the shape. The forms are chosen smooth and well scaled, so that tolerances
!> on phi are lengths:
!> - disk/sphere: |x - c| - r (signed distance);
!> - ellipse/ellipsoid: (a_min/2) (sum ((x - c)/a)^2 - 1), which is the signed
!>   distance to first order for a circle and has |grad phi| in
!>   [a_min/a_max, 1] on the surface;
!> - box: max over its 2*dim faces of the signed face distances (signed
!>   distance inside, a lower bound of it outside);
!> - halfspace: (x - p).n with n the unit outward normal (signed distance);
!> - cylinder: |(I - a a^T)(x - p)| - r with a the unit axis (signed distance).
!>
!> `phi_range` gives a certified enclosure of phi over an axis-aligned box: the
!> lower bound never exceeds the true minimum and the upper bound is never
!> below the true maximum (up to the rounding of phi's own evaluation, a few
!> ulps of the coordinate magnitude). It is exact (attained) for every kind:
!> each bound is phi evaluated at a point of the box where the extremum is
!> attained, found from the shape's analytic structure, never by sampling.
!>
!> - facets: a closed faceted surface (sprc_geometry_facet_solid): the signed
!>   distance to the nearest facet, negative inside (inside test by ray
!>   parity through the facet hierarchy).
!>
!> For facets `phi_range` is the Lipschitz enclosure phi(centre) -+ half the
!> box diagonal, made sign-definite for a box no facet cuts (the facet
!> solid's classification): certified, not attained. Cells are classified by
!> the facet solid directly (`facet_class`), not from this range.
!>
!> `gradient_range` gives a certified enclosure of one component of the
!> gradient over a box (what a height-direction test needs): exact for the
!> disk/sphere, ellipse/ellipsoid, halfspace and axis-parallel cylinder; a
!> sound over-estimate for an oblique cylinder and for the box (whose gradient
!> takes the values -1, 0, 1).
module sprc_geometry_shape
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp
   use sprc_core_sort, only: sort
   use sprc_core_text, only: itoa, rtoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_geometry_region, only: cell_inside, cell_outside
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_facet_solid, only: facet_solid_type, new_facet_solid, solid_nearest, solid_inside, &
      & solid_box_class
   implicit none
   private

   public :: shape_type
   public :: shape_disk, shape_sphere, shape_ellipse, shape_ellipsoid, shape_box, shape_halfspace, shape_cylinder
   public :: new_disk, new_sphere, new_ellipse, new_ellipsoid, new_box, new_halfspace, new_cylinder
   public :: shape_facets, new_facet_shape
   public :: shape_kind_name, shape_kind_from_name

   !> Shape kinds (values are stable: scene and C API may store them): disk (2D).
   integer, parameter :: shape_disk = 1
   !> Sphere (3D).
   integer, parameter :: shape_sphere = 2
   !> Ellipse (2D).
   integer, parameter :: shape_ellipse = 3
   !> Ellipsoid (3D).
   integer, parameter :: shape_ellipsoid = 4
   !> Axis-aligned box.
   integer, parameter :: shape_box = 5
   !> Halfspace.
   integer, parameter :: shape_halfspace = 6
   !> Infinite cylinder (3D).
   integer, parameter :: shape_cylinder = 7
   !> Closed faceted surface (2D polygon, 3D triangles).
   integer, parameter :: shape_facets = 8

   character(len=*), parameter :: kind_names(8) = [character(len=9) :: &
      & 'disk', 'sphere', 'ellipse', 'ellipsoid', 'box', 'halfspace', 'cylinder', 'facets']

   !> One implicit primitive. Only the parameters of its kind are meaningful;
   !> vectors hold `dim` used entries (the rest are zero).
   type :: shape_type
      !> One of the `shape_*` kinds; 0 for a shape never constructed.
      integer :: kind = 0
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Name of the surface (boundary conditions refer to it).
      character(len=:), allocatable :: name
      !> Disk, sphere, ellipse, ellipsoid: center.
      real(wp) :: center(3) = 0.0_wp
      !> Disk, sphere, cylinder: radius.
      real(wp) :: radius = 0.0_wp
      !> Ellipse, ellipsoid: semi-axes along x, y (, z).
      real(wp) :: semi_axes(3) = 0.0_wp
      !> Box: lower and upper corners.
      real(wp) :: lower(3) = 0.0_wp, upper(3) = 0.0_wp
      !> Halfspace and cylinder: a point on the plane / on the axis.
      real(wp) :: point(3) = 0.0_wp
      !> Halfspace: unit outward normal (the shape is (x - point).normal <= 0).
      real(wp) :: normal(3) = 0.0_wp
      !> Cylinder: unit axis direction.
      real(wp) :: axis(3) = 0.0_wp
      !> Magnitude of the parameters (a length), for round-off tolerances.
      real(wp) :: scale = 0.0_wp
      !> The faceted solid with its hierarchy (kind facets).
      type(facet_solid_type), allocatable :: solid
   contains
      procedure :: phi => shape_phi
      procedure :: gradient => shape_gradient
      procedure :: phi_range => shape_phi_range
      procedure :: gradient_range => shape_gradient_range
      procedure :: bounds => shape_bounds
      procedure :: facet_class
   end type shape_type

contains

   ! ------------------------------------------------------------ constructors
   ! On error the shape is left unconstructed (kind 0): a body rejects it.

   !> A disk (2D): |x - center| <= radius.
   subroutine new_disk(self, name, center, radius, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: center(:), radius
      type(error_type), allocatable, intent(out) :: error
      call new_round(self, shape_disk, 2, name, center, radius, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_disk

   !> A sphere (3D, the solid ball): |x - center| <= radius.
   subroutine new_sphere(self, name, center, radius, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: center(:), radius
      type(error_type), allocatable, intent(out) :: error
      call new_round(self, shape_sphere, 3, name, center, radius, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_sphere

   subroutine new_round(self, kind, dim, name, center, radius, error)
      type(shape_type), intent(out) :: self
      integer, intent(in) :: kind, dim
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: center(:), radius
      type(error_type), allocatable, intent(out) :: error

      call start(self, kind, dim, name)
      call check_size(self, 'center', size(center), error)
      if (allocated(error)) return
      call check_finite(self, 'center', center, error)
      if (allocated(error)) return
      call check_positive(self, 'radius', [radius], error)
      if (allocated(error)) return
      self%center(1:dim) = center
      self%radius = radius
      self%scale = maxval(abs(center)) + radius
   end subroutine new_round

   !> An axis-aligned ellipse (2D): sum(((x - center)/semi_axes)**2) <= 1.
   subroutine new_ellipse(self, name, center, semi_axes, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: center(:), semi_axes(:)
      type(error_type), allocatable, intent(out) :: error
      call new_ellipsoidal(self, shape_ellipse, 2, name, center, semi_axes, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_ellipse

   !> An axis-aligned ellipsoid (3D): sum(((x - center)/semi_axes)**2) <= 1.
   subroutine new_ellipsoid(self, name, center, semi_axes, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: center(:), semi_axes(:)
      type(error_type), allocatable, intent(out) :: error
      call new_ellipsoidal(self, shape_ellipsoid, 3, name, center, semi_axes, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_ellipsoid

   subroutine new_ellipsoidal(self, kind, dim, name, center, semi_axes, error)
      type(shape_type), intent(out) :: self
      integer, intent(in) :: kind, dim
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: center(:), semi_axes(:)
      type(error_type), allocatable, intent(out) :: error

      call start(self, kind, dim, name)
      call check_size(self, 'center', size(center), error)
      if (allocated(error)) return
      call check_size(self, 'semi_axes', size(semi_axes), error)
      if (allocated(error)) return
      call check_finite(self, 'center', center, error)
      if (allocated(error)) return
      call check_positive(self, 'semi_axes', semi_axes, error)
      if (allocated(error)) return
      self%center(1:dim) = center
      self%semi_axes(1:dim) = semi_axes
      self%scale = maxval(abs(center)) + maxval(semi_axes)
   end subroutine new_ellipsoidal

   !> An axis-aligned box [lower, upper] in 2D or 3D (dimension from size(lower)).
   subroutine new_box(self, name, lower, upper, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: lower(:), upper(:)
      type(error_type), allocatable, intent(out) :: error
      call build_box(self, name, lower, upper, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_box

   subroutine build_box(self, name, lower, upper, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: lower(:), upper(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      call start(self, shape_box, size(lower), name)
      call check_dim_2_or_3(self, 'lower', error)
      if (allocated(error)) return
      call check_size(self, 'upper', size(upper), error)
      if (allocated(error)) return
      call check_finite(self, 'lower', lower, error)
      if (allocated(error)) return
      call check_finite(self, 'upper', upper, error)
      if (allocated(error)) return
      do i = 1, self%dim
         if (.not. lower(i) < upper(i)) then
            call fatal_error(error, prefix(self)//'lower('//itoa(i)//') = '//rtoa(lower(i), '(g0)')// &
               & ' must be < upper('//itoa(i)//') = '//rtoa(upper(i), '(g0)'), stat_invalid_input)
            return
         end if
      end do
      self%lower(1:self%dim) = lower
      self%upper(1:self%dim) = upper
      self%scale = max(maxval(abs(lower)), maxval(abs(upper)))
   end subroutine build_box

   !> A halfspace (x - point).normal <= 0 in 2D or 3D; `normal` (any nonzero
   !> length, normalised here) is the outward normal.
   subroutine new_halfspace(self, name, point, normal, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: point(:), normal(:)
      type(error_type), allocatable, intent(out) :: error
      call build_halfspace(self, name, point, normal, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_halfspace

   subroutine build_halfspace(self, name, point, normal, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: point(:), normal(:)
      type(error_type), allocatable, intent(out) :: error

      call start(self, shape_halfspace, size(point), name)
      call check_dim_2_or_3(self, 'point', error)
      if (allocated(error)) return
      call check_size(self, 'normal', size(normal), error)
      if (allocated(error)) return
      call check_finite(self, 'point', point, error)
      if (allocated(error)) return
      call check_direction(self, 'normal', normal, error)
      if (allocated(error)) return
      self%point(1:self%dim) = point
      self%normal(1:self%dim) = normal/norm2(normal)
      self%scale = maxval(abs(point))
   end subroutine build_halfspace

   !> An infinite solid cylinder (3D) of the given radius around the line
   !> through `point` along `axis` (any nonzero length, normalised here).
   subroutine new_cylinder(self, name, point, axis, radius, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: point(:), axis(:), radius
      type(error_type), allocatable, intent(out) :: error
      call build_cylinder(self, name, point, axis, radius, error)
      if (allocated(error)) self%kind = 0
   end subroutine new_cylinder

   subroutine build_cylinder(self, name, point, axis, radius, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: point(:), axis(:), radius
      type(error_type), allocatable, intent(out) :: error

      call start(self, shape_cylinder, 3, name)
      call check_size(self, 'point', size(point), error)
      if (allocated(error)) return
      call check_size(self, 'axis', size(axis), error)
      if (allocated(error)) return
      call check_finite(self, 'point', point, error)
      if (allocated(error)) return
      call check_direction(self, 'axis', axis, error)
      if (allocated(error)) return
      call check_positive(self, 'radius', [radius], error)
      if (allocated(error)) return
      self%point = point
      self%axis = axis/norm2(axis)
      self%radius = radius
      self%scale = maxval(abs(point)) + radius
   end subroutine build_cylinder

   !> A closed faceted solid (kind shape_facets) of the dimension of the facet
   !> set. The surface must be closed and oriented outwards (the readers
   !> validate it); checked here: dimension 2 or 3, at least dim + 1 facets,
   !> vertex indices in range.
   subroutine new_facet_shape(self, name, facets, error)
      type(shape_type), intent(out) :: self
      character(len=*), intent(in) :: name
      type(facet_set_type), intent(in) :: facets
      type(error_type), allocatable, intent(out) :: error

      call start(self, shape_facets, facets%dim, name)
      call check_dim_2_or_3(self, 'facets%dim', error)
      if (.not. allocated(error)) call check_facet_set(self, facets, error)
      if (allocated(error)) then
         self%kind = 0
         return
      end if
      allocate (self%solid)
      call new_facet_solid(self%solid, facets)
      self%scale = self%solid%scale
   end subroutine new_facet_shape

   subroutine check_facet_set(self, facets, error)
      type(shape_type), intent(in) :: self
      type(facet_set_type), intent(in) :: facets
      type(error_type), allocatable, intent(out) :: error
      integer :: d

      d = facets%dim
      if (facets%nfacet < d + 1 .or. .not. allocated(facets%facet) .or. .not. allocated(facets%vert)) then
         call fatal_error(error, prefix(self)//itoa(facets%nfacet)//' facets; a closed surface needs at least '// &
            & itoa(d + 1), stat_invalid_input)
         return
      end if
      if (size(facets%facet, 1) /= d .or. size(facets%facet, 2) < facets%nfacet .or. &
         & size(facets%vert, 2) < facets%nvert) then
         call fatal_error(error, prefix(self)//'facet array shape does not match dim and nfacet', stat_invalid_input)
         return
      end if
      if (any(facets%facet(:, 1:facets%nfacet) < 1) .or. any(facets%facet(:, 1:facets%nfacet) > facets%nvert)) then
         call fatal_error(error, prefix(self)//'a facet vertex index is outside 1..'//itoa(facets%nvert), &
            & stat_invalid_input)
         return
      end if
      call check_finite(self, 'vert', reshape(facets%vert(:, 1:facets%nvert), [3*facets%nvert]), error)
   end subroutine check_facet_set

   !> Class (cell_inside / cell_outside / cell_cut) of the box [lo, hi] for a
   !> facet shape (sprc_geometry_facet_solid notes).
   pure integer function facet_class(self, lo, hi) result(cls)
      class(shape_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      cls = solid_box_class(self%solid, lo, hi)
   end function facet_class

   !> Name of a kind ('disk', ...); '' for an unknown kind.
   pure function shape_kind_name(kind) result(name)
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      if (kind >= 1 .and. kind <= size(kind_names)) then
         name = trim(kind_names(kind))
      else
         name = ''
      end if
   end function shape_kind_name

   !> Kind of a name ('disk' -> shape_disk, ...); 0 for an unknown name.
   pure integer function shape_kind_from_name(name) result(kind)
      character(len=*), intent(in) :: name
      do kind = 1, size(kind_names)
         if (trim(adjustl(name)) == trim(kind_names(kind))) return
      end do
      kind = 0
   end function shape_kind_from_name

   ! ------------------------------------------------------------ level set

   !> Axis-aligned box [lo, hi] (size dim) that holds the shape, exact for the
   !> bounded kinds; an unbounded side is -huge / +huge. A halfspace is bounded
   !> only along an axis its normal is parallel to, a cylinder only across the
   !> axes its direction has no component along.
   pure subroutine shape_bounds(self, lo, hi)
      class(shape_type), intent(in) :: self
      real(wp), intent(out) :: lo(:), hi(:)
      integer :: d, k

      d = self%dim
      lo(1:d) = -huge(1.0_wp)
      hi(1:d) = huge(1.0_wp)
      select case (self%kind)
      case (shape_disk, shape_sphere)
         lo(1:d) = self%center(1:d) - self%radius
         hi(1:d) = self%center(1:d) + self%radius
      case (shape_ellipse, shape_ellipsoid)
         lo(1:d) = self%center(1:d) - self%semi_axes(1:d)
         hi(1:d) = self%center(1:d) + self%semi_axes(1:d)
      case (shape_box)
         lo(1:d) = self%lower(1:d)
         hi(1:d) = self%upper(1:d)
      case (shape_halfspace)
         do k = 1, d
            if (count(self%normal(1:d) /= 0.0_wp) /= 1 .or. self%normal(k) == 0.0_wp) cycle
            if (self%normal(k) > 0.0_wp) then
               hi(k) = self%point(k)
            else
               lo(k) = self%point(k)
            end if
         end do
      case (shape_cylinder)
         do k = 1, d
            if (self%axis(k) /= 0.0_wp) cycle
            lo(k) = self%point(k) - self%radius
            hi(k) = self%point(k) + self%radius
         end do
      case (shape_facets)
         lo(1:d) = self%solid%lo(1:d, 1)
         hi(1:d) = self%solid%hi(1:d, 1)
      case default
         ! A shape never constructed is empty.
         lo(1:d) = huge(1.0_wp)
         hi(1:d) = -huge(1.0_wp)
      end select
   end subroutine shape_bounds

   !> Level set at x (size dim): negative inside, zero on the surface.
   pure real(wp) function shape_phi(self, x) result(f)
      class(shape_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer :: d

      d = self%dim
      select case (self%kind)
      case (shape_disk, shape_sphere)
         f = norm2(x(1:d) - self%center(1:d)) - self%radius
      case (shape_ellipse, shape_ellipsoid)
         f = ellipsoid_factor(self)*(sum(((x(1:d) - self%center(1:d))/self%semi_axes(1:d))**2) - 1.0_wp)
      case (shape_box)
         f = maxval(max(self%lower(1:d) - x(1:d), x(1:d) - self%upper(1:d)))
      case (shape_halfspace)
         f = dot_product(x(1:d) - self%point(1:d), self%normal(1:d))
      case (shape_cylinder)
         f = norm2(perpendicular(self%axis, x(1:3) - self%point)) - self%radius
      case (shape_facets)
         f = facet_phi(self, x)
      case default
         ! A shape never constructed is empty: outside everywhere.
         f = huge(1.0_wp)
      end select
   end function shape_phi

   !> Gradient of phi at x. Unit length for every kind except the ellipse and
   !> ellipsoid. Where phi is not differentiable the rule is: sphere center and
   !> cylinder axis give a fixed unit vector (e_1, or a unit vector normal to
   !> the axis); on a box edge or corner the first face (in the order x-lower,
   !> x-upper, y-lower, ...) attaining the maximum wins.
   pure function shape_gradient(self, x) result(g)
      class(shape_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp) :: g(size(x))
      real(wp) :: v(3), length, face
      integer :: d, i

      d = self%dim
      g = 0.0_wp
      select case (self%kind)
      case (shape_disk, shape_sphere)
         v(1:d) = x(1:d) - self%center(1:d)
         length = norm2(v(1:d))
         if (length > 0.0_wp) then
            g(1:d) = v(1:d)/length
         else
            g(1) = 1.0_wp
         end if
      case (shape_ellipse, shape_ellipsoid)
         g(1:d) = 2.0_wp*ellipsoid_factor(self)*(x(1:d) - self%center(1:d))/self%semi_axes(1:d)**2
      case (shape_box)
         face = -huge(1.0_wp)
         do i = 1, d
            if (self%lower(i) - x(i) > face) then
               face = self%lower(i) - x(i)
               g = 0.0_wp
               g(i) = -1.0_wp
            end if
            if (x(i) - self%upper(i) > face) then
               face = x(i) - self%upper(i)
               g = 0.0_wp
               g(i) = 1.0_wp
            end if
         end do
      case (shape_halfspace)
         g(1:d) = self%normal(1:d)
      case (shape_cylinder)
         v = perpendicular(self%axis, x(1:3) - self%point)
         length = norm2(v)
         if (length > 0.0_wp) then
            g = v/length
         else
            i = minloc(abs(self%axis), 1)
            v = 0.0_wp
            v(i) = 1.0_wp
            v = perpendicular(self%axis, v)
            g = v/norm2(v)
         end if
      case (shape_facets)
         g(1:d) = facet_gradient(self, x)
      end select
   end function shape_gradient

   !> Signed distance to the faceted surface (0 on it within the snapping length).
   pure real(wp) function facet_phi(self, x) result(f)
      type(shape_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer :: g
      logical :: inside, on

      call solid_nearest(self%solid, x, g, f)
      call solid_inside(self%solid, x, inside, on)
      if (on) f = 0.0_wp
      if (inside) f = -f
   end function facet_phi

   !> Gradient for facets: the outward normal of the nearest facet (the
   !> gradient of the signed distance wherever the nearest point is inside a
   !> facet; a unit direction of the same side elsewhere).
   pure function facet_gradient(self, x) result(g)
      type(shape_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp) :: g(self%dim), f
      integer :: k

      call solid_nearest(self%solid, x, k, f)
      g = self%solid%normal(1:self%dim, k)
   end function facet_gradient

   !> Certified enclosure [fmin, fmax] of phi over the box [lo, hi] (size dim,
   !> lo <= hi). Exact for every kind (see the module notes):
   !> - sphere: distance from the center to the box, and to its farthest corner;
   !> - ellipsoid: sum of independent 1D quadratics, each clamped;
   !> - box: min over the box of max_i g_i(x_i) = max_i min g_i (separable);
   !> - halfspace: linear, so per-axis choice of the corner;
   !> - cylinder: max at a corner (|P(x - p)| is convex); min is the
   !>   line-to-box distance, minimised exactly over the piecewise quadratic
   !>   distance along the axis.
   pure subroutine shape_phi_range(self, lo, hi, fmin, fmax)
      class(shape_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp), intent(out) :: fmin, fmax
      real(wp) :: near(3), far(3), tmin(3), tmax(3), s
      integer :: d, i, corner

      d = self%dim
      select case (self%kind)
      case (shape_disk, shape_sphere)
         near(1:d) = min(max(self%center(1:d), lo(1:d)), hi(1:d)) - self%center(1:d)
         far(1:d) = max(abs(lo(1:d) - self%center(1:d)), abs(hi(1:d) - self%center(1:d)))
         fmin = norm2(near(1:d)) - self%radius
         fmax = norm2(far(1:d)) - self%radius
      case (shape_ellipse, shape_ellipsoid)
         near(1:d) = min(max(self%center(1:d), lo(1:d)), hi(1:d)) - self%center(1:d)
         far(1:d) = max(abs(lo(1:d) - self%center(1:d)), abs(hi(1:d) - self%center(1:d)))
         s = ellipsoid_factor(self)
         fmin = s*(sum((near(1:d)/self%semi_axes(1:d))**2) - 1.0_wp)
         fmax = s*(sum((far(1:d)/self%semi_axes(1:d))**2) - 1.0_wp)
      case (shape_box)
         ! g_i(t) = max(lower_i - t, t - upper_i) is V-shaped with its vertex at the mid-plane.
         near(1:d) = min(max(0.5_wp*(self%lower(1:d) + self%upper(1:d)), lo(1:d)), hi(1:d))
         tmin(1:d) = max(self%lower(1:d) - near(1:d), near(1:d) - self%upper(1:d))
         tmax(1:d) = max(self%lower(1:d) - lo(1:d), hi(1:d) - self%upper(1:d))
         fmin = maxval(tmin(1:d))
         fmax = maxval(tmax(1:d))
      case (shape_halfspace)
         tmin(1:d) = self%normal(1:d)*(lo(1:d) - self%point(1:d))
         tmax(1:d) = self%normal(1:d)*(hi(1:d) - self%point(1:d))
         fmin = sum(min(tmin(1:d), tmax(1:d)))
         fmax = sum(max(tmin(1:d), tmax(1:d)))
      case (shape_facets)
         call facet_phi_range(self, lo, hi, fmin, fmax)
      case (shape_cylinder)
         fmin = line_box_distance(self%point, self%axis, lo(1:3), hi(1:3)) - self%radius
         fmax = -huge(1.0_wp)
         do corner = 0, 7
            do i = 1, 3
               far(i) = merge(hi(i), lo(i), btest(corner, i - 1))
            end do
            fmax = max(fmax, self%phi(far))
         end do
      case default
         fmin = huge(1.0_wp)
         fmax = huge(1.0_wp)
      end select
   end subroutine shape_phi_range

   !> Lipschitz enclosure of the signed distance over a box, sign-definite if no facet cuts it.
   pure subroutine facet_phi_range(self, lo, hi, fmin, fmax)
      type(shape_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp), intent(out) :: fmin, fmax
      real(wp) :: f, r
      integer :: d

      d = self%dim
      f = facet_phi(self, 0.5_wp*(lo(1:d) + hi(1:d)))
      r = 0.5_wp*norm2(hi(1:d) - lo(1:d))
      fmin = f - r
      fmax = f + r
      select case (self%facet_class(lo, hi))
      case (cell_inside)
         fmax = min(fmax, 0.0_wp)
      case (cell_outside)
         fmin = max(fmin, 0.0_wp)
      end select
   end subroutine facet_phi_range

   !> Certified enclosure [gmin, gmax] of the k-th gradient component over the
   !> box [lo, hi] (size dim, lo <= hi, 1 <= k <= dim); see the module notes.
   !> - sphere: g_k = t/sqrt(t^2 + s^2) with t = x_k - c_k and s the distance of
   !>   the other coordinates to the center's: increasing in t, decreasing in
   !>   s for t > 0 and increasing for t < 0, so each bound takes t at a face
   !>   and s at its nearest or farthest value (exact); [-1, 1] if the center
   !>   lies in the box (every direction is a limit there);
   !> - ellipsoid: affine in x_k; halfspace: constant;
   !> - cylinder along a coordinate axis: the disk rule in the normal plane
   !>   (exact); oblique: numerator range over denominator range, clipped to
   !>   [-1, 1] (sound);
   !> - box: -1 possible only in the lower half along k, +1 only in the
   !>   upper half, 0 wherever another face may win (sound).
   pure subroutine shape_gradient_range(self, lo, hi, k, gmin, gmax)
      class(shape_type), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: k
      real(wp), intent(out) :: gmin, gmax
      real(wp) :: s, nlo, nhi, dmin, dmax, far(3)
      logical :: other(3)
      integer :: d, i, corner

      d = self%dim
      select case (self%kind)
      case (shape_disk, shape_sphere)
         other = .true.
         other(k) = .false.
         call round_gradient_range(self%center, lo, hi, k, other(1:d), gmin, gmax)
      case (shape_ellipse, shape_ellipsoid)
         s = 2.0_wp*ellipsoid_factor(self)/self%semi_axes(k)**2
         gmin = s*(lo(k) - self%center(k))
         gmax = s*(hi(k) - self%center(k))
      case (shape_halfspace)
         gmin = self%normal(k)
         gmax = self%normal(k)
      case (shape_cylinder)
         if (count(self%axis == 0.0_wp) == 2) then
            ! axis along a coordinate direction: phi is the disk's in the normal plane
            other = self%axis == 0.0_wp
            if (.not. other(k)) then
               gmin = 0.0_wp
               gmax = 0.0_wp
               return
            end if
            other(k) = .false.
            call round_gradient_range(self%point, lo, hi, k, other, gmin, gmax)
            return
         end if
         ! numerator e_k.P(x - p) is affine: its range is attained at corners
         nlo = huge(1.0_wp)
         nhi = -huge(1.0_wp)
         do corner = 0, 7
            do i = 1, 3
               far(i) = merge(hi(i), lo(i), btest(corner, i - 1))
            end do
            s = perpendicular_component(self%axis, far - self%point, k)
            nlo = min(nlo, s)
            nhi = max(nhi, s)
         end do
         dmin = line_box_distance(self%point, self%axis, lo(1:3), hi(1:3))
         dmax = -huge(1.0_wp)
         do corner = 0, 7
            do i = 1, 3
               far(i) = merge(hi(i), lo(i), btest(corner, i - 1))
            end do
            dmax = max(dmax, norm2(perpendicular(self%axis, far - self%point)))
         end do
         gmin = -1.0_wp
         gmax = 1.0_wp
         if (dmin > 0.0_wp) then
            gmin = max(-1.0_wp, min(nlo/dmin, nlo/dmax))
            gmax = min(1.0_wp, max(nhi/dmin, nhi/dmax))
         end if
      case (shape_box)
         s = 0.5_wp*(self%lower(k) + self%upper(k))
         gmin = merge(-1.0_wp, 0.0_wp, lo(k) < s)
         gmax = merge(1.0_wp, 0.0_wp, hi(k) > s)
      case (shape_facets)
         gmin = -1.0_wp
         gmax = 1.0_wp
      case default
         gmin = 0.0_wp
         gmax = 0.0_wp
      end select
   end subroutine shape_gradient_range

   !> Range of (x_k - c_k)/|x_J - c_J| over the box, J = {k} and the dims marked in `other`.
   pure subroutine round_gradient_range(c, lo, hi, k, other, gmin, gmax)
      real(wp), intent(in) :: c(:), lo(:), hi(:)
      integer, intent(in) :: k
      logical, intent(in) :: other(:)
      real(wp), intent(out) :: gmin, gmax
      real(wp) :: near2, far2, nearest
      integer :: i

      near2 = 0.0_wp
      far2 = 0.0_wp
      do i = 1, size(other)
         if (.not. other(i)) cycle
         nearest = min(max(c(i), lo(i)), hi(i)) - c(i)
         near2 = near2 + nearest**2
         far2 = far2 + max(abs(lo(i) - c(i)), abs(hi(i) - c(i)))**2
      end do
      if (near2 == 0.0_wp .and. lo(k) <= c(k) .and. c(k) <= hi(k)) then
         gmin = -1.0_wp
         gmax = 1.0_wp
         return
      end if
      gmax = ratio(hi(k) - c(k), near2, far2)
      gmin = -ratio(c(k) - lo(k), near2, far2)
   contains
      !> Largest t/sqrt(t^2 + s^2) at this t over s^2 in [near2, far2].
      pure real(wp) function ratio(t, near2, far2) result(r)
         real(wp), intent(in) :: t, near2, far2
         if (t > 0.0_wp) then
            r = t/sqrt(t*t + near2)
         else if (t < 0.0_wp) then
            r = t/sqrt(t*t + far2)
         else
            r = 0.0_wp
         end if
      end function ratio
   end subroutine round_gradient_range

   !> k-th component of v normal to the unit vector a.
   pure real(wp) function perpendicular_component(a, v, k) result(w)
      real(wp), intent(in) :: a(3), v(3)
      integer, intent(in) :: k
      w = v(k) - dot_product(v, a)*a(k)
   end function perpendicular_component

   ! ------------------------------------------------------------ helpers

   !> a_min/2: makes the ellipsoid's phi the signed distance to first order for a sphere.
   pure real(wp) function ellipsoid_factor(self) result(s)
      type(shape_type), intent(in) :: self
      s = 0.5_wp*minval(self%semi_axes(1:self%dim))
   end function ellipsoid_factor

   !> Component of v normal to the unit vector a.
   pure function perpendicular(a, v) result(w)
      real(wp), intent(in) :: a(3), v(3)
      real(wp) :: w(3)
      w = v - dot_product(v, a)*a
   end function perpendicular

   !> Distance between the line p + t a (a unit) and the box [lo, hi].
   !> dist(p + t a, box)^2 is convex and piecewise quadratic in t, with breaks
   !> where a coordinate crosses lo_i or hi_i. Its minimum is at a break or at
   !> the stationary point of one quadratic piece: all are candidates, and
   !> each candidate's value is the true distance of a point of the line, so
   !> the result is attained.
   pure real(wp) function line_box_distance(p, a, lo, hi) result(dist)
      real(wp), intent(in) :: p(3), a(3), lo(3), hi(3)
      real(wp) :: breaks(0:7), tfirst(3), tlast(3), left, right, alpha, beta, num, den, t
      integer :: nbreak, i, k

      nbreak = 0
      do i = 1, 3
         if (.not. abs(a(i)) > 0.0_wp) cycle
         tfirst(i) = min((lo(i) - p(i))/a(i), (hi(i) - p(i))/a(i))
         tlast(i) = max((lo(i) - p(i))/a(i), (hi(i) - p(i))/a(i))
         breaks(nbreak + 1:nbreak + 2) = [tfirst(i), tlast(i)]
         nbreak = nbreak + 2
      end do
      call sort(breaks(1:nbreak))
      ! sentinels: the first and last pieces are unbounded
      breaks(0) = -huge(1.0_wp)
      breaks(nbreak + 1) = huge(1.0_wp)

      dist = huge(1.0_wp)
      do k = 1, nbreak
         dist = min(dist, gap_length(p + breaks(k)*a, lo, hi))
      end do
      do k = 0, nbreak
         left = breaks(k)
         right = breaks(k + 1)
         ! On (left, right) each coordinate is below, inside or above its slab:
         ! its gap is alpha + beta t (or zero) and the piece is sum (alpha + beta t)^2.
         num = 0.0_wp
         den = 0.0_wp
         do i = 1, 3
            if (.not. abs(a(i)) > 0.0_wp) cycle
            if (right <= tfirst(i)) then
               ! before entering the slab: below lo if a > 0, above hi if a < 0
               if (a(i) > 0.0_wp) then
                  alpha = lo(i) - p(i); beta = -a(i)
               else
                  alpha = p(i) - hi(i); beta = a(i)
               end if
            else if (left >= tlast(i)) then
               if (a(i) > 0.0_wp) then
                  alpha = p(i) - hi(i); beta = a(i)
               else
                  alpha = lo(i) - p(i); beta = -a(i)
               end if
            else
               cycle
            end if
            num = num + alpha*beta
            den = den + beta*beta
         end do
         if (den <= 0.0_wp) cycle
         t = min(max(-num/den, left), right)
         dist = min(dist, gap_length(p + t*a, lo, hi))
      end do
   end function line_box_distance

   !> Distance from the point q to the box [lo, hi].
   pure real(wp) function gap_length(q, lo, hi) result(length)
      real(wp), intent(in) :: q(3), lo(3), hi(3)
      length = norm2(max(lo - q, 0.0_wp, q - hi))
   end function gap_length

   ! ------------------------------------------------------------ validation

   subroutine start(self, kind, dim, name)
      type(shape_type), intent(inout) :: self
      integer, intent(in) :: kind, dim
      character(len=*), intent(in) :: name
      self%kind = kind
      self%dim = dim
      self%name = name
   end subroutine start

   pure function prefix(self) result(text)
      type(shape_type), intent(in) :: self
      character(len=:), allocatable :: text
      text = "shape '"//self%name//"' ("//shape_kind_name(self%kind)//"): "
   end function prefix

   subroutine check_dim_2_or_3(self, field, error)
      type(shape_type), intent(in) :: self
      character(len=*), intent(in) :: field
      type(error_type), allocatable, intent(out) :: error
      if (self%dim == 2 .or. self%dim == 3) return
      call fatal_error(error, prefix(self)//field//' has '//itoa(self%dim)//' values, expected 2 or 3', &
         & stat_invalid_input)
   end subroutine check_dim_2_or_3

   subroutine check_size(self, field, n, error)
      type(shape_type), intent(in) :: self
      character(len=*), intent(in) :: field
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      if (n == self%dim) return
      call fatal_error(error, prefix(self)//field//' has '//itoa(n)//' values, expected '//itoa(self%dim), &
         & stat_invalid_input)
   end subroutine check_size

   subroutine check_finite(self, field, v, error)
      type(shape_type), intent(in) :: self
      character(len=*), intent(in) :: field
      real(wp), intent(in) :: v(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      do i = 1, size(v)
         if (ieee_is_finite(v(i))) cycle
         call fatal_error(error, prefix(self)//field//'('//itoa(i)//') = '//rtoa(v(i), '(g0)')//' is not finite', &
            & stat_invalid_input)
         return
      end do
   end subroutine check_finite

   subroutine check_positive(self, field, v, error)
      type(shape_type), intent(in) :: self
      character(len=*), intent(in) :: field
      real(wp), intent(in) :: v(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      do i = 1, size(v)
         if (ieee_is_finite(v(i))) then
            if (v(i) > 0.0_wp) cycle
         end if
         call fatal_error(error, prefix(self)//field//' = '//rtoa(v(i), '(g0)')//' must be positive and finite', &
            & stat_invalid_input)
         return
      end do
   end subroutine check_positive

   subroutine check_direction(self, field, v, error)
      type(shape_type), intent(in) :: self
      character(len=*), intent(in) :: field
      real(wp), intent(in) :: v(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: length
      call check_finite(self, field, v, error)
      if (allocated(error)) return
      length = norm2(v)
      if (length > tiny(1.0_wp) .and. ieee_is_finite(length)) return
      call fatal_error(error, prefix(self)//field//' = ('//vector_str(v)//') has zero length', stat_invalid_input)
   end subroutine check_direction

   pure function vector_str(v) result(s)
      real(wp), intent(in) :: v(:)
      character(len=:), allocatable :: s
      integer :: i
      s = ''
      do i = 1, size(v)
         if (i > 1) s = s//', '
         s = s//rtoa(v(i), '(g0)')
      end do
   end function vector_str

end module sprc_geometry_shape
