//! The C face of coverage, per-point and per-face fields, the CSR Jacobian, the heat of
//! a state the host passes, and conductance callbacks (`seam.h`, "coverage and
//! fields", "CSR", "callbacks").

use super::*;
use std::ffi::c_void;
use std::sync::Arc;

use crate::embed::{
    Conductance, Coverage, FaceValues, FnConductance, PointState, PointValues, UnpairedReason,
};

/// Arrays the field and coverage queries return (valid until the next such query).
#[derive(Default)]
pub(super) struct Buffers {
    points: Vec<SeamPointValues>,
    faces: Vec<SeamFaceValues>,
    unpaired_index: Vec<usize>,
    unpaired_xyz: Vec<f64>,
    unpaired_reason: Vec<c_int>,
    pub(super) quarantined_xyz: Vec<f64>,
    pub(super) quarantined_reasons: std::ffi::CString,
    /// The last evaluation was `seam_evaluate_csr` (its results are the embedding's
    /// `evaluation()`).
    pub(super) csr_current: bool,
}

/// What a search paired (`seam_coverage`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct SeamCoverage {
    pub points: usize,
    pub paired_points: usize,
    pub area: f64,
    pub paired_area: f64,
    pub unpaired: usize,
    /// 1 when something paired (then `gap_min`, `gap_max` hold), else 0.
    pub has_gap: c_int,
    pub gap_min: f64,
    pub gap_max: f64,
}

/// One side-A point's values (`seam_point_fields`, `seam_tie_point_fields`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamPointValues {
    pub x: [f64; 3],
    pub weight: f64,
    pub paired: c_int,
    /// Side-A face (element, 1-based side); element −1 for a node of a node surface.
    pub side_a_element: i64,
    pub side_a_side: c_int,
    /// Side-B face; element −1 when not paired.
    pub side_b_element: i64,
    pub side_b_side: c_int,
    pub gap: f64,
    pub flux: f64,
    pub temp_a: f64,
    pub temp_b: f64,
    /// 1 for a mortar tie's point with a multiplier (then `multiplier` is λ_h there).
    pub has_multiplier: c_int,
    pub multiplier: f64,
}

/// One face's values (`seam_face_fields`, `seam_tie_face_fields`).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamFaceValues {
    pub element: i64,
    pub side: c_int,
    /// 0 side A, 1 side B.
    pub surface_side: c_int,
    pub area: f64,
    pub paired_area: f64,
    pub fraction: f64,
    pub gap: f64,
    pub flux: f64,
}

impl From<&PointValues> for SeamPointValues {
    fn from(p: &PointValues) -> Self {
        let face = |f: Option<crate::embed::HostFace>| {
            f.map_or((-1, 0), |f| (as_i64(f.element), c_int::from(f.side)))
        };
        let (side_a_element, side_a_side) = face(p.side_a);
        let (side_b_element, side_b_side) = face(p.side_b);
        SeamPointValues {
            x: p.x,
            weight: p.weight,
            paired: c_int::from(p.paired),
            side_a_element,
            side_a_side,
            side_b_element,
            side_b_side,
            gap: p.gap,
            flux: p.flux,
            temp_a: p.temp_a,
            temp_b: p.temp_b,
            has_multiplier: c_int::from(p.multiplier.is_some()),
            multiplier: p.multiplier.unwrap_or(0.0),
        }
    }
}

impl From<&Coverage> for SeamCoverage {
    fn from(c: &Coverage) -> Self {
        let (has_gap, (gap_min, gap_max)) = match c.gap_range {
            Some(g) => (1, g),
            None => (0, (0.0, 0.0)),
        };
        SeamCoverage {
            points: c.points,
            paired_points: c.paired_points,
            area: c.area,
            paired_area: c.paired_area,
            unpaired: c.unpaired.len(),
            has_gap,
            gap_min,
            gap_max,
        }
    }
}

impl From<&FaceValues> for SeamFaceValues {
    fn from(f: &FaceValues) -> Self {
        SeamFaceValues {
            element: as_i64(f.face.element),
            side: c_int::from(f.face.side),
            surface_side: c_int::from(f.side),
            area: f.area,
            paired_area: f.paired_area,
            fraction: f.fraction,
            gap: f.gap,
            flux: f.flux,
        }
    }
}

/// An array the handle keeps, through the out pointers (count and start).
pub(super) unsafe fn array_out<T>(
    values: &[T],
    out_n: *mut usize,
    out_values: *mut *const T,
) -> Result<(), Failure> {
    unsafe {
        out(out_n, values.len(), "out_n")?;
        out(out_values, values.as_ptr(), "out_values")
    }
}

pub(super) unsafe fn handle_ref<'a>(
    ptr: *mut SeamEmbedding,
) -> Result<&'a mut SeamEmbedding, Failure> {
    unsafe { handle(ptr, "embedding") }
}

/// What the last search of interaction `index` paired.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_coverage(
    embedding: *const SeamEmbedding,
    index: usize,
    out_coverage: *mut SeamCoverage,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let c: Coverage = e.inner.coverage(index)?;
        unsafe { out(out_coverage, SeamCoverage::from(&c), "out_coverage") }
    })
}

/// The unpaired points of interaction `index`: their point indices, positions (xyz per
/// point) and reasons (SEAM_UNPAIRED_*).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_unpaired_points(
    embedding: *mut SeamEmbedding,
    index: usize,
    out_n: *mut usize,
    out_points: *mut *const usize,
    out_xyz: *mut *const f64,
    out_reasons: *mut *const c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let c = e.inner.coverage(index)?;
        let b = &mut e.buffers;
        b.unpaired_index = c.unpaired.iter().map(|u| u.point).collect();
        b.unpaired_xyz = c.unpaired.iter().flat_map(|u| u.x).collect();
        b.unpaired_reason = c
            .unpaired
            .iter()
            .map(|u| match u.reason {
                UnpairedReason::NoFace => 1,
                UnpairedReason::TooFar => 2,
                UnpairedReason::NormalsNotOpposed => 3,
                UnpairedReason::OutsideSubdomain => 4,
            })
            .collect();
        unsafe {
            out(out_n, b.unpaired_index.len(), "out_n")?;
            out(out_points, b.unpaired_index.as_ptr(), "out_points")?;
            out(out_xyz, b.unpaired_xyz.as_ptr(), "out_xyz")?;
            out(out_reasons, b.unpaired_reason.as_ptr(), "out_reasons")
        }
    })
}

/// Let interaction `index` (every interaction with SIZE_MAX) pair nothing without
/// SEAM_ERR_NOTHING_PAIRED (`allow` non-zero), or refuse it again (0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_allow_unpaired(
    embedding: *mut SeamEmbedding,
    index: usize,
    allow: c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let which = (index != usize::MAX).then_some(index);
        Ok(e.inner.allow_unpaired(which, allow != 0)?)
    })
}

/// The values at every side-A point of flux interaction `index` at the host's field
/// `u` (`n` entries, by host dof).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_point_fields(
    embedding: *mut SeamEmbedding,
    index: usize,
    u: *const f64,
    n: usize,
    out_n: *mut usize,
    out_values: *mut *const SeamPointValues,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let u = unsafe { slice(u, n, "u") }?;
        let values = e.inner.point_fields(index, u)?;
        e.buffers.points = values.iter().map(SeamPointValues::from).collect();
        unsafe { array_out(&e.buffers.points, out_n, out_values) }
    })
}

/// Per face of flux interaction `index` at `u`: side A's faces, then side B's when
/// `side_b` is non-zero.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_face_fields(
    embedding: *mut SeamEmbedding,
    index: usize,
    u: *const f64,
    n: usize,
    side_b: c_int,
    out_n: *mut usize,
    out_values: *mut *const SeamFaceValues,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let u = unsafe { slice(u, n, "u") }?;
        let values = e.inner.face_fields(index, u, side_b != 0)?;
        e.buffers.faces = values.iter().map(SeamFaceValues::from).collect();
        unsafe { array_out(&e.buffers.faces, out_n, out_values) }
    })
}

/// The values at every side-A point of tie `tie` (after `seam_constraints`) for its
/// multipliers `lambda` (`n` = its number of multipliers; for a condensed dual tie,
/// see `seam_dual_multipliers`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_tie_point_fields(
    embedding: *mut SeamEmbedding,
    tie: usize,
    lambda: *const f64,
    n: usize,
    out_n: *mut usize,
    out_values: *mut *const SeamPointValues,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let lambda = unsafe { slice(lambda, n, "lambda") }?;
        let t = ties::tie(e, tie)?.0.clone();
        let values = e.inner.tie_point_fields(&t, lambda)?;
        e.buffers.points = values.iter().map(SeamPointValues::from).collect();
        unsafe { array_out(&e.buffers.points, out_n, out_values) }
    })
}

/// The dual multipliers of a condensed dual tie from the host's own residual `K u − F`
/// without the tie (`n` entries, by host dof): `out_lambda` receives one value per
/// multiplier (`n_multipliers` of `seam_tie_rows`), written into the caller's array of
/// `capacity` entries.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_dual_multipliers(
    embedding: *mut SeamEmbedding,
    tie: usize,
    residual: *const f64,
    n: usize,
    out_lambda: *mut f64,
    capacity: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let residual = unsafe { slice(residual, n, "residual") }?;
        let lambda = ties::tie(e, tie)?.0.dual_multipliers(residual)?;
        unsafe { write_lambda(&lambda, out_lambda, capacity) }
    })
}

/// Copy `lambda` into the caller's `out_lambda` of `capacity` values.
pub(super) unsafe fn write_lambda(
    lambda: &[f64],
    out_lambda: *mut f64,
    capacity: usize,
) -> Result<(), Failure> {
    if capacity < lambda.len() {
        return Err(bad(
            format!(
                "out_lambda holds {capacity} values, the tie has {} multipliers",
                lambda.len()
            ),
            "pass an array of n_multipliers entries (seam_tie_rows)",
        ));
    }
    if lambda.is_empty() {
        return Ok(());
    }
    if out_lambda.is_null() {
        return Err(null("out_lambda"));
    }
    // SAFETY: non-null and valid for `capacity` ≥ len entries (checked above).
    unsafe { std::ptr::copy_nonoverlapping(lambda.as_ptr(), out_lambda, lambda.len()) };
    Ok(())
}

/// Heat (W) leaving side A and side B of flux interaction `index` at the host's field
/// `u` (`n` entries, by host dof), whatever was evaluated before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_heat_at(
    embedding: *const SeamEmbedding,
    index: usize,
    u: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let u = unsafe { slice(u, n, "u") }?;
        let h = e.inner.heat_of(index, u)?.ok_or_else(|| {
            bad(
                format!("interaction {index} is a mortar tie"),
                "read its heat with seam_tie_heat or seam_dual_tie_heat",
            )
        })?;
        unsafe {
            out(out_side_a, h.side_a, "out_side_a")?;
            out(out_side_b, h.side_b, "out_side_b")
        }
    })
}

/// Evaluate at the host's field `u` (`n` entries, by host dof; `n` is the matrix size)
/// into a CSR Jacobian whose pattern is built at the first call after a search or move
/// and then only refreshed, and dense residual and load vectors. Read them with
/// `seam_jacobian_csr`, `seam_residual_dense`, `seam_load_dense`; `seam_heat` gives the
/// heat of this evaluation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_evaluate_csr(
    embedding: *mut SeamEmbedding,
    u: *const f64,
    n: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let u = unsafe { slice(u, n, "u") }?;
        e.evaluated = None;
        e.cutback = None;
        e.buffers.csr_current = false;
        match e.inner.evaluate(u) {
            Ok(_) => {
                e.buffers.csr_current = true;
                Ok(())
            }
            Err(err) => {
                if let EmbedError::Cutback { factor, .. } = &err {
                    e.cutback = Some(*factor);
                }
                Err(err.into())
            }
        }
    })
}

pub(super) fn csr(e: &SeamEmbedding) -> Result<&crate::embed::Evaluation, Failure> {
    e.inner
        .evaluation()
        .filter(|_| e.buffers.csr_current)
        .ok_or_else(|| {
            Failure(
                SeamStatus::Order,
                "nothing evaluated into CSR\n  help: call seam_evaluate_csr first (after seam_search)".into(),
            )
        })
}

/// The CSR Jacobian of the last `seam_evaluate_csr`: `n_rows + 1` row offsets, `nnz`
/// column indices (sorted within a row) and values. `pattern` changes only when a
/// search or a move made a new pattern: while it stays, offsets and columns are the
/// same arrays with the same contents and a host may keep its symbolic factorisation.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_jacobian_csr(
    embedding: *const SeamEmbedding,
    out_n_rows: *mut usize,
    out_nnz: *mut usize,
    out_row_offsets: *mut *const usize,
    out_columns: *mut *const usize,
    out_values: *mut *const f64,
    out_pattern: *mut u64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let j = &csr(e)?.jacobian;
        unsafe {
            out(out_n_rows, j.n, "out_n_rows")?;
            out(out_nnz, j.columns.len(), "out_nnz")?;
            out(out_row_offsets, j.row_offsets.as_ptr(), "out_row_offsets")?;
            out(out_columns, j.columns.as_ptr(), "out_columns")?;
            out(out_values, j.values.as_ptr(), "out_values")?;
            if !out_pattern.is_null() {
                out(out_pattern, csr(e)?.pattern, "out_pattern")?;
            }
            Ok(())
        }
    })
}

/// One dense vector of the last `seam_evaluate_csr`, through the out pointers.
unsafe fn dense_out(
    embedding: *const SeamEmbedding,
    pick: fn(&crate::embed::Evaluation) -> &Vec<f64>,
    out_n: *mut usize,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { array_out(pick(csr(e)?), out_n, out_values) }
    })
}

/// The residual of the last `seam_evaluate_csr`, dense by host dof (`n` entries).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_residual_dense(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_values: *mut *const f64,
) -> c_int {
    unsafe { dense_out(embedding, |e| &e.residual, out_n, out_values) }
}

/// The load (right-hand side of linear models) of the last `seam_evaluate_csr`, dense.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_load_dense(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_values: *mut *const f64,
) -> c_int {
    unsafe { dense_out(embedding, |e| &e.load, out_n, out_values) }
}

/// A point's state as a C conductance callback sees it.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamPointState {
    pub gap: f64,
    pub pressure: f64,
    pub temp_a: f64,
    pub temp_b: f64,
    pub x: [f64; 3],
    pub time: f64,
}

/// `int f(const seam_point_state *state, void *user_data, double *out_h,
/// double *out_dh_dtemp_a, double *out_dh_dtemp_b)`: 0 on success.
pub type SeamConductanceFn = Option<
    unsafe extern "C" fn(*const SeamPointState, *mut c_void, *mut f64, *mut f64, *mut f64) -> c_int,
>;

/// `callback(state, user_data, …)` as a conductance: a non-zero status is a failure at
/// the point, and what it returns is checked like every model's.
fn callback_conductance(
    f: unsafe extern "C" fn(
        *const SeamPointState,
        *mut c_void,
        *mut f64,
        *mut f64,
        *mut f64,
    ) -> c_int,
    user_data: *mut c_void,
) -> impl Fn(&PointState) -> Result<Conductance, String> {
    move |state: &PointState| {
        let s = SeamPointState {
            gap: state.gap,
            pressure: state.pressure,
            temp_a: state.temp_a,
            temp_b: state.temp_b,
            x: state.x,
            time: state.time,
        };
        let (mut h, mut da, mut db) = (f64::NAN, 0.0, 0.0);
        // SAFETY: the host promised (seam.h) a callback and user data valid while the
        // embedding lives; the out pointers are to these locals.
        let status = unsafe { f(&s, user_data, &mut h, &mut da, &mut db) };
        if status != 0 {
            return Err(format!("the callback returned {status}"));
        }
        Ok(Conductance {
            h,
            dh_dtemp_a: da,
            dh_dtemp_b: db,
            ..Conductance::default()
        })
    }
}

/// As `seam_add_interaction` (SEAM_CONDUCTANCE or SEAM_GAP_CONDUCTANCE), with h from
/// `callback(state, user_data, &h, &dh_dtemp_a, &dh_dtemp_b)` at each point.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_add_interaction_with_conductance(
    embedding: *mut SeamEmbedding,
    side_a: *const c_char,
    side_b: *const c_char,
    model: c_int,
    callback: SeamConductanceFn,
    user_data: *mut c_void,
    depends_on_temperature: c_int,
    offset: f64,
    out_index: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let (a, b) = unsafe { (text(side_a, "side_a")?, text(side_b, "side_b")?) };
        let f = callback.ok_or_else(|| null("callback"))?;
        if !matches!(model, 1 | 2) {
            return Err(bad(
                format!("model code {model} takes no conductance"),
                "use SEAM_CONDUCTANCE or SEAM_GAP_CONDUCTANCE",
            ));
        }
        let model = interactions::model_of(model, 0.0)?;
        // An embedding is used by one thread at a time (seam.h), like its models.
        #[allow(clippy::arc_with_non_send_sync)]
        let c = Arc::new(FnConductance::new(
            "host conductance callback",
            depends_on_temperature != 0,
            callback_conductance(f, user_data),
        ));
        interactions::add(
            e,
            Interaction::new(a, b, model).conductance(c).offset(offset),
            out_index,
        )
    })
}
