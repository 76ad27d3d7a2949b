//! Voltage ties and voltage-dependent electrical contacts through `seam run`: two bars in series, meshed apart (non-matching across
//! the interface), whose voltage is joined by every tie of the Energy equation —
//! `Tied_Voltage` and `Tied_Ip_Voltage` (Nitsche), `Tied` with `Side B Variable voltage
//! To voltage` (mortar multipliers, standard and dual), `Dash` — against the 1-D closed
//! form at every node, with Joule heat in the bulk, the current through the tie, and the
//! electrical power against the heat leaving.
//!
//! The bars: [0,1]² × [0, L1] (block 1, σ1, k1) and [0,1]² × [L1, L] (block 2, σ2, k2).
//! Side sets: 1 the end z = 0, 2 block 1's interface face, 3 block 2's, 4 the end z = L.
//! V is held at V0 at z = 0 and 0 at z = L; both ends lose heat by convection to T∞.
//! With a perfect joint (`V_A = V_B + ΔV`) the current density is
//! `j = (V0 − ΔV) / (L1/σ1 + L2/σ2)`, V is linear in each bar, and the temperature
//! solves `−k T'' = j²/σ`: piecewise quadratic, continuous with continuous flux across
//! the thermal mortar tie. Linear elements in 1-D hold both at the nodes, so every node
//! must match to round-off. An electrical contact conductance that depends on the
//! voltage (`Contact Gap Voltage`) gives the current of the scalar closed form.

use seam::mesh::Mesh;
use seam::run::{RunError, RunResult};

use crate::species::{L, L1, bars};

const SIGMA: [f64; 2] = [2e3, 1e3];
const K: [f64; 2] = [5.0, 2.0];
const V0: f64 = 0.9;
const H_C: f64 = 10.0;
const T_INF: f64 = 300.0;

/// The deck: a thermal mortar tie and the voltage block `voltage` (its lines).
fn deck(voltage: &str) -> String {
    format!(
        "begin contact definition bars\n contact surface a contains surface_2\n contact surface b contains surface_3\n\
         begin interaction\n  side a a\n  side b b\n end\n\
         begin enforcement thermal\n  enforcement for energy = tied\n  side b variable temperature to temperature\n end\n\
         begin enforcement electrical\n{voltage}\n end\nend\n"
    )
}

const PROBLEM: &str = "[mesh]\nfile = \"bars.exo\"\n\
    [[material]]\nblocks = [\"block_1\"]\nconductivity = 5.0\nelectrical_conductivity = 2e3\n\
    [[material]]\nblocks = [\"block_2\"]\nconductivity = 2.0\nelectrical_conductivity = 1e3\n\
    [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_1\"]\nvalue = 0.9\n\
    [[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n\
    [[bc]]\nkind = \"convection\"\nsurfaces = [\"surface_1\", \"surface_4\"]\nvalue = 10.0\nambient = 300.0\n\
    [contact]\nfile = \"contact.i\"\n\
    [solve]\nkind = \"steady\"\ntolerance = 1e-13\n";

/// Run the case `name` (mesh, deck) with [`PROBLEM`].
fn run_case(name: &str, mesh: &Mesh, deck: &str) -> RunResult {
    crate::species::run_case(&format!("voltage-{name}"), mesh, deck, PROBLEM)
}

/// The closed form: the current density j, and V(z, side), T(z, side) with side 0 in
/// block 1 and 1 in block 2, for the jump `dv` = V_A − V_B.
fn closed_form(dv: f64) -> (f64, impl Fn(f64, usize) -> (f64, f64)) {
    let l2 = L - L1;
    let j = (V0 - dv) / (L1 / SIGMA[0] + l2 / SIGMA[1]);
    // The heat q_i = j²/σ_i per unit volume; T_i = a_i + b_i s − q_i s²/(2 k_i) with s
    // the distance from each bar's outer end (s = z in bar 1, s = L − z in bar 2).
    let q = [j * j / SIGMA[0], j * j / SIGMA[1]];
    // Ends: k_i T_i'(0) = h_c (T_i(0) − T∞) (heat leaving by convection) gives
    // a_i = T∞ + k_i b_i / h_c. At the interface, T_1(L1) = T_2(l2) and
    // k_1 T_1'(L1) = −k_2 T_2'(l2) (the flux is continuous; s runs opposite ways).
    // Unknowns b1, b2:
    //   (T∞ + k1 b1/h + b1 L1 − q1 L1²/(2k1)) − (T∞ + k2 b2/h + b2 l2 − q2 l2²/(2k2)) = 0
    //   k1 b1 − q1 L1 + k2 b2 − q2 l2 = 0
    let (h, [k1, k2]) = (H_C, K);
    let (a11, a12) = (k1 / h + L1, -(k2 / h + l2));
    let r1 = q[0] * L1 * L1 / (2.0 * k1) - q[1] * l2 * l2 / (2.0 * k2);
    let (a21, a22, r2) = (k1, k2, q[0] * L1 + q[1] * l2);
    let det = a11 * a22 - a12 * a21;
    let b1 = (r1 * a22 - a12 * r2) / det;
    let b2 = (a11 * r2 - r1 * a21) / det;
    let exact = move |z: f64, side: usize| {
        let (s, k, b, q, v) = match side {
            0 => (z, k1, b1, q[0], V0 - j * z / SIGMA[0]),
            _ => (L - z, k2, b2, q[1], j * (L - z) / SIGMA[1]),
        };
        let t = T_INF + k * b / h + b * s - q * s * s / (2.0 * k);
        (v, t)
    };
    (j, exact)
}

/// The largest nodal errors of V (relative to V0) and T (relative to the temperature
/// rise) of a run against `exact`, and the nodal V and T.
fn nodal_errors(
    r: &RunResult,
    exact: impl Fn(f64, usize) -> (f64, f64),
) -> ((f64, f64), Vec<f64>, Vec<f64>) {
    let dofs = &r.solution.dofs;
    let v = dofs.nodal_values(dofs.field("voltage").unwrap(), &r.solution.u);
    let t = dofs.nodal_values(dofs.field("temperature").unwrap(), &r.solution.u);
    let mesh = &r.mesh;
    let rise = (t.iter().copied().fold(f64::MIN, f64::max) - T_INF).max(1e-300);
    let (mut ev, mut et) = (0.0f64, 0.0f64);
    for (b, block) in mesh.blocks.iter().enumerate() {
        for k in 0..block.len() {
            let e = seam::mesh::ElemId(block.first_elem.0 + k as u32);
            for n in mesh.elem_nodes(e) {
                let (ve, te) = exact(mesh.coords[n.index()][2], b);
                ev = ev.max((v[n.index()] - ve).abs() / V0);
                et = et.max((t[n.index()] - te).abs() / rise);
            }
        }
    }
    ((ev, et), v, t)
}

/// The mean of nodal `f` over the nodes at z = `z`.
fn mean_at(mesh: &Mesh, f: &[f64], z: f64) -> f64 {
    let at: Vec<f64> = (mesh.coords.iter().zip(f))
        .filter(|(x, _)| (x[2] - z).abs() < 1e-12)
        .map(|(_, v)| *v)
        .collect();
    at.iter().sum::<f64>() / at.len() as f64
}

/// The electrical power fed at z = 0 by the current density `j` (over the unit
/// section), less a jump `dv`'s share, and the heat leaving by convection at the two
/// ends, from the nodal voltages and temperatures `(v, t)`.
fn power_in_and_out(r: &RunResult, (v, t): (&[f64], &[f64]), j: f64, dv: f64) -> (f64, f64) {
    let power = j * (mean_at(&r.mesh, v, 0.0) - mean_at(&r.mesh, v, L)) - j * dv;
    let out = H_C * (mean_at(&r.mesh, t, 0.0) - T_INF) + H_C * (mean_at(&r.mesh, t, L) - T_INF);
    (power, out)
}

#[test]
fn every_voltage_tie_reproduces_the_series_bars_at_the_nodes() {
    let mortar = "  enforcement for voltage = tied\n  side b variable voltage to voltage";
    let dual =
        "  enforcement for voltage = tied multipliers = dual\n  side b variable voltage to voltage";
    let cases = [
        (
            "nitsche",
            "  enforcement for voltage = tied_voltage".to_string(),
        ),
        (
            "interior-penalty",
            "  enforcement for voltage = tied_ip_voltage".to_string(),
        ),
        ("mortar", mortar.to_string()),
        ("dual", dual.to_string()),
        (
            "dash",
            "  enforcement for voltage = dash\n  dash penalty factor = 1e8".to_string(),
        ),
        (
            "offset",
            "  enforcement for voltage = tied_voltage\n  offset voltage = 0.2".to_string(),
        ),
    ];
    let mesh = bars([3, 4], [4, 5]);
    for (name, lines) in cases {
        let dv = if name == "offset" { 0.2 } else { 0.0 };
        let (j, exact) = closed_form(dv);
        let r = run_case(name, &mesh, &deck(&lines));
        let ((ev, et), v, t) = nodal_errors(&r, exact);
        eprintln!("{name}: V error {ev:.1e}, T error {et:.1e}");
        // Dash is a penalty: it holds the tie to its penalty's accuracy, not exactly.
        let (tol_v, tol_t) = if name == "dash" {
            (1e-5, 1e-5)
        } else {
            (1e-12, 1e-11)
        };
        assert!(ev < tol_v, "{name}: V error {ev:e}");
        assert!(et < tol_t, "{name}: T error {et:e}");
        // The current through the tie (A over the unit section) in the summary.
        let c = &r.summary.electrical_contacts;
        assert_eq!(
            c.len(),
            1,
            "{name}: one electrical interface in the summary"
        );
        let tol_i = if name == "dash" { 1e-7 } else { 1e-10 };
        assert!(
            (c[0].current - j).abs() <= tol_i * j,
            "{name}: current {} A against {j} A",
            c[0].current
        );
        assert_eq!(
            c[0].joule_heat, 0.0,
            "{name}: a tie releases no contact heat"
        );
        // The electrical power fed at z = 0 (j V0 over the unit section) leaves as heat
        // by convection at the two ends, less the jump's share for an offset.
        let (power, out) = power_in_and_out(&r, (&v, &t), j, dv);
        let tol_p = if name == "dash" { 1e-7 } else { 1e-10 };
        assert!(
            (power - out).abs() <= tol_p * power,
            "{name}: power {power} W against {out} W leaving"
        );
    }
}

#[test]
fn a_voltage_tie_refuses_another_field_and_a_side_without_a_voltage() {
    let mesh = bars([2, 3], [2, 3]);
    let scratch = crate::scratch("voltage-tie-refusals");
    let dir = scratch.path();
    crate::twod::write_mesh(&dir.join("bars.exo"), &mesh);
    let check = |deck: &str, problem: &str| -> Vec<String> {
        std::fs::write(dir.join("contact.i"), deck).unwrap();
        std::fs::write(dir.join("problem.toml"), problem).unwrap();
        match seam::run::check(&dir.join("problem.toml")) {
            Err(RunError::Input(d, _)) => d.errors().map(|d| d.code.to_string()).collect(),
            Ok(_) => Vec::new(),
            Err(e) => panic!("{e:?}"),
        }
    };
    let tied = deck("  enforcement for voltage = tied_voltage");
    assert!(check(&tied, PROBLEM).is_empty(), "the tie itself checks");
    // A voltage tie mapping the temperature.
    let other = deck("  enforcement for voltage = tied\n  side b variable temperature to voltage");
    assert_eq!(check(&other, PROBLEM), ["E0431"]);
    // Block 2 without an electrical conductivity: its side of the tie carries no voltage.
    let bare = PROBLEM.replacen(
        "conductivity = 2.0\nelectrical_conductivity = 1e3\n",
        "conductivity = 2.0\n",
        1,
    );
    let bare = bare.replace(
        "[[bc]]\nkind = \"voltage\"\nsurfaces = [\"surface_4\"]\nvalue = 0.0\n",
        "",
    );
    assert_eq!(check(&tied, &bare), ["E0431"]);
}

/// The current density through the contact of the bars when h_e = 500 (1 + 2 V_s), with
/// V_s the voltage `seen` gives of (V_A, V_B): the root of h_e(V_s) (V_A − V_B) = j with
/// V_A = V0 − j L1/σ1 and V_B = j L2/σ2, by bisection.
fn contact_current(seen: impl Fn(f64, f64) -> f64) -> f64 {
    let l2 = L - L1;
    let excess = |j: f64| {
        let (va, vb) = (V0 - j * L1 / SIGMA[0], j * l2 / SIGMA[1]);
        500.0 * (1.0 + 2.0 * seen(va, vb)) * (va - vb) - j
    };
    let (mut lo, mut hi) = (0.0, V0 / (L1 / SIGMA[0] + l2 / SIGMA[1]));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if excess(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

/// The voltage a contact conductance sees of (V_A, V_B).
type Seen = dyn Fn(f64, f64) -> f64;

#[test]
fn contact_gap_voltage_chooses_the_voltage_a_contact_conductance_sees() {
    let mesh = bars([3, 4], [4, 5]);
    let side_a = |a: f64, _: f64| a;
    // The same law from a C plugin, which reads V_A from the point's fields.
    let plugin = crate::plugin::cc_shared("plugins/tests/c/volt_contact.c", &[], "volt_contact");
    let cases: [(&str, &str, &Seen); 6] = [
        ("both", "", &side_a),
        ("side_a", "contact gap voltage = side_a", &side_a),
        ("side_b", "contact gap voltage = side_b", &|_, b| b),
        ("mean", "contact gap voltage = mean", &|a, b| 0.5 * (a + b)),
        (
            "plugin",
            "contact gap voltage = mean\n  real data 500 2",
            &|a, b| 0.5 * (a + b),
        ),
        (
            "constant",
            "contact gap voltage = constant value = 0.1",
            &|_, _| 0.1,
        ),
    ];
    let mut currents = Vec::new();
    for (name, line, seen) in cases {
        let j = contact_current(seen);
        let block = match name {
            "plugin" => format!(
                "  enforcement for voltage = plugin library = \"{}\"\n  {line}",
                plugin.display()
            ),
            _ => format!(
                "  enforcement for voltage = gap_conductance\n  gap conductance coefficient = lua \"500 * (1 + 2 * volt_a)\"\n  {line}"
            ),
        };
        let r = run_case(&format!("seen-{name}"), &mesh, &deck(&block));
        let c = &r.summary.electrical_contacts[0];
        assert!(
            (c.current - j).abs() <= 1e-10 * j,
            "{name}: current {} A against {j} A",
            c.current
        );
        // V is linear in each bar: every node on the closed form with the jump j/h_e.
        let exact = |z: f64, side: usize| match side {
            0 => (V0 - j * z / SIGMA[0], 0.0),
            _ => (j * (L - z) / SIGMA[1], 0.0),
        };
        let dofs = &r.solution.dofs;
        let v = dofs.nodal_values(dofs.field("voltage").unwrap(), &r.solution.u);
        let t = dofs.nodal_values(dofs.field("temperature").unwrap(), &r.solution.u);
        let mut ev = 0.0f64;
        for (b, block) in r.mesh.blocks.iter().enumerate() {
            for k in 0..block.len() {
                let e = seam::mesh::ElemId(block.first_elem.0 + k as u32);
                for n in r.mesh.elem_nodes(e) {
                    let (ve, _) = exact(r.mesh.coords[n.index()][2], b);
                    ev = ev.max((v[n.index()] - ve).abs() / V0);
                }
            }
        }
        assert!(ev < 1e-10, "{name}: V error {ev:e}");
        // The power fed leaves as heat: the bulk's and the contact's Joule heat.
        let power = j * (mean_at(&r.mesh, &v, 0.0) - mean_at(&r.mesh, &v, L));
        let out =
            H_C * (mean_at(&r.mesh, &t, 0.0) - T_INF) + H_C * (mean_at(&r.mesh, &t, L) - T_INF);
        assert!(
            (power - out).abs() <= 1e-10 * power,
            "{name}: power {power} W against {out} W leaving"
        );
        assert!(c.joule_heat > 0.0, "{name}: the contact heats");
        eprintln!(
            "contact gap voltage {name}: current {:.12} A (closed form {j:.12}), V error {ev:.1e}, Newton {}",
            c.current, r.solution.newton_iterations
        );
        currents.push(j);
    }
    // The choices differ (so each check above tells them apart), and `side_a` is what an
    // expression of volt_a sees without the line.
    assert!((currents[1] - currents[0]).abs() < 1e-12 * currents[0]);
    assert!((currents[2] - currents[1]).abs() > 1e-3 * currents[1]);
    assert!((currents[3] - currents[1]).abs() > 1e-3 * currents[1]);
    assert!((currents[5] - currents[1]).abs() > 1e-3 * currents[1]);
    assert!((currents[4] - currents[3]).abs() < 1e-12 * currents[3]);
}

#[test]
fn only_an_electrical_contact_sees_voltages() {
    let mesh = bars([2, 3], [2, 3]);
    let scratch = crate::scratch("voltage-seen-refusals");
    let dir = scratch.path();
    crate::twod::write_mesh(&dir.join("bars.exo"), &mesh);
    let check = |deck: &str| -> Vec<String> {
        std::fs::write(dir.join("contact.i"), deck).unwrap();
        std::fs::write(dir.join("problem.toml"), PROBLEM).unwrap();
        match seam::run::check(&dir.join("problem.toml")) {
            Err(RunError::Input(d, _)) => d.errors().map(|d| d.code.to_string()).collect(),
            Ok(_) => Vec::new(),
            Err(e) => panic!("{e:?}"),
        }
    };
    let energy = |lines: &str| {
        format!(
            "begin contact definition bars\n contact surface a contains surface_2\n contact surface b contains surface_3\n\
             begin interaction\n  side a a\n  side b b\n end\n\
             begin enforcement thermal\n  enforcement for energy = gap_conductance\n{lines}\n end\n\
             begin enforcement electrical\n  enforcement for voltage = tied_voltage\n end\nend\n"
        )
    };
    let plain = energy("  gap conductance coefficient = constant h = 100");
    assert!(check(&plain).is_empty(), "the deck itself checks");
    // A thermal conductance naming the voltage.
    assert_eq!(
        check(&energy(
            "  gap conductance coefficient = lua \"100 + volt_a\""
        )),
        ["E0431"]
    );
    // `Contact Gap Voltage` in the Energy block, and in a voltage tie's.
    assert_eq!(
        check(&energy(
            "  gap conductance coefficient = constant h = 100\n  contact gap voltage = mean"
        )),
        ["E0431"]
    );
    assert_eq!(
        check(&deck(
            "  enforcement for voltage = tied_voltage\n  contact gap voltage = side_a"
        )),
        ["E0431"]
    );
}

/// `problem` with σ(T) = σ0 / (1 + 0.001 (T − 300)) in both bars.
fn sigma_of_t(problem: &str) -> String {
    problem
        .replace(
            "electrical_conductivity = 2e3\n",
            "electrical_conductivity = \"2e3 / (1 + 0.001 * (T - 300))\"\n",
        )
        .replace(
            "electrical_conductivity = 1e3\n",
            "electrical_conductivity = \"1e3 / (1 + 0.001 * (T - 300))\"\n",
        )
}

/// σ(T) = σ0 / (1 + 0.001 (T − 300)) across a voltage tie, 750 A/m² fed at z = 0: the
/// Nitsche forms weigh the jump with σ at each point's temperature, so the Nitsche tie
/// approaches the mortar tie's answer (whose multiplier needs no weights) at about second
/// order; with σ at a probe temperature it is first order and 26–40× farther.
#[test]
fn a_nitsche_voltage_tie_follows_sigma_of_t() {
    let problem = sigma_of_t(PROBLEM).replace(
        "kind = \"voltage\"\nsurfaces = [\"surface_1\"]\nvalue = 0.9",
        "kind = \"current\"\nsurfaces = [\"surface_1\"]\nvalue = 750.0",
    );
    let mortar = "  enforcement for voltage = tied\n  side b variable voltage to voltage";
    let nitsche = "  enforcement for voltage = tied_voltage";
    let mut gaps = Vec::new();
    for n in [1, 2] {
        let mesh = bars([3 * n, 4 * n], [4 * n, 5 * n]);
        let run = |name: &str, lines: &str| {
            crate::species::run_case(
                &format!("sigma-t-{name}-{n}"),
                &mesh,
                &deck(lines),
                &problem,
            )
        };
        let (a, b) = (run("mortar", mortar), run("nitsche", nitsche));
        assert!(a.solution.converged && b.solution.converged);
        let volt = |r: &RunResult| {
            let dofs = &r.solution.dofs;
            dofs.nodal_values(dofs.field("voltage").unwrap(), &r.solution.u)
        };
        let (va, vb) = (volt(&a), volt(&b));
        let gap = va
            .iter()
            .zip(&vb)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
            / V0;
        let (ia, ib) = (
            a.summary.electrical_contacts[0].current,
            b.summary.electrical_contacts[0].current,
        );
        eprintln!(
            "σ(T) voltage tie, {n}: Nitsche against mortar {gap:.2e} V0, currents {ia:.12} / {ib:.12} A"
        );
        assert!((ia - ib).abs() <= 1e-6 * ia, "currents {ia} and {ib}");
        gaps.push(gap);
    }
    // Measured: 1.1e-5 and 3.7e-6 V0; with σ at a probe temperature 3.0e-4 and 1.5e-4
    // (first order).
    assert!(gaps[0] <= 5e-5, "{gaps:?}");
    assert!(gaps[1] <= gaps[0] / 2.8, "{gaps:?}");
}

/// σ(T) with the voltage held at both ends (0.9 V and 0): a fresh voltage is 0 inside,
/// and Newton's first step from it used to overshoot the temperatures by about 1000 K,
/// turn σ negative and diverge. The first iteration now solves for the voltage alone;
/// Newton then converges (quadratically with the mortar tie, whose multiplier carries no
/// σ), and the electrical power fed equals the heat leaving by convection.
#[test]
fn sigma_of_t_with_the_voltage_held_at_both_ends_converges() {
    let problem = sigma_of_t(PROBLEM);
    let mesh = bars([3, 4], [4, 5]);
    let cases = [
        (
            "mortar",
            "  enforcement for voltage = tied\n  side b variable voltage to voltage",
        ),
        ("nitsche", "  enforcement for voltage = tied_voltage"),
        (
            "contact",
            "  enforcement for voltage = gap_conductance\n  gap conductance coefficient = constant h = 1e6",
        ),
    ];
    for (name, lines) in cases {
        let r = crate::species::run_case(
            &format!("sigma-t-held-{name}"),
            &mesh,
            &deck(lines),
            &problem,
        );
        let history = &r.solution.residual_history;
        eprintln!("{name}: Newton residuals {history:?}");
        assert!(r.solution.converged, "{name}: {history:?}");
        let dofs = &r.solution.dofs;
        let v = dofs.nodal_values(dofs.field("voltage").unwrap(), &r.solution.u);
        let t = dofs.nodal_values(dofs.field("temperature").unwrap(), &r.solution.u);
        // The power the current through the interface is fed with (the contact's
        // Joule heat included, released into its sides) leaves by convection.
        let c = &r.summary.electrical_contacts[0];
        let (power, out) = power_in_and_out(&r, (&v, &t), c.current, 0.0);
        // A Nitsche tie leaves a jump of the discretisation's size where V is not
        // linear (σ varies along the bar), and the power its current carries across the
        // jump is not released as heat: measured 2.4e-5 of the power.
        let tol = if name == "nitsche" { 1e-4 } else { 1e-10 };
        assert!(
            (power - out).abs() <= tol * power,
            "{name}: power {power} W against {out} W leaving"
        );
        // The temperatures stay where σ is positive and the rise is the few tens of
        // kelvin the constant-σ closed form gives.
        let (lo, hi) = t
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(lo > T_INF && hi < T_INF + 100.0, "{name}: T in {lo}..{hi}");
    }
}
