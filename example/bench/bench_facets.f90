!> Benchmark of faceted solids: classification and cut-cell quadrature of a
!> UV sphere of ~1e4, 1e5 and 1e6 triangles (radius 0.8, centre off the grid
!> planes) on the 3D grid of level 8 over [-1, 1]^3 (~2e5 cut cells).
!> Boxes are classified top-down (only cut boxes are split, as the grid
!> builder does); each cut cell of the finest level then gets its volume and
!> surface rule (Q1 points, q = 3). Prints the facet count, hierarchy build,
!> classification and quadrature wall times, cut cells, quadrature points,
!> the volume and area errors against the polyhedron's, and peak memory
!> (VmHWM, cumulative over the runs: the largest run is last).
!>
!> Run: fpm run --profile release --example bench_facets [-- level]
program bench_facets
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_timer, only: wall_time
   use sprc_core_memory, only: peak_memory
   use sprc_geometry_region, only: cell_cut, cell_inside
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_shape, only: shape_type, new_facet_shape
   use sprc_geometry_body, only: body_type, new_body, csg_add
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule, &
      & default_points
   implicit none

   real(wp), parameter :: pi = acos(-1.0_wp)
   character(len=8) :: arg
   integer :: level

   level = 8
   if (command_argument_count() > 0) then
      call get_command_argument(1, arg)
      read (arg, *) level
   end if
   write (*, '(a)') '  facets  build_s  classify_s  quadrature_s  cut_cells  points  vol_rel_err  area_rel_err  peak_MB'
   call run(70, 72, level)
   call run(224, 224, level)
   call run(708, 708, level)

contains

   subroutine run(nlon, nlat, level)
      integer, intent(in) :: nlon, nlat, level
      type(facet_set_type) :: set
      type(shape_type) :: shape
      type(body_type) :: body
      type(error_type), allocatable :: error
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      real(wp), allocatable :: cells(:, :)
      real(wp) :: t0, t1, t2, t3, vol, area, v_ref, a_ref
      integer :: ncut, i
      integer(i8) :: npoints

      call uv_sphere(set, [0.013_wp, -0.021_wp, 0.007_wp], 0.8_wp, nlon, nlat)
      call measures(set, v_ref, a_ref)
      t0 = wall_time()
      call new_facet_shape(shape, 'sphere', set, error)
      if (allocated(error)) error stop 'new_facet_shape'
      call new_body(body, 'ball')
      call body%add_shape(csg_add, shape, error)
      if (allocated(error)) error stop 'add_shape'
      t1 = wall_time()
      allocate (cells(6, 1024))
      ncut = 0
      vol = 0.0_wp
      call descend(body, [-1.0_wp, -1.0_wp, -1.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], level, cells, ncut, vol)
      t2 = wall_time()
      call new_cut_quadrature(quad, 3, default_points(1), error)
      npoints = 0
      area = 0.0_wp
      do i = 1, ncut
         call cell_rule(quad, body, cells(1:3, i), cells(4:6, i), rule, error)
         if (allocated(error)) error stop 'cell_rule'
         vol = vol + sum(rule%vol_w(1:rule%nvol))
         area = area + sum(rule%surf_w(1:rule%nsurf))
         npoints = npoints + rule%nvol + rule%nsurf
      end do
      t3 = wall_time()
      write (*, '(i8, 3f11.3, i11, i12, 2es13.2, i9)') set%nfacet, t1 - t0, t2 - t1, t3 - t2, ncut, npoints, &
         & abs(vol - v_ref)/v_ref, abs(area - a_ref)/a_ref, peak_memory()/2**20
   end subroutine run

   !> Classify [lo, hi]; inside boxes add their volume, cut boxes are split down
   !> to `level` levels below and listed there.
   recursive subroutine descend(body, lo, hi, level, cells, ncut, vol)
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(3), hi(3)
      integer, intent(in) :: level
      real(wp), allocatable, intent(inout) :: cells(:, :)
      integer, intent(inout) :: ncut
      real(wp), intent(inout) :: vol
      real(wp), allocatable :: grown(:, :)
      real(wp) :: mid(3), clo(3), chi(3)
      integer :: child, k

      select case (body%classify_box(lo, hi))
      case (cell_inside)
         vol = vol + product(hi - lo)
         return
      case (cell_cut)
      case default
         return
      end select
      if (level == 0) then
         if (ncut == size(cells, 2)) then
            allocate (grown(6, 2*ncut))
            grown(:, 1:ncut) = cells
            call move_alloc(grown, cells)
         end if
         ncut = ncut + 1
         cells(1:3, ncut) = lo
         cells(4:6, ncut) = hi
         return
      end if
      mid = 0.5_wp*(lo + hi)
      do child = 0, 7
         do k = 1, 3
            clo(k) = merge(mid(k), lo(k), btest(child, k - 1))
            chi(k) = merge(hi(k), mid(k), btest(child, k - 1))
         end do
         call descend(body, clo, chi, level - 1, cells, ncut, vol)
      end do
   end subroutine descend

   !> UV sphere, outward oriented (see the facet set's conventions).
   subroutine uv_sphere(set, c, r, nlon, nlat)
      type(facet_set_type), intent(out) :: set
      real(wp), intent(in) :: c(3), r
      integer, intent(in) :: nlon, nlat
      real(wp) :: th, ph
      integer :: i, j, f, np, jn

      np = (nlat - 1)*nlon
      set%dim = 3
      set%nvert = np + 2
      set%nfacet = 2*nlon*(nlat - 1)
      allocate (set%vert(3, set%nvert), set%facet(3, set%nfacet), set%group(set%nfacet), set%group_name(0), &
         & set%file_index(set%nfacet))
      set%group = 0
      set%file_index = 0
      set%source = 'bench'
      do i = 1, nlat - 1
         th = pi*i/nlat
         do j = 1, nlon
            ph = 2*pi*(j - 1)/nlon
            set%vert(:, (i - 1)*nlon + j) = c + r*[sin(th)*cos(ph), sin(th)*sin(ph), cos(th)]
         end do
      end do
      set%vert(:, np + 1) = c + [0.0_wp, 0.0_wp, r]
      set%vert(:, np + 2) = c - [0.0_wp, 0.0_wp, r]
      f = 0
      do j = 1, nlon
         jn = mod(j, nlon) + 1
         set%facet(:, f + 1) = [np + 1, j, jn]
         set%facet(:, f + 2) = [(nlat - 2)*nlon + j, np + 2, (nlat - 2)*nlon + jn]
         f = f + 2
         do i = 1, nlat - 2
            set%facet(:, f + 1) = [(i - 1)*nlon + j, i*nlon + j, i*nlon + jn]
            set%facet(:, f + 2) = [(i - 1)*nlon + j, i*nlon + jn, (i - 1)*nlon + jn]
            f = f + 2
         end do
      end do
   end subroutine uv_sphere

   !> Volume (divergence theorem) and area of the facet set.
   subroutine measures(set, vol, area)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(out) :: vol, area
      real(wp) :: a(3), b(3), c(3), n(3)
      integer :: f
      vol = 0.0_wp
      area = 0.0_wp
      do f = 1, set%nfacet
         a = set%vert(:, set%facet(1, f))
         b = set%vert(:, set%facet(2, f))
         c = set%vert(:, set%facet(3, f))
         n = [(b(2) - a(2))*(c(3) - a(3)) - (b(3) - a(3))*(c(2) - a(2)), &
            & (b(3) - a(3))*(c(1) - a(1)) - (b(1) - a(1))*(c(3) - a(3)), &
            & (b(1) - a(1))*(c(2) - a(2)) - (b(2) - a(2))*(c(1) - a(1))]
         vol = vol + dot_product(a, n)/6.0_wp
         area = area + 0.5_wp*norm2(n)
      end do
   end subroutine measures

end program bench_facets
