!> Tests of the SPR-C contact pieces of the recovery core: the contact operators
!> (sprc_recovery_contact_operators) and the auxiliary domain
!> (sprc_recovery_contact_aux).
!>
!> Operators are checked against rows computed here by hand (the corrected eqs. 118,
!> 119, 127) and on exact two-body stress pairs built in the contact frame:
!> sigma = R T R^T with T symmetric, so that sigma n = R T e_1 carries the frame
!> traction T(:, 1) chosen per law, and the other entries of T (the in-plane stresses,
!> which may jump across a contact surface) differ between the bodies.
module sprc_test_contact_recovery
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: stat_invalid_input
   use sprc_recovery_contact_operators, only: contact_frame, contact_operator, contact_law_operator, &
      & contact_rows, contact_law_frictionless, contact_law_slip, contact_law_stick, contact_traction
   use sprc_recovery_contact_aux, only: aux_domain_type, new_aux_domain, aux_contains, aux_select
   use sprc_recovery_contact_patch_solve, only: recover_sprc_contact, recover_contact_patch
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_add_point, &
      & patch_add_boundary_point, boundary_contact, boundary_symmetry, boundary_none
   use sprc_recovery_workspace, only: recovery_workspace_type
   use sprc_core_material, only: plane_strain, solid
   use sprc_core_poly, only: poly_basis_type, new_poly_basis
   use sprc_core_text, only: itoa, rtoa
   use sprc_io_namelist, only: read_text_file
   use sprc_study_level, only: study_type, level_type
   use sprc_test_study, only: run_text
   use sprc_contact_result, only: contact_open
   use sprc_estimate_recovered_field, only: recovered_field_type
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type, replaced
   use sprc_core_dense, only: qr_pivoted
   use sprc_estimate_contact_patches, only: point_cells_type, new_point_cells, cells_box, cells_prism, aux_bounds
   use sprc_exact_hertz, only: cattaneo_mindlin_traction
   use sprc_contact_surface, only: contact_surface_type, new_contact_surface
   use sprc_study_run_contact_recovery, only: paired_point
   use sprc_recovery_contact_edge_fit, only: contact_edge_type, fit_edge_gap, gap_amplitude
   implicit none
   private

   public :: collect_contact_recovery

   !> Round-off bound of a residual H sigma1 - H' sigma2 of stresses with entries up to
   !> `smax`, relative: sigma = R T R^T is 2 sums of 3 products per entry, H sigma a sum of
   !> at most 6 products of 3 rounded factors, each step within a few eps; 64 eps covers the
   !> sum of these bounds with room (a wrong row or sign gives an O(1) residual).
   real(wp), parameter :: tol_roundoff = 64*epsilon(1.0_wp)
   !> Round-off tier of values that pass through the coupled patch solve, relative to the
   !> stress scale: sqrt(eps), the tier of the single-patch solves (test_recovery's tol_exact,
   !> which states why): the solve is backward stable, its conditioning is not estimated, and
   !> sqrt(eps) is still 1e5 below the error a wrong contact row makes.
   real(wp), parameter :: tol_exact = sqrt(epsilon(1.0_wp))

   !> A linear stress field in coordinates (x, y, z) with the contact plane z = 0 (the last
   !> coordinate; 2D uses (x, z) as (x, y)): sxz = tx + a.x, syz = ty + b.x,
   !> szz = e + f x + g y + h z, sxy = q0 + q.x, sxx = p0 + px x + py y + pz z,
   !> syy = r0 + rx x + ry y + rz z, with h, px, ry fixed by div sigma + bf = 0 (constant body
   !> force bf, so that the equilibrium rows have a nonzero right-hand side); linear stresses
   !> are compatible.
   type :: linear_field_t
      real(wp) :: tx = 0, a(3) = 0, ty = 0, b(3) = 0, e = 0, f = 0, g = 0, q0 = 0, q(3) = 0
      real(wp) :: p0 = 0, py = 0, pz = 0, r0 = 0, rx = 0, rz = 0, bf(3) = 0
   end type linear_field_t

contains

   subroutine collect_contact_recovery(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('operator_2d_errata', test_operator_2d), &
         new_unittest('operator_3d_errata', test_operator_3d), &
         new_unittest('laws_2d', test_laws_2d), &
         new_unittest('laws_3d', test_laws_3d), &
         new_unittest('rows', test_rows), &
         new_unittest('traction_p_ts', test_traction_p_ts), &
         new_unittest('operator_errors', test_operator_errors), &
         new_unittest('aux_flat_3d', test_aux_flat_3d), &
         new_unittest('aux_curved_2d', test_aux_curved_2d), &
         new_unittest('aux_errors', test_aux_errors), &
         new_unittest('coupled_exact_2d', test_coupled_exact_2d), &
         new_unittest('coupled_exact_3d', test_coupled_exact_3d), &
         new_unittest('coupled_wrong_law', test_coupled_wrong_law), &
         new_unittest('coupled_offset', test_coupled_offset), &
         new_unittest('paired_point_ring', test_paired_point), &
         new_unittest('coupled_weight2', test_coupled_weight), &
         new_unittest('coupled_errors', test_coupled_errors), &
         new_unittest('contact_patch_depth', test_contact_patch_depth), &
         new_unittest('study_patch_pressures', test_study_patch_pressures), &
         new_unittest('grid_exact_2d', test_grid_exact_2d), &
         new_unittest('grid_exact_3d', test_grid_exact_3d), &
         new_unittest('traction_jump_shrink_fit', test_traction_jump), &
         new_unittest('aux_boundary_points', test_aux_boundary), &
         new_unittest('aux_candidates', test_aux_candidates), &
         new_unittest('qr_max_steps', test_qr_max_steps), &
         new_unittest('cells_prism', test_cells_prism), &
         new_unittest('cattaneo_mindlin_sprc', test_cattaneo_sprc), &
         new_unittest('edge_gap_fit', test_edge_gap_fit) &
         ]
   end subroutine collect_contact_recovery

   ! ------------------------------------------------------------------ operators

   !> 2D H at n = (0.6, 0.8) with the slip along s = (-0.8, 0.6), by hand:
   !> row 1 (nx^2, ny^2, 2 nx ny) (erratum of eq. 118), row 2 (nx sx, ny sy, nx sy + ny sx).
   !> A slip along -s flips row 2.
   subroutine test_operator_2d(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: frame(3, 3), h(3, 6), want(2, 3)

      want(1, :) = [0.36_wp, 0.64_wp, 0.96_wp]
      want(2, :) = [-0.48_wp, 0.48_wp, -0.28_wp]
      call contact_frame(2, [0.6_wp, 0.8_wp], frame, error, slip=[-1.6_wp, 1.2_wp])
      if (allocated(error)) return
      call contact_operator(2, frame, h)
      call check(error, maxval(abs(h(1:2, 1:3) - want)) <= 4*epsilon(1.0_wp), 'H 2D = corrected eq. 118')
      if (allocated(error)) return
      call contact_frame(2, [0.6_wp, 0.8_wp], frame, error, slip=[0.8_wp, -0.6_wp])
      if (allocated(error)) return
      call contact_operator(2, frame, h)
      call check(error, maxval(abs(h(2, 1:3) + want(2, :))) <= 4*epsilon(1.0_wp), 'H 2D row 2 follows the slip sign')
   end subroutine test_operator_2d

   !> 3D H at n = (1, 2, 2)/3, slip s = (2, 1, -2)/3, so p = n x s = (-2, 2, -1)/3; rows by hand
   !> (eq. 119 corrected: 2 n_a n_b in row 1, n_x p_z + n_z p_x = -5/9 last in row 3, where the
   !> seed's n_x s_z + n_z s_x would give 2/9).
   subroutine test_operator_3d(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: frame(3, 3), h(3, 6), want(3, 6)

      want(1, :) = [1, 4, 4, 4, 8, 4]/9.0_wp
      want(2, :) = [2, 2, -4, 5, -2, 2]/9.0_wp
      want(3, :) = [-2, 4, -2, -2, 2, -5]/9.0_wp
      call contact_frame(3, [1, 2, 2]/3.0_wp, frame, error, slip=[2, 1, -2]/3.0_wp + 0.7_wp*[1, 2, 2]/3.0_wp)
      if (allocated(error)) return
      call check(error, maxval(abs(frame(:, 3) - [-2, 2, -1]/3.0_wp)) <= 4*epsilon(1.0_wp), &
         & 'p = n x s (slip projected onto the tangent plane)')
      if (allocated(error)) return
      call contact_operator(3, frame, h)
      call check(error, maxval(abs(h - want)) <= 8*epsilon(1.0_wp), 'H 3D = corrected eq. 119')
   end subroutine test_operator_3d

   subroutine test_laws_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call law_pairs(2, [0.6_wp, 0.8_wp, 0.0_wp], [-0.8_wp, 0.6_wp, 0.0_wp], error)
      if (allocated(error)) return
      call law_pairs(2, [-0.28_wp, 0.96_wp, 0.0_wp], [0.96_wp, 0.28_wp, 0.0_wp], error)
   end subroutine test_laws_2d

   subroutine test_laws_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call law_pairs(3, [1, 2, 2]/3.0_wp, [2, 1, -2]/3.0_wp, error)
      if (allocated(error)) return
      call law_pairs(3, [0.0_wp, 0.0_wp, -1.0_wp], [0.6_wp, -0.8_wp, 0.0_wp], error)
   end subroutine test_laws_3d

   !> For each law, a pair that satisfies it (residual at round-off) and pairs that violate it
   !> (residual of the size of the violation). n, s unit and orthogonal; p = n x s.
   subroutine law_pairs(dim, n, s, error)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(3), s(3)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: mu = 0.3_wp, tn = -1.7_wp, mu_wrong = 0.5_wp
      real(wp) :: r(3, 3), t1(3, 3), t2(3, 3)

      r(:, 1) = n
      r(:, 2) = s
      r(:, 3) = [n(2)*s(3) - n(3)*s(2), n(3)*s(1) - n(1)*s(3), n(1)*s(2) - n(2)*s(1)]
      ! Frictionless: equal normal tractions, no tangential traction on either body.
      call frame_stresses([tn, 0.0_wp, 0.0_wp], [tn, 0.0_wp, 0.0_wp], t1, t2)
      call expect(contact_law_frictionless, 0.0_wp, .true., 'frictionless, law satisfied')
      call frame_stresses([tn, 0.0_wp, 0.0_wp], [0.9_wp*tn, 0.0_wp, 0.0_wp], t1, t2)
      call expect(contact_law_frictionless, 0.0_wp, .false., 'frictionless, normal tractions differ')
      call frame_stresses([tn, 0.4_wp, 0.0_wp], [tn, 0.4_wp, 0.0_wp], t1, t2)
      call expect(contact_law_frictionless, 0.0_wp, .false., 'frictionless, tangential traction')
      ! Coulomb slip: t_s = mu t_n on body (1) (opposed to its slip along s), t_p = 0.
      call frame_stresses([tn, mu*tn, 0.0_wp], [tn, mu*tn, 0.0_wp], t1, t2)
      call expect(contact_law_slip, mu, .true., 'slip, law satisfied')
      call frame_stresses([tn, -mu*tn, 0.0_wp], [tn, -mu*tn, 0.0_wp], t1, t2)
      call expect(contact_law_slip, mu, .false., 'slip, friction along the slip instead of against it')
      call frame_stresses([tn, mu_wrong*tn, 0.0_wp], [tn, mu_wrong*tn, 0.0_wp], t1, t2)
      call expect(contact_law_slip, mu, .false., 'slip, wrong friction coefficient')
      if (dim == 3) then
         call frame_stresses([tn, mu*tn, 0.2_wp], [tn, mu*tn, 0.2_wp], t1, t2)
         call expect(contact_law_slip, mu, .false., 'slip, traction across the slip direction')
      end if
      ! Stick: the whole traction vector continuous.
      call frame_stresses([tn, 0.4_wp, -0.3_wp], [tn, 0.4_wp, -0.3_wp], t1, t2)
      call expect(contact_law_stick, 0.0_wp, .true., 'stick, law satisfied')
      call frame_stresses([tn, 0.4_wp, -0.3_wp], [tn, 0.5_wp, -0.3_wp], t1, t2)
      call expect(contact_law_stick, 0.0_wp, .false., 'stick, tangential tractions differ')
   contains
      !> Frame stresses with frame tractions a (body 1) and b (body 2) and different in-plane parts.
      subroutine frame_stresses(a, b, t1, t2)
         real(wp), intent(in) :: a(3), b(3)
         real(wp), intent(out) :: t1(3, 3), t2(3, 3)
         t1 = reshape([a(1), a(2), a(3), a(2), 0.8_wp, 0.25_wp, a(3), 0.25_wp, -0.6_wp], [3, 3])
         t2 = reshape([b(1), b(2), b(3), b(2), -1.3_wp, 0.5_wp, b(3), 0.5_wp, 0.9_wp], [3, 3])
         if (dim == 2) then
            t1(3, :) = 0.0_wp
            t1(:, 3) = 0.0_wp
            t2(3, :) = 0.0_wp
            t2(:, 3) = 0.0_wp
         end if
      end subroutine frame_stresses

      subroutine expect(law, mu_law, zero, what)
         integer, intent(in) :: law
         real(wp), intent(in) :: mu_law
         logical, intent(in) :: zero
         character(len=*), intent(in) :: what
         real(wp) :: frame(3, 3), h(3, 6), hp(3, 6), res(3), smax
         character(len=160) :: buf

         if (allocated(error)) return
         call contact_frame(dim, n(1:dim), frame, error, slip=s(1:dim))
         if (allocated(error)) return
         call contact_operator(dim, frame, h)
         call contact_law_operator(dim, law, mu_law, h, hp, error)
         if (allocated(error)) return
         res(1:dim) = matmul(h(1:dim, 1:nvoigt()), voigt(rotate(t1))) - matmul(hp(1:dim, 1:nvoigt()), voigt(rotate(t2)))
         smax = max(maxval(abs(t1)), maxval(abs(t2)))
         write (buf, '(a," (dim ",i0,"): |residual| = ",es10.3,", round-off bound ",es10.3)') what, dim, &
            & maxval(abs(res(1:dim))), tol_roundoff*smax
         if (zero) then
            call check(error, maxval(abs(res(1:dim))) <= tol_roundoff*smax, trim(buf))
         else
            call check(error, maxval(abs(res(1:dim))) > 1.0e-2_wp*smax, trim(buf))
         end if
      end subroutine expect

      pure integer function nvoigt()
         nvoigt = merge(3, 6, dim == 2)
      end function nvoigt

      pure function rotate(t) result(sig)
         real(wp), intent(in) :: t(3, 3)
         real(wp) :: sig(3, 3)
         sig = matmul(r, matmul(t, transpose(r)))
      end function rotate

      pure function voigt(sig) result(v)
         real(wp), intent(in) :: sig(3, 3)
         real(wp) :: v(merge(3, 6, dim == 2))
         if (dim == 2) then
            v = [sig(1, 1), sig(2, 2), sig(1, 2)]
         else
            v = [sig(1, 1), sig(2, 2), sig(3, 3), sig(1, 2), sig(2, 3), sig(1, 3)]
         end if
      end function voigt
   end subroutine law_pairs

   !> contact_rows: (op x p) A equals op applied to the stress P A at the point (2D, degree 1).
   subroutine test_rows(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: op(3, 6), rows(3, 18), a(3, 3), p(3), sig(3), want(3), scale
      integer :: c

      op(1:2, 1:3) = reshape([1.0_wp, -2.0_wp, 0.5_wp, 3.0_wp, -1.0_wp, 0.25_wp], [2, 3])
      a = reshape([1.0_wp, 2.0_wp, 3.0_wp, -1.0_wp, 0.5_wp, 4.0_wp, 2.0_wp, -3.0_wp, 1.5_wp], [3, 3])
      p = [1.0_wp, 0.3_wp, -0.7_wp]
      call contact_rows(2, 3, op, p, -2.0_wp, rows)
      do c = 1, 3
         sig(c) = dot_product(p, a(:, c))
      end do
      want(1:2) = -2.0_wp*matmul(op(1:2, 1:3), sig)
      ! Both sides are sums of 9 products of 4 factors: bounded by the sum of |terms| times a few eps.
      scale = 2.0_wp*sum(abs(op(1:2, 1:3)))*maxval(abs(p))*maxval(abs(a))
      call check(error, maxval(abs(matmul(rows(1:2, 1:9), reshape(a, [9])) - want(1:2))) <= tol_roundoff*scale, &
         & 'rows (op x p) A = factor op (P A)')
   end subroutine test_rows

   !> p and ts by hand: n = (0.6, 0.8), sigma = (1, 2, 0.5): sigma n = (1.0, 1.9), t_n = 2.12,
   !> tangential part (-0.272, 0.204) of length 0.34; 3D: sigma = diag(1, 2, -3) at n = e_z:
   !> p = 3, ts = 0.
   subroutine test_traction_p_ts(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: p, ts

      call contact_traction(2, [0.6_wp, 0.8_wp], [1.0_wp, 2.0_wp, 0.5_wp], p, ts)
      call check(error, abs(p + 2.12_wp) <= 8*epsilon(1.0_wp) .and. abs(ts - 0.34_wp) <= 8*epsilon(1.0_wp), &
         & 'p, ts in 2D by hand')
      if (allocated(error)) return
      call contact_traction(3, [0.0_wp, 0.0_wp, 1.0_wp], [1.0_wp, 2.0_wp, -3.0_wp, 0.4_wp, 0.0_wp, 0.0_wp], p, ts)
      call check(error, abs(p - 3.0_wp) <= 4*epsilon(1.0_wp) .and. ts <= 4*epsilon(1.0_wp), 'p, ts in 3D by hand')
   end subroutine test_traction_p_ts

   subroutine test_operator_errors(error)
      use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      real(wp) :: frame(3, 3), h(3, 6), hp(3, 6)

      call contact_frame(2, [0.6_wp, 0.7_wp], frame, err)
      call expect_invalid(error, err, 'non-unit normal', 'unit normal')
      call contact_frame(3, [0.0_wp, 0.0_wp, 1.0_wp], frame, err, slip=[0.0_wp, 0.0_wp, -2.0_wp])
      call expect_invalid(error, err, 'slip along the normal', 'slip direction')
      call contact_frame(3, [0.0_wp, 0.0_wp, 1.0_wp], frame, err, slip=[ieee_value(1.0_wp, ieee_quiet_nan), 1.0_wp, 0.0_wp])
      call expect_invalid(error, err, 'slip not finite', 'slip direction')
      call contact_frame(3, [0.0_wp, 0.0_wp, 1.0_wp], frame, err)
      if (allocated(err)) then
         call test_failed(error, 'valid frame refused: '//err%message)
         return
      end if
      call contact_operator(3, frame, h)
      call contact_law_operator(3, contact_law_slip, -0.1_wp, h, hp, err)
      call expect_invalid(error, err, 'mu < 0', 'mu =')
      call contact_law_operator(3, 7, 0.1_wp, h, hp, err)
      call expect_invalid(error, err, 'unknown law', 'law = 7')
   end subroutine test_operator_errors

   ! ------------------------------------------------------------------ Omega_aux

   !> A flat contact patch z = 0 over [0, 2] x [0, 1] with normals +z: Omega_aux is the box
   !> [0, 2] x [0, 1] x [0, depth]; points just inside its 8 corners are in, points just
   !> outside each face are out.
   subroutine test_aux_flat_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(aux_domain_type) :: aux
      real(wp), parameter :: depth = 0.75_wp, d = 1.0e-9_wp
      real(wp) :: x(3, 15), n(3, 15), w(15), y(3, 8), lo(3), hi(3)
      integer :: i, j, k, idx(8), cnt

      k = 0
      do j = 0, 2
         do i = 0, 4
            k = k + 1
            x(:, k) = [0.5_wp*i, 0.5_wp*j, 0.0_wp]
            n(:, k) = [0.0_wp, 0.0_wp, 1.0_wp]
            w(k) = 1.0_wp + 0.1_wp*k
         end do
      end do
      call new_aux_domain(aux, 3, x, n, w, depth, 0.0_wp, error)
      if (allocated(error)) return
      call check(error, maxval(abs(aux%frame(:, 1) - [0.0_wp, 0.0_wp, 1.0_wp])) <= epsilon(1.0_wp), 'mean normal +z')
      if (allocated(error)) return
      lo = [0.0_wp, 0.0_wp, 0.0_wp]
      hi = [2.0_wp, 1.0_wp, depth]
      k = 0
      do i = 0, 7
         k = k + 1
         y(:, k) = merge(hi - d, lo + d, [btest(i, 0), btest(i, 1), btest(i, 2)])
      end do
      call aux_select(aux, y, idx, cnt)
      call check(error, cnt, 8, 'points just inside the corners of the box')
      if (allocated(error)) return
      do k = 1, 3
         y(:, 1) = 0.5_wp*(lo + hi)
         y(k, 1) = lo(k) - d
         y(:, 2) = 0.5_wp*(lo + hi)
         y(k, 2) = hi(k) + d
         call check(error, .not. aux_contains(aux, y(:, 1)) .and. .not. aux_contains(aux, y(:, 2)), &
            & 'points just outside a face of the box are out')
         if (allocated(error)) return
      end do
   end subroutine test_aux_flat_3d

   !> Contact points on the unit circle (body (1) a disc) at angles -0.2 .. 0.2, radial normals,
   !> equal weights: nbar = (1, 0), centre (c, 0) with c the mean of cos(phi), cross-section
   !> |y2| <= sin 0.2, cos 0.2 <= y1 <= 1 + depth. Points by hand; then the same arc as the
   !> inside of a ring (body (1) the ring, normals inward): body (2), the disc, is kept.
   subroutine test_aux_curved_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(aux_domain_type) :: aux
      real(wp), parameter :: depth = 0.5_wp
      real(wp) :: x(2, 5), n(2, 5), w(5), phi, cbar, y(2, 8)
      integer :: i, idx(8), cnt
      logical, parameter :: want(8) = [.true., .false., .false., .true., .true., .false., .false., .true.]

      cbar = 0.0_wp
      do i = 1, 5
         phi = 0.1_wp*(i - 3)
         x(:, i) = [cos(phi), sin(phi)]
         n(:, i) = x(:, i)
         w(i) = 0.1_wp
         cbar = cbar + cos(phi)/5
      end do
      call new_aux_domain(aux, 2, x, n, w, depth, 0.0_wp, error)
      if (allocated(error)) return
      call check(error, abs(aux%frame(1, 1) - 1.0_wp) <= 2*epsilon(1.0_wp) .and. &
         & abs(aux%frame(2, 1)) <= 2*epsilon(1.0_wp) .and. abs(aux%centre(1) - cbar) <= 4*epsilon(1.0_wp), &
         & 'curved: mean normal (1, 0) and centroid (mean cos, 0)')
      if (allocated(error)) return
      ! in; beside (|y2| > sin 0.2 = 0.19867); beyond the depth plane (y1 > 1.5); near the upper
      ! corner; just above the lowest contact point (cos 0.2 = 0.98007); below it; beside, low;
      ! just below the depth plane, depth beyond the highest contact point (1).
      y = reshape([1.1_wp, 0.0_wp, 1.1_wp, 0.25_wp, 1.6_wp, 0.0_wp, 1.45_wp, 0.19_wp, 0.99_wp, 0.19_wp, &
         & 0.97_wp, 0.0_wp, 1.0_wp, -0.2_wp, 1.49_wp, 0.0_wp], [2, 8])
      call check(error, all([(aux_contains(aux, y(:, i)), i=1, 8)] .eqv. want), 'curved: points in / out by hand')
      if (allocated(error)) return
      call aux_select(aux, y, idx, cnt)
      call check(error, cnt == 4 .and. all(idx(1:4) == [1, 4, 5, 8]), 'curved: aux_select indices')
      if (allocated(error)) return
      ! Ring around the disc: normals -x_i, nbar = (-1, 0); along nbar the arc spans x = 1 .. cos 0.2,
      ! so the prism holds the disc's x in [cos 0.2 - depth, 1] = [0.48007, 1].
      call new_aux_domain(aux, 2, x, -n, w, depth, 0.0_wp, error)
      if (allocated(error)) return
      y(:, 1) = [0.95_wp, 0.0_wp]
      y(:, 2) = [0.98_wp, 0.19_wp]
      y(:, 3) = [0.47_wp, 0.0_wp]
      y(:, 4) = [1.01_wp, 0.0_wp]
      call check(error, aux_contains(aux, y(:, 1)) .and. aux_contains(aux, y(:, 2)) .and. &
         & .not. aux_contains(aux, y(:, 3)) .and. .not. aux_contains(aux, y(:, 4)), &
         & 'ring: disc points next to the arc are in, beyond the depth or in the ring are out')
   end subroutine test_aux_curved_2d

   subroutine test_aux_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(aux_domain_type) :: aux
      real(wp) :: x(2, 2), n(2, 2), w(2)

      x = reshape([0.0_wp, 0.0_wp, 1.0_wp, 0.0_wp], [2, 2])
      n = reshape([0.0_wp, 1.0_wp, 0.0_wp, 1.0_wp], [2, 2])
      w = 1.0_wp
      call new_aux_domain(aux, 2, x, n, w, 0.0_wp, 0.0_wp, err)
      call expect_invalid(error, err, 'depth = 0', 'depth')
      call new_aux_domain(aux, 2, x, n, w, 1.0_wp, -1.0_wp, err)
      call expect_invalid(error, err, 'margin < 0', 'margin')
      call new_aux_domain(aux, 2, x, n, [1.0_wp, -1.0_wp], 1.0_wp, 0.0_wp, err)
      call expect_invalid(error, err, 'negative weight', 'w(2)')
      call new_aux_domain(aux, 2, x, n, [0.0_wp, 0.0_wp], 1.0_wp, 0.0_wp, err)
      call expect_invalid(error, err, 'zero weights', 'sum to 0')
      call new_aux_domain(aux, 2, x, reshape([0.0_wp, 1.0_wp, 0.0_wp, -1.0_wp], [2, 2]), w, 1.0_wp, 0.0_wp, err)
      call expect_invalid(error, err, 'opposite normals', 'cancel')
      call new_aux_domain(aux, 2, x, 2*n, w, 1.0_wp, 0.0_wp, err)
      call expect_invalid(error, err, 'non-unit normal', 'n(:, 1)')
      call new_aux_domain(aux, 2, x(:, 1:0), n(:, 1:0), w(1:0), 1.0_wp, 0.0_wp, err)
      call expect_invalid(error, err, 'no points', 'no contact points')
   end subroutine test_aux_errors

   ! ------------------------------------------------------------------ coupled solve

   !> Exactness (issue 12): two bodies carrying linear fields that satisfy equilibrium,
   !> compatibility and the contact law, sampled at Gauss points of a patch of body (1) (below
   !> the contact plane) and of a non-matching grid of body (2) selected by Omega_aux: the
   !> coupled SPR-C recovers both fields and the contact residual at round-off, p = 1 and 2,
   !> frictionless, slip and stick; side 2 is the mirrored (master-side) patch.
   subroutine test_coupled_exact_2d(error)
      type(error_type), allocatable, intent(out) :: error
      call coupled_laws(2, error)
   end subroutine test_coupled_exact_2d

   subroutine test_coupled_exact_3d(error)
      type(error_type), allocatable, intent(out) :: error
      call coupled_laws(3, error)
   end subroutine test_coupled_exact_3d

   subroutine coupled_laws(dim, error)
      integer, intent(in) :: dim
      type(error_type), allocatable, intent(out) :: error
      type(linear_field_t) :: f1, f2
      real(wp) :: err1, err2, res
      integer :: law, p, side
      real(wp), parameter :: mu = 0.35_wp
      character(len=160) :: buf

      do side = 1, 2
         do p = 1, 2
            do law = contact_law_frictionless, contact_law_stick
               call law_fields(dim, law, mu, f1, f2)
               call coupled_case(dim, p, law, mu, f1, f2, err1, err2, res, error, mirror=side == 2)
               if (allocated(error)) return
               write (buf, '("dim ",i0,", side ",i0,", p = ",i0,", law ",i0,": errors ",es9.2,", ",es9.2, &
                  & ", contact residual ",es9.2," (tier ",es9.2,")")') dim, side, p, law, err1, err2, res, tol_exact
               call check(error, max(err1, err2, res) <= tol_exact, trim(buf))
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine coupled_laws

   !> Surfaces kept apart (an interference): body (2)'s field is that of coupled_laws moved by
   !> g along the contact normal and divided by a measure ratio r, so that forces balance between
   !> x_j and x_j + g n with dA2/dA1 = r. With offset g n and ratio r the coupled SPR-C recovers
   !> both fields and the balance at round-off (2D and 3D, both sides, p = 1 and 2, every law);
   !> the same data recovered as if the surfaces met (no offset, no ratio) are not recovered
   !> exactly: the rows equate t1(x_j) with t2(x_j), which the data do not satisfy.
   subroutine test_coupled_offset(error)
      type(error_type), allocatable, intent(out) :: error
      type(linear_field_t) :: f1, f2
      real(wp) :: err1, err2, res, e0(3)
      integer :: dim, law, p, side
      real(wp), parameter :: mu = 0.35_wp, g = -0.07_wp, r = 0.93_wp
      character(len=200) :: buf

      do dim = 2, 3
         do side = 1, 2
            do p = 1, 2
               do law = contact_law_frictionless, contact_law_stick
                  call law_fields(dim, law, mu, f1, f2)
                  call coupled_case(dim, p, law, mu, f1, f2, err1, err2, res, error, mirror=side == 2, shift=g, &
                     & scale=r)
                  if (allocated(error)) return
                  call coupled_case(dim, p, law, mu, f1, f2, e0(1), e0(2), e0(3), error, mirror=side == 2, shift=g, &
                     & scale=r, ignore=.true.)
                  if (allocated(error)) return
                  write (buf, '("dim ",i0,", side ",i0,", p = ",i0,", law ",i0,": errors ",es9.2,", ",es9.2, &
                     & ", balance ",es9.2,"; without the offset ",es9.2," (tier ",es9.2,")")') dim, side, p, law, err1, &
                     & err2, res, max(e0(1), e0(2)), tol_exact
                  call check(error, max(err1, err2, res) <= tol_exact .and. max(e0(1), e0(2)) > 1.0e3_wp*tol_exact, &
                     & trim(buf))
                  if (allocated(error)) return
               end do
            end do
         end do
      end do
   end subroutine test_coupled_offset

   !> recover_sprc_contact's weight2 on data that disagree across the contact: coupled_laws'
   !> fields with body (2)'s normal stress raised by a constant (still in equilibrium and
   !> compatible, but its traction on the contact plane no longer balances body (1)'s). Weighed
   !> by w2, the fit of the weighed-up body keeps its own data up to O(1/w) of the disagreement
   !> (the constrained least squares moves the two fits in the ratio of their weights), so with
   !> w2 = 1e8 body (2)'s recovered field is its data within 1e-6 of the stress scale (100 times
   !> the 1e-8 the ratio gives), with w2 = 1e-8 body (1)'s is; with w2 = 1 neither is (both move
   !> by a share of the 0.3 raised). 2D and 3D, p = 1 and 2, frictionless.
   subroutine test_coupled_weight(error)
      type(error_type), allocatable, intent(out) :: error
      type(linear_field_t) :: f1, f2
      real(wp) :: err1(3), err2(3), res
      integer :: dim, p, k
      real(wp), parameter :: w(3) = [1.0e8_wp, 1.0e-8_wp, 1.0_wp]
      character(len=200) :: buf

      do dim = 2, 3
         do p = 1, 2
            call law_fields(dim, contact_law_frictionless, 0.0_wp, f1, f2)
            f2%e = f2%e + 0.3_wp
            do k = 1, 3
               call coupled_case(dim, p, contact_law_frictionless, 0.0_wp, f1, f2, err1(k), err2(k), res, error, &
                  & weight2=w(k))
               if (allocated(error)) return
            end do
            write (buf, '("dim ",i0,", p = ",i0,": body (2) w2 = 1e8 ",es9.2,", body (1) w2 = 1e-8 ",es9.2, &
               & ", w2 = 1: ",es9.2,", ",es9.2)') dim, p, err2(1), err1(2), err1(3), err2(3)
            call check(error, err2(1) <= 1.0e-6_wp .and. err1(2) <= 1.0e-6_wp .and. min(err1(3), err2(3)) > 1.0e-3_wp, &
               & trim(buf))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_coupled_weight

   !> The paired point of a slave point on a circle (sphere) of radius R whose master surface is
   !> the concentric one of radius R + g (g < 0: an interference): offset g n on the slave side
   !> (the master point), g n_m on the master side (the slave point), and the measure ratio
   !> 1 + g div_s n = 1 + (dim - 1) g/R on the slave side, 1/(1 + (dim - 1) g/(R + g)) on the
   !> master side, whose points lie on the master surface (the slope of the normal is exact on a
   !> circle or sphere, so only round-off is left: a few eps
   !> per term of the sums over the neighbours, 64 eps with room). A wrong sign or a missing
   !> (dim - 1) is an O(g/R) = 5e-2 error.
   subroutine test_paired_point(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: rr = 2.0_wp, g = -0.1_wp, tol = 64*epsilon(1.0_wp)
      type(contact_surface_type) :: surface
      real(wp) :: x(3, 9), n(3, 9), off(3), ratio, want
      integer :: dim, i, side, np

      do dim = 2, 3
         np = merge(5, 9, dim == 2)
         do i = 1, np
            n(:, i) = 0.0_wp
            if (dim == 2) then
               n(1:2, i) = [cos(0.3_wp + 0.05_wp*i), sin(0.3_wp + 0.05_wp*i)]
            else
               n(:, i) = [0.04_wp*mod(i - 1, 3) + 0.1_wp, 0.05_wp*((i - 1)/3) - 0.03_wp, 1.0_wp]
               n(:, i) = n(:, i)/norm2(n(:, i))
            end if
            x(:, i) = [0.3_wp, -0.2_wp, 0.7_wp] + rr*n(:, i)
         end do
         call new_contact_surface(surface, x(1:dim, 1:np), [(0.1_wp, i=1, np)], n(1:dim, 1:np), [(1, i=1, np)], &
            & error)
         if (allocated(error)) return
         surface%master_x = surface%x + g*surface%normal
         surface%master_normal = -surface%normal
         surface%has_master = [(.true., i=1, np)]
         do side = 1, 2
            ! The master side sees the points on the master surface (radius R + g), as pair_contact.
            want = 1.0_wp + (dim - 1)*g/rr
            if (side == 2) want = 1.0_wp/(1.0_wp + (dim - 1)*g/(rr + g))
            call paired_point(surface, side, 2, 2, merge(surface%x, surface%master_x, side == 1), [(i, i=1, np)], &
               & [(i, i=1, np)], &
               & merge(1.0_wp, -1.0_wp, side == 1)*n(1:dim, 2), off(1:dim), ratio)
            call check(error, abs(ratio - want) <= tol*want .and. &
               & all(abs(off(1:dim) - merge(1.0_wp, -1.0_wp, side == 1)*g*n(1:dim, 2)) <= tol*rr), &
               & 'dim '//itoa(dim)//', side '//itoa(side)//': ratio '//rtoa(ratio)//', expected '//rtoa(want))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_paired_point

   !> Stick data recovered as frictionless: the contact rows force body (1)'s shear traction
   !> to zero, so the recovery cannot be exact (the contact rows act).
   subroutine test_coupled_wrong_law(error)
      type(error_type), allocatable, intent(out) :: error
      type(linear_field_t) :: f1, f2
      real(wp) :: err1, err2, res
      integer :: dim
      character(len=120) :: buf

      do dim = 2, 3
         call law_fields(dim, contact_law_stick, 0.0_wp, f1, f2)
         call coupled_case(dim, 1, contact_law_frictionless, 0.0_wp, f1, f2, err1, err2, res, error)
         if (allocated(error)) return
         write (buf, '("dim ",i0,": error ",es9.2," with the wrong law")') dim, err1
         call check(error, err1 > 1.0e-3_wp, trim(buf))
         if (allocated(error)) return
      end do
   end subroutine test_coupled_wrong_law

   !> recover_contact_patch from all of body (2)'s points: a first depth of 0.1 holds one layer
   !> of body (2)'s Gauss points (heights 0.068, 0.3, 0.53 in its first cell row), rank deficient
   !> for p >= 1 along the normal; the depth doubles to 0.4 (two layers) for p = 1 and 0.8 (three)
   !> for p = 2, and the recovery is exact.
   subroutine test_contact_patch_depth(error)
      type(error_type), allocatable, intent(out) :: error
      type(linear_field_t) :: f1, f2
      real(wp) :: err1, err2, res, dused
      integer :: dim, p
      character(len=160) :: buf

      do dim = 2, 3
         do p = 1, 2
            call law_fields(dim, contact_law_stick, 0.0_wp, f1, f2)
            call coupled_case(dim, p, contact_law_stick, 0.0_wp, f1, f2, err1, err2, res, error, depth0=0.1_wp, &
               & depth_used=dused)
            if (allocated(error)) return
            write (buf, '("dim ",i0,", p = ",i0,": depth ",f5.2,", errors ",3es9.2)') dim, p, dused, err1, err2, res
            call check(error, abs(dused - merge(0.4_wp, 0.8_wp, p == 1)) < 1.0e-12_wp .and. &
               & max(err1, err2, res) <= tol_exact, trim(buf))
            if (allocated(error)) return
         end do
      end do
   end subroutine test_contact_patch_depth

   !> The contact patch test (uniform sigma_yy = -1 across a flat interface of two materials on
   !> non-matching cut grids, test/data/contact/patch_2d.nml, level 3, SPR and SPR-C): the
   !> recovered pressures p_spr, p_sprc of the contact result are 1 and ts_sprc is 0 at every
   !> closed point. Tolerance: the FE's 10 eps/rcond (test_contact_fe) plus the sqrt(eps) tier of
   !> values that pass through a patch solve.
   subroutine test_study_patch_pressures(error)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      type(study_type) :: study
      character(len=:), allocatable :: text
      real(wp) :: tol, worst
      integer :: b

      call read_text_file('test/data/contact/patch_2d.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "recovery = 'none'", "recovery = 'both'")
      call run_text(text, 3, result, error, study)
      if (allocated(error)) return
      tol = tol_exact
      do b = 1, size(result%bodies)
         tol = tol + 10.0_wp*epsilon(1.0_wp)/result%bodies(b)%problem%rcond
      end do
      associate (c => result%contacts(1))
         worst = max(maxval(abs(c%p_spr - 1.0_wp), c%state /= contact_open), &
            & maxval(abs(c%p_sprc - 1.0_wp), c%state /= contact_open), maxval(c%ts_sprc, c%state /= contact_open))
         ! all(...) rather than the max alone: a NaN (an unfilled, empty value) fails every comparison.
         call check(error, count(c%state /= contact_open) > 0 .and. all(c%state == contact_open .or. &
            & (abs(c%p_spr - 1.0_wp) <= tol .and. abs(c%p_sprc - 1.0_wp) <= tol .and. c%ts_sprc <= tol)), &
            & 'p_spr, p_sprc = 1, ts_sprc = 0: max deviation '//rtoa(worst)//', tolerance '//rtoa(tol))
      end associate
   end subroutine test_study_patch_pressures

   !> The coupled contact patches through the grid path (sprc_estimate_patches, sprc_study_level):
   !> two blocks of different materials on non-matching offset grids whose flat interface
   !> cuts cells of both, carrying the uniform stress sigma_yy = -1 (frictionless: the
   !> materials may differ; stick: equal materials, or the lateral strains would differ).
   !> Both bodies' SPR-C fields reproduce it (every patch, contact patches among them, in both
   !> bodies) and p_sprc = 1, ts_sprc = 0 at the closed points: the contact residual is zero.
   !> Q1 (patch degree 1) and Q2 (patch degree 3).
   subroutine test_grid_exact_2d(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      integer :: order
      character(len=*), parameter :: friction(2) = ['frictionless', 'stick       ']
      integer :: k

      call read_text_file('test/data/contact/patch_2d.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "recovery = 'none'", "recovery = 'both'")
      do order = 1, 2
         do k = 1, 2
            call grid_exact_case(replaced(replaced(replaced(text, "order    = 1", "order    = "//itoa(order)), &
               & "'frictionless'", "'"//trim(friction(k))//"'"), "young=3.0 poisson=0.2", &
               & merge("young=1.0 poisson=0.3", "young=3.0 poisson=0.2", k == 2)), 3, [0.0_wp, -1.0_wp, 0.0_wp], &
               & 'order '//itoa(order)//', '//trim(friction(k)), error)
            if (allocated(error)) return
         end do
      end do
   end subroutine test_grid_exact_2d

   !> test_grid_exact_2d in 3D (Q1, frictionless and stick; Q2 frictionless), level 2 (level 1
   !> for Q2).
   subroutine test_grid_exact_3d(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      real(wp), parameter :: sigma(6) = [0.0_wp, 0.0_wp, -1.0_wp, 0.0_wp, 0.0_wp, 0.0_wp]

      call read_text_file('test/data/contact/patch_3d.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "recovery = 'none'", "recovery = 'both'")
      call grid_exact_case(text, 2, sigma, 'Q1 frictionless', error)
      if (allocated(error)) return
      call grid_exact_case(replaced(replaced(text, "'frictionless'", "'stick'"), "young=3.0 poisson=0.2", &
         & "young=1.0 poisson=0.3"), 2, sigma, 'Q1 stick', error)
      if (allocated(error)) return
      call grid_exact_case(replaced(text, "order    = 1", "order    = 2"), 1, sigma, 'Q2 frictionless', error)
   end subroutine test_grid_exact_3d

   !> Action-reaction of the recovered stresses on the compound cylinder (example shrink fit,
   !> level 6): the jump of the normal traction between the two bodies at the contact points
   !> (level_type%traction_jump) is zero in the exact solution; a regression guard: SPR-C's
   !> jump below half of the FE stresses' and SPR's; the report's jump columns are these. The
   !> slave's SPR-C pressure is at most a third as far from the exact one as that of its FE
   !> stresses, -n.sigma_h.n (the acceptance of the contact pressure): it holds with the hub's
   !> coarser first layer weighed down in the contact patches (sprc_estimate_contact_patches)
   !> and fails without (a factor of 2.2 at this level, doc/benchmarks.md).
   subroutine test_traction_jump(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text
      type(level_type) :: result

      call read_text_file('example/scenes/shrink_fit.nml', text, error)
      if (allocated(error)) return
      call run_text(text, 6, result, error)
      if (allocated(error)) return
      associate (j => result%traction_jump(:, 1), r => result%row)
         call check(error, all(j >= 0.0_wp) .and. j(3) <= 0.5_wp*j(1) .and. j(3) <= 0.5_wp*j(2), &
            & 'traction jump FE, SPR, SPR-C: '//rtoa(j(1))//', '//rtoa(j(2))//', '//rtoa(j(3)))
         if (allocated(error)) return
         call check(error, all([r%jump_fe, r%jump_spr, r%jump_sprc] == j), 'report columns jump_fe, jump_spr, '// &
            & 'jump_sprc: '//rtoa(r%jump_fe)//', '//rtoa(r%jump_spr)//', '//rtoa(r%jump_sprc))
         if (allocated(error)) return
         call check(error, r%err_p_sprc <= r%err_p_fe_stress/3, 'err_p_sprc '//rtoa(r%err_p_sprc)// &
            & ' not below a third of err_p_fe_stress '//rtoa(r%err_p_fe_stress))
      end associate
   end subroutine test_traction_jump

   !> One case of test_grid_exact_2d/3d: the scene `text` at `level` carries the uniform stress
   !> `sigma` (Voigt).
   subroutine grid_exact_case(text, level, sigma, name, error)
      character(len=*), intent(in) :: text, name
      integer, intent(in) :: level
      real(wp), intent(in) :: sigma(:)
      type(error_type), allocatable, intent(out) :: error
      type(level_type) :: result
      real(wp) :: tol, worst
      integer :: b, ncontact

      call run_text(text, level, result, error)
      if (allocated(error)) then
         error%message = name//': '//error%message
         return
      end if
      tol = tol_exact
      do b = 1, size(result%bodies)
         tol = tol + 10.0_wp*epsilon(1.0_wp)/result%bodies(b)%problem%rcond
      end do
      do b = 1, size(result%bodies)
         call field_deviation(result%bodies(b)%field(2), sigma, worst, ncontact)
         call check(error, ncontact > 0 .and. worst <= tol, name//', body '//itoa(b)//': '//itoa(ncontact)// &
            & ' contact patches, SPR-C deviates by '//rtoa(worst)//' from the uniform stress, tolerance '//rtoa(tol))
         if (allocated(error)) return
      end do
      associate (c => result%contacts(1))
         worst = max(maxval(abs(c%p_sprc - 1.0_wp), c%state /= contact_open), maxval(c%ts_sprc, c%state /= contact_open))
         call check(error, count(c%state /= contact_open) > 0 .and. all(c%state == contact_open .or. &
            & (abs(c%p_sprc - 1.0_wp) <= tol .and. c%ts_sprc <= tol)), &
            & name//': p_sprc = 1, ts_sprc = 0: max deviation '//rtoa(worst)//', tolerance '//rtoa(tol))
         if (allocated(error)) return
         ! The FE stresses are the uniform stress too: so is their pressure.
         worst = maxval(abs(c%p_fe_stress - 1.0_wp), c%state /= contact_open)
         call check(error, all(c%state == contact_open .or. abs(c%p_fe_stress - 1.0_wp) <= tol), &
            & name//': p_fe_stress = 1: max deviation '//rtoa(worst)//', tolerance '//rtoa(tol))
      end associate
   end subroutine grid_exact_case

   !> Largest deviation of a recovered field's patch polynomials from the constant `sigma`
   !> (the constant term against sigma, every other coefficient against 0: the scaled
   !> coordinates are O(1) on a patch), and the number of its contact patches.
   subroutine field_deviation(field, sigma, worst, ncontact)
      type(recovered_field_type), intent(in) :: field
      real(wp), intent(in) :: sigma(:)
      real(wp), intent(out) :: worst
      integer, intent(out) :: ncontact
      integer :: ip, c

      worst = 0.0_wp
      ncontact = count(field%recs%boundary_kind == boundary_contact)
      do ip = 1, size(field%recs)
         associate (r => field%recs(ip))
            if (.not. allocated(r%coef)) cycle
            do c = 1, r%nstress
               worst = max(worst, abs(r%coef(1, c) - sigma(c)))
               if (r%nterms > 1) worst = max(worst, maxval(abs(r%coef(2:r%nterms, c))))
            end do
         end associate
      end do
   end subroutine field_deviation

   !> Body (2)'s own boundary points inside Omega_aux (recover_contact_patch's boundary2): a
   !> symmetry plane x = 0 through the prism constrains the Omega_aux fit (its boundary kind is
   !> symmetry; without boundary2 it has none) and, the uniform stress satisfying it and the
   !> frictionless law, both fits stay exact; a symmetry point outside the prism is left out.
   subroutine test_aux_boundary(error)
      type(error_type), allocatable, intent(out) :: error
      type(patch_type) :: p1, p2, b2
      type(recovery_workspace_type) :: ws1, ws2
      type(recovered_patch_type) :: rec1, rec2
      real(wp), parameter :: sigma(3) = [1.0_wp, -2.0_wp, 0.0_wp]
      real(wp) :: y2(2, 16), w2(16), s2(3, 16), sl(2, 3), worst
      integer :: i, j, n, pass

      call strip_patch(p1, sigma)
      n = 0
      do i = 0, 3
         do j = 0, 3
            n = n + 1
            y2(:, n) = [0.15_wp*i - 0.2_wp, 0.15_wp*j + 0.05_wp]
            w2(n) = 1.0_wp
            s2(:, n) = sigma
         end do
      end do
      call patch_reset(b2, 2, plane_strain, 2.0_wp, 0.25_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      do j = 1, 3
         call patch_add_boundary_point(b2, [0.0_wp, 0.1_wp*j], 0.1_wp, [-1.0_wp, 0.0_wp], boundary_symmetry)
      end do
      call patch_add_boundary_point(b2, [0.0_wp, 5.0_wp], 0.1_wp, [-1.0_wp, 0.0_wp], boundary_symmetry)
      sl = 0.0_wp
      do pass = 1, 2
         if (pass == 1) then
            call recover_contact_patch(p1, 1, [(contact_law_frictionless, i=1, 3)], 0.0_wp, sl, y2, w2, s2, 2.0_wp, &
               & 0.25_wp, 0.5_wp, ws1, ws2, p2, rec1, rec2, error, boundary2=b2)
         else
            call recover_contact_patch(p1, 1, [(contact_law_frictionless, i=1, 3)], 0.0_wp, sl, y2, w2, s2, 2.0_wp, &
               & 0.25_wp, 0.5_wp, ws1, ws2, p2, rec1, rec2, error)
         end if
         if (allocated(error)) return
         worst = max(maxval(abs(rec1%coef(1, 1:3) - sigma)), maxval(abs(rec2%coef(1, 1:3) - sigma)), &
            & maxval(abs(rec1%coef(2:, 1:3))), maxval(abs(rec2%coef(2:, 1:3))))
         call check(error, worst <= tol_exact .and. rec2%boundary_kind == merge(boundary_symmetry, boundary_none, &
            & pass == 1) .and. p2%nbpoints == merge(3, 0, pass == 1), 'pass '//itoa(pass)//': Omega_aux kind '// &
            & itoa(rec2%boundary_kind)//', '//itoa(p2%nbpoints)//' boundary points, deviation '//rtoa(worst))
         if (allocated(error)) return
      end do
   end subroutine test_aux_boundary

   !> Patch (1) of the Omega_aux tests: 4 x 4 points below y = 0 carrying sigma, three
   !> contact points on y = 0 (normal +y, into body (2)).
   subroutine strip_patch(p1, sigma)
      type(patch_type), intent(out) :: p1
      real(wp), intent(in) :: sigma(3)
      integer :: i, j

      call patch_reset(p1, 2, plane_strain, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 0.6_wp)
      do i = 0, 3
         do j = 0, 3
            call patch_add_point(p1, [0.2_wp*i - 0.3_wp, -0.2_wp*j - 0.1_wp], 1.0_wp, sigma)
         end do
      end do
      do i = 1, 3
         call patch_add_boundary_point(p1, [0.2_wp*i - 0.4_wp, 0.0_wp], 0.2_wp, [0.0_wp, 1.0_wp], boundary_contact)
      end do
   end subroutine strip_patch

   !> recover_contact_patch's `candidates`: body (2)'s points given by index (every other
   !> point, and those far outside Omega_aux) give the same bits as the same points passed as
   !> arrays of their own; an index outside body (2) is a clear error.
   subroutine test_aux_candidates(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(patch_type) :: p1, p2
      type(recovery_workspace_type) :: ws1, ws2
      type(recovered_patch_type) :: rec1, rec2, ref1, ref2
      real(wp) :: y2(2, 40), w2(40), s2(3, 40), sl(2, 3)
      integer :: i, j, n
      integer, allocatable :: pick(:)

      call strip_patch(p1, [1.0_wp, -2.0_wp, 0.3_wp])
      n = 0
      do i = 0, 4
         do j = 0, 7
            n = n + 1
            ! Columns 3 and 4 lie far to the right of the prism.
            y2(:, n) = [0.15_wp*i - 0.2_wp + merge(5.0_wp, 0.0_wp, i >= 3), 0.1_wp*j + 0.05_wp]
            w2(n) = 1.0_wp + 0.01_wp*n
            s2(:, n) = [1.0_wp + 0.2_wp*y2(1, n), -2.0_wp + 0.3_wp*y2(2, n)**2, 0.1_wp*n]
         end do
      end do
      pick = [(n, n=1, 40, 2)]
      sl = 0.0_wp
      call recover_contact_patch(p1, 1, [(contact_law_frictionless, i=1, 3)], 0.0_wp, sl, y2(:, pick), w2(pick), &
         & s2(:, pick), 2.0_wp, 0.25_wp, 0.5_wp, ws1, ws2, p2, ref1, ref2, error)
      if (allocated(error)) return
      call recover_contact_patch(p1, 1, [(contact_law_frictionless, i=1, 3)], 0.0_wp, sl, y2, w2, s2, 2.0_wp, &
         & 0.25_wp, 0.5_wp, ws1, ws2, p2, rec1, rec2, error, candidates=pick)
      if (allocated(error)) return
      call check(error, all(rec1%coef == ref1%coef) .and. all(rec2%coef == ref2%coef) .and. p2%npoints > 0, &
         & 'candidates: the fits differ from those of the same points as arrays')
      if (allocated(error)) return
      call recover_contact_patch(p1, 1, [(contact_law_frictionless, i=1, 3)], 0.0_wp, sl, y2, w2, s2, 2.0_wp, &
         & 0.25_wp, 0.5_wp, ws1, ws2, p2, rec1, rec2, err, candidates=[1, 41])
      call expect_invalid(error, err, 'candidate 41 of 40 points', 'candidates(2) = 41')
   end subroutine test_aux_candidates

   !> Bad input of the coupled solve: clear errors, no crash.
   subroutine test_coupled_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      type(patch_type) :: p1, p2, p3
      type(recovery_workspace_type) :: ws1, ws2
      type(recovered_patch_type) :: rec1, rec2
      real(wp) :: sl(2, 4)
      integer :: i, j

      call patch_reset(p1, 2, plane_strain, 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp], 1.0_wp)
      call patch_reset(p2, 2, plane_strain, 1.0_wp, 0.3_wp, [0.0_wp, 0.5_wp], 1.0_wp)
      do i = 0, 2
         do j = 0, 2
            call patch_add_point(p1, [0.4_wp*i - 0.4_wp, -0.4_wp*j - 0.1_wp], 1.0_wp, [1.0_wp, 2.0_wp, 0.0_wp])
            call patch_add_point(p2, [0.4_wp*i - 0.4_wp, 0.4_wp*j + 0.1_wp], 1.0_wp, [1.0_wp, 2.0_wp, 0.0_wp])
         end do
      end do
      p3 = p1
      call recover_sprc_contact(p1, p2, 1, [contact_law_stick], 0.0_wp, sl, ws1, ws2, rec1, rec2, err)
      call expect_invalid(error, err, 'no contact points', 'no contact points')
      do i = 1, 2
         call patch_add_boundary_point(p1, [0.3_wp*i - 0.45_wp, 0.0_wp], 0.5_wp, [0.0_wp, 1.0_wp], boundary_contact)
      end do
      sl = 0.0_wp
      sl(2, :) = 1.0_wp
      call recover_sprc_contact(p1, p2, 1, [contact_law_stick], 0.0_wp, sl, ws1, ws2, rec1, rec2, err)
      call expect_invalid(error, err, 'law too short', 'law and slip')
      call recover_sprc_contact(p1, p2, 1, [contact_law_slip, contact_law_slip], 0.3_wp, sl, ws1, ws2, rec1, rec2, err)
      call expect_invalid(error, err, 'slip along the normal', 'boundary point 1 (law slip)')
      call recover_sprc_contact(p1, p1, 1, [contact_law_stick, contact_law_stick], 0.0_wp, sl, ws1, ws2, rec1, &
         & rec2, err)
      call expect_invalid(error, err, 'Omega_aux with contact points', 'patch2')
      call recover_sprc_contact(p1, p2, 1, [contact_law_stick, 9], 0.0_wp, sl, ws1, ws2, rec1, rec2, err)
      call expect_invalid(error, err, 'unknown law', 'law = 9')
      call recover_sprc_contact(p3, p2, 1, [contact_law_stick], 0.0_wp, sl, ws1, ws2, rec1, rec2, err)
      call expect_invalid(error, err, 'patch without contact', 'no contact points')
   end subroutine test_coupled_errors

   !> Fields of the two bodies that satisfy `law` on z = 0 (body (1) below, its outward
   !> normal +z, slip along +x): shared traction coefficients, different free ones.
   pure subroutine law_fields(dim, law, mu, f1, f2)
      integer, intent(in) :: dim, law
      real(wp), intent(in) :: mu
      type(linear_field_t), intent(out) :: f1, f2

      f1%e = -2.0_wp
      f1%f = 0.3_wp
      f1%tx = 0.5_wp
      f1%a = [0.2_wp, 0.0_wp, 0.7_wp]
      f1%p0 = 1.1_wp
      f1%pz = -0.4_wp
      f1%bf = [0.3_wp, 0.0_wp, 0.5_wp]
      if (dim == 3) then
         f1%bf(2) = -0.2_wp
         f1%g = -0.25_wp
         f1%a(2) = 0.15_wp
         f1%ty = -0.3_wp
         f1%b = [0.1_wp, 0.35_wp, -0.6_wp]
         f1%q0 = 0.45_wp
         f1%q = [0.2_wp, -0.1_wp, 0.3_wp]
         f1%py = 0.25_wp
         f1%r0 = -0.8_wp
         f1%rx = 0.6_wp
         f1%rz = 0.2_wp
      end if
      select case (law)
      case (contact_law_frictionless)
         f1%tx = 0.0_wp
         f1%a(1:2) = 0.0_wp
         f1%ty = 0.0_wp
         f1%b(1:2) = 0.0_wp
      case (contact_law_slip)
         f1%tx = mu*f1%e
         f1%a(1) = mu*f1%f
         f1%a(2) = mu*f1%g
         f1%ty = 0.0_wp
         f1%b(1:2) = 0.0_wp
      end select
      ! Body (2): the same traction on z = 0, different free coefficients.
      f2 = f1
      f2%a(3) = -0.9_wp
      f2%p0 = -0.5_wp
      f2%pz = 0.8_wp
      f2%bf = [-0.4_wp, 0.0_wp, 0.25_wp]
      if (dim == 3) then
         f2%bf(2) = 0.1_wp
         f2%b(3) = 0.4_wp
         f2%q0 = -0.2_wp
         f2%q = [-0.3_wp, 0.25_wp, 0.1_wp]
         f2%py = -0.15_wp
         f2%r0 = 0.9_wp
         f2%rx = -0.4_wp
         f2%rz = 0.5_wp
      end if
   end subroutine law_fields

   !> Voigt stress of a field at x (dim coordinates; the last is normal to the contact plane).
   pure function field_stress(dim, fl, x) result(sig)
      integer, intent(in) :: dim
      type(linear_field_t), intent(in) :: fl
      real(wp), intent(in) :: x(:)
      real(wp) :: sig(6), y(3), sxx, syy, szz, sxy, syz, sxz, h, px, ry

      y = 0.0_wp
      if (dim == 2) then
         y(1) = x(1)
         y(3) = x(2)
      else
         y = x(1:3)
      end if
      h = -fl%a(1) - fl%b(2) - fl%bf(3)
      px = -fl%a(3) - fl%q(2) - fl%bf(1)
      ry = -fl%b(3) - fl%q(1) - fl%bf(2)
      sxz = fl%tx + dot_product(fl%a, y)
      syz = fl%ty + dot_product(fl%b, y)
      szz = fl%e + fl%f*y(1) + fl%g*y(2) + h*y(3)
      sxy = fl%q0 + dot_product(fl%q, y)
      sxx = fl%p0 + px*y(1) + fl%py*y(2) + fl%pz*y(3)
      syy = fl%r0 + fl%rx*y(1) + ry*y(2) + fl%rz*y(3)
      sig = 0.0_wp
      if (dim == 2) then
         sig(1:3) = [sxx, szz, sxz]
      else
         sig = [sxx, syy, szz, sxy, syz, sxz]
      end if
   end function field_stress

   !> One coupled recovery on hand-made sampling data (see coupled_laws); errors relative to the
   !> largest stress: err1 over body (1)'s points, err2 over Omega_aux's, res the contact residual.
   !> With depth0, Omega_aux and its points come from recover_contact_patch (all of body (2)'s
   !> points passed, depth0 its first depth; depth_used returned).
   subroutine coupled_case(dim, degree, law, mu, f1, f2, err1, err2, res, error, depth0, depth_used, mirror, shift, &
      & scale, ignore, weight2)
      integer, intent(in) :: dim, degree, law
      real(wp), intent(in) :: mu
      type(linear_field_t), intent(in) :: f1, f2
      real(wp), intent(out) :: err1, err2, res
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: depth0
      real(wp), intent(out), optional :: depth_used
      !> Mirrored: the patch is body (2)'s (above z = 0, contact normal -z, slip -x) and Omega_aux
      !> lies in body (1) (the master-side treatment); errors are then body (2)'s, body (1)'s.
      logical, intent(in), optional :: mirror
      !> Body (2)'s field moved by shift along the contact normal and divided by scale (the
      !> surfaces kept apart, test_coupled_offset); the offset and ratio passed to the solve
      !> unless `ignore`.
      real(wp), intent(in), optional :: shift, scale
      logical, intent(in), optional :: ignore
      !> recover_sprc_contact's weight2 (test_coupled_weight).
      real(wp), intent(in), optional :: weight2
      type(linear_field_t) :: fa, fb
      real(wp) :: g, rs, offs(3, 200), rat(200)
      logical :: pass
      real(wp) :: sgn
      real(wp), parameter :: gx(3) = [-sqrt(0.6_wp), 0.0_wp, sqrt(0.6_wp)], gw(3) = [5, 8, 5]/9.0_wp
      real(wp), parameter :: h2cell = 0.6_wp, off2 = -1.33_wp, depth = 1.5_wp
      type(patch_type) :: p1, p2
      type(recovery_workspace_type) :: ws1, ws2
      type(recovered_patch_type) :: rec1, rec2
      type(aux_domain_type) :: aux
      type(poly_basis_type) :: basis
      real(wp) :: x(3), wgt, cx(3, 200), cn(3, 200), cw(200), smax, nrm(3), sl(3, 200), frame(3, 3)
      real(wp) :: hh(3, 6), hp(3, 6), s1(6), s2(6)
      integer :: laws(200), nc, ns, ncell1, ncell2, c, i, j, k, nq, ijk(3), top, rank, want_rank, n2
      real(wp) :: y2(3, 3000), w2(3000), st2(6, 3000)

      ns = merge(3, 6, dim == 2)
      fa = f1
      fb = f2
      sgn = 1.0_wp
      if (present(mirror)) then
         if (mirror) then
            fa = f2
            fb = f1
            sgn = -1.0_wp
         end if
      end if
      g = 0.0_wp
      rs = 1.0_wp
      if (present(shift)) g = shift
      if (present(scale)) rs = scale
      pass = present(shift) .or. present(scale)
      if (present(ignore)) pass = pass .and. .not. ignore
      nq = 3**dim
      call new_poly_basis(basis, dim, degree, error)
      if (allocated(error)) return
      ! Body (1): cells of size 1 below z = 0 around the node at the origin.
      call patch_reset(p1, dim, merge(plane_strain, solid, dim == 2), 1.0_wp, 0.3_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
         & 1.5_wp)
      p1%body_force(1:dim) = body_force(fa)
      ncell1 = 2**(dim - 1)
      nc = 0
      nrm = 0.0_wp
      nrm(dim) = sgn
      smax = 0.0_wp
      do c = 0, ncell1 - 1
         do k = 0, nq - 1
            ijk = [mod(k, 3), mod(k/3, 3), k/9]
            x = 0.0_wp
            wgt = 1.0_wp
            do i = 1, dim - 1
               x(i) = merge(-1.0_wp, 0.0_wp, .not. btest(c, i - 1)) + 0.5_wp*(1.0_wp + gx(ijk(i) + 1))
               wgt = wgt*0.5_wp*gw(ijk(i) + 1)
            end do
            x(dim) = -sgn*0.5_wp*(1.0_wp - gx(ijk(dim) + 1))
            wgt = wgt*0.5_wp*gw(ijk(dim) + 1)
            s1 = field_stress(dim, fa, x(1:dim))
            call patch_add_point(p1, x(1:dim), wgt, s1(1:ns))
            smax = max(smax, maxval(abs(s1)))
            ! The Gauss points of the top face (z = 0) are the contact points.
            if (ijk(dim) == 0) then
               x(dim) = 0.0_wp
               nc = nc + 1
               cx(:, nc) = x
               cn(:, nc) = nrm
               cw(nc) = wgt/(0.5_wp*gw(1))
               call patch_add_boundary_point(p1, x(1:dim), cw(nc), nrm(1:dim), boundary_contact)
            end if
         end do
      end do
      laws = law
      sl = 0.0_wp
      sl(1, :) = sgn
      ! Body (2): a non-matching grid (cells 0.6, offset) above z = 0; its Gauss points in Omega_aux.
      call new_aux_domain(aux, dim, cx(1:dim, 1:nc), cn(1:dim, 1:nc), cw(1:nc), depth, 0.0_wp, error)
      if (allocated(error)) return
      call patch_reset(p2, dim, merge(plane_strain, solid, dim == 2), 1.0_wp, 0.3_wp, aux%centre(1:dim), depth)
      p2%body_force(1:dim) = body_force(fb)/rs
      do i = 1, nc
         offs(:, i) = g*nrm
         rat(i) = rs
      end do
      ncell2 = 5
      n2 = 0
      top = merge(ncell2, 1, dim == 3)
      do c = 0, ncell2**(dim - 1)*4 - 1
         do k = 0, nq - 1
            ijk = [mod(k, 3), mod(k/3, 3), k/9]
            x = 0.0_wp
            x(1) = off2 + h2cell*(mod(c, ncell2) + 0.5_wp*(1.0_wp + gx(ijk(1) + 1)))
            if (dim == 3) x(2) = off2 + h2cell*(mod(c/ncell2, top) + 0.5_wp*(1.0_wp + gx(ijk(2) + 1)))
            j = c/(ncell2*top)
            x(dim) = sgn*h2cell*(j + 0.5_wp*(1.0_wp + gx(ijk(dim) + 1)))
            wgt = (0.5_wp*h2cell)**dim*product(gw(ijk(1:dim) + 1))
            s2 = field_stress(dim, fb, x(1:dim) - g*nrm(1:dim))/rs
            n2 = n2 + 1
            y2(:, n2) = x
            w2(n2) = wgt
            st2(:, n2) = s2
            if (.not. aux_contains(aux, x(1:dim))) cycle
            call patch_add_point(p2, x(1:dim), wgt, s2(1:ns))
            smax = max(smax, maxval(abs(s2)))
         end do
      end do
      if (present(depth0)) then
         call recover_contact_patch(p1, degree, laws(1:p1%nbpoints), mu, sl(1:dim, 1:p1%nbpoints), y2(1:dim, 1:n2), &
            & w2(1:n2), st2(1:ns, 1:n2), 1.0_wp, 0.3_wp, depth0, ws1, ws2, p2, rec1, rec2, error, &
            & body_force2=body_force(fb), depth_used=depth_used)
         if (allocated(error)) return
         rank = -1
      else if (present(weight2)) then
         call recover_sprc_contact(p1, p2, degree, laws, mu, sl, ws1, ws2, rec1, rec2, error, contact_rank=rank, &
            & weight2=weight2)
      else if (pass) then
         call recover_sprc_contact(p1, p2, degree, laws, mu, sl, ws1, ws2, rec1, rec2, error, contact_rank=rank, &
            & offset=offs(1:dim, 1:nc), ratio=rat(1:nc))
      else
         call recover_sprc_contact(p1, p2, degree, laws, mu, sl, ws1, ws2, rec1, rec2, error, contact_rank=rank)
      end if
      if (allocated(error)) return
      ! A flat contact surface: the residual's dim components are degree-p polynomials along it.
      want_rank = merge(2*(degree + 1), 3*((degree + 1)*(degree + 2))/2, dim == 2)
      if (rank /= want_rank .and. rank /= -1) then
         call test_failed(error, 'contact rank '//itoa(rank)//', expected the flat-surface rank '//itoa(want_rank))
         return
      end if
      err1 = 0.0_wp
      do i = 1, p1%npoints
         err1 = max(err1, maxval(abs(eval(rec1, p1%x(1:dim, i)) - p1%stress(1:ns, i))))
      end do
      err2 = 0.0_wp
      do i = 1, p2%npoints
         err2 = max(err2, maxval(abs(eval(rec2, p2%x(1:dim, i)) - p2%stress(1:ns, i))))
      end do
      res = 0.0_wp
      do i = 1, nc
         call contact_frame(dim, cn(1:dim, i), frame, error, slip=sl(1:dim, i))
         if (allocated(error)) return
         call contact_operator(dim, frame, hh)
         call contact_law_operator(dim, law, mu, hh, hp, error)
         if (allocated(error)) return
         s1(1:ns) = eval(rec1, cx(1:dim, i))
         s2(1:ns) = eval(rec2, cx(1:dim, i) + g*nrm(1:dim))
         res = max(res, maxval(abs(matmul(hh(1:dim, 1:ns), s1(1:ns)) - rs*matmul(hp(1:dim, 1:ns), s2(1:ns)))))
      end do
      err1 = err1/smax
      err2 = err2/smax
      res = res/smax
   contains
      pure function body_force(fl) result(b)
         type(linear_field_t), intent(in) :: fl
         real(wp) :: b(dim)
         if (dim == 2) then
            b = [fl%bf(1), fl%bf(3)]
         else
            b = fl%bf
         end if
      end function body_force

      function eval(rec, xp) result(sig)
         type(recovered_patch_type), intent(in) :: rec
         real(wp), intent(in) :: xp(:)
         real(wp) :: sig(ns), pv(20)
         integer :: cc
         call basis%eval((xp - rec%x0(1:dim))/rec%h, pv)
         do cc = 1, ns
            sig(cc) = dot_product(pv(1:basis%nterms), rec%coef(1:basis%nterms, cc))
         end do
      end function eval
   end subroutine coupled_case

   !> Fail `error` unless `err` holds stat_invalid_input with `word` in its message; clears err.
   subroutine expect_invalid(error, err, what, word)
      type(error_type), allocatable, intent(inout) :: error, err
      character(len=*), intent(in) :: what, word
      if (allocated(error)) return
      if (.not. allocated(err)) then
         call test_failed(error, what//': accepted')
      else if (err%stat /= stat_invalid_input .or. index(err%message, word) == 0) then
         call test_failed(error, what//': wrong status or message: '//err%message)
      end if
      if (allocated(err)) deallocate (err)
   end subroutine expect_invalid

   !> qr_pivoted with max_steps = 3 on a full-rank 40 x 12 matrix (the contact rows' shape,
   !> smaller): the first 3 rows of R (from the diagonal on, in the original column order:
   !> later pivots swap whole columns), the first 3 pivots, reflectors and tau are those of
   !> the full factorisation bit for bit (step k depends on the steps before it alone), and
   !> tau = 0 after them. Exact equality is the claim, not a tolerance.
   subroutine test_qr_max_steps(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: m = 40, n = 12, k = 3
      real(wp) :: a(m, n), full(m, n), part(m, n), tauf(n), taup(n), vn(n, 2), rp(n), rf(n)
      integer :: jf(n), jp(n), i, j

      do j = 1, n
         do i = 1, m
            a(i, j) = sin(0.37_wp*i*j + 0.11_wp*i + 0.5_wp*j)
         end do
      end do
      full = a
      call qr_pivoted(m, n, full, jf, tauf, vn, 1.0e-12_wp)
      part = a
      call qr_pivoted(m, n, part, jp, taup, vn, 1.0e-12_wp, max_steps=k)
      call check(error, all(jp(1:k) == jf(1:k)) .and. all(taup(1:k) == tauf(1:k)) .and. all(taup(k + 1:) == 0.0_wp), &
         & 'the first pivots and tau equal, tau = 0 after max_steps')
      if (allocated(error)) return
      do i = 1, k
         ! Later pivots swap whole columns: row i compares in the original column order.
         rp(jp(i:n)) = part(i, i:n)
         rf(jf(i:n)) = full(i, i:n)
         call check(error, all(rp(jp(i:n)) == rf(jp(i:n))) .and. all(part(i + 1:m, i) == full(i + 1:m, i)), &
            & 'row '//itoa(i)//' of R and reflector '//itoa(i)//' equal to the full factorisation''s')
         if (allocated(error)) return
      end do
   end subroutine test_qr_max_steps

   !> cells_prism (cell culling against Omega_aux) returns exactly the points of cells_box over
   !> the prism's bounding box that aux_contains keeps, in the same order: 2D and 3D, scattered
   !> points, prisms whose mean normal is oblique to the axes, with points placed on the prism's
   !> faces too (the cells those cut are tested per point).
   subroutine test_cells_prism(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: d, t

      do d = 2, 3
         do t = 1, 4
            call one_case(d, t, error)
            if (allocated(error)) return
         end do
      end do
   contains
      subroutine one_case(d, t, error)
         integer, intent(in) :: d, t
         type(error_type), allocatable, intent(out) :: error
         integer, parameter :: npt = 4000, nc = 6
         type(point_cells_type) :: cells
         type(aux_domain_type) :: aux
         real(wp) :: y(d, npt), x(d, nc), n(d, nc), w(nc), c(3), nn(3), blo(3), bhi(3), r
         integer, allocatable :: box(:), got(:)
         integer :: i, k, nbox, ngot, m

         do i = 1, npt
            y(:, i) = [(modulo(0.6180339887_wp*i*(k + 1) + 0.1_wp*k*t, 1.0_wp), k=1, d)]
         end do
         nn = 0.0_wp
         nn(1:d) = [(cos(0.7_wp*t + 1.3_wp*k), k=1, d)]
         nn = nn/norm2(nn)
         c = 0.5_wp
         do i = 1, nc
            r = 0.1_wp*(i - 3.5_wp)
            x(:, i) = c(1:d) + r*[(merge(nn(2), -nn(1), k == 1)*merge(1.0_wp, 0.0_wp, k <= 2), k=1, d)] &
               & + 0.02_wp*i*[(merge(1.0_wp, 0.0_wp, k == d), k=1, d)]
            n(:, i) = nn(1:d)
            w(i) = 1.0_wp + 0.1_wp*i
         end do
         call new_aux_domain(aux, d, x, n, w, 0.15_wp*t, 0.05_wp*t, error)
         if (allocated(error)) return
         ! Points on the prism's faces: on the plane at its far end.
         do i = 1, 200
            y(:, i) = aux%centre(1:d) + aux%hi*aux%frame(1:d, 1) + &
               & (aux%tmin(1) + (aux%tmax(1) - aux%tmin(1))*(i - 1)/199.0_wp)*aux%frame(1:d, 2)
         end do
         call new_point_cells(cells, y, error)
         if (allocated(error)) return
         call aux_bounds(aux, blo, bhi)
         call cells_box(cells, y, blo, bhi, box, nbox)
         m = 0
         do i = 1, nbox
            if (.not. aux_contains(aux, y(:, box(i)))) cycle
            m = m + 1
            box(m) = box(i)
         end do
         call cells_prism(cells, y, aux, got, ngot)
         call check(error, ngot == m .and. m > 0, 'dim '//itoa(d)//' case '//itoa(t)//': '//itoa(ngot)// &
            & ' points, expected '//itoa(m))
         if (allocated(error)) return
         call check(error, all(got(1:ngot) == box(1:m)), 'dim '//itoa(d)//' case '//itoa(t)//': the same points in order')
      end subroutine one_case
   end subroutine test_cells_prism

   !> Cattaneo-Mindlin (test/data/contact/cattaneo_2d.nml, level 3, a/h = 12.8; the closed
   !> form q_ex of exact/hertz's cattaneo_mindlin_traction, as test_contact_fe's): SPR-C's
   !> tangential traction ts_sprc is closer to q_ex than the FE's |t_fe| in the slave
   !> surface's L2 norm (issue 12's acceptance; no tolerance: the comparison is the claim).
   !> With the slip direction of the Coulomb patches taken from the slave's FE stress, whose
   !> tangential traction in the cut cells at the leading edge of the contact zone has the
   !> wrong sign, SPR-C's tangential traction reversed there: 0.255 ||q_ex|| against the FE's 0.230.
   subroutine test_cattaneo_sprc(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: pi = acos(-1.0_wp), load = 1.0788436_wp, q_load = 2*0.0809163_wp, mu = 0.3_wp
      real(wp), parameter :: e_star = 1000.0_wp/(2*(1 - 0.3_wp**2))
      type(level_type) :: result
      character(len=:), allocatable :: text
      real(wp) :: a, p0, c, err_fe, err_sprc
      real(wp), allocatable :: q_ex(:)
      logical, allocatable :: filled(:)

      call read_text_file('test/data/contact/cattaneo_2d.nml', text, error)
      if (allocated(error)) return
      text = replaced(text, "recovery = 'none'", "recovery = 'sprc'")
      call run_text(text, 3, result, error)
      if (allocated(error)) return
      a = sqrt(4*load/(pi*e_star))
      p0 = 2*load/(pi*a)
      c = a*sqrt(1 - q_load/(mu*load))
      associate (r => result%contacts(1), x => result%contacts(1)%x(1, :), w => result%contacts(1)%weight)
         q_ex = cattaneo_mindlin_traction(x, a, c, mu, p0)
         ! Points without a slave cell carry no value (NaN, never equal to itself): none may be closed.
         filled = r%ts_sprc == r%ts_sprc .and. norm2(r%t_fe, dim=1) == norm2(r%t_fe, dim=1)
         call check(error, all(filled .or. r%state == contact_open), 'a closed point without a traction')
         if (allocated(error)) return
         err_fe = sqrt(sum(w*(norm2(r%t_fe, dim=1) - q_ex)**2, filled)/sum(w*q_ex**2, filled))
         err_sprc = sqrt(sum(w*(r%ts_sprc - q_ex)**2, filled)/sum(w*q_ex**2, filled))
         call check(error, err_sprc < err_fe, 'relative L2 error of the tangential traction: SPR-C '// &
            & rtoa(err_sprc)//', FE '//rtoa(err_fe))
      end associate
   end subroutine test_cattaneo_sprc

   !> The gap fit of a contact edge (sprc_recovery_contact_edge_fit, fit_edge_gap) on a line at
   !> 30 degrees, points every 0.37 facet lengths: gaps of the model g = C xi_+^(3/2) (1 + c xi)
   !> with the edge at s = 0.37 and s = -1.21 facet lengths from the vertex are found to the
   !> golden sections' bracket (the scan's step 4/16 shrunk by 0.618^30, 3e-7 facet lengths;
   !> 1e-6 stated), and the coefficient of xi^(3/2) at the edge, 3e-4 (1 + 0.2 s)/L^(3/2) per
   !> length^(3/2), to the same relative tier. A gap that closes (C < 0) is not kept. Last the
   !> amplitude of the gap that Hertz's pressure opens (Johnson 1985 eq. 4.45: p0 sqrt(2/a)
   !> from C = (2 sqrt 2/3) sqrt(a)/R; two materials, plane strain; a plane stress E* likewise)
   !> to round-off (8 eps).
   subroutine test_edge_gap_fit(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_edge_type) :: edge
      real(wp), parameter :: length = 0.02_wp, se(2) = [0.37_wp, -1.21_wp]
      real(wp) :: x(2, 40), gap(40), xi(40), s, c, c_ex, e_star, a, p0
      real(wp), parameter :: young(2) = [210.0_wp, 70.0_wp], nu(2) = [0.3_wp, 0.33_wp], r = 0.8_wp, load = 0.9_wp
      logical :: ok
      integer :: i, k

      edge%vertex = [0.3_wp, 0.1_wp]
      edge%tangent = [cos(acos(-1.0_wp)/6), sin(acos(-1.0_wp)/6)]
      edge%length = length
      do k = 1, 2
         do i = 1, size(gap)
            xi(i) = 0.37_wp*(i - 3)
            x(:, i) = edge%vertex + xi(i)*length*edge%tangent
         end do
         gap = 3.0e-4_wp*max(xi - se(k), 0.0_wp)**1.5_wp*(1.0_wp + 0.2_wp*xi)
         call fit_edge_gap(edge, x, gap, [-2.0_wp, 2.0_wp], s, c, ok)
         call check(error, ok .and. abs(s - se(k)) < 1.0e-6_wp, 'edge at '//rtoa(se(k))//': fitted at '//rtoa(s))
         if (allocated(error)) return
         c_ex = 3.0e-4_wp*(1.0_wp + 0.2_wp*se(k))/length**1.5_wp
         call check(error, abs(c - c_ex) < 1.0e-6_wp*c_ex, 'edge at '//rtoa(se(k))//': coefficient '//rtoa(c)// &
            & ', expected '//rtoa(c_ex))
         if (allocated(error)) return
      end do
      call fit_edge_gap(edge, x, -gap, [-2.0_wp, 2.0_wp], s, c, ok)
      call check(error, .not. ok, 'a closing gap kept as an edge at '//rtoa(s))
      if (allocated(error)) return
      do k = 1, 2
         if (k == 1) e_star = 1.0_wp/sum((1.0_wp - nu**2)/young)
         if (k == 2) e_star = 1.0_wp/sum(1.0_wp/young)
         a = sqrt(4.0_wp*load*r/(acos(-1.0_wp)*e_star))
         p0 = 2.0_wp*load/(acos(-1.0_wp)*a)
         c = 2.0_wp*sqrt(2.0_wp)/3.0_wp*sqrt(a)/r
         s = gap_amplitude(c, young, nu, k == 2)
         call check(error, abs(s - p0*sqrt(2.0_wp/a)) <= 8*epsilon(1.0_wp)*s, 'Hertz amplitude '//rtoa(s)// &
            & ', expected '//rtoa(p0*sqrt(2.0_wp/a)))
         if (allocated(error)) return
      end do
   end subroutine test_edge_gap_fit

end module sprc_test_contact_recovery
