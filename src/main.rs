//! The `seam` command line: parse the arguments, set up logging and threads, and hand
//! over to the command's module under `cli/`.
//!
//! Exit codes: 0 ok; 1 ran but failed; 2 bad input or usage; 3 plugin fault.

use std::process::ExitCode;

use clap::Parser;

mod cli;

use cli::args::{Cli, ColorWhen, Command};
use cli::{EXIT_BAD_INPUT, QUIET};

fn main() -> ExitCode {
    let cli = Cli::parse();
    seam::logging::init_stderr(match (cli.quiet, cli.verbose) {
        (true, _) => log::LevelFilter::Error,
        (false, 0) => log::LevelFilter::Warn,
        (false, 1) => log::LevelFilter::Info,
        _ => log::LevelFilter::Debug,
    });
    QUIET.store(cli.quiet, std::sync::atomic::Ordering::Relaxed);
    match cli.color {
        ColorWhen::Auto => {} // anstream asks the terminal, NO_COLOR and CLICOLOR_FORCE
        ColorWhen::Always => anstream::ColorChoice::Always.write_global(),
        ColorWhen::Never => anstream::ColorChoice::Never.write_global(),
    }
    if let Some(n) = cli.threads
        && let Err(e) = rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .build_global()
    {
        eprintln!("error: --threads {n}: {e}");
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    match cli.command {
        Command::Example { name, dir } => cli::check::example(name.as_deref(), dir),
        Command::Surfaces {
            deck,
            mesh,
            json,
            dead,
            axisymmetric,
        } => cli::surfaces::surfaces(&deck, &mesh, json, dead.as_deref(), axisymmetric),
        Command::Search {
            deck,
            mesh,
            json,
            segments,
            order,
            axisymmetric,
            points,
        } => cli::search::search(
            &deck,
            &mesh,
            json,
            (segments, order as usize),
            axisymmetric,
            points.as_deref(),
        ),
        Command::Run {
            problem,
            json,
            restart,
        } => cli::run::run(problem, json, restart),
        Command::CheckPlugin {
            path,
            real,
            integer,
            isolate,
            json,
        } => cli::check::check_plugin(&path, &real, &integer, isolate, json),
        Command::PluginWorker => ExitCode::from(seam::plugin::serve_worker().clamp(0, 255) as u8),
        Command::Check {
            deck,
            mesh,
            problem,
            axisymmetric,
            json,
        } => cli::check::check(
            &deck,
            mesh.as_deref(),
            problem.as_deref(),
            axisymmetric,
            json,
        ),
    }
}
