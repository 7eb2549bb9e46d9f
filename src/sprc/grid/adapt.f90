!> Size field of an adaptive step: the level wanted for each element of a
!> mesh from its error indicator, as input to `grid_type%build_adapted`.
!> Pure maths over element arrays; the caller concatenates all bodies.
!>
!> `optimal_levels`: the criterion of the minimum number of elements for a
!> prescribed error (Ródenas, Fuenmayor, Tarancón and Nadal), derived in
!> doc/theory.md, section 10a: with ‖e‖_K² = `err_sq(K)` and the target
!> E_t² = η_t² `norm_sq`, the size ratio
!>
!>     r_K = ‖e‖_K^(-2/(2p+d)) · [E_t² / Σ_i ‖e‖_i^(2d/(2p+d))]^(1/(2p))
!>
!> equidistributes the error over the new elements. Evaluated in base-2
!> logarithms (no overflow for any finite input; a zero estimate gives
!> r_K = huge); the level change x_K = -log2 r_K counts as an integer within
!> sqrt(eps) of one. A coarsening is rounded up (never coarser than predicted);
!> a refinement to the nearer error, the finer level when the fraction of x_K
!> exceeds θ_p = -log2((1 + 2^(-2p))/2) / (2p), so the new errors sum to the
!> target to first order (rounding every refinement up overshoots the cells).
!> If no x_K exceeds θ_p while η > η_t, the refinements are rounded up, so a
!> step always refines something. The change is clamped to [-1, max_change]
!> (`default_max_change` = 2: where the local rate is below p a one-shot
!> prediction over-refines all of K; a few levels per step with a new estimate
!> grade the mesh instead), then into [0, max_level].
!>
!> `fraction_levels`: Dörfler bulk marking, for comparison: refine by one
!> level the smallest set of elements whose squared estimates sum to at least
!> `fraction` of the total (sorted descending, ties by index; O(n log n)).
module sprc_grid_adapt
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_core_text, only: itoa, rtoa
   use sprc_core_sort, only: sort_order
   use sprc_grid_tree, only: grid_max_level
   implicit none
   private

   public :: optimal_levels, optimal_ratio, fraction_levels, default_max_change

   !> Levels an element may refine by in one `optimal_levels` step unless told otherwise.
   integer, parameter :: default_max_change = 2

   !> Level changes within this of an integer count as that integer.
   real(wp), parameter :: change_tol = sqrt(epsilon(1.0_wp))

contains

   !> The level wanted for each element (`levels`, size n) from the optimal-mesh
   !> prediction (module notes): elements of level `leaf_level`, squared error
   !> estimates `err_sq`, target relative error `target` in (0, 1) against the
   !> squared norm `norm_sq`, degree `degree`, dimension `dim`. The change is at
   !> most `max_change` (>= 1, default `default_max_change`) levels finer and one
   !> coarser; the result lies in [0, max_level].
   subroutine optimal_levels(leaf_level, err_sq, norm_sq, target, degree, dim, max_level, levels, error, &
         & max_change)
      integer, intent(in) :: leaf_level(:)
      real(wp), intent(in) :: err_sq(:), norm_sq, target
      integer, intent(in) :: degree, dim, max_level
      integer, allocatable, intent(out) :: levels(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: max_change
      character(len=*), parameter :: who = 'optimal_levels: '
      real(wp), allocatable :: lr(:)
      integer :: up, k, change, stat
      real(wp) :: theta

      up = default_max_change
      if (present(max_change)) up = max_change
      call check_levels(who, leaf_level, err_sq, max_level, error)
      if (.not. allocated(error)) call check_optimal(who, norm_sq, target, degree, dim, error)
      if (allocated(error)) return
      if (up < 1) then
         call fatal_error(error, who//'max_change must be >= 1, got '//itoa(up), stat_invalid_input)
         return
      end if
      allocate (levels(size(err_sq)), lr(size(err_sq)), stat=stat)
      call check_allocation(stat, 'optimal_levels', 'the levels', size(err_sq), 12, error)
      if (allocated(error)) return
      call log2_ratio(err_sq, norm_sq, target, degree, dim, lr)
      theta = nearer_error_threshold(degree)
      if (.not. any(err_sq > 0.0_wp .and. -lr > theta)) theta = 0.0_wp
      do k = 1, size(err_sq)
         if (err_sq(k) > 0.0_wp) then
            change = max(-1, min(up, level_change(-lr(k), theta)))
         else
            change = -1
         end if
         levels(k) = max(0, min(max_level, leaf_level(k) + change))
      end do
   end subroutine optimal_levels

   !> θ_p of the module notes: a refinement rounds up when the fraction of its
   !> change exceeds it.
   pure real(wp) function nearer_error_threshold(degree) result(theta)
      integer, intent(in) :: degree
      theta = -log((1.0_wp + 2.0_wp**(-2*degree))/2.0_wp)/(2*degree*log(2.0_wp))
   end function nearer_error_threshold

   !> The integer level change for the wanted change `x`: a coarsening rounded
   !> up, a refinement rounded up when its fraction exceeds `theta` (0: always).
   pure integer function level_change(x, theta) result(change)
      real(wp), intent(in) :: x, theta
      if (x <= change_tol) then
         change = ceiling(x - change_tol)
      else
         change = floor(x + change_tol)
         if (x - change > max(theta, change_tol)) change = change + 1
      end if
   end function level_change

   !> The predicted size ratio r_K = h_new / h_K of each element (module notes;
   !> huge for an element whose estimate is zero), before rounding and clamping.
   subroutine optimal_ratio(err_sq, norm_sq, target, degree, dim, ratio, error)
      real(wp), intent(in) :: err_sq(:), norm_sq, target
      integer, intent(in) :: degree, dim
      real(wp), allocatable, intent(out) :: ratio(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: who = 'optimal_ratio: '
      integer :: stat

      call check_estimates(who, err_sq, error)
      if (.not. allocated(error)) call check_optimal(who, norm_sq, target, degree, dim, error)
      if (allocated(error)) return
      allocate (ratio(size(err_sq)), stat=stat)
      call check_allocation(stat, 'optimal_ratio', 'the ratios', size(err_sq), 8, error)
      if (allocated(error)) return
      call log2_ratio(err_sq, norm_sq, target, degree, dim, ratio)
      where (err_sq > 0.0_wp .and. ratio < real(maxexponent(1.0_wp) - 1, wp))
         ratio = 2.0_wp**ratio
      elsewhere
         ratio = huge(1.0_wp)
      end where
   end subroutine optimal_ratio

   !> log2 r_K for the elements with err_sq > 0 (others: undefined), scaled by
   !> the largest estimate so that no power under- or overflows.
   pure subroutine log2_ratio(err_sq, norm_sq, target, degree, dim, lr)
      real(wp), intent(in) :: err_sq(:), norm_sq, target
      integer, intent(in) :: degree, dim
      real(wp), intent(out) :: lr(:)
      real(wp) :: a, m, log2_s, log2_et2, q

      lr = 0.0_wp
      m = 0.0_wp
      if (size(err_sq) > 0) m = maxval(err_sq)
      if (m <= 0.0_wp) return
      q = real(2*degree + dim, wp)
      a = real(dim, wp)/q
      log2_s = a*lg(m) + lg(sum((err_sq/m)**a))
      log2_et2 = 2.0_wp*lg(target) + lg(norm_sq)
      where (err_sq > 0.0_wp)
         lr = -lg(err_sq)/q + (log2_et2 - log2_s)/real(2*degree, wp)
      end where
   end subroutine log2_ratio

   elemental real(wp) function lg(x)
      real(wp), intent(in) :: x
      lg = log(x)/log(2.0_wp)
   end function lg

   !> Dörfler marking (module notes): `levels` = leaf_level + 1 (at most max_level)
   !> on the smallest set of elements carrying `fraction` in (0, 1] of the sum of
   !> `err_sq`, leaf_level (at most max_level) elsewhere.
   subroutine fraction_levels(leaf_level, err_sq, fraction, max_level, levels, error)
      integer, intent(in) :: leaf_level(:)
      real(wp), intent(in) :: err_sq(:), fraction
      integer, intent(in) :: max_level
      integer, allocatable, intent(out) :: levels(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: who = 'fraction_levels: '
      integer, allocatable :: order(:), work(:)
      real(wp) :: total, partial
      integer :: n, k, stat

      call check_levels(who, leaf_level, err_sq, max_level, error)
      if (allocated(error)) return
      if (.not. (fraction > 0.0_wp .and. fraction <= 1.0_wp)) then
         call fatal_error(error, who//'fraction must be in (0, 1], got '//rtoa(fraction), stat_invalid_input)
         return
      end if
      n = size(err_sq)
      allocate (levels(n), order(n), work(n), stat=stat)
      call check_allocation(stat, 'fraction_levels', 'the levels and the sort order', n, 12, error)
      if (allocated(error)) return
      levels = min(leaf_level, max_level)
      call sort_order(-err_sq, order, work)
      ! The total summed in the same order as the partial sums: with fraction = 1 the
      ! marking stops at the last nonzero estimate, whatever the rounding.
      total = 0.0_wp
      do k = 1, n
         total = total + err_sq(order(k))
      end do
      partial = 0.0_wp
      do k = 1, n
         if (partial >= fraction*total) exit
         partial = partial + err_sq(order(k))
         levels(order(k)) = min(leaf_level(order(k)) + 1, max_level)
      end do
   end subroutine fraction_levels

   subroutine check_levels(who, leaf_level, err_sq, max_level, error)
      character(len=*), intent(in) :: who
      integer, intent(in) :: leaf_level(:)
      real(wp), intent(in) :: err_sq(:)
      integer, intent(in) :: max_level
      type(error_type), allocatable, intent(out) :: error
      integer :: k

      if (size(leaf_level) /= size(err_sq)) then
         call fatal_error(error, who//'leaf_level has '//itoa(size(leaf_level))//' entries, err_sq '// &
            & itoa(size(err_sq)), stat_invalid_input)
      else if (max_level < 0 .or. max_level > grid_max_level) then
         call fatal_error(error, who//'max_level must be in [0, '//itoa(grid_max_level)//'], got '// &
            & itoa(max_level), stat_invalid_input)
      else if (any(leaf_level < 0 .or. leaf_level > grid_max_level)) then
         k = findloc(leaf_level < 0 .or. leaf_level > grid_max_level, .true., 1)
         call fatal_error(error, who//'leaf_level('//itoa(k)//') = '//itoa(leaf_level(k))//' is not in [0, '// &
            & itoa(grid_max_level)//']', stat_invalid_input)
      else
         call check_estimates(who, err_sq, error)
      end if
   end subroutine check_levels

   subroutine check_estimates(who, err_sq, error)
      character(len=*), intent(in) :: who
      real(wp), intent(in) :: err_sq(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      do k = 1, size(err_sq)
         if (ieee_is_nan(err_sq(k)) .or. .not. (err_sq(k) >= 0.0_wp .and. err_sq(k) <= huge(1.0_wp))) then
            call fatal_error(error, who//'err_sq('//itoa(k)//') = '//rtoa(err_sq(k))// &
               & ' is not a finite non-negative number', stat_invalid_input)
            return
         end if
      end do
   end subroutine check_estimates

   subroutine check_optimal(who, norm_sq, target, degree, dim, error)
      character(len=*), intent(in) :: who
      real(wp), intent(in) :: norm_sq, target
      integer, intent(in) :: degree, dim
      type(error_type), allocatable, intent(out) :: error

      if (.not. (norm_sq > 0.0_wp .and. norm_sq <= huge(1.0_wp))) then
         call fatal_error(error, who//'norm_sq must be positive and finite, got '//rtoa(norm_sq), stat_invalid_input)
      else if (.not. (target > 0.0_wp .and. target < 1.0_wp)) then
         call fatal_error(error, who//'target must be in (0, 1), got '//rtoa(target), stat_invalid_input)
      else if (degree < 1) then
         call fatal_error(error, who//'degree must be >= 1, got '//itoa(degree), stat_invalid_input)
      else if (dim /= 2 .and. dim /= 3) then
         call fatal_error(error, who//'dim must be 2 or 3, got '//itoa(dim), stat_invalid_input)
      end if
   end subroutine check_optimal

end module sprc_grid_adapt
