//! `seam surfaces`: the contact surfaces of a deck on a mesh, as a table or JSON.

use std::collections::HashSet;
use std::path::Path;
use std::process::ExitCode;

use serde::Serialize;

use seam::diag::{Diagnostic, Diagnostics, SourceMap};
use seam::mesh::{ElemId, Mesh};
use seam::scene::ContactScene;
use seam::surface::SurfaceKind;

use super::{EXIT_BAD_INPUT, eprint_diagnostics, format_number, load, report_errors};

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
pub struct Warning {
    pub code: &'static str,
    pub message: String,
}

impl Warning {
    /// The warnings of `diags`, as the `--json` reports list them.
    pub fn all(diags: &seam::diag::Diagnostics) -> Vec<Warning> {
        diags
            .warnings()
            .map(|d| Warning {
                code: d.code,
                message: d.message.clone(),
            })
            .collect()
    }
}

/// A `--json` report on stdout, one line.
pub fn print_json(report: &impl Serialize) {
    println!(
        "{}",
        serde_json::to_string(report).expect("plain data serialises")
    );
}

#[derive(Serialize)]
struct SurfacesReport {
    surfaces: Vec<SurfaceRow>,
    warnings: Vec<Warning>,
}

pub fn surfaces(
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
            let d = Diagnostic::error("E0002", format!("--dead {e}"));
            report_errors(json, &Diagnostics(vec![d]), &SourceMap::default());
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
        eprint_diagnostics(&diags, &loaded.sources);
        return ExitCode::from(EXIT_BAD_INPUT);
    }
    if json {
        print_json(&SurfacesReport {
            surfaces: rows,
            warnings: Warning::all(&diags),
        });
    } else {
        print_table(&rows);
        use std::io::Write as _;
        let _ = std::io::stdout().flush();
        eprint_diagnostics(&diags, &loaded.sources);
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
