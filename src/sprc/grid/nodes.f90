!> Nodes of the Q1 / Q2 Lagrange elements on the active leaves of a grid.
!>
!> Elements are the grid's leaves in its (Morton) order: element e is leaf e.
!> Local node order is VTK's (`sprc_core_lagrange`), so output needs no permutation.
!>
!> Nodes live on an integer lattice of resolution `lattice_level` = finest leaf
!> level + 1 (so Q2 midpoints of the finest leaves are lattice points) and are
!> merged by lattice coordinates, so no two nodes share a position. Numbering
!> is by first appearance when the elements are visited in order and their
!> nodes in local order: deterministic and local in memory. Only nodes of
!> active elements exist.
module sprc_grid_nodes
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_core_hash, only: key_table_type
   use sprc_core_lagrange, only: element_node_index, tensor_shape
   use sprc_grid_tree, only: grid_type
   implicit none
   private

   public :: grid_nodes_type, element_node_index, element_shape, nodes_per_element

   !> The routine named in messages.
   character(len=*), parameter :: who = 'grid nodes'

   !> Node numbering, coordinates, connectivity and node-to-element adjacency.
   type :: grid_nodes_type
      !> Space dimension and element degree (1: Q1, 2: Q2).
      integer :: dim = 0, degree = 0
      integer :: n_nodes = 0, n_elements = 0, nodes_per_element = 0
      !> Node lattice resolution: lattice coordinates are in units of box_size / 2**lattice_level.
      integer :: lattice_level = 0
      !> Integer lattice coordinates (dim, n_nodes).
      integer, allocatable :: lattice(:, :)
      !> Coordinates (dim, n_nodes).
      real(wp), allocatable :: x(:, :)
      !> Global node of each local node (nodes_per_element, n_elements), VTK order.
      integer, allocatable :: connectivity(:, :)
      !> Elements sharing node i: node_element(node_element_ptr(i) : node_element_ptr(i+1)-1), ascending.
      integer, allocatable :: node_element_ptr(:), node_element(:)
   contains
      procedure :: build => nodes_build
      procedure :: copy => nodes_copy
   end type grid_nodes_type

contains

   !> Number of nodes of a Q`degree` element in `dim` dimensions.
   pure integer function nodes_per_element(dim, degree)
      integer, intent(in) :: dim, degree
      nodes_per_element = (degree + 1)**dim
   end function nodes_per_element

   !> Values of the Q`degree` shape functions (VTK order) at reference point xi in [0, 1]^dim.
   pure subroutine element_shape(dim, degree, xi, shape)
      integer, intent(in) :: dim, degree
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: shape(:)
      call tensor_shape(element_node_index(dim, degree), degree, xi, shape)
   end subroutine element_shape

   !> Number the Q`degree` nodes of the active leaves of `grid`.
   subroutine nodes_build(self, grid, degree, error)
      class(grid_nodes_type), intent(out) :: self
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: degree
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: idx(:, :)
      type(key_table_type) :: table
      integer :: d, nen, e, j, size_e, step, estimate, stat
      logical :: added
      real(wp) :: h

      if (degree /= 1 .and. degree /= 2) then
         call fatal_error(error, 'grid nodes: degree must be 1 (Q1) or 2 (Q2)', stat_invalid_input)
         return
      end if
      if (grid%dim /= 2 .and. grid%dim /= 3) then
         call fatal_error(error, 'grid nodes: the grid is not built', stat_invalid_input)
         return
      end if
      d = grid%dim
      nen = nodes_per_element(d, degree)
      allocate (idx, source=element_node_index(d, degree))
      self%dim = d
      self%degree = degree
      self%nodes_per_element = nen
      self%n_elements = grid%n_leaves
      self%lattice_level = grid%max_level + 1

      ! Each element adds about degree**dim nodes of its own; the table grows if that is short.
      estimate = grid%n_leaves*degree**d + 64
      call table%init(d, estimate, who, error)
      if (allocated(error)) return
      allocate (self%connectivity(nen, grid%n_leaves), stat=stat)
      call check_allocation(stat, who, 'the element connectivity', grid%n_leaves, 4*nen, error)
      if (allocated(error)) return
      do e = 1, grid%n_leaves
         size_e = 2**(self%lattice_level - grid%leaf_level(e))
         step = size_e/degree
         do j = 1, nen
            call table%insert(grid%leaf_coord(:, e)*size_e + idx(:, j)*step, self%connectivity(j, e), added, error)
            if (allocated(error)) return
         end do
      end do
      self%n_nodes = table%n
      allocate (self%lattice(d, self%n_nodes), stat=stat)
      call check_allocation(stat, who, 'the node lattice points', self%n_nodes, 4*d, error)
      if (allocated(error)) return
      self%lattice(:, :) = table%keys(:, 1:self%n_nodes)

      h = grid%box_size*2.0_wp**(-self%lattice_level)
      allocate (self%x(d, self%n_nodes), stat=stat)
      call check_allocation(stat, who, 'the node coordinates', self%n_nodes, 8*d, error)
      if (allocated(error)) return
      do j = 1, self%n_nodes
         self%x(:, j) = grid%box_min(1:d) + real(self%lattice(:, j), wp)*h
      end do
      call node_elements(self, error)
   end subroutine nodes_build

   !> `copy` = the nodes, with a failed allocation returned as an error (the intrinsic
   !> assignment copy = nodes stops the program when it cannot allocate, or crashes).
   subroutine nodes_copy(self, copy, error)
      class(grid_nodes_type), intent(in) :: self
      type(grid_nodes_type), intent(out) :: copy
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      stat = 0
      if (allocated(self%lattice)) allocate (copy%lattice, source=self%lattice, stat=stat)
      if (stat == 0 .and. allocated(self%x)) allocate (copy%x, source=self%x, stat=stat)
      if (stat == 0 .and. allocated(self%connectivity)) &
         & allocate (copy%connectivity, source=self%connectivity, stat=stat)
      if (stat == 0 .and. allocated(self%node_element_ptr)) &
         & allocate (copy%node_element_ptr, source=self%node_element_ptr, stat=stat)
      if (stat == 0 .and. allocated(self%node_element)) &
         & allocate (copy%node_element, source=self%node_element, stat=stat)
      call check_allocation(stat, 'grid nodes copy', 'the nodes', self%n_nodes, &
         & 12*self%dim + 4*(2 + 2*self%nodes_per_element), error)
      if (allocated(error)) return
      copy%dim = self%dim
      copy%degree = self%degree
      copy%n_nodes = self%n_nodes
      copy%n_elements = self%n_elements
      copy%nodes_per_element = self%nodes_per_element
      copy%lattice_level = self%lattice_level
   end subroutine nodes_copy

   !> Node -> elements adjacency (CSR), elements ascending.
   subroutine node_elements(self, error)
      type(grid_nodes_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: fill(:)
      integer :: e, j, n, stat

      allocate (self%node_element_ptr(self%n_nodes + 1), fill(self%n_nodes), stat=stat)
      call check_allocation(stat, who, 'the node-to-element pointers', self%n_nodes, 8, error)
      if (allocated(error)) return
      self%node_element_ptr = 0
      do e = 1, self%n_elements
         do j = 1, self%nodes_per_element
            n = self%connectivity(j, e)
            self%node_element_ptr(n + 1) = self%node_element_ptr(n + 1) + 1
         end do
      end do
      self%node_element_ptr(1) = 1
      do n = 1, self%n_nodes
         self%node_element_ptr(n + 1) = self%node_element_ptr(n + 1) + self%node_element_ptr(n)
      end do
      allocate (self%node_element(self%node_element_ptr(self%n_nodes + 1) - 1), stat=stat)
      call check_allocation(stat, who, 'the node-to-element lists', self%node_element_ptr(self%n_nodes + 1) - 1, &
         & 4, error)
      if (allocated(error)) return
      fill(:) = self%node_element_ptr(1:self%n_nodes)
      do e = 1, self%n_elements
         do j = 1, self%nodes_per_element
            n = self%connectivity(j, e)
            self%node_element(fill(n)) = e
            fill(n) = fill(n) + 1
         end do
      end do
   end subroutine node_elements

end module sprc_grid_nodes
