!> The light-data side of the field output: the HDF5 file layout, the cell
!> types, and the XDMF text that lets ParaView open the HDF5 file.
!>
!> **Layout** of PREFIX.h5 (dimensions in C order, as h5dump shows them):
!> ```
!> /level_LL/<body>/mesh/x             float64 (n_nodes, dim)          dim = 2 or 3
!> /level_LL/<body>/mesh/connectivity  int32   (n_cells, nodes_per_cell)  0-based, VTK order
!> /level_LL/<body>/node/<name>        float64 (n_nodes) | (n_nodes, ncomp)
!> /level_LL/<body>/cell/<name>        float64 or int32 (n_cells) | (n_cells, ncomp)
!> /level_LL/contact_<k>/mesh/x        float64 (n_points, dim)   slave points of &contact pair k
!> /level_LL/contact_<k>/node/<name>   float64 or int32 (n_points) | (n_points, 3)
!> ```
!> LL is the level with two digits; a writer with no body name gets `/level_LL/mesh/x`.
!> The fields are `sprc_io_fields`'s. Every field dataset carries the string attributes
!> `units` (the scene's own, in words) and, with several columns, `components`. A vector
!> has 3 components (a 2-D one gets z = 0): ParaView treats only those as vectors. A
!> contact pair's slave points are a grid of Polyvertex cells beside the bodies' grids.
!>
!> **Only the body.** A cut cell's nodes reach beyond the boundary, where the fields are
!> extrapolations: the node field `inside` is 1 in the body or on its boundary, 0 beyond
!> (ParaView: Threshold `inside` 1..1 with "All Scalars"); `volume_fraction` is each
!> cell's share in the body.
!>
!> **XDMF** (3.0, also read by ParaView's legacy reader): one temporal collection whose
!> Time is the level; per level one Uniform grid, or a Spatial collection of one grid per
!> body. Topologies Quadrilateral(_9), Hexahedron(_27); attributes Scalar, Vector, and for
!> named components one Scalar per component (`<name>_<component>`, an XDMF HyperSlab):
!> ParaView loads Tensor6 as an unnamed array, and 2-D Voigt stresses have no XDMF tensor.
!> (Checked with VTK's vtkXdmfReader for one unnamed grid per level; the per-body Spatial
!> collection was not opened in a reader.)
!>
!> **Node order** is VTK's, which both ParaView XDMF readers copy without reordering, and
!> `sprc_grid_nodes`'s. quad4: corners counter-clockwise from (0,0). quad9: corners,
!> midpoints of edges 0-1, 1-2, 2-3, 3-0, centre. hex8: bottom face z=0 as quad4, then top.
!> hex27: 8 corners; midpoints of the bottom edges (01 12 23 30), top edges (45 56 67 74),
!> vertical edges (04 15 26 37); face centres x=0, x=1, y=0, y=1, z=0, z=1; body centre.
!> (Gmsh and others order the 27-node face centres differently; XDMF does not fix it.)
module sprc_io_xdmf
   use sprc_core_error, only: error_type, fatal_error, stat_io, stat_invalid_input
   use sprc_core_text, only: itoa, xml_escape
   implicit none
   private

   public :: cell_quad4, cell_quad9, cell_hex8, cell_hex27, cell_vertex, cell_nodes, cell_dim, topology_name
   public :: center_node, center_cell, field_scalar, field_vector, field_components
   public :: xdmf_field_type, xdmf_grid_type, xdmf_text, write_xdmf
   public :: level_group, grid_group, mesh_x_path, mesh_connectivity_path, field_path, n_attributes, attribute_name, &
      & valid_name
   public :: max_name_length

   !> Cell types; `cell_vertex` is one point (a point set: XDMF Polyvertex).
   integer, parameter :: cell_quad4 = 1, cell_quad9 = 2, cell_hex8 = 3, cell_hex27 = 4, cell_vertex = 5
   !> Where a field lives.
   integer, parameter :: center_node = 1, center_cell = 2
   !> How a field is shown: one scalar, a 3-vector, or one scalar per named component.
   integer, parameter :: field_scalar = 1, field_vector = 2, field_components = 3
   !> Longest field or component name.
   integer, parameter :: max_name_length = 64

   character(len=*), parameter :: nl = new_line('a')

   !> One field of a level as stored in the HDF5 file.
   type :: xdmf_field_type
      character(len=:), allocatable :: name
      integer :: center = center_node
      integer :: kind = field_scalar
      !> Columns of the dataset (1: a 1-D dataset).
      integer :: ncomp = 1
      logical :: is_integer = .false.
      !> Component names, for kind = field_components.
      character(len=max_name_length), allocatable :: components(:)
      !> The values' units in words ('' or not allocated: none given).
      character(len=:), allocatable :: units
   end type xdmf_field_type

   !> One level's mesh and fields as stored in the HDF5 file; with several
   !> bodies, one per body and level.
   type :: xdmf_grid_type
      integer :: level = 0
      !> Name of the body ('' or not allocated: the level has one unnamed grid).
      character(len=:), allocatable :: body
      !> Coordinates per node (2 or 3).
      integer :: ncoord = 0
      integer :: n_nodes = 0, n_cells = 0
      integer :: cell_type = 0
      integer :: n_fields = 0
      type(xdmf_field_type), allocatable :: fields(:)
   end type xdmf_grid_type

contains

   !> Nodes per cell of a cell type (0 for an unknown type).
   pure integer function cell_nodes(cell_type)
      integer, intent(in) :: cell_type
      select case (cell_type)
      case (cell_quad4); cell_nodes = 4
      case (cell_quad9); cell_nodes = 9
      case (cell_hex8); cell_nodes = 8
      case (cell_hex27); cell_nodes = 27
      case (cell_vertex); cell_nodes = 1
      case default; cell_nodes = 0
      end select
   end function cell_nodes

   !> Topological dimension of a cell type (0 for an unknown type).
   pure integer function cell_dim(cell_type)
      integer, intent(in) :: cell_type
      select case (cell_type)
      case (cell_quad4, cell_quad9); cell_dim = 2
      case (cell_hex8, cell_hex27); cell_dim = 3
      case default; cell_dim = 0 ! a vertex, or unknown
      end select
   end function cell_dim

   !> XDMF TopologyType of a cell type.
   pure function topology_name(cell_type) result(name)
      integer, intent(in) :: cell_type
      character(len=:), allocatable :: name
      select case (cell_type)
      case (cell_quad4); name = 'Quadrilateral'
      case (cell_quad9); name = 'Quadrilateral_9'
      case (cell_hex8); name = 'Hexahedron'
      case (cell_hex27); name = 'Hexahedron_27'
      case (cell_vertex); name = 'Polyvertex'
      case default; name = 'unknown'
      end select
   end function topology_name

   !> HDF5 group of a level: `/level_04`.
   pure function level_group(level) result(path)
      integer, intent(in) :: level
      character(len=:), allocatable :: path
      path = '/level_'//itoa(level, 2)
   end function level_group

   !> HDF5 group of a grid: `/level_04`, or `/level_04/<body>` for a body's grid.
   pure function grid_group(grid) result(path)
      type(xdmf_grid_type), intent(in) :: grid
      character(len=:), allocatable :: path
      path = level_group(grid%level)
      if (allocated(grid%body)) then
         if (len(grid%body) > 0) path = path//'/'//grid%body
      end if
   end function grid_group

   pure function mesh_x_path(grid) result(path)
      type(xdmf_grid_type), intent(in) :: grid
      character(len=:), allocatable :: path
      path = grid_group(grid)//'/mesh/x'
   end function mesh_x_path

   pure function mesh_connectivity_path(grid) result(path)
      type(xdmf_grid_type), intent(in) :: grid
      character(len=:), allocatable :: path
      path = grid_group(grid)//'/mesh/connectivity'
   end function mesh_connectivity_path

   !> Dataset of a field: `<grid group>/node/<name>` or `<grid group>/cell/<name>`.
   pure function field_path(grid, center, name) result(path)
      type(xdmf_grid_type), intent(in) :: grid
      integer, intent(in) :: center
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: path
      if (center == center_node) then
         path = grid_group(grid)//'/node/'//name
      else
         path = grid_group(grid)//'/cell/'//name
      end if
   end function field_path

   !> True for a name usable as HDF5 link and XML attribute value alike:
   !> a letter or '_' first, then letters, digits, '_', '-', '.'; at most
   !> `max_name_length` characters.
   pure logical function valid_name(name)
      character(len=*), intent(in) :: name
      character(len=*), parameter :: first = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ_'
      valid_name = .false.
      if (len(name) < 1 .or. len(name) > max_name_length) return
      if (index(first, name(1:1)) == 0) return
      valid_name = verify(name, first//'0123456789-.') == 0
   end function valid_name

   !> Number of ParaView arrays a field produces (1, or one per component).
   pure integer function n_attributes(field)
      type(xdmf_field_type), intent(in) :: field
      n_attributes = 1
      if (field%kind == field_components) n_attributes = size(field%components)
   end function n_attributes

   !> Name of the j-th ParaView array of a field: the field's name, or
   !> `<name>_<component>` for named components.
   pure function attribute_name(field, j) result(name)
      type(xdmf_field_type), intent(in) :: field
      integer, intent(in) :: j
      character(len=:), allocatable :: name
      name = field%name
      if (field%kind == field_components) name = field%name//'_'//trim(field%components(j))
   end function attribute_name

   !> Write the XDMF file `path` describing `grids` stored in the HDF5 file
   !> `h5_path`. Both files must be in the same directory: the XDMF refers to
   !> the HDF5 file by its base name, so the pair can be moved together.
   subroutine write_xdmf(path, h5_path, grids, error)
      character(len=*), intent(in) :: path, h5_path
      type(xdmf_grid_type), intent(in) :: grids(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat
      character(len=256) :: msg

      if (dirname(path) /= dirname(h5_path)) then
         call fatal_error(error, 'XDMF: "'//path//'" and "'//h5_path//'" must be in the same directory', &
            stat_invalid_input)
         return
      end if
      open (newunit=unit, file=path, status='replace', action='write', access='stream', form='unformatted', &
         iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, 'XDMF: cannot open "'//path//'" for writing: '//trim(msg), stat_io)
         return
      end if
      write (unit, iostat=stat, iomsg=msg) xdmf_text(basename(h5_path), grids)
      if (stat /= 0) then
         close (unit)
         call fatal_error(error, 'XDMF: cannot write "'//path//'": '//trim(msg), stat_io)
         return
      end if
      close (unit, iostat=stat, iomsg=msg)
      if (stat /= 0) call fatal_error(error, 'XDMF: cannot close "'//path//'": '//trim(msg), stat_io)
   end subroutine write_xdmf

   !> The XDMF text for `grids` stored in the HDF5 file named `h5_name`.
   function xdmf_text(h5_name, grids) result(text)
      character(len=*), intent(in) :: h5_name
      type(xdmf_grid_type), intent(in) :: grids(:)
      character(len=:), allocatable :: text
      integer :: g, k, level
      logical :: done(size(grids))

      text = '<?xml version="1.0" encoding="UTF-8"?>'//nl//'<!DOCTYPE Xdmf SYSTEM "Xdmf.dtd" []>'//nl// &
         '<Xdmf xmlns:xi="http://www.w3.org/2001/XInclude" Version="3.0">'//nl// &
         ' <Domain>'//nl// &
         '  <Grid Name="levels" GridType="Collection" CollectionType="Temporal">'//nl
      ! Levels in increasing (= time) order, whatever order they were written in;
      ! the bodies of a level in the order written.
      done = .false.
      do k = 1, size(grids)
         if (all(done)) exit
         g = minloc(grids%level, dim=1, mask=.not. done)
         level = grids(g)%level
         if (count(grids%level == level) == 1 .and. .not. named(grids(g))) then
            text = text//grid_text(xml_escape(h5_name), grids(g), .true.)
         else
            text = text//'   <Grid Name="level_'//itoa(level, 2)//'" GridType="Collection" '// &
               'CollectionType="Spatial">'//nl//'    <Time Value="'//itoa(level)//'"/>'//nl
            do g = 1, size(grids)
               if (grids(g)%level == level) text = text//grid_text(xml_escape(h5_name), grids(g), .false.)
            end do
            text = text//'   </Grid>'//nl
         end if
         where (grids%level == level) done = .true.
      end do
      text = text//'  </Grid>'//nl//' </Domain>'//nl//'</Xdmf>'//nl
   end function xdmf_text

   pure logical function named(grid)
      type(xdmf_grid_type), intent(in) :: grid
      named = .false.
      if (allocated(grid%body)) named = len(grid%body) > 0
   end function named

   !> A Uniform grid; `with_time`: it is a level of its own (Time = level),
   !> otherwise one body's grid inside the level's spatial collection.
   function grid_text(h5, grid, with_time) result(text)
      character(len=*), intent(in) :: h5
      type(xdmf_grid_type), intent(in) :: grid
      logical, intent(in) :: with_time
      character(len=:), allocatable :: text, geometry, name
      integer :: f

      geometry = 'XYZ'
      if (grid%ncoord == 2) geometry = 'XY'
      if (named(grid)) then
         name = grid%body
      else
         name = 'level_'//itoa(grid%level, 2)
      end if
      text = '   <Grid Name="'//name//'" GridType="Uniform">'//nl
      if (with_time) text = text//'    <Time Value="'//itoa(grid%level)//'"/>'//nl
      text = text// &
         '    <Topology TopologyType="'//topology_name(grid%cell_type)//'" NumberOfElements="'// &
         itoa(grid%n_cells)//'"'//nodes_per_element(grid%cell_type)//'>'//nl// &
         '     '//data_item(h5, mesh_connectivity_path(grid), [grid%n_cells, cell_nodes(grid%cell_type)], &
         .true.)//nl// &
         '    </Topology>'//nl// &
         '    <Geometry GeometryType="'//geometry//'">'//nl// &
         '     '//data_item(h5, mesh_x_path(grid), [grid%n_nodes, grid%ncoord], .false.)//nl// &
         '    </Geometry>'//nl
      do f = 1, grid%n_fields
         text = text//attribute_text(h5, grid, grid%fields(f))
      end do
      text = text//'   </Grid>'//nl
   end function grid_text

   !> The Attribute element(s) of one field.
   function attribute_text(h5, grid, field) result(text)
      character(len=*), intent(in) :: h5
      type(xdmf_grid_type), intent(in) :: grid
      type(xdmf_field_type), intent(in) :: field
      character(len=:), allocatable :: text, center, item, path
      integer :: n, j

      n = merge(grid%n_nodes, grid%n_cells, field%center == center_node)
      center = merge('Node', 'Cell', field%center == center_node)
      path = field_path(grid, field%center, field%name)
      text = ''
      select case (field%kind)
      case (field_scalar)
         text = attribute_open(attribute_name(field, 1), 'Scalar', center)//information(field)// &
            '     '//data_item(h5, path, [n], field%is_integer)//nl//'    </Attribute>'//nl
      case (field_vector)
         text = attribute_open(attribute_name(field, 1), 'Vector', center)//information(field)// &
            '     '//data_item(h5, path, [n, field%ncomp], field%is_integer)//nl//'    </Attribute>'//nl
      case default
         item = data_item(h5, path, [n, field%ncomp], field%is_integer)
         do j = 1, field%ncomp
            ! HyperSlab parameters: start, stride, count, each in (row, column).
            text = text//attribute_open(attribute_name(field, j), 'Scalar', center)//information(field)// &
               '     <DataItem ItemType="HyperSlab" Dimensions="'//itoa(n)//' 1" Type="HyperSlab">'//nl// &
               '      <DataItem Dimensions="3 2" NumberType="Int" Format="XML">0 '//itoa(j - 1)//' 1 1 '// &
               itoa(n)//' 1</DataItem>'//nl// &
               '      '//item//nl//'     </DataItem>'//nl//'    </Attribute>'//nl
         end do
      end select
   end function attribute_text

   !> `<Information Name="units" Value="..."/>` of a field with units ('' without).
   function information(field) result(text)
      type(xdmf_field_type), intent(in) :: field
      character(len=:), allocatable :: text
      text = ''
      if (.not. allocated(field%units)) return
      if (len(field%units) > 0) text = '     <Information Name="units" Value="'//xml_escape(field%units)//'"/>'//nl
   end function information

   !> XDMF needs the nodes per element of a Polyvertex topology (the other types fix it).
   pure function nodes_per_element(cell_type) result(text)
      integer, intent(in) :: cell_type
      character(len=:), allocatable :: text
      text = ''
      if (cell_type == cell_vertex) text = ' NodesPerElement="1"'
   end function nodes_per_element

   function attribute_open(name, type, center) result(text)
      character(len=*), intent(in) :: name, type, center
      character(len=:), allocatable :: text
      text = '    <Attribute Name="'//name//'" AttributeType="'//type//'" Center="'//center//'">'//nl
   end function attribute_open

   !> A DataItem referring to dataset `path` of the HDF5 file `h5`.
   function data_item(h5, path, dims, is_integer) result(text)
      character(len=*), intent(in) :: h5, path
      integer, intent(in) :: dims(:)
      logical, intent(in) :: is_integer
      character(len=:), allocatable :: text, d
      integer :: k

      d = itoa(dims(1))
      do k = 2, size(dims)
         d = d//' '//itoa(dims(k))
      end do
      if (is_integer) then
         text = '<DataItem Dimensions="'//d//'" NumberType="Int" Precision="4" Format="HDF">'
      else
         text = '<DataItem Dimensions="'//d//'" NumberType="Float" Precision="8" Format="HDF">'
      end if
      text = text//h5//':'//path//'</DataItem>'
   end function data_item

   !> Directory part of a path ('' when there is none).
   pure function dirname(path) result(dir)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: dir
      dir = path(:index(path, '/', back=.true.))
   end function dirname

   pure function basename(path) result(base)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: base
      base = path(index(path, '/', back=.true.) + 1:)
   end function basename

end module sprc_io_xdmf
