!> The iterative solve of contact pairs (sprc_contact_pair_solve: CG or GMRES +
!> the bodies' stacked multigrid hierarchies) against the direct one.
!>
!> Each case runs a scene with `solver = 'direct'` and `solver = 'iterative'`
!> and requires: the iterative path was taken (Krylov iterations counted, the
!> Krylov solver named); the same state at every slave point and the same
!> active-set iterations (Coulomb: within one, as the slip directions settle
!> at `direction_tol` = 1e-8, finer than the solve's tolerance, so the
!> confirming iteration may come one sooner or later); every error,
!> estimate and pressure column of the report equal to the direct one's to
!> six digits (relative difference below 1e-6: the stopping test's energy
!> bound, 1e-7 (h/L)^p of the solution, `iteration_tolerance`, moves them by
!> less); each point's FE pressure within 1e-4 of the peak (a local value
!> the energy bound does not control; measured up to 9e-6); and at most
!> `max_per_solve(order)` Krylov iterations per active-set iteration on
!> average. Multigrid makes the count independent of h; the bounds are
!> about twice the largest measured on these scenes (Q1: 16 per solve, the
!> Cattaneo-Mindlin roller; Q2: 49, the 3D patch), so they catch a
!> preconditioner that lost the contact terms (without the kept contact
!> nodes of sprc_fem_multigrid the Hertz sphere Q1 needed 70 per solve at
!> 2.6e3 unknowns, and the count grows with kappa).
module sprc_test_contact_iterative
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, stat_out_of_memory
   use sprc_geometry_body, only: body_type
   use sprc_io_scene, only: scene_type, read_scene
   use sprc_study_model, only: build_bodies
   use sprc_study_budget, only: level_memory, coupled_memory
   use sprc_study_level, only: study_type, prepare_study, run_level
   use sprc_core_text, only: real_text, itoa
   use sprc_io_namelist, only: read_text_file
   use sprc_study_level, only: level_type
   use sprc_fem_linear_solver, only: use_iterative, solver_auto, solver_direct
   use sprc_study_row, only: report_row_type, is_empty
   use sprc_contact_result, only: contact_stick
   use sprc_test_study, only: run_text
   use sprc_testsuite, only: unittest_type, new_unittest, check, replaced
   implicit none
   private

   public :: collect_contact_iterative

   character(len=*), parameter :: patch_2d = 'test/data/contact/patch_2d.nml'
   character(len=*), parameter :: patch_3d = 'test/data/contact/patch_3d.nml'
   character(len=*), parameter :: hertz_2d = 'test/data/contact/hertz_2d.nml'
   character(len=*), parameter :: incline_2d = 'test/data/contact/incline_2d.nml'
   character(len=*), parameter :: cattaneo_2d = 'test/data/contact/cattaneo_2d.nml'
   character(len=*), parameter :: incline_3d = 'test/data/contact/incline_3d.nml'
   character(len=*), parameter :: nl = new_line('a')
   integer, parameter :: max_per_solve(2) = [36, 100]
   real(wp), parameter :: six_digits = 1.0e-6_wp

contains

   subroutine collect_contact_iterative(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('hertz_2d_q1', test_hertz_2d), &
         new_unittest('shrink_fit_2d_q2', test_shrink_q2), &
         new_unittest('shrink_fit_2d_q1_stick', test_shrink_stick), &
         new_unittest('patch_3d_q1', test_patch_3d_q1), &
         new_unittest('patch_3d_q2', test_patch_3d_q2), &
         new_unittest('compound_sphere_q1', test_sphere), &
         new_unittest('compound_sphere_stiff_kappa', test_sphere_kappa), &
         new_unittest('incline_coulomb_slip_gmres', test_incline_slip), &
         new_unittest('cattaneo_mindlin_coulomb', test_cattaneo), &
         new_unittest('patch_3d_coulomb_slip', test_patch_3d_slip), &
         new_unittest('incline_3d_coulomb_stick_uniform', test_incline_3d), &
         new_unittest('hertz_sphere_loose_active_sets', test_hertz_sphere_loose), &
         new_unittest('hertz_2d_loose_active_sets', test_hertz_2d_loose), &
         new_unittest('hertz_sphere_first_set', test_hertz_sphere_first_set), &
         new_unittest('vee_groove_widened_first_set', test_vee_groove), &
         new_unittest('patch_2d_recovered', test_recovered), &
         new_unittest('auto_rule_for_pairs', test_auto_rule), &
         new_unittest('coupled_memory_estimate', test_coupled_memory), &
         new_unittest('coupled_level_refused_before_build', test_coupled_refused) &
         ]
   end subroutine collect_contact_iterative

   !> Hertz line contact, Q1, with both recoveries (the estimates compared too).
   subroutine test_hertz_2d(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(hertz_2d, text, error)
      if (allocated(error)) return
      call same_as_direct(replaced(text, "recovery = 'none'", "recovery = 'both'"), 4, 'cg+gmg', error)
   end subroutine test_hertz_2d

   !> The 2D shrink fit (compound cylinder), Q2, frictionless.
   subroutine test_shrink_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call same_as_direct(shrink_text(2, 'frictionless'), 4, 'cg+gmg', error, order=2)
   end subroutine test_shrink_q2

   !> The 2D shrink fit, Q1, stick (the vector multiplier).
   subroutine test_shrink_stick(error)
      type(error_type), allocatable, intent(out) :: error
      call same_as_direct(shrink_text(1, 'stick'), 5, 'cg+gmg', error)
   end subroutine test_shrink_stick

   subroutine test_patch_3d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(patch_3d, text, error)
      if (allocated(error)) return
      call same_as_direct(text, 3, 'cg+gmg', error)
   end subroutine test_patch_3d_q1

   subroutine test_patch_3d_q2(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(patch_3d, text, error)
      if (allocated(error)) return
      call same_as_direct(replaced(text, 'order    = 1', 'order    = 2'), 2, 'cg+gmg', error, order=2)
   end subroutine test_patch_3d_q2

   !> The compound sphere (3D shrink fit, octant), Q1, with the SPR estimate.
   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      character(len=*), parameter :: axis(3) = ['x', 'y', 'z'], normal(3) = ['-1,0,0', '0,-1,0', '0,0,-1']
      character(len=5), parameter :: bodies(2) = ['shaft', 'hub  ']
      integer :: k, b

      text = "&scene title='shrink fit 3d' analysis='solid' order=1 levels=3 box_min=0,0,0 box_size=2.5 "// &
         & "recovery='spr' output='' /"//nl// &
         & "&body name='shaft' young=2.0 poisson=0.3 /"//nl// &
         & "&body name='hub' young=1.0 poisson=0.25 box_min=0.0,0.0,0.0 box_size=2.2 /"//nl// &
         & "&shape body='shaft' op='add' kind='sphere' name='shaft_out' center=0,0,0 radius=1.50001 /"//nl// &
         & "&shape body='shaft' op='subtract' kind='sphere' name='bore' center=0,0,0 radius=1 /"//nl// &
         & "&shape body='hub' op='add' kind='sphere' name='hub_out' center=0,0,0 radius=2 /"//nl// &
         & "&shape body='hub' op='subtract' kind='sphere' name='hub_in' center=0,0,0 radius=1.5 /"//nl// &
         & "&bc on='bore' type='pressure' value=1.0e-3 /"//nl// &
         & "&contact slave='shaft' master='hub' slave_surface='shaft_out' master_surface='hub_in' /"//nl
      do b = 1, 2
         do k = 1, 3
            text = text//"&shape body='"//trim(bodies(b))//"' op='intersect' kind='halfspace' name='"// &
               & trim(bodies(b))//"_s"//axis(k)//"' point=0,0,0 normal="//normal(k)//" /"//nl// &
               & "&bc on='"//trim(bodies(b))//"_s"//axis(k)//"' type='symmetry' /"//nl
         end do
      end do
      call same_as_direct(text, 4, 'cg+gmg', error)
   end subroutine test_sphere

   !> example/scenes/compound_sphere.nml (interference fit, every cell
   !> closed) at level 3 with kappa = 1e6, the top of its safe range: the
   !> pressures and their errors equal the direct ones to six digits. A
   !> closed cell's multiplier amplifies the iteration's strain error by
   !> kappa, which the tight bound must carry (`contact_tolerance`): without
   !> the 1/kappa err_p_fe differed by 1.2e-6 here (measured 6.9e-7 with it;
   !> the example at its default kappa = 1e4, level 4: 8.6e-6 and 1.8e-7).
   subroutine test_sphere_kappa(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file('example/scenes/compound_sphere.nml', text, error)
      if (allocated(error)) return
      text = replaced(replaced(text, '&contact ', '&contact kappa=1e6 '), "recovery = 'both'", "recovery = 'none'")
      call same_as_direct(replaced(text, "output   = 'out/compound_sphere'", "output   = ''"), 3, 'cg+gmg', error)
   end subroutine test_sphere_kappa

   !> The incline with Coulomb mu = 0.4: cells slip, the system is
   !> unsymmetric (GMRES), over four load steps.
   subroutine test_incline_slip(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(incline_2d, text, error)
      if (allocated(error)) return
      call same_as_direct(replaced(text, "friction='stick'", "friction='coulomb' mu=0.4 steps=4"), 4, 'gmres+gmg', &
         & error, coulomb=.true.)
   end subroutine test_incline_slip

   !> Cattaneo-Mindlin: stick and slip zones under a normal then a tangential load.
   subroutine test_cattaneo(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(cattaneo_2d, text, error)
      if (allocated(error)) return
      call same_as_direct(text, 2, 'gmres+gmg', error, coulomb=.true.)
   end subroutine test_cattaneo

   !> The 3D patch with Coulomb mu = 0.05 and a tangential traction (0.3,
   !> 0.2) on top: the whole interface slips (GMRES) in 3D, at level 2.
   subroutine test_patch_3d_slip(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(patch_3d, text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='frictionless'", "friction='coulomb' mu=0.05")
      text = replaced(text, "type='pressure' value=1.0 /", "type='traction' vector=0.3, 0.2, -1.0 /")
      call same_as_direct(text, 2, 'gmres+gmg', error, coulomb=.true.)
   end subroutine test_patch_3d_slip

   !> The 3D block on an inclined interface (tan theta = 0.447) with Coulomb
   !> mu = 0.6: every point sticks and the uniform stress is exact, through
   !> the iterative path (CG: no cell slips) as through the direct one: the
   !> same states, p_max_fe = n_y^2 = 5/6 to six digits, and err_fe below
   !> the iterative stopping bound, 1e-7 (h/L)^(1 + 3/2) = 3.1e-9 at level 2
   !> (h/L = 1/4; `contact_tolerance`), where the direct solve is at
   !> round-off.
   subroutine test_incline_3d(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      type(level_type) :: direct, iterative
      real(wp), parameter :: bound = 1.0e-7_wp*0.25_wp**2.5_wp, p_exact = 5.0_wp/6.0_wp

      call read_text_file(incline_3d, text, error)
      if (allocated(error)) return
      text = replaced(text, "friction='stick'", "friction='coulomb' mu=0.6")
      call run_text(replaced(text, '&scene', "&scene solver='direct'"), 2, direct, error)
      if (allocated(error)) return
      call run_text(replaced(text, '&scene', "&scene solver='iterative'"), 2, iterative, error)
      if (allocated(error)) return
      associate (d => direct%contacts(1), it => iterative%contacts(1))
         call check(error, iterative%row%solver_iterations > 0 .and. &
            & index(iterative%bodies(1)%problem%solver_name, 'cg+gmg') == 1, 'the iterative path was not taken: '// &
            & iterative%bodies(1)%problem%solver_name)
         if (allocated(error)) return
         call check(error, all(it%state == d%state) .and. all(it%state == contact_stick), &
            & itoa(count(it%state /= d%state))//' point states differ, '//itoa(count(it%state /= contact_stick))// &
            & ' do not stick')
         if (allocated(error)) return
      end associate
      call check(error, abs(iterative%row%p_max_fe - p_exact) <= six_digits*p_exact .and. &
         & abs(direct%row%p_max_fe - p_exact) <= six_digits*p_exact, 'p_max_fe: direct '// &
         & real_text(direct%row%p_max_fe)//', iterative '//real_text(iterative%row%p_max_fe))
      if (allocated(error)) return
      call check(error, iterative%row%err_fe <= bound .and. direct%row%err_fe <= bound, 'err_fe: direct '// &
         & real_text(direct%row%err_fe)//', iterative '//real_text(iterative%row%err_fe)//', bound '// &
         & real_text(bound))
   end subroutine test_incline_3d

   !> The Hertz sphere at level 3 (2,646 unknowns) under 27 times the load
   !> (contact radius 0.31, three times the scene's, so the active set grows
   !> from the first contact over several sets): the same report as the
   !> direct solve, and the active-set iterations before the set repeats
   !> stop at the loose tolerances (sprc_contact_pair_solve's
   !> `changing_set_tolerance` while the set grows, then
   !> `active_set_tolerance`), only the confirming solve at the tight one:
   !> at most 5 Krylov iterations per active-set iteration on average
   !> (measured 13 in 3 sets; 21 with every loose solve at
   !> `active_set_tolerance`).
   subroutine test_hertz_sphere_loose(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text

      call hertz_sphere_text(27.0_wp, text, error)
      if (.not. allocated(error)) call same_as_direct(text, 3, 'cg+gmg', error, per_solve=5, min_sets=2)
   end subroutine test_hertz_sphere_loose

   !> The loose tiers in 2D: hertz_2d at level 4 under 27 times the load
   !> (contact half-width five times the scene's; the constant multiplier,
   !> whose set grows by cells): the same report as the direct solve over
   !> several active sets, at most 12 Krylov iterations per active-set
   !> iteration on average (measured 56 in 7 sets; 121 with the loose solves
   !> at `active_set_tolerance`, 184 with every solve tight).
   subroutine test_hertz_2d_loose(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(hertz_2d, text, error)
      if (allocated(error)) return
      text = replaced(replaced(text, 'vector=0.0, -0.5394218', 'vector=0.0, '//real_text(-0.5394218_wp*27.0_wp)), &
         & "friction='frictionless'", "friction='frictionless' multiplier='constant'")
      call same_as_direct(text, 4, 'cg+gmg', error, per_solve=12, min_sets=5)
   end subroutine test_hertz_2d_loose

   !> The first active set (sprc_contact_pair_solve's `first_set`): the Hertz
   !> sphere at level 3, direct, settles in at most two active-set
   !> iterations (its first-contact cells are the final set: one; closing
   !> every cell with g0 <= h, as before, took three, opening the rim a few
   !> cells per set).
   subroutine test_hertz_sphere_first_set(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      type(level_type) :: direct

      call hertz_sphere_text(1.0_wp, text, error)
      if (.not. allocated(error)) call run_text(replaced(text, '&scene', "&scene solver='direct'"), 3, direct, error)
      if (allocated(error)) return
      call check(error, direct%contacts(1)%iterations <= 2, itoa(direct%contacts(1)%iterations)// &
         & ' active-set iterations, at most 2 expected')
   end subroutine test_hertz_sphere_first_set

   !> The wedge in a V-groove (test/data/contact/vee_groove.nml), whose
   !> first active set leaves it free (sprc_contact_pair_solve's
   !> `widen_first_set`): the kept block-system pattern of the iterative
   !> path takes the widened set.
   subroutine test_vee_groove(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file('test/data/contact/vee_groove.nml', text, error)
      if (.not. allocated(error)) call same_as_direct(text, 4, 'cg+gmg', error)
   end subroutine test_vee_groove

   !> The Hertz sphere scene without recovery or output, its load (the top
   !> traction and the exact solution's force) times `factor`.
   subroutine hertz_sphere_text(factor, text, error)
      real(wp), intent(in) :: factor
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      call read_text_file('example/scenes/hertz_sphere.nml', text, error)
      if (allocated(error)) return
      text = replaced(replaced(text, "recovery = 'both'", "recovery = 'none'"), "output   = 'out/hertz_sphere'", &
         & "output   = ''")
      text = replaced(replaced(text, 'vector=0.0, 0.0, -0.49931', 'vector=0.0, 0.0, '//real_text(-0.49931_wp*factor)), &
         & 'load=0.8', 'load='//real_text(0.8_wp*factor))
   end subroutine hertz_sphere_text

   !> The recovered stabilization: the kept solver of the repeated solves.
   subroutine test_recovered(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      call read_text_file(patch_2d, text, error)
      if (allocated(error)) return
      call same_as_direct(replaced(text, "friction='frictionless'", "friction='frictionless' "// &
         & "stabilization='recovered'"), 4, 'cg+gmg', error)
   end subroutine test_recovered

   !> 'auto' for a contact pair's coupled system: iterative from 100,000
   !> unknowns in 3D Q1 (one body: 25,000), never in 2D or for Q2 unless the
   !> direct solve does not fit; 'direct' stays direct.
   subroutine test_auto_rule(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, use_iterative(solver_auto, 3, 1, 30000) .and. .not. use_iterative(solver_auto, 3, 1, 30000, &
         & coupled=.true.) .and. .not. use_iterative(solver_auto, 3, 1, 96258, coupled=.true.) .and. &
         & use_iterative(solver_auto, 3, 1, 100000, coupled=.true.) .and. .not. &
         & use_iterative(solver_auto, 2, 1, 10**8, coupled=.true.) .and. .not. use_iterative(solver_auto, 3, 2, 10**8, &
         & coupled=.true.) .and. use_iterative(solver_auto, 3, 2, 100, direct_fits=.false., coupled=.true.) .and. &
         & .not. use_iterative(solver_direct, 3, 1, 10**8, coupled=.true.), 'the coupled thresholds')
   end subroutine test_auto_rule

   !> The memory estimate of a contact pair (sprc_study_budget's
   !> `coupled_memory`; Hertz sphere, level 5): the dofs of both bodies in
   !> one system; a direct estimate above the sum of the bodies' own (the
   !> factor of the coupled system fills more than two smaller ones); an
   !> iterative one of 32 MB + 8 kB per dof plus the Omega_aux data, which
   !> is positive; and 'auto' takes the iterative estimate when one byte
   !> less than the direct one is available.
   subroutine test_coupled_memory(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(body_type), allocatable :: bodies(:)
      real(wp) :: cells, dofs, direct, iterative, alone(2), dofs_alone(2), bytes
      logical :: fits
      integer :: b

      call read_scene('example/scenes/hertz_sphere.nml', scene, error)
      if (.not. allocated(error)) call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      scene%solver = 'direct'
      do b = 1, 2
         call level_memory(scene, bodies(b), 5, cells, dofs_alone(b), alone(b), error)
         if (allocated(error)) return
      end do
      call coupled_memory(scene, bodies, [1, 2], [1], 5, cells, dofs, direct, error)
      if (allocated(error)) return
      call check(error, abs(dofs - sum(dofs_alone)) <= 1.0e-12_wp*dofs, 'coupled dofs '//real_text(dofs)// &
         & ', the bodies'' '//real_text(sum(dofs_alone)))
      if (allocated(error)) return
      call check(error, direct > sum(alone), 'direct: coupled '//real_text(direct)//' B, apart '// &
         & real_text(sum(alone))//' B')
      if (allocated(error)) return
      scene%solver = 'iterative'
      call coupled_memory(scene, bodies, [1, 2], [1], 5, cells, dofs, iterative, error)
      if (allocated(error)) return
      call check(error, iterative > 32.0e6_wp + 8.0e3_wp*dofs .and. iterative < direct, 'iterative: '// &
         & real_text(iterative)//' B, without Omega_aux '//real_text(32.0e6_wp + 8.0e3_wp*dofs))
      if (allocated(error)) return
      scene%solver = 'auto'
      call coupled_memory(scene, bodies, [1, 2], [1], 5, cells, dofs, bytes, error, available=int(direct, i8) - 1, &
         & direct_fits=fits)
      if (allocated(error)) return
      call check(error, .not. fits .and. abs(bytes - iterative) <= 1.0e-12_wp*bytes, 'auto without room for the '// &
         & 'direct solve: '//real_text(bytes)//' B')
   end subroutine test_coupled_memory

   !> A level whose contact pair cannot fit (Hertz sphere, level 9: 1e9
   !> unknowns) is refused by the pair's estimate before either body is
   !> built (no body result exists), naming the pair (stat_out_of_memory).
   subroutine test_coupled_refused(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result
      type(error_type), allocatable :: e

      call read_scene('example/scenes/hertz_sphere.nml', scene, error)
      if (.not. allocated(error)) call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      call run_level(study, 9, result, e)
      call check(error, allocated(e), 'level 9 ran')
      if (allocated(error)) return
      call check(error, e%stat == stat_out_of_memory .and. index(e%message, "&contact 'sphere' on 'block'") == 1 &
         & .and. index(e%message, 'solved together') > 0 .and. .not. allocated(result%bodies), &
         & 'message: '//e%message)
   end subroutine test_coupled_refused

   !> Run `text` at `level` with the direct and the iterative solver and
   !> compare (module notes); `name` is the Krylov solver the last block
   !> solve must have used.
   subroutine same_as_direct(text, level, name, error, order, coulomb, per_solve, min_sets)
      character(len=*), intent(in) :: text, name
      integer, intent(in) :: level
      type(error_type), allocatable, intent(out) :: error
      !> The element degree (default 1) and whether the friction is Coulomb.
      integer, intent(in), optional :: order
      logical, intent(in), optional :: coulomb
      !> Krylov iterations per active-set iteration allowed on average
      !> (default `max_per_solve(order)`).
      integer, intent(in), optional :: per_solve
      !> Active-set iterations the direct solve must take at least (default 1).
      integer, intent(in), optional :: min_sets
      type(level_type) :: direct, iterative
      real(wp) :: scale
      integer :: degree, per

      degree = 1
      if (present(order)) degree = order
      per = max_per_solve(degree)
      if (present(per_solve)) per = per_solve
      call run_text(replaced(text, '&scene', "&scene solver='direct'"), level, direct, error)
      if (allocated(error)) return
      call run_text(replaced(text, '&scene', "&scene solver='iterative'"), level, iterative, error)
      if (allocated(error)) return
      associate (d => direct%contacts(1), it => iterative%contacts(1), row => iterative%row)
         call check(error, direct%row%solver_iterations == 0 .and. row%solver_iterations > 0 .and. &
            & index(iterative%bodies(1)%problem%solver_name, name) == 1, &
            & 'the iterative path was not taken: '//itoa(row%solver_iterations)//' Krylov iterations, solver '// &
            & iterative%bodies(1)%problem%solver_name//', expected '//name)
         if (allocated(error)) return
         call check(error, abs(it%iterations - d%iterations) <= merge(1, 0, present(coulomb)) .and. &
            & all(it%state == d%state), 'active-set iterations '// &
            & itoa(it%iterations)//' (direct '//itoa(d%iterations)//') or '// &
            & itoa(count(it%state /= d%state))//' point states differ')
         if (allocated(error)) return
         if (present(min_sets)) then
            call check(error, d%iterations >= min_sets, itoa(d%iterations)//' active-set iterations, at least '// &
               & itoa(min_sets)//' expected')
            if (allocated(error)) return
         end if
         call check(error, row%solver_iterations <= per*it%iterations, itoa(row%solver_iterations)// &
            & ' Krylov iterations for '//itoa(it%iterations)//' active-set iterations')
         if (allocated(error)) return
         scale = maxval(abs(d%p_fe))
         call check(error, maxval(abs(it%p_fe - d%p_fe)) <= 1.0e-4_wp*scale, 'FE pressure differs by '// &
            & real_text(maxval(abs(it%p_fe - d%p_fe)))//' of '//real_text(scale))
         if (allocated(error)) return
      end associate
      call same_columns(direct%row, iterative%row, error)
   end subroutine same_as_direct

   !> The error, estimate and pressure columns agree to six digits.
   subroutine same_columns(a, b, error)
      type(report_row_type), intent(in) :: a, b
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: names(12) = [character(len=15) :: 'err_fe', 'err_spr', 'err_sprc', &
         & 'eta_spr', 'eta_sprc', 'contact_measure', 'p_max_fe', 'p_max_spr', 'p_max_sprc', 'err_p_fe', 'err_p_spr', &
         & 'err_p_sprc']
      real(wp) :: x(12), y(12)
      integer :: k

      x = [a%err_fe, a%err_spr, a%err_sprc, a%eta_spr, a%eta_sprc, a%contact_measure, a%p_max_fe, a%p_max_spr, &
         & a%p_max_sprc, a%err_p_fe, a%err_p_spr, a%err_p_sprc]
      y = [b%err_fe, b%err_spr, b%err_sprc, b%eta_spr, b%eta_sprc, b%contact_measure, b%p_max_fe, b%p_max_spr, &
         & b%p_max_sprc, b%err_p_fe, b%err_p_spr, b%err_p_sprc]
      do k = 1, size(x)
         if (is_empty(x(k)) .and. is_empty(y(k))) cycle
         call check(error, abs(x(k) - y(k)) <= six_digits*max(abs(x(k)), abs(y(k))), trim(names(k))//': direct '// &
            & real_text(x(k))//', iterative '//real_text(y(k)))
         if (allocated(error)) return
      end do
   end subroutine same_columns

   !> The quarter-model shrink fit of test_contact_fe (shaft slave, bore
   !> pressure 1e-3, interference 1e-5, shaft twice as stiff).
   function shrink_text(order, friction) result(text)
      integer, intent(in) :: order
      character(len=*), intent(in) :: friction
      character(len=:), allocatable :: text
      text = "&scene title='shrink fit' analysis='plane_strain' order="//achar(48 + order)// &
         & " levels=3 box_min=0,0 box_size=2.5 recovery='both' output='' /"//nl// &
         & "&body name='shaft' young=2.0 poisson=0.3 /"//nl// &
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
         & "&contact slave='shaft' master='hub' slave_surface='shaft_out' master_surface='hub_in' friction='"// &
         & friction//"' /"//nl
   end function shrink_text

end module sprc_test_contact_iterative
