!> Tests of the contact side of the scene -> analysis glue: the exact
!> solutions of the contact kinds as `build_exact` gives them per body (in
!> each body's analysis units), the exact contact pressure of a pair, and the
!> contact columns of a report row from (synthetic) contact results.
!>
!> Reference values: issue 11's compound cylinder (a = 1, c = 1.5, b = 2,
!> delta = 1e-3): interface pressure 1.080247e-4 (E = 1, nu = 0.3, plane
!> stress), 1.187085e-4 (plane strain), 3.000113e-4 (E_inner = 2, nu_inner =
!> 0.3, E_outer = 1, nu_outer = 0.25, p_in = 1e-3, plane strain), given to 7
!> digits: a tolerance of half a unit in the 7th digit.
module sprc_test_contact_model
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_exact_solution, only: exact_solution_type
   use sprc_exact_pressure, only: exact_pressure_type
   use sprc_io_scene, only: scene_type, read_scene, read_scene_text
   use sprc_study_model, only: build_exact, build_exact_pressure, exact_has_field, analysis_units, &
      & analysis_units_type, in_units
   use sprc_study_row, only: report_row_type, is_empty, report_empty
   use sprc_study_contact_row, only: fill_contact_row, fill_exact_pressure, fill_contact_exact
   use sprc_contact_result, only: contact_result_type, new_contact_result, contact_open, contact_stick, &
      & contact_slip
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed
   use sprc_test_model, only: replaced
   use sprc_test_report, only: read_text_file
   implicit none
   private

   public :: collect_contact_model, contact_sample

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Round-off tier of a few dozen operations on O(1) quantities.
   real(wp), parameter :: roundoff = 64.0_wp*epsilon(1.0_wp)
   character(len=*), parameter :: shrink_fit = 'test/data/scenes/valid/shrink_fit.nml'

contains

   subroutine collect_contact_model(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('compound_two_materials_scene', test_compound_two_materials), &
         new_unittest('compound_one_material_scenes', test_compound_one_material), &
         new_unittest('compound_units_scaled', test_compound_scaled), &
         new_unittest('shrink_fit_example', test_shrink_fit_example), &
         new_unittest('uniform_scene_per_body', test_uniform_scene), &
         new_unittest('hertz_scene_pressure_only', test_hertz_scene), &
         new_unittest('hertz_examples', test_hertz_examples), &
         new_unittest('contact_row_hand_values', test_contact_row), &
         new_unittest('contact_row_without_exact', test_contact_row_no_exact), &
         new_unittest('contact_row_huge_pressure', test_contact_row_huge), &
         new_unittest('fill_exact_pressure', test_fill_exact_pressure), &
         new_unittest('fill_contact_exact_scene', test_fill_contact_exact) &
         ]
   end subroutine collect_contact_model

   ! ------------------------------------------------------------- compound

   !> The shrink fit of test/data (issue 11's two-material case, with p_in and
   !> the moduli 2 and 1 in different analysis units) through scene -> build_exact.
   subroutine test_compound_two_materials(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene

      call read_scene(shrink_fit, scene, error)
      if (allocated(error)) return
      call check_compound(scene, 3.000113e-4_wp, 1.0_wp, error)
   end subroutine test_compound_two_materials

   !> One material (E = 1, nu = 0.3), no internal pressure: plane stress and strain.
   subroutine test_compound_one_material(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: analysis(2) = ['plane_stress', 'plane_strain']
      real(wp), parameter :: expected(2) = [1.080247e-4_wp, 1.187085e-4_wp]
      integer :: k

      do k = 1, 2
         call one_material_text(analysis(k), 1.0_wp, text, error)
         if (allocated(error)) return
         call read_scene_text(text, 'one material '//analysis(k), scene, error)
         if (allocated(error)) return
         call check_compound(scene, expected(k), 1.0_wp, error)
         if (allocated(error)) return
      end do
   end subroutine test_compound_one_material

   !> The two-material case with the moduli and p_in times 1e5 (moduli 2e5 and
   !> 1e5: analysis units 2^17 and 2^16): the pressure scales with them.
   subroutine test_compound_scaled(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      character(len=:), allocatable :: text

      call read_text_file(shrink_fit, text, error)
      if (allocated(error)) return
      text = replaced(text, "young=2.0", "young=2.0e5")
      text = replaced(text, "young=1.0", "young=1.0e5")
      text = replaced(text, "value=1.0e-3", "value=100.0")
      text = replaced(text, "p_in=1.0e-3", "p_in=100.0")
      call read_scene_text(text, 'scaled shrink fit', scene, error)
      if (allocated(error)) return
      call check(error, scene%bodies(1)%young, 2.0e5_wp, 0.0_wp, 'scaled scene read')
      if (allocated(error)) return
      call check_compound(scene, 3.000113e-4_wp, 1.0e5_wp, error)
   end subroutine test_compound_scaled

   !> example/scenes/shrink_fit.nml (steel in aluminium, MPa, bore pressure
   !> 10): its comment's p_c = 3.923350 MPa, from the plane-strain closed form
   !> by hand (f_o, f_i, u_i of sprc_exact_compound's documentation, E' =
   !> E/(1 - nu^2), nu' = nu/(1 - nu)).
   subroutine test_shrink_fit_example(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene

      call read_scene('example/scenes/shrink_fit.nml', scene, error)
      if (allocated(error)) return
      call check_compound(scene, 3.923350e-4_wp, 1.0e4_wp, error)
   end subroutine test_shrink_fit_example

   !> For both rings, built in their own analysis units and converted back to
   !> the scene's, on the real radii (doc/scene.md compound_cylinder: the inner
   !> ring ends at its surface r_s = c + delta, the outer's bore at c):
   !> sigma_rr(r_s) = -p_s on the inner ring, sigma_rr(c) = -p_m on the outer
   !> with equal forces p_s r_s = p_m c, the gap closed (c + u_o(c) = r_s +
   !> u_i(r_s)), sigma_rr = -p_in at the bore, 0 at r_out, and the exact pressure
   !> of the pair on the slave's surface is p_s. p_s agrees with the nominal
   !> closed form's p_c = `reference`*`scale` (by hand, at r_s = c) to first
   !> order in delta/c: within 2 delta/c relative.
   subroutine check_compound(scene, reference, scale, error)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: reference, scale
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), allocatable :: inner, outer
      class(exact_pressure_type), allocatable :: pressure
      real(wp) :: s_unit(2), u_unit(2), sigma(3), ui(2), uo(2), p_s, p_m, c, rs, xs(2), xm(2), x(2)

      c = scene%exact%r_contact
      rs = c + scene%exact%interference
      xs = scene%exact%center + [rs, 0.0_wp]
      xm = scene%exact%center + [c, 0.0_wp]
      call body_exact(scene, scene%exact%inner_index, inner, s_unit(1), u_unit(1), error)
      if (allocated(error)) return
      call body_exact(scene, scene%exact%outer_index, outer, s_unit(2), u_unit(2), error)
      if (allocated(error)) return
      call inner%stress(xs, sigma)
      p_s = -s_unit(1)*sigma(1)
      call check(error, abs(p_s - reference*scale) <= 2.0_wp*scene%exact%interference/c*reference*scale, &
         & 'interface pressure of the inner ring against the nominal closed form')
      if (allocated(error)) return
      call outer%stress(xm, sigma)
      p_m = -s_unit(2)*sigma(1)
      call check(error, p_m*c, p_s*rs, roundoff, 'equal forces on the two surfaces', rel=.true.)
      if (allocated(error)) return
      call inner%stress(scene%exact%center + [scene%exact%r_in, 0.0_wp], sigma)
      call check(error, abs(s_unit(1)*sigma(1) + scene%exact%p_in) <= roundoff*p_s, 'p_in at the bore')
      if (allocated(error)) return
      call outer%stress(scene%exact%center + [scene%exact%r_out, 0.0_wp], sigma)
      call check(error, abs(s_unit(2)*sigma(1)) <= roundoff*p_s, 'free outer surface')
      if (allocated(error)) return
      call inner%displacement(xs, ui)
      call outer%displacement(xm, uo)
      call check(error, u_unit(2)*uo(1) - u_unit(1)*ui(1), scene%exact%interference, roundoff, &
         & 'u_o(c) - u_i(c + delta) = interference: the gap closed', rel=.true.)
      if (allocated(error)) return
      call build_exact_pressure(scene, 1, pressure, error)
      if (allocated(error)) return
      call check(error, allocated(pressure), 'exact pressure of the pair')
      if (allocated(error)) return
      ! The slave (shaft = inner) normal at its surface point on the x axis is +x.
      call check(error, pressure%pressure(xs, [1.0_wp, 0.0_wp]), p_s, roundoff, 'exact contact pressure', rel=.true.)
      if (allocated(error)) return
      x = scene%exact%center + rs*[0.6_wp, 0.8_wp]
      call check(error, pressure%pressure(x, [0.6_wp, 0.8_wp]), p_s, roundoff, &
         & 'exact contact pressure at another slave point', rel=.true.)
   end subroutine check_compound

   !> Issue 11's ring pair, one material (E, nu = 0.3), p_in = 0, in `analysis`.
   subroutine one_material_text(analysis, young, text, error)
      character(len=*), intent(in) :: analysis
      real(wp), intent(in) :: young
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      character(len=32) :: e

      call read_text_file(shrink_fit, text, error)
      if (allocated(error)) return
      write (e, '(es12.5)') young
      text = replaced(text, "'plane_strain'", "'"//analysis//"'")
      text = replaced(text, "young=2.0 poisson=0.3", "young="//trim(adjustl(e))//" poisson=0.3")
      text = replaced(text, "young=1.0 poisson=0.25", "young="//trim(adjustl(e))//" poisson=0.3")
      text = replaced(text, "value=1.0e-3", "value=0.0")
      text = replaced(text, "p_in=1.0e-3", "p_in=0.0")
   end subroutine one_material_text

   ! -------------------------------------------------------------- uniform

   !> The 3D contact patch test of test/data: uniform sigma_zz = -1 in both
   !> blocks (moduli 1 and 3: different analysis units); u = D_b^-1 sigma x
   !> with each block's material; p = 1 on the slave (upper) surface.
   subroutine test_uniform_scene(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_solution_type), allocatable :: exact
      class(exact_pressure_type), allocatable :: pressure
      real(wp) :: s_unit, u_unit, sigma(6), u(3), x(3), expected(3)
      integer :: b

      call read_scene('test/data/scenes/valid/uniform_patch_3d.nml', scene, error)
      if (allocated(error)) return
      call check(error, exact_has_field(scene), 'uniform has a stress field')
      if (allocated(error)) return
      x = [0.3_wp, 0.4_wp, 0.5_wp]
      do b = 1, 2
         call body_exact(scene, b, exact, s_unit, u_unit, error)
         if (allocated(error)) return
         call exact%stress(x, sigma)
         call check(error, maxval(abs(s_unit*sigma - [0, 0, -1, 0, 0, 0])), 0.0_wp, roundoff, &
            & 'uniform stress of body '//scene%bodies(b)%name)
         if (allocated(error)) return
         associate (e => scene%bodies(b)%young, nu => scene%bodies(b)%poisson)
            expected = [nu*x(1), nu*x(2), -x(3)]/e
         end associate
         call exact%displacement(x, u)
         call check(error, maxval(abs(u_unit*u - expected)), 0.0_wp, roundoff*maxval(abs(expected)), &
            & 'u = D^-1 sigma x with the material of body '//scene%bodies(b)%name)
         if (allocated(error)) return
      end do
      call build_exact_pressure(scene, 1, pressure, error)
      if (allocated(error)) return
      call check(error, pressure%pressure(x, [0.0_wp, 0.0_wp, -1.0_wp]), 1.0_wp, roundoff, 'p = -n.sigma.n = 1')
   end subroutine test_uniform_scene

   ! ---------------------------------------------------------------- hertz

   !> The roller of test/data (R = 1, P = 2, E = 1000, nu = 0.3 both, plane
   !> strain): no field in either body; the pair's pressure is Hertz's with
   !> E* = E/(2 (1 - nu^2)), by hand.
   subroutine test_hertz_scene(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_solution_type), allocatable :: exact
      class(exact_pressure_type), allocatable :: pressure
      real(wp) :: e_star, a, p0
      integer :: b

      call read_scene('test/data/scenes/valid/hertz_roller.nml', scene, error)
      if (allocated(error)) return
      call check(error, .not. exact_has_field(scene), 'hertz: pressure only')
      if (allocated(error)) return
      do b = 1, 2
         call build_exact(scene, b, exact, error)
         if (allocated(error)) return
         call check(error, .not. allocated(exact), 'no exact field in body '//scene%bodies(b)%name)
         if (allocated(error)) return
      end do
      call build_exact_pressure(scene, 1, pressure, error)
      if (allocated(error)) return
      e_star = 1000.0_wp/(2.0_wp*(1.0_wp - 0.09_wp))
      a = sqrt(4.0_wp*2.0_wp*1.0_wp/(pi*e_star))
      p0 = 2.0_wp*2.0_wp/(pi*a)
      call check(error, pressure%pressure([0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp]), p0, roundoff, 'p0', rel=.true.)
      if (allocated(error)) return
      call check(error, pressure%pressure([0.5_wp*a, 1.0e-3_wp], [0.0_wp, -1.0_wp]), p0*sqrt(0.75_wp), roundoff, &
         & 'p(a/2)', rel=.true.)
      if (allocated(error)) return
      call check(error, pressure%pressure([1.01_wp*a, 0.0_wp], [0.0_wp, -1.0_wp]), 0.0_wp, 0.0_wp, 'open beyond a')
   end subroutine test_hertz_scene

   !> The peak pressures the example scenes state (hertz_cylinder: p0 =
   !> 13.74, a = 0.05003; hertz_sphere: p0 = 36.02, a = 0.10298), to their
   !> digits, at the first point of contact with the slave's normal.
   subroutine test_hertz_examples(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_pressure_type), allocatable :: pressure

      call read_scene('example/scenes/hertz_cylinder.nml', scene, error)
      if (allocated(error)) return
      call build_exact_pressure(scene, 1, pressure, error)
      if (allocated(error)) return
      call check(error, abs(pressure%pressure([0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp]) - 13.74_wp) <= 0.005_wp, &
         & 'hertz_cylinder example: p0 = 13.74')
      if (allocated(error)) return
      call check(error, pressure%pressure([0.05003_wp, 0.0_wp], [0.0_wp, -1.0_wp]) < 0.3_wp .and. &
         & pressure%pressure([0.05002_wp, 0.0_wp], [0.0_wp, -1.0_wp]) > 0.0_wp, 'hertz_cylinder example: a = 0.05003')
      if (allocated(error)) return
      call read_scene('example/scenes/hertz_sphere.nml', scene, error)
      if (allocated(error)) return
      call build_exact_pressure(scene, 1, pressure, error)
      if (allocated(error)) return
      call check(error, abs(pressure%pressure([0.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, -1.0_wp]) - 36.02_wp) <= &
         & 0.005_wp, 'hertz_sphere example: p0 = 36.02')
      if (allocated(error)) return
      call check(error, pressure%pressure([0.0_wp, 0.102975_wp, 0.0_wp], [0.0_wp, 0.0_wp, -1.0_wp]) > 0.0_wp .and. &
         & .not. (pressure%pressure([0.0_wp, 0.102985_wp, 0.0_wp], [0.0_wp, 0.0_wp, -1.0_wp]) > 0.0_wp), &
         & 'hertz_sphere example: a = 0.10298')
   end subroutine test_hertz_examples

   ! ---------------------------------------------------------- contact row

   !> Two pairs of hand-made results (see `contact_sample`), the row by hand:
   !> measure 0.5 + 1 + 0.25; p_max_fe 4, p_max_sprc 3, p_max_exact 3, SPR not
   !> run; ||p_ex||^2 = 0.5*4 + 4 + 0.25*9 = 8.25, FE error^2 = 1 + 0.25,
   !> SPR-C error^2 = 0.5 + 1 + 0.25; p_max_fe_stress 2.5, FE-stress error^2 =
   !> 0.5*0.25 + 0.25 + 0.25*0.25 + 0.25 = 0.6875; the jumps the worst pair's
   !> (a negative jump is a pair without one).
   subroutine test_contact_row(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type), allocatable :: contacts(:)
      type(report_row_type) :: row
      real(wp), parameter :: jump(3, 2) = reshape([0.1_wp, 0.2_wp, 0.05_wp, -1.0_wp, 0.3_wp, -1.0_wp], [3, 2])

      contacts = contact_sample()
      call fill_contact_row(contacts, row, error, jump)
      if (allocated(error)) return
      call check(error, row%has_contact, 'has_contact')
      if (allocated(error)) return
      call check(error, row%contact_measure, 1.75_wp, 0.0_wp, 'contact_measure: closed points only')
      if (allocated(error)) return
      call check(error, row%p_max_fe, 4.0_wp, 0.0_wp, 'p_max_fe over both pairs')
      if (allocated(error)) return
      call check(error, row%p_max_sprc, 3.0_wp, 0.0_wp, 'p_max_sprc')
      if (allocated(error)) return
      call check(error, row%p_max_exact, 3.0_wp, 0.0_wp, 'p_max_exact')
      if (allocated(error)) return
      call check(error, is_empty(row%p_max_spr) .and. is_empty(row%err_p_spr), 'SPR not run: empty')
      if (allocated(error)) return
      call check(error, row%err_p_fe, sqrt(1.25_wp/8.25_wp), roundoff, 'err_p_fe', rel=.true.)
      if (allocated(error)) return
      call check(error, row%err_p_sprc, sqrt(1.75_wp/8.25_wp), roundoff, 'err_p_sprc', rel=.true.)
      if (allocated(error)) return
      call check(error, row%p_max_fe_stress, 2.5_wp, 0.0_wp, 'p_max_fe_stress')
      if (allocated(error)) return
      call check(error, row%err_p_fe_stress, sqrt(0.6875_wp/8.25_wp), roundoff, 'err_p_fe_stress', rel=.true.)
      if (allocated(error)) return
      call check(error, all([row%jump_fe, row%jump_spr, row%jump_sprc] == [0.1_wp, 0.3_wp, 0.05_wp]), &
         & 'jumps: the worst pair''s')
      if (allocated(error)) return
      call fill_contact_row(contacts, row, error, reshape([-1.0_wp, -1.0_wp, -1.0_wp], [3, 1]))
      if (allocated(error)) return
      call check(error, is_empty(row%jump_fe) .and. is_empty(row%jump_spr) .and. is_empty(row%jump_sprc), &
         & 'no pair with a jump: empty')
   end subroutine test_contact_row

   !> Without an exact pressure the exact and error columns are empty; the
   !> others are not; the same with a zero exact pressure everywhere.
   subroutine test_contact_row_no_exact(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type), allocatable :: contacts(:)
      type(report_row_type) :: row
      integer :: k

      contacts = contact_sample()
      do k = 1, size(contacts)
         contacts(k)%p_exact = report_empty
      end do
      call fill_contact_row(contacts, row, error)
      if (allocated(error)) return
      call check(error, is_empty(row%p_max_exact) .and. is_empty(row%err_p_fe) .and. is_empty(row%err_p_sprc), &
         & 'no exact: p_max_exact and err_p_* empty')
      if (allocated(error)) return
      call check(error, row%p_max_fe, 4.0_wp, 0.0_wp, 'p_max_fe still there')
      if (allocated(error)) return
      do k = 1, size(contacts)
         contacts(k)%p_exact = 0.0_wp
      end do
      call fill_contact_row(contacts, row, error)
      if (allocated(error)) return
      call check(error, row%p_max_exact, 0.0_wp, 0.0_wp, 'zero exact pressure: p_max_exact 0')
      if (allocated(error)) return
      call check(error, is_empty(row%err_p_fe), 'zero exact pressure: no relative error')
   end subroutine test_contact_row_no_exact

   !> The relative pressure error does not overflow when the FE pressure is far
   !> larger than the exact one (a fuzzed load of 1e308): p_fe = 1e300 p_exact
   !> gives err_p_fe = 1e300 - 1 by hand (it was Infinity: the squares of
   !> (p_fe - p_exact)/max|p_exact| overflowed).
   subroutine test_contact_row_huge(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type), allocatable :: contacts(:)
      type(report_row_type) :: row
      integer :: k

      contacts = contact_sample()
      do k = 1, size(contacts)
         contacts(k)%p_fe = 1.0e300_wp*contacts(k)%p_exact
      end do
      call fill_contact_row(contacts, row, error)
      if (allocated(error)) return
      call check(error, row%err_p_fe, 1.0e300_wp - 1.0_wp, roundoff, 'err_p_fe of p_fe = 1e300 p_exact', rel=.true.)
   end subroutine test_contact_row_huge

   !> fill_exact_pressure evaluates at each point with its normal: the uniform
   !> patch test's p = -n.sigma.n = -sigma_zz for n = -e_z, -sigma_xx for n = e_x.
   subroutine test_fill_exact_pressure(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      class(exact_pressure_type), allocatable :: pressure
      type(contact_result_type) :: result
      real(wp) :: x(3, 2), normal(3, 2)

      call read_scene_text("&scene analysis='solid' levels=1 box_min=0,0,0 box_size=2 /"//new_line('a')// &
         & "&body name='a' young=1 poisson=0.3 /"//new_line('a')// &
         & "&body name='b' young=2 poisson=0.2 /"//new_line('a')// &
         & "&shape body='a' op='add' kind='box' name='a_box' lower=0,0,0 upper=1,1,1 /"//new_line('a')// &
         & "&shape body='b' op='add' kind='box' name='b_box' lower=0,0,1 upper=1,1,2 /"//new_line('a')// &
         & "&contact slave='b' master='a' slave_surface='b_box' master_surface='a_box' /"//new_line('a')// &
         & "&exact kind='uniform' stress=-2, 0, -5, 0, 0, 0 /", 'uniform pair', scene, error)
      if (allocated(error)) return
      call build_exact_pressure(scene, 1, pressure, error)
      if (allocated(error)) return
      x = reshape([0.5_wp, 0.5_wp, 1.0_wp, 1.0_wp, 0.5_wp, 1.5_wp], [3, 2])
      normal = reshape([0.0_wp, 0.0_wp, -1.0_wp, 1.0_wp, 0.0_wp, 0.0_wp], [3, 2])
      call new_contact_result(result, x, [0.5_wp, 0.5_wp], normal, 2, 1, error)
      if (allocated(error)) return
      call fill_exact_pressure(pressure, result)
      call check(error, maxval(abs(result%p_exact - [5.0_wp, 2.0_wp])), 0.0_wp, roundoff, 'p_exact at both points')
   end subroutine test_fill_exact_pressure

   !> Through the scene: the shrink fit example's pair (slave = shaft, its
   !> outward normal radial) gets p_c at two points of the interface; a scene
   !> without &exact leaves p_exact empty.
   subroutine test_fill_contact_exact(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(contact_result_type) :: contacts(1)
      real(wp) :: x(2, 2), normal(2, 2)

      call read_scene('example/scenes/shrink_fit.nml', scene, error)
      if (allocated(error)) return
      normal = reshape([1.0_wp, 0.0_wp, sqrt(0.5_wp), sqrt(0.5_wp)], [2, 2])
      x = 20.0_wp*normal
      call new_contact_result(contacts(1), x, [1.0_wp, 1.0_wp], normal, 1, 2, error)
      if (allocated(error)) return
      call fill_contact_exact(scene, contacts, error)
      if (allocated(error)) return
      ! the nominal closed form's p_c by hand; the real radii move it by O(delta/c)
      call check(error, maxval(abs(contacts(1)%p_exact - 3.923350_wp)) <= 2.0_wp*0.002_wp/20.0_wp*3.923350_wp, &
         & 'p_c at both points')
      if (allocated(error)) return
      call read_scene('test/data/scenes/valid/contact_punch.nml', scene, error)
      if (allocated(error)) return
      call new_contact_result(contacts(1), x, [1.0_wp, 1.0_wp], normal, 1, 2, error)
      if (allocated(error)) return
      call fill_contact_exact(scene, contacts, error)
      if (allocated(error)) return
      call check(error, all(is_empty(contacts(1)%p_exact)), 'no &exact: p_exact empty')
   end subroutine test_fill_contact_exact

   !> Two pairs of synthetic results (2D): pair 1 with 3 points (slip, stick,
   !> open; weights 0.5, 1, 0.25), pair 2 with one slipping point (weight
   !> 0.25). p_fe = (2, 1, 0 | 4), p_sprc = (1, 1, 1 | 3), p_exact = (2, 2, 0 | 3),
   !> p_spr empty (SPR not run); gaps, tangential tractions made up.
   function contact_sample() result(contacts)
      type(contact_result_type), allocatable :: contacts(:)
      real(wp) :: x(2, 3), normal(2, 3)
      type(error_type), allocatable :: error

      allocate (contacts(2))
      x = reshape([0.0_wp, 1.0_wp, 0.5_wp, 1.0_wp, 1.0_wp, 1.0_wp], [2, 3])
      normal = reshape([0.0_wp, -1.0_wp, 0.0_wp, -1.0_wp, 0.0_wp, -1.0_wp], [2, 3])
      call new_contact_result(contacts(1), x, [0.5_wp, 1.0_wp, 0.25_wp], normal, 2, 1, error)
      contacts(1)%state = [contact_slip, contact_stick, contact_open]
      contacts(1)%gap = [-1.0e-6_wp, 0.0_wp, 2.5e-3_wp]
      contacts(1)%p_fe = [2.0_wp, 1.0_wp, 0.0_wp]
      contacts(1)%p_sprc = [1.0_wp, 1.0_wp, 1.0_wp]
      contacts(1)%p_exact = [2.0_wp, 2.0_wp, 0.0_wp]
      contacts(1)%p_fe_stress = [2.5_wp, 1.5_wp, 0.5_wp]
      contacts(1)%ts_fe = [0.6_wp, 0.1_wp, 0.0_wp]
      contacts(1)%iterations = 3
      call new_contact_result(contacts(2), reshape([2.0_wp, 1.0_wp], [2, 1]), [0.25_wp], &
         & reshape([0.0_wp, -1.0_wp], [2, 1]), 2, 1, error)
      contacts(2)%state = [contact_slip]
      contacts(2)%gap = [-2.0e-6_wp]
      contacts(2)%p_fe = [4.0_wp]
      contacts(2)%p_sprc = [3.0_wp]
      contacts(2)%p_exact = [3.0_wp]
      contacts(2)%p_fe_stress = [2.0_wp]
      contacts(2)%ts_fe = [1.2_wp]
   end function contact_sample

   ! -------------------------------------------------------------- helpers

   !> Body b's exact solution in its analysis units, and the factors taking its
   !> stresses and displacements back to the scene's units.
   subroutine body_exact(scene, b, exact, s_unit, u_unit, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: b
      class(exact_solution_type), allocatable, intent(out) :: exact
      real(wp), intent(out) :: s_unit, u_unit
      type(error_type), allocatable, intent(out) :: error
      type(analysis_units_type) :: units

      call analysis_units(scene, units, error, b)
      if (allocated(error)) return
      call build_exact(in_units(scene, units), b, exact, error)
      if (allocated(error)) return
      if (.not. allocated(exact)) then
         call test_failed(error, 'no exact solution for body '//scene%bodies(b)%name)
         return
      end if
      s_unit = units%modulus*units%strain
      u_unit = units%strain
   end subroutine body_exact

end module sprc_test_contact_model
