!> The cut mesh of one body at one level: the body, its grid, the Q`degree`
!> nodes and hanging-node constraints on that grid, and the cut-cell
!> quadrature of every element (volume points, and boundary-surface points
!> with exact normals and shape index), built once and then read by
!> everything that works on that level (FE problem, contact surface,
!> recovery, output).
!>
!> ```fortran
!> call mesh%build(body, box_min, box_size, level, refine_boundary, degree, error)   ! t_mesh
!> call mesh%build_adapted(body, old_grid, target, max_level, degree, error)         ! t_mesh
!> call mesh%integrate(quad, error)                                                   ! t_quadrature
!> ```
!> The FE problem (`sprc_fem_problem`) takes the mesh over (`move_alloc`, no
!> copy) and exposes it as `problem%mesh`.
module sprc_grid_cut_mesh
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_core_timer, only: timer_type
   use sprc_geometry_body, only: body_type
   use sprc_geometry_region, only: cell_inside
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   use sprc_grid_quadrature, only: cut_quadrature_type, cell_rule_type, cell_rule, tensor_point
   implicit none
   private

   public :: cut_mesh_type

   !> Cells per block of `integrate`: the unit of scheduling, and of storage for the points
   !> of the cells that are not tensor cells.
   integer, parameter :: block_cells = 64

   character(len=*), parameter :: who = 'cut mesh quadrature'

   !> The points of one cell that is not a tensor cell, while the rules are computed in parallel.
   type :: rule_store_type
      real(wp), allocatable :: x(:, :), w(:), sx(:, :), sw(:), sn(:, :)
      integer, allocatable :: ss(:)
   end type rule_store_type

   !> The kept points of the cells of one block (`cell(k)`: its k-th cell), allocated
   !> when the block has a cell that is not a tensor cell.
   type :: block_store_type
      type(rule_store_type), allocatable :: cell(:)
   end type block_store_type

   !> One body's cut mesh at one level (module notes).
   type :: cut_mesh_type
      !> The body that cuts the grid; the settings of the cell rules (`integrate`).
      type(body_type) :: body
      type(cut_quadrature_type) :: quad
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hanging
      !> Volume points of element e: vol_x(:, vol_ptr(e) : vol_ptr(e+1)-1), weights w|J| in vol_w.
      integer, allocatable :: vol_ptr(:)
      real(wp), allocatable :: vol_x(:, :), vol_w(:)
      !> Surface points: coordinates, weights, unit outward normals, shape index.
      integer, allocatable :: surf_ptr(:)
      real(wp), allocatable :: surf_x(:, :), surf_w(:), surf_n(:, :)
      integer, allocatable :: surf_shape(:)
      !> Volume fraction of each element.
      real(wp), allocatable :: fraction(:)
      !> Cut elements.
      integer :: n_cut = 0
      !> Wall-clock seconds to build grid, nodes and constraints, and the cell rules.
      real(wp) :: t_mesh = 0.0_wp, t_quadrature = 0.0_wp
   contains
      procedure :: build => mesh_build
      procedure :: build_adapted => mesh_build_adapted
      procedure :: integrate => mesh_integrate
   end type cut_mesh_type

contains

   !> The grid of `body` (uniform `level`, `refine_boundary` extra levels on
   !> cut cells, level-0 cell at `box_min` of edge `box_size`), its
   !> Q`degree` nodes and hanging-node constraints (t_mesh). The rules come
   !> with `integrate`.
   subroutine mesh_build(self, body, box_min, box_size, level, refine_boundary, degree, error)
      class(cut_mesh_type), intent(out) :: self
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: box_min(:), box_size
      integer, intent(in) :: level, refine_boundary, degree
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer

      self%body = body
      call timer%start()
      call self%grid%build(body, body%dim, box_min, box_size, level, refine_boundary, error)
      call complete_mesh(self, degree, timer, error)
   end subroutine mesh_build

   !> The grid of `body` adapted from `old` (`grid_type%build_adapted`: the level
   !> `target(j)` wanted where old leaf j was, at most `max_level`, same box), its
   !> Q`degree` nodes and hanging-node constraints (t_mesh). `old` must not be
   !> this mesh's own grid.
   subroutine mesh_build_adapted(self, body, old, target, max_level, degree, error)
      class(cut_mesh_type), intent(out) :: self
      type(body_type), intent(in) :: body
      type(grid_type), intent(in) :: old
      integer, intent(in) :: target(:), max_level, degree
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: timer

      self%body = body
      call timer%start()
      call self%grid%build_adapted(body, old, target, max_level, error)
      call complete_mesh(self, degree, timer, error)
   end subroutine mesh_build_adapted

   !> Nodes and constraints on the grid just built (unless `error` says it failed),
   !> then the time since `timer` started into t_mesh.
   subroutine complete_mesh(self, degree, timer, error)
      type(cut_mesh_type), intent(inout) :: self
      integer, intent(in) :: degree
      type(timer_type), intent(inout) :: timer
      type(error_type), allocatable, intent(inout) :: error

      if (.not. allocated(error)) call self%nodes%build(self%grid, degree, error)
      if (.not. allocated(error)) call self%hanging%build(self%grid, self%nodes, error)
      call timer%stop()
      self%t_mesh = timer%elapsed
   end subroutine complete_mesh

   !> Cut-cell quadrature of every element with the settings `quad` (parallel,
   !> one rule object per thread), concatenated in element order; volume
   !> fractions (t_quadrature). After `build`. With `cells` = [first, last],
   !> only the elements first..last get their rules (a rank's share of a
   !> partitioned level, `sprc_study_partition`); the others get no points
   !> and fraction 0 until the shares are gathered.
   subroutine mesh_integrate(self, quad, error, cells)
      class(cut_mesh_type), intent(inout) :: self
      type(cut_quadrature_type), intent(in) :: quad
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: cells(2)
      type(timer_type) :: timer
      integer :: range(2)

      self%quad = quad
      range = [1, self%grid%n_leaves]
      if (present(cells)) range = [max(cells(1), 1), min(cells(2), self%grid%n_leaves)]
      call timer%start()
      call drop_rules(self)
      call integrate(self, range, error)
      ! a mesh whose rules failed has none (what setup checks), and may be integrated again
      if (allocated(error)) call drop_rules(self)
      call timer%stop()
      self%t_quadrature = timer%elapsed
   end subroutine mesh_integrate

   !> Forget the cell rules (pointers, points, fractions), if any.
   subroutine drop_rules(self)
      type(cut_mesh_type), intent(inout) :: self
      if (allocated(self%vol_ptr)) deallocate (self%vol_ptr)
      if (allocated(self%surf_ptr)) deallocate (self%surf_ptr)
      if (allocated(self%fraction)) deallocate (self%fraction)
      if (allocated(self%vol_x)) deallocate (self%vol_x)
      if (allocated(self%vol_w)) deallocate (self%vol_w)
      if (allocated(self%surf_x)) deallocate (self%surf_x)
      if (allocated(self%surf_w)) deallocate (self%surf_w)
      if (allocated(self%surf_n)) deallocate (self%surf_n)
      if (allocated(self%surf_shape)) deallocate (self%surf_shape)
      self%n_cut = 0
   end subroutine drop_rules

   !> The rules of all cells in parallel, a block of `block_cells` consecutive cells at a
   !> time: each cell's point counts go straight to its place in the pointers, and only a
   !> cell whose rule is not the tensor rule of its cell (a cut cell, or an inside cell with
   !> boundary points on its faces) keeps its points, in its block's store, allocated by
   !> the thread that computes the block. Then the points of every cell are copied (or,
   !> for a tensor cell, generated: the rule as `cell_rule` gives it) to the places its
   !> index fixes, again in parallel. No serial pass over the cells but the sum of the
   !> counts: nothing is allocated or initialised per cell for the tensor cells, which
   !> are most of a level (a store per cell, allocated and freed serially, took as long
   !> as computing the rules).
   subroutine integrate(self, range, error)
      type(cut_mesh_type), intent(inout) :: self
      integer, intent(in) :: range(2)
      type(error_type), allocatable, intent(out) :: error
      type(block_store_type), allocatable :: store(:)
      type(cell_rule_type) :: rule
      integer, allocatable :: bad(:), stats(:)
      integer :: b, e, n, d, nb, stat
      real(wp) :: lo(3), hi(3)

      n = self%grid%n_leaves
      d = self%grid%dim
      nb = (n + block_cells - 1)/block_cells
      allocate (store(nb), bad(nb), stats(nb), self%vol_ptr(n + 1), self%surf_ptr(n + 1), self%fraction(n), &
         & stat=stat)
      call check_allocation(stat, who, 'the quadrature pointers and volume fractions', n + 1, 16, error)
      if (allocated(error)) return
      !$omp parallel do schedule(dynamic, 1) default(shared) private(b, rule)
      do b = 1, nb
         call block_rules(self, b, range, rule, store(b), bad(b), stats(b))
      end do
      !$omp end parallel do
      if (any(bad /= 0)) then
         b = findloc(bad /= 0, .true., 1)
         e = bad(b)
         if (stats(b) /= 0) then
            call check_allocation(stats(b), who, 'the quadrature points of cell '//itoa(e - 1)// &
               & ' (coordinates, weights, normals)', self%vol_ptr(e + 1)*(d + 1) + self%surf_ptr(e + 1)*(2*d + 1), &
               & 8, error)
            return
         end if
         call self%grid%leaf_box(e, lo(1:d), hi(1:d))
         call cell_rule(self%quad, self%body, lo(1:d), hi(1:d), rule, error)
         return
      end if
      call gather_points(self, store, error)
      if (allocated(error)) return
      self%n_cut = count(self%grid%leaf_class /= cell_inside)
   end subroutine integrate

   !> The rules of the cells of block b (those in `range`; the others get no points):
   !> their counts in vol_ptr(e + 1), surf_ptr(e + 1), the points of those that are not
   !> tensor cells in `store`. bad = the first cell whose rule failed (0: none), with
   !> `stat` nonzero when its points could not be kept.
   subroutine block_rules(self, b, range, rule, store, bad, stat)
      type(cut_mesh_type), intent(inout) :: self
      integer, intent(in) :: b, range(2)
      type(cell_rule_type), intent(inout) :: rule
      type(block_store_type), intent(inout) :: store
      integer, intent(out) :: bad, stat
      type(error_type), allocatable :: cell_error
      integer :: e, first, d
      real(wp) :: lo(3), hi(3)

      d = self%grid%dim
      first = (b - 1)*block_cells + 1
      bad = 0
      stat = 0
      do e = first, min(b*block_cells, self%grid%n_leaves)
         self%vol_ptr(e + 1) = 0
         self%surf_ptr(e + 1) = 0
         if (e < range(1) .or. e > range(2)) cycle
         call self%grid%leaf_box(e, lo(1:d), hi(1:d))
         call cell_rule(self%quad, self%body, lo(1:d), hi(1:d), rule, cell_error)
         if (allocated(cell_error)) then
            bad = e
            return
         end if
         self%vol_ptr(e + 1) = rule%nvol
         self%surf_ptr(e + 1) = rule%nsurf
         if (tensor_only(rule, self%quad) .or. rule%nvol + rule%nsurf == 0) cycle
         if (.not. allocated(store%cell)) allocate (store%cell(block_cells), stat=stat)
         if (stat == 0) call keep_rule(rule, d, store%cell(e - first + 1), stat)
         if (stat /= 0) then
            bad = e
            return
         end if
      end do
   end subroutine block_rules

   !> Whether `rule` is the plain tensor rule of its cell: an inside cell without
   !> boundary points on its faces.
   pure logical function tensor_only(rule, quad)
      type(cell_rule_type), intent(in) :: rule
      type(cut_quadrature_type), intent(in) :: quad
      tensor_only = rule%cls == cell_inside .and. rule%nsurf == 0 .and. rule%nvol == quad%q**quad%dim
   end function tensor_only

   !> The points of all cells, concatenated in cell order (pointers from the counts, then
   !> each block's points to their places in parallel), and the volume fractions.
   subroutine gather_points(self, store, error)
      type(cut_mesh_type), intent(inout) :: self
      type(block_store_type), intent(inout) :: store(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: b, e, n, d, nv, ns, stat

      n = self%grid%n_leaves
      d = self%grid%dim
      self%vol_ptr(1) = 1
      self%surf_ptr(1) = 1
      do e = 1, n
         self%vol_ptr(e + 1) = self%vol_ptr(e) + self%vol_ptr(e + 1)
         self%surf_ptr(e + 1) = self%surf_ptr(e) + self%surf_ptr(e + 1)
      end do
      nv = self%vol_ptr(n + 1) - 1
      ns = self%surf_ptr(n + 1) - 1
      allocate (self%vol_x(d, nv), self%vol_w(nv), stat=stat)
      call check_allocation(stat, who, 'the volume quadrature points', nv, 8*(d + 1), error)
      if (allocated(error)) return
      allocate (self%surf_x(d, ns), self%surf_w(ns), self%surf_n(d, ns), self%surf_shape(ns), stat=stat)
      call check_allocation(stat, who, 'the surface quadrature points', ns, 8*(2*d + 1) + 4, error)
      if (allocated(error)) return
      !$omp parallel do schedule(dynamic, 1) default(shared) private(b)
      do b = 1, size(store)
         call block_points(self, b, store(b))
      end do
      !$omp end parallel do
   end subroutine gather_points

   !> The points and volume fractions of the cells of block b (pointers set); the
   !> block's store is freed.
   subroutine block_points(self, b, store)
      type(cut_mesh_type), intent(inout) :: self
      integer, intent(in) :: b
      type(block_store_type), intent(inout) :: store
      integer :: e, first, d, iv, is, nvol, nsurf, k
      real(wp) :: lo(3), hi(3)

      d = self%grid%dim
      first = (b - 1)*block_cells + 1
      do e = first, min(b*block_cells, self%grid%n_leaves)
         iv = self%vol_ptr(e) - 1
         is = self%surf_ptr(e) - 1
         nvol = self%vol_ptr(e + 1) - 1 - iv
         nsurf = self%surf_ptr(e + 1) - 1 - is
         call self%grid%leaf_box(e, lo(1:d), hi(1:d))
         if (kept(store, e - first + 1)) then
            associate (cell => store%cell(e - first + 1))
               self%vol_x(:, iv + 1:iv + nvol) = cell%x
               self%vol_w(iv + 1:iv + nvol) = cell%w
               self%surf_x(:, is + 1:is + nsurf) = cell%sx
               self%surf_w(is + 1:is + nsurf) = cell%sw
               self%surf_n(:, is + 1:is + nsurf) = cell%sn
               self%surf_shape(is + 1:is + nsurf) = cell%ss
            end associate
         else
            do k = 1, nvol
               call tensor_point(self%quad, lo(1:d), hi(1:d), k, self%vol_x(:, iv + k), self%vol_w(iv + k))
            end do
         end if
         self%fraction(e) = sum(self%vol_w(iv + 1:iv + nvol))/product(hi(1:d) - lo(1:d))
      end do
      if (allocated(store%cell)) deallocate (store%cell)
   end subroutine block_points

   !> Whether cell k of a block has its points in the block's store.
   pure logical function kept(store, k)
      type(block_store_type), intent(in) :: store
      integer, intent(in) :: k
      kept = .false.
      if (allocated(store%cell)) kept = allocated(store%cell(k)%w)
   end function kept

   !> `store` = the points of `rule` (dimension d); `stat` nonzero when an array could
   !> not be allocated (the points of all cells together grow with the grid).
   pure subroutine keep_rule(rule, d, store, stat)
      type(cell_rule_type), intent(in) :: rule
      integer, intent(in) :: d
      type(rule_store_type), intent(inout) :: store
      integer, intent(out) :: stat

      allocate (store%x, source=rule%vol_x(1:d, 1:rule%nvol), stat=stat)
      if (stat == 0) allocate (store%w, source=rule%vol_w(1:rule%nvol), stat=stat)
      if (stat == 0) allocate (store%sx, source=rule%surf_x(1:d, 1:rule%nsurf), stat=stat)
      if (stat == 0) allocate (store%sw, source=rule%surf_w(1:rule%nsurf), stat=stat)
      if (stat == 0) allocate (store%sn, source=rule%surf_n(1:d, 1:rule%nsurf), stat=stat)
      if (stat == 0) allocate (store%ss, source=rule%surf_shape(1:rule%nsurf), stat=stat)
   end subroutine keep_rule

end module sprc_grid_cut_mesh
