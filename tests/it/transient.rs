//! Transient and nonlinear runs of `seam run`: temporal order of backward Euler and
//! BDF2, restart bit for bit, toggles, two fields joined by `Side B Variable`, a nodal
//! contact pressure (from Lua or from an Exodus variable), radiation and k(T).
//!
//! Every case runs on the bundled two-block mesh (base k = 16 under lid k = 200, joined
//! through a non-matching interface at z = 1) with problem files written here.

use std::path::{Path, PathBuf};

use seam::run::{RunError, RunResult};

use crate::scratch;

fn mesh() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks/two_blocks.exo")
}

const GAP_DECK: &str = "begin contact definition
  contact surface base_face contains base_top
  contact surface lid_face contains lid_bottom
  begin interaction
    side a base_face
    side b lid_face
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 500
  end
end
";

/// Write `contact.i` and `problem.toml` (the mesh line is added) and run.
fn run_case(dir: &Path, deck: &str, problem: &str) -> Result<RunResult, String> {
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    let text = format!(
        "[mesh]\nfile = {:?}\n[contact]\nfile = \"contact.i\"\n{problem}",
        mesh().display().to_string()
    );
    std::fs::write(dir.join("problem.toml"), text).unwrap();
    match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => Ok(r),
        Err(RunError::Input(d, s)) => Err(d.render(&s)),
        Err(RunError::Solve(e)) => Err(e),
    }
}

fn ok(dir: &Path, deck: &str, problem: &str) -> RunResult {
    run_case(dir, deck, problem).unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
}

/// Materials with a capacity that makes the diffusion time of the blocks about 1 s
/// (base: L²ρc/k = 1·ρc/16).
const MATERIALS: &str = "[[material]]
blocks = [\"base\"]
conductivity = 16.0
rho_c = 16.0
[[material]]
blocks = [\"lid\"]
conductivity = 200.0
density = 100.0
specific_heat = 1.0
";

/// Smooth data: the base's bottom held at 300 K, the lid's top warmed from 300 K
/// along a smooth curve; the initial field matches the data at t = 0.
const WARMING: &str = "[[bc]]
kind = \"temperature\"
surfaces = [\"base_bottom\"]
value = 300.0
[[bc]]
kind = \"temperature\"
surfaces = [\"lid_top\"]
value = \"300 + 100*math.sin(2*t)\"
[initial]
temperature = 300.0
";

fn transient(dir: &Path, scheme: &str, dt: f64, end: f64, extra: &str) -> RunResult {
    ok(
        dir,
        GAP_DECK,
        &format!(
            "{MATERIALS}{WARMING}[solve]\nkind = \"transient\"\nscheme = \"{scheme}\"\ndt = {dt}\nend_time = {end}\n{extra}"
        ),
    )
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Temporal order: with steps halved from 1/8 to 1/128 s, the differences between
/// successive runs at t = 1 shrink by 2^p. Backward Euler must show p = 1 and BDF2
/// p = 2 over the last halving: within ±0.15 for backward Euler; within −0.15/+0.25
/// for BDF2, whose rate approaches 2 from above here (2.7, 2.3, 2.2 measured on the
/// coarser halvings: the backward-Euler start step and the next error term).
#[test]
fn backward_euler_is_first_order_and_bdf2_second() {
    let tmp = scratch("transient-order");
    let dir = tmp.path();
    for (scheme, order, above) in [("backward_euler", 1.0, 0.15), ("bdf2", 2.0, 0.25)] {
        let runs: Vec<Vec<f64>> = [8.0, 16.0, 32.0, 64.0, 128.0]
            .iter()
            .map(|n| {
                let r = transient(dir, scheme, 1.0 / n, 1.0, "");
                assert_eq!(r.history.len(), *n as usize, "{scheme}: one step per dt");
                r.solution.temperature
            })
            .collect();
        let diffs: Vec<f64> = runs.windows(2).map(|w| max_diff(&w[0], &w[1])).collect();
        let rates: Vec<f64> = diffs.windows(2).map(|w| (w[0] / w[1]).log2()).collect();
        eprintln!("{scheme}: differences {diffs:.3?}, rates {rates:.3?}");
        let last = *rates.last().unwrap();
        assert!(
            last > order - 0.15 && last < order + above,
            "{scheme}: rate {last:.3}, expected {order} (differences {diffs:?})"
        );
        assert!(diffs[0] > 1e-3, "{scheme}: the study must see a time error");
    }
}

/// Conservation in time: over every step, the heat through side A and side B of the
/// conductance balances to round-off (1e-12 of the heat).
#[test]
fn interface_heat_balances_every_step() {
    let tmp = scratch("transient-balance");
    let dir = tmp.path();
    let r = transient(
        dir,
        "bdf2",
        0.05,
        0.5,
        "[output]\ndir = \"out\"\nevery = 2\n",
    );
    for s in &r.history {
        let (a, b) = s.heat[0];
        assert!(a.abs() > 1e-6, "step {}: no heat crosses", s.step);
        assert!(
            (a + b).abs() <= 1e-12 * a.abs().max(b.abs()),
            "step {}: {a} + {b}",
            s.step
        );
    }
    // The files a transient run writes.
    let out = dir.join("out");
    for f in [
        "temperature.pvd",
        "temperature_00010.vtu",
        "temperature_00002.vtu",
        "steps.csv",
        "interface_heat.csv",
        "checkpoint.seam",
    ] {
        assert!(out.join(f).exists(), "{f} missing");
    }
    assert!(
        !out.join("temperature_00001.vtu").exists(),
        "every = 2 writes even steps only"
    );
    let csv = std::fs::read_to_string(out.join("interface_heat.csv")).unwrap();
    assert_eq!(csv.lines().count(), 1 + 10, "{csv}");
}

/// Restart: a run stopped at step 7 and continued from its checkpoint ends bit for bit
/// where the uninterrupted run ends, for BDF2 (whose state holds two past steps).
#[test]
fn restart_reproduces_the_run_bit_for_bit() {
    let tmp = scratch("transient-restart");
    let dir = tmp.path();
    let full = transient(
        dir,
        "bdf2",
        0.05,
        0.6,
        "[output]\ndir = \"out\"\ncheckpoint_every = 7\n",
    );
    let checkpoint = dir.join("out/checkpoint_00007.seam");
    assert!(checkpoint.exists());
    let again = transient(
        dir,
        "bdf2",
        0.05,
        0.6,
        &format!("[restart]\nfile = {:?}\n", checkpoint.display().to_string()),
    );
    assert_eq!(again.history.first().map(|r| r.step), Some(8));
    assert_eq!(again.history.len(), full.history.len() - 7);
    let a: Vec<u64> = full.solution.u.iter().map(|v| v.to_bits()).collect();
    let b: Vec<u64> = again.solution.u.iter().map(|v| v.to_bits()).collect();
    assert_eq!(a.len(), b.len());
    let differ = a.iter().zip(&b).filter(|(x, y)| x != y).count();
    assert_eq!(differ, 0, "{differ} dofs differ after the restart");
    // A checkpoint of another problem is refused with a clear error.
    std::fs::write(dir.join("bad.seam"), b"SEAMCKP1 too short").unwrap();
    let e = run_case(
        dir,
        GAP_DECK,
        &format!("{MATERIALS}{WARMING}[solve]\nkind = \"transient\"\ndt = 0.1\nend_time = 1\n[restart]\nfile = \"bad.seam\"\n"),
    )
    .err()
    .unwrap();
    assert!(e.contains("E0713") && e.contains("bad.seam"), "{e}");
}

/// `Use Toggle Block`: the conductance is off until t = 0.3, so no heat crosses in the
/// steps before and heat crosses after; an unknown toggle name is an input error.
#[test]
fn toggle_switches_the_enforcement_in_time() {
    let tmp = scratch("transient-toggle");
    let dir = tmp.path();
    let deck = GAP_DECK.replace(
        "    gap conductance coefficient = constant h = 500\n",
        "    gap conductance coefficient = constant h = 500\n    use toggle block = later\n",
    );
    let problem = format!(
        "{MATERIALS}{WARMING}[[toggle]]\nname = \"later\"\non = [[0.3, 10.0]]\n[solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 0.1\nend_time = 0.6\n"
    );
    let r = ok(dir, &deck, &problem);
    for s in &r.history {
        let (a, _) = s.heat[0];
        if s.time < 0.3 - 1e-9 {
            assert_eq!(a, 0.0, "t = {}: the enforcement is off", s.time);
        } else {
            assert!(a.abs() > 1e-3, "t = {}: the enforcement is on", s.time);
        }
    }
    let e = run_case(
        dir,
        &deck,
        &problem.replace("name = \"later\"", "name = \"latter\""),
    )
    .err()
    .unwrap();
    assert!(e.contains("E0711") && e.contains("later"), "{e}");
}

/// Two fields: the lid carries `temp_lid`, joined to the base's `temperature` by a
/// mortar tie with `Side B Variable temp_lid To temperature`. The nodal result equals
/// the single-field tie's to 1e-10 relative (the same equations in another dof
/// order); a missing or wrong mapping is an input error naming both fields.
#[test]
fn side_b_variable_joins_two_fields() {
    let tmp = scratch("transient-fields");
    let dir = tmp.path();
    let tie = |map: &str| {
        format!(
            "begin contact definition
  contact surface base_face contains base_top
  contact surface lid_face contains lid_bottom
  begin interaction
    side a base_face
    side b lid_face
  end
  begin enforcement
    enforcement for energy = tied
    {map}
  end
end
"
        )
    };
    let bcs = "[[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n[[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n";
    let one = ok(
        dir,
        &tie("side b variable temperature to temperature"),
        &format!(
            "[[material]]\nblocks = [\"base\"]\nconductivity = 16.0\n[[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\n{bcs}"
        ),
    );
    let two_fields = format!(
        "[[material]]\nblocks = [\"base\"]\nconductivity = 16.0\n[[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\nfield = \"temp_lid\"\n{bcs}"
    );
    let two = ok(
        dir,
        &tie("side b variable temp_lid to temperature"),
        &two_fields,
    );
    let spread = 100.0;
    let d = max_diff(&one.solution.temperature, &two.solution.temperature);
    assert!(d <= 1e-10 * spread, "two fields differ from one by {d}");
    assert!(two.solution.dofs.field("temp_lid").is_some());
    let (a, b) = (
        two.summary.interactions[0].heat_side_a,
        two.summary.interactions[0].heat_side_b,
    );
    assert!((a + b).abs() < 1e-10 * a.abs() && a.abs() > 1.0, "{a} {b}");
    let e = run_case(
        dir,
        &tie("side b variable temperature to temp_lid"),
        &two_fields,
    )
    .err()
    .unwrap();
    assert!(e.contains("E0428") && e.contains("temp_lid"), "{e}");
    let e = run_case(dir, &tie(""), &two_fields).err().unwrap();
    assert!(
        e.contains("E0428") && e.contains("Side B Variable temp_lid To temperature"),
        "{e}"
    );
}

const CMY_DECK: &str = "begin contact definition
  contact surface base_face contains base_top
  contact surface lid_face contains lid_bottom
  begin interaction
    side a base_face
    side b lid_face
  end
  begin enforcement
    enforcement for energy = contact_resistance
    gap conductance coefficient = cmy k_a = 16 k_b = 200 slope = 0.1 roughness = 1e-6 hardness = 3e9
    PRESSURE
  end
end
";

/// A nodal contact pressure: a uniform field gives the same answer as `Contact
/// Pressure` (1e-12 relative: the same numbers reach the model); a field rising in x
/// gives more heat than its smallest value and less than its largest (CMY grows with
/// pressure), so the field is really interpolated; an unknown name is an input error.
#[test]
fn contact_pressure_from_a_nodal_field() {
    let tmp = scratch("transient-pressure");
    let dir = tmp.path();
    let base = "[[material]]\nblocks = [\"base\"]\nconductivity = 16.0\n[[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\n[[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n[[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n";
    let heat = |pressure_line: &str, field: &str| {
        let r = ok(
            dir,
            &CMY_DECK.replace("PRESSURE", pressure_line),
            &format!("{base}{field}"),
        );
        r.summary.interactions[0].heat_side_a
    };
    let constant = heat("contact pressure = 1e6", "");
    let uniform = heat(
        "contact pressure variable = p",
        "[[nodal_field]]\nname = \"p\"\nvalue = 1e6\n",
    );
    assert!(
        (constant - uniform).abs() <= 1e-12 * constant.abs(),
        "{constant} vs {uniform}"
    );
    let low = heat("contact pressure = 0.5e6", "");
    let high = heat("contact pressure = 1.5e6", "");
    let ramp = heat(
        "contact pressure variable = p",
        "[[nodal_field]]\nname = \"p\"\nvalue = \"0.5e6 + 1e6*x\"\n",
    );
    assert!(
        low.abs() < ramp.abs() && ramp.abs() < high.abs(),
        "{low} {ramp} {high}"
    );
    let e = run_case(
        dir,
        &CMY_DECK.replace("PRESSURE", "contact pressure variable = q"),
        &format!("{base}[[nodal_field]]\nname = \"p\"\nvalue = 1\n"),
    )
    .err()
    .unwrap();
    assert!(e.contains("E0712"), "{e}");
}

/// A contact pressure read from a nodal variable of an Exodus file (written here with
/// seam's own writer, two steps) gives the same interface heat as the same field given
/// in Lua, to 1e-12 relative (the same numbers reach the model), whether the step is
/// picked by time, by number or by default (the last), and when the file stores the
/// nodes in another order (paired by node number). A missing variable, a time the file
/// does not hold, a file on another mesh (other count, or nodes elsewhere) are input
/// errors (E0712) naming the file and the variable.
#[test]
fn contact_pressure_from_an_exodus_variable() {
    use seam::output::exodus::ExodusWriter;
    let tmp = scratch("transient-pressure-exodus");
    let dir = tmp.path();
    let base = "[[material]]\nblocks = [\"base\"]\nconductivity = 16.0\n[[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\n[[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n[[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n";
    let deck = CMY_DECK.replace("PRESSURE", "contact pressure variable = p");
    let heat = |field: &str| {
        ok(
            dir,
            &deck,
            &format!("{base}[[nodal_field]]\nname = \"p\"\n{field}"),
        )
        .summary
        .interactions[0]
            .heat_side_a
    };
    let mesh = seam::mesh::read(&mesh()).unwrap();
    let ramp: Vec<f64> = mesh.coords.iter().map(|x| 0.5e6 + 1e6 * x[0]).collect();
    let flat = vec![1.0; mesh.num_nodes()];
    let mut w = ExodusWriter::create(&dir.join("pressure.exo"), &mesh, &["pressure"], &[]).unwrap();
    w.write_step(0.0, &[&flat], &[]).unwrap();
    w.write_step(1.0, &[&ramp], &[]).unwrap();
    w.finish().unwrap();
    let lua = heat("value = \"0.5e6 + 1e6*x\"\n");
    for pick in ["time = 1.0\n", "step = 2\n", ""] {
        let exo = heat(&format!(
            "file = \"pressure.exo\"\nvariable = \"pressure\"\n{pick}"
        ));
        eprintln!("{pick:?}: Lua {lua}, Exodus {exo}");
        assert!(
            (exo - lua).abs() <= 1e-12 * lua.abs(),
            "{pick:?}: Exodus {exo} vs Lua {lua}"
        );
    }
    // The nodes stored in reverse order with their numbers: paired by number, the same
    // heat; the same file with the numbers left in place puts nodes elsewhere: an error.
    let n = mesh.num_nodes();
    let mut reversed = mesh.clone();
    reversed.coords.reverse();
    reversed.node_numbers.reverse();
    for b in &mut reversed.blocks {
        b.connectivity
            .iter_mut()
            .for_each(|v| v.0 = (n - 1) as u32 - v.0);
    }
    for s in &mut reversed.node_sets {
        s.nodes.iter_mut().for_each(|v| v.0 = (n - 1) as u32 - v.0);
    }
    let back: Vec<f64> = ramp.iter().rev().copied().collect();
    for (name, numbers) in [
        ("reversed.exo", reversed.node_numbers.clone()),
        ("moved.exo", mesh.node_numbers.clone()),
    ] {
        let m = seam::mesh::Mesh {
            node_numbers: numbers,
            ..reversed.clone()
        };
        let mut w = ExodusWriter::create(&dir.join(name), &m, &["pressure"], &[]).unwrap();
        w.write_step(1.0, &[&back], &[]).unwrap();
        w.finish().unwrap();
    }
    let exo = heat("file = \"reversed.exo\"\nvariable = \"pressure\"\n");
    assert!(
        (exo - lua).abs() <= 1e-12 * lua.abs(),
        "reversed: {exo} vs {lua}"
    );
    let e = run_case(
        dir,
        &deck,
        &format!(
            "{base}[[nodal_field]]\nname = \"p\"\nfile = \"moved.exo\"\nvariable = \"pressure\"\n"
        ),
    )
    .err()
    .unwrap();
    assert!(
        e.contains("E0712") && e.contains("moved.exo: node") && e.contains("there but at"),
        "{e}"
    );
    // Between the stored times the field is interpolated: at t = 0.25 it is
    // 0.75 · 1 Pa + 0.25 · ramp, the same heat as that field written in Lua.
    let between = heat("file = \"pressure.exo\"\nvariable = \"pressure\"\ntime = 0.25\n");
    let blend = heat("value = \"0.75 + 0.25*(0.5e6 + 1e6*x)\"\n");
    eprintln!("t = 0.25: Exodus interpolated {between}, Lua {blend}");
    assert!(
        (between - blend).abs() <= 1e-12 * blend.abs(),
        "{between} vs {blend}"
    );
    // Step 1 holds the flat field of 1 Pa: much less heat than the ramp.
    let first = heat("file = \"pressure.exo\"\nvariable = \"pressure\"\nstep = 1\n");
    assert!(first.abs() < 0.5 * lua.abs(), "{first} vs {lua}");
    // Another mesh with the same variable.
    let other = seam::mesh::generate::boxes(
        &[seam::mesh::generate::BoxSpec::hex(
            [0.0; 3],
            [1.0; 3],
            [2, 2, 2],
            1,
        )],
        false,
    );
    let values = vec![1e6; other.num_nodes()];
    let mut w = ExodusWriter::create(&dir.join("other.exo"), &other, &["pressure"], &[]).unwrap();
    w.write_step(0.0, &[&values], &[]).unwrap();
    w.finish().unwrap();
    // (file, variable, what the message says); the caret is on the `file` line (21).
    for (file, variable, expect) in [
        ("pressure.exo", "presure", "no nodal variable `presure`"),
        (
            "pressure.exo",
            "pressure",
            "time 1.5 for `pressure` is outside",
        ),
        (
            "other.exo",
            "pressure",
            "has values at 27 nodes, but the mesh has",
        ),
    ] {
        let time = if expect.contains("1.5") {
            "time = 1.5\n"
        } else {
            ""
        };
        let field = format!("file = \"{file}\"\nvariable = \"{variable}\"\n{time}");
        let e = run_case(
            dir,
            &deck,
            &format!("{base}[[nodal_field]]\nname = \"p\"\n{field}"),
        )
        .err()
        .unwrap();
        eprintln!("{e}");
        assert!(e.contains("error[E0712]") && e.contains(expect), "{e}");
        assert!(
            e.contains(file) && e.contains(&format!("`{variable}`")),
            "{e}"
        );
        assert!(
            e.contains("problem.toml:21:8") && e.contains("= help:"),
            "{e}"
        );
    }
    let e = run_case(
        dir,
        &deck,
        &format!("{base}[[nodal_field]]\nname = \"p\"\nfile = \"pressure.exo\"\nvalue = 1.0\n"),
    )
    .err()
    .unwrap();
    assert!(
        e.contains("E0712") && e.contains("both `value` and `file`"),
        "{e}"
    );
}

/// k(T) as a Lua expression and radiation to ambient, steady: Newton converges
/// (quadratically: the last residual drops below 1e-8 of the first within 8
/// iterations) and the heat that enters at the fixed-temperature face leaves by
/// radiation — checked through the interface, which carries all of it: the interface
/// heat equals εσ∫(T⁴ − T∞⁴) over the lid's top computed here from the nodal field
/// (to 2e-2: the face integral here is a nodal trapezoid rule, seam's a Gauss rule).
#[test]
fn nonlinear_conductivity_and_radiation() {
    let tmp = scratch("transient-radiation");
    let dir = tmp.path();
    let r = ok(
        dir,
        GAP_DECK,
        "[[material]]
blocks = [\"base\", \"lid\"]
conductivity = \"10 + 0.05*T\"
[[bc]]
kind = \"temperature\"
surfaces = [\"base_bottom\"]
value = 900.0
[[bc]]
kind = \"radiation\"
surfaces = [\"lid_top\"]
value = 0.8
ambient = 300.0
",
    );
    let h = &r.history[0].residual_history;
    assert!(h.len() <= 9 && h.last().unwrap() <= &(1e-8 * h[0]), "{h:?}");
    let q = r.summary.interactions[0].heat_side_a;
    // The lid's top: z = 1.5, unit square; mean of T⁴ over its nodes (a uniform grid).
    let m = &r.mesh;
    let top: Vec<f64> = (0..m.num_nodes())
        .filter(|&n| (m.coords[n][2] - 1.5).abs() < 1e-12)
        .map(|n| r.solution.temperature[n])
        .collect();
    let mean4 = top.iter().map(|t| t.powi(4)).sum::<f64>() / top.len() as f64;
    let radiated = 0.8 * 5.670374419e-8 * (mean4 - 300f64.powi(4));
    assert!(
        (q - radiated).abs() < 2e-2 * radiated,
        "interface {q} vs radiated {radiated}"
    );
    // A table law in T is accepted and bad ones are refused with the material named.
    let e = run_case(
        dir,
        GAP_DECK,
        "[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = { table = [[300.0, 10.0], [200.0, 20.0]] }\n",
    )
    .err()
    .unwrap();
    assert!(e.contains("E0704") && e.contains("increase"), "{e}");
}

/// Boundary fields that do not go with their kind are input errors, not silent
/// defaults: convection without `ambient` (it would be 0 K), `ambient` on a
/// temperature condition, an emissivity outside (0, 1].
#[test]
fn boundary_fields_are_checked_against_their_kind() {
    let tmp = scratch("transient-bc-fields");
    let dir = tmp.path();
    let materials = "[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1.0\n";
    for (bc, expect) in [
        (
            "kind = \"convection\"\nsurfaces = [\"lid_top\"]\nvalue = 10.0\n",
            "convection needs `ambient`",
        ),
        (
            "kind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 10.0\nambient = 3.0\n",
            "not temperature",
        ),
        (
            "kind = \"radiation\"\nsurfaces = [\"lid_top\"]\nvalue = 1.5\nambient = 300.0\n",
            "emissivity 1.5",
        ),
    ] {
        let e = run_case(dir, GAP_DECK, &format!("{materials}[[bc]]\n{bc}"))
            .err()
            .unwrap();
        assert!(e.contains("E0706") && e.contains(expect), "{e}");
    }
}

/// A linear step is solved with one assembly: its residual and interface heat after the
/// solve are carried forward as R + J du instead of being assembled again. The same
/// conductance written as a Lua expression counts as temperature-dependent, so that run
/// takes full Newton steps with a fresh assembly at every iterate. Both must report the
/// same heat at every step and end at the same temperatures, to the Newton tolerance
/// (1e-10 relative; the difference measured is far below it), and the linear run must
/// take one Newton iteration per step while the other takes at least two.
#[test]
fn linear_steps_carry_their_residual_exactly() {
    let lua_deck = GAP_DECK.replace("constant h = 500", "lua \"500 + 0*temp_a\"");
    assert_ne!(lua_deck, GAP_DECK);
    let problem = format!(
        "{MATERIALS}{WARMING}[solve]\nkind = \"transient\"\nscheme = \"bdf2\"\ndt = 0.1\nend_time = 1.0\ntolerance = 1e-12\n"
    );
    let linear = ok(scratch("transient-carry-linear").path(), GAP_DECK, &problem);
    let newton = ok(
        scratch("transient-carry-newton").path(),
        &lua_deck,
        &problem,
    );
    assert_eq!(linear.history.len(), newton.history.len());
    for (l, n) in linear.history.iter().zip(&newton.history) {
        assert_eq!(l.newton_iterations, 1, "step {}: linear", l.step);
        assert!(n.newton_iterations >= 2, "step {}: Newton", n.step);
        let (a, b) = (l.heat[0].0, n.heat[0].0);
        assert!(
            (a - b).abs() <= 1e-10 * b.abs(),
            "step {}: heat {a} (one assembly) against {b} (Newton)",
            l.step
        );
        assert!(
            *l.residual_history.last().unwrap() <= 1e-9 * l.residual_history[0],
            "step {}: residual {:?}",
            l.step,
            l.residual_history
        );
    }
    let spread = newton
        .solution
        .temperature
        .iter()
        .fold(0.0f64, |m, t| m.max((t - 300.0).abs()));
    let d = max_diff(&linear.solution.temperature, &newton.solution.temperature);
    eprintln!("one assembly vs Newton: max temperature difference {d:e} K over a {spread} K rise");
    assert!(d <= 1e-10 * spread);
}

/// A linear problem keeps its element matrices from step to step and only recomputes
/// them when a face condition's derivative changes. Here the convection coefficient on
/// the lid follows a table in time, so the kept matrices go stale at every step unless
/// they are refreshed. The same problem with the base's conductivity written as a Lua
/// expression of T is solved by full Newton with every matrix recomputed: both must end
/// at the same temperatures (1e-10 of the rise; a stale h moves them by percents).
#[test]
fn kept_element_matrices_follow_a_changing_convection() {
    let case = |conductivity: &str, name: &str| {
        let problem = format!(
            "[[material]]
blocks = [\"base\"]
conductivity = {conductivity}
rho_c = 16.0
[[material]]
blocks = [\"lid\"]
conductivity = 200.0
rho_c = 100.0
[[bc]]
kind = \"temperature\"
surfaces = [\"base_bottom\"]
value = 300.0
[[bc]]
kind = \"convection\"
surfaces = [\"lid_top\"]
value = {{ table = [[0.0, 10.0], [0.5, 2000.0], [1.0, 50.0]] }}
ambient = 400.0
[initial]
temperature = 300.0
[solve]
kind = \"transient\"
scheme = \"bdf2\"
dt = 0.05
end_time = 1.0
tolerance = 1e-13
"
        );
        ok(
            scratch(&format!("transient-{name}")).path(),
            GAP_DECK,
            &problem,
        )
    };
    let kept = case("16.0", "kept-constant");
    let newton = case("\"16 + 0*T\"", "kept-lua");
    assert!(kept.history.iter().all(|s| s.newton_iterations == 1));
    assert!(newton.history.iter().any(|s| s.newton_iterations >= 2));
    let rise = newton
        .solution
        .temperature
        .iter()
        .fold(0.0f64, |m, t| m.max(t - 300.0));
    let d = max_diff(&kept.solution.temperature, &newton.solution.temperature);
    eprintln!("kept matrices vs Newton under h(t): {d:e} K over a {rise} K rise");
    assert!(rise > 1.0, "the convection must warm the body");
    assert!(d <= 1e-10 * rise, "{d} K");
}
