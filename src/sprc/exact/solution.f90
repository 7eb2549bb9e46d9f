!> Abstract exact (analytical) linear-elastic solution: stress, displacement
!> and body force at a point, and the traction sigma*n on any plane.
!>
!> Exact solutions give the reference for energy-norm errors, the data of the
!> `exact_traction` / `exact_displacement` boundary conditions and the fields
!> of recovery tests. Evaluation is pure and reads only the object, so one
!> object may be shared by OpenMP threads.
!>
!> Voigt order 2D (xx, yy, xy), 3D (xx, yy, zz, xy, yz, xz). Evaluation cannot
!> fail: the caller passes `x(dim)` and arrays of size `dim` / `nstress`.
!>
!> The module also holds the small helpers the concrete kinds share: input
!> checks with messages naming the field, and the radial frame with its floor.
module sprc_exact_solution
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: voigt_size, analysis_name, check_material, solid, plane_stress
   implicit none
   private

   public :: exact_solution_type
   public :: init_exact_solution, check_center, check_field, is_finite, radial_frame, radius_floor, kolosov_constants

   !> Points closer to the center than `radius_floor` times the solution's
   !> reference length are evaluated at that distance (same direction; e_1 at
   !> the center itself). Such points lie outside the body (in the hole); the
   !> floor only guarantees finite numbers: with a ratio of 1e-6 the largest
   !> term, (a/r)^4 of Kirsch, stays near 1e24 times the load.
   real(wp), parameter :: radius_floor = 1.0e-6_wp

   !> An exact solution. Concrete kinds set the components in their constructor.
   type, abstract :: exact_solution_type
      !> Space dimension, 2 or 3.
      integer :: dim = 0
      !> Number of Voigt stress components: 3 (2D) or 6 (3D).
      integer :: nstress = 0
      !> Analysis kind from `sprc_core_material`: plane_stress or plane_strain in 2D, solid in 3D.
      integer :: analysis = 0
      !> Young's modulus.
      real(wp) :: young = 0.0_wp
      !> Poisson's ratio.
      real(wp) :: poisson = 0.0_wp
   contains
      !> Stress in Voigt order at a point.
      procedure(field_interface), deferred :: stress
      !> Displacement at a point.
      procedure(field_interface), deferred :: displacement
      !> Body force at a point (zero unless overridden).
      procedure :: body_force
      !> Traction sigma*n on the plane with unit normal n.
      procedure :: traction
   end type exact_solution_type

   abstract interface
      !> A field at a point: `x(dim)` in, `v(nstress)` or `v(dim)` out.
      pure subroutine field_interface(self, x, v)
         import :: exact_solution_type, wp
         class(exact_solution_type), intent(in) :: self
         real(wp), intent(in) :: x(:)
         real(wp), intent(out) :: v(:)
      end subroutine field_interface
   end interface

contains

   !> Body force b(x) with div(sigma) + b = 0; zero for the solutions here.
   pure subroutine body_force(self, x, b)
      class(exact_solution_type), intent(in) :: self
      !> Point, size dim (unused by the default).
      real(wp), intent(in) :: x(:)
      !> Body force per unit volume, size dim.
      real(wp), intent(out) :: b(:)
      associate (unused => x); end associate
      b(1:self%dim) = 0.0_wp
   end subroutine body_force

   !> Traction t = sigma(x) n. With n the body's outward normal this is the
   !> traction the exterior exerts on the body.
   pure subroutine traction(self, x, n, t)
      class(exact_solution_type), intent(in) :: self
      !> Point, size dim.
      real(wp), intent(in) :: x(:)
      !> Unit normal, size dim.
      real(wp), intent(in) :: n(:)
      !> Traction, size dim.
      real(wp), intent(out) :: t(:)
      real(wp) :: s(6)

      call self%stress(x, s(1:self%nstress))
      if (self%dim == 2) then
         t(1) = s(1)*n(1) + s(3)*n(2)
         t(2) = s(3)*n(1) + s(2)*n(2)
      else
         t(1) = s(1)*n(1) + s(4)*n(2) + s(6)*n(3)
         t(2) = s(4)*n(1) + s(2)*n(2) + s(5)*n(3)
         t(3) = s(6)*n(1) + s(5)*n(2) + s(3)*n(3)
      end if
   end subroutine traction

   !> Set and check the components shared by all kinds. `analyses` lists the
   !> analysis kinds the caller supports; `context` names it in messages.
   pure subroutine init_exact_solution(self, context, analysis, analyses, young, poisson, error)
      class(exact_solution_type), intent(inout) :: self
      character(len=*), intent(in) :: context
      integer, intent(in) :: analysis, analyses(:)
      real(wp), intent(in) :: young, poisson
      type(error_type), allocatable, intent(out) :: error
      character(len=12) :: buf

      if (.not. any(analyses == analysis)) then
         write (buf, '(i0)') analysis
         call fatal_error(error, context//': analysis '//trim(buf)//' ('//analysis_name(analysis)// &
            & ') is not supported; expected one of:'//names(analyses), stat_invalid_input)
         return
      end if
      call check_material(young, poisson, context, error)
      if (allocated(error)) return
      self%analysis = analysis
      self%nstress = voigt_size(analysis)
      self%dim = 2
      if (analysis == solid) self%dim = 3
      self%young = young
      self%poisson = poisson

   contains

      pure function names(kinds) result(text)
         integer, intent(in) :: kinds(:)
         character(len=:), allocatable :: text
         integer :: i
         text = ''
         do i = 1, size(kinds)
            text = text//' '//analysis_name(kinds(i))
         end do
      end function names

   end subroutine init_exact_solution

   !> Shear modulus mu = E/(2(1 + nu)) and Kolosov's constant kappa of a 2D
   !> solution: (3 - nu)/(1 + nu) in plane stress, 3 - 4 nu in plane strain.
   pure subroutine kolosov_constants(self, mu, kappa)
      class(exact_solution_type), intent(in) :: self
      real(wp), intent(out) :: mu, kappa

      mu = self%young/(2.0_wp*(1.0_wp + self%poisson))
      if (self%analysis == plane_stress) then
         kappa = (3.0_wp - self%poisson)/(1.0_wp + self%poisson)
      else
         kappa = 3.0_wp - 4.0_wp*self%poisson
      end if
   end subroutine kolosov_constants

   !> Check that `center` has `dim` finite entries.
   pure subroutine check_center(context, center, dim, error)
      character(len=*), intent(in) :: context
      real(wp), intent(in) :: center(:)
      integer, intent(in) :: dim
      type(error_type), allocatable, intent(out) :: error
      character(len=40) :: buf

      if (size(center) /= dim) then
         write (buf, '("has ",i0," entries, expected ",i0)') size(center), dim
         call fatal_error(error, context//': center '//trim(buf), stat_invalid_input)
      else if (.not. all(is_finite(center))) then
         call fatal_error(error, context//': center must be finite', stat_invalid_input)
      end if
   end subroutine check_center

   !> Fail with "context: field requirement, got value" unless `ok`.
   pure subroutine check_field(ok, context, field, requirement, value, error)
      logical, intent(in) :: ok
      character(len=*), intent(in) :: context, field, requirement
      real(wp), intent(in) :: value
      type(error_type), allocatable, intent(out) :: error
      character(len=32) :: buf

      if (ok) return
      write (buf, '(es16.8)') value
      call fatal_error(error, context//': '//field//' '//requirement//', got '//trim(adjustl(buf)), &
         & stat_invalid_input)
   end subroutine check_field

   !> True for a finite real (false for NaN and +-Inf).
   elemental logical function is_finite(x)
      real(wp), intent(in) :: x
      is_finite = abs(x) <= huge(x)
   end function is_finite

   !> Distance r = |dx| and unit radial direction e of an offset dx from a
   !> center, with r floored at `r_min` (e = e_1 when dx = 0).
   pure subroutine radial_frame(dx, r_min, r, e)
      real(wp), intent(in) :: dx(:)
      real(wp), intent(in) :: r_min
      real(wp), intent(out) :: r
      real(wp), intent(out) :: e(:)
      real(wp) :: length

      length = norm2(dx)
      if (length > 0.0_wp) then
         e = dx/length
      else
         e = 0.0_wp
         e(1) = 1.0_wp
      end if
      r = max(length, r_min)
   end subroutine radial_frame

end module sprc_exact_solution
