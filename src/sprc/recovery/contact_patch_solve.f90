!> The coupled SPR-C solve of a contact patch (thesis eqs. 129-138): body (1)'s patch and
!> the fit of body (2)'s stresses on Omega_aux (sprc_recovery_contact_aux) recovered
!> together, coupled by the contact law on the patch's contact points.
!>
!> Each body keeps its own SPR-C problem (sprc_constraints of sprc_recovery_patch_solve: weighted
!> least squares of its sampling points, its equilibrium, compatibility and boundary rows
!> C_b A_b = Lambda_b). The contact adds, in least-squares form (eqs. 129-133), the rows
!> of Z(x_j) = [H(x_j) P(s1(x_j)), -H'_t(x_j) P(s2(x_j))] (sprc_recovery_contact_operators)
!> at the contact points x_j of patch (1) with the weights sqrt(w_j / sum w): the stacked
!> rows E (dim rows per point) are factored by QR with column pivoting, E Pi = Q R, and
!> Z^T Z A' = 0 becomes R Pi^T A' = 0, its leading rows with |R_kk| > traction_rank_tol
!> |R_11| kept, at most the rank of the rows on a flat surface (`flat_traction_rank`: each
!> of the dim residual components is a degree-p polynomial along it), degree p - 1 on a
!> curved one - as the traction rows (sprc_recovery_patch_solve, (c)). The two systems and the
!> contact rows form the one system of eq. 138 (with the erratum: the contact rows have
!> two different column blocks). All rows are stacked, normalised and rank-selected once
!> more (recovery_rank_tol), and the constrained minimum is computed as in sprc_recovery_patch_solve
!> by orthogonal transformations (no KKT matrix): with z_b = (I x R_b Pi_b^T) A_b the
!> objective is |z1 - g1|^2 + |z2 - g2|^2 and the constraints W z = Lambda with
!> W = C blockdiag(I x Pi_b R_b^-1); the pivoted QR of W^T gives the projection of g.
!> Each body's weights are normalised by their own sum, so the two fits weigh alike unless the
!> caller weighs body (2)'s objective by `weight2` against body (1)'s (the grid recovery:
!> (h1/h2)^(2p) of the bodies' cell sizes, sprc_estimate_contact_patches). Fields of the
!> recovery space are recovered exactly with any weight.
!>
!> Contact points are the boundary points of patch (1) of kind boundary_contact, with the
!> law, mu and slip direction given per boundary point (sprc_recovery_contact_operators:
!> s is the slip of body (1) relative to body (2)). A patch (1) with contact points imposes
!> contact and no other boundary rows (the thesis, "contact always wins"). Patch (2) is an
!> ordinary patch (no contact points), e.g. body (2)'s sampling points in Omega_aux with its
!> other boundaries' traction points there.
!>
!> Rank decisions are reported as recover_sprc's (rec%max_dropped_ratio, tolerance_bites):
!> the contact rows' in rec1, the stacked selection's in both.
!>
!> Storage: the coupled rows are allocated per call (a contact patch is one of few).
module sprc_recovery_contact_patch_solve
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular
   use sprc_core_text, only: itoa
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, boundary_contact, patch_reset, patch_reserve
   use sprc_recovery_contact_aux, only: aux_domain_type, new_aux_domain, aux_contains
   use sprc_recovery_workspace, only: recovery_workspace_type
   use sprc_recovery_patch_solve, only: sprc_constraints, note_dropped, recovery_rank_tol, recovery_bite_ratio, traction_rank_tol, &
      & flat_traction_rank
   use sprc_core_dense, only: qr_pivoted, apply_qt, apply_q, solve_upper
   use sprc_recovery_contact_operators, only: contact_frame, contact_operator, contact_law_operator, contact_rows, &
      & contact_law_slip, contact_law_name
   implicit none
   private

   public :: recover_sprc_contact, recover_contact_patch, contact_curved_tol, aux_max_doublings, contact_points
   public :: aux_margin

   !> A contact surface whose unit normals differ by more than this (1 - cos) is curved.
   real(wp), parameter :: contact_curved_tol = 1.0e-10_wp
   !> recover_contact_patch doubles a rank-deficient Omega_aux's depth at most this often.
   integer, parameter :: aux_max_doublings = 4

contains

   !> Coupled SPR-C of patch (1) (with contact points) and patch (2) (the Omega_aux fit of the
   !> other body), module notes. law(j), slip(1:dim, j): contact law and slip direction of
   !> boundary point j of patch1 (read where bkind(j) = boundary_contact; slip only for the
   !> slip law); mu: friction coefficient. Results rec1, rec2 as recover_sprc's; rec1%rows /
   !> ranks count the contact rows nowhere (ncontact_rows, contact_rank give them).
   !> Errors: invalid input (stat_invalid_input), rank-deficient patches or dependent
   !> constraints (stat_singular).
   subroutine recover_sprc_contact(patch1, patch2, degree, law, mu, slip, ws1, ws2, rec1, rec2, error, &
      & ncontact_rows, contact_rank, offset, ratio, weight2)
      type(patch_type), intent(in) :: patch1, patch2
      integer, intent(in) :: degree
      integer, intent(in) :: law(:)
      real(wp), intent(in) :: mu, slip(:, :)
      type(recovery_workspace_type), intent(inout) :: ws1, ws2
      type(recovered_patch_type), intent(out) :: rec1, rec2
      type(error_type), allocatable, intent(out) :: error
      integer, intent(out), optional :: ncontact_rows, contact_rank
      !> Where the surfaces of the two bodies are apart (an interference, a gap closed by the
      !> contact): body (2)'s point paired with contact point j is bx(:, j) + offset(1:dim, j),
      !> and ratio(j) = dA2/dA1 the ratio of the two surfaces' measures there, so that the rows
      !> balance forces: t1(x_j) dA1 = -t2(x_j + offset_j) dA2 (the FE contact's balance of
      !> each slave point with its master point). Default: the same point, ratio 1.
      real(wp), intent(in), optional :: offset(:, :), ratio(:)
      !> The weight of body (2)'s objective against body (1)'s (> 0; default 1, alike).
      real(wp), intent(in), optional :: weight2
      real(wp), allocatable :: c(:, :), lam(:)
      real(wp) :: sc
      integer :: mc1, mc2, mz, r, n1, n2

      call check_contact_input(patch1, law, slip, error, patch2)
      if (allocated(error)) return
      if (present(offset)) then
         if (size(offset, 1) < patch1%dim .or. size(offset, 2) < patch1%nbpoints) call fatal_error(error, &
            & 'recover_sprc_contact: offset needs '//itoa(patch1%dim)//' x '//itoa(patch1%nbpoints)//' entries', &
            & stat_invalid_input)
      end if
      if (present(weight2) .and. .not. allocated(error)) then
         if (.not. (weight2 > 0.0_wp .and. weight2 <= huge(1.0_wp))) call fatal_error(error, &
            & 'recover_sprc_contact: weight2 is not finite and > 0', stat_invalid_input)
      end if
      if (present(ratio) .and. .not. allocated(error)) then
         if (size(ratio) < patch1%nbpoints) then
            call fatal_error(error, 'recover_sprc_contact: ratio needs '//itoa(patch1%nbpoints)//' boundary points', &
               & stat_invalid_input)
         else if (.not. all(ratio(1:patch1%nbpoints) > 0.0_wp)) then
            call fatal_error(error, 'recover_sprc_contact: a measure ratio is not positive', stat_invalid_input)
         end if
      end if
      if (allocated(error)) return
      call sprc_constraints(patch1, degree, ws1, rec1, mc1, .true., error)
      if (allocated(error)) return
      call sprc_constraints(patch2, degree, ws2, rec2, mc2, .false., error)
      if (allocated(error)) then
         error%message = 'Omega_aux fit: '//error%message
         return
      end if
      n1 = ws1%n
      n2 = ws2%n
      mz = patch1%dim*count(patch1%bkind(1:patch1%nbpoints) == boundary_contact)
      allocate (c(mc1 + mc2 + min(mz, n1 + n2), n1 + n2), lam(mc1 + mc2 + min(mz, n1 + n2)))
      c = 0.0_wp
      lam = 0.0_wp
      c(1:mc1, 1:n1) = ws1%c(1:mc1, 1:n1)
      lam(1:mc1) = ws1%lam(1:mc1)
      c(mc1 + 1:mc1 + mc2, n1 + 1:n1 + n2) = ws2%c(1:mc2, 1:n2)
      lam(mc1 + 1:mc1 + mc2) = ws2%lam(1:mc2)
      call contact_block(patch1, patch2, degree, law, mu, slip, ws1, ws2, mz, c(mc1 + mc2 + 1:, :), r, rec1, error, &
         & offset, ratio)
      if (allocated(error)) return
      if (present(ncontact_rows)) ncontact_rows = mz
      if (present(contact_rank)) contact_rank = r
      sc = 1.0_wp
      if (present(weight2)) sc = sqrt(weight2)
      call coupled_solve(patch1, patch2, ws1, ws2, c(1:mc1 + mc2 + r, :), lam(1:mc1 + mc2 + r), sc, rec1, rec2, error)
   end subroutine recover_sprc_contact

   pure subroutine check_contact_input(patch1, law, slip, error, patch2)
      type(patch_type), intent(in) :: patch1
      integer, intent(in) :: law(:)
      real(wp), intent(in) :: slip(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type), intent(in), optional :: patch2
      character(len=120) :: buf

      buf = ''
      if (patch1%nbpoints < 1) then
         buf = 'patch1 has no contact points'
      else if (.not. allocated(patch1%bkind)) then
         buf = 'patch1 boundary arrays are not allocated'
      else if (count(patch1%bkind(1:min(patch1%nbpoints, size(patch1%bkind))) == boundary_contact) == 0) then
         buf = 'patch1 has no contact points'
      else if (size(law) < patch1%nbpoints .or. size(slip, 2) < patch1%nbpoints .or. size(slip, 1) < patch1%dim) then
         write (buf, '("law and slip need ",i0," boundary points")') patch1%nbpoints
      else if (present(patch2)) then
         if (patch2%dim /= patch1%dim) then
            write (buf, '("patch2%dim = ",i0," differs from patch1%dim = ",i0)') patch2%dim, patch1%dim
         else if (patch2%nbpoints > 0) then
            if (any(patch2%bkind(1:patch2%nbpoints) == boundary_contact)) buf = 'patch2 (Omega_aux) has contact points'
         end if
      end if
      if (len_trim(buf) > 0) call fatal_error(error, 'recover_sprc_contact: '//trim(buf), stat_invalid_input)
   end subroutine check_contact_input

   !> The contact rows (module notes): rows(1:r, :) of R Pi^T, r the kept rank.
   subroutine contact_block(patch1, patch2, degree, law, mu, slip, ws1, ws2, mz, rows, r, rec1, error, offset, ratio)
      type(patch_type), intent(in) :: patch1, patch2
      integer, intent(in) :: degree, law(:), mz
      real(wp), intent(in) :: mu, slip(:, :)
      type(recovery_workspace_type), intent(in) :: ws1, ws2
      real(wp), intent(inout) :: rows(:, :)
      integer, intent(out) :: r
      type(recovered_patch_type), intent(inout) :: rec1
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: offset(:, :), ratio(:)
      real(wp) :: frame(3, 3), h(3, 6), hp(3, 6), p(20), s(3), sq, wsum, z(3, 120), nref(3), x2(3), r2
      real(wp), allocatable :: e(:, :), tau(:), vn(:, :)
      integer, allocatable :: jpvt(:)
      integer :: j, d, n1, n2, m, k, cap, jc
      logical :: curved

      d = patch1%dim
      n1 = ws1%n
      n2 = ws2%n
      allocate (e(mz, n1 + n2), tau(min(mz, n1 + n2)), jpvt(n1 + n2), vn(n1 + n2, 2))
      wsum = 0.0_wp
      jc = 0
      curved = .false.
      do j = 1, patch1%nbpoints
         if (patch1%bkind(j) /= boundary_contact) cycle
         wsum = wsum + patch1%bw(j)
         if (jc == 0) then
            jc = j
            nref(1:d) = patch1%bn(1:d, j)
         end if
         curved = curved .or. dot_product(nref(1:d), patch1%bn(1:d, j)) < 1.0_wp - contact_curved_tol
      end do
      if (.not. (wsum > 0.0_wp)) then
         call fatal_error(error, 'recover_sprc_contact: the contact weights of patch1 sum to 0', stat_invalid_input)
         return
      end if
      m = 0
      do j = 1, patch1%nbpoints
         if (patch1%bkind(j) /= boundary_contact) cycle
         if (law(j) == contact_law_slip) then
            call contact_frame(d, patch1%bn(1:d, j), frame, error, slip=slip(1:d, j))
         else
            call contact_frame(d, patch1%bn(1:d, j), frame, error)
         end if
         if (.not. allocated(error)) then
            call contact_operator(d, frame, h)
            call contact_law_operator(d, law(j), mu, h, hp, error)
         end if
         if (allocated(error)) then
            error%message = 'recover_sprc_contact: boundary point '//itoa(j)//' (law '// &
               & contact_law_name(law(j))//'): '//error%message
            return
         end if
         sq = sqrt(patch1%bw(j)/wsum)
         s(1:d) = (patch1%bx(1:d, j) - patch1%x0(1:d))/patch1%h
         call ws1%basis%eval(s(1:d), p)
         call contact_rows(d, ws1%nt, h, p, sq, z(:, 1:n1))
         e(m + 1:m + d, 1:n1) = z(1:d, 1:n1)
         x2(1:d) = patch1%bx(1:d, j)
         if (present(offset)) x2(1:d) = x2(1:d) + offset(1:d, j)
         r2 = 1.0_wp
         if (present(ratio)) r2 = ratio(j)
         s(1:d) = (x2(1:d) - patch2%x0(1:d))/patch2%h
         call ws2%basis%eval(s(1:d), p)
         call contact_rows(d, ws2%nt, hp, p, -sq*r2, z(:, 1:n2))
         e(m + 1:m + d, n1 + 1:n1 + n2) = z(1:d, 1:n2)
         m = m + d
      end do
      cap = flat_traction_rank(d, merge(degree - 1, degree, curved))
      call qr_pivoted(mz, n1 + n2, e, jpvt, tau, vn, recovery_bite_ratio, max_steps=cap)
      r = 0
      do k = 1, min(mz, n1 + n2, cap)
         if (abs(e(k, k)) > traction_rank_tol*abs(e(1, 1))) r = k
      end do
      if (r < min(mz, n1 + n2, cap) .and. r > 0) call note_dropped(rec1, abs(e(r + 1, r + 1))/abs(e(1, 1)))
      do k = 1, r
         rows(k, :) = 0.0_wp
         rows(k, jpvt(k:n1 + n2)) = e(k, k:n1 + n2)
      end do
   end subroutine contact_block

   !> The constrained minimum of both bodies' fits under the stacked rows c z = lam (module notes),
   !> body (2)'s objective weighed by sc^2: in z2' = sc z2 the objective is |z1 - g1|^2 +
   !> |z2' - sc g2|^2 and body (2)'s constraint columns are divided by sc.
   subroutine coupled_solve(patch1, patch2, ws1, ws2, c, lam, sc, rec1, rec2, error)
      type(patch_type), intent(in) :: patch1, patch2
      type(recovery_workspace_type), intent(inout) :: ws1, ws2
      real(wp), intent(inout) :: c(:, :), lam(:)
      real(wp), intent(in) :: sc
      type(recovered_patch_type), intent(inout) :: rec1, rec2
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: wt(:, :), tau(:), z(:, :), g1(:, :), g2(:, :), vn(:, :)
      integer, allocatable :: jpvt(:), keep(:)
      integer :: n1, n2, nn, mc, k, r
      real(wp) :: nrm
      logical :: ok

      n1 = ws1%n
      n2 = ws2%n
      nn = n1 + n2
      mc = size(c, 1)
      ! Rank selection of the stacked rows, normalised (as select_stacked).
      allocate (wt(nn, mc), tau(max(1, min(nn, mc))), jpvt(max(1, mc)), keep(max(1, mc)), vn(max(1, mc), 2))
      do k = 1, mc
         nrm = sqrt(sum(c(k, :)**2))
         wt(:, k) = c(k, :)/nrm
      end do
      r = 0
      if (mc > 0) then
         call qr_pivoted(nn, mc, wt, jpvt, tau, vn, recovery_bite_ratio)
         do k = 1, min(nn, mc)
            if (abs(wt(k, k)) > recovery_rank_tol*abs(wt(1, 1))) r = k
         end do
         if (r < min(nn, mc) .and. r > 0) then
            call note_dropped(rec1, abs(wt(r + 1, r + 1))/abs(wt(1, 1)))
            call note_dropped(rec2, abs(wt(r + 1, r + 1))/abs(wt(1, 1)))
         end if
      end if
      keep(1:r) = jpvt(1:r)
      ! W^T = blockdiag(I x R_b^-T Pi_b^T) C^T of the kept rows.
      deallocate (wt)
      allocate (wt(nn, max(1, r)))
      do k = 1, r
         call body_columns(ws1, c(keep(k), 1:n1), wt(1:n1, k), ok)
         if (ok) call body_columns(ws2, c(keep(k), n1 + 1:nn), wt(n1 + 1:nn, k), ok)
         if (.not. ok) exit
         wt(n1 + 1:nn, k) = wt(n1 + 1:nn, k)/sc
      end do
      if (r > 0 .and. ok) then
         call qr_pivoted(nn, r, wt, jpvt, tau, vn)
      end if
      allocate (z(nn, 1))
      call body_rhs(patch1, ws1, g1)
      call body_rhs(patch2, ws2, g2)
      z(1:n1, 1) = reshape(g1(1:ws1%nt, 1:ws1%ns), [n1])
      z(n1 + 1:nn, 1) = sc*reshape(g2(1:ws2%nt, 1:ws2%ns), [n2])
      if (r > 0 .and. ok) then
         call apply_qt(nn, r, wt, tau, 1, z)
         z(1:r, 1) = lam(keep(jpvt(1:r)))
         call solve_upper(r, wt, 1, z, ok, transposed=.true.)
         if (ok) call apply_q(nn, r, wt, tau, 1, z)
      end if
      if (.not. ok) then
         call fatal_error(error, 'recover_sprc_contact: the coupled constraint rows are dependent in the norm '// &
            & 'of the patches (singular constrained system)', stat_singular)
         return
      end if
      z(n1 + 1:nn, 1) = z(n1 + 1:nn, 1)/sc
      rec1%rank_total = r
      rec2%rank_total = r
      call body_coef(ws1, z(1:n1, 1), rec1, ok)
      if (ok) call body_coef(ws2, z(n1 + 1:nn, 1), rec2, ok)
      if (.not. ok) call fatal_error(error, 'recover_sprc_contact: the triangular factor of a basis is singular', &
         & stat_singular)
   end subroutine coupled_solve

   !> v := (I x R^-T Pi^T) row: the row in the z coordinates of one body.
   pure subroutine body_columns(ws, row, v, ok)
      type(recovery_workspace_type), intent(in) :: ws
      real(wp), intent(in) :: row(:)
      real(wp), intent(out) :: v(:)
      logical, intent(out) :: ok
      real(wp) :: b(ws%nt, 1)
      integer :: cc, o

      ok = .true.
      do cc = 1, ws%ns
         o = (cc - 1)*ws%nt
         b(:, 1) = row(o + ws%jpvt_p(1:ws%nt))
         call solve_upper(ws%nt, ws%qr, 1, b, ok, transposed=.true.)
         if (.not. ok) return
         v(o + 1:o + ws%nt) = b(:, 1)
      end do
   end subroutine body_columns

   !> g = Q^T sqrt(w) sigma, its leading nt rows per component.
   subroutine body_rhs(patch, ws, g)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(in) :: ws
      real(wp), allocatable, intent(out) :: g(:, :)
      integer :: cc, np

      np = patch%npoints
      allocate (g(np, ws%ns))
      do cc = 1, ws%ns
         g(:, cc) = ws%wn(1:np)*patch%stress(cc, 1:np)
      end do
      call apply_qt(np, ws%nt, ws%qr, ws%tau_p, ws%ns, g)
   end subroutine body_rhs

   !> A_c = Pi R^-1 z_c into rec%coef.
   pure subroutine body_coef(ws, z, rec, ok)
      type(recovery_workspace_type), intent(in) :: ws
      real(wp), intent(in) :: z(:)
      type(recovered_patch_type), intent(inout) :: rec
      logical, intent(out) :: ok
      real(wp) :: b(ws%nt, ws%ns)

      b = reshape(z, [ws%nt, ws%ns])
      call solve_upper(ws%nt, ws%qr, ws%ns, b, ok)
      if (.not. ok) return
      if (allocated(rec%coef)) deallocate (rec%coef)
      allocate (rec%coef(ws%nt, ws%ns))
      rec%coef(ws%jpvt_p(1:ws%nt), :) = b
   end subroutine body_coef

   !> One contact patch from the other body's sampling points (mesh-agnostic): Omega_aux of
   !> patch1's contact points (sprc_recovery_contact_aux, margin 0, widened as below) with depth `depth`, patch2
   !> filled with body (2)'s points y2(1:dim, j), weights w2(j), Voigt stresses stress2(:, j)
   !> inside it (x0 the Omega_aux centre, h the largest distance from it to a chosen point;
   !> material young2, poisson2, body force body_force2 if given; the analysis of patch1), then
   !> recover_sprc_contact. While the Omega_aux fit is rank deficient (too few or coplanar
   !> points of body (2)) the depth is doubled, at most aux_max_doublings times, and the
   !> cross-section widened by half the added depth on every side (a patch whose contact
   !> points nearly coincide has a prism too thin to hold points); depth_used
   !> returns the depth of the solve. patch2 is storage reused between calls.
   !> `max_doublings` (default aux_max_doublings) bounds the doublings. With `candidates`, only
   !> body (2)'s points j = candidates(i) are considered, in that order (a caller that has
   !> culled them, sprc_estimate_contact_patches: no copy of the points).
   subroutine recover_contact_patch(patch1, degree, law, mu, slip, y2, w2, stress2, young2, poisson2, depth, &
      & ws1, ws2, patch2, rec1, rec2, error, body_force2, depth_used, max_doublings, boundary2, candidates, offset, &
      & ratio, weight2)
      type(patch_type), intent(in) :: patch1
      integer, intent(in) :: degree, law(:)
      real(wp), intent(in) :: mu, slip(:, :), y2(:, :), w2(:), stress2(:, :), young2, poisson2, depth
      type(recovery_workspace_type), intent(inout) :: ws1, ws2
      type(patch_type), intent(inout) :: patch2
      type(recovered_patch_type), intent(out) :: rec1, rec2
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: body_force2(:)
      real(wp), intent(out), optional :: depth_used
      integer, intent(in), optional :: max_doublings
      !> Body (2)'s boundary points other than its contact surface (traction or symmetry kinds,
      !> in the boundary arrays of a patch): those inside Omega_aux constrain its fit.
      type(patch_type), intent(in), optional :: boundary2
      integer, intent(in), optional :: candidates(:)
      !> Body (2)'s paired points, the measure ratios and body (2)'s weight (recover_sprc_contact's).
      real(wp), intent(in), optional :: offset(:, :), ratio(:), weight2
      type(aux_domain_type) :: aux
      real(wp), allocatable :: cx(:, :), cn(:, :), cw(:)
      real(wp) :: dep
      integer :: d, k, kmax, j

      d = patch1%dim
      call check_contact_input(patch1, law, slip, error)
      if (allocated(error)) return
      if (size(y2, 1) < d .or. size(w2) > size(y2, 2) .or. size(stress2, 2) < size(w2)) then
         call fatal_error(error, 'recover_contact_patch: y2, w2 and stress2 disagree in size', stat_invalid_input)
         return
      end if
      if (present(candidates)) then
         if (any(candidates < 1 .or. candidates > size(w2))) then
            j = findloc(candidates < 1 .or. candidates > size(w2), .true., dim=1)
            call fatal_error(error, 'recover_contact_patch: candidates('//itoa(j)//') = '//itoa(candidates(j))// &
               & ' is not a point of body (2) (1..'//itoa(size(w2))//')', stat_invalid_input)
            return
         end if
      end if
      call contact_points(patch1, cx, cn, cw)
      dep = depth
      kmax = aux_max_doublings
      if (present(max_doublings)) kmax = max(0, min(max_doublings, aux_max_doublings))
      do k = 0, kmax
         call new_aux_domain(aux, d, cx, cn, cw, dep, aux_margin(dep, depth), error)
         if (allocated(error)) then
            error%message = 'recover_contact_patch: '//error%message
            return
         end if
         if (present(candidates)) then
            call fill_aux_patch(patch1, aux, y2, w2, stress2, young2, poisson2, patch2, candidates)
         else
            call fill_aux_patch(patch1, aux, y2, w2, stress2, young2, poisson2, patch2)
         end if
         if (present(boundary2)) call add_aux_boundary(aux, boundary2, patch2)
         if (present(body_force2)) patch2%body_force(1:d) = body_force2(1:d)
         if (present(depth_used)) depth_used = dep
         dep = 2*dep
         if (patch2%npoints == 0 .and. k < kmax) cycle
         call recover_sprc_contact(patch1, patch2, degree, law, mu, slip, ws1, ws2, rec1, rec2, error, offset=offset, &
            & ratio=ratio, weight2=weight2)
         if (.not. allocated(error)) return
         if (error%stat /= stat_singular .or. index(error%message, 'Omega_aux fit') == 0) return
      end do
   end subroutine recover_contact_patch

   !> The cross-section margin of Omega_aux at depth `dep` when the first depth is `depth`
   !> (recover_contact_patch: half the added depth).
   pure real(wp) function aux_margin(dep, depth)
      real(wp), intent(in) :: dep, depth
      aux_margin = 0.5_wp*(dep - depth)
   end function aux_margin

   !> The contact points of patch1: coordinates, normals, weights.
   pure subroutine contact_points(patch1, cx, cn, cw)
      type(patch_type), intent(in) :: patch1
      real(wp), allocatable, intent(out) :: cx(:, :), cn(:, :), cw(:)
      integer :: j, m, d

      d = patch1%dim
      m = count(patch1%bkind(1:patch1%nbpoints) == boundary_contact)
      allocate (cx(d, m), cn(d, m), cw(m))
      m = 0
      do j = 1, patch1%nbpoints
         if (patch1%bkind(j) /= boundary_contact) cycle
         m = m + 1
         cx(:, m) = patch1%bx(1:d, j)
         cn(:, m) = patch1%bn(1:d, j)
         cw(m) = patch1%bw(j)
      end do
   end subroutine contact_points

   !> Body (2)'s boundary points inside Omega_aux into patch2 (where the prism meets another
   !> boundary of body (2): its traction or symmetry, Figure 31).
   pure subroutine add_aux_boundary(aux, boundary2, patch2)
      type(aux_domain_type), intent(in) :: aux
      type(patch_type), intent(in) :: boundary2
      type(patch_type), intent(inout) :: patch2
      integer :: j, n

      n = 0
      do j = 1, boundary2%nbpoints
         if (boundary2%bkind(j) /= boundary_contact .and. aux_contains(aux, boundary2%bx(:, j))) n = n + 1
      end do
      call patch_reserve(patch2, 0, patch2%nbpoints + n)
      do j = 1, boundary2%nbpoints
         if (boundary2%bkind(j) == boundary_contact .or. .not. aux_contains(aux, boundary2%bx(:, j))) cycle
         patch2%nbpoints = patch2%nbpoints + 1
         associate (k => patch2%nbpoints)
            patch2%bx(:, k) = boundary2%bx(:, j)
            patch2%bw(k) = boundary2%bw(j)
            patch2%bn(:, k) = boundary2%bn(:, j)
            patch2%bkind(k) = boundary2%bkind(j)
            patch2%bpiece(k) = boundary2%bpiece(j)
            patch2%btraction(:, k) = boundary2%btraction(:, j)
         end associate
      end do
   end subroutine add_aux_boundary

   !> patch2 := body (2)'s points inside Omega_aux (recover_contact_patch), of `candidates` if given.
   pure subroutine fill_aux_patch(patch1, aux, y2, w2, stress2, young2, poisson2, patch2, candidates)
      type(patch_type), intent(in) :: patch1
      type(aux_domain_type), intent(in) :: aux
      real(wp), intent(in) :: y2(:, :), w2(:), stress2(:, :), young2, poisson2
      type(patch_type), intent(inout) :: patch2
      integer, intent(in), optional :: candidates(:)
      integer, allocatable :: inside(:)
      integer :: i, j, k, n, d, ns, nc
      real(wp) :: h

      d = patch1%dim
      ns = merge(3, 6, d == 2)
      nc = size(w2)
      if (present(candidates)) nc = size(candidates)
      allocate (inside(nc))
      h = 0.0_wp
      n = 0
      do i = 1, nc
         j = i
         if (present(candidates)) j = candidates(i)
         if (.not. aux_contains(aux, y2(:, j))) cycle
         n = n + 1
         inside(n) = j
         h = max(h, norm2(y2(1:d, j) - aux%centre(1:d)))
      end do
      call patch_reset(patch2, d, patch1%analysis, young2, poisson2, aux%centre(1:d), max(h, tiny(1.0_wp)))
      call patch_reserve(patch2, n, 0)
      do k = 1, n
         j = inside(k)
         patch2%x(:, k) = 0.0_wp
         patch2%x(1:d, k) = y2(1:d, j)
         patch2%w(k) = w2(j)
         patch2%stress(:, k) = 0.0_wp
         patch2%stress(1:ns, k) = stress2(1:ns, j)
      end do
      patch2%npoints = n
   end subroutine fill_aux_patch

end module sprc_recovery_contact_patch_solve
