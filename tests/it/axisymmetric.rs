//! Axisymmetric models (`[mesh] axisymmetric = true`: x the radius, y the axis, every
//! integral per full revolution) against closed-form solutions: concentric cylinders
//! joined by a gap conductance (the logarithmic solution), a disc heated on the axis,
//! and the same cylinders as a 3-D wedge with cylindrical periodicity.

use std::f64::consts::TAU;

use seam::heat::error_norms;
use seam::mesh::Mesh;
use seam::mesh::generate::{self, PlaneKind, RectSpec};
use seam::run::RunResult;

use crate::scratch;
use crate::twod::{
    last_node_of_block_1, pair_deck, problem_text, run, worst_error_by_part, write_mesh,
};

/// The cylinders: inner part a < r < c (k₁), outer part c < r < b (k₂), height H, T = T_a
/// on r = a and T_b on r = b, insulated ends, a gap conductance h at r = c.
#[derive(Clone, Copy)]
struct Cylinders {
    a: f64,
    c: f64,
    b: f64,
    height: f64,
    k: [f64; 2],
    h: f64,
    t: [f64; 2],
}

const CYLINDERS: Cylinders = Cylinders {
    a: 0.5,
    c: 1.0,
    b: 2.0,
    height: 0.5,
    k: [2.0, 5.0],
    h: 3.0,
    t: [400.0, 300.0],
};

impl Cylinders {
    /// The heat Q through every cylinder r = const (W, the whole revolution): the
    /// series of the two logarithmic resistances and the gap's, 1/(2π r H k) per unit of
    /// ln r, 1/(2π c H h) at the gap.
    fn heat(&self) -> f64 {
        let s = TAU * self.height;
        let resistance = (self.c / self.a).ln() / (s * self.k[0])
            + 1.0 / (s * self.c * self.h)
            + (self.b / self.c).ln() / (s * self.k[1]);
        (self.t[0] - self.t[1]) / resistance
    }

    /// T(r) on `side` (0 inner, 1 outer) and dT/dr.
    fn temperature(&self, side: usize, r: f64) -> (f64, f64) {
        let q = self.heat() / (TAU * self.height);
        if side == 0 {
            (
                self.t[0] - q / self.k[0] * (r / self.a).ln(),
                -q / (self.k[0] * r),
            )
        } else {
            (
                self.t[1] + q / self.k[1] * (self.b / r).ln(),
                -q / (self.k[1] * r),
            )
        }
    }
}

/// The (r, y) section meshed apart: the inner part with `n` cells across and `2n` up
/// (Quad4), the outer part with `3n/2` across and `3n` up (Tri3): the interface edges do
/// not match. Side sets: 1 r = a, 2 r = b, 3 the inner part's r = c, 4 the outer's.
fn section(g: &Cylinders, n: usize) -> Mesh {
    generate::rectangles(
        &[
            RectSpec::quad([g.a, 0.0], [g.c, g.height], [n, 2 * n], 1).with_side_sets([1, 3, 0, 0]),
            RectSpec {
                kind: PlaneKind::Tri3,
                ..RectSpec::quad([g.c, 0.0], [g.b, g.height], [3 * n / 2, 3 * n], 2)
            }
            .with_side_sets([4, 2, 0, 0]),
        ],
        false,
    )
}

fn problem(g: &Cylinders, axisymmetric: bool) -> String {
    let (inner, outer) = (g.t[0].to_string(), g.t[1].to_string());
    problem_text(
        "mesh.exo",
        axisymmetric,
        &[("block_1", g.k[0]), ("block_2", g.k[1])],
        &[("surface_1", &inner), ("surface_2", &outer)],
        "",
    )
}

/// A gap conductance `h` between the parts' side sets 3 (side A) and 4.
fn gap_deck(h: f64) -> String {
    let model = format!(
        "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = {h}"
    );
    pair_deck(
        "contact surface a contains surface_3",
        "surface_4",
        "",
        &model,
    )
}

/// The L2 norm (per revolution) of the temperature error of a run, block by block.
fn l2_error(r: &RunResult, exact: impl Fn(usize, f64) -> (f64, f64) + Sync) -> f64 {
    let mut sum = 0.0;
    for b in 0..r.mesh.blocks.len() {
        let e = |x: [f64; 3]| exact(b, x[0]).0;
        let g = |x: [f64; 3]| [exact(b, x[0]).1, 0.0, 0.0];
        let norms = error_norms(&r.mesh, &[b], &r.solution.temperature, &e, &g, 6).unwrap();
        sum += norms.l2 * norms.l2;
    }
    sum.sqrt()
}

/// log2 of successive ratios.
fn rates(errors: &[f64]) -> Vec<f64> {
    errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect()
}

/// Concentric cylinders joined by a gap conductance, axisymmetric, against the
/// logarithmic solution: over five meshes (four refinements, non-matching Quad4 / Tri3
/// at the gap) the temperature's L2 error (per revolution) falls at rate 2 (each rate
/// above 1.9), its largest nodal error at rate 2 (above 1.8: 1.87 on the coarsest pair)
/// and the interface heat's error at rate 2 (above 1.9); the heats of the two sides balance to round-off. The plane
/// reading of the same mesh (no 2πr) is far off the axisymmetric heat: the control
/// that shows the weight matters.
#[test]
fn concentric_cylinders_converge_to_the_logarithmic_solution() {
    let g = CYLINDERS;
    let tmp = scratch("axi-cylinders");
    let dir = tmp.path();
    std::fs::write(dir.join("problem.toml"), problem(&g, true)).unwrap();
    std::fs::write(dir.join("plane.toml"), problem(&g, false)).unwrap();
    std::fs::write(dir.join("contact.i"), gap_deck(g.h)).unwrap();
    let exact_heat = g.heat();
    let (mut l2, mut nodal, mut heat) = (Vec::new(), Vec::new(), Vec::new());
    for n in [2, 4, 8, 16, 32] {
        let mesh = section(&g, n);
        write_mesh(&dir.join("mesh.exo"), &mesh);
        let r = run(&dir.join("problem.toml"));
        let i = &r.summary.interactions[0];
        assert!(
            i.imbalance.abs() <= 1e-12 * exact_heat,
            "imbalance {}",
            i.imbalance
        );
        let worst = worst_error_by_part(&r, |part, x| g.temperature(part, x[0]).0);
        let e = l2_error(&r, |b, x| g.temperature(b, x));
        let q = i.heat_side_a;
        eprintln!(
            "axisymmetric cylinders, n = {n}: L2 error {e:.4e}, worst nodal {worst:.4e} K, heat {q:.10} W (exact {exact_heat:.10}, error {:.3e})",
            (q - exact_heat).abs() / exact_heat
        );
        l2.push(e);
        nodal.push(worst);
        heat.push((q - exact_heat).abs());
        if n == 2 {
            let plane = run(&dir.join("plane.toml")).summary.interactions[0].heat_side_a;
            eprintln!("the same mesh read plane: {plane:.6} W per unit depth");
            assert!((plane - exact_heat).abs() > 0.5 * exact_heat);
        }
    }
    let (rl2, rn, rq) = (rates(&l2), rates(&nodal), rates(&heat));
    eprintln!("axisymmetric cylinders: rates L2 {rl2:.2?}, nodal {rn:.2?}, heat {rq:.2?}");
    assert!(rl2.iter().all(|&r| r > 1.9), "L2 rates {rl2:?}");
    assert!(rn.iter().all(|&r| r > 1.8), "nodal rates {rn:?}");
    assert!(rq.iter().all(|&r| r > 1.9), "heat rates {rq:?}");
}

/// A disc heated on the axis: a uniform source Q in the core r < c (meshed through the
/// axis, nodes at r = 0, Quad4), a ring c < r < b (Tri3, meshed apart) joined to it by a
/// gap conductance h, T_b on r = b, insulated ends. Everything the core makes crosses
/// the gap: the interface heat is Q π c² H per revolution — exactly, since a constant
/// source is integrated exactly (2×2 Gauss on r) and the balance of the discrete
/// equations is exact — and the field converges at rate 2 in L2 to
/// T = T_c + Q (c² − r²)/(4 k₁) in the core, T_b + (Q c²/2k₂) ln(b/r) in the ring, with
/// the jump Q c/(2h) at the gap (each rate above 1.85 — 1.89 on the coarsest pair — and
/// above 1.95 on the finest). The axis needs no condition (the weight r makes its
/// flux vanish) and no division by r happens anywhere.
#[test]
fn disc_heated_on_the_axis_matches_its_analytic_solution() {
    let (c, b, height, k, h, q, t_b) = (1.0, 2.0, 0.5, [2.0, 5.0], 4.0, 1000.0, 300.0);
    let tmp = scratch("axi-disc");
    let dir = tmp.path();
    let problem = problem_text(
        "mesh.exo",
        true,
        &[("block_1", k[0]), ("block_2", k[1])],
        &[("surface_2", &t_b.to_string())],
        &format!("[[source]]\nblocks = [\"block_1\"]\nvalue = {q}\n"),
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    std::fs::write(dir.join("contact.i"), gap_deck(h)).unwrap();
    let made = q * std::f64::consts::PI * c * c * height;
    let t_ring = |r: f64| t_b + q * c * c / (2.0 * k[1]) * (b / r).ln();
    let t_core = t_ring(c) + q * c / (2.0 * h);
    let exact = move |block: usize, r: f64| {
        if block == 0 {
            (
                t_core + q * (c * c - r * r) / (4.0 * k[0]),
                -q * r / (2.0 * k[0]),
            )
        } else {
            (t_ring(r), -q * c * c / (2.0 * k[1] * r))
        }
    };
    let mut l2 = Vec::new();
    for n in [2, 4, 8, 16, 32] {
        let mesh = generate::rectangles(
            &[
                RectSpec::quad([0.0, 0.0], [c, height], [n, n], 1).with_side_sets([5, 3, 0, 0]),
                RectSpec {
                    kind: PlaneKind::Tri3,
                    ..RectSpec::quad([c, 0.0], [b, height], [n, n + 1], 2)
                }
                .with_side_sets([4, 2, 0, 0]),
            ],
            false,
        );
        assert!(mesh.coords.iter().any(|x| x[0] == 0.0), "nodes on the axis");
        write_mesh(&dir.join("mesh.exo"), &mesh);
        let r = run(&dir.join("problem.toml"));
        let i = &r.summary.interactions[0];
        let balance = (i.heat_side_a - made).abs() / made;
        let e = l2_error(&r, exact);
        let axis = r
            .solution
            .temperature
            .iter()
            .zip(&mesh.coords)
            .filter(|(_, x)| x[0] == 0.0)
            .map(|(t, _)| (t - exact(0, 0.0).0).abs())
            .fold(0.0, f64::max);
        eprintln!(
            "axisymmetric disc, n = {n}: interface heat {:.10} W (made {made:.10}, {balance:.1e}), L2 error {e:.4e}, worst error on the axis {axis:.3e} K",
            i.heat_side_a
        );
        assert!(r.solution.temperature.iter().all(|t| t.is_finite()));
        assert!(balance <= 1e-12, "heat {} against {made}", i.heat_side_a);
        l2.push(e);
    }
    let rl2 = rates(&l2);
    eprintln!("axisymmetric disc: L2 rates {rl2:.2?}");
    assert!(rl2.iter().all(|&r| r > 1.85), "L2 rates {rl2:?}");
    assert!(rl2[rl2.len() - 1] > 1.95, "L2 rates {rl2:?}");
}

/// The same cylinders as a 3-D wedge: two annular sectors of 30° (Hex8, meshed apart:
/// the inner with `n` cells across, `2n` around, 2 up; the outer `3n/2`, `3n`, 3), the
/// gap conductance between them and the cut faces tied by cylindrical periodicity (a
/// second contact definition, a mortar tie). The wedge's heat times 12 and the
/// axisymmetric heat on the same radial cells both approach the exact one at rate 2,
/// and they differ by no more than their errors do (the 3-D faceting of the circle,
/// O(Δθ²), and the radial discretisation, O(h²)): to discretisation error. (No heat
/// crosses the cut faces in this field — the tie carries below 1e-3 of the gap's — so
/// the periodicity is checked for not disturbing the field, as insulated cuts would
/// not either.)
#[test]
fn wedge_with_cylindrical_periodicity_agrees_with_the_axisymmetric_model() {
    let g = CYLINDERS;
    let tmp = scratch("axi-wedge");
    let dir = tmp.path();
    let exact = g.heat();
    std::fs::write(dir.join("axi.toml"), problem(&g, true)).unwrap();
    std::fs::write(
        dir.join("wedge.toml"),
        problem(&g, false).replace("contact.i", "wedge.i"),
    )
    .unwrap();
    std::fs::write(dir.join("contact.i"), gap_deck(g.h)).unwrap();
    std::fs::write(
        dir.join("wedge.i"),
        format!(
            "{}begin contact definition cuts\n contact surface start contains surface_5 surface_7\n contact surface stop contains surface_6 surface_8\n\
             periodicity for start = cylindrical axis = 0 0 1 center = 0 0 0 angle = 30\n\
             begin enforcement\n  enforcement for energy = tied\n  side b variable temperature to temperature\n end\nend\n",
            gap_deck(g.h)
        ),
    )
    .unwrap();
    let mut rows = Vec::new();
    for n in [2, 4, 8] {
        let inner = generate::annulus(
            g.a,
            g.c,
            30.0,
            [0.0, g.height],
            [n, 2 * n, 2],
            1,
            [1, 3, 5, 6, 0, 0],
        );
        let outer = generate::annulus(
            g.c,
            g.b,
            30.0,
            [0.0, g.height],
            [3 * n / 2, 3 * n, 3],
            2,
            [4, 2, 7, 8, 0, 0],
        );
        write_mesh(
            &dir.join("mesh.exo"),
            &generate::disjoint_union(&inner, &outer),
        );
        let r3 = run(&dir.join("wedge.toml"));
        let i = &r3.summary.interactions[0];
        let wedge = 12.0 * i.heat_side_a;
        assert!(
            i.imbalance.abs() <= 1e-10 * exact,
            "imbalance {}",
            i.imbalance
        );
        // The cut faces carry (almost) nothing in this field: the tie must not disturb it.
        let cut = r3.summary.interactions[1].heat_side_a;
        assert!(
            cut.abs() <= 1e-3 * i.heat_side_a,
            "heat across the cut {cut}"
        );
        write_mesh(&dir.join("mesh.exo"), &section(&g, n));
        let axi = run(&dir.join("axi.toml")).summary.interactions[0].heat_side_a;
        let (e3, ea, d) = (
            (wedge - exact).abs() / exact,
            (axi - exact).abs() / exact,
            (wedge - axi).abs() / exact,
        );
        eprintln!(
            "cylinders, n = {n}: wedge × 12 {wedge:.8} W, axisymmetric {axi:.8} W, exact {exact:.8} W; errors {e3:.3e} (3-D), {ea:.3e} (axisymmetric), apart {d:.3e}"
        );
        assert!(d <= e3 + ea, "apart by more than their errors: {d:e}");
        rows.push((e3, ea, d));
    }
    let e3: Vec<f64> = rows.iter().map(|r| r.0).collect();
    let apart: Vec<f64> = rows.iter().map(|r| r.2).collect();
    let (r3, rd) = (rates(&e3), rates(&apart));
    eprintln!("wedge: heat error rates {r3:.2?}; apart rates {rd:.2?}");
    assert!(r3.iter().all(|&r| r > 1.8), "3-D rates {r3:?}");
    assert!(
        rd.iter().all(|&r| r > 1.8),
        "the two models do not close in: {rd:?}"
    );
}

/// What an axisymmetric model refuses, each with its code and reason: a cylindrical
/// periodicity (E0327: the model is already the whole revolution), a periodic map that
/// moves nodes off their radius (E0327, naming the node), a node at x < 0 (E0718);
/// while a periodicity along the axis (`Rectangular Offset = 0 dy`) is accepted and
/// carries the periodic field.
#[test]
fn axisymmetric_refusals_say_why() {
    let tmp = scratch("axi-refusals");
    let dir = tmp.path();
    let render = |problem: &str| match seam::run::run(&dir.join(problem)) {
        Err(seam::run::RunError::Input(d, s)) => d.render(&s),
        Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
        Ok(_) => panic!("{problem} ran"),
    };
    // A slab 1 < r < 2, 0 < y < 1: its bottom edge periodic with its top.
    let slab = |x0: f64| {
        generate::rectangles(
            &[RectSpec::quad([x0, 0.0], [x0 + 1.0, 1.0], [2, 3], 1).with_side_sets([1, 2, 3, 4])],
            false,
        )
    };
    write_mesh(&dir.join("mesh.exo"), &slab(1.0));
    write_mesh(&dir.join("left.exo"), &slab(-0.5));
    let problem = |mesh: &str| {
        format!(
            "[mesh]\nfile = \"{mesh}\"\naxisymmetric = true\n\
             [[material]]\nblocks = [\"block_1\"]\nconductivity = 1\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = 1\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_2\"]\nvalue = 0\n\
             [contact]\nfile = \"contact.i\"\n"
        )
    };
    std::fs::write(dir.join("problem.toml"), problem("mesh.exo")).unwrap();
    std::fs::write(dir.join("left.toml"), problem("left.exo")).unwrap();
    let deck = |transform: &str| {
        std::fs::write(
            dir.join("contact.i"),
            format!(
                "begin contact definition\n contact surface low contains surface_3\n contact surface high contains surface_4\n\
                 periodicity for low = {transform}\n\
                 begin enforcement\n  enforcement for energy = tied_temperature\n end\nend\n"
            ),
        )
        .unwrap();
    };
    deck("cylindrical axis = 0 1 0 center = 0 0 0 angle = 30");
    let text = render("problem.toml");
    eprintln!("{text}");
    assert!(text.contains("error[E0327]") && text.contains("already the full revolution"));
    deck("rectangular offset = 0.5 1");
    let text = render("problem.toml");
    eprintln!("{text}");
    assert!(text.contains("error[E0327]") && text.contains("keep each node's radius"));
    deck("rectangular offset = 0 1");
    let r = run(&dir.join("problem.toml"));
    // The field is T = ln(2/r)/ln 2 whatever the periodicity: nothing crosses it.
    let worst = r
        .solution
        .temperature
        .iter()
        .zip(&r.mesh.coords)
        .map(|(t, x)| (t - (2.0 / x[0]).ln() / 2f64.ln()).abs())
        .fold(0.0, f64::max);
    eprintln!("axial periodicity accepted; worst nodal error {worst:.2e}");
    assert!(worst < 1e-2);
    let text = render("left.toml");
    eprintln!("{text}");
    assert!(text.contains("error[E0718]") && text.contains("x = -0.5"));
}

/// ∫ N_i 2πr dA of the nodes of a 2-D element, row sums of its consistent mass per
/// revolution, in closed form: a triangle's `2π A (Σr + r_i)/12`, an axis-aligned
/// rectangle's `2π (Δy/2) Δr (2r_i + r_j)/6` (r_j the other radius of the cell).
fn lumped_per_revolution(mesh: &Mesh) -> Vec<f64> {
    let mut m = vec![0.0; mesh.coords.len()];
    for block in &mesh.blocks {
        for k in 0..block.len() {
            let nodes = block.elem_nodes(k);
            let x: Vec<[f64; 3]> = nodes.iter().map(|n| mesh.coords[n.index()]).collect();
            if nodes.len() == 3 {
                let area = 0.5
                    * ((x[1][0] - x[0][0]) * (x[2][1] - x[0][1])
                        - (x[2][0] - x[0][0]) * (x[1][1] - x[0][1]));
                let sum: f64 = x.iter().map(|p| p[0]).sum();
                for (n, p) in nodes.iter().zip(&x) {
                    m[n.index()] += TAU * area * (sum + p[0]) / 12.0;
                }
            } else {
                let (r0, r1) = (x[0][0], x[1][0]);
                let dy = x[3][1] - x[0][1];
                for (n, p) in nodes.iter().zip(&x) {
                    let other = if p[0] == r0 { r1 } else { r0 };
                    m[n.index()] += TAU * 0.5 * dy * (r1 - r0).abs() * (2.0 * p[0] + other) / 6.0;
                }
            }
        }
    }
    m
}

/// A transient axisymmetric run conserves energy per revolution: the heated core and the
/// insulated ring of the disc above (no temperature condition), backward Euler with
/// lumped capacity. Every step stores exactly what the source makes, so at the end
/// Σ_i ρc_i M_i (T_i − T₀), with M_i = ∫ N_i 2πr dA computed here in closed form,
/// equals Q π c² H t to round-off — which needs the capacity, the source and the gap
/// all weighted by 2πr; the field is not uniform (the ring lags), so a missing weight
/// anywhere would show.
#[test]
fn transient_axisymmetric_run_stores_what_the_source_makes() {
    let (c, b, height, q, t0, t_end) = (1.0, 2.0, 0.5, 1000.0, 300.0, 1.0);
    let rho_c = [3.0, 7.0];
    let tmp = scratch("axi-transient");
    let dir = tmp.path();
    let mesh = generate::rectangles(
        &[
            RectSpec::quad([0.0, 0.0], [c, height], [4, 3], 1).with_side_sets([0, 3, 0, 0]),
            RectSpec {
                kind: PlaneKind::Tri3,
                ..RectSpec::quad([c, 0.0], [b, height], [5, 4], 2)
            }
            .with_side_sets([4, 0, 0, 0]),
        ],
        false,
    );
    write_mesh(&dir.join("mesh.exo"), &mesh);
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"mesh.exo\"\naxisymmetric = true\n\
             [[material]]\nblocks = [\"block_1\"]\nconductivity = 2\nrho_c = {}\n\
             [[material]]\nblocks = [\"block_2\"]\nconductivity = 5\nrho_c = {}\n\
             [[source]]\nblocks = [\"block_1\"]\nvalue = {q}\n\
             [initial]\ntemperature = {t0}\n\
             [contact]\nfile = \"contact.i\"\n\
             [solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 0.1\nend_time = {t_end}\ntolerance = 1e-12\n",
            rho_c[0], rho_c[1]
        ),
    )
    .unwrap();
    std::fs::write(dir.join("contact.i"), gap_deck(4.0)).unwrap();
    let r = run(&dir.join("problem.toml"));
    let m = lumped_per_revolution(&mesh);
    let block_1 = last_node_of_block_1(&mesh);
    let stored: f64 = (0..mesh.coords.len())
        .map(|i| rho_c[usize::from(i > block_1)] * m[i] * (r.solution.temperature[i] - t0))
        .sum();
    let made = q * std::f64::consts::PI * c * c * height * t_end;
    let (core, ring) = (
        r.solution.temperature[0],
        r.solution.temperature[block_1 + 1],
    );
    eprintln!(
        "transient axisymmetric disc: stored {stored:.10} J, made {made:.10} J ({:.1e}); core at {core:.3} K, ring at {ring:.3} K",
        (stored - made).abs() / made
    );
    assert!(core - ring > 10.0, "the field is not uniform");
    assert!((stored - made).abs() <= 1e-11 * made);
}

/// A sphere in a spherical shell, axisymmetric, on the gmsh meshes of
/// tests/fixtures/make_2d_fixtures.py (the half-disc section, triangles in the core,
/// recombined quads in the shell, meshed apart: a curved non-matching interface, nodes
/// on the axis): a source q in the core, T_b on ρ = 2, a gap conductance h at ρ = 1.
/// The heat crossing the gap is all the core makes, q V_h, with V_h the volume of the
/// meshed core's revolution (Pappus: Σ 2π r̄ A over its straight-sided elements, summed
/// here) — to round-off on every mesh; and the temperature converges in L2 (per
/// revolution) to T = T_b + (Q/4πk₂)(1/ρ − ½) in the shell, the core's
/// T_c + q (1 − ρ²)/(6k₁) above the jump Q/(4πh) (Q = 4πq/3), at rate 2 (each above
/// 1.8: the meshes are unstructured, h halving at each level).
#[test]
fn sphere_in_a_shell_on_gmsh_meshes_converges_axisymmetric() {
    let (k, h, q, t_b) = ([2.0, 5.0], 3.0, 600.0, 300.0);
    let total = 4.0 * std::f64::consts::PI * q / 3.0;
    let t_shell = move |rho: f64| t_b + total / (2.0 * TAU * k[1]) * (1.0 / rho - 0.5);
    let t_core = t_shell(1.0) + total / (2.0 * TAU * h);
    let exact = move |block: usize, x: [f64; 3]| -> (f64, [f64; 3]) {
        let rho = x[0].hypot(x[1]);
        let (t, dt) = if block == 0 {
            (
                t_core + q * (1.0 - rho * rho) / (6.0 * k[0]),
                -q * rho / (3.0 * k[0]),
            )
        } else {
            (t_shell(rho), -total / (2.0 * TAU * k[1] * rho * rho))
        };
        // dT/dρ along (x, y)/ρ.
        let g = if rho > 0.0 { dt / rho } else { 0.0 };
        (t, [g * x[0], g * x[1], 0.0])
    };
    let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures");
    let tmp = scratch("axi-spheres");
    let dir = tmp.path();
    let expected: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixtures.join("expected_2d.json")).unwrap())
            .unwrap();
    let mut l2 = Vec::new();
    for level in 1..=3 {
        let path = fixtures.join(format!("spheres_axi_{level}.msh"));
        let problem = problem_text(
            path.to_str().unwrap(),
            true,
            &[("core", k[0]), ("shell", k[1])],
            &[("shell_outer", &t_b.to_string())],
            &format!("[[source]]\nblocks = [\"core\"]\nvalue = {q}\n"),
        );
        std::fs::write(dir.join("problem.toml"), problem).unwrap();
        let model = format!(
            "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = {h}"
        );
        let deck = pair_deck(
            "contact surface a contains core_surface",
            "shell_inner",
            "",
            &model,
        );
        std::fs::write(dir.join("contact.i"), deck).unwrap();
        let r = run(&dir.join("problem.toml"));
        let m = &r.mesh;
        let core = m.find_block("core").unwrap();
        // The mesh is what gmsh made (the script's sidecar).
        let made = &expected[format!("spheres_axi_{level}.msh").as_str()];
        let shell = m.find_block("shell").unwrap();
        assert_eq!(
            m.blocks[core].len() as u64,
            made["core_elements"].as_u64().unwrap()
        );
        assert_eq!(
            m.blocks[shell].len() as u64,
            made["shell_elements"].as_u64().unwrap()
        );
        let on_axis = m.coords.iter().filter(|x| x[0] == 0.0).count() as u64;
        assert_eq!(on_axis, made["axis_nodes"].as_u64().unwrap());
        let volume: f64 = (0..m.blocks[core].len())
            .map(|e| {
                let x: Vec<[f64; 3]> = m.blocks[core]
                    .elem_nodes(e)
                    .iter()
                    .map(|n| m.coords[n.index()])
                    .collect();
                // Triangles and quads alike: fan from the first node (Pappus per piece).
                (1..x.len() - 1)
                    .map(|i| {
                        let (a, b, c) = (x[0], x[i], x[i + 1]);
                        let area =
                            0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
                        TAU * (a[0] + b[0] + c[0]) / 3.0 * area
                    })
                    .sum::<f64>()
            })
            .sum();
        let i = &r.summary.interactions[0];
        let balance = (i.heat_side_a - q * volume).abs() / (q * volume);
        let blocks: Vec<usize> = (0..m.blocks.len()).collect();
        let mut sum = 0.0;
        for &b in &blocks {
            let block = usize::from(b != core);
            let e = |x: [f64; 3]| exact(block, x).0;
            let g = |x: [f64; 3]| exact(block, x).1;
            let n = error_norms(m, &[b], &r.solution.temperature, &e, &g, 6).unwrap();
            sum += n.l2 * n.l2;
        }
        let e = sum.sqrt();
        eprintln!(
            "spheres, level {level}: interface heat {:.10} W, q V_h {:.10} ({balance:.1e}; the sphere's {:.10}), L2 error {e:.4e}",
            i.heat_side_a,
            q * volume,
            total
        );
        assert!(balance <= 1e-12, "{balance:e}");
        l2.push(e);
    }
    let r = rates(&l2);
    eprintln!("spheres: L2 rates {r:.2?}");
    assert!(r.iter().all(|&r| r > 1.8), "{r:?}");
}

/// `seam run`'s thermal–electrical coupling, axisymmetric: two copper-like cylinders of
/// radius 1 stacked along the axis (Quad4, meshed apart, 3 against 4 edges at y = 0.6),
/// a current density j₀ fed in at y = 0 and the top end at 0 V, a thermal and an
/// electrical contact conductance between them, convection at both ends. The current is
/// axial, so V is linear in each part with the drop j₀/h_e at the contact: at every node
/// to round-off; the contact carries j₀ π per revolution and releases (j₀²/h_e) π as
/// Joule heat.
#[test]
fn thermal_electrical_run_is_per_revolution() {
    let (j0, sigma, h_e, l1, l) = (1e4, [2e3, 1e3], 5e3, 0.6, 1.5);
    let tmp = scratch("axi-electric");
    let dir = tmp.path();
    let mesh = generate::rectangles(
        &[
            RectSpec::quad([0.0, 0.0], [1.0, l1], [3, 4], 1).with_side_sets([0, 0, 1, 2]),
            RectSpec::quad([0.0, l1], [1.0, l], [4, 5], 2).with_side_sets([0, 0, 3, 4]),
        ],
        false,
    );
    write_mesh(&dir.join("mesh.exo"), &mesh);
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"mesh.exo\"\naxisymmetric = true\n\
             [[material]]\nblocks = [\"block_1\"]\nconductivity = 5\nelectrical_conductivity = {}\n\
             [[material]]\nblocks = [\"block_2\"]\nconductivity = 2\nelectrical_conductivity = {}\n\
             [[bc]]\nkind = \"current\"\nsurfaces = [\"surface_1\"]\nvalue = {j0}\n\
             [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_4\"]\nvalue = 0\n\
             [[bc]]\nkind = \"convection\"\nsurfaces = [\"surface_1\", \"surface_4\"]\nvalue = 10\nambient = 300\n\
             [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-12\n",
            sigma[0], sigma[1]
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n contact surface a contains surface_2\n contact surface b contains surface_3\n\
             begin interaction\n  side a a\n  side b b\n end\n\
             begin enforcement thermal\n  enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = 100\n end\n\
             begin enforcement electrical\n  enforcement for voltage = gap_conductance\n  gap conductance coefficient = constant h = {h_e}\n end\nend\n"
        ),
    )
    .unwrap();
    let r = run(&dir.join("problem.toml"));
    let c = &r.summary.electrical_contacts[0];
    let pi = std::f64::consts::PI;
    let (current, joule) = (j0 * pi, j0 * j0 / h_e * pi);
    eprintln!(
        "axisymmetric thermal-electrical: contact current {:.10} A (j0 π {current:.10}), Joule heat {:.10} W ({joule:.10})",
        c.current, c.joule_heat
    );
    assert!((c.current - current).abs() <= 1e-9 * current);
    assert!((c.joule_heat - joule).abs() <= 1e-9 * joule);
    // V from the solution's dofs: the run's nodal voltage through its dof map.
    let dofs = &r.solution.dofs;
    let field = dofs.field("voltage").unwrap();
    let v = dofs.nodal_values(field, &r.solution.u);
    let last = last_node_of_block_1(&mesh);
    let worst = (0..mesh.num_nodes())
        .map(|n| {
            let y = mesh.coords[n][1];
            let exact = if n <= last {
                j0 * ((l1 - y) / sigma[0] + 1.0 / h_e + (l - l1) / sigma[1])
            } else {
                j0 * (l - y) / sigma[1]
            };
            (v[n] - exact).abs()
        })
        .fold(0.0, f64::max);
    eprintln!("axisymmetric thermal-electrical: worst nodal V error {worst:.1e} V");
    assert!(worst <= 1e-9, "{worst}");
}
