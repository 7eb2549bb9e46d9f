!> The types of a study and of one of its levels (`sprc_study_level`): what
!> every level shares of the scene and of each body (`study_type`,
!> `study_body_type`), where an adapted mesh comes from (`mesh_source_type`),
!> and one level's results per body and per contact pair (`level_type`,
!> `body_level_type`). Apart so every stage runner can use them.
module sprc_study_level_types
   use sprc_core_kinds, only: wp
   use sprc_geometry_body, only: body_type
   use sprc_exact_solution, only: exact_solution_type
   use sprc_grid_tree, only: grid_type
   use sprc_estimate_recovered_field, only: recovered_field_type
   use sprc_estimate_norms, only: zz_estimate_type
   use sprc_fem_bc, only: fe_bc_type
   use sprc_fem_problem, only: elasticity_problem_type
   use sprc_study_spec, only: scene_type
   use sprc_study_model, only: analysis_units_type
   use sprc_study_partition, only: partition_type
   use sprc_study_row, only: report_row_type
   use sprc_contact_result, only: contact_result_type
   implicit none
   private

   public :: study_body_type, mesh_source_type, study_type, body_level_type, level_type

   !> What every level needs of one body, built once from the scene.
   type :: study_body_type
      character(len=:), allocatable :: name
      type(body_type) :: geometry
      !> The exact solution with this body's material (not allocated without `&exact`).
      class(exact_solution_type), allocatable :: exact
      !> FE conditions on the body's own shape indices.
      type(fe_bc_type), allocatable :: bcs(:)
      !> The body's analysis runs in these units (`sprc_study_model`): scaled
      !> modulus, body force, conditions and exact solution.
      type(analysis_units_type) :: units
      real(wp) :: young = 0.0_wp, poisson = 0.0_wp
      real(wp), allocatable :: body_force(:)
      !> The level-0 cell of the body's grid.
      real(wp), allocatable :: box_min(:)
      real(wp) :: box_size = 0.0_wp
   end type study_body_type

   !> Where an adapted mesh of one body comes from (`run_level`'s `source`):
   !> the grid of the body's previous mesh and the level wanted for each of its
   !> leaves (sprc_grid_adapt), at most `max_level`; `dofs`, the dofs predicted
   !> for the new mesh (its memory estimate).
   type :: mesh_source_type
      type(grid_type) :: old
      integer, allocatable :: levels(:)
      integer :: max_level = 0
      real(wp) :: dofs = 0.0_wp
   end type mesh_source_type

   !> A prepared study: its bodies and the settings every level shares.
   type :: study_type
      !> The scene (for the memory estimate of a level).
      type(scene_type) :: scene
      type(study_body_type), allocatable :: bodies(:)
      integer :: dim = 0, order = 0, analysis = 0, refine_boundary = 0
      !> Gauss points per direction of the cut-cell rules; patch polynomial degree.
      integer :: points = 0, degree(2) = 0
      !> Nitsche penalty factor (the scene's `nitsche_gamma`) and volumetric formulation
      !> (`sprc_fem_dilatation`'s choice for the scene's `dilatation`).
      real(wp) :: gamma = 0.0_wp
      integer :: dilatation = 0
      !> Recoveries to run (1 SPR, 2 SPR-C) and whether the scene has an exact solution.
      logical :: run(2) = .false.
      logical :: have_exact = .false.
      !> The MPI ranks a level is shared out among (`sprc_study_partition`; one in a serial run).
      type(partition_type) :: partition
   end type study_type

   !> One body at one level. Its cut mesh (grid, nodes, hanging-node
   !> constraints, cell rules) is `problem%mesh`.
   type :: body_level_type
      type(elasticity_problem_type) :: problem
      !> Recovered fields and estimates per method (1 SPR, 2 SPR-C), where run.
      type(recovered_field_type) :: field(2)
      type(zz_estimate_type) :: est(2)
      !> With an exact solution: ||sigma_ex - sigma_h||_E, ||sigma_ex||_E and the
      !> error per element (energy norm) of the FE stress.
      real(wp) :: err_norm = 0.0_wp, norm_exact = 0.0_wp
      real(wp), allocatable :: element_error(:)
      !> Factor taking this body's squared energy norms to those of the first
      !> body's units (a power of two; 1 for the first body), for the sums.
      real(wp) :: norm2_scale = 1.0_wp
   end type body_level_type

   !> One level of a study: every body's results and the report row.
   type :: level_type
      integer :: level = 0
      !> Which recoveries ran (1 SPR, 2 SPR-C).
      logical :: done(2) = .false.
      type(body_level_type), allocatable :: bodies(:)
      !> One result per `&contact` pair (not allocated without `&contact`).
      type(contact_result_type), allocatable :: contacts(:)
      !> Per pair (columns) the jump of the normal traction between the two bodies over the
      !> closed slave points with a master point, relative (`traction_jump`): rows FE, SPR,
      !> SPR-C (negative where the recovery did not run).
      real(wp), allocatable :: traction_jump(:, :)
      type(report_row_type) :: row
   end type level_type

end module sprc_study_level_types
