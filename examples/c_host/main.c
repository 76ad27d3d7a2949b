/*
 * A C host that owns its mesh, its dof numbering and its (dense) matrix, and asks
 * libseam for the interface terms between two blocks meshed apart.
 *
 * The scene is examples/two_blocks: a base [0,1]^3 of 6x6x6 Hex8 (k = 16) and a lid
 * [0,1]^2 x [1,1.5] of 4x4x3 Hex8 (k = 200) meeting non-conformingly at z = 1, base
 * bottom at 300 K, lid top at 400 K, gap conductance h = 500 W/m^2K. The host meshes
 * the blocks itself, assembles its own trilinear conduction, adds seam's Jacobian, and
 * prints the interface heat; then ties the blocks by dual mortar instead, condenses
 * seam's constraint rows into its system (it carries no multipliers) and prints that
 * heat too.
 *
 * Build and run from the repository root (after `cargo build`):
 *   cc -Wall -Wextra -O2 -Iinclude examples/c_host/main.c -Ltarget/debug -lseam \
 *      -Wl,-rpath,$PWD/target/debug -lm -o c_host && ./c_host
 * or `make -C examples/c_host` (see its Makefile).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "seam.h"
#include "host_fem.h"

/* A structured box of nx*ny*nz Hex8, nodes appended to coords from `first`. */
typedef struct {
    int nx, ny, nz;
    int64_t first;
} Box;

static int64_t box_node(const Box *b, int i, int j, int k) {
    return b->first + i + (int64_t)(b->nx + 1) * (j + (int64_t)(b->ny + 1) * k);
}

static void box_coords(const Box *b, const double lo[3], const double size[3], double *coords) {
    for (int k = 0; k <= b->nz; k++)
        for (int j = 0; j <= b->ny; j++)
            for (int i = 0; i <= b->nx; i++) {
                double *x = coords + 3 * box_node(b, i, j, k);
                x[0] = lo[0] + size[0] * i / b->nx;
                x[1] = lo[1] + size[1] * j / b->ny;
                x[2] = lo[2] + size[2] * k / b->nz;
            }
}

/* Exodus Hex8 order: bottom face counter-clockwise, then the top face. */
static void box_connectivity(const Box *b, int64_t *conn) {
    size_t e = 0;
    for (int k = 0; k < b->nz; k++)
        for (int j = 0; j < b->ny; j++)
            for (int i = 0; i < b->nx; i++, e++) {
                int64_t *c = conn + 8 * e;
                for (int layer = 0; layer < 2; layer++) {
                    c[4 * layer + 0] = box_node(b, i, j, k + layer);
                    c[4 * layer + 1] = box_node(b, i + 1, j, k + layer);
                    c[4 * layer + 2] = box_node(b, i + 1, j + 1, k + layer);
                    c[4 * layer + 3] = box_node(b, i, j + 1, k + layer);
                }
            }
}

/* The faces of the layer of nodes k, as corner node lists. */
static void box_layer_faces(const Box *b, int k, int64_t *faces) {
    size_t f = 0;
    for (int j = 0; j < b->ny; j++)
        for (int i = 0; i < b->nx; i++, f++) {
            faces[4 * f + 0] = box_node(b, i, j, k);
            faces[4 * f + 1] = box_node(b, i + 1, j, k);
            faces[4 * f + 2] = box_node(b, i + 1, j + 1, k);
            faces[4 * f + 3] = box_node(b, i, j + 1, k);
        }
}

/* The host's conduction matrix of both blocks, dense, in host numbering. */
static void assemble_conduction(double *k, size_t n, const double *coords, const int64_t *dof,
                                const int64_t *const blocks[2], const size_t counts[2]) {
    const double conductivity[2] = {16.0, 200.0};
    memset(k, 0, sizeof(double) * n * n);
    for (int blk = 0; blk < 2; blk++)
        for (size_t el = 0; el < counts[blk]; el++) {
            const int64_t *c = blocks[blk] + 8 * el;
            double x[8][3], ke[8][8];
            for (int a = 0; a < 8; a++) memcpy(x[a], coords + 3 * c[a], sizeof x[a]);
            hex8_conduction(x, conductivity[blk], ke);
            for (int a = 0; a < 8; a++)
                for (int b = 0; b < 8; b++) k[dof[c[a]] * n + dof[c[b]]] += ke[a][b];
        }
}

/* Impose u[d] = fixed[d] (not NaN) by symmetric elimination. */
static void apply_dirichlet(double *k, double *f, size_t n, const double *fixed) {
    for (size_t d = 0; d < n; d++) {
        if (isnan(fixed[d])) continue;
        for (size_t r = 0; r < n; r++) {
            f[r] -= k[r * n + d] * fixed[d];
            k[r * n + d] = 0.0;
        }
        for (size_t c = 0; c < n; c++) k[d * n + c] = 0.0;
        k[d * n + d] = 1.0;
    }
    for (size_t d = 0; d < n; d++)
        if (!isnan(fixed[d])) f[d] = fixed[d];
}

/* What the search paired, and the fields at the host's solution u: every side-A point
 * (position, paired, flux, gap) and every face (element, side, flux, fraction). */
static void report_fields(seam_embedding *e, const double *u, size_t n) {
    seam_coverage_info c;
    CHECK(seam_coverage(e, 0, &c));
    printf("coverage: %zu points, %zu paired, area %.17g, paired %.17g, gap %d %.17g %.17g\n",
           c.points, c.paired_points, c.area, c.paired_area, c.has_gap, c.gap_min, c.gap_max);
    size_t np, nf;
    const seam_point_values *p;
    const seam_face_values *f;
    CHECK(seam_point_fields(e, 0, u, n, &np, &p));
    double sum = 0.0;
    for (size_t i = 0; i < np; i++) {
        if (p[i].paired) sum += p[i].weight * p[i].flux;
        printf("point %.17g %.17g %.17g %d %.17g %.17g\n", p[i].x[0], p[i].x[1], p[i].x[2],
               p[i].paired, p[i].flux, p[i].gap);
    }
    printf("point flux sum: %.17g W\n", sum);
    CHECK(seam_face_fields(e, 0, u, n, 1, &nf, &f));
    for (size_t i = 0; i < nf; i++)
        printf("face %d %.17g %.17g %.17g\n", f[i].surface_side, f[i].flux, f[i].fraction,
               f[i].paired_area);
    double a, b;
    double *half = malloc(sizeof(double) * n);
    for (size_t i = 0; i < n; i++) half[i] = 0.5 * u[i];
    CHECK(seam_heat_at(e, 0, half, n, &a, &b));
    printf("heat at u/2: %.17g W\n", a);
    free(half);
}

/* The CSR Jacobian against the triplets at the same field, and its pattern kept. */
static void check_csr(seam_embedding *e, const double *u, size_t n) {
    size_t nt, n_rows, nnz;
    const int64_t *rows, *cols;
    const double *vals, *values;
    const size_t *offsets, *columns;
    uint64_t pattern, again;
    CHECK(seam_evaluate(e, u, n));
    CHECK(seam_jacobian(e, &nt, &rows, &cols, &vals));
    double *dense = calloc(n * n, sizeof(double));
    for (size_t t = 0; t < nt; t++) dense[rows[t] * n + cols[t]] += vals[t];
    CHECK(seam_evaluate_csr(e, u, n));
    CHECK(seam_jacobian_csr(e, &n_rows, &nnz, &offsets, &columns, &values, &pattern));
    for (size_t r = 0; r < n_rows; r++)
        for (size_t k = offsets[r]; k < offsets[r + 1]; k++) dense[r * n + columns[k]] -= values[k];
    double worst = 0.0;
    for (size_t i = 0; i < n * n; i++) worst = fmax(worst, fabs(dense[i]));
    const size_t *columns_before = columns;
    CHECK(seam_evaluate_csr(e, u, n));
    CHECK(seam_jacobian_csr(e, &n_rows, &nnz, &offsets, &columns, &values, &again));
    size_t nr;
    const double *r;
    CHECK(seam_residual_dense(e, &nr, &r));
    printf("csr: rows %zu entries %zu triplets %zu largest difference %.3e pattern kept %d\n",
           n_rows, nnz, nt, worst, pattern == again && columns == columns_before && nr == n);
    free(dense);
}

/* A conductance from a C callback: h = 500 from user data, and one that fails. */
static int constant_h(const seam_point_state *s, void *user, double *h, double *da, double *db) {
    (void)s;
    *h = *(const double *)user;
    *da = *db = 0.0;
    return 0;
}

static int failing_h(const seam_point_state *s, void *user, double *h, double *da, double *db) {
    (void)user, (void)da, (void)db;
    *h = 1.0;
    return s->x[0] > 0.5 ? 7 : 0;
}

static void check_callbacks(const seam_builder *b, const double *u, size_t n, double q_a) {
    seam_embedding *e = NULL;
    double h = 500.0, a, side_b;
    CHECK(seam_embedding_new(b, &e));
    CHECK(seam_add_interaction_with_conductance(e, "base_top", "lid_bottom",
                                                SEAM_GAP_CONDUCTANCE, constant_h, &h, 0, 0.0,
                                                NULL));
    CHECK(seam_add_interaction_with_conductance(e, "base_top", "lid_bottom", SEAM_CONDUCTANCE,
                                                failing_h, NULL, 1, 0.0, NULL));
    CHECK(seam_search(e));
    CHECK(seam_heat_at(e, 0, u, n, &a, &side_b));
    printf("callback heat: %.17g W (constant model %.17g W)\n", a, q_a);
    int status = seam_heat_at(e, 1, u, n, &a, &side_b);
    printf("expected callback failure %d: %s\n", status, seam_last_error());
    /* Quarantined, the failing points carry nothing and are listed. */
    size_t nq, past = 0;
    const double *xyz;
    const char *reasons;
    CHECK(seam_set_quarantine(e, 1, 1));
    CHECK(seam_heat_at(e, 1, u, n, &a, &side_b));
    CHECK(seam_quarantined(e, 1, &nq, &xyz, &reasons));
    for (size_t i = 0; i < nq; i++) past += xyz[3 * i] > 0.5;
    printf("quarantine: heat %.17g W, %zu points, past x = 0.5: %zu, first reason: %.40s\n", a,
           nq, past, nq > 0 ? reasons : "");
    /* Switched off: 0 W; point pressures of the wrong count are refused. */
    CHECK(seam_set_active(e, 0, 0));
    CHECK(seam_heat_at(e, 0, u, n, &a, &side_b));
    double p[2] = {1e5, 1e5};
    status = seam_set_point_pressures(e, 0, p, 2);
    printf("switched off: %.17g W; expected pressure error %d\n", a, status);
    seam_embedding_free(e);
}

/* The lid lifted half a metre: nothing pairs, which is an error until allowed. */
static void check_nothing_paired(seam_embedding *e, const double *coords, size_t n_nodes,
                                 size_t first_lid_node) {
    double *moved = malloc(sizeof(double) * 3 * n_nodes);
    memcpy(moved, coords, sizeof(double) * 3 * n_nodes);
    for (size_t i = 0; i < n_nodes; i++)
        if (i >= first_lid_node) moved[3 * i + 2] += 0.5;
    CHECK(seam_move_nodes(e, moved, n_nodes));
    int status = seam_search(e);
    printf("expected nothing paired %d: %s\n", status, seam_last_error());
    CHECK(seam_allow_unpaired(e, SIZE_MAX, 1));
    CHECK(seam_search(e));
    seam_coverage_info c;
    size_t nu;
    const size_t *which;
    const double *xyz;
    const int *reasons;
    CHECK(seam_coverage(e, 0, &c));
    CHECK(seam_unpaired_points(e, 0, &nu, &which, &xyz, &reasons));
    printf("apart: %zu paired of %zu points, area %.17g paired %.17g, %zu unpaired, first reason %d\n",
           c.paired_points, c.points, c.area, c.paired_area, nu, nu > 0 ? reasons[0] : -1);
    free(moved);
}

int main(void) {
    Box base = {6, 6, 6, 0};
    Box lid = {4, 4, 3, 0};
    lid.first = (int64_t)(base.nx + 1) * (base.ny + 1) * (base.nz + 1);
    size_t n_nodes = (size_t)lid.first + (size_t)(lid.nx + 1) * (lid.ny + 1) * (lid.nz + 1);
    size_t n_base = (size_t)base.nx * base.ny * base.nz, n_lid = (size_t)lid.nx * lid.ny * lid.nz;
    double *coords = malloc(sizeof(double) * 3 * n_nodes);
    int64_t *conn_base = malloc(sizeof(int64_t) * 8 * n_base);
    int64_t *conn_lid = malloc(sizeof(int64_t) * 8 * n_lid);
    int64_t *faces_base = malloc(sizeof(int64_t) * 4 * base.nx * base.ny);
    int64_t *faces_lid = malloc(sizeof(int64_t) * 4 * lid.nx * lid.ny);
    int64_t *dof = malloc(sizeof(int64_t) * n_nodes);
    box_coords(&base, (double[3]){0, 0, 0}, (double[3]){1, 1, 1}, coords);
    box_coords(&lid, (double[3]){0, 0, 1}, (double[3]){1, 1, 0.5}, coords);
    box_connectivity(&base, conn_base);
    box_connectivity(&lid, conn_lid);
    box_layer_faces(&base, base.nz, faces_base);
    box_layer_faces(&lid, 0, faces_lid);
    /* The host's own numbering: the lid's nodes first, then the base's. */
    size_t n_lid_nodes = n_nodes - (size_t)lid.first;
    for (size_t i = 0; i < n_nodes; i++)
        dof[i] = i < (size_t)lid.first ? (int64_t)(i + n_lid_nodes) : (int64_t)(i - lid.first);

    /* Dirichlet data by host dof: base bottom (z = 0) 300 K, lid top (z = 1.5) 400 K. */
    double *fixed = malloc(sizeof(double) * n_nodes);
    int64_t *fixed_nodes = malloc(sizeof(int64_t) * n_nodes);
    size_t n_fixed = 0;
    for (size_t i = 0; i < n_nodes; i++) {
        double z = coords[3 * i + 2];
        fixed[dof[i]] = fabs(z) < 1e-12 ? 300.0 : fabs(z - 1.5) < 1e-12 ? 400.0 : NAN;
        if (!isnan(fixed[dof[i]])) fixed_nodes[n_fixed++] = (int64_t)i;
    }

    seam_builder *b = NULL;
    seam_embedding *e = NULL;
    CHECK(seam_builder_new(coords, n_nodes, &b));
    CHECK(seam_builder_add_block(b, "base", SEAM_HEX8, conn_base, n_base, 16.0));
    CHECK(seam_builder_add_block(b, "lid", SEAM_HEX8, conn_lid, n_lid, 200.0));
    CHECK(seam_builder_add_face_set(b, "base_top", faces_base, 4, (size_t)base.nx * base.ny));
    CHECK(seam_builder_add_face_set(b, "lid_bottom", faces_lid, 4, (size_t)lid.nx * lid.ny));
    CHECK(seam_builder_set_dofs(b, dof, n_nodes));
    CHECK(seam_builder_set_fixed_nodes(b, fixed_nodes, n_fixed));
    CHECK(seam_embedding_new(b, &e));

    /* A misspelt surface is an error with a message, not a crash. */
    int status = seam_add_interaction(e, "base_topp", "lid_bottom", SEAM_GAP_CONDUCTANCE, 500.0,
                                      0.0, NULL);
    printf("expected error %d: %s\n", status, seam_last_error());
    if (status != SEAM_ERR_ARGUMENT) return 1;

    CHECK(seam_add_interaction(e, "base_top", "lid_bottom", SEAM_GAP_CONDUCTANCE, 500.0, 0.0,
                               NULL));
    CHECK(seam_search(e));

    /* The host's system: conduction of both blocks, dense, in host numbering. */
    size_t n = n_nodes;
    double *k = malloc(sizeof(double) * n * n);
    double *f = calloc(n, sizeof(double));
    double *u = calloc(n, sizeof(double));
    const int64_t *const blocks[2] = {conn_base, conn_lid};
    const size_t counts[2] = {n_base, n_lid};
    assemble_conduction(k, n, coords, dof, blocks, counts);

    /* seam's interface terms: linear (constant h), so take them at u = 0. */
    size_t nj, nl;
    const int64_t *rows, *cols, *load_dofs;
    const double *vals, *load_vals;
    CHECK(seam_evaluate(e, u, n));
    CHECK(seam_jacobian(e, &nj, &rows, &cols, &vals));
    for (size_t t = 0; t < nj; t++) k[rows[t] * n + cols[t]] += vals[t];
    CHECK(seam_load(e, &nl, &load_dofs, &load_vals));
    for (size_t t = 0; t < nl; t++) f[load_dofs[t]] += load_vals[t];

    apply_dirichlet(k, f, n, fixed);
    if (solve_dense(k, f, n) != 0) {
        fprintf(stderr, "singular system\n");
        return 1;
    }
    memcpy(u, f, sizeof(double) * n);

    double q_a, q_b;
    CHECK(seam_evaluate(e, u, n));
    CHECK(seam_heat(e, 0, &q_a, &q_b));
    printf("interface heat: side A %.17g W, side B %.17g W\n", q_a, q_b);

    report_fields(e, u, n);
    check_csr(e, u, n);
    check_callbacks(b, u, n, q_a);
    check_nothing_paired(e, coords, n_nodes, (size_t)lid.first);

    seam_embedding_free(e);

    /* The same blocks tied by dual mortar, which this host (no multipliers) condenses:
     * u = T v + g, solve T^T K T v = T^T (F - K g), then recover the side-A values. */
    seam_embedding *tie = NULL;
    size_t n_rows;
    const int64_t *row_dof, *row_cols;
    const double *row_const, *row_coef;
    const size_t *row_off;
    CHECK(seam_embedding_new(b, &tie));
    CHECK(seam_add_interaction(tie, "base_top", "lid_bottom", SEAM_TIED_DUAL_MORTAR, 0.0, 0.0,
                               NULL));
    CHECK(seam_search(tie));
    CHECK(seam_constraints(tie, &n_rows, &row_dof, &row_const, &row_off, &row_cols, &row_coef));
    double *k0 = malloc(sizeof(double) * n * n);
    assemble_conduction(k0, n, coords, dof, blocks, counts);
    memcpy(k, k0, sizeof(double) * n * n);
    memset(f, 0, sizeof(double) * n);
    for (size_t r = 0; r < n_rows; r++)
        for (size_t i = 0; i < n; i++) f[i] -= k0[i * n + row_dof[r]] * row_const[r];
    for (size_t r = 0; r < n_rows; r++) /* rows: T^T */
        for (size_t t = row_off[r]; t < row_off[r + 1]; t++) {
            f[row_cols[t]] += row_coef[t] * f[row_dof[r]];
            for (size_t c = 0; c < n; c++) k[row_cols[t] * n + c] += row_coef[t] * k[row_dof[r] * n + c];
        }
    for (size_t r = 0; r < n_rows; r++) /* columns: T */
        for (size_t t = row_off[r]; t < row_off[r + 1]; t++)
            for (size_t i = 0; i < n; i++) k[i * n + row_cols[t]] += row_coef[t] * k[i * n + row_dof[r]];
    for (size_t r = 0; r < n_rows; r++) {
        size_t d = (size_t)row_dof[r];
        for (size_t i = 0; i < n; i++) k[d * n + i] = k[i * n + d] = 0.0;
        k[d * n + d] = 1.0;
        f[d] = 0.0;
    }
    apply_dirichlet(k, f, n, fixed);
    if (solve_dense(k, f, n) != 0) {
        fprintf(stderr, "singular condensed system\n");
        return 1;
    }
    for (size_t r = 0; r < n_rows; r++) {
        double v = row_const[r];
        for (size_t t = row_off[r]; t < row_off[r + 1]; t++) v += row_coef[t] * f[row_cols[t]];
        f[row_dof[r]] = v;
    }
    /* The heat follows from the host's own residual K u - F (F = 0 here). */
    for (size_t i = 0; i < n; i++) {
        double s = 0.0;
        for (size_t c = 0; c < n; c++) s += k0[i * n + c] * f[c];
        u[i] = s;
    }
    CHECK(seam_dual_tie_heat(tie, 0, u, n, &q_a, &q_b));
    printf("dual tie heat: side A %.17g W, side B %.17g W\n", q_a, q_b);
    /* Its multipliers from the same residual, and the multiplier field at its points. */
    size_t n_mult, n_entries, n_points;
    const int64_t *mult_dofs, *mults, *entry_dofs;
    const double *g, *entry_values;
    const seam_point_values *tp;
    CHECK(seam_tie_rows(tie, 0, &n_mult, &mult_dofs, &g, &n_entries, &mults, &entry_dofs,
                        &entry_values));
    double *lambda = malloc(sizeof(double) * n_mult);
    CHECK(seam_dual_multipliers(tie, 0, u, n, lambda, n_mult));
    CHECK(seam_tie_point_fields(tie, 0, lambda, n_mult, &n_points, &tp));
    double tie_sum = 0.0;
    for (size_t i = 0; i < n_points; i++)
        if (tp[i].has_multiplier) tie_sum += tp[i].weight * tp[i].multiplier;
    printf("dual tie multiplier field: %zu points, sum of w lambda_h %.17g W\n", n_points,
           tie_sum);
    free(lambda);

    seam_embedding_free(tie);
    seam_builder_free(b);
    free(coords), free(conn_base), free(conn_lid), free(faces_base), free(faces_lid);
    free(dof), free(k), free(k0), free(f), free(u), free(fixed), free(fixed_nodes);
    return 0;
}
