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

/* sprc_run_scene on threads OpenMP threads: threads > 0 runs every level on
 * that many; 0 chooses as the driver does (and as sprc_run_scene does): a
 * level estimated below 5000 dofs on one thread, the others on the
 * caller's omp_get_max_threads(). The caller's OpenMP thread count is
 * restored on return. Same bits for any thread count. threads < 0:
 * SPRC_STAT_INVALID_INPUT. */
sprc_report sprc_run_scene_threads(sprc_error error, const char *path, const int *levels, int nlevels, int threads);

/* ---------------------------------------------------------------- studies */

/* A study run that keeps the fields of some of its levels as arrays: the
 * arrays the driver writes to PREFIX.h5 (built by the same code, so a field
 * read here has the bits of its dataset). Addressed by
 *   row    the 0-based row of the study's report (one per level run);
 *   grid   a body's name, or "contact_<k>" for &contact pair k (1-based, a
 *          '_' put in front while a body has that name), as the HDF5 groups
 *          /level_LL/<grid>/ are named;
 *   field  for a body: "nodes" [n_nodes][dim] (double), "cells"
 *          [n_cells][nodes_per_cell] (int, 0-based node indices, VTK order:
 *          quad4 / quad9 / hex8 / hex27 by dim and order), then its fields as
 *          named in the HDF5 file: node fields "displacement" [n_nodes][dim],
 *          "sigma_fe", "sigma_spr", "sigma_sprc" [n_nodes][nstress] (nodal
 *          stresses, Voigt xx yy xy or xx yy zz xy yz xz; sigma_spr and
 *          sigma_sprc only where that recovery ran), "inside" [n_nodes] (int:
 *          1 in the body or on its boundary, 0 for the grid's nodes beyond
 *          it); cell fields "zz_error_spr", "zz_error_sprc" (ZZ indicator of
 *          each element, energy norm; where run), "exact_error_fe" (with an
 *          exact solution), "cut" (int), "volume_fraction", "cell_level"
 *          (int) [n_cells];
 *          for a contact pair: "points" [n_points][dim], then "p_fe",
 *          "p_spr", "p_sprc", "p_exact", "gap", "ts_fe", "ts_sprc", "weight"
 *          [n_points], "normal" [n_points][dim], "state" [n_points] (int: 0
 *          open, 1 stick, 2 slip): the columns of PREFIX_contact.csv.
 * Values in the scene's units; an empty value (not computed) is NaN. In the
 * HDF5 file a 2-D vector is stored with a zero third column (ParaView's
 * vectors have 3) and a field of one column is 1-D; here a field has the
 * columns listed above. */

typedef struct _sprc_study *sprc_study;

/* Field types of sprc_get_study_field_shape. */
#define SPRC_FIELD_REAL 1
#define SPRC_FIELD_INT 2

/* Run the scene at path as sprc_run_scene_threads does (levels[nlevels],
 * NULL and 0: the scene's levels; threads as there) and keep the fields of
 * the levels keep[nkeep], each one of the levels run (NULL and 0: of every
 * level run; in an adaptive study, &adapt, keep names steps, 0 the start
 * mesh, as the report's step column). Fields of the other levels are freed
 * as the run goes on.
 * Returns a new study (free it with sprc_delete_study) or NULL with the
 * error set (as sprc_run_scene; a level in keep that is not run:
 * SPRC_STAT_INVALID_INPUT). */
sprc_study sprc_run_study(sprc_error error, const char *path, const int *levels, int nlevels, const int *keep,
                          int nkeep, int threads);

/* The study's report as a new report handle (free it with
 * sprc_delete_report); NULL on error. */
sprc_report sprc_get_study_report(sprc_error error, sprc_study study);

/* Number of grids of row: the bodies in scene order, then the contact
 * pairs in &contact order; -1 on error (a row out of range or whose fields
 * were not kept: SPRC_STAT_INVALID_INPUT). */
int sprc_get_study_grids(sprc_error error, sprc_study study, int row);

/* The name of grid index (0-based) of row into buf of *size bytes
 * (truncated and NUL-terminated like sprc_get_error). Returns 0 for a body,
 * 1 for a contact pair, -1 on error. */
int sprc_get_study_grid(sprc_error error, sprc_study study, int row, int index, char *buf, const int *size);

/* Number of fields of the named grid at row (mesh arrays included); -1 on
 * error (an unknown grid: the message lists the grids). */
int sprc_get_study_fields(sprc_error error, sprc_study study, int row, const char *grid);

/* The name of field index (0-based) of the named grid at row into buf. */
void sprc_get_study_field_name(sprc_error error, sprc_study study, int row, const char *grid, int index, char *buf,
                               const int *size);

/* The shape of a field into shape[2]: rows (nodes, cells or points) and
 * columns. Returns SPRC_FIELD_REAL or SPRC_FIELD_INT, -1 on error (an
 * unknown field, e.g. sigma_spr of a study that ran SPR-C only: the
 * message lists the fields). */
int sprc_get_study_field_shape(sprc_error error, sprc_study study, int row, const char *grid, const char *field,
                               int *shape);

/* A real field into values[n], row-major [rows][columns]; n must be
 * rows * columns. An integer field, a wrong n or NULL values is an error
 * and leaves values unchanged. */
void sprc_get_study_field(sprc_error error, sprc_study study, int row, const char *grid, const char *field,
                          double *values, int n);

/* An integer field ("cells" 0-based) into values[n], as sprc_get_study_field. */
void sprc_get_study_field_int(sprc_error error, sprc_study study, int row, const char *grid, const char *field,
                              int *values, int n);

/* Free *study and set it to NULL. */
void sprc_delete_study(sprc_study *study);

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

/* Conventions of gauss_xi (sprc_recover_reference): SPRC_REFERENCE_UNIT, quads
 * and hexes on [0,1]^dim (sprc_recover_xi's); SPRC_REFERENCE_SYMMETRIC, on
 * [-1,1]^dim (most FE codes'). tri3 and tet4 use the unit simplex (xi >= 0,
 * sum xi <= 1) in both. */
#define SPRC_REFERENCE_UNIT 0
#define SPRC_REFERENCE_SYMMETRIC 1

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
 *   facet_nodes    [nfacet][facet_nnode]  0-based; a side (face) of exactly
 *                                     one element, its nodes in any order
 *                                     (line2 / line3 in 2D, tri3 / quad4 /
 *                                     quad9 faces in 3D); else an error naming
 *                                     facet_nodes[f]; NULL with nfacet = 0
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

/* sprc_recover_xi with the convention of gauss_xi: reference is
 * SPRC_REFERENCE_UNIT (the same as sprc_recover_xi) or SPRC_REFERENCE_SYMMETRIC
 * (quads and hexes on [-1,1]^dim); another value is SPRC_STAT_INVALID_INPUT.
 * A point outside the chosen reference cell is SPRC_STAT_INVALID_INPUT naming
 * gauss_xi[e][q] and the convention. */
sprc_recovery sprc_recover_reference(sprc_error error, int dim, int analysis, int nnode, const double *nodes,
                                     int element_type, int nen, int nelem, const int *connectivity, int ngp,
                                     const double *gauss_points, const double *gauss_weights,
                                     const double *gauss_stress, double young, double poisson, int method,
                                     const double *body_force, int nfacet, int facet_nnode, const int *facet_nodes,
                                     const int *facet_kind, const double *facet_traction, const double *gauss_xi,
                                     int reference);

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

/* ---------------------------------------- contact recovery on your meshes */

/* SPR-C recovery of bodies in contact (the seed's eqs. 103-138) on your own
 * meshes: collect the bodies and the contact pairs in an sprc_contact_input,
 * recover, then read each body as an sprc_recovery and each pair's contact
 * tractions at its slave facets' quadrature points. Both sides of a pair get
 * contact-aware patches (each is body (1) of its own patches, the other
 * body's integration and boundary points in the prism Omega_aux over the
 * patch's contact facets), as in sprc's own pipeline. Several pairs and
 * bodies per call; a patch whose contact points belong to two pairs is an
 * error (give the pairs' facets apart). SPRC_METHOD_SPR ignores contact. */

/* Contact laws of a contact facet: open (a free surface), frictionless,
 * Coulomb slip (|t_t| = mu p, against the slip direction), stick. */
#define SPRC_CONTACT_OPEN 0
#define SPRC_CONTACT_FRICTIONLESS 1
#define SPRC_CONTACT_SLIP 2
#define SPRC_CONTACT_STICK 3

typedef struct _sprc_contact_input *sprc_contact_input;
typedef struct _sprc_contact_recovery *sprc_contact_recovery;

/* A new, empty input; NULL on error. */
sprc_contact_input sprc_new_contact_input(sprc_error error);

/* Add a body: the arguments of sprc_recover_reference (without method).
 * The real arrays (nodes, gauss_points, gauss_weights, gauss_stress,
 * body_force, facet_traction, gauss_xi) are used in place: keep them valid
 * until sprc_recover_contact returns. The index arrays are checked and
 * copied now. Returns the body's index (0-based), -1 on error (messages
 * name bodies[i]). The facets here are the body's other boundaries; its
 * contact facets come with the pairs. */
int sprc_contact_add_body(sprc_error error, sprc_contact_input input, int dim, int analysis, int nnode,
                          const double *nodes, int element_type, int nen, int nelem, const int *connectivity,
                          int ngp, const double *gauss_points, const double *gauss_weights,
                          const double *gauss_stress, double young, double poisson, const double *body_force,
                          int nfacet, int facet_nnode, const int *facet_nodes, const int *facet_kind,
                          const double *facet_traction, const double *gauss_xi, int reference);

/* Add a contact pair of two bodies added (0-based slave, master):
 *   slave_facets  [nslave][facet_nnode]   0-based nodes of the slave body;
 *                                         sides of its elements, any order
 *   slave_law     [nslave]                SPRC_CONTACT_* per facet
 *   slave_slip    [nslave][dim] or NULL   the slave's slip direction relative
 *                                         to the master (needed on slip facets)
 *   master_*      the same for the master body (its slip relative to the slave)
 *   mu            Coulomb coefficient, finite and >= 0 (read by slip facets)
 *   pressure      [nslave * points per facet] or NULL: your FE contact
 *                 pressure at the slave points (kept for reporting)
 * The slip and pressure arrays are used in place (as a body's). Returns the
 * pair's index (0-based), -1 on error (messages name pairs[k]). */
int sprc_contact_add_pair(sprc_error error, sprc_contact_input input, int slave, int master, int nslave,
                          const int *slave_facets, const int *slave_law, const double *slave_slip, int nmaster,
                          const int *master_facets, const int *master_law, const double *master_slip, double mu,
                          const double *pressure);

/* Recover (SPRC_METHOD_SPRC or SPRC_METHOD_SPR, optionally OR-ed with
 * SPRC_RECOVERY_P or SPRC_RECOVERY_P_PLUS_1 as in sprc_recover: each body's
 * patch degree is then its element's, or one more; else 'auto'); a new
 * contact recovery or NULL with the error set. In 2D, where a closed
 * frictionless slave facet meets an open one, the patches near that edge of
 * the contact zone add the edge field (the pressure falls like the square
 * root of the distance to the edge; its point and amplitude fitted to both
 * bodies' stresses); SPRC_CONTACT_NO_EDGES OR-ed into method turns it off.
 * Messages name the entries as C does: bodies[i]: gauss_weights[e][q],
 * pairs[k].slave_facets[f][a], ... */
#define SPRC_CONTACT_NO_EDGES 1024
sprc_contact_recovery sprc_recover_contact(sprc_error error, sprc_contact_input input, int method);

/* Body `body` (0-based) as a new sprc_recovery (a copy; read it with the
 * sprc_get_recovery_* calls, free it with sprc_delete_recovery); NULL on
 * error. */
sprc_recovery sprc_get_contact_body(sprc_error error, sprc_contact_recovery recovery, int body);

/* The number of contact points of pair `pair` (the quadrature points of its
 * slave facets, in facet order); -1 on error. */
int sprc_get_contact_points(sprc_error error, sprc_contact_recovery recovery, int pair);

/* Pair `pair`'s values at its npoints points (npoints must equal
 * sprc_get_contact_points); any array may be NULL:
 *   points, normals (the slave's outward unit normal n)      [npoints][dim]
 *   weights (surface measure)                                [npoints]
 *   pressure = -n.sigma*_slave.n, pressure_master = -n.sigma*_master.n  [npoints]
 *   traction_tangential (slave), traction_tangential_master  [npoints][dim]
 *   jump = (sigma*_slave - sigma*_master) n (action-reaction) [npoints][dim]
 * The master's field is taken at the facing point: the nearest point of the
 * elements owning the master's contact facets (the point itself where it lies
 * in one; on a curved contact the undeformed slave points lie off the
 * master's mesh by the gap). */
void sprc_get_contact_pair(sprc_error error, sprc_contact_recovery recovery, int pair, int npoints, double *points,
                           double *weights, double *normals, double *pressure, double *pressure_master,
                           double *traction_tangential, double *traction_tangential_master, double *jump);

/* Free *input (not your arrays) / *recovery and set it to NULL. */
void sprc_delete_contact_input(sprc_contact_input *input);
void sprc_delete_contact_recovery(sprc_contact_recovery *recovery);

#ifdef __cplusplus
}
#endif

#endif /* SPRC_H */
