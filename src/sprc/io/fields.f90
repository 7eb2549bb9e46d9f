!> The fields of one study level as named arrays (`level_fields`), and their
!> HDF5 output (layout in `sprc_io_xdmf`). One implementation for both: the
!> HDF5 file and the C API's study handle (`sprc_capi_study`) hold the arrays
!> built here, so they carry the same bits.
!>
!> Per body (a grid named after it; `nodes` (dim, n_nodes), `cells`
!> (nodes_per_cell, n_cells), 1-based here): node fields `inside` (1 where
!> the node lies in the body or on its boundary, within the geometry's
!> snapping tolerance; 0 for the grid's nodes beyond it), `displacement`
!> (dim), `sigma_fe` (the average of the elements' FE stresses at the node),
!> `sigma_spr`, `sigma_sprc` (recovered, where run); cell fields
!> `zz_error_spr`, `zz_error_sprc` (ZZ indicator of each element, energy
!> norm, where run), `exact_error_fe` (with an exact solution), `cut` (1 for
!> a cell the boundary crosses), `volume_fraction` (the share of the cell in
!> the body: every cell of the grid meets the body, cells beyond it are not
!> in the grid), `cell_level` (the cell's refinement level). Stresses in
!> Voigt order, xx yy xy (2D) or xx yy zz xy yz xz (3D).
!> Per `&contact` pair (a grid `contact_<k>` of Polyvertex cells, one per
!> slave-surface quadrature point; `nodes` are the points): the columns of
!> `PREFIX_contact.csv` (`p_fe`, `p_spr`, `p_sprc`, `p_exact`, `p_fe_stress`, `gap`,
!> `ts_fe`, `ts_sprc`, `weight`, `state` 0 open / 1 stick / 2 slip) and the
!> slave normal `normal` (dim).
!> Values in the scene's units (the analysis ran in `units`); an empty value
!> (not computed) is NaN. Each field carries its units in words (`units`).
!> An adaptive study (`&adapt`) writes each step under `/level_SS/`, SS the
!> step (0 the start mesh), not a level (the steps' finest levels repeat).
module sprc_io_fields
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   use sprc_geometry_region, only: cell_cut, cell_outside
   use sprc_geometry_body, only: body_type
   use sprc_study_level, only: study_type, level_type, body_level_type, nodal_fe_stress
   use sprc_study_model, only: analysis_units_type
   use sprc_io_hdf5, only: h5_output_type
   use sprc_io_xdmf, only: cell_quad4, cell_quad9, cell_hex8, cell_hex27, cell_vertex, center_node, center_cell, &
      & max_name_length
   use sprc_core_text, only: itoa
   use sprc_contact_result, only: contact_result_type
   implicit none
   private

   !> The writer, as allocation errors name it.
   character(len=*), parameter :: who = 'level fields'

   public :: field_array_type, grid_fields_type, level_fields_type
   public :: level_fields, write_level_fields, write_grid_fields

   !> One named field: real or integer values (ncomp, n) at the nodes or cells of its grid.
   type :: field_array_type
      character(len=:), allocatable :: name
      !> `center_node` or `center_cell` (sprc_io_xdmf).
      integer :: center = center_node
      !> The values: `reals` for a real field, `ints` for an integer one.
      real(wp), allocatable :: reals(:, :)
      integer, allocatable :: ints(:, :)
      !> Component names (Voigt stresses), not allocated for a scalar or vector.
      character(len=max_name_length), allocatable :: components(:)
      !> The units in words ('' for a number without units).
      character(len=:), allocatable :: units
   end type field_array_type

   !> The mesh and fields of one body, or the point set of one contact pair, at one level.
   type :: grid_fields_type
      !> The body's name, or `contact_<k>` for pair k (sprc_io_xdmf).
      character(len=:), allocatable :: name
      logical :: is_contact = .false.
      !> `cell_quad4` ... `cell_vertex` (sprc_io_xdmf).
      integer :: cell_type = 0
      !> Node coordinates (dim, n_nodes); connectivity (nodes_per_cell, n_cells), 1-based, VTK order.
      real(wp), allocatable :: nodes(:, :)
      integer, allocatable :: cells(:, :)
      integer :: n_fields = 0
      type(field_array_type), allocatable :: fields(:)
   end type grid_fields_type

   !> Every grid of one level: the bodies in scene order, then the contact pairs.
   type :: level_fields_type
      integer :: level = 0
      type(grid_fields_type), allocatable :: grids(:)
   end type level_fields_type

contains

   !> Write every body and contact pair of `result` (a level of `study`) into `h5`;
   !> with `step` (an adaptive study's step), under that number instead of the level.
   subroutine write_level_fields(h5, study, result, error, step)
      type(h5_output_type), intent(inout) :: h5
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: step
      type(level_fields_type) :: fields
      integer :: g, key

      call level_fields(study, result, fields, error)
      if (allocated(error)) return
      key = fields%level
      if (present(step)) key = step
      do g = 1, size(fields%grids)
         call write_grid_fields(h5, key, fields%grids(g), error)
         if (allocated(error)) return
      end do
   end subroutine write_level_fields

   !> One grid's mesh and fields into `h5` at `level` (a contact pair without points writes nothing).
   subroutine write_grid_fields(h5, level, grid, error)
      type(h5_output_type), intent(inout) :: h5
      integer, intent(in) :: level
      type(grid_fields_type), intent(in) :: grid
      type(error_type), allocatable, intent(out) :: error
      integer :: f

      if (size(grid%cells, 2) == 0) return
      call h5%write_level(level, grid%nodes, grid%cells, grid%cell_type, error, body=grid%name)
      if (allocated(error)) return
      do f = 1, grid%n_fields
         associate (fa => grid%fields(f))
            if (fa%center == center_node) then
               if (allocated(fa%reals)) then
                  call h5%write_node_field(level, fa%name, fa%reals, error, components=fa%components, &
                     & body=grid%name, units=fa%units)
               else
                  call h5%write_node_field(level, fa%name, fa%ints, error, components=fa%components, &
                     & body=grid%name, units=fa%units)
               end if
            else
               if (allocated(fa%reals)) then
                  call h5%write_cell_field(level, fa%name, fa%reals, error, components=fa%components, &
                     & body=grid%name, units=fa%units)
               else
                  call h5%write_cell_field(level, fa%name, fa%ints, error, components=fa%components, &
                     & body=grid%name, units=fa%units)
               end if
            end if
         end associate
         if (allocated(error)) return
      end do
   end subroutine write_grid_fields

   !> The fields of every body and contact pair of `result` (a level of `study`).
   subroutine level_fields(study, result, fields, error)
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      type(level_fields_type), intent(out) :: fields
      type(error_type), allocatable, intent(out) :: error
      integer :: cell_type, b, n_contacts

      if (study%dim == 2) then
         cell_type = merge(cell_quad4, cell_quad9, study%order == 1)
      else
         cell_type = merge(cell_hex8, cell_hex27, study%order == 1)
      end if
      n_contacts = 0
      if (allocated(result%contacts)) n_contacts = size(result%contacts)
      fields%level = result%level
      allocate (fields%grids(size(result%bodies) + n_contacts))
      do b = 1, size(result%bodies)
         call body_fields(study%bodies(b)%name, study%bodies(b)%units, study%bodies(b)%geometry, cell_type, &
            & study%dim, result%bodies(b), result%done, fields%grids(b), error)
         if (allocated(error)) return
      end do
      do b = 1, n_contacts
         call contact_fields(contact_grid_name(b, study), result%contacts(b), fields%grids(size(result%bodies) + b), &
            & error)
         if (allocated(error)) return
      end do
   end subroutine level_fields

   !> `contact_<k>`, with '_' put in front while a body has that name.
   function contact_grid_name(k, study) result(name)
      integer, intent(in) :: k
      type(study_type), intent(in) :: study
      character(len=:), allocatable :: name
      integer :: b
      name = 'contact_'//itoa(k)
      b = 1
      do while (b <= size(study%bodies))
         if (study%bodies(b)%name == name) then
            name = '_'//name
            b = 1
         else
            b = b + 1
         end if
      end do
   end function contact_grid_name

   !> The slave points of one pair as a point set named `name`.
   subroutine contact_fields(name, c, grid, error)
      character(len=*), intent(in) :: name
      type(contact_result_type), intent(in) :: c
      type(grid_fields_type), intent(out) :: grid
      type(error_type), allocatable, intent(out) :: error
      integer :: i, stat

      grid%name = name
      grid%is_contact = .true.
      grid%cell_type = cell_vertex
      allocate (grid%fields(10), grid%cells(1, c%npoint), grid%nodes(c%dim, c%npoint), stat=stat)
      call check_allocation(stat, who, 'the slave points of a contact pair', c%npoint, 4 + 8*c%dim, error)
      if (allocated(error)) return
      if (c%npoint == 0) return
      grid%nodes(:, :) = c%x(:, :c%npoint)
      do i = 1, c%npoint
         grid%cells(1, i) = i
      end do
      if (.not. allocated(error)) call scalar('p_fe', c%p_fe, 'stress')
      if (.not. allocated(error)) call scalar('p_spr', c%p_spr, 'stress')
      if (.not. allocated(error)) call scalar('p_sprc', c%p_sprc, 'stress')
      if (.not. allocated(error)) call scalar('p_exact', c%p_exact, 'stress')
      if (.not. allocated(error)) call scalar('p_fe_stress', c%p_fe_stress, 'stress')
      if (.not. allocated(error)) call scalar('gap', c%gap, 'length')
      if (.not. allocated(error)) call scalar('ts_fe', c%ts_fe, 'stress')
      if (.not. allocated(error)) call scalar('ts_sprc', c%ts_sprc, 'stress')
      if (.not. allocated(error)) call scalar('weight', c%weight, merge('length', 'area  ', c%dim == 2))
      if (.not. allocated(error)) call add_real(grid, 'normal', center_node, 1.0_wp, c%normal, '', error)
      if (allocated(error)) return
      ! 0 open, 1 stick, 2 slip (sprc_contact_result)
      call add_int(grid, 'state', center_node, reshape(c%state, [1, c%npoint]), error)
   contains
      subroutine scalar(field, values, units)
         character(len=*), intent(in) :: field, units
         real(wp), intent(in) :: values(:)
         call add_real(grid, field, center_node, 1.0_wp, reshape(values, [1, size(values)]), trim(units), error)
      end subroutine scalar
   end subroutine contact_fields

   !> One body's mesh and fields, in the scene's units (the analysis ran in `units`).
   subroutine body_fields(name, units, geometry, cell_type, dim, bl, done, grid, error)
      character(len=*), intent(in) :: name
      type(analysis_units_type), intent(in) :: units
      type(body_type), intent(in) :: geometry
      integer, intent(in) :: cell_type, dim
      type(body_level_type), intent(in) :: bl
      logical, intent(in) :: done(2)
      type(grid_fields_type), intent(out) :: grid
      type(error_type), allocatable, intent(out) :: error
      character(len=4), parameter :: method_name(2) = ['spr ', 'sprc']
      character(len=:), allocatable :: energy
      real(wp), allocatable :: sigma_fe(:, :)
      real(wp) :: sunit, eunit
      integer :: m, n_cells, stat

      associate (mesh => bl%problem%mesh)
         n_cells = mesh%grid%n_leaves
         grid%name = name
         grid%cell_type = cell_type
         allocate (grid%fields(12), stat=stat)
         if (stat == 0) allocate (grid%nodes, source=mesh%nodes%x, stat=stat)
         if (stat == 0) allocate (grid%cells, source=mesh%nodes%connectivity, stat=stat)
         call check_allocation(stat, who, 'the mesh of body "'//name//'"', size(mesh%nodes%x, kind=i8), 8*dim + 4, &
            & error)
         if (allocated(error)) return
         ! stress unit modulus*strain; energy norm sqrt(sigma D^-1 sigma): sqrt(modulus)*strain
         sunit = units%modulus*units%strain
         eunit = sqrt(units%modulus)*units%strain
         energy = 'energy norm, sqrt(stress*length^'//itoa(dim)//')'
         call add_real(grid, 'displacement', center_node, units%strain, bl%problem%u, 'length', error)
         if (allocated(error)) return
         call nodal_fe_stress(bl%problem, mesh%nodes, sigma_fe, error)
         if (allocated(error)) return
         call add_real(grid, 'sigma_fe', center_node, sunit, sigma_fe, 'stress', error, voigt=.true.)
         if (allocated(error)) return
         deallocate (sigma_fe)
         do m = 1, 2
            if (.not. done(m)) cycle
            call add_real(grid, 'sigma_'//trim(method_name(m)), center_node, sunit, bl%field(m)%nodal, 'stress', &
               & error, voigt=.true.)
            if (allocated(error)) return
            call add_real(grid, 'zz_error_'//trim(method_name(m)), center_cell, eunit, &
               & reshape(bl%est(m)%elem_err2, [1, size(bl%est(m)%elem_err2)]), energy, error, root=.true.)
            if (allocated(error)) return
         end do
         if (allocated(bl%element_error)) then
            call add_real(grid, 'exact_error_fe', center_cell, eunit, &
               & reshape(bl%element_error, [1, size(bl%element_error)]), energy, error)
            if (allocated(error)) return
         end if
         call add_int(grid, 'cut', center_cell, &
            & reshape(merge(1, 0, mesh%grid%leaf_class(1:n_cells) == cell_cut), [1, n_cells]), error)
         if (allocated(error)) return
         call add_real(grid, 'volume_fraction', center_cell, 1.0_wp, reshape(mesh%fraction(1:n_cells), [1, n_cells]), &
            & '', error)
         if (allocated(error)) return
         call add_int(grid, 'cell_level', center_cell, reshape(mesh%grid%leaf_level(1:n_cells), [1, n_cells]), error)
         if (allocated(error)) return
         call add_int(grid, 'inside', center_node, inside_mask(geometry, mesh%nodes%x), error)
      end associate
   end subroutine body_fields

   !> 1 for a node in the body or on its boundary, 0 beyond (`inside` above),
   !> as one integer row: the class of the node as a box of no extent.
   function inside_mask(geometry, x) result(mask)
      type(body_type), intent(in) :: geometry
      real(wp), intent(in) :: x(:, :)
      integer :: mask(1, size(x, 2))
      integer :: n
      do n = 1, size(x, 2)
         mask(1, n) = merge(0, 1, geometry%classify_box(x(:, n), x(:, n)) == cell_outside)
      end do
   end function inside_mask

   !> Append the real field unit*values (or unit*sqrt(values) with `root`);
   !> `voigt` names the components of a stress.
   subroutine add_real(grid, name, center, unit, values, units, error, voigt, root)
      type(grid_fields_type), intent(inout) :: grid
      character(len=*), intent(in) :: name, units
      integer, intent(in) :: center
      real(wp), intent(in) :: unit, values(:, :)
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: voigt, root
      character(len=2), parameter :: c2(3) = ['xx', 'yy', 'xy'], c3(6) = ['xx', 'yy', 'zz', 'xy', 'yz', 'xz']
      integer :: stat

      call next_field(grid, name, center, units)
      associate (fa => grid%fields(grid%n_fields))
         allocate (fa%reals(size(values, 1), size(values, 2)), stat=stat)
         call check_allocation(stat, who, 'field "'//name//'" of "'//grid%name//'"', size(values, kind=i8), 8, error)
         if (allocated(error)) return
         fa%reals(:, :) = unit*values
         if (present(root)) then
            if (root) fa%reals(:, :) = unit*sqrt(values)
         end if
         if (present(voigt)) then
            if (voigt .and. size(values, 1) == 3) fa%components = c2
            if (voigt .and. size(values, 1) == 6) fa%components = c3
         end if
      end associate
   end subroutine add_real

   !> Append an integer field.
   subroutine add_int(grid, name, center, values, error)
      type(grid_fields_type), intent(inout) :: grid
      character(len=*), intent(in) :: name
      integer, intent(in) :: center
      integer, intent(in) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      call next_field(grid, name, center, '')
      allocate (grid%fields(grid%n_fields)%ints, source=values, stat=stat)
      call check_allocation(stat, who, 'field "'//name//'" of "'//grid%name//'"', size(values, kind=i8), 4, error)
   end subroutine add_int

   subroutine next_field(grid, name, center, units)
      type(grid_fields_type), intent(inout) :: grid
      character(len=*), intent(in) :: name, units
      integer, intent(in) :: center
      type(field_array_type), allocatable :: more(:)

      if (grid%n_fields == size(grid%fields)) then
         allocate (more(2*size(grid%fields)))
         more(:grid%n_fields) = grid%fields
         call move_alloc(more, grid%fields)
      end if
      grid%n_fields = grid%n_fields + 1
      grid%fields(grid%n_fields)%name = name
      grid%fields(grid%n_fields)%center = center
      grid%fields(grid%n_fields)%units = units
   end subroutine next_field

end module sprc_io_fields
