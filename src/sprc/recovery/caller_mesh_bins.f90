!> A uniform grid of bins over the (padded) element boxes of a caller's mesh, to find the
!> elements that may hold a point without testing every element.
!>
!> Element e is listed in every bin its padded box [lo - pad, hi + pad] (pad = pad_ratio
!> times its largest extent) overlaps, in ascending element order. A point's bin is
!> floor((x - origin)/size) per axis: the same monotone formula as the boxes' bins, so
!> every element whose padded box holds x is in x's bin, and testing x's bin in list order
!> finds the lowest-index element holding x, as a scan of all elements does. About one bin
!> per element (cubic bins over the boxes' bounding box): O(nelem) to build, O(1) bins per
!> element of a mesh of comparable element sizes.
module sprc_recovery_caller_mesh_bins
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_out_of_memory
   implicit none
   private

   public :: element_bins_type, build_element_bins, bin_of_point

   !> Bins (CSR): the elements of bin b are list(ptr(b):ptr(b + 1) - 1).
   type :: element_bins_type
      integer :: dim = 0
      integer :: n(3) = 1
      real(wp) :: origin(3) = 0.0_wp, size(3) = 1.0_wp
      integer, allocatable :: ptr(:), list(:)
   end type element_bins_type

contains

   !> Bins over the boxes (box_lo, box_hi)(dim, nelem), padded by pad_ratio times each box's
   !> largest extent (module notes).
   subroutine build_element_bins(box_lo, box_hi, pad_ratio, bins, error)
      real(wp), intent(in) :: box_lo(:, :), box_hi(:, :), pad_ratio
      type(element_bins_type), intent(out) :: bins
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: fill(:)
      real(wp) :: lo(3), hi(3), side, extent(3), pad
      integer :: d, e, nelem, st, pass, b, lo_b(3), hi_b(3), i, j, k
      integer(i8) :: total

      d = size(box_lo, 1)
      nelem = size(box_lo, 2)
      bins%dim = d
      allocate (bins%ptr(1), bins%list(0))
      bins%ptr = 1
      if (nelem == 0) return
      lo(1:d) = huge(1.0_wp)
      hi(1:d) = -huge(1.0_wp)
      do e = 1, nelem
         pad = pad_ratio*maxval(box_hi(:, e) - box_lo(:, e))
         lo(1:d) = min(lo(1:d), box_lo(:, e) - pad)
         hi(1:d) = max(hi(1:d), box_hi(:, e) + pad)
      end do
      extent(1:d) = max(hi(1:d) - lo(1:d), tiny(1.0_wp))
      ! Cubic bins, about one per element (at most 4 nelem + 1 in all).
      side = (product(extent(1:d))/nelem)**(1.0_wp/d)
      do k = 1, d
         bins%n(k) = int(max(1.0_wp, min(real(nelem, wp), extent(k)/max(side, tiny(1.0_wp)))))
      end do
      total = product(int(bins%n(1:d), i8))
      do while (total > 4_i8*nelem + 1)
         bins%n(1:d) = max(1, bins%n(1:d)/2)
         total = product(int(bins%n(1:d), i8))
      end do
      bins%origin(1:d) = lo(1:d)
      bins%size(1:d) = extent(1:d)/bins%n(1:d)
      deallocate (bins%ptr)
      allocate (bins%ptr(total + 1), fill(total), stat=st)
      if (st /= 0) then
         call fatal_error(error, 'element bins: out of memory', stat_out_of_memory)
         return
      end if
      ! Pass 1 counts, pass 2 lists (element order).
      do pass = 1, 2
         fill = 0
         do e = 1, nelem
            pad = pad_ratio*maxval(box_hi(:, e) - box_lo(:, e))
            lo_b = 0
            hi_b = 0
            do k = 1, d
               lo_b(k) = axis_bin(bins, k, box_lo(k, e) - pad)
               hi_b(k) = axis_bin(bins, k, box_hi(k, e) + pad)
            end do
            do k = lo_b(3), hi_b(3)
               do j = lo_b(2), hi_b(2)
                  do i = lo_b(1), hi_b(1)
                     b = 1 + i + bins%n(1)*(j + bins%n(2)*k)
                     if (pass == 2) bins%list(bins%ptr(b) + fill(b)) = e
                     fill(b) = fill(b) + 1
                  end do
               end do
            end do
         end do
         if (pass == 1) then
            bins%ptr(1) = 1
            do b = 1, int(total)
               bins%ptr(b + 1) = bins%ptr(b) + fill(b)
            end do
            deallocate (bins%list)
            allocate (bins%list(bins%ptr(total + 1) - 1), stat=st)
            if (st /= 0) then
               call fatal_error(error, 'element bins: out of memory', stat_out_of_memory)
               return
            end if
         end if
      end do
   end subroutine build_element_bins

   !> Bin coordinate (0-based) of v on axis k: floor((v - origin)/size) clamped to the grid,
   !> a monotone function of v (module notes).
   pure integer function axis_bin(bins, k, v) result(c)
      type(element_bins_type), intent(in) :: bins
      integer, intent(in) :: k
      real(wp), intent(in) :: v
      real(wp) :: t
      t = (v - bins%origin(k))/bins%size(k)
      t = max(0.0_wp, min(real(bins%n(k) - 1, wp), t))
      c = int(t)
   end function axis_bin

   !> The bin (1-based) whose elements are the candidates for x.
   pure integer function bin_of_point(bins, x) result(b)
      type(element_bins_type), intent(in) :: bins
      real(wp), intent(in) :: x(:)
      integer :: c(3), k

      c = 0
      do k = 1, bins%dim
         c(k) = axis_bin(bins, k, x(k))
      end do
      b = 1 + c(1) + bins%n(1)*(c(2) + bins%n(2)*c(3))
   end function bin_of_point

end module sprc_recovery_caller_mesh_bins
