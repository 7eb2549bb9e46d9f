!> What a scene asks for, as plain validated data (doc/scene.md): the scene, its
!> bodies, shapes, boundary conditions, exact solution and contact pairs.
!> These are *specifications*: the geometry objects built from them live in
!> `sprc_geometry_*`, the FE conditions in `sprc_fem_bc`. `sprc_io_scene`
!> reads and validates scene files into them; the study layer runs them.
module sprc_study_spec
   use sprc_core_kinds, only: wp
   use sprc_core_text, only: real_text, itoa
   use sprc_recovery_patch_loop, only: auto_degree
   use sprc_geometry_facets, only: facet_set_type
   ! The defaults and limits scene validation needs from the layers that own
   ! them, handed to io here so that io (file formats) names no fem or grid module.
   use sprc_fem_dilatation, only: projected_poisson
   use sprc_fem_linear_solver, only: solver_names, auto_iterative_min_dofs, auto_never, auto_coupled_iterative_min_dofs
   use sprc_fem_problem, only: default_gamma, gamma_note
   use sprc_grid_tree, only: grid_max_level
   implicit none
   private

   public :: scene_type, body_spec_type, shape_spec_type, bc_spec_type, exact_spec_type, contact_spec_type
   public :: adapt_spec_type, default_max_level
   public :: recovery_degree, contact_unsupported, contact_components
   public :: default_kappa, default_stabilization, kappa_range, kappa_note, default_multiplier, auto_multiplier
   public :: projected_poisson, solver_names, auto_iterative_min_dofs, auto_never, default_gamma, gamma_note
   public :: auto_coupled_iterative_min_dofs
   public :: grid_max_level

   !> Default of `&contact kappa`, the dimensionless factor of the contact
   !> stabilization (effective stiffness kappa*E/h, thesis eq. 5): the centre,
   !> in decades, of the safe range `kappa_range`, so that every kappa from a
   !> hundredth to a hundred times the default is safe (test kappa_decades);
   !> a lower default put a stiff Q2 slave's loss of coercivity in that range.
   real(wp), parameter :: default_kappa = 1.0e4_wp
   !> Safe range of `&contact kappa` (sweeps in doc/benchmarks.md, "Contact"):
   !> inside, err_fe and p_max_fe do not depend on kappa. Below, the
   !> stabilization no longer dominates the slave's trace-inverse bound
   !> (coercivity is lost); above, the block system's rcond falls in proportion
   !> to kappa until the rigid-mode check or the factorization fails.
   real(wp), parameter :: kappa_range(2) = [100.0_wp, 1.0e6_wp]
   !> Lower end of the safe range with `stabilization = 'recovered'`, whose
   !> cell blocks are a plain penalty (no trace-inverse bound to beat): on the
   !> shrink fit it settles down to kappa = 0.1 and stalls below
   !> (doc/benchmarks.md, "Contact").
   real(wp), parameter :: kappa_min_recovered = 0.1_wp
   !> Default of `&contact stabilization`: the FE stress. At the default kappa
   !> the recovered variant gives the same results to 4 digits at 1.0-1.15x
   !> the time (README "Contact", figures in the commit that chose it).
   character(len=*), parameter :: default_stabilization = 'fe'
   !> Default of `&contact multiplier` (doc/scene.md): 'auto', resolved by
   !> `auto_multiplier` when the scene is read.
   character(len=*), parameter :: default_multiplier = 'auto'

   !> One elastic body.
   type :: body_spec_type
      !> Unique non-empty name.
      character(len=:), allocatable :: name
      !> Young's modulus, > 0.
      real(wp) :: young = 0.0_wp
      !> Poisson's ratio, -1 < poisson < 0.5.
      real(wp) :: poisson = 0.0_wp
      !> Body force per unit volume, `dim` values.
      real(wp), allocatable :: body_force(:)
      !> The body's level-0 cell: its own `box_min`, `box_size` when `has_box`,
      !> else copies of the `&scene` ones.
      real(wp), allocatable :: box_min(:)
      real(wp) :: box_size = 0.0_wp
      logical :: has_box = .false.
   end type body_spec_type

   !> One CSG primitive of a body; its surface keeps `name`.
   !> Array fields are allocated (with `dim` values) only for the kinds using them.
   type :: shape_spec_type
      !> Name of the body it builds.
      character(len=:), allocatable :: body
      !> Index of that body in `scene%bodies`.
      integer :: body_index = 0
      !> Index of the shape among its body's shapes (1..number of shapes of that body, file order):
      !> the shape index the body's geometry, FE conditions and recovery input use.
      integer :: body_shape = 0
      !> 'add' | 'subtract' | 'intersect'.
      character(len=:), allocatable :: op
      !> 'disk' | 'sphere' | 'ellipse' | 'ellipsoid' | 'box' | 'halfspace' | 'cylinder' |
      !> 'stl' | 'obj' | 'polygon' (the faceted kinds).
      character(len=:), allocatable :: kind
      !> Unique non-empty name of the surface.
      character(len=:), allocatable :: name
      !> Centre (disk, sphere, ellipse, ellipsoid).
      real(wp), allocatable :: center(:)
      !> Radius (disk, sphere, cylinder), > 0.
      real(wp) :: radius = 0.0_wp
      !> Semi-axes (ellipse, ellipsoid), all > 0.
      real(wp), allocatable :: semi_axes(:)
      !> Corners (box), lower < upper componentwise.
      real(wp), allocatable :: lower(:), upper(:)
      !> A point on the plane (halfspace) or on the axis (cylinder).
      real(wp), allocatable :: point(:)
      !> Unit outward normal (halfspace): the body side is (x - point).normal <= 0.
      real(wp), allocatable :: normal(:)
      !> Unit axis direction (cylinder).
      real(wp), allocatable :: axis(:)
      !> Geometry file (stl, obj, polygon) as the scene gives it.
      character(len=:), allocatable :: file
      !> Faceted kinds: x -> scale*x + translate applied to the file's vertices.
      real(wp) :: scale = 1.0_wp
      real(wp), allocatable :: translate(:)
      !> Vertices x1, y1, x2, y2, ... (polygon without a file).
      real(wp), allocatable :: points(:)
      !> Faceted kinds: the validated closed surface, placed and oriented outwards;
      !> its groups are surfaces of their own for `&bc on`.
      type(facet_set_type) :: facets
      !> '' or a note for the user from the validation (a surface flipped outwards).
      character(len=:), allocatable :: note
   end type shape_spec_type

   !> A boundary condition on one shape surface.
   type :: bc_spec_type
      !> Name of the shape surface.
      character(len=:), allocatable :: on
      !> Index of that shape in `scene%shapes`.
      integer :: shape_index = 0
      !> A group of a faceted shape (index in its `facets%group_name`) when `on`
      !> names one; 0 when `on` names the shape's whole surface.
      integer :: group = 0
      !> 'free' | 'pressure' | 'traction' | 'displacement' | 'symmetry' |
      !> 'exact_traction' | 'exact_displacement'.
      character(len=:), allocatable :: type
      !> Pressure (type 'pressure'): t = -value n.
      real(wp) :: value = 0.0_wp
      !> Traction or displacement (types 'traction', 'displacement'), `dim` values.
      real(wp), allocatable :: vector(:)
      !> Load stage, >= 1: applied once the stages before it are (doc/scene.md).
      integer :: stage = 1
   end type bc_spec_type

   !> The analytical solution, if any.
   type :: exact_spec_type
      !> Whether the scene has an `&exact` group.
      logical :: present = .false.
      !> 'lame_cylinder' | 'lame_sphere' | 'kirsch' | 'uniform' | 'compound_cylinder' |
      !> 'compound_sphere' | 'layered_cylinder' | 'layered_sphere' | 'hertz_cylinder' | 'hertz_sphere' |
      !> 'corner'.
      character(len=:), allocatable :: kind
      !> Centre, `dim` values.
      real(wp), allocatable :: center(:)
      !> Lamé: inner and outer radius, inner and outer pressure.
      real(wp) :: r_in = 0.0_wp, r_out = 0.0_wp, p_in = 0.0_wp, p_out = 0.0_wp
      !> Kirsch: hole radius and remote uniaxial stress along x. Hertz: relative radius.
      real(wp) :: radius = 0.0_wp, s_inf = 0.0_wp
      !> Uniform: the stress in Voigt order, 3 (2D) or 6 (3D) values.
      real(wp), allocatable :: stress(:)
      !> Compound: contact radius (r_in < r_contact < r_out) and radial interference, >= 0.
      real(wp) :: r_contact = 0.0_wp, interference = 0.0_wp
      !> Compound: the inner and outer bodies and their indices in `scene%bodies`.
      character(len=:), allocatable :: inner, outer
      integer :: inner_index = 0, outer_index = 0
      !> For layered_*, the radii r_0 < ... < r_n (n + 1 values, inside out), the n ring bodies
      !> inside out (names and indices in `scene%bodies`) and the n - 1 radial interferences.
      real(wp), allocatable :: radii(:), interferences(:)
      !> For layered_* and compound_*, the interferences as lengths (the inner rings' outer
      !> surfaces lie that far out; not scaled with the analysis units, as lengths are not).
      real(wp), allocatable :: ring_shifts(:)
      character(len=:), allocatable :: ring_names
      integer, allocatable :: ring_index(:)
      !> Hertz: first-contact point and the unit normal of the contact plane, `dim` values.
      real(wp), allocatable :: point(:), normal(:)
      !> Hertz: the whole contact force (per unit thickness in 2D), > 0.
      real(wp) :: load = 0.0_wp
      !> Corner: unit bisector of the material wedge (`point` is the apex), 2 values.
      real(wp), allocatable :: direction(:)
      !> Corner: opening of the material wedge in degrees, 180 < angle <= 360.
      real(wp) :: angle = 0.0_wp
      !> Corner: amplitudes of the mode 1 (symmetric) and mode 2 (antisymmetric) fields, not both 0.
      real(wp) :: mode1 = 0.0_wp, mode2 = 0.0_wp
   end type exact_spec_type

   !> A contact pair between two bodies.
   type :: contact_spec_type
      !> Body names and their indices in `scene%bodies`.
      character(len=:), allocatable :: slave, master
      integer :: slave_index = 0, master_index = 0
      !> Surfaces in contact: their names, their shapes' indices in `scene%shapes`
      !> and, for a group of a faceted shape, the group (index in its
      !> `facets%group_name`; 0 for the shape's whole surface).
      character(len=:), allocatable :: slave_surface, master_surface
      integer :: slave_surface_index = 0, master_surface_index = 0
      integer :: slave_group = 0, master_group = 0
      !> 'frictionless' | 'coulomb' | 'stick'.
      character(len=:), allocatable :: friction
      !> Friction coefficient (coulomb), >= 0.
      real(wp) :: mu = 0.0_wp
      !> Stabilization factor, > 0; `default_kappa` unless given (`has_kappa`).
      real(wp) :: kappa = default_kappa
      logical :: has_kappa = .false.
      !> Load increments per stage, >= 1.
      integer :: steps = 1
      !> Source of the stabilization stress: 'fe' | 'recovered'.
      character(len=:), allocatable :: stabilization
      !> The multiplier space: 'constant' | 'linear' ('auto' resolved when read, `auto_multiplier`).
      character(len=:), allocatable :: multiplier
      !> SPR-C's contact-edge field at the edges of 2D frictionless contact zones (doc/scene.md).
      logical :: edges = .true.
   end type contact_spec_type

   !> Default of `&adapt max_level`, 2D and 3D: the deepest cell an adaptive
   !> run may make. Local refinement keeps the cell count far below that of a
   !> uniform grid of the same level, so it lies above the uniform limits of
   !> `&scene levels` (14, 9). In 2D it is the grid's own limit
   !> (`grid_max_level`): the apex of a re-entrant corner asks for the deepest
   !> cells a target of 0.1 % with Q2 needs; in 3D the budget stops a run
   !> long before level 12 anywhere but at a point.
   integer, parameter :: default_max_level(2:3) = [20, 12]

   !> Error-driven adaptivity (`&adapt`; absent: the uniform study of `levels`).
   type :: adapt_spec_type
      !> Whether the scene has an `&adapt` group.
      logical :: present = .false.
      !> Stop when eta <= target (eta_sprc where SPR-C runs, else eta_spr); 0 < target < 1.
      real(wp) :: target = 0.0_wp
      !> Analyses at most, the start mesh included; >= 1.
      integer :: max_steps = 10
      !> Dofs at most (over all bodies); 0: what the memory budget allows.
      integer :: max_dofs = 0
      !> 'optimal' (the size field of equidistributed error) | 'fraction' (Doerfler marking).
      character(len=:), allocatable :: strategy
      !> 'fraction': the share of the squared estimate the refined cells carry, 0 < fraction <= 1.
      real(wp) :: fraction = 0.5_wp
      !> Deepest cell level, start level <= max_level <= grid_max_level.
      integer :: max_level = 0
   end type adapt_spec_type

   !> A validated scene, defaults filled in.
   type :: scene_type
      !> Name of the source (file name) it was read from.
      character(len=:), allocatable :: source
      character(len=:), allocatable :: title
      !> 'plane_stress' | 'plane_strain' | 'solid'.
      character(len=:), allocatable :: analysis
      !> 2 for plane_stress and plane_strain, 3 for solid.
      integer :: dim = 0
      !> FE degree, 1 or 2.
      integer :: order = 1
      !> Uniform grid levels, strictly increasing; with `&adapt` one value, the start level.
      integer, allocatable :: levels(:)
      !> Extra levels on cut elements, 0..6.
      integer :: refine_boundary = 0
      !> Corner of the level-0 cell, `dim` values.
      real(wp), allocatable :: box_min(:)
      !> Edge of the level-0 cell, > 0.
      real(wp) :: box_size = 0.0_wp
      !> 'none' | 'spr' | 'sprc' | 'both'.
      character(len=:), allocatable :: recovery
      !> Patch polynomial degree of SPR and SPR-C: 'auto' (SPR at p, SPR-C at p+1 for order 2
      !> and p for order 1), 'p' (the FE degree) or 'p+1'.
      character(len=:), allocatable :: recovery_degree
      !> Prefix of the files written; '' writes none.
      character(len=:), allocatable :: output
      !> Volumetric formulation: 'auto' | 'full' | 'projected' (`sprc_fem_dilatation`).
      character(len=:), allocatable :: dilatation
      !> Nitsche penalty factor, > 0 (default `default_gamma(order)`).
      real(wp) :: nitsche_gamma = 0.0_wp
      !> Linear solver: 'auto' | 'direct' | 'iterative' (`sprc_fem_linear_solver`).
      character(len=:), allocatable :: solver
      type(body_spec_type), allocatable :: bodies(:)
      type(shape_spec_type), allocatable :: shapes(:)
      type(bc_spec_type), allocatable :: bcs(:)
      type(exact_spec_type) :: exact
      type(contact_spec_type), allocatable :: contacts(:)
      !> Adaptivity; `adapt%present` false: the uniform study.
      type(adapt_spec_type) :: adapt
   end type scene_type

contains

   !> The multiplier space of `multiplier = 'auto'` (doc/scene.md): linear
   !> in 2D, where the constant one leaves the Q2 interface pressure on a
   !> floor the Q2 solution falls below (the compound cylinder's pressure
   !> stalls at rate 0.4 from the third level) and the Q1 pressure at its
   !> own projection error (Hertz: several times the linear one's);
   !> constant in 3D (several times the solve time). `order` is kept for
   !> callers. doc/benchmarks.md has the measurements.
   pure function auto_multiplier(dim, order) result(name)
      integer, intent(in) :: dim, order
      character(len=:), allocatable :: name
      if (dim == 2) then
         name = 'linear'
      else
         name = 'constant'
      end if
   end function auto_multiplier

   !> '' when `kappa` lies in the safe range of `stabilization` ('fe':
   !> `kappa_range`; 'recovered': down to `kappa_min_recovered`), else a
   !> sentence saying what to expect (for a warning).
   function kappa_note(kappa, stabilization) result(note)
      real(wp), intent(in) :: kappa
      character(len=*), intent(in) :: stabilization
      character(len=:), allocatable :: note
      real(wp) :: low

      note = ''
      low = kappa_range(1)
      if (stabilization == 'recovered') low = kappa_min_recovered
      if (kappa >= low .and. kappa <= kappa_range(2)) return
      note = 'kappa = '//real_text(kappa)//' lies outside the safe range ['//real_text(low)//', '// &
         & real_text(kappa_range(2))//'] of stabilization '''//stabilization//''': '
      if (kappa < low) then
         note = note//'the contact stabilization may not hold the gap (the pressure error grows several times, '// &
            & 'the active set may cycle); raise it'
      else
         note = note//'the condition number of the contact system grows in proportion to kappa (singular near '// &
            & '1e10); lower it'
      end if
   end function kappa_note

   !> Patch polynomial degree of the scene's recovery `method` (1 SPR, 2 SPR-C): 'auto' (the
   !> default) by sprc_recovery_patch_loop's `auto_degree`, 'p' the FE order, 'p+1' one more.
   pure integer function recovery_degree(scene, method)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: method
      recovery_degree = auto_degree(method == 2, scene%order)
      if (.not. allocated(scene%recovery_degree)) return
      if (scene%recovery_degree == 'p') recovery_degree = scene%order
      if (scene%recovery_degree == 'p+1') recovery_degree = scene%order + 1
   end function recovery_degree

   !> Pairs of a component with more than one pair are solved together
   !> (`contact_components`); this version runs such a component with
   !> friction 'frictionless' or 'stick' and the FE stabilization stress only
   !> (Coulomb's load path and the recovered stabilization's fixed point are
   !> per pair). Empty when the scene can run.
   pure function contact_unsupported(scene) result(why)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: why
      integer, allocatable :: comp(:)
      integer :: k, n

      why = ''
      if (.not. allocated(scene%contacts)) return
      if (size(scene%contacts) == 0) return
      call contact_components(scene, comp, n)
      do k = 1, size(scene%contacts)
         associate (c => scene%contacts(k))
            if (c%stabilization == 'recovered' .and. c%friction == 'coulomb') then
               why = "&contact: stabilization = 'recovered' with friction = 'coulomb' is not in this version (use 'fe')"
            else if (count(comp(scene%contacts%slave_index) == comp(c%slave_index)) > 1 .and. &
               & (c%stabilization == 'recovered' .or. c%friction == 'coulomb')) then
               why = '&contact '//itoa(k)//": friction = '"//c%friction//"', stabilization = '"//c%stabilization// &
                  & "' in an assembly of several pairs: this version solves several pairs together with "// &
                  & "friction 'frictionless' or 'stick' and stabilization 'fe' only"
            end if
         end associate
         if (len(why) > 0) return
      end do
   end function contact_unsupported

   !> The components of the contact graph (bodies joined by `&contact` pairs):
   !> comp(b) in 1..n for a body in contact, numbered in the order of their
   !> first body; 0 for a body without contact (its own problem).
   pure subroutine contact_components(scene, comp, n)
      type(scene_type), intent(in) :: scene
      integer, allocatable, intent(out) :: comp(:)
      integer, intent(out) :: n
      integer :: b, k, root(size(scene%bodies)), a, c

      root = [(b, b=1, size(scene%bodies))]
      do k = 1, size(scene%contacts)
         a = find(scene%contacts(k)%slave_index)
         c = find(scene%contacts(k)%master_index)
         root(max(a, c)) = min(a, c)
      end do
      allocate (comp(size(scene%bodies)), source=0)
      n = 0
      do b = 1, size(scene%bodies)
         if (.not. (any(scene%contacts%slave_index == b) .or. any(scene%contacts%master_index == b))) cycle
         a = find(b)
         if (comp(a) == 0) then
            n = n + 1
            comp(a) = n
         end if
         comp(b) = comp(a)
      end do
   contains
      pure integer function find(b0)
         integer, intent(in) :: b0
         find = b0
         do while (root(find) /= find)
            find = root(find)
         end do
      end function find
   end subroutine contact_components

end module sprc_study_spec
