!> Geometric multigrid hierarchy on the grid's node lattice: the
!> prolongations of the iterative solver's PCMG (`sprc_fem_petsc`).
!>
!> The reduced unknowns are blocks of `dim` components at master nodes, and
!> every node sits on the grid's integer node lattice (`grid_nodes_type`,
!> lattice coordinates in units of box_size / 2**lattice_level; a Q1 node
!> step is 2 there, a Q2 one 1). The coarse space of a level of spacing s
!> (in lattice units: twice the node step, then 4, 8, ... times it) has one
!> node per lattice point of spacing s that is a node of the finer level
!> (a C-point, taken by injection). Every other node (F-point) gets its value
!> from the corners of the coarse cell of side s that holds it:
!> - all corners with a nonzero (tri/bi)linear weight are C-points: those
!>   weights (a Q2 level is coarsened to the Q1-like vertex lattice this way);
!> - otherwise (near cuts, where corners of the coarse cell are no nodes):
!>   the weights w closest to the linear ones t, |w - t| least, among those
!>   that reproduce every linear field exactly (sum w = 1, sum w x_k = x), on
!>   the cell's corners that are C-points and, while these do not span the
!>   space affinely, the nearest C-points of the neighbouring cells (few
!>   weights per row, so the coarse matrices stay sparse);
!> - if no C-points nearby can reproduce linear fields (fewer than dim + 1,
!>   or affinely dependent) the node itself is a C-point of the coarse level.
!> So the prolongation reproduces linear fields exactly, the rigid-body modes
!> of elasticity included, on every level, and it has full column rank (the
!> C-points' rows are the identity): the Galerkin coarse matrices P^T A P
!> are symmetric positive definite whenever A is. Coarsening stops at
!> `coarse_nodes` nodes or when a level no longer shrinks.
!>
!> Several bodies in one system (a contact pair: `stack_hierarchies`): each
!> body's nodes are coarsened on its own lattice and the prolongation of a
!> level is block diagonal, the bodies' nodes in their order on every level;
!> a body whose hierarchy is shorter keeps its coarsest nodes (identity) on
!> the remaining levels. The coupling terms are then seen by the coarse
!> levels through the Galerkin products of the coupled fine matrix.
!> Kept nodes (`keep`, the contact surface's) are C-points on every level and
!> lend no F-point a weight off the coarse lattice: the contact penalty would
!> otherwise lock the coarse spaces, whose surfaces do not match, and CG's
!> iterations grow with the penalty. Coarsening stops by the nodes not kept.
module sprc_fem_multigrid
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_core_hash, only: key_table_type
   use sprc_core_sort, only: sort_pairs
   use sprc_core_dense, only: qr_pivoted, apply_q, solve_upper
   implicit none
   private

   public :: prolongation_type, lattice_hierarchy, coarsen, stack_hierarchies

   !> A scalar prolongation from `n_coarse` coarse nodes to `n_fine` fine ones
   !> in 1-based CSR (columns ascending in each row), and the coarse nodes'
   !> lattice coordinates (dim, n_coarse).
   type :: prolongation_type
      integer :: n_fine = 0, n_coarse = 0
      integer, allocatable :: rowptr(:), col(:)
      real(wp), allocatable :: val(:)
      integer, allocatable :: lattice(:, :)
      !> The coarse nodes that are kept (module notes); not allocated: none.
      logical, allocatable :: keep(:)
   end type prolongation_type

   !> Stop coarsening at this many nodes or fewer (a coarse problem that a
   !> direct factorization solves in well under a millisecond per cycle).
   integer, parameter, public :: coarse_nodes = 200
   !> A level that keeps more than this fraction of its finer level's nodes
   !> ends the hierarchy (the coarsening no longer pays).
   real(wp), parameter :: min_shrink = 0.8_wp
   character(len=*), parameter :: who = 'multigrid hierarchy'

contains

   !> The prolongations `p(1)` (finest to first coarse level), `p(2)`, ... of
   !> the nodes at the lattice coordinates `lattice(dim, n)` (non-negative,
   !> multiples of `step`, no two alike) whose node step is `step`. `p` is
   !> empty when the nodes do not coarsen (at most `coarse` of them;
   !> `coarse` defaults to `coarse_nodes`). `keep`: the nodes kept on every
   !> level (module notes); they do not count towards `coarse`.
   subroutine lattice_hierarchy(lattice, step, p, error, coarse, keep)
      integer, intent(in) :: lattice(:, :), step
      type(prolongation_type), allocatable, intent(out) :: p(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: coarse
      logical, intent(in), optional :: keep(:)
      type(prolongation_type) :: next
      logical, allocatable :: kept(:)
      integer :: s, smallest, n_free

      smallest = coarse_nodes
      if (present(coarse)) smallest = coarse

      allocate (p(0))
      call check_lattice(lattice, step, error)
      if (allocated(error)) return
      if (present(keep)) then
         if (size(keep) /= size(lattice, 2)) then
            call fatal_error(error, who//': the kept nodes are not given for each node', stat_invalid_input)
            return
         end if
         kept = keep
      else
         allocate (kept(size(lattice, 2)), source=.false.)
      end if
      n_free = count(.not. kept)
      if (n_free <= smallest) return
      s = 2*step
      do
         if (size(p) == 0) then
            call coarsen(lattice, s, next, error, kept)
         else
            call coarsen(p(size(p))%lattice, s, next, error, kept)
         end if
         if (allocated(error)) return
         if (real(next%n_coarse - count(next%keep), wp) > min_shrink*real(n_free, wp)) exit
         kept = next%keep
         n_free = next%n_coarse - count(kept)
         p = [p, next]
         if (n_free <= smallest .or. s >= 2**22) exit
         s = 2*s
      end do
   end subroutine lattice_hierarchy

   !> Nodes on the lattice: non-negative, multiples of `step`, below 2**22
   !> (the grid's lattice bound), no two at one point.
   subroutine check_lattice(lattice, step, error)
      integer, intent(in) :: lattice(:, :), step
      type(error_type), allocatable, intent(out) :: error
      type(key_table_type) :: points
      integer :: d, j, other
      logical :: added
      character(len=160) :: buf

      d = size(lattice, 1)
      if (step < 1 .or. (d /= 2 .and. d /= 3)) then
         call fatal_error(error, who//': the node step must be positive and the dimension 2 or 3', stat_invalid_input)
         return
      end if
      if (any(lattice < 0) .or. any(lattice >= 2**22) .or. any(mod(lattice, step) /= 0)) then
         call fatal_error(error, who//': a node is not on the node lattice (outside 0 .. 2**22 - 1, or not a '// &
            & 'multiple of the node step)', stat_invalid_input)
         return
      end if
      call points%init(d, size(lattice, 2), who, error)
      if (allocated(error)) return
      do j = 1, size(lattice, 2)
         call points%insert(lattice(:, j), other, added, error)
         if (allocated(error)) return
         if (.not. added) then
            write (buf, '(a,": nodes ",i0," and ",i0," (0-based) share a lattice point")') who, other - 1, j - 1
            call fatal_error(error, trim(buf), stat_invalid_input)
            return
         end if
      end do
   end subroutine check_lattice

   !> One coarsening (module notes) of the nodes `lattice(dim, n)` to the
   !> lattice of spacing `s`: the prolongation and the coarse nodes; `keep`
   !> the nodes kept (C-points of their own), `p%keep` the coarse ones.
   subroutine coarsen(lattice, s, p, error, keep)
      integer, intent(in) :: lattice(:, :), s
      type(prolongation_type), intent(out) :: p
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: keep(:)
      type(key_table_type) :: c_points
      integer, allocatable :: coarse_of(:), col(:)
      real(wp), allocatable :: val(:)
      integer :: d, n, j, stat, nc, q, m, cols(4**size(lattice, 1))
      logical :: added
      real(wp) :: vals(4**size(lattice, 1))

      d = size(lattice, 1)
      n = size(lattice, 2)
      allocate (coarse_of(n), p%rowptr(n + 1), col(2*n), val(2*n), stat=stat)
      call check_allocation(stat, who, 'a prolongation', n, 24, error)
      if (allocated(error)) return
      call c_points%init(d, n, who, error)
      if (allocated(error)) return
      ! C-points on the coarse lattice, numbered in node order
      coarse_of = 0
      do j = 1, n
         if (all(mod(lattice(:, j), s) == 0)) then
            call c_points%insert(lattice(:, j)/s, coarse_of(j), added, error)
            if (allocated(error)) return
         end if
      end do
      ! rows: injection at C-points; F-points get weights, or are C-points of their own
      nc = c_points%n
      q = 0
      do j = 1, n
         p%rowptr(j) = q + 1
         if (coarse_of(j) == 0) then
            m = 0
            if (.not. kept(j)) call f_point_weights(lattice(:, j), s, c_points, cols, vals, m)
            if (m == 0) then
               nc = nc + 1
               coarse_of(j) = nc
            end if
         end if
         if (coarse_of(j) /= 0) then
            m = 1
            cols(1) = coarse_of(j)
            vals(1) = 1.0_wp
         end if
         call append_row(cols(1:m), vals(1:m), q, col, val, error)
         if (allocated(error)) return
      end do
      p%rowptr(n + 1) = q + 1
      p%n_fine = n
      p%n_coarse = nc
      p%col = col(1:q)
      p%val = val(1:q)
      allocate (p%lattice(d, nc), p%keep(nc), stat=stat)
      call check_allocation(stat, who, 'the coarse nodes', nc, 4*d + 4, error)
      if (allocated(error)) return
      p%keep = .false.
      do j = 1, n
         if (coarse_of(j) == 0) cycle
         p%lattice(:, coarse_of(j)) = lattice(:, j)
         p%keep(coarse_of(j)) = kept(j)
      end do
   contains
      pure logical function kept(j)
         integer, intent(in) :: j
         kept = .false.
         if (present(keep)) kept = keep(j)
      end function kept
   end subroutine coarsen

   !> Append a row (sorted by column) after position q of the growing arrays col, val.
   subroutine append_row(cols, vals, q, col, val, error)
      integer, intent(inout) :: cols(:)
      real(wp), intent(inout) :: vals(:)
      integer, intent(inout) :: q
      integer, allocatable, intent(inout) :: col(:)
      real(wp), allocatable, intent(inout) :: val(:)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: col_new(:)
      real(wp), allocatable :: val_new(:)
      integer :: m, stat

      m = size(cols)
      if (q + m > size(col)) then
         allocate (col_new(2*size(col) + m), val_new(2*size(col) + m), stat=stat)
         call check_allocation(stat, who, 'a prolongation', 2*size(col) + m, 12, error)
         if (allocated(error)) return
         col_new(1:q) = col(1:q)
         val_new(1:q) = val(1:q)
         call move_alloc(col_new, col)
         call move_alloc(val_new, val)
      end if
      call sort_pairs(cols, vals)
      col(q + 1:q + m) = cols
      val(q + 1:q + m) = vals
      q = q + m
   end subroutine append_row

   !> The m weights `vals(1:m)` of the F-point at lattice point `q` from the
   !> coarse nodes `cols(1:m)` of spacing `s` (`c_points`: their coarse
   !> lattice points); m = 0 when no weights reproduce linear fields (module
   !> notes). The (bi/tri)linear weights when the corners of the coarse cell
   !> that have one are all C-points; otherwise the weights closest to them on
   !> the cell's corners that are C-points and, while those do not span the
   !> space affinely, the nearest C-points of the neighbouring cells (offsets
   !> -1 .. 2): few weights, so the coarse matrices stay sparse.
   subroutine f_point_weights(q, s, c_points, cols, vals, m)
      integer, intent(in) :: q(:), s
      type(key_table_type), intent(in) :: c_points
      integer, intent(out) :: cols(:)
      real(wp), intent(out) :: vals(:)
      integer, intent(out) :: m
      integer :: d, k, i, base(size(q)), off(size(q)), order(size(cols)), n_near, c, rank
      real(wp) :: t(size(q)), x(size(q), size(cols)), w0(size(cols)), dist(size(cols)), basis(size(q), size(q))
      logical :: complete, corner

      d = size(q)
      base = q/s
      t = real(q - base*s, wp)/real(s, wp)
      complete = .true.
      m = 0
      n_near = 0
      rank = -1
      do k = 0, 2**d - 1
         off = [(mod(k/2**(i - 1), 2), i = 1, d)]
         c = c_points%find(base + off)
         if (c == 0) then
            if (linear_weight(t, off) /= 0.0_wp) complete = .false.
            cycle
         end if
         call take(c, off)
      end do
      if (complete) then
         ! keep the corners with a weight
         k = 0
         do i = 1, m
            if (w0(i) == 0.0_wp) cycle
            k = k + 1
            cols(k) = cols(i)
            vals(k) = w0(i)
         end do
         m = k
         return
      end if
      if (rank < d) then
         ! the C-points among offsets -1 .. 2 outside the cell, nearest first
         do k = 0, 4**d - 1
            off = [(mod(k/4**(i - 1), 4) - 1, i = 1, d)]
            corner = all(off == 0 .or. off == 1)
            if (corner) cycle
            c = c_points%find(base + off)
            if (c == 0) cycle
            n_near = n_near + 1
            order(n_near) = c
            x(:, size(cols) - n_near + 1) = real(off, wp)
            dist(n_near) = sum((real(off, wp) - t)**2)
         end do
         do while (rank < d .and. n_near > 0)
            k = minloc(dist(1:n_near), dim=1)
            off = nint(x(:, size(cols) - k + 1))
            call take(order(k), off)
            dist(k) = huge(1.0_wp)
            if (all(dist(1:n_near) == huge(1.0_wp))) exit
         end do
      end if
      if (rank < d) then
         m = 0
         return
      end if
      call closest_linear_weights(x(:, 1:m), t, w0(1:m), vals(1:m), complete)
      if (.not. complete) m = 0
   contains
      !> Add the coarse node c at offset off to the support and its direction to the affine basis.
      subroutine take(c, off)
         integer, intent(in) :: c, off(:)
         real(wp) :: v(size(off))
         integer :: j
         m = m + 1
         cols(m) = c
         x(:, m) = real(off, wp)
         w0(m) = linear_weight(t, off)
         if (rank < 0) then
            rank = 0
            return
         end if
         if (rank >= d) return
         v = x(:, m) - x(:, 1)
         do j = 1, rank
            v = v - dot_product(v, basis(:, j))*basis(:, j)
         end do
         if (norm2(v) < 1.0e-8_wp) return
         rank = rank + 1
         basis(:, rank) = v/norm2(v)
      end subroutine take
   end subroutine f_point_weights

   !> The (bi/tri)linear weight of the corner at offset `off` (0 or 1 per
   !> axis; -1 and 2 lie beyond the cell: weight 0) for local coordinates t.
   pure real(wp) function linear_weight(t, off) result(w)
      real(wp), intent(in) :: t(:)
      integer, intent(in) :: off(:)
      integer :: i
      w = 1.0_wp
      do i = 1, size(t)
         select case (off(i))
         case (0)
            w = w*(1.0_wp - t(i))
         case (1)
            w = w*t(i)
         case default
            w = 0.0_wp
         end select
      end do
   end function linear_weight

   !> w = argmin |w - w0| subject to sum w = 1 and sum_k w_k x(:, k) = t: with
   !> A = [1; x] (d + 1 rows, m >= d + 1 columns), w = w0 + delta where delta is
   !> the least-norm solution of A delta = [1; t] - A w0, from the pivoted QR of
   !> A^T (`sprc_core_dense`, the patch solves' kernel): A^T P = Q R gives
   !> R^T (Q^T delta)(1:d+1) = P^T ([1; t] - A w0) and the rest of Q^T delta = 0.
   !> `found` is false when A has not full row rank: |R_(d+1,d+1)| at most
   !> sqrt(eps) |R_11| (the offsets are small integers, so a rank-deficient A
   !> gives round-off there and a full-rank one a value of order one).
   pure subroutine closest_linear_weights(x, t, w0, w, found)
      real(wp), intent(in) :: x(:, :), t(:), w0(:)
      real(wp), intent(out) :: w(:)
      logical, intent(out) :: found
      real(wp) :: at(size(w0), size(t) + 1), tau(size(t) + 1), vn(size(t) + 1, 2), r(size(t) + 1), &
         & y(size(w0), 1)
      integer :: d, m, n, jpvt(size(t) + 1), k

      d = size(t)
      m = size(w0)
      n = d + 1
      w = 0.0_wp
      found = .false.
      if (m < n) return
      at(:, 1) = 1.0_wp
      at(:, 2:) = transpose(x)
      r(1) = 1.0_wp - sum(w0)
      r(2:) = t - matmul(x, w0)
      call qr_pivoted(m, n, at, jpvt, tau, vn)
      if (.not. abs(at(n, n)) > sqrt(epsilon(1.0_wp))*abs(at(1, 1))) return
      y = 0.0_wp
      do k = 1, n
         y(k, 1) = r(jpvt(k))
      end do
      call solve_upper(n, at, 1, y, found, transposed=.true.)
      if (.not. found) return
      call apply_q(m, n, at, tau, 1, y)
      w = w0 + y(:, 1)
   end subroutine closest_linear_weights

   !> The hierarchy of two node sets numbered one after the other (`a`'s
   !> `na` fine nodes first, then `b`'s `nb`): level l's prolongation is
   !> diag(a(l), b(l)), with the identity for a set whose hierarchy has ended
   !> (module notes); one identity level when neither coarsens. The coarse
   !> lattices are not kept (they belong to different lattices).
   subroutine stack_hierarchies(a, na, b, nb, p, error)
      type(prolongation_type), intent(in) :: a(:), b(:)
      integer, intent(in) :: na, nb
      type(prolongation_type), allocatable, intent(out) :: p(:)
      type(error_type), allocatable, intent(out) :: error
      type(prolongation_type) :: ia, ib
      integer :: l, ma, mb, stat

      allocate (p(max(size(a), size(b))), stat=stat)
      call check_allocation(stat, who, 'the stacked levels', size(p), 64, error)
      if (allocated(error)) return
      ma = na
      mb = nb
      do l = 1, size(p)
         if (l <= size(a)) then
            if (a(l)%n_fine /= ma) exit
            ia = a(l)
         else
            call identity(ma, ia)
         end if
         if (l <= size(b)) then
            if (b(l)%n_fine /= mb) exit
            ib = b(l)
         else
            call identity(mb, ib)
         end if
         call diagonal_pair(ia, ib, p(l), error)
         if (allocated(error)) return
         ma = ia%n_coarse
         mb = ib%n_coarse
      end do
      if (l <= size(p)) call fatal_error(error, who//': a level of the stacked hierarchies does not start from '// &
         & 'the nodes of the level before', stat_invalid_input)
      if (size(p) > 0 .or. allocated(error)) return
      ! Neither coarsens (both small): one identity level, so that the coarse
      ! solve is the whole system, exact, rather than no hierarchy (GAMG,
      ! whose aggregates lock under the coupling as unkept nodes do).
      deallocate (p)
      allocate (p(1))
      call identity(na + nb, p(1))
   end subroutine stack_hierarchies

   !> The identity prolongation of n nodes.
   pure subroutine identity(n, p)
      integer, intent(in) :: n
      type(prolongation_type), intent(out) :: p
      integer :: j
      p%n_fine = n
      p%n_coarse = n
      p%rowptr = [(j, j = 1, n + 1)]
      p%col = [(j, j = 1, n)]
      p%val = [(1.0_wp, j = 1, n)]
   end subroutine identity

   !> diag(a, b): b's rows and columns after a's.
   subroutine diagonal_pair(a, b, p, error)
      type(prolongation_type), intent(in) :: a, b
      type(prolongation_type), intent(out) :: p
      type(error_type), allocatable, intent(out) :: error
      integer :: nnz_a, stat

      nnz_a = a%rowptr(a%n_fine + 1) - 1
      p%n_fine = a%n_fine + b%n_fine
      p%n_coarse = a%n_coarse + b%n_coarse
      allocate (p%rowptr(p%n_fine + 1), stat=stat)
      call check_allocation(stat, who, 'a stacked prolongation', p%n_fine, 4, error)
      if (allocated(error)) return
      p%rowptr(1:a%n_fine) = a%rowptr(1:a%n_fine)
      p%rowptr(a%n_fine + 1:) = b%rowptr + nnz_a
      p%col = [a%col(1:nnz_a), b%col(1:b%rowptr(b%n_fine + 1) - 1) + a%n_coarse]
      p%val = [a%val(1:nnz_a), b%val(1:b%rowptr(b%n_fine + 1) - 1)]
   end subroutine diagonal_pair

end module sprc_fem_multigrid
