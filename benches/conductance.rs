//! Cost of one conductance evaluation (h and its four derivatives) per contact point,
//! for each model, and the error of the Lua model against the equivalent built-in.
//!
//! `cargo bench --bench conductance`. 1e6 points with gaps 1e-7…1e-2 m, pressures
//! 0…1e8 Pa and temperatures 300…1000 K; best of 3 runs, ns per point. The Lua rows
//! are timed twice: `value` (one Lua call) and `evaluate` (value plus two calls per
//! derivative of a variable the expression names). Nothing here gates CI.

use std::hint::black_box;
use std::time::Instant;

use seam::enforce::conductance::{
    Cmy, ConductanceModel, Constant, GasGap, LuaConductance, MinGapOrder, PointState, Radiation,
    Sum, Table, TableVariable,
};

const N: usize = 1_000_000;
const RUNS: usize = 3;

/// Deterministic pseudo-random numbers in [0, 1) (a 64-bit LCG; quality is irrelevant).
fn uniform(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64
}

fn points() -> Vec<PointState> {
    let mut seed = 7;
    (0..N)
        .map(|i| PointState {
            gap: 10f64.powf(-7.0 + 5.0 * uniform(&mut seed)),
            pressure: 1e8 * uniform(&mut seed),
            temp_a: 300.0 + 700.0 * uniform(&mut seed),
            temp_b: 300.0 + 700.0 * uniform(&mut seed),
            x: [uniform(&mut seed), 0.0, 0.0],
            time: i as f64,
        })
        .collect()
}

/// Best-of-`RUNS` ns per point of `f` over `pts`.
fn time(pts: &[PointState], f: impl Fn(&PointState) -> f64) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..RUNS {
        let t = Instant::now();
        let mut acc = 0.0;
        for p in pts {
            acc += f(black_box(p));
        }
        black_box(acc);
        best = best.min(t.elapsed().as_secs_f64() * 1e9 / pts.len() as f64);
    }
    best
}

fn eval(m: &dyn ConductanceModel) -> impl Fn(&PointState) -> f64 + '_ {
    move |p| {
        let c = m.evaluate(p).expect("evaluates");
        c.h + c.dh_dgap + c.dh_dpressure + c.dh_dtemp_a + c.dh_dtemp_b
    }
}

fn main() {
    let pts = points();
    let table_pts: Vec<(f64, f64)> = (0..10)
        .map(|i| (1e-3 * i as f64, 1000.0 / (1.0 + i as f64)))
        .collect();
    let gas = GasGap::with(0.025, 1e-3, 300.0, 1e-6, 1e6, MinGapOrder::One).unwrap();
    let builtins: Vec<(&str, Box<dyn ConductanceModel>)> = vec![
        ("constant", Box::new(Constant::new(10.0).unwrap())),
        ("gas_gap (beta, order 1)", Box::new(gas)),
        ("radiation", Box::new(Radiation::new(0.8, 0.6).unwrap())),
        (
            "cmy",
            Box::new(Cmy::new(16.0, 200.0, 0.1, 1e-6, 3e9).unwrap()),
        ),
        (
            "table of gap (10 points)",
            Box::new(Table::new(TableVariable::Gap, &table_pts).unwrap()),
        ),
        (
            "sum cmy + gas_gap + radiation",
            Box::new(Sum::new(vec![
                Box::new(Cmy::new(16.0, 200.0, 0.1, 1e-6, 3e9).unwrap()),
                Box::new(gas),
                Box::new(Radiation::new(0.8, 0.6).unwrap()),
            ])),
        ),
    ];
    println!("{N} points, best of {RUNS}");
    println!("{:<56} {:>10}", "model", "ns/point");
    for (name, m) in &builtins {
        println!("{:<56} {:>10.1}", name, time(&pts, eval(m.as_ref())));
    }

    let lua_linear = LuaConductance::expression("bench", "100 + 0.1*(temp_a + temp_b)/2").unwrap();
    let gas0 = GasGap::with(0.025, 1e-3, 300.0, 1e-6, 1e6, MinGapOrder::Zero).unwrap();
    let lua_gas = LuaConductance::expression(
        "bench",
        "0.025*(1 + 1e-3*((temp_a + temp_b)/2 - 300))/math.max(gap, 1e-6)",
    )
    .unwrap();
    for (name, m) in [
        ("lua `100 + 0.1*(temp_a + temp_b)/2`", &lua_linear),
        ("lua gas gap", &lua_gas),
    ] {
        let v = time(&pts, |p| m.value(p).expect("evaluates"));
        println!("{:<56} {:>10.1}", format!("{name}: value"), v);
        let e = time(&pts, eval(m));
        println!("{:<56} {:>10.1}", format!("{name}: value + derivatives"), e);
    }

    // Error of the Lua gas gap against the built-in, away from the kink at g_min where
    // a central difference straddles it (|g − g_min| > 2 steps).
    let (mut value_err, mut deriv_err) = (0.0f64, 0.0f64);
    for p in pts.iter().filter(|p| (p.gap - 1e-6).abs() > 1e-10 * 1e4) {
        let (l, b) = (lua_gas.evaluate(p).unwrap(), gas0.evaluate(p).unwrap());
        value_err = value_err.max((l.h - b.h).abs() / b.h);
        let scale_g = p.gap.abs().max(1e-9);
        for (dl, db, scale) in [
            (l.dh_dgap, b.dh_dgap, scale_g),
            (l.dh_dtemp_a, b.dh_dtemp_a, p.temp_a),
            (l.dh_dtemp_b, b.dh_dtemp_b, p.temp_b),
        ] {
            deriv_err = deriv_err.max((dl - db).abs() / (db.abs() + b.h / scale));
        }
    }
    println!(
        "lua gas gap vs built-in: max relative error h {value_err:.1e}, derivatives {deriv_err:.1e}"
    );
}
