!> SPR / SPR-C recovery and the ZZ estimate on a caller's own unstructured mesh (thesis
!> eqs. 1, 8-11, 19-24, 99-102; Figure 15 for patch expansion). For legacy FE codes: the
!> mesh is plain arrays, the result one object (`mesh_recovery_type`, opaque to bindings).
!>
!> Input (`recover_on_mesh`, whose arguments say the shapes): one element type for the mesh
!> (sprc_recovery_caller_mesh_element: tri3, quad4, quad9, tet4, hex8, hex27; VTK codes and node
!> order), 1-based connectivity, per element the integration points, weights times |J| and
!> FE stresses (Voigt), the material and method, optionally a body force and boundary
!> facets. Every point must lie in its element (inverse isoparametric map, 1e-6 in reference
!> coordinates). Given reference coordinates `gauss_xi` are checked instead, in the
!> convention `reference` names (mesh_reference_unit [0, 1]^dim, the default, or
!> mesh_reference_symmetric [-1, 1]^dim; simplices are the unit simplex in both). Two used
!> nodes at one point and two elements on the same vertices are input errors.
!>
!> Facets: each a side of exactly one element, nodes in any order (else an error naming
!> it); kinds traction, symmetry, free, pressure; normals point away from the element's
!> vertex centroid. Only surfaces given as facets are constrained; SPR ignores them.
!>
!> Patches: one per vertex node, holding the elements that contain it; h = the largest
!> distance from the node to a node of those elements; SPR-C adds the facets' points of
!> those elements. A rank-deficient patch grows by rings up to `max_rounds` (default
!> mesh_default_max_rounds), as on the grid. Degree 'auto' is `auto_degree`'s.
!>
!> Output: nodal values (vertex nodes: the patch polynomial; other nodes the union, eq. 102,
!> in their first element; unused nodes zero); the field sigma*(x) (SPR eq. 101, SPR-C eq.
!> 102); the patch polynomials, except for SPR on linear elements, whose field needs only
!> the nodal values (then the patches are solved in chunks and their records dropped); element and total ZZ errors and eta, summed scaled by powers of two so any finite
!> stresses give finite results. `mesh_recovery_eval` finds a point's element through bins
!> (sprc_recovery_caller_mesh_bins) unless given: the lowest-index element holding it.
!>
!> Contact (`contact_facets`, SPR-C only; the two-body entry sprc_contact_caller_mesh_recovery):
!> contact facets are element sides as the boundary facets, each with a law (0 open:
!> a free surface; contact_law_frictionless, _slip, _stick), a slip direction and the
!> index of its pair. A patch holding a point of a closed contact facet is solved by the
!> caller's `mesh_contact_solver_type` (the coupled solve with the other body, contact
!> wins), whose points must all belong to one pair (else an error naming the node).
!> `mesh_facet_points` gives the quadrature points of a facet list as the recovery
!> builds them (owner element, outward normal).
!> The patch loop is sprc_recovery_patch_loop's: the bits do not depend on the threads.
module sprc_recovery_caller_mesh
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular, &
      & stat_not_converged, stat_out_of_memory
   use sprc_core_material, only: voigt_size, compliance_matrix, plane_stress, solid
   use sprc_core_timer, only: wall_time
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_reserve, &
      & boundary_traction, boundary_symmetry, boundary_contact
   use sprc_recovery_workspace, only: recovery_workspace_type
   use sprc_recovery_patch_loop, only: patch_source_type, patch_loop_type, run_patch_loop, patch_capacity, auto_degree, &
      & recover_patch_default
   use sprc_recovery_estimate, only: eval_recovered_points, energy_norms, scaled_norm, relative_error
   use sprc_recovery_caller_mesh_element, only: elem_tri3, elem_quad4, elem_tet4, elem_hex8, elem_quad9, elem_hex27, &
      & element_dim, element_nodes, element_vertices, element_degree, element_facet_nodes, element_shape, &
      & element_facet_order, element_simplex, &
      & element_vertex_shape, element_node_xi, element_inside, element_inverse_map, element_name, &
      & facet_points, facet_npoints, max_facet_points, max_element_nodes
   use sprc_core_text, only: itoa
   use sprc_core_alloc, only: check_allocation
   use sprc_recovery_caller_mesh_bins, only: element_bins_type, build_element_bins, bin_of_point
   use sprc_recovery_caller_mesh_check, only: check_mesh_options, check_mesh_arrays, check_mesh_facets, &
      & check_duplicate_nodes, check_duplicate_elements, vec_str, entry_name, index_name, &
      & mesh_reference_unit, mesh_reference_symmetric, reference_cell_name, &
      & mesh_method_spr, mesh_method_sprc, facet_traction, facet_symmetry, facet_free, facet_pressure, &
      & method_code_type
   implicit none
   private

   public :: mesh_recovery_type, recover_on_mesh, mesh_recovery_eval, mesh_default_max_rounds, coded_degree
   public :: mesh_method_spr, mesh_method_sprc, facet_traction, facet_symmetry, facet_free, facet_pressure
   public :: mesh_reference_unit, mesh_reference_symmetric
   public :: elem_tri3, elem_quad4, elem_tet4, elem_hex8, elem_quad9, elem_hex27
   public :: mesh_contact_solver_type, mesh_facet_points, mesh_recovery_eval_near

   !> Default limit of expansion rounds per patch.
   integer, parameter :: mesh_default_max_rounds = 3
   !> Tolerance (reference coordinates) for a point to count as inside an element.
   real(wp), parameter :: inside_tol = 1.0e-6_wp
   !> mesh_recovery_eval bins the elements when at least this many points are searched
   !> (building the bins costs about a few scans over the elements).
   integer, parameter :: bins_min_points = 4
   !> Patches per chunk of `patches_to_nodal`: a buffer of a few MB, and few enough chunks
   !> that the loop's per-call set-up (each thread's element stamps) stays small.
   integer, parameter :: patch_chunk = 16384

   !> Result of `recover_on_mesh` (module notes). Components are public plain data.
   type :: mesh_recovery_type
      !> Dimension, analysis, element type, method, patch degree, stress components.
      integer :: dim = 0, analysis = 0, element_type = 0, method = 0, degree = 0, nstress = 0
      !> Nodes, elements, nodes and vertices per element.
      integer :: nnode = 0, nelem = 0, nen = 0, nvertex = 0
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      !> Messages name entries as C does (0-based, row-major; module sprc_recovery_caller_mesh_check).
      logical :: c_indices = .false.
      !> Copy of the mesh: nodes x(dim, nnode), connectivity(nen, nelem), element boxes.
      real(wp), allocatable :: x(:, :), box_lo(:, :), box_hi(:, :)
      integer, allocatable :: connectivity(:, :)
      !> The patches: node of each (ascending), patch of each node (0: none), recovered polynomials
      !> (not kept, recs unallocated, for SPR on linear elements: module notes), expansion rounds
      !> and final element count of each.
      integer :: n_patches = 0
      integer, allocatable :: patch_node(:), patch_of_node(:), patch_rounds(:), patch_elements(:)
      type(recovered_patch_type), allocatable :: recs(:)
      !> Patches expanded, most rounds used, patches where the rank tolerance decided a rank,
      !> boundary quadrature points generated from the facets.
      integer :: n_expanded = 0, max_rounds_used = 0, n_tolerance_bites = 0, n_boundary_points = 0
      !> Recovered nodal stresses (nstress, nnode).
      real(wp), allocatable :: nodal(:, :)
      !> Per element: ZZ error and FE stress energy norm (not squared).
      real(wp), allocatable :: elem_err(:), elem_norm_h(:)
      !> Global ZZ estimate, FE stress norm, estimated relative error.
      real(wp) :: err = 0.0_wp, norm_h = 0.0_wp, eta = 0.0_wp
      !> Wall times (s) of the phases: input checks; topology (node -> element lists,
      !> duplicate checks, facet points); reference coordinates of the points; patch solves;
      !> nodal values; ZZ estimate.
      real(wp) :: t_check = 0.0_wp, t_topology = 0.0_wp, t_points = 0.0_wp, t_patches = 0.0_wp, &
         & t_nodal = 0.0_wp, t_estimate = 0.0_wp
      !> Process CPU time (s, all threads) of the input checks and the topology, the set-up a
      !> library holding a built mesh and spaces does before its estimator is called: a
      !> benchmark subtracts it to compare like with like.
      real(wp) :: cpu_setup = 0.0_wp
   end type mesh_recovery_type

   !> The solver of a body's contact patches (module notes): `solve` recovers a filled patch
   !> holding contact points of pair `pair`, law(j) and slip(1:dim, j) per boundary point j
   !> (read where patch%bkind(j) = boundary_contact). Called from several threads at once.
   type, abstract :: mesh_contact_solver_type
   contains
      procedure(contact_solve_interface), deferred :: solve
   end type mesh_contact_solver_type

   abstract interface
      subroutine contact_solve_interface(self, pair, patch, law, slip, degree, ws, rec, error)
         import :: mesh_contact_solver_type, patch_type, recovery_workspace_type, recovered_patch_type, &
            & error_type, wp
         class(mesh_contact_solver_type), intent(in) :: self
         integer, intent(in) :: pair, law(:), degree
         type(patch_type), intent(in) :: patch
         real(wp), intent(in) :: slip(:, :)
         type(recovery_workspace_type), intent(inout) :: ws
         type(recovered_patch_type), intent(out) :: rec
         type(error_type), allocatable, intent(out) :: error
      end subroutine contact_solve_interface
   end interface

   !> Mesh data of one recovery: node -> element CSR and boundary points per element (CSR),
   !> with the contact law, pair and slip direction of each (law 0: not a contact point).
   type :: topology_type
      integer, allocatable :: ne_ptr(:), ne_list(:)
      integer, allocatable :: bptr(:), bkind(:), bpiece(:), blaw(:), bpair(:)
      real(wp), allocatable :: bx(:, :), bw(:), bn(:, :), bt(:, :), bslip(:, :)
      real(wp) :: body_force(3) = 0.0_wp
   end type topology_type

   !> The integration rule of the caller's points when every element has the same reference
   !> points, bit for bit (as an FE code's Gauss rule): their shape values, evaluated once
   !> instead of at every point of every element (the same values, so the same bits).
   type :: rule_type
      !> True if every element's reference points are those of element 1.
      logical :: shared = .false.
      !> Shape values at the points: the element's map(1:nen, i); the method's field
      !> n(:, i) (`method_shape`).
      real(wp), allocatable :: map(:, :), n(:, :)
   end type rule_type

   !> The caller's mesh as a source of patches (sprc_recovery_patch_loop): read-only views
   !> of the result's copy of the mesh, the topology and the caller's point arrays.
   type, extends(patch_source_type) :: mesh_source_type
      integer :: dim = 0, analysis = 0, nstress = 0, nen = 0
      logical :: sprc = .false.
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      ! contiguous: the gathering of a patch's points indexes them directly (no strides)
      real(wp), pointer, contiguous :: x(:, :) => null(), gp(:, :, :) => null(), gw(:, :) => null(), &
         & gs(:, :, :) => null()
      integer, pointer, contiguous :: connectivity(:, :) => null()
      type(topology_type), pointer :: topo => null()
      class(mesh_contact_solver_type), pointer :: contact => null()
      logical :: c_indices = .false.
   contains
      procedure :: fill => mesh_fill
      procedure :: points_of => mesh_points_of
      procedure :: recover => mesh_recover
   end type mesh_source_type

contains

   !> The patch degree a decoded method code asks for on elements of type `element_type`:
   !> the element's degree plus `degree_above`, or 'auto' (`auto_degree`).
   pure integer function coded_degree(code, element_type) result(degree)
      type(method_code_type), intent(in) :: code
      integer, intent(in) :: element_type

      degree = auto_degree(code%method == mesh_method_sprc, element_degree(element_type))
      if (code%degree_above >= 0) degree = element_degree(element_type) + code%degree_above
   end function coded_degree

   !> Recover the stresses of a caller's mesh and estimate the error (module notes). Errors
   !> name the argument and index: invalid input (stat_invalid_input), a point whose
   !> inverse map does not converge (stat_not_converged), a patch still rank deficient after
   !> `max_rounds` expansions (stat_singular, naming the node).
   subroutine recover_on_mesh(dim, analysis, nodes, element_type, connectivity, gp, gw, gs, young, poisson, method, &
         & result, error, body_force, facet_nodes, facet_kind, facet_traction, degree, max_rounds, c_indices, &
         & gauss_xi, reference, contact_facets, contact_law, contact_slip, contact_pair, contact_solver)
      integer, intent(in) :: dim, analysis
      !> Node coordinates (dim, nnode).
      real(wp), intent(in) :: nodes(:, :)
      integer, intent(in) :: element_type
      !> Element nodes (nen, nelem), 1-based, VTK order.
      integer, intent(in) :: connectivity(:, :)
      !> Integration points (dim, ngp, nelem), weight*|J| (ngp, nelem), FE stress (nstress, ngp, nelem).
      real(wp), intent(in), target, contiguous :: gp(:, :, :), gw(:, :), gs(:, :, :)
      real(wp), intent(in) :: young, poisson
      integer, intent(in) :: method
      type(mesh_recovery_type), intent(out), target :: result
      type(error_type), allocatable, intent(out) :: error
      !> Constant body force (dim).
      real(wp), intent(in), optional :: body_force(:)
      !> Boundary facets (nfn, nfacet) and their kinds (nfacet).
      integer, intent(in), optional :: facet_nodes(:, :), facet_kind(:)
      !> The facets' tractions (dim, nfacet); for a pressure facet, p in row 1.
      real(wp), intent(in), optional :: facet_traction(:, :)
      !> Patch polynomial degree (1..3; default 'auto', module notes); expansion rounds (>= 0).
      integer, intent(in), optional :: degree, max_rounds
      !> Name array entries in messages as C does (the C and Python entries): 0-based,
      !> row-major, C argument names (default false: Fortran's gw(i, e)).
      logical, intent(in), optional :: c_indices
      !> Reference coordinates (dim, ngp, nelem) of the integration points in their elements
      !> (the element library's reference cells), if the caller has them: then they are
      !> checked (`given_coordinates`) instead of derived by Newton's method.
      real(wp), intent(in), optional, target :: gauss_xi(:, :, :)
      !> The convention of gauss_xi: mesh_reference_unit (default: quads and hexes on
      !> [0, 1]^dim) or mesh_reference_symmetric ([-1, 1]^dim); simplices are the unit simplex
      !> in both.
      integer, intent(in), optional :: reference
      !> Contact facets (nfn, ncontact), element sides as facet_nodes; per facet the law (0
      !> open, contact_law_frictionless, _slip, _stick), the slip direction (dim, ncontact;
      !> read for slip) and the pair (>= 1, passed to the solver); the solver of the contact
      !> patches (module notes). All or none; validated by the caller (the contact entry)
      !> except for being element sides.
      integer, intent(in), optional :: contact_facets(:, :), contact_law(:), contact_pair(:)
      real(wp), intent(in), optional :: contact_slip(:, :)
      class(mesh_contact_solver_type), intent(in), optional, target :: contact_solver
      type(topology_type), target :: topo
      type(rule_type) :: rule
      real(wp), allocatable :: xi(:, :, :)
      real(wp), allocatable, target :: xi_unit(:, :, :)
      real(wp), pointer, contiguous :: gxi(:, :, :)
      integer :: deg, rounds, ref, st
      logical :: ci
      real(wp) :: t(0:6), c(0:1)

      deg = auto_degree(method == mesh_method_sprc, element_degree(element_type))
      if (present(degree)) deg = degree
      rounds = mesh_default_max_rounds
      if (present(max_rounds)) rounds = max_rounds
      ci = .false.
      if (present(c_indices)) ci = c_indices
      ref = mesh_reference_unit
      if (present(reference)) ref = reference
      t(0) = wall_time()
      call cpu_time(c(0))
      call check_mesh_options(dim, analysis, element_type, method, deg, rounds, young, poisson, error)
      if (allocated(error)) return
      if (ref /= mesh_reference_unit .and. ref /= mesh_reference_symmetric) then
         call fatal_error(error, 'recover_on_mesh: reference = '//itoa(ref)//' is not unit ('// &
            & itoa(mesh_reference_unit)//') or symmetric ('//itoa(mesh_reference_symmetric)//')', stat_invalid_input)
         return
      end if
      call check_mesh_arrays(dim, analysis, nodes, element_type, connectivity, gp, gw, gs, ci, error, body_force)
      if (allocated(error)) return
      call check_mesh_facets(dim, element_type, size(nodes, 2), ci, error, facet_nodes, facet_kind, facet_traction)
      if (allocated(error)) return
      t(1) = wall_time()

      call init_result(result, dim, analysis, element_type, method, deg, young, poisson, nodes, connectivity, error)
      if (allocated(error)) return
      result%c_indices = ci
      call node_elements(result, topo, error)
      if (allocated(error)) return
      call check_duplicate_nodes(nodes, topo%ne_ptr(2:) > topo%ne_ptr(:size(nodes, 2)), ci, error)
      if (allocated(error)) return
      call check_duplicate_elements(connectivity, result%nvertex, topo%ne_ptr, topo%ne_list, ci, error)
      if (allocated(error)) return
      if (present(body_force)) topo%body_force(1:dim) = body_force
      call boundary_points(result, topo, error, facet_nodes, facet_kind, facet_traction)
      if (allocated(error)) return
      if (present(contact_facets)) then
         call add_contact_points(result, topo, contact_facets, contact_law, contact_slip, contact_pair, error)
         if (allocated(error)) return
      end if
      t(2) = wall_time()
      call cpu_time(c(1))
      result%cpu_setup = c(1) - c(0)
      ! The caller's reference coordinates are used in place (checked, not copied), or on
      ! [-1, 1]^dim mapped onto the element library's [0, 1]^dim once.
      if (present(gauss_xi)) then
         gxi => gauss_xi
         if (ref == mesh_reference_symmetric .and. .not. element_simplex(element_type)) then
            allocate (xi_unit, mold=gauss_xi, stat=st)
            call check_allocation(st, 'recover_on_mesh', 'the reference coordinates on [0, 1]', size(gauss_xi), 8, error)
            if (allocated(error)) return
            xi_unit = 0.5_wp*(gauss_xi + 1.0_wp)
            gxi => xi_unit
         end if
         call given_coordinates(result, gp, gxi, rule, error, ref, gauss_xi)
      else
         call point_coordinates(result, gp, xi, error)
      end if
      if (allocated(error)) return
      t(3) = wall_time()
      if (present(contact_solver)) then
         call recover_patches(result, topo, gp, gw, gs, rounds, error, contact_solver)
      else
         call recover_patches(result, topo, gp, gw, gs, rounds, error)
      end if
      if (allocated(error)) return
      t(4) = wall_time()
      call nodal_values(result, topo, error)
      if (allocated(error)) return
      t(5) = wall_time()
      if (present(gauss_xi)) then
         call estimate(result, gp, gw, gs, gxi, rule, error)
      else
         call estimate(result, gp, gw, gs, xi, rule, error)
      end if
      t(6) = wall_time()
      result%t_check = t(1) - t(0)
      result%t_topology = t(2) - t(1)
      result%t_points = t(3) - t(2)
      result%t_patches = t(4) - t(3)
      result%t_nodal = t(5) - t(4)
      result%t_estimate = t(6) - t(5)
   end subroutine recover_on_mesh

   subroutine init_result(r, dim, analysis, element_type, method, deg, young, poisson, nodes, connectivity, error)
      type(mesh_recovery_type), intent(inout) :: r
      integer, intent(in) :: dim, analysis, element_type, method, deg
      real(wp), intent(in) :: young, poisson, nodes(:, :)
      integer, intent(in) :: connectivity(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: e, a, st
      real(wp) :: lo(3), hi(3)

      r%dim = dim
      r%analysis = analysis
      r%element_type = element_type
      r%method = method
      r%degree = deg
      r%nstress = voigt_size(analysis)
      r%nnode = size(nodes, 2)
      r%nelem = size(connectivity, 2)
      r%nen = element_nodes(element_type)
      r%nvertex = element_vertices(element_type)
      r%young = young
      r%poisson = poisson
      if (allocated(r%x)) deallocate (r%x)
      if (allocated(r%connectivity)) deallocate (r%connectivity)
      allocate (r%x, source=nodes, stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the node coordinates', r%nnode, 8*dim, error)
      if (allocated(error)) return
      allocate (r%connectivity, source=connectivity, stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the connectivity', r%nelem, 4*size(connectivity, 1), error)
      if (allocated(error)) return
      allocate (r%box_lo(dim, r%nelem), r%box_hi(dim, r%nelem), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the element boxes', r%nelem, 16*dim, error)
      if (allocated(error)) return
      !$omp parallel do schedule(static) private(a, lo, hi)
      do e = 1, r%nelem
         ! In fixed-length scalars (run-time length dim made memcpy calls and short loops).
         lo = huge(1.0_wp)
         hi = -huge(1.0_wp)
         do a = 1, r%nen
            lo(1:2) = min(lo(1:2), nodes(1:2, connectivity(a, e)))
            hi(1:2) = max(hi(1:2), nodes(1:2, connectivity(a, e)))
            if (dim == 3) then
               lo(3) = min(lo(3), nodes(3, connectivity(a, e)))
               hi(3) = max(hi(3), nodes(3, connectivity(a, e)))
            end if
         end do
         r%box_lo(1:2, e) = lo(1:2)
         r%box_hi(1:2, e) = hi(1:2)
         if (dim == 3) then
            r%box_lo(3, e) = lo(3)
            r%box_hi(3, e) = hi(3)
         end if
      end do
      !$omp end parallel do
   end subroutine init_result

   !> Node -> element CSR (elements ascending per node); patches at the vertex nodes.
   subroutine node_elements(r, topo, error)
      type(mesh_recovery_type), intent(inout) :: r
      type(topology_type), intent(inout) :: topo
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: fill(:)
      logical, allocatable :: vertex(:)
      integer :: e, a, n, st

      allocate (topo%ne_ptr(r%nnode + 1), fill(r%nnode), vertex(r%nnode), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the node-element pointers', r%nnode + 1, 12, error)
      if (allocated(error)) return
      ! Loops, not fill(connectivity(:, e)): that vector subscript made a heap temporary per
      ! element.
      fill = 0
      vertex = .false.
      do e = 1, r%nelem
         do a = 1, r%nen
            n = r%connectivity(a, e)
            fill(n) = fill(n) + 1
            if (a <= r%nvertex) vertex(n) = .true.
         end do
      end do
      topo%ne_ptr(1) = 1
      do n = 1, r%nnode
         topo%ne_ptr(n + 1) = topo%ne_ptr(n) + fill(n)
      end do
      allocate (topo%ne_list(topo%ne_ptr(r%nnode + 1) - 1), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the node-element list', topo%ne_ptr(r%nnode + 1) - 1, 4, error)
      if (allocated(error)) return
      fill = 0
      do e = 1, r%nelem
         do a = 1, r%nen
            n = r%connectivity(a, e)
            topo%ne_list(topo%ne_ptr(n) + fill(n)) = e
            fill(n) = fill(n) + 1
         end do
      end do
      r%n_patches = count(vertex)
      allocate (r%patch_node(r%n_patches), r%patch_of_node(r%nnode), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the patch of each node', r%nnode, 8, error)
      if (allocated(error)) return
      r%patch_of_node = 0
      r%n_patches = 0
      do n = 1, r%nnode
         if (.not. vertex(n)) cycle
         r%n_patches = r%n_patches + 1
         r%patch_node(r%n_patches) = n
         r%patch_of_node(n) = r%n_patches
      end do
   end subroutine node_elements

   !> Reference coordinates of every integration point in its element, computed once here
   !> (the estimate reuses them). Newton starts from the point's coordinates in element 1
   !> (a caller's rule is usually the same in every element: then one step confirms them),
   !> from the centroid if that fails. OpenMP over elements; the guess does not depend on
   !> the schedule, so neither do the bits. The first failing point (element order) is named.
   subroutine point_coordinates(r, gp, xi, error)
      type(mesh_recovery_type), intent(in) :: r
      real(wp), intent(in) :: gp(:, :, :)
      real(wp), allocatable, intent(out) :: xi(:, :, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: guess(:, :)
      integer, allocatable :: bad(:)
      integer :: e, i, ngp, st

      ngp = size(gp, 2)
      allocate (xi(r%dim, ngp, r%nelem), bad(r%nelem), guess(r%dim, ngp), stat=st)
      if (st /= 0) then
         call fatal_error(error, 'recover_on_mesh: out of memory for the reference coordinates', stat_out_of_memory)
         return
      end if
      bad(1) = map_element(1)
      guess = xi(:, :, 1)
      if (bad(1) /= 0) guess = 0.5_wp
      !$omp parallel do schedule(static)
      do e = 2, r%nelem
         bad(e) = map_element(e, guess)
      end do
      !$omp end parallel do
      if (all(bad == 0)) return
      e = findloc(bad /= 0, .true., dim=1)
      i = abs(bad(e))
      if (bad(e) < 0) then
         call fatal_error(error, 'recover_on_mesh: the inverse map of '//point_name(i, e)// &
            & ' did not converge (distorted or inverted element '//index_name(r%c_indices, e)//'?)', &
            & stat_not_converged)
      else
         call fatal_error(error, 'recover_on_mesh: '//point_name(i, e)//' is not inside element '// &
            & index_name(r%c_indices, e)//' (reference coordinates '//vec_str(xi(:, i, e))//')', &
            & stat_invalid_input)
      end if
   contains
      !> 0, or -i (point i did not converge), or i (point i is outside).
      integer function map_element(e, start) result(status)
         integer, intent(in) :: e
         real(wp), intent(in), optional :: start(:, :)
         real(wp) :: xe(3, max_element_nodes)
         logical :: ok
         integer :: a, j

         do a = 1, r%nen
            xe(1:r%dim, a) = r%x(:, r%connectivity(a, e))
         end do
         status = 0
         do j = 1, ngp
            ok = .false.
            if (present(start)) then
               call element_inverse_map(r%element_type, xe, gp(:, j, e), xi(:, j, e), ok, start(:, j))
               ! A curved element's map may have a root outside it too: then from the centroid.
               if (ok) ok = element_inside(r%element_type, xi(:, j, e), inside_tol)
            end if
            if (.not. ok) call element_inverse_map(r%element_type, xe, gp(:, j, e), xi(:, j, e), ok)
            if (.not. ok) then
               status = -j
            else if (.not. element_inside(r%element_type, xi(:, j, e), inside_tol)) then
               status = j
            end if
            if (status /= 0) return
         end do
      end function map_element
      pure function point_name(i, e) result(s)
         integer, intent(in) :: i, e
         character(len=:), allocatable :: s
         s = entry_name(r%c_indices, 'gp', 'gauss_points', [0, i, e])
      end function point_name
   end subroutine point_coordinates

   !> The caller's reference coordinates gxi of the integration points, checked: finite,
   !> inside the element (inside_tol, as a derived point must be) and mapped onto the point:
   !> |x(gxi) - gp|_inf <= inside_tol h_e + (nen + 2) eps (|gp| + sum_a |N_a| |x_a|), with h_e
   !> the largest extent of the element's box (inside_tol in reference units, which the map
   !> stretches by about h_e) plus the round-off of evaluating the map (as in Newton's stopping
   !> test, sprc_recovery_caller_mesh_element). `rule`: the shape values of element 1's points, and
   !> whether every element has the same points (then its shape values serve every element).
   !> OpenMP over elements; the first bad point (element order) is named.
   subroutine given_coordinates(r, gp, gxi, rule, error, reference, shown)
      type(mesh_recovery_type), intent(in) :: r
      real(wp), intent(in) :: gp(:, :, :), gxi(:, :, :)
      type(rule_type), intent(out) :: rule
      type(error_type), allocatable, intent(out) :: error
      !> The caller's convention and coordinates (gxi mapped onto [0, 1]^dim), for messages.
      integer, intent(in) :: reference
      real(wp), intent(in) :: shown(:, :, :)
      character(len=:), allocatable :: what
      integer, allocatable :: bad(:)
      logical, allocatable :: ok1(:)
      real(wp), allocatable :: nsum1(:)
      logical :: shared
      integer :: e, i, ngp, st

      ngp = size(gp, 2)
      if (any(shape(gxi) /= [r%dim, ngp, r%nelem])) then
         call fatal_error(error, 'recover_on_mesh: '//trim(merge('gauss_xi', 'gxi     ', r%c_indices))//' has shape '// &
            & shape_str(shape(gxi))//'; need '//shape_str([r%dim, ngp, r%nelem])//' as gp', stat_invalid_input)
         return
      end if
      allocate (bad(r%nelem), rule%map(max_element_nodes, ngp), rule%n(max_element_nodes, ngp), ok1(ngp), &
         & nsum1(ngp), stat=st)
      if (st /= 0) then
         call fatal_error(error, 'recover_on_mesh: out of memory for the check of the reference coordinates', &
            & stat_out_of_memory)
         return
      end if
      ! Element 1's points: what an element with the same bits shares (the outcome of the
      ! point checks, the shape values and their sum of magnitudes).
      do i = 1, ngp
         ok1(i) = point_ok(gxi(:, i, 1))
         call element_shape(r%element_type, gxi(:, i, 1), rule%map(:, i))
         call method_shape(r, gxi(:, i, 1), rule%n(:, i))
         nsum1(i) = sum(abs(rule%map(1:r%nen, i)))
      end do
      shared = .true.
      !$omp parallel do schedule(static) reduction(.and.:shared)
      do e = 1, r%nelem
         bad(e) = check_element(e, shared)
      end do
      !$omp end parallel do
      rule%shared = shared
      if (all(bad == 0)) return
      e = findloc(bad /= 0, .true., dim=1)
      i = bad(e)
      if (.not. all(abs(gxi(:, i, e)) <= huge(1.0_wp))) then
         what = ' is not finite'
      else if (.not. point_ok(gxi(:, i, e))) then
         what = ' is outside the reference cell '//reference_cell_name(r%element_type, reference)// &
            & ' (tolerance 1e-6 on [0, 1])'
      else
         what = ' is inside the reference cell but does not map onto '// &
            & entry_name(r%c_indices, 'gp', 'gauss_points', [0, i, e])//' = '//vec_str(gp(:, i, e))// &
            & ' in element '//index_name(r%c_indices, e)
      end if
      call fatal_error(error, 'recover_on_mesh: '//entry_name(r%c_indices, 'gxi', 'gauss_xi', [0, i, e])//' = '// &
         & vec_str(shown(:, i, e))//what, stat_invalid_input)
   contains
      !> 0, or the first point of e whose coordinates fail; shared = .false. if e's points
      !> differ from element 1's.
      integer function check_element(e, shared) result(status)
         integer, intent(in) :: e
         logical, intent(inout) :: shared
         real(wp) :: xe(3, max_element_nodes), n(max_element_nodes), x(3), he, xmax, tol, nsum, gmax, dev
         integer :: a, j, d, nen
         logical :: same

         d = r%dim
         nen = r%nen
         ! Fixed-length copies (run-time length d became a memcpy call per node).
         do a = 1, nen
            xe(1:2, a) = r%x(1:2, r%connectivity(a, e))
            xe(3, a) = 0.0_wp
            if (d == 3) xe(3, a) = r%x(3, r%connectivity(a, e))
         end do
         he = maxval(r%box_hi(:, e) - r%box_lo(:, e))
         xmax = maxval(abs(xe(1:d, 1:nen)))
         same = same_bits(gxi(:, :, e), gxi(:, :, 1))
         shared = shared .and. same
         status = 0
         do j = 1, ngp
            status = j
            if (same) then
               if (.not. ok1(j)) return
               call map_point(xe, rule%map(:, j), x)
               nsum = nsum1(j)
            else
               if (.not. point_ok(gxi(:, j, e))) return
               call element_shape(r%element_type, gxi(:, j, e), n)
               call map_point(xe, n, x)
               nsum = sum(abs(n(1:nen)))
            end if
            gmax = max(abs(gp(1, j, e)), abs(gp(2, j, e)))
            dev = max(abs(x(1) - gp(1, j, e)), abs(x(2) - gp(2, j, e)))
            if (d == 3) then
               gmax = max(gmax, abs(gp(3, j, e)))
               dev = max(dev, abs(x(3) - gp(3, j, e)))
            end if
            tol = inside_tol*he + real(nen + 2, wp)*epsilon(1.0_wp)*(gmax + nsum*xmax)
            if (.not. (dev <= tol)) return
            status = 0
         end do
      end function check_element
      !> x = sum_a xe(:, a) n(a) in three scalar sums (x(1:d) in memory stalled on store
      !> forwarding); n is used in place (a copy of run-time length is a memcpy call).
      pure subroutine map_point(xe, n, x)
         real(wp), intent(in) :: xe(:, :), n(:)
         real(wp), intent(out) :: x(3)
         integer :: a
         x = 0.0_wp
         do a = 1, r%nen
            x(1) = x(1) + xe(1, a)*n(a)
            x(2) = x(2) + xe(2, a)*n(a)
            x(3) = x(3) + xe(3, a)*n(a)
         end do
      end subroutine map_point
      !> Finite and inside the reference element (inside_tol).
      pure logical function point_ok(xi)
         real(wp), intent(in) :: xi(:)
         point_ok = all(abs(xi) <= huge(1.0_wp))
         if (point_ok) point_ok = element_inside(r%element_type, xi, inside_tol)
      end function point_ok
      pure function shape_str(v) result(s)
         integer, intent(in) :: v(:)
         character(len=:), allocatable :: s
         s = '('//itoa(v(1))//', '//itoa(v(2))//', '//itoa(v(3))//')'
         if (r%c_indices) s = '['//itoa(v(3))//']['//itoa(v(2))//']['//itoa(v(1))//']'
      end function shape_str
   end subroutine given_coordinates

   !> True if a and b (same shape) hold the same bits (+0 and -0 differ: so do their shape
   !> values' signs of zero).
   pure logical function same_bits(a, b)
      real(wp), intent(in) :: a(:, :), b(:, :)
      integer :: i, j
      same_bits = .false.
      do j = 1, size(a, 2)
         do i = 1, size(a, 1)
            if (transfer(a(i, j), 1_i8) /= transfer(b(i, j), 1_i8)) return
         end do
      end do
      same_bits = .true.
   end function same_bits

   !> Quadrature points of the facets, gathered per owning element (CSR), normals outward.
   subroutine boundary_points(r, topo, error, facet_nodes, facet_kind, facet_traction_value)
      type(mesh_recovery_type), intent(inout) :: r
      type(topology_type), intent(inout) :: topo
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: facet_nodes(:, :), facet_kind(:)
      real(wp), intent(in), optional :: facet_traction_value(:, :)
      integer, allocatable :: owner(:), fill(:), ordered(:, :)
      real(wp) :: xq(3, max_facet_points), wq(max_facet_points), nq(3, max_facet_points)
      integer :: nf, nfn, f, e, q, nq_f, k, d, st

      d = r%dim
      nf = 0
      if (present(facet_nodes)) nf = size(facet_nodes, 2)
      nfn = element_facet_nodes(r%element_type)
      allocate (owner(nf), ordered(nfn, nf), fill(r%nelem), topo%bptr(r%nelem + 1), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the facet owners and boundary pointers', &
         & (nfn + 1)*nf + 2*r%nelem + 1, 4, error)
      if (allocated(error)) return
      fill = 0
      do f = 1, nf
         call facet_owner(r, topo, facet_nodes(:, f), f, owner(f), ordered(:, f), error, 'facet_nodes')
         if (allocated(error)) return
         fill(owner(f)) = fill(owner(f)) + 1
      end do
      nq_f = facet_npoints(nfn)
      topo%bptr(1) = 1
      do e = 1, r%nelem
         topo%bptr(e + 1) = topo%bptr(e) + nq_f*fill(e)
      end do
      k = topo%bptr(r%nelem + 1) - 1
      if (nf == 0) k = 0
      r%n_boundary_points = k
      allocate (topo%bx(d, k), topo%bw(k), topo%bn(d, k), topo%bt(d, k), topo%bkind(k), topo%bpiece(k), &
         & topo%blaw(k), topo%bpair(k), topo%bslip(d, k), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the boundary points', k, 32*d + 24, error)
      if (allocated(error)) return
      topo%blaw = 0
      topo%bpair = 0
      topo%bslip = 0.0_wp
      fill = 0
      do f = 1, nf
         e = owner(f)
         call facet_quadrature(r, e, ordered(:, f), f, 'facet', nq_f, xq, wq, nq, error)
         if (allocated(error)) return
         do q = 1, nq_f
            k = topo%bptr(e) + fill(e)
            fill(e) = fill(e) + 1
            topo%bx(:, k) = xq(1:d, q)
            topo%bw(k) = wq(q)
            topo%bn(:, k) = nq(1:d, q)
            topo%bt(:, k) = 0.0_wp
            select case (facet_kind(f))
            case (facet_traction)
               topo%bkind(k) = boundary_traction
               topo%bt(:, k) = facet_traction_value(:, f)
               topo%bpiece(k) = 1
            case (facet_pressure)
               ! The facet's own outward normal at this point: the traction turns with it.
               topo%bkind(k) = boundary_traction
               topo%bt(:, k) = -facet_traction_value(1, f)*topo%bn(:, k)
               topo%bpiece(k) = 1
            case (facet_free)
               topo%bkind(k) = boundary_traction
               topo%bpiece(k) = 1
            case default
               topo%bkind(k) = boundary_symmetry
               topo%bpiece(k) = 2
            end select
         end do
      end do
   end subroutine boundary_points

   !> The quadrature points of facet f (nodes `ordered`, a side of element e): coordinates,
   !> weights, normals pointing away from e's vertex centroid. `what` names the facet in
   !> the error of a degenerate one.
   subroutine facet_quadrature(r, e, ordered, f, what, nq_f, xq, wq, nq, error)
      type(mesh_recovery_type), intent(in) :: r
      integer, intent(in) :: e, ordered(:), f
      character(len=*), intent(in) :: what
      integer, intent(out) :: nq_f
      real(wp), intent(out) :: xq(:, :), wq(:), nq(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: c(3)
      integer :: d, q

      d = r%dim
      call facet_points(d, size(ordered), r%x(:, ordered), nq_f, xq, wq, nq)
      if (.not. all(wq(1:nq_f) > 0.0_wp)) then
         call fatal_error(error, 'recover_on_mesh: '//what//' '//index_name(r%c_indices, f)// &
            & ' is degenerate (zero length or area)', stat_invalid_input)
         return
      end if
      c(1:d) = sum(r%x(:, r%connectivity(1:r%nvertex, e)), dim=2)/real(r%nvertex, wp)
      do q = 1, nq_f
         if (dot_product(xq(1:d, q) - c(1:d), nq(1:d, q)) < 0.0_wp) nq(1:d, q) = -nq(1:d, q)
      end do
   end subroutine facet_quadrature

   !> Append the quadrature points of the contact facets to the boundary points (CSR per
   !> element, after the facets' own): kind boundary_contact where the law is closed, a free
   !> surface (zero traction, piece 1) where it is open (module notes).
   subroutine add_contact_points(r, topo, cfacets, claw, cslip, cpair, error)
      type(mesh_recovery_type), intent(inout) :: r
      type(topology_type), intent(inout) :: topo
      integer, intent(in) :: cfacets(:, :), claw(:), cpair(:)
      real(wp), intent(in) :: cslip(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: owner(:), ordered(:, :), cnt(:), ptr(:), perm(:)
      real(wp) :: xq(3, max_facet_points), wq(max_facet_points), nq(3, max_facet_points)
      integer :: nc, f, e, q, nq_f, k, j, d, nb, st
      type(topology_type) :: old

      d = r%dim
      nc = size(cfacets, 2)
      allocate (owner(nc), ordered(size(cfacets, 1), nc), cnt(r%nelem), ptr(r%nelem + 1), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the contact facet owners', nc + r%nelem, 8, error)
      if (allocated(error)) return
      cnt = 0
      do f = 1, nc
         call facet_owner(r, topo, cfacets(:, f), f, owner(f), ordered(:, f), error, 'contact_facets')
         if (allocated(error)) return
         cnt(owner(f)) = cnt(owner(f)) + 1
      end do
      nq_f = facet_npoints(size(cfacets, 1))
      ! New CSR: each element's old points, then its contact points (in facet order).
      ptr(1) = 1
      do e = 1, r%nelem
         ptr(e + 1) = ptr(e) + (topo%bptr(e + 1) - topo%bptr(e)) + nq_f*cnt(e)
      end do
      nb = ptr(r%nelem + 1) - 1
      call move_alloc(topo%bptr, old%bptr)
      call move_alloc(topo%bx, old%bx)
      call move_alloc(topo%bw, old%bw)
      call move_alloc(topo%bn, old%bn)
      call move_alloc(topo%bt, old%bt)
      call move_alloc(topo%bkind, old%bkind)
      call move_alloc(topo%bpiece, old%bpiece)
      call move_alloc(topo%blaw, old%blaw)
      call move_alloc(topo%bpair, old%bpair)
      call move_alloc(topo%bslip, old%bslip)
      allocate (topo%bx(d, nb), topo%bw(nb), topo%bn(d, nb), topo%bt(d, nb), topo%bkind(nb), topo%bpiece(nb), &
         & topo%blaw(nb), topo%bpair(nb), topo%bslip(d, nb), perm(r%nelem), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the boundary and contact points', nb, 32*d + 24, error)
      if (allocated(error)) return
      do e = 1, r%nelem
         k = ptr(e)
         do j = old%bptr(e), old%bptr(e + 1) - 1
            topo%bx(:, k) = old%bx(:, j)
            topo%bw(k) = old%bw(j)
            topo%bn(:, k) = old%bn(:, j)
            topo%bt(:, k) = old%bt(:, j)
            topo%bkind(k) = old%bkind(j)
            topo%bpiece(k) = old%bpiece(j)
            topo%blaw(k) = 0
            topo%bpair(k) = 0
            topo%bslip(:, k) = 0.0_wp
            k = k + 1
         end do
         perm(e) = k
      end do
      call move_alloc(ptr, topo%bptr)
      do f = 1, nc
         e = owner(f)
         call facet_quadrature(r, e, ordered(:, f), f, 'contact facet', nq_f, xq, wq, nq, error)
         if (allocated(error)) return
         do q = 1, nq_f
            k = perm(e)
            perm(e) = k + 1
            topo%bx(:, k) = xq(1:d, q)
            topo%bw(k) = wq(q)
            topo%bn(:, k) = nq(1:d, q)
            topo%bt(:, k) = 0.0_wp
            topo%blaw(k) = claw(f)
            topo%bpair(k) = cpair(f)
            topo%bslip(:, k) = cslip(1:d, f)
            topo%bpiece(k) = 1
            topo%bkind(k) = merge(boundary_contact, boundary_traction, claw(f) /= 0)
         end do
      end do
      r%n_boundary_points = nb
   end subroutine add_contact_points

   !> The quadrature points of the facets facet_nodes(:, f) (nfn, nfacet; element sides, any
   !> node order) of a caller's mesh as the recovery builds them: x(dim, nq nfacet), weights
   !> w, outward normals n, the owner element and facet of each point (`fname` names the
   !> array in messages). Errors as recover_on_mesh's for facets and the mesh.
   subroutine mesh_facet_points(dim, nodes, element_type, connectivity, facet_nodes, c_indices, fname, x, w, n, &
         & owner_elem, facet_of, error)
      integer, intent(in) :: dim, element_type
      real(wp), intent(in) :: nodes(:, :)
      integer, intent(in) :: connectivity(:, :), facet_nodes(:, :)
      logical, intent(in) :: c_indices
      character(len=*), intent(in) :: fname
      real(wp), allocatable, intent(out) :: x(:, :), w(:), n(:, :)
      integer, allocatable, intent(out) :: owner_elem(:), facet_of(:)
      type(error_type), allocatable, intent(out) :: error
      type(mesh_recovery_type) :: r
      type(topology_type) :: topo
      real(wp) :: xq(3, max_facet_points), wq(max_facet_points), nq(3, max_facet_points)
      integer :: ordered(size(facet_nodes, 1)), f, e, nq_f, k, nf, st

      call init_result(r, dim, solid_or_plane(dim), element_type, mesh_method_spr, 1, 1.0_wp, 0.0_wp, nodes, &
         & connectivity, error)
      if (allocated(error)) return
      r%c_indices = c_indices
      call node_elements(r, topo, error)
      if (allocated(error)) return
      nf = size(facet_nodes, 2)
      nq_f = facet_npoints(size(facet_nodes, 1))
      allocate (x(dim, nq_f*nf), w(nq_f*nf), n(dim, nq_f*nf), owner_elem(nq_f*nf), facet_of(nq_f*nf), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the facet points', nq_f*nf, 16*dim + 16, error)
      if (allocated(error)) return
      k = 0
      do f = 1, nf
         call facet_owner(r, topo, facet_nodes(:, f), f, e, ordered, error, fname)
         if (allocated(error)) return
         call facet_quadrature(r, e, ordered, f, fname, nq_f, xq, wq, nq, error)
         if (allocated(error)) return
         x(:, k + 1:k + nq_f) = xq(1:dim, 1:nq_f)
         w(k + 1:k + nq_f) = wq(1:nq_f)
         n(:, k + 1:k + nq_f) = nq(1:dim, 1:nq_f)
         owner_elem(k + 1:k + nq_f) = e
         facet_of(k + 1:k + nq_f) = f
         k = k + nq_f
      end do
   contains
      pure integer function solid_or_plane(d)
         integer, intent(in) :: d
         solid_or_plane = merge(solid, plane_stress, d == 3)
      end function solid_or_plane
   end subroutine mesh_facet_points

   !> The one element that has the facet as a side (face), its nodes in any order
   !> (element_facet_order), and the facet's nodes in an order that parametrises it.
   !> Candidates are the elements of the facet's first node (node -> element CSR): O(valence).
   subroutine facet_owner(r, topo, fnodes, f, owner, ordered, error, fname)
      type(mesh_recovery_type), intent(in) :: r
      type(topology_type), intent(in) :: topo
      integer, intent(in) :: fnodes(:), f
      !> The caller's array of the facet (facet_nodes, contact_facets), for messages.
      character(len=*), intent(in) :: fname
      integer, intent(out) :: owner, ordered(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: k, e, a, b, n, holder, loc(max_element_nodes), perm(max_element_nodes)
      logical :: side

      n = size(fnodes)
      owner = 0
      holder = 0
      do a = 2, n
         do b = 1, a - 1
            if (fnodes(a) /= fnodes(b)) cycle
            call fatal_error(error, 'recover_on_mesh: '//word()//' '//index_name(r%c_indices, f)//' is degenerate: '// &
               & facet_name()//' repeats node '//index_name(r%c_indices, fnodes(a)), stat_invalid_input)
            return
         end do
      end do
      do k = topo%ne_ptr(fnodes(1)), topo%ne_ptr(fnodes(1) + 1) - 1
         e = topo%ne_list(k)
         do a = 1, n
            loc(a) = findloc(r%connectivity(:, e), fnodes(a), dim=1)
            if (loc(a) == 0) exit
         end do
         if (a <= n) cycle
         holder = e
         call element_facet_order(r%element_type, loc(1:n), perm(1:n), side)
         if (.not. side) cycle
         if (owner /= 0) then
            call fatal_error(error, 'recover_on_mesh: '//word()//' '//index_name(r%c_indices, f)//' is shared by elements '// &
               & index_name(r%c_indices, owner)//' and '//index_name(r%c_indices, e)//': not a boundary facet ('// &
               & facet_name()//')', stat_invalid_input)
            return
         end if
         owner = e
         ordered = fnodes(perm(1:n))
      end do
      if (owner /= 0) return
      if (holder /= 0) then
         call fatal_error(error, 'recover_on_mesh: '//word()//' '//index_name(r%c_indices, f)//' is not a side of any '// &
            & 'element: '//facet_name()//' are nodes of element '//index_name(r%c_indices, holder)//' but not one of its '// &
            & trim(merge('sides', 'faces', r%dim == 2))//' (a boundary facet is an element side, its nodes in any '// &
            & 'order)', stat_invalid_input)
      else
         call fatal_error(error, 'recover_on_mesh: '//word()//' '//index_name(r%c_indices, f)//' is not a side of any '// &
            & 'element: '//facet_name()//' are not the nodes of one element', stat_invalid_input)
      end if
   contains
      !> The facet as the caller wrote it (only for messages: facets are many).
      pure function facet_name() result(s)
         character(len=:), allocatable :: s
         s = entry_name(r%c_indices, fname, fname, [0, f])//' = ('//ivec_str(r%c_indices, fnodes)//')'
      end function facet_name
      !> 'facet' or 'contact facet'.
      pure function word() result(s)
         character(len=:), allocatable :: s
         s = 'facet'
         if (fname /= 'facet_nodes') s = 'contact facet'
      end function word
   end subroutine facet_owner

   !> The shared patch loop (sprc_recovery_patch_loop) over the vertex nodes; a failing
   !> patch is named by its node.
   subroutine recover_patches(r, topo, gp, gw, gs, rounds, error, contact)
      type(mesh_recovery_type), intent(inout), target :: r
      type(topology_type), intent(in), target :: topo
      real(wp), intent(in), target, contiguous :: gp(:, :, :), gw(:, :), gs(:, :, :)
      integer, intent(in) :: rounds
      type(error_type), allocatable, intent(out) :: error
      class(mesh_contact_solver_type), intent(in), optional, target :: contact
      type(mesh_source_type) :: src
      type(patch_loop_type) :: opt
      integer :: ip, n, st

      src%dim = r%dim
      src%analysis = r%analysis
      src%nstress = r%nstress
      src%nen = r%nen
      src%sprc = r%method == mesh_method_sprc
      src%young = r%young
      src%poisson = r%poisson
      src%x => r%x
      src%connectivity => r%connectivity
      src%topo => topo
      src%gp => gp
      src%gw => gw
      src%gs => gs
      if (present(contact)) src%contact => contact
      src%c_indices = r%c_indices
      opt = patch_loop_type(dim=r%dim, degree=r%degree, rounds_limit=rounds, sprc=src%sprc)
      opt%cap = patch_capacity(src, r%dim, r%degree, topo%ne_ptr, topo%ne_list, r%patch_node)
      allocate (r%patch_rounds(r%n_patches), r%patch_elements(r%n_patches), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the patch counts', r%n_patches, 8, error)
      if (allocated(error)) return
      if (keeps_records(r)) then
         allocate (r%recs(r%n_patches), stat=st)
         call check_allocation(st, 'recover_on_mesh', 'the patch records', r%n_patches, storage_size(r%recs)/8, error)
         if (allocated(error)) return
         call run_patch_loop(opt, src, topo%ne_ptr, topo%ne_list, r%connectivity, r%patch_node, r%recs, &
            & r%patch_rounds, r%patch_elements, ip, error)
         if (.not. allocated(error)) r%n_tolerance_bites = count(r%recs%tolerance_bites)
      else
         call patches_to_nodal(r, topo, opt, src, ip, error)
      end if
      if (allocated(error)) then
         if (ip == 0) return
         n = r%patch_node(ip)
         if (error%stat == stat_singular) then
            error%message = 'recover_on_mesh: patch of node '//index_name(r%c_indices, n)//' at '// &
               & vec_str(r%x(:, n))//', '//itoa(r%patch_elements(ip))//' elements after '// &
               & itoa(r%patch_rounds(ip))//' expansion rounds: '//error%message
         else
            error%message = 'recover_on_mesh: patch of node '//index_name(r%c_indices, n)//': '//error%message
         end if
         return
      end if
      r%n_expanded = count(r%patch_rounds > 0)
      r%max_rounds_used = 0
      if (r%n_patches > 0) r%max_rounds_used = maxval(r%patch_rounds)
   end subroutine recover_patches

   !> Whether the result keeps every patch's record: SPR-C (its field is the union of the
   !> patches, eq. 102), and elements with nodes besides the vertices (their nodal values are
   !> the union). SPR on linear elements needs the patches only for the nodal values (its field
   !> is their interpolation, eq. 101): `patches_to_nodal` keeps none.
   pure logical function keeps_records(r)
      type(mesh_recovery_type), intent(in) :: r
      keeps_records = r%method /= mesh_method_spr .or. r%nen /= r%nvertex
   end function keeps_records

   !> The patch loop in chunks of patch_chunk patches into one buffer of records, each
   !> chunk's nodal values taken from its records at once: the records of a whole mesh (a
   !> few hundred bytes per patch, and a heap block for each one's coefficients) are never
   !> allocated and the nodal values are evaluated while the records are in cache. Same
   !> solves, same values, as the loop over all patches. ip: the failing patch, as
   !> run_patch_loop's (0 if none).
   subroutine patches_to_nodal(r, topo, opt, src, ip, error)
      type(mesh_recovery_type), intent(inout) :: r
      type(topology_type), intent(in) :: topo
      type(patch_loop_type), intent(in) :: opt
      type(mesh_source_type), intent(in) :: src
      integer, intent(out) :: ip
      type(error_type), allocatable, intent(out) :: error
      type(recovered_patch_type), allocatable :: buf(:)
      integer :: i0, m, k, n, st

      ip = 0
      r%n_tolerance_bites = 0
      allocate (buf(min(patch_chunk, r%n_patches)), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the patch records of a chunk', min(patch_chunk, r%n_patches), &
         & storage_size(buf)/8, error)
      if (allocated(error)) return
      allocate (r%nodal(r%nstress, r%nnode), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the nodal stresses', r%nnode, 8*r%nstress, error)
      if (allocated(error)) return
      do i0 = 1, r%n_patches, patch_chunk
         m = min(patch_chunk, r%n_patches - i0 + 1)
         call run_patch_loop(opt, src, topo%ne_ptr, topo%ne_list, r%connectivity, r%patch_node(i0:i0 + m - 1), &
            & buf(1:m), r%patch_rounds(i0:i0 + m - 1), r%patch_elements(i0:i0 + m - 1), ip, error)
         if (allocated(error)) then
            if (ip > 0) ip = i0 + ip - 1
            return
         end if
         !$omp parallel do schedule(static) private(n)
         do k = 1, m
            n = r%patch_node(i0 + k - 1)
            call eval_recovered_points(buf(k), r%x(:, n:n), r%nodal(:, n:n))
         end do
         !$omp end parallel do
         r%n_tolerance_bites = r%n_tolerance_bites + count(buf(1:m)%tolerance_bites)
      end do
   end subroutine patches_to_nodal

   !> Solve a filled patch: by the contact solver if it holds a contact point (module
   !> notes), else the default. law / slip / pair of its boundary points in mesh_fill's order.
   subroutine mesh_recover(self, node, elements, patch, degree, sprc, ws, rec, error)
      class(mesh_source_type), intent(in) :: self
      integer, intent(in) :: node, elements(:), degree
      type(patch_type), intent(in) :: patch
      logical, intent(in) :: sprc
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: law(:)
      real(wp), allocatable :: slip(:, :)
      integer :: i, j, k, pair

      if (sprc .and. associated(self%contact) .and. patch%nbpoints > 0) then
         if (any(patch%bkind(1:patch%nbpoints) == boundary_contact)) then
            allocate (law(patch%nbpoints), slip(self%dim, patch%nbpoints))
            j = 0
            pair = 0
            do i = 1, size(elements)
               do k = self%topo%bptr(elements(i)), self%topo%bptr(elements(i) + 1) - 1
                  j = j + 1
                  law(j) = self%topo%blaw(k)
                  slip(:, j) = self%topo%bslip(:, k)
                  if (self%topo%bkind(k) /= boundary_contact) cycle
                  if (pair /= 0 .and. self%topo%bpair(k) /= pair) then
                     call fatal_error(error, 'the patch holds contact points of pairs '// &
                        & index_name(self%c_indices, pair)//' and '//index_name(self%c_indices, self%topo%bpair(k))// &
                        & ': a contact patch couples one other body (give the pairs'' facets apart)', &
                        & stat_invalid_input)
                     return
                  end if
                  pair = self%topo%bpair(k)
               end do
            end do
            call self%contact%solve(pair, patch, law, slip, degree, ws, rec, error)
            return
         end if
      end if
      call recover_patch_default(self, node, elements, patch, degree, sprc, ws, rec, error)
   end subroutine mesh_recover

   !> [volume points, boundary points] the elements add to a patch.
   pure function mesh_points_of(self, elements) result(counts)
      class(mesh_source_type), intent(in) :: self
      integer, intent(in) :: elements(:)
      integer :: counts(2)
      integer :: i

      counts = [size(self%gp, 2)*size(elements), 0]
      if (.not. self%sprc) return
      do i = 1, size(elements)
         counts(2) = counts(2) + self%topo%bptr(elements(i) + 1) - self%topo%bptr(elements(i))
      end do
   end function mesh_points_of

   !> The patch of node n over the listed elements (storage reused).
   subroutine mesh_fill(self, node, elements, patch)
      class(mesh_source_type), intent(in) :: self
      integer, intent(in) :: node, elements(:)
      type(patch_type), intent(inout) :: patch
      real(wp) :: h, x0(3), dx(3)
      integer :: d, i, e, k, a, m, np, nb, ngp, ns, q

      d = self%dim
      ns = self%nstress
      ngp = size(self%gp, 2)
      ! h = the largest distance: the largest square, one root (sqrt is monotonic and
      ! correctly rounded: the same value as the largest root). Squares summed in coordinate
      ! order from zero, as sum() does, in scalars.
      ! Fixed-length copies and differences (run-time length d became memcpy calls).
      x0 = 0.0_wp
      x0(1:2) = self%x(1:2, node)
      if (d == 3) x0(3) = self%x(3, node)
      h = 0.0_wp
      nb = 0
      do i = 1, size(elements)
         e = elements(i)
         do a = 1, self%nen
            m = self%connectivity(a, e)
            dx(1:2) = self%x(1:2, m) - x0(1:2)
            dx(3) = 0.0_wp
            if (d == 3) dx(3) = self%x(3, m) - x0(3)
            h = max(h, ((0.0_wp + dx(1)**2) + dx(2)**2) + dx(3)**2)
         end do
         if (self%sprc) nb = nb + self%topo%bptr(e + 1) - self%topo%bptr(e)
      end do
      h = sqrt(h)
      np = ngp*size(elements)
      call patch_reset(patch, d, self%analysis, self%young, self%poisson, x0(1:d), h)
      call patch_reserve(patch, np, nb)
      patch%body_force = self%topo%body_force
      ! check_mesh_arrays validated the caller's points, weights and stresses.
      patch%points_checked = .true.
      np = 0
      do i = 1, size(elements)
         e = elements(i)
         ! Point by point with fixed-length copies (a copy of run-time length d or ns is a
         ! memcpy call).
         do q = 1, ngp
            patch%x(1:2, np + q) = self%gp(1:2, q, e)
            if (d == 3) patch%x(3, np + q) = self%gp(3, q, e)
            patch%w(np + q) = self%gw(q, e)
            patch%stress(1:3, np + q) = self%gs(1:3, q, e)
            if (ns == 6) patch%stress(4:6, np + q) = self%gs(4:6, q, e)
         end do
         np = np + ngp
         patch%npoints = np
         if (.not. self%sprc) cycle
         do k = self%topo%bptr(e), self%topo%bptr(e + 1) - 1
            patch%nbpoints = patch%nbpoints + 1
            patch%bx(1:d, patch%nbpoints) = self%topo%bx(:, k)
            patch%bw(patch%nbpoints) = self%topo%bw(k)
            patch%bn(1:d, patch%nbpoints) = self%topo%bn(:, k)
            patch%bkind(patch%nbpoints) = self%topo%bkind(k)
            patch%bpiece(patch%nbpoints) = self%topo%bpiece(k)
            patch%btraction(1:d, patch%nbpoints) = self%topo%bt(:, k)
         end do
      end do
   end subroutine mesh_fill

   !> Nodal stresses: patch value at vertex nodes, the union elsewhere (module notes).
   subroutine nodal_values(r, topo, error)
      type(mesh_recovery_type), intent(inout) :: r
      type(topology_type), intent(in) :: topo
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: xi(3)
      integer :: n, e, a, st

      if (.not. allocated(r%nodal)) then
         allocate (r%nodal(r%nstress, r%nnode), stat=st)
         call check_allocation(st, 'recover_on_mesh', 'the nodal stresses', r%nnode, 8*r%nstress, error)
         if (allocated(error)) return
      end if
      !$omp parallel do schedule(static) private(e, a, xi)
      do n = 1, r%nnode
         ! Each branch writes the whole column (a zero fill first was a memset call per node).
         if (r%patch_of_node(n) > 0) then
            ! Without records (patches_to_nodal) the vertex values are already in place.
            if (allocated(r%recs)) call eval_recovered_points(r%recs(r%patch_of_node(n)), r%x(:, n:n), r%nodal(:, n:n))
         else if (topo%ne_ptr(n + 1) > topo%ne_ptr(n)) then
            e = topo%ne_list(topo%ne_ptr(n))
            a = findloc(r%connectivity(:, e), n, dim=1)
            call element_node_xi(r%element_type, a, xi)
            call union_at_node(r, e, xi, n)
         else
            r%nodal(:, n) = 0.0_wp
         end if
      end do
      !$omp end parallel do
   end subroutine nodal_values

   !> The union (eq. 102) at node n of element e, reference point xi, into nodal(:, n).
   pure subroutine union_at_node(r, e, xi, n)
      type(mesh_recovery_type), intent(inout) :: r
      integer, intent(in) :: e, n
      real(wp), intent(in) :: xi(:)
      real(wp) :: nv(max_element_nodes, 1), s(6, 1), sj(6, 1, 8)

      sj = 0.0_wp
      call element_vertex_shape(r%element_type, xi, nv(:, 1))
      call element_field(r, e, .true., 1, nv, r%x(:, n:n), s, sj)
      r%nodal(:, n) = s(1:r%nstress, 1)
   end subroutine union_at_node

   !> The shape values the method's field uses at reference point xi: the element's own
   !> (SPR, nodal interpolation, n(1:nen)) or the vertex partition of unity (SPR-C, the
   !> union, n(1:nvertex)).
   pure subroutine method_shape(r, xi, n)
      type(mesh_recovery_type), intent(in) :: r
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: n(:)
      if (r%method == mesh_method_sprc) then
         call element_vertex_shape(r%element_type, xi, n)
      else
         call element_shape(r%element_type, xi, n)
      end if
   end subroutine method_shape

   !> A field of element e at np points x(1:dim, i), sigma(1:nstress, i), from the shape
   !> values n(:, i) there: the nodal interpolation sum_a n_a nodal(:, a) (eq. 101; SPR's
   !> field), or if `union` the union sum_J n_J sigma*_J(x) over the vertices (eq. 102; SPR-C's
   !> field), each patch evaluated at all np points at once into sj(:, 1:np, J) (work space
   !> sj(6, np, nvertex); its rows beyond nstress must be finite: they are summed, unused).
   !> Sums in node / vertex order, in six scalar lanes.
   pure subroutine element_field(r, e, union, np, n, x, sigma, sj)
      type(mesh_recovery_type), intent(in) :: r
      integer, intent(in) :: e, np
      logical, intent(in) :: union
      real(wp), intent(in) :: n(:, :), x(:, :)
      real(wp), intent(out) :: sigma(:, :)
      real(wp), intent(inout) :: sj(:, :, :)
      real(wp) :: v(6, max_element_nodes), acc(6)
      integer :: a, i, ns, nv

      ns = r%nstress
      if (union) then
         nv = r%nvertex
         do a = 1, nv
            call eval_recovered_points(r%recs(r%patch_of_node(r%connectivity(a, e))), x(:, 1:np), sj(:, :, a))
         end do
         do i = 1, np
            acc = 0.0_wp
            do a = 1, nv
               acc = acc + n(a, i)*sj(:, i, a)
            end do
            call store(acc, sigma(:, i))
         end do
      else
         ! Copies of fixed length (3 or 6): a copy of run-time length ns became a memcpy call.
         do a = 1, r%nen
            v(1:3, a) = r%nodal(1:3, r%connectivity(a, e))
            v(4:6, a) = 0.0_wp
            if (ns == 6) v(4:6, a) = r%nodal(4:6, r%connectivity(a, e))
         end do
         do i = 1, np
            acc = 0.0_wp
            do a = 1, r%nen
               acc = acc + v(:, a)*n(a, i)
            end do
            call store(acc, sigma(:, i))
         end do
      end if
   contains
      pure subroutine store(acc, sig)
         real(wp), intent(in) :: acc(6)
         real(wp), intent(inout) :: sig(:)
         sig(1:3) = acc(1:3)
         if (ns == 6) sig(4:6) = acc(4:6)
      end subroutine store
   end subroutine element_field

   !> The method's field at reference point xi / physical point x of element e.
   subroutine field_at(r, e, xi, x, sigma)
      type(mesh_recovery_type), intent(in) :: r
      integer, intent(in) :: e
      real(wp), intent(in) :: xi(:), x(:)
      real(wp), intent(out) :: sigma(:)
      real(wp) :: n(max_element_nodes, 1), xp(3, 1), s(6, 1), sj(6, 1, 8)

      sj = 0.0_wp
      call method_shape(r, xi, n(:, 1))
      xp(1:r%dim, 1) = x(1:r%dim)
      call element_field(r, e, r%method == mesh_method_sprc, 1, n, xp(1:r%dim, :), s, sj)
      sigma(1:r%nstress) = s(1:r%nstress, 1)
   end subroutine field_at

   !> ZZ estimate at the caller's points (module notes); OpenMP over elements, the sums in
   !> element order (the bits do not depend on the thread count). The shape values of the
   !> points are those of `rule` when all elements share one rule (`shared_rule`), else
   !> evaluated per point.
   subroutine estimate(r, gp, gw, gs, xi, rule, error)
      type(mesh_recovery_type), intent(inout) :: r
      real(wp), intent(in) :: gp(:, :, :), xi(:, :, :)
      ! Contiguous as recover_on_mesh's: energy_norms takes each element's slice without a copy.
      real(wp), intent(in), contiguous :: gw(:, :), gs(:, :, :)
      type(rule_type), intent(in) :: rule
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sstar(:, :), sj(:, :, :), n(:, :), cmat(:, :)
      integer :: e, i, ngp, ns, st

      ngp = size(gp, 2)
      ns = r%nstress
      allocate (r%elem_err(r%nelem), r%elem_norm_h(r%nelem), cmat(ns, ns), stat=st)
      call check_allocation(st, 'recover_on_mesh', 'the element errors', r%nelem, 16, error)
      if (allocated(error)) return
      call compliance_matrix(r%analysis, r%young, r%poisson, cmat, error)
      if (allocated(error)) return
      !$omp parallel default(shared) private(sstar, sj, n, i)
      allocate (sstar(ns, ngp), sj(6, ngp, 8), n(max_element_nodes, ngp))
      sj = 0.0_wp
      if (rule%shared) n = rule%n
      !$omp do schedule(static)
      do e = 1, r%nelem
         if (.not. rule%shared) then
            do i = 1, ngp
               call method_shape(r, xi(:, i, e), n(:, i))
            end do
         end if
         call element_field(r, e, r%method == mesh_method_sprc, ngp, n, gp(:, :, e), sstar, sj)
         call energy_norms(cmat, gw(:, e), sstar, gs(:, :, e), r%elem_err(e), r%elem_norm_h(e))
      end do
      !$omp end do
      !$omp end parallel
      ! Scaled sums: finite stresses never overflow to NaN.
      r%err = scaled_norm(r%elem_err)
      r%norm_h = scaled_norm(r%elem_norm_h)
      r%eta = relative_error(r%err, r%norm_h)
      if (.not. (r%err <= huge(1.0_wp))) then
         e = findloc(.not. (r%elem_err <= huge(1.0_wp)), .true., dim=1)
         call fatal_error(error, 'recover_on_mesh: the recovered stress of element '//index_name(r%c_indices, e)// &
            & ' is not finite (stresses near the overflow threshold?)', stat_invalid_input)
      end if
   end subroutine estimate

   !> The recovered field sigma(nstress, npts) at points x(dim, npts) (SPR: nodal
   !> interpolation; SPR-C: union). elem(i) in 1..nelem names the element of point i (the
   !> point must lie in it); elem(i) = 0 or no `elem`: the element is searched (module
   !> notes: binned when several points are searched). Errors: result not built, shapes, non-finite points, an
   !> element out of range, a point in no element (stat_invalid_input).
   subroutine mesh_recovery_eval(result, x, sigma, error, elem)
      type(mesh_recovery_type), intent(in) :: result
      real(wp), intent(in) :: x(:, :)
      real(wp), intent(out) :: sigma(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: elem(:)
      real(wp) :: xi(3)
      integer :: i, e, npts, nsearch
      type(element_bins_type) :: bins

      npts = size(x, 2)
      if (.not. allocated(result%nodal)) then
         call fail('the result is not built (recover_on_mesh did not succeed)')
      else if (size(x, 1) /= result%dim .or. size(sigma, 1) /= result%nstress .or. size(sigma, 2) /= npts) then
         call fail('x has shape ('//itoa(size(x, 1))//', '//itoa(npts)//'), sigma ('//itoa(size(sigma, 1))//', '// &
            & itoa(size(sigma, 2))//'); need ('//itoa(result%dim)//', npts) and ('//itoa(result%nstress)//', npts)')
      end if
      if (allocated(error)) return
      if (present(elem)) then
         if (size(elem) /= npts) call fail('elem has '//itoa(size(elem))//' entries, x '//itoa(npts)//' points')
         if (allocated(error)) return
         nsearch = count(elem == 0)
      else
         nsearch = npts
      end if
      ! Several points to search: bins first (O(nelem) once instead of per point).
      if (nsearch >= bins_min_points) then
         call build_element_bins(result%box_lo, result%box_hi, inside_tol, bins, error)
         if (allocated(error)) return
      end if
      do i = 1, npts
         if (.not. all(abs(x(:, i)) <= huge(1.0_wp))) then
            call fail(point(i)//' is not finite')
            return
         end if
         e = 0
         if (present(elem)) e = elem(i)
         if (e < 0 .or. e > result%nelem) then
            call fail(entry_name(result%c_indices, 'elem', 'elements', [i])//' = '//index_name(result%c_indices, e)// &
               & ' is not '//index_name(result%c_indices, 0)//' (search) or an element in '// &
               & index_name(result%c_indices, 1)//'..'//index_name(result%c_indices, result%nelem))
            return
         end if
         if (e > 0) then
            if (.not. in_element(result, e, x(:, i), xi)) then
               call fail(point(i)//' = '//vec_str(x(:, i))//' is not in element '//index_name(result%c_indices, e))
               return
            end if
         else
            if (allocated(bins%list)) then
               e = locate(result, x(:, i), xi, bins)
            else
               e = locate(result, x(:, i), xi)
            end if
            if (e == 0) then
               call fail(point(i)//' = '//vec_str(x(:, i))//' is in no element')
               return
            end if
         end if
         call field_at(result, e, xi, x(:, i), sigma(:, i))
      end do
   contains
      subroutine fail(message)
         character(len=*), intent(in) :: message
         call fatal_error(error, 'mesh_recovery_eval: '//message, stat_invalid_input)
      end subroutine fail
      pure function point(i) result(s)
         integer, intent(in) :: i
         character(len=:), allocatable :: s
         s = entry_name(result%c_indices, 'x', 'points', [0, i])
      end function point
   end subroutine mesh_recovery_eval

   !> The recovered field sigma(nstress, npts) at points x(dim, npts) on or near the mesh (a
   !> contact surface of another body whose facets do not match this mesh's): each point in
   !> the element holding it, else in the element among the candidates of its bin (bins padded
   !> by `pad` times each element's extent) whose reference point is nearest its reference
   !> cell (the field extended past the element; a point off the mesh by a gap of the order of
   !> the discretisation of a curved surface). Errors (stat_invalid_input): shapes, a
   !> non-finite point, a point near no element.
   subroutine mesh_recovery_eval_near(result, x, sigma, pad, error)
      type(mesh_recovery_type), intent(in) :: result
      real(wp), intent(in) :: x(:, :), pad
      real(wp), intent(out) :: sigma(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(element_bins_type) :: bins
      real(wp) :: xi(3), best_xi(3), dist, best
      integer :: i, k, e, b
      logical :: ok

      if (.not. allocated(result%nodal) .or. size(x, 1) /= result%dim .or. size(sigma, 1) /= result%nstress .or. &
         & size(sigma, 2) /= size(x, 2)) then
         call fatal_error(error, 'mesh_recovery_eval_near: the result is not built or the shapes disagree', &
            & stat_invalid_input)
         return
      end if
      call build_element_bins(result%box_lo, result%box_hi, pad, bins, error)
      if (allocated(error)) return
      do i = 1, size(x, 2)
         if (.not. all(abs(x(:, i)) <= huge(1.0_wp))) then
            call fatal_error(error, 'mesh_recovery_eval_near: point '//itoa(i)//' is not finite', stat_invalid_input)
            return
         end if
         b = bin_of_point(bins, x(:, i))
         best = huge(1.0_wp)
         e = 0
         do k = bins%ptr(b), bins%ptr(b + 1) - 1
            call element_inverse_map(result%element_type, result%x(:, result%connectivity(:, bins%list(k))), &
               & x(:, i), xi(1:result%dim), ok)
            if (.not. ok) cycle
            dist = outside(xi(1:result%dim))
            if (dist < best) then
               best = dist
               e = bins%list(k)
               best_xi = xi
            end if
            if (best <= inside_tol) exit
         end do
         if (e == 0) then
            call fatal_error(error, 'mesh_recovery_eval_near: point '//index_name(result%c_indices, i)//' = '// &
               & vec_str(x(:, i))//' is near no element', stat_invalid_input)
            return
         end if
         call field_at(result, e, best_xi(1:result%dim), x(:, i), sigma(:, i))
      end do
   contains
      !> How far xi lies outside the reference cell (0 inside).
      pure real(wp) function outside(xi)
         real(wp), intent(in) :: xi(:)
         outside = max(0.0_wp, maxval(-xi))
         if (element_simplex(result%element_type)) then
            outside = max(outside, sum(xi) - 1.0_wp)
         else
            outside = max(outside, maxval(xi - 1.0_wp))
         end if
      end function outside
   end subroutine mesh_recovery_eval_near

   !> True (and the reference coordinates) if x lies in element e.
   logical function in_element(r, e, x, xi)
      type(mesh_recovery_type), intent(in) :: r
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: xi(:)
      logical :: ok

      call element_inverse_map(r%element_type, r%x(:, r%connectivity(:, e)), x, xi, ok)
      in_element = ok
      if (ok) in_element = element_inside(r%element_type, xi, inside_tol)
   end function in_element

   !> The first element (lowest index) holding x, 0 if none: among the candidates of x's bin
   !> if `bins` is given (the same element: sprc_recovery_caller_mesh_bins), else among all.
   integer function locate(r, x, xi, bins) result(found)
      type(mesh_recovery_type), intent(in) :: r
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: xi(:)
      type(element_bins_type), intent(in), optional :: bins
      real(wp) :: pad
      integer :: k, e, b

      found = 0
      if (present(bins)) then
         b = bin_of_point(bins, x)
         do k = bins%ptr(b), bins%ptr(b + 1) - 1
            if (try(bins%list(k))) return
         end do
      else
         do e = 1, r%nelem
            if (try(e)) return
         end do
      end if
   contains
      logical function try(e)
         integer, intent(in) :: e
         try = .false.
         pad = inside_tol*maxval(r%box_hi(:, e) - r%box_lo(:, e))
         if (any(x(1:r%dim) < r%box_lo(:, e) - pad) .or. any(x(1:r%dim) > r%box_hi(:, e) + pad)) return
         try = in_element(r, e, x, xi)
         if (try) found = e
      end function try
   end function locate

   pure function ivec_str(c_indices, v) result(s)
      logical, intent(in) :: c_indices
      integer, intent(in) :: v(:)
      character(len=:), allocatable :: s
      integer :: i
      s = ''
      do i = 1, size(v)
         s = s//index_name(c_indices, v(i))
         if (i < size(v)) s = s//' '
      end do
   end function ivec_str

end module sprc_recovery_caller_mesh
