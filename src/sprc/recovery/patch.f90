!> Patch data for SPR / SPR-C recovery: plain arrays that any mesh can fill,
!> and the recovered polynomial of one patch.
!>
!> A patch is the set of elements sharing a vertex node. The recovery core
!> needs no mesh: a producer (the Cartesian grid, or a legacy code's
!> unstructured mesh) fills a `patch_type` with
!> - the analysis kind and the isotropic material,
!> - the patch node x0 and a patch size h (both only scale coordinates:
!>   s = (x - x0)/h; h is e.g. the largest distance from x0 to a patch node),
!> - integration points: coordinates, weight*|J| and the FE stress (Voigt),
!> - boundary quadrature points: coordinates, weight*|J|, outward unit normal,
!>   boundary kind, the boundary piece it lies on (e.g. the shape index; default 1)
!>   and, for traction boundaries, the prescribed traction,
!> - a constant body force (zero unless set),
!> - which constraint kinds SPR-C applies.
!>
!> Storage is reused: `patch_reset` keeps the arrays, `patch_add_point` and
!> `patch_add_boundary_point` grow them (doubling) only when a larger patch
!> comes, so a patch loop with one patch object per thread allocates nothing
!> once the largest patch has been seen. Arrays may also be filled directly:
!> set the leading columns and `npoints` / `nbpoints` (after `patch_reserve`; `bpiece`
!> is 1 in newly grown storage but keeps old values in reused storage: set it too).
!>
!> Symmetry boundaries are planes: the symmetry points of a patch are grouped
!> into (at most three) planes by their normal and offset, and SPR-C imposes
!> zero shear on each whole plane, not only at the points.
module sprc_recovery_patch
   use sprc_core_kinds, only: wp
   use sprc_core_boundary, only: bc_none, bc_traction, bc_symmetry, bc_contact
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, check_material
   implicit none
   private

   public :: patch_type, recovered_patch_type
   public :: patch_reset, patch_reserve, patch_add_point, patch_add_boundary_point, check_patch
   public :: boundary_traction, boundary_symmetry, boundary_contact, boundary_none
   public :: boundary_measure, dominant_boundary_kind, boundary_kind_name
   public :: kind_equilibrium, kind_compatibility, kind_traction, kind_symmetry, nconstraint_kinds

   !> Boundary kinds of boundary points, those of `sprc_core_boundary` a patch constrains.
   integer, parameter :: boundary_none = bc_none
   !> Prescribed traction t = sigma n (includes free surfaces, t = 0).
   integer, parameter :: boundary_traction = bc_traction
   !> Symmetry plane: zero shear traction on the plane.
   integer, parameter :: boundary_symmetry = bc_symmetry
   !> Contact surface (reserved: the contact constraints come with the contact layer).
   integer, parameter :: boundary_contact = bc_contact

   !> Constraint kinds, the index of the per-kind diagnostics of `recovered_patch_type`.
   integer, parameter :: kind_equilibrium = 1, kind_compatibility = 2, kind_traction = 3, kind_symmetry = 4
   !> The number of constraint kinds.
   integer, parameter :: nconstraint_kinds = 4

   !> Input of one patch recovery. All components are public plain data.
   type :: patch_type
      !> Space dimension, 2 or 3 (must agree with `analysis`).
      integer :: dim = 0
      !> plane_stress, plane_strain or solid (sprc_core_material).
      integer :: analysis = 0
      !> Young's modulus and Poisson's ratio.
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      !> Patch node (the origin of the scaled coordinates), x0(1:dim).
      real(wp) :: x0(3) = 0.0_wp
      !> Patch size h > 0 for the scaled coordinates s = (x - x0)/h.
      real(wp) :: h = 0.0_wp
      !> Number of integration points in use.
      integer :: npoints = 0
      !> Integration point coordinates x(1:dim, i).
      real(wp), allocatable :: x(:, :)
      !> Integration weight times |J|, > 0.
      real(wp), allocatable :: w(:)
      !> FE stress at the points, Voigt, stress(1:voigt_size, i).
      real(wp), allocatable :: stress(:, :)
      !> Number of boundary points in use.
      integer :: nbpoints = 0
      !> Boundary point coordinates bx(1:dim, j).
      real(wp), allocatable :: bx(:, :)
      !> Boundary weight times surface |J|, >= 0.
      real(wp), allocatable :: bw(:)
      !> Outward unit normal bn(1:dim, j).
      real(wp), allocatable :: bn(:, :)
      !> Boundary kind of point j (boundary_traction, boundary_symmetry, boundary_contact).
      integer, allocatable :: bkind(:)
      !> Boundary piece of point j (>= 1): the surface it lies on, e.g. the shape index. SPR-C
      !> bounds the traction constraint rank per piece (sprc_recovery_patch_solve).
      integer, allocatable :: bpiece(:)
      !> Prescribed traction vector t(1:dim, j) (traction points only; ignored otherwise).
      real(wp), allocatable :: btraction(:, :)
      !> Constant body force per unit volume, b(1:dim); equilibrium is div sigma + b = 0.
      real(wp) :: body_force(3) = 0.0_wp
      !> SPR-C: impose internal equilibrium (least-squares form).
      logical :: use_equilibrium = .true.
      !> SPR-C: impose compatibility (only acts for degree >= 2).
      logical :: use_compatibility = .true.
      !> SPR-C: impose boundary constraints (traction / symmetry).
      logical :: use_boundary = .true.
      !> For SPR-C, if false (the thesis's rule), only the boundary kind with the largest
      !> measure in the patch is imposed (`dominant_boundary_kind`); if true, every kind
      !> present is imposed (dependent rows are dropped by the rank selection).
      logical :: all_boundary_kinds = .false.
      !> Set by a producer that has validated every integration point it gathers (finite x
      !> and stress, 0 < w < huge; the caller's-mesh producer checks the caller's arrays once):
      !> `check_patch` then skips its per-point loop, which repeated that check for every
      !> patch a point belongs to. patch_reset clears it.
      logical :: points_checked = .false.
   end type patch_type

   !> Result of one patch recovery: sigma*(x) = P((x - x0)/h) A, plus diagnostics.
   !> Fixed-size storage, so arrays of it are copied and filled without allocation.
   type :: recovered_patch_type
      !> Dimension, number of stress components, degree and number of terms.
      integer :: dim = 0, nstress = 0, degree = -1, nterms = 0
      !> Scaling of the polynomial: s = (x - x0)/h.
      real(wp) :: x0(3) = 0.0_wp, h = 1.0_wp
      !> Coefficients A: coef(1:nterms, c) of stress component c, in sprc_core_poly's term order;
      !> allocated (nterms, nstress) by a successful solve.
      real(wp), allocatable :: coef(:, :)
      !> Rank of the (weighted) basis matrix at the integration points (= nterms on success).
      integer :: basis_rank = 0
      !> Per constraint kind (kind_equilibrium .. kind_symmetry): constraint rows generated
      !> and rows kept by the block's rank selection.
      integer :: rows(nconstraint_kinds) = 0, ranks(nconstraint_kinds) = 0
      !> Constraint rows in the KKT system after the rank selection of the stacked blocks.
      integer :: rank_total = 0
      !> Boundary kind imposed (boundary_none if none).
      integer :: boundary_kind = boundary_none
      !> Largest |R_kk|/|R_11| among the pivots discarded by any rank decision (0 if none).
      real(wp) :: max_dropped_ratio = 0.0_wp
      !> True when a discarded pivot was above round-off (max_dropped_ratio > recovery_bite_ratio):
      !> the rank tolerance, not exact dependence, decided the rank.
      logical :: tolerance_bites = .false.
      !> A 2D patch at the edge of a frictionless contact zone adds the edge field of amplitude
      !> edge_amplitude (sprc_recovery_contact_edge: edge point, unit tangent towards the open
      !> side, the body's outward normal) to its polynomial; 0: none.
      real(wp) :: edge_amplitude = 0.0_wp, edge_point(2) = 0.0_wp, edge_tangent(2) = 0.0_wp, edge_normal(2) = 0.0_wp
   end type recovered_patch_type

contains

   !> Start a new patch, keeping the storage: sets the scalars, zeroes the counts and
   !> the body force, restores the default constraint switches.
   pure subroutine patch_reset(patch, dim, analysis, young, poisson, x0, h)
      type(patch_type), intent(inout) :: patch
      integer, intent(in) :: dim, analysis
      real(wp), intent(in) :: young, poisson
      !> Patch node x0(1:dim).
      real(wp), intent(in) :: x0(:)
      real(wp), intent(in) :: h

      patch%dim = dim
      patch%analysis = analysis
      patch%young = young
      patch%poisson = poisson
      ! Entry by entry: a copy of run-time length is a memcpy call (per patch).
      patch%x0 = 0.0_wp
      if (size(x0) >= 1) patch%x0(1) = x0(1)
      if (size(x0) >= 2) patch%x0(2) = x0(2)
      if (size(x0) >= 3) patch%x0(3) = x0(3)
      patch%h = h
      patch%npoints = 0
      patch%nbpoints = 0
      patch%body_force = 0.0_wp
      patch%use_equilibrium = .true.
      patch%use_compatibility = .true.
      patch%use_boundary = .true.
      patch%all_boundary_kinds = .false.
      patch%points_checked = .false.
   end subroutine patch_reset

   !> Make room for at least `npoints` integration and `nbpoints` boundary points
   !> (3 coordinate rows, 6 stress rows, so one patch object serves 2D and 3D).
   !> Existing contents are kept; nothing is allocated if the capacity suffices.
   pure subroutine patch_reserve(patch, npoints, nbpoints)
      type(patch_type), intent(inout) :: patch
      integer, intent(in) :: npoints, nbpoints

      if (.not. allocated(patch%w)) then
         allocate (patch%x(3, 0), patch%w(0), patch%stress(6, 0))
         allocate (patch%bx(3, 0), patch%bw(0), patch%bn(3, 0), patch%bkind(0), patch%btraction(3, 0))
         allocate (patch%bpiece(0))
      end if
      if (npoints > size(patch%w)) then
         call grow2(patch%x, npoints)
         call grow1(patch%w, npoints)
         call grow2(patch%stress, npoints)
      end if
      if (nbpoints > size(patch%bw)) then
         call grow2(patch%bx, nbpoints)
         call grow1(patch%bw, nbpoints)
         call grow2(patch%bn, nbpoints)
         call grow2(patch%btraction, nbpoints)
         call grow1i(patch%bkind, nbpoints, boundary_none)
         call grow1i(patch%bpiece, nbpoints, 1)
      end if
   end subroutine patch_reserve

   !> Append an integration point (coordinates x(1:dim), weight*|J|, Voigt stress).
   pure subroutine patch_add_point(patch, x, w, stress)
      type(patch_type), intent(inout) :: patch
      real(wp), intent(in) :: x(:), w, stress(:)
      integer :: i

      ! Grow only when full, by doubling: reserving 2*npoints at every call
      ! reallocated at every point once the storage was half full (quadratic).
      if (.not. allocated(patch%w)) call patch_reserve(patch, 0, 0)
      if (patch%npoints >= size(patch%w)) call patch_reserve(patch, max(4, 2*patch%npoints), 0)
      i = patch%npoints + 1
      patch%x(:, i) = 0.0_wp
      patch%x(1:size(x), i) = x
      patch%w(i) = w
      patch%stress(:, i) = 0.0_wp
      patch%stress(1:size(stress), i) = stress
      patch%npoints = i
   end subroutine patch_add_point

   !> Append a boundary point (coordinates, weight*|J|, outward unit normal, kind,
   !> the prescribed traction for traction points, and the boundary piece, default 1).
   pure subroutine patch_add_boundary_point(patch, x, w, normal, kind, traction, piece)
      type(patch_type), intent(inout) :: patch
      real(wp), intent(in) :: x(:), w, normal(:)
      integer, intent(in) :: kind
      real(wp), intent(in), optional :: traction(:)
      integer, intent(in), optional :: piece
      integer :: j

      if (.not. allocated(patch%bw)) call patch_reserve(patch, 0, 0)
      if (patch%nbpoints >= size(patch%bw)) call patch_reserve(patch, 0, max(4, 2*patch%nbpoints))
      j = patch%nbpoints + 1
      patch%bx(:, j) = 0.0_wp
      patch%bx(1:size(x), j) = x
      patch%bw(j) = w
      patch%bn(:, j) = 0.0_wp
      patch%bn(1:size(normal), j) = normal
      patch%bkind(j) = kind
      patch%btraction(:, j) = 0.0_wp
      if (present(traction)) patch%btraction(1:size(traction), j) = traction
      patch%bpiece(j) = 1
      if (present(piece)) patch%bpiece(j) = piece
      patch%nbpoints = j
   end subroutine patch_add_boundary_point

   !> Total weight (length in 2D, area in 3D) of the boundary points of one kind.
   pure real(wp) function boundary_measure(patch, kind) result(measure)
      type(patch_type), intent(in) :: patch
      integer, intent(in) :: kind
      integer :: j

      measure = 0.0_wp
      do j = 1, patch%nbpoints
         if (patch%bkind(j) == kind) measure = measure + patch%bw(j)
      end do
   end function boundary_measure

   !> The boundary kind SPR-C imposes on a patch (the thesis, "Formulación del SPR-C"): contact
   !> whenever present, otherwise the kind with the largest measure inside the patch (ties:
   !> traction before symmetry); boundary_none if the patch has no boundary points.
   pure integer function dominant_boundary_kind(patch) result(kind)
      type(patch_type), intent(in) :: patch
      real(wp) :: mt, ms

      kind = boundary_none
      if (patch%nbpoints == 0) return
      if (any(patch%bkind(1:patch%nbpoints) == boundary_contact)) then
         kind = boundary_contact
         return
      end if
      mt = boundary_measure(patch, boundary_traction)
      ms = boundary_measure(patch, boundary_symmetry)
      if (any(patch%bkind(1:patch%nbpoints) == boundary_traction)) kind = boundary_traction
      if (any(patch%bkind(1:patch%nbpoints) == boundary_symmetry) .and. &
         & (kind == boundary_none .or. ms > mt)) kind = boundary_symmetry
   end function dominant_boundary_kind

   !> Name of a boundary kind, for messages.
   pure function boundary_kind_name(kind) result(name)
      integer, intent(in) :: kind
      character(len=:), allocatable :: name
      select case (kind)
      case (boundary_none); name = 'none'
      case (boundary_traction); name = 'traction'
      case (boundary_symmetry); name = 'symmetry'
      case (boundary_contact); name = 'contact'
      case default; name = 'unknown'
      end select
   end function boundary_kind_name

   !> Validate a patch: kinds and sizes, material, finite coordinates, positive weights,
   !> finite stresses, unit normals, known boundary kinds, finite tractions and body force.
   !> Messages name the field, the index and the value.
   pure subroutine check_patch(patch, error)
      type(patch_type), intent(in) :: patch
      type(error_type), allocatable, intent(out) :: error
      integer :: i, d, ns
      character(len=96) :: buf

      d = patch%dim
      ns = voigt_size(patch%analysis)
      if (ns == 0) then
         write (buf, '(i0)') patch%analysis
         call fail(error, 'analysis = '//trim(buf)//' is not plane_stress, plane_strain or solid')
         return
      end if
      if (.not. ((d == 2 .and. patch%analysis /= solid) .or. (d == 3 .and. patch%analysis == solid))) then
         write (buf, '("dim = ",i0," does not match analysis ",i0)') d, patch%analysis
         call fail(error, trim(buf))
         return
      end if
      call check_material(patch%young, patch%poisson, 'patch', error)
      if (allocated(error)) return
      if (.not. (patch%h > 0.0_wp .and. patch%h <= huge(1.0_wp))) then
         write (buf, '(es12.4)') patch%h
         call fail(error, 'h = '//trim(adjustl(buf))//' must be finite and > 0')
         return
      end if
      if (.not. all(abs(patch%x0(1:d)) <= huge(1.0_wp))) then
         call fail(error, 'x0 is not finite')
         return
      end if
      if (.not. all(abs(patch%body_force(1:d)) <= huge(1.0_wp))) then
         call fail(error, 'body_force is not finite')
         return
      end if
      if (patch%npoints < 1) then
         call fail(error, 'no integration points (npoints < 1)')
         return
      end if
      if (.not. allocated(patch%w)) then
         call fail(error, 'point arrays are not allocated (use patch_reserve or patch_add_point)')
         return
      end if
      if (patch%npoints > size(patch%w) .or. patch%npoints > size(patch%x, 2) .or. &
         & patch%npoints > size(patch%stress, 2) .or. size(patch%x, 1) < d .or. size(patch%stress, 1) < ns) then
         write (buf, '("npoints = ",i0," exceeds the point arrays (w has ",i0,")")') patch%npoints, size(patch%w)
         call fail(error, trim(buf))
         return
      end if
      do i = 1, merge(0, patch%npoints, patch%points_checked)
         if (.not. all(abs(patch%x(1:d, i)) <= huge(1.0_wp))) then
            write (buf, '("x(:, ",i0,") is not finite")') i
            call fail(error, trim(buf))
            return
         end if
         if (.not. (patch%w(i) > 0.0_wp .and. patch%w(i) <= huge(1.0_wp))) then
            write (buf, '("w(",i0,") = ",es12.4," must be finite and > 0")') i, patch%w(i)
            call fail(error, trim(buf))
            return
         end if
         if (.not. all(abs(patch%stress(1:ns, i)) <= huge(1.0_wp))) then
            write (buf, '("stress(:, ",i0,") is not finite (NaN or Inf)")') i
            call fail(error, trim(buf))
            return
         end if
      end do
      call check_boundary(patch, error)
   end subroutine check_patch

   pure subroutine fail(error, message)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), intent(in) :: message
      call fatal_error(error, 'patch: '//message, stat_invalid_input)
   end subroutine fail

   pure subroutine check_boundary(patch, error)
      type(patch_type), intent(in) :: patch
      type(error_type), allocatable, intent(out) :: error
      integer :: j, d
      real(wp) :: nrm
      character(len=96) :: buf

      d = patch%dim
      if (patch%nbpoints < 0) then
         call fatal_error(error, 'patch: nbpoints < 0', stat_invalid_input)
         return
      end if
      if (patch%nbpoints == 0) return
      if (.not. (allocated(patch%bw) .and. allocated(patch%bx) .and. allocated(patch%bn) .and. &
         & allocated(patch%bkind) .and. allocated(patch%btraction) .and. allocated(patch%bpiece))) then
         call fatal_error(error, 'patch: boundary arrays are not allocated (use patch_reserve)', stat_invalid_input)
         return
      end if
      if (patch%nbpoints > size(patch%bw) .or. patch%nbpoints > size(patch%bx, 2) .or. &
         & patch%nbpoints > size(patch%bn, 2) .or. patch%nbpoints > size(patch%bkind) .or. &
         & patch%nbpoints > size(patch%btraction, 2) .or. patch%nbpoints > size(patch%bpiece) .or. &
         & size(patch%bx, 1) < d .or. &
         & size(patch%bn, 1) < d .or. size(patch%btraction, 1) < d) then
         write (buf, '("nbpoints = ",i0," exceeds the boundary arrays (bw has ",i0,")")') &
            & patch%nbpoints, size(patch%bw)
         call fatal_error(error, 'patch: '//trim(buf), stat_invalid_input)
         return
      end if
      do j = 1, patch%nbpoints
         buf = ''
         nrm = sqrt(sum(patch%bn(1:d, j)**2))
         if (.not. all(abs(patch%bx(1:d, j)) <= huge(1.0_wp))) then
            write (buf, '("bx(:, ",i0,") is not finite")') j
         else if (.not. (patch%bw(j) >= 0.0_wp .and. patch%bw(j) <= huge(1.0_wp))) then
            write (buf, '("bw(",i0,") = ",es12.4," must be finite and >= 0")') j, patch%bw(j)
         else if (.not. (abs(nrm - 1.0_wp) <= 1.0e-8_wp)) then
            write (buf, '("bn(:, ",i0,") has length ",es12.4,", expected a unit normal")') j, nrm
         else if (.not. any(patch%bkind(j) == [boundary_traction, boundary_symmetry, boundary_contact])) then
            write (buf, '("bkind(",i0,") = ",i0," is not traction=",i0,", symmetry=",i0," or contact=",i0)') j, &
               & patch%bkind(j), boundary_traction, boundary_symmetry, boundary_contact
         else if (patch%bpiece(j) < 1) then
            write (buf, '("bpiece(",i0,") = ",i0," must be >= 1")') j, patch%bpiece(j)
         else if (patch%bkind(j) == boundary_traction .and. &
            & .not. all(abs(patch%btraction(1:d, j)) <= huge(1.0_wp))) then
            write (buf, '("btraction(:, ",i0,") is not finite")') j
         end if
         if (len_trim(buf) > 0) then
            call fatal_error(error, 'patch: '//trim(buf), stat_invalid_input)
            return
         end if
      end do
   end subroutine check_boundary

   pure subroutine grow1(a, n)
      real(wp), allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n
      real(wp), allocatable :: tmp(:)
      allocate (tmp(n))
      tmp = 0.0_wp
      tmp(1:size(a)) = a
      call move_alloc(tmp, a)
   end subroutine grow1

   pure subroutine grow1i(a, n, fill)
      integer, allocatable, intent(inout) :: a(:)
      integer, intent(in) :: n, fill
      integer, allocatable :: tmp(:)
      allocate (tmp(n))
      tmp = fill
      tmp(1:size(a)) = a
      call move_alloc(tmp, a)
   end subroutine grow1i

   pure subroutine grow2(a, n)
      real(wp), allocatable, intent(inout) :: a(:, :)
      integer, intent(in) :: n
      real(wp), allocatable :: tmp(:, :)
      allocate (tmp(size(a, 1), n))
      tmp = 0.0_wp
      tmp(:, 1:size(a, 2)) = a
      call move_alloc(tmp, a)
   end subroutine grow2

end module sprc_recovery_patch
