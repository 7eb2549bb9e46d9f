!> Tests of the study layer (one level of a study over all bodies).
!>
!> Milestone of several bodies: bodies without contact are independent
!> problems, so a scene with two bodies far apart must reproduce, body by
!> body and bit for bit, the runs of scenes holding each body alone; the
!> report row's norms are those of the two bodies summed (SCENE.md: squares
!> added, then the ratio), recomputed here from the single-body results.
module sprc_test_study
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, stat_singular
   use sprc_study_spec, only: scene_type
   use sprc_io_scene, only: read_scene_text
   use sprc_study_level, only: study_type, prepare_study, run_level, level_type, body_level_type
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, replaced
   use sprc_core_blas_threads, only: blas_reserved_threads
   use sprc_core_text, only: itoa
   !$ use omp_lib, only: omp_get_max_threads
   implicit none
   private

   public :: collect_study, two_body_scene, run_text

   character(len=*), parameter :: nl = new_line('a')

contains

   subroutine collect_study(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('two_bodies_far_apart', test_two_bodies), &
         new_unittest('body_own_box', test_body_box), &
         new_unittest('contact_lost_names_body', test_contact_lost), &
         new_unittest('body_error_names_body', test_body_error), &
         new_unittest('prepare_takes_blas_buffers', test_prepare_blas) &
         ]
   end subroutine collect_study

   !> A scene of the Lame quarter cylinder ('cylinder', pressure inside,
   !> symmetry planes) and/or a disk ('rim', another material) at (22.5, 22.5),
   !> clear of the cylinder, held by the exact displacement on its rim; both
   !> on the same level-0 cell, with the Lame exact solution.
   function two_body_scene(cylinder, rim, levels) result(text)
      logical, intent(in) :: cylinder, rim
      character(len=*), intent(in) :: levels
      character(len=:), allocatable :: text
      text = "&scene title='two bodies' analysis='plane_strain' order=1 levels="//levels// &
         & " box_min=0,0 box_size=25 recovery='both' output='' /"//nl
      if (cylinder) text = text// &
         & "&body name='cylinder' young=1000 poisson=0.3 /"//nl// &
         & "&shape body='cylinder' op='add' kind='disk' name='outer' center=0,0 radius=20 /"//nl// &
         & "&shape body='cylinder' op='subtract' kind='disk' name='inner' center=0,0 radius=5 /"//nl// &
         & "&shape body='cylinder' op='intersect' kind='halfspace' name='sym_x' point=0,0 normal=-1,0 /"//nl// &
         & "&shape body='cylinder' op='intersect' kind='halfspace' name='sym_y' point=0,0 normal=0,-1 /"//nl
      if (rim) text = text// &
         & "&body name='block' young=2000 poisson=0.25 /"//nl// &
         & "&shape body='block' op='add' kind='disk' name='rim' center=22.5,22.5 radius=1.7 /"//nl// &
         & "&bc on='rim' type='exact_displacement' /"//nl
      if (cylinder) text = text// &
         & "&bc on='inner' type='pressure' value=1.0 /"//nl// &
         & "&bc on='sym_x' type='symmetry' /"//nl// &
         & "&bc on='sym_y' type='symmetry' /"//nl
      text = text//"&exact kind='lame_cylinder' center=0,0 r_in=5 r_out=20 p_in=1.0 /"//nl
   end function two_body_scene

   !> prepare_study takes OpenBLAS's buffer of every thread (blas_reserve_buffers),
   !> so that a library user who calls prepare_study and run_level gets an
   !> error, not OpenBLAS's endless retry, when the buffers do not fit.
   !> (Run alone: `fpm test unit -- study prepare_takes_blas_buffers`; nothing
   !> else in this process has reserved them before.)
   subroutine test_prepare_blas(error)
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(study_type) :: study
      integer :: threads
      threads = 1
      !$ threads = omp_get_max_threads()
      call read_scene_text(two_body_scene(.true., .false., '1'), 'one body', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      call check(error, blas_reserved_threads() >= threads, &
         & 'buffers of '//itoa(threads)//' threads reserved: '//itoa(blas_reserved_threads()))
   end subroutine test_prepare_blas

   !> Read a scene from `text`, prepare the study (a copy in `study` if
   !> present) and run one level.
   subroutine run_text(text, level, result, error, study)
      character(len=*), intent(in) :: text
      integer, intent(in) :: level
      type(level_type), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      type(study_type), intent(out), optional :: study
      type(scene_type) :: scene
      type(study_type) :: prepared
      call read_scene_text(text, 'two_bodies', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, prepared, error)
      if (allocated(error)) return
      call run_level(prepared, level, result, error)
      if (present(study)) study = prepared
   end subroutine run_text

   !> The milestone (module notes), at levels 3 and 4. The two bodies are
   !> given in the file in the other order than their &bc groups, so body-local
   !> shape indices and per-body materials are exercised too.
   subroutine test_two_bodies(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: both, one(2)
      integer :: level, b

      do level = 3, 4
         call run_text(two_body_scene(.true., .true., '3'), level, both, error)
         if (allocated(error)) return
         call run_text(two_body_scene(.true., .false., '3'), level, one(1), error)
         if (allocated(error)) return
         call run_text(two_body_scene(.false., .true., '3'), level, one(2), error)
         if (allocated(error)) return
         call check(error, size(both%bodies), 2, 'two bodies')
         if (allocated(error)) return
         do b = 1, 2
            call same_body(both%bodies(b), one(b)%bodies(1), error)
            if (allocated(error)) then
               error%message = 'level '//achar(48 + level)//', body '//achar(48 + b)//': '//error%message
               return
            end if
         end do
         call check_sums(both, one, error)
         if (allocated(error)) return
      end do
   end subroutine test_two_bodies

   !> Every result of a body bit for bit: mesh, solution, FE error, recovered
   !> fields and estimates.
   subroutine same_body(x, y, error)
      type(body_level_type), intent(in) :: x, y
      type(error_type), allocatable, intent(out) :: error
      integer :: m

      call check(error, x%problem%mesh%grid%n_leaves == y%problem%mesh%grid%n_leaves .and. &
         & x%problem%n_dofs() == y%problem%n_dofs(), 'same cells and dofs')
      if (allocated(error)) return
      call check(error, all(x%problem%mesh%nodes%x == y%problem%mesh%nodes%x) .and. all(x%problem%u == y%problem%u), &
         & 'same nodes and displacements')
      if (allocated(error)) return
      call check(error, x%err_norm == y%err_norm .and. x%norm_exact == y%norm_exact .and. &
         & all(x%element_error == y%element_error), 'same FE error')
      if (allocated(error)) return
      do m = 1, 2
         call check(error, all(x%field(m)%nodal == y%field(m)%nodal) .and. &
            & all(x%est(m)%elem_err2 == y%est(m)%elem_err2) .and. x%est(m)%err == y%est(m)%err .and. &
            & x%est(m)%err_star == y%est(m)%err_star, 'same recovered field and estimate, method '//achar(48 + m))
         if (allocated(error)) return
      end do
   end subroutine same_body

   !> The two-body row from the single-body norms (squares added, then the ratio).
   subroutine check_sums(both, one, error)
      type(level_type), intent(in) :: both, one(2)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: e(2), n(2), c(2), err, nh

      call check(error, both%row%elements, one(1)%row%elements + one(2)%row%elements, 'elements add up')
      if (allocated(error)) return
      call check(error, both%row%dofs, one(1)%row%dofs + one(2)%row%dofs, 'dofs add up')
      if (allocated(error)) return
      call check(error, both%row%cut_elements, one(1)%row%cut_elements + one(2)%row%cut_elements, &
         & 'cut elements add up')
      if (allocated(error)) return
      ! Each body's squared norms are taken to the first body's units (a power of two).
      c = [both%bodies(1)%norm2_scale, both%bodies(2)%norm2_scale]
      call check(error, c(1) == 1.0_wp .and. fraction(c(2)) == 0.5_wp, 'unit factors: 1 and a power of two')
      if (allocated(error)) return
      e = [one(1)%bodies(1)%err_norm, one(2)%bodies(1)%err_norm]
      n = [one(1)%bodies(1)%norm_exact, one(2)%bodies(1)%norm_exact]
      call check(error, both%row%err_fe == sqrt(c(1)*e(1)**2 + c(2)*e(2)**2)/sqrt(c(1)*n(1)**2 + c(2)*n(2)**2), &
         & 'err_fe summed')
      if (allocated(error)) return
      ! A body's own relative error differs from the sum (the test is not vacuous).
      call check(error, both%row%err_fe /= one(1)%row%err_fe .and. both%row%err_fe /= one(2)%row%err_fe, &
         & 'err_fe of the two bodies differs from each body''s')
      if (allocated(error)) return
      err = sqrt(c(1)*one(1)%bodies(1)%est(2)%err**2 + c(2)*one(2)%bodies(1)%est(2)%err**2)
      nh = sqrt(c(1)*one(1)%bodies(1)%est(2)%norm_h**2 + c(2)*one(2)%bodies(1)%est(2)%norm_h**2)
      call check(error, both%row%eta_sprc == err/sqrt(nh**2 + err**2), 'eta_sprc summed')
      if (allocated(error)) return
      e = [one(1)%bodies(1)%est(2)%err_star, one(2)%bodies(1)%est(2)%err_star]
      n = [one(1)%bodies(1)%est(2)%norm_ex, one(2)%bodies(1)%est(2)%norm_ex]
      call check(error, both%row%err_sprc == sqrt(c(1)*e(1)**2 + c(2)*e(2)**2)/sqrt(c(1)*n(1)**2 + c(2)*n(2)**2), &
         & 'err_sprc summed')
      if (allocated(error)) return
      e = [one(1)%bodies(1)%est(1)%err_ex, one(2)%bodies(1)%est(1)%err_ex]
      call check(error, both%row%theta_spr == sqrt(c(1)*one(1)%bodies(1)%est(1)%err**2 + &
         & c(2)*one(2)%bodies(1)%est(1)%err**2)/sqrt(c(1)*e(1)**2 + c(2)*e(2)**2), 'theta_spr summed')
   end subroutine check_sums

   !> A body on its own level-0 cell (&body box_min, box_size): bit for bit the
   !> single-body run whose &scene box is that cell, next to a body on the
   !> scene's cell; and not the run on the scene's cell (the box is used).
   subroutine test_body_box(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: scene_box = ' box_min=0,0 box_size=25 ', own_box = ' box_min=20,20 box_size=5 '
      character(len=*), parameter :: block = "&body name='block' young=2000 poisson=0.25"
      type(level_type) :: both, one(2), scene_cell

      call run_text(replaced(two_body_scene(.true., .true., '3'), block, block//own_box), 3, both, error)
      if (allocated(error)) return
      call run_text(two_body_scene(.true., .false., '3'), 3, one(1), error)
      if (allocated(error)) return
      call run_text(replaced(two_body_scene(.false., .true., '3'), scene_box, own_box), 3, one(2), error)
      if (allocated(error)) return
      call run_text(two_body_scene(.false., .true., '3'), 3, scene_cell, error)
      if (allocated(error)) return
      call same_body(both%bodies(1), one(1)%bodies(1), error)
      if (allocated(error)) return
      call same_body(both%bodies(2), one(2)%bodies(1), error)
      if (allocated(error)) return
      call check(error, both%bodies(2)%problem%n_dofs() /= scene_cell%bodies(1)%problem%n_dofs(), &
         & 'the block on its own cell is meshed differently from the block on the scene cell')
      if (allocated(error)) return
      call check(error, both%row%h, 25.0_wp/8, 0.0_wp, 'h: the coarsest body cell at level 3')
   end subroutine test_body_box

   !> A body held only by a contact that never closes (the disk far from the
   !> cylinder) is an error naming that body, not a singular-matrix message.
   subroutine test_contact_lost(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      type(error_type), allocatable :: failed
      character(len=:), allocatable :: text

      text = two_body_scene(.true., .true., '3')
      ! A contact surface takes no &bc: the rim is held by the contact alone.
      text = replaced(text, "&bc on='rim' type='exact_displacement' /"//nl, '')
      text = text//"&contact slave='block' master='cylinder' slave_surface='rim' master_surface='outer' "// &
         & "friction='frictionless' /"//nl
      call run_text(text, 3, result, failed)
      if (.not. allocated(failed)) then
         call test_failed(error, 'a body held by nothing was solved')
         return
      end if
      call check(error, failed%stat, stat_singular, 'status singular')
      if (allocated(error)) return
      call check(error, index(failed%message, "body 'block' is not held: translation x, translation y, "// &
         & 'rotation about z free') > 0 .and. index(failed%message, "body 'cylinder'") == 0, &
         & 'message: '//failed%message)
   end subroutine test_contact_lost

   !> With several bodies a failure names the body: here the block without
   !> its &bc is free to move rigidly.
   subroutine test_body_error(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      type(error_type), allocatable :: failed
      character(len=:), allocatable :: text
      integer :: k

      text = two_body_scene(.true., .true., '3')
      k = index(text, "&bc on='rim'")
      text = text(:k - 1)//text(k + index(text(k:), nl):)
      call run_text(text, 3, result, failed)
      if (.not. allocated(failed)) then
         call test_failed(error, 'a body free to move was solved')
         return
      end if
      call check(error, index(failed%message, 'body ''block'': ') == 1 .and. &
         & index(failed%message, 'rigid-body motion') > 0, 'message: '//failed%message)
   end subroutine test_body_error

end module sprc_test_study
