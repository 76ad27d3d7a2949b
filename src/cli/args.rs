//! The command line's grammar: every subcommand, flag and its help text.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "seam",
    version,
    about = "Interface enforcement for implicit finite-element codes"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Threads to use (default: every core; `RAYON_NUM_THREADS=n` does the same). The
    /// answers do not depend on it: every sum runs in a fixed order.
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// Report what the library does on stderr: -v its phases, -vv each Newton iteration.
    #[arg(short, long, global = true, action = clap::ArgAction::Count, conflicts_with = "quiet")]
    pub verbose: u8,
    /// Print only errors and the results (no progress, no warnings).
    #[arg(short, long, global = true)]
    pub quiet: bool,
    /// When to colour diagnostics: `auto` colours them on a terminal unless `NO_COLOR`
    /// is set (`CLICOLOR_FORCE=1` colours a pipe too); `always`; `never`.
    #[arg(long, global = true, value_enum, value_name = "WHEN", default_value_t = ColorWhen::Auto)]
    pub color: ColorWhen,
}

/// The choices of `--color`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ColorWhen {
    Auto,
    Always,
    Never,
}

#[derive(Subcommand)]
pub enum Command {
    /// Build the contact surfaces of a deck on a mesh and print them.
    Surfaces {
        /// Contact definition: Sierra syntax (.i or any) or TOML (.toml).
        deck: PathBuf,
        /// Mesh: Exodus II (.e .exo .g .gen) or Gmsh 4.1 (.msh).
        #[arg(long)]
        mesh: PathBuf,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Dead elements, by element number: `3,7,10-20`.
        #[arg(long)]
        dead: Option<String>,
        /// Read the (2-D) mesh as axisymmetric: x the radius, areas per full revolution.
        #[arg(long)]
        axisymmetric: bool,
    },
    /// Build surfaces, pair them by the deck's interactions and periodicity, and report
    /// the coverage of each pair.
    Search {
        deck: PathBuf,
        #[arg(long)]
        mesh: PathBuf,
        /// Print one JSON object instead of a table.
        #[arg(long)]
        json: bool,
        /// Integrate on mortar segments (exact overlap) instead of side-A Gauss points.
        #[arg(long)]
        segments: bool,
        /// Quadrature order (Gauss points per face direction, or segment rule degree), 1 to 20.
        #[arg(long, default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=seam::search::pairing::MAX_ORDER as i64))]
        order: u16,
        /// Read the (2-D) mesh as axisymmetric: x the radius, areas per full revolution.
        #[arg(long)]
        axisymmetric: bool,
    },
    /// Solve a heat-transfer problem with contact (a TOML problem file) and write the
    /// temperature as VTK XML. Exit 1 if Newton does not converge.
    Run {
        /// The problem file (see docs/run.md); the bundled two-block scene when omitted.
        problem: Option<PathBuf>,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
        /// Continue a transient run from this checkpoint (`checkpoint.seam`).
        #[arg(long)]
        restart: Option<PathBuf>,
    },
    /// Load an enforcement plugin, print its descriptor, and probe it on a grid of
    /// states: outputs finite and non-negative, derivatives against finite differences.
    /// Exit 0 when it passes, 3 on any fault.
    CheckPlugin {
        /// The shared library.
        path: PathBuf,
        /// Real Data handed to the plugin, as the deck would (`--real 1.5 2e3`).
        #[arg(long, num_args = 1.., allow_negative_numbers = true)]
        real: Vec<f64>,
        /// Integer Data handed to the plugin (`--integer 1 2 3`).
        #[arg(long, num_args = 1.., allow_negative_numbers = true)]
        integer: Vec<i64>,
        /// Run the plugin in a worker process (`Plugin Isolation = Process`): a crash or
        /// an `exit` in it is a FAILED check (exit 3) instead of the end of seam.
        #[arg(long)]
        isolate: bool,
        /// Print one JSON object (`passed`, the descriptor, counts, failures) instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Serve one plugin on standard input for an isolated host (`Plugin Isolation =
    /// Process`); not for direct use.
    #[command(name = "plugin-worker", hide = true)]
    PluginWorker,
    /// Write a bundled scene (problem file, deck, mesh) into a folder, ready for
    /// `seam run FOLDER/problem.toml`; with no name, list the scenes.
    Example {
        /// The scene: `two_blocks` (the default of `seam run`) or `busbar_joint`.
        name: Option<String>,
        /// The folder to write it into (default: a folder named after the scene). Files
        /// already there are not overwritten: the command stops instead.
        #[arg(long)]
        dir: Option<PathBuf>,
    },
    /// Validate a deck and print every diagnostic: everything `seam run` checks before
    /// it solves (enforcement models made, Lua compiled, plugins loaded). With --mesh its
    /// surfaces, interactions and search too; with --problem the whole problem file.
    Check {
        deck: PathBuf,
        #[arg(long)]
        mesh: Option<PathBuf>,
        /// A problem file (`seam run`'s) to check up to the solve, with its mesh and deck.
        #[arg(long)]
        problem: Option<PathBuf>,
        /// Read the mesh given by --mesh as axisymmetric (a problem file says so itself).
        #[arg(long)]
        axisymmetric: bool,
        /// Print one JSON object (`ok`, counts, `diagnostics`) instead of text.
        #[arg(long)]
        json: bool,
    },
}
