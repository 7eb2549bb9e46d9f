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
      & contact_rows, contact_law_frictionless, contact_law_slip, contact_law_stick
   use sprc_recovery_contact_aux, only: aux_domain_type, new_aux_domain, aux_contains, aux_select
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   implicit none
   private

   public :: collect_contact_recovery

   !> Round-off bound of a residual H sigma1 - H' sigma2 of stresses with entries up to
   !> `smax`, relative: sigma = R T R^T is 2 sums of 3 products per entry, H sigma a sum of
   !> at most 6 products of 3 rounded factors, each step within a few eps; 64 eps covers the
   !> sum of these bounds with room (a wrong row or sign gives an O(1) residual).
   real(wp), parameter :: tol_roundoff = 64*epsilon(1.0_wp)

contains

   subroutine collect_contact_recovery(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('operator_2d_errata', test_operator_2d), &
         new_unittest('operator_3d_errata', test_operator_3d), &
         new_unittest('laws_2d', test_laws_2d), &
         new_unittest('laws_3d', test_laws_3d), &
         new_unittest('rows', test_rows), &
         new_unittest('operator_errors', test_operator_errors), &
         new_unittest('aux_flat_3d', test_aux_flat_3d), &
         new_unittest('aux_curved_2d', test_aux_curved_2d), &
         new_unittest('aux_errors', test_aux_errors) &
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

   subroutine test_operator_errors(error)
      use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: err
      real(wp) :: frame(3, 3), h(3, 6), hp(3, 6)

      call contact_frame(2, [0.6_wp, 0.7_wp], frame, err)
      call expect_invalid('non-unit normal')
      call contact_frame(3, [0.0_wp, 0.0_wp, 1.0_wp], frame, err, slip=[0.0_wp, 0.0_wp, -2.0_wp])
      call expect_invalid('slip along the normal')
      call contact_frame(3, [0.0_wp, 0.0_wp, 1.0_wp], frame, err, slip=[ieee_value(1.0_wp, ieee_quiet_nan), 1.0_wp, 0.0_wp])
      call expect_invalid('slip not finite')
      call contact_frame(3, [0.0_wp, 0.0_wp, 1.0_wp], frame, err)
      if (allocated(err)) then
         call test_failed(error, 'valid frame refused: '//err%message)
         return
      end if
      call contact_operator(3, frame, h)
      call contact_law_operator(3, contact_law_slip, -0.1_wp, h, hp, err)
      call expect_invalid('mu < 0')
      call contact_law_operator(3, 7, 0.1_wp, h, hp, err)
      call expect_invalid('unknown law')
   contains
      subroutine expect_invalid(what)
         character(len=*), intent(in) :: what
         if (allocated(error)) return
         if (.not. allocated(err)) then
            call test_failed(error, what//': accepted')
         else if (err%stat /= stat_invalid_input) then
            call test_failed(error, what//': wrong status')
         end if
         if (allocated(err)) deallocate (err)
      end subroutine expect_invalid
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
      call expect_invalid('depth = 0', 'depth')
      call new_aux_domain(aux, 2, x, n, w, 1.0_wp, -1.0_wp, err)
      call expect_invalid('margin < 0', 'margin')
      call new_aux_domain(aux, 2, x, n, [1.0_wp, -1.0_wp], 1.0_wp, 0.0_wp, err)
      call expect_invalid('negative weight', 'w(2)')
      call new_aux_domain(aux, 2, x, n, [0.0_wp, 0.0_wp], 1.0_wp, 0.0_wp, err)
      call expect_invalid('zero weights', 'sum to 0')
      call new_aux_domain(aux, 2, x, reshape([0.0_wp, 1.0_wp, 0.0_wp, -1.0_wp], [2, 2]), w, 1.0_wp, 0.0_wp, err)
      call expect_invalid('opposite normals', 'cancel')
      call new_aux_domain(aux, 2, x, 2*n, w, 1.0_wp, 0.0_wp, err)
      call expect_invalid('non-unit normal', 'n(:, 1)')
      call new_aux_domain(aux, 2, x(:, 1:0), n(:, 1:0), w(1:0), 1.0_wp, 0.0_wp, err)
      call expect_invalid('no points', 'no contact points')
   contains
      subroutine expect_invalid(what, word)
         character(len=*), intent(in) :: what, word
         if (allocated(error)) return
         if (.not. allocated(err)) then
            call test_failed(error, what//': accepted')
         else if (err%stat /= stat_invalid_input .or. index(err%message, word) == 0) then
            call test_failed(error, what//': wrong status or message: '//err%message)
         end if
         if (allocated(err)) deallocate (err)
      end subroutine expect_invalid
   end subroutine test_aux_errors

end module sprc_test_contact_recovery
