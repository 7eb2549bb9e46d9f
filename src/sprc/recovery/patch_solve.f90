!> SPR and SPR-C patch solves (the thesis, doc/theory.md, eqs. 8-11, 19-24, 35-42, 44-62,
!> 77-80, 88-94, 99-100).
!>
!> Both fit sigma*(x) = P(s) A, s = (x - x0)/h, with the complete polynomial of degree p in
!> patch-scaled coordinates (sprc_core_poly's term order).
!>
!> - `recover_spr` (Zienkiewicz-Zhu 1992): least squares per component at the integration
!>   points, by QR with column pivoting of P (not normal equations: the pivoted QR decides
!>   the rank anyway and solves with cond(P), not cond(P)^2); components share one factor.
!> - `recover_sprc` (Rodenas et al. 2007): all components at once, integral least squares
!>   with weights w|J| (normalised by their sum), plus equality constraints:
!>   (a) internal equilibrium, least-squares form (eq. 42), formed in coefficient space as
!>       B^T (I x Mp) B with B the exact divergence: no per-point work;
!>   (b) compatibility for p >= 2, exact, from the compliance;
!>   (c) traction equilibrium, least-squares form (eq. 80), only on faces the node lies on
!>       (within traction_reach h): rows far from the node pin the polynomial away from it.
!>       Per face, a pivoted QR keeps at most the flat-face rank (degree p), or degree p - 1
!>       on a curved face, where the further rows would fit the arc and ignore the interior
!>       data. Rows are weighted (1 - |x - x0|/h)^4 (`traction_focus`) to centre the fit on
!>       the node, which the union (eq. 102) uses most;
!>   (d) symmetry, exact: zero shear at a unisolvent lattice on each symmetry plane.
!>   Each block, then the stacked normalised rows, is rank-reduced by pivoted QR. The KKT
!>   minimiser is computed by orthogonal transformations only (`project_constraints`):
!>   cond(sqrt(W) P) instead of the KKT matrix's cond(P)^2, and no LAPACK call overhead.
!>
!> Normal equations (SPR only): with G = P^T P = R^T R (Cholesky), kappa_2(P) = kappa_2(R)
!> <= kappa_F(R) = |R|_F |R^-1|_F, computed from R (a few nt^3 flops, far below the QR's
!> np nt^2). When kappa_F(R) <= spr_normal_kappa the basis has full rank with room (the
!> pivoted QR's |R_nn|/|R_11| >= 1/kappa_2(P), far above recovery_rank_tol, so it would keep
!> every pivot and drop none), and the normal equations' forward error, of order
!> eps kappa^2, is within a factor spr_normal_kappa of the QR's eps kappa: the coefficients
!> agree with the QR's to round-off (tested against it). This is the usual SPR patch of
!> linear elements (kappa of a few in patch-scaled coordinates), where the QR's column norms
!> and reflector chains dominated the loop; any other patch, and every SPR-C patch, takes
!> the pivoted QR. `ws%normal_equations` = .false. forces the QR (tests).
!>
!> Rank: pivots below `recovery_rank_tol` |R_11| are dropped; a dropped pivot above
!> `recovery_bite_ratio` means the tolerance, not exact dependence, decided a rank, and is
!> reported (`tolerance_bites`, `max_dropped_ratio`). A basis of rank < nterms returns
!> stat_singular naming the rank: the producer grows the patch (the thesis, Figure 15) and
!> calls again; SPR-C needs full rank too, so that M is positive definite.
!>
!> Timing (ws%timing): each dense kernel adds its wall time to ws%lapack_seconds and the
!> flop count of the equivalent LAPACK/BLAS call to ws%flops (design matrix: ws%design_flops).
!>
!> Thread safety: no module state; one workspace per thread; no BLAS or LAPACK calls, so
!> no OpenBLAS lock and no dependence on its thread count.
module sprc_recovery_patch_solve
   use sprc_core_kinds, only: wp
   use sprc_core_sort, only: sort
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular
   use sprc_core_dense, only: qr_pivoted, apply_qt, apply_q, solve_upper
   use sprc_core_material, only: compliance_matrix
   use sprc_core_poly, only: poly_max_degree
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, check_patch, dominant_boundary_kind, &
      & boundary_traction, boundary_symmetry, boundary_contact, boundary_none, &
      & kind_equilibrium, kind_compatibility, kind_traction, kind_symmetry
   use sprc_recovery_operators, only: traction_operator, shear_operator, plane_tangents, compatibility_rows, &
      & ncompat_equations
   use sprc_recovery_workspace, only: recovery_workspace_type, workspace_reserve, workspace_tic, workspace_toc
   use sprc_recovery_flops, only: flops_gemm, flops_gemv, flops_syrk, flops_geqrf, flops_ormqr_left, flops_trtrs, &
      & flops_potrf, flops_trtri, design_matrix_flops
   implicit none
   private

   public :: recover_spr, recover_sprc, sprc_constraints, note_dropped, recovery_rank_tol, recovery_bite_ratio, traction_rank_tol
   public :: flat_traction_rank, traction_reach

   !> Relative tolerance of every rank decision (pivoted QR): |R_kk| > tol |R_11| counts.
   real(wp), parameter :: recovery_rank_tol = 1.0e-10_wp
   !> A discarded pivot above this ratio means the tolerance decided the rank.
   real(wp), parameter :: recovery_bite_ratio = 1.0e-12_wp
   !> Relative pivot tolerance of the traction rows: a ratio of the weighted E, not of E^T E.
   real(wp), parameter :: traction_rank_tol = 1.0e-8_wp
   !> Traction rows only for patches with a traction point within traction_reach h of the node.
   real(wp), parameter :: traction_reach = 0.1_wp
   !> Largest kappa_F(R) for which SPR solves the normal equations (module notes): their
   !> error eps kappa^2 is then at most spr_normal_kappa times the QR's eps kappa.
   real(wp), parameter :: spr_normal_kappa = 100.0_wp
   !> Largest basis solved by the normal equations (degree 1 in 3D).
   integer, parameter :: spr_normal_terms = 4
   !> A traction face whose unit normals differ by more than this (1 - cos) is curved.
   real(wp), parameter :: flat_face_tol = 1.0e-10_wp
   !> Floor of the traction weight (1 - rho)^4 (`traction_focus`).
   real(wp), parameter :: traction_focus_floor = 0.05_wp
   !> Two traction points of one piece belong to one face if their normals' cosine exceeds this.
   real(wp), parameter :: face_cos = 0.25_wp
   !> Two symmetry points lie on the same plane if normals and offsets (scaled) agree to this.
   real(wp), parameter :: plane_tol = 1.0e-8_wp

contains

   !> SPR (Zienkiewicz-Zhu 1992): per-component least squares of the FE stresses at the
   !> integration points with the complete basis of degree `degree` (0..3). Weights are not
   !> used. Errors: invalid patch (stat_invalid_input), rank-deficient patch (stat_singular).
   subroutine recover_spr(patch, degree, ws, rec, error)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: degree
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error

      logical :: done

      call design_matrix(patch, degree, ws, rec, .false., 'recover_spr', error)
      if (allocated(error)) return
      if (ws%normal_equations) then
         call spr_normal_equations(patch, ws, rec, done)
         if (done) return
      end if
      call factor_design(ws, rec, degree, patch%npoints, 'recover_spr', error)
      if (allocated(error)) return
      call least_squares(patch, ws, rec, .false., 0, 'recover_spr', error)
   end subroutine recover_spr

   !> SPR's least squares by the normal equations (P^T P) A = P^T sigma, Cholesky P^T P = R^T R,
   !> taken only when R proves the basis well conditioned (module notes, "Normal equations"):
   !> kappa_F(R) = |R|_F |R^-1|_F <= spr_normal_kappa. done = .false.: not taken; the caller
   !> factors the basis by pivoted QR instead. Bases of up to spr_normal_terms terms (degree 1:
   !> 3 terms in 2D, 4 in 3D), in fixed-size storage; a constant nt per branch lets the compiler
   !> unroll the tiny loops.
   subroutine spr_normal_equations(patch, ws, rec, done)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      logical, intent(out) :: done
      real(wp) :: a(spr_normal_terms, 6)
      integer :: i, c

      integer :: np, nt, ns

      done = .false.
      np = patch%npoints
      nt = ws%nt
      ns = ws%ns
      if (np < nt .or. nt > spr_normal_terms) return
      call workspace_tic(ws)
      select case (nt)
      case (3)
         call normal_solve(3, np, ns, ws%pw, patch%stress, a, done)
      case (4)
         call normal_solve(4, np, ns, ws%pw, patch%stress, a, done)
      case default
         call normal_solve(nt, np, ns, ws%pw, patch%stress, a, done)
      end select
      ! Counted as dsyrk + dgemm (P^T P, P^T sigma), dpotrf, dtrtri (the condition estimate)
      ! and two dtrtrs, whether taken or not.
      call workspace_toc(ws, flops_syrk(nt, np) + flops_gemm(nt, ns, np) + flops_potrf(nt) + flops_trtri(nt) + &
         & 2*flops_trtrs(nt, ns))
      if (.not. done) return
      rec%basis_rank = nt
      call coef_storage(rec, nt, ns)
      do c = 1, ns
         do i = 1, nt
            rec%coef(i, c) = a(i, c)
         end do
      end do
   end subroutine spr_normal_equations

   !> The normal-equation solve of `spr_normal_equations` for nt terms: a(1:nt, 1:ns), or
   !> done = .false. if a Cholesky pivot is not positive or kappa_F(R) > spr_normal_kappa.
   !> R^-1, computed for kappa_F anyway, also gives a = R^-1 (R^-T b) by two triangular
   !> products: independent sums instead of chains of divisions. Past the Gram matrix the
   !> system is padded to m = spr_normal_terms with an identity block (and zero data): its
   !> Cholesky factor, inverse and solution are exactly block-diagonal (the products with the
   !> padding are exact zeros), and constant loop bounds let the compiler unroll the tiny
   !> loops; kappa_F sums the first nt columns only.
   pure subroutine normal_solve(nt, np, ns, pw, stress, a, done)
      integer, intent(in) :: nt, np, ns
      real(wp), intent(in) :: pw(:, :), stress(:, :)
      real(wp), intent(out) :: a(spr_normal_terms, 6)
      logical, intent(out) :: done
      integer, parameter :: m = spr_normal_terms
      real(wp) :: r(m, m), ri(m, m), b(m, 6), t(m), dinv(m), d, rf, rif
      integer :: i, j, c

      done = .false.
      ! Gram matrix (upper triangle) and right-hand sides: sums over the points in order.
      do j = 1, nt
         do i = 1, j
            r(i, j) = dot_product(pw(1:np, i), pw(1:np, j))
         end do
         do c = 1, ns
            b(j, c) = dot_product(pw(1:np, j), stress(c, 1:np))
         end do
      end do
      ! The padding, entry by entry (whole-array zeroing was a `rep stos` per patch).
      do j = nt + 1, m
         do i = 1, j - 1
            r(i, j) = 0.0_wp
         end do
         r(j, j) = 1.0_wp
         do c = 1, ns
            b(j, c) = 0.0_wp
         end do
      end do
      ! Cholesky in place, with the pivots' reciprocals.
      rf = 0.0_wp
      do j = 1, m
         do i = 1, j - 1
            r(i, j) = (r(i, j) - dot_product(r(1:i - 1, i), r(1:i - 1, j)))*dinv(i)
         end do
         d = r(j, j) - dot_product(r(1:j - 1, j), r(1:j - 1, j))
         if (.not. (d > 0.0_wp)) return
         r(j, j) = sqrt(d)
         dinv(j) = 1.0_wp/r(j, j)
         if (j <= nt) rf = rf + dot_product(r(1:j, j), r(1:j, j))
      end do
      ! R^-1 column by column (R y = e_j) and |R^-1|_F.
      rif = 0.0_wp
      do j = 1, m
         ri(j, j) = dinv(j)
         do i = j - 1, 1, -1
            ri(i, j) = -dot_product(r(i, i + 1:j), ri(i + 1:j, j))*dinv(i)
         end do
         if (j <= nt) rif = rif + dot_product(ri(1:j, j), ri(1:j, j))
      end do
      if (.not. (rf*rif <= spr_normal_kappa**2)) return
      do c = 1, ns
         do i = 1, m
            t(i) = dot_product(ri(1:i, i), b(1:i, c))
         end do
         do i = 1, m
            a(i, c) = dot_product(ri(i, i:m), t(i:m))
         end do
      end do
      done = all(abs(a(1:nt, 1:ns)) <= huge(1.0_wp))
   end subroutine normal_solve

   !> SPR-C by integral least squares with the constraints switched on in `patch`
   !> (use_equilibrium, use_compatibility, use_boundary, all_boundary_kinds); see the module
   !> documentation. Errors: invalid patch (stat_invalid_input), rank-deficient patch or
   !> singular KKT system (stat_singular), contact boundaries (stat_invalid_input: not yet).
   subroutine recover_sprc(patch, degree, ws, rec, error)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: degree
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error
      integer :: mc

      call sprc_constraints(patch, degree, ws, rec, mc, .false., error)
      if (allocated(error)) return
      call least_squares(patch, ws, rec, .true., mc, 'recover_sprc', error)
   end subroutine recover_sprc

   !> SPR-C up to its solve: the validated patch's weighted basis QR (ws%qr, ws%jpvt_p, ws%tau_p,
   !> the weights ws%wn) and the rank-selected constraint rows ws%c(1:mc, 1:ws%n) A = ws%lam(1:mc)
   !> of the kinds switched on in `patch`. With contact_by_caller, contact boundary points are
   !> accepted and add no rows here (a patch with contact imposes contact only, as in the thesis): the
   !> coupled contact solve (sprc_recovery_contact_patch_solve) adds them. Errors as recover_sprc.
   subroutine sprc_constraints(patch, degree, ws, rec, mc, contact_by_caller, error)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: degree
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      integer, intent(out) :: mc
      logical, intent(in) :: contact_by_caller
      type(error_type), allocatable, intent(out) :: error

      mc = 0
      call prepare(patch, degree, ws, rec, .true., 'recover_sprc', error)
      if (allocated(error)) return
      call gram(ws, patch%npoints)
      if (patch%use_equilibrium) call equilibrium_block(patch, ws, rec, mc, error)
      if (allocated(error)) return
      if (patch%use_compatibility .and. degree >= 2) call compatibility_block(patch, ws, rec, mc, error)
      if (allocated(error)) return
      if (patch%use_boundary) call boundary_blocks(patch, ws, rec, mc, contact_by_caller, error)
      if (allocated(error)) return
      if (mc > 0) then
         call select_stacked(ws, mc, rec, error)
         if (allocated(error)) return
      end if
      rec%rank_total = mc
   end subroutine sprc_constraints

   !> Validate, reserve, scale the points, fill the (weighted) design matrix and decide its rank.
   subroutine prepare(patch, degree, ws, rec, weighted, context, error)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: degree
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      logical, intent(in) :: weighted
      character(len=*), intent(in) :: context
      type(error_type), allocatable, intent(out) :: error

      call design_matrix(patch, degree, ws, rec, weighted, context, error)
      if (allocated(error)) return
      call factor_design(ws, rec, degree, patch%npoints, context, error)
   end subroutine prepare

   !> Validate, reserve, scale the points and fill the (weighted) design matrix ws%pw.
   subroutine design_matrix(patch, degree, ws, rec, weighted, context, error)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: degree
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      logical, intent(in) :: weighted
      character(len=*), intent(in) :: context
      type(error_type), allocatable, intent(out) :: error
      integer :: i, np, nt
      real(wp) :: wsum
      character(len=160) :: buf

      if (degree < 0 .or. degree > poly_max_degree) then
         write (buf, '("degree = ",i0," is not in 0..",i0)') degree, poly_max_degree
         call fatal_error(error, context//': '//trim(buf), stat_invalid_input)
         return
      end if
      call check_patch(patch, error)
      if (allocated(error)) then
         error%message = context//': '//error%message
         return
      end if
      np = patch%npoints
      call workspace_reserve(ws, patch%dim, degree, np, patch%nbpoints, error)
      if (allocated(error)) return
      nt = ws%nt
      rec%dim = patch%dim
      rec%nstress = ws%ns
      rec%degree = degree
      rec%nterms = nt
      rec%x0 = patch%x0
      rec%h = patch%h

      ! Per coordinate with fixed bounds (a loop of run-time length dim per point cost more
      ! than its two or three divisions).
      do i = 1, np
         ws%s(1:2, i) = (patch%x(1:2, i) - patch%x0(1:2))/patch%h
      end do
      if (patch%dim == 3) then
         do i = 1, np
            ws%s(3, i) = (patch%x(3, i) - patch%x0(3))/patch%h
         end do
      end if
      call ws%basis%eval_points(ws%s(1:patch%dim, 1:np), ws%pw)
      if (weighted) then
         wsum = sum(patch%w(1:np))
         ws%wn(1:np) = sqrt(patch%w(1:np)/wsum)
         do i = 1, nt
            ws%pw(1:np, i) = ws%wn(1:np)*ws%pw(1:np, i)
         end do
      else
         ws%wn(1:np) = 1.0_wp
      end if
      if (ws%timing) ws%design_flops = ws%design_flops + design_matrix_flops(patch%dim, np, nt, weighted)
   end subroutine design_matrix

   !> Pivoted QR of the design matrix (in ws%qr) and its rank: stat_singular below nt.
   subroutine factor_design(ws, rec, degree, np, context, error)
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(in) :: degree, np
      character(len=*), intent(in) :: context
      type(error_type), allocatable, intent(out) :: error
      integer :: nt, r
      character(len=160) :: buf

      nt = ws%nt
      ws%qr(1:np, 1:nt) = ws%pw(1:np, 1:nt)
      call workspace_tic(ws)
      call qr_pivoted(np, nt, ws%qr, ws%jpvt_p, ws%tau_p, ws%vn, recovery_bite_ratio)
      call workspace_toc(ws, flops_geqrf(np, nt))
      r = diag_rank(ws%qr, min(np, nt))
      rec%basis_rank = r
      if (r < min(np, nt)) call note_dropped(rec, abs(ws%qr(r + 1, r + 1))/abs(ws%qr(1, 1)))
      if (r < nt) then
         write (buf, '("patch rank deficient: basis matrix rank ",i0," < ",i0," terms (degree ",i0,", ",i0, &
            & " points); too few or aligned points: expand the patch")') r, nt, degree, np
         call fatal_error(error, context//': '//trim(buf), stat_singular)
      end if
   end subroutine factor_design

   !> Rank from the diagonal of a pivoted-QR R: |R_kk| > tol |R_11| (tol: recovery_rank_tol
   !> unless given).
   pure integer function diag_rank(a, k, tol) result(r)
      real(wp), intent(in) :: a(:, :)
      integer, intent(in) :: k
      real(wp), intent(in), optional :: tol
      real(wp) :: t
      integer :: i

      t = recovery_rank_tol
      if (present(tol)) t = tol
      r = 0
      if (k < 1) return
      if (.not. (abs(a(1, 1)) > 0.0_wp)) return
      do i = 1, k
         if (abs(a(i, i)) > t*abs(a(1, 1))) r = i
      end do
   end function diag_rank

   !> Record a discarded pivot ratio |R_kk|/|R_11| of a rank decision in `rec`.
   pure subroutine note_dropped(rec, ratio)
      type(recovered_patch_type), intent(inout) :: rec
      real(wp), intent(in) :: ratio
      rec%max_dropped_ratio = max(rec%max_dropped_ratio, ratio)
      rec%tolerance_bites = rec%max_dropped_ratio > recovery_bite_ratio
   end subroutine note_dropped

   !> Least squares by the pivoted QR of the (weighted) design matrix already in ws%qr
   !> (Pw Pi = Q R), with the mc constraint rows ws%c(1:mc, :) A = ws%lam(1:mc) if mc > 0
   !> (module notes, "Constrained least squares"): A = Pi R^-1 z, z = Q^T (sqrt(w) sigma)
   !> projected onto the constraints.
   subroutine least_squares(patch, ws, rec, weighted, mc, context, error)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      logical, intent(in) :: weighted
      integer, intent(in) :: mc
      character(len=*), intent(in) :: context
      type(error_type), allocatable, intent(out) :: error
      integer :: np, nt, ns, c, i
      logical :: ok

      np = patch%npoints
      nt = ws%nt
      ns = ws%ns
      do c = 1, ns
         ws%rhs(1:np, c) = patch%stress(c, 1:np)
         if (weighted) ws%rhs(1:np, c) = ws%wn(1:np)*ws%rhs(1:np, c)
      end do
      call workspace_tic(ws)
      call apply_qt(np, nt, ws%qr, ws%tau_p, ns, ws%rhs)
      call workspace_toc(ws, flops_ormqr_left(np, ns, nt))
      if (mc > 0) then
         call project_constraints(ws, mc, ok)
         if (.not. ok) then
            call fatal_error(error, context//': the stacked constraint rows are dependent in the norm of the '// &
               & 'patch (singular constrained system)', stat_singular)
            return
         end if
      end if
      call workspace_tic(ws)
      call solve_upper(nt, ws%qr, ns, ws%rhs, ok)
      call workspace_toc(ws, flops_trtrs(nt, ns))
      if (.not. ok) then
         call fatal_error(error, context//': the triangular factor of the basis is singular (least squares)', &
            & stat_singular)
         return
      end if
      call coef_storage(rec, nt, ns)
      ! Loops, not vector-subscript assignments: those made array temporaries per patch.
      do c = 1, ns
         do i = 1, nt
            rec%coef(ws%jpvt_p(i), c) = ws%rhs(i, c)
         end do
      end do
   end subroutine least_squares

   !> The constrained minimum (module notes): with z_c = R Pi^T A_c the objective is
   !> |z - g|^2 (g = ws%rhs(1:nt, :)) and the constraints W z = Lambda, W = C (I x Pi R^-1).
   !> W^T Pi2 = U T (pivoted QR, U = the first mc columns of V = H_1 ... H_mc): the minimiser
   !> is z = V [T^-T Pi2^T Lambda; (V^T g)(mc+1:n)]. Orthogonal transformations and
   !> triangular solves only: no normal equations. ok = .false. if T is singular.
   subroutine project_constraints(ws, mc, ok)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: mc
      logical, intent(out) :: ok
      integer :: nt, ns, n, c, i, b, k

      nt = ws%nt
      ns = ws%ns
      n = ws%n
      do i = 1, mc
         do c = 1, ns
            b = (c - 1)*nt
            do k = 1, nt
               ws%cq(b + k, i) = ws%c(i, b + ws%jpvt_p(k))
            end do
         end do
      end do
      call workspace_tic(ws)
      do c = 1, ns
         b = (c - 1)*nt
         call solve_upper(nt, ws%qr, mc, ws%cq(b + 1:b + nt, 1:mc), ok, transposed=.true.)
         if (.not. ok) return
      end do
      call qr_pivoted(n, mc, ws%cq, ws%jpvt, ws%tau, ws%vn)
      do c = 1, ns
         ws%z((c - 1)*nt + 1:c*nt, 1) = ws%rhs(1:nt, c)
      end do
      call apply_qt(n, mc, ws%cq, ws%tau, 1, ws%z)
      do i = 1, mc
         ws%z(i, 1) = ws%lam(ws%jpvt(i))
      end do
      call solve_upper(mc, ws%cq, 1, ws%z, ok, transposed=.true.)
      if (ok) call apply_q(n, mc, ws%cq, ws%tau, 1, ws%z)
      call workspace_toc(ws, ns*flops_trtrs(nt, mc) + flops_geqrf(n, mc) + 2*flops_ormqr_left(n, 1, mc) + &
         & flops_trtrs(mc, 1))
      if (.not. ok) return
      do c = 1, ns
         ws%rhs(1:nt, c) = ws%z((c - 1)*nt + 1:c*nt, 1)
      end do
   end subroutine project_constraints

   !> Mp = P^T W P of one component (full symmetric).
   subroutine gram(ws, np)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: np
      integer :: i, j, nt

      nt = ws%nt
      call workspace_tic(ws)
      do j = 1, nt
         do i = 1, j
            ws%mp(i, j) = dot_product(ws%pw(1:np, i), ws%pw(1:np, j))
         end do
      end do
      call workspace_toc(ws, flops_syrk(nt, np))
      do i = 1, nt
         ws%mp(i + 1:nt, i) = ws%mp(i, i + 1:nt)
      end do
   end subroutine gram

   !> (a) internal equilibrium, least-squares form: rows B^T (I x Mp) B, rhs -h B^T (b x Mp(:,1)).
   subroutine equilibrium_block(patch, ws, rec, mc, error)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(inout) :: mc
      type(error_type), allocatable, intent(out) :: error
      integer :: i, j, k, l, r, b, nt, n, d

      nt = ws%nt
      n = ws%n
      d = patch%dim
      call workspace_tic(ws)
      ! Over B's nonzeros by column (ws%bnz_*: one or two per column), not the dense B:
      ! tmp(:, j) = (I x Mp) B(:, j), blk(k, j) = B(:, k)^T tmp(:, j).
      do j = 1, n
         ws%tmp(1:d*nt, j) = 0.0_wp
         do l = ws%bnz_ptr(j), ws%bnz_ptr(j + 1) - 1
            r = ws%bnz_row(l)
            b = ((r - 1)/nt)*nt
            ws%tmp(b + 1:b + nt, j) = ws%tmp(b + 1:b + nt, j) + ws%bnz_val(l)*ws%mp(1:nt, r - b)
         end do
      end do
      do i = 1, d
         ws%erhs((i - 1)*nt + 1:i*nt) = -patch%h*patch%body_force(i)*ws%mp(1:nt, 1)
      end do
      ! blk(k, :) = B(:, k)^T tmp, a row at a time over the nonzeros of B(:, k) (each entry
      ! the sum sparse_dot forms, in the same order; one loop of n per nonzero instead of a
      ! loop of one or two per entry).
      do k = 1, n
         ws%blk(k, 1:n) = 0.0_wp
         do l = ws%bnz_ptr(k), ws%bnz_ptr(k + 1) - 1
            r = ws%bnz_row(l)
            do j = 1, n
               ws%blk(k, j) = ws%blk(k, j) + ws%bnz_val(l)*ws%tmp(r, j)
            end do
         end do
      end do
      do j = 1, n
         ws%brhs(j) = sparse_dot(j, ws%erhs(1:d*nt))
      end do
      call workspace_toc(ws, d*flops_gemm(nt, n, nt) + flops_gemm(n, n, d*nt) + flops_gemv(d*nt, n))
      call select_block(ws, n, kind_equilibrium, rec, mc, error)
   contains
      !> B(:, k)^T v over the nonzeros of column k.
      pure real(wp) function sparse_dot(k, v)
         integer, intent(in) :: k
         real(wp), intent(in) :: v(:)
         integer :: l
         sparse_dot = 0.0_wp
         do l = ws%bnz_ptr(k), ws%bnz_ptr(k + 1) - 1
            sparse_dot = sparse_dot + ws%bnz_val(l)*v(ws%bnz_row(l))
         end do
      end function sparse_dot
   end subroutine equilibrium_block

   !> (b) compatibility, exact: coefficient rows of L'C P A (compliance times E, which only scales).
   subroutine compatibility_block(patch, ws, rec, mc, error)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(inout) :: mc
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: cmat(6, 6)
      integer :: m, ns

      ns = ws%ns
      call compliance_matrix(patch%analysis, patch%young, patch%poisson, cmat(1:ns, 1:ns), error)
      if (allocated(error)) return
      cmat(1:ns, 1:ns) = patch%young*cmat(1:ns, 1:ns)
      m = ncompat_equations(patch%dim)*ws%nt
      call compatibility_rows(patch%dim, ws%nt, ws%incomp, cmat(1:ns, 1:ns), ws%d2, ws%blk(1:m, 1:ws%n))
      ws%brhs(1:m) = 0.0_wp
      call select_block(ws, m, kind_compatibility, rec, mc, error)
   end subroutine compatibility_block

   !> (c), (d): boundary constraints of the dominant kind (or of every kind present).
   subroutine boundary_blocks(patch, ws, rec, mc, contact_by_caller, error)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(inout) :: mc
      logical, intent(in) :: contact_by_caller
      type(error_type), allocatable, intent(out) :: error
      integer :: kind

      kind = dominant_boundary_kind(patch)
      rec%boundary_kind = kind
      if (kind == boundary_none) return
      if (kind == boundary_contact) then
         if (.not. contact_by_caller) then
            call fatal_error(error, 'recover_sprc: a patch with contact boundary points '// &
               & 'needs the coupled contact solve (recover_sprc_contact)', stat_invalid_input)
         else if (any(patch%bkind(1:patch%nbpoints) == boundary_symmetry)) then
            ! Contact wins over tractions (the thesis); a symmetry plane agrees with any contact law
            ! (zero shear on the plane), so a contact patch at one keeps it.
            call symmetry_block(patch, ws, rec, mc, error)
         end if
         return
      end if
      if ((kind == boundary_traction .or. patch%all_boundary_kinds) .and. traction_near_node(patch)) then
         call traction_block(patch, ws, rec, mc, error)
         if (allocated(error)) return
      end if
      if (kind == boundary_symmetry .or. patch%all_boundary_kinds) then
         call symmetry_block(patch, ws, rec, mc, error)
      end if
   end subroutine boundary_blocks

   !> Weight of a traction point at distance rho = |x - x0| / h from the patch node (module
   !> notes, (c)): the quartic (1 - rho)^4 of moving least squares, floored so that no point of
   !> the patch (rho <= 1) drops out.
   pure real(wp) function traction_focus(rho)
      real(wp), intent(in) :: rho
      traction_focus = max(1.0_wp - rho, traction_focus_floor)**4
   end function traction_focus

   !> (c) traction equilibrium, least-squares form (eq. 80), per boundary face (module notes):
   !> QR with column pivoting of the face's weighted rows sqrt(bw_j f_j) E_j, E_j = G(n_j) P(s_j),
   !> f_j = traction_focus: E Pi = Q R, and eq. 80 (E^T E A = E^T t) is R Pi^T A = Q^T t. The
   !> leading rows of R whose pivots pass traction_rank_tol become constraints, at most the
   !> flat-face rank of degree p (flat face) or p - 1 (curved face).
   subroutine traction_block(patch, ws, rec, mc, error)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(inout) :: mc
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: g(3, 6), p(20), s(3), bsum, sq
      integer :: nfaces, f, j, i, k, c, d, nt, n, m, r, cap, kmax

      d = patch%dim
      nt = ws%nt
      n = ws%n
      call traction_faces(patch, ws, nfaces)
      do f = 1, nfaces
         if (.not. face_near_node(patch, ws, f)) cycle
         cap = flat_traction_rank(d, ws%degree)
         if (face_is_curved(patch, ws, f)) cap = flat_traction_rank(d, ws%degree - 1)
         bsum = 0.0_wp
         do j = 1, patch%nbpoints
            if (ws%bface(j) == f) bsum = bsum + patch%bw(j)*focus(j)
         end do
         m = 0
         do j = 1, patch%nbpoints
            if (ws%bface(j) /= f) cycle
            sq = sqrt(patch%bw(j)*focus(j)/bsum)
            s(1:d) = (patch%bx(1:d, j) - patch%x0(1:d))/patch%h
            call ws%basis%eval(s(1:d), p)
            call traction_operator(d, patch%bn(1:d, j), g)
            do i = 1, d
               m = m + 1
               do c = 1, ws%ns
                  ws%estack(m, (c - 1)*nt + 1:c*nt) = (sq*g(i, c))*p(1:nt)
               end do
               ws%trhs(m, 1) = sq*patch%btraction(i, j)
            end do
         end do
         rec%rows(kind_traction) = rec%rows(kind_traction) + m
         kmax = min(m, n)
         call workspace_tic(ws)
         call qr_pivoted(m, n, ws%estack, ws%jpvt, ws%tau, ws%vn, recovery_bite_ratio)
         call apply_qt(m, kmax, ws%estack, ws%tau, 1, ws%trhs)
         call workspace_toc(ws, flops_geqrf(m, n) + flops_ormqr_left(m, 1, kmax))
         r = diag_rank(ws%estack, kmax, traction_rank_tol)
         if (r < min(kmax, cap) .and. r > 0) &
            & call note_dropped(rec, abs(ws%estack(r + 1, r + 1))/abs(ws%estack(1, 1)))
         r = min(r, cap)
         do k = 1, r
            ws%c(mc + k, 1:n) = 0.0_wp
            do i = k, n
               ws%c(mc + k, ws%jpvt(i)) = ws%estack(k, i)
            end do
            ws%lam(mc + k) = ws%trhs(k, 1)
         end do
         mc = mc + r
         rec%ranks(kind_traction) = rec%ranks(kind_traction) + r
      end do
   contains
      real(wp) function focus(j)
         integer, intent(in) :: j
         focus = traction_focus(norm2(patch%bx(1:d, j) - patch%x0(1:d))/patch%h)
      end function focus
   end subroutine traction_block

   !> Traction faces of a patch: its traction points with weight > 0 grouped by boundary piece and,
   !> within a piece, by normal (a point joins the first face of its piece whose first normal
   !> makes an angle below acos(face_cos) with its own; corners of a box are separate faces).
   !> ws%bface(j) = face of point j (0: none).
   pure subroutine traction_faces(patch, ws, nfaces)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(out) :: nfaces
      integer :: j, f, q, d

      d = patch%dim
      nfaces = 0
      do j = 1, patch%nbpoints
         ws%bface(j) = 0
         if (patch%bkind(j) /= boundary_traction .or. .not. (patch%bw(j) > 0.0_wp)) cycle
         do f = 1, nfaces
            q = ws%bfirst(f)
            if (patch%bpiece(q) == patch%bpiece(j) .and. &
               & dot_product(patch%bn(1:d, q), patch%bn(1:d, j)) > face_cos) then
               ws%bface(j) = f
               exit
            end if
         end do
         if (ws%bface(j) == 0) then
            nfaces = nfaces + 1
            ws%bfirst(nfaces) = j
            ws%bface(j) = nfaces
         end if
      end do
   end subroutine traction_faces

   !> True if the normals of traction face f are not all parallel (1 - cos > flat_face_tol).
   pure logical function face_is_curved(patch, ws, f) result(curved)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(in) :: ws
      integer, intent(in) :: f
      integer :: j, q, d
      d = patch%dim
      q = ws%bfirst(f)
      curved = .false.
      do j = 1, patch%nbpoints
         if (ws%bface(j) /= f) cycle
         if (dot_product(patch%bn(1:d, q), patch%bn(1:d, j)) < 1.0_wp - flat_face_tol) then
            curved = .true.
            return
         end if
      end do
   end function face_is_curved

   !> True if the patch node lies on traction face f up to traction_reach h (module notes).
   pure logical function face_near_node(patch, ws, f) result(near)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(in) :: ws
      integer, intent(in) :: f
      near = node_near_points(patch, ws%bface, f)
   end function face_near_node

   !> True if the patch node lies on the traction boundary up to traction_reach h (module notes).
   pure logical function traction_near_node(patch) result(near)
      type(patch_type), intent(in) :: patch
      near = node_near_points(patch)
   end function traction_near_node

   !> The node's distance to the tangent plane at the nearest of the chosen boundary points is
   !> at most traction_reach h. Chosen: the points of face f (face_of(j) == f), or without
   !> face_of every traction point of positive weight.
   pure logical function node_near_points(patch, face_of, f) result(near)
      type(patch_type), intent(in) :: patch
      integer, intent(in), optional :: face_of(:), f
      integer :: j, jn, d
      real(wp) :: dist, dmin

      d = patch%dim
      jn = 0
      dmin = huge(1.0_wp)
      do j = 1, patch%nbpoints
         if (present(face_of)) then
            if (face_of(j) /= f) cycle
         else if (patch%bkind(j) /= boundary_traction .or. .not. (patch%bw(j) > 0.0_wp)) then
            cycle
         end if
         dist = norm2(patch%bx(1:d, j) - patch%x0(1:d))
         if (dist < dmin) then
            dmin = dist
            jn = j
         end if
      end do
      near = .false.
      if (jn > 0) near = abs(dot_product(patch%bn(1:d, jn), patch%x0(1:d) - patch%bx(1:d, jn))) <= &
         & traction_reach*patch%h
   end function node_near_points

   !> Rank of the traction rows of degree-`degree` stresses on a flat boundary piece: dim
   !> components, each a polynomial of degree p in dim - 1 variables, dim C(p + dim - 1, dim - 1).
   pure integer function flat_traction_rank(dim, degree) result(r)
      integer, intent(in) :: dim, degree
      if (dim == 2) then
         r = 2*(degree + 1)
      else
         r = 3*((degree + 1)*(degree + 2))/2
      end if
   end function flat_traction_rank

   !> (d) symmetry, exact: zero shear n^T sigma* t on each symmetry plane, imposed at the
   !> principal lattice of degree p on the plane (unisolvent for the restriction).
   subroutine symmetry_block(patch, ws, rec, mc, error)
      type(patch_type), intent(in) :: patch
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(inout) :: mc
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: pn(3, 3), pd(3), s(3), nrm(3), off, t(3, 2), g(6), p(20), base(3), alpha, beta
      integer :: nplanes, j, k, q, i1, i2, c, d, nt, m, deg, ntan
      character(len=80) :: buf

      d = patch%dim
      nt = ws%nt
      deg = ws%degree
      nplanes = 0
      do j = 1, patch%nbpoints
         if (patch%bkind(j) /= boundary_symmetry) cycle
         nrm(1:d) = patch%bn(1:d, j)
         s(1:d) = (patch%bx(1:d, j) - patch%x0(1:d))/patch%h
         off = dot_product(nrm(1:d), s(1:d))
         if (any([(maxval(abs(pn(1:d, k) - nrm(1:d))) <= plane_tol .and. abs(pd(k) - off) <= plane_tol, &
            & k=1, nplanes)])) cycle
         if (nplanes == 3) then
            write (buf, '("symmetry point ",i0," lies on a 4th plane")') j
            call fatal_error(error, 'recover_sprc: '//trim(buf)// &
               & ' (at most 3 symmetry planes per patch; symmetry boundaries must be planes)', stat_invalid_input)
            return
         end if
         nplanes = nplanes + 1
         pn(1:d, nplanes) = nrm(1:d)
         pd(nplanes) = off
      end do
      m = 0
      ntan = d - 1
      do k = 1, nplanes
         call plane_tangents(d, pn(:, k), t)
         base(1:d) = pd(k)*pn(1:d, k)
         do i1 = 0, deg
            do i2 = 0, merge(0, deg - i1, d == 2)
               alpha = 0.0_wp
               beta = 0.0_wp
               if (deg > 0) then
                  alpha = real(i1, wp)/real(deg, wp)
                  beta = real(i2, wp)/real(deg, wp)
               end if
               s(1:d) = base(1:d) + alpha*t(1:d, 1) + beta*t(1:d, 2)
               call ws%basis%eval(s(1:d), p)
               do q = 1, ntan
                  call shear_operator(d, pn(:, k), t(:, q), g)
                  m = m + 1
                  do c = 1, ws%ns
                     ws%blk(m, (c - 1)*nt + 1:c*nt) = g(c)*p(1:nt)
                  end do
                  ws%brhs(m) = 0.0_wp
               end do
            end do
         end do
      end do
      call select_block(ws, m, kind_symmetry, rec, mc, error)
   end subroutine symmetry_block

   !> Keep the rank-revealing rows of the block ws%blk(1:m, 1:n) / ws%brhs(1:m): dgeqp3 on the
   !> transposed rows; rows jpvt(1:r) (in their original order) go to ws%c / ws%lam after mc.
   subroutine select_block(ws, m, kind, rec, mc, error)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: m, kind
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(inout) :: mc
      type(error_type), allocatable, intent(out) :: error
      integer :: n, r, k, i

      rec%rows(kind) = rec%rows(kind) + m
      if (m == 0) return
      n = ws%n
      do k = 1, m
         ws%cq(1:n, k) = ws%blk(k, 1:n)
      end do
      call pivoted_rank(ws, n, m, rec, r, error)
      if (allocated(error)) return
      call sort(ws%jpvt(1:r))
      do k = 1, r
         i = ws%jpvt(k)
         ws%c(mc + k, 1:n) = ws%blk(i, 1:n)
         ws%lam(mc + k) = ws%brhs(i)
      end do
      mc = mc + r
      rec%ranks(kind) = rec%ranks(kind) + r
   end subroutine select_block

   !> Final rank selection over the stacked kept rows (normalised to unit length).
   subroutine select_stacked(ws, mc, rec, error)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(inout) :: mc
      type(recovered_patch_type), intent(inout) :: rec
      type(error_type), allocatable, intent(out) :: error
      integer :: n, r, k, i
      real(wp) :: nrm

      n = ws%n
      do k = 1, mc
         nrm = sqrt(sum(ws%c(k, 1:n)**2))
         ws%cq(1:n, k) = ws%c(k, 1:n)/nrm
      end do
      call pivoted_rank(ws, n, mc, rec, r, error)
      if (allocated(error)) return
      if (r == mc) return
      call sort(ws%jpvt(1:r))
      do k = 1, r
         i = ws%jpvt(k)
         ws%c(k, 1:n) = ws%c(i, 1:n)
         ws%lam(k) = ws%lam(i)
      end do
      mc = r
   end subroutine select_stacked

   !> Pivoted QR of ws%cq(1:n, 1:m); rank r from its diagonal; pivots in ws%jpvt(1:m).
   subroutine pivoted_rank(ws, n, m, rec, r, error)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: n, m
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(out) :: r
      type(error_type), allocatable, intent(out) :: error

      call workspace_tic(ws)
      call qr_pivoted(n, m, ws%cq, ws%jpvt, ws%tau, ws%vn, recovery_bite_ratio)
      call workspace_toc(ws, flops_geqrf(n, m))
      r = diag_rank(ws%cq, min(n, m))
      if (r < min(n, m) .and. r > 0) call note_dropped(rec, abs(ws%cq(r + 1, r + 1))/abs(ws%cq(1, 1)))
   end subroutine pivoted_rank

   !> rec%coef allocated (nterms, nstress), its entries left to the caller (least_squares
   !> sets every one): storage of the patch's own size, so that a mesh of many patches
   !> holds only what its degree needs.
   pure subroutine coef_storage(rec, nt, ns)
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(in) :: nt, ns
      if (allocated(rec%coef)) then
         if (any(shape(rec%coef) /= [nt, ns])) deallocate (rec%coef)
      end if
      if (.not. allocated(rec%coef)) allocate (rec%coef(nt, ns))
   end subroutine coef_storage

end module sprc_recovery_patch_solve
