!> Hanging-node constraints of Q1 / Q2 elements on a 2:1 grid, as the sparse
!> transformation u = T ubar from free to all nodes.
!>
!> A node of an element E is hanging when it lies on a face or edge that E
!> shares with a coarser active leaf C and is not a node of C. Continuity then
!> requires u_h = sum_k N_k^C(x_h) u_k over C's nodes (multi-point constraint
!> from the coarse neighbour's shape functions). A master that hangs itself
!> (a chain) cannot occur on grids from `grid_type%build`: its balance makes
!> every level-(l-1) neighbour of a level-l leaf's parent exist, and all
!> masters of a hanging node of that leaf lie on the parent's closure. Grids
!> made otherwise may have chains; they are substituted until every master is
!> free. Masters sit on strictly coarser elements, so this ends within
!> grid_max_level rounds (`chain_rounds` tells how many were needed).
!>
!> T has one row per node (n_all = nodes%n_nodes: only nodes of active
!> elements exist) and one column per free node, numbered in node order.
!> It is scalar: vector fields apply it per component.
module sprc_grid_hanging
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_internal
   use sprc_core_alloc, only: check_allocation
   use sprc_grid_tree, only: grid_type, grid_max_level
   use sprc_grid_nodes, only: grid_nodes_type, element_node_index, element_shape
   implicit none
   private

   public :: hanging_type

   !> Free-node numbering and the transformation T (n_all x n_free) in CSR form.
   type :: hanging_type
      !> All nodes, free nodes, hanging (constrained) nodes.
      integer :: n_all = 0, n_free = 0, n_hanging = 0
      !> Rounds of chain substitution that were needed (0: every master was free).
      integer :: chain_rounds = 0
      !> Free number of each node, 0 for a hanging node (n_all).
      integer, allocatable :: free_index(:)
      !> Node of each free number (n_free).
      integer, allocatable :: free_node(:)
      !> T in CSR: row i has columns t_col(t_ptr(i) : t_ptr(i+1)-1) (free numbers,
      !> ascending) and values t_val(...). A free node's row is its own column with 1.
      integer, allocatable :: t_ptr(:), t_col(:)
      real(wp), allocatable :: t_val(:)
   contains
      procedure :: build => hanging_build
      procedure :: expand => hanging_expand
   end type hanging_type

   !> Sparse rows over node numbers while the constraints are assembled.
   type :: rows_type
      integer, allocatable :: ptr(:), col(:)
      real(wp), allocatable :: val(:)
   end type rows_type

   !> The routine named in messages.
   character(len=*), parameter :: who = 'hanging nodes'

contains

   !> Find the hanging nodes of `nodes` on `grid` and build T.
   subroutine hanging_build(self, grid, nodes, error)
      class(hanging_type), intent(out) :: self
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(error_type), allocatable, intent(out) :: error
      logical, allocatable :: hanging(:)
      type(rows_type) :: rows
      integer :: i, round, stat

      if (nodes%n_elements /= grid%n_leaves .or. nodes%dim /= grid%dim .or. &
         & nodes%lattice_level /= grid%max_level + 1) then
         call fatal_error(error, 'hanging nodes: the node set was not built on this grid', stat_invalid_input)
         return
      end if
      self%n_all = nodes%n_nodes
      call direct_constraints(grid, nodes, hanging, rows, error)
      if (allocated(error)) return

      self%n_hanging = count(hanging)
      self%n_free = self%n_all - self%n_hanging
      allocate (self%free_index(self%n_all), self%free_node(self%n_free), stat=stat)
      call check_allocation(stat, who, 'the free-node numbering', self%n_all, 8, error)
      if (allocated(error)) return
      self%n_free = 0
      do i = 1, self%n_all
         self%free_index(i) = 0
         if (hanging(i)) cycle
         self%n_free = self%n_free + 1
         self%free_index(i) = self%n_free
         self%free_node(self%n_free) = i
      end do

      do round = 1, grid_max_level + 1
         if (.not. any_hanging(rows, hanging)) exit
         self%chain_rounds = round
         call substitute(rows, hanging, error)
         if (allocated(error)) return
      end do
      if (any_hanging(rows, hanging)) then
         call fatal_error(error, 'hanging nodes: constraint chains did not resolve', stat_internal)
         return
      end if
      call move_alloc(rows%ptr, self%t_ptr)
      call move_alloc(rows%val, self%t_val)
      allocate (self%t_col(size(rows%col)), stat=stat)
      call check_allocation(stat, who, 'the columns of T', size(rows%col), 4, error)
      if (allocated(error)) return
      do i = 1, size(rows%col)
         self%t_col(i) = self%free_index(rows%col(i))
      end do
   end subroutine hanging_build

   !> Does a row of `rows` name a hanging node (a chain still to substitute)?
   pure logical function any_hanging(rows, hanging)
      type(rows_type), intent(in) :: rows
      logical, intent(in) :: hanging(:)
      integer :: k
      any_hanging = .false.
      do k = 1, size(rows%col)
         if (hanging(rows%col(k))) then
            any_hanging = .true.
            return
         end if
      end do
   end function any_hanging

   !> u = T ubar (ubar: n_free values; u: n_all values).
   pure subroutine hanging_expand(self, ubar, u)
      class(hanging_type), intent(in) :: self
      real(wp), intent(in) :: ubar(:)
      real(wp), intent(out) :: u(:)
      integer :: i, k
      do i = 1, self%n_all
         u(i) = 0.0_wp
         do k = self%t_ptr(i), self%t_ptr(i + 1) - 1
            u(i) = u(i) + self%t_val(k)*ubar(self%t_col(k))
         end do
      end do
   end subroutine hanging_expand

   !> One row per node: identity for free nodes, the coarse neighbour's shape
   !> function values for hanging ones (masters may still hang).
   subroutine direct_constraints(grid, nodes, hanging, rows, error)
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      logical, allocatable, intent(out) :: hanging(:)
      type(rows_type), intent(out) :: rows
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: idx(:, :), owner(:), side_nodes(:, :), n_side(:)
      real(wp), allocatable :: shape(:)
      integer :: d, p, nen, e, c, k, j, m, n, first, last, dir(3, 26), ndir, r(3), sc, pos
      integer :: coarse(0:26), parent(grid%dim), dir_p(3), slot, stat

      d = grid%dim
      p = nodes%degree
      nen = nodes%nodes_per_element
      allocate (idx, source=element_node_index(d, p))
      call side_tables(d, p, idx, dir, ndir, side_nodes, n_side)
      allocate (shape(nen))
      allocate (hanging(nodes%n_nodes), owner(nodes%n_nodes), stat=stat)
      call check_allocation(stat, who, 'the hanging flags', nodes%n_nodes, 8, error)
      if (allocated(error)) return
      hanging = .false.
      owner = 0
      r = 0
      ! First pass: which nodes hang, and on which coarse element (owner).
      do e = 1, grid%n_leaves
         ! No leaf is coarser than the uniform level, so leaves of that level have no coarser neighbour.
         if (grid%leaf_level(e) <= grid%level) cycle
         ! The cell across direction k lies in the parent's neighbour across dir_p (the
         ! components of k that leave the parent); one query per distinct dir_p.
         coarse = -1
         parent = grid%leaf_coord(:, e)/2
         do k = 1, ndir
            dir_p = 0
            dir_p(1:d) = merge(dir(1:d, k), 0, mod(grid%leaf_coord(:, e), 2) == merge(1, 0, dir(1:d, k) > 0))
            if (all(dir_p == 0)) cycle
            slot = (dir_p(1) + 1) + 3*(dir_p(2) + 1) + 9*(dir_p(3) + 1)
            if (coarse(slot) < 0) then
               coarse(slot) = 0
               call grid%find_cell(grid%leaf_level(e) - 1, parent + dir_p(1:d), first, last)
               if (first == last) then
                  if (grid%leaf_level(first) < grid%leaf_level(e)) coarse(slot) = first
               end if
            end if
            c = coarse(slot)
            if (c == 0) cycle
            sc = 2**(nodes%lattice_level - grid%leaf_level(c))
            do m = 1, n_side(k)
               n = nodes%connectivity(side_nodes(m, k), e)
               if (hanging(n)) cycle
               r(1:d) = nodes%lattice(:, n) - grid%leaf_coord(:, c)*sc
               if (any(r(1:d) < 0 .or. r(1:d) > sc)) then
                  call fatal_error(error, 'hanging nodes: a node is not on its coarse neighbour', stat_internal)
                  return
               end if
               if (all(mod(r(1:d), sc/p) == 0)) cycle
               hanging(n) = .true.
               owner(n) = c
            end do
         end do
      end do

      ! Second pass: the rows. A master whose shape function vanishes on the hanging
      ! node's face or edge is left out (decided on the integer lattice).
      allocate (rows%ptr(nodes%n_nodes + 1), stat=stat)
      call check_allocation(stat, who, 'the row pointers of T', nodes%n_nodes + 1, 4, error)
      if (allocated(error)) return
      rows%ptr(1) = 1
      do n = 1, nodes%n_nodes
         pos = 1
         if (hanging(n)) then
            call offsets(n, r, sc)
            pos = 0
            do j = 1, nen
               if (is_master(r, sc, idx(:, j))) pos = pos + 1
            end do
         end if
         rows%ptr(n + 1) = rows%ptr(n) + pos
      end do
      allocate (rows%col(rows%ptr(nodes%n_nodes + 1) - 1), rows%val(rows%ptr(nodes%n_nodes + 1) - 1), stat=stat)
      call check_allocation(stat, who, 'the entries of T', rows%ptr(nodes%n_nodes + 1) - 1, 12, error)
      if (allocated(error)) return
      do n = 1, nodes%n_nodes
         pos = rows%ptr(n)
         if (.not. hanging(n)) then
            rows%col(pos) = n
            rows%val(pos) = 1.0_wp
            cycle
         end if
         call offsets(n, r, sc)
         ! r / sc is a multiple of 1/4: exact in binary, so are the shape values.
         call element_shape(d, p, real(r(1:d), wp)/real(sc, wp), shape)
         do j = 1, nen
            if (.not. is_master(r, sc, idx(:, j))) cycle
            rows%col(pos) = nodes%connectivity(j, owner(n))
            rows%val(pos) = shape(j)
            pos = pos + 1
         end do
      end do
      call compress(rows, error)

   contains

      !> Lattice offset r of hanging node n from its owner's lowest corner, owner size sc.
      subroutine offsets(n, r, sc)
         integer, intent(in) :: n
         integer, intent(out) :: r(3), sc
         sc = 2**(nodes%lattice_level - grid%leaf_level(owner(n)))
         r = 0
         r(1:d) = nodes%lattice(:, n) - grid%leaf_coord(:, owner(n))*sc
      end subroutine offsets

      !> Does the coarse node with Lagrange index `ij` carry weight at offset r? Not if
      !> along some axis r sits on another node position (the 1D factor is then zero).
      pure logical function is_master(r, sc, ij)
         integer, intent(in) :: r(3), sc, ij(:)
         is_master = .not. any(mod(r(1:d)*p, sc) == 0 .and. r(1:d)*p/sc /= ij)
      end function is_master

   end subroutine direct_constraints

   !> Directions of the faces and edges of an element (corners are left out: a corner
   !> contact never puts a node inside a coarse face or edge) and, for each, the local
   !> nodes on that side.
   pure subroutine side_tables(d, p, idx, dir, ndir, side_nodes, n_side)
      integer, intent(in) :: d, p, idx(:, :)
      integer, intent(out) :: dir(3, 26), ndir
      integer, allocatable, intent(out) :: side_nodes(:, :), n_side(:)
      integer :: k, j, t(3), side(3)

      allocate (side_nodes(size(idx, 2), 26), n_side(26))
      ndir = 0
      dir = 0
      n_side = 0
      side_nodes = 0
      do k = 0, 3**d - 1
         t = [mod(k, 3) - 1, mod(k/3, 3) - 1, mod(k/9, 3) - 1]
         if (d == 2) t(3) = 0
         if (count(t /= 0) == 0 .or. count(t /= 0) == d) cycle
         ndir = ndir + 1
         dir(:, ndir) = t
         side = merge(p, 0, t > 0)
         do j = 1, size(idx, 2)
            if (any(t(1:d) /= 0 .and. idx(:, j) /= side(1:d))) cycle
            n_side(ndir) = n_side(ndir) + 1
            side_nodes(n_side(ndir), ndir) = j
         end do
      end do
   end subroutine side_tables

   !> Replace every hanging column by its own row (one round of chain substitution).
   subroutine substitute(rows, hanging, error)
      type(rows_type), intent(inout) :: rows
      logical, intent(in) :: hanging(:)
      type(error_type), allocatable, intent(out) :: error
      type(rows_type) :: new
      integer :: n, i, k, m, pos, nrow, stat

      nrow = size(rows%ptr) - 1
      allocate (new%ptr(nrow + 1), stat=stat)
      call check_allocation(stat, who, 'the row pointers of T', nrow + 1, 4, error)
      if (allocated(error)) return
      new%ptr(1) = 1
      do n = 1, nrow
         pos = 0
         do k = rows%ptr(n), rows%ptr(n + 1) - 1
            m = rows%col(k)
            if (hanging(m)) then
               pos = pos + rows%ptr(m + 1) - rows%ptr(m)
            else
               pos = pos + 1
            end if
         end do
         new%ptr(n + 1) = new%ptr(n) + pos
      end do
      allocate (new%col(new%ptr(nrow + 1) - 1), new%val(new%ptr(nrow + 1) - 1), stat=stat)
      call check_allocation(stat, who, 'the entries of T', new%ptr(nrow + 1) - 1, 12, error)
      if (allocated(error)) return
      do n = 1, nrow
         pos = new%ptr(n)
         do k = rows%ptr(n), rows%ptr(n + 1) - 1
            m = rows%col(k)
            if (hanging(m)) then
               do i = rows%ptr(m), rows%ptr(m + 1) - 1
                  new%col(pos) = rows%col(i)
                  new%val(pos) = rows%val(k)*rows%val(i)
                  pos = pos + 1
               end do
            else
               new%col(pos) = m
               new%val(pos) = rows%val(k)
               pos = pos + 1
            end if
         end do
      end do
      call compress(new, error)
      if (allocated(error)) return
      call move_alloc(new%ptr, rows%ptr)
      call move_alloc(new%col, rows%col)
      call move_alloc(new%val, rows%val)
   end subroutine substitute

   !> Sort each row by column and sum duplicates, in place.
   subroutine compress(rows, error)
      type(rows_type), intent(inout) :: rows
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: col(:)
      real(wp), allocatable :: val(:)
      integer :: n, k, i, pos, start, col_k, stat
      real(wp) :: val_k

      pos = 1
      do n = 1, size(rows%ptr) - 1
         start = pos
         do k = rows%ptr(n), rows%ptr(n + 1) - 1
            col_k = rows%col(k)
            val_k = rows%val(k)
            ! Insertion into the (short) row under construction.
            i = pos - 1
            do while (i >= start)
               if (rows%col(i) <= col_k) exit
               i = i - 1
            end do
            if (i >= start) then
               if (rows%col(i) == col_k) then
                  rows%val(i) = rows%val(i) + val_k
                  cycle
               end if
            end if
            rows%col(i + 2:pos) = rows%col(i + 1:pos - 1)
            rows%val(i + 2:pos) = rows%val(i + 1:pos - 1)
            rows%col(i + 1) = col_k
            rows%val(i + 1) = val_k
            pos = pos + 1
         end do
         rows%ptr(n) = start
      end do
      rows%ptr(size(rows%ptr)) = pos
      allocate (col(pos - 1), val(pos - 1), stat=stat)
      call check_allocation(stat, who, 'the entries of T', pos - 1, 12, error)
      if (allocated(error)) return
      col(:) = rows%col(1:pos - 1)
      val(:) = rows%val(1:pos - 1)
      call move_alloc(col, rows%col)
      call move_alloc(val, rows%val)
   end subroutine compress

end module sprc_grid_hanging
