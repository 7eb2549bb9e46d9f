!> The Lagrange reference elements every layer shares: the 1D basis of degree 1 or 2
!> on the equispaced nodes of [0, 1], VTK's local node order of the line, quadrilateral
!> and hexahedron as Lagrange indices, and the tensor-product shape functions.
!>
!> Local node order is VTK's, so output needs no permutation. Node j of an element of
!> degree p sits at the reference point idx(:, j)/p in [0, 1]^dim:
!> - line2, line3 (VTK_LINE, VTK_QUADRATIC_EDGE): the two ends, then the midpoint;
!> - quad4 (VTK_QUAD): (0,0) (1,0) (1,1) (0,1);
!> - quad9 (VTK_BIQUADRATIC_QUAD): corners as quad4, then the edge midpoints of
!>   y=0, x=1, y=1, x=0, then the centre;
!> - hex8 (VTK_HEXAHEDRON): the bottom face z=0 as quad4, then the top face z=1;
!> - hex27 (VTK_TRIQUADRATIC_HEXAHEDRON): corners as hex8; the edge midpoints of the
!>   bottom face (as quad9's 4..7), of the top face, then of the vertical edges above
!>   corners 0..3; the face centres x=0, x=1, y=0, y=1, z=0, z=1; the centre.
module sprc_core_lagrange
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: lagrange_1d, tensor_shape, element_node_index
   public :: vtk_line2, vtk_line3, vtk_quad4, vtk_quad9, vtk_hex8, vtk_hex27

   !> Lagrange indices (dim, nodes) of VTK's line2 (module notes).
   integer, parameter :: vtk_line2(1, 2) = reshape([0, 1], [1, 2])
   !> Lagrange indices of VTK's line3 (VTK_QUADRATIC_EDGE).
   integer, parameter :: vtk_line3(1, 3) = reshape([0, 2, 1], [1, 3])
   !> Lagrange indices of VTK's quad4.
   integer, parameter :: vtk_quad4(2, 4) = reshape([0, 0, 1, 0, 1, 1, 0, 1], [2, 4])
   !> Lagrange indices of VTK's quad9.
   integer, parameter :: vtk_quad9(2, 9) = reshape([0, 0, 2, 0, 2, 2, 0, 2, 1, 0, 2, 1, 1, 2, 0, 1, 1, 1], [2, 9])
   !> Lagrange indices of VTK's hex8.
   integer, parameter :: vtk_hex8(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, &
      & 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1], [3, 8])
   !> Lagrange indices of VTK's hex27.
   integer, parameter :: vtk_hex27(3, 27) = reshape([ &
      & 0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0, 0, 0, 2, 2, 0, 2, 2, 2, 2, 0, 2, 2, &
      & 1, 0, 0, 2, 1, 0, 1, 2, 0, 0, 1, 0, &
      & 1, 0, 2, 2, 1, 2, 1, 2, 2, 0, 1, 2, &
      & 0, 0, 1, 2, 0, 1, 2, 2, 1, 0, 2, 1, &
      & 0, 1, 1, 2, 1, 1, 1, 0, 1, 1, 2, 1, 1, 1, 0, 1, 1, 2, &
      & 1, 1, 1], [3, 27])

contains

   !> The 1D Lagrange basis l(0:degree) of degree 1 or 2 on the equispaced nodes
   !> k/degree of [0, 1] at t (any real: outside [0, 1] it extrapolates), and its
   !> derivative dl if wanted; entries beyond degree are 0.
   pure subroutine lagrange_1d(degree, t, l, dl)
      integer, intent(in) :: degree
      real(wp), intent(in) :: t
      real(wp), intent(out) :: l(0:2)
      real(wp), intent(out), optional :: dl(0:2)
      if (degree == 1) then
         l = [1.0_wp - t, t, 0.0_wp]
         if (present(dl)) dl = [-1.0_wp, 1.0_wp, 0.0_wp]
      else
         l = [(2.0_wp*t - 1.0_wp)*(t - 1.0_wp), 4.0_wp*t*(1.0_wp - t), t*(2.0_wp*t - 1.0_wp)]
         if (present(dl)) dl = [4.0_wp*t - 3.0_wp, 4.0_wp - 8.0_wp*t, 4.0_wp*t - 1.0_wp]
      end if
   end subroutine lagrange_1d

   !> Lagrange indices (dim, (degree+1)**dim) of the local nodes of the quadrilateral
   !> (dim 2) or hexahedron (dim 3) of degree 1 or 2, in VTK order.
   pure function element_node_index(dim, degree) result(idx)
      integer, intent(in) :: dim, degree
      integer :: idx(dim, (degree + 1)**dim)
      if (dim == 2 .and. degree == 1) then
         idx = vtk_quad4
      else if (dim == 2) then
         idx = vtk_quad9
      else if (degree == 1) then
         idx = vtk_hex8
      else
         idx = vtk_hex27
      end if
   end function element_node_index

   !> Tensor Lagrange shape functions n(j) of degree deg on [0,1]^rdim (rdim = 1, 2, 3),
   !> node j at idx(:, j)/deg, and their reference derivatives d(1:rdim, j) if wanted.
   !> Products written out per dimension (no temporaries: this runs per point).
   pure subroutine tensor_shape(idx, deg, xi, n, d)
      integer, intent(in) :: idx(:, :), deg
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: n(:)
      real(wp), intent(out), optional :: d(:, :)
      real(wp) :: l(0:2, 3), dl(0:2, 3)
      integer :: j, k, rdim

      rdim = size(idx, 1)
      do k = 1, rdim
         call lagrange_1d(deg, xi(k), l(:, k), dl(:, k))
      end do
      select case (rdim)
      case (1)
         do j = 1, size(idx, 2)
            n(j) = l(idx(1, j), 1)
         end do
      case (2)
         do j = 1, size(idx, 2)
            n(j) = l(idx(1, j), 1)*l(idx(2, j), 2)
         end do
      case default
         do j = 1, size(idx, 2)
            n(j) = l(idx(1, j), 1)*l(idx(2, j), 2)*l(idx(3, j), 3)
         end do
      end select
      if (.not. present(d)) return
      select case (rdim)
      case (1)
         do j = 1, size(idx, 2)
            d(1, j) = dl(idx(1, j), 1)
         end do
      case (2)
         do j = 1, size(idx, 2)
            d(1, j) = dl(idx(1, j), 1)*l(idx(2, j), 2)
            d(2, j) = l(idx(1, j), 1)*dl(idx(2, j), 2)
         end do
      case default
         do j = 1, size(idx, 2)
            d(1, j) = dl(idx(1, j), 1)*l(idx(2, j), 2)*l(idx(3, j), 3)
            d(2, j) = l(idx(1, j), 1)*dl(idx(2, j), 2)*l(idx(3, j), 3)
            d(3, j) = l(idx(1, j), 1)*l(idx(2, j), 2)*dl(idx(3, j), 3)
         end do
      end select
   end subroutine tensor_shape

end module sprc_core_lagrange
