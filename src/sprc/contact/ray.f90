!> Where a line meets a body's named surface on its exact geometry: the root
!> finder of the contact gap (thesis eq. 3). The method, its tie rules and
!> tolerances are derived in doc/theory.md, section 6b.
!>
!> The line is x(t) = x0 + t n (n a unit vector); sought, in a search interval
!> [t_lo, t_hi] on one side of 0, the crossing of the surface nearest the start
!> that bounds the body (`body%is_boundary_on`) and, when asked (`facing`),
!> faces the line.
!> - Implicit shapes: certified enclosures of phi and grad phi . n over a
!>   segment's box (`phi_range`, `gradient_range`) drop segments without a root
!>   and isolate monotone ones, which safeguarded Newton solves to a bracket of
!>   t_tol; other segments are halved, the half nearer the start first, so the
!>   first accepted root is the nearest. A line running in the surface is split
!>   only to 2^-12 of the interval.
!> - Faceted shapes (`facet_crossing`): the facets the segment's box meets in
!>   the facet hierarchy are intersected one by one; a crossing counts on the
!>   closed facet, on the asked surface (shape or named group), facing and
!>   bounding as above; nearest wins, the lowest facet on a tie.
!> - t_tol = 8 eps (|x0|_inf + max(|a|, |b|)); a root's `tolerance` bounds
!>   |t - t_exact|; more than `max_visits` segments fails (a guard).
module sprc_contact_ray
   use sprc_core_kinds, only: wp
   use sprc_geometry_body, only: body_type, snap_tolerance, csg_subtract
   use sprc_geometry_facet_solid, only: solid_query_segment, solid_line_facet
   implicit none
   private

   public :: ray_hit_type, nearest_crossing, facet_crossing, position_tolerance, max_visits

   !> Guard on the segments one search may visit (module notes).
   integer, parameter :: max_visits = 100000

   !> A line lying in the surface is resolved to segments of this fraction of
   !> the search interval (module notes).
   real(wp), parameter :: plateau_fraction = 2.0_wp**(-12)

   !> Result of a search.
   type :: ray_hit_type
      !> A crossing was found.
      logical :: found = .false.
      !> The search exceeded max_visits (then found is false).
      logical :: exhausted = .false.
      !> Line parameter of the crossing (signed distance from x0 along n).
      real(wp) :: t = 0.0_wp
      !> Bound on |t - t_exact| (module notes).
      real(wp) :: tolerance = 0.0_wp
      !> The crossing point x0 + t n and the body's outward unit normal there.
      real(wp) :: x(3) = 0.0_wp, normal(3) = 0.0_wp
      !> Segments visited, and Newton/bisection iterations of the accepted root.
      integer :: visits = 0, iterations = 0
   end type ray_hit_type

   !> The fixed data of one search.
   type :: line_type
      integer :: dim = 0, shape = 0
      real(wp) :: x0(3) = 0.0_wp, n(3) = 0.0_wp
      !> Length of the search interval (caps the reported tolerance).
      real(wp) :: span = 0.0_wp
      !> Accept only crossings where the body's outward normal m has n . m <= 0.
      logical :: facing = .true.
   end type line_type

contains

   !> Position tolerance t_tol of the points x0 + t n, t in [a, b] (module notes).
   pure real(wp) function position_tolerance(x0, a, b) result(t_tol)
      real(wp), intent(in) :: x0(:), a, b
      t_tol = 8.0_wp*epsilon(1.0_wp)*(maxval(abs(x0)) + max(abs(a), abs(b)))
   end function position_tolerance

   !> Crossing of the line x0 + t n (n unit) with shape `shape`'s surface where
   !> it bounds `body`: the first in [t_lo, t_hi] going from the end nearer to
   !> 0 towards the other (module notes).
   !> With `facing`, only crossings where the body's outward normal opposes n
   !> (n . normal <= 0) count.
   pure subroutine nearest_crossing(body, shape, x0, n, t_lo, t_hi, facing, hit)
      class(body_type), intent(in) :: body
      integer, intent(in) :: shape
      real(wp), intent(in) :: x0(:), n(:), t_lo, t_hi
      logical, intent(in) :: facing
      type(ray_hit_type), intent(out) :: hit
      type(line_type) :: line
      logical :: done

      line%dim = size(x0)
      line%shape = shape
      line%x0(1:line%dim) = x0
      line%n(1:line%dim) = n(1:line%dim)
      line%span = abs(t_hi - t_lo)
      line%facing = facing
      if (abs(t_hi) >= abs(t_lo)) then
         call search(body, line, t_lo, t_hi, hit, done)
      else
         call search(body, line, t_hi, t_lo, hit, done)
      end if
   end subroutine nearest_crossing

   !> The crossing of the line x0 + t n (n unit) with the faceted shape
   !> `shape` of `body` where it bounds the body, on the facets of surface
   !> `surface` of the body (the shape's id: every facet; a group's id: the
   !> group's), the first in [t_lo, t_hi] from the end nearer to 0 (module
   !> notes). `facing` as nearest_crossing's.
   pure subroutine facet_crossing(body, shape, surface, x0, n, t_lo, t_hi, facing, hit)
      class(body_type), intent(in) :: body
      integer, intent(in) :: shape, surface
      real(wp), intent(in) :: x0(:), n(:), t_lo, t_hi
      logical, intent(in) :: facing
      type(ray_hit_type), intent(out) :: hit
      integer, allocatable :: list(:)
      real(wp) :: t, near, x(3), m(3), pad, tol, t_tol
      logical :: meets
      integer :: i, f, g, nlist, d, best

      d = size(x0)
      near = merge(t_lo, t_hi, abs(t_lo) <= abs(t_hi))
      best = 0
      associate (solid => body%shapes(shape)%solid)
         pad = snap_tolerance(body%shapes(shape), x0, x0) + position_tolerance(x0, t_lo, t_hi)
         call solid_query_segment(solid, x0, n, min(t_lo, t_hi), max(t_lo, t_hi), pad, list, nlist)
         hit%visits = nlist
         do i = 1, nlist
            f = list(i)
            g = 0
            if (allocated(solid%set%group)) g = solid%set%group(f)
            if (surface /= shape .and. body%group_surface(shape, g) /= surface) cycle
            call solid_line_facet(solid, f, x0, n, meets, t)
            if (.not. meets .or. t < min(t_lo, t_hi) .or. t > max(t_lo, t_hi)) cycle
            if (best > 0) then
               if (abs(t - near) > abs(hit%t - near)) cycle
               if (abs(t - near) == abs(hit%t - near) .and. f > best) cycle
            end if
            m = 0.0_wp
            m(1:d) = solid%normal(1:d, f)
            if (body%ops(shape) == csg_subtract) m = -m
            if (facing .and. dot_product(m(1:d), n(1:d)) > 0.0_wp) cycle
            x = 0.0_wp
            x(1:d) = x0(1:d) + t*n(1:d)
            t_tol = position_tolerance(x0, t, t)
            tol = snap_tolerance(body%shapes(shape), x(1:d), x(1:d))
            if (.not. body%is_boundary_on(x(1:d), shape, tol + t_tol)) cycle
            best = f
            hit%t = t
            hit%tolerance = t_tol + tol/abs(dot_product(m(1:d), n(1:d)))
            hit%x = x
            hit%normal = m
         end do
      end associate
      hit%found = best > 0
   end subroutine facet_crossing

   !> Depth-first search of the segment from `near` to `far` (either order
   !> on the t axis), nearer half first. `done` once a root is accepted or
   !> the visit guard is exceeded.
   pure recursive subroutine search(body, line, near, far, hit, done)
      class(body_type), intent(in) :: body
      type(line_type), intent(in) :: line
      real(wp), intent(in) :: near, far
      type(ray_hit_type), intent(inout) :: hit
      logical, intent(out) :: done
      real(wp) :: fmin, fmax, dmin, dmax, tol_f, f_near, f_far, mid, t_tol
      integer :: verdict

      done = .false.
      hit%visits = hit%visits + 1
      if (hit%visits > max_visits) then
         hit%exhausted = .true.
         done = .true.
         return
      end if
      call enclosures(body, line, near, far, fmin, fmax, dmin, dmax, tol_f)
      if (fmin > tol_f .or. fmax < -tol_f) return
      if (fmin >= -tol_f .and. fmax <= tol_f .and. abs(far - near) <= line%span*plateau_fraction) then
         ! The segment lies in the surface (within rounding): one candidate for all of it.
         call accept(body, line, near, far, tol_f, hit, verdict)
         done = verdict == 1
         return
      end if
      f_near = f_at(body, line, near)
      f_far = f_at(body, line, far)
      t_tol = position_tolerance(line%x0(1:line%dim), near, far)
      if (abs(far - near) <= t_tol .or. dmin > 0.0_wp .or. dmax < 0.0_wp) then
         if (.not. brackets(f_near, f_far)) return
         if (abs(far - near) <= t_tol) then
            call accept(body, line, near, far, tol_f, hit, verdict)
         else
            call solve(body, line, near, far, f_near, f_far, tol_f, hit, verdict)
         end if
         done = verdict == 1
         return
      end if
      mid = 0.5_wp*(near + far)
      call search(body, line, near, mid, hit, done)
      if (done) return
      call search(body, line, mid, far, hit, done)
   end subroutine search

   !> Enclosures of f and f' over the box spanned by the segment [a, b].
   pure subroutine enclosures(body, line, a, b, fmin, fmax, dmin, dmax, tol_f)
      class(body_type), intent(in) :: body
      type(line_type), intent(in) :: line
      real(wp), intent(in) :: a, b
      real(wp), intent(out) :: fmin, fmax, dmin, dmax, tol_f
      real(wp) :: lo(3), hi(3), gmin, gmax
      integer :: k

      associate (d => line%dim, s => body%shapes(line%shape))
         lo(1:d) = min(line%x0(1:d) + a*line%n(1:d), line%x0(1:d) + b*line%n(1:d))
         hi(1:d) = max(line%x0(1:d) + a*line%n(1:d), line%x0(1:d) + b*line%n(1:d))
         call s%phi_range(lo(1:d), hi(1:d), fmin, fmax)
         tol_f = snap_tolerance(s, lo(1:d), hi(1:d))
         dmin = 0.0_wp
         dmax = 0.0_wp
         do k = 1, d
            call s%gradient_range(lo(1:d), hi(1:d), k, gmin, gmax)
            dmin = dmin + min(line%n(k)*gmin, line%n(k)*gmax)
            dmax = dmax + max(line%n(k)*gmin, line%n(k)*gmax)
         end do
      end associate
   end subroutine enclosures

   !> Safeguarded Newton on a monotone bracket [a, b] with f(a) f(b) <= 0.
   !> verdict: 1 accepted, 0 rejected (see `accept`).
   pure subroutine solve(body, line, a0, b0, fa0, fb0, tol_f, hit, verdict)
      class(body_type), intent(in) :: body
      type(line_type), intent(in) :: line
      real(wp), intent(in) :: a0, b0, fa0, fb0, tol_f
      type(ray_hit_type), intent(inout) :: hit
      integer, intent(out) :: verdict
      real(wp) :: a, b, fa, t, f, df, t_new, probe, t_tol
      integer :: iter, side

      ! The bracket [a, b], a < b, with fa the value at a; a zero end closes it.
      a = min(a0, b0)
      b = max(a0, b0)
      fa = merge(fa0, fb0, a0 < b0)
      if (is_zero(fa)) then
         b = a
      else if (is_zero(merge(fb0, fa0, a0 < b0))) then
         a = b
      end if
      t = 0.5_wp*(a + b)
      do iter = 1, 200
         t_tol = position_tolerance(line%x0(1:line%dim), a, b)
         if (b - a <= t_tol) exit
         f = f_at(body, line, t)
         call shrink(a, b, fa, t, f)
         df = df_at(body, line, t)
         t_new = 0.5_wp*(a + b)
         if (abs(df) > 0.0_wp) then
            t_new = t - f/df
            ! A converged step (f is then at its rounding level, its sign
            ! unreliable): close the bracket by probing t_tol/2 either side.
            if (abs(f/df) < 0.5_wp*t_tol) then
               do side = -1, 1, 2
                  probe = min(b, max(a, t_new + side*0.5_wp*t_tol))
                  call shrink(a, b, fa, probe, f_at(body, line, probe))
               end do
            end if
         end if
         if (.not. (t_new > a .and. t_new < b)) t_new = 0.5_wp*(a + b)
         t = t_new
      end do
      call accept(body, line, a, b, tol_f, hit, verdict)
      hit%iterations = iter
   end subroutine solve

   !> Move the end of the bracket [a, b] whose value has the sign of f(x) to
   !> x; a zero value closes the bracket at x.
   pure subroutine shrink(a, b, fa, x, fx)
      real(wp), intent(inout) :: a, b, fa
      real(wp), intent(in) :: x, fx
      if (is_zero(fx)) then
         a = x
         b = x
      else if ((fx > 0.0_wp) .eqv. (fa > 0.0_wp)) then
         a = x
         fa = fx
      else
         b = x
      end if
   end subroutine shrink

   !> The crossing at the midpoint of the final bracket [a, b]: accepted
   !> (verdict 1) if it bounds the body and faces the line, else rejected (0).
   pure subroutine accept(body, line, a, b, tol_f, hit, verdict)
      class(body_type), intent(in) :: body
      type(line_type), intent(in) :: line
      real(wp), intent(in) :: a, b, tol_f
      type(ray_hit_type), intent(inout) :: hit
      integer, intent(out) :: verdict
      real(wp) :: t, x(3), m(3), df, t_tol

      verdict = 0
      t = 0.5_wp*(a + b)
      associate (d => line%dim)
         t_tol = position_tolerance(line%x0(1:d), a, b)
         x(1:d) = line%x0(1:d) + t*line%n(1:d)
         if (.not. body%is_boundary_on(x(1:d), line%shape, tol_f + t_tol)) return
         call body%outward_normal(x(1:d), line%shape, m(1:d))
         if (line%facing .and. dot_product(m(1:d), line%n(1:d)) > 0.0_wp) return
         df = abs(df_at(body, line, t))
         hit%found = .true.
         hit%t = t
         hit%tolerance = 0.5_wp*abs(b - a) + 0.5_wp*t_tol + tol_f/max(df, tol_f/max(line%span, tiny(df)))
         hit%x = 0.0_wp
         hit%x(1:d) = x(1:d)
         hit%normal = 0.0_wp
         hit%normal(1:d) = m(1:d)
      end associate
      verdict = 1
   end subroutine accept

   !> f = 0 (written without a real equality).
   pure logical function is_zero(f)
      real(wp), intent(in) :: f
      is_zero = .not. (f < 0.0_wp .or. f > 0.0_wp)
   end function is_zero

   !> f(a) and f(b) of opposite signs or one of them zero (no products: they
   !> could underflow to zero or overflow).
   pure logical function brackets(fa, fb)
      real(wp), intent(in) :: fa, fb
      brackets = (fa <= 0.0_wp .and. fb >= 0.0_wp) .or. (fa >= 0.0_wp .and. fb <= 0.0_wp)
   end function brackets

   pure real(wp) function f_at(body, line, t)
      class(body_type), intent(in) :: body
      type(line_type), intent(in) :: line
      real(wp), intent(in) :: t
      associate (d => line%dim)
         f_at = body%shapes(line%shape)%phi(line%x0(1:d) + t*line%n(1:d))
      end associate
   end function f_at

   pure real(wp) function df_at(body, line, t)
      class(body_type), intent(in) :: body
      type(line_type), intent(in) :: line
      real(wp), intent(in) :: t
      associate (d => line%dim)
         df_at = dot_product(body%shapes(line%shape)%gradient(line%x0(1:d) + t*line%n(1:d)), line%n(1:d))
      end associate
   end function df_at

end module sprc_contact_ray
