//! `seam search`: pair the deck's surfaces and report each pair's coverage.

use std::path::Path;
use std::process::ExitCode;

use serde::Serialize;

use seam::scene::{ContactScene, SceneOptions};

use super::surfaces::{Warning, print_json};
use super::{EXIT_BAD_INPUT, eprint_diagnostics, format_number, load_reporting};

#[derive(Serialize)]
struct SearchReport {
    interactions: Vec<seam::search::scene::PairingSummary>,
    timing: seam::search::scene::Timing,
    warnings: Vec<Warning>,
}

pub fn search(
    deck_path: &Path,
    mesh_path: &Path,
    json: bool,
    (segments, order): (bool, usize),
    axisymmetric: bool,
    points: Option<&Path>,
) -> ExitCode {
    use seam::scene::OutputRule;
    use seam::search::pairing::Integration;
    // Under an MPI launcher (`--features mpi`): the distributed search, rank 0 alone
    // printing and writing (docs/parallel.md).
    #[cfg(feature = "mpi")]
    let _session = match super::start_mpi() {
        Ok(s) => s,
        Err(code) => return code,
    };
    let root = seam::parallel::is_root();
    if !root {
        log::set_max_level(log::LevelFilter::Error);
    }
    // (Rank 0 alone reports what stops the command: every rank meets it.)
    let report = root.then_some(json);
    let (loaded, mesh) = match load_reporting(deck_path, Some(mesh_path), axisymmetric, report) {
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
        if root {
            eprint_diagnostics(&diags, &loaded.sources);
        }
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    if !root {
        return ExitCode::SUCCESS;
    }
    if let Some(path) = points
        && let Err(e) = write_points(path, searched.iter().flat_map(|s| &s.pairings))
    {
        eprintln!("error: cannot write {}: {e}", path.display());
        return ExitCode::from(1);
    }
    if json {
        print_json(&SearchReport {
            interactions: summaries,
            timing,
            warnings: Warning::all(&diags),
        });
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
    eprint_diagnostics(&diags, &loaded.sources);
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

/// Every searched point of `pairings` as csv, in the search's order, to `path` (`--points`).
fn write_points<'a>(
    path: &Path,
    pairings: impl Iterator<Item = &'a seam::search::scene::Pairing>,
) -> std::io::Result<()> {
    use std::io::Write as _;
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    writeln!(
        out,
        "interaction,point,a_face,a_node,status,b_face,xi_a0,xi_a1,xi_b0,xi_b1,gap,weight,x,y,z"
    )?;
    let id = |i: Option<u32>| i.map_or(String::new(), |i| i.to_string());
    for (k, p) in pairings.enumerate() {
        for (i, q) in p.result.points.iter().enumerate() {
            writeln!(
                out,
                "{k},{i},{},{},{:?},{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{:e}",
                id(q.a_face),
                id(q.a_node),
                q.status,
                id(q.b_face),
                q.xi_a[0],
                q.xi_a[1],
                q.xi_b[0],
                q.xi_b[1],
                q.gap,
                q.weight,
                q.x[0],
                q.x[1],
                q.x[2]
            )?;
        }
    }
    out.flush()
}
