!> Tests of the exact solutions for contact: uniform stress, compound
!> cylinder and sphere (shrink fit with internal pressure), Hertz line and
!> point contact, and the exact contact pressure they give.
!>
!> Field solutions are checked like the single-body ones (sprc_test_exact):
!> equilibrium and the strain-displacement-stress relation by central
!> differences, boundary tractions; plus what makes them contact solutions:
!> u_o(c) - u_i(c) = delta and equal tractions on the interface, and the
!> reference interface pressures of issue 11. Hertz is checked against hand
!> values and against its defining integral (the pressure sums to the load).
module sprc_test_exact_contact
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use sprc_core_kinds, only: wp, i8
   use sprc_core_gauss, only: gauss_legendre
   use sprc_core_material, only: plane_stress, plane_strain, solid, analysis_name
   use sprc_exact_uniform, only: uniform_type, new_uniform
   use sprc_exact_compound, only: compound_type, new_compound_cylinder, new_compound_sphere
   use sprc_exact_hertz, only: hertz_type, new_hertz_cylinder, new_hertz_sphere, cattaneo_mindlin_traction
   use sprc_exact_pressure, only: field_pressure_type, new_field_pressure
   use sprc_test_exact, only: check_equilibrium_fd, check_compatibility_fd, shell_points, expect_error, npoint
   use sprc_testsuite, only: unittest_type, new_unittest, check, error_type
   implicit none
   private

   public :: collect_exact_contact

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Round-off tier of a few dozen operations on O(1) quantities.
   real(wp), parameter :: roundoff = 64.0_wp*epsilon(1.0_wp)
   !> Issue 11's compound cylinder: a = 1, c = 1.5, b = 2, delta = 1e-3.
   real(wp), parameter :: a = 1.0_wp, c = 1.5_wp, b = 2.0_wp, delta = 1.0e-3_wp
   !> Number of compound cases (make_compound).
   integer, parameter :: ncompound = 4

contains

   subroutine collect_exact_contact(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('uniform_fd', test_uniform_fd), &
         new_unittest('uniform_linear_field', test_uniform_linear), &
         new_unittest('uniform_errors', test_uniform_errors), &
         new_unittest('compound_reference_pressure', test_compound_reference), &
         new_unittest('compound_closed_form', test_compound_closed_form), &
         new_unittest('compound_fd', test_compound_fd), &
         new_unittest('compound_interface', test_compound_interface), &
         new_unittest('compound_boundary', test_compound_boundary), &
         new_unittest('compound_open_interface', test_compound_open), &
         new_unittest('compound_errors', test_compound_errors), &
         new_unittest('hertz_hand_values', test_hertz_hand_values), &
         new_unittest('hertz_total_force', test_hertz_total_force), &
         new_unittest('cattaneo_mindlin_total_force', test_cattaneo_mindlin_force), &
         new_unittest('hertz_errors', test_hertz_errors), &
         new_unittest('field_pressure', test_field_pressure) &
         ]
   end subroutine collect_exact_contact

   ! ------------------------------------------------------------------ uniform

   !> Uniform stress for the three analyses and two materials: the FD checks
   !> of sprc_test_exact (a linear u is differenced exactly up to round-off).
   subroutine test_uniform_fd(error)
      type(error_type), allocatable, intent(out) :: error
      type(uniform_type) :: sol
      integer :: analysis, k
      integer(i8) :: seed
      real(wp), allocatable :: points(:, :), center(:)
      real(wp), parameter :: young(2) = [1000.0_wp, 3.0_wp], poisson(2) = [0.3_wp, -0.2_wp]

      seed = 42_i8
      do analysis = plane_stress, solid
         do k = 1, 2
            call make_uniform(analysis, young(k), poisson(k), sol, error)
            if (allocated(error)) return
            center = spread(0.5_wp, 1, sol%dim)
            points = shell_points(center, 0.1_wp, 2.0_wp, seed)
            call check_equilibrium_fd(error, sol, points, 1.0_wp, 3.0_wp, 'uniform '//analysis_name(analysis))
            if (allocated(error)) return
            call check_compatibility_fd(error, sol, points, 1.0_wp, 3.0_wp, 'uniform '//analysis_name(analysis))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_uniform_fd

   !> u(0) = 0 and no rotation: u_i(e_j) = u_j(e_i); the stress is the input
   !> everywhere. Round-off tier relative to |S|/E.
   subroutine test_uniform_linear(error)
      type(error_type), allocatable, intent(out) :: error
      type(uniform_type) :: sol
      integer :: analysis, i, j
      real(wp) :: u(3, 3), x(3), s(6), zero(3)

      do analysis = plane_stress, solid
         call make_uniform(analysis, 7.0_wp, 0.25_wp, sol, error)
         if (allocated(error)) return
         associate (d => sol%dim, ns => sol%nstress)
            x = 0.0_wp
            call sol%displacement(x(1:d), zero(1:d))
            call check(error, maxval(abs(zero(1:d))), 0.0_wp, 0.0_wp, 'u(0) = 0, '//analysis_name(analysis))
            if (allocated(error)) return
            do j = 1, d
               x = 0.0_wp
               x(j) = 1.0_wp
               call sol%displacement(x(1:d), u(1:d, j))
            end do
            do j = 1, d
               do i = 1, d
                  call check(error, u(i, j), u(j, i), roundoff*3.0_wp/7.0_wp, 'no rotation')
                  if (allocated(error)) return
               end do
            end do
            call sol%stress([(real(i, wp), i=1, d)], s(1:ns))
            call check(error, all(s(1:ns) == sol%sigma(1:ns)), 'constant stress')
            if (allocated(error)) return
         end associate
      end do
   end subroutine test_uniform_linear

   subroutine test_uniform_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(uniform_type) :: sol
      type(error_type), allocatable :: e
      real(wp) :: nan

      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      call new_uniform(sol, [1.0_wp, 2.0_wp], 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'stress has 2 entries, expected 3', 'uniform stress size')
      if (allocated(error)) return
      call new_uniform(sol, [1.0_wp, 2.0_wp, 3.0_wp], 1.0_wp, 0.3_wp, solid, e)
      call expect_error(error, e, 'expected 6', 'uniform 2D stress in 3D')
      if (allocated(error)) return
      call new_uniform(sol, [1.0_wp, nan, 3.0_wp], 1.0_wp, 0.3_wp, plane_strain, e)
      call expect_error(error, e, 'stress must be finite', 'uniform NaN stress')
      if (allocated(error)) return
      call new_uniform(sol, [1.0_wp, 2.0_wp, 3.0_wp], -1.0_wp, 0.3_wp, plane_strain, e)
      call expect_error(error, e, 'uniform: young', 'uniform young < 0')
   end subroutine test_uniform_errors

   subroutine make_uniform(analysis, young, poisson, sol, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      type(uniform_type), intent(out) :: sol
      type(error_type), allocatable, intent(out) :: error

      if (analysis == solid) then
         call new_uniform(sol, [1.0_wp, -2.0_wp, 3.0_wp, 0.5_wp, -0.25_wp, 0.75_wp], young, poisson, analysis, error)
      else
         call new_uniform(sol, [1.0_wp, -2.0_wp, 0.5_wp], young, poisson, analysis, error)
      end if
   end subroutine make_uniform

   ! ----------------------------------------------------------------- compound

   !> Issue 11's values (given to 7 digits, so tolerance half a unit of the
   !> 7th digit, 5e-7 relative): one material E = 1, nu = 0.3, delta = 1e-3,
   !> no p_in: 1.080247e-4 plane stress, 1.187085e-4 plane strain; E_inner =
   !> 2, nu_inner = 0.3, E_outer = 1, nu_outer = 0.25, p_in = 1e-3, plane strain:
   !> 3.000113e-4.
   subroutine test_compound_reference(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      real(wp), parameter :: tol = 5.0e-7_wp

      call new_compound_cylinder(cc, [0.0_wp, 0.0_wp], a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, &
         & plane_stress, error)
      if (allocated(error)) return
      call check(error, cc%contact_pressure, 1.080247e-4_wp, tol, 'p_c plane stress', rel=.true.)
      if (allocated(error)) return
      call new_compound_cylinder(cc, [0.0_wp, 0.0_wp], a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      call check(error, cc%contact_pressure, 1.187085e-4_wp, tol, 'p_c plane strain', rel=.true.)
      if (allocated(error)) return
      call new_compound_cylinder(cc, [0.0_wp, 0.0_wp], a, c, b, 1.0e-3_wp, delta, 2.0_wp, 0.3_wp, 1.0_wp, 0.25_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      call check(error, cc%contact_pressure, 3.000113e-4_wp, tol, 'p_c two materials, p_in, plane strain', rel=.true.)
   end subroutine test_compound_reference

   !> Against the closed forms of the module doc (written out here, not through
   !> the Lame modules): one material, textbook E delta (c^2-a^2)(b^2-c^2)/(2 c^3 (b^2-a^2));
   !> two materials in plane stress with p_in from f_i, f_o, u_i(c; p_in, 0);
   !> plane strain by E -> E/(1-nu^2), nu -> nu/(1-nu); the sphere's
   !> 2 E delta (c^3-a^3)(b^3-c^3)/(3 (1-nu) c^4 (b^3-a^3)) and its f_i, f_o,
   !> u_i(c; p_in, 0) (derived by hand from the Lame sphere). Round-off tier.
   subroutine test_compound_closed_form(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      real(wp), parameter :: ei = 210.0_wp, ni = 0.3_wp, eo = 70.0_wp, no = 0.33_wp, p_in = 0.05_wp
      real(wp) :: expected
      integer :: analysis

      call new_compound_cylinder(cc, [3.0_wp, -1.0_wp], a, c, b, 0.0_wp, delta, ei, ni, ei, ni, plane_stress, error)
      if (allocated(error)) return
      expected = ei*delta*(c**2 - a**2)*(b**2 - c**2)/(2.0_wp*c**3*(b**2 - a**2))
      call check(error, cc%contact_pressure, expected, roundoff, 'textbook shrink fit', rel=.true.)
      if (allocated(error)) return
      do analysis = plane_stress, plane_strain
         call new_compound_cylinder(cc, [3.0_wp, -1.0_wp], a, c, b, p_in, delta, ei, ni, eo, no, analysis, error)
         if (allocated(error)) return
         if (analysis == plane_stress) then
            expected = plane_stress_pc(ei, ni, eo, no)
         else
            expected = plane_stress_pc(ei/(1.0_wp - ni**2), ni/(1.0_wp - ni), eo/(1.0_wp - no**2), no/(1.0_wp - no))
         end if
         call check(error, cc%contact_pressure, expected, roundoff, 'p_c closed form, '//analysis_name(analysis), &
            & rel=.true.)
         if (allocated(error)) return
      end do
      call new_compound_sphere(cc, [3.0_wp, -1.0_wp, 0.5_wp], a, c, b, 0.0_wp, delta, ei, ni, ei, ni, error)
      if (allocated(error)) return
      expected = 2.0_wp*ei*delta*(c**3 - a**3)*(b**3 - c**3)/(3.0_wp*(1.0_wp - ni)*c**4*(b**3 - a**3))
      call check(error, cc%contact_pressure, expected, roundoff, 'textbook compound sphere', rel=.true.)
      if (allocated(error)) return
      call new_compound_sphere(cc, [3.0_wp, -1.0_wp, 0.5_wp], a, c, b, p_in, delta, ei, ni, eo, no, error)
      if (allocated(error)) return
      call check(error, cc%contact_pressure, sphere_pc(ei, ni, eo, no), roundoff, 'p_c closed form, sphere', &
         & rel=.true.)

   contains

      pure real(wp) function sphere_pc(e_i, n_i, e_o, n_o)
         real(wp), intent(in) :: e_i, n_i, e_o, n_o
         real(wp) :: f_i, f_o, u_p
         f_o = c/e_o*((1.0_wp - 2.0_wp*n_o)*c**3 + 0.5_wp*(1.0_wp + n_o)*b**3)/(b**3 - c**3)
         f_i = c/e_i*((1.0_wp - 2.0_wp*n_i)*c**3 + 0.5_wp*(1.0_wp + n_i)*a**3)/(c**3 - a**3)
         u_p = 1.5_wp*(1.0_wp - n_i)*a**3*c*p_in/(e_i*(c**3 - a**3))
         sphere_pc = (delta + u_p)/(f_o + f_i)
      end function sphere_pc

      pure real(wp) function plane_stress_pc(e_i, n_i, e_o, n_o)
         real(wp), intent(in) :: e_i, n_i, e_o, n_o
         real(wp) :: f_i, f_o, u_p
         f_o = c/e_o*((b**2 + c**2)/(b**2 - c**2) + n_o)
         f_i = c/e_i*((c**2 + a**2)/(c**2 - a**2) - n_i)
         u_p = 2.0_wp*a**2*c*p_in/(e_i*(c**2 - a**2))
         plane_stress_pc = (delta + u_p)/(f_o + f_i)
      end function plane_stress_pc

   end subroutine test_compound_closed_form

   !> Equilibrium and compatibility in each ring by central differences,
   !> points uniform in its radial range; stress scale max(p_in, p_c), length a.
   subroutine test_compound_fd(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      integer :: k
      integer(i8) :: seed
      real(wp) :: scale
      character(len=:), allocatable :: label

      seed = 7_i8
      do k = 1, ncompound
         call make_compound(k, cc, label, error)
         if (allocated(error)) return
         scale = max(cc%p_in, cc%contact_pressure)
         associate (x0 => cc%center(1:cc%dim))
            call check_equilibrium_fd(error, cc%inner, shell_points(x0, a, c, seed), a, scale, label//' inner')
            if (allocated(error)) return
            call check_equilibrium_fd(error, cc%outer, shell_points(x0, c, b, seed), a, scale, label//' outer')
            if (allocated(error)) return
            call check_compatibility_fd(error, cc%inner, shell_points(x0, a, c, seed), a, scale, label//' inner')
            if (allocated(error)) return
            call check_compatibility_fd(error, cc%outer, shell_points(x0, c, b, seed), a, scale, label//' outer')
            if (allocated(error)) return
         end associate
      end do
   end subroutine test_compound_fd

   !> On r = c in random directions e: u_o.e - u_i.e = delta, no tangential
   !> displacement, and equal tractions sigma_i e = sigma_o e = -p_c e.
   !> Round-off tier relative to the largest displacement / stress involved.
   subroutine test_compound_interface(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      integer :: k, ip
      integer(i8) :: seed
      real(wp), allocatable :: points(:, :)
      real(wp) :: e(3), x(3), ui(3), uo(3), ti(3), to(3), u_scale, s_scale
      character(len=:), allocatable :: label

      seed = 11_i8
      do k = 1, ncompound
         call make_compound(k, cc, label, error)
         if (allocated(error)) return
         associate (d => cc%dim, x0 => cc%center(1:cc%dim))
            points = shell_points(x0, c, c, seed)
            s_scale = max(cc%p_in, cc%contact_pressure)
            do ip = 1, npoint
               e(1:d) = (points(:, ip) - x0)/c
               x(1:d) = x0 + c*e(1:d)
               call cc%inner%displacement(x(1:d), ui(1:d))
               call cc%outer%displacement(x(1:d), uo(1:d))
               u_scale = max(norm2(ui(1:d)), norm2(uo(1:d)))
               call check(error, dot_product(uo(1:d) - ui(1:d), e(1:d)), cc%interference, roundoff*u_scale, &
                  & 'u_o(c) - u_i(c) = delta, '//label)
               if (allocated(error)) return
               call check(error, norm2(uo(1:d) - ui(1:d) - cc%interference*e(1:d)), 0.0_wp, roundoff*u_scale, &
                  & 'no tangential jump, '//label)
               if (allocated(error)) return
               call cc%inner%traction(x(1:d), e(1:d), ti(1:d))
               call cc%outer%traction(x(1:d), e(1:d), to(1:d))
               call check(error, norm2(ti(1:d) - to(1:d)), 0.0_wp, roundoff*s_scale, 'traction continuity, '//label)
               if (allocated(error)) return
               call check(error, norm2(ti(1:d) + cc%contact_pressure*e(1:d)), 0.0_wp, roundoff*s_scale, &
                  & 'interface traction -p_c e_r, '//label)
               if (allocated(error)) return
            end do
         end associate
      end do
   end subroutine test_compound_interface

   !> sigma n = -p_in n on r = a (n = -e_r) and free on r = b.
   subroutine test_compound_boundary(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      integer :: k, ip
      integer(i8) :: seed
      real(wp), allocatable :: points(:, :)
      real(wp) :: e(3), t(3), s_scale
      character(len=:), allocatable :: label

      seed = 13_i8
      do k = 1, ncompound
         call make_compound(k, cc, label, error)
         if (allocated(error)) return
         s_scale = max(cc%p_in, cc%contact_pressure)
         associate (d => cc%dim, x0 => cc%center(1:cc%dim))
            points = shell_points(x0, 1.0_wp, 1.0_wp, seed)
            do ip = 1, npoint
               e(1:d) = points(:, ip) - x0
               call cc%inner%traction(x0 + a*e(1:d), -e(1:d), t(1:d))
               call check(error, norm2(t(1:d) - cc%p_in*e(1:d)), 0.0_wp, roundoff*s_scale, 'p_in on r_in, '//label)
               if (allocated(error)) return
               call cc%outer%traction(x0 + b*e(1:d), e(1:d), t(1:d))
               call check(error, norm2(t(1:d)), 0.0_wp, roundoff*s_scale, 'free r_out, '//label)
               if (allocated(error)) return
            end do
         end associate
      end do
   end subroutine test_compound_boundary

   !> A clearance (delta < 0) wider than what p_in closes leaves the interface
   !> open: p_c = 0, the outer ring unloaded, the inner one a plain Lame shell
   !> whose outer surface is free. Suction p_in < 0 without interference too.
   subroutine test_compound_open(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      real(wp) :: s(3), t(2)

      call new_compound_cylinder(cc, [0.0_wp, 0.0_wp], a, c, b, 1.0e-3_wp, -1.0e-2_wp, 1.0_wp, 0.3_wp, 1.0_wp, &
         & 0.3_wp, plane_strain, error)
      if (allocated(error)) return
      call check(error, cc%contact_pressure, 0.0_wp, 0.0_wp, 'open interface: p_c = 0')
      if (allocated(error)) return
      call cc%outer%stress([0.0_wp, 1.7_wp], s)
      call check(error, maxval(abs(s)), 0.0_wp, 0.0_wp, 'open interface: outer ring unloaded')
      if (allocated(error)) return
      call cc%inner%traction([c, 0.0_wp], [1.0_wp, 0.0_wp], t)
      call check(error, maxval(abs(t)), 0.0_wp, roundoff*1.0e-3_wp, 'open interface: inner ring free at c')
      if (allocated(error)) return
      call new_compound_cylinder(cc, [0.0_wp, 0.0_wp], a, c, b, -1.0e-3_wp, 0.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, &
         & 0.3_wp, plane_stress, error)
      if (allocated(error)) return
      call check(error, cc%contact_pressure, 0.0_wp, 0.0_wp, 'suction: p_c = 0')
   end subroutine test_compound_open

   subroutine test_compound_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(compound_type) :: cc
      type(error_type), allocatable :: e
      real(wp) :: nan
      real(wp), parameter :: z2(2) = 0.0_wp, z3(3) = 0.0_wp

      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      call new_compound_cylinder(cc, z2, a, a, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'compound_cylinder: r_contact must be finite and > r_in', 'r_contact = r_in')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, a, c, c, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'r_out must be finite and > r_contact', 'r_out = r_contact')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, -a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'r_in must be finite and > 0', 'r_in < 0')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, a, c, b, 0.0_wp, nan, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'interference must be finite', 'interference NaN')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, a, c, b, nan, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'p_in must be finite', 'p_in NaN')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, a, c, b, 0.0_wp, delta, 0.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'compound_cylinder inner body: young', 'inner young = 0')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.5_wp, plane_strain, e)
      call expect_error(error, e, 'compound_cylinder outer body: poisson', 'outer poisson = 0.5')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z3, a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_stress, e)
      call expect_error(error, e, 'center has 3 entries, expected 2', 'cylinder center in 3D')
      if (allocated(error)) return
      call new_compound_cylinder(cc, z2, a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, solid, e)
      call expect_error(error, e, 'compound_cylinder: analysis solid is not supported', 'cylinder analysis solid')
      if (allocated(error)) return
      call new_compound_sphere(cc, z2, a, c, b, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, e)
      call expect_error(error, e, 'compound_sphere: center has 2 entries, expected 3', 'sphere center in 2D')
      if (allocated(error)) return
      call new_compound_sphere(cc, z3, a, c, 0.5_wp, 0.0_wp, delta, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, e)
      call expect_error(error, e, 'compound_sphere: r_out', 'sphere r_out < r_contact')
   end subroutine test_compound_errors

   !> Case k: 1 cylinder plane stress, 2 cylinder plane strain (two materials,
   !> p_in and delta), 3 sphere, 4 cylinder with a material ratio of 1000
   !> (the issue's largest); centers off the origin.
   subroutine make_compound(k, cc, label, error)
      integer, intent(in) :: k
      type(compound_type), intent(out) :: cc
      character(len=:), allocatable, intent(out) :: label
      type(error_type), allocatable, intent(out) :: error

      select case (k)
      case (1, 2)
         label = 'compound_cylinder '//analysis_name(k)
         call new_compound_cylinder(cc, [0.5_wp, -1.5_wp], a, c, b, 1.0e-3_wp, delta, 2.0_wp, 0.3_wp, 1.0_wp, &
            & 0.25_wp, k, error)
      case (3)
         label = 'compound_sphere'
         call new_compound_sphere(cc, [0.5_wp, -1.5_wp, 2.0_wp], a, c, b, 1.0e-3_wp, delta, 2.0_wp, 0.3_wp, &
            & 1.0_wp, 0.25_wp, error)
      case default
         label = 'compound_cylinder E_inner/E_outer = 1000'
         call new_compound_cylinder(cc, [0.5_wp, -1.5_wp], a, c, b, 1.0e-3_wp, delta, 1000.0_wp, 0.3_wp, 1.0_wp, &
            & 0.45_wp, plane_strain, error)
      end select
   end subroutine make_compound

   ! -------------------------------------------------------------------- Hertz

   !> Hand values with E* = 1 and R = 1: line contact P = pi/4 gives a = 1,
   !> p0 = 1/2; point contact F = 4/3 gives a = 1, p0 = 2/pi. E* = 1 from
   !> E = 1.5 and 3 (plane stress, any nu: 2/3 + 1/3 = 1), E = 2 (1 - nu^2)
   !> for both (plane strain), E = 1.5 (1 - nu_1^2) and 3 (1 - nu_2^2) (3D).
   !> p(0.6 a) = 0.8 p0; p = p0 on the normal line; p = 0 beyond a.
   subroutine test_hertz_hand_values(error)
      type(error_type), allocatable, intent(out) :: error
      type(hertz_type) :: h
      real(wp), parameter :: nu = 0.3_wp, tol = roundoff
      real(wp) :: t2(2), t3(3)

      call new_hertz_cylinder(h, [1.0_wp, 2.0_wp], [0.0_wp, -3.0_wp], 1.0_wp, pi/4.0_wp, 1.5_wp, nu, 3.0_wp, 0.1_wp, &
         & plane_stress, error)
      if (allocated(error)) return
      call check_hertz(error, h, 1.0_wp, 0.5_wp, 1.0_wp, 'line contact, plane stress')
      if (allocated(error)) return
      t2 = [1.0_wp, 0.0_wp]
      call check(error, h%pressure([1.0_wp, 2.0_wp] + 0.6_wp*t2, -t2), 0.4_wp, tol, 'p(0.6 a) = 0.8 p0')
      if (allocated(error)) return
      call check(error, h%pressure([1.0_wp, 2.0_wp] + 0.7_wp*[0.0_wp, 1.0_wp], -t2), 0.5_wp, tol, 'p on the normal')
      if (allocated(error)) return
      call check(error, h%pressure([1.0_wp, 2.0_wp] - 1.5_wp*t2, -t2), 0.0_wp, 0.0_wp, 'p = 0 beyond a')
      if (allocated(error)) return
      call new_hertz_cylinder(h, [1.0_wp, 2.0_wp], [0.0_wp, 1.0_wp], 1.0_wp, pi/4.0_wp, 2.0_wp*(1.0_wp - nu**2), nu, &
         & 2.0_wp*(1.0_wp - 0.2_wp**2), 0.2_wp, plane_strain, error)
      if (allocated(error)) return
      call check_hertz(error, h, 1.0_wp, 0.5_wp, 1.0_wp, 'line contact, plane strain')
      if (allocated(error)) return
      call new_hertz_sphere(h, [0.0_wp, 0.0_wp, 1.0_wp], [0.0_wp, 0.0_wp, 2.0_wp], 1.0_wp, 4.0_wp/3.0_wp, &
         & 1.5_wp*(1.0_wp - nu**2), nu, 3.0_wp*(1.0_wp - 0.2_wp**2), 0.2_wp, error)
      if (allocated(error)) return
      call check_hertz(error, h, 1.0_wp, 2.0_wp/pi, 1.0_wp, 'point contact')
      if (allocated(error)) return
      t3 = [0.6_wp, 0.0_wp, 5.0_wp]/sqrt(2.0_wp)
      call check(error, h%pressure([0.0_wp, 0.0_wp, 1.0_wp] + [t3(1), t3(1), t3(3)], [0.0_wp, 0.0_wp, 1.0_wp]), &
         & 1.6_wp/pi, tol, 'p(0.6 a) = 0.8 p0 off the plane')
   end subroutine test_hertz_hand_values

   subroutine check_hertz(error, h, a_expected, p0_expected, e_star, what)
      type(error_type), allocatable, intent(out) :: error
      type(hertz_type), intent(in) :: h
      real(wp), intent(in) :: a_expected, p0_expected, e_star
      character(len=*), intent(in) :: what

      call check(error, h%e_star, e_star, roundoff, 'E*, '//what, rel=.true.)
      if (allocated(error)) return
      call check(error, h%half_width, a_expected, roundoff, 'a, '//what, rel=.true.)
      if (allocated(error)) return
      call check(error, h%p0, p0_expected, roundoff, 'p0, '//what, rel=.true.)
      if (allocated(error)) return
      call check(error, h%pressure(h%point(1:h%dim), h%normal(1:h%dim)), p0_expected, roundoff, 'p(0) = p0, '//what, &
         & rel=.true.)
   end subroutine check_hertz

   !> The pressure integrates to the load: line contact int p ds = P, point
   !> contact int p 2 pi r dr = F, sampled through `pressure` along a tangent
   !> of an oblique normal. With s = a sin(theta) the integrands are smooth
   !> (cos^2, cos^2 sin) and 20-point Gauss-Legendre is exact to round-off.
   subroutine test_hertz_total_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(hertz_type) :: h
      real(wp) :: x(20), w(20), theta, s, total, n2(2), t2(2), n3(3), t3(3)
      integer :: i

      call gauss_legendre(20, x, w, error)
      if (allocated(error)) return
      n2 = [3.0_wp, 4.0_wp]/5.0_wp
      t2 = [-4.0_wp, 3.0_wp]/5.0_wp
      call new_hertz_cylinder(h, [1.0_wp, 1.0_wp], 2.0_wp*n2, 25.0_wp, 3.0_wp, 1000.0_wp, 0.3_wp, 200.0_wp, 0.25_wp, &
         & plane_strain, error)
      if (allocated(error)) return
      total = 0.0_wp
      do i = 1, 20
         theta = 0.5_wp*pi*x(i)
         s = h%half_width*sin(theta)
         total = total + 0.5_wp*pi*w(i)*h%pressure([1.0_wp, 1.0_wp] + s*t2 + 0.1_wp*n2, n2)*h%half_width*cos(theta)
      end do
      call check(error, total, 3.0_wp, 1.0e-13_wp, 'line contact: int p ds = P', rel=.true.)
      if (allocated(error)) return
      n3 = [2.0_wp, -1.0_wp, 2.0_wp]/3.0_wp
      t3 = [1.0_wp, 2.0_wp, 0.0_wp]/sqrt(5.0_wp)
      call new_hertz_sphere(h, [0.0_wp, 1.0_wp, 0.0_wp], n3, 10.0_wp, 2.0_wp, 1000.0_wp, 0.3_wp, 200.0_wp, 0.25_wp, &
         & error)
      if (allocated(error)) return
      total = 0.0_wp
      do i = 1, 20
         theta = 0.25_wp*pi*(x(i) + 1.0_wp)
         s = h%half_width*sin(theta)
         total = total + 0.25_wp*pi*w(i)*h%pressure([0.0_wp, 1.0_wp, 0.0_wp] + s*t3, n3)*2.0_wp*pi*s* &
            & h%half_width*cos(theta)
      end do
      call check(error, total, 2.0_wp, 1.0e-13_wp, 'point contact: int p dA = F', rel=.true.)
   end subroutine test_hertz_total_force

   !> The Cattaneo-Mindlin traction integrates to the tangential load: int q ds over the
   !> contact = mu P (1 - c^2/a^2) = Q with P = pi a p0/2 (Johnson 1985, sec. 7.1), by
   !> Gauss on each smooth piece (s = c sin t on the stick zone, s = a sin t beyond it).
   subroutine test_cattaneo_mindlin_force(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: a = 0.05_wp, c = 0.035_wp, mu = 0.3_wp, p0 = 13.7_wp
      real(wp) :: x(20), w(20), t, tc, total
      integer :: i

      call gauss_legendre(20, x, w, error)
      if (allocated(error)) return
      tc = asin(c/a)
      total = 0.0_wp
      do i = 1, 20
         t = 0.25_wp*pi*(x(i) + 1.0_wp)
         total = total + 0.25_wp*pi*w(i)*cattaneo_mindlin_traction(c*sin(t), a, c, mu, p0)*c*cos(t)
         t = tc + 0.5_wp*(0.5_wp*pi - tc)*(x(i) + 1.0_wp)
         total = total + 0.5_wp*(0.5_wp*pi - tc)*w(i)*cattaneo_mindlin_traction(a*sin(t), a, c, mu, p0)*a*cos(t)
      end do
      call check(error, 2*total, mu*(0.5_wp*pi*a*p0)*(1 - (c/a)**2), 1.0e-13_wp, 'int q ds = Q', rel=.true.)
      if (allocated(error)) return
      call check(error, cattaneo_mindlin_traction(2*a, a, c, mu, p0), 0.0_wp, 0.0_wp, 'q = 0 outside the contact')
   end subroutine test_cattaneo_mindlin_force

   subroutine test_hertz_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(hertz_type) :: h
      type(error_type), allocatable :: e
      real(wp), parameter :: p2(2) = 0.0_wp, n2(2) = [0.0_wp, 1.0_wp], p3(3) = 0.0_wp, n3(3) = [0.0_wp, 0.0_wp, 1.0_wp]

      call new_hertz_cylinder(h, p2, n2, 1.0_wp, 0.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_strain, e)
      call expect_error(error, e, 'hertz_cylinder: load must be finite and > 0', 'load 0')
      if (allocated(error)) return
      call new_hertz_cylinder(h, p2, n2, -1.0_wp, 1.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_strain, e)
      call expect_error(error, e, 'radius must be finite and > 0', 'radius < 0')
      if (allocated(error)) return
      call new_hertz_cylinder(h, p2, [0.0_wp, 0.0_wp], 1.0_wp, 1.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_strain, e)
      call expect_error(error, e, 'normal must have 2 finite entries, not all zero', 'zero normal')
      if (allocated(error)) return
      call new_hertz_cylinder(h, p3, n2, 1.0_wp, 1.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, plane_strain, e)
      call expect_error(error, e, 'point must have 2 finite entries', 'point in 3D')
      if (allocated(error)) return
      call new_hertz_cylinder(h, p2, n2, 1.0_wp, 1.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, solid, e)
      call expect_error(error, e, 'hertz_cylinder: analysis solid', 'cylinder in solid')
      if (allocated(error)) return
      call new_hertz_cylinder(h, p2, n2, 1.0_wp, 1.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.5_wp, plane_stress, e)
      call expect_error(error, e, 'hertz_cylinder body 2: poisson', 'poisson 0.5')
      if (allocated(error)) return
      call new_hertz_sphere(h, p3, n2, 1.0_wp, 1.0_wp, 1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, e)
      call expect_error(error, e, 'hertz_sphere: normal must have 3', 'sphere normal in 2D')
      if (allocated(error)) return
      call new_hertz_sphere(h, p3, n3, 1.0_wp, 1.0_wp, -1.0_wp, 0.3_wp, 1.0_wp, 0.3_wp, e)
      call expect_error(error, e, 'hertz_sphere body 1: young', 'young < 0')
   end subroutine test_hertz_errors

   ! ------------------------------------------------------------ pressure

   !> p = -n.sigma.n: uniform S = (-3, 1, 2) with n = (0.6, 0.8) gives
   !> -(0.36*(-3) + 0.64*1 + 2*0.48*2) = -1.48; compound rings give p_c on
   !> r = c from either side (n = e_r for the inner, -e_r for the outer).
   subroutine test_field_pressure(error)
      type(error_type), allocatable, intent(out) :: error
      type(uniform_type) :: sol
      type(compound_type) :: cc
      type(field_pressure_type) :: fp
      real(wp) :: e(2)
      character(len=:), allocatable :: fp_label

      call new_uniform(sol, [-3.0_wp, 1.0_wp, 2.0_wp], 5.0_wp, 0.2_wp, plane_strain, error)
      if (allocated(error)) return
      call new_field_pressure(fp, sol)
      call check(error, fp%pressure([4.0_wp, 5.0_wp], [0.6_wp, 0.8_wp]), -1.48_wp, roundoff*3.0_wp, 'uniform p')
      if (allocated(error)) return
      call make_compound(2, cc, fp_label, error)
      if (allocated(error)) return
      e = [0.8_wp, -0.6_wp]
      call new_field_pressure(fp, cc%inner)
      call check(error, fp%pressure(cc%center(1:2) + c*e, e), cc%contact_pressure, roundoff, 'inner ring p_c', &
         & rel=.true.)
      if (allocated(error)) return
      call new_field_pressure(fp, cc%outer)
      call check(error, fp%pressure(cc%center(1:2) + c*e, -e), cc%contact_pressure, roundoff, 'outer ring p_c', &
         & rel=.true.)
   end subroutine test_field_pressure

end module sprc_test_exact_contact
