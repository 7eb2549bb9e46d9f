!> Sparse matrices for assembly and direct solves: a growable triplet list
!> (`coo_type`) that finite elements add to, and compressed sparse rows
!> (`csr_type`) that the solvers read, and a list of dense element blocks
!> (`block_list_type`) that a finite-element assembly fills in parallel and
!> turns into CSR row by row in parallel.
!>
!> The COO -> CSR conversion sums duplicates in insertion order, so the same
!> sequence of `add` calls gives a bit-identical matrix on every run and with
!> any thread count. It is O(nnz + nrows + ncols): a stable counting sort by
!> row, duplicates merged through a column marker, then a sort of each row's
!> distinct columns (rows are short: at most 81 entries for Q1 elasticity).
!>
!> The block list gives the same matrix as adding its blocks to a COO list in
!> block order (each entry summed over the blocks in block order), but needs
!> no row and column index per value and builds each row on its own: rows are
!> shared out among the OpenMP threads, and a row's sums do not depend on which
!> thread forms them, so the bits do not depend on the thread count.
module sprc_fem_sparse
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite
   use sprc_core_kinds, only: wp, i8
   use sprc_core_sort, only: sort_pairs
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   implicit none
   private

   public :: coo_type, csr_type, block_list_type, csr_validate

   !> Capacity of a `coo_type` whose first `add` finds no storage.
   integer(i8), parameter :: min_capacity = 64

   !> Growable list of (row, column, value) triplets of an `nrows` x `ncols`
   !> matrix, indices 1-based. Duplicates are kept and summed by `to_csr`.
   type :: coo_type
      !> Dimensions, fixed by `init`.
      integer :: nrows = 0, ncols = 0
      !> Number of triplets stored (duplicates counted).
      integer(i8) :: nnz = 0
      !> Triplets 1..nnz; the arrays may be longer (capacity).
      integer, allocatable :: row(:), col(:)
      real(wp), allocatable :: val(:)
   contains
      procedure :: init => coo_init
      procedure :: reserve => coo_reserve
      procedure, private :: coo_add_entry, coo_add_block, coo_add_square_block
      !> `add(i, j, v, error)`, `add(rows, cols, block, error)` or `add(dofs, block, error)`.
      generic :: add => coo_add_entry, coo_add_block, coo_add_square_block
      procedure :: clear => coo_clear
      procedure :: to_csr => coo_to_csr
   end type coo_type

   !> Square dense blocks on lists of distinct indices of an `n` x `n` matrix, with
   !> a vector per block: block b adds val(val_ptr(b) + (i - 1) + (j - 1) m) to
   !> A(dofs(p + i), dofs(p + j)) and rhs(p + i) to f(dofs(p + i)), p = dof_ptr(b) - 1,
   !> m = dof_ptr(b + 1) - dof_ptr(b) (column-major blocks). `init` sizes the arrays;
   !> the caller fills dofs, val and rhs (block by block, in any order or in parallel);
   !> `to_csr` sums them.
   type :: block_list_type
      integer :: n = 0, nblocks = 0
      integer(i8), allocatable :: dof_ptr(:), val_ptr(:)
      integer, allocatable :: dofs(:)
      real(wp), allocatable :: val(:), rhs(:)
   contains
      procedure :: init => blocks_init
      procedure :: to_csr => blocks_to_csr
   end type block_list_type

   !> Compressed sparse rows, 1-based: row `i` holds `col(k), val(k)` for
   !> `k = rowptr(i) .. rowptr(i+1)-1`, columns strictly increasing.
   type :: csr_type
      integer :: nrows = 0, ncols = 0
      !> Row starts, size nrows+1, `rowptr(1) = 1`; 64-bit so nnz may pass 2**31.
      integer(i8), allocatable :: rowptr(:)
      integer, allocatable :: col(:)
      real(wp), allocatable :: val(:)
   contains
      procedure :: nnz => csr_nnz
      procedure :: copy => csr_copy
      procedure :: matvec => csr_matvec
      procedure :: norm1 => csr_norm1
   end type csr_type

contains

   !> Empty the list and fix the dimensions; `capacity` triplets are reserved
   !> (an estimate of the final count saves regrowth).
   subroutine coo_init(self, nrows, ncols, error, capacity)
      class(coo_type), intent(inout) :: self
      integer, intent(in) :: nrows, ncols
      type(error_type), allocatable, intent(out) :: error
      integer(i8), intent(in), optional :: capacity
      character(len=64) :: buf

      if (nrows < 0 .or. ncols < 0) then
         write (buf, '(i0," x ",i0)') nrows, ncols
         call fatal_error(error, 'coo_type%init: negative dimensions '//trim(buf), stat_invalid_input)
         return
      end if
      call self%clear()
      self%nrows = nrows
      self%ncols = ncols
      if (present(capacity)) call self%reserve(capacity, error)
   end subroutine coo_init

   !> Make room for at least `capacity` triplets in total, keeping the stored ones.
   subroutine coo_reserve(self, capacity, error)
      class(coo_type), intent(inout) :: self
      integer(i8), intent(in) :: capacity
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: irow(:), icol(:)
      real(wp), allocatable :: v(:)
      integer :: stat

      if (allocated(self%val)) then
         if (size(self%val, kind=i8) >= capacity) return
      end if
      if (capacity <= 0) return
      allocate (irow(capacity), icol(capacity), v(capacity), stat=stat)
      call check_allocation(stat, 'coo_type%reserve', 'the triplet list', capacity, 16, error)
      if (allocated(error)) return
      if (self%nnz > 0) then
         irow(1:self%nnz) = self%row(1:self%nnz)
         icol(1:self%nnz) = self%col(1:self%nnz)
         v(1:self%nnz) = self%val(1:self%nnz)
      end if
      call move_alloc(irow, self%row)
      call move_alloc(icol, self%col)
      call move_alloc(v, self%val)
   end subroutine coo_reserve

   !> Drop all triplets and storage; the dimensions become 0 x 0.
   subroutine coo_clear(self)
      class(coo_type), intent(inout) :: self
      if (allocated(self%row)) deallocate (self%row)
      if (allocated(self%col)) deallocate (self%col)
      if (allocated(self%val)) deallocate (self%val)
      self%nnz = 0
      self%nrows = 0
      self%ncols = 0
   end subroutine coo_clear

   !> Room for `extra` more triplets, doubling the capacity so that n adds cost O(n).
   subroutine coo_grow(self, extra, error)
      class(coo_type), intent(inout) :: self
      integer(i8), intent(in) :: extra
      type(error_type), allocatable, intent(out) :: error
      integer(i8) :: have

      have = 0
      if (allocated(self%val)) have = size(self%val, kind=i8)
      if (self%nnz + extra <= have) return
      call self%reserve(max(self%nnz + extra, 2*have, min_capacity), error)
   end subroutine coo_grow

   !> Add one triplet A(i, j) += v.
   subroutine coo_add_entry(self, i, j, v, error)
      class(coo_type), intent(inout) :: self
      integer, intent(in) :: i, j
      real(wp), intent(in) :: v
      type(error_type), allocatable, intent(out) :: error

      call check_indices(self, [i], [j], error)
      if (allocated(error)) return
      call check_finite([i], [j], reshape([v], [1, 1]), error)
      if (allocated(error)) return
      call coo_grow(self, 1_i8, error)
      if (allocated(error)) return
      self%nnz = self%nnz + 1
      self%row(self%nnz) = i
      self%col(self%nnz) = j
      self%val(self%nnz) = v
   end subroutine coo_add_entry

   !> Add an element block: A(rows(a), cols(b)) += block(a, b). Nothing is added
   !> when any index or value is rejected. Triplets go in column-major order of
   !> `block`, which fixes the summation order of duplicates.
   subroutine coo_add_block(self, rows, cols, block, error)
      class(coo_type), intent(inout) :: self
      integer, intent(in) :: rows(:), cols(:)
      real(wp), intent(in) :: block(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: a, b
      integer(i8) :: k
      character(len=96) :: buf

      if (size(block, 1) /= size(rows) .or. size(block, 2) /= size(cols)) then
         write (buf, '(i0," x ",i0," block for ",i0," rows and ",i0," columns")') &
            size(block, 1), size(block, 2), size(rows), size(cols)
         call fatal_error(error, 'coo_type%add: '//trim(buf), stat_invalid_input)
         return
      end if
      call check_indices(self, rows, cols, error)
      if (allocated(error)) return
      call check_finite(rows, cols, block, error)
      if (allocated(error)) return
      call coo_grow(self, size(block, kind=i8), error)
      if (allocated(error)) return
      k = self%nnz
      do b = 1, size(cols)
         do a = 1, size(rows)
            k = k + 1
            self%row(k) = rows(a)
            self%col(k) = cols(b)
            self%val(k) = block(a, b)
         end do
      end do
      self%nnz = k
   end subroutine coo_add_block

   !> Add a square element block on the same rows and columns: A(dofs, dofs) += block.
   subroutine coo_add_square_block(self, dofs, block, error)
      class(coo_type), intent(inout) :: self
      integer, intent(in) :: dofs(:)
      real(wp), intent(in) :: block(:, :)
      type(error_type), allocatable, intent(out) :: error
      call coo_add_block(self, dofs, dofs, block, error)
   end subroutine coo_add_square_block

   subroutine check_indices(self, rows, cols, error)
      type(coo_type), intent(in) :: self
      integer, intent(in) :: rows(:), cols(:)
      type(error_type), allocatable, intent(out) :: error
      character(len=96) :: buf
      integer :: k

      do k = 1, size(rows)
         if (rows(k) < 1 .or. rows(k) > self%nrows) then
            write (buf, '("row index ",i0," outside 1..",i0)') rows(k), self%nrows
            call fatal_error(error, 'coo_type%add: '//trim(buf), stat_invalid_input)
            return
         end if
      end do
      do k = 1, size(cols)
         if (cols(k) < 1 .or. cols(k) > self%ncols) then
            write (buf, '("column index ",i0," outside 1..",i0)') cols(k), self%ncols
            call fatal_error(error, 'coo_type%add: '//trim(buf), stat_invalid_input)
            return
         end if
      end do
   end subroutine check_indices

   subroutine check_finite(rows, cols, block, error)
      integer, intent(in) :: rows(:), cols(:)
      real(wp), intent(in) :: block(:, :)
      type(error_type), allocatable, intent(out) :: error
      integer :: a, b
      character(len=96) :: buf

      do b = 1, size(block, 2)
         do a = 1, size(block, 1)
            if (ieee_is_finite(block(a, b))) cycle
            write (buf, '("value for (",i0,", ",i0,") is not finite (NaN or Inf)")') rows(a), cols(b)
            call fatal_error(error, 'coo_type%add: '//trim(buf), stat_invalid_input)
            return
         end do
      end do
   end subroutine check_finite

   !> Convert to CSR, summing duplicates in insertion order; entries that sum
   !> to zero are kept (the pattern does not depend on values).
   !>
   !> Memory: beside the list and the result, only one band of rows is held
   !> sorted at a time (12 bytes a triplet, about 1/`n_bands` of the list),
   !> not the whole list a second time: the list of a large 3D assembly is
   !> several GB. Each band is gathered twice from the list, first for the
   !> pattern (the result is allocated at its exact size), then with values.
   subroutine coo_to_csr(self, a, error)
      class(coo_type), intent(in) :: self
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n_bands = 4
      integer(i8), allocatable :: start(:), next(:), marker(:)
      integer, allocatable :: first_row(:), tcol(:)
      real(wp), allocatable :: tval(:)
      integer(i8) :: k, band_max
      integer :: i, b, stat

      a%nrows = self%nrows
      a%ncols = self%ncols
      allocate (a%rowptr(self%nrows + 1), start(self%nrows + 1), next(self%nrows), marker(self%ncols), stat=stat)
      call check_allocation(stat, 'coo_type%to_csr', 'the row pointers', max(self%nrows + 1, self%ncols), 32, error)
      if (allocated(error)) return

      ! start(i): where row i's triplets begin in the list sorted by row.
      call row_starts(self%row(1:self%nnz), start)
      call row_bands(start, (self%nnz + n_bands - 1)/n_bands, first_row, band_max)
      allocate (tcol(band_max), tval(band_max), stat=stat)
      call check_allocation(stat, 'coo_type%to_csr', 'a band of sorted triplets', band_max, 12, error)
      if (allocated(error)) return

      ! Pattern: distinct columns of each row (marker(j) = last row seen in column j).
      marker = 0
      do b = 1, size(first_row) - 1
         call gather_band(self, first_row(b), first_row(b + 1) - 1, start, next, tcol)
         do i = first_row(b), first_row(b + 1) - 1
            a%rowptr(i + 1) = 0
            do k = start(i) - start(first_row(b)) + 1, start(i + 1) - start(first_row(b))
               if (marker(tcol(k)) /= i) then
                  marker(tcol(k)) = i
                  a%rowptr(i + 1) = a%rowptr(i + 1) + 1
               end if
            end do
         end do
      end do
      call allocate_rows(a, 'coo_type%to_csr', error)
      if (allocated(error)) return

      ! Values: duplicates summed in list order (the gather is stable).
      marker = 0
      do b = 1, size(first_row) - 1
         call gather_band(self, first_row(b), first_row(b + 1) - 1, start, next, tcol, tval)
         call merge_band(a, first_row(b), first_row(b + 1) - 1, start, tcol, tval, marker)
      end do
   end subroutine coo_to_csr

   !> rowptr(i + 1) holds the entry count of row i: make the row pointers of `a` from
   !> the counts and allocate its columns and values.
   subroutine allocate_rows(a, who, error)
      type(csr_type), intent(inout) :: a
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      integer :: i, stat

      a%rowptr(1) = 1
      do i = 1, a%nrows
         a%rowptr(i + 1) = a%rowptr(i + 1) + a%rowptr(i)
      end do
      allocate (a%col(a%rowptr(a%nrows + 1) - 1), a%val(a%rowptr(a%nrows + 1) - 1), stat=stat)
      call check_allocation(stat, who, 'the CSR matrix', a%rowptr(a%nrows + 1) - 1, 12, error)
   end subroutine allocate_rows

   !> start(i): where row i begins (1-based) in a list of entries in rows `rows` once
   !> sorted by row (the pointers of a counting sort); size(start) = rows + 1.
   pure subroutine row_starts(rows, start)
      integer, intent(in) :: rows(:)
      integer(i8), intent(out) :: start(:)
      integer(i8) :: k
      integer :: i

      start = 0
      do k = 1, size(rows, kind=i8)
         start(rows(k) + 1) = start(rows(k) + 1) + 1
      end do
      start(1) = 1
      do i = 1, size(start) - 1
         start(i + 1) = start(i + 1) + start(i)
      end do
   end subroutine row_starts

   !> Rows split into consecutive bands of at most `target` triplets each (or
   !> one row, if longer): band b is rows first_row(b) .. first_row(b+1)-1;
   !> `band_max` the most triplets of a band.
   subroutine row_bands(start, target, first_row, band_max)
      integer(i8), intent(in) :: start(:), target
      integer, allocatable, intent(out) :: first_row(:)
      integer(i8), intent(out) :: band_max
      integer :: i, nrows

      nrows = size(start) - 1
      first_row = [1]
      do i = 2, nrows
         if (start(i + 1) - start(first_row(size(first_row))) > target) first_row = [first_row, i]
      end do
      first_row = [first_row, nrows + 1]
      if (nrows == 0) first_row = [1, 1]
      band_max = 1
      do i = 1, size(first_row) - 1
         band_max = max(band_max, start(first_row(i + 1)) - start(first_row(i)))
      end do
   end subroutine row_bands

   !> The triplets of rows r0..r1 sorted by row, stable (list order within a
   !> row): columns into `tcol`, and values into `tval` when present.
   subroutine gather_band(self, r0, r1, start, next, tcol, tval)
      class(coo_type), intent(in) :: self
      integer, intent(in) :: r0, r1
      integer(i8), intent(in) :: start(:)
      integer(i8), intent(inout) :: next(:)
      integer, intent(inout) :: tcol(:)
      real(wp), intent(inout), optional :: tval(:)
      integer(i8) :: k
      integer :: i

      next(r0:r1) = start(r0:r1) - start(r0) + 1
      do k = 1, self%nnz
         i = self%row(k)
         if (i < r0 .or. i > r1) cycle
         tcol(next(i)) = self%col(k)
         if (present(tval)) tval(next(i)) = self%val(k)
         next(i) = next(i) + 1
      end do
   end subroutine gather_band

   !> Rows r0..r1 of `a` (pattern set) from a gathered band: duplicates
   !> summed in order, columns sorted. marker(j) is where column j was last
   !> written; positions grow across rows, so it needs no reset.
   subroutine merge_band(a, r0, r1, start, tcol, tval, marker)
      type(csr_type), intent(inout) :: a
      integer, intent(in) :: r0, r1
      integer(i8), intent(in) :: start(:)
      integer, intent(in) :: tcol(:)
      real(wp), intent(in) :: tval(:)
      integer(i8), intent(inout) :: marker(:)
      integer(i8) :: p, q
      integer :: i, j

      do i = r0, r1
         q = a%rowptr(i) - 1
         do p = start(i) - start(r0) + 1, start(i + 1) - start(r0)
            j = tcol(p)
            if (marker(j) >= a%rowptr(i)) then
               a%val(marker(j)) = a%val(marker(j)) + tval(p)
            else
               q = q + 1
               marker(j) = q
               a%col(q) = j
               a%val(q) = tval(p)
            end if
         end do
         call sort_pairs(a%col(a%rowptr(i):q), a%val(a%rowptr(i):q))
      end do
   end subroutine merge_band

   !> Room for blocks of sizes m(1..nblocks) on an n x n matrix (their dofs,
   !> values and vectors uninitialised).
   subroutine blocks_init(self, n, m, error)
      class(block_list_type), intent(inout) :: self
      integer, intent(in) :: n, m(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: b, stat

      self%n = n
      self%nblocks = size(m)
      if (allocated(self%dof_ptr)) deallocate (self%dof_ptr, self%val_ptr)
      if (allocated(self%dofs)) deallocate (self%dofs, self%val, self%rhs)
      allocate (self%dof_ptr(size(m) + 1), self%val_ptr(size(m) + 1), stat=stat)
      call check_allocation(stat, 'block list', 'the block offsets', size(m) + 1, 16, error)
      if (allocated(error)) return
      self%dof_ptr(1) = 1
      self%val_ptr(1) = 1
      do b = 1, size(m)
         self%dof_ptr(b + 1) = self%dof_ptr(b) + m(b)
         self%val_ptr(b + 1) = self%val_ptr(b) + int(m(b), i8)**2
      end do
      allocate (self%dofs(self%dof_ptr(size(m) + 1) - 1), self%rhs(self%dof_ptr(size(m) + 1) - 1), stat=stat)
      call check_allocation(stat, 'block list', 'the block dofs and vectors', self%dof_ptr(size(m) + 1) - 1, 12, error)
      if (allocated(error)) return
      allocate (self%val(self%val_ptr(size(m) + 1) - 1), stat=stat)
      call check_allocation(stat, 'block list', 'the block values', self%val_ptr(size(m) + 1) - 1, 8, error)
   end subroutine blocks_init

   !> The sum of the blocks as CSR `a` (columns sorted; entries that sum to zero
   !> kept) and, with `f`, the sum of their vectors. Rows are built in parallel,
   !> each entry summed over the blocks in block order (module notes).
   subroutine blocks_to_csr(self, a, error, f)
      class(block_list_type), intent(in) :: self
      type(csr_type), intent(out) :: a
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable, intent(out), optional :: f(:)
      integer(i8), allocatable :: inc_ptr(:), next(:)
      integer, allocatable :: inc_blk(:), inc_loc(:)
      integer(i8) :: p, total
      integer :: i, b, stat, failed
      character(len=*), parameter :: who = 'block list to CSR'

      a%nrows = self%n
      a%ncols = self%n
      total = self%dof_ptr(self%nblocks + 1) - 1
      allocate (a%rowptr(self%n + 1), inc_ptr(self%n + 1), next(self%n), inc_blk(total), inc_loc(total), stat=stat)
      call check_allocation(stat, who, 'the blocks of each row', max(int(self%n, i8), total), 32, error)
      if (allocated(error)) return
      if (present(f)) then
         allocate (f(self%n), stat=stat)
         call check_allocation(stat, who, 'the summed vector', self%n, 8, error)
         if (allocated(error)) return
      end if
      ! Row i meets block inc_blk(k) at its local index inc_loc(k), k = inc_ptr(i) ..
      ! inc_ptr(i + 1) - 1, in block order (a counting sort by row).
      call row_starts(self%dofs(1:total), inc_ptr)
      next = inc_ptr(1:self%n)
      do b = 1, self%nblocks
         do p = self%dof_ptr(b), self%dof_ptr(b + 1) - 1
            i = self%dofs(p)
            inc_blk(next(i)) = b
            inc_loc(next(i)) = int(p - self%dof_ptr(b)) + 1
            next(i) = next(i) + 1
         end do
      end do
      deallocate (next)
      call row_counts(self, inc_ptr, inc_blk, a%rowptr, failed)
      if (failed /= 0) then
         call check_allocation(failed, who, 'the column marks of a thread', self%n, 4, error)
         return
      end if
      call allocate_rows(a, who, error)
      if (allocated(error)) return
      call row_sums(self, inc_ptr, inc_blk, inc_loc, a, failed)
      if (failed /= 0) then
         call check_allocation(failed, who, 'the column places of a thread', self%n, 8, error)
         return
      end if
      if (present(f)) call vector_sums(self, inc_ptr, inc_blk, inc_loc, f)
   end subroutine blocks_to_csr

   !> rowptr(i + 1) = the number of distinct columns of row i (OpenMP over rows;
   !> each thread marks columns in its own array). `failed` /= 0: a thread could not
   !> allocate its marks (the stat= value).
   subroutine row_counts(self, inc_ptr, inc_blk, rowptr, failed)
      type(block_list_type), intent(in) :: self
      integer(i8), intent(in) :: inc_ptr(:)
      integer, intent(in) :: inc_blk(:)
      integer(i8), intent(inout) :: rowptr(:)
      integer, intent(out) :: failed
      integer, allocatable :: mark(:)
      integer(i8) :: k, p, cnt
      integer :: i, j, stat

      failed = 0
      !$omp parallel default(shared) private(mark, k, p, cnt, i, j, stat) reduction(max: failed)
      allocate (mark(self%n), stat=stat)
      if (stat == 0) mark = 0
      failed = stat
      !$omp do schedule(dynamic, 256)
      do i = 1, self%n
         if (stat /= 0) cycle
         cnt = 0
         do k = inc_ptr(i), inc_ptr(i + 1) - 1
            do p = self%dof_ptr(inc_blk(k)), self%dof_ptr(inc_blk(k) + 1) - 1
               j = self%dofs(p)
               if (mark(j) == i) cycle
               mark(j) = i
               cnt = cnt + 1
            end do
         end do
         rowptr(i + 1) = cnt
      end do
      !$omp end do
      !$omp end parallel
   end subroutine row_counts

   !> The values of every row (rowptr set): entries summed over the row's blocks in
   !> block order, then the row's columns sorted (OpenMP over rows). place(j) is where
   !> this thread last wrote column j; its rows come in increasing order, so places
   !> before rowptr(i) belong to earlier rows and need no reset.
   subroutine row_sums(self, inc_ptr, inc_blk, inc_loc, a, failed)
      type(block_list_type), intent(in) :: self
      integer(i8), intent(in) :: inc_ptr(:)
      integer, intent(in) :: inc_blk(:), inc_loc(:)
      type(csr_type), intent(inout) :: a
      integer, intent(out) :: failed
      integer(i8), allocatable :: place(:)
      integer(i8) :: k, p, q, v0
      integer :: i, j, m, b, stat

      failed = 0
      !$omp parallel default(shared) private(place, k, p, q, v0, i, j, m, b, stat) reduction(max: failed)
      allocate (place(self%n), stat=stat)
      if (stat == 0) place = 0
      failed = stat
      !$omp do schedule(dynamic, 256)
      do i = 1, self%n
         if (stat /= 0) cycle
         q = a%rowptr(i) - 1
         do k = inc_ptr(i), inc_ptr(i + 1) - 1
            b = inc_blk(k)
            m = int(self%dof_ptr(b + 1) - self%dof_ptr(b))
            ! row inc_loc(k) of block b: its entries m apart (column-major)
            v0 = self%val_ptr(b) + inc_loc(k) - 1
            do p = self%dof_ptr(b), self%dof_ptr(b + 1) - 1
               j = self%dofs(p)
               if (place(j) >= a%rowptr(i)) then
                  a%val(place(j)) = a%val(place(j)) + self%val(v0)
               else
                  q = q + 1
                  place(j) = q
                  a%col(q) = j
                  a%val(q) = self%val(v0)
               end if
               v0 = v0 + m
            end do
         end do
         call sort_pairs(a%col(a%rowptr(i):q), a%val(a%rowptr(i):q))
      end do
      !$omp end do
      !$omp end parallel
   end subroutine row_sums

   !> f(i) = the sum of the blocks' vector entries on row i, in block order.
   subroutine vector_sums(self, inc_ptr, inc_blk, inc_loc, f)
      type(block_list_type), intent(in) :: self
      integer(i8), intent(in) :: inc_ptr(:)
      integer, intent(in) :: inc_blk(:), inc_loc(:)
      real(wp), intent(out) :: f(:)
      integer(i8) :: k
      integer :: i

      !$omp parallel do schedule(static) default(shared) private(k)
      do i = 1, self%n
         f(i) = 0.0_wp
         do k = inc_ptr(i), inc_ptr(i + 1) - 1
            f(i) = f(i) + self%rhs(self%dof_ptr(inc_blk(k)) + inc_loc(k) - 1)
         end do
      end do
      !$omp end parallel do
   end subroutine vector_sums

   !> `copy` = the matrix, with a failed allocation returned as an error (the
   !> intrinsic assignment copy = matrix stops the program when it cannot allocate).
   subroutine csr_copy(self, copy, error)
      class(csr_type), intent(in) :: self
      type(csr_type), intent(out) :: copy
      type(error_type), allocatable, intent(out) :: error
      integer :: stat

      stat = 0
      if (allocated(self%rowptr)) allocate (copy%rowptr, source=self%rowptr, stat=stat)
      if (stat == 0 .and. allocated(self%col)) allocate (copy%col, source=self%col, stat=stat)
      if (stat == 0 .and. allocated(self%val)) allocate (copy%val, source=self%val, stat=stat)
      call check_allocation(stat, 'csr_type%copy', 'the matrix', self%nnz(), 12, error)
      if (allocated(error)) return
      copy%nrows = self%nrows
      copy%ncols = self%ncols
   end subroutine csr_copy

   !> Number of stored entries.
   pure function csr_nnz(self) result(nnz)
      class(csr_type), intent(in) :: self
      integer(i8) :: nnz
      nnz = 0
      if (allocated(self%rowptr)) nnz = self%rowptr(self%nrows + 1) - 1
   end function csr_nnz

   !> y = A x.
   subroutine csr_matvec(self, x, y, error)
      class(csr_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: y(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      integer(i8) :: k
      real(wp) :: s
      character(len=96) :: buf

      if (size(x) /= self%ncols .or. size(y) /= self%nrows) then
         write (buf, '(i0," x ",i0," matrix, x of size ",i0,", y of size ",i0)') &
            self%nrows, self%ncols, size(x), size(y)
         call fatal_error(error, 'csr_type%matvec: '//trim(buf), stat_invalid_input)
         return
      end if
      do i = 1, self%nrows
         s = 0.0_wp
         do k = self%rowptr(i), self%rowptr(i + 1) - 1
            s = s + self%val(k)*x(self%col(k))
         end do
         y(i) = s
      end do
   end subroutine csr_matvec

   !> Matrix 1-norm: the largest column sum of magnitudes (0 for an empty matrix).
   !> A failed allocation of the column sums returns `error` (norm 0).
   function csr_norm1(self, error) result(norm)
      class(csr_type), intent(in) :: self
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: norm
      real(wp), allocatable :: colsum(:)
      integer(i8) :: k
      integer :: stat

      norm = 0.0_wp
      allocate (colsum(self%ncols), stat=stat)
      call check_allocation(stat, 'csr_type%norm1', 'the column sums', self%ncols, 8, error)
      if (allocated(error)) return
      colsum = 0.0_wp
      do k = 1, self%nnz()
         colsum(self%col(k)) = colsum(self%col(k)) + abs(self%val(k))
      end do
      if (self%ncols > 0) norm = maxval(colsum)
   end function csr_norm1

   !> Check the CSR invariants the solvers rely on: array sizes, `rowptr`
   !> non-decreasing from 1, columns in range and strictly increasing in each
   !> row, values finite. `who` names the caller in the message.
   subroutine csr_validate(a, who, error)
      type(csr_type), intent(in) :: a
      character(len=*), intent(in) :: who
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      integer(i8) :: k, nnz
      character(len=128) :: buf

      if (a%nrows < 0 .or. a%ncols < 0) then
         call fatal_error(error, who//': matrix with negative dimensions', stat_invalid_input)
         return
      end if
      if (.not. (allocated(a%rowptr) .and. allocated(a%col) .and. allocated(a%val))) then
         call fatal_error(error, who//': matrix arrays not allocated', stat_invalid_input)
         return
      end if
      if (size(a%rowptr, kind=i8) /= a%nrows + 1_i8) then
         call fatal_error(error, who//': rowptr must have nrows+1 entries', stat_invalid_input)
         return
      end if
      nnz = a%rowptr(a%nrows + 1) - 1
      if (a%rowptr(1) /= 1 .or. nnz > size(a%col, kind=i8) .or. nnz > size(a%val, kind=i8)) then
         call fatal_error(error, who//': rowptr(1) must be 1 and rowptr(nrows+1)-1 at most size(col)', &
            stat_invalid_input)
         return
      end if
      do i = 1, a%nrows
         if (a%rowptr(i + 1) < a%rowptr(i)) then
            write (buf, '("rowptr decreases at row ",i0)') i
            call fatal_error(error, who//': '//trim(buf), stat_invalid_input)
            return
         end if
         do k = a%rowptr(i), a%rowptr(i + 1) - 1
            if (a%col(k) < 1 .or. a%col(k) > a%ncols) then
               write (buf, '("column ",i0," in row ",i0," outside 1..",i0)') a%col(k), i, a%ncols
            else if (k > a%rowptr(i) .and. a%col(k) <= a%col(max(k - 1, 1_i8))) then
               write (buf, '("columns of row ",i0," not strictly increasing")') i
            else if (.not. ieee_is_finite(a%val(k))) then
               write (buf, '("value in row ",i0,", column ",i0," is not finite")') i, a%col(k)
            else
               cycle
            end if
            call fatal_error(error, who//': '//trim(buf), stat_invalid_input)
            return
         end do
      end do
   end subroutine csr_validate

end module sprc_fem_sparse
