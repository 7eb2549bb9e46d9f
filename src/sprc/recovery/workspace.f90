!> Per-thread work storage of the SPR / SPR-C patch solves.
!>
!> One `recovery_workspace_type` per thread holds every work array.
!> `workspace_reserve` (called by the solves) grows the arrays only when a patch
!> needs more than the current capacity, so a patch loop allocates nothing once
!> its largest patch has been seen. The polynomial basis,
!> its derivative matrices and the divergence and incompatibility operators
!> depend only on (dim, degree) and are rebuilt only when these change: keep one
!> workspace per (dim, degree) in a loop that mixes them.
!>
!> No module state: workspaces are independent objects, one per thread. Declare
!> the thread's workspace inside the parallel region (a `block` construct, or a
!> local variable of a procedure called there), or call `workspace_init` on a
!> `private` copy first: gfortran does not apply default initialisation to
!> OpenMP private copies, and a garbage capacity would be trusted.
!>
!> Contact patches (sprc_estimate_contact_patches) keep in the thread's workspace what they need
!> besides it (`contact`): the workspace and patch of the Omega_aux fit, allocated on the
!> thread's first contact patch and kept.
module sprc_recovery_workspace
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_out_of_memory
   use sprc_core_text, only: itoa
   use sprc_core_poly, only: poly_basis_type, new_poly_basis, poly_nterms, poly_max_degree
   use sprc_core_timer, only: wall_time
   use sprc_recovery_operators, only: divergence_operator, incompatibility_operator, ncompat_equations, &
      & hess_index, voigt_pair
   implicit none
   private

   public :: recovery_workspace_type, workspace_init, workspace_reserve, workspace_tic, workspace_toc

   !> Work arrays of the patch solves (components are internal to sprc_recovery; public only
   !> so that the solve module can reach them without accessor overhead).
   type :: recovery_workspace_type
      !> Dimension and degree the basis and operators are built for.
      integer :: dim = 0, degree = -1
      !> Terms, stress components, unknowns nt*ns.
      integer :: nt = 0, ns = 0, n = 0
      !> Polynomial basis of (dim, degree).
      type(poly_basis_type) :: basis
      !> Derivative matrices d/ds_k, dmat(nt, nt, dim); second-derivative matrices d2(nt, nt, nhess).
      real(wp), allocatable :: dmat(:, :, :), d2(:, :, :)
      !> Coefficient-space divergence operator bdiv(dim*nt, n), and its nonzeros by column
      !> (about one or two of dim*nt: a derivative maps a monomial to one monomial): column k
      !> has rows bnz_row(bnz_ptr(k):bnz_ptr(k + 1) - 1) with values bnz_val(...).
      real(wp), allocatable :: bdiv(:, :)
      integer, allocatable :: bnz_ptr(:), bnz_row(:)
      real(wp), allocatable :: bnz_val(:)
      !> Incompatibility operator on strains, incomp(ncompat, ns, nhess).
      real(wp), allocatable :: incomp(:, :, :)
      !> Capacities: integration points, boundary points, unknowns, block rows, QR columns.
      integer :: cap_p = 0, cap_b = 0, cap_n = 0, cap_mr = 0, cap_mq = 0, cap_nt = 0
      !> Scaled point coordinates s(3, cap_p) and normalised weights wn(cap_p).
      real(wp), allocatable :: s(:, :), wn(:)
      !> (Weighted) design matrix pw(cap_p, cap_nt), its QR copy, right-hand sides rhs(cap_p, 6).
      real(wp), allocatable :: pw(:, :), qr(:, :), rhs(:, :)
      !> Gram matrix of one component mp(cap_nt, cap_nt).
      real(wp), allocatable :: mp(:, :)
      !> One constraint block blk(cap_mr, cap_n) with right-hand side brhs(cap_mr).
      real(wp), allocatable :: blk(:, :), brhs(:)
      !> (I x Mp) B, tmp(3*cap_nt, cap_n).
      real(wp), allocatable :: tmp(:, :)
      !> Weighted traction operator rows estack(3*cap_b, cap_n) and data trhs(3*cap_b, 1);
      !> equilibrium right-hand side erhs(3*cap_nt).
      real(wp), allocatable :: estack(:, :), trhs(:, :), erhs(:)
      !> Traction face of each boundary point bface(cap_b) and the first point of each face bfirst(cap_b).
      integer, allocatable :: bface(:), bfirst(:)
      !> Transposed rows for the pivoted QR, cq(cap_n, cap_mq).
      real(wp), allocatable :: cq(:, :)
      !> Accepted constraint rows c(cap_mq, cap_n) and right-hand side lam(cap_mq).
      real(wp), allocatable :: c(:, :), lam(:)
      !> Column norms of the pivoted QRs vn(max(cap_mq, cap_n), 2); the constrained solve's
      !> vector z(cap_n, 1).
      real(wp), allocatable :: vn(:, :), z(:, :)
      !> Householder scalars and pivots of the basis QR (tau_p, jpvt_p) and of the others.
      real(wp), allocatable :: tau(:), tau_p(:)
      integer, allocatable :: jpvt(:), jpvt_p(:)
      !> SPR may solve a well-conditioned patch by the normal equations (sprc_recovery_patch_solve,
      !> "Normal equations"); .false.: always the pivoted QR (tests compare the two).
      logical :: normal_equations = .true.
      !> If true, the solves accumulate the wall time spent inside the dense kernels
      !> (sprc_core_dense and the small products) and their nominal flop counts.
      logical :: timing = .false.
      !> Seconds spent in the dense kernels (only if `timing`).
      real(wp) :: lapack_seconds = 0.0_wp
      !> Nominal flops of those kernels (only if `timing`; counted as the LAPACK/BLAS call
      !> of the same operation, LAWN 41 leading terms, sprc_recovery_flops).
      integer(i8) :: flops = 0
      !> Hand count of forming the design matrix at the integration points, the one counted
      !> hand-written loop (only if `timing`; `design_matrix_flops`), kept apart from `flops`.
      integer(i8) :: design_flops = 0
      real(wp) :: t0 = 0.0_wp
      !> Contact patches' storage (module notes; its type is sprc_estimate_contact_patches's: a producer's).
      class(*), allocatable :: contact
   end type recovery_workspace_type

contains

   !> Reset a workspace to its empty default state (frees its storage). Needed only for
   !> copies whose default initialisation is not guaranteed (OpenMP `private`).
   pure subroutine workspace_init(ws)
      type(recovery_workspace_type), intent(out) :: ws
      ws%dim = 0
   end subroutine workspace_init

   !> Prepare `ws` for a patch of `npoints` integration and `nbpoints` boundary points with a
   !> basis of `degree` in `dim`: rebuilds basis and operators if (dim, degree) changed, grows
   !> arrays only beyond the current capacity (then re-queries lwork).
   subroutine workspace_reserve(ws, dim, degree, npoints, nbpoints, error)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: dim, degree, npoints, nbpoints
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: buf

      if ((dim /= 2 .and. dim /= 3) .or. degree < 0 .or. degree > poly_max_degree) then
         write (buf, '("dim = ",i0,", degree = ",i0)') dim, degree
         call fatal_error(error, 'recovery workspace: unsupported '//trim(buf)// &
            & ' (dim 2 or 3, degree 0..3)', stat_invalid_input)
         return
      end if
      if (npoints < 0 .or. nbpoints < 0) then
         call fatal_error(error, 'recovery workspace: negative point count', stat_invalid_input)
         return
      end if
      if (dim /= ws%dim .or. degree /= ws%degree) then
         call build_operators(ws, dim, degree, error)
         if (allocated(error)) return
      end if
      if (npoints > ws%cap_p .or. nbpoints > ws%cap_b .or. ws%n > ws%cap_n .or. ws%nt > ws%cap_nt) then
         call grow(ws, max(npoints, ws%cap_p), max(nbpoints, ws%cap_b), max(ws%n, ws%cap_n), &
            & max(ws%nt, ws%cap_nt), error)
      end if
   end subroutine workspace_reserve

   subroutine build_operators(ws, dim, degree, error)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: dim, degree
      type(error_type), allocatable, intent(out) :: error
      integer :: k, m, a, b, nt, nh

      call new_poly_basis(ws%basis, dim, degree, error)
      if (allocated(error)) return
      nt = poly_nterms(dim, degree)
      nh = merge(3, 6, dim == 2)
      ws%dim = dim
      ws%degree = degree
      ws%nt = nt
      ws%ns = nh
      ws%n = nt*nh
      if (allocated(ws%dmat)) deallocate (ws%dmat, ws%d2, ws%bdiv, ws%incomp)
      allocate (ws%dmat(nt, nt, dim), ws%d2(nt, nt, nh), ws%bdiv(dim*nt, ws%n))
      allocate (ws%incomp(ncompat_equations(dim), nh, nh))
      do k = 1, dim
         call ws%basis%derivative_matrix(k, ws%dmat(:, :, k), error)
         if (allocated(error)) return
      end do
      do m = 1, nh
         call voigt_pair(dim, m, a, b)
         if (hess_index(dim, a, b) /= m) then
            call fatal_error(error, 'recovery workspace: second-derivative order mismatch', stat_invalid_input)
            return
         end if
         ws%d2(:, :, m) = matmul(ws%dmat(:, :, a), ws%dmat(:, :, b))
      end do
      call divergence_operator(dim, nt, ws%dmat, ws%bdiv)
      call sparse_columns(ws%bdiv, ws%bnz_ptr, ws%bnz_row, ws%bnz_val)
      call incompatibility_operator(dim, ws%incomp)
   end subroutine build_operators

   !> The nonzeros of a by column (CSC without the matrix's zeros).
   pure subroutine sparse_columns(a, ptr, row, val)
      real(wp), intent(in) :: a(:, :)
      integer, allocatable, intent(out) :: ptr(:), row(:)
      real(wp), allocatable, intent(out) :: val(:)
      integer :: k, i, m

      allocate (ptr(size(a, 2) + 1), row(count(a /= 0.0_wp)), val(count(a /= 0.0_wp)))
      m = 0
      ptr(1) = 1
      do k = 1, size(a, 2)
         do i = 1, size(a, 1)
            if (a(i, k) == 0.0_wp) cycle
            m = m + 1
            row(m) = i
            val(m) = a(i, k)
         end do
         ptr(k + 1) = m + 1
      end do
   end subroutine sparse_columns

   subroutine grow(ws, cp, cb, cn, cnt, error)
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(in) :: cp, cb, cn, cnt
      type(error_type), allocatable, intent(out) :: error
      integer :: st

      ws%cap_p = cp
      ws%cap_b = cb
      ws%cap_n = cn
      ws%cap_nt = cnt
      ! Largest block: n Gram rows, 6 compatibility equations x nt, or symmetry rows
      ! (2 tangents x 10 lattice points x 3 planes).
      ws%cap_mr = max(cn, 6*cnt, 60)
      ! Accepted rows before the stacked selection: equilibrium, compatibility and symmetry
      ! at most cn each, traction at most one per traction row (3 per boundary point).
      ws%cap_mq = max(ws%cap_mr, 4*cn, 3*cn + 3*cb)
      if (allocated(ws%s)) then
         deallocate (ws%s, ws%wn, ws%pw, ws%qr, ws%rhs, ws%mp, ws%blk, ws%brhs, ws%tmp)
         deallocate (ws%estack, ws%trhs, ws%erhs, ws%cq, ws%c, ws%lam, ws%bface, ws%bfirst)
         deallocate (ws%tau, ws%jpvt, ws%tau_p, ws%jpvt_p, ws%vn, ws%z)
      end if
      allocate (ws%s(3, max(cp, 1)), ws%wn(max(cp, 1)), stat=st)
      if (st == 0) allocate (ws%pw(max(cp, cnt), cnt), ws%qr(max(cp, cnt), cnt), ws%rhs(max(cp, cnt), 6), stat=st)
      if (st == 0) allocate (ws%mp(cnt, cnt), ws%blk(ws%cap_mr, cn), ws%brhs(ws%cap_mr), ws%tmp(3*cnt, cn), stat=st)
      if (st == 0) allocate (ws%estack(max(3*cb, 1), cn), ws%trhs(max(3*cb, 1), 1), ws%erhs(3*cnt), stat=st)
      if (st == 0) allocate (ws%cq(cn, ws%cap_mq), ws%c(ws%cap_mq, cn), ws%lam(ws%cap_mq), stat=st)
      if (st == 0) allocate (ws%bface(max(cb, 1)), ws%bfirst(max(cb, 1)), stat=st)
      if (st == 0) allocate (ws%tau(max(ws%cap_mq, cn)), ws%jpvt(max(ws%cap_mq, cn)), ws%tau_p(cnt), &
         & ws%jpvt_p(cnt), stat=st)
      if (st == 0) allocate (ws%vn(max(ws%cap_mq, cn, cnt), 2), ws%z(cn, 1), stat=st)
      if (st /= 0) then
         call workspace_init(ws)
         call fatal_error(error, 'recovery workspace: out of memory for a patch of '//itoa(cp)//' points', &
            & stat_out_of_memory)
      end if
   end subroutine grow

   !> Start timing a LAPACK/BLAS call (no-op unless ws%timing).
   subroutine workspace_tic(ws)
      type(recovery_workspace_type), intent(inout) :: ws
      if (ws%timing) ws%t0 = wall_time()
   end subroutine workspace_tic

   !> Stop timing a LAPACK/BLAS call and accumulate into ws%lapack_seconds, and the call's
   !> nominal flop count `flops` (sprc_recovery_flops; the sum if the tic/toc pair encloses
   !> several calls) into ws%flops.
   subroutine workspace_toc(ws, flops)
      type(recovery_workspace_type), intent(inout) :: ws
      !> Required, so that a new LAPACK call site cannot leave the count out unnoticed.
      integer(i8), intent(in) :: flops
      if (.not. ws%timing) return
      ws%lapack_seconds = ws%lapack_seconds + (wall_time() - ws%t0)
      ws%flops = ws%flops + flops
   end subroutine workspace_toc

end module sprc_recovery_workspace
