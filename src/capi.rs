//! The C API of [`crate::embed`]: `libseam` with the header `include/seam.h`.
//!
//! Entry points mirror the Rust API: a builder handle (`seam_builder_*`) takes the
//! host's nodes, blocks, surfaces and dof numbers; `seam_embedding_new` checks them and
//! makes an embedding handle; interactions come from `seam_add_interaction`,
//! `seam_add_periodic_interaction`, `seam_add_deck` or `seam_add_deck_file`; then `seam_search`, `seam_move_nodes`, `seam_evaluate` with the
//! accessors of its results, and `seam_constraints` with `seam_tie_*` for mortar ties.
//!
//! Conventions:
//! - Every function returns a [`SeamStatus`] code (0 is success). On failure the
//!   message — what, where, how to fix — is kept per thread and read with
//!   `seam_last_error()`.
//! - No panic crosses the boundary: each body runs under `catch_unwind`; a panic
//!   (a seam bug) becomes `SEAM_ERR_INTERNAL` with its message.
//! - Arrays returned through `const T**` out-parameters are owned by the handle and
//!   stay valid until the next call that recomputes them or the handle is freed.
//! - Indices (nodes, elements, dofs) are 0-based `int64_t`; counts are `size_t`.
//!
//! Safety: every pointer argument must be null or valid for the stated number of
//! elements; handles must come from this library and be used by one thread at a time.
//! Null handles and null arrays with a non-zero count are reported, not dereferenced.

#![allow(clippy::missing_safety_doc)] // the module's Safety paragraph covers every function

use std::cell::RefCell;
use std::ffi::{CStr, CString, c_char, c_int};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::embed::{
    Contributions, EmbedError, Embedding, EmbeddingBuilder, Integration, Interaction, Model,
    Multipliers, Periodic, TieConstraints, Topology,
};

/// Status codes (`SEAM_OK` … in `seam.h`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeamStatus {
    Ok = 0,
    /// A null handle or a null array with a non-zero length.
    NullArgument = 1,
    /// The host's mesh arrays are inconsistent or fail the mesh checks.
    Mesh = 2,
    /// A contact deck with errors.
    Deck = 3,
    /// An argument out of range, an unknown name or code.
    Argument = 4,
    /// A call out of order (e.g. `seam_evaluate` before `seam_search`).
    Order = 5,
    /// An enforcement failed at a contact point.
    Enforcement = 6,
    /// A bug in seam (a caught panic).
    Internal = 7,
    /// A plugin enforcement could not be loaded, or its plugin failed at a contact point.
    Plugin = 8,
    /// A plugin asks for a smaller step (`seam_cutback_factor` gives its suggestion).
    Cutback = 9,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = text);
}

struct Failure(SeamStatus, String);

impl From<EmbedError> for Failure {
    fn from(e: EmbedError) -> Self {
        let status = match &e {
            EmbedError::Mesh { .. } | EmbedError::Invalid(_) => SeamStatus::Mesh,
            EmbedError::Deck(_) => SeamStatus::Deck,
            EmbedError::Order { .. } => SeamStatus::Order,
            EmbedError::Enforcement { .. } => SeamStatus::Enforcement,
            EmbedError::Plugin { .. } => SeamStatus::Plugin,
            EmbedError::Cutback { .. } => SeamStatus::Cutback,
            _ => SeamStatus::Argument,
        };
        Failure(status, e.to_string())
    }
}

fn null(what: &str) -> Failure {
    Failure(
        SeamStatus::NullArgument,
        format!("{what} is null\n  help: pass a valid pointer"),
    )
}

fn bad(what: String, help: &str) -> Failure {
    Failure(SeamStatus::Argument, format!("{what}\n  help: {help}"))
}

/// Run `body`, turning its error or panic into a status code and the last error.
fn guard(body: impl FnOnce() -> Result<(), Failure>) -> c_int {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => SeamStatus::Ok as c_int,
        Ok(Err(Failure(status, message))) => {
            set_error(&message);
            status as c_int
        }
        Err(panic) => {
            let what = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            set_error(&format!(
                "internal error in seam: {what}\n  help: this is a bug in seam; please report it with the input that caused it"
            ));
            SeamStatus::Internal as c_int
        }
    }
}

unsafe fn slice<'a, T>(ptr: *const T, len: usize, what: &str) -> Result<&'a [T], Failure> {
    if len == 0 {
        return Ok(&[]);
    }
    if ptr.is_null() {
        return Err(null(what));
    }
    if len > isize::MAX as usize / std::mem::size_of::<T>().max(1) {
        return Err(bad(
            format!("{what}: {len} entries is more than any array can hold"),
            "check the count passed with the array",
        ));
    }
    // SAFETY: the caller promises `ptr` is valid for `len` elements (module Safety).
    Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
}

unsafe fn text<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, Failure> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: the caller promises a NUL-terminated string (module Safety).
    unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .map_err(|_| bad(format!("{what} is not UTF-8"), "pass UTF-8 text"))
}

unsafe fn handle<'a, T>(ptr: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: a non-null handle came from this library (module Safety).
    unsafe { ptr.as_mut() }.ok_or_else(|| null(what))
}

fn index(v: i64, what: &str) -> Result<usize, Failure> {
    usize::try_from(v).map_err(|_| bad(format!("{what} {v} is negative"), "indices are 0-based"))
}

unsafe fn out<T>(ptr: *mut T, value: T, what: &str) -> Result<(), Failure> {
    if ptr.is_null() {
        return Err(null(what));
    }
    // SAFETY: the caller passes a writable location (module Safety).
    unsafe { ptr.write(value) };
    Ok(())
}

/// The builder handle: the host's arrays, kept until `seam_embedding_new`.
pub struct SeamBuilder(Option<EmbeddingBuilder>);

impl SeamBuilder {
    fn update(&mut self, f: impl FnOnce(EmbeddingBuilder) -> EmbeddingBuilder) {
        if let Some(b) = self.0.take() {
            self.0 = Some(f(b));
        }
    }
}

/// Results of the last evaluation, as C arrays.
#[derive(Default)]
struct Evaluated {
    residual_dofs: Vec<i64>,
    residual_values: Vec<f64>,
    rows: Vec<i64>,
    cols: Vec<i64>,
    values: Vec<f64>,
    load_dofs: Vec<i64>,
    load_values: Vec<f64>,
    heat: Vec<Option<(f64, f64)>>,
}

/// Condensed rows of every dual tie, in compressed-row form, and each tie's rows.
#[derive(Default)]
struct Rows {
    dofs: Vec<i64>,
    constants: Vec<f64>,
    offsets: Vec<usize>,
    cols: Vec<i64>,
    coefficients: Vec<f64>,
    ties: Vec<(TieConstraints, TieArrays)>,
}

/// One tie's `C u = g` as C arrays.
struct TieArrays {
    multiplier_dofs: Vec<i64>,
    multipliers: Vec<i64>,
    dofs: Vec<i64>,
    values: Vec<f64>,
}

impl TieArrays {
    fn from(t: &TieConstraints) -> Self {
        TieArrays {
            multiplier_dofs: t.multiplier_dofs.iter().map(|&d| as_i64(d)).collect(),
            multipliers: t.entries.iter().map(|e| as_i64(e.0)).collect(),
            dofs: t.entries.iter().map(|e| as_i64(e.1)).collect(),
            values: t.entries.iter().map(|e| e.2).collect(),
        }
    }
}

/// The embedding handle.
pub struct SeamEmbedding {
    inner: Embedding,
    evaluated: Option<Evaluated>,
    rows: Option<Rows>,
    /// The step factor a plugin suggested when the last evaluation asked for a cutback.
    cutback: Option<f64>,
}

impl SeamEmbedding {
    /// The interactions or the geometry changed: the last evaluation and tie rows no
    /// longer hold.
    fn forget_results(&mut self) {
        self.evaluated = None;
        self.rows = None;
    }
}

fn as_i64(v: usize) -> i64 {
    v as i64
}

impl Evaluated {
    fn from(c: Contributions) -> Self {
        let mut e = Evaluated::default();
        for (d, v) in c.residual {
            e.residual_dofs.push(as_i64(d));
            e.residual_values.push(v);
        }
        for (i, j, v) in c.jacobian {
            e.rows.push(as_i64(i));
            e.cols.push(as_i64(j));
            e.values.push(v);
        }
        for (d, v) in c.load {
            e.load_dofs.push(as_i64(d));
            e.load_values.push(v);
        }
        e.heat = c
            .heat
            .into_iter()
            .map(|h| h.map(|h| (h.side_a, h.side_b)))
            .collect();
        e
    }
}

/// The library's version, e.g. "0.1.0" (static storage).
#[unsafe(no_mangle)]
pub extern "C" fn seam_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr().cast()
}

/// The message of the last failed call on this thread ("" if none). Valid until the
/// next failing call on the same thread.
#[unsafe(no_mangle)]
pub extern "C" fn seam_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_new(
    coords: *const f64,
    n_nodes: usize,
    out_builder: *mut *mut SeamBuilder,
) -> c_int {
    guard(|| {
        let xyz = unsafe { slice(coords, n_nodes.saturating_mul(3), "coords") }?;
        let points: Vec<[f64; 3]> = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let b = Box::new(SeamBuilder(Some(Embedding::builder(&points))));
        unsafe { out(out_builder, Box::into_raw(b), "out_builder") }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_free(builder: *mut SeamBuilder) {
    if !builder.is_null() {
        // SAFETY: made by Box::into_raw in seam_builder_new and freed once (module Safety).
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(builder) })));
    }
}

fn topology(code: c_int) -> Result<Topology, Failure> {
    Ok(match code {
        1 => Topology::Hex8,
        2 => Topology::Tet4,
        3 => Topology::Wedge6,
        4 => Topology::Pyramid5,
        other => {
            return Err(bad(
                format!("unknown topology code {other}"),
                "use SEAM_HEX8, SEAM_TET4, SEAM_WEDGE6 or SEAM_PYRAMID5",
            ));
        }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_add_block(
    builder: *mut SeamBuilder,
    name: *const c_char,
    topology_code: c_int,
    connectivity: *const i64,
    n_elems: usize,
    conductivity: f64,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let name = unsafe { text(name, "name") }?;
        let t = topology(topology_code)?;
        let conn = unsafe {
            slice(
                connectivity,
                n_elems.saturating_mul(t.node_count()),
                "connectivity",
            )
        }?;
        let conn = conn
            .iter()
            .map(|&v| index(v, "connectivity node"))
            .collect::<Result<Vec<_>, _>>()?;
        b.update(|x| x.block(name, t, &conn, conductivity));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_add_side_set(
    builder: *mut SeamBuilder,
    name: *const c_char,
    elems: *const i64,
    sides: *const c_int,
    n_faces: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let name = unsafe { text(name, "name") }?;
        let elems = unsafe { slice(elems, n_faces, "elems") }?;
        let sides = unsafe { slice(sides, n_faces, "sides") }?;
        let list = elems
            .iter()
            .zip(sides)
            .map(|(&e, &s)| {
                let side = u8::try_from(s)
                    .map_err(|_| bad(format!("side {s} is out of range"), "sides are 1 to 6"))?;
                Ok((index(e, "element")?, side))
            })
            .collect::<Result<Vec<_>, Failure>>()?;
        b.update(|x| x.side_set(name, &list));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_add_face_set(
    builder: *mut SeamBuilder,
    name: *const c_char,
    face_nodes: *const i64,
    nodes_per_face: usize,
    n_faces: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let name = unsafe { text(name, "name") }?;
        if !matches!(nodes_per_face, 3 | 4) {
            return Err(bad(
                format!("nodes_per_face = {nodes_per_face}"),
                "faces are triangles (3) or quadrilaterals (4)",
            ));
        }
        let nodes = unsafe {
            slice(
                face_nodes,
                n_faces.saturating_mul(nodes_per_face),
                "face_nodes",
            )
        }?;
        let faces = nodes
            .chunks_exact(nodes_per_face)
            .map(|f| f.iter().map(|&v| index(v, "face node")).collect())
            .collect::<Result<Vec<Vec<usize>>, _>>()?;
        b.update(|x| x.face_set(name, &faces));
        Ok(())
    })
}

/// `dofs[node]` is the host's dof of each node; a negative value means none.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_dofs(
    builder: *mut SeamBuilder,
    dofs: *const i64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let dofs = unsafe { slice(dofs, n_nodes, "dofs") }?;
        let list: Vec<Option<usize>> = dofs.iter().map(|&d| usize::try_from(d).ok()).collect();
        b.update(|x| x.partial_dofs(&list));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_fixed_nodes(
    builder: *mut SeamBuilder,
    nodes: *const i64,
    n: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let nodes = unsafe { slice(nodes, n, "nodes") }?
            .iter()
            .map(|&v| index(v, "fixed node"))
            .collect::<Result<Vec<_>, _>>()?;
        b.update(|x| x.fixed_nodes(&nodes));
        Ok(())
    })
}

/// `kind` 0: mortar segments, 1: Gauss quadrature on side A; `order` the rule's order,
/// 1 to [`crate::search::pairing::MAX_ORDER`].
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_integration(
    builder: *mut SeamBuilder,
    kind: c_int,
    order: c_int,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let order = usize::try_from(order)
            .ok()
            .filter(|o| (1..=crate::search::pairing::MAX_ORDER).contains(o))
            .ok_or_else(|| bad(format!("order {order}"), "give an order of 1 to 20"))?;
        let integration = match kind {
            0 => Integration::Segments { order },
            1 => Integration::Quadrature { order },
            other => {
                return Err(bad(
                    format!("unknown integration kind {other}"),
                    "use SEAM_SEGMENTS or SEAM_QUADRATURE",
                ));
            }
        };
        b.update(|x| x.integration(integration));
        Ok(())
    })
}

/// Check the builder's arrays and make an embedding. The builder is left as it was
/// (free it with `seam_builder_free`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_embedding_new(
    builder: *const SeamBuilder,
    out_embedding: *mut *mut SeamEmbedding,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let b = unsafe { builder.as_ref() }.ok_or_else(|| null("builder"))?;
        let inner =
            b.0.clone()
                .ok_or_else(|| bad("the builder is unusable".into(), "make a new one"))?
                .build()?;
        let e = Box::new(SeamEmbedding {
            inner,
            evaluated: None,
            rows: None,
            cutback: None,
        });
        unsafe { out(out_embedding, Box::into_raw(e), "out_embedding") }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_embedding_free(embedding: *mut SeamEmbedding) {
    if !embedding.is_null() {
        // SAFETY: made by Box::into_raw in seam_embedding_new, freed once (module Safety).
        let _ = catch_unwind(AssertUnwindSafe(|| {
            drop(unsafe { Box::from_raw(embedding) })
        }));
    }
}

/// Add an interaction between two named surfaces. `model`: SEAM_CONDUCTANCE and
/// SEAM_GAP_CONDUCTANCE use `h`; SEAM_TIED_NITSCHE, SEAM_TIED_MORTAR and
/// SEAM_TIED_DUAL_MORTAR ignore it. `offset` is a prescribed jump `u_A − u_B`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_interaction(
    embedding: *mut SeamEmbedding,
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
        let model = model_of(model, h)?;
        add(e, Interaction::new(a, b, model).offset(offset), out_index)
    })
}

fn model_of(code: c_int, h: f64) -> Result<Model, Failure> {
    Ok(match code {
        1 => Model::Conductance { h },
        2 => Model::GapConductance { h },
        3 => Model::TiedNitsche,
        4 => Model::TiedMortar {
            multipliers: Multipliers::Standard,
        },
        5 => Model::TiedMortar {
            multipliers: Multipliers::Dual,
        },
        other => {
            return Err(bad(
                format!("unknown model code {other}"),
                "use one of the SEAM_CONDUCTANCE … SEAM_TIED_DUAL_MORTAR codes of seam.h",
            ));
        }
    })
}

fn add(e: &mut SeamEmbedding, i: Interaction, out_index: *mut usize) -> Result<(), Failure> {
    let i = e.inner.add_interaction(i)?;
    e.forget_results();
    if !out_index.is_null() {
        unsafe { out(out_index, i, "out_index") }?;
    }
    Ok(())
}

/// The periodic map of `transform` (a SEAM_PERIODIC_* code) from its parameters.
fn periodic_of(transform: c_int, p: &[f64]) -> Result<Periodic, Failure> {
    let count = |want: &[usize], usage: &str| -> Result<(), Failure> {
        if want.contains(&p.len()) {
            Ok(())
        } else {
            Err(bad(
                format!("{} parameters for periodic map {transform}", p.len()),
                usage,
            ))
        }
    };
    Ok(match transform {
        1 => {
            count(&[3], "SEAM_PERIODIC_RECTANGULAR takes the offset: dx dy dz")?;
            Periodic::Rectangular {
                offset: [p[0], p[1], p[2]],
            }
        }
        2 => {
            count(
                &[7],
                "SEAM_PERIODIC_CYLINDRICAL takes axis x y z, center x y z and the angle in degrees",
            )?;
            Periodic::Cylindrical {
                axis: [p[0], p[1], p[2]],
                center: [p[3], p[4], p[5]],
                angle: p[6],
            }
        }
        3 => {
            count(
                &[0, 1],
                "SEAM_PERIODIC_ALIGN_SURFACE takes nothing or invert_normals (1 or 0)",
            )?;
            Periodic::AlignSurface {
                invert_normals: p.first().is_none_or(|&v| v != 0.0),
            }
        }
        other => {
            return Err(bad(
                format!("unknown periodic map code {other}"),
                "use SEAM_PERIODIC_RECTANGULAR, SEAM_PERIODIC_CYLINDRICAL or SEAM_PERIODIC_ALIGN_SURFACE (Lua maps come in a deck: seam_add_deck)",
            ));
        }
    })
}

/// As `seam_add_interaction`, between the image of `side_a` under a periodic map and
/// `side_b`. `transform` is a SEAM_PERIODIC_* code with `n_params` parameters (see
/// seam.h); the image must land on `side_b`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_periodic_interaction(
    embedding: *mut SeamEmbedding,
    side_a: *const c_char,
    side_b: *const c_char,
    model: c_int,
    h: f64,
    offset: f64,
    transform: c_int,
    params: *const f64,
    n_params: usize,
    out_index: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let (a, b) = unsafe { (text(side_a, "side_a")?, text(side_b, "side_b")?) };
        let model = model_of(model, h)?;
        let periodic = periodic_of(transform, unsafe { slice(params, n_params, "params") }?)?;
        let i = Interaction::new(a, b, model)
            .offset(offset)
            .periodic(periodic);
        add(e, i, out_index)
    })
}

/// Add the interactions of a Sierra-syntax contact deck given as text; `name` labels
/// its messages. `out_count` (may be null) receives how many were added.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_deck(
    embedding: *mut SeamEmbedding,
    deck_text: *const c_char,
    name: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let deck = unsafe { text(deck_text, "deck_text") }?;
        let name = if name.is_null() {
            "deck"
        } else {
            unsafe { text(name, "name") }?
        };
        let added = e.inner.add_deck(name, deck)?;
        e.forget_results();
        if !out_count.is_null() {
            unsafe { out(out_count, added.len(), "out_count") }?;
        }
        Ok(())
    })
}

/// Add the interactions of a deck file (Sierra syntax or `.toml`); relative paths in
/// it (Lua files, plugin libraries) are taken from its folder.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_deck_file(
    embedding: *mut SeamEmbedding,
    path: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let path = unsafe { text(path, "path") }?;
        let added = e.inner.add_deck_file(std::path::Path::new(path))?;
        e.forget_results();
        if !out_count.is_null() {
            unsafe { out(out_count, added.len(), "out_count") }?;
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_interaction_count(
    embedding: *const SeamEmbedding,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { out(out_count, e.inner.len(), "out_count") }
    })
}

/// Search every interaction anew.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_search(embedding: *mut SeamEmbedding) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.inner.search()?;
        e.forget_results();
        Ok(())
    })
}

/// The host's time for the next `seam_evaluate` (conductance models and plugins that
/// depend on t see it).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_set_time(embedding: *mut SeamEmbedding, time: f64) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.inner.set_time(time)?;
        e.evaluated = None;
        Ok(())
    })
}

/// New coordinates of every node (3 per node): pairings are kept, gaps measured anew.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_move_nodes(
    embedding: *mut SeamEmbedding,
    coords: *const f64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let xyz = unsafe { slice(coords, n_nodes.saturating_mul(3), "coords") }?;
        let points: Vec<[f64; 3]> = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        e.inner.move_nodes(&points)?;
        e.forget_results();
        Ok(())
    })
}

/// Evaluate the interface terms at the host's field `u` (`n` entries, by host dof).
/// Read them with `seam_residual`, `seam_jacobian`, `seam_load` and `seam_heat`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_evaluate(
    embedding: *mut SeamEmbedding,
    u: *const f64,
    n: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let u = unsafe { slice(u, n, "u") }?;
        e.evaluated = None;
        e.cutback = None;
        match e.inner.contributions(u) {
            Ok(c) => e.evaluated = Some(Evaluated::from(c)),
            Err(err) => {
                if let EmbedError::Cutback { factor, .. } = &err {
                    e.cutback = Some(*factor);
                }
                return Err(err.into());
            }
        }
        Ok(())
    })
}

/// After `seam_evaluate` returned SEAM_CUTBACK: the new/old step the plugin suggests,
/// in (0, 1), or 0 when it leaves the choice to the host.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_cutback_factor(
    embedding: *const SeamEmbedding,
    out_factor: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let factor = e.cutback.ok_or_else(|| {
            Failure(
                SeamStatus::Order,
                "the last evaluation asked for no cutback\n  help: call this after seam_evaluate returned SEAM_CUTBACK".into(),
            )
        })?;
        unsafe { out(out_factor, factor, "out_factor") }
    })
}

fn evaluated(e: &SeamEmbedding) -> Result<&Evaluated, Failure> {
    e.evaluated.as_ref().ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "nothing evaluated\n  help: call seam_evaluate first (after seam_search)".into(),
        )
    })
}

unsafe fn pairs(
    n: *mut usize,
    dofs: *mut *const i64,
    values: *mut *const f64,
    d: &[i64],
    v: &[f64],
) -> Result<(), Failure> {
    unsafe {
        out(n, d.len(), "out_n")?;
        out(dofs, d.as_ptr(), "out_dofs")?;
        out(values, v.as_ptr(), "out_values")
    }
}

/// Residual entries `(dofs[k], values[k])` of the last evaluation; dofs may repeat.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_residual(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let ev = evaluated(e)?;
        unsafe {
            pairs(
                out_n,
                out_dofs,
                out_values,
                &ev.residual_dofs,
                &ev.residual_values,
            )
        }
    })
}

/// Right-hand-side entries of linear models (offset terms) of the last evaluation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_load(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let ev = evaluated(e)?;
        unsafe { pairs(out_n, out_dofs, out_values, &ev.load_dofs, &ev.load_values) }
    })
}

/// Jacobian triplets `(rows[k], cols[k], values[k])`; pairs may repeat (sum them).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_jacobian(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_rows: *mut *const i64,
    out_cols: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let ev = evaluated(e)?;
        unsafe {
            out(out_n, ev.rows.len(), "out_n")?;
            out(out_rows, ev.rows.as_ptr(), "out_rows")?;
            out(out_cols, ev.cols.as_ptr(), "out_cols")?;
            out(out_values, ev.values.as_ptr(), "out_values")
        }
    })
}

/// Heat (W) leaving side A and side B of interaction `index` at the last evaluation.
/// For a mortar tie use `seam_tie_heat` or `seam_dual_tie_heat`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_heat(
    embedding: *const SeamEmbedding,
    index: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let ev = evaluated(e)?;
        let (a, b) = match ev.heat.get(index) {
            Some(Some(h)) => *h,
            Some(None) => {
                return Err(bad(
                    format!("interaction {index} is a mortar tie"),
                    "read its heat with seam_tie_heat or seam_dual_tie_heat",
                ));
            }
            None => {
                return Err(bad(
                    format!(
                        "interaction {index} does not exist ({} in all)",
                        ev.heat.len()
                    ),
                    "indices are 0-based, in the order interactions were added",
                ));
            }
        };
        unsafe {
            out(out_side_a, a, "out_side_a")?;
            out(out_side_b, b, "out_side_b")
        }
    })
}

/// Compute the rows of every mortar tie (after `seam_search`) and return the
/// condensed rows of the dual ones:
/// `u[dofs[r]] = constants[r] + Σ_{k in offsets[r]..offsets[r+1]} coefficients[k] u[cols[k]]`.
/// `offsets` has `n_rows + 1` entries. Ties with standard multipliers add no condensed
/// rows; read their `C u = g` with `seam_tie_rows`.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_constraints(
    embedding: *mut SeamEmbedding,
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
        let mut r = Rows {
            offsets: vec![0],
            ..Rows::default()
        };
        for c in ties.iter().flat_map(|t| &t.condensed) {
            r.dofs.push(as_i64(c.dof));
            r.constants.push(c.constant);
            for &(j, v) in &c.terms {
                r.cols.push(as_i64(j));
                r.coefficients.push(v);
            }
            r.offsets.push(r.cols.len());
        }
        r.ties = ties
            .into_iter()
            .map(|t| {
                let arrays = TieArrays::from(&t);
                (t, arrays)
            })
            .collect();
        let r = e.rows.insert(r);
        unsafe {
            out(out_n_rows, r.dofs.len(), "out_n_rows")?;
            out(out_dofs, r.dofs.as_ptr(), "out_dofs")?;
            out(out_constants, r.constants.as_ptr(), "out_constants")?;
            out(out_offsets, r.offsets.as_ptr(), "out_offsets")?;
            out(out_cols, r.cols.as_ptr(), "out_cols")?;
            out(
                out_coefficients,
                r.coefficients.as_ptr(),
                "out_coefficients",
            )
        }
    })
}

fn tie<'a>(
    e: *const SeamEmbedding,
    index: usize,
) -> Result<&'a (TieConstraints, TieArrays), Failure> {
    // SAFETY: a non-null handle came from this library (module Safety).
    let e = unsafe { e.as_ref() }.ok_or_else(|| null("embedding"))?;
    let rows = e.rows.as_ref().ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "no constraints yet\n  help: call seam_constraints first (after seam_search)".into(),
        )
    })?;
    rows.ties.get(index).ok_or_else(|| {
        bad(
            format!("tie {index} does not exist ({} in all)", rows.ties.len()),
            "ties are numbered from 0 in interaction order",
        )
    })
}

/// Number of mortar ties (after `seam_constraints`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_tie_count(
    embedding: *const SeamEmbedding,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let n = e.rows.as_ref().map_or(0, |r| r.ties.len());
        unsafe { out(out_count, n, "out_count") }
    })
}

/// The rows `C u = g` of tie `index`: `n_multipliers` multipliers, the host dof of
/// each one's side-A node, `rhs` (g, one per multiplier), and `n_entries` entries
/// `C[multipliers[k]][dofs[k]] = values[k]`. For hosts that carry multipliers.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_tie_rows(
    embedding: *const SeamEmbedding,
    index: usize,
    out_n_multipliers: *mut usize,
    out_multiplier_dofs: *mut *const i64,
    out_rhs: *mut *const f64,
    out_n_entries: *mut usize,
    out_multipliers: *mut *const i64,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        let (t, a) = tie(embedding, index)?;
        unsafe {
            out(
                out_n_multipliers,
                a.multiplier_dofs.len(),
                "out_n_multipliers",
            )?;
            out(
                out_multiplier_dofs,
                a.multiplier_dofs.as_ptr(),
                "out_multiplier_dofs",
            )?;
            out(out_rhs, t.rhs.as_ptr(), "out_rhs")?;
            out(out_n_entries, a.values.len(), "out_n_entries")?;
            out(out_multipliers, a.multipliers.as_ptr(), "out_multipliers")?;
            out(out_dofs, a.dofs.as_ptr(), "out_dofs")?;
            out(out_values, a.values.as_ptr(), "out_values")
        }
    })
}

/// Heat through tie `index` for the host's multipliers `lambda` (one per multiplier).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_tie_heat(
    embedding: *const SeamEmbedding,
    index: usize,
    lambda: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let (t, _) = tie(embedding, index)?;
        let lambda = unsafe { slice(lambda, n, "lambda") }?;
        let heat = t.heat(lambda)?;
        unsafe {
            out(out_side_a, heat.side_a, "out_side_a")?;
            out(out_side_b, heat.side_b, "out_side_b")
        }
    })
}

/// Heat through dual tie `index` of a host that condensed it, from its own residual
/// `K u − F` without the tie (`n` entries, by host dof) at its solution.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_dual_tie_heat(
    embedding: *const SeamEmbedding,
    index: usize,
    residual: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let (t, _) = tie(embedding, index)?;
        let r = unsafe { slice(residual, n, "residual") }?;
        let heat = t.heat(&t.dual_multipliers(r)?)?;
        unsafe {
            out(out_side_a, heat.side_a, "out_side_a")?;
            out(out_side_b, heat.side_b, "out_side_b")
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_a_status_and_a_message() {
        let status = guard(|| panic!("boom at point 7"));
        assert_eq!(status, SeamStatus::Internal as c_int);
        let message = unsafe { CStr::from_ptr(seam_last_error()) }.to_string_lossy();
        assert!(
            message.contains("internal error in seam: boom at point 7"),
            "{message}"
        );
        // The next success leaves the message alone; the next failure replaces it.
        assert_eq!(guard(|| Ok(())), 0);
        let status = guard(|| Err(bad("x = 3".into(), "give 2")));
        assert_eq!(status, SeamStatus::Argument as c_int);
        let message = unsafe { CStr::from_ptr(seam_last_error()) }.to_string_lossy();
        assert_eq!(message, "x = 3\n  help: give 2");
    }
}
