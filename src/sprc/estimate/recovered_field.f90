!> The recovered stress field on a Cartesian grid: the vertex-patch polynomials of
!> SPR / SPR-C (filled by `sprc_estimate_patches`) and their interpolation over the
!> elements, evaluable at any point of any element without the grid objects.
!>
!> Two interpolations (thesis eqs. 101, 102):
!> - nodal (eq. 101, the SPR field): sigma*(x) = sum_J N_J(x) sigma*_J over all
!>   nodes J of the element with the element's own Q1 / Q2 shape functions N_J.
!>   The nodal values sigma*_J (`nodal_interp`) are
!>   * at a vertex node with a patch: its patch polynomial at the node;
!>   * at a free Q2 node without a patch (mid-edge, face or cell centre): the
!>     polynomial union (eq. 102) evaluated at the node, i.e. the average of the
!>     vertex patches of the edge / face / cell it is the centre of (the Q1
!>     partition of unity is 1/2, 1/4 or 1/8 there). On a 2:1 grid such a node
!>     lies only on entities shared by leaves of one level, so every element
!>     containing it gives the same value; the first element of the node's list
!>     is used;
!>   * at a hanging node: the hanging constraint applied to the nodal values,
!>     sigma*_h = sum_k c_k sigma*_k, so that the field is continuous as the FE
!>     displacement is.
!> - union (eq. 102, the SPR-C field): sigma*(x) = sum_J N_J(x) sigma*_J(x) over
!>   the element's vertices J with the Q1 (vertex) partition of unity N_J, and
!>   sigma*_J the whole patch polynomial of J. A hanging vertex (Q1 only: on a
!>   2:1 grid every Q2 corner node is free) has no patch; its N_J goes to its
!>   masters through the Q1 hanging constraint, N_J c_k to master k, so the
!>   weights still sum to one (the c_k do) and the union is continuous across
!>   coarse / fine faces. The per-corner (patch, coefficient) lists are built
!>   once (`corner_ptr`, `corner_patch`, `corner_coef`).
!> A point outside its element's box extrapolates both formulas (no error).
!>
!> Nodal output `nodal`: the method's field at every node (incl. hanging and Q2
!> nodes). SPR: `nodal_interp`. SPR-C: the union at the node in the node's first
!> element (at a vertex with a patch this is the patch value itself).
module sprc_estimate_recovered_field
   use sprc_core_kinds, only: wp, i8
   use sprc_core_alloc, only: check_allocation
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_internal
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type, element_shape
   use sprc_grid_hanging, only: hanging_type
   use sprc_recovery_patch, only: recovered_patch_type
   use sprc_recovery_estimate, only: eval_recovered
   use sprc_estimate_singular, only: singular_fit_type
   implicit none
   private

   public :: recovered_field_type, method_spr, method_sprc, method_name
   public :: interp_default, interp_nodal, interp_union
   public :: field_eval, field_eval_unchecked, field_union_weights, build_field

   !> Recovery methods (values are part of the C API; never renumber).
   integer, parameter :: method_spr = 1, method_sprc = 2
   !> The interpolations: the method's own (nodal for SPR, union for SPR-C), eq. 101, eq. 102.
   integer, parameter :: interp_default = 0, interp_nodal = 1, interp_union = 2

   !> Recovered field of one grid: patches, interpolation data, nodal values, diagnostics.
   type :: recovered_field_type
      !> method_spr or method_sprc; polynomial degree of the patches; FE (element) degree.
      integer :: method = 0, degree = -1, fe_degree = 0
      !> Dimension and number of Voigt stress components.
      integer :: dim = 0, nstress = 0
      !> Elements (leaves), nodes, nodes per element, vertices per element (2**dim).
      integer :: n_elements = 0, n_nodes = 0, nodes_per_element = 0, nvertex = 0
      !> Number of patches (free vertex nodes).
      integer :: n_patches = 0
      !> Node of each patch (n_patches, ascending) and patch of each node (n_nodes; 0: none).
      integer, allocatable :: patch_node(:), patch_of_node(:)
      !> Recovered polynomial of each patch.
      type(recovered_patch_type), allocatable :: recs(:)
      !> Expansion rounds each patch needed (0: none) and its final number of elements.
      integer, allocatable :: patch_rounds(:), patch_elements(:)
      !> Patches that needed expansion, the most rounds any needed, patches where the rank
      !> tolerance (not exact dependence) decided a rank.
      integer :: n_expanded = 0, max_rounds_used = 0, n_tolerance_bites = 0
      !> Element boxes (dim, n_elements) and connectivity (nodes_per_element, n_elements), VTK order.
      real(wp), allocatable :: elem_lo(:, :), elem_hi(:, :)
      integer, allocatable :: connectivity(:, :)
      !> Node coordinates (dim, n_nodes).
      real(wp), allocatable :: node_x(:, :)
      !> Union weights: corner j of element e is slot s = (e-1)*nvertex + j; its patches are
      !> corner_patch(corner_ptr(s) : corner_ptr(s+1)-1) with coefficients corner_coef(...)
      !> (one entry of 1 for a vertex with a patch, the Q1 constraint for a hanging vertex).
      integer, allocatable :: corner_ptr(:), corner_patch(:)
      real(wp), allocatable :: corner_coef(:)
      !> Nodal values of eq. 101 (nstress, n_nodes) and the method's field at the nodes.
      real(wp), allocatable :: nodal_interp(:, :), nodal(:, :)
      !> Singular fields of re-entrant corners (sprc_estimate_singular), with fitted amplitudes,
      !> and per patch the corner whose field its polynomial leaves out (0: none). The
      !> field adds each corner's stress with the union weights of its patches.
      type(singular_fit_type), allocatable :: singular(:)
      integer, allocatable :: patch_corner(:)
      !> Seconds: patch recoveries (t_recovery) and building this field's data (t_field).
      real(wp) :: t_recovery = 0.0_wp, t_field = 0.0_wp
   end type recovered_field_type

contains

   !> Name of a recovery method, for messages and reports.
   pure function method_name(method) result(name)
      integer, intent(in) :: method
      character(len=:), allocatable :: name
      select case (method)
      case (method_spr); name = 'spr'
      case (method_sprc); name = 'sprc'
      case default; name = 'unknown'
      end select
   end function method_name

   !> Recovered stress sigma(1:nstress) at point x(1:dim) of element `elem`. `interpolation`:
   !> interp_default (the method's), interp_nodal (eq. 101) or interp_union (eq. 102).
   !> Errors: field not built, element out of range, short arrays, non-finite x.
   pure subroutine field_eval(field, elem, x, sigma, error, interpolation)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: elem
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: interpolation
      integer :: interp
      character(len=120) :: buf

      interp = interp_default
      if (present(interpolation)) interp = interpolation
      if (.not. allocated(field%nodal)) then
         call fatal_error(error, 'field_eval: the recovered field is not built', stat_invalid_input)
      else if (elem < 1 .or. elem > field%n_elements) then
         write (buf, '("element ",i0," is not in 1..",i0)') elem, field%n_elements
         call fatal_error(error, 'field_eval: '//trim(buf), stat_invalid_input)
      else if (size(x) < field%dim .or. size(sigma) < field%nstress) then
         write (buf, '("x has ",i0," entries (need ",i0,"), sigma ",i0," (need ",i0,")")') size(x), field%dim, &
            & size(sigma), field%nstress
         call fatal_error(error, 'field_eval: '//trim(buf), stat_invalid_input)
      else if (.not. all(abs(x(1:field%dim)) <= huge(1.0_wp))) then
         call fatal_error(error, 'field_eval: x is not finite', stat_invalid_input)
      else if (interp < interp_default .or. interp > interp_union) then
         write (buf, '("interpolation = ",i0," is not 0 (default), 1 (nodal) or 2 (union)")') interp
         call fatal_error(error, 'field_eval: '//trim(buf), stat_invalid_input)
      end if
      if (allocated(error)) return
      call field_eval_unchecked(field, elem, x, interp, sigma)
   end subroutine field_eval

   !> `field_eval` without the checks, for loops over valid elements and points
   !> (1 <= elem <= n_elements, size(x) >= dim, size(sigma) >= nstress).
   pure subroutine field_eval_unchecked(field, elem, x, interpolation, sigma)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: elem
      real(wp), intent(in) :: x(:)
      integer, intent(in) :: interpolation
      real(wp), intent(out) :: sigma(:)
      integer :: interp

      interp = interpolation
      if (interp == interp_default) interp = merge(interp_nodal, interp_union, field%method == method_spr)
      if (interp == interp_nodal) then
         call nodal_at(field, elem, x, sigma)
      else
         call union_at(field, elem, x, sigma)
      end if
      if (allocated(field%singular)) call add_singular(field, elem, x, sigma)
   end subroutine field_eval_unchecked

   !> sigma += sum over the corners c of w_c(x) S_c(x), w_c the Q1 union weight of the
   !> patches that left corner c's field out (module sprc_estimate_singular).
   pure subroutine add_singular(field, e, x, sigma)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(inout) :: sigma(:)
      real(wp) :: xi(3), shp(8), weight(size(field%singular)), s(3)
      integer :: j, k, s0, c

      call reference_point(field, e, x, xi)
      call element_shape(field%dim, 1, xi, shp)
      weight = 0.0_wp
      do j = 1, field%nvertex
         s0 = (e - 1)*field%nvertex + j
         do k = field%corner_ptr(s0), field%corner_ptr(s0 + 1) - 1
            c = field%patch_corner(field%corner_patch(k))
            if (c > 0) weight(c) = weight(c) + shp(j)*field%corner_coef(k)
         end do
      end do
      do c = 1, size(weight)
         if (weight(c) == 0.0_wp) cycle
         call field%singular(c)%corner%stress(x(1:2), s)
         sigma(1:3) = sigma(1:3) + weight(c)*s
      end do
   end subroutine add_singular

   !> Reference coordinates xi in [0, 1]^dim of x in the box of element e.
   pure subroutine reference_point(field, e, x, xi)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: xi(3)
      integer :: d
      d = field%dim
      xi = 0.0_wp
      xi(1:d) = (x(1:d) - field%elem_lo(:, e))/(field%elem_hi(:, e) - field%elem_lo(:, e))
   end subroutine reference_point

   !> Eq. 101: element shape functions times the nodal values.
   pure subroutine nodal_at(field, e, x, sigma)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      real(wp) :: xi(3), shp(27)
      integer :: j, ns

      ns = field%nstress
      call reference_point(field, e, x, xi)
      call element_shape(field%dim, field%fe_degree, xi, shp)
      sigma(1:ns) = 0.0_wp
      do j = 1, field%nodes_per_element
         sigma(1:ns) = sigma(1:ns) + shp(j)*field%nodal_interp(:, field%connectivity(j, e))
      end do
   end subroutine nodal_at

   !> Eq. 102: Q1 partition of unity times the vertex patches' polynomials.
   pure subroutine union_at(field, e, x, sigma)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      type(error_type), allocatable :: err
      real(wp) :: xi(3), shp(8), sj(6)
      integer :: j, k, s, ns

      ns = field%nstress
      call reference_point(field, e, x, xi)
      call element_shape(field%dim, 1, xi, shp)
      sigma(1:ns) = 0.0_wp
      do j = 1, field%nvertex
         s = (e - 1)*field%nvertex + j
         do k = field%corner_ptr(s), field%corner_ptr(s + 1) - 1
            ! Cannot fail: every stored patch comes from a successful solve and sizes are fixed.
            call eval_recovered(field%recs(field%corner_patch(k)), x, sj, err)
            sigma(1:ns) = sigma(1:ns) + (shp(j)*field%corner_coef(k))*sj(1:ns)
         end do
      end do
   end subroutine union_at

   !> Union weights of element `elem` at x: weights(p) = sum of the Q1 weights that reach
   !> patch patches(p), p = 1..npatch (distinct patches, first-appearance order). They sum
   !> to one (up to round-off). For diagnostics and tests; no checks beyond the element range.
   pure subroutine field_union_weights(field, elem, x, patches, weights, npatch, error)
      type(recovered_field_type), intent(in) :: field
      integer, intent(in) :: elem
      real(wp), intent(in) :: x(:)
      !> At least 2**dim * 2**(dim-1) entries (every corner, every master).
      integer, intent(out) :: patches(:)
      real(wp), intent(out) :: weights(:)
      integer, intent(out) :: npatch
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: xi(3), shp(8)
      integer :: j, k, s, p, m

      npatch = 0
      if (elem < 1 .or. elem > field%n_elements .or. .not. allocated(field%corner_ptr)) then
         call fatal_error(error, 'field_union_weights: element out of range or field not built', stat_invalid_input)
         return
      end if
      call reference_point(field, elem, x, xi)
      call element_shape(field%dim, 1, xi, shp)
      do j = 1, field%nvertex
         s = (elem - 1)*field%nvertex + j
         do k = field%corner_ptr(s), field%corner_ptr(s + 1) - 1
            p = field%corner_patch(k)
            m = findloc(patches(1:npatch), p, dim=1)
            if (m == 0) then
               if (npatch == min(size(patches), size(weights))) then
                  call fatal_error(error, 'field_union_weights: output arrays too short', stat_invalid_input)
                  return
               end if
               npatch = npatch + 1
               m = npatch
               patches(m) = p
               weights(m) = 0.0_wp
            end if
            weights(m) = weights(m) + shp(j)*field%corner_coef(k)
         end do
      end do
   end subroutine field_union_weights

   !> Fill the interpolation data of `field` once its patches are recovered (method, degrees,
   !> dim, nstress, n_patches, patch_node, patch_of_node, recs set): element boxes,
   !> connectivity, node coordinates, union corner weights, nodal values (module notes).
   !> Errors (stat_internal): a vertex without a patch that is not a Q1 hanging node, or a
   !> master without a patch.
   subroutine build_field(field, grid, nodes, hanging, error)
      type(recovered_field_type), intent(inout) :: field
      type(grid_type), intent(in) :: grid
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      type(error_type), allocatable, intent(out) :: error
      integer :: e, stat

      field%n_elements = nodes%n_elements
      field%n_nodes = nodes%n_nodes
      field%nodes_per_element = nodes%nodes_per_element
      field%nvertex = 2**field%dim
      field%fe_degree = nodes%degree
      if (.not. allocated(field%elem_lo)) then
         allocate (field%elem_lo(field%dim, field%n_elements), field%elem_hi(field%dim, field%n_elements), stat=stat)
         call check_allocation(stat, 'recovered field', 'the element boxes', field%n_elements, 16*field%dim, error)
         if (allocated(error)) return
         do e = 1, field%n_elements
            call grid%leaf_box(e, field%elem_lo(:, e), field%elem_hi(:, e))
         end do
      end if
      if (allocated(field%connectivity)) deallocate (field%connectivity)
      if (allocated(field%node_x)) deallocate (field%node_x)
      allocate (field%connectivity, mold=nodes%connectivity, stat=stat)
      if (stat == 0) allocate (field%node_x, mold=nodes%x, stat=stat)
      call check_allocation(stat, 'recovered field', 'the connectivity and node coordinates', &
         & int(size(nodes%connectivity), i8) + int(size(nodes%x), i8), 8, error)
      if (allocated(error)) return
      field%connectivity = nodes%connectivity
      field%node_x = nodes%x
      call corner_weights(field, hanging, error)
      if (allocated(error)) return
      call nodal_values(field, nodes, hanging, error)
   end subroutine build_field

   subroutine corner_weights(field, hanging, error)
      type(recovered_field_type), intent(inout) :: field
      type(hanging_type), intent(in) :: hanging
      type(error_type), allocatable, intent(out) :: error
      integer :: pass, e, j, n, k, s, pos, p, stat
      character(len=120) :: buf

      allocate (field%corner_ptr(field%n_elements*field%nvertex + 1), stat=stat)
      call check_allocation(stat, 'recovered field', 'the corner pointers', &
         & int(field%n_elements, i8)*field%nvertex + 1, 4, error)
      if (allocated(error)) return
      ! Pass 1 counts the entries of each corner, pass 2 fills them.
      do pass = 1, 2
         pos = 1
         do e = 1, field%n_elements
            do j = 1, field%nvertex
               s = (e - 1)*field%nvertex + j
               if (pass == 1) field%corner_ptr(s) = pos
               n = field%connectivity(j, e)
               if (field%patch_of_node(n) > 0) then
                  if (pass == 2) then
                     field%corner_patch(pos) = field%patch_of_node(n)
                     field%corner_coef(pos) = 1.0_wp
                  end if
                  pos = pos + 1
               else if (hanging%free_index(n) == 0 .and. field%fe_degree == 1) then
                  do k = hanging%t_ptr(n), hanging%t_ptr(n + 1) - 1
                     p = field%patch_of_node(hanging%free_node(hanging%t_col(k)))
                     if (p == 0) then
                        write (buf, '("master of hanging vertex ",i0," has no patch")') n
                        call fatal_error(error, 'recovered field: '//trim(buf), stat_internal)
                        return
                     end if
                     if (pass == 2) then
                        field%corner_patch(pos) = p
                        field%corner_coef(pos) = hanging%t_val(k)
                     end if
                     pos = pos + 1
                  end do
               else
                  write (buf, '("vertex node ",i0," of element ",i0," has no patch and no Q1 constraint")') n, e
                  call fatal_error(error, 'recovered field: '//trim(buf), stat_internal)
                  return
               end if
            end do
         end do
         if (pass == 1) then
            field%corner_ptr(field%n_elements*field%nvertex + 1) = pos
            allocate (field%corner_patch(pos - 1), field%corner_coef(pos - 1), stat=stat)
            call check_allocation(stat, 'recovered field', 'the corner weights', pos - 1, 12, error)
            if (allocated(error)) return
         end if
      end do
   end subroutine corner_weights

   !> Nodal values of the field: for `nodal_interp`, patch values, unions at free non-vertex
   !> nodes, then hanging constraints; for `nodal`, the method's field at each node.
   subroutine nodal_values(field, nodes, hanging, error)
      type(recovered_field_type), intent(inout) :: field
      type(grid_nodes_type), intent(in) :: nodes
      type(hanging_type), intent(in) :: hanging
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      integer :: n, k, e, ns, stat

      ns = field%nstress
      allocate (field%nodal_interp(ns, field%n_nodes), field%nodal(ns, field%n_nodes), stat=stat)
      call check_allocation(stat, 'recovered field', 'the nodal stresses', int(ns, i8)*field%n_nodes, 16, error)
      if (allocated(error)) return
      !$omp parallel do schedule(static) private(e, err)
      do n = 1, field%n_nodes
         e = nodes%node_element(nodes%node_element_ptr(n))
         if (field%patch_of_node(n) > 0) then
            call eval_recovered(field%recs(field%patch_of_node(n)), field%node_x(:, n), field%nodal_interp(:, n), err)
            field%nodal(:, n) = field%nodal_interp(:, n)
         else
            call union_at(field, e, field%node_x(:, n), field%nodal(:, n))
            field%nodal_interp(:, n) = field%nodal(:, n)
         end if
      end do
      !$omp end parallel do
      ! Hanging nodes: masters are free (hanging_type resolves chains), so one pass suffices.
      do n = 1, field%n_nodes
         if (hanging%free_index(n) /= 0) cycle
         field%nodal_interp(:, n) = 0.0_wp
         do k = hanging%t_ptr(n), hanging%t_ptr(n + 1) - 1
            field%nodal_interp(:, n) = field%nodal_interp(:, n) + &
               & hanging%t_val(k)*field%nodal_interp(:, hanging%free_node(hanging%t_col(k)))
         end do
         if (field%method == method_spr) field%nodal(:, n) = field%nodal_interp(:, n)
      end do
      if (.not. allocated(field%singular)) return
      do n = 1, field%n_nodes
         call add_singular(field, nodes%node_element(nodes%node_element_ptr(n)), field%node_x(:, n), field%nodal(:, n))
      end do
   end subroutine nodal_values

end module sprc_estimate_recovered_field
