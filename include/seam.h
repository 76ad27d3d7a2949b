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
 * numbered block after block; local sides are 1-based in Exodus II order. Every
 * function returns a status (SEAM_OK = 0); on failure seam_last_error() says what went
 * wrong, where, and how to fix it (per thread). No function aborts or unwinds into the
 * caller. Arrays returned through `const T **` belong to the handle and stay valid
 * until the next call that recomputes them or the handle is freed. A handle must be
 * used by one thread at a time.
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
#define SEAM_CUTBACK 9           /* a plugin asks for a smaller step (seam_cutback_factor) */

/* Element topologies (3-D solids). */
#define SEAM_HEX8 1
#define SEAM_TET4 2
#define SEAM_WEDGE6 3
#define SEAM_PYRAMID5 4

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
/* A surface of faces by their corner nodes (3 or 4 per face, any order). */
int seam_builder_add_face_set(seam_builder *builder, const char *name,
                              const int64_t *face_nodes, size_t nodes_per_face, size_t n_faces);
/* The host's dof of every node; negative: none (only for nodes of no block). */
int seam_builder_set_dofs(seam_builder *builder, const int64_t *dofs, size_t n_nodes);
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
/* Residual entries to add to R(u) = K u - F; dofs may repeat. */
int seam_residual(const seam_embedding *embedding, size_t *out_n, const int64_t **out_dofs,
                  const double **out_values);
/* Jacobian triplets to add to dR/du; (row, col) pairs may repeat. */
int seam_jacobian(const seam_embedding *embedding, size_t *out_n, const int64_t **out_rows,
                  const int64_t **out_cols, const double **out_values);
/* Right-hand side of linear models (offset terms): residual = J u - load. */
int seam_load(const seam_embedding *embedding, size_t *out_n, const int64_t **out_dofs,
              const double **out_values);
/* Heat (W) leaving side A and side B of a flux-type interaction. */
int seam_heat(const seam_embedding *embedding, size_t index, double *out_side_a,
              double *out_side_b);

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

#ifdef __cplusplus
}
#endif

#endif /* SEAM_H */
