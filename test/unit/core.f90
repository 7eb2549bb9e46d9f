!> Tests of the core layer: error type, timers, LAPACK interfaces and the
!> translation of LAPACK status.
module sprc_test_core
   use sprc_core_kinds, only: wp, dp, i4, i8
   use sprc_core_error, only: error_type, fatal_error, stat_name, stat_invalid_input, &
      & stat_singular, stat_not_positive_definite
   use sprc_core_timer, only: timer_type, wall_time
   use sprc_core_text, only: fixed_text, itoa, rtoa, lower, xml_escape
   use sprc_core_boundary, only: bc_none, bc_traction, bc_symmetry, bc_free, bc_pressure, bc_contact, bc_kind_name, &
      & bc_kind_from_name
   use sprc_core_lapack, only: dgesv, dgecon, dgetrf, dlange, dpotrf, dpotrs, dgeqp3, dgesvd, &
      & dgemm, dsyrk, dsysv, lapack_info_error
   use sprc_core_lagrange, only: lagrange_1d, tensor_shape, element_node_index, vtk_line2, vtk_line3, &
      & vtk_quad4, vtk_quad9, vtk_hex8, vtk_hex27
   use sprc_core_hash, only: key_table_type, hash_int
   use sprc_core_sort, only: sort_order, sort, sort_pairs
   use sprc_testsuite, only: unittest_type, new_unittest, check
   implicit none
   private

   public :: collect_core

contains

   subroutine collect_core(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('kinds', test_kinds), &
         new_unittest('error_default_stat', test_error_default_stat), &
         new_unittest('error_names', test_error_names), &
         new_unittest('timer_accumulates', test_timer), &
         new_unittest('dgesv_hilbert4', test_dgesv), &
         new_unittest('dgecon_diagonal', test_dgecon), &
         new_unittest('dpotrf_spd_and_not', test_dpotrf), &
         new_unittest('dgeqp3_rank', test_dgeqp3_rank), &
         new_unittest('dgesvd_known', test_dgesvd), &
         new_unittest('fixed_text_leading_zero', test_fixed_text), &
         new_unittest('dgemm_dsyrk', test_dgemm_dsyrk), &
         new_unittest('dsysv_indefinite', test_dsysv), &
         new_unittest('lapack_info_translation', test_info_translation), &
         new_unittest('strings', test_strings), &
         new_unittest('lower_and_xml_escape', test_lower_escape), &
         new_unittest('lagrange_vtk_tables', test_lagrange_tables), &
         new_unittest('lagrange_kronecker_unity', test_lagrange_kronecker), &
         new_unittest('lagrange_derivative_fd', test_lagrange_derivative), &
         new_unittest('key_table_structured_keys', test_key_table), &
         new_unittest('sort_stable_against_counting', test_sort), &
         new_unittest('boundary_kinds', test_boundary_kinds) &
         ]
   end subroutine collect_core

   subroutine test_kinds(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, precision(1.0_wp) >= 15 .and. range(1.0_dp) >= 307, 'wp is at least double')
      if (allocated(error)) return
      call check(error, range(1_i4) >= 9 .and. range(1_i8) >= 18, 'integer kinds')
   end subroutine test_kinds

   subroutine test_error_default_stat(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      call fatal_error(e, 'bad thing')
      call check(error, e%stat, stat_invalid_input, 'default status')
      if (allocated(error)) return
      call check(error, e%message, 'bad thing')
      if (allocated(error)) return
      call fatal_error(e, 'x', stat_singular)
      call check(error, e%stat, stat_singular, 'explicit status')
   end subroutine test_error_default_stat

   subroutine test_error_names(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: s
      do s = 0, 8
         call check(error, stat_name(s) /= 'unknown status', 'every status has a name')
         if (allocated(error)) return
      end do
      call check(error, stat_name(99), 'unknown status')
   end subroutine test_error_names

   subroutine test_timer(error)
      type(error_type), allocatable, intent(out) :: error
      type(timer_type) :: t
      real(wp) :: t0, x
      integer :: i
      call check(error, .not. t%running(), 'new timer is stopped')
      if (allocated(error)) return
      t0 = wall_time()
      call t%start()
      x = 0.0_wp
      do i = 1, 100000
         x = x + sqrt(real(i, wp))
      end do
      call t%stop()
      call t%stop() ! stopping twice must not add time
      call check(error, t%elapsed >= 0.0_wp .and. t%elapsed <= wall_time() - t0 + 1.0e-9_wp .and. x > 0.0_wp, &
         'elapsed within the outer interval')
      if (allocated(error)) return
      call t%reset()
      call check(error, t%elapsed, 0.0_wp, 0.0_wp, 'reset')
   end subroutine test_timer

   !> Hilbert 4x4 with right-hand side H*1: the solution is ones, up to c cond_1(H) eps with
   !> cond_1(H) = ||H||_1 ||H^-1||_1 = (25/12) 13620 = 28375 exactly and c = 10 for the
   !> backward error of LU with partial pivoting (n = 4) and the rounding of H and H*1.
   subroutine test_dgesv(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(4, 4), b(4, 1)
      integer :: ipiv(4), info, i, j
      do j = 1, 4
         do i = 1, 4
            a(i, j) = 1.0_dp/real(i + j - 1, dp)
         end do
      end do
      b(:, 1) = sum(a, dim=2)
      call dgesv(4, 1, a, 4, ipiv, b, 4, info)
      call check(error, info, 0, 'dgesv info')
      if (allocated(error)) return
      call check(error, maxval(abs(b(:, 1) - 1.0_dp)), 0.0_dp, 10.0_dp*28375.0_dp*epsilon(1.0_dp), 'Hilbert solve')
   end subroutine test_dgesv

   !> diag(1, 1e-3): 1-norm condition number is exactly 1e3; dgecon estimates rcond.
   subroutine test_dgecon(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), work(8), anorm, rcond
      integer :: ipiv(2), iwork(2), info
      a = reshape([1.0_dp, 0.0_dp, 0.0_dp, 1.0e-3_dp], [2, 2])
      anorm = dlange('1', 2, 2, a, 2, work)
      call dgetrf(2, 2, a, 2, ipiv, info)
      call dgecon('1', 2, a, 2, anorm, rcond, work, iwork, info)
      call check(error, rcond, 1.0e-3_dp, 1.0e-14_dp, 'rcond of diag(1,1e-3)', rel=.true.)
   end subroutine test_dgecon

   subroutine test_dpotrf(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(3, 3), b(3, 1)
      integer :: info
      type(error_type), allocatable :: e
      ! 1D Laplace stencil: SPD; A*[1,2,3] = [0,0,4]
      a = reshape([2.0_dp, -1.0_dp, 0.0_dp, -1.0_dp, 2.0_dp, -1.0_dp, 0.0_dp, -1.0_dp, 2.0_dp], [3, 3])
      b(:, 1) = [0.0_dp, 0.0_dp, 4.0_dp]
      call dpotrf('L', 3, a, 3, info)
      call dpotrs('L', 3, 1, a, 3, b, 3, info)
      call check(error, maxval(abs(b(:, 1) - [1.0_dp, 2.0_dp, 3.0_dp])), 0.0_dp, 1.0e-14_dp, 'Cholesky solve')
      if (allocated(error)) return
      a = reshape([1.0_dp, 2.0_dp, 0.0_dp, 2.0_dp, 1.0_dp, 0.0_dp, 0.0_dp, 0.0_dp, 1.0_dp], [3, 3])
      call dpotrf('L', 3, a, 3, info)
      call check(error, info, 2, 'indefinite matrix fails at minor 2')
      if (allocated(error)) return
      call lapack_info_error('dpotrf', info, 'test', e)
      call check(error, e%stat, stat_not_positive_definite, 'translated status')
   end subroutine test_dpotrf

   !> Columns c1, c2, c1+c2 and 2*c1: rank 2, found by pivoted QR with a relative tolerance.
   subroutine test_dgeqp3_rank(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(5, 4), tau(4), work(200)
      integer :: jpvt(4), info, rank, k
      a(:, 1) = [1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp, 5.0_dp]
      a(:, 2) = [1.0_dp, -1.0_dp, 0.5_dp, 0.0_dp, 2.0_dp]
      a(:, 3) = a(:, 1) + a(:, 2)
      a(:, 4) = 2.0_dp*a(:, 1)
      jpvt = 0
      call dgeqp3(5, 4, a, 5, jpvt, tau, work, size(work), info)
      rank = 0
      do k = 1, 4
         if (abs(a(k, k)) > 1.0e-12_dp*abs(a(1, 1))) rank = rank + 1
      end do
      call check(error, rank, 2, 'numerical rank')
   end subroutine test_dgeqp3_rank

   !> Fixed notation keeps the zero before the point that f0.d drops ('done in .063 s').
   subroutine test_fixed_text(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, fixed_text(0.063_dp, 3), '0.063')
      if (allocated(error)) return
      call check(error, fixed_text(-0.5_dp, 2), '-0.50')
      if (allocated(error)) return
      call check(error, fixed_text(12.345_dp, 3), '12.345')
      if (allocated(error)) return
      call check(error, fixed_text(0.0_dp, 1), '0.0')
   end subroutine test_fixed_text

   !> Singular values of [[3,0],[4,5]] are sqrt(45) and sqrt(5) (A^T A has eigenvalues 45 and 5).
   subroutine test_dgesvd(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), s(2), u(1, 1), vt(1, 1), work(64)
      integer :: info
      a = reshape([3.0_dp, 4.0_dp, 0.0_dp, 5.0_dp], [2, 2])
      call dgesvd('N', 'N', 2, 2, a, 2, s, u, 1, vt, 1, work, size(work), info)
      call check(error, s(1), sqrt(45.0_dp), 1.0e-14_dp, 'sigma_1', rel=.true.)
      if (allocated(error)) return
      call check(error, s(2), sqrt(5.0_dp), 1.0e-14_dp, 'sigma_2', rel=.true.)
   end subroutine test_dgesvd

   subroutine test_dgemm_dsyrk(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(3, 2), c(2, 2), g(2, 2)
      a = reshape([1.0_dp, 2.0_dp, 3.0_dp, -1.0_dp, 0.5_dp, 4.0_dp], [3, 2])
      c = 0.0_dp
      call dgemm('T', 'N', 2, 2, 3, 1.0_dp, a, 3, a, 3, 0.0_dp, c, 2)
      call check(error, maxval(abs(c - matmul(transpose(a), a))), 0.0_dp, 1.0e-14_dp, 'dgemm A^T A')
      if (allocated(error)) return
      g = 0.0_dp
      call dsyrk('U', 'T', 2, 3, 1.0_dp, a, 3, 0.0_dp, g, 2)
      call check(error, abs(g(1, 1) - c(1, 1)) + abs(g(1, 2) - c(1, 2)) + abs(g(2, 2) - c(2, 2)), &
         0.0_dp, 1.0e-14_dp, 'dsyrk upper triangle')
   end subroutine test_dgemm_dsyrk

   !> A small KKT matrix [[2,1],[1,0]] is symmetric indefinite: dsysv solves it.
   subroutine test_dsysv(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: a(2, 2), b(2, 1), work(64)
      integer :: ipiv(2), info
      a = reshape([2.0_dp, 1.0_dp, 1.0_dp, 0.0_dp], [2, 2])
      b(:, 1) = [4.0_dp, 1.0_dp] ! x = (1, 2)
      call dsysv('U', 2, 1, a, 2, ipiv, b, 2, work, size(work), info)
      call check(error, info, 0, 'dsysv info')
      if (allocated(error)) return
      call check(error, maxval(abs(b(:, 1) - [1.0_dp, 2.0_dp])), 0.0_dp, 1.0e-14_dp, 'KKT solution')
   end subroutine test_dsysv

   subroutine test_info_translation(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      call lapack_info_error('dgesv', 0, 'ok', e)
      call check(error, .not. allocated(e), 'info 0 is no error')
      if (allocated(error)) return
      call lapack_info_error('dgesv', 3, 'patch 7', e)
      call check(error, e%stat, stat_singular, 'dgesv info>0 is singular')
      if (allocated(error)) return
      call check(error, index(e%message, 'patch 7') > 0 .and. index(e%message, 'dgesv') > 0, &
         'message names context and routine: '//e%message)
      if (allocated(error)) return
      call lapack_info_error('dgesv', -4, 'x', e)
      call check(error, e%stat, stat_invalid_input, 'negative info')
   end subroutine test_info_translation

   !> Integers and reals as text, checked against literal strings.
   !> lower touches A-Z only; xml_escape writes all five XML entities (the apostrophe
   !> too, so the text may sit in single-quoted attributes) and leaves the rest alone.
   subroutine test_lower_escape(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, lower('Kind = "Hertz_3D" @[Z]`{'), 'kind = "hertz_3d" @[z]`{', 'lower')
      if (allocated(error)) return
      call check(error, len(lower('AB  ')), 4, 'lower keeps the length')
      if (allocated(error)) return
      call check(error, xml_escape('a<b & "c" > it''s'), 'a&lt;b &amp; &quot;c&quot; &gt; it&apos;s', 'xml_escape')
      if (allocated(error)) return
      call check(error, xml_escape('&amp;'), '&amp;amp;', 'xml_escape escapes an entity once more')
      if (allocated(error)) return
      call check(error, len(xml_escape('')), 0, 'xml_escape of nothing')
   end subroutine test_lower_escape

   !> Each VTK table is a permutation of the Lagrange indices {0..p}^dim with the
   !> vertices first, and a few nodes sit where VTK puts them (by hand from the
   !> VTK file-format figures).
   subroutine test_lagrange_tables(error)
      type(error_type), allocatable, intent(out) :: error
      call check_table(vtk_line2, 1)
      if (allocated(error)) return
      call check_table(vtk_line3, 2)
      if (allocated(error)) return
      call check_table(vtk_quad4, 1)
      if (allocated(error)) return
      call check_table(vtk_quad9, 2)
      if (allocated(error)) return
      call check_table(vtk_hex8, 1)
      if (allocated(error)) return
      call check_table(vtk_hex27, 2)
      if (allocated(error)) return
      call check(error, all(vtk_quad9(:, 6) == [2, 1]) .and. all(vtk_quad9(:, 9) == [1, 1]) .and. &
         & all(vtk_hex27(:, 17) == [0, 0, 1]) .and. all(vtk_hex27(:, 18) == [2, 0, 1]) .and. &
         & all(vtk_hex27(:, 21) == [0, 1, 1]) .and. all(vtk_hex27(:, 23) == [1, 0, 1]) .and. &
         & all(vtk_hex27(:, 25) == [1, 1, 0]), 'quad9 and hex27 edge and face nodes where VTK puts them')
      if (allocated(error)) return
      call check(error, all(element_node_index(2, 2) == vtk_quad9) .and. all(element_node_index(3, 1) == vtk_hex8), &
         & 'element_node_index picks the table')
   contains
      subroutine check_table(idx, p)
         integer, intent(in) :: idx(:, :), p
         integer :: j, k, nv
         nv = 2**size(idx, 1)
         call check(error, size(idx, 2), (p + 1)**size(idx, 1), 'node count')
         if (allocated(error)) return
         call check(error, all(idx >= 0 .and. idx <= p), 'indices in 0..p')
         if (allocated(error)) return
         do j = 1, size(idx, 2)
            do k = 1, j - 1
               call check(error, any(idx(:, j) /= idx(:, k)), 'no two nodes alike')
               if (allocated(error)) return
            end do
            call check(error, (j <= nv) .eqv. all(idx(:, j) == 0 .or. idx(:, j) == p), 'vertices first')
            if (allocated(error)) return
         end do
      end subroutine check_table
   end subroutine test_lagrange_tables

   !> Kronecker property n_i(x_j) = delta_ij at the nodes (exact: the basis takes the
   !> values 0 and 1 there in floating point), and partition of unity at points inside
   !> and outside the element to a few ulps; for every table, degree 1 and 2.
   subroutine test_lagrange_kronecker(error)
      type(error_type), allocatable, intent(out) :: error
      call check_element(vtk_line2, 1)
      if (allocated(error)) return
      call check_element(vtk_line3, 2)
      if (allocated(error)) return
      call check_element(vtk_quad4, 1)
      if (allocated(error)) return
      call check_element(vtk_quad9, 2)
      if (allocated(error)) return
      call check_element(vtk_hex8, 1)
      if (allocated(error)) return
      call check_element(vtk_hex27, 2)
   contains
      subroutine check_element(idx, p)
         integer, intent(in) :: idx(:, :), p
         real(wp) :: n(size(idx, 2)), xi(size(idx, 1)), delta(size(idx, 2))
         real(wp), parameter :: pts(3, 4) = reshape([0.3_wp, 0.71_wp, 0.05_wp, -0.4_wp, 1.3_wp, 0.5_wp, &
            & 1.0_wp/3.0_wp, 0.9_wp, 2.0_wp, 0.123_wp, -1.0_wp, 0.77_wp], [3, 4])
         integer :: j, q
         do j = 1, size(idx, 2)
            xi = real(idx(:, j), wp)/real(p, wp)
            call tensor_shape(idx, p, xi, n)
            delta = 0.0_wp
            delta(j) = 1.0_wp
            call check(error, all(n == delta), 'n_i(x_j) = delta_ij')
            if (allocated(error)) return
         end do
         do q = 1, size(pts, 2)
            call tensor_shape(idx, p, pts(1:size(idx, 1), q), n)
            ! The terms reach |n| < 20 at these points; their sum rounds to 1 within 64 eps.
            call check(error, sum(n), 1.0_wp, thr=64*epsilon(1.0_wp), rel=.false.)
            if (allocated(error)) return
         end do
      end subroutine check_element
   end subroutine test_lagrange_kronecker

   !> The derivatives against central differences: the basis is of degree <= 2 in each
   !> variable, so the central difference has no truncation error and differs only by
   !> rounding, below 16 eps / h with h = 2**-10 (values up to ~4 in magnitude here).
   subroutine test_lagrange_derivative(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: h = 2.0_wp**(-10)
      real(wp) :: l(0:2), dl(0:2), lp(0:2), lm(0:2)
      integer :: p
      real(wp) :: t
      do p = 1, 2
         t = 0.37_wp
         call lagrange_1d(p, t, l, dl)
         call lagrange_1d(p, t + h, lp)
         call lagrange_1d(p, t - h, lm)
         call check(error, maxval(abs((lp - lm)/(2*h) - dl)) <= 16*epsilon(1.0_wp)/h, '1D derivative')
         if (allocated(error)) return
      end do
      call check_element(vtk_line3, 2)
      if (allocated(error)) return
      call check_element(vtk_quad4, 1)
      if (allocated(error)) return
      call check_element(vtk_quad9, 2)
      if (allocated(error)) return
      call check_element(vtk_hex8, 1)
      if (allocated(error)) return
      call check_element(vtk_hex27, 2)
   contains
      subroutine check_element(idx, p)
         integer, intent(in) :: idx(:, :), p
         real(wp) :: n(size(idx, 2)), np(size(idx, 2)), nm(size(idx, 2)), d(size(idx, 1), size(idx, 2))
         real(wp) :: xi(size(idx, 1)), e(size(idx, 1))
         real(wp), parameter :: x0(3) = [0.31_wp, 1.2_wp, -0.15_wp]
         integer :: k, rdim
         rdim = size(idx, 1)
         xi = x0(1:rdim)
         call tensor_shape(idx, p, xi, n, d)
         do k = 1, rdim
            e = 0.0_wp
            e(k) = h
            call tensor_shape(idx, p, xi + e, np)
            call tensor_shape(idx, p, xi - e, nm)
            call check(error, maxval(abs((np - nm)/(2*h) - d(k, :))) <= 16*epsilon(1.0_wp)/h, &
               & 'd n / d xi by central differences')
            if (allocated(error)) return
         end do
      end subroutine check_element
   end subroutine test_lagrange_derivative

   !> The hash table on adversarial keys: lattice points that are multiples of 2**18
   !> (all low bits zero), keys differing only in their highest bits, negative keys,
   !> each inserted twice (ties). Every key keeps the number of its first insertion, a
   !> repeat adds nothing, absent keys are not found, and no probe run is long: at load
   !> alpha <= 1/2 linear probing's longest run over n keys is about
   !> ln(n)/(alpha - 1 - ln alpha) = ln(n)/0.193, 50 for n = 3*4096, so 128 fails only for a hash that lets
   !> structured keys collide (the slot from the low bits alone puts them all in slot 0).
   subroutine test_key_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(key_table_type) :: t
      integer, parameter :: m = 4096
      integer :: i, k, number, key(3), run, longest
      integer(i8) :: s
      logical :: added

      call t%init(3, 16, 'test', error)
      if (allocated(error)) return
      do k = 1, 2
         do i = 1, 3*m
            key = adversarial(i)
            call t%insert(key, number, added, error)
            if (allocated(error)) return
            call check(error, number == i .and. (added .eqv. k == 1), 'first-insertion numbering, ties added once')
            if (allocated(error)) return
         end do
      end do
      call check(error, t%n, 3*m, 'keys stored')
      if (allocated(error)) return
      call check(error, t%find([1, 2, 3]) == 0 .and. t%find([0, 0, 0]) == 0 .and. &
         & t%find([-2**30, 0, 0]) == 0, 'absent keys')
      if (allocated(error)) return
      longest = 0
      do i = 1, t%n
         s = iand(hash_int(t%keys(:, i)), t%mask)
         run = 0
         do while (t%slot(s) /= i)
            s = iand(s + 1_i8, t%mask)
            run = run + 1
         end do
         longest = max(longest, run)
      end do
      call check(error, longest <= 128, 'longest probe run '//itoa(longest)//' for structured keys')
   contains
      pure function adversarial(i) result(g)
         integer, intent(in) :: i
         integer :: g(3)
         select case ((i - 1)/m)
         case (0)   ! dyadic lattice points: multiples of 2**18
            g = [mod(i, 2)*2**18, (i/2)*2**18, 0]
         case (1)   ! only the high bits vary
            g = [ishft(mod(i, 128), 24), ishft(i/128, 24), 7]
         case default   ! negative, and equal but for the sign
            g = [-i, i, -huge(1)]
         end select
      end function adversarial
   end subroutine test_key_table

   !> The sorts against an independent O(n**2) reference: in a stable ascending sort,
   !> element i goes to 1 + #{j: v(j) < v(i)} + #{j < i: v(j) == v(i)}. Keys with many
   !> ties, negative values, -0 and +0 (equal under <), huge and subnormal reals; sizes
   !> around the insertion runs (16) and merge widths.
   subroutine test_sort(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: sizes(8) = [0, 1, 2, 15, 16, 17, 33, 1000]
      integer :: c, n, i
      real(wp), allocatable :: r(:), rv(:)
      integer, allocatable :: k(:), kv(:), order(:), work(:), expect(:)
      integer(i8), allocatable :: k8(:)
      real(wp), parameter :: special(6) = [-0.0_wp, 0.0_wp, huge(1.0_wp), -huge(1.0_wp), tiny(1.0_wp)/8, -1.5_wp]

      do c = 1, size(sizes)
         n = sizes(c)
         allocate (r(n), k(n), k8(n), order(n), work(n), expect(n))
         do i = 1, n
            k(i) = mod(7919*i, 23) - 11
            r(i) = real(k(i), wp)/4.0_wp
            if (mod(i, 5) == 0) r(i) = special(1 + mod(i/5, size(special)))
            k8(i) = int(k(i), i8)*2_i8**40 + mod(i, 3)
         end do
         call sort_order(r, order, work)
         expect = stable_positions(r)
         call check(error, all(expect(order) == [(i, i=1, n)]), 'real sort_order, n = '//itoa(n))
         if (allocated(error)) return
         call sort_order(k, order, work)
         expect = stable_positions(real(k, wp))
         call check(error, all(expect(order) == [(i, i=1, n)]), 'integer sort_order')
         if (allocated(error)) return
         call sort_order(k8, order, work)
         expect = stable_positions(real(k8, wp))
         call check(error, all(expect(order) == [(i, i=1, n)]), 'integer(i8) sort_order')
         if (allocated(error)) return
         ! In place: the same values as the permuted input, bit for bit (-0 and +0 in input order).
         call sort_order(r, order, work)
         rv = r
         call sort(rv)
         call check(error, all(transfer(rv, 1_i8, n) == transfer(r(order), 1_i8, n)), 'real sort in place')
         if (allocated(error)) return
         kv = k
         call sort(kv)
         call sort_order(k, order, work)
         call check(error, all(kv == k(order)), 'integer sort in place')
         if (allocated(error)) return
         kv = [(n + 1 - i, i=1, n)]*3
         rv = real(kv, wp) + 0.5_wp
         call sort_pairs(kv, rv)
         call check(error, all(kv == [(3*i, i=1, n)]) .and. all(rv == real(kv, wp) + 0.5_wp), 'sort_pairs carries values')
         if (allocated(error)) return
         deallocate (r, k, k8, order, work, expect)
      end do
   contains
      pure function stable_positions(v) result(pos)
         real(wp), intent(in) :: v(:)
         integer :: pos(size(v)), i, j
         do i = 1, size(v)
            pos(i) = 1
            do j = 1, size(v)
               if (v(j) < v(i) .or. (j < i .and. v(j) == v(i))) pos(i) = pos(i) + 1
            end do
         end do
      end function stable_positions
   end subroutine test_sort

   subroutine test_strings(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, itoa(0)//' '//itoa(-12)//' '//itoa(huge(1_i4))//' '//itoa(-huge(1_i8)), &
         & '0 -12 2147483647 -9223372036854775807', 'itoa')
      if (allocated(error)) return
      call check(error, itoa(4, 2)//' '//itoa(123, 2)//' '//itoa(-4_i8, 3)//' '//itoa(7, 0), '04 123 -004 7', &
         & 'itoa with digits')
      if (allocated(error)) return
      call check(error, rtoa(-1234.5_wp)//' '//rtoa(0.0_wp), '-1.2345E+03 0.0000E+00', 'rtoa')
      if (allocated(error)) return
      call check(error, rtoa(0.5_wp, '(g0)')//' '//rtoa(-2.0_wp, '(es16.8)'), '0.50000000000000000 -2.00000000E+00', &
         & 'rtoa with a format')
   end subroutine test_strings

   !> One vocabulary: every kind's name maps back to it; the facet kinds of
   !> the C header (include/sprc.h, read here) are the same numbers, and every
   !> layer's names for them are the same constants.
   subroutine test_boundary_kinds(error)
      use sprc_fem_bc, only: fe_traction => bc_traction, fe_free => bc_free
      use sprc_estimate_patches, only: grid_traction => bc_traction, grid_symmetry => bc_symmetry
      use sprc_recovery_caller_mesh, only: facet_traction, facet_symmetry, facet_free
      use sprc_recovery_patch, only: boundary_traction, boundary_symmetry, boundary_contact, boundary_none
      use sprc_test_report, only: read_text_file
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: header
      integer :: k

      do k = bc_none, bc_contact
         call check(error, bc_kind_from_name(bc_kind_name(k)), k, 'name of kind '//itoa(k)//' maps back')
         if (allocated(error)) return
      end do
      call check(error, bc_kind_name(bc_contact + 1) == '' .and. bc_kind_from_name('torus') == -1, 'unknown kinds')
      if (allocated(error)) return
      call read_text_file('include/sprc.h', header, error)
      if (allocated(error)) return
      call check(error, index(header, '#define SPRC_FACET_TRACTION '//itoa(bc_traction)//new_line('a')) > 0 .and. &
         & index(header, '#define SPRC_FACET_SYMMETRY '//itoa(bc_symmetry)//new_line('a')) > 0 .and. &
         & index(header, '#define SPRC_FACET_FREE '//itoa(bc_free)//new_line('a')) > 0 .and. &
         & index(header, '#define SPRC_FACET_PRESSURE '//itoa(bc_pressure)//new_line('a')) > 0, 'C facet kinds')
      if (allocated(error)) return
      call check(error, all([fe_traction, grid_traction, facet_traction, boundary_traction] == bc_traction) .and. &
         & all([grid_symmetry, facet_symmetry, boundary_symmetry] == bc_symmetry) .and. &
         & all([fe_free, facet_free] == bc_free) .and. boundary_contact == bc_contact .and. boundary_none == bc_none, &
         & 'every layer uses the one vocabulary')
   end subroutine test_boundary_kinds

end module sprc_test_core
