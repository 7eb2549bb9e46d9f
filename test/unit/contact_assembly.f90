!> Tests of contact assemblies: several `&contact` pairs solved as one
!> coupled system per component of the contact graph (sprc_study_level,
!> sprc_contact_pair_solve's solve_contact_assembly).
!>
!> - A stack of three blocks of different materials on offset grids, the
!>   middle one the slave of one pair and the master of the other, under a
!>   uniform pressure: the uniform stress in every body and the pressure 1 at
!>   every closed point of both pairs to round-off, C eps/rcond with rcond
!>   the block solver's condition estimate and C = 10 (as the one-pair patch
!>   test, sprc_test_contact_fe); with SPR and SPR-C the recovered fields
!>   too. The middle block (0.3 tall, cells 0.36 at level 2) has vertex
!>   patches holding contact points of both pairs (10 at levels 2 and 3),
!>   where one pair's coupled contact patch wins and the other's points are
!>   left out (sprc_estimate_patches): keeping them fails Q2 (the patch's
!>   contact normals cancel), letting the pair with fewer points win fails
!>   Q1.
!> - Three concentric rings with two interference fits and a bore pressure
!>   against the layered_cylinder closed form (on the real radii): err_fe
!>   at a rate of at least 0.95 p over the last two levels, theta_sprc in
!>   [0.95, 1.05] at the finest level; each pair's pressure error: Q1 at
!>   the finest level at most half of that at the coarsest, Q2 at every
!>   level at most a tenth of err_fe; each pair's mean pressure (the force
!>   the interface carries, a functional of the solution) converging at a
!>   rate of at least 0.95 p over the three levels (Q2: 2.8 to 3.9), which
!>   a reference off by the interference (delta/r = 1e-5) would stop, as
!>   would a wrong sampling of p_ex. The Q2 multiplier's L2 error pauses near 4e-6
!>   at levels 5-6 (5e-7 at level 7) while its mean is right to 1e-8 and
!>   1e-9 of p: most of it (87 % of the square at level 6) is two adjacent
!>   contact cells at a sliver of the slave's cut boundary, a local
!>   oscillation of the multiplier, not the reference. Q1 and Q2, plane
!>   strain and plane stress.
!> - Three concentric spherical shells (octant, Q1) against layered_sphere
!>   on the real radii, levels 2 and 3: err_fe at a rate of at least 0.85
!>   (a stated pre-asymptotic tier: 0.89 at levels 2-3, 0.97 at 3-4, which
!>   costs too much here), each pair's pressure error and mean pressure
!>   error at a rate of at least 0.95 p (1.39-1.41 and 1.75-1.80).
!> - Two Hertz rollers on one block (two pairs sharing the block's top as
!>   master surface): each pair's peak pressure within the single roller's
!>   3 % of its own Hertz p0.
module sprc_test_contact_assembly
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_text, only: real_text
   use sprc_io_namelist, only: read_text_file
   use sprc_study_level, only: study_type, level_type
   use sprc_test_study, only: run_text
   use sprc_contact_result, only: contact_open, contact_result_type
   use sprc_testsuite, only: unittest_type, new_unittest, check, replaced
   implicit none
   private

   public :: collect_contact_assembly

   character(len=*), parameter :: stack_2d = 'test/data/contact/stack_2d.nml'
   character(len=*), parameter :: rollers_2d = 'example/scenes/two_rollers.nml'
   character(len=*), parameter :: rings = 'example/scenes/layered_rings.nml'
   character(len=*), parameter :: shells = 'test/data/contact/layered_sphere.nml'

contains

   subroutine collect_contact_assembly(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('stack_q1', test_stack_q1), &
         new_unittest('stack_q2', test_stack_q2), &
         new_unittest('stack_q1_linear', test_stack_q1_linear), &
         new_unittest('layered_rings_q1_plane_strain', test_rings_q1_strain), &
         new_unittest('layered_rings_q1_plane_stress', test_rings_q1_stress), &
         new_unittest('layered_rings_q2_plane_strain', test_rings_q2_strain), &
         new_unittest('layered_rings_q2_plane_stress', test_rings_q2_stress), &
         new_unittest('layered_sphere_q1', test_layered_sphere), &
         new_unittest('two_rollers', test_two_rollers), &
         new_unittest('unloaded_fits_cycle_warned', test_cycle_warned) &
         ]
   end subroutine collect_contact_assembly

   subroutine test_stack_q1(error)
      type(error_type), allocatable, intent(out) :: error
      call stack_case(1, 3, error)
   end subroutine test_stack_q1

   subroutine test_stack_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call stack_case(2, 2, error)
   end subroutine test_stack_q2

   !> The stack with the linear multiplier on both pairs: still exact.
   subroutine test_stack_q1_linear(error)
      type(error_type), allocatable, intent(out) :: error
      call stack_case(1, 3, error, linear=.true.)
   end subroutine test_stack_q1_linear

   !> The stack at `order` and `level` with SPR and SPR-C (module notes).
   subroutine stack_case(order, level, error, linear)
      integer, intent(in) :: order, level
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: linear
      type(level_type) :: result
      type(study_type) :: study
      character(len=:), allocatable :: text
      real(wp) :: tol, worst, pworst, unit, sigma(3)
      integer :: b, e, q, k

      call read_text_file(stack_2d, text, error)
      if (allocated(error)) return
      text = replaced(text, 'order    = 1', 'order    = '//achar(48 + order))
      text = replaced(text, "recovery = 'none'", "recovery = 'both'")
      if (present(linear)) then
         text = replaced(text, "&contact slave='middle'", "&contact multiplier='linear' slave='middle'")
         text = replaced(text, "&contact slave='top'", "&contact multiplier='linear' slave='top'")
      end if
      call run_text(text, level, result, error, study)
      if (allocated(error)) return
      call check(error, size(result%contacts), 2, 'two pairs')
      if (allocated(error)) return
      tol = 0.0_wp
      worst = 0.0_wp
      do b = 1, 3
         associate (pb => result%bodies(b)%problem)
            unit = study%bodies(b)%units%modulus*study%bodies(b)%units%strain
            tol = max(tol, 10.0_wp*epsilon(1.0_wp)/pb%rcond)
            do e = 1, pb%mesh%grid%n_leaves
               do q = pb%mesh%vol_ptr(e), pb%mesh%vol_ptr(e + 1) - 1
                  call pb%stress_in_element(e, pb%mesh%vol_x(:, q), sigma)
                  worst = max(worst, maxval(abs(sigma*unit - [0.0_wp, -1.0_wp, 0.0_wp])))
               end do
            end do
         end associate
      end do
      call check(error, worst <= tol, 'uniform stress: max error '//real_text(worst)//' > '//real_text(tol))
      if (allocated(error)) return
      do k = 1, 2
         associate (c => result%contacts(k))
            call check(error, all(c%state /= contact_open), 'pair '//achar(48 + k)//': every slave point closed')
            if (allocated(error)) return
            pworst = maxval(abs(c%p_fe - 1.0_wp))
            call check(error, pworst <= tol, 'pair '//achar(48 + k)//': pressure error '//real_text(pworst)//' > '// &
               & real_text(tol))
            if (allocated(error)) return
         end associate
      end do
      ! The recovered fields (relative energy errors of a uniform field of norm O(1)).
      call check(error, max(result%row%err_fe, result%row%err_spr, result%row%err_sprc) <= tol, &
         & 'err_fe, err_spr, err_sprc '//real_text(result%row%err_fe)//', '//real_text(result%row%err_spr)// &
         & ', '//real_text(result%row%err_sprc)//' > '//real_text(tol))
      if (allocated(error)) return
      ! One component: its iterations counted once, not once per pair.
      call check(error, result%row%contact_iterations, result%contacts(1)%iterations, 'contact_iterations')
   end subroutine stack_case

   subroutine test_rings_q1_strain(error)
      type(error_type), allocatable, intent(out) :: error
      call rings_case(1, 'plane_strain', [3, 4, 5], error)
   end subroutine test_rings_q1_strain

   subroutine test_rings_q1_stress(error)
      type(error_type), allocatable, intent(out) :: error
      call rings_case(1, 'plane_stress', [3, 4, 5], error)
   end subroutine test_rings_q1_stress

   subroutine test_rings_q2_strain(error)
      type(error_type), allocatable, intent(out) :: error
      call rings_case(2, 'plane_strain', [2, 3, 4], error)
   end subroutine test_rings_q2_strain

   subroutine test_rings_q2_stress(error)
      type(error_type), allocatable, intent(out) :: error
      call rings_case(2, 'plane_stress', [2, 3, 4], error)
   end subroutine test_rings_q2_stress

   !> The layered rings at `order` in `analysis` on `levels` (module notes).
   subroutine rings_case(order, analysis, levels, error)
      integer, intent(in) :: order, levels(3)
      character(len=*), intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text, what
      real(wp) :: err(3), theta, perr(2, 3), pmean(2, 3), rate
      integer :: l, k

      call read_text_file(rings, text, error)
      if (allocated(error)) return
      text = replaced(text, 'order    = 1', 'order    = '//achar(48 + order))
      text = replaced(text, "analysis = 'plane_strain'", "analysis = '"//analysis//"'")
      text = replaced(text, "recovery = 'both'", "recovery = 'sprc'")
      text = replaced(text, "output   = 'out/layered_rings'", "output   = ''")
      what = 'Q'//achar(48 + order)//' '//analysis//': '
      do l = 1, 3
         call run_text(text, levels(l), result, error)
         if (allocated(error)) return
         err(l) = result%row%err_fe
         theta = result%row%theta_sprc
         do k = 1, 2
            call pressure_errors(result%contacts(k), perr(k, l), pmean(k, l))
         end do
      end do
      rate = log(err(2)/err(3))/log(2.0_wp)
      call check(error, rate >= 0.95_wp*order, what//'err_fe rate '//real_text(rate)//' (err_fe '// &
         & real_text(err(2))//', '//real_text(err(3))//')')
      if (allocated(error)) return
      call check(error, theta >= 0.95_wp .and. theta <= 1.05_wp, what//'theta_sprc '//real_text(theta))
      if (allocated(error)) return
      do k = 1, 2
         if (order == 1) then
            call check(error, perr(k, 3) <= 0.5_wp*perr(k, 1), what//'pair '//achar(48 + k)//' pressure error '// &
               & real_text(perr(k, 1))//' -> '//real_text(perr(k, 3))//' does not converge')
         else
            call check(error, all(perr(k, :) <= 0.1_wp*err), what//'pair '//achar(48 + k)//' pressure errors '// &
               & real_text(perr(k, 1))//', '//real_text(perr(k, 2))//', '//real_text(perr(k, 3))// &
               & ' not a tenth of err_fe')
         end if
         if (allocated(error)) return
         rate = log(pmean(k, 1)/pmean(k, 3))/log(2.0_wp**(levels(3) - levels(1)))
         call check(error, rate >= 0.95_wp*order, what//'pair '//achar(48 + k)//' mean pressure error '// &
            & real_text(pmean(k, 1))//' -> '//real_text(pmean(k, 3))//': rate '//real_text(rate))
         if (allocated(error)) return
      end do
   end subroutine rings_case

   !> The layered shells (module notes).
   subroutine test_layered_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: err(2), perr(2, 2), pmean(2, 2), rate
      integer :: l, k

      call read_text_file(shells, text, error)
      if (allocated(error)) return
      do l = 1, 2
         call run_text(text, l + 1, result, error)
         if (allocated(error)) return
         err(l) = result%row%err_fe
         do k = 1, 2
            call pressure_errors(result%contacts(k), perr(k, l), pmean(k, l))
         end do
      end do
      rate = log(err(1)/err(2))/log(2.0_wp)
      call check(error, rate >= 0.85_wp, 'err_fe rate '//real_text(rate)//' (err_fe '//real_text(err(1))//', '// &
         & real_text(err(2))//')')
      do k = 1, 2
         if (allocated(error)) return
         rate = min(log(perr(k, 1)/perr(k, 2)), log(pmean(k, 1)/pmean(k, 2)))/log(2.0_wp)
         call check(error, rate >= 0.95_wp, 'pair '//achar(48 + k)//' pressure error '//real_text(perr(k, 1))// &
            & ' -> '//real_text(perr(k, 2))//', mean '//real_text(pmean(k, 1))//' -> '//real_text(pmean(k, 2)))
      end do
   end subroutine test_layered_sphere

   !> The relative L2 error of a pair's multiplier over its slave surface, and that of its
   !> surface mean (the force the interface carries).
   subroutine pressure_errors(c, perr, pmean)
      type(contact_result_type), intent(in) :: c
      real(wp), intent(out) :: perr, pmean
      perr = sqrt(sum(c%weight*(c%p_fe - c%p_exact)**2)/sum(c%weight*c%p_exact**2))
      pmean = abs(sum(c%weight*(c%p_fe - c%p_exact)))/sum(c%weight*c%p_exact)
   end subroutine pressure_errors

   !> Each roller's peak within 3 % of its Hertz p0 = 2P/(pi a), a =
   !> sqrt(4 P R/(pi E*)), 1/E* = 2 (1 - nu^2)/E (module notes).
   subroutine test_two_rollers(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: pi = acos(-1.0_wp), young = 1000.0_wp, nu = 0.3_wp, radius = 1.0_wp
      real(wp), parameter :: load(2) = [1.0788436_wp, 2.1576872_wp]
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: e_star, a, p0, pmax
      integer :: k

      call read_text_file(rollers_2d, text, error)
      if (allocated(error)) return
      text = replaced(replaced(text, "recovery = 'both'", "recovery = 'none'"), "output   = 'out/two_rollers'", &
         & "output   = ''")
      call run_text(text, 6, result, error)
      if (allocated(error)) return
      e_star = young/(2.0_wp*(1.0_wp - nu**2))
      do k = 1, 2
         a = sqrt(4.0_wp*load(k)*radius/(pi*e_star))
         p0 = 2.0_wp*load(k)/(pi*a)
         pmax = maxval(result%contacts(k)%p_fe)
         call check(error, abs(pmax/p0 - 1.0_wp) <= 0.03_wp, 'roller '//achar(48 + k)//': p_max/p0 = '// &
            & real_text(pmax/p0))
         if (allocated(error)) return
      end do
   end subroutine test_two_rollers

   !> Two closed fits under no load (the shaft and hub of
   !> test/data/contact/closed_fit_unloaded.nml, the hub in a third ring
   !> fixed outside; stick, one assembly, level 4): the linear multiplier's
   !> set cycles on round-off in the assembly's iteration too; the pair whose
   !> set repeated carries the warning (the hub's pair comes first in the
   !> scene).
   subroutine test_cycle_warned(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      character(len=:), allocatable :: text

      call read_text_file('test/data/contact/closed_fit_unloaded.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "&body name='hub' young=1.0 poisson=0.25 /", &
         & "&body name='hub' young=1.0 poisson=0.25 box_min=-2.03,-2.02 box_size=4.1 /"//new_line('a')// &
         & "&body name='ring' young=1.0 poisson=0.25 /"//new_line('a')// &
         & "&shape body='ring' op='add' kind='disk' name='ring_out' center=0.013,0.021 radius=2.5 /"// &
         & new_line('a')//"&shape body='ring' op='subtract' kind='disk' name='ring_in' center=0.013,0.021 "// &
         & "radius=2 /"//new_line('a')//"&contact slave='hub' master='ring' slave_surface='hub_out' "// &
         & "master_surface='ring_in' friction='stick' /")
      text = replaced(text, "&bc on='hub_out' type='displacement'", "&bc on='ring_out' type='displacement'")
      call run_text(text, 4, result, error)
      if (allocated(error)) return
      call check(error, allocated(result%contacts(1)%warning), 'a warning')
      if (allocated(error)) return
      call check(error, index(result%contacts(1)%warning, "contact 'hub' on 'ring': the active set repeated an "// &
         & 'earlier one at active-set iteration ') == 1, "warning '"//result%contacts(1)%warning//"'")
   end subroutine test_cycle_warned

end module sprc_test_contact_assembly
