!> Tests of the contact FE (sprc_contact_pair_solve through the study layer).
!>
!> Patch test (issue 11 acceptance): two blocks of different materials on
!> non-matching, offset grids with a flat interface that cuts cells, uniform
!> pressure on top: the FE reproduces sigma_yy = -1 in both blocks and the
!> contact pressure 1 at every slave point, to round-off. The tolerance is
!> C eps / rcond with rcond the block solver's reciprocal 1-norm condition
!> estimate and C = 10 (the backward error of a Cholesky solve, a few eps,
!> carried into the stresses and pressures by operators of norm O(1) in the
!> problem's units).
module sprc_test_contact_fe
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, stat_singular, stat_not_converged
   use sprc_io_namelist, only: read_text_file
   use sprc_study_level, only: study_type, level_type
   use sprc_test_study, only: run_text
   use sprc_contact_result, only: contact_open, contact_stick, contact_slip, contact_result_type
   use sprc_core_material, only: plane_stress, plane_strain, compliance_matrix
   use sprc_exact_compound, only: compound_type, new_compound_cylinder, new_compound_sphere
   use sprc_exact_hertz, only: cattaneo_mindlin_traction
   use sprc_grid_quadrature, only: default_points
   use sprc_study_spec, only: default_kappa
   use sprc_contact_pair_solve, only: master_levels
   use sprc_core_text, only: itoa
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, replaced
   implicit none
   private

   public :: collect_contact_fe

   character(len=*), parameter :: patch_2d = 'test/data/contact/patch_2d.nml'
   character(len=*), parameter :: patch_3d = 'test/data/contact/patch_3d.nml'
   character(len=*), parameter :: hertz_2d = 'test/data/contact/hertz_2d.nml'
   character(len=*), parameter :: incline_2d = 'test/data/contact/incline_2d.nml'
   character(len=*), parameter :: cattaneo_2d = 'test/data/contact/cattaneo_2d.nml'
   character(len=*), parameter :: nl = new_line('a')

contains

   subroutine collect_contact_fe(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('patch_2d_q1', test_patch_2d_q1), &
         new_unittest('patch_2d_q2', test_patch_2d_q2), &
         new_unittest('patch_2d_stick_same_material', test_patch_2d_stick), &
         new_unittest('patch_3d_q1', test_patch_3d_q1), &
         new_unittest('patch_3d_q2', test_patch_3d_q2), &
         new_unittest('patch_2d_q1_linear', test_patch_2d_q1_linear), &
         new_unittest('patch_2d_q2_linear', test_patch_2d_q2_linear), &
         new_unittest('patch_2d_stick_linear', test_patch_2d_stick_linear), &
         new_unittest('patch_3d_q1_linear', test_patch_3d_q1_linear), &
         new_unittest('lost_contact_names_body', test_lost_contact), &
         new_unittest('vee_groove_held_by_both_flanks', test_vee_groove), &
         new_unittest('vee_groove_linear_multiplier', test_vee_groove_linear), &
         new_unittest('vee_groove_assembly_with_lid', test_vee_groove_lid), &
         new_unittest('vee_groove_3d_held_by_both_flanks', test_vee_groove_3d), &
         new_unittest('vee_groove_coulomb_held_by_both_flanks', test_vee_groove_coulomb), &
         new_unittest('shrink_fit_q1_plane_strain', test_shrink_q1), &
         new_unittest('shrink_fit_q2_plane_stress_ratio_1000', test_shrink_q2), &
         new_unittest('shrink_fit_q1_plane_stress_ratio_1000', test_shrink_q1_stress), &
         new_unittest('shrink_fit_q2_plane_strain', test_shrink_q2_strain), &
         new_unittest('hertz_2d', test_hertz_2d), &
         new_unittest('hertz_2d_linear_multiplier', test_hertz_2d_linear), &
         new_unittest('contact_cells_master_ratio', test_master_levels), &
         new_unittest('hertz_2d_master_1pct_coarser', test_hertz_2d_coarser_master), &
         new_unittest('hertz_cylinder_sprc_contact_edge', test_hertz_cylinder_sprc_edge), &
         new_unittest('kappa_decades', test_kappa_decades), &
         new_unittest('incline_stick_exact_frictionless_not', test_incline), &
         new_unittest('bodies_in_contact_share_units', test_units), &
         new_unittest('coulomb_proportional_steps', test_coulomb_steps), &
         new_unittest('coulomb_stages_on_one_surface', test_coulomb_stages), &
         new_unittest('cattaneo_mindlin', test_cattaneo_mindlin), &
         new_unittest('shrink_fit_sphere_q1', test_sphere), &
         new_unittest('patch_2d_q1_recovered', test_patch_2d_q1_recovered), &
         new_unittest('patch_2d_q2_recovered', test_patch_2d_q2_recovered), &
         new_unittest('patch_2d_stick_recovered', test_patch_2d_stick_recovered), &
         new_unittest('patch_3d_q1_recovered', test_patch_3d_q1_recovered), &
         new_unittest('shrink_fit_q1_recovered', test_shrink_q1_recovered), &
         new_unittest('recovered_not_converged', test_recovered_not_converged), &
         new_unittest('recovered_fixed_point', test_recovered_fixed_point) &
         ]
   end subroutine collect_contact_fe

   subroutine test_patch_2d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 1, 3, '', '', 3, error)
   end subroutine test_patch_2d_q1

   subroutine test_patch_2d_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 2, 2, '', '', 3, error)
   end subroutine test_patch_2d_q2

   !> Stick ties the interface: with one material the uniform state has no
   !> relative tangential displacement, so it is still exact.
   subroutine test_patch_2d_stick(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 1, 3, "young=3.0 poisson=0.2", "young=1.0 poisson=0.3", 3, error, stick=.true.)
   end subroutine test_patch_2d_stick

   !> The patch scene at `order` and `level` (optionally one body's material
   !> replaced), checked against the uniform state of normal stress -1 across
   !> the interface (2D sigma_yy, 3D sigma_zz; `ns` Voigt components) and the
   !> contact pressure `p_exact` (default 1) at every closed slave point.
   subroutine patch_case(path, order, level, old, new, ns, error, stick, p_exact, recovered, linear)
      character(len=*), intent(in) :: path, old, new
      integer, intent(in) :: order, level, ns
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: stick
      real(wp), intent(in), optional :: p_exact
      !> With the recovered stabilization (`test_patch_2d_q1_recovered`).
      logical, intent(in), optional :: recovered
      !> With the linear multiplier (`test_patch_2d_q1_linear`).
      logical, intent(in), optional :: linear
      type(level_type) :: result
      real(wp) :: worst, pworst, tol
      character(len=:), allocatable :: text

      call read_text_file(path, text, error)
      if (allocated(error)) return
      text = replaced(text, 'order    = 1', 'order    = '//achar(48 + order))
      if (len(old) > 0) text = replaced(text, old, new)
      if (present(stick)) text = replaced(text, "friction='frictionless'", "friction='stick'")
      if (present(recovered)) text = replaced(text, '&contact ', "&contact stabilization='recovered' ")
      if (present(linear)) text = replaced(text, '&contact ', "&contact multiplier='linear' ")
      call uniform_errors(text, level, ns, result, worst, pworst, tol, error, p_exact)
      if (allocated(error)) return
      if (present(recovered)) tol = tol + sqrt(epsilon(1.0_wp))
      call check(error, worst <= tol, 'uniform stress: max error '//real_text(worst)//' > '//real_text(tol))
      if (allocated(error)) return
      call check(error, all(result%contacts(1)%state /= contact_open), 'every slave point is closed')
      if (allocated(error)) return
      call check(error, pworst <= tol, 'contact pressure: max error '//real_text(pworst)//' > '//real_text(tol))
   end subroutine patch_case

   !> Run the scene `text` at `level`; the largest deviation of the stresses
   !> (scene units) from the uniform state of normal stress -1 across the
   !> x/y plane (`ns` Voigt components), of the closed points' pressures from
   !> `p_exact` (default 1), and the tolerance C eps/rcond (module notes);
   !> with `scale` the stresses and pressures are divided by it first.
   subroutine uniform_errors(text, level, ns, result, worst, pworst, tol, error, p_exact, scale)
      character(len=*), intent(in) :: text
      integer, intent(in) :: level, ns
      type(level_type), intent(out) :: result
      real(wp), intent(out) :: worst, pworst, tol
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: p_exact, scale
      type(study_type) :: study
      real(wp) :: expected(6), unit, sigma(6), p, s
      integer :: b, e, q

      call run_text(text, level, result, error, study)
      if (allocated(error)) return
      s = 1.0_wp
      if (present(scale)) s = scale
      expected = 0.0_wp
      expected(merge(2, 3, ns == 3)) = -1.0_wp
      worst = 0.0_wp
      tol = 0.0_wp
      do b = 1, size(result%bodies)
         associate (pb => result%bodies(b)%problem)
            ! stresses in the body's units: sigma_scene = sigma*unit
            unit = (study%bodies(b)%units%modulus/s)*study%bodies(b)%units%strain
            tol = max(tol, 10.0_wp*epsilon(1.0_wp)/pb%rcond)
            do e = 1, pb%mesh%grid%n_leaves
               do q = pb%mesh%vol_ptr(e), pb%mesh%vol_ptr(e + 1) - 1
                  call pb%stress_in_element(e, pb%mesh%vol_x(:, q), sigma(1:ns))
                  worst = max(worst, maxval(abs(sigma(1:ns)*unit - expected(1:ns))))
               end do
            end do
         end associate
      end do
      p = 1.0_wp
      if (present(p_exact)) p = p_exact
      associate (c => result%contacts(1))
         pworst = maxval(abs(c%p_fe/s - p), c%state /= contact_open)
      end associate
   end subroutine uniform_errors

   !> The block on the inclined interface (tan theta = 0.5): with stick and
   !> with Coulomb mu = 0.6 the uniform stress and the pressure cos^2 theta =
   !> 0.8 are exact; frictionless contact and Coulomb mu = 0.4 cannot carry
   !> the tangential traction 0.4 and are not (their stress error exceeds a
   !> hundred times the round-off tolerance), and mu = 0.4 has slipping points.
   subroutine test_incline(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: worst, pworst, tol

      call read_text_file(incline_2d, text, error)
      if (allocated(error)) return
      call uniform_errors(text, 3, 3, result, worst, pworst, tol, error, p_exact=0.8_wp)
      if (allocated(error)) return
      call check(error, worst <= tol .and. pworst <= tol, 'stick: stress error '//real_text(worst)// &
         & ', pressure error '//real_text(pworst)//', tolerance '//real_text(tol))
      if (allocated(error)) return
      call check(error, abs(maxval(result%contacts(1)%ts_fe) - 0.4_wp) <= tol, 'stick: tangential traction '// &
         & real_text(maxval(result%contacts(1)%ts_fe))//', expected 0.4')
      if (allocated(error)) return
      call uniform_errors(replaced(text, "friction='stick'", "friction='frictionless'"), 3, 3, result, worst, &
         & pworst, tol, error, p_exact=0.8_wp)
      if (allocated(error)) return
      call check(error, worst > 100.0_wp*tol, 'frictionless: stress error '//real_text(worst)//' is round-off')
      if (allocated(error)) return
      ! Coulomb, mu = 0.6 >= tan(theta): every cell sticks, the uniform state is exact.
      call uniform_errors(replaced(text, "friction='stick'", "friction='coulomb' mu=0.6"), 3, 3, result, worst, &
         & pworst, tol, error, p_exact=0.8_wp)
      if (allocated(error)) return
      call check(error, worst <= tol .and. pworst <= tol .and. all(result%contacts(1)%state == contact_stick), &
         & 'coulomb 0.6: stress error '//real_text(worst)//', pressure error '//real_text(pworst)//', tolerance '// &
         & real_text(tol)//' (all stick)')
      if (allocated(error)) return
      ! mu = 0.4 < tan(theta): the interface slips, the uniform state is not the solution.
      call uniform_errors(replaced(text, "friction='stick'", "friction='coulomb' mu=0.4"), 3, 3, result, worst, &
         & pworst, tol, error, p_exact=0.8_wp)
      if (allocated(error)) return
      call check(error, worst > 100.0_wp*tol .and. any(result%contacts(1)%state == contact_slip), &
         & 'coulomb 0.4: stress error '//real_text(worst)//' is round-off, or no point slips')
   end subroutine test_incline

   !> Coulomb friction under proportional loading does not depend on the
   !> increments: the slipping incline (mu = 0.4) in 1 and in 4 steps gives
   !> the same pressures and tangential tractions (to round-off: C eps/rcond
   !> times the pressure scale 1) and the same states.
   subroutine test_coulomb_steps(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: one, four
      character(len=:), allocatable :: text

      call read_text_file(incline_2d, text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='stick'", "friction='coulomb' mu=0.4")
      call same_path_result(text, replaced(text, "mu=0.4", "mu=0.4 steps=4"), one, four, error)
   end subroutine test_coulomb_steps

   !> Two &bc on one surface in stages 1 and 2 (SCENE.md `&bc stage`): their
   !> loads add up, each applied in its own stage. The inclined interface
   !> under Coulomb mu = 0.4 with the pressure 1 as 0.75 in stage 1 and 0.25
   !> in stage 2 is a proportional path: the result of one &bc of pressure 1
   !> to round-off (as `test_coulomb_steps`).
   subroutine test_coulomb_stages(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: one, two
      character(len=:), allocatable :: text

      call read_text_file(incline_2d, text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='stick'", "friction='coulomb' mu=0.4")
      call same_path_result(text, replaced(text, "type='pressure' value=1.0 /", "type='pressure' value=0.75 /"// &
         & nl//"&bc on='upper_top' type='pressure' value=0.25 stage=2 /"), one, two, error)
      if (allocated(error)) return
      call check(error, two%contacts(1)%iterations > one%contacts(1)%iterations, 'one increment only')
   end subroutine test_coulomb_stages

   !> Cattaneo-Mindlin (test/data/contact/cattaneo_2d.nml: a roller on a block
   !> of the same material, mu = 0.3, stage 1 the normal load P, stage 2 the
   !> tangential load Q = 0.5 mu P; Johnson 1985, sec. 7.1), level 3, h =
   !> 2/512 = a/12.8 at the contact. The stick/slip iteration settles (it
   !> cycled between the two slip directions of one cell before), and:
   !> - the stick zone, from the outer edge of its leftmost contact cell to that
   !>   of its rightmost (contact cells are 2h wide and aligned to 2h), ends
   !>   within two cells (2h) of +-c, c = a sqrt(1 - Q/(mu P));
   !> - the tangential traction on the block, q = -t_x of the roller's, is
   !>   within the discretization error of q_ex(x) = mu p0 [sqrt(1 - x^2/a^2) -
   !>   (c/a) sqrt(1 - x^2/c^2)] (the second term for |x| < c) in the slave
   !>   surface's L2 norm: ||q - q_ex|| <= ||q_ex - P0 q_ex|| + mu ||p - p_ex||,
   !>   the distance of q_ex from the piecewise constants on the contact cells
   !>   (the multiplier space; computed here from q_ex alone) plus the error
   !>   that the pressure carries into the slip zones' mu p (p_ex the Hertz
   !>   pressure). Frictionless contact (q = 0) misses it by a factor 3.
   subroutine test_cattaneo_mindlin(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: pi = acos(-1.0_wp), load = 1.0788436_wp, q_load = 2*0.0809163_wp, mu = 0.3_wp
      real(wp), parameter :: e_star = 1000.0_wp/(2*(1 - 0.3_wp**2)), h = 2.0_wp/512
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: a, p0, c, lo, hi, err, bound
      real(wp), allocatable :: q(:), q_ex(:), p_ex(:), q_mean(:)
      integer, allocatable :: cell(:)
      integer :: k

      call read_text_file(cattaneo_2d, text, error)
      if (allocated(error)) return
      call run_text(text, 3, result, error)
      if (allocated(error)) return
      a = sqrt(4*load/(pi*e_star))
      p0 = 2*load/(pi*a)
      c = a*sqrt(1 - q_load/(mu*load))
      associate (r => result%contacts(1), x => result%contacts(1)%x(1, :), w => result%contacts(1)%weight)
         call check(error, any(r%state == contact_stick) .and. any(r%state == contact_slip), 'no stick or no slip')
         if (allocated(error)) return
         lo = floor(minval(x, r%state == contact_stick)/(2*h))*2*h
         hi = ceiling(maxval(x, r%state == contact_stick)/(2*h))*2*h
         call check(error, abs(-lo - c) <= 2*h .and. abs(hi - c) <= 2*h, 'stick zone '//real_text(lo)//' .. '// &
            & real_text(hi)//', c = '//real_text(c)//', h = '//real_text(h))
         if (allocated(error)) return
         q = -r%t_fe(1, :)
         p_ex = p0*sqrt(max(0.0_wp, 1 - (x/a)**2))
         q_ex = cattaneo_mindlin_traction(x, a, c, mu, p0)
         ! P0 q_ex: its mean over each contact cell (open points: q_ex = 0 there).
         cell = floor(x/(2*h))
         allocate (q_mean(size(x)))
         do k = 1, size(x)
            q_mean(k) = sum(w*q_ex, cell == cell(k))/sum(w, cell == cell(k))
         end do
         err = sqrt(sum(w*(q - q_ex)**2))
         bound = sqrt(sum(w*(q_ex - q_mean)**2)) + mu*sqrt(sum(w*(r%p_fe - p_ex)**2))
         call check(error, err <= bound .and. 3*err < sqrt(sum(w*q_ex**2)), '||q - q_ex|| = '//real_text(err)// &
            & ' > '//real_text(bound)//' (best P0 plus mu times the pressure error), or not a third of ||q_ex|| = '// &
            & real_text(sqrt(sum(w*q_ex**2))))
      end associate
   end subroutine test_cattaneo_mindlin

   !> Scenes `text` and `other` at level 3 give the same contact states, and
   !> pressures and tangential tractions to round-off (C eps/rcond times the
   !> pressure scale 1).
   subroutine same_path_result(text, other, one, two, error)
      character(len=*), intent(in) :: text, other
      type(level_type), intent(out) :: one, two
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: tol, diff

      call run_text(text, 3, one, error)
      if (allocated(error)) return
      call run_text(other, 3, two, error)
      if (allocated(error)) return
      tol = 10.0_wp*epsilon(1.0_wp)/min(one%bodies(1)%problem%rcond, two%bodies(1)%problem%rcond)
      diff = max(maxval(abs(one%contacts(1)%p_fe - two%contacts(1)%p_fe)), &
         & maxval(abs(one%contacts(1)%ts_fe - two%contacts(1)%ts_fe)))
      call check(error, all(one%contacts(1)%state == two%contacts(1)%state), 'states differ')
      if (allocated(error)) return
      call check(error, diff <= tol, 'pressures or tractions differ by '//real_text(diff)//' > '//real_text(tol))
   end subroutine same_path_result

   !> Bodies in contact share one unit system: the inclined-interface stick
   !> test with the modulus scaled by 1e200 and the pressure by 4e200 (alone,
   !> the lower body, which carries no load of its own, would get a
   !> displacement unit 4 times the upper one's, and the tied interface would
   !> mix them) gives the uniform stress and the pressure, 4e200 times those
   !> of the unscaled test, to round-off.
   subroutine test_units(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: worst, pworst, tol

      call read_text_file(incline_2d, text, error)
      if (allocated(error)) return
      text = replaced(text, "young=1.0 poisson=0.3 box_min=-0.1", "young=1.0e200 poisson=0.3 box_min=-0.1")
      text = replaced(text, "young=1.0 poisson=0.3 box_min=-0.2", "young=1.0e200 poisson=0.3 box_min=-0.2")
      text = replaced(text, "type='pressure' value=1.0", "type='pressure' value=4.0e200")
      call uniform_errors(text, 3, 3, result, worst, pworst, tol, error, p_exact=0.8_wp, scale=4.0e200_wp)
      if (allocated(error)) return
      call check(error, worst <= tol .and. pworst <= tol, 'stress error '//real_text(worst)//', pressure error '// &
         & real_text(pworst)//' (relative to 4e200) > '//real_text(tol))
   end subroutine test_units

   subroutine test_patch_3d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_3d, 1, 2, '', '', 6, error)
   end subroutine test_patch_3d_q1

   subroutine test_patch_3d_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_3d, 2, 1, '', '', 6, error)
   end subroutine test_patch_3d_q2

   !> The patch tests with the linear multiplier (sprc_contact_pair_solve notes):
   !> its hats sum to one at every point, so the uniform pressure is in the
   !> space and every point's pressure is exact to the solve's round-off.
   subroutine test_patch_2d_q1_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 1, 3, '', '', 3, error, linear=.true.)
   end subroutine test_patch_2d_q1_linear

   subroutine test_patch_2d_q2_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 2, 2, '', '', 3, error, linear=.true.)
   end subroutine test_patch_2d_q2_linear

   subroutine test_patch_2d_stick_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 1, 3, "young=3.0 poisson=0.2", "young=1.0 poisson=0.3", 3, error, stick=.true., &
         & linear=.true.)
   end subroutine test_patch_2d_stick_linear

   subroutine test_patch_3d_q1_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_3d, 1, 2, '', '', 6, error, linear=.true.)
   end subroutine test_patch_3d_q1_linear

   !> A body held only by contact whose contact surface is far from the master
   !> surface: an error naming the body, not a singular-matrix message.
   subroutine test_lost_contact(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      type(error_type), allocatable :: failed
      character(len=:), allocatable :: text

      call read_text_file(patch_2d, text, error)
      if (allocated(error)) return
      ! lift the upper block 0.3 above the lower one (more than one cell)
      text = replaced(text, "name='upper_bottom' point=0,0.55", "name='upper_bottom' point=0,0.85")
      call run_text(text, 3, result, failed)
      if (.not. allocated(failed)) then
         call test_failed(error, 'a body held by nothing was solved')
         return
      end if
      call check(error, failed%stat, stat_singular, 'status singular')
      if (allocated(error)) return
      call check(error, index(failed%message, "body 'upper' is not held: translation y") > 0, &
         & 'message: '//failed%message)
   end subroutine test_lost_contact

   !> A wedge pressed into a V-groove (test/data/contact/vee_groove.nml)
   !> touches one flank first and is held only once both are closed: the
   !> first active set (its first contact, one flank) leaves it free to
   !> slide, and the solve must start again from every candidate cell
   !> rather than report it not held. Level 4: three contact cells per
   !> flank (at level 3 one per flank, whose mean gaps leave the rotation
   !> free). Every point closed, and equilibrium, which the discrete system
   !> keeps exactly (the slave's rigid translations are in its FE space and
   !> carry no stress; the load, normal to the top, has no x part): the two
   !> flanks' normal forces equal to a sqrt(eps) tier (x), each positive,
   !> and their sum within 1 % of the load's normal share 2 (1.79/sqrt(2))
   !> (y: the discrete load is the pressure over the top edge as the cut
   !> cells locate its ends, not exactly 1.79).
   subroutine test_vee_groove(error)
      type(error_type), allocatable, intent(out) :: error
      call vee_groove_case('', 4, error)
   end subroutine test_vee_groove

   !> The same with the linear multiplier (its closed nodes' hats are cut
   !> anew for the widened set), at level 5: at level 4 its four nodes, two
   !> per flank, leave the wedge free even with every node closed.
   subroutine test_vee_groove_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call vee_groove_case(" multiplier='linear'", 5, error)
   end subroutine test_vee_groove_linear

   !> The same wedge under a lid that carries the pressure (three bodies,
   !> two pairs: `solve_contact_assembly`): the lid, held in x by a
   !> symmetry condition on its left side, follows the wedge down as it
   !> slides along the first flank, so the assembly's first set leaves both
   !> free. Both flanks close and carry the load: the lid's force is its
   !> pressure over its top, 1.6, and
   !> the flanks' forces are equal and sum to 1.6 sqrt(2) to a sqrt(eps)
   !> tier.
   subroutine test_vee_groove_lid(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: force(2), share

      call read_text_file('test/data/contact/vee_groove.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "&bc    on='wedge_top'  type='pressure' value=1.0 /", &
         & "&body  name='lid' young=1.0 poisson=0.3 box_min=-0.85, 0.85 box_size=1.7 /"//nl// &
         & "&shape body='lid' op='add' kind='box' name='lid_box' lower=-1,0.5 upper=0.8,1.5 /"//nl// &
         & "&shape body='lid' op='intersect' kind='halfspace' name='lid_left' point=-0.8,0 normal=-1,0 /"//nl// &
         & "&shape body='lid' op='intersect' kind='halfspace' name='lid_top' point=0,1.1 normal=0,1 /"//nl// &
         & "&shape body='lid' op='intersect' kind='halfspace' name='lid_bottom' point=0,0.9 normal=0,-1 /"//nl// &
         & "&bc    on='lid_left' type='symmetry' /"//nl// &
         & "&bc    on='lid_top'  type='pressure' value=1.0 /"//nl// &
         & "&contact slave='lid' master='wedge' slave_surface='lid_bottom' master_surface='wedge_top' /")
      call run_text(text, 4, result, error)
      if (allocated(error)) return
      ! the lid's pair comes first in the scene
      associate (c => result%contacts(2))
         call check(error, all(c%state /= contact_open), itoa(count(c%state == contact_open))//' points open')
         if (allocated(error)) return
         share = 1.6_wp/sqrt(2.0_wp)
         force = flank_forces(c)
         call check(error, maxval(abs(force - share)) <= sqrt(epsilon(1.0_wp))*share, 'flank forces '// &
            & real_text(force(1))//', '//real_text(force(2))//' (expected '//real_text(share)//' each)')
      end associate
   end subroutine test_vee_groove_lid

   !> The V-groove in 3D (test/data/contact/vee_groove_3d.nml: the wedge and
   !> the notch are OBJ prisms, a slab 0.6 thick between grid planes, the
   !> wedge on symmetry planes at both ends): the first contact, the left
   !> flank, leaves the wedge free to slide, the widened set holds it. Every
   !> point closed; the flanks' normal forces equal to a sqrt(eps) tier
   !> (x equilibrium) and sum to twice the load's normal share (1.79 * 0.6 /
   !> sqrt(2) each) within 1 %. The forces balance the discrete load, whose
   !> top measures 1.08 against 1.074 (+0.56 %, as the forces; kappa 1e2 to
   !> 1e8 alike): the top is a halfspace on a grid plane that the prism's
   !> facets cross, and the quadrature decides such a face part by
   !> membership, not by clipping it to the facets (doc/scene.md, `sprc
   !> mesh`).
   subroutine test_vee_groove_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: force(2), share

      call read_text_file('test/data/contact/vee_groove_3d.nml', text, error)
      if (allocated(error)) return
      text = replaced(replaced(text, "file='vee_wedge.obj'", "file='test/data/contact/vee_wedge.obj'"), &
         & "file='vee_notch.obj'", "file='test/data/contact/vee_notch.obj'")
      call run_text(text, 4, result, error)
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call check(error, all(c%state /= contact_open), itoa(count(c%state == contact_open))//' points open')
         if (allocated(error)) return
         share = 1.79_wp*0.6_wp/sqrt(2.0_wp)
         force = flank_forces(c)
         call check(error, abs(force(1) - force(2)) <= sqrt(epsilon(1.0_wp))*share .and. all(force > 0.0_wp) .and. &
            & abs(sum(force) - 2.0_wp*share) <= 2.0e-2_wp*share, 'flank forces '//real_text(force(1))//', '// &
            & real_text(force(2))//' (expected '//real_text(share)//' each)')
      end associate
   end subroutine test_vee_groove_3d

   !> The 2D V-groove with Coulomb friction, mu = 0.2 (below tan 45 degrees, so
   !> the wedge slides along the first flank until the second closes). The
   !> first active-set iteration holds it by stick on the first flank, so the
   !> widening is not what is tested here (the test passes without it); the
   !> slip iterations must close the second flank: every point closed. The contact tractions -p n + t over
   !> the flanks balance the load (0, -1.79): their x sum vanishes to a
   !> sqrt(eps) tier, their y sum is within 1 % of 1.79; friction acts: the
   !> tangential force is nonzero and at most mu times the normal force.
   subroutine test_vee_groove_coulomb(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: total(2), normal_force, tangential
      integer :: i

      call read_text_file('test/data/contact/vee_groove.nml', text, error)
      if (allocated(error)) return
      call run_text(replaced(text, "friction='frictionless'", "friction='coulomb' mu=0.2"), 4, result, error)
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call check(error, all(c%state /= contact_open), itoa(count(c%state == contact_open))//' points open')
         if (allocated(error)) return
         total = 0.0_wp
         normal_force = 0.0_wp
         tangential = 0.0_wp
         do i = 1, c%npoint
            total = total + c%weight(i)*(-c%p_fe(i)*c%normal(:, i) + c%t_fe(:, i))
            normal_force = normal_force + c%weight(i)*c%p_fe(i)
            tangential = tangential + c%weight(i)*norm2(c%t_fe(:, i))
         end do
         call check(error, abs(total(1)) <= sqrt(epsilon(1.0_wp))*1.79_wp .and. &
            & abs(total(2) - 1.79_wp) <= 1.0e-2_wp*1.79_wp, 'contact force '//real_text(total(1))//', '// &
            & real_text(total(2))//' (expected 0, 1.79)')
         if (allocated(error)) return
         call check(error, tangential > 1.0e-3_wp*normal_force .and. &
            & tangential <= 0.2_wp*normal_force*(1.0_wp + sqrt(epsilon(1.0_wp))), 'tangential force '// &
            & real_text(tangential)//' against mu times the normal force '//real_text(0.2_wp*normal_force))
      end associate
   end subroutine test_vee_groove_coulomb

   subroutine vee_groove_case(keys, level, error)
      character(len=*), intent(in) :: keys
      integer, intent(in) :: level
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: force(2), share

      call read_text_file('test/data/contact/vee_groove.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='frictionless'", "friction='frictionless'"//keys)
      call run_text(text, level, result, error)
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call check(error, all(c%state /= contact_open), itoa(count(c%state == contact_open))//' points open')
         if (allocated(error)) return
         share = 1.79_wp/sqrt(2.0_wp)
         force = flank_forces(c)
         call check(error, abs(force(1) - force(2)) <= sqrt(epsilon(1.0_wp))*share .and. all(force > 0.0_wp) .and. &
            & abs(sum(force) - 2.0_wp*share) <= 1.0e-2_wp*share, 'flank forces '//real_text(force(1))//', '// &
            & real_text(force(2))//' (expected '//real_text(share)//' each)')
      end associate
   end subroutine vee_groove_case

   !> The normal forces sum p_fe w on the V-groove's left flank (outward slave
   !> normal with n_x < 0) and on its right one.
   pure function flank_forces(c) result(force)
      type(contact_result_type), intent(in) :: c
      real(wp) :: force(2)
      force(1) = sum(c%p_fe*c%weight, mask=c%normal(1, :) < 0.0_wp)
      force(2) = sum(c%p_fe*c%weight, mask=c%normal(1, :) > 0.0_wp)
   end function flank_forces

   !> Shrink fit (compound cylinder, quarter model): shaft 1 < r < 1.5 + delta
   !> pressed into a hub 1.5 < r < 2 (radial interference delta = 1e-5, small so
   !> that the geometry matches the exact solution's, modelled at r = 1.5, to
   !> 7e-6), bore pressure 1e-3, frictionless. Q1, plane strain, E 2 / 1.
   subroutine test_shrink_q1(error)
      type(error_type), allocatable, intent(out) :: error
      call shrink_case(1, 'plane_strain', 2.0_wp, [4, 5, 6], error)
   end subroutine test_shrink_q1

   !> The same, Q2, plane stress, the shaft 1000 times stiffer than the hub.
   subroutine test_shrink_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call shrink_case(2, 'plane_stress', 1000.0_wp, [3, 4, 5], error)
   end subroutine test_shrink_q2

   !> The other two corners of issue 11's shrink-fit matrix: Q1 in plane
   !> stress with the shaft 1000 times stiffer than the hub (the p_c of the
   !> interference alone is then 1e-3 of the bore pressure's share), and Q2
   !> in plane strain with the materials of `test_shrink_q1`.
   subroutine test_shrink_q1_stress(error)
      type(error_type), allocatable, intent(out) :: error
      call shrink_case(1, 'plane_stress', 1000.0_wp, [4, 5, 6], error)
   end subroutine test_shrink_q1_stress

   subroutine test_shrink_q2_strain(error)
      type(error_type), allocatable, intent(out) :: error
      call shrink_case(2, 'plane_strain', 2.0_wp, [3, 4, 5], error)
   end subroutine test_shrink_q2_strain

   !> err_fe over three `levels` against the compound cylinder: the rate over
   !> them is at least 0.95 p (issue 11), the pressure error at the finest
   !> level at most err_fe, every slave point closed, and at every level the
   !> closed measure (the report's contact_measure) the quarter circumference
   !> of the slave surface, pi/2 * 1.50001, within the cut-cell quadrature
   !> tolerance (`measure_tolerance`).
   subroutine shrink_case(order, analysis, young_shaft, levels, error, kappa, stabilization)
      integer, intent(in) :: order
      character(len=*), intent(in) :: analysis
      real(wp), intent(in) :: young_shaft
      integer, intent(in) :: levels(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: kappa
      character(len=*), intent(in), optional :: stabilization
      type(compound_type) :: exact
      type(level_type) :: result
      type(study_type) :: study
      character(len=:), allocatable :: text
      character(len=32) :: buf
      real(wp) :: err(size(levels)), perr(size(levels)), rate
      integer :: i, n

      call shrink_exact(analysis, young_shaft, exact, error)
      if (allocated(error)) return
      text = shrink_text(order, analysis, young_shaft, kappa, stabilization)
      do i = 1, size(levels)
         call run_text(text, levels(i), result, error, study)
         if (allocated(error)) return
         err(i) = energy_error_pair(study, result, exact)
         perr(i) = pressure_error(result%contacts(1), exact%contact_pressure)
         call check(error, all(result%contacts(1)%state /= contact_open), 'every slave point closed')
         if (allocated(error)) return
         call check_measure(result%contacts(1), 0.5_wp*acos(-1.0_wp)*1.50001_wp, order, error)
         if (allocated(error)) return
      end do
      n = size(levels)
      rate = log(err(n - 2)/err(n))/log(real(2**(levels(n) - levels(n - 2)), wp))
      write (buf, '(f6.3)') rate
      call check(error, rate >= 0.95_wp*order, 'err_fe rate '//trim(buf)//' < 0.95 p')
      if (allocated(error)) return
      ! The relative L2 pressure error is no larger than the relative energy
      ! error of the stresses (measured: 0.5 and 0.4 times it at the finest level).
      call check(error, perr(n) <= err(n), 'pressure error '//real_text(perr(n))//' > err_fe '//real_text(err(n)))
      if (allocated(error)) return
      ! With a stable multiplier space (sprc_contact_pair_solve: macro cells) the a
      ! priori estimate h^(1/2) |lambda - lambda_h|_L2 <= C h^p gives a rate of
      ! at least 1/2 for the L2 pressure error; a checkerboard mode stalls it.
      rate = log(perr(n - 2)/perr(n))/log(real(2**(levels(n) - levels(n - 2)), wp))
      write (buf, '(f6.3)') rate
      call check(error, rate >= 0.95_wp*0.5_wp, 'err_p_fe rate '//trim(buf)//' < 0.95/2 (pressure errors '// &
         & real_text(perr(n - 2))//', '//real_text(perr(n))//')')
   end subroutine shrink_case

   !> The compound cylinder of `shrink_text`'s shrink fit.
   subroutine shrink_exact(analysis, young_shaft, exact, error)
      character(len=*), intent(in) :: analysis
      real(wp), intent(in) :: young_shaft
      type(compound_type), intent(out) :: exact
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: delta = 1.0e-5_wp, p_in = 1.0e-3_wp
      call new_compound_cylinder(exact, [0.0_wp, 0.0_wp], 1.0_wp, 1.5_wp, 2.0_wp, p_in, delta, young_shaft, 0.3_wp, &
         & 1.0_wp, 0.25_wp, merge(plane_stress, plane_strain, analysis == 'plane_stress'), error)
   end subroutine shrink_exact

   !> The scene of `shrink_case` (quarter model, shaft slave, bore pressure
   !> 1e-3, interference 1e-5), with `kappa` and `stabilization` when given.
   function shrink_text(order, analysis, young_shaft, kappa, stabilization) result(text)
      integer, intent(in) :: order
      character(len=*), intent(in) :: analysis
      real(wp), intent(in) :: young_shaft
      real(wp), intent(in), optional :: kappa
      character(len=*), intent(in), optional :: stabilization
      character(len=:), allocatable :: text
      character(len=32) :: buf
      write (buf, '(es23.16)') young_shaft
      text = "&scene title='shrink fit' analysis='"//analysis//"' order="//achar(48 + order)// &
         & " levels=3 box_min=0,0 box_size=2.5 recovery='none' output='' /"//nl// &
         & "&body name='shaft' young="//trim(buf)//" poisson=0.3 /"//nl// &
         & "&body name='hub' young=1.0 poisson=0.25 box_min=0.0,0.0 box_size=2.2 /"//nl// &
         & "&shape body='shaft' op='add' kind='disk' name='shaft_out' center=0,0 radius=1.50001 /"//nl// &
         & "&shape body='shaft' op='subtract' kind='disk' name='bore' center=0,0 radius=1 /"//nl// &
         & "&shape body='shaft' op='intersect' kind='halfspace' name='shaft_sx' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='shaft' op='intersect' kind='halfspace' name='shaft_sy' point=0,0 normal=0,-1 /"//nl// &
         & "&shape body='hub' op='add' kind='disk' name='hub_out' center=0,0 radius=2 /"//nl// &
         & "&shape body='hub' op='subtract' kind='disk' name='hub_in' center=0,0 radius=1.5 /"//nl// &
         & "&shape body='hub' op='intersect' kind='halfspace' name='hub_sx' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='hub' op='intersect' kind='halfspace' name='hub_sy' point=0,0 normal=0,-1 /"//nl// &
         & "&bc on='bore' type='pressure' value=1.0e-3 /"//nl// &
         & "&bc on='shaft_sx' type='symmetry' /"//nl//"&bc on='shaft_sy' type='symmetry' /"//nl// &
         & "&bc on='hub_sx' type='symmetry' /"//nl//"&bc on='hub_sy' type='symmetry' /"//nl// &
         & "&contact slave='shaft' master='hub' slave_surface='shaft_out' master_surface='hub_in'"
      if (present(kappa)) text = text//" kappa="//real_text(kappa)
      if (present(stabilization)) text = text//" stabilization='"//stabilization//"'"
      text = text//" /"//nl
   end function shrink_text

   !> Hertz line contact (test/data/contact/hertz_2d.nml, a = 0.05, p0 =
   !> 2P/(pi a)): at h = a/25.6 on the contact (issue 11: h <= a/12) the peak
   !> FE pressure is within 3 % of p0 and the closed half-width (the report's
   !> contact_measure, the closed points' weights) within one slave cell of a.
   subroutine test_hertz_2d(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: a = 0.05_wp, load = 1.0788436_wp, pi = acos(-1.0_wp), h = 2.0_wp/1024
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: p0, pmax, width

      call read_text_file(hertz_2d, text, error)
      if (allocated(error)) return
      call run_text(text, 6, result, error)
      if (allocated(error)) return
      p0 = 2.0_wp*load/(pi*a)
      associate (c => result%contacts(1))
         pmax = maxval(c%p_fe)
         width = sum(c%weight, mask=c%state /= contact_open)
      end associate
      call check(error, abs(pmax/p0 - 1.0_wp) <= 0.03_wp, 'p_max/p0 = '//real_text(pmax/p0))
      if (allocated(error)) return
      call check(error, abs(width - a) <= h, 'closed half-width '//real_text(width)//', a = 0.05, h = '//real_text(h))
   end subroutine test_hertz_2d

   !> The linear multiplier follows the Hertz pressure p0 sqrt(1 - x^2/a^2)
   !> closer than any multiplier constant on its contact cells can: at level
   !> 5 (h = a/12.8, contact cells 2h = a/6.4 wide), the roller's grid
   !> offset by 0.4 h and by 1.4 h, its relative L2 error over the slave
   !> surface is below 6.30 %, the least L2 projection error of the exact
   !> pressure onto piecewise constants on cells a/6.4 wide over every
   !> offset of the cells (computed from the closed form by quadrature, 6e5
   !> points: 6.30 % to 8.98 %). Measured 4.80 % and 4.14 % with the
   !> active set per point (the contact edge where the pressure changes
   !> sign); with the edge at the midpoint between nodes the active set at
   !> 1.4 h cycled and never settled. No pressure where the state is open.
   subroutine test_hertz_2d_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call hertz_offset_case('linear', '-0.0015625', error)
      if (.not. allocated(error)) call hertz_offset_case('linear', '-0.00546875', error)
   end subroutine test_hertz_2d_linear

   !> A contact cell is two slave cells wide over master cells up to a
   !> quarter level larger (equal grids on root boxes 1 % apart), and spans
   !> two master cells beyond: 2^(levels+1) slave cells >= 2 master cells
   !> once the ratio exceeds 2^(1/4), never more than the next power of two.
   subroutine test_master_levels(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: ratio(8) = [0.5_wp, 1.0_wp, 1.01_wp, 1.15_wp, 1.3_wp, 2.0_wp, 2.02_wp, 4.0_wp]
      integer, parameter :: expected(8) = [0, 0, 0, 0, 1, 1, 1, 2]
      integer :: i
      do i = 1, size(ratio)
         call check(error, master_levels(ratio(i)) == expected(i), 'master cells '//real_text(ratio(i))// &
            & ' times the slave''s: '//itoa(master_levels(ratio(i)))//' levels, expected '//itoa(expected(i)))
         if (allocated(error)) return
      end do
   end subroutine test_master_levels

   !> The Hertz case of `test_hertz_2d` at level 5 (h = a/12.8) with the
   !> block's grid 1 % coarser than the roller's: the contact cells stay two
   !> slave cells (a/6.4) wide, as on equal grids. Cells of four slave cells
   !> (a/3.2) cannot bring the constant multiplier's relative L2 pressure
   !> error below 10.83 %, the least L2 projection error of the exact
   !> pressure onto constants on such cells over every offset (closed form
   !> by quadrature, 3e5 points; 10.83 % to 16.69 %). Measured: 9.8 % (9.4 %
   !> on equal grids).
   subroutine test_hertz_2d_coarser_master(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: bound = 0.1083_wp
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: rel

      call read_text_file(hertz_2d, text, error)
      if (allocated(error)) return
      text = replaced(text, "box_min=0.0, -1.99 box_size=2.0", "box_min=0.0, -1.99 box_size=2.02")
      call run_text(text, 5, result, error)
      if (allocated(error)) return
      rel = hertz_2d_multiplier_error(result%contacts(1))
      call check(error, rel < bound, 'relative L2 pressure error '//real_text(rel)//' >= '//real_text(bound))
   end subroutine test_hertz_2d_coarser_master

   !> SPR-C's contact-edge field (doc/scene.md `&contact edges`) on the Hertz cylinder
   !> (example/scenes/hertz_cylinder.nml, level 6: h = a/3.2, its exact pressure): the recovered
   !> pressure's relative L2 error over the slave surface against the FE stresses' (-n.sigma_h.n),
   !> with the field and without it. The issue's target is a factor 3 at h = a/6.4 and a/12.8
   !> (doc/benchmarks.md, measured 3.76 and 3.01). The claim at this coarse level is the gain
   !> of point and amplitude from the gaps beyond the edge: 1.89 with them, 1.54 with both fitted
   !> to the stresses (the FE states place the edge within a contact cell only; the patches'
   !> states on the edge's side and pressures clipped at 0 alike), 1.37 before either, 1.33
   !> without the field. The bound, 1.75, lies between the first two. The field must also beat
   !> the polynomials alone.
   subroutine test_hertz_cylinder_sprc_edge(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: factor = 1.75_wp
      real(wp) :: rel(2), fe_stress
      integer :: k

      do k = 1, 2
         call sprc_pressure_error(merge('.true. ', '.false.', k == 1), rel(k), fe_stress, error)
         if (allocated(error)) return
      end do
      call check(error, rel(1) < rel(2), 'err_p_sprc with the edge field '//real_text(rel(1))// &
         & ', without '//real_text(rel(2))//': not smaller')
      if (allocated(error)) return
      call check(error, factor*rel(1) <= fe_stress, 'err_p_sprc with the edge field '//real_text(rel(1))// &
         & ', of the FE stresses '//real_text(fe_stress)//': not '//real_text(factor)//' times smaller')
   end subroutine test_hertz_cylinder_sprc_edge

   !> err_p_sprc and err_p_fe_stress of the Hertz cylinder at level 6 with edges = `edges`.
   subroutine sprc_pressure_error(edges, rel, fe_stress, error)
      character(len=*), intent(in) :: edges
      real(wp), intent(out) :: rel, fe_stress
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text

      rel = huge(1.0_wp)
      fe_stress = 0.0_wp
      call read_text_file('example/scenes/hertz_cylinder.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "recovery = 'both'", "recovery = 'sprc'")
      text = replaced(text, "output   = 'out/hertz_cylinder'", "output   = ''")
      text = replaced(text, '&contact ', '&contact edges='//trim(edges)//' ')
      call run_text(text, 6, result, error)
      if (allocated(error)) return
      rel = result%row%err_p_sprc
      fe_stress = result%row%err_p_fe_stress
   end subroutine sprc_pressure_error

   !> `test_hertz_2d_linear` with the multiplier space `multiplier`.
   subroutine hertz_offset_case(multiplier, shift, error)
      character(len=*), intent(in) :: multiplier
      !> The roller's box_min x (its grid's offset).
      character(len=*), intent(in) :: shift
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: bound = 0.0630_wp
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: rel

      call read_text_file(hertz_2d, text, error)
      if (allocated(error)) return
      text = replaced(text, "box_min=0.0, 0.0 box_size=2.0", "box_min="//shift//", 0.0 box_size=2.0")
      text = replaced(text, '&contact ', "&contact multiplier='"//multiplier//"' ")
      call run_text(text, 5, result, error)
      if (allocated(error)) return
      rel = hertz_2d_multiplier_error(result%contacts(1))
      call check(error, rel < bound, 'roller at x = '//shift//': relative L2 pressure error '//real_text(rel)// &
         & ' >= '//real_text(bound))
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call check(error, all(c%p_fe == 0.0_wp .or. c%state /= contact_open), 'pressure '// &
            & real_text(maxval(c%p_fe, mask=c%state == contact_open))//' at an open point')
      end associate
   end subroutine hertz_offset_case

   !> The contact multiplier's relative L2 pressure error over the slave
   !> points of test/data hertz_2d (a = 0.05, load 1.0788436 per unit
   !> length) against Hertz's pressure p0 sqrt(1 - (x/a)^2).
   function hertz_2d_multiplier_error(c) result(rel)
      type(contact_result_type), intent(in) :: c
      real(wp) :: rel
      real(wp), parameter :: a = 0.05_wp, load = 1.0788436_wp, pi = acos(-1.0_wp)
      real(wp) :: p0, p_ex(size(c%weight))
      p0 = 2.0_wp*load/(pi*a)
      p_ex = p0*sqrt(max(0.0_wp, 1.0_wp - (c%x(1, :)/a)**2))
      rel = sqrt(sum(c%weight*(c%p_fe - p_ex)**2)/sum(c%weight*p_ex**2))
   end function hertz_2d_multiplier_error

   !> Issue 11's kappa sweep: err_fe and p_max_fe at a hundredth and a
   !> hundred times `default_kappa` within 1 % (the issue's bound) of those
   !> at the default, on the shrink fit with a Q2 shaft 1000 times stiffer
   !> than the hub (plane stress, level 3), the case whose coercivity needs
   !> the largest kappa. It fails with the former default 1000: at 10 err_fe
   !> is 30 % higher.
   subroutine test_kappa_decades(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: factor(3) = [1.0_wp, 0.01_wp, 100.0_wp]
      type(compound_type) :: exact
      type(level_type) :: result
      type(study_type) :: study
      real(wp) :: err(3), pmax(3)
      integer :: i

      call shrink_exact('plane_stress', 1000.0_wp, exact, error)
      if (allocated(error)) return
      do i = 1, 3
         call run_text(shrink_text(2, 'plane_stress', 1000.0_wp, factor(i)*default_kappa), 3, result, error, study)
         if (allocated(error)) return
         err(i) = energy_error_pair(study, result, exact)
         pmax(i) = maxval(result%contacts(1)%p_fe)
      end do
      do i = 2, 3
         call check(error, abs(err(i)/err(1) - 1.0_wp) < 0.01_wp .and. abs(pmax(i)/pmax(1) - 1.0_wp) < 0.01_wp, &
            & 'kappa = '//real_text(factor(i)*default_kappa)//': err_fe '//real_text(err(i))//', p_max_fe '// &
            & real_text(pmax(i))//' against '//real_text(err(1))//', '//real_text(pmax(1))//' at the default')
         if (allocated(error)) return
      end do
   end subroutine test_kappa_decades

   !> Compound sphere (octant): the shrink fit's rings as spherical shells,
   !> Q1: err_fe over levels 2, 3, 4 at a rate of at least 0.95, the pressure
   !> error at level 4 at most err_fe and converging (rate >= 0.95/2, as
   !> `shrink_case`), every point closed, and on levels 3 and 4 the closed
   !> area an eighth of the sphere r = 1.50001 within the quadrature
   !> tolerance (`check_measure`; at level 2 the cells, 0.625 wide on a
   !> radius of 1.5, are coarser than that asymptotic bound assumes:
   !> measured 4.1e-7 against 1.4e-7, 1.4e-8 at level 3).
   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: delta = 1.0e-5_wp, p_in = 1.0e-3_wp
      integer, parameter :: levels(3) = [2, 3, 4]
      type(compound_type) :: exact
      type(level_type) :: result
      type(study_type) :: study
      character(len=:), allocatable :: text
      real(wp) :: err(3), perr(3), rate
      integer :: i

      call new_compound_sphere(exact, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 1.5_wp, 2.0_wp, p_in, delta, 2.0_wp, 0.3_wp, &
         & 1.0_wp, 0.25_wp, error)
      if (allocated(error)) return
      text = "&scene title='shrink fit 3d' analysis='solid' order=1 levels=3 box_min=0,0,0 box_size=2.5 "// &
         & "recovery='none' output='' /"//nl// &
         & "&body name='shaft' young=2.0 poisson=0.3 /"//nl// &
         & "&body name='hub' young=1.0 poisson=0.25 box_min=0.0,0.0,0.0 box_size=2.2 /"//nl// &
         & "&shape body='shaft' op='add' kind='sphere' name='shaft_out' center=0,0,0 radius=1.50001 /"//nl// &
         & "&shape body='shaft' op='subtract' kind='sphere' name='bore' center=0,0,0 radius=1 /"//nl// &
         & "&shape body='hub' op='add' kind='sphere' name='hub_out' center=0,0,0 radius=2 /"//nl// &
         & "&shape body='hub' op='subtract' kind='sphere' name='hub_in' center=0,0,0 radius=1.5 /"//nl// &
         & "&bc on='bore' type='pressure' value=1.0e-3 /"//nl// &
         & "&contact slave='shaft' master='hub' slave_surface='shaft_out' master_surface='hub_in' /"//nl
      text = text//octant_planes('shaft')//octant_planes('hub')
      do i = 1, 3
         call run_text(text, levels(i), result, error, study)
         if (allocated(error)) return
         err(i) = energy_error_pair(study, result, exact)
         perr(i) = pressure_error(result%contacts(1), exact%contact_pressure)
         call check(error, all(result%contacts(1)%state /= contact_open), 'every slave point closed')
         if (allocated(error)) return
         if (i > 1) call check_measure(result%contacts(1), 0.5_wp*acos(-1.0_wp)*1.50001_wp**2, 1, error)
         if (allocated(error)) return
      end do
      rate = log(err(1)/err(3))/log(4.0_wp)
      call check(error, rate >= 0.95_wp, 'err_fe rate '//real_text(rate)//' < 0.95')
      if (allocated(error)) return
      call check(error, perr(3) <= err(3), 'pressure error '//real_text(perr(3))//' > err_fe '//real_text(err(3)))
      if (allocated(error)) return
      rate = log(perr(1)/perr(3))/log(4.0_wp)
      call check(error, rate >= 0.95_wp*0.5_wp, 'err_p_fe rate '//real_text(rate)//' < 0.95/2 (pressure errors '// &
         & real_text(perr(1))//', '//real_text(perr(3))//')')
   end subroutine test_sphere

   !> The three symmetry planes of an octant model of `body` with their conditions.
   function octant_planes(body) result(text)
      character(len=*), intent(in) :: body
      character(len=:), allocatable :: text
      character(len=*), parameter :: axis(3) = ['x', 'y', 'z'], normal(3) = ['-1,0,0', '0,-1,0', '0,0,-1']
      integer :: k
      text = ''
      do k = 1, 3
         text = text//"&shape body='"//body//"' op='intersect' kind='halfspace' name='"//body//"_s"//axis(k)// &
            & "' point=0,0,0 normal="//normal(k)//" /"//nl//"&bc on='"//body//"_s"//axis(k)//"' type='symmetry' /"//nl
      end do
   end function octant_planes

   !> ||sigma_ex - sigma_h||_E / ||sigma_ex||_E over both bodies of a level in
   !> scene units; body 1 is the inner shell of `exact`, body 2 the outer.
   real(wp) function energy_error_pair(study, result, exact) result(rel)
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      type(compound_type), intent(in) :: exact
      real(wp) :: c(6, 6), sh(6), se(6), d(6), unit, e2, x2
      type(error_type), allocatable :: error
      integer :: b, e, q, ns

      e2 = 0.0_wp
      x2 = 0.0_wp
      do b = 1, size(result%bodies)
         associate (p => result%bodies(b)%problem, u => study%bodies(b)%units)
            ns = p%nstress
            unit = u%modulus*u%strain
            call compliance_matrix(p%analysis, p%young*u%modulus, p%poisson, c(1:ns, 1:ns), error)
            do e = 1, p%mesh%grid%n_leaves
               do q = p%mesh%vol_ptr(e), p%mesh%vol_ptr(e + 1) - 1
                  call p%stress_in_element(e, p%mesh%vol_x(:, q), sh(1:ns))
                  if (b == 1) then
                     call exact%inner%stress(p%mesh%vol_x(:, q), se(1:ns))
                  else
                     call exact%outer%stress(p%mesh%vol_x(:, q), se(1:ns))
                  end if
                  d(1:ns) = se(1:ns) - unit*sh(1:ns)
                  e2 = e2 + p%mesh%vol_w(q)*dot_product(d(1:ns), matmul(c(1:ns, 1:ns), d(1:ns)))
                  x2 = x2 + p%mesh%vol_w(q)*dot_product(se(1:ns), matmul(c(1:ns, 1:ns), se(1:ns)))
               end do
            end do
         end associate
      end do
      rel = sqrt(e2/x2)
   end function energy_error_pair

   !> The closed measure of contact result `c` (the report's contact_measure)
   !> is `exact` within the relative error bound rho^(-2q) of the cut-cell
   !> surface rule, rho >= 13.9 and q = default_points(order) points per
   !> direction (sprc_grid_quadrature notes; test_contact_surface's bound).
   subroutine check_measure(c, exact, order, error)
      type(contact_result_type), intent(in) :: c
      real(wp), intent(in) :: exact
      integer, intent(in) :: order
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: measure
      measure = sum(c%weight, c%state /= contact_open)
      call check(error, abs(measure/exact - 1.0_wp) <= 13.9_wp**(-2*default_points(order)), 'contact_measure '// &
         & real_text(measure)//', exact '//real_text(exact)//': relative error '//real_text(measure/exact - 1.0_wp))
   end subroutine check_measure

   !> ||p_fe - p_ex|| / ||p_ex|| in L2 over the slave surface, p_ex constant.
   pure real(wp) function pressure_error(c, p_exact) result(rel)
      type(contact_result_type), intent(in) :: c
      real(wp), intent(in) :: p_exact
      rel = sqrt(sum(c%weight*(c%p_fe - p_exact)**2)/sum(c%weight*p_exact**2))
   end function pressure_error

   function real_text(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(es12.4)') x
      s = trim(adjustl(buf))
   end function real_text

   !> The patch tests with the recovered stabilization (sprc_contact_pair_solve
   !> notes): the uniform state is its fixed point (the SPR-C traction of a
   !> uniform FE field is exact, so gbar = 0 and lambda = p*), reached from
   !> the penalty start. Tolerance: the solve's C eps/rcond plus the
   !> iteration's stopping tier sqrt(eps) (relative change of the contact
   !> traction, which bounds the distance to the fixed point while the update
   !> contracts by at most 1/2).
   subroutine test_patch_2d_q1_recovered(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 1, 3, '', '', 3, error, recovered=.true.)
   end subroutine test_patch_2d_q1_recovered

   subroutine test_patch_2d_q2_recovered(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 2, 2, '', '', 3, error, recovered=.true.)
   end subroutine test_patch_2d_q2_recovered

   subroutine test_patch_2d_stick_recovered(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_2d, 1, 3, "young=3.0 poisson=0.2", "young=1.0 poisson=0.3", 3, error, stick=.true., &
         & recovered=.true.)
   end subroutine test_patch_2d_stick_recovered

   subroutine test_patch_3d_q1_recovered(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_3d, 1, 2, '', '', 6, error, recovered=.true.)
   end subroutine test_patch_3d_q1_recovered

   !> The shrink fit's checks (rates of err_fe and err_p_fe, pressure error
   !> below err_fe) hold with the recovered stabilization.
   subroutine test_shrink_q1_recovered(error)
      type(error_type), allocatable, intent(out) :: error
      call shrink_case(1, 'plane_strain', 2.0_wp, [4, 5, 6], error, stabilization='recovered')
   end subroutine test_shrink_q1_recovered

   !> A stabilization far too weak for the lagged traction (kappa = 1e-3: the
   !> update contracts by about C_I/kappa > 1) does not settle: an error with
   !> stat_not_converged saying so, not a wrong answer.
   subroutine test_recovered_not_converged(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      type(error_type), allocatable :: failed
      character(len=:), allocatable :: text

      call read_text_file('example/scenes/shrink_fit.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='frictionless' /", "friction='frictionless' stabilization='recovered' kappa=1e-3 /")
      call run_text(text, 3, result, failed)
      if (.not. allocated(failed)) then
         call test_failed(error, 'the recovered stabilization settled at kappa = 1e-3')
         return
      end if
      call check(error, failed%stat, stat_not_converged, 'status not converged: '//failed%message)
      if (allocated(error)) return
      call check(error, index(failed%message, "contact 'shaft' on 'hub': the recovered stabilization did not settle") &
         & > 0, 'message: '//failed%message)
   end subroutine test_recovered_not_converged

   !> A settled recovered stabilization is stabilized by the recovered stress
   !> it reports: the stabilization pressure p* of the last solve (the slave's
   !> coupled SPR-C traction of the solution before it) equals the report's
   !> p_sprc of the final solution over the closed points, to the settling
   !> tier (the last update moved the contact traction by at most sqrt(eps) of
   !> its norm; the recovered traction, a bounded linear map of the same
   !> displacement change, is allowed two orders of magnitude more). A
   !> stabilization by another recovery (the slave alone, its contact surface
   !> free) misses by the difference of the two recoveries.
   subroutine test_recovered_fixed_point(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: diff, norm

      call read_text_file('example/scenes/shrink_fit.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='frictionless' /", "friction='frictionless' stabilization='recovered' kappa=1 /")
      call run_text(text, 4, result, error)
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call check(error, allocated(c%p_star), 'p_star is set with the recovered stabilization')
         if (allocated(error)) return
         diff = sqrt(sum(c%weight*(c%p_star - c%p_sprc)**2, mask=c%state /= contact_open))
         norm = sqrt(sum(c%weight*c%p_sprc**2, mask=c%state /= contact_open))
         call check(error, count(c%state /= contact_open) > 0 .and. diff <= 100.0_wp*sqrt(epsilon(1.0_wp))*norm, &
            & 'p_star against p_sprc: relative L2 difference '//real_text(diff/norm))
      end associate
   end subroutine test_recovered_fixed_point

end module sprc_test_contact_fe
