//! 2-D models through `seam run` (plane, unit depth): the patch tests of every tie and of
//! a gap conductance across non-matching interfaces, with Quad4 and Tri3 on either side.
//! Each case writes its mesh (Exodus), deck and problem file, runs the whole pipeline
//! (surfaces, search, scene, enforcement, solve) and compares the nodal temperatures
//! with the exact field.

use std::path::{Path, PathBuf};

use seam::mesh::Mesh;
use seam::mesh::generate::{self, PlaneKind, RectSpec};
use seam::output::exodus::ExodusWriter;
use seam::run::{RunError, RunResult};

use crate::scratch;

pub(crate) fn write_mesh(path: &Path, m: &Mesh) {
    ExodusWriter::create(path, m, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
}

pub(crate) fn run(problem: &Path) -> RunResult {
    match seam::run::run(problem) {
        Ok(r) => r,
        Err(RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(RunError::Solve(e)) => panic!("{e}"),
    }
}

/// A steady problem file: the mesh `mesh` (a path, as TOML writes a string), read
/// axisymmetric or not, the conductivity of each block, temperature conditions (side
/// set, value as TOML: a number or a quoted Lua expression), `extra` lines (sources,
/// output) and the deck `contact.i`.
pub(crate) fn problem_text(
    mesh: &str,
    axisymmetric: bool,
    materials: &[(&str, f64)],
    temperatures: &[(&str, &str)],
    extra: &str,
) -> String {
    let mut t = format!("[mesh]\nfile = {mesh:?}\naxisymmetric = {axisymmetric}\n");
    for (block, k) in materials {
        t += &format!("[[material]]\nblocks = [\"{block}\"]\nconductivity = {k}\n");
    }
    for (set, value) in temperatures {
        t += &format!("[[bc]]\nkind = \"temperature\"\nsurfaces = [\"{set}\"]\nvalue = {value}\n");
    }
    t + extra + "[contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-13\n"
}

/// A contact deck of one interaction: side A `a` made by the line `a_line` (`contact
/// surface a contains …`, or `contact node set a contains …`), side B `b` of side set
/// `b_set`, `extra` definition lines, and the enforcement `model` (its lines).
pub(crate) fn pair_deck(a_line: &str, b_set: &str, extra: &str, model: &str) -> String {
    format!(
        "begin contact definition\n {a_line}\n contact surface b contains {b_set}\n{extra}\
         begin interaction\n  side a a\n  side b b\n end\n\
         begin enforcement\n  {model}\n end\nend\n"
    )
}

/// The series problem of two parts (300 K on side set `cold`, 400 K on `hot`, the
/// conductivities `k` of `blocks`), with `extra` lines.
fn series_problem(
    mesh: &str,
    axisymmetric: bool,
    blocks: [&str; 2],
    [cold, hot]: [&str; 2],
    k: [f64; 2],
    extra: &str,
) -> String {
    let materials = [(blocks[0], k[0]), (blocks[1], k[1])];
    problem_text(
        mesh,
        axisymmetric,
        &materials,
        &[(cold, "300"), (hot, "400")],
        extra,
    )
}

/// The blocks and the temperature side sets of the libexodus and gmsh contact meshes.
const PARTS: ([&str; 2], [&str; 2]) = (["lower", "upper"], ["lower_bottom", "upper_top"]);

/// A gap conductance h = 10 and a dual multiplier tie (h = ∞), as deck lines with h.
const GAP_AND_TIE: [(&str, f64); 2] = [
    (
        "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = 10",
        10.0,
    ),
    (
        "enforcement for energy = tied multipliers = dual\n  side b variable temperature to temperature",
        f64::INFINITY,
    ),
];

/// `pair_deck` of side sets `surface_1` (side A) and `surface_2`.
fn rectangles_deck(model: &str) -> String {
    pair_deck(
        "contact surface a contains surface_1",
        "surface_2",
        "",
        model,
    )
}

/// Two rectangles meshed apart: block 1 on [0, 1] × [0, 1] (`n1` cells across, 2 up),
/// block 2 on [0, 1] × [1, 2] (`n2` across, 3 up), each of its own kind. Side sets: 1 the
/// top of block 1, 2 the bottom of block 2, 3 the rest of block 1's boundary but its
/// top (bottom, left and right), 4 the same of block 2; 5 block 1's bottom, 6 block 2's
/// top.
fn two_rectangles(n1: usize, k1: PlaneKind, n2: usize, k2: PlaneKind) -> Mesh {
    let spec = |min, max, n, kind, id, sets| {
        RectSpec {
            kind,
            ..RectSpec::quad(min, max, [n, if id == 1 { 2 } else { 3 }], id)
        }
        .with_side_sets(sets)
    };
    let mut m = generate::rectangles(
        &[
            spec([0.0, 0.0], [1.0, 1.0], n1, k1, 1, [3, 3, 5, 1]),
            spec([0.0, 1.0], [1.0, 2.0], n2, k2, 2, [4, 4, 2, 6]),
        ],
        false,
    );
    // The bottom (5) and top (6) edges belong to the Dirichlet sets too.
    copy_sides(&mut m, [(5, 3), (6, 4)]);
    m
}

/// Add the sides of side set `from` to side set `to`, for each pair.
fn copy_sides(m: &mut Mesh, pairs: [(i64, i64); 2]) {
    for (from, to) in pairs {
        let sides = m
            .side_sets
            .iter()
            .find(|s| s.id == from)
            .unwrap()
            .sides
            .clone();
        let set = m.side_sets.iter_mut().find(|s| s.id == to).unwrap();
        set.sides.extend(sides);
    }
}

const KINDS: [(PlaneKind, &str); 2] = [(PlaneKind::Quad4, "quad4"), (PlaneKind::Tri3, "tri3")];

/// The worst nodal error of a run against `exact`.
fn worst_error(r: &RunResult, exact: impl Fn([f64; 3]) -> f64) -> f64 {
    worst_error_by_part(r, |_, x| exact(x))
}

/// The last node of block 1 of two parts meshed apart (the generators number block 1's
/// nodes first): nodes up to it are part 0, the rest part 1.
pub(crate) fn last_node_of_block_1(mesh: &Mesh) -> usize {
    mesh.blocks[0]
        .connectivity
        .iter()
        .map(|n| n.index())
        .max()
        .unwrap()
}

/// The worst nodal error of a run of two parts meshed apart against `exact(part, x)`.
pub(crate) fn worst_error_by_part(r: &RunResult, exact: impl Fn(usize, [f64; 3]) -> f64) -> f64 {
    let last = last_node_of_block_1(&r.mesh);
    r.mesh
        .coords
        .iter()
        .zip(&r.solution.temperature)
        .enumerate()
        .map(|(n, (x, t))| (t - exact(usize::from(n > last), *x)).abs())
        .fold(0.0, f64::max)
}

/// The refinements of the periodic cases.
const SIZES: [usize; 3] = [4, 8, 16];

/// Successive errors of a periodic case and, in the second column, of the same case with
/// insulated edges instead: the first falls at second order (each rate above 1.8), the
/// second does not fall (a control showing the periodicity carries the field).
fn assert_periodic_rates(label: &str, ns: &[usize], errors: &[Vec<f64>]) {
    for (n, row) in ns.iter().zip(errors) {
        eprintln!(
            "{label}, n = {n}: worst nodal error {:.3e} (insulated edges instead: {:.3e})",
            row[0], row[1]
        );
    }
    for w in errors.windows(2) {
        let rate = (w[0][0] / w[1][0]).log2();
        eprintln!("{label}: rate {rate:.2}");
        assert!(rate > 1.8, "rate {rate}");
        assert!(w[1][1] > 0.5 * w[0][1], "insulated edges converge?");
    }
}

/// Patch test in 2-D: T = 1 + 2x + 3y, given on the whole outer boundary, crosses the
/// non-matching interface y = 1 (3 against 4 cells, 4 against 7; Quad4 and Tri3 on
/// either side) exactly for every tie — Nitsche, interior penalty, standard and dual
/// multipliers — with segment (mortar) integration. k = 2 on both sides: a linear field
/// is the exact solution only when the flux −k∇T does not jump. Round-off: nodal values
/// ~10 with condition numbers ~1e3 give ~1e-13; the bound is 1e-11. (With quadrature
/// integration of order 1 instead, not exact on non-matching meshes, the Nitsche case is
/// off by 4.6e-2: the test can fail.)
#[test]
fn linear_field_crosses_non_matching_2d_ties_exactly() {
    let tmp = scratch("twod-patch-ties");
    let dir = tmp.path();
    let exact = |x: [f64; 3]| 1.0 + 2.0 * x[0] + 3.0 * x[1];
    let ties = [
        ("nitsche", "enforcement for energy = tied_temperature"),
        (
            "interior penalty",
            "enforcement for energy = tied_ip_temperature",
        ),
        (
            "standard multipliers",
            "enforcement for energy = tied\n  side b variable temperature to temperature",
        ),
        (
            "dual multipliers",
            "enforcement for energy = tied multipliers = dual\n  side b variable temperature to temperature",
        ),
    ];
    let linear = "\"1 + 2*x + 3*y\"";
    let problem = problem_text(
        "rects.exo",
        false,
        &[("block_1", 2.0), ("block_2", 2.0)],
        &[("surface_3", linear), ("surface_4", linear)],
        "",
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    let mut worst_all = 0.0f64;
    for (n1, n2) in [(3, 4), (4, 7)] {
        for (k1, name1) in KINDS {
            for (k2, name2) in KINDS {
                write_mesh(&dir.join("rects.exo"), &two_rectangles(n1, k1, n2, k2));
                for (tie, model) in ties {
                    std::fs::write(dir.join("contact.i"), rectangles_deck(model)).unwrap();
                    let r = run(&dir.join("problem.toml"));
                    let worst = worst_error(&r, exact);
                    eprintln!(
                        "2-D patch, {tie}, {name1} {n1} / {name2} {n2}: worst nodal error {worst:.1e}"
                    );
                    assert!(
                        worst <= 1e-11,
                        "{tie}, {name1} {n1} / {name2} {n2}: {worst:e}"
                    );
                    worst_all = worst_all.max(worst);
                }
            }
        }
    }
    eprintln!("2-D tie patch tests: worst nodal error {worst_all:.1e}");
}

/// A piecewise-linear field across a 2-D gap conductance: T = 0 at y = 0, T = 1 at y =
/// 2, insulated sides, k₁ = 1 below the interface y = 1 and k₂ = 5 above, h = 10. The
/// flux is q = 1/(1/k₁ + 1/h + 1/k₂) and the jump q/h; the finite-element space holds
/// this field (linear on either side), so the solve gives it to round-off, on
/// non-matching Quad4 and Tri3 meshes, and the interface heat per unit depth is q × 1.
#[test]
fn piecewise_linear_field_crosses_a_2d_gap_conductance_exactly() {
    let tmp = scratch("twod-patch-gap");
    let dir = tmp.path();
    let (k1, k2, h) = (1.0, 5.0, 10.0);
    let q = 1.0 / (1.0 / k1 + 1.0 / h + 1.0 / k2);
    let problem = problem_text(
        "rects.exo",
        false,
        &[("block_1", k1), ("block_2", k2)],
        &[("surface_5", "0"), ("surface_6", "1")],
        "",
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    let model = format!(
        "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = {h}"
    );
    std::fs::write(dir.join("contact.i"), rectangles_deck(&model)).unwrap();
    let mut worst_all = 0.0f64;
    for (n1, n2) in [(3, 4), (5, 2)] {
        for (kind1, name1) in KINDS {
            for (kind2, name2) in KINDS {
                let mesh = two_rectangles(n1, kind1, n2, kind2);
                write_mesh(&dir.join("rects.exo"), &mesh);
                let r = run(&dir.join("problem.toml"));
                let worst = worst_error_by_part(&r, |part, x| {
                    if part == 0 {
                        q * x[1] / k1
                    } else {
                        1.0 - q * (2.0 - x[1]) / k2
                    }
                });
                let i = &r.summary.interactions[0];
                let heat_error = (i.heat_side_a + q).abs() / q;
                eprintln!(
                    "2-D gap conductance, {name1} {n1} / {name2} {n2}: worst nodal error {worst:.1e}, heat {:.15} (exact {:.15}, {heat_error:.1e})",
                    i.heat_side_a, -q
                );
                assert!(worst <= 1e-12, "{name1} {n1} / {name2} {n2}: {worst:e}");
                assert!(
                    heat_error <= 1e-12,
                    "{name1} / {name2}: heat {heat_error:e}"
                );
                assert!(i.imbalance.abs() <= 1e-13, "imbalance {}", i.imbalance);
                worst_all = worst_all.max(worst);
            }
        }
    }
    eprintln!("2-D gap-conductance patch tests: worst nodal error {worst_all:.1e}");
}

/// The series heat of the 2-D two-rectangle case (300 K at y = 0, 400 K at y = 2, k₁
/// below y = 1, k₂ above, insulated sides) through an interface of conductance
/// `h(T_A, T_B)`: the field is linear on either side, so with T_A = 300 + q/k₁ and T_B =
/// 400 − q/k₂ the flux solves q = h (T_B − T_A); found by bisection on [0, q_tied] (the
/// right-hand side falls as q grows for every h ≥ 0 here).
fn series_flux(k: [f64; 2], h: impl Fn(f64, f64) -> f64) -> f64 {
    let residual = |q: f64| {
        let (ta, tb) = (300.0 + q / k[0], 400.0 - q / k[1]);
        q - h(ta, tb) * (tb - ta)
    };
    let (mut lo, mut hi) = (0.0, 100.0 / (1.0 / k[0] + 1.0 / k[1]));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if residual(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Run `dir`'s problem with `deck` as its contact deck: the run, and the relative error
/// of both sides' heats against the series value of `h` over the interface's `area`
/// (1 per unit depth, π per revolution over the disc r < 1), printed with `label`.
fn series_heat_error(
    dir: &Path,
    deck: &str,
    k: [f64; 2],
    h: impl Fn(f64, f64) -> f64,
    area: f64,
    label: &str,
) -> (RunResult, f64) {
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    let r = run(&dir.join("problem.toml"));
    assert!(r.summary.converged, "{label}");
    let q = series_flux(k, h) * area;
    let i = &r.summary.interactions[0];
    let err = (i.heat_side_a + q).abs().max((i.heat_side_b - q).abs()) / q;
    eprintln!(
        "{label}: heat {:.12} / {:.12}, series {q:.12}, relative {err:.1e}",
        i.heat_side_a, i.heat_side_b
    );
    (r, err)
}

/// Every enforcement model and every conductance law through the 2-D scene pipeline
/// (`seam run`, non-matching Quad4 / Tri3 meshes, segment integration): the interface
/// heat per unit depth is the series value of the model's h — constant, gas gap at
/// zero gap (h = k/g_min), radiation and a Lua law (nonlinear in T, solved by Newton),
/// CMY at a contact pressure, a table in pressure, the C table plugin, the Dash penalty
/// (h = β_D k_eff/h_e, the penalty of docs/theory.md with h_e the smaller element
/// area over edge length) and the ties (no resistance) — and the heats of the two
/// sides balance. The field is linear either side, which the elements hold, so what
/// is left is round-off and Newton's tolerance: 1e-9 relative.
#[test]
fn every_model_carries_the_series_heat_in_2d() {
    let tmp = scratch("twod-every-model");
    let dir = tmp.path();
    let k = [1.0, 5.0];
    crate::examples::compile_c_table(dir);
    let rectangles = (["block_1", "block_2"], ["surface_5", "surface_6"]);
    let problem = series_problem("rects.exo", false, rectangles.0, rectangles.1, k, "");
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    let sigma = seam::heat::STEFAN_BOLTZMANN;
    let radiation =
        move |a: f64, b: f64| sigma * (a * a + b * b) * (a + b) / (1.0 / 0.8 + 1.0 / 0.6 - 1.0);
    // CMY: 1.25 k_s (m/σ_s)(p/H)^0.95 with the harmonic mean k_s of K_A = 1, K_B = 5.
    let cmy = 1.25 * (2.0 * 5.0 / 6.0) * (0.1 / 1e-6) * (1e6f64 / 3e9).powf(0.95);
    let plugin = format!(
        "enforcement for energy = plugin library = \"{}\" model = c_table\n  real data = 0 1000  1e6 5000  4e6 6500\n  contact pressure = 2e6",
        crate::examples::PLUGIN_LIBRARY
    );
    type H = Box<dyn Fn(f64, f64) -> f64>;
    let constant = |h: f64| -> H { Box::new(move |_, _| h) };
    let models: Vec<(&str, String, H)> = vec![
        (
            "contact resistance",
            "enforcement for energy = contact_resistance h = 10".into(),
            constant(10.0),
        ),
        (
            "constant",
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = 10".into(),
            constant(10.0),
        ),
        (
            "gas gap",
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = gas_gap k = 0.025 min_gap = 1e-3".into(),
            constant(25.0),
        ),
        (
            "radiation",
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = radiation emissivity_a = 0.8 emissivity_b = 0.6".into(),
            Box::new(radiation),
        ),
        (
            "cmy",
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = cmy k_a = 1 k_b = 5 slope = 0.1 roughness = 1e-6 hardness = 3e9\n  contact pressure = 1e6".into(),
            constant(cmy),
        ),
        (
            "table of pressure",
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = table of pressure = 0 10 2e6 30\n  contact pressure = 1e6".into(),
            constant(20.0),
        ),
        (
            "lua",
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = lua \"10 + 0.01*(temp_a + temp_b)\"".into(),
            Box::new(|a, b| 10.0 + 0.01 * (a + b)),
        ),
        ("plugin", plugin, constant(5500.0)),
        (
            "nitsche tie",
            "enforcement for energy = tied_temperature".into(),
            constant(f64::INFINITY),
        ),
        (
            "dual multiplier tie",
            "enforcement for energy = tied multipliers = dual\n  side b variable temperature to temperature".into(),
            constant(f64::INFINITY),
        ),
    ];
    let mut worst = 0.0f64;
    for (kinds, name) in [
        ((PlaneKind::Quad4, PlaneKind::Tri3), "quad4 3 / tri3 4"),
        ((PlaneKind::Tri3, PlaneKind::Quad4), "tri3 3 / quad4 4"),
    ] {
        let mesh = two_rectangles(3, kinds.0, 4, kinds.1);
        write_mesh(&dir.join("rects.exo"), &mesh);
        // Dash: h = β_D k_eff / h_e, h_e the smaller area / edge length: 1/2 and 1/3 for
        // the quads (cells 1/2 and 1/3 high), half that for triangles.
        let h_e = |kind, height: f64| match kind {
            PlaneKind::Quad4 => height,
            PlaneKind::Tri3 => 0.5 * height,
        };
        let dash = 2.0 * (2.0 * k[0] * k[1] / (k[0] + k[1]))
            / h_e(kinds.0, 0.5).min(h_e(kinds.1, 1.0 / 3.0));
        let dash_h = move |_: f64, _: f64| dash;
        let dash_line = "enforcement for energy = dash\n  dash penalty factor = 2".to_string();
        let cases = models
            .iter()
            .map(|(m, l, h)| (*m, l.clone(), &**h))
            .chain(std::iter::once((
                "dash",
                dash_line,
                &dash_h as &dyn Fn(f64, f64) -> f64,
            )));
        for (model, lines, h) in cases {
            let deck = rectangles_deck(&lines);
            let label = format!("2-D {model:<20} {name} (W/m)");
            let (_, err) = series_heat_error(dir, &deck, k, h, 1.0, &label);
            assert!(err <= 1e-9, "{model}, {name}: {err:e}");
            worst = worst.max(err);
        }
    }
    eprintln!("2-D models: worst relative heat error {worst:.1e}");
}

/// A contact node set in 2-D: side A is block 1's nodes on y = 1, each weighted by its
/// tributary length from the edges around it (node-to-face form), against block 2's
/// edges. On matching edges (3 cells against 3; Quad4 below, Tri3 above) the collocated
/// form is exact for this one-dimensional field and the heat is the series value, for a
/// gap conductance and a dual multiplier tie; on non-matching ones (3 against 4) side
/// B's rows integrate q N_B at side A's nodes, which is not exact (the node-to-segment
/// limitation, as in 3-D: docs/verification.md), so only the balance is asserted there
/// and the heat's error is printed.
#[test]
fn contact_node_set_carries_the_series_heat_in_2d() {
    let tmp = scratch("twod-node-set");
    let dir = tmp.path();
    let k = [1.0, 5.0];
    let (blocks, sets) = (["block_1", "block_2"], ["surface_5", "surface_6"]);
    let problem = series_problem("rects.exo", false, blocks, sets, k, "");
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    for n2 in [3, 4] {
        let mut mesh = two_rectangles(3, PlaneKind::Quad4, n2, PlaneKind::Tri3);
        let top: Vec<seam::mesh::NodeId> = (0..=last_node_of_block_1(&mesh))
            .filter(|&n| mesh.coords[n][1] == 1.0)
            .map(|n| seam::mesh::NodeId(n as u32))
            .collect();
        assert_eq!(top.len(), 4, "block 1 has 4 nodes on y = 1");
        mesh.node_sets.push(seam::mesh::NodeSet {
            id: 1,
            name: "a_top".into(),
            nodes: top,
        });
        write_mesh(&dir.join("rects.exo"), &mesh);
        for (model, h) in GAP_AND_TIE {
            let deck = pair_deck("contact node set a contains a_top", "surface_2", "", model);
            let label = format!(
                "2-D contact node set, 3 / {n2} edges, {} (W/m)",
                model.lines().next().unwrap()
            );
            let (r, err) = series_heat_error(dir, &deck, k, |_, _| h, 1.0, &label);
            let (i, q) = (&r.summary.interactions[0], series_flux(k, |_, _| h));
            if n2 == 3 {
                assert!(err <= 1e-10, "{model}: {err:e}");
            } else {
                assert!(err <= 1e-2, "{model}: {err:e}");
            }
            assert!(i.imbalance.abs() <= 1e-12 * q, "imbalance {}", i.imbalance);
        }
    }
}

/// Rectangular periodicity in 2-D: the unit square in two blocks meshed apart (x < ½
/// with n × 3n/2 cells, x > ½ with n × 2n, tied at x = ½), T = sin 2πx at y = 0 and 0 at
/// y = 1, the left edge periodic with the right (`Rectangular Offset = 1 0`, tied;
/// non-matching, 3n/2 against 2n edges). The exact field is
/// T = sin 2πx · sinh 2π(1 − y) / sinh 2π; the nodal error falls at second order (rate
/// above 1.8 from n = 4 to 8 and 8 to 16), and without the periodicity (insulated
/// sides) it does not fall at all. The same translation as a Lua map (`Mapped X_Map =
/// "x + 1"`) gives the same field to round-off.
#[test]
fn rectangular_periodicity_converges_in_2d() {
    let tmp = scratch("twod-periodic");
    let dir = tmp.path();
    let tau = std::f64::consts::TAU;
    let exact = move |x: [f64; 3]| (tau * x[0]).sin() * (tau * (1.0 - x[1])).sinh() / tau.sinh();
    std::fs::write(
        dir.join("problem.toml"),
        "[mesh]\nfile = \"square.exo\"\n\
         [[material]]\nblocks = [\"block_1\", \"block_2\"]\nconductivity = 1.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_5\"]\nvalue = \"math.sin(2*math.pi*x)\"\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_6\"]\nvalue = 0\n\
         [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-12\n",
    )
    .unwrap();
    let deck = |periodicity: &str| {
        format!(
            "begin contact definition\n contact surface mid_a contains surface_2\n contact surface mid_b contains surface_3\n\
             contact surface left contains surface_1\n contact surface right contains surface_4\n{periodicity}\
             begin interaction\n  side a mid_a\n  side b mid_b\n end\n\
             begin enforcement\n  enforcement for energy = tied_temperature\n end\nend\n"
        )
    };
    let rectangular = " periodicity for left = rectangular offset = 1 0\n";
    let mut errors = Vec::new();
    for n in SIZES {
        let mut m = generate::rectangles(
            &[
                RectSpec::quad([0.0, 0.0], [0.5, 1.0], [n, 3 * n / 2], 1)
                    .with_side_sets([1, 2, 5, 6]),
                RectSpec::quad([0.5, 0.0], [1.0, 1.0], [n, 2 * n], 2).with_side_sets([3, 4, 7, 8]),
            ],
            false,
        );
        // Bottom and top of both blocks in one set each.
        copy_sides(&mut m, [(7, 5), (8, 6)]);
        write_mesh(&dir.join("square.exo"), &m);
        let mut row = Vec::new();
        let mut periodic_field = Vec::new();
        for periodicity in [rectangular, ""] {
            std::fs::write(dir.join("contact.i"), deck(periodicity)).unwrap();
            let r = run(&dir.join("problem.toml"));
            if !periodicity.is_empty() {
                let i = &r.summary.interactions[1];
                assert!(
                    i.imbalance.abs() <= 1e-12,
                    "periodic imbalance {}",
                    i.imbalance
                );
                periodic_field = r.solution.temperature.clone();
            }
            row.push(worst_error(&r, exact));
        }
        if n == 8 {
            // The same translation written as a Lua map gives the same field.
            let lua = " periodicity for left = mapped x_map = \"x + 1\" y_map = \"y\"\n";
            std::fs::write(dir.join("contact.i"), deck(lua)).unwrap();
            let r = run(&dir.join("problem.toml"));
            let apart = r
                .solution
                .temperature
                .iter()
                .zip(&periodic_field)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            eprintln!(
                "2-D periodic square, n = 8: the Lua map's field {apart:.1e} from the offset's"
            );
            assert!(apart <= 1e-12, "{apart}");
        }
        errors.push(row);
    }
    assert_periodic_rates("2-D periodic square", &SIZES, &errors);
}

/// Cylindrical periodicity in plane 2-D: a quarter of the annulus 1 < r < 2 (`ring`,
/// 90°, Quad4), T = sin 4θ on r = 1 and 0 on r = 2, its θ = 0 edge periodic with the θ =
/// 90° edge by a turn of 90° about z. The exact field is
/// T = sin 4θ (r⁴ − 2⁸ r⁻⁴)/(1 − 2⁸), whose flux crosses the two edges; the nodal error
/// falls at second order (rate above 1.8 over two refinements), while with insulated
/// edges instead it stays put.
#[test]
fn cylindrical_periodicity_converges_in_plane_2d() {
    let tmp = scratch("twod-periodic-ring");
    let dir = tmp.path();
    let exact = |x: [f64; 3]| {
        let (r, t) = (x[0].hypot(x[1]), x[1].atan2(x[0]));
        (4.0 * t).sin() * (r.powi(4) - 256.0 / r.powi(4)) / (1.0 - 256.0)
    };
    let problem = "[mesh]\nfile = \"ring.exo\"\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = 1.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = \"math.sin(4*math.atan(y, x))\"\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_2\"]\nvalue = 0\n\
         [solve]\nkind = \"steady\"\ntolerance = 1e-12\n";
    std::fs::write(dir.join("insulated.toml"), problem).unwrap();
    std::fs::write(
        dir.join("problem.toml"),
        format!("{problem}[contact]\nfile = \"contact.i\"\n"),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        "begin contact definition\n contact surface start contains surface_3\n contact surface stop contains surface_4\n\
         periodicity for start = cylindrical axis = 0 0 1 center = 0 0 0 angle = 90\n\
         begin enforcement\n  enforcement for energy = tied_temperature\n end\nend\n",
    )
    .unwrap();
    let mut errors = Vec::new();
    for n in SIZES {
        let m = generate::ring(
            1.0,
            2.0,
            90.0,
            [n, 2 * n],
            PlaneKind::Quad4,
            1,
            [1, 2, 3, 4],
        );
        write_mesh(&dir.join("ring.exo"), &m);
        let mut row = Vec::new();
        for file in ["problem.toml", "insulated.toml"] {
            let r = run(&dir.join(file));
            if let Some(i) = r.summary.interactions.first() {
                assert!(i.imbalance.abs() <= 1e-12, "imbalance {}", i.imbalance);
            }
            row.push(worst_error(&r, exact));
        }
        errors.push(row);
    }
    assert_periodic_rates("2-D quarter ring", &SIZES, &errors);
}

/// The 2-D contact mesh written by the Exodus II C library (tests/exodus/write_fixtures.c,
/// `contact2d`: QUAD4 below, TRI3 above, 3 against 4 edges at y = 1; the committed copy,
/// or `SEAM_EXODUS_REFERENCE_DIR`'s fresh one), in each netCDF flavour, run plane and
/// axisymmetric with the deck naming its side sets by their stored names: 300 K at y =
/// 0, 400 K at y = 2, a gap conductance or a dual tie between the parts. The field is
/// axial and linear either side, so the heat is the series value exactly — per unit
/// depth over the unit width plane, per revolution over the disc r < 1 (× π)
/// axisymmetric. With `SEAM_EXODUS_CHECKER` (CI: tests/exodus/check_results.c) the C
/// library also reads the `results.exo` of each run and compares it with the mesh.
#[test]
fn exodus_writer_2d_runs_on_the_libexodus_contact_mesh() {
    let reference = match std::env::var_os("SEAM_EXODUS_REFERENCE_DIR") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/reference"),
    };
    let tmp = scratch("twod-libexodus-contact2d");
    let dir = tmp.path();
    let k = [1.0, 5.0];
    for flavour in ["classic", "offset64", "nc4"] {
        // Absolute: the problem file's paths are relative to its own folder.
        let mesh =
            std::fs::canonicalize(reference.join(format!("contact2d_{flavour}.exo"))).unwrap();
        for axisymmetric in [false, true] {
            for (model, h) in GAP_AND_TIE {
                let problem = series_problem(
                    mesh.to_str().unwrap(),
                    axisymmetric,
                    PARTS.0,
                    PARTS.1,
                    k,
                    "[output]\ndir = \"out\"\n",
                );
                std::fs::write(dir.join("problem.toml"), problem).unwrap();
                let a = "contact surface a contains lower_top";
                let deck = pair_deck(a, "upper_bottom", " visualize contact\n", model);
                let area = if axisymmetric {
                    std::f64::consts::PI
                } else {
                    1.0
                };
                let label = format!(
                    "contact2d_{flavour}, axisymmetric {axisymmetric}, {} (W)",
                    model.lines().next().unwrap()
                );
                let (_, err) = series_heat_error(dir, &deck, k, |_, _| h, area, &label);
                assert!(err <= 1e-12, "{err:e}");
                if let Some(checker) = std::env::var_os("SEAM_EXODUS_CHECKER") {
                    let o = std::process::Command::new(checker)
                        .arg(&mesh)
                        .arg(dir.join("out/results.exo"))
                        .arg(dir.join("out/results.dump"))
                        .output()
                        .unwrap();
                    assert!(
                        o.status.success(),
                        "the Exodus II library disagrees:\n{}{}",
                        String::from_utf8_lossy(&o.stdout),
                        String::from_utf8_lossy(&o.stderr)
                    );
                }
            }
        }
    }
}

/// The 2-D contact mesh made with the gmsh Python API (tests/fixtures/make_2d_fixtures.py:
/// recombined quads below, unstructured triangles above, meshed apart): read as gmsh made
/// it (element and edge counts from the script's sidecar, physical names as blocks and
/// side sets, 2-D) and run with a gap conductance and a dual tie: the series heat to
/// round-off, the triangles' edges at y = 1 not matching the quads'.
#[test]
fn gmsh_2d_contact_mesh_reads_and_runs() {
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixtures.join("expected_2d.json")).unwrap())
            .unwrap();
    let e = &expected["contact2d.msh"];
    let path = fixtures.join("contact2d.msh");
    let m = seam::mesh::read(&path).unwrap();
    assert_eq!(m.dim, 2);
    let count = |name: &str| m.blocks[m.find_block(name).unwrap()].len() as u64;
    assert_eq!(count("lower"), e["quads"].as_u64().unwrap());
    assert_eq!(count("upper"), e["triangles"].as_u64().unwrap());
    for (name, n) in e["edges"].as_object().unwrap() {
        let set = m.side_sets.iter().find(|s| s.name == *name).unwrap();
        assert_eq!(set.sides.len() as u64, n.as_u64().unwrap(), "{name}");
    }
    let tmp = scratch("twod-gmsh-contact2d");
    let dir = tmp.path();
    let k = [1.0, 5.0];
    let problem = series_problem(path.to_str().unwrap(), false, PARTS.0, PARTS.1, k, "");
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    for (model, h) in GAP_AND_TIE {
        let deck = pair_deck(
            "contact surface a contains lower_top",
            "upper_bottom",
            "",
            model,
        );
        let label = format!("gmsh contact2d, {} (W/m)", model.lines().next().unwrap());
        let (_, err) = series_heat_error(dir, &deck, k, |_, _| h, 1.0, &label);
        assert!(err <= 1e-12, "{err:e}");
    }
}
