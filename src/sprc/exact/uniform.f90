!> Uniform stress in a body: the field of the contact patch test. Zero body
!> force; any isotropic material, plane stress, plane strain or solid.
!>
!> sigma(x) = S (constant, Voigt order), eps = C S with C = D^-1 the
!> compliance of the body's material and analysis (sprc_core_material), and
!>
!>   u(x) = E x,   E_ii = eps_ii,  E_ij = gamma_ij/2 (i /= j),
!>
!> the symmetric displacement gradient: u has no rotation and u(0) = 0. The
!> exact solution of a body is fixed only up to a rigid motion; this is the
!> representative the `exact_displacement` condition prescribes. Two bodies in
!> contact under the same S have the same traction on any common plane, so a
!> contact interface transmits S exactly whatever the two materials.
module sprc_exact_uniform
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, compliance_matrix
   use sprc_exact_solution, only: exact_solution_type, init_exact_solution, is_finite
   implicit none
   private

   public :: uniform_type, new_uniform

   !> Uniform stress and the linear displacement of one body.
   type, extends(exact_solution_type) :: uniform_type
      !> The stress S in Voigt order, size nstress (3 or 6; trailing entries unused in 2D).
      real(wp) :: sigma(6) = 0.0_wp
      !> Symmetric displacement gradient E (u = E x).
      real(wp) :: gradient(3, 3) = 0.0_wp
   contains
      procedure :: stress => uniform_stress
      procedure :: displacement => uniform_displacement
   end type uniform_type

contains

   !> Create a uniform-stress solution for one body. `stress` has 3 (2D) or 6
   !> (3D) Voigt entries matching `analysis`.
   pure subroutine new_uniform(self, stress, young, poisson, analysis, error)
      type(uniform_type), intent(out) :: self
      real(wp), intent(in) :: stress(:)
      real(wp), intent(in) :: young, poisson
      integer, intent(in) :: analysis
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: context = 'uniform'
      real(wp) :: comp(6, 6), eps(6)
      character(len=48) :: buf
      integer :: ns

      call init_exact_solution(self, context, analysis, [plane_stress, plane_strain, solid], young, poisson, error)
      if (allocated(error)) return
      ns = voigt_size(analysis)
      if (size(stress) /= ns) then
         write (buf, '("has ",i0," entries, expected ",i0)') size(stress), ns
         call fatal_error(error, context//': stress '//trim(buf), stat_invalid_input)
         return
      end if
      if (.not. all(is_finite(stress))) then
         call fatal_error(error, context//': stress must be finite', stat_invalid_input)
         return
      end if
      call compliance_matrix(analysis, young, poisson, comp(1:ns, 1:ns), error)
      if (allocated(error)) return
      self%sigma(1:ns) = stress
      eps(1:ns) = matmul(comp(1:ns, 1:ns), stress)
      if (ns == 3) then
         self%gradient(1:2, 1:2) = reshape([eps(1), 0.5_wp*eps(3), 0.5_wp*eps(3), eps(2)], [2, 2])
      else
         self%gradient = reshape([eps(1), 0.5_wp*eps(4), 0.5_wp*eps(6), &
            & 0.5_wp*eps(4), eps(2), 0.5_wp*eps(5), &
            & 0.5_wp*eps(6), 0.5_wp*eps(5), eps(3)], [3, 3])
      end if
   end subroutine new_uniform

   pure subroutine uniform_stress(self, x, v)
      class(uniform_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      associate (unused => x); end associate
      v(1:self%nstress) = self%sigma(1:self%nstress)
   end subroutine uniform_stress

   pure subroutine uniform_displacement(self, x, v)
      class(uniform_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: v(:)
      associate (d => self%dim)
         v(1:d) = matmul(self%gradient(1:d, 1:d), x(1:d))
      end associate
   end subroutine uniform_displacement

end module sprc_exact_uniform
