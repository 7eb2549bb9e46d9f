!> HDF5 output of meshes and fields, one group per level, for ParaView via
!> the XDMF file that `write_xdmf` produces next to it. The dataset layout,
!> cell types and node order are documented in `sprc_io_xdmf`.
!>
!> ```fortran
!> type(h5_output_type) :: out
!> call out%create('run.h5', error)
!> call out%write_level(4, x, connectivity, cell_quad9, error)
!> call out%write_node_field(4, 'displacement', u, error)                    ! 2 or 3 comps: vector
!> call out%write_node_field(4, 'sigma_spr', s, error, components=['xx', 'yy', 'xy'])
!> call out%write_cell_field(4, 'eta_spr', eta, error)                       ! (1, n_cells)
!> call out%write_cell_field(4, 'cut', cut_flag, error)                      ! integer (1, n_cells)
!> call out%close(error)
!> call out%write_xdmf('run.xdmf', error)
!> ```
!> Every HDF5 id this module opens is closed before the call returns, except
!> the file, which `close` closes. `create` initialises HDF5's Fortran
!> interface (`h5open_f`) only if it is not initialised yet, and nothing here
!> calls `h5close_f`: that would invalidate every other HDF5 id in the
!> process, a host code's included, so it is left to the program, at its
!> very end if it wants to. HDF5's automatic error
!> printing is switched off during each call and restored afterwards: the
!> library does not print; failures come back as `stat_io` errors.
module sprc_io_hdf5
   use, intrinsic :: iso_c_binding, only: c_ptr, c_funptr, c_int, c_int64_t, c_loc, c_null_ptr, c_null_funptr
   use hdf5, only: hid_t, hsize_t, h5open_f, h5iis_valid_f, h5fcreate_f, h5fclose_f, h5gcreate_f, h5gclose_f, &
      & h5screate_simple_f, h5screate_f, h5sclose_f, h5dcreate_f, h5dwrite_f, h5dclose_f, &
      & h5tcopy_f, h5tset_size_f, h5tclose_f, h5acreate_f, h5awrite_f, h5aclose_f, size_t, &
      & H5F_ACC_TRUNC_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, H5T_NATIVE_CHARACTER, H5S_SCALAR_F
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_io, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_io_xdmf, only: xdmf_grid_type, xdmf_field_type, write_xdmf_file => write_xdmf, &
      & cell_nodes, cell_dim, topology_name, center_node, center_cell, field_scalar, field_vector, &
      & field_components, level_group, grid_group, mesh_x_path, mesh_connectivity_path, field_path, n_attributes, &
      & attribute_name, valid_name, max_name_length
   implicit none
   private

   public :: h5_output_type

   !> An HDF5 output file being written, and a record of what it holds (for the XDMF file).
   type :: h5_output_type
      private
      integer(hid_t) :: file = -1
      logical :: is_open = .false.
      character(len=:), allocatable :: path
      integer :: n_grids = 0
      type(xdmf_grid_type), allocatable :: grids(:)
   contains
      !> Create (or truncate) the HDF5 file.
      procedure :: create => h5_create
      !> Write one level's mesh.
      procedure :: write_level => h5_write_level
      procedure, private :: write_node_field_real => h5_write_node_field
      procedure, private :: write_node_field_int => h5_write_node_field_int
      !> Write a node field (real or integer) of a level.
      generic :: write_node_field => write_node_field_real, write_node_field_int
      procedure, private :: write_cell_field_real => h5_write_cell_field_real
      procedure, private :: write_cell_field_int => h5_write_cell_field_int
      !> Write a cell field (real or integer) of a level.
      generic :: write_cell_field => write_cell_field_real, write_cell_field_int
      !> Close the file (a no-op when none is open).
      procedure :: close => h5_close
      !> Write the XDMF file describing what was written.
      procedure :: write_xdmf => h5_write_xdmf
      !> True while a file is open.
      procedure :: opened => h5_opened
   end type h5_output_type

   !> The automatic error handler of the default HDF5 error stack, saved while sprc runs quietly.
   type :: h5_quiet_type
      type(c_funptr) :: func
      type(c_ptr) :: client_data
      logical :: saved = .false.
   end type h5_quiet_type

   ! hid_t is int64_t since HDF5 1.10 (H5Ipublic.h); c_int64_t keeps the interfaces interoperable.
   interface
      integer(c_int) function h5eget_auto2(estack_id, func, client_data) bind(C, name='H5Eget_auto2')
         import :: c_int64_t, c_int, c_funptr, c_ptr
         integer(c_int64_t), value :: estack_id
         type(c_funptr), intent(out) :: func
         type(c_ptr), intent(out) :: client_data
      end function h5eget_auto2
      integer(c_int) function h5eset_auto2(estack_id, func, client_data) bind(C, name='H5Eset_auto2')
         import :: c_int64_t, c_int, c_funptr, c_ptr
         integer(c_int64_t), value :: estack_id
         type(c_funptr), value :: func
         type(c_ptr), value :: client_data
      end function h5eset_auto2
   end interface

   !> H5E_DEFAULT of H5Epublic.h: the default error stack.
   integer(c_int64_t), parameter :: h5e_default = 0

contains

   !> Create the HDF5 file `path`, replacing an existing one.
   subroutine h5_create(self, path, error)
      class(h5_output_type), intent(inout) :: self
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      type(h5_quiet_type) :: quiet
      integer :: hdferr

      if (self%is_open) then
         call fatal_error(error, 'HDF5 output: create "'//path//'": "'//self%path//'" is still open', &
            stat_invalid_input)
         return
      end if
      call initialise_hdf5(error)
      if (allocated(error)) return
      call quiet_begin(quiet)
      call h5fcreate_f(path, H5F_ACC_TRUNC_F, self%file, hdferr)
      call quiet_end(quiet)
      call check_hdf5(hdferr, 'create "'//path//'"', error)
      if (allocated(error)) return
      self%is_open = .true.
      self%path = path
      self%n_grids = 0
      if (allocated(self%grids)) deallocate (self%grids)
      allocate (self%grids(4))
   end subroutine h5_create

   !> Write the mesh of one level: node coordinates `nodes_x(dim, n_nodes)`
   !> (dim 2 or 3) and `connectivity(nodes_per_cell, n_cells)` with 1-based
   !> node numbers in VTK local order (stored 0-based). `cell_type` is one of
   !> `cell_quad4`, `cell_quad9`, `cell_hex8`, `cell_hex27`, or `cell_vertex`
   !> for a point set (connectivity (1, n_points)) (`sprc_io_xdmf`).
   !> Each level (0..99) is written once; with `body` (a name as for fields),
   !> each body of each level once, under `/level_LL/<body>/`. A level holds
   !> either one unnamed grid or named ones.
   subroutine h5_write_level(self, level, nodes_x, connectivity, cell_type, error, body)
      class(h5_output_type), intent(inout) :: self
      integer, intent(in) :: level
      real(wp), intent(in), target, contiguous :: nodes_x(:, :)
      integer, intent(in) :: connectivity(:, :)
      integer, intent(in) :: cell_type
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: body
      integer, allocatable, target :: conn0(:, :)
      type(xdmf_grid_type) :: grid
      type(h5_quiet_type) :: quiet
      character(len=:), allocatable :: where
      logical :: new_level
      integer :: stat

      grid%level = level
      grid%body = ''
      if (present(body)) grid%body = body
      where = grid_where(self, grid)//': '
      call check_open(self, where, error)
      if (allocated(error)) return
      if (level < 0 .or. level > 99) then
         call fatal_error(error, where//'level must be in 0..99', stat_invalid_input)
         return
      end if
      if (len(grid%body) > 0 .and. .not. valid_name(grid%body)) then
         call fatal_error(error, where//'a body name is a letter or _, then letters, digits, _ - . (at most '// &
            itoa(max_name_length)//')', stat_invalid_input)
         return
      end if
      if (find_grid(self, level, grid%body) > 0) then
         call fatal_error(error, where//'already written', stat_invalid_input)
         return
      end if
      new_level = .true.
      if (self%n_grids > 0) new_level = .not. any(self%grids(:self%n_grids)%level == level)
      if (.not. new_level .and. (len(grid%body) == 0 .or. find_grid(self, level, '') > 0)) then
         call fatal_error(error, where//'a level holds one unnamed grid or named ones (bodies), not both', &
            stat_invalid_input)
         return
      end if
      if (cell_nodes(cell_type) == 0) then
         call fatal_error(error, where//'unknown cell type '//itoa(cell_type), stat_invalid_input)
         return
      end if
      if (size(nodes_x, 1) < max(2, cell_dim(cell_type)) .or. size(nodes_x, 1) > 3) then
         call fatal_error(error, where//topology_name(cell_type)//' cells need '// &
            trim(merge('2 or 3', '3     ', cell_dim(cell_type) <= 2))//' coordinates per node, got '// &
            itoa(size(nodes_x, 1)), stat_invalid_input)
         return
      end if
      if (size(connectivity, 1) /= cell_nodes(cell_type)) then
         call fatal_error(error, where//topology_name(cell_type)//' cells have '//itoa(cell_nodes(cell_type))// &
            ' nodes, connectivity has '//itoa(size(connectivity, 1)), stat_invalid_input)
         return
      end if
      if (size(nodes_x, 2) == 0 .or. size(connectivity, 2) == 0) then
         call fatal_error(error, where//'no nodes or no cells', stat_invalid_input)
         return
      end if
      if (any(connectivity < 1 .or. connectivity > size(nodes_x, 2))) then
         call fatal_error(error, where//'connectivity refers to nodes outside 1..'//itoa(size(nodes_x, 2)), &
            stat_invalid_input)
         return
      end if

      allocate (conn0, source=connectivity - 1, stat=stat)
      call check_allocation(stat, where//'write_level', 'the 0-based connectivity', size(connectivity, 2), &
         & 4*size(connectivity, 1), error)
      if (allocated(error)) return
      call quiet_begin(quiet)
      call write_level_data(self, grid, new_level, nodes_x, conn0, where, error)
      call quiet_end(quiet)
      if (allocated(error)) return

      grid%ncoord = size(nodes_x, 1)
      grid%n_nodes = size(nodes_x, 2)
      grid%n_cells = size(connectivity, 2)
      grid%cell_type = cell_type
      allocate (grid%fields(4))
      if (self%n_grids == size(self%grids)) self%grids = [self%grids, self%grids]
      self%n_grids = self%n_grids + 1
      self%grids(self%n_grids) = grid
   end subroutine h5_write_level

   subroutine write_level_data(self, grid, new_level, nodes_x, conn0, where, error)
      type(h5_output_type), intent(in) :: self
      type(xdmf_grid_type), intent(in) :: grid
      logical, intent(in) :: new_level
      real(wp), intent(in), target, contiguous :: nodes_x(:, :)
      integer, intent(in), target, contiguous :: conn0(:, :)
      character(len=*), intent(in) :: where
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: groups(4) = [character(len=5) :: '', '/mesh', '/node', '/cell']
      integer :: k

      if (new_level .and. len(grid%body) > 0) then
         call create_group(self%file, level_group(grid%level), where, error)
         if (allocated(error)) return
      end if
      do k = 1, size(groups)
         call create_group(self%file, grid_group(grid)//trim(groups(k)), where, error)
         if (allocated(error)) return
      end do
      call write_dataset(self%file, mesh_x_path(grid), shape(nodes_x, hsize_t), H5T_NATIVE_DOUBLE, &
         c_loc(nodes_x), where, error)
      if (allocated(error)) return
      call write_dataset(self%file, mesh_connectivity_path(grid), shape(conn0, hsize_t), H5T_NATIVE_INTEGER, &
         c_loc(conn0), where, error)
   end subroutine write_level_data

   !> Write a node field `values(ncomp, n_nodes)` of a written level. Without
   !> `components`, 1 component is a scalar and 2 or 3 a vector (stored with
   !> 3, z = 0 in 2D); with `components` (one name per row of `values`,
   !> e.g. ['xx', 'yy', 'xy'] for 2D Voigt stresses) ParaView shows one
   !> scalar `<name>_<component>` per row.
   subroutine h5_write_node_field(self, level, name, values, error, components, body, units)
      class(h5_output_type), intent(inout) :: self
      integer, intent(in) :: level
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: components(:)
      !> The body of the level's grid (as given to write_level).
      character(len=*), intent(in), optional :: body
      !> The values' units in words (an HDF5 attribute `units` and an XDMF Information; '' none).
      character(len=*), intent(in), optional :: units

      call write_field(self, center_node, level, name, size(values, 1), size(values, 2), error, components, body, &
         real_values=values, units=units)
   end subroutine h5_write_node_field

   !> Write an integer node field `values(ncomp, n_nodes)` (e.g. the state of
   !> a contact point), stored as int32; components as for real node fields.
   subroutine h5_write_node_field_int(self, level, name, values, error, components, body, units)
      class(h5_output_type), intent(inout) :: self
      integer, intent(in) :: level
      character(len=*), intent(in) :: name
      integer, intent(in) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: components(:)
      !> The body of the level's grid (as given to write_level).
      character(len=*), intent(in), optional :: body
      !> The values' units in words (an HDF5 attribute `units` and an XDMF Information; '' none).
      character(len=*), intent(in), optional :: units

      call write_field(self, center_node, level, name, size(values, 1), size(values, 2), error, components, body, &
         int_values=values, units=units)
   end subroutine h5_write_node_field_int

   !> Write a real cell field `values(ncomp, n_cells)` (e.g. element error
   !> indicators); components as for node fields.
   subroutine h5_write_cell_field_real(self, level, name, values, error, components, body, units)
      class(h5_output_type), intent(inout) :: self
      integer, intent(in) :: level
      character(len=*), intent(in) :: name
      real(wp), intent(in) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: components(:)
      !> The body of the level's grid (as given to write_level).
      character(len=*), intent(in), optional :: body
      !> The values' units in words (an HDF5 attribute `units` and an XDMF Information; '' none).
      character(len=*), intent(in), optional :: units

      call write_field(self, center_cell, level, name, size(values, 1), size(values, 2), error, components, body, &
         real_values=values, units=units)
   end subroutine h5_write_cell_field_real

   !> Write an integer cell field `values(ncomp, n_cells)` (e.g. the cell
   !> class: internal / cut), stored as int32.
   subroutine h5_write_cell_field_int(self, level, name, values, error, components, body, units)
      class(h5_output_type), intent(inout) :: self
      integer, intent(in) :: level
      character(len=*), intent(in) :: name
      integer, intent(in) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: components(:)
      !> The body of the level's grid (as given to write_level).
      character(len=*), intent(in), optional :: body
      !> The values' units in words (an HDF5 attribute `units` and an XDMF Information; '' none).
      character(len=*), intent(in), optional :: units

      call write_field(self, center_cell, level, name, size(values, 1), size(values, 2), error, components, body, &
         int_values=values, units=units)
   end subroutine h5_write_cell_field_int

   !> Check, store and record one field (real or integer values).
   subroutine write_field(self, center, level, name, ncomp, n, error, components, body, real_values, int_values, units)
      type(h5_output_type), intent(inout) :: self
      integer, intent(in) :: center, level, ncomp, n
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: components(:), body, units
      real(wp), intent(in), optional :: real_values(:, :)
      integer, intent(in), optional :: int_values(:, :)
      type(xdmf_field_type) :: field
      type(h5_quiet_type) :: quiet
      real(wp), allocatable, target :: rbuf(:, :)
      integer, allocatable, target :: ibuf(:, :)
      character(len=:), allocatable :: where
      integer :: g, expected, stored, j, stat
      integer(hsize_t), allocatable :: dims(:)

      where = 'HDF5 output "'//file_name(self)//'" level '//itoa(level)//' '// &
         merge('node', 'cell', center == center_node)//' field "'//name//'": '
      if (present(body)) where = 'HDF5 output "'//file_name(self)//'" level '//itoa(level)//' body "'//body// &
         '" '//merge('node', 'cell', center == center_node)//' field "'//name//'": '
      call check_open(self, where, error)
      if (allocated(error)) return
      if (present(body)) then
         g = find_grid(self, level, body)
      else
         g = find_grid(self, level, '')
      end if
      if (g == 0) then
         call fatal_error(error, where//'level not written yet (call write_level first)', stat_invalid_input)
         return
      end if
      if (.not. valid_name(name)) then
         call fatal_error(error, where//'a name is a letter or _, then letters, digits, _ - . (at most '// &
            itoa(max_name_length)//')', stat_invalid_input)
         return
      end if
      expected = merge(self%grids(g)%n_nodes, self%grids(g)%n_cells, center == center_node)
      if (n /= expected .or. ncomp < 1) then
         call fatal_error(error, where//'values have shape ('//itoa(ncomp)//', '//itoa(n)//'), expected (ncomp, '// &
            itoa(expected)//')', stat_invalid_input)
         return
      end if

      field%name = name
      field%center = center
      field%is_integer = present(int_values)
      stored = ncomp
      if (present(components)) then
         if (size(components) /= ncomp) then
            call fatal_error(error, where//itoa(size(components))//' component names for '//itoa(ncomp)// &
               ' components', stat_invalid_input)
            return
         end if
         do j = 1, ncomp
            if (.not. valid_name(trim(components(j)))) then
               call fatal_error(error, where//'bad component name "'//trim(components(j))//'"', stat_invalid_input)
               return
            end if
         end do
         field%kind = field_components
         field%components = components
      else if (ncomp == 1) then
         field%kind = field_scalar
      else if (ncomp <= 3) then
         field%kind = field_vector
         stored = 3
      else
         call fatal_error(error, where//itoa(ncomp)//' components: give their names (components=[...])', &
            stat_invalid_input)
         return
      end if
      field%ncomp = stored
      field%units = ''
      if (present(units)) field%units = units
      call check_names_free(self%grids(g), field, where, error)
      if (allocated(error)) return

      if (stored == 1) then
         allocate (dims(1))
         dims = int(n, hsize_t)
      else
         dims = int([stored, n], hsize_t)
      end if
      if (present(real_values)) then
         allocate (rbuf(stored, n), source=0.0_wp, stat=stat)
         call check_allocation(stat, where//'write', 'the values', n, 8*stored, error)
      else
         allocate (ibuf(stored, n), source=0, stat=stat)
         call check_allocation(stat, where//'write', 'the values', n, 4*stored, error)
      end if
      if (allocated(error)) return
      call quiet_begin(quiet)
      if (present(real_values)) then
         rbuf(:ncomp, :) = real_values
         call write_dataset(self%file, field_path(self%grids(g), center, name), dims, H5T_NATIVE_DOUBLE, c_loc(rbuf), &
            where, error, field_attributes(field, ncomp))
      else
         ibuf(:ncomp, :) = int_values
         call write_dataset(self%file, field_path(self%grids(g), center, name), dims, H5T_NATIVE_INTEGER, c_loc(ibuf), &
            where, error, field_attributes(field, ncomp))
      end if
      call quiet_end(quiet)
      if (allocated(error)) return

      associate (grid => self%grids(g))
         if (grid%n_fields == size(grid%fields)) grid%fields = [grid%fields, grid%fields]
         grid%n_fields = grid%n_fields + 1
         grid%fields(grid%n_fields) = field
      end associate
   end subroutine write_field

   !> The ParaView array names of `field` must not be taken by an earlier
   !> field of the same centre (nor repeat among themselves).
   subroutine check_names_free(grid, field, where, error)
      type(xdmf_grid_type), intent(in) :: grid
      type(xdmf_field_type), intent(in) :: field
      character(len=*), intent(in) :: where
      type(error_type), allocatable, intent(out) :: error
      integer :: f, i, j

      do j = 1, n_attributes(field)
         do i = 1, j - 1
            if (attribute_name(field, i) == attribute_name(field, j)) then
               call fatal_error(error, where//'component name repeated', stat_invalid_input)
               return
            end if
         end do
      end do
      do f = 1, grid%n_fields
         if (grid%fields(f)%center /= field%center) cycle
         do j = 1, n_attributes(field)
            do i = 1, n_attributes(grid%fields(f))
               if (attribute_name(grid%fields(f), i) == attribute_name(field, j) &
                  .or. grid%fields(f)%name == field%name) then
                  call fatal_error(error, where//'name already used by field "'//grid%fields(f)%name//'"', &
                     stat_invalid_input)
                  return
               end if
            end do
         end do
      end do
   end subroutine check_names_free

   !> Close the file. Closing a closed output does nothing.
   subroutine h5_close(self, error)
      class(h5_output_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      type(h5_quiet_type) :: quiet
      integer :: hdferr

      if (.not. self%is_open) return
      call quiet_begin(quiet)
      call h5fclose_f(self%file, hdferr)
      call quiet_end(quiet)
      self%is_open = .false.
      self%file = -1
      call check_hdf5(hdferr, 'close "'//self%path//'"', error)
   end subroutine h5_close

   !> Write the XDMF file `path` for everything written so far (usually after
   !> `close`). It must be in the HDF5 file's directory: it refers to the
   !> HDF5 file by base name (PREFIX.xdmf next to PREFIX.h5); `data_path` is the
   !> name the HDF5 file will have when it differs from the one it was created
   !> with (written under a temporary name, renamed when complete).
   subroutine h5_write_xdmf(self, path, error, data_path)
      class(h5_output_type), intent(in) :: self
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: data_path

      if (.not. allocated(self%path)) then
         call fatal_error(error, 'XDMF "'//path//'": no HDF5 file was created', stat_invalid_input)
         return
      end if
      if (present(data_path)) then
         call write_xdmf_file(path, data_path, self%grids(:self%n_grids), error)
      else
         call write_xdmf_file(path, self%path, self%grids(:self%n_grids), error)
      end if
   end subroutine h5_write_xdmf

   logical function h5_opened(self)
      class(h5_output_type), intent(in) :: self
      h5_opened = self%is_open
   end function h5_opened

   ! ------------------------------------------------------------------ helpers

   !> Initialise HDF5's Fortran interface unless it is: each `h5open_f`
   !> copies the predefined datatypes again (about 55 ids that are never
   !> freed), so it is called only while those ids are not valid: before the
   !> first initialisation, or after a host's `h5close_f`. No sprc state.
   subroutine initialise_hdf5(error)
      type(error_type), allocatable, intent(out) :: error
      logical :: valid
      integer :: hdferr

      call h5iis_valid_f(H5T_NATIVE_DOUBLE, valid, hdferr)
      if (hdferr >= 0 .and. valid) return
      call h5open_f(hdferr)
      call check_hdf5(hdferr, 'initialise the HDF5 library', error)
   end subroutine initialise_hdf5

   !> The one place where HDF5 status becomes an sprc error.
   subroutine check_hdf5(hdferr, what, error)
      integer, intent(in) :: hdferr
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(out) :: error
      if (hdferr < 0) call fatal_error(error, 'HDF5: cannot '//what, stat_io)
   end subroutine check_hdf5

   subroutine check_open(self, where, error)
      type(h5_output_type), intent(in) :: self
      character(len=*), intent(in) :: where
      type(error_type), allocatable, intent(out) :: error
      if (.not. self%is_open) call fatal_error(error, where//'no HDF5 file open (call create first)', &
         stat_invalid_input)
   end subroutine check_open

   !> Index of the grid of `level` and `body` ('' for the unnamed grid), 0 if not written.
   integer function find_grid(self, level, body) result(g)
      type(h5_output_type), intent(in) :: self
      integer, intent(in) :: level
      character(len=*), intent(in) :: body
      do g = 1, self%n_grids
         if (self%grids(g)%level == level .and. self%grids(g)%body == body) return
      end do
      g = 0
   end function find_grid

   !> `HDF5 output "FILE" level L` and ` body "NAME"` for a body's grid, for messages.
   function grid_where(self, grid) result(where)
      type(h5_output_type), intent(in) :: self
      type(xdmf_grid_type), intent(in) :: grid
      character(len=:), allocatable :: where
      where = 'HDF5 output "'//file_name(self)//'" level '//itoa(grid%level)
      if (len(grid%body) > 0) where = where//' body "'//grid%body//'"'
   end function grid_where

   function file_name(self) result(name)
      type(h5_output_type), intent(in) :: self
      character(len=:), allocatable :: name
      name = ''
      if (allocated(self%path)) name = self%path
   end function file_name

   subroutine create_group(file, path, where, error)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path, where
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: group
      integer :: hdferr, closeerr

      call h5gcreate_f(file, path, group, hdferr)
      if (hdferr >= 0) then
         call h5gclose_f(group, closeerr)
         hdferr = min(hdferr, closeerr)
      end if
      call check_hdf5(hdferr, 'create group '//path//' ('//where//')', error)
   end subroutine create_group

   !> The string attributes of a field's dataset, as (name, value) rows:
   !> `components` (the columns, e.g. 'xx yy xy' for Voigt stresses, 'x y z'
   !> for a vector, 'x y z (z = 0: a 2-D vector)' when padded), `units`.
   function field_attributes(field, ncomp) result(attrs)
      type(xdmf_field_type), intent(in) :: field
      integer, intent(in) :: ncomp
      character(len=max_name_length*8), allocatable :: attrs(:, :)
      character(len=:), allocatable :: columns
      integer :: j

      allocate (attrs(2, 0))
      columns = ''
      if (field%kind == field_components) then
         columns = trim(field%components(1))
         do j = 2, size(field%components)
            columns = columns//' '//trim(field%components(j))
         end do
         if (field%components(1) == 'xx') columns = columns//' (Voigt order)'
      else if (field%kind == field_vector) then
         columns = 'x y z'
         if (ncomp == 2) columns = 'x y z (z = 0: a 2-D vector)'
      end if
      if (len(columns) > 0) attrs = reshape([character(len=len(attrs)) :: 'components', columns], [2, 1])
      if (len(field%units) > 0) attrs = reshape([character(len=len(attrs)) :: attrs, 'units', field%units], &
         & [2, size(attrs, 2) + 1])
   end function field_attributes

   !> Create dataset `path` of Fortran shape `dims` and memory type `mem_type`
   !> from the buffer at `buf`, with the string attributes `attrs` (name,
   !> value); the file type is the native one. Every id opened here is
   !> closed here, also on failure.
   subroutine write_dataset(file, path, dims, mem_type, buf, where, error, attrs)
      integer(hid_t), intent(in) :: file, mem_type
      character(len=*), intent(in) :: path, where
      integer(hsize_t), intent(in) :: dims(:)
      type(c_ptr), intent(in) :: buf
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: attrs(:, :)
      integer(hid_t) :: space, dset
      integer :: hdferr, closeerr, k

      call h5screate_simple_f(size(dims), dims, space, hdferr)
      if (hdferr >= 0) then
         call h5dcreate_f(file, path, mem_type, space, dset, hdferr)
         if (hdferr >= 0) then
            call h5dwrite_f(dset, mem_type, buf, hdferr)
            if (present(attrs)) then
               do k = 1, size(attrs, 2)
                  if (hdferr >= 0) call write_string_attribute(dset, trim(attrs(1, k)), trim(attrs(2, k)), hdferr)
               end do
            end if
            call h5dclose_f(dset, closeerr)
            hdferr = min(hdferr, closeerr)
         end if
         call h5sclose_f(space, closeerr)
         hdferr = min(hdferr, closeerr)
      end if
      call check_hdf5(hdferr, 'write dataset '//path//' ('//where//')', error)
   end subroutine write_dataset

   !> A scalar fixed-length string attribute `name` = `value` (not empty) of the object `obj`.
   subroutine write_string_attribute(obj, name, value, hdferr)
      integer(hid_t), intent(in) :: obj
      character(len=*), intent(in) :: name, value
      integer, intent(out) :: hdferr
      integer(hid_t) :: space, stype, attr
      integer :: closeerr

      call h5screate_f(H5S_SCALAR_F, space, hdferr)
      if (hdferr < 0) return
      call h5tcopy_f(H5T_NATIVE_CHARACTER, stype, hdferr)
      if (hdferr >= 0) then
         call h5tset_size_f(stype, int(len(value), size_t), hdferr)
         if (hdferr >= 0) call h5acreate_f(obj, name, stype, space, attr, hdferr)
         if (hdferr >= 0) then
            call h5awrite_f(attr, stype, value, [1_hsize_t], hdferr)
            call h5aclose_f(attr, closeerr)
            hdferr = min(hdferr, closeerr)
         end if
         call h5tclose_f(stype, closeerr)
         hdferr = min(hdferr, closeerr)
      end if
      call h5sclose_f(space, closeerr)
      hdferr = min(hdferr, closeerr)
   end subroutine write_string_attribute

   !> Save HDF5's automatic error handler and switch it off.
   subroutine quiet_begin(quiet)
      type(h5_quiet_type), intent(out) :: quiet

      quiet%saved = h5eget_auto2(h5e_default, quiet%func, quiet%client_data) >= 0
      if (.not. quiet%saved) return
      quiet%saved = h5eset_auto2(h5e_default, c_null_funptr, c_null_ptr) >= 0
   end subroutine quiet_begin

   !> Restore the handler saved by `quiet_begin`.
   subroutine quiet_end(quiet)
      type(h5_quiet_type), intent(in) :: quiet
      integer(c_int) :: status
      if (quiet%saved) status = h5eset_auto2(h5e_default, quiet%func, quiet%client_data)
   end subroutine quiet_end


end module sprc_io_hdf5
