//! Node surfaces — contact node sets and `Contact Type = node` — carry heat node to face:
//! each side-A node weighted by its tributary area. On matching meshes the heat through a
//! node surface is the heat through the face surface to round-off, for every model; the
//! expected values are the slabs' exact solution, not the code's own output.

use seam::deck::spec::{ContactDefinition, ContactType, SurfaceBlock, SurfaceDef};
use seam::diag::{Loc, SourceMap};
use seam::enforce::interface::{DEFAULT_BETA, Form, HInput, HValue, InterfaceForm};
use seam::enforce::mortar::Multipliers;
use seam::heat::Material;
use seam::heat::steady::{ContactTerm, SteadyProblem, SteadySolution, TieTerm, solve_steady};
use seam::mesh::generate::{self, BoxSpec, SolidKind};
use seam::mesh::{Mesh, NodeId, NodeSet};
use seam::scene::surfaces;
use seam::search::SearchSettings;
use seam::search::pairing::{ContactPoint, Integration, PointStatus, Searcher, SurfaceGeometry};
use seam::surface::{SurfaceKind, SurfaceSet};

/// Block 1 on [0,1]²×[0,1] (n1 cells a side), block 2 on [0,1]²×[1,2] (n2), meshed
/// apart. Side sets: 1 top of block 1, 2 bottom of block 2, 3 bottom of block 1 (z = 0),
/// 4 top of block 2 (z = 2). Node set 1 `a_top`: block 1's nodes at z = 1.
fn slabs(n1: usize, n2: usize, kind: SolidKind) -> Mesh {
    let b = |min, max, n, id| BoxSpec {
        kind,
        ..BoxSpec::hex(min, max, [n, n, n], id)
    };
    let mut mesh = generate::boxes(
        &[
            b([0.0; 3], [1.0; 3], n1, 1).with_side_sets([0, 0, 0, 0, 3, 1]),
            b([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], n2, 2).with_side_sets([0, 0, 0, 0, 2, 4]),
        ],
        false,
    );
    let first_b = (n1 + 1).pow(3);
    mesh.node_sets.push(NodeSet {
        id: 1,
        name: "a_top".into(),
        nodes: (0..first_b)
            .filter(|&i| mesh.coords[i][2] == 1.0)
            .map(|i| NodeId(i as u32))
            .collect(),
    });
    mesh
}

/// How side A is defined.
#[derive(Clone, Copy, Debug, PartialEq)]
enum SideA {
    /// `Contact Surface a Contains surface_1`.
    Faces,
    /// `Contact Node Set a Contains a_top`.
    NodeSet,
    /// `begin contact surface a  surface = surface_1  contact type = node  end`.
    TypeNode,
}

fn surfaces(mesh: &Mesh, side_a: SideA) -> SurfaceSet {
    let at = Loc::default();
    let a = match side_a {
        SideA::Faces => SurfaceDef::Contains {
            name: "a".into(),
            contains: vec!["surface_1".into()],
            at: at.clone(),
        },
        SideA::NodeSet => SurfaceDef::NodeSet {
            name: "a".into(),
            contains: vec!["a_top".into()],
            at: at.clone(),
        },
        SideA::TypeNode => SurfaceDef::Block(SurfaceBlock {
            name: "a".into(),
            side_sets: vec!["surface_1".into()],
            contact_type: ContactType::Node,
            ..SurfaceBlock::default()
        }),
    };
    let b = SurfaceDef::Contains {
        name: "b".into(),
        contains: vec!["surface_2".into()],
        at,
    };
    let def = ContactDefinition {
        surfaces: vec![a, b],
        ..ContactDefinition::default()
    };
    let set = surfaces::build(mesh, &def, &SourceMap::default());
    assert!(!set.diagnostics.has_errors(), "{:?}", set.diagnostics);
    set
}

struct Setup {
    mesh: Mesh,
    a: SurfaceGeometry,
    b: SurfaceGeometry,
    points: Vec<ContactPoint>,
}

fn setup(n1: usize, n2: usize, kind: SolidKind, side_a: SideA) -> Setup {
    let mesh = slabs(n1, n2, kind);
    let set = surfaces(&mesh, side_a);
    let geometry =
        |name| SurfaceGeometry::from_surface(&mesh, set.get(name).unwrap(), &mesh.coords).unwrap();
    let (a, b) = (geometry("a"), geometry("b"));
    assert_eq!(
        set.get("a").unwrap().kind == SurfaceKind::Nodes,
        side_a != SideA::Faces
    );
    let settings = SearchSettings::defaults(3);
    // Segments of degree 5 for faces: exact for the products of (bi)linear traces.
    let r = Searcher::new(&b, &settings).search(
        &a,
        &b,
        &settings,
        Integration::Segments { order: 5 },
        None,
    );
    assert_eq!(r.stats.matched, r.stats.points, "{:?}", r.stats);
    Setup {
        mesh,
        a,
        b,
        points: std::sync::Arc::unwrap_or_clone(r.points),
    }
}

fn materials(k: [f64; 2]) -> [Material; 2] {
    k.map(|conductivity| Material {
        conductivity,
        rho_c: 1.0,
    })
}

/// T = 0 at z = 0 and T = 1 at z = 2, insulated sides.
fn slab_dirichlet(mesh: &Mesh) -> Vec<(NodeId, f64)> {
    (0..mesh.num_nodes())
        .filter_map(|i| {
            let z = mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then(|| (NodeId(i as u32), z / 2.0))
        })
        .collect()
}

fn solve_form(
    s: &Setup,
    form: Form,
    h: f64,
    k: [f64; 2],
    dirichlet: &[(NodeId, f64)],
) -> SteadySolution {
    let materials = materials(k);
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
        block_source: None,
        dirichlet,
        face_bcs: &[],
        ties: vec![],
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
                conductivity_of_t: None,
                temperature_field: None,
            },
            linear: true,
        }],
        interfaces: None,
        reproducible: true,
        iterative: false,
        tolerance: 1e-13,
        max_iterations: 3,
    };
    let sol = solve_steady(&problem).unwrap();
    assert!(sol.converged, "{:?}", sol.residual_history);
    sol
}

fn solve_tie(
    s: &Setup,
    multipliers: Multipliers,
    k: [f64; 2],
    dirichlet: &[(NodeId, f64)],
) -> SteadySolution {
    let materials = materials(k);
    let problem = SteadyProblem {
        mesh: &s.mesh,
        materials: &materials,
        source: None,
        block_source: None,
        dirichlet,
        face_bcs: &[],
        ties: vec![TieTerm {
            side_a: &s.a,
            side_b: &s.b,
            points: &s.points,
            offset: 0.0,
            multipliers,
        }],
        contact: vec![],
        interfaces: None,
        reproducible: true,
        iterative: false,
        tolerance: 1e-13,
        max_iterations: 3,
    };
    let sol = solve_steady(&problem).unwrap();
    assert!(sol.converged, "{:?}", sol.residual_history);
    sol
}

/// The models and conductivities compared: (form, h, k). Dash is a pure penalty whose
/// jump q/α depends on α, so it is compared where the face and node penalties agree
/// (equal k and element sizes); every other form is consistent and exact here.
const CASES: [(Form, f64, [f64; 2]); 7] = [
    (Form::Conductance, 1.0, [1.0, 5.0]),
    (Form::Conductance, 10.0, [1.0, 5.0]),
    (Form::GapConductance, 1.0, [1.0, 5.0]),
    (Form::GapConductance, 1e6, [1.0, 5.0]),
    (Form::TiedNitsche, f64::INFINITY, [1.0, 5.0]),
    (Form::TiedInteriorPenalty, f64::INFINITY, [1.0, 5.0]),
    (Form::Penalty, 1.0, [2.0, 2.0]),
];

/// Two slabs meshed apart with coincident nodes at z = 1 (3 × 3 cells both): the heat
/// through a contact node set and through a `Contact Type = node` surface equals the heat
/// through the face surface to 1e-10 relative, for the resistance, Robin–Nitsche gap
/// conductance, tied Nitsche, tied interior penalty and Dash; both are the exact
/// `q = 1/(1/k_A + 1/h + 1/k_B)` (Dash: `1/α` in place of `1/h`); heat leaving side A is
/// heat entering side B to round-off.
#[test]
fn node_surface_heat_equals_face_surface_heat_on_matching_meshes() {
    let faces = setup(3, 3, SolidKind::Hex8, SideA::Faces);
    let dirichlet = slab_dirichlet(&faces.mesh);
    for side_a in [SideA::NodeSet, SideA::TypeNode] {
        let nodes = setup(3, 3, SolidKind::Hex8, side_a);
        assert_eq!(nodes.points.len(), 16, "one point per interface node");
        for (form, h, k) in CASES {
            let by_face = solve_form(&faces, form, h, k, &dirichlet).heat[0];
            let by_node = solve_form(&nodes, form, h, k, &dirichlet).heat[0];
            let diff = (by_node.0 - by_face.0).abs() / by_face.0.abs();
            eprintln!(
                "{side_a:?} {form:?} h={h:e}: heat {:.15} (faces {:.15}), relative difference {diff:.1e}, imbalance {:.1e}",
                by_node.0,
                by_face.0,
                by_node.0 + by_node.1
            );
            assert!(diff <= 1e-10, "{side_a:?} {form:?} h={h}: {diff:e}");
            assert!(
                (by_node.0 + by_node.1).abs() <= 1e-12 * by_node.0.abs(),
                "{side_a:?} {form:?}: imbalance {}",
                by_node.0 + by_node.1
            );
            if form != Form::Penalty {
                // Heat flows from the hot top (B) into A: side A loses −q.
                let q = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
                assert!(
                    (by_node.0 + q).abs() <= 1e-10 * q,
                    "{side_a:?} {form:?} h={h}: {} vs {}",
                    by_node.0,
                    -q
                );
            }
        }
    }
}

/// Heat is conserved node to face on non-matching meshes too (3:2 hexes, 3:2 tets, and
/// the coarse side A against a fine side B): heat leaving side A equals heat entering
/// side B to round-off, for every form.
#[test]
fn node_surface_heat_is_conserved_on_non_matching_meshes() {
    for (n1, n2, kind) in [
        (3, 2, SolidKind::Hex8),
        (2, 3, SolidKind::Hex8),
        (3, 2, SolidKind::Tet4),
    ] {
        let s = setup(n1, n2, kind, SideA::NodeSet);
        let dirichlet = slab_dirichlet(&s.mesh);
        for (form, h, k) in CASES {
            let (qa, qb) = solve_form(&s, form, h, k, &dirichlet).heat[0];
            assert!(qa.abs() > 0.1, "{form:?}: heat {qa} crosses");
            // Not exact here (module docs of `enforce::interface`): how far off, printed.
            if form != Form::Penalty {
                let q = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
                eprintln!(
                    "{n1}:{n2} {kind:?} {form:?} h={h:e}: heat off the exact by {:.1e} of q, imbalance {:.1e}",
                    (qa + q).abs() / q,
                    qa + qb
                );
            }
            assert!(
                (qa + qb).abs() <= 1e-12 * qa.abs(),
                "{n1}:{n2} {kind:?} {form:?}: imbalance {}",
                qa + qb
            );
        }
    }
}

fn linear_field(p: [f64; 3]) -> f64 {
    1.0 + p[0] + 2.0 * p[1] - 3.0 * p[2]
}

/// The worst nodal error of a solution against `exact`, relative to the field's size.
fn worst_error(mesh: &Mesh, t: &[f64], exact: impl Fn([f64; 3]) -> f64) -> f64 {
    let scale = mesh
        .coords
        .iter()
        .map(|&p| exact(p).abs())
        .fold(0.0, f64::max);
    (0..mesh.num_nodes())
        .map(|i| (t[i] - exact(mesh.coords[i])).abs())
        .fold(0.0, f64::max)
        / scale
}

/// Node-to-segment patch test. T = 1 + x + 2y − 3z (a normal flux of 3 through the
/// interface) prescribed on the outer boundary is reproduced at every node to 1e-12 by
/// the tied forms and the collocated multiplier tie, on non-matching meshes whose side-B
/// traces are linear on side A's faces (side A nested in side B: 4:2 and 6:3 hexes).
/// On arbitrary non-matching meshes (3:2), T = 1 + x + 2y (no normal flux) crosses as
/// exactly; with a normal flux there a node-to-face collocation is not exact (the known
/// one-pass node-to-segment limitation) — the measured error is printed.
#[test]
fn linear_field_crosses_node_to_face_ties_exactly() {
    type Field = fn([f64; 3]) -> f64;
    let cases: [(usize, usize, Field, bool); 4] = [
        (4, 2, linear_field, true),
        (6, 3, linear_field, true),
        (3, 2, tangential_field, true),
        (3, 2, linear_field, false),
    ];
    for (n1, n2, field, exact) in cases {
        let s = setup(n1, n2, SolidKind::Hex8, SideA::NodeSet);
        let on_boundary = |p: [f64; 3]| {
            p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0 || p[2] == 0.0 || p[2] == 2.0
        };
        let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
            .filter(|&i| on_boundary(s.mesh.coords[i]))
            .map(|i| (NodeId(i as u32), field(s.mesh.coords[i])))
            .collect();
        let k = [1.0, 1.0];
        let mut errors = Vec::new();
        for form in [Form::TiedNitsche, Form::TiedInteriorPenalty] {
            let sol = solve_form(&s, form, f64::INFINITY, k, &dirichlet);
            errors.push((
                format!("{form:?}"),
                worst_error(&s.mesh, &sol.temperature, field),
            ));
        }
        for m in [Multipliers::Standard, Multipliers::Dual] {
            let sol = solve_tie(&s, m, k, &dirichlet);
            errors.push((
                format!("{m:?} multipliers"),
                worst_error(&s.mesh, &sol.temperature, field),
            ));
        }
        for (name, e) in errors {
            eprintln!("{n1}:{n2} {name}: worst nodal error {e:.1e} (exact expected: {exact})");
            if exact {
                assert!(e < 1e-12, "{n1}:{n2} {name}: {e:e}");
            }
        }
    }
}

fn tangential_field(p: [f64; 3]) -> f64 {
    1.0 + p[0] + 2.0 * p[1]
}

/// A multiplier tie on a node surface, matching meshes: the constraint holds at every
/// side-A node (its temperature is the coincident side-B node's), and the heat is the
/// face tie's and the exact q = 1/(1/k_A + 1/k_B), standard and dual alike.
#[test]
fn mortar_tie_on_a_node_surface_matches_the_face_tie() {
    let k = [1.0, 5.0];
    let q = 1.0 / (1.0 / k[0] + 1.0 / k[1]);
    let faces = setup(3, 3, SolidKind::Hex8, SideA::Faces);
    let dirichlet = slab_dirichlet(&faces.mesh);
    for side_a in [SideA::NodeSet, SideA::TypeNode] {
        let nodes = setup(3, 3, SolidKind::Hex8, side_a);
        for m in [Multipliers::Standard, Multipliers::Dual] {
            let by_face = solve_tie(&faces, m, k, &dirichlet).tie_heat[0];
            let sol = solve_tie(&nodes, m, k, &dirichlet);
            let by_node = sol.tie_heat[0];
            let diff = (by_node.0 - by_face.0).abs() / by_face.0.abs();
            eprintln!(
                "{side_a:?} {m:?}: heat {:.15} (faces {:.15}), relative difference {diff:.1e}",
                by_node.0, by_face.0
            );
            assert!(diff <= 1e-10, "{side_a:?} {m:?}: {diff:e}");
            assert!((by_node.0 + q).abs() <= 1e-10 * q, "{by_node:?} vs {}", -q);
            assert!((by_node.0 + by_node.1).abs() <= 1e-12 * q);
            // The constraint at the nodes: each side-A node against the side-B node at the
            // same place. The standard tie is a saddle-point solve stopped at 1e-8 ‖F‖
            // after its one (linear) step, whose factorisation leaves ~1e-12 here (the
            // face tie's own jump is printed alongside); the dual tie is condensed.
            let jump = |t: &[f64]| {
                let mut worst = 0.0f64;
                for &(n, x) in &nodes.a.nodes {
                    let partner = (0..nodes.mesh.num_nodes())
                        .find(|&j| j != n.index() && nodes.mesh.coords[j] == x)
                        .expect("a coincident side-B node");
                    worst = worst.max((t[n.index()] - t[partner]).abs());
                }
                worst
            };
            let worst = jump(&sol.temperature);
            let face_jump = jump(&solve_tie(&faces, m, k, &dirichlet).temperature);
            eprintln!(
                "{side_a:?} {m:?}: worst jump at a node {worst:.1e} (face tie {face_jump:.1e})"
            );
            assert!(worst < 1e-11, "{side_a:?} {m:?}: jump {worst:e} at a node");
        }
    }
}

/// Tributary areas of a unit face: they sum to 1 on Quad4 (hexes) and Tri3 (tets); on
/// the 3 × 3 quad grid an interior node has (1/3)², an edge node half, a corner a
/// quarter; every normal is the face's, +z.
#[test]
fn tributary_areas_sum_to_the_surface_area() {
    for kind in [SolidKind::Hex8, SolidKind::Tet4] {
        for side_a in [SideA::NodeSet, SideA::TypeNode] {
            let mesh = slabs(3, 2, kind);
            let set = surfaces(&mesh, side_a);
            let g =
                SurfaceGeometry::from_surface(&mesh, set.get("a").unwrap(), &mesh.coords).unwrap();
            assert_eq!(g.nodes.len(), 16);
            let total: f64 = g.node_area.iter().sum();
            eprintln!("{kind:?} {side_a:?}: Σ A_i − 1 = {:.1e}", total - 1.0);
            assert!((total - 1.0).abs() < 1e-14, "{kind:?}: {total}");
            assert!((g.area() - 1.0).abs() < 1e-14);
            // `seam surfaces` reports the same area.
            assert!((set.get("a").unwrap().area(&mesh) - 1.0).abs() < 1e-14);
            for (k, &(_, x)) in g.nodes.iter().enumerate() {
                let n = g.node_normal[k];
                assert!((n[2] - 1.0).abs() < 1e-14 && n[0].abs() < 1e-14 && n[1].abs() < 1e-14);
                if kind == SolidKind::Hex8 {
                    let on_rim = |c: f64| c == 0.0 || c == 1.0;
                    let rims = [x[0], x[1]].iter().filter(|&&c| on_rim(c)).count();
                    let expect = [1.0 / 9.0, 1.0 / 18.0, 1.0 / 36.0][rims];
                    assert!((g.node_area[k] - expect).abs() < 1e-15, "{x:?}");
                }
            }
        }
    }
}

/// A node set with a node on no exterior face whose nodes all belong to it (one interior
/// node of a top face alone) is reported (W0308, naming the surface), and that node
/// carries nothing rather than an arbitrary area.
#[test]
fn isolated_nodes_are_reported_and_carry_nothing() {
    let mut mesh = slabs(3, 3, SolidKind::Hex8);
    let lone = mesh.node_sets[0].nodes[5];
    mesh.node_sets.push(NodeSet {
        id: 2,
        name: "lone".into(),
        nodes: vec![lone],
    });
    let def = ContactDefinition {
        surfaces: vec![SurfaceDef::NodeSet {
            name: "single".into(),
            contains: vec!["lone".into()],
            at: Loc::default(),
        }],
        ..ContactDefinition::default()
    };
    let set = surfaces::build(&mesh, &def, &SourceMap::default());
    let w: Vec<_> = set
        .diagnostics
        .0
        .iter()
        .filter(|d| d.code == "W0308")
        .collect();
    assert_eq!(w.len(), 1, "{:?}", set.diagnostics);
    assert!(w[0].message.contains("`single`"), "{}", w[0].message);
    let g = SurfaceGeometry::from_surface(&mesh, set.get("single").unwrap(), &mesh.coords).unwrap();
    assert_eq!(g.node_area, vec![0.0]);
}

/// A point of a node surface pairs with its normal: a side-B face whose normal is not
/// opposed to the node's is rejected by the angle check, as for faces; the search's
/// statistics count the matched nodes' tributary areas as the covered area.
#[test]
fn node_points_meet_the_normal_angle_check() {
    let s = setup(3, 3, SolidKind::Hex8, SideA::NodeSet);
    for p in &s.points {
        assert_eq!(p.status, PointStatus::Matched);
        let n = p.normal_a;
        assert!(n[0].abs() < 1e-15 && n[1].abs() < 1e-15 && (n[2] - 1.0).abs() < 1e-15);
    }
    // Side A paired with itself-facing faces: the top of block 2 (normal +z, not opposed).
    let mesh = &s.mesh;
    let ss = mesh.side_sets.iter().position(|ss| ss.id == 4).unwrap();
    let top = SurfaceGeometry::from_side_set(mesh, ss).unwrap();
    let mut moved = s.a.clone();
    for (_, x) in &mut moved.nodes {
        x[2] = 2.0;
    }
    let settings = SearchSettings::defaults(3);
    let r = Searcher::new(&top, &settings).search(
        &moved,
        &top,
        &settings,
        Integration::Quadrature { order: 1 },
        None,
    );
    assert!(
        r.points
            .iter()
            .all(|p| p.status == PointStatus::RejectedAngle),
        "{:?}",
        r.stats
    );
    assert_eq!(r.stats.overlap_area, 0.0);
    // Paired with the facing side B, the whole unit face is covered, as `seam search`
    // reports: side-A area and overlap are the tributary areas' sum.
    let r = Searcher::new(&s.b, &settings).search(
        &s.a,
        &s.b,
        &settings,
        Integration::Quadrature { order: 1 },
        None,
    );
    assert!((r.stats.overlap_area - 1.0).abs() < 1e-14, "{:?}", r.stats);
    assert!((r.stats.side_a_area - 1.0).abs() < 1e-14, "{:?}", r.stats);
}

/// `seam run` end to end, from a problem file, a contact deck and an Exodus mesh (the
/// matching slabs written out, node set `a_top` included): a contact node set and a
/// `Contact Type = node` surface carry the heat of the face surface to 1e-10 relative,
/// and the exact q = 1/(1/k_A + 1/h + 1/k_B), for a resistance, a gap conductance (also
/// a temperature-dependent one written in Lua), a Nitsche tie and standard and dual
/// multiplier ties — nonzero heat, not the 0 W of a dropped surface.
#[test]
fn seam_run_with_a_contact_node_set_carries_the_face_heat() {
    use seam::output::exodus::ExodusWriter;
    let tmp = crate::scratch("node-surfaces-run");
    let dir = tmp.path();
    let mesh = slabs(3, 3, SolidKind::Hex8);
    ExodusWriter::create(&dir.join("slabs.exo"), &mesh, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    let k = [1.0, 5.0];
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"slabs.exo\"\n\
             [[material]]\nblocks = [\"block_1\"]\nconductivity = {}\n\
             [[material]]\nblocks = [\"block_2\"]\nconductivity = {}\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_3\"]\nvalue = 0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 1\n\
             [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-12\n",
            k[0], k[1]
        ),
    )
    .unwrap();
    let side_a = [
        ("faces", "contact surface a contains surface_1"),
        ("contact node set", "contact node set a contains a_top"),
        (
            "contact type = node",
            "begin contact surface a\n  surface = surface_1\n  contact type = node\n end",
        ),
    ];
    let models = [
        ("enforcement for energy = contact_resistance h = 10", 10.0),
        (
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = 10",
            10.0,
        ),
        ("enforcement for energy = tied_temperature", f64::INFINITY),
        (
            "enforcement for energy = tied\n  side b variable temperature to temperature",
            f64::INFINITY,
        ),
        (
            "enforcement for energy = tied multipliers = dual\n  side b variable temperature to temperature",
            f64::INFINITY,
        ),
        // NaN: h = 10 + (T_A + T_B)/2 from Lua, solved by Newton; the exact q below.
        (
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = lua \"10 + 0.5*(temp_a + temp_b)\"",
            f64::NAN,
        ),
    ];
    // The Lua case: T_A = q/k_A and T_B = 1 − q/k_B either side of z = 1, so q is the
    // fixed point of q = 1/(1/k_A + 1/h(q) + 1/k_B), a contraction (|dq/dh| q/h² < 1e-2).
    let lua_q = {
        let mut q = 0.5;
        for _ in 0..200 {
            let h = 10.0 + 0.5 * (q / k[0] + 1.0 - q / k[1]);
            q = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
        }
        q
    };
    for (model, h) in models {
        let q = if h.is_nan() {
            lua_q
        } else {
            1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1])
        };
        let mut face_heat = None;
        for (what, a) in side_a {
            std::fs::write(
                dir.join("contact.i"),
                format!(
                    "begin contact definition\n visualize contact\n {a}\n contact surface b contains surface_2\n\
                     begin interaction\n  side a a\n  side b b\n end\n\
                     begin enforcement\n  {model}\n end\nend\n"
                ),
            )
            .unwrap();
            let r = match seam::run::run(&dir.join("problem.toml")) {
                Ok(r) => r,
                Err(seam::run::RunError::Input(d, s)) => panic!("{what}: {}", d.render(&s)),
                Err(seam::run::RunError::Solve(e)) => panic!("{what}: {e}"),
            };
            assert!(r.summary.converged, "{what} / {model}");
            let i = &r.summary.interactions[0];
            let heat = i.heat_side_a;
            let reference = *face_heat.get_or_insert(heat);
            let diff = (heat - reference).abs() / reference.abs();
            eprintln!(
                "seam run, {what}, {}: heat {heat:.15}, exact {:.15}, against faces {diff:.1e}",
                model.lines().next().unwrap(),
                -q
            );
            assert!(
                (heat + q).abs() <= 1e-10 * q,
                "{what} / {model}: {heat} vs {}",
                -q
            );
            assert!(diff <= 1e-10, "{what} / {model}: {diff:e}");
            assert!(
                i.imbalance.abs() <= 1e-12 * q,
                "{what}: imbalance {}",
                i.imbalance
            );
        }
    }
}

/// Aria's masking reaches node surfaces: a convection condition on the faces under a
/// contact node set (its tributary faces, which the nodes cover) is masked like one under
/// a face surface (W0701), so it changes nothing — unless `no_coverage_flux = true`.
#[test]
fn face_conditions_under_a_contact_node_set_are_masked() {
    use seam::output::exodus::ExodusWriter;
    let tmp = crate::scratch("node-surfaces-mask");
    let dir = tmp.path();
    let mesh = slabs(3, 3, SolidKind::Hex8);
    ExodusWriter::create(&dir.join("slabs.exo"), &mesh, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        "begin contact definition\n contact node set a contains a_top\n contact surface b contains surface_2\n\
         begin interaction\n  side a a\n  side b b\n end\n\
         begin enforcement\n  enforcement for energy = contact_resistance h = 10\n end\nend\n",
    )
    .unwrap();
    let run = |extra: &str| {
        std::fs::write(
            dir.join("problem.toml"),
            format!(
                "[mesh]\nfile = \"slabs.exo\"\n\
                 [[material]]\nblocks = [\"block_1\", \"block_2\"]\nconductivity = 1.0\n\
                 [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_3\"]\nvalue = 0\n\
                 [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 1\n{extra}\
                 [contact]\nfile = \"contact.i\"\n"
            ),
        )
        .unwrap();
        match seam::run::run(&dir.join("problem.toml")) {
            Ok(r) => (
                r.solution.temperature,
                r.warnings.0.iter().map(|d| d.code).collect::<Vec<_>>(),
            ),
            Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
            Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
        }
    };
    let convection =
        "[[bc]]\nkind = \"convection\"\nsurfaces = [\"surface_1\"]\nvalue = 50.0\nambient = 5.0\n";
    let (plain, _) = run("");
    let (masked, codes) = run(convection);
    let (kept, _) = run(&format!("{convection}no_coverage_flux = true\n"));
    let diff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    // Round-off apart (a parallel factorisation may sum in another order).
    assert!(diff(&plain, &masked) < 1e-12, "{}", diff(&plain, &masked));
    assert!(codes.contains(&"W0701"), "{codes:?}");
    assert!(
        diff(&plain, &kept) > 0.1,
        "an unmasked hot convection heats the interface"
    );
}

/// The Jacobian of the node-to-face form with a temperature-dependent conductance
/// (h = 2 + T_A/2 + T_B²/4), resistance and Robin–Nitsche, on non-matching meshes: every
/// column of the assembled blocks against central differences of the residual (step
/// 1e-6; agreement to 1e-7 of the largest entry, the differences' own truncation error).
#[test]
fn node_point_jacobian_matches_finite_differences() {
    use seam::assembly::DofMap;
    use seam::enforce::interface::InterfacePoints;
    let s = setup(3, 2, SolidKind::Hex8, SideA::NodeSet);
    let dofs = DofMap::new(&s.mesh, &[("temperature", &[0, 1])]).unwrap();
    let field = dofs.field("temperature").unwrap();
    let n = dofs.len();
    let k = [1.0, 5.0];
    let hf = |i: &HInput| {
        Ok(HValue {
            h: 2.0 + 0.5 * i.temp_a + 0.25 * i.temp_b * i.temp_b,
            dh_dtemp_a: 0.5,
            dh_dtemp_b: 0.5 * i.temp_b,
            ..HValue::default()
        })
    };
    for form in [Form::Conductance, Form::GapConductance] {
        let f = InterfaceForm {
            form,
            h: &hf,
            offset: 0.1,
            beta: DEFAULT_BETA,
            conductivity: &k,
            conductivity_of_t: None,
            temperature_field: None,
        };
        let points =
            InterfacePoints::new(&s.mesh, &dofs, field, &s.a, &s.b, &s.points, &f).unwrap();
        assert_eq!(points.len(), 16, "every interface node is a point");
        let u: Vec<f64> = (0..n).map(|i| 1.0 + 0.3 * (0.7 * i as f64).sin()).collect();
        let residual = |u: &[f64]| {
            let mut r = vec![0.0; n];
            for (d, v) in points.evaluate(&f, u).unwrap().residual {
                r[d as usize] += v;
            }
            r
        };
        let sys = points.evaluate(&f, &u).unwrap();
        let mut jac = vec![0.0; n * n];
        for (d, m) in &sys.blocks {
            let nl = d.len();
            for a in 0..nl {
                for b in 0..nl {
                    jac[d[a] as usize * n + d[b] as usize] += m[a * nl + b];
                }
            }
        }
        let largest = jac.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut columns: Vec<u32> = sys.residual.iter().map(|&(d, _)| d).collect();
        columns.dedup();
        let eps = 1e-6;
        let mut worst = 0.0f64;
        for &j in &columns {
            let (mut up, mut down) = (u.clone(), u.clone());
            up[j as usize] += eps;
            down[j as usize] -= eps;
            let (rp, rm) = (residual(&up), residual(&down));
            for i in 0..n {
                let fd = (rp[i] - rm[i]) / (2.0 * eps);
                worst = worst.max((fd - jac[i * n + j as usize]).abs());
            }
        }
        eprintln!("{form:?}: worst Jacobian entry error {worst:.1e} of {largest:.1e}");
        assert!(
            worst <= 1e-7 * largest,
            "{form:?}: {worst:e} of {largest:e}"
        );
    }
}

/// A transient `seam run` (backward Euler, the general Newton solver) through a contact
/// node set: the slabs start at 0 and the top is held at 1. The solution stays uniform
/// in x and y, so with a constant conductance the node-to-face and face forms are the
/// same discrete equations (∫ h [u] N_i = h [u] A_i when [u] is uniform): the final
/// temperatures and heat agree to round-off, and the heat is not zero.
#[test]
fn transient_run_through_a_contact_node_set_matches_the_face_surface() {
    use seam::output::exodus::ExodusWriter;
    let tmp = crate::scratch("node-surfaces-transient");
    let dir = tmp.path();
    let mesh = slabs(3, 3, SolidKind::Hex8);
    ExodusWriter::create(&dir.join("slabs.exo"), &mesh, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    std::fs::write(
        dir.join("problem.toml"),
        "[mesh]\nfile = \"slabs.exo\"\n[initial]\ntemperature = 0.0\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = 1.0\nrho_c = 1.0\n\
         [[material]]\nblocks = [\"block_2\"]\nconductivity = 5.0\nrho_c = 2.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_3\"]\nvalue = 0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 1\n\
         [contact]\nfile = \"contact.i\"\n\
         [solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 0.05\nend_time = 0.5\n",
    )
    .unwrap();
    let run = |side_a: &str| {
        std::fs::write(
            dir.join("contact.i"),
            format!(
                "begin contact definition\n {side_a}\n contact surface b contains surface_2\n\
                 begin interaction\n  side a a\n  side b b\n end\n\
                 begin enforcement\n  enforcement for energy = contact_resistance h = 10\n end\nend\n"
            ),
        )
        .unwrap();
        match seam::run::run(&dir.join("problem.toml")) {
            Ok(r) => {
                assert!(r.summary.converged);
                (
                    r.solution.temperature,
                    r.summary.interactions[0].heat_side_a,
                )
            }
            Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
            Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
        }
    };
    let (t_face, q_face) = run("contact surface a contains surface_1");
    let (t_node, q_node) = run("contact node set a contains a_top");
    let worst = t_face
        .iter()
        .zip(&t_node)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    let diff = (q_node - q_face).abs() / q_face.abs();
    eprintln!(
        "transient: worst nodal difference {worst:.1e}, heat {q_node:.15} against faces {q_face:.15} ({diff:.1e})"
    );
    assert!(q_face.abs() > 0.1, "heat crosses: {q_face}");
    assert!(worst < 1e-12, "{worst:e}");
    assert!(diff <= 1e-10, "{diff:e}");
}
