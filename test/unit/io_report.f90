!> Tests of the study report: CSV contract and bitwise round trip, table
!> layout, SVG plot. Also holds the small XML well-formedness checker that
!> the output tests reuse for the XDMF file. Files go to build/.
module sprc_test_report
   use sprc_core_text, only: lower, itoa
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_io, stat_invalid_input
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   use sprc_io_report, only: report_row_type, report_table, write_report_csv, read_report_csv, &
      & report_column, report_empty, is_empty, report_csv_header, report_columns, n_report_columns, &
      & report_column_indices
   use sprc_io_svg, only: write_report_svg, report_svg
   implicit none
   private

   public :: collect_report, xml_well_formed, read_text_file, python_xml_check, attribute_real, cell_of, count_sub, &
      & split_lines

   character(len=*), parameter :: dir = 'build/'

contains

   subroutine collect_report(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('csv_header_exact', test_csv_header), &
         new_unittest('csv_header_contact', test_csv_header_contact), &
         new_unittest('csv_round_trip_bitwise', test_csv_round_trip), &
         new_unittest('csv_round_trip_contact', test_csv_round_trip_contact), &
         new_unittest('csv_read_contract_columns_only', test_csv_read_base_only), &
         new_unittest('csv_empty_cells_empty', test_csv_empty_cells), &
         new_unittest('csv_no_rows', test_csv_no_rows), &
         new_unittest('csv_unwritable_path', test_csv_unwritable), &
         new_unittest('csv_read_missing_file', test_csv_read_missing), &
         new_unittest('csv_read_bad_header', test_csv_read_bad_header), &
         new_unittest('csv_read_bad_value', test_csv_read_bad_value), &
         new_unittest('csv_read_short_line', test_csv_read_short_line), &
         new_unittest('column_access', test_column_access), &
         new_unittest('table_levels_aligned', test_table), &
         new_unittest('table_contact_columns', test_table_contact), &
         new_unittest('table_significant_digits', test_table_digits), &
         new_unittest('table_compact_default', test_table_compact), &
         new_unittest('table_compact_adaptive', test_table_compact_adaptive), &
         new_unittest('xml_checker_rejects_bad', test_xml_checker), &
         new_unittest('svg_well_formed', test_svg_well_formed), &
         new_unittest('svg_log_scale_positions', test_svg_positions), &
         new_unittest('svg_time_axis_cumulative', test_svg_cumulative_time), &
         new_unittest('svg_reference_slope', test_svg_reference_slope), &
         new_unittest('svg_omits_empty_columns', test_svg_omits_empty), &
         new_unittest('svg_single_row', test_svg_single_row), &
         new_unittest('svg_non_positive_skipped', test_svg_non_positive), &
         new_unittest('svg_escapes_title', test_svg_title_escaped), &
         new_unittest('svg_unwritable_path', test_svg_unwritable) &
         ]
   end subroutine collect_report

   !> Three levels of a made-up study with an exact solution: every column set,
   !> values chosen to exercise rounding (1/3, 0.1) and extreme exponents.
   function sample_rows() result(rows)
      type(report_row_type) :: rows(3)
      integer :: i
      do i = 1, 3
         rows(i)%level = i + 1
         rows(i)%h = 1.0_wp/2.0_wp**(i + 1)
         rows(i)%elements = 4_i8**(i + 1)
         rows(i)%cut_elements = 2_i8**(i + 1)
         rows(i)%dofs = 2_i8*(2_i8**(i + 1) + 1)**2
         rows(i)%t_mesh = 1.0e-4_wp*i
         rows(i)%t_quadrature = 1.0_wp/3.0_wp*10.0_wp**(i - 3)
         rows(i)%t_assembly = 0.1_wp*i
         rows(i)%t_solve = 12.345678_wp*i
         rows(i)%t_recovery = 1.0e-300_wp
         rows(i)%t_estimate = tiny(1.0_wp)/3.0_wp ! subnormal
         rows(i)%t_total = 10.0_wp**i
         rows(i)%err_fe = 0.1_wp/2.0_wp**i
         rows(i)%err_spr = 0.05_wp/4.0_wp**i
         rows(i)%err_sprc = 0.04_wp/4.0_wp**i
         rows(i)%eta_spr = 0.09_wp/2.0_wp**i
         rows(i)%eta_sprc = 0.095_wp/2.0_wp**i
         rows(i)%theta_spr = 0.9_wp
         rows(i)%theta_sprc = huge(1.0_wp)
      end do
      rows(2)%theta_spr = -0.0_wp
   end function sample_rows

   !> The sample rows of a study with contact: every contact column set (a
   !> Krylov solve, so solver_iterations too), err_p_spr empty in row 1.
   function contact_rows() result(rows)
      type(report_row_type) :: rows(3)
      integer :: i
      rows = sample_rows()
      do i = 1, 3
         rows(i)%has_contact = .true.
         rows(i)%contact_iterations = 3*i + 1
         rows(i)%t_contact = 0.25_wp*i
         rows(i)%contact_measure = 1.0_wp/3.0_wp + i
         rows(i)%p_max_fe = 1.1e-4_wp*i
         rows(i)%p_max_spr = 1.2e-4_wp*i
         rows(i)%p_max_sprc = 1.3e-4_wp*i
         rows(i)%p_max_exact = 1.080247e-4_wp
         rows(i)%err_p_fe = 0.1_wp/3.0_wp**i
         rows(i)%err_p_spr = 0.2_wp/3.0_wp**i
         rows(i)%err_p_sprc = 0.3_wp/3.0_wp**i
         rows(i)%p_max_fe_stress = 1.4e-4_wp*i
         rows(i)%err_p_fe_stress = 0.4_wp/3.0_wp**i
         rows(i)%jump_fe = 0.5_wp/7.0_wp**i
         rows(i)%jump_spr = 0.6_wp/7.0_wp**i
         rows(i)%jump_sprc = 0.7_wp/7.0_wp**i
         rows(i)%solver_iterations = 100*i + 7
      end do
      rows(1)%err_p_spr = report_empty
   end function contact_rows

   !> Rows without an exact solution: err_* and theta_* empty.
   function no_exact_rows() result(rows)
      type(report_row_type) :: rows(3)
      rows = sample_rows()
      rows%err_fe = report_empty
      rows%err_spr = report_empty
      rows%err_sprc = report_empty
      rows%theta_spr = report_empty
      rows%theta_sprc = report_empty
   end function no_exact_rows

   subroutine test_csv_header(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      character(len=*), parameter :: path = dir//'test_report_header.csv'
      character(len=*), parameter :: contract = 'level,h,elements,cut_elements,dofs,t_mesh,t_quadrature,'// &
         't_assembly,t_solve,t_recovery,t_estimate,t_total,err_fe,err_spr,err_sprc,eta_spr,eta_sprc,'// &
         'theta_spr,theta_sprc'

      call write_report_csv(path, sample_rows(), error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      ! The header is copied from SCENE.md, independently of the module's constant:
      ! the columns of every report, then (no contact) solver_iterations.
      call check(error, text(1:index(text, new_line('a')) - 1), contract//',solver_iterations', 'CSV header line')
      if (allocated(error)) return
      call check(error, report_csv_header, contract, 'report_csv_header')
      if (allocated(error)) return
      call check(error, count_char(text, new_line('a')), 4, 'header + 3 rows')
   end subroutine test_csv_header

   !> A study with contact: the contact columns of SCENE.md after theta_sprc,
   !> then solver_iterations; integers printed as integers.
   subroutine test_csv_header_contact(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, line
      character(len=*), parameter :: path = dir//'test_report_header_contact.csv'
      character(len=*), parameter :: contract = 'level,h,elements,cut_elements,dofs,t_mesh,t_quadrature,'// &
         't_assembly,t_solve,t_recovery,t_estimate,t_total,err_fe,err_spr,err_sprc,eta_spr,eta_sprc,'// &
         'theta_spr,theta_sprc,'// &
         'contact_iterations,t_contact,contact_measure,p_max_fe,p_max_spr,p_max_sprc,p_max_exact,err_p_fe,'// &
         'err_p_spr,err_p_sprc,p_max_fe_stress,err_p_fe_stress,jump_fe,jump_spr,jump_sprc,solver_iterations'

      call write_report_csv(path, contact_rows(), error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, text(1:index(text, new_line('a')) - 1), contract, 'CSV header line')
      if (allocated(error)) return
      line = text(index(text, new_line('a')) + 1:)
      line = line(:index(line, new_line('a')) - 1)
      call check(error, count_char(line, ','), 34, 'every row has 35 cells')
      if (allocated(error)) return
      call check(error, cell_of(line, 20), '4', 'contact_iterations an integer')
      if (allocated(error)) return
      call check(error, cell_of(line, 28), '', 'err_p_spr empty')
      if (allocated(error)) return
      call check(error, cell_of(line, 35), '107', 'solver_iterations an integer (last cell)')
   end subroutine test_csv_header_contact

   !> Every column of a study with contact reads back bit for bit, and the rows
   !> read back have contact.
   subroutine test_csv_round_trip_contact(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      type(report_row_type), allocatable :: back(:)

      rows = contact_rows()
      call check_round_trip(rows, dir//'test_report_round_trip_contact.csv', back, error)
      if (allocated(error)) return
      call check(error, all(back%has_contact), 'rows read back have contact')
      if (allocated(error)) return
      call check(error, all(back%solver_iterations == rows%solver_iterations) .and. &
         & all(back%contact_iterations == rows%contact_iterations), 'iteration counts')
   end subroutine test_csv_round_trip_contact

   !> A file with only the 19 columns of every report (an older sprc) reads:
   !> no contact, solver_iterations 0; an unknown further column is ignored.
   subroutine test_csv_read_base_only(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = dir//'test_report_base_only.csv'
      character(len=*), parameter :: nl = new_line('a')

      call write_text_file(path, report_csv_header//',future_column'//nl//'1,0.5,4,0,18,,,,,,,,0.25,,,,,,,x'//nl, &
         & error)
      if (allocated(error)) return
      call read_report_csv(path, back, error)
      if (allocated(error)) return
      call check(error, size(back), 1, 'one row')
      if (allocated(error)) return
      call check(error, .not. back(1)%has_contact .and. back(1)%solver_iterations == 0 .and. &
         & .not. (abs(back(1)%err_fe - 0.25_wp) > 0.0_wp) .and. back(1)%dofs == 18, 'row read by the header names')
      if (allocated(error)) return
      call check(error, all(is_empty(report_column(back, 'p_max_fe'))), 'contact column empty without contact')
   end subroutine test_csv_read_base_only

   subroutine test_csv_round_trip(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type), allocatable :: back(:)

      call check_round_trip(sample_rows(), dir//'test_report_round_trip.csv', back, error)
      if (allocated(error)) return
      call check(error, transfer(back(2)%theta_spr, 1_i8) == transfer(-0.0_wp, 1_i8), 'negative zero kept')
   end subroutine test_csv_round_trip

   !> Write `rows` to `path` and read them back: every column bit for bit.
   subroutine check_round_trip(rows, path, back, error)
      type(report_row_type), intent(in) :: rows(3)
      character(len=*), intent(in) :: path
      type(report_row_type), allocatable, intent(out) :: back(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i, j
      real(wp) :: a(3), b(3)

      call write_report_csv(path, rows, error)
      if (allocated(error)) return
      call read_report_csv(path, back, error)
      if (allocated(error)) return
      call check(error, size(back), 3, 'rows read back')
      if (allocated(error)) return
      do j = 1, n_report_columns
         a = report_column(rows, trim(report_columns(j)))
         b = report_column(back, trim(report_columns(j)))
         do i = 1, 3
            ! Bitwise: 17 significant digits identify every double, subnormals and -0 included.
            if (transfer(a(i), 1_i8) /= transfer(b(i), 1_i8)) then
               call test_failed(error, 'column '//trim(report_columns(j))//' row '//itoa(i)//' differs in bits')
               return
            end if
         end do
      end do
   end subroutine check_round_trip

   subroutine test_csv_empty_cells(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      type(report_row_type), allocatable :: back(:)
      character(len=:), allocatable :: text, line
      character(len=*), parameter :: path = dir//'test_report_empty.csv'
      integer :: i, pos

      rows = no_exact_rows()
      rows(3)%t_recovery = report_empty
      call write_report_csv(path, rows, error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, index(lower(text), 'nan') == 0, 'no NaN anywhere in the CSV')
      if (allocated(error)) return
      ! Second data line: columns 13..15 and 18..19 empty, then solver_iterations.
      pos = index(text, new_line('a'))
      do i = 1, 2
         line = text(pos + 1:)
         line = line(:index(line, new_line('a')) - 1)
         pos = pos + len(line) + 1
      end do
      call check(error, count_char(line, ','), 19, 'every row has 20 cells')
      if (allocated(error)) return
      call check(error, cell_of(line, 13), '', 'err_fe empty')
      if (allocated(error)) return
      call check(error, cell_of(line, 19), '', 'theta_sprc empty')
      if (allocated(error)) return
      call check(error, cell_of(line, 20), '0', 'solver_iterations 0 (a direct solve; last cell)')
      if (allocated(error)) return
      call check(error, len(cell_of(line, 16)) > 0, 'eta_spr present')
      if (allocated(error)) return
      call read_report_csv(path, back, error)
      if (allocated(error)) return
      call check(error, all(is_empty(report_column(back, 'err_fe'))), 'err_fe read back empty')
      if (allocated(error)) return
      call check(error, is_empty(back(3)%t_recovery) .and. .not. is_empty(back(2)%t_recovery), &
         't_recovery empty only in row 3')
      if (allocated(error)) return
      call check(error, .not. any(is_empty(report_column(back, 'eta_sprc'))), 'eta_sprc read back present')
   end subroutine test_csv_empty_cells

   subroutine test_csv_no_rows(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(0)
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = dir//'test_report_no_rows.csv'

      call write_report_csv(path, rows, error)
      if (allocated(error)) return
      call read_report_csv(path, back, error)
      if (allocated(error)) return
      call check(error, size(back), 0, 'header only reads as no rows')
   end subroutine test_csv_no_rows

   subroutine test_csv_unwritable(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      character(len=*), parameter :: path = dir//'no_such_directory/report.csv'

      call write_report_csv(path, sample_rows(), err)
      call check_error(error, err, stat_io, path)
   end subroutine test_csv_unwritable

   subroutine test_csv_read_missing(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = dir//'no_such_file_report.csv'

      call read_report_csv(path, back, err)
      call check_error(error, err, stat_io, path)
   end subroutine test_csv_read_missing

   subroutine test_csv_read_bad_header(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = dir//'test_report_bad_header.csv'

      call write_text_file(path, 'level,h,elements,dofs,cut_elements'//new_line('a'), error)
      if (allocated(error)) return
      call read_report_csv(path, back, err)
      call check_error(error, err, stat_invalid_input, 'cut_elements')
   end subroutine test_csv_read_bad_header

   subroutine test_csv_read_bad_value(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = dir//'test_report_bad_value.csv'
      character(len=*), parameter :: nl = new_line('a')

      call write_text_file(path, report_csv_header//nl//'1,0.5,4,0,18,,,,,,,,NaN,,,,,,'//nl, error)
      if (allocated(error)) return
      call read_report_csv(path, back, err)
      call check_error(error, err, stat_invalid_input, 'err_fe')
      if (allocated(error)) return
      call write_text_file(path, report_csv_header//nl//'1,0.5,four,0,18,,,,,,,,,,,,,,'//nl, error)
      if (allocated(error)) return
      call read_report_csv(path, back, err)
      call check_error(error, err, stat_invalid_input, 'elements')
   end subroutine test_csv_read_bad_value

   subroutine test_csv_read_short_line(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(report_row_type), allocatable :: back(:)
      character(len=*), parameter :: path = dir//'test_report_short_line.csv'
      character(len=*), parameter :: nl = new_line('a')

      call write_text_file(path, report_csv_header//nl//'1,0.5,4,0,18,1.0'//nl, error)
      if (allocated(error)) return
      call read_report_csv(path, back, err)
      call check_error(error, err, stat_invalid_input, 'line 2')
   end subroutine test_csv_read_short_line

   subroutine test_column_access(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      real(wp) :: v(3), w(3)

      rows = sample_rows()
      v = report_column(rows, 'dofs')
      call check(error, all(nint(v, i8) == rows%dofs), 'dofs as reals')
      if (allocated(error)) return
      v = report_column(rows, 'eta_sprc')
      w = rows%eta_sprc
      call check(error, all(transfer(v, 1_i8, 3) == transfer(w, 1_i8, 3)), 'eta_sprc')
      if (allocated(error)) return
      call check(error, all(is_empty(report_column(rows, 'no_such_column'))), 'unknown column is empty')
      if (allocated(error)) return
      ! A fresh row: integers zero, every real empty.
      rows(1) = report_row_type()
      call check(error, all(is_empty([rows(1)%h, rows(1)%t_total, rows(1)%err_fe, rows(1)%theta_sprc])), &
         'default reals are empty')
   end subroutine test_column_access

   !> Columns are read off the rule line (runs of dashes): there must be one
   !> per contract column, each header name and each non-empty cell must end
   !> exactly where its run ends, and nothing may stick out of a run.
   subroutine test_table(error)
      type(error_type), allocatable, intent(out) :: error
      call check_table(no_exact_rows(), 20, error)
   end subroutine test_table

   !> With contact the table has all 30 columns, contact ones included.
   subroutine test_table_contact(error)
      type(error_type), allocatable, intent(out) :: error
      call check_table(contact_rows(), 35, error)
   end subroutine test_table_contact

   subroutine check_table(rows, ncolumns, error)
      type(report_row_type), intent(in) :: rows(3)
      integer, intent(in) :: ncolumns
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: table
      character(len=800) :: lines(5)
      integer :: i, j, n, first(n_report_columns), last(n_report_columns), ncol, pos
      integer, allocatable :: columns(:)
      character(len=:), allocatable :: name
      real(wp) :: v(3)

      table = report_table(rows, wide=.true.)
      columns = report_column_indices(rows)
      call check(error, size(columns), ncolumns, 'columns of the rows')
      if (allocated(error)) return
      call split_lines(table, lines, n)
      call check(error, n, 5, 'header, rule, 3 rows')
      if (allocated(error)) return
      call check(error, len_trim(lines(2)) < len(lines), 'table fits the test buffer')
      if (allocated(error)) return
      call check(error, index(lower(table), 'nan') == 0, 'no NaN in the table')
      if (allocated(error)) return
      ncol = 0
      pos = 1
      do while (pos <= len_trim(lines(2)))
         if (lines(2)(pos:pos) == '-') then
            ncol = ncol + 1
            if (ncol > n_report_columns) exit
            first(ncol) = pos
            do while (lines(2)(pos:pos) == '-')
               pos = pos + 1
            end do
            last(ncol) = pos - 1
         else
            pos = pos + 1
         end if
      end do
      call check(error, ncol, ncolumns, 'dash runs in the rule')
      if (allocated(error)) return
      do j = 1, ncolumns
         name = trim(report_columns(columns(j)))
         call check(error, lines(1)(first(j):last(j)), right_in(name, last(j) - first(j) + 1), &
            'header of column '//itoa(j))
         if (allocated(error)) return
         v = report_column(rows, name)
         do i = 1, 3
            if (is_empty(v(i))) then
               call check(error, len_trim(lines(i + 2)(first(j):last(j))) == 0, &
                  'empty '//name//' blank in row '//itoa(i))
            else
               call check(error, lines(i + 2)(last(j):last(j)) /= ' ' .and. lines(i + 2)(first(j):first(j)) /= '-', &
                  name//' right-aligned in row '//itoa(i))
            end if
            if (allocated(error)) return
         end do
      end do
      call check(error, all(first(2:ncolumns) - last(:ncolumns - 1) == 3), 'two blanks between columns')
      if (allocated(error)) return
      do i = 1, 3
         call check(error, adjustl(lines(i + 2)(first(1):last(1))), itoa(rows(i)%level), 'level of row '//itoa(i))
         if (allocated(error)) return
         call check(error, adjustl(lines(i + 2)(first(5):last(5))), itoa(int(rows(i)%dofs)), 'dofs of row '//itoa(i))
         if (allocated(error)) return
         call check(error, adjustl(lines(i + 2)(first(ncolumns):last(ncolumns))), itoa(rows(i)%solver_iterations), &
            & 'solver_iterations (last) of row '//itoa(i))
         if (allocated(error)) return
      end do
   end subroutine check_table

   pure function right_in(s, w) result(r)
      character(len=*), intent(in) :: s
      integer, intent(in) :: w
      character(len=w) :: r
      r = repeat(' ', w - len(s))//s
   end function right_in

   subroutine test_table_digits(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(1)
      character(len=:), allocatable :: table

      rows(1)%t_mesh = 0.0012345_wp
      rows(1)%t_solve = 12.345_wp
      rows(1)%t_total = 9.9996_wp
      rows(1)%t_assembly = 123456.7_wp
      rows(1)%t_recovery = 2.5e-7_wp
      rows(1)%err_fe = 0.012345_wp
      rows(1)%theta_sprc = 0.98765_wp
      table = report_table(rows, wide=.true.)
      call check(error, index(table, ' 0.00123 ') > 0, 't_mesh 3 digits: '//table)
      if (allocated(error)) return
      call check(error, index(table, ' 12.3 ') > 0, 't_solve 3 digits')
      if (allocated(error)) return
      call check(error, index(table, ' 10.0 ') > 0, 't_total rounds into the next decade')
      if (allocated(error)) return
      call check(error, index(table, ' 123457 ') > 0, 't_assembly large')
      if (allocated(error)) return
      call check(error, index(table, ' 2.50E-07 ') > 0, 't_recovery tiny in es')
      if (allocated(error)) return
      call check(error, index(table, ' 1.235E-02 ') > 0 .or. index(table, ' 1.234E-02 ') > 0, 'err_fe in es')
      if (allocated(error)) return
      call check(error, index(table, ' 0.988') > 0, 'theta 3 digits')
   end subroutine test_table_digits

   subroutine test_xml_checker(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: msg

      call check(error, xml_well_formed('<a x="1"><b/><c>t &amp; u</c></a>', 'a', msg), 'good: '//msg)
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<a><b></a></b>', 'a', msg), 'crossed tags')
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<a><b></a>', 'a', msg), 'unclosed')
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<a x=1/>', 'a', msg), 'unquoted attribute')
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<a>x & y</a>', 'a', msg), 'bare ampersand')
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<a/><b/>', 'a', msg), 'two roots')
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<a><!-- x -- y --></a>', 'a', msg), 'double dash in comment')
      if (allocated(error)) return
      call check(error, .not. xml_well_formed('<b/>', 'a', msg), 'wrong root')
   end subroutine test_xml_checker

   subroutine test_svg_well_formed(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = dir//'test_report.svg'
      character(len=:), allocatable :: text, msg
      character(len=*), parameter :: series(5) = [character(len=8) :: 'err_fe', 'err_spr', 'err_sprc', &
         & 'eta_spr', 'eta_sprc']
      integer :: k

      call write_report_svg(path, sample_rows(), 'Kirsch plate, Q2', error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, 'xmlns="http://www.w3.org/2000/svg"') > 0, 'SVG namespace')
      if (allocated(error)) return
      call check(error, index(text, 'version="1.1"') > 0, 'SVG 1.1')
      if (allocated(error)) return
      call check(error, index(text, '<script') == 0 .and. index(text, '@import') == 0 .and. &
         index(text, 'href') == 0, 'no scripts, no external references')
      if (allocated(error)) return
      call check(error, index(text, 'Kirsch plate, Q2') > 0, 'title')
      if (allocated(error)) return
      do k = 1, size(series)
         ! One polyline per panel and a legend entry per column with values.
         call check(error, count_sub(text, 'class="line '//trim(series(k))//'"'), 2, trim(series(k))//' lines')
         if (allocated(error)) return
         call check(error, index(text, '('//trim(series(k))//')</text>') > 0, trim(series(k))//' in legend')
         if (allocated(error)) return
      end do
      ! The legend says in words what each series is, naming the energy norm.
      call check(error, index(text, '>FE error ‖σ−σ_h‖_E / ‖σ‖_E (err_fe)</text>') > 0 .and. &
         & index(text, '>ZZ estimate, SPR-C (eta_sprc)</text>') > 0 .and. &
         & index(text, '>SPR-C error ‖σ−σ*‖_E / ‖σ‖_E (err_sprc)</text>') > 0, 'legend in words')
      if (allocated(error)) return
      ! 5 columns x 3 rows x 2 panels of markers.
      call check(error, count_sub(text, 'class="point'), 30, 'markers')
      if (allocated(error)) return
      ! err_fe is a wide pale band drawn first: eta_sprc on top of it (effectivity 1)
      ! hid it when both were thin lines.
      call check(error, index(text, 'class="line err_fe"') > 0 .and. &
         & index(text, 'class="line err_fe"') < index(text, 'class="line eta_sprc"') .and. &
         & count_sub(text, 'stroke-width="6" stroke-opacity="0.35"') == 3, 'err_fe band under the other lines')
      if (allocated(error)) return
      call check(error, index(text, 'run time') > 0 .and. index(text, 'degrees of freedom') > 0 .and. &
         index(text, 'relative error') > 0, 'axis labels')
      if (allocated(error)) return
      call python_xml_check(path, error)
   end subroutine test_svg_well_formed

   !> On log axes, values a constant factor apart are equally spaced: err_fe
   !> halves per level and dofs/t_total grow geometrically, so the err_fe
   !> markers are equally spaced and collinear in each panel. Decade labels of
   !> the t_total axis (10..1000 s) must be 10^1, 10^2, 10^3.
   subroutine test_svg_positions(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      character(len=:), allocatable :: text
      real(wp) :: cx(6), cy(6)
      integer :: i, pos, k

      rows = sample_rows()
      do i = 1, 3
         rows(i)%dofs = 100_i8*10_i8**(i - 1)
      end do
      text = report_svg(rows, 'positions')
      pos = 1
      do k = 1, 6
         i = index(text(pos:), 'class="point err_fe"')
         call check(error, i > 0, 'err_fe marker '//itoa(k))
         if (allocated(error)) return
         pos = pos + i
         cx(k) = attribute_real(text(pos:), 'cx')
         cy(k) = attribute_real(text(pos:), 'cy')
      end do
      ! The time panel: cumulative times 10, 110, 1110 s on decades 10^1..10^4, 390 px.
      call check(error, cx(2) - cx(1), 130.0_wp*log10(11.0_wp), 0.05_wp, 'cumulative time, first step')
      if (allocated(error)) return
      call check(error, cx(3) - cx(2), 130.0_wp*log10(1110.0_wp/110.0_wp), 0.05_wp, 'cumulative time, second step')
      if (allocated(error)) return
      do k = 1, 4, 3
         ! 0.05 px: coordinates are written with 2 decimals.
         if (k == 4) call check(error, (cx(k + 2) - cx(k + 1)) - (cx(k + 1) - cx(k)), 0.0_wp, 0.05_wp, &
            & 'equal x steps')
         if (allocated(error)) return
         call check(error, (cy(k + 2) - cy(k + 1)) - (cy(k + 1) - cy(k)), 0.0_wp, 0.05_wp, 'equal y steps')
         if (allocated(error)) return
         call check(error, cx(k + 1) > cx(k) .and. cy(k + 1) > cy(k), 'x grows right, error falls down')
         if (allocated(error)) return
      end do
      ! Both panels plot the same errors against a decade-per-level abscissa: same steps.
      call check(error, cy(2) - cy(1), cy(5) - cy(4), 0.05_wp, 'same y scale in both panels')
      if (allocated(error)) return
      do k = 1, 3
         call check(error, index(text, '>10<tspan dy="-7" font-size="10">'//itoa(k)//'</tspan></text>') > 0, &
            'decade label 10^'//itoa(k))
         if (allocated(error)) return
      end do
   end subroutine test_svg_positions

   subroutine test_svg_omits_empty(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: path = dir//'test_report_no_exact.svg'
      character(len=:), allocatable :: text, msg

      call write_report_svg(path, no_exact_rows(), 'no exact solution', error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, 'err_fe') == 0 .and. index(text, 'err_spr') == 0, 'err_* columns omitted')
      if (allocated(error)) return
      call check(error, index(text, '(eta_spr)</text>') > 0 .and. index(text, '(eta_sprc)</text>') > 0, &
         'eta_* in the legend')
      if (allocated(error)) return
      call check(error, index(text, 'measured rate of eta_sprc') > 0, 'without err_fe the rate is eta_sprc''s')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point'), 12, '2 columns x 3 rows x 2 panels')
   end subroutine test_svg_omits_empty

   subroutine test_svg_single_row(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      character(len=*), parameter :: path = dir//'test_report_one_row.svg'
      character(len=:), allocatable :: text, msg

      rows = sample_rows()
      call write_report_svg(path, rows(2:2), 'one level', error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, '<polyline') == 0, 'no lines through one point')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point'), 10, 'one marker per column and panel')
      if (allocated(error)) return
      ! Axes still get decade labels when all points share one value.
      call check(error, index(text, '<tspan') > 0, 'decade labels')
      if (allocated(error)) return
      ! No rows at all still gives a valid picture.
      text = report_svg(rows(1:0), 'empty')
      call check(error, xml_well_formed(text, 'svg', msg), 'empty report SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, 'no data') > 0, 'says no data')
   end subroutine test_svg_single_row

   subroutine test_svg_non_positive(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      character(len=*), parameter :: path = dir//'test_report_non_positive.svg'
      character(len=:), allocatable :: text, msg

      rows = sample_rows()
      rows(2)%err_spr = 0.0_wp
      rows(3)%err_spr = -1.0e-3_wp
      rows(1)%t_total = 0.0_wp
      call write_report_svg(path, rows, 'non-positive', error)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      ! err_spr keeps only level 2 (1 point per panel, minus level 2 in the time panel since t_total(1) = 0).
      call check(error, count_sub(text, 'class="point err_spr"'), 1, 'err_spr markers')
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="point err_fe"'), 5, 'err_fe markers (time panel misses row 1)')
      if (allocated(error)) return
      call check(error, index(text, '<!-- skipped') > 0, 'comment says what was skipped')
      if (allocated(error)) return
      call check(error, index(text, 'err_spr at level 3') > 0 .and. index(text, 't_total at level 2') > 0, &
         'comment names the skipped cells')
      if (allocated(error)) return
      call check(error, index(lower(text), 'nan') == 0 .and. index(lower(text), 'infinity') == 0, 'no NaN/Inf')
   end subroutine test_svg_non_positive

   subroutine test_svg_title_escaped(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, msg

      text = report_svg(sample_rows(), 'a < b & "c"')
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, index(text, 'a &lt; b &amp; &quot;c&quot;') > 0, 'title escaped')
   end subroutine test_svg_title_escaped

   subroutine test_svg_unwritable(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      character(len=*), parameter :: path = dir//'no_such_directory/report.svg'

      call write_report_svg(path, sample_rows(), 'x', err)
      call check_error(error, err, stat_io, path)
   end subroutine test_svg_unwritable

   !> The compact table (the default) fits a terminal: level, dofs, err_fe, the
   !> estimates and effectivities, t_total, in that order, lines <= 90
   !> characters; columns empty in every row are left out; `wide` prints
   !> every column of the report.
   subroutine test_table_compact(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=600) :: lines(5)
      character(len=:), allocatable :: table
      type(report_row_type) :: rows(3)
      integer :: n, i, j
      integer, allocatable :: columns(:)

      table = report_table(contact_rows())
      call split_lines(table, lines, n)
      call check(error, n, 5, 'header, rule, 3 rows')
      if (allocated(error)) return
      call check(error, words(lines(1)), 'level dofs err_fe eta_spr eta_sprc theta_spr theta_sprc t_total', &
         & 'compact header')
      if (allocated(error)) return
      do i = 1, n
         call check(error, len_trim(lines(i)) <= 90, 'line '//itoa(i)//' of '//itoa(len_trim(lines(i)))// &
            & ' characters fits a terminal')
         if (allocated(error)) return
      end do
      rows = contact_rows()
      call check(error, index(words(lines(3)), itoa(rows(1)%level)//' '//itoa(int(rows(1)%dofs))//' ') == 1, &
         & 'level and dofs of row 1: '//trim(lines(3)))
      if (allocated(error)) return
      call split_lines(report_table(no_exact_rows()), lines, n)
      call check(error, words(lines(1)), 'level dofs eta_spr eta_sprc t_total', 'empty columns left out')
      if (allocated(error)) return
      call split_lines(report_table(contact_rows(), wide=.true.), lines, n)
      columns = report_column_indices(contact_rows())
      table = ''
      do j = 1, size(columns)
         table = table//' '//trim(report_columns(columns(j)))
      end do
      call check(error, words(lines(1)), table(2:), 'wide: every column')
   end subroutine test_table_compact

   !> An adaptive study's compact table starts with `step`, still <= 100 characters.
   subroutine test_table_compact_adaptive(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      character(len=600) :: lines(5)
      integer :: n, i

      rows = sample_rows()
      do i = 1, 3
         rows(i)%step = i - 1
         rows(i)%dofs = 123456789_i8
      end do
      call split_lines(report_table(rows), lines, n)
      call check(error, words(lines(1)), 'step level dofs err_fe eta_spr eta_sprc theta_spr theta_sprc t_total', &
         & 'adaptive compact header')
      if (allocated(error)) return
      do i = 1, n
         call check(error, len_trim(lines(i)) <= 100, 'line '//itoa(i)//' fits a terminal')
         if (allocated(error)) return
      end do
   end subroutine test_table_compact_adaptive

   !> The time panel's abscissa is the cumulative run time: with t_total
   !> falling from row to row (timing noise, or a cheap level after a costly
   !> one), the err_fe markers still go right, and the axis says so.
   subroutine test_svg_cumulative_time(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      character(len=:), allocatable :: text
      real(wp) :: cx(3)
      integer :: i, pos, k

      rows = sample_rows()
      rows%t_total = [5.0_wp, 1.0_wp, 2.0_wp]
      text = report_svg(rows, 'noise')
      pos = 1
      do k = 1, 3
         i = index(text(pos:), 'class="point err_fe"')
         call check(error, i > 0, 'err_fe marker '//itoa(k))
         if (allocated(error)) return
         pos = pos + i
         cx(k) = attribute_real(text(pos:), 'cx')
      end do
      ! 5, 6, 8 s on the decade 10^0..10^1, 390 px.
      call check(error, cx(2) - cx(1), 390.0_wp*log10(6.0_wp/5.0_wp), 0.05_wp, 'first step')
      if (allocated(error)) return
      call check(error, cx(3) - cx(2), 390.0_wp*log10(8.0_wp/6.0_wp), 0.05_wp, 'second step')
      if (allocated(error)) return
      call check(error, index(text, 'cumulative run time, sum of t_total [s]') > 0, 'time axis title')
   end subroutine test_svg_cumulative_time

   !> With the order and dimension, the dofs panel has a reference line of
   !> slope -p/d and the legend names it and the measured rate: err_fe halves
   !> per level while the dofs grow tenfold, rate log10(2) = 0.30; the line's
   !> pixel slope to that of the err_fe markers is (p/d)/log10(2).
   subroutine test_svg_reference_slope(error)
      type(error_type), allocatable, intent(out) :: error
      type(report_row_type) :: rows(3)
      character(len=*), parameter :: path = dir//'test_report_slope.svg'
      character(len=:), allocatable :: text, msg
      real(wp) :: cx(2), cy(2), x1, y1, x2, y2
      integer :: i, pos, k

      rows = sample_rows()
      do i = 1, 3
         rows(i)%dofs = 100_i8*10_i8**(i - 1)
      end do
      call write_report_svg(path, rows, 'slope', error, order=2, dim=3)
      if (allocated(error)) return
      call read_text_file(path, text, error)
      if (allocated(error)) return
      call check(error, xml_well_formed(text, 'svg', msg), 'SVG well-formed: '//msg)
      if (allocated(error)) return
      call check(error, count_sub(text, 'class="reference-slope"'), 1, 'one reference line, in the dofs panel')
      if (allocated(error)) return
      call check(error, index(text, 'optimal rate p/d = 2/3') > 0, 'reference rate in the legend')
      if (allocated(error)) return
      call check(error, index(text, 'measured rate of err_fe: 0.30 (last two rows)') > 0, 'measured rate')
      if (allocated(error)) return
      pos = index(text, 'class="reference-slope"')
      x1 = attribute_real(text(pos:), 'x1')
      y1 = attribute_real(text(pos:), 'y1')
      x2 = attribute_real(text(pos:), 'x2')
      y2 = attribute_real(text(pos:), 'y2')
      ! The dofs panel's err_fe markers: the 4th and 5th.
      pos = 1
      do k = 1, 5
         i = index(text(pos:), 'class="point err_fe"')
         pos = pos + i
         if (k >= 4) cx(k - 3) = attribute_real(text(pos:), 'cx')
         if (k >= 4) cy(k - 3) = attribute_real(text(pos:), 'cy')
      end do
      call check(error, x1 >= 500.0_wp .and. x2 > x1, 'the line lies in the dofs panel')
      if (allocated(error)) return
      call check(error, ((y2 - y1)/(x2 - x1))/((cy(2) - cy(1))/(cx(2) - cx(1))), &
         & (2.0_wp/3.0_wp)/log10(2.0_wp), 1.0e-3_wp, 'slope -p/d')
      if (allocated(error)) return
      ! Without the order and dimension: no reference line, the measured rate still.
      text = report_svg(rows, 'no slope')
      call check(error, index(text, 'reference-slope') == 0 .and. index(text, 'measured rate of err_fe') > 0, &
         & 'no reference without p and d')
   end subroutine test_svg_reference_slope

   ! ---------------------------------------------------------------- helpers

   !> The blank-separated words of `line`, joined by one blank.
   function words(line) result(w)
      character(len=*), intent(in) :: line
      character(len=:), allocatable :: w
      integer :: i
      w = ''
      do i = 1, len_trim(line)
         if (line(i:i) == ' ' .and. (len(w) == 0 .or. w(max(1, len(w)):) == ' ')) cycle
         w = w//line(i:i)
      end do
      w = trim(w)
   end function words

   !> `err` must be allocated with status `stat` and a message containing `part`.
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

   !> Whole file as one string (lines joined by newlines).
   subroutine read_text_file(path, text, error)
      character(len=*), intent(in) :: path
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat, fsize

      open (newunit=unit, file=path, status='old', access='stream', form='unformatted', action='read', &
         iostat=stat)
      if (stat /= 0) then
         call test_failed(error, 'cannot open '//path)
         return
      end if
      inquire (unit=unit, size=fsize)
      allocate (character(len=fsize) :: text)
      if (fsize > 0) read (unit, iostat=stat) text
      close (unit)
      if (stat /= 0) call test_failed(error, 'cannot read '//path)
   end subroutine read_text_file

   subroutine write_text_file(path, text, error)
      character(len=*), intent(in) :: path, text
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat

      open (newunit=unit, file=path, status='replace', access='stream', form='unformatted', action='write', &
         iostat=stat)
      if (stat /= 0) then
         call test_failed(error, 'cannot write '//path)
         return
      end if
      write (unit) text
      close (unit)
   end subroutine write_text_file

   !> Optional second opinion: parse `path` with Python's xml.etree when
   !> python3 runs here (exit 0 = parsed, 1 = parse error, else skipped).
   subroutine python_xml_check(path, error)
      character(len=*), intent(in) :: path
      type(error_type), allocatable, intent(out) :: error
      integer :: exitstat, cmdstat

      call execute_command_line('python3 -c "import sys, xml.etree.ElementTree as E; E.parse(sys.argv[1])" ' &
         //path//' 2>/dev/null', exitstat=exitstat, cmdstat=cmdstat)
      if (cmdstat /= 0) return
      if (exitstat == 1) call test_failed(error, 'python3 xml.etree cannot parse '//path)
   end subroutine python_xml_check

   !> A small XML well-formedness check: balanced, properly nested tags,
   !> quoted attributes, entities only as &name; or &#n;, comments without
   !> "--", exactly one root element named `root`. `msg` says what is wrong.
   logical function xml_well_formed(text, root, msg) result(ok)
      character(len=*), intent(in) :: text, root
      character(len=:), allocatable, intent(out) :: msg
      character(len=64) :: stack(64)
      integer :: depth, pos, close_at, n, nroot
      character(len=:), allocatable :: tag, name

      ok = .false.
      msg = ''
      depth = 0
      nroot = 0
      pos = 1
      n = len(text)
      do while (pos <= n)
         if (text(pos:pos) /= '<') then
            close_at = index(text(pos:), '<')
            if (close_at == 0) close_at = n - pos + 2
            if (.not. entities_ok(text(pos:pos + close_at - 2))) then
               msg = 'bad & in text near '//itoa(pos)
               return
            end if
            if (depth == 0 .and. verify(text(pos:pos + close_at - 2), ' '//achar(9)//achar(10)//achar(13)) > 0) then
               msg = 'text outside the root near '//itoa(pos)
               return
            end if
            pos = pos + close_at - 1
            cycle
         end if
         if (starts(text(pos:), '<!--')) then
            close_at = index(text(pos + 4:), '-->')
            if (close_at == 0) then
               msg = 'unterminated comment'
               return
            end if
            if (index(text(pos + 4:pos + 2 + close_at), '--') > 0) then
               msg = '"--" inside a comment near '//itoa(pos)
               return
            end if
            pos = pos + 4 + close_at + 2
         else if (starts(text(pos:), '<?')) then
            close_at = index(text(pos:), '?>')
            if (close_at == 0) then
               msg = 'unterminated <?'
               return
            end if
            pos = pos + close_at + 1
         else if (starts(text(pos:), '<!DOCTYPE')) then
            close_at = index(text(pos:), '>')
            if (index(text(pos:pos + close_at - 1), '[') > 0) close_at = index(text(pos:), ']>') + 1
            pos = pos + close_at
         else
            close_at = index(text(pos:), '>')
            if (close_at == 0) then
               msg = 'unterminated tag near '//itoa(pos)
               return
            end if
            tag = text(pos + 1:pos + close_at - 2)
            pos = pos + close_at
            if (tag(1:1) == '/') then
               name = trim(tag(2:))
               if (depth == 0) then
                  msg = 'end tag </'//name//'> without start'
                  return
               end if
               if (name /= trim(stack(depth))) then
                  msg = 'end tag </'//name//'> closes <'//trim(stack(depth))//'>'
                  return
               end if
               depth = depth - 1
            else
               if (.not. start_tag_ok(tag, name)) then
                  msg = 'malformed tag <'//tag//'>'
                  return
               end if
               if (depth == 0) nroot = nroot + 1
               if (depth == 0 .and. name /= root) then
                  msg = 'root element is <'//name//'>, expected <'//root//'>'
                  return
               end if
               if (tag(len(tag):) /= '/') then
                  depth = depth + 1
                  stack(depth) = name
               end if
            end if
         end if
      end do
      if (depth /= 0) then
         msg = 'unclosed <'//trim(stack(depth))//'>'
      else if (nroot /= 1) then
         msg = itoa(nroot)//' root elements'
      else
         ok = .true.
      end if
   end function xml_well_formed

   !> `<name attr="v" attr2='w' /?>`: a name, then name=quoted-value pairs.
   logical function start_tag_ok(tag, name) result(ok)
      character(len=*), intent(in) :: tag
      character(len=:), allocatable, intent(out) :: name
      integer :: i, n, q
      character :: quote

      ok = .false.
      n = len(tag)
      if (n > 0) then
         if (tag(n:n) == '/') n = n - 1
      end if
      i = 1
      do while (i <= n)
         if (.not. name_char(tag(i:i))) exit
         i = i + 1
      end do
      name = tag(1:i - 1)
      if (len(name) == 0) return
      do
         do while (i <= n)
            if (tag(i:i) /= ' ' .and. tag(i:i) /= new_line('a')) exit
            i = i + 1
         end do
         if (i > n) exit
         q = i
         do while (i <= n)
            if (.not. name_char(tag(i:i))) exit
            i = i + 1
         end do
         if (i == q .or. i > n) return
         if (tag(i:i) /= '=') return
         i = i + 1
         if (i > n) return
         quote = tag(i:i)
         if (quote /= '"' .and. quote /= "'") return
         q = index(tag(i + 1:n), quote)
         if (q == 0) return
         if (index(tag(i + 1:i + q - 1), '<') > 0) return
         if (.not. entities_ok(tag(i + 1:i + q - 1))) return
         i = i + q + 1
      end do
      ok = .true.
   end function start_tag_ok

   logical function name_char(c)
      character, intent(in) :: c
      name_char = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z') .or. (c >= '0' .and. c <= '9') &
         .or. c == '_' .or. c == '-' .or. c == ':' .or. c == '.'
   end function name_char

   !> Every & starts an entity: &name; or &#digits;.
   logical function entities_ok(s) result(ok)
      character(len=*), intent(in) :: s
      character(len=*), parameter :: entity_chars = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ#0123456789'
      integer :: i, amp, semi

      ok = .false.
      i = 1
      do while (i <= len(s))
         amp = index(s(i:), '&')
         if (amp == 0) exit
         amp = i + amp - 1
         semi = index(s(amp:), ';')
         if (semi < 3) return
         if (verify(s(amp + 1:amp + semi - 2), entity_chars) /= 0) return
         i = amp + semi
      end do
      ok = .true.
   end function entities_ok

   logical function starts(s, prefix)
      character(len=*), intent(in) :: s, prefix
      starts = .false.
      if (len(s) >= len(prefix)) starts = s(1:len(prefix)) == prefix
   end function starts

   !> Value of attribute `name="..."` at its first occurrence in `s`.
   real(wp) function attribute_real(s, name) result(x)
      character(len=*), intent(in) :: s, name
      integer :: i, j
      i = index(s, ' '//name//'="') + len(name) + 3
      j = index(s(i:), '"')
      read (s(i:i + j - 2), *) x
   end function attribute_real

   !> Cell j (1-based) of a CSV line.
   function cell_of(line, j) result(cell)
      character(len=*), intent(in) :: line
      integer, intent(in) :: j
      character(len=:), allocatable :: cell
      integer :: k, pos, next

      pos = 1
      do k = 1, j - 1
         pos = pos + index(line(pos:), ',')
      end do
      next = index(line(pos:), ',')
      if (next == 0) then
         cell = line(pos:)
      else
         cell = line(pos:pos + next - 2)
      end if
   end function cell_of

   !> The first size(lines) lines of `text`, blank-padded; `n` = number of lines in `text`.
   subroutine split_lines(text, lines, n)
      character(len=*), intent(in) :: text
      character(len=*), intent(out) :: lines(:)
      integer, intent(out) :: n
      integer :: pos, k, eol

      n = count_char(text, new_line('a'))
      lines = ''
      pos = 1
      do k = 1, min(n, size(lines))
         eol = pos + index(text(pos:), new_line('a')) - 1
         lines(k) = text(pos:eol - 1)
         pos = eol + 1
      end do
   end subroutine split_lines

   integer function count_char(s, c) result(n)
      character(len=*), intent(in) :: s
      character, intent(in) :: c
      integer :: i
      n = 0
      do i = 1, len(s)
         if (s(i:i) == c) n = n + 1
      end do
   end function count_char

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

end module sprc_test_report
