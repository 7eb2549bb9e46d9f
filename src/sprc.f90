!> The one stable Fortran API of sprc. `use sprc` gives the public types and
!> procedures of every layer; the layer modules (sprc_<layer>_<x>) stay
!> available for finer-grained use, but only what is re-exported here is
!> promised to stay source-compatible between minor versions.
module sprc
   use sprc_core_kinds, only: wp, dp, i4, i8
   use sprc_core_error, only: error_type, fatal_error, stat_name, stat_success, stat_invalid_input, &
      & stat_singular, stat_not_positive_definite, stat_not_converged, stat_io, stat_out_of_memory, &
      & stat_unsupported, stat_internal
   use sprc_core_timer, only: timer_type, wall_time
   use sprc_core_material, only: plane_stress, plane_strain, solid, voigt_size, material_matrix, &
      & compliance_matrix
   use sprc_core_poly, only: poly_basis_type, new_poly_basis, scale_point, scale_points
   use sprc_exact_solution, only: exact_solution_type
   use sprc_exact_lame, only: lame_cylinder_type, lame_sphere_type, new_lame_cylinder, new_lame_sphere
   use sprc_exact_kirsch, only: kirsch_type, new_kirsch
   use sprc_exact_uniform, only: uniform_type, new_uniform
   use sprc_exact_compound, only: compound_type, new_compound_cylinder, new_compound_sphere
   use sprc_exact_pressure, only: exact_pressure_type, field_pressure_type, new_field_pressure
   use sprc_exact_hertz, only: hertz_type, new_hertz_cylinder, new_hertz_sphere
   use sprc_exact_corner, only: corner_type, new_corner, corner_eigenvalues
   use sprc_geometry_region, only: region_type, cell_outside, cell_inside, cell_cut
   use sprc_geometry_shape, only: geometry_shape_type => shape_type
   use sprc_geometry_body, only: geometry_body_type => body_type, new_body
   use sprc_io_scene, only: scene_type, read_scene, read_scene_text, scene_summary, default_scene_text
   use sprc_study_model, only: build_bodies, build_exact, body_conditions
   use sprc_recovery_caller_mesh, only: mesh_recovery_type, recover_on_mesh, mesh_recovery_eval, mesh_method_spr, &
      & mesh_method_sprc, facet_traction, facet_symmetry, facet_free, facet_pressure, elem_tri3, elem_quad4, &
      & elem_tet4, elem_hex8, elem_quad9, elem_hex27, mesh_reference_unit, mesh_reference_symmetric
   use sprc_contact_caller_mesh_recovery, only: contact_body_type, contact_pair_type, mesh_contact_recovery_type, &
      & contact_pair_recovery_type, recover_contact_on_mesh, contact_open, contact_law_frictionless, contact_law_slip, &
      & contact_law_stick
   use sprc_study_mesh_table, only: mesh_row_type, mesh_study, study_levels
   use sprc_study_level, only: study_type, study_body_type, prepare_study, run_level, level_type, body_level_type
   use sprc_io_fields, only: write_level_fields
   use sprc_io_report, only: report_row_type, report_table, write_report_csv, read_report_csv, report_column, &
      & report_empty, is_empty, report_columns, format_mesh_row
   use sprc_io_svg, only: write_report_svg
   use sprc_version, only: sprc_version_string, sprc_version_number, get_sprc_version
   implicit none
   public
end module sprc
