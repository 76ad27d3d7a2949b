//! User enforcement models loaded at run time as shared libraries (plain C ABI v1).
//!
//! Entry points:
//! - [`Plugin::load`] / [`Plugin::load_with`]: `dlopen` the library (once per process,
//!   never unloaded), resolve `seam_plugin_v1`, check the descriptor (ABI major equal,
//!   minor not newer than seam's, struct large enough, required functions present) and
//!   create one instance with the enforcement's `Integer Data` / `Real Data`;
//! - [`Plugin::evaluate`]: evaluate contact points (batch entry if the plugin has one,
//!   else point by point; serialised behind a mutex unless the plugin is `THREAD_SAFE`),
//!   then validate every output. A [`PluginFault`] names the plugin and the point index;
//!   the caller adds the interaction and face;
//! - [`Plugin::load_isolated`] / [`Plugin::load_with_isolation`]: the same, in a worker
//!   process (`Plugin Isolation = Process`): a crash or an `exit` in the plugin is a
//!   [`PluginFault::ProcessDied`] and the host goes on (see [`isolate`]);
//! - [`check_plugin`] / [`check_plugin_with`]: what `seam check-plugin [--isolate]` runs;
//! - [`PluginSpec`]: a plugin to load (library, data, isolation), as the scene makes it
//!   from a deck's `Enforcement for Energy = Plugin Library = "…" Model = …`.
//!
//! Conventions: gap > 0 open; pressure ≥ 0 in compression; a conductance h must be ≥ 0
//! and gives q = h (T_B − T_A) into side A; a plugin with `RETURNS_FLUX` returns q
//! itself. The ABI types and rules are in the `seam-plugin-abi` crate and
//! `plugins/include/seam_plugin.h`; the user guide is `docs/plugins.md`.

mod check;
mod guard;
mod host;
pub mod isolate;
mod spec;

use std::path::PathBuf;

pub use check::{CheckReport, check_plugin, check_plugin_with};
pub use host::{
    ContactPoint, FD_FLOOR_GAP, FD_FLOOR_PRESSURE, FD_FLOOR_TEMPERATURE, Plugin, PluginData,
    PluginInfo, PointResult, StateStore, StepContext,
};
pub use isolate::{serve_worker, set_worker_program, worker_program};
pub use seam_plugin_abi as abi;
pub use spec::PluginSpec;

/// Where a plugin runs (`Plugin Isolation = None | Process` in a deck).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Isolation {
    /// In seam's own process: fastest; a crash in the plugin ends the run (exit 3).
    #[default]
    None,
    /// In a worker process: a crash or an `exit` in the plugin is an ordinary fault.
    Process,
}

/// Why a plugin could not be loaded or set up. Every message names the library path.
#[derive(Debug, thiserror::Error)]
pub enum PluginError {
    #[error("plugin library {} does not exist", path.display())]
    NotFound { path: PathBuf },
    #[error("plugin {} could not be loaded as a shared library: {reason}", path.display())]
    NotLibrary { path: PathBuf, reason: String },
    #[error(
        "plugin {} does not export the entry symbol `{symbol}`: it is not a seam plugin for ABI major {host_major} (build it with seam_plugin.h or the seam-plugin-sdk crate)",
        path.display()
    )]
    NoEntry {
        path: PathBuf,
        symbol: &'static str,
        host_major: u32,
    },
    #[error(
        "plugin {} was built for plugin ABI {plugin_major}.{plugin_minor}, but this seam speaks ABI {host_major}.{host_minor}: the major versions must be equal (rebuild the plugin against this seam's seam_plugin.h / seam-plugin-sdk)",
        path.display()
    )]
    AbiMajor {
        path: PathBuf,
        plugin_major: u32,
        plugin_minor: u32,
        host_major: u32,
        host_minor: u32,
    },
    #[error(
        "plugin {} was built for plugin ABI {plugin_major}.{plugin_minor}, newer than this seam's ABI {host_major}.{host_minor}: update seam, or rebuild the plugin against the older header",
        path.display()
    )]
    AbiMinor {
        path: PathBuf,
        plugin_major: u32,
        plugin_minor: u32,
        host_major: u32,
        host_minor: u32,
    },
    #[error(
        "plugin {}: its descriptor declares struct_size {size} bytes, but ABI {major}.{minor} needs at least {need}",
        path.display()
    )]
    DescriptorTooSmall {
        path: PathBuf,
        size: u32,
        need: usize,
        major: u32,
        minor: u32,
    },
    #[error("plugin {}: `{symbol}` returned a NULL descriptor", path.display())]
    NullDescriptor { path: PathBuf, symbol: &'static str },
    #[error("plugin {}: descriptor field `{field}` is NULL but required", path.display())]
    NullFunction { path: PathBuf, field: &'static str },
    #[error("plugin {}: bad descriptor: {reason}", path.display())]
    BadDescriptor { path: PathBuf, reason: String },
    #[error(
        "plugin {} provides model `{provided}`, but the deck asks for model `{asked}`",
        path.display()
    )]
    ModelMismatch {
        path: PathBuf,
        provided: String,
        asked: String,
    },
    #[error("plugin `{name}` ({}) refused its Integer/Real Data: {message}", path.display())]
    Init {
        path: PathBuf,
        name: String,
        message: String,
    },
    #[error("{0}")]
    Spec(String),
    /// A load error met by the worker of an isolated plugin: the in-process message.
    #[error("{message}")]
    Isolated { message: String },
    #[error(
        "plugin {}: no plugin worker for `Plugin Isolation = Process` ({tried}): set SEAM_PLUGIN_WORKER to the seam executable, or call seam::plugin::set_worker_program",
        path.display()
    )]
    NoWorker { path: PathBuf, tried: String },
    #[error(
        "plugin {}: the plugin worker {} {how}",
        path.display(),
        program.display()
    )]
    Worker {
        path: PathBuf,
        program: PathBuf,
        how: String,
    },
}

/// A fault while evaluating: which plugin (`name (path)`), which point of the call, what.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PluginFault {
    /// The plugin asks for a smaller step (`SEAM_STATUS_CUTBACK`); not an error by itself.
    #[error(
        "plugin {plugin}: point {point}: asks for a smaller time step (factor {factor}): {message}"
    )]
    Cutback {
        plugin: String,
        point: usize,
        /// Suggested new/old step in (0, 1), or 0: the host decides.
        factor: f64,
        message: String,
    },
    #[error("plugin {plugin}: point {point}: the plugin reported an error: {message}")]
    Error {
        plugin: String,
        point: usize,
        message: String,
    },
    #[error("plugin {plugin}: point {point}: {what} is {value}, not a finite number")]
    NotFinite {
        plugin: String,
        point: usize,
        what: &'static str,
        value: f64,
    },
    #[error("plugin {plugin}: point {point}: conductance {value} is negative")]
    Negative {
        plugin: String,
        point: usize,
        value: f64,
    },
    #[error(
        "plugin {plugin}: point {point}: unknown status code {status} (expected 0 OK, 1 ERROR or 2 CUTBACK)"
    )]
    BadStatus {
        plugin: String,
        point: usize,
        status: i32,
    },
    /// The worker process of an isolated plugin died (a crash, an `exit`) or could not be
    /// started again during a call: an ordinary fault, the host goes on.
    #[error(
        "plugin {plugin}: {}in `{entry}`, the isolated plugin process {how}",
        place(points, interaction.as_deref())
    )]
    ProcessDied {
        plugin: String,
        /// The entry point running when it died.
        entry: &'static str,
        /// `side A / side B`, when the call was about points.
        interaction: Option<String>,
        /// The points of the caller's call that were being evaluated.
        points: std::ops::Range<usize>,
        /// `was killed by SIGSEGV (…); a new process serves the next call`.
        how: String,
    },
    /// The caller passed inconsistent arrays (a bug in the caller, reported, not panicked).
    #[error("plugin {plugin}: bad call: {message}")]
    Usage { plugin: String, message: String },
}

impl PluginFault {
    /// The point index of the call, if the fault is at one point.
    pub fn point(&self) -> Option<usize> {
        match self {
            PluginFault::Cutback { point, .. }
            | PluginFault::Error { point, .. }
            | PluginFault::NotFinite { point, .. }
            | PluginFault::Negative { point, .. }
            | PluginFault::BadStatus { point, .. } => Some(*point),
            PluginFault::ProcessDied { points, .. } => (!points.is_empty()).then_some(points.start),
            PluginFault::Usage { .. } => None,
        }
    }

    pub fn is_cutback(&self) -> bool {
        matches!(self, PluginFault::Cutback { .. })
    }
}

/// `point 3 on interaction A / B: `, `points 0–255 …: `, or nothing for a call without
/// points.
fn place(points: &std::ops::Range<usize>, interaction: Option<&str>) -> String {
    let points = match points.len() {
        0 => return String::new(),
        1 => format!("point {}", points.start),
        _ => format!("points {}–{}", points.start, points.end - 1),
    };
    match interaction {
        Some(i) => format!("{points} on interaction {i}: "),
        None => format!("{points}: "),
    }
}
