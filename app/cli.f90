!> Command line of the sprc driver (doc/scene.md, "The driver"): parsed and validated
!> before any scene is read, so a bad option exits 2 at once.
module sprc_app_cli
   use sprc_fem_linear_solver, only: solver_choice, solver_names
   implicit none
   private

   public :: cli_type, parse_cli, usage_text

   !> What the user asked for.
   type :: cli_type
      !> 'default' (no arguments), 'help', 'version', 'run', 'check' or 'mesh'
      character(len=:), allocatable :: command
      character(len=:), allocatable :: scene_path
      character(len=:), allocatable :: output
      integer, allocatable :: levels(:)
      !> 0: not given
      integer :: threads = 0
      !> 0: from the FE order
      integer :: points = 0
      !> --solver: overrides the scene's `solver` ('' when not given)
      character(len=:), allocatable :: solver
      logical :: quiet = .false.
      !> --wide: print every report column (the default table is the compact one)
      logical :: wide = .false.
   end type cli_type

contains

   function usage_text() result(text)
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      text = 'usage:'//nl// &
         '  sprc                          run the built-in default scene (Lame cylinder study)'//nl// &
         '  sprc run SCENE.nml [--output PREFIX] [--levels 3,4,5] [--threads N] [--points Q]'//nl// &
         '                     [--solver auto|direct|iterative] [--quiet] [--wide]'//nl// &
         '  sprc check SCENE.nml          validate; print the scene and what it switches on and off'//nl// &
         '  sprc mesh SCENE.nml [--levels 3,4] [--points Q]   grid, classification, quadrature per level'//nl// &
         '  sprc --help | --version'//nl//nl// &
         'exit status: 0 success; 2 bad input (the message names the group, field and value);'//nl// &
         '             1 numerical failure, or a capability this version does not have yet'//nl// &
         'environment: SPRC_MEMORY_CHECK=off runs a level that its memory estimate would refuse'
   end function usage_text

   !> Parse the command line. On error, `message` is allocated (exit status 2).
   subroutine parse_cli(cli, message)
      type(cli_type), intent(out) :: cli
      character(len=:), allocatable, intent(out) :: message
      character(len=:), allocatable :: arg
      integer :: nargs, i

      nargs = command_argument_count()
      cli%output = ''
      cli%solver = ''
      if (nargs == 0) then
         cli%command = 'default'
         return
      end if
      call get_arg(1, arg)
      select case (arg)
      case ('-h', '--help', 'help')
         cli%command = 'help'
         return
      case ('-V', '--version')
         cli%command = 'version'
         return
      case ('run', 'check', 'mesh')
         cli%command = arg
      case default
         message = 'unknown command "'//arg//'" (try sprc --help)'
         if (names_scene(arg)) message = 'unknown command "'//arg//'": to run this scene, sprc run '//arg// &
            & ' (to validate it, sprc check '//arg//')'
         return
      end select
      if (nargs < 2) then
         message = 'sprc '//cli%command//' needs a scene file: sprc '//cli%command//' SCENE.nml'
         return
      end if
      call get_arg(2, cli%scene_path)
      i = 3
      do while (i <= nargs)
         call get_arg(i, arg)
         call parse_option(cli, arg, i, nargs, message)
         if (allocated(message)) return
         i = i + 1
      end do
   end subroutine parse_cli

   !> One option (and its value, advancing `i`), allowed per command.
   subroutine parse_option(cli, arg, i, nargs, message)
      type(cli_type), intent(inout) :: cli
      character(len=*), intent(in) :: arg
      integer, intent(inout) :: i
      integer, intent(in) :: nargs
      character(len=:), allocatable, intent(out) :: message
      character(len=:), allocatable :: value

      if (arg == '--quiet' .and. cli%command == 'run') then
         cli%quiet = .true.
         return
      end if
      if (arg == '--wide' .and. cli%command == 'run') then
         cli%wide = .true.
         return
      end if
      if (.not. allowed(cli%command, arg)) then
         message = 'sprc '//cli%command//': unknown option "'//arg//'" (try sprc --help)'
         return
      end if
      if (i == nargs) then
         message = 'sprc '//cli%command//': option '//arg//' needs a value'
         return
      end if
      i = i + 1
      call get_arg(i, value)
      select case (arg)
      case ('--output')
         ! A blank prefix would write files named " .csv" etc.: a quoting mistake, not a wish.
         if (len(value) > 0 .and. len_trim(value) == 0) then
            message = 'sprc '//cli%command//': --output "'//value//'" is blank; give a file prefix'
            return
         end if
         ! 'res/' would write the hidden files res/.csv, res/.h5, ...
         if (len(value) > 0) then
            if (value(len(value):) == '/') then
               message = 'sprc '//cli%command//': --output "'//value//'" names a directory; give a file prefix '// &
                  & 'such as "'//value//'name"'
               return
            end if
         end if
         cli%output = value
      case ('--threads')
         call parse_positive(arg, value, 4096, cli%threads, message)
      case ('--points')
         call parse_positive(arg, value, 10, cli%points, message)
      case ('--levels')
         call parse_levels(value, cli%levels, message)
      case ('--solver')
         if (solver_choice(value) == 0) then
            message = 'sprc '//cli%command//': --solver "'//value//'" is not one of: '//solver_names
            return
         end if
         cli%solver = value
      end select
   end subroutine parse_option

   !> Whether a first argument that is no command looks like a scene file
   !> (ends in .nml or names an existing file): the user left out `run`.
   logical function names_scene(arg)
      character(len=*), intent(in) :: arg
      logical :: exists
      names_scene = .false.
      if (len(arg) == 0) return
      if (len(arg) >= 4) names_scene = arg(len(arg) - 3:) == '.nml'
      if (names_scene) return
      inquire (file=arg, exist=exists)
      names_scene = exists .and. arg(1:1) /= '-'
   end function names_scene

   pure logical function allowed(command, option)
      character(len=*), intent(in) :: command, option
      select case (command)
      case ('run')
         allowed = any(option == [character(len=9) :: '--output', '--levels', '--threads', '--points', '--solver'])
      case ('mesh')
         allowed = option == '--points' .or. option == '--levels'
      case default
         allowed = .false.
      end select
   end function allowed

   !> An integer in 1..upper.
   subroutine parse_positive(option, text, upper, value, message)
      character(len=*), intent(in) :: option, text
      integer, intent(in) :: upper
      integer, intent(out) :: value
      character(len=:), allocatable, intent(out) :: message
      character(len=16) :: buf
      integer :: ios

      value = 0
      ios = 1
      if (verify(text, '0123456789') == 0 .and. len(text) > 0 .and. len(text) < 10) read (text, *, iostat=ios) value
      if (ios /= 0 .or. value < 1 .or. value > upper) then
         write (buf, '(i0)') upper
         message = 'option '//option//' = "'//text//'": expected a whole number from 1 to '//trim(buf)
      end if
   end subroutine parse_positive

   !> A comma-separated list of levels, each 0..20 (the scene's own limits apply later).
   subroutine parse_levels(text, levels, message)
      character(len=*), intent(in) :: text
      integer, allocatable, intent(out) :: levels(:)
      character(len=:), allocatable, intent(out) :: message
      integer :: start, comma, value, ios

      allocate (levels(0))
      start = 1
      value = 0
      do
         comma = index(text(start:), ',')
         if (comma == 0) then
            comma = len(text) + 1
         else
            comma = start + comma - 1
         end if
         ios = 1
         if (comma > start .and. comma - start < 4) then
            if (verify(text(start:comma - 1), '0123456789') == 0) read (text(start:comma - 1), *, iostat=ios) value
         end if
         if (ios /= 0 .or. value > 20) then
            message = 'option --levels = "'//text//'": expected levels 0..20 separated by commas, e.g. 3,4,5'
            return
         end if
         levels = [levels, value]
         if (comma > len(text)) exit
         start = comma + 1
      end do
   end subroutine parse_levels

   subroutine get_arg(i, arg)
      integer, intent(in) :: i
      character(len=:), allocatable, intent(out) :: arg
      integer :: length
      call get_command_argument(i, length=length)
      allocate (character(len=length) :: arg)
      if (length > 0) call get_command_argument(i, arg)
   end subroutine get_arg

end module sprc_app_cli
