!> One row of a study's report (doc/scene.md "The report"): what one level of the
!> study gives, summed over the bodies. `sprc_io_report` writes rows as a
!> table and CSV, `sprc_io_svg` plots them.
!>
!> A real cell that does not apply (no exact solution, recovery not run) is
!> *empty*: it holds a quiet NaN (`report_empty`, from `sprc_core_empty`,
!> re-exported here) and `is_empty` is true for it.
module sprc_study_row
   use sprc_core_kinds, only: wp, i8
   use sprc_core_empty, only: report_empty, is_empty
   implicit none
   private

   public :: report_row_type, report_empty, is_empty

   !> One level of a study. Times are wall-clock seconds for that level alone;
   !> errors and estimates are relative, in the energy norm (doc/scene.md).
   !> Real components start empty: set only those that apply.
   type :: report_row_type
      integer :: level = 0
      !> Element size of the level.
      real(wp) :: h = report_empty
      !> Active elements, of which cut by the boundary; degrees of freedom.
      integer(i8) :: elements = 0, cut_elements = 0, dofs = 0
      real(wp) :: t_mesh = report_empty, t_quadrature = report_empty, t_assembly = report_empty
      real(wp) :: t_solve = report_empty, t_recovery = report_empty, t_estimate = report_empty
      real(wp) :: t_total = report_empty
      !> Exact relative errors of the FE, SPR and SPR-C stresses.
      real(wp) :: err_fe = report_empty, err_spr = report_empty, err_sprc = report_empty
      !> Estimated relative errors (ZZ with the SPR / SPR-C field).
      real(wp) :: eta_spr = report_empty, eta_sprc = report_empty
      !> Global effectivity indices.
      real(wp) :: theta_spr = report_empty, theta_sprc = report_empty
      !> Contact columns (doc/scene.md; only scenes with `&contact`, `has_contact`):
      !> contact iterations summed over increments, contact time (search, gaps,
      !> contact terms), measure of the closed slave surface, maximum pressures and
      !> relative L2 pressure errors over the slave surface (fe the contact multiplier,
      !> fe_stress the slave's FE stresses -n.sigma_h.n); the relative jump of the normal
      !> traction between the two bodies with the FE stresses, SPR and SPR-C (worst pair).
      logical :: has_contact = .false.
      integer :: contact_iterations = 0
      real(wp) :: t_contact = report_empty, contact_measure = report_empty
      real(wp) :: p_max_fe = report_empty, p_max_spr = report_empty, p_max_sprc = report_empty
      real(wp) :: p_max_exact = report_empty
      real(wp) :: err_p_fe = report_empty, err_p_spr = report_empty, err_p_sprc = report_empty
      real(wp) :: p_max_fe_stress = report_empty, err_p_fe_stress = report_empty
      real(wp) :: jump_fe = report_empty, jump_spr = report_empty, jump_sprc = report_empty
      !> Krylov iterations of the level's solves (0 for a direct solve).
      integer :: solver_iterations = 0
      !> Adaptive studies (`&adapt`): the step (0 the start mesh; -1, empty, in a
      !> uniform study) and the seconds to build it from the previous step's
      !> estimate (size field and new grids; inside t_total, 0 at step 0).
      integer :: step = -1
      real(wp) :: t_adapt = report_empty
   end type report_row_type

end module sprc_study_row
