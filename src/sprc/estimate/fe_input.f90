!> The FE → recovery adapter: the recovery's view of a solved FE problem on
!> a cut grid (`recovery_input_type` of `sprc_estimate_patches`).
!>
!> - volume points of each element with w|J| and the FE stress there;
!> - boundary points with w|J|, outward normals and the body's shape index;
!> - per shape the boundary kind the SPR-C constraints use, from the FE
!>   conditions: free surfaces (and shapes without a condition) are
!>   traction with t = 0, pressure and traction keep their data, exact
!>   traction needs the exact solution at recovery time, symmetry is a
!>   symmetry plane, and Dirichlet surfaces (displacement, exact
!>   displacement) carry no recovery constraint.
module sprc_estimate_fe_input
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_core_boundary, only: bc_none, bc_free, bc_pressure, bc_traction, bc_symmetry, bc_exact_traction
   use sprc_estimate_patches, only: recovery_input_type
   use sprc_fem_problem, only: elasticity_problem_type
   implicit none
   private

   public :: fe_recovery_input

contains

   !> The recovery input of the solved `problem` (module notes). Error if the
   !> problem is not solved.
   subroutine fe_recovery_input(problem, input, error)
      type(elasticity_problem_type), intent(in) :: problem
      type(recovery_input_type), intent(out) :: input
      type(error_type), allocatable, intent(out) :: error
      integer :: e, q, d, nq, nb, ns, stat
      character(len=*), parameter :: who = 'FE recovery input'

      if (.not. problem%solved) then
         call fatal_error(error, 'FE recovery input: the problem is not solved', stat_invalid_input)
         return
      end if
      d = problem%dim
      input%analysis = problem%analysis
      input%young = problem%young
      input%poisson = problem%poisson
      input%body_force(1:d) = problem%body_force(1:d)
      nq = size(problem%mesh%vol_w)
      nb = size(problem%mesh%surf_w)
      ns = problem%nstress
      allocate (input%elem_ptr(size(problem%mesh%vol_ptr)), input%x(d, nq), input%w(nq), input%stress(ns, nq), stat=stat)
      call check_allocation(stat, who, 'the volume quadrature points and their stresses', nq, 8*(d + 1 + ns) + 4, error)
      if (allocated(error)) return
      allocate (input%belem_ptr(size(problem%mesh%surf_ptr)), input%bx(d, nb), input%bw(nb), input%bn(d, nb), &
         & input%bshape(nb), stat=stat)
      call check_allocation(stat, who, 'the boundary quadrature points', nb, 8*(2*d + 1) + 8, error)
      if (allocated(error)) return
      input%elem_ptr(:) = problem%mesh%vol_ptr
      input%x(:, :) = problem%mesh%vol_x(1:d, :)
      input%w(:) = problem%mesh%vol_w
      do e = 1, problem%mesh%grid%n_leaves
         do q = problem%mesh%vol_ptr(e), problem%mesh%vol_ptr(e + 1) - 1
            call problem%stress_in_element(e, problem%mesh%vol_x(1:d, q), input%stress(:, q))
         end do
      end do
      input%belem_ptr(:) = problem%mesh%surf_ptr
      input%bx(:, :) = problem%mesh%surf_x(1:d, :)
      input%bw(:) = problem%mesh%surf_w
      input%bn(:, :) = problem%mesh%surf_n(1:d, :)
      input%bshape(:) = problem%mesh%surf_shape
      call boundary_kinds(problem, input)
   end subroutine fe_recovery_input

   !> Recovery kind and data of each surface from the problem's conditions.
   subroutine boundary_kinds(problem, input)
      type(elasticity_problem_type), intent(in) :: problem
      type(recovery_input_type), intent(inout) :: input
      integer :: nshape, i, s, d

      d = problem%dim
      nshape = size(problem%bc_of_shape)
      allocate (input%bc_kind(nshape), input%bc_traction(3, nshape), input%bc_pressure(nshape))
      input%bc_kind = bc_traction
      input%bc_traction = 0.0_wp
      input%bc_pressure = 0.0_wp
      ! per surface through bc_of_shape: a faceted group inherits its shape's condition
      do s = 1, nshape
         i = problem%bc_of_shape(s)
         if (i == 0) cycle
         input%bc_kind(s) = problem%bcs(i)%kind
         select case (problem%bcs(i)%kind)
         case (bc_free)
            input%bc_kind(s) = bc_traction
         case (bc_pressure)
            input%bc_pressure(s) = problem%bcs(i)%value
         case (bc_traction)
            input%bc_traction(1:d, s) = problem%bcs(i)%vector(1:d)
         case (bc_exact_traction, bc_symmetry)   ! the kind alone says it
         case default
            input%bc_kind(s) = bc_none
         end select
      end do
   end subroutine boundary_kinds

end module sprc_estimate_fe_input
