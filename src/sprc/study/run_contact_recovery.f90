!> The recoveries of a contact pair (`sprc_study_run_contact`): each body's
!> coupled SPR-C description of the pair (`pair_contact`), its recovered
!> tractions, and the `stabilization = 'recovered'` iteration that re-solves
!> the pair with the slave body's recovered traction until it settles.
module sprc_study_run_contact_recovery
   use sprc_core_kinds, only: wp
   use sprc_core_error, only: error_type, fatal_error, stat_not_converged
   use sprc_core_timer, only: timer_type
   use sprc_core_alloc, only: check_allocation
   use sprc_grid_nodes, only: grid_nodes_type
   use sprc_estimate_patches, only: recovery_input_type, recover_grid, boundary_points
   use sprc_recovery_patch, only: patch_type
   use sprc_estimate_recovered_field, only: recovered_field_type, method_sprc, field_eval
   use sprc_recovery_contact_operators, only: contact_traction, contact_law_frictionless, contact_law_slip, &
      & contact_law_stick
   use sprc_estimate_contact_patches, only: grid_contact_type, new_grid_contact, point_cells_type, &
      & new_point_cells, cells_box, set_grid_contact_edges
   use sprc_recovery_contact_edge_fit, only: contact_edge_type, fit_contact_edge, fit_facets, fit_edge_gap, gap_amplitude
   use sprc_core_material, only: plane_stress
   use sprc_estimate_fe_input, only: fe_recovery_input
   use sprc_study_spec, only: contact_spec_type
   use sprc_study_model, only: scene_surface, analysis_units_type
   use sprc_contact_result, only: contact_result_type, new_contact_result, contact_open, contact_stick, &
      & contact_slip
   use sprc_contact_surface, only: contact_surface_type
   use sprc_contact_pair_solve, only: contact_solution_type, solve_contact_pair, friction_kind, friction_coulomb, &
      & friction_frictionless, default_max_iterations, contact_factor_type, multiplier_kind
   use sprc_fem_element, only: traction_matrix
   use sprc_core_text, only: itoa, real_text
   use sprc_study_level_types, only: study_type, body_level_type
   use sprc_study_run_estimate, only: recover_body
   use sprc_study_run_bodies, only: exact_error
   implicit none
   private

   public :: stabilize_recovered, finish_pair, pair_contact, recovered_tractions, contact_result, paired_point
   public :: pair_edges_type, pair_edges

   !> The fitted contact edges of a pair (`pair_edges`), computed once and given to both
   !> sides' `pair_contact`; not allocated where the pair has no edge field (3D, friction,
   !> `edges = .false.`).
   type :: pair_edges_type
      type(contact_edge_type), allocatable :: edges(:)
   end type pair_edges_type

   !> The range of a contact edge along its tangent, in slave cells from the midpoint of the
   !> last closed and the first open slave point (`contact_edges`): the multiplier is constant
   !> over contact cells of two slave cells, so the states place the edge within a contact cell
   !> either way (doc/scene.md: a - contact_measure within -1.01 h .. +0.75 h).
   real(wp), parameter :: edge_range(2) = [-2.0_wp, 2.0_wp]

contains

   !> Tur's recovered stabilization (sprc_contact_pair_solve notes): the pair
   !> solved with a zero stabilization traction first (the penalty method,
   !> SPD for every kappa), then again and again with the slave body's
   !> recovered traction sigma* n of the previous solution at the slave
   !> points as the known stabilization traction, until an update leaves
   !> the active set as it was and moves the contact traction (pressure and tangential part, L2 over
   !> the slave surface) by at most sqrt(eps) of its norm: the fixed point's
   !> own round-off tier, as the update contracts by about C_I/kappa (the
   !> traction operator's bound over the penalty). `sol%iterations` sums every
   !> active-set iteration of every solve (doc/scene.md contact_iterations), and
   !> `sol%t_contact` the stabilization's recoveries (the stabilization
   !> traction is a contact term; t_recovery stays the reported fields'); an
   !> iteration that has not settled after default_max_iterations updates is
   !> stat_not_converged.
   subroutine stabilize_recovered(study, spec, surface, names, bodies, sol, pstar, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      character(len=*), intent(in) :: names(2)
      type(body_level_type), intent(inout) :: bodies(:)
      type(contact_solution_type), intent(out) :: sol
      !> The stabilization traction of the last solve (dim, npoint; pair units).
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(contact_factor_type) :: factor

      call recovered_updates(study, spec, surface, names, bodies, factor, sol, pstar, error)
      call factor%destroy()
   end subroutine stabilize_recovered

   !> The iteration of `stabilize_recovered` with the block factor kept
   !> between updates (sprc_contact_pair_solve: the matrix depends on the active
   !> set only).
   subroutine recovered_updates(study, spec, surface, names, bodies, factor, sol, pstar, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      character(len=*), intent(in) :: names(2)
      type(body_level_type), intent(inout) :: bodies(:)
      type(contact_factor_type), intent(inout) :: factor
      type(contact_solution_type), intent(out) :: sol
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(contact_solution_type) :: next
      type(timer_type) :: timer
      real(wp) :: change, size_, t_solve, t_contact
      integer :: s, m, it, iterations, stat

      s = spec%slave_index
      m = spec%master_index
      allocate (pstar(surface%dim, surface%npoint), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact pair', 'the recovered traction of each slave point', surface%npoint, &
         & 8*surface%dim, error)
      if (allocated(error)) return
      call solve_contact_pair(bodies(s)%problem, bodies(m)%problem, surface, friction_kind(spec%friction), &
         & spec%kappa, names, sol, error, recovered=pstar, factor=factor, multiplier=multiplier_kind(spec%multiplier))
      if (allocated(error)) return
      iterations = sol%iterations
      t_solve = sol%t_solve
      t_contact = sol%t_contact
      do it = 1, default_max_iterations
         call timer%reset()
         call timer%start()
         call slave_recovered_traction(study, spec, surface, sol, bodies, pstar, error)
         call timer%stop()
         t_contact = t_contact + timer%elapsed
         if (.not. allocated(error)) call solve_contact_pair(bodies(s)%problem, bodies(m)%problem, surface, &
            & friction_kind(spec%friction), spec%kappa, names, next, error, recovered=pstar, factor=factor, &
            & multiplier=multiplier_kind(spec%multiplier))
         if (allocated(error)) return
         iterations = iterations + next%iterations
         t_solve = t_solve + next%t_solve
         t_contact = t_contact + next%t_contact
         change = sqrt(sum(surface%weight*((next%pressure - sol%pressure)**2 + (next%tangential - sol%tangential)**2)))
         size_ = sqrt(sum(surface%weight*(next%pressure**2 + next%tangential**2)))
         if (all(next%closed .eqv. sol%closed) .and. change <= sqrt(epsilon(1.0_wp))*size_) exit
         if (it == default_max_iterations) then
            call fatal_error(error, "contact '"//trim(names(1))//"' on '"//trim(names(2))//"': the recovered "// &
               & 'stabilization did not settle in '//itoa(it)//' updates; the last moved the contact traction by '// &
               & real_text(change/max(size_, tiny(1.0_wp)))//' of its norm and switched '// &
               & itoa(count(next%closed .neqv. sol%closed))//' points (raise kappa)', stat_not_converged)
            return
         end if
         sol = next
      end do
      sol = next
      sol%iterations = iterations
      sol%t_solve = t_solve
      sol%t_contact = t_contact
   end subroutine recovered_updates

   !> The slave body's recovered traction sigma* n at every slave point
   !> (dim, npoint; zero where the point has no slave cell), in the pair's
   !> units: the slave's SPR-C recovery of the current solution `sol`, with
   !> the patch degree of the scene's SPR-C and the pair's coupled contact
   !> patches (`pair_contact` of sol's contact states, the master's FE
   !> stresses as body (2)): the field the report's p_sprc comes from, so
   !> that a settled iteration is stabilized by the recovered stress it
   !> reports. Open parts of the contact surface are free surfaces.
   subroutine slave_recovered_traction(study, spec, surface, sol, bodies, pstar, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_solution_type), intent(in) :: sol
      type(body_level_type), intent(in) :: bodies(:)
      real(wp), allocatable, intent(out) :: pstar(:, :)
      type(error_type), allocatable, intent(out) :: error
      type(recovery_input_type) :: inputs(2)
      type(contact_result_type) :: result
      type(grid_contact_type) :: contact(1)
      type(pair_edges_type) :: edges
      type(recovered_field_type) :: field
      real(wp) :: sigma(6), tn(3, 6)
      integer :: i, d, s, stat

      d = surface%dim
      s = spec%slave_index
      call contact_result(surface, sol, spec, study%bodies(s)%units, result, error)
      if (.not. allocated(error)) call fe_recovery_input(bodies(s)%problem, inputs(1), error)
      if (.not. allocated(error)) call fe_recovery_input(bodies(spec%master_index)%problem, inputs(2), error)
      if (.not. allocated(error)) call pair_edges(study, spec, surface, result, bodies(s)%problem%mesh%nodes, &
         & inputs(1), inputs(2), edges, error)
      if (.not. allocated(error)) call pair_contact(study, spec, surface, result, 1, inputs(1), &
         & bodies(s)%problem%mesh%nodes, inputs(2), contact(1), error, bodies(spec%master_index)%problem%mesh%nodes, &
         & edges)
      if (allocated(error)) return
      associate (mesh => bodies(s)%problem%mesh)
         call recover_grid(inputs(1), mesh%grid, mesh%nodes, mesh%hanging, method_sprc, study%degree(2), field, &
            & error, contacts=contact)
      end associate
      if (allocated(error)) return
      allocate (pstar(d, surface%npoint), source=0.0_wp, stat=stat)
      call check_allocation(stat, 'contact pair', 'the recovered traction of each slave point', surface%npoint, 8*d, error)
      if (allocated(error)) return
      do i = 1, surface%npoint
         if (surface%slave_cell(i) < 1 .or. .not. surface%has_master(i)) cycle
         call field_eval(field, surface%slave_cell(i), surface%x(:, i), sigma, error)
         if (allocated(error)) return
         call traction_matrix(d, surface%normal(:, i), tn(1:d, 1:bodies(s)%problem%nstress))
         pstar(:, i) = matmul(tn(1:d, 1:bodies(s)%problem%nstress), sigma(1:bodies(s)%problem%nstress))
      end do
   end subroutine slave_recovered_traction

   !> After a pair's FE solve: both bodies' exact errors, recoveries and estimates, SPR-C
   !> with each body's contact surface (`pair_contact`): the coupled contact patches of
   !> both bodies, each with the other as body (2) (sprc_estimate_contact_patches).
   subroutine finish_pair(study, spec, surface, result, bodies, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      type(body_level_type), intent(inout) :: bodies(:)
      type(error_type), allocatable, intent(out) :: error
      type(recovery_input_type) :: inputs(2)
      type(grid_contact_type) :: contacts(2)
      type(pair_edges_type) :: edges
      integer :: b, k(2)

      k = [spec%slave_index, spec%master_index]
      do b = 1, 2
         call exact_error(study, study%bodies(k(b)), bodies(k(b)), error)
         if (.not. allocated(error) .and. any(study%run)) call fe_recovery_input(bodies(k(b))%problem, inputs(b), error)
         if (allocated(error)) then
            error%message = 'body '''//study%bodies(k(b))%name//''': '//error%message
            return
         end if
      end do
      if (.not. any(study%run)) return
      call pair_edges(study, spec, surface, result, bodies(k(1))%problem%mesh%nodes, inputs(1), inputs(2), edges, &
         & error)
      if (allocated(error)) return
      do b = 1, 2
         call pair_contact(study, spec, surface, result, b, inputs(b), &
            & bodies(k(b))%problem%mesh%nodes, inputs(3 - b), contacts(b), error, bodies(k(3 - b))%problem%mesh%nodes, &
            & edges)
         if (.not. allocated(error)) &
            & call recover_body(study, study%bodies(k(b)), bodies(k(b)), inputs(b), error, contacts(b:b))
         if (allocated(error)) then
            error%message = 'body '''//study%bodies(k(b))%name//''': '//error%message
            return
         end if
      end do
   end subroutine finish_pair

   !> The contact surface of side b (1 slave, 2 master) for its recovery (sprc_estimate_contact_patches):
   !> each of the body's boundary points on its contact shape takes the state of the nearest
   !> slave point (side 2: nearest master point of a slave point) within the size of its
   !> element, else open (within the radius of a fitted contact edge: the edge's side,
   !> `contact_edges`); closed states give the law (frictionless; stick; Coulomb: stick
   !> or slip) and, for slip, the slip direction of the body relative to the other: opposed
   !> to the contact's FE tangential traction on the slave (`result%t_fe`) on the slave side,
   !> along it on the master side.
   !> The other body's volume points, FE stresses and boundary points (its contact surface
   !> left out) are `other`'s.
   subroutine pair_contact(study, spec, surface, result, side, input, nodes, other, contact, error, other_nodes, &
      & edges)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      integer, intent(in) :: side
      type(recovery_input_type), intent(in) :: input, other
      type(grid_nodes_type), intent(in) :: nodes
      type(grid_contact_type), intent(out) :: contact
      type(error_type), allocatable, intent(out) :: error
      !> The other body's nodes: with them its fit weighs by the cells' sizes (the grid contact's
      !> fe_order and cell, sprc_estimate_contact_patches).
      type(grid_nodes_type), intent(in), optional :: other_nodes
      !> The pair's contact edges (`pair_edges`): points within an edge's radius take its side.
      type(pair_edges_type), intent(in), optional :: edges
      integer, allocatable :: law(:)
      real(wp), allocatable :: slip(:, :), offset(:, :), ratio(:), cell(:)
      real(wp) :: t(3), size_e, dist, best
      type(patch_type) :: oboundary
      type(point_cells_type) :: cells
      logical :: edged
      real(wp), allocatable :: sx(:, :)
      integer, allocatable :: near(:), sel(:)
      integer, allocatable :: surfaces(:), osurfaces(:)
      integer :: nb, e, k, i, j, inear, mnear, d, o, nnear, stat
      logical :: closed

      d = study%dim
      nb = size(input%bw)
      o = merge(spec%master_index, spec%slave_index, side == 1)
      if (side == 1) then
         surfaces = study%bodies(spec%slave_index)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%slave_surface_index, spec%slave_group))
         osurfaces = study%bodies(o)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%master_surface_index, spec%master_group))
      else
         surfaces = study%bodies(spec%master_index)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%master_surface_index, spec%master_group))
         osurfaces = study%bodies(o)%geometry%surface_parts( &
            & scene_surface(study%scene, spec%slave_surface_index, spec%slave_group))
      end if
      allocate (law(nb), slip(d, nb), offset(d, nb), ratio(nb), stat=stat)
      call check_allocation(stat, 'pair_contact', 'the contact law of each boundary point', nb, 12 + 16*d, error)
      if (allocated(error)) return
      law = 0
      slip = 0.0_wp
      offset = 0.0_wp
      ratio = 1.0_wp
      ! This side's points of the slave points (on the master side those with a master point), in cells.
      if (side == 1) then
         sel = [(i, i=1, surface%npoint)]
         sx = surface%x
      else
         sel = pack([(i, i=1, surface%npoint)], surface%has_master)
         sx = surface%master_x(:, sel)
      end if
      call new_point_cells(cells, sx, error)
      if (allocated(error)) return
      edged = .false.
      if (present(edges)) edged = allocated(edges%edges)
      do e = 1, nodes%n_elements
         if (input%belem_ptr(e + 1) == input%belem_ptr(e)) cycle
         size_e = element_size(nodes, e)
         do k = input%belem_ptr(e), input%belem_ptr(e + 1) - 1
            if (.not. any(surfaces == input%bshape(k))) cycle
            best = huge(1.0_wp)
            inear = 0
            mnear = 0
            call cells_box(cells, sx, input%bx(:, k) - size_e, input%bx(:, k) + size_e, near, nnear)
            do j = 1, nnear
               i = sel(near(j))
               dist = norm2(sx(:, near(j)) - input%bx(:, k))
               if (dist < best .or. (dist == best .and. i < inear)) then
                  best = dist
                  inear = i
                  mnear = near(j)
               end if
            end do
            if (inear == 0 .or. best > size_e) cycle
            closed = result%state(inear) /= contact_open
            ! Near a fitted contact edge its side decides (module notes of contact_edges).
            if (edged) then
               if (surface%has_master(inear)) call edge_side(edges%edges, input%bx(1:2, k), closed)
            end if
            if (.not. closed) cycle
            if (surface%has_master(inear)) call paired_point(surface, side, inear, mnear, sx, sel, near(1:nnear), &
               & input%bn(:, k), offset(:, k), ratio(k))
            select case (friction_kind(spec%friction))
            case (friction_frictionless)
               law(k) = contact_law_frictionless
            case (friction_coulomb)
               law(k) = merge(contact_law_slip, contact_law_stick, result%state(inear) == contact_slip)
            case default
               law(k) = contact_law_stick
            end select
            if (law(k) /= contact_law_slip) cycle
            ! The direction of the contact's own tangential traction at the slave point (the
            ! multiplier, of magnitude mu p_fe on a slipping point), not that of the slave's FE
            ! stress there: near the edge of the contact zone the stress of a cut cell gave a
            ! tangential traction of the wrong sign (Cattaneo-Mindlin).
            t(1:d) = result%t_fe(:, inear)
            ! No tangential traction to give a direction: then mu p ~ 0, and stick is safe.
            if (.not. (norm2(t(1:d)) > sqrt(epsilon(1.0_wp))*abs(result%p_fe(inear)))) then
               law(k) = contact_law_stick
            else
               slip(:, k) = merge(-1.0_wp, 1.0_wp, side == 1)*t(1:d)
            end if
         end do
      end do
      if (allocated(study%bodies(o)%exact)) then
         call boundary_points(other, d, osurfaces, oboundary, study%bodies(o)%exact)
      else
         call boundary_points(other, d, osurfaces, oboundary)
      end if
      if (.not. present(other_nodes)) then
         call new_grid_contact(contact, surfaces, law, slip, spec%mu, other%x, other%w, other%stress, other%young, &
            & other%poisson, other%body_force(1:d), error, boundary=oboundary, offset=offset, ratio=ratio)
         return
      end if
      allocate (cell(size(other%w)), stat=stat)
      call check_allocation(stat, 'pair_contact', 'the cell size of each of the other body''s points', size(other%w), &
         & 8, error)
      if (allocated(error)) return
      do e = 1, other_nodes%n_elements
         cell(other%elem_ptr(e):other%elem_ptr(e + 1) - 1) = element_size(other_nodes, e)
      end do
      call new_grid_contact(contact, surfaces, law, slip, spec%mu, other%x, other%w, other%stress, other%young, &
         & other%poisson, other%body_force(1:d), error, boundary=oboundary, offset=offset, ratio=ratio, &
         & fe_order=study%order, cell=cell)
      if (allocated(error) .or. .not. edged) return
      call set_grid_contact_edges(contact, edges%edges, merge(1.0_wp, -1.0_wp, side == 1), error)
   end subroutine pair_contact

   !> The contact edges of a pair (`contact_edges`) for both sides' `pair_contact`: 2D
   !> frictionless pairs with `edges` on only (set%edges not allocated otherwise).
   subroutine pair_edges(study, spec, surface, result, slave_nodes, slave, master, set, error)
      type(study_type), intent(in) :: study
      type(contact_spec_type), intent(in) :: spec
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      type(grid_nodes_type), intent(in) :: slave_nodes
      type(recovery_input_type), intent(in) :: slave, master
      type(pair_edges_type), intent(out) :: set
      type(error_type), allocatable, intent(out) :: error
      if (study%dim /= 2 .or. friction_kind(spec%friction) /= friction_frictionless .or. .not. spec%edges) return
      call contact_edges(surface, result, study%bodies(spec%slave_index)%units%strain, slave_nodes, slave, master, &
         & set%edges, error)
   end subroutine pair_edges

   !> The edges of a 2D frictionless contact zone (sprc_recovery_contact_edge_fit) from the
   !> slave points' states: a closed slave point and an open one that meets the master surface,
   !> each the other's nearest point of the other state within the size of the closed point's
   !> cell. The edge's vertex is their midpoint, its tangent points from the closed to the open
   !> one, its normal is the closed point's and its length the size of that cell (a facet of
   !> the caller's meshes: the fit's radius is fit_facets lengths). Point and amplitude come
   !> from the FE gaps of the open slave points beyond it (fit_edge_gap, gap_amplitude) where
   !> that fit is kept, else from both bodies' FE stresses (slave, master); the stress fit
   !> decides whether the edge is kept (its amplitude 0 otherwise). The states place the edge within a
   !> contact cell only, and the stresses next to it carry that error; the gaps a few cells
   !> beyond do not. Within an edge's radius the edge's side, not the point's state, then makes
   !> a boundary point closed or open in the patches (`pair_contact`): the patches' contact and
   !> free-surface rows agree with the edge field (which is traction-free on the open side).
   subroutine contact_edges(surface, result, strain, slave_nodes, slave, master, edges, error)
      type(contact_surface_type), intent(in) :: surface
      type(contact_result_type), intent(in) :: result
      !> The pair's displacement unit: result%gap/strain is in the bodies' units.
      real(wp), intent(in) :: strain
      type(grid_nodes_type), intent(in) :: slave_nodes
      type(recovery_input_type), intent(in) :: slave, master
      type(contact_edge_type), allocatable, intent(out) :: edges(:)
      type(error_type), allocatable, intent(out) :: error
      type(contact_edge_type), allocatable :: buf(:)
      type(point_cells_type) :: cells
      logical, allocatable :: closed(:), open_(:)
      real(wp), allocatable :: xo(:, :), go(:)
      real(wp) :: h, s, c, range(2)
      logical :: ok
      integer :: i, j, m, n

      n = surface%npoint
      allocate (edges(0))
      if (size(surface%slave_cell) < n .or. n == 0) return
      closed = result%state /= contact_open
      open_ = .not. closed .and. surface%has_master
      if (.not. (any(closed) .and. any(open_))) return
      xo = reshape(pack(surface%x(1:2, :), spread(open_, 1, 2)), [2, count(open_)])
      go = pack(result%gap, open_)/strain
      call new_point_cells(cells, surface%x, error)
      if (allocated(error)) return
      allocate (buf(n))
      m = 0
      do i = 1, n
         if (.not. closed(i) .or. surface%slave_cell(i) < 1) cycle
         h = element_size(slave_nodes, surface%slave_cell(i))
         j = nearest(i, open_, h)
         if (j == 0) cycle
         if (nearest(j, closed, h) /= i) cycle
         m = m + 1
         buf(m)%vertex = 0.5_wp*(surface%x(1:2, i) + surface%x(1:2, j))
         buf(m)%point = buf(m)%vertex
         buf(m)%tangent = (surface%x(1:2, j) - surface%x(1:2, i))/norm2(surface%x(1:2, j) - surface%x(1:2, i))
         buf(m)%normal = surface%normal(1:2, i)
         buf(m)%length = h
         buf(m)%radius = fit_facets*h
         call fit_edge_gap(buf(m), xo, go, edge_range, s, c, ok)
         if (.not. ok) range = edge_range
         if (ok) range = [s, s]
         call fit_contact_edge(buf(m), slave%x, slave%w, slave%stress(1:3, :), master%x, master%w, &
            & master%stress(1:3, :), range)
         if (ok .and. buf(m)%amplitude > 0.0_wp) buf(m)%amplitude = gap_amplitude(c, [slave%young, master%young], &
            & [slave%poisson, master%poisson], slave%analysis == plane_stress)
      end do
      edges = buf(1:m)
   contains
      !> The nearest point to point k within distance r among those of mask (0: none; ties to
      !> the lower index).
      integer function nearest(k, mask, r) result(best)
         integer, intent(in) :: k
         logical, intent(in) :: mask(:)
         real(wp), intent(in) :: r
         integer, allocatable :: near(:)
         real(wp) :: dist, dbest
         integer :: q, nnear

         best = 0
         dbest = r
         call cells_box(cells, surface%x, surface%x(:, k) - r, surface%x(:, k) + r, near, nnear)
         do q = 1, nnear
            if (.not. mask(near(q)) .or. near(q) == k) cycle
            dist = norm2(surface%x(:, near(q)) - surface%x(:, k))
            if (dist < dbest .or. (dist == dbest .and. near(q) < best)) then
               dbest = dist
               best = near(q)
            end if
         end do
      end function nearest
   end subroutine contact_edges

   !> Whether the boundary point x lies on the closed side of the nearest edge of nonzero
   !> amplitude within the edge's radius (xi = (x - x_e).t <= 0); `closed` unchanged where
   !> no such edge is near.
   pure subroutine edge_side(edges, x, closed)
      type(contact_edge_type), intent(in) :: edges(:)
      real(wp), intent(in) :: x(2)
      logical, intent(inout) :: closed
      real(wp) :: dist, best
      integer :: e, near

      near = 0
      best = huge(1.0_wp)
      do e = 1, size(edges)
         if (edges(e)%amplitude == 0.0_wp) cycle
         dist = norm2(x - edges(e)%point)
         if (dist < edges(e)%radius .and. dist < best) then
            best = dist
            near = e
         end if
      end do
      if (near > 0) closed = dot_product(x - edges(near)%point, edges(near)%tangent) <= 0.0_wp
   end subroutine edge_side

   !> The other body's point paired with a boundary point of normal bn near slave point i, as
   !> the FE contact pairs them (sprc_contact_surface): the slave point and its master point
   !> x_m = x_s + g n_s, g = (x_m - x_s).n_s (negative for an interference). The boundary
   !> point's partner is offset = g bn on either side (bn = n_s on the slave, -n_s on the
   !> master), and ratio = dA_other/dA_own, with dA_m/dA_s = (1 + g div_s n_s)/|n_s.n_m|
   !> (a surface moved by g along its normal changes its measure by 1 + g div_s n, to first
   !> order in g; the projection onto a master surface of normal n_m divides by the cosine):
   !> the FE multiplier's force w_s p_s is the master's traction over the projected measure.
   !> div_s n_s is the least-squares slope of the normal along the surface over the slave
   !> points near(:) (indices of sx, slave point sel(near(j))): (dim - 1) sum dn.dx / sum
   !> |dx|^2, exact on a circle or sphere; 0 with no neighbour.
   pure subroutine paired_point(surface, side, i, m, sx, sel, near, bn, offset, ratio)
      type(contact_surface_type), intent(in) :: surface
      !> i: the slave point; m: its index in sx (sx(:, m) its point on this side).
      integer, intent(in) :: side, i, m, sel(:), near(:)
      real(wp), intent(in) :: sx(:, :), bn(:)
      real(wp), intent(out) :: offset(:), ratio
      real(wp) :: g, num, den, dx(3), curv, scale, cosn
      integer :: j, d

      d = surface%dim
      g = dot_product(surface%master_x(1:d, i) - surface%x(1:d, i), surface%normal(1:d, i))
      num = 0.0_wp
      den = 0.0_wp
      do j = 1, size(near)
         if (sel(near(j)) == i) cycle
         dx(1:d) = sx(1:d, near(j)) - sx(1:d, m)
         num = num + dot_product(surface%normal(1:d, sel(near(j))) - surface%normal(1:d, i), dx(1:d))
         den = den + sum(dx(1:d)**2)
      end do
      curv = 0.0_wp
      if (den > 0.0_wp) curv = (d - 1)*num/den
      cosn = abs(dot_product(surface%normal(1:d, i), surface%master_normal(1:d, i)))
      scale = 1.0_wp + g*curv
      offset(1:d) = g*bn(1:d)
      ratio = 1.0_wp
      ! A partner too far off for the first-order measure (beyond any closed contact): as before.
      if (.not. (scale > 0.5_wp .and. cosn > 0.5_wp)) then
         offset(1:d) = 0.0_wp
         return
      end if
      ratio = merge(scale/cosn, cosn/scale, side == 1)
   end subroutine paired_point

   !> The largest edge of element e's box.
   pure real(wp) function element_size(nodes, e)
      type(grid_nodes_type), intent(in) :: nodes
      integer, intent(in) :: e
      integer :: nv

      nv = 2**nodes%dim
      element_size = maxval(maxval(nodes%x(:, nodes%connectivity(1:nv, e)), dim=2) - &
         & minval(nodes%x(:, nodes%connectivity(1:nv, e)), dim=2))
   end function element_size

   !> p_fe_stress, p_spr, p_sprc and ts_sprc of a contact result (scene units) from the slave
   !> body's FE stresses and recovered fields (SPR, SPR-C where run) at its slave points:
   !> p = max(-n.sigma.n, 0), ts = |sigma n - (n.sigma n) n| (sprc_recovery_contact_operators):
   !> a contact carries no tension, so a tensile normal stress (an open point, or a stress that
   !> overshoots past the edge of the contact zone) is a contact pressure of 0, for the FE
   !> stresses as for the recovered ones.
   !> SPR-C's field there comes from the coupled contact patches (`finish_pair`).
   subroutine recovered_tractions(surface, bl, run, units, result, error)
      type(contact_surface_type), intent(in) :: surface
      type(body_level_type), intent(in) :: bl
      logical, intent(in) :: run(2)
      type(analysis_units_type), intent(in) :: units
      type(contact_result_type), intent(inout) :: result
      type(error_type), allocatable, intent(out) :: error
      real(wp) :: sigma(6), p, ts, unit
      integer :: i, m, d

      d = surface%dim
      unit = units%modulus*units%strain
      if (size(surface%slave_cell) < surface%npoint) return
      do m = 0, 2
         if (m > 0) then
            if (.not. run(m)) cycle
         end if
         do i = 1, surface%npoint
            if (surface%slave_cell(i) < 1) cycle
            if (m == 0) then
               call bl%problem%stress_in_element(surface%slave_cell(i), surface%x(:, i), sigma(1:merge(3, 6, d == 2)))
            else
               call field_eval(bl%field(m), surface%slave_cell(i), surface%x(:, i), sigma, error)
               if (allocated(error)) return
            end if
            call contact_traction(d, surface%normal(:, i), sigma, p, ts)
            p = max(p, 0.0_wp)
            select case (m)
            case (0)
               result%p_fe_stress(i) = p*unit
            case (1)
               result%p_spr(i) = p*unit
            case default
               result%p_sprc(i) = p*unit
               result%ts_sprc(i) = ts*unit
            end select
         end do
      end do
   end subroutine recovered_tractions

   !> The contact result of a pair in scene units (pressures times the stress
   !> unit, gaps times the displacement unit).
   subroutine contact_result(surface, sol, spec, units, result, error)
      type(contact_surface_type), intent(in) :: surface
      type(contact_solution_type), intent(in) :: sol
      type(contact_spec_type), intent(in) :: spec
      type(analysis_units_type), intent(in) :: units
      type(contact_result_type), intent(out) :: result
      type(error_type), allocatable, intent(out) :: error
      integer :: closed_state

      call new_contact_result(result, surface%x, surface%weight, surface%normal, spec%slave_index, spec%master_index, &
         & error)
      if (allocated(error)) return
      closed_state = merge(contact_slip, contact_stick, friction_kind(spec%friction) == friction_frictionless)
      where (surface%has_master) result%gap = sol%gap*units%strain
      result%state = merge(closed_state, contact_open, sol%closed)
      where (sol%slipping) result%state = contact_slip
      result%p_fe = (sol%pressure*units%modulus)*units%strain
      result%ts_fe = (sol%tangential*units%modulus)*units%strain
      result%t_fe = (sol%traction_t*units%modulus)*units%strain
      result%iterations = sol%iterations
      result%warning = ''
      if (allocated(sol%warning)) result%warning = sol%warning
   end subroutine contact_result

end module sprc_study_run_contact_recovery
