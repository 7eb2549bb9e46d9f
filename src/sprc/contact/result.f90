!> What a contact solve gives at one level, per slave-surface point, for the
!> report (doc/scene.md "The report"), `PREFIX_contact.csv` / `.svg` and the
!> HDF5/XDMF point set. Producers: the contact FE (p_fe, ts_fe, gap, state)
!> and the recoveries (p_spr, p_sprc, ts_sprc), the slave's FE stresses
!> (p_fe_stress); the exact solution gives
!> p_exact. A real value that does not apply is empty (`report_empty`).
module sprc_contact_result
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_alloc, only: check_allocation
   use sprc_core_empty, only: report_empty
   implicit none
   private

   public :: contact_result_type, new_contact_result, state_name
   public :: contact_open, contact_stick, contact_slip

   !> States of a slave point (doc/scene.md "Output files", `state`: open, stick, slip). Frictionless
   !> closed points are `contact_slip` (they slide freely).
   integer, parameter :: contact_open = 0, contact_stick = 1, contact_slip = 2

   !> Per slave point of one contact pair at one level, in scene units.
   type :: contact_result_type
      !> Space dimension and number of slave points.
      integer :: dim = 0, npoint = 0
      !> Slave and master body (1-based scene indices).
      integer :: slave = 0, master = 0
      !> Coordinates (dim, npoint), weights (surface measure), unit outward slave normals (dim, npoint).
      real(wp), allocatable :: x(:, :), weight(:), normal(:, :)
      !> Linearized gap of the solution (positive open, negative penetration).
      real(wp), allocatable :: gap(:)
      !> `contact_open`, `contact_stick` or `contact_slip`.
      integer, allocatable :: state(:)
      !> Contact pressure p = -n.sigma.n (positive in compression) from the FE contact
      !> formulation, SPR, SPR-C and the exact solution.
      real(wp), allocatable :: p_fe(:), p_spr(:), p_sprc(:), p_exact(:)
      !> The pressure -n.sigma_h.n of the slave's own FE stresses at the point, which
      !> the contact multiplier p_fe and the recovered p_spr, p_sprc are compared with.
      real(wp), allocatable :: p_fe_stress(:)
      !> Magnitude of the tangential traction: FE formulation and SPR-C.
      real(wp), allocatable :: ts_fe(:), ts_sprc(:)
      !> The FE tangential traction on the slave body as a vector (dim, npoint):
      !> its sign shows the direction of friction (Cattaneo-Mindlin).
      real(wp), allocatable :: t_fe(:, :)
      !> With `stabilization = 'recovered'` only: the stabilization pressure
      !> -n.t* of the last solve, t* the slave's recovered traction (SPR-C with
      !> the coupled contact patches) of the solution before it; once the
      !> iteration has settled it agrees with p_sprc to the settling tolerance.
      real(wp), allocatable :: p_star(:)
      !> Iterations of the contact nonlinearity summed over all increments.
      integer :: iterations = 0
      !> What the solve warns of ('' for nothing; the contact solution's
      !> `warning`): a driver prints it.
      character(len=:), allocatable :: warning
   end type contact_result_type

contains

   !> A result for `npoint` slave points: geometry copied, every value empty,
   !> every point open.
   pure subroutine new_contact_result(self, x, weight, normal, slave, master, error)
      type(contact_result_type), intent(out) :: self
      real(wp), intent(in) :: x(:, :), weight(:), normal(:, :)
      integer, intent(in) :: slave, master
      type(error_type), allocatable, intent(out) :: error
      integer :: n, stat

      n = size(weight)
      self%dim = size(x, 1)
      self%npoint = n
      self%slave = slave
      self%master = master
      allocate (self%x, source=x, stat=stat)
      if (stat == 0) allocate (self%weight, source=weight, stat=stat)
      if (stat == 0) allocate (self%normal, source=normal, stat=stat)
      if (stat == 0) allocate (self%gap(n), self%p_fe(n), self%p_spr(n), self%p_sprc(n), self%p_exact(n), &
         & self%p_fe_stress(n), self%ts_fe(n), self%ts_sprc(n), source=report_empty, stat=stat)
      if (stat == 0) allocate (self%t_fe(self%dim, n), source=report_empty, stat=stat)
      if (stat == 0) allocate (self%state(n), source=contact_open, stat=stat)
      call check_allocation(stat, 'contact result', 'the values of each slave point', n, &
         & 8*(3*self%dim + 9) + 4, error)
   end subroutine new_contact_result

   !> The doc/scene.md name of a state.
   pure function state_name(state) result(name)
      integer, intent(in) :: state
      character(len=:), allocatable :: name
      select case (state)
      case (contact_stick)
         name = 'stick'
      case (contact_slip)
         name = 'slip'
      case default
         name = 'open'
      end select
   end function state_name

end module sprc_contact_result
