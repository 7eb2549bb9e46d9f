!> Hierarchical Cartesian grid of one body (the cgFEM / FEAVox family).
!>
!> Level 0 is the cube (square) [box_min, box_min + box_size]^dim; a cell of
!> level l with integer coordinates c (0 <= c < 2**l) splits into 2**dim
!> children 2c + {0,1}^dim. `build` refines top-down to the uniform `level`,
!> skipping external subtrees and copying the class of internal cells to their
!> children without asking the region, refines cut cells `refine_boundary`
!> more levels, and then enforces 2:1 balance across faces, edges and corners
!> between active leaves (a ripple that sweeps the levels from the finest one
!> down; new leaves are classified when they appear).
!>
!> `build_adapted` builds a grid of the same box from a level wanted per leaf
!> of an existing grid `old` (the size field of an adaptive step): top-down
!> from level 0, a non-external cell splits while its level is below the
!> largest level wanted by the old leaves it overlaps (one `find_cell` on the
!> Morton-sorted old leaves per cell), so it refines and coarsens; then the
!> same 2:1 balance. A non-external cell that no old leaf overlaps (the old
!> grid split it into external cells only) splits like the old grid did, down
!> to the old finest level. Its `level` is the coarsest leaf level (every
!> leaf is at least that fine, what the uniform level of `build` promises),
!> `refine_boundary` = `max_level` - `level`.
!>
!> Only active leaves (internal and cut) are stored: external space is never
!> materialised. They are sorted by the Morton key of their lowest corner at
!> the common resolution `grid_max_level`, so the descendants of any cell are
!> a contiguous run and a cell or point query is one binary search.
!>
!> Leaf counts per level: `n_inside(l)`, `n_cut(l)`, `n_outside(l)`. External
!> cells coarser than the uniform level are counted as the number of cells of
!> the uniform level they cover, so a uniform grid (refine_boundary = 0) has
!> n_inside + n_cut + n_outside = 2**(dim*level) at its level, and in general
!> sum over l of (n_inside + n_cut + n_outside)(l) * 2**(-dim*l) = 1.
module sprc_grid_tree
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_core_text, only: itoa
   use sprc_geometry_region, only: region_type, cell_outside, cell_inside, cell_cut
   use sprc_grid_morton, only: morton_encode
   use sprc_core_hash, only: key_table_type
   use sprc_core_sort, only: sort_order
   implicit none
   private

   public :: grid_type, grid_max_level

   !> Finest level a grid may hold (level + refine_boundary <= grid_max_level).
   integer, parameter :: grid_max_level = 20

   !> The active leaves of one body's grid, sorted by Morton key.
   type :: grid_type
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Lowest corner of the level-0 cell (entries beyond `dim` are zero).
      real(wp) :: box_min(3) = 0.0_wp
      !> Edge length of the level-0 cell.
      real(wp) :: box_size = 0.0_wp
      !> Uniform level and number of extra boundary levels asked for; no leaf is
      !> coarser than `level`. For `build_adapted`: the coarsest leaf level and
      !> the levels between it and the finest.
      integer :: level = 0, refine_boundary = 0
      !> Finest level among the leaves.
      integer :: max_level = 0
      !> Number of active leaves (the elements of the analysis mesh).
      integer :: n_leaves = 0
      !> Level of each leaf.
      integer, allocatable :: leaf_level(:)
      !> Integer coordinates (dim, n_leaves) of each leaf at its own level.
      integer, allocatable :: leaf_coord(:, :)
      !> `cell_inside` or `cell_cut` for each leaf.
      integer, allocatable :: leaf_class(:)
      !> Morton key of each leaf's lowest corner at resolution `grid_max_level`; ascending.
      integer(i8), allocatable :: leaf_key(:)
      !> Leaf counts per level by class (external: see the module notes).
      integer(i8) :: n_inside(0:grid_max_level) = 0_i8
      integer(i8) :: n_cut(0:grid_max_level) = 0_i8
      integer(i8) :: n_outside(0:grid_max_level) = 0_i8
      !> Leaves split by the 2:1 balance.
      integer :: n_balance_splits = 0
   contains
      procedure :: build => grid_build
      procedure :: build_adapted => grid_build_adapted
      procedure :: copy => grid_copy
      procedure :: cell_width => grid_cell_width
      procedure :: leaf_box => grid_leaf_box
      procedure :: find_cell => grid_find_cell
      procedure :: neighbour => grid_neighbour
      procedure :: locate_point => grid_locate_point
   end type grid_type

   !> Working state of a build: growable leaf arrays and a hash of every stored cell
   !> (value > 0: leaf index; -1: split cell; absent: external or not yet made).
   type :: builder_type
      integer :: dim = 0, level = 0, top = 0
      real(wp) :: box_min(3) = 0.0_wp, box_size = 0.0_wp
      integer :: n = 0, n_splits = 0
      logical :: bad_class = .false.
      integer, allocatable :: lev(:), crd(:, :), cls(:)
      logical, allocatable :: alive(:)
      !> Every stored cell by its key [level, coord(1:dim)], with the value above.
      type(key_table_type) :: cells
      integer(i8) :: n_outside(0:grid_max_level) = 0_i8
      !> Set when an array could not grow: the build stops and returns it.
      type(error_type), allocatable :: error
   end type builder_type

contains

   !> Build the grid of `region` in the box [box_min, box_min + box_size]^dim: uniform
   !> `level`, `refine_boundary` extra levels on cut cells, then 2:1 balance.
   subroutine grid_build(self, region, dim, box_min, box_size, level, refine_boundary, error)
      class(grid_type), intent(out) :: self
      class(region_type), intent(in) :: region
      integer, intent(in) :: dim
      real(wp), intent(in) :: box_min(:)
      real(wp), intent(in) :: box_size
      integer, intent(in) :: level, refine_boundary
      type(error_type), allocatable, intent(out) :: error
      type(builder_type) :: b
      integer :: root(3), root_class

      call check_input(dim, box_min, box_size, level, refine_boundary, error)
      if (allocated(error)) return

      b%dim = dim
      b%level = level
      b%top = level + refine_boundary
      b%box_min(1:dim) = box_min(1:dim)
      b%box_size = box_size
      call builder_init(b)

      root = 0
      root_class = classify(b, region, 0, root)
      call descend(b, region, 0, root, root_class)
      call complete(self, b, region, .false., error)
      self%refine_boundary = refine_boundary
   end subroutine grid_build

   !> Build the grid of `region` in the box of `old` from the level `target(j)`
   !> wanted for the cells covering old leaf j (module notes): a non-external
   !> cell of level l splits iff l < max{target(j) : old leaf j overlaps it},
   !> clamped to [0, max_level]; then 2:1 balance. Refines and coarsens.
   !> `old` must not be `self`.
   subroutine grid_build_adapted(self, region, old, target, max_level, error)
      class(grid_type), intent(out) :: self
      class(region_type), intent(in) :: region
      type(grid_type), intent(in) :: old
      integer, intent(in) :: target(:)
      integer, intent(in) :: max_level
      type(error_type), allocatable, intent(out) :: error
      type(builder_type) :: b
      integer :: root(3), root_class

      call check_adapt_input(old, target, max_level, error)
      if (allocated(error)) return

      b%dim = old%dim
      b%level = 0
      b%top = max_level
      b%box_min = old%box_min
      b%box_size = old%box_size
      call builder_init(b)

      root = 0
      root_class = classify(b, region, 0, root)
      call descend(b, region, 0, root, root_class, old, target)
      if (b%n > 0) b%level = minval(b%lev(1:b%n))
      call complete(self, b, region, .true., error)
      if (allocated(error)) return
      self%refine_boundary = self%max_level - self%level
   end subroutine grid_build_adapted

   !> After the descent: 2:1 balance (levels above b%level, no leaf being coarser),
   !> with `coarsest` b%level raised to the coarsest leaf level left by the balance,
   !> external counts folded to b%level, the leaves sorted into `self`.
   subroutine complete(self, b, region, coarsest, error)
      type(grid_type), intent(inout) :: self
      type(builder_type), intent(inout) :: b
      class(region_type), intent(in) :: region
      logical, intent(in) :: coarsest
      type(error_type), allocatable, intent(out) :: error
      integer :: l

      if (.not. allocated(b%error)) call balance(b, region)
      if (allocated(b%error)) then
         call move_alloc(b%error, error)
         return
      end if
      if (b%bad_class) then
         call fatal_error(error, 'grid build: the region returned a class other than cell_outside, '// &
            & 'cell_inside or cell_cut', stat_invalid_input)
         return
      end if
      if (coarsest .and. any(b%alive(1:b%n))) b%level = minval(b%lev(1:b%n), mask=b%alive(1:b%n))
      ! External cells coarser than the uniform level count as the cells of that level they cover.
      do l = 0, b%level - 1
         b%n_outside(b%level) = b%n_outside(b%level) + b%n_outside(l)*ishft(1_i8, b%dim*(b%level - l))
         b%n_outside(l) = 0_i8
      end do

      self%dim = b%dim
      self%box_min = b%box_min
      self%box_size = b%box_size
      self%level = b%level
      self%n_outside = b%n_outside
      self%n_balance_splits = b%n_splits
      call finalize(self, b, error)
   end subroutine complete

   !> `copy` = the grid, with a failed allocation returned as an error (the intrinsic
   !> assignment copy = grid stops the program when it cannot allocate, or crashes).
   subroutine grid_copy(self, copy, error)
      class(grid_type), intent(in) :: self
      type(grid_type), intent(out) :: copy
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      stat = 0
      if (allocated(self%leaf_level)) allocate (copy%leaf_level, source=self%leaf_level, stat=stat)
      if (stat == 0 .and. allocated(self%leaf_coord)) allocate (copy%leaf_coord, source=self%leaf_coord, stat=stat)
      if (stat == 0 .and. allocated(self%leaf_class)) allocate (copy%leaf_class, source=self%leaf_class, stat=stat)
      if (stat == 0 .and. allocated(self%leaf_key)) allocate (copy%leaf_key, source=self%leaf_key, stat=stat)
      call check_allocation(stat, 'grid copy', 'the leaves of the grid', self%n_leaves, 4*(self%dim + 2) + 8, error)
      if (allocated(error)) return
      copy%dim = self%dim
      copy%box_min = self%box_min
      copy%box_size = self%box_size
      copy%level = self%level
      copy%refine_boundary = self%refine_boundary
      copy%max_level = self%max_level
      copy%n_leaves = self%n_leaves
      copy%n_inside = self%n_inside
      copy%n_cut = self%n_cut
      copy%n_outside = self%n_outside
      copy%n_balance_splits = self%n_balance_splits
   end subroutine grid_copy

   subroutine check_adapt_input(old, target, max_level, error)
      type(grid_type), intent(in) :: old
      integer, intent(in) :: target(:)
      integer, intent(in) :: max_level
      type(error_type), allocatable, intent(out) :: error
      integer :: j
      character(len=*), parameter :: who = 'grid build_adapted: '

      if (old%dim /= 2 .and. old%dim /= 3) then
         call fatal_error(error, who//'the old grid has dim '//itoa(old%dim)//' (not built?), expected 2 or 3', &
            & stat_invalid_input)
      else if (.not. (old%box_size > 0.0_wp .and. old%box_size <= huge(1.0_wp)) .or. &
         & .not. all(abs(old%box_min(1:old%dim)) <= huge(1.0_wp))) then
         call fatal_error(error, who//'the old grid''s box is not finite and positive', stat_invalid_input)
      else if (.not. leaves_consistent(old)) then
         call fatal_error(error, who//'the old grid''s leaf arrays do not hold n_leaves = '//itoa(old%n_leaves)// &
            & ' leaves', stat_invalid_input)
      else if (size(target) /= old%n_leaves) then
         call fatal_error(error, who//'target has '//itoa(size(target))//' entries, the old grid '// &
            & itoa(old%n_leaves)//' leaves', stat_invalid_input)
      else if (max_level < 0 .or. max_level > grid_max_level) then
         call fatal_error(error, who//'max_level must be in [0, '//itoa(grid_max_level)//'], got '// &
            & itoa(max_level), stat_invalid_input)
      else if (any(target < 0)) then
         j = findloc(target < 0, .true., 1)
         call fatal_error(error, who//'target('//itoa(j)//') = '//itoa(target(j))//' is negative', &
            & stat_invalid_input)
      end if
   end subroutine check_adapt_input

   pure logical function leaves_consistent(grid) result(ok)
      type(grid_type), intent(in) :: grid
      integer :: n
      n = grid%n_leaves
      ok = n >= 0 .and. allocated(grid%leaf_level) .and. allocated(grid%leaf_coord) .and. &
         & allocated(grid%leaf_class) .and. allocated(grid%leaf_key)
      if (.not. ok) return
      ok = size(grid%leaf_level) == n .and. size(grid%leaf_coord, 2) == n .and. &
         & size(grid%leaf_coord, 1) == grid%dim .and. size(grid%leaf_key) == n
   end function leaves_consistent

   subroutine check_input(dim, box_min, box_size, level, refine_boundary, error)
      integer, intent(in) :: dim
      real(wp), intent(in) :: box_min(:)
      real(wp), intent(in) :: box_size
      integer, intent(in) :: level, refine_boundary
      type(error_type), allocatable, intent(out) :: error
      character(len=32) :: buf

      if (dim /= 2 .and. dim /= 3) then
         write (buf, '(i0)') dim
         call fatal_error(error, 'grid build: dim must be 2 or 3, got '//trim(buf), stat_invalid_input)
      else if (size(box_min) < dim) then
         write (buf, '(i0)') size(box_min)
         call fatal_error(error, 'grid build: box_min needs dim entries, got '//trim(buf), stat_invalid_input)
      else if (.not. all(abs(box_min(1:dim)) <= huge(1.0_wp))) then
         call fatal_error(error, 'grid build: box_min is not finite', stat_invalid_input)
      else if (.not. (box_size > 0.0_wp .and. box_size <= huge(1.0_wp))) then
         write (buf, '(es12.4)') box_size
         call fatal_error(error, 'grid build: box_size must be positive and finite, got '//trim(adjustl(buf)), &
            & stat_invalid_input)
      else if (level < 0) then
         write (buf, '(i0)') level
         call fatal_error(error, 'grid build: level must be >= 0, got '//trim(buf), stat_invalid_input)
      else if (refine_boundary < 0) then
         write (buf, '(i0)') refine_boundary
         call fatal_error(error, 'grid build: refine_boundary must be >= 0, got '//trim(buf), stat_invalid_input)
      else if (level > grid_max_level - refine_boundary) then
         write (buf, '(i0)') grid_max_level
         call fatal_error(error, 'grid build: level + refine_boundary exceeds the maximum level '//trim(buf), &
            & stat_invalid_input)
      end if
   end subroutine check_input

   !> Edge length of a cell of level `level`.
   pure real(wp) function grid_cell_width(self, level) result(h)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: level
      h = self%box_size*2.0_wp**(-level)
   end function grid_cell_width

   !> Box [lo, hi] (size dim) of leaf `leaf`.
   pure subroutine grid_leaf_box(self, leaf, lo, hi)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: leaf
      real(wp), intent(out) :: lo(:), hi(:)
      call cell_box(self%dim, self%box_min, self%box_size, self%leaf_level(leaf), self%leaf_coord(:, leaf), lo, hi)
   end subroutine grid_leaf_box

   !> Leaves that cover the cell (`level`, `coord`): if one leaf of this or a coarser
   !> level contains the cell, first = last = that leaf; if the cell is refined,
   !> first..last are all leaves inside it (a contiguous Morton run, possibly
   !> including leaves that do not touch a given face); first > last when the
   !> cell is external or outside the box. One binary search.
   pure subroutine grid_find_cell(self, level, coord, first, last)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: level
      integer, intent(in) :: coord(:)
      integer, intent(out) :: first, last
      integer(i8) :: k0, k1
      integer :: j, shift, d

      first = 1
      last = 0
      d = self%dim
      if (level < 0 .or. level > grid_max_level .or. self%n_leaves == 0) return
      if (any(coord(1:d) < 0) .or. any(coord(1:d) >= 2**level)) return
      shift = grid_max_level - level
      k0 = morton_encode(ishft(coord(1:d), shift))
      k1 = k0 + ishft(1_i8, d*shift) - 1_i8
      j = last_le(self%leaf_key, self%n_leaves, k0)
      if (j > 0) then
         if (self%leaf_level(j) <= level .and. k0 <= last_key(self, j)) then
            first = j
            last = j
            return
         end if
         if (self%leaf_key(j) == k0) then
            first = j
         else
            first = j + 1
         end if
      end if
      last = last_le(self%leaf_key, self%n_leaves, k1)
   end subroutine grid_find_cell

   !> Leaves across a face, edge or corner of `leaf`: the cell of the same level
   !> shifted by `dir` (entries -1, 0, 1), answered as in `find_cell`.
   pure subroutine grid_neighbour(self, leaf, dir, first, last)
      class(grid_type), intent(in) :: self
      integer, intent(in) :: leaf
      integer, intent(in) :: dir(:)
      integer, intent(out) :: first, last
      integer :: d
      d = self%dim
      call self%find_cell(self%leaf_level(leaf), self%leaf_coord(1:d, leaf) + dir(1:d), first, last)
   end subroutine grid_neighbour

   !> Leaf containing the point `x`, 0 if the point is outside the box or in external
   !> space. A point on a shared face belongs to the leaf on its upper side (floor convention).
   pure integer function grid_locate_point(self, x) result(leaf)
      class(grid_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      integer :: ic(3), d, k, j, nfine
      integer(i8) :: kp
      real(wp) :: t

      leaf = 0
      d = self%dim
      if (self%n_leaves == 0) return
      nfine = 2**grid_max_level
      do k = 1, d
         t = (x(k) - self%box_min(k))/self%box_size
         if (.not. (t >= 0.0_wp .and. t <= 1.0_wp)) return
         ic(k) = min(int(t*real(nfine, wp)), nfine - 1)
      end do
      kp = morton_encode(ic(1:d))
      j = last_le(self%leaf_key, self%n_leaves, kp)
      if (j > 0) then
         if (kp <= last_key(self, j)) leaf = j
      end if
   end function grid_locate_point

   !> Last key of the Morton range covered by leaf `j`.
   pure integer(i8) function last_key(self, j)
      type(grid_type), intent(in) :: self
      integer, intent(in) :: j
      last_key = self%leaf_key(j) + ishft(1_i8, self%dim*(grid_max_level - self%leaf_level(j))) - 1_i8
   end function last_key

   !> Index of the last entry of the ascending `keys(1:n)` that is <= k (0 if none).
   pure integer function last_le(keys, n, k) result(j)
      integer(i8), intent(in) :: keys(:)
      integer, intent(in) :: n
      integer(i8), intent(in) :: k
      integer :: lo, hi, mid
      lo = 0
      hi = n
      do while (lo < hi)
         mid = lo + (hi - lo + 1)/2
         if (keys(mid) <= k) then
            lo = mid
         else
            hi = mid - 1
         end if
      end do
      j = lo
   end function last_le

   pure subroutine cell_box(dim, box_min, box_size, level, coord, lo, hi)
      integer, intent(in) :: dim, level, coord(:)
      real(wp), intent(in) :: box_min(:), box_size
      real(wp), intent(out) :: lo(:), hi(:)
      real(wp) :: h
      ! Powers of two scale exactly, so neighbouring cells share bit-identical faces.
      h = box_size*2.0_wp**(-level)
      lo(1:dim) = box_min(1:dim) + real(coord(1:dim), wp)*h
      hi(1:dim) = box_min(1:dim) + real(coord(1:dim) + 1, wp)*h
   end subroutine cell_box

   ! ---------------------------------------------------------------- building

   subroutine builder_init(b)
      type(builder_type), intent(inout) :: b
      integer, parameter :: cap0 = 1024
      allocate (b%lev(cap0), b%crd(3, cap0), b%cls(cap0), b%alive(cap0))
      call b%cells%init(b%dim + 1, cap0, 'grid build', b%error)
   end subroutine builder_init

   integer function classify(b, region, level, coord) result(cls)
      type(builder_type), intent(inout) :: b
      class(region_type), intent(in) :: region
      integer, intent(in) :: level, coord(3)
      real(wp) :: lo(3), hi(3)
      call cell_box(b%dim, b%box_min, b%box_size, level, coord, lo, hi)
      cls = region%classify_box(lo(1:b%dim), hi(1:b%dim))
      if (cls /= cell_outside .and. cls /= cell_inside .and. cls /= cell_cut) then
         b%bad_class = .true.
         cls = cell_cut
      end if
   end function classify

   !> Offset of child `k` (0 .. 2**dim - 1): bit i of k is the offset along axis i+1.
   pure function child_offset(k) result(off)
      integer, intent(in) :: k
      integer :: off(3)
      off = [iand(k, 1), iand(ishft(k, -1), 1), iand(ishft(k, -2), 1)]
   end function child_offset

   !> Descend from cell (level, coord) of class `cls`: split as `build` asks, or,
   !> with `old` and `target`, as `build_adapted` asks.
   recursive subroutine descend(b, region, level, coord, cls, old, target)
      type(builder_type), intent(inout) :: b
      class(region_type), intent(in) :: region
      integer, intent(in) :: level, coord(3), cls
      type(grid_type), intent(in), optional :: old
      integer, intent(in), optional :: target(:)
      integer :: k, child(3), child_class
      logical :: split

      if (allocated(b%error)) return
      if (cls == cell_outside) then
         call add_outside(b, level)
         return
      end if
      if (present(old)) then
         split = level < wanted_level(old, target, level, coord, b%top)
      else
         split = level < b%level .or. (cls == cell_cut .and. level < b%top)
      end if
      if (split) then
         call hash_put(b, level, coord, -1)
         do k = 0, 2**b%dim - 1
            child = 2*coord + child_offset(k)
            if (b%dim == 2) child(3) = 0
            child_class = cell_inside
            if (cls == cell_cut) child_class = classify(b, region, level + 1, child)
            call descend(b, region, level + 1, child, child_class, old, target)
         end do
      else
         call add_leaf(b, level, coord, cls)
      end if
   end subroutine descend

   !> The level wanted for the cell (level, coord) of an adapted grid: the largest
   !> target of the old leaves it overlaps (one leaf covering it, or the Morton run of
   !> those inside it), the old finest level if none does, clamped to [0, top].
   integer function wanted_level(old, target, level, coord, top) result(want)
      type(grid_type), intent(in) :: old
      integer, intent(in) :: target(:), level, coord(3), top
      integer :: first, last
      call old%find_cell(level, coord(1:old%dim), first, last)
      if (first <= last) then
         want = maxval(target(first:last))
      else
         want = old%max_level
      end if
      want = max(0, min(want, top))
   end function wanted_level

   !> Count an external cell at its level (`complete` folds the coarse ones).
   subroutine add_outside(b, level)
      type(builder_type), intent(inout) :: b
      integer, intent(in) :: level
      b%n_outside(level) = b%n_outside(level) + 1_i8
   end subroutine add_outside

   subroutine add_leaf(b, level, coord, cls)
      type(builder_type), intent(inout) :: b
      integer, intent(in) :: level, coord(3), cls
      if (b%n == size(b%lev)) call grow_leaves(b)
      if (allocated(b%error)) return
      b%n = b%n + 1
      b%lev(b%n) = level
      b%crd(:, b%n) = coord
      b%cls(b%n) = cls
      b%alive(b%n) = .true.
      call hash_put(b, level, coord, b%n)
   end subroutine add_leaf

   subroutine grow_leaves(b)
      type(builder_type), intent(inout) :: b
      integer, allocatable :: ilev(:), icrd(:, :), icls(:)
      logical, allocatable :: ialive(:)
      integer :: cap, stat
      cap = 2*size(b%lev)
      allocate (ilev(cap), icrd(3, cap), icls(cap), ialive(cap), stat=stat)
      call check_allocation(stat, 'grid build', 'the leaf arrays', cap, 6*storage_size(cap)/8, b%error)
      if (allocated(b%error)) return
      ilev(1:b%n) = b%lev(1:b%n)
      icrd(:, 1:b%n) = b%crd(:, 1:b%n)
      icls(1:b%n) = b%cls(1:b%n)
      ialive(1:b%n) = b%alive(1:b%n)
      call move_alloc(ilev, b%lev)
      call move_alloc(icrd, b%crd)
      call move_alloc(icls, b%cls)
      call move_alloc(ialive, b%alive)
   end subroutine grow_leaves

   !> Replace leaf `i` by its non-external children.
   subroutine split_leaf(b, region, i)
      type(builder_type), intent(inout) :: b
      class(region_type), intent(in) :: region
      integer, intent(in) :: i
      integer :: level, coord(3), cls, k, child(3), child_class

      level = b%lev(i)
      coord = b%crd(:, i)
      cls = b%cls(i)
      b%alive(i) = .false.
      b%n_splits = b%n_splits + 1
      call hash_put(b, level, coord, -1)
      do k = 0, 2**b%dim - 1
         child = 2*coord + child_offset(k)
         if (b%dim == 2) child(3) = 0
         child_class = cell_inside
         if (cls == cell_cut) child_class = classify(b, region, level + 1, child)
         if (child_class == cell_outside) then
            call add_outside(b, level + 1)
         else
            call add_leaf(b, level + 1, child, child_class)
         end if
      end do
   end subroutine split_leaf

   !> The 2:1 balance across faces, edges and corners. A leaf of level l needs every
   !> level-(l-1) neighbour of its parent to exist (or to be external): a coarser
   !> leaf covering such a cell is split down to level l-1. Levels are swept from
   !> the finest down, so leaves made while sweeping level l (all of level < l)
   !> are checked when their own level is swept.
   subroutine balance(b, region)
      type(builder_type), intent(inout) :: b
      class(region_type), intent(in) :: region
      integer :: l, i, n0, parent(3), q(3), d(3), k, ndir
      integer(i8) :: pkey, last_parent

      ndir = 3**b%dim
      do l = b%top, b%level + 2, -1
         n0 = b%n
         last_parent = -1_i8
         do i = 1, n0
            if (allocated(b%error)) return
            if (.not. b%alive(i) .or. b%lev(i) /= l) cycle
            parent = b%crd(:, i)/2
            pkey = cell_key(b%dim, l - 1, parent)
            if (pkey == last_parent) cycle
            last_parent = pkey
            do k = 0, ndir - 1
               d = [mod(k, 3) - 1, mod(k/3, 3) - 1, mod(k/9, 3) - 1]
               if (b%dim == 2) d(3) = 0
               if (all(d == 0)) cycle
               q = parent + d
               if (any(q(1:b%dim) < 0) .or. any(q(1:b%dim) >= 2**(l - 1))) cycle
               call ensure_cell(b, region, l - 1, q)
            end do
         end do
      end do
   end subroutine balance

   !> Make the cell (level, coord) exist unless it is external.
   subroutine ensure_cell(b, region, level, coord)
      type(builder_type), intent(inout) :: b
      class(region_type), intent(in) :: region
      integer, intent(in) :: level, coord(3)
      integer :: m, v

      if (hash_get(b, level, coord) /= 0) return
      v = 0
      do m = level - 1, 0, -1
         v = hash_get(b, m, ishft(coord, -(level - m)))
         if (v /= 0) exit
      end do
      if (v <= 0) return
      do
         call split_leaf(b, region, v)
         m = m + 1
         if (m == level) exit
         v = hash_get(b, m, ishft(coord, -(level - m)))
         if (v <= 0) exit
      end do
   end subroutine ensure_cell

   !> Move the live leaves into `grid`, sorted by Morton key, and count them per level.
   subroutine finalize(grid, b, error)
      type(grid_type), intent(inout) :: grid
      type(builder_type), intent(inout) :: b
      type(error_type), allocatable, intent(out) :: error
      integer(i8), allocatable :: keys(:)
      integer, allocatable :: idx(:), perm(:), work(:)
      integer :: n, i, j, d, stat

      deallocate (b%cells%keys, b%cells%value, b%cells%slot)
      d = b%dim
      n = count(b%alive(1:b%n))
      allocate (keys(n), idx(n), stat=stat)
      call check_allocation(stat, 'grid build', 'the sort keys of the leaves', n, 12, error)
      if (allocated(error)) return
      j = 0
      do i = 1, b%n
         if (.not. b%alive(i)) cycle
         j = j + 1
         idx(j) = i
         keys(j) = morton_encode(ishft(b%crd(1:d, i), grid_max_level - b%lev(i)))
      end do
      allocate (perm(n), work(n), stat=stat)
      call check_allocation(stat, 'grid build', 'the sort permutation of the leaves', n, 8, error)
      if (allocated(error)) return
      call sort_order(keys, perm, work)
      allocate (grid%leaf_level(n), grid%leaf_coord(d, n), grid%leaf_class(n), grid%leaf_key(n), stat=stat)
      call check_allocation(stat, 'grid build', 'the leaves of the grid', n, 4*(d + 2) + 8, error)
      if (allocated(error)) return
      grid%n_leaves = n
      grid%max_level = b%level
      do j = 1, n
         i = idx(perm(j))
         grid%leaf_key(j) = keys(perm(j))
         grid%leaf_level(j) = b%lev(i)
         grid%leaf_coord(:, j) = b%crd(1:d, i)
         grid%leaf_class(j) = b%cls(i)
         grid%max_level = max(grid%max_level, b%lev(i))
         if (b%cls(i) == cell_inside) then
            grid%n_inside(b%lev(i)) = grid%n_inside(b%lev(i)) + 1_i8
         else
            grid%n_cut(b%lev(i)) = grid%n_cut(b%lev(i)) + 1_i8
         end if
      end do
   end subroutine finalize

   ! ---------------------------------------------------------------- cell hash

   !> Key of a cell unique over all levels: its Morton key with a marker bit above it.
   pure integer(i8) function cell_key(dim, level, coord)
      integer, intent(in) :: dim, level, coord(3)
      cell_key = ior(morton_encode(coord(1:dim)), ishft(1_i8, dim*level))
   end function cell_key

   !> The value of the cell (level, coord): 0 if it was never stored.
   integer function hash_get(b, level, coord) result(val)
      type(builder_type), intent(in) :: b
      integer, intent(in) :: level, coord(3)
      integer :: n
      val = 0
      n = b%cells%find([level, coord(1:b%dim)])
      if (n > 0) val = b%cells%value(n)
   end function hash_get

   !> Store the cell (level, coord) with the value val (see builder_type).
   subroutine hash_put(b, level, coord, val)
      type(builder_type), intent(inout) :: b
      integer, intent(in) :: level, coord(3), val
      integer :: n
      logical :: added
      if (allocated(b%error)) return
      call b%cells%insert([level, coord(1:b%dim)], n, added, b%error)
      if (allocated(b%error)) return
      b%cells%value(n) = val
   end subroutine hash_put

end module sprc_grid_tree
