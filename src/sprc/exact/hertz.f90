!> Hertz contact pressure between two elastic bodies with smooth, convex
!> (or one flat) surfaces: line contact (2D, `hertz_cylinder`) and point
!> contact (3D, `hertz_sphere`). Johnson, Contact Mechanics, 1985, ch. 4
!> (eqs. 4.45 and 4.22-4.23). Frictionless, small strains, a << R.
!>
!> Line contact (force P per unit thickness, relative radius R with
!> 1/R = 1/R_1 + 1/R_2, R_2 = infinity for a flat block):
!>   a = sqrt(4 P R/(pi E*)),  p0 = 2 P/(pi a),  p(s) = p0 sqrt(1 - s^2/a^2),
!>   1/E* = 1/E'_1 + 1/E'_2,  E' = E/(1 - nu^2) (plane strain), E' = E (plane stress).
!> Point contact (force F):
!>   a = (3 F R/(4 E*))^(1/3),  p0 = 3 F/(2 pi a^2),  p(r) = p0 sqrt(1 - r^2/a^2),
!>   1/E* = (1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2.
!>
!> s (r) is the distance of x from the line (2D: point) through `point` along
!> `normal`, i.e. the length of (x - point) projected on the contact plane;
!> p = 0 for s >= a. `load` is the force of the whole contact: a symmetric
!> half model carries P/2 and a quarter model F/4 (doc/scene.md). Pressure only:
!> no stress or displacement field, so the energy-norm columns stay empty.
module sprc_exact_hertz
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, analysis_name, check_material
   use sprc_exact_solution, only: check_field, is_finite
   use sprc_exact_pressure, only: exact_pressure_type
   implicit none
   private

   public :: hertz_type, new_hertz_cylinder, new_hertz_sphere, cattaneo_mindlin_traction

   real(wp), parameter :: pi = acos(-1.0_wp)

   !> Hertz pressure distribution, line (dim 2) or point (dim 3) contact.
   type, extends(exact_pressure_type) :: hertz_type
      !> First point of contact, size dim.
      real(wp) :: point(3) = 0.0_wp
      !> Unit normal of the contact plane, size dim.
      real(wp) :: normal(3) = 0.0_wp
      !> Relative radius R and contact force (P per unit thickness, or F).
      real(wp) :: radius = 0.0_wp, load = 0.0_wp
      !> Contact modulus E*.
      real(wp) :: e_star = 0.0_wp
      !> Half-width (2D) or radius (3D) a of the contact, and peak pressure p0.
      real(wp) :: half_width = 0.0_wp, p0 = 0.0_wp
   contains
      procedure :: pressure => hertz_pressure
   end type hertz_type

contains

   !> Hertz line contact of two cylinders (or a cylinder on a block) in plane
   !> stress or plane strain; (young_k, poisson_k) are the two bodies' materials.
   pure subroutine new_hertz_cylinder(self, point, normal, radius, load, young_1, poisson_1, young_2, poisson_2, &
      & analysis, error)
      type(hertz_type), intent(out) :: self
      real(wp), intent(in) :: point(:), normal(:)
      real(wp), intent(in) :: radius, load, young_1, poisson_1, young_2, poisson_2
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: context = 'hertz_cylinder'

      if (analysis /= plane_stress .and. analysis /= plane_strain) then
         call fatal_error(error, context//': analysis '//analysis_name(analysis)// &
            & ' is not supported; expected one of: plane_stress plane_strain', stat_invalid_input)
         return
      end if
      call check_contact(self, context, 2, point, normal, radius, load, young_1, poisson_1, young_2, poisson_2, error)
      if (allocated(error)) return
      if (analysis == plane_strain) then
         self%e_star = 1.0_wp/((1.0_wp - poisson_1**2)/young_1 + (1.0_wp - poisson_2**2)/young_2)
      else
         self%e_star = 1.0_wp/(1.0_wp/young_1 + 1.0_wp/young_2)
      end if
      self%half_width = sqrt(4.0_wp*load*radius/(pi*self%e_star))
      self%p0 = 2.0_wp*load/(pi*self%half_width)
   end subroutine new_hertz_cylinder

   !> Hertz point contact of two spheres (or a sphere on a block), 3D.
   pure subroutine new_hertz_sphere(self, point, normal, radius, load, young_1, poisson_1, young_2, poisson_2, error)
      type(hertz_type), intent(out) :: self
      real(wp), intent(in) :: point(:), normal(:)
      real(wp), intent(in) :: radius, load, young_1, poisson_1, young_2, poisson_2
      type(error_type), allocatable, intent(out) :: error

      call check_contact(self, 'hertz_sphere', 3, point, normal, radius, load, young_1, poisson_1, young_2, &
         & poisson_2, error)
      if (allocated(error)) return
      self%e_star = 1.0_wp/((1.0_wp - poisson_1**2)/young_1 + (1.0_wp - poisson_2**2)/young_2)
      self%half_width = (3.0_wp*load*radius/(4.0_wp*self%e_star))**(1.0_wp/3.0_wp)
      self%p0 = 3.0_wp*load/(2.0_wp*pi*self%half_width**2)
   end subroutine new_hertz_sphere

   !> Check and store the fields shared by both kinds; the normal is normalized.
   pure subroutine check_contact(self, context, dim, point, normal, radius, load, young_1, poisson_1, young_2, &
      & poisson_2, error)
      type(hertz_type), intent(inout) :: self
      character(len=*), intent(in) :: context
      integer, intent(in) :: dim
      real(wp), intent(in) :: point(:), normal(:)
      real(wp), intent(in) :: radius, load, young_1, poisson_1, young_2, poisson_2
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: length
      character(len=1) :: d

      write (d, '(i1)') dim
      if (size(point) /= dim .or. .not. all(is_finite(point))) then
         call fatal_error(error, context//': point must have '//d//' finite entries', stat_invalid_input)
         return
      end if
      length = 0.0_wp
      if (size(normal) == dim) length = norm2(normal)
      if (.not. (length > 0.0_wp .and. length <= huge(length))) then
         call fatal_error(error, context//': normal must have '//d//' finite entries, not all zero', stat_invalid_input)
         return
      end if
      call check_field(radius > 0.0_wp .and. is_finite(radius), context, 'radius', 'must be finite and > 0', &
         & radius, error)
      if (allocated(error)) return
      call check_field(load > 0.0_wp .and. is_finite(load), context, 'load', 'must be finite and > 0', load, error)
      if (allocated(error)) return
      call check_material(young_1, poisson_1, context//' body 1', error)
      if (allocated(error)) return
      call check_material(young_2, poisson_2, context//' body 2', error)
      if (allocated(error)) return
      self%dim = dim
      self%point(1:dim) = point
      self%normal(1:dim) = normal/length
      self%radius = radius
      self%load = load
   end subroutine check_contact

   !> p0 sqrt(1 - s^2/a^2) with s the distance from the contact axis; the
   !> slave normal n is not needed (the distribution is given on the plane).
   pure real(wp) function hertz_pressure(self, x, n)
      class(hertz_type), intent(in) :: self
      real(wp), intent(in) :: x(:), n(:)
      real(wp) :: d(3), ratio

      associate (unused => n); end associate
      associate (m => self%dim)
         d(1:m) = x(1:m) - self%point(1:m)
         d(1:m) = d(1:m) - dot_product(d(1:m), self%normal(1:m))*self%normal(1:m)
         ratio = dot_product(d(1:m), d(1:m))/self%half_width**2
      end associate
      hertz_pressure = self%p0*sqrt(max(0.0_wp, 1.0_wp - ratio))
   end function hertz_pressure

   !> Cattaneo-Mindlin (Johnson 1985, sec. 7.1): the tangential traction of a Hertz
   !> line contact (half-width a, peak pressure p0) under a tangential load Q < mu P
   !> at distance s from the contact axis: mu p0 [sqrt(1 - s^2/a^2) - (c/a) sqrt(1 -
   !> s^2/c^2)], the second term only in the stick zone |s| < c, c = a sqrt(1 - Q/(mu P));
   !> 0 outside the contact zone.
   elemental real(wp) function cattaneo_mindlin_traction(s, a, c, mu, p0) result(q)
      real(wp), intent(in) :: s, a, c, mu, p0

      q = mu*p0*sqrt(max(0.0_wp, 1.0_wp - (s/a)**2))
      if (abs(s) < c) q = q - mu*p0*(c/a)*sqrt(max(0.0_wp, 1.0_wp - (s/c)**2))
   end function cattaneo_mindlin_traction

end module sprc_exact_hertz
