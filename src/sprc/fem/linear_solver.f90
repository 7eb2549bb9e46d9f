!> Sparse direct solvers behind one abstract type: factorize once, solve for
!> many right-hand sides, estimate the reciprocal condition number.
!>
!> The public operations (`factorize`, `solve`, `rcond`, `destroy`) are
!> implemented here once: they check arguments and state, handle the empty
!> matrix, and detect numerical singularity. A back end (CHOLMOD, UMFPACK)
!> only supplies the three deferred `*_backend` bindings, which the public
!> operations call with checked arguments. Status codes coming back from the
!> C shim become an `error_type` in one place, `backend_error`.
!>
!> Objects own C memory through a handle: call `destroy` when done, and do not
!> copy a factorized solver by assignment (both copies would share one factor).
module sprc_fem_linear_solver
   use, intrinsic :: iso_c_binding, only: c_char, c_null_char, c_int
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular, &
      & stat_not_positive_definite, stat_not_converged, stat_out_of_memory, stat_internal
   use sprc_core_lapack, only: dlacn2
   use sprc_core_blas_threads, only: blas_threads, set_blas_threads
   use sprc_fem_sparse, only: csr_type, csr_validate
   use sprc_core_alloc, only: check_allocation
   implicit none
   private

   public :: linear_solver_type, backend_error, message_length, blas_threads, set_blas_threads
   public :: solver_auto, solver_direct, solver_iterative, solver_names, solver_choice, use_iterative, &
      & auto_iterative_min_dofs, auto_coupled_iterative_min_dofs, auto_never, solve_ranks, set_solve_ranks

   !> The scene's `solver`: 'auto', 'direct' (CHOLMOD, UMFPACK) or 'iterative'
   !> (Krylov + multigrid, `sprc_fem_petsc`, `sprc_fem_multigrid`); codes in `solver_names` order.
   integer, parameter :: solver_auto = 1, solver_direct = 2, solver_iterative = 3
   !> The names of the solver codes, blank-separated, in code order.
   character(len=*), parameter :: solver_names = 'auto direct iterative'

   !> 'auto''s table: a system of dimension `dim` (2, 3) and element degree
   !> `degree` (1, 2) is solved iteratively from `auto_min_dofs(dim, degree)`
   !> unknowns on, directly below (`auto_never`: always directly). Each entry
   !> is a crossover of the two solve times (doc/benchmarks.md, "Linear
   !> solvers"); re-tune here
   !> when either solver changes. 2D stays direct (CHOLMOD's fill is mild
   !> there); so does Q2 in 3D, where GAMG needs ~200 iterations.
   integer, parameter :: auto_never = huge(1)
   integer, parameter :: auto_min_dofs(2:3, 1:2) = reshape([auto_never, 25000, auto_never, auto_never], [2, 2])
   !> The same for the coupled system of bodies in contact (sprc_contact_pair_solve,
   !> both bodies' unknowns): its iterative solve sets up the multigrid once
   !> per active-set iteration with the contact surface on the coarsest
   !> level, and its tolerance is tighter (pointwise pressures), so the
   !> crossover lies higher (doc/benchmarks.md: the Hertz sphere, even at
   !> 17.5k unknowns, iterative faster at 128k; the compound sphere, one
   !> active set, direct faster at 96k).
   integer, parameter :: auto_coupled_min_dofs(2:3, 1:2) = reshape([auto_never, 100000, auto_never, auto_never], &
      & [2, 2])

   !> MPI ranks the iterative solves are distributed over (`mpirun -n R`,
   !> sprc_fem_petsc's `start_ranks`); 1 in a serial run. With several ranks
   !> 'auto' solves every system iteratively: the direct solvers run on one
   !> rank only, so they would be repeated on each.
   integer, protected :: solve_ranks = 1

   !> Length of the message buffer the C shim fills.
   integer, parameter :: message_length = 512

   !> A direct solver for A x = b with A square and sparse (`csr_type`).
   !>
   !> After a successful `factorize`, `n`, `factor_nnz`, `peak_bytes`,
   !> `pivot_ratio` and `rcond_estimate` describe the factor; treat them as
   !> read-only. `rcond_tol` is a setting.
   type, abstract :: linear_solver_type
      !> Order of the factored matrix (0 when nothing is factored).
      integer :: n = 0
      !> True between a successful `factorize` and `destroy`.
      logical :: factorized = .false.
      !> Nonzeros of the factor(s) as the back end counts them, -1 if unknown.
      integer(i8) :: factor_nnz = -1
      !> Peak memory of the back end during factorize [bytes], -1 if unknown.
      integer(i8) :: peak_bytes = -1
      !> Smallest over largest pivot magnitude, as the back end measures it.
      !> Informative only: for a singular matrix it is rounding noise that
      !> grows with the order, so `rcond_tol` decides singularity instead.
      real(wp) :: pivot_ratio = 0.0_wp
      !> Reciprocal 1-norm condition estimate made by `factorize` (-1 when
      !> `rcond_tol <= 0` skipped it).
      real(wp) :: rcond_estimate = -1.0_wp
      !> `factorize` reports `stat_singular` when the reciprocal condition
      !> estimate is below `rcond_tol`. For a singular matrix the factor is
      !> exact for a nearby matrix A + E with ||E|| a small multiple of eps
      !> ||A||, so the estimate comes out as a fraction of eps (1e-19..3e-17
      !> for floating elasticity systems of 50 to 15000 unknowns); eps itself
      !> (MATLAB's threshold too) accepts every cond_1 below 4.5e15. Costs
      !> about five solves; set 0 to skip the check.
      real(wp) :: rcond_tol = epsilon(1.0_wp)
   contains
      !> `factorize(a, error)`: factor `a`, replacing any previous factor.
      procedure :: factorize
      procedure, private :: solve_one, solve_many
      !> `solve(b, x, error [, transposed])` with `b(n)`, `x(n)` or `b(n, nrhs)`,
      !> `x(n, nrhs)`; solves A^T x = b when `transposed` is true. `b` and `x`
      !> must not be the same array.
      generic :: solve => solve_one, solve_many
      !> `rcond(a, value, error)`: reciprocal 1-norm condition estimate.
      procedure :: rcond
      !> `destroy()`: release the factor; harmless when repeated.
      procedure :: destroy
      !> Back end: factor a validated square `a` of order >= 1 and set
      !> `factor_nnz`, `peak_bytes`, `pivot_ratio`. Called by `factorize` only.
      procedure(factorize_interface), deferred :: factorize_backend
      !> Back end: solve with the current factor for `nrhs >= 1` columns.
      !> Called by `solve` and `rcond` only.
      procedure(solve_interface), deferred :: solve_backend
      !> Back end: release C resources; must accept an object that has none.
      procedure(destroy_interface), deferred :: destroy_backend
   end type linear_solver_type

   abstract interface
      subroutine factorize_interface(self, a, error)
         import :: linear_solver_type, csr_type, error_type
         class(linear_solver_type), intent(inout) :: self
         type(csr_type), intent(in) :: a
         type(error_type), allocatable, intent(out) :: error
      end subroutine factorize_interface

      subroutine solve_interface(self, n, nrhs, b, x, transposed, error)
         import :: linear_solver_type, error_type, wp
         class(linear_solver_type), intent(inout) :: self
         integer, intent(in) :: n, nrhs
         real(wp), intent(in) :: b(n, nrhs)
         real(wp), intent(out) :: x(n, nrhs)
         logical, intent(in) :: transposed
         type(error_type), allocatable, intent(out) :: error
      end subroutine solve_interface

      subroutine destroy_interface(self)
         import :: linear_solver_type
         class(linear_solver_type), intent(inout) :: self
      end subroutine destroy_interface
   end interface

contains

   !> Factor the square matrix `a`. On failure nothing stays factored:
   !> `stat_not_positive_definite` (CHOLMOD: a pivot <= 0, named by column),
   !> `stat_singular` (a zero pivot, or `rcond_estimate < rcond_tol`),
   !> `stat_invalid_input` (not square, broken CSR), `stat_out_of_memory`.
   subroutine factorize(self, a, error)
      class(linear_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      character(len=128) :: buf

      call self%destroy()
      call csr_validate(a, 'factorize', error)
      if (allocated(error)) return
      if (a%nrows /= a%ncols) then
         write (buf, '("factorize: the matrix is ",i0," x ",i0,", not square")') a%nrows, a%ncols
         call fatal_error(error, trim(buf), stat_invalid_input)
         return
      end if
      if (a%nrows > 0) then
         call self%factorize_backend(a, error)
         if (allocated(error)) then
            call self%destroy()
            return
         end if
         self%n = a%nrows
         self%factorized = .true.
         if (self%rcond_tol > 0.0_wp) then
            call self%rcond(a, self%rcond_estimate, error)
            if (allocated(error)) then
               call self%destroy()
               return
            end if
            ! written so that a NaN estimate (an overflowing factor) also fails
            if (.not. (self%rcond_estimate >= self%rcond_tol)) then
               write (buf, '("factorize: the matrix is numerically singular: reciprocal condition estimate ", &
                  & es9.2," < rcond_tol ",es9.2)') self%rcond_estimate, self%rcond_tol
               call self%destroy()
               call fatal_error(error, trim(buf), stat_singular)
               return
            end if
         end if
      else
         self%factor_nnz = 0
         self%peak_bytes = 0
         self%pivot_ratio = 1.0_wp
         self%rcond_estimate = 1.0_wp
      end if
      self%n = a%nrows
      self%factorized = .true.
   end subroutine factorize

   !> Release the factor and forget the statistics.
   subroutine destroy(self)
      class(linear_solver_type), intent(inout) :: self
      call self%destroy_backend()
      self%n = 0
      self%factorized = .false.
      self%factor_nnz = -1
      self%peak_bytes = -1
      self%pivot_ratio = 0.0_wp
      self%rcond_estimate = -1.0_wp
   end subroutine destroy

   subroutine check_ready(self, nb, nx, error)
      class(linear_solver_type), intent(in) :: self
      integer, intent(in) :: nb, nx
      type(error_type), allocatable, intent(out) :: error
      character(len=128) :: buf

      if (.not. self%factorized) then
         call fatal_error(error, 'solve: no factor (factorize was not called, failed, or destroy followed)', &
            stat_invalid_input)
      else if (nb /= self%n .or. nx /= self%n) then
         write (buf, '("solve: b has ",i0," rows and x ",i0," for a matrix of order ",i0)') nb, nx, self%n
         call fatal_error(error, trim(buf), stat_invalid_input)
      end if
   end subroutine check_ready

   subroutine solve_one(self, b, x, error, transposed)
      class(linear_solver_type), intent(inout) :: self
      real(wp), intent(in) :: b(:)
      real(wp), intent(out) :: x(:)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: transposed

      call check_ready(self, size(b), size(x), error)
      if (allocated(error)) return
      if (self%n == 0) return
      call self%solve_backend(self%n, 1, b, x, optval(transposed), error)
   end subroutine solve_one

   subroutine solve_many(self, b, x, error, transposed)
      class(linear_solver_type), intent(inout) :: self
      real(wp), intent(in) :: b(:, :)
      real(wp), intent(out) :: x(:, :)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: transposed
      character(len=128) :: buf

      call check_ready(self, size(b, 1), size(x, 1), error)
      if (allocated(error)) return
      if (size(b, 2) /= size(x, 2)) then
         write (buf, '("solve: b has ",i0," columns and x ",i0)') size(b, 2), size(x, 2)
         call fatal_error(error, trim(buf), stat_invalid_input)
         return
      end if
      if (self%n == 0 .or. size(b, 2) == 0) return
      call self%solve_backend(self%n, size(b, 2), b, x, optval(transposed), error)
   end subroutine solve_many

   pure logical function optval(flag)
      logical, intent(in), optional :: flag
      optval = .false.
      if (present(flag)) optval = flag
   end function optval

   !> Reciprocal condition estimate 1/(||A||_1 est(||A^-1||_1)) of the factored
   !> matrix `a` (the same matrix given to `factorize`), by Hager's method as
   !> refined by Higham (LAPACK dlacn2) with solves by the factor. The
   !> estimate of ||A^-1||_1 is a lower bound, usually exact or within a factor
   !> 3, so `value` is an upper bound of the true reciprocal condition number,
   !> usually within a factor 3. Costs a few solves.
   subroutine rcond(self, a, value, error)
      class(linear_solver_type), intent(inout) :: self
      type(csr_type), intent(in) :: a
      real(wp), intent(out) :: value
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: v(:), x(:), y(:)
      integer, allocatable :: isgn(:)
      integer :: kase, isave(3), stat
      real(wp) :: anorm, ainvnorm

      value = 0.0_wp
      if (.not. self%factorized) then
         call fatal_error(error, 'rcond: no factor (factorize was not called or failed)', stat_invalid_input)
         return
      end if
      if (a%nrows /= self%n .or. a%ncols /= self%n) then
         call fatal_error(error, 'rcond: the matrix is not the one factored (order differs)', stat_invalid_input)
         return
      end if
      value = 1.0_wp
      if (self%n == 0) return
      anorm = a%norm1(error)
      if (allocated(error)) return
      value = 0.0_wp
      if (.not. (anorm > 0.0_wp)) return

      allocate (v(self%n), x(self%n), y(self%n), isgn(self%n), stat=stat)
      call check_allocation(stat, 'rcond', 'the estimator vectors', int(self%n, i8), 28, error)
      if (allocated(error)) return
      ainvnorm = 0.0_wp
      kase = 0
      do
         call dlacn2(self%n, v, x, isgn, ainvnorm, kase, isave)
         if (kase == 0) exit
         call self%solve_backend(self%n, 1, x, y, kase == 2, error)
         if (allocated(error)) return
         x = y
      end do
      if (ainvnorm > 0.0_wp) value = (1.0_wp/anorm)/ainvnorm
   end subroutine rcond

   !> The one translation of a C-shim status into an `error_type`: `status` is
   !> one of the shim's codes (which mirror `stat_*`: 0 success, 1 invalid
   !> input, 2 singular, 3 not positive definite, 4 not converged, 6 out of memory, 8
   !> internal), `message` the NUL-terminated text the shim wrote.
   subroutine backend_error(status, message, error)
      integer, intent(in) :: status
      character(kind=c_char, len=*), intent(in) :: message
      type(error_type), allocatable, intent(out) :: error
      integer :: stat, last

      select case (status)
      case (0)
         return
      case (1)
         stat = stat_invalid_input
      case (2)
         stat = stat_singular
      case (3)
         stat = stat_not_positive_definite
      case (4)
         stat = stat_not_converged
      case (6)
         stat = stat_out_of_memory
      case default
         stat = stat_internal
      end select
      last = index(message, c_null_char) - 1
      if (last < 0) last = len(message)
      call fatal_error(error, message(1:last), stat)
   end subroutine backend_error

   !> The code of a `solver_names` entry; 0 for any other name.
   pure integer function solver_choice(name) result(code)
      character(len=*), intent(in) :: name
      select case (name)
      case ('auto')
         code = solver_auto
      case ('direct')
         code = solver_direct
      case ('iterative')
         code = solver_iterative
      case default
         code = 0
      end select
   end function solver_choice

   !> Whether the solver `choice` means the iterative solver for a system of
   !> `n` unknowns in dimension `dim` with elements of degree `degree` (on
   !> `solve_ranks` ranks). 'auto' follows `auto_min_dofs`, and also goes
   !> iterative when `direct_fits` is false: a direct solve of the system
   !> would not fit in the memory available (sprc_study_budget).
   pure logical function use_iterative(choice, dim, degree, n, direct_fits, coupled)
      integer, intent(in) :: choice, dim, degree, n
      logical, intent(in), optional :: direct_fits
      !> The coupled system of bodies in contact (`auto_coupled_min_dofs`).
      logical, intent(in), optional :: coupled
      logical :: fits
      integer :: min_dofs

      fits = .true.
      if (present(direct_fits)) fits = direct_fits
      min_dofs = auto_iterative_min_dofs(dim, degree)
      if (present(coupled)) then
         if (coupled) min_dofs = auto_coupled_iterative_min_dofs(dim, degree)
      end if
      use_iterative = choice == solver_iterative .or. (choice == solver_auto .and. &
         & (solve_ranks > 1 .or. .not. fits .or. n >= min_dofs))
   end function use_iterative

   !> 'auto''s threshold for `dim` and `degree` (`auto_min_dofs`; `auto_never`
   !> outside the table: a degree or dimension without a known crossover).
   pure integer function auto_iterative_min_dofs(dim, degree) result(min_dofs)
      integer, intent(in) :: dim, degree
      min_dofs = auto_never
      if (dim >= lbound(auto_min_dofs, 1) .and. dim <= ubound(auto_min_dofs, 1) .and. &
         & degree >= lbound(auto_min_dofs, 2) .and. degree <= ubound(auto_min_dofs, 2)) &
         & min_dofs = auto_min_dofs(dim, degree)
   end function auto_iterative_min_dofs

   !> 'auto''s threshold for the coupled system of bodies in contact
   !> (`auto_coupled_min_dofs`; `auto_never` where a single body has none).
   pure integer function auto_coupled_iterative_min_dofs(dim, degree) result(min_dofs)
      integer, intent(in) :: dim, degree
      min_dofs = auto_iterative_min_dofs(dim, degree)
      if (min_dofs /= auto_never) min_dofs = auto_coupled_min_dofs(dim, degree)
   end function auto_coupled_iterative_min_dofs

   !> Set `solve_ranks` (by sprc_fem_petsc's `start_ranks` only).
   subroutine set_solve_ranks(ranks)
      integer, intent(in) :: ranks
      solve_ranks = max(ranks, 1)
   end subroutine set_solve_ranks

end module sprc_fem_linear_solver
