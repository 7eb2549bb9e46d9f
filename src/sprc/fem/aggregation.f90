!> Cell aggregation for small cut cells (AgFEM: Badia, Verdugo & Martin 2018;
!> doc/theory.md, section 4).
!>
!> A cell is well posed when it is inside the body, or cut with a volume
!> fraction |cell ∩ body| / |cell| >= eta. Every other (ill-posed) cell is
!> attached to a well-posed root: layer by layer, an ill-posed cell next
!> to a cell that already has a root takes that root (so a chain
!> of small cells ends in one well-posed cell). Neighbours across faces,
!> edges and corners count (a sliver may touch the rest of the body only at
!> an edge); among several candidates the root whose centre is nearest wins
!> (ties: lower leaf index), which prefers face neighbours and keeps
!> aggregates compact; the result is deterministic. The FE space then
!> constrains every dof that no well-posed cell supports to the root's
!> polynomial (`sprc_fem_constraints`).
!>
!> Threshold: `default_eta` = 0.3. Aggregation is what makes the condition
!> number and the Nitsche inverse inequality independent of how a cell is
!> cut; eta only trades how many cells are aggregated (extrapolation over at
!> most a few cell sizes, which keeps the optimal order) against the worst
!> ratio left in well-posed cells, which is 1/eta. Any value in 0.1..0.5 works;
!> 0.3 keeps aggregates to one or two cells on the example scenes.
module sprc_fem_aggregation
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_grid_tree, only: grid_type
   implicit none
   private

   public :: aggregate_cells, default_eta

   !> Default volume-fraction threshold of a well-posed cut cell (module notes).
   real(wp), parameter :: default_eta = 0.3_wp

contains

   !> Roots of the cells of `grid`: root(e) = e for a well-posed cell (fraction(e)
   !> >= eta or an inside cell, `inside(e)`), else the well-posed cell whose
   !> polynomial extends over e. Fails when an ill-posed cell has no face path to
   !> a well-posed one (a body made only of slivers).
   subroutine aggregate_cells(grid, inside, fraction, eta, root, error)
      type(grid_type), intent(in) :: grid
      logical, intent(in) :: inside(:)
      real(wp), intent(in) :: fraction(:), eta
      integer, allocatable, intent(out) :: root(:)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: next(:)
      integer :: e, n, d, k, first, last, nb, best, dir(3), stat
      real(wp) :: lo(3), hi(3), c(3), dist, best_dist
      logical :: changed
      character(len=400) :: buf

      n = grid%n_leaves
      d = grid%dim
      allocate (root(n), next(n), stat=stat)
      call check_allocation(stat, 'cell aggregation', 'the root of each cell', n, 8, error)
      if (allocated(error)) return
      do e = 1, n
         root(e) = 0
         if (inside(e) .or. fraction(e) >= eta) root(e) = e
      end do
      do
         changed = .false.
         next(:) = root
         do e = 1, n
            if (root(e) /= 0) cycle
            call grid%leaf_box(e, lo(1:d), hi(1:d))
            c(1:d) = 0.5_wp*(lo(1:d) + hi(1:d))
            best = 0
            best_dist = huge(1.0_wp)
            do k = 0, 3**d - 1
               dir = [mod(k, 3), mod(k/3, 3), k/9] - 1
               if (all(dir(1:d) == 0)) cycle
               call grid%neighbour(e, dir(1:d), first, last)
               do nb = first, last
                  if (root(nb) == 0) cycle
                  if (.not. touches(grid, e, nb, dir(1:d))) cycle
                  dist = centre_distance(grid, root(nb), c(1:d))
                  if (dist < best_dist .or. (dist == best_dist .and. root(nb) < best)) then
                     best = root(nb)
                     best_dist = dist
                  end if
               end do
            end do
            if (best /= 0) then
               next(e) = best
               changed = .true.
            end if
         end do
         root(:) = next
         if (.not. changed) exit
      end do
      do e = 1, n
         if (root(e) == 0) then
            write (buf, '("the body (or a part of it) is too thin for cells of this size: no cell of that part ", &
               & "is filled to ",i0,"% or more (cut cell ",i0," is filled to ",g0.2,"%), so the cut-cell ", &
               & "method has no cell to extend its small cuts from; raise the level, or refine_boundary, so that ", &
               & "the body spans whole cells")') nint(100*eta), e, 100*fraction(e)
            call fatal_error(error, trim(buf), stat_invalid_input)
            return
         end if
      end do
   end subroutine aggregate_cells

   !> True if leaf nb (from the neighbour cell of e in direction dir) touches e:
   !> along each axis with dir /= 0 their boxes meet, along the others they overlap.
   pure logical function touches(grid, e, nb, dir)
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: e, nb, dir(:)
      real(wp) :: lo(3), hi(3), nlo(3), nhi(3)
      integer :: d, m

      d = grid%dim
      call grid%leaf_box(e, lo(1:d), hi(1:d))
      call grid%leaf_box(nb, nlo(1:d), nhi(1:d))
      touches = .true.
      do m = 1, d
         select case (dir(m))
         case (1)
            touches = touches .and. nlo(m) == hi(m)
         case (-1)
            touches = touches .and. nhi(m) == lo(m)
         case default
            touches = touches .and. nlo(m) < hi(m) .and. nhi(m) > lo(m)
         end select
      end do
   end function touches

   pure real(wp) function centre_distance(grid, leaf, c) result(dist)
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: leaf
      real(wp), intent(in) :: c(:)
      real(wp) :: lo(3), hi(3)
      integer :: d
      d = grid%dim
      call grid%leaf_box(leaf, lo(1:d), hi(1:d))
      dist = norm2(0.5_wp*(lo(1:d) + hi(1:d)) - c)
   end function centre_distance

end module sprc_fem_aggregation
