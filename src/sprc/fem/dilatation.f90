!> Projected dilatation (B-bar / mean dilatation) on cell aggregates: the
!> locking-free formulation for nearly incompressible materials
!> (doc/theory.md, section 5).
!>
!> Formulation. With m the volumetric vector, kappa = m^T D m / k^2, the
!> dilatation theta = m^T eps(u) and D_dev = D - kappa m m^T (D_dev m = 0),
!> theta is replaced by its L2 projection theta_bar onto P_k(A) on each
!> aggregate A (a well-posed cell and its attached small cut cells,
!> `sprc_fem_aggregation`):
!>   a(u, v) = int eps(v)^T D_dev eps(u) + int kappa theta_bar(v) theta_bar(u),
!>   sigma_bar(u) = D_dev eps(u) + kappa theta_bar(u) m.
!> This is B-bar (Hughes 1980), the mean dilatation for k = 0 (Nagtegaal,
!> Parks & Rice 1974), and the displacement form of the mixed method with
!> pressure kappa theta_bar: Q1/P0 and Q2/P1-discontinuous, the inf-sup stable
!> pair of optimal order for Q2 (Brezzi & Fortin 1991). The pressure space
!> lives on the aggregates (as in Badia, Martin & Verdugo 2018, for Stokes):
!> a small cut cell carries no dilatation of its own, so the number of
!> incompressibility constraints does not grow with how the boundary cuts
!> the grid. The Gram matrices use each cell's cut-cell volume rule.
!>
!> Nitsche terms use the stress of the formulation, sigma_bar(v) n, so the
!> method stays consistent: a rank-np coupling between the surface points of
!> an aggregate and its dilatation (`add_aggregate_block`).
!>
!> When. The displacement formulation locks as nu -> 1/2 in plane strain and
!> 3D (kappa / mu grows without bound); plane stress does not lock and
!> `dilatation_auto` never projects it. It projects from nu >=
!> `projected_poisson` = 0.4, where the projection starts to lower err_fe
!> (doc/benchmarks.md). The stiffness keeps the kappa scale: its condition
!> number still grows like kappa / mu.
module sprc_fem_dilatation
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_singular
   use sprc_core_alloc, only: check_allocation
   use sprc_core_lapack, only: dpotrf, dpotrs, dgemm
   use sprc_core_material, only: plane_stress, solid
   use sprc_grid_tree, only: grid_type
   use sprc_fem_element, only: shape_functions, strain_matrix
   implicit none
   private

   public :: dilatation_type, dilatation_auto, dilatation_full, dilatation_projected, projected_poisson
   public :: resolve_dilatation, dilatation_name, dilatation_choice

   !> Formulation choices: automatic (by analysis and nu), the plain
   !> displacement formulation, the projected dilatation.
   integer, parameter :: dilatation_auto = 0, dilatation_full = 1, dilatation_projected = 2

   !> `dilatation_auto` projects (plane strain and 3D) from this Poisson ratio up.
   real(wp), parameter :: projected_poisson = 0.4_wp

   !> Projected dilatation of one problem (module notes). Inactive: the
   !> displacement formulation (np = 0).
   type :: dilatation_type
      logical :: active = .false.
      !> Dimension, Voigt size, size of the dilatation basis P_k (1 or dim + 1).
      integer :: dim = 0, nstress = 0, np = 0
      real(wp) :: kappa = 0.0_wp
      !> Volumetric vector m and deviatoric material matrix D - kappa m m^T.
      real(wp) :: m(6) = 0.0_wp, d_dev(6, 6) = 0.0_wp
      integer :: n_aggregates = 0
      !> Aggregate of each element; members of aggregate a: member(ptr(a) : ptr(a+1)-1), root first.
      integer, allocatable :: aggregate(:), ptr(:), member(:)
      !> Basis centre (dim, n_aggregates) and length (the root cell's box).
      real(wp), allocatable :: centre(:, :), length(:)
      !> Cholesky factor (upper) of the Gram matrix M_A (np, np, n_aggregates).
      real(wp), allocatable :: gram(:, :, :)
      !> Coefficients of theta_bar on each aggregate (np, n_aggregates), after `set_solution`.
      real(wp), allocatable :: coef(:, :)
   contains
      procedure :: build
      procedure :: basis
      procedure :: element_moments
      procedure :: add_moment
      procedure :: add_aggregate_block
      procedure :: set_coefficients
      procedure :: projected_stress
   end type dilatation_type

contains

   !> Whether `choice` projects the dilatation for this analysis and nu.
   pure logical function resolve_dilatation(choice, analysis, poisson)
      integer, intent(in) :: choice, analysis
      real(wp), intent(in) :: poisson
      select case (choice)
      case (dilatation_projected)
         resolve_dilatation = .true.
      case (dilatation_full)
         resolve_dilatation = .false.
      case default
         resolve_dilatation = analysis /= plane_stress .and. poisson >= projected_poisson
      end select
   end function resolve_dilatation

   !> Name of a formulation choice ('auto', 'full', 'projected').
   pure function dilatation_name(choice) result(name)
      integer, intent(in) :: choice
      character(len=:), allocatable :: name
      select case (choice)
      case (dilatation_full)
         name = 'full'
      case (dilatation_projected)
         name = 'projected'
      case default
         name = 'auto'
      end select
   end function dilatation_name

   !> The choice named 'full' or 'projected'; anything else is `dilatation_auto`.
   pure integer function dilatation_choice(name)
      character(len=*), intent(in) :: name
      select case (name)
      case ('full')
         dilatation_choice = dilatation_full
      case ('projected')
         dilatation_choice = dilatation_projected
      case default
         dilatation_choice = dilatation_auto
      end select
   end function dilatation_choice

   !> Set up the projection: material split, aggregates from `root`
   !> (`sprc_fem_aggregation`), Gram matrices from the volume rules
   !> (x(:, ptr(e) : ptr(e+1)-1), weights w). `degree` is the FE degree
   !> (P0 for Q1, P1 for Q2). Fails when a Gram matrix is singular (an
   !> aggregate without volume), naming the root cell.
   subroutine build(self, analysis, d, degree, grid, root, vol_ptr, vol_x, vol_w, error)
      class(dilatation_type), intent(out) :: self
      integer, intent(in) :: analysis, degree
      real(wp), intent(in) :: d(:, :)
      type(grid_type), intent(in) :: grid
      integer, intent(in) :: root(:), vol_ptr(:)
      real(wp), intent(in) :: vol_x(:, :), vol_w(:)
      type(error_type), allocatable, intent(out) :: error
      integer, allocatable :: fill(:)
      real(wp) :: p(4), lo(3), hi(3)
      integer :: e, a, q, k, ns, info, n, j, stat
      character(len=160) :: buf
      character(len=*), parameter :: who = 'projected dilatation'

      self%active = .true.
      self%dim = grid%dim
      ns = size(d, 1)
      self%nstress = ns
      k = merge(3, 2, analysis == solid)
      self%m = 0.0_wp
      self%m(1:k) = 1.0_wp
      self%kappa = dot_product(self%m(1:ns), matmul(d, self%m(1:ns)))/real(k*k, wp)
      self%d_dev = 0.0_wp
      self%d_dev(1:ns, 1:ns) = d - self%kappa*spread(self%m(1:ns), 2, ns)*spread(self%m(1:ns), 1, ns)
      self%np = 1
      if (degree >= 2) self%np = self%dim + 1

      n = size(root)
      allocate (self%aggregate(n), self%member(n), stat=stat)
      call check_allocation(stat, who, 'the aggregate of each cell', n, 8, error)
      if (allocated(error)) return
      self%aggregate = 0
      self%n_aggregates = 0
      do e = 1, n
         if (root(e) /= e) cycle
         self%n_aggregates = self%n_aggregates + 1
         self%aggregate(e) = self%n_aggregates
      end do
      do e = 1, n
         self%aggregate(e) = self%aggregate(root(e))
      end do
      allocate (self%ptr(self%n_aggregates + 1), fill(self%n_aggregates), stat=stat)
      call check_allocation(stat, who, 'the aggregate members', self%n_aggregates + 1, 8, error)
      if (allocated(error)) return
      fill = 0
      do e = 1, n
         fill(self%aggregate(e)) = fill(self%aggregate(e)) + 1
      end do
      self%ptr(1) = 1
      do a = 1, self%n_aggregates
         self%ptr(a + 1) = self%ptr(a) + fill(a)
      end do
      fill = 0
      do e = 1, n
         if (root(e) /= e) cycle
         a = self%aggregate(e)
         self%member(self%ptr(a)) = e
         fill(a) = 1
      end do
      do e = 1, n
         if (root(e) == e) cycle
         a = self%aggregate(e)
         self%member(self%ptr(a) + fill(a)) = e
         fill(a) = fill(a) + 1
      end do

      allocate (self%centre(self%dim, self%n_aggregates), self%length(self%n_aggregates), &
         & self%gram(self%np, self%np, self%n_aggregates), self%coef(self%np, self%n_aggregates), stat=stat)
      call check_allocation(stat, who, 'the aggregate Gram matrices', self%n_aggregates, &
         & 8*(self%dim + 1 + self%np*(self%np + 1)), error)
      if (allocated(error)) return
      self%coef = 0.0_wp
      do a = 1, self%n_aggregates
         e = self%member(self%ptr(a))
         call grid%leaf_box(e, lo(1:self%dim), hi(1:self%dim))
         self%centre(:, a) = 0.5_wp*(lo(1:self%dim) + hi(1:self%dim))
         self%length(a) = maxval(hi(1:self%dim) - lo(1:self%dim))
         self%gram(:, :, a) = 0.0_wp
         do j = self%ptr(a), self%ptr(a + 1) - 1
            e = self%member(j)
            do q = vol_ptr(e), vol_ptr(e + 1) - 1
               call self%basis(a, vol_x(:, q), p(1:self%np))
               self%gram(:, :, a) = self%gram(:, :, a) + vol_w(q)* &
                  & spread(p(1:self%np), 2, self%np)*spread(p(1:self%np), 1, self%np)
            end do
         end do
         call dpotrf('U', self%np, self%gram(:, :, a), self%np, info)
         if (info /= 0) then
            write (buf, '("projected dilatation: the aggregate of cell ",i0," has a singular Gram matrix ", &
               & "(no volume inside the body)")') self%member(self%ptr(a)) - 1
            call fatal_error(error, trim(buf), stat_singular)
            return
         end if
      end do
   end subroutine build

   !> Dilatation basis p(np) of aggregate a at x: 1, then (x - centre)/length for P1.
   pure subroutine basis(self, a, x, p)
      class(dilatation_type), intent(in) :: self
      integer, intent(in) :: a
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: p(:)
      p(1) = 1.0_wp
      if (self%np > 1) p(2:self%np) = (x(1:self%dim) - self%centre(:, a))/self%length(a)
   end subroutine basis

   !> Moments g(dim*nen, np) = sum_q w_q (m^T B(x_q))^T p(x_q)^T of the element
   !> box [lo, hi] (Q`degree`) over its volume points x(:, q), weights w(q),
   !> in the basis of aggregate a: theta_bar's load on the element's dofs.
   pure subroutine element_moments(self, a, degree, lo, hi, x, w, g)
      class(dilatation_type), intent(in) :: self
      integer, intent(in) :: a, degree
      real(wp), intent(in) :: lo(:), hi(:), x(:, :), w(:)
      real(wp), intent(out) :: g(:, :)
      real(wp) :: n((degree + 1)**self%dim), dndx(self%dim, (degree + 1)**self%dim)
      real(wp) :: b(self%nstress, self%dim*(degree + 1)**self%dim)
      integer :: q

      g = 0.0_wp
      do q = 1, size(w)
         call shape_functions(self%dim, degree, lo, hi, x(:, q), n, dndx)
         call strain_matrix(self%dim, dndx, b)
         call self%add_moment(a, x(:, q), w(q), b, g)
      end do
   end subroutine element_moments

   !> One point's share of `element_moments`: g += w (m^T b)^T p(x)^T, b the
   !> strain matrix at x (for callers that have it already).
   pure subroutine add_moment(self, a, x, w, b, g)
      class(dilatation_type), intent(in) :: self
      integer, intent(in) :: a
      real(wp), intent(in) :: x(:), w, b(:, :)
      real(wp), intent(inout) :: g(:, :)
      real(wp) :: div(size(b, 2)), p(4)
      integer :: i
      div = matmul(self%m(1:self%nstress), b)
      call self%basis(a, x, p(1:self%np))
      do i = 1, self%np
         g(:, i) = g(:, i) + (w*p(i))*div
      end do
   end subroutine add_moment

   !> Add the dilatation terms of aggregate a on a dof set of size nd:
   !>   k += kappa (G M^-1 G^T - H M^-1 G^T - G M^-1 H^T),  f -= kappa G M^-1 s,
   !> with G(nd, np) the moments (`element_moments`) summed over the members,
   !> H(nd, np) = sum over the Nitsche points of w N^T P n p^T and
   !> s(np) = sum of w (g.P n) p (the data of the Nitsche terms with sigma_bar).
   subroutine add_aggregate_block(self, a, g, h, s, k, f)
      class(dilatation_type), intent(in) :: self
      integer, intent(in) :: a
      real(wp), intent(in) :: g(:, :), h(:, :), s(:)
      real(wp), intent(inout) :: k(:, :), f(:)
      real(wp) :: y(self%np, size(g, 1)), gy(size(g, 1), size(g, 1)), hy(size(g, 1), size(g, 1))
      integer :: nd, np, info

      nd = size(g, 1)
      np = self%np
      if (nd == 0) return
      y = transpose(g)
      call dpotrs('U', np, nd, self%gram(:, :, a), np, y, np, info)
      call dgemm('N', 'N', nd, nd, np, self%kappa, g, nd, y, np, 0.0_wp, gy, nd)
      call dgemm('N', 'N', nd, nd, np, self%kappa, h, nd, y, np, 0.0_wp, hy, nd)
      k = k + 0.5_wp*(gy + transpose(gy)) - hy - transpose(hy)
      f = f - self%kappa*matmul(s, y)
   end subroutine add_aggregate_block

   !> Coefficients of theta_bar on aggregate a from gu(np) = sum over the
   !> members of G_e^T u_e: coef = M_A^-1 gu.
   subroutine set_coefficients(self, a, gu)
      class(dilatation_type), intent(inout) :: self
      integer, intent(in) :: a
      real(wp), intent(in) :: gu(:)
      integer :: info
      self%coef(:, a) = gu
      call dpotrs('U', self%np, 1, self%gram(:, :, a), self%np, self%coef(:, a), self%np, info)
   end subroutine set_coefficients

   !> sigma = D_dev eps + kappa theta_bar(x) m for element e, given eps.
   pure subroutine projected_stress(self, e, x, eps, sigma)
      class(dilatation_type), intent(in) :: self
      integer, intent(in) :: e
      real(wp), intent(in) :: x(:), eps(:)
      real(wp), intent(out) :: sigma(:)
      real(wp) :: p(4)
      integer :: a, ns
      a = self%aggregate(e)
      ns = self%nstress
      call self%basis(a, x, p(1:self%np))
      sigma = matmul(self%d_dev(1:ns, 1:ns), eps) + (self%kappa*dot_product(p(1:self%np), self%coef(:, a)))* &
         & self%m(1:ns)
   end subroutine projected_stress

end module sprc_fem_dilatation
