!> Benchmark of recovery + ZZ estimate on a caller's mesh (recover_on_mesh), per phase, with
!> 1 and 2 OpenMP threads: a quarter annulus 5 <= r <= 20 of 512 x 512 = 262,144 quad4
!> (plane strain) and a quarter of a thick cylinder of 48 x 48 x 46 = 105,984 hex8, each
!> with 2^dim Gauss points per element and the Lame stresses (internal pressure 1) plus a
!> smooth perturbation of 1 % as FE stresses. SPR without facets (as an estimator that knows
!> no boundary); SPR-C with facets: pressure on the inner surface, symmetry on the planes of
!> the quarter (and on the z planes of the hex mesh), free outer surface. Times are medians
!> of `nrep` runs, in milliseconds; 'total' is recovery + estimate (all phases), wall time;
!> 'cpu' the process's CPU time of the call (all threads; at 1 thread it is the work
!> itself, little changed by other jobs on a shared machine, unlike the wall times);
!> 'cpu-set' the same without the set-up (res%cpu_setup: input checks and topology), the
!> scope of MFEM's ZienkiewiczZhuEstimator::GetLocalErrors in tools/bench-mfem-zz.py, whose
!> mesh topology and spaces are built before its clock starts (that script's notes). The
!> 1- and 2-thread runs alternate, and the speedup is the median of the paired ratios, so
!> that a load that comes and goes on a shared machine hits both alike.
!>
!> Each run's nodal stresses, element errors and global error are reduced to a fingerprint of
!> their bits (`fingerprint`, printed in hexadecimal): every run of one mesh and method, at any
!> thread count, must give the same one (the library's determinism; 'bits' says whether they
!> did), and a change meant to keep the bits keeps it.
!>
!> The caller's reference coordinates of the points are passed (gauss_xi), as an FE code has
!> them; the word `newton` derives them instead (Newton's method per point, the 'points' phase).
!>
!> Lattices: the unit square of N x N quad4 (N = 64, 128, 256, 512) and the unit cube of
!> N x N x N hex8 (N = 32, 40, 64), axis-aligned (every coordinate a dyadic fraction when N is
!> a power of two, ties in every coordinate), and the 256 x 256 square and 32^3 cube rotated
!> by 0.3 rad about z; a smooth field plus 1 % as FE stresses; SPR-C with free facets on the
!> whole boundary. They are what a power-of-two grid gives, where a hash of coordinate bits
!> or a search that degenerates on ties shows.
!>
!> Run: fpm run --profile release --example bench_mesh_recovery [-- NREP [MESH|all [spr|sprc|all
!> [newton]]]] (the optional words restrict the runs to the meshes whose label holds MESH, e.g.
!> annulus, cylinder, square, square256, cube, rotated, and to one method).
program bench_mesh_recovery
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_material, only: plane_strain, solid
   use sprc_recovery_caller_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_method_spr, mesh_method_sprc, &
      & facet_pressure, facet_symmetry, facet_free, elem_quad4, elem_hex8
   !$ use omp_lib, only: omp_set_num_threads, omp_get_max_threads
   implicit none

   type :: mesh_type
      integer :: dim = 0, etype = 0, analysis = 0
      real(wp), allocatable :: x(:, :), gp(:, :, :), gw(:, :), gs(:, :, :), gxi(:, :, :)
      integer, allocatable :: conn(:, :), fn(:, :), fk(:)
      real(wp), allocatable :: ft(:, :)
   end type mesh_type

   real(wp), parameter :: pi = acos(-1.0_wp), r_in = 5.0_wp, r_out = 20.0_wp, young = 1000.0_wp, nu = 0.3_wp
   type(mesh_type) :: quad, hex
   integer :: nrep, nmax
   logical :: newton
   character(len=16) :: arg, only_mesh, only_method

   nrep = 3
   only_mesh = ''
   only_method = ''
   if (command_argument_count() > 0) then
      call get_command_argument(1, arg)
      read (arg, *) nrep
   end if
   if (command_argument_count() > 1) call get_command_argument(2, only_mesh)
   if (command_argument_count() > 2) call get_command_argument(3, only_method)
   newton = .false.
   if (command_argument_count() > 3) then
      call get_command_argument(4, arg)
      newton = trim(arg) == 'newton'
   end if
   nmax = 1
   !$ nmax = omp_get_max_threads()
   if (selected('quad4 annulus')) call annulus(512, 512, 0, quad)
   if (selected('hex8 cylinder')) call annulus(48, 48, 46, hex)
   write (*, '(a,i0,a,i0,a)') 'bench_mesh_recovery: medians of ', nrep, ' runs, milliseconds; ', nmax, &
      & ' threads available; reference coordinates '//trim(merge('by Newton  ', 'given (gxi)', newton))
   write (*, '(a)') 'scope: cpu = the whole recover_on_mesh call from raw arrays (input checks; topology: node -> '// &
      & 'element lists, duplicate node and element checks, facet points; points; patches; nodal; estimate)'
   write (*, '(a)') '       cpu-set = cpu without checks and topology: the scope of MFEM''s GetLocalErrors, whose '// &
      & 'mesh and spaces are built before its clock starts'
   write (*, '(a)') 'mesh               elements  method  threads   check  topology  points  patches  nodal  '// &
      & 'estimate   total    cpu cpu-set'
   call run(quad, 'quad4 annulus', mesh_method_spr)
   call run(quad, 'quad4 annulus', mesh_method_sprc)
   call run(hex, 'hex8 cylinder', mesh_method_spr)
   call run(hex, 'hex8 cylinder', mesh_method_sprc)
   call run_lattice(2, 64, 0.0_wp, 'square64')
   call run_lattice(2, 128, 0.0_wp, 'square128')
   call run_lattice(2, 256, 0.0_wp, 'square256')
   call run_lattice(2, 512, 0.0_wp, 'square512')
   call run_lattice(2, 256, 0.3_wp, 'rotated256')
   call run_lattice(3, 32, 0.0_wp, 'cube32')
   call run_lattice(3, 40, 0.0_wp, 'cube40')
   call run_lattice(3, 64, 0.0_wp, 'cube64')
   call run_lattice(3, 32, 0.3_wp, 'rotated32^3')

contains

   !> Whether the command line selects the mesh `label`.
   logical function selected(label)
      character(len=*), intent(in) :: label
      selected = len_trim(only_mesh) == 0 .or. trim(only_mesh) == 'all' .or. index(label, trim(only_mesh)) > 0
   end function selected

   !> Both methods on an n^dim lattice of the unit square / cube, rotated by `angle` about z.
   subroutine run_lattice(d, n, angle, label)
      integer, intent(in) :: d, n
      real(wp), intent(in) :: angle
      character(len=*), intent(in) :: label
      type(mesh_type) :: m
      character(len=17) :: full

      full = trim(merge('quad4', 'hex8 ', d == 2))//' '//label
      if (.not. selected(full)) return
      call lattice_mesh(d, n, angle, m)
      call run(m, full, mesh_method_spr)
      call run(m, full, mesh_method_sprc)
   end subroutine run_lattice

   !> Timings of one mesh and method with 1 and 2 threads.
   subroutine run(m, label, method)
      type(mesh_type), intent(in) :: m
      character(len=*), intent(in) :: label
      integer, intent(in) :: method
      type(mesh_recovery_type) :: res
      type(error_type), allocatable :: error
      real(wp), allocatable :: t(:, :, :)
      real(wp) :: med(9), c0, c1
      integer :: nt, k, i, ntmax
      integer(i8) :: bits, bits1
      logical :: same

      if (.not. selected(label)) return
      if (len_trim(only_method) > 0 .and. trim(only_method) /= 'all' .and. trim(only_method) /= trim(merge('spr ', &
         & 'sprc', method == mesh_method_spr))) return
      ntmax = min(2, nmax)
      allocate (t(9, nrep, ntmax))
      ! 1 and 2 threads in turn, so that a change of the machine's load hits both alike.
      do k = 1, nrep
         do nt = 1, ntmax
            !$ call omp_set_num_threads(nt)
            call release(res)
            call cpu_time(c0)
            call recover(m, method, res, error)
            call cpu_time(c1)
            if (allocated(error)) then
               write (*, '(a)') 'bench_mesh_recovery: '//error%message
               stop 1
            end if
            t(:, k, nt) = 1.0e3_wp*[res%t_check, res%t_topology, res%t_points, res%t_patches, res%t_nodal, &
               & res%t_estimate, 0.0_wp]
            t(7, k, nt) = sum(t(1:6, k, nt))
            t(8, k, nt) = 1.0e3_wp*(c1 - c0)
            t(9, k, nt) = t(8, k, nt) - 1.0e3_wp*res%cpu_setup
            bits = fingerprint(res)
            if (k == 1 .and. nt == 1) then
               bits1 = bits
               same = .true.
            end if
            same = same .and. bits == bits1
         end do
      end do
      !$ call omp_set_num_threads(nmax)
      do nt = 1, ntmax
         do i = 1, 9
            med(i) = median(t(i, :, nt))
         end do
         write (*, '(a17,i10,2x,a6,i9,6f9.1,f9.1,f7.0,f8.0)') label, size(m%conn, 2), merge('spr   ', 'sprc  ', &
            & method == mesh_method_spr), nt, med
      end do
      if (ntmax == 2) write (*, '(a,f6.2,a,f6.2)') '   speedup on 2 threads (median of the paired runs): total', &
         & median(t(7, :, 1)/t(7, :, 2)), ', patches', median(t(4, :, 1)/t(4, :, 2))
      write (*, '(a,es10.3,a,es10.3,a,z16.16,a,a)') '   global error ', res%err, ', eta ', res%eta, &
         & ', fingerprint ', bits1, ', bits ', trim(merge('identical in every run', 'DIFFER between runs   ', same))
   end subroutine run

   !> The bits of the nodal stresses, element errors and global error, folded (xor-shift).
   integer(i8) function fingerprint(res) result(h)
      type(mesh_recovery_type), intent(in) :: res
      h = fold(fold(fold(88172645463325252_i8, reshape(res%nodal, [size(res%nodal)])), res%elem_err), [res%err])
   end function fingerprint

   pure integer(i8) function fold(h0, v) result(h)
      integer(i8), intent(in) :: h0
      real(wp), intent(in) :: v(:)
      integer :: i
      h = h0
      do i = 1, size(v)
         h = ieor(h, transfer(v(i), h))
         h = ieor(h, shiftl(h, 13))
         h = ieor(h, shiftr(h, 7))
         h = ieor(h, shiftl(h, 17))
      end do
   end function fold

   !> Frees the previous run's result before the clock starts, as tools/bench-mfem-zz.py does
   !> (its previous estimator is destroyed before it times the next): otherwise the cpu column
   !> of a run held the deallocation of the last run's patch records.
   subroutine release(res)
      type(mesh_recovery_type), intent(out) :: res
      res%n_patches = 0
   end subroutine release

   !> One recovery: facets for SPR-C only, the reference coordinates unless `newton`.
   subroutine recover(m, method, res, error)
      type(mesh_type), intent(in) :: m
      integer, intent(in) :: method
      type(mesh_recovery_type), intent(out) :: res
      type(error_type), allocatable, intent(out) :: error

      if (method == mesh_method_spr .and. newton) then
         call recover_on_mesh(m%dim, m%analysis, m%x, m%etype, m%conn, m%gp, m%gw, m%gs, young, nu, method, res, error)
      else if (method == mesh_method_spr) then
         call recover_on_mesh(m%dim, m%analysis, m%x, m%etype, m%conn, m%gp, m%gw, m%gs, young, nu, method, res, &
            & error, gauss_xi=m%gxi)
      else if (newton) then
         call recover_on_mesh(m%dim, m%analysis, m%x, m%etype, m%conn, m%gp, m%gw, m%gs, young, nu, method, res, &
            & error, facet_nodes=m%fn, facet_kind=m%fk, facet_traction=m%ft)
      else
         call recover_on_mesh(m%dim, m%analysis, m%x, m%etype, m%conn, m%gp, m%gw, m%gs, young, nu, method, res, &
            & error, facet_nodes=m%fn, facet_kind=m%fk, facet_traction=m%ft, gauss_xi=m%gxi)
      end if
   end subroutine recover

   real(wp) function median(v)
      real(wp), intent(in) :: v(:)
      real(wp) :: w(size(v)), s
      integer :: i, j
      w = v
      do i = 2, size(w)
         s = w(i)
         j = i - 1
         do while (j >= 1)
            if (w(j) <= s) exit
            w(j + 1) = w(j)
            j = j - 1
         end do
         w(j + 1) = s
      end do
      median = w((size(w) + 1)/2)
   end function median

   !> Quarter annulus r_in <= r <= r_out of nr x nt quad4 (nz = 0) or, extruded over
   !> 0 <= z <= 10 in nz layers, hex8; points, weights, Lame stresses and facets.
   subroutine annulus(nr, nt, nz, m)
      integer, intent(in) :: nr, nt, nz
      type(mesh_type), intent(out) :: m
      integer :: i, j, k, e, nl, nn, ne, ngp, a, g, d
      real(wp) :: r, th, z, gx(2), xi(3), shp(8), dshp(3, 8), jac(3, 3), xe(3, 8)
      integer, parameter :: corner(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, &
         & 0, 1, 1], [3, 8])

      d = merge(2, 3, nz == 0)
      m%dim = d
      m%etype = merge(elem_quad4, elem_hex8, d == 2)
      m%analysis = merge(plane_strain, solid, d == 2)
      nl = max(nz, 0) + 1
      nn = (nr + 1)*(nt + 1)*nl
      ne = nr*nt*max(nz, 1)
      ngp = 2**d
      allocate (m%x(d, nn), m%conn(2**d, ne), m%gp(d, ngp, ne), m%gw(ngp, ne), m%gs(3*(d - 1), ngp, ne))
      allocate (m%gxi(d, ngp, ne))
      do k = 0, nl - 1
         do j = 0, nt
            do i = 0, nr
               r = r_in + (r_out - r_in)*i/nr
               th = 0.5_wp*pi*j/nt
               z = 10.0_wp*k/max(nz, 1)
               m%x(1:2, lattice(nr, nt, i, j, k)) = [r*cos(th), r*sin(th)]
               if (d == 3) m%x(3, lattice(nr, nt, i, j, k)) = z
            end do
         end do
      end do
      gx = 0.5_wp + [-0.5_wp, 0.5_wp]/sqrt(3.0_wp)
      e = 0
      do k = 0, max(nz, 1) - 1
         do j = 0, nt - 1
            do i = 0, nr - 1
               e = e + 1
               do a = 1, 2**d
                  m%conn(a, e) = lattice(nr, nt, i + corner(1, a), j + corner(2, a), k + corner(3, a))
                  xe(1:d, a) = m%x(:, m%conn(a, e))
               end do
               do g = 1, ngp
                  xi = [gx(1 + mod(g - 1, 2)), gx(1 + mod((g - 1)/2, 2)), gx(1 + (g - 1)/4)]
                  call multilinear(d, xi, shp, dshp)
                  m%gp(:, g, e) = matmul(xe(1:d, 1:2**d), shp(1:2**d))
                  m%gxi(:, g, e) = xi(1:d)
                  jac(1:d, 1:d) = matmul(xe(1:d, 1:2**d), transpose(dshp(1:d, 1:2**d)))
                  m%gw(g, e) = abs(det(d, jac))/2**d
                  call lame(m%gp(:, g, e), m%gs(:, g, e))
               end do
            end do
         end do
      end do
      call facets(m, nr, nt, nz)
   end subroutine annulus

   !> The unit square (d = 2: n x n quad4, plane strain) or cube (d = 3: n^3 hex8) rotated
   !> by `angle` about z; 2^d Gauss points, a smooth field + 1 % as stresses, free facets on
   !> the whole boundary.
   subroutine lattice_mesh(d, n, angle, m)
      integer, intent(in) :: d, n
      real(wp), intent(in) :: angle
      type(mesh_type), intent(out) :: m
      integer :: i, j, k, e, nl, ne, ngp, a, g, f, nf, side, ax, b1, b2, lo(3), u(3), v(3)
      real(wp) :: p(3), xi(3), gx(2), shp(8), dshp(3, 8), jac(3, 3), xe(3, 8)
      integer, parameter :: corner(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, &
         & 0, 1, 1], [3, 8])

      m%dim = d
      m%etype = merge(elem_quad4, elem_hex8, d == 2)
      m%analysis = merge(plane_strain, solid, d == 2)
      nl = merge(1, n + 1, d == 2)
      ne = n**d
      ngp = 2**d
      allocate (m%x(d, (n + 1)**2*nl), m%conn(2**d, ne), m%gp(d, ngp, ne), m%gw(ngp, ne), m%gs(3*(d - 1), ngp, ne))
      allocate (m%gxi(d, ngp, ne))
      do k = 0, nl - 1
         do j = 0, n
            do i = 0, n
               p = [real(i, wp), real(j, wp), real(k, wp)]/n
               m%x(1:2, lattice(n, n, i, j, k)) = [cos(angle)*p(1) - sin(angle)*p(2), sin(angle)*p(1) + cos(angle)*p(2)]
               if (d == 3) m%x(3, lattice(n, n, i, j, k)) = p(3)
            end do
         end do
      end do
      gx = 0.5_wp + [-0.5_wp, 0.5_wp]/sqrt(3.0_wp)
      e = 0
      do k = 0, max(nl - 1, 1) - 1
         do j = 0, n - 1
            do i = 0, n - 1
               e = e + 1
               do a = 1, 2**d
                  m%conn(a, e) = lattice(n, n, i + corner(1, a), j + corner(2, a), k + corner(3, a))
                  xe(1:d, a) = m%x(:, m%conn(a, e))
               end do
               do g = 1, ngp
                  xi = [gx(1 + mod(g - 1, 2)), gx(1 + mod((g - 1)/2, 2)), gx(1 + (g - 1)/4)]
                  call multilinear(d, xi, shp, dshp)
                  m%gp(:, g, e) = matmul(xe(1:d, 1:2**d), shp(1:2**d))
                  m%gxi(:, g, e) = xi(1:d)
                  jac(1:d, 1:d) = matmul(xe(1:d, 1:2**d), transpose(dshp(1:d, 1:2**d)))
                  m%gw(g, e) = abs(det(d, jac))/2**d
                  call smooth(m%gp(:, g, e), m%gs(:, g, e))
               end do
            end do
         end do
      end do
      ! Free facets: the element sides on each face of the square / cube.
      nf = 2*d*n**(d - 1)
      allocate (m%fn(2**(d - 1), nf), m%fk(nf), m%ft(d, nf))
      m%fk = facet_free
      m%ft = 0.0_wp
      f = 0
      do ax = 1, d
         do side = 0, 1
            do b2 = 0, merge(0, n - 1, d == 2)
               do b1 = 0, n - 1
                  ! u, v: the in-face axes; lo: the facet's lowest lattice corner.
                  u = 0
                  v = 0
                  u(1 + mod(ax, d)) = 1
                  if (d == 3) v(1 + mod(ax + 1, d)) = 1
                  lo = b1*u + b2*v
                  lo(ax) = side*n
                  f = f + 1
                  if (d == 2) then
                     m%fn(:, f) = [lattice_node(n, lo), lattice_node(n, lo + u)]
                  else
                     m%fn(:, f) = [lattice_node(n, lo), lattice_node(n, lo + u), lattice_node(n, lo + u + v), &
                        & lattice_node(n, lo + v)]
                  end if
               end do
            end do
         end do
      end do
   end subroutine lattice_mesh

   !> Node of lattice point c of an n x n (x n) lattice mesh.
   pure integer function lattice_node(n, c)
      integer, intent(in) :: n, c(3)
      lattice_node = lattice(n, n, c(1), c(2), c(3))
   end function lattice_node

   !> A smooth stress field plus a 1 % perturbation, Voigt.
   pure subroutine smooth(x, s)
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: s(:)
      real(wp) :: noise, z
      noise = 0.01_wp*sin(30.0_wp*x(1) + 20.0_wp*x(2))
      z = 0.0_wp
      if (size(x) == 3) z = x(3)
      if (size(s) == 3) then
         s = [1.0_wp + x(1)**2 - x(2), x(1)*x(2), 0.5_wp - x(2)**2] + noise
      else
         s = [1.0_wp + x(1)**2 - x(2), x(1)*x(2) + z, 0.5_wp - z**2, x(2)*z, x(1) - z, 0.2_wp*x(1)*x(2)] + noise
      end if
   end subroutine smooth

   !> Node of lattice point (i, j, k) of an nr x nt (x nz) annulus mesh.
   pure integer function lattice(nr, nt, i, j, k)
      integer, intent(in) :: nr, nt, i, j, k
      lattice = 1 + i + (nr + 1)*(j + (nt + 1)*k)
   end function lattice

   !> Boundary facets: pressure 1 on r = r_in, symmetry on x = 0, y = 0 (and z = 0, 10),
   !> free on r = r_out.
   subroutine facets(m, nr, nt, nz)
      type(mesh_type), intent(inout) :: m
      integer, intent(in) :: nr, nt, nz
      integer :: f, i, j, k, nf, nfn

      nfn = 2**(m%dim - 1)
      if (m%dim == 2) then
         nf = 2*nt + 2*nr
      else
         nf = 2*nt*nz + 2*nr*nz + 2*nr*nt
      end if
      allocate (m%fn(nfn, nf), m%fk(nf), m%ft(m%dim, nf))
      m%ft = 0.0_wp
      f = 0
      do k = 0, max(nz, 1) - 1
         do j = 0, nt - 1
            call add_side(m, nr, nt, f, [0, j, k], [0, j + 1, k], facet_pressure)
            call add_side(m, nr, nt, f, [nr, j, k], [nr, j + 1, k], facet_free)
         end do
         do i = 0, nr - 1
            call add_side(m, nr, nt, f, [i, 0, k], [i + 1, 0, k], facet_symmetry)
            call add_side(m, nr, nt, f, [i, nt, k], [i + 1, nt, k], facet_symmetry)
         end do
      end do
      if (m%dim == 3) then
         do k = 0, nz, nz
            do j = 0, nt - 1
               do i = 0, nr - 1
                  f = f + 1
                  m%fn(:, f) = [lattice(nr, nt, i, j, k), lattice(nr, nt, i + 1, j, k), &
                     & lattice(nr, nt, i + 1, j + 1, k), lattice(nr, nt, i, j + 1, k)]
                  m%fk(f) = facet_symmetry
               end do
            end do
         end do
      end if
      where (m%fk == facet_pressure) m%ft(1, :) = 1.0_wp
   end subroutine facets

   !> Facet f + 1: the side from lattice point a to b (2D), or the quad a, b, b + dz, a + dz (3D).
   subroutine add_side(m, nr, nt, f, a, b, kind)
      type(mesh_type), intent(inout) :: m
      integer, intent(in) :: nr, nt, a(3), b(3), kind
      integer, intent(inout) :: f
      f = f + 1
      if (m%dim == 2) then
         m%fn(:, f) = [lattice(nr, nt, a(1), a(2), 0), lattice(nr, nt, b(1), b(2), 0)]
      else
         m%fn(:, f) = [lattice(nr, nt, a(1), a(2), a(3)), lattice(nr, nt, b(1), b(2), b(3)), &
            & lattice(nr, nt, b(1), b(2), b(3) + 1), lattice(nr, nt, a(1), a(2), a(3) + 1)]
      end if
      m%fk(f) = kind
   end subroutine add_side

   !> Lame stresses (internal pressure 1, plane strain) at x, perturbed by 1 %, Voigt.
   subroutine lame(x, s)
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: s(:)
      real(wp) :: r2, a, b, srr, stt, c, sn, noise

      r2 = x(1)**2 + x(2)**2
      a = r_in**2/(r_out**2 - r_in**2)
      b = a*r_out**2
      srr = a - b/r2
      stt = a + b/r2
      c = x(1)/sqrt(r2)
      sn = x(2)/sqrt(r2)
      noise = 0.01_wp*sin(3.0_wp*x(1) + 2.0_wp*x(2))
      if (size(s) == 3) then
         s = [srr*c**2 + stt*sn**2, srr*sn**2 + stt*c**2, (srr - stt)*c*sn] + noise
      else
         s = [srr*c**2 + stt*sn**2, srr*sn**2 + stt*c**2, nu*(srr + stt), (srr - stt)*c*sn, 0.0_wp, 0.0_wp] + noise
      end if
   end subroutine lame

   pure subroutine multilinear(d, xi, n, dn)
      integer, intent(in) :: d
      real(wp), intent(in) :: xi(3)
      real(wp), intent(out) :: n(8), dn(3, 8)
      integer, parameter :: c(3, 8) = reshape([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, &
         & 0, 1, 1], [3, 8])
      real(wp) :: l(0:1, 3), dl(0:1, 3)
      integer :: a, k

      do k = 1, 3
         l(:, k) = [1.0_wp - xi(k), xi(k)]
         dl(:, k) = [-1.0_wp, 1.0_wp]
      end do
      if (d == 2) then
         l(:, 3) = [1.0_wp, 0.0_wp]
         dl(:, 3) = 0.0_wp
      end if
      do a = 1, 2**d
         n(a) = l(c(1, a), 1)*l(c(2, a), 2)*l(c(3, a), 3)
         dn(1, a) = dl(c(1, a), 1)*l(c(2, a), 2)*l(c(3, a), 3)
         dn(2, a) = l(c(1, a), 1)*dl(c(2, a), 2)*l(c(3, a), 3)
         dn(3, a) = l(c(1, a), 1)*l(c(2, a), 2)*dl(c(3, a), 3)
      end do
   end subroutine multilinear

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

end program bench_mesh_recovery
