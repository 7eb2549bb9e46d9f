!> `PREFIX_contact.csv` (doc/scene.md "The report"): one row per slave-surface
!> quadrature point and level,
!> `level,x,y,z,weight,gap,state,p_fe,p_spr,p_sprc,p_exact,ts_fe,ts_sprc`,
!> then (trailing) `tx_fe,ty_fe,tz_fe`, the FE
!> tangential traction on the slave body as a vector (`tz_fe` empty in 2D),
!> `pair`, the point's `&contact` pair (1-based, scene order), and
!> `p_fe_stress`, the pressure -n.sigma_h.n of the slave's FE stresses,
!> reals as in the report CSV (read back bit for bit), `z` empty in
!> 2D, `state` open / stick / slip, an empty value (not computed) an empty
!> cell. The pairs of a level follow each other in `&contact` order.
module sprc_io_contact_csv
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_io
   use sprc_contact_result, only: contact_result_type, state_name
   use sprc_io_report, only: csv_real
   implicit none
   private

   public :: contact_level_type, contact_csv_header, write_contact_csv

   !> The CSV header: doc/scene.md's columns, then the signed tangential traction, the pair
   !> and the pressure of the slave's FE stresses.
   character(len=*), parameter :: contact_csv_header = 'level,x,y,z,weight,gap,state,p_fe,p_spr,p_sprc,p_exact,'// &
      & 'ts_fe,ts_sprc,tx_fe,ty_fe,tz_fe,pair,p_fe_stress'

   !> The contact results of one level of a study.
   type :: contact_level_type
      integer :: level = 0
      type(contact_result_type), allocatable :: contacts(:)
   end type contact_level_type

contains

   !> Write every slave point of every level to `path` (replacing it). Fails
   !> with stat_io naming the path.
   subroutine write_contact_csv(path, levels, error)
      character(len=*), intent(in) :: path
      type(contact_level_type), intent(in) :: levels(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat, l, k, i
      character(len=256) :: msg

      open (newunit=unit, file=path, status='replace', action='write', form='formatted', iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, 'contact CSV: cannot open "'//path//'" for writing: '//trim(msg), stat_io)
         return
      end if
      write (unit, '(a)', iostat=stat, iomsg=msg) contact_csv_header
      do l = 1, size(levels)
         if (.not. allocated(levels(l)%contacts)) cycle
         do k = 1, size(levels(l)%contacts)
            do i = 1, levels(l)%contacts(k)%npoint
               if (stat /= 0) exit
               write (unit, '(a)', iostat=stat, iomsg=msg) point_line(levels(l)%level, levels(l)%contacts(k), i)// &
                  & ','//itoa(k)//','//csv_real(levels(l)%contacts(k)%p_fe_stress(i))
            end do
         end do
      end do
      if (stat /= 0) then
         close (unit)
         call fatal_error(error, 'contact CSV: cannot write "'//path//'": '//trim(msg), stat_io)
         return
      end if
      close (unit, iostat=stat, iomsg=msg)
      if (stat /= 0) call fatal_error(error, 'contact CSV: cannot close "'//path//'": '//trim(msg), stat_io)
   end subroutine write_contact_csv

   !> The CSV line of slave point i of `c` at `level`.
   function point_line(level, c, i) result(line)
      integer, intent(in) :: level, i
      type(contact_result_type), intent(in) :: c
      character(len=:), allocatable :: line
      character(len=:), allocatable :: z, tz

      z = ''
      tz = ''
      if (c%dim == 3) then
         z = csv_real(c%x(3, i))
         tz = csv_real(c%t_fe(3, i))
      end if
      line = itoa(level)//','//csv_real(c%x(1, i))//','//csv_real(c%x(2, i))//','//z//','// &
         & csv_real(c%weight(i))//','//csv_real(c%gap(i))//','//state_name(c%state(i))//','// &
         & csv_real(c%p_fe(i))//','//csv_real(c%p_spr(i))//','//csv_real(c%p_sprc(i))//','// &
         & csv_real(c%p_exact(i))//','//csv_real(c%ts_fe(i))//','//csv_real(c%ts_sprc(i))//','// &
         & csv_real(c%t_fe(1, i))//','//csv_real(c%t_fe(2, i))//','//tz
   end function point_line

end module sprc_io_contact_csv
