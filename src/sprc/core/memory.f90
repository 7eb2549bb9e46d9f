!> How much memory this process may still use, from what Linux reports: the
!> system's MemAvailable (/proc/meminfo), the cgroup v2 limit of the process
!> (memory.max - memory.current) and the soft limits on its address space and
!> data segment (getrlimit RLIMIT_AS, RLIMIT_DATA, less the current VmSize,
!> VmData of /proc/self/status). The smallest known value counts; a source that
!> is missing or unlimited is ignored (-1 when none is known: another system).
module sprc_core_memory
   use, intrinsic :: iso_c_binding, only: c_int, c_long
   use sprc_core_kinds, only: i8
   implicit none
   private

   public :: available_memory, peak_memory

   !> struct rlimit of Linux (rlim_t is unsigned long; RLIM_INFINITY reads as -1).
   type, bind(C) :: rlimit_type
      integer(c_long) :: cur = -1, max = -1
   end type rlimit_type

   !> RLIMIT_DATA and RLIMIT_AS of Linux (asm-generic/resource.h).
   integer(c_int), parameter :: rlimit_data = 2, rlimit_as = 9

   interface
      integer(c_int) function c_getrlimit(resource, limit) bind(C, name='getrlimit')
         import :: c_int, rlimit_type
         integer(c_int), value :: resource
         type(rlimit_type), intent(out) :: limit
      end function c_getrlimit
   end interface

contains

   !> Bytes this process may still allocate (-1 if unknown) and the source that
   !> bounds it ('MemAvailable', 'cgroup memory.max', 'ulimit -v', 'ulimit -d').
   subroutine available_memory(bytes, source)
      integer(i8), intent(out) :: bytes
      character(len=:), allocatable, intent(out) :: source

      bytes = -1
      source = 'unknown'
      call take(1024_i8*file_value('/proc/meminfo', 'MemAvailable:'), 'MemAvailable')
      call take(cgroup_room(), 'cgroup memory.max')
      call take(limit_room(rlimit_as, 'VmSize:'), 'ulimit -v')
      call take(limit_room(rlimit_data, 'VmData:'), 'ulimit -d')
   contains
      subroutine take(value, name)
         integer(i8), intent(in) :: value
         character(len=*), intent(in) :: name
         if (value < 0) return
         if (bytes >= 0 .and. value >= bytes) return
         bytes = value
         source = name
      end subroutine take
   end subroutine available_memory

   !> Peak resident memory of this process since it started, in bytes (VmHWM of
   !> /proc/self/status; what getrusage's ru_maxrss and `time -f %M` report), -1
   !> if unknown. It is never reset here: resetting it (/proc/self/clear_refs)
   !> would also reset what `time` reports for the whole run.
   integer(i8) function peak_memory() result(bytes)
      bytes = file_value('/proc/self/status', 'VmHWM:')
      if (bytes >= 0) bytes = 1024_i8*bytes
   end function peak_memory

   !> Soft limit `resource` less the current use (kB line `key` of
   !> /proc/self/status), -1 if unlimited or unknown.
   integer(i8) function limit_room(resource, key) result(room)
      integer(c_int), intent(in) :: resource
      character(len=*), intent(in) :: key
      type(rlimit_type) :: limit
      integer(i8) :: used

      room = -1
      if (c_getrlimit(resource, limit) /= 0) return
      if (limit%cur < 0) return
      used = file_value('/proc/self/status', key)
      if (used < 0) used = 0
      room = max(0_i8, int(limit%cur, i8) - 1024_i8*used)
   end function limit_room

   !> memory.max - memory.current of the process's cgroup (v2, mounted at
   !> /sys/fs/cgroup as in containers), -1 if unlimited or unknown.
   integer(i8) function cgroup_room() result(room)
      integer(i8) :: limit, used
      room = -1
      limit = file_value('/sys/fs/cgroup/memory.max', '')
      used = file_value('/sys/fs/cgroup/memory.current', '')
      if (limit < 0 .or. used < 0) return
      room = max(0_i8, limit - used)
   end function cgroup_room

   !> The integer after `key` on the first line that starts with it (the first
   !> line when `key` is ''), -1 if the file, the key or the number is missing
   !> ('max' included).
   integer(i8) function file_value(path, key) result(value)
      character(len=*), intent(in) :: path, key
      character(len=256) :: line
      integer :: unit, stat

      value = -1
      open (newunit=unit, file=path, status='old', action='read', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (len(key) > 0) then
            if (index(line, key) /= 1) cycle
            read (line(len(key) + 1:), *, iostat=stat) value
         else
            read (line, *, iostat=stat) value
         end if
         if (stat /= 0) value = -1
         exit
      end do
      close (unit)
   end function file_value

end module sprc_core_memory
