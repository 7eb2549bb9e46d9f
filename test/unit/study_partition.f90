!> Tests of a level shared out among ranks (`sprc_study_partition`), with the
!> ranks simulated in one process: what each rank computes of its share must
!> be, bit for bit, what the serial run computes there. The gathers that join
!> the shares are MPI's (tools/test-driver runs `mpirun -n 2`).
module sprc_test_partition
   use sprc_core_kinds, only: wp, i8
   use sprc_core_error, only: error_type
   use sprc_core_text, only: itoa
   use sprc_study_spec, only: scene_type
   use sprc_io_scene, only: read_scene_text
   use sprc_study_level, only: study_type, prepare_study
   use sprc_study_partition, only: owned_rows, cut_cell_work
   use sprc_grid_share, only: split_by_work
   use sprc_geometry_region, only: cell_inside
   use sprc_grid_cut_mesh, only: cut_mesh_type
   use sprc_grid_quadrature, only: cut_quadrature_type, new_cut_quadrature
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_fem_sparse, only: csr_type
   use sprc_test_study, only: two_body_scene
   use sprc_testsuite, only: unittest_type, new_unittest, check, replaced
   implicit none
   private

   public :: collect_partition

contains

   subroutine collect_partition(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest('split_by_work', test_split), &
         new_unittest('quadrature_shares', test_quadrature), &
         new_unittest('owned_rows_serial_bits', test_rows), &
         new_unittest('owned_rows_serial_bits_projected', test_rows_projected) &
         ]
   end subroutine collect_partition

   !> Hand-computed ranges: equal work splits in the middle; a heavy first
   !> item takes a rank alone; more ranks than items leave ranks empty.
   subroutine test_split(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, all(split_by_work([1, 1, 1, 1], 2) == [1, 3, 5]), 'four equal items on two ranks')
      if (allocated(error)) return
      call check(error, all(split_by_work([20, 1, 1, 1, 1], 2) == [1, 2, 6]), 'a cut cell first')
      if (allocated(error)) return
      call check(error, all(split_by_work([1, 1, 1, 1, 1, 1], 3) == [1, 3, 5, 7]), 'six items on three ranks')
      if (allocated(error)) return
      call check(error, all(split_by_work([1], 3) == [1, 1, 2, 2]), 'one item on three ranks: the middle one')
   end subroutine test_split

   !> The cut Lame cylinder with one extra level at the boundary (hanging
   !> nodes; small cut cells aggregated), its mesh built and integrated (the
   !> leaves `cells` only, if given).
   subroutine cylinder_mesh(dilatation, study, mesh, quad, error, cells)
      character(len=*), intent(in) :: dilatation
      type(study_type), intent(out) :: study
      type(cut_mesh_type), allocatable, intent(out) :: mesh
      type(cut_quadrature_type), intent(out) :: quad
      type(error_type), allocatable, intent(out) :: error
      integer, intent(in), optional :: cells(2)
      type(scene_type) :: scene

      call read_scene_text(replaced(two_body_scene(.true., .false., '3'), "output=''", &
         & "output='' refine_boundary=1 dilatation='"//dilatation//"'"), 'cylinder', scene, error)
      if (allocated(error)) return
      call prepare_study(scene, 0, study, error)
      if (allocated(error)) return
      allocate (mesh)
      associate (sb => study%bodies(1))
         call mesh%build(sb%geometry, sb%box_min, sb%box_size, 3, study%refine_boundary, study%order, error)
      end associate
      if (allocated(error)) return
      call new_cut_quadrature(quad, study%dim, study%points, error)
      if (.not. allocated(error)) call mesh%integrate(quad, error, cells)
   end subroutine cylinder_mesh

   !> Each rank's range of leaves (split_by_work) integrated alone gives the
   !> serial points of those leaves, bit for bit, and the ranges cover the leaves.
   subroutine test_quadrature(error)
      type(error_type), allocatable, intent(out) :: error
      type(study_type) :: study
      type(cut_mesh_type), allocatable :: whole, part
      type(cut_quadrature_type) :: quad
      integer, allocatable :: first(:)
      integer :: r, lo, hi

      call cylinder_mesh('auto', study, whole, quad, error)
      if (allocated(error)) return
      first = split_by_work(merge(1, cut_cell_work, whole%grid%leaf_class == cell_inside), 3)
      call check(error, first(1) == 1 .and. first(4) == whole%grid%n_leaves + 1 .and. all(first(2:) >= first(:3)), &
         & 'the ranges cover the leaves')
      if (allocated(error)) return
      do r = 1, 3
         lo = first(r)
         hi = first(r + 1) - 1
         call cylinder_mesh('auto', study, part, quad, error, [lo, hi])
         if (allocated(error)) return
         associate (v0 => whole%vol_ptr(lo), v1 => whole%vol_ptr(hi + 1) - 1, s0 => whole%surf_ptr(lo), &
            & s1 => whole%surf_ptr(hi + 1) - 1, p0 => part%vol_ptr(lo), q0 => part%surf_ptr(lo))
            call check(error, all(part%vol_ptr(lo:hi + 1) - p0 == whole%vol_ptr(lo:hi + 1) - v0) .and. &
               & all(part%surf_ptr(lo:hi + 1) - q0 == whole%surf_ptr(lo:hi + 1) - s0), &
               & 'rank '//itoa(r - 1)//': point counts')
            if (allocated(error)) return
            call check(error, same_bits(flat(part%vol_x(:, p0:p0 + v1 - v0)), flat(whole%vol_x(:, v0:v1))) .and. &
               & same_bits(part%vol_w(p0:p0 + v1 - v0), whole%vol_w(v0:v1)) .and. &
               & same_bits(flat(part%surf_x(:, q0:q0 + s1 - s0)), flat(whole%surf_x(:, s0:s1))) .and. &
               & same_bits(flat(part%surf_n(:, q0:q0 + s1 - s0)), flat(whole%surf_n(:, s0:s1))) .and. &
               & same_bits(part%fraction(lo:hi), whole%fraction(lo:hi)), 'rank '//itoa(r - 1)//': points')
         end associate
         if (allocated(error)) return
      end do
   end subroutine test_quadrature

   subroutine test_rows(error)
      type(error_type), allocatable, intent(out) :: error
      call check_rows('auto', error)
   end subroutine test_rows

   !> With the projected dilatation the aggregates' blocks couple their
   !> members' dofs as well.
   subroutine test_rows_projected(error)
      type(error_type), allocatable, intent(out) :: error
      call check_rows('projected', error)
   end subroutine test_rows_projected

   !> Each simulated rank of 2 and 3 assembles its rows (owned_rows): they are
   !> the serial K's and f's rows, bit for bit (same blocks summed in the same
   !> order: a ghost element missed, or reached without the hanging-node and
   !> aggregation constraints, changes some row), and the ranks' rows tile 1..n.
   subroutine check_rows(dilatation, error)
      character(len=*), intent(in) :: dilatation
      type(error_type), allocatable, intent(out) :: error
      type(study_type) :: study
      type(cut_mesh_type), allocatable :: mesh
      type(cut_quadrature_type) :: quad
      type(elasticity_problem_type) :: problem
      type(csr_type) :: k
      real(wp), allocatable :: f(:)
      integer :: ranks, r, rows(2), next
      character(len=:), allocatable :: who

      call cylinder_mesh(dilatation, study, mesh, quad, error)
      if (allocated(error)) return
      associate (sb => study%bodies(1))
         call problem%setup(mesh, study%analysis, sb%young, sb%poisson, sb%body_force, sb%bcs, error, &
            & gamma=study%gamma, dilatation=study%dilatation)
      end associate
      if (allocated(error)) return
      call check(error, problem%dilatation%active .eqv. dilatation == 'projected' .and. problem%n_aggregated > 0 &
         & .and. problem%constraints%n_masters < problem%mesh%nodes%n_nodes, &
         & 'the scene has aggregated cells and hanging nodes (and the projected dilatation when asked)')
      if (allocated(error)) return
      call problem%assemble(error)
      if (allocated(error)) return
      k = problem%k
      f = problem%f
      do ranks = 2, 3
         next = 1
         do r = 0, ranks - 1
            who = 'rank '//itoa(r)//' of '//itoa(ranks)//': '
            rows = owned_rows(problem%constraints%dof, r, ranks)
            call check(error, rows(1) == next .and. rows(2) >= rows(1), who//'rows follow on')
            if (allocated(error)) return
            next = rows(2) + 1
            call problem%assemble(error, rows)
            if (allocated(error)) return
            associate (p => problem%k, a => k%rowptr(rows(1)), b => k%rowptr(rows(2) + 1) - 1)
               call check(error, all(p%rowptr(rows(1):rows(2) + 1) - p%rowptr(rows(1)) == &
                  & k%rowptr(rows(1):rows(2) + 1) - a), who//'row lengths')
               if (allocated(error)) return
               call check(error, all(p%col(p%rowptr(rows(1)):p%rowptr(rows(2) + 1) - 1) == k%col(a:b)) .and. &
                  & same_bits(p%val(p%rowptr(rows(1)):p%rowptr(rows(2) + 1) - 1), k%val(a:b)), who//'K entries')
               if (allocated(error)) return
               call check(error, same_bits(problem%f(rows(1):rows(2)), f(rows(1):rows(2))), who//'f entries')
               if (allocated(error)) return
            end associate
         end do
         call check(error, next == k%nrows + 1, 'the rows of '//itoa(ranks)//' ranks end at n')
         if (allocated(error)) return
      end do
   end subroutine check_rows

   !> Whether a and b hold the same bits (an equal value of another sign or
   !> NaN payload differs).
   pure logical function same_bits(a, b)
      real(wp), intent(in) :: a(:), b(:)
      same_bits = size(a) == size(b) .and. all(transfer(a, 1_i8, size(a)) == transfer(b, 1_i8, size(b)))
   end function same_bits

   pure function flat(a) result(v)
      real(wp), intent(in) :: a(:, :)
      real(wp) :: v(size(a))
      v = reshape(a, [size(a)])
   end function flat

end module sprc_test_partition
