//! The C API of [`crate::embed::RankEmbedding`] (`--features mpi`): one handle per rank
//! of a host on MPI, made from a builder holding the rank's local part and the host's
//! communicator. Every function but `seam_rank_free` and the getters is collective.

use super::*;
use crate::embed::RankEmbedding;

/// The per-rank embedding handle.
pub struct SeamRankEmbedding {
    inner: RankEmbedding,
    evaluated: Option<Evaluated>,
    /// This rank's rows of the mortar ties (`seam_rank_constraints`), with each tie's
    /// multipliers' indices in the whole tie and its count of them.
    rows: Option<(Rows, Vec<Places>)>,
    /// The last `seam_rank_point_fields` or `seam_rank_tie_point_fields`.
    points: OwnPoints,
    /// The last `seam_rank_face_fields` or `seam_rank_tie_face_fields`.
    faces: Vec<fields::SeamFaceValues>,
    /// The last `seam_rank_quarantined`: xyz and the reasons.
    quarantined: (Vec<f64>, CString),
    /// The last evaluation was `seam_rank_evaluate_csr` (its terms are in `inner`).
    csr_current: bool,
}

impl SeamRankEmbedding {
    /// What the terms depend on changed (time, switches, pressures, quarantine): the
    /// last evaluation's values no longer hold.
    fn values_changed(&mut self) {
        (self.evaluated, self.csr_current) = (None, false);
    }

    /// The interactions or the geometry changed (a search, a move): the last
    /// evaluation and tie rows no longer hold.
    fn forget_results(&mut self) {
        self.values_changed();
        self.rows = None;
    }
}

/// This rank's own points of the last `seam_rank_point_fields`: their values, their
/// indices in the interaction's point order, and their side-B faces' ranks.
#[derive(Default)]
struct OwnPoints {
    values: Vec<fields::SeamPointValues>,
    index: Vec<usize>,
    side_b_rank: Vec<c_int>,
}

impl OwnPoints {
    /// Keep `points` as C arrays and hand them out.
    unsafe fn write(
        &mut self,
        points: &[crate::embed::RankPoint],
        out_n: *mut usize,
        out_values: *mut *const fields::SeamPointValues,
        out_points: *mut *const usize,
        out_side_b_ranks: *mut *const c_int,
    ) -> Result<(), Failure> {
        *self = OwnPoints {
            values: points.iter().map(|p| (&p.values).into()).collect(),
            index: points.iter().map(|p| p.point).collect(),
            side_b_rank: (points.iter())
                .map(|p| p.side_b_rank.map_or(-1, |r| r as c_int))
                .collect(),
        };
        unsafe {
            out(out_points, self.index.as_ptr(), "out_points")?;
            out(
                out_side_b_ranks,
                self.side_b_rank.as_ptr(),
                "out_side_b_ranks",
            )?;
            fields::array_out(&self.values, out_n, out_values)
        }
    }
}

/// A tie's multipliers on this rank: their places in the whole tie, and its count.
type Places = (Vec<i64>, usize);

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
        // The communicator first (collective): every argument is then checked on every
        // rank before the build, so a bad one on one rank fails them all.
        // SAFETY: the host passes MPI_COMM_NULL or a communicator of its MPI (seam.h).
        let comm = unsafe { crate::embed::duplicate(comm) }?;
        let args = (|| {
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
            Ok((b, ids))
        })();
        let (b, ids) = on_every_rank(&comm, args)?;
        let inner = b.build_on_ranks(comm, &ids)?;
        let e = Box::new(SeamRankEmbedding {
            inner,
            evaluated: None,
            rows: None,
            points: Default::default(),
            faces: Vec::new(),
            quarantined: Default::default(),
            csr_current: false,
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
        let args = (|| {
            let (a, b) = unsafe { (text(side_a, "side_a")?, text(side_b, "side_b")?) };
            Ok::<_, Failure>((a, b, interactions::model_of(model, h)?))
        })();
        let (a, b, model) = on_every_rank(e.inner.comm(), args)?;
        let i = e
            .inner
            .add_interaction(Interaction::new(a, b, model).offset(offset))?;
        e.forget_results();
        unsafe { interactions::optional_out(out_index, i) }
    })
}

/// As `seam_add_deck`, the same deck on every rank. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_add_deck(
    embedding: *mut SeamRankEmbedding,
    deck_text: *const c_char,
    name: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let args = unsafe { interactions::deck_args(deck_text, name) };
        let (deck, name) = on_every_rank(e.inner.comm(), args)?;
        let added = e.inner.add_deck(name, deck)?;
        e.forget_results();
        unsafe { interactions::optional_out(out_count, added.len()) }
    })
}

/// As `seam_add_deck_file`: every rank reads the same file (relative paths in it from
/// its folder). Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_add_deck_file(
    embedding: *mut SeamRankEmbedding,
    path: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let path = on_every_rank(e.inner.comm(), unsafe { text(path, "path") })?;
        let added = e.inner.add_deck_file(std::path::Path::new(path))?;
        e.forget_results();
        unsafe { interactions::optional_out(out_count, added.len()) }
    })
}

/// Pair every interaction anew. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_search(embedding: *mut SeamRankEmbedding) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.forget_results();
        Ok(e.inner.search()?)
    })
}

/// New coordinates of this rank's local nodes (xyz per node, `n_nodes` of them, as the
/// builder's nodes): pairings kept, points placed again on the moved faces and gaps
/// measured anew, as `seam_move_nodes`. The last evaluation and tie rows are dropped.
/// Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_move_nodes(
    embedding: *mut SeamRankEmbedding,
    coords: *const f64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let points = on_every_rank(e.inner.comm(), unsafe {
            interactions::xyz(coords, n_nodes)
        })?;
        e.forget_results();
        Ok(e.inner.move_nodes(&points)?)
    })
}

/// What the last search of interaction `index` paired, over every rank (the same on
/// every rank: each holds the whole pairing). Local.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_coverage(
    embedding: *const SeamRankEmbedding,
    index: usize,
    out_coverage: *mut fields::SeamCoverage,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let c = e.inner.coverage(index)?;
        unsafe { out(out_coverage, fields::SeamCoverage::from(&c), "out_coverage") }
    })
}

/// The host's time for the next `seam_rank_evaluate` (conductance models and plugins
/// that depend on t see it). Collective: the same time on every rank, else
/// SEAM_ERR_ARGUMENT on every rank. The last evaluation is dropped.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_set_time(embedding: *mut SeamRankEmbedding, time: f64) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.values_changed();
        Ok(e.inner.set_time(time)?)
    })
}

/// Switch interaction `index` on (`on` non-zero) or off: while off a flux interaction
/// adds nothing on any rank and reports 0 W. Collective, with the same arguments on
/// every rank. The last evaluation is dropped.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_set_active(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    on: c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.values_changed();
        Ok(e.inner.set_active(index, on != 0)?)
    })
}

/// The contact pressure (Pa, >= 0) at each of this rank's own `n` contact points of
/// interaction `index`, in the order `seam_rank_point_fields` lists them on this rank;
/// `pressures` null and `n` 0 (on every rank) go back to the enforcement's pressure. A
/// search drops them. Collective. The last evaluation is dropped.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_set_point_pressures(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    pressures: *const f64,
    n: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let given = on_every_rank(e.inner.comm(), unsafe {
            state::pressures_arg(pressures, n)
        })?;
        e.values_changed();
        Ok(e.inner.set_point_pressures(index, given)?)
    })
}

/// Quarantine the points where interaction `index`'s conductance fails (`on`
/// non-zero): they contribute nothing and each rank lists its own by
/// `seam_rank_quarantined`. Collective, with the same arguments on every rank.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_set_quarantine(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    on: c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.values_changed();
        Ok(e.inner.set_quarantine(index, on != 0)?)
    })
}

/// Let interaction `index` (every interaction with SIZE_MAX) pair nothing without
/// SEAM_ERR_NOTHING_PAIRED (`allow` non-zero), or refuse it again (0). Collective, with
/// the same arguments on every rank.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_allow_unpaired(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    allow: c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let which = (index != usize::MAX).then_some(index);
        Ok(e.inner.allow_unpaired(which, allow != 0)?)
    })
}

/// The points of interaction `index` this rank quarantined so far (its own side-A
/// points): `out_n` points, their xyz (3 per point) and the reasons, one line per point;
/// valid until the next `seam_rank_quarantined` on this handle. `out_total` (may be
/// null only if every rank passes null) the count over every rank. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_quarantined(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    out_n: *mut usize,
    out_xyz: *mut *const f64,
    out_reasons: *mut *const c_char,
    out_total: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let total = e.inner.quarantined_count(index);
        e.quarantined = state::quarantined_arrays(&e.inner.quarantined(index));
        if !out_total.is_null() {
            unsafe { out(out_total, total, "out_total") }?;
        }
        let (xyz, reasons) = &e.quarantined;
        unsafe { state::quarantined_out((xyz, reasons), out_n, out_xyz, out_reasons) }
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
        let u = on_every_rank(e.inner.comm(), unsafe {
            slice(u_local, n_nodes, "u_local")
        })?;
        e.values_changed();
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
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let heat: Vec<Option<(f64, f64)>> = match rank_csr(e) {
            Ok(c) => (c.heat.iter())
                .map(|h| h.map(|h| (h.side_a, h.side_b)))
                .collect(),
            Err(_) => unsafe { rank_evaluated(embedding) }?.heat.clone(),
        };
        let (a, b) = heat.get(index).copied().flatten().ok_or_else(|| {
            bad(
                format!("no flux interaction {index} ({} interactions)", heat.len()),
                "interaction indices are 0-based, in the order they were added",
            )
        })?;
        unsafe { terms::write_heat((a, b), out_side_a, out_side_b) }
    })
}

/// Evaluate this rank's own side-A points at the local field (`n_nodes` values, one per
/// local node) into CSR: the rows its points touch, in the host's global dofs, built at
/// the first call after a search or move and refreshed in place after. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_evaluate_csr(
    embedding: *mut SeamRankEmbedding,
    u_local: *const f64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let u = on_every_rank(e.inner.comm(), unsafe {
            slice(u_local, n_nodes, "u_local")
        })?;
        e.values_changed();
        e.inner.evaluate(u)?;
        e.csr_current = true;
        Ok(())
    })
}

fn rank_csr(e: &SeamRankEmbedding) -> Result<&crate::embed::RankEvaluation, Failure> {
    (e.inner.evaluation()).filter(|_| e.csr_current).ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "nothing evaluated into CSR\n  help: call seam_rank_evaluate_csr first (after seam_rank_search)".into(),
        )
    })
}

/// This rank's CSR of the last `seam_rank_evaluate_csr`: `n_rows` rows (their global
/// dofs ascending in `rows`), `n_rows + 1` offsets, `nnz` global columns (ascending
/// within a row) and values. `pattern` (may be null) changes only when a search or a
/// move made a new pattern; while it stays, rows, offsets and columns hold the same
/// contents. Arrays valid until the next evaluation, search or move. Local.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_rank_jacobian_csr(
    embedding: *const SeamRankEmbedding,
    out_n_rows: *mut usize,
    out_nnz: *mut usize,
    out_rows: *mut *const usize,
    out_row_offsets: *mut *const usize,
    out_columns: *mut *const usize,
    out_values: *mut *const f64,
    out_pattern: *mut u64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let c = rank_csr(e)?;
        unsafe {
            out(out_n_rows, c.rows.len(), "out_n_rows")?;
            out(out_nnz, c.columns.len(), "out_nnz")?;
            out(out_rows, c.rows.as_ptr(), "out_rows")?;
            out(out_row_offsets, c.row_offsets.as_ptr(), "out_row_offsets")?;
            out(out_columns, c.columns.as_ptr(), "out_columns")?;
            out(out_values, c.values.as_ptr(), "out_values")?;
            if !out_pattern.is_null() {
                out(out_pattern, c.pattern, "out_pattern")?;
            }
            Ok(())
        }
    })
}

/// This rank's share of the residual (`load` zero) or of the load of linear models
/// (`load` non-zero) at each of the CSR's `n_rows` rows, as `seam_rank_jacobian_csr`
/// gives them. Local.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_vector_csr(
    embedding: *const SeamRankEmbedding,
    load: c_int,
    out_n_rows: *mut usize,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let c = rank_csr(e)?;
        let v = if load != 0 { &c.load } else { &c.residual };
        unsafe {
            out(out_n_rows, v.len(), "out_n_rows")?;
            out(out_values, v.as_ptr(), "out_values")
        }
    })
}

/// This rank's rows of every mortar tie (after `seam_rank_search`; collective): the
/// multipliers whose side-A node it owns, in the host's global dofs. Returns the dual
/// ties' condensed rows as `seam_constraints` does; `seam_rank_tie_rows` gives each
/// tie's `C u = g` and `seam_rank_tie_index` its multipliers' places in the whole tie.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_rank_constraints(
    embedding: *mut SeamRankEmbedding,
    out_n_rows: *mut usize,
    out_dofs: *mut *const i64,
    out_constants: *mut *const f64,
    out_offsets: *mut *const usize,
    out_cols: *mut *const i64,
    out_coefficients: *mut *const f64,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.rows = None;
        let ties = e.inner.constraints()?;
        let index = (ties.iter())
            .map(|t| (t.index.iter().map(|&k| as_i64(k)).collect(), t.total))
            .collect();
        let rows = Rows::of(ties.into_iter().map(|t| t.rows).collect());
        let (r, _) = e.rows.insert((rows, index));
        unsafe {
            r.write_condensed(
                out_n_rows,
                out_dofs,
                out_constants,
                out_offsets,
                out_cols,
                out_coefficients,
            )
        }
    })
}

/// The rows of `seam_rank_constraints`, or why not.
unsafe fn rank_rows<'a>(e: *const SeamRankEmbedding) -> Result<&'a (Rows, Vec<Places>), Failure> {
    // SAFETY: a non-null handle came from this library (module Safety).
    let e = unsafe { e.as_ref() }.ok_or_else(|| null("embedding"))?;
    e.rows.as_ref().ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "no constraints yet\n  help: call seam_rank_constraints first (after seam_rank_search)"
                .into(),
        )
    })
}

/// Number of mortar ties (after `seam_rank_constraints`; 0 before).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_tie_count(
    embedding: *const SeamRankEmbedding,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let n = e.rows.as_ref().map_or(0, |(r, _)| r.ties.len());
        unsafe { out(out_count, n, "out_count") }
    })
}

/// This rank's rows `C u = g` of tie `index`, as `seam_tie_rows`: its multipliers
/// numbered 0.. in this rank's order, dofs global.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_rank_tie_rows(
    embedding: *const SeamRankEmbedding,
    index: usize,
    out_n_multipliers: *mut usize,
    out_multiplier_dofs: *mut *const i64,
    out_rhs: *mut *const f64,
    out_n_entries: *mut usize,
    out_multipliers: *mut *const i64,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| unsafe {
        ties::write_tie_rows(
            rank_rows(embedding)?.0.tie(index)?,
            out_n_multipliers,
            out_multiplier_dofs,
            out_rhs,
            out_n_entries,
            out_multipliers,
            out_dofs,
            out_values,
        )
    })
}

/// Each of this rank's multipliers of tie `index`: its place in the whole tie (the same
/// numbering on every rank, ascending), and the whole tie's count of multipliers.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_tie_index(
    embedding: *const SeamRankEmbedding,
    index: usize,
    out_index: *mut *const i64,
    out_total: *mut usize,
) -> c_int {
    guard(|| {
        let (rows, places) = unsafe { rank_rows(embedding) }?;
        rows.tie(index)?;
        let (place, total) = &places[index];
        unsafe {
            out(out_index, place.as_ptr(), "out_index")?;
            out(out_total, *total, "out_total")
        }
    })
}

/// Heat through tie `index` for this rank's multipliers `lambda` (`n` of them, in this
/// rank's order), summed over the ranks. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_tie_heat(
    embedding: *const SeamRankEmbedding,
    index: usize,
    lambda: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let (e, t, lambda) = unsafe { tie_on_every_rank(embedding, index, lambda, n, "lambda") }?;
        let heat = e.inner.tie_heat(t, lambda)?;
        unsafe { terms::write_heat((heat.side_a, heat.side_b), out_side_a, out_side_b) }
    })
}

/// A condensed dual tie's multipliers on this rank, `λ_k = −r_k / D_k`, from the host's
/// residual `K u − F` without the tie at each of this rank's multipliers' dofs
/// (`residual_at`, `n` values in this rank's order): written into `out_lambda`, which
/// holds `capacity` ≥ n values. Local.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_dual_multipliers(
    embedding: *const SeamRankEmbedding,
    index: usize,
    residual_at: *const f64,
    n: usize,
    out_lambda: *mut f64,
    capacity: usize,
) -> c_int {
    guard(|| {
        let (rows, _) = unsafe { rank_rows(embedding) }?;
        let (t, _) = rows.tie(index)?;
        let at = unsafe { slice(residual_at, n, "residual_at") }?;
        let lambda = t.dual_multipliers_at(at)?;
        unsafe { fields::write_lambda(&lambda, out_lambda, capacity) }
    })
}

/// Heat (W) through condensed dual tie `index` from the host's residual `K u − F`
/// without the tie at each of this rank's multipliers' dofs (`residual_at`, `n` values
/// in this rank's order), summed over the ranks: the rank form of `seam_dual_tie_heat`.
/// Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_dual_tie_heat(
    embedding: *const SeamRankEmbedding,
    index: usize,
    residual_at: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let (e, t, at) =
            unsafe { tie_on_every_rank(embedding, index, residual_at, n, "residual_at") }?;
        let heat = e.inner.dual_tie_heat(t, at)?;
        unsafe { terms::write_heat((heat.side_a, heat.side_b), out_side_a, out_side_b) }
    })
}

/// The handle, tie `index`'s rows on this rank and the `n` values at `values`, agreed
/// on every rank ([`on_every_rank`]) for a collective call.
unsafe fn tie_on_every_rank<'a>(
    embedding: *const SeamRankEmbedding,
    index: usize,
    values: *const f64,
    n: usize,
    name: &str,
) -> Result<(&'a SeamRankEmbedding, &'a TieConstraints, &'a [f64]), Failure> {
    // SAFETY: a non-null handle came from this library (module Safety).
    let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
    let local = (|| {
        let (t, _) = unsafe { rank_rows(embedding) }?.0.tie(index)?;
        Ok::<_, Failure>((t, unsafe { slice(values, n, name) }?))
    })();
    let (t, values) = on_every_rank(e.inner.comm(), local)?;
    Ok((e, t, values))
}

/// This rank's reading of its arguments, agreed on before a collective call: a bad
/// argument (a null or short array, a bad string) on one rank must not leave the others
/// waiting, so this rank returns its own failure and the others
/// `SEAM_ERR_OTHER_RANK`.
fn on_every_rank<T>(
    comm: &mpi::topology::SimpleCommunicator,
    local: Result<T, Failure>,
) -> Result<T, Failure> {
    let agreed = crate::embed::agree(
        comm,
        match &local {
            Ok(_) => Ok(()),
            Err(f) => Err(crate::embed::EmbedError::Argument {
                what: f.1.clone(),
                help: String::new(),
            }),
        },
    );
    let value = local?;
    agreed?;
    Ok(value)
}

/// The values at this rank's own side-A points of flux interaction `index` at the
/// local field (`n_nodes` values, one per local node, as for `seam_rank_evaluate`):
/// `out_values`; for each, `out_points` its index in the interaction's point order (the
/// serial `seam_point_fields` order; the ranks' points together are that list, each
/// point once) and `out_side_b_ranks` the rank whose element `side_b_element` is (−1
/// where unpaired). Faces are named by the element index of the rank that gave them:
/// side A's is this rank's own. The arrays stay valid until the next call. Collective.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_rank_point_fields(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    u_local: *const f64,
    n_nodes: usize,
    out_n: *mut usize,
    out_values: *mut *const fields::SeamPointValues,
    out_points: *mut *const usize,
    out_side_b_ranks: *mut *const c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let u = on_every_rank(e.inner.comm(), unsafe {
            slice(u_local, n_nodes, "u_local")
        })?;
        let points = e.inner.point_fields(index, u)?;
        unsafe {
            e.points
                .write(&points, out_n, out_values, out_points, out_side_b_ranks)
        }
    })
}

/// The values at this rank's own side-A points of tie `index` (after
/// `seam_rank_constraints`) for this rank's multipliers `lambda` (`n`, in this rank's
/// order: the host's unknowns, or `seam_rank_dual_multipliers`' for a condensed dual
/// tie), with each point's index and side-B face's rank, as `seam_rank_point_fields`
/// gives them; `multiplier` is the multiplier field λ_h at the point, summed from every
/// rank's multipliers. The arrays stay valid until the next point-field call.
/// Collective.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_rank_tie_point_fields(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    lambda: *const f64,
    n: usize,
    out_n: *mut usize,
    out_values: *mut *const fields::SeamPointValues,
    out_points: *mut *const usize,
    out_side_b_ranks: *mut *const c_int,
) -> c_int {
    guard(|| {
        let (e, t, lambda) = unsafe { tie_on_every_rank(embedding, index, lambda, n, "lambda") }?;
        let points = e.inner.tie_point_fields(t, lambda)?;
        let e = unsafe { handle(embedding, "embedding") }?;
        unsafe {
            e.points
                .write(&points, out_n, out_values, out_points, out_side_b_ranks)
        }
    })
}

/// Per face of flux interaction `index` at the local field (`n_nodes` values, as for
/// `seam_rank_evaluate`): the faces this rank gave (side A's, then side B's when
/// `side_b` is nonzero), named by its own elements, with `seam_face_fields`' values
/// (every point's flux summed from the rank that owns it). The ranks' faces together are
/// the serial list. Array valid until the next face-field call. Collective.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_rank_face_fields(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    u_local: *const f64,
    n_nodes: usize,
    side_b: c_int,
    out_n: *mut usize,
    out_values: *mut *const fields::SeamFaceValues,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let u = on_every_rank(e.inner.comm(), unsafe {
            slice(u_local, n_nodes, "u_local")
        })?;
        let faces = e.inner.face_fields(index, u, side_b != 0)?;
        e.faces = faces.iter().map(fields::SeamFaceValues::from).collect();
        unsafe { fields::array_out(&e.faces, out_n, out_values) }
    })
}

/// Per face of tie `index` (after `seam_rank_constraints`) for this rank's multipliers
/// `lambda` (`n`, as for `seam_rank_tie_point_fields`): the faces this rank gave, as
/// `seam_rank_face_fields` gives them, `flux` the mean multiplier field. Array valid
/// until the next face-field call. Collective.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_rank_tie_face_fields(
    embedding: *mut SeamRankEmbedding,
    index: usize,
    lambda: *const f64,
    n: usize,
    side_b: c_int,
    out_n: *mut usize,
    out_values: *mut *const fields::SeamFaceValues,
) -> c_int {
    guard(|| {
        let (e, t, lambda) = unsafe { tie_on_every_rank(embedding, index, lambda, n, "lambda") }?;
        let faces = e.inner.tie_face_fields(t, lambda, side_b != 0)?;
        let e = unsafe { handle(embedding, "embedding") }?;
        e.faces = faces.iter().map(fields::SeamFaceValues::from).collect();
        unsafe { fields::array_out(&e.faces, out_n, out_values) }
    })
}
