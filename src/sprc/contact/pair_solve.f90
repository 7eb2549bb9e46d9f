!> The coupled FE solve of one contact pair: both bodies' reduced systems in one
!> block system plus the contact terms on the slave surface points. The maths and
!> the reasons for each choice are in doc/theory.md, section 6 (Tur et al. 2015;
!> the scene keys in doc/scene.md, `&contact`).
!>
!> - Multiplier: stabilized (gamma = kappa E_s/h, h the smallest edge of the slave
!>   point's aggregate root), with p_N the slave's FE traction (Nitsche-type) or,
!>   with `recovered`, its recovered traction of the previous solution.
!> - Multiplier space: P0 on contact cells (`macro_cells`, `group_cells`: slave
!>   aggregates of a parent cell, spanning two master cells where those are larger
!>   by more than a quarter level, turning at most a quarter turn), as P0 on slave
!>   cells is not inf-sup stable; eliminated cell by cell (lambda_c = pbar +
!>   gamma gbar, SPD above the trace-inverse bound). `multiplier='linear'`
!>   (`node_cells`): hats of the cells' vertex lattice along the surface,
!>   eliminated node by node (mass lumped), the active set per point
!>   (`next_set`: the edge where the pressure or the gap changes sign), a
!>   closed node's hat cut to its closed points (`cut_edges`); nodes joined
!>   across rows only where the surface passes (`join_rows`), a cell that
!>   shares no node one constant node (`constant_alone`); a set repeating an
!>   earlier one ends the iteration with a warning (`cycle_warning`).
!> - Frame: at point i lambda_c acts as R_i lambda_c, R_i the least rotation from the
!>   cell's mean normal to n_i (`frame_rotation`): a uniform pressure on a curved
!>   surface is in the space (a Cartesian constant costs Q2 its order).
!> - Points: the slave's cut-cell surface points cut at the master grid's planes.
!> - Active set: primal-dual per contact cell from the first contact (`first_set`:
!>   the cells with g0 <= h at the smallest gap; every g0 <= h cell if that
!>   leaves a body free, `widen_first_set`), one factorization per
!>   iteration, until the set repeats (else stat_not_converged); a body the
!>   closed cells and its conditions leave free is stat_singular, named.
!> - Friction: stick and Coulomb take the cell normal as the mean bisector of the
!>   two normals (a curved slave gets no spurious shear). Coulomb is path dependent:
!>   the loads come in increments, states and slip directions iterate until they
!>   repeat, a slipping cell whose trial turns against its slip sticks, and the
!>   slipping linearization is unsymmetric (UMFPACK).
!> - Recovered stabilization: the cell's block is the penalty W gamma G^T G and p*
!>   moves to the load (SPD for every gamma > 0); frictionless and stick only; with
!>   a `contact_factor_type` the factor is reused while the active set repeats.
!> - Iterative solves (`block_solver_type`, 'iterative' or 'auto' from
!>   `auto_coupled_min_dofs`): CG (GMRES if unsymmetric or indefinite), both bodies'
!>   multigrids stacked (`stack_hierarchies`, contact nodes kept, Galerkin coarse
!>   operators of each new fine matrix, set up anew per active set: a lagged one
!>   costs CG several times the iterations; on a kept pattern, `kept_system`, only
!>   the numeric products and coarse factor are redone), warm starts, `contact_tolerance`
!>   (looser while the set changes: `changing_set_tolerance`, then
!>   `active_set_tolerance` once a change does not shrink, `confirm_set`); under
!>   mpirun (`share`) each rank holds its rows and the solution is gathered.
!>
!> Assemblies (`solve_contact_assembly`): several bodies and their pairs in one block
!> system (bodies' reduced systems on the diagonal in body order, every pair's cells
!> built as a pair's alone), one active set, a direct solve. Frictionless and stick
!> with the FE stabilization only; the rest stays per pair (`solve_contact_pair`).
module sprc_contact_pair_solve
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_not_converged, stat_singular, &
      & stat_unsupported, stat_not_positive_definite
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_core_hash, only: hash_int
   use sprc_core_timer, only: timer_type
   use sprc_fem_sparse, only: coo_type, csr_type
   use sprc_fem_element, only: shape_functions, strain_matrix, traction_matrix, displacement_matrix
   use sprc_fem_problem, only: elasticity_problem_type, free_motions, motion_names, solve_spd_or_lu, &
      & master_hierarchy
   use sprc_fem_linear_solver, only: use_iterative, solver_iterative
   use sprc_fem_petsc, only: petsc_solver_type, iteration_tolerance, start_petsc
   use sprc_fem_multigrid, only: prolongation_type, stack_hierarchies
   use sprc_fem_umfpack, only: umfpack_solver_type
   use sprc_fem_cholmod, only: cholmod_solver_type
   use sprc_contact_surface, only: contact_surface_type
   use sprc_grid_tree, only: grid_max_level
   use sprc_contact_result, only: contact_open, contact_stick, contact_slip
   use sprc_grid_share, only: share_type
   implicit none
   private

   public :: contact_solution_type, solve_contact_pair, friction_kind, contact_progress, contact_factor_type
   public :: contact_body_type, contact_pair_type, solve_contact_assembly, pair_iterative
   public :: friction_frictionless, friction_stick, friction_coulomb, default_max_iterations
   public :: multiplier_constant, multiplier_linear, multiplier_kind, master_levels

   abstract interface
      !> Told after each iteration of the contact nonlinearity (the library
      !> never prints; a driver may): load increment `increment` of
      !> `increments` (1 of 1 without a load path), its iteration `iteration`,
      !> and the slave points whose contact cells changed state (or slip
      !> direction) in it; 0 ends the increment.
      subroutine contact_progress(increment, increments, iteration, switched)
         integer, intent(in) :: increment, increments, iteration, switched
      end subroutine contact_progress
   end interface

   !> Friction laws (doc/scene.md `friction`).
   integer, parameter :: friction_frictionless = 0, friction_stick = 1, friction_coulomb = 2
   !> Multiplier spaces (doc/scene.md `multiplier`): constant on each contact
   !> cell, or continuous and multilinear on the contact cells' lattice.
   integer, parameter :: multiplier_constant = 0, multiplier_linear = 1
   !> Active-set iterations before giving up.
   integer, parameter :: default_max_iterations = 50
   !> A slip direction counts as settled when it moves by less than this
   !> between iterations (unit vectors; in 2D it only flips).
   real(wp), parameter :: direction_tol = 1.0e-8_wp
   !> A contact cell's normals stay within 45 degrees of its mean normal
   !> (`turns_too_far`): cos 45 degrees, less a round-off margin so that an
   !> exact quarter turn (a quarter model's one cell) stays one cell.
   real(wp), parameter :: cos_max_turn = sqrt(0.5_wp) - 1.0e-12_wp
   !> A contact cell widens to span two master cells (`master_levels`) once
   !> the master cells exceed the slave's by more than this factor, a quarter
   !> of a level (2^(1/4)): grids on different root boxes have any size
   !> ratio, and a cell of two slave cells over master cells up to 1.15
   !> times the slave's gives pressures as good as over equal cells, from
   !> 1.2 times three to ten times worse (doc/benchmarks.md, "Contact cells
   !> over a coarser master").
   real(wp), parameter :: master_ratio_tol = 2.0_wp**0.25_wp

   !> The contact operators of the points with a master point (local dofs in
   !> the block numbering, gap and traction operators) and their contact cells.
   type :: point_operators_type
      integer, allocatable :: ptr(:), dofs(:)
      !> g(u) - g0 n = gop(:, ptr(i):ptr(i+1)-1) u(dofs(...)); slave traction sigma(u_s) n likewise with top.
      real(wp), allocatable :: gop(:, :), top(:, :)
      !> Contact cells: points cell_point(cell_ptr(c) : cell_ptr(c+1)-1); the cell of each point (0: none).
      !> A point of a linear multiplier belongs to the cells (nodes) of its hats.
      integer :: ncell = 0
      integer, allocatable :: cell_ptr(:), cell_point(:), cell_of_point(:)
      !> The multiplier's basis function of each cell at each of its points,
      !> parallel to cell_point: 1 (constant multiplier) or the node's hat.
      real(wp), allocatable :: cell_phi(:)
      !> Linear multiplier: each point's owner, the node of its largest hat
      !> (its state), and the hats before `cut_edges` masks them.
      integer, allocatable :: owner(:)
      real(wp), allocatable :: phi_full(:)
      !> Linear multiplier: the points' states (the active set is per point,
      !> `next_set`) and those the last solve proposes.
      logical, allocatable :: pclosed(:), pnext(:)
      !> Linear multiplier: the point sets solved so far (`next_set`).
      logical, allocatable :: seen(:, :)
      integer :: nseen = 0
      !> Penalty gamma = kappa E_s/h of each contact cell.
      real(wp), allocatable :: gamma(:)
   end type point_operators_type

   !> One contact cell's operators on the union of its points' dofs: rows are
   !> the normal direction (frictionless) or the dim components (stick).
   type :: cell_operators_type
      integer :: nu = 0, rows = 0
      integer, allocatable :: dofs(:)
      real(wp) :: measure = 0.0_wp
      !> Unit mean normal of the cell's points.
      real(wp), allocatable :: nbar(:)
      !> Means of the gap operator, its constant part and the traction operator.
      real(wp), allocatable :: gbar(:, :), g0bar(:), tbar(:, :)
      !> Per point: the traction operator minus its mean, (rows, nu, npoints), and the weights.
      real(wp), allocatable :: tdev(:, :, :), w(:)
      !> Per point (stick): the rotation R_i (dim, dim, npoints) carrying the
      !> cell frame to the point's, R_i nbar = n_i; the multiplier at the
      !> point is R_i lambda_c (module notes).
      real(wp), allocatable :: rot(:, :, :)
   end type cell_operators_type

   !> One point's operators of both bodies while they are built.
   type :: local_type
      integer :: ms = 0, mm = 0
      integer, allocatable :: ds(:), dm(:)
      real(wp), allocatable :: ns(:, :), ts(:, :), nm(:, :), tm(:, :)
   end type local_type

   !> The linear solver of the block system (module notes): direct, or
   !> Krylov + the bodies' stacked multigrid hierarchy, set up once by
   !> `block_solver_setup`.
   type :: block_solver_type
      logical :: ready = .false., iterative = .false.
      type(petsc_solver_type) :: krylov
      !> The Krylov tolerances of the final solve (`contact_tolerance`), of
      !> the solves while the active set changes (`changing_set_tolerance`
      !> first, `loose` now) and of those once a change did not shrink
      !> (`active_set_tolerance`).
      real(wp) :: tight = 0.0_wp, loose = 0.0_wp, careful = 0.0_wp
      !> The cells whose blocks the kept pattern of the iterative block
      !> system holds, and both bodies' K on it (`kept_system`).
      logical, allocatable :: cover(:)
      real(wp), allocatable :: base(:)
   end type block_solver_type

   !> The CHOLMOD factor of a recovered-stabilization block system and the
   !> contact cells' active set it was built for (module notes), kept by the
   !> caller between updates of the stabilization traction; or the
   !> iterative solver set up for that system.
   type :: contact_factor_type
      private
      type(cholmod_solver_type) :: chol
      type(block_solver_type) :: bs
      logical, allocatable :: closed(:)
   contains
      !> `destroy()`: release the factor (harmless when repeated).
      procedure :: destroy => factor_destroy
   end type contact_factor_type

   !> What the coupled solve gives per slave point (in the problems' units).
   type :: contact_solution_type
      !> Active-set iterations (factorizations).
      integer :: iterations = 0
      !> Closed points of the final set (their cell is closed), and those slipping (Coulomb).
      logical, allocatable :: closed(:), slipping(:)
      !> Linearized normal gap of the solution (huge where the point has no master point).
      real(wp), allocatable :: gap(:)
      !> Contact pressure p = -lambda_n (0 open) and |lambda_t| (module notes).
      real(wp), allocatable :: pressure(:), tangential(:)
      !> The tangential traction lambda_t on the slave body itself (dim, npoint; 0 open or frictionless).
      real(wp), allocatable :: traction_t(:, :)
      !> nbar.lambda_c of every contact cell: negative where the cell carries
      !> compression when closed.
      real(wp), allocatable :: lambda_n(:)
      !> Reciprocal condition estimate of the last block system (-1 when an
      !> iterative solve made none) and the solver used.
      real(wp) :: rcond = -1.0_wp
      character(len=:), allocatable :: solver_name
      !> Krylov iterations of all block solves (0 for direct solves).
      integer :: solver_iterations = 0
      !> Seconds of the contact operators and active-set evaluation, and of the
      !> block assemblies and solves.
      real(wp) :: t_contact = 0.0_wp, t_solve = 0.0_wp
      !> What a caller should tell the user about the solve ('' for nothing):
      !> the linear multiplier's active set ended by repeating an earlier
      !> one (`next_set`), a cycle the solve cut short.
      character(len=:), allocatable :: warning
   end type contact_solution_type

   !> A body of an assembly (`solve_contact_assembly`): its assembled problem and its name.
   type :: contact_body_type
      type(elasticity_problem_type), pointer :: problem => null()
      character(len=:), allocatable :: name
   end type contact_body_type

   !> A pair of an assembly: slave and master (indices into the assembly's
   !> bodies), the slave surface with its initial gaps to the master, the
   !> friction law (frictionless or stick) and kappa.
   type :: contact_pair_type
      integer :: slave = 0, master = 0, friction = friction_frictionless
      !> The multiplier space (`multiplier_constant` or `multiplier_linear`).
      integer :: multiplier = multiplier_constant
      real(wp) :: kappa = 0.0_wp
      type(contact_surface_type) :: surface
   end type contact_pair_type

   !> A matrix of a list of matrices (one body's rigid modes).
   type :: dense_block_type
      real(wp), allocatable :: a(:, :)
   end type dense_block_type

   !> A pair's operators, contact cells and active set during an assembly's solve.
   type :: pair_work_type
      type(point_operators_type) :: ops
      type(cell_operators_type), allocatable :: cells(:)
      !> The active set, and the candidate cells (g0 <= h) of `first_set`.
      logical, allocatable :: closed(:), wide(:)
   end type pair_work_type

contains

   !> The multiplier constant of a doc/scene.md `multiplier` name (-1 if unknown).
   pure integer function multiplier_kind(name)
      character(len=*), intent(in) :: name
      select case (name)
      case ('constant'); multiplier_kind = multiplier_constant
      case ('linear'); multiplier_kind = multiplier_linear
      case default; multiplier_kind = -1
      end select
   end function multiplier_kind

   !> The friction constant of a doc/scene.md `friction` name (-1 if unknown).
   pure integer function friction_kind(name)
      character(len=*), intent(in) :: name
      select case (name)
      case ('frictionless'); friction_kind = friction_frictionless
      case ('stick'); friction_kind = friction_stick
      case ('coulomb'); friction_kind = friction_coulomb
      case default; friction_kind = -1
      end select
   end function friction_kind

   !> Solve the pair (module notes): `slave` and `master` assembled
   !> (`assemble`), `surface` with its initial gaps to the master; on success
   !> both problems hold their solution (`set_solution`). `names` are the slave
   !> and master body names for messages.
   subroutine solve_contact_pair(slave, master, surface, friction, kappa, names, sol, error, max_iterations, mu, &
         & loads, progress, recovered, factor, multiplier, share, bounds)
      type(elasticity_problem_type), intent(inout) :: slave, master
      type(contact_surface_type), intent(in) :: surface
      integer, intent(in) :: friction
      real(wp), intent(in) :: kappa
      character(len=*), intent(in) :: names(2)
      type(contact_solution_type), intent(out) :: sol
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: max_iterations
      !> With Coulomb friction, the friction coefficient and the load path (block loads at the
      !> end of each increment, one column each; default one increment, the
      !> assembled loads).
      real(wp), intent(in), optional :: mu, loads(:, :)
      !> Told after each iteration (`contact_progress`).
      procedure(contact_progress), optional :: progress
      !> The stabilization traction p*_i of each surface point (dim, npoint),
      !> in the problems' units: Tur's variant (module notes); without it the
      !> slave's FE traction.
      real(wp), intent(in), optional :: recovered(:, :)
      !> With `recovered`: the factor of the previous solve (module notes),
      !> updated.
      type(contact_factor_type), intent(inout), optional, target :: factor
      !> The multiplier space (`multiplier_constant`, the default, or `multiplier_linear`).
      integer, intent(in), optional :: multiplier
      !> With several ranks (`sprc_study_partition`'s `assemble_pair_rows`):
      !> both problems hold only this rank's rows of the block system, rows
      !> bounds(r + 1) .. bounds(r + 2) - 1 on rank r of `share`; the solve
      !> must be iterative (distributed), and the rigid-mode check gathers
      !> its rows (`free_motions`). Frictionless and stick only.
      class(share_type), intent(in), optional :: share
      integer(i8), intent(in), optional :: bounds(:)
      type(point_operators_type) :: ops
      type(cell_operators_type), allocatable :: cells(:)
      type(csr_type) :: k
      type(timer_type) :: timer
      real(wp), allocatable :: f(:), x(:)
      logical, allocatable :: closed(:), next(:), wide(:)
      integer, allocatable :: state(:)
      real(wp), allocatable :: slip(:, :), tau(:, :), pstar(:, :)
      type(block_solver_type), target :: own
      type(block_solver_type), pointer :: bs
      integer :: it, maxit, n, c, switched, stat, last_switched, attempt, cycled
      logical :: kept, again

      sol%warning = ''
      call check_pair(slave, master, surface, friction, kappa, error)
      if (.not. allocated(error) .and. present(recovered)) call check_recovered(surface, friction, recovered, error)
      if (allocated(error)) return
      maxit = default_max_iterations
      if (present(max_iterations)) maxit = max_iterations
      call timer%start()
      call point_operators(slave, master, surface, kappa, ops, error, multiplier=multiplier)
      if (allocated(error)) return
      allocate (cells(ops%ncell), closed(ops%ncell), next(ops%ncell), stat=stat)
      call check_allocation(stat, 'contact solve', 'the contact cells', ops%ncell, 2, error)
      if (allocated(error)) return
      do c = 1, ops%ncell
         call cell_operators(surface, ops, c, merge(friction_stick, friction, friction == friction_coulomb), cells(c), &
            & error)
         if (allocated(error)) return
      end do
      call first_set(slave, surface, ops, closed, wide)
      if (present(recovered)) then
         call cell_tractions(surface, ops, cells, recovered, pstar, error)
         if (allocated(error)) return
      end if
      kept = present(factor) .and. present(recovered)
      bs => own
      if (kept) then
         if (allocated(factor%closed)) then
            if (size(factor%closed) == size(closed)) closed = factor%closed
         end if
         bs => factor%bs
      end if
      call timer%stop()
      sol%t_contact = timer%elapsed
      n = slave%n_dofs() + master%n_dofs()
      allocate (x(n), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact solve', 'the solution of both bodies', n, 8, error)
      call timer%reset()
      call timer%start()
      if (.not. allocated(error)) call block_solver_setup(slave, master, ops, kappa, bs, error)
      call timer%stop()
      sol%t_solve = timer%elapsed
      if (allocated(error)) return
      ! from every candidate (an interference fit) the set does not grow by rows: `changing_set_tolerance`
      if (all(closed .eqv. wide)) bs%loose = bs%careful
      if (present(share) .and. (friction == friction_coulomb .or. .not. bs%iterative)) then
         call fatal_error(error, 'contact solve: a block system whose rows are shared out among ranks needs the '// &
            & 'iterative solver and frictionless or stick contact', stat_invalid_input)
         return
      end if
      if (friction == friction_coulomb) then
         if (.not. present(mu)) then
            call fatal_error(error, 'contact solve: Coulomb friction needs mu', stat_invalid_input)
            return
         end if
         if (present(loads)) then
            call solve_coulomb(slave, master, ops, cells, closed, mu, loads, names, maxit, bs, x, sol, state, tau, &
               & slip, error, progress)
         else
            call solve_coulomb(slave, master, ops, cells, closed, mu, reshape([slave%f, master%f], [n, 1]), names, &
               & maxit, bs, x, sol, state, tau, slip, error, progress)
         end if
         if (allocated(error)) return
         call point_gaps(surface, ops, ops%ncell, x, sol, error)
         if (allocated(error)) return
         call coulomb_output(ops, cells, mu, state, tau, slip, x, sol)
      end if
      last_switched = huge(1)
      do it = 1, merge(0, maxit, friction == friction_coulomb)
         sol%iterations = it
         call timer%reset()
         call timer%start()
         do attempt = 1, 2
            if (allocated(ops%owner) .and. .not. present(recovered)) then
               call cut_edges(surface, ops, cells, closed, friction, error)
               if (allocated(error)) return
            end if
            if (kept) then
               call factored_solve(slave, master, ops, cells, closed, pstar, names, it, factor, x, sol, error, &
                  & share, bounds)
            else if (present(recovered)) then
               call block_system(slave, master, ops, cells, closed, k, f, error, pstar)
            else if (bs%iterative .and. .not. present(share)) then
               call kept_system(slave, master, ops, cells, closed, bs, k, f, error)
            else
               call block_system(slave, master, ops, cells, closed, k, f, error)
            end if
            if (.not. (allocated(error) .or. kept)) &
               & call check_held(slave, master, k, names, closed_points(ops, closed), it, error, share, bounds)
            call widen_first_set(it, wide, closed, error, again)
            if (.not. again) exit
            ! the linear multiplier's point states follow the widened cells (`cut_edges`)
            if (allocated(ops%pclosed)) deallocate (ops%pclosed)
         end do
         if (.not. (allocated(error) .or. kept)) call solve_block(bs, k, f, x, sol, error)
         call timer%stop()
         sol%t_solve = sol%t_solve + timer%elapsed
         if (allocated(error)) return
         call timer%reset()
         call timer%start()
         if (present(recovered)) then
            call evaluate(surface, ops, cells, closed, x, sol, error, pstar)
         else
            call evaluate(surface, ops, cells, closed, x, sol, error)
         end if
         if (allocated(error)) return
         call next_set(ops, closed, sol%lambda_n, sol%gap, next, switched, cycled)
         call timer%stop()
         sol%t_contact = sol%t_contact + timer%elapsed
         if (switched == 0 .and. .not. kept .and. bs%iterative .and. bs%krylov%tolerance > bs%tight) then
            call timer%reset()
            call timer%start()
            call confirm_set(surface, ops, cells, closed, bs, f, x, sol, next, switched, cycled, error, pstar)
            call timer%stop()
            sol%t_solve = sol%t_solve + timer%elapsed
            if (allocated(error)) return
         end if
         if (present(progress)) call progress(1, 1, it, switched)
         if (cycled > 0) sol%warning = cycle_warning("contact '"//trim(names(1))//"' on '"//trim(names(2))//"'", &
            & it, cycled)
         if (switched == 0) exit
         ! loose solves that do not shrink the change of the set: tighter ones from here on
         if (switched >= last_switched) bs%loose = merge(bs%careful, bs%tight, bs%loose > bs%careful)
         last_switched = switched
         closed = next
         if (allocated(ops%pnext)) ops%pclosed = ops%pnext
         if (it == maxit) then
            call fatal_error(error, "contact '"//trim(names(1))//"' on '"//trim(names(2))// &
               & "': the active set did not settle in "//itoa(maxit)//' iterations; '//itoa(switched)//' of '// &
               & itoa(count(surface%has_master))//' points still switched in the last one', stat_not_converged)
            return
         end if
      end do
      ! PETSc's copy of the block system, its hierarchy and coarse factor: not the recovery's to carry
      call own%krylov%destroy()
      call slave%set_solution(x(1:slave%n_dofs()), error)
      if (.not. allocated(error)) call master%set_solution(x(slave%n_dofs() + 1:), error)
   end subroutine solve_contact_pair

   !> The first active set: the candidate cells (a point's initial gap within
   !> the cell size h) whose smallest gap is within sqrt(eps) h of the pair's
   !> first contact, max(min g0, 0): the points the bodies touch first when
   !> they approach rigidly, every point of an interference or a zero-gap fit
   !> (the round-off of the gaps is eps times the geometry's scale). Closing
   !> every candidate instead ties cells the load never closes, and the
   !> primal-dual iteration then opens them a few per active set; from the
   !> first contact the penetrating cells close in one set. `wide` gets the
   !> candidate cells (`widen_first_set`).
   subroutine first_set(slave, surface, ops, closed, wide)
      type(elasticity_problem_type), intent(in) :: slave
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(in) :: ops
      logical, intent(out) :: closed(:)
      logical, allocatable, intent(out) :: wide(:)
      real(wp) :: gmin(size(closed)), h(size(closed)), first
      integer :: c
      do c = 1, size(closed)
         gmin(c) = minval(surface%g0(ops%cell_point(ops%cell_ptr(c):ops%cell_ptr(c + 1) - 1)))
         h(c) = cell_size(slave, slave%root(surface%slave_cell(ops%cell_point(ops%cell_ptr(c)))))
      end do
      wide = gmin <= h
      closed = wide
      if (.not. any(closed)) return
      first = max(minval(gmin, mask=closed), 0.0_wp)
      closed = closed .and. gmin <= first + sqrt(epsilon(1.0_wp))*h
   end subroutine first_set

   !> The first contact need not hold a body that the load closes more
   !> cells to hold: a wedge pressed into a V-groove touches one flank
   !> first and, frictionless, slides along it until the other closes. When
   !> the first active-set iteration's system leaves a body free
   !> (stat_singular from `check_held`) and the candidate cells `wide` close
   !> more than `closed`, the iteration starts again, once, from `wide` (the
   !> primal-dual iteration opens what the load does not close); `again`
   !> says so and the error is cleared.
   subroutine widen_first_set(iteration, wide, closed, error, again)
      integer, intent(in) :: iteration
      logical, intent(in) :: wide(:)
      logical, intent(inout) :: closed(:)
      type(error_type), allocatable, intent(inout) :: error
      logical, intent(out) :: again
      again = .false.
      if (.not. allocated(error) .or. iteration /= 1) return
      if (error%stat /= stat_singular .or. all(closed .eqv. wide)) return
      deallocate (error)
      closed = wide
      again = .true.
   end subroutine widen_first_set

   !> The linear multiplier's active set is per point (`next_set`): a node
   !> is closed when a point of its hat is, and acts on (carries pressure
   !> at) only its closed points, so its hat ends at the contact edge. Its
   !> mean gap would otherwise take in the open side's gap, pressing the
   !> closed side in, and its pressure would run on past the edge. The
   !> first set closes the points whose owner (the node of their largest
   !> hat) `first_set` closed. Nodes whose hats change are rebuilt; the
   !> hats depend on the active set alone.
   subroutine cut_edges(surface, ops, cells, closed, friction, error)
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(inout) :: ops
      type(cell_operators_type), intent(inout) :: cells(:)
      logical, intent(inout) :: closed(:)
      integer, intent(in) :: friction
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: phi(maxval(ops%cell_ptr(2:) - ops%cell_ptr(:ops%ncell)))
      integer :: c, q0, q1, n, i
      if (.not. allocated(ops%pclosed)) then
         allocate (ops%pclosed(size(ops%owner)), source=.false.)
         do i = 1, size(ops%owner)
            if (ops%owner(i) > 0) ops%pclosed(i) = closed(ops%owner(i))
         end do
      end if
      do c = 1, ops%ncell
         q0 = ops%cell_ptr(c)
         q1 = ops%cell_ptr(c + 1) - 1
         n = q1 - q0 + 1
         phi(1:n) = merge(ops%phi_full(q0:q1), 0.0_wp, ops%pclosed(ops%cell_point(q0:q1)))
         closed(c) = any(phi(1:n) > 0.0_wp)
         if (.not. closed(c)) phi(1:n) = ops%phi_full(q0:q1)
         if (all(phi(1:n) == ops%cell_phi(q0:q1))) cycle
         ops%cell_phi(q0:q1) = phi(1:n)
         call cell_operators(surface, ops, c, merge(friction_stick, friction, friction == friction_coulomb), cells(c), &
            & error)
         if (allocated(error)) return
      end do
   end subroutine cut_edges

   pure integer function closed_points(ops, closed)
      type(point_operators_type), intent(in) :: ops
      logical, intent(in) :: closed(:)
      closed_points = sum(ops%cell_ptr(2:) - ops%cell_ptr(:size(closed)), mask=closed)
   end function closed_points

   pure real(wp) function cell_size(problem, e)
      type(elasticity_problem_type), intent(in) :: problem
      integer, intent(in) :: e
      real(wp) :: lo(3), hi(3)
      call problem%element_box(e, lo(1:problem%dim), hi(1:problem%dim))
      cell_size = minval(hi(1:problem%dim) - lo(1:problem%dim))
   end function cell_size

   subroutine check_pair(slave, master, surface, friction, kappa, error)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(contact_surface_type), intent(in) :: surface
      integer, intent(in) :: friction
      real(wp), intent(in) :: kappa
      type(error_type), allocatable, intent(out) :: error

      if (.not. (allocated(slave%f) .and. allocated(master%f))) then
         call fatal_error(error, 'contact solve: both bodies must be assembled first', stat_invalid_input)
      else if (.not. allocated(surface%g0)) then
         call fatal_error(error, 'contact solve: the contact surface has no initial gaps', stat_invalid_input)
      else if (slave%dim /= master%dim .or. surface%dim /= slave%dim .or. slave%analysis /= master%analysis) then
         call fatal_error(error, 'contact solve: the two bodies and the surface differ in dimension or analysis', &
            & stat_invalid_input)
      else if (.not. (kappa > 0.0_wp .and. kappa < huge(1.0_wp))) then
         call fatal_error(error, 'contact solve: kappa must be finite and > 0', stat_invalid_input)
      else if (friction /= friction_frictionless .and. friction /= friction_stick .and. &
         & friction /= friction_coulomb) then
         call fatal_error(error, 'contact solve: unknown friction law '//itoa(friction), stat_invalid_input)
      else if (slave%dilatation%active) then
         call fatal_error(error, 'contact: the projected dilatation (nearly incompressible slave body) is not '// &
            & 'combined with contact in this version; set dilatation = ''full''', stat_unsupported)
      end if
   end subroutine check_pair

   !> Gap and traction operators of every point with a master point.
   !> `offsets`: the slave's and the master's first dof less one in the
   !> system's numbering (default 0 and the slave's dofs: the pair's block system).
   subroutine point_operators(slave, master, surface, kappa, ops, error, offsets, multiplier)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(contact_surface_type), intent(in) :: surface
      real(wp), intent(in) :: kappa
      type(point_operators_type), intent(out) :: ops
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: offsets(2), multiplier
      type(local_type), allocatable :: loc(:)
      integer :: i, q0, q1, d, c, stat, off(2)

      d = surface%dim
      off = [0, slave%n_dofs()]
      if (present(offsets)) off = offsets
      call group_cells(surface, slave, master, ops, error, multiplier)
      if (allocated(error)) return
      allocate (loc(surface%npoint), ops%ptr(surface%npoint + 1), ops%gamma(ops%ncell), stat=stat)
      call check_allocation(stat, 'contact operators', 'the points'' operators', surface%npoint, 128, error)
      if (allocated(error)) return
      do c = 1, ops%ncell
         ops%gamma(c) = kappa*slave%young/cell_size(slave, slave%root(surface%slave_cell(ops%cell_point(ops%cell_ptr(c)))))
      end do
      ops%ptr(1) = 1
      do i = 1, surface%npoint
         ops%ptr(i + 1) = ops%ptr(i)
         if (.not. surface%has_master(i)) cycle
         call body_operators(slave, surface%slave_cell(i), surface%x(:, i), surface%normal(:, i), loc(i)%ds, &
            & loc(i)%ns, loc(i)%ts, loc(i)%ms, error)
         if (.not. allocated(error)) call body_operators(master, surface%master_cell(i), surface%master_x(:, i), &
            & surface%normal(:, i), loc(i)%dm, loc(i)%nm, loc(i)%tm, loc(i)%mm, error)
         if (allocated(error)) return
         ops%ptr(i + 1) = ops%ptr(i) + loc(i)%ms + loc(i)%mm
      end do
      allocate (ops%dofs(ops%ptr(surface%npoint + 1) - 1), ops%gop(d, ops%ptr(surface%npoint + 1) - 1), &
         & ops%top(d, ops%ptr(surface%npoint + 1) - 1), stat=stat)
      call check_allocation(stat, 'contact operators', 'the gap and traction operators', &
         & ops%ptr(surface%npoint + 1) - 1, 4 + 16*d, error)
      if (allocated(error)) return
      do i = 1, surface%npoint
         if (.not. surface%has_master(i)) cycle
         associate (p => loc(i))
            q0 = ops%ptr(i)
            q1 = q0 + p%ms - 1
            ops%dofs(q0:q1) = off(1) + p%ds(1:p%ms)
            ops%gop(:, q0:q1) = -p%ns
            ops%top(:, q0:q1) = p%ts
            q0 = q1 + 1
            q1 = ops%ptr(i + 1) - 1
            ops%dofs(q0:q1) = off(2) + p%dm(1:p%mm)
            ops%gop(:, q0:q1) = p%nm
            ops%top(:, q0:q1) = 0.0_wp
         end associate
      end do
   end subroutine point_operators

   !> The contact cells: the macro cells (`macro_cells`) of the slave
   !> aggregates (`root`, sprc_fem_aggregation) holding points with a master
   !> point, in leaf order, each with its points in point order. A small cut
   !> cell's segment thus shares its root's multiplier, as its displacement is
   !> the root's polynomial. A group whose surface measure is below half its
   !> representative's h^(dim-1) (the surface clips a corner of a parent cell)
   !> joins the group of at least that measure whose centroid is nearest: a
   !> multiplier on a sliver is barely constrained by the displacements, and
   !> its pressure is noise that can open it falsely.
   subroutine group_cells(surface, slave, master, ops, error, multiplier)
      type(contact_surface_type), intent(in) :: surface
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(inout) :: ops
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: multiplier
      integer :: key(surface%npoint), group(slave%mesh%grid%n_leaves), cell_of_leaf(slave%mesh%grid%n_leaves)
      integer :: fill(slave%mesh%grid%n_leaves), i, e, c, best, n_leaves, d, stat
      real(wp) :: measure(slave%mesh%grid%n_leaves), centroid(surface%dim, slave%mesh%grid%n_leaves), dist, best_dist
      logical :: small(slave%mesh%grid%n_leaves)
      integer :: macro(slave%mesh%grid%n_leaves), shift(slave%mesh%grid%n_leaves)

      n_leaves = slave%mesh%grid%n_leaves
      d = surface%dim
      key = 0
      measure = 0.0_wp
      centroid = 0.0_wp
      call macro_cells(surface, slave, master, macro, shift)
      do i = 1, surface%npoint
         if (.not. surface%has_master(i)) cycle
         key(i) = macro(slave%root(surface%slave_cell(i)))
         measure(key(i)) = measure(key(i)) + surface%weight(i)
         centroid(:, key(i)) = centroid(:, key(i)) + surface%weight(i)*surface%x(:, i)
      end do
      small = .false.
      do e = 1, n_leaves
         group(e) = e
         if (.not. measure(e) > 0.0_wp) cycle
         centroid(:, e) = centroid(:, e)/measure(e)
         small(e) = measure(e) < 0.5_wp*cell_size(slave, e)**(d - 1)
      end do
      if (.not. all(small .or. .not. measure > 0.0_wp)) then
         do e = 1, n_leaves
            if (.not. small(e)) cycle
            best = 0
            best_dist = huge(1.0_wp)
            do c = 1, n_leaves
               if (.not. measure(c) > 0.0_wp .or. small(c)) cycle
               dist = norm2(centroid(:, c) - centroid(:, e))
               if (dist < best_dist) then
                  best = c
                  best_dist = dist
               end if
            end do
            group(e) = best
         end do
      end if
      fill = 0
      do i = 1, surface%npoint
         if (key(i) > 0) fill(group(key(i))) = fill(group(key(i))) + 1
      end do
      ops%ncell = count(fill > 0)
      allocate (ops%cell_ptr(ops%ncell + 1), ops%cell_point(count(surface%has_master)), &
         & ops%cell_of_point(surface%npoint), stat=stat)
      call check_allocation(stat, 'contact cells', 'the cells'' points', surface%npoint + ops%ncell, 8, error)
      if (allocated(error)) return
      ops%cell_ptr(1) = 1
      cell_of_leaf = 0
      c = 0
      do e = 1, n_leaves
         if (fill(e) == 0) cycle
         c = c + 1
         cell_of_leaf(e) = c
         ops%cell_ptr(c + 1) = ops%cell_ptr(c) + fill(e)
      end do
      fill = 0
      ops%cell_of_point = 0
      do i = 1, surface%npoint
         if (key(i) == 0) cycle
         c = cell_of_leaf(group(key(i)))
         ops%cell_of_point(i) = c
         ops%cell_point(ops%cell_ptr(c) + fill(c)) = i
         fill(c) = fill(c) + 1
      end do
      allocate (ops%cell_phi(size(ops%cell_point)), source=1.0_wp, stat=stat)
      call check_allocation(stat, 'contact cells', 'the cells'' basis', size(ops%cell_point), 8, error)
      if (allocated(error) .or. .not. present(multiplier)) return
      if (multiplier == multiplier_linear) call node_cells(surface, slave, ops, pack([(e, e=1, n_leaves)], &
         & cell_of_leaf > 0), shift, error)
   end subroutine group_cells

   !> The cells of the linear multiplier (module notes): nodes of hats along
   !> the surface. A contact cell's box is its macro cell (`shift` levels
   !> above its representative root `rep(c)`); its normal axis k is the axis
   !> nearest its mean normal, and its hats are the multilinear ones of the
   !> box's vertex lattice in the other axes (a point's coordinates clamped to
   !> the box: a sliver joined to a neighbour cell), so they sum to one at
   !> every point and a uniform pressure lies in the space. A node is keyed by
   !> k, the box's row along k and the vertex in the other axes on the finest
   !> lattice; the nodes of the same vertex in neighbouring rows are one (the
   !> surface passing from row to row), so the multiplier is continuous
   !> between cells of one size and normal axis. Hats over the whole box (both
   !> rows of vertices) would make two nodes with nearly the same constraint
   !> where the surface runs near a lattice line, and their difference free:
   !> an oscillating pressure. Nodes come in the order of their first point.
   subroutine node_cells(surface, slave, ops, rep, shift, error)
      type(contact_surface_type), intent(in) :: surface
      type(elasticity_problem_type), intent(in) :: slave
      type(point_operators_type), intent(inout) :: ops
      integer, intent(in) :: rep(:), shift(:)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: node(:, :), keys(:, :), table(:), axis(:), parent(:), id(:)
      real(wp), allocatable :: phi(:, :), nsum(:, :)
      real(wp) :: lo(3), hi(3), h(3), t(3), f
      integer :: d, nc, i, c, e, k, v, m, nn, nslot, stat, kt(2), vkey(5), scale, j, r

      d = surface%dim
      nc = 2**(d - 1)
      allocate (node(nc, surface%npoint), phi(nc, surface%npoint), keys(d + 2, nc*size(ops%cell_point)), &
         & axis(ops%ncell), nsum(d, ops%ncell), stat=stat)
      call check_allocation(stat, 'contact cells', 'the multiplier''s nodes', nc*surface%npoint, 12 + 4*(d + 2), error)
      if (allocated(error)) return
      nslot = 2
      do while (nslot < 2*nc*size(ops%cell_point))
         nslot = 2*nslot
      end do
      allocate (table(0:nslot - 1), source=0, stat=stat)
      call check_allocation(stat, 'contact cells', 'the nodes'' table', nslot, 4, error)
      if (allocated(error)) return
      nsum = 0.0_wp
      do i = 1, surface%npoint
         c = ops%cell_of_point(i)
         if (c > 0) nsum(:, c) = nsum(:, c) + surface%weight(i)*surface%normal(:, i)
      end do
      do c = 1, ops%ncell
         axis(c) = maxloc(abs(nsum(:, c)), 1)
      end do
      node = 0
      phi = 0.0_wp
      nn = 0
      do i = 1, surface%npoint
         c = ops%cell_of_point(i)
         if (c == 0) cycle
         e = rep(c)
         k = axis(c)
         kt(1:d - 1) = pack([(j, j=1, d)], [(j, j=1, d)] /= k)
         call slave%mesh%grid%leaf_box(e, lo(1:d), hi(1:d))
         h(1:d) = (hi(1:d) - lo(1:d))*2**shift(e)
         ! The macro box's lower corner: the root's corner rounded down to the macro lattice.
         lo(1:d) = lo(1:d) - (hi(1:d) - lo(1:d))*modulo(slave%mesh%grid%leaf_coord(1:d, e), 2**shift(e))
         t(1:d) = min(1.0_wp, max(0.0_wp, (surface%x(:, i) - lo(1:d))/h(1:d)))
         scale = 2**(grid_max_level - slave%mesh%grid%leaf_level(e) + shift(e))
         do v = 1, nc
            vkey(1) = k
            vkey(2:d + 1) = (slave%mesh%grid%leaf_coord(1:d, e)/2**shift(e))*scale
            vkey(d + 2) = scale
            f = 1.0_wp
            do j = 1, d - 1
               if (btest(v - 1, j - 1)) then
                  f = f*t(kt(j))
                  vkey(1 + kt(j)) = vkey(1 + kt(j)) + scale
               else
                  f = f*(1.0_wp - t(kt(j)))
               end if
            end do
            if (.not. f > 0.0_wp) cycle
            m = find_key(vkey(1:d + 2), .true.)
            node(v, i) = m
            phi(v, i) = f
         end do
      end do
      call join_rows(error)
      if (allocated(error)) return
      call constant_alone(error)
      if (allocated(error)) return
      call node_lists(node, phi, nn, ops, error)
   contains
      !> A contact cell that shares none of its nodes with another cell (its
      !> neighbours along the surface of another normal axis or size: a
      !> coarse ring, a quarter turn of a few cells) gets one node with
      !> phi = 1, the constant multiplier's cell: its own hats would add a
      !> slope that no neighbour ties, over master cells that may be as
      !> large as the cell itself where `turns_too_far` narrowed it (a
      !> closed fit at a coarse level: the slopes oscillate, one node in
      !> tension). Nodes renumbered 1..nn.
      subroutine constant_alone(error)
         type(error_type), allocatable, intent(out) :: error
         integer, allocatable :: first(:), newid(:), single(:)
         logical, allocatable :: shared(:), alone(:)
         allocate (first(nn), newid(nn), shared(nn), alone(ops%ncell), single(ops%ncell), stat=stat)
         call check_allocation(stat, 'contact cells', 'the nodes'' cells', nn + ops%ncell, 12, error)
         if (allocated(error)) return
         first = 0
         shared = .false.
         do i = 1, surface%npoint
            c = ops%cell_of_point(i)
            do v = 1, nc
               m = node(v, i)
               if (m == 0) cycle
               if (first(m) == 0) first(m) = c
               shared(m) = shared(m) .or. first(m) /= c
            end do
         end do
         alone = .true.
         single = huge(1)
         do i = 1, surface%npoint
            c = ops%cell_of_point(i)
            if (c == 0) cycle
            do v = 1, nc
               if (node(v, i) == 0) cycle
               alone(c) = alone(c) .and. .not. shared(node(v, i))
               single(c) = min(single(c), node(v, i))
            end do
         end do
         if (.not. any(alone)) return
         do i = 1, surface%npoint
            c = ops%cell_of_point(i)
            if (c == 0) cycle
            if (.not. alone(c)) cycle
            node(:, i) = 0
            phi(:, i) = 0.0_wp
            node(1, i) = single(c)
            phi(1, i) = 1.0_wp
         end do
         newid = 0
         do i = 1, surface%npoint
            do v = 1, nc
               if (node(v, i) > 0) newid(node(v, i)) = 1
            end do
         end do
         m = 0
         do j = 1, nn
            if (newid(j) == 0) cycle
            m = m + 1
            newid(j) = m
         end do
         nn = m
         call remap(newid)
      end subroutine constant_alone

      !> Every node index in node(:, :) replaced by map(index).
      subroutine remap(map)
         integer, intent(in) :: map(:)
         do i = 1, surface%npoint
            do v = 1, nc
               if (node(v, i) > 0) node(v, i) = map(node(v, i))
            end do
         end do
      end subroutine remap

      !> One node per vertex over neighbouring rows (union-find, the lower
      !> index the root) where the surface passes from one row to the other
      !> (`passes`): nodes renumbered 1..nn, node(:, :) remapped.
      subroutine join_rows(error)
         type(error_type), allocatable, intent(out) :: error
         integer, allocatable :: ptr(:), list(:), fill(:)
         allocate (parent(nn), id(nn), ptr(nn + 1), fill(nn), stat=stat)
         call check_allocation(stat, 'contact cells', 'the nodes'' classes', nn, 16, error)
         if (allocated(error)) return
         fill = 0
         do i = 1, surface%npoint
            do v = 1, nc
               if (node(v, i) > 0) fill(node(v, i)) = fill(node(v, i)) + 1
            end do
         end do
         ptr(1) = 1
         do m = 1, nn
            ptr(m + 1) = ptr(m) + fill(m)
         end do
         allocate (list(ptr(nn + 1) - 1), stat=stat)
         call check_allocation(stat, 'contact cells', 'the nodes'' points', ptr(nn + 1) - 1, 4, error)
         if (allocated(error)) return
         fill = 0
         do i = 1, surface%npoint
            do v = 1, nc
               m = node(v, i)
               if (m == 0) cycle
               list(ptr(m) + fill(m)) = i
               fill(m) = fill(m) + 1
            end do
         end do
         parent = [(m, m=1, nn)]
         do m = 1, nn
            vkey(1:d + 2) = keys(:, m)
            vkey(1 + vkey(1)) = vkey(1 + vkey(1)) + vkey(d + 2)
            r = find_key(vkey(1:d + 2), .false.)
            if (r == 0) cycle
            if (passes(list(ptr(m):ptr(m + 1) - 1), list(ptr(r):ptr(r + 1) - 1))) call join(m, r)
         end do
         nn = 0
         do m = 1, size(parent)
            r = root_of(m)
            if (r == m) then
               nn = nn + 1
               id(m) = nn
            end if
         end do
         do m = 1, size(parent)
            id(m) = id(root_of(m))
         end do
         call remap(id)
      end subroutine join_rows

      !> Whether the surface runs from the points `a` of one node to the
      !> points `b` of the node of the same vertex in the neighbouring row:
      !> a point of each within two slave-cell diagonals of each other (the
      !> points nearest the crossing of the rows' common face lie each
      !> within a cell's diagonal of it). Two parts of the surface that
      !> merely lie in neighbouring rows (the two flanks of a V-groove)
      !> keep their own nodes: one node on both would constrain only the
      !> mean of their gaps, and leave free the motions that move them
      !> oppositely.
      logical function passes(a, b)
         integer, intent(in) :: a(:), b(:)
         integer :: ia, ib
         real(wp) :: reach
         passes = .true.
         do ia = 1, size(a)
            do ib = 1, size(b)
               reach = 2.0_wp*sqrt(real(d, wp))*max(cell_size(slave, surface%slave_cell(a(ia))), &
                  & cell_size(slave, surface%slave_cell(b(ib))))
               if (norm2(surface%x(:, a(ia)) - surface%x(:, b(ib))) <= reach) return
            end do
         end do
         passes = .false.
      end function passes

      !> The node of `key` (0 if absent and not `add`).
      integer function find_key(key, add) result(found)
         integer, intent(in) :: key(:)
         logical, intent(in) :: add
         integer :: slot
         slot = int(iand(hash_int(key), int(nslot - 1, i8)))
         do
            if (table(slot) == 0) then
               found = 0
               if (.not. add) return
               nn = nn + 1
               keys(:, nn) = key
               table(slot) = nn
               found = nn
               return
            end if
            if (all(keys(:, table(slot)) == key)) then
               found = table(slot)
               return
            end if
            slot = iand(slot + 1, nslot - 1)
         end do
      end function find_key

      integer function root_of(m) result(r)
         integer, intent(in) :: m
         r = m
         do while (parent(r) /= r)
            r = parent(r)
         end do
      end function root_of

      subroutine join(a, b)
         integer, intent(in) :: a, b
         integer :: ra, rb
         ra = root_of(a)
         rb = root_of(b)
         parent(max(ra, rb)) = min(ra, rb)
      end subroutine join
   end subroutine node_cells

   !> The cells of `node_cells` from each point's nodes node(:, i) (0: none)
   !> and hats phi(:, i): nodes 1..nn, each with its points in point order.
   subroutine node_lists(node, phi, nn, ops, error)
      integer, intent(in) :: node(:, :), nn
      real(wp), intent(in) :: phi(:, :)
      type(point_operators_type), intent(inout) :: ops
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: fill(:)
      integer :: i, v, m, q, stat

      allocate (fill(nn), source=0, stat=stat)
      call check_allocation(stat, 'contact cells', 'the nodes'' points', nn, 4, error)
      if (allocated(error)) return
      do i = 1, size(node, 2)
         do v = 1, size(node, 1)
            if (node(v, i) > 0) fill(node(v, i)) = fill(node(v, i)) + 1
         end do
      end do
      if (allocated(ops%cell_ptr)) deallocate (ops%cell_ptr, ops%cell_point, ops%cell_phi)
      allocate (ops%cell_ptr(nn + 1), ops%cell_point(sum(fill)), ops%cell_phi(sum(fill)), stat=stat)
      call check_allocation(stat, 'contact cells', 'the nodes'' points', sum(fill) + nn, 12, error)
      if (allocated(error)) return
      ops%cell_ptr(1) = 1
      do m = 1, nn
         ops%cell_ptr(m + 1) = ops%cell_ptr(m) + fill(m)
      end do
      fill = 0
      do i = 1, size(node, 2)
         do v = 1, size(node, 1)
            m = node(v, i)
            if (m == 0) cycle
            q = ops%cell_ptr(m) + fill(m)
            ops%cell_point(q) = i
            ops%cell_phi(q) = phi(v, i)
            fill(m) = fill(m) + 1
         end do
      end do
      ops%ncell = nn
      ops%phi_full = ops%cell_phi
      allocate (ops%owner(size(node, 2)), source=0)
      do i = 1, size(node, 2)
         q = 0
         do v = 1, size(node, 1)
            if (node(v, i) == 0) cycle
            if (q == 0) then
               q = v
            else if (phi(v, i) > phi(q, i) .or. (phi(v, i) == phi(q, i) .and. node(v, i) < node(q, i))) then
               q = v
            end if
         end do
         if (q > 0) ops%owner(i) = node(q, i)
      end do
   end subroutine node_lists

   !> macro(e): the representative of slave root e's contact macro cell, the
   !> first root of the contact (in leaf order) with the same ancestor `shift`
   !> levels up: the parent (shift 1), or the ancestor at least twice as large
   !> as the master cells of the root's points (module notes). A macro cell
   !> whose surface turns too far (`turns_too_far`) goes one level down for
   !> all its roots, to the roots themselves at the least.
   subroutine macro_cells(surface, slave, master, macro, shift)
      type(contact_surface_type), intent(in) :: surface
      type(elasticity_problem_type), intent(in) :: slave, master
      integer, intent(out) :: macro(:)
      !> Of each root: the levels from it up to its macro cell.
      integer, intent(out) :: shift(:)
      integer, allocatable :: roots(:)
      logical :: used(size(macro)), wide(size(macro))
      integer :: i, e, r

      used = .false.
      shift = 1
      do i = 1, surface%npoint
         if (.not. surface%has_master(i)) cycle
         r = slave%root(surface%slave_cell(i))
         used(r) = .true.
         shift(r) = max(shift(r), 1 + master_levels(cell_size(master, surface%master_cell(i))/cell_size(slave, r)))
      end do
      roots = pack([(e, e=1, size(macro))], used)
      do
         call group_roots(slave, surface%dim, roots, shift, macro)
         call turns_too_far(surface, slave, macro, wide)
         wide = wide .and. shift > 0
         if (.not. any(wide(roots))) exit
         do i = 1, size(roots)
            if (wide(macro(roots(i)))) shift(roots(i)) = shift(roots(i)) - 1
         end do
      end do
   end subroutine macro_cells

   !> macro(e) for the roots `roots` with their ancestor shifts: the first
   !> root with the same level, shift and ancestor (e itself elsewhere). The
   !> groups go through a hash table of their keys (sprc_core_hash), linear
   !> in the roots: the contact surface is a user-scaled size.
   subroutine group_roots(slave, d, roots, shift, macro)
      type(elasticity_problem_type), intent(in) :: slave
      integer, intent(in) :: d, roots(:), shift(:)
      integer, intent(out) :: macro(:)
      integer, allocatable :: table(:)
      integer :: i, e, r, slot, nslot, key(d + 2)

      macro = [(e, e=1, size(macro))]
      nslot = 2
      do while (nslot < 2*size(roots))
         nslot = 2*nslot
      end do
      allocate (table(0:nslot - 1))
      table = 0
      do i = 1, size(roots)
         r = roots(i)
         key = root_key(r)
         slot = int(iand(hash_int(key), int(nslot - 1, i8)))
         do
            if (table(slot) == 0) then
               table(slot) = r
               exit
            end if
            if (all(root_key(table(slot)) == key)) then
               macro(r) = macro(table(slot))
               exit
            end if
            slot = iand(slot + 1, nslot - 1)
         end do
      end do
   contains
      !> A root's group: its level, its shift and its ancestor's coordinates.
      pure function root_key(e) result(k)
         integer, intent(in) :: e
         integer :: k(d + 2)
         k(1) = slave%mesh%grid%leaf_level(e)
         k(2) = shift(e)
         k(3:) = slave%mesh%grid%leaf_coord(1:d, e)/2**shift(e)
      end function root_key
   end subroutine group_roots

   !> The levels a contact cell of two slave cells goes up so that it spans
   !> two master cells, for master cells `ratio` times the slave's: the
   !> nearest power of two at or above the ratio, the ratio first divided by
   !> `master_ratio_tol` (a master cell at most that much larger counts as
   !> the same size; module notes).
   pure integer function master_levels(ratio)
      real(wp), intent(in) :: ratio
      master_levels = max(0, ceiling(log(ratio/master_ratio_tol)/log(2.0_wp)))
   end function master_levels

   !> wide(m): the points of macro cell m (representative m) have a normal
   !> more than `max_turn` from the cell's mean normal. A cell's multiplier is
   !> one vector in the cell's frame (module notes), its constraint the mean
   !> gap over the cell: a cell around a whole ring (a coarse level, a fit
   !> with no symmetry planes) has no mean normal and constrains neither a
   !> translation nor, with stick, the rotation; at most a quarter turn each,
   !> a closed curve has at least four cells whose mean normals hold both
   !> translations and, with stick, the rotation (a closed surface at least
   !> six).
   subroutine turns_too_far(surface, slave, macro, wide)
      type(contact_surface_type), intent(in) :: surface
      type(elasticity_problem_type), intent(in) :: slave
      integer, intent(in) :: macro(:)
      logical, intent(out) :: wide(:)
      real(wp) :: nsum(surface%dim, size(macro)), len
      integer :: i, m

      nsum = 0.0_wp
      do i = 1, surface%npoint
         if (.not. surface%has_master(i)) cycle
         m = macro(slave%root(surface%slave_cell(i)))
         nsum(:, m) = nsum(:, m) + surface%weight(i)*surface%normal(:, i)
      end do
      wide = .false.
      do i = 1, surface%npoint
         if (.not. surface%has_master(i)) cycle
         m = macro(slave%root(surface%slave_cell(i)))
         len = norm2(nsum(:, m))
         if (wide(m)) cycle
         ! A mean normal of exactly zero (normals that cancel) is the widest turn of all.
         wide(m) = .not. (len > 0.0_wp .and. dot_product(surface%normal(:, i), nsum(:, m)) >= cos_max_turn*len)
      end do
   end subroutine turns_too_far

   !> The means and deviations of cell c's operators on the union of its
   !> points' dofs (module notes): normal rows (frictionless) or all
   !> components (stick).
   pure subroutine cell_operators(surface, ops, c, friction, cell, error)
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(in) :: ops
      integer, intent(in) :: c, friction
      type(cell_operators_type), intent(out) :: cell
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: pos(:)
      real(wp), allocatable :: g(:, :)
      integer :: j, i, q, q0, q1, np, d, stat
      real(wp) :: nrm(surface%dim), rt(surface%dim, surface%dim), npt(surface%dim, ops%cell_ptr(c + 1) - ops%cell_ptr(c))
      real(wp) :: wi

      d = surface%dim
      np = ops%cell_ptr(c + 1) - ops%cell_ptr(c)
      cell%rows = merge(d, 1, friction == friction_stick)
      allocate (cell%dofs(0), stat=stat)
      call check_allocation(stat, 'contact cell '//itoa(c), 'its dofs', 0, 4, error)
      if (allocated(error)) return
      do j = ops%cell_ptr(c), ops%cell_ptr(c + 1) - 1
         i = ops%cell_point(j)
         do q = ops%ptr(i), ops%ptr(i + 1) - 1
            if (.not. any(cell%dofs == ops%dofs(q))) cell%dofs = [cell%dofs, ops%dofs(q)]
         end do
      end do
      cell%nu = size(cell%dofs)
      allocate (cell%gbar(cell%rows, cell%nu), cell%tbar(cell%rows, cell%nu), cell%g0bar(cell%rows), &
         & cell%tdev(cell%rows, cell%nu, np), cell%w(np), g(cell%rows, cell%nu), cell%rot(d, d, np), stat=stat)
      call check_allocation(stat, 'contact cell '//itoa(c), 'its operators', cell%rows*cell%nu*(np + 3) + d*d*np, &
         & 8, error)
      if (allocated(error)) return
      associate (pts => ops%cell_point(ops%cell_ptr(c):ops%cell_ptr(c + 1) - 1))
         cell%w = surface%weight(pts)*ops%cell_phi(ops%cell_ptr(c):ops%cell_ptr(c + 1) - 1)
         do j = 1, np
            npt(:, j) = contact_normal(surface, pts(j), friction)
         end do
         cell%nbar = matmul(npt, cell%w)
         cell%nbar = cell%nbar/norm2(cell%nbar)
      end associate
      cell%gbar = 0.0_wp
      cell%tbar = 0.0_wp
      cell%g0bar = 0.0_wp
      cell%tdev = 0.0_wp
      do j = 1, np
         i = ops%cell_point(ops%cell_ptr(c) + j - 1)
         wi = cell%w(j)
         q0 = ops%ptr(i)
         q1 = ops%ptr(i + 1) - 1
         nrm = surface%normal(:, i)
         cell%rot(:, :, j) = frame_rotation(cell%nbar, npt(:, j))
         pos = [(findloc(cell%dofs, ops%dofs(q), 1), q = q0, q1)]
         g = 0.0_wp
         if (friction == friction_stick) then
            rt = transpose(cell%rot(:, :, j))
            g(:, pos) = matmul(rt, ops%gop(:, q0:q1))
            cell%tdev(:, pos, j) = matmul(rt, ops%top(:, q0:q1))
            cell%g0bar = cell%g0bar + wi*surface%g0(i)*dot_product(nrm, surface%master_normal(:, i))* &
               & matmul(rt, surface%master_normal(:, i))
         else
            g(1, pos) = matmul(nrm, ops%gop(:, q0:q1))
            cell%tdev(1, pos, j) = matmul(nrm, ops%top(:, q0:q1))
            cell%g0bar = cell%g0bar + wi*surface%g0(i)
         end if
         cell%gbar = cell%gbar + wi*g
         cell%tbar = cell%tbar + wi*cell%tdev(:, :, j)
      end do
      cell%measure = sum(cell%w)
      cell%gbar = cell%gbar/cell%measure
      cell%tbar = cell%tbar/cell%measure
      cell%g0bar = cell%g0bar/cell%measure
      do j = 1, np
         cell%tdev(:, :, j) = cell%tdev(:, :, j) - cell%tbar
      end do
   end subroutine cell_operators

   !> The unit contact normal of point i: the slave normal (frictionless) or
   !> the bisector n_s - n_m of both surfaces' normals (stick and Coulomb:
   !> the contact plane, the same whichever body is the slave).
   pure function contact_normal(surface, i, friction) result(n)
      type(contact_surface_type), intent(in) :: surface
      integer, intent(in) :: i, friction
      real(wp) :: n(surface%dim)
      if (friction == friction_stick) then
         n = surface%normal(:, i) - surface%master_normal(:, i)
         n = n/norm2(n)
      else
         n = surface%normal(:, i)
      end if
   end function contact_normal

   !> The rotation R in the plane of the unit vectors a and b that carries a
   !> to b (identity on the complement; 2D and 3D alike):
   !>   R = I - (a + b)(a + b)^T/(1 + a.b) + 2 b a^T.
   !> Its columns move the cell frame to a point's by the least rotation, so
   !> that a multiplier R_i lambda_c keeps its normal and tangential parts
   !> along the curved surface (module notes).
   pure function frame_rotation(a, b) result(r)
      real(wp), intent(in) :: a(:), b(:)
      real(wp) :: r(size(a), size(a))
      integer :: k
      r = 2.0_wp*spread(b, 2, size(a))*spread(a, 1, size(a)) &
         & - spread(a + b, 2, size(a))*spread(a + b, 1, size(a))/(1.0_wp + dot_product(a, b))
      do k = 1, size(a)
         r(k, k) = r(k, k) + 1.0_wp
      end do
   end function frame_rotation

   !> Reduced operators of `problem` at x in element e: dofs(1:m), the
   !> displacement n(dim, m) and the traction sigma(u) nrm, t(dim, m).
   subroutine body_operators(problem, e, x, nrm, dofs, n, t, m, error)
      type(elasticity_problem_type), intent(in) :: problem
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:), nrm(:)
      integer, allocatable, intent(out) :: dofs(:)
      real(wp), allocatable, intent(out) :: n(:, :), t(:, :)
      integer, intent(out) :: m
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: lo(3), hi(3)
      real(wp) :: sh(problem%nen), dndx(problem%dim, problem%nen), b(problem%nstress, problem%dim*problem%nen)
      real(wp) :: nmat(problem%dim, problem%dim*problem%nen), tn(problem%dim, problem%nstress)
      real(wp), allocatable :: tmat(:, :)
      integer :: d, nd, ns, stat

      d = problem%dim
      nd = d*problem%nen
      ns = problem%nstress
      allocate (dofs(nd*32), tmat(nd, nd*32), stat=stat)
      call check_allocation(stat, 'contact operators', 'an element''s constraint map', nd*32, 4 + 8*nd, error)
      if (allocated(error)) return
      call problem%constraints%element_map(problem%mesh%nodes%connectivity(:, e), dofs, tmat, m)
      call problem%element_box(e, lo(1:d), hi(1:d))
      call shape_functions(d, problem%degree, lo(1:d), hi(1:d), x, sh, dndx)
      call strain_matrix(d, dndx, b)
      call displacement_matrix(d, sh, nmat)
      call traction_matrix(d, nrm, tn)
      n = matmul(nmat, tmat(:, 1:m))
      t = matmul(matmul(tn, matmul(problem%d(1:ns, 1:ns), b)), tmat(:, 1:m))
   end subroutine body_operators

   !> The block system [K_s 0; 0 K_m] + contact terms of the closed cells,
   !> and its load (module notes); with `pstar` (each cell's mean
   !> stabilization traction, `cell_tractions`) those of the recovered
   !> stabilization.
   subroutine block_system(slave, master, ops, cells, closed, k, f, error, pstar)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      type(csr_type), intent(out) :: k
      real(wp), allocatable, intent(out) :: f(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: pstar(:, :)
      type(coo_type) :: coo
      real(wp), allocatable :: kc(:, :)
      integer(i8) :: capacity
      integer :: ns, c

      ns = slave%n_dofs()
      capacity = slave%k%nnz() + master%k%nnz()
      do c = 1, size(cells)
         if (closed(c)) capacity = capacity + int(cells(c)%nu, i8)**2
      end do
      call coo%init(ns + master%n_dofs(), ns + master%n_dofs(), error, capacity=capacity)
      if (allocated(error)) return
      call add_csr(coo, slave%k, 0, error)
      if (.not. allocated(error)) call add_csr(coo, master%k, ns, error)
      if (allocated(error)) return
      do c = 1, size(cells)
         if (.not. closed(c)) cycle
         associate (cell => cells(c), gamma => ops%gamma(c))
            if (present(pstar)) then
               kc = (cell%measure*gamma)*matmul(transpose(cell%gbar), cell%gbar)
            else
               call tied_block(cell, gamma, kc)
            end if
            call coo%add(cell%dofs, kc, error)
            if (allocated(error)) return
         end associate
      end do
      call coo%to_csr(k, error)
      if (.not. allocated(error)) call block_load(slave, master, ops, cells, closed, f, pstar)
   end subroutine block_system

   !> The block system of `block_system` (FE stabilization) on a pattern
   !> kept across active sets for the iterative solver, whose set-up then
   !> redoes only its numeric part (`petsc_solver_type%update`): both
   !> bodies' K and the blocks of every cell closed in any set so far
   !> (`bs%cover`), explicit zeros where a cell is open. A set that closes a
   !> cell outside the pattern widens it.
   subroutine kept_system(slave, master, ops, cells, closed, bs, k, f, error)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      type(block_solver_type), intent(inout) :: bs
      type(csr_type), intent(inout) :: k
      real(wp), allocatable, intent(out) :: f(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: kc(:, :)
      integer :: c

      if (.not. allocated(bs%cover)) allocate (bs%cover(size(closed)), source=.false.)
      if (any(closed .and. .not. bs%cover) .or. .not. allocated(bs%base)) then
         bs%cover = bs%cover .or. closed
         call cover_pattern(slave, master, cells, bs%cover, k, error)
         if (allocated(error)) return
         bs%base = k%val
      else
         k%val = bs%base
      end if
      do c = 1, size(cells)
         if (.not. closed(c)) cycle
         call tied_block(cells(c), ops%gamma(c), kc)
         call add_block(k, cells(c)%dofs, kc)
      end do
      call block_load(slave, master, ops, cells, closed, f)
   end subroutine kept_system

   !> Both bodies' K with explicit zeros at the entries of the cells `cover`.
   subroutine cover_pattern(slave, master, cells, cover, k, error)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: cover(:)
      type(csr_type), intent(out) :: k
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      integer(i8) :: capacity
      integer :: ns, c

      ns = slave%n_dofs()
      capacity = slave%k%nnz() + master%k%nnz() + sum(int(cells%nu, i8)**2, mask=cover)
      call coo%init(ns + master%n_dofs(), ns + master%n_dofs(), error, capacity=capacity)
      if (.not. allocated(error)) call add_csr(coo, slave%k, 0, error)
      if (.not. allocated(error)) call add_csr(coo, master%k, ns, error)
      do c = 1, size(cells)
         if (allocated(error)) return
         if (cover(c)) call coo%add(cells(c)%dofs, spread(spread(0.0_wp, 1, cells(c)%nu), 2, cells(c)%nu), error)
      end do
      if (.not. allocated(error)) call coo%to_csr(k, error)
   end subroutine cover_pattern

   !> k(dofs(i), dofs(j)) += b(i, j), every entry in k's pattern (columns
   !> ascending in each row: found by bisection).
   pure subroutine add_block(k, dofs, b)
      type(csr_type), intent(inout) :: k
      integer, intent(in) :: dofs(:)
      real(wp), intent(in) :: b(:, :)
      integer(i8) :: lo, hi, mid
      integer :: i, j

      do i = 1, size(dofs)
         do j = 1, size(dofs)
            lo = k%rowptr(dofs(i))
            hi = k%rowptr(dofs(i) + 1) - 1
            do while (lo < hi)
               mid = (lo + hi)/2
               if (k%col(mid) < dofs(j)) then
                  lo = mid + 1
               else
                  hi = mid
               end if
            end do
            k%val(lo) = k%val(lo) + b(i, j)
         end do
      end do
   end subroutine add_block

   !> The load of `block_system`.
   pure subroutine block_load(slave, master, ops, cells, closed, f, pstar)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      real(wp), allocatable, intent(out) :: f(:)
      real(wp), intent(in), optional :: pstar(:, :)
      integer :: c

      f = [slave%f, master%f]
      do c = 1, size(cells)
         if (.not. closed(c)) cycle
         associate (cell => cells(c), gamma => ops%gamma(c))
            if (present(pstar)) then
               f(cell%dofs) = f(cell%dofs) - cell%measure*matmul(pstar(1:cell%rows, c) + gamma*cell%g0bar, cell%gbar)
            else
               f(cell%dofs) = f(cell%dofs) - cell%measure*matmul(cell%g0bar, cell%tbar + gamma*cell%gbar)
            end if
         end associate
      end do
   end subroutine block_load

   !> One active-set iteration of the recovered stabilization with a kept
   !> factor: while the active set is the factor's, only the load is built
   !> and the factor solves it; else the block system is assembled, checked
   !> for free rigid modes and factorized (CHOLMOD: SPD for every gamma),
   !> replacing the factor.
   subroutine factored_solve(slave, master, ops, cells, closed, pstar, names, it, factor, x, sol, error, share, &
         & bounds)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      real(wp), intent(in) :: pstar(:, :)
      character(len=*), intent(in) :: names(2)
      integer, intent(in) :: it
      type(contact_factor_type), intent(inout) :: factor
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      class(share_type), intent(in), optional :: share
      integer(i8), intent(in), optional :: bounds(:)
      type(csr_type) :: k
      real(wp), allocatable :: f(:)
      logical :: same

      same = .false.
      if (allocated(factor%closed)) same = size(factor%closed) == size(closed)
      if (same) same = all(factor%closed .eqv. closed)
      if (same) then
         call block_load(slave, master, ops, cells, closed, f, pstar)
      else
         call factor%chol%destroy()
         if (allocated(factor%closed)) deallocate (factor%closed)
         call block_system(slave, master, ops, cells, closed, k, f, error, pstar)
         if (.not. allocated(error)) &
            & call check_held(slave, master, k, names, closed_points(ops, closed), it, error, share, bounds)
         if (allocated(error)) return
         if (factor%bs%iterative) then
            call krylov_setup(factor%bs%krylov, k, .true., error)
         else
            call factor%chol%factorize(k, error)
         end if
         if (allocated(error)) return
         factor%closed = closed
      end if
      if (factor%bs%iterative) then
         call krylov_solve(factor%bs%krylov, f, x, sol, error)
         return
      end if
      sol%solver_name = 'cholmod'
      sol%rcond = factor%chol%rcond_estimate
      call factor%chol%solve(f, x, error)
      if (allocated(error)) error%message = 'contact solve (CHOLMOD): '//error%message
   end subroutine factored_solve

   !> Release a contact factor.
   subroutine factor_destroy(self)
      class(contact_factor_type), intent(inout) :: self
      call self%chol%destroy()
      call self%bs%krylov%destroy()
      self%bs%ready = .false.
      if (allocated(self%closed)) deallocate (self%closed)
   end subroutine factor_destroy

   !> The block of a closed cell whose rows are all tied (frictionless: the
   !> normal row; stick: every component): W [T^T G + G^T T + gamma G^T G] -
   !> 1/gamma sum_i w_i dT_i^T dT_i (module notes); its load is
   !> -W (T + gamma G)^T g0.
   pure subroutine tied_block(cell, gamma, kc)
      type(cell_operators_type), intent(in) :: cell
      real(wp), intent(in) :: gamma
      real(wp), allocatable, intent(out) :: kc(:, :)
      kc = cell%measure*(matmul(transpose(cell%tbar), cell%gbar) + matmul(transpose(cell%gbar), cell%tbar) &
         & + gamma*matmul(transpose(cell%gbar), cell%gbar))
      call add_variance(cell, gamma, kc)
   end subroutine tied_block

   !> The stabilization's variance term of a closed cell, -1/gamma sum_i w_i
   !> dT_i^T dT_i over every row of the cell's operators (module notes).
   pure subroutine add_variance(cell, gamma, kc)
      type(cell_operators_type), intent(in) :: cell
      real(wp), intent(in) :: gamma
      real(wp), intent(inout) :: kc(:, :)
      integer :: j
      do j = 1, size(cell%w)
         kc = kc - (cell%w(j)/gamma)*matmul(transpose(cell%tdev(:, :, j)), cell%tdev(:, :, j))
      end do
   end subroutine add_variance

   !> Add the entries of a (rows and columns shifted by `shift`) to coo.
   subroutine add_csr(coo, a, shift, error)
      type(coo_type), intent(inout) :: coo
      type(csr_type), intent(in) :: a
      integer, intent(in) :: shift
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      integer(i8) :: q
      do i = 1, a%nrows
         do q = a%rowptr(i), a%rowptr(i + 1) - 1
            call coo%add(i + shift, a%col(q) + shift, a%val(q), error)
            if (allocated(error)) return
         end do
      end do
   end subroutine add_csr

   !> Coulomb friction (module notes): for each increment (column n of the
   !> load path `loads`, the block system's load at the end of the increment)
   !> an iteration on the cells' states (open, stick, slip) and slip
   !> directions, solved with UMFPACK (the slip terms are unsymmetric); the
   !> slip of each cell is history.
   subroutine solve_coulomb(slave, master, ops, cells, closed, mu, loads, names, maxit, bs, x, sol, state, tau, slip, &
         & error, progress)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      real(wp), intent(in) :: mu, loads(:, :)
      character(len=*), intent(in) :: names(2)
      integer, intent(in) :: maxit
      type(block_solver_type), intent(inout) :: bs
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      !> Final state of each cell, its slip direction (slipping cells) and its slip (history).
      integer, allocatable, intent(out) :: state(:)
      real(wp), allocatable, intent(out) :: tau(:, :), slip(:, :)
      type(error_type), allocatable, intent(out) :: error
      procedure(contact_progress), optional :: progress
      type(csr_type) :: k
      type(timer_type) :: timer
      real(wp), allocatable :: tau_new(:, :), f(:)
      integer, allocatable :: state_new(:)
      integer :: n, it, c, d, changed, switched, stat

      d = slave%dim
      allocate (slip(d, size(cells)), tau(d, size(cells)), tau_new(d, size(cells)), stat=stat)
      call check_allocation(stat, 'contact solve (Coulomb)', 'the slips and slip directions', size(cells), 24*d, error)
      if (allocated(error)) return
      slip = 0.0_wp
      tau = 0.0_wp
      state = merge(contact_stick, contact_open, closed)
      state_new = state
      do n = 1, size(loads, 2)
         do it = 1, maxit
            sol%iterations = sol%iterations + 1
            call timer%reset()
            call timer%start()
            ! The rigid-mode check on the symmetric part without the friction
            ! terms (which resist no rigid motion): the system with mu = 0.
            call coulomb_system(slave, master, ops, cells, state, tau, slip, 0.0_wp, loads(:, n), k, f, error)
            if (.not. allocated(error)) &
               & call check_held(slave, master, k, names, closed_points(ops, state /= contact_open), &
               & sol%iterations, error)
            if (.not. allocated(error) .and. any(state == contact_slip)) &
               & call coulomb_system(slave, master, ops, cells, state, tau, slip, mu, loads(:, n), k, f, error)
            if (.not. allocated(error)) then
               if (bs%iterative) then
                  call iterative_block(bs%krylov, k, f, .not. any(state == contact_slip), x, sol, error)
               else
                  call solve_unsymmetric(k, f, x, sol, error)
               end if
            end if
            call timer%stop()
            sol%t_solve = sol%t_solve + timer%elapsed
            if (allocated(error)) return
            call coulomb_states(ops, cells, mu, slip, x, state, tau, state_new, tau_new)
            changed = 0
            switched = 0
            do c = 1, size(cells)
               if (state_new(c) == state(c)) then
                  if (state(c) /= contact_slip) cycle
                  if (.not. norm2(tau_new(:, c) - tau(:, c)) > direction_tol) cycle
               end if
               changed = changed + 1
               switched = switched + ops%cell_ptr(c + 1) - ops%cell_ptr(c)
            end do
            if (present(progress)) call progress(n, size(loads, 2), it, switched)
            state = state_new
            tau = tau_new
            if (changed == 0) exit
            if (it == maxit) then
               call fatal_error(error, "contact '"//trim(names(1))//"' on '"//trim(names(2))//"', increment "// &
                  & itoa(n)//': the stick/slip states did not settle in '//itoa(maxit)//' iterations; '// &
                  & itoa(changed)//' of '//itoa(size(cells))//' contact cells still changed in the last one', &
                  & stat_not_converged)
               return
            end if
         end do
         call update_slip(ops, cells, mu, state, tau, x, slip)
      end do
   end subroutine solve_coulomb

   !> The block system with the Coulomb terms of the closed cells: stick
   !> cells tied (vector gap less the cell's slip), slip cells the normal
   !> terms and the friction traction -mu lambda_n tau (module notes).
   subroutine coulomb_system(slave, master, ops, cells, state, tau, slip, mu, load, k, f, error)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      integer, intent(in) :: state(:)
      real(wp), intent(in) :: tau(:, :), slip(:, :), mu, load(:)
      type(csr_type), intent(out) :: k
      real(wp), allocatable, intent(out) :: f(:)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      real(wp), allocatable :: kc(:, :), gn(:), tn(:), gt(:), tt(:)
      integer(i8) :: capacity
      integer :: ns, c

      ns = slave%n_dofs()
      capacity = slave%k%nnz() + master%k%nnz()
      do c = 1, size(cells)
         if (state(c) /= contact_open) capacity = capacity + int(cells(c)%nu, i8)**2
      end do
      call coo%init(ns + master%n_dofs(), ns + master%n_dofs(), error, capacity=capacity)
      if (allocated(error)) return
      call add_csr(coo, slave%k, 0, error)
      if (.not. allocated(error)) call add_csr(coo, master%k, ns, error)
      if (allocated(error)) return
      f = load
      do c = 1, size(cells)
         if (state(c) == contact_open) cycle
         associate (cell => cells(c), gamma => ops%gamma(c), nb => cells(c)%nbar)
            if (state(c) == contact_stick) then
               call tied_block(cell, gamma, kc)
               f(cell%dofs) = f(cell%dofs) - cell%measure*matmul(cell%g0bar - slip(:, c), cell%tbar + gamma*cell%gbar)
            else
               gn = matmul(nb, cell%gbar)
               tn = matmul(nb, cell%tbar)
               gt = matmul(tau(:, c), cell%gbar)
               tt = matmul(tau(:, c), cell%tbar)
               kc = cell%measure*(outer(tn, gn) + outer(gn, tn) + gamma*outer(gn, gn) - outer(tt, tt)/gamma &
                  & - mu*outer(gt + tt/gamma, tn + gamma*gn))
               call add_variance(cell, gamma, kc)
               f(cell%dofs) = f(cell%dofs) - cell%measure*dot_product(nb, cell%g0bar)*(tn + gamma*gn - mu*(gamma*gt + tt))
            end if
            call coo%add(cell%dofs, kc, error)
            if (allocated(error)) return
         end associate
      end do
      call coo%to_csr(k, error)
   end subroutine coulomb_system

   pure function outer(a, b) result(m)
      real(wp), intent(in) :: a(:), b(:)
      real(wp) :: m(size(a), size(b))
      m = spread(a, 2, size(b))*spread(b, 1, size(a))
   end function outer

   !> The cells' multiplier lambda = tbar u + gamma (gbar u + g0bar - slip),
   !> its normal part along nbar and tangential part.
   pure subroutine cell_multiplier(ops, cells, c, slip, x, lam_n, lam_t)
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      integer, intent(in) :: c
      real(wp), intent(in) :: slip(:), x(:)
      real(wp), intent(out) :: lam_n, lam_t(:)
      real(wp) :: lam(size(slip))
      associate (cell => cells(c))
         lam = matmul(cell%tbar + ops%gamma(c)*cell%gbar, x(cell%dofs)) + ops%gamma(c)*(cell%g0bar - slip)
         lam_n = dot_product(lam, cell%nbar)
         lam_t = lam - lam_n*cell%nbar
      end associate
   end subroutine cell_multiplier

   !> Trial states: open where lambda_n >= 0, stick where |lambda_t| <= mu
   !> (-lambda_n), else slip along tau = lambda_t/|lambda_t|; but a cell that
   !> slipped along tau_old and whose trial now points against it (tau .
   !> tau_old < 0) sticks: its friction traction cannot pass from mu p tau_old
   !> to -mu p tau_old without crossing the stick range, where the trial,
   !> continuous in the friction traction, changes sign (module notes).
   pure subroutine coulomb_states(ops, cells, mu, slip, x, state_old, tau_old, state, tau)
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      real(wp), intent(in) :: mu, slip(:, :), x(:), tau_old(:, :)
      integer, intent(in) :: state_old(:)
      integer, intent(out) :: state(:)
      real(wp), intent(out) :: tau(:, :)
      real(wp) :: lam_n, lam_t(size(slip, 1))
      integer :: c
      tau = 0.0_wp
      do c = 1, size(cells)
         call cell_multiplier(ops, cells, c, slip(:, c), x, lam_n, lam_t)
         if (lam_n >= 0.0_wp) then
            state(c) = contact_open
         else if (norm2(lam_t) <= -mu*lam_n) then
            state(c) = contact_stick
         else if (state_old(c) == contact_slip .and. dot_product(lam_t, tau_old(:, c)) < 0.0_wp) then
            state(c) = contact_stick
         else
            state(c) = contact_slip
            tau(:, c) = lam_t/norm2(lam_t)
         end if
      end do
   end subroutine coulomb_states

   !> History at the end of an increment: a slipping cell's slip moves so that
   !> its trial tangential multiplier is the friction traction mu p tau; an
   !> open cell's slip follows the relative tangential displacement (it
   !> closes stuck where it is); a stuck cell keeps its slip.
   pure subroutine update_slip(ops, cells, mu, state, tau, x, slip)
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      real(wp), intent(in) :: mu, tau(:, :), x(:)
      integer, intent(in) :: state(:)
      real(wp), intent(inout) :: slip(:, :)
      real(wp) :: lam_n, lam_t(size(slip, 1))
      integer :: c
      do c = 1, size(cells)
         if (state(c) == contact_stick) cycle
         call cell_multiplier(ops, cells, c, slip(:, c), x, lam_n, lam_t)
         if (state(c) == contact_slip) then
            slip(:, c) = slip(:, c) + (lam_t + mu*lam_n*tau(:, c))/ops%gamma(c)
         else
            slip(:, c) = slip(:, c) + lam_t/ops%gamma(c)
         end if
      end do
   end subroutine update_slip

   !> Per point: closed, slipping, pressure and tangential traction of its cell.
   subroutine coulomb_output(ops, cells, mu, state, tau, slip, x, sol)
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      real(wp), intent(in) :: mu, tau(:, :), slip(:, :), x(:)
      integer, intent(in) :: state(:)
      type(contact_solution_type), intent(inout) :: sol
      real(wp) :: lam_n, lam_t(size(slip, 1)), largest(size(sol%pressure))
      integer :: c, i, j

      largest = 0.0_wp
      do c = 1, size(cells)
         call cell_multiplier(ops, cells, c, slip(:, c), x, lam_n, lam_t)
         sol%lambda_n(c) = lam_n
         do j = ops%cell_ptr(c), ops%cell_ptr(c + 1) - 1
            i = ops%cell_point(j)
            ! A point's state is that of its largest basis function's cell.
            if (ops%cell_phi(j) > largest(i)) then
               largest(i) = ops%cell_phi(j)
               sol%closed(i) = state(c) /= contact_open
               sol%slipping(i) = state(c) == contact_slip
            end if
         end do
         if (state(c) == contact_open) cycle
         if (state(c) == contact_slip) lam_t = -mu*lam_n*tau(:, c)
         do j = ops%cell_ptr(c), ops%cell_ptr(c + 1) - 1
            i = ops%cell_point(j)
            sol%pressure(i) = sol%pressure(i) - ops%cell_phi(j)*lam_n
            sol%traction_t(:, i) = sol%traction_t(:, i) + &
               & ops%cell_phi(j)*matmul(cells(c)%rot(:, :, j - ops%cell_ptr(c) + 1), lam_t)
         end do
      end do
      sol%tangential = norm2(sol%traction_t, dim=1)
   end subroutine coulomb_output

   !> Solve the unsymmetric block system with UMFPACK.
   subroutine solve_unsymmetric(k, f, x, sol, error)
      type(csr_type), intent(in) :: k
      real(wp), intent(in) :: f(:)
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: lu

      sol%solver_name = 'umfpack'
      call lu%factorize(k, error)
      if (.not. allocated(error)) then
         sol%rcond = lu%rcond_estimate
         call lu%solve(f, x, error)
      end if
      call lu%destroy()
      if (allocated(error)) error%message = 'contact solve (UMFPACK): '//error%message
   end subroutine solve_unsymmetric

   !> Every rigid-body mode of both bodies must be resisted by the block
   !> system; a free one is an error naming the body (module notes). With
   !> `share`, k holds this rank's rows of `bounds` (`solve_contact_pair`).
   subroutine check_held(slave, master, k, names, nclosed, iteration, error, share, bounds)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(csr_type), intent(in) :: k
      character(len=*), intent(in) :: names(2)
      integer, intent(in) :: nclosed, iteration
      type(error_type), allocatable, intent(out) :: error
      class(share_type), intent(in), optional :: share
      integer(i8), intent(in), optional :: bounds(:)
      real(wp), allocatable :: rs(:, :), rm(:, :), r(:, :), vec(:, :)
      logical :: involved(12)
      integer :: nfree, j, ns, ms, b, stat
      character(len=:), allocatable :: what

      call slave%rigid_modes(rs, error)
      if (.not. allocated(error)) call master%rigid_modes(rm, error)
      if (allocated(error)) return
      ns = size(rs, 2)
      ms = size(rm, 2)
      allocate (r(size(rs, 1) + size(rm, 1), ns + ms), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact rigid-mode check', 'the rigid-body motions of both bodies', &
         & int(size(rs, 1) + size(rm, 1), i8)*(ns + ms), 8, error)
      if (allocated(error)) return
      r(1:size(rs, 1), 1:ns) = rs
      r(size(rs, 1) + 1:, ns + 1:) = rm
      call free_motions(k, r, vec, nfree, error, share, bounds)
      if (allocated(error) .or. nfree == 0) return
      involved = .false.
      do j = 1, nfree
         involved(1:ns + ms) = involved(1:ns + ms) .or. abs(vec(:, j)) >= 0.2_wp*maxval(abs(vec(:, j)))
      end do
      what = ''
      do b = 1, 2
         associate (flags => involved((b - 1)*ns + 1:b*ns))
            if (.not. any(flags)) cycle
            if (len(what) > 0) what = what//'; '
            what = what//"body '"//trim(names(b))//"' is not held: "//motion_names(slave%dim, flags)//' free'
         end associate
      end do
      call fatal_error(error, what//' (contact '''//trim(names(1))//''' on '''//trim(names(2))// &
         & ''', active-set iteration '//itoa(iteration)//', '//itoa(nclosed)//' closed points): a body held '// &
         & 'only by contact has lost it, or its conditions leave it free', stat_singular)
   end subroutine check_held

   !> Solve the symmetric block system: directly (CHOLMOD, UMFPACK if not
   !> SPD) or iteratively (`iterative_block`), as `bs` was set up.
   subroutine solve_block(bs, k, f, x, sol, error)
      type(block_solver_type), intent(inout) :: bs
      type(csr_type), intent(in) :: k
      real(wp), intent(in) :: f(:)
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: note
      if (bs%iterative) then
         bs%krylov%tolerance = bs%loose
         call iterative_block(bs%krylov, k, f, .true., x, sol, error)
         return
      end if
      call solve_spd_or_lu(k, f, x, sol%rcond, sol%solver_name, note, error)
      if (allocated(error)) error%message = 'contact solve'//error%message
   end subroutine solve_block

   !> Decide between the direct and the iterative solver (module notes) and,
   !> for the iterative one, set up the block layout of both bodies and their
   !> stacked multigrid hierarchy; nothing happens when `bs` is ready.
   subroutine block_solver_setup(slave, master, ops, kappa, bs, error)
      type(elasticity_problem_type), intent(in) :: slave, master
      type(point_operators_type), intent(in) :: ops
      !> The contact stabilization factor (`active_set_tolerance`).
      real(wp), intent(in) :: kappa
      type(block_solver_type), intent(inout) :: bs
      type(error_type), allocatable, intent(out) :: error
      type(prolongation_type), allocatable :: ps(:), pm(:), p(:)
      integer, allocatable :: dof(:, :)
      logical, allocatable :: touched(:)
      integer :: ns
      logical :: found_s, found_m
      real(wp) :: h_over_l

      if (bs%ready) return
      bs%iterative = pair_iterative(slave, master)
      bs%ready = .true.
      if (.not. bs%iterative) return
      call start_petsc(error)
      if (allocated(error)) return
      ns = slave%n_dofs()
      associate (cs => slave%constraints, cm => master%constraints)
         dof = reshape([cs%dof, merge(cm%dof + ns, 0, cm%dof > 0)], [slave%dim, cs%n_masters + cm%n_masters])
         call bs%krylov%set_blocks(dof, reshape([slave%mesh%nodes%x(:, cs%master_node), &
            & master%mesh%nodes%x(:, cm%master_node)], shape(dof)), error)
         if (allocated(error)) return
         ! the masters a contact point's operators act on are kept on every level (sprc_fem_multigrid)
         allocate (touched(0:slave%n_dofs() + master%n_dofs()), source=.false.)
         touched(ops%dofs) = .true.
         call master_hierarchy(slave, ps, found_s, error, keep=kept_masters(touched, dof(:, :cs%n_masters)))
         if (.not. allocated(error)) call master_hierarchy(master, pm, found_m, error, &
            & keep=kept_masters(touched, dof(:, cs%n_masters + 1:)))
         if (allocated(error)) return
         if (found_s .and. found_m) then
            call stack_hierarchies(ps, cs%n_masters, pm, cm%n_masters, p, error)
            if (.not. allocated(error)) call bs%krylov%set_hierarchy(p, error)
            if (allocated(error)) return
         end if
      end associate
      h_over_l = 0.5_wp**max(slave%mesh%grid%max_level, master%mesh%grid%max_level)
      bs%tight = contact_tolerance(h_over_l, slave%degree, slave%dim, kappa)
      bs%careful = max(active_set_tolerance(h_over_l, slave%dim, kappa), bs%tight)
      bs%loose = max(changing_set_tolerance(h_over_l, slave%dim), bs%careful)
      bs%krylov%tolerance = bs%tight
   end subroutine block_solver_setup

   !> Whether the block system of the pair is solved iteratively (module
   !> notes): the bodies' solver settings (iterative if either asks for it)
   !> by `use_iterative`'s rule for coupled systems.
   pure logical function pair_iterative(slave, master)
      type(elasticity_problem_type), intent(in) :: slave, master
      integer :: choice
      choice = slave%solver
      if (master%solver == solver_iterative) choice = solver_iterative
      pair_iterative = use_iterative(choice, slave%dim, slave%degree, slave%n_dofs() + master%n_dofs(), coupled=.true.)
   end function pair_iterative

   !> The Krylov stopping tolerance of the block system (a relative energy
   !> bound): the single body's `iteration_tolerance` 1e-7 (h/L)^p (h the
   !> finer grid's finest cell, L its box) times (h/L)^(d/2)/kappa. A contact
   !> report's pressures (p_max, each point's p) are pointwise tractions, which
   !> the energy norm bounds only through an inverse estimate: a strain error
   !> e in one cell of size h is at most C (L/h)^(d/2) times the relative
   !> energy error (the cell's share of the energy). A closed cell's
   !> multiplier pbar + gamma gbar, gamma = kappa E/h, takes it twice: E e
   !> through the traction pbar and, the gap moving by about h e, kappa E e
   !> through gamma gbar; so the bound carries 1/kappa (kappa >= 1) as
   !> `active_set_tolerance` does. Not below 1e-12, the round-off of the solve.
   pure real(wp) function contact_tolerance(h_over_l, degree, dim, kappa) result(tau)
      real(wp), intent(in) :: h_over_l, kappa
      integer, intent(in) :: degree, dim
      tau = max(iteration_tolerance(h_over_l, degree)*h_over_l**(0.5_wp*dim)/max(kappa, 1.0_wp), 1.0e-12_wp)
   end function contact_tolerance

   !> The Krylov tolerance of the active-set iterations before the set
   !> repeats: they only decide the sign of each cell's multiplier, and the
   !> set they end on is confirmed by a solve to `contact_tolerance`
   !> (`confirm_set`). The multiplier pbar + gamma gbar amplifies a gap error
   !> by gamma = kappa E/h: a strain error e in a cell moves it by about
   !> kappa E e, and by the inverse estimate of `contact_tolerance` e is at
   !> most (L/h)^(d/2) times the relative energy error. A bound of
   !> 1e-2 (h/L)^(d/2)/kappa keeps a cell's multiplier within about 1 % of
   !> the stress scale, so only cells that close to changing sign can be put
   !> on the wrong side, and the confirming solve sees them.
   pure real(wp) function active_set_tolerance(h_over_l, dim, kappa) result(tau)
      real(wp), intent(in) :: h_over_l, kappa
      integer, intent(in) :: dim
      tau = changing_set_tolerance(h_over_l, dim)/max(kappa, 1.0_wp)
   end function active_set_tolerance

   !> The Krylov tolerance of the first active-set iterations when the
   !> first set is a part of the candidates (`first_set`: the set then
   !> grows from the first contact by rows of cells): `active_set_tolerance`
   !> without its 1/kappa, 1e-2 (h/L)^(d/2), which keeps the slave's
   !> traction pbar of a cell within about 1 % of the stress scale but not
   !> the kappa-amplified gap term gamma gbar, so it may misplace cells
   !> near the sign change, which the next sets correct. Once a change of
   !> the set does not shrink, the solves go to `active_set_tolerance`; a
   !> first set of every candidate (an interference fit, every cell closed
   !> from the start, whose cells flip at this tolerance) starts there; the
   !> final set is confirmed at `contact_tolerance` in any case
   !> (`confirm_set`).
   pure real(wp) function changing_set_tolerance(h_over_l, dim) result(tau)
      real(wp), intent(in) :: h_over_l
      integer, intent(in) :: dim
      tau = 1.0e-2_wp*h_over_l**(0.5_wp*dim)
   end function changing_set_tolerance

   !> The points whose contact cell changes state from `closed` to `next`.
   pure integer function switched_points(ops, closed, next) result(switched)
      type(point_operators_type), intent(in) :: ops
      logical, intent(in) :: closed(:), next(:)
      switched = sum(ops%cell_ptr(2:) - ops%cell_ptr(:size(closed)), mask=next .neqv. closed)
   end function switched_points

   !> The next active set from the multipliers lambda_n of the last solve
   !> and the points that switch. Constant multiplier: the cells with
   !> lambda_n < 0. Linear multiplier (`cut_edges`), per point: a point in
   !> the hat of a closed node is closed where the pressure interpolated by
   !> the closed nodes' whole hats, -sum_j phi_j lambda_j, is positive, so
   !> the contact edge falls where that pressure changes sign, between
   !> points, not at a node or a midpoint; any other point takes the state
   !> of its owner's trial multiplier (a whole hat's, the node open). A
   !> node is closed when one of its points is.
   subroutine next_set(ops, closed, lambda_n, gap, next, switched, cycled)
      type(point_operators_type), intent(inout) :: ops
      logical, intent(in) :: closed(:)
      real(wp), intent(in) :: lambda_n(:), gap(:)
      logical, intent(out) :: next(:)
      integer, intent(out) :: switched
      !> The points that would have switched into a set solved before (the
      !> set then repeats and the iteration ends on it); 0 otherwise.
      integer, intent(out) :: cycled
      real(wp) :: p(size(ops%cell_of_point))
      logical :: covered(size(ops%cell_of_point))
      integer :: c, q, i, k

      cycled = 0
      if (.not. allocated(ops%pclosed)) then
         next = lambda_n < 0.0_wp
         switched = switched_points(ops, closed, next)
         return
      end if
      p = 0.0_wp
      covered = .false.
      do c = 1, ops%ncell
         if (.not. closed(c)) cycle
         do q = ops%cell_ptr(c), ops%cell_ptr(c + 1) - 1
            i = ops%cell_point(q)
            p(i) = p(i) - ops%phi_full(q)*lambda_n(c)
            covered(i) = covered(i) .or. ops%phi_full(q) > 0.0_wp
         end do
      end do
      if (.not. allocated(ops%pnext)) allocate (ops%pnext(size(p)))
      do i = 1, size(p)
         if (covered(i) .and. ops%pclosed(i)) then
            ops%pnext(i) = p(i) > 0.0_wp
         else if (covered(i)) then
            ops%pnext(i) = gap(i) < 0.0_wp
         else if (ops%owner(i) > 0) then
            ops%pnext(i) = lambda_n(ops%owner(i)) < 0.0_wp
         else
            ops%pnext(i) = .false.
         end if
      end do
      do c = 1, ops%ncell
         next(c) = any(ops%pnext(ops%cell_point(ops%cell_ptr(c):ops%cell_ptr(c + 1) - 1)) .and. &
            & ops%phi_full(ops%cell_ptr(c):ops%cell_ptr(c + 1) - 1) > 0.0_wp)
      end do
      switched = count(ops%pnext .neqv. ops%pclosed)
      call remember_set(ops)
      do k = 1, ops%nseen
         if (switched == 0) exit
         if (.not. all(ops%seen(:, k) .eqv. ops%pnext)) cycle
         cycled = switched
         ops%pnext = ops%pclosed
         next = closed
         switched = 0
      end do
   end subroutine next_set

   !> Append the points' current set to those solved (`ops%seen`).
   pure subroutine remember_set(ops)
      type(point_operators_type), intent(inout) :: ops
      logical, allocatable :: grown(:, :)
      if (.not. allocated(ops%seen)) allocate (ops%seen(size(ops%pclosed), 4))
      if (ops%nseen == size(ops%seen, 2)) then
         allocate (grown(size(ops%seen, 1), 2*ops%nseen))
         grown(:, 1:ops%nseen) = ops%seen
         call move_alloc(grown, ops%seen)
      end if
      ops%nseen = ops%nseen + 1
      ops%seen(:, ops%nseen) = ops%pclosed
   end subroutine remember_set

   !> The active set repeated after a solve to `active_set_tolerance`: solve
   !> the same system again (its preconditioner set up) to the final
   !> tolerance from that solution and evaluate again; `switched` says
   !> whether the set still repeats.
   subroutine confirm_set(surface, ops, cells, closed, bs, f, x, sol, next, switched, cycled, error, pstar)
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(inout) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      type(block_solver_type), intent(inout) :: bs
      real(wp), intent(in) :: f(:)
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      logical, intent(out) :: next(:)
      integer, intent(out) :: switched, cycled
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: pstar(:, :)

      cycled = 0
      bs%krylov%tolerance = bs%tight
      call krylov_solve(bs%krylov, f, x, sol, error)
      if (.not. allocated(error)) call evaluate(surface, ops, cells, closed, x, sol, error, pstar)
      if (allocated(error)) return
      call next_set(ops, closed, sol%lambda_n, sol%gap, next, switched, cycled)
   end subroutine confirm_set

   !> The warning of a pair `what` whose active set repeated an earlier one
   !> at active-set iteration `iteration` with `cycled` points switching.
   pure function cycle_warning(what, iteration, cycled) result(text)
      character(len=*), intent(in) :: what
      integer, intent(in) :: iteration, cycled
      character(len=:), allocatable :: text
      text = what//': the active set repeated an earlier one at active-set iteration '//itoa(iteration)//' ('// &
         & itoa(cycled)//' points switching back and forth, their pressure near zero); the solution of the '// &
         & 'repeated set is kept'
   end function cycle_warning

   !> The blocks (masters) of `dof` with a component in `touched` (0: none).
   pure function kept_masters(touched, dof) result(keep)
      logical, intent(in) :: touched(0:)
      integer, intent(in) :: dof(:, :)
      logical :: keep(size(dof, 2))
      integer :: m
      keep = [(any(touched(dof(:, m))), m = 1, size(dof, 2))]
   end function kept_masters

   !> Set up the Krylov solver on k (CG when `symmetric`, else GMRES): its
   !> numeric part only when k has the pattern of the last set-up.
   subroutine krylov_setup(krylov, k, symmetric, error)
      type(petsc_solver_type), intent(inout) :: krylov
      type(csr_type), intent(in) :: k
      logical, intent(in) :: symmetric
      type(error_type), allocatable, intent(out) :: error
      krylov%symmetric = symmetric
      call krylov%update(k, error)
      if (allocated(error)) error%message = 'contact solve (iterative setup): '//error%message
   end subroutine krylov_setup

   !> Solve with the set-up Krylov solver from x (the previous solution).
   subroutine krylov_solve(krylov, f, x, sol, error)
      type(petsc_solver_type), intent(inout) :: krylov
      real(wp), intent(in) :: f(:)
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      integer :: before

      before = krylov%iterations
      krylov%guess = x
      call krylov%solve(f, x, error)
      sol%solver_iterations = sol%solver_iterations + krylov%iterations - before
      sol%solver_name = merge('cg+   ', 'gmres+', krylov%symmetric)
      sol%solver_name = trim(sol%solver_name)//trim(merge('gmg ', 'gamg', krylov%multigrid))
      sol%rcond = -1.0_wp
      if (allocated(error)) error%message = 'contact solve (iterative): '//error%message
   end subroutine krylov_solve

   !> One block system through the Krylov solver (CG when `symmetric`, else
   !> GMRES; GMRES too when CG finds the system indefinite), from x.
   subroutine iterative_block(krylov, k, f, symmetric, x, sol, error)
      type(petsc_solver_type), intent(inout) :: krylov
      type(csr_type), intent(in) :: k
      real(wp), intent(in) :: f(:)
      logical, intent(in) :: symmetric
      real(wp), intent(inout) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: x0(:)

      x0 = x
      call krylov_setup(krylov, k, symmetric, error)
      if (.not. allocated(error)) call krylov_solve(krylov, f, x, sol, error)
      if (.not. allocated(error) .or. .not. symmetric) return
      if (error%stat /= stat_not_positive_definite) return
      deallocate (error)
      x = x0
      call krylov_setup(krylov, k, .false., error)
      if (.not. allocated(error)) call krylov_solve(krylov, f, x, sol, error)
   end subroutine iterative_block

   !> The outputs allocated and reset (every point open); the linearized
   !> normal gap of every point with a master point (huge elsewhere).
   subroutine point_gaps(surface, ops, ncell, x, sol, error)
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(in) :: ops
      integer, intent(in) :: ncell
      real(wp), intent(in) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      integer :: i, q0, q1, stat

      if (.not. allocated(sol%gap)) then
         allocate (sol%gap(surface%npoint), sol%pressure(surface%npoint), sol%tangential(surface%npoint), &
            & sol%lambda_n(ncell), sol%closed(surface%npoint), sol%slipping(surface%npoint), &
            & sol%traction_t(surface%dim, surface%npoint), stat=stat)
         call check_allocation(stat, 'contact solve', 'the values of each slave point', surface%npoint + ncell, &
            & 8*(4 + surface%dim) + 8, error)
         if (allocated(error)) return
      end if
      sol%gap = huge(1.0_wp)
      sol%pressure = 0.0_wp
      sol%tangential = 0.0_wp
      sol%traction_t = 0.0_wp
      sol%closed = .false.
      sol%slipping = .false.
      do i = 1, surface%npoint
         if (.not. surface%has_master(i)) cycle
         q0 = ops%ptr(i)
         q1 = ops%ptr(i + 1) - 1
         sol%gap(i) = surface%g0(i) + dot_product(surface%normal(:, i), matmul(ops%gop(:, q0:q1), x(ops%dofs(q0:q1))))
      end do
   end subroutine point_gaps

   !> Gaps, cell multipliers, pressures and tangential tractions of the
   !> solution x (module notes).
   subroutine evaluate(surface, ops, cells, closed, x, sol, error, pstar)
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      logical, intent(in) :: closed(:)
      real(wp), intent(in) :: x(:)
      type(contact_solution_type), intent(inout) :: sol
      type(error_type), allocatable, intent(out) :: error
      !> The cells' mean stabilization tractions (recovered stabilization).
      real(wp), intent(in), optional :: pstar(:, :)
      real(wp) :: lam(surface%dim), lami(surface%dim), nrm(surface%dim), phi, largest(surface%npoint)
      integer :: i, c, j

      call point_gaps(surface, ops, size(cells), x, sol, error)
      if (allocated(error)) return
      largest = 0.0_wp
      do c = 1, size(cells)
         associate (cell => cells(c), pts => ops%cell_point(ops%cell_ptr(c):ops%cell_ptr(c + 1) - 1))
            lam = 0.0_wp
            if (present(pstar)) then
               lam(1:cell%rows) = pstar(1:cell%rows, c) + ops%gamma(c)*(matmul(cell%gbar, x(cell%dofs)) + cell%g0bar)
            else
               lam(1:cell%rows) = matmul(cell%tbar + ops%gamma(c)*cell%gbar, x(cell%dofs)) + ops%gamma(c)*cell%g0bar
            end if
            if (cell%rows == 1) then
               sol%lambda_n(c) = lam(1)
            else
               sol%lambda_n(c) = dot_product(lam, cell%nbar)
            end if
            do j = 1, size(pts)
               i = pts(j)
               phi = ops%cell_phi(ops%cell_ptr(c) + j - 1)
               ! A point's state is that of its largest basis function's cell (its owner).
               if (allocated(ops%pclosed)) then
                  sol%closed(i) = ops%pclosed(i)
               else if (allocated(ops%owner)) then
                  sol%closed(i) = closed(ops%owner(i))
               else if (phi > largest(pts(j))) then
                  largest(i) = phi
                  sol%closed(i) = closed(c)
               end if
               if (.not. closed(c)) cycle
               nrm = surface%normal(:, i)
               if (cell%rows == 1) then
                  sol%pressure(i) = sol%pressure(i) - phi*lam(1)
               else
                  lami = phi*matmul(cell%rot(:, :, j), lam)
                  sol%pressure(i) = sol%pressure(i) - dot_product(lami, nrm)
                  sol%traction_t(:, i) = sol%traction_t(:, i) + lami - dot_product(lami, nrm)*nrm
               end if
            end do
         end associate
      end do
      if (size(cells) > 0) then
         if (cells(1)%rows > 1) sol%tangential = norm2(sol%traction_t, dim=1)
      end if
   end subroutine evaluate

   !> The recovered stabilization traction must be finite, one vector per
   !> surface point, and is not combined with Coulomb friction.
   subroutine check_recovered(surface, friction, recovered, error)
      type(contact_surface_type), intent(in) :: surface
      integer, intent(in) :: friction
      real(wp), intent(in) :: recovered(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      if (friction == friction_coulomb) then
         call fatal_error(error, 'contact solve: the recovered stabilization is not combined with Coulomb friction '// &
            & 'in this version', stat_unsupported)
      else if (size(recovered, 1) /= surface%dim .or. size(recovered, 2) /= surface%npoint) then
         call fatal_error(error, 'contact solve: recovered has shape ('//itoa(size(recovered, 1))//', '// &
            & itoa(size(recovered, 2))//'), expected (dim, points) = ('//itoa(surface%dim)//', '// &
            & itoa(surface%npoint)//')', stat_invalid_input)
      else
         do i = 1, surface%npoint
            if (surface%has_master(i) .and. .not. all(abs(recovered(:, i)) <= huge(1.0_wp))) then
               call fatal_error(error, 'contact solve: recovered(:, '//itoa(i - 1)//') (0-based point) is not finite', &
                  & stat_invalid_input)
               return
            end if
         end do
      end if
   end subroutine check_recovered

   !> pstar(1:rows, c): the mean over contact cell c's points of the given
   !> stabilization traction, its normal component n_i.p*_i (frictionless)
   !> or the vector (stick), as the FE traction's mean tbar.
   pure subroutine cell_tractions(surface, ops, cells, recovered, pstar, error)
      type(contact_surface_type), intent(in) :: surface
      type(point_operators_type), intent(in) :: ops
      type(cell_operators_type), intent(in) :: cells(:)
      real(wp), intent(in) :: recovered(:, :)
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: c, j, i, stat

      allocate (pstar(surface%dim, size(cells)), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact solve', 'the recovered traction of each contact cell', size(cells), &
         & 8*surface%dim, error)
      if (allocated(error)) return
      do c = 1, size(cells)
         do j = ops%cell_ptr(c), ops%cell_ptr(c + 1) - 1
            i = ops%cell_point(j)
            if (cells(c)%rows == 1) then
               pstar(1, c) = pstar(1, c) + surface%weight(i)*ops%cell_phi(j)* &
                  & dot_product(surface%normal(:, i), recovered(:, i))
            else
               pstar(:, c) = pstar(:, c) + surface%weight(i)*ops%cell_phi(j)* &
                  & matmul(transpose(cells(c)%rot(:, :, j - ops%cell_ptr(c) + 1)), recovered(:, i))
            end if
         end do
         pstar(:, c) = pstar(:, c)/cells(c)%measure
      end do
   end subroutine cell_tractions

   !> Solve an assembly: several bodies and the pairs between them (a
   !> connected component of the contact graph) in one block system, every
   !> body's reduced system on the diagonal and every pair's contact cells
   !> (module notes, frictionless or stick, the FE stabilization stress), one
   !> active-set iteration over the cells of all pairs: each iteration
   !> assembles, checks the rigid modes of every body and solves the one
   !> system, then every pair's cells take their next state; it ends when no
   !> cell of any pair switches. A pair's cells, first active set and
   !> operators are those `solve_contact_pair` gives it alone. On success
   !> every problem holds its solution and sols(k) is pair k's; the iteration
   !> count, condition estimate, solver and times are the assembly's, the
   !> same in every sols(k).
   subroutine solve_contact_assembly(bodies, pairs, sols, error, max_iterations, progress)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pairs(:)
      type(contact_solution_type), allocatable, intent(out) :: sols(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: max_iterations
      procedure(contact_progress), optional :: progress
      type(pair_work_type), allocatable :: work(:)
      type(contact_solution_type) :: solved
      !> Unset: a direct solve (module notes).
      type(block_solver_type) :: bs
      type(csr_type) :: k
      type(timer_type) :: timer
      real(wp), allocatable :: f(:), x(:)
      integer, allocatable :: offset(:)
      integer :: it, maxit, p, c, switched, b, stat, moved, attempt, cycled
      logical, allocatable :: next(:)
      logical :: again

      maxit = default_max_iterations
      if (present(max_iterations)) maxit = max_iterations
      allocate (sols(size(pairs)), work(size(pairs)), offset(size(bodies) + 1), stat=stat)
      call check_allocation(stat, 'contact assembly', 'the pairs', size(pairs), 64, error)
      if (allocated(error)) return
      do p = 1, size(pairs)
         sols(p)%warning = ''
      end do
      offset(1) = 0
      do b = 1, size(bodies)
         offset(b + 1) = offset(b) + bodies(b)%problem%n_dofs()
      end do
      call timer%start()
      do p = 1, size(pairs)
         call pair_work(bodies, pairs(p), offset, work(p), error)
         if (allocated(error)) then
            error%message = pair_name(bodies, pairs(p))//': '//error%message
            return
         end if
      end do
      call timer%stop()
      solved%t_contact = timer%elapsed
      allocate (x(offset(size(bodies) + 1)), stat=stat)
      call check_allocation(stat, 'contact assembly', 'the solution of every body', size(x), 8, error)
      if (allocated(error)) return
      do it = 1, maxit
         solved%iterations = it
         call timer%reset()
         call timer%start()
         do attempt = 1, 2
            do p = 1, size(pairs)
               if (.not. allocated(work(p)%ops%owner)) cycle
               call cut_edges(pairs(p)%surface, work(p)%ops, work(p)%cells, work(p)%closed, pairs(p)%friction, &
                  & error)
               if (allocated(error)) return
            end do
            call assembly_system(bodies, offset, work, k, f, error)
            if (.not. allocated(error)) call check_held_bodies(bodies, k, &
               & sum([(closed_points(work(p)%ops, work(p)%closed), p=1, size(pairs))]), it, error)
            call widen_assembly(it, work, error, again)
            if (.not. again) exit
         end do
         if (.not. allocated(error)) call solve_block(bs, k, f, x, solved, error)
         call timer%stop()
         solved%t_solve = solved%t_solve + timer%elapsed
         if (allocated(error)) return
         call timer%reset()
         call timer%start()
         switched = 0
         do p = 1, size(pairs)
            associate (w => work(p))
               call evaluate(pairs(p)%surface, w%ops, w%cells, w%closed, x, sols(p), error)
               if (allocated(error)) return
               if (allocated(next)) deallocate (next)
               allocate (next(size(w%closed)))
               call next_set(w%ops, w%closed, sols(p)%lambda_n, sols(p)%gap, next, moved, cycled)
               if (cycled > 0) sols(p)%warning = cycle_warning(pair_name(bodies, pairs(p)), it, cycled)
               switched = switched + moved
               w%closed = next
               if (allocated(w%ops%pnext)) w%ops%pclosed = w%ops%pnext
            end associate
         end do
         call timer%stop()
         solved%t_contact = solved%t_contact + timer%elapsed
         if (present(progress)) call progress(1, 1, it, switched)
         if (switched == 0) exit
         if (it == maxit) then
            call fatal_error(error, 'contact assembly of bodies '//body_list(bodies)// &
               & ': the active set did not settle in '//itoa(maxit)//' iterations; '//itoa(switched)// &
               & ' points still switched in the last one', stat_not_converged)
            return
         end if
      end do
      do b = 1, size(bodies)
         call bodies(b)%problem%set_solution(x(offset(b) + 1:offset(b + 1)), error)
         if (allocated(error)) return
      end do
      do p = 1, size(pairs)
         sols(p)%iterations = solved%iterations
         sols(p)%rcond = solved%rcond
         sols(p)%solver_name = solved%solver_name
         sols(p)%t_solve = solved%t_solve
         sols(p)%t_contact = solved%t_contact
      end do
   end subroutine solve_contact_assembly

   !> `widen_first_set` for every pair of an assembly: all start again from
   !> their candidate cells.
   subroutine widen_assembly(iteration, work, error, again)
      integer, intent(in) :: iteration
      type(pair_work_type), intent(inout) :: work(:)
      type(error_type), allocatable, intent(inout) :: error
      logical, intent(out) :: again
      integer :: p
      again = .false.
      if (.not. allocated(error) .or. iteration /= 1) return
      if (error%stat /= stat_singular .or. all([(all(work(p)%closed .eqv. work(p)%wide), p=1, size(work))])) return
      deallocate (error)
      do p = 1, size(work)
         work(p)%closed = work(p)%wide
         ! the linear multiplier's point states follow the widened cells (`cut_edges`)
         if (allocated(work(p)%ops%pclosed)) deallocate (work(p)%ops%pclosed)
      end do
      again = .true.
   end subroutine widen_assembly

   !> A pair's operators in the assembly's numbering, its cells and first
   !> active set (as `solve_contact_pair`'s).
   subroutine pair_work(bodies, pair, offset, work, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pair
      integer, intent(in) :: offset(:)
      type(pair_work_type), intent(out) :: work
      type(error_type), allocatable, intent(out) :: error
      integer :: c, stat

      if (pair%friction /= friction_frictionless .and. pair%friction /= friction_stick) then
         call fatal_error(error, 'contact assembly: friction '//itoa(pair%friction)//' is not frictionless or '// &
            & 'stick', stat_unsupported)
         return
      end if
      associate (slave => bodies(pair%slave)%problem, master => bodies(pair%master)%problem)
         call check_pair(slave, master, pair%surface, pair%friction, pair%kappa, error)
         if (.not. allocated(error)) call point_operators(slave, master, pair%surface, pair%kappa, work%ops, error, &
            & [offset(pair%slave), offset(pair%master)], pair%multiplier)
         if (allocated(error)) return
         allocate (work%cells(work%ops%ncell), work%closed(work%ops%ncell), stat=stat)
         call check_allocation(stat, 'contact solve', 'the contact cells', work%ops%ncell, 2, error)
         if (allocated(error)) return
         do c = 1, work%ops%ncell
            call cell_operators(pair%surface, work%ops, c, pair%friction, work%cells(c), error)
            if (allocated(error)) return
         end do
         call first_set(slave, pair%surface, work%ops, work%closed, work%wide)
      end associate
   end subroutine pair_work

   !> The assembly's block system (every body's K on the diagonal, the closed
   !> cells' blocks of every pair) and its load.
   subroutine assembly_system(bodies, offset, work, k, f, error)
      type(contact_body_type), intent(in) :: bodies(:)
      integer, intent(in) :: offset(:)
      type(pair_work_type), intent(in) :: work(:)
      type(csr_type), intent(out) :: k
      real(wp), allocatable, intent(out) :: f(:)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      real(wp), allocatable :: kc(:, :)
      integer(i8) :: capacity
      integer :: b, p, c, n

      n = offset(size(bodies) + 1)
      capacity = 0
      do b = 1, size(bodies)
         capacity = capacity + bodies(b)%problem%k%nnz()
      end do
      do p = 1, size(work)
         do c = 1, size(work(p)%cells)
            if (work(p)%closed(c)) capacity = capacity + int(work(p)%cells(c)%nu, i8)**2
         end do
      end do
      call coo%init(n, n, error, capacity=capacity)
      if (allocated(error)) return
      allocate (f(n))
      do b = 1, size(bodies)
         call add_csr(coo, bodies(b)%problem%k, offset(b), error)
         if (allocated(error)) return
         f(offset(b) + 1:offset(b + 1)) = bodies(b)%problem%f
      end do
      do p = 1, size(work)
         do c = 1, size(work(p)%cells)
            if (.not. work(p)%closed(c)) cycle
            associate (cell => work(p)%cells(c), gamma => work(p)%ops%gamma(c))
               call tied_block(cell, gamma, kc)
               call coo%add(cell%dofs, kc, error)
               if (allocated(error)) return
               f(cell%dofs) = f(cell%dofs) - cell%measure*matmul(cell%g0bar, cell%tbar + gamma*cell%gbar)
            end associate
         end do
      end do
      call coo%to_csr(k, error)
   end subroutine assembly_system

   !> Every rigid-body mode of every body of an assembly must be resisted by
   !> its block system; the free ones are an error naming their bodies.
   subroutine check_held_bodies(bodies, k, nclosed, iteration, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(csr_type), intent(in) :: k
      integer, intent(in) :: nclosed, iteration
      type(error_type), allocatable, intent(out) :: error
      type(dense_block_type), allocatable :: modes(:)
      real(wp), allocatable :: r(:, :), vec(:, :)
      logical, allocatable :: involved(:)
      integer :: nfree, j, b, row, col, nm, stat
      character(len=:), allocatable :: what

      allocate (modes(size(bodies)), stat=stat)
      call check_allocation(stat, 'contact rigid-mode check', 'the bodies'' modes', size(bodies), 64, error)
      if (allocated(error)) return
      do b = 1, size(bodies)
         call bodies(b)%problem%rigid_modes(modes(b)%a, error)
         if (allocated(error)) return
      end do
      nm = size(modes(1)%a, 2)
      allocate (r(k%nrows, nm*size(bodies)), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact rigid-mode check', 'the rigid-body motions of every body', &
         & int(k%nrows, i8)*nm*size(bodies), 8, error)
      if (allocated(error)) return
      row = 0
      do b = 1, size(bodies)
         col = (b - 1)*nm
         r(row + 1:row + size(modes(b)%a, 1), col + 1:col + nm) = modes(b)%a
         row = row + size(modes(b)%a, 1)
      end do
      call free_motions(k, r, vec, nfree, error)
      if (allocated(error) .or. nfree == 0) return
      allocate (involved(nm*size(bodies)), source=.false.)
      do j = 1, nfree
         involved = involved .or. abs(vec(:, j)) >= 0.2_wp*maxval(abs(vec(:, j)))
      end do
      what = ''
      do b = 1, size(bodies)
         associate (flags => involved((b - 1)*nm + 1:b*nm))
            if (.not. any(flags)) cycle
            if (len(what) > 0) what = what//'; '
            what = what//"body '"//bodies(b)%name//"' is not held: "//motion_names(bodies(1)%problem%dim, flags)// &
               & ' free'
         end associate
      end do
      call fatal_error(error, what//' (contact assembly of bodies '//body_list(bodies)//', active-set iteration '// &
         & itoa(iteration)//', '//itoa(nclosed)//' closed points): a body held only by contact has lost it, or '// &
         & 'its conditions leave it free', stat_singular)
   end subroutine check_held_bodies

   !> 'a', 'b', 'c': the assembly's body names for messages.
   function body_list(bodies) result(text)
      type(contact_body_type), intent(in) :: bodies(:)
      character(len=:), allocatable :: text
      integer :: b
      text = ''
      do b = 1, size(bodies)
         if (b > 1) text = text//', '
         text = text//"'"//bodies(b)%name//"'"
      end do
   end function body_list

   !> "contact 'slave' on 'master'" of a pair, for messages.
   function pair_name(bodies, pair) result(text)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pair
      character(len=:), allocatable :: text
      text = "contact '"//bodies(pair%slave)%name//"' on '"//bodies(pair%master)%name//"'"
   end function pair_name

end module sprc_contact_pair_solve
