!> A legacy-style caller of the contact recovery: two quad4 blocks on non-matching meshes,
!> [0,2] x [-1,0] (4 x 2 elements, the slave) pressed against [0,2] x [0,1] (5 x 3, the
!> master), frictionless. The FE stresses at the 2x2 Gauss points are replaced by a known
!> field that satisfies the contact law (sigma_yy = -1 - 0.2 x, sigma_xx = 0.5 y, sigma_xy = 0:
!> in equilibrium, no shear on y = 0), one call of sprc_recover_contact_mesh, then the
!> recovered pressures of both bodies at the contact points against the exact 1 + 0.2 x.
program legacy_contact
   use sprc_legacy, only: sprc_recover_contact_mesh
   implicit none
   integer, parameter :: nx1 = 4, ny1 = 2, nx2 = 5, ny2 = 3, ngp = 4, mpts = 2*nx1
   integer, parameter :: n1 = (nx1 + 1)*(ny1 + 1), e1 = nx1*ny1, n2 = (nx2 + 1)*(ny2 + 1), e2 = nx2*ny2
   integer, parameter :: quad4 = 9, planestrain = 2, sprc = 2, frictionless = 1
   double precision :: x1(2, n1), gp1(2, ngp, e1), gw1(ngp, e1), gs1(3, ngp, e1), nodal1(3, n1), err1(e1)
   double precision :: x2(2, n2), gp2(2, ngp, e2), gw2(ngp, e2), gs2(3, ngp, e2), nodal2(3, n2), err2(e2)
   double precision :: slip1(2, nx1), slip2(2, nx2), xc(2, mpts), pc(mpts), pcm(mpts), jc(2, mpts)
   double precision :: glerr1, eta1, glerr2, eta2, worst
   integer :: c1(4, e1), c2(4, e2), f1(2, nx1), f2(2, nx2), law1(nx1), law2(nx2), npts, stat, i
   character(len=256) :: errmsg

   call block(nx1, ny1, -1.0d0, x1, c1, gp1, gw1, gs1)
   call block(nx2, ny2, 0.0d0, x2, c2, gp2, gw2, gs2)
   ! Contact facets: the slave's top row of sides, the master's bottom row (1-based nodes).
   do i = 1, nx1
      f1(:, i) = [ny1*(nx1 + 1) + i, ny1*(nx1 + 1) + i + 1]
   end do
   do i = 1, nx2
      f2(:, i) = [i, i + 1]
   end do
   law1 = frictionless
   law2 = frictionless
   slip1 = 0.0d0
   slip2 = 0.0d0

   call sprc_recover_contact_mesh(2, 3, planestrain, sprc, &
      & n1, x1, quad4, 4, e1, c1, ngp, gp1, gw1, gs1, 210.0d3, 0.3d0, &
      & n2, x2, quad4, 4, e2, c2, ngp, gp2, gw2, gs2, 70.0d3, 0.33d0, &
      & 2, nx1, f1, law1, slip1, 2, nx2, f2, law2, slip2, 0.0d0, mpts, &
      & nodal1, err1, glerr1, eta1, nodal2, err2, glerr2, eta2, npts, xc, pc, pcm, jc, stat, errmsg)
   if (stat /= 0) then
      write (*, '(a,i0,a,a)') 'sprc_recover_contact_mesh failed, stat = ', stat, ': ', trim(errmsg)
      stop 1
   end if

   write (*, '(a)') '        x   p slave  p master   p exact     jump_y'
   worst = 0.0d0
   do i = 1, npts
      write (*, '(f9.4,3f10.6,es11.2)') xc(1, i), pc(i), pcm(i), 1.0d0 + 0.2d0*xc(1, i), jc(2, i)
      worst = max(worst, abs(pc(i) - 1.0d0 - 0.2d0*xc(1, i)), abs(pcm(i) - 1.0d0 - 0.2d0*xc(1, i)))
   end do
   write (*, '(/,a,es10.2)') ' largest pressure error ', worst
   write (*, '(a,2es10.2)') ' ZZ estimates (slave, master) ', glerr1, glerr2

contains

   !> A quad4 mesh of [0,2] x [y0, y0 + 1], nx x ny elements, 2x2 Gauss points, the field.
   subroutine block(nx, ny, y0, x, c, gp, gw, gs)
      integer, intent(in) :: nx, ny
      double precision, intent(in) :: y0
      double precision, intent(out) :: x(:, :), gp(:, :, :), gw(:, :), gs(:, :, :)
      integer, intent(out) :: c(:, :)
      double precision :: g, r(4), t(4), shp(4), hx, hy
      integer :: i, j, e, n, q, a

      hx = 2.0d0/nx
      hy = 1.0d0/ny
      do j = 0, ny
         do i = 0, nx
            x(:, 1 + i + (nx + 1)*j) = [hx*i, y0 + hy*j]
         end do
      end do
      g = 0.5d0/sqrt(3.0d0)
      r = [0.5d0 - g, 0.5d0 + g, 0.5d0 + g, 0.5d0 - g]
      t = [0.5d0 - g, 0.5d0 - g, 0.5d0 + g, 0.5d0 + g]
      do j = 1, ny
         do i = 1, nx
            e = i + nx*(j - 1)
            n = i + (nx + 1)*(j - 1)
            c(:, e) = [n, n + 1, n + nx + 2, n + nx + 1]
            do q = 1, 4
               shp = [(1 - r(q))*(1 - t(q)), r(q)*(1 - t(q)), r(q)*t(q), (1 - r(q))*t(q)]
               gp(:, q, e) = 0.0d0
               do a = 1, 4
                  gp(:, q, e) = gp(:, q, e) + shp(a)*x(:, c(a, e))
               end do
               gw(q, e) = 0.25d0*hx*hy
               gs(:, q, e) = [0.5d0*gp(2, q, e), -1.0d0 - 0.2d0*gp(1, q, e), 0.0d0]
            end do
         end do
      end do
   end subroutine block

end program legacy_contact
