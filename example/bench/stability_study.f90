!> Stability study (issue 15): the Lame quarter cylinder of the default scene
!> (plane strain, pressure 1 inside) run through the driver's own path
!> (`prepare_study`, `run_level`), under
!>   1. a Poisson sweep 0.3 ... 0.4999, Q1 and Q2 (level 6), with the
!>      displacement formulation (dilatation = 'full') and the locking-free one
!>      ('projected');
!>   1b. the same in 3D on the Lame sphere octant (Q1 level 5, Q2 level 4; poisson 0.3
!>      and 0.4999);
!>   2. Young's modulus 1e-6 ... 1e12 (Q1, level 5; relative errors must not move);
!>   3. the Nitsche penalty factor gamma over six decades (Q1 and Q2, level 5) on a
!>      variant where Nitsche carries every condition: the grid is shifted so the
!>      symmetry planes cut cells (weak symmetry) and the outer surface has the
!>      exact displacement;
!>   4. a tiny cut: the body cut by the plane x = 10 h + delta h (exact
!>      traction there), delta = 0 ... 1e-12 (Q1 and Q2, level 4).
!> Each row: err_fe, err_sprc, eta_sprc, theta_sprc and CHOLMOD's reciprocal
!> condition estimate of the stiffness (rcond), as a Markdown table (the README's).
!> Then the checks of the issue's targets; the last line counts the failures.
!> Run: fpm run --profile release --example stability_study [-- nu | sphere | young | gamma | cut]
program stability_study
   use, intrinsic :: iso_fortran_env, only: output_unit
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_io_scene, only: scene_type, read_scene_text
   use sprc_study_level, only: study_type, prepare_study, run_level, level_type
   use sprc_study_row, only: report_row_type
   use sprc_fem_problem, only: default_gamma, gamma_note
   implicit none

   !> One row of the study.
   type :: result_type
      real(wp) :: err_fe = 0.0_wp, err_sprc = 0.0_wp, eta_sprc = 0.0_wp, theta = 0.0_wp, rcond = 0.0_wp
   end type result_type

   character(len=*), parameter :: nl = new_line('a')
   character(len=16) :: arg
   integer :: i, nfail

   nfail = 0
   if (command_argument_count() == 0) then
      call nu_sweep()
      call sphere_sweep()
      call young_sweep()
      call gamma_sweep()
      call cut_sweep()
   else
      do i = 1, command_argument_count()
         call get_command_argument(i, arg)
         select case (arg)
         case ('nu')
            call nu_sweep()
         case ('sphere')
            call sphere_sweep()
         case ('young')
            call young_sweep()
         case ('gamma')
            call gamma_sweep()
         case ('cut')
            call cut_sweep()
         case default
            write (output_unit, '("unknown section ",a,": nu, sphere, young, gamma, cut")') trim(arg)
            nfail = nfail + 1
         end select
      end do
   end if
   write (output_unit, '(/,"checks failed: ",i0)') nfail

contains

   !> The Lame quarter cylinder scene text (see the program notes): FE order,
   !> material, dilatation choice, one level; `shift` moves the grid off the
   !> symmetry planes and `clamp` prescribes the exact displacement outside;
   !> `cut` > 0 intersects with x <= cut (exact traction there).
   function cylinder(order, young, poisson, dilatation, level, shift, clamp, cut) result(text)
      integer, intent(in) :: order, level
      real(wp), intent(in) :: young, poisson, shift, cut
      character(len=*), intent(in) :: dilatation
      logical, intent(in) :: clamp
      character(len=:), allocatable :: text
      character(len=64) :: b
      text = "&scene analysis='plane_strain' order="//itoa(order)//" levels="//itoa(level)// &
         & " box_min="//rtoa(-shift)//","//rtoa(-shift)//" box_size=25 recovery='sprc' dilatation='"// &
         & dilatation//"' /"//nl
      write (b, '(es24.16)') young
      text = text//"&body name='c' young="//trim(adjustl(b))//" poisson="//rtoa(poisson)//" /"//nl// &
         & "&shape body='c' op='add' kind='disk' name='outer' center=0,0 radius=20 /"//nl// &
         & "&shape body='c' op='subtract' kind='disk' name='inner' center=0,0 radius=5 /"//nl// &
         & "&shape body='c' op='intersect' kind='halfspace' name='sym_x' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='c' op='intersect' kind='halfspace' name='sym_y' point=0,0 normal=0,-1 /"//nl
      if (cut > 0.0_wp) text = text//"&shape body='c' op='intersect' kind='halfspace' name='cut' point="// &
         & rtoa(cut)//",0 normal=1,0 /"//nl//"&bc on='cut' type='exact_traction' /"//nl
      text = text//"&bc on='inner' type='pressure' value=1.0 /"//nl// &
         & "&bc on='sym_x' type='symmetry' /"//nl//"&bc on='sym_y' type='symmetry' /"//nl
      if (clamp) text = text//"&bc on='outer' type='exact_displacement' /"//nl
      text = text//"&exact kind='lame_cylinder' center=0,0 r_in=5 r_out=20 p_in=1.0 /"//nl
   end function cylinder

   !> The Lame sphere octant (example/scenes/lame_sphere.nml) at one level.
   function sphere(order, poisson, dilatation, level) result(text)
      integer, intent(in) :: order, level
      real(wp), intent(in) :: poisson
      character(len=*), intent(in) :: dilatation
      character(len=:), allocatable :: text
      text = "&scene analysis='solid' order="//itoa(order)//" levels="//itoa(level)// &
         & " box_min=0,0,0 box_size=25 recovery='sprc' dilatation='"//dilatation//"' /"//nl// &
         & "&body name='s' young=1000 poisson="//rtoa(poisson)//" /"//nl// &
         & "&shape body='s' op='add' kind='sphere' name='outer' center=0,0,0 radius=20 /"//nl// &
         & "&shape body='s' op='subtract' kind='sphere' name='inner' center=0,0,0 radius=10 /"//nl// &
         & "&shape body='s' op='intersect' kind='halfspace' name='sym_x' point=0,0,0 normal=-1,0,0 /"//nl// &
         & "&shape body='s' op='intersect' kind='halfspace' name='sym_y' point=0,0,0 normal=0,-1,0 /"//nl// &
         & "&shape body='s' op='intersect' kind='halfspace' name='sym_z' point=0,0,0 normal=0,0,-1 /"//nl// &
         & "&bc on='inner' type='pressure' value=1.0 /"//nl//"&bc on='sym_x' type='symmetry' /"//nl// &
         & "&bc on='sym_y' type='symmetry' /"//nl//"&bc on='sym_z' type='symmetry' /"//nl// &
         & "&exact kind='lame_sphere' center=0,0,0 r_in=10 r_out=20 p_in=1.0 /"//nl
   end function sphere

   !> Run the scene `text` at its one level (gamma: the Nitsche factor, 0 = default).
   function run(text, gamma) result(r)
      character(len=*), intent(in) :: text
      real(wp), intent(in) :: gamma
      type(result_type) :: r
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result
      type(report_row_type) :: row
      type(error_type), allocatable :: error

      call read_scene_text(text, 'stability_study', scene, error)
      if (.not. allocated(error)) call prepare_study(scene, 0, study, error)
      if (.not. allocated(error)) then
         if (gamma > 0.0_wp) study%gamma = gamma
         call run_level(study, scene%levels(1), result, error)
      end if
      if (allocated(error)) then
         write (output_unit, '("run failed: ",a)') error%message
         nfail = nfail + 1
         r%err_fe = huge(1.0_wp)
         return
      end if
      row = result%row
      r%rcond = result%bodies(1)%problem%rcond
      r%err_fe = row%err_fe
      r%err_sprc = row%err_sprc
      r%eta_sprc = row%eta_sprc
      r%theta = row%theta_sprc
   end function run

   subroutine print_row(label, r)
      character(len=*), intent(in) :: label
      type(result_type), intent(in) :: r
      character(len=12) :: theta
      if (abs(r%theta) < 100.0_wp) then
         write (theta, '(f6.3)') r%theta
      else
         write (theta, '(es9.2)') r%theta
      end if
      write (output_unit, '("| ",a," | ",es9.2," | ",es9.2," | ",es9.2," | ",a," | ",es8.1," |")') label, &
         & r%err_fe, r%err_sprc, r%eta_sprc, trim(adjustl(theta)), r%rcond
   end subroutine print_row

   subroutine header(title, first)
      character(len=*), intent(in) :: title, first
      write (output_unit, '(/,a,/)') title
      write (output_unit, '("| ",a," | err_fe | err_sprc | eta_sprc | theta_sprc | rcond |")') first
      write (output_unit, '("|---|---|---|---|---|---|")')
   end subroutine header

   subroutine expect(ok, what)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: what
      if (ok) return
      nfail = nfail + 1
      write (output_unit, '("CHECK FAILED: ",a)') what
   end subroutine expect

   !> 1. Poisson sweep: with 'projected', err_fe and err_sprc within 1.5x of
   !> nu = 0.3 (full) and theta_sprc in [0.9, 1.1].
   subroutine nu_sweep()
      real(wp), parameter :: nus(6) = [0.3_wp, 0.4_wp, 0.45_wp, 0.49_wp, 0.499_wp, 0.4999_wp]
      character(len=*), parameter :: forms(2) = [character(len=9) :: 'full', 'projected']
      type(result_type) :: r, ref
      integer :: p, k, f, level
      level = 6
      call header('Poisson sweep (Lame cylinder, plane strain)', 'order, level, nu, dilatation')
      do p = 1, 2
         do f = 1, 2
            do k = 1, size(nus)
               r = run(cylinder(p, 1000.0_wp, nus(k), trim(forms(f)), level, 0.0_wp, .false., 0.0_wp), 0.0_wp)
               if (k == 1 .and. f == 1) ref = r
               call print_row('Q'//itoa(p)//', '//itoa(level)//', '//rtoa(nus(k))//', '//trim(forms(f)), r)
               if (f == 2) then
                  call expect(r%err_fe <= 1.5_wp*ref%err_fe .and. r%err_sprc <= 1.5_wp*ref%err_sprc, &
                     & 'projected: errors within 1.5x of nu = 0.3')
                  call expect(r%theta >= 0.9_wp .and. r%theta <= 1.1_wp, 'projected: theta_sprc in [0.9, 1.1]')
               end if
            end do
         end do
      end do
   end subroutine nu_sweep

   !> 1b. Poisson 0.3 and 0.4999 in 3D: with 'projected', errors within 1.5x of
   !> nu = 0.3 (full) and theta_sprc within 10% of the projected one at nu =
   !> 0.3 (independent of nu; the levels are coarse).
   subroutine sphere_sweep()
      real(wp), parameter :: nus(2) = [0.3_wp, 0.4999_wp]
      character(len=*), parameter :: forms(2) = [character(len=9) :: 'full', 'projected']
      type(result_type) :: r, ref, ref_projected
      integer :: p, k, f, level
      call header('Poisson sweep in 3D (Lame sphere octant)', 'order, level, nu, dilatation')
      do p = 1, 2
         level = 6 - p
         do f = 1, 2
            do k = 1, size(nus)
               r = run(sphere(p, nus(k), trim(forms(f)), level), 0.0_wp)
               if (k == 1 .and. f == 1) ref = r
               if (k == 1 .and. f == 2) ref_projected = r
               call print_row('Q'//itoa(p)//', '//itoa(level)//', '//rtoa(nus(k))//', '//trim(forms(f)), r)
               if (f == 2) then
                  call expect(r%err_fe <= 1.5_wp*ref%err_fe .and. r%err_sprc <= 1.5_wp*ref%err_sprc, &
                     & 'projected (3D): errors within 1.5x of nu = 0.3')
                  call expect(abs(r%theta - ref_projected%theta) <= 0.1_wp*ref_projected%theta, &
                     & 'projected (3D): theta within 10% of nu = 0.3')
               end if
            end do
         end do
      end do
   end subroutine sphere_sweep

   !> 2. Young's modulus 1e-6 ... 1e12: the relative errors and theta agree
   !> with E = 1 to 1e-10 (relative), rcond too (it is scale free).
   subroutine young_sweep()
      type(result_type) :: r, ref
      integer :: k
      call header("Young's modulus (Q1, level 5, nu = 0.3)", 'E')
      ref = run(cylinder(1, 1.0_wp, 0.3_wp, 'auto', 5, 0.0_wp, .false., 0.0_wp), 0.0_wp)
      do k = -6, 12, 3
         r = run(cylinder(1, 10.0_wp**k, 0.3_wp, 'auto', 5, 0.0_wp, .false., 0.0_wp), 0.0_wp)
         call print_row('1e'//itoa(k), r)
         call expect(abs(r%err_fe - ref%err_fe) <= 1.0e-10_wp*ref%err_fe .and. &
            & abs(r%err_sprc - ref%err_sprc) <= 1.0e-10_wp*ref%err_sprc .and. &
            & abs(r%theta - ref%theta) <= 1.0e-10_wp*ref%theta, 'errors independent of E to 1e-10')
      end do
   end subroutine young_sweep

   !> 3. Nitsche gamma over six decades around the default 10 (p+1)^2, all
   !> conditions weak: inside the documented safe range (`gamma_range`) the
   !> errors move by less than the discretization error itself
   !> (|err - err(default)| < err(default), err_fe and err_sprc); outside,
   !> the row is marked (the driver warns, `gamma_note`).
   subroutine gamma_sweep()
      real(wp), parameter :: factors(9) = [1.0e-3_wp, 1.0e-2_wp, 1.0e-1_wp, 0.5_wp, 1.0_wp, 1.0e1_wp, 1.0e2_wp, &
         & 1.0e3_wp, 1.0e4_wp]
      type(result_type) :: r, ref
      real(wp) :: g0, g
      integer :: p, k
      character(len=32) :: b
      call header('Nitsche penalty (weak symmetry, exact displacement outside, nu = 0.3, level 5)', 'order, gamma')
      do p = 1, 2
         g0 = default_gamma(p)
         ref = run(cylinder(p, 1000.0_wp, 0.3_wp, 'auto', 5, 0.3_wp, .true., 0.0_wp), g0)
         do k = 1, size(factors)
            g = factors(k)*g0
            r = run(cylinder(p, 1000.0_wp, 0.3_wp, 'auto', 5, 0.3_wp, .true., 0.0_wp), g)
            write (b, '(es8.1)') g
            if (len(gamma_note(p, g)) > 0) b = trim(adjustl(b))//' (outside)'
            call print_row('Q'//itoa(p)//', '//trim(adjustl(b)), r)
            if (len(gamma_note(p, g)) == 0) call expect(abs(r%err_fe - ref%err_fe) < ref%err_fe .and. &
               & abs(r%err_sprc - ref%err_sprc) < ref%err_sprc, 'safe gamma: change below the error')
         end do
      end do
   end subroutine gamma_sweep

   !> 4. Tiny cut: err_fe within 1% and rcond within 10x of delta = 0 (no cut
   !> there), theta_sprc in [0.8, 1.5] (the level is coarse).
   subroutine cut_sweep()
      real(wp), parameter :: deltas(6) = [0.0_wp, 1.0e-1_wp, 1.0e-3_wp, 1.0e-6_wp, 1.0e-9_wp, 1.0e-12_wp]
      type(result_type) :: r, ref
      real(wp) :: h
      integer :: p, k
      character(len=32) :: b
      h = 25.0_wp/16.0_wp
      call header('Tiny cut x = 10 h + delta h (level 4, nu = 0.3)', 'order, delta')
      do p = 1, 2
         do k = 1, size(deltas)
            r = run(cylinder(p, 1000.0_wp, 0.3_wp, 'auto', 4, 0.0_wp, .false., 10.0_wp*h + deltas(k)*h), 0.0_wp)
            if (k == 1) ref = r
            write (b, '(es8.1)') deltas(k)
            call print_row('Q'//itoa(p)//', '//trim(adjustl(b)), r)
            call expect(abs(r%err_fe - ref%err_fe) <= 0.01_wp*ref%err_fe .and. r%rcond >= 0.1_wp*ref%rcond, &
               & 'tiny cut: err_fe within 1%, rcond within 10x')
            call expect(r%theta >= 0.8_wp .and. r%theta <= 1.5_wp, 'tiny cut: theta_sprc in [0.8, 1.5]')
         end do
      end do
   end subroutine cut_sweep

   function itoa(i) result(s)
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      character(len=16) :: b
      write (b, '(i0)') i
      s = trim(b)
   end function itoa

   !> Shortest decimal text of a real for the scene (up to 10 significant digits).
   function rtoa(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=32) :: b
      write (b, '(f20.10)') x
      s = trim(adjustl(b))
      do while (s(len(s):len(s)) == '0')
         s = s(1:len(s) - 1)
      end do
      if (s(len(s):len(s)) == '.') s = s//'0'
   end function rtoa

end program stability_study
