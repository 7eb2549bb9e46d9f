!> Tests of recovery on a caller's unstructured mesh (sprc_recovery_caller_mesh) and of the legacy
!> wrapper (sprc_legacy).
!>
!> The meshes, their isoparametric maps and Gauss rules are built here from a lattice, not
!> with the library's element module: node (i, j, k) of a (q m + 1)^dim lattice on [0,1]^dim,
!> vertex nodes (all indices multiples of q) moved by a smooth perturbation of 0.2 cell
!> (interior components only, so the sides stay planar), other nodes at the multilinear
!> average of their cell's vertices (straight-sided quad9 / hex27: then the isoparametric
!> image of a quadratic field is in Q2 and nodal interpolation of exact values is exact).
!> The map of a cell is the tensor Lagrange interpolation of its lattice nodes, indexed by
!> lattice offset; simplices are the Kuhn splits of the cells, mapped affinely. The library
!> sees the elements through the VTK tables written below (a wrong table would break every
!> exactness check).
!>
!> Exact fields: linear (any, with the body force b = -div sigma) and quadratic
!> sigma = Hess(phi) + const with phi harmonic (equilibrated with b = 0, compatible:
!> eps = Hess(phi)/(2 mu) up to scale). Tolerance: `tol` (below) of the field's magnitude.
module sprc_test_mesh_recovery
   use sprc_core_kinds, only: wp
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   use sprc_core_error, only: stat_invalid_input, stat_singular
   use sprc_core_material, only: plane_stress, plane_strain, solid
   use sprc_recovery_caller_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_recovery_eval, mesh_method_spr, &
      & mesh_method_sprc, facet_traction, facet_symmetry, facet_free, facet_pressure, elem_tri3, elem_quad4, &
      & elem_tet4, elem_hex8, elem_quad9, elem_hex27, mesh_reference_symmetric
   use sprc_legacy, only: sprc_recover_mesh
   use sprc_recovery_caller_mesh_check, only: check_duplicate_nodes
   use sprc_core_kinds, only: i8
   use sprc_core_text, only: rtoa
   use sprc_recovery_caller_mesh_element, only: facet_points, element_inverse_map, element_facet_order
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_add_point
   use sprc_recovery_patch_loop, only: patch_source_type, patch_loop_type, run_patch_loop, patch_capacity
   !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
   implicit none
   private

   public :: collect_mesh_recovery, case_type, build_case, node_id

   !> Round-off tier of values that pass through the patch solves (QR, KKT by dsysv), relative
   !> to the stress scale: sqrt(eps). The solves are backward stable, but the conditioning of a
   !> patch system is not estimated (rank decisions keep pivots down to recovery_rank_tol, so
   !> it is not bounded by a small number either); sqrt(eps) admits condition numbers up to
   !> 1/sqrt(eps) ~ 7e7 and is still 1e5 below the errors a wrong constraint or basis makes.
   real(wp), parameter :: tol = sqrt(epsilon(1.0_wp))

   !> Field ids.
   integer, parameter :: f_linear = 1, f_quadratic = 2, f_traction = 3, f_symmetry = 4, f_symmetry3 = 5

   !> A test mesh with its integration points and FE stresses.
   type :: case_type
      integer :: dim = 0, etype = 0, q = 1, m = 1, field = 0, analysis = 0
      real(wp), allocatable :: x(:, :), gp(:, :, :), gw(:, :), gs(:, :, :)
      integer, allocatable :: conn(:, :)
      real(wp) :: body(3) = 0.0_wp
      real(wp) :: scale = 1.0_wp
   end type case_type

   integer, parameter :: vtk_quad4(2, 4) = reshape([0, 0, 1, 0, 1, 1, 0, 1], [2, 4])
   integer, parameter :: vtk_quad9(2, 9) = reshape([0, 0, 2, 0, 2, 2, 0, 2, 1, 0, 2, 1, 1, 2, 0, 1, 1, 1], [2, 9])
   integer, parameter :: vtk_hex8(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, &
      & 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1], [3, 8])
   integer, parameter :: vtk_hex27(3, 27) = reshape([ &
      & 0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0, 0, 0, 2, 2, 0, 2, 2, 2, 2, 0, 2, 2, &
      & 1, 0, 0, 2, 1, 0, 1, 2, 0, 0, 1, 0, 1, 0, 2, 2, 1, 2, 1, 2, 2, 0, 1, 2, &
      & 0, 0, 1, 2, 0, 1, 2, 2, 1, 0, 2, 1, &
      & 0, 1, 1, 2, 1, 1, 1, 0, 1, 1, 2, 1, 1, 1, 0, 1, 1, 2, 1, 1, 1], [3, 27])

   !> A test mesh as a source of patches for the shared patch loop (the plainest one:
   !> the elements' points, h = 1).
   type, extends(patch_source_type) :: case_source_type
      type(case_type), pointer :: c => null()
   contains
      procedure :: fill => case_fill
      procedure :: points_of => case_points_of
   end type case_source_type

contains

   subroutine collect_mesh_recovery(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('linear_quad4', test_linear_quad4), &
         new_unittest('spr_linear_chunks', test_spr_chunks), &
         new_unittest('linear_tri3', test_linear_tri3), &
         new_unittest('linear_hex8', test_linear_hex8), &
         new_unittest('linear_tet4', test_linear_tet4), &
         new_unittest('quadratic_quad9', test_quadratic_quad9), &
         new_unittest('quadratic_hex27', test_quadratic_hex27), &
         new_unittest('eval_points', test_eval_points), &
         new_unittest('facet_quadrature', test_facet_quadrature), &
         new_unittest('traction_facets', test_traction_facets), &
         new_unittest('symmetry_facets', test_symmetry_facets), &
         new_unittest('symmetry_facets_3d', test_symmetry_facets_3d), &
         new_unittest('rank_deficient_expanded', test_rank_deficient), &
         new_unittest('thread_determinism', test_threads), &
         new_unittest('validation_errors', test_validation), &
         new_unittest('facet_errors', test_facet_errors), &
         new_unittest('facet_node_order', test_facet_order), &
         new_unittest('far_from_origin', test_far_from_origin), &
         new_unittest('huge_stresses', test_huge_stresses), &
         new_unittest('pressure_facets', test_pressure_facets), &
         new_unittest('duplicates', test_duplicates), &
         new_unittest('duplicate_check_dyadic_lattices', test_duplicate_probes), &
         new_unittest('c_index_messages', test_c_index_messages), &
         new_unittest('patch_loop_skip', test_patch_loop_skip), &
         new_unittest('degree_auto', test_degree_auto), &
         new_unittest('legacy_wrapper', test_legacy), &
         new_unittest('given_reference_coordinates', test_given_xi), &
         new_unittest('eval_binned_search', test_eval_binned) &
         ]
   end subroutine collect_mesh_recovery

   ! ------------------------------------------------------------------ exact fields

   !> Exact stress of field `id` at x (Voigt).
   pure subroutine exact(id, dim, x, s)
      integer, intent(in) :: id, dim
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: s(:)
      real(wp) :: a, b, c

      a = x(1)
      b = x(2)
      c = 0.0_wp
      if (dim == 3) c = x(3)
      select case (id)
      case (f_linear)
         if (dim == 2) then
            s(1:3) = [1.0_wp + 2*a + 3*b, -2.0_wp + 0.5_wp*a - b, 0.7_wp - 1.5_wp*a + 0.25_wp*b]
         else
            s(1:6) = [1.0_wp + 2*a + 3*b - c, -2.0_wp + 0.5_wp*a - b + 2*c, 0.5_wp - a + b + 1.5_wp*c, &
               & 0.7_wp - 1.5_wp*a + 0.25_wp*b + c, 0.3_wp + a - 0.5_wp*b + 0.2_wp*c, -0.4_wp + 0.6_wp*a + b - c]
         end if
      case (f_quadratic)
         if (dim == 2) then
            ! phi = x^4 - 6 x^2 y^2 + y^4 + x^3 - 3 x y^2 (harmonic); sigma = (phi_xx, phi_yy, phi_xy).
            s(1:3) = [12*a**2 - 12*b**2 + 6*a + 1.0_wp, -12*a**2 + 12*b**2 - 6*a + 2.0_wp, -24*a*b - 6*b + 0.5_wp]
         else
            ! phi = x^4 - 6x^2y^2 + y^4 + (y^4 - 6y^2z^2 + z^4)/2 + xyz (harmonic).
            s(1:6) = [12*a**2 - 12*b**2 + 1.0_wp, -12*a**2 + 18*b**2 - 6*c**2 + 2.0_wp, -6*b**2 + 6*c**2 - 1.0_wp, &
               & -24*a*b + c, -12*b*c + a + 0.5_wp, b - 0.3_wp]
         end if
      case (f_traction)
         ! sigma_xx, sigma_xy depend on x only: constant traction on the sides x = 0 and x = 1.
         s(1:3) = [1.0_wp + 2*a, -2.0_wp + 0.5_wp*a - b, 0.5_wp - a]
      case (f_symmetry)
         ! sigma_xy = 0 on y = 0.
         s(1:3) = [1.0_wp + 2*a + 3*b, -2.0_wp + 0.5_wp*a - b, 0.25_wp*b]
      case (f_symmetry3)
         ! sigma_yz = sigma_xz = 0 on z = 0.
         s(1:6) = [1.0_wp + 2*a + 3*b - c, -2.0_wp + 0.5_wp*a - b + 2*c, 0.5_wp - a + b + 1.5_wp*c, &
            & 0.7_wp - 1.5_wp*a + 0.25_wp*b + c, 0.2_wp*c, -0.5_wp*c]
      end select
   end subroutine exact

   !> Body force b = -div sigma of a field (constant for the fields above), by central
   !> differences of the exact field (exact for linear and quadratic fields up to round-off).
   pure subroutine body_force(id, dim, b)
      integer, intent(in) :: id, dim
      real(wp), intent(out) :: b(3)
      real(wp) :: sp(6), sm(6), x(3), hstep
      integer :: j, i, v

      b = 0.0_wp
      hstep = 0.25_wp
      do j = 1, dim
         x = 0.3_wp
         x(j) = 0.3_wp + hstep
         call exact(id, dim, x, sp)
         x(j) = 0.3_wp - hstep
         call exact(id, dim, x, sm)
         do i = 1, dim
            v = voigt(dim, i, j)
            b(i) = b(i) - (sp(v) - sm(v))/(2*hstep)
         end do
      end do
   end subroutine body_force

   pure integer function voigt(dim, i, j)
      integer, intent(in) :: dim, i, j
      integer, parameter :: v2(2, 2) = reshape([1, 3, 3, 2], [2, 2])
      integer, parameter :: v3(3, 3) = reshape([1, 4, 6, 4, 2, 5, 6, 5, 3], [3, 3])
      if (dim == 2) then
         voigt = v2(i, j)
      else
         voigt = v3(i, j)
      end if
   end function voigt

   ! ------------------------------------------------------------------ meshes

   pure integer function node_id(c, i, j, k)
      type(case_type), intent(in) :: c
      integer, intent(in) :: i, j, k
      integer :: n
      n = c%q*c%m + 1
      node_id = 1 + i + n*(j + n*k)
   end function node_id

   !> Build a case: mesh of m^dim cells, points of the rule (npt per direction for tensor
   !> cells, 0: the default), FE stresses = exact field + noise*perturbation.
   subroutine build_case(c, etype, m, field, noise, one_point)
      type(case_type), intent(out) :: c
      integer, intent(in) :: etype, m, field
      real(wp), intent(in) :: noise
      logical, intent(in), optional :: one_point
      integer :: d, q, n, i, j, k, nn
      real(wp) :: h, xv(3), s(6)

      c%etype = etype
      c%m = m
      c%field = field
      select case (etype)
      case (elem_tri3, elem_quad4, elem_quad9); c%dim = 2
      case default; c%dim = 3
      end select
      c%q = merge(2, 1, etype == elem_quad9 .or. etype == elem_hex27)
      c%analysis = merge(solid, plane_strain, c%dim == 3)
      if (etype == elem_quad4) c%analysis = plane_stress
      d = c%dim
      q = c%q
      n = q*m + 1
      nn = n**d
      h = 1.0_wp/m
      allocate (c%x(d, nn))
      ! Vertices first, then the averages.
      do k = 0, merge(n - 1, 0, d == 3)
         do j = 0, n - 1
            do i = 0, n - 1
               xv = real([i, j, k], wp)/real(q*m, wp)
               if (all(mod([i, j, k], q) == 0)) xv(1:d) = xv(1:d) + perturb([i, j, k]/q, m, d)*h
               c%x(:, node_id(c, i, j, k)) = xv(1:d)
            end do
         end do
      end do
      if (q == 2) call average_nodes(c)
      call build_cells(c, present(one_point))
      call body_force(field, d, c%body)
      allocate (c%gs(merge(3, 6, d == 2), size(c%gp, 2), size(c%gp, 3)))
      c%scale = 0.0_wp
      do k = 1, size(c%gp, 3)
         do j = 1, size(c%gp, 2)
            call exact(field, d, c%gp(:, j, k), s)
            c%scale = max(c%scale, maxval(abs(s(1:size(c%gs, 1)))))
            c%gs(:, j, k) = s(1:size(c%gs, 1)) + noise*sin(7*c%gp(1, j, k) + 3*c%gp(2, j, k) + 1.0_wp + &
               & [(real(i, wp), i=1, size(c%gs, 1))])*cos(5*c%gp(d, j, k))
         end do
      end do
   end subroutine build_case

   !> Smooth perturbation of vertex (i, j, k) of an m-lattice: 0.2 cell, interior components only.
   pure function perturb(ijk, m, d) result(p)
      integer, intent(in) :: ijk(3), m, d
      real(wp) :: p(d)
      integer :: l
      do l = 1, d
         p(l) = 0.0_wp
         if (ijk(l) > 0 .and. ijk(l) < m) p(l) = 0.2_wp*sin(1.7_wp*ijk(1) + 2.3_wp*ijk(2) + 3.1_wp*ijk(3) + l)
      end do
   end function perturb

   !> Non-vertex lattice nodes at the average of the vertices around them.
   subroutine average_nodes(c)
      type(case_type), intent(inout) :: c
      integer :: i, j, k, n, a, b, e, cnt
      real(wp) :: s(3)

      n = 2*c%m + 1
      do k = 0, merge(n - 1, 0, c%dim == 3)
         do j = 0, n - 1
            do i = 0, n - 1
               if (all(mod([i, j, k], 2) == 0)) cycle
               s = 0.0_wp
               cnt = 0
               do a = -1, 1, 2
                  do b = -1, 1, 2
                     do e = -1, 1, 2
                        if ((mod(i, 2) == 0 .and. a == 1) .or. (mod(j, 2) == 0 .and. b == 1) .or. &
                           & (mod(k, 2) == 0 .and. e == 1)) cycle
                        cnt = cnt + 1
                        s(1:c%dim) = s(1:c%dim) + c%x(:, node_id(c, i + merge(0, a, mod(i, 2) == 0), &
                           & j + merge(0, b, mod(j, 2) == 0), k + merge(0, e, mod(k, 2) == 0)))
                     end do
                  end do
               end do
               c%x(:, node_id(c, i, j, k)) = s(1:c%dim)/cnt
            end do
         end do
      end do
   end subroutine average_nodes

   !> Elements (VTK order), points and weights*|J| of every cell.
   subroutine build_cells(c, one_point)
      type(case_type), intent(inout) :: c
      logical, intent(in) :: one_point
      integer, parameter :: kuhn(3, 6) = reshape([1, 2, 3, 1, 3, 2, 2, 1, 3, 2, 3, 1, 3, 1, 2, 3, 2, 1], [3, 6])
      real(wp) :: rx(3, 27), rw(27)
      integer :: d, m, ncell, nsub, nen, ngp, e, ic, jc, kc, s, a, o(3), v(3, 4), l
      real(wp) :: ta, tb

      d = c%dim
      m = c%m
      ncell = m**d
      nsub = 1
      if (c%etype == elem_tri3) nsub = 2
      if (c%etype == elem_tet4) nsub = 6
      select case (c%etype)
      case (elem_tri3)
         nen = 3
         ngp = 3
         rx(1:2, 1:3) = reshape([1.0_wp/6, 1.0_wp/6, 2.0_wp/3, 1.0_wp/6, 1.0_wp/6, 2.0_wp/3], [2, 3])
         rw(1:3) = 1.0_wp/6
      case (elem_tet4)
         nen = 4
         ngp = 4
         ta = 0.5854101966249685_wp
         tb = 0.1381966011250105_wp
         rx(1:3, 1:4) = reshape([tb, tb, tb, ta, tb, tb, tb, ta, tb, tb, tb, ta], [3, 4])
         rw(1:4) = 1.0_wp/24
      case default
         nen = (c%q + 1)**d
         call tensor_rule(d, c%q + 1, rx, rw, ngp)
      end select
      if (one_point) then
         ngp = 1
         rx(:, 1) = 0.5_wp
         rw(1) = 1.0_wp
      end if
      allocate (c%conn(nen, ncell*nsub), c%gp(d, ngp, ncell*nsub), c%gw(ngp, ncell*nsub))
      e = 0
      do kc = 0, merge(m - 1, 0, d == 3)
         do jc = 0, m - 1
            do ic = 0, m - 1
               o = [ic, jc, kc]*c%q
               do s = 1, nsub
                  e = e + 1
                  select case (c%etype)
                  case (elem_quad4); call set_tensor(vtk_quad4)
                  case (elem_quad9); call set_tensor(vtk_quad9)
                  case (elem_hex8); call set_tensor(vtk_hex8)
                  case (elem_hex27); call set_tensor(vtk_hex27)
                  case (elem_tri3)
                     v(1:2, 1:3) = reshape([0, 0, 1, 0, 1, 1], [2, 3])
                     if (s == 2) v(1:2, 1:3) = reshape([0, 0, 1, 1, 0, 1], [2, 3])
                     call set_simplex(3)
                  case (elem_tet4)
                     v(:, 1) = 0
                     v(:, 2) = 0
                     v(kuhn(1, s), 2) = 1
                     v(:, 3) = v(:, 2)
                     v(kuhn(2, s), 3) = 1
                     v(:, 4) = 1
                     call set_simplex(4)
                  end select
               end do
            end do
         end do
      end do
   contains
      subroutine set_tensor(table)
         integer, intent(in) :: table(:, :)
         real(wp) :: x(3), jac(3, 3)
         integer :: g
         do a = 1, size(table, 2)
            c%conn(a, e) = node_id(c, o(1) + table(1, a), o(2) + table(2, a), o(3) + table(min(3, d), a)*(d - 2))
         end do
         do g = 1, ngp
            call tensor_map(c, o, rx(:, g), x, jac)
            c%gp(:, g, e) = x(1:d)
            c%gw(g, e) = rw(g)*abs(det(d, jac))
         end do
      end subroutine set_tensor
      subroutine set_simplex(nv)
         integer, intent(in) :: nv
         real(wp) :: xs(3, 4), jac(3, 3)
         integer :: g
         do a = 1, nv
            c%conn(a, e) = node_id(c, o(1) + v(1, a), o(2) + v(2, a), o(3) + v(min(3, d), a)*(d - 2))
            xs(1:d, a) = c%x(:, c%conn(a, e))
         end do
         do l = 1, d
            jac(1:d, l) = xs(1:d, l + 1) - xs(1:d, 1)
         end do
         do g = 1, ngp
            c%gp(:, g, e) = xs(1:d, 1) + matmul(jac(1:d, 1:d), rx(1:d, g))
            c%gw(g, e) = rw(g)*abs(det(d, jac))
         end do
      end subroutine set_simplex
   end subroutine build_cells

   !> Tensor Gauss rule with n (2 or 3) points per direction on [0,1]^d.
   subroutine tensor_rule(d, n, rx, rw, ngp)
      integer, intent(in) :: d, n
      real(wp), intent(out) :: rx(:, :), rw(:)
      integer, intent(out) :: ngp
      real(wp) :: g(3), w(3)
      integer :: i, j, k

      if (n == 2) then
         g(1:2) = 0.5_wp + [-0.5_wp, 0.5_wp]/sqrt(3.0_wp)
         w(1:2) = 0.5_wp
      else
         g = 0.5_wp + [-0.5_wp*sqrt(0.6_wp), 0.0_wp, 0.5_wp*sqrt(0.6_wp)]
         w = [5.0_wp, 8.0_wp, 5.0_wp]/18.0_wp
      end if
      ngp = 0
      do k = 1, merge(n, 1, d == 3)
         do j = 1, n
            do i = 1, n
               ngp = ngp + 1
               rx(1:d, ngp) = [g(i), g(j), g(k)]
               rw(ngp) = w(i)*w(j)
               if (d == 3) rw(ngp) = rw(ngp)*w(k)
            end do
         end do
      end do
   end subroutine tensor_rule

   !> Isoparametric map of the cell at lattice offset o: Lagrange interpolation of its
   !> (q+1)^d lattice nodes.
   subroutine tensor_map(c, o, xi, x, jac)
      type(case_type), intent(in) :: c
      integer, intent(in) :: o(3)
      real(wp), intent(in) :: xi(:)
      real(wp), intent(out) :: x(3), jac(3, 3)
      real(wp) :: l(0:2, 3), dl(0:2, 3), nval, dn(3)
      integer :: i, j, k, d, r, t

      d = c%dim
      do r = 1, d
         if (c%q == 1) then
            l(0:1, r) = [1.0_wp - xi(r), xi(r)]
            dl(0:1, r) = [-1.0_wp, 1.0_wp]
         else
            l(:, r) = [2*(xi(r) - 0.5_wp)*(xi(r) - 1), -4*xi(r)*(xi(r) - 1), 2*xi(r)*(xi(r) - 0.5_wp)]
            dl(:, r) = [4*xi(r) - 3, 4 - 8*xi(r), 4*xi(r) - 1]
         end if
      end do
      if (d == 2) then
         l(0, 3) = 1.0_wp
         dl(0, 3) = 0.0_wp
      end if
      x = 0.0_wp
      jac = 0.0_wp
      do k = 0, merge(c%q, 0, d == 3)
         do j = 0, c%q
            do i = 0, c%q
               nval = l(i, 1)*l(j, 2)*l(k, 3)
               dn = [dl(i, 1)*l(j, 2)*l(k, 3), l(i, 1)*dl(j, 2)*l(k, 3), l(i, 1)*l(j, 2)*dl(k, 3)]
               x(1:d) = x(1:d) + nval*c%x(:, node_id(c, o(1) + i, o(2) + j, o(3) + k))
               do t = 1, d
                  jac(1:d, t) = jac(1:d, t) + dn(t)*c%x(:, node_id(c, o(1) + i, o(2) + j, o(3) + k))
               end do
            end do
         end do
      end do
   end subroutine tensor_map

   pure real(wp) function det(d, a)
      integer, intent(in) :: d
      real(wp), intent(in) :: a(3, 3)
      if (d == 2) then
         det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
      else
         det = a(1, 1)*(a(2, 2)*a(3, 3) - a(2, 3)*a(3, 2)) - a(1, 2)*(a(2, 1)*a(3, 3) - a(2, 3)*a(3, 1)) + &
            & a(1, 3)*(a(2, 1)*a(3, 2) - a(2, 2)*a(3, 1))
      end if
   end function det

   !> Facets (line2 / line3 in 2D, quad4 / quad9 in 3D) of the side lattice(axis) = 0 (side 0)
   !> or = q m (side 1).
   subroutine side_facets(c, axis, side, fnodes)
      type(case_type), intent(in) :: c
      integer, intent(in) :: axis, side
      integer, allocatable, intent(out) :: fnodes(:, :)
      integer :: a, b, f, t, lat(3), p(2)
      integer :: table(2, 9), ntab

      if (c%dim == 2) then
         allocate (fnodes(c%q + 1, c%m))
         do f = 1, c%m
            do t = 1, c%q + 1
               lat = 0
               lat(axis) = side*c%q*c%m
               lat(3 - axis) = (f - 1)*c%q + merge(merge(0, c%q, t == 1), 1, t <= 2)
               fnodes(t, f) = node_id(c, lat(1), lat(2), 0)
            end do
         end do
      else
         ntab = 4
         table(:, 1:4) = vtk_quad4
         if (c%q == 2) then
            ntab = 9
            table = vtk_quad9
         end if
         p = pack([1, 2, 3], [1, 2, 3] /= axis)
         allocate (fnodes(ntab, c%m**2))
         f = 0
         do b = 0, c%m - 1
            do a = 0, c%m - 1
               f = f + 1
               do t = 1, ntab
                  lat(axis) = side*c%q*c%m
                  lat(p(1)) = a*c%q + table(1, t)
                  lat(p(2)) = b*c%q + table(2, t)
                  fnodes(t, f) = node_id(c, lat(1), lat(2), lat(3))
               end do
            end do
         end do
      end if
   end subroutine side_facets

   ! ------------------------------------------------------------------ checks

   !> Max |nodal - exact| over the nodes used by the mesh, relative to the field scale.
   real(wp) function nodal_error(c, res) result(err)
      type(case_type), intent(in) :: c
      type(mesh_recovery_type), intent(in) :: res
      real(wp) :: s(6)
      integer :: n, ns
      ns = res%nstress
      err = 0.0_wp
      do n = 1, size(c%x, 2)
         if (.not. any(c%conn == n)) cycle
         call exact(c%field, c%dim, c%x(:, n), s)
         err = max(err, maxval(abs(res%nodal(:, n) - s(1:ns))))
      end do
      err = err/c%scale
   end function nodal_error

   !> Exactness of both methods on a case: nodal stresses, ZZ estimate ~ 0.
   subroutine check_exact(c, error, label)
      type(case_type), intent(in) :: c
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: label
      type(mesh_recovery_type) :: res
      integer :: method
      character(len=4), parameter :: names(2) = ['spr ', 'sprc']

      do method = mesh_method_spr, mesh_method_sprc
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, method, &
            & res, error, body_force=c%body(1:c%dim))
         if (allocated(error)) return
         call check(error, nodal_error(c, res) <= tol, label//' '//trim(names(method))//': nodal stresses exact')
         if (allocated(error)) return
         call check(error, res%n_patches > 0 .and. res%norm_h > 0.0_wp, label//': patches and norm')
         if (allocated(error)) return
         ! ZZ error of an exact recovery: the relative estimate is round-off.
         call check(error, res%eta <= tol, label//' '//trim(names(method))//': eta ~ 0')
         if (allocated(error)) return
      end do
   end subroutine check_exact

   subroutine test_linear_quad4(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      call build_case(c, elem_quad4, 4, f_linear, 0.0_wp)
      call check_exact(c, error, 'quad4')
   end subroutine test_linear_quad4

   !> SPR on linear elements solves its patches in chunks and keeps no records
   !> (patches_to_nodal): a 128^2 quad4 mesh has 16,641 patches, more than one chunk, and a
   !> linear field is reproduced at every node, the last chunk's included (a chunk's values
   !> stored at another chunk's nodes, or left out, would not be).
   subroutine test_spr_chunks(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res

      call build_case(c, elem_quad4, 128, f_linear, 0.0_wp)
      call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_spr, res, error, body_force=c%body(1:c%dim))
      if (allocated(error)) return
      call check(error, res%n_patches == 129**2 .and. .not. allocated(res%recs), '16,641 patches, no records kept')
      if (allocated(error)) return
      call check(error, nodal_error(c, res) <= tol .and. res%eta <= tol, 'nodal stresses exact at every node')
   end subroutine test_spr_chunks

   subroutine test_linear_tri3(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      call build_case(c, elem_tri3, 4, f_linear, 0.0_wp)
      call check_exact(c, error, 'tri3')
   end subroutine test_linear_tri3

   subroutine test_linear_hex8(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      call build_case(c, elem_hex8, 3, f_linear, 0.0_wp)
      call check_exact(c, error, 'hex8')
   end subroutine test_linear_hex8

   subroutine test_linear_tet4(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      call build_case(c, elem_tet4, 2, f_linear, 0.0_wp)
      call check_exact(c, error, 'tet4')
   end subroutine test_linear_tet4

   subroutine test_quadratic_quad9(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      call build_case(c, elem_quad9, 3, f_quadratic, 0.0_wp)
      call check_exact(c, error, 'quad9')
   end subroutine test_quadratic_quad9

   subroutine test_quadratic_hex27(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      call build_case(c, elem_hex27, 2, f_quadratic, 0.0_wp)
      call check_exact(c, error, 'hex27')
   end subroutine test_quadratic_hex27

   !> The field at points: with the element given and searched, exact for exact data; the
   !> search finds the element (checked through the value); a point outside is an error.
   subroutine test_eval_points(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      real(wp) :: xp(2, 3), sp(3, 3), s(6)
      integer :: method, i

      call build_case(c, elem_quad9, 3, f_quadratic, 0.0_wp)
      xp = reshape([0.1_wp, 0.2_wp, 0.55_wp, 0.45_wp, 0.93_wp, 0.71_wp], [2, 3])
      do method = mesh_method_spr, mesh_method_sprc
         call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, method, &
            & res, error)
         if (allocated(error)) return
         call mesh_recovery_eval(res, xp, sp, error)
         if (allocated(error)) return
         do i = 1, 3
            call exact(f_quadratic, 2, xp(:, i), s)
            call check(error, maxval(abs(sp(:, i) - s(1:3))) <= tol*c%scale, 'searched point value')
            if (allocated(error)) return
         end do
         ! Element 1 is the cell at the origin: holds point 1.
         call mesh_recovery_eval(res, xp(:, 1:1), sp(:, 1:1), error, [1])
         if (allocated(error)) return
         call exact(f_quadratic, 2, xp(:, 1), s)
         call check(error, maxval(abs(sp(:, 1) - s(1:3))) <= tol*c%scale, 'given element value')
         if (allocated(error)) return
      end do
      call mesh_recovery_eval(res, xp(:, 3:3), sp(:, 1:1), error, [1])
      call expect(error, stat_invalid_input, 'is not in element 1')
      if (allocated(error)) return
      call mesh_recovery_eval(res, reshape([1.5_wp, 0.5_wp], [2, 1]), sp(:, 1:1), error)
      call expect(error, stat_invalid_input, 'is in no element')
   end subroutine test_eval_points

   !> Facet quadrature against hand values: length / area (sum of w|J|), unit normals
   !> perpendicular to the facet, and the first moment (centroid) of each facet; line2,
   !> line3, tri3, quad4, quad9 (a rectangle in the plane x = 1 with its VTK node order).
   subroutine test_facet_quadrature(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: x(3, 9), w(9), nrm(3, 9), xf(3, 9)
      integer :: nq

      xf(1:2, 1:3) = reshape([0.0_wp, 0.0_wp, 3.0_wp, 4.0_wp, 1.5_wp, 2.0_wp], [2, 3])
      call facet_points(2, 2, xf(1:2, 1:2), nq, x, w, nrm)
      call check_facet(nq, 2, 5.0_wp, [1.5_wp, 2.0_wp, 0.0_wp], [0.8_wp, -0.6_wp, 0.0_wp], 'line2')
      if (allocated(error)) return
      call facet_points(2, 3, xf(1:2, 1:3), nq, x, w, nrm)
      call check_facet(nq, 3, 5.0_wp, [1.5_wp, 2.0_wp, 0.0_wp], [0.8_wp, -0.6_wp, 0.0_wp], 'line3')
      if (allocated(error)) return
      xf(:, 1:3) = reshape([0.0_wp, 0.0_wp, 1.0_wp, 2.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 3.0_wp, 1.0_wp], [3, 3])
      call facet_points(3, 3, xf(:, 1:3), nq, x, w, nrm)
      call check_facet(nq, 3, 3.0_wp, [2.0_wp/3, 1.0_wp, 1.0_wp], [0.0_wp, 0.0_wp, 1.0_wp], 'tri3')
      if (allocated(error)) return
      ! Rectangle y in [0, 2], z in [0, 1] at x = 1, VTK quad9 order in (y, z).
      xf(1, 1:9) = 1.0_wp
      xf(2, 1:9) = [0.0_wp, 2.0_wp, 2.0_wp, 0.0_wp, 1.0_wp, 2.0_wp, 1.0_wp, 0.0_wp, 1.0_wp]
      xf(3, 1:9) = [0.0_wp, 0.0_wp, 1.0_wp, 1.0_wp, 0.0_wp, 0.5_wp, 1.0_wp, 0.5_wp, 0.5_wp]
      call facet_points(3, 4, xf(:, 1:4), nq, x, w, nrm)
      call check_facet(nq, 4, 2.0_wp, [1.0_wp, 1.0_wp, 0.5_wp], [1.0_wp, 0.0_wp, 0.0_wp], 'quad4')
      if (allocated(error)) return
      call facet_points(3, 9, xf(:, 1:9), nq, x, w, nrm)
      call check_facet(nq, 9, 2.0_wp, [1.0_wp, 1.0_wp, 0.5_wp], [1.0_wp, 0.0_wp, 0.0_wp], 'quad9')
   contains
      subroutine check_facet(nq_got, nq_want, measure, centroid, normal, label)
         integer, intent(in) :: nq_got, nq_want
         real(wp), intent(in) :: measure, centroid(3), normal(3)
         character(len=*), intent(in) :: label
         integer :: q, d
         d = merge(2, 3, label(1:4) == 'line')
         call check(error, nq_got, nq_want, label//': points')
         if (allocated(error)) return
         call check(error, sum(w(1:nq_got)), measure, 1.0e-14_wp, label//': measure', rel=.true.)
         if (allocated(error)) return
         do q = 1, d
            call check(error, sum(w(1:nq_got)*x(q, 1:nq_got))/measure, centroid(q), 1.0e-14_wp, label//': centroid')
            if (allocated(error)) return
         end do
         do q = 1, nq_got
            ! The sign is the producer's business: |n . normal| = 1.
            call check(error, abs(dot_product(nrm(1:d, q), normal(1:d))), 1.0_wp, 1.0e-14_wp, label//': normal')
            if (allocated(error)) return
         end do
      end subroutine check_facet
   end subroutine test_facet_quadrature

   !> Traction facets on x = 0 and x = 1 (constant exact traction): exact data stays exact;
   !> noisy data: SPR-C's nodal stresses on those sides satisfy sigma n = t, SPR's do not.
   subroutine test_traction_facets(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, allocatable :: f0(:, :), f1(:, :), fn(:, :), fk(:)
      real(wp), allocatable :: ft(:, :)
      real(wp) :: s0(6), s1(6), viol
      integer :: method, nf, n, j

      call build_case(c, elem_quad4, 4, f_traction, 0.0_wp)
      call side_facets(c, 1, 0, f0)
      call side_facets(c, 1, 1, f1)
      nf = size(f0, 2)
      fn = reshape([f0, f1], [2, 2*nf])
      allocate (fk(2*nf), ft(2, 2*nf))
      fk = facet_traction
      call exact(f_traction, 2, [0.0_wp, 0.0_wp], s0)
      call exact(f_traction, 2, [1.0_wp, 0.0_wp], s1)
      ! Outward normals (-1, 0) at x = 0 and (1, 0) at x = 1.
      ft(:, 1:nf) = spread(-[s0(1), s0(3)], 2, nf)
      ft(:, nf + 1:) = spread([s1(1), s1(3)], 2, nf)
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_sprc, res, error, body_force=c%body(1:2), facet_nodes=fn, facet_kind=fk, facet_traction=ft)
      if (allocated(error)) return
      call check(error, res%n_boundary_points == 2*2*nf, 'two points per line2 facet')
      if (allocated(error)) return
      call check(error, nodal_error(c, res) <= tol, 'exact data with traction facets stays exact')
      if (allocated(error)) return
      call check(error, res%eta <= tol, 'exact data: eta ~ 0')
      if (allocated(error)) return
      ! Normals are oriented away from the owning element: the facets' node order is free.
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_sprc, res, error, body_force=c%body(1:2), facet_nodes=fn(2:1:-1, :), facet_kind=fk, &
         & facet_traction=ft)
      if (allocated(error)) return
      call check(error, nodal_error(c, res) <= tol, 'reversed facet node order: still exact')
      if (allocated(error)) return

      call build_case(c, elem_quad4, 4, f_traction, 0.3_wp)
      do method = mesh_method_spr, mesh_method_sprc
         call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, method, &
            & res, error, body_force=c%body(1:2), facet_nodes=fn, facet_kind=fk, facet_traction=ft)
         if (allocated(error)) return
         viol = 0.0_wp
         do j = 1, size(fn, 2)
            n = fn(1, j)
            if (j <= nf) then
               viol = max(viol, abs(-res%nodal(1, n) - ft(1, j)), abs(-res%nodal(3, n) - ft(2, j)))
            else
               viol = max(viol, abs(res%nodal(1, n) - ft(1, j)), abs(res%nodal(3, n) - ft(2, j)))
            end if
         end do
         if (method == mesh_method_sprc) then
            call check(error, viol <= tol*c%scale, 'SPR-C nodal stresses satisfy the tractions')
         else
            ! The noise (0.3 on a field of size ~3) moves SPR's boundary values by O(0.1).
            call check(error, viol > 1.0e-3_wp, 'SPR nodal stresses do not satisfy the tractions')
         end if
         if (allocated(error)) return
      end do
   end subroutine test_traction_facets

   !> Symmetry facets (line3 of quad9) on y = 0, where sigma_xy = 0: exact data stays exact
   !> (degree 1, the field is linear); noisy data: SPR-C gives sigma_xy = 0 at the vertex and
   !> mid-side nodes on y = 0, SPR does not.
   subroutine test_symmetry_facets(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, allocatable :: fn(:, :), fk(:)
      integer :: method, j
      real(wp) :: viol

      call build_case(c, elem_quad9, 3, f_symmetry, 0.0_wp)
      call side_facets(c, 2, 0, fn)
      allocate (fk(size(fn, 2)))
      fk = facet_symmetry
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_sprc, res, error, body_force=c%body(1:2), facet_nodes=fn, facet_kind=fk, degree=1)
      if (allocated(error)) return
      call check(error, nodal_error(c, res) <= tol, 'exact data with symmetry facets stays exact')
      if (allocated(error)) return
      call build_case(c, elem_quad9, 3, f_symmetry, 0.3_wp)
      do method = mesh_method_spr, mesh_method_sprc
         call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, method, &
            & res, error, body_force=c%body(1:2), facet_nodes=fn, facet_kind=fk)
         if (allocated(error)) return
         viol = 0.0_wp
         do j = 1, size(fn, 2)
            ! Vertex nodes and mid-side nodes (the union of two patches with zero shear).
            viol = max(viol, maxval(abs(res%nodal(3, fn(:, j)))))
         end do
         if (method == mesh_method_sprc) then
            call check(error, viol <= tol*c%scale, 'SPR-C: zero shear on the symmetry line')
         else
            call check(error, viol > 1.0e-3_wp, 'SPR: shear on the symmetry line')
         end if
         if (allocated(error)) return
      end do
   end subroutine test_symmetry_facets

   !> 3D symmetry facets (quad4 faces of hex8 on z = 0): exact data stays exact; noisy data:
   !> SPR-C's nodal sigma_yz, sigma_xz vanish there.
   subroutine test_symmetry_facets_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, allocatable :: fn(:, :), fk(:)

      call build_case(c, elem_hex8, 2, f_symmetry3, 0.0_wp)
      call side_facets(c, 3, 0, fn)
      allocate (fk(size(fn, 2)))
      fk = facet_symmetry
      call recover_on_mesh(3, solid, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_sprc, res, error, body_force=c%body(1:3), facet_nodes=fn, facet_kind=fk)
      if (allocated(error)) return
      call check(error, nodal_error(c, res) <= tol, 'exact data with 3D symmetry facets stays exact')
      if (allocated(error)) return
      call build_case(c, elem_hex8, 2, f_symmetry3, 0.3_wp)
      call recover_on_mesh(3, solid, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_sprc, res, error, body_force=c%body(1:3), facet_nodes=fn, facet_kind=fk)
      if (allocated(error)) return
      call check(error, maxval(abs(res%nodal(5:6, fn(1, :)))) <= tol*c%scale, 'SPR-C: zero shear on z = 0')
   end subroutine test_symmetry_facets_3d

   !> One point per quad4: corner patches hold one point (< 3 terms) and are expanded; the
   !> linear field is still recovered exactly. Without expansion rounds: stat_singular.
   subroutine test_rank_deficient(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res

      call build_case(c, elem_quad4, 3, f_linear, 0.0_wp, one_point=.true.)
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_spr, res, error)
      if (allocated(error)) return
      ! By hand: 4 corner patches (1 point) and 8 side patches (2 points) have fewer points
      ! than the 3 terms of p = 1; the 4 interior patches (4 points) do not.
      call check(error, res%n_expanded, 12, 'corner and side patches expanded')
      if (allocated(error)) return
      call check(error, nodal_error(c, res) <= tol, 'expanded patches recover the linear field')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
         & mesh_method_spr, res, error, max_rounds=0)
      call expect(error, stat_singular, 'expand the patch')
   end subroutine test_rank_deficient

   !> Same bits with 1 and 3 threads (noisy data, SPR-C with facets, hex8).
   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res(2)
      integer, allocatable :: fn(:, :), fk(:)
      integer :: nt, nt0

      call build_case(c, elem_hex8, 3, f_symmetry3, 0.3_wp)
      call side_facets(c, 3, 0, fn)
      allocate (fk(size(fn, 2)))
      fk = facet_symmetry
      nt0 = 1
      !$ nt0 = omp_get_max_threads()
      do nt = 1, 2
         !$ call omp_set_num_threads(2*nt - 1)
         call recover_on_mesh(3, solid, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res(nt), error, body_force=c%body(1:3), facet_nodes=fn, facet_kind=fk)
         if (allocated(error)) exit
      end do
      !$ call omp_set_num_threads(nt0)
      if (allocated(error)) return
      call check(error, same(res(1)%nodal, res(2)%nodal) .and. same(res(1)%elem_err, res(2)%elem_err), &
         & 'bitwise identical nodal stresses and element errors')
   end subroutine test_threads

   !> Bitwise equality of two arrays (same shape assumed): no difference above zero.
   pure logical function same(a, b)
      real(wp), intent(in) :: a(..)
      real(wp), intent(in) :: b(..)
      same = .false.
      select rank (a)
      rank (1)
         select rank (b)
         rank (1); same = maxval(abs(a - b)) <= 0.0_wp
         end select
      rank (2)
         select rank (b)
         rank (2); same = maxval(abs(a - b)) <= 0.0_wp
         end select
      end select
   end function same

   !> An error with the status and a message containing `text`; clears it on success.
   subroutine expect(error, stat, text)
      type(error_type), allocatable, intent(inout) :: error
      integer, intent(in) :: stat
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: msg

      if (.not. allocated(error)) then
         call test_failed(error, 'expected an error containing "'//text//'"')
         return
      end if
      msg = error%message
      if (error%stat /= stat .or. index(msg, text) == 0) then
         deallocate (error)
         call test_failed(error, 'expected "'//text//'", got: '//msg)
         return
      end if
      deallocate (error)
   end subroutine expect

   !> Every validation path of the arrays and options.
   subroutine test_validation(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      real(wp), allocatable :: gw(:, :), gs(:, :, :), gp(:, :, :)
      integer, allocatable :: conn(:, :)
      real(wp) :: nan

      call build_case(c, elem_quad4, 2, f_linear, 0.0_wp)
      nan = 0.0_wp
      nan = nan/nan
      call run(2, c%analysis, c%etype, 1, 1.0e3_wp)
      call expect(error, stat_invalid_input, 'dim = 1')
      if (allocated(error)) return
      call run(2, solid, c%etype, 2, 1.0e3_wp)
      call expect(error, stat_invalid_input, 'analysis = 3 does not fit dim = 2')
      if (allocated(error)) return
      call run(2, c%analysis, 7, 2, 1.0e3_wp)
      call expect(error, stat_invalid_input, 'element_type = 7 is unknown')
      if (allocated(error)) return
      call run(2, c%analysis, elem_hex8, 2, 1.0e3_wp)
      call expect(error, stat_invalid_input, '3D element, dim = 2')
      if (allocated(error)) return
      call run(5, c%analysis, c%etype, 2, 1.0e3_wp)
      call expect(error, stat_invalid_input, 'method = 5')
      if (allocated(error)) return
      call run(1, c%analysis, c%etype, 2, -1.0_wp)
      call expect(error, stat_invalid_input, 'young')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, &
         & degree=4)
      call expect(error, stat_invalid_input, 'degree = 4')
      if (allocated(error)) return
      ! Shapes.
      call recover_on_mesh(2, c%analysis, c%x(:, 1:0), c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, &
         & error)
      call expect(error, stat_invalid_input, 'nodes has shape')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn(1:3, :), c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, &
         & error)
      call expect(error, stat_invalid_input, 'connectivity has shape')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp(:, :, 1:2), c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, &
         & res, error)
      call expect(error, stat_invalid_input, 'gp has shape')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw(1:2, :), c%gs, 1.0e3_wp, 0.3_wp, 1, &
         & res, error)
      call expect(error, stat_invalid_input, 'gw has shape')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs(1:2, :, :), 1.0e3_wp, 0.3_wp, 1, &
         & res, error)
      call expect(error, stat_invalid_input, 'gs has shape')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, &
         & body_force=[1.0_wp])
      call expect(error, stat_invalid_input, 'body_force has 1 entries')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, &
         & body_force=[1.0_wp, nan])
      call expect(error, stat_invalid_input, 'body_force is not finite')
      if (allocated(error)) return
      ! Values.
      conn = c%conn
      conn(3, 2) = 10
      call recover_on_mesh(2, c%analysis, c%x, c%etype, conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'connectivity(3, 2) = 10 is not a node in 1..9')
      if (allocated(error)) return
      conn(3, 2) = 0
      call recover_on_mesh(2, c%analysis, c%x, c%etype, conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'connectivity(3, 2) = 0')
      if (allocated(error)) return
      conn(3, 2) = conn(1, 2)
      call recover_on_mesh(2, c%analysis, c%x, c%etype, conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'element 2 repeats node')
      if (allocated(error)) return
      gw = c%gw
      gw(2, 3) = 0.0_wp
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'gw(2, 3) =')
      if (allocated(error)) return
      gw(2, 3) = -1.0_wp
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'must be finite and > 0')
      if (allocated(error)) return
      gs = c%gs
      gs(2, 1, 4) = nan
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'gs(:, 1, 4) is not finite')
      if (allocated(error)) return
      gp = c%gp
      gp(1, 1, 1) = nan
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'gp(:, 1, 1) is not finite')
      if (allocated(error)) return
      ! A point of element 4 handed to element 1.
      gp = c%gp
      gp(:, 1, 1) = c%gp(:, 1, 4)
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'gp(:, 1, 1) is not inside element 1')
      if (allocated(error)) return
      call mesh_recovery_eval(res, c%x, c%gs(:, 1, :), error)
      call expect(error, stat_invalid_input, 'not built')
   contains
      subroutine run(method, analysis, etype, dim, young)
         integer, intent(in) :: method, analysis, etype, dim
         real(wp), intent(in) :: young
         call recover_on_mesh(dim, analysis, c%x, etype, c%conn, c%gp, c%gw, c%gs, young, 0.3_wp, method, res, &
            & error)
      end subroutine run
   end subroutine test_validation

   !> element_facet_order on the unit square / cube (hand values): a quad's diagonal and a
   !> hex's face diagonal plane are no sides; the bottom face of hex8 / hex27 with its nodes
   !> in an order that is no parametrisation (corners 2 and 3 swapped; hex27 also mid-sides
   !> 5 and 7) is put in an order whose quadrature has the face's area 1 and its centroid
   !> (1/2, 1/2, 0), to round-off (the bow-tie order as given has area 2/sqrt(3)); a side
   !> given in order keeps it.
   subroutine test_facet_order(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: xc(3, 27), x(3, 9), w(9), nrm(3, 9)
      integer :: perm(9), loc(9), a, nq, k
      logical :: ok

      call element_facet_order(elem_quad4, [1, 3], perm(1:2), ok)
      call check(error, .not. ok, 'the diagonal of a quad4 is no side')
      if (allocated(error)) return
      call element_facet_order(elem_hex8, [1, 2, 7, 8], perm(1:4), ok)
      call check(error, .not. ok, 'a diagonal plane of a hex8 is no face')
      if (allocated(error)) return
      call element_facet_order(elem_quad4, [3, 2], perm(1:2), ok)
      call check(error, ok .and. all(perm(1:2) == [1, 2]), 'a quad4 side in reverse order, kept')
      if (allocated(error)) return
      do k = 1, 2
         if (k == 1) then
            do a = 1, 8
               xc(:, a) = real(vtk_hex8(:, a), wp)
            end do
            loc(1:4) = [1, 3, 2, 4]
            call element_facet_order(elem_hex8, loc(1:4), perm(1:4), ok)
            call facet_points(3, 4, xc(:, loc(perm(1:4))), nq, x, w, nrm)
         else
            do a = 1, 27
               xc(:, a) = 0.5_wp*real(vtk_hex27(:, a), wp)
            end do
            loc = [1, 3, 2, 4, 11, 10, 9, 12, 25]
            call element_facet_order(elem_hex27, loc, perm, ok)
            call facet_points(3, 9, xc(:, loc(perm)), nq, x, w, nrm)
         end if
         call check(error, ok, 'the bottom face in a shuffled order is a face')
         if (allocated(error)) return
         call check(error, abs(sum(w(1:nq)) - 1.0_wp) <= 10*epsilon(1.0_wp) .and. &
            & all(abs(matmul(x(:, 1:nq), w(1:nq)) - [0.5_wp, 0.5_wp, 0.0_wp]) <= 10*epsilon(1.0_wp)), &
            & 'the reordered face has area 1 and centroid (1/2, 1/2, 0)')
         if (allocated(error)) return
      end do
      call facet_points(3, 4, xc(:, [1, 3, 2, 4]), nq, x, w, nrm)
      call check(error, abs(sum(w(1:nq)) - 1.0_wp) > 0.1_wp, 'the bow-tie order as given has the wrong area')
   end subroutine test_facet_order

   !> Facet validation: kinds, shapes, node range, missing traction, not a side, interior.
   subroutine test_facet_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, allocatable :: fn(:, :)
      real(wp) :: ft(2, 2)

      call build_case(c, elem_quad4, 2, f_linear, 0.0_wp)
      call side_facets(c, 1, 0, fn)
      ft = 0.0_wp
      call go(fn, [1, 5], ft)
      call expect(error, stat_invalid_input, 'facet_kind(2) = 5')
      if (allocated(error)) return
      call go(fn, [1, 2])
      call expect(error, stat_invalid_input, 'facet_traction is not given')
      if (allocated(error)) return
      call go(fn, [1], ft)
      call expect(error, stat_invalid_input, 'facet_kind has 1 entries')
      if (allocated(error)) return
      call go(reshape([1, 2, 3, 4, 5, 6], [3, 2]), [2, 2])
      call expect(error, stat_invalid_input, 'facet_nodes has 3 rows')
      if (allocated(error)) return
      call go(reshape([1, 2, 3, 40], [2, 2]), [2, 2])
      call expect(error, stat_invalid_input, 'facet_nodes(2, 2) = 40')
      if (allocated(error)) return
      call go(fn, [1, 3], ft(:, 1:1))
      call expect(error, stat_invalid_input, 'facet_traction has shape')
      if (allocated(error)) return
      ! Nodes 1 and 9 are opposite corners of the mesh; nodes 4 and 5 share the middle edge
      ! of elements 1 and 3.
      call go(reshape([1, 9, 4, 5], [2, 2]), [2, 2])
      call expect(error, stat_invalid_input, 'facet 1 is not a side of any element: facet_nodes(:, 1) = (1 9) are '// &
         & 'not the nodes of one element')
      if (allocated(error)) return
      call go(reshape([4, 1, 4, 5], [2, 2]), [2, 3])
      call expect(error, stat_invalid_input, 'facet 2 is shared by elements 1 and 3')
      if (allocated(error)) return
      call go(reshape([1, 1, 4, 1], [2, 2]), [2, 3])
      call expect(error, stat_invalid_input, 'facet 1 is degenerate')
      if (allocated(error)) return
      ! Nodes 1 and 5 are opposite corners of element 1 (its diagonal), in either order.
      call go(reshape([1, 2, 5, 1], [2, 2]), [3, 3])
      call expect(error, stat_invalid_input, 'facet 2 is not a side of any element: facet_nodes(:, 2) = (5 1) are '// &
         & 'nodes of element 1 but not one of its sides')
      if (allocated(error)) return
      call go(reshape([1, 5], [2, 1]), [3])
      call expect(error, stat_invalid_input, 'facet_nodes(:, 1) = (1 5) are nodes of element 1 but not')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 2, res, &
         & error, facet_nodes=fn)
      call expect(error, stat_invalid_input, 'must be given together')
   contains
      subroutine go(fnodes, kinds, tr)
         integer, intent(in) :: fnodes(:, :), kinds(:)
         real(wp), intent(in), optional :: tr(:, :)
         call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 2, res, &
            & error, facet_nodes=fnodes, facet_kind=kinds, facet_traction=tr)
      end subroutine go
   end subroutine test_facet_errors


   !> Finite stresses of order 1e160 (issue 13, defect 2: their squares overflow): the
   !> stresses times 2**532 (1.4e160) give the estimate of the unscaled ones times 2**532 and
   !> the same eta, finite. A power of two scales every operation exactly; the tolerance is
   !> the file's tier, room for LAPACK's own scaling decisions inside the patch solves.
   subroutine test_huge_stresses(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res0, res
      real(wp), parameter :: big = 2.0_wp**532
      integer :: method

      call build_case(c, elem_quad4, 3, f_quadratic, 0.3_wp)
      do method = mesh_method_spr, mesh_method_sprc
         call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, method, &
            & res0, error)
         if (allocated(error)) return
         call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, big*c%gs, 1000.0_wp, 0.3_wp, method, &
            & res, error)
         if (allocated(error)) return
         call check(error, res%err/big, res0%err, tol, 'global error of huge stresses', rel=.true.)
         if (allocated(error)) return
         call check(error, res%norm_h/big, res0%norm_h, tol, 'norm of huge stresses', rel=.true.)
         if (allocated(error)) return
         call check(error, res%eta, res0%eta, tol, 'eta of huge stresses', rel=.true.)
         if (allocated(error)) return
         call check(error, maxval(abs(res%elem_err/big - res0%elem_err)) <= tol*maxval(res0%elem_err), &
            & 'element errors of huge stresses')
         if (allocated(error)) return
      end do
   end subroutine test_huge_stresses

   !> Pressure facets on a curved boundary (issue 13, defect 4): a quarter annulus
   !> 1 <= r <= 2 of curved quad9 (nodes on the circles), line3 facets on r = 2 with a
   !> pressure p, FE stresses the hydrostatic sigma = -p I, whose traction -p n turns along
   !> each facet. With the pressure kind SPR-C recovers it exactly (round-off, the file's
   !> tolerance); with the best constant traction per facet (-p times the chord's normal),
   !> the only way before, the traction rows contradict the field and it is not (error above
   !> 1e-6 p: the normal turns by pi/16 along a facet).
   subroutine test_pressure_facets(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, allocatable :: fn(:, :), fk(:)
      real(wp), allocatable :: ft(:, :)
      real(wp), parameter :: p = 3.0_wp, pi = acos(-1.0_wp)
      real(wp) :: chord(2), s(3)
      integer :: i, j, n, f, k

      call build_case(c, elem_quad9, 4, f_linear, 0.0_wp)
      n = c%q*c%m + 1
      do j = 0, n - 1
         do i = 0, n - 1
            c%x(:, node_id(c, i, j, 0)) = (1.0_wp + real(i, wp)/(n - 1))* &
               & [cos(0.5_wp*pi*j/(n - 1)), sin(0.5_wp*pi*j/(n - 1))]
         end do
      end do
      deallocate (c%conn, c%gp, c%gw)
      call build_cells(c, .false.)
      c%gs = 0.0_wp
      c%gs(1:2, :, :) = -p
      call side_facets(c, 1, 1, fn)
      allocate (fk(size(fn, 2)), ft(2, size(fn, 2)))
      do k = 1, 2
         fk = merge(facet_pressure, facet_traction, k == 1)
         do f = 1, size(fn, 2)
            chord = c%x(:, fn(2, f)) - c%x(:, fn(1, f))
            ft(:, f) = merge([p, 0.0_wp], -p*[chord(2), -chord(1)]/norm2(chord), k == 1)
         end do
         call recover_on_mesh(2, plane_strain, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res, error, facet_nodes=fn, facet_kind=fk, facet_traction=ft)
         if (allocated(error)) return
         s = 0.0_wp
         do i = 1, size(c%x, 2)
            s = max(s, abs(res%nodal(:, i) - [-p, -p, 0.0_wp]))
         end do
         if (k == 1) then
            call check(error, maxval(s) <= tol*p, 'pressure facets: the hydrostatic field is exact')
         else
            call check(error, maxval(s) > 1.0e-6_wp*p, 'constant tractions on curved facets: not exact')
         end if
         if (allocated(error)) return
      end do
   end subroutine test_pressure_facets

   !> Duplicate nodes (two used nodes at one point) and duplicate elements (the same
   !> vertices, here in another order) are input errors naming both (issue 13, defect 3).
   subroutine test_duplicates(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      real(wp), allocatable :: x(:, :)
      integer, allocatable :: conn(:, :)

      call build_case(c, elem_quad4, 2, f_linear, 0.0_wp)
      ! Node 10 at node 5 (the centre), used by element 4 instead of node 5.
      x = reshape([c%x, c%x(:, 5)], [2, 10])
      conn = c%conn
      where (conn(:, 4) == 5) conn(:, 4) = 10
      call recover_on_mesh(2, c%analysis, x, c%etype, conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'nodes 5 and 10 are at the same point')
      if (allocated(error)) return
      ! An unused node at the same point is harmless.
      call recover_on_mesh(2, c%analysis, x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      if (allocated(error)) return
      conn = c%conn
      conn(:, 4) = cshift(c%conn(:, 1), 1)
      call recover_on_mesh(2, c%analysis, c%x, c%etype, conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error)
      call expect(error, stat_invalid_input, 'elements 1 and 4 have the same vertices')
   end subroutine test_duplicates

   !> The duplicate-node check's hash table on coordinates with structure: the 257^2 nodes
   !> of the unit square's 256 x 256 lattice (dyadic fractions: their low mantissa bits are
   !> all zero), the 33^3 and 41^3 nodes of cube lattices (ties in all three coordinates) and
   !> the 256 x 256 lattice rotated (no structure, the control). Bound on the slots read per
   !> node: linear probing at load a with keys spread as by a random function costs
   !> (1 + 1/(1 - a)^2)/2 per insertion, 5 at the table's largest load 2/3 (2.5 at the load
   !> 1/2 these sizes give). A hash that maps such keys to a few slots reads O(n) per node.
   !> Then a duplicate among them is still found (the last node moved onto the first).
   subroutine test_duplicate_probes(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: x(:, :)
      integer(i8) :: probes
      integer :: n

      call lattice(2, 256, 0.0_wp)
      if (allocated(error)) return
      call lattice(3, 32, 0.0_wp)
      if (allocated(error)) return
      call lattice(3, 40, 0.0_wp)
      if (allocated(error)) return
      call lattice(2, 256, 0.3_wp)
      if (allocated(error)) return
      x(:, size(x, 2)) = x(:, 1)
      call check_duplicate_nodes(x, [(.true., n=1, size(x, 2))], .false., error)
      call expect(error, stat_invalid_input, 'nodes 1 and 66049 are at the same point')
   contains
      subroutine lattice(d, m, angle)
         integer, intent(in) :: d, m
         real(wp), intent(in) :: angle
         integer :: i, j, k
         real(wp) :: p(3)
         if (allocated(x)) deallocate (x)
         allocate (x(d, (m + 1)**d))
         n = 0
         do k = 0, merge(0, m, d == 2)
            do j = 0, m
               do i = 0, m
                  n = n + 1
                  p = [real(i, wp), real(j, wp), real(k, wp)]/m
                  x(1:2, n) = [cos(angle)*p(1) - sin(angle)*p(2), sin(angle)*p(1) + cos(angle)*p(2)]
                  if (d == 3) x(3, n) = p(3)
               end do
            end do
         end do
         call check_duplicate_nodes(x, [(.true., i=1, n)], .false., error, probes)
         if (allocated(error)) return
         call check(error, real(probes, wp)/n <= 5.0_wp, 'duplicate-node hash on a '//trim(merge('square', &
            & 'cube  ', d == 2))//' lattice: '//rtoa(real(probes, wp)/n)//' slots read per node, bound 5')
      end subroutine lattice
   end subroutine test_duplicate_probes

   !> With c_indices (the C and Python entries) messages name entries 0-based in C order
   !> with the C argument names (issue 13, defect 5): gw(2, 3) is gauss_weights[2][1].
   subroutine test_c_index_messages(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      real(wp), allocatable :: gw(:, :), gp(:, :, :), x(:, :)
      real(wp) :: sp(3, 1)

      call build_case(c, elem_quad4, 2, f_linear, 0.0_wp)
      gw = c%gw
      gw(2, 3) = 0.0_wp
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, &
         & c_indices=.true.)
      call expect(error, stat_invalid_input, 'gauss_weights[2][1] = ')
      if (allocated(error)) return
      gp = c%gp
      gp(:, 1, 1) = c%gp(:, 1, 4)
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, &
         & c_indices=.true.)
      call expect(error, stat_invalid_input, 'gauss_points[0][0] is not inside element 0')
      if (allocated(error)) return
      x = reshape([c%x, c%x(:, 5)], [2, 10])
      call recover_on_mesh(2, c%analysis, x, c%etype, reshape([c%conn(:, 1:3), merge(10, c%conn(:, 4), &
         & c%conn(:, 4) == 5)], [4, 4]), c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, c_indices=.true.)
      call expect(error, stat_invalid_input, 'nodes 4 and 9 are at the same point')
      if (allocated(error)) return
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 1, res, error, &
         & c_indices=.true.)
      if (allocated(error)) return
      call mesh_recovery_eval(res, reshape([0.9_wp, 0.9_wp], [2, 1]), sp, error, [1])
      call expect(error, stat_invalid_input, 'points[0] = ')
      if (allocated(error)) return
      call mesh_recovery_eval(res, reshape([0.9_wp, 0.9_wp], [2, 1]), sp, error, [1])
      call expect(error, stat_invalid_input, 'is not in element 0')
   end subroutine test_c_index_messages

   subroutine case_fill(self, node, elements, patch)
      class(case_source_type), intent(in) :: self
      integer, intent(in) :: node, elements(:)
      type(patch_type), intent(inout) :: patch
      integer :: i, g
      call patch_reset(patch, self%c%dim, self%c%analysis, 1000.0_wp, 0.3_wp, self%c%x(:, node), 1.0_wp)
      do i = 1, size(elements)
         do g = 1, size(self%c%gp, 2)
            call patch_add_point(patch, self%c%gp(:, g, elements(i)), self%c%gw(g, elements(i)), &
               & self%c%gs(:, g, elements(i)))
         end do
      end do
   end subroutine case_fill

   pure function case_points_of(self, elements) result(counts)
      class(case_source_type), intent(in) :: self
      integer, intent(in) :: elements(:)
      integer :: counts(2)
      counts = [size(self%c%gp, 2)*size(elements), 0]
   end function case_points_of

   !> The shared patch loop (sprc_recovery_patch_loop) with patches left to another module
   !> (contact): skipped patches stay empty with 0 rounds and elements, the others have the
   !> bits of the loop without skips (results depend on the patch alone). The linear field
   !> makes every solved patch exact (checked at its node: the file's tolerance).
   subroutine test_patch_loop_skip(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type), target :: c
      type(case_source_type) :: src
      type(patch_loop_type) :: opt
      type(recovered_patch_type), allocatable :: recs(:), recs_skip(:)
      integer, allocatable :: ne_ptr(:), ne_list(:), nodes(:), rounds(:), nel(:)
      logical, allocatable :: skip(:)
      integer :: n, e, a, failed, nn, ip
      real(wp) :: s(6)

      call build_case(c, elem_quad4, 3, f_linear, 0.2_wp)
      c%gs = 0.0_wp
      do e = 1, size(c%gp, 3)
         do a = 1, size(c%gp, 2)
            call exact(f_linear, 2, c%gp(:, a, e), s)
            c%gs(:, a, e) = s(1:3)
         end do
      end do
      src%c => c
      nn = size(c%x, 2)
      allocate (ne_ptr(nn + 1))
      ne_ptr = 0
      do e = 1, size(c%conn, 2)
         ne_ptr(c%conn(:, e) + 1) = ne_ptr(c%conn(:, e) + 1) + 1
      end do
      ne_ptr(1) = 1
      do n = 1, nn
         ne_ptr(n + 1) = ne_ptr(n + 1) + ne_ptr(n)
      end do
      allocate (ne_list(ne_ptr(nn + 1) - 1), nodes(nn))
      nodes = ne_ptr(1:nn)
      do e = 1, size(c%conn, 2)
         do a = 1, 4
            ne_list(nodes(c%conn(a, e))) = e
            nodes(c%conn(a, e)) = nodes(c%conn(a, e)) + 1
         end do
      end do
      nodes = [(n, n=1, nn)]
      opt = patch_loop_type(dim=2, degree=1, rounds_limit=2, sprc=.false.)
      opt%cap = patch_capacity(src, 2, 1, ne_ptr, ne_list, nodes)
      allocate (recs(nn), recs_skip(nn), rounds(nn), nel(nn), skip(nn))
      call run_patch_loop(opt, src, ne_ptr, ne_list, c%conn, nodes, recs, rounds, nel, failed, error)
      if (allocated(error)) return
      skip = mod(nodes, 3) == 0
      call run_patch_loop(opt, src, ne_ptr, ne_list, c%conn, nodes, recs_skip, rounds, nel, failed, error, skip)
      if (allocated(error)) return
      do ip = 1, nn
         if (skip(ip)) then
            call check(error, recs_skip(ip)%nterms == 0 .and. rounds(ip) == 0 .and. nel(ip) == 0, &
               & 'a skipped patch stays empty')
         else
            call check(error, recs_skip(ip)%nterms == recs(ip)%nterms .and. &
               & same(recs_skip(ip)%coef(1:3, 1:3), recs(ip)%coef(1:3, 1:3)), 'the other patches keep their bits')
            if (allocated(error)) return
            call exact(f_linear, 2, c%x(:, ip), s)
            call check(error, maxval(abs(recs(ip)%coef(1, 1:3) - s(1:3))) <= tol*c%scale, 'patch exact at its node')
         end if
         if (allocated(error)) return
      end do
   end subroutine test_patch_loop_skip

   !> The default degree is 'auto' (issue 13): SPR-C at p + 1 on quad9 and hex27, at p on
   !> linear elements; SPR at p.
   subroutine test_degree_auto(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, parameter :: etypes(3) = [elem_quad9, elem_hex27, elem_quad4], want(3) = [3, 3, 1]
      integer :: k

      do k = 1, 3
         call build_case(c, etypes(k), 2, f_linear, 0.0_wp)
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res, error, body_force=c%body(1:c%dim))
         if (allocated(error)) return
         call check(error, res%degree, want(k), 'SPR-C auto degree')
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res, error)
         if (allocated(error)) return
         call check(error, res%degree, merge(2, 1, k < 3), 'SPR auto degree')
         if (allocated(error)) return
      end do
   end subroutine test_degree_auto

   !> Elements small against their distance from the origin (issue 13, defect 1): the inverse
   !> map's stopping test follows the map's round-off, so a unit quad4 shifted by 1000 and a
   !> 4 x 4 grid of squares of side 0.01 at x = 10 (|x|/h = 1e3) are recovered, exactly for a
   !> linear field, and their own integration points evaluate in their elements. The field is
   !> the linear one of the unshifted mesh (linear in the moved coordinates too); the
   !> tolerance is the file's tier: the patch coordinates (x - x0)/h carry the round-off of
   !> x, eps |x|/h = 2e-13 relative here, far below it.
   subroutine test_far_from_origin(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      real(wp), allocatable :: x(:, :), gp(:, :, :)
      real(wp) :: s(6), sp(3, 1)
      integer :: k, n, e, i, method
      real(wp), parameter :: side(2) = [1.0_wp, 0.01_wp], offset(2) = [1000.0_wp, 10.0_wp]

      do k = 1, 2
         call build_case(c, elem_quad4, merge(1, 4, k == 1), f_linear, 0.0_wp)
         x = offset(k) + side(k)*c%x
         gp = offset(k) + side(k)*c%gp
         do method = mesh_method_spr, mesh_method_sprc
            call recover_on_mesh(2, c%analysis, x, c%etype, c%conn, gp, c%gw*side(k)**2, c%gs, 1000.0_wp, 0.3_wp, &
               & method, res, error, body_force=c%body(1:2)/side(k))
            if (allocated(error)) return
            do n = 1, size(c%x, 2)
               call exact(f_linear, 2, c%x(:, n), s)
               call check(error, maxval(abs(res%nodal(:, n) - s(1:3))) <= tol*c%scale, &
                  & 'far from the origin: nodal stresses exact')
               if (allocated(error)) return
            end do
            do e = 1, size(c%conn, 2)
               do i = 1, size(gp, 2)
                  call mesh_recovery_eval(res, gp(:, i:i, e), sp, error, [e])
                  if (allocated(error)) return
               end do
            end do
         end do
      end do
   end subroutine test_far_from_origin

   !> The legacy wrapper with plain double precision arrays: same nodal stresses as the
   !> modern call (free facets on y = 1 included), points evaluated, errors as stat/errmsg.
   subroutine test_legacy(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      integer, allocatable :: fn(:, :), fk(:)
      double precision, allocatable :: nodal(:, :), elerr(:), ftrac(:, :), nodal_auto(:, :)
      double precision :: glerr, eta, xpts(2, 2), spts(3, 2), bf(2)
      integer :: stat, epts(2)
      character(len=200) :: msg
      integer, allocatable :: conn(:, :)

      call build_case(c, elem_quad4, 3, f_quadratic, 0.2_wp)
      call side_facets(c, 2, 1, fn)
      allocate (fk(size(fn, 2)), ftrac(2, size(fn, 2)), nodal(3, size(c%x, 2)), elerr(size(c%conn, 2)))
      fk = facet_free
      ftrac = 0.0d0
      bf = c%body(1:2)
      xpts = reshape([0.2d0, 0.3d0, 0.8d0, 0.9d0], [2, 2])
      epts = [0, 0]
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 2, res, error, &
         & body_force=c%body(1:2), facet_nodes=fn, facet_kind=fk)
      if (allocated(error)) return
      call sprc_recover_mesh(2, size(c%x, 2), c%x, elem_quad4, 4, size(c%conn, 2), c%conn, size(c%gw, 1), c%gp, c%gw, &
         & 3, c%gs, plane_stress, 1.0d3, 0.3d0, 2, bf, size(fn, 2), 2, fn, fk, ftrac, 2, xpts, epts, nodal, elerr, &
         & glerr, eta, spts, stat, msg)
      call check(error, stat, 0, 'legacy stat: '//trim(msg))
      if (allocated(error)) return
      call check(error, same(nodal, res%nodal) .and. same(elerr, res%elem_err) .and. same([glerr, eta], &
         & [res%err, res%eta]), 'legacy outputs equal the modern result')
      if (allocated(error)) return
      call check(error, len_trim(msg) == 0 .and. glerr > 0.0d0, 'blank errmsg, positive estimate')
      if (allocated(error)) return
      ! The C API's degree flag: SPR-C at p + 1 = 2 on quad4 ('auto' is p).
      nodal_auto = nodal
      call recover_on_mesh(2, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1.0e3_wp, 0.3_wp, 2, res, error, &
         & body_force=c%body(1:2), facet_nodes=fn, facet_kind=fk, degree=2)
      if (allocated(error)) return
      call sprc_recover_mesh(2, size(c%x, 2), c%x, elem_quad4, 4, size(c%conn, 2), c%conn, size(c%gw, 1), c%gp, c%gw, &
         & 3, c%gs, plane_stress, 1.0d3, 0.3d0, 2 + 256, bf, size(fn, 2), 2, fn, fk, ftrac, 2, xpts, epts, nodal, elerr, &
         & glerr, eta, spts, stat, msg)
      call check(error, stat == 0 .and. same(nodal, res%nodal) .and. same([glerr, eta], [res%err, res%eta]) .and. &
         & maxval(abs(nodal - nodal_auto)) > 1.0d-6*maxval(abs(nodal_auto)), &
         & 'legacy with SPRC_RECOVERY_P_PLUS_1 equals degree 2 (and differs from auto): '//trim(msg))
      if (allocated(error)) return
      call sprc_recover_mesh(2, size(c%x, 2), c%x, elem_quad4, 4, size(c%conn, 2), c%conn, size(c%gw, 1), c%gp, c%gw, &
         & 3, c%gs, plane_stress, 1.0d3, 0.3d0, 2 + 1024, bf, size(fn, 2), 2, fn, fk, ftrac, 2, xpts, epts, nodal, &
         & elerr, glerr, eta, spts, stat, msg)
      call check(error, stat == stat_invalid_input .and. index(msg, 'method = 1026 has unknown flag bits') > 0 .and. &
         & maxval(abs(nodal)) <= 0.0d0, 'legacy: the contact flag on a plain recovery: '//trim(msg))
      if (allocated(error)) return
      call sprc_recover_mesh(2, size(c%x, 2), c%x, elem_quad4, 4, size(c%conn, 2), c%conn, size(c%gw, 1), c%gp, c%gw, &
         & 3, c%gs, plane_stress, 1.0d3, 0.3d0, 3 + 256, bf, size(fn, 2), 2, fn, fk, ftrac, 2, xpts, epts, nodal, &
         & elerr, glerr, eta, spts, stat, msg)
      call check(error, stat == stat_invalid_input .and. &
         & index(msg, 'method = 259 is not SPRC_METHOD_SPR (1) or SPRC_METHOD_SPRC (2)') > 0, &
         & 'legacy: method 3 with a flag: '//trim(msg))
      if (allocated(error)) return
      allocate (conn, source=c%conn)
      conn(2, 5) = 99
      call sprc_recover_mesh(2, size(c%x, 2), c%x, elem_quad4, 4, size(c%conn, 2), conn, size(c%gw, 1), c%gp, c%gw, &
         & 3, c%gs, plane_stress, 1.0d3, 0.3d0, 2, bf, size(fn, 2), 2, fn, fk, ftrac, 2, xpts, epts, nodal, elerr, &
         & glerr, eta, spts, stat, msg)
      call check(error, stat, stat_invalid_input, 'legacy stat on bad connectivity')
      if (allocated(error)) return
      call check(error, index(msg, 'connectivity(2, 5) = 99') > 0 .and. maxval(abs(nodal)) <= 0.0d0 .and. abs(glerr) <= 0.0d0, &
         & 'legacy errmsg names the entry, outputs zeroed: '//trim(msg))
      if (allocated(error)) return
      epts = [1, 0]
      call sprc_recover_mesh(2, size(c%x, 2), c%x, elem_quad4, 4, size(c%conn, 2), c%conn, size(c%gw, 1), c%gp, &
         & c%gw, 3, c%gs, plane_stress, 1.0d3, 0.3d0, 2, bf, size(fn, 2), 2, fn, fk, ftrac, 2, xpts + 5.0d0, epts, &
         & nodal, elerr, glerr, eta, spts, stat, msg)
      call check(error, stat, stat_invalid_input, 'legacy stat on a point outside')
      if (allocated(error)) return
      call check(error, index(msg, 'mesh_recovery_eval') > 0, 'legacy errmsg from the evaluation: '//trim(msg))
   end subroutine test_legacy

   !> The caller's reference coordinates (gauss_xi) instead of Newton's: on a distorted quad4
   !> and hex8 mesh, the inverse map's coordinates give the same nodal stresses and error
   !> (to round-off: the same points); coordinates moved by 1e-9 (below the 1e-6 tolerance)
   !> pass; moved by 1e-3, outside the element, or of the wrong shape, they are rejected with
   !> the entry named (Fortran and C notation).
   subroutine test_given_xi(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res0, res1
      real(wp), allocatable :: gxi(:, :, :), bad(:, :, :)
      integer, parameter :: etypes(2) = [elem_quad4, elem_hex8]
      integer :: k, e, i
      logical :: ok

      do k = 1, size(etypes)
         call build_case(c, etypes(k), 3, f_linear, 0.1_wp)
         allocate (gxi(c%dim, size(c%gp, 2), size(c%gp, 3)))
         do e = 1, size(c%gp, 3)
            do i = 1, size(c%gp, 2)
               call element_inverse_map(c%etype, c%x(:, c%conn(:, e)), c%gp(:, i, e), gxi(:, i, e), ok)
               if (.not. ok) then
                  call test_failed(error, 'inverse map of the test points')
                  return
               end if
            end do
         end do
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res0, error)
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res1, error, gauss_xi=gxi + 1.0e-9_wp)
         if (allocated(error)) return
         call check(error, maxval(abs(res1%nodal - res0%nodal)) <= tol*c%scale .and. &
            & abs(res1%err - res0%err) <= tol*res0%norm_h, 'given coordinates: same recovery')
         if (allocated(error)) return
         bad = gxi
         bad(1, 2, 5) = bad(1, 2, 5) + 1.0e-3_wp
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=bad)
         call expect(error, stat_invalid_input, 'gxi(:, 2, 5) = ')
         if (allocated(error)) return
         bad = gxi
         bad(2, 1, 3) = 1.5_wp
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=bad, c_indices=.true.)
         call expect(error, stat_invalid_input, 'gauss_xi[2][0] = ')
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=gxi(:, 2:, :))
         call expect(error, stat_invalid_input, 'gxi has shape')
         if (allocated(error)) return
         ! The same points on [-1, 1]^dim with reference = symmetric: the same recovery (the
         ! map xi = (s + 1)/2 rounds once, far below the tier); the [0, 1] coordinates read as
         ! symmetric are inside [-1, 1] but map elsewhere; -0.5 read as unit is outside, and
         ! the message says the convention.
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res1, error, gauss_xi=2.0_wp*gxi - 1.0_wp, reference=mesh_reference_symmetric)
         if (allocated(error)) return
         call check(error, maxval(abs(res1%nodal - res0%nodal)) <= tol*c%scale .and. &
            & abs(res1%err - res0%err) <= tol*res0%norm_h, 'reference symmetric: same recovery')
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=gxi, reference=mesh_reference_symmetric)
         call expect(error, stat_invalid_input, 'is inside the reference cell but does not map onto gp(:, 1, 1)')
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=2.0_wp*gxi - 1.0_wp)
         call expect(error, stat_invalid_input, 'is outside the reference cell [0, 1]^'//merge('2', '3', c%dim == 2)// &
            & " (reference 'unit', the default; 'symmetric' takes [-1, 1]^")
         if (allocated(error)) return
         bad = 2.0_wp*gxi - 1.0_wp
         bad(1, 1, 1) = 1.5_wp
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=bad, reference=mesh_reference_symmetric, c_indices=.true.)
         call expect(error, stat_invalid_input, 'gauss_xi[0][0] = (1.5')
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=bad, reference=mesh_reference_symmetric)
         call expect(error, stat_invalid_input, "is outside the reference cell [-1, 1]^")
         if (allocated(error)) return
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_spr, res1, error, gauss_xi=gxi, reference=7)
         call expect(error, stat_invalid_input, 'reference = 7 is not unit (0) or symmetric (1)')
         if (allocated(error)) return
         deallocate (gxi)
      end do
   end subroutine test_given_xi

   !> mesh_recovery_eval searches several points among the elements of their bin: the same
   !> bits as one point at a time (a scan over all elements), on the nodes (shared by up to
   !> 2^dim elements: the lowest index wins), the integration points and points between,
   !> for quad4, tri3 and hex8; a point outside the mesh is named either way.
   subroutine test_eval_binned(error)
      type(error_type), allocatable, intent(out) :: error
      type(case_type) :: c
      type(mesh_recovery_type) :: res
      real(wp), allocatable :: pts(:, :), s_all(:, :), s_one(:, :)
      integer, parameter :: etypes(3) = [elem_quad4, elem_tri3, elem_hex8]
      integer :: k, i, n

      do k = 1, size(etypes)
         call build_case(c, etypes(k), 3, f_quadratic, 0.2_wp)
         call recover_on_mesh(c%dim, c%analysis, c%x, c%etype, c%conn, c%gp, c%gw, c%gs, 1000.0_wp, 0.3_wp, &
            & mesh_method_sprc, res, error)
         if (allocated(error)) return
         n = size(c%x, 2) + 2*size(c%gp, 2)*size(c%gp, 3)
         allocate (pts(c%dim, n), s_all(res%nstress, n), s_one(res%nstress, n))
         pts(:, 1:size(c%x, 2)) = c%x
         pts(:, size(c%x, 2) + 1:size(c%x, 2) + size(c%gp, 2)*size(c%gp, 3)) = &
            & reshape(c%gp, [c%dim, size(c%gp, 2)*size(c%gp, 3)])
         pts(:, size(c%x, 2) + size(c%gp, 2)*size(c%gp, 3) + 1:) = &
            & 0.5_wp*(reshape(c%gp, [c%dim, size(c%gp, 2)*size(c%gp, 3)]) + 0.5_wp)
         call mesh_recovery_eval(res, pts, s_all, error)
         if (allocated(error)) return
         do i = 1, n
            call mesh_recovery_eval(res, pts(:, i:i), s_one(:, i:i), error)
            if (allocated(error)) return
         end do
         call check(error, same(s_all, s_one), 'binned search: same bits as point by point')
         if (allocated(error)) return
         pts(:, 7) = 1.5_wp
         call mesh_recovery_eval(res, pts, s_all, error)
         call expect(error, stat_invalid_input, 'x(:, 7) = ')
         if (allocated(error)) return
         deallocate (pts, s_all, s_one)
      end do
   end subroutine test_eval_binned

end module sprc_test_mesh_recovery
