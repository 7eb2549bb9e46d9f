!> The memory a level of a study will need, estimated before its grid is built,
!> and the refusal of a level that cannot fit (a deep 3D level would otherwise
!> run out of memory in the middle of building its grid).
!>
!> Cells: the body's grid at a coarse level c (6 in 2D, 4 in 3D, at most the
!> level itself; 4096 cells at most) gives its inside and cut cells; each
!> covers 2^(dim (level - c)) cells of the level, the cut ones
!> 2^((dim - 1)(level - c)) cut cells, and refine_boundary splits each of
!> those into 2^(dim refine_boundary): an upper estimate (the cut cells at
!> level c count whole). Dofs: dim nodes per cell for Q1, dim 2^dim for Q2.
!> Bytes: an upper fit of the peak resident memory of the release build
!> (the fit and its data: doc/benchmarks.md): 32 MB + dofs * 2.5 kB (2D) or
!> 10 kB (dofs / 3e4)^(1/3) (3D, where the Cholesky factor fills more; times
!> 1.75 for Q2); a 3D level sent to the iterative solver (`use_iterative`)
!> has no factor: 8 kB per dof (times 1.75 for Q2). With `solver = 'auto'` a
!> 3D level whose direct estimate does not fit is solved iteratively, and
!> estimated so. The grid and its quadrature alone (`sprc mesh`,
!> `grid_only`): 16 MB + 128 bytes per cell.
!> Under an address-space limit (ulimit -v) the virtual size counts, and with
!> it OpenBLAS's buffer of 128 MiB per calling thread (sprc_core_blas_threads:
!> without it OpenBLAS can loop in its allocator); buffers already taken
!> (blas_reserve_buffers) do not count again.
!>
!> Bodies in contact (`check_coupled_memory`): one level with the sum of their
!> dofs (one direct factor of the whole system), plus the contact recovery's
!> Omega_aux data: per slave cut cell 3 * 2^(d-1) (order + 1)^d (d + 6) * 8
!> bytes (a prism about three cells deep per patch, dim + 6 reals per sampling
!> point, sprc_recovery_contact_aux), times 2 for the patch matrices
!> (`aux_bytes`). 'auto' treats the coupled system as one body.
module sprc_study_budget
   !$ use omp_lib, only: omp_get_max_threads
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type, fatal_error, stat_out_of_memory, stat_invalid_input
   use sprc_core_memory, only: available_memory
   use sprc_core_blas_threads, only: blas_buffer_bytes, blas_reserved_threads
   use sprc_core_text, only: byte_text
   use sprc_geometry_body, only: body_type
   use sprc_grid_tree, only: grid_type
   use sprc_study_spec, only: scene_type
   use sprc_fem_linear_solver, only: solver_auto, solver_iterative, solver_choice, use_iterative
   implicit none
   private

   public :: level_memory, check_level_memory, check_coupled_memory, coupled_memory, memory_check_wanted, level_cells

   real(wp), parameter :: base_bytes = 32.0e6_wp, per_dof_2d = 2.5e3_wp, per_dof_3d = 1.0e4_wp, &
      & dofs_3d = 3.0e4_wp, q2_factor_3d = 1.75_wp, per_dof_3d_iterative = 8.0e3_wp
   !> Grid and quadrature only (module notes).
   !> Environment variable that switches the estimate off (memory_check_wanted).
   character(len=*), parameter :: memory_check_variable = 'SPRC_MEMORY_CHECK'
   real(wp), parameter :: grid_base_bytes = 16.0e6_wp, per_cell_grid = 128.0_wp

contains

   !> Estimated cells, dofs and peak bytes of `level` of the scene's study for `body`
   !> (module notes); with `grid_only`, the bytes of the grid and its quadrature alone.
   !> Given `available` (bytes, -1 unknown), 'auto' takes the iterative solver's
   !> estimate when the direct one exceeds it (`direct_fits` false). With
   !> `known_dofs` (an adapted mesh, whose dofs are predicted by its size
   !> field), those dofs instead of the estimate from `level`.
   subroutine level_memory(scene, body, level, cells, dofs, bytes, error, grid_only, available, direct_fits, &
      & known_dofs)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      integer, intent(in) :: level
      real(wp), intent(out) :: cells, dofs, bytes
      type(error_type), allocatable, intent(out) :: error
      logical, intent(in), optional :: grid_only
      integer(i8), intent(in), optional :: available
      logical, intent(out), optional :: direct_fits
      real(wp), intent(in), optional :: known_dofs
      integer :: d
      real(wp) :: cut

      cells = 0.0_wp
      dofs = 0.0_wp
      bytes = 0.0_wp
      if (present(direct_fits)) direct_fits = .true.
      d = scene%dim
      if (present(known_dofs)) then
         dofs = known_dofs
         cells = dofs/real(d*scene%order**d, wp)
      else
         call level_cells(scene, body, level, cells, cut, error)
         if (allocated(error)) return
         dofs = real(d*scene%order**d, wp)*cells
      end if
      if (present(grid_only)) then
         if (grid_only) then
            bytes = grid_base_bytes + per_cell_grid*cells
            return
         end if
      end if
      call solve_bytes(scene, dofs, 0.0_wp, bytes, available, direct_fits)
   end subroutine level_memory

   !> Peak bytes of a level of `dofs` unknowns in one system plus `extra`
   !> bytes, by the solver 'auto' (or the scene) takes for it (module notes);
   !> `direct_fits` as for `level_memory`.
   subroutine solve_bytes(scene, dofs, extra, bytes, available, direct_fits, coupled)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: dofs, extra
      real(wp), intent(out) :: bytes
      integer(i8), intent(in), optional :: available
      logical, intent(out), optional :: direct_fits
      !> Bodies in contact, one system ('auto''s coupled threshold).
      logical, intent(in), optional :: coupled
      real(wp) :: direct_bytes
      integer :: n
      logical :: fits

      direct_bytes = base_bytes + dofs*per_dof(scene%dim, scene%order, dofs, .false.) + extra
      fits = .true.
      if (present(available)) fits = available < 0 .or. direct_bytes <= real(available, wp)
      n = int(min(dofs, real(huge(n), wp)))
      bytes = direct_bytes
      if (use_iterative(scene_choice(scene), scene%dim, scene%order, n, direct_fits=fits, coupled=coupled)) &
         & bytes = base_bytes + dofs*per_dof(scene%dim, scene%order, dofs, .true.) + extra
      if (present(direct_fits)) direct_fits = fits
   end subroutine solve_bytes

   !> Upper estimate of the cells and cut cells of `body` at `level` (module notes).
   subroutine level_cells(scene, body, level, cells, cut_cells, error)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      integer, intent(in) :: level
      real(wp), intent(out) :: cells, cut_cells
      type(error_type), allocatable, intent(out) :: error
      type(grid_type) :: grid
      integer :: d, coarse, up
      real(wp) :: active, cut, box_size
      real(wp), allocatable :: box_min(:)

      cells = 0.0_wp
      cut_cells = 0.0_wp
      d = scene%dim
      coarse = min(level, merge(6, 4, d == 2))
      call body_box(scene, body, box_min, box_size)
      call grid%build(body, d, box_min, box_size, coarse, 0, error)
      if (allocated(error)) return
      active = real(sum(grid%n_inside) + sum(grid%n_cut), wp)
      cut = real(sum(grid%n_cut), wp)
      up = level - coarse
      cut_cells = cut*2.0_wp**((d - 1)*up)*2.0_wp**((d - 1)*scene%refine_boundary)
      cells = active*2.0_wp**(d*up) + cut*2.0_wp**((d - 1)*up)*(2.0_wp**(d*scene%refine_boundary) - 1.0_wp)
   end subroutine level_cells

   !> Omega_aux bytes of `cut_cells` slave surface cells (module notes).
   pure real(wp) function aux_bytes(scene, cut_cells)
      type(scene_type), intent(in) :: scene
      real(wp), intent(in) :: cut_cells
      integer :: d
      d = scene%dim
      aux_bytes = 2.0_wp*3.0_wp*2.0_wp**(d - 1)*real((scene%order + 1)**d*(d + 6), wp)*8.0_wp*cut_cells
   end function aux_bytes

   !> Estimated cells, dofs and peak bytes of `level` for the bodies
   !> `bodies(members)` solved in one block system, `slaves` those of them
   !> whose contact surfaces carry slave points (module notes); `available`,
   !> `direct_fits` and `known_dofs` (per member) as for `level_memory`.
   !> Without `bodies`, `known_cells(:, k)` are member k's cells and cut cells
   !> (`level_cells`): a caller holding bodies as a component of an array
   !> passes these rather than a copy of every body's geometry.
   subroutine coupled_memory(scene, bodies, members, slaves, level, cells, dofs, bytes, error, available, &
      & direct_fits, known_dofs, known_cells)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in), optional :: bodies(:)
      integer, intent(in) :: members(:), slaves(:), level
      real(wp), intent(out) :: cells, dofs, bytes
      type(error_type), allocatable, intent(out) :: error
      integer(i8), intent(in), optional :: available
      logical, intent(out), optional :: direct_fits
      real(wp), intent(in), optional :: known_dofs(:)
      real(wp), intent(in), optional :: known_cells(:, :)
      real(wp) :: c, cut, extra
      integer :: k

      cells = 0.0_wp
      dofs = 0.0_wp
      bytes = 0.0_wp
      extra = 0.0_wp
      do k = 1, size(members)
         if (present(known_dofs)) then
            c = known_dofs(k)/real(scene%dim*scene%order**scene%dim, wp)
            ! a surface of an adapted mesh: that of a uniform grid of c cells, an upper estimate
            cut = 2.0_wp*real(scene%dim, wp)*c**(real(scene%dim - 1, wp)/real(scene%dim, wp))
         else if (present(known_cells)) then
            c = known_cells(1, k)
            cut = known_cells(2, k)
         else
            call level_cells(scene, bodies(members(k)), level, c, cut, error)
            if (allocated(error)) return
         end if
         cells = cells + c
         if (any(slaves == members(k))) extra = extra + aux_bytes(scene, cut)
      end do
      dofs = real(scene%dim*scene%order**scene%dim, wp)*cells
      call solve_bytes(scene, dofs, extra, bytes, available, direct_fits, coupled=.true.)
   end subroutine coupled_memory

   !> Estimated bytes per dof of a level of `dofs` unknowns in dimension `d`
   !> with elements of degree `order`, solved iteratively or not (module notes).
   pure real(wp) function per_dof(d, order, dofs, iterative)
      integer, intent(in) :: d, order
      real(wp), intent(in) :: dofs
      logical, intent(in) :: iterative
      if (d == 2) then
         per_dof = per_dof_2d
         return
      end if
      if (iterative) then
         per_dof = per_dof_3d_iterative
      else
         per_dof = per_dof_3d*(dofs/dofs_3d)**(1.0_wp/3.0_wp)
      end if
      if (order == 2) per_dof = q2_factor_3d*per_dof
   end function per_dof

   !> The scene's solver choice code ('auto' when unset).
   pure integer function scene_choice(scene) result(choice)
      type(scene_type), intent(in) :: scene
      choice = solver_auto
      if (allocated(scene%solver)) then
         if (len(scene%solver) > 0) choice = solver_choice(scene%solver)
      end if
   end function scene_choice

   !> stat_out_of_memory when the estimate of `level` exceeds the memory this process
   !> may still use (sprc_core_memory); the message names the estimate, what is available
   !> and what bounds it. `solver`: the solver choice code for the level's solve, the
   !> scene's, or `solver_iterative` where 'auto' found that a direct solve would not fit.
   !> `known_dofs`: as for `level_memory`.
   subroutine check_level_memory(scene, body, level, error, grid_only, solver, known_dofs)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      integer, intent(in) :: level
      type(error_type), allocatable, intent(out) :: error
      !> Only the grid and its quadrature will be built (`sprc mesh`).
      logical, intent(in), optional :: grid_only
      integer, intent(out), optional :: solver
      real(wp), intent(in), optional :: known_dofs
      real(wp) :: cells, dofs, bytes, reserve
      integer(i8) :: avail, usable
      character(len=:), allocatable :: source
      character(len=256) :: buf
      logical :: wanted, direct_fits

      if (present(solver)) solver = scene_choice(scene)
      call memory_check_wanted(wanted, error)
      if (allocated(error) .or. .not. wanted) return
      call usable_memory(avail, usable, reserve, source)
      call level_memory(scene, body, level, cells, dofs, bytes, error, grid_only, usable, direct_fits, known_dofs)
      if (allocated(error)) return
      bytes = bytes + reserve
      if (avail < 0 .or. bytes <= real(avail, wp)) then
         if (present(solver) .and. .not. direct_fits) then
            if (solver == solver_auto) solver = solver_iterative
         end if
         return
      end if
      write (buf, '("needs about ",a," of memory (an estimate for ",es7.1," cells, ",es7.1, &
         & " dofs), but ",a," is available (",a,"); use a lower level")') byte_text(bytes), cells, dofs, &
         & byte_text(real(avail, wp)), source
      call fatal_error(error, trim(buf), stat_out_of_memory)
   end subroutine check_level_memory

   !> `check_level_memory` for the bodies `bodies(members)` solved in one
   !> block system (`coupled_memory`): stat_out_of_memory, before any of
   !> them is built, when their estimate exceeds the memory available;
   !> `solver` becomes `solver_iterative` where 'auto' found that a direct
   !> solve of the coupled system would not fit.
   subroutine check_coupled_memory(scene, bodies, members, slaves, level, error, solver, known_dofs, known_cells)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in), optional :: bodies(:)
      integer, intent(in) :: members(:), slaves(:), level
      type(error_type), allocatable, intent(out) :: error
      integer, intent(out), optional :: solver
      real(wp), intent(in), optional :: known_dofs(:), known_cells(:, :)
      real(wp) :: cells, dofs, bytes, reserve
      integer(i8) :: avail, usable
      character(len=:), allocatable :: source
      character(len=320) :: buf
      logical :: wanted, direct_fits

      if (present(solver)) solver = scene_choice(scene)
      call memory_check_wanted(wanted, error)
      if (allocated(error) .or. .not. wanted) return
      call usable_memory(avail, usable, reserve, source)
      call coupled_memory(scene, bodies, members, slaves, level, cells, dofs, bytes, error, usable, direct_fits, &
         & known_dofs, known_cells)
      if (allocated(error)) return
      bytes = bytes + reserve
      if (avail < 0 .or. bytes <= real(avail, wp)) then
         if (present(solver) .and. .not. direct_fits) then
            if (solver == solver_auto) solver = solver_iterative
         end if
         return
      end if
      write (buf, '("the bodies in contact (solved together) need about ",a," of memory (an estimate for ",es7.1, &
         & " cells, ",es7.1," dofs in one system, with the contact recovery''s data), but ",a," is available (",a, &
         & "); use a lower level")') byte_text(bytes), cells, dofs, byte_text(real(avail, wp)), source
      call fatal_error(error, trim(buf), stat_out_of_memory)
   end subroutine check_coupled_memory

   !> The memory available (`avail`, -1 unknown, and what bounds it), less
   !> the BLAS buffers still to be reserved under an address-space limit
   !> (`reserve`; module notes): `usable`.
   subroutine usable_memory(avail, usable, reserve, source)
      integer(i8), intent(out) :: avail, usable
      real(wp), intent(out) :: reserve
      character(len=:), allocatable, intent(out) :: source
      integer :: threads

      call available_memory(avail, source)
      threads = 1
      !$ threads = omp_get_max_threads()
      reserve = 0.0_wp
      if (source == 'ulimit -v') reserve = real(max(0, threads + 1 - blas_reserved_threads()), wp)* &
         & real(blas_buffer_bytes, wp)
      usable = avail
      if (avail >= 0) usable = max(0_i8, avail - int(reserve, i8))
   end subroutine usable_memory

   !> False when the environment variable SPRC_MEMORY_CHECK is 'off': the estimate
   !> above is then skipped (it is an upper estimate; a user who knows a level fits,
   !> or who tests the allocation errors underneath, may run it anyway). Unset, empty
   !> or 'on': the check is made; any other value is an input error.
   subroutine memory_check_wanted(wanted, error)
      logical, intent(out) :: wanted
      type(error_type), allocatable, intent(out) :: error
      character(len=16) :: value
      integer :: length, stat

      wanted = .true.
      call get_environment_variable(memory_check_variable, value, length, stat)
      if (stat == 1 .or. length == 0) return
      if (stat == 0) then
         if (value == 'on') return
         if (value == 'off') then
            wanted = .false.
            return
         end if
      end if
      call fatal_error(error, 'environment variable '//memory_check_variable//' = "'//value(1:min(length, len(value)))// &
         & trim(merge('...', '   ', length > len(value)))//'": expected on or off', stat_invalid_input)
   end subroutine memory_check_wanted

   !> The level-0 cell of `body`'s grid: that of the scene's body of the same name
   !> (`&body` box_min, box_size, the scene's when the body has none of its own).
   subroutine body_box(scene, body, box_min, box_size)
      type(scene_type), intent(in) :: scene
      type(body_type), intent(in) :: body
      real(wp), allocatable, intent(out) :: box_min(:)
      real(wp), intent(out) :: box_size
      integer :: b

      box_min = scene%box_min
      box_size = scene%box_size
      if (.not. allocated(body%name)) return
      do b = 1, size(scene%bodies)
         if (.not. allocated(scene%bodies(b)%name) .or. .not. allocated(scene%bodies(b)%box_min)) cycle
         if (scene%bodies(b)%name /= body%name) cycle
         box_min = scene%bodies(b)%box_min
         box_size = scene%bodies(b)%box_size
         return
      end do
   end subroutine body_box

end module sprc_study_budget
