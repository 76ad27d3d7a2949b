/* Reference Exodus II fixtures, written by the Exodus II C library itself (libexodus,
 * the library Cubit, SEACAS and Sierra use), for seam's reader tests.
 *
 *   write_fixtures OUTDIR
 *
 * writes, for a 3-D mesh (every 3-D topology seam reads: HEX8, TETRA4, WEDGE6,
 * PYRAMID5, SHELL4 with a thickness attribute, TRISHELL3, BAR2 and an empty block), a
 * 2-D mesh (QUAD4, TRI3) and a 2-D contact mesh (a QUAD4 part and a TRI3 part meshed
 * apart, their edges at y = 1 not matching, with the edge side sets and a node set a
 * 2-D contact deck names; x >= 0 with nodes on x = 0, so it reads axisymmetric too),
 * each in the three netCDF flavours,
 *
 *   ref3d_classic.exo  ref3d_offset64.exo  ref3d_nc4.exo   (nc4: 64-bit integers stored)
 *   ref2d_classic.exo  ref2d_offset64.exo  ref2d_nc4.exo
 *   contact2d_classic.exo  contact2d_offset64.exo  contact2d_nc4.exo
 *
 * with number maps, an extra named node map, block/set names, side sets and node sets
 * (with distribution factors on some, an empty one of each), QA and information
 * records, coordinate names and two time steps of global, nodal, element, side-set and
 * node-set variables; and reference.json, printed from the same C arrays, which the
 * Rust tests (tests/it/mesh_io.rs) compare seam's reader with.
 *
 * Build: gcc -std=c99 -Wall -Wextra -Werror tests/exodus/write_fixtures.c \
 *            -lexoIIv2c -lnetcdf -o target/write_fixtures
 * (Debian's libexodusii-dev names the library exoIIv2c.)
 */
#include <exodusII.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define CHECK(call)                                                                     \
  do {                                                                                  \
    int rc_ = (call);                                                                   \
    if (rc_ < 0) {                                                                      \
      fprintf(stderr, "%s:%d: %s failed (%d)\n", __FILE__, __LINE__, #call, rc_);       \
      exit(1);                                                                          \
    }                                                                                   \
  } while (0)

#define MAX_NODES 64
#define MAX_BLOCKS 8
#define MAX_SETS 4
#define MAX_CONN 64
#define MAX_SET 16

struct block {
  int id;
  const char *name;
  const char *type;
  int count;
  int npe;
  int conn[MAX_CONN]; /* 1-based node positions */
  double thickness;   /* > 0: one attribute `thickness` */
};

struct side_set {
  int id;
  const char *name;
  int count;
  int elems[MAX_SET]; /* 1-based element positions */
  int sides[MAX_SET];
  int with_df;
};

struct node_set {
  int id;
  const char *name;
  int count;
  int nodes[MAX_SET]; /* 1-based node positions */
  int with_df;
};

struct mesh {
  const char *key;
  const char *title;
  int dim;
  int num_nodes;
  double x[MAX_NODES], y[MAX_NODES], z[MAX_NODES];
  int nblk;
  struct block blk[MAX_BLOCKS];
  int nss;
  struct side_set ss[MAX_SETS];
  int nns;
  struct node_set ns[MAX_SETS];
};

static int num_elems(const struct mesh *m) {
  int n = 0;
  for (int b = 0; b < m->nblk; b++) n += m->blk[b].count;
  return n;
}

static int node_number(int k) { return 1000 + 7 * k; } /* k: 0-based position */
static int elem_number(int k) { return 500 - 3 * k; }  /* unordered on purpose */
static double total_heat(int step) { return 100.0 * step; }
static double temperature(const struct mesh *m, int k, double t) {
  return 300.0 + m->x[k] + 2.0 * m->y[k] + 3.0 * m->z[k] + 10.0 * t;
}
static const double TIMES[2] = {0.0, 2.5};
static char *QA[2][4] = {{"write_fixtures", "1.0", "01/02/26", "03:04:05"},
                         {"seam_tests", "2.0", "12/31/25", "23:59:59"}};
static char *INFO[2] = {"Reference fixture written by libexodus for seam.",
                        "Second information record."};

static int add_node(struct mesh *m, double x, double y, double z) {
  m->x[m->num_nodes] = x;
  m->y[m->num_nodes] = y;
  m->z[m->num_nodes] = z;
  return ++m->num_nodes; /* 1-based position */
}

static struct block *add_block(struct mesh *m, int id, const char *name, const char *type,
                               int npe) {
  struct block *b = &m->blk[m->nblk++];
  memset(b, 0, sizeof *b);
  b->id = id;
  b->name = name;
  b->type = type;
  b->npe = npe;
  return b;
}

static void add_elem(struct block *b, const int *nodes) {
  for (int i = 0; i < b->npe; i++) b->conn[b->count * b->npe + i] = nodes[i];
  b->count++;
}

/* 3-D: every solid, shell and bar topology, each on its own nodes, all positively
 * oriented (seam validates volumes). */
static void mesh3d(struct mesh *m) {
  memset(m, 0, sizeof *m);
  m->key = "ref3d";
  m->title = "seam reference fixture, 3-D";
  m->dim = 3;
  /* Two hexes on [0,2]x[0,1]x[0,1]. */
  int h[12];
  for (int k = 0; k < 2; k++)
    for (int j = 0; j < 2; j++)
      for (int i = 0; i < 3; i++) h[k * 6 + j * 3 + i] = add_node(m, i, j, k);
  struct block *b = add_block(m, 10, "hexes", "HEX8", 8);
  for (int i = 0; i < 2; i++) {
    int e[8] = {h[i], h[i + 1], h[i + 4], h[i + 3], h[6 + i], h[6 + i + 1], h[6 + i + 4], h[6 + i + 3]};
    add_elem(b, e);
  }
  b = add_block(m, 20, "tets", "TETRA4", 4);
  {
    int e[4] = {add_node(m, 3, 0, 0), add_node(m, 4, 0, 0), add_node(m, 3, 1, 0), add_node(m, 3, 0, 1)};
    add_elem(b, e);
  }
  b = add_block(m, 30, "wedges", "WEDGE6", 6);
  {
    int e[6] = {add_node(m, 5, 0, 0), add_node(m, 6, 0, 0), add_node(m, 5, 1, 0),
                add_node(m, 5, 0, 1), add_node(m, 6, 0, 1), add_node(m, 5, 1, 1)};
    add_elem(b, e);
  }
  b = add_block(m, 40, "pyramids", "PYRAMID5", 5);
  {
    int e[5] = {add_node(m, 7, 0, 0), add_node(m, 8, 0, 0), add_node(m, 8, 1, 0),
                add_node(m, 7, 1, 0), add_node(m, 7.5, 0.5, 1)};
    add_elem(b, e);
  }
  b = add_block(m, 50, "skin", "SHELL4", 4);
  b->thickness = 0.05;
  {
    int e[4] = {add_node(m, 0, 0, 2), add_node(m, 1, 0, 2), add_node(m, 1, 1, 2), add_node(m, 0, 1, 2)};
    add_elem(b, e);
  }
  b = add_block(m, 60, "tri_skin", "TRISHELL3", 3);
  b->thickness = 0.02;
  {
    int e[3] = {add_node(m, 2, 0, 2), add_node(m, 3, 0, 2), add_node(m, 2, 1, 2)};
    add_elem(b, e);
  }
  b = add_block(m, 70, "", "BAR2", 2);
  {
    int e[2] = {add_node(m, 0, 0, 3), add_node(m, 1, 0, 3)};
    add_elem(b, e);
  }
  add_block(m, 80, "empty", "HEX8", 8);

  /* Side sets: the hex tops (side 6); the z = 0 faces of the tet (side 4), the wedge
   * (side 4) and the pyramid (side 5); an empty one. */
  struct side_set *s = &m->ss[m->nss++];
  *s = (struct side_set){1, "hex_top", 2, {1, 2}, {6, 6}, 1};
  s = &m->ss[m->nss++];
  *s = (struct side_set){2, "", 3, {3, 4, 5}, {4, 4, 5}, 0};
  s = &m->ss[m->nss++];
  *s = (struct side_set){3, "nothing", 0, {0}, {0}, 0};

  struct node_set *n = &m->ns[m->nns++];
  *n = (struct node_set){100, "left", 4, {h[0], h[3], h[6], h[9]}, 1};
  n = &m->ns[m->nns++];
  *n = (struct node_set){200, "", 2, {13, 14}, 0};
  n = &m->ns[m->nns++];
  *n = (struct node_set){300, "void", 0, {0}, 0};
}

/* 2-D: a 2x1 quad block and two triangles beside it. */
static void mesh2d(struct mesh *m) {
  memset(m, 0, sizeof *m);
  m->key = "ref2d";
  m->title = "seam reference fixture, 2-D";
  m->dim = 2;
  int q[6];
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 3; i++) q[j * 3 + i] = add_node(m, i, j, 0);
  struct block *b = add_block(m, 1, "plate", "QUAD4", 4);
  for (int i = 0; i < 2; i++) {
    int e[4] = {q[i], q[i + 1], q[i + 4], q[i + 3]};
    add_elem(b, e);
  }
  int a = add_node(m, 3, 0, 0), c = add_node(m, 4, 0, 0), d = add_node(m, 4, 1, 0),
      e = add_node(m, 3, 1, 0);
  b = add_block(m, 2, "triangles", "TRI3", 3);
  {
    int t1[3] = {a, c, d}, t2[3] = {a, d, e};
    add_elem(b, t1);
    add_elem(b, t2);
  }
  struct side_set *s = &m->ss[m->nss++];
  *s = (struct side_set){7, "south", 3, {1, 2, 3}, {1, 1, 1}, 1};
  s = &m->ss[m->nss++];
  *s = (struct side_set){8, "", 1, {4}, {2}, 0};
  struct node_set *n = &m->ns[m->nns++];
  *n = (struct node_set){9, "west", 2, {q[0], q[3]}, 1};
}

/* 2-D contact: block 1 `lower`, 3x2 QUAD4 on [0,1]x[0,1]; block 2 `upper`, 4x2 cells
 * on [0,1]x[1,2] each split into two TRI3 along its diagonal 0-2, on nodes of its own.
 * Side sets: 1 lower_bottom, 2 lower_top, 3 upper_bottom, 4 upper_top; node set 10
 * lower_top_nodes (the lower part's nodes on y = 1). */
static void contact2d(struct mesh *m) {
  memset(m, 0, sizeof *m);
  m->key = "contact2d";
  m->title = "seam reference fixture, 2-D contact";
  m->dim = 2;
  int q[3][4], t[3][5];
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 4; i++) q[j][i] = add_node(m, i / 3.0, j / 2.0, 0);
  for (int j = 0; j < 3; j++)
    for (int i = 0; i < 5; i++) t[j][i] = add_node(m, i / 4.0, 1.0 + j / 2.0, 0);
  struct block *b = add_block(m, 1, "lower", "QUAD4", 4);
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 3; i++) {
      int e[4] = {q[j][i], q[j][i + 1], q[j + 1][i + 1], q[j + 1][i]};
      add_elem(b, e);
    }
  b = add_block(m, 2, "upper", "TRI3", 3);
  for (int j = 0; j < 2; j++)
    for (int i = 0; i < 4; i++) {
      int a[3] = {t[j][i], t[j][i + 1], t[j + 1][i + 1]};
      int c[3] = {t[j][i], t[j + 1][i + 1], t[j + 1][i]};
      add_elem(b, a);
      add_elem(b, c);
    }
  /* Element positions: quads 1-6 (row by row), triangles 7-22 (cell by cell, the one
   * under the diagonal first: its side 1 is the cell's bottom, the other's side 2 its
   * top). */
  struct side_set *s = &m->ss[m->nss++];
  *s = (struct side_set){1, "lower_bottom", 3, {1, 2, 3}, {1, 1, 1}, 0};
  s = &m->ss[m->nss++];
  *s = (struct side_set){2, "lower_top", 3, {4, 5, 6}, {3, 3, 3}, 1};
  s = &m->ss[m->nss++];
  *s = (struct side_set){3, "upper_bottom", 4, {7, 9, 11, 13}, {1, 1, 1, 1}, 0};
  s = &m->ss[m->nss++];
  *s = (struct side_set){4, "upper_top", 4, {16, 18, 20, 22}, {2, 2, 2, 2}, 0};
  struct node_set *n = &m->ns[m->nns++];
  *n = (struct node_set){10, "lower_top_nodes", 4, {q[2][0], q[2][1], q[2][2], q[2][3]}, 0};
}

static void write_mesh(const struct mesh *m, const char *path, int mode) {
  int cws = 8, iows = 8;
  int exo = ex_create(path, EX_CLOBBER | mode, &cws, &iows);
  if (exo < 0) {
    fprintf(stderr, "cannot create %s\n", path);
    exit(1);
  }
  int ne = num_elems(m);
  ex_init_params par;
  memset(&par, 0, sizeof par);
  snprintf(par.title, sizeof par.title, "%s", m->title);
  par.num_dim = m->dim;
  par.num_nodes = m->num_nodes;
  par.num_elem = ne;
  par.num_elem_blk = m->nblk;
  par.num_node_sets = m->nns;
  par.num_side_sets = m->nss;
  par.num_node_maps = 1;
  CHECK(ex_put_init_ext(exo, &par));

  CHECK(ex_put_qa(exo, 2, QA));
  CHECK(ex_put_info(exo, 2, INFO));

  CHECK(ex_put_coord(exo, m->x, m->y, m->dim == 3 ? m->z : NULL));
  char *cn[3] = {"x", "y", "z"};
  CHECK(ex_put_coord_names(exo, cn));

  int nmap[MAX_NODES], emap[MAX_BLOCKS * MAX_CONN], extra[MAX_NODES];
  for (int k = 0; k < m->num_nodes; k++) {
    nmap[k] = node_number(k);
    extra[k] = m->num_nodes - k;
  }
  for (int k = 0; k < ne; k++) emap[k] = elem_number(k);
  CHECK(ex_put_id_map(exo, EX_NODE_MAP, nmap));
  CHECK(ex_put_id_map(exo, EX_ELEM_MAP, emap));
  /* An extra, optional node map (`node_map1`, `nm_prop1`), which a reader may ignore. */
  CHECK(ex_put_num_map(exo, EX_NODE_MAP, 1, extra));

  char *names[MAX_BLOCKS];
  for (int i = 0; i < m->nblk; i++) {
    const struct block *b = &m->blk[i];
    CHECK(ex_put_block(exo, EX_ELEM_BLOCK, b->id, b->type, b->count, b->npe, 0, 0,
                       b->thickness > 0 ? 1 : 0));
    if (b->count > 0) CHECK(ex_put_conn(exo, EX_ELEM_BLOCK, b->id, b->conn, NULL, NULL));
    if (b->thickness > 0) {
      double att[MAX_CONN];
      for (int k = 0; k < b->count; k++) att[k] = b->thickness;
      CHECK(ex_put_attr(exo, EX_ELEM_BLOCK, b->id, att));
      char *an[1] = {"thickness"};
      CHECK(ex_put_attr_names(exo, EX_ELEM_BLOCK, b->id, an));
    }
    names[i] = (char *)b->name;
  }
  CHECK(ex_put_names(exo, EX_ELEM_BLOCK, names));

  for (int i = 0; i < m->nss; i++) {
    const struct side_set *s = &m->ss[i];
    CHECK(ex_put_set_param(exo, EX_SIDE_SET, s->id, s->count, s->with_df ? 2 * s->count : 0));
    if (s->count > 0) CHECK(ex_put_set(exo, EX_SIDE_SET, s->id, s->elems, s->sides));
    if (s->with_df) {
      double df[2 * MAX_SET];
      for (int k = 0; k < 2 * s->count; k++) df[k] = 1.0 + k;
      CHECK(ex_put_set_dist_fact(exo, EX_SIDE_SET, s->id, df));
    }
    names[i] = (char *)s->name;
  }
  if (m->nss) CHECK(ex_put_names(exo, EX_SIDE_SET, names));

  for (int i = 0; i < m->nns; i++) {
    const struct node_set *s = &m->ns[i];
    CHECK(ex_put_set_param(exo, EX_NODE_SET, s->id, s->count, s->with_df ? s->count : 0));
    if (s->count > 0) CHECK(ex_put_set(exo, EX_NODE_SET, s->id, s->nodes, NULL));
    if (s->with_df) {
      double df[MAX_SET];
      for (int k = 0; k < s->count; k++) df[k] = 0.5 * (k + 1);
      CHECK(ex_put_set_dist_fact(exo, EX_NODE_SET, s->id, df));
    }
    names[i] = (char *)s->name;
  }
  if (m->nns) CHECK(ex_put_names(exo, EX_NODE_SET, names));

  /* Results: 1 global, 2 nodal, 1 element variable (not on every block), 1 side-set and
   * 1 node-set variable. */
  CHECK(ex_put_variable_param(exo, EX_GLOBAL, 1));
  char *gn[1] = {"total_heat"};
  CHECK(ex_put_variable_names(exo, EX_GLOBAL, 1, gn));
  CHECK(ex_put_variable_param(exo, EX_NODAL, 2));
  char *nn[2] = {"temperature", "node_index"};
  CHECK(ex_put_variable_names(exo, EX_NODAL, 2, nn));
  CHECK(ex_put_variable_param(exo, EX_ELEM_BLOCK, 1));
  char *en[1] = {"heat_flux_x"};
  CHECK(ex_put_variable_names(exo, EX_ELEM_BLOCK, 1, en));
  int tab[MAX_BLOCKS];
  for (int i = 0; i < m->nblk; i++) tab[i] = (m->blk[i].count > 0 && i != 1) ? 1 : 0;
  CHECK(ex_put_truth_table(exo, EX_ELEM_BLOCK, m->nblk, 1, tab));
  CHECK(ex_put_variable_param(exo, EX_SIDE_SET, 1));
  char *sn[1] = {"side_flux"};
  CHECK(ex_put_variable_names(exo, EX_SIDE_SET, 1, sn));
  CHECK(ex_put_variable_param(exo, EX_NODE_SET, 1));
  char *ns[1] = {"node_set_value"};
  CHECK(ex_put_variable_names(exo, EX_NODE_SET, 1, ns));

  for (int step = 1; step <= 2; step++) {
    double t = TIMES[step - 1];
    CHECK(ex_put_time(exo, step, &t));
    double g = total_heat(step);
    CHECK(ex_put_var(exo, step, EX_GLOBAL, 1, 0, 1, &g));
    double v[MAX_NODES];
    for (int k = 0; k < m->num_nodes; k++) v[k] = temperature(m, k, t);
    CHECK(ex_put_var(exo, step, EX_NODAL, 1, 0, m->num_nodes, v));
    for (int k = 0; k < m->num_nodes; k++) v[k] = k + 1;
    CHECK(ex_put_var(exo, step, EX_NODAL, 2, 0, m->num_nodes, v));
    for (int i = 0; i < m->nblk; i++) {
      if (!tab[i]) continue;
      double ev[MAX_CONN];
      for (int k = 0; k < m->blk[i].count; k++) ev[k] = m->blk[i].id + 0.5 * k + step;
      CHECK(ex_put_var(exo, step, EX_ELEM_BLOCK, 1, m->blk[i].id, m->blk[i].count, ev));
    }
    for (int i = 0; i < m->nss; i++) {
      if (!m->ss[i].count) continue;
      double sv[MAX_SET];
      for (int k = 0; k < m->ss[i].count; k++) sv[k] = -1.0 * (k + step);
      CHECK(ex_put_var(exo, step, EX_SIDE_SET, 1, m->ss[i].id, m->ss[i].count, sv));
    }
    for (int i = 0; i < m->nns; i++) {
      if (!m->ns[i].count) continue;
      double nv[MAX_SET];
      for (int k = 0; k < m->ns[i].count; k++) nv[k] = 7.0 * (k + step);
      CHECK(ex_put_var(exo, step, EX_NODE_SET, 1, m->ns[i].id, m->ns[i].count, nv));
    }
  }
  CHECK(ex_close(exo));
}

static void json_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; s++) {
    if (*s == '"' || *s == '\\') fputc('\\', f);
    fputc(*s, f);
  }
  fputc('"', f);
}

static void json_ints(FILE *f, const int *v, int n) {
  fputc('[', f);
  for (int i = 0; i < n; i++) fprintf(f, "%s%d", i ? "," : "", v[i]);
  fputc(']', f);
}

static void write_json(FILE *f, const struct mesh *m) {
  int ne = num_elems(m);
  fprintf(f, " ");
  json_string(f, m->key);
  fprintf(f, ": {\n  \"title\": ");
  json_string(f, m->title);
  fprintf(f, ",\n  \"dim\": %d,\n  \"num_nodes\": %d,\n  \"num_elems\": %d,\n", m->dim,
          m->num_nodes, ne);
  fprintf(f, "  \"node_numbers\": [");
  for (int k = 0; k < m->num_nodes; k++) fprintf(f, "%s%d", k ? "," : "", node_number(k));
  fprintf(f, "],\n  \"elem_numbers\": [");
  for (int k = 0; k < ne; k++) fprintf(f, "%s%d", k ? "," : "", elem_number(k));
  fprintf(f, "],\n  \"coords\": [");
  for (int k = 0; k < m->num_nodes; k++)
    fprintf(f, "%s[%.17g,%.17g,%.17g]", k ? "," : "", m->x[k], m->y[k],
            m->dim == 3 ? m->z[k] : 0.0);
  fprintf(f, "],\n  \"blocks\": [\n");
  for (int i = 0; i < m->nblk; i++) {
    const struct block *b = &m->blk[i];
    fprintf(f, "   {\"id\": %d, \"name\": ", b->id);
    json_string(f, b->name);
    fprintf(f, ", \"type\": ");
    json_string(f, b->type);
    fprintf(f, ", \"count\": %d, \"nodes_per_elem\": %d, \"connectivity\": ", b->count, b->npe);
    json_ints(f, b->conn, b->count * b->npe);
    if (b->thickness > 0)
      fprintf(f, ", \"thickness\": %.17g}", b->thickness);
    else
      fprintf(f, ", \"thickness\": null}");
    fprintf(f, "%s\n", i + 1 < m->nblk ? "," : "");
  }
  fprintf(f, "  ],\n  \"side_sets\": [\n");
  for (int i = 0; i < m->nss; i++) {
    const struct side_set *s = &m->ss[i];
    fprintf(f, "   {\"id\": %d, \"name\": ", s->id);
    json_string(f, s->name);
    fprintf(f, ", \"elems\": ");
    json_ints(f, s->elems, s->count);
    fprintf(f, ", \"sides\": ");
    json_ints(f, s->sides, s->count);
    fprintf(f, "}%s\n", i + 1 < m->nss ? "," : "");
  }
  fprintf(f, "  ],\n  \"node_sets\": [\n");
  for (int i = 0; i < m->nns; i++) {
    const struct node_set *s = &m->ns[i];
    fprintf(f, "   {\"id\": %d, \"name\": ", s->id);
    json_string(f, s->name);
    fprintf(f, ", \"nodes\": ");
    json_ints(f, s->nodes, s->count);
    fprintf(f, "}%s\n", i + 1 < m->nns ? "," : "");
  }
  fprintf(f, "  ],\n  \"qa_records\": [");
  for (int i = 0; i < 2; i++) {
    fprintf(f, "%s[", i ? "," : "");
    for (int j = 0; j < 4; j++) {
      if (j) fputc(',', f);
      json_string(f, QA[i][j]);
    }
    fputc(']', f);
  }
  fprintf(f, "],\n  \"info_records\": [");
  for (int i = 0; i < 2; i++) {
    if (i) fputc(',', f);
    json_string(f, INFO[i]);
  }
  fprintf(f, "],\n");
  fprintf(f, "  \"times\": [%.17g,%.17g],\n", TIMES[0], TIMES[1]);
  fprintf(f, "  \"global_variables\": {\"total_heat\": [%.17g,%.17g]},\n", total_heat(1),
          total_heat(2));
  fprintf(f, "  \"nodal_variables\": {\"temperature\": [");
  for (int step = 0; step < 2; step++) {
    fprintf(f, "%s[", step ? "," : "");
    for (int k = 0; k < m->num_nodes; k++)
      fprintf(f, "%s%.17g", k ? "," : "", temperature(m, k, TIMES[step]));
    fprintf(f, "]");
  }
  fprintf(f, "]}\n }");
}

int main(int argc, char **argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s OUTDIR\n", argv[0]);
    return 2;
  }
  enum { MESHES = 3 };
  static struct mesh meshes[MESHES];
  mesh3d(&meshes[0]);
  mesh2d(&meshes[1]);
  contact2d(&meshes[2]);
  const struct {
    const char *tag;
    int mode;
  } flavours[3] = {
      {"classic", EX_NORMAL_MODEL},
      {"offset64", EX_LARGE_MODEL},
      {"nc4", EX_NETCDF4 | EX_ALL_INT64_DB},
  };
  char path[4096];
  for (int i = 0; i < MESHES; i++)
    for (int k = 0; k < 3; k++) {
      snprintf(path, sizeof path, "%s/%s_%s.exo", argv[1], meshes[i].key, flavours[k].tag);
      write_mesh(&meshes[i], path, flavours[k].mode);
    }
  snprintf(path, sizeof path, "%s/reference.json", argv[1]);
  FILE *f = fopen(path, "w");
  if (!f) {
    fprintf(stderr, "cannot create %s\n", path);
    return 1;
  }
  fprintf(f, "{\n");
  for (int i = 0; i < MESHES; i++) {
    write_json(f, &meshes[i]);
    fprintf(f, "%s\n", i + 1 < MESHES ? "," : "");
  }
  fprintf(f, "}\n");
  return fclose(f) == 0 ? 0 : 1;
}
