//! The command line's grammar: every subcommand, flag and its help text.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

/// What `seam --help` ends with: the exit codes and the environment.
const AFTER_HELP: &str = "\
Exit codes:
  0  ok (a run converged, a check passed)
  1  ran but failed: Newton did not converge or a solve failed (the last iterate is written)
  2  bad input or usage: diagnostics on stderr (or one JSON object on stdout with --json)
  3  plugin fault: a plugin returned an error status or a value that is not finite, or
     crashed or exited inside a call (during `seam run` and `seam check-plugin`)

Environment:
  RAYON_NUM_THREADS  threads when --threads is not given (default: every core)
  NO_COLOR           set and not empty: no colour in diagnostics (see --color)
  CLICOLOR_FORCE     set to 1: colour diagnostics on a pipe too, unless NO_COLOR is set

Each command's --help lists its own options; docs/run.md describes the problem file.";

#[derive(Parser)]
#[command(
    name = "seam",
    version,
    about = "Interface enforcement for implicit finite-element codes",
    long_about = "Interface enforcement for implicit finite-element codes: contact surfaces \
from a Sierra-syntax or TOML deck, search and pairing across non-matching meshes, and \
tied or gap-conductance heat transfer through them. Units are SI throughout (m, K, s, W).",
    after_help = AFTER_HELP
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Threads for search and assembly, at least 1 [default: every core, or
    /// `RAYON_NUM_THREADS` when set]. The answers do not depend on it: every sum runs in a
    /// fixed order.
    #[arg(long, global = true, value_name = "N", value_parser = clap::value_parser!(u16).range(1..))]
    pub threads: Option<u16>,
    /// Report what the library does on stderr: -v its phases, -vv each Newton iteration
    /// [default: warnings only].
    #[arg(short, long, global = true, action = clap::ArgAction::Count, conflicts_with = "quiet")]
    pub verbose: u8,
    /// Print only errors and the results: no progress, no warnings.
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
    ///
    /// A table of each surface (faces, nodes, area in m², or m² per revolution with
    /// --axisymmetric) and where its faces came from; warnings on stderr. Exit 0, or 2 on
    /// bad input.
    Surfaces {
        /// Contact definition: Sierra syntax (`.i` or any other name) or TOML (`.toml`).
        deck: PathBuf,
        /// Mesh: Exodus II (`.e .exo .g .gen`) or Gmsh 4.1 (`.msh`).
        #[arg(long, value_name = "FILE")]
        mesh: PathBuf,
        /// Print one JSON object (`surfaces`, `warnings`) instead of a table.
        #[arg(long)]
        json: bool,
        /// Dead elements, by element number: `3,7,10-20` [default: none]. Their faces
        /// next to live elements become exposed surface.
        #[arg(long, value_name = "LIST")]
        dead: Option<String>,
        /// Read the (2-D) mesh as axisymmetric: x the radius, areas per full revolution.
        #[arg(long)]
        axisymmetric: bool,
    },
    /// Build surfaces, pair them by the deck's interactions and periodicity, and report
    /// the coverage of each pair.
    ///
    /// Per interaction: integration points, matched, unmatched and rejected (by distance
    /// or angle), overlap and side-A areas (m²) and the gap range (m). Exit 0, or 2 on
    /// bad input.
    Search {
        /// Contact definition: Sierra syntax or TOML (`.toml`).
        deck: PathBuf,
        /// Mesh: Exodus II or Gmsh 4.1.
        #[arg(long, value_name = "FILE")]
        mesh: PathBuf,
        /// Print one JSON object (`interactions`, `timing`, `warnings`) instead of a table.
        #[arg(long)]
        json: bool,
        /// Integrate on mortar segments (exact overlap) instead of side-A Gauss points.
        #[arg(long)]
        segments: bool,
        /// Quadrature order, 1 to 20: Gauss points per face direction, or the segment
        /// rule's degree with --segments.
        #[arg(long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u16).range(1..=seam::search::pairing::MAX_ORDER as i64))]
        order: u16,
        /// Read the (2-D) mesh as axisymmetric: x the radius, areas per full revolution.
        #[arg(long)]
        axisymmetric: bool,
        /// Also write every searched point to FILE (csv: interaction, point, side-A face
        /// or node, status, side-B face, ξ_A, ξ_B, gap, weight, x, y, z), in the order
        /// of the search; under `mpirun`, the distributed search's points, gathered.
        #[arg(long, value_name = "FILE")]
        points: Option<std::path::PathBuf>,
    },
    /// Solve a heat-transfer problem with contact (a TOML problem file) and write the
    /// results (VTK XML, Exodus II, csv histories, plots).
    ///
    /// Exit 0 when it converged; 1 when Newton did not converge or the solve failed (the
    /// last iterate is still written); 2 on bad input; 3 on a plugin fault (a plugin
    /// that returns an error status or a value that is not finite, or crashes).
    Run {
        /// The problem file (see docs/run.md) [default: the bundled two-block scene,
        /// written to a temporary folder when no source tree is at hand].
        problem: Option<PathBuf>,
        /// Print one JSON object (the run's summary, or `ok: false` and its diagnostics)
        /// on stdout instead of text.
        #[arg(long)]
        json: bool,
        /// Continue a transient run from this checkpoint (`checkpoint.seam`, written in
        /// the output folder) [default: start from the initial state].
        #[arg(long, value_name = "FILE")]
        restart: Option<PathBuf>,
    },
    /// Load an enforcement plugin, print its descriptor, and probe it on a grid of
    /// states: outputs finite and non-negative, derivatives against finite differences.
    ///
    /// Exit 0 when it passes, 3 on any fault (the library does not load, an entry point
    /// is missing, a probe fails).
    CheckPlugin {
        /// The plugin's shared library (`.so`, `.dylib`, `.dll`).
        path: PathBuf,
        /// Real Data handed to the plugin, as the deck would (`--real 1.5 2e3`)
        /// [default: none].
        #[arg(long, value_name = "X", num_args = 1.., allow_negative_numbers = true)]
        real: Vec<f64>,
        /// Integer Data handed to the plugin (`--integer 1 2 3`) [default: none].
        #[arg(long, value_name = "N", num_args = 1.., allow_negative_numbers = true)]
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
    ///
    /// Exit 0, or 2 for an unknown scene or a file already in the way.
    Example {
        /// The scene: `two_blocks` (the default of `seam run`) or `busbar_joint`.
        name: Option<String>,
        /// The folder to write it into [default: a folder named after the scene]. Files
        /// already there are not overwritten: the command stops instead.
        #[arg(long, value_name = "DIR")]
        dir: Option<PathBuf>,
    },
    /// Validate a deck and print every diagnostic: everything `seam run` checks before
    /// it solves (enforcement models made, Lua compiled, plugins loaded).
    ///
    /// With --mesh its surfaces, interactions and search too; with --problem the whole
    /// problem file. Exit 0 when nothing is wrong (warnings allowed), 2 otherwise.
    Check {
        /// Contact definition: Sierra syntax or TOML (`.toml`).
        deck: PathBuf,
        /// A mesh to build the deck's surfaces and search on (Exodus II or Gmsh 4.1)
        /// [default: the deck alone].
        #[arg(long, value_name = "FILE")]
        mesh: Option<PathBuf>,
        /// A problem file (`seam run`'s) to check up to the solve, with its mesh and deck.
        #[arg(long, value_name = "FILE")]
        problem: Option<PathBuf>,
        /// Read the mesh given by --mesh as axisymmetric (a problem file says so itself).
        #[arg(long)]
        axisymmetric: bool,
        /// Print one JSON object (`ok`, counts, `diagnostics`) instead of text.
        #[arg(long)]
        json: bool,
    },
}
