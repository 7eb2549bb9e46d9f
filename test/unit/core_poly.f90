!> Tests of sprc_core_poly: term counts, the fixed monomial order, values at a
!> hand-computed point, derivatives against finite differences, the exact
!> differentiation matrices, reproduction of random polynomials by least
!> squares, physical scaling and the error paths.
module sprc_test_poly
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: stat_invalid_input
   use sprc_core_lapack, only: dgelsd
   use sprc_core_poly, only: poly_basis_type, new_poly_basis, poly_nterms, scale_point, scale_points, &
      & poly_max_degree, poly_max_terms, poly_exponents_2d, poly_exponents_3d, poly_hess_pairs_2d, &
      & poly_hess_pairs_3d
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_poly

   !> Hand-written 2D table, one line per term (a, b) of x^a y^b: 1, x, y, x2, xy, y2, x3, x2y, xy2, y3.
   integer, parameter :: table_2d(2, 10) = reshape([ &
      & 0, 0, &
      & 1, 0, &
      & 0, 1, &
      & 2, 0, &
      & 1, 1, &
      & 0, 2, &
      & 3, 0, &
      & 2, 1, &
      & 1, 2, &
      & 0, 3], [2, 10])

   !> Hand-written 3D table, one line per term (a, b, c):
   !> 1, x, y, z, x2, xy, xz, y2, yz, z2, x3, x2y, x2z, xy2, xyz, xz2, y3, y2z, yz2, z3.
   integer, parameter :: table_3d(3, 20) = reshape([ &
      & 0, 0, 0, &
      & 1, 0, 0, &
      & 0, 1, 0, &
      & 0, 0, 1, &
      & 2, 0, 0, &
      & 1, 1, 0, &
      & 1, 0, 1, &
      & 0, 2, 0, &
      & 0, 1, 1, &
      & 0, 0, 2, &
      & 3, 0, 0, &
      & 2, 1, 0, &
      & 2, 0, 1, &
      & 1, 2, 0, &
      & 1, 1, 1, &
      & 1, 0, 2, &
      & 0, 3, 0, &
      & 0, 2, 1, &
      & 0, 1, 2, &
      & 0, 0, 3], [3, 20])

contains

   subroutine collect_poly(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('nterms', test_nterms), &
         new_unittest('exponents_2d_table', test_exponents_2d), &
         new_unittest('exponents_3d_table', test_exponents_3d), &
         new_unittest('lower_degrees_are_prefixes', test_prefix), &
         new_unittest('term_index', test_term_index), &
         new_unittest('eval_hand_point', test_eval_hand), &
         new_unittest('grad_vs_fd', test_grad_fd), &
         new_unittest('hess_vs_fd', test_hess_fd), &
         new_unittest('dmat_consistent_with_grad', test_dmat_grad), &
         new_unittest('dmat_commute_and_hess', test_dmat_commute), &
         new_unittest('dmat_nilpotent', test_dmat_nilpotent), &
         new_unittest('eval_points_matches_eval', test_eval_points), &
         new_unittest('least_squares_reproduction', test_reproduction), &
         new_unittest('physical_scaling', test_scaling), &
         new_unittest('constructor_errors', test_constructor_errors), &
         new_unittest('dmat_errors', test_dmat_errors) &
         ]
   end subroutine collect_poly

   !> Fixed seed so that the "random" points and coefficients are reproducible.
   subroutine seed_rng()
      integer :: n, i
      integer, allocatable :: seed(:)
      call random_seed(size=n)
      allocate (seed(n))
      seed = [(104729*i + 7919, i=1, n)]
      call random_seed(put=seed)
   end subroutine seed_rng

   !> Uniform random numbers in [-1, 1].
   subroutine random_sym(x)
      real(wp), intent(out) :: x(:)
      call random_number(x)
      x = 2.0_wp*x - 1.0_wp
   end subroutine random_sym

   subroutine make_basis(dim, degree, basis, error)
      integer, intent(in) :: dim, degree
      type(poly_basis_type), intent(out) :: basis
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      call new_poly_basis(basis, dim, degree, e)
      if (allocated(e)) call test_failed(error, 'new_poly_basis failed: '//e%message)
   end subroutine make_basis

   !> C(degree+dim, dim) written out by hand: 1 3 6 10 (2D), 1 4 10 20 (3D).
   subroutine test_nterms(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n2(0:3) = [1, 3, 6, 10], n3(0:3) = [1, 4, 10, 20]
      type(poly_basis_type) :: basis
      integer :: p

      do p = 0, poly_max_degree
         call check(error, poly_nterms(2, p), n2(p), '2D nterms')
         if (allocated(error)) return
         call check(error, poly_nterms(3, p), n3(p), '3D nterms')
         if (allocated(error)) return
         call make_basis(2, p, basis, error)
         if (allocated(error)) return
         call check(error, basis%nterms == n2(p) .and. basis%nhess == 3 .and. size(basis%exponents, 2) == n2(p) &
            & .and. basis%dim == 2 .and. basis%degree == p, '2D basis fields')
         if (allocated(error)) return
         call make_basis(3, p, basis, error)
         if (allocated(error)) return
         call check(error, basis%nterms == n3(p) .and. basis%nhess == 6 .and. size(basis%exponents, 2) == n3(p) &
            & .and. basis%dim == 3 .and. basis%degree == p, '3D basis fields')
         if (allocated(error)) return
      end do
      call check(error, poly_nterms(1, 1) == 0 .and. poly_nterms(2, 4) == 0 .and. poly_nterms(3, -1) == 0, &
         & 'nterms out of range is 0')
      if (allocated(error)) return
      call check(error, poly_max_terms, n3(3), 'poly_max_terms')
   end subroutine test_nterms

   !> The generated exponents, and the exported table, equal the hand-written table.
   subroutine test_exponents_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: basis

      call make_basis(2, 3, basis, error)
      if (allocated(error)) return
      call check(error, all(basis%exponents(1:2, :) == table_2d) .and. all(basis%exponents(3, :) == 0), &
         & '2D p=3 generated exponents')
      if (allocated(error)) return
      call check(error, all(poly_exponents_2d(1:2, :) == table_2d) .and. all(poly_exponents_2d(3, :) == 0), &
         & 'exported poly_exponents_2d')
   end subroutine test_exponents_2d

   subroutine test_exponents_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: basis

      call make_basis(3, 3, basis, error)
      if (allocated(error)) return
      call check(error, all(basis%exponents == table_3d), '3D p=3 generated exponents')
      if (allocated(error)) return
      call check(error, all(poly_exponents_3d == table_3d), 'exported poly_exponents_3d')
      if (allocated(error)) return
      call check(error, all(poly_hess_pairs_2d == reshape([1, 1, 2, 2, 1, 2], [2, 3])) .and. &
         & all(poly_hess_pairs_3d == reshape([1, 1, 2, 2, 3, 3, 1, 2, 2, 3, 1, 3], [2, 6])), 'Voigt pairs')
   end subroutine test_exponents_3d

   !> The order is graded, so the degree-p basis is the leading block of the degree-3 basis.
   subroutine test_prefix(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: low, high
      integer :: dim, p

      do dim = 2, 3
         call make_basis(dim, 3, high, error)
         if (allocated(error)) return
         do p = 0, 2
            call make_basis(dim, p, low, error)
            if (allocated(error)) return
            call check(error, all(low%exponents == high%exponents(:, 1:low%nterms)), 'degree p is a prefix of degree 3')
            if (allocated(error)) return
            call check(error, all(sum(high%exponents(:, low%nterms + 1:), 1) > p), 'terms after the prefix have degree > p')
            if (allocated(error)) return
         end do
      end do
   end subroutine test_prefix

   !> term_index (computed from the ordering rule) inverts the exponent table; absent terms give 0.
   subroutine test_term_index(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: basis
      integer :: dim, p, i, e(3)

      do dim = 2, 3
         do p = 0, 3
            call make_basis(dim, p, basis, error)
            if (allocated(error)) return
            do i = 1, basis%nterms
               e = basis%exponents(:, i)
               call check(error, basis%term_index(e(1), e(2), e(3)), i, 'term_index of term i')
               if (allocated(error)) return
            end do
         end do
      end do
      call make_basis(2, 2, basis, error)
      if (allocated(error)) return
      call check(error, basis%term_index(1, 1, 0), 5, 'xy is term 5 in 2D')
      if (allocated(error)) return
      call check(error, basis%term_index(2, 1, 0) == 0 .and. basis%term_index(0, 0, 1) == 0 .and. &
         & basis%term_index(-1, 1, 0) == 0, 'absent 2D terms give 0')
      if (allocated(error)) return
      call make_basis(3, 3, basis, error)
      if (allocated(error)) return
      call check(error, basis%term_index(1, 1, 1), 15, 'xyz is term 15 in 3D')
      if (allocated(error)) return
      call check(error, basis%term_index(4, 0, 0) == 0 .and. basis%term_index(0, -1, 2) == 0, 'absent 3D terms give 0')
   end subroutine test_term_index

   !> Values at s = (1/2, -2[, 3]) computed by hand; all are exact binary fractions, so the
   !> comparison is exact.
   subroutine test_eval_hand(error)
      type(error_type), allocatable, intent(out) :: error
      ! 1, x, y, x2, xy, y2, x3, x2y, xy2, y3 at x = 1/2, y = -2
      real(wp), parameter :: ref2(10) = [1.0_wp, 0.5_wp, -2.0_wp, 0.25_wp, -1.0_wp, 4.0_wp, 0.125_wp, -0.5_wp, &
         & 2.0_wp, -8.0_wp]
      ! 1, x, y, z, x2, xy, xz, y2, yz, z2, x3, x2y, x2z, xy2, xyz, xz2, y3, y2z, yz2, z3 at (1/2, -2, 3)
      real(wp), parameter :: ref3(20) = [1.0_wp, 0.5_wp, -2.0_wp, 3.0_wp, 0.25_wp, -1.0_wp, 1.5_wp, 4.0_wp, &
         & -6.0_wp, 9.0_wp, 0.125_wp, -0.5_wp, 0.75_wp, 2.0_wp, -3.0_wp, 4.5_wp, -8.0_wp, 12.0_wp, -18.0_wp, 27.0_wp]
      type(poly_basis_type) :: basis
      real(wp) :: p(20)
      integer :: i

      call make_basis(2, 3, basis, error)
      if (allocated(error)) return
      p = 99.0_wp
      call basis%eval([0.5_wp, -2.0_wp], p)
      do i = 1, 10
         call check(error, p(i), ref2(i), 0.0_wp, '2D value of term')
         if (allocated(error)) return
      end do
      call check(error, all(p(11:) == 99.0_wp), 'eval writes only p(1:nterms)')
      if (allocated(error)) return
      call make_basis(3, 3, basis, error)
      if (allocated(error)) return
      call basis%eval([0.5_wp, -2.0_wp, 3.0_wp], p)
      do i = 1, 20
         call check(error, p(i), ref3(i), 0.0_wp, '3D value of term')
         if (allocated(error)) return
      end do
   end subroutine test_eval_hand

   !> First derivatives against central differences of eval, term by term, at random points in
   !> [-1,1]^dim. Step 1e-5: the truncation error is step^2/6 |p'''| <= 1e-10 (|p'''| <= 6 for a
   !> cubic monomial with |s| <= 1) and rounding is ~ eps/step ~ 2e-11, so 1e-8 has margin while an
   !> index or coefficient error shows as O(0.1).
   subroutine test_grad_fd(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: step = 1.0e-5_wp, tol = 1.0e-8_wp
      type(poly_basis_type) :: basis
      real(wp) :: s(3), sp(3), sm(3), pp(20), pm(20), dp(20, 3)
      integer :: dim, p, ipt, k, i

      call seed_rng()
      do dim = 2, 3
         do p = 0, 3
            call make_basis(dim, p, basis, error)
            if (allocated(error)) return
            do ipt = 1, 5
               call random_sym(s(1:dim))
               call basis%eval_grad(s(1:dim), dp)
               do k = 1, dim
                  sp = s
                  sm = s
                  sp(k) = s(k) + step
                  sm(k) = s(k) - step
                  call basis%eval(sp(1:dim), pp)
                  call basis%eval(sm(1:dim), pm)
                  do i = 1, basis%nterms
                     call check(error, dp(i, k), (pp(i) - pm(i))/(2.0_wp*step), tol, 'd p_i / d s_k vs FD')
                     if (allocated(error)) return
                  end do
               end do
            end do
         end do
      end do
   end subroutine test_grad_fd

   !> Second derivatives against central differences of eval_grad (checked above) in both orders
   !> (k then l, and l then k), so symmetry is tested too. The gradient is at most quadratic, so the
   !> central difference has no truncation error; rounding ~ 3 eps/step ~ 1e-10 with step 1e-5: 1e-8.
   subroutine test_hess_fd(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: step = 1.0e-5_wp, tol = 1.0e-8_wp
      type(poly_basis_type) :: basis
      real(wp) :: s(3), sp(3), sm(3), gp(20, 3), gm(20, 3), d2p(20, 6)
      integer :: dim, p, ipt, m, k, l, i, pass

      call seed_rng()
      do dim = 2, 3
         do p = 0, 3
            call make_basis(dim, p, basis, error)
            if (allocated(error)) return
            do ipt = 1, 5
               call random_sym(s(1:dim))
               call basis%eval_hess(s(1:dim), d2p)
               do m = 1, basis%nhess
                  do pass = 1, 2
                     if (dim == 2) then
                        k = poly_hess_pairs_2d(pass, m)
                        l = poly_hess_pairs_2d(3 - pass, m)
                     else
                        k = poly_hess_pairs_3d(pass, m)
                        l = poly_hess_pairs_3d(3 - pass, m)
                     end if
                     sp = s
                     sm = s
                     sp(l) = s(l) + step
                     sm(l) = s(l) - step
                     call basis%eval_grad(sp(1:dim), gp)
                     call basis%eval_grad(sm(1:dim), gm)
                     do i = 1, basis%nterms
                        call check(error, d2p(i, m), (gp(i, k) - gm(i, k))/(2.0_wp*step), tol, &
                           & 'd2 p_i / d s_k d s_l vs FD of gradient')
                        if (allocated(error)) return
                     end do
                  end do
               end do
            end do
         end do
      end do
   end subroutine test_hess_fd

   !> p(s) . (D_k a) equals grad p(s)(:, k) . a at random s for random a. Both sides are sums of
   !> ~20 products of O(1) numbers, so they agree to a few ulps: 1e-13.
   subroutine test_dmat_grad(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: tol = 1.0e-13_wp
      type(poly_basis_type) :: basis
      type(error_type), allocatable :: e
      real(wp), allocatable :: d(:, :), a(:)
      real(wp) :: s(3), p(20), dp(20, 3)
      integer :: dim, deg, ipt, k, n

      call seed_rng()
      do dim = 2, 3
         do deg = 0, 3
            call make_basis(dim, deg, basis, error)
            if (allocated(error)) return
            n = basis%nterms
            allocate (d(n, n), a(n))
            do ipt = 1, 5
               call random_sym(s(1:dim))
               call random_sym(a)
               call basis%eval(s(1:dim), p)
               call basis%eval_grad(s(1:dim), dp)
               do k = 1, dim
                  call basis%derivative_matrix(k, d, e)
                  if (allocated(e)) then
                     call test_failed(error, e%message)
                     return
                  end if
                  call check(error, dot_product(p(1:n), matmul(d, a)), dot_product(dp(1:n, k), a), tol, &
                     & 'p . (D_k a) vs grad . a')
                  if (allocated(error)) return
               end do
            end do
            deallocate (d, a)
         end do
      end do
   end subroutine test_dmat_grad

   !> D_k D_l = D_l D_k exactly (integer entries), and p(s) . (D_k D_l a) equals the Voigt
   !> second derivative from eval_hess dotted with a (few ulps: 1e-13).
   subroutine test_dmat_commute(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: tol = 1.0e-13_wp
      type(poly_basis_type) :: basis
      type(error_type), allocatable :: e
      real(wp) :: dk(20, 20), dl(20, 20), s(3), a(20), p(20), d2p(20, 6)
      integer :: dim, deg, m, k, l, n

      call seed_rng()
      do dim = 2, 3
         do deg = 0, 3
            call make_basis(dim, deg, basis, error)
            if (allocated(error)) return
            n = basis%nterms
            call random_sym(s(1:dim))
            call random_sym(a(1:n))
            call basis%eval(s(1:dim), p)
            call basis%eval_hess(s(1:dim), d2p)
            do m = 1, basis%nhess
               if (dim == 2) then
                  k = poly_hess_pairs_2d(1, m)
                  l = poly_hess_pairs_2d(2, m)
               else
                  k = poly_hess_pairs_3d(1, m)
                  l = poly_hess_pairs_3d(2, m)
               end if
               call basis%derivative_matrix(k, dk(1:n, 1:n), e)
               if (.not. allocated(e)) call basis%derivative_matrix(l, dl(1:n, 1:n), e)
               if (allocated(e)) then
                  call test_failed(error, e%message)
                  return
               end if
               call check(error, all(matmul(dk(1:n, 1:n), dl(1:n, 1:n)) == matmul(dl(1:n, 1:n), dk(1:n, 1:n))), &
                  & 'D_k D_l == D_l D_k')
               if (allocated(error)) return
               call check(error, dot_product(p(1:n), matmul(dk(1:n, 1:n), matmul(dl(1:n, 1:n), a(1:n)))), &
                  & dot_product(d2p(1:n, m), a(1:n)), tol, 'p . (D_k D_l a) vs eval_hess . a')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_dmat_commute

   !> D_k applied degree+1 times is zero; applied degree times it is not (x_k^degree is a term).
   subroutine test_dmat_nilpotent(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: basis
      type(error_type), allocatable :: e
      real(wp), allocatable :: d(:, :), q(:, :)
      integer :: dim, deg, k, j, n

      do dim = 2, 3
         do deg = 0, 3
            call make_basis(dim, deg, basis, error)
            if (allocated(error)) return
            n = basis%nterms
            allocate (d(n, n), q(n, n))
            do k = 1, dim
               call basis%derivative_matrix(k, d, e)
               if (allocated(e)) then
                  call test_failed(error, e%message)
                  return
               end if
               q = 0.0_wp
               do j = 1, n
                  q(j, j) = 1.0_wp
               end do
               do j = 1, deg
                  q = matmul(d, q)
               end do
               call check(error, any(q /= 0.0_wp), 'D_k**degree is not zero')
               if (allocated(error)) return
               q = matmul(d, q)
               call check(error, all(q == 0.0_wp), 'D_k**(degree+1) is zero')
               if (allocated(error)) return
            end do
            deallocate (d, q)
         end do
      end do
   end subroutine test_dmat_nilpotent

   !> Row j of the design matrix equals eval at point j (same arithmetic: exact).
   subroutine test_eval_points(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: npts = 7
      type(poly_basis_type) :: basis
      real(wp) :: s(3, npts), pmat(npts + 2, 20), p(20)
      integer :: dim, j

      call seed_rng()
      do dim = 2, 3
         call make_basis(dim, 3, basis, error)
         if (allocated(error)) return
         do j = 1, npts
            call random_sym(s(1:dim, j))
         end do
         pmat = -7.0_wp
         call basis%eval_points(s(1:dim, :), pmat)
         do j = 1, npts
            call basis%eval(s(1:dim, j), p)
            call check(error, all(pmat(j, 1:basis%nterms) == p(1:basis%nterms)), 'row of eval_points == eval')
            if (allocated(error)) return
         end do
         call check(error, all(pmat(npts + 1:, :) == -7.0_wp), 'eval_points writes only the leading block')
         if (allocated(error)) return
      end do
   end subroutine test_eval_points

   !> Completeness: f(s) = prod_{m=1..p} (alpha_m + beta_m . s), a random polynomial of degree p
   !> computed without the basis, is sampled at 2*nterms+5 random points in [-1,1]^dim and fitted by
   !> least squares (dgelsd) with the degree-p basis. The fit must have full rank and reproduce f at
   !> fresh points to 10 nterms eps cond_2(P) relative to max|f|: the solve is backward stable,
   !> its coefficient error is ~eps cond_2(P) (the residual is zero), and the value at a test point
   !> sums nterms terms; cond_2(P) = s_1/s_n from dgelsd's singular values (~20 for such samples).
   !> A degree p+1 product is not reproduced (misfit > 1e-6), which shows the check has teeth.
   subroutine test_reproduction(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: basis
      integer :: dim, deg, extra
      real(wp) :: misfit, fmax, cond

      call seed_rng()
      do dim = 2, 3
         do deg = 0, 3
            call make_basis(dim, deg, basis, error)
            if (allocated(error)) return
            do extra = 0, merge(1, 0, deg < 3)
               call fit_product(basis, deg + extra, misfit, fmax, cond, error)
               if (allocated(error)) return
               if (extra == 0) then
                  call check(error, misfit <= 10.0_wp*real(basis%nterms, wp)*epsilon(1.0_wp)*cond*fmax, &
                     & 'degree-p polynomial reproduced')
               else
                  call check(error, misfit > 1.0e-6_wp*fmax, 'degree-(p+1) polynomial not reproduced')
               end if
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_reproduction

   subroutine fit_product(basis, nfac, misfit, fmax, cond, error)
      type(poly_basis_type), intent(in) :: basis
      integer, intent(in) :: nfac
      !> cond: 2-norm condition number of the design matrix.
      real(wp), intent(out) :: misfit, fmax, cond
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: ntest = 10
      real(wp), allocatable :: s(:, :), pmat(:, :), rhs(:, :), sv(:), work(:), stest(:, :), ptest(:, :)
      real(wp) :: alpha(4), beta(3, 4), wq(1)
      integer, allocatable :: iwork(:)
      integer :: npts, n, dim, rank, info, iq(1)

      cond = 0.0_wp
      dim = basis%dim
      n = basis%nterms
      npts = 2*n + 5
      call random_sym(alpha(1:nfac))
      call random_number(beta)
      beta = 2.0_wp*beta - 1.0_wp
      allocate (s(dim, npts), pmat(npts, n), rhs(npts, 1), sv(n), stest(dim, ntest), ptest(ntest, n))
      call random_number(stest)
      stest = 2.0_wp*stest - 1.0_wp
      call random_number(s)
      s = 2.0_wp*s - 1.0_wp
      call basis%eval_points(s, pmat)
      rhs(:, 1) = product_values(s)

      call dgelsd(npts, n, 1, pmat, npts, rhs, npts, sv, -1.0_wp, rank, wq, -1, iq, info)
      allocate (work(int(wq(1))), iwork(max(1, iq(1))))
      call dgelsd(npts, n, 1, pmat, npts, rhs, npts, sv, -1.0_wp, rank, work, size(work), iwork, info)
      call check(error, info, 0, 'dgelsd info')
      if (allocated(error)) return
      call check(error, rank, n, 'design matrix has full rank')
      if (allocated(error)) return
      cond = sv(1)/sv(n)

      call basis%eval_points(stest, ptest)
      misfit = maxval(abs(matmul(ptest, rhs(1:n, 1)) - product_values(stest)))
      fmax = max(maxval(abs(product_values(stest))), tiny(1.0_wp))

   contains

      function product_values(pts) result(f)
         real(wp), intent(in) :: pts(:, :)
         real(wp) :: f(size(pts, 2))
         integer :: j, m
         do j = 1, size(pts, 2)
            f(j) = 1.0_wp
            do m = 1, nfac
               f(j) = f(j)*(alpha(m) + dot_product(beta(1:dim, m), pts(:, j)))
            end do
         end do
      end function product_values

   end subroutine fit_product

   !> Physical derivatives: with x0 = (1.3, -0.7, 2.1) and a small patch h = 0.05,
   !> f(x) = p((x - x0)/h) . a. Central differences in x with step 1e-5*h: relative to the O(1/h)
   !> gradient the truncation error is ~1e-10 and rounding ~ eps/1e-5 ~ 2e-11, so 1e-8 relative
   !> (to max|grad f|) has margin; forgetting the 1/h factor would be off by a factor 20. The
   !> second derivatives are central differences of the physical gradient (quadratic: no
   !> truncation), with the same tolerance relative to max|hess f| ~ 1/h^2.
   subroutine test_scaling(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: h = 0.05_wp, x0(3) = [1.3_wp, -0.7_wp, 2.1_wp], tol = 1.0e-8_wp
      type(poly_basis_type) :: basis
      real(wp) :: s(3), x(3), xp(3), xm(3), sp(3), sm(3), a(20), pp(20), pm(20), dp(20, 3), dps(20, 3)
      real(wp) :: gp(20, 3), gm(20, 3), d2p(20, 6), fd(3), g(3), fdh(6), hh(6), xs(3, 2), ss(3, 2)
      integer :: dim, n, k, l, m, ipt

      call seed_rng()
      do dim = 2, 3
         call make_basis(dim, 3, basis, error)
         if (allocated(error)) return
         n = basis%nterms
         call random_sym(a(1:n))
         do ipt = 1, 3
            call random_sym(s(1:dim))
            x(1:dim) = x0(1:dim) + h*s(1:dim)
            call scale_point(x(1:dim), x0(1:dim), h, s(1:dim))
            call basis%eval_grad(s(1:dim), dp, h)
            call basis%eval_grad(s(1:dim), dps)
            call basis%eval_hess(s(1:dim), d2p, h)
            do k = 1, dim
               xp = x
               xm = x
               xp(k) = x(k) + 1.0e-5_wp*h
               xm(k) = x(k) - 1.0e-5_wp*h
               call scale_point(xp(1:dim), x0(1:dim), h, sp(1:dim))
               call scale_point(xm(1:dim), x0(1:dim), h, sm(1:dim))
               call basis%eval(sp(1:dim), pp)
               call basis%eval(sm(1:dim), pm)
               fd(k) = dot_product(pp(1:n) - pm(1:n), a(1:n))/(xp(k) - xm(k))
               g(k) = dot_product(dp(1:n, k), a(1:n))
            end do
            do k = 1, dim
               call check(error, g(k), fd(k), tol*maxval(abs(fd(1:dim))), 'physical gradient vs FD in x')
               if (allocated(error)) return
               call check(error, g(k), dot_product(dps(1:n, k), a(1:n))/h, 1.0e-13_wp*maxval(abs(g(1:dim))), &
                  & 'physical gradient is (1/h) scaled gradient')
               if (allocated(error)) return
            end do
            do m = 1, basis%nhess
               if (dim == 2) then
                  k = poly_hess_pairs_2d(1, m)
                  l = poly_hess_pairs_2d(2, m)
               else
                  k = poly_hess_pairs_3d(1, m)
                  l = poly_hess_pairs_3d(2, m)
               end if
               xs(:, 1) = x
               xs(:, 2) = x
               xs(l, 1) = x(l) + 1.0e-5_wp*h
               xs(l, 2) = x(l) - 1.0e-5_wp*h
               call scale_points(xs(1:dim, :), x0(1:dim), h, ss(1:dim, :))
               call basis%eval_grad(ss(1:dim, 1), gp, h)
               call basis%eval_grad(ss(1:dim, 2), gm, h)
               fdh(m) = dot_product(gp(1:n, k) - gm(1:n, k), a(1:n))/(xs(l, 1) - xs(l, 2))
               hh(m) = dot_product(d2p(1:n, m), a(1:n))
            end do
            do m = 1, basis%nhess
               call check(error, hh(m), fdh(m), tol*maxval(abs(fdh(1:basis%nhess))), 'physical hessian vs FD in x')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_scaling

   subroutine test_constructor_errors(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: bad(2, 5) = reshape([1, 1, 4, 1, 0, 2, 2, -1, 3, 4], [2, 5])
      type(poly_basis_type) :: basis
      type(error_type), allocatable :: e
      integer :: i

      do i = 1, size(bad, 2)
         call new_poly_basis(basis, bad(1, i), bad(2, i), e)
         call check(error, allocated(e), 'bad dim/degree must fail')
         if (allocated(error)) return
         call check(error, e%stat, stat_invalid_input, 'status')
         if (allocated(error)) return
      end do
      call new_poly_basis(basis, 2, 7, e)
      call check(error, index(e%message, 'degree = 7') > 0, 'message names the degree')
      if (allocated(error)) return
      call new_poly_basis(basis, 5, 1, e)
      call check(error, index(e%message, 'dim = 5') > 0, 'message names the dim')
   end subroutine test_constructor_errors

   subroutine test_dmat_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(poly_basis_type) :: basis
      type(error_type), allocatable :: e
      real(wp) :: d(6, 6), dbad(6, 5)

      call make_basis(2, 2, basis, error)
      if (allocated(error)) return
      call basis%derivative_matrix(0, d, e)
      call check(error, allocated(e), 'k = 0 must fail')
      if (allocated(error)) return
      call basis%derivative_matrix(3, d, e)
      call check(error, allocated(e), 'k = 3 in 2D must fail')
      if (allocated(error)) return
      call check(error, e%stat, stat_invalid_input, 'status')
      if (allocated(error)) return
      call basis%derivative_matrix(1, dbad, e)
      call check(error, allocated(e), 'wrong shape must fail')
      if (allocated(error)) return
      call basis%derivative_matrix(2, d, e)
      call check(error, .not. allocated(e), 'valid call succeeds')
   end subroutine test_dmat_errors

end module sprc_test_poly
