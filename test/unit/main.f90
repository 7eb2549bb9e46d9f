!> Unit-test driver: `unit [SUITE [TEST]]` runs all suites, one suite, or one
!> test; prints one line per test and `N passed, M failed` last; exits non-zero
!> on any failure or an unknown selection. Suites are named LAYER/NAME after the
!> layer they test (doc/architecture.md); SUITE is LAYER/NAME, NAME, or LAYER/
!> for every suite of the layer. `unit --full [SUITE [TEST]]` runs the
!> expensive variants of the tiered tests too (sprc_testsuite, `make test-full`).
program sprc_unit_tests
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use sprc_testsuite, only: testsuite_type, new_testsuite, run_testsuite, set_full_tier
   use sprc_test_core, only: collect_core
   use sprc_test_poly, only: collect_poly
   use sprc_test_sparse, only: collect_sparse
   use sprc_test_exact, only: collect_exact
   use sprc_test_exact_contact, only: collect_exact_contact
   use sprc_test_exact_corner, only: collect_exact_corner
   use sprc_test_exact_layered, only: collect_exact_layered
   use sprc_test_contact_surface, only: collect_contact_surface
   use sprc_test_namelist, only: collect_namelist
   use sprc_test_scene, only: collect_scene
   use sprc_test_facet_files, only: collect_facet_files
   use sprc_test_geometry, only: collect_geometry
   use sprc_test_grid, only: collect_grid
   use sprc_test_adapt, only: collect_adapt
   use sprc_test_model, only: collect_model
   use sprc_test_quadrature, only: collect_quadrature
   use sprc_test_facets, only: collect_facets
   use sprc_test_recovery, only: collect_recovery
   use sprc_test_report, only: collect_report
   use sprc_test_output, only: collect_output
   use sprc_test_fem, only: collect_fem
   use sprc_test_patches, only: collect_patches
   use sprc_test_singular, only: collect_singular
   use sprc_test_mesh_recovery, only: collect_mesh_recovery
   use sprc_test_contact_mesh, only: collect_contact_mesh
   use sprc_test_stiff, only: collect_stiff
   use sprc_test_study, only: collect_study
   use sprc_test_adaptive, only: collect_adaptive
   use sprc_test_contact_model, only: collect_contact_model
   use sprc_test_contact_output, only: collect_contact_output
   use sprc_test_contact_fe, only: collect_contact_fe
   use sprc_test_contact_assembly, only: collect_contact_assembly
   use sprc_test_contact_friction, only: collect_contact_friction
   use sprc_test_contact_iterative, only: collect_contact_iterative
   use sprc_test_petsc, only: collect_petsc
   use sprc_test_contact_recovery, only: collect_contact_recovery
   use sprc_test_partition, only: collect_partition
   use sprc_test_testsuite, only: collect_testsuite
   implicit none

   type(testsuite_type), allocatable :: suites(:)
   character(len=:), allocatable :: suite_name, test_name
   integer :: i, npass, nfail, nrun, first

   suites = [ &
      new_testsuite('core/core', collect_core), &
      new_testsuite('core/poly', collect_poly), &
      new_testsuite('fem/sparse', collect_sparse), &
      new_testsuite('exact/exact', collect_exact), &
      new_testsuite('exact/exact_contact', collect_exact_contact), &
      new_testsuite('exact/exact_corner', collect_exact_corner), &
      new_testsuite('exact/exact_layered', collect_exact_layered), &
      new_testsuite('contact/contact_surface', collect_contact_surface), &
      new_testsuite('io/namelist', collect_namelist), &
      new_testsuite('io/scene', collect_scene), &
      new_testsuite('io/facet_files', collect_facet_files), &
      new_testsuite('geometry/geometry', collect_geometry), &
      new_testsuite('grid/grid', collect_grid), &
      new_testsuite('grid/adapt', collect_adapt), &
      new_testsuite('study/model', collect_model), &
      new_testsuite('grid/quadrature', collect_quadrature), &
      new_testsuite('geometry/facets', collect_facets), &
      new_testsuite('recovery/recovery', collect_recovery), &
      new_testsuite('io/report', collect_report), &
      new_testsuite('estimate/patches', collect_patches), &
      new_testsuite('estimate/singular', collect_singular), &
      new_testsuite('io/output', collect_output), &
      new_testsuite('fem/fem', collect_fem), &
      new_testsuite('recovery/mesh_recovery', collect_mesh_recovery), &
      new_testsuite('contact/contact_mesh', collect_contact_mesh), &
      new_testsuite('fem/stiff', collect_stiff), &
      new_testsuite('study/study', collect_study), &
      new_testsuite('study/adaptive', collect_adaptive), &
      new_testsuite('study/contact_model', collect_contact_model), &
      new_testsuite('io/contact_output', collect_contact_output), &
      new_testsuite('contact/contact_fe', collect_contact_fe), &
      new_testsuite('contact/contact_assembly', collect_contact_assembly), &
      new_testsuite('contact/contact_friction', collect_contact_friction), &
      new_testsuite('contact/contact_iterative', collect_contact_iterative), &
      new_testsuite('fem/petsc', collect_petsc), &
      new_testsuite('recovery/contact_recovery', collect_contact_recovery), &
      new_testsuite('study/partition', collect_partition), &
      new_testsuite('harness/testsuite', collect_testsuite) &
      ]

   call get_arg(1, suite_name)
   first = 1
   if (suite_name == '--full') then
      call set_full_tier(.true.)
      first = 2
   end if
   call get_arg(first, suite_name)
   call get_arg(first + 1, test_name)
   npass = 0
   nfail = 0
   nrun = 0
   do i = 1, size(suites)
      if (.not. selected(suites(i)%name, suite_name)) cycle
      nrun = nrun + 1
      call run_testsuite(suites(i), test_name, output_unit, npass, nfail)
   end do
   if (nrun == 0 .or. npass + nfail == 0) then
      write (error_unit, '(a)') 'unit: no suite or test matches "'//suite_name//' '//test_name//'"'
      nfail = nfail + 1
   end if
   write (output_unit, '(i0," passed, ",i0," failed")') npass, nfail
   if (nfail > 0) error stop 1

contains

   !> Whether suite `name` (LAYER/SUITE) is selected by the first argument:
   !> none, its full name, its SUITE part, or LAYER/ for all suites of a layer.
   pure logical function selected(name, arg)
      character(len=*), intent(in) :: name, arg
      integer :: slash
      slash = index(name, '/')
      selected = len(arg) == 0 .or. arg == name .or. arg == name(slash + 1:)
      if (len(arg) > 0 .and. slash > 0) selected = selected .or. arg == name(1:slash)
   end function selected

   subroutine get_arg(i, arg)
      integer, intent(in) :: i
      character(len=:), allocatable, intent(out) :: arg
      integer :: length
      call get_command_argument(i, length=length)
      allocate (character(len=length) :: arg)
      if (length > 0) call get_command_argument(i, arg)
   end subroutine get_arg

end program sprc_unit_tests
