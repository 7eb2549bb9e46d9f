!> Scene files (doc/scene.md): read every group, validate everything before any
!> computation, and describe what the scene switches on and off.
!>
!> Every error names the file, line, group, field and offending value, e.g.
!> `scene.nml:7: &body: poisson = 0.5: must satisfy -1 < poisson < 0.5 ...`.
module sprc_io_scene
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: itoa, real_text, lower
   use sprc_core_error, only: error_type, fatal_error
   use sprc_exact_corner, only: corner_eigenvalues
   use sprc_study_spec, only: scene_type, body_spec_type, shape_spec_type, bc_spec_type, exact_spec_type, &
      & contact_spec_type, recovery_degree, default_stabilization, contact_unsupported, default_max_level, &
      & contact_components, projected_poisson, solver_names, auto_iterative_min_dofs, auto_never, default_gamma, &
      & auto_coupled_iterative_min_dofs, &
      & gamma_note, grid_max_level, default_multiplier, auto_multiplier
   use sprc_io_scene_facets, only: load_facets, facet_kind, facet_summary, group_surface
   use sprc_io_namelist, only: nml_group_type, parse_namelist, read_text_file, nml_get, nml_get_array, &
      & nml_has, nml_check_consumed, nml_field_error, nml_group_error, nml_item_text
   implicit none
   private

   public :: scene_type, body_spec_type, shape_spec_type, bc_spec_type, exact_spec_type, contact_spec_type
   public :: read_scene, read_scene_text, default_scene_text, scene_summary, recovery_degree, real_text

   character(len=*), parameter :: known_groups(7) = [character(len=7) :: 'scene', 'body', 'shape', 'bc', &
      & 'exact', 'contact', 'adapt']
   character(len=*), parameter :: scene_keys = 'title analysis order levels refine_boundary box_min box_size '// &
      & 'recovery recovery_degree output dilatation nitsche_gamma solver'
   character(len=*), parameter :: body_keys = 'name young poisson body_force box_min box_size'
   character(len=*), parameter :: shape_fields = 'center radius semi_axes lower upper point normal axis '// &
      & 'file scale translate points'
   character(len=*), parameter :: shape_keys = 'body op kind name '//shape_fields
   character(len=*), parameter :: bc_fields = 'value vector'
   character(len=*), parameter :: bc_keys = 'on type stage '//bc_fields
   character(len=*), parameter :: exact_fields = 'center r_in r_out p_in p_out radius s_inf stress r_contact '// &
      & 'inner outer interference point normal load direction angle mode1 mode2 radii bodies'
   character(len=*), parameter :: exact_keys = 'kind '//exact_fields
   character(len=*), parameter :: contact_keys = 'slave master slave_surface master_surface friction mu kappa '// &
      & 'steps stabilization multiplier edges'

   character(len=*), parameter :: adapt_keys = 'target max_steps max_dofs strategy fraction max_level'
   character(len=*), parameter :: strategies = 'optimal fraction'

   character(len=*), parameter :: analyses = 'plane_stress plane_strain solid'
   character(len=*), parameter :: recoveries = 'none spr sprc both'
   character(len=*), parameter :: recovery_degrees = 'auto p p+1'
   character(len=*), parameter :: dilatations = 'auto full projected'
   character(len=*), parameter :: ops = 'add subtract intersect'
   character(len=*), parameter :: shape_kinds = 'disk sphere ellipse ellipsoid box halfspace cylinder stl obj polygon'
   character(len=*), parameter :: bc_types = 'free pressure traction displacement symmetry exact_traction '// &
      & 'exact_displacement'
   character(len=*), parameter :: exact_kinds = 'lame_cylinder lame_sphere kirsch uniform compound_cylinder '// &
      & 'compound_sphere layered_cylinder layered_sphere hertz_cylinder hertz_sphere corner'
   character(len=*), parameter :: frictions = 'frictionless coulomb stick'
   character(len=*), parameter :: stabilizations = 'fe recovered'
   character(len=*), parameter :: multipliers = 'auto constant linear'

   !> Deepest uniform level accepted, 2D and 3D: 4^14 and 8^9 cells are already
   !> far beyond what a direct solver handles.
   integer, parameter :: max_level_2d = 14, max_level_3d = 9
   integer, parameter :: max_refine_boundary = 6

   !> Longest name of a body or shape: names are identifiers that messages quote
   !> (a 100,000-character name was echoed whole in every message naming it).
   integer, parameter :: max_name_length = 64
   character(len=*), parameter :: name_chars = &
      'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-.'

contains

   !> Read and validate a scene file. A missing or unreadable file is
   !> `stat_io`; a bad scene `stat_invalid_input`.
   subroutine read_scene(path, scene, error)
      !> Path of the scene file; messages name it.
      character(len=*), intent(in) :: path
      type(scene_type), intent(out) :: scene
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text

      call read_text_file(path, text, error)
      if (allocated(error)) return
      call read_scene_text(text, path, scene, error)
   end subroutine read_scene

   !> Read and validate a scene given as namelist text.
   subroutine read_scene_text(text, source_name, scene, error)
      !> The scene file's text.
      character(len=*), intent(in) :: text
      !> Name of the source for messages (a file name).
      character(len=*), intent(in) :: source_name
      type(scene_type), intent(out) :: scene
      type(error_type), allocatable, intent(out) :: error
      type(nml_group_type), allocatable :: groups(:)

      scene%source = source_name
      call parse_namelist(text, source_name, groups, error, known_groups)
      if (allocated(error)) return
      if (size(groups) == 0) then
         if (len_trim(text) == 0) then
            call fatal_error(error, source_name//': empty file: a scene needs a &scene group and at least one &body')
         else
            call fatal_error(error, source_name//': no namelist group in the file (only comments or blanks): '// &
               & 'a scene needs a &scene group and at least one &body')
         end if
         return
      end if
      call read_scene_group(groups, scene, error)
      if (allocated(error)) return
      call read_bodies(groups, scene, error)
      if (allocated(error)) return
      call read_shapes(groups, scene, error)
      if (allocated(error)) return
      call read_exact(groups, scene, error)
      if (allocated(error)) return
      call read_bcs(groups, scene, error)
      if (allocated(error)) return
      call read_contacts(groups, scene, error)
      if (allocated(error)) return
      call read_adapt(groups, scene, error)
   end subroutine read_scene_text

   !> The built-in default scene: the Lamé cylinder study of doc/scene.md,
   !> byte-identical to example/scenes/lame_cylinder.nml.
   function default_scene_text() result(text)
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      text = &
         "&scene"//nl// &
         "  title    = 'Thick cylinder under internal pressure, quarter model'"//nl// &
         "  analysis = 'plane_strain'   ! 'plane_stress' | 'plane_strain' | 'solid' (3D)"//nl// &
         "  order    = 1                ! FE degree, 1 or 2"//nl// &
         "  levels   = 3, 4, 5, 6       ! uniform grid levels: one analysis each (the study)"//nl// &
         "  refine_boundary = 0         ! extra levels on cut elements, 2:1 balanced"//nl// &
         "  box_min  = 0.0, 0.0         ! corner of the level-0 cell (2 or 3 values)"//nl// &
         "  box_size = 25.0             ! edge of the level-0 square/cube"//nl// &
         "  recovery = 'both'           ! 'none' | 'spr' | 'sprc' | 'both'"//nl// &
         "  output   = 'out/lame'       ! prefix of the files written; '' writes none"//nl// &
         "/"//nl// &
         "&body  name='cylinder' young=1000.0 poisson=0.3 body_force=0.0, 0.0 /"//nl// &
         "&shape body='cylinder' op='add'       kind='disk'      name='outer' center=0,0 radius=20 /"//nl// &
         "&shape body='cylinder' op='subtract'  kind='disk'      name='inner' center=0,0 radius=5 /"//nl// &
         "&shape body='cylinder' op='intersect' kind='halfspace' name='sym_x' point=0,0 normal=-1,0 /"//nl// &
         "&shape body='cylinder' op='intersect' kind='halfspace' name='sym_y' point=0,0 normal=0,-1 /"//nl// &
         "&bc    on='inner' type='pressure' value=1.0 /"//nl// &
         "&bc    on='sym_x' type='symmetry' /"//nl// &
         "&bc    on='sym_y' type='symmetry' /"//nl// &
         "&exact kind='lame_cylinder' center=0,0 r_in=5 r_out=20 p_in=1.0 /"//nl
   end function default_scene_text

   ! ---------------------------------------------------------------- &scene

   subroutine read_scene_group(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig, i, max_level
      logical :: found

      ig = 0
      do i = 1, size(groups)
         if (groups(i)%name /= 'scene') cycle
         if (ig > 0) then
            call nml_group_error(groups(i), 'a second &scene group (the first is on line '// &
               & itoa(groups(ig)%line)//'): a scene file has exactly one', error)
            return
         end if
         ig = i
      end do
      if (ig == 0) then
         call fatal_error(error, groups(1)%source//': no &scene group: a scene file needs exactly one '// &
            & '(analysis, levels, box_min, box_size)')
         return
      end if
      associate (g => groups(ig))
         call check_keys(g, scene_keys, error)
         if (allocated(error)) return
         scene%title = ''
         call nml_get(g, 'title', scene%title, found, error)
         if (allocated(error)) return
         call get_choice(g, 'analysis', analyses, .true., scene%analysis, error)
         if (allocated(error)) return
         scene%dim = 2
         if (scene%analysis == 'solid') scene%dim = 3
         call nml_get(g, 'order', scene%order, found, error)
         if (allocated(error)) return
         if (scene%order /= 1 .and. scene%order /= 2) then
            call nml_field_error(g, 'order', 'must be 1 or 2 (the FE degree)', error)
            return
         end if
         max_level = max_level_2d
         if (scene%dim == 3) max_level = max_level_3d
         call nml_get_array(g, 'levels', scene%levels, 1, max_level + 1, found, error)
         if (allocated(error)) return
         if (.not. found) then
            call nml_field_error(g, 'levels', 'required (the uniform grid levels of the study, e.g. 3, 4, 5)', error)
            return
         end if
         if (any(scene%levels < 0 .or. scene%levels > max_level)) then
            call nml_field_error(g, 'levels', 'each level must be 0 to '//itoa(max_level)//' in '// &
               & itoa(scene%dim)//'D', error)
            return
         end if
         do i = 2, size(scene%levels)
            if (scene%levels(i) <= scene%levels(i - 1)) then
               call nml_field_error(g, 'levels', 'must be strictly increasing', error)
               return
            end if
         end do
         call nml_get(g, 'refine_boundary', scene%refine_boundary, found, error)
         if (allocated(error)) return
         if (scene%refine_boundary < 0 .or. scene%refine_boundary > max_refine_boundary) then
            call nml_field_error(g, 'refine_boundary', 'must be 0 to '//itoa(max_refine_boundary), error)
            return
         end if
         call get_vector(g, 'box_min', scene%dim, .true., scene%box_min, error)
         if (allocated(error)) return
         call get_positive(g, 'box_size', .true., scene%box_size, error)
         if (allocated(error)) return
         scene%recovery = 'both'
         call get_choice(g, 'recovery', recoveries, .false., scene%recovery, error)
         if (allocated(error)) return
         scene%recovery_degree = 'auto'
         call get_choice(g, 'recovery_degree', recovery_degrees, .false., scene%recovery_degree, error)
         if (allocated(error)) return
         scene%output = ''
         call nml_get(g, 'output', scene%output, found, error)
         if (allocated(error)) return
         if (len(scene%output) > 0) then
            ! 'res/' would write the hidden files res/.csv, res/.h5, ...
            if (scene%output(len(scene%output):) == '/') then
               call nml_field_error(g, 'output', 'names a directory; give a file prefix such as '''// &
                  & scene%output//'name''', error)
               return
            end if
         end if
         scene%dilatation = 'auto'
         call get_choice(g, 'dilatation', dilatations, .false., scene%dilatation, error)
         if (allocated(error)) return
         scene%nitsche_gamma = default_gamma(scene%order)
         call get_positive(g, 'nitsche_gamma', .false., scene%nitsche_gamma, error)
         if (allocated(error)) return
         scene%solver = 'auto'
         call get_choice(g, 'solver', solver_names, .false., scene%solver, error)
         if (allocated(error)) return
         call nml_check_consumed(g, error)
      end associate
   end subroutine read_scene_group

   ! ----------------------------------------------------------------- &body

   subroutine read_bodies(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig, n, j
      logical :: found

      allocate (scene%bodies(count_groups(groups, 'body')))
      if (size(scene%bodies) == 0) then
         call fatal_error(error, scene%source//': no &body group: a scene needs at least one body')
         return
      end if
      n = 0
      do ig = 1, size(groups)
         if (groups(ig)%name /= 'body') cycle
         n = n + 1
         associate (g => groups(ig), body => scene%bodies(n))
            call check_keys(g, body_keys, error)
            if (allocated(error)) return
            call get_name(g, 'name', body%name, error)
            if (allocated(error)) return
            do j = 1, n - 1
               if (scene%bodies(j)%name == body%name) then
                  call nml_field_error(g, 'name', 'duplicate body name', error)
                  return
               end if
            end do
            call get_positive(g, 'young', .true., body%young, error)
            if (allocated(error)) return
            call nml_get(g, 'poisson', body%poisson, found, error)
            if (allocated(error)) return
            if (.not. found) then
               call nml_field_error(g, 'poisson', 'required (Poisson''s ratio, -1 < poisson < 0.5)', error)
               return
            end if
            if (body%poisson >= 0.5_wp) then
               call nml_field_error(g, 'poisson', 'must satisfy -1 < poisson < 0.5 (the incompressible limit '// &
                  & 'is not supported by displacement finite elements)', error)
               return
            else if (body%poisson <= -1.0_wp) then
               call nml_field_error(g, 'poisson', 'must satisfy -1 < poisson < 0.5', error)
               return
            end if
            allocate (body%body_force(scene%dim), source=0.0_wp)
            call get_vector(g, 'body_force', scene%dim, .false., body%body_force, error)
            if (allocated(error)) return
            call read_body_box(g, scene, body, error)
            if (allocated(error)) return
            call nml_check_consumed(g, error)
            if (allocated(error)) return
         end associate
      end do
   end subroutine read_bodies

   !> The body's own level-0 cell (`box_min` and `box_size` together, validated
   !> like the `&scene` ones), else the scene's.
   subroutine read_body_box(g, scene, body, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      type(body_spec_type), intent(inout) :: body
      type(error_type), allocatable, intent(out) :: error

      body%has_box = nml_has(g, 'box_min') .or. nml_has(g, 'box_size')
      body%box_min = scene%box_min
      body%box_size = scene%box_size
      if (.not. body%has_box) return
      if (.not. nml_has(g, 'box_min')) then
         call nml_field_error(g, 'box_min', 'required with box_size (the body''s own level-0 cell needs both)', error)
         return
      end if
      call get_vector(g, 'box_min', scene%dim, .true., body%box_min, error)
      if (allocated(error)) return
      call get_positive(g, 'box_size', .false., body%box_size, error)
      if (allocated(error)) return
      if (.not. nml_has(g, 'box_size')) &
         & call nml_field_error(g, 'box_size', 'required with box_min (the body''s own level-0 cell needs both)', error)
   end subroutine read_body_box

   ! ---------------------------------------------------------------- &shape

   subroutine read_shapes(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig, n, j
      integer, allocatable :: nshape(:)

      allocate (scene%shapes(count_groups(groups, 'shape')))
      allocate (nshape(size(scene%bodies)), source=0)
      n = 0
      do ig = 1, size(groups)
         if (groups(ig)%name /= 'shape') cycle
         n = n + 1
         associate (g => groups(ig), shape => scene%shapes(n))
            call check_keys(g, shape_keys, error)
            if (allocated(error)) return
            call get_name(g, 'body', shape%body, error)
            if (allocated(error)) return
            shape%body_index = body_index(scene, shape%body)
            if (shape%body_index == 0) then
               call nml_field_error(g, 'body', 'no &body has this name; bodies: '//body_names(scene), error)
               return
            end if
            call get_choice(g, 'op', ops, .true., shape%op, error)
            if (allocated(error)) return
            if (nshape(shape%body_index) == 0 .and. shape%op /= 'add') then
               call nml_field_error(g, 'op', "the first shape of body '"//shape%body// &
                  & "' must have op = 'add' (a body starts from a shape, then adds, subtracts or intersects)", error)
               return
            end if
            nshape(shape%body_index) = nshape(shape%body_index) + 1
            shape%body_shape = nshape(shape%body_index)
            call get_choice(g, 'kind', shape_kinds, .true., shape%kind, error)
            if (allocated(error)) return
            if (kind_dim(shape%kind) /= 0 .and. kind_dim(shape%kind) /= scene%dim) then
               call nml_field_error(g, 'kind', 'is a '//itoa(kind_dim(shape%kind))//'D shape; analysis = '''// &
                  & scene%analysis//''' is '//itoa(scene%dim)//'D', error)
               return
            end if
            call get_name(g, 'name', shape%name, error)
            if (allocated(error)) return
            do j = 1, n - 1
               if (scene%shapes(j)%name == shape%name) then
                  call nml_field_error(g, 'name', 'duplicate shape name (shape names are unique across the scene)', &
                     & error)
                  return
               end if
            end do
            call read_shape_fields(g, scene%dim, shape, error)
            if (.not. allocated(error) .and. facet_kind(shape%kind)) call read_facet_fields(g, scene, shape, error)
            if (allocated(error)) return
            call nml_check_consumed(g, error)
            if (allocated(error)) return
         end associate
      end do
      do j = 1, size(scene%bodies)
         if (nshape(j) == 0) then
            call fatal_error(error, scene%source//": body '"//scene%bodies(j)%name// &
               & "' has no &shape: every body is built from at least one shape")
            return
         end if
      end do
   end subroutine read_shapes

   !> Geometric fields of a shape, as its kind requires.
   subroutine read_shape_fields(g, dim, shape, error)
      type(nml_group_type), intent(inout) :: g
      integer, intent(in) :: dim
      type(shape_spec_type), intent(inout) :: shape
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: fields
      integer :: i

      select case (shape%kind)
      case ('disk', 'sphere'); fields = 'center radius'
      case ('ellipse', 'ellipsoid'); fields = 'center semi_axes'
      case ('box'); fields = 'lower upper'
      case ('halfspace'); fields = 'point normal'
      case ('stl', 'obj', 'polygon'); return
      case default; fields = 'point axis radius'
      end select
      call check_fields(g, shape_fields, fields, '', "kind = '"//shape%kind//"'", error)
      if (allocated(error)) return
      if (has_word(fields, 'center')) call get_vector(g, 'center', dim, .true., shape%center, error)
      if (allocated(error)) return
      if (has_word(fields, 'point')) call get_vector(g, 'point', dim, .true., shape%point, error)
      if (allocated(error)) return
      if (has_word(fields, 'radius')) call get_positive(g, 'radius', .true., shape%radius, error)
      if (allocated(error)) return
      if (has_word(fields, 'semi_axes')) then
         call get_vector(g, 'semi_axes', dim, .true., shape%semi_axes, error)
         if (allocated(error)) return
         if (any(shape%semi_axes <= 0.0_wp)) then
            call nml_field_error(g, 'semi_axes', 'every semi-axis must be > 0', error)
            return
         end if
      end if
      if (has_word(fields, 'lower')) then
         call get_vector(g, 'lower', dim, .true., shape%lower, error)
         if (allocated(error)) return
         call get_vector(g, 'upper', dim, .true., shape%upper, error)
         if (allocated(error)) return
         do i = 1, dim
            if (shape%lower(i) >= shape%upper(i)) then
               call nml_field_error(g, 'upper', 'must exceed lower = '//nml_item_text(g, 'lower')// &
                  & ' in every component (component '//itoa(i)//' does not)', error)
               return
            end if
         end do
      end if
      if (has_word(fields, 'normal')) call get_direction(g, 'normal', dim, shape%normal, error)
      if (allocated(error)) return
      if (has_word(fields, 'axis')) call get_direction(g, 'axis', dim, shape%axis, error)
   end subroutine read_shape_fields

   !> Fields of a faceted shape (stl, obj: `file`; polygon: `points` or
   !> `file`; all: `scale`, `translate`), then its surface read, placed and
   !> validated. A relative `file` is relative to the scene file's directory.
   subroutine read_facet_fields(g, scene, shape, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      type(shape_spec_type), intent(inout) :: shape
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: why
      integer :: stat
      logical :: found

      if (shape%kind == 'polygon') then
         call check_fields(g, shape_fields, '', 'points file scale translate', "kind = 'polygon'", error)
         if (.not. allocated(error) .and. (nml_has(g, 'points') .eqv. nml_has(g, 'file'))) &
            & call nml_group_error(g, "kind = 'polygon' takes either points = x1,y1, x2,y2, ... or file = '...'", error)
      else
         call check_fields(g, shape_fields, 'file', 'scale translate', "kind = '"//shape%kind//"'", error)
      end if
      if (allocated(error)) return
      if (nml_has(g, 'file')) then
         call nml_get(g, 'file', shape%file, found, error)
         if (.not. allocated(error) .and. len_trim(shape%file) == 0) call nml_field_error(g, 'file', 'is empty', error)
      end if
      if (.not. allocated(error) .and. nml_has(g, 'points')) &
         & call nml_get_array(g, 'points', shape%points, 2, huge(1), found, error)
      if (.not. allocated(error)) call get_positive(g, 'scale', .false., shape%scale, error)
      if (.not. allocated(error)) call get_vector(g, 'translate', scene%dim, .false., shape%translate, error)
      if (allocated(error)) return
      if (.not. allocated(shape%translate)) allocate (shape%translate(scene%dim), source=0.0_wp)
      call load_facets(scene%source, shape, error)
      if (.not. allocated(error)) return
      why = error%message
      stat = error%stat
      call nml_field_error(g, trim(merge('file  ', 'points', nml_has(g, 'file'))), why, error, stat)
   end subroutine read_facet_fields

   !> Dimension of a shape kind; 0 for kinds valid in 2D and 3D.
   pure integer function kind_dim(kind)
      character(len=*), intent(in) :: kind
      select case (kind)
      case ('disk', 'ellipse', 'lame_cylinder', 'kirsch', 'compound_cylinder', 'layered_cylinder', 'hertz_cylinder', &
         & 'corner', 'polygon'); kind_dim = 2
      case ('sphere', 'ellipsoid', 'cylinder', 'lame_sphere', 'compound_sphere', 'layered_sphere', 'hertz_sphere', &
         & 'stl', 'obj')
         kind_dim = 3
      case default; kind_dim = 0
      end select
   end function kind_dim

   ! ------------------------------------------------------------------- &bc

   subroutine read_bcs(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig, n
      integer, allocatable :: line_of(:)
      character(len=:), allocatable :: fields, why
      logical :: found

      allocate (scene%bcs(count_groups(groups, 'bc')))
      allocate (line_of(size(scene%bcs)), source=0)
      n = 0
      do ig = 1, size(groups)
         if (groups(ig)%name /= 'bc') cycle
         n = n + 1
         associate (g => groups(ig), bc => scene%bcs(n))
            call check_keys(g, bc_keys, error)
            if (allocated(error)) return
            call get_name(g, 'on', bc%on, error)
            if (allocated(error)) return
            bc%shape_index = shape_index(scene, bc%on)
            call check_unambiguous(g, 'on', scene, bc%on, bc%shape_index, error)
            if (allocated(error)) return
            if (bc%shape_index == 0) then
               call group_surface(scene%shapes, bc%on, bc%shape_index, bc%group, error)
               if (allocated(error)) then
                  why = error%message
                  call nml_field_error(g, 'on', why//'; surfaces: '//shape_names(scene), error)
                  return
               end if
            end if
            line_of(n) = g%line
            call get_choice(g, 'type', bc_types, .true., bc%type, error)
            if (allocated(error)) return
            select case (bc%type)
            case ('pressure'); fields = 'value'
            case ('traction', 'displacement'); fields = 'vector'
            case default; fields = ''
            end select
            call check_fields(g, bc_fields, fields, '', "type = '"//bc%type//"'", error)
            if (allocated(error)) return
            if (fields == 'value') then
               call nml_get(g, 'value', bc%value, found, error)
               if (allocated(error)) return
            end if
            if (fields == 'vector') call get_vector(g, 'vector', scene%dim, .true., bc%vector, error)
            if (allocated(error)) return
            if (index(bc%type, 'exact_') == 1 .and. .not. scene%exact%present) then
               call nml_field_error(g, 'type', 'needs an &exact group (the exact solution it prescribes)', error)
               return
            end if
            if (index(bc%type, 'exact_') == 1 .and. pressure_only(scene%exact)) then
               call nml_field_error(g, 'type', "needs a displacement and stress field; &exact kind = '"// &
                  & scene%exact%kind//"' gives the contact pressure only", error)
               return
            end if
            call read_stage(g, bc, error)
            if (allocated(error)) return
            call check_same_surface(g, scene%bcs(1:n), line_of, error)
            if (allocated(error)) return
            call nml_check_consumed(g, error)
            if (allocated(error)) return
         end associate
      end do
   end subroutine read_bcs

   !> A shape's name that is also a group of another shape's file could mean
   !> either surface: refused. (A group named like its own shape is that
   !> shape's whole surface when `on` names it.)
   subroutine check_unambiguous(g, key, scene, name, k, error)
      type(nml_group_type), intent(in) :: g
      character(len=*), intent(in) :: key
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: name
      integer, intent(in) :: k
      type(error_type), allocatable, intent(out) :: error
      integer :: j
      if (k == 0) return
      do j = 1, size(scene%shapes)
         if (j == k .or. .not. allocated(scene%shapes(j)%facets%group_name)) cycle
         if (.not. any(scene%shapes(j)%facets%group_name == name)) cycle
         call nml_field_error(g, key, "names shape '"//name//"' and a group of the file of shape '"// &
            & scene%shapes(j)%name//"': rename one", error)
         return
      end do
   end subroutine check_unambiguous

   !> The last of `bcs` against the earlier ones on its surface (their groups on
   !> lines `line_of`): a surface takes several &bc only as loads of one type
   !> (pressure, traction or displacement), each in its own stage; their loads
   !> add up (doc/scene.md `&bc stage`).
   subroutine check_same_surface(g, bcs, line_of, error)
      type(nml_group_type), intent(in) :: g
      type(bc_spec_type), intent(in) :: bcs(:)
      integer, intent(in) :: line_of(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: j, n

      n = size(bcs)
      do j = 1, n - 1
         if (.not. surfaces_overlap(bcs(j)%shape_index, bcs(j)%group, bcs(n)%shape_index, bcs(n)%group)) cycle
         if (bcs(j)%type /= bcs(n)%type .or. .not. any(bcs(n)%type == [character(len=12) :: 'pressure', &
            & 'traction', 'displacement'])) then
            call nml_field_error(g, 'on', "this surface already has a &bc of type = '"//bcs(j)%type// &
               & "' (on line "//itoa(line_of(j))//'): several &bc on one surface must all be loads of one '// &
               & 'type (pressure, traction or displacement), one per stage', error)
         else if (bcs(j)%stage == bcs(n)%stage) then
            call nml_field_error(g, 'stage', 'this surface already has a &bc in stage '//itoa(bcs(n)%stage)// &
               & ' (on line '//itoa(line_of(j))//'): one &bc per surface and stage', error)
         end if
         if (allocated(error)) return
      end do
   end subroutine check_same_surface

   !> `stage` (integer >= 1, default 1) of a condition that carries a load.
   subroutine read_stage(g, bc, error)
      type(nml_group_type), intent(inout) :: g
      type(bc_spec_type), intent(inout) :: bc
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      call nml_get(g, 'stage', bc%stage, found, error)
      if (allocated(error) .or. .not. found) return
      if (bc%type == 'free' .or. bc%type == 'symmetry') then
         call nml_field_error(g, 'stage', "does not apply to type = '"//bc%type// &
            & "' (it holds in every stage; stages order loads)", error)
      else if (bc%stage < 1) then
         call nml_field_error(g, 'stage', 'must be >= 1 (stage 1 is applied first)', error)
      end if
   end subroutine read_stage

   ! ---------------------------------------------------------------- &exact

   !> The index of the one group `name` (0 when there is none); a second one
   !> is an error, `rule` saying why ('at most one exact solution').
   subroutine optional_group(groups, name, rule, ig, error)
      type(nml_group_type), intent(in) :: groups(:)
      character(len=*), intent(in) :: name, rule
      integer, intent(out) :: ig
      type(error_type), allocatable, intent(out) :: error
      integer :: i

      ig = 0
      do i = 1, size(groups)
         if (groups(i)%name /= name) cycle
         if (ig > 0) then
            call nml_group_error(groups(i), 'a second &'//name//' group (the first is on line '// &
               & itoa(groups(ig)%line)//'): '//rule, error)
            return
         end if
         ig = i
      end do
   end subroutine optional_group

   subroutine read_exact(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig
      logical :: found

      call optional_group(groups, 'exact', 'at most one exact solution', ig, error)
      if (allocated(error) .or. ig == 0) return
      associate (g => groups(ig), exact => scene%exact)
         call check_keys(g, exact_keys, error)
         if (allocated(error)) return
         call get_choice(g, 'kind', exact_kinds, .true., exact%kind, error)
         if (allocated(error)) return
         if (kind_dim(exact%kind) /= 0 .and. kind_dim(exact%kind) /= scene%dim) then
            call nml_field_error(g, 'kind', 'is a '//itoa(kind_dim(exact%kind))//'D solution; analysis = '''// &
               & scene%analysis//''' is '//itoa(scene%dim)//'D', error)
            return
         end if
         select case (exact%kind)
         case ('kirsch')
            call read_kirsch(g, scene, exact, error)
         case ('uniform')
            call check_fields(g, exact_fields, 'stress', '', "kind = 'uniform'", error)
            if (allocated(error)) return
            call get_vector(g, 'stress', 3*(scene%dim - 1), .true., exact%stress, error)
         case ('compound_cylinder', 'compound_sphere')
            call read_compound(g, scene, exact, error)
         case ('layered_cylinder', 'layered_sphere')
            call read_layered(g, scene, exact, error)
         case ('hertz_cylinder', 'hertz_sphere')
            call read_hertz(g, scene, exact, error)
         case ('corner')
            call read_corner(g, exact, error)
         case default
            call check_fields(g, exact_fields, 'center r_in r_out p_in', 'p_out', "kind = '"//exact%kind//"'", error)
            if (allocated(error)) return
            call read_radii(g, scene, 'r_in r_out', exact, error)
            if (allocated(error)) return
            call nml_get(g, 'p_out', exact%p_out, found, error)
         end select
         if (allocated(error)) return
         call nml_check_consumed(g, error)
         if (allocated(error)) return
         exact%present = .true.
      end associate
   end subroutine read_exact

   ! ---------------------------------------------------------------- &adapt

   !> The optional `&adapt` group (after `&scene`): its fields, and what it
   !> asks of `&scene` (one level, the start; a recovery to estimate with).
   subroutine read_adapt(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig
      logical :: found

      call optional_group(groups, 'adapt', 'at most one', ig, error)
      if (allocated(error) .or. ig == 0) return
      associate (g => groups(ig), a => scene%adapt)
         call check_keys(g, adapt_keys, error)
         if (allocated(error)) return
         if (size(scene%levels) /= 1) then
            call nml_group_error(g, '&scene levels holds '//itoa(size(scene%levels))//' levels; with &adapt '// &
               & 'it holds one, the start level of the adaptive run', error)
            return
         end if
         if (scene%recovery == 'none') then
            call nml_group_error(g, "&scene recovery = 'none': &adapt needs a recovery (spr, sprc or both) "// &
               & 'for the estimate that drives it', error)
            return
         end if
         call get_positive(g, 'target', .true., a%target, error)
         if (allocated(error)) return
         if (a%target >= 1.0_wp) then
            call nml_field_error(g, 'target', 'must be < 1 (a relative error in the energy norm)', error)
            return
         end if
         call nml_get(g, 'max_steps', a%max_steps, found, error)
         if (allocated(error)) return
         if (a%max_steps < 1) then
            call nml_field_error(g, 'max_steps', 'must be >= 1 (the start mesh is step 0)', error)
            return
         end if
         call nml_get(g, 'max_dofs', a%max_dofs, found, error)
         if (allocated(error)) return
         if (found .and. a%max_dofs < 1) then
            call nml_field_error(g, 'max_dofs', 'must be >= 1 (omit it for what the memory budget allows)', error)
            return
         end if
         a%strategy = 'optimal'
         call get_choice(g, 'strategy', strategies, .false., a%strategy, error)
         if (allocated(error)) return
         call nml_get(g, 'fraction', a%fraction, found, error)
         if (allocated(error)) return
         if (found .and. a%strategy /= 'fraction') then
            call nml_field_error(g, 'fraction', "applies to strategy = 'fraction' only", error)
            return
         end if
         if (.not. (a%fraction > 0.0_wp .and. a%fraction <= 1.0_wp)) then
            call nml_field_error(g, 'fraction', 'must lie in (0, 1] (the share of the squared estimate)', error)
            return
         end if
         a%max_level = default_max_level(scene%dim)
         call nml_get(g, 'max_level', a%max_level, found, error)
         if (allocated(error)) return
         if (a%max_level < scene%levels(1) .or. a%max_level > grid_max_level) then
            call nml_field_error(g, 'max_level', 'must be from the start level ('//itoa(scene%levels(1))// &
               & ') to '//itoa(grid_max_level)//' (the grid''s deepest level)', error)
            return
         end if
         call nml_check_consumed(g, error)
         if (allocated(error)) return
         a%present = .true.
      end associate
   end subroutine read_adapt

   subroutine read_kirsch(g, scene, exact, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      type(exact_spec_type), intent(inout) :: exact
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      call check_fields(g, exact_fields, 'center radius s_inf', '', "kind = 'kirsch'", error)
      if (allocated(error)) return
      call get_vector(g, 'center', scene%dim, .true., exact%center, error)
      if (allocated(error)) return
      call get_positive(g, 'radius', .true., exact%radius, error)
      if (allocated(error)) return
      call nml_get(g, 's_inf', exact%s_inf, found, error)
   end subroutine read_kirsch

   !> `center`, the increasing positive radii named in `radii` (of r_in,
   !> r_contact, r_out) and `p_in`: the Lame and compound kinds.
   subroutine read_radii(g, scene, radii, exact, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: radii
      type(exact_spec_type), intent(inout) :: exact
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: word, previous
      real(wp) :: r, r_previous
      integer :: pos
      logical :: found

      call get_vector(g, 'center', scene%dim, .true., exact%center, error)
      if (allocated(error)) return
      previous = ''
      r_previous = 0.0_wp
      pos = 1
      do
         call next_word(radii, pos, word)
         if (len(word) == 0) exit
         call get_positive(g, word, .true., r, error)
         if (allocated(error)) return
         if (len(previous) > 0 .and. r <= r_previous) then
            call nml_field_error(g, word, 'must exceed '//previous//' = '//nml_item_text(g, previous), error)
            return
         end if
         select case (word)
         case ('r_in'); exact%r_in = r
         case ('r_contact'); exact%r_contact = r
         case default; exact%r_out = r
         end select
         previous = word
         r_previous = r
      end do
      call nml_get(g, 'p_in', exact%p_in, found, error)
   end subroutine read_radii

   !> Two concentric rings or shells: the radii and the inner and outer bodies
   !> (two different bodies; the &contact between them is checked with the pairs).
   subroutine read_compound(g, scene, exact, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      type(exact_spec_type), intent(inout) :: exact
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      call check_fields(g, exact_fields, 'center r_in r_contact r_out p_in inner outer', 'interference', &
         & "kind = '"//exact%kind//"'", error)
      if (allocated(error)) return
      call read_radii(g, scene, 'r_in r_contact r_out', exact, error)
      if (allocated(error)) return
      call get_body_ref(g, 'inner', scene, exact%inner, exact%inner_index, error)
      if (allocated(error)) return
      call get_body_ref(g, 'outer', scene, exact%outer, exact%outer_index, error)
      if (allocated(error)) return
      if (exact%outer_index == exact%inner_index) then
         call nml_field_error(g, 'outer', 'must differ from inner: the two rings are two bodies', error)
         return
      end if
      call nml_get(g, 'interference', exact%interference, found, error)
      if (allocated(error)) return
      if (exact%interference < 0.0_wp) then
         call nml_field_error(g, 'interference', &
            & 'must be >= 0 (the radial overlap of the rings; a clearance has no closed-form solution here)', error)
      else if (.not. exact%interference < exact%r_out - exact%r_contact) then
         call nml_field_error(g, 'interference', 'must be less than r_out - r_contact (the outer ring''s width)', error)
      end if
      exact%ring_shifts = [exact%interference]
   end subroutine read_compound

   !> n concentric rings: radii (n + 1, increasing), the ring bodies (n different
   !> bodies, blank- or comma-separated, inside out), the n - 1 interferences
   !> (default 0), p_in, p_out (default 0); the &contact between neighbouring
   !> rings is checked with the pairs.
   subroutine read_layered(g, scene, exact, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      type(exact_spec_type), intent(inout) :: exact
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: names, word
      integer :: n, i, pos, b
      logical :: found

      call check_fields(g, exact_fields, 'center radii bodies p_in', 'interference p_out', "kind = '"//exact%kind//"'", &
         & error)
      if (allocated(error)) return
      call get_vector(g, 'center', scene%dim, .true., exact%center, error)
      if (allocated(error)) return
      call nml_get_array(g, 'radii', exact%radii, 3, 64, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call nml_field_error(g, 'radii', 'required (n + 1 radii of n >= 2 rings, inside out)', error)
         return
      end if
      n = size(exact%radii) - 1
      if (.not. (exact%radii(1) > 0.0_wp)) then
         call nml_field_error(g, 'radii', 'the first radius must be > 0', error)
         return
      end if
      do i = 2, n + 1
         if (.not. (exact%radii(i) > exact%radii(i - 1))) then
            call nml_field_error(g, 'radii', 'must increase (radius '//itoa(i)//' does not exceed radius '// &
               & itoa(i - 1)//')', error)
            return
         end if
      end do
      names = ''
      call nml_get(g, 'bodies', names, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call nml_field_error(g, 'bodies', 'required (the '//itoa(n)//' ring bodies, inside out)', error)
         return
      end if
      names = translate_commas(names)
      allocate (exact%ring_index(0))
      exact%ring_names = ''
      pos = 1
      do
         call next_word(names, pos, word)
         if (len(word) == 0) exit
         b = body_index(scene, word)
         if (b == 0) then
            call nml_field_error(g, 'bodies', "'"//word//"' is not a body; bodies: "//body_names(scene), error)
            return
         end if
         if (any(exact%ring_index == b)) then
            call nml_field_error(g, 'bodies', "names body '"//word//"' twice: each ring is its own body", error)
            return
         end if
         exact%ring_index = [exact%ring_index, b]
         exact%ring_names = join(exact%ring_names, word)
      end do
      if (size(exact%ring_index) /= n) then
         call nml_field_error(g, 'bodies', 'names '//itoa(size(exact%ring_index))//' bodies; radii give '// &
            & itoa(n)//' rings', error)
         return
      end if
      allocate (exact%interferences(n - 1), source=0.0_wp)
      call nml_get_array(g, 'interference', exact%interferences, n - 1, n - 1, found, error)
      if (allocated(error)) return
      if (.not. found) exact%interferences = [(0.0_wp, i=1, n - 1)]
      if (any(exact%interferences < 0.0_wp)) then
         call nml_field_error(g, 'interference', 'must be >= 0 (the radial overlaps of neighbouring rings)', error)
         return
      end if
      if (.not. all(exact%interferences < exact%radii(3:) - exact%radii(2:n))) then
         call nml_field_error(g, 'interference', 'each must be less than the width of the ring outside it', error)
         return
      end if
      exact%ring_shifts = exact%interferences
      call nml_get(g, 'p_in', exact%p_in, found, error)
      if (allocated(error)) return
      call nml_get(g, 'p_out', exact%p_out, found, error)
   end subroutine read_layered

   !> `text` with its commas made blanks (a list of names either way).
   pure function translate_commas(text) result(out)
      character(len=*), intent(in) :: text
      character(len=len(text)) :: out
      integer :: i
      out = text
      do i = 1, len(out)
         if (out(i:i) == ',') out(i:i) = ' '
      end do
   end function translate_commas

   subroutine read_hertz(g, scene, exact, error)
      type(nml_group_type), intent(inout) :: g
      type(scene_type), intent(in) :: scene
      type(exact_spec_type), intent(inout) :: exact
      type(error_type), allocatable, intent(out) :: error
      call check_fields(g, exact_fields, 'point normal radius load', '', "kind = '"//exact%kind//"'", error)
      if (allocated(error)) return
      call get_vector(g, 'point', scene%dim, .true., exact%point, error)
      if (allocated(error)) return
      call get_direction(g, 'normal', scene%dim, exact%normal, error)
      if (allocated(error)) return
      call get_positive(g, 'radius', .true., exact%radius, error)
      if (allocated(error)) return
      call get_positive(g, 'load', .true., exact%load, error)
   end subroutine read_hertz

   !> The apex, the bisector of the material wedge (normalised), the opening
   !> in degrees and the two amplitudes (absent = 0, not both 0).
   subroutine read_corner(g, exact, error)
      type(nml_group_type), intent(inout) :: g
      type(exact_spec_type), intent(inout) :: exact
      type(error_type), allocatable, intent(out) :: error
      logical :: found1, found2
      call check_fields(g, exact_fields, 'point direction angle', 'mode1 mode2', "kind = 'corner'", error)
      if (allocated(error)) return
      call get_vector(g, 'point', 2, .true., exact%point, error)
      if (allocated(error)) return
      call get_direction(g, 'direction', 2, exact%direction, error)
      if (allocated(error)) return
      call nml_get(g, 'angle', exact%angle, found1, error)
      if (allocated(error)) return
      if (.not. (exact%angle > 180.0_wp .and. exact%angle <= 360.0_wp)) then
         call nml_field_error(g, 'angle', 'must satisfy 180 < angle <= 360 (the opening of the material '// &
            & 'wedge in degrees: 270 for an L-shape, 360 for a crack)', error)
         return
      end if
      call nml_get(g, 'mode1', exact%mode1, found1, error)
      if (allocated(error)) return
      call nml_get(g, 'mode2', exact%mode2, found2, error)
      if (allocated(error)) return
      if (exact%mode1 == 0.0_wp .and. exact%mode2 == 0.0_wp) then
         call nml_field_error(g, merge('mode1', 'mode2', found1 .or. .not. found2), &
            & 'mode1 and mode2 are both 0 (absent is 0): the corner field would vanish; give at least one '// &
            & 'nonzero amplitude', error)
      end if
   end subroutine read_corner

   ! -------------------------------------------------------------- &contact

   subroutine read_contacts(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(inout) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig, n
      logical :: found

      allocate (scene%contacts(count_groups(groups, 'contact')))
      n = 0
      do ig = 1, size(groups)
         if (groups(ig)%name /= 'contact') cycle
         n = n + 1
         associate (g => groups(ig), c => scene%contacts(n))
            call check_keys(g, contact_keys, error)
            if (allocated(error)) return
            call get_body_ref(g, 'slave', scene, c%slave, c%slave_index, error)
            if (allocated(error)) return
            call get_body_ref(g, 'master', scene, c%master, c%master_index, error)
            if (allocated(error)) return
            if (c%master_index == c%slave_index) then
               call nml_field_error(g, 'master', 'must differ from slave: contact is between two bodies', error)
               return
            end if
            call get_surface_ref(g, 'slave_surface', scene, c%slave_index, c%slave_surface, &
               & c%slave_surface_index, c%slave_group, error)
            if (allocated(error)) return
            call get_surface_ref(g, 'master_surface', scene, c%master_index, c%master_surface, &
               & c%master_surface_index, c%master_group, error)
            if (allocated(error)) return
            c%friction = 'frictionless'
            call get_choice(g, 'friction', frictions, .false., c%friction, error)
            if (allocated(error)) return
            if (c%friction == 'coulomb') then
               call nml_get(g, 'mu', c%mu, found, error)
               if (allocated(error)) return
               if (.not. found) then
                  call nml_field_error(g, 'mu', "required for friction = 'coulomb' (the friction coefficient)", error)
                  return
               end if
               if (c%mu < 0.0_wp) then
                  call nml_field_error(g, 'mu', 'must be >= 0', error)
                  return
               end if
            else if (nml_has(g, 'mu')) then
               call nml_field_error(g, 'mu', "applies only to friction = 'coulomb'", error)
               return
            end if
            call get_positive(g, 'kappa', .false., c%kappa, error)
            if (allocated(error)) return
            c%has_kappa = nml_has(g, 'kappa')
            call nml_get(g, 'steps', c%steps, found, error)
            if (allocated(error)) return
            if (c%steps < 1) then
               call nml_field_error(g, 'steps', 'must be >= 1 (load increments per stage)', error)
               return
            end if
            c%stabilization = default_stabilization
            call get_choice(g, 'stabilization', stabilizations, .false., c%stabilization, error)
            if (allocated(error)) return
            c%multiplier = default_multiplier
            call get_choice(g, 'multiplier', multipliers, .false., c%multiplier, error)
            if (allocated(error)) return
            if (c%multiplier == 'auto') c%multiplier = auto_multiplier(scene%dim, scene%order)
            call nml_get(g, 'edges', c%edges, found, error)
            if (allocated(error)) return
            call nml_check_consumed(g, error)
            if (.not. allocated(error)) call check_pair_unique(g, scene%contacts(1:n), error)
            if (allocated(error)) return
         end associate
      end do
      call check_exact_pair(groups, scene, error)
   end subroutine read_contacts

   !> Pair `pairs(n)` against the pairs before it (doc/scene.md `&contact`):
   !> two bodies touch through one pair (either way round), a slave surface
   !> belongs to one pair (its points have one master), and a surface is not
   !> the slave of one pair and the master of another. A master surface may
   !> serve several pairs (a rail under two rollers).
   subroutine check_pair_unique(g, pairs, error)
      type(nml_group_type), intent(in) :: g
      type(contact_spec_type), intent(in) :: pairs(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: k, n

      n = size(pairs)
      associate (c => pairs(n))
         do k = 1, n - 1
            associate (o => pairs(k))
               if ((o%slave_index == c%slave_index .and. o%master_index == c%master_index) .or. &
                  & (o%slave_index == c%master_index .and. o%master_index == c%slave_index)) then
                  call nml_field_error(g, 'master', "bodies '"//c%slave//"' and '"//c%master//"' are already "// &
                     & 'a pair (&contact '//itoa(k)//'): two bodies touch through one pair', error)
               else if (surfaces_overlap(o%slave_surface_index, o%slave_group, c%slave_surface_index, &
                  & c%slave_group)) then
                  call nml_field_error(g, 'slave_surface', 'is already the slave surface of &contact '//itoa(k)// &
                     & ': a slave point has one master', error)
               else if (surfaces_overlap(o%master_surface_index, o%master_group, c%slave_surface_index, &
                  & c%slave_group)) then
                  call nml_field_error(g, 'slave_surface', 'is the master surface of &contact '//itoa(k)// &
                     & ': a surface is the slave or the master of its pairs, not both', error)
               else if (surfaces_overlap(o%slave_surface_index, o%slave_group, c%master_surface_index, &
                  & c%master_group)) then
                  call nml_field_error(g, 'master_surface', 'is the slave surface of &contact '//itoa(k)// &
                     & ': a surface is the slave or the master of its pairs, not both', error)
               end if
            end associate
            if (allocated(error)) return
         end do
      end associate
   end subroutine check_pair_unique

   !> Do surface (shape k1, group g1) and (k2, g2) share points? Two groups of
   !> one file are two surfaces; a group (g > 0) is part of its shape's whole
   !> surface (g = 0).
   pure logical function surfaces_overlap(k1, g1, k2, g2)
      integer, intent(in) :: k1, g1, k2, g2
      surfaces_overlap = k1 == k2 .and. (g1 == g2 .or. g1 == 0 .or. g2 == 0)
   end function surfaces_overlap

   !> A compound exact solution needs a &contact between its inner and outer
   !> bodies, a Hertz one a &contact at all: without it their fields do not hold.
   subroutine check_exact_pair(groups, scene, error)
      type(nml_group_type), intent(inout) :: groups(:)
      type(scene_type), intent(in) :: scene
      type(error_type), allocatable, intent(out) :: error
      integer :: ig, i
      logical :: paired

      if (.not. scene%exact%present) return
      associate (e => scene%exact)
         if (index(e%kind, 'compound_') == 1) then
            paired = .false.
            do i = 1, size(scene%contacts)
               associate (c => scene%contacts(i))
                  paired = paired .or. (c%slave_index == e%inner_index .and. c%master_index == e%outer_index) &
                     & .or. (c%slave_index == e%outer_index .and. c%master_index == e%inner_index)
               end associate
            end do
            if (paired) return
            ig = first_group(groups, 'exact')
            call nml_field_error(groups(ig), 'outer', "no &contact between bodies '"//e%inner//"' and '"// &
               & e%outer//"': kind = '"//e%kind//"' is the solution of their shrink fit", error)
         else if (index(e%kind, 'layered_') == 1) then
            do i = 1, size(e%ring_index) - 1
               if (any((scene%contacts%slave_index == e%ring_index(i) .and. &
                  & scene%contacts%master_index == e%ring_index(i + 1)) .or. &
                  & (scene%contacts%slave_index == e%ring_index(i + 1) .and. &
                  & scene%contacts%master_index == e%ring_index(i)))) cycle
               ig = first_group(groups, 'exact')
               call nml_field_error(groups(ig), 'bodies', "no &contact between neighbouring rings '"// &
                  & scene%bodies(e%ring_index(i))%name//"' and '"//scene%bodies(e%ring_index(i + 1))%name// &
                  & "': kind = '"//e%kind//"' is the solution of their fit", error)
               return
            end do
         else if (index(e%kind, 'hertz_') == 1 .and. size(scene%contacts) == 0) then
            ig = first_group(groups, 'exact')
            call nml_field_error(groups(ig), 'kind', 'needs a &contact (it is the pressure of a contact)', error)
         else if (index(e%kind, 'hertz_') == 1 .and. size(scene%contacts) > 1) then
            ig = first_group(groups, 'exact')
            call nml_field_error(groups(ig), 'kind', 'is the pressure of one contact at one point; the scene has '// &
               & itoa(size(scene%contacts))//' &contact pairs', error)
         end if
      end associate
   end subroutine check_exact_pair

   subroutine get_body_ref(g, key, scene, name, index, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable, intent(out) :: name
      integer, intent(out) :: index
      type(error_type), allocatable, intent(out) :: error
      index = 0
      call get_name(g, key, name, error)
      if (allocated(error)) return
      index = body_index(scene, name)
      if (index == 0) call nml_field_error(g, key, 'no &body has this name; bodies: '//body_names(scene), error)
   end subroutine get_body_ref

   !> A shape surface that must belong to body `ibody`.
   subroutine get_surface_ref(g, key, scene, ibody, name, index, group, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: ibody
      character(len=:), allocatable, intent(out) :: name
      integer, intent(out) :: index, group
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: why
      integer :: k
      index = 0
      group = 0
      call get_name(g, key, name, error)
      if (allocated(error)) return
      index = shape_index(scene, name)
      call check_unambiguous(g, key, scene, name, index, error)
      if (allocated(error)) return
      if (index == 0) then
         call group_surface(scene%shapes, name, index, group, error)
         if (allocated(error)) then
            why = error%message
            call nml_field_error(g, key, why//'; surfaces: '//shape_names(scene), error)
            return
         end if
      end if
      if (index == 0) then
         call nml_field_error(g, key, 'no &shape and no group of a faceted shape has this name; surfaces: '// &
            & shape_names(scene), error)
      else if (scene%shapes(index)%body_index /= ibody) then
         call nml_field_error(g, key, "is a surface of body '"//scene%shapes(index)%body//"', not of '"// &
            & scene%bodies(ibody)%name//"'", error)
      else
         do k = 1, size(scene%bcs)
            if (.not. surfaces_overlap(scene%bcs(k)%shape_index, scene%bcs(k)%group, index, group)) cycle
            call nml_field_error(g, key, "has a &bc (type = '"//scene%bcs(k)%type// &
               & "'): a contact surface takes its conditions from &contact alone", error)
            return
         end do
      end if
   end subroutine get_surface_ref

   ! -------------------------------------------------------------- helpers

   !> Fail on a key outside `keys` (blank separated), listing the valid keys.
   subroutine check_keys(g, keys, error)
      type(nml_group_type), intent(in) :: g
      character(len=*), intent(in) :: keys
      type(error_type), allocatable, intent(out) :: error
      integer :: k
      do k = 1, size(g%items)
         if (.not. has_word(keys, g%items(k)%key)) then
            call nml_field_error(g, g%items(k)%key, 'unknown key; valid keys: '//comma_list(keys), error)
            return
         end if
      end do
   end subroutine check_keys

   !> Of the kind-dependent `all` fields, `needed` must be given, `optional`
   !> may be, the rest must not be: they do not apply to `what`.
   subroutine check_fields(g, all, needed, optional, what, error)
      type(nml_group_type), intent(in) :: g
      character(len=*), intent(in) :: all, needed, optional, what
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: word, applies
      integer :: pos

      applies = 'none'
      if (len_trim(needed//optional) > 0) applies = comma_list(trim(needed//' '//optional))
      pos = 1
      do
         call next_word(all, pos, word)
         if (len(word) == 0) exit
         if (nml_has(g, word) .and. .not. (has_word(needed, word) .or. has_word(optional, word))) then
            call nml_field_error(g, word, 'does not apply to '//what//' (its fields: '//applies//')', error)
            return
         end if
         if (.not. nml_has(g, word) .and. has_word(needed, word)) then
            call nml_field_error(g, word, 'required for '//what, error)
            return
         end if
      end do
   end subroutine check_fields

   !> A string from a list of choices (case-insensitive, stored in lower case);
   !> `value` keeps its default when the key is absent and not required.
   subroutine get_choice(g, key, choices, required, value, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key, choices
      logical, intent(in) :: required
      character(len=:), allocatable, intent(inout) :: value
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      call nml_get(g, key, value, found, error)
      if (allocated(error)) return
      if (.not. found) then
         if (required) call nml_field_error(g, key, 'required; one of '//quoted_list(choices), error)
         return
      end if
      value = lower(value)
      if (.not. has_word(choices, value) .or. len(value) == 0) then
         call nml_field_error(g, key, 'must be one of '//quoted_list(choices), error)
      end if
   end subroutine get_choice

   !> A required non-empty name of letters, digits, '_', '-' and '.': names
   !> appear in `key=value` output lines and as HDF5 group names.
   subroutine get_name(g, key, value, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key
      character(len=:), allocatable, intent(out) :: value
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      value = ''
      call nml_get(g, key, value, found, error)
      if (allocated(error)) return
      if (.not. found) then
         call nml_field_error(g, key, 'required', error)
      else if (len_trim(value) == 0) then
         call nml_field_error(g, key, 'must not be empty', error)
      else if (verify(value, name_chars) /= 0) then
         call nml_field_error(g, key, 'may contain only letters, digits, ''_'', ''-'' and ''.''', error)
      else if (len(value) > max_name_length) then
         call nml_field_error(g, key, 'is '//itoa(len(value))//' characters long; names have at most '// &
            & itoa(max_name_length), error)
      end if
   end subroutine get_name

   !> A real > 0; `value` keeps its default when absent and not required.
   subroutine get_positive(g, key, required, value, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key
      logical, intent(in) :: required
      real(wp), intent(inout) :: value
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      call nml_get(g, key, value, found, error)
      if (allocated(error)) return
      if (.not. found) then
         if (required) call nml_field_error(g, key, 'required', error)
      else if (value <= 0.0_wp) then
         call nml_field_error(g, key, 'must be > 0', error)
      end if
   end subroutine get_positive

   !> A vector of exactly `dim` reals.
   subroutine get_vector(g, key, dim, required, value, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key
      integer, intent(in) :: dim
      logical, intent(in) :: required
      real(wp), allocatable, intent(inout) :: value(:)
      type(error_type), allocatable, intent(out) :: error
      logical :: found
      call nml_get_array(g, key, value, dim, dim, found, error)
      if (allocated(error)) return
      if (.not. found .and. required) call nml_field_error(g, key, 'required ('//itoa(dim)//' values)', error)
   end subroutine get_vector

   !> A required nonzero direction, stored normalised.
   subroutine get_direction(g, key, dim, value, error)
      type(nml_group_type), intent(inout) :: g
      character(len=*), intent(in) :: key
      integer, intent(in) :: dim
      real(wp), allocatable, intent(inout) :: value(:)
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: length
      call get_vector(g, key, dim, .true., value, error)
      if (allocated(error)) return
      length = norm2(value)
      if (.not. (length > 0.0_wp)) then
         call nml_field_error(g, key, 'must be a nonzero vector', error)
         return
      end if
      value = value/length
   end subroutine get_direction

   pure integer function count_groups(groups, name) result(n)
      type(nml_group_type), intent(in) :: groups(:)
      character(len=*), intent(in) :: name
      integer :: i
      n = 0
      do i = 1, size(groups)
         if (groups(i)%name == name) n = n + 1
      end do
   end function count_groups

   !> Whether the exact solution gives the contact pressure only (hertz_*).
   pure logical function pressure_only(exact)
      type(exact_spec_type), intent(in) :: exact
      pressure_only = .false.
      if (exact%present) pressure_only = index(exact%kind, 'hertz_') == 1
   end function pressure_only

   !> Index of the first group called `name` (0 if none).
   pure integer function first_group(groups, name) result(ig)
      type(nml_group_type), intent(in) :: groups(:)
      character(len=*), intent(in) :: name
      do ig = 1, size(groups)
         if (groups(ig)%name == name) return
      end do
      ig = 0
   end function first_group

   pure integer function body_index(scene, name) result(k)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: name
      do k = 1, size(scene%bodies)
         if (scene%bodies(k)%name == name) return
      end do
      k = 0
   end function body_index

   pure integer function shape_index(scene, name) result(k)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: name
      do k = 1, size(scene%shapes)
         if (.not. allocated(scene%shapes(k)%name)) cycle
         if (scene%shapes(k)%name == name) return
      end do
      k = 0
   end function shape_index

   function body_names(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      integer :: k
      text = ''
      do k = 1, size(scene%bodies)
         if (.not. allocated(scene%bodies(k)%name)) cycle
         if (k > 1) text = text//', '
         text = text//"'"//scene%bodies(k)%name//"'"
      end do
   end function body_names

   !> The surfaces `&bc on` may name: shapes, then the groups of faceted shapes.
   function shape_names(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      integer :: k, i
      text = ''
      do k = 1, size(scene%shapes)
         if (.not. allocated(scene%shapes(k)%name)) cycle
         if (len(text) > 0) text = text//', '
         text = text//"'"//scene%shapes(k)%name//"'"
         if (.not. allocated(scene%shapes(k)%facets%group_name)) cycle
         do i = 1, size(scene%shapes(k)%facets%group_name)
            text = text//", '"//trim(scene%shapes(k)%facets%group_name(i))//"'"
         end do
      end do
   end function shape_names

   ! -------------------------------------------------------------- summary

   !> The validated scene, defaults filled in, and what it switches on and
   !> off (doc/scene.md); lines separated by new_line('a'), for `sprc check`.
   function scene_summary(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      integer :: i, j

      text = "scene '"//scene%title//"' from "//scene%source//nl
      text = text//'  analysis        = '//scene%analysis//' ('//itoa(scene%dim)//'D)'//nl
      text = text//'  order           = '//itoa(scene%order)//nl
      text = text//'  levels          = '//int_list(scene%levels)//nl
      text = text//'  refine_boundary = '//itoa(scene%refine_boundary)//nl
      text = text//'  box_min         = '//real_list(scene%box_min)//nl
      text = text//'  box_size        = '//real_text(scene%box_size)//nl
      text = text//'  recovery        = '//scene%recovery//nl
      text = text//"  recovery_degree = '"//scene%recovery_degree//"' (SPR "//itoa(recovery_degree(scene, 1))// &
         & ', SPR-C '//itoa(recovery_degree(scene, 2))//')'//nl
      text = text//"  output          = '"//scene%output//"'"//nl
      text = text//'  dilatation      = '//scene%dilatation//nl
      text = text//'  nitsche_gamma   = '//real_text(scene%nitsche_gamma)//nl
      text = text//'  solver          = '//scene%solver//solver_line(scene)//nl
      do i = 1, size(scene%bodies)
         associate (b => scene%bodies(i))
            text = text//"body '"//b%name//"': young = "//real_text(b%young)//', poisson = '// &
               & real_text(b%poisson)//', body_force = '//real_list(b%body_force)
            if (b%has_box) text = text//', box_min = '//real_list(b%box_min)//', box_size = '// &
               & real_text(b%box_size)//' (its own level-0 cell)'
            text = text//nl
         end associate
         do j = 1, size(scene%shapes)
            if (scene%shapes(j)%body_index /= i) cycle
            text = text//'  '//shape_line(scene%shapes(j))//nl
            if (.not. facet_kind(scene%shapes(j)%kind)) cycle
            if (scene%bodies(i)%has_box) then
               text = text//facet_summary(scene%shapes(j), scene%bodies(i)%box_min, scene%bodies(i)%box_size)
            else
               text = text//facet_summary(scene%shapes(j), scene%box_min, scene%box_size)
            end if
         end do
      end do
      text = text//'boundary conditions:'//nl
      do i = 1, size(scene%bcs)
         text = text//'  '//bc_line(scene%bcs(i))//nl
      end do
      text = text//'  traction-free (no &bc): '//none_if_empty(free_surfaces(scene))//nl
      if (size(scene%contacts) > 0) text = text//'  contact surfaces: '//surfaces_of_type(scene, 'contact')//nl
      if (scene%exact%present) then
         text = text//'exact solution: '//exact_line(scene%exact)//nl
      else
         text = text//'exact solution: none'//nl
      end if
      do i = 1, size(scene%contacts)
         if (size(scene%contacts) == 1) then
            text = text//'contact: '//contact_line(scene%contacts(i))//nl
         else
            text = text//'contact '//itoa(i)//': '//contact_line(scene%contacts(i))//nl
         end if
      end do
      if (size(scene%contacts) > 0) text = text//component_lines(scene)
      text = text//switches(scene)
      text = text//adapt_text(scene)
      if (len(contact_unsupported(scene)) > 0) then
         text = text//'NOT RUNNABLE: '//contact_unsupported(scene)//'; the scene is valid but sprc run '// &
            & 'refuses it.'//nl
      end if
      ! Lines are separated, not terminated: the driver prints the text as one record.
      text = text(1:len(text) - 1)
   end function scene_summary

   !> What the study will do: the uniform levels, or the adaptive run of `&adapt`
   !> (its fields, defaults filled in, and when it stops).
   function adapt_text(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      character(len=:), allocatable :: eta

      if (.not. scene%adapt%present) then
         text = 'study: uniform, one analysis per level of &scene levels'//nl
         return
      end if
      associate (a => scene%adapt)
         eta = 'eta_spr'
         if (scene%recovery == 'sprc' .or. scene%recovery == 'both') eta = 'eta_sprc'
         text = 'study: adaptive (&adapt), step 0 the uniform level '//itoa(scene%levels(1))//', then each '// &
            & 'step a new grid per body from the element indicators of '//eta//nl
         text = text//'  target    = '//real_text(a%target)//' (stop when '//eta//' <= target: success)'//nl
         text = text//"  strategy  = '"//a%strategy//"'"
         if (a%strategy == 'fraction') then
            text = text//' (refine the fewest cells carrying '//real_text(a%fraction)// &
               & ' of the squared estimate, coarsen none)'//nl
         else
            text = text//' (cell sizes for the error equidistributed at the target: refines and coarsens)'//nl
         end if
         text = text//'  max_steps = '//itoa(a%max_steps)//' (analyses, the start mesh included)'//nl
         if (a%max_dofs > 0) then
            text = text//'  max_dofs  = '//itoa(a%max_dofs)//nl
         else
            text = text//'  max_dofs  = what the memory budget allows (checked before each step)'//nl
         end if
         text = text//'  max_level = '//itoa(a%max_level)//' (deepest cell)'//nl
         text = text//'  reaching max_steps, max_dofs, max_level or the memory budget first ends the run '// &
            & 'with exit 0 and a warning naming the limit and the best eta'//nl
      end associate
   end function adapt_text

   !> The list of doc/scene.md 'What a scene switches on', one `label: state` per line.
   function switches(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      logical :: spr, sprc
      character(len=:), allocatable :: surfaces

      spr = scene%recovery == 'spr' .or. scene%recovery == 'both'
      sprc = scene%recovery == 'sprc' .or. scene%recovery == 'both'
      text = 'what this scene switches on and off:'//nl
      text = text//'  recovery SPR: '//on_off(spr)//nl
      text = text//'  recovery SPR-C: '//on_off(sprc)//nl
      if (sprc) then
         text = text//'  SPR-C internal equilibrium: on'//nl
         if (scene%order == 1) then
            text = text//'  SPR-C compatibility: off (order 1: holds identically)'//nl
         else
            text = text//'  SPR-C compatibility: on (order '//itoa(scene%order)//')'//nl
         end if
         surfaces = traction_surfaces(scene)
         if (len(surfaces) > 0) then
            text = text//'  SPR-C traction equilibrium: on (surfaces '//surfaces//')'//nl
         else
            text = text//'  SPR-C traction equilibrium: off (no traction boundary)'//nl
         end if
         surfaces = surfaces_of_type(scene, 'symmetry')
         if (len(surfaces) > 0) then
            text = text//'  SPR-C symmetry: on (surfaces '//surfaces//')'//nl
         else
            text = text//'  SPR-C symmetry: off (no symmetry boundary)'//nl
         end if
         if (size(scene%contacts) > 0) then
            text = text//'  SPR-C contact: on (surfaces '//surfaces_of_type(scene, 'contact')//')'//nl
         else
            text = text//'  SPR-C contact: off (no &contact)'//nl
         end if
      else
         text = text//"  SPR-C constraints: off (recovery = '"//scene%recovery//"')"//nl
      end if
      text = text//contact_switches(scene)
      if (pressure_only(scene%exact)) then
         text = text//'  error columns (err_*, theta_*): off (exact solution '//scene%exact%kind// &
            & ' gives the contact pressure only: p_max_exact and err_p_* on)'//nl
      else if (scene%exact%present) then
         text = text//'  error columns (err_*, theta_*): on (exact solution '//scene%exact%kind//')'//nl
      else
         text = text//'  error columns (err_*, theta_*): off (no &exact)'//nl
      end if
      text = text//'  estimate columns (eta_*): '//on_off(spr .or. sprc)//nl
      text = text//dilatation_lines(scene)
      if (len(gamma_note(scene%order, scene%nitsche_gamma)) > 0) &
         & text = text//'  WARNING: '//gamma_note(scene%order, scene%nitsche_gamma)//nl
      if (len(scene%output) > 0) then
         text = text//'  output files: on ('//scene%output//'.csv, '//scene%output//'.svg, '//scene%output// &
            & '.h5, '//scene%output//'.xdmf)'//nl
      else
         text = text//"  output files: off (output = '')"//nl
      end if
   end function switches

   !> What `solver` means for this scene's dimension (for `sprc check`).
   function solver_line(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text, head
      integer :: d, b

      text = ''
      if (scene%solver /= 'auto') return
      d = merge(3, 2, scene%analysis == 'solid')
      head = ' ('//achar(48 + d)//'D Q'//achar(48 + scene%order)//': '
      if (d == 2) then
         ! the budget estimates a 2D level alike for both solvers: no memory fallback
         text = head//'CHOLMOD)'
      else if (auto_iterative_min_dofs(d, scene%order) == auto_never) then
         text = head//'CHOLMOD; CG + geometric multigrid where CHOLMOD would not fit in memory)'
      else if (size(scene%contacts) > 0) then
         text = head//'each &contact pair''s bodies are one coupled system, CG + geometric multigrid from '// &
            & itoa(auto_coupled_iterative_min_dofs(d, scene%order))//' unknowns over both bodies or where '// &
            & 'CHOLMOD would not fit in memory, CHOLMOD below'
         if (any([(.not. (any(scene%contacts%slave_index == b) .or. any(scene%contacts%master_index == b)), &
            & b = 1, size(scene%bodies))])) &
            & text = text//'; a body in no pair from '//itoa(auto_iterative_min_dofs(d, scene%order))//' unknowns'
         text = text//')'
      else
         text = head//'CG + geometric multigrid from '//itoa(auto_iterative_min_dofs(d, scene%order))// &
            & ' unknowns or where CHOLMOD would not fit in memory, CHOLMOD below)'
      end if
   end function solver_line

   !> Per body: whether the locking-free formulation (projected dilatation) is on, and why.
   function dilatation_lines(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      character(len=:), allocatable :: why
      logical :: on
      integer :: i
      text = ''
      do i = 1, size(scene%bodies)
         associate (b => scene%bodies(i))
            select case (scene%dilatation)
            case ('projected')
               on = .true.
               why = "dilatation = 'projected'"
            case ('full')
               on = .false.
               why = "dilatation = 'full'"
            case default
               on = scene%analysis /= 'plane_stress' .and. b%poisson >= projected_poisson
               if (scene%analysis == 'plane_stress') then
                  why = 'auto: plane stress does not lock'
               else if (on) then
                  why = 'auto: poisson = '//real_text(b%poisson)//' >= '//real_text(projected_poisson)
               else
                  why = 'auto: poisson = '//real_text(b%poisson)//' < '//real_text(projected_poisson)
               end if
            end select
            text = text//"  locking-free formulation (projected dilatation, B-bar), body '"//b%name//"': "// &
               & on_off(on)//' ('//why//')'//nl
         end associate
      end do
   end function dilatation_lines

   function on_off(flag) result(text)
      logical, intent(in) :: flag
      character(len=:), allocatable :: text
      text = 'off'
      if (flag) text = 'on'
   end function on_off

   function none_if_empty(list) result(text)
      character(len=*), intent(in) :: list
      character(len=:), allocatable :: text
      text = list
      if (len(list) == 0) text = 'none'
   end function none_if_empty

   !> Type of the &bc on surface (shape `k`, group `g`; g = 0 the shape's
   !> whole surface); without one, 'contact' for a contact surface, else
   !> 'free'. A group without a condition of its own takes its shape's, so the
   !> listings name it only when it has one (`surface_name_list`).
   function surface_type(scene, k, g) result(type)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: k, g
      character(len=:), allocatable :: type
      integer :: i
      type = 'free'
      do i = 1, size(scene%contacts)
         associate (c => scene%contacts(i))
            if ((c%slave_surface_index == k .and. c%slave_group == g) .or. &
               & (c%master_surface_index == k .and. c%master_group == g)) type = 'contact'
         end associate
      end do
      do i = 1, size(scene%bcs)
         if (scene%bcs(i)%shape_index == k .and. scene%bcs(i)%group == g) type = scene%bcs(i)%type
      end do
   end function surface_type

   !> The named surfaces (a shape's whole surface, then its groups that have a
   !> condition of their own) whose type is one of `types` (blank separated),
   !> quoted and joined.
   function surface_name_list(scene, types) result(text)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: types
      character(len=:), allocatable :: text, type
      integer :: k, g, ng
      text = ''
      do k = 1, size(scene%shapes)
         ng = 0
         if (allocated(scene%shapes(k)%facets%group_name)) ng = size(scene%shapes(k)%facets%group_name)
         do g = 0, ng
            type = surface_type(scene, k, g)
            if (g > 0 .and. type == 'free' .and. .not. any(scene%bcs%shape_index == k .and. scene%bcs%group == g)) &
               & cycle
            if (.not. has_word(types, type)) cycle
            if (g == 0) then
               text = join(text, "'"//scene%shapes(k)%name//"'")
            else
               text = join(text, "'"//trim(scene%shapes(k)%facets%group_name(g))//"'")
            end if
         end do
      end do
   end function surface_name_list

   !> Surfaces without a &bc and not in a contact.
   function free_surfaces(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      integer :: k
      text = ''
      do k = 1, size(scene%shapes)
         if (any(scene%bcs%shape_index == k .and. scene%bcs%group == 0) .or. surface_type(scene, k, 0) == 'contact') &
            & cycle
         text = join(text, "'"//scene%shapes(k)%name//"'")
      end do
   end function free_surfaces

   !> Surfaces where the traction is known: free (explicit or implicit),
   !> pressure, traction, exact_traction.
   function traction_surfaces(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      text = surface_name_list(scene, 'free pressure traction exact_traction')
   end function traction_surfaces

   function surfaces_of_type(scene, type) result(text)
      type(scene_type), intent(in) :: scene
      character(len=*), intent(in) :: type
      character(len=:), allocatable :: text
      text = surface_name_list(scene, type)
   end function surfaces_of_type

   function shape_line(shape) result(text)
      type(shape_spec_type), intent(in) :: shape
      character(len=:), allocatable :: text
      text = "shape '"//shape%name//"': "//shape%op//' '//shape%kind
      if (allocated(shape%center)) text = text//', center = '//real_list(shape%center)
      if (allocated(shape%point)) text = text//', point = '//real_list(shape%point)
      if (allocated(shape%semi_axes)) text = text//', semi_axes = '//real_list(shape%semi_axes)
      if (allocated(shape%lower)) text = text//', lower = '//real_list(shape%lower)
      if (allocated(shape%upper)) text = text//', upper = '//real_list(shape%upper)
      if (allocated(shape%normal)) text = text//', normal = '//real_list(shape%normal)
      if (allocated(shape%axis)) text = text//', axis = '//real_list(shape%axis)
      if (allocated(shape%file)) text = text//", file = '"//shape%file//"'"
      if (allocated(shape%points)) text = text//', points = '//real_list(shape%points)
      if (allocated(shape%translate)) text = text//', scale = '//real_text(shape%scale)//', translate = '// &
         & real_list(shape%translate)
      select case (shape%kind)
      case ('disk', 'sphere', 'cylinder'); text = text//', radius = '//real_text(shape%radius)
      end select
   end function shape_line

   function bc_line(bc) result(text)
      type(bc_spec_type), intent(in) :: bc
      character(len=:), allocatable :: text
      text = "on '"//bc%on//"': "//bc%type
      if (bc%type == 'pressure') text = text//', value = '//real_text(bc%value)
      if (allocated(bc%vector)) text = text//', vector = '//real_list(bc%vector)
      if (bc%stage > 1) text = text//', stage = '//itoa(bc%stage)
   end function bc_line

   function exact_line(exact) result(text)
      type(exact_spec_type), intent(in) :: exact
      character(len=:), allocatable :: text
      text = exact%kind
      select case (exact%kind)
      case ('kirsch')
         text = text//', center = '//real_list(exact%center)//', radius = '//real_text(exact%radius)// &
            & ', s_inf = '//real_text(exact%s_inf)
      case ('uniform')
         text = text//', stress = '//real_list(exact%stress)
      case ('compound_cylinder', 'compound_sphere')
         text = text//', center = '//real_list(exact%center)//', r_in = '//real_text(exact%r_in)// &
            & ', r_contact = '//real_text(exact%r_contact)//', r_out = '//real_text(exact%r_out)// &
            & ', p_in = '//real_text(exact%p_in)//", inner = '"//exact%inner//"', outer = '"//exact%outer// &
            & "', interference = "//real_text(exact%interference)
      case ('layered_cylinder', 'layered_sphere')
         text = text//', center = '//real_list(exact%center)//', radii = '//real_list(exact%radii)// &
            & ", bodies = '"//exact%ring_names//"', interference = "//real_list(exact%interferences)// &
            & ', p_in = '//real_text(exact%p_in)//', p_out = '//real_text(exact%p_out)
      case ('corner')
         text = text//', point = '//real_list(exact%point)//', direction = '//real_list(exact%direction)// &
            & ', angle = '//real_text(exact%angle)//', mode1 = '//real_text(exact%mode1)//', mode2 = '// &
            & real_text(exact%mode2)//corner_note(exact%angle)
      case ('hertz_cylinder', 'hertz_sphere')
         text = text//', point = '//real_list(exact%point)//', normal = '//real_list(exact%normal)// &
            & ', radius = '//real_text(exact%radius)//', load = '//real_text(exact%load)// &
            & ' (contact pressure only: the energy-norm columns stay empty)'
      case default
         text = text//', center = '//real_list(exact%center)//', r_in = '//real_text(exact%r_in)// &
            & ', r_out = '//real_text(exact%r_out)//', p_in = '//real_text(exact%p_in)//', p_out = '// &
            & real_text(exact%p_out)
      end select
   end function exact_line

   !> The corner's eigenvalues and the uniform-refinement rate they imply.
   function corner_note(angle) result(text)
      real(wp), intent(in) :: angle
      character(len=:), allocatable :: text
      real(wp) :: lambda(2)
      call corner_eigenvalues(angle, lambda)
      text = ' (lambda1 = '//real_text(lambda(1))//', lambda2 = '//real_text(lambda(2))// &
         & ': stress ~ r^(lambda - 1); under uniform refinement the energy error falls like '// &
         & 'dofs^(-min(order, lambda)/2), lambda of the modes present)'
   end function corner_note

   function contact_line(c) result(text)
      type(contact_spec_type), intent(in) :: c
      character(len=:), allocatable :: text
      text = "slave '"//c%slave//"' surface '"//c%slave_surface//"', master '"//c%master//"' surface '"// &
         & c%master_surface//"', friction = "//c%friction
      if (c%friction == 'coulomb') text = text//', mu = '//real_text(c%mu)
      text = text//', kappa = '//real_text(c%kappa)
      if (.not. c%has_kappa) text = text//' (default)'
      text = text//', steps = '//itoa(c%steps)//', stabilization = '//c%stabilization//', multiplier = '//c%multiplier
   end function contact_line

   !> One line per component of the contact graph (the bodies solved together,
   !> their pairs), then the bodies without contact (each its own problem).
   function component_lines(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      character(len=:), allocatable :: names, pairs
      integer, allocatable :: comp(:)
      integer :: c, n, b, k

      call contact_components(scene, comp, n)
      text = ''
      do c = 1, n
         names = ''
         do b = 1, size(scene%bodies)
            if (comp(b) == c) names = join(names, "'"//scene%bodies(b)%name//"'")
         end do
         pairs = ''
         do k = 1, size(scene%contacts)
            if (comp(scene%contacts(k)%slave_index) == c) pairs = join(pairs, itoa(k))
         end do
         text = text//'contact component '//itoa(c)//': bodies '//names//' (pairs '//pairs// &
            & '): one coupled system, one active set'//nl
      end do
      names = ''
      do b = 1, size(scene%bodies)
         if (comp(b) == 0) names = join(names, "'"//scene%bodies(b)%name//"'")
      end do
      if (len(names) > 0) text = text//'bodies without contact (each its own problem): '//names//nl
   end function component_lines

   !> The contact part of 'what a scene switches on' (doc/scene.md).
   function contact_switches(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      character(len=*), parameter :: nl = new_line('a')
      integer :: stages

      if (size(scene%contacts) == 0) then
         text = '  contact: off (no &contact)'//nl
         return
      end if
      stages = 1
      if (size(scene%bcs) > 0) stages = max(1, maxval(scene%bcs%stage))
      associate (c => scene%contacts(1))
         if (size(scene%contacts) > 1) then
            text = '  contact: on ('//itoa(size(scene%contacts))//' pairs, first: slave '''//c%slave// &
               & ''' on master '''//c%master//''', friction '//c%friction
         else
            text = "  contact: on (slave '"//c%slave//"' on master '"//c%master//"', friction "//c%friction
         end if
         if (len(contact_unsupported(scene)) > 0) then
            text = text//'; NOT IMPLEMENTED in this version: sprc run refuses the scene)'//nl
         else
            text = text//'; coupled solve of '// &
               & trim(merge('both bodies          ', 'the bodies in contact', size(scene%contacts) == 1))// &
               & ', active-set iteration)'//nl
         end if
         text = text//'  contact stabilization stress: '//c%stabilization//nl
         if (c%friction == 'coulomb') then
            text = text//'  load history: on ('//itoa(stages)//' stage(s), '//itoa(c%steps)// &
               & ' increment(s) each: Coulomb friction depends on the load path)'//nl
         else
            text = text//'  load history: off (friction '//c%friction//': all stages are one linear load)'//nl
         end if
      end associate
      text = text//'  contact columns (contact_iterations ... jump_sprc): on'//nl
      if (len(scene%output) > 0) then
         text = text//'  contact files: on ('//scene%output//'_contact.csv, '//scene%output//'_contact.svg)'//nl
      else
         text = text//"  contact files: off (output = '')"//nl
      end if
   end function contact_switches

   ! ---------------------------------------------------------- text utils

   function join(list, item) result(text)
      character(len=*), intent(in) :: list, item
      character(len=:), allocatable :: text
      if (len(list) == 0) then
         text = item
      else
         text = list//', '//item
      end if
   end function join

   !> Next blank-separated word of `list` from `pos` ('' at the end).
   pure subroutine next_word(list, pos, word)
      character(len=*), intent(in) :: list
      integer, intent(inout) :: pos
      character(len=:), allocatable, intent(out) :: word
      integer :: j
      do while (pos <= len(list))
         if (list(pos:pos) /= ' ') exit
         pos = pos + 1
      end do
      j = pos
      do while (j <= len(list))
         if (list(j:j) == ' ') exit
         j = j + 1
      end do
      word = list(pos:j - 1)
      pos = j
   end subroutine next_word

   pure logical function has_word(list, word)
      character(len=*), intent(in) :: list, word
      has_word = index(' '//list//' ', ' '//word//' ') > 0 .and. len_trim(word) == len(word) .and. len(word) > 0
   end function has_word

   function comma_list(list) result(text)
      character(len=*), intent(in) :: list
      character(len=:), allocatable :: text, word
      integer :: pos
      text = ''
      pos = 1
      do
         call next_word(list, pos, word)
         if (len(word) == 0) exit
         text = join(text, word)
      end do
   end function comma_list

   function quoted_list(list) result(text)
      character(len=*), intent(in) :: list
      character(len=:), allocatable :: text, word
      integer :: pos
      text = ''
      pos = 1
      do
         call next_word(list, pos, word)
         if (len(word) == 0) exit
         text = join(text, "'"//word//"'")
      end do
   end function quoted_list

   function int_list(values) result(text)
      integer, intent(in) :: values(:)
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, size(values)
         text = join(text, itoa(values(i)))
      end do
   end function int_list

   function real_list(values) result(text)
      real(wp), intent(in) :: values(:)
      character(len=:), allocatable :: text
      integer :: i
      text = ''
      do i = 1, size(values)
         text = join(text, real_text(values(i)))
      end do
   end function real_list


end module sprc_io_scene
