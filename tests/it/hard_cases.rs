//! Hard cases: the interface heat as accurate as the temperatures for every conductance
//! from 0 to ∞, at conductivity contrasts to 1e8.
//!
//! The case: the bundled two-block mesh (base k_A on z ∈ [0, 1], 6×6×6 hexes; lid k_B on
//! z ∈ [1, 1.5], 4×4×3 hexes, non-matching at z = 1), 300 K below, 400 K on top, sides
//! insulated. The exact field is piecewise linear in z, which the elements hold, so the
//! discrete heat must be the series value 100 / (1/k_A + 1/h + 0.5/k_B) to round-off,
//! on both sides of the interface.

use std::path::Path;

use crate::scratch;

/// The conductances swept: every few decades from 0 to ∞.
pub(crate) const H_SWEEP: [f64; 16] = [
    0.0, 1e-12, 1e-8, 1e-4, 1.0, 1e2, 1e4, 1e6, 1e8, 1e12, 1e16, 1e20, 1e50, 1e100, 1e200, 1e300,
];

/// Conductivity pairs (k_A, k_B): the bundled scene's, and contrasts of 1e8 both ways.
const CONTRASTS: [(f64, f64); 3] = [(16.0, 200.0), (1.0, 1e8), (1e8, 1.0)];

/// The exact heat from the lid into the base.
pub(crate) fn exact_heat(h: f64, k_a: f64, k_b: f64) -> f64 {
    if h == 0.0 {
        return 0.0;
    }
    100.0 / (1.0 / k_a + 1.0 / h + 0.5 / k_b)
}

/// Solve the two-block case with `enforcement` (the lines inside `begin enforcement`);
/// returns the heat into side A (the base) and out of side B (the lid), both positive
/// when heat flows down.
pub(crate) fn two_block_heat(name: &str, k_a: f64, k_b: f64, enforcement: &str) -> (f64, f64) {
    let tmp = scratch(&format!("hard-{name}"));
    let dir = tmp.path();
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks/two_blocks.exo");
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = {mesh:?}\n\
             [[material]]\nblocks = [\"base\"]\nconductivity = {k_a:e}\n\
             [[material]]\nblocks = [\"lid\"]\nconductivity = {k_b:e}\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n\
             [contact]\nfile = \"contact.i\"\n",
            mesh = mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n  contact surface base_face contains base_top\n  contact surface lid_face contains lid_bottom\n\
             begin interaction\n  side a base_face\n  side b lid_face\n end\n begin enforcement\n{enforcement}\n end\nend\n"
        ),
    )
    .unwrap();
    match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => {
            assert!(r.summary.converged, "{name}: not converged");
            let i = &r.summary.interactions[0];
            (-i.heat_side_a, i.heat_side_b)
        }
        Err(seam::run::RunError::Input(d, s)) => panic!("{name}: {}", d.render(&s)),
        Err(seam::run::RunError::Solve(e)) => panic!("{name}: {e}"),
    }
}

/// Sweep `h` for one model (`lines` with `H` standing for the conductance) at every
/// contrast; returns the worst relative error of either side's heat, and prints each.
pub(crate) fn sweep(model: &str, lines: &str, hs: &[f64]) -> f64 {
    let mut worst = 0.0f64;
    for (c, &(k_a, k_b)) in CONTRASTS.iter().enumerate() {
        for &h in hs {
            let text = if h.is_infinite() {
                "inf".to_string()
            } else {
                format!("{h:e}")
            };
            let (a, b) = two_block_heat(
                &format!("{model}-{c}-{text}"),
                k_a,
                k_b,
                &lines.replace('H', &text),
            );
            let exact = exact_heat(h, k_a, k_b);
            // At h = 0 nothing crosses: judge against the heat at h = 1 instead.
            let scale = if exact == 0.0 {
                exact_heat(1.0, k_a, k_b)
            } else {
                exact
            };
            let err = ((a - exact).abs()).max((b - exact).abs()) / scale;
            println!(
                "{model:<20} k_A {k_a:>6e} k_B {k_b:>6e} h {text:>7}: side A {a:.15e}, side B {b:.15e}, exact {exact:.15e}, rel err {err:.1e}"
            );
            worst = worst.max(err);
        }
    }
    println!("{model}: worst relative error {worst:.1e}");
    worst
}

/// Relative error allowed: the temperatures of this case are exact to about 1e-13 of
/// their range; the heat through a 1e8 contrast sums element fluxes of size k ΔT/L with
/// k up to 1e8, so a few more digits go to round-off there.
const TOLERANCE: f64 = 1e-9;

#[test]
fn contact_resistance_heat_is_exact_for_every_h() {
    let mut hs = H_SWEEP.to_vec();
    hs.push(f64::INFINITY);
    let worst = sweep(
        "contact_resistance",
        "  enforcement for energy = contact_resistance h = H",
        &hs,
    );
    assert!(worst <= TOLERANCE, "worst relative error {worst:e}");
}

#[test]
fn gap_conductance_heat_is_exact_for_every_h() {
    let mut hs = H_SWEEP.to_vec();
    hs.push(f64::INFINITY);
    let worst = sweep(
        "gap_conductance",
        "  enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = H",
        &hs,
    );
    assert!(worst <= TOLERANCE, "worst relative error {worst:e}");
}

#[test]
fn lua_conductance_heat_is_exact_for_every_finite_h() {
    // A Lua model returns a number; ∞ is not one (refused as not finite).
    let worst = sweep(
        "lua",
        "  enforcement for energy = contact_resistance\n  gap conductance coefficient = lua \"H\"",
        &H_SWEEP,
    );
    assert!(worst <= TOLERANCE, "worst relative error {worst:e}");
}

/// A run that does not converge exits 1, leaves its last iterate marked by a
/// `NOT_CONVERGED` file and says why: the residual history and the likely cause. A run
/// that converges in the same folder removes the mark.
#[test]
fn a_run_that_does_not_converge_says_so_and_why() {
    let tmp = scratch("hard-not_converged");
    let dir = tmp.path();
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks/two_blocks.exo");
    let problem = |iterations: usize| {
        format!(
            "[mesh]\nfile = {mesh:?}\n[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = \"16 + 0.5*T\"\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n\
             [[bc]]\nkind = \"radiation\"\nsurfaces = [\"lid_top\"]\nvalue = 0.8\nambient = 2000.0\n\
             [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\nmax_iterations = {iterations}\n[output]\ndir = \"out\"\n",
            mesh = mesh.to_str().unwrap()
        )
    };
    std::fs::write(
        dir.join("contact.i"),
        "begin contact definition\n  contact surface a contains base_top\n  contact surface b contains lid_bottom\n  begin interaction\n    side a a\n    side b b\n  end\n  begin enforcement\n    enforcement for energy = contact_resistance h = 500\n  end\nend\n",
    )
    .unwrap();
    std::fs::write(dir.join("problem.toml"), problem(2)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_seam"))
        .args(["run", "problem.toml", "--json"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let summary: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(summary["converged"], false);
    let why = summary["diagnosis"].as_str().unwrap();
    // Three residuals (the guess and two iterates), growing from a guess far away.
    assert_eq!(why.matches('→').count(), 2, "{why}");
    assert!(why.contains("the residual grew"), "{why}");
    let mark = std::fs::read_to_string(dir.join("out").join(seam::run::NOT_CONVERGED)).unwrap();
    assert_eq!(mark.trim(), why);
    assert!(dir.join("out/temperature.vtu").exists());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("error[E0800]") && err.contains(why), "{err}");

    std::fs::write(dir.join("problem.toml"), problem(50)).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_seam"))
        .args(["run", "problem.toml", "--json"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!dir.join("out").join(seam::run::NOT_CONVERGED).exists());
}

/// Gaps of 1e-12, 0 and slightly negative (the lid shifted by δ along z) under a gas-gap
/// conductance h = k_gas / max(g, g_min): the heat is the series value with the gap the
/// mesh holds, on both sides.
#[test]
fn gas_gap_heat_is_exact_for_tiny_zero_and_negative_gaps() {
    use seam::output::exodus::ExodusWriter;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = seam::mesh::read(&root.join("examples/two_blocks/two_blocks.exo")).unwrap();
    let lid = base
        .blocks
        .iter()
        .position(|b| b.name == "lid")
        .expect("the lid block");
    let (k_gas, g_min) = (0.026, 1e-14);
    let mut worst = 0.0f64;
    for delta in [1e-12, 0.0, -1e-12] {
        let mut mesh = base.clone();
        let mut moved = vec![false; mesh.num_nodes()];
        for e in mesh.blocks[lid].elems() {
            for n in mesh.elem_nodes(e) {
                moved[n.index()] = true;
            }
        }
        for (x, m) in mesh.coords.iter_mut().zip(&moved) {
            if *m {
                x[2] += delta;
            }
        }
        let tmp = scratch(&format!("hard-gap-{delta:e}"));
        let dir = tmp.path();
        let path = dir.join("shifted.exo");
        ExodusWriter::create(&path, &mesh, &[], &[])
            .unwrap()
            .finish()
            .unwrap();
        std::fs::write(
            dir.join("problem.toml"),
            "[mesh]\nfile = \"shifted.exo\"\n[[material]]\nblocks = [\"base\"]\nconductivity = 16.0\n\
             [[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n[contact]\nfile = \"contact.i\"\n",
        )
        .unwrap();
        std::fs::write(
            dir.join("contact.i"),
            format!(
                "begin contact definition\n  contact surface a contains base_top\n  contact surface b contains lid_bottom\n  begin interaction\n    side a a\n    side b b\n  end\n  begin enforcement\n    enforcement for energy = gap_conductance\n    gap conductance coefficient = gas_gap k = {k_gas} min_gap = {g_min:e}\n  end\nend\n"
            ),
        )
        .unwrap();
        let r = seam::run::run(&dir.join("problem.toml")).unwrap_or_else(|e| panic!("{e:?}"));
        let i = &r.summary.interactions[0];
        // The gap the mesh holds: fl(1 + δ) − 1.
        let g = (1.0 + delta) - 1.0;
        let exact = exact_heat(k_gas / f64::max(g, g_min), 16.0, 200.0);
        let err = (-i.heat_side_a - exact)
            .abs()
            .max((i.heat_side_b - exact).abs())
            / exact;
        println!(
            "gap {delta:e}: heat {} / {}, exact {exact}, rel err {err:.1e}",
            -i.heat_side_a, i.heat_side_b
        );
        worst = worst.max(err);
    }
    assert!(worst <= TOLERANCE, "{worst:e}");
}

/// The per-face interface flux that `Visualize Contact` writes is as exact as the heat
/// for huge and infinite conductances: uniform, and equal to the series flux, on every
/// face of side A.
#[test]
fn contact_flux_per_face_is_exact_for_huge_h() {
    for h in ["1e8", "1e20", "1e300", "inf"] {
        let tmp = scratch(&format!("hard-faces-{h}"));
        let dir = tmp.path();
        let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks/two_blocks.exo");
        std::fs::write(
            dir.join("problem.toml"),
            format!(
                "[mesh]\nfile = {mesh:?}\n[[material]]\nblocks = [\"base\"]\nconductivity = 16.0\n\
                 [[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\n\
                 [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n\
                 [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n\
                 [contact]\nfile = \"contact.i\"\n[output]\ndir = \"out\"\n",
                mesh = mesh.to_str().unwrap()
            ),
        )
        .unwrap();
        std::fs::write(
            dir.join("contact.i"),
            format!(
                "begin contact definition\n  contact surface a contains base_top\n  contact surface b contains lid_bottom\n  visualize contact\n  begin interaction\n    side a a\n    side b b\n  end\n  begin enforcement\n    enforcement for energy = contact_resistance h = {h}\n  end\nend\n"
            ),
        )
        .unwrap();
        seam::run::run(&dir.join("problem.toml")).unwrap_or_else(|e| panic!("{e:?}"));
        let xml = std::fs::read_to_string(dir.join("out/contact.vtu")).unwrap();
        let flux = crate::run_fields::vtu_array(&xml, "interface_flux");
        // Heat flows from the lid (B) into the base (A): the flux from A to B is −q.
        let exact = -exact_heat(h.parse().unwrap(), 16.0, 200.0);
        let worst = flux
            .iter()
            .map(|q| (q - exact).abs() / exact.abs())
            .fold(0.0, f64::max);
        println!(
            "h = {h}: {} faces, worst relative error of the face flux {worst:.1e}",
            flux.len()
        );
        assert_eq!(flux.len(), 36);
        assert!(worst <= 1e-9, "h = {h}: {worst:e}");
    }
}
