!> Benchmark of the grid layer: build + classify + 2:1 balance of a 2D grid of
!> about 1M cells and a 3D grid of about 2M cells around a disk / sphere with
!> two extra boundary levels, then Q1 / Q2 nodes and hanging-node constraints,
!> then `build_adapted` from that grid: the same levels (the same grid back),
!> and one level finer on the half x < 1/2 and one coarser on the rest.
!> Prints wall times, leaf counts, cells per second and peak memory (VmHWM).
!>
!> The body is a disk / sphere from the geometry layer (certified box
!> classification), off-centre so that the boundary does not follow grid lines.
!> Level 10 in 2D is 2^20 = 1M cells, level 7 in 3D 2^21 = 2M cells, before
!> the two boundary levels.
!>
!> Run: fpm run --profile release --example bench_grid [-- 2|3]
program bench_grid
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_timer, only: wall_time
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere
   use sprc_geometry_body, only: body_type, new_body, csg_add
   use sprc_grid_tree, only: grid_type
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_grid_hanging, only: hanging_type
   implicit none

   character(len=8) :: arg

   ! Optional argument 2 or 3 runs one dimension only.
   arg = ''
   if (command_argument_count() > 0) call get_command_argument(1, arg)
   if (arg /= '3') call run(2, 10, 2)
   if (arg /= '2') call run(3, 7, 2)

contains

   subroutine run(dim, level, refine)
      integer, intent(in) :: dim, level, refine
      type(body_type) :: ball
      type(shape_type) :: shape
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(error_type), allocatable :: error
      real(wp) :: t0, t_grid, t_nodes, t_hang
      integer :: p

      call reset_peak()
      if (dim == 2) then
         call new_disk(shape, 'boundary', [0.5013_wp, 0.4987_wp], 0.45_wp, error)
      else
         call new_sphere(shape, 'boundary', [0.5013_wp, 0.4987_wp, 0.5007_wp], 0.45_wp, error)
      end if
      if (allocated(error)) return
      call new_body(ball, 'ball')
      call ball%add_shape(csg_add, shape, error)
      if (allocated(error)) return
      t0 = wall_time()
      call grid%build(ball, dim, [0.0_wp, 0.0_wp, 0.0_wp], 1.0_wp, level, refine, error)
      t_grid = wall_time() - t0
      if (allocated(error)) then
         write (*, '(a)') error%message
         return
      end if
      write (*, '(a,i0,a,i0,a,i0)') 'dim ', dim, '  level ', level, '  refine_boundary ', refine
      write (*, '(a,i0,a,i0,a,i0,a,i0)') '  leaves ', grid%n_leaves, '  (internal ', sum(grid%n_inside), &
         & ', cut ', sum(grid%n_cut), '), balance splits ', grid%n_balance_splits
      write (*, '(a,f8.3,a,es10.3,a,f9.1,a)') '  build + classify + balance: ', t_grid, ' s, ', &
         & real(grid%n_leaves, wp)/t_grid, ' leaves/s, peak ', peak_mib(), ' MiB'
      do p = 1, 2
         t0 = wall_time()
         call nodes%build(grid, p, error)
         t_nodes = wall_time() - t0
         if (allocated(error)) return
         t0 = wall_time()
         call hang%build(grid, nodes, error)
         t_hang = wall_time() - t0
         if (allocated(error)) return
         write (*, '(a,i0,a,i0,a,f8.3,a,i0,a,f8.3,a,f9.1,a)') '  Q', p, ': nodes ', nodes%n_nodes, ' in ', t_nodes, &
            & ' s; hanging ', hang%n_hanging, ' in ', t_hang, ' s, peak ', peak_mib(), ' MiB'
      end do
      call adapted(ball, grid, t_grid, level + refine)
   end subroutine run

   !> `build_adapted` from `grid` (built in t_build seconds): the same levels, then one
   !> level finer where x < 1/2 and one coarser elsewhere.
   subroutine adapted(ball, grid, t_build, max_level)
      type(body_type), intent(in) :: ball
      type(grid_type), intent(in) :: grid
      real(wp), intent(in) :: t_build
      integer, intent(in) :: max_level
      type(grid_type) :: new
      type(error_type), allocatable :: error
      integer, allocatable :: target(:)
      real(wp) :: t0, t, lo(3), hi(3)
      integer :: j, d

      d = grid%dim
      t0 = wall_time()
      call new%build_adapted(ball, grid, grid%leaf_level, max_level, error)
      t = wall_time() - t0
      if (allocated(error)) return
      write (*, '(a,i0,a,f8.3,a,f6.2,a)') '  build_adapted, same levels: leaves ', new%n_leaves, ' in ', t, &
         & ' s (', t/t_build, ' x build)'
      target = grid%leaf_level
      do j = 1, grid%n_leaves
         call grid%leaf_box(j, lo(1:d), hi(1:d))
         target(j) = target(j) + merge(1, -1, hi(1) <= 0.5_wp)
      end do
      t0 = wall_time()
      call new%build_adapted(ball, grid, target, max_level + 1, error)
      t = wall_time() - t0
      if (allocated(error)) return
      write (*, '(a,i0,a,i0,a,f8.3,a,f9.1,a)') '  build_adapted, finer | coarser halves: leaves ', new%n_leaves, &
         & ', balance splits ', new%n_balance_splits, ' in ', t, ' s, peak ', peak_mib(), ' MiB'
   end subroutine adapted

   !> Reset the peak-memory mark (Linux: write 5 to /proc/self/clear_refs); harmless if refused.
   subroutine reset_peak()
      integer :: unit, stat
      open (newunit=unit, file='/proc/self/clear_refs', action='write', status='old', iostat=stat)
      if (stat /= 0) return
      write (unit, '(a)', iostat=stat) '5'
      close (unit, iostat=stat)
   end subroutine reset_peak

   !> Peak resident memory of the process (VmHWM in /proc/self/status), MiB; -1 if unknown.
   real(wp) function peak_mib()
      character(len=256) :: line
      integer :: unit, stat
      integer(i8) :: kib
      peak_mib = -1.0_wp
      open (newunit=unit, file='/proc/self/status', action='read', status='old', iostat=stat)
      if (stat /= 0) return
      do
         read (unit, '(a)', iostat=stat) line
         if (stat /= 0) exit
         if (line(1:6) == 'VmHWM:') then
            read (line(7:), *, iostat=stat) kib
            if (stat == 0) peak_mib = real(kib, wp)/1024.0_wp
            exit
         end if
      end do
      close (unit)
   end function peak_mib

end program bench_grid
