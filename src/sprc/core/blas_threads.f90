!> OpenBLAS's thread count, through the C shim (src/shim/sprc_suitesparse.c; weak
!> references, so with another BLAS the count reads 0 and setting it does nothing).
!>
!> Two reasons to run BLAS/LAPACK in one thread inside sprc:
!> - bits: OpenBLAS splits level-2/3 work across threads in ways that change the rounding
!>   (the sparse solvers' factorizations);
!> - speed: the recovery calls small LAPACK routines from every thread of an OpenMP loop
!>   over patches; with an OpenBLAS thread pool of 2 or more, those concurrent calls contend
!>   for OpenBLAS's shared buffers and threads and spin in the kernel (measured: sphere octant
!>   Q1 level 5, 2 threads, t_recovery 0.87 - 3.4 s against 0.25 s with one BLAS thread).
!> `blas_serial_begin` / `blas_serial_end` bracket such regions and restore the caller's
!> count. The count is process-global: a caller running its own BLAS work in other threads
!> at the same time sees it at 1 meanwhile.
module sprc_core_blas_threads
   use, intrinsic :: iso_c_binding, only: c_int
   implicit none
   private

   public :: blas_threads, set_blas_threads, blas_serial_begin, blas_serial_end

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

end module sprc_core_blas_threads
