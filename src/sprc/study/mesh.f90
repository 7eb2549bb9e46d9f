!> The levels of a study and what `sprc mesh` computes over them (cells,
!> measure and boundary measure of each body's grid), as rows of data; the
!> driver or the C API format them (`sprc_io_report`).
module sprc_study_mesh
   use sprc_core_kinds, only: wp, i8
   use sprc_core_text, only: itoa
   use sprc_core_error, only: error_type, fatal_error, stat_invalid_input
   use sprc_core_timer, only: timer_type
   use sprc_geometry_body, only: body_type
   use sprc_grid_tree, only: grid_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature, cell_rule_type, cell_rule, &
      & default_points
   use sprc_study_spec, only: scene_type
   use sprc_study_model, only: build_bodies
   use sprc_study_budget, only: check_level_memory
   implicit none
   private

   public :: mesh_row_type, mesh_study, study_levels

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
      !> Gauss points per direction used.
      integer :: points = 0
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
      integer :: l, b, k

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
            call integrate_measures(grid, bodies(b), quad, rows(k)%measure, rows(k)%boundary_measure, error)
            call timer%stop()
            rows(k)%t_quadrature = timer%elapsed
            if (allocated(error)) return
         end do
      end do
   end subroutine mesh_study

   !> Sum of the volume and surface weights of every active cell's rule, in
   !> leaf order with compensated (Neumaier) sums, so that the printed 15
   !> digits are the quadrature's, not the summation's.
   subroutine integrate_measures(grid, body, quad, measure, boundary_measure, error)
      type(grid_type), intent(in) :: grid
      type(body_type), intent(in) :: body
      type(cut_quadrature_type), intent(in) :: quad
      real(wp), intent(out) :: measure, boundary_measure
      type(error_type), allocatable, intent(out) :: error
      type(cell_rule_type) :: rule
      real(wp) :: lo(3), hi(3), vol(2), surf(2)
      integer :: leaf, d

      d = grid%dim
      vol = 0.0_wp
      surf = 0.0_wp
      do leaf = 1, grid%n_leaves
         call grid%leaf_box(leaf, lo(1:d), hi(1:d))
         call cell_rule(quad, body, lo(1:d), hi(1:d), rule, error)
         if (allocated(error)) return
         call neumaier_add(vol, rule%vol_w(1:rule%nvol))
         call neumaier_add(surf, rule%surf_w(1:rule%nsurf))
      end do
      measure = vol(1) + vol(2)
      boundary_measure = surf(1) + surf(2)
   end subroutine integrate_measures

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

end module sprc_study_mesh
