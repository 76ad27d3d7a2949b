//! Benchmark: a 2-D tied problem, speed per phase against error, and the share of
//! contact — T = sin(πx) sin(πy/2) on [0,1] × [0,2] with its source (k = 1), T = 0 on
//! the boundary; block A = [0,1]² with n × n Quad4, block B = [0,1] × [1,2] with m × m
//! cells (m = 2n/3) split into Tri3, meshed apart and tied across y = 1 (weighted
//! Nitsche on mortar segments, order 4); "conforming" is the same problem on one mesh of
//! n × n Quad4 in both blocks, the cost floor.
//!
//! Phases (seconds, one run, release build): search (surfaces to contact points:
//! geometry, tree, mortar segments), interface terms (the contact points' element
//! pairs evaluated into dense blocks once, `InterfacePoints::new` + `evaluate`, timed
//! apart here: the same work the assembly does for contact), assembly (volume and
//! contact terms into the matrix), factor (or AMG set-up), solve. The contact share is
//! (search + interface terms) / total. `cargo bench --bench twod` runs n = 90 and 300
//! (about 1e4 and 1.3e5 unknowns); add `-- large` for n = 832 (about 1.0e6 unknowns
//! tied, AMG-preconditioned CG). Opt-in: not run by `cargo test` or CI.

#[path = "common/mod.rs"]
mod common;

use std::f64::consts::PI;
use std::time::Instant;

use seam::assembly::DofMap;
use seam::enforce::interface::{
    DEFAULT_BETA, Form, HInput, HValue, InterfaceForm, InterfacePoints,
};
use seam::heat::Material;
use seam::heat::steady::{ContactTerm, SteadyProblem, SteadySolution, solve_steady};
use seam::mesh::generate::{self, PlaneKind, RectSpec};
use seam::mesh::{Mesh, NodeId};
use seam::search::SearchSettings;
use seam::search::pairing::{Integration, Searcher, SurfaceGeometry};

fn exact(p: [f64; 3]) -> f64 {
    (PI * p[0]).sin() * (0.5 * PI * p[1]).sin()
}

fn grad(p: [f64; 3]) -> [f64; 3] {
    [
        PI * (PI * p[0]).cos() * (0.5 * PI * p[1]).sin(),
        0.5 * PI * (PI * p[0]).sin() * (0.5 * PI * p[1]).cos(),
        0.0,
    ]
}

fn boundary(mesh: &Mesh) -> Vec<(NodeId, f64)> {
    (0..mesh.num_nodes())
        .filter(|&i| {
            let p = mesh.coords[i];
            p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 2.0
        })
        .map(|i| (NodeId(i as u32), 0.0))
        .collect()
}

fn errors(mesh: &Mesh, t: &[f64]) -> (f64, f64) {
    common::errors(mesh, t, exact, grad)
}

/// One line of the table: the case, its unknowns and errors, and the seconds of each
/// phase — search, interface terms, assembly, factor (or AMG set-up), solve.
fn print(label: &str, dofs: usize, (l2, max): (f64, f64), phases: [f64; 5]) {
    let [search, interface, assembly, factor, solve] = phases;
    let total = search + assembly + factor + solve;
    println!(
        "{label:<24} {dofs:>9} {l2:>10.3e} {max:>10.3e} {search:>8.3} {interface:>8.3} {assembly:>8.3} {factor:>8.3} {solve:>8.3} {total:>8.3} {:>7.2}%",
        100.0 * (search + interface) / total
    );
}

/// The steady solve of `mesh` with the source, T = 0 on the boundary and `contact`.
fn solve(mesh: &Mesh, contact: Vec<ContactTerm<'_>>, iterative: bool) -> SteadySolution {
    let source = |p: [f64; 3]| 1.25 * PI * PI * exact(p);
    let materials = [Material {
        conductivity: 1.0,
        rho_c: 1.0,
    }; 2];
    solve_steady(&SteadyProblem {
        mesh,
        materials: &materials,
        source: Some(&source),
        block_source: None,
        dirichlet: &boundary(mesh),
        face_bcs: &[],
        ties: vec![],
        contact,
        interfaces: None,
        reproducible: true,
        iterative,
        tolerance: 1e-10,
        max_iterations: 3,
    })
    .unwrap()
}

fn main() {
    let large = std::env::args().any(|a| a == "large");
    let sizes: &[usize] = if large { &[90, 300, 832] } else { &[90, 300] };
    println!(
        "{:<24} {:>9} {:>10} {:>10} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8}",
        "case",
        "unknowns",
        "L2 error",
        "max error",
        "search",
        "iface",
        "assembly",
        "factor",
        "solve",
        "total",
        "contact"
    );
    for &n in sizes {
        let m = 2 * n / 3;
        let iterative = n >= 200;
        let conforming = generate::rectangles(
            &[
                RectSpec::quad([0.0, 0.0], [1.0, 1.0], [n, n], 1),
                RectSpec::quad([0.0, 1.0], [1.0, 2.0], [n, n], 2),
            ],
            true,
        );
        let sol = solve(&conforming, vec![], iterative);
        let t = &sol.timing;
        print(
            &format!("conforming n={n}"),
            sol.dofs.len(),
            errors(&conforming, &sol.temperature),
            [0.0, 0.0, t.assembly_s, t.factor_s, t.solve_s],
        );
        drop((conforming, sol));

        let mesh = generate::rectangles(
            &[
                RectSpec::quad([0.0, 0.0], [1.0, 1.0], [n, n], 1).with_side_sets([0, 0, 0, 1]),
                RectSpec {
                    kind: PlaneKind::Tri3,
                    ..RectSpec::quad([0.0, 1.0], [1.0, 2.0], [m, m], 2)
                }
                .with_side_sets([0, 0, 2, 0]),
            ],
            false,
        );
        let t = Instant::now();
        let a = SurfaceGeometry::from_side_set(&mesh, 0).unwrap();
        let b = SurfaceGeometry::from_side_set(&mesh, 1).unwrap();
        let settings = SearchSettings::defaults(2);
        let integration = Integration::Segments { order: 4 };
        let r = Searcher::new(&b, &settings).search_points(&a, &b, &settings, integration, None);
        let search = t.elapsed().as_secs_f64();
        let k = [1.0, 1.0];
        let tied = |_: &HInput| Ok(HValue::default());
        let form = || InterfaceForm {
            form: Form::TiedNitsche,
            h: &tied,
            offset: 0.0,
            beta: DEFAULT_BETA,
            conductivity: &k,
            conductivity_of_t: None,
            temperature_field: None,
        };
        // The interface terms alone: what the assembly does for the contact points.
        let dofs = DofMap::new(&mesh, &[("temperature", &[0, 1])]).unwrap();
        let t = Instant::now();
        let points = InterfacePoints::new(
            &mesh,
            &dofs,
            dofs.field("temperature").unwrap(),
            &a,
            &b,
            &r.points,
            &form(),
        )
        .unwrap();
        let zero = vec![0.0; dofs.len()];
        let system = points.evaluate(&form(), &zero).unwrap();
        let interface = t.elapsed().as_secs_f64();
        drop((points, system, dofs));
        let contact = vec![ContactTerm {
            side_a: &a,
            side_b: &b,
            points: &r.points,
            form: form(),
            linear: true,
        }];
        let sol = solve(&mesh, contact, iterative);
        let t = &sol.timing;
        print(
            &format!("tied nitsche n={n}/{m}"),
            sol.dofs.len(),
            errors(&mesh, &sol.temperature),
            [search, interface, t.assembly_s, t.factor_s, t.solve_s],
        );
        println!(
            "  ({} contact points on {} side-A edges; heat imbalance {:.1e})",
            r.points.len(),
            a.faces.len(),
            sol.heat[0].0 + sol.heat[0].1
        );
    }
}
