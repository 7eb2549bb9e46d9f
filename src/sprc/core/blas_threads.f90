!> OpenBLAS's thread count, through the C shim (src/shim/sprc_suitesparse.c; weak
!> references, so with another BLAS the count reads 0 and setting it does nothing).
!>
!> Two reasons to run BLAS/LAPACK in one thread inside sprc:
!> - bits: OpenBLAS splits level-2/3 work across threads in ways that change the rounding
!>   (the sparse solvers' factorizations);
!> - speed: the recovery calls small LAPACK routines from every thread of an OpenMP loop
!>   over patches; with an OpenBLAS thread pool of 2 or more, those concurrent calls contend
!>   for OpenBLAS's shared buffers and threads and spin in the kernel (several times slower
!>   than with one BLAS thread).
!> `blas_serial_begin` / `blas_serial_end` bracket such regions and restore the caller's
!> count. The count is process-global: a caller running its own BLAS work in other threads
!> at the same time sees it at 1 meanwhile.
module sprc_core_blas_threads
   use, intrinsic :: iso_c_binding, only: c_int
   use sprc_core_kinds, only: wp, i8
   use sprc_core_lapack, only: dgemm
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   implicit none
   private

   public :: blas_threads, set_blas_threads, blas_serial_begin, blas_serial_end
   public :: blas_reserve_buffers, blas_reserved_threads, blas_buffer_bytes

   !> Address space OpenBLAS takes for each thread that calls it, on its first call
   !> (malloc(134221824) per thread, seen in a debugger).
   integer(i8), parameter :: blas_buffer_bytes = 134221824_i8
   !> Threads whose buffer is taken (process-global, like OpenBLAS's own pool).
   integer, save :: reserved_threads = 0

   interface
      !> OpenBLAS's thread count; 0 with a BLAS that has no such control.
      function blas_threads() result(n) bind(C, name='sprc_blas_get_threads')
         import :: c_int
         integer(c_int) :: n
      end function blas_threads

      !> Set OpenBLAS's thread count (n >= 1; no-op without OpenBLAS).
      subroutine set_blas_threads(n) bind(C, name='sprc_blas_set_threads')
         import :: c_int
         integer(c_int), value :: n
      end subroutine set_blas_threads
   end interface

contains

   !> Run BLAS in one thread from here on; returns the count to restore.
   integer function blas_serial_begin() result(saved)
      saved = blas_threads()
      if (saved > 1) call set_blas_threads(1_c_int)
   end function blas_serial_begin

   !> Restore the count `blas_serial_begin` returned.
   subroutine blas_serial_end(saved)
      integer, intent(in) :: saved
      if (saved > 1) call set_blas_threads(int(saved, c_int))
   end subroutine blas_serial_end

   !> One BLAS call on every thread of an OpenMP team, so that OpenBLAS takes its
   !> buffer for each (`blas_buffer_bytes` of address space, on a thread's first
   !> dgemm with a transposed operand) now, while there is room, and not in the
   !> middle of a level: when that allocation fails OpenBLAS retries for ever
   !> (blas_memory_alloc), a hang instead of an error (seen under ulimit -v with
   !> the memory estimate off). Each thread first
   !> allocates and frees as much itself: when that fails, `error` says so and
   !> BLAS is not called.
   subroutine blas_reserve_buffers(error)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: probe(:)
      real(wp) :: a(1, 1), b(1, 1), c(1, 1)
      integer :: stat, failed

      a = 1.0_wp
      b = 1.0_wp
      failed = 0
      !$omp parallel private(c, probe, stat) reduction(max: failed)
      allocate (probe(blas_buffer_bytes/(storage_size(1.0_wp)/8)), stat=stat)
      if (stat == 0) then
         deallocate (probe)
         call dgemm('T', 'N', 1, 1, 1, 1.0_wp, a, 1, b, 1, 0.0_wp, c, 1)
      else
         failed = 1
      end if
      !$omp end parallel
      if (failed == 0) then
         reserved_threads = max(reserved_threads, omp_threads())
         return
      end if
      call check_allocation(failed, 'BLAS start-up', 'the OpenBLAS buffer of each thread', omp_threads(), &
         & int(blas_buffer_bytes), error)
      error%message = error%message//'; fewer threads need less (OMP_NUM_THREADS, sprc run --threads)'
   end subroutine blas_reserve_buffers

   !> Threads whose OpenBLAS buffer `blas_reserve_buffers` has reserved.
   integer function blas_reserved_threads()
      blas_reserved_threads = reserved_threads
   end function blas_reserved_threads

   integer function omp_threads() result(n)
      !$ use omp_lib, only: omp_get_max_threads
      n = 1
      !$ n = omp_get_max_threads()
   end function omp_threads

end module sprc_core_blas_threads
