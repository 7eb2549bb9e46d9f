!> A body's contact surface as the grid recovery sees it (thesis eqs. 103-138, "Formulación
!> del SPR-C en contacto"): which boundary points are in contact and under which
!> law, and the other body's FE stresses for the auxiliary domains Omega_aux.
!>
!> The grid producer (sprc_estimate_patches) marks the body's boundary points on `shape` with a
!> closed law as contact points and solves every SPR-C patch holding one by the coupled
!> contact solve (sprc_recovery_contact_patch_solve, contact wins), with body (2) the other body;
!> points of `shape` that are open are a free surface (zero traction). Both bodies of a pair
!> get a description, each with the other as body (2): the master-side patches are the
!> mirrored ones, so both recovered fields near the contact surface are contact-aware.
!>
!> Where the bodies' grids differ (a shaft on a grid half the hub's) the finer body's data
!> decide: with `fe_order` p the other body's fit weighs (h1/h2)^(2p) against the patch's own,
!> h1 the largest cell of the patch, h2 the largest of the other body's cells with points in
!> Omega_aux: the inverse variance of first-layer stresses that err O(h^p) pointwise, whose
!> error the fit does not remove (doc/benchmarks.md). Otherwise the coarser body's first layer,
!> through Omega_aux, sets the finer body's recovered contact traction. Equal cells weigh alike.
!>
!> Omega_aux depth: `depth` times the patch size h, by default `default_aux_depth(dim)`: 3 h
!> in 2D, 2 h in 3D. A prism of one patch size holds mostly the other body's cut cells, whose
!> stresses are the poorest; in 2D deeper ones stop gaining at 3 h and do not over-smooth the
!> Hertz peak. In 3D 2 h fits better than 3 h on the compound sphere (err_sprc, theta, the
!> pressure, the traction jump), ties on the Hertz sphere, and its prisms hold fewer points
!> (doc/benchmarks.md). The solve doubles it while the Omega_aux fit lacks rank.
!>
!> The other body's volume and boundary points are sorted into uniform cells once (a
!> counting sort, `point_cells_type`): a patch passes the solve only those in the bounding
!> box of its Omega_aux, the box growing with the depth doublings.
!>
!> The other body's boundary points where a prism meets its other boundaries (symmetry planes,
!> loaded or free surfaces) constrain the Omega_aux fit as in any SPR-C patch.
!>
!> Each thread keeps the Omega_aux fit's workspace and patch in its recovery workspace
!> (`contact_scratch_type`), allocated on its first contact patch.
!>
!> Contact edges (2D, frictionless; `set_grid_contact_edges`): where the contact zone ends on
!> a smooth surface the pressure falls like the square root of the distance to its edge. A
!> patch within the radius of an edge fitted to both bodies' data (sprc_recovery_contact_edge_fit)
!> recovers sigma_h - K S, with the other body's sigma_h - K S in Omega_aux, and adds K S back
!> (S the edge field of sprc_recovery_contact_edge, each body its own outward normal), as the
!> caller's-mesh recovery does (sprc_contact_caller_mesh_recovery).
!>
!> Small deformations: undeformed points and normals.
module sprc_estimate_contact_patches
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reserve
   use sprc_recovery_workspace, only: recovery_workspace_type
   use sprc_recovery_contact_operators, only: contact_law_frictionless, contact_law_slip, contact_law_stick
   use sprc_recovery_contact_patch_solve, only: recover_contact_patch, aux_max_doublings, contact_points, aux_margin
   use sprc_recovery_contact_aux, only: aux_domain_type, new_aux_domain, aux_contains
   use sprc_recovery_contact_edge_fit, only: contact_edge_type, edge_subtract
   implicit none
   private

   public :: grid_contact_type, new_grid_contact, contact_patch_solve, default_aux_depth, set_grid_contact_edges
   public :: point_cells_type, new_point_cells, cells_box, cells_prism, aux_bounds

   !> Mean points per cell of the other body's point cells.
   real(wp), parameter :: points_per_cell = 8.0_wp

   !> Points sorted into uniform cells over their box (a counting sort, stable), ncell(k)
   !> along axis k (1 beyond dim): the points of cell c (`cell_index`) are
   !> perm(ptr(c) .. ptr(c+1)-1), ascending within a cell.
   type :: point_cells_type
      integer :: dim = 0
      integer :: ncell(3) = 1
      integer, allocatable :: ptr(:), perm(:)
      real(wp) :: ymin(3) = 0.0_wp, width(3) = 1.0_wp
   end type point_cells_type

   !> A thread's storage of contact patches, kept in its recovery workspace (module notes): the
   !> Omega_aux fit's workspace and patch, and the other body's boundary points in Omega_aux.
   type :: contact_scratch_type
      type(recovery_workspace_type) :: ws2
      type(patch_type) :: patch2, bbox
   end type contact_scratch_type

   !> One body's contact surface for the grid recovery (module notes).
   type :: grid_contact_type
      !> The surface ids of the body's contact surface (the bshape values of its boundary
      !> points there: a shape's, and those of its facet groups).
      integer, allocatable :: surfaces(:)
      !> Per boundary point k of the body's recovery input (read where bshape(k) is in surfaces): the
      !> contact law (contact_law_frictionless, _slip, _stick; 0 = open) and, for slip, the slip
      !> direction of this body relative to the other, slip(1:dim, k).
      integer, allocatable :: law(:)
      real(wp), allocatable :: slip(:, :)
      !> Per boundary point k (as law; empty if not given): the other body's point paired with
      !> it, at bx(:, k) + offset(1:dim, k), and ratio(k) = dA_other/dA_own, the ratio of the two
      !> surfaces' measures there (sprc_recovery_contact_patch_solve: the contact rows balance
      !> forces between surfaces that an interference or a closed gap keeps apart).
      real(wp), allocatable :: offset(:, :), ratio(:)
      !> The bodies' FE order p (0: the fits weigh alike) and the cell size (largest box edge)
      !> of each of the other body's volume points (module notes; empty if not given: then the
      !> cells' sizes are taken from the largest quadrature weights of the patch and of the
      !> other body's points in Omega_aux, as on a caller's mesh of uncut elements).
      integer :: fe_order = 0
      real(wp), allocatable :: cell(:)
      !> Coulomb friction coefficient (slip law).
      real(wp) :: mu = 0.0_wp
      !> Omega_aux depth in patch sizes (`default_aux_depth` of the dimension unless given).
      real(wp) :: depth = 0.0_wp
      !> The other body: volume points, weight*|J|, FE stresses, and their cells.
      real(wp), allocatable :: y(:, :), w(:), stress(:, :)
      type(point_cells_type) :: cells
      !> The other body's boundary points other than its contact surface (boundary arrays
      !> only; nbpoints = 0 if not given): they constrain its Omega_aux fits.
      type(patch_type) :: boundary
      type(point_cells_type) :: boundary_cells
      !> The other body's material and body force.
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp, body_force(3) = 0.0_wp
      !> Contact edges of nonzero amplitude (module notes; empty: none), this body's outward
      !> normal as edge_sign times the edges' (1 the slave, -1 the master), and the other body's
      !> stresses less each edge's field, edge_stress(:, j, e).
      type(contact_edge_type), allocatable :: edges(:)
      real(wp) :: edge_sign = 1.0_wp
      real(wp), allocatable :: edge_stress(:, :, :)
   end type grid_contact_type

contains

   !> The Omega_aux depth in patch sizes of a `dim`-dimensional body (module notes).
   pure real(wp) function default_aux_depth(dim)
      integer, intent(in) :: dim
      default_aux_depth = merge(2.0_wp, 3.0_wp, dim == 3)
   end function default_aux_depth

   !> The contact description of one body: `surfaces`, law(k) and slip(1:dim, k) per boundary
   !> point of its recovery input, mu, and the other body's volume points y(1:dim, j), weights
   !> w(j), FE stresses stress(:, j), material and body force. Errors (stat_invalid_input):
   !> sizes that disagree, an unknown law, a non-finite point.
   subroutine new_grid_contact(self, surfaces, law, slip, mu, y, w, stress, young, poisson, body_force, error, depth, &
      & boundary, offset, ratio, fe_order, cell)
      type(grid_contact_type), intent(out) :: self
      integer, intent(in) :: surfaces(:), law(:)
      real(wp), intent(in) :: slip(:, :), mu, y(:, :), w(:), stress(:, :), young, poisson, body_force(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: depth
      !> The other body's boundary points (`boundary`).
      type(patch_type), intent(in), optional :: boundary
      !> The paired points and measure ratios per boundary point (`offset`, `ratio` of the type).
      real(wp), intent(in), optional :: offset(:, :), ratio(:)
      !> The bodies' FE order and the other body's cell size per volume point (the type's).
      integer, intent(in), optional :: fe_order
      real(wp), intent(in), optional :: cell(:)
      integer :: n

      n = size(w)
      if (size(slip, 2) /= size(law) .or. size(y, 2) /= n .or. size(stress, 2) /= n) then
         call fatal_error(error, 'grid contact: law/slip or y/w/stress disagree in size', stat_invalid_input)
         return
      end if
      if (present(offset) .neqv. present(ratio)) then
         call fatal_error(error, 'grid contact: offset and ratio go together', stat_invalid_input)
         return
      end if
      if (present(fe_order)) self%fe_order = fe_order
      if (present(cell)) then
         if (size(cell) /= n .or. .not. all(cell > 0.0_wp .and. cell <= huge(1.0_wp))) then
            call fatal_error(error, 'grid contact: cell needs a finite size > 0 per point of the other body', &
               & stat_invalid_input)
            return
         end if
         self%cell = cell
      end if
      if (present(offset)) then
         if (size(offset, 2) /= size(law) .or. size(ratio) /= size(law) .or. size(offset, 1) < size(y, 1)) then
            call fatal_error(error, 'grid contact: offset/ratio and law disagree in size', stat_invalid_input)
            return
         end if
         self%offset = offset
         self%ratio = ratio
      end if
      if (any(law /= 0 .and. law /= contact_law_frictionless .and. law /= contact_law_slip .and. &
         & law /= contact_law_stick)) then
         call fatal_error(error, 'grid contact: a contact law is not 0 (open), frictionless, slip or stick', &
            & stat_invalid_input)
         return
      end if
      if (.not. all(abs(y) <= huge(1.0_wp))) then
         call fatal_error(error, 'grid contact: the other body''s points are not finite', stat_invalid_input)
         return
      end if
      self%surfaces = surfaces
      self%law = law
      self%slip = slip
      self%mu = mu
      self%depth = default_aux_depth(size(y, 1))
      if (present(depth)) self%depth = depth
      if (present(boundary)) self%boundary = boundary
      self%young = young
      self%poisson = poisson
      self%body_force = 0.0_wp
      self%body_force(1:size(body_force)) = body_force
      self%y = y
      self%w = w
      self%stress = stress
      call new_point_cells(self%cells, y, error)
      if (allocated(error)) return
      if (self%boundary%nbpoints > 0) &
         & call new_point_cells(self%boundary_cells, self%boundary%bx(1:size(y, 1), 1:self%boundary%nbpoints), error)
   end subroutine new_grid_contact

   !> The contact edges of a 2D body's contact surface (module notes): those of `edges` with a
   !> nonzero amplitude; sgn = 1 on the slave, -1 on the master (the edges' normals are the
   !> slave's). The other body's stresses less each edge's field are kept per edge.
   subroutine set_grid_contact_edges(self, edges, sgn, error)
      type(grid_contact_type), intent(inout) :: self
      type(contact_edge_type), intent(in) :: edges(:)
      real(wp), intent(in) :: sgn
      type(error_type), allocatable, intent(out) :: error
      integer :: e, n, stat

      self%edges = pack(edges, edges%amplitude /= 0.0_wp)
      self%edge_sign = sgn
      n = size(self%w)
      if (size(self%edges) == 0) return
      if (size(self%y, 1) /= 2) then
         call fatal_error(error, 'grid contact: contact edges are two-dimensional', stat_invalid_input)
         return
      end if
      allocate (self%edge_stress(size(self%stress, 1), n, size(self%edges)), stat=stat)
      call check_allocation(stat, 'grid contact', 'the other body''s stresses less each contact edge''s field', &
         & n*size(self%edges), 8*size(self%stress, 1), error)
      if (allocated(error)) return
      do e = 1, size(self%edges)
         self%edge_stress(:, :, e) = self%stress
         call edge_subtract(self%edges(e), -sgn, self%y, self%edge_stress(:, :, e))
      end do
   end subroutine set_grid_contact_edges

   !> Sort the points y(1:dim, j) into cells of about points_per_cell points (module notes).
   subroutine new_point_cells(cells, y, error)
      type(point_cells_type), intent(out) :: cells
      real(wp), intent(in) :: y(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: cell(:)
      real(wp) :: ymax(3)
      integer :: n, d, j, c, stat

      d = size(y, 1)
      n = size(y, 2)
      cells%dim = d
      cells%ymin = 0.0_wp
      ymax = 0.0_wp
      if (n > 0) then
         cells%ymin(1:d) = minval(y, dim=2)
         ymax(1:d) = maxval(y, dim=2)
      end if
      cells%ncell(1:d) = max(1, nint((real(n, wp)/points_per_cell)**(1.0_wp/d)))
      cells%width(1:d) = max((ymax(1:d) - cells%ymin(1:d))/real(cells%ncell(1:d), wp), tiny(1.0_wp))
      allocate (cells%ptr(product(cells%ncell) + 1), cells%perm(n), cell(n), stat=stat)
      call check_allocation(stat, 'grid contact', 'the cells of the other body''s points', n, 12, error)
      if (allocated(error)) return
      cells%ptr = 0
      do j = 1, n
         cell(j) = cell_index(cells, cell_of(cells, y(:, j)))
         cells%ptr(cell(j) + 1) = cells%ptr(cell(j) + 1) + 1
      end do
      cells%ptr(1) = 1
      do c = 2, size(cells%ptr)
         cells%ptr(c) = cells%ptr(c) + cells%ptr(c - 1)
      end do
      do j = 1, n
         cells%perm(cells%ptr(cell(j))) = j
         cells%ptr(cell(j)) = cells%ptr(cell(j)) + 1
      end do
      do c = size(cells%ptr), 2, -1
         cells%ptr(c) = cells%ptr(c - 1)
      end do
      cells%ptr(1) = 1
   end subroutine new_point_cells

   !> Cell coordinates (1-based, clamped to the box) of a point.
   pure function cell_of(cells, y) result(c)
      type(point_cells_type), intent(in) :: cells
      real(wp), intent(in) :: y(:)
      integer :: c(3), k
      real(wp) :: t

      c = 1
      do k = 1, cells%dim
         t = (y(k) - cells%ymin(k))/cells%width(k)
         if (t >= real(cells%ncell(k), wp)) then
            c(k) = cells%ncell(k)
         else if (t >= 1.0_wp) then
            c(k) = int(t) + 1
         end if
      end do
   end function cell_of

   !> Linear index of cell coordinates c (first axis fastest).
   pure integer function cell_index(cells, c)
      type(point_cells_type), intent(in) :: cells
      integer, intent(in) :: c(3)
      cell_index = c(1) + cells%ncell(1)*((c(2) - 1) + cells%ncell(2)*(c(3) - 1))
   end function cell_index

   !> The points y(:, j) in the box blo <= y <= bhi: idx(1:n), in cell order (fixed by the
   !> points alone: the same for any thread count).
   pure subroutine cells_box(cells, y, blo, bhi, idx, n)
      type(point_cells_type), intent(in) :: cells
      real(wp), intent(in) :: y(:, :), blo(:), bhi(:)
      integer, allocatable, intent(out) :: idx(:)
      integer, intent(out) :: n
      real(wp) :: lo(3), hi(3)

      lo = 0.0_wp
      hi = 0.0_wp
      lo(1:cells%dim) = blo(1:cells%dim)
      hi(1:cells%dim) = bhi(1:cells%dim)
      call cells_select(cells, y, lo, hi, idx, n)
   end subroutine cells_box

   !> The points y(:, j) inside Omega_aux: idx(1:n), the points of `cells_box` over the
   !> prism's bounding box (`aux_bounds`) for which aux_contains holds, in the same order.
   !> A cell whose box lies inside the prism (the prism is convex: the box's projections on
   !> the prism's axes within its bounds, by a margin far above the round-off of
   !> aux_contains) is taken without a test per point, and one outside it is skipped; only
   !> the points of cells that straddle a face are tested. (The prism of an oblique normal
   !> fills a fraction of its bounding box, and the test per point was most of the contact
   !> patches' time.)
   pure subroutine cells_prism(cells, y, aux, idx, n)
      type(point_cells_type), intent(in) :: cells
      real(wp), intent(in) :: y(:, :)
      type(aux_domain_type), intent(in) :: aux
      integer, allocatable, intent(out) :: idx(:)
      integer, intent(out) :: n
      real(wp) :: blo(3), bhi(3)

      call aux_bounds(aux, blo, bhi)
      call cells_select(cells, y, blo, bhi, idx, n, aux)
   end subroutine cells_prism

   !> The points in the box blo..bhi (and, with aux, in Omega_aux: `cells_prism`), in cell order.
   pure subroutine cells_select(cells, y, blo, bhi, idx, n, aux)
      type(point_cells_type), intent(in) :: cells
      real(wp), intent(in) :: y(:, :), blo(3), bhi(3)
      integer, allocatable, intent(out) :: idx(:)
      integer, intent(out) :: n
      type(aux_domain_type), intent(in), optional :: aux
      real(wp) :: clo(3), chi(3), pad(3)
      integer :: lo(3), hi(3), ic(3), i1, i2, i3, k, d, c, state

      d = cells%dim
      call box_cells(cells, blo, bhi, lo, hi, n)
      allocate (idx(n))
      n = 0
      if (.not. allocated(cells%ptr)) return
      ! A point sorted into a cell lies in the cell's box up to the round-off of cell_of.
      pad(1:d) = 1.0e-12_wp*cells%width(1:d) + &
         & 8*epsilon(1.0_wp)*(abs(cells%ymin(1:d)) + cells%ncell(1:d)*cells%width(1:d))
      state = 0
      do i3 = lo(3), hi(3)
         do i2 = lo(2), hi(2)
            do i1 = lo(1), hi(1)
               ic = [i1, i2, i3]
               c = cell_index(cells, ic)
               if (cells%ptr(c + 1) == cells%ptr(c)) cycle
               if (present(aux)) then
                  clo(1:d) = cells%ymin(1:d) + (ic(1:d) - 1)*cells%width(1:d) - pad(1:d)
                  chi(1:d) = cells%ymin(1:d) + ic(1:d)*cells%width(1:d) + pad(1:d)
                  state = box_in_prism(aux, clo, chi)
                  if (state < 0) cycle
               end if
               do k = cells%ptr(c), cells%ptr(c + 1) - 1
                  if (state == 0) then
                     if (any(y(1:d, cells%perm(k)) < blo(1:d)) .or. any(y(1:d, cells%perm(k)) > bhi(1:d))) cycle
                     if (present(aux)) then
                        if (.not. aux_contains(aux, y(:, cells%perm(k)))) cycle
                     end if
                  end if
                  n = n + 1
                  idx(n) = cells%perm(k)
               end do
            end do
         end do
      end do
   end subroutine cells_select

   !> The range lo..hi of cell coordinates over the box blo..bhi and the number of points in
   !> those cells (0 without cells).
   pure subroutine box_cells(cells, blo, bhi, lo, hi, n)
      type(point_cells_type), intent(in) :: cells
      real(wp), intent(in) :: blo(:), bhi(:)
      integer, intent(out) :: lo(3), hi(3), n
      integer :: i2, i3, c, d

      d = cells%dim
      lo = 1
      hi = 0
      n = 0
      if (.not. allocated(cells%ptr)) return
      lo = cell_of(cells, blo(1:d))
      hi = cell_of(cells, bhi(1:d))
      do i3 = lo(3), hi(3)
         do i2 = lo(2), hi(2)
            c = cell_index(cells, [lo(1), i2, i3])
            n = n + cells%ptr(c + hi(1) - lo(1) + 1) - cells%ptr(c)
         end do
      end do
   end subroutine box_cells

   !> Where the box clo..chi lies relative to Omega_aux: 1 inside, -1 outside, 0 across a
   !> face (or too close to one to tell), from its projections on the prism's axes.
   pure integer function box_in_prism(aux, clo, chi) result(state)
      type(aux_domain_type), intent(in) :: aux
      real(wp), intent(in) :: clo(3), chi(3)
      real(wp) :: mid(3), half(3), pc, pr, a, b, tol
      integer :: k, d

      d = aux%dim
      mid(1:d) = 0.5_wp*(clo(1:d) + chi(1:d)) - aux%centre(1:d)
      half(1:d) = 0.5_wp*(chi(1:d) - clo(1:d))
      tol = sqrt(epsilon(1.0_wp))*(aux%hi - aux%lo + maxval(aux%tmax(1:d - 1) - aux%tmin(1:d - 1)) + &
         & maxval(abs(aux%centre(1:d))))
      state = 1
      do k = 1, d
         if (k == 1) then
            a = aux%lo
            b = aux%hi
         else
            a = aux%tmin(k - 1)
            b = aux%tmax(k - 1)
         end if
         pc = dot_product(mid(1:d), aux%frame(1:d, k))
         pr = sum(half(1:d)*abs(aux%frame(1:d, k)))
         if (pc + pr < a - tol .or. pc - pr > b + tol) then
            state = -1
            return
         end if
         if (pc - pr < a + tol .or. pc + pr > b - tol) state = 0
      end do
   end function box_in_prism

   !> The coupled SPR-C solve of a patch holding contact points (sprc_recovery_contact_patch_solve):
   !> law(j), slip(1:dim, j) per boundary point j of `patch`, body (2) the other body's points
   !> (module notes). rec is the patch's recovered stress. The Omega_aux storage is the
   !> thread's (in `ws`, module notes).
   subroutine contact_patch_solve(self, patch, law, slip, degree, ws, rec, error, offset, ratio, h1)
      type(grid_contact_type), intent(in) :: self
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: law(:), degree
      real(wp), intent(in) :: slip(:, :)
      !> Per boundary point of `patch`: the paired points and measure ratios (the type's).
      real(wp), intent(in), optional :: offset(:, :), ratio(:)
      !> The largest cell of the patch (module notes: the fits' weights).
      real(wp), intent(in), optional :: h1
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error
      class(*), allocatable :: scratch
      type(patch_type) :: split
      real(wp) :: dist, best
      integer :: stat, e, near

      ! Out of ws for the call (ws and the scratch are distinct arguments below).
      call move_alloc(ws%contact, scratch)
      if (.not. allocated(scratch)) then
         allocate (contact_scratch_type :: scratch, stat=stat)
         call check_allocation(stat, 'contact patch', 'the thread''s Omega_aux storage', 1, &
            & storage_size(ws)/8, error)
         if (allocated(error)) return
      end if
      ! The nearest edge within its radius (module notes).
      near = 0
      best = huge(1.0_wp)
      if (allocated(self%edges)) then
         do e = 1, size(self%edges)
            dist = norm2(patch%x0(1:2) - self%edges(e)%point)
            if (dist < self%edges(e)%radius .and. dist < best) then
               best = dist
               near = e
            end if
         end do
      end if
      select type (scratch)
      type is (contact_scratch_type)
         if (near == 0) then
            call solve(scratch, patch, self%stress)
         else
            split = patch
            call edge_subtract(self%edges(near), self%edge_sign, split%x(:, 1:split%npoints), &
               & split%stress(:, 1:split%npoints))
            call solve(scratch, split, self%edge_stress(:, :, near))
            if (.not. allocated(error)) then
               rec%edge_amplitude = self%edges(near)%amplitude
               rec%edge_point = self%edges(near)%point
               rec%edge_tangent = self%edges(near)%tangent
               rec%edge_normal = self%edge_sign*self%edges(near)%normal
            end if
         end if
      end select
      call move_alloc(scratch, ws%contact)
   contains
      !> The solve of patch p with the other body's stresses s2.
      subroutine solve(sc, p, s2)
         type(contact_scratch_type), intent(inout) :: sc
         type(patch_type), intent(in) :: p
         real(wp), intent(in) :: s2(:, :)
         type(recovered_patch_type) :: rec2
         type(aux_domain_type) :: aux
         integer, allocatable :: idx(:)
         real(wp), allocatable :: cx(:, :), cn(:, :), cw(:)
         real(wp) :: dep, w2
         integer :: n, k

         call contact_points(p, cx, cn, cw)
         ! Each k passes the points in Omega_aux after k doublings (which holds the smaller ones),
         ! so that a patch copies no more of the other body than it can use.
         do k = 0, aux_max_doublings
            dep = self%depth*p%h*2.0_wp**k
            call new_aux_domain(aux, p%dim, cx, cn, cw, dep, aux_margin(dep, self%depth*p%h), error)
            if (allocated(error)) return
            call cells_prism(self%cells, self%y, aux, idx, n)
            call prism_boundary(self, aux, sc%bbox)
            w2 = 1.0_wp
            if (self%fe_order > 0 .and. n > 0) then
               if (present(h1) .and. allocated(self%cell)) then
                  w2 = (h1/maxval(self%cell(idx(1:n))))**(2*self%fe_order)
               else if (p%npoints > 0) then
                  ! Uncut elements of one quadrature rule: the largest weights are as the cells' measures.
                  w2 = (maxval(p%w(1:p%npoints))/maxval(self%w(idx(1:n))))**(2.0_wp*self%fe_order/p%dim)
               end if
            end if
            call recover_contact_patch(p, degree, law, self%mu, slip, self%y, self%w, s2, self%young, &
               & self%poisson, self%depth*p%h, ws, sc%ws2, sc%patch2, rec, rec2, error, &
               & body_force2=self%body_force, max_doublings=k, boundary2=sc%bbox, candidates=idx(1:n), offset=offset, &
               & ratio=ratio, weight2=w2)
            if (.not. allocated(error)) return
            if (index(error%message, 'Omega_aux fit') == 0) return
         end do
      end subroutine solve
   end subroutine contact_patch_solve

   !> The other body's boundary points in Omega_aux (boundary arrays of `points`).
   pure subroutine prism_boundary(self, aux, points)
      type(grid_contact_type), intent(in) :: self
      type(aux_domain_type), intent(in) :: aux
      type(patch_type), intent(inout) :: points
      integer, allocatable :: idx(:)
      integer :: n, d

      points%nbpoints = 0
      if (self%boundary%nbpoints == 0) return
      d = self%boundary_cells%dim
      call cells_prism(self%boundary_cells, self%boundary%bx(1:d, 1:self%boundary%nbpoints), aux, idx, n)
      call patch_reserve(points, 0, n)
      points%nbpoints = n
      points%bx(:, 1:n) = self%boundary%bx(:, idx(1:n))
      points%bw(1:n) = self%boundary%bw(idx(1:n))
      points%bn(:, 1:n) = self%boundary%bn(:, idx(1:n))
      points%bkind(1:n) = self%boundary%bkind(idx(1:n))
      points%bpiece(1:n) = self%boundary%bpiece(idx(1:n))
      points%btraction(:, 1:n) = self%boundary%btraction(:, idx(1:n))
   end subroutine prism_boundary

   !> The axis-aligned bounding box blo..bhi of the prism Omega_aux (its 2^dim corners), widened
   !> by a few ulps of its extent so that points on its faces stay inside.
   pure subroutine aux_bounds(aux, blo, bhi)
      type(aux_domain_type), intent(in) :: aux
      real(wp), intent(out) :: blo(3), bhi(3)
      real(wp) :: corner(3), a(3), b(3), pad
      integer :: m, k, d

      d = aux%dim
      a = 0.0_wp
      b = 0.0_wp
      a(1) = aux%lo
      b(1) = aux%hi
      a(2:d) = aux%tmin(1:d - 1)
      b(2:d) = aux%tmax(1:d - 1)
      blo = huge(1.0_wp)
      bhi = -huge(1.0_wp)
      do m = 0, 2**d - 1
         corner = aux%centre
         do k = 1, d
            corner(1:d) = corner(1:d) + merge(b(k), a(k), btest(m, k - 1))*aux%frame(1:d, k)
         end do
         blo(1:d) = min(blo(1:d), corner(1:d))
         bhi(1:d) = max(bhi(1:d), corner(1:d))
      end do
      pad = 16*epsilon(1.0_wp)*(maxval(bhi(1:d) - blo(1:d)) + maxval(abs(aux%centre(1:d))))
      blo(1:d) = blo(1:d) - pad
      bhi(1:d) = bhi(1:d) + pad
   end subroutine aux_bounds

end module sprc_estimate_contact_patches
