!> Kirsch's infinite plate with a circular hole under remote uniaxial tension
!> (Kirsch 1898, VDI Zeitschrift 42; Szabo & Babuska, Finite Element
!> Analysis, 1991; the "infinite plate with a hole" benchmark of XFEM papers,
!> e.g. Sukumar et al. 2001). Zero body force, plane stress or plane strain.
!>
!> Hole of radius a at the center, remote stress sigma_xx = S (s_inf) along x.
!> With (r, t) polar coordinates about the center, t measured from the x axis:
!>
!>   sigma_xx = S (1 - (a/r)^2 (3/2 cos 2t + cos 4t) + 3/2 (a/r)^4 cos 4t)
!>   sigma_yy = S (  - (a/r)^2 (1/2 cos 2t - cos 4t) - 3/2 (a/r)^4 cos 4t)
!>   sigma_xy = S (  - (a/r)^2 (1/2 sin 2t + sin 4t) + 3/2 (a/r)^4 sin 4t)
!>
!>   u_x = S a/(8 mu) (r/a (kappa + 1) cos t + 2 a/r ((1 + kappa) cos t + cos 3t) - 2 (a/r)^3 cos 3t)
!>   u_y = S a/(8 mu) (r/a (kappa - 3) sin t + 2 a/r ((1 - kappa) sin t + sin 3t) - 2 (a/r)^3 sin 3t)
!>
!> with mu = E/(2(1 + nu)), kappa = (3 - nu)/(1 + nu) (plane stress) or
!> 3 - 4 nu (plane strain). On the hole sigma_tt = S (1 - 2 cos 2t): 3S at
!> t = 90 deg, -S at t = 0; the hole is traction-free and the stress tends to
!> (S, 0, 0) like (a/r)^2. Plane strain has sigma_zz = nu (sigma_xx + sigma_yy),
!> not part of the 2D Voigt vector.
!>
!> Rigid-body normalisation: u has no rigid part; u_x is odd in x - x_c and
!> even in y - y_c, u_y the reverse, so u_y = 0 on y = y_c and u_x = 0 on
!> x = x_c (the symmetry planes of a quarter model). Far away u tends to the
!> uniform-strain field of the plate without hole, centered at the hole.
!>
!> Points with r < 1e-6 a (`radius_floor`) are evaluated at r = 1e-6 a; points
!> in the hole are outside the body and get the formulas' analytic
!> continuation. No NaN or Inf comes out for finite input.
module sprc_exact_kirsch
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_material, only: plane_stress, plane_strain
   use sprc_exact_solution, only: exact_solution_type, init_exact_solution, check_center, check_field, &
      & is_finite, radial_frame, radius_floor, kolosov_constants
   implicit none
   private

   public :: kirsch_type, new_kirsch

   !> Infinite plate with a circular hole under remote uniaxial stress along x.
   type, extends(exact_solution_type) :: kirsch_type
      !> Center of the hole.
      real(wp) :: center(2) = 0.0_wp
      !> Radius of the hole, a > 0.
      real(wp) :: radius = 0.0_wp
      !> Remote stress sigma_xx (positive in tension).
      real(wp) :: s_inf = 0.0_wp
   contains
      procedure :: stress => kirsch_stress
      procedure :: displacement => kirsch_displacement
   end type kirsch_type

contains

   !> Create a Kirsch solution; `analysis` is plane_stress or plane_strain.
   pure subroutine new_kirsch(self, center, radius, s_inf, young, poisson, analysis, error)
      type(kirsch_type), intent(out) :: self
      !> Center of the hole, 2 entries.
      real(wp), intent(in) :: center(:)
      real(wp), intent(in) :: radius, s_inf, young, poisson
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: context = 'kirsch'

      call check_center(context, center, 2, error)
      if (allocated(error)) return
      call check_field(radius > 0.0_wp .and. is_finite(radius), context, 'radius', 'must be finite and > 0', &
         & radius, error)
      if (allocated(error)) return
      call check_field(is_finite(s_inf), context, 's_inf', 'must be finite', s_inf, error)
      if (allocated(error)) return
      call init_exact_solution(self, context, analysis, [plane_stress, plane_strain], young, poisson, error)
      if (allocated(error)) return
      self%center = center
      self%radius = radius
      self%s_inf = s_inf
   end subroutine new_kirsch

   pure subroutine kirsch_stress(self, x, v)
      class(kirsch_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, e(2), q2, q4, c2, s2, c4, s4

      call radial_frame(x(1:2) - self%center, radius_floor*self%radius, r, e)
      q2 = (self%radius/r)**2
      q4 = q2**2
      c2 = e(1)**2 - e(2)**2
      s2 = 2.0_wp*e(1)*e(2)
      c4 = c2**2 - s2**2
      s4 = 2.0_wp*s2*c2
      v(1) = self%s_inf*(1.0_wp - q2*(1.5_wp*c2 + c4) + 1.5_wp*q4*c4)
      v(2) = self%s_inf*(-q2*(0.5_wp*c2 - c4) - 1.5_wp*q4*c4)
      v(3) = self%s_inf*(-q2*(0.5_wp*s2 + s4) + 1.5_wp*q4*s4)
   end subroutine kirsch_stress

   pure subroutine kirsch_displacement(self, x, v)
      class(kirsch_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, e(2), q, kappa, mu, c1, s1, c3, s3, f

      call radial_frame(x(1:2) - self%center, radius_floor*self%radius, r, e)
      q = self%radius/r
      call kolosov_constants(self, mu, kappa)
      c1 = e(1)
      s1 = e(2)
      c3 = c1*(4.0_wp*c1**2 - 3.0_wp)
      s3 = s1*(3.0_wp - 4.0_wp*s1**2)
      f = self%s_inf*self%radius/(8.0_wp*mu)
      v(1) = f*((kappa + 1.0_wp)*c1/q + 2.0_wp*q*((1.0_wp + kappa)*c1 + c3) - 2.0_wp*q**3*c3)
      v(2) = f*((kappa - 3.0_wp)*s1/q + 2.0_wp*q*((1.0_wp - kappa)*s1 + s3) - 2.0_wp*q**3*s3)
   end subroutine kirsch_displacement

end module sprc_exact_kirsch
