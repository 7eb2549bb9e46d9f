!> The levels of a study and what `sprc mesh` computes over them (cells,
!> measure and boundary measure of each body's grid), as rows of data; the
!> driver or the C API format them (`sprc_io_report`).
module sprc_study_mesh_table
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_timer, only: timer_type
   use sprc_geometry_body, only: body_type, new_body, shape_name, csg_op_name
   use sprc_grid_tree, only: grid_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule, &
      & default_points
   use sprc_study_spec, only: scene_type
   use sprc_study_model, only: build_bodies, scene_surface
   use sprc_study_budget, only: check_level_memory
   implicit none
   private

   public :: mesh_row_type, surface_measure_type, mesh_study, study_levels, check_surfaces

   !> The boundary measure of one surface named by `&bc` or `&contact` (a shape,
   !> or a named group of a faceted shape).
   type :: surface_measure_type
      character(len=:), allocatable :: name
      real(wp) :: measure = 0.0_wp
   end type surface_measure_type

   !> One line of `sprc mesh`: a body's grid at one level.
   type :: mesh_row_type
      integer :: level = 0
      character(len=:), allocatable :: body
      !> Leaves of each class, summed over all levels of the grid; external
      !> cells coarser than `level` count as the level-`level` cells they cover.
      integer(i8) :: internal = 0, cut = 0, external = 0
      !> Area (2D) / volume (3D) of the body and length / area of its boundary,
      !> summed from the cut-cell quadrature.
      real(wp) :: measure = 0.0_wp, boundary_measure = 0.0_wp
      !> The named surfaces of the body (`&bc`, `&contact`), in file order: each one's
      !> part of boundary_measure (the surface points the quadrature tags with its shape,
      !> or its group).
      type(surface_measure_type), allocatable :: surfaces(:)
      !> Gauss points per direction used; volume and surface points of all cells' rules.
      integer :: points = 0
      integer(i8) :: volume_points = 0, surface_points = 0
      !> Boxes the cut-cell quadrature integrated without resolving the geometry
      !> (sprc_grid_quadrature `nunresolved`: where a faceted surface meets another
      !> surface at the smallest box, or no height direction at max_depth).
      integer(i8) :: unresolved = 0
      !> Seconds to build, classify and balance the grid, and to build the rules.
      real(wp) :: t_mesh = 0.0_wp, t_quadrature = 0.0_wp
   end type mesh_row_type

contains

   !> The levels of a study: the scene's, or `override` when given (each
   !> must respect the scene's limits: 0..14 in 2D, 0..9 in 3D).
   subroutine study_levels(scene, override, levels, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in), optional :: override(:)
      integer, allocatable, intent(out) :: levels(:)
      type(error_type), allocatable, intent(out) :: error
      integer :: top, i
      character(len=16) :: buf

      levels = scene%levels
      if (.not. present(override)) return
      if (size(override) == 0) return
      if (scene%adapt%present .and. size(override) /= 1) then
         call fatal_error(error, '--levels: '//itoa(size(override))//' levels; a scene with &adapt takes one, '// &
            & 'the start level', stat_invalid_input)
         return
      end if
      top = merge(14, 9, scene%dim == 2)
      do i = 1, size(override)
         if (override(i) < 0 .or. override(i) > top) then
            write (buf, '(i0)') override(i)
            call fatal_error(error, '--levels: level '//trim(buf)//' is out of range for a '// &
               merge('2D', '3D', scene%dim == 2)//' scene (0..'//trim(merge('14', '9 ', scene%dim == 2))//')', &
               stat_invalid_input)
            return
         end if
      end do
      if (scene%adapt%present .and. override(1) > scene%adapt%max_level) then
         call fatal_error(error, '--levels: start level '//itoa(override(1))//' lies above &adapt max_level = '// &
            & itoa(scene%adapt%max_level), stat_invalid_input)
         return
      end if
      levels = override
   end subroutine study_levels

   !> Build each body's grid at each level, count its cells and integrate its
   !> measure and boundary measure with `points` Gauss points per direction
   !> (0: the default for the scene's FE order).
   subroutine mesh_study(scene, levels, points, rows, error)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: levels(:), points
      type(mesh_row_type), allocatable, intent(out) :: rows(:)
      type(error_type), allocatable, intent(out) :: error
      type(body_type), allocatable :: bodies(:)
      type(grid_type) :: grid
      type(timer_type) :: timer
      type(cut_quadrature_type) :: quad
      real(wp), allocatable :: by_surface(:)
      integer, allocatable :: named(:)
      integer :: l, b, k, j

      call build_bodies(scene, bodies, error)
      if (allocated(error)) return
      call new_cut_quadrature(quad, scene%dim, merge(points, default_points(scene%order), points > 0), error)
      if (allocated(error)) return
      allocate (rows(size(levels)*size(bodies)))
      k = 0
      do l = 1, size(levels)
         do b = 1, size(bodies)
            k = k + 1
            call check_level_memory(scene, bodies(b), levels(l), error, grid_only=.true.)
            if (.not. allocated(error)) then
               call timer%reset()
               call timer%start()
               call grid%build(bodies(b), scene%dim, scene%bodies(b)%box_min, scene%bodies(b)%box_size, &
                  & levels(l), scene%refine_boundary, error)
               call timer%stop()
            end if
            if (allocated(error)) then
               error%message = 'body '''//bodies(b)%name//''', level '//itoa(levels(l))//': '//error%message
               return
            end if
            rows(k)%level = levels(l)
            rows(k)%body = bodies(b)%name
            rows(k)%internal = sum(grid%n_inside)
            rows(k)%cut = sum(grid%n_cut)
            rows(k)%external = sum(grid%n_outside)
            rows(k)%t_mesh = timer%elapsed
            rows(k)%points = quad%q
            call timer%reset()
            call timer%start()
            call integrate_measures(grid, bodies(b), quad, rows(k)%measure, rows(k)%boundary_measure, by_surface, &
               & rows(k)%volume_points, error, rows(k)%surface_points, rows(k)%unresolved)
            call timer%stop()
            rows(k)%t_quadrature = timer%elapsed
            if (allocated(error)) return
            named = named_surfaces(scene, b)
            allocate (rows(k)%surfaces(size(named)))
            do j = 1, size(named)
               rows(k)%surfaces(j)%name = bodies(b)%surface_name(named(j))
               rows(k)%surfaces(j)%measure = by_surface(named(j))
            end do
         end do
      end do
   end subroutine mesh_study

   !> Sum of the volume and surface weights of every active cell's rule, in
   !> leaf order with compensated (Neumaier) sums, so that the printed 15
   !> digits are the quadrature's, not the summation's; by_surface(i) is the
   !> part of boundary_measure whose points the quadrature tags with surface
   !> id i (sprc_geometry_body): a shape's includes its groups'. npoints: the
   !> volume points of all rules; nsurf their surface points; unresolved the
   !> boxes integrated without resolving the geometry.
   subroutine integrate_measures(grid, body, quad, measure, boundary_measure, by_surface, npoints, error, nsurf, &
         & unresolved)
      type(grid_type), intent(in) :: grid
      type(body_type), intent(in) :: body
      type(cut_quadrature_type), intent(in) :: quad
      real(wp), intent(out) :: measure, boundary_measure
      real(wp), allocatable, intent(out) :: by_surface(:)
      integer(i8), intent(out) :: npoints, nsurf, unresolved
      type(error_type), allocatable, intent(out) :: error
      type(cell_rule_type) :: rule
      real(wp) :: lo(3), hi(3), vol(2), surf(2)
      real(wp), allocatable :: acc(:, :)
      integer :: leaf, d, q, s, id

      d = grid%dim
      vol = 0.0_wp
      surf = 0.0_wp
      allocate (acc(2, body%nsurface()), source=0.0_wp)
      npoints = 0
      nsurf = 0
      unresolved = 0
      do leaf = 1, grid%n_leaves
         call grid%leaf_box(leaf, lo(1:d), hi(1:d))
         call cell_rule(quad, body, lo(1:d), hi(1:d), rule, error)
         if (allocated(error)) return
         call neumaier_add(vol, rule%vol_w(1:rule%nvol))
         npoints = npoints + rule%nvol
         nsurf = nsurf + rule%nsurf
         unresolved = unresolved + rule%nunresolved
         call neumaier_add(surf, rule%surf_w(1:rule%nsurf))
         do q = 1, rule%nsurf
            id = rule%surf_shape(q)
            s = body%surface_shape(id)
            if (s < 1) cycle
            call neumaier_add(acc(:, id), rule%surf_w(q:q))
            if (id /= s) call neumaier_add(acc(:, s), rule%surf_w(q:q))
         end do
      end do
      measure = vol(1) + vol(2)
      boundary_measure = surf(1) + surf(2)
      by_surface = acc(1, :) + acc(2, :)
   end subroutine integrate_measures

   !> Body b's surface ids (sprc_geometry_body) named by a `&bc` or a `&contact`, ascending:
   !> its shapes in file order, then the named groups of its faceted shapes.
   function named_surfaces(scene, b) result(list)
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: b
      integer, allocatable :: list(:)
      logical, allocatable :: named(:)
      integer :: k, n

      n = 0
      do k = 1, size(scene%shapes)
         if (scene%shapes(k)%body_index /= b) cycle
         n = n + 1
         if (allocated(scene%shapes(k)%facets%group_name)) n = n + size(scene%shapes(k)%facets%group_name)
      end do
      allocate (named(n), source=.false.)
      if (allocated(scene%bcs)) then
         do k = 1, size(scene%bcs)
            call mark(scene%bcs(k)%shape_index, scene%bcs(k)%group)
         end do
      end if
      if (allocated(scene%contacts)) then
         do k = 1, size(scene%contacts)
            call mark(scene%contacts(k)%slave_surface_index, scene%contacts(k)%slave_group)
            call mark(scene%contacts(k)%master_surface_index, scene%contacts(k)%master_group)
         end do
      end if
      list = pack([(k, k=1, n)], named)
   contains
      subroutine mark(shape, group)
         integer, intent(in) :: shape, group
         if (shape < 1) return
         if (scene%shapes(shape)%body_index == b) named(scene_surface(scene, shape, group)) = .true.
      end subroutine mark
   end function named_surfaces

   !> Every body must have material and every surface named by a `&bc` or a
   !> `&contact` must bound its body with a positive measure at `level` (the
   !> first level of the study): a load on a surface the body does not have
   !> would be dropped silently. The measures are those of `sprc mesh`: the
   !> body's volume quadrature and the surface points the cut-cell quadrature
   !> tags with each shape, which are those a load is applied on (where two
   !> shapes' surfaces coincide the quadrature tags one of them: SCENE.md). The
   !> quadrature resolves the geometry inside a cell, so a coarse level decides
   !> as well as a fine one, except for features below 2^-max_depth of a cell.
   !> Errors (stat_invalid_input) name the body or the surface and why: the
   !> shape that covers it, or that it never reaches the body. First the
   !> level's memory check: the whole study's (as the run makes it) or, with
   !> grid_only, the grid's (`sprc mesh`).
   subroutine check_surfaces(scene, bodies, level, points, error, grid_only)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: bodies(:)
      integer, intent(in) :: level, points
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: grid_only
      type(cut_quadrature_type) :: quad
      real(wp), allocatable :: by_surface(:)
      integer, allocatable :: named(:)
      real(wp) :: measure
      integer :: b, j, i

      call new_cut_quadrature(quad, scene%dim, merge(points, default_points(scene%order), points > 0), error)
      if (allocated(error)) return
      do b = 1, size(bodies)
         call check_level_memory(scene, bodies(b), level, error, grid_only=grid_only)
         if (allocated(error)) then
            error%message = "body '"//bodies(b)%name//"', level "//itoa(level)//': '//error%message
            return
         end if
         call body_measures(scene, bodies(b), b, level, quad, measure, by_surface, error)
         if (allocated(error)) return
         if (.not. measure > 0.0_wp) then
            call fatal_error(error, "body '"//bodies(b)%name//"' is empty at level "//itoa(level)// &
               & ' (measure 0): its shapes have no material in common inside the box', stat_invalid_input)
            return
         end if
         named = named_surfaces(scene, b)
         do j = 1, size(named)
            i = named(j)
            if (by_surface(i) > 0.0_wp) cycle
            call uncovered_error(scene, bodies(b), b, i, level, quad, error)
            return
         end do
      end do
   end subroutine check_surfaces

   !> Body b's measure and each surface's boundary measure on its grid at `level`.
   subroutine body_measures(scene, body, b, level, quad, measure, by_surface, error)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      integer, intent(in) :: b, level
      type(cut_quadrature_type), intent(in) :: quad
      real(wp), intent(out) :: measure
      real(wp), allocatable, intent(out) :: by_surface(:)
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      real(wp) :: boundary_measure
      integer(i8) :: npoints, nsurf, unresolved

      call grid%build(body, scene%dim, scene%bodies(b)%box_min, scene%bodies(b)%box_size, level, &
         & scene%refine_boundary, error)
      if (allocated(error)) then
         error%message = "body '"//body%name//"', level "//itoa(level)//': '//error%message
         return
      end if
      call integrate_measures(grid, body, quad, measure, boundary_measure, by_surface, npoints, error, nsurf, &
         & unresolved)
   end subroutine body_measures

   !> The error for surface id of body b (a shape i's whole surface, or a
   !> group g of faceted shape i), which does not bound the body: why, from the
   !> bodies of its first k shapes (k = i, i+1, ...): none of the surface
   !> bounds the first i (it misses the shapes before it, or lies outside the
   !> box), or shape k is the first after which none does.
   subroutine uncovered_error(scene, body, b, id, level, quad, error)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      integer, intent(in) :: b, id, level
      type(cut_quadrature_type), intent(in) :: quad
      type(error_type), allocatable, intent(out) :: error
      type(body_type) :: prefix
      real(wp), allocatable :: by_surface(:)
      real(wp) :: measure
      character(len=:), allocatable :: what, why
      integer :: k, i, g

      i = body%surface_shape(id)
      g = 0
      if (id /= i) g = id - body%group_surface(i, 1) + 1

      call new_body(prefix, body%name)
      do k = 1, body%nshape
         call prefix%add_shape(body%ops(k), body%shapes(k), error)
         if (allocated(error)) return
         if (k < i) cycle
         call body_measures(scene, prefix, b, level, quad, measure, by_surface, error)
         if (allocated(error)) return
         ! the prefix body's id of the surface: its groups follow its k shapes
         if (.not. by_surface(prefix%group_surface(i, g)) > 0.0_wp) exit
      end do
      k = min(k, body%nshape)
      what = "surface '"//body%surface_name(id)//"'"
      if (g > 0) what = what//" (a group of shape '"//shape_name(body%shapes(i))//"')"
      what = what//" does not bound body '"//body%name//"' (boundary measure 0 at level "//itoa(level)//'): '
      if (k > i) then
         why = "shape '"//shape_name(body%shapes(k))//"' ("//csg_op_name(body%ops(k))// &
            & ') covers the last of it, or takes it where their surfaces coincide (sprc mesh shows each named '// &
            & "surface's measure)"
      else if (i == 1) then
         why = "its surface lies wholly outside the box of the body's grid (box_min, box_size)"
      else
         why = 'it misses the body of the shapes before it ('//csg_op_name(body%ops(i))// &
            & ' of a shape wholly inside or outside them, or coinciding with their boundary)'
      end if
      call fatal_error(error, what//why//'; a &bc or &contact surface must bound its body', stat_invalid_input)
   end subroutine uncovered_error

   !> acc = (sum, compensation) += values, Neumaier's variant of Kahan summation.
   pure subroutine neumaier_add(acc, values)
      real(wp), intent(inout) :: acc(2)
      real(wp), intent(in) :: values(:)
      real(wp) :: t
      integer :: i
      do i = 1, size(values)
         t = acc(1) + values(i)
         if (abs(acc(1)) >= abs(values(i))) then
            acc(2) = acc(2) + ((acc(1) - t) + values(i))
         else
            acc(2) = acc(2) + ((values(i) - t) + acc(1))
         end if
         acc(1) = t
      end do
   end subroutine neumaier_add

end module sprc_study_mesh_table
