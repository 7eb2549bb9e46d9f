!> Convergence and small-cut studies of the FE layer (the heavier companions
!> of test/unit/fem.f90), printed as tables:
!> - err_fe (energy norm, relative) against the level for the Lame cylinder
!>   quarter (plane strain and plane stress, Q1 and Q2 levels 3..6), the
!>   Kirsch quarter plate (plane stress, Q1 and Q2 3..7) and the Lame sphere
!>   octant (Q1 2..4), with the rate log2(err(l-1)/err(l)), the number of
!>   aggregated cells and the times, and the rate over the last three levels
!>   log4(err(L-2)/err(L));
!> - the small-cut sweep: the Lame quarter (level 4) cut by x = 10 h + delta h
!>   (exact traction there) for delta = 0 (no cut) and 1e-1 .. 1e-12: smallest
!>   cut fraction, reciprocal condition estimate of the diagonally scaled
!>   stiffness, err_fe.
!> Run: fpm run --example fem_convergence [--profile release]
program fem_convergence
   use, intrinsic :: iso_fortran_env, only: output_unit
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_material, only: plane_stress, plane_strain, solid, analysis_name
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_halfspace, new_box
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_exact_solution, only: exact_solution_type
   use sprc_exact_lame, only: lame_cylinder_type, new_lame_cylinder, lame_sphere_type, new_lame_sphere
   use sprc_exact_kirsch, only: kirsch_type, new_kirsch
   use sprc_fem_bc, only: fe_bc_type, new_fe_bc, bc_free, bc_pressure, bc_symmetry, bc_exact_traction
   use sprc_fem_problem, only: elasticity_problem_type, solve_on_grid
   implicit none

   real(wp), parameter :: young = 1000.0_wp, poisson = 0.3_wp
   type(body_type) :: body
   type(fe_bc_type), allocatable :: bcs(:)
   type(lame_cylinder_type) :: cylinder
   type(kirsch_type) :: kirsch
   type(lame_sphere_type) :: sphere
   type(error_type), allocatable :: error
   integer :: a, p
   integer, parameter :: analyses(2) = [plane_strain, plane_stress]

   do a = 1, 2
      call lame_body(analyses(a), -1.0_wp)
      do p = 1, 2
         call study('Lame cylinder '//analysis_name(analyses(a)), body, bcs, cylinder, [0.0_wp, 0.0_wp], &
            & 25.0_wp, p, analyses(a), 3, 6)
      end do
   end do
   call kirsch_body()
   do p = 1, 2
      call study('Kirsch plate plane_stress', body, bcs, kirsch, [0.0_wp, 0.0_wp], 10.0_wp, p, plane_stress, 3, 7)
   end do
   call sphere_body()
   call study('Lame sphere solid', body, bcs, sphere, [0.0_wp, 0.0_wp, 0.0_wp], 25.0_wp, 1, solid, 2, 4)
   do p = 1, 2
      call sweep(p)
   end do

contains

   subroutine stop_on(error)
      type(error_type), allocatable, intent(in) :: error
      if (allocated(error)) then
         write (output_unit, '(a)') 'error: '//error%message
         error stop 1
      end if
   end subroutine stop_on

   subroutine make(shapes, ops)
      type(shape_type), intent(in) :: shapes(:)
      integer, intent(in) :: ops(:)
      integer :: i
      call new_body(body, 'bench')
      do i = 1, size(shapes)
         call body%add_shape(ops(i), shapes(i), error)
         call stop_on(error)
      end do
   end subroutine make

   !> Lame quarter; cut > 0 adds the halfspace x <= cut with exact traction.
   subroutine lame_body(analysis, cut)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: cut
      type(shape_type) :: s(5)
      call new_disk(s(1), 'outer', [0.0_wp, 0.0_wp], 20.0_wp, error)
      call new_disk(s(2), 'inner', [0.0_wp, 0.0_wp], 5.0_wp, error)
      call new_halfspace(s(3), 'sym_x', [0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      call new_halfspace(s(4), 'sym_y', [0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], error)
      bcs = [new_fe_bc(2, bc_pressure, value=1.0_wp), new_fe_bc(3, bc_symmetry), new_fe_bc(4, bc_symmetry)]
      if (cut > 0.0_wp) then
         call new_halfspace(s(5), 'cut', [cut, 0.0_wp], [1.0_wp, 0.0_wp], error)
         call make(s, [csg_add, csg_subtract, csg_intersect, csg_intersect, csg_intersect])
         bcs = [bcs, new_fe_bc(5, bc_exact_traction)]
      else
         call make(s(1:4), [csg_add, csg_subtract, csg_intersect, csg_intersect])
      end if
      call new_lame_cylinder(cylinder, [0.0_wp, 0.0_wp], 5.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, young, poisson, &
         & analysis, error)
      call stop_on(error)
   end subroutine lame_body

   subroutine kirsch_body()
      type(shape_type) :: s(4)
      call new_box(s(1), 'edges', [-10.0_wp, -10.0_wp], [10.0_wp, 10.0_wp], error)
      call new_disk(s(2), 'hole', [0.0_wp, 0.0_wp], 1.0_wp, error)
      call new_halfspace(s(3), 'sym_x', [0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], error)
      call new_halfspace(s(4), 'sym_y', [0.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], error)
      call make(s, [csg_add, csg_subtract, csg_intersect, csg_intersect])
      bcs = [new_fe_bc(1, bc_exact_traction), new_fe_bc(2, bc_free), new_fe_bc(3, bc_symmetry), &
         & new_fe_bc(4, bc_symmetry)]
      call new_kirsch(kirsch, [0.0_wp, 0.0_wp], 1.0_wp, 1.0_wp, young, poisson, plane_stress, error)
      call stop_on(error)
   end subroutine kirsch_body

   subroutine sphere_body()
      type(shape_type) :: s(5)
      real(wp) :: n(3)
      integer :: k
      call new_sphere(s(1), 'outer', [0.0_wp, 0.0_wp, 0.0_wp], 20.0_wp, error)
      call new_sphere(s(2), 'inner', [0.0_wp, 0.0_wp, 0.0_wp], 10.0_wp, error)
      do k = 1, 3
         n = 0.0_wp
         n(k) = -1.0_wp
         call new_halfspace(s(2 + k), 'sym'//achar(119 + k), [0.0_wp, 0.0_wp, 0.0_wp], n, error)
      end do
      call make(s, [csg_add, csg_subtract, csg_intersect, csg_intersect, csg_intersect])
      bcs = [new_fe_bc(2, bc_pressure, value=1.0_wp), (new_fe_bc(2 + k, bc_symmetry), k = 1, 3)]
      call new_lame_sphere(sphere, [0.0_wp, 0.0_wp, 0.0_wp], 10.0_wp, 20.0_wp, 1.0_wp, 0.0_wp, young, poisson, error)
      call stop_on(error)
   end subroutine sphere_body

   subroutine study(title, body, bcs, exact, box_min, box_size, degree, analysis, l0, l1)
      character(len=*), intent(in) :: title
      type(body_type), intent(in) :: body
      type(fe_bc_type), intent(in) :: bcs(:)
      class(exact_solution_type), intent(in) :: exact
      real(wp), intent(in) :: box_min(:), box_size
      integer, intent(in) :: degree, analysis, l0, l1
      type(elasticity_problem_type) :: problem
      real(wp), allocatable :: ee(:)
      real(wp) :: err, prev, nfe, nex, rate, errs(0:l1)
      integer :: level

      write (output_unit, '(/,a," Q",i0)') title, degree
      write (output_unit, '(a5,a11,a9,a12,a7,a7,a9,a9,a9)') 'level', 'h', 'dofs', 'err_fe', 'rate', 'aggr', &
         & 't_quad', 't_asm', 't_solve'
      prev = -1.0_wp
      do level = l0, l1
         call solve_on_grid(problem, body, box_min, box_size, level, 0, degree, analysis, young, poisson, &
            & spread(0.0_wp, 1, size(box_min)), bcs, error, exact=exact)
         call stop_on(error)
         call problem%energy_error(err, ee, nfe, nex, error)
         call stop_on(error)
         rate = 0.0_wp
         if (prev > 0.0_wp) rate = log(prev/err)/log(2.0_wp)
         write (output_unit, '(i5,es11.3,i9,es12.4,f7.3,i7,3f9.3)') level, box_size*2.0_wp**(-level), &
            & problem%n_dofs(), err, rate, problem%n_aggregated, problem%mesh%t_quadrature, problem%t_assembly, &
            & problem%t_solve
         prev = err
         errs(level) = err
      end do
      if (l1 - l0 >= 2) write (output_unit, '(a,i0,a,i0,a,f6.3,a,f6.3,a)') 'rate over levels ', l1 - 2, '..', l1, &
         & ': ', log(errs(l1 - 2)/errs(l1))/log(4.0_wp), '  (required >= 0.95 p = ', 0.95_wp*real(degree, wp), ')'
   end subroutine study

   subroutine sweep(degree)
      integer, intent(in) :: degree
      real(wp), parameter :: deltas(8) = [0.0_wp, 1.0e-1_wp, 1.0e-2_wp, 1.0e-4_wp, 1.0e-6_wp, 1.0e-8_wp, &
         & 1.0e-10_wp, 1.0e-12_wp]
      type(elasticity_problem_type) :: problem
      real(wp), allocatable :: ee(:)
      real(wp) :: h, err, nfe, nex, rc
      integer :: i

      h = 25.0_wp/16.0_wp
      write (output_unit, '(/,a,i0,a)') 'Small cuts: Lame quarter plane_strain, level 4, Q', degree, &
         & ', cut x = 10 h + delta h'
      write (output_unit, '(a11,a14,a14,a14,a8)') 'delta', 'min fraction', 'rcond(scaled)', 'err_fe', 'aggr'
      do i = 1, size(deltas)
         call lame_body(plane_strain, 10.0_wp*h + deltas(i)*h)
         call solve_on_grid(problem, body, [0.0_wp, 0.0_wp], 25.0_wp, 4, 0, degree, plane_strain, young, &
            & poisson, [0.0_wp, 0.0_wp], bcs, error, exact=cylinder)
         call stop_on(error)
         call problem%energy_error(err, ee, nfe, nex, error)
         call stop_on(error)
         call problem%scaled_rcond(rc, error)
         call stop_on(error)
         write (output_unit, '(es11.2,es14.3,es14.3,es14.6,i8)') deltas(i), minval(problem%mesh%fraction), rc, err, &
            & problem%n_aggregated
      end do
   end subroutine sweep

end program fem_convergence
