!> Tests of the faceted solids (sprc_geometry_facet_solid, sprc_grid_facet_rule):
!> classification and cut-cell quadrature exact for the polyhedron.
!>
!> Independent checks: volume and boundary measure of closed facet sets built
!> here (a box rotated off the axes, a faceted sphere, a torus, a box with a
!> cavity, an octahedron and a cube with vertices and faces on grid nodes and
!> planes, 2D polygons convex and not), computed from the facets alone by the
!> divergence theorem (sum of a.(b x c)/6, shoelace) and summed facet areas;
!> the grid sums of the volume and surface rules over a uniform grid must
!> match. Normals and weights together: sum w x.n = dim * measure and
!> sum w n = 0 over the surface rule.
!>
!> Tolerance: each cut cell's measure is a sum of O(100) simplex measures and
!> clipped fragments, each exact up to a few eps relative to h^dim; with at most
!> ~1e4 cut cells the sum is good to ~1e4 * 100 * eps ~ 2e-10 of h^dim per
!> cell, i.e. far below 1e-10 relative for the total. 1e-10 relative is the
!> acceptance bound (a lost or doubled fragment, a wrong piece class or a
!> cracked edge changes the sums by >= 1e-4).
module sprc_test_facets
   use sprc_core_kinds, only: wp
   use sprc_geometry_region, only: cell_outside, cell_inside, cell_cut
   use sprc_geometry_facets, only: facet_set_type
   use sprc_geometry_shape, only: shape_type, new_facet_shape, new_box, new_cylinder, new_disk, new_halfspace
   use sprc_geometry_body, only: body_type, new_body, csg_add, csg_subtract, csg_intersect
   use sprc_core_text, only: itoa
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule, &
      & default_points
   use sprc_grid_facet_rule, only: facet_rule_type, facet_cell_rule, compress_min_factor
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_facets, facets_box, facets_polygon, facets_sphere

   real(wp), parameter :: pi = acos(-1.0_wp)
   real(wp), parameter :: tol_rel = 1.0e-10_wp

   !> Grid sums: measure, boundary measure, sum w x.n, |sum w n|, smallest weight.
   type :: sums_type
      real(wp) :: vol = 0.0_wp, area = 0.0_wp, div = 0.0_wp, flux(3) = 0.0_wp, wmin = huge(1.0_wp)
      !> Cut cells, unresolved boxes, the most surface points of one cell.
      integer :: ncut = 0, nunresolved = 0, nsurf_max = 0
   end type sums_type

contains

   subroutine collect_facets(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('rotated_box', test_rotated_box), &
         new_unittest('grid_aligned_ties', test_aligned), &
         new_unittest('sphere', test_sphere), &
         new_unittest('torus', test_torus), &
         new_unittest('cavity', test_cavity), &
         new_unittest('polygons_2d', test_polygons), &
         new_unittest('mixed_csg', test_mixed), &
         new_unittest('mixed_planes_compressed', test_mixed_planes), &
         new_unittest('classification', test_classification), &
         new_unittest('shape_errors', test_shape_errors), &
         new_unittest('compressed_rule', test_compressed), &
         new_unittest('cell_rule_compressed', test_cell_compressed) &
         ]
   end subroutine collect_facets

   ! ------------------------------------------------------------ tests

   !> A box rotated off the axes at levels 2..4 and two grid offsets.
   subroutine test_rotated_box(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      integer :: level
      call facets_box(set, [0.13_wp, -0.07_wp, 0.05_wp], [0.7_wp, 0.45_wp, 0.3_wp], [0.3_wp, -0.5_wp, 0.8_wp])
      do level = 2, 4
         call check_measures(set, level, -1.0_wp, 2.0_wp, 'rotated box', error)
         if (allocated(error)) return
         call check_measures(set, level, -1.0_wp - 1.0_wp/3, 3.0_wp, 'rotated box, offset', error)
         if (allocated(error)) return
      end do
   end subroutine test_rotated_box

   !> Vertices, edges and faces exactly on grid nodes, edges and planes: an
   !> octahedron with vertices on grid nodes (its faces through grid nodes and
   !> edges along cell diagonals), an axis-aligned cube with faces on grid planes,
   !> a cube of half a cell offset; 2D: a diamond with vertices on grid nodes and
   !> edges along cell diagonals, a square on grid lines.
   subroutine test_aligned(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      integer :: level

      call facets_octahedron(set, [0.0_wp, 0.0_wp, 0.0_wp], 0.5_wp)
      do level = 2, 4
         call check_measures(set, level, -1.0_wp, 2.0_wp, 'octahedron on nodes', error)
         if (allocated(error)) return
      end do
      call facets_box(set, [0.0_wp, 0.0_wp, 0.0_wp], [0.5_wp, 0.5_wp, 0.25_wp], [0.0_wp, 0.0_wp, 0.0_wp])
      do level = 2, 4
         call check_measures(set, level, -1.0_wp, 2.0_wp, 'cube on grid planes', error)
         if (allocated(error)) return
      end do
      call facets_box(set, [0.0625_wp, 0.0_wp, 0.0_wp], [0.5_wp, 0.5_wp, 0.25_wp], [0.0_wp, 0.0_wp, 0.0_wp])
      call check_measures(set, 3, -1.0_wp, 2.0_wp, 'cube half a cell off', error)
      if (allocated(error)) return
      call facets_polygon(set, reshape([0.5_wp, 0.0_wp, 0.0_wp, 0.5_wp, -0.5_wp, 0.0_wp, 0.0_wp, -0.5_wp], [2, 4]))
      do level = 2, 5
         call check_measures(set, level, -1.0_wp, 2.0_wp, 'diamond on nodes', error)
         if (allocated(error)) return
      end do
      call facets_polygon(set, reshape([-0.5_wp, -0.5_wp, 0.5_wp, -0.5_wp, 0.5_wp, 0.5_wp, -0.5_wp, 0.5_wp], [2, 4]))
      call check_measures(set, 3, -1.0_wp, 2.0_wp, 'square on grid lines', error)
   end subroutine test_aligned

   !> A UV sphere of 32 x 16 segments (960 facets) at levels 3 and 4, offset.
   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      call facets_sphere(set, [0.01_wp, 0.02_wp, -0.03_wp], 0.8_wp, 32, 16)
      call check_measures(set, 3, -1.0_wp, 2.0_wp, 'sphere', error)
      if (allocated(error)) return
      call check_measures(set, 4, -1.1_wp, 2.2_wp, 'sphere offset', error)
   end subroutine test_sphere

   subroutine test_torus(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      call facets_torus(set, 0.6_wp, 0.25_wp, 24, 12)
      call check_measures(set, 4, -1.0_wp, 2.0_wp, 'torus', error)
   end subroutine test_torus

   !> A rotated box with a spherical cavity (the inner surface oriented inwards).
   subroutine test_cavity(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: outer, inner, set
      call facets_box(outer, [0.0_wp, 0.0_wp, 0.0_wp], [0.8_wp, 0.7_wp, 0.75_wp], [0.2_wp, 0.1_wp, -0.3_wp])
      call facets_sphere(inner, [0.02_wp, -0.01_wp, 0.03_wp], 0.4_wp, 16, 8)
      inner%facet([1, 2], :) = inner%facet([2, 1], :)
      call merge_sets(outer, inner, set)
      call check_measures(set, 3, -1.5_wp, 3.0_wp, 'box with cavity', error)
      if (allocated(error)) return
      call check_measures(set, 4, -1.5_wp - 1.0_wp/7, 3.0_wp, 'box with cavity, offset', error)
   end subroutine test_cavity

   !> Polygons: a rotated square, a non-convex star, an L with a vertex on a node.
   subroutine test_polygons(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      real(wp) :: p(2, 10), a
      integer :: i, level

      do i = 1, 4
         a = 0.3_wp + (i - 1)*pi/2
         p(:, i) = 0.7_wp*[cos(a), sin(a)] + [0.03_wp, -0.02_wp]
      end do
      call facets_polygon(set, p(:, 1:4))
      do level = 2, 6
         call check_measures(set, level, -1.0_wp, 2.0_wp, 'rotated square', error)
         if (allocated(error)) return
      end do
      do i = 1, 10
         a = (i - 1)*pi/5 + 0.1_wp
         p(:, i) = merge(0.8_wp, 0.35_wp, mod(i, 2) == 1)*[cos(a), sin(a)]
      end do
      call facets_polygon(set, p)
      do level = 2, 6
         call check_measures(set, level, -1.0_wp, 2.0_wp, 'star', error)
         if (allocated(error)) return
      end do
      call facets_polygon(set, reshape([-0.5_wp, -0.5_wp, 0.5_wp, -0.5_wp, 0.5_wp, 0.0_wp, 0.0_wp, 0.0_wp, &
         & 0.0_wp, 0.5_wp, -0.5_wp, 0.5_wp], [2, 6]))
      call check_measures(set, 4, -1.0_wp, 2.0_wp, 'L on nodes', error)
   end subroutine test_polygons

   !> A faceted box minus an exact cylinder (3D) or disk (2D) against the same
   !> body built from a primitive box. Faces on grid planes (the plate of a
   !> Kirsch scene): no cell is cut by both kinds, so the measures agree to
   !> 1e-10. Faces off the grid: cells on the curves where the bore meets the
   !> faces are halved (`mixed_box`) and the boxes left unresolved are
   !> bounded: each changes the volume by at most its own, a^dim, and the
   !> boundary measure by at most 3 a^(dim-1) (two surface pieces, each at
   !> most sqrt(2) a^(dim-1) for a plane or a nearly flat piece of a cylinder).
   subroutine test_mixed(error)
      type(error_type), allocatable, intent(out) :: error
      call mixed_case(3, [0.5_wp, 0.5_wp, 0.25_wp], 3, error)
      if (allocated(error)) return
      call mixed_case(3, [0.53_wp, 0.47_wp, 0.29_wp], 3, error)
      if (allocated(error)) return
      call mixed_case(2, [0.5_wp, 0.75_wp, 0.0_wp], 4, error)
      if (allocated(error)) return
      call mixed_case(2, [0.53_wp, 0.71_wp, 0.0_wp], 4, error)
   end subroutine test_mixed

   subroutine mixed_case(dim, half, level, error)
      integer, intent(in) :: dim, level
      real(wp), intent(in) :: half(3)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      type(shape_type) :: box, bore
      type(body_type) :: exact_body, mixed_body
      type(sums_type) :: ref, got
      real(wp) :: a, p(2, 4), tol_v, tol_s
      character(len=:), allocatable :: name
      integer :: i

      name = 'mixed '//achar(48 + dim)//'D'
      if (dim == 3) then
         call facets_box(set, [0.0_wp, 0.0_wp, 0.0_wp], half, [0.0_wp, 0.0_wp, 0.0_wp])
         call new_box(box, 'plate', -half, half, error)
         if (allocated(error)) return
         call new_cylinder(bore, 'bore', [0.03_wp, -0.02_wp, 0.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], 0.2_wp, error)
      else
         p = reshape([-half(1), -half(2), half(1), -half(2), half(1), half(2), -half(1), half(2)], [2, 4])
         call facets_polygon(set, p)
         call new_box(box, 'plate', -half(1:2), half(1:2), error)
         if (allocated(error)) return
         call new_disk(bore, 'bore', [0.03_wp, -0.02_wp], 0.2_wp, error)
      end if
      if (allocated(error)) return
      call new_body(exact_body, 'exact')
      call exact_body%add_shape(csg_add, box, error)
      if (.not. allocated(error)) call exact_body%add_shape(csg_subtract, bore, error)
      if (allocated(error)) return
      call make_body(set, mixed_body, error)
      if (.not. allocated(error)) call mixed_body%add_shape(csg_subtract, bore, error)
      if (allocated(error)) return
      call grid_sums(exact_body, dim, level, -1.0_wp, 2.0_wp, ref, error)
      if (allocated(error)) return
      call grid_sums(mixed_body, dim, level, -1.0_wp, 2.0_wp, got, error)
      if (allocated(error)) return
      a = 2.0_wp/2**level/2**merge(4, 8, dim == 3)
      tol_v = tol_rel*ref%vol + got%nunresolved*a**dim
      tol_s = tol_rel*ref%area + got%nunresolved*3*a**(dim - 1)
      call check(error, got%vol, ref%vol, tol_v, name//' volume')
      if (allocated(error)) return
      call check(error, got%area, ref%area, tol_s, name//' boundary measure')
      if (allocated(error)) return
      call check(error, got%wmin > 0.0_wp, name//': non-positive weight')
      if (allocated(error)) return
      i = count([half(1:dim)*2**level/2.0_wp - nint(half(1:dim)*2**level/2.0_wp) /= 0.0_wp])
      if (i == 0) call check(error, got%nunresolved, 0, name//' with faces on grid planes: unresolved boxes')
   end subroutine mixed_case

   !> A faceted box cut by an exact oblique halfspace (3D, faces off the grid
   !> planes) against the same body from a primitive box: cells where the
   !> halfspace meets a facet are halved (`mixed_box`), and their planar
   !> surface points are compressed plane by plane (`compress_planes`). The
   !> measures and the integral of x.n over the boundary agree within the
   !> unresolved boxes' bound (`mixed_case`; |x| <= |half| on it), and no cell
   !> keeps more than 7 M surface points (M = 21, the moments of degree 5 in
   !> the plane; a cell meets at most six facet planes and the halfspace):
   !> without the compression the worst cell keeps several thousand.
   subroutine test_mixed_planes(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      type(shape_type) :: box, cut
      type(body_type) :: exact_body, mixed_body
      type(sums_type) :: ref, got
      real(wp) :: a, half(3), normal(3)
      integer, parameter :: level = 3, m2 = 21

      half = [0.53_wp, 0.47_wp, 0.29_wp]
      normal = [0.3_wp, 0.2_wp, 1.0_wp]
      call facets_box(set, [0.0_wp, 0.0_wp, 0.0_wp], half, [0.0_wp, 0.0_wp, 0.0_wp])
      call new_box(box, 'plate', -half, half, error)
      if (.not. allocated(error)) call new_halfspace(cut, 'cut', [0.05_wp, -0.03_wp, 0.07_wp], normal, error)
      if (allocated(error)) return
      call new_body(exact_body, 'exact')
      call exact_body%add_shape(csg_add, box, error)
      if (.not. allocated(error)) call exact_body%add_shape(csg_intersect, cut, error)
      if (allocated(error)) return
      call make_body(set, mixed_body, error)
      if (.not. allocated(error)) call mixed_body%add_shape(csg_intersect, cut, error)
      if (allocated(error)) return
      call grid_sums(exact_body, 3, level, -1.0_wp, 2.0_wp, ref, error)
      if (allocated(error)) return
      call grid_sums(mixed_body, 3, level, -1.0_wp, 2.0_wp, got, error)
      if (allocated(error)) return
      a = 2.0_wp/2**level/2**4
      call check(error, got%vol, ref%vol, tol_rel*ref%vol + got%nunresolved*a**3, 'mixed planes volume')
      if (allocated(error)) return
      call check(error, got%area, ref%area, tol_rel*ref%area + got%nunresolved*3*a**2, 'mixed planes boundary measure')
      if (allocated(error)) return
      call check(error, got%div, ref%div, tol_rel*ref%area + got%nunresolved*3*a**2*norm2(half), &
         & 'mixed planes: the integral of x.n')
      if (allocated(error)) return
      call check(error, got%wmin > 0.0_wp .and. got%nsurf_max <= 7*m2, 'mixed planes: '//itoa(got%nsurf_max)// &
         & ' surface points in one cell (at most '//itoa(7*m2)//'), weights positive')
   end subroutine test_mixed_planes

   !> Classes of boxes against a unit cube [0, 1]^3 given as facets: inside,
   !> outside, cut, and the tie rules (a facet on a box face, a box touching the
   !> cube only along an edge or at a corner).
   subroutine test_classification(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      type(body_type) :: body
      call facets_box(set, [0.5_wp, 0.5_wp, 0.5_wp], [0.5_wp, 0.5_wp, 0.5_wp], [0.0_wp, 0.0_wp, 0.0_wp])
      call make_body(set, body, error)
      if (allocated(error)) return
      call expect(body, [0.25_wp, 0.25_wp, 0.25_wp], [0.5_wp, 0.5_wp, 0.5_wp], cell_inside, 'interior box', error)
      if (allocated(error)) return
      call expect(body, [1.5_wp, 0.25_wp, 0.25_wp], [2.0_wp, 0.5_wp, 0.5_wp], cell_outside, 'exterior box', error)
      if (allocated(error)) return
      call expect(body, [0.75_wp, 0.25_wp, 0.25_wp], [1.25_wp, 0.5_wp, 0.5_wp], cell_cut, 'straddling box', error)
      if (allocated(error)) return
      call expect(body, [0.5_wp, 0.25_wp, 0.25_wp], [1.0_wp, 0.5_wp, 0.5_wp], cell_inside, 'facet on upper face', &
         & error)
      if (allocated(error)) return
      call expect(body, [1.0_wp, 0.25_wp, 0.25_wp], [1.5_wp, 0.5_wp, 0.5_wp], cell_outside, 'facet on lower face', &
         & error)
      if (allocated(error)) return
      call expect(body, [1.0_wp, 1.0_wp, 0.25_wp], [1.5_wp, 1.5_wp, 0.5_wp], cell_outside, 'touching along an edge', &
         & error)
      if (allocated(error)) return
      call expect(body, [1.0_wp, 1.0_wp, 1.0_wp], [1.5_wp, 1.5_wp, 1.5_wp], cell_outside, 'touching at a corner', error)
      if (allocated(error)) return
      call expect(body, [-0.5_wp, -0.5_wp, -0.5_wp], [1.5_wp, 1.5_wp, 1.5_wp], cell_cut, 'box around the cube', error)
   end subroutine test_classification

   subroutine test_shape_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      type(shape_type) :: shape
      logical :: refused
      call new_facet_shape(shape, 'empty', set, error)
      refused = allocated(error) .and. shape%kind == 0
      call check(error, refused, 'an empty facet set is refused')
      if (allocated(error)) return
      call facets_box(set, [0.0_wp, 0.0_wp, 0.0_wp], [1.0_wp, 1.0_wp, 1.0_wp], [0.0_wp, 0.0_wp, 0.0_wp])
      set%facet(2, 5) = 99
      call new_facet_shape(shape, 'bad index', set, error)
      refused = allocated(error) .and. shape%kind == 0
      call check(error, refused, 'a vertex index out of range is refused')
   end subroutine test_shape_errors

   !> The compressed volume rule of a cut cell (sprc_grid_facet_rule, module
   !> notes) against the full one: at most M = C(2q - 1 + dim, dim) points and
   !> fewer than the full rule, positive weights, and the same integral of every
   !> monomial of total degree <= 2q - 1 in the cell's coordinates scaled to
   !> [-1, 1]. Such a monomial is a combination of the Legendre products with
   !> coefficients of absolute sum 1 (|x^n| and every P_k are 1 at x = 1, and
   !> the coefficients are >= 0), so the moments' acceptance bound M^2 eps V
   !> bounds its error too. Cells aligned with the facets' vertices and
   !> offset, q = 3 (Q1) and 4 (Q2), 3D (sphere, rotated box) and 2D (star).
   subroutine test_compressed(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      real(wp) :: p(2, 10), a
      integer :: i, q

      call facets_sphere(set, [0.01_wp, 0.02_wp, -0.03_wp], 0.8_wp, 32, 16)
      do q = 3, 4
         call compressed_case(set, [0.7_wp, -0.1_wp, -0.1_wp], [0.95_wp, 0.15_wp, 0.15_wp], q, 'sphere', error)
         if (allocated(error)) return
         call compressed_case(set, [0.25_wp, 0.5_wp, 0.25_wp], [0.5_wp, 0.75_wp, 0.5_wp], q, 'sphere aligned', error)
         if (allocated(error)) return
      end do
      call facets_sphere(set, [0.01_wp, 0.02_wp, -0.03_wp], 0.8_wp, 64, 32)
      call compressed_case(set, [0.8095_wp, -0.05_wp, -0.05_wp], [0.9095_wp, 0.05_wp, 0.05_wp], 4, &
         & 'sphere tiny cut', error)
      if (allocated(error)) return
      call facets_box(set, [0.1_wp, 0.0_wp, 0.05_wp], [0.6_wp, 0.4_wp, 0.3_wp], [0.3_wp, -0.2_wp, 0.5_wp])
      call compressed_case(set, [0.3_wp, 0.0_wp, 0.0_wp], [0.8_wp, 0.5_wp, 0.5_wp], 3, 'rotated box', error)
      if (allocated(error)) return
      do i = 1, 10
         a = (i - 1)*pi/5 + 0.1_wp
         p(:, i) = merge(0.8_wp, 0.35_wp, mod(i, 2) == 1)*[cos(a), sin(a)]
      end do
      call facets_polygon(set, p)
      do q = 3, 4
         call compressed_case(set, [-0.5_wp, -0.5_wp], [0.5_wp, 0.5_wp], q, 'star', error)
         if (allocated(error)) return
      end do
   end subroutine test_compressed

   subroutine compressed_case(set, lo, hi, q, name, error)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: q
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shape
      type(facet_rule_type) :: full, comp
      real(wp) :: tol, vol, ifull, icomp, worst
      integer :: d, m, e(3), deg, e1, e2, e3
      character(len=200) :: msg

      call new_facet_shape(shape, name, set, error)
      if (allocated(error)) return
      d = set%dim
      call facet_cell_rule(full, shape%solid, lo, hi, q, .true., .false., compress=.false.)
      call facet_cell_rule(comp, shape%solid, lo, hi, q, .true., .false., compress=.true.)
      deg = 2*q - 1
      m = merge((deg + 1)*(deg + 2)/2, (deg + 1)*(deg + 2)*(deg + 3)/6, d == 2)
      vol = sum(full%vol_w(1:full%nvol))
      tol = real(m, wp)**2*epsilon(1.0_wp)*vol
      write (msg, '(a, ": ", i0, " points of ", i0, ", M = ", i0)') name, comp%nvol, full%nvol, m
      call check(error, comp%nvol <= m .and. comp%nvol < full%nvol .and. comp%nvol_full == full%nvol, trim(msg))
      if (allocated(error)) return
      call check(error, all(comp%vol_w(1:comp%nvol) > 0.0_wp), name//': a weight is not positive')
      if (allocated(error)) return
      worst = 0.0_wp
      do e1 = 0, deg
         do e2 = 0, deg - e1
            do e3 = 0, merge(deg - e1 - e2, 0, d == 3)
               e = [e1, e2, e3]
               ifull = scaled_moment(full%vol_x(:, 1:full%nvol), full%vol_w(1:full%nvol), lo, hi, e, d)
               icomp = scaled_moment(comp%vol_x(:, 1:comp%nvol), comp%vol_w(1:comp%nvol), lo, hi, e, d)
               worst = max(worst, abs(icomp - ifull))
            end do
         end do
      end do
      write (msg, '(a, ": a moment is off by ", es10.3, " > ", es10.3)') name, worst, tol
      call check(error, worst <= tol, trim(msg))
   end subroutine compressed_case

   !> The cell quadrature compresses the volume rule of every cell a faceted
   !> solid cuts, once per cell after its sub-boxes (sprc_grid_quadrature,
   !> `cut_rule`): at most M = C(2q - 1 + dim, dim) points, positive weights,
   !> and every monomial of total degree <= 2q - 1 in the cell's coordinates
   !> scaled to [-1, 1] integrated as the uncompressed polyhedral rule of the
   !> whole cell does (facet_cell_rule without compression: no sub-boxes, an
   !> independent path). Tolerance: the stated sqrt(eps) tier times the cell's
   !> measure (the moments are matched to M^2 eps in the basis of the points'
   !> bounding box; a rule exact to a lower degree is off by >= 1e-5 here).
   !> Cells: a sphere of 2048 facets (the cell meets more than 32: halved),
   !> q = 3 and 4; a tiny cut of it (inside fraction < 1e-3), whose rule is
   !> below the compression threshold and kept; a 2D circle of 256 segments,
   !> q = 4. (The tiny cut's compressed weights: `test_compressed`.)
   subroutine test_cell_compressed(error)
      type(error_type), allocatable, intent(out) :: error
      type(facet_set_type) :: set
      real(wp) :: p(2, 256), a
      integer :: q, i

      call facets_sphere(set, [0.01_wp, 0.02_wp, -0.03_wp], 0.8_wp, 64, 32)
      do q = 3, 4
         call cell_compressed_case(set, [0.4_wp, -0.3_wp, -0.3_wp], [1.0_wp, 0.3_wp, 0.3_wp], q, .false., &
            & 'sphere', error)
         if (allocated(error)) return
      end do
      call cell_compressed_case(set, [0.8095_wp, -0.05_wp, -0.05_wp], [0.9095_wp, 0.05_wp, 0.05_wp], 4, .true., &
         & 'sphere tiny cut', error)
      if (allocated(error)) return
      do i = 1, 256
         a = (i - 1)*pi/128 + 0.01_wp
         p(:, i) = 0.8_wp*[cos(a), sin(a)]
      end do
      call facets_polygon(set, p)
      call cell_compressed_case(set, [0.3_wp, 0.3_wp], [0.7_wp, 0.7_wp], 4, .false., 'circle', error)
   end subroutine test_cell_compressed

   subroutine cell_compressed_case(set, lo, hi, q, tiny, name, error)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: q
      logical, intent(in) :: tiny
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shape
      type(body_type) :: body
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      type(facet_rule_type) :: full
      real(wp) :: tol, vol, worst
      integer :: d, m, e(3), deg, e1, e2, e3
      character(len=200) :: msg

      d = set%dim
      call make_body(set, body, error)
      if (allocated(error)) return
      call new_facet_shape(shape, name, set, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, d, q, error)
      if (allocated(error)) return
      call cell_rule(quad, body, lo, hi, rule, error)
      if (allocated(error)) return
      call facet_cell_rule(full, shape%solid, lo, hi, q, .true., .false., compress=.false.)
      deg = 2*q - 1
      m = merge((deg + 1)*(deg + 2)/2, (deg + 1)*(deg + 2)*(deg + 3)/6, d == 2)
      vol = product(hi(1:d) - lo(1:d))
      write (msg, '(a, ": inside fraction ", es10.3)') name, sum(full%vol_w(1:full%nvol))/vol
      call check(error, (sum(full%vol_w(1:full%nvol)) < 1.0e-3_wp*vol) .eqv. tiny, trim(msg))
      if (allocated(error)) return
      write (msg, '(a, ": ", i0, " points, the full rule ", i0, ", M = ", i0)') name, rule%nvol, full%nvol, m
      if (full%nvol > compress_min_factor*m) then
         call check(error, rule%nvol <= m, trim(msg))
      else
         call check(error, rule%nvol == full%nvol, trim(msg)//' (below the compression threshold: kept)')
      end if
      if (allocated(error)) return
      call check(error, all(rule%vol_w(1:rule%nvol) > 0.0_wp), name//': a weight is not positive')
      if (allocated(error)) return
      tol = sqrt(epsilon(1.0_wp))*vol
      worst = 0.0_wp
      do e1 = 0, deg
         do e2 = 0, deg - e1
            do e3 = 0, merge(deg - e1 - e2, 0, d == 3)
               e = [e1, e2, e3]
               worst = max(worst, abs(scaled_moment(rule%vol_x(:, 1:rule%nvol), rule%vol_w(1:rule%nvol), lo, hi, e, d) - &
                  & scaled_moment(full%vol_x(:, 1:full%nvol), full%vol_w(1:full%nvol), lo, hi, e, d)))
            end do
         end do
      end do
      write (msg, '(a, ": a moment is off by ", es10.3, " > ", es10.3)') name, worst, tol
      call check(error, worst <= tol, trim(msg))
   end subroutine cell_compressed_case

   !> Sum of w times the monomial of exponents e(1:d) in the coordinates of the
   !> box [lo, hi] scaled to [-1, 1].
   real(wp) function scaled_moment(x, w, lo, hi, e, d) result(moment)
      real(wp), intent(in) :: x(:, :), w(:), lo(:), hi(:)
      integer, intent(in) :: e(3), d
      integer :: j, k
      real(wp) :: t
      moment = 0.0_wp
      do j = 1, size(w)
         t = w(j)
         do k = 1, d
            t = t*((2.0_wp*x(k, j) - lo(k) - hi(k))/(hi(k) - lo(k)))**e(k)
         end do
         moment = moment + t
      end do
   end function scaled_moment

   ! ------------------------------------------------------------ checks

   subroutine expect(body, lo, hi, cls, name, error)
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: lo(:), hi(:)
      integer, intent(in) :: cls
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      call check(error, body%classify_box(lo, hi), cls, name)
   end subroutine expect

   subroutine make_body(set, body, error)
      type(facet_set_type), intent(in) :: set
      type(body_type), intent(out) :: body
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shape
      call new_facet_shape(shape, 'part', set, error)
      if (allocated(error)) return
      call new_body(body, 'body')
      call body%add_shape(csg_add, shape, error)
   end subroutine make_body

   !> Volume, boundary measure and the divergence identities of the grid rules
   !> on [x0, x0 + size]^dim at `level` against the facet set's own measures.
   subroutine check_measures(set, level, x0, size, name, error)
      type(facet_set_type), intent(in) :: set
      integer, intent(in) :: level
      real(wp), intent(in) :: x0, size
      character(len=*), intent(in) :: name
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: body
      type(sums_type) :: sums
      real(wp) :: vol, area
      character(len=16) :: tag

      write (tag, '(" L",i0)') level
      call make_body(set, body, error)
      if (allocated(error)) return
      call set_measures(set, vol, area)
      call grid_sums(body, set%dim, level, x0, size, sums, error)
      if (allocated(error)) return
      call check(error, sums%wmin > 0.0_wp, name//trim(tag)//': non-positive weight')
      if (allocated(error)) return
      call check(error, sums%vol, vol, tol_rel, name//trim(tag)//' volume', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%area, area, tol_rel, name//trim(tag)//' boundary measure', rel=.true.)
      if (allocated(error)) return
      call check(error, sums%div, set%dim*vol, tol_rel, name//trim(tag)//' sum w x.n', rel=.true.)
      if (allocated(error)) return
      call check(error, norm2(sums%flux), 0.0_wp, tol_rel*area, name//trim(tag)//' |sum w n|')
   end subroutine check_measures

   subroutine grid_sums(body, dim, level, x0, size, sums, error)
      type(body_type), intent(in) :: body
      integer, intent(in) :: dim, level
      real(wp), intent(in) :: x0, size
      type(sums_type), intent(out) :: sums
      type(error_type), allocatable, intent(out) :: error
      type(cut_quadrature_type) :: quad
      type(cell_rule_type) :: rule
      real(wp) :: lo(3), hi(3), h
      integer :: n, i, j, k, idx(3), q

      call new_cut_quadrature(quad, dim, default_points(1), error)
      if (allocated(error)) return
      n = 2**level
      h = size/n
      do k = 0, merge(n - 1, 0, dim == 3)
         do j = 0, n - 1
            do i = 0, n - 1
               idx = [i, j, k]
               lo(1:dim) = x0 + h*idx(1:dim)
               hi(1:dim) = x0 + h*(idx(1:dim) + 1)
               call cell_rule(quad, body, lo(1:dim), hi(1:dim), rule, error)
               if (allocated(error)) return
               if (rule%cls == cell_cut) sums%ncut = sums%ncut + 1
               sums%nsurf_max = max(sums%nsurf_max, rule%nsurf)
               sums%nunresolved = sums%nunresolved + rule%nunresolved
               sums%vol = sums%vol + sum(rule%vol_w(1:rule%nvol))
               do q = 1, rule%nsurf
                  sums%area = sums%area + rule%surf_w(q)
                  sums%div = sums%div + rule%surf_w(q)*dot_product(rule%surf_x(1:dim, q), rule%surf_n(1:dim, q))
                  sums%flux = sums%flux + rule%surf_w(q)*rule%surf_n(:, q)
               end do
               if (rule%nvol > 0) sums%wmin = min(sums%wmin, minval(rule%vol_w(1:rule%nvol)))
               if (rule%nsurf > 0) sums%wmin = min(sums%wmin, minval(rule%surf_w(1:rule%nsurf)))
            end do
         end do
      end do
   end subroutine grid_sums

   !> Volume (area in 2D) by the divergence theorem and boundary measure, from the facets.
   subroutine set_measures(set, vol, area)
      type(facet_set_type), intent(in) :: set
      real(wp), intent(out) :: vol, area
      real(wp) :: a(3), b(3), c(3), n(3)
      integer :: f
      vol = 0.0_wp
      area = 0.0_wp
      do f = 1, set%nfacet
         a = set%vert(:, set%facet(1, f))
         b = set%vert(:, set%facet(2, f))
         if (set%dim == 2) then
            vol = vol + 0.5_wp*(a(1)*b(2) - a(2)*b(1))
            area = area + norm2(b - a)
         else
            c = set%vert(:, set%facet(3, f))
            n = [b(2)*c(3) - b(3)*c(2), b(3)*c(1) - b(1)*c(3), b(1)*c(2) - b(2)*c(1)]
            vol = vol + dot_product(a, n)/6.0_wp
            n = cross(b - a, c - a)
            area = area + 0.5_wp*norm2(n)
         end if
      end do
   end subroutine set_measures

   ! ------------------------------------------------------------ generators

   !> A box of half-sizes `half` around `center`, rotated by the rotation vector `rot`.
   subroutine facets_box(set, center, half, rot)
      type(facet_set_type), intent(out) :: set
      real(wp), intent(in) :: center(3), half(3), rot(3)
      integer, parameter :: quads(4, 6) = reshape([1, 3, 4, 2, 5, 6, 8, 7, 1, 2, 6, 5, 3, 7, 8, 4, 1, 5, 7, 3, &
         & 2, 4, 8, 6], [4, 6])
      real(wp) :: r(3, 3), s(3)
      integer :: i, f

      r = rotation(rot)
      call start_set(set, 3, 8, 12)
      do i = 1, 8
         s = merge(1.0_wp, -1.0_wp, [btest(i - 1, 0), btest(i - 1, 1), btest(i - 1, 2)])
         set%vert(:, i) = center + matmul(r, s*half)
      end do
      do f = 1, 6
         set%facet(:, 2*f - 1) = quads([1, 2, 3], f)
         set%facet(:, 2*f) = quads([1, 3, 4], f)
      end do
      call orient_from(set, center)
   end subroutine facets_box

   subroutine facets_octahedron(set, center, r)
      type(facet_set_type), intent(out) :: set
      real(wp), intent(in) :: center(3), r
      integer :: i, f, sx, sy, sz
      call start_set(set, 3, 6, 8)
      do i = 1, 3
         set%vert(:, 2*i - 1) = center
         set%vert(i, 2*i - 1) = center(i) + r
         set%vert(:, 2*i) = center
         set%vert(i, 2*i) = center(i) - r
      end do
      f = 0
      do sx = 1, 2
         do sy = 3, 4
            do sz = 5, 6
               f = f + 1
               set%facet(:, f) = [sx, sy, sz]
            end do
         end do
      end do
      call orient_from(set, center)
   end subroutine facets_octahedron

   !> A UV sphere: nlon segments around, nlat from pole to pole.
   subroutine facets_sphere(set, center, r, nlon, nlat)
      type(facet_set_type), intent(out) :: set
      real(wp), intent(in) :: center(3), r
      integer, intent(in) :: nlon, nlat
      real(wp) :: th, ph
      integer :: i, j, f, np, jn

      np = (nlat - 1)*nlon
      call start_set(set, 3, np + 2, 2*nlon*(nlat - 1))
      do i = 1, nlat - 1
         th = pi*i/nlat
         do j = 1, nlon
            ph = 2*pi*(j - 1)/nlon
            set%vert(:, ring(i, j)) = center + r*[sin(th)*cos(ph), sin(th)*sin(ph), cos(th)]
         end do
      end do
      set%vert(:, np + 1) = center + [0.0_wp, 0.0_wp, r]
      set%vert(:, np + 2) = center - [0.0_wp, 0.0_wp, r]
      f = 0
      do j = 1, nlon
         jn = mod(j, nlon) + 1
         f = f + 1
         set%facet(:, f) = [np + 1, ring(1, j), ring(1, jn)]
         f = f + 1
         set%facet(:, f) = [ring(nlat - 1, j), np + 2, ring(nlat - 1, jn)]
         do i = 1, nlat - 2
            f = f + 1
            set%facet(:, f) = [ring(i, j), ring(i + 1, j), ring(i + 1, jn)]
            f = f + 1
            set%facet(:, f) = [ring(i, j), ring(i + 1, jn), ring(i, jn)]
         end do
      end do
      call orient_from(set, center)
   contains
      integer function ring(i, j)
         integer, intent(in) :: i, j
         ring = (i - 1)*nlon + j
      end function ring
   end subroutine facets_sphere

   !> A torus around the z axis (tube radius b around the circle of radius a).
   subroutine facets_torus(set, a, b, nu, nv)
      type(facet_set_type), intent(out) :: set
      real(wp), intent(in) :: a, b
      integer, intent(in) :: nu, nv
      real(wp) :: u, v, c(3), g(3)
      integer :: i, j, f, i1, j1

      call start_set(set, 3, nu*nv, 2*nu*nv)
      do i = 1, nu
         u = 2*pi*(i - 1)/nu + 0.05_wp
         do j = 1, nv
            v = 2*pi*(j - 1)/nv
            set%vert(:, id(i, j)) = [(a + b*cos(v))*cos(u), (a + b*cos(v))*sin(u), b*sin(v)]
         end do
      end do
      f = 0
      do i = 1, nu
         i1 = mod(i, nu) + 1
         do j = 1, nv
            j1 = mod(j, nv) + 1
            f = f + 1
            set%facet(:, f) = [id(i, j), id(i1, j), id(i1, j1)]
            f = f + 1
            set%facet(:, f) = [id(i, j), id(i1, j1), id(i, j1)]
         end do
      end do
      do f = 1, set%nfacet
         ! outward: away from the tube's centre circle
         g = sum(set%vert(:, set%facet(:, f)), dim=2)/3
         c = a*[g(1), g(2), 0.0_wp]/norm2(g(1:2))
         call orient_facet(set, f, g - c)
      end do
   contains
      integer function id(i, j)
         integer, intent(in) :: i, j
         id = (i - 1)*nv + j
      end function id
   end subroutine facets_torus

   !> A polygon, vertices p(2, n) counter-clockwise.
   subroutine facets_polygon(set, p)
      type(facet_set_type), intent(out) :: set
      real(wp), intent(in) :: p(:, :)
      integer :: i, n
      n = size(p, 2)
      call start_set(set, 2, n, n)
      do i = 1, n
         set%vert(1:2, i) = p(:, i)
         set%facet(:, i) = [i, mod(i, n) + 1]
      end do
   end subroutine facets_polygon

   subroutine merge_sets(a, b, set)
      type(facet_set_type), intent(in) :: a, b
      type(facet_set_type), intent(out) :: set
      call start_set(set, a%dim, a%nvert + b%nvert, a%nfacet + b%nfacet)
      set%vert(:, 1:a%nvert) = a%vert
      set%vert(:, a%nvert + 1:) = b%vert
      set%facet(:, 1:a%nfacet) = a%facet
      set%facet(:, a%nfacet + 1:) = b%facet + a%nvert
   end subroutine merge_sets

   subroutine start_set(set, dim, nvert, nfacet)
      type(facet_set_type), intent(out) :: set
      integer, intent(in) :: dim, nvert, nfacet
      set%dim = dim
      set%nvert = nvert
      set%nfacet = nfacet
      allocate (set%vert(3, nvert), set%facet(dim, nfacet), set%group(nfacet), set%group_name(0), &
         & set%file_index(nfacet))
      set%vert = 0.0_wp
      set%group = 0
      set%file_index = 0
      set%source = 'test'
   end subroutine start_set

   !> Orient every facet away from `center` (star-shaped sets).
   subroutine orient_from(set, center)
      type(facet_set_type), intent(inout) :: set
      real(wp), intent(in) :: center(3)
      integer :: f
      do f = 1, set%nfacet
         call orient_facet(set, f, sum(set%vert(:, set%facet(:, f)), dim=2)/3 - center)
      end do
   end subroutine orient_from

   subroutine orient_facet(set, f, out)
      type(facet_set_type), intent(inout) :: set
      integer, intent(in) :: f
      real(wp), intent(in) :: out(3)
      real(wp) :: a(3), b(3), c(3)
      a = set%vert(:, set%facet(1, f))
      b = set%vert(:, set%facet(2, f))
      c = set%vert(:, set%facet(3, f))
      if (dot_product(cross(b - a, c - a), out) < 0.0_wp) set%facet([1, 2], f) = set%facet([2, 1], f)
   end subroutine orient_facet

   !> Rotation matrix of the rotation vector w (Rodrigues).
   function rotation(w) result(r)
      real(wp), intent(in) :: w(3)
      real(wp) :: r(3, 3), t, k(3, 3)
      integer :: i
      r = 0.0_wp
      do i = 1, 3
         r(i, i) = 1.0_wp
      end do
      t = norm2(w)
      if (.not. t > 0.0_wp) return
      k = reshape([0.0_wp, w(3), -w(2), -w(3), 0.0_wp, w(1), w(2), -w(1), 0.0_wp], [3, 3])/t
      r = r + sin(t)*k + (1.0_wp - cos(t))*matmul(k, k)
   end function rotation

   pure function cross(a, b) result(c)
      real(wp), intent(in) :: a(3), b(3)
      real(wp) :: c(3)
      c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
   end function cross

end module sprc_test_facets
