//! The C API of [`crate::embed::RankEmbedding`] (`--features mpi`): one handle per rank
//! of a host on MPI, made from a builder holding the rank's local part and the host's
//! communicator. Every function but `seam_rank_free` and the getters is collective.

use super::*;
use crate::embed::RankEmbedding;

/// The per-rank embedding handle.
pub struct SeamRankEmbedding {
    inner: RankEmbedding,
    evaluated: Option<Evaluated>,
}

/// Make this rank's embedding from `builder` (its local part; its dofs the host's global
/// dofs) and `global_ids` (one per local node), over a duplicate of `comm`. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_new(
    builder: *const SeamBuilder,
    comm: mpi::ffi::MPI_Comm,
    global_ids: *const i64,
    n_nodes: usize,
    out_embedding: *mut *mut SeamRankEmbedding,
) -> c_int {
    guard(|| {
        if out_embedding.is_null() {
            return Err(null("out_embedding"));
        }
        // SAFETY: null or valid for the call (module Safety).
        unsafe { out_embedding.write(std::ptr::null_mut()) };
        // SAFETY: a non-null handle came from this library (module Safety).
        let b = unsafe { builder.as_ref() }.ok_or_else(|| null("builder"))?;
        let b = b.0.clone().ok_or_else(|| null("builder"))?;
        let ids = unsafe { slice(global_ids, n_nodes, "global_ids") }?;
        let ids = ids
            .iter()
            .map(|&g| {
                u64::try_from(g).map_err(|_| {
                    bad(
                        format!("global id {g} is negative"),
                        "global ids are 0-based",
                    )
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        // SAFETY: the host passes MPI_COMM_NULL or a communicator of its MPI (seam.h).
        let comm = unsafe { crate::embed::duplicate(comm) }?;
        let inner = b.build_on_ranks(comm, &ids)?;
        let e = Box::new(SeamRankEmbedding {
            inner,
            evaluated: None,
        });
        unsafe { out(out_embedding, Box::into_raw(e), "out_embedding") }
    })
}

/// Free the handle and its duplicate communicator (before MPI_Finalize). Collective
/// (`MPI_Comm_free`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_free(embedding: *mut SeamRankEmbedding) {
    if !embedding.is_null() {
        // SAFETY: made by Box::into_raw in seam_rank_new and freed once (module Safety).
        let _ = catch_unwind(AssertUnwindSafe(|| {
            drop(unsafe { Box::from_raw(embedding) })
        }));
    }
}

/// As `seam_add_interaction`, on every rank alike. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_add_interaction(
    embedding: *mut SeamRankEmbedding,
    side_a: *const c_char,
    side_b: *const c_char,
    model: c_int,
    h: f64,
    offset: f64,
    out_index: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let (a, b) = unsafe { (text(side_a, "side_a")?, text(side_b, "side_b")?) };
        let model = interactions::model_of(model, h)?;
        if matches!(model, Model::TiedMortar { .. }) {
            return Err(RankEmbedding::no_multipliers(a, b).into());
        }
        let i = e
            .inner
            .add_interaction(Interaction::new(a, b, model).offset(offset))?;
        e.evaluated = None;
        unsafe { interactions::optional_out(out_index, i) }
    })
}

/// As `seam_add_deck`, the same deck on every rank; a deck with a mortar tie is
/// refused whole. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_add_deck(
    embedding: *mut SeamRankEmbedding,
    deck_text: *const c_char,
    name: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let (deck, name) = unsafe { interactions::deck_args(deck_text, name) }?;
        let first = e.inner.len();
        let added = e.inner.add_deck(name, deck)?;
        e.inner.refuse_ties_from(first)?;
        e.evaluated = None;
        unsafe { interactions::optional_out(out_count, added.len()) }
    })
}

/// Pair every interaction anew. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_search(embedding: *mut SeamRankEmbedding) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.evaluated = None;
        Ok(e.inner.search()?)
    })
}

/// Over all ranks, the side-A points of the last search whose side-B face another rank
/// gave.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_points_across(
    embedding: *const SeamRankEmbedding,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { out(out_count, e.inner.points_across(), "out_count") }
    })
}

/// Evaluate this rank's own side-A points at the local field (`n_nodes` values, one per
/// local node). Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_evaluate(
    embedding: *mut SeamRankEmbedding,
    u_local: *const f64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let u = unsafe { slice(u_local, n_nodes, "u_local") }?;
        e.evaluated = None;
        e.evaluated = Some(Evaluated::from(e.inner.contributions(u)?));
        Ok(())
    })
}

unsafe fn rank_evaluated<'a>(e: *const SeamRankEmbedding) -> Result<&'a Evaluated, Failure> {
    // SAFETY: a non-null handle came from this library (module Safety).
    let e = unsafe { e.as_ref() }.ok_or_else(|| null("embedding"))?;
    e.evaluated.as_ref().ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "nothing evaluated\n  help: call seam_rank_evaluate first (after seam_rank_search)"
                .into(),
        )
    })
}

/// This rank's residual entries, by global dof.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_residual(
    embedding: *const SeamRankEmbedding,
    out_n: *mut usize,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| unsafe { rank_evaluated(embedding)?.write_residual(out_n, out_dofs, out_values) })
}

/// This rank's Jacobian triplets, by global dof.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_jacobian(
    embedding: *const SeamRankEmbedding,
    out_n: *mut usize,
    out_rows: *mut *const i64,
    out_cols: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| unsafe {
        rank_evaluated(embedding)?.write_jacobian(out_n, out_rows, out_cols, out_values)
    })
}

/// This rank's load entries (offset terms), by global dof.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_load(
    embedding: *const SeamRankEmbedding,
    out_n: *mut usize,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| unsafe { rank_evaluated(embedding)?.write_load(out_n, out_dofs, out_values) })
}

/// The heat of interaction `index`, summed over the ranks.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_heat(
    embedding: *const SeamRankEmbedding,
    index: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let v = unsafe { rank_evaluated(embedding) }?;
        let (a, b) = v.heat.get(index).copied().flatten().ok_or_else(|| {
            bad(
                format!(
                    "no flux interaction {index} ({} interactions)",
                    v.heat.len()
                ),
                "interaction indices are 0-based, in the order they were added",
            )
        })?;
        unsafe { terms::write_heat((a, b), out_side_a, out_side_b) }
    })
}
