!> A legacy-style caller of the sprc recovery: fixed-size double precision arrays, its own
!> distorted quad4 mesh of [0,2] x [0,1], 2x2 Gauss points with the FE stresses replaced by
!> a known equilibrated field (Airy function phi = (x^4 - 6 x^2 y^2 + y^4)/10), one call of
!> sprc_recover_mesh (SPR-C), then nodal stresses against the exact field and the errors.
program legacy_recovery
   use sprc_legacy, only: sprc_recover_mesh
   implicit none
   integer, parameter :: nx = 8, ny = 4, nnode = (nx + 1)*(ny + 1), nelem = nx*ny, ngp = 4
   integer, parameter :: quad4 = 9, planestress = 1, sprc = 2, npts = 2
   double precision :: coords(2, nnode), gp(2, ngp, nelem), gw(ngp, nelem), gs(3, ngp, nelem)
   double precision :: nodal(3, nnode), elerr(nelem), glerr, eta, bforce(2), ftrac(2, 1)
   double precision :: xpts(2, npts), spts(3, npts), sex(3), xi(2, ngp), shp(4), dshp(2, 4), xj(2, 2)
   integer :: conn(4, nelem), fnodes(2, 1), fkind(1), epts(npts), stat, i, j, e, g, a, n
   character(len=256) :: errmsg

   ! Nodes: a regular grid with interior nodes moved by up to 0.2 of a cell.
   do j = 0, ny
      do i = 0, nx
         n = 1 + i + (nx + 1)*j
         coords(1, n) = 2.0d0*i/nx
         coords(2, n) = 1.0d0*j/ny
         if (i > 0 .and. i < nx) coords(1, n) = coords(1, n) + 0.2d0*(2.0d0/nx)*sin(1.3d0*i + 2.1d0*j)
         if (j > 0 .and. j < ny) coords(2, n) = coords(2, n) + 0.2d0*(1.0d0/ny)*cos(0.7d0*i + 1.9d0*j)
      end do
   end do
   ! Elements, counter-clockwise (VTK quad order).
   do j = 1, ny
      do i = 1, nx
         e = i + nx*(j - 1)
         n = i + (nx + 1)*(j - 1)
         conn(:, e) = [n, n + 1, n + nx + 2, n + nx + 1]
      end do
   end do
   ! 2x2 Gauss points on [-1,1]^2, weights 1.
   xi(:, 1) = [-1.0d0, -1.0d0]/sqrt(3.0d0)
   xi(:, 2) = [1.0d0, -1.0d0]/sqrt(3.0d0)
   xi(:, 3) = [1.0d0, 1.0d0]/sqrt(3.0d0)
   xi(:, 4) = [-1.0d0, 1.0d0]/sqrt(3.0d0)
   do e = 1, nelem
      do g = 1, ngp
         shp = 0.25d0*[(1 - xi(1, g))*(1 - xi(2, g)), (1 + xi(1, g))*(1 - xi(2, g)), &
            & (1 + xi(1, g))*(1 + xi(2, g)), (1 - xi(1, g))*(1 + xi(2, g))]
         dshp(1, :) = 0.25d0*[-(1 - xi(2, g)), (1 - xi(2, g)), (1 + xi(2, g)), -(1 + xi(2, g))]
         dshp(2, :) = 0.25d0*[-(1 - xi(1, g)), -(1 + xi(1, g)), (1 + xi(1, g)), (1 - xi(1, g))]
         gp(:, g, e) = 0.0d0
         xj = 0.0d0
         do a = 1, 4
            gp(:, g, e) = gp(:, g, e) + shp(a)*coords(:, conn(a, e))
            xj(:, 1) = xj(:, 1) + dshp(1, a)*coords(:, conn(a, e))
            xj(:, 2) = xj(:, 2) + dshp(2, a)*coords(:, conn(a, e))
         end do
         gw(g, e) = abs(xj(1, 1)*xj(2, 2) - xj(1, 2)*xj(2, 1))
         call field(gp(:, g, e), gs(:, g, e))
      end do
   end do
   bforce = 0.0d0
   fnodes = 0
   fkind = 0
   ftrac = 0.0d0
   xpts(:, 1) = [0.5d0, 0.5d0]
   xpts(:, 2) = [1.7d0, 0.2d0]
   epts = 0

   call sprc_recover_mesh(2, nnode, coords, quad4, 4, nelem, conn, ngp, gp, gw, 3, gs, planestress, 1.0d3, &
      & 0.3d0, sprc, bforce, 0, 2, fnodes, fkind, ftrac, npts, xpts, epts, nodal, elerr, glerr, eta, spts, &
      & stat, errmsg)
   if (stat /= 0) then
      write (*, '(a,i0,a,a)') 'sprc_recover_mesh failed, stat = ', stat, ': ', trim(errmsg)
      stop 1
   end if

   write (*, '(a)') '  node         x         y    sxx*     sxx    syy*     syy    sxy*     sxy'
   do n = 1, nnode, 5
      call field(coords(:, n), sex)
      write (*, '(i6,2f10.4,6f8.4)') n, coords(:, n), (nodal(a, n), sex(a), a=1, 3)
   end do
   write (*, '(/,a)') ' element  ZZ error'
   do e = 1, nelem, 4
      write (*, '(i8,es10.2)') e, elerr(e)
   end do
   write (*, '(/,a,es10.3,a,f8.4)') ' global ZZ estimate ', glerr, ',  eta = ', eta
   do i = 1, npts
      call field(xpts(:, i), sex)
      write (*, '(a,2f6.2,a,3f9.4,a,3f9.4)') ' at', xpts(:, i), ': recovered', spts(:, i), ', exact', sex
   end do

contains

   !> The known field: sigma = (phi_yy, phi_xx, -phi_xy), phi = (x^4 - 6 x^2 y^2 + y^4)/10.
   subroutine field(x, s)
      double precision, intent(in) :: x(2)
      double precision, intent(out) :: s(3)
      s = 0.1d0*[-12*x(1)**2 + 12*x(2)**2, 12*x(1)**2 - 12*x(2)**2, 24*x(1)*x(2)]
   end subroutine field

end program legacy_recovery
