!> Tests of the corner (Williams) solution, against what defines it and
!> independently of its formulas: the eigenvalues and Q against published
!> digits and their characteristic equations, equilibrium and the
!> strain-displacement-stress relation by central differences, free faces,
!> the symmetry of mode 1 and antisymmetry of mode 2 about the bisector, the
!> textbook K_I / K_II crack-tip fields, and the plane stress / plane strain
!> correspondence.
module sprc_test_exact_corner
   use sprc_core_kinds, only: wp, i8
   use sprc_core_material, only: plane_stress, plane_strain, solid, analysis_name
   use sprc_exact_corner, only: corner_type, new_corner, corner_eigenvalues
   use sprc_test_exact, only: check_equilibrium_fd, check_compatibility_fd, expect_error, uniform
   use sprc_testsuite, only: unittest_type, new_unittest, check, error_type
   implicit none
   private

   public :: collect_exact_corner

   real(wp), parameter :: pi = acos(-1.0_wp)
   real(wp), parameter :: young = 2.1e5_wp, poisson = 0.3_wp
   !> Round-off tier of quantities that pass through a handful of
   !> trigonometric evaluations and a few products: 64 eps.
   real(wp), parameter :: thr = 64.0_wp*epsilon(1.0_wp)
   integer, parameter :: npoint = 20, ncase = 5

contains

   subroutine collect_exact_corner(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('eigenvalues_reference', test_eigenvalues_reference), &
         new_unittest('eigenvalues_smallest_root', test_smallest_root), &
         new_unittest('equilibrium_fd', test_equilibrium), &
         new_unittest('strain_displacement_stress_fd', test_compatibility), &
         new_unittest('free_faces', test_free_faces), &
         new_unittest('mode_symmetry', test_mode_symmetry), &
         new_unittest('crack_k_fields', test_crack_k_fields), &
         new_unittest('plane_stress_strain', test_plane_stress_strain), &
         new_unittest('constructor_errors', test_constructor_errors), &
         new_unittest('no_nan_at_apex', test_no_nan) &
         ]
   end subroutine collect_exact_corner

   !> L-shape (270 deg): l1, l2 to 13 digits (Szabo & Babuska; Mitchell's
   !> benchmark gives l1 = 0.5444837367825, l2 = 0.9085291898461 with
   !> Q1 = 0.5430755788367, Q2 = -0.2189232362488). Longer reference digits of
   !> the roots (0.544483736782463929, 0.908529189846098819, from the
   !> biharmonic singularity of deal.II's tests) allow a round-off check:
   !> |f'| >= 1 at both roots, so an error of 64 eps in f is 64 eps in l.
   !> Crack (360 deg): l1 = l2 = 1/2 exactly, Q1 = 1/3, Q2 = -1 (the K fields).
   subroutine test_eigenvalues_reference(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: lambda(2), q(2)

      call corner_eigenvalues(270.0_wp, lambda, q)
      call check(error, lambda(1), 0.544483736782463929_wp, thr, 'L-shape lambda_1')
      if (allocated(error)) return
      call check(error, lambda(2), 0.908529189846098819_wp, thr, 'L-shape lambda_2')
      if (allocated(error)) return
      ! Q from 13 published digits: half a unit of the last digit.
      call check(error, q(1), 0.5430755788367_wp, 5.0e-14_wp, 'L-shape Q1')
      if (allocated(error)) return
      call check(error, q(2), -0.2189232362488_wp, 5.0e-14_wp, 'L-shape Q2')
      if (allocated(error)) return
      call corner_eigenvalues(360.0_wp, lambda, q)
      call check(error, all(lambda == 0.5_wp), 'crack lambda_1 = lambda_2 = 1/2 exactly')
      if (allocated(error)) return
      call check(error, q(1), 1.0_wp/3.0_wp, thr, 'crack Q1 = 1/3')
      if (allocated(error)) return
      call check(error, q(2), -1.0_wp, thr, 'crack Q2 = -1')
   end subroutine test_eigenvalues_reference

   !> At angles across (180, 360], including both sides of 257.45 deg where
   !> l2 crosses 1: each l solves its equation (sin(l a) + l sin a = 0 for
   !> mode 1, - for mode 2) to round-off, and g(l) = f(l)/(l (l - 1)) (which
   !> removes the trivial roots 0 and, for mode 2, 1: a rigid rotation) has no
   !> sign change on a grid of 999 points in (0, l): l is the smallest root.
   subroutine test_smallest_root(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: angles(8) = [180.5_wp, 200.0_wp, 225.0_wp, 250.0_wp, 265.0_wp, 270.0_wp, &
         & 315.0_wp, 359.5_wp]
      real(wp) :: lambda(2), alpha, s, x, g, g0
      integer :: ia, k, i
      character(len=40) :: label

      do ia = 1, size(angles)
         call corner_eigenvalues(angles(ia), lambda)
         alpha = angles(ia)*pi/180.0_wp
         write (label, '("angle ",f6.1,", mode ",i0)') angles(ia)
         do k = 1, 2
            s = merge(1.0_wp, -1.0_wp, k == 1)
            call check(error, sin(lambda(k)*alpha) + s*lambda(k)*sin(alpha), 0.0_wp, thr, &
               & 'characteristic equation, '//trim(label))
            if (allocated(error)) return
            call check(error, lambda(k) > 0.0_wp .and. abs(lambda(k) - 1.0_wp) > 1.0e-3_wp, &
               & 'a nontrivial root, '//trim(label))
            if (allocated(error)) return
            g0 = 0.0_wp
            do i = 1, 999
               x = lambda(k)*(i - 0.5_wp)/999.0_wp
               g = (sin(x*alpha) + s*x*sin(alpha))/(x*(x - 1.0_wp))
               call check(error, g*g0 >= 0.0_wp, 'no smaller root, '//trim(label))
               if (allocated(error)) return
               g0 = g
            end do
         end do
      end do
   end subroutine test_smallest_root

   !> div sigma = 0 by central differences (the shared helper: step h = 1e-4 L,
   !> tolerance 1e-5 s/L, L = 1, s = |A1| + |A2|). The points lie at
   !> 1 <= r <= 3 from the apex, where the third derivatives of r^(l - 1)
   !> times the angular factors stay below ~100 A: truncation h^2/6 * 100 A
   !> ~ 2e-7 A, round-off eps A/h ~ 1e-12 A. Any pair of analytic potentials
   !> is in equilibrium and compatible, so these two tests catch errors in
   !> writing the fields out (an exponent, a factor, kappa, the rotation), not
   !> in l or Q: the free faces catch those.
   subroutine test_equilibrium(error)
      type(error_type), allocatable, intent(out) :: error
      call fd_cases(error, .true.)
   end subroutine test_equilibrium

   !> Strain of the displacement by central differences equals the
   !> compliance times the stress (same step and bounds, in units of s/E). A
   !> wrong kappa or shear modulus leaves O(nu s/E).
   subroutine test_compatibility(error)
      type(error_type), allocatable, intent(out) :: error
      call fd_cases(error, .false.)
   end subroutine test_compatibility

   subroutine fd_cases(error, equilibrium)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: equilibrium
      type(corner_type) :: c
      real(wp), allocatable :: points(:, :)
      character(len=:), allocatable :: label
      integer :: ic

      do ic = 1, ncase
         call make_case(ic, c, points, label, error)
         if (allocated(error)) return
         if (equilibrium) then
            call check_equilibrium_fd(error, c, points, 1.0_wp, sum(abs(c%amplitude)), label)
         else
            call check_compatibility_fd(error, c, points, 1.0_wp, sum(abs(c%amplitude)), label)
         end if
         if (allocated(error)) return
      end do
   end subroutine fd_cases

   !> sigma n = 0 on both faces t = +-beta, at 0.01 <= r <= 10: round-off
   !> relative to the stress there, |A| l r^(l-1) times factors below 8.
   subroutine test_free_faces(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_type) :: c
      real(wp), allocatable :: points(:, :)
      character(len=:), allocatable :: label
      real(wp) :: beta, r, t(2), n(2), x(2), e(2), f(2), face, scale
      integer :: ic, ip, side
      integer(i8) :: seed

      seed = 4242_i8
      do ic = 1, ncase
         call make_case(ic, c, points, label, error)
         if (allocated(error)) return
         beta = 0.5_wp*c%angle*pi/180.0_wp
         e = c%direction
         f = [-e(2), e(1)]
         do ip = 1, npoint
            r = 10.0_wp**(3.0_wp*uniform(seed) - 2.0_wp)
            do side = -1, 1, 2
               face = side*beta
               x = c%point + r*(cos(face)*e + sin(face)*f)
               ! Outward normal: side * e_theta(face).
               n = side*(-sin(face)*e + cos(face)*f)
               call c%traction(x, n, t)
               scale = 8.0_wp*sum(abs(c%amplitude)*r**(c%lambda - 1.0_wp))
               call check(error, maxval(abs(t)), 0.0_wp, thr*scale, 'free face, '//label)
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_free_faces

   !> With the mirror M about the bisector: mode 1 alone has u(Mx) = M u(x),
   !> sigma(Mx) = M sigma(x) M; mode 2 alone the negatives. Round-off
   !> relative to the field sizes at r <= 3.
   subroutine test_mode_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_type) :: c, m
      real(wp), allocatable :: points(:, :)
      character(len=:), allocatable :: label
      real(wp) :: mir(2, 2), x(2), xm(2), u(2), um(2), s(3), sm(3), st(2, 2), smt(2, 2), sgn, tol_u, tol_s
      integer :: ic, k, ip

      do ic = 1, ncase
         call make_case(ic, c, points, label, error)
         if (allocated(error)) return
         mir = 2.0_wp*spread(c%direction, 2, 2)*spread(c%direction, 1, 2)
         mir(1, 1) = mir(1, 1) - 1.0_wp
         mir(2, 2) = mir(2, 2) - 1.0_wp
         do k = 1, 2
            if (c%amplitude(k) == 0.0_wp) cycle
            call new_corner(m, c%point, c%direction, c%angle, merge(c%amplitude(1), 0.0_wp, k == 1), &
               & merge(c%amplitude(2), 0.0_wp, k == 2), c%young, c%poisson, c%analysis, error)
            if (allocated(error)) return
            sgn = merge(1.0_wp, -1.0_wp, k == 1)
            tol_s = thr*8.0_wp*abs(c%amplitude(k))
            tol_u = tol_s*8.0_wp/c%young
            do ip = 1, npoint
               x = points(:, ip)
               xm = c%point + matmul(mir, x - c%point)
               call m%displacement(x, u)
               call m%displacement(xm, um)
               call check(error, maxval(abs(um - sgn*matmul(mir, u))), 0.0_wp, tol_u, 'u mirrored, mode '// &
                  & merge('1', '2', k == 1)//', '//label)
               if (allocated(error)) return
               call m%stress(x, s)
               call m%stress(xm, sm)
               st = reshape([s(1), s(3), s(3), s(2)], [2, 2])
               smt = reshape([sm(1), sm(3), sm(3), sm(2)], [2, 2])
               call check(error, maxval(abs(smt - sgn*matmul(mir, matmul(st, mir)))), 0.0_wp, tol_s, &
                  & 'sigma mirrored, mode '//merge('1', '2', k == 1)//', '//label)
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_mode_symmetry

   !> A crack with A = K/sqrt(2 pi) is the textbook near-tip field (e.g.
   !> Anderson, Fracture Mechanics, table 2.1/2.2), written here in its own
   !> half-angle form: mode I
   !>   u_x = K/(2G) sqrt(r/(2pi)) cos(t/2) (kappa - 1 + 2 sin^2(t/2)),
   !>   u_y = K/(2G) sqrt(r/(2pi)) sin(t/2) (kappa + 1 - 2 cos^2(t/2)),
   !>   s_xx = K/sqrt(2 pi r) cos(t/2) (1 - sin(t/2) sin(3t/2)),
   !>   s_xy = K/sqrt(2 pi r) cos(t/2) sin(t/2) cos(3t/2);
   !> mode II
   !>   u_x = K/(2G) sqrt(r/(2pi)) sin(t/2) (kappa + 1 + 2 cos^2(t/2)),
   !>   u_y = -K/(2G) sqrt(r/(2pi)) cos(t/2) (kappa - 1 - 2 sin^2(t/2)),
   !>   s_xx = -K/sqrt(2 pi r) sin(t/2) (2 + cos(t/2) cos(3t/2)),
   !>   s_yy = K/sqrt(2 pi r) sin(t/2) cos(t/2) cos(3t/2),
   !>   s_xy = K/sqrt(2 pi r) cos(t/2) (1 - sin(t/2) sin(3t/2)),
   !> in the crack frame (bisector along x). Round-off tier.
   subroutine test_crack_k_fields(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_type) :: c
      integer :: k, ip
      real(wp) :: kk, r, t, x(2), u(2), s(3), ue(2), se(3), mu, kappa, f, g
      real(wp) :: c1, s1, c3, s3
      integer(i8) :: seed

      seed = 99_i8
      kk = 3.0_wp
      mu = young/(2.0_wp*(1.0_wp + poisson))
      kappa = 3.0_wp - 4.0_wp*poisson
      do k = 1, 2
         call new_corner(c, [0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp], 360.0_wp, merge(kk, 0.0_wp, k == 1)/sqrt(2.0_wp*pi), &
            & merge(kk, 0.0_wp, k == 2)/sqrt(2.0_wp*pi), young, poisson, plane_strain, error)
         if (allocated(error)) return
         do ip = 1, npoint
            r = 0.1_wp + 2.0_wp*uniform(seed)
            t = pi*(2.0_wp*uniform(seed) - 1.0_wp)*0.999_wp
            x = r*[cos(t), sin(t)]
            c1 = cos(t/2.0_wp)
            s1 = sin(t/2.0_wp)
            c3 = cos(1.5_wp*t)
            s3 = sin(1.5_wp*t)
            f = kk/(2.0_wp*mu)*sqrt(r/(2.0_wp*pi))
            g = kk/sqrt(2.0_wp*pi*r)
            if (k == 1) then
               ue = f*[c1*(kappa - 1.0_wp + 2.0_wp*s1**2), s1*(kappa + 1.0_wp - 2.0_wp*c1**2)]
               se = g*[c1*(1.0_wp - s1*s3), c1*(1.0_wp + s1*s3), c1*s1*c3]
            else
               ue = f*[s1*(kappa + 1.0_wp + 2.0_wp*c1**2), -c1*(kappa - 1.0_wp - 2.0_wp*s1**2)]
               se = g*[-s1*(2.0_wp + c1*c3), s1*c1*c3, c1*(1.0_wp - s1*s3)]
            end if
            call c%displacement(x, u)
            call c%stress(x, s)
            call check(error, maxval(abs(u - ue)), 0.0_wp, thr*8.0_wp*f, 'crack displacement, mode '//merge('I ', 'II', k == 1))
            if (allocated(error)) return
            call check(error, maxval(abs(s - se)), 0.0_wp, thr*8.0_wp*g, 'crack stress, mode '//merge('I ', 'II', k == 1))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_crack_k_fields

   !> A plane strain solution with (E, nu) is the plane stress one with
   !> E' = E/(1 - nu^2), nu' = nu/(1 - nu) (same kappa and G): same stress and
   !> displacement to round-off, while the same (E, nu) in plane stress moves u.
   subroutine test_plane_stress_strain(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_type) :: a, b, d
      real(wp) :: x(2), ua(2), ub(2), ud(2), sa(3), sb(3)
      integer :: ip
      integer(i8) :: seed

      seed = 31_i8
      call new_corner(a, [0.2_wp, 0.1_wp], [0.6_wp, -0.8_wp], 270.0_wp, 1.0_wp, -0.5_wp, young, poisson, plane_strain, error)
      if (allocated(error)) return
      call new_corner(b, [0.2_wp, 0.1_wp], [0.6_wp, -0.8_wp], 270.0_wp, 1.0_wp, -0.5_wp, young/(1.0_wp - poisson**2), &
         & poisson/(1.0_wp - poisson), plane_stress, error)
      if (allocated(error)) return
      call new_corner(d, [0.2_wp, 0.1_wp], [0.6_wp, -0.8_wp], 270.0_wp, 1.0_wp, -0.5_wp, young, poisson, plane_stress, error)
      if (allocated(error)) return
      do ip = 1, npoint
         x = [0.2_wp, 0.1_wp] + [2.0_wp*uniform(seed) - 1.0_wp, 2.0_wp*uniform(seed) - 1.0_wp]
         call a%displacement(x, ua)
         call b%displacement(x, ub)
         call d%displacement(x, ud)
         call a%stress(x, sa)
         call b%stress(x, sb)
         call check(error, maxval(abs(ua - ub)), 0.0_wp, thr*maxval(abs(ua)), 'u: strain(E, nu) = stress(E'', nu'')')
         if (allocated(error)) return
         call check(error, maxval(abs(sa - sb)), 0.0_wp, thr*maxval(abs(sa)), 'sigma: strain(E, nu) = stress(E'', nu'')')
         if (allocated(error)) return
         call check(error, maxval(abs(ua - ud)) > 1.0e-3_wp*maxval(abs(ua)), 'plane stress (E, nu) differs')
         if (allocated(error)) return
      end do
   end subroutine test_plane_stress_strain

   subroutine test_constructor_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_type) :: c
      type(error_type), allocatable :: e
      real(wp), parameter :: p(2) = [0.0_wp, 0.0_wp], d(2) = [1.0_wp, 0.0_wp]
      real(wp) :: nan

      nan = 0.0_wp
      nan = nan/nan
      call new_corner(c, p, d, 180.0_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'corner: angle must satisfy 180 < angle <= 360', 'angle 180')
      if (allocated(error)) return
      call new_corner(c, p, d, 360.5_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'angle', 'angle 360.5')
      if (allocated(error)) return
      call new_corner(c, p, d, nan, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'angle', 'angle NaN')
      if (allocated(error)) return
      call new_corner(c, p, [0.0_wp, 0.0_wp], 270.0_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'corner: direction must be a finite nonzero vector', 'direction zero')
      if (allocated(error)) return
      call new_corner(c, p, [1.0_wp, nan], 270.0_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'direction', 'direction NaN')
      if (allocated(error)) return
      call new_corner(c, p, [1.0_wp, 0.0_wp, 0.0_wp], 270.0_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'direction must have 2 entries', 'direction size')
      if (allocated(error)) return
      call new_corner(c, [0.0_wp], d, 270.0_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'corner: center has 1 entries', 'point size')
      if (allocated(error)) return
      call new_corner(c, p, d, 270.0_wp, 0.0_wp, 0.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'mode1 and mode2 are both zero', 'no amplitude')
      if (allocated(error)) return
      call new_corner(c, p, d, 270.0_wp, nan, 1.0_wp, young, poisson, plane_strain, e)
      call expect_error(error, e, 'mode1 must be finite', 'mode1 NaN')
      if (allocated(error)) return
      call new_corner(c, p, d, 270.0_wp, 1.0_wp, nan, young, poisson, plane_strain, e)
      call expect_error(error, e, 'mode2 must be finite', 'mode2 NaN')
      if (allocated(error)) return
      call new_corner(c, p, d, 270.0_wp, 1.0_wp, 0.0_wp, young, poisson, solid, e)
      call expect_error(error, e, 'corner: analysis 3 (solid) is not supported', 'solid')
      if (allocated(error)) return
      call new_corner(c, p, d, 270.0_wp, 1.0_wp, 0.0_wp, young, 0.5_wp, plane_strain, e)
      call expect_error(error, e, 'corner: poisson', 'poisson 0.5')
      if (allocated(error)) return
      ! A non-unit direction is accepted and stored normalised.
      call new_corner(c, p, [0.0_wp, -3.0_wp], 270.0_wp, 1.0_wp, 0.0_wp, young, poisson, plane_strain, error)
      if (allocated(error)) return
      call check(error, all(c%direction == [0.0_wp, -1.0_wp]), 'direction normalised')
   end subroutine test_constructor_errors

   !> The apex itself, offsets below the floor (normal and subnormal) and far
   !> away give finite stress, displacement and traction.
   subroutine test_no_nan(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_type) :: c
      real(wp), allocatable :: points(:, :)
      character(len=:), allocatable :: label
      real(wp) :: offsets(5), x(2), s(3), u(2), t(2)
      integer :: ic, ip

      offsets = [0.0_wp, 1.0e-310_wp, 1.0e-300_wp, 1.0e-9_wp, 1.0e12_wp]
      do ic = 1, ncase
         call make_case(ic, c, points, label, error)
         if (allocated(error)) return
         do ip = 1, size(offsets)
            x = c%point + offsets(ip)*[1.0_wp, -1.0_wp]
            call c%stress(x, s)
            call c%displacement(x, u)
            call c%traction(x, [0.6_wp, 0.8_wp], t)
            call check(error, all(abs(s) <= huge(1.0_wp)) .and. all(abs(u) <= huge(1.0_wp)) .and. &
               & all(abs(t) <= huge(1.0_wp)), 'finite values near the apex and far out, '//label)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_no_nan

   !> Case ic: 1 L-shape mixed, plane strain, non-unit oblique bisector;
   !> 2 crack mixed, plane stress; 3 225 deg (l2 > 1) plane strain; 4 300 deg
   !> mode 2 only, plane stress; 5 190 deg mode 1 only. Apexes off the origin.
   !> Points: 1 <= r <= 3, |t| < beta.
   subroutine make_case(ic, c, points, label, error)
      integer, intent(in) :: ic
      type(corner_type), intent(out) :: c
      real(wp), allocatable, intent(out) :: points(:, :)
      character(len=:), allocatable, intent(out) :: label
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: angles(ncase) = [270.0_wp, 360.0_wp, 225.0_wp, 300.0_wp, 190.0_wp]
      real(wp), parameter :: mode1(ncase) = [1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, -1.5_wp]
      real(wp), parameter :: mode2(ncase) = [1.0_wp, -1.0_wp, 0.5_wp, 1.0_wp, 0.0_wp]
      real(wp), parameter :: dirs(2, ncase) = reshape([-1.0_wp, 1.0_wp, cos(0.5_wp), sin(0.5_wp), 0.0_wp, 2.0_wp, &
         & -0.3_wp, -0.4_wp, 1.0_wp, 0.0_wp], [2, ncase])
      integer :: mode, ip
      real(wp) :: beta, r, t, e(2), f(2)
      integer(i8) :: seed
      character(len=16) :: buf

      mode = merge(plane_strain, plane_stress, mod(ic, 2) == 1)
      call new_corner(c, [0.3_wp*ic, -0.7_wp], dirs(:, ic), angles(ic), mode1(ic), mode2(ic), young, poisson, mode, &
         & error)
      if (allocated(error)) return
      write (buf, '(f6.1)') angles(ic)
      label = 'corner '//trim(adjustl(buf))//' deg '//analysis_name(mode)
      beta = 0.5_wp*angles(ic)*pi/180.0_wp
      e = c%direction
      f = [-e(2), e(1)]
      seed = 500_i8 + ic
      allocate (points(2, npoint))
      do ip = 1, npoint
         r = 1.0_wp + 2.0_wp*uniform(seed)
         t = 0.98_wp*beta*(2.0_wp*uniform(seed) - 1.0_wp)
         points(:, ip) = c%point + r*(cos(t)*e + sin(t)*f)
      end do
   end subroutine make_case

end module sprc_test_exact_corner
