//! The one integration-test binary; each module is one area.

mod axisymmetric;
mod bad_cli;
mod bad_decks;
mod cases;
mod cli;
mod cli_conventions;
mod conductance;
mod conductivity_of_t;
mod docs;
mod electric;
mod embed;
mod embed_2d;
mod embed_api;
mod enforce;
mod examples;
mod fem;
mod fortran_plugin;
mod fuzz_regressions;
mod hard_cases;
mod hard_input;
mod interactions;
mod linear_solver;
mod manual;
mod mesh_io;
mod moving;
mod node_surfaces;
mod output;
mod plugin;
mod preflight;
mod run_fields;
mod search;
mod search_kernels;
mod sources;
mod species;
mod surfaces;
mod transient;
mod twod;
mod voltage_ties;

/// Held by the tests that run the turbine sector in this process. Two of them running at
/// once give wrong answers (sector against ring, embedding against `seam run`) in about
/// four runs of six of `cargo test --test it turbine` — already so before issue 12's
/// change (measured at 7e6556a). The cause, some state two concurrent runs of this scene
/// share, is not found yet; until it is, they take turns so the suite checks the
/// numbers and not the race.
pub(crate) static TURBINE_RUNS: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// A scratch folder for one test, under cargo's `target/tmp` and named `NAME-xxxxxx`:
/// removed when the value is dropped — at the end of the test, or while a failing test
/// unwinds — and never shared by two tests that run at once. Keep the value alive for as
/// long as the folder is used (`let dir = scratch(..); .. dir.path() ..`).
pub(crate) fn scratch(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("{name}-"))
        .tempdir_in(env!("CARGO_TARGET_TMPDIR"))
        .unwrap_or_else(|e| panic!("cannot make a scratch folder for {name}: {e}"))
}
