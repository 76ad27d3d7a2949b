//! Axisymmetric models (`[mesh] axisymmetric = true`: x the radius, y the axis, every
//! integral per full revolution) against closed-form solutions: concentric cylinders
//! joined by a gap conductance (the logarithmic solution), a disc heated on the axis,
//! and the same cylinders as a 3-D wedge with cylindrical periodicity.

use std::f64::consts::TAU;

use seam::heat::error_norms;
use seam::mesh::Mesh;
use seam::mesh::generate::{self, PlaneKind, RectSpec};
use seam::run::RunResult;

use crate::twod::{run, scratch, write_mesh};

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
    format!(
        "[mesh]\nfile = \"mesh.exo\"\naxisymmetric = {axisymmetric}\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = {}\n\
         [[material]]\nblocks = [\"block_2\"]\nconductivity = {}\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = {}\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_2\"]\nvalue = {}\n\
         [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-13\n",
        g.k[0], g.k[1], g.t[0], g.t[1]
    )
}

fn gap_deck(h: f64, extra: &str) -> String {
    format!(
        "begin contact definition\n contact surface inner contains surface_3\n contact surface outer contains surface_4\n{extra}\
         begin interaction\n  side a inner\n  side b outer\n end\n\
         begin enforcement\n  enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = {h}\n end\nend\n"
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
    let dir = scratch("axi-cylinders");
    std::fs::write(dir.join("problem.toml"), problem(&g, true)).unwrap();
    std::fs::write(dir.join("plane.toml"), problem(&g, false)).unwrap();
    std::fs::write(dir.join("contact.i"), gap_deck(g.h, "")).unwrap();
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
        let block_1 = mesh.blocks[0]
            .connectivity
            .iter()
            .map(|n| n.index())
            .max()
            .unwrap();
        let worst = r
            .solution
            .temperature
            .iter()
            .enumerate()
            .map(|(k, t)| (t - g.temperature(usize::from(k > block_1), mesh.coords[k][0]).0).abs())
            .fold(0.0, f64::max);
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
    let dir = scratch("axi-disc");
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"mesh.exo\"\naxisymmetric = true\n\
             [[material]]\nblocks = [\"block_1\"]\nconductivity = {}\n\
             [[material]]\nblocks = [\"block_2\"]\nconductivity = {}\n\
             [[source]]\nblocks = [\"block_1\"]\nvalue = {q}\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_2\"]\nvalue = {t_b}\n\
             [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-13\n",
            k[0], k[1]
        ),
    )
    .unwrap();
    std::fs::write(dir.join("contact.i"), gap_deck(h, "")).unwrap();
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
