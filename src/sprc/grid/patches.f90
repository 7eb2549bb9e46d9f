!> The Cartesian grid as a producer of SPR / SPR-C vertex patches (seed eqs. 8-11,
!> 19-24, 99-100; Figure 15 for patch expansion).
!>
!> Input (`recovery_input_type`, plain data the FE layer fills; element e is leaf e of
!> the grid, in the grid's Morton order):
!> - material: analysis (plane_stress, plane_strain, solid), young, poisson, and a
!>   constant body force (div sigma + b = 0);
!> - volume integration points per element, CSR: the points of element e are
!>   elem_ptr(e) .. elem_ptr(e+1)-1 (elem_ptr(1) = 1, non-decreasing, size n_elements+1),
!>   with coordinates x(dim, npts), weight*|J| w(npts) > 0 and the FE stress
!>   stress(nstress, npts) in Voigt order;
!> - boundary points per element, CSR likewise (belem_ptr, bx(dim, nb), bw(nb) >= 0,
!>   unit outward normals bn(dim, nb), shape index bshape(nb) in 1..size(bc_kind));
!> - per shape index s the boundary kind for recovery, bc_kind(s):
!>   bc_none (not constrained: Dirichlet surfaces, or surfaces left alone),
!>   bc_traction (t = bc_traction(1:dim, s), constant), bc_pressure
!>   (t = -bc_pressure(s) n), bc_exact_traction (t = sigma_exact(x) n; needs the `exact`
!>   argument), bc_symmetry (zero shear on the plane). Free surfaces are bc_traction
!>   with t = 0.
!>
!> Patches (`recover_grid`): one per free vertex node, i.e. per corner node of an active
!> leaf that does not hang (for Q2 only corner nodes; mid-edge, face and centre nodes
!> get their values from the vertex patches, see sprc_grid_recovered_field). Hanging
!> vertices get no patch: their values follow from the constraints. Patch of node n:
!> x0 = x_n; elements = the leaves whose closure holds n (node -> element CSR); h = the
!> largest distance from x0 to a corner of those leaves; its points are the elements'
!> volume points and (SPR-C) boundary points of kinds other than bc_none. The recovery
!> core imposes the dominant boundary kind (`dominant_boundary_kind`: contact wins, else
!> the largest measure).
!>
!> Expansion (seed Figure 15): a patch whose basis matrix lacks rank (the core returns
!> stat_singular: too few or aligned points, e.g. a corner node with one small cut
!> element) gets one more ring of leaves, those sharing a node with the patch, and is
!> solved again; at most `max_rounds` rounds (default `default_max_rounds` = 3: a ring
!> of a 2:1 grid at least doubles the patch extent in every direction it can grow, so
!> three rings reach about 8 cells from the node). Beyond that the recovery fails with
!> stat_singular naming the node. `field%patch_rounds`, `field%n_expanded` tell how many
!> patches needed it.
!>
!> Parallelism and determinism: the patch loop is OpenMP-parallel, each thread owns a
!> patch object, a recovery workspace, an element list and an element stamp array. LAPACK
!> results depend on the workspace's capacities (leading dimensions, lwork and with it
!> blocked or unblocked code paths), so every thread reserves the same capacity before the
!> loop, that of the largest unexpanded patch, and never grows it: a patch that outgrows it
!> (only possible after expansion) is solved in a second workspace reset to that patch's
!> own size. Results then depend on the patch alone, elements and points are gathered in a
!> fixed order, and results are stored per patch: the bits do not depend on the thread
!> count or schedule. Nothing is allocated per patch except for such outgrown expanded
!> patches. Errors inside the loop are recorded per patch; after the loop the first
!> failing patch (lowest node) is solved again serially for its message.
module sprc_grid_patches
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_singular, stat_internal
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, check_material
   use sprc_core_poly, only: poly_max_degree, poly_nterms
   use sprc_core_timer, only: wall_time
   use sprc_core_blas_threads, only: blas_serial_begin, blas_serial_end
   use sprc_exact_solution, only: exact_solution_type
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_reserve, &
      & boundary_traction, boundary_symmetry
   use sprc_recovery_workspace, only: recovery_workspace_type, workspace_reserve, workspace_init
   use sprc_recovery_solve, only: recover_spr, recover_sprc
   use sprc_grid_recovered_field, only: recovered_field_type, method_spr, method_sprc, build_field
   implicit none
   private

   public :: recovery_input_type, check_recovery_input, recover_grid, default_max_rounds
   public :: bc_none, bc_traction, bc_pressure, bc_exact_traction, bc_symmetry, bc_kind_name

   !> Boundary kinds per shape index (values are part of the C API; never renumber).
   integer, parameter :: bc_none = 0, bc_traction = 1, bc_pressure = 2, bc_exact_traction = 3, bc_symmetry = 4

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
      !> Boundary kind per shape index (bc_none .. bc_symmetry).
      integer, allocatable :: bc_kind(:)
      !> Traction vector (3, nshape) of bc_traction shapes; pressure (nshape) of bc_pressure shapes.
      real(wp), allocatable :: bc_traction(:, :), bc_pressure(:)
   end type recovery_input_type

   !> Per-thread storage of the patch loop.
   type :: scratch_type
      type(patch_type) :: patch
      !> Workspace of the common capacity (same in every thread) and one for larger patches.
      type(recovery_workspace_type) :: ws, ws_big
      !> Elements of the current patch (1:nlist) and a stamp per element (= the patch's node).
      integer, allocatable :: list(:), stamp(:)
      integer :: nlist = 0
   end type scratch_type

contains

   !> Name of a boundary kind of the input, for messages.
   pure function bc_kind_name(kind) result(name)
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      select case (kind)
      case (bc_none); name = 'none'
      case (bc_traction); name = 'traction'
      case (bc_pressure); name = 'pressure'
      case (bc_exact_traction); name = 'exact_traction'
      case (bc_symmetry); name = 'symmetry'
      case default; name = 'unknown'
      end select
   end function bc_kind_name

   !> Recover the stress of every free vertex node of `grid` and build the recovered field.
   !> `method` is method_spr or method_sprc, `degree` the patch polynomial degree (1..3;
   !> the FE degree p or p+1). `exact` is needed for bc_exact_traction shapes. Errors:
   !> invalid input (stat_invalid_input, naming the field and index), a patch still rank
   !> deficient after `max_rounds` expansions (stat_singular, naming the node).
   subroutine recover_grid(input, grid, nodes, hanging, method, degree, field, error, exact, max_rounds)
      type(recovery_input_type), intent(in) :: input
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      integer, intent(in) :: method, degree
      type(recovered_field_type), intent(out) :: field
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      !> Expansion rounds allowed per patch (>= 0; default `default_max_rounds`).
      integer, intent(in), optional :: max_rounds
      integer, allocatable :: status(:)
      integer :: rounds_limit, ip, e, cap(2), saved_blas
      real(wp) :: t0
      character(len=80) :: buf

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
      allocate (field%elem_lo(grid%dim, nodes%n_elements), field%elem_hi(grid%dim, nodes%n_elements))
      do e = 1, nodes%n_elements
         call grid%leaf_box(e, field%elem_lo(:, e), field%elem_hi(:, e))
      end do
      call number_patches(nodes, hanging, field)
      allocate (field%recs(field%n_patches), field%patch_rounds(field%n_patches), &
         & field%patch_elements(field%n_patches), status(field%n_patches))

      cap = initial_capacity(input, nodes, method, degree)

      ! Small LAPACK calls from every thread: OpenBLAS in one thread (sprc_core_blas_threads).
      saved_blas = blas_serial_begin()
      !$omp parallel default(shared)
      call patch_loop(input, nodes, field, method, degree, rounds_limit, cap, status, exact)
      !$omp end parallel
      call blas_serial_end(saved_blas)

      if (any(status /= 0)) then
         ip = findloc(status /= 0, .true., dim=1)
         block
            type(scratch_type) :: sc
            call init_scratch(sc, nodes, degree, cap)
            call recover_patch(input, nodes, field%elem_lo, field%elem_hi, field%patch_node(ip), field%nstress, &
               & method, degree, rounds_limit, sc, field%recs(ip), field%patch_rounds(ip), field%patch_elements(ip), &
               & error, exact)
         end block
         if (.not. allocated(error)) then
            write (buf, '("patch ",i0," failed in the parallel loop but not serially")') ip
            call fatal_error(error, 'recover_grid: '//trim(buf), stat_internal)
         end if
         return
      end if
      field%n_expanded = count(field%patch_rounds > 0)
      field%max_rounds_used = 0
      if (field%n_patches > 0) field%max_rounds_used = maxval(field%patch_rounds)
      field%n_tolerance_bites = count(field%recs%tolerance_bites)
      field%t_recovery = wall_time() - t0

      t0 = wall_time()
      call build_field(field, grid, nodes, hanging, error)
      field%t_field = wall_time() - t0
   end subroutine recover_grid

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

   !> Free vertex nodes in node order get patches 1, 2, ...
   subroutine number_patches(nodes, hanging, field)
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      type(recovered_field_type), intent(inout) :: field
      logical, allocatable :: vertex(:)
      integer :: n, nv, e

      nv = 2**nodes%dim
      allocate (vertex(nodes%n_nodes), field%patch_of_node(nodes%n_nodes))
      vertex = .false.
      ! VTK order puts the corners first.
      do e = 1, nodes%n_elements
         vertex(nodes%connectivity(1:nv, e)) = .true.
      end do
      vertex = vertex .and. hanging%free_index > 0
      field%n_patches = count(vertex)
      allocate (field%patch_node(field%n_patches))
      field%n_patches = 0
      field%patch_of_node = 0
      do n = 1, nodes%n_nodes
         if (.not. vertex(n)) cycle
         field%n_patches = field%n_patches + 1
         field%patch_node(field%n_patches) = n
         field%patch_of_node(n) = field%n_patches
      end do
   end subroutine number_patches

   !> One thread's share of the patch loop (called inside the parallel region: its locals
   !> are the thread's own, default-initialised).
   subroutine patch_loop(input, nodes, field, method, degree, rounds_limit, cap, status, exact)
      type(recovery_input_type), intent(in) :: input
      type(grid_nodes_type), intent(in) :: nodes
      type(recovered_field_type), intent(inout) :: field
      integer, intent(in) :: method, degree, rounds_limit, cap(2)
      integer, intent(inout) :: status(:)
      class(exact_solution_type), intent(in), optional :: exact
      type(scratch_type) :: sc
      type(error_type), allocatable :: err
      integer :: ip

      call init_scratch(sc, nodes, degree, cap)
      !$omp do schedule(dynamic, 16)
      do ip = 1, field%n_patches
         call recover_patch(input, nodes, field%elem_lo, field%elem_hi, field%patch_node(ip), field%nstress, &
            & method, degree, rounds_limit, sc, field%recs(ip), field%patch_rounds(ip), field%patch_elements(ip), &
            & err, exact)
         status(ip) = 0
         if (allocated(err)) status(ip) = err%stat
      end do
      !$omp end do
   end subroutine patch_loop

   !> Points and boundary points of the largest unexpanded patch (at least 4 nterms points:
   !> the LAPACK workspace queries need room for a full basis).
   function initial_capacity(input, nodes, method, degree) result(cap)
      type(recovery_input_type), intent(in) :: input
      type(grid_nodes_type), intent(in) :: nodes
      integer, intent(in) :: method, degree
      integer :: cap(2)
      integer :: n, k, e, np, nb

      cap = [4*poly_nterms(nodes%dim, degree), 0]
      do n = 1, nodes%n_nodes
         np = 0
         nb = 0
         do k = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
            e = nodes%node_element(k)
            np = np + input%elem_ptr(e + 1) - input%elem_ptr(e)
            if (method == method_sprc) nb = nb + input%belem_ptr(e + 1) - input%belem_ptr(e)
         end do
         cap = max(cap, [np, nb])
      end do
   end function initial_capacity

   !> Thread storage. The LAPACK results depend on the workspace's capacities (leading
   !> dimensions, lwork and with it blocked or unblocked code), so every thread reserves the
   !> same capacity `cap` once, and a patch that outgrows it (only after expansion) is
   !> solved in `ws_big`, reset to that patch's own size: results depend on the patch only.
   subroutine init_scratch(sc, nodes, degree, cap)
      type(scratch_type), intent(inout) :: sc
      type(grid_nodes_type), intent(in) :: nodes
      integer, intent(in) :: degree, cap(2)
      type(error_type), allocatable :: err

      allocate (sc%list(64), sc%stamp(nodes%n_elements))
      sc%stamp = 0
      ! Cannot fail: dim and degree were validated.
      call workspace_reserve(sc%ws, nodes%dim, degree, cap(1), cap(2), err)
      call patch_reserve(sc%patch, cap(1), cap(2))
   end subroutine init_scratch

   !> Gather, solve, and expand while the basis lacks rank.
   subroutine recover_patch(input, nodes, elem_lo, elem_hi, n, ns, method, degree, rounds_limit, sc, rec, rounds, &
         & nel, error, exact)
      type(recovery_input_type), intent(in) :: input
      type(grid_nodes_type), intent(in) :: nodes
      real(wp), intent(in) :: elem_lo(:, :), elem_hi(:, :)
      !> Patch node and number of stress components.
      integer, intent(in) :: n, ns
      integer, intent(in) :: method, degree, rounds_limit
      type(scratch_type), intent(inout) :: sc
      type(recovered_patch_type), intent(out) :: rec
      integer, intent(out) :: rounds, nel
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), intent(in), optional :: exact
      integer :: k, round, nprev
      character(len=160) :: buf

      sc%nlist = 0
      do k = nodes%node_element_ptr(n), nodes%node_element_ptr(n + 1) - 1
         call list_add(sc, nodes%node_element(k), n)
      end do
      rounds = 0
      do round = 0, rounds_limit
         if (round > 0) then
            nprev = sc%nlist
            call expand(nodes, sc, n)
            if (sc%nlist == nprev) exit
            rounds = round
         end if
         nel = sc%nlist
         call fill_patch(input, nodes, elem_lo, elem_hi, n, ns, method, sc, exact)
         if (sc%patch%npoints == 0) cycle
         if (sc%patch%npoints <= sc%ws%cap_p .and. sc%patch%nbpoints <= sc%ws%cap_b) then
            call solve(sc%ws)
         else
            call workspace_init(sc%ws_big)
            call solve(sc%ws_big)
         end if
         if (.not. allocated(error)) return
         if (error%stat /= stat_singular) exit
      end do
      nel = sc%nlist
      write (buf, '("patch of node ",i0," at (",3(es12.4,:,","))') n, nodes%x(:, n)
      if (.not. allocated(error)) then
         call fatal_error(error, 'recover_grid: '//trim(buf)//'): no integration points', stat_singular)
      else if (error%stat == stat_singular) then
         write (buf, '(a,"), ",i0," elements after ",i0," expansion rounds: ")') trim(buf), nel, rounds
         error%message = 'recover_grid: '//trim(buf)//error%message
      else
         error%message = 'recover_grid: '//trim(buf)//'): '//error%message
      end if
   contains
      subroutine solve(ws)
         type(recovery_workspace_type), intent(inout) :: ws
         if (method == method_spr) then
            call recover_spr(sc%patch, degree, ws, rec, error)
         else
            call recover_sprc(sc%patch, degree, ws, rec, error)
         end if
      end subroutine solve
   end subroutine recover_patch

   subroutine list_add(sc, e, tag)
      type(scratch_type), intent(inout) :: sc
      integer, intent(in) :: e, tag
      integer, allocatable :: tmp(:)

      if (sc%stamp(e) == tag) return
      sc%stamp(e) = tag
      if (sc%nlist == size(sc%list)) then
         allocate (tmp(2*size(sc%list)))
         tmp(1:sc%nlist) = sc%list(1:sc%nlist)
         call move_alloc(tmp, sc%list)
      end if
      sc%nlist = sc%nlist + 1
      sc%list(sc%nlist) = e
   end subroutine list_add

   !> One ring: every leaf sharing a node with the current patch, in list and node order.
   subroutine expand(nodes, sc, tag)
      type(grid_nodes_type), intent(in) :: nodes
      type(scratch_type), intent(inout) :: sc
      integer, intent(in) :: tag
      integer :: i, j, k, m, n0

      n0 = sc%nlist
      do i = 1, n0
         do j = 1, nodes%nodes_per_element
            m = nodes%connectivity(j, sc%list(i))
            do k = nodes%node_element_ptr(m), nodes%node_element_ptr(m + 1) - 1
               call list_add(sc, nodes%node_element(k), tag)
            end do
         end do
      end do
   end subroutine expand

   !> The patch of node n over the listed elements (storage reused).
   subroutine fill_patch(input, nodes, elem_lo, elem_hi, n, ns, method, sc, exact)
      type(recovery_input_type), intent(in) :: input
      type(grid_nodes_type), intent(in) :: nodes
      real(wp), intent(in) :: elem_lo(:, :), elem_hi(:, :)
      integer, intent(in) :: n, ns, method
      type(scratch_type), intent(inout) :: sc
      class(exact_solution_type), intent(in), optional :: exact
      real(wp) :: x0(3), h, t(3)
      integer :: d, i, e, k, np, nb, kind

      d = nodes%dim
      x0 = 0.0_wp
      x0(1:d) = nodes%x(:, n)
      h = 0.0_wp
      np = 0
      nb = 0
      do i = 1, sc%nlist
         e = sc%list(i)
         h = max(h, sqrt(sum(max(abs(elem_lo(:, e) - x0(1:d)), abs(elem_hi(:, e) - x0(1:d)))**2)))
         np = np + input%elem_ptr(e + 1) - input%elem_ptr(e)
         if (method == method_sprc) nb = nb + input%belem_ptr(e + 1) - input%belem_ptr(e)
      end do
      associate (p => sc%patch)
         call patch_reset(p, d, input%analysis, input%young, input%poisson, x0(1:d), h)
         call patch_reserve(p, np, nb)
         p%body_force(1:d) = input%body_force(1:d)
         do i = 1, sc%nlist
            e = sc%list(i)
            do k = input%elem_ptr(e), input%elem_ptr(e + 1) - 1
               p%npoints = p%npoints + 1
               p%x(1:d, p%npoints) = input%x(:, k)
               p%w(p%npoints) = input%w(k)
               p%stress(1:ns, p%npoints) = input%stress(:, k)
            end do
            if (method /= method_sprc) cycle
            do k = input%belem_ptr(e), input%belem_ptr(e + 1) - 1
               call boundary_data(input, k, d, kind, t, exact)
               if (kind == 0) cycle
               p%nbpoints = p%nbpoints + 1
               p%bx(1:d, p%nbpoints) = input%bx(:, k)
               p%bw(p%nbpoints) = input%bw(k)
               p%bn(1:d, p%nbpoints) = input%bn(:, k)
               p%bkind(p%nbpoints) = kind
               p%bpiece(p%nbpoints) = input%bshape(k)
               p%btraction(1:d, p%nbpoints) = t(1:d)
            end do
         end do
      end associate
   end subroutine fill_patch

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
            call input_error(error, 'bc_kind('//itoa(s)//') = '//itoa(input%bc_kind(s))// &
               & ' is not none=0, traction=1, pressure=2, exact_traction=3 or symmetry=4')
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

   pure function itoa(i) result(s)
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      character(len=16) :: buf
      write (buf, '(i0)') i
      s = trim(buf)
   end function itoa

   pure function rtoa(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(es12.4)') x
      s = trim(adjustl(buf))
   end function rtoa

end module sprc_grid_patches
