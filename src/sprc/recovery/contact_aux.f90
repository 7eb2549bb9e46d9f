!> The auxiliary domain Omega_aux of a contact patch in the other body (thesis eq. 116,
!> Figures 28-31): geometry and the selection of the other body's sampling points.
!>
!> A contact patch of body (1) holds contact points x_i (the patch's part of the
!> contact surface, Gamma_C^p) with outward unit normals n_i and surface weights w_i.
!> - Mean normal (eq. 116): nbar = sum w_i n_i / |sum w_i n_i|. The thesis divides by the
!>   measure sum w_i, which leaves nbar shorter than unit on a curved surface; only its
!>   direction is used, so sprc normalises it. It points from body (1) into body (2).
!> - Frame: [nbar t1 (t2)] with the tangents of `plane_tangents(nbar)` (on a Cartesian
!>   grid and an axis-aligned nbar they are grid directions), origin the weighted centroid
!>   c = sum w_i x_i / sum w_i.
!> - Prism (Figure 30): Gamma_C^p projected along nbar. With quadrature points rather than
!>   the perimeter, its cross-section is the box of the projected points,
!>   tmin_k - margin <= (y - c).t_k <= tmax_k + margin. The points lie inside Gamma_C^p, so
!>   with margin = 0 the box is Gamma_C^p's projection less at most the distance from the
!>   outermost points to the perimeter (a fraction of a cell).
!> - Bounds along nbar (Figure 31): below, the plane through the lowest contact point,
!>   (y - c).nbar >= lo = min_i (x_i - c).nbar; above, the plane at depth `depth` beyond the
!>   highest one, (y - c).nbar <= hi = max_i (x_i - c).nbar + depth. Body (2)'s points inside
!>   the box all lie above lo whether the surface is convex or concave seen from body (1)
!>   (test: a disc and a ring), so lo cuts nothing of body (2) next to Gamma_C^p; it only
!>   stops the prism from reaching through body (1) to another part of body (2).
!> Small deformations: undeformed points and normals (the thesis projects the deformed
!> perimeter; the difference is of the order of the displacement gradient).
!>
!> Size (the thesis: too small an Omega_aux holds only boundary cells, whose FE stresses are
!> the poorest; too large a one over-smooths). The caller chooses `depth`. The grid recovery
!> takes 3 patch sizes in 2D and 2 in 3D (sprc_estimate_contact_patches, which gives the measurements:
!> depth h, 2h, 3h, 4h on the shrink fit and the Hertz cylinder; 2h, 3h on the compound and
!> Hertz spheres). A fit on Omega_aux that is rank deficient (too
!> few points of body (2), e.g. much coarser cells) is the caller's cue to double depth, like
!> the expansion of a rank-deficient patch (recover_contact_patch does).
module sprc_recovery_contact_aux
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_recovery_operators, only: plane_tangents
   use sprc_recovery_contact_operators, only: contact_normal_tol
   implicit none
   private

   public :: aux_domain_type, new_aux_domain, aux_contains, aux_select

   !> The prism Omega_aux (module notes).
   type :: aux_domain_type
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Frame: frame(:, 1) = nbar (into body (2)), frame(:, 2:dim) the tangents.
      real(wp) :: frame(3, 3) = 0.0_wp
      !> Origin: the weighted centroid of the contact points.
      real(wp) :: centre(3) = 0.0_wp
      !> Cross-section: tmin(k) <= (y - centre).frame(:, k + 1) <= tmax(k), k = 1..dim-1.
      real(wp) :: tmin(2) = 0.0_wp, tmax(2) = 0.0_wp
      !> Bounds along nbar: lo <= (y - centre).nbar <= hi.
      real(wp) :: lo = 0.0_wp, hi = 0.0_wp
      !> Measure of the patch's contact surface, sum w_i.
      real(wp) :: measure = 0.0_wp
   end type aux_domain_type

contains

   !> Build Omega_aux from a patch's contact points x(1:dim, i), unit outward normals
   !> n(1:dim, i) and weights w(i) >= 0 (module notes), with depth > 0 and margin >= 0.
   !> Errors (stat_invalid_input): no points or no positive weight, a non-unit normal,
   !> non-finite data, normals that cancel (|sum w n| <= sqrt(eps) sum w), bad depth/margin.
   pure subroutine new_aux_domain(aux, dim, x, n, w, depth, margin, error)
      type(aux_domain_type), intent(out) :: aux
      integer, intent(in) :: dim
      real(wp), intent(in) :: x(:, :), n(:, :), w(:), depth, margin
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: nsum(3), t(3, 2), y(3), a
      integer :: i, k, m

      call check_input(dim, x, n, w, depth, margin, error)
      if (allocated(error)) return
      m = size(w)
      aux%dim = dim
      aux%measure = sum(w)
      nsum = 0.0_wp
      do i = 1, m
         nsum(1:dim) = nsum(1:dim) + w(i)*n(1:dim, i)
         aux%centre(1:dim) = aux%centre(1:dim) + w(i)*x(1:dim, i)
      end do
      aux%centre(1:dim) = aux%centre(1:dim)/aux%measure
      if (.not. (sqrt(sum(nsum**2)) > sqrt(epsilon(1.0_wp))*aux%measure)) then
         call fatal_error(error, 'new_aux_domain: the contact normals cancel (no mean normal, eq. 116)', &
            & stat_invalid_input)
         return
      end if
      aux%frame(1:dim, 1) = nsum(1:dim)/sqrt(sum(nsum**2))
      call plane_tangents(dim, aux%frame(:, 1), t)
      aux%frame(:, 2:3) = t
      aux%tmin = huge(1.0_wp)
      aux%tmax = -huge(1.0_wp)
      aux%lo = huge(1.0_wp)
      aux%hi = -huge(1.0_wp)
      do i = 1, m
         y = 0.0_wp
         y(1:dim) = x(1:dim, i) - aux%centre(1:dim)
         do k = 1, dim - 1
            a = dot_product(y(1:dim), aux%frame(1:dim, k + 1))
            aux%tmin(k) = min(aux%tmin(k), a)
            aux%tmax(k) = max(aux%tmax(k), a)
         end do
         a = dot_product(y(1:dim), aux%frame(1:dim, 1))
         aux%lo = min(aux%lo, a)
         aux%hi = max(aux%hi, a)
      end do
      aux%tmin(1:dim - 1) = aux%tmin(1:dim - 1) - margin
      aux%tmax(1:dim - 1) = aux%tmax(1:dim - 1) + margin
      aux%hi = aux%hi + depth
   end subroutine new_aux_domain

   pure subroutine check_input(dim, x, n, w, depth, margin, error)
      integer, intent(in) :: dim
      real(wp), intent(in) :: x(:, :), n(:, :), w(:), depth, margin
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      character(len=120) :: buf

      buf = ''
      if (dim /= 2 .and. dim /= 3) then
         write (buf, '("dim = ",i0," is not 2 or 3")') dim
      else if (size(w) < 1) then
         buf = 'no contact points'
      else if (size(x, 1) < dim .or. size(n, 1) < dim .or. size(x, 2) < size(w) .or. size(n, 2) < size(w)) then
         write (buf, '("x and n must be (",i0,", ",i0,") at least")') dim, size(w)
      else if (.not. (depth > 0.0_wp .and. depth <= huge(1.0_wp))) then
         write (buf, '("depth = ",es12.4," must be finite and > 0")') depth
      else if (.not. (margin >= 0.0_wp .and. margin <= huge(1.0_wp))) then
         write (buf, '("margin = ",es12.4," must be finite and >= 0")') margin
      end if
      do i = 1, size(w)
         if (len_trim(buf) > 0) exit
         if (.not. (w(i) >= 0.0_wp .and. w(i) <= huge(1.0_wp))) then
            write (buf, '("w(",i0,") = ",es12.4," must be finite and >= 0")') i, w(i)
         else if (.not. all(abs(x(1:dim, i)) <= huge(1.0_wp))) then
            write (buf, '("x(:, ",i0,") is not finite")') i
         else if (.not. (abs(sqrt(sum(n(1:dim, i)**2)) - 1.0_wp) <= contact_normal_tol)) then
            write (buf, '("n(:, ",i0,") is not a unit normal")') i
         end if
      end do
      if (len_trim(buf) == 0 .and. size(w) > 0) then
         if (.not. (sum(w) > 0.0_wp)) buf = 'the contact weights sum to 0'
      end if
      if (len_trim(buf) > 0) call fatal_error(error, 'new_aux_domain: '//trim(buf), stat_invalid_input)
   end subroutine check_input

   !> True if y(1:dim) lies in Omega_aux (bounds included).
   pure logical function aux_contains(aux, y) result(inside)
      type(aux_domain_type), intent(in) :: aux
      real(wp), intent(in) :: y(:)
      real(wp) :: r(3), a
      integer :: k, d

      d = aux%dim
      r = 0.0_wp
      r(1:d) = y(1:d) - aux%centre(1:d)
      a = dot_product(r(1:d), aux%frame(1:d, 1))
      inside = a >= aux%lo .and. a <= aux%hi
      do k = 1, d - 1
         if (.not. inside) return
         a = dot_product(r(1:d), aux%frame(1:d, k + 1))
         inside = a >= aux%tmin(k) .and. a <= aux%tmax(k)
      end do
   end function aux_contains

   !> The sampling points y(1:dim, j) of body (2) inside Omega_aux: their indices in
   !> idx(1:count), ascending (idx needs size(y, 2) entries at most).
   pure subroutine aux_select(aux, y, idx, count)
      type(aux_domain_type), intent(in) :: aux
      real(wp), intent(in) :: y(:, :)
      integer, intent(out) :: idx(:), count
      integer :: j

      count = 0
      do j = 1, size(y, 2)
         if (aux_contains(aux, y(:, j))) then
            count = count + 1
            idx(count) = j
         end if
      end do
   end subroutine aux_select

end module sprc_recovery_contact_aux
