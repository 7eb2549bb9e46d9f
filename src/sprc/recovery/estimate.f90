!> Evaluation of recovered patch polynomials, the polynomial-union field of an
!> element (thesis eq. 102) and the Zienkiewicz-Zhu element error integral (eq. 1).
!> Mesh-agnostic: the caller supplies points, shape-function values and weights.
!> All procedures are pure and allocate nothing.
module sprc_recovery_estimate
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: voigt_size, compliance_matrix
   use sprc_core_poly, only: poly_exponents_2d, poly_exponents_3d, poly_max_degree, poly_max_terms
   use sprc_recovery_patch, only: recovered_patch_type
   use sprc_recovery_contact_edge, only: edge_stress
   implicit none
   private

   public :: eval_recovered, eval_recovered_unchecked, eval_recovered_points, eval_union, zz_error_integral, zz_error_norm, &
      & energy_norms
   public :: scaled_norm, relative_error

contains

   !> sigma*(x) = P((x - x0)/h) A of one recovered patch; sigma(1:nstress) is written.
   pure subroutine eval_recovered(rec, x, sigma, error)
      type(recovered_patch_type), intent(in) :: rec
      !> Physical point x(1:dim).
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      type(error_type), allocatable, intent(out) :: error

      call check_rec(rec, size(x), size(sigma), 'eval_recovered', error)
      if (allocated(error)) return
      call eval_recovered_unchecked(rec, x, sigma)
   end subroutine eval_recovered

   !> `eval_recovered` without its checks, for a producer's own patches from successful
   !> solves (x(1:dim), sigma(1:nstress)).
   pure subroutine eval_recovered_unchecked(rec, x, sigma)
      type(recovered_patch_type), intent(in) :: rec
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      real(wp) :: xp(3, 1), s(6, 1)

      xp(1:rec%dim, 1) = x(1:rec%dim)
      call eval_recovered_points(rec, xp(1:rec%dim, :), s)
      sigma(1:rec%nstress) = s(1:rec%nstress, 1)
   end subroutine eval_recovered_unchecked

   !> `eval_recovered_unchecked` at the points x(1:dim, i) into sigma(1:nstress, i): one call
   !> per element instead of per point.
   pure subroutine eval_recovered_points(rec, x, sigma)
      type(recovered_patch_type), intent(in) :: rec
      real(wp), intent(in) :: x(:, :)
      real(wp), intent(inout) :: sigma(:, :)

      real(wp) :: se(3)
      integer :: i

      call eval_points(rec, rec%nterms, rec%nstress, rec%coef, x, sigma)
      if (rec%edge_amplitude == 0.0_wp) return
      do i = 1, size(x, 2)
         call edge_stress(rec%edge_point, rec%edge_tangent, rec%edge_normal, rec%edge_amplitude, x(1:2, i), se)
         sigma(1:3, i) = sigma(1:3, i) + se
      end do
   end subroutine eval_recovered_points

   !> The kernel of `eval_recovered_points`, with the coefficients coef(nt, ns) of explicit
   !> shape. Each component one sum over the terms in term order, from zero.
   pure subroutine eval_points(rec, nt, ns, coef, x, sigma)
      type(recovered_patch_type), intent(in) :: rec
      integer, intent(in) :: nt, ns
      real(wp), intent(in) :: coef(nt, ns), x(:, :)
      real(wp), intent(inout) :: sigma(:, :)
      real(wp) :: p(poly_max_terms), acc, s1, s2, s3
      integer :: i, c, t

      do i = 1, size(x, 2)
         if (rec%degree == 1) then
            ! Terms 1, s_1, .., s_dim (the values term_values gives: products with ones), in
            ! scalars: stored to p(:) and loaded in pairs they stalled on store forwarding (perf).
            s1 = (x(1, i) - rec%x0(1))/rec%h
            s2 = (x(2, i) - rec%x0(2))/rec%h
            s3 = 0.0_wp
            if (rec%dim == 3) s3 = (x(3, i) - rec%x0(3))/rec%h
            do c = 1, ns
               acc = 0.0_wp + 1.0_wp*coef(1, c)
               acc = acc + s1*coef(2, c)
               acc = acc + s2*coef(3, c)
               if (nt == 4) acc = acc + s3*coef(4, c)
               sigma(c, i) = acc
            end do
            cycle
         end if
         call term_values(rec, x(:, i), p)
         do c = 1, ns
            acc = 0.0_wp
            do t = 1, nt
               acc = acc + p(t)*coef(t, c)
            end do
            sigma(c, i) = acc
         end do
      end do
   end subroutine eval_points

   !> The terms p(1:nterms) of rec's basis at x: powers of each scaled coordinate once (s**e
   !> is a call per term), each term as s(1)**e(1) * s(2)**e(2) * s(3)**e(3) in that order.
   pure subroutine term_values(rec, x, p)
      type(recovered_patch_type), intent(in) :: rec
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: p(:)
      real(wp) :: s, pw(0:poly_max_degree, 3)
      integer :: i, k, e(3)

      pw = 1.0_wp
      do k = 1, rec%dim
         s = (x(k) - rec%x0(k))/rec%h
         pw(1, k) = s
         pw(2, k) = s*s
         pw(3, k) = pw(2, k)*s
      end do
      do i = 1, rec%nterms
         if (rec%dim == 2) then
            e = poly_exponents_2d(:, i)
         else
            e = poly_exponents_3d(:, i)
         end if
         p(i) = pw(e(1), 1)*pw(e(2), 2)*pw(e(3), 3)
      end do
   end subroutine term_values

   pure subroutine check_rec(rec, nx, nsig, context, error)
      type(recovered_patch_type), intent(in) :: rec
      integer, intent(in) :: nx, nsig
      character(len=*), intent(in) :: context
      type(error_type), allocatable, intent(out) :: error
      character(len=96) :: buf

      if ((rec%dim /= 2 .and. rec%dim /= 3) .or. rec%nterms < 1 .or. rec%nstress < 3 .or. &
         & .not. (rec%h > 0.0_wp)) then
         call fatal_error(error, context//': recovered patch is empty (not produced by a successful solve)', &
            & stat_invalid_input)
      else if (nx < rec%dim .or. nsig < rec%nstress) then
         write (buf, '("x has ",i0," entries (need ",i0,"), sigma ",i0," (need ",i0,")")') nx, rec%dim, nsig, &
            & rec%nstress
         call fatal_error(error, context//': '//trim(buf), stat_invalid_input)
      end if
   end subroutine check_rec

   !> Polynomial union (thesis eq. 102) at a point x of an element:
   !> sigma*(x) = sum_J shape_values(J) sigma*_J(x), with sigma*_J the recovered polynomial of
   !> the patch of the element's vertex J and shape_values(J) = N_J(x) its (linear) shape
   !> function at x. The nodal interpolation (eq. 101) is the same sum with each sigma*_J
   !> evaluated at its own node; the producer does that from `eval_recovered`.
   pure subroutine eval_union(recs, shape_values, x, sigma, error)
      type(recovered_patch_type), intent(in) :: recs(:)
      real(wp), intent(in) :: shape_values(:)
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sigma(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: sj(6)
      integer :: j, ns
      character(len=80) :: buf

      if (size(recs) /= size(shape_values) .or. size(recs) < 1) then
         write (buf, '(i0," patches and ",i0," shape-function values")') size(recs), size(shape_values)
         call fatal_error(error, 'eval_union: '//trim(buf)//' (need the same, >= 1)', stat_invalid_input)
         return
      end if
      do j = 1, size(recs)
         call check_rec(recs(j), size(x), size(sigma), 'eval_union', error)
         if (allocated(error)) return
         if (recs(j)%dim /= recs(1)%dim) then
            call fatal_error(error, 'eval_union: patches of different dimensions', stat_invalid_input)
            return
         end if
      end do
      if (.not. all(abs(shape_values) <= huge(1.0_wp))) then
         call fatal_error(error, 'eval_union: shape_values are not finite', stat_invalid_input)
         return
      end if
      ns = recs(1)%nstress
      sigma(1:ns) = 0.0_wp
      do j = 1, size(recs)
         call eval_recovered_unchecked(recs(j), x, sj)
         sigma(1:ns) = sigma(1:ns) + shape_values(j)*sj(1:ns)
      end do
   end subroutine eval_union

   !> ZZ error integral of one element: err2 = sum_i w_i (s*_i - s_h,i)^T D^-1 (s*_i - s_h,i),
   !> the square of the energy norm of the estimated error (thesis eq. 1), with w_i = weight*|J|
   !> and D^-1 the closed-form compliance of `analysis`. Overflows where the squared norm
   !> does (stresses ~1e154 and more): `zz_error_norm` does not.
   pure subroutine zz_error_integral(analysis, young, poisson, w, sigma_star, sigma_h, err2, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      !> Quadrature weights times |J|, w(npoints) >= 0.
      real(wp), intent(in) :: w(:)
      !> Recovered and FE stresses, Voigt, (nstress, npoints).
      real(wp), intent(in) :: sigma_star(:, :), sigma_h(:, :)
      real(wp), intent(out) :: err2
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: s, ssq

      call scaled_integral(analysis, young, poisson, w, sigma_star, sigma_h, s, ssq, error)
      err2 = ssq*s*s
   end subroutine zz_error_integral

   !> The energy norm err = sqrt(err2) of `zz_error_integral`, computed without overflow for
   !> any finite stresses (stresses ~1e160 would overflow to NaN): the differences are scaled
   !> by a power of two before squaring, so the result has the same bits as sqrt(err2)
   !> wherever err2 does not overflow or underflow.
   pure subroutine zz_error_norm(analysis, young, poisson, w, sigma_star, sigma_h, err, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      real(wp), intent(in) :: w(:)
      real(wp), intent(in) :: sigma_star(:, :), sigma_h(:, :)
      real(wp), intent(out) :: err
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: s, ssq

      call scaled_integral(analysis, young, poisson, w, sigma_star, sigma_h, s, ssq, error)
      err = s*sqrt(ssq)
   end subroutine zz_error_norm

   !> err2 = s**2 * ssq with s a power of two near the largest stress difference (1 if all
   !> differences vanish): scaling by a power of two is exact, squaring cannot overflow.
   pure subroutine scaled_integral(analysis, young, poisson, w, sigma_star, sigma_h, s, ssq, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      real(wp), intent(in) :: w(:)
      real(wp), intent(in) :: sigma_star(:, :), sigma_h(:, :)
      real(wp), intent(out) :: s, ssq
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: cmat(6, 6), diff(6)
      integer :: i, ns
      character(len=96) :: buf

      s = 1.0_wp
      ssq = 0.0_wp
      ns = voigt_size(analysis)
      if (ns > 0) then
         call compliance_matrix(analysis, young, poisson, cmat(1:ns, 1:ns), error)
      else
         call compliance_matrix(analysis, young, poisson, cmat(1:3, 1:3), error)
      end if
      if (allocated(error)) then
         error%message = 'zz_error_integral: '//error%message
         return
      end if
      if (size(sigma_star, 1) /= ns .or. size(sigma_h, 1) /= ns .or. size(sigma_star, 2) /= size(w) .or. &
         & size(sigma_h, 2) /= size(w)) then
         write (buf, '("shapes w(",i0,"), sigma_star(",i0,",",i0,"), sigma_h(",i0,",",i0,"); nstress = ",i0)') &
            & size(w), shape(sigma_star), shape(sigma_h), ns
         call fatal_error(error, 'zz_error_integral: '//trim(buf), stat_invalid_input)
         return
      end if
      do i = 1, size(w)
         if (.not. (w(i) >= 0.0_wp .and. w(i) <= huge(1.0_wp))) then
            write (buf, '("w(",i0,") = ",es12.4," must be finite and >= 0")') i, w(i)
            call fatal_error(error, 'zz_error_integral: '//trim(buf), stat_invalid_input)
            return
         end if
         diff(1:ns) = sigma_star(:, i) - sigma_h(:, i)
         if (.not. all(abs(diff(1:ns)) <= huge(1.0_wp))) then
            write (buf, '("stresses at point ",i0," are not finite")') i
            call fatal_error(error, 'zz_error_integral: '//trim(buf), stat_invalid_input)
            return
         end if
      end do
      block
         real(wp) :: c(ns, ns)
         c = cmat(1:ns, 1:ns)
         call scaled_sum(ns, size(w), c, ns, w, sigma_star, sigma_h, .true., s, ssq)
      end block
   end subroutine scaled_integral

   !> Both energy norms of one element for a validated caller (finite stresses, weights
   !> >= 0) and its compliance cmat(nstress, nstress): err = ||s* - s_h||, norm_h = ||s_h||,
   !> the bits of `zz_error_norm` (of s* and of a zero s*) without its checks and set-up.
   !> When neither needs scaling (`scaled_sum`'s test) both sums are formed in one pass
   !> with scale 1, as scaled_sum forms them then.
   pure subroutine energy_norms(cmat, w, sigma_star, sigma_h, err, norm_h)
      real(wp), intent(in), contiguous :: cmat(:, :), w(:), sigma_star(:, :), sigma_h(:, :)
      real(wp), intent(out) :: err, norm_h
      real(wp) :: s, ssq, ssq_h

      if (size(cmat, 1) == 3 .and. unscaled(size(w), sigma_star, sigma_h)) then
         call accumulate3_both(size(w), cmat, w, sigma_star, sigma_h, ssq, ssq_h)
         err = sqrt(ssq)
         norm_h = sqrt(ssq_h)
         return
      end if
      call scaled_sum(size(cmat, 1), size(w), cmat, size(cmat, 1), w, sigma_star, sigma_h, .true., s, ssq)
      err = s*sqrt(ssq)
      call scaled_sum(size(cmat, 1), size(w), cmat, size(cmat, 1), w, sigma_h, sigma_h, .false., s, ssq)
      norm_h = s*sqrt(ssq)
   end subroutine energy_norms

   !> True if scaled_sum would take s = 1 for both the differences a - b and b (2D stresses).
   pure logical function unscaled(n, a, b)
      integer, intent(in) :: n
      real(wp), intent(in) :: a(3, n), b(3, n)
      real(wp), parameter :: safe_hi = 2.0_wp**200, safe_lo = 2.0_wp**(-200)
      real(wp) :: d, h
      integer :: i, j

      unscaled = .false.
      do i = 1, n
         do j = 1, 3
            d = abs(a(j, i) - b(j, i))
            h = abs(b(j, i))
            if (.not. (d <= safe_hi .and. h <= safe_hi)) return
            if ((d > 0.0_wp .and. d < safe_lo) .or. (h > 0.0_wp .and. h < safe_lo)) return
         end do
      end do
      unscaled = .true.
   end function unscaled

   !> `accumulate3` of the differences a - b and of b (with a = 0) at once, scale 1: the same
   !> products and sums per quantity, in the same order.
   pure subroutine accumulate3_both(n, c, w, a, b, ssq, ssq_h)
      integer, intent(in) :: n
      real(wp), intent(in) :: c(3, 3), w(n), a(3, n), b(3, n)
      real(wp), intent(out) :: ssq, ssq_h
      real(wp) :: d1, d2, d3, q
      integer :: i

      ssq = 0.0_wp
      ssq_h = 0.0_wp
      do i = 1, n
         d1 = (a(1, i) - b(1, i))*1.0_wp
         d2 = (a(2, i) - b(2, i))*1.0_wp
         d3 = (a(3, i) - b(3, i))*1.0_wp
         q = ((d1*((c(1, 1)*d1 + c(1, 2)*d2) + c(1, 3)*d3) + d2*((c(2, 1)*d1 + c(2, 2)*d2) + c(2, 3)*d3)) + &
            & d3*((c(3, 1)*d1 + c(3, 2)*d2) + c(3, 3)*d3))
         ssq = ssq + w(i)*q
         d1 = (0.0_wp - b(1, i))*1.0_wp
         d2 = (0.0_wp - b(2, i))*1.0_wp
         d3 = (0.0_wp - b(3, i))*1.0_wp
         q = ((d1*((c(1, 1)*d1 + c(1, 2)*d2) + c(1, 3)*d3) + d2*((c(2, 1)*d1 + c(2, 2)*d2) + c(2, 3)*d3)) + &
            & d3*((c(3, 1)*d1 + c(3, 2)*d2) + c(3, 3)*d3))
         ssq_h = ssq_h + w(i)*q
      end do
   end subroutine accumulate3_both

   !> ssq = sum_i w_i d_i^T cmat d_i / s**2, d_i = a_i - b_i (a = 0 if not use_a), s the power
   !> of two of the largest |d| (`power_of_two`), or s = 1 where every nonzero |d| lies
   !> within 2**(+-200) (squares far from overflow and underflow): scaling by a power of two
   !> is exact, so the final norm s sqrt(ssq) has the same bits either way, and the common
   !> case saves the divisions. The products are those of dot_product(d, matmul(cmat, d)).
   pure subroutine scaled_sum(ns, n, cmat, ldc, w, a, b, use_a, s, ssq)
      integer, intent(in) :: ns, n, ldc
      !> The compliance in cmat(1:ns, 1:ns) of an array with leading dimension ldc.
      real(wp), intent(in) :: cmat(ldc, ns), w(n), a(ns, n), b(ns, n)
      logical, intent(in) :: use_a
      real(wp), intent(out) :: s, ssq
      real(wp), parameter :: safe_hi = 2.0_wp**200, safe_lo = 2.0_wp**(-200)
      real(wp) :: big, small, d
      integer :: i, j

      big = 0.0_wp
      small = huge(1.0_wp)
      do i = 1, n
         do j = 1, ns
            if (use_a) then
               d = abs(a(j, i) - b(j, i))
            else
               d = abs(b(j, i))
            end if
            big = max(big, d)
            small = min(small, merge(d, huge(1.0_wp), d > 0.0_wp))
         end do
      end do
      s = 1.0_wp
      if (.not. (big <= safe_hi .and. (small >= safe_lo .or. big == 0.0_wp))) s = power_of_two(big)
      call accumulate(ns, n, cmat, ldc, w, a, b, use_a, 1.0_wp/s, ssq)
   end subroutine scaled_sum

   !> sum_i w_i d_i^T cmat d_i with d_i = (a_i - b_i) scale (a = 0 if not use_a).
   pure subroutine accumulate(ns, n, cmat, ldc, w, a, b, use_a, scale, ssq)
      integer, intent(in) :: ns, n, ldc
      real(wp), intent(in) :: cmat(ldc, ns), w(n), a(ns, n), b(ns, n), scale
      logical, intent(in) :: use_a
      real(wp), intent(out) :: ssq
      real(wp) :: d(6), cd(6), q
      integer :: i, j, k

      ssq = 0.0_wp
      if (ns == 3) then
         call accumulate3(n, cmat, ldc, w, a, b, use_a, scale, ssq)
         return
      end if
      if (ns == 6) then
         call accumulate6(n, cmat, ldc, w, a, b, use_a, scale, ssq)
         return
      end if
      do i = 1, n
         do j = 1, ns
            if (use_a) then
               d(j) = (a(j, i) - b(j, i))*scale
            else
               d(j) = (0.0_wp - b(j, i))*scale
            end if
         end do
         cd(1:ns) = 0.0_wp
         do k = 1, ns
            do j = 1, ns
               cd(j) = cd(j) + cmat(j, k)*d(k)
            end do
         end do
         q = 0.0_wp
         do j = 1, ns
            q = q + d(j)*cd(j)
         end do
         ssq = ssq + w(i)*q
      end do
   end subroutine accumulate

   !> `accumulate` for 2D stresses, written out (the estimate's inner loop); the products
   !> and sums in the same order, so the same bits.
   pure subroutine accumulate3(n, c, ldc, w, a, b, use_a, scale, ssq)
      integer, intent(in) :: n, ldc
      real(wp), intent(in) :: c(ldc, 3), w(n), a(3, n), b(3, n), scale
      logical, intent(in) :: use_a
      real(wp), intent(inout) :: ssq
      real(wp) :: d1, d2, d3, q
      integer :: i

      do i = 1, n
         if (use_a) then
            d1 = (a(1, i) - b(1, i))*scale
            d2 = (a(2, i) - b(2, i))*scale
            d3 = (a(3, i) - b(3, i))*scale
         else
            d1 = (0.0_wp - b(1, i))*scale
            d2 = (0.0_wp - b(2, i))*scale
            d3 = (0.0_wp - b(3, i))*scale
         end if
         q = ((d1*((c(1, 1)*d1 + c(1, 2)*d2) + c(1, 3)*d3) + d2*((c(2, 1)*d1 + c(2, 2)*d2) + c(2, 3)*d3)) + &
            & d3*((c(3, 1)*d1 + c(3, 2)*d2) + c(3, 3)*d3))
         ssq = ssq + w(i)*q
      end do
   end subroutine accumulate3

   !> `accumulate` for 3D stresses with fixed bounds (the same products and sums in the same
   !> order, so the same bits).
   pure subroutine accumulate6(n, c, ldc, w, a, b, use_a, scale, ssq)
      integer, intent(in) :: n, ldc
      real(wp), intent(in) :: c(ldc, 6), w(n), a(6, n), b(6, n), scale
      logical, intent(in) :: use_a
      real(wp), intent(inout) :: ssq
      real(wp) :: d(6), cd(6), q
      integer :: i, j, k

      do i = 1, n
         if (use_a) then
            d = (a(:, i) - b(:, i))*scale
         else
            d = (0.0_wp - b(:, i))*scale
         end if
         cd = 0.0_wp
         do k = 1, 6
            do j = 1, 6
               cd(j) = cd(j) + c(j, k)*d(k)
            end do
         end do
         q = 0.0_wp
         do j = 1, 6
            q = q + d(j)*cd(j)
         end do
         ssq = ssq + w(i)*q
      end do
   end subroutine accumulate6

   !> sqrt(sum(v**2)) without overflow or underflow; the same bits as that expression
   !> wherever it neither overflows nor underflows (scaling by a power of two).
   pure real(wp) function scaled_norm(v) result(r)
      real(wp), intent(in) :: v(:)
      real(wp) :: s
      s = power_of_two(maxval(abs(v), mask=abs(v) <= huge(1.0_wp)))
      r = s*sqrt(sum((v/s)**2))
   end function scaled_norm

   !> err / sqrt(norm**2 + err**2) (0 if both vanish) without overflow, same bits as that
   !> expression where it does not overflow.
   pure real(wp) function relative_error(err, norm) result(eta)
      real(wp), intent(in) :: err, norm
      real(wp) :: s
      eta = 0.0_wp
      s = power_of_two(max(abs(err), abs(norm)))
      if ((norm/s)**2 + (err/s)**2 > 0.0_wp) eta = (err/s)/sqrt((norm/s)**2 + (err/s)**2)
   end function relative_error

   !> A power of two s with s <= x < 2 s for finite x > 0; 1 otherwise.
   elemental real(wp) function power_of_two(x) result(s)
      real(wp), intent(in) :: x
      s = 1.0_wp
      if (x > 0.0_wp .and. x <= huge(1.0_wp)) s = set_exponent(1.0_wp, exponent(x))
   end function power_of_two

end module sprc_recovery_estimate
