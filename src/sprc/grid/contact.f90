!> A body's contact surface as the grid recovery sees it (seed eqs. 103-138, "Formulación
!> del SPR-C en contacto"; issue 12): which boundary points are in contact and under which
!> law, and the other body's FE stresses for the auxiliary domains Omega_aux.
!>
!> The grid producer (sprc_grid_patches) marks the body's boundary points on `shape` with a
!> closed law as contact points and solves every SPR-C patch holding one by the coupled
!> contact solve (sprc_recovery_contact_solve, contact wins), with body (2) the other body;
!> points of `shape` that are open are a free surface (zero traction). Both bodies of a pair
!> get a description, each with the other as body (2): the master-side patches are the
!> mirrored ones, so both recovered fields near the contact surface are contact-aware.
!>
!> Omega_aux depth: `depth` times the patch size h, default 3 h (measured, Q1, levels 5..7,
!> depth h / 2h / 3h / 4h: on the shrink fit the pressure error at level 7 is 4.0e-3 /
!> 2.2e-3 / 1.7e-3 / 1.6e-3 (err_p_fe 2.5e-3) and err_sprc 5.30e-4 / 5.17e-4 / 5.17e-4 /
!> 5.20e-4; on the Hertz cylinder err_p_sprc 0.0529 / 0.0532 / 0.0536 and p_max_sprc
!> 13.70 / 13.69 / 13.71 (p0 13.74): a prism of one patch size holds mostly the other
!> body's cut cells, whose stresses are the poorest, deeper ones stop gaining at 3h and do
!> not over-smooth the Hertz peak at these levels). The solve doubles it while the Omega_aux
!> fit lacks rank.
!>
!> The other body's points are sorted into uniform cells once (a counting sort): a patch
!> passes the solve only those in a box about its node that Omega_aux can reach, the box
!> growing with the depth doublings.
!>
!> The other body's boundary points where a prism meets its other boundaries (symmetry planes,
!> loaded or free surfaces) constrain the Omega_aux fit as in any SPR-C patch.
!>
!> Small deformations: undeformed points and normals.
module sprc_grid_contact
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_alloc, only: check_allocation
   use sprc_recovery_patch, only: patch_type, recovered_patch_type
   use sprc_recovery_workspace, only: recovery_workspace_type, workspace_init
   use sprc_recovery_contact_operators, only: contact_law_frictionless, contact_law_slip, contact_law_stick
   use sprc_recovery_contact_solve, only: recover_contact_patch, aux_max_doublings
   implicit none
   private

   public :: grid_contact_type, new_grid_contact, contact_patch_solve, default_aux_depth

   !> Omega_aux depth in patch sizes (module notes).
   real(wp), parameter :: default_aux_depth = 3.0_wp
   !> Mean points per cell of the other body's point cells.
   real(wp), parameter :: points_per_cell = 8.0_wp

   !> One body's contact surface for the grid recovery (module notes).
   type :: grid_contact_type
      !> The body's shape index of its contact surface (the bshape of its boundary points).
      integer :: shape = 0
      !> Per boundary point k of the body's recovery input (read where bshape(k) = shape): the
      !> contact law (contact_law_frictionless, _slip, _stick; 0 = open) and, for slip, the slip
      !> direction of this body relative to the other, slip(1:dim, k).
      integer, allocatable :: law(:)
      real(wp), allocatable :: slip(:, :)
      !> Coulomb friction coefficient (slip law).
      real(wp) :: mu = 0.0_wp
      !> Omega_aux depth in patch sizes.
      real(wp) :: depth = default_aux_depth
      !> The other body: volume points sorted along the first axis, weight*|J|, FE stresses.
      real(wp), allocatable :: y(:, :), w(:), stress(:, :)
      !> The other body's boundary points other than its contact surface (boundary arrays
      !> only; nbpoints = 0 if not given): they constrain its Omega_aux fits.
      type(patch_type) :: boundary
      !> The other body's material and body force.
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp, body_force(3) = 0.0_wp
      !> Uniform cells over the box of the points, ncell(k) along axis k (1 beyond dim): the
      !> points of cell c (`cell_index`) are cell_ptr(c) .. cell_ptr(c+1)-1.
      integer :: ncell(3) = 1
      integer, allocatable :: cell_ptr(:)
      real(wp) :: ymin(3) = 0.0_wp, cell_width(3) = 1.0_wp
   end type grid_contact_type

contains

   !> The contact description of one body: `shape`, law(k) and slip(1:dim, k) per boundary
   !> point of its recovery input, mu, and the other body's volume points y(1:dim, j), weights
   !> w(j), FE stresses stress(:, j), material and body force. Errors (stat_invalid_input):
   !> sizes that disagree, an unknown law, a non-finite point.
   subroutine new_grid_contact(self, shape, law, slip, mu, y, w, stress, young, poisson, body_force, error, depth, &
      & boundary)
      type(grid_contact_type), intent(out) :: self
      integer, intent(in) :: shape, law(:)
      real(wp), intent(in) :: slip(:, :), mu, y(:, :), w(:), stress(:, :), young, poisson, body_force(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: depth
      !> The other body's boundary points (`boundary`).
      type(patch_type), intent(in), optional :: boundary
      integer, allocatable :: bin(:)
      integer :: n, d, j, b, stat
      real(wp) :: ymax(3)

      n = size(w)
      if (size(slip, 2) /= size(law) .or. size(y, 2) /= n .or. size(stress, 2) /= n) then
         call fatal_error(error, 'grid contact: law/slip or y/w/stress disagree in size', stat_invalid_input)
         return
      end if
      if (any(law /= 0 .and. law /= contact_law_frictionless .and. law /= contact_law_slip .and. &
         & law /= contact_law_stick)) then
         call fatal_error(error, 'grid contact: a contact law is not 0 (open), frictionless, slip or stick', &
            & stat_invalid_input)
         return
      end if
      if (.not. all(abs(y) <= huge(1.0_wp))) then
         call fatal_error(error, 'grid contact: the other body''s points are not finite', stat_invalid_input)
         return
      end if
      self%shape = shape
      self%law = law
      self%slip = slip
      self%mu = mu
      if (present(depth)) self%depth = depth
      if (present(boundary)) self%boundary = boundary
      self%young = young
      self%poisson = poisson
      self%body_force = 0.0_wp
      self%body_force(1:size(body_force)) = body_force
      d = size(y, 1)
      allocate (self%y(d, n), self%w(n), self%stress(size(stress, 1), n), bin(n), stat=stat)
      call check_allocation(stat, 'grid contact', 'the other body''s points', n, 8*(d + size(stress, 1) + 2), error)
      if (allocated(error)) return
      self%ymin = 0.0_wp
      ymax = 0.0_wp
      if (n > 0) then
         self%ymin(1:d) = minval(y, dim=2)
         ymax(1:d) = maxval(y, dim=2)
      end if
      ! About points_per_cell points a cell where they fill the box.
      self%ncell = 1
      self%ncell(1:d) = max(1, nint((real(n, wp)/points_per_cell)**(1.0_wp/d)))
      self%cell_width = 1.0_wp
      self%cell_width(1:d) = max((ymax(1:d) - self%ymin(1:d))/real(self%ncell(1:d), wp), tiny(1.0_wp))
      allocate (self%cell_ptr(product(self%ncell) + 1), stat=stat)
      call check_allocation(stat, 'grid contact', 'the cells of the other body''s points', product(self%ncell), 4, &
         & error)
      if (allocated(error)) return
      self%cell_ptr = 0
      do j = 1, n
         bin(j) = cell_index(self, cell_of(self, y(:, j)))
         self%cell_ptr(bin(j) + 1) = self%cell_ptr(bin(j) + 1) + 1
      end do
      self%cell_ptr(1) = 1
      do b = 2, size(self%cell_ptr)
         self%cell_ptr(b) = self%cell_ptr(b) + self%cell_ptr(b - 1)
      end do
      ! Stable counting sort: points keep their order within a cell.
      do j = 1, n
         b = bin(j)
         self%y(:, self%cell_ptr(b)) = y(:, j)
         self%w(self%cell_ptr(b)) = w(j)
         self%stress(:, self%cell_ptr(b)) = stress(:, j)
         self%cell_ptr(b) = self%cell_ptr(b) + 1
      end do
      do b = size(self%cell_ptr), 2, -1
         self%cell_ptr(b) = self%cell_ptr(b - 1)
      end do
      self%cell_ptr(1) = 1
   end subroutine new_grid_contact

   !> Cell coordinates (1-based, clamped to the box) of a point.
   pure function cell_of(self, y) result(c)
      type(grid_contact_type), intent(in) :: self
      real(wp), intent(in) :: y(:)
      integer :: c(3), k
      real(wp) :: t

      c = 1
      do k = 1, size(y)
         t = (y(k) - self%ymin(k))/self%cell_width(k)
         if (t >= real(self%ncell(k), wp)) then
            c(k) = self%ncell(k)
         else if (t >= 1.0_wp) then
            c(k) = int(t) + 1
         end if
      end do
   end function cell_of

   !> Linear index of cell coordinates c (first axis fastest).
   pure integer function cell_index(self, c)
      type(grid_contact_type), intent(in) :: self
      integer, intent(in) :: c(3)
      cell_index = c(1) + self%ncell(1)*((c(2) - 1) + self%ncell(2)*(c(3) - 1))
   end function cell_index

   !> The coupled SPR-C solve of a patch holding contact points (sprc_recovery_contact_solve):
   !> law(j), slip(1:dim, j) per boundary point j of `patch`, body (2) the other body's points
   !> (module notes). rec is the patch's recovered stress.
   subroutine contact_patch_solve(self, patch, law, slip, degree, ws, rec, error)
      type(grid_contact_type), intent(in) :: self
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: law(:), degree
      real(wp), intent(in) :: slip(:, :)
      type(recovery_workspace_type), intent(inout) :: ws
      type(recovered_patch_type), intent(out) :: rec
      type(error_type), allocatable, intent(out) :: error
      type(recovery_workspace_type) :: ws2
      type(patch_type) :: patch2
      type(recovered_patch_type) :: rec2
      integer, allocatable :: idx(:)
      real(wp) :: reach
      integer :: n, k

      call workspace_init(ws2)
      ! Omega_aux after k doublings reaches 2^k depth h beyond the contact points (within h of
      ! the node) and widens by (2^k - 1) depth h / 2: the box of half-width
      ! h (1 + depth (1.5 2^k - 0.5)) holds it. Each k gathers its own box, so that a patch
      ! needing doublings does not scan the whole other body.
      do k = 0, aux_max_doublings
         reach = patch%h*(1.0_wp + self%depth*(1.5_wp*2.0_wp**k - 0.5_wp))
         call gather_box(self, patch, reach, idx, n)
         call recover_contact_patch(patch, degree, law, self%mu, slip, self%y(:, idx(1:n)), self%w(idx(1:n)), &
            & self%stress(:, idx(1:n)), self%young, self%poisson, self%depth*patch%h, ws, ws2, patch2, rec, rec2, &
            & error, body_force2=self%body_force, max_doublings=k, boundary2=self%boundary)
         if (.not. allocated(error)) return
         if (index(error%message, 'Omega_aux fit') == 0) return
      end do
   end subroutine contact_patch_solve

   !> The other body's points within `reach` of the patch node in every coordinate, in
   !> their sorted order: idx(1:n).
   pure subroutine gather_box(self, patch, reach, idx, n)
      type(grid_contact_type), intent(in) :: self
      type(patch_type), intent(in) :: patch
      real(wp), intent(in) :: reach
      integer, allocatable, intent(out) :: idx(:)
      integer, intent(out) :: n
      integer :: lo(3), hi(3), i1, i2, i3, j, d, c

      d = patch%dim
      lo = cell_of(self, patch%x0(1:d) - reach)
      hi = cell_of(self, patch%x0(1:d) + reach)
      n = 0
      do i3 = lo(3), hi(3)
         do i2 = lo(2), hi(2)
            c = cell_index(self, [lo(1), i2, i3])
            n = n + self%cell_ptr(c + hi(1) - lo(1) + 1) - self%cell_ptr(c)
         end do
      end do
      allocate (idx(n))
      n = 0
      do i3 = lo(3), hi(3)
         do i2 = lo(2), hi(2)
            do i1 = lo(1), hi(1)
               c = cell_index(self, [i1, i2, i3])
               do j = self%cell_ptr(c), self%cell_ptr(c + 1) - 1
                  if (any(abs(self%y(1:d, j) - patch%x0(1:d)) > reach)) cycle
                  n = n + 1
                  idx(n) = j
               end do
            end do
         end do
      end do
   end subroutine gather_box

end module sprc_grid_contact
