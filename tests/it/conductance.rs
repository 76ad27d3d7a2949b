//! Conductance-coefficient models against independent truth: each value against its
//! formula written out here, each derivative against central finite differences of
//! the model's own value, the Lua model against the equivalent built-in, the plugin
//! adapter against the built-in table, and the deck lines (good ones evaluated, bad
//! ones as diagnostic snapshots in `tests/bad/conductance_*/`).
//!
//! Derivative check: for variable x with value x₀ the step is δ = 1e-5 · max(|x₀|, s)
//! (s = 1 K, 1 Pa or 1e-9 m), and the central difference must agree with the exact
//! derivative d to |d − fd| ≤ 1e-6 (|d| + |h|/max(|x₀|, s)). The second term is h's
//! natural derivative scale in x, so a derivative that should be 0 is compared with a
//! floor instead of 0. With δ/x = 1e-5 the truncation error of a smooth model is about
//! (δ/x)²/6 ≈ 2e-11 relative and round-off ε/(δ/x) ≈ 2e-11, far below 1e-6; a wrong
//! factor of 2, a wrong sign or a missing term shows up as O(1).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, OnceLock};

use seam::deck::parse_sierra;
use seam::deck::spec::Enforcement;
use seam::diag::SourceMap;
use seam::enforce::conductance::{
    Cmy, Conductance, ConductanceModel, Constant, GasGap, LuaConductance, MinGapOrder,
    PluginConductance, PointState, Radiation, STEFAN_BOLTZMANN, Sum, Table, TableVariable,
};
use seam::plugin::{Plugin, PluginData};
use seam::scene::conductance::from_properties;
use seam::script::Limits;

const SIGMA: f64 = 5.670374419e-8;

fn state(gap: f64, pressure: f64, temp_a: f64, temp_b: f64) -> PointState {
    PointState {
        gap,
        pressure,
        temp_a,
        temp_b,
        x: [0.1, -0.2, 0.3],
        time: 2.5,
    }
}

/// A grid of states: gaps from penetration through g_min to wide open, pressures from
/// tension to 100 MPa, temperatures from cryogenic to hot, unequal sides.
fn grid() -> Vec<PointState> {
    let mut out = Vec::new();
    for &g in &[-1e-4, 0.0, 3e-7, 2e-6, 1e-4, 3e-3, 0.5] {
        for &p in &[-1e3, 0.0, 10.0, 1e5, 1e8] {
            for &(a, b) in &[
                (20.0, 30.0),
                (300.0, 300.0),
                (290.0, 450.0),
                (1500.0, 800.0),
            ] {
                out.push(state(g, p, a, b));
            }
        }
    }
    out
}

fn rel_close(got: f64, want: f64, rtol: f64) -> bool {
    (got - want).abs() <= rtol * want.abs().max(f64::MIN_POSITIVE)
}

fn value(m: &dyn ConductanceModel, s: &PointState) -> f64 {
    m.evaluate(s).unwrap_or_else(|e| panic!("{e}")).h
}

type Field = fn(&mut PointState) -> &mut f64;

const VARIABLES: [(&str, Field, f64); 4] = [
    ("gap", |s| &mut s.gap, 1e-9),
    ("pressure", |s| &mut s.pressure, 1.0),
    ("temp_a", |s| &mut s.temp_a, 1.0),
    ("temp_b", |s| &mut s.temp_b, 1.0),
];

fn exact(c: &Conductance, var: &str) -> f64 {
    match var {
        "gap" => c.dh_dgap,
        "pressure" => c.dh_dpressure,
        "temp_a" => c.dh_dtemp_a,
        _ => c.dh_dtemp_b,
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Fd {
    Central,
    /// Forward: at a breakpoint the models use the right-hand slope.
    Forward,
}

/// Check every derivative of `m` at `s` against finite differences (see module doc).
fn check_derivatives_with(m: &dyn ConductanceModel, s: &PointState, kind: Fd, rtol: f64) {
    let c = m.evaluate(s).unwrap_or_else(|e| panic!("{e}"));
    for (var, field, floor) in VARIABLES {
        let mut p = *s;
        let x = *field(&mut p);
        let scale = x.abs().max(floor);
        let step = 1e-5 * scale;
        *field(&mut p) = x + step;
        let up = value(m, &p);
        let fd = match kind {
            Fd::Central => {
                *field(&mut p) = x - step;
                (up - value(m, &p)) / (2.0 * step)
            }
            Fd::Forward => (up - c.h) / step,
        };
        let d = exact(&c, var);
        assert!(
            (d - fd).abs() <= rtol * (d.abs() + c.h / scale),
            "{}: dh/d{var} = {d:e}, finite difference {fd:e} at ({s})",
            m.name()
        );
    }
}

fn check_derivatives(m: &dyn ConductanceModel, s: &PointState) {
    check_derivatives_with(m, s, Fd::Central, 1e-6);
}

#[test]
fn constant_is_constant_with_zero_derivatives() {
    let m = Constant::new(10.0).unwrap();
    for s in grid() {
        let c = m.evaluate(&s).unwrap();
        assert_eq!(
            c,
            Conductance {
                h: 10.0,
                ..Conductance::default()
            }
        );
    }
}

#[test]
fn stefan_boltzmann_is_codata_2018() {
    assert_eq!(STEFAN_BOLTZMANN, 5.670374419e-8);
}

/// MOOSE GapConductance with gap_geometry_type = PLATE, written out independently.
fn gas_gap_formula(
    k0: f64,
    beta: f64,
    t0: f64,
    gmin: f64,
    gmax: f64,
    order: u8,
    s: &PointState,
) -> f64 {
    let t = (s.temp_a + s.temp_b) / 2.0;
    let k = k0 * (1.0 + beta * (t - t0));
    let inv = if s.gap > gmax {
        1.0 / gmax
    } else if s.gap >= gmin {
        1.0 / s.gap
    } else if order == 0 {
        1.0 / gmin
    } else {
        1.0 / gmin - (s.gap - gmin) / (gmin * gmin)
    };
    k * inv
}

#[test]
fn gas_gap_matches_the_formula_and_its_derivatives() {
    let (k0, beta, t0) = (0.025, 1e-3, 300.0);
    // max_gap 0.1 so that the wide-open gap (0.5 m) exercises the cap.
    for (order, mo) in [(0u8, MinGapOrder::Zero), (1, MinGapOrder::One)] {
        let m = GasGap::with(k0, beta, t0, 1e-6, 0.1, mo).unwrap();
        for s in grid() {
            let want = gas_gap_formula(k0, beta, t0, 1e-6, 0.1, order, &s);
            let got = value(&m, &s);
            assert!(
                rel_close(got, want, 1e-14),
                "order {order} at ({s}): {got} vs {want}"
            );
            check_derivatives(&m, &s);
        }
        // Flat below g_min for order 0: dh/dg = 0 exactly.
        let c = m.evaluate(&state(1e-7, 0.0, 300.0, 300.0)).unwrap();
        if order == 0 {
            assert_eq!(c.dh_dgap, 0.0);
        } else {
            assert!(rel_close(c.dh_dgap, -0.025 / 1e-12, 1e-14));
        }
        // At g_min itself the right-hand branch holds: forward differences agree.
        check_derivatives_with(&m, &state(1e-6, 0.0, 310.0, 290.0), Fd::Forward, 1e-4);
    }
    // MOOSE defaults: min_gap 1e-6, max_gap 1e6, order 0.
    let m = GasGap::new(0.025).unwrap();
    let h = |g: f64| value(&m, &state(g, 0.0, 300.0, 300.0));
    assert!(rel_close(h(0.0), 0.025 / 1e-6, 1e-15));
    assert!(rel_close(h(1e7), 0.025 / 1e6, 1e-15));
}

#[test]
fn radiation_matches_the_formula_and_its_derivatives() {
    let (ea, eb) = (0.8, 0.6);
    let m = Radiation::new(ea, eb).unwrap();
    for s in grid() {
        let (a, b) = (s.temp_a, s.temp_b);
        let want = SIGMA * (a * a + b * b) * (a + b) / (1.0 / ea + 1.0 / eb - 1.0);
        assert!(rel_close(value(&m, &s), want, 1e-14), "at ({s})");
        check_derivatives(&m, &s);
    }
    // Black bodies: h = 4σT³ for equal temperatures.
    let m = Radiation::new(1.0, 1.0).unwrap();
    let h = value(&m, &state(0.0, 0.0, 1000.0, 1000.0));
    assert!(rel_close(h, 4.0 * SIGMA * 1e9, 1e-14));
}

#[test]
fn cmy_matches_the_formula_and_its_derivatives() {
    let (ka, kb, m_s, rough, hard) = (16.0, 200.0, 0.1, 1e-6, 3e9);
    let m = Cmy::new(ka, kb, m_s, rough, hard).unwrap();
    let ks = 2.0 * ka * kb / (ka + kb);
    for s in grid() {
        let want = if s.pressure > 0.0 {
            1.25 * ks * m_s / rough * (s.pressure / hard).powf(0.95)
        } else {
            0.0
        };
        let c = m.evaluate(&s).unwrap();
        assert!(rel_close(c.h, want, 1e-14) || c.h == want, "at ({s})");
        if s.pressure > 0.0 {
            check_derivatives(&m, &s);
        } else {
            // One-sided derivative 0 at and below p = 0 (C⁰ kink at p = 0).
            assert_eq!(c, Conductance::default(), "at ({s})");
        }
    }
}

const GAP_TABLE: [(f64, f64); 4] = [(0.0, 1000.0), (1e-4, 600.0), (1e-3, 100.0), (5e-3, 100.0)];

/// Linear interpolation, flat outside, written independently of the model.
fn interpolate(table: &[(f64, f64)], v: f64) -> f64 {
    if v <= table[0].0 {
        return table[0].1;
    }
    for w in table.windows(2) {
        if v <= w[1].0 {
            return w[0].1 + (w[1].1 - w[0].1) * (v - w[0].0) / (w[1].0 - w[0].0);
        }
    }
    table[table.len() - 1].1
}

#[test]
fn tables_interpolate_with_flat_ends_and_right_hand_slopes() {
    let m = Table::new(TableVariable::Gap, &GAP_TABLE).unwrap();
    let gaps = [-1.0, -1e-6, 0.0, 3e-5, 1e-4, 2e-4, 1e-3, 3e-3, 5e-3, 1.0];
    for &g in &gaps {
        let s = state(g, 0.0, 300.0, 300.0);
        assert!(
            rel_close(value(&m, &s), interpolate(&GAP_TABLE, g), 1e-14),
            "h({g})"
        );
        let at_breakpoint = GAP_TABLE.iter().any(|p| p.0 == g);
        let kind = if at_breakpoint {
            Fd::Forward
        } else {
            Fd::Central
        };
        // Linear pieces: forward and central differences are exact up to round-off.
        check_derivatives_with(&m, &s, kind, 1e-6);
    }
    // Beyond the last point h stays at its last value (no drop to 0, unlike Abaqus).
    assert_eq!(value(&m, &state(10.0, 0.0, 300.0, 300.0)), 100.0);
    // Right-hand slope at an interior breakpoint.
    let c = m.evaluate(&state(1e-4, 0.0, 300.0, 300.0)).unwrap();
    assert!(rel_close(c.dh_dgap, (100.0 - 600.0) / 9e-4, 1e-12));

    let pt = [(0.0, 1e3), (1e6, 5e3), (4e6, 6.5e3)];
    let m = Table::new(TableVariable::Pressure, &pt).unwrap();
    for &p in &[-5.0, 0.0, 2.5e5, 1e6, 3e6, 4e6, 1e7] {
        let s = state(1e-3, p, 300.0, 300.0);
        assert!(rel_close(value(&m, &s), interpolate(&pt, p), 1e-14));
        let kind = if pt.iter().any(|q| q.0 == p) {
            Fd::Forward
        } else {
            Fd::Central
        };
        check_derivatives_with(&m, &s, kind, 1e-6);
    }

    // Temperature tables use T̄ = (T_A + T_B)/2: dh/dT_A = dh/dT_B = slope/2.
    let tt = [(300.0, 10.0), (600.0, 40.0), (900.0, 40.0)];
    let m = Table::new(TableVariable::Temperature, &tt).unwrap();
    for &(a, b) in &[
        (100.0, 200.0),
        (300.0, 350.0),
        (500.0, 600.0),
        (700.0, 900.0),
        (2e3, 1e3),
    ] {
        let s = state(1e-3, 0.0, a, b);
        assert!(rel_close(
            value(&m, &s),
            interpolate(&tt, (a + b) / 2.0),
            1e-14
        ));
        check_derivatives(&m, &s);
    }
    let c = m.evaluate(&state(0.0, 0.0, 400.0, 500.0)).unwrap();
    assert!(rel_close(c.dh_dtemp_a, 0.05, 1e-12) && c.dh_dtemp_a == c.dh_dtemp_b);
}

#[test]
fn sums_add_values_and_derivatives() {
    let parts = || -> Vec<Box<dyn ConductanceModel>> {
        vec![
            Box::new(Cmy::new(16.0, 200.0, 0.1, 1e-6, 3e9).unwrap()),
            Box::new(GasGap::with(0.025, 1e-3, 300.0, 1e-6, 1e6, MinGapOrder::One).unwrap()),
            Box::new(Radiation::new(0.8, 0.6).unwrap()),
        ]
    };
    let sum = Sum::new(parts());
    for s in grid() {
        let got = sum.evaluate(&s).unwrap();
        let mut want = Conductance::default();
        for p in parts() {
            let c = p.evaluate(&s).unwrap();
            want.h += c.h;
            want.dh_dgap += c.dh_dgap;
            want.dh_dpressure += c.dh_dpressure;
            want.dh_dtemp_a += c.dh_dtemp_a;
            want.dh_dtemp_b += c.dh_dtemp_b;
        }
        assert_eq!(got, want, "at ({s})");
        if s.pressure > 0.0 {
            check_derivatives(&sum, &s);
        }
    }
}

/// Lua against the built-in: values to round-off, derivatives to FD accuracy.
fn lua_equals(lua: &dyn ConductanceModel, builtin: &dyn ConductanceModel, states: &[PointState]) {
    for s in states {
        let (l, b) = (lua.evaluate(s).unwrap(), builtin.evaluate(s).unwrap());
        assert!(
            (l.h - b.h).abs() <= 1e-14 * b.h.abs(),
            "{} vs {} at ({s}): {} vs {}",
            lua.name(),
            builtin.name(),
            l.h,
            b.h
        );
        for (var, _, floor) in VARIABLES {
            let scale = match var {
                "gap" => s.gap.abs().max(floor),
                "pressure" => s.pressure.abs().max(floor),
                "temp_a" => s.temp_a.abs().max(floor),
                _ => s.temp_b.abs().max(floor),
            };
            let (dl, db) = (exact(&l, var), exact(&b, var));
            assert!(
                (dl - db).abs() <= 1e-6 * (db.abs() + b.h / scale),
                "{}: dh/d{var} = {dl:e} vs built-in {db:e} at ({s})",
                lua.name()
            );
        }
    }
}

#[test]
fn lua_expressions_equal_the_built_in_models() {
    let smooth: Vec<PointState> = grid()
        .into_iter()
        .filter(|s| s.gap >= 1e-5 && s.gap < 0.1 && s.pressure > 0.0)
        .collect();
    let lua = LuaConductance::expression("test", "10").unwrap();
    lua_equals(&lua, &Constant::new(10.0).unwrap(), &grid());

    let lua = LuaConductance::expression(
        "test",
        "0.025*(1 + 1e-3*((temp_a + temp_b)/2 - 300))/math.max(gap, 1e-6)",
    )
    .unwrap();
    let gas = GasGap::with(0.025, 1e-3, 300.0, 1e-6, 1e6, MinGapOrder::Zero).unwrap();
    lua_equals(&lua, &gas, &smooth);

    // The T_A / T_B aliases.
    let lua = LuaConductance::expression(
        "test",
        "5.670374419e-8*(T_A^2 + T_B^2)*(T_A + T_B)/(1/0.8 + 1/0.6 - 1)",
    )
    .unwrap();
    lua_equals(&lua, &Radiation::new(0.8, 0.6).unwrap(), &smooth);

    let lua = LuaConductance::expression(
        "test",
        "pressure > 0 and 1.25*(2*16*200/216)*(0.1/1e-6)*(pressure/3e9)^0.95 or 0",
    )
    .unwrap();
    lua_equals(
        &lua,
        &Cmy::new(16.0, 200.0, 0.1, 1e-6, 3e9).unwrap(),
        &smooth,
    );
}

#[test]
fn lua_sees_position_and_time() {
    let lua = LuaConductance::expression("test", "x + 10*y + 100*z + 1000*t").unwrap();
    let s = PointState {
        x: [1.0, 2.0, 3.0],
        time: 4.0,
        ..PointState::default()
    };
    assert_eq!(lua.evaluate(&s).unwrap().h, 1.0 + 20.0 + 300.0 + 4000.0);
}

fn lua_error(expr: &str, limits: Limits) -> String {
    let lua = LuaConductance::expression_with("deck.i:7", expr, limits).unwrap();
    lua.evaluate(&state(1e-3, 5.0, 300.0, 400.0))
        .unwrap_err()
        .to_string()
}

#[test]
fn lua_faults_are_errors_that_name_the_point() {
    let limits = Limits {
        instructions: 100_000,
        ..Limits::default()
    };
    let e = lua_error("(function() while true do end end)()", limits);
    assert!(e.contains("budget of 100000 instructions"), "{e}");
    assert!(e.contains("gap = 1e-3") && e.contains("T_B = 400"), "{e}");

    let e = lua_error("error('boom')", Limits::default());
    assert!(
        e.contains("boom") && e.contains("deck.i:7") && e.contains("T_A = 300"),
        "{e}"
    );

    let e = lua_error("-1", Limits::default());
    assert!(
        e.contains("negative") && e.contains("pressure = 5e0"),
        "{e}"
    );

    let e = lua_error("0/0", Limits::default());
    assert!(e.contains("finite number"), "{e}");

    // No escape from the sandbox.
    for (expr, needle) in [
        ("os.execute('true')", "os"),
        ("io.open('/etc/passwd')", "io"),
        ("require('x')", "require"),
        ("load('return 1')()", "load"),
    ] {
        let e = lua_error(expr, Limits::default());
        assert!(e.contains(needle) && e.contains("gap ="), "{expr}: {e}");
    }
}

#[test]
fn lua_file_functions_work_and_report_syntax_errors_with_file_and_line() {
    let tmp = crate::scratch("conductance-lua");
    let dir = tmp.path();
    let good = dir.join("h.lua");
    std::fs::write(
        &good,
        "-- gas gap\nfunction h(gap, temp_a, temp_b, p)\n  return 0.025/math.max(gap, 1e-6)\nend\n",
    )
    .unwrap();
    let lua = LuaConductance::file(&good, "h").unwrap();
    lua_equals(
        &lua,
        &GasGap::new(0.025).unwrap(),
        &[
            state(1e-4, 1.0, 300.0, 310.0),
            state(2e-3, 0.0, 800.0, 310.0),
        ],
    );
    let bad = dir.join("bad.lua");
    std::fs::write(&bad, "function h(gap)\n  return gap +\nend\n").unwrap();
    let e = LuaConductance::file(&bad, "h").err().unwrap().to_string();
    assert!(e.contains("bad.lua:3:"), "{e}");
    let e = LuaConductance::file(&good, "nope")
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("`nope` is not a Lua function"), "{e}");
}

// ---- deck lines ----

/// The first enforcement of a deck whose contact definition holds `lines`.
fn enforcement(lines: &str) -> (Enforcement, SourceMap) {
    let text = format!(
        "begin contact definition\n  begin enforcement e\n    enforcement for energy = gap_conductance\n{lines}  end\nend\n"
    );
    let file: Arc<str> = Arc::from("deck.i");
    let (deck, diags) = parse_sierra(&file, &text);
    assert!(!diags.has_errors(), "{}", {
        let mut s = SourceMap::default();
        s.add(&file, &text);
        diags.render(&s)
    });
    let mut sources = SourceMap::default();
    sources.add(&file, &text);
    (deck.contact_definitions[0].enforcements[0].clone(), sources)
}

fn from_deck(lines: &str) -> Box<dyn ConductanceModel> {
    let (e, sources) = enforcement(lines);
    let (m, diags) = from_properties(&e, Path::new("."), &sources);
    assert!(diags.is_empty(), "{}", diags.render(&sources));
    m.expect("a model")
}

#[test]
fn deck_spellings_build_the_models() {
    let s = state(2e-4, 1e6, 310.0, 290.0);
    let cases: Vec<(&str, Box<dyn ConductanceModel>)> = vec![
        (
            "Gap Conductance Coefficient = Constant H = 10",
            Box::new(Constant::new(10.0).unwrap()),
        ),
        (
            "gap conductance coefficient = CONSTANT h = 10",
            Box::new(Constant::new(10.0).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Gas_Gap K = 0.025 Beta = 0.001 T0 = 300 Min_Gap = 1e-5 Max_Gap = 1 Min_Gap_Order = 1",
            Box::new(GasGap::with(0.025, 0.001, 300.0, 1e-5, 1.0, MinGapOrder::One).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Gas_Gap K = 0.025",
            Box::new(GasGap::new(0.025).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Radiation Emissivity_A = 0.8 Emissivity_B = 0.6",
            Box::new(Radiation::new(0.8, 0.6).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = CMY K_A = 16 K_B = 200 Slope = 0.1 Roughness = 1e-6 Hardness = 3e9",
            Box::new(Cmy::new(16.0, 200.0, 0.1, 1e-6, 3e9).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Cooper_Mikic_Yovanovich K_A = 16 K_B = 200 Slope = 0.1 Roughness = 1e-6 Hardness = 3e9",
            Box::new(Cmy::new(16.0, 200.0, 0.1, 1e-6, 3e9).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Table Of Gap = 0 1000 1e-3 100",
            Box::new(Table::new(TableVariable::Gap, &[(0.0, 1000.0), (1e-3, 100.0)]).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Table Of Pressure = 0 10 1e7 5000",
            Box::new(Table::new(TableVariable::Pressure, &[(0.0, 10.0), (1e7, 5000.0)]).unwrap()),
        ),
        (
            "Gap Conductance Coefficient = Table Of Temperature = 200 5 400 7",
            Box::new(
                Table::new(TableVariable::Temperature, &[(200.0, 5.0), (400.0, 7.0)]).unwrap(),
            ),
        ),
        (
            "Gap Conductance Coefficient = Lua \"100 + 0.1*(temp_a + temp_b)/2\"",
            Box::new(
                Table::new(TableVariable::Temperature, &[(0.0, 100.0), (1000.0, 200.0)]).unwrap(),
            ),
        ),
    ];
    for (line, want) in cases {
        let got = from_deck(&format!("    {line}\n"));
        let (g, w) = (got.evaluate(&s).unwrap(), want.evaluate(&s).unwrap());
        assert!(rel_close(g.h, w.h, 1e-13), "{line}: {} vs {}", g.h, w.h);
        for var in ["gap", "pressure", "temp_a", "temp_b"] {
            let (a, b) = (exact(&g, var), exact(&w, var));
            assert!(
                (a - b).abs() <= 1e-6 * (b.abs() + w.h / 300.0),
                "{line}: d{var} {a} vs {b}"
            );
        }
    }
}

#[test]
fn several_deck_lines_add_up() {
    let m = from_deck(
        "    Gap Conductance Coefficient = Constant H = 10\n    Gap Conductance Coefficient = Radiation Emissivity_A = 1 Emissivity_B = 1\n    Gap Conductance Coefficient = Gas_Gap K = 0.025\n",
    );
    let s = state(1e-3, 0.0, 500.0, 500.0);
    let want = 10.0 + 4.0 * SIGMA * 500f64.powi(3) + 25.0;
    assert!(rel_close(value(&*m, &s), want, 1e-14));
    assert!(
        m.name()
            .starts_with("sum of constant + radiation + gas_gap"),
        "{}",
        m.name()
    );
    // Other material-model lines are not this module's business.
    let (e, sources) = enforcement("    Contact Gap Temperature = Mean\n");
    let (m, d) = from_properties(&e, Path::new("."), &sources);
    assert!(m.is_none() && d.is_empty());
}

#[test]
fn deck_lua_file_is_taken_from_the_deck_directory() {
    let tmp = crate::scratch("conductance-deck");
    let dir = tmp.path();
    std::fs::write(
        dir.join("h.lua"),
        "function h_of(gap, ta, tb)\n  return 3 + gap\nend\n",
    )
    .unwrap();
    let (e, sources) =
        enforcement("    Gap Conductance Coefficient = Lua File = \"h.lua\" Function = h_of\n");
    let (m, d) = from_properties(&e, dir, &sources);
    assert!(d.is_empty(), "{}", d.render(&sources));
    let c = m.unwrap().evaluate(&state(0.5, 0.0, 1.0, 1.0)).unwrap();
    assert!(
        rel_close(c.h, 3.5, 1e-15) && rel_close(c.dh_dgap, 1.0, 1e-9),
        "{c:?}"
    );
}

#[test]
fn toml_properties_build_the_same_models() {
    let text = r#"
[[contact_definition]]
[[contact_definition.enforcement]]
[[contact_definition.enforcement.property]]
property = "gap_conductance_coefficient"
model = "table"
args = [{ value = "of" }, { key = "pressure", value = "0" }, { value = "10" }, { value = "1e7" }, { value = "5000" }]
[[contact_definition.enforcement.property]]
property = "gap_conductance_coefficient"
model = "lua"
args = [{ value = "T_A - T_B" }]
"#;
    let file: Arc<str> = Arc::from("deck.toml");
    let (deck, diags) = seam::deck::parse_toml(&file, text);
    let sources = SourceMap::default();
    assert!(!diags.has_errors(), "{}", diags.render(&sources));
    let e = &deck.contact_definitions[0].enforcements[0];
    let (m, d) = from_properties(e, Path::new("."), &sources);
    assert!(d.is_empty(), "{}", d.render(&sources));
    let c = m.unwrap().evaluate(&state(0.0, 5e6, 400.0, 300.0)).unwrap();
    let want = 10.0 + 4990.0 * 0.5 + 100.0;
    assert!(rel_close(c.h, want, 1e-14), "{} vs {want}", c.h);
    assert!(rel_close(c.dh_dtemp_a, 1.0, 1e-9) && rel_close(c.dh_dtemp_b, -1.0, 1e-9));
    assert!(rel_close(c.dh_dpressure, 4990.0 / 1e7, 1e-12));
}

// ---- bad deck lines: snapshots ----

/// Each `tests/bad/conductance_*/` directory holds `conductance.i` (an enforcement
/// with bad `Gap Conductance Coefficient` lines) and `expected.stderr`, the rendered
/// diagnostics of `from_properties`. The deck is not named `deck.i`: the
/// `bad_decks` harness takes every `deck.i` under `tests/bad/` as a deck that the
/// parser itself must reject, and these decks parse cleanly. `SEAM_BLESS=1` rewrites
/// the snapshots (then read every changed file before committing it).
#[test]
fn bad_conductance_lines_match_their_snapshots() {
    let bless = std::env::var_os("SEAM_BLESS").is_some_and(|v| v == "1");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad");
    let mut dirs: Vec<PathBuf> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            p.file_name()
                .is_some_and(|n| n.to_string_lossy().starts_with("conductance_"))
        })
        .collect();
    dirs.sort();
    assert!(
        dirs.len() >= 6,
        "expected the conductance cases, found {}",
        dirs.len()
    );
    let mut failures = Vec::new();
    for dir in dirs {
        let name = "conductance.i";
        let text = std::fs::read_to_string(dir.join(name)).expect("conductance.i");
        let file: Arc<str> = Arc::from(name);
        let (deck, parse) = parse_sierra(&file, &text);
        let mut sources = SourceMap::default();
        sources.add(&file, &text);
        assert!(
            parse.is_empty(),
            "{}: {}",
            dir.display(),
            parse.render(&sources)
        );
        let e = &deck.contact_definitions[0].enforcements[0];
        let (m, diags) = from_properties(e, &dir, &sources);
        assert!(
            m.is_none() && diags.has_errors(),
            "{}: no errors",
            dir.display()
        );
        let got = diags.render(&sources);
        let path = dir.join("expected.stderr");
        if bless {
            std::fs::write(&path, &got).unwrap();
            continue;
        }
        let want = std::fs::read_to_string(&path).unwrap_or_default();
        if got != want {
            failures.push(format!(
                "--- {} ---\nexpected:\n{want}\ngot:\n{got}",
                dir.display()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} snapshot(s) differ (SEAM_BLESS=1 rewrites them):\n{}",
        failures.len(),
        failures.join("\n")
    );
}

// ---- plugin adapter ----

/// A C plugin compiled once per test process into this test's own directory.
fn compile(source: &str, stem: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("conductance-plugins");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!(
        "{}{stem}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ));
    let partial = dir.join(format!("{stem}.{}.partial", std::process::id()));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&cc)
        .args(["-std=c99", "-O2", "-shared", "-fPIC", "-I"])
        .arg(root.join("plugins/include"))
        .arg(root.join(source))
        .arg("-o")
        .arg(&partial)
        .arg("-lm")
        .status()
        .unwrap_or_else(|e| panic!("cannot run `{cc}`: {e}"));
    assert!(status.success(), "compiling {source} failed");
    std::fs::rename(&partial, &out).unwrap();
    out
}

fn c_table() -> &'static Path {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| compile("plugins/examples/c_table/c_table.c", "cond_table"))
}

#[test]
fn plugin_adapter_equals_the_built_in_table() {
    let pairs = [(0.0, 1e3), (1e6, 5e3), (4e6, 6.5e3)];
    let real: Vec<f64> = pairs.iter().flat_map(|&(p, h)| [p, h]).collect();
    let data = PluginData {
        real_data: real.clone(),
        ..PluginData::default()
    };
    let plugin = PluginConductance::new(Plugin::load_with(c_table(), &data).unwrap())
        .unwrap()
        .on_surfaces("a", "b");
    let table = Table::new(TableVariable::Pressure, &pairs).unwrap();
    for &p in &[-1.0, 0.0, 5e5, 1e6, 2e6, 4e6, 9e6] {
        let s = state(1e-4, p, 300.0, 320.0);
        let (a, b) = (plugin.evaluate(&s).unwrap(), table.evaluate(&s).unwrap());
        assert!(rel_close(a.h, b.h, 1e-14), "h({p}): {} vs {}", a.h, b.h);
        assert!(
            (a.dh_dpressure - b.dh_dpressure).abs() <= 1e-12 * b.dh_dpressure.abs(),
            "p = {p}"
        );
    }
    // The same through the deck, with the enforcement's Real Data.
    let reals: Vec<String> = real.iter().map(|v| format!("{v:e}")).collect();
    let lib = c_table().display().to_string();
    let (e, sources) = enforcement(&format!(
        "    Real Data = {}\n    Gap Conductance Coefficient = Plugin Library = \"{lib}\"\n",
        reals.join(" ")
    ));
    let (m, d) = from_properties(&e, Path::new("."), &sources);
    assert!(d.is_empty(), "{}", d.render(&sources));
    let s = state(0.0, 2e6, 300.0, 300.0);
    assert!(rel_close(value(&*m.unwrap(), &s), value(&table, &s), 1e-14));
    // A plugin with per-point state is not a coefficient model.
    let echo = compile("plugins/tests/c/echo.c", "cond_echo");
    let e = PluginConductance::new(Plugin::load(&echo).unwrap())
        .err()
        .unwrap();
    assert!(e.to_string().contains("stateless"), "{e}");
}
