!> Benchmark of the sparse direct solve: `bench_sparse 2d|3d N` assembles Q1
!> linear elasticity (E = 1, nu = 0.3, plane strain in 2D) on a grid of N^dim
!> nodes over the unit square/cube with the face x = 0 clamped, factorizes it
!> with CHOLMOD, solves for a uniform body force, and prints one table row.
!> `bench_sparse header` prints the column heads. Peak memory is the process
!> high-water mark (VmHWM), so run each size in its own process.
!>
!> Columns: dim, unknowns, nnz(A) (both triangles), nnz(L) (CHOLMOD, without
!> supernodal padding), wall times of assembly (COO -> CSR included),
!> factorization (analysis included, singularity check excluded), one solve,
!> and the condition estimate (= the singularity check `factorize` makes by
!> default); VmHWM; CHOLMOD's own peak; the reciprocal condition estimate;
!> the normwise backward error |b - A x|/(|A| |x| + |b|) in the inf-norm.
program bench_sparse
   use, intrinsic :: iso_fortran_env, only: error_unit, output_unit
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_timer, only: wall_time
   use sprc_fem_sparse, only: coo_type, csr_type
   use sprc_fem_cholmod, only: cholmod_solver_type
   implicit none

   character(len=*), parameter :: head_fmt = '(a3,1x,a9,1x,a11,1x,a12,4(1x,a11),2(1x,a10),1x,a9,1x,a9)'
   character(len=*), parameter :: row_fmt = '(i3,1x,i9,1x,i11,1x,i12,4(1x,f11.3),2(1x,f10.1),1x,es9.2,1x,es9.2)'
   type(error_type), allocatable :: error
   type(csr_type) :: a
   type(cholmod_solver_type) :: solver
   real(wp), allocatable :: b(:), x(:), r(:)
   real(wp) :: t0, t_asm, t_fac, t_sol, t_rc, rc, anorm
   character(len=16) :: arg
   integer :: dim, n

   call get_command_argument(1, arg)
   if (arg == 'header') then
      write (output_unit, head_fmt) 'dim', 'unknowns', 'nnz(A)', 'nnz(L)', 'assemble[s]', 'factor[s]', &
         'solve[s]', 'rcond[s]', 'VmHWM[MiB]', 'chol[MiB]', 'rcond', 'backerr'
      stop
   end if
   select case (arg)
   case ('2d'); dim = 2
   case ('3d'); dim = 3
   case default
      write (error_unit, '(a)') 'usage: bench_sparse header | bench_sparse 2d|3d N   (N nodes per side)'
      error stop 2
   end select
   call get_command_argument(2, arg)
   read (arg, *) n

   t0 = wall_time()
   call elasticity(dim, n - 1, a, error)
   call check_error()
   t_asm = wall_time() - t0
   allocate (b(a%nrows), x(a%nrows), r(a%nrows))
   ! uniform body force (0, -1[, 0]) lumped to the nodes
   b = 0.0_wp
   b(2::dim) = -(1.0_wp/real(n - 1, wp))**dim

   ! the singularity check (a condition estimate) is timed on its own
   solver%rcond_tol = 0.0_wp
   t0 = wall_time()
   call solver%factorize(a, error)
   call check_error()
   t_fac = wall_time() - t0
   t0 = wall_time()
   call solver%solve(b, x, error)
   call check_error()
   t_sol = wall_time() - t0
   t0 = wall_time()
   call solver%rcond(a, rc, error)
   call check_error()
   t_rc = wall_time() - t0

   call a%matvec(x, r, error)
   call check_error()
   anorm = a%norm1(error)
   call check_error()
   ! normwise backward error in the infinity norm (= 1-norm, A symmetric)
   r = r - b
   write (output_unit, row_fmt) dim, a%nrows, a%nnz(), solver%factor_nnz, t_asm, t_fac, t_sol, t_rc, &
      vm_hwm_mib(), real(solver%peak_bytes, wp)/2.0_wp**20, rc, &
      maxval(abs(r))/(anorm*maxval(abs(x)) + maxval(abs(b)))
   call solver%destroy()

contains

   subroutine check_error()
      if (.not. allocated(error)) return
      write (error_unit, '(a)') 'bench_sparse: '//error%message
      error stop 1
   end subroutine check_error

   !> Peak resident set size of this process [MiB], -1 if unknown.
   function vm_hwm_mib() result(mib)
      real(wp) :: mib
      character(len=256) :: line
      integer :: unit, stat
      integer(i8) :: kib

      mib = -1.0_wp
      open (newunit=unit, file='/proc/self/status', action='read', status='old', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (line(1:6) == 'VmHWM:') then
            read (line(7:), *, iostat=stat) kib
            if (stat == 0) mib = real(kib, wp)/1024.0_wp
            exit
         end if
      end do
      close (unit)
   end function vm_hwm_mib

   !> Q1 elasticity on nel^dim elements of the unit square/cube, face x = 0
   !> clamped and eliminated, dofs node-major. Element stiffness as in
   !> test/unit/fem_sparse.f90 (the FE layer's element will replace both).
   subroutine elasticity(dim, nel, a, error)
      integer, intent(in) :: dim, nel
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      real(wp), parameter :: young = 1.0_wp, nu = 0.3_wp
      type(coo_type) :: coo
      real(wp), allocatable :: ke(:, :)
      integer, allocatable :: first(:), dofs(:), keep(:)
      integer :: nside, node, e, c, d, ndof, m, idx(3)
      real(wp) :: h, lambda, mu

      nside = nel + 1
      h = 1.0_wp/real(nel, wp)
      lambda = young*nu/((1.0_wp + nu)*(1.0_wp - 2.0_wp*nu))
      mu = young/(2.0_wp*(1.0_wp + nu))
      call q1_stiffness(dim, h, lambda, mu, ke)
      allocate (first(nside**dim))
      ndof = 0
      do node = 1, nside**dim
         idx(1:dim) = grid_index(node - 1, nside, dim)
         first(node) = 0
         if (idx(1) == 0) cycle
         first(node) = ndof + 1
         ndof = ndof + dim
      end do
      call coo%init(ndof, ndof, error, capacity=int(nel, i8)**dim*size(ke, kind=i8))
      if (allocated(error)) return
      allocate (dofs(size(ke, 1)), keep(size(ke, 1)))
      do e = 0, nel**dim - 1
         idx(1:dim) = grid_index(e, nel, dim)
         m = 0
         do c = 0, 2**dim - 1
            node = 1 + node_number(idx(1:dim) + corner(c, dim), nside)
            if (first(node) == 0) cycle
            do d = 1, dim
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

   subroutine q1_stiffness(dim, h, lambda, mu, ke)
      integer, intent(in) :: dim
      real(wp), intent(in) :: h, lambda, mu
      real(wp), allocatable, intent(out) :: ke(:, :)
      real(wp) :: xi(dim), g(dim, 0:2**dim - 1), w
      integer :: q, c, b, i, j, d, nc

      nc = 2**dim
      allocate (ke(dim*nc, dim*nc))
      ke = 0.0_wp
      w = (h/2.0_wp)**dim
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

   pure function corner(c, dim) result(off)
      integer, intent(in) :: c, dim
      integer :: off(dim), d
      off = [(ibits(c, d - 1, 1), d=1, dim)]
   end function corner

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

end program bench_sparse
