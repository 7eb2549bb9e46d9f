!> Complete polynomial bases of total degree 0..3 in 2D and 3D, evaluated in
!> patch-local scaled coordinates, with first and second derivatives and the
!> exact coefficient-space differentiation matrices that the SPR / SPR-C
!> recovery builds its constraint operators from.
!>
!> ## Monomial order (fixed for all of sprc)
!> A term x^a y^b z^c is graded by total degree n = a + b + c; within a degree,
!> exponents are in descending a, then descending b. Because the order is
!> graded, the basis of degree p is the first C(p+dim, dim) terms of the
!> degree-3 basis (lower degrees are prefixes of higher ones).
!>
!> 2D: 1, x, y, x^2, xy, y^2, x^3, x^2y, xy^2, y^3.
!> 3D: 1, x, y, z, x^2, xy, xz, y^2, yz, z^2, x^3, x^2y, x^2z, xy^2, xyz, xz^2, y^3, y^2z,
!> yz^2, z^3.
!>
!> The thesis uses three different quadratic orders (its table of p(x),
!> eq. 40 and eq. 54/62); sprc uses only this one, exported as the parameter
!> tables `poly_exponents_2d` and `poly_exponents_3d`.
!>
!> ## Coordinates and derivatives
!> All evaluation is in scaled coordinates s = (x - x0)/h (`scale_point`),
!> with x0 the patch node and h the patch size, so that |s| = O(1) and the
!> least-squares matrices stay well conditioned. Derivatives returned by
!> `eval_grad` and `eval_hess` are with respect to s unless the optional
!> argument `h` is given; then they are physical: d/dx = (1/h) d/ds and
!> d2/dx2 = (1/h^2) d2/ds2. The derivative matrices act on coefficient vectors
!> and are always in s; a physical k-th derivative is (1/h) D_k.
!>
!> Second derivatives are stored in the Voigt-like order of sprc's stresses:
!> 2D (ss_xx, ss_yy, ss_xy), 3D (xx, yy, zz, xy, yz, xz) (`poly_hess_pairs_*`).
!>
!> ## Performance contract
!> `eval`, `eval_grad`, `eval_hess` and `eval_points` are pure, allocate
!> nothing and do not check array sizes: callers pass s(dim) and outputs with
!> at least `nterms` rows (only the leading block is written). Values come from
!> a recurrence along the graded order, one multiply per term (no `**`);
!> every first or second derivative of a term is an integer multiple of a
!> lower term, so derivatives cost one gather and one multiply per entry.
!> They read the basis only, so one basis object may be shared by all threads
!> of an OpenMP patch loop; copying it allocates only `exponents`.
module sprc_core_poly
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   implicit none
   private

   public :: poly_basis_type, new_poly_basis, poly_nterms, scale_point, scale_points
   public :: poly_max_degree, poly_max_terms, poly_exponents_2d, poly_exponents_3d
   public :: poly_hess_pairs_2d, poly_hess_pairs_3d

   !> Highest supported total degree.
   integer, parameter :: poly_max_degree = 3
   !> Number of terms of the largest basis (3D, degree 3).
   integer, parameter :: poly_max_terms = 20

   !> 2D exponents (a, b, c=0) of x^a y^b in sprc order, degree 3 (see the table above).
   integer, parameter :: poly_exponents_2d(3, 10) = reshape([ &
      & 0, 0, 0, &
      & 1, 0, 0, 0, 1, 0, &
      & 2, 0, 0, 1, 1, 0, 0, 2, 0, &
      & 3, 0, 0, 2, 1, 0, 1, 2, 0, 0, 3, 0], [3, 10])

   !> 3D exponents (a, b, c) of x^a y^b z^c in sprc order, degree 3 (see the table above).
   integer, parameter :: poly_exponents_3d(3, 20) = reshape([ &
      & 0, 0, 0, &
      & 1, 0, 0, 0, 1, 0, 0, 0, 1, &
      & 2, 0, 0, 1, 1, 0, 1, 0, 1, 0, 2, 0, 0, 1, 1, 0, 0, 2, &
      & 3, 0, 0, 2, 1, 0, 2, 0, 1, 1, 2, 0, 1, 1, 1, 1, 0, 2, 0, 3, 0, 0, 2, 1, 0, 1, 2, 0, 0, 3], &
      & [3, 20])

   !> Coordinate pairs (k, l) of the second derivatives d2/ds_k ds_l, 2D order (xx, yy, xy).
   integer, parameter :: poly_hess_pairs_2d(2, 3) = reshape([1, 1, 2, 2, 1, 2], [2, 3])
   !> Coordinate pairs (k, l) of the second derivatives, 3D order (xx, yy, zz, xy, yz, xz).
   integer, parameter :: poly_hess_pairs_3d(2, 6) = reshape([1, 1, 2, 2, 3, 3, 1, 2, 2, 3, 1, 3], [2, 6])

   !> A complete polynomial basis of total degree `degree` in `dim` variables.
   !> Built by `new_poly_basis`; read-only afterwards (safe to share between threads).
   type :: poly_basis_type
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Total degree, 0..3.
      integer :: degree = -1
      !> Number of terms, C(degree+dim, dim).
      integer :: nterms = 0
      !> Number of distinct second derivatives: 3 in 2D, 6 in 3D.
      integer :: nhess = 0
      !> exponents(:, i) = (a, b, c) of term i, x^a y^b z^c; c = 0 in 2D.
      integer, allocatable :: exponents(:, :)
      ! Fixed-size tables for the hot paths (set by new_poly_basis):
      ! p_i = p_parent(i) * s_var(i), where parent(i) < i lowers the first nonzero
      ! exponent of term i; d p_i/ds_k = gcoef(i,k) p_gidx(i,k);
      ! d2 p_i/ds_k ds_l = hcoef(i,m) p_hidx(i,m) for the m-th Voigt pair (k,l).
      ! A vanishing derivative has coefficient 0 and points at term 1, which keeps
      ! the loops branch-free.
      integer :: parent(poly_max_terms) = 1
      integer :: var(poly_max_terms) = 1
      integer :: gidx(poly_max_terms, 3) = 1
      real(wp) :: gcoef(poly_max_terms, 3) = 0.0_wp
      integer :: hidx(poly_max_terms, 6) = 1
      real(wp) :: hcoef(poly_max_terms, 6) = 0.0_wp
   contains
      !> Values p(s) of all terms.
      procedure :: eval
      !> First derivatives of all terms.
      procedure :: eval_grad
      !> Second derivatives of all terms.
      procedure :: eval_hess
      !> Values at many points, as a design matrix.
      procedure :: eval_points
      !> Coefficient-space matrix of d/ds_k.
      procedure :: derivative_matrix
      !> Index of a monomial in this basis.
      procedure :: term_index
   end type poly_basis_type

contains

   !> Number of terms C(degree+dim, dim) of the complete basis; 0 if out of range.
   pure function poly_nterms(dim, degree) result(n)
      integer, intent(in) :: dim, degree
      integer :: n

      n = 0
      if (degree < 0 .or. degree > poly_max_degree) return
      select case (dim)
      case (2)
         n = (degree + 1)*(degree + 2)/2
      case (3)
         n = (degree + 1)*(degree + 2)*(degree + 3)/6
      end select
   end function poly_nterms

   !> Build the complete basis of total degree `degree` (0..3) in `dim` (2 or 3) variables.
   pure subroutine new_poly_basis(self, dim, degree, error)
      !> Basis to build.
      type(poly_basis_type), intent(out) :: self
      !> Space dimension, 2 or 3.
      integer, intent(in) :: dim
      !> Total degree, 0..3.
      integer, intent(in) :: degree
      !> Set if `dim` or `degree` is out of range (stat_invalid_input).
      type(error_type), allocatable, intent(out) :: error
      character(len=16) :: buf
      integer :: i, m, k, l, e(3), exps(3, poly_max_terms)
      real(wp) :: c1, c2

      if (dim /= 2 .and. dim /= 3) then
         write (buf, '(i0)') dim
         call fatal_error(error, 'new_poly_basis: dim = '//trim(buf)//' is not 2 or 3', stat_invalid_input)
         return
      end if
      if (degree < 0 .or. degree > poly_max_degree) then
         write (buf, '(i0)') degree
         call fatal_error(error, 'new_poly_basis: degree = '//trim(buf)//' is not in 0..3', stat_invalid_input)
         return
      end if

      self%dim = dim
      self%degree = degree
      self%nterms = poly_nterms(dim, degree)
      self%nhess = merge(3, 6, dim == 2)
      call generate_exponents(dim, degree, exps)
      self%exponents = exps(:, 1:self%nterms)

      do i = 2, self%nterms
         e = exps(:, i)
         self%var(i) = findloc(e > 0, .true., 1)
         e(self%var(i)) = e(self%var(i)) - 1
         self%parent(i) = self%term_index(e(1), e(2), e(3))
      end do
      do i = 1, self%nterms
         do k = 1, dim
            e = exps(:, i)
            call lower(e, k, self%gcoef(i, k))
            self%gidx(i, k) = self%term_index(e(1), e(2), e(3))
         end do
         do m = 1, self%nhess
            call hess_pair(dim, m, k, l)
            ! If the first lowering vanishes, its zero coefficient zeroes the product.
            e = exps(:, i)
            call lower(e, k, c1)
            call lower(e, l, c2)
            self%hcoef(i, m) = c1*c2
            self%hidx(i, m) = self%term_index(e(1), e(2), e(3))
         end do
      end do
   end subroutine new_poly_basis

   !> Exponents in sprc order, generated by the rule (graded; descending a, then b)
   !> rather than copied from the parameter tables, so the tests can compare the two.
   pure subroutine generate_exponents(dim, degree, exps)
      integer, intent(in) :: dim, degree
      integer, intent(out) :: exps(:, :)
      integer :: n, a, b, i

      exps = 0
      i = 0
      do n = 0, degree
         do a = n, 0, -1
            if (dim == 2) then
               i = i + 1
               exps(:, i) = [a, n - a, 0]
            else
               do b = n - a, 0, -1
                  i = i + 1
                  exps(:, i) = [a, b, n - a - b]
               end do
            end if
         end do
      end do
   end subroutine generate_exponents

   !> Differentiate the monomial with exponents `e` once in variable k: coefficient e(k),
   !> exponent e(k)-1. A vanishing derivative gives coefficient 0 and leaves e unchanged
   !> (any valid term will do, its value is multiplied by 0).
   pure subroutine lower(e, k, coef)
      integer, intent(inout) :: e(3)
      integer, intent(in) :: k
      real(wp), intent(out) :: coef

      coef = real(e(k), wp)
      if (e(k) > 0) e(k) = e(k) - 1
   end subroutine lower

   pure subroutine hess_pair(dim, m, k, l)
      integer, intent(in) :: dim, m
      integer, intent(out) :: k, l

      if (dim == 2) then
         k = poly_hess_pairs_2d(1, m)
         l = poly_hess_pairs_2d(2, m)
      else
         k = poly_hess_pairs_3d(1, m)
         l = poly_hess_pairs_3d(2, m)
      end if
   end subroutine hess_pair

   !> Patch-local scaled coordinates of one point: s = (x - x0)/h. Requires h > 0.
   pure subroutine scale_point(x, x0, h, s)
      !> Physical point, x(dim).
      real(wp), intent(in) :: x(:)
      !> Patch origin (the patch node), x0(dim).
      real(wp), intent(in) :: x0(:)
      !> Patch size, > 0.
      real(wp), intent(in) :: h
      !> Scaled point, s(dim).
      real(wp), intent(out) :: s(:)

      s = (x - x0)/h
   end subroutine scale_point

   !> Scaled coordinates of many points: s(:, i) = (x(:, i) - x0)/h. Requires h > 0.
   pure subroutine scale_points(x, x0, h, s)
      !> Physical points, x(dim, npoints).
      real(wp), intent(in) :: x(:, :)
      !> Patch origin, x0(dim).
      real(wp), intent(in) :: x0(:)
      !> Patch size, > 0.
      real(wp), intent(in) :: h
      !> Scaled points, s(dim, npoints).
      real(wp), intent(out) :: s(:, :)
      integer :: i

      do i = 1, size(x, 2)
         s(:, i) = (x(:, i) - x0)/h
      end do
   end subroutine scale_points

   !> Values of all terms at the scaled point s: p(1:nterms).
   pure subroutine eval(self, s, p)
      class(poly_basis_type), intent(in) :: self
      !> Scaled point, s(dim).
      real(wp), intent(in) :: s(:)
      !> Term values; p(1:nterms) is written.
      real(wp), intent(inout) :: p(:)
      integer :: i

      p(1) = 1.0_wp
      do i = 2, self%nterms
         p(i) = p(self%parent(i))*s(self%var(i))
      end do
   end subroutine eval

   !> First derivatives of all terms at s: dp(i, k) = d p_i / d s_k, or d p_i / d x_k if h is given.
   pure subroutine eval_grad(self, s, dp, h)
      class(poly_basis_type), intent(in) :: self
      !> Scaled point, s(dim).
      real(wp), intent(in) :: s(:)
      !> Derivatives; dp(1:nterms, 1:dim) is written.
      real(wp), intent(inout) :: dp(:, :)
      !> Patch size: if present, return physical derivatives (times 1/h).
      real(wp), intent(in), optional :: h
      real(wp) :: p(poly_max_terms)
      integer :: i, k

      call self%eval(s, p)
      if (present(h)) p(1:self%nterms) = p(1:self%nterms)/h
      do k = 1, self%dim
         do i = 1, self%nterms
            dp(i, k) = self%gcoef(i, k)*p(self%gidx(i, k))
         end do
      end do
   end subroutine eval_grad

   !> Second derivatives of all terms at s: d2p(i, m) = d2 p_i / d s_k d s_l with (k, l) the
   !> m-th Voigt pair (2D xx, yy, xy; 3D xx, yy, zz, xy, yz, xz); physical (times 1/h^2) if h is given.
   pure subroutine eval_hess(self, s, d2p, h)
      class(poly_basis_type), intent(in) :: self
      !> Scaled point, s(dim).
      real(wp), intent(in) :: s(:)
      !> Second derivatives; d2p(1:nterms, 1:nhess) is written.
      real(wp), intent(inout) :: d2p(:, :)
      !> Patch size: if present, return physical derivatives (times 1/h**2).
      real(wp), intent(in), optional :: h
      real(wp) :: p(poly_max_terms)
      integer :: i, m

      call self%eval(s, p)
      if (present(h)) p(1:self%nterms) = p(1:self%nterms)/(h*h)
      do m = 1, self%nhess
         do i = 1, self%nterms
            d2p(i, m) = self%hcoef(i, m)*p(self%hidx(i, m))
         end do
      end do
   end subroutine eval_hess

   !> Design matrix of many scaled points: pmat(j, i) = p_i(s(:, j)).
   !>
   !> Column-major with one row per point and one column per term, i.e. the usual
   !> least-squares matrix P(npoints, nterms): M = P^T W P is `dsyrk('U', 'T', nterms,
   !> npoints, ...)` on the rows scaled by sqrt(w), with lda = size of pmat's first dimension.
   pure subroutine eval_points(self, s, pmat)
      class(poly_basis_type), intent(in) :: self
      !> Scaled points, s(dim, npoints).
      real(wp), intent(in) :: s(:, :)
      !> Design matrix; pmat(1:npoints, 1:nterms) is written.
      real(wp), intent(inout) :: pmat(:, :)
      integer :: i, j

      ! Term-outer loop: each column is one contiguous, vectorisable sweep over the points.
      pmat(1:size(s, 2), 1) = 1.0_wp
      do i = 2, self%nterms
         do j = 1, size(s, 2)
            pmat(j, i) = pmat(j, self%parent(i))*s(self%var(i), j)
         end do
      end do
   end subroutine eval_points

   !> Exact coefficient-space differentiation: d/ds_k [p(s) . a] = p(s) . (d a) for every a.
   !> Differentiation lowers the degree, so the result stays in the basis; d is nilpotent
   !> (d**(degree+1) = 0) and second derivatives are products d_k d_l (which commute).
   !> For physical derivatives multiply by 1/h. With a design matrix P from `eval_points`,
   !> P d is the matrix of d/ds_k at all points (one dgemm).
   pure subroutine derivative_matrix(self, k, d, error)
      class(poly_basis_type), intent(in) :: self
      !> Variable, 1..dim.
      integer, intent(in) :: k
      !> Matrix d(nterms, nterms), exactly this shape.
      real(wp), intent(out) :: d(:, :)
      !> Set if k is out of range or d has the wrong shape (stat_invalid_input).
      type(error_type), allocatable, intent(out) :: error
      character(len=64) :: buf
      integer :: j

      if (k < 1 .or. k > self%dim) then
         write (buf, '("k = ",i0," is not in 1..",i0)') k, self%dim
         call fatal_error(error, 'poly derivative_matrix: '//trim(buf), stat_invalid_input)
         return
      end if
      if (size(d, 1) /= self%nterms .or. size(d, 2) /= self%nterms) then
         write (buf, '("d is ",i0,"x",i0,", expected ",i0,"x",i0)') size(d, 1), size(d, 2), &
            & self%nterms, self%nterms
         call fatal_error(error, 'poly derivative_matrix: '//trim(buf), stat_invalid_input)
         return
      end if
      ! Column j holds the single nonzero of d/ds_k p_j: gcoef(j,k) at row gidx(j,k).
      d = 0.0_wp
      do j = 1, self%nterms
         d(self%gidx(j, k), j) = self%gcoef(j, k)
      end do
   end subroutine derivative_matrix

   !> Index of the monomial x^a y^b z^c in this basis; 0 if it is not a term of it
   !> (negative exponent, degree above the basis degree, or c /= 0 in 2D).
   !> Computed from the ordering rule, independent of the stored tables.
   pure function term_index(self, a, b, c) result(idx)
      class(poly_basis_type), intent(in) :: self
      integer, intent(in) :: a, b, c
      integer :: idx
      integer :: n

      idx = 0
      if (a < 0 .or. b < 0 .or. c < 0) return
      n = a + b + c
      if (n > self%degree) return
      select case (self%dim)
      case (2)
         if (c /= 0) return
         ! n(n+1)/2 terms of lower degree, then descending a.
         idx = n*(n + 1)/2 + (n - a) + 1
      case (3)
         ! C(n+2,3) terms of lower degree; (n-a)(n-a+1)/2 terms of degree n with larger a;
         ! then descending b.
         idx = n*(n + 1)*(n + 2)/6 + (n - a)*(n - a + 1)/2 + (n - a - b) + 1
      end select
   end function term_index

end module sprc_core_poly
