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
!> The time panel's abscissa is the cumulative run time, the sum of t_total
!> over the rows so far: what reaching that accuracy cost (for an adaptive
!> study, the steps so far; for a uniform one, the levels run in order). It
!> grows from row to row, so timing noise cannot fold a curve back on itself.
!> The legend names each series in words (the energy norm of the error or
!> the ZZ estimate). Given the order p and the dimension d, the dofs panel
!> has a dotted reference line of slope -p/d, the optimal rate, and the
!> legend the rate measured between the last two rows.
!>
!> The contact plot (`contact_svg`, PREFIX_contact.svg) is one panel with
!> linear axes: the contact pressure p_fe, p_spr, p_sprc and p_exact at the
!> slave points of a level, in 2D against the arc length along the slave
!> surface (points ordered by their projection on the principal direction
!> of the points, which is monotone along a flat or gently curved surface
!> and along a quarter circle, and joined in that order) or, in 3D, against
!> the distance from the point of peak pressure (exact, else FE; markers
!> only, a surface has no order). The abscissa spans the loaded part of the
!> surface with a margin. Same page layout, markers and legend as the report
!> plot.
module sprc_io_svg
   use sprc_core_kinds, only: wp, i8
   use sprc_core_sort, only: sort_order
   use sprc_core_text, only: fixed_text, xml_escape
   use sprc_core_alloc, only: check_allocation
   use sprc_core_error, only: error_type, fatal_error, stat_io
   use sprc_io_report, only: report_row_type, report_column, is_empty, report_empty
   use sprc_contact_result, only: contact_result_type, contact_open
   implicit none
   private

   public :: write_report_svg, report_svg, write_contact_svg, contact_svg

   integer, parameter :: n_series = 5
   character(len=8), parameter :: series_name(n_series) = [character(len=8) :: &
      & 'err_fe', 'err_spr', 'err_sprc', 'eta_spr', 'eta_sprc']
   !> The legend's words for each series.
   character(len=*), parameter :: series_label(n_series) = [character(len=64) :: &
      & 'FE error ‖σ−σ_h‖_E / ‖σ‖_E (err_fe)', 'SPR error ‖σ−σ*‖_E / ‖σ‖_E (err_spr)', &
      & 'SPR-C error ‖σ−σ*‖_E / ‖σ‖_E (err_sprc)', 'ZZ estimate, SPR (eta_spr)', &
      & 'ZZ estimate, SPR-C (eta_sprc)']
   character(len=7), parameter :: series_colour(n_series) = [character(len=7) :: &
      & '#1f77b4', '#ff7f0e', '#2ca02c', '#ff7f0e', '#2ca02c']
   logical, parameter :: series_estimate(n_series) = [.false., .false., .false., .true., .true.]

   !> Page and panel geometry in px. Panel p occupies x in [(p-1)*panel_width, p*panel_width].
   real(wp), parameter :: page_width = 1000.0_wp, page_height = 510.0_wp, panel_width = 500.0_wp
   real(wp), parameter :: plot_left = 85.0_wp, plot_right = 475.0_wp, plot_top = 70.0_wp, plot_bottom = 370.0_wp

   character(len=*), parameter :: nl = new_line('a')

   !> Decades [lo, hi] covered by a log axis.
   type :: axis_type
      integer :: lo = 0, hi = 1
   end type axis_type

   !> A linear axis from lo to hi with ticks every `step`.
   type :: linear_axis_type
      real(wp) :: lo = 0.0_wp, hi = 1.0_wp, step = 0.5_wp
   end type linear_axis_type

   !> The markers: pale wide disc (a reference drawn as a band), filled circle, open square, none.
   integer, parameter :: marker_band = 1, marker_dot = 2, marker_square = 3, marker_none = 4

   !> How a series is drawn: its name (class), colour, stroke attributes, marker
   !> and its words in the legend (the name when not set).
   type :: series_style_type
      character(len=:), allocatable :: name, colour, stroke
      integer :: marker = marker_dot
      character(len=:), allocatable :: label
   end type series_style_type

   !> The reference line of the optimal rate.
   character(len=*), parameter :: reference_colour = '#555555', &
      & reference_stroke = ' stroke-width="1.5" stroke-dasharray="2,3"'

   !> The contact plot's series: FE, SPR, SPR-C and the exact pressure.
   integer, parameter :: n_contact_series = 4
   !> At most this many markers per series in the contact plot: a 3D slave
   !> surface has tens of thousands of points; more markers only blacken the
   !> picture and bloat the file. Every k-th point (in abscissa order) is drawn.
   integer, parameter :: max_markers = 2000

   !> Text built piece by piece in amortized linear time (a plot of many
   !> points made by repeated concatenation took quadratic time: 23 s for
   !> the 22k slave points of a 3D level).
   !> Its growth is an allocation sized by the input (the slave points):
   !> one that fails marks the buffer (`stat`), which then takes no more
   !> pieces, and `buffer_error` turns the mark into an error.
   type :: text_buffer_type
      character(len=:), allocatable :: text
      integer :: n = 0
      !> The stat= of a growth that failed (-1: longer than the longest string); 0 while all fitted.
      integer :: stat = 0
      !> The length that growth asked for.
      integer(i8) :: wanted = 0
   end type text_buffer_type
   !> Extent of the contact plot's panel (one panel across the page).
   real(wp), parameter :: contact_right = page_width - 25.0_wp

contains

   !> Write the plot of `rows` to `path` (replacing it). Fails with stat_io naming the path.
   subroutine write_report_svg(path, rows, title, error, order, dim)
      character(len=*), intent(in) :: path
      type(report_row_type), intent(in) :: rows(:)
      !> Title on top of the picture (plain text; escaped here).
      character(len=*), intent(in) :: title
      type(error_type), allocatable, intent(out) :: error
      !> FE order and dimension: with both, the reference slope -order/dim.
      integer, intent(in), optional :: order, dim

      call write_text(path, 'report SVG', report_svg(rows, title, order, dim), error)
   end subroutine write_report_svg

   !> Write the contact plot of `contacts` (one level's pairs) to `path`
   !> (replacing it). Fails with stat_io naming the path.
   subroutine write_contact_svg(path, contacts, title, error)
      character(len=*), intent(in) :: path
      type(contact_result_type), intent(in) :: contacts(:)
      !> Title on top of the picture (plain text; escaped here).
      character(len=*), intent(in) :: title
      type(error_type), allocatable, intent(out) :: error
      type(text_buffer_type) :: buf

      call contact_picture(contacts, title, buf, error)
      if (allocated(error)) return
      call write_text(path, 'contact SVG', buf%text(:buf%n), error)
   end subroutine write_contact_svg

   !> Write `text` to `path` (replacing it); `what` names the file in messages.
   subroutine write_text(path, what, text, error)
      character(len=*), intent(in) :: path, what, text
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, stat
      character(len=256) :: msg

      open (newunit=unit, file=path, status='replace', action='write', access='stream', form='unformatted', &
         iostat=stat, iomsg=msg)
      if (stat /= 0) then
         call fatal_error(error, what//': cannot open "'//path//'" for writing: '//trim(msg), stat_io)
         return
      end if
      write (unit, iostat=stat, iomsg=msg) text
      if (stat /= 0) then
         close (unit)
         call fatal_error(error, what//': cannot write "'//path//'": '//trim(msg), stat_io)
         return
      end if
      close (unit, iostat=stat, iomsg=msg)
      if (stat /= 0) call fatal_error(error, what//': cannot close "'//path//'": '//trim(msg), stat_io)
   end subroutine write_text

   !> The report plot's series, from the constants above.
   function report_styles() result(styles)
      type(series_style_type) :: styles(n_series)
      integer :: k
      do k = 1, n_series
         styles(k)%name = trim(series_name(k))
         styles(k)%colour = series_colour(k)
         styles(k)%stroke = series_stroke(k)
         styles(k)%label = trim(series_label(k))
         if (k == 1) then
            styles(k)%marker = marker_band
         else if (series_estimate(k)) then
            styles(k)%marker = marker_square
         else
            styles(k)%marker = marker_dot
         end if
      end do
   end function report_styles

   !> The SVG text of the plot of `rows`.
   function report_svg(rows, title, order, dim) result(svg)
      type(report_row_type), intent(in) :: rows(:)
      character(len=*), intent(in) :: title
      !> FE order and dimension: with both, the reference slope -order/dim.
      integer, intent(in), optional :: order, dim
      character(len=:), allocatable :: svg
      real(wp) :: y(size(rows), n_series), x(size(rows), 2), levels(size(rows)), rate
      logical :: active(n_series), shown(n_series + 2)
      type(series_style_type) :: styles(n_series + 2)
      integer :: k, p

      levels = report_column(rows, 'level')
      x(:, 1) = cumulative_time(report_column(rows, 't_total'))
      x(:, 2) = report_column(rows, 'dofs')
      rate = report_empty
      if (present(order) .and. present(dim)) rate = real(order, wp)/dim
      do k = 1, n_series
         y(:, k) = report_column(rows, trim(series_name(k)))
         active(k) = any(.not. is_empty(y(:, k)))
      end do

      svg = page_open('sprc report: relative errors (err_*) and estimated relative errors (eta_*) on log-log '// &
         'axes. Empty cells and values <= 0 are skipped: a log scale cannot show them.', &
         skipped_comment(x, y, active, levels), title)
      do p = 1, 2
         svg = svg//panel(p, x(:, p), y, active, rate)
      end do
      styles(:n_series) = report_styles()
      shown(:n_series) = active
      k = reference_series(active)
      shown(n_series + 1) = .not. is_empty(rate) .and. k > 0
      shown(n_series + 2) = k > 0
      styles(n_series + 1)%name = 'reference'
      styles(n_series + 1)%colour = reference_colour
      styles(n_series + 1)%stroke = reference_stroke
      styles(n_series + 1)%marker = marker_none
      if (shown(n_series + 1)) styles(n_series + 1)%label = 'optimal rate p/d = '//inum(real(order, wp))//'/'// &
         & inum(real(dim, wp))//' (dotted)'
      styles(n_series + 2)%name = 'measured'
      styles(n_series + 2)%colour = 'none'
      styles(n_series + 2)%stroke = ''
      styles(n_series + 2)%marker = marker_none
      if (k > 0) styles(n_series + 2)%label = measured_rate(x(:, 2), y(:, k), trim(series_name(k)))
      svg = svg//legend(styles, shown)//'</g>'//nl//'</svg>'//nl
   end function report_svg

   !> The running sum of `t` (empty cells add nothing and stay empty).
   pure function cumulative_time(t) result(c)
      real(wp), intent(in) :: t(:)
      real(wp) :: c(size(t)), total
      integer :: i
      total = 0.0_wp
      do i = 1, size(t)
         c(i) = t(i)
         if (is_empty(t(i))) cycle
         total = total + t(i)
         c(i) = total
      end do
   end function cumulative_time

   !> The series the rates refer to: err_fe, else eta_sprc, else eta_spr (0: none active).
   pure integer function reference_series(active)
      logical, intent(in) :: active(:)
      integer, parameter :: preference(3) = [1, 5, 4]
      integer :: k
      reference_series = 0
      do k = 1, size(preference)
         if (.not. active(preference(k))) cycle
         reference_series = preference(k)
         return
      end do
   end function reference_series

   !> The legend's words for the rate of `y` against the dofs `n` between the
   !> last two rows where both can be shown on log axes: -d log y / d log n.
   function measured_rate(n, y, name) result(text)
      real(wp), intent(in) :: n(:), y(:)
      character(len=*), intent(in) :: name
      character(len=:), allocatable :: text
      integer :: i, last, before

      last = 0
      before = 0
      do i = 1, size(n)
         if (.not. (positive(n(i)) .and. positive(y(i)))) cycle
         before = last
         last = i
      end do
      text = 'measured rate of '//name//': '
      if (before == 0) then
         text = text//'needs two rows'
      else if (.not. (n(last) > n(before) .or. n(last) < n(before))) then
         text = text//'needs two dof counts'
      else
         text = text//fixed_text(-log(y(last)/y(before))/log(n(last)/n(before)), 2)//' (last two rows)'
      end if
   end function measured_rate

   !> The start of a page: XML declaration, svg element, a comment, `extra`
   !> (comments), title, white background, the group of text defaults, the
   !> title line. `page_close` ends it.
   function page_open(comment, extra, title) result(svg)
      character(len=*), intent(in) :: comment, extra, title
      character(len=:), allocatable :: svg
      svg = '<?xml version="1.0" encoding="UTF-8" standalone="no"?>'//nl// &
         '<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="'//num(page_width)//'" height="'// &
         num(page_height)//'" viewBox="0 0 '//num(page_width)//' '//num(page_height)//'">'//nl// &
         '<!-- '//comment//' -->'//nl//extra// &
         '<title>'//xml_escape(title)//'</title>'//nl// &
         '<rect x="0" y="0" width="'//num(page_width)//'" height="'//num(page_height)//'" fill="white"/>'//nl// &
         '<g font-family="sans-serif" font-size="12" fill="black">'//nl// &
         '<text x="'//num(page_width/2)//'" y="30" font-size="18" text-anchor="middle">'//xml_escape(title)// &
         '</text>'//nl
   end function page_open

   !> The SVG text of the contact plot of `contacts` (one level's pairs).
   subroutine contact_svg(contacts, title, svg, error)
      type(contact_result_type), intent(in) :: contacts(:)
      character(len=*), intent(in) :: title
      character(len=:), allocatable, intent(out) :: svg
      type(error_type), allocatable, intent(out) :: error
      type(text_buffer_type) :: buf
      integer :: stat

      call contact_picture(contacts, title, buf, error)
      if (allocated(error)) return
      allocate (character(len=buf%n) :: svg, stat=stat)
      call check_allocation(stat, 'contact SVG', 'the text of the picture', buf%n, 1, error)
      if (allocated(error)) return
      svg(1:buf%n) = buf%text(:buf%n)
   end subroutine contact_svg

   !> The contact plot of `contacts` in `buf`. Every array sized by the
   !> slave points is allocated here, with stat= (sprc_core_alloc): the
   !> points in abscissa order, then those shown, are prefixes of `order`.
   subroutine contact_picture(contacts, title, buf, error)
      type(contact_result_type), intent(in) :: contacts(:)
      character(len=*), intent(in) :: title
      type(text_buffer_type), intent(out) :: buf
      type(error_type), allocatable, intent(out) :: error
      type(series_style_type) :: styles(n_contact_series)
      real(wp), allocatable :: x(:, :), p(:, :), s(:)
      integer, allocatable :: order(:), work(:)
      logical, allocatable :: closed(:)
      logical :: active(n_contact_series)
      integer :: dim, k, n, stat

      styles = contact_styles()
      call gather_points(contacts, x, p, closed, error)
      if (allocated(error)) return
      dim = 2
      if (size(contacts) > 0) dim = contacts(1)%dim
      n = size(x, 2)
      allocate (s(n), order(n), work(n), stat=stat)
      call check_allocation(stat, 'contact SVG', 'the abscissae of the slave points', n, 16, error)
      if (allocated(error)) return
      if (dim == 2) then
         call along_surface(x, s)
      else
         call from_peak(x, p, s)
      end if
      call sort_order(s, order, work)
      if (dim == 2) call arc_length(x, order, s)
      call contact_window(s, p, closed, order, n)
      do k = 1, n_contact_series
         active(k) = any(.not. is_empty(p(:, k)))
      end do
      call append(buf, page_open('sprc contact pressure along the slave surface (p = -n.sigma.n, positive in '// &
         'compression). Empty values (not computed) are left out; the abscissa spans the contact zone (the closed '// &
         'points; without any, the loaded ones) and a quarter of it on either side.', '', title))
      call contact_panel(buf, s, p, order(:n), styles, active, dim == 2, error)
      if (allocated(error)) return
      call append(buf, legend(styles, active)//'</g>'//nl//'</svg>'//nl)
      call buffer_error(buf, 'contact SVG', error)
   end subroutine contact_picture

   !> The contact plot's series: FE dots, SPR dashed squares, SPR-C dots, exact a black line.
   function contact_styles() result(styles)
      type(series_style_type) :: styles(n_contact_series)
      styles(1) = series_style_type('p_fe', '#1f77b4', ' stroke-width="1.8"', marker_dot)
      styles(2) = series_style_type('p_spr', '#ff7f0e', ' stroke-width="1.8" stroke-dasharray="6,4"', marker_square)
      styles(3) = series_style_type('p_sprc', '#2ca02c', ' stroke-width="1.8"', marker_dot)
      styles(4) = series_style_type('p_exact', '#000000', ' stroke-width="1.5"', marker_none)
   end function contact_styles

   !> Every slave point of every pair: coordinates x(dim, n), pressures
   !> p(n, 4) in the order of `contact_styles`, whether it is closed (stick or slip).
   subroutine gather_points(contacts, x, p, closed, error)
      type(contact_result_type), intent(in) :: contacts(:)
      real(wp), allocatable, intent(out) :: x(:, :), p(:, :)
      logical, allocatable, intent(out) :: closed(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: k, n, m, dim, stat

      dim = 2
      if (size(contacts) > 0) dim = contacts(1)%dim
      allocate (x(dim, sum(contacts%npoint)), p(sum(contacts%npoint), n_contact_series), &
         & closed(sum(contacts%npoint)), stat=stat)
      call check_allocation(stat, 'contact SVG', 'the slave points', sum(contacts%npoint), &
         & 8*(dim + n_contact_series) + 4, error)
      if (allocated(error)) return
      n = 0
      do k = 1, size(contacts)
         m = contacts(k)%npoint
         x(:, n + 1:n + m) = contacts(k)%x
         p(n + 1:n + m, 1) = contacts(k)%p_fe
         p(n + 1:n + m, 2) = contacts(k)%p_spr
         p(n + 1:n + m, 3) = contacts(k)%p_sprc
         p(n + 1:n + m, 4) = contacts(k)%p_exact
         closed(n + 1:n + m) = contacts(k)%state(:m) /= contact_open
         n = n + m
      end do
   end subroutine gather_points

   !> In 2D, s is the coordinate of each point x(:, i) along the principal direction
   !> of the points (largest spread), from their centroid, the direction's first
   !> nonzero component positive.
   pure subroutine along_surface(x, s)
      real(wp), intent(in) :: x(:, :)
      real(wp), intent(out) :: s(:)
      real(wp) :: c(2), d(2), t(2), sxy, sxx, syy, theta
      integer :: i

      if (size(x, 2) == 0) return
      c = sum(x, dim=2)/size(x, 2)
      sxy = 0.0_wp
      sxx = 0.0_wp
      syy = 0.0_wp
      do i = 1, size(x, 2)
         d = x(:, i) - c
         sxy = sxy + d(1)*d(2)
         sxx = sxx + d(1)**2
         syy = syy + d(2)**2
      end do
      theta = 0.5_wp*atan2(2.0_wp*sxy, sxx - syy)
      t = [cos(theta), sin(theta)]
      if (t(1) < 0.0_wp .or. (.not. (abs(t(1)) > 0.0_wp) .and. t(2) < 0.0_wp)) t = -t
      do i = 1, size(x, 2)
         s(i) = dot_product(t, x(:, i) - c)
      end do
   end subroutine along_surface

   !> s(order(i)) = the arc length at the points x(:, order(:)), in that order
   !> along a curve: the sum of the distances between consecutive points, 0 at the first.
   pure subroutine arc_length(x, order, s)
      real(wp), intent(in) :: x(:, :)
      integer, intent(in) :: order(:)
      real(wp), intent(inout) :: s(:)
      integer :: i

      if (size(order) == 0) return
      s(order(1)) = 0.0_wp
      do i = 2, size(order)
         s(order(i)) = s(order(i - 1)) + norm2(x(:, order(i)) - x(:, order(i - 1)))
      end do
   end subroutine arc_length

   !> The points to plot: of `order` (s ascending), the first `m` on return are
   !> those within the contact zone and a quarter of its length on either side,
   !> in the same order, so that a Hertz contact a few per cent of the surface
   !> long fills the picture. The zone is the stretch of the closed points;
   !> without any, of the loaded ones (some pressure above 1e-3 of the
   !> largest); without either, every point is plotted.
   pure subroutine contact_window(s, p, closed, order, m)
      real(wp), intent(in) :: s(:), p(:, :)
      logical, intent(in) :: closed(:)
      integer, intent(inout) :: order(:)
      integer, intent(out) :: m
      real(wp) :: p_max, lo, hi, margin
      integer :: i, j
      logical :: in_zone(size(s))

      m = size(order)
      if (any(closed)) then
         in_zone = closed
      else
         p_max = 0.0_wp
         do i = 1, size(s)
            p_max = max(p_max, maxval(abs(p(i, :)), mask=.not. is_empty(p(i, :))))
         end do
         if (.not. (p_max > 0.0_wp)) return
         do i = 1, size(s)
            in_zone(i) = any(abs(p(i, :)) > 1.0e-3_wp*p_max .and. .not. is_empty(p(i, :)))
         end do
      end if
      lo = minval(s, mask=in_zone)
      hi = maxval(s, mask=in_zone)
      margin = 0.25_wp*(hi - lo)
      if (.not. (margin > 0.0_wp)) margin = 0.05_wp*(s(order(size(order))) - s(order(1)))
      m = 0
      do i = 1, size(order)
         j = order(i)
         if (s(j) < lo - margin .or. s(j) > hi + margin) cycle
         m = m + 1
         order(m) = j
      end do
   end subroutine contact_window

   !> In 3D, s is the distance of each point from the point of largest exact pressure
   !> (largest FE pressure without an exact one; the first point without either).
   pure subroutine from_peak(x, p, s)
      real(wp), intent(in) :: x(:, :), p(:, :)
      real(wp), intent(out) :: s(:)
      integer :: i, peak, k

      if (size(x, 2) == 0) return
      peak = 0
      do k = 4, 1, -3
         do i = 1, size(x, 2)
            if (is_empty(p(i, k))) cycle
            if (peak == 0) then
               peak = i
            else if (p(i, k) > p(peak, k)) then
               peak = i
            end if
         end do
         if (peak > 0) exit
      end do
      peak = max(peak, 1)
      do i = 1, size(x, 2)
         s(i) = norm2(x(:, i) - x(:, peak))
      end do
   end subroutine from_peak

   !> The one panel of the contact plot, appended to `buf`: frame, grid, ticks,
   !> axis titles, one series per active column of p over the points `shown`
   !> (joined by lines when `lines`).
   subroutine contact_panel(buf, s, p, shown, styles, active, lines, error)
      type(text_buffer_type), intent(inout) :: buf
      real(wp), intent(in) :: s(:), p(:, :)
      integer, intent(in) :: shown(:)
      type(series_style_type), intent(in) :: styles(:)
      logical, intent(in) :: active(:), lines
      type(error_type), allocatable, intent(out) :: error
      type(linear_axis_type) :: ax, ay
      real(wp), allocatable :: xs(:), ys(:)
      real(wp) :: s_range(2), p_range(2)
      integer :: k, i, m, stat

      s_range = [huge(1.0_wp), -huge(1.0_wp)]
      p_range = [0.0_wp, 0.0_wp]
      do k = 1, size(styles)
         if (.not. active(k)) cycle
         do i = 1, size(shown)
            if (is_empty(p(shown(i), k))) cycle
            s_range = [min(s_range(1), s(shown(i))), max(s_range(2), s(shown(i)))]
            p_range = [min(p_range(1), p(shown(i), k)), max(p_range(2), p(shown(i), k))]
         end do
      end do
      call append(buf, '<g>'//nl//'<text x="'//num((plot_left + contact_right)/2)//'" y="'// &
         num(plot_bottom + 42)//'" text-anchor="middle">'//pick(lines, 'arc length along the slave surface', &
         'distance from the point of peak pressure')//'</text>'//nl// &
         '<text x="22" y="'//num((plot_top + plot_bottom)/2)//'" text-anchor="middle" '// &
         'transform="rotate(-90 22 '//num((plot_top + plot_bottom)/2)//')">contact pressure p</text>'//nl)
      if (s_range(1) > s_range(2)) then
         call append(buf, frame(plot_left, contact_right)//'<text x="'//num((plot_left + contact_right)/2)// &
            '" y="'//num((plot_top + plot_bottom)/2)//'" text-anchor="middle" fill="#888888">no data</text>'// &
            nl//'</g>'//nl)
         return
      end if
      allocate (xs(size(shown)), ys(size(shown)), stat=stat)
      call check_allocation(stat, 'contact SVG', 'the positions of the points shown', size(shown), 16, error)
      if (allocated(error)) return
      ax = linear_axis(s_range)
      ay = linear_axis(p_range)
      call append(buf, linear_ticks(ax, .true.)//linear_ticks(ay, .false.)//frame(plot_left, contact_right))
      do k = 1, size(styles)
         if (.not. active(k)) cycle
         m = 0
         do i = 1, size(shown)
            if (is_empty(p(shown(i), k))) cycle
            m = m + 1
            xs(m) = linear_map(ax, s(shown(i)), plot_left, contact_right)
            ys(m) = linear_map(ay, p(shown(i), k), plot_bottom, plot_top)
         end do
         if (lines .and. m >= 2) call append_polyline(buf, styles(k), xs(:m), ys(:m))
         do i = 1, m, max(1, (m + max_markers - 1)/max_markers)
            call append(buf, marker(styles(k), xs(i), ys(i), 'point '//styles(k)%name))
         end do
      end do
      call append(buf, '</g>'//nl)
   end subroutine contact_panel

   !> Add `piece` to the end of `buf`, doubling its room when full. A growth
   !> that cannot be allocated marks `buf` failed (`stat`, `wanted`); a failed
   !> buffer takes no more pieces.
   pure subroutine append(buf, piece)
      type(text_buffer_type), intent(inout) :: buf
      character(len=*), intent(in) :: piece
      character(len=:), allocatable :: larger
      integer(i8) :: needed, room

      if (buf%stat /= 0) return
      needed = int(buf%n, i8) + len(piece)
      room = 0
      if (allocated(buf%text)) room = len(buf%text)
      if (needed > room) then
         room = min(max(4096_i8, 2*room, needed), int(huge(0), i8))
         buf%wanted = room
         if (needed > room) then
            buf%stat = -1
            return
         end if
         allocate (character(len=room) :: larger, stat=buf%stat)
         if (buf%stat /= 0) return
         if (buf%n > 0) larger(:buf%n) = buf%text(:buf%n)
         call move_alloc(larger, buf%text)
      end if
      buf%text(buf%n + 1:buf%n + len(piece)) = piece
      buf%n = buf%n + len(piece)
   end subroutine append

   !> `error` (stat_out_of_memory) when a growth of `buf` failed; `who` names the picture.
   pure subroutine buffer_error(buf, who, error)
      type(text_buffer_type), intent(in) :: buf
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      call check_allocation(buf%stat, who, 'the text of the picture', buf%wanted, 1, error)
   end subroutine buffer_error

   !> An axis from a multiple of a round step (1, 2 or 5 times a power of ten,
   !> about five steps) below the values to one above them; a single value
   !> gets a range around it.
   pure function linear_axis(v) result(axis)
      real(wp), intent(in) :: v(:)
      type(linear_axis_type) :: axis
      real(wp), parameter :: nice(3) = [1.0_wp, 2.0_wp, 5.0_wp]
      real(wp) :: lo, hi, raw, unit
      integer :: k

      lo = minval(v)
      hi = maxval(v)
      if (.not. (hi > lo)) then
         raw = max(abs(lo), tiny(1.0_wp))
         lo = lo - 0.5_wp*raw
         hi = hi + 0.5_wp*raw
      end if
      raw = (hi - lo)/5.0_wp
      unit = 10.0_wp**floor(log10(raw))
      axis%step = 10.0_wp*unit
      do k = 3, 1, -1
         if (raw <= nice(k)*unit) axis%step = nice(k)*unit
      end do
      axis%lo = floor(lo/axis%step)*axis%step
      axis%hi = ceiling(hi/axis%step)*axis%step
   end function linear_axis

   !> Pixel position of v on a linear axis running from pixel a (lo) to b (hi).
   pure real(wp) function linear_map(axis, v, a, b)
      type(linear_axis_type), intent(in) :: axis
      real(wp), intent(in) :: v, a, b
      linear_map = a + (v - axis%lo)/(axis%hi - axis%lo)*(b - a)
   end function linear_map

   !> Grid lines, ticks and labels at every step of a linear axis of the contact panel.
   function linear_ticks(axis, horizontal) result(text)
      type(linear_axis_type), intent(in) :: axis
      logical, intent(in) :: horizontal
      character(len=:), allocatable :: text, label
      real(wp) :: t, v
      integer :: k, n

      text = ''
      n = nint((axis%hi - axis%lo)/axis%step)
      do k = 0, n
         v = axis%lo + k*axis%step
         label = tick_label(v, axis%step)
         if (horizontal) then
            t = linear_map(axis, v, plot_left, contact_right)
            text = text//line(t, plot_top, t, plot_bottom, '#dddddd')//line(t, plot_bottom, t, plot_bottom + 6, 'black')// &
               '<text x="'//num(t)//'" y="'//num(plot_bottom + 22)//'" text-anchor="middle">'//label//'</text>'//nl
         else
            t = linear_map(axis, v, plot_bottom, plot_top)
            text = text//line(plot_left, t, contact_right, t, '#dddddd')//line(plot_left - 6, t, plot_left, t, 'black')// &
               '<text x="'//num(plot_left - 10)//'" y="'//num(t + 4)//'" text-anchor="end">'//label//'</text>'//nl
         end if
      end do
   end function linear_ticks

   !> A tick value with the decimals its step needs (fixed point for steps
   !> 1e-4 .. 1e5, es notation outside); a value within round-off of 0 is '0'.
   function tick_label(v, step) result(label)
      real(wp), intent(in) :: v, step
      character(len=:), allocatable :: label
      character(len=32) :: buf

      if (abs(v) < 1.0e-9_wp*step) then
         label = '0'
      else if (step >= 1.0e-4_wp .and. step < 1.0e5_wp) then
         label = fixed_text(v, max(0, -floor(log10(step) + 1.0e-9_wp)))
         ! f0.0 ends in a point: "3." is 3
         if (label(len(label):) == '.') label = label(:len(label) - 1)
      else
         write (buf, '(es10.2)') v
         label = trim(adjustl(buf))
      end if
   end function tick_label

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
   !> In panel 2 (dofs), a `rate` not empty draws the reference line of slope -rate.
   function panel(p, x, y, active, rate) result(text)
      integer, intent(in) :: p
      real(wp), intent(in) :: x(:), y(:, :)
      logical, intent(in) :: active(:)
      real(wp), intent(in) :: rate
      character(len=:), allocatable :: text
      logical :: valid(size(x), n_series)
      type(axis_type) :: ax, ay
      type(series_style_type) :: styles(n_series)
      real(wp) :: x0, left, right, xs(size(x)), ys(size(x))
      integer :: k, i, m

      styles = report_styles()
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
         '" text-anchor="middle">'//pick(p == 1, 'cumulative run time, sum of t_total [s]', &
         'degrees of freedom')//'</text>'//nl// &
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
      k = reference_series(any(valid, dim=1))
      if (p == 2 .and. .not. is_empty(rate) .and. k > 0) text = text//reference_line(ax, ay, left, right, &
         & pack(x, valid(:, k)), pack(y(:, k), valid(:, k)), rate)
      do k = 1, n_series
         m = 0
         do i = 1, size(x)
            if (.not. valid(i, k)) cycle
            m = m + 1
            xs(m) = map(ax, x(i), left, right)
            ys(m) = map(ay, y(i, k), plot_bottom, plot_top)
         end do
         if (m >= 2) text = text//polyline(styles(k), xs(:m), ys(:m))
         do i = 1, m
            text = text//marker(styles(k), xs(i), ys(i), 'point '//trim(series_name(k)))
         end do
      end do
      text = text//'</g>'//nl
   end function panel

   !> The reference line of slope -rate on log axes through the point a factor
   !> 2 below the last of (xv, yv), clipped to the panel.
   function reference_line(ax, ay, left, right, xv, yv, rate) result(text)
      type(axis_type), intent(in) :: ax, ay
      real(wp), intent(in) :: left, right, xv(:), yv(:), rate
      character(len=:), allocatable :: text
      real(wp) :: lx, ly, lo, hi

      text = ''
      lx = log10(xv(size(xv)))
      ly = log10(yv(size(yv))/2)
      ! log10 y = ly - rate*(s - lx) within [ay%lo, ay%hi] for s in [lo, hi]
      lo = max(real(ax%lo, wp), lx + (ly - ay%hi)/rate)
      hi = min(real(ax%hi, wp), lx + (ly - ay%lo)/rate)
      if (.not. (hi > lo)) return
      text = '<line class="reference-slope" x1="'//num(map(ax, 10.0_wp**lo, left, right))//'" y1="'// &
         & num(map(ay, 10.0_wp**(ly - rate*(lo - lx)), plot_bottom, plot_top))//'" x2="'// &
         & num(map(ax, 10.0_wp**hi, left, right))//'" y2="'// &
         & num(map(ay, 10.0_wp**(ly - rate*(hi - lx)), plot_bottom, plot_top))//'" stroke="'//reference_colour// &
         & '"'//reference_stroke//'/>'//nl
   end function reference_line

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

   !> The line of a series through the few points (xs, ys) of the report plot.
   function polyline(style, xs, ys) result(text)
      type(series_style_type), intent(in) :: style
      real(wp), intent(in) :: xs(:), ys(:)
      character(len=:), allocatable :: text
      type(text_buffer_type) :: buf
      call append_polyline(buf, style, xs, ys)
      text = ''
      if (buf%stat == 0) text = buf%text(:buf%n)
   end function polyline

   !> Append the line of a series through the points (xs, ys) to `buf`.
   subroutine append_polyline(buf, style, xs, ys)
      type(text_buffer_type), intent(inout) :: buf
      type(series_style_type), intent(in) :: style
      real(wp), intent(in) :: xs(:), ys(:)
      integer :: i
      call append(buf, '<polyline class="line '//style%name//'" points="')
      do i = 1, size(xs)
         call append(buf, pick(i > 1, ' ', '')//num(xs(i))//','//num(ys(i)))
      end do
      call append(buf, '" fill="none" stroke="'//style%colour//'"'//style%stroke//'/>'//nl)
   end subroutine append_polyline

   !> The marker of a series centred at (x, y): a pale wide disc, a filled
   !> circle, an open square, or nothing.
   function marker(style, x, y, class) result(text)
      type(series_style_type), intent(in) :: style
      real(wp), intent(in) :: x, y
      character(len=*), intent(in) :: class
      character(len=:), allocatable :: text
      select case (style%marker)
      case (marker_square)
         text = '<rect class="'//class//'" x="'//num(x - 3.5_wp)//'" y="'//num(y - 3.5_wp)// &
            '" width="7" height="7" fill="white" stroke="'//style%colour//'" stroke-width="1.5"/>'//nl
      case (marker_band)
         text = '<circle class="'//class//'" cx="'//num(x)//'" cy="'//num(y)//'" r="6" fill="'// &
            style%colour//'" fill-opacity="0.35"/>'//nl
      case (marker_dot)
         text = '<circle class="'//class//'" cx="'//num(x)//'" cy="'//num(y)//'" r="4" fill="'// &
            style%colour//'"/>'//nl
      case default
         text = ''
      end select
   end function marker

   !> Stroke attributes of report series k: err_fe (k = 1) a wide pale band, estimates dashed.
   pure function series_stroke(k) result(text)
      integer, intent(in) :: k
      character(len=:), allocatable :: text
      if (k == 1) then
         text = ' stroke-width="6" stroke-opacity="0.35"'
      else
         text = ' stroke-width="1.8"'//pick(series_estimate(k), ' stroke-dasharray="6,4"', '')
      end if
   end function series_stroke

   !> Legend entries under the panels, the active series in rows of at most
   !> the page's width, each row centred: a line and marker (none for a
   !> colour 'none': words only) and the series' words.
   function legend(styles, active) result(text)
      type(series_style_type), intent(in) :: styles(:)
      logical, intent(in) :: active(:)
      character(len=:), allocatable :: text
      real(wp), parameter :: top = 440.0_wp, row_height = 24.0_wp, room = page_width - 40.0_wp
      real(wp) :: width(size(styles)), x, y
      integer :: k, first, last

      text = ''
      do k = 1, size(styles)
         width(k) = 0.0_wp
         if (active(k)) width(k) = entry_width(styles(k))
      end do
      y = top
      first = 1
      do while (first <= size(styles))
         last = first
         do while (last < size(styles))
            if (sum(width(first:last + 1)) > room) exit
            last = last + 1
         end do
         x = (page_width - sum(width(first:last)))/2
         do k = first, last
            if (.not. active(k)) cycle
            text = text//legend_entry(styles(k), x, y)
            x = x + width(k)
         end do
         if (any(active(first:last))) y = y + row_height
         first = last + 1
      end do
   end function legend

   !> The legend's words of a series.
   function legend_label(style) result(label)
      type(series_style_type), intent(in) :: style
      character(len=:), allocatable :: label
      label = style%name
      if (allocated(style%label)) label = style%label
   end function legend_label

   !> Width in px of a legend entry: the sample line and the words (about 6.5 px
   !> per character at font size 12; UTF-8 continuation bytes are no characters).
   function entry_width(style) result(w)
      type(series_style_type), intent(in) :: style
      real(wp) :: w
      character(len=:), allocatable :: label
      integer :: i, n
      label = legend_label(style)
      n = 0
      do i = 1, len(label)
         if (iand(ichar(label(i:i)), 192) /= 128) n = n + 1
      end do
      w = 6.5_wp*n + merge(24.0_wp, 68.0_wp, style%colour == 'none')
   end function entry_width

   !> One legend entry at (x, y).
   function legend_entry(style, x, y) result(text)
      type(series_style_type), intent(in) :: style
      real(wp), intent(in) :: x, y
      character(len=:), allocatable :: text
      if (style%colour == 'none') then
         text = '<text class="legend '//style%name//'" x="'//num(x)//'" y="'//num(y + 4)//'">'// &
            & xml_escape(legend_label(style))//'</text>'//nl
         return
      end if
      text = '<line x1="'//num(x)//'" y1="'//num(y)//'" x2="'//num(x + 36)//'" y2="'//num(y)// &
         '" stroke="'//style%colour//'"'//style%stroke//'/>'//nl// &
         marker(style, x + 18, y, 'legend')// &
         '<text class="legend '//style%name//'" x="'//num(x + 44)//'" y="'//num(y + 4)//'">'// &
         & xml_escape(legend_label(style))//'</text>'//nl
   end function legend_entry

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

end module sprc_io_svg
