!> The study report (doc/scene.md "The report"): one row per level, printed as a
!> fixed-width table and written as a CSV file whose reals round-trip bit for
!> bit; a CSV reader for tests and comparisons. The SVG plot of the same rows
!> is `sprc_io_svg`.
!>
!> A real cell that does not apply (no exact solution, recovery not run) is
!> *empty*: it holds a quiet NaN (`report_empty`) and `is_empty` is true for
!> it. Every NaN counts as empty, so no writer ever prints "NaN": an empty cell
!> is an empty string in the CSV and blanks in the table.
module sprc_io_report
   use, intrinsic :: ieee_arithmetic, only: ieee_is_nan, ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: fixed_text, itoa
   use sprc_core_error, only: error_type, fatal_error, stat_io, stat_invalid_input
   use sprc_study_row, only: report_row_type, report_empty, is_empty
   use sprc_study_mesh_table, only: mesh_row_type
   implicit none
   private

   public :: report_row_type, report_table, write_report_csv, read_report_csv, format_mesh_row
   public :: report_column, report_empty, is_empty
   public :: n_report_columns, report_columns, report_csv_header, report_column_indices, report_header, csv_real

   !> Number of columns a report may have: the 19 of every study, the 15
   !> contact columns, `solver_iterations` and the 2 adaptive columns.
   integer, parameter :: n_report_columns = 37

   !> Column names, in the contract's order (doc/scene.md "The report").
   character(len=18), parameter :: report_columns(n_report_columns) = [character(len=18) :: &
      & 'level', 'h', 'elements', 'cut_elements', 'dofs', 't_mesh', 't_quadrature', 't_assembly', &
      & 't_solve', 't_recovery', 't_estimate', 't_total', 'err_fe', 'err_spr', 'err_sprc', &
      & 'eta_spr', 'eta_sprc', 'theta_spr', 'theta_sprc', &
      & 'contact_iterations', 't_contact', 'contact_measure', 'p_max_fe', 'p_max_spr', 'p_max_sprc', &
      & 'p_max_exact', 'err_p_fe', 'err_p_spr', 'err_p_sprc', 'p_max_fe_stress', 'err_p_fe_stress', &
      & 'jump_fe', 'jump_spr', 'jump_sprc', 'solver_iterations', 'step', 't_adapt']

   !> Columns 1..n_base_columns are in every report, in this order, first; the
   !> contact columns (first_contact_column..last_contact_column) only in a
   !> study with contact; `solver_iterations` in every report; the adaptive
   !> columns (`step`, `t_adapt`, from first_adapt_column) last, only in an
   !> adaptive study, so that a uniform study's report is what it was.
   integer, parameter :: n_base_columns = 19, first_contact_column = 20, last_contact_column = 34, &
      & first_adapt_column = 36

   !> The CSV header of the columns every report starts with, exactly as doc/scene.md
   !> states it (`report_header` gives a report's whole header).
   character(len=*), parameter :: report_csv_header = 'level,h,elements,cut_elements,dofs,t_mesh,'// &
      & 't_quadrature,t_assembly,t_solve,t_recovery,t_estimate,t_total,err_fe,err_spr,err_sprc,'// &
      & 'eta_spr,eta_sprc,theta_spr,theta_sprc'

   !> How each column is formatted in the table.
   integer, parameter :: kind_integer = 1, kind_sig3 = 2, kind_error = 3
   integer, parameter :: column_kind(n_report_columns) = [kind_integer, kind_sig3, kind_integer, &
      & kind_integer, kind_integer, kind_sig3, kind_sig3, kind_sig3, kind_sig3, kind_sig3, kind_sig3, &
      & kind_sig3, kind_error, kind_error, kind_error, kind_error, kind_error, kind_sig3, kind_sig3, &
      & kind_integer, kind_sig3, kind_error, kind_error, kind_error, kind_error, kind_error, kind_error, &
      & kind_error, kind_error, kind_error, kind_error, kind_error, kind_error, kind_error, kind_integer, &
      & kind_integer, kind_sig3]

contains

   !> The columns `rows` carry, as indices into `report_columns`: the 19 of
   !> every report, the contact ones (after theta_sprc) when any row has
   !> contact, solver_iterations, and the adaptive ones (`step`, `t_adapt`)
   !> when any row is an adaptive step.
   pure function report_column_indices(rows) result(indices)
      type(report_row_type), intent(in) :: rows(:)
      integer, allocatable :: indices(:)
      integer :: j

      indices = [(j, j=1, n_base_columns)]
      if (any(rows%has_contact)) indices = [indices, (j, j=first_contact_column, last_contact_column)]
      indices = [indices, last_contact_column + 1]
      if (any(rows%step >= 0)) indices = [indices, (j, j=first_adapt_column, n_report_columns)]
   end function report_column_indices

   !> The CSV header line of `rows`: their columns' names, comma-separated.
   pure function report_header(rows) result(header)
      type(report_row_type), intent(in) :: rows(:)
      character(len=:), allocatable :: header
      integer, allocatable :: indices(:)
      integer :: j

      indices = report_column_indices(rows)
      header = trim(report_columns(indices(1)))
      do j = 2, size(indices)
         header = header//','//trim(report_columns(indices(j)))
      end do
   end function report_header

   !> The values of column `name` over `rows` (integers converted to real;
   !> empty cells stay empty; the contact columns are empty in a row without
   !> contact). An unknown name gives all-empty values.
   pure function report_column(rows, name) result(values)
      type(report_row_type), intent(in) :: rows(:)
      character(len=*), intent(in) :: name
      real(wp) :: values(size(rows))
      integer :: i, j

      values = report_empty
      j = findloc(report_columns, name, dim=1)
      if (j == 0) return
      do i = 1, size(rows)
         values(i) = row_values(rows(i), j)
      end do
   end function report_column

   !> Column j of a row as a real.
   pure real(wp) function row_values(row, j) result(x)
      type(report_row_type), intent(in) :: row
      integer, intent(in) :: j

      if (j >= first_contact_column .and. j <= last_contact_column .and. .not. row%has_contact) then
         x = report_empty
         return
      end if
      select case (j)
      case (1); x = real(row%level, wp)
      case (2); x = row%h
      case (3); x = real(row%elements, wp)
      case (4); x = real(row%cut_elements, wp)
      case (5); x = real(row%dofs, wp)
      case (6); x = row%t_mesh
      case (7); x = row%t_quadrature
      case (8); x = row%t_assembly
      case (9); x = row%t_solve
      case (10); x = row%t_recovery
      case (11); x = row%t_estimate
      case (12); x = row%t_total
      case (13); x = row%err_fe
      case (14); x = row%err_spr
      case (15); x = row%err_sprc
      case (16); x = row%eta_spr
      case (17); x = row%eta_sprc
      case (18); x = row%theta_spr
      case (19); x = row%theta_sprc
      case (20); x = real(row%contact_iterations, wp)
      case (21); x = row%t_contact
      case (22); x = row%contact_measure
      case (23); x = row%p_max_fe
      case (24); x = row%p_max_spr
      case (25); x = row%p_max_sprc
      case (26); x = row%p_max_exact
      case (27); x = row%err_p_fe
      case (28); x = row%err_p_spr
      case (29); x = row%err_p_sprc
      case (30); x = row%p_max_fe_stress
      case (31); x = row%err_p_fe_stress
      case (32); x = row%jump_fe
      case (33); x = row%jump_spr
      case (34); x = row%jump_sprc
      case (36)
         x = report_empty
         if (row%step >= 0) x = real(row%step, wp)
      case (37); x = row%t_adapt
      case default; x = real(row%solver_iterations, wp)
      end select
   end function row_values

   !> Set real column j of a row (j is never an integer column here).
   pure subroutine set_real(row, j, x)
      type(report_row_type), intent(inout) :: row
      integer, intent(in) :: j
      real(wp), intent(in) :: x

      select case (j)
      case (2); row%h = x
      case (6); row%t_mesh = x
      case (7); row%t_quadrature = x
      case (8); row%t_assembly = x
      case (9); row%t_solve = x
      case (10); row%t_recovery = x
      case (11); row%t_estimate = x
      case (12); row%t_total = x
      case (13); row%err_fe = x
      case (14); row%err_spr = x
      case (15); row%err_sprc = x
      case (16); row%eta_spr = x
      case (17); row%eta_sprc = x
      case (18); row%theta_spr = x
      case (19); row%theta_sprc = x
      case (21); row%t_contact = x
      case (22); row%contact_measure = x
      case (23); row%p_max_fe = x
      case (24); row%p_max_spr = x
      case (25); row%p_max_sprc = x
      case (26); row%p_max_exact = x
      case (27); row%err_p_fe = x
      case (28); row%err_p_spr = x
      case (29); row%err_p_sprc = x
      case (30); row%p_max_fe_stress = x
      case (31); row%err_p_fe_stress = x
      case (32); row%jump_fe = x
      case (33); row%jump_spr = x
      case (34); row%jump_sprc = x
      case (37); row%t_adapt = x
      end select
   end subroutine set_real

   !> Set integer column j of a row.
   pure subroutine set_integer(row, j, n)
      type(report_row_type), intent(inout) :: row
      integer, intent(in) :: j
      integer(i8), intent(in) :: n

      select case (j)
      case (1); row%level = int(n)
      case (3); row%elements = n
      case (4); row%cut_elements = n
      case (5); row%dofs = n
      case (20); row%contact_iterations = int(n)
      case (35); row%solver_iterations = int(n)
      case (36); row%step = int(n)
      end select
   end subroutine set_integer

   !> Integer column j of a row.
   pure integer(i8) function row_integer(row, j) result(n)
      type(report_row_type), intent(in) :: row
      integer, intent(in) :: j

      select case (j)
      case (1); n = int(row%level, i8)
      case (3); n = row%elements
      case (4); n = row%cut_elements
      case (5); n = row%dofs
      case (20); n = int(row%contact_iterations, i8)
      case (36); n = int(row%step, i8)
      case default; n = int(row%solver_iterations, i8)
      end select
   end function row_integer

   !> The report as a fixed-width table: a header, a rule, one line per row,
   !> each line ended by a newline (trailing blanks dropped). Columns are right-aligned to a common
   !> width; times, h and theta have 3 significant digits, errors and
   !> estimates es notation; empty cells are blank.
   !> By default the compact table (`compact_columns`), which fits a terminal;
   !> with `wide`, every column of the report, as in the CSV.
   function report_table(rows, wide) result(table)
      type(report_row_type), intent(in) :: rows(:)
      logical, intent(in), optional :: wide
      character(len=:), allocatable :: table
      type :: cell_type
         character(len=:), allocatable :: s
      end type cell_type
      type(cell_type), allocatable :: cells(:, :)
      integer, allocatable :: columns(:), width(:)
      integer :: i, j, n
      character(len=:), allocatable :: line
      character, parameter :: nl = new_line('a')

      columns = compact_columns(rows)
      if (present(wide)) then
         if (wide) columns = report_column_indices(rows)
      end if
      n = size(columns)
      allocate (cells(n, size(rows)), width(n))
      do j = 1, n
         width(j) = len_trim(report_columns(columns(j)))
         do i = 1, size(rows)
            cells(j, i)%s = table_cell(rows(i), columns(j))
            width(j) = max(width(j), len(cells(j, i)%s))
         end do
      end do

      line = ''
      do j = 1, n
         line = line//'  '//right(trim(report_columns(columns(j))), width(j))
      end do
      table = line(3:)//nl
      line = ''
      do j = 1, n
         line = line//'  '//repeat('-', width(j))
      end do
      table = table//line(3:)//nl
      do i = 1, size(rows)
         line = ''
         do j = 1, n
            line = line//'  '//right(cells(j, i)%s, width(j))
         end do
         table = table//trim(line(3:))//nl
      end do
   end function report_table

   !> The columns a user reads first, as indices into `report_columns`: `step`
   !> (adaptive studies), level, dofs, err_fe, the estimates and effectivities
   !> of the recoveries, t_total; of these, the error columns empty in every
   !> row are left out (no exact solution, a recovery not run).
   pure function compact_columns(rows) result(indices)
      type(report_row_type), intent(in) :: rows(:)
      integer, allocatable :: indices(:)
      character(len=*), parameter :: optional_columns(5) = [character(len=10) :: 'err_fe', 'eta_spr', &
         & 'eta_sprc', 'theta_spr', 'theta_sprc']
      integer :: k, i, j

      indices = [integer ::]
      if (any(rows%step >= 0)) indices = [first_adapt_column]
      indices = [indices, findloc(report_columns, 'level'), findloc(report_columns, 'dofs')]
      do k = 1, size(optional_columns)
         j = findloc(report_columns, optional_columns(k), dim=1)
         if (any([(.not. is_empty(row_values(rows(i), j)), i=1, size(rows))])) indices = [indices, j]
      end do
      indices = [indices, findloc(report_columns, 't_total')]
   end function compact_columns

   !> `s` right-aligned in a field of `w` characters.
   pure function right(s, w) result(r)
      character(len=*), intent(in) :: s
      integer, intent(in) :: w
      character(len=max(w, len(s))) :: r
      r = repeat(' ', max(0, w - len(s)))//s
   end function right

   !> Table text of column j of a row.
   function table_cell(row, j) result(s)
      type(report_row_type), intent(in) :: row
      integer, intent(in) :: j
      character(len=:), allocatable :: s
      character(len=32) :: buf
      real(wp) :: x

      x = row_values(row, j)
      if (column_kind(j) == kind_integer .and. .not. is_empty(x)) then
         write (buf, '(i0)') row_integer(row, j)
         s = trim(buf)
         return
      end if
      if (is_empty(x)) then
         s = ''
      else if (column_kind(j) == kind_error) then
         write (buf, '(es10.3)') x
         s = trim(adjustl(buf))
      else
         s = sig3(x)
      end if
   end function table_cell

   !> `x` with 3 significant digits: fixed point for 1e-4 <= |x| < 1e6
   !> ("0.00123", "1.23", "123", "12346"), es notation outside.
   function sig3(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=32) :: buf
      integer :: d, decimals
      real(wp) :: a

      a = abs(x)
      if (a <= 0.0_wp) then
         s = '0'
         return
      end if
      if (.not. ieee_is_finite(x)) then
         write (buf, '(es10.2)') x
         s = trim(adjustl(buf))
         return
      end if
      d = floor(log10(a))
      ! Rounding to 3 digits may carry into the next decade (9.996 -> 10.0).
      if (d >= -4 .and. d <= 5) then
         if (anint(a*10.0_wp**(2 - d)) >= 1000.0_wp) d = d + 1
      end if
      if (d < -4 .or. d > 5) then
         write (buf, '(es9.2)') x
         s = trim(adjustl(buf))
      else if (d >= 2) then
         write (buf, '(i0)') nint(x, i8)
         s = trim(adjustl(buf))
      else
         decimals = 2 - d
         s = fixed_text(x, decimals)
      end if
   end function sig3

   !> CSV text of column j of a row: integers plain, reals with 17
   !> significant digits and a 3-digit exponent (read back bit for bit, by
   !> Fortran and by Python's float), empty cells empty.
   function csv_cell(row, j) result(s)
      type(report_row_type), intent(in) :: row
      integer, intent(in) :: j
      character(len=:), allocatable :: s
      character(len=32) :: buf
      real(wp) :: x

      x = row_values(row, j)
      if (column_kind(j) == kind_integer .and. .not. is_empty(x)) then
         write (buf, '(i0)') row_integer(row, j)
         s = trim(buf)
      else
         s = csv_real(x)
      end if
   end function csv_cell

   !> A real as a CSV cell: 17 significant digits and a 3-digit exponent (read
   !> back bit for bit, by Fortran and by Python's float); '' when empty.
   function csv_real(x) result(s)
      real(wp), intent(in) :: x
      character(len=:), allocatable :: s
      character(len=32) :: buf
      s = ''
      if (is_empty(x)) return
      write (buf, '(es25.16e3)') x
      s = trim(adjustl(buf))
   end function csv_real

   !> Write `rows` as CSV to `path` (replacing it): the header of their columns
   !> (`report_header`), then one line per row. Fails with stat_io naming the path.
   subroutine write_report_csv(path, rows, error)
      character(len=*), intent(in) :: path
      type(report_row_type), intent(in) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat, i, j
      character(len=256) :: msg
      character(len=:), allocatable :: line
      integer, allocatable :: columns(:)

      open (newunit=unit, file=path, status='replace', action='write', form='formatted', &
         iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, 'report CSV: cannot open "'//path//'" for writing: '//trim(msg), stat_io)
         return
      end if
      columns = report_column_indices(rows)
      write (unit, '(a)', iostat=stat, iomsg=msg) report_header(rows)
      do i = 1, size(rows)
         if (stat /= 0) exit
         line = csv_cell(rows(i), columns(1))
         do j = 2, size(columns)
            line = line//','//csv_cell(rows(i), columns(j))
         end do
         write (unit, '(a)', iostat=stat, iomsg=msg) line
      end do
      if (stat /= 0) then
         close (unit)
         call fatal_error(error, 'report CSV: cannot write "'//path//'": '//trim(msg), stat_io)
         return
      end if
      close (unit, iostat=stat, iomsg=msg)
      if (stat /= 0) call fatal_error(error, 'report CSV: cannot close "'//path//'": '//trim(msg), stat_io)
   end subroutine write_report_csv

   !> Read a report CSV written by `write_report_csv` (or by anything that
   !> follows the contract). The header must start with the 19 columns every
   !> report has, in order; the columns after them are read by their names
   !> (the contact columns, which mark the rows as `has_contact`, and
   !> `solver_iterations`, 0 when absent), unknown ones ignored. Empty real
   !> cells become empty; "NaN" is refused (the contract never writes it). A
   !> missing file is stat_io; a malformed line is stat_invalid_input naming
   !> path and line.
   subroutine read_report_csv(path, rows, error)
      character(len=*), intent(in) :: path
      type(report_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat, nline
      character(len=256) :: msg
      character(len=:), allocatable :: line
      type(report_row_type) :: row
      type(report_row_type), allocatable :: buffer(:)
      integer, allocatable :: columns(:)
      integer :: nrows

      allocate (rows(0))
      open (newunit=unit, file=path, status='old', action='read', form='formatted', iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, 'report CSV: cannot open "'//path//'" for reading: '//trim(msg), stat_io)
         return
      end if
      call read_line(unit, line, stat)
      if (stat /= 0) then
         close (unit)
         call fatal_error(error, 'report CSV "'//path//'": no header line', stat_invalid_input)
         return
      end if
      call header_columns(line, path, columns, error)
      if (allocated(error)) then
         close (unit)
         return
      end if
      allocate (buffer(16))
      nrows = 0
      nline = 1
      do
         call read_line(unit, line, stat)
         if (stat /= 0) exit
         nline = nline + 1
         if (len_trim(line) == 0) cycle
         call parse_row(line, path, nline, columns, row, error)
         if (allocated(error)) exit
         if (nrows == size(buffer)) buffer = [buffer, buffer]
         nrows = nrows + 1
         buffer(nrows) = row
      end do
      close (unit)
      if (allocated(error)) return
      if (.not. is_iostat_end(stat)) then
         call fatal_error(error, 'report CSV "'//path//'": read error after line '//itoa(nline), stat_io)
         return
      end if
      rows = buffer(:nrows)
   end subroutine read_report_csv

   !> The column (index into `report_columns`, 0 if unknown) of each field of
   !> a header line, which must start with the 19 columns of every report.
   subroutine header_columns(line, path, columns, error)
      character(len=*), intent(in) :: line, path
      integer, allocatable, intent(out) :: columns(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: field
      integer :: pos, j, k

      allocate (columns(0))
      pos = 1
      do j = 1, n_base_columns
         call next_field(line, pos, field)
         if (field /= trim(report_columns(j))) then
            call fatal_error(error, 'report CSV "'//path//'": header column '//itoa(j)//' is "'//field// &
               '", expected "'//trim(report_columns(j))//'"', stat_invalid_input)
            return
         end if
         columns = [columns, j]
      end do
      do while (pos <= len(line) + 1)
         call next_field(line, pos, field)
         k = 0
         do j = n_base_columns + 1, n_report_columns
            if (field == trim(report_columns(j))) k = j
         end do
         columns = [columns, k]
      end do
   end subroutine header_columns

   !> Parse one data line into a row; `columns` as from `header_columns`.
   subroutine parse_row(line, path, nline, columns, row, error)
      character(len=*), intent(in) :: line, path
      integer, intent(in) :: nline, columns(:)
      type(report_row_type), intent(out) :: row
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: field
      character(len=64) :: buf
      integer :: pos, k, j, stat
      integer(i8) :: n
      real(wp) :: x

      row%has_contact = any(columns >= first_contact_column .and. columns <= last_contact_column)
      pos = 1
      do k = 1, size(columns)
         if (pos > len(line) + 1) then
            call fatal_error(error, 'report CSV "'//path//'" line '//itoa(nline)//': '//itoa(k - 1)// &
               ' columns, expected '//itoa(size(columns)), stat_invalid_input)
            return
         end if
         call next_field(line, pos, field)
         j = columns(k)
         if (j == 0) cycle
         stat = 0
         if (len(field) > len(buf)) stat = 1
         buf = field
         if (column_kind(j) == kind_integer .and. j == first_adapt_column .and. len(field) == 0) then
            ! an empty step: a uniform row
            row%step = -1
         else if (column_kind(j) == kind_integer) then
            if (len(field) == 0) stat = 1
            if (stat == 0) read (buf, '(i64)', iostat=stat) n
            ! every integer column but elements, cut_elements and dofs is a default integer
            if (stat == 0 .and. (j < 3 .or. j > 5) .and. abs(n) > huge(1)) stat = 1
            if (stat == 0) call set_integer(row, j, n)
         else if (len(field) > 0) then
            if (stat == 0) read (buf, '(f64.0)', iostat=stat) x
            if (stat == 0 .and. ieee_is_nan(x)) stat = 1
            if (stat == 0) call set_real(row, j, x)
         end if
         if (stat /= 0) then
            call fatal_error(error, 'report CSV "'//path//'" line '//itoa(nline)//': column '// &
               trim(report_columns(j))//' has bad value "'//field//'"', stat_invalid_input)
            return
         end if
      end do
   end subroutine parse_row

   !> The comma-separated field starting at `pos`, blanks trimmed; `pos`
   !> moves past the comma (to len(line)+2 after the last field).
   subroutine next_field(line, pos, field)
      character(len=*), intent(in) :: line
      integer, intent(inout) :: pos
      character(len=:), allocatable, intent(out) :: field
      integer :: last

      if (pos > len(line)) then
         field = ''
         pos = len(line) + 2
         return
      end if
      last = index(line(pos:), ',')
      if (last == 0) then
         field = trim(adjustl(line(pos:)))
         pos = len(line) + 2
      else
         field = trim(adjustl(line(pos:pos + last - 2)))
         pos = pos + last
      end if
   end subroutine next_field

   !> Read one line of any length; a trailing carriage return is dropped.
   subroutine read_line(unit, line, stat)
      integer, intent(in) :: unit
      character(len=:), allocatable, intent(out) :: line
      integer, intent(out) :: stat
      character(len=512) :: buf
      integer :: n

      line = ''
      do
         read (unit, '(a)', advance='no', iostat=stat, size=n) buf
         line = line//buf(:n)
         if (stat /= 0) exit
      end do
      if (is_iostat_eor(stat)) stat = 0
      if (stat == 0 .and. len(line) > 0) then
         if (line(len(line):) == achar(13)) line = line(:len(line) - 1)
      end if
   end subroutine read_line

   !> `level=4 body=cylinder internal=1234 cut=210 external=604 ...` (doc/scene.md).
   function format_mesh_row(row) result(line)
      type(mesh_row_type), intent(in) :: row
      character(len=:), allocatable :: line
      character(len=32) :: t, tq, m, bm
      integer :: i

      write (t, '(es10.3)') row%t_mesh
      write (tq, '(es10.3)') row%t_quadrature
      write (m, '(es24.16)') row%measure
      write (bm, '(es24.16)') row%boundary_measure
      line = 'level='//itoa(row%level)//' body='//row%body//' internal='//itoa(row%internal)// &
         ' cut='//itoa(row%cut)//' external='//itoa(row%external)//' measure='//trim(adjustl(m))// &
         ' boundary_measure='//trim(adjustl(bm))//' points='//itoa(row%points)//' t_mesh='//trim(adjustl(t))// &
         ' t_quadrature='//trim(adjustl(tq))//' volume_points='//itoa(row%volume_points)// &
         ' surface_points='//itoa(row%surface_points)//' unresolved='//itoa(row%unresolved)
      if (.not. allocated(row%surfaces)) return
      do i = 1, size(row%surfaces)
         write (m, '(es24.16)') row%surfaces(i)%measure
         line = line//' surface_measure['//row%surfaces(i)%name//']='//trim(adjustl(m))
      end do
   end function format_mesh_row

end module sprc_io_report
