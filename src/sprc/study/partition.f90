!> A level shared out among MPI ranks (`mpirun -n R sprc run`,
!> doc/distributed.md): each rank computes its part of the per-cell work and
!> the parts are gathered in rank order, so every rank ends with the same
!> arrays, bit for bit, as a serial run computes.
!>
!> - Quadrature: the leaves (in the tree's Morton order) split into R
!>   contiguous ranges of nearly equal work (`split_by_work`, a cut cell
!>   weighing `cut_cell_work` inside cells); each rank computes the cut-cell
!>   rules of its range, then the points of all ranges are gathered in leaf
!>   order (the volume fractions with them, which the cell aggregation of
!>   every rank needs).
!> - Assembly: rank r owns the reduced rows of a contiguous range of whole
!>   master blocks (`owned_rows`, the blocks split evenly); it computes the
!>   element and aggregate blocks that touch one of its rows (its elements
!>   and one layer of ghosts, reached through hanging-node and aggregation
!>   constraints by the element's reduced dofs) and sums its rows as the
!>   serial assembly does, over the same blocks in element order
!>   (`sprc_fem_problem`'s `assemble` with `rows`), so each row has the
!>   serial bits (PETSc's stash would add a row's off-rank parts in an order
!>   that is not fixed). It keeps only its rows (`keep_rows`): no rank holds
!>   the whole K; the problem's `rows_share` and `row_bounds` say which rows
!>   are where, PETSc's parallel matrix gets each rank's rows (the same split
!>   of the masters, `sprc_petsc_own_blocks`), and the solution is gathered
!>   to every rank (the recovery needs the displacements of its patches).
!>   A forced direct solve is refused: the direct solvers need the whole K.
!> - Recovery, estimate and exact error: `sprc_grid_share` (patches and
!>   elements in contiguous ranges, the records and element terms gathered;
!>   partition_type is the share whose gather is MPI's), for contact scenes too.
!> - Contact pairs (frictionless or stick, iterative): each rank assembles its
!>   rows of the pair's block system (`assemble_pair_rows`), the slave's
!>   unknowns then the master's, split by whole masters as the solve splits them.
!>
!> What is not partitioned: every rank holds the whole grid, points and the
!> gathered solution and recovered fields (doc/distributed.md). A serial run (one rank) takes none of these
!> paths: nothing of MPI is loaded. SPRC_PARTITION=0 in the environment keeps
!> every rank on the whole level (`split`).
module sprc_study_partition
   use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_char
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_core_timer, only: timer_type
   use sprc_geometry_region, only: cell_inside
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_grid_share, only: share_type, split_by_work
   use sprc_grid_quadrature, only: cut_quadrature_type
   use sprc_fem_sparse, only: csr_type
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_fem_linear_solver, only: backend_error, message_length, solve_ranks, solver_direct
   implicit none
   private

   public :: partition_type, start_partition, owned_rows, cut_cell_work
   public :: integrate_level, solve_level, largest_over_ranks, fail_together, assemble_pair_rows

   !> This process's place among the ranks of a partitioned level (rank 0 of
   !> 1: serial).
   type, extends(share_type) :: partition_type
      !> When false, every rank does the whole level's per-cell work (only the solve
      !> is distributed), as chosen by SPRC_PARTITION=0 in the environment; the
      !> test that the shared-out level gives the same bits compares the two.
      logical :: split = .true.
   contains
      procedure :: gather => gather_real
      procedure :: shared
   end type partition_type

   !> Quadrature work of a cut cell in units of an inside cell's (whose tensor
   !> rule is only counted, then generated when the points are gathered): the
   !> ratio of `cell_rule`'s times on the 3D sphere octant, where cut cells
   !> weigh most (doc/benchmarks.md).
   integer, parameter :: cut_cell_work = 5

   interface
      integer(c_int) function sprc_mpi_ranks(rank, size, msg, len) bind(c)
         import :: c_int, c_int64_t, c_char
         integer(c_int), intent(out) :: rank, size
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_mpi_ranks

      integer(c_int) function sprc_mpi_gather_double(send, count, recv, counts, size, msg, len) bind(c)
         import :: c_int, c_int64_t, c_double, c_char
         real(c_double), intent(in) :: send(*)
         integer(c_int64_t), value :: count
         real(c_double), intent(inout) :: recv(*)
         integer(c_int64_t), intent(in) :: counts(*)
         integer(c_int), value :: size
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_mpi_gather_double

      integer(c_int) function sprc_mpi_fail_together(seconds) bind(c)
         import :: c_int, c_double
         real(c_double), value :: seconds
      end function sprc_mpi_fail_together

      integer(c_int) function sprc_mpi_gather_int(send, count, recv, counts, size, msg, len) bind(c)
         import :: c_int, c_int32_t, c_int64_t, c_char
         integer(c_int32_t), intent(in) :: send(*)
         integer(c_int64_t), value :: count
         integer(c_int32_t), intent(inout) :: recv(*)
         integer(c_int64_t), intent(in) :: counts(*)
         integer(c_int), value :: size
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_mpi_gather_int
   end interface

contains

   !> The ranks of this run: several only when the solves are distributed
   !> (`solve_ranks` > 1, set by sprc_fem_petsc's `start_ranks` under mpirun).
   subroutine start_partition(part, error)
      type(partition_type), intent(out) :: part
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      character(len=8) :: choice
      integer(c_int) :: status, r, s
      integer :: length, env_status

      if (solve_ranks <= 1) return
      call get_environment_variable('SPRC_PARTITION', choice, length, env_status)
      part%split = .not. (env_status == 0 .and. choice == '0')
      msg = ''
      status = sprc_mpi_ranks(r, s, msg, int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
      if (allocated(error)) return
      part%rank = r
      part%ranks = s
   end subroutine start_partition

   !> Whether the level's per-cell work is shared out (several ranks, `split`).
   pure logical function shared(self)
      class(partition_type), intent(in) :: self
      shared = self%ranks > 1 .and. self%split
   end function shared

   !> The reduced rows [lo, hi] of rank `rank` of `ranks`: those of a
   !> contiguous range of whole master blocks (`dof(c, m)`, numbered master by
   !> master), the blocks split evenly. Empty (hi < lo) for a rank without blocks.
   pure function owned_rows(dof, rank, ranks) result(rows)
      integer, intent(in) :: dof(:, :), rank, ranks
      integer :: rows(2)
      integer :: m_first, m_last

      m_first = int(int(size(dof, 2), i8)*rank/ranks)
      m_last = int(int(size(dof, 2), i8)*(rank + 1)/ranks)
      rows(1) = count(dof(:, 1:m_first) > 0) + 1
      rows(2) = count(dof(:, 1:m_last) > 0)
   end function owned_rows

   !> The cut-cell quadrature of the level (`mesh%integrate`): with several
   !> ranks each computes its range of leaves and the points are gathered in
   !> leaf order; t_quadrature counts both.
   subroutine integrate_level(part, mesh, quad, error)
      type(partition_type), intent(in) :: part
      type(cut_mesh_type), intent(inout) :: mesh
      type(cut_quadrature_type), intent(in) :: quad
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer
      integer, allocatable :: first(:)

      if (.not. part%shared()) then
         call mesh%integrate(quad, error)
         return
      end if
      call timer%start()
      first = split_by_work(merge(1, cut_cell_work, mesh%grid%leaf_class == cell_inside), part%ranks)
      call mesh%integrate(quad, error, [first(part%rank + 1), first(part%rank + 2) - 1])
      call part%agree('the cut-cell quadrature', error)
      if (.not. allocated(error)) call gather_points(part, first, mesh, error)
      call timer%stop()
      mesh%t_quadrature = timer%elapsed
   end subroutine integrate_level

   !> Assemble, solve and expand the solution of a body not in contact (`problem%solve`):
   !> with several ranks each assembles and keeps its rows (`owned_rows`,
   !> `keep_rows`; t_assembly counts both), the iterative solve is distributed
   !> and its solution gathered to every rank. A failure on any rank is an
   !> error on all of them.
   subroutine solve_level(part, problem, error)
      type(partition_type), intent(in) :: part
      type(elasticity_problem_type), intent(inout) :: problem
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer
      real(wp), allocatable :: ubar(:)
      integer(i8) :: bounds(part%ranks + 1)
      integer :: r, rows(2)

      if (.not. part%shared()) then
         call problem%solve(error)
         return
      end if
      if (problem%solver == solver_direct) then
         call fatal_error(error, 'solver = ''direct'' under mpirun with '//itoa(part%ranks)//' ranks: the direct '// &
            & 'solvers need the whole stiffness on one rank, and each rank holds only its rows; use solver = '// &
            & '''iterative'' or ''auto'', or run the direct solve without mpirun', stat_invalid_input)
         return
      end if
      do r = 0, part%ranks - 1
         rows = owned_rows(problem%constraints%dof, r, part%ranks)
         bounds(r + 1) = rows(1)
      end do
      bounds(part%ranks + 1) = problem%n_dofs() + 1
      rows = owned_rows(problem%constraints%dof, part%rank, part%ranks)
      call problem%assemble(error, rows)
      call timer%start()
      if (.not. allocated(error)) call keep_rows(rows, problem%k, problem%f, error)
      call timer%stop()
      problem%t_assembly = problem%t_assembly + timer%elapsed
      call part%agree('the assembly', error)
      if (allocated(error)) return
      if (allocated(problem%rows_share)) deallocate (problem%rows_share)
      allocate (problem%rows_share, source=part)
      problem%row_bounds = bounds
      call problem%solve_reduced(error)
      call part%agree('the solve', error)
      if (allocated(error)) return
      ! Rows of K serve no one after the distributed solve: their room goes to the recovery.
      deallocate (problem%k%rowptr, problem%k%col, problem%k%val, problem%f)
      ! set_solution takes a copy: its argument may not be the problem's own ubar
      ubar = problem%ubar
      call problem%set_solution(ubar, error)
   end subroutine solve_level

   !> The rows of a contact pair's block system (the slave's reduced unknowns,
   !> then the master's) shared out as its distributed solve shares them:
   !> rank r owns the rows of the masters r B/R .. (r + 1) B/R - 1 of the B
   !> masters of both bodies in that order (`owned_rows` on the pair's block
   !> layout, `sprc_petsc_own_blocks`). Each rank assembles and keeps only
   !> its rows of each body (`keep_rows`, possibly none of one body);
   !> bounds(r + 1) is rank r's first row of the block system, bounds(R + 1)
   !> its order plus one. A failure on any rank is an error on all of them.
   subroutine assemble_pair_rows(part, slave, master, bounds, error)
      type(partition_type), intent(in) :: part
      type(elasticity_problem_type), intent(inout) :: slave, master
      integer(i8), allocatable, intent(out) :: bounds(:)
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer
      integer, allocatable :: dof(:, :)
      integer :: r, ns, rows(2), rs(2), rm(2)

      ns = slave%n_dofs()
      associate (cs => slave%constraints, cm => master%constraints)
         dof = reshape([cs%dof, merge(cm%dof + ns, 0, cm%dof > 0)], [slave%dim, cs%n_masters + cm%n_masters])
      end associate
      allocate (bounds(part%ranks + 1))
      do r = 0, part%ranks - 1
         rows = owned_rows(dof, r, part%ranks)
         bounds(r + 1) = rows(1)
      end do
      bounds(part%ranks + 1) = ns + master%n_dofs() + 1
      rows = owned_rows(dof, part%rank, part%ranks)
      ! the slave's rows lo..min(hi, ns), the master's those above ns; an empty range as [lo, lo - 1]
      rs = [min(rows(1), ns + 1), min(rows(2), ns)]
      rm = [max(rows(1), ns + 1) - ns, max(rows(2) - ns, max(rows(1), ns + 1) - ns - 1)]
      call slave%assemble(error, rs)
      if (.not. allocated(error)) call master%assemble(error, rm)
      call timer%start()
      if (.not. allocated(error)) call keep_rows(rs, slave%k, slave%f, error)
      if (.not. allocated(error)) call keep_rows(rm, master%k, master%f, error)
      call timer%stop()
      slave%t_assembly = slave%t_assembly + timer%elapsed
      call part%agree('the contact pair''s assembly', error)
   end subroutine assemble_pair_rows

   !> Whether every rank calls this within `seconds`, as after a failure that
   !> all of them know of (`agree`); false when this rank failed alone (the
   !> others wait in a collective it will not enter): the driver then ends
   !> the run on every rank. True in a serial run.
   logical function fail_together(seconds)
      real(wp), intent(in) :: seconds
      fail_together = sprc_mpi_fail_together(real(seconds, c_double)) /= 0
   end function fail_together

   !> The largest `value` over the ranks (every rank calls it; with one rank,
   !> `value`).
   subroutine largest_over_ranks(part, value, top, error)
      type(partition_type), intent(in) :: part
      real(wp), intent(in) :: value
      real(wp), intent(out) :: top
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: all(part%ranks)

      top = value
      if (part%ranks <= 1) return
      call part%gather([value], spread(1_i8, 1, part%ranks), all, error)
      if (.not. allocated(error)) top = maxval(all)
   end subroutine largest_over_ranks

   !> The points and fractions of every rank's leaves (`first`, as `split_by_work`
   !> gave them) gathered in leaf order into `mesh`.
   subroutine gather_points(part, first, mesh, error)
      type(partition_type), intent(in) :: part
      integer, intent(in) :: first(:)
      type(cut_mesh_type), intent(inout) :: mesh
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: nvol(:), nsurf(:), vol_ptr(:), surf_ptr(:), surf_shape(:)
      real(wp), allocatable :: vol_x(:, :), vol_w(:), surf_x(:, :), surf_w(:), surf_n(:, :), fraction(:)
      integer(i8) :: cells(part%ranks), nv(part%ranks), ns(part%ranks)
      integer :: lo, hi, n, d, r, e, stat
      character(len=*), parameter :: who = 'partitioned quadrature'

      n = mesh%grid%n_leaves
      d = mesh%grid%dim
      lo = first(part%rank + 1)
      hi = first(part%rank + 2) - 1
      cells = int(first(2:) - first(:part%ranks), i8)
      allocate (nvol(n), nsurf(n), vol_ptr(n + 1), surf_ptr(n + 1), fraction(n), stat=stat)
      call check_allocation(stat, who, 'the point counts of the leaves', n, 28, error)
      if (allocated(error)) return
      call gather_int(part, mesh%vol_ptr(lo + 1:hi + 1) - mesh%vol_ptr(lo:hi), cells, nvol, error)
      if (.not. allocated(error)) &
         & call gather_int(part, mesh%surf_ptr(lo + 1:hi + 1) - mesh%surf_ptr(lo:hi), cells, nsurf, error)
      if (.not. allocated(error)) call part%gather(mesh%fraction(lo:hi), cells, fraction, error)
      if (allocated(error)) return
      vol_ptr(1) = 1
      surf_ptr(1) = 1
      do e = 1, n
         vol_ptr(e + 1) = vol_ptr(e) + nvol(e)
         surf_ptr(e + 1) = surf_ptr(e) + nsurf(e)
      end do
      do r = 1, part%ranks
         nv(r) = vol_ptr(first(r + 1)) - vol_ptr(first(r))
         ns(r) = surf_ptr(first(r + 1)) - surf_ptr(first(r))
      end do
      allocate (vol_x(d, vol_ptr(n + 1) - 1), vol_w(vol_ptr(n + 1) - 1), stat=stat)
      call check_allocation(stat, who, 'the volume points', vol_ptr(n + 1) - 1, 8*(d + 1), error)
      if (allocated(error)) return
      allocate (surf_x(d, surf_ptr(n + 1) - 1), surf_w(surf_ptr(n + 1) - 1), surf_n(d, surf_ptr(n + 1) - 1), &
         & surf_shape(surf_ptr(n + 1) - 1), stat=stat)
      call check_allocation(stat, who, 'the surface points', surf_ptr(n + 1) - 1, 8*(2*d + 1) + 4, error)
      if (allocated(error)) return
      associate (v0 => mesh%vol_ptr(lo), v1 => mesh%vol_ptr(hi + 1) - 1, s0 => mesh%surf_ptr(lo), &
         & s1 => mesh%surf_ptr(hi + 1) - 1)
         call part%gather(mesh%vol_x(:, v0:v1), d*nv, vol_x, error)
         if (.not. allocated(error)) call part%gather(mesh%vol_w(v0:v1), nv, vol_w, error)
         if (.not. allocated(error)) call part%gather(mesh%surf_x(:, s0:s1), d*ns, surf_x, error)
         if (.not. allocated(error)) call part%gather(mesh%surf_w(s0:s1), ns, surf_w, error)
         if (.not. allocated(error)) call part%gather(mesh%surf_n(:, s0:s1), d*ns, surf_n, error)
         if (.not. allocated(error)) call gather_int(part, mesh%surf_shape(s0:s1), ns, surf_shape, error)
      end associate
      if (allocated(error)) return
      call move_alloc(vol_ptr, mesh%vol_ptr)
      call move_alloc(surf_ptr, mesh%surf_ptr)
      call move_alloc(vol_x, mesh%vol_x)
      call move_alloc(vol_w, mesh%vol_w)
      call move_alloc(surf_x, mesh%surf_x)
      call move_alloc(surf_w, mesh%surf_w)
      call move_alloc(surf_n, mesh%surf_n)
      call move_alloc(surf_shape, mesh%surf_shape)
      call move_alloc(fraction, mesh%fraction)
   end subroutine gather_points

   !> Only the rows [lo, hi] = `rows` of k and f are kept: the other rows of k
   !> emptied (k keeps its order, its row starts cover all rows), of f zeroed.
   subroutine keep_rows(rows, k, f, error)
      integer, intent(in) :: rows(2)
      type(csr_type), intent(inout) :: k
      real(wp), intent(inout) :: f(:)
      type(error_type), allocatable, intent(out) :: error
      type(csr_type) :: mine
      integer(i8) :: first, nnz
      integer :: lo, hi, stat

      lo = rows(1)
      hi = max(rows(2), lo - 1)
      first = k%rowptr(lo)
      nnz = k%rowptr(hi + 1) - first
      mine%nrows = k%nrows
      mine%ncols = k%ncols
      allocate (mine%rowptr(k%nrows + 1), mine%col(nnz), mine%val(nnz), stat=stat)
      call check_allocation(stat, 'partitioned assembly', 'the owned rows of K', nnz, 12, error)
      if (allocated(error)) return
      mine%rowptr(1:lo) = 1
      mine%rowptr(lo + 1:hi + 1) = k%rowptr(lo + 1:hi + 1) - first + 1
      mine%rowptr(hi + 2:) = nnz + 1
      mine%col = k%col(first:first + nnz - 1)
      mine%val = k%val(first:first + nnz - 1)
      f(:lo - 1) = 0.0_wp
      f(hi + 1:) = 0.0_wp
      call move_alloc(mine%rowptr, k%rowptr)
      call move_alloc(mine%col, k%col)
      call move_alloc(mine%val, k%val)
   end subroutine keep_rows

   !> all = the `local` arrays of the ranks concatenated in rank order (counts(r)
   !> values from rank r - 1; `local` has this rank's count).
   subroutine gather_real(self, local, counts, all, error)
      class(partition_type), intent(in) :: self
      real(wp), intent(in) :: local(*)
      integer(i8), intent(in) :: counts(:)
      real(wp), intent(inout) :: all(*)
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status

      msg = ''
      status = sprc_mpi_gather_double(local, counts(self%rank + 1), all, counts, int(self%ranks, c_int), msg, &
         & int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
   end subroutine gather_real

   !> `gather_real` for integers.
   subroutine gather_int(part, local, counts, all, error)
      type(partition_type), intent(in) :: part
      integer, intent(in) :: local(*)
      integer(i8), intent(in) :: counts(:)
      integer, intent(inout) :: all(*)
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status

      msg = ''
      status = sprc_mpi_gather_int(local, counts(part%rank + 1), all, counts, int(part%ranks, c_int), msg, &
         & int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
   end subroutine gather_int

end module sprc_study_partition
