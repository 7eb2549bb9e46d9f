!> Readers of faceted geometry (STL ASCII and binary, OBJ, polygons) and the
!> validation and measures of `sprc_geometry_facet_check`, on solids this
!> test writes itself: the measures are checked against the polyhedra's
!> closed forms (not against the divergence theorem the library uses).
!> Tolerance of a measure: 4 n eps relative for a sum of n facet terms, the
!> worst-case bound of recursive summation with eps-accurate terms.
module sprc_test_facet_files
   use, intrinsic :: iso_fortran_env, only: int32, real32
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_text, only: itoa
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_facet_check, only: check_facets, facet_measures, group_measure
   use sprc_io_stl, only: read_stl
   use sprc_io_obj, only: read_obj
   use sprc_io_polygon, only: read_polygon_file, polygon_from_points
   use sprc_io_facet_file, only: place_facets
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed
   implicit none
   private

   public :: collect_facet_files

   character(len=*), parameter :: dir = 'build/test_facets_'
   real(wp), parameter :: pi = acos(-1.0_wp)

contains

   subroutine collect_facet_files(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('binary_header_solid', test_binary_solid_header), &
         new_unittest('ascii_rotated_box_merged', test_ascii_box), &
         new_unittest('torus_measures', test_torus), &
         new_unittest('sphere_8000_facets', test_sphere), &
         new_unittest('cavity_measures', test_cavity), &
         new_unittest('inward_surface_flipped', test_inward), &
         new_unittest('scale_translate', test_place), &
         new_unittest('obj_quads_groups_negative', test_obj), &
         new_unittest('polygon_file_edges', test_polygon_file), &
         new_unittest('polygon_clockwise_flipped', test_polygon_points), &
         new_unittest('polygon_crossing_many', test_polygon_crossing), &
         new_unittest('edge_errors_lowest_facet', test_edge_errors) &
         ]
   end subroutine collect_facet_files

   ! ---------------------------------------------------------- generators

   !> The 12 triangles of the parallelepiped o + [0,1]^3 . (e1, e2, e3),
   !> outward when det(e1, e2, e3) > 0; reversed with `inward`.
   function box_triangles(o, e1, e2, e3, inward) result(t)
      real(wp), intent(in) :: o(3), e1(3), e2(3), e3(3)
      logical, intent(in) :: inward
      real(wp) :: t(3, 3, 12), c(3, 0:7)
      integer, parameter :: quads(4, 6) = reshape([0, 4, 6, 2, 1, 3, 7, 5, 0, 1, 5, 4, 2, 6, 7, 3, 0, 2, 3, 1, &
         & 4, 5, 7, 6], [4, 6])
      integer :: i, q
      do i = 0, 7
         c(:, i) = o + merge(1, 0, btest(i, 0))*e1 + merge(1, 0, btest(i, 1))*e2 + merge(1, 0, btest(i, 2))*e3
      end do
      do q = 1, 6
         t(:, :, 2*q - 1) = c(:, quads([1, 2, 3], q))
         t(:, :, 2*q) = c(:, quads([1, 3, 4], q))
      end do
      if (inward) t(:, [2, 3], :) = t(:, [3, 2], :)
   end function box_triangles

   !> n x m trapezoids of the torus of radii big, small about the z axis.
   function torus_triangles(big, small, n, m) result(t)
      real(wp), intent(in) :: big, small
      integer, intent(in) :: n, m
      real(wp), allocatable :: t(:, :, :)
      integer :: i, j, k
      allocate (t(3, 3, 2*n*m))
      k = 0
      do i = 0, n - 1
         do j = 0, m - 1
            t(:, 1, k + 1) = torus_point(i, j)
            t(:, 2, k + 1) = torus_point(i + 1, j)
            t(:, 3, k + 1) = torus_point(i + 1, j + 1)
            t(:, 1, k + 2) = torus_point(i, j)
            t(:, 2, k + 2) = torus_point(i + 1, j + 1)
            t(:, 3, k + 2) = torus_point(i, j + 1)
            k = k + 2
         end do
      end do
   contains
      function torus_point(i, j) result(p)
         integer, intent(in) :: i, j
         real(wp) :: p(3), a, b
         a = 2*pi*mod(i, n)/n
         b = 2*pi*mod(j, m)/m
         p = [(big + small*cos(b))*cos(a), (big + small*cos(b))*sin(a), small*sin(b)]
      end function torus_point
   end function torus_triangles

   !> Sphere of radius r, n segments per great circle (n longitudes, n/2 bands).
   function sphere_triangles(r, n) result(t)
      real(wp), intent(in) :: r
      integer, intent(in) :: n
      real(wp), allocatable :: t(:, :, :)
      integer :: i, j, k, m
      m = n/2
      allocate (t(3, 3, 2*n*(m - 1)))
      k = 0
      do j = 0, m - 1
         do i = 0, n - 1
            if (j > 0) then
               k = k + 1
               t(:, :, k) = reshape([p(i, j), p(i, j + 1), p(i + 1, j)], [3, 3])
            end if
            if (j < m - 1) then
               k = k + 1
               t(:, :, k) = reshape([p(i + 1, j), p(i, j + 1), p(i + 1, j + 1)], [3, 3])
            end if
         end do
      end do
   contains
      function p(i, j) result(x)
         integer, intent(in) :: i, j
         real(wp) :: x(3), a, b
         a = 2*pi*mod(i, n)/n
         b = pi*j/m
         x = r*[sin(b)*cos(a), sin(b)*sin(a), cos(b)]
         if (j == 0) x = [0.0_wp, 0.0_wp, r]
         if (j == m) x = [0.0_wp, 0.0_wp, -r]
      end function p
   end function sphere_triangles

   !> ASCII STL, one solid per name (`first(k)`: first triangle of solid k).
   subroutine write_ascii_stl(path, t, names, first)
      character(len=*), intent(in) :: path
      real(wp), intent(in) :: t(:, :, :)
      character(len=*), intent(in) :: names(:)
      integer, intent(in) :: first(:)
      integer :: unit, k, s, j
      open (newunit=unit, file=path, status='replace', action='write')
      do s = 1, size(names)
         write (unit, '(a)') 'solid '//trim(names(s))
         do k = first(s), merge(size(t, 3), first(min(s + 1, size(first))) - 1, s == size(names))
            write (unit, '(a)') ' facet normal 0 0 0', '  outer loop'
            do j = 1, 3
               write (unit, '("   vertex",3es25.17)') t(:, j, k)
            end do
            write (unit, '(a)') '  endloop', ' endfacet'
         end do
         write (unit, '(a)') 'endsolid '//trim(names(s))
      end do
      close (unit)
   end subroutine write_ascii_stl

   !> Binary STL (little-endian host assumed, as every test machine is).
   subroutine write_binary_stl(path, t, header)
      character(len=*), intent(in) :: path, header
      real(wp), intent(in) :: t(:, :, :)
      character(len=80) :: head
      integer :: unit, k
      head = header
      open (newunit=unit, file=path, status='replace', access='stream', form='unformatted', action='write')
      write (unit) head, int(size(t, 3), int32)
      do k = 1, size(t, 3)
         write (unit) real([0.0_wp, 0.0_wp, 0.0_wp], real32), real(t(:, :, k), real32), 'ab'
      end do
      close (unit)
   end subroutine write_binary_stl

   subroutine write_text(path, text)
      character(len=*), intent(in) :: path, text
      integer :: unit
      open (newunit=unit, file=path, status='replace', access='stream', form='unformatted', action='write')
      write (unit) text
      close (unit)
   end subroutine write_text

   !> Read (stl/obj by the suffix), validate, measure.
   subroutine load(path, set, note, volume, area, error)
      character(len=*), intent(in) :: path
      type(facet_set_type), intent(out) :: set
      character(len=:), allocatable, intent(out) :: note
      real(wp), intent(out) :: volume, area
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: why
      if (index(path, '.obj') > 0) then
         call read_obj(path, set, error)
      else
         call read_stl(path, set, error)
      end if
      if (.not. allocated(error)) call check_facets(set, note, error)
      if (allocated(error)) then
         why = error%message
         call test_failed(error, 'unexpected error: '//why)
         return
      end if
      call facet_measures(set, volume, area)
   end subroutine load

   pure real(wp) function tol(n)
      integer, intent(in) :: n
      tol = 4*n*epsilon(1.0_wp)
   end function tol

   ! --------------------------------------------------------------- tests

   !> A binary file whose header starts with "solid" is binary (by its size).
   !> A box 3 x 1.5 x 0.75 rotated off the axes with float32-exact vertices.
   subroutine test_binary_solid_header(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a
      call write_binary_stl(dir//'solidhdr.stl', box_triangles([0.5_wp, -1.0_wp, 2.0_wp], [1.0_wp, 2.0_wp, 2.0_wp], &
         & 0.25_wp*[2.0_wp, -2.0_wp, 1.0_wp], 0.5_wp*[2.0_wp, 1.0_wp, -2.0_wp], .false.), 'solid part exported by CAD')
      call load(dir//'solidhdr.stl', set, note, v, a, error)
      if (allocated(error)) return
      call check(error, set%nfacet, 12, 'facets')
      if (.not. allocated(error)) call check(error, set%nvert, 8, 'merged vertices')
      if (.not. allocated(error)) call check(error, v, 3.375_wp, tol(12), 'volume 3 * 1.5 * 0.75', rel=.true.)
      if (.not. allocated(error)) call check(error, a, 15.75_wp, tol(12), 'area 2(4.5 + 1.125 + 2.25)', rel=.true.)
      if (.not. allocated(error)) call check(error, len(note), 0, 'no note on an outward surface')
   end subroutine test_binary_solid_header

   !> ASCII, a box rotated by a general rotation, one solid per face pair.
   subroutine test_ascii_box(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: q(3, 3), v, a, c, s
      c = cos(0.7_wp)
      s = sin(0.7_wp)
      q(:, 1) = [c, s, 0.0_wp]
      q(:, 2) = [-s*cos(0.4_wp), c*cos(0.4_wp), sin(0.4_wp)]
      q(:, 3) = [s*sin(0.4_wp), -c*sin(0.4_wp), cos(0.4_wp)]
      call write_ascii_stl(dir//'box.stl', box_triangles([1.0_wp, 2.0_wp, 3.0_wp], 3*q(:, 1), 2*q(:, 2), q(:, 3), &
         & .false.), [character(len=8) :: 'xfaces', 'yfaces', 'zfaces'], [1, 5, 9])
      call load(dir//'box.stl', set, note, v, a, error)
      if (allocated(error)) return
      call check(error, set%nvert, 8, 'vertices merged exactly across solids')
      if (.not. allocated(error)) call check(error, size(set%group_name), 3, 'three solids')
      if (.not. allocated(error)) call check(error, v, 6.0_wp, 16*tol(12), 'volume 3 * 2 * 1', rel=.true.)
      if (.not. allocated(error)) call check(error, a, 22.0_wp, 16*tol(12), 'area', rel=.true.)
      if (.not. allocated(error)) call check(error, group_measure(set, 3), 12.0_wp, 16*tol(4), 'solid zfaces: 2 x (3 x 2)', &
         & rel=.true.)
   end subroutine test_ascii_box

   !> Torus R = 3, r = 1, 48 x 24 trapezoids. The solid between two meridian
   !> planes is swept by chords, volume sin(da) times the first moment of the
   !> meridian polygon: V = N sin(2 pi/N) R (M/2) r^2 sin(2 pi/M). Area: each
   !> trapezoid by its parallel sides and height.
   subroutine test_torus(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 48, m = 24
      real(wp), parameter :: big = 3.0_wp, small = 1.0_wp
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a, exact_v, exact_a, rho(0:m), z(0:m), half
      integer :: j

      call write_binary_stl(dir//'torus.stl', torus_triangles(big, small, n, m), 'torus')
      ! Binary: the vertices are float32; compare with the closed form of the
      ! double torus to float32 accuracy, then the ASCII torus at double.
      call write_ascii_stl(dir//'torus_ascii.stl', torus_triangles(big, small, n, m), ['torus'], [1])
      call load(dir//'torus_ascii.stl', set, note, v, a, error)
      if (allocated(error)) return
      exact_v = n*sin(2*pi/n)*big*(m/2.0_wp)*small**2*sin(2*pi/m)
      half = pi/n
      do j = 0, m
         rho(j) = big + small*cos(2*pi*j/m)
         z(j) = small*sin(2*pi*j/m)
      end do
      exact_a = 0.0_wp
      do j = 0, m - 1
         exact_a = exact_a + n*(rho(j) + rho(j + 1))*sin(half)*hypot((rho(j + 1) - rho(j))*cos(half), z(j + 1) - z(j))
      end do
      call check(error, set%nfacet, 2*n*m, 'facets')
      if (.not. allocated(error)) call check(error, set%nvert, n*m, 'vertices merged')
      if (.not. allocated(error)) call check(error, v, exact_v, 16*tol(set%nfacet), 'torus volume', rel=.true.)
      if (.not. allocated(error)) call check(error, a, exact_a, 16*tol(set%nfacet), 'torus area', rel=.true.)
      if (allocated(error)) return
      call load(dir//'torus.stl', set, note, v, a, error)
      if (allocated(error)) return
      call check(error, v, exact_v, 1.0e-6_wp, 'binary torus volume (float32 vertices)', rel=.true.)
   end subroutine test_torus

   !> Sphere r = 1, n = 128 (16128 facets): bands are frustums of regular
   !> n-gon pyramids, V = sum h/3 (A1 + A2 + sqrt(A1 A2)), A = n gon area
   !> r^2 n/2 sin(2 pi/n); lateral area n (s1 + s2)/2 times the slant height.
   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 128, m = n/2
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a, exact_v, exact_a, r1, r2, z1, z2, a1, a2
      integer :: j

      call write_ascii_stl(dir//'sphere.stl', sphere_triangles(1.0_wp, n), ['sphere'], [1])
      call load(dir//'sphere.stl', set, note, v, a, error)
      if (allocated(error)) return
      exact_v = 0.0_wp
      exact_a = 0.0_wp
      do j = 0, m - 1
         r1 = sin(pi*j/m)
         r2 = sin(pi*(j + 1)/m)
         z1 = cos(pi*j/m)
         z2 = cos(pi*(j + 1)/m)
         a1 = n/2.0_wp*r1**2*sin(2*pi/n)
         a2 = n/2.0_wp*r2**2*sin(2*pi/n)
         exact_v = exact_v + (z1 - z2)/3*(a1 + a2 + sqrt(a1*a2))
         exact_a = exact_a + n*(r1 + r2)*sin(pi/n)*hypot(z1 - z2, (r2 - r1)*cos(pi/n))
      end do
      call check(error, set%nfacet >= 8000, 'at least 8000 facets: '//itoa(set%nfacet))
      if (.not. allocated(error)) call check(error, v, exact_v, 16*tol(set%nfacet), 'sphere volume', rel=.true.)
      if (.not. allocated(error)) call check(error, a, exact_a, 16*tol(set%nfacet), 'sphere area', rel=.true.)
   end subroutine test_sphere

   !> A cube of side 4 with a cube of side 2 hollowed out (its facets facing
   !> into the cavity): V = 64 - 8, A = 96 + 24; not flipped.
   subroutine test_cavity(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: t(3, 3, 24), v, a
      t(:, :, 1:12) = box_triangles([0.0_wp, 0.0_wp, 0.0_wp], [4.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 4.0_wp, 0.0_wp], &
         & [0.0_wp, 0.0_wp, 4.0_wp], .false.)
      t(:, :, 13:24) = box_triangles([1.0_wp, 1.0_wp, 1.0_wp], [2.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 2.0_wp, 0.0_wp], &
         & [0.0_wp, 0.0_wp, 2.0_wp], .true.)
      call write_ascii_stl(dir//'cavity.stl', t, [character(len=6) :: 'outer', 'cavity'], [1, 13])
      call load(dir//'cavity.stl', set, note, v, a, error)
      if (allocated(error)) return
      call check(error, v, 56.0_wp, tol(24), 'volume 64 - 8', rel=.true.)
      if (.not. allocated(error)) call check(error, a, 120.0_wp, tol(24), 'area 96 + 24', rel=.true.)
      if (.not. allocated(error)) call check(error, group_measure(set, 2), 24.0_wp, tol(12), 'cavity solid', rel=.true.)
      if (.not. allocated(error)) call check(error, len(note), 0, 'a cavity is not a flipped surface')
   end subroutine test_cavity

   !> A closed surface given inwards is flipped, with a note.
   subroutine test_inward(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a
      call write_ascii_stl(dir//'inward.stl', box_triangles([0.0_wp, 0.0_wp, 0.0_wp], [2.0_wp, 0.0_wp, 0.0_wp], &
         & [0.0_wp, 3.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 5.0_wp], .true.), ['inward'], [1])
      call load(dir//'inward.stl', set, note, v, a, error)
      if (allocated(error)) return
      call check(error, v, 30.0_wp, tol(12), 'volume positive after the flip', rel=.true.)
      if (.not. allocated(error)) call check(error, index(note, 'oriented inwards') > 0 .and. &
         & index(note, 'flipped') > 0, 'note: '//note)
   end subroutine test_inward

   !> scale then translate: volume scale^3, box moved.
   subroutine test_place(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a
      call write_ascii_stl(dir//'unit.stl', box_triangles([0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp, 0.0_wp], &
         & [0.0_wp, 1.0_wp, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], .false.), ['unit'], [1])
      call read_stl(dir//'unit.stl', set, error)
      if (allocated(error)) return
      call place_facets(set, 2.5_wp, [10.0_wp, -1.0_wp, 0.5_wp])
      call check_facets(set, note, error)
      if (allocated(error)) return
      call facet_measures(set, v, a)
      call check(error, v, 2.5_wp**3, tol(12), 'volume', rel=.true.)
      if (.not. allocated(error)) call check(error, minval(set%vert(1, :)), 10.0_wp, 0.0_wp, 'x min moved')
      if (.not. allocated(error)) call check(error, maxval(set%vert(3, :)), 3.0_wp, 0.0_wp, 'z max 0.5 + 2.5')
   end subroutine test_place

   !> OBJ: quads fanned, groups, negative indices, texture/normal indices.
   subroutine test_obj(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: nl = new_line('a')
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a
      call write_text(dir//'bar.obj', '# a 4 x 1 x 1 bar'//nl// &
         & 'v 0 0 0'//nl//'v 4 0 0'//nl//'v 4 1 0'//nl//'v 0 1 0'//nl// &
         & 'v 0 0 1'//nl//'v 4 0 1'//nl//'v 4 1 1'//nl//'v 0 1 1'//nl//'vt 0 0'//nl//'vn 0 0 1'//nl// &
         & 'o end0'//nl//'f 1 5 8 4'//nl//'g end1'//nl//'f 2/1 3/1 7/1 6/1'//nl//'g side'//nl// &
         & 'f 1//1 4//1 3//1 2//1'//nl//'f -4 -3 -2 -1'//nl//'f 1 2 6 5'//nl//'f 4 8 7 3'//nl)
      call load(dir//'bar.obj', set, note, v, a, error)
      if (allocated(error)) return
      call check(error, set%nfacet, 12, 'six quads fanned')
      if (.not. allocated(error)) call check(error, set%file_index(4), 1, 'a fan keeps its face number')
      if (.not. allocated(error)) call check(error, v, 4.0_wp, tol(12), 'volume', rel=.true.)
      if (.not. allocated(error)) call check(error, a, 18.0_wp, tol(12), 'area', rel=.true.)
      if (.not. allocated(error)) call check(error, trim(set%group_name(2)), 'end1', 'group names')
      if (.not. allocated(error)) call check(error, group_measure(set, 3), 16.0_wp, tol(8), 'side area', rel=.true.)
   end subroutine test_obj

   !> A polygon file with edge names: area, perimeter, named edges.
   subroutine test_polygon_file(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: nl = new_line('a')
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a
      call write_text(dir//'lshape.txt', '# an L, counter-clockwise'//nl//'0 0 base'//nl//'2, 0'//nl// &
         & '2 1 step'//nl//'1 1 step'//nl//'1 2'//nl//'0 2  # no name: the whole surface only'//nl)
      call read_polygon_file(dir//'lshape.txt', set, error)
      if (.not. allocated(error)) call check_facets(set, note, error)
      if (allocated(error)) return
      call facet_measures(set, v, a)
      call check(error, v, 3.0_wp, tol(6), 'area of the L', rel=.true.)
      if (.not. allocated(error)) call check(error, a, 8.0_wp, tol(6), 'perimeter', rel=.true.)
      if (.not. allocated(error)) call check(error, size(set%group_name), 2, 'edge names base, step')
      if (.not. allocated(error)) call check(error, group_measure(set, 2), 2.0_wp, tol(2), 'step edges', rel=.true.)
      if (.not. allocated(error)) call check(error, len(note), 0, 'counter-clockwise: no flip')
   end subroutine test_polygon_file

   !> points = ... clockwise: flipped with a note, area positive.
   subroutine test_polygon_points(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      real(wp) :: v, a
      call polygon_from_points([0.0_wp, 0.0_wp, 0.0_wp, 3.0_wp, 4.0_wp, 0.0_wp], 'points', set, error)
      if (.not. allocated(error)) call check_facets(set, note, error)
      if (allocated(error)) return
      call facet_measures(set, v, a)
      call check(error, v, 6.0_wp, tol(3), 'area 3 * 4 / 2', rel=.true.)
      if (.not. allocated(error)) call check(error, a, 12.0_wp, tol(3), 'perimeter 3 + 4 + 5', rel=.true.)
      if (.not. allocated(error)) call check(error, index(note, 'flipped') > 0, 'note: '//note)
   end subroutine test_polygon_points

   !> A star polygon of 2000 vertices is simple; moving one vertex across
   !> the polygon makes it cross itself, found through the bins.
   subroutine test_polygon_crossing(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 2000
      type(facet_set_type) :: set
      character(len=:), allocatable :: note
      character(len=:), allocatable :: why
      real(wp) :: xy(2*n), r, t
      integer :: i
      do i = 1, n
         t = 2*pi*(i - 1)/n
         r = 1.0_wp + 0.3_wp*merge(1.0_wp, -1.0_wp, mod(i, 2) == 0)
         xy(2*i - 1:2*i) = r*[cos(t), sin(t)]
      end do
      call polygon_from_points(xy, 'points', set, error)
      if (.not. allocated(error)) call check_facets(set, note, error)
      if (allocated(error)) then
         why = error%message
         call test_failed(error, 'the star is simple: '//why)
         return
      end if
      xy(2*500 - 1:2*500) = -xy(2*500 - 1:2*500)
      call polygon_from_points(xy, 'points', set, error)
      if (allocated(error)) return
      call check_facets(set, note, error)
      if (.not. allocated(error)) then
         call test_failed(error, 'a vertex moved across the polygon was not found crossing')
         return
      end if
      why = error%message
      if (index(why, 'crosses itself') > 0) then
         deallocate (error)
      else
         call test_failed(error, 'unexpected message: '//why)
      end if
   end subroutine test_polygon_crossing

   !> Of several bad edges the one of the lowest facet number is named: a box
   !> with facets 7 and 10 reversed; facet 2 (x = 1 face) shares an edge with
   !> facet 7 and is the lowest of the facets at a bad edge.
   subroutine test_edge_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      character(len=:), allocatable :: note, why
      real(wp) :: t(3, 3, 12)
      t = box_triangles([0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp, 0.0_wp], [0.0_wp, 1.0_wp, 0.0_wp], &
         & [0.0_wp, 0.0_wp, 1.0_wp], .false.)
      t(:, [2, 3], 11) = t(:, [3, 2], 11)
      t(:, [2, 3], 8) = t(:, [3, 2], 8)
      call write_ascii_stl(dir//'two_flipped.stl', t, ['x'], [1])
      call read_stl(dir//'two_flipped.stl', set, error)
      if (allocated(error)) return
      call check_facets(set, note, error)
      if (.not. allocated(error)) then
         call test_failed(error, 'two reversed facets passed')
         return
      end if
      why = error%message
      if (index(why, 'facet 2: inconsistent orientation') > 0 .and. index(why, 'facets 2 and 7') > 0) then
         deallocate (error)
      else
         call test_failed(error, 'expected facets 2 and 7 named: '//why)
      end if
   end subroutine test_edge_errors

end module sprc_test_facet_files
