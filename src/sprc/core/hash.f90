!> Hashing of integer and real keys, and the project's one hash table (`key_table_type`:
!> open addressing, linear probing in a power-of-two table; the slot is the hash's low bits).
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
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   implicit none
   private

   public :: hash_seed, hash_int, hash_i8, hash_real, key_table_type

   !> Initial state (FNV-1a's 32-bit offset basis: any nonzero constant below 2**32).
   integer(i8), parameter :: hash_seed = 2166136261_i8
   integer(i8), parameter :: mask32 = 4294967295_i8, mask16 = 65535_i8

   !> Keys (tuples of `width` default integers) numbered 1, 2, ... in the order they were
   !> first inserted, each with an integer `value` (0 until the caller sets it). Equal keys
   !> are one entry, so the numbering does not depend on the hash; the slots are kept at
   !> most half full, which with `hash_int` keeps probe runs short for structured keys
   !> (lattice points, dyadic coordinates, cell levels and indices) as for random ones.
   type :: key_table_type
      integer :: width = 0, n = 0
      !> The keys (width, capacity) by number; keys(:, 1:n) are in use.
      integer, allocatable :: keys(:, :)
      !> The caller's value of each key (capacity), 0 when inserted.
      integer, allocatable :: value(:)
      !> Number of the key in each slot (0: empty); size a power of two.
      integer, allocatable :: slot(:)
      integer(i8) :: mask = -1_i8
      !> The routine named in allocation errors.
      character(len=:), allocatable :: who
   contains
      procedure :: init => key_table_init
      procedure :: find => key_table_find
      procedure :: insert => key_table_insert
   end type key_table_type

contains

   !> An empty table of `width`-integer keys with room for `expected` of them before
   !> it grows; `who` names the caller in allocation errors.
   subroutine key_table_init(self, width, expected, who, error)
      class(key_table_type), intent(out) :: self
      integer, intent(in) :: width, expected
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      integer :: cap, stat
      self%who = who
      self%width = width
      cap = 16
      do while (cap < 2*expected)
         cap = 2*cap
      end do
      allocate (self%keys(width, max(expected, 1)), self%value(max(expected, 1)), self%slot(0:cap - 1), stat=stat)
      call check_allocation(stat, who, 'a hash table', cap + (width + 1)*max(expected, 1), 4, error)
      if (allocated(error)) return
      self%slot = 0
      self%mask = int(cap, i8) - 1_i8
   end subroutine key_table_init

   !> The number of `key` (size width), 0 if absent.
   pure integer function key_table_find(self, key) result(number)
      class(key_table_type), intent(in) :: self
      integer, intent(in) :: key(:)
      integer(i8) :: s
      call locate(self, key, s, number)
   end function key_table_find

   !> The slot s of `key`: its number there, or 0 and the empty slot where it goes.
   pure subroutine locate(self, key, s, number)
      type(key_table_type), intent(in) :: self
      integer, intent(in) :: key(:)
      integer(i8), intent(out) :: s
      integer, intent(out) :: number
      s = iand(hash_int(key), self%mask)
      do
         number = self%slot(s)
         if (number == 0) return
         if (all(self%keys(:, number) == key)) return
         s = iand(s + 1_i8, self%mask)
      end do
   end subroutine locate

   !> The number of `key`, inserted as number n + 1 if absent (`added`).
   subroutine key_table_insert(self, key, number, added, error)
      class(key_table_type), intent(inout) :: self
      integer, intent(in) :: key(:)
      integer, intent(out) :: number
      logical, intent(out) :: added
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: s

      call locate(self, key, s, number)
      added = number == 0
      if (.not. added) return
      if (self%n == size(self%keys, 2)) call grow_keys(self, error)
      if (allocated(error)) return
      self%n = self%n + 1
      number = self%n
      self%keys(:, number) = key
      self%value(number) = 0
      self%slot(s) = number
      if (2*self%n > size(self%slot)) call grow_slots(self, error)
   end subroutine key_table_insert

   subroutine grow_keys(self, error)
      type(key_table_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: keys(:, :), value(:)
      integer :: cap, stat
      cap = 2*size(self%keys, 2)
      allocate (keys(self%width, cap), value(cap), stat=stat)
      call check_allocation(stat, self%who, 'the keys of a hash table', cap, 4*(self%width + 1), error)
      if (allocated(error)) return
      keys(:, 1:self%n) = self%keys(:, 1:self%n)
      value(1:self%n) = self%value(1:self%n)
      call move_alloc(keys, self%keys)
      call move_alloc(value, self%value)
   end subroutine grow_keys

   !> Twice the slots, every key placed again (in number order: deterministic).
   subroutine grow_slots(self, error)
      type(key_table_type), intent(inout) :: self
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: slot(:)
      integer(i8) :: s
      integer :: i, stat
      allocate (slot(0:2*size(self%slot) - 1), stat=stat)
      call check_allocation(stat, self%who, 'the slots of a hash table', 2*size(self%slot), 4, error)
      if (allocated(error)) return
      call move_alloc(slot, self%slot)
      self%slot = 0
      self%mask = int(size(self%slot), i8) - 1_i8
      do i = 1, self%n
         s = iand(hash_int(self%keys(:, i)), self%mask)
         do while (self%slot(s) /= 0)
            s = iand(s + 1_i8, self%mask)
         end do
         self%slot(s) = i
      end do
   end subroutine grow_slots

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
