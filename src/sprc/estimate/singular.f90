!> The singular part of the recovered field at re-entrant corners in 2D: the
!> split of SPR-CX (Rodenas, Gonzalez-Estrada, Tarancon, Fuenmayor 2008,
!> IJNME 76: sigma = sigma_smooth + sigma_singular, the smooth part recovered
!> by the patches, the singular part added in closed form). Near the apex the
!> stress grows like r^(lambda - 1) (sprc_exact_corner), which no patch
!> polynomial follows; the method and its reasons are in doc/theory.md,
!> section 8a.
!>
!> 1. `find_corners`: an element whose boundary points lie on two straight
!>    traction-free faces (to the relative tolerance `straight_tol`) meeting
!>    inside its box at a re-entrant angle, the normals at least 30 degrees
!>    apart (lambda1 <= 0.75: the weaker kinks of a faceted curve are left to
!>    the polynomials). The same apex found from two elements counts once;
!>    curved, loaded or symmetry faces are not corners (the eigenfunctions are
!>    those of straight free faces).
!> 2. `fit_corner`: the amplitudes (A1, A2) and a smooth part P c by least
!>    squares of the FE stress in the energy norm over the elements between
!>    `inner_cells` and `fit_cells` of their own width from the apex (the inner
!>    rings are polluted by the apex). The normal equations, columns scaled to
!>    unit diagonal, are solved by eigen-decomposition, eigenvalues below
!>    n eps of the largest dropped: the rank of the data decides.
!> 3. The patches recover sigma_h - S and t - S n (S is in equilibrium,
!>    compatible and free on the faces, so every constraint still holds) and the
!>    field adds S back (sprc_estimate_recovered_field); a patch holding an inner
!>    element takes the fit's P c as its data. All patches take part when one
!>    corner's wedge holds the whole body, else those within `enrich_cells` of
!>    their width from a corner; patches with symmetry points keep the whole
!>    field (the symmetry constraint is on the whole stress).
module sprc_estimate_singular
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type
   use sprc_core_material, only: plane_stress, plane_strain, compliance_matrix
   use sprc_core_lapack, only: dsyev
   use sprc_core_poly, only: poly_basis_type, new_poly_basis
   use sprc_exact_corner, only: corner_type, new_corner
   implicit none
   private

   public :: corner_site_type, singular_fit_type, find_corners, fit_corner
   public :: straight_tol, fit_cells, enrich_cells, inner_cells

   !> Relative tolerance of "straight face" and "apex in the element" (module notes).
   real(wp), parameter :: straight_tol = 1.0e-6_wp
   !> Smallest angle between the faces' normals of a corner (30 degrees).
   real(wp), parameter :: min_turn = 0.5235987755982988_wp
   !> Fit region and enriched patches, in element / patch widths from the apex.
   real(wp), parameter :: fit_cells = 8.0_wp, enrich_cells = 3.0_wp
   !> The apex rings, in element widths from the apex: left out of the fit, and the
   !> patches that hold such an element take their smooth part from the fit.
   real(wp), parameter :: inner_cells = 2.0_wp

   !> A corner found on the mesh: apex, unit bisector of the material wedge,
   !> opening in degrees, the width of the element that holds the apex.
   type :: corner_site_type
      real(wp) :: point(2) = 0.0_wp, direction(2) = 0.0_wp, angle = 0.0_wp, width = 0.0_wp
   end type corner_site_type

   !> A corner's fitted field: the singular part S (`corner`, amplitudes fitted) and the
   !> smooth part of the fit, smooth(i, :) the coefficients of component i in
   !> `basis` at (x - corner%point)/scale.
   type :: singular_fit_type
      type(corner_type) :: corner
      type(poly_basis_type) :: basis
      real(wp) :: scale = 1.0_wp
      real(wp), allocatable :: smooth(:, :)
   contains
      procedure :: smooth_stress
   end type singular_fit_type

contains

   !> The corners of the boundary points (module notes). `bx`, `bn` the points
   !> and unit outward normals, `belem_ptr` the points of each element (CSR),
   !> `free(k)` whether point k is traction free; `elem_lo`, `elem_hi` the boxes.
   pure subroutine find_corners(bx, bn, belem_ptr, free, elem_lo, elem_hi, sites)
      real(wp), intent(in) :: bx(:, :), bn(:, :), elem_lo(:, :), elem_hi(:, :)
      integer, intent(in) :: belem_ptr(:)
      logical, intent(in) :: free(:)
      type(corner_site_type), allocatable, intent(out) :: sites(:)
      type(corner_site_type) :: site
      integer :: e, a, b
      logical :: found

      allocate (sites(0))
      do e = 1, size(belem_ptr) - 1
         a = belem_ptr(e)
         b = belem_ptr(e + 1) - 1
         if (b - a < 1) cycle
         if (.not. all(free(a:b))) cycle
         call element_corner(bx(:, a:b), bn(:, a:b), elem_lo(:, e), elem_hi(:, e), site, found)
         if (.not. found) cycle
         if (any([(norm2(sites(a)%point - site%point) <= straight_tol*max(site%width, sites(a)%width), &
            & a=1, size(sites))])) cycle
         sites = [sites, site]
      end do
   end subroutine find_corners

   !> The corner of one element's boundary points, if they form one.
   pure subroutine element_corner(x, n, lo, hi, site, found)
      real(wp), intent(in) :: x(:, :), n(:, :), lo(:), hi(:)
      type(corner_site_type), intent(out) :: site
      logical, intent(out) :: found
      real(wp) :: na(2), nb(2), c(2), pa(2), pb(2), det, h, dmin, d
      integer :: i, j, ia, ib, m
      logical :: on_a(size(x, 2))

      found = .false.
      m = size(x, 2)
      h = maxval(hi - lo)
      ! the two most different normals
      dmin = 2.0_wp
      ia = 1
      ib = 1
      do i = 1, m
         do j = i + 1, m
            d = dot_product(n(1:2, i), n(1:2, j))
            if (d < dmin) then
               dmin = d
               ia = i
               ib = j
            end if
         end do
      end do
      if (dmin > cos(min_turn)) return
      na = n(1:2, ia)
      nb = n(1:2, ib)
      ! each point on the face whose normal it has
      do i = 1, m
         on_a(i) = dot_product(n(1:2, i), na) >= dot_product(n(1:2, i), nb)
         if (norm2(n(1:2, i) - merge(na, nb, on_a(i))) > straight_tol) return
      end do
      pa = x(1:2, ia)
      pb = x(1:2, ib)
      det = na(1)*nb(2) - na(2)*nb(1)
      c(1) = (dot_product(na, pa)*nb(2) - dot_product(nb, pb)*na(2))/det
      c(2) = (na(1)*dot_product(nb, pb) - nb(1)*dot_product(na, pa))/det
      if (any(c < lo - straight_tol*h) .or. any(c > hi + straight_tol*h)) return
      do i = 1, m
         if (on_a(i)) then
            if (abs(dot_product(na, x(1:2, i) - c)) > straight_tol*h) return
            if (dot_product(nb, x(1:2, i) - c) < -straight_tol*h) return
         else
            if (abs(dot_product(nb, x(1:2, i) - c)) > straight_tol*h) return
            if (dot_product(na, x(1:2, i) - c) < -straight_tol*h) return
         end if
      end do
      ! both faces present with a point off the apex (a re-entrant, not a convex, corner)
      if (.not. (any(on_a) .and. any(.not. on_a))) return
      if (maxval([(merge(dot_product(nb, x(1:2, i) - c), 0.0_wp, on_a(i)), i=1, m)]) <= straight_tol*h) return
      if (maxval([(merge(0.0_wp, dot_product(na, x(1:2, i) - c), on_a(i)), i=1, m)]) <= straight_tol*h) return
      site%point = c
      site%direction = -(na + nb)/norm2(na + nb)
      site%angle = 180.0_wp + acos(max(-1.0_wp, min(1.0_wp, dmin)))*180.0_wp/acos(-1.0_wp)
      site%width = h
      found = .true.
   end subroutine element_corner

   !> The singular field of `site` with amplitudes fitted to the FE stress
   !> (module notes). `x`, `w`, `stress` the volume points, weights and FE
   !> stresses, `elem_ptr` the points of each element; `degree` the polynomial
   !> degree of the smooth part. `ok` is false where the fit has no data or
   !> gives no amplitude (the corner is then left alone).
   subroutine fit_corner(site, analysis, young, poisson, x, w, stress, elem_ptr, elem_lo, elem_hi, degree, &
         & fit, ok)
      type(corner_site_type), intent(in) :: site
      integer, intent(in) :: analysis, elem_ptr(:), degree
      real(wp), intent(in) :: young, poisson, x(:, :), w(:), stress(:, :), elem_lo(:, :), elem_hi(:, :)
      type(singular_fit_type), intent(out) :: fit
      logical, intent(out) :: ok
      type(corner_type) :: mode(2)
      type(error_type), allocatable :: error
      real(wp), allocatable :: m(:, :), r(:), b(:, :), cb(:, :), ev(:), work(:), z(:)
      real(wp) :: c(3, 3), s(3), p(20), scale, dist, width
      integer :: nt, nu, e, k, i, info

      ok = .false.
      if (analysis /= plane_stress .and. analysis /= plane_strain) return
      call new_corner(mode(1), site%point, site%direction, site%angle, 1.0_wp, 0.0_wp, young, poisson, analysis, &
         & error)
      if (.not. allocated(error)) call new_corner(mode(2), site%point, site%direction, site%angle, 0.0_wp, 1.0_wp, &
         & young, poisson, analysis, error)
      if (.not. allocated(error)) call new_corner(fit%corner, site%point, site%direction, site%angle, 1.0_wp, 0.0_wp, &
         & young, poisson, analysis, error)
      if (.not. allocated(error)) call new_poly_basis(fit%basis, 2, degree, error)
      if (.not. allocated(error)) call compliance_matrix(analysis, young, poisson, c, error)
      if (allocated(error)) return
      nt = fit%basis%nterms
      nu = 2 + 3*nt
      allocate (m(nu, nu), r(nu), b(3, nu), cb(3, nu), ev(nu), work(max(1, 3*nu)), z(nu))
      m = 0.0_wp
      r = 0.0_wp
      scale = 0.0_wp
      do e = 1, size(elem_ptr) - 1
         call box_distance(site%point, elem_lo(:, e), elem_hi(:, e), dist, width)
         if (dist > fit_cells*width .or. dist < inner_cells*width) cycle
         scale = max(scale, dist + width*sqrt(2.0_wp))
      end do
      if (scale <= 0.0_wp) return
      do e = 1, size(elem_ptr) - 1
         call box_distance(site%point, elem_lo(:, e), elem_hi(:, e), dist, width)
         if (dist > fit_cells*width .or. dist < inner_cells*width) cycle
         do k = elem_ptr(e), elem_ptr(e + 1) - 1
            call mode(1)%stress(x(1:2, k), b(:, 1))
            call mode(2)%stress(x(1:2, k), b(:, 2))
            call fit%basis%eval((x(1:2, k) - site%point)/scale, p)
            b(:, 3:) = 0.0_wp
            do i = 1, 3
               b(i, 3 + (i - 1)*nt:2 + i*nt) = p(1:nt)
            end do
            cb = matmul(c, b)
            m = m + w(k)*matmul(transpose(b), cb)
            s = stress(1:3, k)
            r = r + w(k)*matmul(s, cb)
         end do
      end do
      ! columns to unit diagonal, then the pseudo-inverse of the eigen-decomposition
      do i = 1, nu
         z(i) = merge(1.0_wp/sqrt(m(i, i)), 0.0_wp, m(i, i) > 0.0_wp)
      end do
      if (z(1) == 0.0_wp .and. z(2) == 0.0_wp) return
      do i = 1, nu
         m(:, i) = m(:, i)*z*z(i)
      end do
      call dsyev('V', 'U', nu, m, nu, ev, work, size(work), info)
      if (info /= 0) return
      r = r*z
      ev = merge(1.0_wp/ev, 0.0_wp, ev > real(nu, wp)*epsilon(1.0_wp)*maxval(ev))
      r = matmul(m, ev*matmul(r, m))*z
      if (.not. all(abs(r(1:2)) <= huge(1.0_wp))) return
      fit%corner%amplitude = r(1:2)
      fit%scale = scale
      fit%smooth = transpose(reshape(r(3:), [nt, 3]))
      ok = any(r(1:2) /= 0.0_wp)
   end subroutine fit_corner

   !> The smooth part of the fit at x.
   pure subroutine smooth_stress(self, x, s)
      class(singular_fit_type), intent(in) :: self
      real(wp), intent(in) :: x(:)
      real(wp), intent(out) :: s(3)
      real(wp) :: p(20)
      call self%basis%eval((x(1:2) - self%corner%point)/self%scale, p)
      s = matmul(self%smooth, p(1:self%basis%nterms))
   end subroutine smooth_stress

   !> Distance from p to the box [lo, hi] and the box's width.
   pure subroutine box_distance(p, lo, hi, dist, width)
      real(wp), intent(in) :: p(:), lo(:), hi(:)
      real(wp), intent(out) :: dist, width
      dist = norm2(max(lo - p, 0.0_wp, p - hi))
      width = maxval(hi - lo)
   end subroutine box_distance

end module sprc_estimate_singular
