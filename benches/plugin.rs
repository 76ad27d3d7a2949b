//! Cost of a plugin call per contact point, against the same model as native Rust.
//!
//! `cargo bench --bench plugin`. Builds the C table plugin with `cc -O2` and the Rust CMY
//! plugin with `cargo build --release` (into `$CARGO_TARGET_TMPDIR`), then times 1e6
//! points through: (a) a native Rust closure (the built-in stand-in), (b) the host's
//! batched call, (c) the host's per-point call, and (d) the raw batch entry on
//! pre-built `SeamPointIn` arrays (no host marshalling or validation). Best of 5 runs.
//! Also reports the largest difference between native and plugin values (speed *and*
//! error). Then it assembles a 1e6-point interface (two slabs, 500 × 500 side-A faces
//! with 2 × 2 Gauss points against 450 × 450 side-B faces) with the gap-conductance
//! form whose h comes from: the built-in constant model, the C table plugin (flat at
//! h = 10) called per point, the same plugin evaluated in one batch before the assembly,
//! and a Lua expression `10`; time per point for evaluation plus assembly, best of 3.
//! Last, `Plugin Isolation = Process` against in process (both plugins, 256 points per
//! call and one point per call, medians of 11; the worker's start-up time; results
//! compared bit for bit); `cargo bench --bench plugin -- isolation` runs that part alone.
//! Nothing here gates CI.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use seam::plugin::{ContactPoint, Plugin, PluginData, PointResult, StepContext};
use std::ffi::c_char;

use seam_plugin_abi::{
    SEAM_MESSAGE_LEN, SeamInstanceIn, SeamPluginDescriptor, SeamPointIn, SeamPointOut,
};

const N: usize = 1_000_000;
const RUNS: usize = 5;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn dll(dir: &Path, stem: &str) -> PathBuf {
    dir.join(format!(
        "{}{stem}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ))
}

fn build_plugins() -> (PathBuf, PathBuf) {
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cdir = tmp.join("bench-plugins-c");
    std::fs::create_dir_all(&cdir).expect("create dir");
    let table = dll(&cdir, "seam_c_table");
    let ok = Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
        .args([
            "-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-shared", "-fPIC", "-I",
        ])
        .arg(root().join("plugins/include"))
        .arg(root().join("plugins/examples/c_table/c_table.c"))
        .arg("-o")
        .arg(&table)
        .status()
        .expect("run cc")
        .success();
    assert!(ok, "cc failed");
    let target = tmp.join("bench-plugins-target");
    let ok = Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
        .args([
            "build",
            "--quiet",
            "--release",
            "--locked",
            "--manifest-path",
        ])
        .arg(root().join("plugins/Cargo.toml"))
        .args(["-p", "seam-example-rust-cmy", "--target-dir"])
        .arg(&target)
        .env_remove("CARGO_TARGET_DIR")
        .status()
        .expect("run cargo")
        .success();
    assert!(ok, "cargo build of the CMY plugin failed");
    (table, dll(&target.join("release"), "seam_rust_cmy"))
}

/// Best wall time over RUNS of `f`, in ns per point.
fn time(mut f: impl FnMut()) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..RUNS {
        let t = Instant::now();
        f();
        best = best.min(t.elapsed().as_secs_f64());
    }
    best * 1e9 / N as f64
}

const TABLE: [(f64, f64); 4] = [(0.0, 1e3), (1e6, 5e3), (4e6, 6.5e3), (1e7, 6.5e3)];
const CMY: [f64; 8] = [20.0, 0.1, 1e-6, 1e9, 0.026, 1e-5, 0.8, 0.6];

fn native_table(p: f64) -> PointResult {
    let n = TABLE.len();
    if p < TABLE[0].0 {
        return PointResult {
            value: TABLE[0].1,
            ..PointResult::default()
        };
    }
    if p >= TABLE[n - 1].0 {
        return PointResult {
            value: TABLE[n - 1].1,
            ..PointResult::default()
        };
    }
    let i = TABLE.partition_point(|&(q, _)| q <= p) - 1;
    let ((p0, h0), (p1, h1)) = (TABLE[i], TABLE[i + 1]);
    let slope = (h1 - h0) / (p1 - p0);
    PointResult {
        value: h0 + slope * (p - p0),
        d_pressure: slope,
        ..PointResult::default()
    }
}

fn native_cmy(c: &ContactPoint) -> PointResult {
    let [k_s, m, sigma, h_c, k_g, gm, ea, eb] = CMY;
    let sb = 5.670_374_419e-8;
    let (hc, dhc) = if c.pressure > 0.0 {
        let h = 1.25 * k_s * (m / sigma) * (c.pressure / h_c).powf(0.95);
        (h, 0.95 * h / c.pressure)
    } else {
        (0.0, 0.0)
    };
    let g = c.gap.max(0.0);
    let hg = k_g / (g + gm);
    let e = 1.0 / ea + 1.0 / eb - 1.0;
    let (ta, tb) = (c.temp_a, c.temp_b);
    PointResult {
        value: hc + hg + sb * (ta * ta + tb * tb) * (ta + tb) / e,
        d_temp_a: sb * (3.0 * ta * ta + 2.0 * ta * tb + tb * tb) / e,
        d_temp_b: sb * (3.0 * tb * tb + 2.0 * ta * tb + ta * ta) / e,
        d_gap: if c.gap > 0.0 { -hg / (g + gm) } else { 0.0 },
        d_pressure: dhc,
    }
}

fn max_diff(a: &[PointResult], b: &[PointResult]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            let rel = |u: f64, v: f64| (u - v).abs() / u.abs().max(v.abs()).max(1e-300);
            rel(x.value, y.value)
                .max(rel(x.d_temp_a, y.d_temp_a))
                .max(rel(x.d_temp_b, y.d_temp_b))
                .max(rel(x.d_gap, y.d_gap))
                .max(rel(x.d_pressure, y.d_pressure))
        })
        .fold(0.0, f64::max)
}

/// ns per point through `evaluate_batch` directly.
fn raw_batch(d: &'static SeamPluginDescriptor, real: &[f64], points: &[ContactPoint]) -> f64 {
    let input = SeamInstanceIn {
        struct_size: size_of::<SeamInstanceIn>() as u32,
        reserved: 0,
        model: c"bench".as_ptr(),
        integer_data: std::ptr::null(),
        n_integer: 0,
        real_data: real.as_ptr(),
        n_real: real.len(),
    };
    let mut instance = std::ptr::null_mut();
    let mut message = [0 as c_char; SEAM_MESSAGE_LEN];
    if let Some(init) = d.init {
        // SAFETY: valid input, instance slot and message buffer, as the ABI requires.
        let status = unsafe { init(&input, &mut instance, message.as_mut_ptr()) };
        assert_eq!(status, 0, "init failed");
    }
    let ins: Vec<SeamPointIn> = points
        .iter()
        .map(|c| {
            let mut s = SeamPointIn::new();
            s.gap = c.gap;
            s.pressure = c.pressure;
            s.temp_a = c.temp_a;
            s.temp_b = c.temp_b;
            s.real_data = real.as_ptr();
            s.n_real = real.len();
            s
        })
        .collect();
    let mut outs = vec![SeamPointOut::new(); 4096];
    let batch = d.evaluate_batch.expect("both examples have a batch entry");
    let t = time(|| {
        for chunk in ins.chunks(4096) {
            // SAFETY: chunk.len() valid inputs (real data outlives the call) and at least
            // as many writable outputs; the instance came from this descriptor's init.
            unsafe { batch(instance, chunk.as_ptr(), outs.as_mut_ptr(), chunk.len()) };
            black_box(&outs);
        }
    });
    if let Some(finalize) = d.finalize {
        // SAFETY: the instance from init above, released once.
        unsafe { finalize(instance) };
    }
    t
}

fn main() {
    let (table_path, cmy_path) = build_plugins();
    // `cargo bench --bench plugin -- isolation`: only the in-process / isolated table.
    if std::env::args().skip(1).any(|a| a == "isolation") {
        isolation(&table_path, &cmy_path);
        return;
    }
    let points: Vec<ContactPoint> = (0..N)
        .map(|i| {
            let t = i as f64 / N as f64;
            ContactPoint {
                gap: 1e-4 * t,
                pressure: 1.2e7 * t,
                temp_a: 300.0 + 600.0 * t,
                temp_b: 350.0 + 100.0 * t,
                normal_a: [0.0, 0.0, 1.0],
                normal_b: [0.0, 0.0, -1.0],
                weight: 1.0,
                ..ContactPoint::default()
            }
        })
        .collect();
    let ctx = StepContext {
        surface_a: "a",
        surface_b: "b",
        time: 1.0,
        dt: 1.0,
        step: 1,
        ..StepContext::default()
    };
    println!("plugin call cost, {N} points, best of {RUNS} runs (ns per point)");
    println!(
        "{:<8} {:>9} {:>9} {:>9} {:>9} {:>8} {:>8} {:>11}",
        "model", "native", "batch", "point", "raw", "batch/n", "point/n", "max rel err"
    );
    let table_real: Vec<f64> = TABLE.iter().flat_map(|&(p, h)| [p, h]).collect();
    for (name, path, real, native) in [
        (
            "c_table",
            &table_path,
            table_real,
            &(|c: &ContactPoint| native_table(c.pressure)) as &dyn Fn(&ContactPoint) -> PointResult,
        ),
        ("cmy", &cmy_path, CMY.to_vec(), &native_cmy),
    ] {
        let data = PluginData {
            model: None,
            integer_data: vec![],
            real_data: real,
        };
        let plugin = Plugin::load_with(path, &data).expect("load plugin");
        let mut native_out = vec![PointResult::default(); N];
        let t_native = time(|| {
            for (o, c) in native_out.iter_mut().zip(&points) {
                *o = native(black_box(c));
            }
            black_box(&native_out);
        });
        let mut batch_out = vec![PointResult::default(); N];
        let t_batch = time(|| {
            plugin
                .evaluate(&ctx, &points, &mut batch_out, None)
                .expect("batch")
        });
        let mut point_out = vec![PointResult::default(); N];
        let t_point = time(|| {
            plugin
                .evaluate_per_point(&ctx, &points, &mut point_out, None)
                .expect("point")
        });
        // Raw: the ABI batch call alone, on inputs marshalled once, 4096 points per call,
        // with an instance of our own (no host copies, chunking or validation).
        let t_raw = raw_batch(
            plugin.descriptor().expect("loaded in process"),
            &data.real_data,
            &points,
        );
        let err = max_diff(&native_out, &batch_out).max(max_diff(&native_out, &point_out));
        println!(
            "{:<8} {:>9.1} {:>9.1} {:>9.1} {:>9.1} {:>8.2} {:>8.2} {:>11.1e}",
            name,
            t_native,
            t_batch,
            t_point,
            t_raw,
            t_batch / t_native,
            t_point / t_native,
            err
        );
    }

    assembly(&table_path);
    isolation(&table_path, &cmy_path);
}

/// Median of `reps` timings of `f`, each over `points` points, in ns per point.
fn median_ns(reps: usize, points: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..reps)
        .map(|_| {
            let start = Instant::now();
            f();
            start.elapsed().as_secs_f64() * 1e9 / points as f64
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[reps / 2]
}

/// `Plugin Isolation = Process` against in process: ns per point with 256 points per call
/// (a batch, as the host's chunks) and with one point per call (as `seam run` calls a
/// conductance), medians of 11 timings; and the cost of starting a worker (what a crash
/// costs before the next call). The results of both modes are compared bit for bit.
fn isolation(table_path: &Path, cmy_path: &Path) {
    seam::plugin::set_worker_program(env!("CARGO_BIN_EXE_seam"));
    const REPS: usize = 11;
    const BATCH: usize = 256;
    const CALLS_BATCH: usize = 400;
    const CALLS_POINT: usize = 20_000;
    let points: Vec<ContactPoint> = (0..BATCH)
        .map(|i| {
            let t = i as f64 / BATCH as f64;
            ContactPoint {
                gap: 1e-4 * t,
                pressure: 1.2e7 * t,
                temp_a: 300.0 + 600.0 * t,
                temp_b: 350.0 + 100.0 * t,
                normal_a: [0.0, 0.0, 1.0],
                normal_b: [0.0, 0.0, -1.0],
                weight: 1.0,
                ..ContactPoint::default()
            }
        })
        .collect();
    let ctx = StepContext {
        surface_a: "side_a",
        surface_b: "side_b",
        time: 1.0,
        dt: 1.0,
        step: 1,
        ..StepContext::default()
    };
    println!();
    println!(
        "plugin isolation: ns per point, median of {REPS} (batch: {CALLS_BATCH} calls of {BATCH} points; point: {CALLS_POINT} calls of 1)"
    );
    println!(
        "{:<8} {:>11} {:>11} {:>8} {:>11} {:>11} {:>8} {:>10} {:>9}",
        "model",
        "batch none",
        "batch proc",
        "ratio",
        "point none",
        "point proc",
        "ratio",
        "start ms",
        "bitwise"
    );
    let table_real: Vec<f64> = TABLE.iter().flat_map(|&(p, h)| [p, h]).collect();
    for (name, path, real) in [
        ("c_table", table_path, table_real),
        ("cmy", cmy_path, CMY.to_vec()),
    ] {
        let data = PluginData {
            model: None,
            integer_data: vec![],
            real_data: real,
        };
        let here = Plugin::load_with(path, &data).expect("load in process");
        let there = Plugin::load_isolated(path, &data).expect("load in a worker");
        let mut out = vec![PointResult::default(); BATCH];
        let batch = |p: &Plugin, out: &mut [PointResult]| {
            median_ns(REPS, CALLS_BATCH * BATCH, || {
                for _ in 0..CALLS_BATCH {
                    p.evaluate(&ctx, &points, out, None).expect("batch");
                }
                black_box(&*out);
            })
        };
        let single = |p: &Plugin, out: &mut [PointResult]| {
            median_ns(REPS, CALLS_POINT, || {
                for k in 0..CALLS_POINT {
                    let i = k % BATCH;
                    p.evaluate(&ctx, &points[i..=i], &mut out[i..=i], None)
                        .expect("point");
                }
                black_box(&*out);
            })
        };
        let (b_none, b_proc) = (batch(&here, &mut out), batch(&there, &mut out));
        let (p_none, p_proc) = (single(&here, &mut out), single(&there, &mut out));
        let start_ms = median_ns(REPS, 1, || {
            black_box(Plugin::load_isolated(path, &data).expect("load in a worker"));
        }) * 1e-6;
        let mut a = vec![PointResult::default(); BATCH];
        let mut b = vec![PointResult::default(); BATCH];
        here.evaluate(&ctx, &points, &mut a, None).expect("batch");
        there.evaluate(&ctx, &points, &mut b, None).expect("batch");
        let same = a.iter().zip(&b).all(|(x, y)| {
            [x.value, x.d_temp_a, x.d_temp_b, x.d_gap, x.d_pressure].map(f64::to_bits)
                == [y.value, y.d_temp_a, y.d_temp_b, y.d_gap, y.d_pressure].map(f64::to_bits)
        });
        println!(
            "{:<8} {:>11.1} {:>11.1} {:>8.1} {:>11.1} {:>11.1} {:>8.1} {:>10.2} {:>9}",
            name,
            b_none,
            b_proc,
            b_proc / b_none,
            p_none,
            p_proc,
            p_proc / p_none,
            start_ms,
            if same { "yes" } else { "NO" }
        );
    }
}

/// Time per point of assembling the interface terms with each conductance source.
fn assembly(table_path: &Path) {
    use seam::assembly::DofMap;
    use seam::enforce::conductance::{
        ConductanceModel, Constant, LuaConductance, PluginConductance, PointState,
    };
    use seam::enforce::interface::{
        DEFAULT_BETA, Form, HFn, HInput, HValue, InterfaceForm, interface_terms,
    };
    use seam::mesh::generate::{self, BoxSpec};
    use seam::search::SearchSettings;
    use seam::search::pairing::{Integration, PointStatus, Searcher, SurfaceGeometry};
    use std::cell::Cell;

    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.01], [500, 500, 1], 1)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0, 0.0, 0.01], [1.0, 1.0, 0.02], [450, 450, 1], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    );
    let a = SurfaceGeometry::from_side_set(&mesh, 0).expect("side A");
    let b = SurfaceGeometry::from_side_set(&mesh, 1).expect("side B");
    let settings = SearchSettings::defaults(3);
    let r = Searcher::new(&b, &settings).search_points(
        &a,
        &b,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    let n = r
        .points
        .iter()
        .filter(|p| p.status == PointStatus::Matched)
        .count();
    let dofs = DofMap::new(&mesh, &[("temperature", &[0, 1])]).expect("dofs");
    let field = dofs.field("temperature").expect("field");
    let u = vec![0.0; dofs.len()];
    let k = [16.0, 200.0];
    let state = |p: &HInput| PointState {
        gap: p.gap,
        pressure: 0.0,
        temp_a: p.temp_a,
        temp_b: p.temp_b,
        x: p.x,
        time: 0.0,
    };
    let via = |m: &dyn ConductanceModel, p: &HInput| -> Result<HValue, String> {
        let c = m.evaluate(&state(p)).map_err(|e| e.to_string())?;
        Ok(HValue {
            h: c.h,
            dh_dtemp_a: c.dh_dtemp_a,
            dh_dtemp_b: c.dh_dtemp_b,
            ..HValue::default()
        })
    };
    let time_form = |h: &HFn<'_>| -> f64 {
        let f = InterfaceForm {
            form: Form::GapConductance,
            h,
            offset: 0.0,
            beta: DEFAULT_BETA,
            conductivity: &k,
            conductivity_of_t: None,
            temperature_field: None,
        };
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let t = Instant::now();
            let s =
                interface_terms(&mesh, &dofs, field, &a, &b, &r.points, &f, &u).expect("assembly");
            best = best.min(t.elapsed().as_secs_f64());
            black_box(s);
        }
        best * 1e9 / n as f64
    };
    let constant = Constant::new(10.0).expect("h");
    let t_builtin = time_form(&|p: &HInput| via(&constant, p));
    let data = PluginData {
        model: None,
        integer_data: vec![],
        real_data: vec![0.0, 10.0, 1e6, 10.0],
    };
    let plugin = PluginConductance::new(Plugin::load_with(table_path, &data).expect("load"))
        .expect("conductance plugin");
    let t_point = time_form(&|p: &HInput| via(&plugin, p));
    // Batched: every matched point evaluated in one host call first, then the assembly
    // reads the values in the order it meets the points.
    let host = Plugin::load_with(table_path, &data).expect("load");
    let inputs: Vec<ContactPoint> = r
        .points
        .iter()
        .filter(|p| p.status == PointStatus::Matched)
        .map(|p| ContactPoint {
            gap: p.gap,
            x: p.x,
            normal_a: p.normal_a,
            normal_b: p.normal_b,
            weight: p.weight,
            ..ContactPoint::default()
        })
        .collect();
    let mut outputs = vec![PointResult::default(); inputs.len()];
    let next = Cell::new(0usize);
    let t_batch = {
        let mut best = f64::INFINITY;
        for _ in 0..3 {
            let t = Instant::now();
            host.evaluate(&StepContext::default(), &inputs, &mut outputs, None)
                .expect("batch");
            next.set(0);
            let h = |_: &HInput| {
                let i = next.get();
                next.set(i + 1);
                Ok(HValue {
                    h: outputs[i].value,
                    dh_dtemp_a: outputs[i].d_temp_a,
                    dh_dtemp_b: outputs[i].d_temp_b,
                    ..HValue::default()
                })
            };
            let f = InterfaceForm {
                form: Form::GapConductance,
                h: &h,
                offset: 0.0,
                beta: DEFAULT_BETA,
                conductivity: &k,
                conductivity_of_t: None,
                temperature_field: None,
            };
            let s =
                interface_terms(&mesh, &dofs, field, &a, &b, &r.points, &f, &u).expect("assembly");
            best = best.min(t.elapsed().as_secs_f64());
            black_box(s);
        }
        best * 1e9 / n as f64
    };
    let lua = LuaConductance::expression("bench", "10").expect("lua");
    let t_lua = time_form(&|p: &HInput| via(&lua, p));
    println!();
    println!("interface assembly, {n} points, best of 3 (ns per point, evaluation + assembly)");
    println!("{:<26} {:>9} {:>9}", "conductance", "ns/point", "/built-in");
    for (name, t) in [
        ("built-in constant", t_builtin),
        ("plugin, batched", t_batch),
        ("plugin, per point", t_point),
        ("lua expression", t_lua),
    ] {
        println!("{name:<26} {t:>9.1} {:>9.2}", t / t_builtin);
    }
}
