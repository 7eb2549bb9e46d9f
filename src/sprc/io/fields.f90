!> The fields of one study level in the HDF5 output (layout in
!> `sprc_io_xdmf`): per body, under `/level_LL/<body>/`, its mesh,
!> displacement, FE nodal stresses (average of the elements at each node),
!> recovered nodal stresses, element error indicators (ZZ per method; exact
!> where known) and cell class.
module sprc_io_fields
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_geometry_region, only: cell_cut
   use sprc_study_level, only: study_type, level_type, body_level_type, nodal_fe_stress
   use sprc_study_model, only: analysis_units_type
   use sprc_io_hdf5, only: h5_output_type
   use sprc_io_xdmf, only: cell_quad4, cell_quad9, cell_hex8, cell_hex27
   implicit none
   private

   public :: write_level_fields

contains

   !> Write every body of `result` (a level of `study`) into `h5`.
   subroutine write_level_fields(h5, study, result, error)
      type(h5_output_type), intent(inout) :: h5
      type(study_type), intent(in) :: study
      type(level_type), intent(in) :: result
      type(error_type), allocatable, intent(out) :: error
      integer :: cell_type, b

      if (study%dim == 2) then
         cell_type = merge(cell_quad4, cell_quad9, study%order == 1)
      else
         cell_type = merge(cell_hex8, cell_hex27, study%order == 1)
      end if
      do b = 1, size(result%bodies)
         call write_body(h5, result%level, study%bodies(b)%name, study%bodies(b)%units, cell_type, &
            & result%bodies(b), result%done, error)
         if (allocated(error)) return
      end do
   end subroutine write_level_fields

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
      real(wp), allocatable :: sigma_fe(:, :), elem(:, :)
      real(wp) :: sunit, eunit
      integer, allocatable :: cls(:, :)
      integer :: m

      call h5%write_level(level, bl%nodes%x, bl%nodes%connectivity, cell_type, error, body=body)
      if (allocated(error)) return
      ! stress unit modulus*strain; energy norm sqrt(sigma D^-1 sigma): sqrt(modulus)*strain
      sunit = units%modulus*units%strain
      eunit = sqrt(units%modulus)*units%strain
      call h5%write_node_field(level, 'displacement', units%strain*bl%problem%u, error, body=body)
      if (allocated(error)) return
      call nodal_fe_stress(bl%problem, bl%nodes, sigma_fe)
      call write_stress('sigma_fe', sunit*sigma_fe, error)
      if (allocated(error)) return
      do m = 1, 2
         if (.not. done(m)) cycle
         call write_stress('sigma_'//trim(method_name(m)), sunit*bl%field(m)%nodal, error)
         if (allocated(error)) return
         elem = reshape(eunit*sqrt(bl%est(m)%elem_err2), [1, size(bl%est(m)%elem_err2)])
         call h5%write_cell_field(level, 'zz_error_'//trim(method_name(m)), elem, error, body=body)
         if (allocated(error)) return
      end do
      if (allocated(bl%element_error)) then
         elem = reshape(eunit*bl%element_error, [1, size(bl%element_error)])
         call h5%write_cell_field(level, 'exact_error_fe', elem, error, body=body)
         if (allocated(error)) return
      end if
      allocate (cls(1, bl%grid%n_leaves))
      cls(1, :) = merge(1, 0, bl%grid%leaf_class(1:bl%grid%n_leaves) == cell_cut)
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

end module sprc_io_fields
