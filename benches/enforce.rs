//! Benchmark: speed against error of the enforcements on the two-block non-matching
//! problem — T = sin(πx) sin(πy) sin(πz/2) on [0,1]² × [0,2] with the matching source,
//! block A = [0,1]³ with n³ hexes, block B = [0,1]² × [1,2] with (2n/3)³ (ratio 3:2),
//! tied across z = 1, T = 0 on the whole boundary — plus the same problem on one
//! conforming mesh (n³ on both) as the baseline.
//!
//! For each model and integration mode (side-A Gauss points vs mortar segments):
//! unknowns, L2 and max nodal error, time per phase. `cargo bench --bench enforce`
//! runs n = 18 and 40 (about 1e4 and 1e5 unknowns); add `-- large` for n = 88 (about
//! 1e6). The linear solver is `seam run`'s default: sparse Cholesky below
//! `AUTO_AMG_THRESHOLD` nodes, AMG-preconditioned CG from there on.

#[path = "common/mod.rs"]
mod common;

use std::f64::consts::PI;
use std::time::Instant;

use seam::enforce::interface::{DEFAULT_BETA, Form, HInput, HValue, InterfaceForm};
use seam::heat::Material;
use seam::heat::steady::{AUTO_AMG_THRESHOLD, ContactTerm, SteadyProblem, solve_steady};
use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{Mesh, NodeId};
use seam::search::SearchSettings;
use seam::search::pairing::{Integration, Searcher, SurfaceGeometry};

fn exact(p: [f64; 3]) -> f64 {
    (PI * p[0]).sin() * (PI * p[1]).sin() * (0.5 * PI * p[2]).sin()
}

fn grad(p: [f64; 3]) -> [f64; 3] {
    let (sx, sy, sz) = (
        (PI * p[0]).sin(),
        (PI * p[1]).sin(),
        (0.5 * PI * p[2]).sin(),
    );
    let (cx, cy, cz) = (
        (PI * p[0]).cos(),
        (PI * p[1]).cos(),
        (0.5 * PI * p[2]).cos(),
    );
    [
        PI * cx * sy * sz,
        PI * sx * cy * sz,
        0.5 * PI * sx * sy * cz,
    ]
}

fn geometry(mesh: &Mesh, set: usize) -> SurfaceGeometry {
    SurfaceGeometry::from_side_set(mesh, set).unwrap()
}

fn boundary(mesh: &Mesh) -> Vec<(NodeId, f64)> {
    (0..mesh.num_nodes())
        .filter(|&i| {
            let p = mesh.coords[i];
            p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0 || p[2] == 0.0 || p[2] == 2.0
        })
        .map(|i| (NodeId(i as u32), 0.0))
        .collect()
}

struct Row {
    label: String,
    dofs: usize,
    l2: f64,
    max: f64,
    search: f64,
    assembly: f64,
    factor: f64,
    solve: f64,
}

fn print(r: &Row) {
    let total = r.search + r.assembly + r.factor + r.solve;
    println!(
        "{:<34} {:>9} {:>11.3e} {:>11.3e} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3}",
        r.label, r.dofs, r.l2, r.max, r.search, r.assembly, r.factor, r.solve, total
    );
}

fn errors(mesh: &Mesh, t: &[f64]) -> (f64, f64) {
    common::errors(mesh, t, exact, grad)
}

fn main() {
    let large = std::env::args().any(|a| a == "large");
    let sizes: &[usize] = if large { &[18, 40, 88] } else { &[18, 40] };
    println!(
        "{:<34} {:>9} {:>11} {:>11} {:>9} {:>9} {:>9} {:>9} {:>9}",
        "case",
        "unknowns",
        "L2 error",
        "max error",
        "search s",
        "assemb s",
        "factor s",
        "solve s",
        "total s"
    );
    let source = |p: [f64; 3]| 2.25 * PI * PI * exact(p);
    let mat = [Material {
        conductivity: 1.0,
        rho_c: 1.0,
    }; 2];
    for &n in sizes {
        let m = 2 * n / 3;
        // Conforming baseline: both blocks with n cells across, sharing the z = 1 nodes.
        let conforming = generate::boxes(
            &[
                BoxSpec::hex([0.0; 3], [1.0; 3], [n, n, n], 1),
                BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [n, n, n], 2),
            ],
            true,
        );
        let bc = boundary(&conforming);
        let t = Instant::now();
        let sol = solve_steady(&SteadyProblem {
            mesh: &conforming,
            materials: &mat,
            source: Some(&source),
            block_source: None,
            dirichlet: &bc,
            face_bcs: &[],
            ties: vec![],
            contact: vec![],
            interfaces: None,
            reproducible: true,
            // `seam run`'s default: AMG-CG from the auto threshold on.
            iterative: conforming.num_nodes() >= AUTO_AMG_THRESHOLD,
            tolerance: 1e-10,
            max_iterations: 3,
        })
        .unwrap();
        let _ = t;
        let (l2, max) = errors(&conforming, &sol.temperature);
        print(&Row {
            label: format!("conforming n={n}"),
            dofs: sol.dofs.len(),
            l2,
            max,
            search: 0.0,
            assembly: sol.timing.assembly_s,
            factor: sol.timing.factor_s,
            solve: sol.timing.solve_s,
        });

        let mesh = generate::boxes(
            &[
                BoxSpec::hex([0.0; 3], [1.0; 3], [n, n, n], 1).with_side_sets([0, 0, 0, 0, 0, 1]),
                BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [m, m, m], 2)
                    .with_side_sets([0, 0, 0, 0, 2, 0]),
            ],
            false,
        );
        let bc = boundary(&mesh);
        let (a, b) = (geometry(&mesh, 0), geometry(&mesh, 1));
        let settings = SearchSettings::defaults(3);
        let k = [1.0, 1.0];
        for (integration, mode) in [
            (Integration::Quadrature { order: 2 }, "gauss"),
            (Integration::Segments { order: 4 }, "segments"),
        ] {
            let t = Instant::now();
            let r =
                Searcher::new(&b, &settings).search_points(&a, &b, &settings, integration, None);
            let search = t.elapsed().as_secs_f64();
            for (form, name, h) in [
                (Form::TiedNitsche, "tied nitsche", 0.0),
                (Form::TiedInteriorPenalty, "tied ip", 0.0),
                (Form::GapConductance, "gap conductance h=1e8", 1e8),
            ] {
                let hf = move |_: &HInput| {
                    Ok(HValue {
                        h,
                        ..HValue::default()
                    })
                };
                let sol = solve_steady(&SteadyProblem {
                    mesh: &mesh,
                    materials: &mat,
                    source: Some(&source),
                    block_source: None,
                    dirichlet: &bc,
                    face_bcs: &[],
                    ties: vec![],
                    contact: vec![ContactTerm {
                        side_a: &a,
                        side_b: &b,
                        points: &r.points,
                        form: InterfaceForm {
                            form,
                            h: &hf,
                            offset: 0.0,
                            beta: DEFAULT_BETA,
                            conductivity: &k,
                            conductivity_of_t: None,
                            temperature_field: None,
                        },
                        linear: true,
                    }],
                    interfaces: None,
                    reproducible: true,
                    iterative: mesh.num_nodes() >= AUTO_AMG_THRESHOLD,
                    tolerance: 1e-10,
                    max_iterations: 3,
                })
                .unwrap();
                let (l2, max) = errors(&mesh, &sol.temperature);
                print(&Row {
                    label: format!("{name} {mode} n={n}"),
                    dofs: sol.dofs.len(),
                    l2,
                    max,
                    search,
                    assembly: sol.timing.assembly_s,
                    factor: sol.timing.factor_s,
                    solve: sol.timing.solve_s,
                });
            }
        }
    }
}
