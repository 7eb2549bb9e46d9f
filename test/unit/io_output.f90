!> Tests of the HDF5 + XDMF field output: meshes and fields are read back with
!> the HDF5 API (shapes and bits), every HDF5 reference of the XDMF file must
!> resolve to a dataset of the stated dimensions, and every error path.
!> Files go to build/.
module sprc_test_output
   use, intrinsic :: iso_c_binding, only: c_loc, c_ptr
   use hdf5, only: hid_t, hsize_t, size_t, h5fopen_f, h5fclose_f, h5dopen_f, h5dclose_f, h5dread_f, &
      & h5dget_space_f, h5sget_simple_extent_ndims_f, h5sget_simple_extent_dims_f, h5sclose_f, &
      & h5fget_obj_count_f, h5eset_auto_f, H5F_ACC_RDONLY_F, H5F_OBJ_ALL_F, H5T_NATIVE_DOUBLE, H5T_NATIVE_INTEGER, &
      & h5aopen_f, h5aclose_f, h5aget_type_f, h5aread_f, h5tget_size_f, h5tclose_f
   use sprc_core_text, only: itoa
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_io, stat_invalid_input
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   use sprc_io_hdf5, only: h5_output_type
   use sprc_io_xdmf, only: cell_quad4, cell_quad9, cell_hex8, cell_hex27
   use sprc_test_report, only: xml_well_formed, read_text_file, python_xml_check
   implicit none
   private

   public :: collect_output

   character(len=*), parameter :: dir = 'build/'

   !> VTK_TRIQUADRATIC_HEXAHEDRON local node positions in units of half the
   !> cell edge, transcribed from VTK's documented diagram (vtkTriQuadraticHexahedron.h):
   !> corners, bottom / top / vertical edge midpoints, face centres x-, x+, y-, y+, z-, z+, centre.
   integer, parameter :: hex27_ref(3, 27) = reshape([ &
      & 0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0, 0, 0, 2, 2, 0, 2, 2, 2, 2, 0, 2, 2, &
      & 1, 0, 0, 2, 1, 0, 1, 2, 0, 0, 1, 0, 1, 0, 2, 2, 1, 2, 1, 2, 2, 0, 1, 2, &
      & 0, 0, 1, 2, 0, 1, 2, 2, 1, 0, 2, 1, &
      & 0, 1, 1, 2, 1, 1, 1, 0, 1, 1, 2, 1, 1, 1, 0, 1, 1, 2, 1, 1, 1], [3, 27])
   !> VTK_QUAD corners, counter-clockwise.
   integer, parameter :: quad4_ref(2, 4) = reshape([0, 0, 1, 0, 1, 1, 0, 1], [2, 4])

   !> A mesh for the tests.
   type :: mesh_type
      real(wp), allocatable :: x(:, :)
      integer, allocatable :: conn(:, :)
   end type mesh_type

contains

   subroutine collect_output(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('quad4_levels_read_back', test_quad4_read_back), &
         new_unittest('quad4_xdmf_references', test_quad4_xdmf), &
         new_unittest('hex27_read_back', test_hex27_read_back), &
         new_unittest('hex27_xdmf_references', test_hex27_xdmf), &
         new_unittest('no_open_hdf5_objects', test_no_leaks), &
         new_unittest('create_unwritable_path', test_create_unwritable), &
         new_unittest('not_open_errors', test_not_open), &
         new_unittest('level_errors', test_level_errors), &
         new_unittest('field_errors', test_field_errors), &
         new_unittest('xdmf_errors', test_xdmf_errors), &
         new_unittest('run_fields_resolve', test_run_fields), &
         new_unittest('run_fields_two_bodies', test_run_fields_bodies), &
         new_unittest('contact_point_sets', test_contact_point_sets) &
         ]
   end subroutine collect_output

   !> A structured n x n quad4 mesh of [0,1]^2: node (i,j) is number 1 + i + (n+1) j.
   function quad4_mesh(n) result(mesh)
      integer, intent(in) :: n
      type(mesh_type) :: mesh
      integer :: i, j, a, e

      allocate (mesh%x(2, (n + 1)**2), mesh%conn(4, n*n))
      do j = 0, n
         do i = 0, n
            mesh%x(:, 1 + i + (n + 1)*j) = [real(i, wp), real(j, wp)]/n
         end do
      end do
      e = 0
      do j = 0, n - 1
         do i = 0, n - 1
            e = e + 1
            do a = 1, 4
               mesh%conn(a, e) = 1 + (i + quad4_ref(1, a)) + (n + 1)*(j + quad4_ref(2, a))
            end do
         end do
      end do
   end function quad4_mesh

   !> `ne` hex27 cells in a row along x, each [e-1, e] x [0,1] x [0,1]; the
   !> nodes form a (2 ne + 1) x 3 x 3 lattice of step 1/2, numbered x fastest.
   function hex27_mesh(ne) result(mesh)
      integer, intent(in) :: ne
      type(mesh_type) :: mesh
      integer :: i, j, k, a, e, nx

      nx = 2*ne + 1
      allocate (mesh%x(3, nx*9), mesh%conn(27, ne))
      do k = 0, 2
         do j = 0, 2
            do i = 0, nx - 1
               mesh%x(:, 1 + i + nx*(j + 3*k)) = 0.5_wp*[real(i, wp), real(j, wp), real(k, wp)]
            end do
         end do
      end do
      do e = 1, ne
         do a = 1, 27
            mesh%conn(a, e) = 1 + (2*(e - 1) + hex27_ref(1, a)) + nx*(hex27_ref(2, a) + 3*hex27_ref(3, a))
         end do
      end do
   end function hex27_mesh

   !> A smooth made-up field with `ncomp` components at points `x`.
   function field_at(x, ncomp, seed) result(v)
      real(wp), intent(in) :: x(:, :)
      integer, intent(in) :: ncomp, seed
      real(wp) :: v(ncomp, size(x, 2))
      integer :: c, i
      do i = 1, size(x, 2)
         do c = 1, ncomp
            v(c, i) = sin(seed + c*sum(x(:, i))) + 0.1_wp*c*x(1, i)**2
         end do
      end do
   end function field_at

   !> A made-up cell class (0 internal, 1 cut) per cell.
   pure function class_pattern(level, n) result(c)
      integer, intent(in) :: level, n
      integer :: c(n), l
      c = [(mod(level + l, 2), l = 1, n)]
   end function class_pattern

   !> Cell centres of a mesh (mean of its nodes).
   function centres(mesh) result(xc)
      type(mesh_type), intent(in) :: mesh
      real(wp) :: xc(size(mesh%x, 1), size(mesh%conn, 2))
      integer :: e
      do e = 1, size(mesh%conn, 2)
         xc(:, e) = sum(mesh%x(:, mesh%conn(:, e)), dim=2)/size(mesh%conn, 1)
      end do
   end function centres

   !> Write the 2D file: levels 1 and 2 of a quad4 mesh with displacement,
   !> FE / SPR / SPR-C stresses (Voigt xx yy xy), error indicators, cell class.
   subroutine write_quad4_file(prefix, error)
      character(len=*), intent(in) :: prefix
      type(error_type), allocatable, intent(out) :: error
      type(h5_output_type) :: out
      type(mesh_type) :: mesh
      integer :: level

      call out%create(prefix//'.h5', error)
      if (allocated(error)) return
      do level = 1, 2
         mesh = quad4_mesh(2**level)
         call out%write_level(level, mesh%x, mesh%conn, cell_quad4, error)
         if (allocated(error)) return
         call out%write_node_field(level, 'displacement', field_at(mesh%x, 2, 1), error)
         if (allocated(error)) return
         call out%write_node_field(level, 'sigma_fe', field_at(mesh%x, 3, 2), error, components=['xx', 'yy', 'xy'])
         if (allocated(error)) return
         call out%write_node_field(level, 'sigma_spr', field_at(mesh%x, 3, 3), error, components=['xx', 'yy', 'xy'])
         if (allocated(error)) return
         call out%write_node_field(level, 'sigma_sprc', field_at(mesh%x, 3, 4), error, components=['xx', 'yy', 'xy'])
         if (allocated(error)) return
         call out%write_cell_field(level, 'eta_spr', field_at(centres(mesh), 1, 5), error)
         if (allocated(error)) return
         call out%write_cell_field(level, 'class', reshape(class_pattern(level, size(mesh%conn, 2)), &
            [1, size(mesh%conn, 2)]), error)
         if (allocated(error)) return
      end do
      call out%close(error)
      if (allocated(error)) return
      call out%write_xdmf(prefix//'.xdmf', error)
   end subroutine write_quad4_file

   subroutine test_quad4_read_back(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: prefix = dir//'test_output_quad4'
      type(mesh_type) :: mesh
      integer(hid_t) :: file
      real(wp), allocatable :: v(:, :), w(:, :)
      integer, allocatable :: iv(:, :)
      integer :: hdferr, level, ne

      call write_quad4_file(prefix, error)
      if (allocated(error)) return
      call h5fopen_f(prefix//'.h5', H5F_ACC_RDONLY_F, file, hdferr)
      call check(error, hdferr >= 0, 'reopen '//prefix//'.h5')
      if (allocated(error)) return
      do level = 1, 2
         mesh = quad4_mesh(2**level)
         ne = size(mesh%conn, 2)
         call read_real(file, '/level_0'//achar(48 + level)//'/mesh/x', [2, size(mesh%x, 2)], v, error)
         if (allocated(error)) exit
         call check(error, all(same_bits(v, mesh%x)), 'coordinates bitwise')
         if (allocated(error)) exit
         call read_int(file, '/level_0'//achar(48 + level)//'/mesh/connectivity', [4, ne], iv, error)
         if (allocated(error)) exit
         call check(error, all(iv == mesh%conn - 1), 'connectivity 0-based')
         if (allocated(error)) exit
         ! A 2-D vector is stored with 3 components, z = 0.
         call read_real(file, '/level_0'//achar(48 + level)//'/node/displacement', [3, size(mesh%x, 2)], v, error)
         if (allocated(error)) exit
         w = field_at(mesh%x, 2, 1)
         call check(error, all(same_bits(v(1:2, :), w)) .and. all(same_bits(v(3, :), 0.0_wp)), 'displacement padded to 3')
         if (allocated(error)) exit
         call read_real(file, '/level_0'//achar(48 + level)//'/node/sigma_sprc', [3, size(mesh%x, 2)], v, error)
         if (allocated(error)) exit
         call check(error, all(same_bits(v, field_at(mesh%x, 3, 4))), 'sigma_sprc bitwise')
         if (allocated(error)) exit
         ! One component: a 1-D dataset.
         call read_real(file, '/level_0'//achar(48 + level)//'/cell/eta_spr', [ne], v, error)
         if (allocated(error)) exit
         call check(error, all(same_bits(v(:, 1), reshape(field_at(centres(mesh), 1, 5), [ne]))), 'eta_spr bitwise')
         if (allocated(error)) exit
         call read_int(file, '/level_0'//achar(48 + level)//'/cell/class', [ne], iv, error)
         if (allocated(error)) exit
         call check(error, all(iv(:, 1) == class_pattern(level, ne)), 'class int32')
         if (allocated(error)) exit
      end do
      call h5fclose_f(file, hdferr)
   end subroutine test_quad4_read_back

   subroutine test_quad4_xdmf(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: prefix = dir//'test_output_quad4x'
      character(len=:), allocatable :: text

      call write_quad4_file(prefix, error)
      if (allocated(error)) return
      ! Per level: topology, geometry, displacement, 3 x 3 stress components, eta, class.
      call check_xdmf(prefix//'.xdmf', 'test_output_quad4x.h5', 28, error)
      if (allocated(error)) return
      call read_text_file(prefix//'.xdmf', text, error)
      if (allocated(error)) return
      call check(error, index(text, 'CollectionType="Temporal"') > 0 .and. index(text, '<Time Value="1"/>') > 0 &
         .and. index(text, '<Time Value="2"/>') > 0, 'temporal collection over the levels')
      if (allocated(error)) return
      call check(error, count_sub(text, 'TopologyType="Quadrilateral"'), 2, 'quad4 topology per level')
      if (allocated(error)) return
      call check(error, count_sub(text, 'GeometryType="XY"'), 2, 'XY geometry')
      if (allocated(error)) return
      call check(error, index(text, 'NumberOfElements="16"') > 0, '16 cells at level 2')
      if (allocated(error)) return
      call check(error, index(text, 'Name="displacement" AttributeType="Vector" Center="Node"') > 0, 'vector')
      if (allocated(error)) return
      call check(error, index(text, 'Name="sigma_spr_xy" AttributeType="Scalar" Center="Node"') > 0, &
         'Voigt component as a scalar')
      if (allocated(error)) return
      ! Level 2 has 25 nodes: the xy column is start (0,2), stride (1,1), count (25,1).
      call check(error, index(text, '>0 2 1 1 25 1</DataItem>') > 0, 'hyperslab of the third column')
      if (allocated(error)) return
      call check(error, index(text, 'Name="class" AttributeType="Scalar" Center="Cell"') > 0, 'cell class')
   end subroutine test_quad4_xdmf

   !> Write the 3D file: level 3 of two hex27 cells and level 0 of one hex8.
   subroutine write_hex_file(prefix, error)
      character(len=*), intent(in) :: prefix
      type(error_type), allocatable, intent(out) :: error
      type(h5_output_type) :: out
      type(mesh_type) :: mesh
      character(len=2), parameter :: voigt(6) = ['xx', 'yy', 'zz', 'xy', 'yz', 'xz']

      call out%create(prefix//'.h5', error)
      if (allocated(error)) return
      mesh = hex27_mesh(2)
      call out%write_level(3, mesh%x, mesh%conn, cell_hex27, error)
      if (allocated(error)) return
      call out%write_node_field(3, 'displacement', field_at(mesh%x, 3, 1), error)
      if (allocated(error)) return
      call out%write_node_field(3, 'sigma_sprc', field_at(mesh%x, 6, 2), error, components=voigt)
      if (allocated(error)) return
      call out%write_cell_field(3, 'eta_sprc', field_at(centres(mesh), 1, 3), error)
      if (allocated(error)) return
      ! A hex8 level written before the files closes, out of level order.
      mesh%x = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1]*1.0_wp, [3, 8])
      mesh%conn = reshape([1, 2, 3, 4, 5, 6, 7, 8], [8, 1])
      call out%write_level(0, mesh%x, mesh%conn, cell_hex8, error)
      if (allocated(error)) return
      call out%close(error)
      if (allocated(error)) return
      call out%write_xdmf(prefix//'.xdmf', error)
   end subroutine write_hex_file

   !> The hex27 connectivity comes back 0-based and in VTK order: node a of
   !> each cell sits at the cell origin + hex27_ref(:, a)/2.
   subroutine test_hex27_read_back(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: prefix = dir//'test_output_hex27'
      type(mesh_type) :: mesh
      integer(hid_t) :: file
      real(wp), allocatable :: x(:, :), s(:, :)
      integer, allocatable :: conn(:, :)
      integer :: hdferr, e, a

      call write_hex_file(prefix, error)
      if (allocated(error)) return
      mesh = hex27_mesh(2)
      call h5fopen_f(prefix//'.h5', H5F_ACC_RDONLY_F, file, hdferr)
      call check(error, hdferr >= 0, 'reopen')
      if (allocated(error)) return
      call read_real(file, '/level_03/mesh/x', [3, 45], x, error)
      if (.not. allocated(error)) call read_int(file, '/level_03/mesh/connectivity', [27, 2], conn, error)
      if (.not. allocated(error)) call read_real(file, '/level_03/node/sigma_sprc', [6, 45], s, error)
      call h5fclose_f(file, hdferr)
      if (allocated(error)) return
      do e = 1, 2
         do a = 1, 27
            call check(error, all(same_bits(x(:, conn(a, e) + 1), [real(e - 1, wp), 0.0_wp, 0.0_wp] + 0.5_wp*hex27_ref(:, a))), &
               'cell '//achar(48 + e)//' node '//itoa(a)//' at its VTK position')
            if (allocated(error)) return
         end do
      end do
      call check(error, all(same_bits(s, field_at(mesh%x, 6, 2))), 'Voigt stresses bitwise')
   end subroutine test_hex27_read_back

   subroutine test_hex27_xdmf(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: prefix = dir//'test_output_hex27x'
      character(len=:), allocatable :: text

      call write_hex_file(prefix, error)
      if (allocated(error)) return
      ! 2 topologies + 2 geometries + displacement + 6 hyperslab sources + eta.
      call check_xdmf(prefix//'.xdmf', 'test_output_hex27x.h5', 12, error)
      if (allocated(error)) return
      call read_text_file(prefix//'.xdmf', text, error)
      if (allocated(error)) return
      call check(error, index(text, 'TopologyType="Hexahedron_27" NumberOfElements="2"') > 0, 'hex27 topology')
      if (allocated(error)) return
      call check(error, index(text, 'TopologyType="Hexahedron" NumberOfElements="1"') > 0, 'hex8 topology')
      if (allocated(error)) return
      call check(error, count_sub(text, 'GeometryType="XYZ"'), 2, 'XYZ geometry')
      if (allocated(error)) return
      call check(error, index(text, '<Time Value="0"/>') < index(text, '<Time Value="3"/>'), &
         'levels in time order though written 3 then 0')
      if (allocated(error)) return
      call check(error, index(text, 'Name="sigma_sprc_xz"') > 0, 'sixth Voigt component')
      if (allocated(error)) return
      call check(error, index(text, 'Dimensions="45 3" NumberType="Float" Precision="8" Format="HDF">'// &
         'test_output_hex27x.h5:/level_03/node/displacement<') > 0, 'displacement reference')
   end subroutine test_hex27_xdmf

   !> After close, no HDF5 object is left open (counted by HDF5 itself, all
   !> files and transient datatypes: the Fortran interface's count leaves out
   !> one set of its predefined types, so repeated h5open_f calls would show
   !> here too), also after a failed call.
   subroutine test_no_leaks(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(h5_output_type) :: out, other
      type(mesh_type) :: mesh
      integer(size_t) :: n_open
      integer :: hdferr

      call write_quad4_file(dir//'test_output_leaks', error)
      if (allocated(error)) return
      call h5fget_obj_count_f(int(H5F_OBJ_ALL_F, hid_t), H5F_OBJ_ALL_F, n_open, hdferr)
      call check(error, hdferr >= 0 .and. n_open == 0, 'objects open after a full write: '//itoa(int(n_open)))
      if (allocated(error)) return
      call out%create(dir//'test_output_leaks2.h5', error)
      if (allocated(error)) return
      mesh = quad4_mesh(1)
      call out%write_level(2, mesh%x, mesh%conn, cell_quad4, error)
      if (allocated(error)) return
      call h5fget_obj_count_f(int(H5F_OBJ_ALL_F, hid_t), H5F_OBJ_ALL_F, n_open, hdferr)
      call check(error, n_open == 1, 'only the file is open between calls: '//itoa(int(n_open)))
      if (allocated(error)) return
      ! A call failing inside HDF5 (the file is open in `out`) leaves nothing open.
      call other%create(dir//'test_output_leaks2.h5', err)
      call check_error(error, err, stat_io, 'test_output_leaks2.h5')
      if (allocated(error)) return
      call h5fget_obj_count_f(int(H5F_OBJ_ALL_F, hid_t), H5F_OBJ_ALL_F, n_open, hdferr)
      call check(error, n_open == 1, 'still only the file after a failed create: '//itoa(int(n_open)))
      if (allocated(error)) return
      call out%write_node_field(2, 'u', field_at(mesh%x, 1, 1), error)
      if (allocated(error)) return
      call out%close(error)
      if (allocated(error)) return
      call out%close(err)
      call check(error, .not. allocated(err), 'closing twice is harmless')
      if (allocated(error)) return
      call h5fget_obj_count_f(int(H5F_OBJ_ALL_F, hid_t), H5F_OBJ_ALL_F, n_open, hdferr)
      call check(error, n_open == 0, 'objects open after close: '//itoa(int(n_open)))
   end subroutine test_no_leaks

   subroutine test_create_unwritable(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(h5_output_type) :: out
      character(len=*), parameter :: path = dir//'no_such_directory/out.h5'

      call out%create(path, err)
      call check_error(error, err, stat_io, path)
      if (allocated(error)) return
      call check(error, .not. out%opened(), 'not open after a failed create')
   end subroutine test_create_unwritable

   subroutine test_not_open(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(h5_output_type) :: out
      type(mesh_type) :: mesh

      mesh = quad4_mesh(1)
      call out%write_level(1, mesh%x, mesh%conn, cell_quad4, err)
      call check_error(error, err, stat_invalid_input, 'no HDF5 file open')
      if (allocated(error)) return
      call out%write_node_field(1, 'u', mesh%x, err)
      call check_error(error, err, stat_invalid_input, 'no HDF5 file open')
      if (allocated(error)) return
      call out%write_xdmf(dir//'test_output_never.xdmf', err)
      call check_error(error, err, stat_invalid_input, 'no HDF5 file was created')
      if (allocated(error)) return
      call out%create(dir//'test_output_twice.h5', error)
      if (allocated(error)) return
      call out%create(dir//'test_output_twice2.h5', err)
      call check_error(error, err, stat_invalid_input, 'still open')
      if (allocated(error)) return
      call out%close(error)
   end subroutine test_not_open

   subroutine test_level_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(h5_output_type) :: out
      type(mesh_type) :: mesh, hex
      real(wp) :: xyz(3, 9)
      real(wp), allocatable :: flat(:, :)

      mesh = quad4_mesh(2)
      hex = hex27_mesh(1)
      call out%create(dir//'test_output_level_errors.h5', error)
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn, 99, err)
      call check_error(error, err, stat_invalid_input, 'unknown cell type')
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn, cell_quad9, err)
      call check_error(error, err, stat_invalid_input, 'Quadrilateral_9 cells have 9 nodes')
      if (allocated(error)) return
      flat = hex%x(1:2, :)
      call out%write_level(1, flat, hex%conn, cell_hex27, err)
      call check_error(error, err, stat_invalid_input, 'need 3 coordinates')
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn + 1, cell_quad4, err)
      call check_error(error, err, stat_invalid_input, 'outside 1..9')
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn(:, 1:0), cell_quad4, err)
      call check_error(error, err, stat_invalid_input, 'no nodes or no cells')
      if (allocated(error)) return
      call out%write_level(100, mesh%x, mesh%conn, cell_quad4, err)
      call check_error(error, err, stat_invalid_input, '0..99')
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn, cell_quad4, error)
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn, cell_quad4, err)
      call check_error(error, err, stat_invalid_input, 'already written')
      if (allocated(error)) return
      ! A quad mesh may carry 3 coordinates (XYZ).
      xyz = 0.0_wp
      xyz(1:2, :) = mesh%x
      call out%write_level(2, xyz, mesh%conn, cell_quad4, error)
      if (allocated(error)) return
      ! Grids of bodies: valid names, each once, not next to an unnamed grid.
      call out%write_level(1, mesh%x, mesh%conn, cell_quad4, err, body='a')
      call check_error(error, err, stat_invalid_input, 'one unnamed grid or named ones')
      if (allocated(error)) return
      call out%write_level(3, mesh%x, mesh%conn, cell_quad4, err, body='1st')
      call check_error(error, err, stat_invalid_input, 'a body name is a letter')
      if (allocated(error)) return
      call out%write_level(3, mesh%x, mesh%conn, cell_quad4, error, body='a')
      if (allocated(error)) return
      call out%write_level(3, mesh%x, mesh%conn, cell_quad4, err, body='a')
      call check_error(error, err, stat_invalid_input, 'level 3 body "a": already written')
      if (allocated(error)) return
      call out%write_level(3, mesh%x, mesh%conn, cell_quad4, err)
      call check_error(error, err, stat_invalid_input, 'one unnamed grid or named ones')
      if (allocated(error)) return
      call out%write_node_field(3, 'u', mesh%x, err, body='b')
      call check_error(error, err, stat_invalid_input, 'level not written yet')
      if (allocated(error)) return
      call out%close(error)
   end subroutine test_level_errors

   subroutine test_field_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(h5_output_type) :: out
      type(mesh_type) :: mesh
      real(wp), allocatable :: u(:, :)

      mesh = quad4_mesh(2)
      u = field_at(mesh%x, 3, 1)
      call out%create(dir//'test_output_field_errors.h5', error)
      if (allocated(error)) return
      call out%write_node_field(1, 'u', u, err)
      call check_error(error, err, stat_invalid_input, 'level not written')
      if (allocated(error)) return
      call out%write_level(1, mesh%x, mesh%conn, cell_quad4, error)
      if (allocated(error)) return
      call out%write_node_field(1, 'u', u(:, 1:8), err)
      call check_error(error, err, stat_invalid_input, 'expected (ncomp, 9)')
      if (allocated(error)) return
      call out%write_cell_field(1, 'u', u, err)
      call check_error(error, err, stat_invalid_input, 'expected (ncomp, 4)')
      if (allocated(error)) return
      call out%write_node_field(1, 'a/b', u, err)
      call check_error(error, err, stat_invalid_input, 'a name is')
      if (allocated(error)) return
      call out%write_node_field(1, '', u, err)
      call check_error(error, err, stat_invalid_input, 'a name is')
      if (allocated(error)) return
      call out%write_node_field(1, 'sigma', field_at(mesh%x, 4, 1), err)
      call check_error(error, err, stat_invalid_input, 'give their names')
      if (allocated(error)) return
      call out%write_node_field(1, 'sigma', u, err, components=['xx', 'yy'])
      call check_error(error, err, stat_invalid_input, '2 component names for 3')
      if (allocated(error)) return
      call out%write_node_field(1, 'sigma', u, err, components=['xx', 'x"', 'yy'])
      call check_error(error, err, stat_invalid_input, 'bad component name')
      if (allocated(error)) return
      call out%write_node_field(1, 'sigma', u, err, components=['xx', 'yy', 'xx'])
      call check_error(error, err, stat_invalid_input, 'repeated')
      if (allocated(error)) return
      call out%write_node_field(1, 'sigma', u, error, components=['xx', 'yy', 'xy'])
      if (allocated(error)) return
      call out%write_node_field(1, 'sigma', u, err)
      call check_error(error, err, stat_invalid_input, 'already used')
      if (allocated(error)) return
      ! 'sigma_xx' would show in ParaView under the same name as a component of 'sigma'.
      call out%write_node_field(1, 'sigma_xx', u(1:1, :), err)
      call check_error(error, err, stat_invalid_input, 'already used')
      if (allocated(error)) return
      ! The same name at the other centre is a different array.
      call out%write_cell_field(1, 'sigma', field_at(centres(mesh), 1, 2), error)
      if (allocated(error)) return
      call out%close(error)
   end subroutine test_field_errors

   subroutine test_xdmf_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(h5_output_type) :: out

      call out%create(dir//'test_output_xdmf_errors.h5', error)
      if (allocated(error)) return
      call out%close(error)
      if (allocated(error)) return
      call out%write_xdmf('test_output_elsewhere.xdmf', err)
      call check_error(error, err, stat_invalid_input, 'same directory')
      if (allocated(error)) return
      call out%write_xdmf(dir//'test_output_xdmf_errors.h5/x.xdmf', err)
      call check_error(error, err, stat_invalid_input, 'same directory')
      if (allocated(error)) return
      call out%create(dir//'no_such_dir_h5/out.h5', err)
      call check_error(error, err, stat_io, 'no_such_dir_h5/out.h5')
   end subroutine test_xdmf_errors

   ! ---------------------------------------------------------------- helpers

   !> `sprc run`'s own output: two levels of the default scene written through
   !> the run pipeline; every XDMF reference resolves to a dataset of the stated
   !> shape, and the displacement has one row per node of the level's mesh.
   subroutine test_run_fields(error)
      use sprc_io_scene, only: scene_type, read_scene_text, default_scene_text
      use sprc_study_level, only: study_type, prepare_study, run_level, level_type
      use sprc_io_fields, only: write_level_fields
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result
      type(h5_output_type) :: h5
      integer :: level

      call read_scene_text(default_scene_text(), 'default', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      call h5%create('build/test_output_run.h5', error)
      if (allocated(error)) return
      do level = 3, 4
         call run_level(study, level, result, error)
         if (allocated(error)) return
         call write_level_fields(h5, study, result, error)
         if (allocated(error)) return
         call check(error, result%row%err_fe > 0.0_wp .and. result%row%err_fe < 1.0_wp .and. &
            result%row%eta_spr > 0.0_wp, 'report row of the level has its errors')
         if (allocated(error)) return
      end do
      call h5%close(error)
      if (allocated(error)) return
      call h5%write_xdmf('build/test_output_run.xdmf', error)
      if (allocated(error)) return
      call check_xdmf('build/test_output_run.xdmf', 'test_output_run.h5', -1, error)
   end subroutine test_run_fields

   !> Two bodies: each level is a spatial collection of one grid per body, under
   !> `/level_LL/<body>/`; every reference resolves, and a body's displacement
   !> reads back bit for bit.
   subroutine test_run_fields_bodies(error)
      use sprc_io_scene, only: scene_type, read_scene_text
      use sprc_study_level, only: study_type, prepare_study, run_level, level_type
      use sprc_io_fields, only: write_level_fields
      use sprc_test_study, only: two_body_scene
      type(error_type), allocatable, intent(out) :: error
      type(scene_type) :: scene
      type(study_type) :: study
      type(level_type) :: result
      type(h5_output_type) :: h5
      character(len=:), allocatable :: text
      real(wp), allocatable :: u(:, :)
      integer(hid_t) :: file
      integer :: level, hdferr

      call read_scene_text(two_body_scene(.true., .true., '3'), 'two bodies', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      call h5%create('build/test_output_bodies.h5', error)
      if (allocated(error)) return
      do level = 4, 3, -1
         call run_level(study, level, result, error)
         if (allocated(error)) return
         call write_level_fields(h5, study, result, error)
         if (allocated(error)) return
      end do
      call h5%close(error)
      if (allocated(error)) return
      call h5%write_xdmf('build/test_output_bodies.xdmf', error)
      if (allocated(error)) return
      call check_xdmf('build/test_output_bodies.xdmf', 'test_output_bodies.h5', -1, error)
      if (allocated(error)) return
      call read_text_file('build/test_output_bodies.xdmf', text, error)
      if (allocated(error)) return
      call check(error, index(text, '<Grid Name="level_03" GridType="Collection" CollectionType="Spatial">') > 0 &
         & .and. index(text, '<Grid Name="block" GridType="Uniform">') > 0 .and. &
         & index(text, 'level_03') < index(text, 'level_04'), 'levels in order, bodies as spatial collections')
      if (allocated(error)) return
      call h5fopen_f('build/test_output_bodies.h5', H5F_ACC_RDONLY_F, file, hdferr)
      call check(error, hdferr >= 0, 'open the HDF5 file')
      if (allocated(error)) return
      associate (ub => result%bodies(2)%problem%u)
         call read_real(file, '/level_03/block/node/displacement', [3, size(ub, 2)], u, error)
         if (.not. allocated(error)) call check(error, all(u(1:2, :) == study%bodies(2)%units%strain*ub) .and. &
            & all(u(3, :) == 0.0_wp), 'displacement of the block at level 3 reads back (in the scene''s units)')
      end associate
      if (.not. allocated(error)) call check_attribute(file, '/level_03/block/node/displacement', 'units', 'length', error)
      if (.not. allocated(error)) call check_attribute(file, '/level_03/block/node/displacement', 'components', &
         & 'x y z (z = 0: a 2-D vector)', error)
      if (.not. allocated(error)) call check_attribute(file, '/level_04/cylinder/node/sigma_sprc', 'components', &
         & 'xx yy xy (Voigt order)', error)
      if (.not. allocated(error)) call check_attribute(file, '/level_04/cylinder/node/sigma_fe', 'units', 'stress', error)
      if (.not. allocated(error)) call check_attribute(file, '/level_04/cylinder/cell/zz_error_spr', 'units', &
         & 'energy norm, sqrt(stress*length^2)', error)
      call h5fclose_f(file, hdferr)
      if (allocated(error)) return
      call check(error, index(text, '<Information Name="units" Value="stress"/>') > 0, 'the XDMF names the units')
   end subroutine test_run_fields_bodies

   !> The slave points of a level's contact pairs (synthetic results: the 2D
   !> sample's two pairs) as point sets `/level_LL/contact_<k>/`, a '_' in
   !> front while a body has that name; every XDMF reference resolves, the
   !> topology is Polyvertex, and coordinates, pressures (empty: NaN) and
   !> states read back bit for bit.
   subroutine test_contact_point_sets(error)
      use, intrinsic :: ieee_arithmetic, only: ieee_is_nan
      use sprc_study_level, only: study_type, level_type
      use sprc_io_fields, only: write_level_fields
      use sprc_test_contact_model, only: contact_sample
      type(error_type), allocatable, intent(out) :: error
      type(study_type) :: study
      type(level_type) :: result
      type(h5_output_type) :: h5
      character(len=:), allocatable :: text
      real(wp), allocatable :: v(:, :)
      integer, allocatable :: iv(:, :)
      integer(hid_t) :: file
      integer :: hdferr

      study%dim = 2
      study%order = 1
      allocate (study%bodies(1))
      study%bodies(1)%name = 'contact_1'
      result%level = 5
      allocate (result%bodies(0))
      result%contacts = contact_sample()
      call h5%create('build/test_output_contact.h5', error)
      if (allocated(error)) return
      call write_level_fields(h5, study, result, error)
      if (allocated(error)) return
      call h5%close(error)
      if (allocated(error)) return
      call h5%write_xdmf('build/test_output_contact.xdmf', error)
      if (allocated(error)) return
      call check_xdmf('build/test_output_contact.xdmf', 'test_output_contact.h5', -1, error)
      if (allocated(error)) return
      call read_text_file('build/test_output_contact.xdmf', text, error)
      if (allocated(error)) return
      call check(error, count_sub(text, 'TopologyType="Polyvertex" NumberOfElements="3" NodesPerElement="1"'), 1, &
         & 'pair 1: a point set of 3 points')
      if (allocated(error)) return
      call check(error, index(text, '<Grid Name="_contact_1" GridType="Uniform">') > 0 .and. &
         & index(text, '<Grid Name="contact_2" GridType="Uniform">') > 0, 'named contact_<k>, clear of body names')
      if (allocated(error)) return
      call h5fopen_f('build/test_output_contact.h5', H5F_ACC_RDONLY_F, file, hdferr)
      call check(error, hdferr >= 0, 'open the HDF5 file')
      if (allocated(error)) return
      associate (c => result%contacts(1))
         call read_real(file, '/level_05/_contact_1/mesh/x', [2, 3], v, error)
         if (.not. allocated(error)) call check(error, all(same_bits(v, c%x)), 'coordinates')
         if (.not. allocated(error)) call read_real(file, '/level_05/_contact_1/node/p_fe', [3], v, error)
         if (.not. allocated(error)) call check(error, all(same_bits(v(:, 1), c%p_fe)), 'p_fe')
         if (.not. allocated(error)) call read_real(file, '/level_05/_contact_1/node/p_spr', [3], v, error)
         if (.not. allocated(error)) call check(error, all(ieee_is_nan(v)), 'p_spr not computed: NaN')
         if (.not. allocated(error)) call read_real(file, '/level_05/_contact_1/node/normal', [3, 3], v, error)
         if (.not. allocated(error)) call check(error, all(same_bits(v(1:2, :), c%normal)), 'normal')
         if (.not. allocated(error)) call read_int(file, '/level_05/_contact_1/node/state', [3], iv, error)
         if (.not. allocated(error)) call check(error, all(iv(:, 1) == c%state), 'state')
         if (.not. allocated(error)) call read_int(file, '/level_05/_contact_1/mesh/connectivity', [1, 3], iv, error)
         if (.not. allocated(error)) call check(error, all(iv(1, :) == [0, 1, 2]), 'one vertex per point, 0-based')
      end associate
      if (.not. allocated(error)) call read_real(file, '/level_05/contact_2/node/gap', [1], v, error)
      if (.not. allocated(error)) call check(error, all(same_bits(v(:, 1), result%contacts(2)%gap)), 'gap of pair 2')
      call h5fclose_f(file, hdferr)
   end subroutine test_contact_point_sets

   !> Every `<DataItem ... Format="HDF">FILE:/PATH</DataItem>` of the XDMF file
   !> must name `h5_name`, and PATH must be a dataset whose dimensions (C
   !> order) are the item's Dimensions. Also: the file is well-formed XML, and
   !> there are `n_refs` references (n_refs < 0: at least one).
   subroutine check_xdmf(path, h5_name, n_refs, error)
      character(len=*), intent(in) :: path, h5_name
      integer, intent(in) :: n_refs
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, msg, tag, ref, dims_text
      integer(hid_t) :: file
      integer :: hdferr, pos, k, n, colon
      integer, allocatable :: dims(:), expected(:)

      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'Xdmf', msg), 'XDMF well-formed: '//msg)
      if (allocated(error)) return
      call python_xml_check(path, error)
      if (allocated(error)) return
      call h5fopen_f(path(:index(path, '/', back=.true.))//h5_name, H5F_ACC_RDONLY_F, file, hdferr)
      call check(error, hdferr >= 0, 'open '//h5_name)
      if (allocated(error)) return
      n = 0
      pos = 1
      do
         k = index(text(pos:), '<DataItem ')
         if (k == 0) exit
         pos = pos + k - 1
         tag = text(pos:pos + index(text(pos:), '>') - 1)
         pos = pos + len(tag)
         if (index(tag, 'Format="HDF"') == 0) cycle
         n = n + 1
         ref = text(pos:pos + index(text(pos:), '</DataItem>') - 2)
         colon = index(ref, ':')
         call check(error, ref(:colon - 1), h5_name, 'HDF5 file of a reference')
         if (allocated(error)) exit
         dims_text = tag(index(tag, 'Dimensions="') + 12:)
         dims_text = dims_text(:index(dims_text, '"') - 1)
         expected = parse_ints(dims_text)
         call dataset_dims(file, ref(colon + 1:), dims, error)
         if (allocated(error)) exit
         ! HDF5's Fortran API reports dimensions in Fortran order, XDMF in C order.
         call check(error, size(dims) == size(expected), ref//': rank')
         if (allocated(error)) exit
         call check(error, all(dims(size(dims):1:-1) == expected), ref//': dimensions '//dims_text)
         if (allocated(error)) exit
      end do
      call h5fclose_f(file, hdferr)
      if (allocated(error)) return
      if (n_refs < 0) then
         call check(error, n > 0, 'HDF5 references in '//path)
      else
         call check(error, n, n_refs, 'HDF5 references in '//path)
      end if
   end subroutine check_xdmf

   !> Dimensions (Fortran order) of dataset `path`; a missing dataset fails the test.
   subroutine dataset_dims(file, path, dims, error)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path
      integer, allocatable, intent(out) :: dims(:)
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: dset, space
      integer(hsize_t) :: d(7), maxd(7)
      integer :: hdferr, rank

      call h5eset_auto_f(0, hdferr)
      call h5dopen_f(file, path, dset, hdferr)
      call h5eset_auto_f(1, rank) ! rank: a spare status, reset below
      if (hdferr < 0) then
         call test_failed(error, 'no dataset '//path)
         return
      end if
      call h5dget_space_f(dset, space, hdferr)
      call h5sget_simple_extent_ndims_f(space, rank, hdferr)
      call h5sget_simple_extent_dims_f(space, d, maxd, hdferr)
      dims = int(d(:rank))
      call h5sclose_f(space, hdferr)
      call h5dclose_f(dset, hdferr)
   end subroutine dataset_dims

   !> Read a float64 dataset whose Fortran shape must be `shape_`; a 1-D
   !> dataset comes back as one column.
   subroutine read_real(file, path, shape_, values, error)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path
      integer, intent(in) :: shape_(:)
      real(wp), allocatable, target, intent(out) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: dset
      type(c_ptr) :: buf
      integer :: hdferr

      call open_checked(file, path, shape_, dset, error)
      if (allocated(error)) return
      if (size(shape_) == 1) then
         allocate (values(shape_(1), 1))
      else
         allocate (values(shape_(1), shape_(2)))
      end if
      buf = c_loc(values)
      call h5dread_f(dset, H5T_NATIVE_DOUBLE, buf, hdferr)
      call h5dclose_f(dset, hdferr)
   end subroutine read_real

   !> The string attribute `name` of dataset `path` reads `expected`.
   subroutine check_attribute(file, path, name, expected, error)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path, name, expected
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: dset, attr, atype
      integer(size_t) :: n
      character(len=256) :: value
      integer :: hdferr, e2

      value = ''
      n = 0
      call h5dopen_f(file, path, dset, hdferr)
      if (hdferr >= 0) then
         call h5aopen_f(dset, name, attr, hdferr)
         if (hdferr >= 0) then
            call h5aget_type_f(attr, atype, hdferr)
            if (hdferr >= 0) call h5tget_size_f(atype, n, hdferr)
            if (hdferr >= 0 .and. n <= len(value)) call h5aread_f(attr, atype, value(1:n), [1_hsize_t], hdferr)
            call h5tclose_f(atype, e2)
            call h5aclose_f(attr, e2)
         end if
         call h5dclose_f(dset, e2)
      end if
      call check(error, hdferr >= 0 .and. value(1:n) == expected, path//' attribute '//name//' = "'// &
         & value(1:n)//'", expected "'//expected//'"')
   end subroutine check_attribute

   subroutine read_int(file, path, shape_, values, error)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path
      integer, intent(in) :: shape_(:)
      integer, allocatable, target, intent(out) :: values(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer(hid_t) :: dset
      type(c_ptr) :: buf
      integer :: hdferr

      call open_checked(file, path, shape_, dset, error)
      if (allocated(error)) return
      if (size(shape_) == 1) then
         allocate (values(shape_(1), 1))
      else
         allocate (values(shape_(1), shape_(2)))
      end if
      buf = c_loc(values)
      call h5dread_f(dset, H5T_NATIVE_INTEGER, buf, hdferr)
      call h5dclose_f(dset, hdferr)
   end subroutine read_int

   !> Open dataset `path` after checking it has Fortran shape `shape_`.
   subroutine open_checked(file, path, shape_, dset, error)
      integer(hid_t), intent(in) :: file
      character(len=*), intent(in) :: path
      integer, intent(in) :: shape_(:)
      integer(hid_t), intent(out) :: dset
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: dims(:)
      integer :: hdferr

      call dataset_dims(file, path, dims, error)
      if (allocated(error)) return
      if (size(dims) /= size(shape_)) then
         call test_failed(error, path//': rank '//itoa(size(dims))//', expected '//itoa(size(shape_)))
         return
      end if
      if (any(dims /= shape_)) then
         call test_failed(error, path//': wrong shape')
         return
      end if
      call h5dopen_f(file, path, dset, hdferr)
   end subroutine open_checked

   function parse_ints(s) result(v)
      character(len=*), intent(in) :: s
      integer, allocatable :: v(:)
      integer :: n, i, stat
      n = 1
      do i = 1, len_trim(s)
         if (s(i:i) == ' ') n = n + 1
      end do
      allocate (v(n))
      read (s, *, iostat=stat) v
      if (stat /= 0) v = -1
   end function parse_ints

   subroutine check_error(error, err, stat, part)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable, intent(in) :: err
      integer, intent(in) :: stat
      character(len=*), intent(in) :: part

      if (.not. allocated(err)) then
         call test_failed(error, 'expected an error mentioning "'//part//'"')
         return
      end if
      call check(error, err%stat, stat, 'status of: '//err%message)
      if (allocated(error)) return
      call check(error, index(err%message, part) > 0, 'message "'//err%message//'" names "'//part//'"')
   end subroutine check_error

   !> Bitwise equality: what was written must come back unchanged.
   elemental logical function same_bits(a, b)
      real(wp), intent(in) :: a, b
      same_bits = transfer(a, 1_i8) == transfer(b, 1_i8)
   end function same_bits

   integer function count_sub(s, sub) result(n)
      character(len=*), intent(in) :: s, sub
      integer :: pos, k
      n = 0
      pos = 1
      do
         k = index(s(pos:), sub)
         if (k == 0) exit
         n = n + 1
         pos = pos + k
      end do
   end function count_sub

end module sprc_test_output
