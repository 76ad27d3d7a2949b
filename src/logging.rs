//! What the library reports as it works goes through the `log` facade; it never prints.
//! A host installs the logger it likes; [`init_stderr`] is the one the `seam` binary
//! installs for `-v`/`-q`: one line per record on standard error,
//! `seam[LEVEL] target: message`.
//!
//! Levels: `info` for each phase of a run (mesh read, contact scene built, solve done,
//! outputs written), `debug` for each Newton iteration and linear solve.

use log::{Level, LevelFilter, Log, Metadata, Record};

struct Stderr;

impl Log for Stderr {
    fn enabled(&self, metadata: &Metadata<'_>) -> bool {
        metadata.level() <= log::max_level()
    }

    fn log(&self, record: &Record<'_>) {
        if self.enabled(record.metadata()) {
            let level = match record.level() {
                Level::Error => "ERROR",
                Level::Warn => "WARN",
                Level::Info => "INFO",
                Level::Debug => "DEBUG",
                Level::Trace => "TRACE",
            };
            eprintln!("seam[{level}] {}: {}", record.target(), record.args());
        }
    }

    fn flush(&self) {}
}

static STDERR: Stderr = Stderr;

/// Send the library's records up to `level` to standard error. A second call (a logger
/// already installed) only changes the level.
pub fn init_stderr(level: LevelFilter) {
    let _ = log::set_logger(&STDERR);
    log::set_max_level(level);
}
