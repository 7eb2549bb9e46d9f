!> Sorting permutations.
module sprc_core_sort
   use sprc_core_kinds, only: wp
   implicit none
   private

   public :: sort_order

contains

   !> `order`, the permutation sorting `v` ascending: a stable bottom-up merge
   !> sort (equal values keep their index order, so the result is the same on
   !> every machine); O(n log n). `work` is scratch of the same size.
   pure subroutine sort_order(v, order, work)
      real(wp), intent(in) :: v(:)
      integer, intent(out) :: order(:), work(:)
      integer :: width, lo, mid, hi, i, j, k, n

      n = size(v)
      order = [(i, i=1, n)]
      width = 1
      do while (width < n)
         do lo = 1, n, 2*width
            mid = min(lo + width - 1, n)
            hi = min(lo + 2*width - 1, n)
            i = lo
            j = mid + 1
            do k = lo, hi
               if (j > hi) then
                  work(k) = order(i)
                  i = i + 1
               else if (i > mid) then
                  work(k) = order(j)
                  j = j + 1
               else if (v(order(j)) < v(order(i))) then
                  work(k) = order(j)
                  j = j + 1
               else
                  work(k) = order(i)
                  i = i + 1
               end if
            end do
         end do
         order = work
         width = 2*width
      end do
   end subroutine sort_order

end module sprc_core_sort
