!> Q1 / Q2 Lagrange elements on axis-aligned boxes (the grid's cells).
!>
!> A cell [lo, hi] is mapped from the reference cube by x = lo + (hi - lo) xi,
!> so the Jacobian is the constant diagonal diag(hi - lo): gradients are the
!> reference gradients divided by the edge lengths, with no inversion. Shape
!> functions are tensor products of 1D Lagrange polynomials on equispaced
!> nodes, and the local node order is VTK's (`sprc_core_lagrange`). Points outside the box are allowed: the element's
!> polynomial is then extrapolated (what cell aggregation needs).
!>
!> Local dofs are node-major: dof (j - 1) dim + c is component c of node j.
!> Voigt order 2D (xx, yy, xy), 3D (xx, yy, zz, xy, yz, xz) with engineering
!> shear strains, as in `sprc_core_material`.
!>
!> Everything here is pure and allocation-free apart from automatic arrays
!> sized by the element, so it may be called from OpenMP threads.
module sprc_fem_element
   use sprc_core_kinds, only: wp
   use sprc_core_lagrange, only: lagrange_1d, element_node_index
   implicit none
   private

   public :: shape_functions, strain_matrix, traction_matrix, displacement_matrix
   public :: add_stiffness, mirror_upper, element_stress, element_strain

contains

   !> Values n(nen) and physical gradients dndx(dim, nen) of the Q`degree`
   !> shape functions of the box [lo, hi] at the point x (size dim each).
   pure subroutine shape_functions(dim, degree, lo, hi, x, n, dndx)
      integer, intent(in) :: dim, degree
      real(wp), intent(in) :: lo(:), hi(:), x(:)
      real(wp), intent(out) :: n(:), dndx(:, :)
      real(wp) :: l(0:2, 3), dl(0:2, 3), width(3)
      integer :: idx(dim, (degree + 1)**dim)
      integer :: j, k, m

      do k = 1, dim
         width(k) = hi(k) - lo(k)
         call lagrange_1d(degree, (x(k) - lo(k))/width(k), l(:, k), dl(:, k))
      end do
      idx = element_node_index(dim, degree)
      do j = 1, size(idx, 2)
         n(j) = 1.0_wp
         do k = 1, dim
            n(j) = n(j)*l(idx(k, j), k)
            dndx(k, j) = dl(idx(k, j), k)/width(k)
            do m = 1, dim
               if (m /= k) dndx(k, j) = dndx(k, j)*l(idx(m, j), m)
            end do
         end do
      end do
   end subroutine shape_functions

   !> Strain-displacement matrix b(nstress, dim*nen): eps = b u_e.
   pure subroutine strain_matrix(dim, dndx, b)
      integer, intent(in) :: dim
      real(wp), intent(in) :: dndx(:, :)
      real(wp), intent(out) :: b(:, :)
      integer :: j, c

      b = 0.0_wp
      do j = 1, size(dndx, 2)
         c = (j - 1)*dim
         b(1, c + 1) = dndx(1, j)
         b(2, c + 2) = dndx(2, j)
         if (dim == 2) then
            b(3, c + 1) = dndx(2, j)
            b(3, c + 2) = dndx(1, j)
         else
            b(3, c + 3) = dndx(3, j)
            b(4, c + 1) = dndx(2, j)
            b(4, c + 2) = dndx(1, j)
            b(5, c + 2) = dndx(3, j)
            b(5, c + 3) = dndx(2, j)
            b(6, c + 1) = dndx(3, j)
            b(6, c + 3) = dndx(1, j)
         end if
      end do
   end subroutine strain_matrix

   !> Matrix tn(dim, nstress) with t = tn sigma = sigma n for the unit normal n.
   pure subroutine traction_matrix(dim, n, tn)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(:)
      real(wp), intent(out) :: tn(:, :)
      tn = 0.0_wp
      if (dim == 2) then
         tn(1, 1) = n(1); tn(1, 3) = n(2)
         tn(2, 2) = n(2); tn(2, 3) = n(1)
      else
         tn(1, 1) = n(1); tn(1, 4) = n(2); tn(1, 6) = n(3)
         tn(2, 2) = n(2); tn(2, 4) = n(1); tn(2, 5) = n(3)
         tn(3, 3) = n(3); tn(3, 5) = n(2); tn(3, 6) = n(1)
      end if
   end subroutine traction_matrix

   !> Displacement interpolation matrix nm(dim, dim*nen): u = nm u_e.
   pure subroutine displacement_matrix(dim, n, nm)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(:)
      real(wp), intent(out) :: nm(:, :)
      integer :: j, c
      nm = 0.0_wp
      do j = 1, size(n)
         do c = 1, dim
            nm(c, (j - 1)*dim + c) = n(j)
         end do
      end do
   end subroutine displacement_matrix

   !> ke += w b^T d b on and above the diagonal (i <= j), with db = d b (nstress, ndof)
   !> supplied by the caller (it is also what a Nitsche term or a stress needs); the
   !> caller mirrors the upper triangle when its sums are complete (`mirror_upper`).
   !> Plain loops, not BLAS: OpenBLAS takes a lock on every call, which serializes the
   !> threads of an element loop on these tiny products.
   pure subroutine add_stiffness(b, db, w, ke)
      real(wp), intent(in) :: b(:, :), db(:, :), w
      real(wp), intent(inout) :: ke(:, :)
      real(wp) :: bt(size(b, 2), size(b, 1)), c
      integer :: s, j

      bt = transpose(b)
      do j = 1, size(b, 2)
         do s = 1, size(b, 1)
            c = w*db(s, j)
            ke(1:j, j) = ke(1:j, j) + c*bt(1:j, s)
         end do
      end do
   end subroutine add_stiffness

   !> k(j, i) = k(i, j) for i < j: the lower triangle from the upper one.
   pure subroutine mirror_upper(k)
      real(wp), intent(inout) :: k(:, :)
      integer :: i, j
      do j = 2, size(k, 2)
         do i = 1, j - 1
            k(j, i) = k(i, j)
         end do
      end do
   end subroutine mirror_upper

   !> Stress sigma(nstress) = d b u_e at a point of the box [lo, hi] from the
   !> element's nodal displacements ue(dim*nen), node-major.
   pure subroutine element_stress(dim, degree, d, lo, hi, x, ue, sigma)
      integer, intent(in) :: dim, degree
      real(wp), intent(in) :: d(:, :), lo(:), hi(:), x(:), ue(:)
      real(wp), intent(out) :: sigma(:)
      real(wp) :: eps(size(d, 1))

      call element_strain(dim, degree, lo, hi, x, ue, eps)
      sigma = matmul(d, eps)
   end subroutine element_stress

   !> Strain eps(nstress) = b u_e at a point of the box [lo, hi] (as `element_stress`).
   pure subroutine element_strain(dim, degree, lo, hi, x, ue, eps)
      integer, intent(in) :: dim, degree
      real(wp), intent(in) :: lo(:), hi(:), x(:), ue(:)
      real(wp), intent(out) :: eps(:)
      real(wp) :: n((degree + 1)**dim), dndx(dim, (degree + 1)**dim)
      real(wp) :: b(size(eps), dim*(degree + 1)**dim)

      call shape_functions(dim, degree, lo, hi, x, n, dndx)
      call strain_matrix(dim, dndx, b)
      eps = matmul(b, ue)
   end subroutine element_strain

end module sprc_fem_element
