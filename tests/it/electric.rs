//! Thermal–electrical coupling: two bars in series through a non-matching contact with
//! electrical and thermal contact conductances, Joule heat in the bulk and at the
//! contact, against the 1-D closed form; the electrical power against the heat leaving;
//! the coupled Jacobians against central differences; Newton's rate with σ(T) and a
//! temperature-dependent contact conductance.

use std::collections::HashSet;

use seam::assembly::DofMap;
use seam::enforce::interface::{DEFAULT_BETA, Form, HInput, HValue, InterfaceForm};
use seam::fem::Basis;
use seam::heat::electric::{ElectricContact, VOLTAGE, joule_residual_jacobian};
use seam::heat::interfaces::{ContactTerm, Terms};
use seam::heat::law::Law;
use seam::heat::transient::{
    BlockLaws, Electric, Loads, Start, StepReport, TimeMode, TransientProblem, solve,
};
use seam::heat::{FaceBc, TEMPERATURE};
use seam::mesh::Topology;
use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{Mesh, NodeId, Side};
use seam::search::SearchSettings;
use seam::search::pairing::{ContactPoint, Integration, Searcher, SurfaceGeometry};

/// The bars: [0,1]² × [0, L1] (block 1, n1 cells across, m1 along) and [0,1]² × [L1, L]
/// (block 2), meshed apart. Side sets: 1 the end z = 0, 2 block 1's contact face, 3
/// block 2's contact face, 4 the end z = L.
const L1: f64 = 0.6;
const L: f64 = 1.5;

fn bars(n1: usize, m1: usize, n2: usize, m2: usize) -> Mesh {
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, L1], [n1, n1, m1], 1)
                .with_side_sets([0, 0, 0, 0, 1, 2]),
            BoxSpec::hex([0.0, 0.0, L1], [1.0, 1.0, L], [n2, n2, m2], 2)
                .with_side_sets([0, 0, 0, 0, 3, 4]),
        ],
        false,
    )
}

fn set(mesh: &Mesh, id: i64) -> usize {
    mesh.side_sets.iter().position(|s| s.id == id).unwrap()
}

fn sides(mesh: &Mesh, id: i64) -> Vec<Side> {
    mesh.side_sets[set(mesh, id)].sides.clone()
}

fn nodes_of(mesh: &Mesh, id: i64) -> Vec<NodeId> {
    let mut n: Vec<NodeId> = sides(mesh, id)
        .into_iter()
        .flat_map(|s| mesh.side_nodes(s).collect::<Vec<_>>())
        .collect();
    n.sort();
    n.dedup();
    n
}

/// The data of the series problem.
#[derive(Clone, Copy)]
struct Bars {
    k: [f64; 2],
    sigma: [f64; 2],
    /// Electrical and thermal contact conductances.
    h_e: f64,
    h_t: f64,
    /// Convection at both ends.
    h_c: f64,
    t_inf: f64,
    /// Current density into the bar at z = 0.
    j0: f64,
    /// Share of the contact's Joule heat given to side A (block 1).
    fraction_a: f64,
}

impl Bars {
    /// The closed form: V(z) and T(z) on each bar (`side` 0 or 1).
    fn exact(&self, z: f64, side: usize) -> (f64, f64) {
        let [k1, k2] = self.k;
        let [s1, s2] = self.sigma;
        let j0 = self.j0;
        let (q1, q2) = (j0 * j0 / s1, j0 * j0 / s2);
        let pc = j0 * j0 / self.h_e;
        let v0 = j0 * (L1 / s1 + 1.0 / self.h_e + (L - L1) / s2);
        // T1 = b1 + a1 z − q1 z²/2k1, T2 = b2 + a2 z − q2 z²/2k2; unknowns [a1 b1 a2 b2].
        let (hc, ti, ht, fa) = (self.h_c, self.t_inf, self.h_t, self.fraction_a);
        // Rows: coefficients of a1, b1, a2, b2 = rhs.
        let m = [
            // k1 T1'(0) = hc (T1(0) − T∞)
            [k1, -hc, 0.0, 0.0, -hc * ti],
            // −k2 T2'(L) = hc (T2(L) − T∞)
            [
                0.0,
                0.0,
                -k2 - hc * L,
                -hc,
                -q2 * L + (-hc) * (q2 * L * L / (2.0 * k2)) - hc * ti,
            ],
            // −k1 T1'(L1) + fa Pc = ht (T1(L1) − T2(L1))
            [
                -k1 - ht * L1,
                -ht,
                ht * L1,
                ht,
                -q1 * L1 - fa * pc - ht * q1 * L1 * L1 / (2.0 * k1)
                    + ht * q2 * L1 * L1 / (2.0 * k2),
            ],
            // ht (T1(L1) − T2(L1)) + (1 − fa) Pc = −k2 T2'(L1)
            [
                ht * L1,
                ht,
                -ht * L1 + k2,
                -ht,
                -(1.0 - fa) * pc + ht * q1 * L1 * L1 / (2.0 * k1) - ht * q2 * L1 * L1 / (2.0 * k2)
                    + q2 * L1,
            ],
        ];
        let [a1, b1, a2, b2] = solve4(m);
        if side == 0 {
            (v0 - j0 * z / s1, b1 + a1 * z - q1 * z * z / (2.0 * k1))
        } else {
            (j0 * (L - z) / s2, b2 + a2 * z - q2 * z * z / (2.0 * k2))
        }
    }
}

/// Gaussian elimination with partial pivoting on an augmented 4 × 5 system.
fn solve4(mut m: [[f64; 5]; 4]) -> [f64; 4] {
    for c in 0..4 {
        let p = (c..4)
            .max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            .unwrap();
        m.swap(c, p);
        for r in c + 1..4 {
            let f = m[r][c] / m[c][c];
            let pivot = m[c];
            m[r].iter_mut()
                .zip(pivot)
                .skip(c)
                .for_each(|(x, p)| *x -= f * p);
        }
    }
    let mut x = [0.0; 4];
    for r in (0..4).rev() {
        let s: f64 = (r + 1..4).map(|k| m[r][k] * x[k]).sum();
        x[r] = (m[r][4] - s) / m[r][r];
    }
    x
}

struct Pairing {
    a: SurfaceGeometry,
    b: SurfaceGeometry,
    points: Vec<ContactPoint>,
}

fn pair(mesh: &Mesh) -> Pairing {
    let a = SurfaceGeometry::from_side_set(mesh, set(mesh, 2)).unwrap();
    let b = SurfaceGeometry::from_side_set(mesh, set(mesh, 3)).unwrap();
    let settings = SearchSettings::defaults(3);
    let r = Searcher::new(&b, &settings).search(
        &a,
        &b,
        &settings,
        Integration::Segments { order: 5 },
        None,
    );
    assert_eq!(r.stats.matched, r.stats.points);
    Pairing {
        a,
        b,
        points: std::sync::Arc::unwrap_or_clone(r.points),
    }
}

/// A steady coupled solve of the bars with the given laws; the last report, the dofs
/// and the state.
fn run(
    mesh: &Mesh,
    bars: &Bars,
    sigma: [Law; 2],
    h_e: &(dyn Fn(&HInput) -> Result<HValue, String> + Sync),
) -> (StepReport, DofMap, Vec<f64>) {
    let h_e = |i: &HInput, _t: f64| h_e(i);
    let p = pair(mesh);
    let laws: Vec<BlockLaws> = bars
        .k
        .iter()
        .map(|&k| BlockLaws {
            conductivity: Law::Constant(k),
            capacity: Law::Constant(1.0),
        })
        .collect();
    let sigma: Vec<Option<Law>> = sigma.into_iter().map(Some).collect();
    let contact =
        ElectricContact::new(&p.a, &p.b, &p.points, 0.0, bars.fraction_a).expect("contact");
    // The thermal contact over the dofs the solver numbers: temperature, then voltage.
    let all = [0usize, 1];
    let dofs = DofMap::new(mesh, &[(TEMPERATURE, &all), (VOLTAGE, &all)]).unwrap();
    let field = dofs.field(TEMPERATURE).unwrap();
    let h_t = bars.h_t;
    let ht = move |_: &HInput| {
        Ok(HValue {
            h: h_t,
            ..HValue::default()
        })
    };
    let terms = [ContactTerm {
        side_a: &p.a,
        side_b: &p.b,
        points: &p.points,
        form: InterfaceForm {
            form: Form::Conductance,
            h: &ht,
            offset: 0.0,
            beta: DEFAULT_BETA,
            conductivity: &bars.k,
            conductivity_of_t: None,
            temperature_field: None,
        },
        linear: true,
    }];
    let interfaces = Terms::new(
        mesh,
        &dofs,
        field.into(),
        (&terms, &[]),
        HashSet::new(),
        &bars.k,
    )
    .unwrap();
    let (left, right) = (sides(mesh, 1), sides(mesh, 4));
    let ground = nodes_of(mesh, 4);
    let b = *bars;
    let loads = move |_t: f64| {
        let faces = left
            .iter()
            .chain(&right)
            .map(|&side| FaceBc::Convection {
                side,
                h: b.h_c,
                t_inf: b.t_inf,
            })
            .collect();
        Ok(Loads {
            dirichlet: Vec::new(),
            faces,
            voltage: ground.iter().map(|&n| (n, 0.0)).collect(),
            currents: left.iter().map(|&s| (s, b.j0)).collect(),
            ..Loads::default()
        })
    };
    let problem = TransientProblem {
        mesh,
        fields: Vec::new(),
        laws: &laws,
        source: None,
        block_source: None,
        loads: &loads,
        interfaces: Some(&interfaces),
        tolerance: 1e-13,
        max_iterations: 25,
        reproducible: true,
        amg_threshold: None,
        electric: Some(Electric {
            conductivity: &sigma,
            contacts: vec![(contact, &h_e)],
        }),
        death: None,
        species: None,
    };
    let initial = |_| bars.t_inf;
    let mut last = None;
    let outcome = solve(
        &problem,
        TimeMode::Steady { time: 0.0 },
        Start::Fresh {
            time: 0.0,
            dt: 1.0,
            initial: &initial,
        },
        &mut |r, _, _| {
            last = Some(r.clone());
            Ok(())
        },
    )
    .expect("the coupled solve");
    (last.unwrap(), outcome.dofs, outcome.state.u)
}

fn constant(h: f64) -> impl Fn(&HInput) -> Result<HValue, String> + Sync {
    move |_: &HInput| {
        Ok(HValue {
            h,
            ..HValue::default()
        })
    }
}

const BARS: Bars = Bars {
    k: [5.0, 2.0],
    sigma: [2e3, 1e3],
    h_e: 2e3,
    h_t: 100.0,
    h_c: 10.0,
    t_inf: 300.0,
    j0: 1e3,
    fraction_a: 0.5,
};

#[test]
fn series_bars_reproduce_the_closed_form_at_the_nodes() {
    for (fraction_a, (n1, m1, n2, m2)) in [(0.5, (3, 4, 2, 5)), (0.3, (2, 3, 3, 4))] {
        let bars = Bars { fraction_a, ..BARS };
        let mesh = bars_mesh(n1, m1, n2, m2);
        let he = constant(bars.h_e);
        let (report, dofs, u) = run(&mesh, &bars, [2e3, 1e3].map(Law::Constant), &he);
        let ((et, ev), tn, vn) = nodal_errors(&mesh, &bars, &dofs, &u, 2);
        // Scales: ΔT ~ 100 K over 300 K, V ~ 2 V.
        assert!(et < 1e-9, "T error {et:e} (share {fraction_a})");
        assert!(ev < 1e-12, "V error {ev:e} (share {fraction_a})");
        // The contact: the current through it and its Joule heat.
        let pw = report.electric[0];
        assert!((pw.current - bars.j0).abs() < 1e-9 * bars.j0, "{pw:?}");
        let pc = bars.j0 * bars.j0 / bars.h_e;
        assert!((pw.joule - pc).abs() < 1e-9 * pc, "{pw:?}");
        // The electrical power in = the heat leaving by convection at the two ends.
        let mean = |f: &[f64], id: i64| {
            let n = nodes_of(&mesh, id);
            n.iter().map(|n| f[n.index()]).sum::<f64>() / n.len() as f64
        };
        let power = bars.j0 * mean(&vn, 1);
        let out = bars.h_c * (mean(&tn, 1) - bars.t_inf) + bars.h_c * (mean(&tn, 4) - bars.t_inf);
        assert!(
            (power - out).abs() <= 1e-10 * power,
            "power {power} W against {out} W leaving"
        );
    }
}

/// The largest nodal errors of T and V of a solve against the closed form along the
/// coordinate `axis` (z in 3-D, y in 2-D), and the nodal T and V.
fn nodal_errors(
    mesh: &Mesh,
    bars: &Bars,
    dofs: &DofMap,
    u: &[f64],
    axis: usize,
) -> ((f64, f64), Vec<f64>, Vec<f64>) {
    let (t, v) = (
        dofs.field(TEMPERATURE).unwrap(),
        dofs.field(VOLTAGE).unwrap(),
    );
    let (tn, vn) = (dofs.nodal_values(t, u), dofs.nodal_values(v, u));
    let mut block_of = vec![0usize; mesh.num_nodes()];
    for n in &mesh.blocks[1].connectivity {
        block_of[n.index()] = 1;
    }
    let (mut et, mut ev) = (0.0f64, 0.0f64);
    for (i, x) in mesh.coords.iter().enumerate() {
        let (ve, te) = bars.exact(x[axis], block_of[i]);
        et = et.max((tn[i] - te).abs());
        ev = ev.max((vn[i] - ve).abs());
    }
    ((et, ev), tn, vn)
}

fn bars_mesh(n1: usize, m1: usize, n2: usize, m2: usize) -> Mesh {
    bars(n1, m1, n2, m2)
}

/// A temperature-dependent law as a closure `(value, d/dT)`.
fn linear_in_t(v0: f64, slope: f64) -> impl Fn(f64, [f64; 3]) -> (f64, f64) {
    move |t, _| (v0 * (1.0 + slope * (t - 300.0)), v0 * slope)
}

/// Largest difference between an analytic Jacobian column and its central difference,
/// relative to the largest Jacobian entry.
fn fd_mismatch(
    n: usize,
    x0: &[f64],
    jac: &[f64],
    residual: impl Fn(&[f64]) -> Vec<f64>,
    step: impl Fn(usize) -> f64,
) -> f64 {
    let scale = jac.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for c in 0..n {
        let h = step(c);
        let (mut xp, mut xm) = (x0.to_vec(), x0.to_vec());
        xp[c] += h;
        xm[c] -= h;
        let (rp, rm) = (residual(&xp), residual(&xm));
        for r in 0..rp.len() {
            let fd = (rp[r] - rm[r]) / (2.0 * h);
            worst = worst.max((fd - jac[r * n + c]).abs() / scale);
        }
    }
    worst
}

#[test]
fn the_coupled_element_jacobian_matches_central_differences() {
    // A distorted hex, temperatures around 400 K, voltages of a few volts.
    let mut x: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.1, 0.0],
        [1.2, 1.1, 0.1],
        [0.1, 0.9, 0.0],
        [0.0, 0.1, 0.9],
        [1.1, 0.0, 1.0],
        [1.0, 1.0, 1.2],
        [-0.1, 1.0, 1.0],
    ];
    x.iter_mut()
        .for_each(|p| p.iter_mut().for_each(|c| *c *= 0.01));
    let basis = Basis::standard(Topology::Hex8).unwrap();
    let t: Vec<f64> = (0..8)
        .map(|a| 400.0 + 13.0 * a as f64 - 2.0 * (a * a) as f64)
        .collect();
    let v: Vec<f64> = (0..8)
        .map(|a| 0.3 * a as f64 - 0.05 * (a % 3) as f64)
        .collect();
    let k = || linear_in_t(5.0, 2e-3);
    let s = || linear_in_t(2e3, -4e-3);
    let eval = |tv: &[f64]| {
        let (mut re, mut je) = (vec![0.0; 16], vec![0.0; 256]);
        joule_residual_jacobian(&basis, &x, &tv[..8], &tv[8..], (k(), s()), &mut re, &mut je)
            .unwrap();
        (re, je)
    };
    let tv: Vec<f64> = t.iter().chain(&v).copied().collect();
    let (_, je) = eval(&tv);
    let worst = fd_mismatch(
        16,
        &tv,
        &je,
        |u| eval(u).0,
        |c| if c < 8 { 1e-3 } else { 1e-5 },
    );
    assert!(worst < 1e-6, "largest relative difference {worst:e}");
}

#[test]
fn the_electrical_contact_jacobian_matches_central_differences() {
    let mesh = bars(3, 2, 2, 2);
    let p = pair(&mesh);
    let all = [0usize, 1];
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &all), (VOLTAGE, &all)]).unwrap();
    let (tf, vf) = (
        dofs.field(TEMPERATURE).unwrap(),
        dofs.field(VOLTAGE).unwrap(),
    );
    // The second case also depends on the voltages (`Contact Gap Voltage`).
    for (fraction_a, volts) in [(0.5, false), (0.8, false), (0.5, true), (0.3, true)] {
        let mut c = ElectricContact::new(&p.a, &p.b, &p.points, 0.05, fraction_a).unwrap();
        c.bind(&mesh, &dofs, tf, vf).unwrap();
        // h_e(T_A, T_B) = 2e3 (1 + 3e-3 (T_A − 300) − 1e-3 (T_B − 300)), times
        // (1 + 0.4 V_A² − 0.3 V_B) when it sees the voltages.
        let h = |i: &HInput| {
            let ht = 2e3 * (1.0 + 3e-3 * (i.temp_a - 300.0) - 1e-3 * (i.temp_b - 300.0));
            let (f, dfa, dfb) = match volts {
                true => (
                    1.0 + 0.4 * i.volt_a * i.volt_a - 0.3 * i.volt_b,
                    0.8 * i.volt_a,
                    -0.3,
                ),
                false => (1.0, 0.0, 0.0),
            };
            Ok(HValue {
                h: ht * f,
                dh_dtemp_a: 2e3 * 3e-3 * f,
                dh_dtemp_b: -2e3 * 1e-3 * f,
                dh_dvolt_a: ht * dfa,
                dh_dvolt_b: ht * dfb,
            })
        };
        let n = dofs.len();
        let u: Vec<f64> = (0..n)
            .map(|d| {
                let node = d % mesh.num_nodes();
                let xyz = mesh.coords[node];
                if d < mesh.num_nodes() {
                    350.0 + 40.0 * xyz[0] + 25.0 * xyz[1] * xyz[1] + 30.0 * xyz[2]
                } else {
                    1.0 + 0.5 * xyz[0] - 0.3 * xyz[1] + 2.0 * xyz[2]
                }
            })
            .collect();
        let residual = |u: &[f64]| {
            let mut r = vec![0.0; n];
            c.evaluate(u, &h, &mut r, |_, _| {}).unwrap();
            r
        };
        let mut jac = vec![0.0; n * n];
        let mut r = vec![0.0; n];
        c.evaluate(&u, &h, &mut r, |list, m| {
            let k = list.len();
            for i in 0..k {
                for j in 0..k {
                    jac[list[i] as usize * n + list[j] as usize] += m[i * k + j];
                }
            }
        })
        .unwrap();
        let worst = fd_mismatch(n, &u, &jac, residual, |d| {
            if d < mesh.num_nodes() { 1e-3 } else { 1e-5 }
        });
        assert!(
            worst < 1e-6,
            "largest relative difference {worst:e} (share {fraction_a}, voltages {volts})"
        );
    }
}

#[test]
fn newton_converges_quadratically_with_sigma_of_t_and_a_temperature_dependent_contact() {
    let mesh = bars(3, 4, 2, 5);
    let he = |i: &HInput| {
        let tm = 0.5 * (i.temp_a + i.temp_b);
        Ok(HValue {
            h: 2e3 * (1.0 + 2e-3 * (tm - 300.0)),
            dh_dtemp_a: 2e3 * 1e-3,
            dh_dtemp_b: 2e3 * 1e-3,
            ..HValue::default()
        })
    };
    let sigma = |s0: f64| Law::Lua {
        expr: format!("{s0} / (1 + 0.004 * (T - 300))"),
        chunk: "sigma".into(),
    };
    let (report, _, _) = run(&mesh, &BARS, [sigma(2e3), sigma(1e3)], &he);
    let r = &report.residual_history;
    // The order p from three successive residuals, while they are well above round-off.
    let floor = 1e-9 * r[0];
    let orders: Vec<f64> = r
        .windows(3)
        .filter(|w| w[2] > floor)
        .map(|w| (w[2] / w[1]).ln() / (w[1] / w[0]).ln())
        .collect();
    assert!(
        !orders.is_empty(),
        "too few iterations to see a rate: {r:?}"
    );
    let last = *orders.last().unwrap();
    assert!(last > 1.8, "Newton's order {last:.2} (residuals {r:?})");
}

/// The busbar scene with `edit` applied to its problem file and `deck_edit` to its deck:
/// the codes of `seam check`'s errors.
fn check_codes(edit: impl Fn(&str) -> String, deck_edit: impl Fn(&str) -> String) -> Vec<String> {
    check_errors(edit, deck_edit)
        .into_iter()
        .map(|(c, _)| c)
        .collect()
}

/// As [`check_codes`], each with the file name and line it points at.
fn check_errors(
    edit: impl Fn(&str) -> String,
    deck_edit: impl Fn(&str) -> String,
) -> Vec<(String, Option<(String, u32)>)> {
    let tmp = crate::examples::copy_scene_as("busbar_joint", "electric-check");
    let dir = tmp.path();
    let problem = std::fs::read_to_string(dir.join("problem.toml")).unwrap();
    std::fs::write(dir.join("problem.toml"), edit(&problem)).unwrap();
    let deck = std::fs::read_to_string(dir.join("contact.i")).unwrap();
    std::fs::write(dir.join("contact.i"), deck_edit(&deck)).unwrap();
    match seam::run::check(&dir.join("problem.toml")) {
        Err(seam::run::RunError::Input(d, _)) => d
            .errors()
            .map(|d| {
                let at = d.loc.as_ref().map(|l| {
                    let file = std::path::Path::new(&*l.file).file_name().unwrap();
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
fn electrical_input_that_cannot_be_solved_is_refused_with_its_reason() {
    let same = |s: &str| s.to_string();
    assert!(
        check_codes(same, same).is_empty(),
        "the scene itself checks"
    );
    // A voltage contact in a problem where nothing carries a voltage (and no voltage
    // conditions either).
    let no_sigma = |s: &str| {
        s.replace("electrical_conductivity = 5.8e7\n", "")
            .replace("kind = \"current\"", "kind = \"flux\"")
            .replace(
                "[[bc]]\nkind = \"voltage\"\nsurfaces = [\"b_end\"]\nvalue = 0.0\n",
                "",
            )
    };
    assert_eq!(check_codes(no_sigma, same), ["E0431"]);
    // A voltage that floats: no voltage condition.
    let floating = |s: &str| s.replace("kind = \"voltage\"", "kind = \"current\"");
    let problem = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/busbar_joint/problem.toml"),
    )
    .unwrap();
    let sigma_line = problem
        .lines()
        .position(|l| l.starts_with("electrical_conductivity"))
        .unwrap() as u32
        + 1;
    // At the line that gives the voltage, in the problem file.
    assert_eq!(
        check_errors(floating, same),
        [(
            "E0706".to_string(),
            Some(("problem.toml".to_string(), sigma_line))
        )]
    );
    // One block claiming Energy and Voltage: its coefficient cannot be both.
    let mixed = |d: &str| {
        d.replace(
            "    enforcement for energy = gap_conductance\n",
            "    enforcement for energy = gap_conductance\n    enforcement for voltage = gap_conductance\n",
        )
    };
    assert!(check_codes(same, mixed).contains(&"E0431".to_string()));
    // A tied voltage is a perfect joint: it needs no coefficient (the one given is
    // refused as a line with no meaning for a tie).
    let tied = |d: &str| {
        d.replace(
            "enforcement for voltage = gap_conductance\n    gap conductance coefficient = constant h = 8e7",
            "enforcement for voltage = tied_voltage",
        )
    };
    assert_eq!(check_codes(same, tied), Vec::<String>::new());
}

/// Above the size threshold a coupled run solves its Newton steps by GMRES with the
/// temperature and voltage blocks' AMG, and gets the factorisation's answer.
#[test]
fn large_coupled_runs_take_block_amg_gmres_and_match_the_factorisation() {
    let tmp = crate::examples::copy_scene_as("busbar_joint", "electric-gmres");
    let dir = tmp.path();
    let problem = std::fs::read_to_string(dir.join("problem.toml")).unwrap();
    let solve = |extra: &str, name: &str| {
        let text = problem.replace("tolerance = 1e-12", &format!("tolerance = 1e-12\n{extra}"));
        let path = dir.join(format!("{name}.toml"));
        std::fs::write(
            &path,
            text.replace("dir = \"out\"", &format!("dir = \"{name}\"")),
        )
        .unwrap();
        let r = seam::run::run(&path).unwrap_or_else(|e| panic!("{e:?}"));
        let dofs = &r.solution.dofs;
        let v = dofs.nodal_values(dofs.field(VOLTAGE).unwrap(), &r.solution.u);
        (
            r.summary.linear_solver.name.clone(),
            r.solution.temperature.clone(),
            v,
        )
    };
    let (direct, t0, v0) = solve("linear_solver = \"direct\"", "direct");
    let (krylov, t1, v1) = solve("auto_threshold = 1000", "gmres");
    assert_eq!(direct, "direct");
    assert_eq!(krylov, "GMRES");
    let diff = |a: &[f64], b: &[f64]| {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    };
    assert!(diff(&t1, &t0) < 1e-10, "temperature {:e}", diff(&t1, &t0));
    assert!(diff(&v1, &v0) < 1e-9, "voltage {:e}", diff(&v1, &v0));
}

/// The coupling in 2-D, plane and axisymmetric: the same two bars as a plane strip of
/// unit width, and as cylinders of radius 1 along the axis (`Mesh::set_axisymmetric`),
/// their (r, y) section in 2-D (Quad4, meshed apart: the contact edges at y = L1 do not
/// match, 3 against 4). The field is still one-dimensional and the quads' integrals
/// separate in r and y, so T (quadratic in y) and V at every node are the closed form's,
/// as with the 3-D case's hexes (triangles would couple r and y and lose the nodal
/// exactness) — which needs every term per revolution when axisymmetric: the Joule heat
/// and charge in the elements, the current fed in and the convection at the ends (face
/// loads × 2πr), the contact's current and heat (points × 2πr). The current through the
/// contact is j₀ per unit depth, j₀ π per revolution.
#[test]
fn series_bars_reproduce_the_closed_form_axisymmetric() {
    use seam::mesh::generate::RectSpec;
    for axisymmetric in [false, true] {
        let mut mesh = generate::rectangles(
            &[
                RectSpec::quad([0.0, 0.0], [1.0, L1], [3, 4], 1).with_side_sets([0, 0, 1, 2]),
                RectSpec::quad([0.0, L1], [1.0, L], [4, 5], 2).with_side_sets([0, 0, 3, 4]),
            ],
            false,
        );
        if axisymmetric {
            mesh.set_axisymmetric().unwrap();
        }
        let he = constant(BARS.h_e);
        let (report, dofs, u) = run(&mesh, &BARS, [2e3, 1e3].map(Law::Constant), &he);
        let ((et, ev), _, _) = nodal_errors(&mesh, &BARS, &dofs, &u, 1);
        // Through the unit width per unit depth (plane), the disc r < 1 (axisymmetric).
        let current = report.electric[0].current;
        let want = BARS.j0
            * if axisymmetric {
                std::f64::consts::PI
            } else {
                1.0
            };
        eprintln!(
            "2-D bars, axisymmetric {axisymmetric}: worst T error {et:.1e} K, V error {ev:.1e} V; contact current {current:.10} A (exact {want:.10})"
        );
        assert!(et < 1e-9, "T error {et:e}");
        assert!(ev < 1e-12, "V error {ev:e}");
        assert!(
            (current - want).abs() < 1e-9 * want,
            "{current} against {want}"
        );
    }
}
