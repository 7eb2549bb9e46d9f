!> The cut mesh of one body at one level: the body, its grid, the Q`degree`
!> nodes and hanging-node constraints on that grid, and the cut-cell
!> quadrature of every element (volume points, and boundary-surface points
!> with exact normals and shape index), built once and then read by
!> everything that works on that level (FE problem, contact surface,
!> recovery, output).
!>
!> ```fortran
!> call mesh%build(body, box_min, box_size, level, refine_boundary, degree, error)   ! t_mesh
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

   !> Quadrature of one element while the rules are computed in parallel.
   type :: rule_store_type
      integer :: nvol = 0, nsurf = 0
      real(wp), allocatable :: x(:, :), w(:), sx(:, :), sw(:), sn(:, :)
      integer, allocatable :: ss(:)
   end type rule_store_type

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
      if (.not. allocated(error)) call self%nodes%build(self%grid, degree, error)
      if (.not. allocated(error)) call self%hanging%build(self%grid, self%nodes, error)
      call timer%stop()
      self%t_mesh = timer%elapsed
   end subroutine mesh_build

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
      call integrate(self, range, error)
      call timer%stop()
      self%t_quadrature = timer%elapsed
   end subroutine mesh_integrate

   !> The rules of all cells in parallel (a cut cell's kept in `store`, an inside cell
   !> without boundary points only counted), then the points of every cell copied (or,
   !> for such an inside cell, generated: the tensor rule, as `cell_rule` gives it) to
   !> the places its index fixes, again in parallel: no serial pass over the points,
   !> and no allocation for most cells.
   subroutine integrate(self, range, error)
      type(cut_mesh_type), intent(inout) :: self
      integer, intent(in) :: range(2)
      type(error_type), allocatable, intent(out) :: error
      type(rule_store_type), allocatable :: store(:)
      type(cell_rule_type) :: rule
      type(error_type), allocatable :: cell_error
      logical, allocatable :: failed(:)
      integer, allocatable :: stats(:)
      integer :: e, n, d, stat
      real(wp) :: lo(3), hi(3)
      character(len=*), parameter :: who = 'cut mesh quadrature'

      n = self%grid%n_leaves
      d = self%grid%dim
      allocate (store(n), failed(n), stats(n), stat=stat)
      call check_allocation(stat, who, 'the quadrature rule of each cell', n, storage_size(store)/8 + 8, error)
      if (allocated(error)) return
      failed = .false.
      stats = 0
      !$omp parallel do schedule(dynamic, 16) default(shared) private(e, rule, cell_error, lo, hi)
      do e = range(1), range(2)
         call self%grid%leaf_box(e, lo(1:d), hi(1:d))
         call cell_rule(self%quad, self%body, lo(1:d), hi(1:d), rule, cell_error)
         if (allocated(cell_error)) then
            failed(e) = .true.
            cycle
         end if
         call keep_rule(rule, d, tensor_only(rule, self%quad), store(e), stats(e))
      end do
      !$omp end parallel do
      if (any(failed)) then
         e = findloc(failed, .true., 1)
         call self%grid%leaf_box(e, lo(1:d), hi(1:d))
         call cell_rule(self%quad, self%body, lo(1:d), hi(1:d), rule, error)
         return
      end if
      if (any(stats /= 0)) then
         e = findloc(stats /= 0, .true., 1)
         call check_allocation(stats(e), who, 'the quadrature points of cell '//itoa(e - 1)// &
            & ' (coordinates, weights, normals)', store(e)%nvol*(d + 1) + store(e)%nsurf*(2*d + 1), 8, error)
         return
      end if
      call gather_points(self, store, error)
      if (allocated(error)) return
      self%n_cut = count(self%grid%leaf_class /= cell_inside)
   end subroutine integrate

   !> Whether `rule` is the plain tensor rule of its cell: an inside cell without
   !> boundary points on its faces.
   pure logical function tensor_only(rule, quad)
      type(cell_rule_type), intent(in) :: rule
      type(cut_quadrature_type), intent(in) :: quad
      tensor_only = rule%cls == cell_inside .and. rule%nsurf == 0 .and. rule%nvol == quad%q**quad%dim
   end function tensor_only

   !> The points of all cells, concatenated in cell order (pointers from the counts, then
   !> each cell's points to its places in parallel), and the volume fractions.
   subroutine gather_points(self, store, error)
      type(cut_mesh_type), intent(inout) :: self
      type(rule_store_type), intent(inout) :: store(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: e, n, d, nv, ns, iv, is, k, stat
      real(wp) :: lo(3), hi(3)
      character(len=*), parameter :: who = 'cut mesh quadrature'

      n = size(store)
      d = self%grid%dim
      allocate (self%vol_ptr(n + 1), self%surf_ptr(n + 1), self%fraction(n), stat=stat)
      call check_allocation(stat, who, 'the quadrature pointers and volume fractions', n + 1, 16, error)
      if (allocated(error)) return
      self%vol_ptr(1) = 1
      self%surf_ptr(1) = 1
      do e = 1, n
         self%vol_ptr(e + 1) = self%vol_ptr(e) + store(e)%nvol
         self%surf_ptr(e + 1) = self%surf_ptr(e) + store(e)%nsurf
      end do
      nv = self%vol_ptr(n + 1) - 1
      ns = self%surf_ptr(n + 1) - 1
      allocate (self%vol_x(d, nv), self%vol_w(nv), stat=stat)
      call check_allocation(stat, who, 'the volume quadrature points', nv, 8*(d + 1), error)
      if (allocated(error)) return
      allocate (self%surf_x(d, ns), self%surf_w(ns), self%surf_n(d, ns), self%surf_shape(ns), stat=stat)
      call check_allocation(stat, who, 'the surface quadrature points', ns, 8*(2*d + 1) + 4, error)
      if (allocated(error)) return
      !$omp parallel do schedule(dynamic, 64) default(shared) private(e, iv, is, k, lo, hi)
      do e = 1, n
         iv = self%vol_ptr(e) - 1
         is = self%surf_ptr(e) - 1
         call self%grid%leaf_box(e, lo(1:d), hi(1:d))
         if (allocated(store(e)%w)) then
            self%vol_x(:, iv + 1:iv + store(e)%nvol) = store(e)%x
            self%vol_w(iv + 1:iv + store(e)%nvol) = store(e)%w
            self%surf_x(:, is + 1:is + store(e)%nsurf) = store(e)%sx
            self%surf_w(is + 1:is + store(e)%nsurf) = store(e)%sw
            self%surf_n(:, is + 1:is + store(e)%nsurf) = store(e)%sn
            self%surf_shape(is + 1:is + store(e)%nsurf) = store(e)%ss
            deallocate (store(e)%x, store(e)%w, store(e)%sx, store(e)%sw, store(e)%sn, store(e)%ss)
         else
            do k = 1, store(e)%nvol
               call tensor_point(self%quad, lo(1:d), hi(1:d), k, self%vol_x(:, iv + k), self%vol_w(iv + k))
            end do
         end if
         self%fraction(e) = sum(self%vol_w(iv + 1:iv + store(e)%nvol))/product(hi(1:d) - lo(1:d))
      end do
      !$omp end parallel do
   end subroutine gather_points

   !> `store` = the points of `rule` (dimension d), or only their counts when `counts_only`
   !> (the tensor rule, generated again by `gather_points`); `stat` nonzero when an array
   !> could not be allocated (the points of all cells together grow with the grid).
   pure subroutine keep_rule(rule, d, counts_only, store, stat)
      type(cell_rule_type), intent(in) :: rule
      integer, intent(in) :: d
      logical, intent(in) :: counts_only
      type(rule_store_type), intent(inout) :: store
      integer, intent(out) :: stat

      store%nvol = rule%nvol
      store%nsurf = rule%nsurf
      stat = 0
      if (counts_only) return
      allocate (store%x, source=rule%vol_x(1:d, 1:rule%nvol), stat=stat)
      if (stat == 0) allocate (store%w, source=rule%vol_w(1:rule%nvol), stat=stat)
      if (stat == 0) allocate (store%sx, source=rule%surf_x(1:d, 1:rule%nsurf), stat=stat)
      if (stat == 0) allocate (store%sw, source=rule%surf_w(1:rule%nsurf), stat=stat)
      if (stat == 0) allocate (store%sn, source=rule%surf_n(1:d, 1:rule%nsurf), stat=stat)
      if (stat == 0) allocate (store%ss, source=rule%surf_shape(1:rule%nsurf), stat=stat)
   end subroutine keep_rule

end module sprc_grid_cut_mesh
