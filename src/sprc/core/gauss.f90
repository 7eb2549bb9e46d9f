!> Gauss-Legendre quadrature: 1D nodes and weights on [-1, 1] and tensor
!> rules on axis-aligned boxes in 2D and 3D.
!>
!> Nodes come from Newton's method on the Legendre polynomial P_n (three-term
!> recurrence), started from the Tricomi-type guess cos(pi (i - 1/4)/(n + 1/2))
!> and iterated until the correction is below a few ulps; weights are
!> 2/((1 - x^2) P_n'(x)^2). For n <= max_gauss_points this reaches full double
!> precision (the test compares with closed forms and checks exactness on
!> monomials of degree <= 2n - 1).
module sprc_core_gauss
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   implicit none
   private

   public :: max_gauss_points, gauss_legendre, gauss_legendre_nodes, tensor_gauss

   !> Largest number of points per direction accepted.
   integer, parameter :: max_gauss_points = 20

contains

   !> The n-point Gauss-Legendre rule on [-1, 1]: x(1:n) ascending, w(1:n) > 0.
   !> Errors: n outside [1, max_gauss_points], x or w shorter than n.
   pure subroutine gauss_legendre(n, x, w, error)
      integer, intent(in) :: n
      real(wp), intent(out) :: x(:), w(:)
      type(error_type), allocatable, intent(out) :: error

      if (n < 1 .or. n > max_gauss_points) then
         call fatal_error(error, 'gauss_legendre: n = '//itoa(n)//' points, expected 1 to '// &
            & itoa(max_gauss_points), stat_invalid_input)
         return
      end if
      if (size(x) < n .or. size(w) < n) then
         call fatal_error(error, 'gauss_legendre: x and w need '//itoa(n)//' entries, got '// &
            & itoa(min(size(x), size(w))), stat_invalid_input)
         return
      end if
      call gauss_legendre_nodes(n, x, w)
   end subroutine gauss_legendre

   !> Unchecked kernel of `gauss_legendre` (1 <= n <= max_gauss_points, size(x), size(w) >= n).
   pure subroutine gauss_legendre_nodes(n, x, w)
      integer, intent(in) :: n
      real(wp), intent(out) :: x(:), w(:)
      real(wp), parameter :: pi = 3.14159265358979323846264338327950288_wp
      real(wp) :: z, dz, p, dp
      integer :: i, iter

      do i = 1, (n + 1)/2
         z = cos(pi*(real(i, wp) - 0.25_wp)/(real(n, wp) + 0.5_wp))
         do iter = 1, 100
            call legendre(n, z, p, dp)
            dz = p/dp
            z = z - dz
            if (abs(dz) <= 2.0_wp*epsilon(1.0_wp)) exit
         end do
         ! one more step at the converged point: the weight uses the final P_n'
         call legendre(n, z, p, dp)
         x(i) = -z
         x(n + 1 - i) = z
         w(i) = 2.0_wp/((1.0_wp - z*z)*dp*dp)
         w(n + 1 - i) = w(i)
      end do
      if (mod(n, 2) == 1) x((n + 1)/2) = 0.0_wp
   end subroutine gauss_legendre_nodes

   !> P_n(z) and P_n'(z) by the three-term recurrence.
   pure subroutine legendre(n, z, p, dp)
      integer, intent(in) :: n
      real(wp), intent(in) :: z
      real(wp), intent(out) :: p, dp
      real(wp) :: p0, p1
      integer :: k

      p0 = 1.0_wp
      p1 = z
      if (n == 0) then
         p = 1.0_wp
         dp = 0.0_wp
         return
      end if
      do k = 2, n
         p = (real(2*k - 1, wp)*z*p1 - real(k - 1, wp)*p0)/real(k, wp)
         p0 = p1
         p1 = p
      end do
      p = p1
      dp = real(n, wp)*(z*p1 - p0)/(z*z - 1.0_wp)
   end subroutine legendre

   !> Tensor n^dim-point Gauss rule on the box [lo, hi] (dim = size(lo), 1 to 3):
   !> points x(1:dim, 1:n**dim), weights w(1:n**dim) (the box volume times the
   !> reference weights), first coordinate fastest. Errors: bad n, dim not
   !> 1..3, size(hi) /= dim, lo > hi, x or w too small.
   pure subroutine tensor_gauss(n, lo, hi, x, w, error)
      integer, intent(in) :: n
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp), intent(out) :: x(:, :), w(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: t(max_gauss_points), tw(max_gauss_points), half(3), mid(3)
      integer :: dim, npt, ipt, idx(3), d, i

      dim = size(lo)
      if (dim < 1 .or. dim > 3 .or. size(hi) /= dim) then
         call fatal_error(error, 'tensor_gauss: lo and hi must have the same size 1 to 3, got '// &
            & itoa(size(lo))//' and '//itoa(size(hi)), stat_invalid_input)
         return
      end if
      do d = 1, dim
         if (.not. lo(d) <= hi(d)) then
            call fatal_error(error, 'tensor_gauss: lo('//itoa(d)//') > hi('//itoa(d)//')', &
               & stat_invalid_input)
            return
         end if
      end do
      call gauss_legendre(n, t, tw, error)
      if (allocated(error)) return
      npt = n**dim
      if (size(x, 1) < dim .or. size(x, 2) < npt .or. size(w) < npt) then
         call fatal_error(error, 'tensor_gauss: x needs shape ('//itoa(dim)//', '//itoa(npt)// &
            & ') and w size '//itoa(npt), stat_invalid_input)
         return
      end if
      half(1:dim) = 0.5_wp*(hi - lo)
      mid(1:dim) = 0.5_wp*(hi + lo)
      do ipt = 1, npt
         i = ipt - 1
         do d = 1, dim
            idx(d) = mod(i, n) + 1
            i = i/n
         end do
         w(ipt) = 1.0_wp
         do d = 1, dim
            x(d, ipt) = mid(d) + half(d)*t(idx(d))
            w(ipt) = w(ipt)*half(d)*tw(idx(d))
         end do
      end do
   end subroutine tensor_gauss

end module sprc_core_gauss
