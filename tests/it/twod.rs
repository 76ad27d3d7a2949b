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

/// A scratch directory for one case, emptied.
pub(crate) fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("twod-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

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
    for (from, to) in [(5, 3), (6, 4)] {
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
    m
}

const KINDS: [(PlaneKind, &str); 2] = [(PlaneKind::Quad4, "quad4"), (PlaneKind::Tri3, "tri3")];

/// The worst nodal error of a run against `exact`.
fn worst_error(r: &RunResult, exact: impl Fn([f64; 3]) -> f64) -> f64 {
    r.mesh
        .coords
        .iter()
        .zip(&r.solution.temperature)
        .map(|(x, t)| (t - exact(*x)).abs())
        .fold(0.0, f64::max)
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
    let dir = scratch("patch-ties");
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
    std::fs::write(
        dir.join("problem.toml"),
        "[mesh]\nfile = \"rects.exo\"\n\
         [[material]]\nblocks = [\"block_1\", \"block_2\"]\nconductivity = 2.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_3\", \"surface_4\"]\nvalue = \"1 + 2*x + 3*y\"\n\
         [contact]\nfile = \"contact.i\"\nintegration = \"segments\"\n\
         [solve]\nkind = \"steady\"\ntolerance = 1e-12\n",
    )
    .unwrap();
    let mut worst_all = 0.0f64;
    for (n1, n2) in [(3, 4), (4, 7)] {
        for (k1, name1) in KINDS {
            for (k2, name2) in KINDS {
                write_mesh(&dir.join("rects.exo"), &two_rectangles(n1, k1, n2, k2));
                for (tie, model) in ties {
                    std::fs::write(
                        dir.join("contact.i"),
                        format!(
                            "begin contact definition\n contact surface a contains surface_1\n contact surface b contains surface_2\n\
                             begin interaction\n  side a a\n  side b b\n end\n\
                             begin enforcement\n  {model}\n end\nend\n"
                        ),
                    )
                    .unwrap();
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
    let dir = scratch("patch-gap");
    let (k1, k2, h) = (1.0, 5.0, 10.0);
    let q = 1.0 / (1.0 / k1 + 1.0 / h + 1.0 / k2);
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"rects.exo\"\n\
             [[material]]\nblocks = [\"block_1\"]\nconductivity = {k1}\n\
             [[material]]\nblocks = [\"block_2\"]\nconductivity = {k2}\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_5\"]\nvalue = 0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_6\"]\nvalue = 1\n\
             [contact]\nfile = \"contact.i\"\n\
             [solve]\nkind = \"steady\"\ntolerance = 1e-12\n"
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n contact surface a contains surface_1\n contact surface b contains surface_2\n\
             begin interaction\n  side a a\n  side b b\n end\n\
             begin enforcement\n  enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = {h}\n end\nend\n"
        ),
    )
    .unwrap();
    let mut worst_all = 0.0f64;
    for (n1, n2) in [(3, 4), (5, 2)] {
        for (kind1, name1) in KINDS {
            for (kind2, name2) in KINDS {
                let mesh = two_rectangles(n1, kind1, n2, kind2);
                write_mesh(&dir.join("rects.exo"), &mesh);
                let r = run(&dir.join("problem.toml"));
                // Block 1's nodes are the first ones (meshed apart): below or on y = 1.
                let below = mesh.blocks[0]
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
                    .map(|(n, t)| {
                        let y = mesh.coords[n][1];
                        let want = if n <= below {
                            q * y / k1
                        } else {
                            1.0 - q * (2.0 - y) / k2
                        };
                        (t - want).abs()
                    })
                    .fold(0.0, f64::max);
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
