!> Tests of the contact FE (sprc_contact_solve through the study layer).
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
   use sprc_core_error, only: error_type, stat_singular
   use sprc_io_namelist, only: read_text_file
   use sprc_study_level, only: study_type, level_type
   use sprc_test_study, only: run_text
   use sprc_contact_result, only: contact_open
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, replaced
   implicit none
   private

   public :: collect_contact_fe

   character(len=*), parameter :: patch_2d = 'test/data/contact/patch_2d.nml'
   character(len=*), parameter :: patch_3d = 'test/data/contact/patch_3d.nml'

contains

   subroutine collect_contact_fe(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('patch_2d_q1', test_patch_2d_q1), &
         new_unittest('patch_2d_q2', test_patch_2d_q2), &
         new_unittest('patch_2d_stick_same_material', test_patch_2d_stick), &
         new_unittest('patch_3d_q1', test_patch_3d_q1), &
         new_unittest('patch_3d_q2', test_patch_3d_q2), &
         new_unittest('lost_contact_names_body', test_lost_contact) &
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
   !> the interface (2D sigma_yy, 3D sigma_zz; `ns` Voigt components).
   subroutine patch_case(path, order, level, old, new, ns, error, stick)
      character(len=*), intent(in) :: path, old, new
      integer, intent(in) :: order, level, ns
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: stick
      type(level_type) :: result
      type(study_type) :: study
      character(len=:), allocatable :: text
      real(wp) :: expected(6), worst, tol, unit, sigma(6), pworst
      integer :: b, e, q

      call read_text_file(path, text, error)
      if (allocated(error)) return
      text = replaced(text, 'order    = 1', 'order    = '//achar(48 + order))
      if (len(old) > 0) text = replaced(text, old, new)
      if (present(stick)) text = replaced(text, "friction='frictionless'", "friction='stick'")
      call run_text(text, level, result, error, study)
      if (allocated(error)) return
      expected = 0.0_wp
      expected(merge(2, 3, ns == 3)) = -1.0_wp
      worst = 0.0_wp
      tol = 0.0_wp
      do b = 1, size(result%bodies)
         associate (p => result%bodies(b)%problem)
            ! stresses in the body's units: sigma_scene = sigma*unit
            unit = study%bodies(b)%units%modulus*study%bodies(b)%units%strain
            tol = max(tol, 10.0_wp*epsilon(1.0_wp)/p%rcond)
            do e = 1, p%grid%n_leaves
               do q = p%vol_ptr(e), p%vol_ptr(e + 1) - 1
                  call p%stress_in_element(e, p%vol_x(:, q), sigma(1:ns))
                  worst = max(worst, maxval(abs(sigma(1:ns)*unit - expected(1:ns))))
               end do
            end do
         end associate
      end do
      call check(error, worst <= tol, 'uniform stress: max error '//real_text(worst)//' > '//real_text(tol))
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call check(error, all(c%state /= contact_open), 'every slave point is closed')
         if (allocated(error)) return
         pworst = maxval(abs(c%p_fe - 1.0_wp))
         call check(error, pworst <= tol, 'contact pressure: max error '//real_text(pworst)//' > '//real_text(tol))
      end associate
   end subroutine patch_case

   subroutine test_patch_3d_q1(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_3d, 1, 2, '', '', 6, error)
   end subroutine test_patch_3d_q1

   subroutine test_patch_3d_q2(error)
      type(error_type), allocatable, intent(out) :: error
      call patch_case(patch_3d, 2, 1, '', '', 6, error)
   end subroutine test_patch_3d_q2

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

   function real_text(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(es12.4)') x
      s = trim(adjustl(buf))
   end function real_text

end module sprc_test_contact_fe
