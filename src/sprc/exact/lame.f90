!> Lame's thick-walled cylinder and sphere under inner and outer pressure
!> (Lame 1852; e.g. Timoshenko & Goodier, Theory of Elasticity, 3rd ed., 1970,
!> thick-walled cylinder and hollow sphere). Zero body force.
!>
!> With a = r_in, b = r_out and the boundary conditions sigma_rr(a) = -p_in,
!> sigma_rr(b) = -p_out (positive pressure pushes on the wall):
!>
!> Cylinder (2D, plane stress or plane strain), q = (a/b)^2:
!>   sigma_rr = A - B/r^2,  sigma_tt = A + B/r^2,  sigma_rt = 0,
!>   A = (p_in q - p_out)/(1 - q),  B = (p_in - p_out) a^2/(1 - q),
!>   u_r = r/E ((1 - nu) A + (1 + nu) B/r^2)         plane stress,
!>   u_r = (1 + nu) r/E ((1 - 2 nu) A + B/r^2)       plane strain
!>   (from u_r = r eps_tt with the plane stress / plane strain compliance;
!>   plane strain has sigma_zz = 2 nu A, not part of the 2D Voigt vector).
!>
!> Sphere (3D), q = (a/b)^3:
!>   sigma_rr = A - 2B/r^3,  sigma_tt = sigma_pp = A + B/r^3,
!>   A = (p_in q - p_out)/(1 - q),  B = (p_in - p_out) a^3/(2 (1 - q)),
!>   u_r = r/E ((1 - 2 nu) A + (1 + nu) B/r^3).
!>
!> Cartesian components: sigma = sigma_tt I + (sigma_rr - sigma_tt) e_r e_r^T
!> (in the plane for the cylinder), u = u_r e_r. The displacement has no rigid
!> part: it is symmetric about every plane through the center.
!>
!> Points with r < 1e-6 r_in (`radius_floor`) are evaluated at r = 1e-6 r_in;
!> points inside r_in are outside the body and get the formulas' analytic
!> continuation. No NaN or Inf comes out for finite input.
module sprc_exact_lame
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_material, only: plane_stress, plane_strain, solid
   use sprc_exact_solution, only: exact_solution_type, init_exact_solution, check_center, check_field, &
      & is_finite, radial_frame, radius_floor
   implicit none
   private

   public :: lame_cylinder_type, lame_sphere_type, new_lame_cylinder, new_lame_sphere

   !> Thick cylinder in plane stress or plane strain.
   type, extends(exact_solution_type) :: lame_cylinder_type
      !> Center of the cross-section.
      real(wp) :: center(2) = 0.0_wp
      !> Inner and outer radius, 0 < r_in < r_out.
      real(wp) :: r_in = 0.0_wp, r_out = 0.0_wp
      !> Inner and outer pressure (positive pushes on the wall).
      real(wp) :: p_in = 0.0_wp, p_out = 0.0_wp
   contains
      procedure :: stress => cylinder_stress
      procedure :: displacement => cylinder_displacement
   end type lame_cylinder_type

   !> Thick hollow sphere.
   type, extends(exact_solution_type) :: lame_sphere_type
      !> Center.
      real(wp) :: center(3) = 0.0_wp
      !> Inner and outer radius, 0 < r_in < r_out.
      real(wp) :: r_in = 0.0_wp, r_out = 0.0_wp
      !> Inner and outer pressure (positive pushes on the wall).
      real(wp) :: p_in = 0.0_wp, p_out = 0.0_wp
   contains
      procedure :: stress => sphere_stress
      procedure :: displacement => sphere_displacement
   end type lame_sphere_type

contains

   !> Create a Lame cylinder; `analysis` is plane_stress or plane_strain.
   pure subroutine new_lame_cylinder(self, center, r_in, r_out, p_in, p_out, young, poisson, analysis, error)
      type(lame_cylinder_type), intent(out) :: self
      !> Center, 2 entries.
      real(wp), intent(in) :: center(:)
      real(wp), intent(in) :: r_in, r_out, p_in, p_out, young, poisson
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: context = 'lame_cylinder'

      call check_shell(context, center, 2, r_in, r_out, p_in, p_out, error)
      if (allocated(error)) return
      call init_exact_solution(self, context, analysis, [plane_stress, plane_strain], young, poisson, error)
      if (allocated(error)) return
      self%center = center
      self%r_in = r_in
      self%r_out = r_out
      self%p_in = p_in
      self%p_out = p_out
   end subroutine new_lame_cylinder

   !> Create a Lame sphere (3D, analysis solid).
   pure subroutine new_lame_sphere(self, center, r_in, r_out, p_in, p_out, young, poisson, error)
      type(lame_sphere_type), intent(out) :: self
      !> Center, 3 entries.
      real(wp), intent(in) :: center(:)
      real(wp), intent(in) :: r_in, r_out, p_in, p_out, young, poisson
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: context = 'lame_sphere'

      call check_shell(context, center, 3, r_in, r_out, p_in, p_out, error)
      if (allocated(error)) return
      call init_exact_solution(self, context, solid, [solid], young, poisson, error)
      if (allocated(error)) return
      self%center = center
      self%r_in = r_in
      self%r_out = r_out
      self%p_in = p_in
      self%p_out = p_out
   end subroutine new_lame_sphere

   pure subroutine check_shell(context, center, dim, r_in, r_out, p_in, p_out, error)
      character(len=*), intent(in) :: context
      real(wp), intent(in) :: center(:)
      integer, intent(in) :: dim
      real(wp), intent(in) :: r_in, r_out, p_in, p_out
      type(error_type), allocatable, intent(out) :: error

      call check_center(context, center, dim, error)
      if (allocated(error)) return
      call check_field(r_in > 0.0_wp .and. is_finite(r_in), context, 'r_in', 'must be finite and > 0', r_in, error)
      if (allocated(error)) return
      call check_field(r_out > r_in .and. is_finite(r_out), context, 'r_out', 'must be finite and > r_in', r_out, error)
      if (allocated(error)) return
      call check_field(is_finite(p_in), context, 'p_in', 'must be finite', p_in, error)
      if (allocated(error)) return
      call check_field(is_finite(p_out), context, 'p_out', 'must be finite', p_out, error)
   end subroutine check_shell

   !> Radial and hoop stress of the cylinder at the (floored) radius r.
   pure subroutine cylinder_polar(self, r, a_coef, b_term)
      class(lame_cylinder_type), intent(in) :: self
      real(wp), intent(in) :: r
      !> A and B/r^2.
      real(wp), intent(out) :: a_coef, b_term
      real(wp) :: q

      q = (self%r_in/self%r_out)**2
      a_coef = (self%p_in*q - self%p_out)/(1.0_wp - q)
      b_term = (self%p_in - self%p_out)/(1.0_wp - q)*(self%r_in/r)**2
   end subroutine cylinder_polar

   pure subroutine cylinder_stress(self, x, v)
      class(lame_cylinder_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, e(2), a_coef, b_term, s_rr, s_tt

      call radial_frame(x(1:2) - self%center, radius_floor*self%r_in, r, e)
      call cylinder_polar(self, r, a_coef, b_term)
      s_rr = a_coef - b_term
      s_tt = a_coef + b_term
      v(1) = s_tt + (s_rr - s_tt)*e(1)**2
      v(2) = s_tt + (s_rr - s_tt)*e(2)**2
      v(3) = (s_rr - s_tt)*e(1)*e(2)
   end subroutine cylinder_stress

   pure subroutine cylinder_displacement(self, x, v)
      class(lame_cylinder_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, e(2), a_coef, b_term, u_r, nu

      call radial_frame(x(1:2) - self%center, radius_floor*self%r_in, r, e)
      call cylinder_polar(self, r, a_coef, b_term)
      nu = self%poisson
      if (self%analysis == plane_stress) then
         u_r = r/self%young*((1.0_wp - nu)*a_coef + (1.0_wp + nu)*b_term)
      else
         u_r = (1.0_wp + nu)*r/self%young*((1.0_wp - 2.0_wp*nu)*a_coef + b_term)
      end if
      v(1:2) = u_r*e
   end subroutine cylinder_displacement

   !> A and B/r^3 of the sphere at the (floored) radius r.
   pure subroutine sphere_polar(self, r, a_coef, b_term)
      class(lame_sphere_type), intent(in) :: self
      real(wp), intent(in) :: r
      real(wp), intent(out) :: a_coef, b_term
      real(wp) :: q

      q = (self%r_in/self%r_out)**3
      a_coef = (self%p_in*q - self%p_out)/(1.0_wp - q)
      b_term = 0.5_wp*(self%p_in - self%p_out)/(1.0_wp - q)*(self%r_in/r)**3
   end subroutine sphere_polar

   pure subroutine sphere_stress(self, x, v)
      class(lame_sphere_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, e(3), a_coef, b_term, s_rr, s_tt

      call radial_frame(x(1:3) - self%center, radius_floor*self%r_in, r, e)
      call sphere_polar(self, r, a_coef, b_term)
      s_rr = a_coef - 2.0_wp*b_term
      s_tt = a_coef + b_term
      v(1:3) = s_tt + (s_rr - s_tt)*e**2
      v(4) = (s_rr - s_tt)*e(1)*e(2)
      v(5) = (s_rr - s_tt)*e(2)*e(3)
      v(6) = (s_rr - s_tt)*e(1)*e(3)
   end subroutine sphere_stress

   pure subroutine sphere_displacement(self, x, v)
      class(lame_sphere_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, e(3), a_coef, b_term, u_r

      call radial_frame(x(1:3) - self%center, radius_floor*self%r_in, r, e)
      call sphere_polar(self, r, a_coef, b_term)
      u_r = r/self%young*((1.0_wp - 2.0_wp*self%poisson)*a_coef + (1.0_wp + self%poisson)*b_term)
      v(1:3) = u_r*e
   end subroutine sphere_displacement

end module sprc_exact_lame
