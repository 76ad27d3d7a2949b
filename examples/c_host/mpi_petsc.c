/*
 * A host on MPI and PETSc that embeds seam rank by rank (seam_rank_* in seam.h).
 *
 * The problem: two bricks side by side, a = [0,1]^3 (3 x 4 x 4 hexahedra, k = 2 W/m/K)
 * and b = [1,2] x [0,1]^2 (2 x 5 x 3 hexahedra, k = 5 W/m/K), their faces at x = 1
 * non-matching, joined by a gap conductance h = 50 W/m^2/K; T = 400 K at x = 0 and
 * T = 300 K at x = 2, every other face insulated. The answer is 1-D: a heat of
 * 100 / (1/2 + 1/50 + 1/5) W through the interface, T linear in each brick.
 *
 * Every rank makes the whole (small) mesh and keeps its part: rank r owns a contiguous
 * slab of the element list (a's elements, then b's, x slowest), so from 2 ranks on the
 * interface is cut and pairs straddle ranks. A node belongs to the lowest rank among its
 * elements; PETSc's global dofs number the nodes rank after rank. Each rank gives seam
 * its elements' nodes (owned and ghost) with their global ids and dofs and the interface
 * faces of its elements, assembles its elements' conduction into an MPIAIJ matrix, adds
 * seam's terms of its own side-A points (ADD_VALUES), fixes the Dirichlet rows and solves
 * with KSP (MUMPS LU by default; PETSc options override). Rank 0 prints the interface
 * heat and the temperature at every node (by global id), and the flux at every contact
 * point weighted and summed over the ranks, each rank reading its own points
 * (seam_rank_point_fields), with the count of points, and the same from the mean flux
 * of every face (seam_rank_face_fields: side A's and side B's), with the count of faces.
 *
 * `mpi_petsc serial` (on one rank) solves the same problem through the serial embedding
 * (seam_embedding_*) with a dense solve instead, for comparison.
 *
 * `mpi_petsc tie` ties the two faces by a mortar tie with standard multipliers instead
 * (T continuous: a heat of 100 / (1/2 + 1/5) W): each rank gets the rows C u = g of the
 * multipliers whose side-A node it owns (seam_rank_constraints, seam_rank_tie_rows) and
 * their places in the whole tie (seam_rank_tie_index); the host numbers the multipliers
 * after every node, as extra rows of the last rank, adds C and C^T (ADD_VALUES) and
 * solves [K C^T; C 0] [T; lambda] = [F; g] by MUMPS; the heat comes from its
 * multipliers (seam_rank_tie_heat) and from the multiplier field at the contact points
 * (seam_rank_tie_point_fields, weighted and summed over the ranks). `mpi_petsc tie dual`
 * does the same with dual multipliers, and also recovers them from its own residual
 * K T - F without the tie at its multipliers' dofs (seam_rank_dual_multipliers) and
 * takes the tie's heat from that residual (seam_rank_dual_tie_heat), as a host that
 * condensed the tie would: rank 0 prints the largest difference from the solved ones.
 *
 * Build: make -C examples/c_host mpi_petsc (needs petsc-dev and libseam built with
 * --features mpi); run: mpirun -n 4 examples/c_host/mpi_petsc.
 */
#include <petsc.h>

#include "host_fem.h"

enum { NXA = 3, NYA = 4, NZA = 4, NXB = 2, NYB = 5, NZB = 3 };
#define KA 2.0
#define KB 5.0
#define H 50.0
#define T_LEFT 400.0
#define T_RIGHT 300.0
#define NODES_A ((NXA + 1) * (NYA + 1) * (NZA + 1))
#define NODES ((NODES_A) + (NXB + 1) * (NYB + 1) * (NZB + 1))
#define ELEMS_A (NXA * NYA * NZA)
#define ELEMS ((ELEMS_A) + NXB * NYB * NZB)

/* The whole mesh, the same on every rank. */
typedef struct {
    double xyz[NODES][3];
    int conn[ELEMS][8]; /* global node ids, Exodus order */
    int interface_side[ELEMS]; /* 2: a's face at x = 1 (side A), 4: b's (side B), 0 none */
    double fixed[NODES]; /* Dirichlet value, or NAN */
} Mesh;

static void make_mesh(Mesh *m) {
    const int nx[2] = {NXA, NXB}, ny[2] = {NYA, NYB}, nz[2] = {NZA, NZB};
    const double x0[2] = {0.0, 1.0};
    int node0 = 0, elem = 0;
    for (int blk = 0; blk < 2; blk++) {
        int sx = nx[blk] + 1, sy = ny[blk] + 1;
        for (int k = 0; k <= nz[blk]; k++)
            for (int j = 0; j <= ny[blk]; j++)
                for (int i = 0; i <= nx[blk]; i++) {
                    int n = node0 + i + sx * (j + sy * k);
                    m->xyz[n][0] = x0[blk] + (double)i / nx[blk];
                    m->xyz[n][1] = (double)j / ny[blk];
                    m->xyz[n][2] = (double)k / nz[blk];
                    m->fixed[n] = NAN;
                    if (blk == 0 && i == 0) m->fixed[n] = T_LEFT;
                    if (blk == 1 && i == nx[blk]) m->fixed[n] = T_RIGHT;
                }
        for (int i = 0; i < nx[blk]; i++)
            for (int k = 0; k < nz[blk]; k++)
                for (int j = 0; j < ny[blk]; j++, elem++) {
                    int c[8][3] = {{i, j, k},         {i + 1, j, k},     {i + 1, j + 1, k},
                                   {i, j + 1, k},     {i, j, k + 1},     {i + 1, j, k + 1},
                                   {i + 1, j + 1, k + 1}, {i, j + 1, k + 1}};
                    for (int a = 0; a < 8; a++)
                        m->conn[elem][a] = node0 + c[a][0] + sx * (c[a][1] + sy * c[a][2]);
                    m->interface_side[elem] = 0;
                    if (blk == 0 && i == nx[blk] - 1) m->interface_side[elem] = 2;
                    if (blk == 1 && i == 0) m->interface_side[elem] = 4;
                }
        node0 += sx * sy * (nz[blk] + 1);
    }
}

static void element_matrix(const Mesh *m, int e, double ke[8][8]) {
    double x[8][3];
    for (int a = 0; a < 8; a++)
        for (int d = 0; d < 3; d++) x[a][d] = m->xyz[m->conn[e][a]][d];
    hex8_conduction(x, e < ELEMS_A ? KA : KB, ke);
}

static void print_results(const Mesh *m, const double *t_by_node, double qa, double qb,
                          int ranks, size_t across) {
    printf("ranks: %d\npoints across ranks: %zu\nheat: %.17g %.17g\n", ranks, across, qa, qb);
    printf("x:");
    for (int n = 0; n < NODES; n++) printf(" %.17g", m->xyz[n][0]);
    printf("\ntemperature:");
    for (int n = 0; n < NODES; n++) printf(" %.17g", t_by_node[n]);
    printf("\n");
}

/* The entries of the distributed vector `from` at global rows `rows` (n of them), into
 * `out` on this rank (collective over from's communicator). */
static PetscErrorCode gather_at(Vec from, PetscInt n, const PetscInt *rows, double *out) {
    IS at;
    Vec local;
    VecScatter scatter;
    const PetscScalar *v;
    PetscFunctionBeginUser;
    PetscCall(ISCreateGeneral(PETSC_COMM_SELF, n, rows, PETSC_COPY_VALUES, &at));
    PetscCall(VecCreateSeq(PETSC_COMM_SELF, n, &local));
    PetscCall(VecScatterCreate(from, at, local, NULL, &scatter));
    PetscCall(VecScatterBegin(scatter, from, local, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(scatter, from, local, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecGetArrayRead(local, &v));
    for (PetscInt k = 0; k < n; k++) out[k] = v[k];
    PetscCall(VecRestoreArrayRead(local, &v));
    PetscCall(VecScatterDestroy(&scatter));
    PetscCall(VecDestroy(&local));
    PetscCall(ISDestroy(&at));
    PetscFunctionReturn(0); /* PETSc 3.18 has no PETSC_SUCCESS */
}

/* The same problem through the serial embedding and a dense solve. */
static int serial(const Mesh *m) {
    static double k[NODES * NODES], t[NODES];
    int64_t conn[ELEMS * 8], dofs[NODES];
    size_t n_right = 0, n_left = 0;
    int64_t right_elem[ELEMS], left_elem[ELEMS];
    int right_side[ELEMS], left_side[ELEMS];
    for (int e = 0; e < ELEMS; e++) {
        for (int a = 0; a < 8; a++) conn[8 * e + a] = m->conn[e][a];
        if (m->interface_side[e] == 2) {
            right_elem[n_right] = e;
            right_side[n_right++] = 2;
        } else if (m->interface_side[e] == 4) {
            left_elem[n_left] = e;
            left_side[n_left++] = 4;
        }
    }
    for (int n = 0; n < NODES; n++) dofs[n] = n;
    seam_builder *b;
    seam_embedding *s;
    CHECK(seam_builder_new(&m->xyz[0][0], NODES, &b));
    CHECK(seam_builder_add_block(b, "a", SEAM_HEX8, conn, ELEMS_A, KA));
    CHECK(seam_builder_add_block(b, "b", SEAM_HEX8, conn + 8 * ELEMS_A, ELEMS - ELEMS_A, KB));
    CHECK(seam_builder_add_side_set(b, "right", right_elem, right_side, n_right));
    CHECK(seam_builder_add_side_set(b, "left", left_elem, left_side, n_left));
    CHECK(seam_builder_set_dofs(b, dofs, NODES));
    CHECK(seam_embedding_new(b, &s));
    seam_builder_free(b);
    CHECK(seam_add_interaction(s, "right", "left", SEAM_GAP_CONDUCTANCE, H, 0.0, NULL));
    CHECK(seam_search(s));
    for (int e = 0; e < ELEMS; e++) {
        double ke[8][8];
        element_matrix(m, e, ke);
        for (int a = 0; a < 8; a++)
            for (int c = 0; c < 8; c++) k[m->conn[e][a] * NODES + m->conn[e][c]] += ke[a][c];
    }
    CHECK(seam_evaluate(s, t, NODES)); /* t = 0: the Jacobian of a linear model */
    size_t n;
    const int64_t *rows, *cols;
    const double *vals;
    CHECK(seam_jacobian(s, &n, &rows, &cols, &vals));
    for (size_t q = 0; q < n; q++) k[rows[q] * NODES + cols[q]] += vals[q];
    /* Dirichlet rows and columns: the identity's, their values moved to the right. */
    for (int r = 0; r < NODES; r++) {
        if (isnan(m->fixed[r])) continue;
        for (int i = 0; i < NODES; i++) {
            t[i] -= k[i * NODES + r] * m->fixed[r];
            k[i * NODES + r] = 0.0;
            k[r * NODES + i] = 0.0;
        }
    }
    for (int r = 0; r < NODES; r++)
        if (!isnan(m->fixed[r])) {
            k[r * NODES + r] = 1.0;
            t[r] = m->fixed[r];
        }
    if (solve_dense(k, t, NODES) != 0) {
        fprintf(stderr, "the serial system is singular\n");
        return 1;
    }
    double qa, qb;
    CHECK(seam_heat_at(s, 0, t, NODES, &qa, &qb));
    print_results(m, t, qa, qb, 1, 0);
    seam_embedding_free(s);
    return 0;
}

/* The last seam_rank_evaluate's terms of this rank's points, added to the matrix `a`
 * and the load `b` in the host's global dofs (PETSc moves the entries of other ranks'
 * rows at assembly). */
static PetscErrorCode add_triplets(seam_rank_embedding *s, Mat a, Vec b) {
    size_t n;
    const int64_t *rows, *cols, *dofs;
    const double *vals;
    PetscFunctionBeginUser;
    CHECK(seam_rank_jacobian(s, &n, &rows, &cols, &vals));
    for (size_t q = 0; q < n; q++)
        PetscCall(MatSetValue(a, (PetscInt)rows[q], (PetscInt)cols[q], vals[q], ADD_VALUES));
    CHECK(seam_rank_load(s, &n, &dofs, &vals));
    for (size_t q = 0; q < n; q++)
        PetscCall(VecSetValue(b, (PetscInt)dofs[q], vals[q], ADD_VALUES));
    PetscFunctionReturn(0);
}

/* The interface terms through the CSR form (seam_rank_evaluate_csr at u, this rank's
 * rows added row by row) against the triplets of the last seam_rank_evaluate at the same
 * u (which it replaces): prints the largest difference of the matrices and of the loads
 * over the ranks, and the count of CSR entries over the ranks. */
static PetscErrorCode csr_against_triplets(seam_rank_embedding *s, int rank, PetscInt local_rows,
                                           const double *u, size_t n_local) {
    Mat T, C;
    Vec lt, lc;
    PetscReal dm, dv;
    size_t n_rows, nnz;
    const size_t *csr_rows, *offsets, *columns;
    const double *csr_vals, *csr_load;
    uint64_t pattern;
    PetscFunctionBeginUser;
    PetscCall(MatCreateAIJ(PETSC_COMM_WORLD, local_rows, local_rows, PETSC_DETERMINE,
                           PETSC_DETERMINE, 64, NULL, 64, NULL, &T));
    PetscCall(MatSetOption(T, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
    PetscCall(MatDuplicate(T, MAT_DO_NOT_COPY_VALUES, &C));
    PetscCall(MatCreateVecs(T, &lt, &lc));
    PetscCall(add_triplets(s, T, lt));
    CHECK(seam_rank_evaluate_csr(s, u, n_local));
    CHECK(seam_rank_jacobian_csr(s, &n_rows, &nnz, &csr_rows, &offsets, &columns, &csr_vals,
                                 &pattern));
    CHECK(seam_rank_vector_csr(s, 1, &n_rows, &csr_load));
    for (size_t r = 0; r < n_rows; r++) {
        for (size_t k = offsets[r]; k < offsets[r + 1]; k++)
            PetscCall(MatSetValue(C, (PetscInt)csr_rows[r], (PetscInt)columns[k], csr_vals[k],
                                  ADD_VALUES));
        PetscCall(VecSetValue(lc, (PetscInt)csr_rows[r], csr_load[r], ADD_VALUES));
    }
    PetscCall(MatAssemblyBegin(T, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(T, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyBegin(C, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(C, MAT_FINAL_ASSEMBLY));
    PetscCall(VecAssemblyBegin(lt));
    PetscCall(VecAssemblyEnd(lt));
    PetscCall(VecAssemblyBegin(lc));
    PetscCall(VecAssemblyEnd(lc));
    PetscCall(MatAXPY(T, -1.0, C, DIFFERENT_NONZERO_PATTERN));
    PetscCall(MatNorm(T, NORM_INFINITY, &dm));
    PetscCall(VecAXPY(lt, -1.0, lc));
    PetscCall(VecNorm(lt, NORM_INFINITY, &dv));
    unsigned long long mine = nnz, all;
    PetscCallMPI(MPI_Allreduce(&mine, &all, 1, MPI_UNSIGNED_LONG_LONG, MPI_SUM, PETSC_COMM_WORLD));
    if (rank == 0) printf("csr against triplets: %.3e %.3e %llu\n", (double)dm, (double)dv, all);
    PetscCall(MatDestroy(&T));
    PetscCall(MatDestroy(&C));
    PetscCall(VecDestroy(&lt));
    PetscCall(VecDestroy(&lc));
    PetscFunctionReturn(0);
}

int main(int argc, char **argv) {
    static Mesh m;
    PetscMPIInt rank, size;
    PetscCall(PetscInitialize(&argc, &argv, NULL, NULL));
    PetscCallMPI(MPI_Comm_rank(PETSC_COMM_WORLD, &rank));
    PetscCallMPI(MPI_Comm_size(PETSC_COMM_WORLD, &size));
    make_mesh(&m);
    if (argc > 1 && strcmp(argv[1], "serial") == 0) {
        int status = size == 1 ? serial(&m) : 2;
        if (size != 1) fprintf(stderr, "`serial` runs on one rank\n");
        PetscCall(PetscFinalize());
        return status;
    }

    const int tie = argc > 1 && strcmp(argv[1], "tie") == 0;
    const int dual = tie && argc > 2 && strcmp(argv[2], "dual") == 0;

    /* Partition: slabs of the element list; a node to the lowest rank among its elements. */
    static int elem_rank[ELEMS], node_rank[NODES], dof[NODES], local_of[NODES];
    for (int e = 0; e < ELEMS; e++) elem_rank[e] = (int)((long)e * size / ELEMS);
    for (int n = 0; n < NODES; n++) node_rank[n] = size;
    for (int e = 0; e < ELEMS; e++)
        for (int a = 0; a < 8; a++) {
            int n = m.conn[e][a];
            if (elem_rank[e] < node_rank[n]) node_rank[n] = elem_rank[e];
        }
    /* PETSc's numbering: the nodes rank after rank, by global id inside a rank. */
    int next = 0, owned = 0;
    for (int r = 0; r < size; r++)
        for (int n = 0; n < NODES; n++)
            if (node_rank[n] == r) {
                if (r == rank) owned++;
                dof[n] = next++;
            }

    /* This rank's part: its elements, their nodes (owned and ghost) in first-seen order. */
    static double xyz[NODES][3];
    static int64_t gid[NODES], gdof[NODES], conn[ELEMS * 8], right[ELEMS], left[ELEMS];
    static int right_side[ELEMS], left_side[ELEMS];
    int n_local = 0, n_a = 0, n_b = 0;
    size_t n_right = 0, n_left = 0;
    for (int n = 0; n < NODES; n++) local_of[n] = -1;
    for (int pass = 0; pass < 2; pass++) /* block a's elements, then b's */
        for (int e = 0; e < ELEMS; e++) {
            if (elem_rank[e] != rank || (e < ELEMS_A) != (pass == 0)) continue;
            int local_elem = n_a + n_b;
            for (int a = 0; a < 8; a++) {
                int n = m.conn[e][a];
                if (local_of[n] < 0) {
                    local_of[n] = n_local;
                    memcpy(xyz[n_local], m.xyz[n], sizeof xyz[0]);
                    gid[n_local] = n;
                    gdof[n_local] = dof[n];
                    n_local++;
                }
                conn[8 * local_elem + a] = local_of[n];
            }
            if (m.interface_side[e] == 2) {
                right[n_right] = local_elem;
                right_side[n_right++] = 2;
            } else if (m.interface_side[e] == 4) {
                left[n_left] = local_elem;
                left_side[n_left++] = 4;
            }
            if (pass == 0) n_a++;
            else n_b++;
        }

    seam_builder *b;
    seam_rank_embedding *s;
    CHECK(seam_builder_new(&xyz[0][0], (size_t)n_local, &b));
    CHECK(seam_builder_add_block(b, "a", SEAM_HEX8, conn, (size_t)n_a, KA));
    CHECK(seam_builder_add_block(b, "b", SEAM_HEX8, conn + 8 * n_a, (size_t)n_b, KB));
    CHECK(seam_builder_add_side_set(b, "right", right, right_side, n_right));
    CHECK(seam_builder_add_side_set(b, "left", left, left_side, n_left));
    CHECK(seam_builder_set_dofs(b, gdof, (size_t)n_local));
    CHECK(seam_rank_new(b, PETSC_COMM_WORLD, gid, (size_t)n_local, &s));
    seam_builder_free(b);
    CHECK(seam_rank_add_interaction(s, "right", "left",
                                    dual ? SEAM_TIED_DUAL_MORTAR : tie ? SEAM_TIED_MORTAR : SEAM_GAP_CONDUCTANCE, H, 0.0,
                                    NULL));
    CHECK(seam_rank_search(s));
    size_t across;
    CHECK(seam_rank_points_across(s, &across));

    /* A tie: this rank's multipliers' rows, and where they sit in the whole tie. */
    size_t n_mult = 0, n_entries = 0, total = 0;
    const int64_t *mult_dofs = NULL, *mults = NULL, *mult_cols = NULL, *place = NULL;
    const double *g = NULL, *c_values = NULL;
    if (tie) {
        size_t n_rows;
        const int64_t *rdofs, *rcols;
        const double *rconst, *rcoef;
        const size_t *roffsets;
        CHECK(seam_rank_constraints(s, &n_rows, &rdofs, &rconst, &roffsets, &rcols, &rcoef));
        CHECK(seam_rank_tie_rows(s, 0, &n_mult, &mult_dofs, &g, &n_entries, &mults, &mult_cols,
                                 &c_values));
        CHECK(seam_rank_tie_index(s, 0, &place, &total));
    }
    /* The multipliers are numbered after every node, as the last rank's extra rows. */
    const PetscInt local_rows = owned + (rank == size - 1 ? (PetscInt)total : 0);

    /* Conduction of this rank's elements, then seam's terms of its own side-A points. */
    Mat A, K; /* K: the conduction alone, for the residual without the tie */
    Vec rhs, t;
    PetscCall(MatCreateAIJ(PETSC_COMM_WORLD, local_rows, local_rows, PETSC_DETERMINE,
                           PETSC_DETERMINE, 64, NULL, 64, NULL, &A));
    PetscCall(MatCreateAIJ(PETSC_COMM_WORLD, local_rows, local_rows, PETSC_DETERMINE,
                           PETSC_DETERMINE, 27, NULL, 27, NULL, &K));
    PetscCall(MatSetOption(A, MAT_NEW_NONZERO_ALLOCATION_ERR, PETSC_FALSE));
    PetscCall(MatCreateVecs(A, &t, &rhs));
    for (int e = 0; e < ELEMS; e++) {
        if (elem_rank[e] != rank) continue;
        double ke[8][8];
        PetscInt rows[8];
        element_matrix(&m, e, ke);
        for (int a = 0; a < 8; a++) rows[a] = dof[m.conn[e][a]];
        PetscCall(MatSetValues(A, 8, rows, 8, rows, &ke[0][0], ADD_VALUES));
        PetscCall(MatSetValues(K, 8, rows, 8, rows, &ke[0][0], ADD_VALUES));
    }
    static double zero[NODES];
    /* A bad argument on one rank (no field on the last) fails the call on every rank, that
     * rank with its own status and the others with SEAM_ERR_OTHER_RANK: none is left
     * waiting in the collective. */
    const int last = rank == size - 1;
    int status = seam_rank_evaluate(s, last ? NULL : zero, (size_t)n_local);
    int as_expected = status == (last ? SEAM_ERR_NULL_ARGUMENT : SEAM_ERR_OTHER_RANK), all_expected;
    PetscCallMPI(MPI_Allreduce(&as_expected, &all_expected, 1, MPI_INT, MPI_LAND, PETSC_COMM_WORLD));
    if (rank == 0) printf("bad argument refused on every rank: %d\n", all_expected);
    /* The host's time, which every rank must give alike: a time that differs on the last
     * rank is refused on every rank (SEAM_ERR_ARGUMENT); then the same time everywhere. */
    status = seam_rank_set_time(s, size > 1 && last ? 1.0 : 0.0);
    int time_ok = status == (size > 1 ? SEAM_ERR_ARGUMENT : SEAM_OK), all_time_ok;
    PetscCallMPI(MPI_Allreduce(&time_ok, &all_time_ok, 1, MPI_INT, MPI_LAND, PETSC_COMM_WORLD));
    if (rank == 0) printf("differing times refused on every rank: %d\n", all_time_ok);
    CHECK(seam_rank_set_time(s, 0.0));
    CHECK(seam_rank_set_active(s, 0, 1));
    CHECK(seam_rank_evaluate(s, zero, (size_t)n_local)); /* a linear model: J at any u */
    {
        /* A constant model fails nowhere: no point quarantined on any rank. */
        size_t own, total;
        const double *xyz;
        const char *reasons;
        CHECK(seam_rank_quarantined(s, 0, &own, &xyz, &reasons, &total));
        if (rank == 0) printf("quarantined: %zu\n", total + own);
    }
    PetscCall(add_triplets(s, A, rhs));
    PetscCall(csr_against_triplets(s, rank, local_rows, zero, (size_t)n_local));
    for (size_t q = 0; q < n_entries; q++) { /* C and C^T of this rank's multipliers */
        PetscInt row = NODES + (PetscInt)place[mults[q]], col = (PetscInt)mult_cols[q];
        PetscCall(MatSetValue(A, row, col, c_values[q], ADD_VALUES));
        PetscCall(MatSetValue(A, col, row, c_values[q], ADD_VALUES));
    }
    for (size_t k = 0; k < n_mult; k++)
        PetscCall(VecSetValue(rhs, NODES + (PetscInt)place[k], g[k], ADD_VALUES));
    PetscCall(MatAssemblyBegin(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(A, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyBegin(K, MAT_FINAL_ASSEMBLY));
    PetscCall(MatAssemblyEnd(K, MAT_FINAL_ASSEMBLY));
    PetscCall(VecAssemblyBegin(rhs));
    PetscCall(VecAssemblyEnd(rhs));

    /* Dirichlet: this rank's fixed rows and columns become the identity's. */
    static PetscInt fixed_rows[NODES];
    PetscInt n_fixed = 0;
    for (int g = 0; g < NODES; g++)
        if (node_rank[g] == rank && !isnan(m.fixed[g])) {
            fixed_rows[n_fixed++] = dof[g];
            PetscCall(VecSetValue(t, dof[g], m.fixed[g], INSERT_VALUES));
        }
    PetscCall(VecAssemblyBegin(t));
    PetscCall(VecAssemblyEnd(t));
    PetscCall(MatZeroRowsColumns(A, n_fixed, fixed_rows, 1.0, t, rhs));

    KSP ksp;
    PC pc;
    PetscCall(KSPCreate(PETSC_COMM_WORLD, &ksp));
    PetscCall(KSPSetOperators(ksp, A, A));
    PetscCall(KSPSetType(ksp, KSPPREONLY));
    PetscCall(KSPGetPC(ksp, &pc));
    PetscCall(PCSetType(pc, PCLU));
    PetscCall(PCFactorSetMatSolverType(pc, MATSOLVERMUMPS));
    PetscCall(KSPSetFromOptions(ksp));
    PetscCall(KSPSolve(ksp, rhs, t));

    /* The solution at this rank's nodes (owned and ghost), for seam's heat. */
    static PetscInt local_dofs[NODES];
    static double t_local[NODES];
    for (int k = 0; k < n_local; k++) local_dofs[k] = (PetscInt)gdof[k];
    PetscCall(gather_at(t, n_local, local_dofs, t_local));
    CHECK(seam_rank_evaluate(s, t_local, (size_t)n_local));
    double qa, qb;
    if (tie) { /* this rank's multipliers from the solution, for the tie's heat */
        static PetscInt at[NODES];
        static double lambda[NODES];
        for (size_t k = 0; k < n_mult; k++) at[k] = NODES + (PetscInt)place[k];
        PetscCall(gather_at(t, (PetscInt)n_mult, at, lambda));
        CHECK(seam_rank_tie_heat(s, 0, lambda, n_mult, &qa, &qb));
        /* The multiplier field at this rank's own points, weighted and summed over the
         * ranks: the flux density integrated over the face, the tie's heat. */
        size_t n_points;
        const seam_point_values *values;
        const size_t *points;
        const int *side_b_ranks;
        CHECK(seam_rank_tie_point_fields(s, 0, lambda, n_mult, &n_points, &values, &points,
                                         &side_b_ranks));
        double own[2] = {0.0, (double)n_points}, all[2];
        for (size_t k = 0; k < n_points; k++)
            if (values[k].has_multiplier) own[0] += values[k].multiplier * values[k].weight;
        PetscCallMPI(MPI_Allreduce(own, all, 2, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD));
        if (rank == 0) printf("point fields: %.17g %.0f\n", all[0], all[1]);
        if (dual) { /* the multipliers again, from K T (no source: F = 0) */
            static double r_at[NODES], recovered[NODES];
            Vec kt;
            PetscCall(VecDuplicate(t, &kt));
            PetscCall(MatMult(K, t, kt));
            for (size_t k = 0; k < n_mult; k++) at[k] = (PetscInt)mult_dofs[k];
            PetscCall(gather_at(kt, (PetscInt)n_mult, at, r_at));
            PetscCall(VecDestroy(&kt));
            CHECK(seam_rank_dual_multipliers(s, 0, r_at, n_mult, recovered, NODES));
            double worst = 0.0, all_worst;
            for (size_t k = 0; k < n_mult; k++) worst = fmax(worst, fabs(recovered[k] - lambda[k]));
            PetscCallMPI(MPI_Reduce(&worst, &all_worst, 1, MPI_DOUBLE, MPI_MAX, 0,
                                    PETSC_COMM_WORLD));
            if (rank == 0) printf("dual multipliers from the residual: %.3e\n", all_worst);
            /* The heat straight from the residual, as a condensing host would take it. */
            double ra, rb;
            CHECK(seam_rank_dual_tie_heat(s, 0, r_at, n_mult, &ra, &rb));
            if (rank == 0) printf("dual heat from the residual: %.17g %.17g\n", ra, rb);
        }
    } else {
        CHECK(seam_rank_heat(s, 0, &qa, &qb));
        /* The flux at this rank's own contact points, weighted and summed over the
         * ranks: each point is one rank's, so the sum is the interface's heat. */
        size_t n_points;
        const seam_point_values *values;
        const size_t *points;
        const int *side_b_ranks;
        CHECK(seam_rank_point_fields(s, 0, t_local, (size_t)n_local, &n_points, &values, &points,
                                     &side_b_ranks));
        double own[2] = {0.0, (double)n_points}, all[2];
        for (size_t k = 0; k < n_points; k++) {
            if (!values[k].paired) continue;
            own[0] += values[k].flux * values[k].weight;
            /* Side A is this rank's own element, side B an element of side_b_ranks[k]. */
            if (values[k].side_a_element < 0 || side_b_ranks[k] < 0 || side_b_ranks[k] >= size) {
                fprintf(stderr, "rank %d: point %zu names faces it should not\n", rank, points[k]);
                return 1;
            }
        }
        PetscCallMPI(MPI_Allreduce(own, all, 2, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD));
        if (rank == 0) printf("point fields: %.17g %.0f\n", all[0], all[1]);
        /* What the search paired: the whole interaction's, on every rank. */
        seam_coverage_info coverage;
        CHECK(seam_rank_coverage(s, 0, &coverage));
        if (rank == 0)
            printf("coverage: %zu %zu %.17g\n", coverage.points, coverage.paired_points,
                   coverage.paired_area);
        /* Per face, the mean flux over its paired area, on the faces this rank gave:
         * summed over the ranks, side A's and side B's each carry the heat. */
        size_t n_faces;
        const seam_face_values *faces;
        CHECK(seam_rank_face_fields(s, 0, t_local, (size_t)n_local, 1, &n_faces, &faces));
        double on[3] = {0.0, 0.0, (double)n_faces}, summed[3];
        for (size_t k = 0; k < n_faces; k++)
            on[faces[k].surface_side] += faces[k].flux * faces[k].paired_area;
        PetscCallMPI(MPI_Allreduce(on, summed, 3, MPI_DOUBLE, MPI_SUM, PETSC_COMM_WORLD));
        if (rank == 0) printf("face fields: %.17g %.17g %.0f\n", summed[0], summed[1], summed[2]);
    }

    /* Rank 0 prints every node's temperature, by global id. */
    Vec t0;
    VecScatter to_zero;
    PetscCall(VecScatterCreateToZero(t, &to_zero, &t0));
    PetscCall(VecScatterBegin(to_zero, t, t0, INSERT_VALUES, SCATTER_FORWARD));
    PetscCall(VecScatterEnd(to_zero, t, t0, INSERT_VALUES, SCATTER_FORWARD));
    if (rank == 0) {
        static double by_node[NODES];
        const PetscScalar *all;
        PetscCall(VecGetArrayRead(t0, &all));
        for (int g = 0; g < NODES; g++) by_node[g] = all[dof[g]];
        PetscCall(VecRestoreArrayRead(t0, &all));
        print_results(&m, by_node, qa, qb, size, across);
    }

    seam_rank_free(s);
    PetscCall(VecScatterDestroy(&to_zero));
    PetscCall(VecDestroy(&t0));
    PetscCall(KSPDestroy(&ksp));
    PetscCall(VecDestroy(&t));
    PetscCall(VecDestroy(&rhs));
    PetscCall(MatDestroy(&A));
    PetscCall(MatDestroy(&K));
    PetscCall(PetscFinalize());
    return 0;
}
