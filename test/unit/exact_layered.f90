!> Tests of the layered cylinder and sphere (sprc_exact_layered): n
!> concentric rings, one interference fit per interface, inner and outer
!> pressure. Checked independently of how the interface pressures were
!> solved: equilibrium and the strain-displacement-stress relation in every
!> ring by central differences, the fields' own radial displacement jump at
!> every interface (= its interference) and traction continuity there, the
!> boundary tractions, the reduction to compound_cylinder / compound_sphere
!> for n = 2, and an interface that opens.
module sprc_test_exact_layered
   use sprc_core_kinds, only: wp, i8
   use sprc_core_material, only: plane_stress, plane_strain, solid, analysis_name
   use sprc_exact_compound, only: compound_type, new_compound_cylinder, new_compound_sphere
   use sprc_exact_layered, only: layered_type, new_layered
   use sprc_test_exact, only: check_equilibrium_fd, check_compatibility_fd, shell_points, npoint
   use sprc_testsuite, only: unittest_type, new_unittest, check, error_type
   implicit none
   private

   public :: collect_exact_layered

   !> Round-off tier of a few dozen operations on O(1) quantities.
   real(wp), parameter :: roundoff = 64.0_wp*epsilon(1.0_wp)
   !> Three rings (the acceptance's stack): radii, interferences, materials.
   real(wp), parameter :: radii(4) = [1.0_wp, 1.5_wp, 2.0_wp, 2.5_wp]
   real(wp), parameter :: fits(2) = [1.5e-3_wp, 2.0e-3_wp]
   real(wp), parameter :: young(3) = [3.0_wp, 1.0_wp, 2.0_wp], poisson(3) = [0.3_wp, 0.25_wp, 0.35_wp]
   real(wp), parameter :: p_in = 1.0e-2_wp, p_out = 2.0e-3_wp
   integer, parameter :: analyses(3) = [plane_stress, plane_strain, solid]

contains

   subroutine collect_exact_layered(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('layered_fd', test_layered_fd), &
         new_unittest('layered_interfaces', test_layered_interfaces), &
         new_unittest('layered_boundary', test_layered_boundary), &
         new_unittest('layered_two_rings_is_compound', test_layered_compound), &
         new_unittest('layered_open_interface', test_layered_open), &
         new_unittest('layered_real_radii', test_layered_real), &
         new_unittest('layered_errors', test_layered_errors) &
         ]
   end subroutine collect_exact_layered

   !> Case k: 1 plane stress, 2 plane strain (cylinders), 3 sphere.
   subroutine make_case(k, ly, label, error)
      integer, intent(in) :: k
      type(layered_type), intent(out) :: ly
      character(len=:), allocatable, intent(out) :: label
      type(error_type), allocatable, intent(out) :: error
      integer :: analysis, dim
      analysis = analyses(k)
      dim = merge(3, 2, k == 3)
      label = analysis_name(analysis)
      call new_layered(ly, dim, analysis, spread(0.25_wp, 1, dim), radii, fits, p_in, p_out, young, poisson, error)
   end subroutine make_case

   subroutine test_layered_fd(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      character(len=:), allocatable :: label
      integer(i8) :: seed
      integer :: k, i
      real(wp) :: scale

      seed = 17_i8
      do k = 1, 3
         call make_case(k, ly, label, error)
         if (allocated(error)) return
         scale = maxval(abs(ly%pressure))
         associate (x0 => ly%center(1:ly%dim))
            do i = 1, 3
               call check_equilibrium_fd(error, ly%rings(i)%field, shell_points(x0, radii(i), radii(i + 1), seed), &
                  & radii(1), scale, label//' ring')
               if (allocated(error)) return
               call check_compatibility_fd(error, ly%rings(i)%field, shell_points(x0, radii(i), radii(i + 1), seed), &
                  & radii(1), scale, label//' ring')
               if (allocated(error)) return
            end do
         end associate
      end do
   end subroutine test_layered_fd

   !> At every interface r_j, in random directions e: the fields' radial
   !> displacement jump is the interference, the tangential one zero, and
   !> both rings' tractions are -p_j e with p_j >= 0.
   subroutine test_layered_interfaces(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      character(len=:), allocatable :: label
      real(wp), allocatable :: points(:, :)
      real(wp) :: e(3), x(3), ui(3), uo(3), ti(3), to(3), u_scale, s_scale
      integer(i8) :: seed
      integer :: k, j, ip

      seed = 19_i8
      do k = 1, 3
         call make_case(k, ly, label, error)
         if (allocated(error)) return
         s_scale = maxval(abs(ly%pressure))
         associate (d => ly%dim, x0 => ly%center(1:ly%dim))
            do j = 1, 2
               call check(error, ly%pressure(j + 1) > 0.0_wp, label//': both interfaces closed')
               if (allocated(error)) return
               points = shell_points(x0, 1.0_wp, 1.0_wp, seed)
               do ip = 1, npoint
                  e(1:d) = points(:, ip) - x0
                  x(1:d) = x0 + radii(j + 1)*e(1:d)
                  call ly%rings(j)%field%displacement(x(1:d), ui(1:d))
                  call ly%rings(j + 1)%field%displacement(x(1:d), uo(1:d))
                  u_scale = max(norm2(ui(1:d)), norm2(uo(1:d)))
                  call check(error, norm2(uo(1:d) - ui(1:d) - fits(j)*e(1:d)), 0.0_wp, roundoff*u_scale, &
                     & label//': displacement jump = interference e_r')
                  if (allocated(error)) return
                  call ly%rings(j)%field%traction(x(1:d), e(1:d), ti(1:d))
                  call ly%rings(j + 1)%field%traction(x(1:d), e(1:d), to(1:d))
                  call check(error, norm2(ti(1:d) - to(1:d)), 0.0_wp, roundoff*s_scale, label//': traction continuity')
                  if (allocated(error)) return
                  call check(error, norm2(ti(1:d) + ly%pressure(j + 1)*e(1:d)), 0.0_wp, roundoff*s_scale, &
                     & label//': interface traction -p_j e_r')
                  if (allocated(error)) return
               end do
            end do
         end associate
      end do
   end subroutine test_layered_interfaces

   !> sigma n = -p_in n on r_0 (n = -e_r) and -p_out n on r_n.
   subroutine test_layered_boundary(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      character(len=:), allocatable :: label
      real(wp), allocatable :: points(:, :)
      real(wp) :: e(3), t(3), s_scale
      integer(i8) :: seed
      integer :: k, ip

      seed = 23_i8
      do k = 1, 3
         call make_case(k, ly, label, error)
         if (allocated(error)) return
         s_scale = maxval(abs(ly%pressure))
         associate (d => ly%dim, x0 => ly%center(1:ly%dim))
            points = shell_points(x0, 1.0_wp, 1.0_wp, seed)
            do ip = 1, npoint
               e(1:d) = points(:, ip) - x0
               call ly%rings(1)%field%traction(x0 + radii(1)*e(1:d), -e(1:d), t(1:d))
               call check(error, norm2(t(1:d) - p_in*e(1:d)), 0.0_wp, roundoff*s_scale, label//': p_in on r_0')
               if (allocated(error)) return
               call ly%rings(3)%field%traction(x0 + radii(4)*e(1:d), e(1:d), t(1:d))
               call check(error, norm2(t(1:d) + p_out*e(1:d)), 0.0_wp, roundoff*s_scale, label//': p_out on r_n')
               if (allocated(error)) return
            end do
         end associate
      end do
   end subroutine test_layered_boundary

   !> n = 2 with p_out = 0 is the compound cylinder / sphere: the same
   !> interface pressure and the same fields at points of both rings.
   subroutine test_layered_compound(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      type(compound_type) :: cc
      real(wp), allocatable :: points(:, :)
      real(wp) :: s1(6), s2(6), u1(3), u2(3), x0(3)
      integer(i8) :: seed
      integer :: k, ip, d, ns, analysis, ring

      seed = 29_i8
      do k = 1, 3
         analysis = analyses(k)
         d = merge(3, 2, k == 3)
         ns = merge(6, 3, d == 3)
         x0 = 0.1_wp
         call new_layered(ly, d, analysis, x0(1:d), [1.0_wp, 1.5_wp, 2.0_wp], [1.0e-3_wp], 1.0e-3_wp, 0.0_wp, &
            & [2.0_wp, 1.0_wp], [0.3_wp, 0.25_wp], error)
         if (allocated(error)) return
         if (d == 2) then
            call new_compound_cylinder(cc, x0(1:d), 1.0_wp, 1.5_wp, 2.0_wp, 1.0e-3_wp, 1.0e-3_wp, 2.0_wp, 0.3_wp, &
               & 1.0_wp, 0.25_wp, analysis, error)
         else
            call new_compound_sphere(cc, x0(1:d), 1.0_wp, 1.5_wp, 2.0_wp, 1.0e-3_wp, 1.0e-3_wp, 2.0_wp, 0.3_wp, &
               & 1.0_wp, 0.25_wp, error)
         end if
         if (allocated(error)) return
         call check(error, ly%pressure(2), cc%contact_pressure, roundoff*cc%contact_pressure, &
            & analysis_name(analysis)//': p_c')
         if (allocated(error)) return
         do ring = 1, 2
            points = shell_points(x0(1:d), 0.5_wp + 0.5_wp*ring, 1.0_wp + 0.5_wp*ring, seed)
            do ip = 1, npoint
               call ly%rings(ring)%field%stress(points(:, ip), s1(1:ns))
               call ly%rings(ring)%field%displacement(points(:, ip), u1(1:d))
               if (ring == 1) then
                  call cc%inner%stress(points(:, ip), s2(1:ns))
                  call cc%inner%displacement(points(:, ip), u2(1:d))
               else
                  call cc%outer%stress(points(:, ip), s2(1:ns))
                  call cc%outer%displacement(points(:, ip), u2(1:d))
               end if
               call check(error, maxval(abs(s1(1:ns) - s2(1:ns))), 0.0_wp, roundoff*cc%contact_pressure, &
                  & analysis_name(analysis)//': stress as compound')
               if (allocated(error)) return
               call check(error, maxval(abs(u1(1:d) - u2(1:d))), 0.0_wp, roundoff*maxval(abs(u2(1:d))), &
                  & analysis_name(analysis)//': displacement as compound')
               if (allocated(error)) return
            end do
         end do
      end do
   end subroutine test_layered_compound

   !> No interference at the outer interface and suction from outside
   !> (p_out < 0): the outer interface opens (p_2 = 0, the rings separate:
   !> u_3 - u_2 >= 0 there) while the inner fit stays closed.
   subroutine test_layered_open(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      real(wp) :: x(2), ui(2), uo(2)

      call new_layered(ly, 2, plane_strain, [0.0_wp, 0.0_wp], radii, [1.5e-3_wp, 0.0_wp], 0.0_wp, -1.0e-3_wp, &
         & young, poisson, error)
      if (allocated(error)) return
      call check(error, ly%pressure(3), 0.0_wp, 0.0_wp, 'outer interface open: p_2 = 0')
      if (allocated(error)) return
      call check(error, ly%pressure(2) > 0.0_wp, 'inner fit closed')
      if (allocated(error)) return
      x = [radii(3), 0.0_wp]
      call ly%rings(2)%field%displacement(x, ui)
      call ly%rings(3)%field%displacement(x, uo)
      call check(error, uo(1) - ui(1) >= 0.0_wp, 'the open rings do not overlap')
   end subroutine test_layered_open

   !> With real radii (ring j ends at r_j + delta_j): the gap along the
   !> radius closes, u_(j+1)(r_j) - u_j(r_j + delta_j) = delta_j, the two
   !> surfaces exchange equal forces, t_j (r_j + delta_j)^(d-1) = t_(j+1)
   !> r_j^(d-1) (radial tractions of the fields themselves), the boundary
   !> tractions hold, and equilibrium and compatibility hold in every ring.
   subroutine test_layered_real(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      real(wp) :: x(3), e(3), ui(3), uo(3), ti(3), to(3), ri, ro, s_scale
      integer(i8) :: seed
      integer :: k, j, d

      seed = 31_i8
      do k = 1, 3
         d = merge(3, 2, k == 3)
         call new_layered(ly, d, analyses(k), spread(0.0_wp, 1, d), radii, fits, p_in, p_out, young, poisson, error, &
            & shifts=fits)
         if (allocated(error)) return
         s_scale = maxval(abs(ly%pressure))
         e = 0.0_wp
         e(1:d) = 1.0_wp/sqrt(real(d, wp))
         do j = 1, 2
            ri = radii(j + 1) + fits(j)
            ro = radii(j + 1)
            call check(error, ly%outer_radii(j), ri, 0.0_wp, 'ring outer radius r_j + delta_j')
            if (allocated(error)) return
            x(1:d) = ri*e(1:d)
            call ly%rings(j)%field%displacement(x(1:d), ui(1:d))
            call ly%rings(j)%field%traction(x(1:d), e(1:d), ti(1:d))
            x(1:d) = ro*e(1:d)
            call ly%rings(j + 1)%field%displacement(x(1:d), uo(1:d))
            call ly%rings(j + 1)%field%traction(x(1:d), e(1:d), to(1:d))
            call check(error, dot_product(uo(1:d) - ui(1:d), e(1:d)), fits(j), roundoff*max(norm2(ui(1:d)), norm2(uo(1:d))), &
               & analysis_name(analyses(k))//': the gap closes at the real radii')
            if (allocated(error)) return
            call check(error, dot_product(ti(1:d), e(1:d))*ri**(d - 1), dot_product(to(1:d), e(1:d))*ro**(d - 1), &
               & roundoff*s_scale*ro**(d - 1), analysis_name(analyses(k))//': equal forces')
            if (allocated(error)) return
            call check(error, ly%pressure(j + 1) > 0.0_wp, 'closed interface')
            if (allocated(error)) return
            call check_equilibrium_fd(error, ly%rings(j)%field, shell_points(spread(0.0_wp, 1, d), radii(j), ri, &
               & seed), radii(1), s_scale, 'real radii ring')
            if (allocated(error)) return
            call check_compatibility_fd(error, ly%rings(j)%field, shell_points(spread(0.0_wp, 1, d), radii(j), ri, &
               & seed), radii(1), s_scale, 'real radii ring')
            if (allocated(error)) return
         end do
         x(1:d) = radii(1)*e(1:d)
         call ly%rings(1)%field%traction(x(1:d), -e(1:d), ti(1:d))
         call check(error, norm2(ti(1:d) - p_in*e(1:d)), 0.0_wp, roundoff*s_scale, 'p_in on r_0 (real radii)')
         if (allocated(error)) return
         x(1:d) = radii(4)*e(1:d)
         call ly%rings(3)%field%traction(x(1:d), e(1:d), to(1:d))
         call check(error, norm2(to(1:d) + p_out*e(1:d)), 0.0_wp, roundoff*s_scale, 'p_out on r_n (real radii)')
         if (allocated(error)) return
      end do
   end subroutine test_layered_real

   !> Bad input is an error naming the field.
   subroutine test_layered_errors(error)
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: ly
      type(error_type), allocatable :: e

      call new_layered(ly, 2, plane_strain, [0.0_wp, 0.0_wp], [1.0_wp, 2.0_wp, 1.5_wp, 2.5_wp], fits, p_in, 0.0_wp, &
         & young, poisson, e)
      call check(error, allocated(e), 'decreasing radii refused')
      if (allocated(error)) return
      call check(error, index(e%message, 'radii(3)') > 0, 'the message names radii(3): '//e%message)
      if (allocated(error)) return
      deallocate (e)
      call new_layered(ly, 2, plane_strain, [0.0_wp, 0.0_wp], radii, [1.0e-3_wp], p_in, 0.0_wp, young, poisson, e)
      call check(error, allocated(e), 'one interference for two interfaces refused')
      if (allocated(error)) return
      deallocate (e)
      call new_layered(ly, 2, solid, [0.0_wp, 0.0_wp], radii, fits, p_in, 0.0_wp, young, poisson, e)
      call check(error, allocated(e), 'a cylinder in solid analysis refused')
   end subroutine test_layered_errors

end module sprc_test_exact_layered
