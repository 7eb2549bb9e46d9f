!> The report plot: a standalone SVG 1.1 picture with two log-log panels,
!> relative error against run time (t_total) and against dofs, one polyline
!> with markers per column err_fe, err_spr, err_sprc, eta_spr, eta_sprc.
!>
!> Colours pair each estimate with its recovery: err_X solid with filled
!> circles, eta_X dashed with open squares, same colour. err_fe, the reference,
!> is a wide pale band drawn first, so that a line on it (eta_sprc when the
!> effectivity is 1) stays visible and so does the band. Columns that are
!> empty in every row are left out (also from the legend). A log axis cannot
!> show empty cells or values <= 0: such points are skipped and listed in a
!> comment in the file. A series with one point gets a marker, no line.
!> No scripts, no external fonts or references (generic `sans-serif`).
module sprc_io_svg
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: fixed_text
   use sprc_core_error, only: error_type, fatal_error, stat_io
   use sprc_io_report, only: report_row_type, report_column, is_empty
   implicit none
   private

   public :: write_report_svg, report_svg

   integer, parameter :: n_series = 5
   character(len=8), parameter :: series_name(n_series) = [character(len=8) :: &
      & 'err_fe', 'err_spr', 'err_sprc', 'eta_spr', 'eta_sprc']
   character(len=7), parameter :: series_colour(n_series) = [character(len=7) :: &
      & '#1f77b4', '#ff7f0e', '#2ca02c', '#ff7f0e', '#2ca02c']
   logical, parameter :: series_estimate(n_series) = [.false., .false., .false., .true., .true.]

   !> Page and panel geometry in px. Panel p occupies x in [(p-1)*panel_width, p*panel_width].
   real(wp), parameter :: page_width = 1000.0_wp, page_height = 480.0_wp, panel_width = 500.0_wp
   real(wp), parameter :: plot_left = 85.0_wp, plot_right = 475.0_wp, plot_top = 70.0_wp, plot_bottom = 370.0_wp

   character(len=*), parameter :: nl = new_line('a')

   !> Decades [lo, hi] covered by a log axis.
   type :: axis_type
      integer :: lo = 0, hi = 1
   end type axis_type

contains

   !> Write the plot of `rows` to `path` (replacing it). Fails with stat_io naming the path.
   subroutine write_report_svg(path, rows, title, error)
      character(len=*), intent(in) :: path
      type(report_row_type), intent(in) :: rows(:)
      !> Title on top of the picture (plain text; escaped here).
      character(len=*), intent(in) :: title
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat
      character(len=256) :: msg

      open (newunit=unit, file=path, status='replace', action='write', access='stream', form='unformatted', &
         iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, 'report SVG: cannot open "'//path//'" for writing: '//trim(msg), stat_io)
         return
      end if
      write (unit, iostat=stat, iomsg=msg) report_svg(rows, title)
      if (stat /= 0) then
         close (unit)
         call fatal_error(error, 'report SVG: cannot write "'//path//'": '//trim(msg), stat_io)
         return
      end if
      close (unit, iostat=stat, iomsg=msg)
      if (stat /= 0) call fatal_error(error, 'report SVG: cannot close "'//path//'": '//trim(msg), stat_io)
   end subroutine write_report_svg

   !> The SVG text of the plot of `rows`.
   function report_svg(rows, title) result(svg)
      type(report_row_type), intent(in) :: rows(:)
      character(len=*), intent(in) :: title
      character(len=:), allocatable :: svg
      real(wp) :: y(size(rows), n_series), x(size(rows), 2), levels(size(rows))
      logical :: active(n_series)
      integer :: k, p

      levels = report_column(rows, 'level')
      x(:, 1) = report_column(rows, 't_total')
      x(:, 2) = report_column(rows, 'dofs')
      do k = 1, n_series
         y(:, k) = report_column(rows, trim(series_name(k)))
         active(k) = any(.not. is_empty(y(:, k)))
      end do

      svg = '<?xml version="1.0" encoding="UTF-8" standalone="no"?>'//nl// &
         '<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="'//num(page_width)//'" height="'// &
         num(page_height)//'" viewBox="0 0 '//num(page_width)//' '//num(page_height)//'">'//nl// &
         '<!-- sprc report: relative errors (err_*) and estimated relative errors (eta_*) on log-log axes. '// &
         'Empty cells and values <= 0 are skipped: a log scale cannot show them. -->'//nl
      svg = svg//skipped_comment(x, y, active, levels)
      svg = svg//'<title>'//escape(title)//'</title>'//nl// &
         '<rect x="0" y="0" width="'//num(page_width)//'" height="'//num(page_height)//'" fill="white"/>'//nl// &
         '<g font-family="sans-serif" font-size="12" fill="black">'//nl// &
         '<text x="'//num(page_width/2)//'" y="30" font-size="18" text-anchor="middle">'//escape(title)// &
         '</text>'//nl
      do p = 1, 2
         svg = svg//panel(p, x(:, p), y, active)
      end do
      svg = svg//legend(active)//'</g>'//nl//'</svg>'//nl
   end function report_svg

   !> A comment listing every skipped non-positive value, or nothing.
   function skipped_comment(x, y, active, levels) result(text)
      real(wp), intent(in) :: x(:, :), y(:, :), levels(:)
      logical, intent(in) :: active(:)
      character(len=:), allocatable :: text
      character(len=:), allocatable :: list
      integer :: i, k

      list = ''
      do i = 1, size(levels)
         if (.not. is_empty(x(i, 1)) .and. x(i, 1) <= 0.0_wp) list = list//'; t_total at level '//inum(levels(i))
         if (.not. is_empty(x(i, 2)) .and. x(i, 2) <= 0.0_wp) list = list//'; dofs at level '//inum(levels(i))
         do k = 1, n_series
            if (.not. active(k)) cycle
            if (.not. is_empty(y(i, k)) .and. y(i, k) <= 0.0_wp) &
               list = list//'; '//trim(series_name(k))//' at level '//inum(levels(i))
         end do
      end do
      text = ''
      if (len(list) > 0) text = '<!-- skipped, value <= 0: '//list(3:)//' -->'//nl
   end function skipped_comment

   !> One panel: frame, grid, decade ticks and labels, axis titles, series.
   function panel(p, x, y, active) result(text)
      integer, intent(in) :: p
      real(wp), intent(in) :: x(:), y(:, :)
      logical, intent(in) :: active(:)
      character(len=:), allocatable :: text
      logical :: valid(size(x), n_series)
      type(axis_type) :: ax, ay
      real(wp) :: x0, left, right, xs(size(x)), ys(size(x))
      integer :: k, i, m
      character(len=:), allocatable :: pts

      x0 = (p - 1)*panel_width
      left = x0 + plot_left
      right = x0 + plot_right
      do k = 1, n_series
         valid(:, k) = active(k) .and. positive(x) .and. positive(y(:, k))
      end do
      text = '<g>'//nl//'<text x="'//num((left + right)/2)//'" y="'//num(plot_top - 12)// &
         '" font-size="14" text-anchor="middle">'//pick(p == 1, 'error against run time', &
         'error against dofs')//'</text>'//nl
      text = text//'<text x="'//num((left + right)/2)//'" y="'//num(plot_bottom + 42)// &
         '" text-anchor="middle">'//pick(p == 1, 'run time t_total [s]', 'degrees of freedom')//'</text>'//nl// &
         '<text x="'//num(x0 + 22)//'" y="'//num((plot_top + plot_bottom)/2)//'" text-anchor="middle" '// &
         'transform="rotate(-90 '//num(x0 + 22)//' '//num((plot_top + plot_bottom)/2)//')">relative error</text>'//nl
      if (.not. any(valid)) then
         text = text//frame(left, right)//'<text x="'//num((left + right)/2)//'" y="'// &
            num((plot_top + plot_bottom)/2)//'" text-anchor="middle" fill="#888888">no data</text>'//nl//'</g>'//nl
         return
      end if
      ax = log_axis(pack(spread(x, 2, n_series), valid))
      ay = log_axis(pack(y, valid))
      text = text//ticks(ax, left, right, .true.)//ticks(ay, left, right, .false.)//frame(left, right)
      do k = 1, n_series
         m = 0
         do i = 1, size(x)
            if (.not. valid(i, k)) cycle
            m = m + 1
            xs(m) = map(ax, x(i), left, right)
            ys(m) = map(ay, y(i, k), plot_bottom, plot_top)
         end do
         if (m >= 2) then
            pts = ''
            do i = 1, m
               pts = pts//' '//num(xs(i))//','//num(ys(i))
            end do
            text = text//'<polyline class="line '//trim(series_name(k))//'" points="'//pts(2:)// &
               '" fill="none" stroke="'//series_colour(k)//'"'//series_stroke(k)//'/>'//nl
         end if
         do i = 1, m
            text = text//marker(k, xs(i), ys(i), 'point '//trim(series_name(k)))
         end do
      end do
      text = text//'</g>'//nl
   end function panel

   !> True where v is a value a log axis can show.
   elemental logical function positive(v)
      real(wp), intent(in) :: v
      positive = .false.
      if (.not. is_empty(v)) positive = v > 0.0_wp
   end function positive

   !> Whole decades enclosing the values (at least one decade).
   function log_axis(v) result(axis)
      real(wp), intent(in) :: v(:)
      type(axis_type) :: axis
      axis%lo = floor(log10(minval(v)))
      axis%hi = ceiling(log10(maxval(v)))
      if (axis%hi <= axis%lo) axis%hi = axis%lo + 1
   end function log_axis

   !> Pixel position of v on an axis running from pixel a (decade lo) to b (decade hi).
   pure real(wp) function map(axis, v, a, b)
      type(axis_type), intent(in) :: axis
      real(wp), intent(in) :: v, a, b
      map = a + (log10(v) - axis%lo)/real(axis%hi - axis%lo, wp)*(b - a)
   end function map

   function frame(left, right) result(text)
      real(wp), intent(in) :: left, right
      character(len=:), allocatable :: text
      text = '<rect x="'//num(left)//'" y="'//num(plot_top)//'" width="'//num(right - left)//'" height="'// &
         num(plot_bottom - plot_top)//'" fill="none" stroke="black" stroke-width="1"/>'//nl
   end function frame

   !> Grid lines, major ticks labelled 10^k (every decade, or every n-th when
   !> there are many), minor ticks at 2..9 when the axis spans <= 6 decades.
   function ticks(axis, left, right, horizontal) result(text)
      type(axis_type), intent(in) :: axis
      real(wp), intent(in) :: left, right
      logical, intent(in) :: horizontal
      character(len=:), allocatable :: text
      integer :: k, m, step
      real(wp) :: t
      character(len=:), allocatable :: label

      text = ''
      step = max(1, (axis%hi - axis%lo + 7)/8)
      do k = axis%lo, axis%hi
         label = '10<tspan dy="-7" font-size="10">'//inum(real(k, wp))//'</tspan>'
         if (horizontal) then
            t = map(axis, 10.0_wp**k, left, right)
            text = text//line(t, plot_top, t, plot_bottom, '#dddddd')//line(t, plot_bottom, t, plot_bottom + 6, 'black')
            if (mod(k - axis%lo, step) == 0) text = text//'<text x="'//num(t)//'" y="'//num(plot_bottom + 22)// &
               '" text-anchor="middle">'//label//'</text>'//nl
         else
            t = map(axis, 10.0_wp**k, plot_bottom, plot_top)
            text = text//line(left, t, right, t, '#dddddd')//line(left - 6, t, left, t, 'black')
            if (mod(k - axis%lo, step) == 0) text = text//'<text x="'//num(left - 10)//'" y="'//num(t + 4)// &
               '" text-anchor="end">'//label//'</text>'//nl
         end if
         if (k == axis%hi .or. axis%hi - axis%lo > 6) cycle
         do m = 2, 9
            if (horizontal) then
               t = map(axis, m*10.0_wp**k, left, right)
               text = text//line(t, plot_bottom, t, plot_bottom + 3, 'black')
            else
               t = map(axis, m*10.0_wp**k, plot_bottom, plot_top)
               text = text//line(left - 3, t, left, t, 'black')
            end if
         end do
      end do
   end function ticks

   function line(xa, ya, xb, yb, colour) result(text)
      real(wp), intent(in) :: xa, ya, xb, yb
      character(len=*), intent(in) :: colour
      character(len=:), allocatable :: text
      text = '<line x1="'//num(xa)//'" y1="'//num(ya)//'" x2="'//num(xb)//'" y2="'//num(yb)// &
         '" stroke="'//colour//'" stroke-width="1"/>'//nl
   end function line

   !> Filled circle (err_*) or open square (eta_*) centred at (x, y).
   function marker(k, x, y, class) result(text)
      integer, intent(in) :: k
      real(wp), intent(in) :: x, y
      character(len=*), intent(in) :: class
      character(len=:), allocatable :: text
      if (series_estimate(k)) then
         text = '<rect class="'//class//'" x="'//num(x - 3.5_wp)//'" y="'//num(y - 3.5_wp)// &
            '" width="7" height="7" fill="white" stroke="'//series_colour(k)//'" stroke-width="1.5"/>'//nl
      else if (k == 1) then
         text = '<circle class="'//class//'" cx="'//num(x)//'" cy="'//num(y)//'" r="6" fill="'// &
            series_colour(k)//'" fill-opacity="0.35"/>'//nl
      else
         text = '<circle class="'//class//'" cx="'//num(x)//'" cy="'//num(y)//'" r="4" fill="'// &
            series_colour(k)//'"/>'//nl
      end if
   end function marker

   !> Stroke attributes of series k: err_fe (k = 1) a wide pale band, estimates dashed.
   pure function series_stroke(k) result(text)
      integer, intent(in) :: k
      character(len=:), allocatable :: text
      if (k == 1) then
         text = ' stroke-width="6" stroke-opacity="0.35"'
      else
         text = ' stroke-width="1.8"'//pick(series_estimate(k), ' stroke-dasharray="6,4"', '')
      end if
   end function series_stroke

   !> One row of legend entries under the panels, centred.
   function legend(active) result(text)
      logical, intent(in) :: active(:)
      character(len=:), allocatable :: text
      real(wp), parameter :: entry_width = 130.0_wp, y = 450.0_wp
      real(wp) :: x
      integer :: k

      text = ''
      if (.not. any(active)) return
      x = (page_width - count(active)*entry_width)/2
      do k = 1, n_series
         if (.not. active(k)) cycle
         text = text//'<line x1="'//num(x)//'" y1="'//num(y)//'" x2="'//num(x + 36)//'" y2="'//num(y)// &
            '" stroke="'//series_colour(k)//'"'//series_stroke(k)//'/>'//nl// &
            marker(k, x + 18, y, 'legend')// &
            '<text x="'//num(x + 44)//'" y="'//num(y + 4)//'">'//trim(series_name(k))//'</text>'//nl
         x = x + entry_width
      end do
   end function legend

   !> `a` if `condition`, else `b`.
   pure function pick(condition, a, b) result(s)
      logical, intent(in) :: condition
      character(len=*), intent(in) :: a, b
      character(len=:), allocatable :: s
      if (condition) then
         s = a
      else
         s = b
      end if
   end function pick

   !> A coordinate with 2 decimals and a leading zero.
   function num(v) result(s)
      real(wp), intent(in) :: v
      character(len=:), allocatable :: s
      s = fixed_text(v, 2)
   end function num

   !> An integral value as text.
   function inum(v) result(s)
      real(wp), intent(in) :: v
      character(len=:), allocatable :: s
      character(len=24) :: buf
      write (buf, '(i0)') nint(v)
      s = trim(buf)
   end function inum

   !> Text with the XML special characters escaped.
   pure function escape(s) result(t)
      character(len=*), intent(in) :: s
      character(len=:), allocatable :: t
      integer :: i
      t = ''
      do i = 1, len(s)
         select case (s(i:i))
         case ('&'); t = t//'&amp;'
         case ('<'); t = t//'&lt;'
         case ('>'); t = t//'&gt;'
         case ('"'); t = t//'&quot;'
         case ("'"); t = t//'&apos;'
         case default; t = t//s(i:i)
         end select
      end do
   end function escape

end module sprc_io_svg
