!> An allocation that fails is an error, never a crash: a routine
!> allocates with `stat=` and passes the status to `check_allocation`, which
!> leaves `error` unallocated on success and otherwise returns
!> `stat_out_of_memory` with a message naming the routine, what was being
!> allocated and how large it was (entries, bytes). The memory estimate of a
!> level (sprc_study_budget) refuses most levels that cannot fit before they
!> start; this is the net under it (an estimate that was low, another process
!> that took the memory meanwhile, a caller of the library with its own sizes).
!>
!> The rule for which allocations take `stat=`:
!> - every allocation whose size follows from the input: cells, leaves, nodes,
!>   dofs, nonzeros, quadrature points, patches, points, the number of scene
!>   groups or values, the size of a file; growth of such an array included;
!> - temporaries of such a size count too: an automatic array or an
!>   array-valued expression assigned to an allocatable (gfortran then
!>   allocates on the heap and aborts when it cannot) of about one value per
!>   cell, node, dof or nonzero is written as an explicit allocation;
!> - allocations of a fixed or dimension-bounded size stay as they are: the
!>   dim, 3, 6, 2**dim, 3**dim sized ones, an element's nodes or dofs, an
!>   error object or a short message string; so do the per-cell scratch
!>   arrays of the cut-cell quadrature (bounded by the quadrature order and
!>   depth, not by the size of the problem), per-patch work arrays (bounded
!>   by the patch size), and the parsed groups of a scene file (bounded by
!>   its 16 MB limit and max_groups, max_items, max_values of io/namelist).
!>   Their failure would mean the process has almost no memory left, which a
!>   message could not report either.
module sprc_core_alloc
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_out_of_memory
   use sprc_core_text, only: itoa, byte_text
   implicit none
   private

   public :: check_allocation

   !> The entry count as a default or an 8-byte integer.
   interface check_allocation
      module procedure check_allocation_i8, check_allocation_i4
   end interface check_allocation

contains

   !> Nothing when `stat` is 0; otherwise `error` (stat_out_of_memory) saying that
   !> `who` could not allocate `what`: `entries` entries of `entry_bytes` bytes.
   pure subroutine check_allocation_i8(stat, who, what, entries, entry_bytes, error)
      !> The `stat=` of the allocate statement.
      integer, intent(in) :: stat
      !> The routine, e.g. 'grid build'.
      character(len=*), intent(in) :: who
      !> What was being allocated, e.g. 'the leaf arrays'.
      character(len=*), intent(in) :: what
      !> Number of entries (values, leaves, rows) asked for.
      integer(i8), intent(in) :: entries
      !> Bytes per entry (all the arrays of the statement together).
      integer, intent(in) :: entry_bytes
      type(error_type), allocatable, intent(out) :: error

      if (stat == 0) return
      call fatal_error(error, who//': out of memory: cannot allocate '//what//' ('//itoa(entries)// &
         & ' entries of '//itoa(entry_bytes)//' bytes, '// &
         & byte_text(real(entries, wp)*real(entry_bytes, wp))//')', stat_out_of_memory)
   end subroutine check_allocation_i8

   pure subroutine check_allocation_i4(stat, who, what, entries, entry_bytes, error)
      integer, intent(in) :: stat
      character(len=*), intent(in) :: who, what
      integer, intent(in) :: entries, entry_bytes
      type(error_type), allocatable, intent(out) :: error
      call check_allocation_i8(stat, who, what, int(entries, i8), entry_bytes, error)
   end subroutine check_allocation_i4

end module sprc_core_alloc
