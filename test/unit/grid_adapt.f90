!> Tests of h-adaptivity on the grid side: `grid_type%build_adapted`,
!> `cut_mesh_type%build_adapted` and the size fields of `sprc_grid_adapt`.
!>
!> Independent checks: grids built by `build` (the same leaves, keys, classes
!> and counts); brute-force pair tests of 2:1 balance and of the levels the
!> old leaves asked for (integer boxes, no `find_cell`); the closed-form area
!> and volume of a disk and a ball summed from the cut-cell rules; the
!> optimal-mesh prediction by hand for equal indicators and one hot element,
!> and numerically through its defining properties (equidistribution, the
!> target met, the element count minimal under perturbation); Dörfler
!> marking by hand and against the smallest subset found by enumeration.
module sprc_test_adapt
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input
   use sprc_geometry_region, only: cell_inside
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere
   use sprc_geometry_body, only: body_type, new_body, csg_add
   use sprc_grid_tree, only: grid_type, grid_max_level
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature
   use sprc_grid_adapt, only: optimal_levels, optimal_ratio, fraction_levels, default_max_change
   use sprc_core_text, only: itoa
   use sprc_test_grid, only: check_balance, check_volume, int_box
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_adapt

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Cut-cell rules with q = 6 on level >= 3 give area and volume to 1e-12 (2D) and
   !> 1e-10 (3D) relative (the acceptance bounds of the quadrature suite).
   real(wp), parameter :: tol2d = 1.0e-12_wp, tol3d = 1.0e-10_wp

contains

   subroutine collect_adapt(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('same-levels-reproduce-2d', test_same_2d), &
         new_unittest('same-levels-reproduce-3d', test_same_3d), &
         new_unittest('one-finer-is-uniform-2d', test_finer_2d), &
         new_unittest('one-finer-is-uniform-3d', test_finer_3d), &
         new_unittest('refine-at-point-2d', test_point_2d), &
         new_unittest('refine-at-point-3d', test_point_3d), &
         new_unittest('coarsen-half-2d', test_coarsen_2d), &
         new_unittest('coarsen-half-3d', test_coarsen_3d), &
         new_unittest('level-after-balance', test_level_after_balance), &
         new_unittest('mesh-measure-2d', test_measure_2d), &
         new_unittest('mesh-measure-3d', test_measure_3d), &
         new_unittest('adapted-bad-input', test_adapted_bad_input), &
         new_unittest('optimal-equal-indicators', test_optimal_equal), &
         new_unittest('optimal-hot-element', test_optimal_hot), &
         new_unittest('optimal-clamps', test_optimal_clamps), &
         new_unittest('optimal-equidistribution', test_optimal_identity), &
         new_unittest('fraction-hand', test_fraction_hand), &
         new_unittest('fraction-minimal-set', test_fraction_minimal), &
         new_unittest('marking-bad-input', test_marking_bad_input) &
         ]
   end subroutine collect_adapt

   ! ------------------------------------------------------------------ helpers

   !> A disk (2D) or ball (3D) of radius r about a centre off every grid line of the unit box.
   subroutine round_body(dim, r, body, error)
      integer, intent(in) :: dim
      real(wp), intent(in) :: r
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: s
      if (dim == 2) then
         call new_body(body, 'disk')
         call new_disk(s, 'disk', [0.513_wp, 0.4871_wp], r, error)
      else
         call new_body(body, 'ball')
         call new_sphere(s, 'ball', [0.513_wp, 0.4871_wp, 0.5029_wp], r, error)
      end if
      if (allocated(error)) return
      call body%add_shape(csg_add, s, error)
   end subroutine round_body

   !> The two grids have the same leaves (keys, levels, coordinates, classes) and counts.
   subroutine check_same_grid(error, a, b, what)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: a, b
      character(len=*), intent(in) :: what
      call check(error, a%n_leaves, b%n_leaves, what//': leaf count')
      if (allocated(error)) return
      call check(error, all(a%leaf_key == b%leaf_key) .and. all(a%leaf_level == b%leaf_level) .and. &
         & all(a%leaf_coord == b%leaf_coord) .and. all(a%leaf_class == b%leaf_class), what//': leaves')
      if (allocated(error)) return
      call check(error, all(a%n_inside == b%n_inside) .and. all(a%n_cut == b%n_cut) .and. &
         & all(a%n_outside == b%n_outside), what//': counts per level')
      if (allocated(error)) return
      call check(error, a%level == b%level .and. a%max_level == b%max_level .and. a%dim == b%dim .and. &
         & all(a%box_min == b%box_min) .and. a%box_size == b%box_size, what//': level, finest level, box')
   end subroutine check_same_grid

   !> Brute force over all pairs (new leaf, old leaf) that overlap: the new leaf is at
   !> least as fine as the old leaf's target (clamped to max_level). With `exact`, a new
   !> leaf is also no finer than the largest such target unless the balance split it
   !> (it touches a leaf two levels finer than itself would be).
   subroutine check_targets(error, new, old, target, max_level)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: new, old
      integer, intent(in) :: target(:), max_level
      integer :: i, j, d, lo(3), hi(3), olo(3), ohi(3)
      d = new%dim
      do i = 1, new%n_leaves
         call int_box(new, i, lo, hi)
         do j = 1, old%n_leaves
            call int_box(old, j, olo, ohi)
            if (.not. all(lo(1:d) < ohi(1:d) .and. olo(1:d) < hi(1:d))) cycle
            if (new%leaf_level(i) < min(target(j), max_level)) then
               call test_failed(error, 'new leaf '//itoa(i)//' of level '//itoa(new%leaf_level(i))// &
                  & ' overlaps old leaf '//itoa(j)//' that wants level '//itoa(target(j)))
               return
            end if
         end do
      end do
   end subroutine check_targets

   !> Brute force: every leaf of level l > 0 is needed, i.e. its parent overlaps an old
   !> leaf whose target (at most max_level) is >= l, or the balance split the parent:
   !> a leaf of level >= l + 1 has its level-l ancestor touching the parent's box (the
   !> balance makes a level-l cell exist next to the parent of a level-(l+1) leaf).
   subroutine check_needed(error, new, old, target, max_level)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in) :: new, old
      integer, intent(in) :: target(:), max_level
      integer :: i, j, k, d, l, lo(3), hi(3), olo(3), ohi(3), s
      logical :: needed
      d = new%dim
      do i = 1, new%n_leaves
         l = new%leaf_level(i)
         if (l == 0) cycle
         s = 2**(grid_max_level - l + 1)
         lo = 0
         hi = 0
         lo(1:d) = (new%leaf_coord(:, i)/2)*s
         hi(1:d) = lo(1:d) + s
         needed = .false.
         do j = 1, old%n_leaves
            call int_box(old, j, olo, ohi)
            if (all(lo(1:d) < ohi(1:d) .and. olo(1:d) < hi(1:d)) .and. min(target(j), max_level) >= l) then
               needed = .true.
               exit
            end if
         end do
         if (needed) cycle
         do k = 1, new%n_leaves
            if (new%leaf_level(k) <= l) cycle
            olo = 0
            ohi = 0
            olo(1:d) = ishft(new%leaf_coord(:, k), l - new%leaf_level(k))*2**(grid_max_level - l)
            ohi(1:d) = olo(1:d) + 2**(grid_max_level - l)
            if (all(lo(1:d) <= ohi(1:d) .and. olo(1:d) <= hi(1:d))) then
               needed = .true.
               exit
            end if
         end do
         if (.not. needed) then
            call test_failed(error, 'leaf '//itoa(i)//' of level '//itoa(l)//' is finer than any target or '// &
               & 'the balance needs')
            return
         end if
      end do
   end subroutine check_needed

   ! ------------------------------------------------------------ build_adapted

   !> Targets = the old levels give the old grid back, leaf for leaf, count for count:
   !> a grid with boundary refinement (rb = 2), built by `build`.
   subroutine same_case(error, dim, level, rb)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level, rb
      type(body_type) :: body
      type(grid_type) :: old, new
      call round_body(dim, 0.31_wp, body, error)
      if (allocated(error)) return
      call old%build(body, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, rb, error)
      if (allocated(error)) return
      call new%build_adapted(body, old, old%leaf_level, level + rb, error)
      if (allocated(error)) return
      call check_same_grid(error, new, old, 'same levels')
      if (allocated(error)) return
      call check(error, new%refine_boundary, rb, 'levels between coarsest and finest')
      if (allocated(error)) return
      ! and again from the adapted grid
      call old%build_adapted(body, new, new%leaf_level, level + rb, error)
      if (allocated(error)) return
      call check_same_grid(error, old, new, 'same levels twice')
   end subroutine same_case

   subroutine test_same_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call same_case(error, 2, 3, 2)
   end subroutine test_same_2d

   subroutine test_same_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call same_case(error, 3, 3, 1)
   end subroutine test_same_3d

   !> Targets = old level + 1 on a uniform grid = the uniform grid one level finer;
   !> on a grid with boundary refinement, every leaf one level finer (no balance needed).
   subroutine finer_case(error, dim, level)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level
      type(body_type) :: body
      type(grid_type) :: old, new, ref
      call round_body(dim, 0.31_wp, body, error)
      if (allocated(error)) return
      call old%build(body, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, 0, error)
      if (.not. allocated(error)) call new%build_adapted(body, old, old%leaf_level + 1, grid_max_level, error)
      if (.not. allocated(error)) call ref%build(body, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level + 1, 0, error)
      if (allocated(error)) return
      call check_same_grid(error, new, ref, 'one level finer')
      if (allocated(error)) return
      call check(error, new%refine_boundary, 0, 'uniform: no levels between coarsest and finest')
      if (allocated(error)) return
      call check(error, new%n_inside(level + 1) + new%n_cut(level + 1) + new%n_outside(level + 1) == &
         & ishft(1_i8, dim*(level + 1)) .and. all(new%n_outside(:level) == 0_i8), &
         & 'uniform: every cell of the level counted at that level')
      if (allocated(error)) return
      call old%build(body, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, 1, error)
      if (.not. allocated(error)) call new%build_adapted(body, old, old%leaf_level + 1, grid_max_level, error)
      if (allocated(error)) return
      call check(error, new%n_balance_splits, 0, 'every leaf one finer needs no balance')
      if (allocated(error)) return
      ! the children of every old leaf: 2**dim each but where a child is external
      call check(error, new%level == old%level + 1 .and. new%max_level == old%max_level + 1, 'levels one finer')
      if (allocated(error)) return
      call check(error, int(sum(new%n_inside)) >= 2**dim*int(sum(old%n_inside)) .and. &
         & new%n_leaves <= 2**dim*old%n_leaves, 'children of the old leaves')
      if (allocated(error)) return
      call check_volume(error, new)
   end subroutine finer_case

   subroutine test_finer_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call finer_case(error, 2, 3)
   end subroutine test_finer_2d

   subroutine test_finer_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call finer_case(error, 3, 3)
   end subroutine test_finer_3d

   !> Refine the leaf at one point 3 levels: 2:1 balance by brute force, every target met,
   !> the point's leaf exactly at the target, the grid finer only near the point (every
   !> leaf finer than the start level lies within a few target cells of the point).
   subroutine point_case(error, dim, level)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level
      type(body_type) :: body
      type(grid_type) :: old, new
      integer, allocatable :: target(:)
      real(wp) :: p(3), lo(3), hi(3), reach
      integer :: j, i

      call round_body(dim, 0.31_wp, body, error)
      if (allocated(error)) return
      call old%build(body, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, 0, error)
      if (allocated(error)) return
      p = [0.4417_wp, 0.5213_wp, 0.4711_wp]
      j = old%locate_point(p(1:dim))
      call check(error, j > 0, 'the point lies in a leaf')
      if (allocated(error)) return
      target = old%leaf_level
      target(j) = level + 3
      call new%build_adapted(body, old, target, level + 3, error)
      if (allocated(error)) return
      call check_balance(error, new)
      if (allocated(error)) return
      call check_volume(error, new)
      if (allocated(error)) return
      call check_targets(error, new, old, target, level + 3)
      if (allocated(error)) return
      call check_needed(error, new, old, target, level + 3)
      if (allocated(error)) return
      call check(error, new%level, minval(new%leaf_level), 'level = coarsest leaf level')
      if (allocated(error)) return
      i = new%locate_point(p(1:dim))
      call check(error, new%leaf_level(i), level + 3, 'the point''s leaf')
      if (allocated(error)) return
      call check(error, new%n_balance_splits > 0 .and. new%max_level == level + 3, &
         & 'the balance graded the refinement')
      if (allocated(error)) return
      ! a balanced grading from level+3 down to level reaches at most 1 + 2 + 4 cells of
      ! levels +3, +2, +1 beyond the old leaf, i.e. within one old cell of it
      reach = old%cell_width(level)
      call old%leaf_box(j, lo(1:dim), hi(1:dim))
      do i = 1, new%n_leaves
         if (new%leaf_level(i) == level) cycle
         block
            real(wp) :: a(3), b(3)
            call new%leaf_box(i, a(1:dim), b(1:dim))
            if (any(a(1:dim) < lo(1:dim) - reach - 1.0e-12_wp) .or. any(b(1:dim) > hi(1:dim) + reach + 1.0e-12_wp)) then
               call test_failed(error, 'leaf '//itoa(i)//' refined far from the point')
               return
            end if
         end block
      end do
   end subroutine point_case

   subroutine test_point_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call point_case(error, 2, 3)
   end subroutine test_point_2d

   subroutine test_point_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call point_case(error, 3, 2)
   end subroutine test_point_3d

   !> Targets one level coarser on the half x < 1/2. On a uniform grid every leaf
   !> there is one level coarser (no balance against the other half, one level apart)
   !> and the other half keeps its leaves. On a grid with boundary refinement (rb = 1)
   !> the old leaves under one new cell want different levels: every target is met
   !> and no leaf is finer than a target or the balance needs (brute force).
   subroutine coarsen_case(error, dim, level, rb)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level, rb
      type(body_type) :: body
      type(grid_type) :: old, new
      integer, allocatable :: target(:)
      real(wp) :: lo(3), hi(3)
      integer :: j, n_left_old, n_left_new

      call round_body(dim, 0.31_wp, body, error)
      if (allocated(error)) return
      call old%build(body, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, rb, error)
      if (allocated(error)) return
      target = old%leaf_level
      n_left_old = 0
      do j = 1, old%n_leaves
         call old%leaf_box(j, lo(1:dim), hi(1:dim))
         if (hi(1) <= 0.5_wp) then
            target(j) = old%leaf_level(j) - 1
            n_left_old = n_left_old + 1
         end if
      end do
      call new%build_adapted(body, old, target, level + rb, error)
      if (allocated(error)) return
      call check_balance(error, new)
      if (allocated(error)) return
      call check_volume(error, new)
      if (allocated(error)) return
      call check_targets(error, new, old, target, level + rb)
      if (allocated(error)) return
      call check_needed(error, new, old, target, level + rb)
      if (allocated(error)) return
      n_left_new = 0
      do j = 1, new%n_leaves
         call new%leaf_box(j, lo(1:dim), hi(1:dim))
         if (hi(1) <= 0.5_wp) then
            n_left_new = n_left_new + 1
            if (rb == 0) call check(error, new%leaf_level(j), level - 1, 'a leaf of the coarsened half')
         else
            call check(error, new%leaf_level(j), old%leaf_level(old%locate_point(lo(1:dim))), &
               & 'a leaf of the kept half')
         end if
         if (allocated(error)) return
      end do
      call check(error, new%n_leaves - n_left_new, old%n_leaves - n_left_old, 'the kept half')
      if (allocated(error)) return
      call check(error, n_left_new < n_left_old .and. n_left_new >= n_left_old/2**dim, 'fewer leaves on the left')
      if (allocated(error)) return
      call check(error, new%level, minval(new%leaf_level), 'level = coarsest leaf level')
      if (allocated(error)) return
      if (rb == 0) call check(error, new%level == level - 1 .and. new%refine_boundary == 1, 'coarsest level one below')
   end subroutine coarsen_case

   subroutine test_coarsen_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call coarsen_case(error, 2, 4, 0)
      if (.not. allocated(error)) call coarsen_case(error, 2, 4, 1)
   end subroutine test_coarsen_2d

   subroutine test_coarsen_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call coarsen_case(error, 3, 3, 0)
      if (.not. allocated(error)) call coarsen_case(error, 3, 3, 1)
   end subroutine test_coarsen_3d

   !> Inside leaves one level coarser next to boundary leaves two levels finer: the
   !> balance splits the coarsened leaves again, and the grid's level is the coarsest
   !> level left (what the hanging constraints and the external counts rely on).
   subroutine test_level_after_balance(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(grid_type) :: old, new
      integer, allocatable :: target(:)
      real(wp) :: lo(2), hi(2)
      integer :: j
      call round_body(2, 0.31_wp, body, error)
      if (.not. allocated(error)) call old%build(body, 2, [0.0_wp, 0.0_wp], 1.0_wp, 4, 1, error)
      if (allocated(error)) return
      ! inside leaves of the left half one coarser (level 3), the upper right quadrant one finer
      target = old%leaf_level
      do j = 1, old%n_leaves
         call old%leaf_box(j, lo, hi)
         if (hi(1) <= 0.5_wp .and. old%leaf_class(j) == cell_inside) target(j) = target(j) - 1
         if (lo(2) >= 0.5_wp .and. lo(1) >= 0.5_wp) target(j) = target(j) + 1
      end do
      call new%build_adapted(body, old, target, 6, error)
      if (allocated(error)) return
      call check(error, new%n_balance_splits > 0, 'the balance split coarsened leaves')
      if (allocated(error)) return
      call check(error, new%level, minval(new%leaf_level), 'level = coarsest leaf level')
      if (allocated(error)) return
      call check_volume(error, new)
      if (allocated(error)) return
      call check_balance(error, new)
   end subroutine test_level_after_balance

   !> The cut mesh on an adapted grid (refined at a point, coarsened on a half, boundary
   !> refined): its cell rules add up to the area or volume of the body.
   subroutine measure_case(error, dim, level, tol)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in) :: dim, level
      real(wp), intent(in) :: tol
      type(body_type) :: body
      type(cut_mesh_type) :: start, mesh
      type(cut_quadrature_type) :: quad
      integer, allocatable :: target(:)
      real(wp) :: r, lo(3), hi(3), exact
      integer :: j, n_left_old, n_left_new

      r = 0.31_wp
      call round_body(dim, r, body, error)
      if (.not. allocated(error)) call start%build(body, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, 1, 1, error)
      if (allocated(error)) return
      target = start%grid%leaf_level
      n_left_old = 0
      do j = 1, start%grid%n_leaves
         call start%grid%leaf_box(j, lo(1:dim), hi(1:dim))
         if (hi(1) <= 0.5_wp) then
            target(j) = target(j) - 1
            n_left_old = n_left_old + 1
         end if
         if (lo(2) >= 0.5_wp .and. lo(1) >= 0.5_wp) target(j) = target(j) + 1
      end do
      call mesh%build_adapted(body, start%grid, target, level + 2, 2, error)
      if (allocated(error)) return
      n_left_new = 0
      do j = 1, mesh%grid%n_leaves
         call mesh%grid%leaf_box(j, lo(1:dim), hi(1:dim))
         if (hi(1) <= 0.5_wp) n_left_new = n_left_new + 1
      end do
      call check(error, n_left_new < n_left_old .and. mesh%grid%max_level == level + 2, 'coarsened and refined')
      if (allocated(error)) return
      call check(error, mesh%grid%level, minval(mesh%grid%leaf_level), 'level = coarsest leaf level')
      if (allocated(error)) return
      call check(error, mesh%nodes%degree == 2 .and. mesh%nodes%n_nodes > 0 .and. mesh%t_mesh >= 0.0_wp, &
         & 'nodes of degree 2 and the time')
      if (allocated(error)) return
      call new_cut_quadrature(quad, dim, 6, error)
      if (.not. allocated(error)) call mesh%integrate(quad, error)
      if (allocated(error)) return
      if (dim == 2) then
         exact = pi*r**2
      else
         exact = 4.0_wp*pi*r**3/3.0_wp
      end if
      call check(error, sum(mesh%vol_w), exact, tol, 'measure of the body', rel=.true.)
   end subroutine measure_case

   subroutine test_measure_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call measure_case(error, 2, 4, tol2d)
   end subroutine test_measure_2d

   subroutine test_measure_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call measure_case(error, 3, 3, tol3d)
   end subroutine test_measure_3d

   !> `build_adapted` refuses a grid that was never built, a target of the wrong size or
   !> with a negative entry, and max_level outside [0, grid_max_level], naming the field.
   subroutine test_adapted_bad_input(error)
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(grid_type) :: old, none, new
      type(cut_mesh_type) :: mesh
      integer, allocatable :: target(:)

      call round_body(2, 0.31_wp, body, error)
      if (.not. allocated(error)) call old%build(body, 2, [0.0_wp, 0.0_wp], 1.0_wp, 2, 0, error)
      if (allocated(error)) return
      target = old%leaf_level
      call new%build_adapted(body, none, [integer ::], 3, error)
      call expect(error, 'dim 0', 'not built')
      if (allocated(error)) return
      call new%build_adapted(body, old, target(2:), 3, error)
      call expect(error, 'target has '//itoa(old%n_leaves - 1)//' entries', 'short target')
      if (allocated(error)) return
      target(5) = -1
      call new%build_adapted(body, old, target, 3, error)
      call expect(error, 'target(5) = -1', 'negative target')
      if (allocated(error)) return
      target(5) = 2
      call new%build_adapted(body, old, target, -1, error)
      call expect(error, 'max_level must be in [0, '//itoa(grid_max_level)//'], got -1', 'max_level < 0')
      if (allocated(error)) return
      call new%build_adapted(body, old, target, grid_max_level + 1, error)
      call expect(error, 'max_level', 'max_level too large')
      if (allocated(error)) return
      call mesh%build_adapted(body, old, target(3:), 3, 1, error)
      call expect(error, 'target has', 'short target through the mesh')
   end subroutine test_adapted_bad_input

   !> `error` was set, invalid input, its message contains `text`; then cleared (unless wrong).
   subroutine expect(error, text, what)
      type(error_type), allocatable, intent(inout) :: error
      character(len=*), intent(in) :: text, what
      type(error_type), allocatable :: got
      call move_alloc(error, got)
      if (.not. allocated(got)) then
         call test_failed(error, what//': accepted')
      else if (got%stat /= stat_invalid_input .or. index(got%message, text) == 0) then
         call test_failed(error, what//': wrong error: '//got%message)
      end if
   end subroutine expect

   ! ------------------------------------------------------------------ marking

   !> Equal indicators: r = (eta_t/eta)**(1/p) for every element (module notes with all
   !> ||e||_K equal). n = 8, ||e||_K^2 = 1, norm_sq = 5000: eta = 0.04.
   subroutine test_optimal_equal(error)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: levels(:)
      integer :: leaf(8), k, p, d
      real(wp) :: e2(8), t
      leaf = 5
      e2 = 1.0_wp
      ! p = 1, eta/eta_t = 4: r = 1/4, two levels finer, in 2D and 3D alike
      call optimal_levels(leaf, e2, 5000.0_wp, 0.01_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 7), 'p = 1, 2D: 2 levels finer')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 5000.0_wp, 0.01_wp, 1, 3, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 7), 'p = 1, 3D: 2 levels finer')
      if (allocated(error)) return
      ! p = 2: r = 1/2, one level
      call optimal_levels(leaf, e2, 5000.0_wp, 0.01_wp, 2, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 6), 'p = 2: 1 level finer')
      if (allocated(error)) return
      ! eta/eta_t = 4 through inexact numbers, p = 1 and 2, 2D and 3D: r = 4**(-1/p) up to
      ! rounding, so 2/p levels finer (the computed change lands within ulps of 2/p, on
      ! either side: without the sqrt(eps) allowance some of these would get 2/p + 1)
      do k = 1, 39
         t = 0.001_wp*k + 0.0037_wp
         e2 = 0.1_wp*k + 0.07_wp
         do p = 1, 2
            do d = 2, 3
               call optimal_levels(leaf, e2, 8*e2(1)/(4*t)**2, t, p, d, 12, levels, error)
               if (allocated(error)) return
               call check(error, all(levels == 5 + 2/p), 'eta = 4 eta_t, case '//itoa(k)//', p = '//itoa(p)// &
                  & ', d = '//itoa(d))
               if (allocated(error)) return
            end do
         end do
      end do
      e2 = 1.0_wp
      ! p = 1, eta/eta_t = 2**2.6: x = 2.6 levels, rounded up to 3, clamped to 2; 3 when allowed
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**2.6_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 5 + default_max_change) .and. default_max_change == 2, 'clamped to 2 finer')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**2.6_wp, 1, 2, 12, levels, error, max_change=3)
      if (allocated(error)) return
      call check(error, all(levels == 8), 'x = 2.6: rounded up to 3 finer')
      if (allocated(error)) return
      ! A refinement rounds to the nearer error (module notes: up iff its fraction exceeds
      ! theta_p = 0.339 for p = 1, 0.228 for p = 2), not always up: p = 1, x = 1.2 gives the
      ! squared error 2**-2 eta^2 = 1.32 eta_t^2 at 1 level, 2**-4 eta^2 = 0.33 eta_t^2 at 2
      ! levels; x = 1.4: 1.74 against 0.44 eta_t^2, 2 levels.
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**2.14_wp, 1, 2, 12, levels, error, max_change=3)
      if (allocated(error)) return
      call check(error, all(levels == 7), 'x = 2.14: 2 finer, the nearer error')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**1.2_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 6), 'p = 1, x = 1.2: 1 finer')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**1.4_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 7), 'p = 1, x = 1.4: 2 finer')
      if (allocated(error)) return
      ! p = 2: x = log2(eta/eta_t)/2
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**2.4_wp, 2, 3, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 6), 'p = 2, x = 1.2: 1 finer')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**2.5_wp, 2, 3, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 7), 'p = 2, x = 1.25: 2 finer')
      if (allocated(error)) return
      ! no fraction above theta_p (x = 0.2 everywhere): rounded up, the step still refines
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp/2.0_wp**0.2_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 6), 'x = 0.2 everywhere: 1 finer')
      if (allocated(error)) return
      ! at the target: r = 1, no change; a hair above: one level finer
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 5), 'at the target: unchanged')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 5000.0_wp, 0.0399_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 6), 'just above the target: one level finer')
      if (allocated(error)) return
      ! eta = eta_t/4, p = 1: r = 4, two levels coarser wanted, one allowed
      call optimal_levels(leaf, e2, 5000.0_wp, 0.16_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 4), 'coarsened one level')
      if (allocated(error)) return
      ! eta = eta_t/2, p = 1: r = 2, exactly one level coarser
      call optimal_levels(leaf, e2, 5000.0_wp, 0.08_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 4), 'r = 2: one level coarser')
      if (allocated(error)) return
      ! eta = eta_t/1.9: r = 1.9 < 2, the coarser cell would be too large: unchanged
      call optimal_levels(leaf, e2, 5000.0_wp, 0.04_wp*1.9_wp, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == 5), 'r = 1.9: unchanged')
   end subroutine test_optimal_equal

   !> One hot element among 16 (2D, p = 1): ||e||^2 = 256 and 1, sum ||e||^(2d/(2p+d)) =
   !> 16 + 16 = 32; E_t^2 = 8 gives [E_t^2/32]^(1/2) = 1/2, r_hot = 256^(-1/4)/2 = 1/8,
   !> r_cold = 1/2; new elements carry 256/8^4 = 1/16 = 1/2^4 each.
   subroutine test_optimal_hot(error)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: levels(:)
      real(wp), allocatable :: ratio(:)
      integer :: leaf(17)
      real(wp) :: e2(17), norm_sq, target

      leaf = 4
      e2 = 1.0_wp
      e2(9) = 256.0_wp
      target = 0.01_wp
      norm_sq = 8.0_wp/target**2
      call optimal_ratio(e2, norm_sq, target, 1, 2, ratio, error)
      if (allocated(error)) return
      ! log2 r is a sum of logarithms of magnitude <= 8, each to a few ulps, through one 2**x
      call check(error, ratio(9), 0.125_wp, 64*epsilon(1.0_wp), 'r of the hot element', rel=.true.)
      if (allocated(error)) return
      call check(error, maxval(abs(ratio([1, 2, 3, 4, 5, 6, 7, 8, 10, 11, 12, 13, 14, 15, 16, 17]) - 0.5_wp)) <= &
         & 32*epsilon(1.0_wp), 'r of the cold elements')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, norm_sq, target, 1, 2, 12, levels, error, max_change=3)
      if (allocated(error)) return
      call check(error, levels(9) == 7 .and. all(levels(1:8) == 5) .and. all(levels(10:) == 5), &
         & 'hot 3 levels finer, cold 1')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, norm_sq, target, 1, 2, 12, levels, error)
      if (allocated(error)) return
      call check(error, levels(9) == 6 .and. all(levels(10:) == 5), 'hot clamped to 2 levels finer')
   end subroutine test_optimal_hot

   !> The levels stay in [0, max_level]; a zero estimate coarsens one level; all-zero
   !> estimates coarsen everything by one; an empty mesh gives no levels.
   subroutine test_optimal_clamps(error)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: levels(:)
      ! eta/eta_t = 4 (p = 1): two finer; levels 0, 6 (max 7), 9 (above max)
      call optimal_levels([0, 6, 9, 3], [1.0_wp, 1.0_wp, 1.0_wp, 0.0_wp], 3.0_wp/0.04_wp**2, 0.01_wp, 1, 2, 7, &
         & levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [2, 7, 7, 2]), 'clamped to max_level; zero estimate one coarser')
      if (allocated(error)) return
      call optimal_levels([0, 3], [0.0_wp, 0.0_wp], 1.0_wp, 0.01_wp, 2, 3, 7, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [0, 2]), 'no error anywhere: one coarser, never below 0')
      if (allocated(error)) return
      call optimal_levels([integer ::], [real(wp) ::], 1.0_wp, 0.01_wp, 2, 3, 7, levels, error)
      if (allocated(error)) return
      call check(error, size(levels), 0, 'empty')
   end subroutine test_optimal_clamps

   !> Random indicators spanning 12 decades, 2D and 3D, p = 1 and 2: the predicted new
   !> elements carry equal errors ||e||_K^2 r_K^(2p+d), the predicted error
   !> sum ||e||_K^2 r_K^(2p) is the target, and moving size between two elements
   !> along the constraint only increases the element count sum r_K^(-d).
   !> Tolerance: r_K comes from logarithms of magnitude <= 64 through one exp, so
   !> r_K^q carries a relative error <= ~ q * 64 * few eps; 256 q eps (q <= 7) bounds it.
   subroutine test_optimal_identity(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 200
      real(wp), allocatable :: r(:)
      real(wp) :: e2(n), norm_sq, target, each(n), tol, dn, t, ri, rj
      integer :: d, p, k, q, j

      do k = 1, n
         e2(k) = 10.0_wp**(-12.0_wp*modulo(0.6180339887_wp*k, 1.0_wp))
      end do
      target = 0.003_wp
      norm_sq = 5.0_wp*sum(e2)/0.01_wp**2
      do d = 2, 3
         do p = 1, 2
            q = 2*p + d
            tol = 256.0_wp*q*epsilon(1.0_wp)
            call optimal_ratio(e2, norm_sq, target, p, d, r, error)
            if (allocated(error)) return
            each = e2*r**q
            call check(error, maxval(each)/minval(each) - 1.0_wp <= tol, 'equidistributed, d = '//itoa(d)// &
               & ', p = '//itoa(p))
            if (allocated(error)) return
            call check(error, sum(e2*r**(2*p)), target**2*norm_sq, tol, 'the target error', rel=.true.)
            if (allocated(error)) return
            ! element k gets (1 + t) r_k; element j, which carries the most error, takes up
            ! the change; the count changes by a second-order amount (first order cancels)
            j = minloc(r, 1)
            do k = 1, 4
               t = merge(0.05_wp, -0.05_wp, mod(k, 2) == 0)
               ri = r(k)*(1.0_wp + t)
               rj = ((e2(k)*r(k)**(2*p) + e2(j)*r(j)**(2*p) - e2(k)*ri**(2*p))/e2(j))**(1.0_wp/(2*p))
               dn = (ri**(-d) - r(k)**(-d)) + (rj**(-d) - r(j)**(-d))
               call check(error, dn > 0.0_wp, 'a perturbed mesh has more elements')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_optimal_identity

   !> Dörfler by hand: [1, 4, 4, 2, 0, 1] (total 12).
   subroutine test_fraction_hand(error)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: levels(:)
      real(wp), parameter :: e2(6) = [1.0_wp, 4.0_wp, 4.0_wp, 2.0_wp, 0.0_wp, 1.0_wp]
      integer, parameter :: leaf(6) = [3, 3, 4, 3, 3, 5]
      call fraction_levels(leaf, e2, 0.5_wp, 9, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [3, 4, 5, 3, 3, 5]), 'half: the two 4s')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 0.25_wp, 9, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [3, 4, 4, 3, 3, 5]), 'a quarter: the first 4 (tie by index)')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 0.75_wp, 9, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [3, 4, 5, 4, 3, 5]), '3/4: the 4s and the 2')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 0.84_wp, 9, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [4, 4, 5, 4, 3, 5]), '0.84 > 10/12: the first 1 too (tie by index)')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 1.0_wp, 5, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [4, 4, 5, 4, 3, 5]), 'all: every nonzero, max_level 5 kept')
      if (allocated(error)) return
      call fraction_levels(leaf, [0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, 9, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == leaf), 'no error: nothing marked')
      if (allocated(error)) return
      call fraction_levels([2, 2, 2, 2], [3.0_wp, 3.0_wp, 3.0_wp, 3.0_wp], 0.5_wp, 9, levels, error)
      if (allocated(error)) return
      call check(error, all(levels == [3, 3, 2, 2]), 'ties: the lowest indices')
   end subroutine test_fraction_hand

   !> The marked set is the smallest carrying the fraction: enumeration of all subsets
   !> of 12 elements (small integers, so the sums are exact) for several fractions.
   subroutine test_fraction_minimal(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 12
      integer, allocatable :: levels(:)
      real(wp) :: e2(n), theta, s
      integer :: k, m, best, f, leaf(n)

      do k = 1, n
         e2(k) = real(mod(k*37, 11) + mod(k, 3), wp)
      end do
      leaf = 1
      do f = 1, 8
         theta = real(f, wp)/8.0_wp
         call fraction_levels(leaf, e2, theta, 9, levels, error)
         if (allocated(error)) return
         best = n + 1
         do m = 0, 2**n - 1
            s = 0.0_wp
            do k = 1, n
               if (btest(m, k - 1)) s = s + e2(k)
            end do
            if (s >= theta*sum(e2)) best = min(best, popcnt(m))
         end do
         call check(error, count(levels == 2), best, 'marked count, fraction '//itoa(f)//'/8')
         if (allocated(error)) return
         call check(error, sum(e2, mask=levels == 2) >= theta*sum(e2), 'the marked set carries the fraction')
         if (allocated(error)) return
      end do
   end subroutine test_fraction_minimal

   !> Sizes, NaN, infinite or negative estimates, target and fraction out of range,
   !> degree, dim, max_change, norm_sq, leaf levels and max_level are refused by name.
   subroutine test_marking_bad_input(error)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: levels(:)
      real(wp), allocatable :: ratio(:)
      real(wp) :: nan, inf
      integer :: leaf(3)
      real(wp) :: e2(3)

      nan = ieee_value(1.0_wp, ieee_quiet_nan)
      inf = ieee_value(1.0_wp, ieee_positive_inf)
      leaf = 3
      e2 = 1.0_wp
      call optimal_levels(leaf(1:2), e2, 1.0_wp, 0.1_wp, 1, 2, 9, levels, error)
      call expect(error, 'leaf_level has 2 entries, err_sq 3', 'sizes')
      if (allocated(error)) return
      call optimal_levels(leaf, [1.0_wp, nan, 1.0_wp], 1.0_wp, 0.1_wp, 1, 2, 9, levels, error)
      call expect(error, 'err_sq(2) = NaN', 'NaN estimate')
      if (allocated(error)) return
      call optimal_levels(leaf, [1.0_wp, 1.0_wp, -1.0_wp], 1.0_wp, 0.1_wp, 1, 2, 9, levels, error)
      call expect(error, 'err_sq(3)', 'negative estimate')
      if (allocated(error)) return
      call optimal_levels(leaf, [inf, 1.0_wp, 1.0_wp], 1.0_wp, 0.1_wp, 1, 2, 9, levels, error)
      call expect(error, 'err_sq(1)', 'infinite estimate')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, 0.0_wp, 1, 2, 9, levels, error)
      call expect(error, 'target must be in (0, 1)', 'target 0')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, 1.0_wp, 1, 2, 9, levels, error)
      call expect(error, 'target must be in (0, 1)', 'target 1')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, nan, 1, 2, 9, levels, error)
      call expect(error, 'target must be in (0, 1)', 'target NaN')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 0.0_wp, 0.1_wp, 1, 2, 9, levels, error)
      call expect(error, 'norm_sq', 'norm_sq 0')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, 0.1_wp, 0, 2, 9, levels, error)
      call expect(error, 'degree', 'degree 0')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, 0.1_wp, 1, 4, 9, levels, error)
      call expect(error, 'dim must be 2 or 3, got 4', 'dim 4')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, 0.1_wp, 1, 2, 9, levels, error, max_change=0)
      call expect(error, 'max_change must be >= 1, got 0', 'max_change 0')
      if (allocated(error)) return
      call optimal_levels([3, -1, 3], e2, 1.0_wp, 0.1_wp, 1, 2, 9, levels, error)
      call expect(error, 'leaf_level(2) = -1', 'negative leaf level')
      if (allocated(error)) return
      call optimal_levels(leaf, e2, 1.0_wp, 0.1_wp, 1, 2, grid_max_level + 1, levels, error)
      call expect(error, 'max_level', 'max_level too large')
      if (allocated(error)) return
      call optimal_ratio([1.0_wp, nan], 1.0_wp, 0.1_wp, 1, 2, ratio, error)
      call expect(error, 'err_sq(2) = NaN', 'NaN estimate (ratio)')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 0.0_wp, 9, levels, error)
      call expect(error, 'fraction must be in (0, 1]', 'fraction 0')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 1.5_wp, 9, levels, error)
      call expect(error, 'fraction must be in (0, 1]', 'fraction 1.5')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, nan, 9, levels, error)
      call expect(error, 'fraction must be in (0, 1]', 'fraction NaN')
      if (allocated(error)) return
      call fraction_levels(leaf, [1.0_wp, 1.0_wp, nan], 0.5_wp, 9, levels, error)
      call expect(error, 'err_sq(3) = NaN', 'NaN estimate (fraction)')
      if (allocated(error)) return
      call fraction_levels(leaf, e2, 0.5_wp, -1, levels, error)
      call expect(error, 'max_level must be in [0', 'max_level < 0 (fraction)')
   end subroutine test_marking_bad_input

end module sprc_test_adapt
