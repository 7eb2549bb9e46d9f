!> Compound cylinder and compound sphere: two concentric elastic shells of
!> different materials pressed together by a radial interference (shrink fit)
!> and an internal pressure, with a frictionless interface. Lame's solution
!> in each shell (sprc_exact_lame); e.g. Timoshenko & Goodier, Theory of
!> Elasticity, 1970, and Ugural & Fenster, Advanced Strength and Applied
!> Elasticity, "compound cylinders".
!>
!> The inner body occupies a <= r <= c, the outer body c <= r <= b (a = r_in,
!> c = r_contact, b = r_out); p_in acts on r = a, r = b is free. The radial
!> interference delta is the overlap of the undeformed shells (inner outer
!> radius minus outer inner radius, both modelled at c): the contact gap is
!> g0 = -delta. With the interface pressure p_c, each shell is a Lame shell:
!>   inner: Lame(a, c; p_in at a, p_c at c), outer: Lame(c, b; p_c at c, 0 at b),
!> and the shells stay in contact where u_o(c) - u_i(c) = delta. The radial
!> displacements at c are linear in the pressures,
!>   u_i(c) = u_i(c; p_in, 0) - f_i p_c,   u_o(c) = f_o p_c,
!> with f_i = -u_i(c; 0, 1) and f_o = u_o(c; 1, 0) the radial compliances of
!> the two shells at the interface, hence
!>   p_c = (delta + u_i(c; p_in, 0))/(f_o + f_i).
!> For the cylinder in plane stress this is
!>   f_o = c/E_o ((b^2 + c^2)/(b^2 - c^2) + nu_o),  f_i = c/E_i ((c^2 + a^2)/(c^2 - a^2) - nu_i),
!>   u_i(c; p_in, 0) = 2 a^2 c p_in/(E_i (c^2 - a^2)),
!> and with one material and p_in = 0 the textbook p_c = E delta (c^2 - a^2)(b^2 - c^2)/(2 c^3 (b^2 - a^2));
!> plane strain replaces E by E/(1 - nu^2) and nu by nu/(1 - nu). For the
!> sphere
!>   f_o = c/E_o ((1 - 2 nu_o) c^3 + (1 + nu_o) b^3/2)/(b^3 - c^3),
!>   f_i = c/E_i ((1 - 2 nu_i) c^3 + (1 + nu_i) a^3/2)/(c^3 - a^3),
!>   u_i(c; p_in, 0) = 3 (1 - nu_i) a^3 c p_in/(2 E_i (c^3 - a^3)),
!> and with one material and p_in = 0 p_c = 2 E delta (c^3 - a^3)(b^3 - c^3)/(3 (1 - nu) c^4 (b^3 - a^3)).
!> The compliances are evaluated through the Lame modules (superposition), so
!> the shell formulas exist once.
!>
!> A contact interface carries no tension: when the formula gives p_c < 0 (a
!> clearance, or suction p_in < 0) the interface opens, p_c = 0, and each
!> shell is alone (the outer one unloaded; it is held only by contact).
!>
!> The result is one exact solution per body (`inner`, `outer`), each with its
!> own material, as the per-body error norms need.
module sprc_exact_compound
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, solid, analysis_name, check_material
   use sprc_exact_solution, only: exact_solution_type, check_center, check_field, is_finite
   use sprc_exact_lame, only: lame_cylinder_type, lame_sphere_type, new_lame_cylinder, new_lame_sphere
   implicit none
   private

   public :: compound_type, new_compound_cylinder, new_compound_sphere, make_shell, radial_displacement

   !> Two concentric shells in frictionless contact at r = r_contact.
   type :: compound_type
      !> Space dimension: 2 (cylinder) or 3 (sphere).
      integer :: dim = 0
      !> Center, size dim.
      real(wp) :: center(3) = 0.0_wp
      !> Radii a < c < b.
      real(wp) :: r_in = 0.0_wp, r_contact = 0.0_wp, r_out = 0.0_wp
      !> Internal pressure and radial interference delta (> 0 for a shrink fit).
      real(wp) :: p_in = 0.0_wp, interference = 0.0_wp
      !> Interface pressure p_c >= 0.
      real(wp) :: contact_pressure = 0.0_wp
      !> Exact solution of the inner body (a <= r <= c) and of the outer body (c <= r <= b).
      class(exact_solution_type), allocatable :: inner, outer
   end type compound_type

contains

   !> Compound cylinder in plane stress or plane strain.
   subroutine new_compound_cylinder(self, center, r_in, r_contact, r_out, p_in, interference, young_inner, &
      & poisson_inner, young_outer, poisson_outer, analysis, error)
      type(compound_type), intent(out) :: self
      !> Center, 2 entries.
      real(wp), intent(in) :: center(:)
      real(wp), intent(in) :: r_in, r_contact, r_out, p_in, interference
      real(wp), intent(in) :: young_inner, poisson_inner, young_outer, poisson_outer
      !> plane_stress or plane_strain.
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error

      if (analysis /= plane_stress .and. analysis /= plane_strain) then
         call fatal_error(error, 'compound_cylinder: analysis '//analysis_name(analysis)// &
            & ' is not supported; expected one of: plane_stress plane_strain', stat_invalid_input)
         return
      end if
      call build(self, 'compound_cylinder', 2, analysis, center, [r_in, r_contact, r_out], p_in, interference, &
         & [young_inner, young_outer], [poisson_inner, poisson_outer], error)
   end subroutine new_compound_cylinder

   !> Compound sphere (3D).
   subroutine new_compound_sphere(self, center, r_in, r_contact, r_out, p_in, interference, young_inner, &
      & poisson_inner, young_outer, poisson_outer, error)
      type(compound_type), intent(out) :: self
      !> Center, 3 entries.
      real(wp), intent(in) :: center(:)
      real(wp), intent(in) :: r_in, r_contact, r_out, p_in, interference
      real(wp), intent(in) :: young_inner, poisson_inner, young_outer, poisson_outer
      type(error_type), allocatable, intent(out) :: error

      call build(self, 'compound_sphere', 3, solid, center, [r_in, r_contact, r_out], p_in, interference, &
         & [young_inner, young_outer], [poisson_inner, poisson_outer], error)
   end subroutine new_compound_sphere

   !> Check the input, solve for p_c and build both shells. radii = (a, c, b);
   !> young, poisson = (inner, outer).
   subroutine build(self, context, dim, analysis, center, radii, p_in, interference, young, poisson, error)
      type(compound_type), intent(inout) :: self
      character(len=*), intent(in) :: context
      integer, intent(in) :: dim, analysis
      real(wp), intent(in) :: center(:), radii(3), p_in, interference, young(2), poisson(2)
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), allocatable :: probe
      real(wp) :: u_load, f_inner, f_outer

      call check_input(context, dim, center, radii, p_in, interference, young, poisson, error)
      if (allocated(error)) return
      self%dim = dim
      self%center(1:dim) = center
      self%r_in = radii(1)
      self%r_contact = radii(2)
      self%r_out = radii(3)
      self%p_in = p_in
      self%interference = interference
      associate (a => radii(1), c => radii(2), b => radii(3))
         call make_shell(dim, center, a, c, p_in, 0.0_wp, young(1), poisson(1), analysis, probe, error)
         if (allocated(error)) return
         u_load = radial_displacement(probe, center, c)
         call make_shell(dim, center, a, c, 0.0_wp, 1.0_wp, young(1), poisson(1), analysis, probe, error)
         if (allocated(error)) return
         f_inner = -radial_displacement(probe, center, c)
         call make_shell(dim, center, c, b, 1.0_wp, 0.0_wp, young(2), poisson(2), analysis, probe, error)
         if (allocated(error)) return
         f_outer = radial_displacement(probe, center, c)
         self%contact_pressure = max(0.0_wp, (interference + u_load)/(f_outer + f_inner))
         call make_shell(dim, center, a, c, p_in, self%contact_pressure, young(1), poisson(1), analysis, &
            & self%inner, error)
         if (allocated(error)) return
         call make_shell(dim, center, c, b, self%contact_pressure, 0.0_wp, young(2), poisson(2), analysis, &
            & self%outer, error)
      end associate
   end subroutine build

   pure subroutine check_input(context, dim, center, radii, p_in, interference, young, poisson, error)
      character(len=*), intent(in) :: context
      integer, intent(in) :: dim
      real(wp), intent(in) :: center(:), radii(3), p_in, interference, young(2), poisson(2)
      type(error_type), allocatable, intent(out) :: error

      call check_center(context, center, dim, error)
      if (allocated(error)) return
      call check_field(radii(1) > 0.0_wp .and. is_finite(radii(1)), context, 'r_in', 'must be finite and > 0', &
         & radii(1), error)
      if (allocated(error)) return
      call check_field(radii(2) > radii(1) .and. is_finite(radii(2)), context, 'r_contact', &
         & 'must be finite and > r_in', radii(2), error)
      if (allocated(error)) return
      call check_field(radii(3) > radii(2) .and. is_finite(radii(3)), context, 'r_out', &
         & 'must be finite and > r_contact', radii(3), error)
      if (allocated(error)) return
      call check_field(is_finite(p_in), context, 'p_in', 'must be finite', p_in, error)
      if (allocated(error)) return
      call check_field(is_finite(interference), context, 'interference', 'must be finite', interference, error)
      if (allocated(error)) return
      call check_material(young(1), poisson(1), context//' inner body', error)
      if (allocated(error)) return
      call check_material(young(2), poisson(2), context//' outer body', error)
   end subroutine check_input

   !> A Lame shell r1 <= r <= r2 with pressures p1 at r1 and p2 at r2:
   !> a cylinder in 2D, a sphere in 3D.
   subroutine make_shell(dim, center, r1, r2, p1, p2, young, poisson, analysis, shell, error)
      integer, intent(in) :: dim, analysis
      real(wp), intent(in) :: center(:), r1, r2, p1, p2, young, poisson
      class(exact_solution_type), allocatable, intent(out) :: shell
      type(error_type), allocatable, intent(out) :: error
      type(lame_cylinder_type) :: cylinder
      type(lame_sphere_type) :: sphere

      if (dim == 2) then
         call new_lame_cylinder(cylinder, center, r1, r2, p1, p2, young, poisson, analysis, error)
         if (.not. allocated(error)) allocate (shell, source=cylinder)
      else
         call new_lame_sphere(sphere, center, r1, r2, p1, p2, young, poisson, error)
         if (.not. allocated(error)) allocate (shell, source=sphere)
      end if
   end subroutine make_shell

   !> Radial displacement of a shell at radius r (along e_1; it is isotropic).
   real(wp) function radial_displacement(shell, center, r)
      class(exact_solution_type), intent(in) :: shell
      real(wp), intent(in) :: center(:), r
      real(wp) :: x(3), u(3)

      associate (d => shell%dim)
         x(1:d) = center(1:d)
         x(1) = x(1) + r
         call shell%displacement(x(1:d), u(1:d))
      end associate
      radial_displacement = u(1)
   end function radial_displacement

end module sprc_exact_compound
