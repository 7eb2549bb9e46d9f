!> Iterative solver for the reduced elasticity system: PETSc's conjugate
!> gradients (GMRES when the system is not symmetric), through the C shim
!> src/shim/sprc_petsc.c, preconditioned by geometric multigrid on the grid's
!> node lattice (`set_lattice`, `sprc_fem_multigrid`: PCMG with Galerkin
!> coarse matrices) or on the caller's prolongations (`set_hierarchy`, also
!> on several MPI ranks) or, without either and with a lattice on several
!> ranks, by smoothed-aggregation algebraic multigrid (GAMG) with the
!> rigid-body near-null space.
!>
!> Blocks. GAMG aggregates whole nodes (block size = dim) and interpolates the
!> rigid-body modes exactly, so it needs each unknown's node and component.
!> The reduced unknowns of `sprc_fem_constraints` are nodal values: the pair
!> (master node m, component c) is unknown `dof(c, m)`, numbered master by
!> master, and a hanging or aggregated node is a combination of masters,
!> u_slave = sum_k t_k u_master_k. Hanging-node and aggregation constraints
!> interpolate linear fields exactly, so a rigid mode r(x) = a + W x of the
!> whole grid is T applied to r evaluated at the masters: the near-null space
!> of the reduced system is the rigid modes at the master nodes' coordinates
!> (what MatNullSpaceCreateRigidBody builds from them), with no term from the
!> eliminated nodes. A component fixed at zero by a strong symmetry plane is
!> not an unknown; it keeps its place in its node's block as an identity row
!> (scaled to the mean diagonal, right-hand side 0, solution 0) so every block
!> has dim rows; its rigid-mode entry is a harmless extra in the prolongation.
!>
!> Factorize is the multigrid setup, solve a Krylov solve per right-hand side.
!> There is no condition estimate (`rcond_tol` is set to 0 by `set_blocks`).
!> PETSc's indices are 32-bit in Debian's build: larger systems are refused.
module sprc_fem_petsc
   use, intrinsic :: iso_c_binding, only: c_ptr, c_null_ptr, c_associated, c_int, c_int32_t, c_int64_t, &
      & c_double, c_char, c_loc
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_unsupported
   use sprc_core_blas_threads, only: blas_serial_begin, blas_serial_end
   use sprc_core_alloc, only: check_allocation
   use sprc_fem_sparse, only: csr_type
   use sprc_core_sort, only: sort_pairs
   use sprc_fem_linear_solver, only: linear_solver_type, backend_error, message_length, set_solve_ranks, solve_ranks
   use sprc_fem_multigrid, only: prolongation_type, lattice_hierarchy
   implicit none
   private

   public :: petsc_solver_type, iteration_tolerance, start_ranks, start_petsc

   !> Krylov solver with GAMG (module notes). Set the blocks (`set_blocks`)
   !> before `factorize`; `tolerance`, `max_iterations` and `symmetric` are
   !> settings, `iterations` and `residual_bound` results.
   type, extends(linear_solver_type) :: petsc_solver_type
      private
      type(c_ptr) :: handle = c_null_ptr
      integer :: dim = 0, n_padded = 0
      !> Position (1-based) of each reduced unknown in the padded, blocked system.
      integer, allocatable :: slot(:)
      !> Coordinates of each block's node, dim values per block.
      real(wp), allocatable :: coords(:)
      !> Grid lattice coordinates of each block's node (dim, blocks) and the
      !> node step (`set_lattice`): geometric multigrid when allocated.
      integer, allocatable :: lattice(:, :)
      integer :: step = 0
      !> Prolongations given by the caller (`set_hierarchy`): built once,
      !> used by every `factorize` until the next `set_blocks`.
      type(prolongation_type), allocatable :: hierarchy(:)
      !> True when the last `factorize` set up geometric multigrid (false: GAMG).
      logical, public :: multigrid = .false.
      !> The blocked matrix in 0-based CSR (`padded_csr`), this rank's rows
      !> only. On one rank it is PETSc's matrix itself, so it lives until `destroy`.
      integer(c_int32_t), allocatable :: rowptr(:), col(:)
      real(wp), allocatable :: val(:)
      !> Where each entry of the factorized matrix (its CSR order) sits in
      !> `val` (one rank only; `update`), and the `symmetric` it was set up with.
      integer(i8), allocatable :: entry(:)
      logical :: setup_symmetric = .true.
      !> Bound of the relative energy norm of the iteration error (CG; see
      !> energy_test in the shim) at which a solve stops.
      real(wp), public :: tolerance = 1.0e-8_wp
      integer, public :: max_iterations = 1000
      !> False: GMRES instead of CG (an unsymmetric system).
      logical, public :: symmetric = .true.
      !> Krylov iterations of all solves since `factorize`.
      integer, public :: iterations = 0
      !> The stopping quantity reached by the last solve (<= tolerance).
      real(wp), public :: residual_bound = 0.0_wp
      !> Where the Krylov iteration starts (reduced unknowns, order n; nested
      !> iteration: another grid's solution), for every one-column solve while
      !> allocated with that order; otherwise x = 0. The stopping test does
      !> not depend on the start.
      real(wp), allocatable, public :: guess(:)
   contains
      procedure :: set_blocks
      procedure :: set_lattice
      procedure :: set_hierarchy
      procedure :: update
      procedure :: factorize_backend => petsc_factorize
      procedure :: solve_backend => petsc_solve
      procedure :: destroy_backend => petsc_destroy
   end type petsc_solver_type

   !> The multigrid hierarchy as the shim takes it (sprc_petsc_levels).
   type, bind(c) :: petsc_levels_type
      integer(c_int) :: n_levels = 0
      type(c_ptr) :: n_coarse = c_null_ptr, rowptr = c_null_ptr, col = c_null_ptr, val = c_null_ptr
   end type petsc_levels_type

   interface
      integer(c_int) function sprc_petsc_setup(handle, n, dim, rowptr, col, val, coords, levels, symmetric, &
            & borrowed, msg, len) bind(c)
         import :: c_ptr, c_int, c_int32_t, c_int64_t, c_double, c_char, petsc_levels_type
         type(c_ptr), intent(out) :: handle
         integer(c_int64_t), value :: n
         integer(c_int), value :: dim
         integer(c_int32_t), intent(in) :: rowptr(*), col(*)
         real(c_double), intent(in) :: val(*), coords(*)
         type(petsc_levels_type), intent(in) :: levels
         integer(c_int), value :: symmetric
         integer(c_int), intent(out) :: borrowed
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_petsc_setup

      integer(c_int) function sprc_petsc_solve(handle, n, b, x, guess, tau, max_it, iterations, bound, msg, len) &
            & bind(c)
         import :: c_ptr, c_int, c_int64_t, c_double, c_char
         type(c_ptr), value :: handle
         integer(c_int64_t), value :: n
         real(c_double), intent(in) :: b(*)
         real(c_double), intent(inout) :: x(*)
         integer(c_int), value :: guess
         real(c_double), value :: tau
         integer(c_int), value :: max_it
         integer(c_int), intent(out) :: iterations
         real(c_double), intent(out) :: bound
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_petsc_solve

      integer(c_int) function sprc_petsc_start(msg, len) bind(c)
         import :: c_int, c_int64_t, c_char
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_petsc_start

      integer(c_int) function sprc_petsc_ranks(rank, size, msg, len) bind(c)
         import :: c_int, c_int64_t, c_char
         integer(c_int), intent(out) :: rank, size
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_petsc_ranks

      subroutine sprc_petsc_own_blocks(blocks, first, last) bind(c)
         import :: c_int64_t
         integer(c_int64_t), value :: blocks
         integer(c_int64_t), intent(out) :: first, last
      end subroutine sprc_petsc_own_blocks

      integer(c_int) function sprc_petsc_update(handle, msg, len) bind(c)
         import :: c_ptr, c_int, c_int64_t, c_char
         type(c_ptr), value :: handle
         character(kind=c_char), intent(inout) :: msg(*)
         integer(c_int64_t), value :: len
      end function sprc_petsc_update

      integer(c_int) function sprc_petsc_multigrid(handle) bind(c)
         import :: c_ptr, c_int
         type(c_ptr), value :: handle
      end function sprc_petsc_multigrid

      subroutine sprc_petsc_free(handle) bind(c)
         import :: c_ptr
         type(c_ptr), intent(inout) :: handle
      end subroutine sprc_petsc_free
   end interface

contains

   !> This process's `rank` (0-based) among `size` MPI ranks. Under Open MPI's
   !> mpirun with several ranks (OMPI_COMM_WORLD_SIZE > 1) PETSc and MPI are
   !> started here, before any solve, and every later iterative solve is
   !> distributed over the ranks (`solve_ranks`); otherwise nothing is loaded
   !> and the run is serial: rank 0 of 1.
   subroutine start_ranks(rank, size, error)
      integer, intent(out) :: rank, size
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      character(len=16) :: text
      integer(c_int) :: status, r, s
      integer :: length, env_status, ranks, io

      rank = 0
      size = 1
      call get_environment_variable('OMPI_COMM_WORLD_SIZE', text, length, env_status)
      if (env_status /= 0) return
      read (text, *, iostat=io) ranks
      if (io /= 0 .or. ranks <= 1) return
      msg = ''
      status = sprc_petsc_ranks(r, s, msg, int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
      if (allocated(error)) return
      rank = r
      size = s
      call set_solve_ranks(size)
   end subroutine start_ranks

   !> Loads and starts PETSc now (once per process; nothing happens when it is
   !> up already). PETSc is loaded on first use (a serial run that never solves
   !> iteratively loads nothing); the elasticity solve calls this before its
   !> timer starts, since the start-up is a cost of the process, like the
   !> loading of the linked libraries, not of the first iterative solve.
   subroutine start_petsc(error)
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status
      msg = ''
      status = sprc_petsc_start(msg, int(len(msg), c_int64_t))
      call backend_error(status, msg, error)
   end subroutine start_petsc

   !> Stopping tolerance tied to the discretization: the iteration error in the
   !> energy norm, relative to the solution's, at most 1e-7 (h/L)^p (h the
   !> finest cell, L the grid box, p the element degree), and not below 1e-12
   !> (round-off of the solve itself, ~eps sqrt(cond K)). The FE energy error
   !> of a field that is not a polynomial of degree p is at least of order
   !> 0.1 (h/L)^p relative (a priori estimate c h^p |u|_(p+1) with its
   !> constant seldom below 0.1 on these bodies), so the iteration moves each
   !> error and estimate of the report by about 1e-6 of its size or less: the
   !> first six digits are the direct solve's. The FE error itself moves
   !> only at second order (Galerkin orthogonality: the iteration error is
   !> in the FE space).
   pure real(wp) function iteration_tolerance(h_over_l, degree) result(tau)
      real(wp), intent(in) :: h_over_l
      integer, intent(in) :: degree
      tau = max(1.0e-7_wp*h_over_l**degree, 1.0e-12_wp)
   end function iteration_tolerance

   !> The block layout: `dof(c, m)` is the reduced unknown of component c at
   !> block m (0: the component is fixed at zero), `x(:, m)` that block's node.
   !> Every reduced unknown 1..n must occur exactly once.
   subroutine set_blocks(self, dof, x, error)
      class(petsc_solver_type), intent(inout) :: self
      integer, intent(in) :: dof(:, :)
      real(wp), intent(in) :: x(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: m, c, n, stat

      self%dim = size(dof, 1)
      self%rcond_tol = 0.0_wp
      if (size(x, 1) /= self%dim .or. size(x, 2) /= size(dof, 2) .or. (self%dim /= 2 .and. self%dim /= 3)) then
         call fatal_error(error, 'iterative solver: block layout and coordinates do not match', stat_invalid_input)
         return
      end if
      n = count(dof > 0)
      if (allocated(self%slot)) deallocate (self%slot)
      allocate (self%slot(n), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the place of each unknown', n, 4, error)
      if (allocated(error)) return
      self%slot = 0
      do m = 1, size(dof, 2)
         do c = 1, self%dim
            if (dof(c, m) < 0 .or. dof(c, m) > n) exit
            if (dof(c, m) > 0) self%slot(dof(c, m)) = (m - 1)*self%dim + c
         end do
      end do
      if (any(self%slot == 0) .or. any(dof < 0) .or. any(dof > n)) then
         deallocate (self%slot)
         call fatal_error(error, 'iterative solver: the block layout does not number each unknown once', &
            & stat_invalid_input)
         return
      end if
      self%n_padded = self%dim*size(dof, 2)
      if (allocated(self%coords)) deallocate (self%coords)
      allocate (self%coords(self%n_padded), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the block coordinates', self%n_padded, 8, error)
      if (allocated(error)) then
         deallocate (self%slot)
         return
      end if
      self%coords = reshape(x, [self%n_padded])
      if (allocated(self%lattice)) deallocate (self%lattice)
      if (allocated(self%hierarchy)) deallocate (self%hierarchy)
   end subroutine set_blocks

   !> Geometric multigrid (`sprc_fem_multigrid`) instead of GAMG, after
   !> `set_blocks`: `lattice(:, m)` is block m's node on the grid's node
   !> lattice (`grid_nodes_type%lattice`), `step` the lattice step between
   !> neighbouring nodes of the finest elements (2 for Q1, 1 for Q2). A
   !> distributed solve (several MPI ranks) keeps GAMG.
   subroutine set_lattice(self, lattice, step, error)
      class(petsc_solver_type), intent(inout) :: self
      integer, intent(in) :: lattice(:, :), step
      type(error_type), allocatable, intent(out) :: error

      if (allocated(self%lattice)) deallocate (self%lattice)
      if (size(lattice, 1) /= self%dim .or. size(lattice, 2)*self%dim /= self%n_padded .or. self%dim == 0) then
         call fatal_error(error, 'iterative solver: the lattice points do not match the block layout (set_blocks '// &
            & 'first, one point per block)', stat_invalid_input)
         return
      end if
      self%lattice = lattice
      self%step = step
   end subroutine set_lattice

   !> Geometric multigrid on prolongations the caller built (after
   !> `set_blocks`; `p(1)%n_fine` is the number of blocks), kept for every
   !> later `factorize`: the hierarchy of several bodies in one system
   !> (`stack_hierarchies`), built once and used for each of the systems
   !> that differ in their coupling terms only. A distributed solve takes it
   !> too: each rank's rows of each prolongation (those of its blocks on both
   !> levels, the shim's split) become PETSc's parallel matrices.
   subroutine set_hierarchy(self, p, error)
      class(petsc_solver_type), intent(inout) :: self
      type(prolongation_type), intent(in) :: p(:)
      type(error_type), allocatable, intent(out) :: error

      if (allocated(self%hierarchy)) deallocate (self%hierarchy)
      if (self%dim == 0) then
         call fatal_error(error, 'iterative solver: set_blocks must come before set_hierarchy', stat_invalid_input)
         return
      end if
      if (size(p) > 0) then
         if (p(1)%n_fine*self%dim /= self%n_padded) then
            call fatal_error(error, 'iterative solver: the finest prolongation does not map to the blocks of '// &
               & 'set_blocks', stat_invalid_input)
            return
         end if
      end if
      self%hierarchy = p
   end subroutine set_hierarchy

   subroutine petsc_factorize(self, a, error)
      class(petsc_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status, borrowed
      integer :: saved
      type(prolongation_type), allocatable :: p(:)
      type(petsc_levels_type) :: levels
      integer(c_int32_t), allocatable, target :: n_coarse(:), rowptr(:), col(:)
      real(c_double), allocatable, target :: val(:)

      call petsc_destroy(self)
      self%multigrid = .false.
      if (.not. allocated(self%slot)) then
         call fatal_error(error, 'iterative solver: set_blocks was not called', stat_invalid_input)
         return
      else if (size(self%slot) /= a%nrows) then
         call fatal_error(error, 'iterative solver: the matrix order differs from the block layout''s unknowns', &
            & stat_invalid_input)
         return
      end if
      call padded_csr(self, a, self%rowptr, self%col, self%val, error)
      if (allocated(error)) return
      ! A caller's hierarchy serves distributed solves too (its prolongations
      ! distributed by the shim); a lattice's only one rank, GAMG on several.
      if (allocated(self%hierarchy) .or. (allocated(self%lattice) .and. solve_ranks == 1)) then
         if (allocated(self%hierarchy)) then
            p = self%hierarchy
         else
            call lattice_hierarchy(self%lattice, self%step, p, error)
         end if
         if (allocated(error)) return
         call blocked_levels(p, self%dim, n_coarse, rowptr, col, val, error)
         if (allocated(error)) return
         levels%n_levels = int(size(p), c_int)
         if (size(p) > 0) then
            levels%n_coarse = c_loc(n_coarse)
            levels%rowptr = c_loc(rowptr)
            levels%col = c_loc(col)
            levels%val = c_loc(val)
         end if
      end if
      msg = ''
      saved = blas_serial_begin()
      status = sprc_petsc_setup(self%handle, int(self%n_padded, c_int64_t), int(self%dim, c_int), self%rowptr, &
         & self%col, self%val, self%coords, levels, merge(1_c_int, 0_c_int, self%symmetric), borrowed, msg, &
         & int(len(msg), c_int64_t))
      call blas_serial_end(saved)
      if (borrowed == 0 .or. status /= 0) deallocate (self%rowptr, self%col, self%val)
      call backend_error(status, msg, error)
      self%iterations = 0
      if (status /= 0) return
      self%multigrid = sprc_petsc_multigrid(self%handle) /= 0
      self%setup_symmetric = self%symmetric
      if (borrowed /= 0) call entry_map(self, a, error)
   end subroutine petsc_factorize

   !> New values of the matrix of the last `factorize`, `a` with its
   !> pattern: the set-up keeps its symbolic work (the blocked copy's layout,
   !> PETSc's Galerkin products and coarse LU redo only their numeric part).
   !> Another pattern, another `symmetric`, several ranks or nothing set up:
   !> a `factorize`.
   subroutine update(self, a, error)
      class(petsc_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      integer(c_int) :: status
      integer :: saved

      if (.not. same_pattern(self, a)) then
         call self%factorize(a, error)
         return
      end if
      self%val(self%entry) = a%val
      msg = ''
      saved = blas_serial_begin()
      status = sprc_petsc_update(self%handle, msg, int(len(msg), c_int64_t))
      call blas_serial_end(saved)
      call backend_error(status, msg, error)
      self%iterations = 0
      if (allocated(error)) call self%destroy()
   end subroutine update

   !> Whether `a` has the pattern (rows, and columns in their order) of the
   !> matrix set up last on one rank, with the same `symmetric`: each entry
   !> maps by `entry` to its column in its own row of the blocked copy, and
   !> each row has as many entries as that row.
   logical function same_pattern(self, a) result(same)
      class(petsc_solver_type), intent(in) :: self
      type(csr_type), intent(in) :: a
      integer(i8) :: q
      integer :: i, p

      same = c_associated(self%handle) .and. allocated(self%entry) .and. allocated(self%val) .and. &
         & self%factorized .and. (self%symmetric .eqv. self%setup_symmetric) .and. a%nrows == self%n
      if (.not. same) return
      same = size(self%entry, kind=i8) == a%nnz()
      do i = 1, a%nrows
         if (.not. same) return
         p = self%slot(i)
         same = a%rowptr(i + 1) - a%rowptr(i) == int(self%rowptr(p + 1) - self%rowptr(p), i8)
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            if (self%entry(q) <= self%rowptr(p) .or. self%entry(q) > self%rowptr(p + 1)) then
               same = .false.
            else if (self%col(self%entry(q)) /= self%slot(a%col(q)) - 1) then
               same = .false.
            end if
         end do
      end do
   end function same_pattern

   !> `entry` of the blocked copy set up from `a` on one rank (`update`):
   !> each entry's place found in its sorted row.
   subroutine entry_map(self, a, error)
      class(petsc_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: q, lo, hi, mid
      integer :: i, p, stat
      integer(c_int32_t) :: c

      if (allocated(self%entry)) deallocate (self%entry)
      allocate (self%entry(a%nnz()), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the place of each matrix entry', a%nnz(), 8, error)
      if (allocated(error)) return
      do i = 1, a%nrows
         p = self%slot(i)
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            c = int(self%slot(a%col(q)) - 1, c_int32_t)
            lo = self%rowptr(p) + 1
            hi = self%rowptr(p + 1)
            do while (lo < hi)
               mid = (lo + hi)/2
               if (self%col(mid) < c) then
                  lo = mid + 1
               else
                  hi = mid
               end if
            end do
            self%entry(q) = lo
         end do
      end do
   end subroutine entry_map

   !> The scalar prolongations p as the shim takes them: each coarse node a
   !> block of dim unknowns, component c of a block interpolated from
   !> component c of the coarse blocks; 0-based CSR arrays, level after level.
   subroutine blocked_levels(p, dim, n_coarse, rowptr, col, val, error)
      type(prolongation_type), intent(in) :: p(:)
      integer, intent(in) :: dim
      integer(c_int32_t), allocatable, intent(out) :: n_coarse(:), rowptr(:), col(:)
      real(c_double), allocatable, intent(out) :: val(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: l, j, c, q, r, k, rows, nnz, stat

      rows = sum(dim*p%n_fine + 1)
      nnz = 0
      do l = 1, size(p)
         nnz = nnz + dim*(p(l)%rowptr(p(l)%n_fine + 1) - 1)
      end do
      allocate (n_coarse(size(p)), rowptr(rows), col(nnz), val(nnz), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the multigrid prolongations', nnz, 12, error)
      if (allocated(error)) return
      r = 0
      k = 0
      do l = 1, size(p)
         n_coarse(l) = int(dim*p(l)%n_coarse, c_int32_t)
         q = 0
         do j = 1, p(l)%n_fine
            do c = 1, dim
               r = r + 1
               rowptr(r) = int(q, c_int32_t)
               associate (first => p(l)%rowptr(j), last => p(l)%rowptr(j + 1) - 1)
                  col(k + 1:k + last - first + 1) = int(dim*(p(l)%col(first:last) - 1) + c - 1, c_int32_t)
                  val(k + 1:k + last - first + 1) = p(l)%val(first:last)
                  k = k + last - first + 1
                  q = q + last - first + 1
               end associate
            end do
         end do
         r = r + 1
         rowptr(r) = int(q, c_int32_t)
      end do
   end subroutine blocked_levels

   !> This rank's rows of `a` (those of its blocks, `sprc_petsc_own_blocks`:
   !> all on one rank; `a` needs no other rows) in blocked order with identity
   !> rows (the mean diagonal of these rows) at the fixed components; 0-based
   !> 32-bit CSR from 0 with global columns, ascending in each row (as PETSc's
   !> matrix on the arrays needs), refused if PETSc's 32-bit indices cannot hold it.
   subroutine padded_csr(self, a, rowptr, col, val, error)
      class(petsc_solver_type), intent(in) :: self
      type(csr_type), intent(in) :: a
      integer(c_int32_t), allocatable, intent(out) :: rowptr(:), col(:)
      real(wp), allocatable, intent(out) :: val(:)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: row_of(:)
      integer(i8) :: nnz, q, k
      integer(c_int64_t) :: first, last
      integer :: p, i, stat, p0, p1, n_own
      real(wp) :: mean_diag
      character(len=200) :: buf

      call sprc_petsc_own_blocks(int(self%n_padded/self%dim, c_int64_t), first, last)
      p0 = int(first)*self%dim + 1
      p1 = int(last)*self%dim
      allocate (row_of(self%n_padded), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the row of each blocked unknown', self%n_padded, 4, error)
      if (allocated(error)) return
      row_of = 0
      do i = 1, a%nrows
         row_of(self%slot(i)) = i
      end do
      nnz = 0
      n_own = 0
      mean_diag = 0.0_wp
      do p = p0, p1
         i = row_of(p)
         nnz = nnz + 1
         if (i == 0) cycle
         n_own = n_own + 1
         nnz = nnz + a%rowptr(i + 1) - a%rowptr(i) - 1
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            if (a%col(q) == i) mean_diag = mean_diag + abs(a%val(q))
         end do
      end do
      mean_diag = max(mean_diag/real(max(n_own, 1), wp), tiny(1.0_wp))
      if (nnz > int(huge(1_c_int32_t), i8)) then
         write (buf, '("iterative solver: ",i0," nonzeros exceed the 32-bit indices of this PETSc build ", &
            & "(Debian libpetsc-real-dev); use solver = ''direct'' or a PETSc with 64-bit indices")') nnz
         call fatal_error(error, trim(buf), stat_unsupported)
         return
      end if
      allocate (rowptr(p1 - p0 + 2), col(nnz), val(nnz), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the blocked matrix', nnz, 12, error)
      if (allocated(error)) return
      k = 0
      do p = p0, p1
         rowptr(p - p0 + 1) = int(k, c_int32_t)
         i = row_of(p)
         if (i == 0) then
            k = k + 1
            col(k) = int(p - 1, c_int32_t)
            val(k) = mean_diag
            cycle
         end if
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            k = k + 1
            col(k) = int(self%slot(a%col(q)) - 1, c_int32_t)
            val(k) = a%val(q)
         end do
         associate (r0 => rowptr(p - p0 + 1))
            if (any(col(r0 + 2:k) <= col(r0 + 1:k - 1))) call sort_pairs(col(r0 + 1:k), val(r0 + 1:k))
         end associate
      end do
      rowptr(p1 - p0 + 2) = int(k, c_int32_t)
   end subroutine padded_csr

   subroutine petsc_solve(self, n, nrhs, b, x, transposed, error)
      class(petsc_solver_type), intent(inout) :: self
      integer, intent(in) :: n, nrhs
      real(wp), intent(in) :: b(n, nrhs)
      real(wp), intent(out) :: x(n, nrhs)
      logical, intent(in) :: transposed
      type(error_type), allocatable, intent(out) :: error
      character(kind=c_char, len=message_length) :: msg
      real(wp), allocatable :: bp(:), xp(:)
      integer(c_int) :: status, its, start
      integer :: j, saved, stat

      if (transposed .and. .not. self%symmetric) then
         call fatal_error(error, 'iterative solver: transposed solves of an unsymmetric system are not supported', &
            & stat_unsupported)
         return
      end if
      allocate (bp(self%n_padded), xp(self%n_padded), stat=stat)
      call check_allocation(stat, 'iterative solver', 'the blocked right-hand side and solution', self%n_padded, &
         & 16, error)
      if (allocated(error)) return
      do j = 1, nrhs
         bp = 0.0_wp
         bp(self%slot) = b(:, j)
         xp = 0.0_wp
         start = 0_c_int
         if (allocated(self%guess) .and. nrhs == 1) then
            if (size(self%guess) == n) then
               xp(self%slot) = self%guess
               start = 1_c_int
            end if
         end if
         msg = ''
         saved = blas_serial_begin()
         status = sprc_petsc_solve(self%handle, int(self%n_padded, c_int64_t), bp, xp, start, &
            & real(self%tolerance, c_double), int(self%max_iterations, c_int), its, self%residual_bound, msg, &
            & int(len(msg), c_int64_t))
         call blas_serial_end(saved)
         self%iterations = self%iterations + its
         call backend_error(status, msg, error)
         if (allocated(error)) return
         x(:, j) = xp(self%slot)
      end do
   end subroutine petsc_solve

   subroutine petsc_destroy(self)
      class(petsc_solver_type), intent(inout) :: self
      if (c_associated(self%handle)) call sprc_petsc_free(self%handle)
      if (allocated(self%entry)) deallocate (self%entry)
      if (allocated(self%rowptr)) deallocate (self%rowptr)
      if (allocated(self%col)) deallocate (self%col)
      if (allocated(self%val)) deallocate (self%val)
   end subroutine petsc_destroy

end module sprc_fem_petsc
