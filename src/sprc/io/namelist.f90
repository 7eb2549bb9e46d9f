!> A strict reader of the Fortran namelist format that remembers line numbers.
!>
!> gfortran's intrinsic namelist READ can neither name the field of a bad value
!> nor give a line number, so sprc parses namelist text itself. It accepts a
!> subset of the standard format — every file it accepts is also valid Fortran
!> namelist input:
!>
!> - groups `&name key = value[, value ...] ... /`, spanning lines;
!> - `!` comments; values separated by commas and/or blanks;
!> - strings in '...' or "..." (a doubled quote stands for one quote);
!> - integers, reals (`e`/`d` exponents, leading sign), logicals
!>   (`.true.`, `.false.`, `t`, `f`, `.t.`, `.f.`) and the repeat form `r*c`;
!> - group names and keys are case-insensitive.
!>
!> Rejected with a message naming file, line, group, key and value: NaN and
!> Inf, null values, subscripts, undelimited strings, unknown groups, duplicate
!> keys, unterminated groups or strings, text outside groups, non-text bytes.
!>
!> Text in, structures out: the only I/O is `read_text_file`.
module sprc_io_namelist
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: itoa, lower
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_io_file, only: file_size, read_bytes
   implicit none
   private

   public :: nml_value_type, nml_item_type, nml_group_type
   public :: nml_integer, nml_real, nml_string, nml_logical
   public :: max_text_size, max_repeat, max_groups, max_items, max_values
   public :: read_text_file, check_text, parse_namelist
   public :: nml_get, nml_get_array, nml_has, nml_check_consumed
   public :: nml_field_error, nml_group_error, nml_item_text

   !> Token kinds of a value.
   integer, parameter :: nml_integer = 1, nml_real = 2, nml_string = 3, nml_logical = 4

   !> Largest file `read_text_file` accepts (bytes): a scene is a few kilobytes.
   integer, parameter :: max_text_size = 16*1024*1024
   !> Largest repeat count `r` of `r*c`: bounds memory when a getter expands it.
   integer, parameter :: max_repeat = 100000
   !> Most groups in a text, keys in a group, values (repeats expanded) of a key.
   !> Far above any scene; they keep hostile input from costing quadratic time
   !> in duplicate checks or overflowing value counts.
   integer, parameter :: max_groups = 10000, max_items = 1000, max_values = 100000

   !> One value constant of an item, possibly repeated (`r*c`).
   type :: nml_value_type
      !> One of `nml_integer`, `nml_real`, `nml_string`, `nml_logical`.
      integer :: kind = 0
      !> The constant as written (with quotes and repeat count), for messages.
      character(len=:), allocatable :: text
      !> How many times the constant stands (r of r*c; 1 without repeat).
      integer :: count = 1
      !> Integer value (kind `nml_integer`).
      integer :: ival = 0
      !> Real value (kinds `nml_integer` and `nml_real`).
      real(wp) :: rval = 0.0_wp
      !> Logical value (kind `nml_logical`).
      logical :: lval = .false.
      !> String value without quotes (kind `nml_string`).
      character(len=:), allocatable :: sval
   end type nml_value_type

   !> One `key = values` item of a group.
   type :: nml_item_type
      !> Key in lower case.
      character(len=:), allocatable :: key
      !> Line of the key in the source.
      integer :: line = 0
      !> The values in order.
      type(nml_value_type), allocatable :: values(:)
      !> Set when a getter has read the item.
      logical :: consumed = .false.
   end type nml_item_type

   !> One `&name ... /` group.
   type :: nml_group_type
      !> Group name in lower case, without `&`.
      character(len=:), allocatable :: name
      !> Name of the source (file name) for messages.
      character(len=:), allocatable :: source
      !> Line of `&name`.
      integer :: line = 0
      !> The items in file order.
      type(nml_item_type), allocatable :: items(:)
      !> Keys the schema asked for, comma separated, for unknown-key messages.
      character(len=:), allocatable :: schema
   end type nml_group_type

   !> Read a scalar value of a key: real, integer, string or logical.
   interface nml_get
      module procedure :: get_real, get_integer, get_string, get_logical
   end interface nml_get

   !> Read an array value of a key with a count in [min_count, max_count].
   interface nml_get_array
      module procedure :: get_real_array, get_integer_array
   end interface nml_get_array

   !> Position of the scanner in the text.
   type :: scanner_type
      integer :: pos = 1
      integer :: line = 1
   end type scanner_type

   character(len=*), parameter :: blanks = ' '//achar(9)//achar(10)//achar(12)//achar(13)

contains

   !> Read a whole text file into `text`. A missing or unreadable file is
   !> `stat_io`; binary content (NUL or control bytes, invalid UTF-8) and files
   !> over `max_text_size` bytes are `stat_invalid_input`.
   subroutine read_text_file(path, text, error)
      !> Path of the file.
      character(len=*), intent(in) :: path
      !> The file's bytes.
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: size

      call file_size(path, size, error)
      if (allocated(error)) return
      if (size > int(max_text_size, i8)) then
         call fatal_error(error, "'"//path//"': "//itoa(int(size / 1024_i8))// &
            & ' KiB is too large for a text input file (limit '//itoa(max_text_size / 1024)//' KiB)')
         return
      end if
      call read_bytes(path, 1_i8, size, text, error)
      if (allocated(error)) return
      call check_text(text, path, error)
   end subroutine read_text_file

   !> Fail unless `text` is plain text: no NUL or other control bytes besides
   !> tab, line feed, form feed and carriage return, and valid UTF-8.
   subroutine check_text(text, source, error)
      character(len=*), intent(in) :: text
      !> Name of the source for messages.
      character(len=*), intent(in) :: source
      type(error_type), allocatable, intent(out) :: error
      integer :: i, line, code, ntrail, k

      line = 1
      i = 1
      do while (i <= len(text))
         code = iachar(text(i:i))
         if (code == 10) line = line + 1
         if (code == 0) then
            call fatal_error(error, source//':'//itoa(line)//': not a text file: NUL byte at offset ' &
               & //itoa(i - 1))
            return
         else if ((code < 32 .and. index(blanks, text(i:i)) == 0) .or. code == 127) then
            call fatal_error(error, source//':'//itoa(line)//': not a text file: control byte ' &
               & //itoa(code)//' at offset '//itoa(i - 1))
            return
         else if (code >= 128) then
            ! Lead byte of a UTF-8 sequence: count the continuation bytes it needs.
            select case (code)
            case (194:223); ntrail = 1
            case (224:239); ntrail = 2
            case (240:244); ntrail = 3
            case default; ntrail = -1
            end select
            if (ntrail > 0 .and. i + ntrail <= len(text)) then
               do k = i + 1, i + ntrail
                  if (iachar(text(k:k)) < 128 .or. iachar(text(k:k)) > 191) ntrail = -1
               end do
            else
               ntrail = -1
            end if
            if (ntrail < 0) then
               call fatal_error(error, source//':'//itoa(line)// &
                  & ': not a text file: invalid UTF-8 byte '//itoa(code)//' at offset '//itoa(i - 1))
               return
            end if
            i = i + ntrail
         end if
         i = i + 1
      end do
   end subroutine check_text

   !> Parse namelist text into its groups, in file order.
   subroutine parse_namelist(text, source, groups, error, known_groups)
      !> The namelist text.
      character(len=*), intent(in) :: text
      !> Name of the source (file name) for messages.
      character(len=*), intent(in) :: source
      !> The groups found.
      type(nml_group_type), allocatable, intent(out) :: groups(:)
      type(error_type), allocatable, intent(out) :: error
      !> Group names allowed (lower case, trailing blanks ignored); absent: any.
      character(len=*), intent(in), optional :: known_groups(:)
      type(scanner_type) :: s
      type(nml_group_type) :: group
      integer :: ngroup

      allocate (groups(0))
      call check_text(text, source, error)
      if (allocated(error)) return
      ngroup = 0
      do
         call skip_blanks(text, s)
         if (s%pos > len(text)) exit
         if (text(s%pos:s%pos) /= '&') then
            call fatal_error(error, source//':'//itoa(s%line)//": unexpected text '"//snippet(text, s%pos)// &
               & "' outside a namelist group (a group starts with &name and ends with /)")
            return
         end if
         if (ngroup == max_groups) then
            call fatal_error(error, source//':'//itoa(s%line)//': more than '//itoa(max_groups)// &
               & ' namelist groups')
            return
         end if
         call parse_group(text, source, s, group, error, known_groups)
         if (allocated(error)) return
         call append_group(groups, ngroup, group)
      end do
      groups = groups(1:ngroup)
   end subroutine parse_namelist

   subroutine parse_group(text, source, s, group, error, known_groups)
      character(len=*), intent(in) :: text, source
      type(scanner_type), intent(inout) :: s
      type(nml_group_type), intent(out) :: group
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in), optional :: known_groups(:)
      type(nml_item_type) :: item
      integer :: nitem, i
      character(len=:), allocatable :: where

      group%source = source
      group%line = s%line
      group%schema = ''
      allocate (group%items(0))
      nitem = 0
      s%pos = s%pos + 1
      call read_name(text, s, group%name)
      if (len(group%name) == 0) then
         call fatal_error(error, source//':'//itoa(s%line)//": expected a group name after '&', found '"// &
            & snippet(text, s%pos)//"'")
         return
      end if
      where = source//':'//itoa(group%line)//': &'//group%name//': '
      if (present(known_groups)) then
         if (.not. any(known_groups == group%name)) then
            call fatal_error(error, where//'unknown group; valid groups: '//join_names(known_groups, '&'))
            return
         end if
      end if
      do
         call skip_blanks(text, s)
         if (s%pos > len(text)) then
            call fatal_error(error, where//"unterminated group: end of file before the closing '/'")
            return
         end if
         select case (text(s%pos:s%pos))
         case ('/')
            s%pos = s%pos + 1
            call check_line_end(text, source, s, group, error)
            exit
         case ('&')
            call fatal_error(error, where//"unterminated group: '&"//snippet(text, s%pos + 1)// &
               & "' on line "//itoa(s%line)//" starts before the closing '/'")
            return
         end select
         if (nitem == max_items) then
            call fatal_error(error, where//'more than '//itoa(max_items)//' keys in one group')
            return
         end if
         call parse_item(text, s, group, item, error)
         if (allocated(error)) return
         do i = 1, nitem
            if (group%items(i)%key == item%key) then
               call fatal_error(error, source//':'//itoa(item%line)//': &'//group%name//': '//item%key// &
                  & ' = '//values_text(item%values)//': duplicate key (first given on line '// &
                  & itoa(group%items(i)%line)//')')
               return
            end if
         end do
         call append_item(group%items, nitem, item)
      end do
      group%items = group%items(1:nitem)
   end subroutine parse_group

   !> After a group's closing `/` only blanks or a comment may follow on the
   !> line: Fortran skips the rest of that line, so a group there would be lost.
   subroutine check_line_end(text, source, s, group, error)
      character(len=*), intent(in) :: text, source
      type(scanner_type), intent(in) :: s
      type(nml_group_type), intent(in) :: group
      type(error_type), allocatable, intent(out) :: error
      integer :: j
      j = s%pos
      do while (j <= len(text))
         if (text(j:j) /= ' ' .and. text(j:j) /= achar(9)) exit
         j = j + 1
      end do
      if (j > len(text)) return
      if (index('!'//achar(10)//achar(13), text(j:j)) > 0) return
      call fatal_error(error, source//':'//itoa(s%line)//': &'//group%name//": text '"//snippet(text, j)// &
         & "' after the closing '/' on the same line: Fortran ignores the rest of that line; start it on a new line")
   end subroutine check_line_end

   !> Parse `key = value, ...` at the scanner position.
   subroutine parse_item(text, s, group, item, error)
      character(len=*), intent(in) :: text
      type(scanner_type), intent(inout) :: s
      type(nml_group_type), intent(in) :: group
      type(nml_item_type), intent(out) :: item
      type(error_type), allocatable, intent(out) :: error
      type(nml_value_type) :: value
      character(len=:), allocatable :: where
      integer :: nvalue, total

      where = group%source//':'//itoa(s%line)//': &'//group%name//': '
      item%line = s%line
      call read_name(text, s, item%key)
      if (len(item%key) == 0) then
         call fatal_error(error, where//"expected a key name or the closing '/', found '"//snippet(text, s%pos)//"'")
         return
      end if
      where = where//item%key//': '
      call skip_blanks(text, s)
      if (s%pos <= len(text)) then
         select case (text(s%pos:s%pos))
         case ('(')
            call fatal_error(error, where//'subscripts and substrings are not supported; give the whole array')
            return
         case ('%')
            call fatal_error(error, where//'derived-type components are not supported')
            return
         end select
      end if
      if (s%pos > len(text)) then
         call fatal_error(error, where//"expected '=' after the key, found end of file")
         return
      end if
      if (text(s%pos:s%pos) /= '=') then
         call fatal_error(error, where//"expected '=' after the key, found '"//snippet(text, s%pos)//"'")
         return
      end if
      s%pos = s%pos + 1
      allocate (item%values(0))
      nvalue = 0
      total = 0
      do
         call skip_blanks(text, s)
         if (s%pos > len(text)) exit
         if (text(s%pos:s%pos) == '/' .or. text(s%pos:s%pos) == '&') exit
         if (starts_key(text, s%pos)) exit
         if (text(s%pos:s%pos) == ',') then
            call fatal_error(error, group%source//':'//itoa(s%line)//': &'//group%name//': '//item%key// &
               & ': empty value before a comma (null values are not supported)')
            return
         end if
         call parse_value(text, s, value, error)
         if (allocated(error)) then
            error%message = group%source//':'//itoa(s%line)//': &'//group%name//': '//item%key//' = '// &
               & error%message
            return
         end if
         call append_value(item%values, nvalue, value)
         total = total + value%count
         if (total > max_values) then
            call fatal_error(error, group%source//':'//itoa(item%line)//': &'//group%name//': '//item%key// &
               & ': more than '//itoa(max_values)//' values')
            return
         end if
         if (s%pos <= len(text)) then
            if (text(s%pos:s%pos) == ',') s%pos = s%pos + 1
         end if
      end do
      item%values = item%values(1:nvalue)
      if (nvalue == 0) call fatal_error(error, where//"no value after '='")
   end subroutine parse_item

   !> Parse one value constant (with optional repeat count); the message of an
   !> error starts with the offending text, the caller prefixes the location.
   subroutine parse_value(text, s, value, error)
      character(len=*), intent(in) :: text
      type(scanner_type), intent(inout) :: s
      type(nml_value_type), intent(out) :: value
      type(error_type), allocatable, intent(out) :: error
      integer :: start, j, ios
      character(len=:), allocatable :: word

      start = s%pos
      value%count = 1
      j = s%pos
      do while (j <= len(text))
         if (.not. is_digit(text(j:j))) exit
         j = j + 1
      end do
      if (j > s%pos .and. j <= len(text)) then
         if (text(j:j) == '*') then
            if (j - s%pos > 6) then
               value%count = max_repeat + 1
            else
               read (text(s%pos:j - 1), *, iostat=ios) value%count
            end if
            if (value%count < 1 .or. value%count > max_repeat) then
               call fatal_error(error, text(s%pos:j)//': repeat count must be 1 to '//itoa(max_repeat))
               return
            end if
            s%pos = j + 1
            if (s%pos > len(text)) then
               call fatal_error(error, text(start:s%pos - 1)//': null values (r*) are not supported')
               return
            else if (index(blanks//',/!', text(s%pos:s%pos)) > 0) then
               call fatal_error(error, text(start:s%pos - 1)//': null values (r*) are not supported')
               return
            end if
         end if
      end if
      if (text(s%pos:s%pos) == "'" .or. text(s%pos:s%pos) == '"') then
         call parse_string(text, s, value, error)
         if (allocated(error)) return
         value%text = text(start:s%pos - 1)
      else
         j = s%pos
         do while (j <= len(text))
            if (index(blanks//',/!', text(j:j)) > 0) exit
            j = j + 1
         end do
         word = text(s%pos:j - 1)
         s%pos = j
         value%text = text(start:j - 1)
         call classify_word(word, value, error)
         if (allocated(error)) then
            error%message = value%text//': '//error%message
            return
         end if
      end if
      if (s%pos <= len(text)) then
         if (index(blanks//',/!', text(s%pos:s%pos)) == 0) then
            call fatal_error(error, text(start:s%pos - 1)//": expected a blank or ',' after the value, found '"// &
               & snippet(text, s%pos)//"'")
         end if
      end if
   end subroutine parse_value

   !> Parse a quoted string; a doubled quote stands for one; no line breaks.
   subroutine parse_string(text, s, value, error)
      character(len=*), intent(in) :: text
      type(scanner_type), intent(inout) :: s
      type(nml_value_type), intent(inout) :: value
      type(error_type), allocatable, intent(out) :: error
      character(len=1) :: quote
      integer :: j, n, closing, k

      quote = text(s%pos:s%pos)
      ! First pass: find the closing quote and the length of the value.
      j = s%pos + 1
      n = 0
      closing = 0
      do while (j <= len(text))
         if (text(j:j) == achar(10) .or. text(j:j) == achar(13)) exit
         if (text(j:j) == quote) then
            if (j < len(text)) then
               if (text(j + 1:j + 1) == quote) then
                  n = n + 1
                  j = j + 2
                  cycle
               end if
            end if
            closing = j
            exit
         end if
         n = n + 1
         j = j + 1
      end do
      if (closing == 0) then
         call fatal_error(error, snippet(text, s%pos)//': unterminated string: no closing '//quote// &
            & ' before the end of the line')
         return
      end if
      allocate (character(len=n) :: value%sval)
      k = 0
      j = s%pos + 1
      do while (j < closing)
         k = k + 1
         value%sval(k:k) = text(j:j)
         if (text(j:j) == quote) j = j + 1
         j = j + 1
      end do
      value%kind = nml_string
      s%pos = closing + 1
   end subroutine parse_string

   !> Classify an unquoted constant: logical, integer or finite real.
   subroutine classify_word(word, value, error)
      character(len=*), intent(in) :: word
      type(nml_value_type), intent(inout) :: value
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: w, body
      integer :: ios, i

      w = lower(word)
      select case (w)
      case ('t', '.t', '.t.', '.true.')
         value%kind = nml_logical
         value%lval = .true.
         return
      case ('f', '.f', '.f.', '.false.')
         value%kind = nml_logical
         value%lval = .false.
         return
      end select
      body = w
      if (len(body) > 0) then
         if (body(1:1) == '+' .or. body(1:1) == '-') body = body(2:)
      end if
      if (index(body, 'nan') == 1 .or. index(body, 'inf') == 1) then
         call fatal_error(error, 'not a finite number (NaN and Inf are not accepted)')
         return
      end if
      if (is_integer_syntax(w)) then
         value%kind = nml_integer
         read (w, *, iostat=ios) value%rval
         if (ios /= 0) value%kind = 0
         if (len(body) <= 9) then
            read (w, *, iostat=ios) value%ival
         else
            ! Too long for a default integer: still a valid real constant.
            value%kind = nml_real
         end if
      else if (is_real_syntax(w)) then
         do i = 1, len(w)
            if (w(i:i) == 'd') w(i:i) = 'e'
         end do
         value%kind = nml_real
         read (w, *, iostat=ios) value%rval
         if (ios /= 0) value%kind = 0
      end if
      if (value%kind == 0) then
         call fatal_error(error, 'not a number, logical or quoted string (strings must be quoted)')
      else if (.not. ieee_is_finite(value%rval)) then
         call fatal_error(error, 'not a finite number (out of the range of double precision)')
      end if
   end subroutine classify_word

   pure logical function is_integer_syntax(w) result(ok)
      character(len=*), intent(in) :: w
      integer :: i0
      i0 = 1
      if (len(w) > 0) then
         if (w(1:1) == '+' .or. w(1:1) == '-') i0 = 2
      end if
      ok = len(w) >= i0 .and. verify(w(i0:), '0123456789') == 0
   end function is_integer_syntax

   !> [sign] (digits [. digits] | . digits) [(e|d) [sign] digits]
   pure logical function is_real_syntax(w) result(ok)
      character(len=*), intent(in) :: w
      integer :: i, ndigit

      ok = .false.
      i = 1
      if (len(w) == 0) return
      if (w(1:1) == '+' .or. w(1:1) == '-') i = 2
      ndigit = 0
      call skip_digits(w, i, ndigit)
      if (i <= len(w)) then
         if (w(i:i) == '.') then
            i = i + 1
            call skip_digits(w, i, ndigit)
         end if
      end if
      if (ndigit == 0) return
      if (i <= len(w)) then
         if (w(i:i) /= 'e' .and. w(i:i) /= 'd') return
         i = i + 1
         if (i <= len(w)) then
            if (w(i:i) == '+' .or. w(i:i) == '-') i = i + 1
         end if
         ndigit = 0
         call skip_digits(w, i, ndigit)
         if (ndigit == 0) return
      end if
      ok = i > len(w)
   end function is_real_syntax

   pure subroutine skip_digits(w, i, ndigit)
      character(len=*), intent(in) :: w
      integer, intent(inout) :: i, ndigit
      do while (i <= len(w))
         if (.not. is_digit(w(i:i))) exit
         i = i + 1
         ndigit = ndigit + 1
      end do
   end subroutine skip_digits

   !> Skip blanks, line breaks and `!` comments.
   subroutine skip_blanks(text, s)
      character(len=*), intent(in) :: text
      type(scanner_type), intent(inout) :: s
      do while (s%pos <= len(text))
         if (text(s%pos:s%pos) == '!') then
            do while (s%pos <= len(text))
               if (text(s%pos:s%pos) == achar(10)) exit
               s%pos = s%pos + 1
            end do
         else if (index(blanks, text(s%pos:s%pos)) == 0) then
            exit
         end if
         if (s%pos > len(text)) exit
         if (text(s%pos:s%pos) == achar(10)) s%line = s%line + 1
         s%pos = s%pos + 1
      end do
   end subroutine skip_blanks

   !> Read a Fortran name (letter, then letters, digits, underscores) in lower
   !> case; empty if none starts at the position.
   subroutine read_name(text, s, name)
      character(len=*), intent(in) :: text
      type(scanner_type), intent(inout) :: s
      character(len=:), allocatable, intent(out) :: name
      integer :: j
      j = name_end(text, s%pos)
      name = lower(text(s%pos:j - 1))
      s%pos = j
   end subroutine read_name

   !> One past the end of the name starting at `pos` (= pos if none).
   pure integer function name_end(text, pos) result(j)
      character(len=*), intent(in) :: text
      integer, intent(in) :: pos
      j = pos
      if (j > len(text)) return
      if (.not. is_letter(text(j:j))) return
      do while (j <= len(text))
         if (.not. (is_letter(text(j:j)) .or. is_digit(text(j:j)) .or. text(j:j) == '_')) exit
         j = j + 1
      end do
   end function name_end

   !> Whether a name followed by `=`, `(` or `%` starts at `pos`: the next key.
   logical function starts_key(text, pos) result(yes)
      character(len=*), intent(in) :: text
      integer, intent(in) :: pos
      type(scanner_type) :: s
      yes = .false.
      s%pos = name_end(text, pos)
      if (s%pos == pos) return
      call skip_blanks(text, s)
      if (s%pos > len(text)) return
      yes = index('=(%', text(s%pos:s%pos)) > 0
   end function starts_key

   !> Whether the group has the key.
   pure logical function nml_has(group, key)
      type(nml_group_type), intent(in) :: group
      character(len=*), intent(in) :: key
      nml_has = find_item(group, key) > 0
   end function nml_has

   pure integer function find_item(group, key) result(k)
      type(nml_group_type), intent(in) :: group
      character(len=*), intent(in) :: key
      do k = 1, size(group%items)
         if (group%items(k)%key == key) return
      end do
      k = 0
   end function find_item

   !> Note that the schema knows `key`, mark the item read and return its index.
   subroutine lookup(group, key, k)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      integer, intent(out) :: k
      if (len(group%schema) == 0) then
         group%schema = key
      else if (index(', '//group%schema//',', ', '//key//',') == 0) then
         group%schema = group%schema//', '//key
      end if
      k = find_item(group, key)
      if (k > 0) group%items(k)%consumed = .true.
   end subroutine lookup

   !> Number of scalar values of an item (repeat counts expanded).
   pure integer function value_count(item)
      type(nml_item_type), intent(in) :: item
      value_count = sum(item%values%count)
   end function value_count

   !> Check that the item holds `min_count` to `max_count` values of kind `wanted`
   !> (integers are accepted where reals are asked for).
   subroutine check_item(group, k, wanted, min_count, max_count, error)
      type(nml_group_type), intent(in) :: group
      integer, intent(in) :: k, wanted, min_count, max_count
      type(error_type), allocatable, intent(out) :: error
      integer :: i, n
      logical :: ok
      character(len=*), parameter :: names(4) = [character(len=18) :: 'an integer', 'a real number', &
         & 'a quoted string', 'a logical (t or f)']

      do i = 1, size(group%items(k)%values)
         ok = group%items(k)%values(i)%kind == wanted
         if (wanted == nml_real) ok = ok .or. group%items(k)%values(i)%kind == nml_integer
         if (.not. ok) then
            call nml_field_error(group, group%items(k)%key, 'expected '//trim(names(wanted))// &
               & ', got '//group%items(k)%values(i)%text, error)
            return
         end if
      end do
      n = value_count(group%items(k))
      if (n < min_count .or. n > max_count) then
         if (min_count == max_count .and. min_count == 1) then
            call nml_field_error(group, group%items(k)%key, 'expected one value, got '//itoa(n), error)
         else if (min_count == max_count) then
            call nml_field_error(group, group%items(k)%key, 'expected '//itoa(min_count)// &
               & ' values, got '//itoa(n), error)
         else
            call nml_field_error(group, group%items(k)%key, 'expected '//itoa(min_count)//' to '// &
               & itoa(max_count)//' values, got '//itoa(n), error)
         end if
      end if
   end subroutine check_item

   !> The one body of every getter: the index k of the item of `key`, checked to
   !> hold `min_count` to `max_count` values of kind `wanted` (k = 0 when the key
   !> is absent or the check fails; `found` says whether it is present).
   subroutine get_item(group, key, wanted, min_count, max_count, k, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      integer, intent(in) :: wanted, min_count, max_count
      integer, intent(out) :: k
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      call lookup(group, key, k)
      found = k > 0
      if (.not. found) return
      call check_item(group, k, wanted, min_count, max_count, error)
      if (allocated(error)) k = 0
   end subroutine get_item

   !> Index into `item%values` of each scalar value, repeat counts expanded.
   pure function expanded(item) result(map)
      type(nml_item_type), intent(in) :: item
      integer, allocatable :: map(:)
      integer :: i, n
      allocate (map(value_count(item)))
      n = 0
      do i = 1, size(item%values)
         map(n + 1:n + item%values(i)%count) = i
         n = n + item%values(i)%count
      end do
   end function expanded

   !> A real scalar; `value` is unchanged when the key is absent.
   subroutine get_real(group, key, value, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      real(wp), intent(inout) :: value
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      call get_item(group, key, nml_real, 1, 1, k, found, error)
      if (k > 0) value = group%items(k)%values(1)%rval
   end subroutine get_real

   !> An integer scalar; `value` is unchanged when the key is absent.
   subroutine get_integer(group, key, value, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      integer, intent(inout) :: value
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      call get_item(group, key, nml_integer, 1, 1, k, found, error)
      if (k > 0) value = group%items(k)%values(1)%ival
   end subroutine get_integer

   !> A string scalar; `value` is unchanged when the key is absent.
   subroutine get_string(group, key, value, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      character(len=:), allocatable, intent(inout) :: value
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      call get_item(group, key, nml_string, 1, 1, k, found, error)
      if (k > 0) value = group%items(k)%values(1)%sval
   end subroutine get_string

   !> A logical scalar; `value` is unchanged when the key is absent.
   subroutine get_logical(group, key, value, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      logical, intent(inout) :: value
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      call get_item(group, key, nml_logical, 1, 1, k, found, error)
      if (k > 0) value = group%items(k)%values(1)%lval
   end subroutine get_logical

   !> A real array of `min_count` to `max_count` values (equal for an exact
   !> count); `values` is unchanged when the key is absent.
   subroutine get_real_array(group, key, values, min_count, max_count, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      real(wp), allocatable, intent(inout) :: values(:)
      integer, intent(in) :: min_count, max_count
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      call get_item(group, key, nml_real, min_count, max_count, k, found, error)
      if (k > 0) values = group%items(k)%values(expanded(group%items(k)))%rval
   end subroutine get_real_array

   !> An integer array of `min_count` to `max_count` values; `values` is
   !> unchanged when the key is absent.
   subroutine get_integer_array(group, key, values, min_count, max_count, found, error)
      type(nml_group_type), intent(inout) :: group
      character(len=*), intent(in) :: key
      integer, allocatable, intent(inout) :: values(:)
      integer, intent(in) :: min_count, max_count
      logical, intent(out) :: found
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      call get_item(group, key, nml_integer, min_count, max_count, k, found, error)
      if (k > 0) values = group%items(k)%values(expanded(group%items(k)))%ival
   end subroutine get_integer_array

   !> Fail on the first key no getter has read, naming it and the valid keys.
   subroutine nml_check_consumed(group, error)
      type(nml_group_type), intent(in) :: group
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      do k = 1, size(group%items)
         if (group%items(k)%consumed) cycle
         if (len(group%schema) == 0) then
            call nml_field_error(group, group%items(k)%key, 'unknown key; this group takes no keys', error)
         else
            call nml_field_error(group, group%items(k)%key, 'unknown key; valid keys: '//group%schema, error)
         end if
         return
      end do
   end subroutine nml_check_consumed

   !> Error `FILE:LINE: &group: key = value: reason`; without the key in the
   !> group, `FILE:LINE: &group: key: reason` at the group's line.
   subroutine nml_field_error(group, key, reason, error, stat)
      type(nml_group_type), intent(in) :: group
      character(len=*), intent(in) :: key, reason
      type(error_type), allocatable, intent(out) :: error
      !> Status (default `stat_invalid_input`).
      integer, intent(in), optional :: stat
      integer :: k
      k = find_item(group, key)
      if (k > 0) then
         call fatal_error(error, group%source//':'//itoa(group%items(k)%line)//': &'//group%name//': '// &
            & key//' = '//nml_item_text(group, key)//': '//reason, stat_invalid_input)
      else
         call fatal_error(error, group%source//':'//itoa(group%line)//': &'//group%name//': '//key//': ' &
            & //reason, stat_invalid_input)
      end if
      if (present(stat)) error%stat = stat
   end subroutine nml_field_error

   !> Error `FILE:LINE: &group: reason` at the group's line.
   subroutine nml_group_error(group, reason, error, stat)
      type(nml_group_type), intent(in) :: group
      character(len=*), intent(in) :: reason
      type(error_type), allocatable, intent(out) :: error
      !> Status (default `stat_invalid_input`).
      integer, intent(in), optional :: stat
      call fatal_error(error, group%source//':'//itoa(group%line)//': &'//group%name//': '//reason, &
         & stat_invalid_input)
      if (present(stat)) error%stat = stat
   end subroutine nml_group_error

   !> The values of a key as written, separated by ', ' ('' if absent).
   function nml_item_text(group, key) result(text)
      type(nml_group_type), intent(in) :: group
      character(len=*), intent(in) :: key
      character(len=:), allocatable :: text
      integer :: k
      k = find_item(group, key)
      text = ''
      if (k > 0) text = values_text(group%items(k)%values)
   end function nml_item_text

   !> Values as written, shortened for messages.
   function values_text(values) result(text)
      type(nml_value_type), intent(in) :: values(:)
      character(len=:), allocatable :: text
      integer :: i
      integer, parameter :: max_len = 80
      text = ''
      do i = 1, size(values)
         if (i > 1) text = text//', '
         text = text//values(i)%text
         if (len(text) > max_len) exit
      end do
      if (len(text) > max_len) text = text(1:max_len - 3)//'...'
   end function values_text

   !> Up to 20 characters of the text from `pos`, up to the end of the line.
   function snippet(text, pos) result(piece)
      character(len=*), intent(in) :: text
      integer, intent(in) :: pos
      character(len=:), allocatable :: piece
      integer :: j
      j = pos
      do while (j <= len(text) .and. j < pos + 20)
         if (text(j:j) == achar(10) .or. text(j:j) == achar(13)) exit
         j = j + 1
      end do
      piece = text(pos:j - 1)
   end function snippet

   function join_names(names, prefix) result(text)
      character(len=*), intent(in) :: names(:), prefix
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, size(names)
         if (i > 1) text = text//', '
         text = text//prefix//trim(names(i))
      end do
   end function join_names

   subroutine append_group(groups, n, group)
      type(nml_group_type), allocatable, intent(inout) :: groups(:)
      integer, intent(inout) :: n
      type(nml_group_type), intent(in) :: group
      type(nml_group_type), allocatable :: grown(:)
      integer :: i
      if (n == size(groups)) then
         allocate (grown(max(4, 2*n)))
         do i = 1, n
            call move_group(groups(i), grown(i))
         end do
         call move_alloc(grown, groups)
      end if
      n = n + 1
      groups(n) = group
   end subroutine append_group

   subroutine move_group(from, to)
      type(nml_group_type), intent(inout) :: from
      type(nml_group_type), intent(inout) :: to
      call move_alloc(from%name, to%name)
      call move_alloc(from%source, to%source)
      call move_alloc(from%items, to%items)
      call move_alloc(from%schema, to%schema)
      to%line = from%line
   end subroutine move_group

   subroutine append_item(items, n, item)
      type(nml_item_type), allocatable, intent(inout) :: items(:)
      integer, intent(inout) :: n
      type(nml_item_type), intent(in) :: item
      type(nml_item_type), allocatable :: grown(:)
      integer :: i
      if (n == size(items)) then
         allocate (grown(max(8, 2*n)))
         do i = 1, n
            call move_alloc(items(i)%key, grown(i)%key)
            call move_alloc(items(i)%values, grown(i)%values)
            grown(i)%line = items(i)%line
            grown(i)%consumed = items(i)%consumed
         end do
         call move_alloc(grown, items)
      end if
      n = n + 1
      items(n) = item
   end subroutine append_item

   subroutine append_value(values, n, value)
      type(nml_value_type), allocatable, intent(inout) :: values(:)
      integer, intent(inout) :: n
      type(nml_value_type), intent(in) :: value
      type(nml_value_type), allocatable :: grown(:)
      if (n == size(values)) then
         allocate (grown(max(4, 2*n)))
         grown(1:n) = values(1:n)
         call move_alloc(grown, values)
      end if
      n = n + 1
      values(n) = value
   end subroutine append_value

   pure logical function is_letter(c)
      character(len=1), intent(in) :: c
      is_letter = (c >= 'a' .and. c <= 'z') .or. (c >= 'A' .and. c <= 'Z')
   end function is_letter

   pure logical function is_digit(c)
      character(len=1), intent(in) :: c
      is_digit = c >= '0' .and. c <= '9'
   end function is_digit

end module sprc_io_namelist
