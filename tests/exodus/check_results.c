/* Reads a `results.exo` written by `seam run` with the Exodus II C library (libexodus)
 * and checks it against the input mesh, also opened with libexodus.
 *
 *   check_results MESH.exo RESULTS.exo DUMP.txt
 *
 * Checks, each with a message naming what differs:
 * - the sizes (dimension, nodes, elements, blocks, node sets, side sets);
 * - the coordinates and the node and element number maps, exactly;
 * - every element block: id, name, topology (the same shape; seam writes TETRA for
 *   TETRA4 as Cubit does), element count, nodes per element, connectivity; shell
 *   thickness attributes where the mesh has them;
 * - every side set (id, name, element and side lists) and node set (id, name, nodes);
 * - the variables: nodal `temperature`, element `heat_flux_x/_y/_z` (`_x/_y` in 2-D;
 *   stored on every non-empty block, by the truth table), global variables in `heat_side_a:…` /
 *   `heat_side_b:…` pairs; at least one step, finite non-decreasing times; every value
 *   finite; a QA record from seam.
 * Then writes DUMP.txt for tests/python/check_results.py, which compares it with
 * independent readers (VTK's reader of the `.vtu` files, interface_heat.csv):
 *   time STEP VALUE                     one line per step
 *   temperature NODE VALUE              the last step, NODE a 1-based position
 *   global STEP NAME VALUE              every global variable at every step
 * Exits 0 when all checks pass, 1 otherwise.
 *
 * Build: gcc -std=c99 -Wall -Wextra -Werror tests/exodus/check_results.c \
 *            -lexoIIv2c -lnetcdf -o target/check_results
 */
#include <ctype.h>
#include <exodusII.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int failures = 0;

#define FAIL(...)                 \
  do {                            \
    fprintf(stderr, "FAIL: ");    \
    fprintf(stderr, __VA_ARGS__); \
    fprintf(stderr, "\n");        \
    failures++;                   \
  } while (0)

#define CALL(call)                                                   \
  do {                                                               \
    if ((call) < 0) {                                                \
      fprintf(stderr, "FAIL: libexodus: %s failed\n", #call);        \
      exit(1);                                                       \
    }                                                                \
  } while (0)

static void *xcalloc(size_t n, size_t size) {
  void *p = calloc(n ? n : 1, size ? size : 1);
  if (!p) {
    fprintf(stderr, "out of memory\n");
    exit(1);
  }
  return p;
}

static int open_exo(const char *path) {
  int cws = 8, iows = 0;
  float version = 0;
  int id = ex_open(path, EX_READ, &cws, &iows, &version);
  if (id < 0) {
    fprintf(stderr, "FAIL: libexodus cannot open %s\n", path);
    exit(1);
  }
  return id;
}

/* Longest name the files use (`maximum_name_length`); names are read in full. */
static int name_len = MAX_STR_LENGTH;

static char **names_alloc(int n) {
  char **v = xcalloc((size_t)n + 1, sizeof *v);
  for (int i = 0; i <= n; i++) v[i] = xcalloc((size_t)name_len + 1, 1);
  return v;
}

/* Entity names; `kind` is EX_ELEM_BLOCK, EX_SIDE_SET, EX_NODE_SET. */
static char **names_of(int exo, ex_entity_type kind, int n) {
  char **v = names_alloc(n);
  if (n > 0) CALL(ex_get_names(exo, kind, v));
  return v;
}

/* The shape of an Exodus topology name: its leading letters, upper-cased. */
static void shape(const char *name, char *out) {
  int k = 0;
  for (; name[k] && isalpha((unsigned char)name[k]) && k < 31; k++)
    out[k] = (char)toupper((unsigned char)name[k]);
  out[k] = 0;
  if (strcmp(out, "TET") == 0) strcpy(out, "TETRA");
}

static void compare_ints(const char *what, const int *a, const int *b, int n) {
  for (int i = 0; i < n; i++)
    if (a[i] != b[i]) {
      FAIL("%s: entry %d is %d in the results, %d in the mesh", what, i + 1, b[i], a[i]);
      return;
    }
}

static int var_index(char **names, int n, const char *name) {
  for (int i = 0; i < n; i++)
    if (strcmp(names[i], name) == 0) return i + 1;
  return 0;
}

int main(int argc, char **argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: %s MESH.exo RESULTS.exo DUMP.txt\n", argv[0]);
    return 2;
  }
  int me = open_exo(argv[1]), re = open_exo(argv[2]);
  for (int f = 0; f < 2; f++) {
    int used = (int)ex_inquire_int(f ? re : me, EX_INQ_DB_MAX_USED_NAME_LENGTH);
    if (used > name_len) name_len = used;
  }
  CALL(ex_set_max_name_length(me, name_len));
  CALL(ex_set_max_name_length(re, name_len));
  char title[MAX_LINE_LENGTH + 1];
  int dim[2], nn[2], ne[2], nb[2], nns[2], nss[2];
  CALL(ex_get_init(me, title, &dim[0], &nn[0], &ne[0], &nb[0], &nns[0], &nss[0]));
  CALL(ex_get_init(re, title, &dim[1], &nn[1], &ne[1], &nb[1], &nns[1], &nss[1]));
  const char *sizes[6] = {"num_dim", "num_nodes", "num_elem", "num_el_blk", "num_node_sets",
                          "num_side_sets"};
  int *pairs[6] = {dim, nn, ne, nb, nns, nss};
  for (int k = 0; k < 6; k++)
    if (pairs[k][0] != pairs[k][1])
      FAIL("%s is %d in the results, %d in the mesh", sizes[k], pairs[k][1], pairs[k][0]);
  if (failures) return 1;
  int n = nn[0], d = dim[0];

  /* Coordinates and maps. */
  double *x[2][3];
  for (int f = 0; f < 2; f++) {
    for (int k = 0; k < 3; k++) x[f][k] = xcalloc((size_t)n, sizeof(double));
    CALL(ex_get_coord(f ? re : me, x[f][0], x[f][1], d == 3 ? x[f][2] : NULL));
  }
  for (int k = 0; k < d; k++)
    for (int i = 0; i < n; i++)
      if (x[0][k][i] != x[1][k][i]) {
        FAIL("coordinate %d of node %d is %.17g in the results, %.17g in the mesh", k, i + 1,
             x[1][k][i], x[0][k][i]);
        break;
      }
  int *map[2];
  for (int f = 0; f < 2; f++) {
    map[f] = xcalloc((size_t)n, sizeof(int));
    CALL(ex_get_id_map(f ? re : me, EX_NODE_MAP, map[f]));
  }
  compare_ints("node_num_map", map[0], map[1], n);
  for (int f = 0; f < 2; f++) {
    free(map[f]);
    map[f] = xcalloc((size_t)ne[0], sizeof(int));
    CALL(ex_get_id_map(f ? re : me, EX_ELEM_MAP, map[f]));
  }
  compare_ints("elem_num_map", map[0], map[1], ne[0]);

  /* Blocks. */
  int *ids[2];
  for (int f = 0; f < 2; f++) {
    ids[f] = xcalloc((size_t)nb[0], sizeof(int));
    CALL(ex_get_ids(f ? re : me, EX_ELEM_BLOCK, ids[f]));
  }
  compare_ints("eb_prop1 (block ids)", ids[0], ids[1], nb[0]);
  char **bnames[2] = {names_of(me, EX_ELEM_BLOCK, nb[0]), names_of(re, EX_ELEM_BLOCK, nb[0])};
  for (int b = 0; b < nb[0]; b++) {
    if (strcmp(bnames[0][b], bnames[1][b]) != 0)
      FAIL("block %d is named `%s` in the results, `%s` in the mesh", ids[0][b], bnames[1][b],
           bnames[0][b]);
    char type[2][MAX_STR_LENGTH + 1], sh[2][32];
    int cnt[2], npe[2], ned[2], nfa[2], natt[2];
    for (int f = 0; f < 2; f++) {
      CALL(ex_get_block(f ? re : me, EX_ELEM_BLOCK, ids[0][b], type[f], &cnt[f], &npe[f], &ned[f],
                        &nfa[f], &natt[f]));
      shape(type[f], sh[f]);
    }
    if (cnt[0] != cnt[1] || (cnt[0] > 0 && npe[0] != npe[1])) {
      FAIL("block %d: %d elements of %d nodes in the results, %d of %d in the mesh", ids[0][b],
           cnt[1], npe[1], cnt[0], npe[0]);
      continue;
    }
    if (cnt[0] == 0) continue;
    if (strcmp(sh[0], sh[1]) != 0)
      FAIL("block %d: element type `%s` in the results, `%s` in the mesh", ids[0][b], type[1],
           type[0]);
    int *conn[2];
    for (int f = 0; f < 2; f++) {
      conn[f] = xcalloc((size_t)cnt[0] * (size_t)npe[0], sizeof(int));
      CALL(ex_get_conn(f ? re : me, EX_ELEM_BLOCK, ids[0][b], conn[f], NULL, NULL));
    }
    char what[64];
    snprintf(what, sizeof what, "connectivity of block %d", ids[0][b]);
    compare_ints(what, conn[0], conn[1], cnt[0] * npe[0]);
    free(conn[0]);
    free(conn[1]);
    if (natt[0] == 1 && natt[1] != 1)
      FAIL("block %d: the mesh has an attribute (thickness), the results %d", ids[0][b], natt[1]);
    if (natt[0] == 1 && natt[1] == 1) {
      double *att[2];
      for (int f = 0; f < 2; f++) {
        att[f] = xcalloc((size_t)cnt[0], sizeof(double));
        CALL(ex_get_attr(f ? re : me, EX_ELEM_BLOCK, ids[0][b], att[f]));
      }
      if (att[0][0] != att[1][0])
        FAIL("block %d: thickness %g in the results, %g in the mesh", ids[0][b], att[1][0],
             att[0][0]);
      free(att[0]);
      free(att[1]);
    }
  }

  /* Side sets and node sets. */
  for (int pass = 0; pass < 2; pass++) {
    ex_entity_type kind = pass ? EX_NODE_SET : EX_SIDE_SET;
    const char *label = pass ? "node set" : "side set";
    int count = pass ? nns[0] : nss[0];
    if (count == 0) continue;
    int *sid[2];
    for (int f = 0; f < 2; f++) {
      sid[f] = xcalloc((size_t)count, sizeof(int));
      CALL(ex_get_ids(f ? re : me, kind, sid[f]));
    }
    compare_ints(pass ? "ns_prop1 (node set ids)" : "ss_prop1 (side set ids)", sid[0], sid[1],
                 count);
    char **sn[2] = {names_of(me, kind, count), names_of(re, kind, count)};
    for (int s = 0; s < count; s++) {
      if (strcmp(sn[0][s], sn[1][s]) != 0)
        FAIL("%s %d is named `%s` in the results, `%s` in the mesh", label, sid[0][s], sn[1][s],
             sn[0][s]);
      int len[2], ndf[2];
      for (int f = 0; f < 2; f++) CALL(ex_get_set_param(f ? re : me, kind, sid[0][s], &len[f], &ndf[f]));
      if (len[0] != len[1]) {
        FAIL("%s %d has %d entries in the results, %d in the mesh", label, sid[0][s], len[1], len[0]);
        continue;
      }
      if (len[0] == 0) continue;
      int *e[2], *side[2];
      for (int f = 0; f < 2; f++) {
        e[f] = xcalloc((size_t)len[0], sizeof(int));
        side[f] = xcalloc((size_t)len[0], sizeof(int));
        CALL(ex_get_set(f ? re : me, kind, sid[0][s], e[f], pass ? NULL : side[f]));
      }
      char what[64];
      snprintf(what, sizeof what, "%s %d %s", label, sid[0][s], pass ? "nodes" : "elements");
      compare_ints(what, e[0], e[1], len[0]);
      if (!pass) {
        snprintf(what, sizeof what, "side set %d sides", sid[0][s]);
        compare_ints(what, side[0], side[1], len[0]);
      }
      for (int f = 0; f < 2; f++) {
        free(e[f]);
        free(side[f]);
      }
    }
  }

  /* QA record. */
  int nqa = (int)ex_inquire_int(re, EX_INQ_QA);
  if (nqa < 1) {
    FAIL("no QA record");
  } else {
    char *qa[64][4];
    if (nqa > 64) nqa = 64;
    for (int i = 0; i < nqa; i++)
      for (int j = 0; j < 4; j++) qa[i][j] = xcalloc(MAX_STR_LENGTH + 1, 1);
    CALL(ex_get_qa(re, qa));
    if (strcmp(qa[0][0], "seam") != 0) FAIL("the QA record names `%s`, not seam", qa[0][0]);
  }

  /* Times and variables. */
  int steps = (int)ex_inquire_int(re, EX_INQ_TIME);
  if (steps < 1) {
    FAIL("no time step");
    return 1;
  }
  double *times = xcalloc((size_t)steps, sizeof(double));
  CALL(ex_get_all_times(re, times));
  for (int s = 0; s < steps; s++)
    if (!isfinite(times[s]) || (s > 0 && times[s] < times[s - 1]))
      FAIL("time_whole is not finite and non-decreasing at step %d: %g", s + 1, times[s]);

  int nvar[3];
  ex_entity_type kinds[3] = {EX_NODAL, EX_ELEM_BLOCK, EX_GLOBAL};
  char **vnames[3];
  for (int k = 0; k < 3; k++) {
    CALL(ex_get_variable_param(re, kinds[k], &nvar[k]));
    vnames[k] = names_alloc(nvar[k]);
    if (nvar[k] > 0) CALL(ex_get_variable_names(re, kinds[k], nvar[k], vnames[k]));
  }
  int t = var_index(vnames[0], nvar[0], "temperature");
  if (!t) FAIL("no nodal variable `temperature`");
  const char *flux[3] = {"heat_flux_x", "heat_flux_y", "heat_flux_z"};
  /* One component per dimension: a 2-D run writes x and y only. */
  for (int k = 0; k < dim[0] && k < 3; k++) {
    int v = var_index(vnames[1], nvar[1], flux[k]);
    if (!v) {
      FAIL("no element variable `%s`", flux[k]);
      continue;
    }
    int *tab = xcalloc((size_t)nb[0] * (size_t)nvar[1], sizeof(int));
    CALL(ex_get_truth_table(re, EX_ELEM_BLOCK, nb[0], nvar[1], tab));
    for (int b = 0; b < nb[0]; b++) {
      int cnt, npe, ned, nfa, natt;
      char type[MAX_STR_LENGTH + 1];
      CALL(ex_get_block(re, EX_ELEM_BLOCK, ids[0][b], type, &cnt, &npe, &ned, &nfa, &natt));
      if (cnt == 0) continue;
      if (!tab[b * nvar[1] + v - 1]) {
        FAIL("`%s` is not stored on block %d (elem_var_tab)", flux[k], ids[0][b]);
        continue;
      }
      double *vals = xcalloc((size_t)cnt, sizeof(double));
      for (int s = 1; s <= steps; s++) {
        CALL(ex_get_var(re, s, EX_ELEM_BLOCK, v, ids[0][b], cnt, vals));
        for (int i = 0; i < cnt; i++)
          if (!isfinite(vals[i])) {
            FAIL("`%s` is not finite on block %d at step %d", flux[k], ids[0][b], s);
            break;
          }
      }
      free(vals);
    }
    free(tab);
  }
  if (nvar[2] % 2 != 0) FAIL("%d global variables; seam writes them in side a/b pairs", nvar[2]);
  for (int g = 0; g < nvar[2]; g++) {
    const char *want = g % 2 ? "heat_side_b:" : "heat_side_a:";
    if (strncmp(vnames[2][g], want, strlen(want)) != 0)
      FAIL("global variable %d is `%s`, expected a name starting `%s`", g + 1, vnames[2][g], want);
  }

  FILE *dump = fopen(argv[3], "w");
  if (!dump) {
    fprintf(stderr, "FAIL: cannot create %s\n", argv[3]);
    return 1;
  }
  for (int s = 0; s < steps; s++) fprintf(dump, "time %d %.17g\n", s + 1, times[s]);
  if (t) {
    double *temp = xcalloc((size_t)n, sizeof(double));
    for (int s = 1; s <= steps; s++) {
      CALL(ex_get_var(re, s, EX_NODAL, t, 1, n, temp));
      for (int i = 0; i < n; i++)
        if (!isfinite(temp[i])) {
          FAIL("temperature is not finite at node %d, step %d", i + 1, s);
          break;
        }
    }
    for (int i = 0; i < n; i++) fprintf(dump, "temperature %d %.17g\n", i + 1, temp[i]);
    free(temp);
  }
  /* A thermal-electrical run's voltage, last step. */
  int volt = var_index(vnames[0], nvar[0], "voltage");
  if (volt) {
    double *v = xcalloc((size_t)n, sizeof(double));
    CALL(ex_get_var(re, steps, EX_NODAL, volt, 1, n, v));
    for (int i = 0; i < n; i++) {
      if (!isfinite(v[i])) {
        FAIL("voltage is not finite at node %d", i + 1);
        break;
      }
      fprintf(dump, "voltage %d %.17g\n", i + 1, v[i]);
    }
    free(v);
  }
  if (nvar[2] > 0) {
    double *g = xcalloc((size_t)nvar[2], sizeof(double));
    for (int s = 1; s <= steps; s++) {
      CALL(ex_get_var(re, s, EX_GLOBAL, 1, 1, nvar[2], g));
      for (int k = 0; k < nvar[2]; k++) {
        if (!isfinite(g[k])) FAIL("global `%s` is not finite at step %d", vnames[2][k], s);
        fprintf(dump, "global %d %s %.17g\n", s, vnames[2][k], g[k]);
      }
    }
    free(g);
  }
  if (fclose(dump) != 0) FAIL("cannot write %s", argv[3]);
  ex_close(me);
  ex_close(re);
  if (failures) return 1;
  printf("ok: %s read by libexodus: %d-D, %d nodes, %d elements, %d blocks, %d side sets, %d node "
         "sets match %s; %d steps; %d nodal, %d element, %d global variables\n",
         argv[2], d, n, ne[0], nb[0], nss[0], nns[0], argv[1], steps, nvar[0], nvar[1], nvar[2]);
  return 0;
}
