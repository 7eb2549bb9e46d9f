!> Nested iteration (the first step of full multigrid): an iterative solve on
!> one grid starts from the FE displacement of the same body solved on
!> another grid of its study, instead of from zero.
!>
!> `fe_displacement_type` keeps what evaluating a solved displacement needs
!> (the grid's leaves, the elements' nodes, the nodal values: a few MB where
!> the problem holds hundreds) so that it can outlive its level; `values_at`
!> evaluates it at any points, e.g. the master nodes of the next level.
!>
!> Why it pays. The grids of a study are nested, so the coarse solution u_H
!> is a function of the fine space's neighbourhood: its energy distance to
!> the fine solution u_h is about the coarse FE error, ||u_h - u_H||_A /
!> ||u_h||_A ~ err_fe(H) (a few percent), where x = 0 starts at 1. CG then
!> needs about log(err_fe(H)) / log(rho) fewer iterations (rho the
!> convergence factor per iteration). The result is still the iterative
!> solve's to its tolerance (the stopping test measures the residual
!> reached, whatever the start), so the report keeps its six digits.
!>
!> Every point of a fine element lies in the closed box of a coarse leaf of
!> the same body (a fine cell that meets the body lies in a coarse cell
!> that does), but a node on the face between a coarse element and an
!> external cell may be located in the external one: then the point is
!> looked up again a quarter of the finest cell inside each cell around it,
!> and a point that no element holds (another body's grid) gets 0.
module sprc_fem_nested
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_grid_tree, only: grid_type
   use sprc_fem_element, only: shape_functions
   implicit none
   private

   public :: fe_displacement_type

   !> A solved FE displacement, independent of its problem (module notes).
   type :: fe_displacement_type
      !> Dimension and element degree; 0 when nothing is held.
      integer :: dim = 0, degree = 0
      type(grid_type) :: grid
      !> Nodes of each element (nodes per element, elements).
      integer, allocatable :: connectivity(:, :)
      !> Nodal displacements (dim, nodes).
      real(wp), allocatable :: u(:, :)
   contains
      procedure :: hold
      procedure :: values_at
   end type fe_displacement_type

contains

   !> Keep a copy of the displacement `u` of the elements `connectivity` on
   !> the leaves of `grid` (degree `degree`).
   subroutine hold(self, grid, degree, connectivity, u, error)
      class(fe_displacement_type), intent(inout) :: self
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: degree
      integer, intent(in) :: connectivity(:, :)
      real(wp), intent(in) :: u(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      self%dim = 0
      if (allocated(self%connectivity)) deallocate (self%connectivity)
      if (allocated(self%u)) deallocate (self%u)
      if (size(connectivity, 2) /= grid%n_leaves .or. size(u, 1) /= grid%dim) then
         call fatal_error(error, 'nested start: the elements or the displacement do not match the grid', &
            & stat_invalid_input)
         return
      end if
      call grid%copy(self%grid, error)
      if (allocated(error)) return
      allocate (self%connectivity, source=connectivity, stat=stat)
      if (stat == 0) allocate (self%u, source=u, stat=stat)
      call check_allocation(stat, 'nested start', 'the coarse displacement', size(u), 8 + 4*size(connectivity, 1), &
         & error)
      if (allocated(error)) return
      self%dim = grid%dim
      self%degree = degree
   end subroutine hold

   !> The held displacement at the points x(dim, n) into v(dim, n) (0 where
   !> no element holds the point; module notes). Nothing held: v = 0.
   subroutine values_at(self, x, v)
      class(fe_displacement_type), intent(in) :: self
      real(wp), intent(in) :: x(:, :)
      real(wp), intent(out) :: v(:, :)
      integer :: i, e

      v = 0.0_wp
      if (self%dim == 0 .or. size(x, 1) /= self%dim) return
      !$omp parallel do private(e) schedule(static)
      do i = 1, size(x, 2)
         e = holding_element(self, x(:, i))
         if (e > 0) call value_in(self, e, x(:, i), v(:, i))
      end do
      !$omp end parallel do
   end subroutine values_at

   !> The element that holds x: the leaf it is located in, or else the first
   !> leaf found a quarter of the finest cell from x towards one of the 2^dim
   !> cells around it; 0 when none.
   pure integer function holding_element(self, x) result(e)
      type(fe_displacement_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp) :: step, y(3)
      integer :: corner, k

      e = self%grid%locate_point(x)
      if (e > 0) return
      step = 0.25_wp*self%grid%box_size*0.5_wp**self%grid%max_level
      do corner = 0, 2**self%dim - 1
         do k = 1, self%dim
            y(k) = x(k) + merge(step, -step, btest(corner, k - 1))
         end do
         e = self%grid%locate_point(y(1:self%dim))
         if (e > 0) return
      end do
   end function holding_element

   !> The displacement v(dim) of element e's polynomial at x.
   pure subroutine value_in(self, e, x, v)
      type(fe_displacement_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      real(wp) :: lo(3), hi(3), n(size(self%connectivity, 1)), dndx(self%dim, size(self%connectivity, 1))
      integer :: j

      call self%grid%leaf_box(e, lo(1:self%dim), hi(1:self%dim))
      call shape_functions(self%dim, self%degree, lo(1:self%dim), hi(1:self%dim), x, n, dndx)
      v = 0.0_wp
      do j = 1, size(n)
         v = v + n(j)*self%u(:, self%connectivity(j, e))
      end do
   end subroutine value_in

end module sprc_fem_nested
