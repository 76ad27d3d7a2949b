//! Species through `seam run`: two bars in series, meshed apart (non-matching across the
//! interface), with a diffusing species joined by `Enforcement for Species` — ties with a
//! partition coefficient, an offset, a mass-transfer interface — against the 1-D closed
//! forms at every node; the mass balance of steady and transient runs; refusals.
//!
//! The bars: [0,1]² × [0, L1] (block 1) and [0,1]² × [L1, L] (block 2). Side sets: 1 the
//! end z = 0, 2 block 1's interface face, 3 block 2's, 4 the end z = L. The species is
//! held at c0 at z = 0 and cl at z = L; with no source the steady c is linear in each
//! bar, so the trilinear hexes hold it exactly and every node must match the closed
//! form to round-off.

use std::path::{Path, PathBuf};

use seam::mesh::Mesh;
use seam::mesh::generate::{self, BoxSpec};
use seam::run::{RunError, RunResult};

const L1: f64 = 0.6;
const L: f64 = 1.5;
const D: [f64; 2] = [2e-3, 5e-4];
const C0: f64 = 10.0;
const CL: f64 = 1.0;

/// The bars with `n` cells across and `m` along, per block.
fn bars(n: [usize; 2], m: [usize; 2]) -> Mesh {
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, L1], [n[0], n[0], m[0]], 1)
                .with_side_sets([0, 0, 0, 0, 1, 2]),
            BoxSpec::hex([0.0, 0.0, L1], [1.0, 1.0, L], [n[1], n[1], m[1]], 2)
                .with_side_sets([0, 0, 0, 0, 3, 4]),
        ],
        false,
    )
}

/// A scratch directory for one case, emptied.
fn scratch(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("species-{name}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The deck: an Energy tie and the species block `species` (its lines).
fn deck(species: &str) -> String {
    format!(
        "begin contact definition bars\n contact surface a contains surface_2\n contact surface b contains surface_3\n\
         begin interaction\n  side a a\n  side b b\n end\n\
         begin enforcement thermal\n  enforcement for energy = tied_temperature\n end\n\
         begin enforcement mass\n{species}\n end\nend\n"
    )
}

/// A problem file on `bars.exo`: the two blocks with their conductivities and
/// diffusivities, temperatures 300 K and 400 K at the ends, the species conditions
/// `bcs` and `extra` lines.
fn problem(bcs: &str, extra: &str) -> String {
    format!(
        "[mesh]\nfile = \"bars.exo\"\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = 10.0\ndiffusivity = {}\n\
         [[material]]\nblocks = [\"block_2\"]\nconductivity = 20.0\ndiffusivity = {}\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = 300.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 400.0\n\
         {bcs}[contact]\nfile = \"contact.i\"\n{extra}",
        D[0], D[1]
    )
}

/// The ends held at c0 and cl.
fn held_ends() -> String {
    format!(
        "[[bc]]\nkind = \"species\"\nsurfaces = [\"surface_1\"]\nvalue = {C0}\n\
         [[bc]]\nkind = \"species\"\nsurfaces = [\"surface_4\"]\nvalue = {CL}\n"
    )
}

const STEADY: &str = "[solve]\nkind = \"steady\"\ntolerance = 1e-13\n";

/// Write the case `name` (mesh, deck, problem) and run it.
fn run_case(name: &str, mesh: &Mesh, deck: &str, problem: &str) -> (RunResult, PathBuf) {
    let dir = scratch(name);
    crate::twod::write_mesh(&dir.join("bars.exo"), mesh);
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    let r = match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => r,
        Err(RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(RunError::Solve(e)) => panic!("{e}"),
    };
    (r, dir)
}

/// The largest difference between the run's nodal concentration and `exact(z, side)`
/// (side 0 for block 1's nodes, 1 for block 2's), relative to c0.
fn worst_error(r: &RunResult, exact: impl Fn(f64, usize) -> f64) -> f64 {
    let c = r.species.as_ref().expect("a species field");
    let mesh = &r.mesh;
    let mut worst = 0.0f64;
    for (b, block) in mesh.blocks.iter().enumerate() {
        for k in 0..block.len() {
            let e = seam::mesh::ElemId(block.first_elem.0 + k as u32);
            for n in mesh.elem_nodes(e) {
                let z = mesh.coords[n.index()][2];
                worst = worst.max((c[n.index()] - exact(z, b)).abs() / C0);
            }
        }
    }
    worst
}

/// The run's concentration on each side of the interface z = L1: (block 1's, block
/// 2's), the largest spread of either across its nodes there (0 for a 1-D field).
fn at_interface(r: &RunResult) -> ((f64, f64), f64) {
    let c = r.species.as_ref().expect("a species field");
    let mesh = &r.mesh;
    let mut sides = [Vec::new(), Vec::new()];
    for (b, block) in mesh.blocks.iter().enumerate() {
        for k in 0..block.len() {
            let e = seam::mesh::ElemId(block.first_elem.0 + k as u32);
            for n in mesh.elem_nodes(e) {
                if (mesh.coords[n.index()][2] - L1).abs() < 1e-12 {
                    sides[b].push(c[n.index()]);
                }
            }
        }
    }
    let spread = |v: &[f64]| {
        let (lo, hi) = v
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        hi - lo
    };
    let spread = spread(&sides[0]).max(spread(&sides[1]));
    ((sides[0][0], sides[1][0]), spread)
}

/// The steady 1-D concentration of the bars with the interface condition
/// `c_A = K c_B + dc` (a tie) and the flux through it, mol/m²/s (`h` = ∞), or the
/// mass-transfer law `j = h (c_A − K c_B − dc)`.
fn closed_form(k: f64, dc: f64, h: f64) -> (impl Fn(f64, usize) -> f64, f64) {
    let (l2, [d1, d2]) = (L - L1, D);
    // j = D1 (c0 − cA)/L1 = D2 (cB − cl)/L2 and cA − K cB − dc = j/h.
    let r = if h.is_finite() { 1.0 / h } else { 0.0 };
    let j = (C0 - k * CL - dc) / (L1 / d1 + k * l2 / d2 + r);
    let (ca, cb) = (C0 - j * L1 / d1, CL + j * l2 / d2);
    let exact = move |z: f64, side: usize| {
        if side == 0 {
            C0 + (ca - C0) * z / L1
        } else {
            cb + (CL - cb) * (z - L1) / l2
        }
    };
    (exact, j)
}

#[test]
fn a_partition_coefficient_tie_gives_the_exact_jump_across_a_non_matching_interface() {
    let mesh = bars([3, 4], [4, 5]);
    for (model, k) in [
        ("tied_species", 3.0),
        ("tied_species", 0.25),
        ("tied\n  side b variable species to species", 3.0),
        (
            "tied multipliers = dual\n  side b variable species to species",
            3.0,
        ),
        ("tied_ip_species", 3.0),
    ] {
        let species = format!("  enforcement for species = {model}\n  partition coefficient = {k}");
        let name = format!("tie-{}", model.len() + (k * 4.0) as usize);
        let (r, dir) = run_case(
            &name,
            &mesh,
            &deck(&species),
            &problem(&held_ends(), STEADY),
        );
        let (exact, j) = closed_form(k, 0.0, f64::INFINITY);
        let err = worst_error(&r, &exact);
        let flux = &r.summary.species_contacts[0];
        // The flux through the unit section, mol/s.
        let flux_err = (flux.flux_side_a - j).abs() / j;
        let ((ca, cb), spread) = at_interface(&r);
        let jump_err = (ca - k * cb).abs() / C0;
        eprintln!(
            "{model:?}, K = {k}: worst nodal error {err:.1e} (relative to c0); at the interface c_A = {ca:.15}, c_B = {cb:.15}, c_A/c_B = {:.15} (|c_A − K c_B|/c0 = {jump_err:.1e}, spread {spread:.1e}); flux {:.12e} mol/s (exact {j:.12e}), imbalance {:.1e}",
            ca / cb,
            flux.flux_side_a,
            flux.imbalance
        );
        assert!(
            jump_err < 1e-12 && spread < 1e-12,
            "{model}: jump {jump_err:e}"
        );
        assert!(err < 1e-12, "{model}: worst nodal error {err:e}");
        assert!(flux_err < 1e-10, "{model}: flux error {flux_err:e}");
        assert!(flux.imbalance.abs() < 1e-12 * j, "{model}: imbalance");
        std::fs::remove_dir_all(&dir).ok();
    }
}
