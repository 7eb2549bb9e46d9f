!> SPR-C recovery of bodies in contact on the caller's own meshes (thesis eqs. 103-138):
!> each body as `recover_on_mesh` takes it (sprc_recovery_caller_mesh) plus, per contact pair, the
!> contact facets of both bodies with their law; out come each body's recovery and, at the
!> slave facets' quadrature points, the recovered contact tractions of both bodies and
!> their jump.
!>
!> The core is the grid pipeline's, not a copy: each body is recovered by recover_on_mesh
!> with its contact facets as contact points, and a patch holding one is solved by
!> `contact_patch_solve` (sprc_estimate_contact_patches) with the pair's other body as body (2): its
!> integration points (weight*|J|, FE stresses) and its boundary points other than contact
!> facets (traction, pressure, symmetry, free facets) inside the prism Omega_aux over the
!> patch's contact points, found through the grid pipeline's point cells (a counting sort
!> once per body, never a scan per patch), depth 3 patch sizes in 2D and 2 in 3D
!> (sprc_estimate_contact_patches's default), doubled while the fit lacks rank. Both bodies get contact-aware patches (the mirrored treatment): each is body (1)
!> of its own patches. SPR (`method` = mesh_method_spr) ignores contact. The two fits of a
!> patch weigh by the bodies' element sizes as in the grid pipeline (fe_order of the grid
!> contact; the sizes from the largest quadrature weights, the elements being uncut).
!>
!> Contact edges (2D, frictionless; sprc_recovery_contact_edge_fit): where a closed facet of a slave
!> meets an open one, the pressure falls like the square root of the distance to the edge
!> of the contact zone. The edge's point and amplitude K are fitted to both bodies' data, and
!> the contact patches within its radius recover sigma_h - K S, the other body's Omega_aux
!> data likewise, and add K S back (S the edge field of sprc_recovery_contact_edge, each body
!> with its own normal: the contact law and the open side's freedom hold for it, so the
!> patches' constraints hold for the remainder). `edges` = false turns it off.
!>
!> Input (`contact_body_type`, `contact_pair_type`): pointer components the caller
!> associates with its arrays (no copy), 1-based. Per pair: slave and master body,
!> contact facets of each (element sides of that body, as boundary facets), the law per
!> facet or one for all (contact_open: a free surface; contact_law_frictionless,
!> _slip, _stick), mu (needed by slip), the slip direction of each body relative to the
!> other (one for all or per facet; the master's defaults to the opposite of a uniform
!> slave direction), optionally the FE contact pressure at the slave points (reported).
!> Several pairs and several bodies per call; a patch whose contact points belong to two
!> pairs is an error (the core couples one other body per patch).
!>
!> Output (`mesh_contact_recovery_type`): bodies(i) as recover_on_mesh gives it; pairs(k)
!> at the quadrature points of the slave facets (`mesh_facet_points`, in facet order): the
!> points, weights, slave outward normals n, the recovered contact pressure of the slave
!> p = -n.sigma*_s n and of the master -n.sigma*_m n, the tangential tractions of both
!> (on each body, its own outward normal), and the jump t_s + t_m = (sigma*_s -
!> sigma*_m) n (action-reaction residual). The master's field is evaluated at the facing
!> point of each slave point: the nearest point of the elements that own the master's contact
!> facets (each element's reference coordinates clamped to its cell), the slave point itself
!> where it lies in one. On a curved surface (a roller on a block) the undeformed slave
!> points lie off the master's mesh by the gap, up to a few elements on a fine mesh; the
!> facing point is where the master's traction acts against them. It is found by a ring
!> search of bins over those elements (mesh_bins), never a scan per point.
!>
!> Errors name the argument as the caller wrote it (Fortran bodies(2)%..., or C / Python
!> bodies[1], pairs[0].slave_facets[3] with c_indices).
module sprc_contact_caller_mesh_recovery
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: voigt_size
   use sprc_recovery_operators, only: traction_operator
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_reserve, &
      & boundary_traction, boundary_symmetry
   use sprc_recovery_workspace, only: recovery_workspace_type
   use sprc_recovery_contact_operators, only: contact_law_frictionless, contact_law_slip, contact_law_stick
   use sprc_recovery_caller_mesh_element, only: element_facet_nodes, element_degree, element_name, facet_npoints, &
      & element_inverse_map, element_map, element_simplex, element_nodes
   use sprc_recovery_caller_mesh_bins, only: element_bins_type, build_element_bins
   use sprc_recovery_caller_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_contact_solver_type, mesh_facet_points, &
      & mesh_recovery_eval, mesh_method_sprc, mesh_method_spr, mesh_reference_unit, &
      & facet_traction, facet_pressure, facet_symmetry, facet_free
   use sprc_recovery_patch_loop, only: auto_degree
   use sprc_recovery_caller_mesh_check, only: check_mesh_arrays, check_mesh_facets
   use sprc_estimate_contact_patches, only: grid_contact_type, new_grid_contact, contact_patch_solve
   use sprc_recovery_contact_edge_fit, only: contact_edge_type, find_contact_edges, fit_contact_edge, edge_subtract
   implicit none
   private

   public :: contact_body_type, contact_pair_type, mesh_contact_recovery_type, contact_pair_recovery_type
   public :: recover_contact_on_mesh, contact_open, contact_law_frictionless, contact_law_slip, contact_law_stick
   public :: mu_not_given

   !> Law of an open contact facet (a free surface).
   integer, parameter :: contact_open = 0
   !> contact_pair_type%mu when not given.
   real(wp), parameter :: mu_not_given = -huge(1.0_wp)

   !> One body: the arguments of recover_on_mesh (module notes; pointers to the caller's arrays).
   type :: contact_body_type
      integer :: dim = 0, analysis = 0, element_type = 0
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      !> nodes(dim, nnode); connectivity(nen, nelem), 1-based.
      real(wp), pointer, contiguous :: nodes(:, :) => null()
      integer, pointer, contiguous :: connectivity(:, :) => null()
      !> Integration points (dim, ngp, nelem), weight*|J| (ngp, nelem), FE stresses (nstress, ngp, nelem).
      real(wp), pointer, contiguous :: gp(:, :, :) => null(), gw(:, :) => null(), gs(:, :, :) => null()
      !> Given or not: body force (dim); boundary facets (nfn, nfacet), kinds, tractions (dim, nfacet);
      !> reference coordinates of the points (dim, ngp, nelem) in the convention `reference`.
      real(wp), pointer, contiguous :: body_force(:) => null(), facet_traction(:, :) => null(), &
         & gauss_xi(:, :, :) => null()
      integer, pointer, contiguous :: facet_nodes(:, :) => null(), facet_kind(:) => null()
      integer :: reference = mesh_reference_unit
   end type contact_body_type

   !> One contact pair (module notes).
   type :: contact_pair_type
      !> Bodies (indices into the bodies).
      integer :: slave = 0, master = 0
      !> Contact facets (nfn, nfacet) of each body, 1-based node indices of that body.
      integer, pointer, contiguous :: slave_facets(:, :) => null(), master_facets(:, :) => null()
      !> Law per facet, or one entry for all (contact_open, contact_law_*).
      integer, pointer, contiguous :: slave_law(:) => null(), master_law(:) => null()
      !> Friction coefficient (slip law).
      real(wp) :: mu = mu_not_given
      !> Slip direction of each body relative to the other, (dim, 1) for all or (dim, nfacet).
      real(wp), pointer, contiguous :: slave_slip(:, :) => null(), master_slip(:, :) => null()
      !> Optional FE contact pressure at the slave points (nq nfacet, the output's order).
      real(wp), pointer, contiguous :: pressure(:) => null()
   end type contact_pair_type

   !> Recovered contact tractions of one pair at the slave facets' points (module notes).
   type :: contact_pair_recovery_type
      integer :: slave = 0, master = 0, npoints = 0
      real(wp), allocatable :: x(:, :), w(:), normal(:, :)
      !> Slave facet and element of each point.
      integer, allocatable :: facet(:), element(:)
      real(wp), allocatable :: pressure(:), pressure_master(:)
      real(wp), allocatable :: traction_tangential(:, :), traction_tangential_master(:, :), jump(:, :)
      !> The caller's FE pressure (if given).
      real(wp), allocatable :: pressure_fe(:)
   end type contact_pair_recovery_type

   type :: mesh_contact_recovery_type
      type(mesh_recovery_type), allocatable :: bodies(:)
      type(contact_pair_recovery_type), allocatable :: pairs(:)
   end type mesh_contact_recovery_type

   !> A contact edge of a pair as one body's patches see it (module notes): the edge, the
   !> sign of this body's normal against the edge's (1 slave, -1 master), and the pair's
   !> other body with the edge field subtracted from its stresses.
   type :: edge_site_type
      integer :: pair = 0
      real(wp) :: sign = 1.0_wp
      type(contact_edge_type) :: edge
      type(grid_contact_type) :: other
   end type edge_site_type

   !> A body's contact patches: the other body of each pair (unused entries empty), and the
   !> contact edges near which its patches are enriched.
   type, extends(mesh_contact_solver_type) :: others_type
      type(grid_contact_type), allocatable :: other(:)
      type(edge_site_type), allocatable :: sites(:)
   contains
      procedure :: solve => others_solve
   end type others_type

   !> One body's side of its pairs: contact facets, law, slip, pair of each.
   type :: side_type
      integer, allocatable :: facets(:, :), law(:), pair(:)
      real(wp), allocatable :: slip(:, :)
   end type side_type

contains

   !> Recover bodies in contact (module notes). method mesh_method_sprc (contact-aware) or
   !> mesh_method_spr; degree and max_rounds as recover_on_mesh's (degree 0 or absent: each
   !> body's 'auto'); `degree_above` (0 or 1, the C and Python flags) sets each body's degree
   !> to its element's plus it instead of 'auto' (a positive `degree` wins); -1 is 'auto'. `edges` (default
   !> true): the patches at the edges of frictionless contact zones in 2D take the edge field
   !> (module notes); false: polynomials only.
   subroutine recover_contact_on_mesh(bodies, pairs, method, result, error, degree, max_rounds, c_indices, &
      & degree_above, edges)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pairs(:)
      integer, intent(in) :: method
      type(mesh_contact_recovery_type), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: degree, max_rounds
      logical, intent(in), optional :: c_indices
      integer, intent(in), optional :: degree_above
      logical, intent(in), optional :: edges
      type(side_type), allocatable :: sides(:)
      type(others_type), allocatable :: others(:)
      logical :: ci
      integer :: b, k

      ci = .false.
      if (present(c_indices)) ci = c_indices
      call check_input(bodies, pairs, method, ci, error)
      if (allocated(error)) return
      if (present(degree_above)) then
         if (degree_above < -1 .or. degree_above > 1) then
            call fatal_error(error, 'recover_contact: degree_above = '//itoa(degree_above)//' is not 0 (the '// &
               & 'element''s degree), 1 (one above) or -1 (''auto'')', stat_invalid_input)
            return
         end if
      end if
      allocate (sides(size(bodies)), others(size(bodies)), result%bodies(size(bodies)), result%pairs(size(pairs)))
      call gather_sides(bodies, pairs, sides)
      if (method == mesh_method_sprc) then
         do b = 1, size(bodies)
            allocate (others(b)%other(size(pairs)))
         end do
         do k = 1, size(pairs)
            call other_body(bodies, pairs(k)%master, pairs(k)%mu, ci, others(pairs(k)%slave)%other(k), error)
            if (allocated(error)) return
            call other_body(bodies, pairs(k)%slave, pairs(k)%mu, ci, others(pairs(k)%master)%other(k), error)
            if (allocated(error)) return
         end do
         do b = 1, size(bodies)
            allocate (others(b)%sites(0))
         end do
         if (bodies(1)%dim == 2 .and. opt_true(edges)) then
            do k = 1, size(pairs)
               call pair_edges(bodies, pairs(k), k, ci, others, error)
               if (allocated(error)) return
            end do
         end if
      end if
      do b = 1, size(bodies)
         call recover_body(bodies(b), sides(b), others(b), method, result%bodies(b), ci, error, degree, max_rounds, &
            & degree_above)
         if (allocated(error)) then
            error%message = body_name(ci, b)//': '//error%message
            return
         end if
      end do
      do k = 1, size(pairs)
         call pair_tractions(bodies, pairs(k), result%bodies, ci, k, result%pairs(k), error)
         if (allocated(error)) return
      end do
   end subroutine recover_contact_on_mesh

   !> One body's recovery with its contact facets.
   subroutine recover_body(body, side, others, method, rec, ci, error, degree, max_rounds, degree_above)
      type(contact_body_type), intent(in) :: body
      type(side_type), intent(in) :: side
      type(others_type), intent(in) :: others
      integer, intent(in) :: method
      type(mesh_recovery_type), intent(out) :: rec
      logical, intent(in) :: ci
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: degree, max_rounds, degree_above
      integer :: deg

      deg = auto_degree(method == mesh_method_sprc, element_degree(body%element_type))
      if (present(degree_above)) then
         if (degree_above >= 0) deg = element_degree(body%element_type) + degree_above
      end if
      if (present(degree)) then
         if (degree > 0) deg = degree
      end if
      if (method == mesh_method_sprc .and. size(side%law) > 0) then
         call recover_on_mesh(body%dim, body%analysis, body%nodes, body%element_type, body%connectivity, body%gp, &
            & body%gw, body%gs, body%young, body%poisson, method, rec, error, body_force=body%body_force, &
            & facet_nodes=body%facet_nodes, facet_kind=body%facet_kind, facet_traction=body%facet_traction, &
            & degree=deg, max_rounds=max_rounds, c_indices=ci, gauss_xi=body%gauss_xi, reference=body%reference, &
            & contact_facets=side%facets, contact_law=side%law, contact_slip=side%slip, contact_pair=side%pair, &
            & contact_solver=others)
      else
         call recover_on_mesh(body%dim, body%analysis, body%nodes, body%element_type, body%connectivity, body%gp, &
            & body%gw, body%gs, body%young, body%poisson, method, rec, error, body_force=body%body_force, &
            & facet_nodes=body%facet_nodes, facet_kind=body%facet_kind, facet_traction=body%facet_traction, &
            & degree=deg, max_rounds=max_rounds, c_indices=ci, gauss_xi=body%gauss_xi, reference=body%reference)
      end if
   end subroutine recover_body

   !> The coupled solve of a patch of this body with the pair's other body (module notes). A
   !> patch within the radius of one of the pair's enriched edges (the nearest) recovers
   !> sigma_h - S with the other body's sigma_h - S and adds S back.
   subroutine others_solve(self, pair, patch, law, slip, degree, ws, rec, error)
      class(others_type), intent(in) :: self
      integer, intent(in) :: pair, law(:), degree
      type(patch_type), intent(in) :: patch
      real(wp), intent(in) :: slip(:, :)
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: split
      real(wp) :: dist, best
      integer :: j, near

      near = 0
      best = huge(1.0_wp)
      do j = 1, size(self%sites)
         if (self%sites(j)%pair /= pair .or. self%sites(j)%edge%amplitude == 0.0_wp) cycle
         dist = norm2(patch%x0(1:2) - self%sites(j)%edge%point)
         if (dist < self%sites(j)%edge%radius .and. dist < best) then
            best = dist
            near = j
         end if
      end do
      if (near == 0) then
         call contact_patch_solve(self%other(pair), patch, law, slip, degree, ws, rec, error)
         return
      end if
      associate (site => self%sites(near))
         split = patch
         call edge_subtract(site%edge, site%sign, split%x(:, 1:split%npoints), split%stress(:, 1:split%npoints))
         call contact_patch_solve(site%other, split, law, slip, degree, ws, rec, error)
         if (allocated(error)) return
         rec%edge_amplitude = site%edge%amplitude
         rec%edge_point = site%edge%point
         rec%edge_tangent = site%edge%tangent
         rec%edge_normal = site%sign*site%edge%normal
      end associate
   end subroutine others_solve

   !> The frictionless contact edges of pair k (sprc_recovery_contact_edge_fit) from its slave's states
   !> and both bodies' data, as sites of both bodies' patches.
   subroutine pair_edges(bodies, pair, k, ci, others, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pair
      integer, intent(in) :: k
      logical, intent(in) :: ci
      type(others_type), intent(inout) :: others(:)
      type(error_type), allocatable, intent(out) :: error
      type(contact_edge_type), allocatable :: edges(:)
      real(wp), allocatable :: x(:, :), w(:), n(:, :), fn(:, :)
      integer, allocatable :: owner(:), facet(:), law(:)
      integer :: f, j, nf, s, m

      s = pair%slave
      m = pair%master
      nf = size(pair%slave_facets, 2)
      associate (b => bodies(s))
         call mesh_facet_points(b%dim, b%nodes, b%element_type, b%connectivity, pair%slave_facets, ci, &
            & pair_field(ci, k, 'slave_facets'), x, w, n, owner, facet, error)
      end associate
      if (allocated(error)) return
      allocate (fn(2, nf), law(nf))
      do j = size(facet), 1, -1
         fn(:, facet(j)) = n(1:2, j)
      end do
      do f = 1, nf
         law(f) = entry(pair%slave_law, f)
      end do
      call find_contact_edges(bodies(s)%nodes, pair%slave_facets, law, contact_law_frictionless, fn, edges)
      do j = 1, size(edges)
         associate (b1 => bodies(s), b2 => bodies(m))
            call fit_contact_edge(edges(j), reshape(b1%gp, [2, size(b1%gw)]), reshape(b1%gw, [size(b1%gw)]), &
               & reshape(b1%gs, [3, size(b1%gw)]), reshape(b2%gp, [2, size(b2%gw)]), reshape(b2%gw, [size(b2%gw)]), &
               & reshape(b2%gs, [3, size(b2%gw)]))
         end associate
         if (edges(j)%amplitude == 0.0_wp) cycle
         call add_site(others(s), bodies, m, 1.0_wp, edges(j))
         if (allocated(error)) return
         call add_site(others(m), bodies, s, -1.0_wp, edges(j))
         if (allocated(error)) return
      end do
   contains
      !> Site of edge e for the patches of the body whose other body is o (its normal sgn
      !> times the edge's is that of the body whose patches see it).
      subroutine add_site(oth, bodies, o, sgn, e)
         type(others_type), intent(inout) :: oth
         type(contact_body_type), intent(in) :: bodies(:)
         integer, intent(in) :: o
         real(wp), intent(in) :: sgn
         type(contact_edge_type), intent(in) :: e
         type(edge_site_type), allocatable :: tmp(:)
         integer :: q

         q = size(oth%sites)
         allocate (tmp(q + 1))
         tmp(1:q) = oth%sites
         tmp(q + 1)%pair = k
         tmp(q + 1)%sign = sgn
         tmp(q + 1)%edge = e
         call other_body(bodies, o, pair%mu, ci, tmp(q + 1)%other, error, e, -sgn)
         call move_alloc(tmp, oth%sites)
      end subroutine add_site
   end subroutine pair_edges

   !> Body o as the other body of a pair: its integration points and its boundary points
   !> other than contact facets (module notes).
   !> With `edge`: the edge field of the body whose outward normal is `sgn` times the edge's
   !> subtracted from its stresses.
   subroutine other_body(bodies, o, mu, ci, other, error, edge, sgn)
      type(contact_body_type), intent(in) :: bodies(:)
      integer, intent(in) :: o
      real(wp), intent(in) :: mu
      logical, intent(in) :: ci
      type(grid_contact_type), intent(out) :: other
      type(error_type), allocatable, intent(out) :: error
      type(contact_edge_type), intent(in), optional :: edge
      real(wp), intent(in), optional :: sgn
      type(patch_type) :: bnd
      real(wp), allocatable :: slip0(:, :), bf(:), gs(:, :)
      integer, allocatable :: law0(:)
      integer :: d, n, ns

      associate (b => bodies(o))
         d = b%dim
         ns = voigt_size(b%analysis)
         n = size(b%gw)
         call boundary_of(b, ci, bnd, error)
         if (allocated(error)) then
            error%message = body_name(ci, o)//': '//error%message
            return
         end if
         allocate (law0(0), slip0(d, 0), bf(d))
         bf = 0.0_wp
         if (associated(b%body_force)) bf = b%body_force
         gs = reshape(b%gs, [ns, n])
         if (present(edge)) call edge_subtract(edge, sgn, reshape(b%gp, [d, n]), gs)
         call new_grid_contact(other, [integer ::], law0, slip0, max(mu, 0.0_wp), reshape(b%gp, [d, n]), &
            & reshape(b%gw, [n]), gs, b%young, b%poisson, bf, error, boundary=bnd, &
            & fe_order=element_degree(b%element_type))
      end associate
   end subroutine other_body

   !> The boundary points of a body's facets (traction, pressure, symmetry, free) as a
   !> patch's boundary arrays: the constraints of its Omega_aux fits.
   subroutine boundary_of(b, ci, bnd, error)
      type(contact_body_type), intent(in) :: b
      logical, intent(in) :: ci
      type(patch_type), intent(out) :: bnd
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: x(:, :), w(:), n(:, :)
      integer, allocatable :: owner(:), facet(:)
      integer :: d, j, f

      d = b%dim
      call patch_reset(bnd, d, b%analysis, b%young, b%poisson, [(0.0_wp, j=1, d)], 1.0_wp)
      if (.not. associated(b%facet_nodes)) return
      call mesh_facet_points(d, b%nodes, b%element_type, b%connectivity, b%facet_nodes, ci, 'facet_nodes', x, w, n, &
         & owner, facet, error)
      if (allocated(error)) return
      call patch_reserve(bnd, 0, size(w))
      bnd%nbpoints = size(w)
      do j = 1, size(w)
         f = facet(j)
         bnd%bx(:, j) = 0.0_wp
         bnd%bx(1:d, j) = x(:, j)
         bnd%bw(j) = w(j)
         bnd%bn(:, j) = 0.0_wp
         bnd%bn(1:d, j) = n(:, j)
         bnd%btraction(:, j) = 0.0_wp
         bnd%bkind(j) = boundary_traction
         bnd%bpiece(j) = 1
         select case (b%facet_kind(f))
         case (facet_traction)
            bnd%btraction(1:d, j) = b%facet_traction(:, f)
         case (facet_pressure)
            bnd%btraction(1:d, j) = -b%facet_traction(1, f)*n(:, j)
         case (facet_symmetry)
            bnd%bkind(j) = boundary_symmetry
            bnd%bpiece(j) = 2
         case default
         end select
      end do
   end subroutine boundary_of

   !> Each body's contact facets over the pairs, with law, slip and pair per facet.
   subroutine gather_sides(bodies, pairs, sides)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pairs(:)
      type(side_type), intent(inout) :: sides(:)
      integer :: b, k, nf, nfn, m, f, d

      do b = 1, size(bodies)
         d = bodies(b)%dim
         nfn = element_facet_nodes(bodies(b)%element_type)
         nf = 0
         do k = 1, size(pairs)
            if (pairs(k)%slave == b) nf = nf + size(pairs(k)%slave_facets, 2)
            if (pairs(k)%master == b) nf = nf + size(pairs(k)%master_facets, 2)
         end do
         allocate (sides(b)%facets(nfn, nf), sides(b)%law(nf), sides(b)%pair(nf), sides(b)%slip(d, nf))
         m = 0
         do k = 1, size(pairs)
            if (pairs(k)%slave == b) then
               do f = 1, size(pairs(k)%slave_facets, 2)
                  m = m + 1
                  sides(b)%facets(:, m) = pairs(k)%slave_facets(:, f)
                  sides(b)%law(m) = entry(pairs(k)%slave_law, f)
                  sides(b)%pair(m) = k
                  sides(b)%slip(:, m) = slip_of(pairs(k), .true., f, d)
               end do
            end if
            if (pairs(k)%master == b) then
               do f = 1, size(pairs(k)%master_facets, 2)
                  m = m + 1
                  sides(b)%facets(:, m) = pairs(k)%master_facets(:, f)
                  sides(b)%law(m) = entry(pairs(k)%master_law, f)
                  sides(b)%pair(m) = k
                  sides(b)%slip(:, m) = slip_of(pairs(k), .false., f, d)
               end do
            end if
         end do
      end do
   end subroutine gather_sides

   !> law(f), or law(1) for a single entry.
   pure integer function entry(law, f)
      integer, intent(in) :: law(:), f
      entry = law(min(f, size(law)))
   end function entry

   !> The slip direction of facet f on one side (zero where not given).
   pure function slip_of(pair, slave, f, d) result(s)
      type(contact_pair_type), intent(in) :: pair
      logical, intent(in) :: slave
      integer, intent(in) :: f, d
      real(wp) :: s(d)

      s = 0.0_wp
      if (slave) then
         if (associated(pair%slave_slip)) s = pair%slave_slip(:, min(f, size(pair%slave_slip, 2)))
      else if (associated(pair%master_slip)) then
         s = pair%master_slip(:, min(f, size(pair%master_slip, 2)))
      else if (associated(pair%slave_slip)) then
         ! A uniform slave direction: the master slides the other way.
         if (size(pair%slave_slip, 2) == 1) s = -pair%slave_slip(:, 1)
      end if
   end function slip_of

   !> The pair's output at the slave facets' points (module notes).
   subroutine pair_tractions(bodies, pair, recs, ci, k, out, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pair
      type(mesh_recovery_type), intent(in) :: recs(:)
      logical, intent(in) :: ci
      integer, intent(in) :: k
      type(contact_pair_recovery_type), intent(out) :: out
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: ss(:, :), sm(:, :), ym(:, :)
      real(wp) :: g(3, 6), ts(3), tm(3), nv(3)
      integer, allocatable :: em(:)
      integer :: d, ns, i, np

      associate (s => bodies(pair%slave))
         d = s%dim
         ns = voigt_size(s%analysis)
         call mesh_facet_points(d, s%nodes, s%element_type, s%connectivity, pair%slave_facets, ci, &
            & pair_field(ci, k, 'slave_facets'), out%x, out%w, out%normal, out%element, out%facet, error)
      end associate
      if (allocated(error)) return
      np = size(out%w)
      out%slave = pair%slave
      out%master = pair%master
      out%npoints = np
      allocate (ss(ns, np), sm(ns, np), out%pressure(np), out%pressure_master(np), out%traction_tangential(d, np), &
         & out%traction_tangential_master(d, np), out%jump(d, np))
      call mesh_recovery_eval(recs(pair%slave), out%x, ss, error, out%element)
      if (.not. allocated(error)) call facing_points(bodies(pair%master), pair%master_facets, out%x, ym, em, error)
      if (.not. allocated(error)) call mesh_recovery_eval(recs(pair%master), ym, sm, error, em)
      if (allocated(error)) then
         error%message = pair_field(ci, k, 'points')//': '//error%message
         return
      end if
      do i = 1, np
         nv = 0.0_wp
         nv(1:d) = out%normal(:, i)
         call traction_operator(d, nv, g)
         ts(1:d) = matmul(g(1:d, 1:ns), ss(:, i))
         tm(1:d) = -matmul(g(1:d, 1:ns), sm(:, i))
         out%pressure(i) = -dot_product(ts(1:d), nv(1:d))
         out%pressure_master(i) = dot_product(tm(1:d), nv(1:d))
         out%traction_tangential(:, i) = ts(1:d) + out%pressure(i)*nv(1:d)
         out%traction_tangential_master(:, i) = tm(1:d) - out%pressure_master(i)*nv(1:d)
         out%jump(:, i) = ts(1:d) + tm(1:d)
      end do
      if (associated(pair%pressure)) out%pressure_fe = pair%pressure
   end subroutine pair_tractions

   !> The facing points y (dim, np) of the points x on the master body b and their elements
   !> (module notes): the nearest point of the elements owning b's contact facets `facets`.
   !> Bins over those elements' boxes; for each point the rings of bins around its own are
   !> searched until the ring lies farther than the nearest point found (an element is in
   !> every bin its box overlaps, so one first met in ring r lies at least (r - 1) bin sides
   !> away).
   subroutine facing_points(b, facets, x, y, elem, error)
      type(contact_body_type), intent(in) :: b
      integer, intent(in) :: facets(:, :)
      real(wp), intent(in) :: x(:, :)
      real(wp), allocatable, intent(out) :: y(:, :)
      integer, allocatable, intent(out) :: elem(:)
      type(error_type), allocatable, intent(out) :: error
      type(element_bins_type) :: bins
      real(wp), allocatable :: fx(:, :), fw(:), fn(:, :), lo(:, :), hi(:, :)
      integer, allocatable :: owner(:), facet(:), cand(:)
      logical, allocatable :: mark(:)
      real(wp) :: best, yc(3), side
      integer :: d, i, k, e, r, c(3), nen

      d = b%dim
      nen = element_nodes(b%element_type)
      call mesh_facet_points(d, b%nodes, b%element_type, b%connectivity, facets, .false., 'master_facets', fx, fw, &
         & fn, owner, facet, error)
      if (allocated(error)) return
      allocate (mark(size(b%connectivity, 2)))
      mark = .false.
      mark(owner) = .true.
      cand = pack([(e, e=1, size(mark))], mark)
      allocate (lo(d, size(cand)), hi(d, size(cand)), y(d, size(x, 2)), elem(size(x, 2)))
      do k = 1, size(cand)
         lo(:, k) = minval(b%nodes(:, b%connectivity(1:nen, cand(k))), dim=2)
         hi(:, k) = maxval(b%nodes(:, b%connectivity(1:nen, cand(k))), dim=2)
      end do
      call build_element_bins(lo, hi, 0.0_wp, bins, error)
      if (allocated(error)) return
      side = minval(bins%size(1:d))
      do i = 1, size(x, 2)
         c = 0
         do k = 1, d
            c(k) = int(max(0.0_wp, min(real(bins%n(k) - 1, wp), (x(k, i) - bins%origin(k))/bins%size(k))))
         end do
         best = huge(1.0_wp)
         elem(i) = 0
         do r = 0, maxval(bins%n(1:d))
            call ring(r)
            if (elem(i) > 0 .and. best <= r*side) exit
         end do
         if (elem(i) == 0) then
            call fatal_error(error, 'no element of the master''s contact facets maps a point near slave point '// &
               & itoa(i), stat_invalid_input)
            return
         end if
      end do
   contains
      !> The candidates of the bins at Chebyshev distance r from c (point i).
      subroutine ring(r)
         integer, intent(in) :: r
         integer :: j(3), jl(3), jh(3), q, bb, j1, j2, j3

         jl = 0
         jh = 0
         jl(1:d) = max(0, c(1:d) - r)
         jh(1:d) = min(bins%n(1:d) - 1, c(1:d) + r)
         do j3 = jl(3), jh(3)
            do j2 = jl(2), jh(2)
               do j1 = jl(1), jh(1)
                  j = [j1, j2, j3]
                  if (maxval(abs(j(1:d) - c(1:d))) /= r) cycle
                  bb = 1 + j1 + bins%n(1)*(j2 + bins%n(2)*j3)
                  do q = bins%ptr(bb), bins%ptr(bb + 1) - 1
                     call try(cand(bins%list(q)))
                  end do
               end do
            end do
         end do
      end subroutine ring
      !> Element e's nearest point to x(:, i) (reference coordinates clamped to its cell).
      subroutine try(e)
         integer, intent(in) :: e
         real(wp) :: xi(3), dist
         logical :: ok

         call element_inverse_map(b%element_type, b%nodes(:, b%connectivity(1:nen, e)), x(:, i), xi(1:d), ok)
         if (.not. ok) return
         xi(1:d) = max(xi(1:d), 0.0_wp)
         if (element_simplex(b%element_type)) then
            if (sum(xi(1:d)) > 1.0_wp) xi(1:d) = xi(1:d)/sum(xi(1:d))
         else
            xi(1:d) = min(xi(1:d), 1.0_wp)
         end if
         call element_map(b%element_type, b%nodes(:, b%connectivity(1:nen, e)), xi(1:d), yc(1:d))
         dist = norm2(yc(1:d) - x(:, i))
         if (dist < best .or. (dist == best .and. e < elem(i))) then
            best = dist
            elem(i) = e
            y(:, i) = yc(1:d)
         end if
      end subroutine try
   end subroutine facing_points

   !> Validation of the bodies and pairs (module notes): what recover_on_mesh checks per
   !> body it checks itself; here the pairs and what they index.
   subroutine check_input(bodies, pairs, method, ci, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pairs(:)
      integer, intent(in) :: method
      logical, intent(in) :: ci
      type(error_type), allocatable, intent(out) :: error
      integer :: b, k

      if (method /= mesh_method_spr .and. method /= mesh_method_sprc) then
         call fail('method = '//itoa(method)//' is not spr (1) or sprc (2)')
      else if (size(bodies) < 2) then
         call fail('need at least 2 bodies, got '//itoa(size(bodies)))
      else if (size(pairs) < 1) then
         call fail('need at least 1 contact pair')
      end if
      if (allocated(error)) return
      do b = 1, size(bodies)
         associate (x => bodies(b))
            if (.not. (associated(x%nodes) .and. associated(x%connectivity) .and. associated(x%gp) .and. &
               & associated(x%gw) .and. associated(x%gs))) then
               call fail(body_name(ci, b)//': nodes, connectivity, gauss points, weights and stresses must be given')
            else if (x%dim /= bodies(1)%dim .or. x%analysis /= bodies(1)%analysis) then
               call fail(body_name(ci, b)//': dim = '//itoa(x%dim)//', analysis = '//itoa(x%analysis)// &
                  & ' differ from '//body_name(ci, 1)//'''s ('//itoa(bodies(1)%dim)//', '// &
                  & itoa(bodies(1)%analysis)//')')
            else if (element_facet_nodes(x%element_type) == 0) then
               call fail(body_name(ci, b)//': element_type = '//itoa(x%element_type)//' is unknown')
            end if
            if (allocated(error)) return
            ! The arrays before any recovery: a body's bad values are read by the other's contact patches.
            call check_mesh_arrays(x%dim, x%analysis, x%nodes, x%element_type, x%connectivity, x%gp, x%gw, x%gs, ci, &
               & error, x%body_force)
            if (.not. allocated(error)) call check_mesh_facets(x%dim, x%element_type, size(x%nodes, 2), ci, error, &
               & x%facet_nodes, x%facet_kind, x%facet_traction)
            if (allocated(error)) error%message = 'recover_contact: '//body_name(ci, b)//': '//error%message
         end associate
         if (allocated(error)) return
      end do
      do k = 1, size(pairs)
         call check_pair(bodies, pairs(k), k, ci, error)
         if (allocated(error)) return
         call check_facing(bodies, pairs(k), k, ci, error)
         if (allocated(error)) return
      end do
   contains
      subroutine fail(message)
         character(len=*), intent(in) :: message
         call fatal_error(error, 'recover_contact: '//message, stat_invalid_input)
      end subroutine fail
   end subroutine check_input

   !> The two sides of a pair face each other: each side's facets are sides of its body's
   !> elements (mesh_facet_points, which names the facet), and the boxes of the two sides'
   !> facet nodes, padded by the largest facet extent, overlap (else the facets of one side
   !> are not where the other's are: a facet of the wrong body, or of another pair).
   subroutine check_facing(bodies, pair, k, ci, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pair
      integer, intent(in) :: k
      logical, intent(in) :: ci
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: x(:, :), w(:), n(:, :)
      integer, allocatable :: owner(:), facet(:)
      real(wp) :: lo(3, 2), hi(3, 2), pad
      integer :: d, s, b, f

      d = bodies(pair%slave)%dim
      pad = 0.0_wp
      do s = 1, 2
         b = merge(pair%slave, pair%master, s == 1)
         associate (fn => merge_facets(s))
            call mesh_facet_points(d, bodies(b)%nodes, bodies(b)%element_type, bodies(b)%connectivity, fn, ci, &
               & pair_field(ci, k, trim(merge('slave_facets ', 'master_facets', s == 1))), x, w, n, owner, facet, error)
            if (allocated(error)) then
               error%message = 'recover_contact: '//error%message
               return
            end if
            lo(1:d, s) = huge(1.0_wp)
            hi(1:d, s) = -huge(1.0_wp)
            do f = 1, size(fn, 2)
               lo(1:d, s) = min(lo(1:d, s), minval(bodies(b)%nodes(:, fn(:, f)), dim=2))
               hi(1:d, s) = max(hi(1:d, s), maxval(bodies(b)%nodes(:, fn(:, f)), dim=2))
               pad = max(pad, maxval(maxval(bodies(b)%nodes(:, fn(:, f)), dim=2) - &
                  & minval(bodies(b)%nodes(:, fn(:, f)), dim=2)))
            end do
         end associate
      end do
      if (any(lo(1:d, 1) > hi(1:d, 2) + pad) .or. any(lo(1:d, 2) > hi(1:d, 1) + pad)) &
         & call fatal_error(error, 'recover_contact: '//pair_field(ci, k, '')//': the slave and master facets do '// &
         & 'not face each other (the boxes of their nodes, padded by the largest facet, are apart): a facet of '// &
         & 'the wrong body?', stat_invalid_input)
   contains
      function merge_facets(s) result(fn)
         integer, intent(in) :: s
         integer, pointer, contiguous :: fn(:, :)
         if (s == 1) then
            fn => pair%slave_facets
         else
            fn => pair%master_facets
         end if
      end function merge_facets
   end subroutine check_facing

   !> One pair: bodies, facets (shapes, node ranges), laws, mu, slip directions, pressure.
   subroutine check_pair(bodies, pair, k, ci, error)
      type(contact_body_type), intent(in) :: bodies(:)
      type(contact_pair_type), intent(in) :: pair
      integer, intent(in) :: k
      logical, intent(in) :: ci
      type(error_type), allocatable, intent(out) :: error
      logical :: slip_law
      integer :: npts

      if (pair%slave < 1 .or. pair%slave > size(bodies)) then
         call fail(field('slave')//' = '//idx(pair%slave)//' is not a body in '//idx(1)//'..'//idx(size(bodies)))
      else if (pair%master < 1 .or. pair%master > size(bodies)) then
         call fail(field('master')//' = '//idx(pair%master)//' is not a body in '//idx(1)//'..'//idx(size(bodies)))
      else if (pair%master == pair%slave) then
         call fail(field('master')//' = '//field('slave')//' = '//idx(pair%slave)//': a pair needs two bodies')
      else if (.not. associated(pair%slave_facets) .or. .not. associated(pair%master_facets)) then
         call fail('needs the contact facets of both sides ('//field('slave_facets')//' and '// &
            & field('master_facets')//')')
      else if (.not. (mu_unset(pair%mu) .or. (pair%mu >= 0.0_wp .and. pair%mu <= huge(1.0_wp)))) then
         call fail(field('mu')//' = '//rstr(pair%mu)//' must be finite and >= 0')
      end if
      if (allocated(error)) return
      call check_side(.true.)
      if (allocated(error)) return
      call check_side(.false.)
      if (allocated(error)) return
      npts = facet_npoints(element_facet_nodes(bodies(pair%slave)%element_type))*size(pair%slave_facets, 2)
      slip_law = any(pair%slave_law == contact_law_slip) .or. any(pair%master_law == contact_law_slip)
      if (slip_law .and. mu_unset(pair%mu)) then
         call fail('has slip facets but '//field('mu')//' is not given')
      else if (associated(pair%pressure)) then
         if (size(pair%pressure) /= npts) then
            call fail(field('pressure')//' has '//itoa(size(pair%pressure))//' entries; need one per slave point ('// &
               & itoa(npts)//')')
         else if (.not. all(abs(pair%pressure) <= huge(1.0_wp))) then
            call fail(field('pressure')//' is not finite')
         end if
      end if
   contains
      subroutine check_side(slave)
         logical, intent(in) :: slave
         integer, pointer, contiguous :: facets(:, :), law(:)
         real(wp), pointer, contiguous :: slip(:, :)
         character(len=:), allocatable :: sname
         integer :: b, nfn, f, a, d, nf

         if (slave) then
            b = pair%slave
            facets => pair%slave_facets
            law => pair%slave_law
            slip => pair%slave_slip
            sname = 'slave'
         else
            b = pair%master
            facets => pair%master_facets
            law => pair%master_law
            slip => pair%master_slip
            sname = 'master'
         end if
         d = bodies(b)%dim
         nfn = element_facet_nodes(bodies(b)%element_type)
         nf = size(facets, 2)
         if (nf < 1) then
            call fail(field(sname//'_facets')//' is empty: a pair needs contact facets on both sides')
         else if (size(facets, 1) /= nfn) then
            call fail(field(sname//'_facets')//' has '//itoa(size(facets, 1))//' nodes per facet; a facet of '// &
               & element_name(bodies(b)%element_type)//' ('//body_name(ci, b)//') has '//itoa(nfn))
         else if (.not. associated(law)) then
            call fail(field(sname//'_law')//' is not given')
         else if (size(law) /= 1 .and. size(law) /= nf) then
            call fail(field(sname//'_law')//' has '//itoa(size(law))//' entries; need 1 or one per facet ('// &
               & itoa(nf)//')')
         end if
         if (allocated(error)) return
         do f = 1, nf
            do a = 1, nfn
               if (facets(a, f) < 1 .or. facets(a, f) > size(bodies(b)%nodes, 2)) then
                  call fail(entry2(sname//'_facets', a, f)//' = '//idx(facets(a, f))//' is not a node of '// &
                     & body_name(ci, b)//' in '//idx(1)//'..'//idx(size(bodies(b)%nodes, 2)))
                  return
               end if
            end do
         end do
         do f = 1, size(law)
            if (law(f) /= contact_open .and. law(f) /= contact_law_frictionless .and. law(f) /= contact_law_slip &
               & .and. law(f) /= contact_law_stick) then
               call fail(entry1(sname//'_law', f)//' = '//itoa(law(f))//' is not open (0), frictionless (1), '// &
                  & 'slip (2) or stick (3)')
               return
            end if
         end do
         if (associated(slip)) then
            if (size(slip, 1) /= d .or. (size(slip, 2) /= 1 .and. size(slip, 2) /= nf)) then
               call fail(field(sname//'_slip')//' has shape ('//itoa(size(slip, 1))//', '//itoa(size(slip, 2))// &
                  & '); need ('//itoa(d)//', 1) or ('//itoa(d)//', '//itoa(nf)//')')
               return
            end if
         end if
         if (.not. any(law == contact_law_slip)) return
         if (.not. associated(slip)) then
            if (slave .or. .not. associated(pair%slave_slip)) then
               call fail('has slip facets but no '//field(sname//'_slip')//' (the slip direction)')
            else if (size(pair%slave_slip, 2) /= 1) then
               call fail('has slip facets but no '//field('master_slip')//' (the master''s direction defaults to '// &
                  & 'the opposite of a uniform slave_slip only)')
            end if
         else
            do f = 1, nf
               if (law(min(f, size(law))) /= contact_law_slip) cycle
               a = min(f, size(slip, 2))
               if (.not. all(abs(slip(:, a)) <= huge(1.0_wp))) then
                  call fail(field(sname//'_slip')//' is not finite ('//entry2(sname//'_slip', 0, a)//')')
               else if (.not. (norm2(slip(:, a)) > 0.0_wp)) then
                  call fail(field(sname//'_slip')//' is zero on a slip facet ('//entry2(sname//'_slip', 0, a)//')')
               end if
               if (allocated(error)) return
            end do
         end if
      end subroutine check_side
      subroutine fail(message)
         character(len=*), intent(in) :: message
         call fatal_error(error, 'recover_contact: '//pair_field(ci, k, '')//' '//message, stat_invalid_input)
      end subroutine fail
      function field(name) result(s)
         character(len=*), intent(in) :: name
         character(len=:), allocatable :: s
         s = pair_field(ci, k, name)
      end function field
      function idx(i) result(s)
         integer, intent(in) :: i
         character(len=:), allocatable :: s
         s = itoa(merge(i - 1, i, ci))
      end function idx
      function entry1(name, i) result(s)
         character(len=*), intent(in) :: name
         integer, intent(in) :: i
         character(len=:), allocatable :: s
         if (ci) then
            s = pair_field(ci, k, name)//'['//itoa(i - 1)//']'
         else
            s = pair_field(ci, k, name)//'('//itoa(i)//')'
         end if
      end function entry1
      function entry2(name, a, f) result(s)
         character(len=*), intent(in) :: name
         integer, intent(in) :: a, f
         character(len=:), allocatable :: s
         if (ci) then
            s = pair_field(ci, k, name)//'['//itoa(f - 1)//']'
            if (a > 0) s = s//'['//itoa(a - 1)//']'
         else
            if (a > 0) then
               s = pair_field(ci, k, name)//'('//itoa(a)//', '//itoa(f)//')'
            else
               s = pair_field(ci, k, name)//'(:, '//itoa(f)//')'
            end if
         end if
      end function entry2
      pure function rstr(x) result(s)
         real(wp), intent(in) :: x
         character(len=:), allocatable :: s
         character(len=32) :: buf
         write (buf, '(es12.4)') x
         s = trim(adjustl(buf))
      end function rstr
   end subroutine check_pair

   !> flag, .true. when absent.
   pure logical function opt_true(flag)
      logical, intent(in), optional :: flag
      opt_true = .true.
      if (present(flag)) opt_true = flag
   end function opt_true

   !> True if mu is mu_not_given (bit for bit).
   pure logical function mu_unset(mu)
      real(wp), intent(in) :: mu
      mu_unset = transfer(mu, 1_i8) == transfer(mu_not_given, 1_i8)
   end function mu_unset

   !> Body b as the caller names it.
   pure function body_name(ci, b) result(s)
      logical, intent(in) :: ci
      integer, intent(in) :: b
      character(len=:), allocatable :: s
      if (ci) then
         s = 'bodies['//itoa(b - 1)//']'
      else
         s = 'bodies('//itoa(b)//')'
      end if
   end function body_name

   !> Field `name` of pair k as the caller names it ('' for the pair itself).
   pure function pair_field(ci, k, name) result(s)
      logical, intent(in) :: ci
      integer, intent(in) :: k
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: s
      if (ci) then
         s = 'pairs['//itoa(k - 1)//']'
         if (len(name) > 0) s = s//'.'//name
      else
         s = 'pairs('//itoa(k)//')'
         if (len(name) > 0) s = s//'%'//name
      end if
   end function pair_field

end module sprc_contact_caller_mesh_recovery
