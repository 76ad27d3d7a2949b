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

use std::path::Path;

use seam::mesh::Mesh;
use seam::mesh::generate::{self, BoxSpec};
use seam::run::{RunError, RunResult};

pub(crate) const L1: f64 = 0.6;
pub(crate) const L: f64 = 1.5;
const D: [f64; 2] = [2e-3, 5e-4];
const C0: f64 = 10.0;
const CL: f64 = 1.0;

/// The bars with `n` cells across and `m` along, per block (also the voltage and k(T)
/// bars of `voltage_ties.rs` and `conductivity_of_t.rs`).
pub(crate) fn bars(n: [usize; 2], m: [usize; 2]) -> Mesh {
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

/// Write the case `name` (mesh, deck, problem) into a scratch folder and run it.
pub(crate) fn run_case(name: &str, mesh: &Mesh, deck: &str, problem: &str) -> RunResult {
    let scratch = crate::scratch(&format!("species-{name}"));
    let dir = scratch.path();
    crate::twod::write_mesh(&dir.join("bars.exo"), mesh);
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => r,
        Err(RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(RunError::Solve(e)) => panic!("{e}"),
    }
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
        let r = run_case(
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
    }
}

#[test]
fn a_mass_transfer_interface_and_an_offset_match_the_closed_form() {
    let mesh = bars([3, 2], [3, 4]);
    // (species lines, K, Δc, h).
    let h = 4e-3;
    let cases = [
        (
            format!("  enforcement for species = conductance\n  gap conductance coefficient = constant h = {h}\n  partition coefficient = 2"),
            2.0,
            0.0,
            h,
        ),
        (
            format!("  enforcement for species = gap_conductance\n  gap conductance coefficient = constant h = {h}\n  partition coefficient = 0.5\n  offset species = 1.5"),
            0.5,
            1.5,
            h,
        ),
        (
            format!("  enforcement for species = contact_resistance h = {h}"),
            1.0,
            0.0,
            h,
        ),
        // A coefficient of the temperature sees the temperature field: the thermal tie
        // puts the interface at T_i = 2500/7 K (k = 10 and 20 from 300 K to 400 K).
        (
            format!("  enforcement for species = gap_conductance\n  gap conductance coefficient = lua \"{h} * (1 + 0.01 * (temp_a - 300))\""),
            1.0,
            0.0,
            h * (1.0 + 0.01 * (2500.0 / 7.0 - 300.0)),
        ),
        (
            "  enforcement for species = tied_species\n  partition coefficient = 2\n  offset species = constant value = -2.5".to_string(),
            2.0,
            -2.5,
            f64::INFINITY,
        ),
        (
            "  enforcement for species = tied multipliers = dual\n  side b variable species to species\n  offset species = 3".to_string(),
            1.0,
            3.0,
            f64::INFINITY,
        ),
    ];
    for (i, (lines, k, dc, h)) in cases.iter().enumerate() {
        let r = run_case(
            &format!("transfer-{i}"),
            &mesh,
            &deck(lines),
            &problem(&held_ends(), STEADY),
        );
        let (exact, j) = closed_form(*k, *dc, *h);
        let err = worst_error(&r, &exact);
        let ((ca, cb), _) = at_interface(&r);
        let flux = &r.summary.species_contacts[0];
        // The interface law at the solution: a tie holds c_A − K c_B = Δc, a transfer
        // interface carries h (c_A − K c_B − Δc).
        let law = if h.is_finite() {
            (h * (ca - k * cb - dc) - flux.flux_side_a).abs() / j
        } else {
            (ca - k * cb - dc).abs() / C0
        };
        eprintln!(
            "case {i} (K = {k}, Δc = {dc}, h = {h}): worst nodal error {err:.1e} (of c0); c_A = {ca:.12}, c_B = {cb:.12}, interface law off by {law:.1e}; flux {:.12e} mol/s (exact {j:.12e})",
            flux.flux_side_a
        );
        assert!(err < 1e-12, "case {i}: worst nodal error {err:e}");
        assert!(law < 1e-12, "case {i}: interface law off by {law:e}");
        assert!(
            (flux.flux_side_a - j).abs() < 1e-10 * j.abs(),
            "case {i}: flux"
        );
    }
}

/// ∫ φ c dV over each block of a run's final concentration (trilinear hexes on boxes:
/// the volume times the mean of the eight nodal values is exact).
fn block_mass(r: &RunResult, phi: [f64; 2]) -> [f64; 2] {
    let c = r.species.as_ref().expect("a species field");
    let mesh = &r.mesh;
    let mut out = [0.0; 2];
    for (b, block) in mesh.blocks.iter().enumerate() {
        for k in 0..block.len() {
            let e = seam::mesh::ElemId(block.first_elem.0 + k as u32);
            let nodes: Vec<_> = mesh.elem_nodes(e).to_vec();
            let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
            for n in &nodes {
                for d in 0..3 {
                    lo[d] = lo[d].min(mesh.coords[n.index()][d]);
                    hi[d] = hi[d].max(mesh.coords[n.index()][d]);
                }
            }
            let volume: f64 = (0..3).map(|d| hi[d] - lo[d]).product();
            let mean = nodes.iter().map(|n| c[n.index()]).sum::<f64>() / nodes.len() as f64;
            out[b] += phi[b] * volume * mean;
        }
    }
    out
}

#[test]
fn what_enters_leaves_steady_and_a_transient_run_keeps_its_mass() {
    let mesh = bars([2, 3], [3, 3]);
    let j0 = 0.02;
    let inflow =
        format!("[[bc]]\nkind = \"species_flux\"\nsurfaces = [\"surface_1\"]\nvalue = {j0}\n");
    let tie = "  enforcement for species = tied_species\n  partition coefficient = 3";
    // Steady: j0 enters at z = 0 through the unit section, crosses the interface and
    // leaves through the held end.
    let held = format!("[[bc]]\nkind = \"species\"\nsurfaces = [\"surface_4\"]\nvalue = {CL}\n");
    let r = run_case(
        "balance",
        &mesh,
        &deck(tie),
        &problem(&(inflow.clone() + &held), STEADY),
    );
    let flux = &r.summary.species_contacts[0];
    eprintln!(
        "steady: {j0} mol/s enters, {:.15e} crosses (side B {:.15e}, imbalance {:.1e})",
        flux.flux_side_a, flux.flux_side_b, flux.imbalance
    );
    assert!((flux.flux_side_a - j0).abs() < 1e-12 * j0);
    assert!(flux.imbalance.abs() < 1e-14 * j0);
    // Transient, from c = 0, nothing leaving: the mass in the bars is j0 t at every
    // step (backward Euler with a lumped capacity conserves it exactly), and block 2
    // gains what crosses the interface, Σ Δt j_Γ.
    let phi = [0.5, 1.0];
    let text = problem(
        &inflow,
        "[solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 20.0\nend_time = 100.0\ntolerance = 1e-13\n[initial]\ntemperature = 350.0\n",
    )
    .replacen("diffusivity = ", "species_capacity = 0.5\ndiffusivity = ", 1);
    let r = run_case("mass", &mesh, &deck(tie), &text);
    let mass = block_mass(&r, phi);
    let t = r.history.last().unwrap().time;
    let total = mass[0] + mass[1];
    let crossing: f64 = r.species_flux.iter().map(|s| 20.0 * s[0].0).sum();
    let ((ca, cb), _) = at_interface(&r);
    eprintln!(
        "transient to t = {t}: mass {total:.15e} mol against j0 t = {:.15e} (relative {:.1e}); block 2 holds {:.15e}, Σ dt·flux = {crossing:.15e}; c_A/c_B = {:.6} (a Nitsche tie holds the jump weakly where c is not linear)",
        j0 * t,
        (total - j0 * t).abs() / (j0 * t),
        mass[1],
        ca / cb
    );
    assert!(
        (total - j0 * t).abs() < 1e-10 * j0 * t,
        "mass {total} against {}",
        j0 * t
    );
    assert!((mass[1] - crossing).abs() < 1e-10 * mass[1], "block 2");
}

/// `seam check` of the two-bar case with `edit` applied to the problem file and the
/// species block `species`: each error's code with the file name and line it points at.
fn check_errors(
    edit: impl Fn(&str) -> String,
    species: &str,
) -> Vec<(String, Option<(String, u32)>)> {
    let scratch = crate::scratch("species-check");
    let dir = scratch.path();
    crate::twod::write_mesh(&dir.join("bars.exo"), &bars([2, 3], [2, 2]));
    std::fs::write(dir.join("contact.i"), deck(species)).unwrap();
    let text = edit(&problem(&held_ends(), STEADY));
    std::fs::write(dir.join("problem.toml"), text).unwrap();
    match seam::run::check(&dir.join("problem.toml")) {
        Err(RunError::Input(d, _)) => d
            .errors()
            .map(|d| {
                let at = d.loc.as_ref().map(|l| {
                    let file = Path::new(&*l.file).file_name().unwrap();
                    (file.to_string_lossy().to_string(), l.line)
                });
                (d.code.to_string(), at)
            })
            .collect(),
        Ok(_) => Vec::new(),
        Err(e) => panic!("{e:?}"),
    }
}

#[test]
fn species_input_that_cannot_be_solved_is_refused_where_it_is_written() {
    let same = |s: &str| s.to_string();
    let tie = "  enforcement for species = tied_species\n  partition coefficient = 2";
    assert!(check_errors(same, tie).is_empty(), "the case itself checks");
    // The deck's lines: the species block opens on line 11 (`begin enforcement mass`),
    // its model on 12, its partition coefficient on 13.
    let at = |line: u32| Some(("contact.i".to_string(), line));
    // Block 2 without a diffusivity, named by the species interface: at the block.
    let bare = |s: &str| s.replacen("diffusivity = 0.0005\n", "", 1);
    let found = check_errors(bare, tie);
    eprintln!("missing diffusivity: {found:?}");
    assert!(found.contains(&("E0432".to_string(), at(11))), "{found:?}");
    // A negative partition coefficient: at its value.
    let negative = "  enforcement for species = tied_species\n  partition coefficient = -2";
    assert_eq!(
        check_errors(same, negative),
        [("E0227".to_string(), at(13))]
    );
    // Porous species is not solved: at the equation.
    let porous = "  enforcement for porous_species = tied_species";
    assert_eq!(check_errors(same, porous), [("E0219".to_string(), at(12))]);
    // A temperature-dependent mass-transfer coefficient sees the temperature field: no
    // refusal.
    let gas = "  enforcement for species = gap_conductance\n  gap conductance coefficient = lua \"1e-3 + 1e-6 * temp_a\"";
    assert_eq!(check_errors(same, gas), []);
    // A species condition where no block carries a species: at its kind.
    let none = |s: &str| {
        s.replace("diffusivity = 0.002\n", "")
            .replace("diffusivity = 0.0005\n", "")
    };
    let found = check_errors(none, "  enforcement for energy = tied_temperature");
    eprintln!("no species: {found:?}");
    assert_eq!(found.first().map(|f| f.0.as_str()), Some("E0706"));
    assert_eq!(
        found
            .first()
            .and_then(|f| f.1.as_ref())
            .map(|f| f.0.as_str()),
        Some("problem.toml")
    );
}
