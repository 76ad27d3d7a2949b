/*
 * seam.h — the C API of libseam: interface enforcement (contact surfaces, search,
 * gap conductance, ties, mortar) for a host code that owns its mesh and its matrix.
 *
 * Usage (see docs/embedding.md and examples/c_host/main.c):
 *   seam_builder_new(coords, n_nodes, &b);            host node coordinates, xyz per node
 *   seam_builder_add_block(b, "base", SEAM_HEX8, conn, n_elems, k);
 *   seam_builder_add_face_set(b, "top", face_nodes, 4, n_faces);   or _add_side_set
 *   seam_builder_set_dofs(b, dof_of_node, n_nodes);   the host's dof numbers
 *   seam_embedding_new(b, &e); seam_builder_free(b);
 *   seam_add_interaction(e, "top", "bottom", SEAM_GAP_CONDUCTANCE, 500.0, 0.0, NULL);
 *   seam_search(e);
 *   seam_evaluate(e, u, n_dofs);                      at the host's current field
 *   seam_jacobian(e, &n, &rows, &cols, &vals);         add into the host's matrix
 *   seam_residual(e, &n, &dofs, &vals);                add into the host's residual
 *   seam_heat(e, 0, &q_a, &q_b);
 *   seam_embedding_free(e);
 *
 * Conventions: indices (nodes, elements, dofs) are 0-based int64_t; elements are
 * numbered block after block; local sides are 1-based in Exodus II order (table below).
 * Every function returns a status (SEAM_OK = 0); on failure seam_last_error() says what
 * went wrong, where, and how to fix it (per thread). No function aborts or unwinds into
 * the caller. A handle must be used by one thread at a time.
 *
 * Ownership and lifetimes:
 *   - Input arrays (`const T *` with a count) are read during the call only and copied
 *     where kept; the caller may free or reuse them as soon as the call returns. A null
 *     array is accepted only with a count of 0.
 *   - Strings (`const char *`) are read during the call only (UTF-8, NUL-terminated).
 *   - Handles (seam_builder *, seam_embedding *) are owned by the caller from the
 *     function that makes them until the matching _free; _free accepts NULL. An
 *     embedding does not keep its builder: free the builder after seam_embedding_new.
 *   - Arrays returned through `const T **` belong to the handle: never free them. They
 *     stay valid until the next call on the same handle that recomputes the same
 *     results (named at each function), a search, a move, an added interaction, or the
 *     handle's _free — copy what must outlive that.
 *   - seam_last_error()'s string belongs to the library (per thread) and stays valid
 *     until the next failing call on that thread.
 *   - A conductance callback and its user_data must stay valid until the embedding is
 *     freed; seam never frees user_data. The callback is called on the thread that
 *     called seam_evaluate / seam_evaluate_csr / a field query, during that call, one
 *     point at a time, and must not call back into the same embedding.
 *
 * Element node order and sides (the Exodus II convention; docs/embedding.md has the
 * same). Reference coordinates of the local nodes (0-based), then each side's local
 * nodes in the order whose right-hand normal points out of the element:
 *   SEAM_HEX8     nodes 0 (-1,-1,-1) 1 (1,-1,-1) 2 (1,1,-1) 3 (-1,1,-1)
 *                       4 (-1,-1,1)  5 (1,-1,1)  6 (1,1,1)  7 (-1,1,1)
 *                 side 1: 0 1 5 4 | side 2: 1 2 6 5 | side 3: 2 3 7 6 |
 *                 side 4: 0 4 7 3 | side 5: 0 3 2 1 | side 6: 4 5 6 7
 *   SEAM_TET4     nodes 0 (0,0,0) 1 (1,0,0) 2 (0,1,0) 3 (0,0,1)
 *                 side 1: 0 1 3 | side 2: 1 2 3 | side 3: 0 3 2 | side 4: 0 2 1
 *   SEAM_WEDGE6   nodes 0 (0,0,-1) 1 (1,0,-1) 2 (0,1,-1) 3 (0,0,1) 4 (1,0,1) 5 (0,1,1)
 *                 side 1: 0 1 4 3 | side 2: 1 2 5 4 | side 3: 0 3 5 2 |
 *                 side 4: 0 2 1 | side 5: 3 4 5
 *   SEAM_PYRAMID5 nodes 0 (-1,-1,0) 1 (1,-1,0) 2 (1,1,0) 3 (-1,1,0) 4 (0,0,1)
 *                 side 1: 0 1 4 | side 2: 1 2 4 | side 3: 2 3 4 | side 4: 0 4 3 |
 *                 side 5: 0 3 2 1
 *   SEAM_QUAD4    nodes 0 (-1,-1) 1 (1,-1) 2 (1,1) 3 (-1,1), counter-clockwise in xy
 *                 side 1: 0 1 | side 2: 1 2 | side 3: 2 3 | side 4: 3 0
 *   SEAM_TRI3     nodes 0 (0,0) 1 (1,0) 2 (0,1), counter-clockwise in xy
 *                 side 1: 0 1 | side 2: 1 2 | side 3: 2 0
 * (A 2-D side's outward normal is its direction turned clockwise by 90 degrees.)
 * An element whose nodes come in another order is inverted or tangled: seam_embedding_new
 * refuses it with SEAM_ERR_MESH and names it, before any face is looked up.
 *
 * Build: link with -lseam (target/<profile>/libseam.so of `cargo build`).
 */
#ifndef SEAM_H
#define SEAM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Status codes. */
#define SEAM_OK 0
#define SEAM_ERR_NULL_ARGUMENT 1 /* a null handle, or a null array with a non-zero length */
#define SEAM_ERR_MESH 2          /* the host's mesh arrays are inconsistent or invalid */
#define SEAM_ERR_DECK 3          /* a contact deck with errors */
#define SEAM_ERR_ARGUMENT 4      /* an argument out of range, an unknown name or code */
#define SEAM_ERR_ORDER 5         /* a call out of order (e.g. evaluate before search) */
#define SEAM_ERR_ENFORCEMENT 6   /* an enforcement failed at a contact point */
#define SEAM_ERR_INTERNAL 7      /* a bug in seam (a caught panic) */
#define SEAM_ERR_PLUGIN 8        /* a plugin could not be loaded, or failed at a contact point */
#define SEAM_CUTBACK 9           /* a conductance model or plugin asks for a smaller step (seam_cutback_factor) */
#define SEAM_ERR_NOTHING_PAIRED 10 /* a flux interaction's search paired no point (seam_allow_unpaired) */
#define SEAM_ERR_OTHER_RANK 11   /* MPI: a collective call failed on another rank (its error says why) */

/* Element topologies: 3-D solids, or 2-D ones (a mesh in the xy plane, z = 0). */
#define SEAM_HEX8 1
#define SEAM_TET4 2
#define SEAM_WEDGE6 3
#define SEAM_PYRAMID5 4
#define SEAM_QUAD4 5
#define SEAM_TRI3 6

/* Interaction models. */
#define SEAM_CONDUCTANCE 1       /* q = h [u] on side A (contact resistance) */
#define SEAM_GAP_CONDUCTANCE 2   /* Robin-Nitsche gap conductance, h in [0, inf] */
#define SEAM_TIED_NITSCHE 3      /* weighted symmetric Nitsche tie */
#define SEAM_TIED_MORTAR 4       /* mortar tie, standard multipliers: rows C u = g */
#define SEAM_TIED_DUAL_MORTAR 5  /* mortar tie, dual multipliers: condensed rows */

/* Periodic maps of seam_add_periodic_interaction, with their parameters. */
#define SEAM_PERIODIC_RECTANGULAR 1   /* offset: dx dy dz */
#define SEAM_PERIODIC_CYLINDRICAL 2   /* axis x y z, center x y z, angle (degrees, right-hand) */
#define SEAM_PERIODIC_ALIGN_SURFACE 3 /* nothing, or invert_normals (1 default, or 0) */

/* Integration of side A. */
#define SEAM_SEGMENTS 0   /* mortar segments (exact; default, order 5) */
#define SEAM_QUADRATURE 1 /* Gauss points of side-A faces, projected */

typedef struct SeamBuilder seam_builder;
typedef struct SeamEmbedding seam_embedding;

const char *seam_version(void);
/* The message of the last failed call on this thread ("" if none). */
const char *seam_last_error(void);

/* --- the host's mesh ------------------------------------------------------------ */
int seam_builder_new(const double *coords, size_t n_nodes, seam_builder **out_builder);
void seam_builder_free(seam_builder *builder);
/* connectivity: n_elems * (nodes of the topology) node indices. k: conductivity W/m/K. */
int seam_builder_add_block(seam_builder *builder, const char *name, int topology,
                           const int64_t *connectivity, size_t n_elems, double conductivity);
/* A surface of (element, 1-based local side) pairs. */
int seam_builder_add_side_set(seam_builder *builder, const char *name, const int64_t *elems,
                              const int *sides, size_t n_faces);
/* A surface of faces by their corner nodes (3 or 4 per face, any order; 2 per edge in a
   2-D mesh). */
int seam_builder_add_face_set(seam_builder *builder, const char *name,
                              const int64_t *face_nodes, size_t nodes_per_face, size_t n_faces);
/* The host's dof of every node; negative: none (only for nodes of no block). */
int seam_builder_set_dofs(seam_builder *builder, const int64_t *dofs, size_t n_nodes);
/* on != 0: a 2-D mesh read as axisymmetric (x the radius r >= 0, y the axis): every
   weight, heat and Jacobian entry is per full revolution (times 2 pi r). */
int seam_builder_set_axisymmetric(seam_builder *builder, int on);
/* Nodes the host prescribes (Dirichlet): mortar ties give them no multiplier. */
int seam_builder_set_fixed_nodes(seam_builder *builder, const int64_t *nodes, size_t n);
/* `order` 1 to 20. */
int seam_builder_set_integration(seam_builder *builder, int kind, int order);

/* --- the embedding ---------------------------------------------------------------- */
/* Checks the builder's arrays; the builder is unchanged and still owned by the caller. */
int seam_embedding_new(const seam_builder *builder, seam_embedding **out_embedding);
void seam_embedding_free(seam_embedding *embedding);
/* h is used by SEAM_CONDUCTANCE and SEAM_GAP_CONDUCTANCE; offset is a prescribed
 * jump u_A - u_B. out_index (may be NULL) receives the interaction's index. */
int seam_add_interaction(seam_embedding *embedding, const char *side_a, const char *side_b,
                         int model, double h, double offset, size_t *out_index);
/* As seam_add_interaction, between the image of side_a under a periodic map (a
 * SEAM_PERIODIC_* code with n_params parameters) and side_b; the image must land on
 * side_b. Lua maps come in a deck. */
int seam_add_periodic_interaction(seam_embedding *embedding, const char *side_a,
                                  const char *side_b, int model, double h, double offset,
                                  int transform, const double *params, size_t n_params,
                                  size_t *out_index);
/* Interactions of a Sierra-syntax contact deck; name labels messages (may be NULL).
 * Periodic conditions and plugin enforcements are taken; relative paths in the deck
 * (Lua files, plugin libraries) are taken from the working directory. */
int seam_add_deck(seam_embedding *embedding, const char *deck_text, const char *name,
                  size_t *out_count);
/* The same from a deck file (Sierra syntax or .toml); relative paths from its folder. */
int seam_add_deck_file(seam_embedding *embedding, const char *path, size_t *out_count);
int seam_interaction_count(const seam_embedding *embedding, size_t *out_count);
/* Pair every interaction anew. */
int seam_search(seam_embedding *embedding);
/* The host's time for the next seam_evaluate: conductance models and plugins that
 * depend on t see it (0 until set; must be finite). */
int seam_set_time(seam_embedding *embedding, double time);
/* New coordinates (xyz per node): pairings kept, gaps measured anew. */
int seam_move_nodes(seam_embedding *embedding, const double *coords, size_t n_nodes);

/* --- interface terms ---------------------------------------------------------------- */
/* Evaluate at the host's field u (n entries, by host dof). A plugin's failure is
 * SEAM_ERR_PLUGIN; its request for a smaller step is SEAM_CUTBACK (nothing evaluated). */
int seam_evaluate(seam_embedding *embedding, const double *u, size_t n);
/* After SEAM_CUTBACK: the plugin's suggested new/old step in (0, 1), or 0 (host decides). */
int seam_cutback_factor(const seam_embedding *embedding, double *out_factor);
/* Residual entries to add to R(u) = K u - F; dofs may repeat. The arrays of
 * seam_residual, seam_jacobian and seam_load stay valid until the next seam_evaluate,
 * seam_evaluate_csr, search, move or added interaction. */
int seam_residual(const seam_embedding *embedding, size_t *out_n, const int64_t **out_dofs,
                  const double **out_values);
/* Jacobian triplets to add to dR/du; (row, col) pairs may repeat. */
int seam_jacobian(const seam_embedding *embedding, size_t *out_n, const int64_t **out_rows,
                  const int64_t **out_cols, const double **out_values);
/* Right-hand side of linear models (offset terms): residual = J u - load. */
int seam_load(const seam_embedding *embedding, size_t *out_n, const int64_t **out_dofs,
              const double **out_values);
/* Heat (W) leaving side A and side B of a flux-type interaction, at the field of the
 * last seam_evaluate or seam_evaluate_csr (SEAM_ERR_ORDER before any); for another
 * state use seam_heat_at. */
int seam_heat(const seam_embedding *embedding, size_t index, double *out_side_a,
              double *out_side_b);

/* --- coverage and fields ------------------------------------------------------------ */
/* Why a side-A point found no partner (seam_unpaired_points). */
#define SEAM_UNPAIRED_NO_FACE 1            /* no side-B face within reach */
#define SEAM_UNPAIRED_TOO_FAR 2            /* farther along the normal than the tolerance */
#define SEAM_UNPAIRED_NORMALS_NOT_OPPOSED 3
#define SEAM_UNPAIRED_OUTSIDE_SUBDOMAIN 4

typedef struct {
    size_t points;        /* side-A points (nodes, for a node surface) */
    size_t paired_points;
    double area;          /* side A's area, m^2 */
    double paired_area;   /* the part of it paired with side B */
    size_t unpaired;      /* points not paired (seam_unpaired_points lists them) */
    int has_gap;          /* 1 when something paired: gap_min and gap_max hold */
    double gap_min, gap_max; /* m, positive open */
} seam_coverage_info;

typedef struct {
    double x[3];
    double weight;          /* the point's share of side A's area, m^2 */
    int paired;
    int64_t side_a_element; /* side-A face (element, 1-based side); -1 for a node point */
    int side_a_side;
    int64_t side_b_element; /* side-B face it paired with; -1 when not paired */
    int side_b_side;
    double gap;             /* m, positive open; 0 when not paired */
    double flux;            /* W/m^2 from side A to side B; 0 when not paired */
    double temp_a, temp_b;  /* side A's and side B's temperature there (NaN for ties) */
    int has_multiplier;     /* ties: 1 where the point has a multiplier */
    double multiplier;      /* ties: lambda_h there (= flux) */
} seam_point_values;

typedef struct {
    int64_t element;        /* the face: element and 1-based side */
    int side;
    int surface_side;       /* 0 side A, 1 side B */
    double area, paired_area, fraction; /* m^2, m^2, paired/area in [0, 1] */
    double gap, flux;       /* means over the paired area (0 with none) */
} seam_face_values;

/* What the last search of interaction `index` paired. */
int seam_coverage(const seam_embedding *embedding, size_t index,
                  seam_coverage_info *out_coverage);
/* Its unpaired points: point indices, xyz (3 per point) and SEAM_UNPAIRED_* reasons.
 * Arrays valid until the next seam_unpaired_points on this handle. */
int seam_unpaired_points(seam_embedding *embedding, size_t index, size_t *out_n,
                         const size_t **out_points, const double **out_xyz,
                         const int **out_reasons);
/* By default seam_search fails with SEAM_ERR_NOTHING_PAIRED when a flux interaction
 * pairs nothing (wrong surfaces or sides, surfaces apart). allow != 0 lets interaction
 * `index` (every one with SIZE_MAX) stand with zero terms; 0 refuses it again. */
int seam_allow_unpaired(seam_embedding *embedding, size_t index, int allow);

/* --- switching, point pressures, quarantine ----------------------------------------- */
/* Switch interaction `index` on (on != 0) or off (Use Toggle Block): while off a flux
 * interaction adds nothing and reports 0 W, and the CSR pattern is kept. A tie's rows
 * stay in seam_constraints: the host drops them while it is off. */
int seam_set_active(seam_embedding *embedding, size_t index, int on);
/* The contact pressure (Pa, >= 0) a conductance model sees at each of the n contact
 * points of interaction `index`, in point order (seam_point_fields); pressures NULL and
 * n = 0 go back to the enforcement's Contact Pressure. seam copies the array; a search
 * drops the values. */
int seam_set_point_pressures(seam_embedding *embedding, size_t index, const double *pressures,
                             size_t n);
/* Quarantine (on != 0) the points where interaction `index`'s conductance fails: they
 * contribute nothing and are listed by seam_quarantined (Quarantine Faulty Points). A
 * model's cutback request is still SEAM_CUTBACK. */
int seam_set_quarantine(seam_embedding *embedding, size_t index, int on);
/* The points of interaction `index` quarantined so far: xyz (3 per point) and the
 * reasons, one line per point ('\n'-separated, NUL-terminated). Both valid until the
 * next seam_quarantined on this handle. */
int seam_quarantined(seam_embedding *embedding, size_t index, size_t *out_n,
                     const double **out_xyz, const char **out_reasons);
/* Values at every side-A point of flux interaction `index` at the host's field u (n
 * entries, by host dof), in point order. Array valid until the next point-field call. */
int seam_point_fields(seam_embedding *embedding, size_t index, const double *u, size_t n,
                      size_t *out_n, const seam_point_values **out_values);
/* Per face of flux interaction `index` at u: side A's faces, then side B's if side_b.
 * Array valid until the next face-field call. */
int seam_face_fields(seam_embedding *embedding, size_t index, const double *u, size_t n,
                     int side_b, size_t *out_n, const seam_face_values **out_values);
/* Heat (W) leaving side A and side B of flux interaction `index` at the field u the
 * host passes (not the last evaluation's). */
int seam_heat_at(const seam_embedding *embedding, size_t index, const double *u, size_t n,
                 double *out_side_a, double *out_side_b);

/* --- CSR: a Jacobian of fixed pattern, refreshed in place ----------------------------- */
/* Evaluate at u (n entries, by host dof; n is the matrix size) into a CSR Jacobian
 * whose pattern is built at the first call after a search or move and only refreshed
 * after, and dense residual and load vectors; seam_heat then gives this evaluation's
 * heat. Arrays of the three getters below stay valid (same pointers) until the next
 * seam_evaluate_csr, search, move or added interaction; their contents change only at
 * the next seam_evaluate_csr. */
int seam_evaluate_csr(seam_embedding *embedding, const double *u, size_t n);
/* row_offsets: n_rows + 1 entries; columns (sorted within a row) and values: nnz.
 * pattern changes only when a search or move made a new pattern (out_pattern may be
 * NULL): while it stays, offsets and columns hold the same contents. */
int seam_jacobian_csr(const seam_embedding *embedding, size_t *out_n_rows, size_t *out_nnz,
                      const size_t **out_row_offsets, const size_t **out_columns,
                      const double **out_values, uint64_t *out_pattern);
int seam_residual_dense(const seam_embedding *embedding, size_t *out_n, const double **out_values);
int seam_load_dense(const seam_embedding *embedding, size_t *out_n, const double **out_values);

/* --- conductance callbacks ------------------------------------------------------------ */
typedef struct {
    double gap;       /* m, positive open */
    double pressure;  /* Pa (0: the host gives no pressure) */
    double temp_a;    /* K, side A at the point */
    double temp_b;    /* K, side B at its projection */
    double x[3];      /* the point */
    double time;      /* seam_set_time's */
} seam_point_state;
/* Return 0 and h >= 0 with its derivatives (finite), or non-zero: the evaluation then
 * fails with SEAM_ERR_ENFORCEMENT naming the point. */
typedef int (*seam_conductance_fn)(const seam_point_state *state, void *user_data,
                                   double *out_h, double *out_dh_dtemp_a,
                                   double *out_dh_dtemp_b);
/* As seam_add_interaction with model SEAM_CONDUCTANCE or SEAM_GAP_CONDUCTANCE, h from
 * callback(state, user_data, ...) at every point. depends_on_temperature = 0 promises
 * h does not change with T (the host may keep a linear solve). See "Ownership" above
 * for the callback's lifetime and threading. */
int seam_add_interaction_with_conductance(seam_embedding *embedding, const char *side_a,
                                          const char *side_b, int model,
                                          seam_conductance_fn callback, void *user_data,
                                          int depends_on_temperature, double offset,
                                          size_t *out_index);

/* --- mortar ties ------------------------------------------------------------------ */
/* Compute every tie's rows (after seam_search). Returns the condensed rows of the dual
 * ties, for hosts without multipliers:
 *   u[dofs[r]] = constants[r] + sum over k in offsets[r]..offsets[r+1]-1 of
 *                coefficients[k] * u[cols[k]]
 * offsets has n_rows + 1 entries. Standard ties add no rows here (see seam_tie_rows). */
int seam_constraints(seam_embedding *embedding, size_t *out_n_rows, const int64_t **out_dofs,
                     const double **out_constants, const size_t **out_offsets,
                     const int64_t **out_cols, const double **out_coefficients);
/* Number of ties (0-based tie indices follow interaction order). */
int seam_tie_count(const seam_embedding *embedding, size_t *out_count);
/* C u = g of one tie, for hosts that carry multipliers: the host dof of each
 * multiplier's side-A node, g (one per multiplier) and the entries
 * C[multipliers[k]][dofs[k]] = values[k]. */
int seam_tie_rows(const seam_embedding *embedding, size_t tie, size_t *out_n_multipliers,
                  const int64_t **out_multiplier_dofs, const double **out_rhs,
                  size_t *out_n_entries, const int64_t **out_multipliers,
                  const int64_t **out_dofs, const double **out_values);
/* Heat (W) through a tie for the host's multipliers lambda (n = number of multipliers). */
int seam_tie_heat(const seam_embedding *embedding, size_t tie, const double *lambda, size_t n,
                  double *out_side_a, double *out_side_b);
/* Heat through a dual tie the host condensed, from its own residual K u - F without
 * the tie (n entries, by host dof) at its solution. */
int seam_dual_tie_heat(const seam_embedding *embedding, size_t tie, const double *residual,
                       size_t n, double *out_side_a, double *out_side_b);
/* A condensed dual tie's multipliers from the host's residual K u - F without the tie
 * (n entries): written into out_lambda, which holds `capacity` >= n_multipliers values. */
int seam_dual_multipliers(seam_embedding *embedding, size_t tie, const double *residual,
                          size_t n, double *out_lambda, size_t capacity);
/* Values at every side-A point of tie `tie` for its multipliers lambda (n = its number
 * of multipliers; standard: the host's unknowns, dual: seam_dual_multipliers): flux and
 * multiplier are lambda_h = sum psi_k lambda_k. Array valid until the next point-field call. */
int seam_tie_point_fields(seam_embedding *embedding, size_t tie, const double *lambda, size_t n,
                          size_t *out_n, const seam_point_values **out_values);

/* --- on MPI: one embedding per rank (libseam built with --features mpi) ----------------
 * Declared when mpi.h (or petsc.h) is included before seam.h. A host on MPI gives each
 * rank's local part and gets, on each rank, the interface terms of that rank's own
 * side-A points in its global dof numbers; added over the ranks (MatSetValues /
 * VecSetValues with ADD_VALUES) they are the serial embedding's terms. See
 * docs/parallel.md ("The embedding on MPI") and examples/c_host/mpi_petsc.c.
 *
 *   seam_builder_new(local_coords, n_local, &b);      the rank's nodes, owned and ghost
 *   seam_builder_add_block(b, "a", SEAM_HEX8, conn, n_elems, k);  every block, on every rank
 *   seam_builder_add_side_set(b, "right", elems, sides, n);  the faces of the elements
 *                                                      this rank owns (each face on one rank)
 *   seam_builder_set_dofs(b, global_dof, n_local);     the host's global dof of each node
 *   seam_rank_new(b, PETSC_COMM_WORLD, global_ids, n_local, &e); seam_builder_free(b);
 *   seam_rank_add_interaction(e, "right", "left", SEAM_GAP_CONDUCTANCE, h, 0.0, NULL);
 *   seam_rank_search(e);
 *   seam_rank_evaluate(e, u_local, n_local);          the field at the local nodes
 *   seam_rank_jacobian(e, &n, &rows, &cols, &vals);    MatSetValues(..., ADD_VALUES)
 *   seam_rank_heat(e, 0, &q_a, &q_b);                 summed over the ranks
 *   seam_rank_free(e);                                before MPI_Finalize / PetscFinalize
 *
 * Collective: seam_rank_new, _add_interaction, _add_deck, _search, _move_nodes, _evaluate,
 * _constraints, _tie_heat, _dual_tie_heat, the point- and face-field calls and _free must be
 * called by every rank of the communicator, in the same order, with the same interactions;
 * the getters are local. An error on one rank is an error on every rank:
 * that rank's own status and message there, SEAM_ERR_OTHER_RANK naming it elsewhere, so
 * no rank is left waiting in a collective.
 *
 * What each rank holds: the whole interface (every rank's interface faces with their
 * elements' nodes, coordinates and global dofs), gathered at seam_rank_new; not the rest
 * of the volume mesh. Every rank searches it whole (the serial search) and evaluates only
 * the points of its own faces. Mortar ties with multipliers are refused (SEAM_ERR_ARGUMENT).
 */
#if defined(MPI_VERSION)
typedef struct SeamRankEmbedding seam_rank_embedding;

/* This rank's embedding. builder: the rank's local part, as for seam_embedding_new, with
 * seam_builder_set_dofs giving the host's global dof of each local node; every rank
 * gives the same blocks and surfaces (names, topologies, conductivities; empty where it
 * has none) in the same order, and each interface face on one rank only (the owner of
 * its element). global_ids: the global id of each of the n_nodes local nodes (>= 0; a
 * node held by several ranks has one id and one dof). comm is duplicated (MPI_Comm_dup):
 * the caller keeps its own. The builder is unchanged and still owned by the caller.
 * On failure *out_embedding is NULL. MPI not running or comm MPI_COMM_NULL is
 * SEAM_ERR_ARGUMENT on that rank alone (there is no communicator to tell the others). */
int seam_rank_new(const seam_builder *builder, MPI_Comm comm, const int64_t *global_ids,
                  size_t n_nodes, seam_rank_embedding **out_embedding);
/* Free the handle and its communicator (collective: MPI_Comm_free); before MPI_Finalize.
 * Accepts NULL. */
void seam_rank_free(seam_rank_embedding *embedding);
/* As seam_add_interaction; a mortar tie (SEAM_TIED_MORTAR, SEAM_TIED_DUAL_MORTAR) gives
 * its rows by seam_rank_constraints. */
int seam_rank_add_interaction(seam_rank_embedding *embedding, const char *side_a,
                              const char *side_b, int model, double h, double offset,
                              size_t *out_index);
/* As seam_add_deck: the same deck on every rank (name may be NULL). */
int seam_rank_add_deck(seam_rank_embedding *embedding, const char *deck_text, const char *name,
                       size_t *out_count);
/* As seam_add_deck_file: every rank reads the same file (relative paths in it from its
 * folder), which must be readable from every rank. */
int seam_rank_add_deck_file(seam_rank_embedding *embedding, const char *path,
                            size_t *out_count);
/* Pair every interaction anew: the serial search of the whole interface, on every rank;
 * each rank keeps the points of its own side-A faces. */
int seam_rank_search(seam_rank_embedding *embedding);
/* New coordinates of this rank's local nodes (xyz per node, n_nodes as the builder's):
 * pairings kept, gaps measured anew, as seam_move_nodes; the last evaluation and the tie
 * rows are dropped. Collective. */
int seam_rank_move_nodes(seam_rank_embedding *embedding, const double *coords, size_t n_nodes);
/* Between evaluations, as seam_set_time, seam_set_active, seam_set_quarantine and
 * seam_allow_unpaired. Collective: every rank calls them in the same order with the same
 * arguments (each rank makes its own points' terms with them); arguments that differ
 * between ranks are SEAM_ERR_ARGUMENT on every rank. All but seam_rank_allow_unpaired
 * drop the last evaluation. */
int seam_rank_set_time(seam_rank_embedding *embedding, double time);
int seam_rank_set_active(seam_rank_embedding *embedding, size_t index, int on);
int seam_rank_set_quarantine(seam_rank_embedding *embedding, size_t index, int on);
/* As seam_set_point_pressures, for this rank's own n contact points of interaction
 * `index`, in the order seam_rank_point_fields lists them on this rank (pressures NULL
 * and n = 0 on every rank go back to the enforcement's Contact Pressure). */
int seam_rank_set_point_pressures(seam_rank_embedding *embedding, size_t index,
                                  const double *pressures, size_t n);
int seam_rank_allow_unpaired(seam_rank_embedding *embedding, size_t index, int allow);
/* The points of interaction `index` this rank quarantined (its own side-A points), as
 * seam_quarantined: xyz (3 per point) and the reasons, one line per point, valid until
 * the next seam_rank_quarantined on this handle; out_total (NULL on every rank, or on
 * none) the count over every rank. Collective. */
int seam_rank_quarantined(seam_rank_embedding *embedding, size_t index, size_t *out_n,
                          const double **out_xyz, const char **out_reasons, size_t *out_total);
/* Over all ranks, the side-A points of the last search paired with a side-B face that
 * another rank gave (the pairs that straddle ranks). Local. */
int seam_rank_points_across(const seam_rank_embedding *embedding, size_t *out_count);
/* What the last search of interaction `index` paired, over every rank (seam_coverage's
 * values; the same on every rank, which holds the whole pairing). Local. */
int seam_rank_coverage(const seam_rank_embedding *embedding, size_t index,
                       seam_coverage_info *out_coverage);
/* Evaluate this rank's own points at the field u_local: one value per local node (owned
 * and ghost, in the builder's node order), current at least at the nodes of the
 * elements of this rank's interface faces. seam gathers what the other ranks' points
 * need. */
int seam_rank_evaluate(seam_rank_embedding *embedding, const double *u_local, size_t n_nodes);
/* CSR, as seam_evaluate_csr: evaluate this rank's own points at u_local into the rows
 * they touch, in the host's global dofs, built at the first call after a search or move
 * and refreshed in place after (collective); seam_rank_heat then gives its heats. */
int seam_rank_evaluate_csr(seam_rank_embedding *embedding, const double *u_local,
                           size_t n_nodes);
/* n_rows rows (their global dofs, ascending, in rows), n_rows + 1 offsets, nnz global
 * columns (ascending within a row) and values, to add with MatSetValues(..., ADD_VALUES)
 * row by row. pattern (may be NULL) changes only when a search or move made a new
 * pattern: while it stays, rows, offsets and columns hold the same contents. Valid until
 * the next evaluation, search or move. Local. */
int seam_rank_jacobian_csr(const seam_rank_embedding *embedding, size_t *out_n_rows,
                           size_t *out_nnz, const size_t **out_rows,
                           const size_t **out_row_offsets, const size_t **out_columns,
                           const double **out_values, uint64_t *out_pattern);
/* This rank's share of the residual (load = 0) or of the load of linear models (load != 0)
 * at each of the CSR's rows. Local. */
int seam_rank_vector_csr(const seam_rank_embedding *embedding, int load, size_t *out_n_rows,
                         const double **out_values);
/* The last evaluation's terms of this rank's points, in the host's global dof numbers
 * (rows and dofs may belong to other ranks: add them with ADD_VALUES); as
 * seam_residual, seam_jacobian and seam_load. The arrays belong to the handle and stay
 * valid until the next seam_rank_evaluate, _search, _move_nodes, _add_interaction,
 * _add_deck, _add_deck_file or _free. */
int seam_rank_residual(const seam_rank_embedding *embedding, size_t *out_n,
                       const int64_t **out_dofs, const double **out_values);
int seam_rank_jacobian(const seam_rank_embedding *embedding, size_t *out_n,
                       const int64_t **out_rows, const int64_t **out_cols,
                       const double **out_values);
int seam_rank_load(const seam_rank_embedding *embedding, size_t *out_n,
                   const int64_t **out_dofs, const double **out_values);
/* Mortar ties on ranks (after seam_rank_search): each rank gets the rows of the
 * multipliers whose side-A node it owns (the lowest rank among the interface elements
 * around it), in global dofs, so every multiplier's row comes from one rank. Computes
 * them (collective) and returns this rank's condensed rows of the dual ties, as
 * seam_constraints. The arrays of these calls belong to the handle and stay valid
 * until the next seam_rank_constraints, _search, _move_nodes, _add_interaction, _add_deck,
 * _add_deck_file or _free. */
int seam_rank_constraints(seam_rank_embedding *embedding, size_t *out_n_rows,
                          const int64_t **out_dofs, const double **out_constants,
                          const size_t **out_offsets, const int64_t **out_cols,
                          const double **out_coefficients);
/* Number of ties (0 before seam_rank_constraints). Local. */
int seam_rank_tie_count(const seam_rank_embedding *embedding, size_t *out_count);
/* This rank's C u = g of one tie, as seam_tie_rows: its multipliers numbered 0.. in this
 * rank's order. Local. */
int seam_rank_tie_rows(const seam_rank_embedding *embedding, size_t tie,
                       size_t *out_n_multipliers, const int64_t **out_multiplier_dofs,
                       const double **out_rhs, size_t *out_n_entries,
                       const int64_t **out_multipliers, const int64_t **out_dofs,
                       const double **out_values);
/* Each of this rank's multipliers' place in the whole tie (the same numbering on every
 * rank: number the host's multiplier unknowns by it) and the tie's count of them. Local. */
int seam_rank_tie_index(const seam_rank_embedding *embedding, size_t tie,
                        const int64_t **out_index, size_t *out_total);
/* A condensed dual tie's multipliers on this rank from the host's residual K u - F
 * without the tie at each of this rank's multipliers' dofs (n values, in this rank's
 * order): written into out_lambda, which holds `capacity` >= n values. Local. */
int seam_rank_dual_multipliers(const seam_rank_embedding *embedding, size_t tie,
                               const double *residual_at, size_t n, double *out_lambda,
                               size_t capacity);
/* Heat (W) through a tie for this rank's multipliers lambda (n, in this rank's order),
 * summed over the ranks. Collective. */
int seam_rank_tie_heat(const seam_rank_embedding *embedding, size_t tie, const double *lambda,
                       size_t n, double *out_side_a, double *out_side_b);
/* Heat (W) through a condensed dual tie from the host's residual K u - F without the
 * tie at each of this rank's multipliers' dofs (n values, in this rank's order), summed
 * over the ranks: the rank form of seam_dual_tie_heat. Collective. */
int seam_rank_dual_tie_heat(const seam_rank_embedding *embedding, size_t tie,
                            const double *residual_at, size_t n, double *out_side_a,
                            double *out_side_b);
/* Heat (W) leaving side A and side B of interaction `index` at the last evaluation,
 * summed over the ranks (the same on every rank). */
int seam_rank_heat(const seam_rank_embedding *embedding, size_t index, double *out_side_a,
                   double *out_side_b);
/* Values at this rank's own side-A points of flux interaction `index` at the local field
 * (n_nodes values, as for seam_rank_evaluate); for each, out_points its index in the
 * interaction's point order (seam_point_fields' order; the ranks' points together are
 * that list, each point once) and out_side_b_ranks the rank whose element
 * side_b_element is (-1 where unpaired). Faces are named by the element index of the
 * rank that gave them: side A's is this rank's own. Arrays valid until the next call.
 * Collective. */
int seam_rank_point_fields(seam_rank_embedding *embedding, size_t index, const double *u_local,
                           size_t n_nodes, size_t *out_n, const seam_point_values **out_values,
                           const size_t **out_points, const int **out_side_b_ranks);
/* Values at this rank's own side-A points of tie `tie` (after seam_rank_constraints) for
 * this rank's multipliers lambda (n, in this rank's order; for a condensed dual tie those
 * of seam_rank_dual_multipliers), as seam_rank_point_fields gives them: multiplier is the
 * multiplier field at the point, summed from every rank's multipliers. Arrays valid
 * until the next point-field call. Collective. */
int seam_rank_tie_point_fields(seam_rank_embedding *embedding, size_t tie, const double *lambda,
                               size_t n, size_t *out_n, const seam_point_values **out_values,
                               const size_t **out_points, const int **out_side_b_ranks);
/* Per face of flux interaction `index` at the local field (n_nodes values): the faces this
 * rank gave (side A's, then side B's if side_b), named by its own elements, with
 * seam_face_fields' values (each point's flux from the rank that owns it). The ranks'
 * faces together are the serial list. Array valid until the next face-field call.
 * Collective. */
int seam_rank_face_fields(seam_rank_embedding *embedding, size_t index, const double *u_local,
                          size_t n_nodes, int side_b, size_t *out_n,
                          const seam_face_values **out_values);
/* Per face of tie `tie` for this rank's multipliers lambda (n, as for
 * seam_rank_tie_point_fields): this rank's faces, flux the mean multiplier field.
 * Collective. */
int seam_rank_tie_face_fields(seam_rank_embedding *embedding, size_t tie, const double *lambda,
                              size_t n, int side_b, size_t *out_n,
                              const seam_face_values **out_values);
#endif /* MPI_VERSION */

#ifdef __cplusplus
}
#endif

#endif /* SEAM_H */
