/*
 * The host's own finite-element pieces, shared by the C hosts main.c, sector.c and
 * axisymmetric.c (each uses what it needs: the functions are inline): a CHECK of seam's
 * status codes, the conduction matrix of a trilinear hexahedron and a dense linear
 * solver. Nothing here is seam's; a real host has its own.
 */
#ifndef HOST_FEM_H
#define HOST_FEM_H

#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "seam.h"

/* Stop the host with seam's message when a call fails. */
#define CHECK(call)                                                                  \
    do {                                                                             \
        int status_ = (call);                                                        \
        if (status_ != SEAM_OK) {                                                    \
            fprintf(stderr, "%s failed (%d): %s\n", #call, status_, seam_last_error()); \
            exit(1);                                                                 \
        }                                                                            \
    } while (0)

/* K_e of a trilinear hexahedron, 2x2x2 Gauss: k * integral of grad N_a . grad N_b. */
static inline void hex8_conduction(const double x[8][3], double k, double ke[8][8]) {
    static const double s[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                   {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
    const double g = 1.0 / sqrt(3.0);
    memset(ke, 0, sizeof(double) * 64);
    for (int q = 0; q < 8; q++) {
        double xi[3] = {s[q][0] * g, s[q][1] * g, s[q][2] * g};
        double dn[8][3], jac[3][3] = {{0}}, inv[3][3], grad[8][3];
        for (int a = 0; a < 8; a++)
            for (int d = 0; d < 3; d++) {
                double v = 0.125 * s[a][d];
                for (int e = 0; e < 3; e++)
                    if (e != d) v *= 1.0 + s[a][e] * xi[e];
                dn[a][d] = v;
            }
        for (int a = 0; a < 8; a++)
            for (int r = 0; r < 3; r++)
                for (int c = 0; c < 3; c++) jac[r][c] += x[a][r] * dn[a][c];
        double det = jac[0][0] * (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1]) -
                     jac[0][1] * (jac[1][0] * jac[2][2] - jac[1][2] * jac[2][0]) +
                     jac[0][2] * (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]);
        /* inv = J^-1 (J maps reference to physical: J[r][c] = dx_r / dxi_c). */
        inv[0][0] = (jac[1][1] * jac[2][2] - jac[1][2] * jac[2][1]) / det;
        inv[0][1] = (jac[0][2] * jac[2][1] - jac[0][1] * jac[2][2]) / det;
        inv[0][2] = (jac[0][1] * jac[1][2] - jac[0][2] * jac[1][1]) / det;
        inv[1][0] = (jac[1][2] * jac[2][0] - jac[1][0] * jac[2][2]) / det;
        inv[1][1] = (jac[0][0] * jac[2][2] - jac[0][2] * jac[2][0]) / det;
        inv[1][2] = (jac[0][2] * jac[1][0] - jac[0][0] * jac[1][2]) / det;
        inv[2][0] = (jac[1][0] * jac[2][1] - jac[1][1] * jac[2][0]) / det;
        inv[2][1] = (jac[0][1] * jac[2][0] - jac[0][0] * jac[2][1]) / det;
        inv[2][2] = (jac[0][0] * jac[1][1] - jac[0][1] * jac[1][0]) / det;
        /* dN/dx_r = sum_c dN/dxi_c dxi_c/dx_r = sum_c dn[c] inv[c][r]. */
        for (int a = 0; a < 8; a++)
            for (int r = 0; r < 3; r++)
                grad[a][r] = dn[a][0] * inv[0][r] + dn[a][1] * inv[1][r] + dn[a][2] * inv[2][r];
        for (int a = 0; a < 8; a++)
            for (int b = 0; b < 8; b++)
                ke[a][b] += k * det *
                            (grad[a][0] * grad[b][0] + grad[a][1] * grad[b][1] +
                             grad[a][2] * grad[b][2]);
    }
}

/* Solve A x = b in place (b becomes x) by Gaussian elimination with partial pivoting. */
static inline int solve_dense(double *a, double *b, size_t n) {
    for (size_t c = 0; c < n; c++) {
        size_t p = c;
        for (size_t r = c + 1; r < n; r++)
            if (fabs(a[r * n + c]) > fabs(a[p * n + c])) p = r;
        if (a[p * n + c] == 0.0) return -1;
        if (p != c) {
            for (size_t k = 0; k < n; k++) {
                double t = a[c * n + k];
                a[c * n + k] = a[p * n + k];
                a[p * n + k] = t;
            }
            double t = b[c];
            b[c] = b[p];
            b[p] = t;
        }
        for (size_t r = c + 1; r < n; r++) {
            double f = a[r * n + c] / a[c * n + c];
            if (f == 0.0) continue;
            for (size_t k = c; k < n; k++) a[r * n + k] -= f * a[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (size_t c = n; c-- > 0;) {
        double s = b[c];
        for (size_t k = c + 1; k < n; k++) s -= a[c * n + k] * b[k];
        b[c] = s / a[c * n + c];
    }
    return 0;
}

#endif /* HOST_FEM_H */
