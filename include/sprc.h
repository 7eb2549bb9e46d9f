/* sprc — C interface.
 *
 * Conventions
 * - Objects are opaque handles. sprc_new_* and sprc_run_* return NULL on
 *   failure; sprc_delete_*(&h) frees h, sets it to NULL, and accepts NULL
 *   (both a NULL h and a NULL &h).
 * - Every call that can fail takes an error handle first. On failure it
 *   stores a status and a message there (replacing any earlier error) and
 *   returns its failure value: NULL, -1 or NaN as documented. A successful
 *   call leaves the error handle as it was: clear it with sprc_clear_error
 *   before a call if you test it afterwards. With a NULL error handle a call
 *   does nothing and returns its failure value (there is nowhere to report);
 *   any other NULL handle or pointer is reported as an error, never a crash.
 * - Scalars are passed by value, arrays as pointers with explicit lengths;
 *   truth values are int; row and column indices are 0-based.
 * - The library never prints and never stops the program.
 */
#ifndef SPRC_H
#define SPRC_H

#ifdef __cplusplus
extern "C" {
#endif

#define SPRC_VERSION_MAJOR 0
#define SPRC_VERSION_MINOR 1
#define SPRC_VERSION_PATCH 0
/* 10000*major + 100*minor + patch, as sprc_get_version() returns */
#define SPRC_VERSION (10000 * SPRC_VERSION_MAJOR + 100 * SPRC_VERSION_MINOR + SPRC_VERSION_PATCH)

/* Status codes of sprc_get_error_status (never renumbered). */
#define SPRC_STAT_SUCCESS 0
#define SPRC_STAT_INVALID_INPUT 1
#define SPRC_STAT_SINGULAR 2
#define SPRC_STAT_NOT_POSITIVE_DEFINITE 3
#define SPRC_STAT_NOT_CONVERGED 4
#define SPRC_STAT_IO 5
#define SPRC_STAT_OUT_OF_MEMORY 6
#define SPRC_STAT_UNSUPPORTED 7
#define SPRC_STAT_INTERNAL 8

/* The version of the library linked: 10000*major + 100*minor + patch. */
int sprc_get_version(void);

/* ---------------------------------------------------------------- errors */

typedef struct _sprc_error *sprc_error;

/* A new error handle holding no error; NULL if out of memory. */
sprc_error sprc_new_error(void);

/* 0: no error, 1: an error is set, 2: the handle is NULL. */
int sprc_check_error(sprc_error error);

/* The status code of the error held (SPRC_STAT_*; SPRC_STAT_SUCCESS when
 * none), SPRC_STAT_INVALID_INPUT for a NULL handle. */
int sprc_get_error_status(sprc_error error);

/* The message into buf of *size bytes: truncated to *size - 1 characters
 * and NUL-terminated whenever *size > 0. "" when no error is held; a message
 * saying so for a NULL handle. NULL buf, NULL size or *size <= 0: writes
 * nothing. */
void sprc_get_error(sprc_error error, char *buf, const int *size);

/* Forget the error held. */
void sprc_clear_error(sprc_error error);

/* Free *error and set it to NULL. */
void sprc_delete_error(sprc_error *error);

/* ---------------------------------------------------------------- scenes */

typedef struct _sprc_report *sprc_report;

/* Read the scene file at path (SCENE.md) and analyse it at levels[nlevels];
 * levels = NULL with nlevels = 0 takes the scene's own levels. Runs exactly
 * what `sprc run` runs, with the scene's defaults; writes no files (the
 * scene's output prefix is ignored). Returns the report, one row per level
 * (for a scene with &adapt, one row per adaptive step; levels then holds one
 * value, the start level; a run that a limit such as max_steps ended is a
 * success, its last row the last step), or NULL with the error set (bad
 * arguments: SPRC_STAT_INVALID_INPUT; scene
 * file missing or unreadable: SPRC_STAT_IO; invalid scene:
 * SPRC_STAT_INVALID_INPUT; not runnable by this version:
 * SPRC_STAT_UNSUPPORTED; a failed analysis: its status). */
sprc_report sprc_run_scene(sprc_error error, const char *path, const int *levels, int nlevels);

/* --------------------------------------------------------------- reports */

/* A report has one row per level and the columns of the report CSV, in its
 * order: level, h, elements, cut_elements, dofs, t_mesh, t_quadrature,
 * t_assembly, t_solve, t_recovery, t_estimate, t_total, err_fe, err_spr,
 * err_sprc, eta_spr, eta_sprc, theta_spr, theta_sprc, then for a study
 * with contact contact_iterations, t_contact, contact_measure, p_max_fe,
 * p_max_spr, p_max_sprc, p_max_exact, err_p_fe, err_p_spr, err_p_sprc, then
 * solver_iterations, then for an adaptive study (&adapt: one row per step)
 * step (0 the start mesh) and t_adapt (more may follow in later versions;
 * read columns by name). Every value is a double; integer columns (level,
 * elements, cut_elements, dofs, contact_iterations, solver_iterations, step)
 * are exact. A cell that does not apply (no
 * exact solution, recovery not run) is EMPTY and reads as a quiet NaN:
 * test it with isnan(). */

/* Number of rows; -1 on error. */
int sprc_get_report_rows(sprc_error error, sprc_report report);

/* Number of columns; -1 on error. */
int sprc_get_report_columns(sprc_error error, sprc_report report);

/* The name of column index (0-based) into buf of *size bytes, truncated and
 * NUL-terminated like sprc_get_error. */
void sprc_get_report_column(sprc_error error, sprc_report report, int index, char *buf, const int *size);

/* The cell at row (0-based) of the named column; NaN for an empty cell.
 * A bad row or column name also returns NaN, with the error set. */
double sprc_get_report_value(sprc_error error, sprc_report report, int row, const char *column);

/* The named column into values[n]; n must equal sprc_get_report_rows.
 * Empty cells are NaN. On error values is left unchanged. */
void sprc_get_report_values(sprc_error error, sprc_report report, const char *column, double *values, int n);

/* Free *report and set it to NULL. */
void sprc_delete_report(sprc_report *report);

/* ------------------------------------------------- recovery on your mesh */

/* SPR / SPR-C stress recovery and the ZZ error estimate on a caller's own
 * mesh (one element type for the whole mesh, VTK node order), from the FE
 * stresses at the integration points. */

/* Element types (VTK cell type ids). */
#define SPRC_TRI3 5
#define SPRC_QUAD4 9
#define SPRC_TET4 10
#define SPRC_HEX8 12
#define SPRC_QUAD9 28
#define SPRC_HEX27 29

/* Analyses: nstress = 3 in 2D (xx, yy, xy), 6 in 3D (xx, yy, zz, xy, yz, xz). */
#define SPRC_PLANE_STRESS 1
#define SPRC_PLANE_STRAIN 2
#define SPRC_SOLID 3

/* Recovery methods. */
#define SPRC_METHOD_SPR 1
#define SPRC_METHOD_SPRC 2
/* Flags to OR into the method: patch polynomials one degree above the
 * element's (the scene key recovery_degree = 'p+1'), or of the element's
 * degree ('p'). Without either, 'auto': SPR at the element's degree p,
 * SPR-C at p + 1 for SPRC_QUAD9 / SPRC_HEX27 and at p for linear elements. */
#define SPRC_RECOVERY_P_PLUS_1 256
#define SPRC_RECOVERY_P 512

/* Boundary facet kinds: a constant traction given per facet, a symmetry
 * plane (zero shear), a free surface (zero traction), a pressure p
 * (t = -p n with the facet's own outward normal at each of its points, so
 * the traction turns along a curved facet; p is facet_traction[f][0], the
 * other components are ignored). */
#define SPRC_FACET_TRACTION 1
#define SPRC_FACET_SYMMETRY 2
#define SPRC_FACET_FREE 3
#define SPRC_FACET_PRESSURE 4

typedef struct _sprc_recovery *sprc_recovery;

/* Recover the stresses of a mesh and estimate the error. Shapes in C order:
 *   nodes          [nnode][dim]
 *   connectivity   [nelem][nen]       0-based node indices, VTK order
 *                                     (nen: tri3 3, quad4 4, quad9 9, tet4 4,
 *                                     hex8 8, hex27 27)
 *   gauss_points   [nelem][ngp][dim]  physical coordinates, inside the element
 *   gauss_weights  [nelem][ngp]       weight times |J|, > 0
 *   gauss_stress   [nelem][ngp][nstress]  FE stresses (Voigt, see above)
 *   body_force     [dim] or NULL      constant body force b (div sigma + b = 0)
 *   facet_nodes    [nfacet][facet_nnode]  0-based; a side of one element
 *                                     (line2 / line3 in 2D, tri3 / quad4 /
 *                                     quad9 faces in 3D); NULL with nfacet = 0
 *   facet_kind     [nfacet]           SPRC_FACET_*
 *   facet_traction [nfacet][dim] or NULL  (needed if a facet is a traction or
 *                                     pressure one; pressure in [f][0])
 * dim 2 or 3; analysis SPRC_PLANE_STRESS / SPRC_PLANE_STRAIN in 2D,
 * SPRC_SOLID in 3D; method SPRC_METHOD_SPR or SPRC_METHOD_SPRC (SPR ignores
 * the facets once validated), optionally OR-ed with SPRC_RECOVERY_P_PLUS_1.
 * The patch degree is 'auto' (above) unless a degree flag is given. Boundary constraints apply only on the facets given.
 * Returns a new recovery (free it with sprc_delete_recovery) or NULL with
 * the error set: SPRC_STAT_INVALID_INPUT for a bad size, code, NULL array,
 * index out of range, non-finite value, point outside its element;
 * SPRC_STAT_SINGULAR for a patch that stays rank deficient;
 * SPRC_STAT_NOT_CONVERGED for a point whose inverse map fails. Duplicate
 * nodes (two used nodes at the same point) and duplicate elements (the same
 * vertices) are SPRC_STAT_INVALID_INPUT. Messages name entries, nodes,
 * elements and facets as C does: 0-based, row-major, with the argument
 * names above (gauss_weights[e][q], element e). */
sprc_recovery sprc_recover(sprc_error error, int dim, int analysis, int nnode, const double *nodes,
                           int element_type, int nen, int nelem, const int *connectivity, int ngp,
                           const double *gauss_points, const double *gauss_weights, const double *gauss_stress,
                           double young, double poisson, int method, const double *body_force, int nfacet,
                           int facet_nnode, const int *facet_nodes, const int *facet_kind,
                           const double *facet_traction);

/* sprc_recover with the reference coordinates of the integration points in
 * their elements, gauss_xi[nelem][ngp][dim] (the reference cells of the
 * element library: [0,1]^dim for quads and hexes, the unit simplex for tri3 and tet4), as an FE
 * code has them; NULL derives them (sprc_recover). Each is checked instead of
 * derived by Newton's method: finite, inside the element (tolerance 1e-6) and
 * mapped onto gauss_points[e][q] up to 1e-6 times the element's size (plus
 * the map's round-off); else SPRC_STAT_INVALID_INPUT naming gauss_xi[e][q]. */
sprc_recovery sprc_recover_xi(sprc_error error, int dim, int analysis, int nnode, const double *nodes,
                              int element_type, int nen, int nelem, const int *connectivity, int ngp,
                              const double *gauss_points, const double *gauss_weights, const double *gauss_stress,
                              double young, double poisson, int method, const double *body_force, int nfacet,
                              int facet_nnode, const int *facet_nodes, const int *facet_kind,
                              const double *facet_traction, const double *gauss_xi);

/* Recovered stresses at the nodes into out[nnode][nstress]; n must equal
 * nnode (nodes of no element get zero). On error out is left unchanged. */
void sprc_get_recovery_nodal_stress(sprc_error error, sprc_recovery recovery, double *out, int n);

/* ZZ error of each element (energy norm of sigma* - sigma_h over its
 * integration points) into out[nelem]; nelem must equal the element count. */
void sprc_get_recovery_element_error(sprc_error error, sprc_recovery recovery, double *out, int nelem);

/* Global ZZ estimate sqrt(sum of squared element errors); NaN on error. */
double sprc_get_recovery_global_error(sprc_error error, sprc_recovery recovery);

/* Estimated relative error err / sqrt(||sigma_h||^2 + err^2); NaN on error. */
double sprc_get_recovery_eta(sprc_error error, sprc_recovery recovery);

/* The recovered field sigma* at points[npts][dim] into stress[npts][nstress].
 * elements[npts] names the element of each point (0-based; -1 searches for
 * it); elements = NULL searches for every point (binned: O(nelem) once per call). A
 * point in no element (or not in the one named) is an error naming
 * points[i] and the element 0-based; on error the contents of stress are
 * unspecified. npts = 0 does nothing. */
void sprc_eval_recovery(sprc_error error, sprc_recovery recovery, int npts, const double *points,
                        const int *elements, double *stress);

/* Free *recovery and set it to NULL. */
void sprc_delete_recovery(sprc_recovery *recovery);

#ifdef __cplusplus
}
#endif

#endif /* SPRC_H */
