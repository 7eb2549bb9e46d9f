!> Benchmark of the grid layer: build + classify + 2:1 balance of a 2D grid of
!> about 1M cells and a 3D grid of about 2M cells around a disk / sphere with
!> two extra boundary levels, then Q1 / Q2 nodes and hanging-node constraints.
!> Prints wall times, leaf counts, cells per second and peak memory (VmHWM).
!>
!> Run: fpm run --profile release --example bench_grid
!> The region of the benchmark: an exactly classified ball.
module sprc_bench_ball
   use sprc_core_kinds, only: wp
   use sprc_geometry_region, only: region_type, cell_outside, cell_inside, cell_cut
   implicit none
   private

   public :: ball_region

   !> Closed ball, classified exactly (nearest point and farthest corner of the box).
   type, extends(region_type) :: ball_region
      real(wp) :: centre(3) = 0.0_wp
      real(wp) :: radius = 0.0_wp
   contains
      procedure :: classify_box => ball_classify
   end type ball_region

contains

   pure integer function ball_classify(self, lo, hi) result(cls)
      class(ball_region), intent(in) :: self
      real(wp), intent(in) :: lo(:), hi(:)
      real(wp) :: near(size(lo)), far(size(lo)), c(size(lo))
      c = self%centre(1:size(lo))
      near = min(max(c, lo), hi)
      far = merge(lo, hi, abs(c - lo) > abs(c - hi))
      if (sum((far - c)**2) <= self%radius**2) then
         cls = cell_inside
      else if (sum((near - c)**2) >= self%radius**2) then
         cls = cell_outside
      else
         cls = cell_cut
      end if
   end function ball_classify

end module sprc_bench_ball

program bench_grid
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_timer, only: wall_time
   use sprc_bench_ball, only: ball_region
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
      type(ball_region) :: ball
      type(grid_type) :: grid
      type(grid_nodes_type) :: nodes
      type(hanging_type) :: hang
      type(error_type), allocatable :: error
      real(wp) :: t0, t_grid, t_nodes, t_hang
      integer :: p

      call reset_peak()
      ball%centre = [0.5013_wp, 0.4987_wp, 0.5007_wp]
      ball%radius = 0.45_wp
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
   end subroutine run

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
