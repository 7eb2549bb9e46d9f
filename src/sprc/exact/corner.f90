!> The singular field at the apex of a traction-free re-entrant corner (a
!> wedge of opening angle 180 < angle <= 360 degrees; 270 is the L-shaped
!> domain, 360 a crack): the first symmetric (mode 1) and antisymmetric
!> (mode 2) eigenfunctions of Williams (1952, J. Appl. Mech. 19), in the
!> normalisation of Szabo & Babuska (Finite Element Analysis, 1991) that
!> Mitchell's adaptivity benchmarks (2013) also use. Zero body force; plane
!> stress or plane strain.
!>
!> Local frame: origin at the apex `point`, x' along `direction` (the
!> bisector of the material wedge), y' the bisector turned 90 degrees
!> counterclockwise; polar angle t from x' in (-pi, pi], so the material is
!> |t| <= beta = alpha/2 and its faces are t = +-beta. The amplitudes
!> A1 = `mode1`, A2 = `mode2` have units of stress times length^(1 - l); for
!> a crack A = K/sqrt(2 pi) (K_I, K_II). The potentials, the stress and
!> displacement formulas, the eigenvalue equations and the ratio Q are written
!> out in doc/theory.md, section 10a ("The corner solution").
!>
!> Both eigenvalues are found by a safeguarded Newton iteration to round-off,
!> each in a bracket where its function is monotone (doc/theory.md); Q is taken
!> from the face equation with the larger denominator, since at the crack one
!> of each pair is 0/0. Near 257.45 degrees l2 is a double root, found to about
!> sqrt(eps); its stress vanishes there with l2 - 1.
!>
!> The displacement has no rigid part beyond the one the formulas carry
!> (u = 0 at the apex). The stress is infinite at the apex: points closer than
!> the smallest normal number are evaluated at that distance, so every finite
!> input gives finite output. Points outside the material wedge get the
!> formulas' analytic continuation (the branch cut is the ray t = pi).
module sprc_exact_corner
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain
   use sprc_exact_solution, only: exact_solution_type, init_exact_solution, check_center, check_field, &
      & is_finite, kolosov_constants
   implicit none
   private

   public :: corner_type, new_corner, corner_eigenvalues

   real(wp), parameter :: pi = acos(-1.0_wp)

   !> Williams' mode 1 and mode 2 eigenfunctions at a traction-free corner.
   type, extends(exact_solution_type) :: corner_type
      !> Apex of the corner.
      real(wp) :: point(2) = 0.0_wp
      !> Unit bisector of the material wedge.
      real(wp) :: direction(2) = [1.0_wp, 0.0_wp]
      !> Opening of the material wedge in degrees, 180 < angle <= 360.
      real(wp) :: angle = 0.0_wp
      !> Amplitudes A1 (symmetric, mode 1) and A2 (antisymmetric, mode 2).
      real(wp) :: amplitude(2) = 0.0_wp
      !> Eigenvalues l1, l2: the stress goes like r^(l - 1).
      real(wp) :: lambda(2) = 0.0_wp
      !> Szabo & Babuska's Q1, Q2 (the psi / phi ratio over l + 1).
      real(wp) :: q(2) = 0.0_wp
   contains
      procedure :: stress => corner_stress
      procedure :: displacement => corner_displacement
   end type corner_type

contains

   !> Create a corner solution; `analysis` is plane_stress or plane_strain.
   !> `direction` need not be unit (it is normalised) but must be nonzero.
   pure subroutine new_corner(self, point, direction, angle, mode1, mode2, young, poisson, analysis, error)
      type(corner_type), intent(out) :: self
      !> Apex, 2 entries.
      real(wp), intent(in) :: point(:)
      !> Bisector of the material wedge, 2 entries, nonzero.
      real(wp), intent(in) :: direction(:)
      !> Opening of the material wedge in degrees, 180 < angle <= 360.
      real(wp), intent(in) :: angle
      !> Amplitudes of the mode 1 and mode 2 fields, finite, not both zero.
      real(wp), intent(in) :: mode1, mode2
      real(wp), intent(in) :: young, poisson
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: context = 'corner'

      call check_center(context, point, 2, error)
      if (allocated(error)) return
      if (size(direction) /= 2) then
         call fatal_error(error, context//': direction must have 2 entries', stat_invalid_input)
         return
      end if
      if (.not. (all(is_finite(direction)) .and. norm2(direction) > 0.0_wp)) then
         call fatal_error(error, context//': direction must be a finite nonzero vector', stat_invalid_input)
         return
      end if
      call check_field(angle > 180.0_wp .and. angle <= 360.0_wp, context, 'angle', &
         & 'must satisfy 180 < angle <= 360 (degrees)', angle, error)
      if (allocated(error)) return
      call check_field(is_finite(mode1), context, 'mode1', 'must be finite', mode1, error)
      if (allocated(error)) return
      call check_field(is_finite(mode2), context, 'mode2', 'must be finite', mode2, error)
      if (allocated(error)) return
      if (mode1 == 0.0_wp .and. mode2 == 0.0_wp) then
         call fatal_error(error, context//': mode1 and mode2 are both zero: the field would vanish', &
            & stat_invalid_input)
         return
      end if
      call init_exact_solution(self, context, analysis, [plane_stress, plane_strain], young, poisson, error)
      if (allocated(error)) return
      self%point = point
      self%direction = direction/norm2(direction)
      self%angle = angle
      self%amplitude = [mode1, mode2]
      call corner_eigenvalues(angle, self%lambda, self%q)
   end subroutine new_corner

   !> Eigenvalues l1, l2 and Szabo & Babuska's Q1, Q2 of a traction-free wedge
   !> of opening `angle` degrees, 180 < angle <= 360 (see the module doc).
   pure subroutine corner_eigenvalues(angle, lambda, q)
      real(wp), intent(in) :: angle
      real(wp), intent(out) :: lambda(2)
      real(wp), intent(out), optional :: q(2)
      real(wp) :: alpha, lmin

      alpha = angle*pi/180.0_wp
      if (angle == 360.0_wp) then
         lambda = 0.5_wp
      else
         lambda(1) = wedge_root(alpha, 1.0_wp, 0.5_wp, pi/alpha)
         ! The minimum of the convex branch of the mode 2 function (l alpha in (pi, 2 pi)).
         lmin = (2.0_wp*pi - acos(max(-1.0_wp, min(1.0_wp, sin(alpha)/alpha))))/alpha
         if (lmin < 1.0_wp) then
            lambda(2) = wedge_root(alpha, -1.0_wp, pi/alpha, lmin)
         else
            lambda(2) = wedge_root(alpha, -1.0_wp, lmin, 2.0_wp*pi/alpha)
         end if
      end if
      if (present(q)) then
         q(1) = ratio_q(lambda(1), 0.5_wp*alpha, 1)
         q(2) = ratio_q(lambda(2), 0.5_wp*alpha, 2)
      end if
   end subroutine corner_eigenvalues

   !> The root of f(l) = sin(l alpha) + s l sin(alpha) between a and b, where
   !> f changes sign once: Newton's iteration kept inside a shrinking bracket,
   !> bisection when a step leaves it, until the step is at round-off.
   pure real(wp) function wedge_root(alpha, s, a, b) result(x)
      real(wp), intent(in) :: alpha, s, a, b
      real(wp) :: lo, hi, f_lo, f, df, step
      integer :: it

      lo = a
      hi = b
      f_lo = sin(lo*alpha) + s*lo*sin(alpha)
      x = lo
      if (f_lo == 0.0_wp) return
      x = 0.5_wp*(lo + hi)
      do it = 1, 200
         f = sin(x*alpha) + s*x*sin(alpha)
         df = alpha*cos(x*alpha) + s*sin(alpha)
         if (f == 0.0_wp) return
         if (sign(1.0_wp, f) == sign(1.0_wp, f_lo)) then
            lo = x
            f_lo = f
         else
            hi = x
         end if
         step = -f/df
         if (.not. (x + step > min(lo, hi) .and. x + step < max(lo, hi))) step = 0.5_wp*(lo + hi) - x
         x = x + step
         if (abs(step) <= 2.0_wp*epsilon(x)*abs(x)) return
      end do
   end function wedge_root

   !> Q of mode k at the eigenvalue l, half-angle beta: of the two real
   !> equations n + Q d = 0 of the free-face condition, the one with the
   !> larger |d| (the other may be 0/0).
   pure real(wp) function ratio_q(l, beta, k) result(q)
      real(wp), intent(in) :: l, beta
      integer, intent(in) :: k
      real(wp) :: n_c, d_c, n_s, d_s

      if (k == 1) then
         n_c = cos((l - 1.0_wp)*beta)
         d_c = cos((l + 1.0_wp)*beta)
         n_s = (l - 1.0_wp)*sin((l - 1.0_wp)*beta)
         d_s = (l + 1.0_wp)*sin((l + 1.0_wp)*beta)
      else
         n_c = (l - 1.0_wp)*cos((l - 1.0_wp)*beta)
         d_c = (l + 1.0_wp)*cos((l + 1.0_wp)*beta)
         n_s = sin((l - 1.0_wp)*beta)
         d_s = sin((l + 1.0_wp)*beta)
      end if
      if (abs(d_c) >= abs(d_s)) then
         q = -n_c/d_c
      else
         q = -n_s/d_s
      end if
   end function ratio_q

   !> Local polar coordinates of x: r (floored at the smallest normal number)
   !> and t in (-pi, pi] from the bisector.
   pure subroutine local_polar(self, x, r, t)
      class(corner_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: r, t
      real(wp) :: d(2), xl, yl

      d = x(1:2) - self%point
      xl = self%direction(1)*d(1) + self%direction(2)*d(2)
      yl = -self%direction(2)*d(1) + self%direction(1)*d(2)
      r = max(hypot(xl, yl), tiny(1.0_wp))
      t = atan2(yl, xl)
   end subroutine local_polar

   !> phi = a z^l and psi = c z^l of mode k: a = A1, c = a Q (l + 1) (mode 1),
   !> a = -i A2 (mode 2).
   pure subroutine potentials(self, k, a, c)
      class(corner_type), intent(in) :: self
      integer, intent(in) :: k
      complex(wp), intent(out) :: a, c

      if (k == 1) then
         a = cmplx(self%amplitude(1), 0.0_wp, wp)
      else
         a = cmplx(0.0_wp, -self%amplitude(2), wp)
      end if
      c = a*self%q(k)*(self%lambda(k) + 1.0_wp)
   end subroutine potentials

   pure subroutine corner_stress(self, x, v)
      class(corner_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, t, l, sum_, s_local(3)
      complex(wp) :: a, c, z1, z3, diff, e2
      integer :: k

      call local_polar(self, x, r, t)
      sum_ = 0.0_wp
      diff = (0.0_wp, 0.0_wp)
      ! e^(-2it), so that one power and one sine/cosine pair serve both terms
      e2 = cmplx(cos(2.0_wp*t), -sin(2.0_wp*t), wp)
      do k = 1, 2
         if (self%amplitude(k) == 0.0_wp) cycle
         call potentials(self, k, a, c)
         l = self%lambda(k)
         ! z^(l-1) and conj(z) z^(l-2) = r^(l-1) e^(i(l-3)t).
         z1 = r**(l - 1.0_wp)*cmplx(cos((l - 1.0_wp)*t), sin((l - 1.0_wp)*t), wp)
         z3 = z1*e2
         sum_ = sum_ + 4.0_wp*real(a*l*z1, wp)
         diff = diff + 2.0_wp*(a*l*(l - 1.0_wp)*z3 + c*l*z1)
      end do
      s_local = [0.5_wp*(sum_ - real(diff, wp)), 0.5_wp*(sum_ + real(diff, wp)), 0.5_wp*aimag(diff)]
      call rotate_stress(self%direction, s_local, v)
   end subroutine corner_stress

   pure subroutine corner_displacement(self, x, v)
      class(corner_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: r, t, l, kappa, mu, rl
      complex(wp) :: a, c, w
      integer :: k

      call local_polar(self, x, r, t)
      call kolosov_constants(self, mu, kappa)
      w = (0.0_wp, 0.0_wp)
      do k = 1, 2
         if (self%amplitude(k) == 0.0_wp) cycle
         call potentials(self, k, a, c)
         l = self%lambda(k)
         rl = r**l
         ! kappa phi - z conj(phi') - conj(psi).
         w = w + rl*(kappa*a*cmplx(cos(l*t), sin(l*t), wp) &
            & - conjg(a)*l*cmplx(cos((2.0_wp - l)*t), sin((2.0_wp - l)*t), wp) &
            & - conjg(c)*cmplx(cos(l*t), -sin(l*t), wp))
      end do
      w = w/(2.0_wp*mu)
      v(1) = self%direction(1)*real(w, wp) - self%direction(2)*aimag(w)
      v(2) = self%direction(2)*real(w, wp) + self%direction(1)*aimag(w)
   end subroutine corner_displacement

   !> Voigt stress from the local frame (x' along e) to the global one.
   pure subroutine rotate_stress(e, s, v)
      real(wp), intent(in) :: e(2), s(3)
      real(wp), intent(out) :: v(:)
      real(wp) :: c, sn

      c = e(1)
      sn = e(2)
      v(1) = c*c*s(1) + sn*sn*s(2) - 2.0_wp*c*sn*s(3)
      v(2) = sn*sn*s(1) + c*c*s(2) + 2.0_wp*c*sn*s(3)
      v(3) = c*sn*(s(1) - s(2)) + (c*c - sn*sn)*s(3)
   end subroutine rotate_stress

end module sprc_exact_corner
