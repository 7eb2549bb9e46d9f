!> Validation of the input of recovery on a caller's mesh (`sprc_recovery_mesh`).
!>
!> Every check names the argument, the index and the value, so that a legacy caller can
!> find the offending entry: options and codes first, then shapes, then values (finite
!> coordinates, connectivity in range without repeated nodes, positive finite weights,
!> finite stresses, facet kinds and nodes, finite tractions and body force).
module sprc_recovery_mesh_check
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, check_material
   use sprc_core_poly, only: poly_max_degree
   use sprc_recovery_mesh_element, only: element_known, element_dim, element_nodes, element_facet_nodes, &
      & element_name, elem_tri3, elem_quad4, elem_tet4, elem_hex8, elem_quad9, elem_hex27
   implicit none
   private

   public :: check_mesh_options, check_mesh_arrays, check_mesh_facets, itoa, rtoa
   public :: mesh_method_spr, mesh_method_sprc, facet_traction, facet_symmetry, facet_free

   !> Recovery methods (values are part of the C API; never renumber).
   integer, parameter :: mesh_method_spr = 1, mesh_method_sprc = 2
   !> Facet kinds (values are part of the C API; never renumber): prescribed traction
   !> (its value per facet), symmetry plane (zero shear), free surface (zero traction).
   integer, parameter :: facet_traction = 1, facet_symmetry = 2, facet_free = 3

contains

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
   !> body force (options already checked).
   pure subroutine check_mesh_arrays(dim, analysis, nodes, element_type, connectivity, gp, gw, gs, error, &
         & body_force)
      integer, intent(in) :: dim, analysis, element_type
      real(wp), intent(in) :: nodes(:, :)
      integer, intent(in) :: connectivity(:, :)
      real(wp), intent(in) :: gp(:, :, :), gw(:, :), gs(:, :, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: body_force(:)
      integer :: nnode, nelem, nen, ngp, ns, e, a, b, i

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
            call fail(error, 'nodes(:, '//itoa(i)//') is not finite')
            return
         end if
      end do
      do e = 1, nelem
         do a = 1, nen
            if (connectivity(a, e) < 1 .or. connectivity(a, e) > nnode) then
               call fail(error, 'connectivity('//itoa(a)//', '//itoa(e)//') = '//itoa(connectivity(a, e))// &
                  & ' is not a node in 1..'//itoa(nnode))
               return
            end if
            do b = 1, a - 1
               if (connectivity(b, e) == connectivity(a, e)) then
                  call fail(error, 'element '//itoa(e)//' repeats node '//itoa(connectivity(a, e))// &
                     & ' (local nodes '//itoa(b)//' and '//itoa(a)//')')
                  return
               end if
            end do
         end do
         do i = 1, ngp
            if (.not. all(abs(gp(:, i, e)) <= huge(1.0_wp))) then
               call fail(error, 'gp(:, '//itoa(i)//', '//itoa(e)//') is not finite')
            else if (.not. (gw(i, e) > 0.0_wp .and. gw(i, e) <= huge(1.0_wp))) then
               call fail(error, 'gw('//itoa(i)//', '//itoa(e)//') = '//rtoa(gw(i, e))//' must be finite and > 0')
            else if (.not. all(abs(gs(:, i, e)) <= huge(1.0_wp))) then
               call fail(error, 'gs(:, '//itoa(i)//', '//itoa(e)//') is not finite (NaN or Inf)')
            end if
            if (allocated(error)) return
         end do
      end do
   end subroutine check_mesh_arrays

   !> Facet arrays: given together, shapes, kinds, node range, finite tractions.
   pure subroutine check_mesh_facets(dim, element_type, nnode, error, facet_nodes, facet_kind, facet_traction_value)
      integer, intent(in) :: dim, element_type, nnode
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: facet_nodes(:, :), facet_kind(:)
      real(wp), intent(in), optional :: facet_traction_value(:, :)
      integer :: nf, nfn, f, a

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
         case (facet_traction)
            if (.not. present(facet_traction_value)) then
               call fail(error, 'facet '//itoa(f)//' has kind traction but facet_traction is not given')
            else if (.not. all(abs(facet_traction_value(:, f)) <= huge(1.0_wp))) then
               call fail(error, 'facet_traction(:, '//itoa(f)//') is not finite')
            end if
         case (facet_symmetry, facet_free)
         case default
            call fail(error, 'facet_kind('//itoa(f)//') = '//itoa(facet_kind(f))// &
               & ' is not traction = 1, symmetry = 2 or free = 3')
         end select
         if (allocated(error)) return
         do a = 1, nfn
            if (facet_nodes(a, f) < 1 .or. facet_nodes(a, f) > nnode) then
               call fail(error, 'facet_nodes('//itoa(a)//', '//itoa(f)//') = '//itoa(facet_nodes(a, f))// &
                  & ' is not a node in 1..'//itoa(nnode))
               return
            end if
         end do
      end do
   end subroutine check_mesh_facets

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

   !> Integer as text.
   pure function itoa(i) result(s)
      integer, intent(in) :: i
      character(len=:), allocatable :: s
      character(len=16) :: buf
      write (buf, '(i0)') i
      s = trim(buf)
   end function itoa

   !> Real as text (es12.4).
   pure function rtoa(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(es12.4)') x
      s = trim(adjustl(buf))
   end function rtoa

end module sprc_recovery_mesh_check
