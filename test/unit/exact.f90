!> Tests of the exact solutions (Lame cylinder and sphere, Kirsch) and of the
!> isotropic material matrices they share with the FE and the recovery.
!>
!> Every solution is checked against what defines it, independently of its
!> formulas: equilibrium and the strain-displacement-stress relation by central
!> differences at pseudo-random points, the boundary conditions, symmetry, and
!> a few textbook values.
module sprc_test_exact
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, analysis_name, &
      & material_matrix, compliance_matrix
   use sprc_exact_solution, only: exact_solution_type
   use sprc_exact_lame, only: lame_cylinder_type, lame_sphere_type, new_lame_cylinder, new_lame_sphere
   use sprc_exact_kirsch, only: kirsch_type, new_kirsch
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_exact
   public :: check_equilibrium_fd, check_compatibility_fd, shell_points, expect_error, npoint, uniform

   real(wp), parameter :: pi = acos(-1.0_wp)
   real(wp), parameter :: young = 2.1e5_wp, poisson = 0.3_wp
   !> Points per case for the finite-difference and boundary tests.
   integer, parameter :: npoint = 20
   !> Number of cases: cylinder (2 modes x p_out zero/nonzero), sphere (p_out zero/nonzero), Kirsch (2 modes).
   integer, parameter :: ncase = 8

   !> One exact solution with the points where it is tested.
   type :: case_type
      class(exact_solution_type), allocatable :: sol
      character(len=:), allocatable :: label
      !> Center of the solution, size dim.
      real(wp), allocatable :: center(:)
      !> Test points in the body, (dim, npoint).
      real(wp), allocatable :: points(:, :)
      !> Reference length (inner radius) and stress scale (largest load).
      real(wp) :: length = 1.0_wp, scale = 1.0_wp
   end type case_type

contains

   subroutine collect_exact(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('material_inverse', test_material_inverse), &
         new_unittest('material_hand_values', test_material_hand_values), &
         new_unittest('compliance_from_3d', test_compliance_from_3d), &
         new_unittest('material_errors', test_material_errors), &
         new_unittest('equilibrium_fd', test_equilibrium), &
         new_unittest('strain_displacement_stress_fd', test_strain_displacement_stress), &
         new_unittest('lame_cylinder_boundary', test_cylinder_boundary), &
         new_unittest('lame_sphere_boundary', test_sphere_boundary), &
         new_unittest('lame_sphere_tangential_isotropy', test_sphere_isotropy), &
         new_unittest('kirsch_hole', test_kirsch_hole), &
         new_unittest('kirsch_far_field', test_kirsch_far_field), &
         new_unittest('symmetry_planes', test_symmetry_planes), &
         new_unittest('hand_values', test_hand_values), &
         new_unittest('traction_and_body_force', test_traction_and_body_force), &
         new_unittest('constructor_components', test_constructor_components), &
         new_unittest('constructor_errors', test_constructor_errors), &
         new_unittest('no_nan_in_hole', test_no_nan), &
         new_unittest('openmp_matches_serial', test_openmp) &
         ]
   end subroutine collect_exact

   ! ------------------------------------------------------------------ material

   !> D C = I for the three kinds. Entries of D are O(E/(1-2nu)) and of C
   !> O(1/E): with nu = 0.45 the product has round-off ~ 10 eps, hence 1e-13.
   subroutine test_material_inverse(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: kind, n, i, j
      real(wp) :: d(6, 6), c(6, 6), p(6, 6), eye
      real(wp), parameter :: nus(3) = [-0.5_wp, 0.3_wp, 0.45_wp]
      integer :: k

      do kind = plane_stress, solid
         do k = 1, size(nus)
            n = voigt_size(kind)
            call material_matrix(kind, 70.0_wp, nus(k), d(1:n, 1:n), error)
            if (allocated(error)) return
            call compliance_matrix(kind, 70.0_wp, nus(k), c(1:n, 1:n), error)
            if (allocated(error)) return
            p(1:n, 1:n) = matmul(d(1:n, 1:n), c(1:n, 1:n))
            do j = 1, n
               do i = 1, n
                  eye = merge(1.0_wp, 0.0_wp, i == j)
                  call check(error, p(i, j), eye, 1.0e-13_wp, 'D*C = I, '//analysis_name(kind))
                  if (allocated(error)) return
               end do
            end do
            call check(error, all(d(1:n, 1:n) == transpose(d(1:n, 1:n))), 'D symmetric')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_material_inverse

   !> Hand-written entries for E = 1000, nu = 0.3: plane strain
   !> E/((1+nu)(1-2nu)) [1-nu, nu; nu, 1-nu] with (1+nu)(1-2nu) = 0.52, plane
   !> stress E/(1-nu^2) [1, nu; nu, 1] with 1-nu^2 = 0.91, shear modulus
   !> mu = E/(2(1+nu)) = 1000/2.6, 3D lambda = E nu/0.52. Exact up to round-off.
   subroutine test_material_hand_values(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: d2(3, 3), d3(6, 6), c2(3, 3)
      real(wp), parameter :: tol = 1.0e-13_wp, mu = 1000.0_wp/2.6_wp, lambda = 300.0_wp/0.52_wp

      call material_matrix(plane_strain, 1000.0_wp, 0.3_wp, d2, error)
      if (allocated(error)) return
      call check_matrix(error, d2, reshape([700.0_wp/0.52_wp, 300.0_wp/0.52_wp, 0.0_wp, &
         & 300.0_wp/0.52_wp, 700.0_wp/0.52_wp, 0.0_wp, 0.0_wp, 0.0_wp, mu], [3, 3]), tol, 'plane strain D')
      if (allocated(error)) return
      call material_matrix(plane_stress, 1000.0_wp, 0.3_wp, d2, error)
      if (allocated(error)) return
      call check_matrix(error, d2, reshape([1000.0_wp/0.91_wp, 300.0_wp/0.91_wp, 0.0_wp, &
         & 300.0_wp/0.91_wp, 1000.0_wp/0.91_wp, 0.0_wp, 0.0_wp, 0.0_wp, mu], [3, 3]), tol, 'plane stress D')
      if (allocated(error)) return
      call compliance_matrix(plane_strain, 1000.0_wp, 0.3_wp, c2, error)
      if (allocated(error)) return
      call check_matrix(error, c2, reshape([0.91e-3_wp, -0.39e-3_wp, 0.0_wp, -0.39e-3_wp, 0.91e-3_wp, 0.0_wp, &
         & 0.0_wp, 0.0_wp, 2.6e-3_wp], [3, 3]), tol, 'plane strain C')
      if (allocated(error)) return
      call material_matrix(solid, 1000.0_wp, 0.3_wp, d3, error)
      if (allocated(error)) return
      call check(error, d3(1, 1), lambda + 2.0_wp*mu, tol, 'solid D11', rel=.true.)
      if (allocated(error)) return
      call check(error, d3(2, 3), lambda, tol, 'solid D23', rel=.true.)
      if (allocated(error)) return
      call check(error, d3(5, 5), mu, tol, 'solid D55', rel=.true.)
      if (allocated(error)) return
      call check(error, abs(d3(1, 4)) + abs(d3(4, 5)), 0.0_wp, 0.0_wp, 'solid D uncouples shear')
   end subroutine test_material_hand_values

   !> The 2D compliances follow from the 3D one: plane stress is sigma_zz = 0,
   !> plane strain is sigma_zz = nu (s_xx + s_yy), which must give eps_zz = 0.
   !> Round-off tolerance relative to the strain size |sigma|/E.
   subroutine test_compliance_from_3d(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: c3(6, 6), c2(3, 3), s2(3), s3(6), e3(6), e2(3), tol
      integer :: i, kind
      integer(i8) :: seed

      seed = 12345_i8
      call compliance_matrix(solid, young, poisson, c3, error)
      if (allocated(error)) return
      do kind = plane_stress, plane_strain
         call compliance_matrix(kind, young, poisson, c2, error)
         if (allocated(error)) return
         do i = 1, 5
            s2 = [2.0_wp*uniform(seed) - 1.0_wp, 2.0_wp*uniform(seed) - 1.0_wp, 2.0_wp*uniform(seed) - 1.0_wp]
            s3 = [s2(1), s2(2), 0.0_wp, s2(3), 0.0_wp, 0.0_wp]
            if (kind == plane_strain) s3(3) = poisson*(s2(1) + s2(2))
            e3 = matmul(c3, s3)
            e2 = matmul(c2, s2)
            tol = 1.0e-14_wp/young
            call check(error, maxval(abs(e2 - e3([1, 2, 4]))), 0.0_wp, tol, &
               & 'reduced compliance, '//analysis_name(kind))
            if (allocated(error)) return
            if (kind == plane_strain) then
               call check(error, e3(3), 0.0_wp, tol, 'plane strain eps_zz = 0')
               if (allocated(error)) return
            end if
         end do
      end do
   end subroutine test_compliance_from_3d

   subroutine test_material_errors(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: d3(3, 3), d6(6, 6), d2(2, 2), nan, inf
      type(error_type), allocatable :: e

      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      inf = ieee_value(1.0_wp, ieee_positive_inf)
      call material_matrix(0, young, poisson, d3, e)
      call expect_error(error, e, 'analysis kind 0', 'material_matrix analysis 0')
      if (allocated(error)) return
      call compliance_matrix(4, young, poisson, d3, e)
      call expect_error(error, e, 'analysis kind 4', 'compliance_matrix analysis 4')
      if (allocated(error)) return
      call material_matrix(plane_stress, 0.0_wp, poisson, d3, e)
      call expect_error(error, e, 'young', 'young = 0')
      if (allocated(error)) return
      call material_matrix(solid, -1.0_wp, poisson, d6, e)
      call expect_error(error, e, 'young', 'young < 0')
      if (allocated(error)) return
      call compliance_matrix(plane_strain, nan, poisson, d3, e)
      call expect_error(error, e, 'young', 'young NaN')
      if (allocated(error)) return
      call compliance_matrix(plane_strain, inf, poisson, d3, e)
      call expect_error(error, e, 'young', 'young Inf')
      if (allocated(error)) return
      call material_matrix(plane_strain, young, 0.5_wp, d3, e)
      call expect_error(error, e, 'poisson', 'poisson = 0.5')
      if (allocated(error)) return
      call material_matrix(solid, young, -1.0_wp, d6, e)
      call expect_error(error, e, 'poisson', 'poisson = -1')
      if (allocated(error)) return
      call compliance_matrix(plane_stress, young, nan, d3, e)
      call expect_error(error, e, 'poisson', 'poisson NaN')
      if (allocated(error)) return
      call material_matrix(plane_strain, young, poisson, d2, e)
      call expect_error(error, e, 'shape 2x2', 'material 2x2 for plane strain')
      if (allocated(error)) return
      call compliance_matrix(solid, young, poisson, d3, e)
      call expect_error(error, e, 'expected 6x6', 'compliance 3x3 for solid')
   end subroutine test_material_errors

   ! ----------------------------------------------------- finite differences

   !> div(sigma) + b = 0 by central differences with step h = 1e-4 L (L the
   !> inner radius). Truncation is h^2/6 times third derivatives of terms like
   !> (a/r)^2 and (a/r)^4, at most ~200 s/L^3 on r >= a, i.e. ~4e-7 s/L;
   !> round-off is ~eps s/h = 2e-12 s/L. Tolerance 1e-5 s/L (s the largest
   !> load), while a wrong coefficient leaves a residual of order s/L.
   subroutine test_equilibrium(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic

      do ic = 1, ncase
         call make_case(ic, c, error)
         if (allocated(error)) return
         call check_equilibrium_fd(error, c%sol, c%points, c%length, c%scale, c%label)
         if (allocated(error)) return
      end do
   end subroutine test_equilibrium

   !> Strain from central differences of u (engineering shear) equals C sigma
   !> with the compliance of the solution's analysis kind. Same step and
   !> reasoning as the equilibrium test, in strain units: tolerance 1e-5 s/E.
   !> Using the wrong plane mode for u gives errors of order nu^2 s/E.
   subroutine test_strain_displacement_stress(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic

      do ic = 1, ncase
         call make_case(ic, c, error)
         if (allocated(error)) return
         call check_compatibility_fd(error, c%sol, c%points, c%length, c%scale, c%label)
         if (allocated(error)) return
      end do
   end subroutine test_strain_displacement_stress

   !> div(sigma) + b = 0 by central differences at `points` with step
   !> h = 1e-4 `length` and tolerance 1e-5 `scale`/`length` (see test_equilibrium).
   subroutine check_equilibrium_fd(error, sol, points, length, scale, label)
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in) :: sol
      real(wp), intent(in) :: points(:, :), length, scale
      character(len=*), intent(in) :: label
      integer :: ip, i, j, dim
      real(wp) :: g(6, 3), b(3), div(3), h

      dim = sol%dim
      h = 1.0e-4_wp*length
      do ip = 1, size(points, 2)
         call fd_gradient(sol, .true., points(:, ip), h, g(1:sol%nstress, 1:dim))
         call sol%body_force(points(:, ip), b(1:dim))
         do i = 1, dim
            div(i) = b(i)
            do j = 1, dim
               div(i) = div(i) + g(voigt_index(dim, i, j), j)
            end do
         end do
         call check(error, maxval(abs(div(1:dim))), 0.0_wp, 1.0e-5_wp*scale/length, 'equilibrium, '//label)
         if (allocated(error)) return
      end do
   end subroutine check_equilibrium_fd

   !> Central-difference strain of u equals C sigma at `points`, step
   !> h = 1e-4 `length`, tolerance 1e-5 `scale`/E (see test_strain_displacement_stress).
   subroutine check_compatibility_fd(error, sol, points, length, scale, label)
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in) :: sol
      real(wp), intent(in) :: points(:, :), length, scale
      character(len=*), intent(in) :: label
      integer :: ip, dim, ns
      real(wp) :: g(3, 3), eps_fd(6), eps(6), sigma(6), comp(6, 6), h

      dim = sol%dim
      ns = sol%nstress
      call compliance_matrix(sol%analysis, sol%young, sol%poisson, comp(1:ns, 1:ns), error)
      if (allocated(error)) return
      h = 1.0e-4_wp*length
      do ip = 1, size(points, 2)
         call fd_gradient(sol, .false., points(:, ip), h, g(1:dim, 1:dim))
         if (dim == 2) then
            eps_fd(1:3) = [g(1, 1), g(2, 2), g(1, 2) + g(2, 1)]
         else
            eps_fd = [g(1, 1), g(2, 2), g(3, 3), g(1, 2) + g(2, 1), g(2, 3) + g(3, 2), g(1, 3) + g(3, 1)]
         end if
         call sol%stress(points(:, ip), sigma(1:ns))
         eps(1:ns) = matmul(comp(1:ns, 1:ns), sigma(1:ns))
         call check(error, maxval(abs(eps_fd(1:ns) - eps(1:ns))), 0.0_wp, 1.0e-5_wp*scale/sol%young, &
            & 'strain-displacement-stress, '//label)
         if (allocated(error)) return
      end do
   end subroutine check_compatibility_fd

   ! ------------------------------------------------------- boundary values

   !> sigma n = -p n on both surfaces with n the body's outward normal
   !> (-e_r at r_in, +e_r at r_out); p_out = 0 makes the outside free.
   !> Round-off: stresses are O(p (b^2+a^2)/(b^2-a^2)), tolerance 1e-13 p.
   subroutine test_cylinder_boundary(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic

      do ic = 1, 4
         call make_case(ic, c, error)
         if (allocated(error)) return
         select type (sol => c%sol)
         type is (lame_cylinder_type)
            call check_pressure(error, c, sol%r_in, -1.0_wp, sol%p_in, 'inner surface')
            if (allocated(error)) return
            call check_pressure(error, c, sol%r_out, 1.0_wp, sol%p_out, 'outer surface')
            if (allocated(error)) return
         class default
            call test_failed(error, 'case is not a cylinder')
            return
         end select
      end do
   end subroutine test_cylinder_boundary

   subroutine test_sphere_boundary(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic

      do ic = 5, 6
         call make_case(ic, c, error)
         if (allocated(error)) return
         select type (sol => c%sol)
         type is (lame_sphere_type)
            call check_pressure(error, c, sol%r_in, -1.0_wp, sol%p_in, 'inner surface')
            if (allocated(error)) return
            call check_pressure(error, c, sol%r_out, 1.0_wp, sol%p_out, 'outer surface')
            if (allocated(error)) return
         class default
            call test_failed(error, 'case is not a sphere')
            return
         end select
      end do
   end subroutine test_sphere_boundary

   !> At each test point's direction, on the sphere of radius r with outward
   !> normal sign*e_r, the traction is -p times that normal.
   subroutine check_pressure(error, c, r, sign, p, what)
      type(error_type), allocatable, intent(out) :: error
      type(case_type), intent(in) :: c
      real(wp), intent(in) :: r, sign, p
      character(len=*), intent(in) :: what
      integer :: ip, dim
      real(wp) :: e(3), x(3), n(3), t(3)

      dim = c%sol%dim
      do ip = 1, npoint
         e(1:dim) = c%points(:, ip) - c%center
         e(1:dim) = e(1:dim)/norm2(e(1:dim))
         x(1:dim) = c%center + r*e(1:dim)
         n(1:dim) = sign*e(1:dim)
         call c%sol%traction(x(1:dim), n(1:dim), t(1:dim))
         call check(error, maxval(abs(t(1:dim) + p*n(1:dim))), 0.0_wp, 1.0e-13_wp*c%scale, &
            & 'sigma n = -p n on the '//what//', '//c%label)
         if (allocated(error)) return
      end do
   end subroutine check_pressure

   !> The sphere's stress is sigma_rr e_r e_r^T + sigma_tt (I - e_r e_r^T): any
   !> two orthonormal tangents t1, t2 see the same normal stress, no shear
   !> between them and none with e_r; sigma_rr and sigma_tt from the polar
   !> formulas of the module doc. Round-off tolerance 1e-13 p.
   subroutine test_sphere_isotropy(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ip, ic
      real(wp) :: e(3), t1(3), t2(3), s(6), m(3, 3), a_coef, b_coef, r, q, tol

      do ic = 5, 6
         call make_case(ic, c, error)
         if (allocated(error)) return
         select type (sol => c%sol)
         type is (lame_sphere_type)
            q = (sol%r_in/sol%r_out)**3
            a_coef = (sol%p_in*q - sol%p_out)/(1.0_wp - q)
            b_coef = 0.5_wp*(sol%p_in - sol%p_out)*sol%r_in**3/(1.0_wp - q)
         class default
            call test_failed(error, 'case is not a sphere')
            return
         end select
         tol = 1.0e-13_wp*c%scale
         do ip = 1, npoint
            e = c%points(:, ip) - c%center
            r = norm2(e)
            e = e/r
            ! A tangent from the coordinate axis least aligned with e_r.
            t1 = 0.0_wp
            t1(minloc(abs(e), 1)) = 1.0_wp
            t1 = t1 - dot_product(t1, e)*e
            t1 = t1/norm2(t1)
            t2 = [e(2)*t1(3) - e(3)*t1(2), e(3)*t1(1) - e(1)*t1(3), e(1)*t1(2) - e(2)*t1(1)]
            call c%sol%stress(c%points(:, ip), s)
            m = reshape([s(1), s(4), s(6), s(4), s(2), s(5), s(6), s(5), s(3)], [3, 3])
            call check(error, dot_product(t1, matmul(m, t1)), a_coef + b_coef/r**3, tol, 'sigma_t1t1 = sigma_tt')
            if (allocated(error)) return
            call check(error, dot_product(t2, matmul(m, t2)), a_coef + b_coef/r**3, tol, 'sigma_t2t2 = sigma_tt')
            if (allocated(error)) return
            call check(error, dot_product(e, matmul(m, e)), a_coef - 2.0_wp*b_coef/r**3, tol, 'sigma_rr')
            if (allocated(error)) return
            call check(error, abs(dot_product(t1, matmul(m, t2))) + abs(dot_product(t1, matmul(m, e))) &
               & + abs(dot_product(t2, matmul(m, e))), 0.0_wp, tol, 'no shear in the polar frame')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_sphere_isotropy

   !> Kirsch on the hole r = a: sigma_xx(a, 90 deg) = 3 S, sigma_yy(a, 0) = -S,
   !> and traction-free (n = -e_r) at every test point's angle. Round-off
   !> tolerance 1e-13 S (stresses are at most 3 S there).
   subroutine test_kirsch_hole(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic, ip
      real(wp) :: s(3), e(2), t(2), a, s_inf, tol

      do ic = 7, 8
         call make_case(ic, c, error)
         if (allocated(error)) return
         select type (sol => c%sol)
         type is (kirsch_type)
            a = sol%radius
            s_inf = sol%s_inf
         class default
            call test_failed(error, 'case is not Kirsch')
            return
         end select
         tol = 1.0e-13_wp*abs(s_inf)
         call c%sol%stress(c%center + [0.0_wp, a], s)
         call check(error, s(1), 3.0_wp*s_inf, tol, 'sigma_xx(a, 90 deg) = 3 s_inf, '//c%label)
         if (allocated(error)) return
         call c%sol%stress(c%center + [0.0_wp, -a], s)
         call check(error, s(1), 3.0_wp*s_inf, tol, 'sigma_xx(a, 270 deg) = 3 s_inf, '//c%label)
         if (allocated(error)) return
         call c%sol%stress(c%center + [a, 0.0_wp], s)
         call check(error, s(2), -s_inf, tol, 'sigma_yy(a, 0) = -s_inf, '//c%label)
         if (allocated(error)) return
         call check(error, abs(s(1)) + abs(s(3)), 0.0_wp, tol, 'sigma_xx = sigma_xy = 0 at (a, 0)')
         if (allocated(error)) return
         do ip = 1, npoint
            e = c%points(:, ip) - c%center
            e = e/norm2(e)
            call c%sol%traction(c%center + a*e, -e, t)
            call check(error, maxval(abs(t)), 0.0_wp, tol, 'traction-free hole, '//c%label)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_kirsch_hole

   !> Far from the hole the stress tends to (S, 0, 0): from the formulas'
   !> coefficients, |sigma - (S, 0, 0)| <= (5/2 (a/r)^2 + 3/2 (a/r)^4) S
   !> <= 4 (a/r)^2 S for r >= a. Checked at r = 10 a, 100 a, 1000 a, and the
   !> bound is not vacuous: at r = 10 a, t = 90 deg sigma_xx - S = (1/2 (a/r)^2
   !> + 3/2 (a/r)^4) S exactly.
   subroutine test_kirsch_far_field(error)
      type(error_type), allocatable, intent(out) :: error
      type(kirsch_type) :: k
      integer :: ir, it
      real(wp) :: s(3), r, t, q2
      real(wp), parameter :: a = 2.0_wp, s_inf = 3.0_wp

      call new_kirsch(k, [1.0_wp, -1.0_wp], a, s_inf, young, poisson, plane_stress, error)
      if (allocated(error)) return
      do ir = 1, 3
         r = a*10.0_wp**ir
         q2 = (a/r)**2
         do it = 0, 11
            t = it*pi/6.0_wp + 0.1_wp
            call k%stress(k%center + r*[cos(t), sin(t)], s)
            call check(error, maxval(abs(s - [s_inf, 0.0_wp, 0.0_wp])), 0.0_wp, 4.0_wp*q2*s_inf, 'far field')
            if (allocated(error)) return
         end do
      end do
      call k%stress(k%center + [0.0_wp, 10.0_wp*a], s)
      call check(error, s(1) - s_inf, (0.5_wp*1.0e-2_wp + 1.5_wp*1.0e-4_wp)*s_inf, 1.0e-14_wp*s_inf, &
         & 'sigma_xx(10 a, 90 deg)')
   end subroutine test_kirsch_far_field

   !> Every solution is symmetric about the coordinate planes through its
   !> center: u_k(mirror_k x) = -u_k(x), the other components equal; on the
   !> plane itself u_k = 0 and the shear stresses across it vanish. This is
   !> the rigid-body normalisation the symmetry boundary conditions rely on.
   !> Round-off tolerances 1e-13 of the displacement scale s L/E and of s.
   subroutine test_symmetry_planes(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic, ip, k, dim, ns
      real(wp) :: x(3), xm(3), u(3), um(3), s(6), tol_u, tol_s

      do ic = 1, ncase
         call make_case(ic, c, error)
         if (allocated(error)) return
         dim = c%sol%dim
         ns = c%sol%nstress
         tol_u = 1.0e-13_wp*c%scale*c%length/c%sol%young*10.0_wp
         tol_s = 1.0e-13_wp*c%scale
         do ip = 1, npoint
            x(1:dim) = c%points(:, ip)
            call c%sol%displacement(x(1:dim), u(1:dim))
            do k = 1, dim
               xm(1:dim) = x(1:dim)
               xm(k) = 2.0_wp*c%center(k) - x(k)
               call c%sol%displacement(xm(1:dim), um(1:dim))
               um(k) = -um(k)
               call check(error, maxval(abs(um(1:dim) - u(1:dim))), 0.0_wp, tol_u, 'mirror symmetry of u, '//c%label)
               if (allocated(error)) return
               ! The point projected onto the plane x_k = c_k.
               xm(1:dim) = x(1:dim)
               xm(k) = c%center(k)
               call c%sol%displacement(xm(1:dim), um(1:dim))
               call check(error, um(k), 0.0_wp, tol_u, 'u normal to a symmetry plane, '//c%label)
               if (allocated(error)) return
               call c%sol%stress(xm(1:dim), s(1:ns))
               call check(error, shear_across(dim, k, s), 0.0_wp, tol_s, 'shear on a symmetry plane, '//c%label)
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_symmetry_planes

   !> Textbook values, written in the textbooks' form rather than the modules':
   !> - cylinder, p_out = 0: sigma_tt(a) = p (b^2 + a^2)/(b^2 - a^2) = 17/15
   !>   (a = 5, b = 20, p = 1); sigma_rr(10) = -0.2;
   !>   u_r(a) = p a/(E (b^2 - a^2)) ((1-nu) a^2 + (1+nu) b^2) = 43/6000 (plane
   !>   stress, E = 1000, nu = 0.3), (1+nu) p a/(E (b^2 - a^2)) ((1-2nu) a^2 + b^2)
   !>   = 533/75000 (plane strain);
   !> - sphere, p_out = 0: sigma_tt(a) = p (b^3 + 2a^3)/(2 (b^3 - a^3)) = 5/7
   !>   (a = 1, b = 2);
   !> - Kirsch: at (a, 45 deg) sigma_tt = S (1 - 2 cos 2t) = S, sigma_rr = 0, so
   !>   sigma = (S/2, S/2, -S/2); plane stress u_r(a, t) = S a/E (1 + 2 cos 2t):
   !>   u_x(a, 0) = 3 S a/E, u_y(a, 90 deg) = -S a/E.
   !> Round-off tolerance 1e-13 relative.
   subroutine test_hand_values(error)
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: cyl
      type(lame_sphere_type) :: sph
      type(kirsch_type) :: kir
      real(wp) :: s(6), u(3)
      real(wp), parameter :: tol = 1.0e-13_wp, c(2) = [3.0_wp, 4.0_wp]

      call new_lame_cylinder(cyl, c, 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, plane_stress, error)
      if (allocated(error)) return
      call cyl%stress(c + [0.0_wp, 5.0_wp], s(1:3))
      call check(error, s(1), 17.0_wp/15.0_wp, tol, 'cylinder sigma_tt(r_in)', rel=.true.)
      if (allocated(error)) return
      call cyl%stress(c + [6.0_wp, 8.0_wp], s(1:3))
      ! sigma_rr = e^T sigma e with e = (0.6, 0.8).
      call check(error, 0.36_wp*s(1) + 0.64_wp*s(2) + 0.96_wp*s(3), -0.2_wp, tol, 'cylinder sigma_rr(10)', rel=.true.)
      if (allocated(error)) return
      call cyl%displacement(c + [5.0_wp, 0.0_wp], u(1:2))
      call check(error, u(1), 43.0_wp/6000.0_wp, tol, 'cylinder u_r(r_in), plane stress', rel=.true.)
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c, 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, plane_strain, error)
      if (allocated(error)) return
      call cyl%displacement(c + [5.0_wp, 0.0_wp], u(1:2))
      call check(error, u(1), 533.0_wp/75000.0_wp, tol, 'cylinder u_r(r_in), plane strain', rel=.true.)
      if (allocated(error)) return

      call new_lame_sphere(sph, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, 1000.0_wp, 0.3_wp, error)
      if (allocated(error)) return
      call sph%stress([0.0_wp, 0.0_wp, 1.0_wp], s)
      call check(error, s(1), 5.0_wp/7.0_wp, tol, 'sphere sigma_tt(r_in)', rel=.true.)
      if (allocated(error)) return
      call check(error, s(3), -1.0_wp, tol, 'sphere sigma_rr(r_in)', rel=.true.)
      if (allocated(error)) return

      call new_kirsch(kir, c, 2.0_wp, 3.0_wp, 1000.0_wp, 0.3_wp, plane_stress, error)
      if (allocated(error)) return
      call kir%stress(c + sqrt(2.0_wp)*[1.0_wp, 1.0_wp], s(1:3))
      call check(error, maxval(abs(s(1:3) - [1.5_wp, 1.5_wp, -1.5_wp])), 0.0_wp, tol*3.0_wp, 'Kirsch sigma(a, 45 deg)')
      if (allocated(error)) return
      call kir%displacement(c + [2.0_wp, 0.0_wp], u(1:2))
      call check(error, u(1), 3.0_wp*3.0_wp*2.0_wp/1000.0_wp, tol, 'Kirsch u_x(a, 0)', rel=.true.)
      if (allocated(error)) return
      call kir%displacement(c + [0.0_wp, 2.0_wp], u(1:2))
      call check(error, u(2), -3.0_wp*2.0_wp/1000.0_wp, tol, 'Kirsch u_y(a, 90 deg)', rel=.true.)
   end subroutine test_hand_values

   !> traction(x, n) is sigma n (checked with n = e_k, which picks a column of
   !> the stress tensor) and the body force of every solution is zero.
   subroutine test_traction_and_body_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer :: ic, ip, k, dim, ns
      real(wp) :: s(6), t(3), n(3), b(3)

      do ic = 1, ncase
         call make_case(ic, c, error)
         if (allocated(error)) return
         dim = c%sol%dim
         ns = c%sol%nstress
         do ip = 1, npoint
            call c%sol%stress(c%points(:, ip), s(1:ns))
            do k = 1, dim
               n = 0.0_wp
               n(k) = 1.0_wp
               call c%sol%traction(c%points(:, ip), n(1:dim), t(1:dim))
               call check(error, all(t(1:dim) == tensor_column(dim, k, s)), 'traction = sigma e_k, '//c%label)
               if (allocated(error)) return
            end do
            call c%sol%body_force(c%points(:, ip), b(1:dim))
            call check(error, all(b(1:dim) == 0.0_wp), 'zero body force, '//c%label)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_traction_and_body_force

   subroutine test_constructor_components(error)
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: cyl
      type(lame_sphere_type) :: sph
      type(kirsch_type) :: kir

      call new_lame_cylinder(cyl, [1.0_wp, 2.0_wp], 1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 0.25_wp, plane_strain, error)
      if (allocated(error)) return
      call check(error, cyl%dim == 2 .and. cyl%nstress == 3 .and. cyl%analysis == plane_strain .and. &
         & cyl%young == 5.0_wp .and. cyl%poisson == 0.25_wp .and. all(cyl%center == [1.0_wp, 2.0_wp]) .and. &
         & cyl%r_in == 1.0_wp .and. cyl%r_out == 2.0_wp .and. cyl%p_in == 3.0_wp .and. cyl%p_out == 4.0_wp, &
         & 'cylinder components')
      if (allocated(error)) return
      call new_lame_sphere(sph, [1.0_wp, 2.0_wp, 3.0_wp], 1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, -0.25_wp, error)
      if (allocated(error)) return
      call check(error, sph%dim == 3 .and. sph%nstress == 6 .and. sph%analysis == solid .and. &
         & sph%young == 5.0_wp .and. sph%poisson == -0.25_wp .and. all(sph%center == [1.0_wp, 2.0_wp, 3.0_wp]) &
         & .and. sph%r_in == 1.0_wp .and. sph%r_out == 2.0_wp .and. sph%p_in == 3.0_wp .and. sph%p_out == 4.0_wp, &
         & 'sphere components')
      if (allocated(error)) return
      call new_kirsch(kir, [1.0_wp, 2.0_wp], 0.5_wp, -2.0_wp, 5.0_wp, 0.0_wp, plane_stress, error)
      if (allocated(error)) return
      call check(error, kir%dim == 2 .and. kir%nstress == 3 .and. kir%analysis == plane_stress .and. &
         & kir%young == 5.0_wp .and. kir%poisson == 0.0_wp .and. all(kir%center == [1.0_wp, 2.0_wp]) .and. &
         & kir%radius == 0.5_wp .and. kir%s_inf == -2.0_wp, 'kirsch components')
   end subroutine test_constructor_components

   !> Every validation in the constructors: the error is stat_invalid_input and
   !> its message names the field.
   subroutine test_constructor_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: cyl
      type(lame_sphere_type) :: sph
      type(kirsch_type) :: kir
      type(error_type), allocatable :: e
      real(wp) :: nan, inf
      real(wp), parameter :: c2(2) = 0.0_wp, c3(3) = 0.0_wp, nu = poisson, ym = young

      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      inf = ieee_value(1.0_wp, ieee_positive_inf)

      call new_lame_cylinder(cyl, c3, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'lame_cylinder: center has 3 entries', 'cylinder center size')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, [nan, 0.0_wp], 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'center must be finite', 'cylinder center NaN')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 0.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'r_in must be finite and > 0', 'cylinder r_in = 0')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, nan, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'r_in', 'cylinder r_in NaN')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, ym, nu, plane_strain, e)
      call expect_error(error, e, 'r_out must be finite and > r_in', 'cylinder r_out = r_in')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, inf, 1.0_wp, 0.0_wp, ym, nu, plane_strain, e)
      call expect_error(error, e, 'r_out', 'cylinder r_out Inf')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 2.0_wp, nan, 0.0_wp, ym, nu, plane_strain, e)
      call expect_error(error, e, 'p_in must be finite', 'cylinder p_in NaN')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 2.0_wp, 1.0_wp, -inf, ym, nu, plane_strain, e)
      call expect_error(error, e, 'p_out must be finite', 'cylinder p_out -Inf')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, nu, plane_strain, e)
      call expect_error(error, e, 'lame_cylinder: young', 'cylinder young = 0')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, 0.5_wp, plane_strain, e)
      call expect_error(error, e, 'lame_cylinder: poisson', 'cylinder poisson = 0.5')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, solid, e)
      call expect_error(error, e, 'analysis 3 (solid) is not supported', 'cylinder analysis solid')
      if (allocated(error)) return
      call new_lame_cylinder(cyl, c2, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, 7, e)
      call expect_error(error, e, 'analysis 7 (unknown)', 'cylinder analysis 7')
      if (allocated(error)) return

      call new_lame_sphere(sph, c2, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, e)
      call expect_error(error, e, 'lame_sphere: center has 2 entries', 'sphere center size')
      if (allocated(error)) return
      call new_lame_sphere(sph, [0.0_wp, inf, 0.0_wp], 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, e)
      call expect_error(error, e, 'center must be finite', 'sphere center Inf')
      if (allocated(error)) return
      call new_lame_sphere(sph, c3, -1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, nu, e)
      call expect_error(error, e, 'lame_sphere: r_in must be finite and > 0, got -1.', 'sphere r_in < 0')
      if (allocated(error)) return
      call new_lame_sphere(sph, c3, 2.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, ym, nu, e)
      call expect_error(error, e, 'r_out', 'sphere r_out < r_in')
      if (allocated(error)) return
      call new_lame_sphere(sph, c3, 1.0_wp, 2.0_wp, inf, 0.0_wp, ym, nu, e)
      call expect_error(error, e, 'p_in', 'sphere p_in Inf')
      if (allocated(error)) return
      call new_lame_sphere(sph, c3, 1.0_wp, 2.0_wp, 1.0_wp, nan, ym, nu, e)
      call expect_error(error, e, 'p_out', 'sphere p_out NaN')
      if (allocated(error)) return
      call new_lame_sphere(sph, c3, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, -ym, nu, e)
      call expect_error(error, e, 'young', 'sphere young < 0')
      if (allocated(error)) return
      call new_lame_sphere(sph, c3, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, ym, -1.0_wp, e)
      call expect_error(error, e, 'poisson', 'sphere poisson = -1')
      if (allocated(error)) return

      call new_kirsch(kir, [0.0_wp], 1.0_wp, 1.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'kirsch: center has 1 entries', 'kirsch center size')
      if (allocated(error)) return
      call new_kirsch(kir, [0.0_wp, nan], 1.0_wp, 1.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'center must be finite', 'kirsch center NaN')
      if (allocated(error)) return
      call new_kirsch(kir, c2, 0.0_wp, 1.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'kirsch: radius must be finite and > 0', 'kirsch radius = 0')
      if (allocated(error)) return
      call new_kirsch(kir, c2, inf, 1.0_wp, ym, nu, plane_stress, e)
      call expect_error(error, e, 'radius', 'kirsch radius Inf')
      if (allocated(error)) return
      call new_kirsch(kir, c2, 1.0_wp, nan, ym, nu, plane_stress, e)
      call expect_error(error, e, 's_inf must be finite', 'kirsch s_inf NaN')
      if (allocated(error)) return
      call new_kirsch(kir, c2, 1.0_wp, 1.0_wp, nan, nu, plane_strain, e)
      call expect_error(error, e, 'kirsch: young', 'kirsch young NaN')
      if (allocated(error)) return
      call new_kirsch(kir, c2, 1.0_wp, 1.0_wp, ym, 0.6_wp, plane_strain, e)
      call expect_error(error, e, 'kirsch: poisson', 'kirsch poisson 0.6')
      if (allocated(error)) return
      call new_kirsch(kir, c2, 1.0_wp, 1.0_wp, ym, nu, solid, e)
      call expect_error(error, e, 'kirsch: analysis 3', 'kirsch analysis solid')
   end subroutine test_constructor_errors

   !> Points at the center (exactly, and closer than the floor), in the hole
   !> and far out give finite stress, displacement and traction.
   subroutine test_no_nan(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(kirsch_type) :: kir
      type(lame_sphere_type) :: sph
      integer :: ic, ip, dim, ns
      real(wp) :: offsets(5), x(3), s(6), u(3), t(3), n(3)

      do ic = 1, ncase
         call make_case(ic, c, error)
         if (allocated(error)) return
         dim = c%sol%dim
         ns = c%sol%nstress
         offsets = [0.0_wp, 1.0e-300_wp, 1.0e-9_wp*c%length, 0.5_wp*c%length, 1.0e12_wp*c%length]
         n = 1.0_wp/sqrt(real(dim, wp))
         do ip = 1, size(offsets)
            x(1:dim) = c%center + offsets(ip)/sqrt(real(dim, wp))
            call c%sol%stress(x(1:dim), s(1:ns))
            call c%sol%displacement(x(1:dim), u(1:dim))
            call c%sol%traction(x(1:dim), n(1:dim), t(1:dim))
            call check(error, all(abs(s(1:ns)) <= huge(1.0_wp)) .and. all(abs(u(1:dim)) <= huge(1.0_wp)) .and. &
               & all(abs(t(1:dim)) <= huge(1.0_wp)), 'finite values off the body, '//c%label)
            if (allocated(error)) return
         end do
      end do
      ! Offsets far below the floor, normal and subnormal, where x - center is not rounded away.
      call new_kirsch(kir, [0.0_wp, 0.0_wp], 1.0_wp, 1.0_wp, young, poisson, plane_strain, error)
      if (allocated(error)) return
      call new_lame_sphere(sph, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, young, poisson, error)
      if (allocated(error)) return
      do ip = 1, 2
         x = merge(1.0e-300_wp, 1.0e-310_wp, ip == 1)*[1.0_wp, -1.0_wp, 1.0_wp]
         call kir%stress(x(1:2), s(1:3))
         call kir%displacement(x(1:2), u(1:2))
         call check(error, all(abs(s(1:3)) <= huge(1.0_wp)) .and. all(abs(u(1:2)) <= huge(1.0_wp)), &
            & 'finite Kirsch values at a tiny offset')
         if (allocated(error)) return
         call sph%stress(x, s)
         call sph%displacement(x, u)
         call check(error, all(abs(s) <= huge(1.0_wp)) .and. all(abs(u) <= huge(1.0_wp)), &
            & 'finite sphere values at a tiny offset')
         if (allocated(error)) return
      end do
   end subroutine test_no_nan

   !> Evaluation is pure and keeps no state: one object shared by OpenMP
   !> threads gives bitwise the serial results.
   subroutine test_openmp(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      integer, parameter :: m = 2000
      real(wp) :: x(3, m), serial(9, m), parallel(9, m)
      integer :: ic, i, j, dim
      integer(i8) :: seed

      do ic = 1, ncase
         call make_case(ic, c, error)
         if (allocated(error)) return
         dim = c%sol%dim
         seed = 777_i8
         ! Points in a box of edge 6 L around the center: in the body, in the hole and outside.
         do i = 1, m
            do j = 1, dim
               x(j, i) = c%center(j) + 6.0_wp*c%length*(uniform(seed) - 0.5_wp)
            end do
         end do
         serial = 0.0_wp
         parallel = 0.0_wp
         do i = 1, m
            call evaluate_all(c%sol, x(1:dim, i), serial(:, i))
         end do
         !$omp parallel do default(shared) private(i)
         do i = 1, m
            call evaluate_all(c%sol, x(1:dim, i), parallel(:, i))
         end do
         !$omp end parallel do
         call check(error, all(serial == parallel), 'OpenMP evaluation equals serial, '//c%label)
         if (allocated(error)) return
      end do
   end subroutine test_openmp

   pure subroutine evaluate_all(sol, x, v)
      class(exact_solution_type), intent(in) :: sol
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      v = 0.0_wp
      call sol%stress(x, v(1:sol%nstress))
      call sol%displacement(x, v(7:6 + sol%dim))
   end subroutine evaluate_all

   ! ------------------------------------------------------------- helpers

   !> Test case ic: 1-4 cylinder (plane stress / plane strain, p_out = 0 /
   !> nonzero), 5-6 sphere (p_out = 0 / nonzero), 7-8 Kirsch (plane stress /
   !> plane strain). Centers are off the origin so that x - center matters.
   subroutine make_case(ic, c, error)
      integer, intent(in) :: ic
      type(case_type), intent(out) :: c
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: cyl
      type(lame_sphere_type) :: sph
      type(kirsch_type) :: kir
      integer :: mode
      real(wp) :: p_out
      integer(i8) :: seed

      seed = 1000_i8 + ic
      select case (ic)
      case (1:4)
         mode = merge(plane_stress, plane_strain, ic <= 2)
         p_out = merge(0.0_wp, 0.4_wp, mod(ic, 2) == 1)
         c%center = [1.5_wp, -2.0_wp]
         call new_lame_cylinder(cyl, c%center, 5.0_wp, 20.0_wp, 1.0_wp, p_out, young, poisson, mode, error)
         if (allocated(error)) return
         allocate (c%sol, source=cyl)
         c%label = 'lame_cylinder '//analysis_name(mode)//merge(' p_out=0  ', ' p_out/=0 ', p_out == 0.0_wp)
         c%length = 5.0_wp
         c%scale = 1.0_wp
         c%points = shell_points(c%center, 5.0_wp, 20.0_wp, seed)
      case (5:6)
         p_out = merge(0.0_wp, -0.7_wp, ic == 5)
         c%center = [0.5_wp, -1.0_wp, 2.0_wp]
         call new_lame_sphere(sph, c%center, 1.0_wp, 2.5_wp, 2.0_wp, p_out, young, 0.2_wp, error)
         if (allocated(error)) return
         allocate (c%sol, source=sph)
         c%label = 'lame_sphere'//merge(' p_out=0  ', ' p_out/=0 ', p_out == 0.0_wp)
         c%length = 1.0_wp
         c%scale = 2.0_wp
         c%points = shell_points(c%center, 1.0_wp, 2.5_wp, seed)
      case default
         mode = merge(plane_stress, plane_strain, ic == 7)
         c%center = [-1.0_wp, 0.5_wp]
         call new_kirsch(kir, c%center, 2.0_wp, 3.0_wp, young, 0.35_wp, mode, error)
         if (allocated(error)) return
         allocate (c%sol, source=kir)
         c%label = 'kirsch '//analysis_name(mode)
         c%length = 2.0_wp
         c%scale = 3.0_wp
         c%points = shell_points(c%center, 2.0_wp, 8.0_wp, seed)
      end select
   end subroutine make_case

   !> npoint points with radius uniform in [r1, r2] and direction uniform on
   !> the circle / sphere around `center`.
   function shell_points(center, r1, r2, seed) result(points)
      real(wp), intent(in) :: center(:), r1, r2
      integer(i8), intent(inout) :: seed
      real(wp), allocatable :: points(:, :)
      real(wp) :: r, phi, z, e(3)
      integer :: ip

      allocate (points(size(center), npoint))
      do ip = 1, npoint
         r = r1 + (r2 - r1)*uniform(seed)
         phi = 2.0_wp*pi*uniform(seed)
         if (size(center) == 2) then
            e(1:2) = [cos(phi), sin(phi)]
         else
            z = 2.0_wp*uniform(seed) - 1.0_wp
            e = [sqrt(1.0_wp - z**2)*cos(phi), sqrt(1.0_wp - z**2)*sin(phi), z]
         end if
         points(:, ip) = center + r*e(1:size(center))
      end do
   end function shell_points

   !> Park-Miller minimal standard generator: deterministic on every compiler.
   real(wp) function uniform(seed)
      integer(i8), intent(inout) :: seed
      seed = mod(16807_i8*seed, 2147483647_i8)
      uniform = real(seed, wp)/2147483647.0_wp
   end function uniform

   !> Central-difference gradient g(component, direction) of the stress
   !> (`use_stress`) or of the displacement.
   subroutine fd_gradient(sol, use_stress, x, h, g)
      class(exact_solution_type), intent(in) :: sol
      logical, intent(in) :: use_stress
      real(wp), intent(in) :: x(:), h
      real(wp), intent(out) :: g(:, :)
      real(wp) :: xp(3), xm(3), fp(6), fm(6)
      integer :: j, n, dim

      n = size(g, 1)
      dim = sol%dim
      do j = 1, dim
         xp(1:dim) = x
         xm(1:dim) = x
         xp(j) = x(j) + h
         xm(j) = x(j) - h
         if (use_stress) then
            call sol%stress(xp(1:dim), fp(1:n))
            call sol%stress(xm(1:dim), fm(1:n))
         else
            call sol%displacement(xp(1:dim), fp(1:n))
            call sol%displacement(xm(1:dim), fm(1:n))
         end if
         g(:, j) = (fp(1:n) - fm(1:n))/(2.0_wp*h)
      end do
   end subroutine fd_gradient

   !> Voigt position of tensor entry (i, j).
   pure integer function voigt_index(dim, i, j)
      integer, intent(in) :: dim, i, j
      integer, parameter :: map2(2, 2) = reshape([1, 3, 3, 2], [2, 2])
      integer, parameter :: map3(3, 3) = reshape([1, 4, 6, 4, 2, 5, 6, 5, 3], [3, 3])
      if (dim == 2) then
         voigt_index = map2(i, j)
      else
         voigt_index = map3(i, j)
      end if
   end function voigt_index

   !> Column k of the stress tensor in Voigt storage s.
   pure function tensor_column(dim, k, s) result(col)
      integer, intent(in) :: dim, k
      real(wp), intent(in) :: s(:)
      real(wp) :: col(dim)
      integer :: i
      col = [(s(voigt_index(dim, i, k)), i=1, dim)]
   end function tensor_column

   !> Largest shear stress on the plane with normal e_k.
   pure real(wp) function shear_across(dim, k, s)
      integer, intent(in) :: dim, k
      real(wp), intent(in) :: s(:)
      integer :: i
      shear_across = 0.0_wp
      do i = 1, dim
         if (i /= k) shear_across = max(shear_across, abs(s(voigt_index(dim, i, k))))
      end do
   end function shear_across

   subroutine check_matrix(error, actual, expected, tol, message)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in) :: actual(:, :), expected(:, :), tol
      character(len=*), intent(in) :: message
      call check(error, maxval(abs(actual - expected)), 0.0_wp, tol*maxval(abs(expected)), message)
   end subroutine check_matrix

   !> `e` must be an invalid-input error whose message contains `fragment`.
   subroutine expect_error(error, e, fragment, what)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable, intent(in) :: e
      character(len=*), intent(in) :: fragment, what

      if (.not. allocated(e)) then
         call test_failed(error, what//': no error returned')
         return
      end if
      call check(error, e%stat, stat_invalid_input, what//': status')
      if (allocated(error)) return
      call check(error, index(e%message, fragment) > 0, what//': message "'//e%message//'" lacks "'//fragment//'"')
   end subroutine expect_error

end module sprc_test_exact
