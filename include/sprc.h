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
 * scene's output prefix is ignored). Returns the report, one row per level,
 * or NULL with the error set (bad arguments: SPRC_STAT_INVALID_INPUT; scene
 * file missing or unreadable: SPRC_STAT_IO; invalid scene:
 * SPRC_STAT_INVALID_INPUT; not runnable by this version:
 * SPRC_STAT_UNSUPPORTED; a failed analysis: its status). */
sprc_report sprc_run_scene(sprc_error error, const char *path, const int *levels, int nlevels);

/* --------------------------------------------------------------- reports */

/* A report has one row per level and the columns of the report CSV, in its
 * order: level, h, elements, cut_elements, dofs, t_mesh, t_quadrature,
 * t_assembly, t_solve, t_recovery, t_estimate, t_total, err_fe, err_spr,
 * err_sprc, eta_spr, eta_sprc, theta_spr, theta_sprc (more may follow in
 * later versions). Every value is a double; integer columns (level,
 * elements, cut_elements, dofs) are exact. A cell that does not apply (no
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

#ifdef __cplusplus
}
#endif

#endif /* SPRC_H */
