/*
 * A C host with a periodic model: the 1/12 sector of a turbine disk of
 * examples/turbine_sector, whose two cut faces are tied by cylindrical periodicity.
 *
 * The host meshes the sector itself (the grid of make_meshes.py: an annulus r 0.10 to
 * 0.20 m graded towards the rim, 30 degrees graded towards theta = 0, 0.02 m thick;
 * 6 x 8 x 2 Hex8, k = 20 W/m/K), assembles its own conduction, the rim's heat flux
 * q = 5e4 (1 + 0.5 cos(12 theta - 1)) W/m^2 (at each face's centroid) and the bore's
 * convection (h = 2000 W/m^2K to 300 K). seam ties the cut at theta = 0 (turned by 30
 * degrees about z) to the cut at theta = 30 degrees with standard mortar multipliers;
 * the host carries them and solves [K C^T; C 0] [u; lambda] = [F; g], then prints the
 * heat through the cut and the temperature range.
 *
 * Build and run from the repository root (after `cargo build`):
 *   cc -Wall -Wextra -O2 -Iinclude examples/c_host/sector.c -Ltarget/debug -lseam \
 *      -Wl,-rpath,$PWD/target/debug -lm -o sector && ./sector
 * or `make -C examples/c_host run-sector` (see its Makefile).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "seam.h"
#include "host_fem.h"

enum { NR = 6, NT = 8, NZ = 2 };
static const double R_IN = 0.10, R_OUT = 0.20, THICKNESS = 0.02;
static const double PI = 3.14159265358979323846;

static int64_t node(int i, int j, int k) { return i + (NR + 1) * (j + (int64_t)(NT + 1) * k); }

/* The corner (di, dj, dk) of cell (i, j, k), in Exodus Hex8 order. */
static const int CORNER[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                                 {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};

/* Bilinear quad face (corners counter-clockwise), 2x2 Gauss: fe += integral of q N_a and
 * ke += integral of h N_a N_b (exact on these flat rectangular faces). */
static void quad4_face(const double x[4][3], double q, double h, double ke[4][4], double fe[4]) {
    const double g = 1.0 / sqrt(3.0);
    static const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int p = 0; p < 4; p++) {
        double xi = s[p][0] * g, eta = s[p][1] * g, n[4], t[2][3] = {{0}};
        for (int a = 0; a < 4; a++) {
            n[a] = 0.25 * (1 + s[a][0] * xi) * (1 + s[a][1] * eta);
            for (int d = 0; d < 3; d++) {
                t[0][d] += 0.25 * s[a][0] * (1 + s[a][1] * eta) * x[a][d];
                t[1][d] += 0.25 * s[a][1] * (1 + s[a][0] * xi) * x[a][d];
            }
        }
        double c[3] = {t[0][1] * t[1][2] - t[0][2] * t[1][1], t[0][2] * t[1][0] - t[0][0] * t[1][2],
                       t[0][0] * t[1][1] - t[0][1] * t[1][0]};
        double da = sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        for (int a = 0; a < 4; a++) {
            fe[a] += q * n[a] * da;
            for (int b = 0; b < 4; b++) ke[a][b] += h * n[a] * n[b] * da;
        }
    }
}

int main(void) {
    size_t n = (size_t)(NR + 1) * (NT + 1) * (NZ + 1), n_elems = (size_t)NR * NT * NZ;
    double *coords = malloc(sizeof(double) * 3 * n);
    int64_t *conn = malloc(sizeof(int64_t) * 8 * n_elems);
    int64_t *dof = malloc(sizeof(int64_t) * n);
    int64_t cut_start[NR * NZ][4], cut_end[NR * NZ][4];

    /* The grid of make_meshes.py (numpy's linspace: i * (1/N), the last point exact). */
    for (int k = 0; k <= NZ; k++)
        for (int j = 0; j <= NT; j++)
            for (int i = 0; i <= NR; i++) {
                double si = i == NR ? 1.0 : i * (1.0 / NR), sj = j == NT ? 1.0 : j * (1.0 / NT);
                double r = R_IN + (R_OUT - R_IN) * (1.0 - pow(1.0 - si, 1.4));
                double theta = (2.0 * PI / 12) * pow(sj, 1.3);
                double *x = coords + 3 * node(i, j, k);
                x[0] = r * cos(theta);
                x[1] = r * sin(theta);
                x[2] = k == NZ ? THICKNESS : k * (THICKNESS / NZ);
            }
    size_t e = 0, f = 0;
    for (int k = 0; k < NZ; k++)
        for (int j = 0; j < NT; j++)
            for (int i = 0; i < NR; i++, e++)
                for (int c = 0; c < 8; c++)
                    conn[8 * e + c] = node(i + CORNER[c][0], j + CORNER[c][1], k + CORNER[c][2]);
    /* The cuts, as corner-node lists: theta = 0 (cells j = 0) and 30 degrees (j = NT - 1). */
    for (int k = 0; k < NZ; k++)
        for (int i = 0; i < NR; i++, f++) {
            int64_t start[4] = {node(i, 0, k), node(i + 1, 0, k), node(i + 1, 0, k + 1),
                                node(i, 0, k + 1)};
            int64_t end[4] = {node(i, NT, k), node(i + 1, NT, k), node(i + 1, NT, k + 1),
                              node(i, NT, k + 1)};
            memcpy(cut_start[f], start, sizeof start);
            memcpy(cut_end[f], end, sizeof end);
        }
    /* The host's own numbering: backwards. */
    for (size_t i = 0; i < n; i++) dof[i] = (int64_t)(n - 1 - i);

    seam_builder *b = NULL;
    seam_embedding *emb = NULL;
    CHECK(seam_builder_new(coords, n, &b));
    CHECK(seam_builder_add_block(b, "disk", SEAM_HEX8, conn, n_elems, 20.0));
    CHECK(seam_builder_add_face_set(b, "cut_start", &cut_start[0][0], 4, NR * NZ));
    CHECK(seam_builder_add_face_set(b, "cut_end", &cut_end[0][0], 4, NR * NZ));
    CHECK(seam_builder_set_dofs(b, dof, n));
    CHECK(seam_embedding_new(b, &emb));
    seam_builder_free(b);

    /* The image of cut_start turned by 30 degrees about z lands on cut_end. */
    const double turn[7] = {0, 0, 1, 0, 0, 0, 30.0};
    CHECK(seam_add_periodic_interaction(emb, "cut_start", "cut_end", SEAM_TIED_MORTAR, 0.0, 0.0,
                                        SEAM_PERIODIC_CYLINDRICAL, turn, 7, NULL));
    /* A turn that does not carry it there is refused. */
    const double wrong[7] = {0, 0, 1, 0, 0, 0, 20.0};
    int status = seam_add_periodic_interaction(emb, "cut_start", "cut_end", SEAM_TIED_MORTAR,
                                               0.0, 0.0, SEAM_PERIODIC_CYLINDRICAL, wrong, 7, NULL);
    printf("expected error %d: %s\n", status, seam_last_error());
    if (status != SEAM_ERR_ARGUMENT) return 1;
    CHECK(seam_search(emb));

    /* The tie's rows C u = g (standard multipliers: no condensed rows). */
    size_t n_rows, m, n_entries;
    const int64_t *row_dofs, *row_cols, *mult_dofs, *mults, *cols;
    const double *row_constants, *row_coefficients, *g, *c_values;
    const size_t *row_offsets;
    CHECK(seam_constraints(emb, &n_rows, &row_dofs, &row_constants, &row_offsets, &row_cols,
                           &row_coefficients));
    CHECK(seam_tie_rows(emb, 0, &m, &mult_dofs, &g, &n_entries, &mults, &cols, &c_values));

    /* [K C^T; C 0] in host numbering, dense. */
    size_t size = n + m;
    double *a = calloc(size * size, sizeof(double));
    double *rhs = calloc(size, sizeof(double));
    for (e = 0; e < n_elems; e++) {
        double x[8][3], ke[8][8];
        for (int c = 0; c < 8; c++) memcpy(x[c], coords + 3 * conn[8 * e + c], sizeof x[c]);
        hex8_conduction(x, 20.0, ke);
        for (int p = 0; p < 8; p++)
            for (int q = 0; q < 8; q++) a[dof[conn[8 * e + p]] * size + dof[conn[8 * e + q]]] += ke[p][q];
    }
    /* Rim (i = NR, flux in) and bore (i = 0, convection) faces, corners counter-clockwise. */
    for (int side = 0; side < 2; side++)
        for (int k = 0; k < NZ; k++)
            for (int j = 0; j < NT; j++) {
                int i = side == 0 ? NR : 0;
                int64_t v[4] = {node(i, j, k), node(i, j + 1, k), node(i, j + 1, k + 1),
                                node(i, j, k + 1)};
                double x[4][3], centroid[3] = {0, 0, 0}, ke[4][4] = {{0}}, fe[4] = {0};
                for (int p = 0; p < 4; p++)
                    for (int d = 0; d < 3; d++) {
                        x[p][d] = coords[3 * v[p] + d];
                        centroid[d] += x[p][d] / 4;
                    }
                if (side == 0) {
                    double q = 5e4 * (1 + 0.5 * cos(12 * atan2(centroid[1], centroid[0]) - 1));
                    quad4_face(x, q, 0.0, ke, fe);
                } else {
                    quad4_face(x, 2000.0 * 300.0, 2000.0, ke, fe);
                }
                for (int p = 0; p < 4; p++) {
                    rhs[dof[v[p]]] += fe[p];
                    for (int q = 0; q < 4; q++) a[dof[v[p]] * size + dof[v[q]]] += ke[p][q];
                }
            }
    for (size_t t = 0; t < n_entries; t++) {
        a[(n + (size_t)mults[t]) * size + (size_t)cols[t]] += c_values[t];
        a[(size_t)cols[t] * size + n + (size_t)mults[t]] += c_values[t];
    }
    for (size_t k = 0; k < m; k++) rhs[n + k] = g[k];
    if (solve_dense(a, rhs, size) != 0) {
        fprintf(stderr, "singular system\n");
        return 1;
    }

    double q_a, q_b, lo = INFINITY, hi = -INFINITY;
    CHECK(seam_tie_heat(emb, 0, rhs + n, m, &q_a, &q_b));
    for (size_t i = 0; i < n; i++) {
        lo = fmin(lo, rhs[i]);
        hi = fmax(hi, rhs[i]);
    }
    printf("periodic tie heat: side A %.17g W, side B %.17g W\n", q_a, q_b);
    printf("temperature: min %.17g K, max %.17g K\n", lo, hi);

    seam_embedding_free(emb);
    free(coords), free(conn), free(dof), free(a), free(rhs);
    return 0;
}
