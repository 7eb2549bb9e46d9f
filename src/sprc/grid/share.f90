!> Per-item work of a level shared out among ranks (`mpirun -n R`, the study
!> layer's `sprc_study_partition` gives the ranks and the gather): items
!> (leaves, elements, patches) split into contiguous ranges of nearly equal
!> work (`split_by_work`), each rank computes its range, and `gather_slices`
!> joins the ranges in rank order, so every rank ends with the array a single
!> process computes, bit for bit (each item's values are computed by the same
!> code from the same inputs; sums over items are taken afterwards, in item
!> order, by the callers as in the serial code).
module sprc_grid_share
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_internal
   use sprc_core_alloc, only: check_allocation
   use sprc_core_text, only: itoa
   use sprc_recovery_patch, only: recovered_patch_type, nconstraint_kinds
   implicit none
   private

   public :: share_type, split_by_work, share_range, gather_patches

   !> Values of a packed patch record before its coefficients.
   integer, parameter :: header_size = 18 + 2*nconstraint_kinds

   !> This process's place among the ranks and the gather that joins their parts.
   type, abstract :: share_type
      integer :: rank = 0, ranks = 1
   contains
      procedure(gather_interface), deferred :: gather
      procedure :: agree
      procedure :: gather_slices
   end type share_type

   abstract interface
      !> all = the `local` arrays of the ranks concatenated in rank order
      !> (counts(r) values from rank r - 1; `local` has this rank's count).
      subroutine gather_interface(self, local, counts, all, error)
         import :: share_type, wp, i8, error_type
         class(share_type), intent(in) :: self
         real(wp), intent(in) :: local(*)
         integer(i8), intent(in) :: counts(:)
         real(wp), intent(inout) :: all(*)
         type(error_type), allocatable, intent(out) :: error
      end subroutine gather_interface
   end interface

contains

   !> Contiguous ranges of nearly equal total `work`: rank r (0-based) gets
   !> items first(r + 1) .. first(r + 2) - 1. An item goes to the rank whose
   !> share of the total holds the middle of its work (integer arithmetic:
   !> the same ranges on every rank).
   pure function split_by_work(work, ranks) result(first)
      integer, intent(in) :: work(:), ranks
      integer :: first(ranks + 1)
      integer(i8) :: total, acc
      integer :: e, owner, r

      total = max(sum(int(work, i8)), 1_i8)
      acc = 0
      first = size(work) + 1
      first(1) = 1
      r = 0
      do e = 1, size(work)
         owner = int(min((int(ranks, i8)*(2*acc + work(e)))/(2*total), int(ranks - 1, i8)))
         do while (r < owner)
            r = r + 1
            first(r + 1) = e
         end do
         acc = acc + work(e)
      end do
   end function split_by_work

   !> This process's items [lo, hi] of `n` with `work`, and every rank's
   !> range (`first`, as `split_by_work`); all of them without `share` or
   !> with one rank.
   subroutine share_range(share, work, first, lo, hi)
      class(share_type), intent(in), optional :: share
      integer, intent(in) :: work(:)
      integer, allocatable, intent(out) :: first(:)
      integer, intent(out) :: lo, hi

      if (present(share)) then
         first = split_by_work(work, share%ranks)
         lo = first(share%rank + 1)
         hi = first(share%rank + 2) - 1
      else
         first = [1, size(work) + 1]
         lo = 1
         hi = size(work)
      end if
   end subroutine share_range

   !> Every rank learns whether any failed (before a collective step, so that
   !> none waits for a rank that has returned): a rank without an error of its
   !> own gets one naming the failed rank and `what` it was doing.
   subroutine agree(self, what, error)
      class(share_type), intent(in) :: self
      character(len=*), intent(in) :: what
      type(error_type), allocatable, intent(inout) :: error
      type(error_type), allocatable :: comm_error
      real(wp) :: failed(self%ranks), mine(1)
      integer :: r

      mine = merge(1.0_wp, 0.0_wp, allocated(error))
      call self%gather(mine, spread(1_i8, 1, self%ranks), failed, comm_error)
      if (allocated(comm_error)) then
         if (.not. allocated(error)) call move_alloc(comm_error, error)
         return
      end if
      if (allocated(error) .or. all(failed == 0.0_wp)) return
      r = findloc(failed, 1.0_wp, 1) - 1
      call fatal_error(error, 'rank '//itoa(r)//' failed in '//what//' (its message is on its standard error)', &
         & stat_internal)
   end subroutine agree

   !> values(bounds(r + 1) : bounds(r + 2) - 1) from rank r, for every rank, into
   !> `values` (this rank's slice is its own values; the others are overwritten).
   subroutine gather_slices(self, bounds, values, error)
      class(share_type), intent(in) :: self
      integer(i8), intent(in) :: bounds(:)
      real(wp), intent(inout) :: values(*)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: mine(:)

      mine = values(bounds(self%rank + 1):bounds(self%rank + 2) - 1)
      call self%gather(mine, bounds(2:) - bounds(:self%ranks), values(bounds(1):bounds(self%ranks + 1) - 1), error)
   end subroutine gather_slices

   !> The patch records of every rank's patches (`first`, as `split_by_work`)
   !> gathered in patch order, with each patch's expansion rounds and element count.
   subroutine gather_patches(share, first, recs, rounds, nel, error)
      class(share_type), intent(in) :: share
      integer, intent(in) :: first(:)
      type(recovered_patch_type), intent(inout) :: recs(:)
      integer, intent(inout) :: rounds(:), nel(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), allocatable :: sizes(:), packed(:)
      integer(i8), allocatable :: at(:)
      integer(i8) :: bounds(size(first))
      integer :: ip, n, stat

      n = size(recs)
      allocate (sizes(n), at(n + 1), stat=stat)
      call check_allocation(stat, 'recovery on ranks', 'the size of each patch record', n, 16, error)
      if (allocated(error)) return
      do ip = first(share%rank + 1), first(share%rank + 2) - 1
         sizes(ip) = real(record_size(recs(ip)), wp)
      end do
      call share%gather_slices(int(first, i8), sizes, error)
      if (allocated(error)) return
      at(1) = 1
      do ip = 1, n
         at(ip + 1) = at(ip) + int(sizes(ip), i8)
      end do
      allocate (packed(at(n + 1) - 1), stat=stat)
      call check_allocation(stat, 'recovery on ranks', 'the patch records', at(n + 1) - 1, 8, error)
      if (allocated(error)) return
      do ip = first(share%rank + 1), first(share%rank + 2) - 1
         call pack_record(recs(ip), rounds(ip), nel(ip), packed(at(ip):at(ip + 1) - 1))
      end do
      bounds = at(first)
      call share%gather_slices(bounds, packed, error)
      if (allocated(error)) return
      do ip = 1, n
         if (ip >= first(share%rank + 1) .and. ip < first(share%rank + 2)) cycle
         call unpack_record(packed(at(ip):at(ip + 1) - 1), recs(ip), rounds(ip), nel(ip))
      end do
   end subroutine gather_patches

   pure integer function record_size(rec)
      type(recovered_patch_type), intent(in) :: rec
      record_size = header_size
      if (allocated(rec%coef)) record_size = record_size + size(rec%coef)
   end function record_size

   !> Integers travel as doubles (exact below 2**53).
   pure subroutine pack_record(rec, rounds, nel, v)
      type(recovered_patch_type), intent(in) :: rec
      integer, intent(in) :: rounds, nel
      real(wp), intent(out) :: v(:)
      integer :: nk

      nk = nconstraint_kinds
      v(1:6) = real([rec%dim, rec%nstress, rec%degree, rec%nterms, rec%basis_rank, rec%rank_total], wp)
      v(7:8) = real([rec%boundary_kind, merge(1, 0, rec%tolerance_bites)], wp)
      v(9:11) = rec%x0
      v(12) = rec%h
      v(13) = rec%max_dropped_ratio
      v(14:16) = real([rounds, nel, merge(1, 0, allocated(rec%coef))], wp)
      v(17:18) = 0.0_wp
      if (allocated(rec%coef)) v(17:18) = real(shape(rec%coef), wp)
      v(19:18 + nk) = real(rec%rows, wp)
      v(19 + nk:18 + 2*nk) = real(rec%ranks, wp)
      if (allocated(rec%coef)) v(header_size + 1:) = reshape(rec%coef, [size(rec%coef)])
   end subroutine pack_record

   pure subroutine unpack_record(v, rec, rounds, nel)
      real(wp), intent(in) :: v(:)
      type(recovered_patch_type), intent(inout) :: rec
      integer, intent(out) :: rounds, nel
      integer :: nk

      nk = nconstraint_kinds
      rec%dim = nint(v(1))
      rec%nstress = nint(v(2))
      rec%degree = nint(v(3))
      rec%nterms = nint(v(4))
      rec%basis_rank = nint(v(5))
      rec%rank_total = nint(v(6))
      rec%boundary_kind = nint(v(7))
      rec%tolerance_bites = nint(v(8)) == 1
      rec%x0 = v(9:11)
      rec%h = v(12)
      rec%max_dropped_ratio = v(13)
      rounds = nint(v(14))
      nel = nint(v(15))
      rec%rows = nint(v(19:18 + nk))
      rec%ranks = nint(v(19 + nk:18 + 2*nk))
      if (allocated(rec%coef)) deallocate (rec%coef)
      if (nint(v(16)) == 1) rec%coef = reshape(v(header_size + 1:), nint(v(17:18)))
   end subroutine unpack_record

end module sprc_grid_share
