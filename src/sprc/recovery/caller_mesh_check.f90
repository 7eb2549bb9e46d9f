!> Validation of the input of recovery on a caller's mesh (`sprc_recovery_caller_mesh`).
!>
!> Every check names the argument, the index and the value, so that a legacy caller can
!> find the offending entry: options and codes first, then shapes, then values (finite
!> coordinates, connectivity in range without repeated nodes, positive finite weights,
!> finite stresses, facet kinds and nodes, finite tractions and body force), then
!> duplicates (two used nodes at the same point, two elements on the same vertices).
!>
!> Indices in messages follow the caller's language (`c_indices`): Fortran's 1-based,
!> column-major `gw(3, 1)`, or for the C and Python entries 0-based, row-major
!> `gauss_weights[0][2]` with the C argument names (module procedure `entry_name`).
module sprc_recovery_caller_mesh_check
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: itoa, rtoa
   use sprc_core_alloc, only: check_allocation
   use sprc_core_hash, only: hash_real
   use sprc_core_boundary, only: bc_traction, bc_symmetry, bc_free, bc_pressure
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, check_material
   use sprc_core_poly, only: poly_max_degree
   use sprc_recovery_caller_mesh_element, only: element_known, element_dim, element_nodes, element_facet_nodes, &
      & element_name, elem_tri3, elem_quad4, elem_tet4, elem_hex8, elem_quad9, elem_hex27
   implicit none
   private

   public :: check_mesh_options, check_mesh_arrays, check_mesh_facets, check_duplicate_nodes, &
      & check_duplicate_elements, vec_str, entry_name, index_name
   public :: mesh_reference_unit, mesh_reference_symmetric, reference_cell_name
   public :: mesh_method_spr, mesh_method_sprc, facet_traction, facet_symmetry, facet_free, facet_pressure
   public :: method_code_type, decode_method, method_flag_p_plus_1, method_flag_p, method_flag_no_edges, method_mask

   !> Recovery methods (values are part of the C API; never renumber).
   integer, parameter :: mesh_method_spr = 1, mesh_method_sprc = 2
   !> Flags OR-ed into an integer method code by the C and legacy entries (values are part of
   !> the C API, sprc.h SPRC_RECOVERY_P_PLUS_1, SPRC_RECOVERY_P, SPRC_CONTACT_NO_EDGES): the
   !> patch degree one above the element's, or the element's (neither: 'auto'); for contact
   !> entries only, no edge field at the edges of contact zones. The low byte is the method.
   integer, parameter :: method_flag_p_plus_1 = 256, method_flag_p = 512, method_flag_no_edges = 1024, &
      & method_mask = 255

   !> An integer method code split into the method proper and its flags.
   type :: method_code_type
      !> `mesh_method_spr` or `mesh_method_sprc`; the patch degree above the element's: 1,
      !> 0, or -1 for 'auto'.
      integer :: method = 0, degree_above = -1
      !> The edge field at the edges of contact zones (contact entries).
      logical :: edges = .true.
   end type method_code_type
   !> Conventions of the caller's reference coordinates (gauss_xi; values are part of the C
   !> API, SPRC_REFERENCE_*): 'unit' quads and hexes on [0, 1]^dim (the element library's own),
   !> 'symmetric' on [-1, 1]^dim (most FE codes'); triangles and tetrahedra are the unit
   !> simplex (xi >= 0, sum xi <= 1) in both.
   integer, parameter :: mesh_reference_unit = 0, mesh_reference_symmetric = 1
   !> Facet kinds, the boundary kinds of `sprc_core_boundary` a facet can have (values are
   !> part of the C API, SPRC_FACET_*): prescribed traction (its value per facet), symmetry
   !> plane (zero shear), free surface (zero traction), pressure p = facet_traction(1, f)
   !> (t = -p n with the facet's own normal at each point).
   integer, parameter :: facet_traction = bc_traction, facet_symmetry = bc_symmetry, facet_free = bc_free, &
      & facet_pressure = bc_pressure

contains

   !> Split `code`, the `method` argument of entry `entry`, into the method and its flags:
   !> SPR or SPR-C, no unknown bit (SPRC_CONTACT_NO_EDGES is known to `contact` entries
   !> only), not both degree flags.
   pure subroutine decode_method(entry, code, contact, decoded, error)
      character(len=*), intent(in) :: entry
      integer, intent(in) :: code
      logical, intent(in) :: contact
      type(method_code_type), intent(out) :: decoded
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: flags
      integer :: known

      known = ior(method_mask, ior(method_flag_p_plus_1, method_flag_p))
      flags = 'SPRC_RECOVERY_P_PLUS_1 = 256 and SPRC_RECOVERY_P = 512'
      if (contact) then
         known = ior(known, method_flag_no_edges)
         flags = 'SPRC_RECOVERY_P_PLUS_1 = 256, SPRC_RECOVERY_P = 512 and SPRC_CONTACT_NO_EDGES = 1024'
      end if
      if (iand(code, not(known)) /= 0) then
         call fail(error, entry//': method = '//itoa(code)//' has unknown flag bits (the flags are '//flags//')')
      else if (iand(code, method_flag_p_plus_1) /= 0 .and. iand(code, method_flag_p) /= 0) then
         call fail(error, entry//': method = '//itoa(code)//' sets both SPRC_RECOVERY_P_PLUS_1 and '// &
            & 'SPRC_RECOVERY_P')
      else if (iand(code, method_mask) /= mesh_method_spr .and. iand(code, method_mask) /= mesh_method_sprc) then
         call fail(error, entry//': method = '//itoa(code)//' is not SPRC_METHOD_SPR (1) or SPRC_METHOD_SPRC (2), '// &
            & 'optionally with the flags '//flags)
      else
         decoded%method = iand(code, method_mask)
         if (iand(code, method_flag_p) /= 0) decoded%degree_above = 0
         if (iand(code, method_flag_p_plus_1) /= 0) decoded%degree_above = 1
         decoded%edges = iand(code, method_flag_no_edges) == 0
      end if
   end subroutine decode_method

   !> Codes and scalars: dim, analysis (and its fit to dim), element type (and its dim),
   !> method, degree, expansion rounds, material.
   pure subroutine check_mesh_options(dim, analysis, element_type, method, degree, max_rounds, young, poisson, &
         & error)
      integer, intent(in) :: dim, analysis, element_type, method, degree, max_rounds
      real(wp), intent(in) :: young, poisson
      type(error_type), allocatable, intent(out) :: error

      if (dim /= 2 .and. dim /= 3) then
         call fail(error, 'dim = '//itoa(dim)//' is not 2 or 3')
      else if (voigt_size(analysis) == 0 .or. (dim == 3 .neqv. analysis == solid)) then
         call fail(error, 'analysis = '//itoa(analysis)//' does not fit dim = '//itoa(dim)//' (plane_stress = '// &
            & itoa(plane_stress)//' or plane_strain = '//itoa(plane_strain)//' in 2D, solid = '//itoa(solid)// &
            & ' in 3D)')
      else if (.not. element_known(element_type)) then
         call fail(error, 'element_type = '//itoa(element_type)//' is unknown (tri3 = '//itoa(elem_tri3)// &
            & ', quad4 = '//itoa(elem_quad4)//', quad9 = '//itoa(elem_quad9)//', tet4 = '//itoa(elem_tet4)// &
            & ', hex8 = '//itoa(elem_hex8)//', hex27 = '//itoa(elem_hex27)//')')
      else if (element_dim(element_type) /= dim) then
         call fail(error, 'element_type = '//itoa(element_type)//' ('//element_name(element_type)//') is a '// &
            & itoa(element_dim(element_type))//'D element, dim = '//itoa(dim))
      else if (method /= mesh_method_spr .and. method /= mesh_method_sprc) then
         call fail(error, 'method = '//itoa(method)//' is not spr (1) or sprc (2)')
      else if (degree < 1 .or. degree > poly_max_degree) then
         call fail(error, 'degree = '//itoa(degree)//' is not in 1..'//itoa(poly_max_degree))
      else if (max_rounds < 0) then
         call fail(error, 'max_rounds = '//itoa(max_rounds)//' is negative')
      else
         call check_material(young, poisson, 'recover_on_mesh', error)
      end if
   end subroutine check_mesh_options

   !> Shapes and values of nodes, connectivity, integration points, weights, stresses and
   !> body force (options already checked). Shapes are named in Fortran order (the C entry
   !> checks its own counts first); entries in the caller's convention (`c_indices`).
   subroutine check_mesh_arrays(dim, analysis, nodes, element_type, connectivity, gp, gw, gs, c_indices, &
         & error, body_force)
      integer, intent(in) :: dim, analysis, element_type
      real(wp), intent(in) :: nodes(:, :)
      integer, intent(in) :: connectivity(:, :)
      real(wp), intent(in), contiguous :: gp(:, :, :), gw(:, :), gs(:, :, :)
      logical, intent(in) :: c_indices
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: body_force(:)
      integer :: nnode, nelem, nen, ngp, ns, e, a, b, i, bad

      nnode = size(nodes, 2)
      nelem = size(connectivity, 2)
      nen = element_nodes(element_type)
      ngp = size(gp, 2)
      ns = voigt_size(analysis)
      if (size(nodes, 1) /= dim .or. nnode < 1) then
         call fail(error, 'nodes has shape ('//itoa(size(nodes, 1))//', '//itoa(nnode)//'), need ('//itoa(dim)// &
            & ', nnode >= 1)')
      else if (size(connectivity, 1) /= nen .or. nelem < 1) then
         call fail(error, 'connectivity has shape ('//itoa(size(connectivity, 1))//', '//itoa(nelem)//'), need ('// &
            & itoa(nen)//' nodes of '//element_name(element_type)//', nelem >= 1)')
      else if (size(gp, 1) /= dim .or. size(gp, 3) /= nelem .or. ngp < 1) then
         call fail(error, 'gp has shape '//shape_str(shape(gp))//', need ('//itoa(dim)//', ngp >= 1, '// &
            & itoa(nelem)//')')
      else if (size(gw, 1) /= ngp .or. size(gw, 2) /= nelem) then
         call fail(error, 'gw has shape '//shape_str(shape(gw))//', need ('//itoa(ngp)//', '//itoa(nelem)//')')
      else if (size(gs, 1) /= ns .or. size(gs, 2) /= ngp .or. size(gs, 3) /= nelem) then
         call fail(error, 'gs has shape '//shape_str(shape(gs))//', need ('//itoa(ns)//', '//itoa(ngp)//', '// &
            & itoa(nelem)//')')
      end if
      if (allocated(error)) return
      if (present(body_force)) then
         if (size(body_force) /= dim) then
            call fail(error, 'body_force has '//itoa(size(body_force))//' entries, need dim = '//itoa(dim))
         else if (.not. all(abs(body_force) <= huge(1.0_wp))) then
            call fail(error, 'body_force is not finite')
         end if
         if (allocated(error)) return
      end if
      do i = 1, nnode
         if (.not. all(abs(nodes(:, i)) <= huge(1.0_wp))) then
            call fail(error, entry_name(c_indices, 'nodes', 'nodes', [0, i])//' is not finite')
            return
         end if
      end do
      ! The first element with a bad entry, found in parallel; its message serially.
      bad = nelem + 1
      !$omp parallel do schedule(static) reduction(min:bad)
      do e = 1, nelem
         if (.not. element_ok(e)) bad = min(bad, e)
      end do
      !$omp end parallel do
      if (bad > nelem) return
      e = bad
      do a = 1, nen
         if (connectivity(a, e) < 1 .or. connectivity(a, e) > nnode) then
            call fail(error, entry_name(c_indices, 'connectivity', 'connectivity', [a, e])//' = '// &
               & index_name(c_indices, connectivity(a, e))//' is not a node in '//index_name(c_indices, 1)// &
               & '..'//index_name(c_indices, nnode))
            return
         end if
         do b = 1, a - 1
            if (connectivity(b, e) == connectivity(a, e)) then
               call fail(error, 'element '//index_name(c_indices, e)//' repeats node '// &
                  & index_name(c_indices, connectivity(a, e))//' (local nodes '//index_name(c_indices, b)// &
                  & ' and '//index_name(c_indices, a)//')')
               return
            end if
         end do
      end do
      do i = 1, ngp
         if (.not. all(abs(gp(:, i, e)) <= huge(1.0_wp))) then
            call fail(error, entry_name(c_indices, 'gp', 'gauss_points', [0, i, e])//' is not finite')
         else if (.not. (gw(i, e) > 0.0_wp .and. gw(i, e) <= huge(1.0_wp))) then
            call fail(error, entry_name(c_indices, 'gw', 'gauss_weights', [i, e])//' = '//rtoa(gw(i, e))// &
               & ' must be finite and > 0')
         else if (.not. all(abs(gs(:, i, e)) <= huge(1.0_wp))) then
            call fail(error, entry_name(c_indices, 'gs', 'gauss_stress', [0, i, e])//' is not finite (NaN or Inf)')
         end if
         if (allocated(error)) return
      end do
   contains
      !> Connectivity in range without repeats, finite points and stresses, weights > 0.
      pure logical function element_ok(e) result(ok)
         integer, intent(in) :: e
         integer :: a, b, i
         ok = .false.
         do a = 1, nen
            if (connectivity(a, e) < 1 .or. connectivity(a, e) > nnode) return
            do b = 1, a - 1
               if (connectivity(b, e) == connectivity(a, e)) return
            end do
         end do
         ! Whole columns of the element at once (one loop each instead of one per point;
         ! the message names the point, serially).
         if (.not. finite(size(gp(:, :, e)), gp(:, :, e))) return
         if (.not. finite(size(gs(:, :, e)), gs(:, :, e))) return
         do i = 1, ngp
            if (.not. (gw(i, e) > 0.0_wp .and. gw(i, e) <= huge(1.0_wp))) return
         end do
         ok = .true.
      end function element_ok
      !> All n values of v finite.
      pure logical function finite(n, v)
         integer, intent(in) :: n
         real(wp), intent(in) :: v(n)
         integer :: k
         finite = .false.
         do k = 1, n
            if (.not. (abs(v(k)) <= huge(1.0_wp))) return
         end do
         finite = .true.
      end function finite
   end subroutine check_mesh_arrays

   !> Facet arrays: given together, shapes, kinds, node range, finite tractions (pressure
   !> facets: the pressure facet_traction(1, f)).
   pure subroutine check_mesh_facets(dim, element_type, nnode, c_indices, error, facet_nodes, facet_kind, &
         & facet_traction_value)
      integer, intent(in) :: dim, element_type, nnode
      logical, intent(in) :: c_indices
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: facet_nodes(:, :), facet_kind(:)
      real(wp), intent(in), optional :: facet_traction_value(:, :)
      integer :: nf, nfn, f, a, nval

      if (present(facet_nodes) .neqv. present(facet_kind)) then
         call fail(error, 'facet_nodes and facet_kind must be given together')
         return
      end if
      if (.not. present(facet_nodes)) return
      nf = size(facet_nodes, 2)
      nfn = element_facet_nodes(element_type)
      if (size(facet_nodes, 1) /= nfn .and. nf > 0) then
         call fail(error, 'facet_nodes has '//itoa(size(facet_nodes, 1))//' rows, a facet of '// &
            & element_name(element_type)//' has '//itoa(nfn)//' nodes')
      else if (size(facet_kind) /= nf) then
         call fail(error, 'facet_kind has '//itoa(size(facet_kind))//' entries, facet_nodes '//itoa(nf)//' facets')
      end if
      if (allocated(error)) return
      if (present(facet_traction_value)) then
         if (size(facet_traction_value, 1) /= dim .or. size(facet_traction_value, 2) /= nf) then
            call fail(error, 'facet_traction has shape '//shape_str(shape(facet_traction_value))//', need ('// &
               & itoa(dim)//', '//itoa(nf)//')')
            return
         end if
      end if
      do f = 1, nf
         select case (facet_kind(f))
         case (facet_traction, facet_pressure)
            nval = merge(dim, 1, facet_kind(f) == facet_traction)
            if (.not. present(facet_traction_value)) then
               call fail(error, 'facet '//index_name(c_indices, f)//' has kind '// &
                  & trim(merge('traction', 'pressure', facet_kind(f) == facet_traction))// &
                  & ' but facet_traction is not given')
            else if (.not. all(abs(facet_traction_value(1:nval, f)) <= huge(1.0_wp))) then
               call fail(error, entry_name(c_indices, 'facet_traction', 'facet_traction', [0, f])//' is not finite')
            end if
         case (facet_symmetry, facet_free)
         case default
            call fail(error, entry_name(c_indices, 'facet_kind', 'facet_kind', [f])//' = '//itoa(facet_kind(f))// &
               & ' is not traction = 1, symmetry = 2, free = 3 or pressure = 4')
         end select
         if (allocated(error)) return
         do a = 1, nfn
            if (facet_nodes(a, f) < 1 .or. facet_nodes(a, f) > nnode) then
               call fail(error, entry_name(c_indices, 'facet_nodes', 'facet_nodes', [a, f])//' = '// &
                  & index_name(c_indices, facet_nodes(a, f))//' is not a node in '//index_name(c_indices, 1)//'..'// &
                  & index_name(c_indices, nnode))
               return
            end if
         end do
      end do
   end subroutine check_mesh_facets

   !> No two nodes used by elements at the same point (bitwise equal coordinates, -0 = +0):
   !> such a mesh is not connected there, and its patches would silently stop at the seam.
   !> A hash table of the used nodes (sprc_core_hash: every bit of the coordinates reaches
   !> the slot, so dyadic coordinates do not collide): O(nnode) expected. The first node
   !> equal to an earlier one is reported, whatever the hash. `probes`: the table slots
   !> read in all (the cost, for tests: about 2.5 per node at load 2/3 if the hash spreads
   !> the keys as a random function would).
   pure subroutine check_duplicate_nodes(nodes, used, c_indices, error, probes)
      real(wp), intent(in) :: nodes(:, :)
      logical, intent(in) :: used(:)
      logical, intent(in) :: c_indices
      type(error_type), allocatable, intent(out) :: error
      integer(i8), intent(out), optional :: probes
      integer, allocatable :: table(:)
      integer :: n, nslot, slot, m, stat
      integer(i8) :: nprobe

      ! A power of two at least 1.5 times the used nodes: load at most 2/3, short probe chains
      ! in adjacent slots, and a table half the size of one at load 1/2 (262,144 nodes: 2 MB,
      ! which stays in a core's L2 cache; its accesses are random).
      nslot = 4
      do while (2*nslot < 3*count(used))
         nslot = 2*nslot
      end do
      allocate (table(nslot), stat=stat)
      call check_allocation(stat, 'mesh check', 'the duplicate-node hash table', nslot, 4, error)
      if (allocated(error)) return
      table = 0
      nprobe = 0
      do n = 1, size(nodes, 2)
         if (.not. used(n)) cycle
         slot = int(iand(hash_real(nodes(:, n)), int(nslot - 1, i8))) + 1
         do
            nprobe = nprobe + 1
            m = table(slot)
            if (m == 0) exit
            if (all(nodes(:, m) == nodes(:, n))) then
               call fail(error, 'nodes '//index_name(c_indices, m)//' and '//index_name(c_indices, n)// &
                  & ' are at the same point '//vec_str(nodes(:, n))//' (duplicate nodes: merge them; a crack or '// &
                  & 'an interface is two meshes, recovered one at a time)')
               if (present(probes)) probes = nprobe
               return
            end if
            slot = mod(slot, nslot) + 1
         end do
         table(slot) = n
      end do
      if (present(probes)) probes = nprobe
   end subroutine check_duplicate_nodes

   !> No two elements on the same set of vertices (a repeated element would count its
   !> points twice). Candidates share the first vertex: ne_ptr / ne_list is the node ->
   !> element CSR (elements ascending per node); O(nelem) for bounded valence.
   subroutine check_duplicate_elements(connectivity, nvertex, ne_ptr, ne_list, c_indices, error)
      integer, intent(in) :: connectivity(:, :), nvertex, ne_ptr(:), ne_list(:)
      logical, intent(in) :: c_indices
      type(error_type), allocatable, intent(out) :: error
      integer :: e, bad

      bad = size(connectivity, 2) + 1
      !$omp parallel do schedule(static) reduction(min:bad)
      do e = 1, size(connectivity, 2)
         if (twin(e) > 0) bad = min(bad, e)
      end do
      !$omp end parallel do
      if (bad > size(connectivity, 2)) return
      call fail(error, 'elements '//index_name(c_indices, twin(bad))//' and '//index_name(c_indices, bad)// &
         & ' have the same vertices (duplicate elements)')
   contains
      !> An element before e on the same vertices, 0 if none.
      pure integer function twin(e) result(o)
         integer, intent(in) :: e
         integer :: k, n, a
         n = connectivity(1, e)
         do k = ne_ptr(n), ne_ptr(n + 1) - 1
            o = ne_list(k)
            if (o >= e) exit
            do a = 1, nvertex
               if (.not. any(connectivity(1:nvertex, o) == connectivity(a, e))) exit
            end do
            if (a > nvertex) return
         end do
         o = 0
      end function twin
   end subroutine check_duplicate_elements

   !> The reference cell of element_type in the convention `reference`, for messages.
   pure function reference_cell_name(element_type, reference) result(s)
      integer, intent(in) :: element_type, reference
      character(len=:), allocatable :: s
      select case (element_type)
      case (elem_tri3)
         s = 'the unit triangle xi >= 0, xi_1 + xi_2 <= 1 (either reference)'
      case (elem_tet4)
         s = 'the unit tetrahedron xi >= 0, xi_1 + xi_2 + xi_3 <= 1 (either reference)'
      case default
         if (reference == mesh_reference_symmetric) then
            s = '[-1, 1]^'//itoa(element_dim(element_type))//" (reference 'symmetric'; 'unit' takes [0, 1]^"// &
               & itoa(element_dim(element_type))//')'
         else
            s = '[0, 1]^'//itoa(element_dim(element_type))//" (reference 'unit', the default; 'symmetric' takes "// &
               & '[-1, 1]^'//itoa(element_dim(element_type))//')'
         end if
      end select
   end function reference_cell_name

   !> An array entry as the caller writes it. idx are Fortran indices (1-based, 0 for a
   !> whole dimension ':'): Fortran `fname(:, 3, 1)`; C (c_indices) `cname[0][2]`, the
   !> indices reversed, 0-based, whole dimensions (the leading Fortran ones) left out.
   pure function entry_name(c_indices, fname, cname, idx) result(s)
      logical, intent(in) :: c_indices
      character(len=*), intent(in) :: fname, cname
      integer, intent(in) :: idx(:)
      character(len=:), allocatable :: s
      integer :: i

      if (c_indices) then
         s = cname
         do i = size(idx), 1, -1
            if (idx(i) > 0) s = s//'['//itoa(idx(i) - 1)//']'
         end do
      else
         s = fname//'('
         do i = 1, size(idx)
            if (idx(i) > 0) then
               s = s//itoa(idx(i))
            else
               s = s//':'
            end if
            if (i < size(idx)) s = s//', '
         end do
         s = s//')'
      end if
   end function entry_name

   !> A 1-based index i (node, element, facet, point) as the caller counts it.
   pure function index_name(c_indices, i) result(s)
      logical, intent(in) :: c_indices
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      s = itoa(merge(i - 1, i, c_indices))
   end function index_name

   pure function vec_str(v) result(s)
      real(wp), intent(in) :: v(:)
      character(len=:), allocatable :: s
      integer :: i
      s = '('
      do i = 1, size(v)
         s = s//rtoa(v(i))
         if (i < size(v)) s = s//', '
      end do
      s = s//')'
   end function vec_str

   pure subroutine fail(error, message)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      call fatal_error(error, 'recover_on_mesh: '//message, stat_invalid_input)
   end subroutine fail

   pure function shape_str(s) result(str)
      integer, intent(in) :: s(:)
      character(len=:), allocatable :: str
      integer :: i
      str = '('
      do i = 1, size(s)
         str = str//itoa(s(i))
         if (i < size(s)) str = str//', '
      end do
      str = str//')'
   end function shape_str

end module sprc_recovery_caller_mesh_check
