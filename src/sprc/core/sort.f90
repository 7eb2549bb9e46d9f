!> The one stable merge sort behind every sort of the library.
!>
!> Every key type is mapped to 64-bit integers in the same order (reals through
!> their IEEE bits, -0 counted as +0 as `<` does), and one routine sorts a
!> permutation by those keys: insertion sort on runs of 16, then bottom-up merges.
!> Equal keys keep their index order, so the result is the same on every machine;
!> O(n log n) in time, and O(n) scratch.
module sprc_core_sort
   use sprc_core_kinds, only: wp, i8
   implicit none
   private

   public :: sort_order, sort, sort_pairs

   !> `order`, the permutation sorting `v` ascending (v(order) is sorted; stable).
   !> `work` is scratch of the same size.
   interface sort_order
      module procedure sort_order_real, sort_order_int, sort_order_i8
   end interface sort_order

   !> v sorted ascending, in place.
   interface sort
      module procedure sort_real, sort_int
   end interface sort

   !> Runs this short are sorted by insertion before the merges.
   integer, parameter :: run = 16

contains

   pure subroutine sort_order_real(v, order, work)
      real(wp), intent(in) :: v(:)
      integer, intent(out) :: order(:), work(:)
      call merge_order(real_key(v), order, work)
   end subroutine sort_order_real

   pure subroutine sort_order_int(v, order, work)
      integer, intent(in) :: v(:)
      integer, intent(out) :: order(:), work(:)
      call merge_order(int(v, i8), order, work)
   end subroutine sort_order_int

   pure subroutine sort_order_i8(v, order, work)
      integer(i8), intent(in) :: v(:)
      integer, intent(out) :: order(:), work(:)
      call merge_order(v, order, work)
   end subroutine sort_order_i8

   pure subroutine sort_real(v)
      real(wp), intent(inout) :: v(:)
      integer :: order(size(v)), work(size(v))
      call merge_order(real_key(v), order, work)
      v = v(order)
   end subroutine sort_real

   pure subroutine sort_int(v)
      integer, intent(inout) :: v(:)
      integer :: order(size(v)), work(size(v))
      call merge_order(int(v, i8), order, work)
      v = v(order)
   end subroutine sort_int

   !> key sorted ascending in place, val carried along (a sparse row's columns and
   !> values).
   pure subroutine sort_pairs(key, val)
      integer, intent(inout) :: key(:)
      real(wp), intent(inout) :: val(:)
      integer :: order(size(key)), work(size(key))
      call merge_order(int(key, i8), order, work)
      key = key(order)
      val = val(order)
   end subroutine sort_pairs

   !> 64-bit integers ordered as the reals x are by `<` (for numbers; -0 maps to +0).
   pure elemental integer(i8) function real_key(x) result(k)
      real(wp), intent(in) :: x
      k = transfer(x + 0.0_wp, 1_i8)
      ! A negative real's bits grow with its magnitude: flip them below the sign.
      if (k < 0_i8) k = ieor(k, huge(1_i8))
   end function real_key

   !> The stable sorting permutation of key (module notes).
   pure subroutine merge_order(key, order, work)
      integer(i8), intent(in) :: key(:)
      integer, intent(out) :: order(:), work(:)
      integer :: width, lo, mid, hi, i, j, k, n, o

      n = size(key)
      order = [(i, i=1, n)]
      do lo = 1, n, run
         hi = min(lo + run - 1, n)
         do i = lo + 1, hi
            o = order(i)
            j = i - 1
            do while (j >= lo)
               if (key(order(j)) <= key(o)) exit
               order(j + 1) = order(j)
               j = j - 1
            end do
            order(j + 1) = o
         end do
      end do
      width = run
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
               else if (key(order(j)) < key(order(i))) then
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
   end subroutine merge_order

end module sprc_core_sort
