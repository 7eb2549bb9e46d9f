!> Exact contact pressure on the slave surface, the reference of the contact
!> report's p_max_exact and err_p_* columns.
!>
!> p = -n.sigma.n, positive in compression, with n the slave body's outward
!> normal (doc/scene.md). Two sources: a field solution of the slave body
!> (`field_pressure_type`: uniform, the rings of compound_cylinder /
!> compound_sphere), or a closed-form pressure distribution without a stress
!> field (`sprc_exact_hertz`). The study holds one `class(exact_pressure_type)`
!> and evaluates either the same way.
module sprc_exact_pressure
   use sprc_core_kinds, only: wp
   use sprc_exact_solution, only: exact_solution_type
   implicit none
   private

   public :: exact_pressure_type, field_pressure_type, new_field_pressure

   !> An exact contact pressure p(x, n) on the slave surface.
   type, abstract :: exact_pressure_type
      !> Space dimension, 2 or 3.
      integer :: dim = 0
   contains
      !> Pressure at a slave-surface point x with outward unit normal n.
      procedure(pressure_interface), deferred :: pressure
   end type exact_pressure_type

   abstract interface
      pure real(wp) function pressure_interface(self, x, n)
         import :: exact_pressure_type, wp
         class(exact_pressure_type), intent(in) :: self
         !> Point, size dim.
         real(wp), intent(in) :: x(:)
         !> Slave body's outward unit normal, size dim.
         real(wp), intent(in) :: n(:)
      end function pressure_interface
   end interface

   !> p = -n.sigma(x).n from the slave body's exact stress field.
   type, extends(exact_pressure_type) :: field_pressure_type
      class(exact_solution_type), allocatable :: field
      !> When `radius` > 0, x is first moved radially onto the sphere (circle) of
      !> that radius about `center`: a closed form with an interference models
      !> both surfaces at one radius, while the slave points lie at r_contact +
      !> delta; evaluating there would extrapolate the ring's field by
      !> delta*dsigma_rr/dr (0.5 % of p_c for a stiff hub).
      real(wp) :: center(3) = 0.0_wp, radius = 0.0_wp
   contains
      procedure :: pressure => field_pressure
   end type field_pressure_type

contains

   !> Wrap the slave body's exact solution (a copy is kept); `center` and
   !> `radius` name the interface the field is evaluated on (see the type).
   pure subroutine new_field_pressure(self, field, center, radius)
      type(field_pressure_type), intent(out) :: self
      class(exact_solution_type), intent(in) :: field
      real(wp), intent(in), optional :: center(:), radius
      self%dim = field%dim
      allocate (self%field, source=field)
      if (present(center) .and. present(radius)) then
         self%center(1:self%dim) = center(1:self%dim)
         self%radius = radius
      end if
   end subroutine new_field_pressure

   pure real(wp) function field_pressure(self, x, n)
      class(field_pressure_type), intent(in) :: self
      real(wp), intent(in) :: x(:), n(:)
      real(wp) :: t(3), y(3), r

      y(1:self%dim) = x(1:self%dim)
      if (self%radius > 0.0_wp) then
         y(1:self%dim) = x(1:self%dim) - self%center(1:self%dim)
         r = norm2(y(1:self%dim))
         if (r > 0.0_wp) y(1:self%dim) = self%center(1:self%dim) + (self%radius/r)*y(1:self%dim)
      end if
      call self%field%traction(y(1:self%dim), n, t(1:self%dim))
      field_pressure = -dot_product(n(1:self%dim), t(1:self%dim))
   end function field_pressure

end module sprc_exact_pressure
