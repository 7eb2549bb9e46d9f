/* SPR-C recovery on your own mesh through the sprc C API: a 4 x 2 quad4 mesh
 * of [0,2] x [0,1] with one interior node moved, 2x2 Gauss points, and FE
 * stresses given at the points (here a smooth field plus a jump between
 * elements, as a piecewise FE field has). Prints the recovered nodal
 * stresses, the element errors and the global ZZ estimate.
 *
 *   cc recovery.c $(pkg-config --cflags --libs sprc) -o recovery && ./recovery
 */
#include <math.h>
#include <stdio.h>

#include "sprc.h"

#define NX 4
#define NY 2
#define NNODE ((NX + 1) * (NY + 1))
#define NELEM (NX * NY)
#define NGP 4

int main(void) {
  double nodes[NNODE][2], gp[NELEM][NGP][2], gw[NELEM][NGP], gs[NELEM][NGP][3];
  double nodal[NNODE][3], elem_err[NELEM];
  int conn[NELEM][4], i, j, e, q, a;
  const double g = 0.5 / sqrt(3.0);
  const double xi[NGP][2] = {{0.5 - g, 0.5 - g}, {0.5 + g, 0.5 - g}, {0.5 + g, 0.5 + g}, {0.5 - g, 0.5 + g}};
  char message[1024];
  int message_size = (int)sizeof message;
  sprc_error error;
  sprc_recovery rec;

  for (j = 0; j <= NY; j++)
    for (i = 0; i <= NX; i++) {
      nodes[i + (NX + 1) * j][0] = 2.0 * i / NX;
      nodes[i + (NX + 1) * j][1] = 1.0 * j / NY;
    }
  nodes[2 + (NX + 1) * 1][0] += 0.1; /* a distorted mesh */
  nodes[2 + (NX + 1) * 1][1] -= 0.05;
  for (j = 0; j < NY; j++)
    for (i = 0; i < NX; i++) { /* counter-clockwise, VTK order, 0-based */
      int n = i + (NX + 1) * j;
      e = i + NX * j;
      conn[e][0] = n;
      conn[e][1] = n + 1;
      conn[e][2] = n + NX + 2;
      conn[e][3] = n + NX + 1;
    }
  /* Gauss points: bilinear map of the reference points, weight * |J|. */
  for (e = 0; e < NELEM; e++)
    for (q = 0; q < NGP; q++) {
      double r = xi[q][0], t = xi[q][1], jac[4] = {0, 0, 0, 0};
      double shp[4] = {(1 - r) * (1 - t), r * (1 - t), r * t, (1 - r) * t};
      double dr[4] = {-(1 - t), 1 - t, t, -t}, dt[4] = {-(1 - r), -r, r, 1 - r};
      double x, y;
      gp[e][q][0] = gp[e][q][1] = 0.0;
      for (a = 0; a < 4; a++) {
        const double *p = nodes[conn[e][a]];
        gp[e][q][0] += shp[a] * p[0];
        gp[e][q][1] += shp[a] * p[1];
        jac[0] += dr[a] * p[0];
        jac[1] += dt[a] * p[0];
        jac[2] += dr[a] * p[1];
        jac[3] += dt[a] * p[1];
      }
      gw[e][q] = 0.25 * fabs(jac[0] * jac[3] - jac[1] * jac[2]);
      x = gp[e][q][0];
      y = gp[e][q][1];
      gs[e][q][0] = 1.0 + x * y + 0.05 * (e % 2);
      gs[e][q][1] = 0.5 - 0.5 * y * y;
      gs[e][q][2] = 0.2 * x - 0.05 * (e % 3);
    }

  error = sprc_new_error();
  rec = sprc_recover(error, 2, SPRC_PLANE_STRESS, NNODE, &nodes[0][0], SPRC_QUAD4, 4, NELEM, &conn[0][0], NGP,
                     &gp[0][0][0], &gw[0][0], &gs[0][0][0], 210000.0, 0.3, SPRC_METHOD_SPRC, NULL, 0, 2, NULL, NULL,
                     NULL);
  if (rec == NULL) {
    sprc_get_error(error, message, &message_size);
    fprintf(stderr, "recovery: %s\n", message);
    sprc_delete_error(&error);
    return 1;
  }
  sprc_get_recovery_nodal_stress(error, rec, &nodal[0][0], NNODE);
  sprc_get_recovery_element_error(error, rec, elem_err, NELEM);
  printf("node          x          y     sxx        syy        sxy\n");
  for (i = 0; i < NNODE; i++)
    printf("%4d %10.4f %10.4f %10.6f %10.6f %10.6f\n", i, nodes[i][0], nodes[i][1], nodal[i][0], nodal[i][1],
           nodal[i][2]);
  printf("element errors:");
  for (e = 0; e < NELEM; e++) printf(" %.3e", elem_err[e]);
  printf("\nglobal error estimate: %.6e\n", sprc_get_recovery_global_error(error, rec));
  printf("relative error estimate (eta): %.6e\n", sprc_get_recovery_eta(error, rec));
  i = sprc_check_error(error);
  sprc_delete_recovery(&rec);
  sprc_delete_error(&error);
  return i == 0 ? 0 : 1;
}
