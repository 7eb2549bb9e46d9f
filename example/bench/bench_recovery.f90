!> Benchmark of the recovery core: patches per second of SPR and SPR-C, 2D and 3D,
!> degree 1 and 2, on synthetic vertex patches (2^dim cells of (p+1)^dim Gauss points
!> each, jittered; half of the patches carry a traction boundary with (p+1)^(dim-1)
!> points per boundary face). Prints per-thread rates, the rate of an OpenMP loop over
!> all threads, and, from a separate single-thread run with ws%timing on: the share of time
!> spent inside the dense kernels (sprc_core_dense and the Gram / equilibrium products,
!> timed around each call), their mean nominal flops per patch (counted as the LAPACK/BLAS
!> calls of the same operations, LAWN 41 leading terms, sprc_recovery_flops), the rate
!> achieved inside them (those flops / the time inside), and the mean hand count
!> of forming the design matrix (the one counted hand-written loop, not in flops/patch).
!> Patches that fail (rank deficient) are in the means: their calls up to the failure count.
!>
!> Run: fpm run --profile release --example bench_recovery
program bench_recovery
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_material, only: plane_stress, solid
   use sprc_core_timer, only: wall_time
   use sprc_core_blas_threads, only: blas_serial_begin, blas_serial_end
   use sprc_recovery_patch, only: patch_type, recovered_patch_type, patch_reset, patch_add_point, &
      & patch_add_boundary_point, boundary_traction
   use sprc_recovery_workspace, only: recovery_workspace_type, workspace_init
   use sprc_recovery_patch_solve, only: recover_spr, recover_sprc
   !$ use omp_lib, only: omp_get_max_threads
   implicit none

   integer, parameter :: npatch = 64
   integer :: dim, p, method, nthreads, saved_blas

   nthreads = 1
   !$ nthreads = omp_get_max_threads()
   write (*, '(a,i0)') 'bench_recovery: synthetic vertex patches; OpenMP threads: ', nthreads
   ! OpenBLAS in one thread throughout, as in the library's own patch loops
   ! (sprc_core_blas_threads: concurrent small calls with a pool of 2+ spin in the kernel).
   saved_blas = blas_serial_begin()
   write (*, '(a)') ' dim  p  method  points  bpoints  patches/s/thread  patches/s (all threads)  kernel share'// &
      & '  flops/patch  kernel GFLOP/s  design flops/patch'
   do dim = 2, 3
      do p = 1, 2
         do method = 1, 2
            call run(dim, p, method)
         end do
      end do
   end do
   call blas_serial_end(saved_blas)

contains

   subroutine run(dim, p, method)
      integer, intent(in) :: dim, p, method
      type(patch_type), allocatable :: patches(:)
      type(recovered_patch_type), allocatable :: recs(:)
      type(recovery_workspace_type) :: ws
      type(recovered_patch_type) :: rec
      type(error_type), allocatable :: error
      integer(i8) :: st
      integer :: i, k, nrep, nfail, ntimed
      real(wp) :: t0, t1, serial, parallel, share, flops, gflops, design

      allocate (patches(npatch), recs(npatch))
      st = 17_i8
      do i = 1, npatch
         call make_patch(dim, p, modulo(i, 2) == 0, st, patches(i))
      end do

      ! Calibrate the repetitions to about 0.4 s single-threaded.
      nrep = 1
      do
         t0 = wall_time()
         call sweep(patches, recs, dim, p, method, nrep, ws, nfail)
         t1 = wall_time() - t0
         if (t1 > 0.4_wp .or. nrep > 1000000) exit
         nrep = nrep*2
      end do
      serial = real(npatch, wp)*nrep/t1

      t0 = wall_time()
      ! One work-shared loop over all repetitions: a single barrier, so a descheduled thread
      ! on a loaded machine does not stall every repetition.
      !$omp parallel private(ws, k, i, error, rec)
      call workspace_init(ws)
      !$omp do schedule(static)
      do k = 0, npatch*nrep - 1
         i = modulo(k, npatch) + 1
         if (method == 1) then
            call recover_spr(patches(i), p, ws, rec, error)
         else
            call recover_sprc(patches(i), p, ws, rec, error)
         end if
      end do
      !$omp end do
      !$omp end parallel
      parallel = real(npatch, wp)*nrep/(wall_time() - t0)

      ws%timing = .true.
      ws%lapack_seconds = 0.0_wp
      ws%flops = 0
      ws%design_flops = 0
      ntimed = max(1, nrep/4)
      t0 = wall_time()
      call sweep(patches, recs, dim, p, method, ntimed, ws, nfail)
      share = ws%lapack_seconds/(wall_time() - t0)
      flops = real(ws%flops, wp)/(real(npatch, wp)*ntimed)
      design = real(ws%design_flops, wp)/(real(npatch, wp)*ntimed)
      gflops = 1.0e-9_wp*real(ws%flops, wp)/max(ws%lapack_seconds, tiny(1.0_wp))

      write (*, '(i4,i3,2x,a6,i8,i9,f18.0,f25.0,f13.1,"%",f13.0,f16.2,f20.0,a,i0)') dim, p, &
         & merge('SPR   ', 'SPR-C ', method == 1), patches(1)%npoints, patches(2)%nbpoints, serial, parallel, &
         & 100.0_wp*share, flops, gflops, design, '  failed: ', nfail
   end subroutine run

   subroutine sweep(patches, recs, dim, p, method, nrep, ws, nfail)
      type(patch_type), intent(in) :: patches(:)
      type(recovered_patch_type), intent(inout) :: recs(:)
      integer, intent(in) :: dim, p, method, nrep
      type(recovery_workspace_type), intent(inout) :: ws
      integer, intent(out) :: nfail
      type(error_type), allocatable :: error
      integer :: rep, i

      if (dim < 0) return
      nfail = 0
      do rep = 1, nrep
         do i = 1, size(patches)
            if (method == 1) then
               call recover_spr(patches(i), p, ws, recs(i), error)
            else
               call recover_sprc(patches(i), p, ws, recs(i), error)
            end if
            if (allocated(error)) nfail = nfail + 1
         end do
      end do
   end subroutine sweep

   real(wp) function urand(st)
      integer(i8), intent(inout) :: st
      st = modulo(st*6364136223846793005_i8 + 1442695040888963407_i8, huge(st))
      urand = 2.0_wp*real(modulo(st/1024_i8, 1048576_i8), wp)/1048576.0_wp - 1.0_wp
   end function urand

   !> 2^dim cells [-1,1]^dim around the vertex at 0, (p+1)^dim jittered points per cell with
   !> random stresses; with `boundary`, only the cells above x_dim = 0 and traction points on it.
   subroutine make_patch(dim, p, boundary, st, patch)
      integer, intent(in) :: dim, p
      logical, intent(in) :: boundary
      integer(i8), intent(inout) :: st
      type(patch_type), intent(inout) :: patch
      integer :: ng, cell, g, k, ncell, npc, idx, nb
      real(wp) :: x(3), sig(6), lo(3)

      ng = p + 1
      call patch_reset(patch, dim, merge(plane_stress, solid, dim == 2), 210.0_wp, 0.3_wp, [0.0_wp, 0.0_wp, 0.0_wp], &
         & 1.0_wp)
      patch%body_force(1:dim) = [0.1_wp, -1.0_wp, 0.2_wp]
      ncell = 2**dim
      npc = ng**dim
      do cell = 0, ncell - 1
         do k = 1, dim
            lo(k) = real(ibits(cell, k - 1, 1) - 1, wp)
         end do
         if (boundary .and. lo(dim) < 0.0_wp) cycle
         do g = 0, npc - 1
            idx = g
            do k = 1, dim
               x(k) = lo(k) + (real(modulo(idx, ng), wp) + 0.5_wp + 0.3_wp*urand(st))/ng
               idx = idx/ng
            end do
            do k = 1, 6
               sig(k) = urand(st)
            end do
            call patch_add_point(patch, x(1:dim), 1.0_wp/npc, sig(1:merge(3, 6, dim == 2)))
         end do
      end do
      if (.not. boundary) return
      nb = 2**(dim - 1)*ng**(dim - 1)
      do g = 1, nb
         x = 0.0_wp
         do k = 1, dim - 1
            x(k) = urand(st)
         end do
         call patch_add_boundary_point(patch, x(1:dim), 1.0_wp/nb, unit_normal(dim), boundary_traction, &
            & [0.0_wp, 0.0_wp, 0.0_wp])
      end do
   end subroutine make_patch

   pure function unit_normal(dim) result(n)
      integer, intent(in) :: dim
      real(wp) :: n(dim)
      n = 0.0_wp
      n(dim) = -1.0_wp
   end function unit_normal

end program bench_recovery
