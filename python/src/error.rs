//! seam's errors as Python exceptions: `SeamError` and one subclass per kind, each with
//! the status code a C host gets for the same failure (`SEAM_ERR_*` in include/seam.h).
//! An instance carries `code`, `message` (what and where) and `help` (how to fix it);
//! `str()` is both. `DeckError` adds `diagnostic_codes` (the deck's `E….` codes) and
//! `CutbackError` the plugin's suggested step `factor`.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::PyList;

use seam::embed::EmbedError;

create_exception!(
    seam,
    SeamError,
    PyException,
    "Any failure reported by seam."
);
create_exception!(
    seam,
    MeshError,
    SeamError,
    "The host's mesh arrays are inconsistent or fail seam's element checks."
);
create_exception!(
    seam,
    DeckError,
    SeamError,
    "A contact deck with errors; `diagnostic_codes` lists their codes."
);
create_exception!(
    seam,
    ArgumentError,
    SeamError,
    "An argument out of range, an unknown name, or an array of the wrong shape."
);
create_exception!(
    seam,
    OrderError,
    SeamError,
    "A call out of order, e.g. evaluate() before search()."
);
create_exception!(
    seam,
    EnforcementError,
    SeamError,
    "An enforcement failed at a contact point (a conductance model or callback failed)."
);
create_exception!(seam, InternalError, SeamError, "A bug in seam.");
create_exception!(
    seam,
    PluginError,
    SeamError,
    "A plugin could not be loaded, or failed at a contact point."
);
create_exception!(
    seam,
    CutbackError,
    SeamError,
    "A conductance model or plugin asks for a smaller step; `factor` is its suggestion."
);
create_exception!(
    seam,
    NothingPairedError,
    SeamError,
    "A flux interaction's search paired no point."
);
create_exception!(
    seam,
    OtherRankError,
    SeamError,
    "On MPI: a collective call failed on another rank, whose own error says what and where."
);

/// The exception classes and their codes, as in include/seam.h.
fn classes(py: Python<'_>) -> [(Bound<'_, pyo3::types::PyType>, i32); 10] {
    [
        (py.get_type::<MeshError>(), 2),
        (py.get_type::<DeckError>(), 3),
        (py.get_type::<ArgumentError>(), 4),
        (py.get_type::<OrderError>(), 5),
        (py.get_type::<EnforcementError>(), 6),
        (py.get_type::<InternalError>(), 7),
        (py.get_type::<PluginError>(), 8),
        (py.get_type::<CutbackError>(), 9),
        (py.get_type::<NothingPairedError>(), 10),
        (py.get_type::<OtherRankError>(), 11),
    ]
}

pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let base = py.get_type::<SeamError>();
    base.setattr("code", 0)?;
    m.add("SeamError", base)?;
    for (class, code) in classes(py) {
        class.setattr("code", code)?;
        m.add(class.name()?, class)?;
    }
    Ok(())
}

/// A Python exception of `class` with seam's full message split into `message` and
/// `help` (seam's messages end with a `help:` line).
fn raise<T: pyo3::PyTypeInfo>(py: Python<'_>, text: &str) -> PyErr {
    let err = PyErr::new::<T, _>(text.to_string());
    // The last line's help, if it is one (a deck report keeps its own per diagnostic).
    let (message, help) = match text.trim_end().rsplit_once("\n  help: ") {
        Some((m, h)) if !h.contains('\n') => (m.to_string(), h.to_string()),
        _ => (text.to_string(), String::new()),
    };
    let value = err.value(py);
    // Setting attributes on a fresh exception instance cannot fail short of memory.
    let _ = value.setattr("message", message);
    let _ = value.setattr("help", help);
    err
}

/// An `ArgumentError` made by the bindings themselves (array shapes, names).
pub fn argument(what: impl std::fmt::Display, help: &str) -> PyErr {
    Python::attach(|py| raise::<ArgumentError>(py, &format!("{what}\n  help: {help}")))
}

/// seam's error as the matching exception.
pub fn to_py(e: EmbedError) -> PyErr {
    Python::attach(|py| {
        let text = e.to_string();
        match &e {
            EmbedError::Mesh { .. } | EmbedError::Invalid(_) => raise::<MeshError>(py, &text),
            EmbedError::Deck(rendered) => {
                let err = raise::<DeckError>(py, &text);
                let codes = diagnostic_codes(rendered);
                if let Ok(list) = PyList::new(py, codes) {
                    let _ = err.value(py).setattr("diagnostic_codes", list);
                }
                err
            }
            EmbedError::Order { .. } => raise::<OrderError>(py, &text),
            EmbedError::Enforcement { .. } => raise::<EnforcementError>(py, &text),
            EmbedError::Plugin { .. } => raise::<PluginError>(py, &text),
            EmbedError::Cutback { factor, .. } => {
                let err = raise::<CutbackError>(py, &text);
                let _ = err.value(py).setattr("factor", *factor);
                err
            }
            EmbedError::NothingPaired { .. } => raise::<NothingPairedError>(py, &text),
            EmbedError::OtherRank { .. } => raise::<OtherRankError>(py, &text),
            _ => raise::<ArgumentError>(py, &text),
        }
    })
}

/// The codes of the error diagnostics in a rendered deck report (`error[E0428]: …`
/// lines), in order, each once.
fn diagnostic_codes(rendered: &str) -> Vec<String> {
    let mut codes: Vec<String> = Vec::new();
    for line in rendered.lines() {
        let Some(rest) = line.strip_prefix("error[") else {
            continue;
        };
        if let Some((code, _)) = rest.split_once(']')
            && !codes.iter().any(|c| c == code)
        {
            codes.push(code.to_string());
        }
    }
    codes
}

pub trait OrPy<T> {
    /// seam's error as a Python exception.
    fn py_err(self) -> PyResult<T>;
}

impl<T> OrPy<T> for Result<T, EmbedError> {
    fn py_err(self) -> PyResult<T> {
        self.map_err(to_py)
    }
}
