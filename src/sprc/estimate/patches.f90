!> The Cartesian grid as a producer of SPR / SPR-C vertex patches (thesis eqs. 8-11,
!> 19-24, 99-100; Figure 15 for patch expansion).
!>
!> Input (`recovery_input_type`, plain data the FE layer fills; element e is leaf e of
!> the grid, in Morton order): the material, volume and boundary points per element (CSR),
!> and per shape index the boundary kind for recovery (bc_none for Dirichlet surfaces or
!> surfaces left alone; free surfaces are bc_traction with t = 0).
!>
!> Patches (`recover_grid`): one per free vertex node, i.e. per corner node of an active
!> leaf that does not hang (for Q2 only corner nodes; mid-edge, face and centre nodes
!> get their values from the vertex patches, see sprc_estimate_recovered_field). Hanging
!> vertices get no patch: their values follow from the constraints. Patch of node n:
!> x0 = x_n; elements = the leaves whose closure holds n (node -> element CSR); h = the
!> largest distance from x0 to a corner of those leaves; its points are the elements'
!> volume points and (SPR-C) boundary points of kinds other than bc_none. The recovery
!> core imposes the dominant boundary kind (`dominant_boundary_kind`: contact wins, else
!> the largest measure).
!>
!> Expansion (thesis Figure 15): a patch whose basis matrix lacks rank (the core returns
!> stat_singular: too few or aligned points, e.g. a corner node with one small cut
!> element) gets one more ring of leaves, those sharing a node with the patch, and is
!> solved again; at most `max_rounds` rounds (`default_max_rounds` = 3: each ring of a
!> 2:1 grid at least doubles the extent, so three reach ~8 cells). Beyond that the recovery fails with
!> stat_singular naming the node. `field%patch_rounds`, `field%n_expanded` tell how many
!> patches needed it.
!>
!> The loop itself (gathering, expansion, OpenMP, determinism) is the shared one of
!> sprc_recovery_patch_loop; this module supplies the grid's patches (`grid_source_type`)
!> and names a failing patch by its node.
!>
!> Contact (SPR-C with a `grid_contact_type`, sprc_estimate_contact_patches): boundary points
!> on the contact surface (surface ids: a shape's with its facet groups, or one group) are
!> contact points where their law is closed, free-surface points where it is open; a patch
!> holding one is solved by the coupled contact solve (contact wins, the thesis). A body of
!> several pairs has one description per pair (`contacts`): a point belongs to the first
!> that closes it; a patch with points of several pairs takes the pair holding most (the
!> first on a tie) and leaves the others' out (a coupled solve has one other body).
module sprc_estimate_patches
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa, rtoa
   use sprc_core_alloc, only: check_allocation
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, check_material
   use sprc_core_poly, only: poly_max_degree
   use sprc_core_timer, only: wall_time
   use sprc_core_boundary, only: bc_none, bc_traction, bc_pressure, bc_exact_traction, bc_symmetry, bc_kind_name
   use sprc_exact_solution, only: exact_solution_type
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   use sprc_recovery_patch, only: patch_type, patch_reset, patch_reserve, boundary_traction, boundary_symmetry, &
      & boundary_contact, recovered_patch_type
   use sprc_recovery_workspace, only: recovery_workspace_type
   use sprc_recovery_patch_loop, only: patch_source_type, patch_loop_type, run_patch_loop, patch_capacity, &
      & recover_patch_default
   use sprc_estimate_contact_patches, only: grid_contact_type, contact_patch_solve
   use sprc_estimate_recovered_field, only: recovered_field_type, method_spr, method_sprc, build_field
   use sprc_grid_share, only: share_type, share_range, gather_patches
   use sprc_exact_corner, only: corner_type
   use sprc_estimate_singular, only: corner_site_type, singular_fit_type, find_corners, fit_corner, enrich_cells, &
      & inner_cells
   implicit none
   private

   public :: recovery_input_type, check_recovery_input, recover_grid, default_max_rounds, boundary_points
   public :: bc_none, bc_traction, bc_pressure, bc_exact_traction, bc_symmetry, bc_kind_name

   !> Default limit of expansion rounds per patch (module notes).
   integer, parameter :: default_max_rounds = 3

   !> Everything the grid producer needs besides the grid, its nodes and hanging constraints.
   type :: recovery_input_type
      !> plane_stress, plane_strain (2D) or solid (3D).
      integer :: analysis = 0
      !> Young's modulus and Poisson's ratio.
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      !> Constant body force per unit volume, body_force(1:dim).
      real(wp) :: body_force(3) = 0.0_wp
      !> Volume points of element e: elem_ptr(e) .. elem_ptr(e+1)-1; size n_elements + 1.
      integer, allocatable :: elem_ptr(:)
      !> Coordinates (dim, npts), weight*|J| (npts), FE stress (nstress, npts).
      real(wp), allocatable :: x(:, :), w(:), stress(:, :)
      !> Boundary points of element e: belem_ptr(e) .. belem_ptr(e+1)-1; size n_elements + 1.
      integer, allocatable :: belem_ptr(:)
      !> Coordinates (dim, nb), weight*|J| (nb), unit outward normals (dim, nb).
      real(wp), allocatable :: bx(:, :), bw(:), bn(:, :)
      !> Shape index of each boundary point (nb), 1..size(bc_kind).
      integer, allocatable :: bshape(:)
      !> Boundary kind per shape index (`sprc_core_boundary`: bc_none, bc_traction, bc_pressure,
      !> bc_exact_traction or bc_symmetry).
      integer, allocatable :: bc_kind(:)
      !> Traction vector (3, nshape) of bc_traction shapes; pressure (nshape) of bc_pressure shapes.
      real(wp), allocatable :: bc_traction(:, :), bc_pressure(:)
   end type recovery_input_type

   !> The grid as a source of patches (sprc_recovery_patch_loop): read-only views of the
   !> input, the nodes, the leaf boxes and the exact solution.
   type, extends(patch_source_type) :: grid_source_type
      type(recovery_input_type), pointer :: input => null()
      type(grid_nodes_type), pointer :: nodes => null()
      real(wp), pointer :: elem_lo(:, :) => null(), elem_hi(:, :) => null()
      class(exact_solution_type), pointer :: exact => null()
      type(grid_contact_type), pointer :: contacts(:) => null()
      !> Singular fields of re-entrant corners and the corner each node's patch leaves
      !> out (0: none), sprc_estimate_singular; unassociated without corners.
      type(singular_fit_type), pointer :: corners(:) => null()
      integer, pointer :: node_corner(:) => null()
      !> Each corner's stress S at the volume points (3, npts, corner) and its
      !> traction S n at the boundary points (2, nb, corner), evaluated once.
      real(wp), pointer :: corner_stress(:, :, :) => null(), corner_traction(:, :, :) => null()
      integer :: nstress = 0
      logical :: sprc = .false.
   contains
      procedure :: fill => grid_fill
      procedure :: points_of => grid_points_of
      procedure :: recover => grid_recover
   end type grid_source_type

contains


   !> Recover the stress of every free vertex node of `grid` and build the recovered field.
   !> `method` is method_spr or method_sprc, `degree` the patch polynomial degree (1..3;
   !> the FE degree p or p+1). `exact` is needed for bc_exact_traction shapes. Errors:
   !> invalid input (stat_invalid_input, naming the field and index), a patch still rank
   !> deficient after `max_rounds` expansions (stat_singular, naming the node). With
   !> `contacts` (SPR-C only; ignored by SPR), the body's contact surfaces, one per pair (module notes).
   !> With `share` (a level shared out among ranks, `sprc_grid_share`) each rank
   !> recovers its range of patches and the records are gathered: the same field
   !> on every rank as one process recovers.
   subroutine recover_grid(input, grid, nodes, hanging, method, degree, field, error, exact, max_rounds, contacts, &
         & share)
      type(recovery_input_type), intent(in), target :: input
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in), target :: nodes
      type(hanging_type), intent(in) :: hanging
      integer, intent(in) :: method, degree
      type(recovered_field_type), intent(out), target :: field
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional, target :: exact
      !> Expansion rounds allowed per patch (>= 0; default `default_max_rounds`).
      integer, intent(in), optional :: max_rounds
      type(grid_contact_type), intent(in), optional, target :: contacts(:)
      class(share_type), intent(in), optional :: share
      type(grid_source_type) :: src
      type(patch_loop_type) :: opt
      integer, allocatable, target :: node_corner(:)
      real(wp), allocatable, target :: corner_stress(:, :, :), corner_traction(:, :, :)
      logical, allocatable :: skip(:)
      integer, allocatable :: first(:)
      integer :: rounds_limit, ip, e, n, stat, lo, hi
      real(wp) :: t0
      character(len=160) :: buf

      rounds_limit = default_max_rounds
      if (present(max_rounds)) rounds_limit = max_rounds
      call check_options(method, degree, rounds_limit, error)
      if (allocated(error)) return
      call check_recovery_input(input, grid, nodes, hanging, error, exact)
      if (allocated(error)) return

      t0 = wall_time()
      field%method = method
      field%degree = degree
      field%dim = grid%dim
      field%nstress = voigt_size(input%analysis)
      field%n_elements = nodes%n_elements
      allocate (field%elem_lo(grid%dim, nodes%n_elements), field%elem_hi(grid%dim, nodes%n_elements), stat=stat)
      call check_allocation(stat, 'recover_grid', 'the element boxes', nodes%n_elements, 16*grid%dim, error)
      if (allocated(error)) return
      !$omp parallel do schedule(static)
      do e = 1, nodes%n_elements
         call grid%leaf_box(e, field%elem_lo(:, e), field%elem_hi(:, e))
      end do
      !$omp end parallel do
      call number_patches(nodes, hanging, field, error)
      if (allocated(error)) return
      allocate (field%recs(field%n_patches), field%patch_rounds(field%n_patches), &
         & field%patch_elements(field%n_patches), stat=stat)
      call check_allocation(stat, 'recover_grid', 'the patch records', field%n_patches, &
         & storage_size(field%recs)/8 + 8, error)
      if (allocated(error)) return

      src%input => input
      src%nodes => nodes
      src%elem_lo => field%elem_lo
      src%elem_hi => field%elem_hi
      if (present(exact)) src%exact => exact
      if (present(contacts)) then
         do n = 1, size(contacts)
            if (size(contacts(n)%law) /= size(input%bw) .or. size(contacts(n)%slip, 1) < grid%dim) then
               call fatal_error(error, 'recover_grid: contact description '//itoa(n)//' has '// &
                  & itoa(size(contacts(n)%law))//' boundary points, the input '//itoa(size(input%bw)), &
                  & stat_invalid_input)
               return
            end if
         end do
         src%contacts => contacts
      end if
      src%nstress = field%nstress
      src%sprc = method == method_sprc
      if (grid%dim == 2 .and. .not. present(contacts)) then
         call singular_corners(src, degree, field, node_corner)
         if (allocated(field%singular)) then
            call corner_values(input, field%singular, corner_stress, corner_traction)
            src%corners => field%singular
            src%node_corner => node_corner
            src%corner_stress => corner_stress
            src%corner_traction => corner_traction
         end if
      end if
      opt = patch_loop_type(dim=grid%dim, degree=degree, rounds_limit=rounds_limit, sprc=src%sprc)
      ! Over all nodes, hanging ones included: the capacity (and with it the bits) of before.
      opt%cap = patch_capacity(src, grid%dim, degree, nodes%node_element_ptr, nodes%node_element, &
         & [(n, n=1, nodes%n_nodes)])
      ! Without `share` skip stays unallocated: an absent argument, nothing to set or read.
      if (present(share)) then
         call share_range(share, patch_work(input, nodes, field%patch_node), first, lo, hi)
         skip = [(ip < lo .or. ip > hi, ip=1, field%n_patches)]
      end if
      call run_patch_loop(opt, src, nodes%node_element_ptr, nodes%node_element, nodes%connectivity, &
         & field%patch_node, field%recs, field%patch_rounds, field%patch_elements, ip, error, skip)
      if (present(share)) then
         call share%agree('the recovery', error)
         if (.not. allocated(error)) &
            & call gather_patches(share, first, field%recs, field%patch_rounds, field%patch_elements, error)
      end if
      if (allocated(error)) then
         if (ip == 0) return
         n = field%patch_node(ip)
         write (buf, '("patch of node ",i0," at (",3(es12.4,:,","))') n, nodes%x(:, n)
         if (error%stat == stat_singular) then
            write (buf, '(a,"), ",i0," elements after ",i0," expansion rounds: ")') trim(buf), &
               & field%patch_elements(ip), field%patch_rounds(ip)
            error%message = 'recover_grid: '//trim(buf)//error%message
         else
            error%message = 'recover_grid: '//trim(buf)//'): '//error%message
         end if
         return
      end if
      call count_rounds(field)
      field%t_recovery = wall_time() - t0

      t0 = wall_time()
      call build_field(field, grid, nodes, hanging, error)
      field%t_field = wall_time() - t0
   end subroutine recover_grid

   !> The patches expanded, the most rounds used, the patches whose rank a tolerance
   !> decided (integer sums and a maximum: the same for any schedule).
   subroutine count_rounds(field)
      type(recovered_field_type), intent(inout) :: field
      integer :: ip, expanded, most, bites

      expanded = 0
      most = 0
      bites = 0
      !$omp parallel do schedule(static) reduction(+:expanded, bites) reduction(max:most)
      do ip = 1, field%n_patches
         if (field%patch_rounds(ip) > 0) expanded = expanded + 1
         most = max(most, field%patch_rounds(ip))
         if (field%recs(ip)%tolerance_bites) bites = bites + 1
      end do
      !$omp end parallel do
      field%n_expanded = expanded
      field%max_rounds_used = most
      field%n_tolerance_bites = bites
   end subroutine count_rounds

   !> The work of each patch for sharing them out: its elements, those with
   !> boundary points counted four times (their constraints and expansions).
   pure function patch_work(input, nodes, patch_node) result(work)
      type(recovery_input_type), intent(in) :: input
      type(grid_nodes_type), intent(in) :: nodes
      integer, intent(in) :: patch_node(:)
      integer :: work(size(patch_node))
      integer :: ip, k, e

      do ip = 1, size(patch_node)
         work(ip) = 0
         do k = nodes%node_element_ptr(patch_node(ip)), nodes%node_element_ptr(patch_node(ip) + 1) - 1
            e = nodes%node_element(k)
            work(ip) = work(ip) + merge(4, 1, input%belem_ptr(e + 1) > input%belem_ptr(e))
         end do
      end do
   end function patch_work

   subroutine check_options(method, degree, rounds_limit, error)
      integer, intent(in) :: method, degree, rounds_limit
      type(error_type), allocatable, intent(out) :: error
      character(len=80) :: buf

      if (method /= method_spr .and. method /= method_sprc) then
         write (buf, '("method = ",i0," is not spr (1) or sprc (2)")') method
      else if (degree < 1 .or. degree > poly_max_degree) then
         write (buf, '("degree = ",i0," is not in 1..",i0)') degree, poly_max_degree
      else if (rounds_limit < 0) then
         write (buf, '("max_rounds = ",i0," is negative")') rounds_limit
      else
         return
      end if
      call fatal_error(error, 'recover_grid: '//trim(buf), stat_invalid_input)
   end subroutine check_options

   !> Free vertex nodes in node order get patches 1, 2, ... A node is a vertex when it is
   !> a corner of one of its elements (VTK order puts the corners first): decided per
   !> node, in parallel.
   subroutine number_patches(nodes, hanging, field, error)
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      type(recovered_field_type), intent(inout) :: field
      type(error_type), allocatable, intent(out) :: error
      logical, allocatable :: vertex(:)
      integer :: n, nv, k, stat

      nv = 2**nodes%dim
      allocate (vertex(nodes%n_nodes), field%patch_of_node(nodes%n_nodes), stat=stat)
      call check_allocation(stat, 'recover_grid', 'the patch of each node', nodes%n_nodes, 8, error)
      if (allocated(error)) return
      !$omp parallel do schedule(static) private(k)
      do n = 1, nodes%n_nodes
         vertex(n) = .false.
         if (hanging%free_index(n) <= 0) cycle
         do k = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
            vertex(n) = any(nodes%connectivity(1:nv, nodes%node_element(k)) == n)
            if (vertex(n)) exit
         end do
      end do
      !$omp end parallel do
      field%n_patches = count(vertex)
      allocate (field%patch_node(field%n_patches), stat=stat)
      call check_allocation(stat, 'recover_grid', 'the node of each patch', field%n_patches, 4, error)
      if (allocated(error)) return
      field%n_patches = 0
      do n = 1, nodes%n_nodes
         field%patch_of_node(n) = 0
         if (.not. vertex(n)) cycle
         field%n_patches = field%n_patches + 1
         field%patch_node(field%n_patches) = n
         field%patch_of_node(n) = field%n_patches
      end do
   end subroutine number_patches

   !> [volume points, boundary points] the leaves add to a patch (boundary points of every
   !> kind: the capacity of before).
   pure function grid_points_of(self, elements) result(counts)
      class(grid_source_type), intent(in) :: self
      integer, intent(in) :: elements(:)
      integer :: counts(2)
      integer :: i, e

      counts = 0
      do i = 1, size(elements)
         e = elements(i)
         counts(1) = counts(1) + self%input%elem_ptr(e + 1) - self%input%elem_ptr(e)
         if (self%sprc) counts(2) = counts(2) + self%input%belem_ptr(e + 1) - self%input%belem_ptr(e)
      end do
   end function grid_points_of

   !> The patch of node n over the listed leaves (storage reused).
   subroutine grid_fill(self, node, elements, patch)
      class(grid_source_type), intent(in) :: self
      integer, intent(in) :: node, elements(:)
      type(patch_type), intent(inout) :: patch
      real(wp) :: x0(3), h, t(3)
      integer :: d, i, e, k, np, nb, kind, ns, c
      logical :: inner

      associate (input => self%input, elem_lo => self%elem_lo, elem_hi => self%elem_hi)
         d = self%nodes%dim
         ns = self%nstress
         x0 = 0.0_wp
         x0(1:d) = self%nodes%x(:, node)
         h = 0.0_wp
         np = 0
         nb = 0
         do i = 1, size(elements)
            e = elements(i)
            h = max(h, sqrt(sum(max(abs(elem_lo(:, e) - x0(1:d)), abs(elem_hi(:, e) - x0(1:d)))**2)))
            np = np + input%elem_ptr(e + 1) - input%elem_ptr(e)
            if (self%sprc) nb = nb + input%belem_ptr(e + 1) - input%belem_ptr(e)
         end do
         call patch_reset(patch, d, input%analysis, input%young, input%poisson, x0(1:d), h)
         call patch_reserve(patch, np, nb)
         patch%body_force(1:d) = input%body_force(1:d)
         ! the corner whose singular field the patch leaves out (sprc_estimate_singular)
         c = 0
         if (associated(self%node_corner)) c = abs(self%node_corner(node))
         inner = .false.
         if (c > 0) inner = self%node_corner(node) < 0
         do i = 1, size(elements)
            e = elements(i)
            do k = input%elem_ptr(e), input%elem_ptr(e + 1) - 1
               patch%npoints = patch%npoints + 1
               patch%x(1:d, patch%npoints) = input%x(:, k)
               patch%w(patch%npoints) = input%w(k)
               patch%stress(1:ns, patch%npoints) = input%stress(:, k)
               if (inner) then
                  call self%corners(c)%smooth_stress(input%x(:, k), patch%stress(1:3, patch%npoints))
               else if (c > 0) then
                  patch%stress(1:3, patch%npoints) = input%stress(:, k) - self%corner_stress(:, k, c)
               end if
            end do
            if (.not. self%sprc) cycle
            do k = input%belem_ptr(e), input%belem_ptr(e + 1) - 1
               call point_kind(self, k, kind, t)
               if (kind == 0) cycle
               patch%nbpoints = patch%nbpoints + 1
               patch%bx(1:d, patch%nbpoints) = input%bx(:, k)
               patch%bw(patch%nbpoints) = input%bw(k)
               patch%bn(1:d, patch%nbpoints) = input%bn(:, k)
               patch%bkind(patch%nbpoints) = kind
               patch%bpiece(patch%nbpoints) = input%bshape(k)
               patch%btraction(1:d, patch%nbpoints) = t(1:d)
               if (c > 0 .and. kind == boundary_traction) &
                  & patch%btraction(1:2, patch%nbpoints) = t(1:2) - self%corner_traction(:, k, c)
            end do
         end do
      end associate
   end subroutine grid_fill

   !> Each corner's stress at the input's volume points and traction at its boundary points.
   subroutine corner_values(input, fits, stress, traction)
      type(recovery_input_type), intent(in) :: input
      type(singular_fit_type), intent(in) :: fits(:)
      real(wp), allocatable, intent(out) :: stress(:, :, :), traction(:, :, :)
      real(wp) :: s(3)
      integer :: c, k

      allocate (stress(3, size(input%w), size(fits)), traction(2, size(input%bw), size(fits)))
      do c = 1, size(fits)
         !$omp parallel do schedule(static)
         do k = 1, size(input%w)
            call fits(c)%corner%stress(input%x(1:2, k), stress(:, k, c))
         end do
         !$omp end parallel do
         !$omp parallel do schedule(static) private(s)
         do k = 1, size(input%bw)
            call fits(c)%corner%stress(input%bx(1:2, k), s)
            traction(1, k, c) = s(1)*input%bn(1, k) + s(3)*input%bn(2, k)
            traction(2, k, c) = s(3)*input%bn(1, k) + s(2)*input%bn(2, k)
         end do
         !$omp end parallel do
      end do
   end subroutine corner_values

   !> The re-entrant corners of a 2D input, their fitted singular fields (field%singular,
   !> left unallocated without any) and the corner of each node's patch (node_corner;
   !> field%patch_corner per patch): sprc_estimate_singular's module notes.
   subroutine singular_corners(src, degree, field, node_corner)
      type(grid_source_type), intent(in) :: src
      integer, intent(in) :: degree
      type(recovered_field_type), intent(inout) :: field
      integer, allocatable, intent(out) :: node_corner(:)
      type(corner_site_type), allocatable :: sites(:)
      type(singular_fit_type), allocatable :: fitted(:)
      type(singular_fit_type) :: corner
      logical, allocatable :: free(:), symmetry(:), bsym(:)
      real(wp) :: t(3), width, dist, lo(2), hi(2)
      integer :: k, kind, c, n, i, e
      logical :: ok, inner, sym, global

      associate (input => src%input, nodes => src%nodes)
         allocate (free(size(input%bw)), bsym(size(input%bw)))
         do k = 1, size(input%bw)
            call point_kind(src, k, kind, t)
            free(k) = kind == boundary_traction .and. all(t(1:2) == 0.0_wp)
            bsym(k) = kind == boundary_symmetry
         end do
         call find_corners(input%bx, input%bn, input%belem_ptr, free, field%elem_lo, field%elem_hi, sites)
         allocate (fitted(0))
         do c = 1, size(sites)
            call fit_corner(sites(c), input%analysis, input%young, input%poisson, input%x, input%w, input%stress, &
               & input%elem_ptr, field%elem_lo, field%elem_hi, degree, corner, ok)
            if (ok) fitted = [fitted, corner]
         end do
         if (size(fitted) == 0) return
         ! elements with symmetry points: their patches keep the whole field
         allocate (symmetry(nodes%n_elements))
         do e = 1, nodes%n_elements
            symmetry(e) = any(bsym(input%belem_ptr(e):input%belem_ptr(e + 1) - 1))
         end do
         allocate (node_corner(nodes%n_nodes))
         node_corner = 0
         global = size(fitted) == 1
         if (global) global = in_wedge(fitted(1)%corner, input%x)
         do n = 1, nodes%n_nodes
            if (field%patch_of_node(n) == 0) cycle
            width = 0.0_wp
            sym = .false.
            do i = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
               e = nodes%node_element(i)
               sym = sym .or. symmetry(e)
               width = max(width, maxval(field%elem_hi(:, e) - field%elem_lo(:, e)))
            end do
            if (sym) cycle
            do c = 1, size(fitted)
               dist = norm2(nodes%x(:, n) - fitted(c)%corner%point)
               if (dist < enrich_cells*width .or. global) then
                  inner = .false.
                  do i = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
                     e = nodes%node_element(i)
                     lo = field%elem_lo(:, e)
                     hi = field%elem_hi(:, e)
                     inner = inner .or. norm2(max(lo - fitted(c)%corner%point, 0.0_wp, fitted(c)%corner%point - hi)) &
                        & < inner_cells*maxval(hi - lo)
                  end do
                  node_corner(n) = merge(-c, c, inner)
                  exit
               end if
            end do
         end do
         if (.not. any(node_corner /= 0)) return
         call move_alloc(fitted, field%singular)
         field%patch_corner = abs(node_corner(field%patch_node))
      end associate
   end subroutine singular_corners

   !> Whether every point x(:, k) lies in the material wedge of `corner` (polar angle
   !> from the bisector at most half the opening, up to round-off), where its field is
   !> continuous.
   pure logical function in_wedge(corner, x) result(inside)
      type(corner_type), intent(in) :: corner
      real(wp), intent(in) :: x(:, :)
      real(wp) :: half, d(2), t
      integer :: k

      half = 0.5_wp*corner%angle*acos(-1.0_wp)/180.0_wp
      inside = .true.
      do k = 1, size(x, 2)
         d = x(1:2, k) - corner%point
         t = atan2(corner%direction(1)*d(2) - corner%direction(2)*d(1), dot_product(corner%direction, d))
         if (abs(t) > half + sqrt(epsilon(1.0_wp))) then
            inside = .false.
            return
         end if
      end do
   end function in_wedge

   !> Recovery boundary kind (0: not constrained) and prescribed traction of input boundary
   !> point k: contact or free on the contact shape (module notes), else `boundary_data`.
   pure subroutine point_kind(self, k, kind, t)
      class(grid_source_type), intent(in) :: self
      integer, intent(in) :: k
      integer, intent(out) :: kind
      real(wp), intent(out) :: t(3)
      integer :: d

      d = self%nodes%dim
      if (associated(self%contacts)) then
         if (on_contact(self, k)) then
            t = 0.0_wp
            kind = merge(boundary_contact, boundary_traction, contact_of(self, k) > 0)
            return
         end if
      end if
      if (associated(self%exact)) then
         call boundary_data(self%input, k, d, kind, t, self%exact)
      else
         call boundary_data(self%input, k, d, kind, t)
      end if
   end subroutine point_kind

   !> Solve a filled patch: the coupled contact solve if it holds contact points, else the
   !> default (module notes). The law and slip of its boundary points follow `grid_fill`'s order.
   subroutine grid_recover(self, node, elements, patch, degree, sprc, ws, rec, error)
      class(grid_source_type), intent(in) :: self
      integer, intent(in) :: node, elements(:), degree
      type(patch_type), intent(in) :: patch
      logical, intent(in) :: sprc
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: law(:), owner(:)
      real(wp), allocatable :: slip(:, :), offset(:, :), ratio(:)
      type(patch_type) :: own
      real(wp) :: t(3), h1
      integer :: i, j, k, kind, d, win

      d = self%nodes%dim
      if (sprc .and. associated(self%contacts) .and. patch%nbpoints > 0) then
         if (any(patch%bkind(1:patch%nbpoints) == boundary_contact)) then
            allocate (law(patch%nbpoints), slip(d, patch%nbpoints), owner(patch%nbpoints), offset(d, patch%nbpoints), &
               & ratio(patch%nbpoints))
            j = 0
            do i = 1, size(elements)
               do k = self%input%belem_ptr(elements(i)), self%input%belem_ptr(elements(i) + 1) - 1
                  call point_kind(self, k, kind, t)
                  if (kind == 0) cycle
                  j = j + 1
                  law(j) = 0
                  slip(:, j) = 0.0_wp
                  offset(:, j) = 0.0_wp
                  ratio(j) = 1.0_wp
                  owner(j) = 0
                  if (kind /= boundary_contact) cycle
                  owner(j) = contact_of(self, k)
                  law(j) = self%contacts(owner(j))%law(k)
                  slip(:, j) = self%contacts(owner(j))%slip(1:d, k)
                  if (.not. allocated(self%contacts(owner(j))%ratio)) cycle
                  offset(:, j) = self%contacts(owner(j))%offset(1:d, k)
                  ratio(j) = self%contacts(owner(j))%ratio(k)
               end do
            end do
            h1 = 0.0_wp
            do i = 1, size(elements)
               h1 = max(h1, maxval(self%elem_hi(1:d, elements(i)) - self%elem_lo(1:d, elements(i))))
            end do
            win = 1
            do i = 2, size(self%contacts)
               if (count(owner == i) > count(owner == win)) win = i
            end do
            if (all(owner == 0 .or. owner == win)) then
               call contact_patch_solve(self%contacts(win), patch, law, slip, degree, ws, rec, error, offset, ratio, h1)
            else
               call one_pair_patch(patch, owner, win, law, slip, offset, ratio, own)
               call contact_patch_solve(self%contacts(win), own, law, slip, degree, ws, rec, error, offset, ratio, h1)
            end if
            return
         end if
      end if
      call recover_patch_default(self, node, elements, patch, degree, sprc, ws, rec, error)
   end subroutine grid_recover

   !> Is boundary point k on the contact surface of one of the contacts?
   pure logical function on_contact(self, k)
      class(grid_source_type), intent(in) :: self
      integer, intent(in) :: k
      integer :: i
      on_contact = .false.
      do i = 1, size(self%contacts)
         if (any(self%contacts(i)%surfaces == self%input%bshape(k))) on_contact = .true.
      end do
   end function on_contact

   !> The contact description (index into `contacts`) that closes boundary point k: the
   !> first whose shape k lies on with a closed law; 0 if none (module notes).
   pure integer function contact_of(self, k)
      class(grid_source_type), intent(in) :: self
      integer, intent(in) :: k
      do contact_of = 1, size(self%contacts)
         if (.not. any(self%contacts(contact_of)%surfaces == self%input%bshape(k))) cycle
         if (self%contacts(contact_of)%law(k) /= 0) return
      end do
      contact_of = 0
   end function contact_of

   !> `patch` without the contact points of pairs other than `win` (owner(j) the pair of
   !> boundary point j, 0 for a point that is not a contact point); law, slip, offset and ratio
   !> compacted alike.
   pure subroutine one_pair_patch(patch, owner, win, law, slip, offset, ratio, own)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: owner(:), win
      integer, intent(inout) :: law(:)
      real(wp), intent(inout) :: slip(:, :), offset(:, :), ratio(:)
      type(patch_type), intent(out) :: own
      integer :: j, m

      own = patch
      m = 0
      do j = 1, patch%nbpoints
         if (owner(j) /= 0 .and. owner(j) /= win) cycle
         m = m + 1
         own%bx(:, m) = patch%bx(:, j)
         own%bw(m) = patch%bw(j)
         own%bn(:, m) = patch%bn(:, j)
         own%bkind(m) = patch%bkind(j)
         own%bpiece(m) = patch%bpiece(j)
         own%btraction(:, m) = patch%btraction(:, j)
         law(m) = law(j)
         slip(:, m) = slip(:, j)
         offset(:, m) = offset(:, j)
         ratio(m) = ratio(j)
      end do
      own%nbpoints = m
   end subroutine one_pair_patch

   !> The recovery boundary points of `input` (kinds and tractions as the patches take them,
   !> bc_none left out) other than those on the surfaces `skip` (ids), in the boundary arrays of
   !> `points` (a contact's other body, sprc_estimate_contact_patches). `exact` as recover_grid's.
   subroutine boundary_points(input, dim, skip, points, exact)
      type(recovery_input_type), intent(in) :: input
      integer, intent(in) :: dim, skip(:)
      type(patch_type), intent(out) :: points
      class(exact_solution_type), intent(in), optional :: exact
      real(wp) :: t(3)
      integer :: k, kind

      call patch_reset(points, dim, input%analysis, input%young, input%poisson, [(0.0_wp, k=1, dim)], 1.0_wp)
      ! One reservation (adding points one by one would grow the arrays at every point).
      call patch_reserve(points, 0, size(input%bw))
      do k = 1, size(input%bw)
         if (any(skip == input%bshape(k))) cycle
         call boundary_data(input, k, dim, kind, t, exact)
         if (kind == 0) cycle
         points%nbpoints = points%nbpoints + 1
         associate (j => points%nbpoints)
            points%bx(:, j) = 0.0_wp
            points%bx(1:dim, j) = input%bx(:, k)
            points%bw(j) = input%bw(k)
            points%bn(:, j) = 0.0_wp
            points%bn(1:dim, j) = input%bn(:, k)
            points%bkind(j) = kind
            points%bpiece(j) = input%bshape(k)
            points%btraction(:, j) = 0.0_wp
            points%btraction(1:dim, j) = t(1:dim)
         end associate
      end do
   end subroutine boundary_points

   !> Recovery boundary kind (0: not constrained) and prescribed traction of boundary point k.
   pure subroutine boundary_data(input, k, d, kind, t, exact)
      type(recovery_input_type), intent(in) :: input
      integer, intent(in) :: k, d
      integer, intent(out) :: kind
      real(wp), intent(out) :: t(3)
      class(exact_solution_type), intent(in), optional :: exact
      integer :: s

      s = input%bshape(k)
      t = 0.0_wp
      kind = boundary_traction
      select case (input%bc_kind(s))
      case (bc_traction)
         t(1:d) = input%bc_traction(1:d, s)
      case (bc_pressure)
         t(1:d) = -input%bc_pressure(s)*input%bn(:, k)
      case (bc_exact_traction)
         if (present(exact)) call exact%traction(input%bx(:, k), input%bn(:, k), t(1:d))
      case (bc_symmetry)
         kind = boundary_symmetry
      case default
         kind = 0
      end select
   end subroutine boundary_data

   !> Validate the input against the grid objects: sizes, CSR pointers, finiteness, positive
   !> weights, unit normals, shape indices, boundary kinds and their data. Messages name the
   !> field, the index and the value.
   subroutine check_recovery_input(input, grid, nodes, hanging, error, exact)
      type(recovery_input_type), intent(in) :: input
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      integer :: d, ns, ne

      d = grid%dim
      ne = grid%n_leaves
      if (d /= 2 .and. d /= 3) then
         call fail('the grid is not built')
      else if (nodes%dim /= d .or. nodes%n_elements /= ne .or. .not. allocated(nodes%connectivity)) then
         call fail('the nodes were not built on this grid')
      else if (hanging%n_all /= nodes%n_nodes .or. .not. allocated(hanging%free_index)) then
         call fail('the hanging constraints were not built on these nodes')
      end if
      if (allocated(error)) return
      ns = voigt_size(input%analysis)
      if (ns == 0 .or. (d == 3 .neqv. input%analysis == solid)) then
         call fail('analysis = '//itoa(input%analysis)//' does not fit dim = '//itoa(d)// &
            & ' (plane_stress = '//itoa(plane_stress)//' or plane_strain = '//itoa(plane_strain)// &
            & ' in 2D, solid = '//itoa(solid)//' in 3D)')
         return
      end if
      call check_material(input%young, input%poisson, 'recovery input', error)
      if (allocated(error)) return
      if (.not. all(abs(input%body_force(1:d)) <= huge(1.0_wp))) then
         call fail('body_force is not finite')
         return
      end if
      call check_volume(input, d, ns, ne, error)
      if (allocated(error)) return
      call check_boundary(input, d, ne, error, present(exact))
      if (allocated(error)) return
      if (present(exact)) then
         if (exact%dim /= d) call fail('the exact solution has dim '//itoa(exact%dim)//', the grid '//itoa(d))
      end if
   contains
      subroutine fail(message)
         character(len=*), intent(in) :: message
         call fatal_error(error, 'recovery input: '//message, stat_invalid_input)
      end subroutine fail
   end subroutine check_recovery_input

   subroutine check_volume(input, d, ns, ne, error)
      type(recovery_input_type), intent(in) :: input
      integer, intent(in) :: d, ns, ne
      type(error_type), allocatable, intent(out) :: error
      integer :: np, k

      if (.not. (allocated(input%elem_ptr) .and. allocated(input%x) .and. allocated(input%w) .and. &
         & allocated(input%stress))) then
         call input_error(error, 'elem_ptr, x, w and stress must be allocated')
         return
      end if
      call check_ptr(input%elem_ptr, 'elem_ptr', ne, np, error)
      if (allocated(error)) return
      if (size(input%w) /= np .or. any(shape(input%x) /= [d, np]) .or. any(shape(input%stress) /= [ns, np])) then
         call input_error(error, 'elem_ptr gives '//itoa(np)//' points; need w('//itoa(np)//'), x('//itoa(d)// &
            & ','//itoa(np)//'), stress('//itoa(ns)//','//itoa(np)//'), got w('//itoa(size(input%w))//'), x('// &
            & itoa(size(input%x, 1))//','//itoa(size(input%x, 2))//'), stress('//itoa(size(input%stress, 1))// &
            & ','//itoa(size(input%stress, 2))//')')
         return
      end if
      do k = 1, np
         if (.not. all(abs(input%x(:, k)) <= huge(1.0_wp))) then
            call input_error(error, 'x(:, '//itoa(k)//') is not finite')
         else if (.not. (input%w(k) > 0.0_wp .and. input%w(k) <= huge(1.0_wp))) then
            call input_error(error, 'w('//itoa(k)//') = '//rtoa(input%w(k))//' must be finite and > 0')
         else if (.not. all(abs(input%stress(:, k)) <= huge(1.0_wp))) then
            call input_error(error, 'stress(:, '//itoa(k)//') is not finite (NaN or Inf)')
         end if
         if (allocated(error)) return
      end do
   end subroutine check_volume

   subroutine check_boundary(input, d, ne, error, have_exact)
      type(recovery_input_type), intent(in) :: input
      integer, intent(in) :: d, ne
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in) :: have_exact
      integer :: nb, k, nshape, s

      if (.not. (allocated(input%belem_ptr) .and. allocated(input%bx) .and. allocated(input%bw) .and. &
         & allocated(input%bn) .and. allocated(input%bshape) .and. allocated(input%bc_kind) .and. &
         & allocated(input%bc_traction) .and. allocated(input%bc_pressure))) then
         call input_error(error, 'belem_ptr, bx, bw, bn, bshape, bc_kind, bc_traction and bc_pressure '// &
            & 'must be allocated (size 0 if there are none)')
         return
      end if
      call check_ptr(input%belem_ptr, 'belem_ptr', ne, nb, error)
      if (allocated(error)) return
      nshape = size(input%bc_kind)
      if (size(input%bw) /= nb .or. size(input%bshape) /= nb .or. any(shape(input%bx) /= [d, nb]) .or. &
         & any(shape(input%bn) /= [d, nb])) then
         call input_error(error, 'belem_ptr gives '//itoa(nb)//' boundary points; bx, bw, bn, bshape disagree')
         return
      end if
      if (size(input%bc_traction, 1) < d .or. size(input%bc_traction, 2) /= nshape .or. &
         & size(input%bc_pressure) /= nshape) then
         call input_error(error, 'bc_traction must be (>= dim, '//itoa(nshape)//') and bc_pressure ('// &
            & itoa(nshape)//') for '//itoa(nshape)//' shapes')
         return
      end if
      do s = 1, nshape
         select case (input%bc_kind(s))
         case (bc_none, bc_symmetry)
         case (bc_traction)
            if (.not. all(abs(input%bc_traction(1:d, s)) <= huge(1.0_wp))) &
               & call input_error(error, 'bc_traction(:, '//itoa(s)//') is not finite')
         case (bc_pressure)
            if (.not. (abs(input%bc_pressure(s)) <= huge(1.0_wp))) &
               & call input_error(error, 'bc_pressure('//itoa(s)//') is not finite')
         case (bc_exact_traction)
            if (.not. have_exact) call input_error(error, 'shape '//itoa(s)// &
               & ' has bc_exact_traction but no exact solution was given')
         case default
            call input_error(error, 'bc_kind('//itoa(s)//') = '//itoa(input%bc_kind(s))//' is not none='// &
               & itoa(bc_none)//', traction='//itoa(bc_traction)//', pressure='//itoa(bc_pressure)// &
               & ', exact_traction='//itoa(bc_exact_traction)//' or symmetry='//itoa(bc_symmetry))
         end select
         if (allocated(error)) return
      end do
      do k = 1, nb
         if (input%bshape(k) < 1 .or. input%bshape(k) > nshape) then
            call input_error(error, 'bshape('//itoa(k)//') = '//itoa(input%bshape(k))//' is not a shape index in 1..' &
               & //itoa(nshape))
         else if (.not. all(abs(input%bx(:, k)) <= huge(1.0_wp))) then
            call input_error(error, 'bx(:, '//itoa(k)//') is not finite')
         else if (.not. (input%bw(k) >= 0.0_wp .and. input%bw(k) <= huge(1.0_wp))) then
            call input_error(error, 'bw('//itoa(k)//') = '//rtoa(input%bw(k))//' must be finite and >= 0')
         else if (.not. (abs(norm2(input%bn(:, k)) - 1.0_wp) <= 1.0e-8_wp)) then
            call input_error(error, 'bn(:, '//itoa(k)//') has length '//rtoa(norm2(input%bn(:, k)))// &
               & ', expected a unit normal')
         end if
         if (allocated(error)) return
      end do
   end subroutine check_boundary

   !> A CSR pointer of n+1 entries starting at 1, non-decreasing; total entries m.
   subroutine check_ptr(ptr, name, n, m, error)
      integer, intent(in) :: ptr(:)
      character(len=*), intent(in) :: name
      integer, intent(in) :: n
      integer, intent(out) :: m
      type(error_type), allocatable, intent(out) :: error
      integer :: e

      m = 0
      if (size(ptr) /= n + 1) then
         call input_error(error, name//' has '//itoa(size(ptr))//' entries, need n_elements + 1 = '//itoa(n + 1))
         return
      end if
      if (ptr(1) /= 1) then
         call input_error(error, name//'(1) = '//itoa(ptr(1))//', must be 1')
         return
      end if
      do e = 1, n
         if (ptr(e + 1) < ptr(e)) then
            call input_error(error, name//' decreases at element '//itoa(e))
            return
         end if
      end do
      m = ptr(n + 1) - 1
   end subroutine check_ptr

   subroutine input_error(error, message)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      call fatal_error(error, 'recovery input: '//message, stat_invalid_input)
   end subroutine input_error

end module sprc_estimate_patches
