!> From a validated scene to the objects the analysis works with: geometry
!> bodies (one per `&body`, shapes in file order), each body's FE conditions
!> on its own shape indices, the exact solution as it holds in each body
!> (with that body's material), and the exact contact pressure of a
!> `&contact` pair.
!>
!> The scene reader has already validated every field; errors here are the
!> constructors' own checks, prefixed with the scene group they came from.
module sprc_study_model
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input, stat_unsupported
   use sprc_core_material, only: plane_stress, plane_strain, solid
   use sprc_geometry_shape, only: shape_type, new_disk, new_sphere, new_ellipse, &
      & new_ellipsoid, new_box, new_halfspace, new_cylinder, new_facet_shape
   use sprc_geometry_body, only: body_type, new_body, csg_op_from_name, check_body_in_box
   use sprc_exact_solution, only: exact_solution_type
   use sprc_exact_lame, only: lame_cylinder_type, lame_sphere_type, new_lame_cylinder, new_lame_sphere
   use sprc_exact_kirsch, only: kirsch_type, new_kirsch
   use sprc_exact_uniform, only: uniform_type, new_uniform
   use sprc_exact_layered, only: layered_type, new_layered
   use sprc_exact_pressure, only: exact_pressure_type, field_pressure_type, new_field_pressure
   use sprc_exact_hertz, only: hertz_type, new_hertz_cylinder, new_hertz_sphere
   use sprc_exact_corner, only: corner_type, new_corner
   use sprc_core_text, only: itoa, real_text
   use sprc_study_spec, only: scene_type, shape_spec_type, bc_spec_type, kappa_note, exact_spec_type, contact_spec_type
   use sprc_fem_bc, only: fe_bc_type, new_fe_bc, bc_kind_from_name
   use sprc_fem_problem, only: gamma_note
   implicit none
   private

   public :: build_bodies, build_exact, body_conditions, analysis_kind, analysis_units, in_units, scene_warnings
   public :: build_exact_pressure, exact_has_field, scene_surface

   !> Units of an analysis: moduli divided by `modulus`, displacements by `strain`
   !> (lengths unchanged), stresses and loads by modulus*strain. Both are powers of two, so
   !> the scaling is exact; the stiffness, loads, displacements and energies of the scaled
   !> problem are O(1) whatever the scale of Young's modulus (E = 1e300 with pressure 1 gave
   !> energies that underflow; E = 1e308 a stiffness that overflows). Relative errors are
   !> unchanged.
   type, public :: analysis_units_type
      real(wp) :: modulus = 1.0_wp, strain = 1.0_wp
   end type analysis_units_type

contains

   !> The analysis constant of sprc_core_material for the scene's `analysis`.
   pure integer function analysis_kind(scene)
      type(scene_type), intent(in) :: scene
      select case (scene%analysis)
      case ('plane_stress'); analysis_kind = plane_stress
      case ('plane_strain'); analysis_kind = plane_strain
      case default; analysis_kind = solid
      end select
   end function analysis_kind

   !> The units of `scene`: `modulus` within a factor 2 of the first body's Young's modulus,
   !> `strain` within a factor 2 of the largest strain the data imply (1 if none): load / modulus (loads:
   !> pressures, tractions, body force times box_size, the exact solution's pressures and
   !> remote stress) or prescribed displacement / box_size. stat_invalid_input when that
   !> strain is not representable (loads 1e300 times the modulus).
   subroutine analysis_units(scene, units, error, body)
      type(scene_type), intent(in) :: scene
      type(analysis_units_type), intent(out) :: units
      type(error_type), allocatable, intent(out) :: error
      !> The units of this body alone (its modulus and the loads on it): bodies
      !> without contact are independent problems, each in its own units.
      integer, intent(in), optional :: body
      real(wp) :: load, disp
      integer :: i, k, b

      if (size(scene%bodies) == 0) return
      b = 1
      if (present(body)) b = body
      units%modulus = scale(1.0_wp, exponent(scene%bodies(b)%young) - 1)
      load = 0.0_wp
      disp = 0.0_wp
      do i = 1, size(scene%bodies)
         if (present(body) .and. i /= b) cycle
         if (allocated(scene%bodies(i)%body_force)) &
            & load = max(load, maxval([0.0_wp, abs(scene%bodies(i)%body_force)])*scene%box_size)
      end do
      do i = 1, size(scene%bcs)
         if (present(body)) then
            if (scene%shapes(scene%bcs(i)%shape_index)%body_index /= b) cycle
         end if
         load = max(load, abs(scene%bcs(i)%value))
         if (.not. allocated(scene%bcs(i)%vector)) cycle
         if (scene%bcs(i)%type == 'displacement') then
            disp = max(disp, maxval([0.0_wp, abs(scene%bcs(i)%vector)])/scene%box_size)
         else
            load = max(load, maxval([0.0_wp, abs(scene%bcs(i)%vector)]))
         end if
      end do
      if (scene%exact%present) then
         load = max(load, abs(scene%exact%p_in), abs(scene%exact%p_out), abs(scene%exact%s_inf))
         if (allocated(scene%exact%stress)) load = max(load, maxval([0.0_wp, abs(scene%exact%stress)]))
         disp = max(disp, abs(scene%exact%interference)/scene%box_size)
      end if
      k = -huge(1)
      if (load > 0.0_wp) k = exponent(load) - exponent(units%modulus)
      if (disp > 0.0_wp) k = max(k, exponent(disp))
      if (k == -huge(1)) return
      ! the strain unit itself must be a double (subnormal allowed: only the written
      ! displacements and stresses lose digits then, not the analysis)
      if (k >= maxexponent(1.0_wp) .or. k <= minexponent(1.0_wp) - digits(1.0_wp)) then
         call fatal_error(error, "the loads (or prescribed displacements) imply strains of about 1e"// &
            & itoa(nint(0.30103_wp*real(k, wp)))//" (load / young), beyond double precision: "// &
            & "check the units of young and of the loads", stat_invalid_input)
         return
      end if
      units%strain = scale(1.0_wp, k)
   end subroutine analysis_units

   !> The scene in `units` (analysis_units_type): moduli divided by units%modulus; body
   !> forces, pressures, tractions and the exact solution's pressures, remote stress,
   !> uniform stress and Hertz load by units%modulus*units%strain (in two steps, so no
   !> intermediate overflows; lengths stay, so a force per length or area scales as a
   !> stress); prescribed displacements and the exact solution's interference by
   !> units%strain. Poisson's ratios and lengths stay. Every body's modulus is scaled by
   !> the same units: a closed form spanning two bodies (compound_*) built from the
   !> scaled scene is the scene's solution in these units.
   function in_units(scene, units) result(scaled)
      type(scene_type), intent(in) :: scene
      type(analysis_units_type), intent(in) :: units
      type(scene_type) :: scaled
      integer :: i

      scaled = scene
      do i = 1, size(scaled%bodies)
         scaled%bodies(i)%young = scene%bodies(i)%young/units%modulus
         if (allocated(scene%bodies(i)%body_force)) scaled%bodies(i)%body_force = stress(scene%bodies(i)%body_force)
      end do
      do i = 1, size(scaled%bcs)
         scaled%bcs(i)%value = stress1(scene%bcs(i)%value)
         if (.not. allocated(scene%bcs(i)%vector)) cycle
         if (scene%bcs(i)%type == 'displacement') then
            scaled%bcs(i)%vector = scene%bcs(i)%vector/units%strain
         else
            scaled%bcs(i)%vector = stress(scene%bcs(i)%vector)
         end if
      end do
      scaled%exact%p_in = stress1(scene%exact%p_in)
      scaled%exact%p_out = stress1(scene%exact%p_out)
      scaled%exact%s_inf = stress1(scene%exact%s_inf)
      scaled%exact%load = stress1(scene%exact%load)
      scaled%exact%interference = scene%exact%interference/units%strain
      if (allocated(scene%exact%interferences)) scaled%exact%interferences = scene%exact%interferences/units%strain
      if (allocated(scene%exact%stress)) scaled%exact%stress = stress(scene%exact%stress)
   contains
      pure function stress(v) result(w)
         real(wp), intent(in) :: v(:)
         real(wp) :: w(size(v))
         w = (v/units%modulus)/units%strain
      end function stress
      pure real(wp) function stress1(v)
         real(wp), intent(in) :: v
         stress1 = (v/units%modulus)/units%strain
      end function stress1
   end function in_units

   !> Valid but physically odd input, as lines 'warning: ...' ('' if none): no load at all
   !> (u = 0: err_fe 1, eta 0, theta 0 mean nothing), and an &exact whose domain does not fit
   !> the first body (its distances from the solution's centre, sampled on a lattice of
   !> 64^2 / 32^3 points of the box, do not reach the solution's radii within two lattice
   !> steps, or for a corner: material outside its wedge, `corner_misfit`; the errors would
   !> compare with the solution of another problem); a contact
   !> kappa outside its safe range (`kappa_note`).
   function scene_warnings(scene, bodies) result(text)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: bodies(:)
      character(len=:), allocatable :: text
      real(wp) :: load, r(2), step
      integer :: i

      text = ''
      do i = 1, size(scene%shapes)
         if (.not. allocated(scene%shapes(i)%note)) cycle
         if (len(scene%shapes(i)%note) > 0) text = text//"warning: shape '"//scene%shapes(i)%name//"': "// &
            & scene%shapes(i)%note//new_line('a')
      end do
      load = 0.0_wp
      do i = 1, size(scene%bodies)
         if (allocated(scene%bodies(i)%body_force)) load = max(load, maxval([0.0_wp, abs(scene%bodies(i)%body_force)]))
      end do
      do i = 1, size(scene%bcs)
         select case (scene%bcs(i)%type)
         case ('pressure')
            load = max(load, abs(scene%bcs(i)%value))
         case ('traction', 'displacement')
            load = max(load, maxval([0.0_wp, abs(scene%bcs(i)%vector)]))
         case ('exact_traction', 'exact_displacement')
            load = max(load, abs(scene%exact%p_in), abs(scene%exact%p_out), abs(scene%exact%s_inf), &
               & abs(scene%exact%interference), abs(scene%exact%mode1), abs(scene%exact%mode2))
            if (allocated(scene%exact%stress)) load = max(load, maxval([0.0_wp, abs(scene%exact%stress)]))
         end select
      end do
      if (.not. (load > 0.0_wp) .and. size(scene%contacts) == 0) text = text//'warning: no load: every '// &
         & 'pressure, traction, body force and prescribed displacement is zero, so the displacement is zero '// &
         & 'and the errors and estimates mean nothing'//new_line('a')
      if (len(gamma_note(scene%order, scene%nitsche_gamma)) > 0) &
         & text = text//'warning: '//gamma_note(scene%order, scene%nitsche_gamma)//new_line('a')
      text = text//contact_warnings(scene)
      if (.not. scene%exact%present .or. size(bodies) == 0) return
      ! Only the one-body solutions have a domain to fit: uniform has no centre, the
      ! compound_* and hertz_* solutions span two bodies.
      select case (scene%exact%kind)
      case ('lame_cylinder', 'lame_sphere', 'kirsch')
      case ('corner')
         text = text//corner_misfit(scene, bodies(1))
         return
      case default
         return
      end select
      call distance_range(scene, bodies(1), scene%exact%center, r, step)
      if (.not. (r(1) <= r(2))) then
         text = text//"warning: &exact: the body '"//bodies(1)%name//"' has no material on the sampling lattice; "// &
            & 'the exact solution is not checked against it'//new_line('a')
         return
      end if
      select case (scene%exact%kind)
      case ('lame_cylinder', 'lame_sphere')
         if (abs(r(1) - scene%exact%r_in) <= 2*step .and. abs(r(2) - scene%exact%r_out) <= 2*step) return
         text = text//"warning: &exact '"//scene%exact%kind//"' does not fit body '"//bodies(1)%name// &
            & "': its material lies at distances "//real_text(rounded(r(1)))//' .. '//real_text(rounded(r(2)))// &
            & ' from the centre, the solution holds for r_in .. r_out = '//real_text(scene%exact%r_in)//' .. '// &
            & real_text(scene%exact%r_out)//'; check center, r_in and r_out'//new_line('a')
      case ('kirsch')
         if (abs(r(1) - scene%exact%radius) <= 2*step) return
         text = text//"warning: &exact 'kirsch' does not fit body '"//bodies(1)%name// &
            & "': its material comes no nearer than "//real_text(rounded(r(1)))//' to the centre, the hole radius is '// &
            & real_text(scene%exact%radius)//'; check center and radius'//new_line('a')
      end select
   end function scene_warnings

   !> The warnings of the contact pairs: a kappa outside `kappa_range`; a
   !> slave at least `stiff_slave` times as stiff as its master.
   function contact_warnings(scene) result(text)
      type(scene_type), intent(in) :: scene
      character(len=:), allocatable :: text
      !> The stability study (README): with the shaft as the slave, E_hub/E_shaft
      !> = 1e-1 already doubled err_p_fe; the softer body as the slave never cost.
      real(wp), parameter :: stiff_slave = 10.0_wp
      real(wp) :: e(2), decades
      integer :: k

      text = ''
      do k = 1, size(scene%contacts)
         associate (c => scene%contacts(k))
            if (len(kappa_note(c%kappa, c%stabilization)) > 0) text = text//"warning: &contact slave='"// &
               & c%slave//"' master='"//c%master//"': "//kappa_note(c%kappa, c%stabilization)//new_line('a')
            if (c%slave_index < 1 .or. c%master_index < 1) cycle
            e = [scene%bodies(c%slave_index)%young, scene%bodies(c%master_index)%young]
            if (.not. (e(1) > 0.0_wp .and. e(2) > 0.0_wp .and. e(1) < huge(1.0_wp) .and. e(2) < huge(1.0_wp))) cycle
            ! logarithms: the moduli may lie anywhere in the representable range
            decades = log10(e(1)) - log10(e(2))
            if (decades >= log10(stiff_slave)) text = text//"warning: &contact slave='"//c%slave//"' master='"// &
               & c%master//"': the slave is about 1e"//itoa(nint(decades))//' times as stiff as the master; the '// &
               & 'contact pressure is more accurate with the softer body as the slave (swap slave and master, '// &
               & 'and slave_surface and master_surface)'//new_line('a')
         end associate
      end do
   end function contact_warnings

   !> Smallest and largest distance from `center` of the body's points among the centres
   !> of a lattice of 64^2 (2D) or 32^3 (3D) cells of the box; r(1) > r(2) if none is in
   !> the body. `step` is the lattice diagonal.
   subroutine distance_range(scene, body, center, r, step)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      real(wp), intent(in) :: center(:)
      real(wp), intent(out) :: r(2), step
      real(wp), allocatable :: x(:, :)
      real(wp) :: dist
      integer :: i

      call material_samples(scene, body, x, step)
      r = [huge(1.0_wp), 0.0_wp]
      do i = 1, size(x, 2)
         dist = norm2(x(:, i) - center(1:size(x, 1)))
         r = [min(r(1), dist), max(r(2), dist)]
      end do
   end subroutine distance_range

   !> The points of a lattice of 64^2 / 32^3 cell centres of the first body's
   !> level-0 cell that lie in `body`, x(dim, m), and the lattice diagonal.
   subroutine material_samples(scene, body, x, step)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      real(wp), allocatable, intent(out) :: x(:, :)
      real(wp), intent(out) :: step
      real(wp) :: y(3), h, box_size
      real(wp), allocatable :: box_min(:)
      integer :: n, i, j, k, d, nk, m

      d = scene%dim
      n = merge(64, 32, d == 2)
      nk = merge(1, n, d == 2)
      ! The body is the first: its own level-0 cell when it has one.
      box_min = scene%box_min
      box_size = scene%box_size
      if (size(scene%bodies) > 0) then
         if (allocated(scene%bodies(1)%box_min)) then
            box_min = scene%bodies(1)%box_min
            box_size = scene%bodies(1)%box_size
         end if
      end if
      h = box_size/real(n, wp)
      step = h*sqrt(real(d, wp))
      allocate (x(d, n*n*nk))
      m = 0
      do k = 1, nk
         do j = 1, n
            do i = 1, n
               y = h*([real(i, wp), real(j, wp), real(k, wp)] - 0.5_wp)
               y(1:d) = box_min(1:d) + y(1:d)
               if (.not. (body%phi(y(1:d)) < 0.0_wp)) cycle
               m = m + 1
               x(:, m) = y(1:d)
            end do
         end do
      end do
      x = x(:, 1:m)
   end subroutine material_samples

   !> A warning ('' if none) when the first body does not fit the corner
   !> solution: material sampled on the lattice of `material_samples` outside
   !> the wedge (beyond rounding: 1e-9 of the lattice step), or, on a lattice
   !> of the same spacing within 8 spacings of the apex, points inside the
   !> wedge that are not material (the wedge wider than the body's corner, or
   !> an apex away from the body). A bisector pointing into the notch instead
   !> of the material is the mistake this catches first.
   function corner_misfit(scene, body) result(text)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      character(len=:), allocatable :: text
      real(wp), parameter :: pi = acos(-1.0_wp)
      real(wp), allocatable :: x(:, :)
      real(wp) :: step, beta, d(2), rho, t, gap, h
      integer :: i, j, outside, missing

      text = ''
      call material_samples(scene, body, x, step)
      if (size(x, 2) == 0) return
      beta = 0.5_wp*scene%exact%angle*pi/180.0_wp
      outside = 0
      do i = 1, size(x, 2)
         call wedge_polar(x(:, i), rho, t)
         if (t <= beta) cycle
         gap = rho
         if (t - beta < 0.5_wp*pi) gap = rho*sin(t - beta)
         if (gap > 1.0e-9_wp*step) outside = outside + 1
      end do
      h = step/sqrt(2.0_wp)
      missing = 0
      do j = -8, 7
         do i = -8, 7
            d = scene%exact%point + h*[i + 0.5_wp, j + 0.5_wp]
            call wedge_polar(d, rho, t)
            if (rho > 8.0_wp*h .or. t >= beta) cycle
            gap = rho
            if (beta - t < 0.5_wp*pi) gap = rho*sin(beta - t)
            if (gap > 1.0e-9_wp*step .and. .not. (body%phi(d) < 0.0_wp)) missing = missing + 1
         end do
      end do
      if (outside > 0) then
         text = "warning: &exact 'corner' does not fit body '"//body%name//"': "//itoa(outside)//' of its '// &
            & itoa(size(x, 2))//' sampled points lie outside the material wedge (angle '// &
            & real_text(scene%exact%angle)//' about direction '//real_text(scene%exact%direction(1))//', '// &
            & real_text(scene%exact%direction(2))//' from point '//real_text(scene%exact%point(1))//', '// &
            & real_text(scene%exact%point(2))//'); check point, angle and direction (the bisector of the '// &
            & 'material, not of the notch)'//new_line('a')
      else if (missing > 0) then
         text = "warning: &exact 'corner' does not fit body '"//body%name//"': "//itoa(missing)//' points '// &
            & 'of the wedge within 8 lattice steps ('//real_text(h)//') of the apex are not in the body (the '// &
            & "body's corner is narrower, or the apex is not on it); check point and angle"//new_line('a')
      end if

   contains

      !> Distance from the apex and |angle| from the bisector of a point.
      pure subroutine wedge_polar(y, rho, t)
         real(wp), intent(in) :: y(2)
         real(wp), intent(out) :: rho, t
         real(wp) :: dy(2)
         dy = y - scene%exact%point
         rho = norm2(dy)
         associate (e => scene%exact%direction)
            t = abs(atan2(-e(2)*dy(1) + e(1)*dy(2), e(1)*dy(1) + e(2)*dy(2)))
         end associate
      end subroutine wedge_polar

   end function corner_misfit

   !> v to six significant digits (sampled distances: more digits would be noise).
   pure real(wp) function rounded(v)
      real(wp), intent(in) :: v
      real(wp) :: unit
      rounded = v
      if (.not. (v > 0.0_wp)) return
      unit = 10.0_wp**(floor(log10(v)) - 5)
      rounded = anint(v/unit)*unit
   end function rounded

   !> One geometry body per `&body`, its shapes added in file order; a body with
   !> material outside the scene's box is an input error (the grid would clip it).
   subroutine build_bodies(scene, bodies, error)
      type(scene_type), intent(in) :: scene
      type(body_type), allocatable, intent(out) :: bodies(:)
      type(error_type), allocatable, intent(out) :: error
      type(shape_type) :: shape
      integer :: b, s

      allocate (bodies(size(scene%bodies)))
      do b = 1, size(scene%bodies)
         call new_body(bodies(b), scene%bodies(b)%name)
      end do
      do s = 1, size(scene%shapes)
         call build_shape(scene%shapes(s), shape, error)
         if (.not. allocated(error)) then
            b = scene%shapes(s)%body_index
            call bodies(b)%add_shape(csg_op_from_name(scene%shapes(s)%op), shape, error)
         end if
         if (allocated(error)) then
            error%message = '&shape '''//scene%shapes(s)%name//''': '//error%message
            return
         end if
      end do
      do b = 1, size(bodies)
         if (allocated(scene%bodies(b)%box_min)) then
            call check_body_in_box(bodies(b), scene%bodies(b)%box_min, scene%bodies(b)%box_size, error, &
               & own_box=scene%bodies(b)%has_box)
         else
            call check_body_in_box(bodies(b), scene%box_min, scene%box_size, error)
         end if
         if (allocated(error)) return
      end do
   end subroutine build_bodies

   subroutine build_shape(spec, shape, error)
      type(shape_spec_type), intent(in) :: spec
      type(shape_type), intent(out) :: shape
      type(error_type), allocatable, intent(out) :: error

      select case (spec%kind)
      case ('disk'); call new_disk(shape, spec%name, spec%center, spec%radius, error)
      case ('sphere'); call new_sphere(shape, spec%name, spec%center, spec%radius, error)
      case ('ellipse'); call new_ellipse(shape, spec%name, spec%center, spec%semi_axes, error)
      case ('ellipsoid'); call new_ellipsoid(shape, spec%name, spec%center, spec%semi_axes, error)
      case ('box'); call new_box(shape, spec%name, spec%lower, spec%upper, error)
      case ('halfspace'); call new_halfspace(shape, spec%name, spec%point, spec%normal, error)
      case ('cylinder'); call new_cylinder(shape, spec%name, spec%point, spec%axis, spec%radius, error)
      case ('stl', 'obj', 'polygon')
         call new_facet_shape(shape, spec%name, spec%facets, error)
      case default
         call fatal_error(error, 'unknown shape kind '''//spec%kind//'''', stat_invalid_input)
      end select
   end subroutine build_shape

   !> The &bc groups on the surfaces of body `b` as FE conditions on the
   !> body's own shape indices (its shapes in file order of their first &bc);
   !> surfaces without &bc are free. A surface with several &bc (one load type,
   !> one per stage; doc/scene.md `&bc stage`) gets one condition carrying the sum
   !> of their loads; with `stage`, of those in stages <= stage only (the
   !> cumulative load at the end of that stage; the condition stays, with a
   !> zero load before its first stage).
   subroutine body_conditions(scene, b, bcs, stage)
      type(scene_type), intent(in) :: scene
      !> Index of the body in `scene%bodies`.
      integer, intent(in) :: b
      type(fe_bc_type), allocatable, intent(out) :: bcs(:)
      integer, intent(in), optional :: stage
      logical :: first(size(scene%bcs))
      integer :: i, j, n, last

      last = huge(1)
      if (present(stage)) last = stage
      do i = 1, size(scene%bcs)
         first(i) = scene%shapes(scene%bcs(i)%shape_index)%body_index == b
         do j = 1, i - 1
            if (bc_surface(scene, scene%bcs(j)) == bc_surface(scene, scene%bcs(i)) .and. &
               & scene%shapes(scene%bcs(j)%shape_index)%body_index == b) first(i) = .false.
         end do
      end do
      allocate (bcs(count(first)))
      n = 0
      do i = 1, size(scene%bcs)
         if (.not. first(i)) cycle
         n = n + 1
         associate (bc => scene%bcs(i))
            if (allocated(bc%vector)) then
               bcs(n) = new_fe_bc(bc_surface(scene, bc), bc_kind_from_name(bc%type), 0.0_wp, 0.0_wp*bc%vector)
            else
               bcs(n) = new_fe_bc(bc_surface(scene, bc), bc_kind_from_name(bc%type), 0.0_wp)
            end if
         end associate
         do j = i, size(scene%bcs)
            associate (bc => scene%bcs(j))
               if (bc_surface(scene, bc) /= bc_surface(scene, scene%bcs(i)) .or. bc%stage > last) cycle
               if (scene%shapes(bc%shape_index)%body_index /= b) cycle
               bcs(n)%value = bcs(n)%value + bc%value
               if (allocated(bc%vector)) bcs(n)%vector = bcs(n)%vector + bc%vector
            end associate
         end do
      end do
   end subroutine body_conditions

   !> The body's surface id a condition acts on (`scene_surface`).
   pure integer function bc_surface(scene, bc) result(id)
      type(scene_type), intent(in) :: scene
      type(bc_spec_type), intent(in) :: bc
      id = scene_surface(scene, bc%shape_index, bc%group)
   end function bc_surface

   !> The body's surface id (sprc_geometry_body, module notes) of shape k of
   !> the scene (index in `scene%shapes`) or of its group `group` (> 0): the
   !> shape's index in its body, or for a group of a faceted shape the id
   !> after the body's shapes and the groups of the shapes before it.
   pure integer function scene_surface(scene, k, group) result(id)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: k, group
      integer :: j, body

      id = scene%shapes(k)%body_shape
      if (group <= 0) return
      body = scene%shapes(k)%body_index
      id = count(scene%shapes%body_index == body)
      do j = 1, size(scene%shapes)
         if (scene%shapes(j)%body_index /= body) cycle
         if (scene%shapes(j)%body_shape >= scene%shapes(k)%body_shape) cycle
         if (allocated(scene%shapes(j)%facets%group_name)) id = id + size(scene%shapes(j)%facets%group_name)
      end do
      id = id + group
   end function scene_surface

   !> Whether the scene's exact solution has a stress field (every kind but
   !> hertz_*, which give the contact pressure only): the energy-norm error
   !> columns apply only then.
   pure logical function exact_has_field(scene)
      type(scene_type), intent(in) :: scene
      exact_has_field = .false.
      if (scene%exact%present) exact_has_field = index(scene%exact%kind, 'hertz_') /= 1
   end function exact_has_field

   !> The scene's exact solution as it holds in body `b`, with that body's
   !> material, in the units of `scene` (pass `in_units(scene, units)` for a
   !> body's analysis units). Not allocated without `&exact`, for hertz_*
   !> (pressure only: `build_exact_pressure`) and, for compound_*, for a body
   !> that is neither `inner` nor `outer`.
   !>
   !> - lame_cylinder, lame_sphere, kirsch: the single-body closed form.
   !> - uniform: sigma = `stress` in every body, u = D_b^-1 sigma x with body b's material.
   !> - compound_cylinder / compound_sphere: the inner ring's field in body `inner`,
   !>   the outer ring's in body `outer` (both materials enter the interface pressure).
   subroutine build_exact(scene, b, exact, error)
      type(scene_type), intent(in) :: scene
      !> Index of the body in `scene%bodies`.
      integer, intent(in) :: b
      class(exact_solution_type), allocatable, intent(out) :: exact
      type(error_type), allocatable, intent(out) :: error

      if (.not. scene%exact%present) return
      associate (spec => scene%exact, young => scene%bodies(b)%young, nu => scene%bodies(b)%poisson)
         select case (spec%kind)
         case ('lame_cylinder')
            allocate (lame_cylinder_type :: exact)
            select type (exact)
            type is (lame_cylinder_type)
               call new_lame_cylinder(exact, spec%center, spec%r_in, spec%r_out, spec%p_in, spec%p_out, &
                  young, nu, analysis_kind(scene), error)
            end select
         case ('lame_sphere')
            allocate (lame_sphere_type :: exact)
            select type (exact)
            type is (lame_sphere_type)
               call new_lame_sphere(exact, spec%center, spec%r_in, spec%r_out, spec%p_in, spec%p_out, &
                  young, nu, error)
            end select
         case ('kirsch')
            allocate (kirsch_type :: exact)
            select type (exact)
            type is (kirsch_type)
               call new_kirsch(exact, spec%center, spec%radius, spec%s_inf, young, nu, analysis_kind(scene), error)
            end select
         case ('uniform')
            allocate (uniform_type :: exact)
            select type (exact)
            type is (uniform_type)
               call new_uniform(exact, spec%stress, young, nu, analysis_kind(scene), error)
            end select
         case ('compound_cylinder', 'compound_sphere')
            call build_compound_ring(scene, b, exact, error)
         case ('layered_cylinder', 'layered_sphere')
            call build_layered_ring(scene, b, exact, error)
         case ('corner')
            allocate (corner_type :: exact)
            select type (exact)
            type is (corner_type)
               call new_corner(exact, spec%point, spec%direction, spec%angle, spec%mode1, spec%mode2, young, nu, &
                  & analysis_kind(scene), error)
            end select
         case ('hertz_cylinder', 'hertz_sphere')
         case default
            call fatal_error(error, 'kind '''//spec%kind//''' is not available in this version', stat_unsupported)
         end select
      end associate
      if (allocated(error)) then
         error%message = '&exact: '//error%message
         if (allocated(exact)) deallocate (exact)
      end if
   end subroutine build_exact

   !> Body b's ring of the scene's compound solution, with the materials of the
   !> bodies `inner` and `outer` (not allocated for another body): the two-ring
   !> layered solution on the real radii (sprc_exact_layered), the inner ring
   !> out to r_contact + interference where the scene puts its surface, so
   !> that the reference carries no delta/r error (with no interference it is
   !> sprc_exact_compound's closed form).
   subroutine build_compound_ring(scene, b, exact, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: b
      class(exact_solution_type), allocatable, intent(out) :: exact
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: layered

      if (b /= scene%exact%inner_index .and. b /= scene%exact%outer_index) return
      associate (spec => scene%exact, inner => scene%bodies(scene%exact%inner_index), &
         & outer => scene%bodies(scene%exact%outer_index))
         call new_layered(layered, scene%dim, analysis_kind(scene), spec%center, [spec%r_in, spec%r_contact, &
            & spec%r_out], [spec%interference], spec%p_in, 0.0_wp, [inner%young, outer%young], &
            & [inner%poisson, outer%poisson], error, shifts=spec%ring_shifts)
      end associate
      if (allocated(error)) return
      if (b == scene%exact%inner_index) then
         call move_alloc(layered%rings(1)%field, exact)
      else
         call move_alloc(layered%rings(2)%field, exact)
      end if
   end subroutine build_compound_ring

   !> Body b's ring of the scene's layered solution, with every ring body's
   !> material (not allocated for a body that is not a ring).
   subroutine build_layered_ring(scene, b, exact, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: b
      class(exact_solution_type), allocatable, intent(out) :: exact
      type(error_type), allocatable, intent(out) :: error
      type(layered_type) :: layered
      real(wp), allocatable :: young(:), poisson(:)
      integer :: i, j

      i = findloc(scene%exact%ring_index, b, 1)
      if (i == 0) return
      allocate (young(size(scene%exact%ring_index)), poisson(size(scene%exact%ring_index)))
      do j = 1, size(young)
         young(j) = scene%bodies(scene%exact%ring_index(j))%young
         poisson(j) = scene%bodies(scene%exact%ring_index(j))%poisson
      end do
      associate (spec => scene%exact)
         call new_layered(layered, scene%dim, analysis_kind(scene), spec%center, spec%radii, spec%interferences, &
            & spec%p_in, spec%p_out, young, poisson, error, shifts=spec%ring_shifts)
      end associate
      if (.not. allocated(error)) call move_alloc(layered%rings(i)%field, exact)
   end subroutine build_layered_ring

   !> The exact contact pressure on the slave surface of `&contact` pair `k`,
   !> in the units of `scene` (the scene's own for a contact result): hertz_*
   !> from the closed form with E* of the pair's two bodies; every other kind
   !> from the slave body's exact field (p = -n.sigma.n; compound_* and
   !> layered_* on the slave's real surface, where its ring ends). Not allocated
   !> without `&exact` or when the slave body has no exact field (a compound
   !> scene's third body).
   subroutine build_exact_pressure(scene, k, pressure, error)
      type(scene_type), intent(in) :: scene
      !> Index of the pair in `scene%contacts`.
      integer, intent(in) :: k
      class(exact_pressure_type), allocatable, intent(out) :: pressure
      type(error_type), allocatable, intent(out) :: error
      class(exact_solution_type), allocatable :: field
      type(hertz_type) :: hertz
      type(field_pressure_type) :: from_field

      if (.not. scene%exact%present) return
      associate (spec => scene%exact, slave => scene%bodies(scene%contacts(k)%slave_index), &
         & master => scene%bodies(scene%contacts(k)%master_index))
         select case (spec%kind)
         case ('hertz_cylinder')
            call new_hertz_cylinder(hertz, spec%point, spec%normal, spec%radius, spec%load, slave%young, &
               & slave%poisson, master%young, master%poisson, analysis_kind(scene), error)
            if (.not. allocated(error)) allocate (pressure, source=hertz)
         case ('hertz_sphere')
            call new_hertz_sphere(hertz, spec%point, spec%normal, spec%radius, spec%load, slave%young, &
               & slave%poisson, master%young, master%poisson, error)
            if (.not. allocated(error)) allocate (pressure, source=hertz)
         case default
            call build_exact(scene, scene%contacts(k)%slave_index, field, error)
            if (allocated(error) .or. .not. allocated(field)) return
            if (spec%kind == 'compound_cylinder' .or. spec%kind == 'compound_sphere') then
               ! On the slave's real surface: the inner ring's ends an interference out.
               call new_field_pressure(from_field, field, spec%center, spec%r_contact + &
                  & merge(spec%ring_shifts(1), 0.0_wp, scene%contacts(k)%slave_index == spec%inner_index))
            else if (spec%kind == 'layered_cylinder' .or. spec%kind == 'layered_sphere') then
               ! On the slave's real surface, where its ring of the closed form ends.
               call new_field_pressure(from_field, field, spec%center, interface_radius(spec, scene%contacts(k)))
            else
               call new_field_pressure(from_field, field)
            end if
            allocate (pressure, source=from_field)
            return
         end select
      end associate
      if (allocated(error)) error%message = '&exact: '//error%message
   end subroutine build_exact_pressure

   !> The radius of the slave surface of `pair` in the layered solution on
   !> real radii (sprc_exact_layered): between rings i and i + 1, the inner
   !> ring's r_i + delta_i when it is the slave, the outer ring's bore r_i
   !> when that is.
   pure real(wp) function interface_radius(spec, pair) result(r)
      type(exact_spec_type), intent(in) :: spec
      type(contact_spec_type), intent(in) :: pair
      integer :: i, j
      i = findloc(spec%ring_index, pair%slave_index, 1)
      j = findloc(spec%ring_index, pair%master_index, 1)
      r = spec%radii(max(1, min(i, j) + 1))
      if (i < j .and. i >= 1 .and. i <= size(spec%ring_shifts)) r = r + spec%ring_shifts(i)
   end function interface_radius

end module sprc_study_model
