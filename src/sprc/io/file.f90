!> Reading a whole file (or its tail) into memory, with every failure (no
!> such file, a directory, unreadable, too large, no memory) an error naming
!> the file: the one reader of scene and geometry files.
module sprc_io_file
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_io, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_core_text, only: byte_text
   implicit none
   private

   public :: file_size, read_bytes

contains

   !> Size in bytes of an existing regular file; a missing file, a directory
   !> or an unreadable file is an error naming it.
   subroutine file_size(path, size, error)
      character(len=*), intent(in) :: path
      integer(i8), intent(out) :: size
      type(error_type), allocatable, intent(out) :: error
      logical :: exists
      integer :: unit, ios
      character(len=256) :: msg

      size = -1
      inquire (file=path//'/.', exist=exists)
      if (exists) then
         call fatal_error(error, "'"//path//"' is a directory, not a file", stat_io)
         return
      end if
      inquire (file=path, exist=exists)
      if (.not. exists) then
         call fatal_error(error, "cannot read '"//path//"': no such file", stat_io)
         return
      end if
      open (newunit=unit, file=path, access='stream', form='unformatted', action='read', status='old', &
         & iostat=ios, iomsg=msg)
      if (ios /= 0) then
         call fatal_error(error, "cannot open '"//path//"': "//trim(msg), stat_io)
         return
      end if
      inquire (unit=unit, size=size)
      close (unit)
      if (size < 0) call fatal_error(error, "cannot read '"//path//"': size unknown", stat_io)
   end subroutine file_size

   !> The bytes of the file from byte `first` (1-based) to its end.
   subroutine read_bytes(path, first, size, text, error)
      character(len=*), intent(in) :: path
      integer(i8), intent(in) :: first, size
      character(len=:), allocatable, intent(out) :: text
      type(error_type), allocatable, intent(out) :: error
      integer :: unit, ios, stat
      character(len=256) :: msg

      if (size - first + 1 > int(huge(1), i8)) then
         call fatal_error(error, "'"//path//"': "//byte_text(real(size, wp))//' is too large a file', stat_invalid_input)
         return
      end if
      allocate (character(len=int(max(0_i8, size - first + 1))) :: text, stat=stat)
      call check_allocation(stat, "read '"//path//"'", 'the bytes of the file', size - first + 1, 1, error)
      if (allocated(error) .or. len(text) == 0) return
      open (newunit=unit, file=path, access='stream', form='unformatted', action='read', status='old', &
         & iostat=ios, iomsg=msg)
      if (ios == 0) read (unit, pos=first, iostat=ios, iomsg=msg) text
      if (ios /= 0) call fatal_error(error, "cannot read '"//path//"': "//trim(msg), stat_io)
      close (unit, iostat=ios)
   end subroutine read_bytes

end module sprc_io_file
