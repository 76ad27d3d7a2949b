//! Enforcement verified on non-matching meshes: patch tests to round-off, the two-slab
//! solution with a jump q/h for every h, conservation.

use seam::enforce::interface::{DEFAULT_BETA, Form, HInput, HValue, InterfaceForm};
use seam::heat::Material;
use seam::heat::steady::{ContactTerm, SteadyProblem, solve_steady};
use seam::interaction::SearchSettings;
use seam::mesh::generate::{self, BoxSpec, SolidKind};
use seam::mesh::{Mesh, NodeId};
use seam::search::pairing::{Integration, Searcher, SurfaceGeometry};
use seam::surface::{ContactSurface, SurfaceFace, SurfaceKind};

/// Block 1 on [0,1]²×[0,1] (n1 cells a side), block 2 on [0,1]²×[1,2] (n2), meshed
/// apart; side set 1 = top of block 1, 2 = bottom of block 2.
fn slabs(n1: usize, n2: usize, kind: SolidKind) -> Mesh {
    let b = |min, max, n, id| BoxSpec {
        kind,
        ..BoxSpec::hex(min, max, [n, n, n], id)
    };
    generate::boxes(
        &[
            b([0.0; 3], [1.0; 3], n1, 1).with_side_sets([0, 0, 0, 0, 0, 1]),
            b([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], n2, 2).with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    )
}

fn geometry(mesh: &Mesh, set: usize) -> SurfaceGeometry {
    let s = ContactSurface {
        name: format!("s{set}"),
        kind: SurfaceKind::Faces,
        faces: mesh.side_sets[set]
            .sides
            .iter()
            .map(|&side| SurfaceFace {
                side,
                loft: 0.0,
                origin: 0,
            })
            .collect(),
        nodes: vec![],
        origins: vec![],
        parent: None,
    };
    SurfaceGeometry::from_surface(mesh, &s, &mesh.coords).unwrap()
}

struct Setup {
    mesh: Mesh,
    a: SurfaceGeometry,
    b: SurfaceGeometry,
    points: Vec<seam::search::pairing::ContactPoint>,
}

fn setup(n1: usize, n2: usize, kind: SolidKind) -> Setup {
    let mesh = slabs(n1, n2, kind);
    let (a, b) = (geometry(&mesh, 0), geometry(&mesh, 1));
    let settings = SearchSettings::defaults(3);
    // Degree 5 on the overlap polygons: exact for the products of (bi)linear traces.
    let r = Searcher::new(&b, &settings).search(
        &a,
        &b,
        &settings,
        Integration::Segments { order: 5 },
        None,
    );
    assert_eq!(r.stats.matched, r.stats.points);
    Setup {
        mesh,
        a,
        b,
        points: r.points,
    }
}

fn solve(
    s: &Setup,
    form: Form,
    h: f64,
    k: [f64; 2],
    dirichlet: &[(NodeId, f64)],
) -> seam::heat::steady::SteadySolution {
    let materials = [
        Material {
            conductivity: k[0],
            rho_c: 1.0,
        },
        Material {
            conductivity: k[1],
            rho_c: 1.0,
        },
    ];
    let hf = move |_: &HInput| {
        Ok(HValue {
            h,
            ..HValue::default()
        })
    };
    let problem = SteadyProblem {
        mesh: &s.mesh,
        materials: &materials,
        source: None,
        dirichlet,
        face_bcs: &[],
        contact: vec![ContactTerm {
            side_a: &s.a,
            side_b: &s.b,
            points: &s.points,
            form: InterfaceForm {
                form,
                h: &hf,
                offset: 0.0,
                beta: DEFAULT_BETA,
                conductivity: &k,
            },
            linear: true,
        }],
        tolerance: 1e-13,
        max_iterations: 3,
    };
    let sol = solve_steady(&problem).unwrap();
    assert!(sol.converged, "{:?}", sol.residual_history);
    sol
}

fn linear_field(p: [f64; 3]) -> f64 {
    1.0 + p[0] + 2.0 * p[1] - 3.0 * p[2]
}

/// Patch test: T = 1 + x + 2y − 3z on the outer boundary of two non-matching blocks
/// (3:2 hexes, 7:3 tets) is reproduced at every node to 1e-12 relative by the tied
/// forms — consistency plus exact (segment) integration leave no other error.
#[test]
fn linear_field_crosses_non_matching_ties_exactly() {
    for (n1, n2, kind) in [
        (3, 2, SolidKind::Hex8),
        (7, 3, SolidKind::Hex8),
        (3, 2, SolidKind::Tet4),
    ] {
        let s = setup(n1, n2, kind);
        let on_boundary = |p: [f64; 3]| {
            p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0 || p[2] == 0.0 || p[2] == 2.0
        };
        let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
            .filter(|&i| on_boundary(s.mesh.coords[i]))
            .map(|i| (NodeId(i as u32), linear_field(s.mesh.coords[i])))
            .collect();
        for form in [
            Form::TiedNitsche,
            Form::TiedInteriorPenalty,
            Form::GapConductance,
        ] {
            let h = if form == Form::GapConductance {
                1e12
            } else {
                0.0
            };
            let sol = solve(&s, form, h, [1.0, 1.0], &dirichlet);
            let worst = (0..s.mesh.num_nodes())
                .map(|i| (sol.temperature[i] - linear_field(s.mesh.coords[i])).abs())
                .fold(0.0, f64::max);
            let tol = if form == Form::GapConductance {
                1e-10
            } else {
                1e-12
            };
            assert!(
                worst < tol * 6.0,
                "{n1}:{n2} {kind:?} {form:?}: worst nodal error {worst:e}"
            );
        }
    }
}

/// Two slabs, T = 0 at z = 0 and T = 1 at z = 2, insulated sides: the exact solution is
/// linear in each slab, with flux q = 1/(1/k_A + 1/h + 1/k_B) (downwards, from B into
/// A) and a jump q/h at z = 1; the heat read off the interface residual is q through
/// each side, with opposite signs to round-off.
#[test]
fn two_slab_jump_is_exact_for_every_conductance() {
    let s = setup(3, 2, SolidKind::Hex8);
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter_map(|i| {
            let z = s.mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then(|| (NodeId(i as u32), z / 2.0))
        })
        .collect();
    let first_b = 4 * 4 * 4;
    for form in [Form::Conductance, Form::GapConductance] {
        for h in [1e-6, 1.0, 10.0, 1e6, 1e12] {
            for k in [[1.0, 1.0], [1.0, 5.0]] {
                if form == Form::Conductance && h > 1e6 {
                    continue; // a pure penalty at 1e12 loses 12 digits to conditioning
                }
                let sol = solve(&s, form, h, k, &dirichlet);
                let q = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
                let exact = |i: usize| {
                    let z = s.mesh.coords[i][2];
                    if i < first_b {
                        q * z / k[0]
                    } else {
                        1.0 - q * (2.0 - z) / k[1]
                    }
                };
                let worst = (0..s.mesh.num_nodes())
                    .map(|i| (sol.temperature[i] - exact(i)).abs())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-11, "{form:?} h={h} k={k:?}: worst {worst:e}");
                // Heat flows from the hot top (B) into A: side A *loses* −q.
                let (qa, qb) = sol.heat[0];
                assert!(
                    (qa + q).abs() < 1e-10 * q,
                    "{form:?} h={h}: heat {qa} vs {}",
                    -q
                );
                assert!(
                    (qa + qb).abs() <= 1e-12 * qa.abs().max(1e-300),
                    "imbalance {}",
                    qa + qb
                );
            }
        }
    }
}
