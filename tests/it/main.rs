//! The one integration-test binary; each module is one area.

mod bad_cli;
mod bad_decks;
mod cases;
mod cli;
mod conductance;
mod docs;
mod embed;
mod enforce;
mod examples;
mod fem;
mod fuzz_regressions;
mod hard_cases;
mod hard_input;
mod interactions;
mod manual;
mod mesh_io;
mod node_surfaces;
mod output;
mod plugin;
mod preflight;
mod run_fields;
mod search;
mod search_kernels;
mod sources;
mod surfaces;
mod transient;
