/* Run a scene through the sprc C API and print its report as CSV (empty
 * cells empty).
 *
 *   cc run_scene.c $(pkg-config --cflags --libs sprc) -o run_scene
 *   ./run_scene example/scenes/lame_cylinder.nml 3 4
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "sprc.h"

int main(int argc, char **argv) {
  int levels[32], nlevels = 0, nrows, ncols, i, j;
  char name[64], message[1024];
  int name_size = (int)sizeof name, message_size = (int)sizeof message;
  sprc_error error;
  sprc_report report;

  if (argc < 2 || argc > 2 + 32) {
    fprintf(stderr, "usage: %s SCENE.nml [LEVEL...]\n", argv[0]);
    return 2;
  }
  if (sprc_get_version() != SPRC_VERSION) {
    fprintf(stderr, "run_scene: compiled against sprc %d, running with %d\n", SPRC_VERSION, sprc_get_version());
    return 1;
  }
  for (i = 2; i < argc; i++) levels[nlevels++] = atoi(argv[i]);

  error = sprc_new_error();
  report = sprc_run_scene(error, argv[1], nlevels > 0 ? levels : NULL, nlevels);
  if (report == NULL) {
    sprc_get_error(error, message, &message_size);
    fprintf(stderr, "run_scene: %s\n", message);
    sprc_delete_error(&error);
    return 1;
  }

  nrows = sprc_get_report_rows(error, report);
  ncols = sprc_get_report_columns(error, report);
  for (j = 0; j < ncols; j++) {
    sprc_get_report_column(error, report, j, name, &name_size);
    printf("%s%s", j ? "," : "", name);
  }
  printf("\n");
  for (i = 0; i < nrows; i++) {
    for (j = 0; j < ncols; j++) {
      double x;
      sprc_get_report_column(error, report, j, name, &name_size);
      x = sprc_get_report_value(error, report, i, name);
      if (j) printf(",");
      if (!isnan(x)) printf("%.17g", x);
    }
    printf("\n");
  }
  j = sprc_check_error(error);
  if (j != 0) {
    sprc_get_error(error, message, &message_size);
    fprintf(stderr, "run_scene: %s\n", message);
  }
  sprc_delete_report(&report);
  sprc_delete_error(&error);
  return j == 0 ? 0 : 1;
}
