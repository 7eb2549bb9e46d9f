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
!>   (`sprc_fem_problem`'s `assemble` with `rows`). The owned rows of K and f
!>   are gathered in rank order: the reduced system of every rank is the
!>   serial one, bit for bit (PETSc's stash would add a row's off-rank parts
!>   in an order that is not fixed).
!> - Recovery, estimate and exact error: `sprc_grid_share` (patches and
!>   elements in contiguous ranges, the records and element terms gathered;
!>   partition_type is the share whose gather is MPI's). A scene with
!>   `&contact` keeps them (and its assembly) on the whole level on every rank.
!>
!> What is not partitioned: every rank holds the whole level (grid, points,
!> K, the gathered solution), so the memory per rank is the serial run's
!> plus its share of PETSc's. A serial run (one rank) takes none of these
!> paths: nothing of MPI is loaded. SPRC_PARTITION=0 in the environment keeps
!> every rank on the whole level (`split`).
module sprc_study_partition
   use, intrinsic :: iso_c_binding, only: c_int, c_int32_t, c_int64_t, c_double, c_char
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   use sprc_core_timer, only: timer_type
   use sprc_geometry_region, only: cell_inside
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_grid_share, only: share_type, split_by_work
   use sprc_grid_quadrature, only: cut_quadrature_type
   use sprc_fem_sparse, only: csr_type
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_fem_linear_solver, only: backend_error, message_length, solve_ranks
   implicit none
   private

   public :: partition_type, start_partition, owned_rows, cut_cell_work
   public :: integrate_level, solve_level

   !> This process's place among the ranks of a partitioned level (rank 0 of
   !> 1: serial).
   type, extends(share_type) :: partition_type
      !> False: every rank does the whole level's per-cell work (only the solve
      !> is distributed), as chosen by SPRC_PARTITION=0 in the environment; the
      !> test that the shared-out level gives the same bits compares the two.
      logical :: split = .true.
   contains
      procedure :: gather => gather_real
      procedure :: shared
   end type partition_type

   !> Quadrature work of a cut cell in units of an inside cell's (whose tensor
   !> rule is only counted, then generated when the points are gathered): the
   !> ratio of `cell_rule`'s times measured on the 3D sphere octant (5.2 at
   !> level 6; 2.7 on the 2D Kirsch plate, where cut cells are few).
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
   !> with several ranks each assembles its rows (`owned_rows`) and the rows are
   !> gathered (t_assembly counts both) before the distributed solve.
   subroutine solve_level(part, problem, error)
      type(partition_type), intent(in) :: part
      type(elasticity_problem_type), intent(inout) :: problem
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer
      real(wp), allocatable :: ubar(:)
      integer, allocatable :: rows(:, :)
      integer :: r

      if (.not. part%shared()) then
         call problem%solve(error)
         return
      end if
      allocate (rows(2, 0:part%ranks - 1))
      do r = 0, part%ranks - 1
         rows(:, r) = owned_rows(problem%constraints%dof, r, part%ranks)
      end do
      call problem%assemble(error, rows(:, part%rank))
      call part%agree('the assembly', error)
      if (allocated(error)) return
      call timer%start()
      call gather_rows(part, rows, problem%k, problem%f, error)
      call timer%stop()
      problem%t_assembly = problem%t_assembly + timer%elapsed
      if (allocated(error)) return
      call problem%solve_reduced(error)
      if (allocated(error)) return
      ! set_solution takes a copy: its argument may not be the problem's own ubar
      ubar = problem%ubar
      call problem%set_solution(ubar, error)
   end subroutine solve_level

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

   !> The owned rows of k and f of every rank (`rows(:, r)`) gathered in rank
   !> order: the whole k and f on every rank.
   subroutine gather_rows(part, rows, k, f, error)
      type(partition_type), intent(in) :: part
      integer, intent(in) :: rows(:, 0:)
      type(csr_type), intent(inout) :: k
      real(wp), allocatable, intent(inout) :: f(:)
      type(error_type), allocatable, intent(out) :: error
      type(csr_type) :: all
      integer(i8) :: counts(part%ranks), nnz(part%ranks)
      integer, allocatable :: lens(:)
      real(wp), allocatable :: f_all(:)
      integer :: n, r, i, stat
      character(len=*), parameter :: who = 'partitioned assembly'

      n = k%nrows
      counts = int(max(rows(2, :) - rows(1, :) + 1, 0), i8)
      allocate (lens(n), f_all(n), all%rowptr(n + 1), stat=stat)
      call check_allocation(stat, who, 'the rows of K', n, 20, error)
      if (allocated(error)) return
      associate (lo => rows(1, part%rank), hi => rows(2, part%rank))
         call gather_int(part, int(k%rowptr(lo + 1:hi + 1) - k%rowptr(lo:hi)), counts, lens, error)
         if (.not. allocated(error)) call part%gather(f(lo:hi), counts, f_all, error)
         if (allocated(error)) return
         all%rowptr(1) = 1
         do i = 1, n
            all%rowptr(i + 1) = all%rowptr(i) + lens(i)
         end do
         do r = 0, part%ranks - 1
            nnz(r + 1) = all%rowptr(rows(2, r) + 1) - all%rowptr(rows(1, r))
            if (counts(r + 1) == 0) nnz(r + 1) = 0
         end do
         allocate (all%col(all%rowptr(n + 1) - 1), all%val(all%rowptr(n + 1) - 1), stat=stat)
         call check_allocation(stat, who, 'the entries of K', all%rowptr(n + 1) - 1, 12, error)
         if (allocated(error)) return
         call gather_int(part, k%col(k%rowptr(lo):k%rowptr(hi + 1) - 1), nnz, all%col, error)
         if (.not. allocated(error)) call part%gather(k%val(k%rowptr(lo):k%rowptr(hi + 1) - 1), nnz, &
            & all%val, error)
      end associate
      if (allocated(error)) return
      call move_alloc(all%rowptr, k%rowptr)
      call move_alloc(all%col, k%col)
      call move_alloc(all%val, k%val)
      call move_alloc(f_all, f)
   end subroutine gather_rows

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
