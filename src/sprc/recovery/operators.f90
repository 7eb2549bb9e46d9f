!> Operator matrices of the SPR-C constraints, built generically from the Voigt
!> index pairs, the normal / tangent vectors and the coefficient-space derivative
!> matrices of sprc_core_poly — never from the thesis's expanded coefficient lists
!> (eqs. 52-53, 61, 97 and the symmetry lists have typos, doc/theory.md, section 11).
!>
!> One rule builds both the traction operator G(n) (eqs. 72-73) and the
!> equilibrium operator L^T (eq. 33, with the erratum of eq. 39): the i-th
!> component of sigma v is sum_c G(v)(i, c) sigma_c, where Voigt component c
!> with index pair (a, b) contributes v_b to row a and, if a /= b, v_a to row b.
!> L^T is G with v replaced by the derivative vector (D_x, D_y, D_z).
!>
!> Compatibility uses the incompatibility tensor S_ij = e_ikm e_jln eps_kl,mn
!> (Levi-Civita e): its six components in 3D are the six Saint-Venant equations
!> (thesis eq. 55/57) and S_33 in 2D is eq. 44. Strains come from the stresses by the
!> compliance (plane stress, reduced plane strain, or solid), eps = C sigma,
!> so the operator is L'C (eqs. 45, 56) for every analysis kind.
!>
!> All procedures are pure and allocate nothing.
module sprc_recovery_operators
   use sprc_core_kinds, only: wp
   use sprc_core_poly, only: poly_hess_pairs_2d, poly_hess_pairs_3d
   implicit none
   private

   public :: voigt_pair, voigt_index, hess_index, traction_operator, shear_operator, plane_tangents
   public :: divergence_operator, incompatibility_operator, compatibility_rows, ncompat_equations

contains

   !> Index pair (a, b), a <= b, of Voigt component c. sprc's stress order is the same
   !> as sprc_core_poly's second-derivative order: 2D (xx, yy, xy), 3D (xx, yy, zz, xy, yz, xz).
   pure subroutine voigt_pair(dim, c, a, b)
      integer, intent(in) :: dim, c
      integer, intent(out) :: a, b
      if (dim == 2) then
         a = poly_hess_pairs_2d(1, c)
         b = poly_hess_pairs_2d(2, c)
      else
         a = poly_hess_pairs_3d(1, c)
         b = poly_hess_pairs_3d(2, c)
      end if
   end subroutine voigt_pair

   !> Voigt component of the index pair (a, b) in either order.
   pure integer function voigt_index(dim, a, b) result(c)
      integer, intent(in) :: dim, a, b
      integer :: k, l
      do c = 1, merge(3, 6, dim == 2)
         call voigt_pair(dim, c, k, l)
         if ((k == a .and. l == b) .or. (k == b .and. l == a)) return
      end do
      c = 0
   end function voigt_index

   !> Second-derivative index m of d2/dx_a dx_b (same pairs as the Voigt order).
   pure integer function hess_index(dim, a, b) result(m)
      integer, intent(in) :: dim, a, b
      m = voigt_index(dim, a, b)
   end function hess_index

   !> Number of independent compatibility equations: 1 in 2D, 6 in 3D.
   pure integer function ncompat_equations(dim)
      integer, intent(in) :: dim
      ncompat_equations = merge(1, 6, dim == 2)
   end function ncompat_equations

   !> G(v): (sigma v)_i = sum_c g(i, c) sigma_c, g(1:dim, 1:nstress). With v the outward
   !> normal this is the Cauchy traction operator of eqs. 72-73.
   pure subroutine traction_operator(dim, v, g)
      integer, intent(in) :: dim
      real(wp), intent(in) :: v(:)
      real(wp), intent(out) :: g(:, :)
      integer :: c, a, b

      g = 0.0_wp
      do c = 1, merge(3, 6, dim == 2)
         call voigt_pair(dim, c, a, b)
         g(a, c) = g(a, c) + v(b)
         if (a /= b) g(b, c) = g(b, c) + v(a)
      end do
   end subroutine traction_operator

   !> Shear stress n^T sigma t = sum_c g(c) sigma_c on a plane with unit normal n and a
   !> unit tangent t (eqs. 92-93 for t = s, t).
   pure subroutine shear_operator(dim, n, t, g)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(:), t(:)
      real(wp), intent(out) :: g(:)
      real(wp) :: gn(3, 6)
      integer :: c

      call traction_operator(dim, n, gn)
      do c = 1, merge(3, 6, dim == 2)
         g(c) = dot_product(t(1:dim), gn(1:dim, c))
      end do
   end subroutine shear_operator

   !> Orthonormal tangents of a plane with unit normal n: t(:, 1) in 2D; t(:, 1:2) in 3D
   !> with (n, t1, t2) right-handed. t1 is n x e_k for the axis e_k least aligned with n.
   pure subroutine plane_tangents(dim, n, t)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(:)
      real(wp), intent(out) :: t(3, 2)
      real(wp) :: e(3), nn(3)
      integer :: k

      t = 0.0_wp
      if (dim == 2) then
         t(1:2, 1) = [-n(2), n(1)]
         return
      end if
      nn = n(1:3)
      k = minloc(abs(nn), 1)
      e = 0.0_wp
      e(k) = 1.0_wp
      t(:, 1) = cross(nn, e)
      t(:, 1) = t(:, 1)/sqrt(sum(t(:, 1)**2))
      t(:, 2) = cross(nn, t(:, 1))
   end subroutine plane_tangents

   pure function cross(a, b) result(c)
      real(wp), intent(in) :: a(3), b(3)
      real(wp) :: c(3)
      c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
   end function cross

   !> Coefficient-space divergence B: for stress coefficients A (column blocks of nterms per
   !> Voigt component), (div_s sigma*)_i = p(s) . (B A)_i, i.e. L^T P(s) A = (I_dim x p(s)) B A.
   !> `dmat(:, :, k)` are the exact derivative matrices d/ds_k; bdiv(dim*nt, nstress*nt).
   pure subroutine divergence_operator(dim, nt, dmat, bdiv)
      integer, intent(in) :: dim, nt
      real(wp), intent(in) :: dmat(:, :, :)
      real(wp), intent(out) :: bdiv(:, :)
      real(wp) :: g(3, 6), e(3)
      integer :: i, c, k

      bdiv = 0.0_wp
      do k = 1, dim
         e = 0.0_wp
         e(k) = 1.0_wp
         call traction_operator(dim, e, g)
         do c = 1, merge(3, 6, dim == 2)
            do i = 1, dim
               if (g(i, c) /= 0.0_wp) then
                  bdiv((i - 1)*nt + 1:i*nt, (c - 1)*nt + 1:c*nt) = &
                     & bdiv((i - 1)*nt + 1:i*nt, (c - 1)*nt + 1:c*nt) + g(i, c)*dmat(1:nt, 1:nt, k)
               end if
            end do
         end do
      end do
   end subroutine divergence_operator

   !> Incompatibility operator on Voigt strains with engineering shears:
   !> equation r is sum_e sum_m op(r, e, m) d2_m eps_e = 0, with m the second-derivative
   !> index. Equations: components of S_ij = e_ikm e_jln eps_kl,mn (tensor strains
   !> eps_kl = gamma_kl/2 for k /= l): 2D S_33 (eq. 44); 3D S_33, S_11, S_22, -2 S_23, -2 S_13,
   !> -2 S_12, which is row by row the operator L' of eq. 57.
   pure subroutine incompatibility_operator(dim, op)
      integer, intent(in) :: dim
      !> op(1:ncompat, 1:nstress, 1:nhess)
      real(wp), intent(out) :: op(:, :, :)
      integer :: r, i, j, k, l, m, n, nr
      real(wp) :: f, s
      ! Component (i, j) of S and its factor per equation, in the thesis's order and scaling
      ! of eq. 57 (row 1 is S_33, the 2D equation 44; rows 4-6 are -2 S_23, -2 S_13, -2 S_12).
      integer, parameter :: eq57_pairs(2, 6) = reshape([3, 3, 1, 1, 2, 2, 2, 3, 1, 3, 1, 2], [2, 6])
      real(wp), parameter :: eq57_factor(6) = [1.0_wp, 1.0_wp, 1.0_wp, -2.0_wp, -2.0_wp, -2.0_wp]

      op = 0.0_wp
      nr = ncompat_equations(dim)
      do r = 1, nr
         i = eq57_pairs(1, r)
         j = eq57_pairs(2, r)
         s = eq57_factor(r)
         do k = 1, dim
            do m = 1, dim
               do l = 1, dim
                  do n = 1, dim
                     f = s*real(levi(i, k, m)*levi(j, l, n), wp)
                     if (f == 0.0_wp) cycle
                     if (k /= l) f = 0.5_wp*f
                     op(r, voigt_index(dim, k, l), hess_index(dim, m, n)) = &
                        & op(r, voigt_index(dim, k, l), hess_index(dim, m, n)) + f
                  end do
               end do
            end do
         end do
      end do
   end subroutine incompatibility_operator

   pure integer function levi(i, j, k)
      integer, intent(in) :: i, j, k
      levi = (i - j)*(j - k)*(k - i)/2
   end function levi

   !> Exact compatibility rows L'C P(s) A = 0 in coefficient space: row block r (nt rows, the
   !> coefficients of the degree p-2 polynomial of equation r), column block c:
   !> sum_e sum_m op(r, e, m) compliance(e, c) D2_m, with D2_m = D_k D_l the second-derivative
   !> matrices. Rows of zeros (terms above degree p-2) are kept: the rank selection drops them.
   pure subroutine compatibility_rows(dim, nt, op, compliance, d2, rows)
      integer, intent(in) :: dim, nt
      real(wp), intent(in) :: op(:, :, :), compliance(:, :), d2(:, :, :)
      !> rows(ncompat*nt, nstress*nt)
      real(wp), intent(out) :: rows(:, :)
      integer :: r, c, e, m, ns
      real(wp) :: f

      ns = merge(3, 6, dim == 2)
      rows = 0.0_wp
      do r = 1, ncompat_equations(dim)
         do c = 1, ns
            do e = 1, ns
               if (compliance(e, c) == 0.0_wp) cycle
               do m = 1, ns
                  f = op(r, e, m)*compliance(e, c)
                  if (f == 0.0_wp) cycle
                  rows((r - 1)*nt + 1:r*nt, (c - 1)*nt + 1:c*nt) = &
                     & rows((r - 1)*nt + 1:r*nt, (c - 1)*nt + 1:c*nt) + f*d2(1:nt, 1:nt, m)
               end do
            end do
         end do
      end do
   end subroutine compatibility_rows

end module sprc_recovery_operators
