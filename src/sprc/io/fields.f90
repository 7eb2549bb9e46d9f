!> The fields of one study level in the HDF5 output (layout in
!> `sprc_io_xdmf`): per body, under `/level_LL/<body>/`, its mesh,
!> displacement, FE nodal stresses (average of the elements at each node),
!> recovered nodal stresses, element error indicators (ZZ per method; exact
!> where known) and cell class; per `&contact` pair, under
!> `/level_LL/contact_<k>/`, its slave-surface points as a point set with
!> the contact pressures, gap, state, tangential tractions, weights and
!> normals (scene units; an empty value, not computed, is NaN).
!> An adaptive study (`&adapt`) writes each step under `/level_SS/`, SS the
!> step (0 the start mesh), not a level (the steps' finest levels repeat),
!> and each body's cells carry their grid level, `cell_level`, to show where
!> the run refined.
module sprc_io_fields
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   use sprc_geometry_region, only: cell_cut
   use sprc_study_level, only: study_type, level_type, body_level_type, nodal_fe_stress
   use sprc_study_model, only: analysis_units_type
   use sprc_io_hdf5, only: h5_output_type
   use sprc_io_xdmf, only: cell_quad4, cell_quad9, cell_hex8, cell_hex27, cell_vertex
   use sprc_core_text, only: itoa
   use sprc_contact_result, only: contact_result_type
   implicit none
   private

   !> The writer, as allocation errors name it.
   character(len=*), parameter :: who = 'HDF5 fields'

   public :: write_level_fields

contains

   !> Write every body of `result` (a level of `study`) into `h5`; with `step`
   !> (an adaptive study's step), under that number, with `cell_level`.
   subroutine write_level_fields(h5, study, result, error, step)
      type(h5_output_type), intent(inout) :: h5
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: step
      integer :: cell_type, b, key

      key = result%level
      if (present(step)) key = step

      if (study%dim == 2) then
         cell_type = merge(cell_quad4, cell_quad9, study%order == 1)
      else
         cell_type = merge(cell_hex8, cell_hex27, study%order == 1)
      end if
      do b = 1, size(result%bodies)
         call write_body(h5, key, study%bodies(b)%name, study%bodies(b)%units, cell_type, &
            & result%bodies(b), result%done, error)
         if (allocated(error)) return
         if (present(step)) call write_cell_level(h5, key, study%bodies(b)%name, result%bodies(b), error)
         if (allocated(error)) return
      end do
      if (.not. allocated(result%contacts)) return
      do b = 1, size(result%contacts)
         call write_contact(h5, key, contact_grid_name(b, study), result%contacts(b), error)
         if (allocated(error)) return
      end do
   end subroutine write_level_fields

   !> The grid level of each cell of a body, `cell_level`.
   subroutine write_cell_level(h5, key, body, bl, error)
      type(h5_output_type), intent(inout) :: h5
      integer, intent(in) :: key
      character(len=*), intent(in) :: body
      type(body_level_type), intent(in) :: bl
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: levels(:, :)
      integer :: stat

      associate (grid => bl%problem%mesh%grid)
         allocate (levels(1, grid%n_leaves), stat=stat)
         call check_allocation(stat, who, 'the level of each cell', grid%n_leaves, 4, error)
         if (allocated(error)) return
         levels(1, :) = grid%leaf_level(1:grid%n_leaves)
      end associate
      call h5%write_cell_field(key, 'cell_level', levels, error, body=body)
   end subroutine write_cell_level

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

   !> The slave points of one pair as a point set named `name` (none without points).
   subroutine write_contact(h5, level, name, c, error)
      type(h5_output_type), intent(inout) :: h5
      integer, intent(in) :: level
      character(len=*), intent(in) :: name
      type(contact_result_type), intent(in) :: c
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: ints(:, :)
      real(wp), allocatable :: work(:, :)
      integer :: i, stat

      if (c%npoint == 0) return
      allocate (ints(1, c%npoint), stat=stat)
      call check_allocation(stat, who, 'the vertex of each slave point', c%npoint, 4, error)
      if (allocated(error)) return
      do i = 1, c%npoint
         ints(1, i) = i
      end do
      call h5%write_level(level, c%x, ints, cell_vertex, error, body=name)
      if (.not. allocated(error)) call scalar('p_fe', c%p_fe)
      if (.not. allocated(error)) call scalar('p_spr', c%p_spr)
      if (.not. allocated(error)) call scalar('p_sprc', c%p_sprc)
      if (.not. allocated(error)) call scalar('p_exact', c%p_exact)
      if (.not. allocated(error)) call scalar('gap', c%gap)
      if (.not. allocated(error)) call scalar('ts_fe', c%ts_fe)
      if (.not. allocated(error)) call scalar('ts_sprc', c%ts_sprc)
      if (.not. allocated(error)) call scalar('weight', c%weight)
      if (.not. allocated(error)) call h5%write_node_field(level, 'normal', c%normal, error, body=name)
      ! 0 open, 1 stick, 2 slip (sprc_contact_result)
      if (allocated(error)) return
      ints(1, :) = c%state
      call h5%write_node_field(level, 'state', ints, error, body=name)
   contains
      subroutine scalar(field, values)
         character(len=*), intent(in) :: field
         real(wp), intent(in) :: values(:)
         call scaled_row(1.0_wp, values, .false., work, error)
         if (.not. allocated(error)) call h5%write_node_field(level, field, work, error, body=name)
      end subroutine scalar
   end subroutine write_contact

   !> One body's fields, in the scene's units (the analysis ran in `units`).
   subroutine write_body(h5, level, body, units, cell_type, bl, done, error)
      type(h5_output_type), intent(inout) :: h5
      integer, intent(in) :: level, cell_type
      character(len=*), intent(in) :: body
      type(analysis_units_type), intent(in) :: units
      type(body_level_type), intent(in) :: bl
      logical, intent(in) :: done(2)
      type(error_type), allocatable, intent(out) :: error
      character(len=4), parameter :: method_name(2) = ['spr ', 'sprc']
      real(wp), allocatable :: sigma_fe(:, :), work(:, :)
      real(wp) :: sunit, eunit
      integer, allocatable :: cls(:, :)
      integer :: m, stat

      call h5%write_level(level, bl%problem%mesh%nodes%x, bl%problem%mesh%nodes%connectivity, cell_type, error, body=body)
      if (allocated(error)) return
      ! stress unit modulus*strain; energy norm sqrt(sigma D^-1 sigma): sqrt(modulus)*strain
      sunit = units%modulus*units%strain
      eunit = sqrt(units%modulus)*units%strain
      call scaled(units%strain, bl%problem%u, work, error)
      if (allocated(error)) return
      call h5%write_node_field(level, 'displacement', work, error, body=body)
      if (allocated(error)) return
      call nodal_fe_stress(bl%problem, bl%problem%mesh%nodes, sigma_fe, error)
      if (allocated(error)) return
      sigma_fe = sunit*sigma_fe
      call write_stress('sigma_fe', sigma_fe, error)
      if (allocated(error)) return
      do m = 1, 2
         if (.not. done(m)) cycle
         call scaled(sunit, bl%field(m)%nodal, work, error)
         if (allocated(error)) return
         call write_stress('sigma_'//trim(method_name(m)), work, error)
         if (allocated(error)) return
         call scaled_row(eunit, bl%est(m)%elem_err2, .true., work, error)
         if (allocated(error)) return
         call h5%write_cell_field(level, 'zz_error_'//trim(method_name(m)), work, error, body=body)
         if (allocated(error)) return
      end do
      if (allocated(bl%element_error)) then
         call scaled_row(eunit, bl%element_error, .false., work, error)
         if (allocated(error)) return
         call h5%write_cell_field(level, 'exact_error_fe', work, error, body=body)
         if (allocated(error)) return
      end if
      allocate (cls(1, bl%problem%mesh%grid%n_leaves), stat=stat)
      call check_allocation(stat, who, 'the cut flag of each cell', bl%problem%mesh%grid%n_leaves, 4, error)
      if (allocated(error)) return
      cls(1, :) = merge(1, 0, bl%problem%mesh%grid%leaf_class(1:bl%problem%mesh%grid%n_leaves) == cell_cut)
      call h5%write_cell_field(level, 'cut', cls, error, body=body)
   contains
      subroutine write_stress(name, values, error)
         character(len=*), intent(in) :: name
         real(wp), intent(in) :: values(:, :)
         type(error_type), allocatable, intent(out) :: error
         character(len=2), parameter :: c2(3) = ['xx', 'yy', 'xy'], c3(6) = ['xx', 'yy', 'zz', 'xy', 'yz', 'xz']
         if (size(values, 1) == 3) then
            call h5%write_node_field(level, name, values, error, components=c2, body=body)
         else
            call h5%write_node_field(level, name, values, error, components=c3, body=body)
         end if
      end subroutine write_stress
   end subroutine write_body

   !> out = unit*values, `out` (re)allocated here with stat= (a field of one
   !> value per node or cell: sprc_core_alloc).
   subroutine scaled(unit, values, out, error)
      real(wp), intent(in) :: unit, values(:, :)
      real(wp), allocatable, intent(inout) :: out(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      if (allocated(out)) deallocate (out)
      allocate (out(size(values, 1), size(values, 2)), stat=stat)
      call check_allocation(stat, who, 'a field in the scene''s units', size(values, kind=i8), 8, error)
      if (allocated(error)) return
      out(:, :) = unit*values
   end subroutine scaled

   !> out(1, :) = unit*values, or unit*sqrt(values) when `root`: one value per
   !> cell or point as a field of one component, allocated as in `scaled`.
   subroutine scaled_row(unit, values, root, out, error)
      real(wp), intent(in) :: unit, values(:)
      logical, intent(in) :: root
      real(wp), allocatable, intent(inout) :: out(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      if (allocated(out)) deallocate (out)
      allocate (out(1, size(values)), stat=stat)
      call check_allocation(stat, who, 'a field in the scene''s units', size(values), 8, error)
      if (allocated(error)) return
      if (root) then
         out(1, :) = unit*sqrt(values)
      else
         out(1, :) = unit*values
      end if
   end subroutine scaled_row

end module sprc_io_fields
