!> Isotropic linear-elastic material matrices shared by the FE, the recovery and
!> the exact solutions, so that all of them use one definition.
!>
!> Voigt order 2D (xx, yy, xy), 3D (xx, yy, zz, xy, yz, xz); engineering shear
!> strains (gamma = 2 eps), so sigma = D eps and eps = C sigma with C = D^-1.
!>
!> - plane stress: sigma_zz = 0, eps_zz = -nu (sigma_xx + sigma_yy)/E is not stored.
!> - plane strain: eps_zz = 0, sigma_zz = nu (sigma_xx + sigma_yy) is not stored;
!>   the reduced compliance is eps_xx = ((1-nu^2) s_xx - nu(1+nu) s_yy)/E,
!>   eps_yy = ((1-nu^2) s_yy - nu(1+nu) s_xx)/E, gamma_xy = 2(1+nu) s_xy/E.
!> - solid: the 6x6 3D law with Lame constants lambda, mu.
module sprc_core_material
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: rtoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   implicit none
   private

   public :: plane_stress, plane_strain, solid
   public :: voigt_size, analysis_name, check_material
   public :: material_matrix, compliance_matrix

   !> Analysis kinds. Values are part of the C API; never renumber. Plane stress (2D),
   integer, parameter :: plane_stress = 1
   !> plane strain (2D),
   integer, parameter :: plane_strain = 2
   !> three-dimensional.
   integer, parameter :: solid = 3

contains

   !> Number of Voigt stress components of an analysis kind: 3 in 2D, 6 in 3D,
   !> 0 for an unknown kind.
   pure integer function voigt_size(analysis)
      integer, intent(in) :: analysis
      select case (analysis)
      case (plane_stress, plane_strain); voigt_size = 3
      case (solid); voigt_size = 6
      case default; voigt_size = 0
      end select
   end function voigt_size

   !> Name of an analysis kind as the scene file spells it ('unknown' otherwise).
   pure function analysis_name(analysis) result(name)
      integer, intent(in) :: analysis
      character(len=:), allocatable :: name
      select case (analysis)
      case (plane_stress); name = 'plane_stress'
      case (plane_strain); name = 'plane_strain'
      case (solid); name = 'solid'
      case default; name = 'unknown'
      end select
   end function analysis_name

   !> Check an isotropic material: finite E > 0 and -1 < nu < 1/2. `context`
   !> prefixes the message (e.g. the caller's name).
   pure subroutine check_material(young, poisson, context, error)
      real(wp), intent(in) :: young, poisson
      character(len=*), intent(in) :: context
      type(error_type), allocatable, intent(out) :: error

      ! Written so that NaN fails every test.
      if (.not. (young > 0.0_wp .and. young <= huge(young))) then
         call fatal_error(error, context//': young must be finite and > 0, got '//rtoa(young, '(es16.8)'), &
            & stat_invalid_input)
      else if (.not. (poisson > -1.0_wp .and. poisson < 0.5_wp)) then
         call fatal_error(error, context//': poisson must satisfy -1 < poisson < 0.5, got '// &
            & rtoa(poisson, '(es16.8)'), stat_invalid_input)
      end if
   end subroutine check_material

   !> Material matrix D (sigma = D eps) of an analysis kind. `d` must have shape
   !> (n, n) with n = `voigt_size(analysis)`.
   pure subroutine material_matrix(analysis, young, poisson, d, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      real(wp), intent(out) :: d(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: lambda, mu, f

      call check_arguments('material_matrix', analysis, young, poisson, shape(d), error)
      if (allocated(error)) return
      d = 0.0_wp
      mu = young/(2.0_wp*(1.0_wp + poisson))
      select case (analysis)
      case (plane_stress)
         f = young/(1.0_wp - poisson**2)
         d(1, 1) = f
         d(2, 2) = f
         d(1, 2) = f*poisson
         d(2, 1) = f*poisson
         d(3, 3) = mu
      case (plane_strain)
         f = young/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson))
         d(1, 1) = f*(1.0_wp - poisson)
         d(2, 2) = f*(1.0_wp - poisson)
         d(1, 2) = f*poisson
         d(2, 1) = f*poisson
         d(3, 3) = mu
      case (solid)
         lambda = young*poisson/((1.0_wp + poisson)*(1.0_wp - 2.0_wp*poisson))
         d(1:3, 1:3) = lambda
         d(1, 1) = lambda + 2.0_wp*mu
         d(2, 2) = lambda + 2.0_wp*mu
         d(3, 3) = lambda + 2.0_wp*mu
         d(4, 4) = mu
         d(5, 5) = mu
         d(6, 6) = mu
      end select
   end subroutine material_matrix

   !> Compliance matrix C = D^-1 (eps = C sigma) of an analysis kind, in closed
   !> form (no inversion). `c` must have shape (n, n), n = `voigt_size(analysis)`.
   pure subroutine compliance_matrix(analysis, young, poisson, c, error)
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      real(wp), intent(out) :: c(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: shear

      call check_arguments('compliance_matrix', analysis, young, poisson, shape(c), error)
      if (allocated(error)) return
      c = 0.0_wp
      shear = 2.0_wp*(1.0_wp + poisson)/young
      select case (analysis)
      case (plane_stress)
         c(1, 1) = 1.0_wp/young
         c(2, 2) = 1.0_wp/young
         c(1, 2) = -poisson/young
         c(2, 1) = -poisson/young
         c(3, 3) = shear
      case (plane_strain)
         c(1, 1) = (1.0_wp - poisson**2)/young
         c(2, 2) = (1.0_wp - poisson**2)/young
         c(1, 2) = -poisson*(1.0_wp + poisson)/young
         c(2, 1) = -poisson*(1.0_wp + poisson)/young
         c(3, 3) = shear
      case (solid)
         c(1:3, 1:3) = -poisson/young
         c(1, 1) = 1.0_wp/young
         c(2, 2) = 1.0_wp/young
         c(3, 3) = 1.0_wp/young
         c(4, 4) = shear
         c(5, 5) = shear
         c(6, 6) = shear
      end select
   end subroutine compliance_matrix

   pure subroutine check_arguments(name, analysis, young, poisson, mshape, error)
      character(len=*), intent(in) :: name
      integer, intent(in) :: analysis
      real(wp), intent(in) :: young, poisson
      integer, intent(in) :: mshape(2)
      type(error_type), allocatable, intent(out) :: error
      integer :: n
      character(len=40) :: buf, want

      n = voigt_size(analysis)
      if (n == 0) then
         write (buf, '(i0)') analysis
         call fatal_error(error, name//': unknown analysis kind '//trim(buf)// &
            & ' (expected plane_stress=1, plane_strain=2 or solid=3)', stat_invalid_input)
         return
      end if
      call check_material(young, poisson, name, error)
      if (allocated(error)) return
      if (any(mshape /= n)) then
         write (buf, '(i0,"x",i0)') mshape
         write (want, '(i0,"x",i0)') n, n
         call fatal_error(error, name//': matrix has shape '//trim(buf)//', expected '//trim(want)// &
            & ' for '//analysis_name(analysis), stat_invalid_input)
      end if
   end subroutine check_arguments

end module sprc_core_material
