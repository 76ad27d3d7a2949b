//! `seam check`, `seam check-plugin` and `seam example`: validate without solving, probe a
//! plugin, write a bundled scene.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use seam::diag::{Diagnostic, Diagnostics, SourceMap};
use seam::run::RunError;
use seam::scene::{ContactScene, SceneOptions};

use super::{EXIT_BAD_INPUT, EXIT_PLUGIN_FAULT, load, report_errors};

pub fn check_plugin(
    path: &Path,
    real: &[f64],
    integer: &[i64],
    isolate: bool,
    json: bool,
) -> ExitCode {
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
pub fn check(
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
    let mut text = diags.render_styled(&loaded.sources);
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
        text += &extra.render_styled(&sources);
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
    anstream::eprint!("{text}");
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

/// `seam example [NAME] [--dir DIR]`: write a bundled scene, or list them.
pub fn example(name: Option<&str>, dir: Option<PathBuf>) -> ExitCode {
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
