//! The `seam` command line.
//!
//! Exit codes: 0 ok; 1 ran but failed; 2 bad input or usage; 3 plugin fault.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use serde::Serialize;

use seam::deck::{self, LoadedDeck};
use seam::diag::{Diagnostic, Diagnostics, SourceMap};
use seam::run::RunError;
use seam::scene::{ContactScene, SceneOptions};

use seam::mesh::{self, ElemId, Mesh};
use seam::surface::SurfaceKind;

const EXIT_BAD_INPUT: u8 = 2;
/// `-q`: no progress lines and no warnings, only errors and the results.
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
const EXIT_PLUGIN_FAULT: u8 = 3;

#[derive(Parser)]
#[command(
    name = "seam",
    version,
    about = "Interface enforcement for implicit finite-element codes"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Threads to use (default: every core; `RAYON_NUM_THREADS=n` does the same). The
    /// answers do not depend on it: every sum runs in a fixed order.
    #[arg(long, global = true, value_parser = clap::value_parser!(u16).range(1..))]
    threads: Option<u16>,
    /// Report what the library does on stderr: -v its phases, -vv each Newton iteration.
    #[arg(short, long, global = true, action = clap::ArgAction::Count, conflicts_with = "quiet")]
    verbose: u8,
    /// Print only errors and the results (no progress, no warnings).
    #[arg(short, long, global = true)]
    quiet: bool,
}

#[derive(Subcommand)]
enum Command {
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

fn main() -> ExitCode {
    let cli = Cli::parse();
    seam::logging::init_stderr(match (cli.quiet, cli.verbose) {
        (true, _) => log::LevelFilter::Error,
        (false, 0) => log::LevelFilter::Warn,
        (false, 1) => log::LevelFilter::Info,
        _ => log::LevelFilter::Debug,
    });
    QUIET.store(cli.quiet, std::sync::atomic::Ordering::Relaxed);
    if let Some(n) = cli.threads
        && let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()
    {
        eprintln!("error: --threads {n}: {e}");
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    match cli.command {
        Command::Example { name, dir } => example(name.as_deref(), dir),
        Command::Surfaces {
            deck,
            mesh,
            json,
            dead,
            axisymmetric,
        } => surfaces(&deck, &mesh, json, dead.as_deref(), axisymmetric),
        Command::Search {
            deck,
            mesh,
            json,
            segments,
            order,
            axisymmetric,
        } => search(&deck, &mesh, json, segments, order as usize, axisymmetric),
        Command::Run {
            problem,
            json,
            restart,
        } => run(problem, json, restart),
        Command::CheckPlugin {
            path,
            real,
            integer,
            isolate,
            json,
        } => check_plugin(&path, &real, &integer, isolate, json),
        Command::PluginWorker => ExitCode::from(seam::plugin::serve_worker().clamp(0, 255) as u8),
        Command::Check {
            deck,
            mesh,
            problem,
            axisymmetric,
            json,
        } => check(
            &deck,
            mesh.as_deref(),
            problem.as_deref(),
            axisymmetric,
            json,
        ),
    }
}

/// Load the deck, then the mesh; stop with exit code 2 on the first stage that fails.
fn load(
    deck_path: &Path,
    mesh_path: Option<&Path>,
    axisymmetric: bool,
    json: bool,
) -> Result<(LoadedDeck, Option<Mesh>), ExitCode> {
    let loaded = deck::load(deck_path);
    let fail = |mut d: Diagnostics, extra: Option<Diagnostic>| {
        d.0.extend(extra);
        report_errors(json, &d, &loaded.sources);
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

#[derive(Serialize)]
struct SurfaceRow {
    name: String,
    kind: SurfaceKind,
    faces: usize,
    nodes: usize,
    area: f64,
    definition: Option<String>,
    parent: Option<String>,
    origins: Vec<Origin>,
}

#[derive(Serialize)]
struct Origin {
    source: String,
    count: usize,
}

#[derive(Serialize)]
struct Warning {
    code: &'static str,
    message: String,
}

#[derive(Serialize)]
struct SurfacesReport {
    surfaces: Vec<SurfaceRow>,
    warnings: Vec<Warning>,
}

fn surfaces(
    deck_path: &Path,
    mesh_path: &Path,
    json: bool,
    dead: Option<&str>,
    axisymmetric: bool,
) -> ExitCode {
    let (loaded, mesh) = match load(deck_path, Some(mesh_path), axisymmetric, json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let mesh = mesh.expect("a mesh path was given");
    let dead = match dead.map(|d| parse_dead(d, &mesh)).transpose() {
        Ok(d) => d.unwrap_or_default(),
        Err(e) => {
            eprintln!("error[E0002]: --dead {e}");
            return ExitCode::from(EXIT_BAD_INPUT);
        }
    };
    let mut diags = loaded.diagnostics.clone();
    let mut rows = Vec::new();
    for (definition, set) in ContactScene::surfaces(&mesh, &loaded, &dead) {
        diags.extend(set.diagnostics);
        for s in set.surfaces {
            rows.push(SurfaceRow {
                area: s.area(&mesh),
                faces: s.faces.len(),
                nodes: s.nodes.len(),
                kind: s.kind,
                definition: definition.clone(),
                parent: s.parent,
                origins: s
                    .origins
                    .into_iter()
                    .map(|(source, count)| Origin { source, count })
                    .collect(),
                name: s.name,
            });
        }
    }
    if diags.has_errors() {
        eprint!("{}", diags.render(&loaded.sources));
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    if json {
        let report = SurfacesReport {
            surfaces: rows,
            warnings: diags
                .warnings()
                .map(|d| Warning {
                    code: d.code,
                    message: d.message.clone(),
                })
                .collect(),
        };
        println!(
            "{}",
            serde_json::to_string(&report).expect("plain data serialises")
        );
    } else {
        print_table(&rows);
        use std::io::Write as _;
        let _ = std::io::stdout().flush();
        eprint!("{}", diags.render(&loaded.sources));
    }
    ExitCode::SUCCESS
}

fn print_table(rows: &[SurfaceRow]) {
    let width = rows.iter().map(|r| r.name.len()).max().unwrap_or(7).max(7);
    println!(
        "{:<width$}  {:<5}  {:>9}  {:>9}  {:>13}  from",
        "surface", "kind", "faces", "nodes", "area"
    );
    for r in rows {
        let kind = match r.kind {
            SurfaceKind::Faces => "faces",
            SurfaceKind::Nodes => "nodes",
        };
        let from = r
            .origins
            .iter()
            .map(|o| format!("{} ({})", o.source, o.count))
            .collect::<Vec<_>>()
            .join(", ");
        println!(
            "{:<width$}  {:<5}  {:>9}  {:>9}  {:>13}  {}",
            r.name,
            kind,
            r.faces,
            r.nodes,
            format_number(r.area),
            from
        );
    }
}

#[derive(Serialize)]
struct SearchReport {
    interactions: Vec<seam::search::scene::PairingSummary>,
    timing: seam::search::scene::Timing,
    warnings: Vec<Warning>,
}

fn search(
    deck_path: &Path,
    mesh_path: &Path,
    json: bool,
    segments: bool,
    order: usize,
    axisymmetric: bool,
) -> ExitCode {
    use seam::scene::OutputRule;
    use seam::search::pairing::Integration;
    let (loaded, mesh) = match load(deck_path, Some(mesh_path), axisymmetric, json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let mesh = mesh.expect("a mesh path was given");
    let deck_dir = deck_path.parent().unwrap_or(Path::new("."));
    let integration = if segments {
        Integration::Segments { order }
    } else {
        Integration::Quadrature { order }
    };
    let mut diags = loaded.diagnostics.clone();
    let searched = ContactScene::search(
        &mesh,
        &loaded,
        deck_dir,
        &SceneOptions {
            integration,
            fields: None,
            phase: None,
            search_only: true,
        },
        &mut diags,
    );
    let mut summaries = Vec::new();
    let mut timing = seam::search::scene::Timing::default();
    let mut details = Vec::new();
    let mut rule = OutputRule::Summary;
    for s in &searched {
        timing.build_s += s.timing.build_s;
        timing.search_s += s.timing.search_s;
        rule = s.view.rule;
        for p in &s.pairings {
            summaries.push(p.summary(s.view.visualize));
            if matches!(rule, OutputRule::Verbose | OutputRule::MoreVerbose) {
                details.push(point_details(p, rule == OutputRule::MoreVerbose));
            }
        }
    }
    if diags.has_errors() {
        eprint!("{}", diags.render(&loaded.sources));
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    if json {
        let report = SearchReport {
            interactions: summaries,
            timing,
            warnings: diags
                .warnings()
                .map(|d| Warning {
                    code: d.code,
                    message: d.message.clone(),
                })
                .collect(),
        };
        println!(
            "{}",
            serde_json::to_string(&report).expect("plain data serialises")
        );
        return ExitCode::SUCCESS;
    }
    if rule != OutputRule::None {
        print_search_table(&summaries);
        println!(
            "search: build {:.3} s, search {:.3} s",
            timing.build_s, timing.search_s
        );
        for d in details {
            print!("{d}");
        }
    }
    use std::io::Write as _;
    let _ = std::io::stdout().flush();
    eprint!("{}", diags.render(&loaded.sources));
    ExitCode::SUCCESS
}

fn print_search_table(rows: &[seam::search::scene::PairingSummary]) {
    let width = rows
        .iter()
        .map(|r| r.side_a.len() + r.side_b.len() + 3)
        .max()
        .unwrap_or(11)
        .max(11);
    println!(
        "{:<width$}  {:>8}  {:>8}  {:>9}  {:>8}  {:>8}  {:>13}  {:>13}  {:>11}  {:>11}",
        "interaction",
        "points",
        "matched",
        "unmatched",
        "rej.dist",
        "rej.angle",
        "overlap area",
        "side-A area",
        "gap min",
        "gap max"
    );
    for r in rows {
        let name = format!(
            "{} / {}{}",
            r.side_a,
            r.side_b,
            if r.periodic { " (periodic)" } else { "" }
        );
        let gap = |g: Option<f64>| g.map_or("-".to_string(), |g| format!("{g:.3e}"));
        println!(
            "{:<width$}  {:>8}  {:>8}  {:>9}  {:>8}  {:>8}  {:>13}  {:>13}  {:>11}  {:>11}",
            name,
            r.stats.points,
            r.stats.matched,
            r.stats.unmatched,
            r.stats.rejected_distance,
            r.stats.rejected_angle,
            format_number(r.stats.overlap_area),
            format_number(r.stats.side_a_area),
            gap(r.stats.gap_min),
            gap(r.stats.gap_max)
        );
    }
}

/// The points that did not pair (verbose: the first 10 per interaction; more verbose:
/// all), with where they are and why.
fn point_details(p: &seam::search::scene::Pairing, all: bool) -> String {
    use seam::search::pairing::PointStatus;
    use std::fmt::Write as _;
    let mut out = String::new();
    let bad: Vec<_> = p
        .result
        .points
        .iter()
        .filter(|q| q.status != PointStatus::Matched)
        .collect();
    if bad.is_empty() {
        return out;
    }
    let _ = writeln!(
        out,
        "{} / {}: {} point(s) not paired",
        p.side_a,
        p.side_b,
        bad.len()
    );
    let shown = if all { bad.len() } else { bad.len().min(10) };
    for q in &bad[..shown] {
        let _ = writeln!(
            out,
            "  {:?} at ({:.6}, {:.6}, {:.6})",
            q.status, q.x[0], q.x[1], q.x[2]
        );
    }
    if shown < bad.len() {
        let _ = writeln!(
            out,
            "  … {} more (Output Rule = more verbose lists all)",
            bad.len() - shown
        );
    }
    out
}

/// Fixed-point with six decimals in the everyday range, scientific outside it.
fn format_number(x: f64) -> String {
    let x = x + 0.0; // no "-0"
    if x == 0.0 || (1e-3..1e7).contains(&x.abs()) {
        format!("{x:.6}")
    } else {
        format!("{x:.6e}")
    }
}

/// The scene `seam run` solves when given no problem file.
const DEFAULT_SCENE: &str = "examples/two_blocks/problem.toml";

fn run(path: Option<PathBuf>, json: bool, restart: Option<PathBuf>) -> ExitCode {
    let path = match path {
        Some(p) => p,
        None => {
            // The bundled scene, in the working directory's or the build's source tree,
            // else written out of the binary into a folder of the system's temporary one.
            let here = Path::new(env!("CARGO_MANIFEST_DIR")).join(DEFAULT_SCENE);
            let p = if Path::new(DEFAULT_SCENE).exists() {
                PathBuf::from(DEFAULT_SCENE)
            } else if here.exists() {
                here
            } else {
                let dir = std::env::temp_dir().join(format!(
                    "seam-{}-{}",
                    seam::run::bundled::DEFAULT,
                    std::process::id()
                ));
                match seam::run::bundled::write(seam::run::bundled::DEFAULT, &dir) {
                    Ok(p) => p,
                    Err(e) => {
                        eprintln!("error: {e}");
                        return ExitCode::from(EXIT_BAD_INPUT);
                    }
                }
            };
            if !json {
                eprintln!(
                    "seam run: no problem file given; solving the bundled scene {}",
                    p.display()
                );
            }
            p
        }
    };
    let path = path.as_path();
    let (progress, phase) = progress_printer(json);
    let options = seam::run::RunOptions {
        restart,
        progress: Some(progress),
        phase: Some(phase),
    };
    let result = seam::run::run_with(path, &options);
    {
        use std::io::IsTerminal as _;
        if std::io::stderr().is_terminal() {
            eprint!("\r\x1b[K"); // clear the progress line
        }
    }
    match result {
        Ok(r) => {
            let s = &r.summary;
            if json {
                println!(
                    "{}",
                    serde_json::to_string(s).expect("plain data serialises")
                );
            } else {
                println!(
                    "{} dofs, {} Newton iteration(s), {}",
                    s.dofs,
                    s.newton_iterations,
                    if s.converged {
                        "converged"
                    } else {
                        "NOT converged"
                    }
                );
                let ls = &s.linear_solver;
                let cg = match ls.iterations_per_solve.len() {
                    0 => String::new(),
                    1 => format!(", {} CG iterations", ls.iterations),
                    k if k <= 6 => format!(
                        ", {} CG iterations ({})",
                        ls.iterations,
                        ls.iterations_per_solve
                            .iter()
                            .map(usize::to_string)
                            .collect::<Vec<_>>()
                            .join(" + ")
                    ),
                    // Many solves (time steps): the range per solve, not every count.
                    k => format!(
                        ", {} CG iterations ({}–{} per solve over {k} solves)",
                        ls.iterations,
                        ls.iterations_per_solve.iter().min().unwrap_or(&0),
                        ls.iterations_per_solve.iter().max().unwrap_or(&0)
                    ),
                };
                println!("  linear solver: {} ({}){cg}", ls.name, ls.reason);
                if s.axisymmetric {
                    println!("  axisymmetric: heats are per full revolution (W)");
                }
                for i in &s.interactions {
                    println!(
                        "  {} / {} ({}): heat out of A {:.6e}, out of B {:.6e}, imbalance {:.3e}",
                        i.side_a, i.side_b, i.model, i.heat_side_a, i.heat_side_b, i.imbalance
                    );
                }
                for e in &s.electrical_contacts {
                    println!(
                        "  {} / {} (voltage): current A → B {:.6e} A, contact Joule heat {:.6e} W",
                        e.side_a, e.side_b, e.current, e.joule_heat
                    );
                }
                if let Some(t) = &s.transient {
                    println!(
                        "  {} time step(s) to t = {} ({} rejected and retried)",
                        t.steps, t.end_time, t.rejected_steps
                    );
                }
                if let Some(o) = &s.output {
                    println!("  wrote {}", o.display());
                }
                println!(
                    "  time: mesh {:.3} s, surfaces {:.3} s, search {:.3} s, assembly {:.3} s, factor {:.3} s, solve {:.3} s, total {:.3} s",
                    s.timing.mesh_s,
                    s.timing.surfaces_s,
                    s.timing.search_s,
                    s.timing.assembly_s,
                    s.timing.factor_s,
                    s.timing.solve_s,
                    s.timing.total_s
                );
                if let Some(m) = s.peak_memory_mib {
                    println!("  peak memory {m:.0} MiB");
                }
            }
            use std::io::Write as _;
            let _ = std::io::stdout().flush();
            if !QUIET.load(std::sync::atomic::Ordering::Relaxed) {
                eprint!("{}", r.warnings.render(&r.sources));
            }
            if let Some(d) = &s.diagnosis {
                eprintln!("error[E0800]: {d}");
                if let Some(o) = &s.output {
                    eprintln!(
                        "  = note: the last iterate is written to {}, marked by the file {}",
                        o.display(),
                        seam::run::NOT_CONVERGED
                    );
                }
            }
            if s.converged {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Err(seam::run::RunError::Input(d, sources)) => {
            report_errors(json, &d, &sources);
            ExitCode::from(EXIT_BAD_INPUT)
        }
        Err(seam::run::RunError::Solve(e)) => {
            let mut d = Diagnostics::default();
            d.push(Diagnostic::error("E0800", e.clone()));
            report_errors(json, &d, &SourceMap::default());
            // A plugin whose worker process died stopped the run: a plugin fault.
            if e.contains(seam::plugin::isolate::PROCESS_DEATH)
                || e.contains(seam::run::PLUGIN_FAULT)
            {
                ExitCode::from(EXIT_PLUGIN_FAULT)
            } else {
                ExitCode::from(1)
            }
        }
    }
}

/// A run's step progress and the phase callback for `RunOptions`.
type Progress = (
    Box<dyn Fn(&seam::heat::transient::StepReport)>,
    Box<dyn Fn(&str)>,
);

/// Progress of a run on stderr: the phase and the steps redrawn in place on a terminal;
/// in logs a line per phase from 2 s into the run and a step line at most every 5 s (nothing with
/// `--json` off a terminal). Every line carries the time since the run started.
fn progress_printer(json: bool) -> Progress {
    let quiet = QUIET.load(std::sync::atomic::Ordering::Relaxed);
    let json = json || quiet;
    use std::io::IsTerminal as _;
    let terminal = std::io::stderr().is_terminal() && !quiet;
    let start = std::time::Instant::now();
    let last = std::cell::Cell::new(start);
    let phase = move |what: &str| {
        let at = start.elapsed().as_secs_f64();
        if terminal {
            eprint!("\r\x1b[K  [{at:7.1} s] {what} …");
        } else if !json && at >= 2.0 {
            // Logs: quiet for short runs, a line per phase once the run takes a while.
            eprintln!("  [{at:7.1} s] {what}");
        }
    };
    let steps = move |r: &seam::heat::transient::StepReport| {
        if r.dt == 0.0 {
            return; // a steady solve: one step
        }
        let now = std::time::Instant::now();
        let at = now.duration_since(start).as_secs_f64();
        if terminal {
            if now.duration_since(last.get()).as_millis() >= 100 {
                eprint!(
                    "\r\x1b[K  [{at:7.1} s] step {:>6}  t = {:<12.6e} dt = {:<10.3e} Newton {:>2}",
                    r.step, r.time, r.dt, r.newton_iterations
                );
                last.set(now);
            }
        } else if !json && now.duration_since(last.get()).as_secs() >= 5 {
            eprintln!(
                "  [{at:7.1} s] step {} t = {:e} dt = {:e} Newton {}",
                r.step, r.time, r.dt, r.newton_iterations
            );
            last.set(now);
        }
    };
    (Box::new(steps), Box::new(phase))
}

fn check_plugin(path: &Path, real: &[f64], integer: &[i64], isolate: bool, json: bool) -> ExitCode {
    let mut stdout: Box<dyn std::io::Write> = if json {
        Box::new(std::io::sink())
    } else {
        Box::new(std::io::stdout())
    };
    let isolation = if isolate {
        seam::plugin::Isolation::Process
    } else {
        seam::plugin::Isolation::None
    };
    match seam::plugin::check_plugin_with(path, real, integer, isolation, &mut stdout) {
        Ok(report) => {
            if json {
                println!("{}", report.to_json());
            }
            ExitCode::from(report.exit_code() as u8)
        }
        Err(e) => {
            let mut d = Diagnostics::default();
            d.push(Diagnostic::error("E0500", e.to_string()));
            report_errors(json, &d, &SourceMap::default());
            ExitCode::from(EXIT_PLUGIN_FAULT)
        }
    }
}

/// The pre-flight: every validation `seam run` makes before it solves. The deck alone:
/// its syntax, each enforcement block resolved and its conductance model made (Lua
/// compiled, plugins loaded and probed). With `--mesh`: the surfaces, interactions and
/// search, and each pair's enforcement. With `--problem`: the whole problem file as
/// `seam run` reads it, up to the solve.
fn check(
    deck_path: &Path,
    mesh_path: Option<&Path>,
    problem: Option<&Path>,
    axisymmetric: bool,
    json: bool,
) -> ExitCode {
    let (loaded, mesh) = match load(deck_path, mesh_path, axisymmetric, json) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let deck_dir = deck_path.parent().unwrap_or(Path::new("."));
    let mut diags = loaded.diagnostics.clone();
    let mut surfaces = 0;
    if let Some(mesh) = &mesh {
        let scene = ContactScene::build(
            mesh,
            &loaded,
            deck_dir,
            &SceneOptions {
                integration: seam::search::pairing::Integration::Segments { order: 5 },
                fields: None,
                phase: None,
                search_only: true,
            },
            &mut diags,
        );
        surfaces = scene.surfaces;
    }
    seam::scene::check_enforcements(&loaded, deck_dir, None, &mut diags);
    let mut seen = Vec::new();
    diags.0.retain(|d| {
        let new = !seen.contains(d);
        if new {
            seen.push(d.clone());
        }
        new
    });
    let mut text = diags.render(&loaded.sources);
    let mut errors = diags.errors().count();
    let mut all = diags.0.clone();
    if let Some(p) = problem {
        let (found, sources) = match seam::run::check(p) {
            Ok(c) => (c.diagnostics, c.sources),
            Err(RunError::Input(d, s)) => (d, s),
            Err(RunError::Solve(e)) => {
                let mut d = Diagnostics::default();
                d.push(Diagnostic::error("E0700", e));
                (d, SourceMap::default())
            }
        };
        // The problem's deck is usually DECK itself: say each thing once.
        let mut extra = Diagnostics::default();
        for d in found.0 {
            if !seen.contains(&d) {
                errors += usize::from(d.is_error());
                seen.push(d.clone());
                extra.push(d);
            }
        }
        text += &extra.render(&sources);
        all.extend(extra.0);
    }
    let defs = loaded.deck.contact_definitions.len();
    if json {
        let report = serde_json::json!({
            "ok": errors == 0,
            "errors": errors,
            "warnings": all.len() - errors,
            "contact_definitions": defs,
            "contact_surfaces": mesh.as_ref().map(|_| surfaces),
            "diagnostics": all,
        });
        println!("{report}");
        return if errors > 0 {
            ExitCode::from(EXIT_BAD_INPUT)
        } else {
            ExitCode::SUCCESS
        };
    }
    eprint!("{text}");
    if errors > 0 {
        let name = problem.unwrap_or(deck_path);
        eprintln!(
            "{}: {errors} error{}",
            name.display(),
            if errors == 1 { "" } else { "s" }
        );
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    let problem_note = if problem.is_some() {
        ", problem ready to run"
    } else {
        ""
    };
    match mesh {
        Some(_) => {
            println!(
                "ok: {defs} contact definition(s), {surfaces} contact surface(s){problem_note}"
            )
        }
        None => println!("ok: {defs} contact definition(s){problem_note}"),
    }
    ExitCode::SUCCESS
}

/// Parse `3,7,10-20` into dense element ids, checking every number exists.
fn parse_dead(text: &str, mesh: &Mesh) -> Result<HashSet<ElemId>, String> {
    let index: std::collections::HashMap<i64, u32> = mesh
        .elem_numbers
        .iter()
        .enumerate()
        .map(|(i, &n)| (n, i as u32))
        .collect();
    let mut out = HashSet::new();
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let (lo, hi) = match part.split_once('-') {
            Some((a, b)) => (a.trim(), b.trim()),
            None => (part, part),
        };
        let parse = |s: &str| {
            s.parse::<i64>()
                .map_err(|_| format!("`{part}` is not an element number or a range like 10-20"))
        };
        let (lo, hi) = (parse(lo)?, parse(hi)?);
        if lo > hi {
            return Err(format!("range `{part}` runs backwards"));
        }
        if hi - lo >= mesh.num_elems() as i64 {
            return Err(format!(
                "range `{part}` is longer than the mesh has elements"
            ));
        }
        for n in lo..=hi {
            match index.get(&n) {
                Some(&e) => {
                    out.insert(ElemId(e));
                }
                None => return Err(format!("element {n} does not exist in the mesh")),
            }
        }
    }
    Ok(out)
}

/// `seam example [NAME] [--dir DIR]`: write a bundled scene, or list them.
fn example(name: Option<&str>, dir: Option<PathBuf>) -> ExitCode {
    match seam::run::bundled::command(name, dir) {
        Ok(text) => {
            println!("{text}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::from(EXIT_BAD_INPUT)
        }
    }
}

/// Diagnostics that stop a command: rendered on stderr, or with `--json` one JSON object
/// `{"ok": false, "diagnostics": [{severity, code, message, loc?, help?}, …]}` on stdout.
fn report_errors(json: bool, diags: &Diagnostics, sources: &SourceMap) {
    if json {
        let report = serde_json::json!({ "ok": false, "diagnostics": diags.0 });
        println!("{report}");
    } else {
        eprint!("{}", diags.render(sources));
    }
}
