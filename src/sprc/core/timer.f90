!> Wall-clock timing of the phases the report shows (mesh, quadrature,
!> assembly, solve, recovery, estimate).
module sprc_core_timer
   use sprc_core_kinds, only: wp, i8
   implicit none
   private

   public :: wall_time, timer_type

   !> Accumulating stopwatch: `start`, `stop`, read `elapsed` (seconds).
   type :: timer_type
      !> Accumulated seconds over all start/stop intervals.
      real(wp) :: elapsed = 0.0_wp
      real(wp), private :: started = -1.0_wp
   contains
      procedure :: start => timer_start
      procedure :: stop => timer_stop
      procedure :: reset => timer_reset
      procedure :: running => timer_running
   end type timer_type

contains

   !> Seconds since an arbitrary fixed origin, from the monotonic system clock.
   function wall_time() result(t)
      real(wp) :: t
      integer(i8) :: count, rate
      call system_clock(count, rate)
      t = real(count, wp)/real(rate, wp)
   end function wall_time

   subroutine timer_start(self)
      class(timer_type), intent(inout) :: self
      self%started = wall_time()
   end subroutine timer_start

   !> Stop and accumulate; stopping a timer that is not running changes nothing.
   subroutine timer_stop(self)
      class(timer_type), intent(inout) :: self
      if (self%started < 0.0_wp) return
      self%elapsed = self%elapsed + max(0.0_wp, wall_time() - self%started)
      self%started = -1.0_wp
   end subroutine timer_stop

   subroutine timer_reset(self)
      class(timer_type), intent(inout) :: self
      self%elapsed = 0.0_wp
      self%started = -1.0_wp
   end subroutine timer_reset

   logical function timer_running(self)
      class(timer_type), intent(in) :: self
      timer_running = self%started >= 0.0_wp
   end function timer_running

end module sprc_core_timer
