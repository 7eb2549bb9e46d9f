/* Tests of the C API (include/sprc.h): every entry point with NULL handles,
 * NULL pointers and wrong sizes (an error comes back, nothing crashes), the
 * error buffer contract, and a real run of the Lamé cylinder example.
 * Prints one line per test and 'N passed, M failed' last; exits 1 on failure.
 * Usage: capi [ROOT]  (the project root holding example/ and test/; default .) */
#include <math.h>
#include <stdio.h>
#include <string.h>

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
  CHECK(sprc_get_report_columns(err, rep) == 19, "not the 19 report columns");
  sprc_get_report_column(err, rep, 0, col, &size);
  CHECK(strcmp(col, "level") == 0, "column 0 is not 'level'");
  sprc_get_report_column(err, rep, 18, col, &size);
  CHECK(strcmp(col, "theta_sprc") == 0, "column 18 is not 'theta_sprc'");
  sprc_get_report_column(err, rep, 12, col, &tiny);
  CHECK(strcmp(col, "er") == 0, "a truncated column name is not 'er'");
  sprc_get_report_column(err, rep, 19, col, &size);
  CHECK(has_error(err, "out of range"), "no error for column index 19");
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

static void test_run_invalid_scene(void) {
  const char *name = "run_invalid_scene";
  char path[1024];
  sprc_error err = sprc_new_error();
  snprintf(path, sizeof path, "%s/test/data/scenes/bad/poisson_half.nml", root);
  CHECK(sprc_run_scene(err, path, NULL, 0) == NULL, "an invalid scene gave a report");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_INVALID_INPUT, "an invalid scene is not SPRC_STAT_INVALID_INPUT");
  CHECK(has_error(err, "poisson"), "the message does not name the bad field");
  /* A valid scene this version cannot run: two bodies in contact. */
  snprintf(path, sizeof path, "%s/test/data/scenes/valid/contact_punch.nml", root);
  CHECK(sprc_run_scene(err, path, NULL, 0) == NULL, "a contact scene gave a report");
  CHECK(sprc_get_error_status(err) == SPRC_STAT_UNSUPPORTED, "a contact scene is not SPRC_STAT_UNSUPPORTED");
  CHECK(has_error(err, "contact"), "the message does not name contact");
  sprc_delete_error(&err);
  PASS();
}

int main(int argc, char **argv) {
  if (argc > 1) root = argv[1];
  test_version();
  test_error_lifecycle();
  test_null_error_handle();
  test_null_report_handle();
  test_error_buffer();
  test_run_bad_arguments();
  test_run_lame();
  test_run_invalid_scene();
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
