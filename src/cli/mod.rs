//! The `seam` command line's commands, one module each; what they share is here: the
//! exit codes, `-q`, loading a deck and a mesh, and reporting the diagnostics that stop a
//! command.
//!
//! Exit codes: 0 ok; 1 ran but failed; 2 bad input or usage; 3 plugin fault.

use std::path::Path;
use std::process::ExitCode;

use seam::deck::{self, LoadedDeck};
use seam::diag::{Diagnostic, Diagnostics, SourceMap};
use seam::mesh::{self, Mesh};

pub mod args;
pub mod check;
pub mod run;
pub mod search;
pub mod surfaces;

pub const EXIT_BAD_INPUT: u8 = 2;
/// `-q`: no progress lines and no warnings, only errors and the results.
pub static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
pub const EXIT_PLUGIN_FAULT: u8 = 3;

/// MPI and PETSc for a command started by an MPI launcher (`--features mpi`; nothing
/// otherwise), up while the returned value lives; exit 1 with E0903 when they cannot
/// start.
#[cfg(feature = "mpi")]
pub fn start_mpi() -> Result<Option<seam::parallel::Session>, ExitCode> {
    seam::parallel::start().map_err(|e| {
        eprintln!("error[E0903]: cannot start MPI and PETSc: {e}");
        ExitCode::from(1)
    })
}

/// Load the deck, then the mesh; stop with exit code 2 on the first stage that fails.
pub fn load(
    deck_path: &Path,
    mesh_path: Option<&Path>,
    axisymmetric: bool,
    json: bool,
) -> Result<(LoadedDeck, Option<Mesh>), ExitCode> {
    load_reporting(deck_path, mesh_path, axisymmetric, Some(json))
}

/// [`load`], its errors reported as `report` says: `Some(json)` on stderr or as JSON,
/// `None` not at all (a rank of an MPI run other than 0, whose rank 0 reports them).
pub fn load_reporting(
    deck_path: &Path,
    mesh_path: Option<&Path>,
    axisymmetric: bool,
    report: Option<bool>,
) -> Result<(LoadedDeck, Option<Mesh>), ExitCode> {
    let loaded = deck::load(deck_path);
    let fail = |mut d: Diagnostics, extra: Option<Diagnostic>| {
        d.0.extend(extra);
        if let Some(json) = report {
            report_errors(json, &d, &loaded.sources);
        }
        Err(ExitCode::from(EXIT_BAD_INPUT))
    };
    if loaded.diagnostics.has_errors() {
        return fail(loaded.diagnostics.clone(), None);
    }
    let mesh = match mesh_path {
        None => None,
        Some(p) => match mesh::read(p) {
            Ok(mut m) => {
                if axisymmetric && let Err(e) = m.set_axisymmetric() {
                    let d = Diagnostic::error(
                        e.code(),
                        format!("--axisymmetric, {}: {e}", p.display()),
                    )
                    .help(e.help());
                    return fail(loaded.diagnostics.clone(), Some(d));
                }
                Some(m)
            }
            Err(e) => {
                let d = Diagnostic::error("E0400", e.to_string());
                return fail(loaded.diagnostics.clone(), Some(d));
            }
        },
    };
    Ok((loaded, mesh))
}

/// Fixed-point with six decimals in the everyday range, scientific outside it.
pub fn format_number(x: f64) -> String {
    let x = x + 0.0; // no "-0"
    if x == 0.0 || (1e-3..1e7).contains(&x.abs()) {
        format!("{x:.6}")
    } else {
        format!("{x:.6e}")
    }
}

/// Diagnostics that stop a command: rendered on stderr, or with `--json` one JSON object
/// `{"ok": false, "diagnostics": [{severity, code, message, loc?, help?}, …]}` on stdout.
pub fn report_errors(json: bool, diags: &Diagnostics, sources: &SourceMap) {
    if json {
        let report = serde_json::json!({ "ok": false, "diagnostics": diags.0 });
        println!("{report}");
    } else {
        eprint_diagnostics(diags, sources);
    }
}

/// Diagnostics on stderr, coloured where stderr wants colour: a terminal, unless
/// `NO_COLOR` is set or `--color never` given (`CLICOLOR_FORCE=1` or `--color always`
/// colour a pipe too). The words are the same either way.
pub fn eprint_diagnostics(diags: &Diagnostics, sources: &SourceMap) {
    if !diags.is_empty() {
        anstream::eprint!("{}", diags.render_styled(sources));
    }
}
