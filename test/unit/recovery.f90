!> Tests of the mesh-agnostic recovery core (sprc_recovery_*).
!>
!> Test patches are built here, independently of any sprc mesh: a 3^dim grid of
!> distorted nodes around a vertex, multilinear quads / hexes with Gauss points
!> mapped isoparametrically (weight*|J|), boundary faces with surface Gauss
!> points, outward normals and the exact traction. Patches are placed in
!> physical space by x = X0 + L R y (rotation R, scale L) so that normals and
!> symmetry planes are oblique to the axes.
!>
!> Exact fields (reference coordinates y, mapped as sigma = R sigma_ref R^T,
!> b = R b_ref / L):
!> - linear fields with random coefficients, three of them fixed so that
!>   div sigma + b = 0 for a constant body force b (linear stresses are always
!>   compatible);
!> - 2D quadratic: Airy stress function phi of degree 4 with c22 = -3(c40 + c04),
!>   i.e. biharmonic, so that sigma = (phi_22, phi_11, -phi_12) is equilibrated and
!>   compatible in plane stress and plane strain;
!> - 3D quadratic: sigma = Hess(phi) for harmonic quartics phi: div = grad(lap phi) = 0,
!>   and eps = C sigma = (1+nu)/E Hess(phi) (trace-free) is a symmetric gradient;
!> - fields symmetric about y1 = 0: components with an odd number of indices 1 are odd
!>   in y1, the others even; phi even in y1; b_1 = 0.
!>
!> Residuals are checked by formulas written here (divergence from the basis
!> gradients, the six Saint-Venant equations written out, sigma n - t, n^T sigma t),
!> not by the constraint rows of the recovery core.
module sprc_test_recovery
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input, stat_singular
   use sprc_core_material, only: plane_stress, plane_strain, solid, compliance_matrix
   use sprc_core_poly, only: poly_basis_type, new_poly_basis
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_add_point, &
      & patch_add_boundary_point, boundary_traction, boundary_symmetry, boundary_contact, boundary_none, &
      & dominant_boundary_kind, kind_equilibrium, kind_compatibility, kind_traction, kind_symmetry
   use sprc_recovery_operators, only: incompatibility_operator
   use sprc_recovery_workspace, only: recovery_workspace_type, workspace_init, workspace_reserve
   use sprc_recovery_patch_solve, only: recover_spr, recover_sprc
   use sprc_recovery_flops, only: flops_gemm, flops_gemv, flops_syrk, flops_geqrf, flops_ormqr_left, flops_trtrs, &
      & flops_sysv, flops_potrf, flops_trtri, design_matrix_flops
   use sprc_recovery_estimate, only: eval_recovered, eval_union, zz_error_integral
   use sprc_core_dense, only: qr_pivoted, apply_qt, apply_q, solve_upper
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_recovery

   integer, parameter :: v_internal = 0, v_traction = 1, v_symmetry = 2, v_mixed = 3

   !> Round-off tier of values that pass through the patch solves (QR, constrained solve), relative
   !> to the stress scale: sqrt(eps). The solves are backward stable, but the conditioning of a
   !> patch system is not estimated (rank decisions keep pivots down to recovery_rank_tol, so
   !> it is not bounded by a small number either); sqrt(eps) admits condition numbers up to
   !> 1/sqrt(eps) ~ 7e7 and is still 1e5 below the errors a wrong constraint or basis makes.
   real(wp), parameter :: tol_exact = sqrt(epsilon(1.0_wp))

   !> An exact stress field in reference coordinates.
   type :: field_t
      integer :: dim = 2
      logical :: quadratic = .false.
      real(wp) :: k(6) = 0.0_wp, g(6, 3) = 0.0_wp, b(3) = 0.0_wp, q(5) = 0.0_wp, yc(3) = 0.0_wp
   end type field_t

   !> Placement x = x0 + l r y.
   type :: frame_t
      real(wp) :: x0(3) = 0.0_wp, l = 1.0_wp
      real(wp) :: r(3, 3) = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [3, 3])
   end type frame_t

contains

   subroutine collect_recovery(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('incompatibility_operator_eq57', test_incompat_operator), &
         new_unittest('exact_2d_internal', test_exact_2d_internal), &
         new_unittest('exact_2d_traction', test_exact_2d_traction), &
         new_unittest('exact_2d_symmetry', test_exact_2d_symmetry), &
         new_unittest('exact_2d_mixed', test_exact_2d_mixed), &
         new_unittest('exact_2d_plane_strain', test_exact_2d_plane_strain), &
         new_unittest('exact_3d_internal', test_exact_3d_internal), &
         new_unittest('exact_3d_traction', test_exact_3d_traction), &
         new_unittest('exact_3d_symmetry', test_exact_3d_symmetry), &
         new_unittest('exact_3d_mixed', test_exact_3d_mixed), &
         new_unittest('exact_2d_unstructured_valence', test_exact_unstructured), &
         new_unittest('known_ranks', test_known_ranks), &
         new_unittest('noisy_constraints_exact', test_noisy), &
         new_unittest('scaling_invariance', test_scaling), &
         new_unittest('rank_deficient_patch', test_rank_deficient), &
         new_unittest('dominant_boundary_kind', test_dominant), &
         new_unittest('workspace_reuse', test_workspace_reuse), &
         new_unittest('thread_safety_bitwise', test_threads), &
         new_unittest('union_and_zz', test_union_zz), &
         new_unittest('error_paths', test_errors), &
         new_unittest('reserve_fewer_points_than_terms', test_reserve_few_points), &
         new_unittest('traction_weight_focus', test_traction_focus), &
         new_unittest('traction_rank_curved_face', test_traction_curved_rank), &
         new_unittest('traction_face_off_node', test_traction_face_off_node), &
         new_unittest('flop_formulas', test_flop_formulas), &
         new_unittest('dense_kernels', test_dense_kernels), &
         new_unittest('flop_count_spr', test_flop_count_spr), &
         new_unittest('spr_normal_equations_vs_qr', test_spr_normal_equations), &
         new_unittest('flop_count_sprc', test_flop_count_sprc), &
         new_unittest('flop_count_sprc_traction', test_flop_count_traction) &
         ]
   end subroutine collect_recovery

   ! ------------------------------------------------------------------ helpers

   !> Deterministic uniform numbers in [-1, 1] (own LCG: no global RNG state, thread-safe).
   real(wp) function urand(st)
      integer(i8), intent(inout) :: st
      st = modulo(st*6364136223846793005_i8 + 1442695040888963407_i8, huge(st))
      urand = 2.0_wp*real(modulo(st/1024_i8, 1048576_i8), wp)/1048576.0_wp - 1.0_wp
   end function urand

   pure subroutine pair(dim, c, a, b)
      integer, intent(in) :: dim, c
      integer, intent(out) :: a, b
      integer, parameter :: p2(2, 3) = reshape([1, 1, 2, 2, 1, 2], [2, 3])
      integer, parameter :: p3(2, 6) = reshape([1, 1, 2, 2, 3, 3, 1, 2, 2, 3, 1, 3], [2, 6])
      if (dim == 2) then
         a = p2(1, c)
         b = p2(2, c)
      else
         a = p3(1, c)
         b = p3(2, c)
      end if
   end subroutine pair

   pure function to_tensor(dim, v) result(t)
      integer, intent(in) :: dim
      real(wp), intent(in) :: v(:)
      real(wp) :: t(3, 3)
      integer :: c, a, b
      t = 0.0_wp
      do c = 1, merge(3, 6, dim == 2)
         call pair(dim, c, a, b)
         t(a, b) = v(c)
         t(b, a) = v(c)
      end do
   end function to_tensor

   pure function to_voigt(dim, t) result(v)
      integer, intent(in) :: dim
      real(wp), intent(in) :: t(3, 3)
      real(wp) :: v(6)
      integer :: c, a, b
      v = 0.0_wp
      do c = 1, merge(3, 6, dim == 2)
         call pair(dim, c, a, b)
         v(c) = t(a, b)
      end do
   end function to_voigt

   !> Random exact field of degree 1 or 2 with body force; symmetric about y1 = 0 if asked.
   subroutine make_field(dim, degree, symmetric, st, f)
      integer, intent(in) :: dim, degree
      logical, intent(in) :: symmetric
      integer(i8), intent(inout) :: st
      type(field_t), intent(out) :: f
      integer :: c, j, a, b, i, cii, ns
      logical :: odd
      real(wp) :: divi

      f%dim = dim
      ns = merge(3, 6, dim == 2)
      do c = 1, ns
         f%k(c) = urand(st)
         do j = 1, dim
            f%g(c, j) = urand(st)
         end do
      end do
      do i = 1, dim
         f%b(i) = urand(st)
      end do
      if (symmetric) then
         f%b(1) = 0.0_wp
         do c = 1, ns
            call pair(dim, c, a, b)
            odd = modulo(count([a, b] == 1), 2) == 1
            if (odd) f%k(c) = 0.0_wp
            do j = 1, dim
               if ((j == 1) .neqv. odd) f%g(c, j) = 0.0_wp
            end do
         end do
      end if
      ! Equilibrium of the linear part: fix d sigma_ii / dy_i.
      do i = 1, dim
         cii = i
         f%g(cii, i) = 0.0_wp
         divi = 0.0_wp
         do c = 1, ns
            call pair(dim, c, a, b)
            if (a == i) divi = divi + f%g(c, b)
            if (b == i .and. a /= b) divi = divi + f%g(c, a)
         end do
         f%g(cii, i) = -f%b(i) - divi
      end do
      f%quadratic = degree >= 2
      if (f%quadratic) then
         do j = 1, 5
            f%q(j) = 0.5_wp*urand(st)
         end do
         do j = 1, dim
            f%yc(j) = 0.5_wp*urand(st)
         end do
         if (symmetric) then
            f%yc(1) = 0.0_wp
            if (dim == 2) then
               f%q(2) = 0.0_wp
               f%q(3) = 0.0_wp
            else
               f%q(3) = 0.0_wp
               f%q(4) = 0.0_wp
            end if
         end if
      end if
   end subroutine make_field

   !> Stress of the reference field at y.
   pure subroutine eval_field_ref(f, y, sig)
      type(field_t), intent(in) :: f
      real(wp), intent(in) :: y(3)
      real(wp), intent(out) :: sig(6)
      real(wp) :: z(3), c22, h(6)
      integer :: c

      sig = 0.0_wp
      do c = 1, merge(3, 6, f%dim == 2)
         sig(c) = f%k(c) + sum(f%g(c, 1:f%dim)*y(1:f%dim))
      end do
      if (.not. f%quadratic) return
      z = y - f%yc
      if (f%dim == 2) then
         ! phi = c40 y1^4 + c31 y1^3 y2 + c22 y1^2 y2^2 + c13 y1 y2^3 + c04 y2^4, q = (c40, c31, c13, c04, -)
         c22 = -3.0_wp*(f%q(1) + f%q(4))
         sig(1) = sig(1) + 2.0_wp*c22*z(1)**2 + 6.0_wp*f%q(3)*z(1)*z(2) + 12.0_wp*f%q(4)*z(2)**2
         sig(2) = sig(2) + 12.0_wp*f%q(1)*z(1)**2 + 6.0_wp*f%q(2)*z(1)*z(2) + 2.0_wp*c22*z(2)**2
         sig(3) = sig(3) - (3.0_wp*f%q(2)*z(1)**2 + 4.0_wp*c22*z(1)*z(2) + 3.0_wp*f%q(3)*z(2)**2)
      else
         ! Hessians (xx, yy, zz, xy, yz, xz) of the harmonic quartics h1..h5 (see module doc).
         h = 0.0_wp
         h(1) = f%q(1)*(12*z(1)**2 - 12*z(2)**2) + f%q(3)*6*z(1)*z(2) + f%q(4)*6*z(1)*z(3)
         h(2) = f%q(1)*(12*z(2)**2 - 12*z(1)**2) + f%q(2)*(12*z(2)**2 - 12*z(3)**2) - f%q(3)*6*z(1)*z(2) &
            & - f%q(4)*6*z(1)*z(3) + f%q(5)*6*z(2)*z(3)
         h(3) = f%q(2)*(12*z(3)**2 - 12*z(2)**2) - f%q(5)*6*z(2)*z(3)
         h(4) = -f%q(1)*24*z(1)*z(2) + f%q(3)*(3*z(1)**2 - 3*z(2)**2) - f%q(4)*6*z(2)*z(3)
         h(5) = -f%q(2)*24*z(2)*z(3) - f%q(4)*6*z(1)*z(2) + f%q(5)*(3*z(2)**2 - 3*z(3)**2)
         h(6) = f%q(4)*(3*z(1)**2 - 3*z(2)**2)
         sig = sig + h
      end if
   end subroutine eval_field_ref

   !> Physical stress at physical x.
   pure subroutine eval_field(f, fr, x, sig)
      type(field_t), intent(in) :: f
      type(frame_t), intent(in) :: fr
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: sig(6)
      real(wp) :: y(3), xx(3), t(3, 3)
      integer :: d

      d = f%dim
      xx = 0.0_wp
      xx(1:d) = x(1:d) - fr%x0(1:d)
      y = matmul(transpose(fr%r), xx)/fr%l
      if (d == 2) y(3) = 0.0_wp
      call eval_field_ref(f, y, sig)
      t = to_tensor(d, sig)
      t = matmul(fr%r, matmul(t, transpose(fr%r)))
      sig = to_voigt(d, t)
   end subroutine eval_field

   pure function phys(fr, y) result(x)
      type(frame_t), intent(in) :: fr
      real(wp), intent(in) :: y(3)
      real(wp) :: x(3)
      x = fr%x0 + fr%l*matmul(fr%r, y)
   end function phys

   function rotation(dim, a1, a2, a3) result(r)
      integer, intent(in) :: dim
      real(wp), intent(in) :: a1, a2, a3
      real(wp) :: r(3, 3), rz(3, 3), ry(3, 3), rx(3, 3)
      rz = reshape([cos(a1), sin(a1), 0.0_wp, -sin(a1), cos(a1), 0.0_wp, 0.0_wp, 0.0_wp, 1.0_wp], [3, 3])
      if (dim == 2) then
         r = rz
         return
      end if
      ry = reshape([cos(a2), 0.0_wp, -sin(a2), 0.0_wp, 1.0_wp, 0.0_wp, sin(a2), 0.0_wp, cos(a2)], [3, 3])
      rx = reshape([1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp, cos(a3), sin(a3), 0.0_wp, -sin(a3), cos(a3)], [3, 3])
      r = matmul(rz, matmul(ry, rx))
   end function rotation

   subroutine gauss(n, xi, wt)
      integer, intent(in) :: n
      real(wp), intent(out) :: xi(3), wt(3)
      select case (n)
      case (1)
         xi(1) = 0.0_wp
         wt(1) = 2.0_wp
      case (2)
         xi(1:2) = [-1.0_wp, 1.0_wp]/sqrt(3.0_wp)
         wt(1:2) = 1.0_wp
      case default
         xi = [-sqrt(0.6_wp), 0.0_wp, sqrt(0.6_wp)]
         wt = [5.0_wp, 8.0_wp, 5.0_wp]/9.0_wp
      end select
   end subroutine gauss

   !> Multilinear map of the cell with lower node index cell(:) at xi: point and Jacobian.
   subroutine cell_map(dim, nodes, cell, xi, y, jac)
      integer, intent(in) :: dim, cell(3)
      real(wp), intent(in) :: nodes(3, 0:2, 0:2, 0:2), xi(3)
      real(wp), intent(out) :: y(3), jac(3, 3)
      integer :: a, k, m, bits(3), idx(3)
      real(wp) :: nval, dn(3), f(3), df(3)

      y = 0.0_wp
      jac = 0.0_wp
      do a = 0, 2**dim - 1
         bits = 0
         do k = 1, dim
            bits(k) = ibits(a, k - 1, 1)
         end do
         idx = cell + bits
         if (dim == 2) idx(3) = 0
         do k = 1, dim
            f(k) = 0.5_wp*(1.0_wp + merge(1.0_wp, -1.0_wp, bits(k) == 1)*xi(k))
            df(k) = 0.5_wp*merge(1.0_wp, -1.0_wp, bits(k) == 1)
         end do
         nval = product(f(1:dim))
         do k = 1, dim
            dn(k) = df(k)
            do m = 1, dim
               if (m /= k) dn(k) = dn(k)*f(m)
            end do
         end do
         y = y + nval*nodes(:, idx(1), idx(2), idx(3))
         do k = 1, dim
            jac(:, k) = jac(:, k) + dn(k)*nodes(:, idx(1), idx(2), idx(3))
         end do
      end do
   end subroutine cell_map

   !> Build a test patch (see module doc). `variant`: internal, traction (boundary at node
   !> layer 1 of the last axis, cells above it), symmetry (plane y1 = 0, cells with y1 > 0),
   !> mixed (both). Gauss order degree+1 per direction. `noise` adds deterministic noise.
   subroutine make_patch(dim, degree, variant, analysis, f, fr, noise, st, patch, distortion)
      integer, intent(in) :: dim, degree, variant, analysis
      type(field_t), intent(in) :: f
      type(frame_t), intent(in) :: fr
      real(wp), intent(in) :: noise
      integer(i8), intent(inout) :: st
      type(patch_type), intent(inout) :: patch
      real(wp), intent(in), optional :: distortion
      real(wp) :: nodes(3, 0:2, 0:2, 0:2), xi(3), wt(3), q(3), y(3), jac(3, 3), sig(6), x(3), amp
      real(wp) :: tn(3), nrm(3), meas, t(3), ww, dirk(3)
      integer :: i, j, k, lo(3), hi(3), cell(3), c1, c2, c3, ng, g1, g2, g3, ax, ns, kind, m1, m2, kmax
      logical :: has_sym, has_tr

      amp = 0.2_wp
      if (present(distortion)) amp = distortion
      ns = merge(3, 6, dim == 2)
      has_sym = variant == v_symmetry .or. variant == v_mixed
      has_tr = variant == v_traction .or. variant == v_mixed
      kmax = merge(0, 2, dim == 2)
      nodes = 0.0_wp
      do k = 0, kmax
         do j = 0, 2
            do i = 0, 2
               nodes(:, i, j, k) = real([i - 1, j - 1, k - 1], wp)
               nodes(1, i, j, k) = nodes(1, i, j, k) + amp*urand(st)
               nodes(2, i, j, k) = nodes(2, i, j, k) + amp*urand(st)
               if (dim == 3) nodes(3, i, j, k) = nodes(3, i, j, k) + amp*urand(st)
               if (dim == 2) nodes(3, i, j, k) = 0.0_wp
               if (has_sym .and. i == 1) nodes(1, i, j, k) = 0.0_wp
               if (has_tr .and. dim == 2 .and. j == 1) nodes(2, i, j, k) = 0.0_wp
               if (has_tr .and. dim == 3 .and. k == 1) nodes(3, i, j, k) = 0.0_wp
            end do
         end do
      end do
      lo = 0
      hi = 1
      if (dim == 2) hi(3) = 0
      if (has_sym) lo(1) = 1
      if (has_tr) lo(dim) = 1

      call patch_reset(patch, dim, analysis, 200.0_wp, 0.3_wp, phys(fr, nodes(:, 1, 1, merge(0, 1, dim == 2))), &
         & 1.5_wp*fr%l)
      patch%body_force = 0.0_wp
      patch%body_force(1:dim) = matmul(fr%r(1:dim, 1:dim), f%b(1:dim))/fr%l
      ng = degree + 1
      call gauss(ng, xi, wt)
      do c3 = lo(3), hi(3)
         do c2 = lo(2), hi(2)
            do c1 = lo(1), hi(1)
               cell = [c1, c2, c3]
               do g3 = 1, merge(1, ng, dim == 2)
                  do g2 = 1, ng
                     do g1 = 1, ng
                        q = [xi(g1), xi(g2), xi(g3)]
                        if (dim == 2) q(3) = 0.0_wp
                        call cell_map(dim, nodes, cell, q, y, jac)
                        x = phys(fr, y)
                        call eval_field(f, fr, x, sig)
                        do i = 1, ns
                           sig(i) = sig(i) + noise*urand(st)
                        end do
                        ww = wt(g1)*wt(g2)*abs(det(dim, jac))*fr%l**dim
                        if (dim == 3) ww = ww*wt(g3)
                        call patch_add_point(patch, x(1:dim), ww, sig(1:ns))
                     end do
                  end do
               end do
               ! Boundary faces xi_ax = -1 of cells at node layer 1 of a boundary axis.
               do ax = 1, dim
                  if (.not. ((ax == 1 .and. has_sym) .or. (ax == dim .and. has_tr))) cycle
                  if (cell(ax) /= 1) cycle
                  kind = merge(boundary_symmetry, boundary_traction, ax == 1 .and. has_sym)
                  if (ax == dim .and. has_tr) kind = boundary_traction
                  if (ax == 1 .and. has_sym) kind = boundary_symmetry
                  m1 = merge(2, 1, ax == 1)
                  m2 = 6 - ax - m1
                  do g2 = 1, merge(1, ng, dim == 2)
                     do g1 = 1, ng
                        q = 0.0_wp
                        q(ax) = -1.0_wp
                        q(m1) = xi(g1)
                        if (dim == 3) q(m2) = xi(g2)
                        call cell_map(dim, nodes, cell, q, y, jac)
                        if (dim == 2) then
                           tn = jac(:, m1)
                           nrm = [tn(2), -tn(1), 0.0_wp]
                           meas = sqrt(sum(tn**2))
                           ww = wt(g1)*meas*fr%l
                        else
                           nrm = cross(jac(:, m1), jac(:, m2))
                           meas = sqrt(sum(nrm**2))
                           ww = wt(g1)*wt(g2)*meas*fr%l**2
                        end if
                        nrm = nrm/sqrt(sum(nrm**2))
                        dirk = jac(:, ax)
                        if (dot_product(nrm, dirk) > 0.0_wp) nrm = -nrm
                        nrm = matmul(fr%r, nrm)
                        x = phys(fr, y)
                        call eval_field(f, fr, x, sig)
                        t = matmul(to_tensor(dim, sig), nrm)
                        call patch_add_boundary_point(patch, x(1:dim), ww, nrm(1:dim), kind, t(1:dim))
                     end do
                  end do
               end do
            end do
         end do
      end do
   end subroutine make_patch

   pure function cross(a, b) result(c)
      real(wp), intent(in) :: a(3), b(3)
      real(wp) :: c(3)
      c = [a(2)*b(3) - a(3)*b(2), a(3)*b(1) - a(1)*b(3), a(1)*b(2) - a(2)*b(1)]
   end function cross

   pure real(wp) function det(dim, a)
      integer, intent(in) :: dim
      real(wp), intent(in) :: a(3, 3)
      if (dim == 2) then
         det = a(1, 1)*a(2, 2) - a(1, 2)*a(2, 1)
      else
         det = dot_product(a(:, 1), cross(a(:, 2), a(:, 3)))
      end if
   end function det

   !> Largest |sigma* - sigma| over random points in the patch, relative to the largest |sigma|.
   subroutine reproduction_error(rec, f, fr, st, relerr)
      type(recovered_patch_type), intent(in) :: rec
      type(field_t), intent(in) :: f
      type(frame_t), intent(in) :: fr
      integer(i8), intent(inout) :: st
      real(wp), intent(out) :: relerr
      real(wp) :: y(3), x(3), se(6), sr(6), emax, smax
      integer :: it, k
      type(error_type), allocatable :: error

      emax = 0.0_wp
      smax = 0.0_wp
      do it = 1, 50
         y = 0.0_wp
         do k = 1, f%dim
            y(k) = urand(st)
         end do
         x = phys(fr, y)
         call eval_field(f, fr, x, se)
         call eval_recovered(rec, x(1:f%dim), sr, error)
         if (allocated(error)) then
            relerr = huge(1.0_wp)
            return
         end if
         emax = max(emax, maxval(abs(sr(1:rec%nstress) - se(1:rec%nstress))))
         smax = max(smax, maxval(abs(se(1:rec%nstress))))
      end do
      relerr = emax/smax
   end subroutine reproduction_error

   !> Stress, gradient and Hessian of the recovered field at x, from sprc_core_poly's basis
   !> derivatives (physical, via h): grad(c, k) = d sigma_c / dx_k, hess(c, m).
   subroutine rec_derivatives(rec, x, grad, hess)
      type(recovered_patch_type), intent(in) :: rec
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: grad(6, 3), hess(6, 6)
      type(poly_basis_type) :: basis
      type(error_type), allocatable :: error
      real(wp) :: s(3), dp(20, 3), d2p(20, 6)
      integer :: c, k, d, nt

      d = rec%dim
      nt = rec%nterms
      call new_poly_basis(basis, d, rec%degree, error)
      s(1:d) = (x(1:d) - rec%x0(1:d))/rec%h
      call basis%eval_grad(s(1:d), dp, rec%h)
      call basis%eval_hess(s(1:d), d2p, rec%h)
      grad = 0.0_wp
      hess = 0.0_wp
      do c = 1, rec%nstress
         do k = 1, d
            grad(c, k) = dot_product(rec%coef(1:nt, c), dp(1:nt, k))
         end do
         do k = 1, rec%nstress
            hess(c, k) = dot_product(rec%coef(1:nt, c), d2p(1:nt, k))
         end do
      end do
   end subroutine rec_derivatives

   !> Constraint residuals of a recovered field, relative: equilibrium |div s* + b| l / S,
   !> compatibility (hand-written Saint-Venant) relative to the size of its terms, traction
   !> |s* n - t| / S at the patch's traction points, symmetry |n^T s* t| / S on the planes.
   subroutine residuals(patch, rec, fr, st, req, rcomp, rtr, rsym)
      type(patch_type), intent(in) :: patch
      type(recovered_patch_type), intent(in) :: rec
      type(frame_t), intent(in) :: fr
      integer(i8), intent(inout) :: st
      real(wp), intent(out) :: req, rcomp, rtr, rsym
      real(wp) :: y(3), x(3), grad(6, 3), hess(6, 6), divs(3), smax, cm(6, 6), d2e(6, 6), r(6), scale, sr(6)
      real(wp) :: tr(3), tens(3, 3), n(3), tg(3)
      integer :: it, d, i, c, a, b, k, j
      type(error_type), allocatable :: error

      d = rec%dim
      smax = 0.0_wp
      do j = 1, patch%npoints
         smax = max(smax, maxval(abs(patch%stress(1:rec%nstress, j))))
      end do
      call compliance_matrix(patch%analysis, patch%young, patch%poisson, cm(1:rec%nstress, 1:rec%nstress), error)
      req = 0.0_wp
      rcomp = 0.0_wp
      rtr = 0.0_wp
      rsym = 0.0_wp
      do it = 1, 20
         y = 0.0_wp
         do k = 1, d
            y(k) = urand(st)
         end do
         x = phys(fr, y)
         call rec_derivatives(rec, x(1:d), grad, hess)
         divs = 0.0_wp
         do c = 1, rec%nstress
            call pair(d, c, a, b)
            divs(a) = divs(a) + grad(c, b)
            if (a /= b) divs(b) = divs(b) + grad(c, a)
         end do
         req = max(req, maxval(abs(divs(1:d) + patch%body_force(1:d)))*fr%l/smax)
         d2e(1:rec%nstress, 1:rec%nstress) = matmul(cm(1:rec%nstress, 1:rec%nstress), hess(1:rec%nstress, 1:rec%nstress))
         if (d == 2) then
            r(1) = d2e(1, 2) + d2e(2, 1) - d2e(3, 3)
            scale = abs(d2e(1, 2)) + abs(d2e(2, 1)) + abs(d2e(3, 3))
            r(2:6) = 0.0_wp
         else
            r(1) = d2e(1, 2) + d2e(2, 1) - d2e(4, 4)
            r(2) = d2e(2, 3) + d2e(3, 2) - d2e(5, 5)
            r(3) = d2e(1, 3) + d2e(3, 1) - d2e(6, 6)
            r(4) = 2*d2e(1, 5) + d2e(5, 1) - d2e(6, 4) - d2e(4, 6)
            r(5) = 2*d2e(2, 6) - d2e(5, 4) + d2e(6, 2) - d2e(4, 5)
            r(6) = 2*d2e(3, 4) - d2e(5, 6) - d2e(6, 5) + d2e(4, 3)
            scale = maxval(abs(d2e(1:6, 1:6)))*6.0_wp
         end if
         ! Terms below 1e-300 are an exactly linear field (p = 1): compatibility is void there.
         if (scale > 1.0e-300_wp) rcomp = max(rcomp, maxval(abs(r))/scale)
      end do
      do j = 1, patch%nbpoints
         call eval_recovered(rec, patch%bx(1:d, j), sr, error)
         tens = to_tensor(d, sr)
         n = 0.0_wp
         n(1:d) = patch%bn(1:d, j)
         if (patch%bkind(j) == boundary_traction) then
            tr = matmul(tens, n)
            rtr = max(rtr, maxval(abs(tr(1:d) - patch%btraction(1:d, j)))/smax)
         else if (patch%bkind(j) == boundary_symmetry) then
            ! On the symmetry plane through this point, at a random point of the plane.
            do i = 1, 3
               y = 0.0_wp
               do k = 2, d
                  y(k) = urand(st)
               end do
               x = patch%bx(:, j) + fr%l*matmul(fr%r, y)
               call eval_recovered(rec, x(1:d), sr, error)
               tens = to_tensor(d, sr)
               do k = 2, d
                  tg = fr%r(:, k)
                  rsym = max(rsym, abs(dot_product(n, matmul(tens, tg)))/smax)
               end do
            end do
         end if
      end do
   end subroutine residuals

   !> One exactness case: exact field through SPR and SPR-C; reproduction and residuals.
   subroutine exact_case(dim, degree, variant, analysis, all_kinds, error)
      integer, intent(in) :: dim, degree, variant, analysis
      logical, intent(in) :: all_kinds
      type(error_type), allocatable, intent(out) :: error
      type(field_t) :: f
      type(frame_t) :: fr
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer(i8) :: st
      real(wp) :: relerr, req, rcomp, rtr, rsym
      character(len=64) :: tag

      write (tag, '("dim ",i0," p ",i0," variant ",i0," analysis ",i0)') dim, degree, variant, analysis
      st = 12345_i8 + 7*dim + 11*degree + 13*variant
      call make_field(dim, degree, variant == v_symmetry .or. variant == v_mixed, st, f)
      fr%x0 = [0.3_wp, -1.7_wp, 2.2_wp]
      fr%l = 0.8_wp
      fr%r = rotation(dim, 0.4_wp, -0.3_wp, 0.7_wp)
      call make_patch(dim, degree, variant, analysis, f, fr, 0.0_wp, st, patch)
      patch%all_boundary_kinds = all_kinds

      call recover_spr(patch, degree, ws, rec, error)
      if (allocated(error)) return
      call reproduction_error(rec, f, fr, st, relerr)
      call check(error, relerr <= tol_exact, 'SPR reproduces the exact field, '//trim(tag))
      if (allocated(error)) return

      call recover_sprc(patch, degree, ws, rec, error)
      if (allocated(error)) return
      call reproduction_error(rec, f, fr, st, relerr)
      call check(error, relerr <= tol_exact, 'SPR-C reproduces the exact field, '//trim(tag))
      if (allocated(error)) return
      call check(error, .not. rec%tolerance_bites, 'no rank decision near the tolerance, '//trim(tag))
      if (allocated(error)) return
      call residuals(patch, rec, fr, st, req, rcomp, rtr, rsym)
      call check(error, max(req, rcomp, rtr, rsym) <= tol_exact, 'SPR-C residuals at round-off, '//trim(tag))
      if (allocated(error)) return
      call check(error, rec%ranks(kind_equilibrium) > 0 .or. degree == 0, 'equilibrium imposed, '//trim(tag))
      if (allocated(error)) return
      if (variant == v_traction .or. (variant == v_mixed .and. all_kinds)) then
         call check(error, rec%ranks(kind_traction) > 0, 'traction imposed, '//trim(tag))
         if (allocated(error)) return
      end if
      if (variant == v_symmetry .or. (variant == v_mixed .and. all_kinds)) then
         call check(error, rec%ranks(kind_symmetry) > 0, 'symmetry imposed, '//trim(tag))
         if (allocated(error)) return
      end if
   end subroutine exact_case

   ! ------------------------------------------------------------------ tests

   !> The Levi-Civita incompatibility operator equals the seed's L' of eq. 57 (3D, checked
   !> there against eq. 55 by hand) and eq. 44 in 2D.
   subroutine test_incompat_operator(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: op3(6, 6, 6), op2(1, 3, 3), want(6, 6, 6)
      ! Entries of eq. 57: (equation, strain component, second derivative, value);
      ! derivative order xx, yy, zz, xy, yz, xz; strains with engineering shears.
      integer, parameter :: nz = 21
      integer, parameter :: e57(3, nz) = reshape([ &
         & 1, 1, 2, 1, 2, 1, 1, 4, 4, &
         & 2, 2, 3, 2, 3, 2, 2, 5, 5, &
         & 3, 1, 3, 3, 3, 1, 3, 6, 6, &
         & 4, 1, 5, 4, 4, 6, 4, 5, 1, 4, 6, 4, &
         & 5, 2, 6, 5, 4, 5, 5, 5, 4, 5, 6, 2, &
         & 6, 3, 4, 6, 4, 3, 6, 5, 6, 6, 6, 5], [3, nz])
      real(wp), parameter :: v57(nz) = [1, 1, -1, 1, 1, -1, 1, 1, -1, 2, -1, 1, -1, 2, -1, -1, 1, 2, 1, -1, -1]
      integer :: i

      call incompatibility_operator(3, op3)
      want = 0.0_wp
      do i = 1, nz
         want(e57(1, i), e57(2, i), e57(3, i)) = v57(i)
      end do
      call check(error, maxval(abs(op3 - want)) == 0.0_wp, 'incompatibility operator 3D = eq. 57')
      if (allocated(error)) return
      call incompatibility_operator(2, op2)
      ! eq. 44: eps_xx,yy + eps_yy,xx - gamma_xy,xy
      call check(error, op2(1, 1, 2) == 1.0_wp .and. op2(1, 2, 1) == 1.0_wp .and. op2(1, 3, 3) == -1.0_wp &
         & .and. count(op2 /= 0.0_wp) == 3, 'incompatibility operator 2D = eq. 44')
   end subroutine test_incompat_operator

   subroutine test_exact_2d_internal(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(2, p, v_internal, plane_stress, .false., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_2d_internal

   subroutine test_exact_2d_traction(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(2, p, v_traction, plane_stress, .false., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_2d_traction

   subroutine test_exact_2d_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(2, p, v_symmetry, plane_stress, .false., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_2d_symmetry

   subroutine test_exact_2d_mixed(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(2, p, v_mixed, plane_stress, .false., error)
         if (allocated(error)) return
         call exact_case(2, p, v_mixed, plane_stress, .true., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_2d_mixed

   subroutine test_exact_2d_plane_strain(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: v
      do v = v_internal, v_mixed
         call exact_case(2, 2, v, plane_strain, .true., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_2d_plane_strain

   subroutine test_exact_3d_internal(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(3, p, v_internal, solid, .false., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_3d_internal

   subroutine test_exact_3d_traction(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(3, p, v_traction, solid, .false., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_3d_traction

   subroutine test_exact_3d_symmetry(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(3, p, v_symmetry, solid, .false., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_3d_symmetry

   subroutine test_exact_3d_mixed(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: p
      do p = 1, 2
         call exact_case(3, p, v_mixed, solid, .false., error)
         if (allocated(error)) return
         call exact_case(3, p, v_mixed, solid, .true., error)
         if (allocated(error)) return
      end do
   end subroutine test_exact_3d_mixed

   !> Unstructured 2D vertex patches: valence 3, 5 and 6 (quads (centre, spoke k, outer k,
   !> spoke k+1) with perturbed radii and angles), p = 1 and 2, internal; SPR and SPR-C
   !> reproduce the exact field and SPR-C's residuals are at round-off.
   subroutine test_exact_unstructured(error)
      type(error_type), allocatable, intent(out) :: error
      type(field_t) :: f
      type(frame_t) :: fr
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer(i8) :: st
      integer :: nv, p, k, g1, g2, a, method
      real(wp) :: spoke(2, 0:6), outer(2, 0:6), ang, xi(3), wt(3), crn(2, 4), nsh(4), dxi(2, 4), y(3), jac(2, 2)
      real(wp) :: x(3), sig(6), relerr, req, rcomp, rtr, rsym
      real(wp), parameter :: pi = 3.14159265358979324_wp
      integer, parameter :: valence(3) = [3, 5, 6]
      character(len=40) :: tag

      fr%r = rotation(2, 0.2_wp, 0.0_wp, 0.0_wp)
      fr%x0 = [5.0_wp, -3.0_wp, 0.0_wp]
      do a = 1, size(valence)
         nv = valence(a)
         do p = 1, 2
            write (tag, '(" (valence ",i0,", p ",i0,")")') nv, p
            st = 2024_i8 + 10*nv + p
            call make_field(2, p, .false., st, f)
            do k = 0, nv - 1
               ang = 2*pi*(k + 0.15_wp*urand(st))/nv
               spoke(:, k) = (1.0_wp + 0.2_wp*urand(st))*[cos(ang), sin(ang)]
               ang = 2*pi*(k + 0.5_wp + 0.1_wp*urand(st))/nv
               outer(:, k) = (1.4_wp + 0.2_wp*urand(st))*[cos(ang), sin(ang)]
            end do
            ! Valence 3: the outer node must stay inside the angle for a convex quad.
            if (nv == 3) outer = 0.9_wp*outer
            spoke(:, nv) = spoke(:, 0)
            call patch_reset(patch, 2, plane_stress, 70.0_wp, 0.33_wp, fr%x0(1:2), 1.5_wp)
            patch%body_force(1:2) = matmul(fr%r(1:2, 1:2), f%b(1:2))
            call gauss(p + 1, xi, wt)
            do k = 0, nv - 1
               crn(:, 1) = 0.0_wp
               crn(:, 2) = spoke(:, k)
               crn(:, 3) = outer(:, k)
               crn(:, 4) = spoke(:, k + 1)
               do g2 = 1, p + 1
                  do g1 = 1, p + 1
                     nsh = 0.25_wp*[(1 - xi(g1))*(1 - xi(g2)), (1 + xi(g1))*(1 - xi(g2)), &
                        & (1 + xi(g1))*(1 + xi(g2)), (1 - xi(g1))*(1 + xi(g2))]
                     dxi(1, :) = 0.25_wp*[-(1 - xi(g2)), (1 - xi(g2)), (1 + xi(g2)), -(1 + xi(g2))]
                     dxi(2, :) = 0.25_wp*[-(1 - xi(g1)), -(1 + xi(g1)), (1 + xi(g1)), (1 - xi(g1))]
                     y = 0.0_wp
                     y(1:2) = matmul(crn, nsh)
                     jac = matmul(crn, transpose(dxi))
                     if (jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1) <= 0.0_wp) then
                        call test_failed(error, 'test setup: inverted quad'//tag)
                        return
                     end if
                     x = phys(fr, y)
                     call eval_field(f, fr, x, sig)
                     call patch_add_point(patch, x(1:2), wt(g1)*wt(g2)*(jac(1, 1)*jac(2, 2) - jac(1, 2)*jac(2, 1)), &
                        & sig(1:3))
                  end do
               end do
            end do
            do method = 1, 2
               if (method == 1) then
                  call recover_spr(patch, p, ws, rec, error)
               else
                  call recover_sprc(patch, p, ws, rec, error)
               end if
               if (allocated(error)) return
               call reproduction_error(rec, f, fr, st, relerr)
               call check(error, relerr <= tol_exact, 'exact field reproduced'//tag)
               if (allocated(error)) return
            end do
            call residuals(patch, rec, fr, st, req, rcomp, rtr, rsym)
            call check(error, max(req, rcomp) <= tol_exact, 'SPR-C residuals at round-off'//tag)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_exact_unstructured

   !> Ranks of the constraint blocks. Hand reasoning (b constant, points unisolvent):
   !> - equilibrium: A -> div sigma* maps onto vector polynomials of degree p-1 (sigma_xx alone
   !>   reaches every x-component: d/dx of its antiderivative), so the LS-form rank is
   !>   dim * C(p-1+dim, dim): 2D p=1: 2 of 9; 2D p=2: 2*3 = 6 of 18; 3D p=1: 3 of 24 (the
   !>   seed's figure); 3D p=2: 3*4 = 12 of 60.
   !> - compatibility (p=2): second derivatives are constants; 1 equation in 2D, 6 independent
   !>   ones in 3D (the Bianchi identities involve derivatives of the equations, void here).
   !> - traction on a straight edge / plane face: sigma n restricted to the boundary is a
   !>   vector polynomial of degree p in dim-1 variables: 2D p=1: 2*2 = 4, p=2: 2*3 = 6;
   !>   3D p=1: 3*3 = 9, p=2: 3*6 = 18.
   !> - symmetry: dim-1 shear components, each a polynomial of degree p on the plane:
   !>   2D p=1: 2, p=2: 3; 3D p=1: 2*3 = 6, p=2: 2*6 = 12.
   !> With one boundary kind, the blocks are independent (rank_total = sum).
   subroutine test_known_ranks(error)
      type(error_type), allocatable, intent(out) :: error
      ! (dim, p, variant, eq rank, eq rows, compat rank, traction rank, symmetry rank)
      integer, parameter :: ncase = 12
      integer, parameter :: table(8, ncase) = reshape([ &
         & 2, 1, v_internal, 2, 9, 0, 0, 0, &
         & 2, 2, v_internal, 6, 18, 1, 0, 0, &
         & 3, 1, v_internal, 3, 24, 0, 0, 0, &
         & 3, 2, v_internal, 12, 60, 6, 0, 0, &
         & 2, 1, v_traction, 2, 9, 0, 4, 0, &
         & 2, 2, v_traction, 6, 18, 1, 6, 0, &
         & 3, 1, v_traction, 3, 24, 0, 9, 0, &
         & 3, 2, v_traction, 12, 60, 6, 18, 0, &
         & 2, 1, v_symmetry, 2, 9, 0, 0, 2, &
         & 2, 2, v_symmetry, 6, 18, 1, 0, 3, &
         & 3, 1, v_symmetry, 3, 24, 0, 0, 6, &
         & 3, 2, v_symmetry, 12, 60, 6, 0, 12], [8, ncase])
      type(field_t) :: f
      type(frame_t) :: fr
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer(i8) :: st
      integer :: i, d, p, v
      character(len=48) :: tag

      do i = 1, ncase
         d = table(1, i)
         p = table(2, i)
         v = table(3, i)
         write (tag, '(" (dim ",i0,", p ",i0,", variant ",i0,")")') d, p, v
         st = 99_i8 + i
         call make_field(d, p, v == v_symmetry, st, f)
         fr%r = rotation(d, 0.9_wp, 0.2_wp, -0.5_wp)
         call make_patch(d, p, v, merge(plane_stress, solid, d == 2), f, fr, 0.0_wp, st, patch)
         call recover_sprc(patch, p, ws, rec, error)
         if (allocated(error)) return
         call check(error, rec%ranks(kind_equilibrium), table(4, i), 'equilibrium rank'//trim(tag))
         if (allocated(error)) return
         call check(error, rec%rows(kind_equilibrium), table(5, i), 'equilibrium rows'//trim(tag))
         if (allocated(error)) return
         call check(error, rec%ranks(kind_compatibility), table(6, i), 'compatibility rank'//trim(tag))
         if (allocated(error)) return
         call check(error, rec%ranks(kind_traction), table(7, i), 'traction rank'//trim(tag))
         if (allocated(error)) return
         call check(error, rec%ranks(kind_symmetry), table(8, i), 'symmetry rank'//trim(tag))
         if (allocated(error)) return
         call check(error, rec%rank_total, sum(table(4:8, i)) - table(5, i), 'total rank'//trim(tag))
         if (allocated(error)) return
      end do
   end subroutine test_known_ranks

   !> A noisy, non-equilibrated field: SPR-C still satisfies every imposed constraint to
   !> round-off, while SPR does not satisfy equilibrium (so the test can tell them apart).
   !> Traction rows weighted by (1 - rho)^4 (solve.f90 notes (c)): on the straight face y = 0
   !> of a 2D p = 1 patch with zero volume stress and a prescribed normal traction
   !> t = (0, -g(x)), g(x) = x^2 + x^3/2 (not linear: p = 1 cannot match it), the flat-rank
   !> rows make the traction of sigma* the weighted least-squares line of g with weights
   !> bw_j (1 - |x_j|/h)^4, and equilibrium (sigma_yy,y = 0) carries it into the patch:
   !> sigma*_yy(x, y) = a + b x, with (a, b) from the 2 x 2 normal equations here.
   subroutine test_traction_focus(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      real(wp) :: xi(3), wt(3), x, y, f, g, nm(2, 2), rhs(2), det, a, b, sig(3)
      integer :: i, j, k, cell

      call gauss(3, xi, wt)
      call patch_reset(patch, 2, plane_stress, 1000.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      nm = 0.0_wp
      rhs = 0.0_wp
      do cell = 0, 1
         do i = 1, 3
            x = cell - 1 + 0.5_wp*(xi(i) + 1.0_wp)
            do j = 1, 3
               y = 0.5_wp*(xi(j) + 1.0_wp)
               call patch_add_point(patch, [x, y], 0.25_wp*wt(i)*wt(j), [0.0_wp, 0.0_wp, 0.0_wp])
            end do
            g = x**2 + 0.5_wp*x**3
            call patch_add_boundary_point(patch, [x, 0.0_wp], 0.5_wp*wt(i), [0.0_wp, -1.0_wp], &
               & boundary_traction, [0.0_wp, -g])
            f = 0.5_wp*wt(i)*(1.0_wp - abs(x))**4
            nm = nm + f*reshape([1.0_wp, x, x, x*x], [2, 2])
            rhs = rhs + f*g*[1.0_wp, x]
         end do
      end do
      det = nm(1, 1)*nm(2, 2) - nm(1, 2)*nm(2, 1)
      a = (nm(2, 2)*rhs(1) - nm(1, 2)*rhs(2))/det
      b = (nm(1, 1)*rhs(2) - nm(2, 1)*rhs(1))/det
      call recover_sprc(patch, 1, ws, rec, error)
      if (allocated(error)) return
      call check(error, rec%ranks(kind_traction) == 4, 'flat-face traction rank 4')
      if (allocated(error)) return
      do k = 1, 3
         x = -0.7_wp + 0.6_wp*k
         call eval_recovered(rec, [x, 0.4_wp], sig, error)
         if (allocated(error)) return
         call check(error, abs(sig(2) - (a + b*x)) <= tol_exact*abs(a), 'sigma_yy is the focused fit of g')
         if (allocated(error)) return
         call check(error, abs(sig(3)) <= tol_exact*abs(a), 'sigma_xy vanishes')
         if (allocated(error)) return
      end do
   end subroutine test_traction_focus

   !> Traction rank cap (solve.f90 notes (c)): on a curved face (an arc) the traction is
   !> matched up to degree p - 1 along it, 2 (p - 1 + 1) rows in 2D: 2 for p = 1, 4 for p = 2;
   !> on a flat face of the same patch size, the full 4 and 6 (known_ranks has more).
   subroutine test_traction_curved_rank(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      real(wp) :: xi(3), wt(3), x, y, th, n(2)
      integer :: i, j, p, k, curved
      character(len=40) :: tag

      call gauss(3, xi, wt)
      do curved = 0, 1
         do p = 1, 2
            call patch_reset(patch, 2, plane_stress, 1000.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
            do i = 1, 3
               do j = 1, 3
                  do k = 0, 1
                     x = k - 1 + 0.5_wp*(xi(i) + 1.0_wp)
                     y = -0.5_wp*(xi(j) + 1.0_wp)
                     call patch_add_point(patch, [x, y], 0.25_wp*wt(i)*wt(j), [0.1_wp*x, 0.2_wp*y, 0.0_wp])
                  end do
               end do
            end do
            do k = -4, 4
               th = 0.1_wp*k
               if (curved == 1) then
                  ! Arc of radius 2 through the node, centre (0, -2), outward normals.
                  n = [sin(th), cos(th)]
                  call patch_add_boundary_point(patch, 2.0_wp*n - [0.0_wp, 2.0_wp], 0.2_wp, n, &
                     & boundary_traction, [0.0_wp, 0.0_wp])
               else
                  call patch_add_boundary_point(patch, [2.0_wp*th, 0.0_wp], 0.2_wp, [0.0_wp, 1.0_wp], &
                     & boundary_traction, [0.0_wp, 0.0_wp])
               end if
            end do
            write (tag, '(" (p ",i0,", curved ",i0,")")') p, curved
            call recover_sprc(patch, p, ws, rec, error)
            if (allocated(error)) return
            call check(error, rec%ranks(kind_traction), merge(2*p, 2*(p + 1), curved == 1), 'traction rank'//tag)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_traction_curved_rank

   !> Traction rows per face only where the node lies on that face (solve.f90 notes (c)): a
   !> 2D patch left of the face x = 0 through its node, plus a short traction face y = 0.9
   !> (another boundary piece, e.g. the arc left by a cut corner) whose tangent plane is
   !> 0.9 h > traction_reach h from the node. Only the node's own face is imposed, with its
   !> flat rank 2 (p + 1) for p = 1, 2. (Before: the far face added its own full-rank rows,
   !> which on a Q2 grid pinned the patch to a 0.02 h arc and gave coefficients ~1e3.)
   subroutine test_traction_face_off_node(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      real(wp) :: xi(3), wt(3), x, y
      integer :: i, j, k, p
      character(len=20) :: tag

      call gauss(3, xi, wt)
      do p = 1, 2
         call patch_reset(patch, 2, plane_stress, 1000.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
         do k = 0, 1
            do i = 1, 3
               x = -0.5_wp*(xi(i) + 1.0_wp)
               do j = 1, 3
                  y = k - 1 + 0.5_wp*(xi(j) + 1.0_wp)
                  call patch_add_point(patch, [x, y], 0.25_wp*wt(i)*wt(j), [0.1_wp*x, 0.2_wp*y, 0.0_wp])
               end do
               y = k - 1 + 0.5_wp*(xi(i) + 1.0_wp)
               call patch_add_boundary_point(patch, [0.0_wp, y], 0.5_wp*wt(i), [1.0_wp, 0.0_wp], &
                  & boundary_traction, [0.0_wp, 0.0_wp], piece=1)
            end do
         end do
         do i = 1, 3
            x = -0.15_wp + 0.05_wp*xi(i)
            call patch_add_boundary_point(patch, [x, 0.9_wp], 0.05_wp*wt(i), [0.0_wp, 1.0_wp], &
               & boundary_traction, [0.0_wp, 0.0_wp], piece=2)
         end do
         write (tag, '(" (p ",i0,")")') p
         call recover_sprc(patch, p, ws, rec, error)
         if (allocated(error)) return
         call check(error, rec%ranks(kind_traction), 2*(p + 1), 'traction rank of the node''s face'//trim(tag))
         if (allocated(error)) return
      end do
   end subroutine test_traction_face_off_node

   subroutine test_noisy(error)
      type(error_type), allocatable, intent(out) :: error
      type(field_t) :: f
      type(frame_t) :: fr
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer(i8) :: st
      real(wp) :: req, rcomp, rtr, rsym
      integer :: d, p, v
      character(len=48) :: tag

      do d = 2, 3
         do p = 1, 2
            do v = v_internal, v_mixed
               write (tag, '(" (dim ",i0,", p ",i0,", variant ",i0,")")') d, p, v
               st = 4242_i8 + 10*d + p + 100*v
               call make_field(d, p, v >= v_symmetry, st, f)
               fr%r = rotation(d, -0.6_wp, 0.35_wp, 0.25_wp)
               call make_patch(d, p, v, merge(plane_strain, solid, d == 2), f, fr, 0.3_wp, st, patch)
               patch%all_boundary_kinds = .true.
               call recover_sprc(patch, p, ws, rec, error)
               if (allocated(error)) return
               call residuals(patch, rec, fr, st, req, rcomp, rtr, rsym)
               call check(error, max(req, rcomp, rtr, rsym) <= tol_exact, 'SPR-C constraints on noisy data'//tag)
               if (allocated(error)) return
               call recover_spr(patch, p, ws, rec, error)
               if (allocated(error)) return
               call residuals(patch, rec, fr, st, req, rcomp, rtr, rsym)
               call check(error, req > 1.0e-4_wp, 'SPR on noisy data is not equilibrated'//tag)
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_noisy

   !> The same noisy patch at unit size near the origin and translated by 1e6 and scaled by 1e6
   !> (body force scaled by 1/L) gives the same recovered stresses at corresponding points to
   !> 1e-9 relative: only scaled coordinates (x - x0)/h enter the solves.
   subroutine test_scaling(error)
      type(error_type), allocatable, intent(out) :: error
      type(field_t) :: f
      type(frame_t) :: fa, fb
      type(patch_type) :: pa, pb
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: ra, rb
      integer(i8) :: st, st0
      real(wp) :: y(3), sa(6), sb(6), emax, smax
      integer :: d, p, v, it, k, method

      fb%x0 = [1.0e6_wp, -2.0e6_wp, 3.0e6_wp]
      fb%l = 1.0e6_wp
      do d = 2, 3
         do p = 1, 2
            do v = v_internal, v_mixed, 3
               do method = 1, 2
                  st0 = 777_i8 + d + 10*p + 100*v
                  st = st0
                  call make_field(d, p, v == v_mixed, st, f)
                  call make_patch(d, p, v, merge(plane_stress, solid, d == 2), f, fa, 0.2_wp, st, pa)
                  st = st0
                  call make_field(d, p, v == v_mixed, st, f)
                  call make_patch(d, p, v, merge(plane_stress, solid, d == 2), f, fb, 0.2_wp, st, pb)
                  if (method == 1) then
                     call recover_spr(pa, p, ws, ra, error)
                     if (.not. allocated(error)) call recover_spr(pb, p, ws, rb, error)
                  else
                     call recover_sprc(pa, p, ws, ra, error)
                     if (.not. allocated(error)) call recover_sprc(pb, p, ws, rb, error)
                  end if
                  if (allocated(error)) return
                  emax = 0.0_wp
                  smax = 0.0_wp
                  do it = 1, 30
                     y = 0.0_wp
                     do k = 1, d
                        y(k) = urand(st)
                     end do
                     call eval_recovered(ra, phys(fa, y), sa, error)
                     if (allocated(error)) return
                     call eval_recovered(rb, phys(fb, y), sb, error)
                     if (allocated(error)) return
                     emax = max(emax, maxval(abs(sa(1:ra%nstress) - sb(1:ra%nstress))))
                     smax = max(smax, maxval(abs(sa(1:ra%nstress))))
                  end do
                  call check(error, emax, 0.0_wp, tol_exact*smax, 'scaled by 1e6: same recovered stresses')
                  if (allocated(error)) return
               end do
            end do
         end do
      end do
   end subroutine test_scaling

   !> Collinear points and too few points are rank deficient: stat_singular with the rank.
   subroutine test_rank_deficient(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer :: i
      real(wp) :: t

      ! Six points on the line y = 0.5 x + 0.1: a linear basis in 2D has rank 2 there.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.25_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      do i = 1, 6
         t = -1.0_wp + 0.4_wp*i
         call patch_add_point(patch, [t, 0.5_wp*t + 0.1_wp], 0.1_wp, [1.0_wp, 2.0_wp, 3.0_wp])
      end do
      call recover_spr(patch, 1, ws, rec, error)
      call check_singular(2)
      if (allocated(error)) return
      call recover_sprc(patch, 1, ws, rec, error)
      call check_singular(2)
      if (allocated(error)) return
      ! Quadratic basis (6 terms) with 5 points in general position.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.25_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      do i = 1, 5
         call patch_add_point(patch, [cos(1.3_wp*i), sin(0.7_wp*i)], 0.1_wp, [1.0_wp, 2.0_wp, 3.0_wp])
      end do
      call recover_spr(patch, 2, ws, rec, error)
      call check_singular(5)
      if (allocated(error)) return
      ! 3D linear basis with points on a plane: rank 3 of 4.
      call patch_reset(patch, 3, solid, 1.0_wp, 0.25_wp, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp)
      do i = 1, 8
         call patch_add_point(patch, [cos(1.1_wp*i), sin(2.1_wp*i), 0.3_wp*cos(1.1_wp*i) - sin(2.1_wp*i)], &
            & 0.1_wp, [1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 6.0_wp])
      end do
      call recover_sprc(patch, 1, ws, rec, error)
      call check_singular(3)
   contains
      subroutine check_singular(rank)
         integer, intent(in) :: rank
         if (.not. allocated(error)) then
            call test_failed(error, 'rank-deficient patch was not detected')
            return
         end if
         if (error%stat /= stat_singular .or. index(error%message, 'rank deficient') == 0) then
            call test_failed(error, 'wrong status/message for a rank-deficient patch: '//error%message)
            return
         end if
         deallocate (error)
         call check(error, rec%basis_rank, rank, 'basis rank reported')
      end subroutine check_singular
   end subroutine test_rank_deficient

   !> The boundary kind with the larger measure wins; contact always wins; none without points.
   subroutine test_dominant(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch

      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.25_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      call check(error, dominant_boundary_kind(patch), boundary_none, 'no boundary points')
      if (allocated(error)) return
      call patch_add_boundary_point(patch, [0.0_wp, 0.0_wp], 0.3_wp, [1.0_wp, 0.0_wp], boundary_traction, &
         & [0.0_wp, 0.0_wp])
      call patch_add_boundary_point(patch, [0.0_wp, 0.1_wp], 0.2_wp, [1.0_wp, 0.0_wp], boundary_symmetry)
      call patch_add_boundary_point(patch, [0.0_wp, 0.2_wp], 0.2_wp, [1.0_wp, 0.0_wp], boundary_symmetry)
      call check(error, dominant_boundary_kind(patch), boundary_symmetry, 'symmetry 0.4 > traction 0.3')
      if (allocated(error)) return
      patch%bw(1) = 0.5_wp
      call check(error, dominant_boundary_kind(patch), boundary_traction, 'traction 0.5 > symmetry 0.4')
      if (allocated(error)) return
      call patch_add_boundary_point(patch, [0.0_wp, 0.3_wp], 1.0e-6_wp, [1.0_wp, 0.0_wp], boundary_contact)
      call check(error, dominant_boundary_kind(patch), boundary_contact, 'contact always wins')
   end subroutine test_dominant

   !> A workspace used for a large 3D patch and then a small 2D one and back gives the same
   !> results as fresh workspaces (capacities and lwork are reused correctly).
   subroutine test_workspace_reuse(error)
      type(error_type), allocatable, intent(out) :: error
      type(field_t) :: f2, f3
      type(frame_t) :: fr
      type(patch_type) :: p2, p3
      type(recovery_workspace_type) :: ws, fresh2, fresh3
      type(recovered_patch_type) :: a, b
      integer(i8) :: st

      st = 31_i8
      call make_field(2, 2, .false., st, f2)
      call make_patch(2, 2, v_traction, plane_stress, f2, fr, 0.1_wp, st, p2)
      call make_field(3, 2, .false., st, f3)
      call make_patch(3, 2, v_traction, solid, f3, fr, 0.1_wp, st, p3)
      call recover_sprc(p3, 2, ws, a, error)
      if (allocated(error)) return
      call recover_sprc(p2, 2, ws, a, error)
      if (allocated(error)) return
      call recover_sprc(p2, 2, fresh2, b, error)
      if (allocated(error)) return
      call check(error, maxval(abs(a%coef - b%coef)), 0.0_wp, tol_exact*maxval(abs(b%coef)), &
         & '2D after 3D in one workspace')
      if (allocated(error)) return
      call recover_sprc(p3, 1, ws, a, error)
      if (allocated(error)) return
      call recover_sprc(p3, 1, fresh3, b, error)
      if (allocated(error)) return
      call check(error, maxval(abs(a%coef - b%coef)), 0.0_wp, tol_exact*maxval(abs(b%coef)), &
         & '3D p=1 after 2D p=2 in one workspace')
   end subroutine test_workspace_reuse

   !> An OpenMP loop over many patches with per-thread workspaces and patch objects gives
   !> bitwise the serial results.
   subroutine test_threads(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: npatch = 48
      type(recovered_patch_type) :: serial(npatch), parallel(npatch)
      logical :: ok(npatch)
      integer :: i

      do i = 1, npatch
         call run_one(i, serial(i), ok(i))
      end do
      call check(error, all(ok), 'serial patch solves succeed')
      if (allocated(error)) return
      ok = .false.
      !$omp parallel do schedule(dynamic, 1)
      do i = 1, npatch
         call run_one(i, parallel(i), ok(i))
      end do
      !$omp end parallel do
      call check(error, all(ok), 'parallel patch solves succeed')
      if (allocated(error)) return
      do i = 1, npatch
         if (any(serial(i)%coef /= parallel(i)%coef)) then
            call test_failed(error, 'parallel result differs from serial')
            return
         end if
      end do
   contains
      subroutine run_one(i, rec, ok)
         integer, intent(in) :: i
         type(recovered_patch_type), intent(out) :: rec
         logical, intent(out) :: ok
         type(recovery_workspace_type) :: ws
         type(patch_type) :: patch
         type(field_t) :: f
         type(frame_t) :: fr
         type(error_type), allocatable :: err
         integer(i8) :: st
         integer :: d, p

         d = 2 + modulo(i, 2)
         p = 1 + modulo(i/2, 2)
         st = 1000_i8 + i
         call make_field(d, p, .false., st, f)
         call make_patch(d, p, modulo(i/4, 2), merge(plane_stress, solid, d == 2), f, fr, 0.1_wp, st, patch)
         if (modulo(i, 3) == 0) then
            call recover_spr(patch, p, ws, rec, err)
         else
            call recover_sprc(patch, p, ws, rec, err)
         end if
         ok = .not. allocated(err)
      end subroutine run_one
   end subroutine test_threads

   !> Union (eq. 102) against a hand sum; partition of unity reproduces a common field;
   !> the ZZ integral against hand-computed energies.
   subroutine test_union_zz(error)
      type(error_type), allocatable, intent(out) :: error
      type(recovered_patch_type) :: recs(2)
      real(wp) :: sig(6), w(4), ss(3, 4), sh(3, 4), err2, ss3(6, 2), sh3(6, 2)
      real(wp), parameter :: e = 200.0_wp, nu = 0.3_wp

      ! Patch 1: sigma = (1 + 2 s_x, 3, -1); patch 2: (5, 4 s_y, 2); s = (x - x0)/h.
      recs(1)%dim = 2
      recs(1)%nstress = 3
      recs(1)%degree = 1
      recs(1)%nterms = 3
      recs(1)%x0 = [1.0_wp, 0.0_wp, 0.0_wp]
      recs(1)%h = 2.0_wp
      allocate (recs(1)%coef(3, 3))
      recs(1)%coef(1:3, 1) = [1.0_wp, 2.0_wp, 0.0_wp]
      recs(1)%coef(1:3, 2) = [3.0_wp, 0.0_wp, 0.0_wp]
      recs(1)%coef(1:3, 3) = [-1.0_wp, 0.0_wp, 0.0_wp]
      recs(2) = recs(1)
      recs(2)%x0 = [0.0_wp, 1.0_wp, 0.0_wp]
      recs(2)%h = 1.0_wp
      recs(2)%coef(1:3, 1) = [5.0_wp, 0.0_wp, 0.0_wp]
      recs(2)%coef(1:3, 2) = [0.0_wp, 0.0_wp, 4.0_wp]
      recs(2)%coef(1:3, 3) = [2.0_wp, 0.0_wp, 0.0_wp]
      ! At x = (3, 3): patch 1 gives (1 + 2*1, 3, -1) = (3, 3, -1); patch 2 (5, 8, 2).
      call eval_union(recs, [0.25_wp, 0.75_wp], [3.0_wp, 3.0_wp], sig, error)
      if (allocated(error)) return
      call check(error, maxval(abs(sig(1:3) - [0.25_wp*3 + 0.75_wp*5, 0.25_wp*3 + 0.75_wp*8, &
         & -0.25_wp + 0.75_wp*2])), 0.0_wp, 1.0e-14_wp, 'union = hand sum')
      if (allocated(error)) return

      ! ZZ, plane stress: uniaxial difference s on area 2: 2 s^2/E; pure shear tau: 2 tau^2 2(1+nu)/E.
      w = 0.5_wp
      ss = 0.0_wp
      sh = 0.0_wp
      ss(1, :) = 3.0_wp
      call zz_error_integral(plane_stress, e, nu, w, ss, sh, err2, error)
      if (allocated(error)) return
      call check(error, err2, 2.0_wp*9.0_wp/e, 1.0e-14_wp, 'ZZ uniaxial', rel=.true.)
      if (allocated(error)) return
      ss = 0.0_wp
      sh(3, :) = 2.0_wp
      call zz_error_integral(plane_stress, e, nu, w, ss, sh, err2, error)
      if (allocated(error)) return
      call check(error, err2, 2.0_wp*4.0_wp*2.0_wp*(1.0_wp + nu)/e, 1.0e-14_wp, 'ZZ shear', rel=.true.)
      if (allocated(error)) return
      ! 3D hydrostatic difference p on volume 1: 3 p^2 (1 - 2 nu)/E.
      ss3 = 0.0_wp
      sh3 = 0.0_wp
      ss3(1:3, :) = 2.0_wp
      call zz_error_integral(solid, e, nu, [0.5_wp, 0.5_wp], ss3, sh3, err2, error)
      if (allocated(error)) return
      call check(error, err2, 3.0_wp*4.0_wp*(1.0_wp - 2.0_wp*nu)/e, 1.0e-14_wp, 'ZZ hydrostatic', rel=.true.)
   end subroutine test_union_zz

   !> Bad input gives stat_invalid_input with a message naming the field.
   subroutine test_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(field_t) :: f
      type(frame_t) :: fr
      type(patch_type) :: patch, good
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec, recs(2)
      type(error_type), allocatable :: err
      integer(i8) :: st
      real(wp) :: nan, sig(6), err2
      integer :: i

      st = 5_i8
      call make_field(2, 1, .true., st, f)
      call make_patch(2, 1, v_mixed, plane_stress, f, fr, 0.0_wp, st, good)
      nan = ieee_nan()

      patch = good
      patch%stress(2, 3) = nan
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('stress(:, 3)')
      if (allocated(error)) return
      patch = good
      call recover_spr(patch, 4, ws, rec, err)
      call expect('degree = 4')
      if (allocated(error)) return
      patch = good
      patch%npoints = size(patch%w) + 1
      call recover_spr(patch, 1, ws, rec, err)
      call expect('exceeds the point arrays')
      if (allocated(error)) return
      patch = good
      patch%dim = 3
      call recover_spr(patch, 1, ws, rec, err)
      call expect('does not match analysis')
      if (allocated(error)) return
      patch = good
      patch%analysis = 7
      call recover_spr(patch, 1, ws, rec, err)
      call expect('analysis = 7')
      if (allocated(error)) return
      patch = good
      patch%h = 0.0_wp
      call recover_spr(patch, 1, ws, rec, err)
      call expect('h = ')
      if (allocated(error)) return
      patch = good
      patch%w(2) = -1.0_wp
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('w(2)')
      if (allocated(error)) return
      patch = good
      patch%young = nan
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('young')
      if (allocated(error)) return
      patch = good
      patch%x(1, 1) = nan
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('x(:, 1)')
      if (allocated(error)) return
      patch = good
      patch%bn(1:2, 1) = 2.0_wp*patch%bn(1:2, 1)
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('unit normal')
      if (allocated(error)) return
      patch = good
      patch%bkind(2) = 9
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('bkind(2)')
      if (allocated(error)) return
      patch = good
      patch%bpiece(2) = 0
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('bpiece(2)')
      if (allocated(error)) return
      patch = good
      do i = 1, patch%nbpoints
         if (patch%bkind(i) == boundary_traction) patch%btraction(1, i) = nan
      end do
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('btraction')
      if (allocated(error)) return
      patch = good
      patch%body_force(2) = nan
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('body_force')
      if (allocated(error)) return
      patch = good
      call patch_add_boundary_point(patch, patch%x(1:2, 1), 0.1_wp, [1.0_wp, 0.0_wp], boundary_contact)
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('contact')
      if (allocated(error)) return
      ! Four different symmetry planes in one patch.
      patch = good
      do i = 1, 4
         call patch_add_boundary_point(patch, [0.1_wp*i, 0.0_wp], 0.1_wp, [cos(0.3_wp*i), sin(0.3_wp*i)], &
            & boundary_symmetry)
      end do
      patch%all_boundary_kinds = .true.
      call recover_sprc(patch, 1, ws, rec, err)
      call expect('4th plane')
      if (allocated(error)) return
      patch = good
      patch%npoints = 0
      call recover_spr(patch, 1, ws, rec, err)
      call expect('no integration points')
      if (allocated(error)) return

      ! Evaluation and estimate.
      call eval_recovered(rec, [0.0_wp, 0.0_wp], sig, err)
      call expect('empty')
      if (allocated(error)) return
      call recover_spr(good, 1, ws, rec, err)
      if (allocated(err)) then
         call test_failed(error, 'good patch failed: '//err%message)
         return
      end if
      call eval_recovered(rec, [0.0_wp], sig, err)
      call expect('x has 1')
      if (allocated(error)) return
      recs = rec
      call eval_union(recs, [1.0_wp], [0.0_wp, 0.0_wp], sig, err)
      call expect('2 patches and 1')
      if (allocated(error)) return
      call zz_error_integral(plane_stress, 1.0_wp, 0.3_wp, [1.0_wp], reshape([1.0_wp, 2.0_wp], [2, 1]), &
         & reshape([1.0_wp, 2.0_wp], [2, 1]), err2, err)
      call expect('shapes')
      if (allocated(error)) return
      call zz_error_integral(plane_stress, 1.0_wp, 0.3_wp, [-1.0_wp], reshape([1.0_wp, 2.0_wp, 3.0_wp], [3, 1]), &
         & reshape([1.0_wp, 2.0_wp, 3.0_wp], [3, 1]), err2, err)
      call expect('w(1)')
      if (allocated(error)) return
      call zz_error_integral(plane_stress, 1.0_wp, 0.3_wp, [1.0_wp], reshape([nan, 2.0_wp, 3.0_wp], [3, 1]), &
         & reshape([1.0_wp, 2.0_wp, 3.0_wp], [3, 1]), err2, err)
      call expect('not finite')
   contains
      subroutine expect(fragment)
         character(len=*), intent(in) :: fragment
         if (.not. allocated(err)) then
            call test_failed(error, 'no error for bad input, expected "'//fragment//'"')
            return
         end if
         if (err%stat /= stat_invalid_input .or. index(err%message, fragment) == 0) then
            call test_failed(error, 'expected invalid input naming "'//fragment//'", got: '//err%message)
            return
         end if
         deallocate (err)
      end subroutine expect
   end subroutine test_errors

   function ieee_nan() result(x)
      use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
      real(wp) :: x
      x = ieee_value(1.0_wp, ieee_quiet_nan)
   end function ieee_nan

   !> A first patch with fewer points than basis terms (3D, degree 2: 10 terms,
   !> 2 points) must size the workspace without LAPACK rejecting the query.
   subroutine test_reserve_few_points(error)
      type(error_type), allocatable, intent(out) :: error
      type(recovery_workspace_type) :: ws
      call workspace_init(ws)
      call workspace_reserve(ws, 3, 2, 2, 0, error)
   end subroutine test_reserve_few_points

   ! ------------------------------------------------------------------ flop counts

   !> The LAWN 41 leading-term formulas against counts worked out by hand, both QR shapes and
   !> both roundings of the thirds (n^3 = 1 and 2 mod 3).
   subroutine test_flop_formulas(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, flops_gemm(2, 3, 4), 48_i8, 'dgemm 2x3x4')
      if (allocated(error)) return
      call check(error, flops_gemv(5, 7), 70_i8, 'dgemv 5x7')
      if (allocated(error)) return
      call check(error, flops_syrk(3, 12), 144_i8, 'dsyrk n=3 k=12: 12*3*4')
      if (allocated(error)) return
      call check(error, flops_geqrf(12, 3), 198_i8, 'dgeqrf 12x3: 216-18')
      if (allocated(error)) return
      call check(error, flops_geqrf(3, 12), 198_i8, 'dgeqrf 3x12 (m < n form)')
      if (allocated(error)) return
      call check(error, flops_geqrf(10, 4), 277_i8, 'dgeqrf 10x4: 320-42.67')
      if (allocated(error)) return
      call check(error, flops_geqrf(10, 5), 417_i8, 'dgeqrf 10x5: 500-83.33')
      if (allocated(error)) return
      call check(error, flops_ormqr_left(12, 3, 3), 378_i8, 'dormqr 12x3, k=3: 432-54')
      if (allocated(error)) return
      call check(error, flops_trtrs(3, 3), 27_i8, 'dtrtrs 3, nrhs 3')
      if (allocated(error)) return
      call check(error, flops_sysv(10, 1), 533_i8, 'dsysv 10: 333.33+200')
      if (allocated(error)) return
      call check(error, flops_sysv(11, 1), 686_i8, 'dsysv 11: 443.67+242')
      if (allocated(error)) return
      call check(error, design_matrix_flops(3, 5, 4, .true.), 30_i8 + 15_i8 + 15_i8 + 20_i8, &
         & 'design matrix 3D, 5 points, 4 terms, weighted')
   end subroutine test_flop_formulas

   !> 2D, seven scattered points, unit weights, arbitrary stresses (no exact field needed:
   !> the counts depend on sizes and ranks only).
   subroutine flop_patch(patch)
      type(patch_type), intent(inout) :: patch
      real(wp), parameter :: x(2, 7) = reshape([0.0_wp, 0.0_wp, 0.5_wp, 0.1_wp, -0.4_wp, 0.3_wp, &
         & 0.2_wp, -0.6_wp, -0.3_wp, -0.2_wp, 0.7_wp, 0.6_wp, -0.6_wp, 0.5_wp], [2, 7])
      integer :: i

      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      do i = 1, size(x, 2)
         call patch_add_point(patch, x(:, i), 1.0_wp, [real(i, wp), 1.0_wp - i, 0.5_wp*i])
      end do
   end subroutine flop_patch

   !> SPR, 2D p=1: nothing counted with timing off; with timing on, exactly its three calls
   !> dgeqp3(np, nt), dormqr(np x ns, nt reflectors), dtrtrs(nt, ns), written out here from
   !> the sizes (nt = 3 makes 2 nt^3 / 3 exact), and twice that after a second solve.
   subroutine test_flop_count_spr(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer(i8) :: np, expected
      integer(i8), parameter :: nt = 3, ns = 3

      call flop_patch(patch)
      ws%normal_equations = .false.
      call recover_spr(patch, 1, ws, rec, error)
      if (allocated(error)) return
      call check(error, ws%flops == 0 .and. ws%design_flops == 0 .and. ws%lapack_seconds == 0.0_wp, &
         & 'nothing counted with timing off')
      if (allocated(error)) return
      np = patch%npoints
      expected = (2*np*nt**2 - 2*nt**3/3) + (4*np*ns*nt - 2*ns*nt**2) + nt**2*ns
      ws%timing = .true.
      call recover_spr(patch, 1, ws, rec, error)
      if (allocated(error)) return
      call check(error, ws%flops, expected, 'SPR 2D p=1 LAPACK flops')
      if (allocated(error)) return
      ! Unweighted: point scaling 2 dim np, basis recurrence np (nt - 1).
      call check(error, ws%design_flops, 2*2*np + np*(nt - 1), 'SPR 2D p=1 design-matrix flops')
      if (allocated(error)) return
      call recover_spr(patch, 1, ws, rec, error)
      if (allocated(error)) return
      call check(error, ws%flops, 2*expected, 'SPR flops accumulate over solves')
      if (allocated(error)) return
      ! The normal equations (this patch is well conditioned): dsyrk + dgemm, dpotrf, dtrtri,
      ! two dtrtrs, and no QR.
      ws%normal_equations = .true.
      ws%flops = 0
      call recover_spr(patch, 1, ws, rec, error)
      if (allocated(error)) return
      call check(error, ws%flops, np*nt*(nt + 1) + 2*nt*ns*np + 2*(nt**3 + 1)/3 + 2*nt**2*ns, &
         & 'SPR 2D p=1 normal-equation flops')
   end subroutine test_flop_count_spr

   !> SPR by the normal equations against the pivoted QR (ws%normal_equations off), on
   !> well-conditioned patches (2D p=1: an interior lattice patch, a corner element, a rotated
   !> one, scattered points; 3D p=1: a hex lattice patch; degree 0): the same coefficients to
   !> 8 np eps kappa^2 relative to the largest (kappa = kappa_F(R) of the QR's R, module notes),
   !> the normal equations taken (their flop count alone). A thin patch (kappa > 100) and a
   !> collinear one take the QR: the same bits, and the rank error as before.
   subroutine test_spr_normal_equations(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      real(wp) :: g(2), c, sn
      integer :: i, j, k, a, b

      g = 0.5_wp + [-0.5_wp, 0.5_wp]/sqrt(3.0_wp)
      ! Interior patch of four unit squares around the origin, 2 x 2 Gauss points each.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], sqrt(2.0_wp))
      do j = -1, 0
         do i = -1, 0
            do b = 1, 2
               do a = 1, 2
                  call add2([i + g(a), j + g(b)])
               end do
            end do
         end do
      end do
      call compare(1, .true., 'interior lattice patch')
      if (allocated(error)) return
      call compare(0, .true., 'degree 0')
      if (allocated(error)) return
      ! Corner: one element.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], sqrt(2.0_wp))
      do b = 1, 2
         do a = 1, 2
            call add2([g(a), g(b)])
         end do
      end do
      call compare(1, .true., 'corner element')
      if (allocated(error)) return
      ! Rotated by 0.3 rad, off the origin, tiny scale.
      c = cos(0.3_wp)
      sn = sin(0.3_wp)
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [1.0e-3_wp, 2.0e-3_wp], 1.0e-3_wp*sqrt(2.0_wp))
      do j = -1, 0
         do i = -1, 0
            do b = 1, 2
               do a = 1, 2
                  call add2(1.0e-3_wp*([1.0_wp, 2.0_wp] + [c*(i + g(a)) - sn*(j + g(b)), sn*(i + g(a)) + c*(j + g(b))]))
               end do
            end do
         end do
      end do
      call compare(1, .true., 'rotated patch')
      if (allocated(error)) return
      ! Scattered points.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [0.1_wp, -0.2_wp], 1.0_wp)
      do i = 1, 9
         call add2([0.1_wp + 0.8_wp*cos(2.1_wp*i), -0.2_wp + 0.7_wp*sin(1.7_wp*i)])
      end do
      call compare(1, .true., 'scattered points')
      if (allocated(error)) return
      ! 3D: eight unit cubes around the origin, 2 x 2 x 2 Gauss points each.
      call patch_reset(patch, 3, solid, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp, 0.0_wp], sqrt(3.0_wp))
      do k = 0, 63
         call patch_add_point(patch, [ibits(k, 0, 1) - 1 + g(1 + ibits(k, 3, 1)), ibits(k, 1, 1) - 1 + &
            & g(1 + ibits(k, 4, 1)), ibits(k, 2, 1) - 1 + g(1 + ibits(k, 5, 1))], 0.125_wp, &
            & [(field3(k, i), i = 1, 6)])
      end do
      call compare(1, .true., '3D lattice patch')
      if (allocated(error)) return
      ! Thin: points in a strip 1e-3 high (kappa ~ 1e3): the QR, bit for bit.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      do i = 1, 8
         call add2([-0.9_wp + 0.25_wp*i, 1.0e-3_wp*sin(3.0_wp*i)])
      end do
      call compare(1, .false., 'thin patch')
      if (allocated(error)) return
      ! Collinear: rank 2 < 3, the same stat_singular from either setting.
      call patch_reset(patch, 2, plane_stress, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      do i = 1, 6
         call add2([-1.0_wp + 0.4_wp*i, 0.1_wp - 0.2_wp*i])
      end do
      call compare(1, .false., 'collinear patch')
   contains
      subroutine add2(x)
         real(wp), intent(in) :: x(2)
         call patch_add_point(patch, x, 0.25_wp, [1.0_wp + x(1) - 2.0_wp*x(2) + 0.01_wp*sin(30.0_wp*x(1)), &
            & x(1)*x(2) - 3.0_wp, 0.5_wp + 0.01_wp*cos(20.0_wp*x(2))])
      end subroutine add2
      pure real(wp) function field3(k, i)
         integer, intent(in) :: k, i
         field3 = real(i, wp) + 0.3_wp*k - 0.01_wp*i*k**2 + 0.01_wp*sin(real(7*k + i, wp))
      end function field3
      !> Solve by both settings; fast: the normal equations must be taken and agree to round-off,
      !> else the two must give the same bits (or the same error).
      subroutine compare(degree, fast, what)
         integer, intent(in) :: degree
         logical, intent(in) :: fast
         character(len=*), intent(in) :: what
         type(recovery_workspace_type) :: wq, wn
         type(recovered_patch_type) :: rq, rn
         type(error_type), allocatable :: eq, en
         real(wp) :: kappa, tol
         integer :: nt, ns, np
         integer(i8) :: normal_flops

         wq%normal_equations = .false.
         wn%timing = .true.
         call recover_spr(patch, degree, wq, rq, eq)
         call recover_spr(patch, degree, wn, rn, en)
         if (allocated(eq) .or. allocated(en)) then
            call check(error, allocated(eq) .and. allocated(en) .and. .not. fast, what//': an error from one setting')
            if (allocated(error)) return
            call check(error, eq%stat == stat_singular .and. en%stat == eq%stat .and. en%message == eq%message, &
               & what//': the same rank error')
            return
         end if
         nt = wq%nt
         ns = wq%ns
         np = patch%npoints
         normal_flops = flops_syrk(nt, np) + flops_gemm(nt, ns, np) + flops_potrf(nt) + flops_trtri(nt) + &
            & 2*flops_trtrs(nt, ns)
         if (.not. fast) then
            call check(error, wn%flops > normal_flops .and. all(rn%coef == rq%coef), what//': the QR, same bits')
            return
         end if
         call check(error, wn%flops == normal_flops .and. rn%basis_rank == nt, what//': normal equations taken')
         if (allocated(error)) return
         kappa = kappa_f(wq%qr(1:nt, 1:nt))
         tol = 8*np*epsilon(1.0_wp)*kappa**2*maxval(abs(rq%coef))
         call check(error, maxval(abs(rn%coef - rq%coef)) <= tol, what//': normal equations = QR to round-off')
      end subroutine compare
      !> |R|_F |R^-1|_F of an upper triangular R (columns of R^-1 by back substitution).
      pure real(wp) function kappa_f(r)
         real(wp), intent(in) :: r(:, :)
         real(wp) :: y(size(r, 1)), s
         integer :: n, i, j
         n = size(r, 1)
         s = 0.0_wp
         do j = 1, n
            y = 0.0_wp
            y(j) = 1.0_wp/r(j, j)
            do i = j - 1, 1, -1
               y(i) = -dot_product(r(i, i + 1:j), y(i + 1:j))/r(i, i)
            end do
            s = s + sum(y**2)
         end do
         kappa_f = sqrt(s*sum([(sum(r(1:j, j)**2), j=1, n)]))
      end function kappa_f
   end subroutine test_spr_normal_equations

   !> SPR-C, 2D p=1, interior patch (equilibrium only; no compatibility below p=2): its
   !> kernels, counted as the LAPACK/BLAS calls of the same operations, with their sizes, written out here; the kept-row counts come from the result
   !> (equilibrium rank 2 for linear stresses in 2D, checked first).
   subroutine test_flop_count_sprc(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      integer(i8) :: np, mr, mc, expected
      integer(i8), parameter :: d = 2, nt = 3, ns = 3, n = nt*ns

      call flop_patch(patch)
      ws%timing = .true.
      call recover_sprc(patch, 1, ws, rec, error)
      if (allocated(error)) return
      call check(error, rec%ranks(kind_equilibrium) == 2 .and. rec%rank_total == 2, 'equilibrium rank 2')
      if (allocated(error)) return
      np = patch%npoints
      mr = rec%ranks(kind_equilibrium)
      mc = rec%rank_total
      expected = (2*np*nt**2 - 2*nt**3/3) &             ! dgeqp3 of the design matrix
         & + np*nt*(nt + 1) &                          ! dsyrk: Mp
         & + d*2*nt*n*nt + 2*n*n*(d*nt) + 2*(d*nt)*n & ! dgemm x d, dgemm, dgemv: equilibrium
         & + (2*n**3 - 2*n**3/3) &                     ! dgeqp3 of the n x n equilibrium rows
         & + nint(2.0_wp*n*mr**2 - 2.0_wp*mr**3/3.0_wp, i8) & ! dgeqp3 of the stacked rows
         & + (4*np*ns*nt - 2*ns*nt**2) &               ! Q^T of the data (as dormqr)
         & + ns*nt**2*mc + (6*n*mc**2 - 2*mc**3 + 1)/3 & ! constrained solve: R^-T per block, QR of W^T,
         & + 2*(4*n*mc - 2*mc**2) + mc**2 &            ! its Q^T and Q on one vector, T^-T,
         & + nt**2*ns                                  ! and R^-1 (as dtrtrs)
      call check(error, ws%flops, expected, 'SPR-C 2D p=1 LAPACK flops')
      if (allocated(error)) return
      ! Weighted: scaling 2 dim np, recurrence np (nt - 1), weights 3 np, row scaling np nt.
      call check(error, ws%design_flops, 2*d*np + np*(nt - 1) + 3*np + np*nt, 'SPR-C design-matrix flops')
   end subroutine test_flop_count_sprc

   !> SPR-C 2D p=1 with one straight traction face of nb points through the node: on top of
   !> the equilibrium-only count (test above), the face's QR (2 nb x n) and Q^T (2 nb x 1,
   !> min(2 nb, n) reflectors), a stacked reduction of mr = 2 + 4 rows instead of 2, and a
   !> constrained solve with more rows. The difference between the two solves is written out from the sizes.
   subroutine test_flop_count_traction(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: patch
      type(recovery_workspace_type) :: ws0, ws1
      type(recovered_patch_type) :: rec0, rec1
      integer(i8) :: m, k, mr0, mr1, expected
      integer(i8), parameter :: n = 9, nb = 5, nt = 3, ns = 3
      integer :: j

      call flop_patch(patch)
      ws0%timing = .true.
      call recover_sprc(patch, 1, ws0, rec0, error)
      if (allocated(error)) return
      do j = 1, int(nb)
         call patch_add_boundary_point(patch, [-0.8_wp + 0.4_wp*(j - 1), 0.0_wp], 0.4_wp, [0.0_wp, -1.0_wp], &
            & boundary_traction, [0.0_wp, 0.1_wp*j])
      end do
      ws1%timing = .true.
      call recover_sprc(patch, 1, ws1, rec1, error)
      if (allocated(error)) return
      call check(error, rec1%ranks(kind_traction) == 4 .and. rec1%rank_total == 6, 'traction rank 4 of 6 in all')
      if (allocated(error)) return
      m = 2*nb
      k = min(m, n)
      mr0 = rec0%rank_total
      mr1 = rec1%rank_total
      expected = ws0%flops &
         & + (6*max(m, n)*min(m, n)**2 - 2*min(m, n)**3 + 1)/3 + (4*m*k - 2*k**2) & ! the face
         & + ((6*n*mr1**2 - 2*mr1**3 + 1)/3 - (6*n*mr0**2 - 2*mr0**3 + 1)/3) &        ! stacked rows
         & + constrained(mr1) - constrained(mr0)                                      ! constrained solve
      call check(error, ws1%flops, expected, 'SPR-C 2D p=1 flops with a traction face')
   contains
      !> The constrained solve's count with mc rows (as in test_flop_count_sprc).
      pure integer(i8) function constrained(mc)
         integer(i8), intent(in) :: mc
         constrained = ns*nt**2*mc + (6*n*mc**2 - 2*mc**3 + 1)/3 + 2*(4*n*mc - 2*mc**2) + mc**2
      end function constrained
   end subroutine test_flop_count_traction

   !> The dense kernels against what they must satisfy: for a 7 x 5 matrix of rank 3 (a
   !> product of 7 x 3 and 3 x 5 factors), Q [R; 0] = A Pi (apply_q on R), Q^T Q = I on a
   !> vector (apply_qt then apply_q), |R_kk| non-increasing to R_44, R_44 and R_55 at round-off
   !> (rank 3 at the solves' 1e-10), the same rank when the factorisation stops at
   !> 1e-12 |R_11|; R x = b and R^T x = b solved to round-off for the leading 3 x 3 R; a
   !> zero diagonal is reported. Tolerances: 100 eps |A| (backward-stable Householder, a
   !> handful of reflections of length 7).
   subroutine test_dense_kernels(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: a(7, 5), f(7, 3), g(3, 5), qr(7, 5), r(7, 5), v(7, 1), v0(7, 1), tau(5), b(3, 2), x(3, 2)
      real(wp) :: tol, vn(5, 2)
      integer :: jpvt(5), i, j
      logical :: ok

      do j = 1, 3
         do i = 1, 7
            f(i, j) = sin(1.3_wp*i*j + 0.7_wp*j)
         end do
         do i = 1, 5
            g(j, i) = cos(0.9_wp*i*j + 0.4_wp*i)
         end do
      end do
      a = matmul(f, g)
      tol = 100.0_wp*epsilon(1.0_wp)*maxval(abs(a))
      qr = a
      call qr_pivoted(7, 5, qr, jpvt, tau, vn)
      r = 0.0_wp
      do j = 1, 5
         r(1:j, j) = qr(1:j, j)
      end do
      call apply_q(7, 5, qr, tau, 5, r)
      call check(error, maxval(abs(r - a(:, jpvt))) <= tol, 'Q R = A Pi')
      if (allocated(error)) return
      call check(error, all([(abs(qr(i + 1, i + 1)) <= abs(qr(i, i)), i=1, 3)]) .and. abs(qr(5, 5)) <= tol .and. &
         & abs(qr(4, 4)) <= tol .and. abs(qr(3, 3)) > 1.0e-10_wp*abs(qr(1, 1)), &
         & '|R_kk| non-increasing, rank 3 revealed')
      if (allocated(error)) return
      v0(:, 1) = [(real(i, wp), i=1, 7)]
      v = v0
      call apply_qt(7, 5, qr, tau, 1, v)
      call check(error, abs(norm2(v) - norm2(v0)) <= 10*epsilon(1.0_wp)*norm2(v0), 'Q^T keeps the norm')
      if (allocated(error)) return
      call apply_q(7, 5, qr, tau, 1, v)
      call check(error, maxval(abs(v - v0)) <= 10*epsilon(1.0_wp)*norm2(v0), 'Q Q^T = I')
      if (allocated(error)) return
      r = a
      call qr_pivoted(7, 5, r, jpvt, tau, vn, 1.0e-12_wp)
      call check(error, all(tau(4:5) == 0.0_wp) .and. abs(r(4, 4)) <= 1.0e-12_wp*abs(r(1, 1)) .and. &
         & abs(r(5, 5)) <= 1.0e-12_wp*abs(r(1, 1)) .and. abs(r(3, 3)) > 1.0e-10_wp*abs(r(1, 1)), &
         & 'stopped at the numerical rank: the same rank 3')
      if (allocated(error)) return
      x = reshape([1.0_wp, -2.0_wp, 0.5_wp, 3.0_wp, 0.25_wp, -1.0_wp], [3, 2])
      b = 0.0_wp
      do j = 1, 3
         b(1:j, :) = b(1:j, :) + spread(qr(1:j, j), 2, 2)*spread(x(j, :), 1, j)
      end do
      call solve_upper(3, qr, 2, b, ok)
      call check(error, ok .and. maxval(abs(b - x)) <= 1.0e6_wp*epsilon(1.0_wp), 'R x = b')
      if (allocated(error)) return
      b = matmul(transpose(upper(qr(1:3, 1:3))), x)
      call solve_upper(3, qr, 2, b, ok, transposed=.true.)
      call check(error, ok .and. maxval(abs(b - x)) <= 1.0e6_wp*epsilon(1.0_wp), 'R^T x = b')
      if (allocated(error)) return
      qr(2, 2) = 0.0_wp
      call solve_upper(3, qr, 2, b, ok)
      call check(error, .not. ok, 'a zero diagonal is reported')
   contains
      pure function upper(m) result(u)
         real(wp), intent(in) :: m(:, :)
         real(wp) :: u(size(m, 1), size(m, 2))
         integer :: p
         u = 0.0_wp
         do p = 1, size(m, 2)
            u(1:p, p) = m(1:p, p)
         end do
      end function upper
   end subroutine test_dense_kernels

end module sprc_test_recovery
