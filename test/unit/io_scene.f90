!> Tests of scene input: the example scenes and the built-in default validate,
!> defaults are filled, directions normalised, the summary states what the
!> scene switches on and off, and every malformed scene in
!> test/data/scenes/bad/ fails with the message its EXPECT line demands.
module sprc_test_scene
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, stat_invalid_input, stat_io, stat_unsupported
   use sprc_io_namelist, only: read_text_file
   use sprc_io_scene, only: scene_type, read_scene, read_scene_text, default_scene_text, scene_summary, recovery_degree
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, replaced
   use sprc_study_spec, only: auto_multiplier
   implicit none
   private

   public :: collect_scene

   character(len=*), parameter :: nl = new_line('a')
   character(len=*), parameter :: bad_dir = 'test/data/scenes/bad/'
   !> Minimum number of malformed scene files the suite must hold.
   integer, parameter :: min_bad_files = 146

   !> A small valid 2D scene; tests edit it with `replaced`.
   character(len=*), parameter :: minimal = &
      & "&scene analysis='plane_stress' levels=2 box_min=0,0 box_size=4 /"//nl// &
      & "&body name='b' young=1 poisson=0 /"//nl// &
      & "&shape body='b' op='add' kind='box' name='sq' lower=1,1 upper=3,3 /"//nl
   !> A valid contact scene: a disk on a block, Coulomb friction.
   character(len=*), parameter :: contact_text = &
      & "&scene analysis='plane_strain' levels=3 box_min=0,0 box_size=4 /"//nl// &
      & "&body name='punch' young=1000 poisson=0.3 /"//nl// &
      & "&body name='block' young=2000 poisson=0.25 /"//nl// &
      & "&shape body='punch' op='add' kind='disk' name='tip' center=2,3 radius=1 /"//nl// &
      & "&shape body='block' op='add' kind='box' name='top' lower=0,0 upper=4,2 /"//nl// &
      & "&contact slave='punch' master='block' slave_surface='tip' master_surface='top'"//nl// &
      & "         friction='coulomb' mu=0.3 kappa=10 /"//nl

contains

   subroutine collect_scene(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('default_equals_example_file', test_default_file), &
         new_unittest('default_scene_validates', test_default_scene), &
         new_unittest('kirsch_example', test_kirsch), &
         new_unittest('lshape_examples', test_lshape), &
         new_unittest('lame_sphere_example', test_lame_sphere), &
         new_unittest('defaults_filled', test_defaults), &
         new_unittest('directions_normalised', test_normalised), &
         new_unittest('shape_fields_per_kind', test_shape_fields), &
         new_unittest('choices_case_insensitive', test_case), &
         new_unittest('summary_switches_order1', test_summary_order1), &
         new_unittest('summary_switches_order2', test_summary_order2), &
         new_unittest('summary_switches_off', test_summary_off), &
         new_unittest('summary_real_format', test_summary_reals), &
         new_unittest('contact_accepted', test_contact), &
         new_unittest('contact_defaults', test_contact_defaults), &
         new_unittest('contact_multiplier_auto', test_contact_multiplier_auto), &
         new_unittest('contact_shrink_fit', test_shrink_fit), &
         new_unittest('contact_hertz_roller', test_hertz_roller), &
         new_unittest('contact_on_polygon_group', test_contact_group), &
         new_unittest('contact_uniform_exact', test_uniform_exact), &
         new_unittest('body_local_shape_indices', test_body_shapes), &
         new_unittest('missing_file', test_missing_file), &
         new_unittest('expect_has_enough_entries', test_expect_count), &
         new_unittest('malformed_files', test_malformed), &
         new_unittest('dilatation_key', test_dilatation_key), &
         new_unittest('solver_key', test_solver_key), &
         new_unittest('nitsche_gamma_key', test_nitsche_gamma_key) &
         ]
   end subroutine collect_scene

   !> Read a scene from text; any error fails the test.
   subroutine read_ok(text, scene, error)
      character(len=*), intent(in) :: text
      type(scene_type), intent(out) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      call read_scene_text(text, 'test.nml', scene, e)
      if (allocated(e)) call test_failed(error, 'unexpected error: '//e%message)
   end subroutine read_ok

   subroutine read_file_ok(path, scene, error)
      character(len=*), intent(in) :: path
      type(scene_type), intent(out) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      call read_scene(path, scene, e)
      if (allocated(e)) call test_failed(error, path//': unexpected error: '//e%message)
   end subroutine read_file_ok

   !> Whether `summary` has the line `  label: state...`.
   logical function has_switch(summary, label, state)
      character(len=*), intent(in) :: summary, label, state
      has_switch = index(summary, nl//'  '//label//': '//state) > 0
   end function has_switch

   subroutine check_switch(error, summary, label, state)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: summary, label, state
      call check(error, has_switch(summary, label, state), 'summary lacks "'//label//': '//state//'" in:'//nl//summary)
   end subroutine check_switch

   subroutine test_default_file(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      character(len=:), allocatable :: text, builtin
      call read_text_file('example/scenes/lame_cylinder.nml', text, e)
      if (allocated(e)) then
         call test_failed(error, e%message)
         return
      end if
      builtin = default_scene_text()
      call check(error, len(builtin), len(text), 'length of default_scene_text() vs the example file')
      if (allocated(error)) return
      call check(error, builtin == text, 'default_scene_text() equals example/scenes/lame_cylinder.nml byte for byte')
   end subroutine test_default_file

   subroutine test_default_scene(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_ok(default_scene_text(), s, error)
      if (allocated(error)) return
      call check(error, s%analysis, 'plane_strain', 'analysis')
      if (allocated(error)) return
      call check(error, s%dim, 2, 'dim')
      if (allocated(error)) return
      call check(error, s%order, 1, 'order')
      if (allocated(error)) return
      call check(error, size(s%levels) == 4 .and. all(s%levels == [3, 4, 5, 6]), 'levels 3..6')
      if (allocated(error)) return
      call check(error, s%box_size, 25.0_wp, 0.0_wp, 'box_size')
      if (allocated(error)) return
      call check(error, s%output, 'out/lame', 'output')
      if (allocated(error)) return
      call check(error, size(s%bodies), 1, 'bodies')
      if (allocated(error)) return
      call check(error, s%bodies(1)%young, 1000.0_wp, 0.0_wp, 'young')
      if (allocated(error)) return
      call check(error, s%bodies(1)%poisson, 0.3_wp, 0.0_wp, 'poisson')
      if (allocated(error)) return
      call check(error, size(s%shapes), 4, 'shapes')
      if (allocated(error)) return
      call check(error, s%shapes(2)%name//' '//s%shapes(2)%op//' '//s%shapes(2)%kind, 'inner subtract disk', 'shape 2')
      if (allocated(error)) return
      call check(error, all(s%shapes%body_index == 1), 'shape body indices')
      if (allocated(error)) return
      call check(error, size(s%bcs), 3, 'bcs')
      if (allocated(error)) return
      call check(error, s%bcs(1)%type, 'pressure', 'bc 1 type')
      if (allocated(error)) return
      call check(error, s%bcs(1)%value, 1.0_wp, 0.0_wp, 'pressure value')
      if (allocated(error)) return
      call check(error, s%bcs(1)%shape_index, 2, 'bc 1 is on shape 2 (inner)')
      if (allocated(error)) return
      call check(error, s%bcs(3)%shape_index, 4, 'bc 3 is on shape 4 (sym_y)')
      if (allocated(error)) return
      call check(error, s%exact%present, 'exact present')
      if (allocated(error)) return
      call check(error, s%exact%kind, 'lame_cylinder', 'exact kind')
      if (allocated(error)) return
      call check(error, s%exact%r_in, 5.0_wp, 0.0_wp, 'r_in')
      if (allocated(error)) return
      call check(error, s%exact%r_out, 20.0_wp, 0.0_wp, 'r_out')
      if (allocated(error)) return
      call check(error, s%exact%p_out, 0.0_wp, 0.0_wp, 'p_out defaults to 0')
      if (allocated(error)) return
      call check(error, size(s%contacts), 0, 'no contact')
   end subroutine test_default_scene

   subroutine test_kirsch(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      call read_file_ok('example/scenes/kirsch_plate.nml', s, error)
      if (allocated(error)) return
      call check(error, s%analysis, 'plane_stress', 'analysis')
      if (allocated(error)) return
      call check(error, size(s%levels) == 4 .and. all(s%levels == [4, 5, 6, 7]), 'levels 4..7')
      if (allocated(error)) return
      call check(error, s%exact%kind, 'kirsch', 'exact kind')
      if (allocated(error)) return
      call check(error, s%exact%radius, 1.0_wp, 0.0_wp, 'hole radius')
      if (allocated(error)) return
      call check(error, s%shapes(s%bcs(1)%shape_index)%kind, 'box', 'exact traction on the plate edges')
      if (allocated(error)) return
      call check(error, s%bcs(1)%type, 'exact_traction', 'bc type')
      if (allocated(error)) return
      summary = scene_summary(s)
      call check_switch(error, summary, 'SPR-C symmetry', "on (surfaces 'sym_x', 'sym_y')")
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C traction equilibrium', "on (surfaces 'edges', 'hole')")
   end subroutine test_kirsch

   !> The L-shape examples: the corner exact kind read (bisector normalised),
   !> its eigenvalues in the summary, and the apex at least 0.2 of a cell
   !> (0.19 allows for rounding) from every grid line at levels 0..20 (the
   !> deepest an adaptive run may reach): the convergence rate the examples
   !> show is that of a corner inside a cell, not on a node or near a sliver.
   subroutine test_lshape(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      character(len=*), parameter :: files(2) = ['example/scenes/lshape_q1.nml', 'example/scenes/lshape_q2.nml']
      real(wp) :: cells
      integer :: i, level, k
      do i = 1, 2
         call read_file_ok(files(i), s, error)
         if (allocated(error)) return
         call check(error, s%order, i, 'order')
         if (allocated(error)) return
         call check(error, s%exact%kind, 'corner', 'exact kind')
         if (allocated(error)) return
         call check(error, maxval(abs(s%exact%direction - [-1.0_wp, 1.0_wp]/sqrt(2.0_wp))), 0.0_wp, &
            & 2.0_wp*epsilon(1.0_wp), 'bisector normalised')
         if (allocated(error)) return
         call check(error, s%exact%angle == 270.0_wp .and. s%exact%mode1 == 1.0_wp .and. s%exact%mode2 == 1.0_wp, &
            & 'angle 270, mode1 = mode2 = 1')
         if (allocated(error)) return
         summary = scene_summary(s)
         call check(error, index(summary, 'lambda1 = 0.544483736782464, lambda2 = 0.908529189846099') > 0, &
            & 'eigenvalues in the summary')
         if (allocated(error)) return
         do level = 0, 20
            do k = 1, 2
               cells = (s%exact%point(k) - s%box_min(k))/s%box_size*2.0_wp**level
               call check(error, abs(cells - anint(cells)) > 0.19_wp, 'apex off the grid lines of level '// &
                  & itoa(level)//', '//files(i))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_lshape

   subroutine test_lame_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_file_ok('example/scenes/lame_sphere.nml', s, error)
      if (allocated(error)) return
      call check(error, s%dim, 3, 'solid is 3D')
      if (allocated(error)) return
      call check(error, size(s%box_min), 3, 'box_min has 3 values')
      if (allocated(error)) return
      call check(error, size(s%bodies(1)%body_force), 3, 'body_force has 3 values')
      if (allocated(error)) return
      call check(error, s%exact%kind, 'lame_sphere', 'exact kind')
      if (allocated(error)) return
      call check(error, s%bcs(2)%type//' '//s%bcs(3)%type//' '//s%bcs(4)%type, 'symmetry symmetry symmetry', &
         & 'three symmetry planes')
   end subroutine test_lame_sphere

   subroutine test_defaults(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_ok(minimal, s, error)
      if (allocated(error)) return
      call check(error, s%title, '', 'title default')
      if (allocated(error)) return
      call check(error, s%order, 1, 'order default')
      if (allocated(error)) return
      call check(error, s%refine_boundary, 0, 'refine_boundary default')
      if (allocated(error)) return
      call check(error, s%recovery, 'both', 'recovery default')
      if (allocated(error)) return
      call check(error, s%recovery_degree, 'auto', 'recovery_degree default')
      if (allocated(error)) return
      call check(error, recovery_degree(s, 1) == s%order .and. recovery_degree(s, 2) == s%order, &
         & 'order 1, auto: SPR and SPR-C at the FE order')
      if (allocated(error)) return
      call check(error, s%output, '', 'output default')
      if (allocated(error)) return
      call check(error, size(s%bodies(1)%body_force), 2, 'body_force size')
      if (allocated(error)) return
      call check(error, all(abs(s%bodies(1)%body_force) <= 0.0_wp), 'body_force default 0')
      if (allocated(error)) return
      call check(error, .not. s%exact%present, 'no exact')
      if (allocated(error)) return
      call check(error, size(s%bcs), 0, 'no bcs')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), "traction-free (no &bc): 'sq'") > 0, 'sq listed as traction-free')
   end subroutine test_defaults

   subroutine test_normalised(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: text
      ! (3, 4)/5 = (0.6, 0.8): the division rounds once, so allow a few ulps.
      real(wp), parameter :: tol = 4*epsilon(1.0_wp)
      text = minimal//"&shape body='b' op='intersect' kind='halfspace' name='h' point=2,2 normal=3,4 /"//nl
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, s%shapes(2)%normal(1), 0.6_wp, tol, 'normal x', rel=.true.)
      if (allocated(error)) return
      call check(error, s%shapes(2)%normal(2), 0.8_wp, tol, 'normal y', rel=.true.)
      if (allocated(error)) return
      text = "&scene analysis='solid' levels=1 box_min=0,0,0 box_size=4 /"//nl// &
         & "&body name='b' young=1 poisson=0.2 /"//nl// &
         & "&shape body='b' op='add' kind='cylinder' name='c' point=2,2,0 axis=0,0,-7 radius=1 /"//nl
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, s%shapes(1)%axis(3), -1.0_wp, tol, 'axis normalised')
      if (allocated(error)) return
      call check(error, abs(s%shapes(1)%axis(1)) + abs(s%shapes(1)%axis(2)), 0.0_wp, tol, 'axis x, y stay 0')
   end subroutine test_normalised

   subroutine test_shape_fields(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: text
      text = minimal// &
         & "&shape body='b' op='subtract' kind='ellipse' name='e' center=2,2 semi_axes=0.5,0.25 /"//nl// &
         & "&shape body='b' op='add' kind='disk' name='d' center=1,1 radius=0.5 /"//nl
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, allocated(s%shapes(1)%lower) .and. allocated(s%shapes(1)%upper) .and. &
         & .not. allocated(s%shapes(1)%center), 'box has lower/upper only')
      if (allocated(error)) return
      call check(error, s%shapes(2)%semi_axes(2), 0.25_wp, 0.0_wp, 'ellipse semi_axes')
      if (allocated(error)) return
      call check(error, .not. allocated(s%shapes(2)%normal), 'ellipse has no normal')
      if (allocated(error)) return
      call check(error, s%shapes(3)%radius, 0.5_wp, 0.0_wp, 'disk radius')
   end subroutine test_shape_fields

   subroutine test_case(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: text
      text = replaced(minimal, "analysis='plane_stress'", "ANALYSIS='Plane_Stress' Recovery='SPR'")
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, s%analysis//' '//s%recovery, 'plane_stress spr', 'choices stored in lower case')
      if (allocated(error)) return
      text = replaced(minimal, 'box_size=4', "box_size=4 order=2 recovery_degree='P+1'")
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, recovery_degree(s, 1) == 3 .and. recovery_degree(s, 2) == 3, "recovery_degree = 'p+1', order 2")
      if (allocated(error)) return
      call check(error, index(scene_summary(s), "recovery_degree = 'p+1' (SPR 3, SPR-C 3)") > 0, &
         & 'summary shows the recovery degree keyword and the patch degrees')
      if (allocated(error)) return
      text = replaced(minimal, 'box_size=4', "box_size=4 order=2")
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, recovery_degree(s, 1) == 2 .and. recovery_degree(s, 2) == 3, 'order 2, auto: SPR 2, SPR-C 3')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), "recovery_degree = 'auto' (SPR 2, SPR-C 3)") > 0, &
         & 'summary shows the auto degrees')
      if (allocated(error)) return
      text = replaced(minimal, 'box_size=4', "box_size=4 order=2 recovery_degree='p'")
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, recovery_degree(s, 1) == 2 .and. recovery_degree(s, 2) == 2, "recovery_degree = 'p', order 2")
   end subroutine test_case

   !> &scene dilatation: default 'auto'; check says per body whether the
   !> locking-free formulation is on, and why.
   subroutine test_dilatation_key(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_ok(minimal, s, error)
      if (allocated(error)) return
      call check(error, s%dilatation, 'auto', 'dilatation default')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), "body 'b': off (auto: plane stress does not lock)") > 0, &
         & 'summary: plane stress, auto: off')
      if (allocated(error)) return
      call read_ok(replaced(replaced(minimal, "'plane_stress'", "'plane_strain'"), 'poisson=0', 'poisson=0.4999'), &
         & s, error)
      if (allocated(error)) return
      call check(error, index(scene_summary(s), "body 'b': on (auto: poisson = 0.4999 >= 0.4)") > 0, &
         & 'summary: plane strain at 0.4999, auto: on')
      if (allocated(error)) return
      call read_ok(replaced(minimal, 'box_size=4', "box_size=4 dilatation='Projected'"), s, error)
      if (allocated(error)) return
      call check(error, index(scene_summary(s), "dilatation      = projected") > 0 .and. &
         & index(scene_summary(s), "body 'b': on (dilatation = 'projected')") > 0, 'summary: projected on request')
   end subroutine test_dilatation_key

   !> &scene solver: default 'auto', which check explains per dimension; a
   !> choice is kept as given (case folded like every choice).
   subroutine test_solver_key(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_ok(minimal, s, error)
      if (allocated(error)) return
      call check(error, s%solver, 'auto', 'solver default')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), 'solver          = auto (2D Q1: CHOLMOD)') > 0, 'summary: 2D auto')
      if (allocated(error)) return
      call read_ok(replaced(minimal, 'box_size=4', "box_size=4 solver='Iterative'"), s, error)
      if (allocated(error)) return
      call check(error, s%solver, 'iterative', 'solver given')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), 'solver          = iterative'//new_line('a')) > 0, &
         & 'summary: iterative')
   end subroutine test_solver_key

   !> &scene nitsche_gamma: default 10 (p+1)^2; outside the safe range the
   !> summary carries a warning (and the driver prints it on standard error).
   subroutine test_nitsche_gamma_key(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_ok(replaced(minimal, 'box_size=4', 'box_size=4 order=2'), s, error)
      if (allocated(error)) return
      call check(error, s%nitsche_gamma, 90.0_wp, 0.0_wp, 'default 10 (p+1)^2 for order 2')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), 'WARNING') == 0, 'no warning at the default')
      if (allocated(error)) return
      call read_ok(replaced(minimal, 'box_size=4', 'box_size=4 nitsche_gamma=5'), s, error)
      if (allocated(error)) return
      call check(error, index(scene_summary(s), 'WARNING: Nitsche gamma = 5.000E+00 lies outside the safe range '// &
         & '[20.0, 4000.0] for Q1: coercivity') > 0, 'warning below the range: '//scene_summary(s))
   end subroutine test_nitsche_gamma_key

   subroutine test_summary_order1(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      call read_ok(default_scene_text(), s, error)
      if (allocated(error)) return
      summary = scene_summary(s)
      call check(error, summary(len(summary):len(summary)) /= nl, 'lines are separated, not terminated')
      if (allocated(error)) return
      call check(error, index(summary, "scene 'Thick cylinder under internal pressure, quarter model'") == 1, 'title')
      if (allocated(error)) return
      call check(error, index(summary, "traction-free (no &bc): 'outer'") > 0, 'outer is traction-free')
      if (allocated(error)) return
      call check(error, index(summary, "shape 'sym_x': intersect halfspace, point = 0.0, 0.0, normal = -1.0, 0.0") > 0, &
         & 'shape line')
      if (allocated(error)) return
      call check(error, index(summary, 'exact solution: lame_cylinder') > 0, 'exact solution line')
      if (allocated(error)) return
      call check_switch(error, summary, 'recovery SPR', 'on')
      if (allocated(error)) return
      call check_switch(error, summary, 'recovery SPR-C', 'on')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C internal equilibrium', 'on')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C compatibility', 'off (order 1: holds identically)')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C traction equilibrium', "on (surfaces 'outer', 'inner')")
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C symmetry', "on (surfaces 'sym_x', 'sym_y')")
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C contact', 'off')
      if (allocated(error)) return
      call check_switch(error, summary, 'contact', 'off (no &contact)')
      if (allocated(error)) return
      call check_switch(error, summary, 'error columns (err_*, theta_*)', 'on (exact solution lame_cylinder)')
      if (allocated(error)) return
      call check_switch(error, summary, 'estimate columns (eta_*)', 'on')
      if (allocated(error)) return
      call check_switch(error, summary, 'output files', 'on (out/lame.csv, out/lame.svg, out/lame.h5, out/lame.xdmf)')
      if (allocated(error)) return
      call check(error, index(summary, 'NOT') == 0, 'nothing unavailable')
   end subroutine test_summary_order1

   subroutine test_summary_order2(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      call read_ok(replaced(default_scene_text(), 'order    = 1', 'order    = 2'), s, error)
      if (allocated(error)) return
      call check(error, s%order, 2, 'order 2 read')
      if (allocated(error)) return
      summary = scene_summary(s)
      call check_switch(error, summary, 'SPR-C compatibility', 'on (order 2)')
   end subroutine test_summary_order2

   subroutine test_summary_off(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary, text
      ! recovery = 'spr': SPR on, SPR-C and its constraints off.
      call read_ok(replaced(minimal, 'box_size=4', "box_size=4 recovery='spr'"), s, error)
      if (allocated(error)) return
      summary = scene_summary(s)
      call check_switch(error, summary, 'recovery SPR', 'on')
      if (allocated(error)) return
      call check_switch(error, summary, 'recovery SPR-C', 'off')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C constraints', "off (recovery = 'spr')")
      if (allocated(error)) return
      call check_switch(error, summary, 'error columns (err_*, theta_*)', 'off (no &exact)')
      if (allocated(error)) return
      call check_switch(error, summary, 'output files', "off (output = '')")
      if (allocated(error)) return
      call check(error, index(summary, 'exact solution: none') > 0, 'no exact solution')
      if (allocated(error)) return
      ! recovery = 'none': no estimate either.
      call read_ok(replaced(minimal, 'box_size=4', "box_size=4 recovery='none'"), s, error)
      if (allocated(error)) return
      summary = scene_summary(s)
      call check_switch(error, summary, 'recovery SPR', 'off')
      if (allocated(error)) return
      call check_switch(error, summary, 'estimate columns (eta_*)', 'off')
      if (allocated(error)) return
      ! A displacement boundary is neither a traction nor a symmetry boundary.
      text = replaced(minimal, 'box_size=4', "box_size=4 recovery='sprc'")//"&bc on='sq' type='displacement' vector=0,0 /"
      call read_ok(text, s, error)
      if (allocated(error)) return
      summary = scene_summary(s)
      call check_switch(error, summary, 'SPR-C traction equilibrium', 'off (no traction boundary)')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C symmetry', 'off (no symmetry boundary)')
      if (allocated(error)) return
      call check(error, index(summary, 'traction-free (no &bc): none') > 0, 'no traction-free surface')
   end subroutine test_summary_off

   subroutine test_summary_reals(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary, text
      ! Shortest text that reads back as the same double, worked out by hand.
      text = replaced(minimal, 'young=1 poisson=0', 'young=2.1d11 poisson=-0.25 body_force=2.5e-7, -9.81')
      ! 0.1 + 0.2 rounds to the double printed as 0.30000000000000004 (17 digits).
      text = replaced(text, 'upper=3,3', 'upper=3,0.30000000000000004')
      text = replaced(text, 'lower=1,1', 'lower=1,0.1')
      text = replaced(text, 'box_size=4', 'box_size=1.0e20')
      call read_ok(text, s, error)
      if (allocated(error)) return
      summary = scene_summary(s)
      call check(error, index(summary, 'young = 210000000000.0, poisson = -0.25, body_force = 2.5e-7, -9.81') > 0, &
         & 'body line in:'//nl//summary)
      if (allocated(error)) return
      call check(error, index(summary, 'box_size        = 1.0e20') > 0, 'large value in exponent form')
      if (allocated(error)) return
      call check(error, index(summary, 'box_min         = 0.0, 0.0') > 0, 'zeros')
      if (allocated(error)) return
      call check(error, index(summary, 'lower = 1.0, 0.1, upper = 3.0, 0.30000000000000004') > 0, &
         & '17 significant digits when needed')
      if (allocated(error)) return
      ! Three-digit exponents (the es descriptor's default width drops the 'E'),
      ! down to the smallest subnormal.
      text = replaced(minimal, 'young=1 poisson=0', 'young=1e-300 poisson=0 body_force=4.9e-324, -1.5e+300')
      text = replaced(text, 'box_size=4', 'box_size=1e100')
      call read_ok(text, s, error)
      if (allocated(error)) return
      summary = scene_summary(s)
      call check(error, index(summary, 'young = 1.0e-300, poisson = 0.0, body_force = 5.0e-324, -1.5e300') > 0, &
         & 'three-digit exponents in:'//nl//summary)
      if (allocated(error)) return
      call check(error, index(summary, 'box_size        = 1.0e100') > 0, 'box_size 1e100')
   end subroutine test_summary_reals

   !> A contact surface named by a polygon edge (a group of a faceted shape):
   !> its shape and group; the summary lists it among the contact surfaces and
   !> its shape's rest (edges without a condition) as traction-free.
   subroutine test_contact_group(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      integer :: k
      call read_file_ok('example/facets/hertz_cylinder_polygon.nml', s, error)
      if (allocated(error)) return
      k = s%contacts(1)%master_surface_index
      call check(error, k > 0, 'master surface found')
      if (allocated(error)) return
      call check(error, s%shapes(k)%name == 'block_part' .and. s%contacts(1)%master_group > 0 .and. &
         & s%contacts(1)%slave_group == 0, 'master: a group of block_part; slave: a whole shape')
      if (allocated(error)) return
      call check(error, s%shapes(k)%facets%group_name(s%contacts(1)%master_group) == 'block_top', 'group block_top')
      if (allocated(error)) return
      summary = scene_summary(s)
      call check_switch(error, summary, 'SPR-C contact', "on (surfaces 'rim', 'block_top')")
      if (allocated(error)) return
      call check(error, index(summary, "traction-free (no &bc): 'block_part'") > 0, 'the rest of the polygon is free')
   end subroutine test_contact_group

   subroutine test_contact(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      call read_ok(contact_text, s, error)
      if (allocated(error)) return
      call check(error, size(s%contacts), 1, 'one contact')
      if (allocated(error)) return
      call check(error, s%contacts(1)%slave_index == 1 .and. s%contacts(1)%master_index == 2, 'body indices')
      if (allocated(error)) return
      call check(error, s%contacts(1)%slave_surface_index == 1 .and. s%contacts(1)%master_surface_index == 2, &
         & 'surface indices')
      if (allocated(error)) return
      call check(error, s%contacts(1)%mu, 0.3_wp, 0.0_wp, 'mu')
      if (allocated(error)) return
      call check(error, s%contacts(1)%has_kappa, 'kappa given')
      if (allocated(error)) return
      summary = scene_summary(s)
      ! Contact surfaces are neither traction-free nor traction boundaries.
      call check(error, index(summary, 'traction-free (no &bc): none') > 0, 'contact surfaces are not traction-free')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C traction equilibrium', 'off (no traction boundary)')
      if (allocated(error)) return
      call check_switch(error, summary, 'SPR-C contact', "on (surfaces 'tip', 'top')")
      if (allocated(error)) return
      call check_switch(error, summary, 'contact', "on (slave 'punch' on master 'block', friction coulomb; "// &
         & 'coupled solve of both bodies, active-set iteration)')
      if (allocated(error)) return
      call check(error, index(summary, "contact: slave 'punch' surface 'tip', master 'block' surface 'top', "// &
         & 'friction = coulomb, mu = 0.3, kappa = 10.0, steps = 1, stabilization = fe') > 0, 'the pair line')
      if (allocated(error)) return
      call check(error, index(summary, 'NOT RUNNABLE') == 0, 'Coulomb friction with the FE stabilization runs')
   end subroutine test_contact

   !> A pair with only its required fields: the documented defaults.
   subroutine test_contact_defaults(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_ok(replaced(contact_text, "friction='coulomb' mu=0.3 kappa=10 /", '/'), s, error)
      if (allocated(error)) return
      associate (c => s%contacts(1))
         call check(error, c%friction == 'frictionless' .and. .not. c%has_kappa .and. c%steps == 1 .and. &
            & c%stabilization == 'fe', 'defaults: frictionless, kappa not given, steps 1, stabilization fe')
         if (allocated(error)) return
         call check(error, c%kappa, 1.0e4_wp, 0.0_wp, 'default kappa')
         if (allocated(error)) return
      end associate
      call check(error, has_switch(scene_summary(s), 'contact', "on (slave 'punch' on master 'block', friction "// &
         & 'frictionless; coupled solve of both bodies, active-set iteration)'), &
         & 'summary names the pair and the friction law')
      if (allocated(error)) return
      call check(error, index(scene_summary(s), 'kappa = 10000.0 (default), steps = 1, stabilization = fe') > 0, &
         & 'summary gives kappa, steps and stabilization with their defaults')
   end subroutine test_contact_defaults

   !> `multiplier` absent or 'auto' resolves when the scene is read: linear
   !> in 2D (Q1 and Q2), constant in 3D; a space written stays.
   subroutine test_contact_multiplier_auto(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: order(4) = ["levels=3        ", "levels=3 order=2", &
         & "levels=3 order=2", "levels=3 order=2"], &
         & written(4) = [character(len=26) :: '', '', "multiplier='auto' ", "multiplier='constant' "], &
         & expected(4) = [character(len=8) :: 'linear', 'linear', 'linear', 'constant']
      type(scene_type) :: s
      integer :: k
      do k = 1, size(order)
         call read_ok(replaced(replaced(contact_text, 'levels=3', trim(order(k))), '&contact ', &
            & '&contact '//trim(written(k))//' '), s, error)
         if (allocated(error)) return
         call check(error, s%contacts(1)%multiplier == trim(expected(k)), trim(order(k))//' '//trim(written(k))// &
            & ': multiplier '//s%contacts(1)%multiplier//', expected '//trim(expected(k)))
         if (allocated(error)) return
      end do
      call check(error, index(scene_summary(s), 'multiplier = constant') > 0, 'the summary gives the space')
      if (allocated(error)) return
      call check(error, auto_multiplier(3, 2) == 'constant' .and. auto_multiplier(3, 1) == 'constant', &
         & '3D resolves to constant')
   end subroutine test_contact_multiplier_auto

   !> The shrink fit: bc stages, a body with its own level-0 cell, the compound exact kind.
   subroutine test_shrink_fit(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      call read_file_ok('test/data/scenes/valid/shrink_fit.nml', s, error)
      if (allocated(error)) return
      call check(error, s%bcs(1)%stage == 2 .and. all(s%bcs(2:)%stage == 1), 'stage 2 on the bore, default 1 elsewhere')
      if (allocated(error)) return
      call check(error, .not. s%bodies(1)%has_box .and. s%bodies(1)%box_size == s%box_size .and. &
         & all(s%bodies(1)%box_min == s%box_min), 'shaft: the scene box')
      if (allocated(error)) return
      call check(error, s%bodies(2)%has_box .and. s%bodies(2)%box_size == 2.2_wp .and. &
         & all(s%bodies(2)%box_min == 0.0_wp), 'hub: its own box')
      if (allocated(error)) return
      associate (e => s%exact)
         call check(error, e%kind == 'compound_cylinder' .and. e%inner_index == 1 .and. e%outer_index == 2, &
            & 'compound_cylinder between shaft (inner) and hub (outer)')
         if (allocated(error)) return
         call check(error, e%r_in == 1.0_wp .and. e%r_contact == 1.5_wp .and. e%r_out == 2.0_wp .and. &
            & e%p_in == 1.0e-3_wp .and. e%interference == 1.0e-3_wp, 'radii, pressure, interference as written')
         if (allocated(error)) return
      end associate
      call check(error, s%contacts(1)%kappa, 10.0_wp, 0.0_wp, 'kappa as written')
      if (allocated(error)) return
      summary = scene_summary(s)
      call check(error, index(summary, "on 'bore': pressure, value = 0.001, stage = 2") > 0, 'stage in the bc line')
      if (allocated(error)) return
      call check(error, index(summary, 'box_min = 0.0, 0.0, box_size = 2.2 (its own level-0 cell)') > 0, 'body box')
      if (allocated(error)) return
      call check_switch(error, summary, 'load history', 'off (friction frictionless')
      if (allocated(error)) return
      call check_switch(error, summary, 'contact files', 'on (out/shrink_fit_contact.csv, out/shrink_fit_contact.svg)')
      if (allocated(error)) return
      call check(error, index(summary, 'NOT RUNNABLE') == 0, 'frictionless contact runs')
   end subroutine test_shrink_fit

   !> Coulomb friction with steps and the recovered stabilization; the Hertz kind.
   subroutine test_hertz_roller(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: summary
      call read_file_ok('test/data/scenes/valid/hertz_roller.nml', s, error)
      if (allocated(error)) return
      associate (c => s%contacts(1), e => s%exact)
         call check(error, c%friction == 'coulomb' .and. c%mu == 0.3_wp .and. c%steps == 4 .and. &
            & c%stabilization == 'recovered', 'coulomb, mu, steps, stabilization as written')
         if (allocated(error)) return
         call check(error, e%kind == 'hertz_cylinder' .and. all(e%point == 0.0_wp) .and. &
            & all(e%normal == [0.0_wp, 1.0_wp]) .and. e%radius == 1.0_wp .and. e%load == 2.0_wp, 'hertz fields')
         if (allocated(error)) return
      end associate
      summary = scene_summary(s)
      call check_switch(error, summary, 'load history', 'on (1 stage(s), 4 increment(s) each')
      if (allocated(error)) return
      call check_switch(error, summary, 'contact stabilization stress', 'recovered')
      if (allocated(error)) return
      call check_switch(error, summary, 'error columns (err_*, theta_*)', 'off (exact solution hertz_cylinder gives')
   end subroutine test_hertz_roller

   subroutine test_uniform_exact(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      call read_file_ok('test/data/scenes/valid/uniform_patch_3d.nml', s, error)
      if (allocated(error)) return
      call check(error, s%exact%kind == 'uniform' .and. size(s%exact%stress) == 6, 'uniform: 6 Voigt values in 3D')
      if (allocated(error)) return
      call check(error, s%exact%stress(3), -1.0_wp, 0.0_wp, 'sigma_zz')
      if (allocated(error)) return
      call check(error, s%contacts(1)%friction == 'stick', 'stick')
   end subroutine test_uniform_exact

   !> Shapes of two bodies interleaved in the file: each shape's index among
   !> its own body's shapes (what the body's geometry and conditions use).
   subroutine test_body_shapes(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: s
      character(len=:), allocatable :: text
      text = "&scene analysis='plane_strain' levels=3 box_min=0,0 box_size=4 /"//nl// &
         & "&body name='a' young=1000 poisson=0.3 /"//nl// &
         & "&body name='b' young=2000 poisson=0.25 /"//nl// &
         & "&shape body='b' op='add' kind='box' name='b1' lower=0,0 upper=1,1 /"//nl// &
         & "&shape body='a' op='add' kind='disk' name='a1' center=3,3 radius=0.5 /"//nl// &
         & "&shape body='b' op='subtract' kind='disk' name='b2' center=0,0 radius=0.5 /"//nl// &
         & "&shape body='a' op='intersect' kind='halfspace' name='a2' point=3,3 normal=0,-1 /"//nl// &
         & "&shape body='b' op='intersect' kind='halfspace' name='b3' point=0,0 normal=-1,0 /"//nl
      call read_ok(text, s, error)
      if (allocated(error)) return
      call check(error, all(s%shapes%body_index == [2, 1, 2, 1, 2]), 'body of each shape')
      if (allocated(error)) return
      call check(error, all(s%shapes%body_shape == [1, 1, 2, 2, 3]), 'index among the body''s shapes')
   end subroutine test_body_shapes

   subroutine test_missing_file(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(scene_type) :: s
      call read_scene(bad_dir//'does_not_exist.nml', s, e)
      call check(error, allocated(e), 'a missing file fails')
      if (allocated(error)) return
      call check(error, e%stat, stat_io, 'missing file is stat_io')
      if (allocated(error)) return
      call check(error, index(e%message, bad_dir//'does_not_exist.nml') > 0, 'message names the path')
   end subroutine test_missing_file

   !> The non-comment lines of EXPECT.
   subroutine expect_lines(lines, error)
      character(len=256), allocatable, intent(out) :: lines(:)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      character(len=:), allocatable :: text
      integer :: start, stop, n
      call read_text_file(bad_dir//'EXPECT', text, e)
      if (allocated(e)) then
         call test_failed(error, e%message)
         return
      end if
      allocate (lines(count([(text(n:n) == nl, n=1, len(text))])))
      n = 0
      start = 1
      do while (start <= len(text))
         stop = index(text(start:), nl) + start - 1
         if (stop < start) stop = len(text) + 1
         if (stop > start .and. text(start:start) /= '#') then
            n = n + 1
            lines(n) = text(start:stop - 1)
         end if
         start = stop + 1
      end do
      lines = lines(1:n)
   end subroutine expect_lines

   subroutine test_expect_count(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=256), allocatable :: lines(:)
      call expect_lines(lines, error)
      if (allocated(error)) return
      call check(error, size(lines) >= min_bad_files, 'EXPECT lists at least '//itoa(min_bad_files)//' malformed files')
   end subroutine test_expect_count

   subroutine test_malformed(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=256), allocatable :: lines(:)
      integer :: i
      call expect_lines(lines, error)
      if (allocated(error)) return
      do i = 1, size(lines)
         call check_malformed(trim(lines(i)), error)
         if (allocated(error)) return
      end do
   end subroutine test_malformed

   !> One EXPECT line: `file|substring|...`, optionally a field `stat=NAME`.
   subroutine check_malformed(line, error)
      character(len=*), intent(in) :: line
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(scene_type) :: s
      character(len=:), allocatable :: file, field
      integer :: start, bar, expected_stat

      bar = index(line, '|')
      if (bar <= 1) then
         call test_failed(error, 'bad EXPECT line: '//line)
         return
      end if
      file = line(1:bar - 1)
      call read_scene(bad_dir//file, s, e)
      if (.not. allocated(e)) then
         call test_failed(error, file//': accepted, but it is malformed')
         return
      end if
      expected_stat = stat_invalid_input
      start = bar + 1
      do while (start <= len(line))
         bar = index(line(start:), '|') + start - 1
         if (bar < start) bar = len(line) + 1
         field = line(start:bar - 1)
         start = bar + 1
         select case (field)
         case ('stat=io'); expected_stat = stat_io
         case ('stat=unsupported'); expected_stat = stat_unsupported
         case ('stat=invalid_input'); expected_stat = stat_invalid_input
         case default
            call check(error, index(e%message, field) > 0, file//': message "'//e%message//'" lacks "'//field//'"')
            if (allocated(error)) return
         end select
      end do
      call check(error, e%stat, expected_stat, file//': status of "'//e%message//'"')
   end subroutine check_malformed

end module sprc_test_scene
