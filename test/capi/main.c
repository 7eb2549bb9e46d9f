/* Tests of the C API (include/sprc.h): every entry point with NULL handles,
 * NULL pointers and wrong sizes (an error comes back, nothing crashes), the
 * error buffer contract, and a real run of the Lamé cylinder example.
 * Prints one line per test and 'N passed, M failed' last; exits 1 on failure.
 * Usage: capi [ROOT]  (the project root holding example/ and test/; default .)
 * The study tests compare the fields of sprc_run_study with the HDF5 file
 * the driver writes for the same scene and levels: the driver is
 * $SPRC_DRIVER (built from the same objects; tools/run-tests sets it), the
 * files go to a directory under $TMPDIR (default /tmp). Without
 * SPRC_DRIVER those comparisons fail, naming the variable. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <hdf5.h>

#include "sprc.h"

static int passed = 0, failed = 0;
static const char *root = ".";

/* One test: a name and the first failed condition, if any. */
#define CHECK(cond, what)                                                    \
  do {                                                                       \
    if (!(cond)) {                                                           \
      printf("FAIL %s: %s (line %d)\n", name, what, __LINE__);               \
      failed++;                                                              \
      return;                                                                \
    }                                                                        \
  } while (0)
#define PASS() (printf("ok   %s\n", name), passed++)

/* True when err holds an error whose message contains text (and clears it). */
static int has_error(sprc_error err, const char *text) {
  char buf[512];
  int size = (int)sizeof buf;
  if (sprc_check_error(err) != 1) return 0;
  sprc_get_error(err, buf, &size);
  sprc_clear_error(err);
  if (strstr(buf, text) == NULL) printf("     (the message was: %s)\n", buf);
  return strstr(buf, text) != NULL;
}

static void test_version(void) {
  const char *name = "version";
  CHECK(sprc_get_version() == SPRC_VERSION, "sprc_get_version() differs from SPRC_VERSION of sprc.h");
  PASS();
}

static void test_error_lifecycle(void) {
  const char *name = "error_lifecycle";
  char buf[64] = "junk";
  int size = (int)sizeof buf;
  sprc_error err = sprc_new_error();
  CHECK(err != NULL, "sprc_new_error returned NULL");
  CHECK(sprc_check_error(err) == 0, "a new handle holds an error");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_SUCCESS, "status of a new handle is not success");
  sprc_get_error(err, buf, &size);
  CHECK(buf[0] == '\0', "message of a new handle is not empty");
  sprc_delete_error(&err);
  CHECK(err == NULL, "sprc_delete_error did not null the handle");
  sprc_delete_error(&err); /* already NULL */
  sprc_delete_error(NULL);
  PASS();
}

static void test_null_error_handle(void) {
  const char *name = "null_error_handle";
  char buf[128];
  int size = (int)sizeof buf;
  double x[2] = {1.0, 2.0};
  int levels[1] = {3};
  sprc_report rep = NULL;
  CHECK(sprc_check_error(NULL) == 2, "sprc_check_error(NULL) is not 2");
  CHECK(sprc_get_error_status(NULL) == SPRC_STAT_INVALID_INPUT, "status of NULL is not invalid input");
  sprc_get_error(NULL, buf, &size);
  CHECK(strstr(buf, "NULL") != NULL, "sprc_get_error(NULL, ...) does not say the handle is NULL");
  sprc_clear_error(NULL);
  CHECK(sprc_run_scene(NULL, "x.nml", levels, 1) == NULL, "sprc_run_scene without error handle");
  CHECK(sprc_get_report_rows(NULL, rep) == -1, "sprc_get_report_rows(NULL, ...)");
  CHECK(sprc_get_report_columns(NULL, rep) == -1, "sprc_get_report_columns(NULL, ...)");
  sprc_get_report_column(NULL, rep, 0, buf, &size);
  CHECK(isnan(sprc_get_report_value(NULL, rep, 0, "level")), "sprc_get_report_value(NULL, ...) is not NaN");
  sprc_get_report_values(NULL, rep, "level", x, 2);
  CHECK(x[0] == 1.0 && x[1] == 2.0, "sprc_get_report_values(NULL, ...) wrote values");
  sprc_delete_report(&rep);
  sprc_delete_report(NULL);
  PASS();
}

static void test_null_report_handle(void) {
  const char *name = "null_report_handle";
  char buf[64] = "junk";
  int size = (int)sizeof buf;
  double x[1] = {7.0};
  sprc_error err = sprc_new_error();
  CHECK(sprc_get_report_rows(err, NULL) == -1, "rows of a NULL report is not -1");
  CHECK(has_error(err, "report handle is NULL"), "rows: no error for a NULL report");
  CHECK(sprc_get_report_columns(err, NULL) == -1, "columns of a NULL report is not -1");
  CHECK(has_error(err, "report handle is NULL"), "columns: no error for a NULL report");
  sprc_get_report_column(err, NULL, 0, buf, &size);
  CHECK(has_error(err, "report handle is NULL"), "column: no error for a NULL report");
  CHECK(strcmp(buf, "junk") == 0, "column name written for a NULL report");
  CHECK(isnan(sprc_get_report_value(err, NULL, 0, "level")), "value of a NULL report is not NaN");
  CHECK(has_error(err, "report handle is NULL"), "value: no error for a NULL report");
  sprc_get_report_values(err, NULL, "level", x, 1);
  CHECK(has_error(err, "report handle is NULL"), "values: no error for a NULL report");
  CHECK(x[0] == 7.0, "values written for a NULL report");
  sprc_delete_error(&err);
  PASS();
}

static void test_error_buffer(void) {
  const char *name = "error_buffer";
  char full[512], small[8];
  int size_full = (int)sizeof full, size_small = (int)sizeof small, zero = 0, negative = -3;
  sprc_error err = sprc_new_error();
  sprc_report rep = sprc_run_scene(err, "/nonexistent/scene.nml", NULL, 0);
  CHECK(rep == NULL, "a missing scene gave a report");
  CHECK(sprc_check_error(err) == 1, "a missing scene gave no error");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_IO, "a missing scene is not SPRC_STAT_IO");
  sprc_get_error(err, full, &size_full);
  CHECK(strstr(full, "/nonexistent/scene.nml") != NULL, "the message does not name the file");
  memset(small, 'x', sizeof small);
  sprc_get_error(err, small, &size_small);
  CHECK(small[7] == '\0', "a truncated message is not NUL-terminated");
  CHECK(strncmp(small, full, 7) == 0, "a truncated message is not the message's start");
  memset(small, 'x', sizeof small);
  sprc_get_error(err, small, &zero);
  sprc_get_error(err, small, &negative);
  CHECK(small[0] == 'x', "size <= 0 wrote into the buffer");
  sprc_get_error(err, NULL, &size_small);
  sprc_get_error(err, small, NULL);
  CHECK(small[0] == 'x', "a NULL size wrote into the buffer");
  CHECK(sprc_check_error(err) == 1, "reading the message cleared the error");
  sprc_clear_error(err);
  CHECK(sprc_check_error(err) == 0, "sprc_clear_error left the error");
  sprc_delete_error(&err);
  PASS();
}

static void test_run_bad_arguments(void) {
  const char *name = "run_bad_arguments";
  char path[1024];
  int levels[2] = {3, 99};
  sprc_error err = sprc_new_error();
  snprintf(path, sizeof path, "%s/example/scenes/lame_cylinder.nml", root);
  CHECK(sprc_run_scene(err, NULL, NULL, 0) == NULL, "a NULL path gave a report");
  CHECK(has_error(err, "path is NULL"), "no error for a NULL path");
  CHECK(sprc_run_scene(err, path, NULL, 2) == NULL, "NULL levels with nlevels = 2 gave a report");
  CHECK(has_error(err, "levels"), "no error for NULL levels with nlevels = 2");
  CHECK(sprc_run_scene(err, path, levels, -1) == NULL, "nlevels = -1 gave a report");
  CHECK(has_error(err, "levels"), "no error for nlevels = -1");
  CHECK(sprc_run_scene(err, path, levels, 2) == NULL, "level 99 gave a report");
  CHECK(has_error(err, "level 99"), "no error naming level 99");
  sprc_delete_error(&err);
  PASS();
}

static void test_run_lame(void) {
  const char *name = "run_lame_cylinder";
  char path[1024], col[32];
  int levels[2] = {3, 4}, size = (int)sizeof col, tiny = 3, i;
  double err_fe[2], dofs[2], x;
  sprc_error err = sprc_new_error();
  sprc_report rep;
  snprintf(path, sizeof path, "%s/example/scenes/lame_cylinder.nml", root);
  rep = sprc_run_scene(err, path, levels, 2);
  if (rep == NULL) {
    char msg[512];
    int n = (int)sizeof msg;
    sprc_get_error(err, msg, &n);
    printf("     %s\n", msg);
  }
  CHECK(rep != NULL, "sprc_run_scene failed on the Lame example");
  CHECK(sprc_check_error(err) == 0, "a successful run set the error");
  CHECK(sprc_get_report_rows(err, rep) == 2, "not 2 rows for levels 3,4");
  /* No contact: the 19 columns of every report, then solver_iterations. */
  CHECK(sprc_get_report_columns(err, rep) == 20, "not the 20 report columns");
  sprc_get_report_column(err, rep, 0, col, &size);
  CHECK(strcmp(col, "level") == 0, "column 0 is not 'level'");
  sprc_get_report_column(err, rep, 18, col, &size);
  CHECK(strcmp(col, "theta_sprc") == 0, "column 18 is not 'theta_sprc'");
  sprc_get_report_column(err, rep, 19, col, &size);
  CHECK(strcmp(col, "solver_iterations") == 0, "column 19 is not 'solver_iterations'");
  sprc_get_report_column(err, rep, 12, col, &tiny);
  CHECK(strcmp(col, "er") == 0, "a truncated column name is not 'er'");
  sprc_get_report_column(err, rep, 20, col, &size);
  CHECK(has_error(err, "out of range"), "no error for column index 20");
  CHECK(isnan(sprc_get_report_value(err, rep, 0, "p_max_fe")) && has_error(err, "p_max_fe"),
        "a contact column of a report without contact is not refused");
  sprc_get_report_column(err, rep, -1, col, &size);
  CHECK(has_error(err, "out of range"), "no error for column index -1");

  for (i = 0; i < 2; i++) {
    CHECK(sprc_get_report_value(err, rep, i, "level") == levels[i], "the level column is not 3, 4");
  }
  sprc_get_report_values(err, rep, "err_fe", err_fe, 2);
  sprc_get_report_values(err, rep, "dofs", dofs, 2);
  CHECK(sprc_check_error(err) == 0, "reading the columns set the error");
  for (i = 0; i < 2; i++) {
    CHECK(err_fe[i] > 0.0 && err_fe[i] < 1.0, "err_fe is not in (0, 1)");
    CHECK(sprc_get_report_value(err, rep, i, "err_fe") == err_fe[i], "value and values differ");
  }
  CHECK(dofs[1] > dofs[0], "dofs do not increase with the level");
  /* The example has an exact solution and runs both recoveries: every cell applies. */
  x = sprc_get_report_value(err, rep, 1, "theta_sprc");
  CHECK(!isnan(x) && x > 0.0, "theta_sprc is empty or not positive");

  x = sprc_get_report_value(err, rep, 2, "level");
  CHECK(isnan(x) && has_error(err, "row 2"), "row 2 of 2 rows: no NaN and error");
  x = sprc_get_report_value(err, rep, -1, "level");
  CHECK(isnan(x) && has_error(err, "row -1"), "row -1: no NaN and error");
  x = sprc_get_report_value(err, rep, 0, "level ");
  CHECK(isnan(x) && has_error(err, "level "), "a column name with a trailing blank: no NaN and error");
  x = sprc_get_report_value(err, rep, 0, "err_nope");
  CHECK(isnan(x) && has_error(err, "err_nope"), "unknown column: no NaN and error");
  x = sprc_get_report_value(err, rep, 0, NULL);
  CHECK(isnan(x) && has_error(err, "column name is NULL"), "NULL column: no NaN and error");
  dofs[0] = dofs[1] = -1.0;
  sprc_get_report_values(err, rep, "dofs", dofs, 3);
  CHECK(has_error(err, "n = 3"), "n = 3 for 2 rows: no error");
  sprc_get_report_values(err, rep, "dofs", dofs, 1);
  CHECK(has_error(err, "n = 1"), "n = 1 for 2 rows: no error");
  CHECK(dofs[0] == -1.0 && dofs[1] == -1.0, "values written despite a wrong n");
  sprc_get_report_values(err, rep, "dofs", NULL, 2);
  CHECK(has_error(err, "values is NULL"), "NULL values: no error");
  sprc_get_report_values(err, rep, NULL, dofs, 2);
  CHECK(has_error(err, "column name is NULL"), "NULL column in values: no error");

  sprc_delete_report(&rep);
  CHECK(rep == NULL, "sprc_delete_report did not null the handle");
  sprc_delete_error(&err);
  PASS();
}

static void test_run_adaptive(void) {
  const char *name = "run_adaptive";
  char path[1024], col[32];
  int size, nrows, ncols, i, levels[2] = {3, 4};
  double x;
  sprc_error err = sprc_new_error();
  sprc_report rep;
  snprintf(path, sizeof path, "%s/test/data/scenes/valid/kirsch_adaptive.nml", root);
  rep = sprc_run_scene(err, path, NULL, 0);
  CHECK(rep != NULL, "sprc_run_scene failed on the adaptive Kirsch scene");
  nrows = sprc_get_report_rows(err, rep);
  ncols = sprc_get_report_columns(err, rep);
  /* The 20 columns of a report without contact, then step and t_adapt. */
  CHECK(ncols == 22, "not 22 columns in an adaptive report");
  size = (int)sizeof col;
  sprc_get_report_column(err, rep, 20, col, &size);
  CHECK(strcmp(col, "step") == 0, "column 20 is not 'step'");
  size = (int)sizeof col;
  sprc_get_report_column(err, rep, 21, col, &size);
  CHECK(strcmp(col, "t_adapt") == 0, "column 21 is not 't_adapt'");
  CHECK(nrows >= 2 && nrows <= 10, "not 2 to max_steps rows");
  for (i = 0; i < nrows; i++) {
    CHECK(sprc_get_report_value(err, rep, i, "step") == i, "step is not the row index");
    x = sprc_get_report_value(err, rep, i, "t_adapt");
    CHECK(x >= 0.0 && x <= sprc_get_report_value(err, rep, i, "t_total"), "t_adapt not within t_total");
  }
  CHECK(sprc_get_report_value(err, rep, nrows - 1, "eta_sprc") <= 0.03, "the last step is above the target");
  CHECK(sprc_get_report_value(err, rep, nrows - 1, "err_fe") < sprc_get_report_value(err, rep, 0, "err_fe"),
        "err_fe did not fall");
  CHECK(sprc_check_error(err) == 0, "reading the report set the error");
  sprc_delete_report(&rep);
  /* With &adapt the levels are one start level. */
  CHECK(sprc_run_scene(err, path, levels, 2) == NULL, "two levels for an adaptive scene gave a report");
  CHECK(has_error(err, "start level"), "no error naming the start level");
  sprc_delete_error(&err);
  PASS();
}

static void test_run_invalid_scene(void) {
  const char *name = "run_invalid_scene";
  char path[1024];
  sprc_error err = sprc_new_error();
  snprintf(path, sizeof path, "%s/test/data/scenes/bad/poisson_half.nml", root);
  CHECK(sprc_run_scene(err, path, NULL, 0) == NULL, "an invalid scene gave a report");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_INVALID_INPUT, "an invalid scene is not SPRC_STAT_INVALID_INPUT");
  CHECK(has_error(err, "poisson"), "the message does not name the bad field");
  /* A valid scene this version cannot run: contact with the recovered stabilization. */
  snprintf(path, sizeof path, "%s/test/data/scenes/valid/hertz_roller.nml", root);
  CHECK(sprc_run_scene(err, path, NULL, 0) == NULL, "a contact scene gave a report");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_UNSUPPORTED, "a contact scene is not SPRC_STAT_UNSUPPORTED");
  CHECK(has_error(err, "contact"), "the message does not name contact");
  /* A traction on a surface the body does not have (later halfspaces cut every face away). */
  snprintf(path, sizeof path, "%s/test/data/scenes/bad/surface_covered_box.nml", root);
  CHECK(sprc_run_scene(err, path, NULL, 0) == NULL, "a load on a covered surface gave a report");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_INVALID_INPUT, "a covered surface is not SPRC_STAT_INVALID_INPUT");
  CHECK(has_error(err, "surface 'outer' does not bound body 'plate'"), "the message does not name the surface");
  sprc_delete_error(&err);
  PASS();
}

/* ------------------------------------------------ recovery on a C mesh */

/* A distorted M x M quad4 mesh of [0,1]^2: interior nodes moved by 0.2 of a
 * cell (sides stay straight), 2x2 Gauss points mapped bilinearly, weights
 * times |J|, and the FE stresses of an exact field at the points. */
#define M 4
#define NNODE ((M + 1) * (M + 1))
#define NELEM (M * M)
#define NGP 4

typedef struct {
  double nodes[NNODE][2];
  int conn[NELEM][4];
  double gp[NELEM][NGP][2], gw[NELEM][NGP], gs[NELEM][NGP][3];
  double body[2];
  int field;
} quad_mesh;

/* field 0: a linear field (body force b = -div sigma = (-2.25, 2.5));
 * field 1: sigma_xx, sigma_xy depend on x only, so the sides x = 0 and
 * x = 1 carry constant tractions (b = (-2, 2));
 * field 2: hydrostatic sigma = -3 I, a pressure 3 on every side (b = 0). */
static void exact_stress(int field, const double *x, double *s) {
  double a = x[0], b = x[1];
  if (field == 0) {
    s[0] = 1.0 + 2 * a + 3 * b;
    s[1] = -2.0 + 0.5 * a - b;
    s[2] = 0.7 - 1.5 * a + 0.25 * b;
  } else if (field == 1) {
    s[0] = 1.0 + 2 * a;
    s[1] = -2.0 + 0.5 * a - b;
    s[2] = 0.5 - a;
  } else {
    s[0] = s[1] = -3.0;
    s[2] = 0.0;
  }
}

static void build_quad_mesh(quad_mesh *m, int field) {
  const double g = 0.5 / sqrt(3.0);
  const double xi[NGP][2] = {{0.5 - g, 0.5 - g}, {0.5 + g, 0.5 - g}, {0.5 + g, 0.5 + g}, {0.5 - g, 0.5 + g}};
  int i, j, e, q, a;
  for (j = 0; j <= M; j++) {
    for (i = 0; i <= M; i++) {
      double *x = m->nodes[i + (M + 1) * j];
      x[0] = (double)i / M;
      x[1] = (double)j / M;
      if (i > 0 && i < M) x[0] += 0.2 / M * sin(1.7 * i + 2.3 * j + 1.0);
      if (j > 0 && j < M) x[1] += 0.2 / M * sin(1.7 * i + 2.3 * j + 2.0);
    }
  }
  for (j = 0; j < M; j++) {
    for (i = 0; i < M; i++) {
      int n = i + (M + 1) * j;
      e = i + M * j;
      m->conn[e][0] = n;
      m->conn[e][1] = n + 1;
      m->conn[e][2] = n + M + 2;
      m->conn[e][3] = n + M + 1;
    }
  }
  for (e = 0; e < NELEM; e++) {
    for (q = 0; q < NGP; q++) {
      double r = xi[q][0], t = xi[q][1];
      double shp[4] = {(1 - r) * (1 - t), r * (1 - t), r * t, (1 - r) * t};
      double dr[4] = {-(1 - t), 1 - t, t, -t}, dt[4] = {-(1 - r), -r, r, 1 - r};
      double jac[2][2] = {{0, 0}, {0, 0}};
      m->gp[e][q][0] = m->gp[e][q][1] = 0.0;
      for (a = 0; a < 4; a++) {
        const double *x = m->nodes[m->conn[e][a]];
        m->gp[e][q][0] += shp[a] * x[0];
        m->gp[e][q][1] += shp[a] * x[1];
        jac[0][0] += dr[a] * x[0];
        jac[0][1] += dt[a] * x[0];
        jac[1][0] += dr[a] * x[1];
        jac[1][1] += dt[a] * x[1];
      }
      m->gw[e][q] = 0.25 * fabs(jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]);
      exact_stress(field, m->gp[e][q], m->gs[e][q]);
    }
  }
  m->field = field;
  m->body[0] = field == 0 ? -2.25 : field == 1 ? -2.0 : 0.0;
  m->body[1] = field == 0 ? 2.5 : field == 1 ? 2.0 : 0.0;
}

/* sprc_recover on the mesh with the given method and no facets. */
static sprc_recovery recover_quad_mesh(sprc_error err, const quad_mesh *m, int method) {
  return sprc_recover(err, 2, SPRC_PLANE_STRESS, NNODE, &m->nodes[0][0], SPRC_QUAD4, 4, NELEM, &m->conn[0][0], NGP,
                      &m->gp[0][0][0], &m->gw[0][0], &m->gs[0][0][0], 1000.0, 0.3, method, m->body, 0, 2, NULL,
                      NULL, NULL);
}

/* Largest |nodal - exact| over the nodes. */
static double nodal_deviation(const quad_mesh *m, double nodal[NNODE][3]) {
  double dev = 0.0, s[3];
  int n, k;
  for (n = 0; n < NNODE; n++) {
    exact_stress(m->field, m->nodes[n], s);
    for (k = 0; k < 3; k++) dev = fmax(dev, fabs(nodal[n][k] - s[k]));
  }
  return dev;
}

static void test_recovery_null_handles(void) {
  const char *name = "recovery_null_handles";
  static quad_mesh m;
  double out[NNODE][3], e[NELEM], pts[1][2] = {{0.5, 0.5}}, s[1][3] = {{7.0, 7.0, 7.0}};
  sprc_recovery rec = NULL;
  sprc_error err = sprc_new_error();
  build_quad_mesh(&m, 0);
  out[0][0] = e[0] = 7.0;
  /* No error handle: nothing happens, failure values come back. */
  CHECK(recover_quad_mesh(NULL, &m, SPRC_METHOD_SPRC) == NULL, "sprc_recover without error handle");
  CHECK(isnan(sprc_get_recovery_global_error(NULL, rec)), "global error without error handle is not NaN");
  CHECK(isnan(sprc_get_recovery_eta(NULL, rec)), "eta without error handle is not NaN");
  sprc_get_recovery_nodal_stress(NULL, rec, &out[0][0], NNODE);
  sprc_get_recovery_element_error(NULL, rec, e, NELEM);
  sprc_eval_recovery(NULL, rec, 1, &pts[0][0], NULL, &s[0][0]);
  CHECK(out[0][0] == 7.0 && e[0] == 7.0 && s[0][0] == 7.0, "output written without error handle");
  /* A NULL recovery handle is an error naming the entry. */
  CHECK(isnan(sprc_get_recovery_global_error(err, NULL)), "global error of NULL is not NaN");
  CHECK(has_error(err, "sprc_get_recovery_global_error: the recovery handle is NULL"), "global error: no error");
  CHECK(isnan(sprc_get_recovery_eta(err, NULL)), "eta of NULL is not NaN");
  CHECK(has_error(err, "sprc_get_recovery_eta: the recovery handle is NULL"), "eta: no error");
  sprc_get_recovery_nodal_stress(err, NULL, &out[0][0], NNODE);
  CHECK(has_error(err, "recovery handle is NULL"), "nodal stress: no error for NULL");
  sprc_get_recovery_element_error(err, NULL, e, NELEM);
  CHECK(has_error(err, "recovery handle is NULL"), "element error: no error for NULL");
  sprc_eval_recovery(err, NULL, 1, &pts[0][0], NULL, &s[0][0]);
  CHECK(has_error(err, "recovery handle is NULL"), "eval: no error for NULL");
  CHECK(out[0][0] == 7.0 && e[0] == 7.0 && s[0][0] == 7.0, "output written for a NULL recovery");
  sprc_delete_recovery(&rec);
  sprc_delete_recovery(NULL);
  sprc_delete_error(&err);
  PASS();
}

/* Every size, code and pointer of sprc_recover, wrong one at a time. */
static void test_recovery_bad_input(void) {
  const char *name = "recovery_bad_input";
  static quad_mesh m, bad;
  const double *x = &m.nodes[0][0], *gp = &m.gp[0][0][0], *gw = &m.gw[0][0], *gs = &m.gs[0][0][0];
  const int *c = &m.conn[0][0];
  int fn[2][2] = {{0, 1}, {1, 2}}, fk[2] = {SPRC_FACET_FREE, SPRC_FACET_TRACTION}, fk_bad[2] = {3, 9};
  double ft[2][2] = {{0, 0}, {0, 0}};
  sprc_error err = sprc_new_error();
  build_quad_mesh(&m, 0);
#define RECOVER_FAILS(text, ...)                                                                  \
  do {                                                                                            \
    sprc_recovery r_ = sprc_recover(err, __VA_ARGS__);                                            \
    CHECK(r_ == NULL, "a recovery came back for bad input: " text);                               \
    CHECK(sprc_get_error_status(err) == SPRC_STAT_INVALID_INPUT, "not invalid input: " text);    \
    CHECK(has_error(err, text), "no error saying: " text);                                        \
  } while (0)
  RECOVER_FAILS("dim = 4", 4, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("analysis = 7", 2, 7, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL,
                NULL);
  RECOVER_FAILS("element_type = 99", 2, 1, NNODE, x, 99, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL,
                NULL, NULL);
  RECOVER_FAILS("nen = 3", 2, 1, NNODE, x, 9, 3, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("nnode = 0", 2, 1, 0, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("nelem = -1", 2, 1, NNODE, x, 9, 4, -1, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("ngp = 0", 2, 1, NNODE, x, 9, 4, NELEM, c, 0, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("nodes is NULL", 2, 1, NNODE, NULL, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL,
                NULL, NULL);
  RECOVER_FAILS("connectivity is NULL", 2, 1, NNODE, x, 9, 4, NELEM, NULL, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2,
                NULL, NULL, NULL);
  RECOVER_FAILS("gauss_points is NULL", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, NULL, gw, gs, 1e3, 0.3, 2, NULL, 0, 2,
                NULL, NULL, NULL);
  RECOVER_FAILS("gauss_weights is NULL", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, NULL, gs, 1e3, 0.3, 2, NULL, 0, 2,
                NULL, NULL, NULL);
  RECOVER_FAILS("gauss_stress is NULL", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, NULL, 1e3, 0.3, 2, NULL, 0, 2,
                NULL, NULL, NULL);
  RECOVER_FAILS("nfacet = -1", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, -1, 2, NULL, NULL,
                NULL);
  RECOVER_FAILS("facet_nodes or facet_kind is NULL", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2,
                NULL, 2, 2, NULL, fk, NULL);
  RECOVER_FAILS("facet_nodes or facet_kind is NULL", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2,
                NULL, 2, 2, &fn[0][0], NULL, NULL);
  RECOVER_FAILS("facet_nnode = 3", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 2, 3,
                &fn[0][0], fk, NULL);
  /* Codes and values the library checks, reported through the C API. */
  RECOVER_FAILS("method = 5", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 5, NULL, 0, 2, NULL, NULL,
                NULL);
  RECOVER_FAILS("analysis = 3 does not fit dim = 2", 2, 3, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2,
                NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("poisson", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.5, 2, NULL, 0, 2, NULL, NULL, NULL);
  RECOVER_FAILS("facet_kind[1] = 9", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 2, 2,
                &fn[0][0], fk_bad, &ft[0][0]);
  RECOVER_FAILS("kind traction but facet_traction is not given", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3,
                0.3, 2, NULL, 2, 2, &fn[0][0], fk, NULL);
  /* 0-based indices: range-checked and named as the caller wrote them. */
  bad = m;
  bad.conn[3][2] = NNODE;
  RECOVER_FAILS("connectivity[3][2] = 25 is not a node in 0..24", 2, 1, NNODE, x, 9, 4, NELEM, &bad.conn[0][0], NGP,
                gp, gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  bad.conn[3][2] = -1;
  RECOVER_FAILS("connectivity[3][2] = -1", 2, 1, NNODE, x, 9, 4, NELEM, &bad.conn[0][0], NGP, gp, gw, gs, 1e3, 0.3, 2,
                NULL, 0, 2, NULL, NULL, NULL);
  fn[1][0] = -3;
  RECOVER_FAILS("facet_nodes[1][0] = -3", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 2, 2,
                &fn[0][0], fk, &ft[0][0]);
  fn[1][0] = 1;
  /* A facet must be a side of exactly one element, in any node order: nodes 0 and
     6 are opposite corners of element 0 (its diagonal), so facet 1 = {6, 0} is
     none (it used to be accepted and changed the estimate). */
  {
    int fd[2][2] = {{1, 0}, {6, 0}}, fkd[2] = {SPRC_FACET_FREE, SPRC_FACET_FREE};
    RECOVER_FAILS("facet 1 is not a side of any element: facet_nodes[1] = (6 0) are nodes of element 0 but not one "
                  "of its sides", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, gs, 1e3, 0.3, 2, NULL, 2, 2, &fd[0][0],
                  fkd, NULL);
  }
  /* Non-finite data and a point outside its element. */
  /* Named 0-based in C order with the C argument names, as the caller wrote them. */
  bad = m;
  bad.gs[5][1][2] = NAN;
  RECOVER_FAILS("gauss_stress[5][1] is not finite", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, gw, &bad.gs[0][0][0], 1e3,
                0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  bad = m;
  bad.gw[2][1] = -1.0;
  RECOVER_FAILS("gauss_weights[2][1] = ", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, gp, &bad.gw[0][0], gs, 1e3, 0.3, 2, NULL,
                0, 2, NULL, NULL, NULL);
  bad = m;
  bad.gp[2][0][0] = 5.0;
  RECOVER_FAILS("gauss_points[2][0] is not inside element 2", 2, 1, NNODE, x, 9, 4, NELEM, c, NGP, &bad.gp[0][0][0],
                gw, gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
  /* Duplicate elements: element 5 repeats element 0's vertices. */
  bad = m;
  memcpy(bad.conn[5], bad.conn[0], sizeof bad.conn[0]);
  RECOVER_FAILS("elements 0 and 5 have the same vertices", 2, 1, NNODE, x, 9, 4, NELEM, &bad.conn[0][0], NGP, gp, gw,
                gs, 1e3, 0.3, 2, NULL, 0, 2, NULL, NULL, NULL);
#undef RECOVER_FAILS
  sprc_delete_error(&err);
  PASS();
}

/* Wrong sizes and pointers of the getters and of sprc_eval_recovery. */
static void test_recovery_bad_output(void) {
  const char *name = "recovery_bad_output";
  static quad_mesh m;
  double out[NNODE][3], e[NELEM], pts[2][2] = {{0.5, 0.5}, {3.0, 0.5}}, s[2][3];
  int el[2] = {0, NELEM}, el_neg[1] = {-2};
  sprc_error err = sprc_new_error();
  sprc_recovery rec;
  build_quad_mesh(&m, 0);
  rec = recover_quad_mesh(err, &m, SPRC_METHOD_SPRC);
  CHECK(rec != NULL && sprc_check_error(err) == 0, "recovery of the quad4 mesh failed");
  out[0][0] = e[0] = 7.0;
  sprc_get_recovery_nodal_stress(err, rec, &out[0][0], NNODE - 1);
  CHECK(has_error(err, "n = 24 but the recovery has nnode = 25"), "nodal stress: no error for n = nnode - 1");
  sprc_get_recovery_nodal_stress(err, rec, &out[0][0], NNODE + 1);
  CHECK(has_error(err, "n = 26"), "nodal stress: no error for n = nnode + 1");
  sprc_get_recovery_nodal_stress(err, rec, NULL, NNODE);
  CHECK(has_error(err, "out is NULL"), "nodal stress: no error for NULL out");
  sprc_get_recovery_element_error(err, rec, e, NELEM + 1);
  CHECK(has_error(err, "nelem = 16"), "element error: no error for a wrong nelem");
  sprc_get_recovery_element_error(err, rec, NULL, NELEM);
  CHECK(has_error(err, "out is NULL"), "element error: no error for NULL out");
  CHECK(out[0][0] == 7.0 && e[0] == 7.0, "output written despite an error");
  sprc_eval_recovery(err, rec, -1, &pts[0][0], NULL, &s[0][0]);
  CHECK(has_error(err, "npts = -1"), "eval: no error for npts = -1");
  sprc_eval_recovery(err, rec, 0, NULL, NULL, NULL);
  CHECK(sprc_check_error(err) == 0, "eval: npts = 0 with NULL arrays is an error");
  sprc_eval_recovery(err, rec, 1, NULL, NULL, &s[0][0]);
  CHECK(has_error(err, "points or stress is NULL"), "eval: no error for NULL points");
  sprc_eval_recovery(err, rec, 1, &pts[0][0], NULL, NULL);
  CHECK(has_error(err, "points or stress is NULL"), "eval: no error for NULL stress");
  sprc_eval_recovery(err, rec, 2, &pts[0][0], el, &s[0][0]);
  CHECK(has_error(err, "elements[1] = 16 is not -1 (search) or an element in 0..15"), "eval: element 16 accepted");
  sprc_eval_recovery(err, rec, 1, &pts[0][0], el_neg, &s[0][0]);
  CHECK(has_error(err, "elements[0] = -2"), "eval: element -2 accepted");
  sprc_eval_recovery(err, rec, 2, &pts[0][0], NULL, &s[0][0]);
  CHECK(has_error(err, "is in no element"), "eval: no error for a point outside the mesh");
  sprc_delete_recovery(&rec);
  CHECK(rec == NULL, "sprc_delete_recovery did not null the handle");
  sprc_delete_error(&err);
  PASS();
}

/* An equilibrated linear field is in the span of both recoveries: the nodal
 * stresses, the field at points and the estimate are exact up to round-off
 * (patch least-squares solves of size <= 20 on scaled coordinates: 1e-10 of
 * the field's magnitude ~ 5 leaves a wide margin over ~1e-14). */
static void test_recovery_linear_quad4(void) {
  const char *name = "recovery_linear_quad4";
  static quad_mesh m;
  double nodal[NNODE][3], e[NELEM], pts[3][2] = {{0.31, 0.47}, {0.9, 0.12}, {0.05, 0.95}}, s[3][3], ex[3];
  int el[3] = {-1, -1, -1}, method, i, k, found;
  sprc_error err = sprc_new_error();
  build_quad_mesh(&m, 0);
  for (method = SPRC_METHOD_SPR; method <= SPRC_METHOD_SPRC; method++) {
    sprc_recovery rec = recover_quad_mesh(err, &m, method);
    CHECK(rec != NULL && sprc_check_error(err) == 0, "recovery of the quad4 mesh failed");
    sprc_get_recovery_nodal_stress(err, rec, &nodal[0][0], NNODE);
    CHECK(nodal_deviation(&m, nodal) <= 5e-10, "nodal stresses deviate from the exact field by more than 1e-10");
    sprc_get_recovery_element_error(err, rec, e, NELEM);
    for (i = 0; i < NELEM; i++) CHECK(e[i] >= 0.0 && e[i] <= 1e-10, "an element error is not ~ 0");
    CHECK(sprc_get_recovery_global_error(err, rec) <= 1e-10, "global error is not ~ 0");
    CHECK(sprc_get_recovery_eta(err, rec) <= 1e-10, "eta is not ~ 0");
    /* With the elements searched, then named (found by searching first). */
    sprc_eval_recovery(err, rec, 3, &pts[0][0], NULL, &s[0][0]);
    CHECK(sprc_check_error(err) == 0, "eval with search failed");
    for (i = 0; i < 3; i++) {
      exact_stress(0, pts[i], ex);
      for (k = 0; k < 3; k++) CHECK(fabs(s[i][k] - ex[k]) <= 5e-10, "field at a point is not exact");
    }
    for (i = 0; i < 3; i++) {
      for (found = 0; found < NELEM; found++) {
        int one[1] = {found};
        sprc_eval_recovery(err, rec, 1, pts[i], one, s[i]);
        if (sprc_check_error(err) == 0) break;
        sprc_clear_error(err);
      }
      CHECK(found < NELEM, "no element holds a point inside the mesh");
      el[i] = found;
    }
    sprc_eval_recovery(err, rec, 3, &pts[0][0], el, &s[0][0]);
    CHECK(sprc_check_error(err) == 0, "eval with named elements failed");
    for (i = 0; i < 3; i++) {
      exact_stress(0, pts[i], ex);
      for (k = 0; k < 3; k++) CHECK(fabs(s[i][k] - ex[k]) <= 5e-10, "field at a point (element named) is not exact");
    }
    el[0] = (el[0] + 1) % NELEM;
    sprc_eval_recovery(err, rec, 3, &pts[0][0], el, &s[0][0]);
    CHECK(has_error(err, "is not in element"), "a point in the wrong element: no error");
    sprc_delete_recovery(&rec);
  }
  sprc_delete_error(&err);
  PASS();
}

/* SPRC_RECOVERY_P_PLUS_1 OR-ed into the method: quadratic patches on quad4
 * still reproduce the linear field; SPRC_RECOVERY_P is accepted; an unknown
 * flag bit and both degree flags at once are refused. */
static void test_recovery_degree_flag(void) {
  const char *name = "recovery_degree_flag";
  static quad_mesh m;
  double nodal[NNODE][3];
  sprc_error err = sprc_new_error();
  sprc_recovery rec;
  build_quad_mesh(&m, 0);
  rec = recover_quad_mesh(err, &m, SPRC_METHOD_SPRC | SPRC_RECOVERY_P_PLUS_1);
  CHECK(rec != NULL && sprc_check_error(err) == 0, "recovery with SPRC_RECOVERY_P_PLUS_1 failed");
  sprc_get_recovery_nodal_stress(err, rec, &nodal[0][0], NNODE);
  CHECK(nodal_deviation(&m, nodal) <= 5e-10, "p+1 nodal stresses deviate from the linear field");
  sprc_delete_recovery(&rec);
  rec = recover_quad_mesh(err, &m, SPRC_METHOD_SPRC | SPRC_RECOVERY_P);
  CHECK(rec != NULL && sprc_check_error(err) == 0, "recovery with SPRC_RECOVERY_P failed");
  sprc_delete_recovery(&rec);
  rec = recover_quad_mesh(err, &m, SPRC_METHOD_SPRC | 1024);
  CHECK(rec == NULL && has_error(err, "unknown flag bits"), "an unknown flag bit was accepted");
  rec = recover_quad_mesh(err, &m, SPRC_METHOD_SPRC | SPRC_RECOVERY_P | SPRC_RECOVERY_P_PLUS_1);
  CHECK(rec == NULL && has_error(err, "sets both"), "both degree flags were accepted");
  sprc_delete_error(&err);
  PASS();
}

/* SPR-C with traction facets on x = 0 and x = 1 (0-based facet nodes in C
 * order, constant tractions sigma n): still exact, and the facets reach the
 * library (a traction that contradicts the field makes the estimate > 0). */
static void test_recovery_facets(void) {
  const char *name = "recovery_traction_facets";
  static quad_mesh m;
  int fn[2 * M][2], fk[2 * M], j;
  double ft[2 * M][2], nodal[NNODE][3], eta;
  sprc_error err = sprc_new_error();
  sprc_recovery rec;
  build_quad_mesh(&m, 1);
  for (j = 0; j < M; j++) {
    fn[j][0] = (M + 1) * j; /* x = 0: t = -(sigma_xx, sigma_xy) = -(1, 0.5) */
    fn[j][1] = (M + 1) * (j + 1);
    ft[j][0] = -1.0;
    ft[j][1] = -0.5;
    fn[M + j][0] = (M + 1) * (j + 1) + M; /* x = 1: t = (3, -0.5), nodes in either order */
    fn[M + j][1] = (M + 1) * j + M;
    ft[M + j][0] = 3.0;
    ft[M + j][1] = -0.5;
    fk[j] = fk[M + j] = SPRC_FACET_TRACTION;
  }
  rec = sprc_recover(err, 2, SPRC_PLANE_STRAIN, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0], NGP,
                     &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body, 2 * M, 2,
                     &fn[0][0], fk, &ft[0][0]);
  CHECK(rec != NULL, "recovery with traction facets failed");
  sprc_get_recovery_nodal_stress(err, rec, &nodal[0][0], NNODE);
  CHECK(nodal_deviation(&m, nodal) <= 5e-10, "nodal stresses with facets are not exact");
  CHECK(sprc_get_recovery_eta(err, rec) <= 1e-10, "eta with consistent facets is not ~ 0");
  sprc_delete_recovery(&rec);
  for (j = 0; j < M; j++) ft[j][0] = 0.0; /* wrong traction on x = 0 */
  rec = sprc_recover(err, 2, SPRC_PLANE_STRAIN, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0], NGP,
                     &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body, 2 * M, 2,
                     &fn[0][0], fk, &ft[0][0]);
  CHECK(rec != NULL, "recovery with a wrong traction failed");
  eta = sprc_get_recovery_eta(err, rec);
  CHECK(eta > 1e-3, "a traction contradicting the field left the estimate ~ 0");
  sprc_delete_recovery(&rec);
  sprc_delete_error(&err);
  PASS();
}

/* SPR-C with SPRC_FACET_PRESSURE on all four sides (p in facet_traction[f][0],
 * t = -p n with each facet's outward normal, whatever its node order) and the
 * hydrostatic field -3 I: exact with p = 3; p = 2 contradicts the field. */
static void test_recovery_pressure_facets(void) {
  const char *name = "recovery_pressure_facets";
  static quad_mesh m;
  int fn[4 * M][2], fk[4 * M], j, k;
  double ft[4 * M][2], nodal[NNODE][3], p;
  sprc_error err = sprc_new_error();
  sprc_recovery rec;
  build_quad_mesh(&m, 2);
  for (j = 0; j < M; j++) {
    int side[4][2] = {{j, j + 1},                                   /* y = 0 */
                      {(M + 1) * j + M, (M + 1) * (j + 1) + M},     /* x = 1 */
                      {(M + 1) * M + j + 1, (M + 1) * M + j},       /* y = 1 */
                      {(M + 1) * (j + 1), (M + 1) * j}};            /* x = 0 */
    for (k = 0; k < 4; k++) {
      fn[4 * j + k][0] = side[k][0];
      fn[4 * j + k][1] = side[k][1];
      fk[4 * j + k] = SPRC_FACET_PRESSURE;
    }
  }
  for (p = 3.0; p >= 2.0; p -= 1.0) {
    for (j = 0; j < 4 * M; j++) {
      ft[j][0] = p;
      ft[j][1] = NAN; /* ignored for a pressure facet */
    }
    rec = sprc_recover(err, 2, SPRC_PLANE_STRAIN, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0], NGP,
                       &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body, 4 * M, 2,
                       &fn[0][0], fk, &ft[0][0]);
    CHECK(rec != NULL, "recovery with pressure facets failed");
    sprc_get_recovery_nodal_stress(err, rec, &nodal[0][0], NNODE);
    if (p == 3.0)
      CHECK(nodal_deviation(&m, nodal) <= 5e-10, "pressure facets: the hydrostatic field is not exact");
    else
      CHECK(nodal_deviation(&m, nodal) > 1e-3, "a pressure contradicting the field left it exact");
    sprc_delete_recovery(&rec);
  }
  sprc_delete_error(&err);
  PASS();
}

/* sprc_recover_xi: the points' reference coordinates (the rule of build_quad_mesh)
 * give the exact field; NULL derives them; a moved one is an error naming
 * gauss_xi[e][q] 0-based. */
static void test_recovery_given_xi(void) {
  const char *name = "recovery_given_xi";
  static quad_mesh m;
  static double gxi[NELEM][NGP][2];
  const double g = 0.5 / sqrt(3.0);
  const double rule[NGP][2] = {{0.5 - g, 0.5 - g}, {0.5 + g, 0.5 - g}, {0.5 + g, 0.5 + g}, {0.5 - g, 0.5 + g}};
  double nodal[NNODE][3];
  int e, q, pass;
  sprc_error err = sprc_new_error();
  sprc_recovery rec;
  build_quad_mesh(&m, 0);
  for (e = 0; e < NELEM; e++)
    for (q = 0; q < NGP; q++) {
      gxi[e][q][0] = rule[q][0];
      gxi[e][q][1] = rule[q][1];
    }
  for (pass = 0; pass < 2; pass++) {
    rec = sprc_recover_xi(err, 2, SPRC_PLANE_STRESS, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0], NGP,
                          &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body, 0, 2,
                          NULL, NULL, NULL, pass == 0 ? &gxi[0][0][0] : NULL);
    CHECK(rec != NULL && sprc_check_error(err) == 0, "recovery with the reference coordinates failed");
    sprc_get_recovery_nodal_stress(err, rec, &nodal[0][0], NNODE);
    CHECK(nodal_deviation(&m, nodal) <= 5e-10, "nodal stresses with given coordinates are not exact");
    sprc_delete_recovery(&rec);
  }
  gxi[3][1][0] += 1e-3;
  rec = sprc_recover_xi(err, 2, SPRC_PLANE_STRESS, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0], NGP,
                        &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body, 0, 2,
                        NULL, NULL, NULL, &gxi[0][0][0]);
  CHECK(rec == NULL && has_error(err, "gauss_xi[3][1] = "), "a moved reference coordinate was accepted");
  /* sprc_recover_reference: the same rule on [-1,1]^2 with SPRC_REFERENCE_SYMMETRIC is
     exact; read as SPRC_REFERENCE_UNIT it is outside [0,1]^2 and the message says the
     convention; SPRC_REFERENCE_UNIT on the [0,1] rule is sprc_recover_xi. */
  for (e = 0; e < NELEM; e++)
    for (q = 0; q < NGP; q++) {
      gxi[e][q][0] = 2.0 * rule[q][0] - 1.0;
      gxi[e][q][1] = 2.0 * rule[q][1] - 1.0;
    }
  rec = sprc_recover_reference(err, 2, SPRC_PLANE_STRESS, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0],
                               NGP, &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body,
                               0, 2, NULL, NULL, NULL, &gxi[0][0][0], SPRC_REFERENCE_SYMMETRIC);
  CHECK(rec != NULL && sprc_check_error(err) == 0, "recovery with symmetric reference coordinates failed");
  sprc_get_recovery_nodal_stress(err, rec, &nodal[0][0], NNODE);
  CHECK(nodal_deviation(&m, nodal) <= 5e-10, "nodal stresses with symmetric reference coordinates are not exact");
  sprc_delete_recovery(&rec);
  rec = sprc_recover_reference(err, 2, SPRC_PLANE_STRESS, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0],
                               NGP, &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body,
                               0, 2, NULL, NULL, NULL, &gxi[0][0][0], SPRC_REFERENCE_UNIT);
  CHECK(rec == NULL && has_error(err, ") is outside the reference cell [0, 1]^2 (reference 'unit'"),
        "symmetric coordinates read as unit: no error naming the convention");
  rec = sprc_recover_reference(err, 2, SPRC_PLANE_STRESS, NNODE, &m.nodes[0][0], SPRC_QUAD4, 4, NELEM, &m.conn[0][0],
                               NGP, &m.gp[0][0][0], &m.gw[0][0], &m.gs[0][0][0], 1000.0, 0.3, SPRC_METHOD_SPRC, m.body,
                               0, 2, NULL, NULL, NULL, &gxi[0][0][0], 5);
  CHECK(rec == NULL && has_error(err, "reference = 5 is not SPRC_REFERENCE_UNIT (0) or SPRC_REFERENCE_SYMMETRIC (1)"),
        "an unknown reference code was accepted");
  sprc_delete_error(&err);
  PASS();
}


/* ------------------------------------------------ fields of a study */

/* One dataset of an HDF5 file: its dims and values (double or int), or
 * ndims = -1 when it cannot be read. */
typedef struct {
  int ndims;
  hsize_t dims[2];
  double *reals;
  int *ints;
} h5_data;

static h5_data read_dataset(const char *file, const char *path, int is_int) {
  h5_data d = {-1, {0, 0}, NULL, NULL};
  hid_t f, ds, sp;
  size_t n = 1;
  int k;
  H5E_auto2_t func;
  void *data;
  H5Eget_auto2(H5E_DEFAULT, &func, &data);
  H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
  f = H5Fopen(file, H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f >= 0) {
    ds = H5Dopen2(f, path, H5P_DEFAULT);
    if (ds >= 0) {
      sp = H5Dget_space(ds);
      d.ndims = H5Sget_simple_extent_ndims(sp);
      if (d.ndims >= 1 && d.ndims <= 2) {
        H5Sget_simple_extent_dims(sp, d.dims, NULL);
        for (k = 0; k < d.ndims; k++) n *= (size_t)d.dims[k];
        if (is_int) {
          d.ints = malloc(n * sizeof(int) + 1);
          if (H5Dread(ds, H5T_NATIVE_INT, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.ints) < 0) d.ndims = -1;
        } else {
          d.reals = malloc(n * sizeof(double) + 1);
          if (H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, d.reals) < 0) d.ndims = -1;
        }
      } else {
        d.ndims = -1;
      }
      H5Sclose(sp);
      H5Dclose(ds);
    }
    H5Fclose(f);
  }
  H5Eset_auto2(H5E_DEFAULT, func, data);
  return d;
}

static void free_dataset(h5_data *d) {
  free(d->reals);
  free(d->ints);
  d->reals = NULL;
  d->ints = NULL;
}

/* The HDF5 dataset of a field of grid at level: mesh/x, mesh/connectivity,
 * node/<name> or cell/<name> (which one exists). */
static h5_data field_dataset(const char *file, int level, const char *grid, const char *field, int is_int) {
  char path[512];
  h5_data d;
  const char *where[2] = {"node", "cell"};
  int k;
  if (strcmp(field, "nodes") == 0 || strcmp(field, "points") == 0) {
    snprintf(path, sizeof path, "/level_%02d/%s/mesh/x", level, grid);
    return read_dataset(file, path, 0);
  }
  if (strcmp(field, "cells") == 0) {
    snprintf(path, sizeof path, "/level_%02d/%s/mesh/connectivity", level, grid);
    return read_dataset(file, path, 1);
  }
  for (k = 0; k < 2; k++) {
    snprintf(path, sizeof path, "/level_%02d/%s/%s/%s", level, grid, where[k], field);
    d = read_dataset(file, path, is_int);
    if (d.ndims > 0) return d;
  }
  return d;
}

/* Every field of every grid of every row of study equals its dataset in
 * file bit for bit (a padded 2-D vector: its first columns, the third
 * zero); the file holds no field of those grids that the study lacks (the
 * counts of fields agree). Returns the number of values compared, or -1
 * with why[] set. */
static long compare_with_hdf5(sprc_error err, sprc_study study, int nrows, const char *file, char *why, size_t nwhy) {
  long compared = 0;
  int row, g, f, k, c, ngrid, nfield, shape[2], type, level;
  char grid[128], field[128];
  int size_grid = (int)sizeof grid, size_field = (int)sizeof field;
  sprc_report rep = sprc_get_study_report(err, study);
  for (row = 0; row < nrows; row++) {
    level = (int)sprc_get_report_value(err, rep, row, "level");
    ngrid = sprc_get_study_grids(err, study, row);
    if (ngrid <= 0) {
      snprintf(why, nwhy, "row %d: %d grids", row, ngrid);
      sprc_delete_report(&rep);
      return -1;
    }
    for (g = 0; g < ngrid; g++) {
      sprc_get_study_grid(err, study, row, g, grid, &size_grid);
      nfield = sprc_get_study_fields(err, study, row, grid);
      for (f = 0; f < nfield; f++) {
        h5_data d;
        size_t n, cols_h5;
        double *vr = NULL;
        int *vi = NULL, bad = 0;
        sprc_get_study_field_name(err, study, row, grid, f, field, &size_field);
        type = sprc_get_study_field_shape(err, study, row, grid, field, shape);
        n = (size_t)shape[0] * (size_t)shape[1];
        d = field_dataset(file, level, grid, field, type == SPRC_FIELD_INT);
        cols_h5 = d.ndims == 2 ? (size_t)d.dims[1] : 1;
        if (d.ndims < 0 || (size_t)d.dims[0] != (size_t)shape[0] ||
            !(cols_h5 == (size_t)shape[1] || (cols_h5 == 3 && shape[1] == 2))) {
          snprintf(why, nwhy, "level %d %s/%s: shape %dx%d, HDF5 %s", level, grid, field, shape[0], shape[1],
                   d.ndims < 0 ? "unreadable" : "differs");
          free_dataset(&d);
          sprc_delete_report(&rep);
          return -1;
        }
        if (type == SPRC_FIELD_REAL) {
          vr = malloc(n * sizeof(double) + 1);
          sprc_get_study_field(err, study, row, grid, field, vr, (int)n);
        } else {
          vi = malloc(n * sizeof(int) + 1);
          sprc_get_study_field_int(err, study, row, grid, field, vi, (int)n);
        }
        for (k = 0; k < shape[0] && !bad; k++) {
          for (c = 0; c < (int)cols_h5; c++) {
            if (type == SPRC_FIELD_REAL) {
              double h = d.reals[(size_t)k * cols_h5 + c], zero = 0.0;
              /* bit for bit: NaN (empty) against NaN with the same bits too */
              if (memcmp(c < shape[1] ? &vr[(size_t)k * shape[1] + c] : &zero, &h, sizeof h) != 0) bad = 1;
            } else if (vi[(size_t)k * shape[1] + c] != d.ints[(size_t)k * cols_h5 + c]) {
              bad = 1;
            }
          }
        }
        compared += (long)n;
        free(vr);
        free(vi);
        free_dataset(&d);
        if (bad || sprc_check_error(err) != 0) {
          snprintf(why, nwhy, "level %d %s/%s differs from the HDF5 dataset at row %d", level, grid, field, k - 1);
          sprc_delete_report(&rep);
          return -1;
        }
      }
    }
  }
  sprc_delete_report(&rep);
  return compared;
}

/* Run the driver on scene at levels ("3,4") into dir/out.*; 0 on success. */
static int run_driver(const char *scene, const char *levels, const char *dir) {
  char cmd[4096];
  const char *driver = getenv("SPRC_DRIVER");
  if (driver == NULL || driver[0] == '\0') return -1;
  snprintf(cmd, sizeof cmd, "mkdir -p '%s' && '%s' run '%s' --levels %s --output '%s/out' --quiet >/dev/null 2>&1",
           dir, driver, scene, levels, dir);
  return system(cmd);
}

/* The fields of sprc_run_study for a scene against the driver's HDF5. */
static void study_against_hdf5(const char *name, const char *scene_rel, const char *levels_text, const int *levels,
                               int nlevels, int min_grids) {
  char scene[1024], dir[1024], file[1100], why[512] = "";
  const char *tmp = getenv("TMPDIR");
  sprc_error err = sprc_new_error();
  sprc_study study;
  long n;
  snprintf(scene, sizeof scene, "%s/%s", root, scene_rel);
  snprintf(dir, sizeof dir, "%s/sprc-capi-%s-%ld", tmp ? tmp : "/tmp", name, (long)getpid());
  snprintf(file, sizeof file, "%s/out.h5", dir);
  CHECK(getenv("SPRC_DRIVER") != NULL, "SPRC_DRIVER is not set (the driver built with this library)");
  CHECK(run_driver(scene, levels_text, dir) == 0, "the driver failed on the scene");
  study = sprc_run_study(err, scene, levels, nlevels, NULL, 0, 0);
  CHECK(study != NULL, "sprc_run_study failed");
  CHECK(sprc_get_study_grids(err, study, 0) >= min_grids, "fewer grids than bodies and contact pairs");
  n = compare_with_hdf5(err, study, nlevels, file, why, sizeof why);
  if (n < 0) printf("     %s\n", why);
  CHECK(n > 0, "a field differs from the driver's HDF5 dataset");
  sprc_delete_study(&study);
  CHECK(study == NULL, "sprc_delete_study did not null the handle");
  sprc_delete_error(&err);
  snprintf(why, sizeof why, "rm -rf '%s'", dir);
  if (system(why) != 0) printf("     could not remove %s\n", dir);
  printf("     %ld values equal\n", n);
  PASS();
}

static void test_study_fields_2d(void) {
  const int levels[2] = {3, 4};
  study_against_hdf5("study_fields_2d_lame_cylinder", "example/scenes/lame_cylinder.nml", "3,4", levels, 2, 1);
}

static void test_study_fields_3d(void) {
  const int levels[1] = {2};
  study_against_hdf5("study_fields_3d_lame_sphere", "example/scenes/lame_sphere.nml", "2", levels, 1, 1);
}

static void test_study_fields_contact(void) {
  const int levels[1] = {3};
  study_against_hdf5("study_fields_contact_shrink_fit", "example/scenes/shrink_fit.nml", "3", levels, 1, 3);
}

/* Bad requests are clean errors; kept levels only; NULL handles. */
static void test_study_bad_requests(void) {
  const char *name = "study_bad_requests";
  char path[1024], buf[64] = "junk";
  int levels[2] = {3, 4}, keep[1] = {4}, bad_keep[1] = {5}, shape[2] = {-7, -7}, size = (int)sizeof buf;
  int cells[4] = {-5, -5, -5, -5};
  double x[4] = {7.0, 7.0, 7.0, 7.0};
  sprc_error err = sprc_new_error();
  sprc_study study = NULL;
  sprc_report rep;
  snprintf(path, sizeof path, "%s/example/scenes/lame_cylinder.nml", root);
  CHECK(sprc_run_study(NULL, path, levels, 2, keep, 1, 0) == NULL, "sprc_run_study without an error handle");
  CHECK(sprc_run_study(err, path, levels, 2, bad_keep, 1, 0) == NULL, "keep = 5 of levels 3,4 gave a study");
  CHECK(has_error(err, "level 5 is not one of the levels run (3, 4)"), "keep = 5: no error naming it");
  CHECK(sprc_run_study(err, path, levels, 2, NULL, 1, 0) == NULL, "NULL keep with nkeep = 1 gave a study");
  CHECK(has_error(err, "keep must be NULL"), "NULL keep with nkeep = 1: no error");
  CHECK(sprc_run_study(err, path, levels, 2, keep, 1, -1) == NULL, "threads = -1 gave a study");
  CHECK(has_error(err, "threads = -1"), "threads = -1: no error");
  CHECK(sprc_run_scene_threads(err, path, levels, 2, -2) == NULL, "sprc_run_scene_threads(-2) gave a report");
  CHECK(has_error(err, "threads = -2"), "sprc_run_scene_threads(-2): no error");
  CHECK(sprc_run_study(err, NULL, levels, 2, keep, 1, 0) == NULL && has_error(err, "path is NULL"), "NULL path");
  CHECK(sprc_get_study_grids(err, NULL, 0) == -1 && has_error(err, "study handle is NULL"), "NULL study");
  CHECK(sprc_get_study_report(err, NULL) == NULL && has_error(err, "study handle is NULL"), "NULL study report");
  sprc_get_study_field(err, NULL, 0, "pipe", "nodes", x, 4);
  CHECK(has_error(err, "study handle is NULL") && x[0] == 7.0, "NULL study field");
  sprc_delete_study(&study);
  sprc_delete_study(NULL);

  study = sprc_run_study(err, path, levels, 2, keep, 1, 1);
  CHECK(study != NULL && sprc_check_error(err) == 0, "sprc_run_study of levels 3,4 keeping 4 failed");
  rep = sprc_get_study_report(err, study);
  CHECK(rep != NULL && sprc_get_report_rows(err, rep) == 2, "the study's report has not 2 rows");
  sprc_delete_report(&rep);
  CHECK(sprc_get_study_grids(err, study, 0) == -1, "row 0 (level 3, not kept) has grids");
  CHECK(has_error(err, "row 0 (level 3) were not kept"), "row 0 not kept: no error saying so");
  CHECK(sprc_get_study_grids(err, study, 2) == -1 && has_error(err, "row 2 is out of range 0..1"), "row 2 of 2");
  CHECK(sprc_get_study_grids(err, study, -1) == -1 && has_error(err, "row -1 is out of range"), "row -1");
  CHECK(sprc_get_study_grids(err, study, 1) == 1, "row 1 (level 4) has not 1 grid");
  CHECK(sprc_get_study_grid(err, study, 1, 0, buf, &size) == 0, "grid 0 is not a body");
  CHECK(sprc_get_study_grid(err, study, 1, 1, buf, &size) == -1 && has_error(err, "grid index 1 is out of range"),
        "grid index 1 of 1");
  CHECK(sprc_get_study_fields(err, study, 1, "nobody") == -1, "an unknown body has fields");
  CHECK(has_error(err, "no body or contact pair named \"nobody\" (grids: "), "unknown body: no error listing grids");
  CHECK(sprc_get_study_fields(err, study, 1, NULL) == -1 && has_error(err, "grid name is NULL"), "NULL grid name");
  CHECK(sprc_get_study_field_shape(err, study, 1, buf, "stress", shape) == -1, "an unknown field has a shape");
  CHECK(has_error(err, "has no field \"stress\" at row 1 (fields: nodes, cells, displacement"),
        "unknown field: no error listing the fields");
  CHECK(shape[0] == -7, "shape written for an unknown field");
  CHECK(sprc_get_study_field_shape(err, study, 1, buf, "nodes", NULL) == -1 && has_error(err, "shape is NULL"),
        "NULL shape");
  CHECK(sprc_get_study_field_shape(err, study, 1, buf, "cells", shape) == SPRC_FIELD_INT && shape[1] == 4,
        "cells are not int [n][4] for the Q1 example");
  sprc_get_study_field(err, study, 1, buf, "cells", x, 4);
  CHECK(has_error(err, "holds integers: read it with sprc_get_study_field_int") && x[0] == 7.0,
        "an int field read as double");
  sprc_get_study_field_int(err, study, 1, buf, "displacement", cells, 4);
  CHECK(has_error(err, "holds doubles") && cells[0] == -5, "a real field read as int");
  sprc_get_study_field_int(err, study, 1, buf, "cells", cells, 4);
  CHECK(has_error(err, "n = 4 but field \"cells\""), "a wrong n: no error");
  CHECK(sprc_get_study_field_shape(err, study, 1, buf, "nodes", shape) == SPRC_FIELD_REAL && shape[1] == 2,
        "nodes are not double [n][2]");
  sprc_get_study_field(err, study, 1, buf, "nodes", NULL, shape[0] * shape[1]);
  CHECK(has_error(err, "values is NULL"), "NULL values: no error");
  sprc_get_study_field_name(err, study, 1, buf, 99, buf, &size);
  CHECK(has_error(err, "field index 99 is out of range"), "field index 99: no error");
  sprc_delete_study(&study);
  CHECK(study == NULL, "sprc_delete_study did not null the handle");
  sprc_delete_error(&err);
  PASS();
}

/* Two bodies in contact: the quad mesh of the unit square (slave, field 2: a
 * uniform compression, sigma_xy = 0) and the same mesh moved up by 1 (master);
 * the slave's top side against the master's bottom side. */
typedef struct {
  quad_mesh a, b;
  int top[M][2], bottom[M][2], law[M], slip_law[M];
  double slip[M][2];
} contact_case;

static void build_contact_case(contact_case *c) {
  int i, e, q;
  build_quad_mesh(&c->a, 2);
  build_quad_mesh(&c->b, 2);
  for (i = 0; i < NNODE; i++) c->b.nodes[i][1] += 1.0;
  for (e = 0; e < NELEM; e++)
    for (q = 0; q < NGP; q++) c->b.gp[e][q][1] += 1.0;
  for (i = 0; i < M; i++) {
    c->top[i][0] = i + (M + 1) * M;
    c->top[i][1] = i + 1 + (M + 1) * M;
    c->bottom[i][0] = i + 1;
    c->bottom[i][1] = i;
    c->law[i] = SPRC_CONTACT_FRICTIONLESS;
    c->slip_law[i] = SPRC_CONTACT_SLIP;
    c->slip[i][0] = 1.0;
    c->slip[i][1] = 0.0;
  }
}

static int add_quad_body(sprc_error err, sprc_contact_input in, const quad_mesh *m) {
  return sprc_contact_add_body(err, in, 2, SPRC_PLANE_STRESS, NNODE, &m->nodes[0][0], SPRC_QUAD4, 4, NELEM,
                               &m->conn[0][0], NGP, &m->gp[0][0][0], &m->gw[0][0], &m->gs[0][0][0], 1000.0, 0.3,
                               NULL, 0, 2, NULL, NULL, NULL, NULL, SPRC_REFERENCE_UNIT);
}

/* A frictionless pair: the recovered pressure is the exact 3 on both sides,
 * the jump zero, the bodies readable as recoveries. */
static void test_contact_recovery(void) {
  const char *name = "contact_recovery";
  static contact_case c;
  double x[2 * M][2], p[2 * M], pm[2 * M], jump[2 * M][2], nodal[NNODE][3], dev = 0.0;
  int i, k;
  sprc_error err = sprc_new_error();
  sprc_contact_input in = sprc_new_contact_input(err);
  sprc_contact_recovery rec;
  sprc_recovery body;
  build_contact_case(&c);
  CHECK(add_quad_body(err, in, &c.a) == 0, "first body is not 0");
  CHECK(add_quad_body(err, in, &c.b) == 1, "second body is not 1");
  CHECK(sprc_contact_add_pair(err, in, 0, 1, M, &c.top[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0,
                              NULL) == 0, "pair is not 0");
  rec = sprc_recover_contact(err, in, SPRC_METHOD_SPRC);
  CHECK(rec != NULL && sprc_check_error(err) == 0, "sprc_recover_contact failed");
  CHECK(sprc_get_contact_points(err, rec, 0) == 2 * M, "not 2 points per facet");
  sprc_get_contact_pair(err, rec, 0, 2 * M, &x[0][0], NULL, NULL, p, pm, NULL, NULL, &jump[0][0]);
  CHECK(sprc_check_error(err) == 0, "sprc_get_contact_pair failed");
  for (i = 0; i < 2 * M; i++) {
    dev = fmax(dev, fmax(fabs(p[i] - 3.0), fabs(pm[i] - 3.0)));
    dev = fmax(dev, fmax(fabs(jump[i][0]), fabs(jump[i][1])));
    CHECK(fabs(x[i][1] - 1.0) < 1e-14, "a contact point is not on y = 1");
  }
  CHECK(dev < 1e-12, "pressure or jump off the exact values");
  for (k = 0; k < 2; k++) {
    body = sprc_get_contact_body(err, rec, k);
    CHECK(body != NULL, "sprc_get_contact_body failed");
    sprc_get_recovery_nodal_stress(err, body, &nodal[0][0], NNODE);
    for (i = 0; i < NNODE; i++) dev = fmax(dev, fabs(nodal[i][1] + 3.0) + fabs(nodal[i][2]));
    sprc_delete_recovery(&body);
  }
  CHECK(dev < 1e-12, "a body's nodal stress is off the exact field");
  sprc_delete_contact_recovery(&rec);
  sprc_delete_contact_input(&in);
  CHECK(in == NULL && rec == NULL, "delete did not clear the handles");
  sprc_delete_contact_input(NULL);
  sprc_delete_contact_recovery(NULL);
  sprc_delete_error(&err);
  PASS();
}

/* Malformed contact calls, one at a time: each a clean error naming it. */
static void test_contact_bad_input(void) {
  const char *name = "contact_bad_input";
  static contact_case c;
  static quad_mesh nan_mesh;
  int inner[1][2] = {{1, 1 + (M + 1)}}, diag[1][2] = {{0, M + 2}}, far[1][2] = {{0, 1000000}}, bad_law[M];
  double nan_slip[M][2], x[2 * M][2];
  sprc_error err = sprc_new_error();
  sprc_contact_input in = sprc_new_contact_input(err);
  sprc_contact_recovery rec;
  int i;
  build_contact_case(&c);
  nan_mesh = c.b;
  nan_mesh.gs[2][1][0] = NAN;
  for (i = 0; i < M; i++) {
    bad_law[i] = 7;
    nan_slip[i][0] = NAN;
    nan_slip[i][1] = 0.0;
  }
#define CONTACT_FAILS(call, text)                                                              \
  do {                                                                                         \
    (void)(call);                                                                              \
    CHECK(sprc_get_error_status(err) == SPRC_STAT_INVALID_INPUT, "not invalid input: " text); \
    CHECK(has_error(err, text), "no error saying: " text);                                     \
  } while (0)
  CONTACT_FAILS(sprc_contact_add_body(err, NULL, 2, 1, NNODE, &c.a.nodes[0][0], 9, 4, NELEM, &c.a.conn[0][0], NGP,
                                      &c.a.gp[0][0][0], &c.a.gw[0][0], &c.a.gs[0][0][0], 1e3, 0.3, NULL, 0, 2, NULL,
                                      NULL, NULL, NULL, 0),
                "contact input handle is NULL");
  CONTACT_FAILS(sprc_contact_add_body(err, in, 4, 1, NNODE, &c.a.nodes[0][0], 9, 4, NELEM, &c.a.conn[0][0], NGP,
                                      &c.a.gp[0][0][0], &c.a.gw[0][0], &c.a.gs[0][0][0], 1e3, 0.3, NULL, 0, 2, NULL,
                                      NULL, NULL, NULL, 0),
                "bodies[0]: dim = 4");
  CONTACT_FAILS(sprc_contact_add_body(err, in, 2, 1, NNODE, NULL, 9, 4, NELEM, &c.a.conn[0][0], NGP,
                                      &c.a.gp[0][0][0], &c.a.gw[0][0], &c.a.gs[0][0][0], 1e3, 0.3, NULL, 0, 2, NULL,
                                      NULL, NULL, NULL, 0),
                "nodes is NULL");
  CONTACT_FAILS(sprc_contact_add_body(err, in, 2, 1, NNODE - 5, &c.a.nodes[0][0], 9, 4, NELEM, &c.a.conn[0][0], NGP,
                                      &c.a.gp[0][0][0], &c.a.gw[0][0], &c.a.gs[0][0][0], 1e3, 0.3, NULL, 0, 2, NULL,
                                      NULL, NULL, NULL, 0),
                "connectivity[");
  CONTACT_FAILS(sprc_contact_add_body(err, in, 2, 1, NNODE, &c.a.nodes[0][0], 9, 4, NELEM, &c.a.conn[0][0], NGP,
                                      &c.a.gp[0][0][0], &c.a.gw[0][0], &c.a.gs[0][0][0], 1e3, 0.3, NULL, 0, 2, NULL,
                                      NULL, NULL, NULL, 5),
                "reference = 5");
  CHECK(add_quad_body(err, in, &c.a) == 0, "first body is not 0");
  CHECK(add_quad_body(err, in, &nan_mesh) == 1, "second body is not 1");
  CHECK(add_quad_body(err, in, &c.b) == 2, "third body is not 2");
  CONTACT_FAILS(sprc_contact_add_pair(err, in, 5, 1, M, &c.top[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL,
                                      0.0, NULL),
                "pairs[0].slave = 5");
  CONTACT_FAILS(sprc_contact_add_pair(err, in, 0, 2, M, &c.top[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL,
                                      -0.5, NULL),
                "pairs[0].mu must be finite and >= 0");
  CONTACT_FAILS(sprc_contact_add_pair(err, in, 0, 2, M, &c.top[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL,
                                      NAN, NULL),
                "pairs[0].mu must be finite");
  CONTACT_FAILS(sprc_contact_add_pair(err, in, 0, 2, M, &c.top[0][0], c.law, NULL, 0, &c.bottom[0][0], c.law, NULL,
                                      0.0, NULL),
                "contact facets on both sides");
  CONTACT_FAILS(sprc_contact_add_pair(err, in, 0, 2, M, NULL, c.law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0,
                                      NULL),
                "slave_facets or slave_law is NULL");
  CONTACT_FAILS(sprc_contact_add_pair(err, in, 0, 2, 1, &far[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL,
                                      0.0, NULL),
                "pairs[0].slave_facets[0][1] = 1000000");
  /* Errors found when recovering: one pair at a time in a fresh input. */
#define PAIR_FAILS(slave, master, ns, sf, sl, ss, nm, mf, ml, ms, mu, text)                               \
  do {                                                                                                     \
    sprc_contact_input in2 = sprc_new_contact_input(err);                                                  \
    add_quad_body(err, in2, &c.a);                                                                         \
    add_quad_body(err, in2, &c.b);                                                                         \
    if ((master) == 2) add_quad_body(err, in2, &nan_mesh);                                                 \
    if (sprc_contact_add_pair(err, in2, slave, master, ns, sf, sl, ss, nm, mf, ml, ms, mu, NULL) == 0) { \
      rec = sprc_recover_contact(err, in2, SPRC_METHOD_SPRC);                                              \
      CHECK(rec == NULL, "a recovery came back: " text);                                                   \
    }                                                                                                      \
    sprc_delete_contact_input(&in2);                                                                       \
    CHECK(sprc_get_error_status(err) == SPRC_STAT_INVALID_INPUT, "not invalid input: " text);             \
    CHECK(has_error(err, text), "no error saying: " text);                                                 \
  } while (0)
  PAIR_FAILS(0, 0, M, &c.top[0][0], c.law, NULL, M, &c.top[0][0], c.law, NULL, 0.0, "a pair needs two bodies");
  PAIR_FAILS(0, 1, M, &c.top[0][0], bad_law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0,
             "pairs[0].slave_law[0] = 7");
  PAIR_FAILS(0, 1, M, &c.top[0][0], c.slip_law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.3, "slave_slip");
  PAIR_FAILS(0, 1, M, &c.top[0][0], c.slip_law, &nan_slip[0][0], M, &c.bottom[0][0], c.law, NULL, 0.3,
             "pairs[0].slave_slip is not finite");
  PAIR_FAILS(0, 1, 1, &inner[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0, "not a boundary facet");
  PAIR_FAILS(0, 1, 1, &diag[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0, "not a side of any element");
  PAIR_FAILS(0, 1, M, &c.top[0][0], c.law, NULL, 1, &far[0][0], c.law, NULL, 0.0,
             "pairs[0].master_facets[0][1] = 1000000 is not a node in 0..24 of bodies[1]");
  /* A facet of the wrong body: the slave's top side given as the master's (nodes of the master's top). */
  PAIR_FAILS(0, 1, M, &c.top[0][0], c.law, NULL, M, &c.top[0][0], c.law, NULL, 0.0, "do not face each other");
  PAIR_FAILS(0, 2, M, &c.top[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0, "bodies[2]");
  {
    sprc_contact_input in3 = sprc_new_contact_input(err);
    add_quad_body(err, in3, &c.a);
    add_quad_body(err, in3, &c.b);
    sprc_contact_add_pair(err, in3, 0, 1, M, &c.top[0][0], c.law, NULL, M, &c.bottom[0][0], c.law, NULL, 0.0, NULL);
    CONTACT_FAILS(sprc_recover_contact(err, in3, 9), "method = 9");
    CONTACT_FAILS(sprc_recover_contact(err, in3, SPRC_METHOD_SPRC | 2048), "unknown flag bits");
    CONTACT_FAILS(sprc_recover_contact(err, in3, SPRC_METHOD_SPRC | SPRC_RECOVERY_P | SPRC_RECOVERY_P_PLUS_1),
                  "sets both SPRC_RECOVERY_P_PLUS_1 and SPRC_RECOVERY_P");
    CONTACT_FAILS(sprc_recover_contact(err, in3, 3 | SPRC_RECOVERY_P),
                  "is not SPRC_METHOD_SPR (1) or SPRC_METHOD_SPRC");
    rec = sprc_recover_contact(err, in3, SPRC_METHOD_SPRC | SPRC_RECOVERY_P_PLUS_1);
    CHECK(rec != NULL, "SPRC_RECOVERY_P_PLUS_1 failed");
    sprc_delete_contact_recovery(&rec);
    rec = sprc_recover_contact(err, in3, SPRC_METHOD_SPRC | SPRC_CONTACT_NO_EDGES | SPRC_RECOVERY_P);
    CHECK(rec != NULL, "SPRC_CONTACT_NO_EDGES failed");
    sprc_delete_contact_recovery(&rec);
    rec = sprc_recover_contact(err, in3, SPRC_METHOD_SPRC);
    CHECK(rec != NULL, "the good input failed");
    CONTACT_FAILS(sprc_get_contact_pair(err, rec, 0, 3, &x[0][0], NULL, NULL, NULL, NULL, NULL, NULL, NULL),
                  "npoints = 3");
    CONTACT_FAILS(sprc_get_contact_pair(err, rec, 4, 2 * M, &x[0][0], NULL, NULL, NULL, NULL, NULL, NULL, NULL),
                  "pair = 4");
    CONTACT_FAILS(sprc_get_contact_body(err, rec, 2), "body = 2");
    CONTACT_FAILS(sprc_get_contact_points(err, NULL, 0), "contact recovery handle is NULL");
    sprc_delete_contact_recovery(&rec);
    sprc_delete_contact_input(&in3);
  }
  sprc_delete_contact_input(&in);
  sprc_delete_error(&err);
  PASS();
}

int main(int argc, char **argv) {
  /* `fpm test -- SUITE` passes the unit tests' suite name to every test
     program: take argv[1] as the root only if it holds example/scenes. */
  if (argc > 1) {
    char probe[4096];
    struct stat st;
    snprintf(probe, sizeof probe, "%s/example/scenes", argv[1]);
    if (stat(probe, &st) == 0 && S_ISDIR(st.st_mode)) root = argv[1];
  }
  test_version();
  test_error_lifecycle();
  test_null_error_handle();
  test_null_report_handle();
  test_error_buffer();
  test_run_bad_arguments();
  test_run_lame();
  test_run_adaptive();
  test_run_invalid_scene();
  test_recovery_null_handles();
  test_recovery_bad_input();
  test_recovery_bad_output();
  test_recovery_linear_quad4();
  test_recovery_degree_flag();
  test_recovery_facets();
  test_recovery_pressure_facets();
  test_recovery_given_xi();
  test_contact_recovery();
  test_contact_bad_input();
  test_study_bad_requests();
  test_study_fields_2d();
  test_study_fields_3d();
  test_study_fields_contact();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
