!> The contact-pressure table of SPR-C on contact surfaces (issue 12): for a scene with one
!> `&contact` pair and recovery = 'both', per level the energy errors (err_fe, err_spr,
!> err_sprc) and theta_sprc where the scene has an exact stress, the L2 errors of the
!> contact pressure over the slave surface (err_p_fe of the multiplier, err_p_spr and
!> err_p_sprc of the slave's recovered stress, SCENE.md's report columns) with their observed
!> rates in h, the peaks p_max_fe, p_max_sprc against p_max_exact, and the traction jump:
!> the relative L2 jump of the normal traction between the two bodies at the closed slave
!> points (`level_type%traction_jump`) with the FE stresses, SPR and SPR-C, and the ratios
!> FE/SPR-C and SPR/SPR-C (issue 12's traction-continuity item asks for 10 or more); last
!> err_p_fe_stress, the error of the slave's FE-stress pressure -n.sigma_h.n, and its ratio
!> to err_p_sprc; then the mean parts of the errors of the multiplier, the FE stresses and
!> SPR-C (`mean_error`: err_p^2 = mean^2 + the rest^2, so no pressure is closer than its
!> mean part; the multiplier's is the FE solution's interface force).
!> Run (levels as `sprc run --levels`):
!>   fpm run --profile release --example contact_study -- SCENE.nml 3,4,5,6,7
program contact_study
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_io_namelist, only: read_text_file
   use sprc_io_scene, only: scene_type, read_scene_text
   use sprc_study_level, only: study_type, level_type, prepare_study, run_level
   use sprc_study_row, only: is_empty
   use sprc_contact_result, only: contact_result_type
   implicit none
   character(len=1024) :: file, arg
   character(len=:), allocatable :: text
   type(error_type), allocatable :: error
   type(scene_type) :: scene
   type(study_type) :: study
   type(level_type) :: result
   integer, allocatable :: levels(:)
   real(wp) :: previous(4), now(4)
   integer :: i, ios

   if (command_argument_count() /= 2) call usage()
   call get_command_argument(1, file)
   call get_command_argument(2, arg)
   call parse_levels(trim(arg), levels, ios)
   if (ios /= 0) call usage()
   call read_text_file(trim(file), text, error)
   if (.not. allocated(error)) call read_scene_text(text, trim(file), scene, error)
   if (.not. allocated(error)) call prepare_study(scene, 0, study, error)
   if (allocated(error)) call fail(error)
   if (size(scene%contacts) /= 1 .or. .not. all(study%run)) then
      write (*, '(a)') 'contact_study: the scene needs one &contact pair and recovery = ''both'''
      stop 2
   end if
   write (*, '(a)') 'level  h        err_fe    err_spr   err_sprc  th_sprc  err_p_fe  rate  err_p_spr rate  '// &
      & 'err_p_sprc rate  p_max_fe   p_max_sprc p_max_ex   jump_fe   jump_spr  jump_sprc fe/sprc spr/sprc'// &
      & ' err_p_fest fest/sprc  mean_fe    mean_fest  mean_sprc'
   previous = -1.0_wp
   do i = 1, size(levels)
      call run_level(study, levels(i), result, error)
      if (allocated(error)) call fail(error)
      associate (r => result%row, j => result%traction_jump(:, 1))
         now = [r%h, r%err_p_fe, r%err_p_spr, r%err_p_sprc]
         write (*, '(i5,es9.2,3a10,a9,3(es10.3,a6),3es11.4,3es10.3,2f8.2,a11,f10.2,3es11.3)') levels(i), r%h, &
            & num(r%err_fe), num(r%err_spr), num(r%err_sprc), fixed(r%theta_sprc), now(2), rate(2), now(3), rate(3), &
            & now(4), rate(4), r%p_max_fe, r%p_max_sprc, r%p_max_exact, j, j(1)/j(3), j(2)/j(3), &
            & num(r%err_p_fe_stress), r%err_p_fe_stress/r%err_p_sprc, &
            & mean_error(result%contacts(1), result%contacts(1)%p_fe), &
            & mean_error(result%contacts(1), result%contacts(1)%p_fe_stress), &
            & mean_error(result%contacts(1), result%contacts(1)%p_sprc)
      end associate
      previous = now
   end do

contains

   !> Observed rate of column k in h against the previous level (blank at the first).
   function rate(k) result(s)
      integer, intent(in) :: k
      character(len=6) :: s
      s = ''
      if (previous(k) > 0.0_wp .and. now(k) > 0.0_wp) write (s, '(f6.2)') log(previous(k)/now(k))/log(previous(1)/now(1))
   end function rate

   !> The mean part of a pressure's relative L2 error over the slave points (the report's
   !> err_p_*): sum w (p - p_ex) / (sqrt(sum w) ||p_ex||), with ||.|| the weighted L2 norm.
   !> The error splits into this constant and a rest orthogonal to it, err_p^2 = mean^2 + rest^2.
   real(wp) function mean_error(c, p)
      type(contact_result_type), intent(in) :: c
      real(wp), intent(in) :: p(:)
      mean_error = sum(c%weight*(p - c%p_exact))/(sqrt(sum(c%weight))*sqrt(sum(c%weight*c%p_exact**2)))
   end function mean_error

   !> A value, or '-' where the report leaves it empty.
   function num(x) result(s)
      real(wp), intent(in) :: x
      character(len=10) :: s
      s = '         -'
      if (.not. is_empty(x)) write (s, '(es10.3)') x
   end function num

   !> A value with four decimals, or '-' where the report leaves it empty.
   function fixed(x) result(s)
      real(wp), intent(in) :: x
      character(len=9) :: s
      s = '        -'
      if (.not. is_empty(x)) write (s, '(f9.4)') x
   end function fixed

   !> The levels of a comma-separated list (ios /= 0 if it is not one of non-negative integers).
   subroutine parse_levels(list, out, ios)
      character(len=*), intent(in) :: list
      integer, allocatable, intent(out) :: out(:)
      integer, intent(out) :: ios
      integer :: n, k
      n = count([(list(k:k) == ',', k=1, len(list))]) + 1
      allocate (out(n))
      read (list, *, iostat=ios) out
      if (ios == 0 .and. any(out < 0)) ios = 1
   end subroutine parse_levels

   !> The command line is wrong: say how to call, exit 2.
   subroutine usage()
      write (*, '(a)') 'usage: contact_study SCENE.nml LEVELS   (LEVELS as 3,4,5)'
      stop 2
   end subroutine usage

   !> A level failed: its message, exit 1.
   subroutine fail(err)
      type(error_type), intent(in) :: err
      write (*, '(a)') 'contact_study: '//err%message
      stop 1
   end subroutine fail

end program contact_study
