!> Accuracy and speed table of the cut-cell quadrature (sprc_grid_quadrature).
!>
!> For eight bodies with closed-form measures, a uniform grid of 2^(dim*L)
!> cells on the unit square/cube at levels L = 2..6 is integrated with q = 1..8
!> points per direction (inside cells: tensor Gauss; cut cells: the
!> dimension-reduction rule; faces on grid planes: the face rule), and the
!> relative errors of the measure, the boundary measure and the first and
!> second moments (of x_1) are printed, with the largest error over the four and
!> the observed order between consecutive levels. Then the speed of the
!> cut-cell rule (cut cells per second, points per cut cell) at q = 2, 4, 6.
!>
!> Run: fpm run --example quadrature_table --profile release [-- quick|full [min_ratio]]
program quadrature_table
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_geometry_region, only: cell_cut
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_ellipse, new_box, new_halfspace, &
      & new_cylinder
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule, &
      & cut_cell_rule, default_min_ratio
   implicit none

   real(wp), parameter :: pi = acos(-1.0_wp)
   integer, parameter :: ncase = 9
   type(body_type) :: body
   type(error_type), allocatable :: error
   real(wp) :: exact(4), got(4), err(4), prev_err, worst, t0, t1, points
   integer :: icase, q, level, lmax, qmax, ncut, nsplitcells, nfallback, ncells
   character(len=40) :: name
   character(len=16) :: arg
   logical :: quick
   real(wp) :: ratio

   call get_command_argument(1, arg)
   quick = arg == 'quick'
   ratio = default_min_ratio
   call get_command_argument(2, arg)
   if (len_trim(arg) > 0) read (arg, *) ratio
   lmax = merge(4, 6, quick)
   qmax = merge(6, 8, quick)

   write (*, '(a)') '# relative errors: measure, boundary measure, int x1, int x1^2; max of the four; observed order'
   do icase = 1, ncase
      call make_case(icase, body, name, exact)
      write (*, '(/,"## ",a," (dim ",i0,")")') trim(name), body%dim
      write (*, '(a4,a6,4a11,a11,a7,a8,a8)') 'q', 'level', 'measure', 'boundary', 'moment1', 'moment2', &
         & 'max', 'order', 'cut', 'split%'
      do q = 1, qmax
         prev_err = -1.0_wp
         do level = 2, lmax
            if (body%dim == 3 .and. level == 6 .and. q > 6 .and. quick) cycle
            call integrate(body, level, q, got, ncut, nsplitcells, nfallback)
            err = abs(got - exact)/abs(exact)
            worst = maxval(err)
            if (prev_err > 0.0_wp .and. worst > 0.0_wp) then
               write (*, '(i4,i6,4es11.2,es11.2,f7.1,i8,f8.2)') q, level, err, worst, log(prev_err/worst)/log(2.0_wp), &
                  & ncut, 100.0_wp*real(nsplitcells, wp)/max(ncut, 1)
            else
               write (*, '(i4,i6,4es11.2,es11.2,a7,i8,f8.2)') q, level, err, worst, '-', ncut, &
                  & 100.0_wp*real(nsplitcells, wp)/max(ncut, 1)
            end if
            if (nfallback > 0) write (*, '(a,i0,a)') '      (', nfallback, ' boxes integrated unresolved at max depth)'
            prev_err = worst
         end do
      end do
   end do

   write (*, '(/,a)') '# speed of cut_cell_rule (all cut cells of the level, repeated)'
   write (*, '(a30,a4,a6,a10,a14,a14)') 'case', 'q', 'level', 'cut', 'cut cells/s', 'points/cell'
   do icase = 1, ncase
      if (icase /= 1 .and. icase /= 5 .and. icase /= 9) cycle
      call make_case(icase, body, name, exact)
      level = merge(7, 5, body%dim == 2)
      do q = 2, 6, 2
         call speed(body, level, q, ncells, points, t0, t1)
         write (*, '(a30,i4,i6,i10,es14.3,f14.1)') trim(name), q, level, ncells, ncells/max(t1 - t0, 1.0e-9_wp), points
      end do
   end do

contains

   !> Sum of the measures over the uniform grid of the given level.
   subroutine integrate(body, level, q, got, ncut, nsplitcells, nfallback)
      type(body_type), intent(in) :: body
      integer, intent(in) :: level, q
      real(wp), intent(out) :: got(4)
      integer, intent(out) :: ncut, nsplitcells, nfallback
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      type(error_type), allocatable :: error
      real(wp) :: lo(3), hi(3), h, cellsum(4), comp(4), t
      integer :: n, dim, cell, idx, d, i

      dim = body%dim
      comp = 0.0_wp
      call new_cut_quadrature(quad, dim, q, error, min_ratio=ratio)
      if (allocated(error)) error stop 'new_cut_quadrature'
      n = 2**level
      h = 1.0_wp/n
      got = 0.0_wp
      ncut = 0
      nsplitcells = 0
      nfallback = 0
      do cell = 0, n**dim - 1
         idx = cell
         do d = 1, dim
            lo(d) = h*mod(idx, n)
            hi(d) = lo(d) + h
            idx = idx/n
         end do
         call cell_rule(quad, body, lo(1:dim), hi(1:dim), rule, error)
         if (allocated(error)) error stop 'cell_rule'
         if (rule%cls == cell_cut) then
            ncut = ncut + 1
            if (rule%nsplit > 0) nsplitcells = nsplitcells + 1
            nfallback = nfallback + rule%nunresolved
         end if
         cellsum = 0.0_wp
         do i = 1, rule%nvol
            cellsum(1) = cellsum(1) + rule%vol_w(i)
            cellsum(3) = cellsum(3) + rule%vol_w(i)*rule%vol_x(1, i)
            cellsum(4) = cellsum(4) + rule%vol_w(i)*rule%vol_x(1, i)**2
         end do
         cellsum(2) = sum(rule%surf_w(1:rule%nsurf))
         ! compensated (Neumaier) sum over up to 2^18 cells: the naive sum's
         ! round-off (~1e-11 at level 6) would mask the quadrature error
         do i = 1, 4
            t = got(i) + cellsum(i)
            if (abs(got(i)) >= abs(cellsum(i))) then
               comp(i) = comp(i) + ((got(i) - t) + cellsum(i))
            else
               comp(i) = comp(i) + ((cellsum(i) - t) + got(i))
            end if
            got(i) = t
         end do
      end do
      got = got + comp
   end subroutine integrate

   !> Time cut_cell_rule over the cut cells of a level (repeated to >= 0.5 s).
   subroutine speed(body, level, q, ncells, points, t0, t1)
      type(body_type), intent(in) :: body
      integer, intent(in) :: level, q
      integer, intent(out) :: ncells
      real(wp), intent(out) :: points, t0, t1
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      type(error_type), allocatable :: error
      real(wp), allocatable :: cuts(:, :)
      real(wp) :: lo(3), hi(3), h
      integer :: n, dim, cell, idx, d, ncut, rep, i
      integer(8) :: c0, c1, rate

      dim = body%dim
      call new_cut_quadrature(quad, dim, q, error, min_ratio=ratio)
      n = 2**level
      h = 1.0_wp/n
      allocate (cuts(3, n**dim))
      ncut = 0
      do cell = 0, n**dim - 1
         idx = cell
         do d = 1, dim
            lo(d) = h*mod(idx, n)
            idx = idx/n
         end do
         hi = lo + h
         if (body%classify_box(lo(1:dim), hi(1:dim)) /= cell_cut) cycle
         ncut = ncut + 1
         cuts(:, ncut) = lo
      end do
      ncells = 0
      points = 0.0_wp
      call system_clock(c0, rate)
      do rep = 1, 1000
         do i = 1, ncut
            lo = cuts(:, i)
            hi = lo + h
            call cut_cell_rule(quad, body, lo(1:dim), hi(1:dim), rule, error)
            points = points + rule%nvol + rule%nsurf
         end do
         ncells = ncells + ncut
         call system_clock(c1)
         if (real(c1 - c0, wp)/rate > 0.5_wp) exit
      end do
      t0 = 0.0_wp
      t1 = real(c1 - c0, wp)/rate
      points = points/max(ncells, 1)
   end subroutine speed

   !> Body number icase with exact [measure, boundary measure, int x1, int x1^2].
   subroutine make_case(icase, body, name, exact)
      integer, intent(in) :: icase
      type(body_type), intent(out) :: body
      character(len=*), intent(out) :: name
      real(wp), intent(out) :: exact(4)
      type(shape_type) :: s
      real(wp) :: c(3), r1, r2, a, b, v, v2, h, zlo, zhi
      real(wp) :: o(3), rr, vh

      call new_body(body, 'case')
      select case (icase)
      case (1)
         name = 'disk'
         c = [0.51_wp, 0.47_wp, 0.0_wp]
         r1 = 0.31_wp
         call new_disk(s, 'disk', c(1:2), r1, error); call add(body, s, csg_add)
         a = pi*r1**2
         exact = [a, 2.0_wp*pi*r1, a*c(1), a*c(1)**2 + pi*r1**4/4.0_wp]
      case (2)
         name = 'annulus'
         c = [0.51_wp, 0.47_wp, 0.0_wp]
         r1 = 0.4_wp
         r2 = 0.15_wp
         call new_disk(s, 'outer', c(1:2), r1, error); call add(body, s, csg_add)
         call new_disk(s, 'inner', c(1:2), r2, error); call add(body, s, csg_subtract)
         a = pi*(r1**2 - r2**2)
         exact = [a, 2.0_wp*pi*(r1 + r2), a*c(1), a*c(1)**2 + pi*(r1**4 - r2**4)/4.0_wp]
      case (3)
         name = 'ellipse with off-centre hole'
         c = [0.5_wp, 0.5_wp, 0.0_wp]
         a = 0.42_wp
         b = 0.27_wp
         o = [0.58_wp, 0.46_wp, 0.0_wp]
         rr = 0.1_wp
         call new_ellipse(s, 'ellipse', c(1:2), [a, b], error); call add(body, s, csg_add)
         call new_disk(s, 'hole', o(1:2), rr, error); call add(body, s, csg_subtract)
         v = pi*a*b
         v2 = pi*rr**2
         exact = [v - v2, ellipse_perimeter(a, b) + 2.0_wp*pi*rr, v*c(1) - v2*o(1), &
            & v*(c(1)**2 + a*a/4.0_wp) - (v2*o(1)**2 + pi*rr**4/4.0_wp)]
      case (4)
         name = 'quarter annulus, planes on grid'
         c = [0.25_wp, 0.25_wp, 0.0_wp]
         r1 = 0.7_wp
         r2 = 0.3_wp
         call new_disk(s, 'outer', c(1:2), r1, error); call add(body, s, csg_add)
         call new_disk(s, 'inner', c(1:2), r2, error); call add(body, s, csg_subtract)
         call new_halfspace(s, 'sym_x', c(1:2), [-1.0_wp, 0.0_wp], error); call add(body, s, csg_intersect)
         call new_halfspace(s, 'sym_y', c(1:2), [0.0_wp, -1.0_wp], error); call add(body, s, csg_intersect)
         a = pi*(r1**2 - r2**2)/4.0_wp
         v = (r1**3 - r2**3)/3.0_wp
         v2 = pi*(r1**4 - r2**4)/16.0_wp
         exact = [a, pi*(r1 + r2)/2.0_wp + 2.0_wp*(r1 - r2), v + c(1)*a, v2 + 2.0_wp*c(1)*v + c(1)**2*a]
      case (5)
         name = 'sphere'
         c = [0.51_wp, 0.47_wp, 0.49_wp]
         r1 = 0.33_wp
         call new_sphere(s, 'sphere', c, r1, error); call add(body, s, csg_add)
         v = 4.0_wp*pi*r1**3/3.0_wp
         exact = [v, 4.0_wp*pi*r1**2, v*c(1), v*c(1)**2 + 4.0_wp*pi*r1**5/15.0_wp]
      case (6)
         name = 'spherical shell octant, planes on grid'
         c = [0.25_wp, 0.25_wp, 0.25_wp]
         r1 = 0.7_wp
         r2 = 0.3_wp
         call new_sphere(s, 'outer', c, r1, error); call add(body, s, csg_add)
         call new_sphere(s, 'inner', c, r2, error); call add(body, s, csg_subtract)
         call new_halfspace(s, 'sym_x', c, [-1.0_wp, 0.0_wp, 0.0_wp], error); call add(body, s, csg_intersect)
         call new_halfspace(s, 'sym_y', c, [0.0_wp, -1.0_wp, 0.0_wp], error); call add(body, s, csg_intersect)
         call new_halfspace(s, 'sym_z', c, [0.0_wp, 0.0_wp, -1.0_wp], error); call add(body, s, csg_intersect)
         v = pi*(r1**3 - r2**3)/6.0_wp
         a = pi*(r1**4 - r2**4)/16.0_wp
         v2 = pi*(r1**5 - r2**5)/30.0_wp
         exact = [v, pi*(r1**2 + r2**2)/2.0_wp + 0.75_wp*pi*(r1**2 - r2**2), a + c(1)*v, &
            & v2 + 2.0_wp*c(1)*a + c(1)**2*v]
      case (7)
         name = 'cube with spherical void'
         c = [0.52_wp, 0.48_wp, 0.5_wp]
         r1 = 0.3_wp
         call new_box(s, 'cube', [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], error); call add(body, s, csg_add)
         call new_sphere(s, 'void', c, r1, error); call add(body, s, csg_subtract)
         v = 4.0_wp*pi*r1**3/3.0_wp
         exact = [1.0_wp - v, 6.0_wp + 4.0_wp*pi*r1**2, 0.5_wp - v*c(1), &
            & 1.0_wp/3.0_wp - (v*c(1)**2 + 4.0_wp*pi*r1**5/15.0_wp)]
      case (8, 9)
         c = [0.5_wp, 0.47_wp, 0.0_wp]
         r1 = 0.3_wp
         if (icase == 8) then
            name = 'capped cylinder, caps on grid'
            zlo = 0.25_wp
            zhi = 0.75_wp
         else
            name = 'capped cylinder, caps off grid'
            zlo = 0.2131_wp
            zhi = 0.7731_wp
         end if
         call new_cylinder(s, 'mantle', c, [0.0_wp, 0.0_wp, 1.0_wp], r1, error); call add(body, s, csg_add)
         call new_halfspace(s, 'bottom', [0.0_wp, 0.0_wp, zlo], [0.0_wp, 0.0_wp, -1.0_wp], error)
         call add(body, s, csg_intersect)
         call new_halfspace(s, 'top', [0.0_wp, 0.0_wp, zhi], [0.0_wp, 0.0_wp, 1.0_wp], error)
         call add(body, s, csg_intersect)
         h = zhi - zlo
         vh = pi*r1**2*h
         exact = [vh, 2.0_wp*pi*r1*h + 2.0_wp*pi*r1**2, vh*c(1), h*(pi*r1**2*c(1)**2 + pi*r1**4/4.0_wp)]
      end select
   end subroutine make_case

   !> Append shape s to the body (stops on a construction error: this is a driver).
   subroutine add(body, s, op)
      type(body_type), intent(inout) :: body
      type(shape_type), intent(in) :: s
      integer, intent(in) :: op
      if (allocated(error)) error stop 'shape'
      call body%add_shape(op, s, error)
      if (allocated(error)) error stop 'add_shape'
   end subroutine add

   !> Perimeter of an ellipse by the arithmetic-geometric mean (quadratic convergence).
   pure real(wp) function ellipse_perimeter(a, b) result(p)
      real(wp), intent(in) :: a, b
      real(wp) :: x, y, s, t, pw
      integer :: it
      x = a
      y = b
      s = 0.5_wp*(a*a + b*b)
      pw = 1.0_wp
      do it = 1, 20
         t = 0.5_wp*(x - y)
         s = s - pw*t*t
         pw = 2.0_wp*pw
         t = sqrt(x*y)
         x = 0.5_wp*(x + y)
         y = t
         if (abs(x - y) <= 1.0e-17_wp*x) exit
      end do
      p = 2.0_wp*pi*s/x
   end function ellipse_perimeter

end program quadrature_table
