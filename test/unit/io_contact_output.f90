!> Tests of the contact outputs: PREFIX_contact.csv read back cell by cell
!> (header as SCENE.md states it, values bit for bit, z empty in 2D, state
!> names, empty cells), PREFIX_contact.svg well-formed with its series and
!> points in order along the surface. The HDF5 point sets are tested with
!> the other HDF5 output (sprc_test_output). Files go to build/.
module sprc_test_contact_output
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_io
   use sprc_core_text, only: itoa
   use sprc_contact_result, only: contact_result_type, new_contact_result, contact_stick
   use sprc_io_contact_csv, only: contact_level_type, contact_csv_header, write_contact_csv
   use sprc_io_svg, only: write_contact_svg, contact_svg
   use sprc_study_row, only: is_empty
   use sprc_test_contact_model, only: contact_sample
   use sprc_test_report, only: xml_well_formed, read_text_file, attribute_real, cell_of, count_sub, split_lines
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_contact_output, contact_sample_3d

   character(len=*), parameter :: dir = 'build/'

contains

   subroutine collect_contact_output(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('csv_read_back', test_csv_read_back), &
         new_unittest('csv_3d_z', test_csv_3d), &
         new_unittest('csv_unwritable_path', test_csv_unwritable), &
         new_unittest('svg_well_formed_series', test_svg_series), &
         new_unittest('svg_points_in_order', test_svg_order), &
         new_unittest('svg_3d_and_empty', test_svg_3d_empty), &
         new_unittest('svg_many_points', test_svg_many_points), &
         new_unittest('svg_loaded_window', test_svg_window), &
         new_unittest('svg_zoom_on_closed_points', test_svg_zoom), &
         new_unittest('svg_unwritable_path', test_svg_unwritable) &
         ]
   end subroutine collect_contact_output

   !> Two levels of the 2D sample (level 3, then level 4 with other gaps):
   !> 1 header + 2 x 4 lines; every cell of every line against the results.
   subroutine test_csv_read_back(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = dir//'test_contact.csv'
      ! SCENE.md's columns, then the trailing signed tangential traction, the pair and the
      ! FE-stress pressure (extensions).
      character(len=*), parameter :: contract = 'level,x,y,z,weight,gap,state,p_fe,p_spr,p_sprc,p_exact,ts_fe,ts_sprc,'// &
         & 'tx_fe,ty_fe,tz_fe,pair,p_fe_stress'
      type(contact_level_type) :: levels(2)
      character(len=:), allocatable :: text
      character(len=400) :: lines(10)
      integer :: n, l, k, i, row

      levels(1) = contact_level_type(3, contact_sample())
      levels(2) = contact_level_type(4, contact_sample())
      levels(2)%contacts(1)%gap(1) = 1.0_wp/3.0_wp
      levels(2)%contacts(1)%ts_sprc = [0.1_wp, tiny(1.0_wp)/3.0_wp, -0.0_wp]
      levels(2)%contacts(1)%t_fe(:, 1) = [0.25_wp, -1.0_wp/3.0_wp]
      call write_contact_csv(path, levels, error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call split_lines(text, lines, n)
      call check(error, n, 9, 'header + 2 levels x 4 points')
      if (allocated(error)) return
      ! Copied from SCENE.md, independently of the module's constant.
      call check(error, trim(lines(1)), contract, 'header')
      if (allocated(error)) return
      call check(error, contact_csv_header, contract, 'contact_csv_header')
      if (allocated(error)) return
      row = 1
      do l = 1, 2
         do k = 1, 2
            do i = 1, levels(l)%contacts(k)%npoint
               row = row + 1
               call check_line(trim(lines(row)), levels(l)%level, levels(l)%contacts(k), i, error)
               if (allocated(error)) return
               call check(error, cell_of(trim(lines(row)), 17), itoa(k), 'line '//itoa(row)//': pair')
               if (allocated(error)) return
               call check_cell(cell_of(trim(lines(row)), 18), levels(l)%contacts(k)%p_fe_stress(i), &
                  & 'line '//itoa(row)//': p_fe_stress', error)
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_csv_read_back

   !> Every cell of one CSV line against slave point i of `c`.
   subroutine check_line(line, level, c, i, error)
      character(len=*), intent(in) :: line
      integer, intent(in) :: level, i
      type(contact_result_type), intent(in) :: c
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: states(0:2) = [character(len=5) :: 'open', 'stick', 'slip']
      character(len=:), allocatable :: where
      integer :: j

      where = 'line of level '//itoa(level)//' point '//itoa(i)//': '
      call check(error, count_sub(line, ','), 17, where//'18 cells')
      if (allocated(error)) return
      call check(error, cell_of(line, 1), itoa(level), where//'level')
      if (allocated(error)) return
      if (c%dim == 2) then
         call check(error, cell_of(line, 4), '', where//'z empty in 2D')
         if (allocated(error)) return
      end if
      call check(error, cell_of(line, 7), trim(states(c%state(i))), where//'state')
      if (allocated(error)) return
      do j = 1, c%dim
         call check_cell(cell_of(line, 1 + j), c%x(j, i), where//'coordinate '//itoa(j), error)
         if (allocated(error)) return
      end do
      call check_cell(cell_of(line, 5), c%weight(i), where//'weight', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 6), c%gap(i), where//'gap', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 8), c%p_fe(i), where//'p_fe', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 9), c%p_spr(i), where//'p_spr', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 10), c%p_sprc(i), where//'p_sprc', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 11), c%p_exact(i), where//'p_exact', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 12), c%ts_fe(i), where//'ts_fe', error)
      if (allocated(error)) return
      call check_cell(cell_of(line, 13), c%ts_sprc(i), where//'ts_sprc', error)
      do j = 1, c%dim
         if (allocated(error)) return
         call check_cell(cell_of(line, 13 + j), c%t_fe(j, i), where//'t_fe '//itoa(j), error)
      end do
      if (allocated(error) .or. c%dim == 3) return
      call check(error, cell_of(line, 16), '', where//'tz_fe empty in 2D')
   end subroutine check_line

   !> A cell is empty for an empty value, else it reads back to the same bits.
   subroutine check_cell(cell, x, what, error)
      character(len=*), intent(in) :: cell, what
      real(wp), intent(in) :: x
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: y
      integer :: stat

      if (is_empty(x)) then
         call check(error, cell, '', what//' empty')
         return
      end if
      read (cell, '(f64.0)', iostat=stat) y
      if (stat /= 0) then
         call test_failed(error, what//': cannot read "'//cell//'"')
         return
      end if
      call check(error, transfer(x, 1_i8) == transfer(y, 1_i8), what//' bit for bit ("'//cell//'")')
   end subroutine check_cell

   !> 3D: z is written; a stick point.
   subroutine test_csv_3d(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = dir//'test_contact_3d.csv'
      type(contact_level_type) :: levels(1)
      character(len=:), allocatable :: text
      character(len=400) :: lines(4)
      integer :: n, i

      levels(1) = contact_level_type(2, [contact_sample_3d()])
      call write_contact_csv(path, levels, error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call split_lines(text, lines, n)
      call check(error, n, 4, 'header + 3 points')
      if (allocated(error)) return
      do i = 1, 3
         call check_line(trim(lines(i + 1)), 2, levels(1)%contacts(1), i, error)
         if (allocated(error)) return
      end do
   end subroutine test_csv_3d

   subroutine test_csv_unwritable(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      character(len=*), parameter :: path = dir//'no_such_directory/contact.csv'

      call write_contact_csv(path, [contact_level_type(1, contact_sample())], err)
      call expect_io_error(error, err, path)
   end subroutine test_csv_unwritable

   !> The 2D sample: well-formed, the FE, SPR-C and exact series (SPR was not
   !> run: absent), one marker per point of FE and SPR-C, the exact one a line.
   subroutine test_svg_series(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = dir//'test_contact.svg'
      character(len=:), allocatable :: text, msg

      call write_contact_svg(path, contact_sample(), 'contact <2D> & "sample"', error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, 'contact &lt;2D&gt; &amp; &quot;sample&quot;') > 0, 'title escaped')
      if (allocated(error)) return
      call check(error, index(text, '>p_fe</text>') > 0 .and. index(text, '>p_sprc</text>') > 0 .and. &
         & index(text, '>p_exact</text>') > 0, 'FE, SPR-C and exact in the legend')
      if (allocated(error)) return
      call check(error, index(text, 'p_spr"') == 0 .and. index(text, '>p_spr</text>') == 0, 'SPR not run: absent')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point p_fe"'), 4, 'a marker per FE point')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point p_sprc"'), 4, 'a marker per SPR-C point')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="line p_exact"'), 1, 'the exact pressure a line')
      if (allocated(error)) return
      call check(error, index(text, 'arc length along the slave surface') > 0, '2D abscissa')
      if (allocated(error)) return
      call check(error, index(text, 'NaN') == 0 .and. index(text, 'nan') == 0, 'no NaN')
      if (allocated(error)) return
      call check(error, index(text, '>1</text>') > 0 .and. index(text, '>1.</text>') == 0, 'integral tick labels')
   end subroutine test_svg_series

   !> The sample's points lie on y = 1 at x = 0, 0.5, 1 (pair 1) and 2 (pair 2):
   !> the FE markers come out left to right at pixel steps proportional to
   !> those distances, and higher pressure is higher up (smaller y).
   subroutine test_svg_order(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type), allocatable :: contacts(:)
      character(len=:), allocatable :: text
      real(wp) :: cx(4), cy(4)
      integer :: k, pos, i

      contacts = contact_sample()
      ! listed out of order: the plot sorts them
      contacts(1)%x(1, :) = [1.0_wp, 0.0_wp, 0.5_wp]
      contacts(1)%p_fe = [0.0_wp, 2.0_wp, 1.0_wp]
      call contact_svg(contacts, 'order', text, error)
      if (allocated(error)) return
      pos = 1
      do k = 1, 4
         i = index(text(pos:), 'class="point p_fe"')
         call check(error, i > 0, 'FE marker '//itoa(k))
         if (allocated(error)) return
         pos = pos + i
         cx(k) = attribute_real(text(pos:), 'cx')
         cy(k) = attribute_real(text(pos:), 'cy')
      end do
      call check(error, all(cx(2:) > cx(:3)), 'left to right')
      if (allocated(error)) return
      call check(error, (cx(4) - cx(3)) - 2*(cx(3) - cx(2)), 0.0_wp, 0.05_wp, 'x steps proportional to distance')
      if (allocated(error)) return
      ! p_fe in order of x: 2, 1, 0, 4
      call check(error, cy(4) < cy(1) .and. cy(1) < cy(2) .and. cy(2) < cy(3), 'pressure grows upwards')
      if (allocated(error)) return
      call check(error, (cy(3) - cy(2)) - (cy(2) - cy(1)), 0.0_wp, 0.05_wp, 'linear pressure axis')
   end subroutine test_svg_order

   !> 3D: markers only (no lines), against the distance from the peak; no
   !> pairs at all: a valid picture saying so.
   subroutine test_svg_3d_empty(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type) :: none(0)
      character(len=:), allocatable :: text, msg

      call contact_svg([contact_sample_3d()], '3D', text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), '3D SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, '<polyline') == 0, 'no lines through a surface')
      if (allocated(error)) return
      ! The open point, 0.3 from the peak, lies beyond the closed points' stretch (0.1) and its quarter.
      call check(error, count_sub(text, 'class="point p_fe"'), 2, 'a marker per FE point of the contact zone')
      if (allocated(error)) return
      call check(error, index(text, 'distance from the point of peak pressure') > 0, '3D abscissa')
      if (allocated(error)) return
      call contact_svg(none, 'empty', text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'empty SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, 'no data') > 0, 'says no data')
   end subroutine test_svg_3d_empty

   !> 20000 slave points (a fine 3D level): at most 2000 markers per series,
   !> every 10th point; the exact series (no markers) still a polyline in 2D.
   subroutine test_svg_many_points(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type) :: c(1)
      character(len=:), allocatable :: text, msg
      real(wp), allocatable :: x(:, :)
      integer :: i, n

      n = 20000
      allocate (x(2, n))
      x(1, :) = [(real(i, wp)/n, i=1, n)]
      x(2, :) = 0.0_wp
      call new_contact_result(c(1), x, spread(1.0_wp/n, 1, n), spread([0.0_wp, -1.0_wp], 2, n), 1, 2, error)
      if (allocated(error)) return
      c(1)%p_fe = 1.0_wp - x(1, :)**2
      c(1)%p_exact = 1.0_wp - x(1, :)**2
      call contact_svg(c, 'many', text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point p_fe"'), 2000, 'every 10th FE point')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="line p_exact"'), 1, 'the exact line')
   end subroutine test_svg_many_points

   !> A Hertz-like load on phi < 0.1 of a quarter circle (101 points 0.01
   !> apart in angle): loaded are the points 0 .. 0.09, so the plot shows
   !> s <= 0.09 + 0.09/4 (points 0 .. 0.11: 12 markers); the abscissa is the
   !> arc length, so equal angle steps are equal pixel steps.
   subroutine test_svg_window(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type) :: c(1)
      character(len=:), allocatable :: text
      real(wp) :: x(2, 101), phi(101), cx(12)
      integer :: i, pos, k

      phi = [(0.01_wp*(i - 1), i=1, 101)]
      x(1, :) = sin(phi)
      x(2, :) = 1.0_wp - cos(phi)
      call new_contact_result(c(1), x, spread(0.01_wp, 1, 101), x, 1, 2, error)
      if (allocated(error)) return
      c(1)%p_fe = merge(1.0_wp - (phi/0.1_wp)**2, 0.0_wp, phi < 0.1_wp)
      call contact_svg(c, 'window', text, error)
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point p_fe"'), 12, 'markers of the loaded stretch and margins')
      if (allocated(error)) return
      pos = 1
      do k = 1, 12
         i = index(text(pos:), 'class="point p_fe"')
         pos = pos + i
         cx(k) = attribute_real(text(pos:), 'cx')
      end do
      call check(error, (cx(12) - cx(11)) - (cx(2) - cx(1)), 0.0_wp, 0.05_wp, 'arc length abscissa')
   end subroutine test_svg_window

   !> The contact plot zooms on the closed points: the quarter circle of
   !> test_svg_window closed (stick) on phi < 0.1, the recovered pressure
   !> smeared over the whole surface (above 1e-3 of the peak everywhere). The
   !> plot keeps the closed stretch s <= 0.09 and a quarter of it (points
   !> 0 .. 0.11: 12 markers per series); the abscissa, 0 .. 0.11 in steps of
   !> 0.05 (about five steps), ends at 0.15.
   subroutine test_svg_zoom(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_result_type) :: c(1)
      character(len=:), allocatable :: text
      real(wp) :: x(2, 101), phi(101), cx
      integer :: i, pos

      phi = [(0.01_wp*(i - 1), i=1, 101)]
      x(1, :) = sin(phi)
      x(2, :) = 1.0_wp - cos(phi)
      call new_contact_result(c(1), x, spread(0.01_wp, 1, 101), x, 1, 2, error)
      if (allocated(error)) return
      c(1)%p_fe = merge(1.0_wp - (phi/0.1_wp)**2, 0.0_wp, phi < 0.1_wp)
      c(1)%p_spr = c(1)%p_fe + 0.01_wp
      where (phi < 0.1_wp) c(1)%state = contact_stick
      call contact_svg(c, 'zoom', text, error)
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point p_fe"'), 12, 'FE markers of the contact zone and margins')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point p_spr"'), 12, 'SPR markers of the contact zone and margins')
      if (allocated(error)) return
      call check(error, index(text, '>0.15</text>') > 0 .and. index(text, '>0.20</text>') == 0, &
         & 'abscissa ends at 0.15')
      if (allocated(error)) return
      pos = index(text, 'class="point p_spr"', back=.true.)
      cx = attribute_real(text(pos:), 'cx')
      call check(error, cx <= 975.0_wp, 'last SPR marker inside the panel')
   end subroutine test_svg_zoom

   subroutine test_svg_unwritable(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      character(len=*), parameter :: path = dir//'no_such_directory/contact.svg'

      call write_contact_svg(path, contact_sample(), 'x', err)
      call expect_io_error(error, err, path)
   end subroutine test_svg_unwritable

   !> One 3D pair of three points: open, stick and slip, every value set.
   function contact_sample_3d() result(c)
      type(contact_result_type) :: c
      real(wp) :: x(3, 3), normal(3, 3)
      integer :: i
      type(error_type), allocatable :: error

      x = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.1_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.3_wp, 1.0_wp], [3, 3])
      normal = spread([0.0_wp, 0.0_wp, -1.0_wp], 2, 3)
      call new_contact_result(c, x, [0.01_wp, 0.02_wp, 0.03_wp], normal, 1, 2, error)
      c%state = [2, contact_stick, 0]
      c%gap = [-1.0e-5_wp, 0.0_wp, 1.0e-3_wp]
      c%p_fe = [3.0_wp, 2.0_wp, 0.0_wp]
      c%p_spr = [2.9_wp, 2.1_wp, 0.1_wp]
      c%p_sprc = [3.05_wp, 1.95_wp, 0.0_wp]
      c%p_exact = [3.0_wp, 2.0_wp, 0.0_wp]
      c%ts_fe = [(0.1_wp*i, i=1, 3)]
      c%t_fe = reshape([(-0.01_wp*i, i=1, 9)], [3, 3])
      c%ts_sprc = [(0.11_wp*i, i=1, 3)]
   end function contact_sample_3d

   subroutine expect_io_error(error, err, part)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable, intent(in) :: err
      character(len=*), intent(in) :: part

      if (.not. allocated(err)) then
         call test_failed(error, 'expected an error naming "'//part//'"')
         return
      end if
      call check(error, err%stat == stat_io .and. index(err%message, part) > 0, 'stat_io naming the path: '// &
         & err%message)
   end subroutine expect_io_error

end module sprc_test_contact_output
