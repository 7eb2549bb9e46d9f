!> Dofs of the FE space and the transformation u = T ubar from the reduced
!> unknowns ubar to the displacement components of all nodes.
!>
!> T is built per node (scalar, applied per component) from two sources, then
!> restricted per component:
!> 1. hanging nodes (`sprc_grid_hanging`): u_h = sum_k c_k u_k over free nodes;
!> 2. cell aggregation (`sprc_fem_aggregation`): a free node that no
!>    well-posed cell uses (directly or as a hanging-node master) is an
!>    "outlaw"; it takes the value of its root cell's polynomial,
!>    u_i = sum_j N_j^root(x_i) u_j over the root's nodes (themselves expanded
!>    by 1, whose masters all belong to well-posed cells). The outlaw's root is
!>    the root of the lowest-numbered cell containing it.
!> The free nodes that remain are the masters, numbered in node order.
!> 3. strong zero components: component c of a node lying on a plane
!>    x_c = const listed by the caller (a symmetry plane on grid planes) is
!>    zero. Its row of T is empty, and a master's component on such a plane
!>    is not an unknown.
!> The reduced dofs are the remaining (master, component) pairs, numbered
!> master by master. T reproduces every field whose components are linear
!> (hanging and aggregation constraints interpolate polynomials exactly), up
!> to the zeroed components.
!>
!> Element matrices are reduced element by element: `element_map` gives the
!> element's reduced dofs and the dense block T_e (rows: local dofs, node-major).
module sprc_fem_constraints
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_internal
   use sprc_core_alloc, only: check_allocation
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type, element_shape
   use sprc_grid_hanging, only: hanging_type
   use sprc_core_sort, only: sort_pairs
   implicit none
   private

   public :: constraint_type

   !> u = T ubar (module notes).
   type :: constraint_type
      integer :: dim = 0
      !> Nodes (rows of the node-level T), masters (its columns), reduced dofs.
      integer :: n_nodes = 0, n_masters = 0, n_dofs = 0
      !> Free nodes constrained by aggregation (outlaws).
      integer :: n_outlaw = 0
      !> Node-level T in CSR over master numbers: row i is t_col/t_val(t_ptr(i) : t_ptr(i+1)-1).
      integer, allocatable :: t_ptr(:), t_col(:)
      real(wp), allocatable :: t_val(:)
      !> Node of each master (n_masters).
      integer, allocatable :: master_node(:)
      !> Reduced dof of component c of master m, 0 when that component is zero (dim, n_masters).
      integer, allocatable :: dof(:, :)
      !> Component c of node i is zero (strong symmetry) (dim, n_nodes).
      logical, allocatable :: zero(:, :)
   contains
      procedure :: build => constraints_build
      procedure :: element_map
      procedure :: expand
      procedure :: restrict_field
   end type constraint_type

contains

   !> Build T for `nodes` on `grid` with hanging constraints `hanging`, cell roots
   !> `root` (root(e) = e: well-posed) and strong zero planes: component
   !> plane_axis(k) is zero on the nodes with |x(plane_axis(k)) - plane_coord(k)| <= tol.
   subroutine constraints_build(self, grid, nodes, hanging, root, plane_axis, plane_coord, tol, error)
      class(constraint_type), intent(out) :: self
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      integer, intent(in) :: root(:), plane_axis(:)
      real(wp), intent(in) :: plane_coord(:), tol
      type(error_type), allocatable, intent(out) :: error
      logical, allocatable :: supported(:)
      integer, allocatable :: master_of(:), a_ptr(:), a_col(:), marker(:), row_col(:)
      real(wp), allocatable :: a_val(:), acc(:)
      integer :: d, e, j, k, i, m, c, nfree, p, q, nrow, r, na, nt, stat
      logical :: done
      real(wp) :: lo(3), hi(3), xi(3), shape(27)
      character(len=*), parameter :: who = 'constraints'

      d = nodes%dim
      if (size(root) /= nodes%n_elements .or. hanging%n_all /= nodes%n_nodes) then
         call fatal_error(error, 'constraints: root or hanging data do not match the nodes', stat_invalid_input)
         return
      end if
      self%dim = d
      self%n_nodes = nodes%n_nodes
      nfree = hanging%n_free

      ! Free nodes used by a well-posed cell.
      allocate (supported(nfree), master_of(nfree), stat=stat)
      call check_allocation(stat, who, 'the master flags of the free nodes', nfree, 8, error)
      if (allocated(error)) return
      supported = .false.
      ! Only .true. is written: the same flags for any schedule.
      !$omp parallel do schedule(static) private(j, i, q)
      do e = 1, nodes%n_elements
         if (root(e) /= e) cycle
         do j = 1, nodes%nodes_per_element
            i = nodes%connectivity(j, e)
            do q = hanging%t_ptr(i), hanging%t_ptr(i + 1) - 1
               !$omp atomic write
               supported(hanging%t_col(q)) = .true.
            end do
         end do
      end do
      !$omp end parallel do
      m = 0
      do k = 1, nfree
         master_of(k) = 0
         if (.not. supported(k)) cycle
         m = m + 1
         master_of(k) = m
      end do
      self%n_masters = m
      allocate (self%master_node(m), stat=stat)
      call check_allocation(stat, who, 'the master nodes', m, 4, error)
      if (allocated(error)) return
      do k = 1, nfree
         if (master_of(k) > 0) self%master_node(master_of(k)) = hanging%free_node(k)
      end do
      self%n_outlaw = nfree - m

      ! Outlaw rows A(k, :) over masters: the root polynomial at the outlaw's position.
      allocate (a_ptr(nfree + 1), marker(m), acc(m), row_col(m), stat=stat)
      call check_allocation(stat, who, 'the outlaw rows', m, 20, error)
      if (allocated(error)) return
      marker = 0
      allocate (a_col(16), a_val(16))
      na = 0
      a_ptr(1) = 1
      do k = 1, nfree
         nrow = 0
         if (supported(k)) then
            a_ptr(k + 1) = na + 1
            cycle
         end if
         i = hanging%free_node(k)
         e = nodes%node_element(nodes%node_element_ptr(i))
         r = root(e)
         call grid%leaf_box(r, lo(1:d), hi(1:d))
         xi(1:d) = (nodes%x(:, i) - lo(1:d))/(hi(1:d) - lo(1:d))
         call element_shape(d, nodes%degree, xi(1:d), shape)
         do j = 1, nodes%nodes_per_element
            p = nodes%connectivity(j, r)
            do q = hanging%t_ptr(p), hanging%t_ptr(p + 1) - 1
               c = master_of(hanging%t_col(q))
               if (c == 0) then
                  call fatal_error(error, 'constraints: a well-posed cell uses an unsupported node', &
                     & stat_internal)
                  return
               end if
               call accumulate(c, shape(j)*hanging%t_val(q))
            end do
         end do
         call flush_row(a_col, a_val, na)
         if (allocated(error)) return
         a_ptr(k + 1) = na + 1
      end do

      ! Node rows: hanging rows with outlaws replaced by their A rows.
      nt = 0
      allocate (self%t_ptr(self%n_nodes + 1), stat=stat)
      call check_allocation(stat, who, 'the row pointers of T', self%n_nodes + 1, 4, error)
      if (allocated(error)) return
      allocate (self%t_col(size(hanging%t_col) + 16), self%t_val(size(hanging%t_col) + 16), stat=stat)
      call check_allocation(stat, who, 'the entries of T', size(hanging%t_col) + 16, 12, error)
      if (allocated(error)) return
      self%t_ptr(1) = 1
      do i = 1, self%n_nodes
         nrow = 0
         call master_row(i, done)
         if (allocated(error)) return
         if (done) then
            self%t_ptr(i + 1) = nt + 1
            cycle
         end if
         do q = hanging%t_ptr(i), hanging%t_ptr(i + 1) - 1
            k = hanging%t_col(q)
            if (master_of(k) > 0) then
               call accumulate(master_of(k), hanging%t_val(q))
            else
               do p = a_ptr(k), a_ptr(k + 1) - 1
                  call accumulate(a_col(p), hanging%t_val(q)*a_val(p))
               end do
            end if
         end do
         call flush_row(self%t_col, self%t_val, nt)
         if (allocated(error)) return
         self%t_ptr(i + 1) = nt + 1
      end do
      call resize(self%t_col, self%t_val, nt, error)
      if (allocated(error)) return

      ! Strong zero components and the reduced dof numbers.
      allocate (self%zero(d, self%n_nodes), self%dof(d, m), stat=stat)
      call check_allocation(stat, who, 'the dof numbers', self%n_nodes, 8*d, error)
      if (allocated(error)) return
      !$omp parallel do schedule(static) private(k)
      do i = 1, self%n_nodes
         self%zero(:, i) = .false.
         do k = 1, size(plane_axis)
            if (abs(nodes%x(plane_axis(k), i) - plane_coord(k)) <= tol) self%zero(plane_axis(k), i) = .true.
         end do
      end do
      !$omp end parallel do
      self%n_dofs = 0
      do j = 1, m
         do c = 1, d
            self%dof(c, j) = 0
            if (self%zero(c, self%master_node(j))) cycle
            self%n_dofs = self%n_dofs + 1
            self%dof(c, j) = self%n_dofs
         end do
      end do

   contains

      !> Row i when it is one entry on a master (most nodes; done): that entry, appended
      !> unless zero, as accumulate and flush_row give it (0 + v = v) without their work.
      subroutine master_row(i, done)
         integer, intent(in) :: i
         logical, intent(out) :: done
         integer :: q
         done = .false.
         if (hanging%t_ptr(i + 1) - hanging%t_ptr(i) /= 1) return
         q = hanging%t_ptr(i)
         if (master_of(hanging%t_col(q)) == 0) return
         done = .true.
         if (hanging%t_val(q) == 0.0_wp) return
         if (nt == size(self%t_col)) then
            call resize(self%t_col, self%t_val, 2*size(self%t_col), error)
            if (allocated(error)) return
         end if
         nt = nt + 1
         self%t_col(nt) = master_of(hanging%t_col(q))
         self%t_val(nt) = hanging%t_val(q)
      end subroutine master_row

      subroutine accumulate(col, val)
         integer, intent(in) :: col
         real(wp), intent(in) :: val
         if (marker(col) == 0) then
            nrow = nrow + 1
            row_col(nrow) = col
            marker(col) = nrow
            acc(nrow) = 0.0_wp
         end if
         acc(marker(col)) = acc(marker(col)) + val
      end subroutine accumulate

      !> Append the accumulated row (columns ascending, exact zeros dropped) and reset the marker.
      subroutine flush_row(cols, vals, count)
         integer, allocatable, intent(inout) :: cols(:)
         real(wp), allocatable, intent(inout) :: vals(:)
         integer, intent(inout) :: count
         integer :: a
         call sort_pairs(row_col(1:nrow), acc(1:nrow))
         do a = 1, nrow
            marker(row_col(a)) = 0
         end do
         if (count + nrow > size(cols)) then
            call resize(cols, vals, max(count + nrow, 2*size(cols)), error)
            if (allocated(error)) return
         end if
         do a = 1, nrow
            if (acc(a) == 0.0_wp) cycle
            count = count + 1
            cols(count) = row_col(a)
            vals(count) = acc(a)
         end do
         nrow = 0
      end subroutine flush_row

   end subroutine constraints_build

   !> Resize the entries (cols, vals) of T to `n`, keeping the first min(n, size) of them.
   subroutine resize(cols, vals, n, error)
      integer, allocatable, intent(inout) :: cols(:)
      real(wp), allocatable, intent(inout) :: vals(:)
      integer, intent(in) :: n
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: c(:)
      real(wp), allocatable :: v(:)
      integer :: keep, stat

      allocate (c(n), v(n), stat=stat)
      call check_allocation(stat, 'constraints', 'the entries of T', n, 12, error)
      if (allocated(error)) return
      keep = min(n, size(cols))
      c(1:keep) = cols(1:keep)
      v(1:keep) = vals(1:keep)
      call move_alloc(c, cols)
      call move_alloc(v, vals)
   end subroutine resize

   !> Reduced dofs dofs(1:m) (ascending) of an element with nodes `conn` and the
   !> block tmat(1:dim*size(conn), 1:m) with u_e = tmat ubar(dofs). `dofs` and
   !> `tmat` must be large enough (size(dofs) >= number of distinct dofs).
   pure subroutine element_map(self, conn, dofs, tmat, m)
      class(constraint_type), intent(in) :: self
      integer, intent(in) :: conn(:)
      integer, intent(out) :: dofs(:)
      real(wp), intent(out) :: tmat(:, :)
      integer, intent(out) :: m
      integer :: j, c, q, g, a, b, d, row, pos

      d = self%dim
      m = 0
      do j = 1, size(conn)
         do q = self%t_ptr(conn(j)), self%t_ptr(conn(j) + 1) - 1
            do c = 1, d
               if (self%zero(c, conn(j))) cycle
               g = self%dof(c, self%t_col(q))
               if (g == 0) cycle
               if (any(dofs(1:m) == g)) cycle
               m = m + 1
               dofs(m) = g
            end do
         end do
      end do
      ! ascending order, so the element's entries reach the COO in a fixed order
      do a = 2, m
         g = dofs(a)
         b = a - 1
         do while (b >= 1)
            if (dofs(b) <= g) exit
            dofs(b + 1) = dofs(b)
            b = b - 1
         end do
         dofs(b + 1) = g
      end do
      tmat(1:d*size(conn), 1:m) = 0.0_wp
      do j = 1, size(conn)
         do c = 1, d
            if (self%zero(c, conn(j))) cycle
            row = (j - 1)*d + c
            do q = self%t_ptr(conn(j)), self%t_ptr(conn(j) + 1) - 1
               g = self%dof(c, self%t_col(q))
               if (g == 0) cycle
               pos = findloc(dofs(1:m), g, 1)
               tmat(row, pos) = tmat(row, pos) + self%t_val(q)
            end do
         end do
      end do
   end subroutine element_map

   !> u(dim, n_nodes) = T ubar(n_dofs).
   pure subroutine expand(self, ubar, u)
      class(constraint_type), intent(in) :: self
      real(wp), intent(in) :: ubar(:)
      real(wp), intent(out) :: u(:, :)
      integer :: i, c, q, g
      do i = 1, self%n_nodes
         do c = 1, self%dim
            u(c, i) = 0.0_wp
            if (self%zero(c, i)) cycle
            do q = self%t_ptr(i), self%t_ptr(i + 1) - 1
               g = self%dof(c, self%t_col(q))
               if (g > 0) u(c, i) = u(c, i) + self%t_val(q)*ubar(g)
            end do
         end do
      end do
   end subroutine expand

   !> ubar(n_dofs) holding the nodal field u(dim, n_nodes) at the masters (the
   !> reduced representation of a field T reproduces; zeroed components dropped).
   pure subroutine restrict_field(self, u, ubar)
      class(constraint_type), intent(in) :: self
      real(wp), intent(in) :: u(:, :)
      real(wp), intent(out) :: ubar(:)
      integer :: j, c
      do j = 1, self%n_masters
         do c = 1, self%dim
            if (self%dof(c, j) > 0) ubar(self%dof(c, j)) = u(c, self%master_node(j))
         end do
      end do
   end subroutine restrict_field

end module sprc_fem_constraints
