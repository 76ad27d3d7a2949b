/*
 * A C host with a 2-D axisymmetric model: two concentric cylinders, the (r, z) section
 * meshed apart (the inner part a < r < c with NR1 x NZ1 Quad4, the outer c < r < b with
 * NR2 x NZ2; the cylinder r = c is where they meet, its edges not matching), joined by a
 * gap conductance h; T = 400 K on r = a and 300 K on r = b, insulated ends.
 *
 * The host meshes the section itself, assembles its own axisymmetric conduction
 * (bilinear quads, 2x2 Gauss, each weight times 2 pi r: per full revolution), gives
 * seam its blocks as SEAM_QUAD4, its interface as edge face sets (2 nodes per face)
 * and the axisymmetric flag; seam's residual and Jacobian (per revolution too) are
 * added, one linear solve. It prints the interface heat and the temperature at r = c on
 * both sides, to compare with the logarithmic solution
 *   Q = 2 pi H (T_a - T_b) / (ln(c/a)/k1 + 1/(c h) + ln(b/c)/k2).
 *
 * Build and run from the repository root (after `cargo build`):
 *   cc -Wall -Wextra -O2 -Iinclude examples/c_host/axisymmetric.c -Ltarget/debug -lseam \
 *      -Wl,-rpath,$PWD/target/debug -lm -o axisymmetric && ./axisymmetric
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "seam.h"
#include "host_fem.h"

enum { NR1 = 8, NZ1 = 6, NR2 = 12, NZ2 = 9 };
static const double A = 0.5, C = 1.0, B = 2.0, H = 0.5, K1 = 2.0, K2 = 5.0, GAP_H = 3.0;
static const double T_A = 400.0, T_B = 300.0, PI = 3.14159265358979323846;

/* K_e of a bilinear quad in the (r, z) plane, 2x2 Gauss, per full revolution:
 * k * integral of grad N_a . grad N_b 2 pi r dA. */
static void quad4_axisymmetric(const double x[4][3], double k, double ke[4][4]) {
    static const double s[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    const double g = 1.0 / sqrt(3.0);
    memset(ke, 0, sizeof(double) * 16);
    for (int q = 0; q < 4; q++) {
        double xi = s[q][0] * g, eta = s[q][1] * g, dn[4][2], jac[2][2] = {{0}}, r = 0;
        for (int a = 0; a < 4; a++) {
            double n = 0.25 * (1 + s[a][0] * xi) * (1 + s[a][1] * eta);
            dn[a][0] = 0.25 * s[a][0] * (1 + s[a][1] * eta);
            dn[a][1] = 0.25 * s[a][1] * (1 + s[a][0] * xi);
            r += n * x[a][0];
            for (int i = 0; i < 2; i++)
                for (int j = 0; j < 2; j++) jac[i][j] += x[a][i] * dn[a][j];
        }
        double det = jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0], grad[4][2];
        for (int a = 0; a < 4; a++) {
            grad[a][0] = (dn[a][0] * jac[1][1] - dn[a][1] * jac[1][0]) / det;
            grad[a][1] = (-dn[a][0] * jac[0][1] + dn[a][1] * jac[0][0]) / det;
        }
        for (int a = 0; a < 4; a++)
            for (int b = 0; b < 4; b++)
                ke[a][b] += k * det * 2 * PI * r * (grad[a][0] * grad[b][0] + grad[a][1] * grad[b][1]);
    }
}

/* Nodes of part p (0 inner, 1 outer): the grid (i, j) after the inner part's nodes. */
static int64_t node(int p, int i, int j) {
    return p == 0 ? i + (NR1 + 1) * j : (NR1 + 1) * (NZ1 + 1) + i + (NR2 + 1) * j;
}

int main(void) {
    size_t n = (size_t)(NR1 + 1) * (NZ1 + 1) + (size_t)(NR2 + 1) * (NZ2 + 1);
    size_t n1 = (size_t)NR1 * NZ1, n2 = (size_t)NR2 * NZ2;
    double *coords = calloc(3 * n, sizeof(double));
    int64_t *conn = malloc(sizeof(int64_t) * 4 * (n1 + n2)), *dof = malloc(sizeof(int64_t) * n);
    int64_t inner_face[NZ1][2], outer_face[NZ2][2];
    for (int p = 0; p < 2; p++) {
        int nr = p ? NR2 : NR1, nz = p ? NZ2 : NZ1;
        double r0 = p ? C : A, r1 = p ? B : C;
        for (int j = 0; j <= nz; j++)
            for (int i = 0; i <= nr; i++) {
                double *x = coords + 3 * node(p, i, j);
                x[0] = i == nr ? r1 : r0 + (r1 - r0) * i / nr;
                x[1] = j == nz ? H : H * j / nz;
            }
    }
    size_t e = 0;
    for (int p = 0; p < 2; p++) {
        int nr = p ? NR2 : NR1, nz = p ? NZ2 : NZ1;
        for (int j = 0; j < nz; j++)
            for (int i = 0; i < nr; i++, e++) {
                int64_t q[4] = {node(p, i, j), node(p, i + 1, j), node(p, i + 1, j + 1),
                                node(p, i, j + 1)};
                memcpy(conn + 4 * e, q, sizeof q);
            }
    }
    /* The interface edges at r = c: the inner part's outer edges, the outer's inner. */
    for (int j = 0; j < NZ1; j++) {
        inner_face[j][0] = node(0, NR1, j);
        inner_face[j][1] = node(0, NR1, j + 1);
    }
    for (int j = 0; j < NZ2; j++) {
        outer_face[j][0] = node(1, 0, j + 1);
        outer_face[j][1] = node(1, 0, j);
    }
    for (size_t i = 0; i < n; i++) dof[i] = (int64_t)(n - 1 - i); /* the host's own order */

    seam_builder *b = NULL;
    seam_embedding *emb = NULL;
    CHECK(seam_builder_new(coords, n, &b));
    CHECK(seam_builder_add_block(b, "inner", SEAM_QUAD4, conn, n1, K1));
    CHECK(seam_builder_add_block(b, "outer", SEAM_QUAD4, conn + 4 * n1, n2, K2));
    CHECK(seam_builder_add_face_set(b, "inner_surface", &inner_face[0][0], 2, NZ1));
    CHECK(seam_builder_add_face_set(b, "outer_bore", &outer_face[0][0], 2, NZ2));
    CHECK(seam_builder_set_dofs(b, dof, n));
    CHECK(seam_builder_set_axisymmetric(b, 1));
    CHECK(seam_embedding_new(b, &emb));
    seam_builder_free(b);
    CHECK(seam_add_interaction(emb, "inner_surface", "outer_bore", SEAM_GAP_CONDUCTANCE, GAP_H,
                               0.0, NULL));
    CHECK(seam_search(emb));

    /* (K + J) u = -R(0) with the Dirichlet rows; the gap is linear in u. */
    double *u = calloc(n, sizeof(double)), *a = calloc(n * n, sizeof(double));
    double *rhs = calloc(n, sizeof(double));
    for (e = 0; e < n1 + n2; e++) {
        double x[4][3], ke[4][4];
        for (int c = 0; c < 4; c++) memcpy(x[c], coords + 3 * conn[4 * e + c], sizeof x[c]);
        quad4_axisymmetric(x, e < n1 ? K1 : K2, ke);
        for (int p = 0; p < 4; p++)
            for (int q = 0; q < 4; q++) a[dof[conn[4 * e + p]] * n + dof[conn[4 * e + q]]] += ke[p][q];
    }
    CHECK(seam_evaluate(emb, u, n));
    size_t m;
    const int64_t *rows, *cols, *dofs;
    const double *values;
    CHECK(seam_jacobian(emb, &m, &rows, &cols, &values));
    for (size_t t = 0; t < m; t++) a[rows[t] * n + cols[t]] += values[t];
    CHECK(seam_residual(emb, &m, &dofs, &values));
    for (size_t t = 0; t < m; t++) rhs[dofs[t]] -= values[t];
    for (int p = 0; p < 2; p++) {
        int nr = p ? NR2 : NR1, nz = p ? NZ2 : NZ1, i = p ? nr : 0;
        for (int j = 0; j <= nz; j++) {
            int64_t d = dof[node(p, i, j)];
            memset(a + d * n, 0, n * sizeof(double));
            a[d * n + d] = 1.0;
            rhs[d] = p ? T_B : T_A;
        }
    }
    if (solve_dense(a, rhs, n) != 0) {
        fprintf(stderr, "singular system\n");
        return 1;
    }
    for (size_t i = 0; i < n; i++) u[i] = rhs[dof[i]]; /* node order */
    /* The heat at the solution (in the host's dof order). */
    double q_a, q_b;
    CHECK(seam_evaluate(emb, rhs, n));
    CHECK(seam_heat(emb, 0, &q_a, &q_b));
    double exact = 2 * PI * H * (T_A - T_B) /
                   (log(C / A) / K1 + 1.0 / (C * GAP_H) + log(B / C) / K2);
    printf("interface heat: side A %.17g W, side B %.17g W\n", q_a, q_b);
    printf("logarithmic solution: %.17g W\n", exact);
    printf("temperature at r = c: inner %.17g K, outer %.17g K\n", u[node(0, NR1, 0)],
           u[node(1, 0, 0)]);
    seam_embedding_free(emb);
    free(coords), free(conn), free(dof), free(u), free(a), free(rhs);
    return 0;
}
