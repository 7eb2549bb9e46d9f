!> Element library for recovery on a caller's unstructured mesh: shape functions,
!> vertex partition of unity, reference node positions, the isoparametric map and its
!> inverse, and facet quadrature (points, weight*|J|, unit normal).
!>
!> Element type codes are the VTK cell type ids (part of the C API; never renumber),
!> and local node order is VTK's (`sprc_core_lagrange`; tri3 (0,0) (1,0) (0,1) and tet4 (0,0,0)
!> (1,0,0) (0,1,0) (0,0,1) on the unit simplex).
!> The vertices are the first 2^dim (dim+1 for simplices) nodes; the vertex partition of
!> unity (for the polynomial union, thesis eq. 102) is the linear element on them (quad4 for
!> quad9, hex8 for hex27).
!>
!> Facets (boundary pieces the caller names by their nodes) by their node count:
!> 2D: 2 nodes line2, 3 nodes line3 (VTK_QUADRATIC_EDGE: the two ends, then the midpoint);
!> 3D: 3 nodes tri3, 4 nodes quad4, 9 nodes quad9 (VTK orders as above). Facet quadrature:
!> Gauss 2 (line2) or 3 (line3) points, the 3-point degree-2 rule on triangles, 2x2 (quad4)
!> or 3x3 (quad9) Gauss. The normal returned here follows the facet's parametrisation
!> ((dy, -dx) of the tangent in 2D, t1 x t2 in 3D); the producer orients it.
module sprc_recovery_caller_mesh_element
   use sprc_core_kinds, only: wp
   use sprc_core_gauss, only: gauss_legendre_nodes
   use sprc_core_lagrange, only: tensor_shape, idx1 => vtk_line2, idx1q => vtk_line3, quad4 => vtk_quad4, &
      & quad9 => vtk_quad9, hex8 => vtk_hex8, hex27 => vtk_hex27
   implicit none
   private

   public :: elem_tri3, elem_quad4, elem_tet4, elem_hex8, elem_quad9, elem_hex27
   public :: element_known, element_name, element_dim, element_nodes, element_vertices, element_degree
   public :: element_facet_nodes, element_simplex, element_facet_order
   public :: element_shape, element_vertex_shape, element_node_xi, element_center_xi, element_inside
   public :: element_map, element_inverse_map, max_element_nodes
   public :: facet_points, facet_npoints, max_facet_points, max_facet_nodes

   !> Element type codes (VTK cell type ids).
   integer, parameter :: elem_tri3 = 5, elem_quad4 = 9, elem_tet4 = 10, elem_hex8 = 12
   !> Quadratic Lagrange quadrilateral and hexahedron (VTK ids).
   integer, parameter :: elem_quad9 = 28, elem_hex27 = 29
   !> Largest node counts of an element and of a facet, largest facet quadrature.
   integer, parameter :: max_element_nodes = 27, max_facet_nodes = 9, max_facet_points = 9

contains

   !> True for a supported element type code.
   pure logical function element_known(etype)
      integer, intent(in) :: etype
      element_known = any(etype == [elem_tri3, elem_quad4, elem_tet4, elem_hex8, elem_quad9, elem_hex27])
   end function element_known

   !> Name of an element type, for messages ('unknown' otherwise).
   pure function element_name(etype) result(name)
      integer, intent(in) :: etype
      character(len=:), allocatable :: name
      select case (etype)
      case (elem_tri3); name = 'tri3'
      case (elem_quad4); name = 'quad4'
      case (elem_tet4); name = 'tet4'
      case (elem_hex8); name = 'hex8'
      case (elem_quad9); name = 'quad9'
      case (elem_hex27); name = 'hex27'
      case default; name = 'unknown'
      end select
   end function element_name

   !> Space dimension of an element type (0 if unknown).
   pure integer function element_dim(etype)
      integer, intent(in) :: etype
      select case (etype)
      case (elem_tri3, elem_quad4, elem_quad9); element_dim = 2
      case (elem_tet4, elem_hex8, elem_hex27); element_dim = 3
      case default; element_dim = 0
      end select
   end function element_dim

   !> Nodes per element (0 if unknown).
   pure integer function element_nodes(etype)
      integer, intent(in) :: etype
      select case (etype)
      case (elem_tri3); element_nodes = 3
      case (elem_quad4, elem_tet4); element_nodes = 4
      case (elem_hex8); element_nodes = 8
      case (elem_quad9); element_nodes = 9
      case (elem_hex27); element_nodes = 27
      case default; element_nodes = 0
      end select
   end function element_nodes

   !> Vertex nodes per element: the leading local nodes (0 if unknown).
   pure integer function element_vertices(etype)
      integer, intent(in) :: etype
      select case (etype)
      case (elem_tri3); element_vertices = 3
      case (elem_quad4, elem_quad9, elem_tet4); element_vertices = 4
      case (elem_hex8, elem_hex27); element_vertices = 8
      case default; element_vertices = 0
      end select
   end function element_vertices

   !> Polynomial degree of the element (1 or 2; 0 if unknown): the default recovery degree p.
   pure integer function element_degree(etype)
      integer, intent(in) :: etype
      select case (etype)
      case (elem_tri3, elem_quad4, elem_tet4, elem_hex8); element_degree = 1
      case (elem_quad9, elem_hex27); element_degree = 2
      case default; element_degree = 0
      end select
   end function element_degree

   !> Nodes of one facet of the element type (line2 2, line3 3, tri3 3, quad4 4, quad9 9).
   pure integer function element_facet_nodes(etype)
      integer, intent(in) :: etype
      select case (etype)
      case (elem_tri3, elem_quad4); element_facet_nodes = 2
      case (elem_quad9, elem_tet4); element_facet_nodes = 3
      case (elem_hex8); element_facet_nodes = 4
      case (elem_hex27); element_facet_nodes = 9
      case default; element_facet_nodes = 0
      end select
   end function element_facet_nodes

   !> True for the simplices (tri3, tet4).
   pure logical function element_simplex(etype)
      integer, intent(in) :: etype
      element_simplex = etype == elem_tri3 .or. etype == elem_tet4
   end function element_simplex

   !> Shape functions n(1:nen) and optionally their reference derivatives dn(1:dim, 1:nen)
   !> at the reference point xi(1:dim) (the element type must be known).
   pure subroutine element_shape(etype, xi, n, dn)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: n(:)
      real(wp), intent(out), optional :: dn(:, :)

      ! dn absent: values only (the estimate and the checks of given coordinates, per point).
      select case (etype)
      case (elem_tri3, elem_tet4)
         call simplex_shape(element_dim(etype), xi, n, dn)
      case (elem_quad4); call tensor_shape(quad4, 1, xi, n, dn)
      case (elem_quad9); call tensor_shape(quad9, 2, xi, n, dn)
      case (elem_hex8); call tensor_shape(hex8, 1, xi, n, dn)
      case (elem_hex27); call tensor_shape(hex27, 2, xi, n, dn)
      end select
   end subroutine element_shape

   !> Vertex partition of unity nv(1:nvertex) at xi: the linear element on the vertices.
   pure subroutine element_vertex_shape(etype, xi, nv)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: nv(:)

      select case (etype)
      case (elem_tri3, elem_tet4)
         call simplex_shape(element_dim(etype), xi, nv)
      case (elem_quad4, elem_quad9); call tensor_shape(quad4, 1, xi, nv)
      case (elem_hex8, elem_hex27); call tensor_shape(hex8, 1, xi, nv)
      end select
   end subroutine element_vertex_shape

   !> Reference coordinates xi(1:dim) of local node j.
   pure subroutine element_node_xi(etype, j, xi)
      integer, intent(in) :: etype, j
      real(wp), intent(out) :: xi(:)
      integer :: d

      d = element_dim(etype)
      select case (etype)
      case (elem_tri3, elem_tet4)
         xi(1:d) = 0.0_wp
         if (j > 1) xi(j - 1) = 1.0_wp
      case (elem_quad4); xi(1:2) = real(quad4(:, j), wp)
      case (elem_quad9); xi(1:2) = 0.5_wp*real(quad9(:, j), wp)
      case (elem_hex8); xi(1:3) = real(hex8(:, j), wp)
      case (elem_hex27); xi(1:3) = 0.5_wp*real(hex27(:, j), wp)
      end select
   end subroutine element_node_xi

   !> Reference centroid.
   pure subroutine element_center_xi(etype, xi)
      integer, intent(in) :: etype
      real(wp), intent(out) :: xi(:)
      integer :: d
      d = element_dim(etype)
      xi(1:d) = merge(1.0_wp/real(d + 1, wp), 0.5_wp, element_simplex(etype))
   end subroutine element_center_xi

   !> True if xi lies in the reference element, enlarged by tol.
   pure logical function element_inside(etype, xi, tol)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xi(:), tol
      integer :: d
      d = element_dim(etype)
      if (element_simplex(etype)) then
         element_inside = all(xi(1:d) >= -tol) .and. sum(xi(1:d)) <= 1.0_wp + tol
      else
         element_inside = all(xi(1:d) >= -tol) .and. all(xi(1:d) <= 1.0_wp + tol)
      end if
   end function element_inside

   !> Whether the distinct local nodes loc(1:nfn) of an element are the nodes of one of its
   !> sides (2D) / faces (3D): on one face of the reference cell (any d distinct vertices of
   !> a simplex are), and `perm`, an order of them that parametrises the facet as
   !> facet_points expects (VTK line2 / line3 / tri3 / quad4 / quad9): the given order if it
   !> does (corners in cyclic order, then mid-sides between them, then the centre), else the
   !> face's own order in its two in-face reference axes.
   pure subroutine element_facet_order(etype, loc, perm, ok)
      integer, intent(in) :: etype, loc(:)
      integer, intent(out) :: perm(:)
      logical, intent(out) :: ok
      ! Reference facet nodes in VTK order: a line's in u, a quad's in (u, v).
      real(wp), parameter :: ref(2, 9) = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 1.0_wp, &
         & 0.5_wp, 0.0_wp, 1.0_wp, 0.5_wp, 0.5_wp, 1.0_wp, 0.0_wp, 0.5_wp, 0.5_wp, 0.5_wp], [2, 9])
      real(wp), parameter :: ref_line(3) = [0.0_wp, 1.0_wp, 0.5_wp]
      real(wp) :: xi(3, max_facet_nodes), uv(2, max_facet_nodes), r(2)
      integer :: n, d, a, j, k, m, slot(max_facet_nodes)

      n = size(loc)
      d = element_dim(etype)
      perm(1:n) = [(a, a=1, n)]
      ok = element_simplex(etype)
      if (ok) return
      do a = 1, n
         call element_node_xi(etype, loc(a), xi(:, a))
      end do
      do k = 1, d
         if (all(xi(k, 1:n) == 0.0_wp) .or. all(xi(k, 1:n) == 1.0_wp)) exit
      end do
      if (k > d) return
      m = 0
      do j = 1, d
         if (j == k) cycle
         m = m + 1
         uv(m, 1:n) = xi(j, 1:n)
      end do
      ! The slot of each node among the reference facet's nodes; distinct nodes, distinct slots.
      slot(1:n) = 0
      do a = 1, n
         do j = 1, n
            r = ref(:, j)
            if (d == 2) r(1) = ref_line(j)
            if (all(uv(1:d - 1, a) == r(1:d - 1))) slot(a) = j
         end do
      end do
      if (any(slot(1:n) == 0)) return
      ok = .true.
      if (parametrises()) return
      do a = 1, n
         perm(slot(a)) = a
      end do
   contains
      !> The given order parametrises the facet.
      pure logical function parametrises() result(yes)
         integer :: c, cn
         if (d == 2) then
            yes = n == 2 .or. uv(1, 3) == 0.5_wp
            return
         end if
         yes = .false.
         do c = 1, 4
            cn = mod(c, 4) + 1
            if (any(uv(1:2, c) == 0.5_wp)) return
            if (count(uv(1:2, c) /= uv(1:2, cn)) /= 1) return
            if (n == 9) then
               if (any(uv(1:2, c + 4) /= 0.5_wp*(uv(1:2, c) + uv(1:2, cn)))) return
            end if
         end do
         yes = .true.
      end function parametrises
   end subroutine element_facet_order

   !> Physical point x(1:dim) of reference point xi; xe(1:dim, 1:nen) are the element's nodes.
   pure subroutine element_map(etype, xe, xi, x)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xe(:, :), xi(:)
      real(wp), intent(out) :: x(:)
      real(wp) :: n(max_element_nodes)
      integer :: d, nen

      d = element_dim(etype)
      nen = element_nodes(etype)
      call element_shape(etype, xi, n)
      x(1:d) = matmul(xe(1:d, 1:nen), n(1:nen))
   end subroutine element_map

   !> Reference coordinates xi of the physical point x by Newton's method on the
   !> isoparametric map, started at the centroid; converged = within 50 steps, the last step
   !> is below 1e-13 (reference units) or below the round-off of the map itself: the
   !> residual x - sum_a N_a x_a carries an error up to (nen + 2) eps (|x| + sum_a |N_a| |x_a|)
   !> (a sum of nen + 1 products), which J^-1 turns into reference units. An element small
   !> against its distance from the origin (|x|/h ~ 1e3 and more) sits there, far above
   !> 1e-13. Affine elements converge in one or two steps. The small Jacobian is inverted
   !> by its adjugate (2x2, 3x3).
   !> With `guess` Newton starts there (a point's reference coordinates in a like element:
   !> then one step confirms them) and falls back to the centroid if that fails.
   pure subroutine element_inverse_map(etype, xe, x, xi, converged, guess)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xe(:, :), x(:)
      real(wp), intent(out) :: xi(:)
      logical, intent(out) :: converged
      real(wp), intent(in), optional :: guess(:)

      if (present(guess)) then
         xi(1:element_dim(etype)) = guess(1:element_dim(etype))
         call newton(etype, xe, x, xi, converged)
         if (converged) return
      end if
      call element_center_xi(etype, xi)
      call newton(etype, xe, x, xi, converged)
   end subroutine element_inverse_map

   !> Newton's iteration of `element_inverse_map` from xi (loops written out: it runs per
   !> point; the round-off floor is computed only when a step is not already below 1e-13).
   pure subroutine newton(etype, xe, x, xi, converged)
      integer, intent(in) :: etype
      real(wp), intent(in) :: xe(:, :), x(:)
      real(wp), intent(inout) :: xi(:)
      logical, intent(out) :: converged
      real(wp) :: n(max_element_nodes), dn(3, max_element_nodes), jac(3, 3), inv(3, 3), r(3), step(3), det
      real(wp) :: map_size, floor, xmap(3)
      integer :: d, nen, it, a, k

      d = element_dim(etype)
      nen = element_nodes(etype)
      converged = .false.
      do it = 1, 50
         call element_shape(etype, xi, n, dn)
         xmap(1:d) = 0.0_wp
         jac(1:d, 1:d) = 0.0_wp
         do a = 1, nen
            xmap(1:d) = xmap(1:d) + xe(1:d, a)*n(a)
            do k = 1, d
               jac(1:d, k) = jac(1:d, k) + xe(1:d, a)*dn(k, a)
            end do
         end do
         r(1:d) = x(1:d) - xmap(1:d)
         call small_inverse(d, jac, inv, det)
         if (.not. (abs(det) > 0.0_wp)) return
         step(1:d) = 0.0_wp
         do k = 1, d
            step(1:d) = step(1:d) + inv(1:d, k)*r(k)
         end do
         if (.not. all(abs(step(1:d)) <= 1.0e3_wp)) return
         xi(1:d) = xi(1:d) + step(1:d)
         if (maxval(abs(step(1:d))) < 1.0e-13_wp) then
            converged = .true.
            return
         end if
         map_size = maxval(abs(x(1:d))) + sum(abs(n(1:nen)))*maxval(abs(xe(1:d, 1:nen)))
         floor = real(nen + 2, wp)*epsilon(1.0_wp)*map_size*maxval(sum(abs(inv(1:d, 1:d)), dim=2))
         if (maxval(abs(step(1:d))) < floor) then
            converged = .true.
            return
         end if
      end do
   end subroutine newton

   !> Number of quadrature points of a facet of `nfn` nodes (line2 2, line3 3, tri3 3,
   !> quad4 2x2, quad9 3x3: one per node, as it happens).
   pure integer function facet_npoints(nfn)
      integer, intent(in) :: nfn
      facet_npoints = nfn
   end function facet_npoints

   !> Quadrature of one facet of `nfn` nodes xf(1:dim, 1:nfn) in `dim` space dimensions:
   !> nq points x(1:dim, q), weights w(q) = weight*|J| and unit normals nrm(1:dim, q) of the
   !> facet's parametrisation (not oriented). A degenerate facet gives w = 0 and nrm = 0.
   pure subroutine facet_points(dim, nfn, xf, nq, x, w, nrm)
      integer, intent(in) :: dim, nfn
      real(wp), intent(in) :: xf(:, :)
      integer, intent(out) :: nq
      real(wp), intent(out) :: x(:, :), w(:), nrm(:, :)
      real(wp) :: gx(3), gw(3), xir(2, max_facet_points), wr(max_facet_points)
      real(wp) :: n(max_facet_nodes), d(3, max_element_nodes), t(3, 2), v(3), a
      integer :: ng, i, j, q

      if (dim == 3 .and. nfn == 3) then
         nq = 3
         xir(:, 1:3) = reshape([1.0_wp/6, 1.0_wp/6, 2.0_wp/3, 1.0_wp/6, 1.0_wp/6, 2.0_wp/3], [2, 3])
         wr(1:3) = 1.0_wp/6
      else
         ng = merge(3, 2, nfn == 3 .or. nfn == 9)
         call gauss_legendre_nodes(ng, gx, gw)
         gx(1:ng) = 0.5_wp*(gx(1:ng) + 1.0_wp)
         gw(1:ng) = 0.5_wp*gw(1:ng)
         if (dim == 2) then
            nq = ng
            xir(1, 1:ng) = gx(1:ng)
            xir(2, 1:ng) = 0.0_wp
            wr(1:ng) = gw(1:ng)
         else
            nq = 0
            do j = 1, ng
               do i = 1, ng
                  nq = nq + 1
                  xir(:, nq) = [gx(i), gx(j)]
                  wr(nq) = gw(i)*gw(j)
               end do
            end do
         end if
      end if
      do q = 1, nq
         select case (10*dim + nfn)
         case (22); call tensor_shape(idx1, 1, xir(:, q), n, d)
         case (23); call tensor_shape(idx1q, 2, xir(:, q), n, d)
         case (33); call simplex_shape(2, xir(:, q), n, d)
         case (34); call tensor_shape(quad4, 1, xir(:, q), n, d)
         case default; call tensor_shape(quad9, 2, xir(:, q), n, d)
         end select
         x(1:dim, q) = matmul(xf(1:dim, 1:nfn), n(1:nfn))
         t(1:dim, 1:dim - 1) = matmul(xf(1:dim, 1:nfn), transpose(d(1:dim - 1, 1:nfn)))
         if (dim == 2) then
            v(1:2) = [t(2, 1), -t(1, 1)]
         else
            v = [t(2, 1)*t(3, 2) - t(3, 1)*t(2, 2), t(3, 1)*t(1, 2) - t(1, 1)*t(3, 2), &
               & t(1, 1)*t(2, 2) - t(2, 1)*t(1, 2)]
         end if
         a = sqrt(sum(v(1:dim)**2))
         w(q) = wr(q)*a
         nrm(1:dim, q) = 0.0_wp
         if (a > 0.0_wp) nrm(1:dim, q) = v(1:dim)/a
      end do
   end subroutine facet_points

   !> Linear simplex shape functions in rdim reference dimensions (unit simplex).
   pure subroutine simplex_shape(rdim, xi, n, d)
      integer, intent(in) :: rdim
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: n(:)
      real(wp), intent(out), optional :: d(:, :)
      integer :: k

      n(1) = 1.0_wp - sum(xi(1:rdim))
      n(2:rdim + 1) = xi(1:rdim)
      if (.not. present(d)) return
      d(1:rdim, 1:rdim + 1) = 0.0_wp
      d(1:rdim, 1) = -1.0_wp
      do k = 1, rdim
         d(k, k + 1) = 1.0_wp
      end do
   end subroutine simplex_shape

   !> Inverse of a 2x2 or 3x3 matrix by its adjugate, and the determinant (inv undefined if 0).
   pure subroutine small_inverse(d, a, inv, det)
      integer, intent(in) :: d
      real(wp), intent(in) :: a(3, 3)
      real(wp), intent(out) :: inv(3, 3), det

      if (d == 2) then
         det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
         if (.not. (abs(det) > 0.0_wp)) return
         inv(1:2, 1:2) = reshape([a(2, 2), -a(2, 1), -a(1, 2), a(1, 1)], [2, 2])/det
      else
         inv(1, 1) = a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)
         inv(1, 2) = a(1, 3)*a(3, 2) - a(1, 2)*a(3, 3)
         inv(1, 3) = a(1, 2)*a(2, 3) - a(1, 3)*a(2, 2)
         inv(2, 1) = a(2, 3)*a(3, 1) - a(2, 1)*a(3, 3)
         inv(2, 2) = a(1, 1)*a(3, 3) - a(1, 3)*a(3, 1)
         inv(2, 3) = a(1, 3)*a(2, 1) - a(1, 1)*a(2, 3)
         inv(3, 1) = a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1)
         inv(3, 2) = a(1, 2)*a(3, 1) - a(1, 1)*a(3, 2)
         inv(3, 3) = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
         det = a(1, 1)*inv(1, 1) + a(1, 2)*inv(2, 1) + a(1, 3)*inv(3, 1)
         if (.not. (abs(det) > 0.0_wp)) return
         inv = inv/det
      end if
   end subroutine small_inverse

end module sprc_recovery_caller_mesh_element
