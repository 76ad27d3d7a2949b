//! `seam run`: solve a problem file, with progress on stderr and a summary on stdout.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use seam::diag::{Diagnostic, Diagnostics, SourceMap};

use super::{EXIT_BAD_INPUT, EXIT_PLUGIN_FAULT, QUIET, eprint_diagnostics, report_errors};

/// The scene `seam run` solves when given no problem file.
const DEFAULT_SCENE: &str = "examples/two_blocks/problem.toml";

pub fn run(path: Option<PathBuf>, json: bool, restart: Option<PathBuf>) -> ExitCode {
    // Under an MPI launcher (`--features mpi`): MPI and PETSc up for the run, rank 0
    // alone printing (docs/parallel.md).
    #[cfg(feature = "mpi")]
    let _session = match super::start_mpi() {
        Ok(s) => s,
        Err(code) => return code,
    };
    if !seam::parallel::is_root() {
        return run_quietly(path, restart);
    }
    let path = match problem_path(path, json) {
        Ok(p) => p,
        Err(code) => return code,
    };
    run_path(&path, json, restart)
}

/// A rank other than 0 of a distributed run: the same run, printing nothing (rank 0
/// reports), with the same exit code.
fn run_quietly(path: Option<PathBuf>, restart: Option<PathBuf>) -> ExitCode {
    log::set_max_level(log::LevelFilter::Error);
    let path = match problem_path(path, true) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let options = seam::run::RunOptions {
        restart,
        ..Default::default()
    };
    match seam::run::run_with(&path, &options) {
        Ok(r) if r.summary.converged => ExitCode::SUCCESS,
        Ok(_) => ExitCode::from(1),
        Err(seam::run::RunError::Input(..)) => ExitCode::from(EXIT_BAD_INPUT),
        Err(seam::run::RunError::Solve(_)) => ExitCode::from(1),
    }
}

/// The problem file to solve: `path`, else the bundled scene.
fn problem_path(path: Option<PathBuf>, json: bool) -> Result<PathBuf, ExitCode> {
    Ok(match path {
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
                        return Err(ExitCode::from(EXIT_BAD_INPUT));
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
    })
}

fn run_path(path: &Path, json: bool, restart: Option<PathBuf>) -> ExitCode {
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
                let krylov = if ls.name == "GMRES" { "GMRES" } else { "CG" };
                let cg = match ls.iterations_per_solve.len() {
                    0 => String::new(),
                    1 => format!(", {} {krylov} iterations", ls.iterations),
                    k if k <= 6 => format!(
                        ", {} {krylov} iterations ({})",
                        ls.iterations,
                        ls.iterations_per_solve
                            .iter()
                            .map(usize::to_string)
                            .collect::<Vec<_>>()
                            .join(" + ")
                    ),
                    // Many solves (time steps): the range per solve, not every count.
                    k => format!(
                        ", {} {krylov} iterations ({}–{} per solve over {k} solves)",
                        ls.iterations,
                        ls.iterations_per_solve.iter().min().unwrap_or(&0),
                        ls.iterations_per_solve.iter().max().unwrap_or(&0)
                    ),
                };
                let kept = match (ls.hierarchy_setups, ls.hierarchy_refreshes) {
                    (Some(s), Some(r)) if r > 0 => {
                        format!("; AMG hierarchy set up {s}×, refreshed {r}×")
                    }
                    _ => String::new(),
                };
                println!("  linear solver: {} ({}){cg}{kept}", ls.name, ls.reason);
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
                eprint_diagnostics(&r.warnings, &r.sources);
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
