!> C API, study reports: `sprc_report` holds the rows of a study (doc/scene.md,
!> "Report"), one per level, and is read cell by cell or column by column.
!> Rows and columns are 0-based; columns are named as in the report's CSV
!> header. Every value is a double (integer columns converted exactly); an
!> empty cell (does not apply) is a quiet NaN.
module sprc_capi_report
   use, intrinsic :: iso_c_binding, only: c_ptr, c_int, c_double, c_null_ptr, c_associated, c_f_pointer
   use sprc_core_error, only: stat_invalid_input
   use sprc_core_text, only: itoa
   use sprc_io_report, only: report_row_type, report_column, report_columns, report_column_indices, report_empty
   use sprc_capi_error, only: capi_error_type, get_capi_error, set_capi_error
   use sprc_capi_string, only: c_string, copy_to_buffer
   implicit none
   private

   public :: capi_report_type
   public :: sprc_get_report_rows, sprc_get_report_columns, sprc_get_report_column, sprc_get_report_value, &
      & sprc_get_report_values, sprc_delete_report

   !> What an `sprc_report` handle points to.
   type :: capi_report_type
      type(report_row_type), allocatable :: rows(:)
   end type capi_report_type

contains

   !> Number of rows (levels); -1 on error.
   function sprc_get_report_rows(errh, reph) result(n) bind(C, name='sprc_get_report_rows')
      type(c_ptr), value :: errh, reph
      integer(c_int) :: n
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep

      n = -1
      if (.not. get_handles(errh, reph, 'sprc_get_report_rows', err, rep)) return
      n = size(rep%rows)
   end function sprc_get_report_rows

   !> Number of columns (the contact columns count only in a report with
   !> contact); -1 on error.
   function sprc_get_report_columns(errh, reph) result(n) bind(C, name='sprc_get_report_columns')
      type(c_ptr), value :: errh, reph
      integer(c_int) :: n
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep

      n = -1
      if (.not. get_handles(errh, reph, 'sprc_get_report_columns', err, rep)) return
      n = size(report_column_indices(rep%rows))
   end function sprc_get_report_columns

   !> The name of column `index` (0-based) into `buf` of `*size` bytes,
   !> truncated and NUL-terminated like `sprc_get_error`.
   subroutine sprc_get_report_column(errh, reph, index, buf, size) bind(C, name='sprc_get_report_column')
      type(c_ptr), value :: errh, reph
      integer(c_int), value :: index
      type(c_ptr), value :: buf, size
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep
      integer, allocatable :: columns(:)

      if (.not. get_handles(errh, reph, 'sprc_get_report_column', err, rep)) return
      columns = report_column_indices(rep%rows)
      ! (`size` is a dummy argument here: the intrinsic is not reachable)
      if (index < 0 .or. index >= n_columns(columns)) then
         call set_capi_error(err, message='sprc_get_report_column: column index '//itoa(index)// &
            ' is out of range 0..'//itoa(n_columns(columns) - 1), stat=stat_invalid_input)
         return
      end if
      call copy_to_buffer(trim(report_columns(columns(index + 1))), buf, size)
   end subroutine sprc_get_report_column

   !> The cell of row `row` (0-based) in the column named `column`; NaN for
   !> an empty cell, and NaN with the error set for a bad row or column.
   function sprc_get_report_value(errh, reph, row, column) result(x) bind(C, name='sprc_get_report_value')
      type(c_ptr), value :: errh, reph
      integer(c_int), value :: row
      type(c_ptr), value :: column
      real(c_double) :: x
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep
      character(len=:), allocatable :: name
      real(c_double) :: values(1)

      x = report_empty
      if (.not. get_handles(errh, reph, 'sprc_get_report_value', err, rep)) return
      if (.not. get_column(err, rep, column, 'sprc_get_report_value', name)) return
      if (row < 0 .or. row >= size(rep%rows)) then
         call set_capi_error(err, message='sprc_get_report_value: row '//itoa(row)//' is out of range 0..'// &
            itoa(size(rep%rows) - 1), stat=stat_invalid_input)
         return
      end if
      values = report_column(rep%rows(row + 1:row + 1), name)
      x = values(1)
   end function sprc_get_report_value

   !> The column named `column` into `values[n]`; `n` must be the number of
   !> rows. Empty cells are NaN. On error `values` is left unchanged.
   subroutine sprc_get_report_values(errh, reph, column, values, n) bind(C, name='sprc_get_report_values')
      type(c_ptr), value :: errh, reph, column, values
      integer(c_int), value :: n
      type(capi_error_type), pointer :: err
      type(capi_report_type), pointer :: rep
      character(len=:), allocatable :: name
      real(c_double), pointer :: out(:)

      if (.not. get_handles(errh, reph, 'sprc_get_report_values', err, rep)) return
      if (.not. get_column(err, rep, column, 'sprc_get_report_values', name)) return
      if (n /= size(rep%rows)) then
         call set_capi_error(err, message='sprc_get_report_values: n = '//itoa(n)//' but the report has '// &
            itoa(size(rep%rows))//' rows', stat=stat_invalid_input)
         return
      end if
      if (.not. c_associated(values)) then
         call set_capi_error(err, message='sprc_get_report_values: values is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(values, out, [n])
      out = report_column(rep%rows, name)
   end subroutine sprc_get_report_values

   !> Free the report `*ptr` and set it to NULL; NULL `ptr` or `*ptr` is a no-op.
   subroutine sprc_delete_report(ptr) bind(C, name='sprc_delete_report')
      type(c_ptr), value :: ptr
      type(c_ptr), pointer :: handle
      type(capi_report_type), pointer :: rep

      if (.not. c_associated(ptr)) return
      call c_f_pointer(ptr, handle)
      if (.not. c_associated(handle)) return
      call c_f_pointer(handle, rep)
      deallocate (rep)
      handle = c_null_ptr
   end subroutine sprc_delete_report

   !> The objects behind an error and a report handle. False when the error
   !> handle is NULL (nothing to report to) or the report handle is NULL
   !> (reported in the error, naming the entry point).
   logical function get_handles(errh, reph, entry, err, rep) result(ok)
      type(c_ptr), intent(in) :: errh, reph
      character(len=*), intent(in) :: entry
      type(capi_error_type), pointer, intent(out) :: err
      type(capi_report_type), pointer, intent(out) :: rep

      rep => null()
      ok = get_capi_error(errh, err)
      if (.not. ok) return
      ok = c_associated(reph)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the report handle is NULL', stat=stat_invalid_input)
         return
      end if
      call c_f_pointer(reph, rep)
   end function get_handles

   !> The column name behind a C string, checked against the report's columns.
   logical function get_column(err, rep, column, entry, name) result(ok)
      type(capi_error_type), intent(inout) :: err
      type(capi_report_type), intent(in) :: rep
      type(c_ptr), intent(in) :: column
      character(len=*), intent(in) :: entry
      character(len=:), allocatable, intent(out) :: name
      integer, allocatable :: columns(:)
      integer :: j

      call c_string(column, name, ok)
      if (.not. ok) then
         call set_capi_error(err, message=entry//': the column name is NULL', stat=stat_invalid_input)
         return
      end if
      ! Not findloc: gfortran 12 finds nothing when the value is a deferred-length dummy.
      ok = .false.
      columns = report_column_indices(rep%rows)
      do j = 1, size(columns)
         ok = len(name) == len_trim(report_columns(columns(j))) .and. trim(report_columns(columns(j))) == name
         if (ok) exit
      end do
      if (.not. ok) call set_capi_error(err, message=entry//': no report column is named "'//name// &
         '" (columns: '//column_list(columns)//')', stat=stat_invalid_input)
   end function get_column

   pure integer function n_columns(columns)
      integer, intent(in) :: columns(:)
      n_columns = size(columns)
   end function n_columns

   function column_list(columns) result(s)
      integer, intent(in) :: columns(:)
      character(len=:), allocatable :: s
      integer :: j
      s = trim(report_columns(columns(1)))
      do j = 2, size(columns)
         s = s//', '//trim(report_columns(columns(j)))
      end do
   end function column_list

end module sprc_capi_report
