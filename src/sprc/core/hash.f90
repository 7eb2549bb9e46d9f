!> Hashing of integer and real keys for the project's open-addressing tables (linear
!> probing in a power-of-two table: the slot is the hash's low bits).
!>
!> Keys with structure are the rule, not the exception: coordinates that are dyadic
!> fractions (every power-of-two grid) have all their low mantissa bits zero, lattice
!> coordinates are multiples of a power of two, Morton keys of one level differ in a few
!> bits. A table indexed by low bits therefore needs every key bit to reach every hash
!> bit: each 32-bit word of the key is xored into the state, which then goes through
!> MurmurHash3's 32-bit finaliser (fmix32, a bijection with full avalanche). The
!> arithmetic is exact in signed 64-bit integers (values below 2**32; each product of the
!> multiplication mod 2**32 is split into 16-bit halves, below 2**48), so there is no
!> integer overflow anywhere.
module sprc_core_hash
   use sprc_core_kinds, only: wp, i8
   implicit none
   private

   public :: hash_seed, hash_int, hash_i8, hash_real

   !> Initial state (FNV-1a's 32-bit offset basis: any nonzero constant below 2**32).
   integer(i8), parameter :: hash_seed = 2166136261_i8
   integer(i8), parameter :: mask32 = 4294967295_i8, mask16 = 65535_i8

contains

   !> The state h (below 2**32) with the 32-bit word w (below 2**32) mixed in.
   pure elemental integer(i8) function hash_word(h, w) result(r)
      integer(i8), intent(in) :: h, w
      r = ieor(h, w)
      r = ieor(r, shiftr(r, 16))
      r = mul32(r, 2246822507_i8)
      r = ieor(r, shiftr(r, 13))
      r = mul32(r, 3266489909_i8)
      r = ieor(r, shiftr(r, 16))
   end function hash_word

   !> a*c mod 2**32 for a, c below 2**32, with every intermediate below 2**49.
   pure elemental integer(i8) function mul32(a, c) result(r)
      integer(i8), intent(in) :: a, c
      r = iand(iand(a, mask16)*c + shiftl(iand(shiftr(a, 16)*c, mask16), 16), mask32)
   end function mul32

   !> The state h with the 64-bit key k (both 32-bit halves, high first) mixed in.
   pure integer(i8) function hash_i8(h, k) result(r)
      integer(i8), intent(in) :: h, k
      r = hash_word(hash_word(h, iand(shiftr(k, 32), mask32)), iand(k, mask32))
   end function hash_i8

   !> The hash of the default integers g (their 32-bit two's complement patterns).
   pure integer(i8) function hash_int(g) result(r)
      integer, intent(in) :: g(:)
      integer :: i
      r = hash_seed
      do i = 1, size(g)
         r = hash_word(r, iand(int(g(i), i8), mask32))
      end do
   end function hash_int

   !> The hash of the bits of x (-0 counted as +0, so that equal points hash alike).
   pure integer(i8) function hash_real(x) result(r)
      real(wp), intent(in) :: x(:)
      integer :: i
      r = hash_seed
      do i = 1, size(x)
         r = hash_i8(r, transfer(x(i) + 0.0_wp, 1_i8))
      end do
   end function hash_real

end module sprc_core_hash
