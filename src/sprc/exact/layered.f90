!> Layered cylinder and layered sphere: n concentric elastic rings (shells) of
!> their own materials, each pressed on the next by a radial interference
!> (a stack of shrink fits) and loaded by an inner and an outer pressure,
!> with frictionless interfaces. Lame's solution in each ring
!> (sprc_exact_lame); the compound cylinder and sphere (sprc_exact_compound)
!> are the case n = 2.
!>
!> Ring i occupies r_(i-1) <= r <= r_i with pressure p_(i-1) inside and p_i
!> outside (p_0 = p_in, p_n = p_out), so the radial stress is continuous by
!> construction; the interface pressures p_1..p_(n-1) solve the tridiagonal
!> system of the interferences (doc/theory.md, section 6a), solved densely
!> since n is a handful.
!>
!> An interface carries no tension: one whose pressure comes out negative
!> opens (p_j = 0, its equation dropped), and an open one whose rings would
!> overlap closes; this active set is iterated until it repeats (at most
!> 2 (n - 1) + 1 solves for the monotone cases; more is an error).
!>
!> Real radii (`shifts`): a scene models interface j with the inner ring's
!> outer surface at r_j + delta_j and the outer ring's bore at r_j; the closed
!> form on the nominal radii would bound the FE error from below by about
!> delta/r. With shifts the interface conditions are the ones the contact
!> formulation converges to (doc/theory.md, section 6a).
!>
!> The result is one exact solution per ring (`rings(i)%field`), each with
!> its own material, as the per-body error norms need.
module sprc_exact_layered
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_not_converged
   use sprc_core_text, only: itoa
   use sprc_core_lapack, only: dgesv
   use sprc_core_material, only: plane_stress, plane_strain, solid, analysis_name, check_material
   use sprc_exact_solution, only: exact_solution_type, check_center, check_field, is_finite
   use sprc_exact_compound, only: make_shell, radial_displacement
   implicit none
   private

   public :: layered_type, ring_type, new_layered

   !> One ring's exact solution.
   type :: ring_type
      class(exact_solution_type), allocatable :: field
   end type ring_type

   !> n concentric rings in frictionless contact (module notes).
   type :: layered_type
      !> Space dimension: 2 (cylinder) or 3 (sphere).
      integer :: dim = 0
      real(wp) :: center(3) = 0.0_wp
      !> Radii r_0 < ... < r_n (n + 1 values).
      real(wp), allocatable :: radii(:)
      !> Pressures p_0 = p_in, the interface pressures p_1 .. p_(n-1) (>= 0) on the
      !> outer rings' bores, p_n = p_out.
      real(wp), allocatable :: pressure(:)
      !> Each ring's outer radius: r_i, or with real radii r_i + delta_i (i < n).
      real(wp), allocatable :: outer_radii(:)
      !> Each ring's field (n).
      type(ring_type), allocatable :: rings(:)
   end type layered_type

contains

   !> n = size(radii) - 1 rings: a cylinder (dim 2, plane stress or plane
   !> strain) or a sphere (dim 3, solid); interference(j) of interface j
   !> (n - 1 values), young(i) and poisson(i) of ring i.
   !> With `shifts` (n - 1 lengths, normally the interferences in length
   !> units) ring j ends at r_j + shifts(j): the rings lie on their real radii
   !> (module notes, "Real radii"); without, on the nominal ones.
   subroutine new_layered(self, dim, analysis, center, radii, interference, p_in, p_out, young, poisson, error, &
         & shifts)
      type(layered_type), intent(out) :: self
      integer, intent(in) :: dim, analysis
      real(wp), intent(in) :: center(:), radii(:), interference(:), p_in, p_out, young(:), poisson(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: shifts(:)
      character(len=:), allocatable :: context
      real(wp), allocatable :: alpha(:, :), beta(:, :), ratio(:)
      integer :: n, i

      context = merge('layered_cylinder', 'layered_sphere  ', dim == 2)
      context = trim(context)
      call check_input(context, dim, analysis, center, radii, interference, p_in, p_out, young, poisson, error)
      if (allocated(error)) return
      n = size(radii) - 1
      if (present(shifts)) then
         if (size(shifts) /= n - 1 .or. .not. all(abs(shifts) < radii(3:) - radii(2:n))) then
            call fatal_error(error, context//': shifts must be n - 1 = '//itoa(n - 1)//' lengths, each less than '// &
               & 'the next ring''s width', stat_invalid_input)
            return
         end if
      end if
      self%dim = dim
      self%center(1:dim) = center
      self%radii = radii
      self%outer_radii = radii(2:)
      if (present(shifts)) self%outer_radii(1:n - 1) = radii(2:n) + shifts(1:n - 1)
      ! ratio(i): ring i's outer pressure over the next ring's bore pressure (force balance).
      ratio = [((radii(i + 1)/self%outer_radii(i))**(dim - 1), i=1, n)]
      ! alpha(s, i), beta(s, i): ring i's radial displacement at its inner (s = 1) and
      ! outer (s = 2) radius under a unit inner pressure, or under its outer pressure
      ! for a unit pressure on the next ring's bore.
      allocate (alpha(2, n), beta(2, n), self%rings(n))
      do i = 1, n
         call unit_response(dim, analysis, center, radii(i), self%outer_radii(i), young(i), poisson(i), alpha(:, i), &
            & beta(:, i), error)
         if (allocated(error)) return
         beta(:, i) = ratio(i)*beta(:, i)
      end do
      call interface_pressures(n, alpha, beta, interference, p_in, p_out, self%pressure, error)
      if (allocated(error)) then
         error%message = context//': '//error%message
         return
      end if
      do i = 1, n
         call make_shell(dim, center, radii(i), self%outer_radii(i), self%pressure(i), ratio(i)*self%pressure(i + 1), &
            & young(i), poisson(i), analysis, self%rings(i)%field, error)
         if (allocated(error)) return
      end do
   end subroutine new_layered

   !> A ring's radial displacement at r1 and r2 under p = 1 at r1 (alpha)
   !> and at r2 (beta) alone.
   subroutine unit_response(dim, analysis, center, r1, r2, young, poisson, alpha, beta, error)
      integer, intent(in) :: dim, analysis
      real(wp), intent(in) :: center(:), r1, r2, young, poisson
      real(wp), intent(out) :: alpha(2), beta(2)
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), allocatable :: probe

      call make_shell(dim, center, r1, r2, 1.0_wp, 0.0_wp, young, poisson, analysis, probe, error)
      if (allocated(error)) return
      alpha = [radial_displacement(probe, center, r1), radial_displacement(probe, center, r2)]
      call make_shell(dim, center, r1, r2, 0.0_wp, 1.0_wp, young, poisson, analysis, probe, error)
      if (allocated(error)) return
      beta = [radial_displacement(probe, center, r1), radial_displacement(probe, center, r2)]
   end subroutine unit_response

   !> p(0:n) = (p_in, p_1 .. p_(n-1), p_out) with the interface conditions and
   !> the active set of the module notes.
   subroutine interface_pressures(n, alpha, beta, interference, p_in, p_out, p, error)
      integer, intent(in) :: n
      real(wp), intent(in) :: alpha(:, :), beta(:, :), interference(:), p_in, p_out
      real(wp), allocatable, intent(out) :: p(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: a(max(n - 1, 1), max(n - 1, 1)), rhs(max(n - 1, 1)), separation
      logical :: closed(max(n - 1, 1)), next(max(n - 1, 1))
      integer :: ipiv(max(n - 1, 1)), j, it, info, m

      allocate (p(n + 1))
      p = 0.0_wp
      p(1) = p_in
      p(n + 1) = p_out
      m = n - 1
      if (m == 0) return
      closed = .true.
      do it = 1, 2*m + 1
         a = 0.0_wp
         rhs = 0.0_wp
         do j = 1, m
            if (.not. closed(j)) then
               a(j, j) = 1.0_wp
               cycle
            end if
            ! Interface j lies between ring j (its outer radius, s = 2) and ring j + 1 (inner, s = 1).
            a(j, j) = alpha(1, j + 1) - beta(2, j)
            rhs(j) = interference(j)
            if (j > 1) then
               if (closed(j - 1)) a(j, j - 1) = -alpha(2, j)
            else
               rhs(j) = rhs(j) + alpha(2, 1)*p_in
            end if
            if (j < m) then
               if (closed(j + 1)) a(j, j + 1) = beta(1, j + 1)
            else
               rhs(j) = rhs(j) - beta(1, n)*p_out
            end if
         end do
         call dgesv(m, 1, a, m, ipiv, rhs, m, info)
         if (info /= 0) then
            call fatal_error(error, 'the interface system is singular (LAPACK dgesv info '//itoa(info)//')', &
               & stat_invalid_input)
            return
         end if
         p(2:n) = merge(rhs(1:m), 0.0_wp, closed(1:m))
         do j = 1, m
            separation = alpha(1, j + 1)*p(j + 1) + beta(1, j + 1)*p(j + 2) - alpha(2, j)*p(j) - beta(2, j)*p(j + 1)
            if (closed(j)) then
               next(j) = p(j + 1) >= 0.0_wp
            else
               next(j) = separation < interference(j)
            end if
         end do
         if (all(next(1:m) .eqv. closed(1:m))) return
         closed = next
      end do
      call fatal_error(error, 'the open and closed interfaces did not settle in '//itoa(2*m + 1)//' solves', &
         & stat_not_converged)
   end subroutine interface_pressures

   pure subroutine check_input(context, dim, analysis, center, radii, interference, p_in, p_out, young, poisson, error)
      character(len=*), intent(in) :: context
      integer, intent(in) :: dim, analysis
      real(wp), intent(in) :: center(:), radii(:), interference(:), p_in, p_out, young(:), poisson(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: i, n

      n = size(radii) - 1
      if ((dim == 2 .and. analysis /= plane_stress .and. analysis /= plane_strain) .or. &
         & (dim == 3 .and. analysis /= solid) .or. (dim /= 2 .and. dim /= 3)) then
         call fatal_error(error, context//': analysis '//analysis_name(analysis)//' is not supported in '// &
            & itoa(dim)//'D', stat_invalid_input)
         return
      end if
      call check_center(context, center, dim, error)
      if (allocated(error)) return
      if (n < 1 .or. size(interference) /= n - 1 .or. size(young) /= n .or. size(poisson) /= n) then
         call fatal_error(error, context//': '//itoa(size(radii))//' radii, '//itoa(size(interference))// &
            & ' interferences, '//itoa(size(young))//' materials; expected n + 1, n - 1, n for n >= 1 rings', &
            & stat_invalid_input)
         return
      end if
      call check_field(radii(1) > 0.0_wp .and. is_finite(radii(1)), context, 'radii(1)', 'must be finite and > 0', &
         & radii(1), error)
      do i = 2, n + 1
         if (allocated(error)) return
         call check_field(radii(i) > radii(i - 1) .and. is_finite(radii(i)), context, 'radii('//itoa(i)//')', &
            & 'must be finite and exceed the radius before it', radii(i), error)
      end do
      do i = 1, n - 1
         if (allocated(error)) return
         call check_field(is_finite(interference(i)), context, 'interference('//itoa(i)//')', 'must be finite', &
            & interference(i), error)
      end do
      if (allocated(error)) return
      call check_field(is_finite(p_in), context, 'p_in', 'must be finite', p_in, error)
      if (allocated(error)) return
      call check_field(is_finite(p_out), context, 'p_out', 'must be finite', p_out, error)
      do i = 1, n
         if (allocated(error)) return
         call check_material(young(i), poisson(i), context//' ring '//itoa(i), error)
      end do
   end subroutine check_input

end module sprc_exact_layered
