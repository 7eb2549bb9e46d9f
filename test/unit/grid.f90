!> Tests of the grid layer: Morton keys, the hierarchical grid (counts, 2:1
!> balance, queries), Q1/Q2 node numbering and hanging-node constraints.
!> The regions used here are defined in this module (exact disk/sphere,
!> half-space, constant and broken classifiers), independent of the geometry layer.
module sprc_test_grid
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input
   use sprc_geometry_region, only: region_type, cell_outside, cell_inside, cell_cut
   use sprc_grid_morton, only: morton_encode, morton_decode, morton_max_bits
   use sprc_grid_tree, only: grid_type, grid_max_level
   use sprc_grid_nodes, only: grid_nodes_type, element_node_index, element_shape, nodes_per_element
   use sprc_grid_hanging, only: hanging_type
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_grid, check_balance, check_volume, int_box

   !> Closed ball |x - centre| <= radius, classified exactly: nearest point of the
   !> box (clamped centre) and farthest corner.
   type, extends(region_type) :: ball_region
      real(wp) :: centre(3) = 0.0_wp
      real(wp) :: radius = 0.0_wp
   contains
      procedure :: classify_box => ball_classify
   end type ball_region

   !> Half-space normal . x <= offset, exact for boxes (extreme corners).
   type, extends(region_type) :: halfspace_region
      real(wp) :: normal(3) = 0.0_wp
      real(wp) :: offset = 0.0_wp
   contains
      procedure :: classify_box => halfspace_classify
   end type halfspace_region

   !> Union of two axis-aligned boxes (exact when no cell is covered by the two together).
   type, extends(region_type) :: two_boxes_region
      real(wp) :: lo(3, 2) = 0.0_wp, hi(3, 2) = 0.0_wp
   contains
      procedure :: classify_box => two_boxes_classify
   end type two_boxes_region

   !> Answers the same class for every box (empty body, whole box, or a broken region).
   type, extends(region_type) :: constant_region
      integer :: answer = cell_outside
   contains
      procedure :: classify_box => constant_classify
   end type constant_region

   !> Values that are exact in binary (0, 1, 1/2, 3/8, ...) are compared with this margin,
   !> which admits nothing but an exact result up to the last bit of an O(1) number.
   real(wp), parameter :: exact = 4.0_wp*epsilon(1.0_wp)

   !> Deterministic pseudo-random numbers (a 48-bit LCG), so tests do not depend on the compiler's generator.
   type :: lcg_type
      integer(i8) :: state = 12345_i8
   end type lcg_type

contains

   subroutine collect_grid(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('morton-hand-values', test_morton_hand), &
         new_unittest('morton-round-trip', test_morton_round_trip), &
         new_unittest('uniform-counts-2d', test_uniform_counts_2d), &
         new_unittest('uniform-counts-3d', test_uniform_counts_3d), &
         new_unittest('uniform-brute-force', test_uniform_brute_force), &
         new_unittest('cut-growth-2d', test_cut_growth_2d), &
         new_unittest('cut-growth-3d', test_cut_growth_3d), &
         new_unittest('balance-2d', test_balance_2d), &
         new_unittest('balance-3d', test_balance_3d), &
         new_unittest('leaf-classes', test_leaf_classes), &
         new_unittest('queries', test_queries), &
         new_unittest('deep-level-3d', test_deep_level), &
         new_unittest('shape-functions', test_shape_functions), &
         new_unittest('nodes-uniform', test_nodes_uniform), &
         new_unittest('nodes-refined', test_nodes_refined), &
         new_unittest('grid-nodes-copy', test_grid_nodes_copy), &
         new_unittest('hanging-q1-2d', test_hanging_q1_2d), &
         new_unittest('hanging-q2-2d', test_hanging_q2_2d), &
         new_unittest('hanging-q1-3d', test_hanging_q1_3d), &
         new_unittest('hanging-q2-3d', test_hanging_q2_3d), &
         new_unittest('hanging-edge-only-3d', test_hanging_edge_only), &
         new_unittest('hanging-hand-2d', test_hanging_hand), &
         new_unittest('hanging-chain', test_hanging_chain), &
         new_unittest('degenerate-aligned', test_degenerate_aligned), &
         new_unittest('degenerate-tiny-body', test_degenerate_tiny), &
         new_unittest('degenerate-empty-full', test_degenerate_empty_full), &
         new_unittest('degenerate-through-nodes', test_degenerate_through_nodes), &
         new_unittest('bad-input', test_bad_input), &
         new_unittest('bad-region-and-nodes', test_bad_region_nodes) &
         ]
   end subroutine collect_grid

   ! ------------------------------------------------------------------ regions

   pure integer function ball_classify(self, lo, hi) result(cls)
      class(ball_region), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: near(size(lo)), far(size(lo)), c(size(lo))
      c = self%centre(1:size(lo))
      near = min(max(c, lo), hi)
      far = merge(lo, hi, abs(c - lo) > abs(c - hi))
      if (sum((far - c)**2) <= self%radius**2) then
         cls = cell_inside
      else if (sum((near - c)**2) >= self%radius**2) then
         cls = cell_outside
      else
         cls = cell_cut
      end if
   end function ball_classify

   pure integer function halfspace_classify(self, lo, hi) result(cls)
      class(halfspace_region), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: vmin, vmax, n(size(lo))
      n = self%normal(1:size(lo))
      vmin = sum(merge(lo, hi, n >= 0.0_wp)*n)
      vmax = sum(merge(hi, lo, n >= 0.0_wp)*n)
      if (vmax <= self%offset) then
         cls = cell_inside
      else if (vmin >= self%offset) then
         cls = cell_outside
      else
         cls = cell_cut
      end if
   end function halfspace_classify

   pure integer function two_boxes_classify(self, lo, hi) result(cls)
      class(two_boxes_region), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      integer :: k, d, c(2)
      d = size(lo)
      do k = 1, 2
         if (all(lo >= self%lo(1:d, k) .and. hi <= self%hi(1:d, k))) then
            c(k) = cell_inside
         else if (any(hi <= self%lo(1:d, k) .or. lo >= self%hi(1:d, k))) then
            c(k) = cell_outside
         else
            c(k) = cell_cut
         end if
      end do
      if (any(c == cell_inside)) then
         cls = cell_inside
      else if (all(c == cell_outside)) then
         cls = cell_outside
      else
         cls = cell_cut
      end if
   end function two_boxes_classify

   pure integer function constant_classify(self, lo, hi) result(cls)
      class(constant_region), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      cls = self%answer
      if (size(lo) /= size(hi)) cls = -1
   end function constant_classify

   function ball(dim, radius) result(r)
      integer, intent(in) :: dim
      real(wp), intent(in) :: radius
      type(ball_region) :: r
      ! Off-centre so that no symmetry hides an error.
      r%centre = [0.513_wp, 0.4871_wp, 0.5029_wp]
      if (dim == 2) r%centre(3) = 0.0_wp
      r%radius = radius
   end function ball

   real(wp) function uniform(rng)
      type(lcg_type), intent(inout) :: rng
      rng%state = modulo(rng%state*25214903917_i8 + 11_i8, 281474976710656_i8)
      uniform = real(rng%state, wp)/281474976710656.0_wp
   end function uniform

   ! ------------------------------------------------------------------ helpers

   !> Sum over levels of all leaf counts weighted by volume must equal the box.
   subroutine check_volume(error, grid)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: grid
      integer(i8) :: total
      integer :: l
      total = 0_i8
      do l = 0, grid%max_level
         total = total + (grid%n_inside(l) + grid%n_cut(l) + grid%n_outside(l))* &
            & ishft(1_i8, grid%dim*(grid%max_level - l))
      end do
      call check(error, total == ishft(1_i8, grid%dim*grid%max_level), &
         & 'leaf and external volumes do not add up to the box')
      if (allocated(error)) return
      call check(error, int(sum(grid%n_inside + grid%n_cut)), grid%n_leaves, 'leaf count by class')
   end subroutine check_volume

   !> Integer box of leaf i at resolution grid_max_level: [lo, hi] (closed).
   pure subroutine int_box(grid, i, lo, hi)
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: i
      integer, intent(out) :: lo(3), hi(3)
      integer :: s
      s = 2**(grid_max_level - grid%leaf_level(i))
      lo = 0
      hi = 0
      lo(1:grid%dim) = grid%leaf_coord(:, i)*s
      hi(1:grid%dim) = lo(1:grid%dim) + s
   end subroutine int_box

   !> Brute force over all pairs: touching leaves (faces, edges or corners) differ by
   !> at most one level, and no two leaves overlap.
   subroutine check_balance(error, grid)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: grid
      integer, allocatable :: lo(:, :), hi(:, :)
      integer :: i, j, d
      logical :: touch, overlap
      character(len=80) :: msg

      d = grid%dim
      allocate (lo(3, grid%n_leaves), hi(3, grid%n_leaves))
      do i = 1, grid%n_leaves
         call int_box(grid, i, lo(:, i), hi(:, i))
      end do
      do i = 1, grid%n_leaves
         do j = i + 1, grid%n_leaves
            touch = all(lo(1:d, i) <= hi(1:d, j) .and. lo(1:d, j) <= hi(1:d, i))
            if (.not. touch) cycle
            overlap = all(lo(1:d, i) < hi(1:d, j) .and. lo(1:d, j) < hi(1:d, i))
            if (overlap .or. abs(grid%leaf_level(i) - grid%leaf_level(j)) > 1) then
               write (msg, '(a,2i8,a,2i4)') 'leaves ', i, j, ' overlap or break 2:1, levels ', &
                  & grid%leaf_level(i), grid%leaf_level(j)
               call test_failed(error, trim(msg))
               return
            end if
         end do
      end do
   end subroutine check_balance

   ! ------------------------------------------------------------------ Morton

   subroutine test_morton_hand(error)
      type(error_type), allocatable, intent(out) :: error
      ! Interleaving by hand: x=101, y=011 -> y2x2 y1x1 y0x0 = 01 10 11 = 27;
      ! x=011, y=101, z=111 -> 110 101 111 = 431.
      call check(error, morton_encode([1, 0]) == 1_i8 .and. morton_encode([0, 1]) == 2_i8, 'unit keys 2d')
      if (allocated(error)) return
      call check(error, morton_encode([5, 3]) == 27_i8, 'key of (5,3)')
      if (allocated(error)) return
      call check(error, morton_encode([0, 0, 1]) == 4_i8, 'unit key z')
      if (allocated(error)) return
      call check(error, morton_encode([3, 5, 7]) == 431_i8, 'key of (3,5,7)')
      if (allocated(error)) return
      call check(error, morton_encode([2**21 - 1, 2**21 - 1, 2**21 - 1]) == huge(1_i8), 'largest 3d key')
      if (allocated(error)) return
      call check(error, morton_encode([huge(1), huge(1)]) == ishft(huge(1_i8), -1), 'largest 2d key')
   end subroutine test_morton_hand

   subroutine test_morton_round_trip(error)
      type(error_type), allocatable, intent(out) :: error
      type(lcg_type) :: rng
      integer :: i, dim, c(3), lim
      integer(i8) :: k
      do dim = 2, 3
         lim = morton_max_bits(dim)
         do i = 1, 2000
            c = 0
            c(1:dim) = [int(uniform(rng)*2.0_wp**lim), int(uniform(rng)*2.0_wp**lim), &
               & int(uniform(rng)*2.0_wp**min(lim, 30))]
            c(1:dim) = min(c(1:dim), 2**lim - 1)
            k = morton_encode(c(1:dim))
            call check(error, k >= 0_i8, 'negative key')
            if (allocated(error)) return
            call check(error, all(morton_decode(k, dim) == c(1:dim)), 'decode(encode(c)) /= c')
            if (allocated(error)) return
            ! One step along an axis that does not carry changes the key by its spread bit.
            if (c(1) < 2**lim - 1 .and. mod(c(1), 2) == 0) then
               call check(error, morton_encode([c(1) + 1, c(2:dim)]) == k + 1_i8, 'x step')
               if (allocated(error)) return
            end if
         end do
      end do
   end subroutine test_morton_round_trip

   ! ------------------------------------------------------------------ counts

   subroutine uniform_counts(error, dim, levels)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, levels(:)
      type(grid_type) :: grid
      integer :: i, l
      do i = 1, size(levels)
         l = levels(i)
         call grid%build(ball(dim, 0.37_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, l, 0, error)
         if (allocated(error)) return
         call check(error, grid%n_inside(l) + grid%n_cut(l) + grid%n_outside(l) == ishft(1_i8, dim*l), &
            & 'internal + cut + external /= 2**(dim*level)')
         if (allocated(error)) return
         call check(error, grid%n_leaves, int(grid%n_inside(l) + grid%n_cut(l)), 'leaves all at the uniform level')
         if (allocated(error)) return
         call check(error, all(grid%leaf_level == l), 'uniform grid with a leaf off its level')
         if (allocated(error)) return
         call check_volume(error, grid)
         if (allocated(error)) return
      end do
   end subroutine uniform_counts

   subroutine test_uniform_counts_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call uniform_counts(error, 2, [0, 1, 2, 3, 5, 8])
   end subroutine test_uniform_counts_2d

   subroutine test_uniform_counts_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call uniform_counts(error, 3, [0, 1, 2, 4, 5])
   end subroutine test_uniform_counts_3d

   !> The top-down build (which skips external subtrees and copies internal classes)
   !> against classifying every cell of the uniform level directly.
   subroutine test_uniform_brute_force(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(ball_region) :: region
      integer :: dim, l, i, j, k, n, cnt(0:2), cls
      real(wp) :: lo(3), hi(3), h
      do dim = 2, 3
         l = merge(6, 4, dim == 2)
         region = ball(dim, 0.41_wp)
         call grid%build(region, dim, [-0.1_wp, 0.05_wp, 0.0_wp], 1.2_wp, l, 0, error)
         if (allocated(error)) return
         n = 2**l
         h = 1.2_wp/real(n, wp)
         cnt = 0
         do k = 0, merge(0, n - 1, dim == 2)
            do j = 0, n - 1
               do i = 0, n - 1
                  lo = [-0.1_wp, 0.05_wp, 0.0_wp] + real([i, j, k], wp)*h
                  hi = [-0.1_wp, 0.05_wp, 0.0_wp] + real([i + 1, j + 1, k + 1], wp)*h
                  cls = region%classify_box(lo(1:dim), hi(1:dim))
                  cnt(cls) = cnt(cls) + 1
               end do
            end do
         end do
         call check(error, int(grid%n_inside(l)), cnt(cell_inside), 'internal count vs brute force')
         if (allocated(error)) return
         call check(error, int(grid%n_cut(l)), cnt(cell_cut), 'cut count vs brute force')
         if (allocated(error)) return
         call check(error, int(grid%n_outside(l)), cnt(cell_outside), 'external count vs brute force')
         if (allocated(error)) return
      end do
   end subroutine test_uniform_brute_force

   !> The boundary is a curve (surface): the cut count doubles (quadruples) per level.
   subroutine cut_growth(error, dim, lmin, lmax, expected)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, lmin, lmax
      real(wp), intent(in) :: expected
      type(grid_type) :: grid
      integer :: l
      real(wp) :: previous, ratio
      character(len=60) :: msg
      previous = 0.0_wp
      do l = lmin, lmax
         call grid%build(ball(dim, 0.37_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, l, 0, error)
         if (allocated(error)) return
         if (l > lmin) then
            ratio = real(grid%n_cut(l), wp)/previous
            write (msg, '(a,i0,a,f6.3)') 'cut ratio at level ', l, ': ', ratio
            ! Length (area) over h gives the ratio up to O(h) cells of curvature and corner effects: 15 %.
            call check(error, abs(ratio - expected) < 0.15_wp*expected, trim(msg))
            if (allocated(error)) return
         end if
         previous = real(grid%n_cut(l), wp)
      end do
   end subroutine cut_growth

   subroutine test_cut_growth_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call cut_growth(error, 2, 4, 9, 2.0_wp)
   end subroutine test_cut_growth_2d

   subroutine test_cut_growth_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call cut_growth(error, 3, 3, 6, 4.0_wp)
   end subroutine test_cut_growth_3d

   ! ------------------------------------------------------------------ balance

   subroutine balance_case(error, dim, level, radius)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level
      real(wp), intent(in) :: radius
      type(grid_type) :: grid
      integer :: refine, splits
      splits = 0
      do refine = 1, 3
         call grid%build(ball(dim, radius), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, refine, error)
         if (allocated(error)) return
         call check(error, grid%max_level, level + refine, 'finest level')
         if (allocated(error)) return
         call check_balance(error, grid)
         if (allocated(error)) return
         call check_volume(error, grid)
         if (allocated(error)) return
         splits = splits + grid%n_balance_splits
      end do
      ! Without balance these grids break 2:1 (refine >= 2 next to uniform internal cells).
      call check(error, splits > 0, 'the balance had nothing to do: the test would not see a missing balance')
   end subroutine balance_case

   subroutine test_balance_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call balance_case(error, 2, 3, 0.33_wp)
   end subroutine test_balance_2d

   subroutine test_balance_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call balance_case(error, 3, 2, 0.3_wp)
   end subroutine test_balance_3d

   !> Every leaf, including those made by the balance, carries the region's class of its box.
   subroutine test_leaf_classes(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(ball_region) :: region
      integer :: dim, i
      real(wp) :: lo(3), hi(3)
      do dim = 2, 3
         region = ball(dim, 0.3_wp)
         call grid%build(region, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2, 3, error)
         if (allocated(error)) return
         do i = 1, grid%n_leaves
            call grid%leaf_box(i, lo(1:dim), hi(1:dim))
            call check(error, grid%leaf_class(i), region%classify_box(lo(1:dim), hi(1:dim)), 'leaf class')
            if (allocated(error)) return
         end do
         call check(error, all(grid%leaf_key(2:) > grid%leaf_key(:grid%n_leaves - 1)), 'keys not ascending')
         if (allocated(error)) return
      end do
   end subroutine test_leaf_classes

   !> Cell, neighbour and point queries against brute force over all leaves.
   subroutine test_queries(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(lcg_type) :: rng
      integer :: dim, i, j, k, first, last, dir(3), lo(3), hi(3), qlo(3), qhi(3), s, found, leaf
      real(wp) :: x(3), blo(3), bhi(3)
      logical :: inside, expect_single
      do dim = 2, 3
         call grid%build(ball(dim, 0.3_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2, 2, error)
         if (allocated(error)) return
         do i = 1, grid%n_leaves, 7
            do k = 0, 3**dim - 1
               dir = [mod(k, 3) - 1, mod(k/3, 3) - 1, mod(k/9, 3) - 1]
               if (dim == 2) dir(3) = 0
               if (all(dir == 0)) cycle
               call grid%neighbour(i, dir(1:dim), first, last)
               s = 2**(grid_max_level - grid%leaf_level(i))
               qlo = 0
               qhi = 0
               qlo(1:dim) = (grid%leaf_coord(:, i) + dir(1:dim))*s
               qhi(1:dim) = qlo(1:dim) + s
               found = 0
               expect_single = .false.
               do j = 1, grid%n_leaves
                  call int_box(grid, j, lo, hi)
                  if (.not. all(lo(1:dim) < qhi(1:dim) .and. qlo(1:dim) < hi(1:dim))) cycle
                  found = found + 1
                  if (grid%leaf_level(j) <= grid%leaf_level(i)) expect_single = .true.
                  call check(error, j >= first .and. j <= last, 'a leaf overlapping the neighbour cell is missed')
                  if (allocated(error)) return
               end do
               call check(error, max(0, last - first + 1), found, 'neighbour range size')
               if (allocated(error)) return
               if (expect_single) then
                  call check(error, found, 1, 'a coarser neighbour must be a single leaf')
                  if (allocated(error)) return
               end if
            end do
         end do
         do k = 1, 300
            x = [uniform(rng), uniform(rng), uniform(rng)]
            leaf = grid%locate_point(x(1:dim))
            found = 0
            do j = 1, grid%n_leaves
               call grid%leaf_box(j, blo(1:dim), bhi(1:dim))
               inside = all(x(1:dim) >= blo(1:dim) .and. x(1:dim) < bhi(1:dim))
               if (inside) found = j
            end do
            call check(error, leaf, found, 'locate_point vs brute force')
            if (allocated(error)) return
         end do
         call check(error, grid%locate_point([1.5_wp, 0.5_wp, 0.5_wp]), 0, 'a point outside the box')
         if (allocated(error)) return
      end do
   end subroutine test_queries

   !> Level 20 in 3D (60-bit keys): a tiny sphere, counts still add up.
   subroutine test_deep_level(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(ball_region) :: region
      integer :: leaf
      region = ball(3, 2.5e-6_wp)
      call grid%build(region, 3, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, grid_max_level, 0, error)
      if (allocated(error)) return
      call check(error, grid%n_leaves > 0 .and. grid%n_cut(grid_max_level) > 0, 'the sphere has leaves')
      if (allocated(error)) return
      call check_volume(error, grid)
      if (allocated(error)) return
      call check_balance(error, grid)
      if (allocated(error)) return
      leaf = grid%locate_point(region%centre)
      call check(error, leaf > 0, 'the centre lies in a leaf')
   end subroutine test_deep_level

   ! ------------------------------------------------------------------ nodes

   subroutine test_shape_functions(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: dim, p, j, nen
      integer, allocatable :: idx(:, :)
      real(wp), allocatable :: shape(:)
      real(wp) :: xi(3)
      do dim = 2, 3
         do p = 1, 2
            nen = nodes_per_element(dim, p)
            idx = element_node_index(dim, p)
            allocate (shape(nen))
            call check(error, size(idx, 2), nen, 'node table size')
            if (allocated(error)) return
            ! Kronecker property at the nodes (exact: products of 0 and 1).
            do j = 1, nen
               call element_shape(dim, p, real(idx(:, j), wp)/real(p, wp), shape)
               shape(j) = shape(j) - 1.0_wp
               call check(error, maxval(abs(shape)) < exact, 'N_k(x_j) /= delta_kj')
               if (allocated(error)) return
            end do
            ! Partition of unity at a generic point (round-off of nen products).
            xi = [0.3_wp, 0.71_wp, 0.45_wp]
            call element_shape(dim, p, xi(1:dim), shape)
            call check(error, sum(shape), 1.0_wp, 1.0e-14_wp, 'partition of unity')
            if (allocated(error)) return
            deallocate (shape)
         end do
      end do
   end subroutine test_shape_functions

   !> Nodes of one grid: unique lattice positions, each element's nodes where its
   !> reference positions map, and the node -> element adjacency is the transpose.
   subroutine check_nodes(error, grid, nodes)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      integer, allocatable :: idx(:, :)
      integer(i8), allocatable :: lkey(:)
      integer :: e, j, n, d, k, m
      real(wp) :: lo(3), hi(3), expected(3)

      d = grid%dim
      allocate (idx(d, nodes%nodes_per_element))
      idx = element_node_index(d, nodes%degree)
      ! Exact: box corners and midpoints are box_min + multiples of powers of two times box_size.
      do e = 1, nodes%n_elements
         call grid%leaf_box(e, lo(1:d), hi(1:d))
         do j = 1, nodes%nodes_per_element
            expected(1:d) = lo(1:d) + (hi(1:d) - lo(1:d))*real(idx(:, j), wp)/real(nodes%degree, wp)
            n = nodes%connectivity(j, e)
            call check(error, maxval(abs(nodes%x(:, n) - expected(1:d))) <= 4.0_wp*epsilon(1.0_wp)*grid%box_size, &
               & 'element node away from its reference position')
            if (allocated(error)) return
         end do
      end do
      ! No duplicates: sorted packed lattice keys are strictly increasing.
      allocate (lkey(nodes%n_nodes))
      do n = 1, nodes%n_nodes
         lkey(n) = 0_i8
         do k = 1, d
            lkey(n) = lkey(n)*int(2**nodes%lattice_level + 1, i8) + int(nodes%lattice(k, n), i8)
         end do
      end do
      call sort_i8(lkey)
      call check(error, all(lkey(2:) > lkey(:nodes%n_nodes - 1)), 'two nodes share a position')
      if (allocated(error)) return
      ! Adjacency: the transpose of the connectivity.
      do n = 1, nodes%n_nodes
         do m = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
            e = nodes%node_element(m)
            call check(error, any(nodes%connectivity(:, e) == n), 'adjacency lists an element without the node')
            if (allocated(error)) return
         end do
      end do
      call check(error, nodes%node_element_ptr(nodes%n_nodes + 1) - 1, nodes%n_elements*nodes%nodes_per_element, &
         & 'adjacency size')
      if (allocated(error)) return
      ! Every node belongs to some element.
      call check(error, all(nodes%node_element_ptr(2:) > nodes%node_element_ptr(:nodes%n_nodes)), 'orphan node')
   end subroutine check_nodes

   subroutine sort_i8(a)
      integer(i8), intent(inout) :: a(:)
      integer :: i, j, gap
      integer(i8) :: t
      ! Shell sort: small test arrays.
      gap = size(a)/2
      do while (gap > 0)
         do i = gap + 1, size(a)
            t = a(i)
            j = i
            do while (j > gap)
               if (a(j - gap) <= t) exit
               a(j) = a(j - gap)
               j = j - gap
            end do
            a(j) = t
         end do
         gap = gap/2
      end do
   end subroutine sort_i8

   !> Whole box covered: (p*2**level + 1)**dim nodes, none hanging.
   subroutine test_nodes_uniform(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(constant_region) :: full
      integer :: dim, p, l
      full%answer = cell_inside
      do dim = 2, 3
         l = 3
         call grid%build(full, dim, [1.0_wp, -2.0_wp, 0.5_wp], 3.0_wp, l, 0, error)
         if (allocated(error)) return
         do p = 1, 2
            call nodes%build(grid, p, error)
            if (allocated(error)) return
            call check(error, nodes%n_nodes, (p*2**l + 1)**dim, 'node count of a full uniform grid')
            if (allocated(error)) return
            call check_nodes(error, grid, nodes)
            if (allocated(error)) return
            call hang%build(grid, nodes, error)
            if (allocated(error)) return
            call check(error, hang%n_hanging, 0, 'hanging nodes on a uniform grid')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_nodes_uniform

   subroutine test_nodes_refined(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      integer :: dim, p
      do dim = 2, 3
         call grid%build(ball(dim, 0.3_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2, 2, error)
         if (allocated(error)) return
         do p = 1, 2
            call nodes%build(grid, p, error)
            if (allocated(error)) return
            call check_nodes(error, grid, nodes)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_nodes_refined

   !> grid%copy and nodes%copy (the deep copies that report a failed allocation) give
   !> what the intrinsic assignment gives, field by field, and copies that stand alone:
   !> the copied nodes pass the node checks on the copied grid after the originals are
   !> rebuilt as something else.
   subroutine test_grid_nodes_copy(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid, copy, assigned
      type(grid_nodes_type) :: nodes, ncopy, nassigned
      integer :: dim

      do dim = 2, 3
         call grid%build(ball(dim, 0.3_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2, 2, error)
         if (allocated(error)) return
         call nodes%build(grid, 2, error)
         if (allocated(error)) return
         call grid%copy(copy, error)
         if (allocated(error)) return
         call nodes%copy(ncopy, error)
         if (allocated(error)) return
         assigned = grid
         nassigned = nodes
         call check(error, copy%dim == assigned%dim .and. all(copy%box_min == assigned%box_min) .and. &
            & copy%box_size == assigned%box_size .and. copy%level == assigned%level .and. &
            & copy%refine_boundary == assigned%refine_boundary .and. copy%max_level == assigned%max_level .and. &
            & copy%n_leaves == assigned%n_leaves .and. all(copy%leaf_level == assigned%leaf_level) .and. &
            & all(copy%leaf_coord == assigned%leaf_coord) .and. all(copy%leaf_class == assigned%leaf_class) .and. &
            & all(copy%leaf_key == assigned%leaf_key) .and. all(copy%n_inside == assigned%n_inside) .and. &
            & all(copy%n_cut == assigned%n_cut) .and. all(copy%n_outside == assigned%n_outside) .and. &
            & copy%n_balance_splits == assigned%n_balance_splits, 'grid copy = grid assignment')
         if (allocated(error)) return
         call check(error, ncopy%dim == nassigned%dim .and. ncopy%degree == nassigned%degree .and. &
            & ncopy%n_nodes == nassigned%n_nodes .and. ncopy%n_elements == nassigned%n_elements .and. &
            & ncopy%nodes_per_element == nassigned%nodes_per_element .and. &
            & ncopy%lattice_level == nassigned%lattice_level .and. all(ncopy%lattice == nassigned%lattice) .and. &
            & all(ncopy%x == nassigned%x) .and. all(ncopy%connectivity == nassigned%connectivity) .and. &
            & all(ncopy%node_element_ptr == nassigned%node_element_ptr) .and. &
            & all(ncopy%node_element == nassigned%node_element), 'nodes copy = nodes assignment')
         if (allocated(error)) return
         call grid%build(ball(dim, 0.4_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 3, 0, error)
         if (allocated(error)) return
         call nodes%build(grid, 1, error)
         if (allocated(error)) return
         call check_nodes(error, copy, ncopy)
         if (allocated(error)) return
      end do
   end subroutine test_grid_nodes_copy

   ! ------------------------------------------------------------------ hanging

   !> Tensor polynomial of degree p per variable (reproduced exactly by Q_p).
   pure real(wp) function poly(coef, p, x)
      real(wp), intent(in) :: coef(0:2, 0:2, 0:2)
      integer, intent(in) :: p
      real(wp), intent(in) :: x(:)
      real(wp) :: y(3)
      integer :: a, b, c
      y = 0.0_wp
      y(1:size(x)) = x
      poly = 0.0_wp
      do c = 0, merge(p, 0, size(x) == 3)
         do b = 0, p
            do a = 0, p
               poly = poly + coef(a, b, c)*y(1)**a*y(2)**b*y(3)**c
            end do
         end do
      end do
   end function poly

   !> (1) a random Q_p polynomial at the free nodes, expanded by T, is exact at every node;
   !> (2) random free values expanded by T give a continuous field: at every node, every
   !>     element containing it interpolates the node's value.
   subroutine hanging_case(error, region, dim, p, level, refine, box_min, box_size)
      type(error_type), allocatable, intent(out) :: error
      class(region_type), intent(in) :: region
      integer, intent(in) :: dim, p, level, refine
      real(wp), intent(in) :: box_min(3), box_size
      type(grid_type) :: grid

      call grid%build(region, dim, box_min, box_size, level, refine, error)
      if (allocated(error)) return
      call check_hanging(error, grid, p)
   end subroutine hanging_case

   subroutine check_hanging(error, grid, p, chain_rounds)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: p
      integer, intent(out), optional :: chain_rounds
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(lcg_type) :: rng
      real(wp) :: coef(0:2, 0:2, 0:2), err, x(3), lo(3), hi(3), val, h, box_min(3), box_size
      real(wp), allocatable :: ubar(:), u(:), shape(:)
      integer :: i, n, k, e, corner, a, b, c, dim

      dim = grid%dim
      box_min = grid%box_min
      box_size = grid%box_size
      call nodes%build(grid, p, error)
      if (allocated(error)) return
      call hang%build(grid, nodes, error)
      if (allocated(error)) return
      if (present(chain_rounds)) chain_rounds = hang%chain_rounds
      call check(error, hang%n_hanging > 0, 'no hanging nodes: the test would prove nothing')
      if (allocated(error)) return
      call check(error, all(hang%free_index(hang%free_node) == [(i, i=1, hang%n_free)]), 'free numbering')
      if (allocated(error)) return

      do c = 0, 2
         do b = 0, 2
            do a = 0, 2
               coef(a, b, c) = 2.0_wp*uniform(rng) - 1.0_wp
            end do
         end do
      end do
      allocate (ubar(hang%n_free), u(hang%n_all), shape(nodes%nodes_per_element))
      do i = 1, hang%n_free
         ubar(i) = poly(coef, p, (nodes%x(:, hang%free_node(i)) - box_min(1:dim))/box_size)
      end do
      call hang%expand(ubar, u)
      err = 0.0_wp
      do n = 1, hang%n_all
         err = max(err, abs(u(n) - poly(coef, p, (nodes%x(:, n) - box_min(1:dim))/box_size)))
      end do
      ! Values are O(1) (scaled coordinates in [0,1], coefficients in [-1,1]); a constraint row
      ! has at most a few dozen exact coefficients, so round-off is ~1e-15: 1e-12 is a wide margin.
      call check(error, err <= 1.0e-12_wp, 'polynomial not reproduced at a hanging node')
      if (allocated(error)) return

      do i = 1, hang%n_free
         ubar(i) = 2.0_wp*uniform(rng) - 1.0_wp
      end do
      call hang%expand(ubar, u)
      h = grid%cell_width(grid%max_level + 2)
      err = 0.0_wp
      do n = 1, hang%n_all
         do corner = 0, 2**dim - 1
            ! A point a quarter of the finest cell away, in each orthant, finds each element at the node.
            x(1:dim) = nodes%x(:, n) + h*real(2*[iand(corner, 1), iand(corner/2, 1), iand(corner/4, 1)] - 1, wp)
            e = grid%locate_point(x(1:dim))
            if (e == 0) cycle
            call grid%leaf_box(e, lo(1:dim), hi(1:dim))
            call element_shape(dim, p, (nodes%x(:, n) - lo(1:dim))/(hi(1:dim) - lo(1:dim)), shape)
            val = 0.0_wp
            do k = 1, nodes%nodes_per_element
               val = val + shape(k)*u(nodes%connectivity(k, e))
            end do
            err = max(err, abs(val - u(n)))
         end do
      end do
      ! Same round-off argument: |u| <= a few, chains multiply at most two rows of shape values.
      call check(error, err <= 1.0e-12_wp, 'discontinuous field across a hanging node')
   end subroutine check_hanging

   !> A constraint chain, on a hand-made unbalanced grid (the balanced build never makes
   !> one): D = [.5,1]x[0,.5] (level 1), C = [.25,.5]^2 (level 2), E = [.375,.5]x[.125,.25]
   !> (level 3). E's corner (.375,.25) hangs on C's edge, whose end (.5,.25) hangs on D's.
   subroutine test_hanging_chain(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      integer :: rounds, i, j, p
      integer :: lev(3), crd(2, 3)
      integer(i8) :: key(3)
      lev = [1, 2, 3]
      crd = reshape([1, 0, 1, 1, 3, 1], [2, 3])
      do i = 1, 3
         key(i) = morton_encode(ishft(crd(:, i), grid_max_level - lev(i)))
      end do
      grid%dim = 2
      grid%box_size = 1.0_wp
      grid%level = 1
      grid%max_level = 3
      grid%n_leaves = 3
      allocate (grid%leaf_level(3), grid%leaf_coord(2, 3), grid%leaf_class(3), grid%leaf_key(3))
      ! Sort the three leaves by key by hand (selection).
      do j = 1, 3
         i = minloc(key, 1)
         grid%leaf_level(j) = lev(i)
         grid%leaf_coord(:, j) = crd(:, i)
         grid%leaf_key(j) = key(i)
         key(i) = huge(1_i8)
      end do
      grid%leaf_class = cell_inside
      do p = 1, 2
         call check_hanging(error, grid, p, rounds)
         if (allocated(error)) return
         if (p == 1) then
            call check(error, rounds >= 1, 'the Q1 chain was not seen')
            if (allocated(error)) return
         end if
      end do
   end subroutine test_hanging_chain

   !> A ball of radius 0.31 box_size, placed like `ball` relative to the box.
   function scaled_ball(dim, box_min, box_size) result(r)
      integer, intent(in) :: dim
      real(wp), intent(in) :: box_min(3), box_size
      type(ball_region) :: r
      r = ball(dim, 0.31_wp*box_size)
      r%centre(1:dim) = box_min(1:dim) + box_size*r%centre(1:dim)
   end function scaled_ball

   !> Fine leaves that touch a coarse leaf along an edge only (3D): the boxes
   !> [0,.5]^2 x [0,1] and [.5,.9]^2 x [0,1] meet on the line x = y = .5; the cells
   !> beside that line in between are external, so only the edge neighbour carries the constraint.
   subroutine test_hanging_edge_only(error)
      type(error_type), allocatable, intent(out) :: error
      type(two_boxes_region) :: region
      integer :: p
      region%lo(:, 1) = [0.0_wp, 0.0_wp, 0.0_wp]
      region%hi(:, 1) = [0.5_wp, 0.5_wp, 1.0_wp]
      region%lo(:, 2) = [0.5_wp, 0.5_wp, 0.0_wp]
      region%hi(:, 2) = [0.9_wp, 0.9_wp, 1.0_wp]
      do p = 1, 2
         call hanging_case(error, region, 3, p, 1, 2, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp)
         if (allocated(error)) return
      end do
   end subroutine test_hanging_edge_only

   subroutine test_hanging_q1_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call hanging_case(error, scaled_ball(2, [-0.7_wp, 0.3_wp, 0.0_wp], 2.5_wp), 2, 1, 2, 3, [-0.7_wp, 0.3_wp, 0.0_wp], 2.5_wp)
   end subroutine test_hanging_q1_2d

   subroutine test_hanging_q2_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call hanging_case(error, scaled_ball(2, [-0.7_wp, 0.3_wp, 0.0_wp], 2.5_wp), 2, 2, 2, 3, [-0.7_wp, 0.3_wp, 0.0_wp], 2.5_wp)
   end subroutine test_hanging_q2_2d

   subroutine test_hanging_q1_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call hanging_case(error, scaled_ball(3, [0.2_wp, -0.4_wp, 1.1_wp], 1.5_wp), 3, 1, 2, 2, [0.2_wp, -0.4_wp, 1.1_wp], 1.5_wp)
   end subroutine test_hanging_q1_3d

   subroutine test_hanging_q2_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call hanging_case(error, scaled_ball(3, [0.2_wp, -0.4_wp, 1.1_wp], 1.5_wp), 3, 2, 2, 2, [0.2_wp, -0.4_wp, 1.1_wp], 1.5_wp)
   end subroutine test_hanging_q2_3d

   !> Hand-checked constraints: one coarse internal cell next to split cut cells gives
   !> the midpoint rule 1/2, 1/2 for Q1 and 3/8, 3/4, -1/8 at quarter points for Q2.
   subroutine test_hanging_hand(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(ball_region) :: region
      integer :: n, k, p
      real(wp) :: xh(2), xm(2)
      ! Disk around (0, 0) of radius 0.75 at level 1 + 1: the cell [0,.5]^2 is internal
      ! (farthest corner at 0.707) and stays coarse; the three other cells are cut and split.
      region%centre = 0.0_wp
      region%radius = 0.75_wp
      call grid%build(region, 2, [0.0_wp, 0.0_wp], 1.0_wp, 1, 1, error)
      if (allocated(error)) return
      call check(error, int(grid%n_inside(1)), 1, 'one coarse internal cell')
      if (allocated(error)) return
      do p = 1, 2
         call nodes%build(grid, p, error)
         if (allocated(error)) return
         call hang%build(grid, nodes, error)
         if (allocated(error)) return
         do n = 1, hang%n_all
            if (hang%free_index(n) /= 0) cycle
            xh = nodes%x(:, n)
            ! Every hanging node lies on the coarse cell's edges x = 0.5 or y = 0.5.
            call check(error, abs(xh(1) - 0.5_wp) < 1.0e-15_wp .or. abs(xh(2) - 0.5_wp) < 1.0e-15_wp, &
               & 'hanging node off the coarse edges')
            if (allocated(error)) return
            if (p == 1) then
               ! Q1: midpoint of a coarse edge from (0.5, 0) or (0, 0.5) to (0.5, 0.5): weights 1/2, 1/2.
               call check(error, hang%t_ptr(n + 1) - hang%t_ptr(n), 2, 'Q1 hanging node with two masters')
               if (allocated(error)) return
               call check(error, all(abs(hang%t_val(hang%t_ptr(n):hang%t_ptr(n + 1) - 1) - 0.5_wp) < exact), &
                  & 'Q1 weights 1/2')
               if (allocated(error)) return
            else
               ! Q2: quarter points of the coarse edge: weights 3/8, 3/4, -1/8 (exact in binary).
               call check(error, hang%t_ptr(n + 1) - hang%t_ptr(n), 3, 'Q2 hanging node with three masters')
               if (allocated(error)) return
               do k = hang%t_ptr(n), hang%t_ptr(n + 1) - 1
                  xm = nodes%x(:, hang%free_node(hang%t_col(k)))
                  call check(error, any(abs(hang%t_val(k) - [0.375_wp, 0.75_wp, -0.125_wp]) < exact), 'Q2 weight')
                  if (allocated(error)) return
                  ! The weight 3/4 belongs to the coarse edge midpoint, at distance 1/4 of the edge.
                  if (abs(hang%t_val(k) - 0.75_wp) < exact) then
                     call check(error, norm2(xm - xh), 0.125_wp, 1.0e-15_wp, 'Q2 midpoint master')
                     if (allocated(error)) return
                  end if
               end do
            end if
         end do
         call check(error, hang%n_hanging, merge(2, 4, p == 1), 'hanging node count')
         if (allocated(error)) return
      end do
   end subroutine test_hanging_hand

   ! ------------------------------------------------------------------ degenerate

   !> Plane on grid faces: exact classification, no cut cells at all.
   subroutine test_degenerate_aligned(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(halfspace_region) :: half
      integer :: dim
      half%normal = [1.0_wp, 0.0_wp, 0.0_wp]
      half%offset = 0.5_wp
      do dim = 2, 3
         call grid%build(half, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 3, 2, error)
         if (allocated(error)) return
         call check(error, grid%n_inside(3) == ishft(1_i8, 3*dim)/2_i8 .and. sum(grid%n_cut) == 0_i8, &
            & 'aligned plane: half the cells inside, none cut')
         if (allocated(error)) return
         call check(error, grid%n_outside(3) == ishft(1_i8, 3*dim)/2_i8, 'aligned plane: half outside')
         if (allocated(error)) return
         call nodes%build(grid, 2, error)
         if (allocated(error)) return
         call hang%build(grid, nodes, error)
         if (allocated(error)) return
         call check(error, hang%n_hanging, 0, 'no hanging nodes on a uniform grid')
         if (allocated(error)) return
      end do
   end subroutine test_degenerate_aligned

   !> A body much smaller than one cell: a few cut leaves, balance and constraints still hold.
   subroutine test_degenerate_tiny(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      integer :: dim
      do dim = 2, 3
         call grid%build(ball(dim, 1.0e-3_wp), dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 3, 2, error)
         if (allocated(error)) return
         call check(error, grid%n_leaves >= 1 .and. all(grid%leaf_class == cell_cut), 'tiny body: cut leaves only')
         if (allocated(error)) return
         call check_volume(error, grid)
         if (allocated(error)) return
         call check_balance(error, grid)
         if (allocated(error)) return
         call nodes%build(grid, 2, error)
         if (allocated(error)) return
         call hang%build(grid, nodes, error)
         if (allocated(error)) return
         call check(error, hang%n_free + hang%n_hanging, nodes%n_nodes, 'free + hanging = all')
         if (allocated(error)) return
      end do
   end subroutine test_degenerate_tiny

   subroutine test_degenerate_empty_full(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(constant_region) :: region
      integer :: dim
      do dim = 2, 3
         region%answer = cell_outside
         call grid%build(region, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 4, 2, error)
         if (allocated(error)) return
         call check(error, grid%n_leaves, 0, 'empty body has no leaves')
         if (allocated(error)) return
         call check(error, grid%n_outside(4) == ishft(1_i8, 4*dim), 'empty body: all external at the uniform level')
         if (allocated(error)) return
         call check(error, grid%locate_point([0.5_wp, 0.5_wp, 0.5_wp]), 0, 'no leaf in an empty grid')
         if (allocated(error)) return
         call nodes%build(grid, 1, error)
         if (allocated(error)) return
         call hang%build(grid, nodes, error)
         if (allocated(error)) return
         call check(error, nodes%n_nodes + hang%n_free, 0, 'empty body has no nodes')
         if (allocated(error)) return

         region%answer = cell_inside
         call grid%build(region, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 3, 2, error)
         if (allocated(error)) return
         call check(error, grid%n_leaves, 2**(3*dim), 'full box: every uniform cell is a leaf')
         if (allocated(error)) return
         call check(error, sum(grid%n_cut) + sum(grid%n_outside) == 0_i8, 'full box: nothing cut or external')
         if (allocated(error)) return
      end do
   end subroutine test_degenerate_empty_full

   !> Circle through grid nodes and tangent to cell edges: centre on a node, radius a multiple of h.
   subroutine test_degenerate_through_nodes(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(ball_region) :: region
      integer :: dim
      do dim = 2, 3
         region%centre = 0.5_wp
         region%radius = 0.25_wp
         call grid%build(region, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 3, 2, error)
         if (allocated(error)) return
         call check_volume(error, grid)
         if (allocated(error)) return
         call check_balance(error, grid)
         if (allocated(error)) return
         call nodes%build(grid, 1, error)
         if (allocated(error)) return
         call hang%build(grid, nodes, error)
         if (allocated(error)) return
         call check(error, hang%n_free > 0, 'free nodes exist')
         if (allocated(error)) return
      end do
   end subroutine test_degenerate_through_nodes

   ! ------------------------------------------------------------------ errors

   subroutine expect_build_error(error, dim, box_min, box_size, level, refine, what)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level, refine
      real(wp), intent(in) :: box_min(:), box_size
      character(len=*), intent(in) :: what
      type(grid_type) :: grid
      type(error_type), allocatable :: build_error
      call grid%build(ball(3, 0.3_wp), dim, box_min, box_size, level, refine, build_error)
      call check(error, allocated(build_error), 'no error for '//what)
      if (allocated(error)) return
      call check(error, build_error%stat, stat_invalid_input, 'status for '//what)
      if (allocated(error)) return
      call check(error, index(build_error%message, 'grid build') > 0, 'message names the grid build: '//what)
   end subroutine expect_build_error

   subroutine test_bad_input(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: zero
      zero = 0.0_wp
      call expect_build_error(error, 2, [0.0_wp, 0.0_wp], 1.0_wp, -1, 0, 'level < 0')
      if (allocated(error)) return
      call expect_build_error(error, 2, [0.0_wp, 0.0_wp], 1.0_wp, 2, -1, 'refine_boundary < 0')
      if (allocated(error)) return
      call expect_build_error(error, 2, [0.0_wp, 0.0_wp], 0.0_wp, 2, 0, 'box_size = 0')
      if (allocated(error)) return
      call expect_build_error(error, 2, [0.0_wp, 0.0_wp], -1.0_wp, 2, 0, 'box_size < 0')
      if (allocated(error)) return
      call expect_build_error(error, 2, [0.0_wp, 0.0_wp], 1.0_wp/zero, 2, 0, 'box_size infinite')
      if (allocated(error)) return
      call expect_build_error(error, 2, [0.0_wp, zero/zero], 1.0_wp, 2, 0, 'box_min NaN')
      if (allocated(error)) return
      call expect_build_error(error, 1, [0.0_wp], 1.0_wp, 2, 0, 'dim = 1')
      if (allocated(error)) return
      call expect_build_error(error, 4, [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 2, 0, 'dim = 4')
      if (allocated(error)) return
      call expect_build_error(error, 3, [0.0_wp, 0.0_wp], 1.0_wp, 2, 0, 'box_min too short')
      if (allocated(error)) return
      call expect_build_error(error, 3, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, grid_max_level - 2, 3, 'too many levels')
   end subroutine test_bad_input

   subroutine test_bad_region_nodes(error)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid, other
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(constant_region) :: broken
      type(error_type), allocatable :: err2

      broken%answer = 7
      call grid%build(broken, 2, [0.0_wp, 0.0_wp], 1.0_wp, 2, 0, err2)
      call check(error, allocated(err2), 'a region answering 7 is an error')
      if (allocated(error)) return
      call check(error, err2%stat, stat_invalid_input, 'status for a broken region')
      if (allocated(error)) return

      call nodes%build(other, 1, err2)
      call check(error, allocated(err2), 'nodes of an unbuilt grid')
      if (allocated(error)) return

      call grid%build(ball(2, 0.3_wp), 2, [0.0_wp, 0.0_wp], 1.0_wp, 3, 1, error)
      if (allocated(error)) return
      call nodes%build(grid, 3, err2)
      call check(error, allocated(err2), 'degree 3 is an error')
      if (allocated(error)) return
      call check(error, err2%stat, stat_invalid_input, 'status for degree 3')
      if (allocated(error)) return

      call nodes%build(grid, 1, error)
      if (allocated(error)) return
      call other%build(ball(2, 0.3_wp), 2, [0.0_wp, 0.0_wp], 1.0_wp, 4, 0, error)
      if (allocated(error)) return
      call hang%build(other, nodes, err2)
      call check(error, allocated(err2), 'hanging nodes with nodes of another grid')
      if (allocated(error)) return
      call check(error, err2%stat, stat_invalid_input, 'status for mismatched nodes')
   end subroutine test_bad_region_nodes

end module sprc_test_grid
