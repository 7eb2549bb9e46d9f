!> Tests of the namelist parser: every token kind, comments, multi-line
!> groups, repeat counts, case, quoting, line numbers, typed getters and every
!> error path.
module sprc_test_namelist
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, stat_invalid_input, stat_io
   use sprc_io_namelist, only: nml_group_type, parse_namelist, read_text_file, nml_get, nml_get_array, &
      & nml_has, nml_check_consumed, nml_field_error, nml_group_error, nml_item_text, nml_integer, nml_real, &
      & nml_string, nml_logical, max_repeat, max_groups, max_items, max_values
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed
   implicit none
   private

   public :: collect_namelist

   character(len=*), parameter :: nl = new_line('a')

contains

   subroutine collect_namelist(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('numbers', test_numbers), &
         new_unittest('logicals', test_logicals), &
         new_unittest('strings_and_quotes', test_strings), &
         new_unittest('repeat_counts', test_repeat), &
         new_unittest('groups_lines_comments_case', test_structure), &
         new_unittest('crlf_line_numbers', test_crlf), &
         new_unittest('getters_defaults_and_found', test_getters), &
         new_unittest('getter_type_and_count_errors', test_getter_errors), &
         new_unittest('unknown_key_lists_schema', test_unknown_key), &
         new_unittest('field_and_group_messages', test_messages), &
         new_unittest('known_groups', test_known_groups), &
         new_unittest('syntax_errors', test_syntax_errors), &
         new_unittest('non_text_content', test_non_text), &
         new_unittest('size_limits', test_limits), &
         new_unittest('utf8_accepted', test_utf8), &
         new_unittest('read_text_file', test_read_file), &
         new_unittest('read_text_file_errors', test_read_file_errors) &
         ]
   end subroutine collect_namelist

   !> Parse `text` as source 'f.nml' into exactly one group.
   subroutine parse_one(text, group, error)
      character(len=*), intent(in) :: text
      type(nml_group_type), intent(out) :: group
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type), allocatable :: groups(:)
      type(error_type), allocatable :: perr
      call parse_namelist(text, 'f.nml', groups, perr)
      if (allocated(perr)) then
         call test_failed(error, 'unexpected parse error: '//perr%message)
         return
      end if
      call check(error, size(groups), 1, 'number of groups')
      if (allocated(error)) return
      group = groups(1)
   end subroutine parse_one

   !> Whether two real arrays are identical. Parsed values are compared with
   !> the compiler's conversion of the same decimal literal: both round the
   !> decimal correctly, so the tolerance is zero.
   pure logical function exact(a, b)
      real(wp), intent(in) :: a(:), b(:)
      exact = size(a) == size(b)
      if (exact) exact = all(abs(a - b) <= 0.0_wp)
   end function exact

   !> Parsing `text` must fail with stat_invalid_input and a message holding `expected`.
   subroutine expect_parse_error(error, text, expected)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: text, expected
      type(nml_group_type), allocatable :: groups(:)
      type(error_type), allocatable :: perr
      call parse_namelist(text, 'f.nml', groups, perr, [character(len=5) :: 'g', 'h'])
      if (.not. allocated(perr)) then
         call test_failed(error, 'no error for: '//text)
         return
      end if
      call check(error, perr%stat, stat_invalid_input, 'status for: '//text)
      if (allocated(error)) return
      call check(error, index(perr%message, expected) > 0, 'message "'//perr%message//'" lacks "'//expected//'"')
   end subroutine expect_parse_error

   subroutine test_numbers(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type) :: g
      real(wp), allocatable :: r(:)
      integer, allocatable :: iv(:)
      logical :: found
      ! Values chosen so the decimal text is exact in binary or compared with
      ! the compiler's own conversion of the same literal: the tolerance is 0.
      call parse_one('&g r = 1, -2, +3.5, .5, 7., 1e3, 1.5d-2, -2E+1, 0.1 i = -42, +7 0 /', g, error)
      if (allocated(error)) return
      call nml_get_array(g, 'r', r, 9, 9, found, error)
      if (allocated(error)) return
      call check(error, found, 'r found')
      if (allocated(error)) return
      call check(error, exact(r, [1.0_wp, -2.0_wp, 3.5_wp, 0.5_wp, 7.0_wp, 1000.0_wp, 1.5e-2_wp, -20.0_wp, 0.1_wp]), &
         & 'real values')
      if (allocated(error)) return
      call check(error, g%items(1)%values(1)%kind, nml_integer, 'integer token kind')
      if (allocated(error)) return
      call check(error, g%items(1)%values(3)%kind, nml_real, 'real token kind')
      if (allocated(error)) return
      call nml_get_array(g, 'i', iv, 1, 5, found, error)
      if (allocated(error)) return
      call check(error, size(iv) == 3 .and. all(iv == [-42, 7, 0]), 'integer values')
      if (allocated(error)) return
      ! An integer too long for a default integer is still a valid real.
      call parse_one('&g x = 123456789012 /', g, error)
      if (allocated(error)) return
      call check(error, g%items(1)%values(1)%kind, nml_real, 'long integer read as real')
      if (allocated(error)) return
      call check(error, g%items(1)%values(1)%rval, 123456789012.0_wp, 0.0_wp, 'long integer value')
   end subroutine test_numbers

   subroutine test_logicals(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type) :: g
      logical :: a, b, c, d, e, f, found
      call parse_one('&g a=.true. b=.FALSE. c=T d=f e=.t. f=.F. /', g, error)
      if (allocated(error)) return
      a = .false.; b = .true.; c = .false.; d = .true.; e = .false.; f = .true.
      call nml_get(g, 'a', a, found, error); if (allocated(error)) return
      call nml_get(g, 'b', b, found, error); if (allocated(error)) return
      call nml_get(g, 'c', c, found, error); if (allocated(error)) return
      call nml_get(g, 'd', d, found, error); if (allocated(error)) return
      call nml_get(g, 'e', e, found, error); if (allocated(error)) return
      call nml_get(g, 'f', f, found, error); if (allocated(error)) return
      call check(error, a .and. .not. b .and. c .and. .not. d .and. e .and. .not. f, 'logical values')
      if (allocated(error)) return
      call check(error, g%items(3)%values(1)%kind, nml_logical, 'logical token kind')
   end subroutine test_logicals

   subroutine test_strings(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type) :: g
      character(len=:), allocatable :: s
      logical :: found
      call parse_one("&g a='it''s' b=""say """"hi"""""" c='' d='x ! not a comment, / nor an end' e=""'"" /", g, error)
      if (allocated(error)) return
      call nml_get(g, 'a', s, found, error); if (allocated(error)) return
      call check(error, s, "it's", 'doubled apostrophe')
      if (allocated(error)) return
      call nml_get(g, 'b', s, found, error); if (allocated(error)) return
      call check(error, s, 'say "hi"', 'doubled double quote')
      if (allocated(error)) return
      call nml_get(g, 'c', s, found, error); if (allocated(error)) return
      call check(error, len(s), 0, 'empty string')
      if (allocated(error)) return
      call nml_get(g, 'd', s, found, error); if (allocated(error)) return
      call check(error, s, 'x ! not a comment, / nor an end', '! , / inside a string')
      if (allocated(error)) return
      call nml_get(g, 'e', s, found, error); if (allocated(error)) return
      call check(error, s, "'", 'other quote inside a string')
      if (allocated(error)) return
      call check(error, g%items(1)%values(1)%kind, nml_string, 'string token kind')
      if (allocated(error)) return
      call check(error, nml_item_text(g, 'a'), "'it''s'", 'text as written')
   end subroutine test_strings

   subroutine test_repeat(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(nml_group_type) :: g
      real(wp), allocatable :: r(:)
      integer, allocatable :: iv(:)
      character(len=:), allocatable :: s
      logical :: found
      call parse_one("&g r = 3*1.5, 2 i = 2*7 1*-1 s = 1*'ab' /", g, error)
      if (allocated(error)) return
      call nml_get_array(g, 'r', r, 4, 4, found, error)
      if (allocated(error)) return
      call check(error, exact(r, [1.5_wp, 1.5_wp, 1.5_wp, 2.0_wp]), 'real repeat expands')
      if (allocated(error)) return
      call nml_get_array(g, 'i', iv, 3, 3, found, error)
      if (allocated(error)) return
      call check(error, all(iv == [7, 7, -1]), 'integer repeat expands')
      if (allocated(error)) return
      call nml_get(g, 's', s, found, error)
      if (allocated(error)) return
      call check(error, s, 'ab', 'string with repeat 1')
      if (allocated(error)) return
      call check(error, nml_item_text(g, 'r'), '3*1.5, 2', 'repeat text as written')
      if (allocated(error)) return
      ! 3*1.5 counts as three values for a count check.
      call nml_get_array(g, 'r', r, 2, 2, found, e)
      call expect_getter_error(error, e, 'r = 3*1.5, 2: expected 2 values, got 4')
   end subroutine test_repeat

   subroutine test_structure(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type), allocatable :: groups(:)
      type(error_type), allocatable :: perr
      real(wp), allocatable :: r(:)
      logical :: found
      character(len=*), parameter :: text = &
         & '! leading comment'//nl// &
         & ''//nl// &
         & '&First   ! a comment after the name'//nl// &
         & '  Alpha = 1.0,'//nl// &
         & '          2.0    ! continued on the next line'//nl// &
         & '  BETA=3 gamma = 4 5,6'//nl// &
         & '/'//nl// &
         & '&second /'//nl// &
         & '&FIRST alpha = 9 /   ! repeated group, trailing comment'//nl

      call parse_namelist(text, 'f.nml', groups, perr)
      if (allocated(perr)) then
         call test_failed(error, perr%message)
         return
      end if
      call check(error, size(groups), 3, 'groups')
      if (allocated(error)) return
      call check(error, groups(1)%name//' '//groups(2)%name//' '//groups(3)%name, 'first second first', 'names')
      if (allocated(error)) return
      call check(error, groups(1)%line, 3, 'line of group 1')
      if (allocated(error)) return
      call check(error, groups(2)%line, 8, 'line of group 2')
      if (allocated(error)) return
      call check(error, groups(3)%line, 9, 'line of group 3')
      if (allocated(error)) return
      call check(error, size(groups(1)%items), 3, 'items of group 1')
      if (allocated(error)) return
      call check(error, groups(1)%items(1)%key//' '//groups(1)%items(2)%key//' '//groups(1)%items(3)%key, &
         & 'alpha beta gamma', 'keys in lower case, in order')
      if (allocated(error)) return
      call check(error, groups(1)%items(1)%line, 4, 'line of alpha')
      if (allocated(error)) return
      call check(error, groups(1)%items(3)%line, 6, 'line of gamma')
      if (allocated(error)) return
      call check(error, size(groups(2)%items), 0, 'empty group')
      if (allocated(error)) return
      ! Keys are looked up case-insensitively (stored in lower case).
      call nml_get_array(groups(1), 'alpha', r, 2, 2, found, error)
      if (allocated(error)) return
      call check(error, found .and. exact(r, [1.0_wp, 2.0_wp]), 'value spanning lines')
      if (allocated(error)) return
      call nml_get_array(groups(1), 'gamma', r, 3, 3, found, error)
      if (allocated(error)) return
      call check(error, exact(r, [4.0_wp, 5.0_wp, 6.0_wp]), 'blank and comma separators')
   end subroutine test_structure

   subroutine test_crlf(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: crlf = achar(13)//achar(10)
      call expect_parse_error(error, '&g'//crlf//' a = 1'//crlf//' b = nan'//crlf//'/'//crlf, 'f.nml:3: &g: b = nan')
   end subroutine test_crlf

   subroutine test_getters(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type) :: g
      real(wp) :: x
      integer :: i
      logical :: l, found
      character(len=:), allocatable :: s
      real(wp), allocatable :: r(:)
      integer, allocatable :: iv(:)

      call parse_one("&g x = 2 n = 5 /", g, error)
      if (allocated(error)) return
      x = 0.0_wp
      call nml_get(g, 'x', x, found, error)
      if (allocated(error)) return
      call check(error, found, 'x found')
      if (allocated(error)) return
      call check(error, x, 2.0_wp, 0.0_wp, 'integer token read as a real')
      if (allocated(error)) return
      ! Absent keys: found is false and the default stays.
      x = 7.0_wp
      i = 3
      l = .true.
      s = 'default'
      allocate (r(2), source=-1.0_wp)
      allocate (iv(1), source=4)
      call nml_get(g, 'missing', x, found, error); if (allocated(error)) return
      call check(error, .not. found .and. exact([x], [7.0_wp]), 'real default kept')
      if (allocated(error)) return
      call nml_get(g, 'missing', i, found, error); if (allocated(error)) return
      call check(error, .not. found .and. i == 3, 'integer default kept')
      if (allocated(error)) return
      call nml_get(g, 'missing', l, found, error); if (allocated(error)) return
      call check(error, .not. found .and. l, 'logical default kept')
      if (allocated(error)) return
      call nml_get(g, 'missing', s, found, error); if (allocated(error)) return
      call check(error, .not. found .and. s == 'default', 'string default kept')
      if (allocated(error)) return
      call nml_get_array(g, 'missing', r, 2, 2, found, error); if (allocated(error)) return
      call check(error, .not. found .and. exact(r, [-1.0_wp, -1.0_wp]), 'real array default kept')
      if (allocated(error)) return
      call nml_get_array(g, 'missing', iv, 1, 1, found, error); if (allocated(error)) return
      call check(error, .not. found .and. all(iv == 4), 'integer array default kept')
      if (allocated(error)) return
      call nml_get(g, 'n', i, found, error); if (allocated(error)) return
      call check(error, i, 5, 'integer value')
      if (allocated(error)) return
      call check(error, nml_has(g, 'n') .and. .not. nml_has(g, 'missing'), 'nml_has')
      if (allocated(error)) return
      ! Everything given was read: no unknown key.
      call nml_check_consumed(g, error)
   end subroutine test_getters

   !> A getter must fail with stat_invalid_input and a message holding `expected`.
   subroutine expect_getter_error(error, e, expected)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable, intent(in) :: e
      character(len=*), intent(in) :: expected
      if (.not. allocated(e)) then
         call test_failed(error, 'no error, expected: '//expected)
         return
      end if
      call check(error, e%stat, stat_invalid_input, 'status')
      if (allocated(error)) return
      call check(error, index(e%message, expected) > 0, 'message "'//e%message//'" lacks "'//expected//'"')
   end subroutine expect_getter_error

   subroutine test_getter_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(nml_group_type) :: g
      real(wp) :: x
      integer :: i
      logical :: l, found
      character(len=:), allocatable :: s
      real(wp), allocatable :: r(:)
      integer, allocatable :: iv(:)

      call parse_one("&g"//nl//" s = 'abc'"//nl//" x = 1.5 i = 2, 3"//nl//" l = t r = 1, 2, 3 /", g, error)
      if (allocated(error)) return
      call nml_get(g, 's', x, found, e)
      call expect_getter_error(error, e, "f.nml:2: &g: s = 'abc': expected a real number, got 'abc'")
      if (allocated(error)) return
      call nml_get(g, 'x', i, found, e)
      call expect_getter_error(error, e, 'f.nml:3: &g: x = 1.5: expected an integer, got 1.5')
      if (allocated(error)) return
      call nml_get(g, 'x', s, found, e)
      call expect_getter_error(error, e, 'f.nml:3: &g: x = 1.5: expected a quoted string')
      if (allocated(error)) return
      call nml_get(g, 'x', l, found, e)
      call expect_getter_error(error, e, 'f.nml:3: &g: x = 1.5: expected a logical')
      if (allocated(error)) return
      call nml_get(g, 'l', x, found, e)
      call expect_getter_error(error, e, 'f.nml:4: &g: l = t: expected a real number')
      if (allocated(error)) return
      call nml_get(g, 'i', i, found, e)
      call expect_getter_error(error, e, 'f.nml:3: &g: i = 2, 3: expected one value, got 2')
      if (allocated(error)) return
      call nml_get_array(g, 'r', r, 2, 2, found, e)
      call expect_getter_error(error, e, 'f.nml:4: &g: r = 1, 2, 3: expected 2 values, got 3')
      if (allocated(error)) return
      call nml_get_array(g, 'r', r, 4, 6, found, e)
      call expect_getter_error(error, e, 'expected 4 to 6 values, got 3')
      if (allocated(error)) return
      call nml_get_array(g, 'x', iv, 1, 2, found, e)
      call expect_getter_error(error, e, 'x = 1.5: expected an integer')
   end subroutine test_getter_errors

   subroutine test_unknown_key(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(nml_group_type) :: g
      real(wp) :: x
      integer :: i
      logical :: found

      call parse_one('&g young = 1'//nl//' youngs = 2 n = 1 /', g, error)
      if (allocated(error)) return
      call nml_get(g, 'young', x, found, error); if (allocated(error)) return
      call nml_get(g, 'n', i, found, error); if (allocated(error)) return
      call nml_get(g, 'poisson', x, found, error); if (allocated(error)) return
      call nml_check_consumed(g, e)
      call expect_getter_error(error, e, 'f.nml:2: &g: youngs = 2: unknown key; valid keys: young, n, poisson')
      if (allocated(error)) return
      ! A group nobody asked anything of takes no keys.
      call parse_one('&g a = 1 /', g, error)
      if (allocated(error)) return
      call nml_check_consumed(g, e)
      call expect_getter_error(error, e, 'a = 1: unknown key; this group takes no keys')
   end subroutine test_unknown_key

   subroutine test_messages(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(nml_group_type) :: g

      call parse_one('&body'//nl//' poisson = 0.5 /', g, error)
      if (allocated(error)) return
      call nml_field_error(g, 'poisson', 'must satisfy -1 < poisson < 0.5', e)
      call check(error, e%message, 'f.nml:2: &body: poisson = 0.5: must satisfy -1 < poisson < 0.5', 'field error')
      if (allocated(error)) return
      call nml_field_error(g, 'young', 'required', e, stat_io)
      call check(error, e%message, 'f.nml:1: &body: young: required', 'absent field error at the group line')
      if (allocated(error)) return
      call check(error, e%stat, stat_io, 'explicit status kept')
      if (allocated(error)) return
      call nml_group_error(g, 'something', e)
      call check(error, e%message, 'f.nml:1: &body: something', 'group error')
      if (allocated(error)) return
      call check(error, e%stat, stat_invalid_input, 'default status')
   end subroutine test_messages

   subroutine test_known_groups(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type), allocatable :: groups(:)
      type(error_type), allocatable :: e
      call parse_namelist('&G a=1 /'//nl//'&h /'//nl, 'f.nml', groups, e, [character(len=5) :: 'g', 'h'])
      call check(error, .not. allocated(e) .and. size(groups) == 2, 'known groups accepted, case-insensitively')
      if (allocated(error)) return
      call expect_parse_error(error, '&g /'//nl//'&boundary x=1 /', 'f.nml:2: &boundary: unknown group; valid groups: &g, &h')
   end subroutine test_known_groups

   subroutine test_syntax_errors(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_parse_error(error, '&g a = 1'//nl//' a = 2 /', 'f.nml:2: &g: a = 2: duplicate key (first given on line 1)')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1'//nl, 'f.nml:1: &g: unterminated group: end of file')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1'//nl//'&h /', "&g: unterminated group: '&h /' on line 2")
      if (allocated(error)) return
      call expect_parse_error(error, "&g a = 'abc"//nl//"'/", "f.nml:1: &g: a = 'abc: unterminated string")
      if (allocated(error)) return
      call expect_parse_error(error, "&g a = 'abc", 'unterminated string')
      if (allocated(error)) return
      call expect_parse_error(error, 'x = 1'//nl//'&g /', "f.nml:1: unexpected text 'x = 1' outside a namelist group")
      if (allocated(error)) return
      call expect_parse_error(error, '&g /'//nl//'junk', "f.nml:2: unexpected text 'junk'")
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = NaN /', 'f.nml:1: &g: a = NaN: not a finite number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = -inf /', 'a = -inf: not a finite number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = +Infinity /', 'a = +Infinity: not a finite number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1e999 /', 'a = 1e999: not a finite number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1,,2 /', 'a: empty value before a comma')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = , 2 /', 'a: empty value before a comma')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 2* /', 'a = 2*: null values (r*) are not supported')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 0*1 /', 'a = 0*: repeat count must be 1 to')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 9999999*1 /', 'repeat count must be 1 to')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a(2) = 1 /', 'a: subscripts and substrings are not supported')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a%b = 1 /', 'a: derived-type components are not supported')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a 1 /', "a: expected '=' after the key, found '1 /'")
      if (allocated(error)) return
      call expect_parse_error(error, '&g a', "a: expected '=' after the key, found end of file")
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = /', "a: no value after '='")
      if (allocated(error)) return
      call expect_parse_error(error, '& g /', "f.nml:1: expected a group name after '&'")
      if (allocated(error)) return
      call expect_parse_error(error, '&g 1 = 2 /', "&g: expected a key name or the closing '/', found '1 = 2 /'")
      if (allocated(error)) return
      call expect_parse_error(error, "&g a = 'x'b /", "a = 'x': expected a blank or ',' after the value")
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = abc /', 'a = abc: not a number, logical or quoted string')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1.2.3 /', 'a = 1.2.3: not a number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1e /', 'a = 1e: not a number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = - /', 'a = -: not a number')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1 / &h /', "f.nml:1: &g: text '&h /' after the closing '/'")
   end subroutine test_syntax_errors

   subroutine test_non_text(error)
      type(error_type), allocatable, intent(out) :: error
      call expect_parse_error(error, '&g a = 1'//nl//' b = 2'//achar(0)//' /', 'f.nml:2: not a text file: NUL byte at offset 15')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 1'//achar(7)//' /', 'not a text file: control byte 7')
      if (allocated(error)) return
      call expect_parse_error(error, "&g a = 'Lam"//achar(233)//"' /", 'not a text file: invalid UTF-8 byte 233')
      if (allocated(error)) return
      ! A truncated multi-byte sequence at the end of the text.
      call expect_parse_error(error, "&g a = 1 / !"//achar(195), 'invalid UTF-8')
   end subroutine test_non_text

   !> Hostile sizes fail cleanly instead of costing quadratic time.
   subroutine test_limits(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type), allocatable :: groups(:)
      type(error_type), allocatable :: e
      character(len=:), allocatable :: text
      character(len=16) :: key
      integer :: i

      call parse_namelist(repeat('&g /'//nl, max_groups), 'f.nml', groups, e)
      call check(error, .not. allocated(e) .and. size(groups) == max_groups, 'max_groups groups accepted')
      if (allocated(error)) return
      call expect_parse_error(error, repeat('&g /'//nl, max_groups + 1), 'f.nml:10001: more than 10000 namelist groups')
      if (allocated(error)) return
      text = '&g'
      do i = 1, max_items + 1
         write (key, '(" k",i0,"=1")') i
         text = text//trim(key)
      end do
      call expect_parse_error(error, text//' /', 'f.nml:1: &g: more than 1000 keys in one group')
      if (allocated(error)) return
      call expect_parse_error(error, '&g a = 100000*1, 2 /', 'f.nml:1: &g: a: more than 100000 values')
      if (allocated(error)) return
      call check(error, max_values == max_repeat, 'one repeat may fill a key')
   end subroutine test_limits

   subroutine test_utf8(error)
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type) :: g
      character(len=:), allocatable :: s
      logical :: found
      ! 'Lamé' in UTF-8 (C3 A9), in a string and in a comment.
      call parse_one("&g t = 'Lam"//achar(195)//achar(169)//"' ! "//achar(195)//achar(169)//nl//"/", g, error)
      if (allocated(error)) return
      call nml_get(g, 't', s, found, error)
      if (allocated(error)) return
      call check(error, s, 'Lam'//achar(195)//achar(169), 'UTF-8 string kept byte for byte')
   end subroutine test_utf8

   subroutine test_read_file(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      character(len=:), allocatable :: text
      call read_text_file('example/scenes/lame_cylinder.nml', text, e)
      if (allocated(e)) then
         call test_failed(error, e%message)
         return
      end if
      call check(error, index(text, '&scene') == 1, 'file starts with &scene')
      if (allocated(error)) return
      call check(error, text(len(text):len(text)) == nl, 'file read to its last byte')
      if (allocated(error)) return
      call read_text_file('test/data/scenes/bad/empty.nml', text, e)
      call check(error, .not. allocated(e) .and. len(text) == 0, 'empty file reads as empty text')
   end subroutine test_read_file

   subroutine test_read_file_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      character(len=:), allocatable :: text
      call read_text_file('test/data/scenes/no_such_file.nml', text, e)
      call check(error, allocated(e), 'missing file fails')
      if (allocated(error)) return
      call check(error, e%stat, stat_io, 'missing file is stat_io')
      if (allocated(error)) return
      call check(error, index(e%message, "'test/data/scenes/no_such_file.nml'") > 0, 'message names the path')
      if (allocated(error)) return
      call read_text_file('test/data/scenes', text, e)
      call check(error, allocated(e), 'a directory fails')
      if (allocated(error)) return
      call check(error, e%stat, stat_io, 'directory is stat_io')
      if (allocated(error)) return
      call read_text_file('test/data/scenes/bad/binary_garbage.nml', text, e)
      call check(error, allocated(e), 'binary file fails')
      if (allocated(error)) return
      call check(error, e%stat, stat_invalid_input, 'binary file is invalid input')
      if (allocated(error)) return
      call check(error, index(e%message, 'binary_garbage.nml:1: not a text file') > 0, e%message)
   end subroutine test_read_file_errors

end module sprc_test_namelist
