//! Volumetric sources of `seam run` (`[[source]]`): a Lua expression of x checked
//! against exact solutions on the linear and the general solver, a table in time
//! checked against the energy it stores, a Q(T) that Newton converges on, and bad
//! expressions reported at their line.
//!
//! Meshes are generated here and written with seam's own Exodus writer.

use std::path::Path;

use seam::mesh::generate::{self, BoxSpec};
use seam::output::exodus::ExodusWriter;
use seam::run::{RunError, RunResult};

use crate::scratch;

/// Hex8 boxes (merged into one conforming mesh) written as `<dir>/<name>.exo`.
fn write_mesh(dir: &Path, name: &str, boxes: &[BoxSpec]) -> seam::mesh::Mesh {
    let mesh = generate::boxes(boxes, true);
    let w = ExodusWriter::create(&dir.join(format!("{name}.exo")), &mesh, &[], &[]).unwrap();
    w.finish().unwrap();
    mesh
}

/// A slab 0 ≤ x ≤ 1 (0.1 thick in y and z) of `n` cells, side sets 1 at x = 0 and 2 at
/// x = 1; y and z faces are insulated, so the problem is one-dimensional.
fn slab(dir: &Path, n: usize) -> seam::mesh::Mesh {
    let b =
        BoxSpec::hex([0.0; 3], [1.0, 0.1, 0.1], [n, 1, 1], 1).with_side_sets([1, 2, 0, 0, 0, 0]);
    write_mesh(dir, "mesh", &[b])
}

/// Write `problem.toml` (after a `[mesh]` line for `mesh.exo`) and run it.
fn run(dir: &Path, problem: &str) -> Result<RunResult, String> {
    let text = format!("[mesh]\nfile = \"mesh.exo\"\n{problem}");
    std::fs::write(dir.join("problem.toml"), text).unwrap();
    match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => Ok(r),
        Err(RunError::Input(d, s)) => Err(d.render(&s)),
        Err(RunError::Solve(e)) => Err(e),
    }
}

const SLAB_BCS: &str = "[[bc]]
kind = \"temperature\"
surfaces = [\"surface_1\", \"surface_2\"]
value = 300.0
";

/// Q = q0·x in a slab with both ends at T0: −k T'' = q0 x gives the cubic
/// T = T0 + q0 (x − x³)/(6k). Linear elements with an exactly integrated load (Q N is
/// quadratic; the 2-point Gauss rule is exact) have exact nodal values in 1-D, so the
/// nodal error is round-off: below 1e-10 K of a 19 K rise, on the linear steady solver
/// and on the general Newton solver alike (k written as a Lua law sends the run there).
#[test]
fn lua_source_gives_the_exact_cubic_of_a_slab() {
    let tmp = scratch("sources-cubic");
    let dir = tmp.path();
    let mesh = slab(dir, 8);
    let (k, q0) = (2.0, 600.0);
    let exact = |x: f64| 300.0 + q0 * (x - x * x * x) / (6.0 * k);
    for (conductivity, linear) in [("2.0", true), ("\"2 + 0*T\"", false)] {
        let r = run(
            dir,
            &format!(
                "[[material]]\nblocks = [\"block_1\"]\nconductivity = {conductivity}\n{SLAB_BCS}[[source]]\nblocks = [\"block_1\"]\nvalue = \"{q0}*x\"\n"
            ),
        )
        .unwrap();
        assert_eq!(r.history.is_empty(), linear, "which solver ran");
        let err = (0..mesh.num_nodes())
            .map(|n| (r.solution.temperature[n] - exact(mesh.coords[n][0])).abs())
            .fold(0.0f64, f64::max);
        eprintln!("k = {conductivity}: max nodal error {err:.3e} K");
        assert!(err < 1e-10, "k = {conductivity}: nodal error {err:e}");
    }
}

/// A manufactured 2-D solution, T = sin(πx) sin(πy) on the unit square (0.1 thick),
/// T = 0 on its four sides, from Q = 2π² sin(πx) sin(πy) given in Lua: the largest
/// nodal error falls at rate 2 (1.9 to 2.1) as the grid is halved from 8 × 8 to 32 × 32.
#[test]
fn lua_source_converges_at_second_order() {
    let tmp = scratch("sources-rate");
    let dir = tmp.path();
    let errors: Vec<f64> = [4, 8, 16, 32]
        .iter()
        .map(|&n| {
            let b = BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.1], [n, n, 1], 1)
                .with_side_sets([1, 2, 3, 4, 0, 0]);
            let mesh = write_mesh(dir, "mesh", &[b]);
            let r = run(
                dir,
                "[[material]]
blocks = [\"block_1\"]
conductivity = 1.0
[[bc]]
kind = \"temperature\"
surfaces = [\"surface_1\", \"surface_2\", \"surface_3\", \"surface_4\"]
value = 0.0
[[source]]
blocks = [\"block_1\"]
value = \"2*math.pi^2*math.sin(math.pi*x)*math.sin(math.pi*y)\"
",
            )
            .unwrap();
            let pi = std::f64::consts::PI;
            (0..mesh.num_nodes())
                .map(|k| {
                    let [x, y, _] = mesh.coords[k];
                    (r.solution.temperature[k] - (pi * x).sin() * (pi * y).sin()).abs()
                })
                .fold(0.0f64, f64::max)
        })
        .collect();
    let rates: Vec<f64> = errors.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
    eprintln!("errors {errors:.3?}, rates {rates:.3?}");
    for &p in &rates[1..] {
        assert!((1.9..2.1).contains(&p), "rate {p:.3} (errors {errors:?})");
    }
}

/// Lumped nodal volumes ∫N_a dV of a mesh of axis-aligned hexes (an eighth of each
/// element's volume at each of its nodes).
fn nodal_volumes(mesh: &seam::mesh::Mesh) -> Vec<f64> {
    let mut w = vec![0.0; mesh.num_nodes()];
    for e in 0..mesh.num_elems() {
        let nodes = mesh.elem_nodes(seam::mesh::ElemId(e as u32));
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for n in nodes {
            for d in 0..3 {
                lo[d] = lo[d].min(mesh.coords[n.index()][d]);
                hi[d] = hi[d].max(mesh.coords[n.index()][d]);
            }
        }
        let v = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
        for n in nodes {
            w[n.index()] += v / 8.0;
        }
    }
    w
}

/// A source table in time on one block of an insulated two-block bar, backward Euler:
/// over every step the energy stored, Σ_a ρc ∫N_a (T_aⁿ⁺¹ − T_aⁿ), equals the energy the
/// source gave, Δt Q(tⁿ⁺¹) V₁ (the lumped capacity and Σ_a N_a = 1 make this exact), to
/// 1e-10 of the step's energy (round-off of the solves: 1e-13 measured). The field is
/// not uniform (heat conducts into block 2), and the ramp up, the ramp down and the
/// plateau of the table are all crossed.
#[test]
fn source_table_in_time_balances_the_stored_energy() {
    let tmp = scratch("sources-table");
    let dir = tmp.path();
    let boxes = [
        BoxSpec::hex([0.0; 3], [0.5, 0.1, 0.1], [5, 1, 1], 1),
        BoxSpec::hex([0.5, 0.0, 0.0], [1.0, 0.1, 0.1], [5, 1, 1], 2),
    ];
    let mesh = write_mesh(dir, "mesh", &boxes);
    assert_eq!(mesh.blocks.len(), 2);
    let (rho_c, dt) = (2e3, 0.1);
    let table = [(0.0, 0.0), (0.3, 5e3), (0.6, 1e3), (1.0, 1e3)];
    let q = |t: f64| {
        let k = table
            .iter()
            .rposition(|p| p.0 <= t)
            .unwrap()
            .min(table.len() - 2);
        let (a, b) = (table[k], table[k + 1]);
        a.1 + (b.1 - a.1) * ((t - a.0) / (b.0 - a.0)).min(1.0)
    };
    run(
        dir,
        &format!(
            "[[material]]
blocks = [\"block_1\", \"block_2\"]
conductivity = 1.0
rho_c = {rho_c}
[[source]]
blocks = [\"block_1\"]
value = {{ table = [[0.0, 0.0], [0.3, 5e3], [0.6, 1e3], [1.0, 1e3]] }}
[initial]
temperature = 300.0
[solve]
kind = \"transient\"
scheme = \"backward_euler\"
dt = {dt}
end_time = 1.0
[output]
dir = \"out\"
"
        ),
    )
    .unwrap();
    let results = dir.join("out/results.exo");
    let times = seam::mesh::exodus::read_times(&results).unwrap();
    assert_eq!(times.len(), 10);
    let w = nodal_volumes(&mesh);
    let v1 = 0.5 * 0.1 * 0.1;
    let mut before = vec![300.0; mesh.num_nodes()];
    let mut worst = 0.0f64;
    for (step, &t) in times.iter().enumerate() {
        let after = seam::mesh::exodus::read_nodal_variable(&results, "temperature", step).unwrap();
        let stored: f64 = (0..w.len())
            .map(|a| rho_c * w[a] * (after[a] - before[a]))
            .sum();
        let given = dt * q(t) * v1;
        let (lo, hi) = after.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
        assert!(
            hi - lo > 1e-3,
            "step {}: the field should not be uniform",
            step + 1
        );
        worst = worst.max((stored - given).abs() / given.max(1e-300));
        assert!(
            (stored - given).abs() <= 1e-10 * given,
            "step {} (t = {t}): stored {stored}, given {given}",
            step + 1
        );
        before = after;
    }
    eprintln!("worst relative energy imbalance over a step {worst:.3e}");
}

/// Q(T) makes the run nonlinear: with T(0) = T(1) = 300 K, k = 1 and
/// Q = 200 − 0.1((T − 300)² − (100x(1 − x))²), the exact solution is still
/// T = 300 + 100 x(1 − x) (where the bracket vanishes) while dQ/dT reaches −5 W/m³/K.
/// Newton with the −dQ/dT N N Jacobian converges in at most 6 iterations (5 measured)
/// to a residual below 1e-9 of the first, and quadratically: once below 1e-2 of the
/// first, ‖R‖ₖ₊₁ ≤ ‖R‖ₖ² (in W; 0.47 ‖R‖ₖ² measured) until round-off. The nodal error, which
/// the T in Q brings in at the quadrature points, is the discretisation's: it falls at
/// rate 2 (1.9 to 2.1) from 16 to 32 cells.
#[test]
fn temperature_dependent_source_converges_in_newton() {
    let tmp = scratch("sources-newton");
    let dir = tmp.path();
    let errors: Vec<f64> = [16, 32]
        .iter()
        .map(|&n| {
            let mesh = slab(dir, n);
            let r = run(
                dir,
                &format!(
                    "[[material]]\nblocks = [\"block_1\"]\nconductivity = 1.0\n{SLAB_BCS}[[source]]\nblocks = [\"block_1\"]\nvalue = \"200 - 0.1*((T - 300)^2 - (100*x*(1 - x))^2)\"\n"
                ),
            )
            .unwrap();
            let h = &r.history[0].residual_history;
            let shown: Vec<String> = h.iter().map(|v| format!("{v:.2e}")).collect();
            eprintln!("{n} cells: {} Newton iterations, ‖R‖ {shown:?}", r.summary.newton_iterations);
            assert!(r.summary.converged && r.summary.newton_iterations <= 6, "{shown:?}");
            assert!(*h.last().unwrap() <= 1e-9 * h[0], "{shown:?}");
            for w in h.windows(2).filter(|w| w[0] < 1e-2 * h[0] && w[1] > 1e-13) {
                assert!(w[1] <= w[0] * w[0], "not quadratic: {shown:?}");
            }
            (0..mesh.num_nodes())
                .map(|k| {
                    let x = mesh.coords[k][0];
                    (r.solution.temperature[k] - (300.0 + 100.0 * x * (1.0 - x))).abs()
                })
                .fold(0.0f64, f64::max)
        })
        .collect();
    let rate = (errors[0] / errors[1]).log2();
    eprintln!("nodal errors {errors:.3?} K, rate {rate:.3}");
    assert!(
        (1.9..2.1).contains(&rate),
        "rate {rate} (errors {errors:?})"
    );
}

/// A bad source is an input error E0714 pointing at the `value` line of its
/// `[[source]]` in the problem file, with a help line: a Lua syntax error, an unknown
/// variable, a table whose times do not increase. One that passes that trial but fails
/// later (past x = 0.5 in a steady run, from t = 0.25 in a transient one) stops the run
/// with the point (and the block and time).
#[test]
fn bad_sources_are_reported_at_their_line() {
    let tmp = scratch("sources-bad");
    let dir = tmp.path();
    slab(dir, 2);
    for (value, expect) in [
        ("\"600*\"", "syntax error"),
        ("\"q0*x\"", "q0"),
        ("{ table = [[1.0, 1.0], [0.5, 2.0]] }", "increase"),
    ] {
        let e = run(
            dir,
            &format!(
                "[[material]]\nblocks = [\"block_1\"]\nconductivity = 1.0\n{SLAB_BCS}[[source]]\nblocks = [\"block_1\"]\nvalue = {value}\n"
            ),
        )
        .err()
        .unwrap();
        eprintln!("{e}");
        // The problem file: [mesh] 2 lines, [[material]] 3, [[bc]] 4, [[source]] 2; the value on line 12.
        assert!(e.contains("error[E0714]: [[source]] #1"), "{e}");
        assert!(e.contains("problem.toml:12:9"), "{e}");
        assert!(e.contains(&format!("12 | value = {value}")), "{e}");
        assert!(
            e.contains("= help: Q (W/m³, finite and within ±1e100) is a number"),
            "{e}"
        );
        assert!(e.contains(expect), "{e}");
    }
    let materials = "[[material]]\nblocks = [\"block_1\"]\nconductivity = 1.0\nrho_c = 1.0\n";
    let e = run(
        dir,
        &format!("{materials}{SLAB_BCS}[[source]]\nblocks = [\"block_1\"]\nvalue = \"x < 0.5 and 1 or 0/0\"\n"),
    )
    .err()
    .unwrap();
    assert!(
        e.contains("[[source]]") && e.contains("returned NaN") && e.contains(" at (0."),
        "{e}"
    );
    let e = run(
        dir,
        &format!("{materials}{SLAB_BCS}[[source]]\nblocks = [\"block_1\"]\nvalue = \"t < 0.25 and 1 or nil\"\n[initial]\ntemperature = 300.0\n[solve]\nkind = \"transient\"\ndt = 0.1\nend_time = 1.0\n"),
    )
    .err()
    .unwrap();
    eprintln!("{e}");
    assert!(
        e.contains("source of block 1") && e.contains("nil") && e.contains("t = 0.3"),
        "{e}"
    );
}
