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
    /// A flux interaction's search paired no point (`seam_allow_unpaired` lets it stand).
    NothingPaired = 10,
    /// On MPI: a collective call failed on another rank (its own error says why).
    OtherRank = 11,
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
            EmbedError::NothingPaired { .. } => SeamStatus::NothingPaired,
            EmbedError::OtherRank { .. } => SeamStatus::OtherRank,

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
    /// Buffers of the field and coverage queries (valid until the next such query).
    buffers: fields::Buffers,
    evaluated: Option<Evaluated>,
    rows: Option<Rows>,
    /// The step factor a plugin suggested when the last evaluation asked for a cutback.
    cutback: Option<f64>,
}

impl SeamEmbedding {
    /// What the terms depend on changed (time, switches, pressures): the last
    /// evaluation's values no longer hold; its pattern does.
    fn values_changed(&mut self) {
        self.evaluated = None;
        self.buffers.csr_current = false;
    }

    /// The interactions or the geometry changed: the last evaluation and tie rows no
    /// longer hold.
    fn forget_results(&mut self) {
        self.evaluated = None;
        self.rows = None;
        self.buffers.csr_current = false;
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

mod builder;
mod fields;
mod interactions;
#[cfg(feature = "mpi")]
mod rank;
mod state;
mod terms;
mod ties;

pub use builder::*;
pub use fields::{
    SeamConductanceFn, SeamCoverage, SeamFaceValues, SeamPointState, SeamPointValues, *,
};
pub use interactions::*;
#[cfg(feature = "mpi")]
pub use rank::*;
pub use terms::*;
pub use ties::*;

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
