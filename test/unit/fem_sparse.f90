!> Tests of the sparse area: COO -> CSR assembly, CSR products and norms, and
!> the CHOLMOD and UMFPACK solvers on finite-element-like systems.
!>
!> Solves are checked against a manufactured x_true with b = A x_true formed
!> densely. The bound on the relative 1-norm error is 10 cond_1(A) eps, with
!> cond_1 computed exactly from a dense inverse: both back ends are normwise
!> backward stable (backward error a small multiple of eps for matrices of
!> this size), and the condition number bounds the forward amplification; the
!> factor 10 is the stated margin.
module sprc_test_sparse
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan, ieee_positive_inf
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: stat_invalid_input, stat_singular, stat_not_positive_definite, stat_out_of_memory
   use sprc_core_lapack, only: dgesv, dgetrf, dgecon, dlange
   use sprc_testsuite, only: unittest_type, new_unittest, check, test_failed, error_type
   use sprc_fem_sparse, only: coo_type, csr_type, block_list_type
   use sprc_fem_linear_solver, only: linear_solver_type
   use sprc_fem_cholmod, only: cholmod_solver_type
   use sprc_fem_umfpack, only: umfpack_solver_type
   implicit none
   private

   public :: collect_sparse

   !> Margin over cond_1(A) eps allowed for the forward error of a solve.
   real(wp), parameter :: solve_margin = 10.0_wp

contains

   subroutine collect_sparse(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('coo_duplicates_sorted', test_coo_duplicates_sorted), &
         new_unittest('coo_insertion_order', test_coo_insertion_order), &
         new_unittest('coo_blocks', test_coo_blocks), &
         new_unittest('block_list_as_coo', test_block_list_as_coo), &
         new_unittest('coo_rejects', test_coo_rejects), &
         new_unittest('coo_zero_size', test_coo_zero_size), &
         new_unittest('coo_out_of_memory', test_coo_out_of_memory), &
         new_unittest('csr_matvec_norm', test_csr_matvec_norm), &
         new_unittest('csr_invalid', test_csr_invalid), &
         new_unittest('elasticity_rigid_modes', test_elasticity_rigid_modes), &
         new_unittest('cholmod_laplace_2d', test_cholmod_laplace_2d), &
         new_unittest('cholmod_laplace_3d', test_cholmod_laplace_3d), &
         new_unittest('cholmod_elasticity_2d', test_cholmod_elasticity_2d), &
         new_unittest('cholmod_elasticity_3d', test_cholmod_elasticity_3d), &
         new_unittest('cholmod_lower_triangle', test_cholmod_lower_triangle), &
         new_unittest('umfpack_laplace_2d', test_umfpack_laplace_2d), &
         new_unittest('umfpack_laplace_3d', test_umfpack_laplace_3d), &
         new_unittest('umfpack_elasticity_2d', test_umfpack_elasticity_2d), &
         new_unittest('umfpack_elasticity_3d', test_umfpack_elasticity_3d), &
         new_unittest('umfpack_convection_diffusion', test_umfpack_convection_diffusion), &
         new_unittest('cholmod_not_positive_definite', test_cholmod_not_positive_definite), &
         new_unittest('floating_singular', test_floating_singular), &
         new_unittest('umfpack_exactly_singular', test_umfpack_exactly_singular), &
         new_unittest('solve_before_factorize', test_solve_before_factorize), &
         new_unittest('wrong_rhs_shape', test_wrong_rhs_shape), &
         new_unittest('factorize_invalid', test_factorize_invalid), &
         new_unittest('rcond_vs_dense', test_rcond_vs_dense), &
         new_unittest('rcond_diagonal', test_rcond_diagonal), &
         new_unittest('destroy_refactorize', test_destroy_refactorize), &
         new_unittest('zero_size_solve', test_zero_size_solve), &
         new_unittest('same_bits_any_blas_threads', test_blas_threads_bits), &
         new_unittest('cholmod_ordering_by_cost', test_cholmod_ordering) &
         ]
   end subroutine collect_sparse

   ! ------------------------------------------------------------------ COO / CSR

   !> A capacity no machine has (2**60 triplets, 18 EB) is an out-of-memory error that
   !> names the routine, the array and its size, not a crash; the list stays usable.
   subroutine test_coo_out_of_memory(error)
      type(error_type), allocatable, intent(out) :: error
      type(error_type), allocatable :: e
      type(coo_type) :: coo
      type(csr_type) :: a

      call coo%init(3, 3, e, capacity=2_i8**60)
      call check(error, allocated(e), 'an absurd capacity fails')
      if (allocated(error)) return
      call check(error, e%stat, stat_out_of_memory, 'status')
      if (allocated(error)) return
      call check(error, e%message, 'coo_type%reserve: out of memory: cannot allocate the triplet list '// &
         & '(1152921504606846976 entries of 16 bytes, 1.8E+10 GB)')
      if (allocated(error)) return
      call add(coo, 2, 3, 1.5_wp, error)
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      call check(error, a%nnz() == 1_i8 .and. a%val(1) == 1.5_wp, 'the list still works after the failure')
   end subroutine test_coo_out_of_memory

   !> Unsorted input with duplicates and an empty row, checked entry by entry.
   subroutine test_coo_duplicates_sorted(error)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      type(csr_type) :: a

      call coo%init(4, 3, error)
      if (allocated(error)) return
      call add(coo, 3, 3, 1.0_wp, error); if (allocated(error)) return
      call add(coo, 1, 2, 2.0_wp, error); if (allocated(error)) return
      call add(coo, 3, 1, 3.0_wp, error); if (allocated(error)) return
      call add(coo, 1, 2, 4.0_wp, error); if (allocated(error)) return
      call add(coo, 4, 2, 5.0_wp, error); if (allocated(error)) return
      call add(coo, 3, 3, -1.0_wp, error); if (allocated(error)) return
      call add(coo, 1, 1, 6.0_wp, error); if (allocated(error)) return
      call check(error, coo%nnz == 7_i8, 'seven triplets stored')
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      ! row 1: (1)6 (2)2+4; row 2 empty; row 3: (1)3 (3)1-1=0 kept; row 4: (2)5
      call check(error, all(a%rowptr == [1_i8, 3_i8, 3_i8, 5_i8, 6_i8]), 'rowptr')
      if (allocated(error)) return
      call check(error, all(a%col == [1, 2, 1, 3, 2]), 'columns sorted within rows')
      if (allocated(error)) return
      call check(error, same(a%val, [6.0_wp, 6.0_wp, 3.0_wp, 0.0_wp, 5.0_wp]), 'duplicates summed')
      if (allocated(error)) return
      call check(error, a%nnz() == 5_i8, 'nnz')
   end subroutine test_coo_duplicates_sorted

   !> Duplicates are summed left to right in insertion order: with u = 2^-53,
   !> (1 + u) + u = 1 (each sum rounds to even) but (u + u) + 1 = 1 + 2u
   !> exactly. Other entries interleaved, and twice over, to show stability.
   subroutine test_coo_insertion_order(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: u = 2.0_wp**(-53)
      type(coo_type) :: coo
      type(csr_type) :: a, b

      call coo%init(2, 2, error)
      if (allocated(error)) return
      call add(coo, 1, 1, 1.0_wp, error); if (allocated(error)) return
      call add(coo, 2, 2, u, error); if (allocated(error)) return
      call add(coo, 1, 2, 7.0_wp, error); if (allocated(error)) return
      call add(coo, 1, 1, u, error); if (allocated(error)) return
      call add(coo, 2, 2, u, error); if (allocated(error)) return
      call add(coo, 2, 1, 7.0_wp, error); if (allocated(error)) return
      call add(coo, 1, 1, u, error); if (allocated(error)) return
      call add(coo, 2, 2, 1.0_wp, error); if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      call check(error, same(a%val(1:1), [1.0_wp]), 'A(1,1) = (1 + u) + u = 1')
      if (allocated(error)) return
      call check(error, same(a%val(4:4), [1.0_wp + 2.0_wp*u]), 'A(2,2) = (u + u) + 1 = 1 + 2u')
      if (allocated(error)) return
      call coo%to_csr(b, error)
      if (allocated(error)) return
      call check(error, same(a%val, b%val) .and. all(a%col == b%col), 'repeatable')
   end subroutine test_coo_insertion_order

   !> A block list (pseudo-random blocks with values of mixed magnitudes, so that the
   !> order of each sum shows in its bits; an empty block; a vector per block) gives
   !> the matrix of adding the same blocks to a COO list in block order, bit for bit,
   !> with 1 and 2 threads; the summed vector equals sums in block order.
   subroutine test_block_list_as_coo(error)
      !$ use omp_lib, only: omp_get_max_threads, omp_set_num_threads
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 40, nb = 60
      type(block_list_type) :: blocks
      type(coo_type) :: coo
      type(csr_type) :: a, ref
      real(wp), allocatable :: f(:)
      real(wp) :: fref(n), r
      integer :: m(nb), b, i, j, nt, saved, k
      integer(i8) :: p, v
      logical :: seen(n)

      do b = 1, nb
         m(b) = mod(7*b, 9)
      end do
      call blocks%init(n, m, error)
      if (allocated(error)) return
      call coo%init(n, n, error)
      if (allocated(error)) return
      fref = 0.0_wp
      k = 0
      do b = 1, nb
         p = blocks%dof_ptr(b)
         v = blocks%val_ptr(b)
         seen = .false.
         do i = 1, m(b)
            ! distinct dofs, not sorted
            do
               k = mod(17*k + 11, n)
               if (.not. seen(k + 1)) exit
            end do
            seen(k + 1) = .true.
            blocks%dofs(p + i - 1) = k + 1
            blocks%rhs(p + i - 1) = 10.0_wp**mod(3*b + i, 17) - 1.0_wp/real(i, wp)
            fref(k + 1) = fref(k + 1) + blocks%rhs(p + i - 1)
         end do
         do j = 1, m(b)
            do i = 1, m(b)
               r = 10.0_wp**mod(5*b + 3*i + j, 19)*(1.0_wp + 1.0_wp/real(i + 2*j, wp))
               blocks%val(v + i - 1 + (j - 1)*m(b)) = r
            end do
         end do
         call coo%add(blocks%dofs(p:p + m(b) - 1), &
            & reshape(blocks%val(v:v + m(b)**2 - 1), [m(b), m(b)]), error)
         if (allocated(error)) return
      end do
      call coo%to_csr(ref, error)
      if (allocated(error)) return
      saved = 1
      !$ saved = omp_get_max_threads()
      do nt = 1, 2
         !$ call omp_set_num_threads(nt)
         call blocks%to_csr(a, error, f)
         if (allocated(error)) exit
         call check(error, all(a%rowptr == ref%rowptr) .and. all(a%col == ref%col) .and. same(a%val, ref%val), &
            & 'the matrix of the COO list, bit for bit, with '//merge('1', '2', nt == 1)//' thread(s)')
         if (allocated(error)) exit
         call check(error, same(f, fref), 'the vector summed in block order')
         if (allocated(error)) exit
      end do
      !$ call omp_set_num_threads(saved)
   end subroutine test_block_list_as_coo

   !> Element blocks (general and square) against a dense sum, including a
   !> repeated index inside one block; a misshapen block is rejected.
   subroutine test_coo_blocks(error)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      type(csr_type) :: a
      type(error_type), allocatable :: err
      real(wp) :: ke(3, 3), kr(2, 3), expect(5, 5)
      integer, parameter :: rows(2) = [4, 1], cols(3) = [1, 3, 4]
      integer :: dofs(3), i, j

      ke = reshape([(real(i, wp), i=1, 9)], [3, 3])
      kr = reshape([(real(10*i, wp), i=1, 6)], [2, 3])
      dofs = [5, 2, 5]
      expect = 0.0_wp
      do j = 1, 3
         do i = 1, 3
            expect(dofs(i), dofs(j)) = expect(dofs(i), dofs(j)) + ke(i, j)
         end do
      end do
      do j = 1, 3
         do i = 1, 2
            expect(rows(i), cols(j)) = expect(rows(i), cols(j)) + kr(i, j)
         end do
      end do
      call coo%init(5, 5, error)
      if (allocated(error)) return
      call coo%add(dofs, ke, error)
      if (allocated(error)) return
      call coo%add(rows, cols, kr, error)
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      call check(error, same(reshape(to_dense(a), [25]), reshape(expect, [25])), 'blocks summed as the dense reference')
      if (allocated(error)) return
      call check(error, a%nnz() == 10_i8, 'distinct entries counted once')
      if (allocated(error)) return

      call coo%add([1, 2], ke, err)
      call expect_error(err, stat_invalid_input, '3 x 3 block for 2 rows and 2 columns', error)
      if (allocated(error)) return
      call check(error, coo%nnz == 15_i8, 'a rejected block adds nothing')
   end subroutine test_coo_blocks

   subroutine test_coo_rejects(error)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      type(error_type), allocatable :: err
      real(wp) :: nan, inf

      nan = ieee_value(0.0_wp, ieee_quiet_nan)
      inf = ieee_value(0.0_wp, ieee_positive_inf)
      call coo%init(3, 2, error)
      if (allocated(error)) return

      call coo%add(0, 1, 1.0_wp, err)
      call expect_error(err, stat_invalid_input, 'row index 0', error)
      if (allocated(error)) return
      call coo%add(4, 1, 1.0_wp, err)
      call expect_error(err, stat_invalid_input, 'row index 4 outside 1..3', error)
      if (allocated(error)) return
      call coo%add(1, 3, 1.0_wp, err)
      call expect_error(err, stat_invalid_input, 'column index 3 outside 1..2', error)
      if (allocated(error)) return
      call coo%add(2, 2, nan, err)
      call expect_error(err, stat_invalid_input, 'not finite', error)
      if (allocated(error)) return
      call coo%add(2, 2, inf, err)
      call expect_error(err, stat_invalid_input, 'not finite', error)
      if (allocated(error)) return
      call coo%add([1, 2], [1, 2], reshape([1.0_wp, 2.0_wp, nan, 4.0_wp], [2, 2]), err)
      call expect_error(err, stat_invalid_input, '(1, 2) is not finite', error)
      if (allocated(error)) return
      call coo%add([1, 9], reshape([1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp], [2, 2]), err)
      call expect_error(err, stat_invalid_input, 'row index 9', error)
      if (allocated(error)) return
      call check(error, coo%nnz == 0_i8, 'nothing stored by rejected adds')
      if (allocated(error)) return

      call coo%init(-1, 2, err)
      call expect_error(err, stat_invalid_input, 'negative dimensions', error)
   end subroutine test_coo_rejects

   subroutine test_coo_zero_size(error)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      type(csr_type) :: a
      real(wp) :: x(0), y(0), y3(3), norm

      call coo%init(0, 0, error)
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      call check(error, size(a%rowptr) == 1 .and. a%rowptr(1) == 1_i8 .and. a%nnz() == 0_i8, &
         '0 x 0: rowptr = [1], no entries')
      if (allocated(error)) return
      call a%matvec(x, y, error)
      if (allocated(error)) return
      norm = a%norm1(error)
      if (allocated(error)) return
      call check(error, norm, 0.0_wp, 0.0_wp, 'norm of the empty matrix')
      if (allocated(error)) return

      call coo%init(3, 0, error)
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      y3 = 1.0_wp
      call a%matvec(x, y3, error)
      if (allocated(error)) return
      call check(error, same(y3, [0.0_wp, 0.0_wp, 0.0_wp]) .and. all(a%rowptr == 1_i8), '3 x 0: empty rows, A x = 0')
   end subroutine test_coo_zero_size

   !> A 7 x 5 matrix with many duplicates from a fixed pseudo-random sequence:
   !> matvec and norm1 against the dense matrix summed independently.
   subroutine test_csr_matvec_norm(error)
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      type(csr_type) :: a
      type(error_type), allocatable :: err
      real(wp) :: dense(7, 5), x(5), y(7), work(5), v, norm
      integer :: k, i, j

      call coo%init(7, 5, error)
      if (allocated(error)) return
      dense = 0.0_wp
      do k = 1, 60
         i = 1 + mod(17*k + 3, 7)
         j = 1 + mod(11*k*k + 5, 5)
         if (i == 4) cycle ! an empty row
         v = sin(real(k, wp)) - 0.25_wp
         dense(i, j) = dense(i, j) + v
         call coo%add(i, j, v, error)
         if (allocated(error)) return
      end do
      call coo%to_csr(a, error)
      if (allocated(error)) return
      x = [(cos(real(j, wp)), j=1, 5)]
      call a%matvec(x, y, error)
      if (allocated(error)) return
      ! sums of at most 60 terms of size <= 1.25: rounding below 1e-13
      call check(error, maxval(abs(y - matmul(dense, x))), 0.0_wp, 1.0e-13_wp, 'A x against dense')
      if (allocated(error)) return
      norm = a%norm1(error)
      if (allocated(error)) return
      call check(error, norm, dlange('1', 7, 5, dense, 7, work), 1.0e-13_wp, 'norm1 against dlange')
      if (allocated(error)) return
      call check(error, a%rowptr(4) == a%rowptr(5), 'row 4 empty')
      if (allocated(error)) return

      call a%matvec(x(1:4), y, err)
      call expect_error(err, stat_invalid_input, '7 x 5 matrix, x of size 4', error)
   end subroutine test_csr_matvec_norm

   !> Hand-broken CSR matrices are rejected by factorize before reaching C.
   subroutine test_csr_invalid(error)
      type(error_type), allocatable, intent(out) :: error
      type(csr_type) :: a
      type(cholmod_solver_type) :: chol
      type(error_type), allocatable :: err

      a%nrows = 2
      a%ncols = 2
      a%rowptr = [1_i8, 3_i8, 4_i8]
      a%col = [2, 1, 2]
      a%val = [1.0_wp, 2.0_wp, 3.0_wp]
      call chol%factorize(a, err)
      call expect_error(err, stat_invalid_input, 'not strictly increasing', error)
      if (allocated(error)) return
      a%col = [1, 2, 3]
      call chol%factorize(a, err)
      call expect_error(err, stat_invalid_input, 'column 3 in row 2 outside 1..2', error)
      if (allocated(error)) return
      a%col = [1, 2, 2]
      a%rowptr = [1_i8, 3_i8, 2_i8]
      call chol%factorize(a, err)
      call expect_error(err, stat_invalid_input, 'rowptr decreases', error)
      if (allocated(error)) return
      deallocate (a%rowptr)
      call chol%factorize(a, err)
      call expect_error(err, stat_invalid_input, 'not allocated', error)
      call chol%destroy()
   end subroutine test_csr_invalid

   !> Independent check of the test's own element: the unconstrained Q1
   !> stiffness annihilates rigid-body modes (translations, and rotations
   !> which Q1 represents exactly), and is symmetric.
   subroutine test_elasticity_rigid_modes(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: dim

      do dim = 2, 3
         call check_rigid_modes(dim, error)
         if (allocated(error)) return
      end do
   end subroutine test_elasticity_rigid_modes

   subroutine check_rigid_modes(dim, error)
      integer, intent(in) :: dim
      type(error_type), allocatable, intent(out) :: error
      type(csr_type) :: k
      real(wp), allocatable :: coords(:, :), r(:), kr(:), kd(:, :)
      real(wp) :: knorm
      integer :: mode, node, nnode

      call elasticity(dim, 3, .false., k, error, coords)
      if (allocated(error)) return
      allocate (kd, source=to_dense(k))
      knorm = k%norm1(error)
      if (allocated(error)) return
      ! symmetric up to the order of the products in one element entry
      call check(error, maxval(abs(kd - transpose(kd))) <= 1.0e-15_wp*knorm, 'stiffness symmetric')
      if (allocated(error)) return
      nnode = size(coords, 2)
      allocate (r(dim*nnode), kr(dim*nnode))
      do mode = 1, dim + 1
         do node = 1, nnode
            if (mode <= dim) then
               r(dim*(node - 1) + 1:dim*node) = 0.0_wp
               r(dim*(node - 1) + mode) = 1.0_wp
            else ! rotation about the z axis
               r(dim*(node - 1) + 1:dim*node) = 0.0_wp
               r(dim*(node - 1) + 1) = -coords(2, node)
               r(dim*(node - 1) + 2) = coords(1, node)
            end if
         end do
         call k%matvec(r, kr, error)
         if (allocated(error)) return
         ! rounding in sums of a few dozen O(1) terms: 1e-13 relative to ||K|| ||r||
         call check(error, maxval(abs(kr)) <= 1.0e-13_wp*knorm*maxval(abs(r)), 'K r = 0 for a rigid mode')
         if (allocated(error)) return
      end do
   end subroutine check_rigid_modes

   ! ------------------------------------------------------------------ solves

   subroutine test_cholmod_laplace_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a
      call laplace(2, 12, a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_cholmod_laplace_2d

   subroutine test_cholmod_laplace_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a
      call laplace(3, 6, a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_cholmod_laplace_3d

   subroutine test_cholmod_elasticity_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a
      call elasticity(2, 8, .true., a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_cholmod_elasticity_2d

   subroutine test_cholmod_elasticity_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a
      call elasticity(3, 4, .true., a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_cholmod_elasticity_3d

   subroutine test_umfpack_laplace_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: solver
      type(csr_type) :: a
      call laplace(2, 12, a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_umfpack_laplace_2d

   subroutine test_umfpack_laplace_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: solver
      type(csr_type) :: a
      call laplace(3, 6, a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_umfpack_laplace_3d

   subroutine test_umfpack_elasticity_2d(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: solver
      type(csr_type) :: a
      call elasticity(2, 8, .true., a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_umfpack_elasticity_2d

   subroutine test_umfpack_elasticity_3d(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: solver
      type(csr_type) :: a
      call elasticity(3, 4, .true., a, error)
      if (allocated(error)) return
      call check_solves(solver, a, error)
   end subroutine test_umfpack_elasticity_3d

   !> Unsymmetric upwind convection-diffusion, cell Peclet number 2: A x = b
   !> and A^T x = b (the transposed solve that rcond relies on).
   subroutine test_umfpack_convection_diffusion(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: solver
      type(csr_type) :: a
      real(wp), allocatable :: ad(:, :), xt(:), x(:)
      real(wp) :: bound

      call convection_diffusion(10, 40.0_wp, a, error)
      if (allocated(error)) return
      allocate (ad, source=to_dense(a))
      call check(error, any(abs(ad - transpose(ad)) > 0.0_wp), 'the matrix is unsymmetric')
      if (allocated(error)) return
      call check_solves(solver, a, error)
      if (allocated(error)) return
      xt = manufactured(a%nrows, 1)
      allocate (x(a%nrows))
      call solver%factorize(a, error)
      if (allocated(error)) return
      call solver%solve(matmul(transpose(ad), xt), x, error, transposed=.true.)
      if (allocated(error)) return
      bound = solve_margin*cond1(transpose(ad))*epsilon(1.0_wp)
      call check(error, relerr(x, xt) <= bound, 'A^T x = b within 10 cond eps')
      call solver%destroy()
   end subroutine test_umfpack_convection_diffusion

   !> Factorize once, then solve one right-hand side and three at once;
   !> every solution within the stated bound; the factor statistics sane.
   subroutine check_solves(solver, a, error)
      class(linear_solver_type), intent(inout) :: solver
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: ad(:, :), xt(:, :), x(:, :), x1(:)
      real(wp) :: bound
      integer :: j, n

      n = a%nrows
      allocate (ad, source=to_dense(a))
      bound = solve_margin*cond1(ad)*epsilon(1.0_wp)
      xt = reshape([(manufactured(n, j), j=1, 3)], [n, 3])
      call solver%factorize(a, error)
      if (allocated(error)) return
      call check(error, solver%n == n .and. solver%factorized, 'factorized, order set')
      if (allocated(error)) return
      call check(error, solver%factor_nnz >= (a%nnz() + n)/2 .and. solver%peak_bytes > 0, &
         'factor statistics reported')
      if (allocated(error)) return
      call check(error, solver%pivot_ratio > 0.0_wp .and. solver%pivot_ratio <= 1.0_wp, 'pivot ratio in (0, 1]')
      if (allocated(error)) return
      ! the condition estimate is at least the true reciprocal condition number
      call check(error, solver%rcond_estimate*(1.0_wp + 1.0e-10_wp) >= solve_margin*epsilon(1.0_wp)/bound, &
         'condition estimate made by factorize')
      if (allocated(error)) return

      allocate (x1(n), x(n, 3))
      call solver%solve(matmul(ad, xt(:, 1)), x1, error)
      if (allocated(error)) return
      call check(error, relerr(x1, xt(:, 1)) <= bound, 'one right-hand side within 10 cond eps')
      if (allocated(error)) return
      call solver%solve(matmul(ad, xt), x, error)
      if (allocated(error)) return
      do j = 1, 3
         call check(error, relerr(x(:, j), xt(:, j)) <= bound, 'three right-hand sides within 10 cond eps')
         if (allocated(error)) return
      end do
      call solver%destroy()
   end subroutine check_solves

   !> CHOLMOD orders with AMD where its factorization is cheap (2D elasticity,
   !> 20,402 unknowns) and with METIS where AMD's factorization would cost
   !> enough for METIS's analysis to pay (3D elasticity, 24,000 unknowns);
   !> either way the solve recovers a manufactured solution within
   !> solve_margin eps / rcond.
   subroutine test_cholmod_ordering(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a
      real(wp), allocatable :: xt(:), x(:), b(:)
      integer :: dim
      character(len=5), parameter :: expected(2:3) = [character(len=5) :: 'AMD', 'METIS']

      do dim = 2, 3
         call elasticity(dim, merge(100, 20, dim == 2), .true., a, error)
         if (allocated(error)) return
         call solver%factorize(a, error)
         if (allocated(error)) return
         call check(error, solver%ordering == expected(dim), achar(48 + dim)//'D: ordering '//trim(solver%ordering)// &
            & ', expected '//trim(expected(dim)))
         if (allocated(error)) return
         xt = manufactured(a%nrows, 1)
         allocate (x(a%nrows), b(a%nrows))
         call a%matvec(xt, b, error)
         if (allocated(error)) return
         call solver%solve(b, x, error)
         if (allocated(error)) return
         call check(error, relerr(x, xt) <= solve_margin*epsilon(1.0_wp)/solver%rcond_estimate, 'solution')
         if (allocated(error)) return
         deallocate (x, b)
         call solver%destroy()
         call check(error, solver%ordering == '', 'no ordering after destroy')
         if (allocated(error)) return
      end do
   end subroutine test_cholmod_ordering

   !> CHOLMOD reads the lower triangle only: garbage in the strict upper
   !> triangle changes nothing, and the lower triangle alone suffices.
   subroutine test_cholmod_lower_triangle(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a, g, low
      type(coo_type) :: coo
      real(wp), allocatable :: x(:), y(:), z(:), b(:)
      integer :: i
      integer(i8) :: k

      call elasticity(2, 4, .true., a, error)
      if (allocated(error)) return
      b = manufactured(a%nrows, 1)
      g = a
      call coo%init(a%nrows, a%ncols, error)
      if (allocated(error)) return
      do i = 1, a%nrows
         do k = a%rowptr(i), a%rowptr(i + 1) - 1
            if (a%col(k) > i) then
               g%val(k) = 1.0e3_wp*real(i, wp)
            else
               call coo%add(i, a%col(k), a%val(k), error)
               if (allocated(error)) return
            end if
         end do
      end do
      call coo%to_csr(low, error)
      if (allocated(error)) return
      allocate (x(a%nrows), y(a%nrows), z(a%nrows))
      call factor_and_solve(a, x, error)
      if (allocated(error)) return
      call factor_and_solve(g, y, error)
      if (allocated(error)) return
      call factor_and_solve(low, z, error)
      if (allocated(error)) return
      ! same lower-triangle input, same deterministic factorization
      call check(error, same(x, y), 'strict upper triangle ignored')
      if (allocated(error)) return
      call check(error, same(x, z), 'lower triangle alone gives the same solution')
   contains
      subroutine factor_and_solve(m, sol, error)
         type(csr_type), intent(in) :: m
         real(wp), intent(out) :: sol(:)
         type(error_type), allocatable, intent(out) :: error
         call solver%factorize(m, error)
         if (allocated(error)) return
         call solver%solve(b, sol, error)
         call solver%destroy()
      end subroutine factor_and_solve
   end subroutine test_cholmod_lower_triangle

   ! ------------------------------------------------------------------ errors

   !> diag(1, 2, -3, 4) breaks down at column 3 whatever the ordering; a
   !> shifted Laplacian (indefinite, not diagonal) is rejected as well.
   subroutine test_cholmod_not_positive_definite(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: solver
      type(csr_type) :: a
      type(error_type), allocatable :: err
      real(wp) :: x(4)
      integer :: i

      call diagonal([1.0_wp, 2.0_wp, -3.0_wp, 4.0_wp], a, error)
      if (allocated(error)) return
      call solver%factorize(a, err)
      call expect_error(err, stat_not_positive_definite, '(matrix column 3)', error)
      if (allocated(error)) return
      call check(error, .not. solver%factorized, 'nothing factored after the failure')
      if (allocated(error)) return
      call solver%solve([1.0_wp, 1.0_wp, 1.0_wp, 1.0_wp], x, err)
      call expect_error(err, stat_invalid_input, 'no factor', error)
      if (allocated(error)) return

      ! eigenvalues of the 2D 5-point Laplacian lie in (0, 8): shift by -4
      call laplace(2, 6, a, error)
      if (allocated(error)) return
      do i = 1, a%nrows
         a%val(a%rowptr(i):a%rowptr(i + 1) - 1) = merge(a%val(a%rowptr(i):a%rowptr(i + 1) - 1) - 4.0_wp, &
            a%val(a%rowptr(i):a%rowptr(i + 1) - 1), a%col(a%rowptr(i):a%rowptr(i + 1) - 1) == i)
      end do
      call solver%factorize(a, err)
      call expect_error(err, stat_not_positive_definite, 'not positive definite', error)
      call solver%destroy()
   end subroutine test_cholmod_not_positive_definite

   !> Unconstrained elasticity has rigid-body modes: both back ends refuse it.
   !> Rounding decides whether CHOLMOD meets a tiny negative pivot
   !> (not positive definite) or only tiny positive ones (then the condition
   !> estimate, a fraction of eps, is below rcond_tol: singular).
   subroutine test_floating_singular(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf
      type(csr_type) :: a
      type(error_type), allocatable :: err
      integer :: dim

      do dim = 2, 3
         call elasticity(dim, 3, .false., a, error)
         if (allocated(error)) return
         call chol%factorize(a, err)
         call check(error, allocated(err), 'CHOLMOD refuses a floating system')
         if (allocated(error)) return
         call check(error, err%stat == stat_singular .or. err%stat == stat_not_positive_definite, &
            'CHOLMOD: singular or not positive definite: '//err%message)
         if (allocated(error)) return
         call umf%factorize(a, err)
         call expect_error(err, stat_singular, 'numerically singular: reciprocal condition estimate', error)
         if (allocated(error)) return
         call check(error, .not. (chol%factorized .or. umf%factorized), 'nothing factored')
         if (allocated(error)) return
      end do
      call chol%destroy()
      call umf%destroy()
   end subroutine test_floating_singular

   !> [1 2; 2 4] has an exactly zero second pivot: UMFPACK's own singular
   !> status, also when the condition check is off (rcond_tol = 0).
   subroutine test_umfpack_exactly_singular(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: solver
      type(csr_type) :: a
      type(error_type), allocatable :: err

      a%nrows = 2
      a%ncols = 2
      a%rowptr = [1_i8, 3_i8, 5_i8]
      a%col = [1, 2, 1, 2]
      a%val = [1.0_wp, 2.0_wp, 2.0_wp, 4.0_wp]
      solver%rcond_tol = 0.0_wp
      call solver%factorize(a, err)
      call expect_error(err, stat_singular, 'UMFPACK factorize: the matrix is singular', error)
      call solver%destroy()
   end subroutine test_umfpack_exactly_singular

   subroutine test_solve_before_factorize(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf
      type(csr_type) :: a
      type(error_type), allocatable :: err
      real(wp) :: x(3), x2(3, 2), value

      call chol%solve([1.0_wp, 2.0_wp, 3.0_wp], x, err)
      call expect_error(err, stat_invalid_input, 'no factor', error)
      if (allocated(error)) return
      call umf%solve(reshape([1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp, 5.0_wp, 6.0_wp], [3, 2]), x2, err)
      call expect_error(err, stat_invalid_input, 'no factor', error)
      if (allocated(error)) return
      call diagonal([1.0_wp, 2.0_wp, 3.0_wp], a, error)
      if (allocated(error)) return
      call umf%rcond(a, value, err)
      call expect_error(err, stat_invalid_input, 'no factor', error)
   end subroutine test_solve_before_factorize

   subroutine test_wrong_rhs_shape(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf
      type(csr_type) :: a, other
      type(error_type), allocatable :: err
      real(wp) :: x(3), x4(4), x2(3, 2), value

      call diagonal([1.0_wp, 2.0_wp, 3.0_wp], a, error)
      if (allocated(error)) return
      call chol%factorize(a, error)
      if (allocated(error)) return
      call umf%factorize(a, error)
      if (allocated(error)) return
      call chol%solve([1.0_wp, 2.0_wp, 3.0_wp, 4.0_wp], x, err)
      call expect_error(err, stat_invalid_input, 'b has 4 rows and x 3 for a matrix of order 3', error)
      if (allocated(error)) return
      call umf%solve([1.0_wp, 2.0_wp, 3.0_wp], x4, err)
      call expect_error(err, stat_invalid_input, 'b has 3 rows and x 4', error)
      if (allocated(error)) return
      call umf%solve(reshape([1.0_wp, 2.0_wp, 3.0_wp], [3, 1]), x2, err)
      call expect_error(err, stat_invalid_input, 'b has 1 columns and x 2', error)
      if (allocated(error)) return
      call diagonal([1.0_wp, 2.0_wp], other, error)
      if (allocated(error)) return
      call chol%rcond(other, value, err)
      call expect_error(err, stat_invalid_input, 'not the one factored', error)
      call chol%destroy()
      call umf%destroy()
   end subroutine test_wrong_rhs_shape

   subroutine test_factorize_invalid(error)
      type(error_type), allocatable, intent(out) :: error
      type(umfpack_solver_type) :: umf
      type(coo_type) :: coo
      type(csr_type) :: a
      type(error_type), allocatable :: err

      call coo%init(2, 3, error)
      if (allocated(error)) return
      call coo%add(1, 1, 1.0_wp, error)
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      call umf%factorize(a, err)
      call expect_error(err, stat_invalid_input, 'is 2 x 3, not square', error)
   end subroutine test_factorize_invalid

   ! ------------------------------------------------------------------ rcond

   !> rcond against the exact 1/(||A||_1 ||A^-1||_1) from a dense inverse and
   !> against LAPACK dgecon. The estimate of ||A^-1||_1 is a lower bound, so
   !> exact <= estimate (up to rounding, 1e-10 relative); Higham's estimator is
   !> usually exact or within a factor 3, so estimate <= 3 exact is required,
   !> and the same factor 3 either way relative to dgecon (another estimate).
   subroutine test_rcond_vs_dense(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf
      type(csr_type) :: a

      call convection_diffusion(6, 40.0_wp, a, error)
      if (allocated(error)) return
      call check_rcond(umf, a, error)
      if (allocated(error)) return
      call laplace(2, 7, a, error)
      if (allocated(error)) return
      call check_rcond(chol, a, error)
      if (allocated(error)) return
      call check_rcond(umf, a, error)
      if (allocated(error)) return
      call elasticity(2, 4, .true., a, error)
      if (allocated(error)) return
      call check_rcond(chol, a, error)
      if (allocated(error)) return
      call check_rcond(umf, a, error)
   end subroutine test_rcond_vs_dense

   subroutine check_rcond(solver, a, error)
      class(linear_solver_type), intent(inout) :: solver
      type(csr_type), intent(in) :: a
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: ad(:, :), work(:)
      integer, allocatable :: ipiv(:), iwork(:)
      real(wp) :: exact, est, lapack, anorm
      integer :: n, info

      n = a%nrows
      allocate (ad, source=to_dense(a))
      exact = 1.0_wp/cond1(ad)
      allocate (ipiv(n), work(4*n), iwork(n))
      anorm = dlange('1', n, n, ad, n, work)
      call dgetrf(n, n, ad, n, ipiv, info)
      if (info == 0) call dgecon('1', n, ad, n, anorm, lapack, work, iwork, info)
      call check(error, info, 0, 'dense reference rcond')
      if (allocated(error)) return

      call solver%factorize(a, error)
      if (allocated(error)) return
      call solver%rcond(a, est, error)
      if (allocated(error)) return
      call check(error, est >= exact*(1.0_wp - 1.0e-10_wp) .and. est <= 3.0_wp*exact, &
         'rcond estimate within [1, 3] times the exact value')
      if (allocated(error)) return
      call check(error, est <= 3.0_wp*lapack .and. lapack <= 3.0_wp*est, 'rcond within a factor 3 of dgecon')
      call solver%destroy()
   end subroutine check_rcond

   !> For a diagonal matrix the estimator is exact: min|d|/max|d|.
   subroutine test_rcond_diagonal(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf
      type(csr_type) :: a
      real(wp) :: value

      call diagonal([2.0_wp, 10.0_wp, 1.0e-3_wp, 5.0_wp, 7.0_wp], a, error)
      if (allocated(error)) return
      call chol%factorize(a, error)
      if (allocated(error)) return
      call chol%rcond(a, value, error)
      if (allocated(error)) return
      ! a few roundings in 1/(10 * 1000)
      call check(error, value, 1.0e-4_wp, 1.0e-14_wp, 'CHOLMOD diagonal rcond exact', rel=.true.)
      if (allocated(error)) return
      call diagonal([-2.0_wp, 10.0_wp, 1.0e-3_wp, -5.0_wp, 7.0_wp], a, error)
      if (allocated(error)) return
      call umf%factorize(a, error)
      if (allocated(error)) return
      call umf%rcond(a, value, error)
      if (allocated(error)) return
      call check(error, value, 1.0e-4_wp, 1.0e-14_wp, 'UMFPACK diagonal rcond exact', rel=.true.)
      if (allocated(error)) return
      call check(error, umf%rcond_estimate, value, 0.0_wp, 'factorize made the same estimate')
      if (allocated(error)) return
      umf%rcond_tol = 0.0_wp
      call umf%factorize(a, error)
      if (allocated(error)) return
      call check(error, umf%rcond_estimate, -1.0_wp, 0.0_wp, 'rcond_tol = 0 skips the estimate')
      call chol%destroy()
      call umf%destroy()
   end subroutine test_rcond_diagonal

   ! ------------------------------------------------------------------ lifecycle

   !> destroy is harmless on a fresh object and when repeated; a solver object
   !> can factor another matrix (of another order) after destroy or directly.
   subroutine test_destroy_refactorize(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf

      call chol%destroy()
      call umf%destroy()
      call check_refactorize(chol, error)
      if (allocated(error)) return
      call check_refactorize(umf, error)
   end subroutine test_destroy_refactorize

   subroutine check_refactorize(solver, error)
      class(linear_solver_type), intent(inout) :: solver
      type(error_type), allocatable, intent(out) :: error
      type(csr_type) :: a
      type(error_type), allocatable :: err
      real(wp) :: x3(3), x2(2)

      call diagonal([2.0_wp, 4.0_wp, 8.0_wp], a, error)
      if (allocated(error)) return
      call solver%factorize(a, error)
      if (allocated(error)) return
      call diagonal([4.0_wp, 5.0_wp], a, error)
      if (allocated(error)) return
      call solver%factorize(a, error)
      if (allocated(error)) return
      call solver%solve([2.0_wp, 10.0_wp], x2, error)
      if (allocated(error)) return
      ! exact: divisions of small integers
      call check(error, same(x2, [0.5_wp, 2.0_wp]) .and. solver%n == 2, 'second factor in use')
      if (allocated(error)) return
      call solver%destroy()
      call solver%destroy()
      call check(error, .not. solver%factorized .and. solver%n == 0, 'destroyed twice, state cleared')
      if (allocated(error)) return
      call solver%solve([1.0_wp, 1.0_wp, 1.0_wp], x3, err)
      call expect_error(err, stat_invalid_input, 'no factor', error)
   end subroutine check_refactorize

   !> A 0 x 0 system factors and solves trivially with either back end.
   subroutine test_zero_size_solve(error)
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: umf

      call check_zero(chol, error)
      if (allocated(error)) return
      call check_zero(umf, error)
   end subroutine test_zero_size_solve

   subroutine check_zero(solver, error)
      class(linear_solver_type), intent(inout) :: solver
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      type(csr_type) :: a
      real(wp) :: b(0), x(0), b2(0, 2), x2(0, 2), value

      call coo%init(0, 0, error)
      if (allocated(error)) return
      call coo%to_csr(a, error)
      if (allocated(error)) return
      call solver%factorize(a, error)
      if (allocated(error)) return
      call solver%solve(b, x, error)
      if (allocated(error)) return
      call solver%solve(b2, x2, error)
      if (allocated(error)) return
      call solver%rcond(a, value, error)
      if (allocated(error)) return
      call check(error, value, 1.0_wp, 0.0_wp, 'rcond of the empty matrix is 1, as in LAPACK')
      call solver%destroy()
   end subroutine check_zero

   ! ------------------------------------------------------------------ helpers

   subroutine add(coo, i, j, v, error)
      type(coo_type), intent(inout) :: coo
      integer, intent(in) :: i, j
      real(wp), intent(in) :: v
      type(error_type), allocatable, intent(out) :: error
      call coo%add(i, j, v, error)
   end subroutine add

   !> `err` must be allocated with status `stat` and contain `text`; it is
   !> consumed, and `error` reports a mismatch.
   subroutine expect_error(err, stat, text, error)
      type(error_type), allocatable, intent(inout) :: err
      integer, intent(in) :: stat
      character(len=*), intent(in) :: text
      type(error_type), allocatable, intent(out) :: error

      if (.not. allocated(err)) then
         call test_failed(error, 'expected an error containing "'//text//'"')
         return
      end if
      if (err%stat /= stat .or. index(err%message, text) == 0) then
         call test_failed(error, 'unexpected error: "'//err%message//'", expected "'//text//'"')
      end if
      deallocate (err)
   end subroutine expect_error

   function to_dense(a) result(d)
      type(csr_type), intent(in) :: a
      real(wp), allocatable :: d(:, :)
      integer :: i
      integer(i8) :: k
      allocate (d(a%nrows, a%ncols))
      d = 0.0_wp
      do i = 1, a%nrows
         do k = a%rowptr(i), a%rowptr(i + 1) - 1
            d(i, a%col(k)) = a%val(k)
         end do
      end do
   end function to_dense

   !> Exact cond_1 from the dense inverse (LU with partial pivoting).
   function cond1(ad) result(c)
      real(wp), intent(in) :: ad(:, :)
      real(wp) :: c
      real(wp), allocatable :: a(:, :), lu(:, :), inv(:, :), work(:)
      integer, allocatable :: ipiv(:)
      integer :: n, i, info

      n = size(ad, 1)
      allocate (a, source=ad)
      allocate (lu, source=ad)
      allocate (inv(n, n), ipiv(n), work(n))
      inv = 0.0_wp
      do i = 1, n
         inv(i, i) = 1.0_wp
      end do
      call dgesv(n, n, lu, n, ipiv, inv, n, info)
      c = huge(1.0_wp)
      if (info == 0) c = dlange('1', n, n, a, n, work)*dlange('1', n, n, inv, n, work)
   end function cond1

   !> Exactly equal values (and no NaN), without a real `==`.
   pure logical function same(x, y)
      real(wp), intent(in) :: x(:), y(:)
      same = size(x) == size(y)
      if (same) same = all(abs(x - y) <= 0.0_wp)
   end function same

   pure function relerr(x, xt) result(r)
      real(wp), intent(in) :: x(:), xt(:)
      real(wp) :: r
      r = sum(abs(x - xt))/sum(abs(xt))
   end function relerr

   !> A smooth-ish, sign-changing solution vector, different per `seed`.
   pure function manufactured(n, seed) result(x)
      integer, intent(in) :: n, seed
      real(wp) :: x(n)
      integer :: i
      x = [(sin(0.37_wp*real(i*seed, wp)) + 0.5_wp*real(seed, wp), i=1, n)]
   end function manufactured

   subroutine diagonal(d, a, error)
      real(wp), intent(in) :: d(:)
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      integer :: i
      call coo%init(size(d), size(d), error)
      if (allocated(error)) return
      do i = 1, size(d)
         call coo%add(i, i, d(i), error)
         if (allocated(error)) return
      end do
      call coo%to_csr(a, error)
   end subroutine diagonal

   !> Dirichlet-eliminated Laplacian on m^dim interior points (5/7-point).
   subroutine laplace(dim, m, a, error)
      integer, intent(in) :: dim, m
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      integer :: p, d, q, stride, ip

      call coo%init(m**dim, m**dim, error)
      if (allocated(error)) return
      do p = 1, m**dim
         call coo%add(p, p, 2.0_wp*dim, error)
         if (allocated(error)) return
         do d = 1, dim
            stride = m**(d - 1)
            ip = mod((p - 1)/stride, m) ! coordinate along d, 0-based
            do q = -1, 1, 2
               if (ip + q < 0 .or. ip + q >= m) cycle
               call coo%add(p, p + q*stride, -1.0_wp, error)
               if (allocated(error)) return
            end do
         end do
      end do
      call coo%to_csr(a, error)
   end subroutine laplace

   !> -Laplace(u) + beta . grad(u) on m x m interior points, h = 1/(m+1),
   !> beta = (beta1, beta1/2), first-order upwind, scaled by h^2.
   subroutine convection_diffusion(m, beta1, a, error)
      integer, intent(in) :: m
      real(wp), intent(in) :: beta1
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      type(coo_type) :: coo
      real(wp) :: h, bx, by
      integer :: i, j, p

      h = 1.0_wp/real(m + 1, wp)
      bx = h*beta1
      by = 0.5_wp*h*beta1
      call coo%init(m*m, m*m, error)
      if (allocated(error)) return
      do j = 1, m
         do i = 1, m
            p = i + m*(j - 1)
            call coo%add(p, p, 4.0_wp + bx + by, error)
            if (allocated(error)) return
            if (i > 1) call coo%add(p, p - 1, -1.0_wp - bx, error)
            if (allocated(error)) return
            if (i < m) call coo%add(p, p + 1, -1.0_wp, error)
            if (allocated(error)) return
            if (j > 1) call coo%add(p, p - m, -1.0_wp - by, error)
            if (allocated(error)) return
            if (j < m) call coo%add(p, p + m, -1.0_wp, error)
            if (allocated(error)) return
         end do
      end do
      call coo%to_csr(a, error)
   end subroutine convection_diffusion

   !> Q1 linear elasticity (E = 1, nu = 0.3; plane strain in 2D) on the unit
   !> square/cube with `nel` elements per side; with `clamp`, the face x = 0 is
   !> fixed and its dofs eliminated. Dofs are node-major (dim per node).
   !> `coords` returns the coordinates of the nodes that carry dofs.
   subroutine elasticity(dim, nel, clamp, a, error, coords)
      integer, intent(in) :: dim, nel
      logical, intent(in) :: clamp
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable, intent(out), optional :: coords(:, :)
      real(wp), parameter :: young = 1.0_wp, nu = 0.3_wp
      type(coo_type) :: coo
      real(wp), allocatable :: ke(:, :)
      integer, allocatable :: first(:), dofs(:), keep(:)
      integer :: nside, nnode, node, e, c, d, ndof, m, idx(3)
      real(wp) :: h, lambda, mu

      nside = nel + 1
      nnode = nside**dim
      h = 1.0_wp/real(nel, wp)
      lambda = young*nu/((1.0_wp + nu)*(1.0_wp - 2.0_wp*nu))
      mu = young/(2.0_wp*(1.0_wp + nu))
      call q1_stiffness(dim, h, lambda, mu, ke)

      ! first(node): first dof of a node, 0 when clamped
      allocate (first(nnode))
      ndof = 0
      if (present(coords)) allocate (coords(dim, 0))
      do node = 1, nnode
         idx(1:dim) = grid_index(node - 1, nside, dim)
         first(node) = 0
         if (clamp .and. idx(1) == 0) cycle
         first(node) = ndof + 1
         ndof = ndof + dim
         if (present(coords)) coords = reshape([coords, h*real(idx(1:dim), wp)], [dim, size(coords, 2) + 1])
      end do

      call coo%init(ndof, ndof, error, capacity=int(nel, i8)**dim*size(ke, kind=i8))
      if (allocated(error)) return
      allocate (dofs(size(ke, 1)), keep(size(ke, 1)))
      do e = 0, nel**dim - 1
         idx(1:dim) = grid_index(e, nel, dim)
         m = 0
         do c = 0, 2**dim - 1
            node = 1 + node_number(idx(1:dim) + corner(c, dim), nside)
            do d = 1, dim
               if (first(node) == 0) cycle
               m = m + 1
               keep(m) = dim*c + d
               dofs(m) = first(node) + d - 1
            end do
         end do
         call coo%add(dofs(1:m), ke(keep(1:m), keep(1:m)), error)
         if (allocated(error)) return
      end do
      call coo%to_csr(a, error)
   end subroutine elasticity

   !> Element stiffness of the Q1 cube of side h, dofs ordered (corner, dir),
   !> corner c with bit d-1 set at the upper face in direction d. Entry
   !> ((a,i),(b,j)) = int lambda N_a,i N_b,j + mu N_a,j N_b,i + mu delta_ij
   !> grad N_a . grad N_b, exact with 2^dim Gauss points on a cube.
   subroutine q1_stiffness(dim, h, lambda, mu, ke)
      integer, intent(in) :: dim
      real(wp), intent(in) :: h, lambda, mu
      real(wp), allocatable, intent(out) :: ke(:, :)
      real(wp) :: xi(dim), g(dim, 0:2**dim - 1), w
      integer :: q, c, b, i, j, d, nc

      nc = 2**dim
      allocate (ke(dim*nc, dim*nc))
      ke = 0.0_wp
      w = (h/2.0_wp)**dim ! weights 1, |J| = (h/2)^dim
      do q = 0, nc - 1
         xi = real(2*corner(q, dim) - 1, wp)/sqrt(3.0_wp)
         do c = 0, nc - 1
            do d = 1, dim
               g(d, c) = shape_derivative(real(2*corner(c, dim) - 1, wp), xi, d)*2.0_wp/h
            end do
         end do
         do b = 0, nc - 1
            do j = 1, dim
               do c = 0, nc - 1
                  do i = 1, dim
                     ke(dim*c + i, dim*b + j) = ke(dim*c + i, dim*b + j) + w*(lambda*g(i, c)*g(j, b) &
                        + mu*g(j, c)*g(i, b) + merge(mu*dot_product(g(:, c), g(:, b)), 0.0_wp, i == j))
                  end do
               end do
            end do
         end do
      end do
   end subroutine q1_stiffness

   !> d/dxi_d of prod_e (1 + s_e xi_e)/2.
   pure function shape_derivative(s, xi, d) result(v)
      real(wp), intent(in) :: s(:), xi(:)
      integer, intent(in) :: d
      real(wp) :: v
      integer :: e
      v = 1.0_wp
      do e = 1, size(xi)
         if (e == d) then
            v = v*s(e)/2.0_wp
         else
            v = v*(1.0_wp + s(e)*xi(e))/2.0_wp
         end if
      end do
   end function shape_derivative

   !> Bits of corner number c: offsets 0/1 per direction.
   pure function corner(c, dim) result(off)
      integer, intent(in) :: c, dim
      integer :: off(dim), d
      off = [(ibits(c, d - 1, 1), d=1, dim)]
   end function corner

   !> 0-based lexicographic index -> 0-based grid coordinates (n per side).
   pure function grid_index(k, n, dim) result(idx)
      integer, intent(in) :: k, n, dim
      integer :: idx(dim), d
      idx = [(mod(k/n**(d - 1), n), d=1, dim)]
   end function grid_index

   pure integer function node_number(idx, n)
      integer, intent(in) :: idx(:), n
      integer :: d
      node_number = 0
      do d = size(idx), 1, -1
         node_number = node_number*n + idx(d)
      end do
   end function node_number

   !> Factorize and solve a 3D elasticity system with OpenBLAS set to 2 threads
   !> and to 1: the solutions must agree bit for bit (the solvers run their
   !> BLAS in one thread). Without OpenBLAS there is nothing to vary: the test
   !> then only checks that the control reports 0.
   subroutine test_blas_threads_bits(error)
      use sprc_fem_linear_solver, only: blas_threads, set_blas_threads
      type(error_type), allocatable, intent(out) :: error
      type(cholmod_solver_type) :: chol
      type(umfpack_solver_type) :: lu
      type(csr_type) :: a
      real(wp), allocatable :: b(:), x1(:), x2(:), y1(:), y2(:)
      integer :: saved

      saved = blas_threads()
      if (saved == 0) return
      call elasticity(3, 12, .true., a, error)
      if (allocated(error)) return
      allocate (b(a%nrows), x1(a%nrows), x2(a%nrows), y1(a%nrows), y2(a%nrows))
      b = 1.0_wp
      call set_blas_threads(2)
      call solve_both(x1, y1, error)
      if (allocated(error)) return
      call check(error, blas_threads(), 2, 'the solvers restore the caller''s thread count')
      if (allocated(error)) return
      call set_blas_threads(1)
      call solve_both(x2, y2, error)
      call set_blas_threads(saved)
      if (allocated(error)) return
      call check(error, all(x1 == x2) .and. all(y1 == y2), 'identical bits with 1 and 2 BLAS threads')
   contains
      subroutine solve_both(x, y, error)
         real(wp), intent(out) :: x(:), y(:)
         type(error_type), allocatable, intent(out) :: error
         call chol%factorize(a, error)
         if (allocated(error)) return
         call chol%solve(b, x, error)
         if (allocated(error)) return
         call lu%factorize(a, error)
         if (allocated(error)) return
         call lu%solve(b, y, error)
      end subroutine solve_both
   end subroutine test_blas_threads_bits

end module sprc_test_sparse
