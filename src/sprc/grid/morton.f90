!> Morton (Z-order) keys of integer cell coordinates in 2D and 3D.
!>
!> A key interleaves the bits of the coordinates, x in the lowest bit:
!> key = ... z1 y1 x1 z0 y0 x0. Cells that are close in space are mostly close
!> in key order, and the descendants of a cell form one contiguous key range,
!> which is what the grid's sorted-leaf queries rely on. Keys are non-negative
!> `integer(i8)`: up to 31 bits per coordinate in 2D and 21 in 3D.
module sprc_grid_morton
   use sprc_core_kinds, only: i8
   implicit none
   private

   public :: morton_encode, morton_decode, morton_max_bits

   !> Largest number of bits per coordinate that a key holds, by dimension (index 2 or 3).
   integer, parameter :: morton_max_bits(2:3) = [31, 21]

   integer(i8), parameter :: m2_16 = int(z'0000FFFF0000FFFF', i8)
   integer(i8), parameter :: m2_8 = int(z'00FF00FF00FF00FF', i8)
   integer(i8), parameter :: m2_4 = int(z'0F0F0F0F0F0F0F0F', i8)
   integer(i8), parameter :: m2_2 = int(z'3333333333333333', i8)
   integer(i8), parameter :: m2_1 = int(z'5555555555555555', i8)
   integer(i8), parameter :: m2_0 = int(z'7FFFFFFF', i8)

   integer(i8), parameter :: m3_32 = int(z'001F00000000FFFF', i8)
   integer(i8), parameter :: m3_16 = int(z'001F0000FF0000FF', i8)
   integer(i8), parameter :: m3_8 = int(z'100F00F00F00F00F', i8)
   integer(i8), parameter :: m3_4 = int(z'10C30C30C30C30C3', i8)
   integer(i8), parameter :: m3_2 = int(z'1249249249249249', i8)
   integer(i8), parameter :: m3_0 = int(z'1FFFFF', i8)

contains

   !> Key of the integer coordinates `coord` (size 2 or 3, each in [0, 2**morton_max_bits(size))).
   !> Bits above the limit are ignored.
   pure function morton_encode(coord) result(key)
      integer, intent(in) :: coord(:)
      integer(i8) :: key

      if (size(coord) == 2) then
         key = ior(spread2(int(coord(1), i8)), ishft(spread2(int(coord(2), i8)), 1))
      else
         key = ior(ior(spread3(int(coord(1), i8)), ishft(spread3(int(coord(2), i8)), 1)), &
            & ishft(spread3(int(coord(3), i8)), 2))
      end if
   end function morton_encode

   !> Coordinates (size `dim`, 2 or 3) of the Morton key `key`.
   pure function morton_decode(key, dim) result(coord)
      integer(i8), intent(in) :: key
      integer, intent(in) :: dim
      integer :: coord(dim)
      integer :: k

      if (dim == 2) then
         do k = 1, 2
            coord(k) = int(compact2(ishft(key, -(k - 1))))
         end do
      else
         do k = 1, 3
            coord(k) = int(compact3(ishft(key, -(k - 1))))
         end do
      end if
   end function morton_decode

   !> Insert a zero bit above each of the 31 low bits of `v`.
   pure function spread2(v) result(x)
      integer(i8), intent(in) :: v
      integer(i8) :: x
      x = iand(v, m2_0)
      x = iand(ior(x, ishft(x, 16)), m2_16)
      x = iand(ior(x, ishft(x, 8)), m2_8)
      x = iand(ior(x, ishft(x, 4)), m2_4)
      x = iand(ior(x, ishft(x, 2)), m2_2)
      x = iand(ior(x, ishft(x, 1)), m2_1)
   end function spread2

   !> Inverse of `spread2`: gather every second bit.
   pure function compact2(v) result(x)
      integer(i8), intent(in) :: v
      integer(i8) :: x
      x = iand(v, m2_1)
      x = iand(ieor(x, ishft(x, -1)), m2_2)
      x = iand(ieor(x, ishft(x, -2)), m2_4)
      x = iand(ieor(x, ishft(x, -4)), m2_8)
      x = iand(ieor(x, ishft(x, -8)), m2_16)
      x = iand(ieor(x, ishft(x, -16)), m2_0)
   end function compact2

   !> Insert two zero bits above each of the 21 low bits of `v`.
   pure function spread3(v) result(x)
      integer(i8), intent(in) :: v
      integer(i8) :: x
      x = iand(v, m3_0)
      x = iand(ior(x, ishft(x, 32)), m3_32)
      x = iand(ior(x, ishft(x, 16)), m3_16)
      x = iand(ior(x, ishft(x, 8)), m3_8)
      x = iand(ior(x, ishft(x, 4)), m3_4)
      x = iand(ior(x, ishft(x, 2)), m3_2)
   end function spread3

   !> Inverse of `spread3`: gather every third bit.
   pure function compact3(v) result(x)
      integer(i8), intent(in) :: v
      integer(i8) :: x
      x = iand(v, m3_2)
      x = iand(ieor(x, ishft(x, -2)), m3_4)
      x = iand(ieor(x, ishft(x, -4)), m3_8)
      x = iand(ieor(x, ishft(x, -8)), m3_16)
      x = iand(ieor(x, ishft(x, -16)), m3_32)
      x = iand(ieor(x, ishft(x, -32)), m3_0)
   end function compact3

end module sprc_grid_morton
