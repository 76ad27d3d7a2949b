//! `Plugin Isolation = Process`: the plugin runs in a child process, so that a crash or an
//! `exit` inside it is an ordinary [`PluginFault`](super::PluginFault) and the host goes
//! on.
//!
//! Entry points: [`Plugin::load_isolated`](super::Plugin::load_isolated) (the parent's
//! side, through `Worker`); [`serve_worker`] (the child's side, what `seam plugin-worker`
//! runs); [`worker_program`] / [`set_worker_program`] (which executable is the worker).
//!
//! The child is a *plugin worker*: the `seam` executable started as `seam plugin-worker`.
//! It loads the library and the instance in process (the checks of
//! [`Plugin::load_with`](super::Plugin::load_with), its errors word for word), then serves requests on its standard
//! input, a Unix socket shared with the parent: evaluate a call's points (the
//! `SeamPointIn` / `SeamPointOut` data, pointers' contents sent with them and re-created
//! in the child), or run the conformance kit. The parent builds the points, validates the
//! outputs and forms finite differences exactly as in process, so both modes give
//! bit-identical results.
//!
//! Wire format: frames of a `u32` length and a payload, numbers little-endian, `f64` as
//! their bits. The parent opens with [`MAGIC`] and a load request; the child greets with
//! [`MAGIC`] (so a program that is not a worker is told from a worker that died while
//! loading), then answers with the plugin's descriptor or the load error. The child
//! speaks on a duplicate of its standard input and sends its standard output to standard
//! error, so a plugin's `printf` cannot corrupt the channel. The parent writes with
//! `MSG_NOSIGNAL`: a dead child is an error, not a `SIGPIPE` for an embedding host.
//!
//! A child that dies (signal or exit) during a request is reaped and described (`was
//! killed by SIGSEGV (invalid memory access)`, `ended with exit status 0`). It is started
//! again on the next call, up to [`MAX_DEATHS`] deaths (failed starts included); after
//! that the plugin is dead and every call faults at once. No timeout: a plugin that
//! hangs, hangs the call.

mod child;
mod parent;
mod wire;

pub use child::serve_worker;
pub(super) use parent::Worker;

use std::path::PathBuf;
use std::sync::Mutex;

/// Opens both directions of the conversation; the digits are the protocol's version.
pub const MAGIC: &[u8; 8] = b"SEAMPW01";

/// Deaths of a plugin's worker after which it is not started again.
pub const MAX_DEATHS: usize = 100;

/// The environment variable naming the worker executable (overrides everything else).
pub const WORKER_ENV: &str = "SEAM_PLUGIN_WORKER";

/// The hidden subcommand of `seam` that serves a plugin.
pub const WORKER_SUBCOMMAND: &str = "plugin-worker";

/// The phrase every fault of a dead worker carries (the binary maps it to exit code 3).
pub const PROCESS_DEATH: &str = "isolated plugin process";

const LOAD: u8 = 1;
const EVALUATE: u8 = 2;
const CONFORMANCE: u8 = 3;
const OK: u8 = 0;
const ERR: u8 = 1;

/// Frames larger than this are a protocol error, not an allocation.
const MAX_FRAME: usize = 1 << 30;

static WORKER_PROGRAM: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Use `program` as the plugin worker (an executable that runs [`serve_worker`] when given
/// the argument `plugin-worker`, such as `seam`). For hosts that are not the `seam`
/// binary: tests (`env!("CARGO_BIN_EXE_seam")`), embedding programs. The environment
/// variable `SEAM_PLUGIN_WORKER` still takes precedence.
pub fn set_worker_program(program: impl Into<PathBuf>) {
    *WORKER_PROGRAM.lock().unwrap_or_else(|e| e.into_inner()) = Some(program.into());
}

/// The worker executable: `$SEAM_PLUGIN_WORKER`; else the one set with
/// [`set_worker_program`]; else this executable if it is `seam`; else a `seam` next to
/// this executable or one directory up (where cargo puts it for tests and benchmarks).
/// The error says what was tried.
pub fn worker_program() -> Result<PathBuf, String> {
    let mut tried = Vec::new();
    if let Some(p) = std::env::var_os(WORKER_ENV).filter(|p| !p.is_empty()) {
        let p = PathBuf::from(p);
        if p.is_file() {
            return Ok(p);
        }
        return Err(format!("{WORKER_ENV}={}: no such file", p.display()));
    }
    if let Some(p) = WORKER_PROGRAM
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
    {
        if p.is_file() {
            return Ok(p);
        }
        tried.push(format!("{} (set by the host; no such file)", p.display()));
    }
    let exe_name = format!("seam{}", std::env::consts::EXE_SUFFIX);
    if let Ok(exe) = std::env::current_exe() {
        if exe.file_name().is_some_and(|n| n == exe_name.as_str()) {
            return Ok(exe);
        }
        for dir in exe.ancestors().skip(1).take(2) {
            let candidate = dir.join(&exe_name);
            if candidate.is_file() {
                return Ok(candidate);
            }
            tried.push(candidate.display().to_string());
        }
    }
    Err(format!("tried {}", tried.join(", ")))
}
