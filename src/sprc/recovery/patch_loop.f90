!> The patch loop of SPR / SPR-C, shared by every producer of patches (the Cartesian grid,
!> sprc_estimate_patches; a caller's mesh, sprc_recovery_caller_mesh). A producer may solve some patches
!> its own way (`recover`: the grid's contact patches) or skip them (`skip`). Thesis eqs. 8-11,
!> 19-24, 99-100; Figure 15.
!>
!> A producer describes its mesh by plain arrays: the node -> element CSR (ne_ptr, ne_list;
!> elements ascending per node), the element -> node table (connectivity, for expansion),
!> the node of each patch; and by a `patch_source_type` extension that gathers the points
!> of a list of elements into a `patch_type` (`fill`) and counts the points a list of
!> elements contributes (`points_of`, for the workspace capacity).
!>
!> Patch of node n: the elements of n, in list order. A patch whose basis matrix lacks
!> rank (the core returns stat_singular) gets one more ring, every element sharing a node
!> with the patch (in list and node order), and is solved again, at most `rounds_limit`
!> times; a ring that adds no element stops the expansion. A patch without points is
!> stat_singular ('no integration points').
!>
!> Parallelism and determinism: the loop is OpenMP-parallel over patches (dynamic
!> schedule); each thread owns a patch object, two recovery workspaces, an element list
!> and an element stamp array. Every thread reserves the same capacity (`patch_capacity`:
!> the largest unexpanded patch over the producer's nodes) and never grows it, so that
!> nothing is allocated per patch; a patch that outgrows it (only after expansion) is
!> solved in the second workspace reset to its own size. The solves' kernels
!> (sprc_core_dense) depend only on the patch's values and sizes, not on capacities,
!> and results are stored per patch: the bits do not depend on the thread count or the
!> schedule. The solves call no BLAS; OpenBLAS is held to one thread inside the loop all
!> the same (sprc_core_blas_threads), for a producer's `fill` that might. Errors are
!> recorded per patch; after the loop the first failing patch is solved again serially
!> for its message.
module sprc_recovery_patch_loop
   use sprc_core_kinds, only: wp
   use sprc_core_alloc, only: check_allocation
   use sprc_core_error, only: error_type, fatal_error, stat_singular, stat_internal
   use sprc_core_poly, only: poly_nterms
   use sprc_core_blas_threads, only: blas_serial_begin, blas_serial_end
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reserve
   use sprc_recovery_workspace, only: recovery_workspace_type, workspace_reserve, workspace_init
   use sprc_recovery_patch_solve, only: recover_spr, recover_sprc
   implicit none
   private

   public :: patch_source_type, patch_loop_type, run_patch_loop, patch_capacity, auto_degree, recover_patch_default

   !> What a producer gives the loop besides its mesh arrays: it must be safe to call from
   !> several threads at once (read-only).
   type, abstract :: patch_source_type
   contains
      !> Reset `patch` and gather the points of `elements` for the patch of `node`.
      procedure(fill_interface), deferred :: fill
      !> [volume points, boundary points] the elements of a list add to a patch (boundary
      !> points 0 when the method takes none). A list, not one element: one dynamic
      !> dispatch per patch, not per element.
      procedure(points_interface), deferred :: points_of
      !> Solve a filled patch: SPR or SPR-C (`recover_patch_default`). A producer overrides
      !> it for patches it solves otherwise (the grid's contact patches); stat_singular
      !> expands the patch as usual.
      procedure :: recover => recover_patch_default
   end type patch_source_type

   abstract interface
      subroutine fill_interface(self, node, elements, patch)
         import :: patch_source_type, patch_type
         class(patch_source_type), intent(in) :: self
         integer, intent(in) :: node, elements(:)
         type(patch_type), intent(inout) :: patch
      end subroutine fill_interface

      pure function points_interface(self, elements) result(counts)
         import :: patch_source_type
         class(patch_source_type), intent(in) :: self
         integer, intent(in) :: elements(:)
         integer :: counts(2)
      end function points_interface
   end interface

   !> Options of one loop.
   type :: patch_loop_type
      !> Space dimension, patch polynomial degree, expansion rounds allowed per patch.
      integer :: dim = 0, degree = 0, rounds_limit = 0
      !> SPR-C (constrained) or SPR.
      logical :: sprc = .false.
      !> Capacity [points, boundary points] every thread reserves (`patch_capacity`).
      integer :: cap(2) = 0
   end type patch_loop_type

   !> Per-thread storage of the loop.
   type :: scratch_type
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws, ws_big
      integer, allocatable :: list(:), stamp(:)
      integer :: nlist = 0
   end type scratch_type

contains

   !> The default patch degree ('auto', every producer): SPR at the FE degree p; SPR-C at
   !> p + 1 for quadratic elements (effectivity closer to 1 and errors 2-3 times smaller on
   !> Q2 rings) and at p for linear ones (their stresses are too rough for quadratic
   !> patches); SPR at p + 1 gets worse.
   pure integer function auto_degree(sprc, fe_degree)
      logical, intent(in) :: sprc
      integer, intent(in) :: fe_degree
      auto_degree = fe_degree
      if (sprc .and. fe_degree == 2) auto_degree = fe_degree + 1
   end function auto_degree

   !> [points, boundary points] of the largest unexpanded patch over `nodes` (at least
   !> 4 nterms points: room for a full basis).
   function patch_capacity(source, dim, degree, ne_ptr, ne_list, nodes) result(cap)
      class(patch_source_type), intent(in) :: source
      integer, intent(in) :: dim, degree, ne_ptr(:), ne_list(:), nodes(:)
      integer :: cap(2)
      integer :: i, n, counts(2), c1, c2

      c1 = 4*poly_nterms(dim, degree)
      c2 = 0
      !$omp parallel do schedule(static) private(n, counts) reduction(max:c1, c2)
      do i = 1, size(nodes)
         n = nodes(i)
         counts = source%points_of(ne_list(ne_ptr(n):ne_ptr(n + 1) - 1))
         c1 = max(c1, counts(1))
         c2 = max(c2, counts(2))
      end do
      !$omp end parallel do
      cap = [c1, c2]
   end function patch_capacity

   !> Recover the patch of every node patch_node(ip) into recs(ip) (module notes), with its
   !> expansion rounds and final element count. skip(ip) = .true.: patch ip is left alone
   !> (another module recovers it; recs(ip) stays empty, rounds and nel 0). On failure
   !> `failed` is the first failing patch and `error` its error as the core gave it
   !> (stat_singular after the last expansion round, or 'no integration points'): the
   !> producer names the patch.
   subroutine run_patch_loop(opt, source, ne_ptr, ne_list, connectivity, patch_node, recs, rounds, nel, failed, &
         & error, skip)
      type(patch_loop_type), intent(in) :: opt
      class(patch_source_type), intent(in) :: source
      integer, intent(in) :: ne_ptr(:), ne_list(:), connectivity(:, :), patch_node(:)
      type(recovered_patch_type), intent(inout) :: recs(:)
      integer, intent(out) :: rounds(:), nel(:), failed
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: skip(:)
      integer, allocatable :: status(:)
      integer :: saved_blas, stat

      allocate (status(size(patch_node)), stat=stat)
      call check_allocation(stat, 'patch loop', 'the status of each patch', size(patch_node), 4, error)
      if (allocated(error)) return
      failed = 0
      saved_blas = blas_serial_begin()
      !$omp parallel default(shared)
      call thread_loop(opt, source, ne_ptr, ne_list, connectivity, patch_node, recs, rounds, nel, status, skip)
      !$omp end parallel
      call blas_serial_end(saved_blas)
      if (all(status == 0)) return
      failed = findloc(status /= 0, .true., dim=1)
      block
         type(scratch_type) :: sc
         call init_scratch(sc, opt, size(connectivity, 2), error)
         if (allocated(error)) return
         call recover_patch(opt, source, ne_ptr, ne_list, connectivity, patch_node(failed), sc, recs(failed), &
            & rounds(failed), nel(failed), error)
      end block
      if (.not. allocated(error)) call fatal_error(error, 'patch loop: the patch failed in the parallel loop '// &
         & 'but not serially', stat_internal)
   end subroutine run_patch_loop

   !> One thread's share (called inside the parallel region: its locals are the thread's).
   subroutine thread_loop(opt, source, ne_ptr, ne_list, connectivity, patch_node, recs, rounds, nel, status, skip)
      type(patch_loop_type), intent(in) :: opt
      class(patch_source_type), intent(in) :: source
      integer, intent(in) :: ne_ptr(:), ne_list(:), connectivity(:, :), patch_node(:)
      type(recovered_patch_type), intent(inout) :: recs(:)
      integer, intent(inout) :: rounds(:), nel(:), status(:)
      logical, intent(in), optional :: skip(:)
      type(scratch_type) :: sc
      type(error_type), allocatable :: err, init_err
      integer :: ip

      ! A thread whose scratch could not be allocated fails its patches; the serial
      ! retry of the first of them reports the error.
      call init_scratch(sc, opt, size(connectivity, 2), init_err)
      !$omp do schedule(dynamic, 16)
      do ip = 1, size(patch_node)
         status(ip) = 0
         rounds(ip) = 0
         nel(ip) = 0
         if (present(skip)) then
            if (skip(ip)) cycle
         end if
         if (allocated(init_err)) then
            status(ip) = init_err%stat
            cycle
         end if
         call recover_patch(opt, source, ne_ptr, ne_list, connectivity, patch_node(ip), sc, recs(ip), rounds(ip), &
            & nel(ip), err)
         if (allocated(err)) status(ip) = err%stat
      end do
      !$omp end do
   end subroutine thread_loop

   !> Thread storage of the common capacity (module notes).
   subroutine init_scratch(sc, opt, n_elements, error)
      type(scratch_type), intent(inout) :: sc
      type(patch_loop_type), intent(in) :: opt
      integer, intent(in) :: n_elements
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      call workspace_init(sc%ws)
      call workspace_init(sc%ws_big)
      allocate (sc%list(64), sc%stamp(n_elements), stat=stat)
      call check_allocation(stat, 'patch loop', 'the element stamps of a thread', n_elements, 4, error)
      if (allocated(error)) return
      sc%stamp = 0
      ! dim and degree were validated by the producer: only an allocation can fail here.
      call workspace_reserve(sc%ws, opt%dim, opt%degree, opt%cap(1), opt%cap(2), error)
      if (allocated(error)) return
      call patch_reserve(sc%patch, opt%cap(1), opt%cap(2))
   end subroutine init_scratch

   !> Gather, solve, and expand while the basis lacks rank.
   subroutine recover_patch(opt, source, ne_ptr, ne_list, connectivity, n, sc, rec, rounds, nel, error)
      type(patch_loop_type), intent(in) :: opt
      class(patch_source_type), intent(in) :: source
      integer, intent(in) :: ne_ptr(:), ne_list(:), connectivity(:, :), n
      type(scratch_type), intent(inout) :: sc
      ! inout: every solve resets rec (its intent(out)); an intent(out) here re-initialised
      ! the record once more per patch (a copy of the default, perf: memmove).
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(out) :: rounds, nel
      type(error_type), allocatable, intent(out) :: error
      integer :: k, round, nprev

      sc%nlist = 0
      do k = ne_ptr(n), ne_ptr(n + 1) - 1
         call list_add(sc, ne_list(k), n)
      end do
      rounds = 0
      do round = 0, opt%rounds_limit
         if (round > 0) then
            nprev = sc%nlist
            call expand(ne_ptr, ne_list, connectivity, sc, n)
            if (sc%nlist == nprev) exit
            rounds = round
         end if
         call source%fill(n, sc%list(1:sc%nlist), sc%patch)
         if (sc%patch%npoints == 0) cycle
         if (sc%patch%npoints <= sc%ws%cap_p .and. sc%patch%nbpoints <= sc%ws%cap_b) then
            call solve(sc%ws)
         else
            call workspace_init(sc%ws_big)
            call solve(sc%ws_big)
         end if
         if (.not. allocated(error)) exit
         if (error%stat /= stat_singular) exit
      end do
      nel = sc%nlist
      if (sc%patch%npoints == 0 .and. .not. allocated(error)) &
         & call fatal_error(error, 'no integration points', stat_singular)
   contains
      subroutine solve(ws)
         type(recovery_workspace_type), intent(inout) :: ws
         call source%recover(n, sc%list(1:sc%nlist), sc%patch, opt%degree, opt%sprc, ws, rec, error)
      end subroutine solve
   end subroutine recover_patch

   !> The default solve of a filled patch (`patch_source_type%recover`): SPR-C or SPR at
   !> `degree` in `ws`. `node` and `elements` are the patch's, as given to `fill`.
   subroutine recover_patch_default(self, node, elements, patch, degree, sprc, ws, rec, error)
      class(patch_source_type), intent(in) :: self
      integer, intent(in) :: node, elements(:), degree
      type(patch_type), intent(in) :: patch
      logical, intent(in) :: sprc
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error

      ! Unused here (an overriding producer's): scalars only, no array constructor (a
      ! heap temporary per patch).
      associate (unused => node + size(elements)); end associate
      associate (unused => self); end associate
      if (sprc) then
         call recover_sprc(patch, degree, ws, rec, error)
      else
         call recover_spr(patch, degree, ws, rec, error)
      end if
   end subroutine recover_patch_default

   subroutine list_add(sc, e, tag)
      type(scratch_type), intent(inout) :: sc
      integer, intent(in) :: e, tag
      integer, allocatable :: tmp(:)

      if (sc%stamp(e) == tag) return
      sc%stamp(e) = tag
      if (sc%nlist == size(sc%list)) then
         allocate (tmp(2*size(sc%list)))
         tmp(1:sc%nlist) = sc%list(1:sc%nlist)
         call move_alloc(tmp, sc%list)
      end if
      sc%nlist = sc%nlist + 1
      sc%list(sc%nlist) = e
   end subroutine list_add

   !> One ring: every element sharing a node with the patch, in list and node order.
   subroutine expand(ne_ptr, ne_list, connectivity, sc, tag)
      integer, intent(in) :: ne_ptr(:), ne_list(:), connectivity(:, :)
      type(scratch_type), intent(inout) :: sc
      integer, intent(in) :: tag
      integer :: i, j, k, m, n0

      n0 = sc%nlist
      do i = 1, n0
         do j = 1, size(connectivity, 1)
            m = connectivity(j, sc%list(i))
            do k = ne_ptr(m), ne_ptr(m + 1) - 1
               call list_add(sc, ne_list(k), tag)
            end do
         end do
      end do
   end subroutine expand

end module sprc_recovery_patch_loop
