!> Zienkiewicz-Zhu error estimate of a recovered field on a grid (thesis eq. 1) and,
!> with an exact solution, the error norms of the report.
!>
!> With ||s||_E^2 = sum over the volume points of w |J| s^T D^-1 s (energy norm of a
!> stress field through the compliance), per element and globally:
!> - err  = ||sigma* - sigma_h||_E                   (the ZZ estimate, `zz_error_integral`)
!> - norm_h = ||sigma_h||_E,  eta = err / sqrt(norm_h^2 + err^2)   (estimated relative error)
!> and with an exact solution sigma_ex:
!> - norm_ex = ||sigma_ex||_E, err_star = ||sigma_ex - sigma*||_E (quality of the recovery),
!>   rel_err_star = err_star / norm_ex  (the report's err_spr / err_sprc),
!> - err_ex = ||sigma_ex - sigma_h||_E, theta = err / err_ex  (effectivity index),
!> - max_boundary_node_error: the largest |sigma*(x_J) - sigma_ex(x_J)| (Euclidean norm of
!>   the Voigt difference) over the boundary vertex nodes J, the vertices with a patch of
!>   elements that have boundary points, restricted to `node_inside` if given (without it,
!>   nodes just outside the body count too: there the exact solution is its formula's
!>   continuation and sigma* an extrapolation from the cut pieces, which for noisy data can
!>   be far off); and the same over the
!>   boundary points themselves (max_boundary_point_error), where the field is the
!>   method's interpolation in the point's element.
!> sigma* is the method's field (nodal for SPR, union for SPR-C) at the same points as
!> sigma_h (`sigma_star`, kept for output). Per-element sums run in point order and the
!> global sums in element order: the bits do not depend on the thread count.
module sprc_estimate_norms
   use sprc_core_kinds, only: wp, i8
   use sprc_core_alloc, only: check_allocation
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_timer, only: wall_time
   use sprc_exact_solution, only: exact_solution_type
   use sprc_recovery_estimate, only: zz_error_integral
   use sprc_estimate_recovered_field, only: recovered_field_type, field_eval_unchecked, interp_default
   use sprc_estimate_patches, only: recovery_input_type
   use sprc_grid_share, only: share_type, share_range
   implicit none
   private

   public :: zz_estimate_type, estimate_error

   !> Error estimate and error norms (module notes).
   type :: zz_estimate_type
      integer :: n_elements = 0
      !> Per element: ||sigma* - sigma_h||^2 and ||sigma_h||^2 (energy norm squares).
      real(wp), allocatable :: elem_err2(:), elem_norm_h2(:)
      !> sigma* at the input's volume points (nstress, npts). Shared among ranks
      !> (`share`): only at the points of this rank's elements, the others
      !> untouched (never resident: nothing reads them; the report needs only
      !> the element terms).
      real(wp), allocatable :: sigma_star(:, :)
      !> Global ZZ estimate, FE stress norm, estimated relative error.
      real(wp) :: err = 0.0_wp, norm_h = 0.0_wp, eta = 0.0_wp
      !> True if the exact-solution quantities below were computed.
      logical :: has_exact = .false.
      !> Per element: ||sigma_ex - sigma_h||^2, ||sigma_ex - sigma*||^2 and ||sigma_ex||^2.
      real(wp), allocatable :: elem_err_ex2(:), elem_err_star2(:), elem_norm_ex2(:)
      real(wp) :: norm_ex = 0.0_wp, err_star = 0.0_wp, rel_err_star = 0.0_wp, err_ex = 0.0_wp, theta = 0.0_wp
      real(wp) :: max_boundary_node_error = 0.0_wp, max_boundary_point_error = 0.0_wp
      integer :: n_boundary_nodes = 0
      !> Seconds: the field's build (field%t_field) plus this estimate.
      real(wp) :: t_estimate = 0.0_wp
   end type zz_estimate_type

contains

   !> ZZ estimate of `field` against the FE stresses of `input` (the same input the field was
   !> recovered from), and with `exact` the error norms. Errors: input and field disagree
   !> (stat_invalid_input), exact solution of another dimension.
   !> With `share` (a level shared out among ranks, `sprc_grid_share`) each rank
   !> computes the terms of its range of elements and the terms (and sigma*) are
   !> gathered before the sums: the same bits on every rank as in one process.
   subroutine estimate_error(input, field, est, error, exact, node_inside, share)
      type(recovery_input_type), intent(in) :: input
      type(recovered_field_type), intent(in) :: field
      type(zz_estimate_type), intent(out) :: est
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      !> Nodes inside or on the body (n_nodes), for max_boundary_node_error.
      logical, intent(in), optional :: node_inside(:)
      class(share_type), intent(in), optional :: share
      real(wp), allocatable :: sex(:, :), zero(:, :)
      real(wp) :: t0
      integer, allocatable :: first(:)
      integer :: ne, ns, np, e, a, b, maxpts, stat, lo, hi

      t0 = wall_time()
      call check_consistent(input, field, error, exact)
      if (allocated(error)) return
      if (present(node_inside)) then
         if (size(node_inside) /= field%n_nodes) then
            call fatal_error(error, 'estimate_error: node_inside must have n_nodes entries', stat_invalid_input)
            return
         end if
      end if
      ne = field%n_elements
      ns = field%nstress
      np = size(input%w)
      est%n_elements = ne
      est%has_exact = present(exact)
      allocate (est%elem_err2(ne), est%elem_norm_h2(ne), est%sigma_star(ns, np), stat=stat)
      call check_allocation(stat, 'estimate_error', 'the element terms and sigma* at the points', &
         & int(ne, i8) + int(ns, i8)*np, 8, error)
      maxpts = 0
      do e = 1, ne
         maxpts = max(maxpts, input%elem_ptr(e + 1) - input%elem_ptr(e))
      end do
      allocate (zero(ns, maxpts))
      zero = 0.0_wp
      if (est%has_exact .and. .not. allocated(error)) then
         allocate (est%elem_err_ex2(ne), est%elem_err_star2(ne), est%elem_norm_ex2(ne), sex(ns, np), stat=stat)
         call check_allocation(stat, 'estimate_error', 'the exact errors and stresses at the points', &
            & 3*int(ne, i8) + int(ns, i8)*np, 8, error)
      else
         allocate (sex(ns, 0))
      end if
      ! A rank that failed alone must not leave the others waiting in the gather.
      if (present(share)) call share%agree('estimate_error', error)
      if (allocated(error)) return

      call share_range(share, input%elem_ptr(2:) - input%elem_ptr(:ne) + 1, first, lo, hi)
      !$omp parallel do schedule(dynamic, 64) private(a, b)
      do e = lo, hi
         a = input%elem_ptr(e)
         b = input%elem_ptr(e + 1) - 1
         call element_terms(input, field, e, a, b, est, zero, sex, exact)
      end do
      !$omp end parallel do
      if (present(share)) then
         call gather_terms(share, first, est, error)
         if (allocated(error)) return
      end if

      est%err = sqrt(sum(est%elem_err2))
      est%norm_h = sqrt(sum(est%elem_norm_h2))
      est%eta = 0.0_wp
      if (est%norm_h**2 + est%err**2 > 0.0_wp) est%eta = est%err/sqrt(est%norm_h**2 + est%err**2)
      if (est%has_exact) then
         call exact_norms(input, field, est, exact, error, node_inside)
         if (allocated(error)) return
      end if
      est%t_estimate = field%t_field + (wall_time() - t0)
   end subroutine estimate_error

   !> The element terms of every rank's elements (`first`, as `split_by_work`)
   !> gathered in element order (not sigma*, which would make the whole
   !> level's resident on every rank).
   subroutine gather_terms(share, first, est, error)
      class(share_type), intent(in) :: share
      integer, intent(in) :: first(:)
      type(zz_estimate_type), intent(inout) :: est
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: cells(size(first))

      cells = int(first, i8)
      call share%gather_slices(cells, est%elem_err2, error)
      if (.not. allocated(error)) call share%gather_slices(cells, est%elem_norm_h2, error)
      if (allocated(error) .or. .not. est%has_exact) return
      call share%gather_slices(cells, est%elem_err_ex2, error)
      if (.not. allocated(error)) call share%gather_slices(cells, est%elem_err_star2, error)
      if (.not. allocated(error)) call share%gather_slices(cells, est%elem_norm_ex2, error)
   end subroutine gather_terms

   !> sigma* at the element's points and its energy-norm terms. Cannot fail: the input was
   !> validated and the weights are positive and finite.
   subroutine element_terms(input, field, e, a, b, est, zero, sex, exact)
      type(recovery_input_type), intent(in) :: input
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: e, a, b
      type(zz_estimate_type), intent(inout) :: est
      real(wp), intent(in) :: zero(:, :)
      real(wp), intent(inout) :: sex(:, :)
      class(exact_solution_type), intent(in), optional :: exact
      type(error_type), allocatable :: err
      integer :: k, m

      m = b - a + 1
      do k = a, b
         call field_eval_unchecked(field, e, input%x(:, k), interp_default, est%sigma_star(:, k))
      end do
      call zz_error_integral(input%analysis, input%young, input%poisson, input%w(a:b), est%sigma_star(:, a:b), &
         & input%stress(:, a:b), est%elem_err2(e), err)
      call zz_error_integral(input%analysis, input%young, input%poisson, input%w(a:b), input%stress(:, a:b), &
         & zero(:, 1:m), est%elem_norm_h2(e), err)
      if (.not. present(exact)) return
      do k = a, b
         call exact%stress(input%x(:, k), sex(:, k))
      end do
      call zz_error_integral(input%analysis, input%young, input%poisson, input%w(a:b), sex(:, a:b), &
         & input%stress(:, a:b), est%elem_err_ex2(e), err)
      call zz_error_integral(input%analysis, input%young, input%poisson, input%w(a:b), sex(:, a:b), &
         & est%sigma_star(:, a:b), est%elem_err_star2(e), err)
      call zz_error_integral(input%analysis, input%young, input%poisson, input%w(a:b), sex(:, a:b), &
         & zero(:, 1:m), est%elem_norm_ex2(e), err)
   end subroutine element_terms

   subroutine exact_norms(input, field, est, exact, error, node_inside)
      type(recovery_input_type), intent(in) :: input
      type(recovered_field_type), intent(in) :: field
      type(zz_estimate_type), intent(inout) :: est
      class(exact_solution_type), intent(in) :: exact
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: node_inside(:)
      logical, allocatable :: bnode(:)
      real(wp) :: s(6), sx(6)
      integer :: e, k, n, ns, stat

      ns = field%nstress
      ! the element terms (from the parallel loop) summed in element order
      est%norm_ex = 0.0_wp
      do e = 1, field%n_elements
         est%norm_ex = est%norm_ex + est%elem_norm_ex2(e)
      end do
      est%norm_ex = sqrt(est%norm_ex)
      est%err_ex = sqrt(sum(est%elem_err_ex2))
      est%err_star = sqrt(sum(est%elem_err_star2))
      est%rel_err_star = 0.0_wp
      if (est%norm_ex > 0.0_wp) est%rel_err_star = est%err_star/est%norm_ex
      est%theta = 0.0_wp
      if (est%err_ex > 0.0_wp) est%theta = est%err/est%err_ex

      ! Boundary vertex nodes and boundary points.
      allocate (bnode(field%n_nodes), stat=stat)
      call check_allocation(stat, 'estimate_error', 'the boundary node flags', field%n_nodes, 4, error)
      if (allocated(error)) return
      bnode = .false.
      est%max_boundary_point_error = 0.0_wp
      do e = 1, field%n_elements
         if (input%belem_ptr(e + 1) == input%belem_ptr(e)) cycle
         bnode(field%connectivity(1:field%nvertex, e)) = .true.
         do k = input%belem_ptr(e), input%belem_ptr(e + 1) - 1
            call field_eval_unchecked(field, e, input%bx(:, k), interp_default, s)
            call exact%stress(input%bx(:, k), sx(1:ns))
            est%max_boundary_point_error = max(est%max_boundary_point_error, norm2(s(1:ns) - sx(1:ns)))
         end do
      end do
      bnode = bnode .and. field%patch_of_node > 0
      if (present(node_inside)) bnode = bnode .and. node_inside
      est%n_boundary_nodes = count(bnode)
      est%max_boundary_node_error = 0.0_wp
      do n = 1, field%n_nodes
         if (.not. bnode(n)) cycle
         call exact%stress(field%node_x(:, n), sx(1:ns))
         est%max_boundary_node_error = max(est%max_boundary_node_error, norm2(field%nodal(:, n) - sx(1:ns)))
      end do
   end subroutine exact_norms

   subroutine check_consistent(input, field, error, exact)
      type(recovery_input_type), intent(in) :: input
      type(recovered_field_type), intent(in) :: field
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      character(len=120) :: buf

      if (.not. allocated(field%nodal)) then
         call fatal_error(error, 'estimate_error: the recovered field is not built', stat_invalid_input)
         return
      end if
      if (.not. (allocated(input%elem_ptr) .and. allocated(input%belem_ptr) .and. allocated(input%w) .and. &
         & allocated(input%x) .and. allocated(input%stress) .and. allocated(input%bx))) then
         call fatal_error(error, 'estimate_error: the input arrays are not allocated', stat_invalid_input)
         return
      end if
      if (size(input%elem_ptr) /= field%n_elements + 1 .or. size(input%belem_ptr) /= field%n_elements + 1 .or. &
         & size(input%stress, 1) /= field%nstress .or. size(input%x, 1) /= field%dim .or. &
         & size(input%w) /= input%elem_ptr(size(input%elem_ptr)) - 1 .or. &
         & size(input%stress, 2) /= size(input%w) .or. size(input%x, 2) /= size(input%w)) then
         write (buf, '("field of ",i0," elements, ",i0," stresses; input elem_ptr(",i0,"), stress(",i0,",",i0,")")') &
            & field%n_elements, field%nstress, size(input%elem_ptr), shape(input%stress)
         call fatal_error(error, 'estimate_error: input and field disagree: '//trim(buf), stat_invalid_input)
         return
      end if
      if (present(exact)) then
         if (exact%dim /= field%dim .or. exact%nstress /= field%nstress) then
            call fatal_error(error, 'estimate_error: the exact solution has another dimension than the field', &
               & stat_invalid_input)
         end if
      end if
   end subroutine check_consistent

end module sprc_estimate_norms
