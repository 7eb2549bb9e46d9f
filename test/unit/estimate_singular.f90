!> Tests of the singular split at re-entrant corners (sprc_estimate_singular):
!> corners found from boundary points against the geometry that made them
!> (apex, opening, bisector of an L-shaped and a 225-degree notch, rotated and
!> offset), no corner on convex corners, curved boundaries, loaded faces or a
!> single face; the fit recovers the amplitudes of data that are exactly
!> Williams' field plus a linear smooth part.
module sprc_test_singular
   use sprc_core_kinds, only: wp
   use sprc_core_material, only: plane_strain, plane_stress
   use sprc_exact_corner, only: corner_type, new_corner
   use sprc_estimate_singular, only: corner_site_type, singular_fit_type, find_corners, fit_corner
   use sprc_testsuite, only: unittest_type, new_unittest, check, error_type
   implicit none
   private

   public :: collect_singular

   real(wp), parameter :: pi = acos(-1.0_wp)
   !> Apex and bisector: a few operations on O(1) numbers, 64 eps.
   real(wp), parameter :: thr = 64.0_wp*epsilon(1.0_wp)

contains

   subroutine collect_singular(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('finds_lshape_corner', test_lshape), &
         new_unittest('finds_rotated_225', test_rotated), &
         new_unittest('no_corner_convex_curved_loaded', test_no_corner), &
         new_unittest('fit_recovers_amplitudes', test_fit) &
         ]
   end subroutine collect_singular

   !> Boundary points of two faces from apex c along unit tangents ta, tb (the
   !> faces' points at distances 0.05 .. 0.35 from c), outward normals na, nb.
   subroutine two_faces(c, ta, na, tb, nb, x, n)
      real(wp), intent(in) :: c(2), ta(2), na(2), tb(2), nb(2)
      real(wp), intent(out) :: x(2, 8), n(2, 8)
      integer :: i
      do i = 1, 4
         x(:, i) = c + (0.05_wp + 0.1_wp*(i - 1))*ta
         n(:, i) = na
         x(:, 4 + i) = c + (0.05_wp + 0.1_wp*(i - 1))*tb
         n(:, 4 + i) = nb
      end do
   end subroutine two_faces

   !> The L-shape's notch at c = (0.1, -0.2) (off the box's lines): faces along +x
   !> (normal -y) and -y (normal +x); 270 degrees, bisector (-1, 1)/sqrt(2).
   subroutine test_lshape(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_site_type), allocatable :: sites(:)
      real(wp) :: x(2, 8), n(2, 8), c(2)

      c = [0.1_wp, -0.2_wp]
      call two_faces(c, [1.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], [0.0_wp, -1.0_wp], [1.0_wp, 0.0_wp], x, n)
      call find_corners(x, n, [1, 9], spread(.true., 1, 8), reshape([-0.3_wp, -0.6_wp], [2, 1]), &
         & reshape([0.5_wp, 0.2_wp], [2, 1]), sites)
      call check(error, size(sites), 1, 'one corner')
      if (allocated(error)) return
      call check(error, norm2(sites(1)%point - c) <= thr, 'apex '//str(sites(1)%point))
      if (allocated(error)) return
      call check(error, sites(1)%angle, 270.0_wp, 270.0_wp*thr, 'opening')
      if (allocated(error)) return
      call check(error, norm2(sites(1)%direction - [-1.0_wp, 1.0_wp]/sqrt(2.0_wp)) <= thr, 'bisector')
      if (allocated(error)) return
      ! the same apex from a second element (a shared edge) counts once
      call find_corners(reshape([x, x], [2, 16]), reshape([n, n], [2, 16]), [1, 9, 17], spread(.true., 1, 16), &
         & reshape([-0.3_wp, -0.6_wp, -0.3_wp, -0.6_wp], [2, 2]), reshape([0.5_wp, 0.2_wp, 0.5_wp, 0.2_wp], [2, 2]), &
         & sites)
      call check(error, size(sites), 1, 'one corner from two elements')
   end subroutine test_lshape

   !> A 225-degree notch turned by 0.3 rad: normals 45 degrees apart.
   subroutine test_rotated(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_site_type), allocatable :: sites(:)
      real(wp) :: x(2, 8), n(2, 8), c(2), a, ta(2), tb(2), na(2), nb(2), bis(2)

      a = 0.3_wp
      c = [0.25_wp, 0.05_wp]
      ! material wedge |t - a| <= 112.5 deg about the bisector at angle a
      ta = [cos(a + 0.625_wp*pi), sin(a + 0.625_wp*pi)]
      tb = [cos(a - 0.625_wp*pi), sin(a - 0.625_wp*pi)]
      ! outward normals: the tangents turned away from the material
      na = [-ta(2), ta(1)]
      nb = [tb(2), -tb(1)]
      bis = [cos(a), sin(a)]
      call two_faces(c, ta, na, tb, nb, x, n)
      call find_corners(x, n, [1, 9], spread(.true., 1, 8), reshape([0.0_wp, -0.2_wp], [2, 1]), &
         & reshape([0.5_wp, 0.3_wp], [2, 1]), sites)
      call check(error, size(sites), 1, 'one corner')
      if (allocated(error)) return
      call check(error, norm2(sites(1)%point - c) <= thr, 'apex '//str(sites(1)%point))
      if (allocated(error)) return
      ! acos near 45 degrees: its derivative is sqrt(2), thr in degrees
      call check(error, sites(1)%angle, 225.0_wp, 180.0_wp/pi*4.0_wp*thr, 'opening')
      if (allocated(error)) return
      call check(error, norm2(sites(1)%direction - bis) <= thr, 'bisector')
   end subroutine test_rotated

   !> No corner: a convex (90 degree) corner, points on a circle (a hole's boundary,
   !> normals as far apart as at a corner), a corner whose faces are loaded, one face,
   !> an apex outside the element's box.
   subroutine test_no_corner(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_site_type), allocatable :: sites(:)
      real(wp) :: x(2, 8), n(2, 8), lo(2, 1), hi(2, 1), t
      logical :: free(8)
      integer :: i

      lo = reshape([-0.5_wp, -0.5_wp], [2, 1])
      hi = reshape([0.5_wp, 0.5_wp], [2, 1])
      free = .true.
      ! convex: faces along -x (normal +y) and -y (normal +x) from the box corner (0, 0)
      call two_faces([0.0_wp, 0.0_wp], [-1.0_wp, 0.0_wp], [0.0_wp, 1.0_wp], [0.0_wp, -1.0_wp], [1.0_wp, 0.0_wp], x, n)
      call find_corners(x, n, [1, 9], free, lo, hi, sites)
      call check(error, size(sites), 0, 'convex corner')
      if (allocated(error)) return
      ! a hole of radius 0.4 about (0.4, 0.4): normals into the hole, 90 degrees of arc
      do i = 1, 8
         t = pi + 0.5_wp*pi*(i - 1)/7.0_wp
         x(:, i) = [0.4_wp, 0.4_wp] + 0.4_wp*[cos(t), sin(t)]
         n(:, i) = -[cos(t), sin(t)]
      end do
      call find_corners(x, n, [1, 9], free, lo, hi, sites)
      call check(error, size(sites), 0, 'circle')
      if (allocated(error)) return
      ! the L-shape's notch with one loaded point
      call two_faces([0.0_wp, 0.0_wp], [1.0_wp, 0.0_wp], [0.0_wp, -1.0_wp], [0.0_wp, -1.0_wp], [1.0_wp, 0.0_wp], x, n)
      free(3) = .false.
      call find_corners(x, n, [1, 9], free, lo, hi, sites)
      call check(error, size(sites), 0, 'loaded face')
      if (allocated(error)) return
      free = .true.
      call find_corners(x(:, 1:4), n(:, 1:4), [1, 5], free(1:4), lo, hi, sites)
      call check(error, size(sites), 0, 'one face')
      if (allocated(error)) return
      ! the same notch, its apex outside the element's box
      call find_corners(x, n, [1, 9], free, reshape([0.01_wp, -0.5_wp], [2, 1]), hi, sites)
      call check(error, size(sites), 0, 'apex outside the element')
   end subroutine test_no_corner

   !> Data that are exactly A1 S1 + A2 S2 plus a linear smooth part on a ring of
   !> elements about the apex of a 270-degree notch: the fit returns A1, A2 and
   !> reproduces the smooth part. Plane strain and plane stress, degree 1 and 2.
   !> The tolerance: the normal equations square the condition of the least
   !> squares (scaled columns, at most about 1e4 here), so sqrt(eps) tier.
   subroutine test_fit(error)
      type(error_type), allocatable, intent(out) :: error
      type(corner_site_type) :: site
      type(corner_type) :: field
      type(singular_fit_type) :: fit
      type(error_type), allocatable :: err
      real(wp), allocatable :: x(:, :), w(:), stress(:, :), lo(:, :), hi(:, :)
      integer, allocatable :: ptr(:)
      real(wp) :: s(3), sm(3), gx(2), h
      integer :: i, j, k, deg, an, m
      logical :: ok

      site%point = [0.03_wp, -0.02_wp]
      site%direction = [-1.0_wp, 1.0_wp]/sqrt(2.0_wp)
      site%angle = 270.0_wp
      site%width = 0.1_wp
      h = 0.1_wp
      do an = 1, 2
         call new_corner(field, site%point, site%direction, 270.0_wp, 0.7_wp, -0.3_wp, 1000.0_wp, 0.3_wp, &
            & merge(plane_strain, plane_stress, an == 1), err)
         if (allocated(err)) then
            call check(error, .false., 'new_corner: '//err%message)
            return
         end if
         ! elements of width h on a 12 x 12 grid about the apex, those of the material only
         allocate (x(2, 0), w(0), stress(3, 0), lo(2, 0), hi(2, 0), ptr(1))
         ptr(1) = 1
         do i = -6, 5
            do j = -6, 5
               if (i >= 0 .and. j < 0) cycle
               lo = reshape([lo, [i*h, j*h] + site%point], [2, size(lo, 2) + 1])
               hi = reshape([hi, [(i + 1)*h, (j + 1)*h] + site%point], [2, size(hi, 2) + 1])
               do k = 1, 4
                  gx = site%point + [(i + merge(0.25_wp, 0.75_wp, k <= 2))*h, (j + merge(0.25_wp, 0.75_wp, mod(k, 2) == 1))*h]
                  call field%stress(gx, s)
                  sm = [2.0_wp + 3.0_wp*gx(1), -1.0_wp + gx(2), 0.5_wp - gx(1) + 2.0_wp*gx(2)]
                  x = reshape([x, gx], [2, size(x, 2) + 1])
                  w = [w, 0.25_wp*h*h]
                  stress = reshape([stress, s + sm], [3, size(stress, 2) + 1])
               end do
               ptr = [ptr, size(w) + 1]
            end do
         end do
         do deg = 1, 2
            call fit_corner(site, merge(plane_strain, plane_stress, an == 1), 1000.0_wp, 0.3_wp, x, w, stress, ptr, &
               & lo, hi, deg, fit, ok)
            call check(error, ok, 'fit done')
            if (allocated(error)) return
            call check(error, fit%corner%amplitude(1), 0.7_wp, sqrt(epsilon(1.0_wp)), 'A1')
            if (allocated(error)) return
            call check(error, fit%corner%amplitude(2), -0.3_wp, sqrt(epsilon(1.0_wp)), 'A2')
            if (allocated(error)) return
            gx = site%point + [-0.25_wp, 0.15_wp]
            call fit%smooth_stress(gx, s)
            sm = [2.0_wp + 3.0_wp*gx(1), -1.0_wp + gx(2), 0.5_wp - gx(1) + 2.0_wp*gx(2)]
            m = maxloc(abs(s - sm), 1)
            call check(error, s(m), sm(m), 4.0_wp*sqrt(epsilon(1.0_wp)), 'smooth part')
            if (allocated(error)) return
         end do
         deallocate (x, w, stress, lo, hi, ptr)
      end do
   end subroutine test_fit

   function str(v) result(s)
      real(wp), intent(in) :: v(:)
      character(len=:), allocatable :: s
      character(len=64) :: buf
      write (buf, '(2es14.6)') v
      s = trim(buf)
   end function str

end module sprc_test_singular
