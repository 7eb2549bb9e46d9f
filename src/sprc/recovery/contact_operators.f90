!> Operators of the SPR-C contact constraint (thesis eqs. 103-128, with the errata of
!> eqs. 118, 119 and 127 in doc/theory.md, section 11), built generically from the traction operator
!> G(n) of sprc_recovery_operators, never from the thesis's written-out matrices.
!>
!> At a contact point of body (1) with outward unit normal n and the frame
!> R = [n s] (2D) or [n s p] (3D), the traction of a stress sigma in that frame is
!>   t_nsp = R^T sigma n = H sigma,   H = R^T G(n)   (eqs. 108, 117-119),
!> whose rows are n^T sigma n, s^T sigma n and p^T sigma n: the shear columns carry
!> 2 n_a n_b in the first row (erratum of eq. 118) and n_a t_b + n_b t_a in the others
!> (erratum of eqs. 119, 127: n_x p_z + n_z p_x).
!> The contact law enters as H'_t = K_t H (eqs. 121-127) with K_t the d x d matrix of
!> the law acting on body (2)'s frame traction:
!> - frictionless (eqs. 122-123): K = diag(1, 0, 0): t_n1 = t_n2, t_s1 = t_p1 = 0;
!> - Coulomb slip (eqs. 124-125): K = [1 0 0; mu 0 0; 0 0 0]: t_n1 = t_n2,
!>   t_s1 = mu t_n2, t_p1 = 0 (eqs. 114-115);
!> - stick (eqs. 126-127): K = I: the whole traction vector is continuous.
!> Both bodies' stresses are evaluated in body (1)'s frame: n2 = -n1 (eq. 107), so
!> H sigma1 - H'_t sigma2 = 0 is action-reaction with the law (eq. 121).
!>
!> Slip direction and sign. s is the unit direction in which body (1) slides relative
!> to body (2) (the tangential part of u1 - u2). With t_n <= 0 in compression, eq. 114's
!> t_s = mu t_n is the friction traction on body (1), of magnitude mu p (p = -t_n the
!> contact pressure), opposed to its slip. (The contact FE's tau, the direction of the
!> tangential traction on the slave, is -s.) Frictionless and stick take any orthonormal
!> completion of n (`plane_tangents`): the residual's norm does not depend on it.
!>
!> What the operator leaves free: body (2)'s tangential traction under frictionless and
!> slip laws (only body (1)'s is constrained: t_s2 is the subject of body (2)'s own,
!> mirrored contact patches), and all in-plane stresses of both bodies, which may jump
!> across a contact surface.
!>
!> Small deformations: n, s and p are those of the undeformed slave surface (the
!> thesis's deformed normals n^d agree to first order, which linear elasticity neglects).
!>
!> Coefficient rows (eqs. 128-132): with sigma(x) = P(s(x)) A, A stacked by component
!> (nt coefficients per Voigt component), op sigma(x) = (op x p(s(x))) A, i.e. the row i
!> of `contact_rows` is op(i, c) p_k(s) at column (c - 1) nt + k; Z(x) is
!> [rows(H, s1(x)), -rows(H'_t, s2(x))] with each body's own scaled coordinates.
module sprc_recovery_contact_operators
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_recovery_operators, only: traction_operator, plane_tangents
   implicit none
   private

   public :: contact_law_frictionless, contact_law_slip, contact_law_stick, contact_law_name
   public :: contact_frame, contact_operator, contact_law_matrix, contact_law_operator, contact_rows
   public :: contact_normal_tol, contact_traction

   !> Contact law at a closed contact point: frictionless, Coulomb slip (sliding at
   !> |t_t| = mu p) and stick (Coulomb below the limit, or friction 'stick').
   integer, parameter :: contact_law_frictionless = 1, contact_law_slip = 2, contact_law_stick = 3
   !> A normal counts as unit if | |n| - 1 | <= contact_normal_tol (as patch normals, check_patch).
   real(wp), parameter :: contact_normal_tol = 1.0e-8_wp

contains

   !> Name of a contact law, for messages.
   pure function contact_law_name(law) result(name)
      integer, intent(in) :: law
      character(len=:), allocatable :: name
      select case (law)
      case (contact_law_frictionless); name = 'frictionless'
      case (contact_law_slip); name = 'slip'
      case (contact_law_stick); name = 'stick'
      case default; name = 'unknown'
      end select
   end function contact_law_name

   !> The frame R = [n s (p)] of a contact point (columns frame(1:dim, 1:dim)), right-handed.
   !> With `slip` (any vector with a tangential part; only its direction counts), s is its
   !> tangential part normalised: the slip direction of body (1) relative to body (2) (module
   !> notes); in 2D only its sign along the tangent counts. Without `slip`, s (and p) are
   !> `plane_tangents(n)`. Errors (stat_invalid_input): n not unit, slip not finite or without
   !> a tangential part above sqrt(eps) |slip|.
   pure subroutine contact_frame(dim, n, frame, error, slip)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(:)
      real(wp), intent(out) :: frame(3, 3)
      type(error_type), allocatable, intent(out) :: error
      real(wp), intent(in), optional :: slip(:)
      real(wp) :: t(3, 2), st(3), nrm
      character(len=96) :: buf

      frame = 0.0_wp
      nrm = sqrt(sum(n(1:dim)**2))
      if (.not. (abs(nrm - 1.0_wp) <= contact_normal_tol)) then
         write (buf, '("normal has length ",es12.4,", expected a unit normal")') nrm
         call fatal_error(error, 'contact_frame: '//trim(buf), stat_invalid_input)
         return
      end if
      frame(1:dim, 1) = n(1:dim)
      call plane_tangents(dim, n, t)
      frame(:, 2:3) = t
      if (.not. present(slip)) return
      st = 0.0_wp
      st(1:dim) = slip(1:dim) - dot_product(slip(1:dim), n(1:dim))*n(1:dim)
      nrm = sqrt(sum(st(1:dim)**2))
      if (.not. (all(abs(slip(1:dim)) <= huge(1.0_wp)) .and. &
         & nrm > sqrt(epsilon(1.0_wp))*sqrt(sum(slip(1:dim)**2)))) then
         call fatal_error(error, 'contact_frame: the slip direction is not finite or has no part tangent '// &
            & 'to the contact surface', stat_invalid_input)
         return
      end if
      if (dim == 2) then
         if (dot_product(st(1:2), t(1:2, 1)) < 0.0_wp) frame(1:2, 2) = -t(1:2, 1)
         return
      end if
      frame(:, 2) = st/nrm
      frame(:, 3) = [n(2)*frame(3, 2) - n(3)*frame(2, 2), n(3)*frame(1, 2) - n(1)*frame(3, 2), &
         & n(1)*frame(2, 2) - n(2)*frame(1, 2)]
   end subroutine contact_frame

   !> H = R^T G(n) (eqs. 117-119 with the errata): h(i, c), i = 1..dim (n, s, p rows),
   !> c = 1..nstress; n = frame(:, 1).
   pure subroutine contact_operator(dim, frame, h)
      integer, intent(in) :: dim
      real(wp), intent(in) :: frame(3, 3)
      real(wp), intent(out) :: h(:, :)
      real(wp) :: g(3, 6)
      integer :: ns

      ns = merge(3, 6, dim == 2)
      call traction_operator(dim, frame(:, 1), g)
      h(1:dim, 1:ns) = matmul(transpose(frame(1:dim, 1:dim)), g(1:dim, 1:ns))
   end subroutine contact_operator

   !> K_t of a contact law (module notes): k(1:dim, 1:dim). Slip needs mu >= 0.
   pure subroutine contact_law_matrix(dim, law, mu, k, error)
      integer, intent(in) :: dim, law
      real(wp), intent(in) :: mu
      real(wp), intent(out) :: k(3, 3)
      type(error_type), allocatable, intent(out) :: error
      integer :: i
      character(len=96) :: buf

      k = 0.0_wp
      select case (law)
      case (contact_law_frictionless)
         k(1, 1) = 1.0_wp
      case (contact_law_slip)
         if (.not. (mu >= 0.0_wp .and. mu <= huge(1.0_wp))) then
            write (buf, '("mu = ",es12.4," must be finite and >= 0")') mu
            call fatal_error(error, 'contact_law_matrix: '//trim(buf), stat_invalid_input)
            return
         end if
         k(1, 1) = 1.0_wp
         k(2, 1) = mu
      case (contact_law_stick)
         do i = 1, dim
            k(i, i) = 1.0_wp
         end do
      case default
         write (buf, '("law = ",i0," is not frictionless=",i0,", slip=",i0," or stick=",i0)') law, &
            & contact_law_frictionless, contact_law_slip, contact_law_stick
         call fatal_error(error, 'contact_law_matrix: '//trim(buf), stat_invalid_input)
      end select
   end subroutine contact_law_matrix

   !> H'_t = K_t H (eqs. 122-127): hp(1:dim, 1:nstress) from h(1:dim, 1:nstress).
   pure subroutine contact_law_operator(dim, law, mu, h, hp, error)
      integer, intent(in) :: dim, law
      real(wp), intent(in) :: mu, h(:, :)
      real(wp), intent(out) :: hp(:, :)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: k(3, 3)
      integer :: ns

      ns = merge(3, 6, dim == 2)
      call contact_law_matrix(dim, law, mu, k, error)
      if (allocated(error)) return
      hp(1:dim, 1:ns) = matmul(k(1:dim, 1:dim), h(1:dim, 1:ns))
   end subroutine contact_law_operator

   !> Coefficient rows of an operator on sigma = P(s) A (module notes):
   !> rows(i, (c - 1) nt + k) = factor op(i, c) p(k), i = 1..dim, over nstress nt columns.
   pure subroutine contact_rows(dim, nt, op, p, factor, rows)
      integer, intent(in) :: dim, nt
      real(wp), intent(in) :: op(:, :), p(:), factor
      real(wp), intent(out) :: rows(:, :)
      integer :: i, c

      do c = 1, merge(3, 6, dim == 2)
         do i = 1, dim
            rows(i, (c - 1)*nt + 1:c*nt) = (factor*op(i, c))*p(1:nt)
         end do
      end do
   end subroutine contact_rows

   !> Contact pressure p = -n^T sigma n (positive in compression) and magnitude ts of the
   !> tangential traction |sigma n - (n^T sigma n) n| of the Voigt stress sigma at a point with
   !> unit normal n: the p and ts of a contact result (sprc_contact_result).
   pure subroutine contact_traction(dim, n, sigma, p, ts)
      integer, intent(in) :: dim
      real(wp), intent(in) :: n(:), sigma(:)
      real(wp), intent(out) :: p, ts
      real(wp) :: g(3, 6), t(3)
      integer :: ns

      ns = merge(3, 6, dim == 2)
      call traction_operator(dim, n, g)
      t(1:dim) = matmul(g(1:dim, 1:ns), sigma(1:ns))
      p = -dot_product(n(1:dim), t(1:dim))
      ts = norm2(t(1:dim) + p*n(1:dim))
   end subroutine contact_traction

end module sprc_recovery_contact_operators
