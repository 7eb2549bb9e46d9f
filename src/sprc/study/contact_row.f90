!> The contact columns of a level's report row (doc/scene.md "The report") from the
!> level's contact results, and the exact pressure of a contact result.
!>
!> Over the slave points i of every pair, with weights w_i (surface measure):
!> - contact_measure = sum of w_i over the closed points (state /= open);
!> - p_max_X = max_i p_X,i (X = fe, spr, sprc, exact, fe_stress);
!> - err_p_X = sqrt(sum w_i (p_X,i - p_ex,i)^2) / sqrt(sum w_i p_ex,i^2), the
!>   relative L2 error over the whole slave surface (the exact pressure is 0
!>   where the exact solution is open, as `exact_pressure_type` gives it).
!> A column is empty where it does not apply: p_max_X when p_X is empty at
!> some point (not computed), err_p_X also without an exact pressure or when
!> the exact pressure is zero everywhere (a relative error of nothing).
!> With `jump` (rows FE, SPR, SPR-C, a column per pair, negative where not
!> computed: `level_type%traction_jump`), jump_fe, jump_spr, jump_sprc are the
!> worst pair's, empty where no pair has one.
!> The row's iteration count and contact time are the contact solve's to set.
!>
!> After a level's contact solve and recoveries:
!> ```fortran
!> call fill_contact_exact(study%scene, result%contacts, error)   ! p_exact where &exact gives it
!> call fill_contact_row(result%contacts, result%row, error, result%traction_jump)
!> ```
module sprc_study_contact_row
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   use sprc_exact_pressure, only: exact_pressure_type
   use sprc_contact_result, only: contact_result_type, contact_open
   use sprc_study_row, only: report_row_type, report_empty, is_empty
   use sprc_study_spec, only: scene_type
   use sprc_study_model, only: build_exact_pressure
   implicit none
   private

   public :: fill_contact_row, fill_exact_pressure, fill_contact_exact

contains

   !> p_exact of every pair's result (`contacts(k)` is `&contact` pair k of
   !> `scene`, in scene units) from the scene's exact solution; left empty
   !> where there is none (no `&exact`, or no field in the slave body).
   subroutine fill_contact_exact(scene, contacts, error)
      type(scene_type), intent(in) :: scene
      type(contact_result_type), intent(inout) :: contacts(:)
      type(error_type), allocatable, intent(out) :: error
      class(exact_pressure_type), allocatable :: pressure
      integer :: k

      do k = 1, size(contacts)
         call build_exact_pressure(scene, k, pressure, error)
         if (allocated(error)) return
         if (allocated(pressure)) call fill_exact_pressure(pressure, contacts(k))
      end do
   end subroutine fill_contact_exact

   !> Set p_exact of `result` at every slave point from `pressure` (same units
   !> as the result: the scene's).
   subroutine fill_exact_pressure(pressure, result)
      class(exact_pressure_type), intent(in) :: pressure
      type(contact_result_type), intent(inout) :: result
      integer :: i

      do i = 1, result%npoint
         result%p_exact(i) = pressure%pressure(result%x(:, i), result%normal(:, i))
      end do
   end subroutine fill_exact_pressure

   !> The contact columns of `row` from the level's contact results; `has_contact` set.
   !> The slave points of all pairs are gathered in arrays allocated with stat=
   !> (sprc_core_alloc): an allocation that fails is `error`.
   subroutine fill_contact_row(contacts, row, error, jump)
      type(contact_result_type), intent(in) :: contacts(:)
      type(report_row_type), intent(inout) :: row
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: jump(:, :)
      real(wp), allocatable :: w(:), p_fe(:), p_spr(:), p_sprc(:), p_ex(:), p_fe_stress(:)
      logical, allocatable :: closed(:)
      integer :: k, n, m, stat

      n = sum(contacts%npoint)
      allocate (w(n), p_fe(n), p_spr(n), p_sprc(n), p_ex(n), p_fe_stress(n), closed(n), stat=stat)
      call check_allocation(stat, 'contact report row', 'the slave points of the pairs', n, 52, error)
      if (allocated(error)) return
      n = 0
      do k = 1, size(contacts)
         associate (c => contacts(k))
            m = c%npoint
            w(n + 1:n + m) = c%weight
            p_fe(n + 1:n + m) = c%p_fe
            p_spr(n + 1:n + m) = c%p_spr
            p_sprc(n + 1:n + m) = c%p_sprc
            p_ex(n + 1:n + m) = c%p_exact
            p_fe_stress(n + 1:n + m) = c%p_fe_stress
            closed(n + 1:n + m) = c%state /= contact_open
            n = n + m
         end associate
      end do
      row%has_contact = .true.
      row%contact_measure = sum(w, mask=closed)
      row%p_max_fe = maximum(p_fe)
      row%p_max_spr = maximum(p_spr)
      row%p_max_sprc = maximum(p_sprc)
      row%p_max_exact = maximum(p_ex)
      row%err_p_fe = relative_l2(p_fe, p_ex, w)
      row%err_p_spr = relative_l2(p_spr, p_ex, w)
      row%err_p_sprc = relative_l2(p_sprc, p_ex, w)
      row%p_max_fe_stress = maximum(p_fe_stress)
      row%err_p_fe_stress = relative_l2(p_fe_stress, p_ex, w)
      if (present(jump)) then
         row%jump_fe = worst(jump(1, :))
         row%jump_spr = worst(jump(2, :))
         row%jump_sprc = worst(jump(3, :))
      end if
   end subroutine fill_contact_row

   !> The largest non-negative value; empty if there is none.
   pure real(wp) function worst(x)
      real(wp), intent(in) :: x(:)
      worst = report_empty
      if (any(x >= 0.0_wp)) worst = maxval(x, mask=x >= 0.0_wp)
   end function worst

   !> Largest value; empty if there is none or any is empty.
   pure real(wp) function maximum(p)
      real(wp), intent(in) :: p(:)
      maximum = report_empty
      if (size(p) == 0) return
      if (any(is_empty(p))) return
      maximum = maxval(p)
   end function maximum

   !> ||p - p_ex|| / ||p_ex|| in the weighted L2 norm; empty if either has an
   !> empty value or ||p_ex|| = 0. Each norm's values are divided by their
   !> largest magnitude first, so squares neither overflow nor underflow
   !> whatever the units and however far p is from p_ex.
   pure real(wp) function relative_l2(p, p_ex, w)
      real(wp), intent(in) :: p(:), p_ex(:), w(:)
      real(wp) :: norm_ex, unit, unit_d

      relative_l2 = report_empty
      if (size(p) == 0) return
      if (any(is_empty(p)) .or. any(is_empty(p_ex))) return
      unit = maxval(abs(p_ex))
      if (.not. (unit > 0.0_wp)) return
      norm_ex = sqrt(sum(w*(p_ex/unit)**2))
      if (.not. (norm_ex > 0.0_wp)) return
      ! The difference in its own unit: p may be far larger than p_ex.
      unit_d = maxval(abs(p - p_ex))
      relative_l2 = 0.0_wp
      if (unit_d > 0.0_wp) relative_l2 = (unit_d/unit)*(sqrt(sum(w*((p - p_ex)/unit_d)**2))/norm_ex)
   end function relative_l2

end module sprc_study_contact_row
