!> The contact surface of a slave/master pair: the slave surface's quadrature
!> points and, for each, the initial gap to the master surface (thesis eq. 3,
!> doc/scene.md `&contact`).
!>
!> Slave points are the surface points of the cut-cell rules
!> (sprc_grid_quadrature) on the slave surface: coordinates, weights (surface
!> measure) and exact unit outward normals of the slave body, with the slave
!> leaf that produced them. `slave_surface_points` builds them from the slave
!> grid; `new_contact_surface` takes them from a caller that already has them.
!>
!> Gap (`initial_gaps`): the line through a slave point x_s along its normal
!> n_s is intersected with the master surface on the master body's exact
!> implicit geometry (sprc_contact_ray; a faceted surface by ray-facet
!> intersection through its facet hierarchy). If x_s lies outside the master body
!> the crossing is sought ahead, t in [-margin, L]; if inside (the shapes
!> overlap) behind, t in [-L, margin]; L = `search_distance`, margin four
!> times the distance that the side test's tolerance stands for (tol over
!> |grad phi|, plus a few ulps), so that touching surfaces (g0 = 0) are found
!> from either side. Only crossings where the
!> master surface faces the slave one (n_s . n_m <= 0) and bounds the master
!> body count. Then g0 = t: positive for a gap, negative for an interference
!> (shrink) fit; small deformations linearize g = g0 + (u_m - u_s).n_s. A point
!> whose line meets no such crossing within L is open: `has_master` false, no
!> master point, g0 = huge. `g0_tolerance` bounds |g0 - g0_exact| (the root
!> finder's stopping test and the level-set rounding). `linearized_gap`
!> adds the displacements: g = g0 + (u_m - u_s).n_s.
!>
!> The master point's host cell is the master-grid leaf containing it; a
!> point on a leaf face that the floor convention of `locate_point` would give
!> to the external neighbour is nudged into the master body by a few ulps.
module sprc_contact_surface
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_not_converged
   use sprc_core_alloc, only: check_allocation
   use sprc_geometry_body, only: body_type, snap_tolerance, body_name
   use sprc_grid_tree, only: grid_type
   use sprc_grid_quadrature, only: cut_quadrature_type, cell_rule_type, cell_rule, boundary_face_rule
   use sprc_geometry_region, only: cell_inside
   use sprc_contact_ray, only: ray_hit_type, nearest_crossing, facet_crossing, position_tolerance
   use sprc_geometry_shape, only: shape_facets
   implicit none
   private

   public :: contact_surface_type, new_contact_surface, slave_surface_points, initial_gaps, linearized_gap

   !> Split planes along one axis.
   type :: planes_type
      real(wp), allocatable :: p(:)
   end type planes_type

   !> Slave-surface points and their initial gaps.
   type :: contact_surface_type
      !> Space dimension and number of slave points.
      integer :: dim = 0, npoint = 0
      !> Coordinates (dim, npoint), weights (npoint), unit outward normals (dim, npoint).
      real(wp), allocatable :: x(:, :), weight(:), normal(:, :)
      !> Leaf of the slave grid holding each point (0 if not known).
      integer, allocatable :: slave_cell(:)
      !> Set by `initial_gaps`: the point's line meets the master surface.
      logical, allocatable :: has_master(:)
      !> Initial gap g0 (huge when open) and a bound on its error.
      real(wp), allocatable :: g0(:), g0_tolerance(:)
      !> Master point and the master body's outward unit normal there (dim, npoint; zero when open).
      real(wp), allocatable :: master_x(:, :), master_normal(:, :)
      !> Leaf of the master grid holding the master point (0 when open).
      integer, allocatable :: master_cell(:)
   end type contact_surface_type

contains

   !> A contact surface from given slave points. `slave_cell` may be empty
   !> (cells unknown). Errors name the first bad point (1-based).
   subroutine new_contact_surface(self, x, weight, normal, slave_cell, error)
      type(contact_surface_type), intent(out) :: self
      real(wp), intent(in) :: x(:, :), weight(:), normal(:, :)
      integer, intent(in) :: slave_cell(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: d, n, i, stat

      d = size(x, 1)
      n = size(x, 2)
      if (d /= 2 .and. d /= 3) then
         call fatal_error(error, 'contact surface: points have '//itoa(d)//' coordinates, expected 2 or 3')
         return
      end if
      if (size(weight) /= n .or. any(shape(normal) /= [d, n]) .or. (size(slave_cell) /= n .and. &
         & size(slave_cell) /= 0)) then
         call fatal_error(error, 'contact surface: '//itoa(n)//' points but '//itoa(size(weight))// &
            & ' weights, '//itoa(size(normal, 2))//' normals of size '//itoa(size(normal, 1))//', '// &
            & itoa(size(slave_cell))//' cells')
         return
      end if
      do i = 1, n
         if (.not. (all(abs(x(:, i)) <= huge(1.0_wp)) .and. weight(i) > 0.0_wp .and. weight(i) <= huge(1.0_wp))) then
            call fatal_error(error, 'contact surface: point '//itoa(i)//' has a non-finite coordinate or a '// &
               & 'weight that is not finite and > 0')
            return
         end if
         ! Normals come normalized from the geometry: round-off only.
         if (.not. abs(norm2(normal(:, i)) - 1.0_wp) <= 64.0_wp*epsilon(1.0_wp)) then
            call fatal_error(error, 'contact surface: the normal of point '//itoa(i)//' is not a unit vector')
            return
         end if
      end do
      self%dim = d
      self%npoint = n
      allocate (self%x, source=x, stat=stat)
      if (stat == 0) allocate (self%weight, source=weight, stat=stat)
      if (stat == 0) allocate (self%normal, source=normal, stat=stat)
      if (stat == 0 .and. size(slave_cell) == n) then
         allocate (self%slave_cell, source=slave_cell, stat=stat)
      else if (stat == 0) then
         allocate (self%slave_cell(n), source=0, stat=stat)
      end if
      call check_allocation(stat, 'contact surface', 'its points', n, 8*(2*d + 1) + 4, error)
   end subroutine new_contact_surface

   !> The surface points of surface `surface` of `body` (a surface id,
   !> sprc_geometry_body: a shape's whole surface with its facet groups, or one
   !> group) from the cut-cell rules of every leaf of its grid, in leaf order. With `split_grid` (the master
   !> body's grid) each leaf holding such points is cut into sub-boxes at the
   !> planes of that grid's finest lattice (every master leaf face lies on
   !> one), and the rules are taken on the sub-boxes: then no part of the
   !> slave surface between two points straddles a master cell face where the
   !> surfaces touch, and a master displacement piecewise polynomial over the
   !> master cells is integrated exactly (the contact patch test; without it
   !> the Gauss points of a slave cell integrate across the master's kinks).
   subroutine slave_surface_points(self, grid, body, quad, surface, error, split_grid)
      type(contact_surface_type), intent(out) :: self
      type(grid_type), intent(in) :: grid
      type(body_type), intent(in) :: body
      type(cut_quadrature_type), intent(in) :: quad
      integer, intent(in) :: surface
      type(error_type), allocatable, intent(out) :: error
      type(grid_type), intent(in), optional :: split_grid
      type(cell_rule_type) :: rule
      real(wp), allocatable :: x(:, :), w(:), nrm(:, :)
      integer, allocatable :: cell(:)
      real(wp) :: lo(3), hi(3), sub_lo(3), sub_hi(3)
      type(planes_type) :: planes(3)
      integer :: leaf, n, d, j(3), k, stat

      if (surface < 1 .or. surface > body%nsurface()) then
         call fatal_error(error, "contact surface: surface "//itoa(surface)//" of body '"//body_name(body)// &
            & "' does not exist (it has "//itoa(body%nsurface())//')')
         return
      end if
      d = grid%dim
      n = 0
      allocate (x(d, 64), w(64), nrm(d, 64), cell(64), stat=stat)
      call check_allocation(stat, 'contact surface', 'its points', 64, 8*(2*d + 1) + 4, error)
      if (allocated(error)) return
      do leaf = 1, grid%n_leaves
         call grid%leaf_box(leaf, lo(1:d), hi(1:d))
         call leaf_rule(grid%leaf_class(leaf) == cell_inside, lo(1:d), hi(1:d), rule, error)
         if (allocated(error)) return
         if (.not. any(on_shape(rule%surf_shape(1:rule%nsurf)))) cycle
         if (.not. present(split_grid)) then
            call collect(leaf, rule)
            cycle
         end if
         do k = 1, d
            call lattice_planes(split_grid, k, lo(k), hi(k), planes(k)%p)
         end do
         j = 1
         do
            do k = 1, d
               sub_lo(k) = planes(k)%p(j(k))
               sub_hi(k) = planes(k)%p(j(k) + 1)
            end do
            call leaf_rule(grid%leaf_class(leaf) == cell_inside, sub_lo(1:d), sub_hi(1:d), rule, error)
            if (allocated(error)) return
            call collect(leaf, rule)
            ! next sub-box (odometer over the dimensions)
            k = 1
            do while (k <= d)
               j(k) = j(k) + 1
               if (j(k) < size(planes(k)%p)) exit
               j(k) = 1
               k = k + 1
            end do
            if (k > d) exit
         end do
      end do
      if (n == 0) then
         call fatal_error(error, "contact surface: surface '"//body%surface_name(surface)//"' of body '"// &
            & body_name(body)//"' has no quadrature points on the grid (it does not bound the body)")
         return
      end if
      call new_contact_surface(self, x(:, 1:n), w(1:n), nrm(:, 1:n), cell(1:n), error)
   contains
      !> The rule of a box of a leaf: an inside leaf has surface points only on
      !> grid-plane boundaries, so its volume rule is skipped.
      subroutine leaf_rule(inside, lo, hi, rule, error)
         logical, intent(in) :: inside
         real(wp), intent(in) :: lo(:), hi(:)
         type(cell_rule_type), intent(inout) :: rule
         type(error_type), allocatable, intent(out) :: error
         if (inside) then
            call boundary_face_rule(quad, body, lo, hi, rule, error)
         else
            call cell_rule(quad, body, lo, hi, rule, error)
         end if
         if (allocated(error)) error%message = 'contact surface, leaf '//itoa(leaf)//': '//error%message
      end subroutine leaf_rule

      !> Is a point of surface id on the contact surface?
      elemental logical function on_shape(id)
         integer, intent(in) :: id
         on_shape = body%surface_part(surface, id)
      end function on_shape

      subroutine collect(leaf, rule)
         integer, intent(in) :: leaf
         type(cell_rule_type), intent(in) :: rule
         integer :: q
         do q = 1, rule%nsurf
            if (.not. on_shape(rule%surf_shape(q))) cycle
            if (n == size(w)) call grow(x, w, nrm, cell, error)
            if (allocated(error)) return
            n = n + 1
            x(:, n) = rule%surf_x(1:d, q)
            w(n) = rule%surf_w(q)
            nrm(:, n) = rule%surf_n(1:d, q)
            cell(n) = leaf
         end do
      end subroutine collect
   end subroutine slave_surface_points

   !> lo, the planes of `grid`'s finest lattice along axis k strictly inside
   !> (lo, hi) (farther than a relative 1e-9 of the lattice step from both, so
   !> no sliver boxes), and hi.
   pure subroutine lattice_planes(grid, k, lo, hi, p)
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: k
      real(wp), intent(in) :: lo, hi
      real(wp), allocatable, intent(out) :: p(:)
      real(wp) :: step, c, margin
      integer :: i, i0, i1

      step = grid%box_size/real(2, wp)**grid%max_level
      margin = 1.0e-9_wp*step
      i0 = ceiling((lo - grid%box_min(k))/step)
      i1 = floor((hi - grid%box_min(k))/step)
      p = [lo]
      do i = i0, i1
         c = grid%box_min(k) + real(i, wp)*step
         if (c > lo + margin .and. c < hi - margin) p = [p, c]
      end do
      p = [p, hi]
   end subroutine lattice_planes

   subroutine grow(x, w, nrm, cell, error)
      real(wp), allocatable, intent(inout) :: x(:, :), w(:), nrm(:, :)
      integer, allocatable, intent(inout) :: cell(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: x2(:, :), w2(:), n2(:, :)
      integer, allocatable :: c2(:)
      integer :: m, stat

      m = size(w)
      allocate (x2(size(x, 1), 2*m), w2(2*m), n2(size(x, 1), 2*m), c2(2*m), stat=stat)
      call check_allocation(stat, 'contact surface', 'its points', 2*m, 8*(2*size(x, 1) + 1) + 4, error)
      if (allocated(error)) return
      x2(:, 1:m) = x
      w2(1:m) = w
      n2(:, 1:m) = nrm
      c2(1:m) = cell
      call move_alloc(x2, x)
      call move_alloc(w2, w)
      call move_alloc(n2, nrm)
      call move_alloc(c2, cell)
   end subroutine grow

   !> Initial gaps of every slave point to surface `surface` of `master` (a
   !> surface id as for `slave_surface_points`; module notes), searched up to
   !> `search_distance` along the normal; master points located in `master_grid`.
   subroutine initial_gaps(self, master, surface, master_grid, search_distance, error)
      type(contact_surface_type), intent(inout) :: self
      type(body_type), intent(in) :: master
      integer, intent(in) :: surface
      type(grid_type), intent(in) :: master_grid
      real(wp), intent(in) :: search_distance
      type(error_type), allocatable, intent(out) :: error
      type(ray_hit_type) :: hit
      integer :: i, stat

      call check_gap_input(self, master, surface, master_grid, search_distance, error)
      if (allocated(error)) return
      associate (d => self%dim, n => self%npoint)
         if (allocated(self%has_master)) deallocate (self%has_master, self%g0, self%g0_tolerance, self%master_x, &
            & self%master_normal, self%master_cell)
         allocate (self%has_master(n), source=.false., stat=stat)
         if (stat == 0) allocate (self%g0(n), source=huge(1.0_wp), stat=stat)
         if (stat == 0) allocate (self%g0_tolerance(n), source=0.0_wp, stat=stat)
         if (stat == 0) allocate (self%master_x(d, n), self%master_normal(d, n), source=0.0_wp, stat=stat)
         if (stat == 0) allocate (self%master_cell(n), source=0, stat=stat)
         call check_allocation(stat, 'contact gap', 'the master points', n, 8*(2*d + 2) + 8, error)
         if (allocated(error)) return
         do i = 1, n
            call gap_of_point(master, surface, self%x(:, i), self%normal(:, i), search_distance, hit)
            if (hit%exhausted) then
               call fatal_error(error, 'contact gap: the search along the normal of slave point '//itoa(i)// &
                  & ' did not isolate a crossing within '//itoa(hit%visits - 1)//' segments', stat_not_converged)
               return
            end if
            if (.not. hit%found) cycle
            self%has_master(i) = .true.
            self%g0(i) = hit%t
            self%g0_tolerance(i) = hit%tolerance
            self%master_x(:, i) = hit%x(1:d)
            self%master_normal(:, i) = hit%normal(1:d)
            self%master_cell(i) = host_cell(master_grid, hit%x(1:d), hit%normal(1:d), hit%tolerance)
            if (self%master_cell(i) == 0) then
               call fatal_error(error, 'contact gap: the master point '//real_list(hit%x(1:d))//' of slave point '// &
                  & itoa(i)//' lies in no leaf of the master grid (is the grid built for the master body?)')
               return
            end if
         end do
      end associate
   end subroutine initial_gaps

   !> Linearized gap g = g0 + (u_m - u_s).n_s of every slave point (small
   !> deformations): u_s the displacement of the slave body at the slave
   !> point, u_m the master body's at the master point, both (dim, npoint)
   !> (the caller interpolates them in slave_cell / master_cell). Open points
   !> keep g = huge. Needs `initial_gaps` first.
   pure subroutine linearized_gap(self, u_slave, u_master, g, error)
      type(contact_surface_type), intent(in) :: self
      real(wp), intent(in) :: u_slave(:, :), u_master(:, :)
      real(wp), intent(out) :: g(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      if (.not. allocated(self%g0)) then
         call fatal_error(error, 'linearized gap: initial_gaps has not been called')
         return
      end if
      if (any(shape(u_slave) /= [self%dim, self%npoint]) .or. any(shape(u_master) /= [self%dim, self%npoint]) &
         & .or. size(g) /= self%npoint) then
         call fatal_error(error, 'linearized gap: displacements must be ('//itoa(self%dim)//', '// &
            & itoa(self%npoint)//') and g of size '//itoa(self%npoint))
         return
      end if
      do i = 1, self%npoint
         g(i) = self%g0(i)
         if (self%has_master(i)) g(i) = g(i) + dot_product(u_master(:, i) - u_slave(:, i), self%normal(:, i))
      end do
   end subroutine linearized_gap

   subroutine check_gap_input(self, master, surface, master_grid, search_distance, error)
      type(contact_surface_type), intent(in) :: self
      type(body_type), intent(in) :: master
      integer, intent(in) :: surface
      type(grid_type), intent(in) :: master_grid
      real(wp), intent(in) :: search_distance
      type(error_type), allocatable, intent(out) :: error

      if (surface < 1 .or. surface > master%nsurface()) then
         call fatal_error(error, "contact gap: surface "//itoa(surface)//" of master body '"//body_name(master)// &
            & "' does not exist (it has "//itoa(master%nsurface())//')')
      else if (master%dim /= self%dim .or. master_grid%dim /= self%dim) then
         call fatal_error(error, 'contact gap: slave points are '//itoa(self%dim)//'D, the master body '// &
            & itoa(master%dim)//'D, its grid '//itoa(master_grid%dim)//'D')
      else if (.not. (search_distance > 0.0_wp .and. search_distance <= huge(1.0_wp))) then
         call fatal_error(error, 'contact gap: search_distance must be finite and > 0')
      end if
   end subroutine check_gap_input

   !> The crossing for one slave point: ahead if x is outside the master body
   !> (or on it), behind if inside.
   pure subroutine gap_of_point(master, surface, x, n, search_distance, hit)
      type(body_type), intent(in) :: master
      integer, intent(in) :: surface
      real(wp), intent(in) :: x(:), n(:), search_distance
      type(ray_hit_type), intent(out) :: hit
      real(wp) :: tol, margin, slope, t_lo, t_hi
      integer :: shape

      shape = master%surface_shape(surface)

      ! Within tol of the surface the side is not decided: start the search a
      ! margin behind, the distance that tol can stand for (tol/|grad phi|).
      tol = snap_tolerance(master%shapes(shape), x, x)
      slope = max(norm2(master%shapes(shape)%gradient(x)), epsilon(1.0_wp))
      margin = min(search_distance, 4.0_wp*(tol/slope + position_tolerance(x, 0.0_wp, 0.0_wp)))
      if (master%phi(x) < -tol) then
         t_lo = -search_distance
         t_hi = margin
      else
         t_lo = -margin
         t_hi = search_distance
      end if
      if (master%shapes(shape)%kind == shape_facets) then
         call facet_crossing(master, shape, surface, x, n, t_lo, t_hi, .true., hit)
      else
         call nearest_crossing(master, shape, x, n, t_lo, t_hi, .true., hit)
      end if
   end subroutine gap_of_point

   !> Leaf of `grid` holding x, nudging x into the body (against the outward
   !> normal m) when x sits on a face owned by an external cell; x is off the
   !> surface by at most `tolerance` (the gap's) plus rounding.
   pure integer function host_cell(grid, x, m, tolerance) result(leaf)
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: x(:), m(:), tolerance
      real(wp) :: nudge

      leaf = grid%locate_point(x)
      if (leaf /= 0) return
      nudge = 2.0_wp*tolerance + 4.0_wp*epsilon(1.0_wp)*(maxval(abs(x)) + grid%box_size)
      leaf = grid%locate_point(x - nudge*m)
   end function host_cell

   pure function real_list(v) result(s)
      real(wp), intent(in) :: v(:)
      character(len=:), allocatable :: s
      character(len=24) :: buf
      integer :: k
      s = '('
      do k = 1, size(v)
         write (buf, '(es23.15)') v(k)
         s = s//trim(adjustl(buf))//merge(', ', ') ', k < size(v))
      end do
      s = trim(s)
   end function real_list

end module sprc_contact_surface
