//! Enforcement plugins: the ABI header, data passing, the two examples, every fault the
//! host must survive, and the conformance kit.
//!
//! The plugins are built by the tests themselves, once per test process:
//! - C plugins with `$CC` (default `cc`) `-std=c99 -Wall -Wextra -Werror -shared -fPIC`
//!   into `$CARGO_TARGET_TMPDIR/plugins-c/`;
//! - Rust plugins with `cargo build --manifest-path plugins/Cargo.toml --locked -p …`
//!   into their own target directory `$CARGO_TARGET_TMPDIR/plugins-target` (a separate
//!   directory, so the inner cargo never waits for the lock the outer `cargo test` holds).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use seam::plugin::{
    ContactPoint, Plugin, PluginData, PluginError, PluginFault, PointResult, StateStore,
    StepContext, check_plugin,
};
use seam_plugin_testkit::{Config, Grid};
use tempfile::TempDir;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn tmp() -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
}

fn dll(dir: &Path, stem: &str) -> PathBuf {
    dir.join(format!(
        "{}{stem}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    ))
}

/// Compile one C file into a shared library with the CI flags; returns its path.
pub(crate) fn cc_shared(source: &str, defines: &[&str], stem: &str) -> PathBuf {
    let dir = tmp().join("plugins-c");
    std::fs::create_dir_all(&dir).expect("create plugins-c");
    let out = dll(&dir, stem);
    // Compile to a private name and rename: a test process that already mapped the old
    // library (another process of a parallel runner) keeps its inode intact.
    let partial = dir.join(format!("{stem}.{}.partial", std::process::id()));
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&compiler)
        .args([
            "-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-shared", "-fPIC",
        ])
        .arg("-I")
        .arg(root().join("plugins/include"))
        .args(defines)
        .arg(root().join(source))
        .arg("-o")
        .arg(&partial)
        .arg("-lm")
        .status()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{compiler}`: {e}"));
    assert!(status.success(), "compiling {source} {defines:?} failed");
    std::fs::rename(&partial, &out).expect("move the compiled plugin into place");
    out
}

/// The faulty C plugins, by FAULT_* name.
const FAULTS: [&str; 13] = [
    "WRONG_DERIVATIVE",
    "NAN",
    "NAN_DERIVATIVE",
    "NEGATIVE",
    "ERROR",
    "CUTBACK",
    "BAD_STATUS",
    "MAJOR",
    "MINOR",
    "SMALL",
    "NULL_EVALUATE",
    "NO_ENTRY",
    "V2_ONLY",
];

struct CPlugins {
    table: PathBuf,
    echo: PathBuf,
    smooth: PathBuf,
}

fn c_plugins() -> &'static CPlugins {
    static BUILT: OnceLock<CPlugins> = OnceLock::new();
    BUILT.get_or_init(|| {
        for f in FAULTS {
            cc_shared(
                "plugins/tests/faulty/faulty.c",
                &[&format!("-DFAULT_{f}")],
                &format!("faulty_{}", f.to_lowercase()),
            );
        }
        CPlugins {
            table: cc_shared("plugins/examples/c_table/c_table.c", &[], "seam_c_table"),
            echo: cc_shared("plugins/tests/c/echo.c", &[], "echo"),
            smooth: cc_shared("plugins/tests/c/smooth.c", &[], "smooth"),
        }
    })
}

fn faulty(name: &str) -> PathBuf {
    c_plugins();
    dll(
        &tmp().join("plugins-c"),
        &format!("faulty_{}", name.to_lowercase()),
    )
}

struct RustPlugins {
    cmy: PathBuf,
    panicky: PathBuf,
}

fn rust_plugins() -> &'static RustPlugins {
    static BUILT: OnceLock<RustPlugins> = OnceLock::new();
    BUILT.get_or_init(|| {
        let target = tmp().join("plugins-target");
        let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
        let status = Command::new(cargo)
            .args(["build", "--quiet", "--locked", "--manifest-path"])
            .arg(root().join("plugins/Cargo.toml"))
            .args([
                "-p",
                "seam-example-rust-cmy",
                "-p",
                "seam-faulty-rust-panic",
            ])
            .arg("--target-dir")
            .arg(&target)
            .env_remove("CARGO_TARGET_DIR")
            .status()
            .expect("run cargo for the plugins workspace");
        assert!(status.success(), "building the Rust plugins failed");
        let dir = target.join("debug");
        RustPlugins {
            cmy: dll(&dir, "seam_rust_cmy"),
            panicky: dll(&dir, "seam_faulty_rust_panic"),
        }
    })
}

pub(crate) fn data(real: &[f64], integer: &[i64]) -> PluginData {
    PluginData {
        model: None,
        integer_data: integer.to_vec(),
        real_data: real.to_vec(),
    }
}

fn ctx() -> StepContext<'static> {
    StepContext {
        surface_a: "block_1_top",
        surface_b: "block_2_bottom",
        time: 1.0,
        dt: 0.5,
        step: 2,
        iteration: 1,
        ..StepContext::default()
    }
}

pub(crate) fn point(gap: f64, pressure: f64, temp_a: f64, temp_b: f64) -> ContactPoint {
    ContactPoint {
        gap,
        pressure,
        temp_a,
        temp_b,
        normal_a: [0.0, 0.0, 1.0],
        normal_b: [0.0, 0.0, -1.0],
        weight: 1.0,
        ..ContactPoint::default()
    }
}

pub(crate) fn eval(
    plugin: &Plugin,
    points: &[ContactPoint],
) -> Result<Vec<PointResult>, PluginFault> {
    let mut r = vec![PointResult::default(); points.len()];
    plugin.evaluate(&ctx(), points, &mut r, None)?;
    Ok(r)
}

fn close(a: f64, b: f64, rtol: f64) -> bool {
    (a - b).abs() <= rtol * a.abs().max(b.abs()).max(f64::MIN_POSITIVE)
}

// --- the header ------------------------------------------------------------------------

/// Every struct's size, every field's offset and every constant in seam_plugin.h equals
/// the Rust definition in seam-plugin-abi.
#[test]
fn c_header_matches_the_rust_abi() {
    use seam_plugin_abi::*;
    use std::mem::{offset_of, size_of};
    /// (struct, [(field, offset, size)], size)
    type Layout<'a> = (&'a str, &'a [(&'a str, usize, usize)], usize);
    fn size_of_field<T, F>(_field: impl Fn(&T) -> &F) -> usize {
        size_of::<F>()
    }
    macro_rules! f {
        ($t:ty, $f:ident) => {
            (
                stringify!($f),
                offset_of!($t, $f),
                size_of_field(|s: &$t| &s.$f),
            )
        };
    }
    let fields: &[Layout<'_>] = &[
        (
            "SeamInstanceIn",
            &[
                f!(SeamInstanceIn, struct_size),
                f!(SeamInstanceIn, reserved),
                f!(SeamInstanceIn, model),
                f!(SeamInstanceIn, integer_data),
                f!(SeamInstanceIn, n_integer),
                f!(SeamInstanceIn, real_data),
                f!(SeamInstanceIn, n_real),
            ],
            size_of::<SeamInstanceIn>(),
        ),
        (
            "SeamPointIn",
            &[
                f!(SeamPointIn, struct_size),
                f!(SeamPointIn, reserved),
                f!(SeamPointIn, gap),
                f!(SeamPointIn, pressure),
                f!(SeamPointIn, temp_a),
                f!(SeamPointIn, temp_b),
                f!(SeamPointIn, x),
                f!(SeamPointIn, normal_a),
                f!(SeamPointIn, normal_b),
                f!(SeamPointIn, weight),
                f!(SeamPointIn, time),
                f!(SeamPointIn, dt),
                f!(SeamPointIn, step),
                f!(SeamPointIn, iteration),
                f!(SeamPointIn, surface_a),
                f!(SeamPointIn, surface_b),
                f!(SeamPointIn, fields),
                f!(SeamPointIn, n_fields),
                f!(SeamPointIn, integer_data),
                f!(SeamPointIn, n_integer),
                f!(SeamPointIn, real_data),
                f!(SeamPointIn, n_real),
                f!(SeamPointIn, state_old),
                f!(SeamPointIn, state_new),
                f!(SeamPointIn, n_state),
            ],
            size_of::<SeamPointIn>(),
        ),
        (
            "SeamPointOut",
            &[
                f!(SeamPointOut, struct_size),
                f!(SeamPointOut, status),
                f!(SeamPointOut, value),
                f!(SeamPointOut, d_temp_a),
                f!(SeamPointOut, d_temp_b),
                f!(SeamPointOut, d_gap),
                f!(SeamPointOut, d_pressure),
                f!(SeamPointOut, cutback_factor),
                f!(SeamPointOut, message),
            ],
            size_of::<SeamPointOut>(),
        ),
        (
            "SeamPluginDescriptor",
            &[
                f!(SeamPluginDescriptor, abi_major),
                f!(SeamPluginDescriptor, abi_minor),
                f!(SeamPluginDescriptor, struct_size),
                f!(SeamPluginDescriptor, state_size),
                f!(SeamPluginDescriptor, name),
                f!(SeamPluginDescriptor, model_version),
                f!(SeamPluginDescriptor, capabilities),
                f!(SeamPluginDescriptor, init),
                f!(SeamPluginDescriptor, finalize),
                f!(SeamPluginDescriptor, evaluate_point),
                f!(SeamPluginDescriptor, evaluate_batch),
            ],
            size_of::<SeamPluginDescriptor>(),
        ),
    ];
    let constants: &[(&str, i128)] = &[
        ("SEAM_PLUGIN_ABI_MAJOR", SEAM_PLUGIN_ABI_MAJOR.into()),
        ("SEAM_PLUGIN_ABI_MINOR", SEAM_PLUGIN_ABI_MINOR.into()),
        ("SEAM_MESSAGE_LEN", SEAM_MESSAGE_LEN as i128),
        ("SEAM_STATUS_OK", SEAM_STATUS_OK.into()),
        ("SEAM_STATUS_ERROR", SEAM_STATUS_ERROR.into()),
        ("SEAM_STATUS_CUTBACK", SEAM_STATUS_CUTBACK.into()),
        ("SEAM_CAP_THREAD_SAFE", SEAM_CAP_THREAD_SAFE.into()),
        (
            "SEAM_CAP_PROVIDES_DERIVATIVES",
            SEAM_CAP_PROVIDES_DERIVATIVES.into(),
        ),
        ("SEAM_CAP_RETURNS_FLUX", SEAM_CAP_RETURNS_FLUX.into()),
        ("SEAM_CAP_HAS_STATE", SEAM_CAP_HAS_STATE.into()),
        ("SEAM_CAP_ALL", SEAM_CAP_ALL.into()),
    ];
    // A C program printing what the C compiler makes of the header, one `key value` a line.
    let mut c = String::from(
        "#include <stdio.h>\n#include <stddef.h>\n#include \"seam_plugin.h\"\nint main(void) {\n",
    );
    let mut expected = Vec::new();
    for (ty, fs, size) in fields {
        c += &format!("  printf(\"sizeof {ty} %lu\\n\", (unsigned long)sizeof({ty}));\n");
        expected.push(format!("sizeof {ty} {size}"));
        for (f, off, size) in *fs {
            c += &format!(
                "  printf(\"field {ty}.{f} offset %lu size %lu\\n\", (unsigned long)offsetof({ty}, {f}), (unsigned long)sizeof((({ty} *)0)->{f}));\n"
            );
            expected.push(format!("field {ty}.{f} offset {off} size {size}"));
        }
    }
    for (name, value) in constants {
        c += &format!("  printf(\"{name} %lld\\n\", (long long)({name}));\n");
        expected.push(format!("{name} {value}"));
    }
    c +=
        "  printf(\"SEAM_PLUGIN_ENTRY_SYMBOL %s\\n\", SEAM_PLUGIN_ENTRY_SYMBOL);\n  return 0;\n}\n";
    let entry = std::str::from_utf8(&ENTRY_SYMBOL[..ENTRY_SYMBOL.len() - 1]).unwrap();
    expected.push(format!("SEAM_PLUGIN_ENTRY_SYMBOL {entry}"));
    let dir = crate::scratch("plugin-layout");
    let src = dir.path().join("layout.c");
    let exe = dir.path().join("layout");
    std::fs::write(&src, c).unwrap();
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(compiler)
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-I"])
        .arg(root().join("plugins/include"))
        .arg(&src)
        .arg("-o")
        .arg(&exe)
        .status()
        .unwrap();
    assert!(status.success(), "the header does not compile cleanly");
    let out = Command::new(&exe).output().unwrap();
    let got: Vec<String> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect();
    let differ: Vec<String> = expected
        .iter()
        .zip(&got)
        .filter(|(e, g)| e != g)
        .map(|(e, g)| format!("Rust `{e}` vs C `{g}`"))
        .collect();
    assert!(
        differ.is_empty() && got.len() == expected.len(),
        "seam_plugin.h and seam-plugin-abi disagree ({} vs {} lines):\n{}",
        got.len(),
        expected.len(),
        differ.join("\n")
    );
}

// --- data passing --------------------------------------------------------------------

/// The echo plugin folds every input into its outputs; the test computes the same sums.
#[test]
fn every_input_arrives_exactly_as_written() {
    let path = &c_plugins().echo;
    let real = [1.5, -0.25, 1e3];
    let integer = [7, -2];
    let plugin = Plugin::load_with(path, &data(&real, &integer)).unwrap();
    assert_eq!(plugin.info().state_size, 2);
    assert!(!plugin.info().thread_safe());
    let points = [
        ContactPoint {
            gap: 1e-5,
            pressure: 2e6,
            temp_a: 301.0,
            temp_b: 299.5,
            x: [0.1, 0.2, 0.3],
            normal_a: [0.0, 0.6, 0.8],
            normal_b: [0.0, -0.6, -0.8],
            weight: 0.125,
        },
        ContactPoint {
            gap: -3e-7,
            pressure: 0.0,
            temp_a: 500.0,
            temp_b: 250.0,
            x: [-1.0, 2.0, -3.0],
            normal_a: [1.0, 0.0, 0.0],
            normal_b: [-1.0, 0.0, 0.0],
            weight: 2.0,
        },
    ];
    let fields = [10.0, 20.0, 30.0, -1.0, -2.0, -3.0];
    let ctx = StepContext {
        surface_a: "side_A_surf",
        surface_b: "Ω_b",
        time: 12.5,
        dt: 0.25,
        step: 9,
        iteration: 3,
        fields: &fields,
        n_fields: 3,
    };
    let mut states = StateStore::new(2, 2);
    let mut r = vec![PointResult::default(); 2];
    let bytes = |s: &str| s.bytes().map(f64::from).sum::<f64>();
    for round in 0..3 {
        plugin
            .evaluate(&ctx, &points, &mut r, Some(&mut states))
            .unwrap();
        for (i, (p, out)) in points.iter().zip(&r).enumerate() {
            let f: f64 = fields[3 * i..3 * i + 3].iter().sum();
            let mix = p.gap
                + 2.0 * p.pressure
                + 3.0 * p.temp_a
                + 5.0 * p.temp_b
                + 7.0 * p.x[0]
                + 11.0 * p.x[1]
                + 13.0 * p.x[2]
                + 17.0 * p.normal_a[0]
                + 19.0 * p.normal_a[1]
                + 23.0 * p.normal_a[2]
                + 29.0 * p.normal_b[0]
                + 31.0 * p.normal_b[1]
                + 37.0 * p.normal_b[2]
                + 41.0 * p.weight
                + 43.0 * ctx.time
                + 47.0 * ctx.dt
                + 53.0 * ctx.step as f64
                + 59.0 * ctx.iteration as f64
                + 61.0 * f;
            // The plugin overwrites its copies of the data each call: the sums stay.
            assert_eq!(
                out.value,
                1.5 - 0.25 + 1e3 + 7.0 - 2.0,
                "round {round} point {i}"
            );
            assert_eq!(out.d_temp_a, 3.0 + 2e3 + 3e6 + 2e9, "lengths, point {i}");
            assert!(
                close(out.d_temp_b, mix, 1e-14),
                "scalars, point {i}: {} vs {mix}",
                out.d_temp_b
            );
            assert_eq!(
                out.d_gap,
                bytes("side_A_surf") + 1e3 * bytes("Ω_b"),
                "surface names"
            );
            // Old state is the committed one: 0 until the first commit, then 1.
            let expected_old = if round < 2 { 0.0 } else { 1.0 };
            assert_eq!(out.d_pressure, expected_old, "state_old, round {round}");
            assert_eq!(states.new_state(i), &[expected_old + 1.0, out.value]);
        }
        if round == 1 {
            states.commit();
        }
    }
    assert_eq!(states.old(0), &[1.0, 1006.25]);
}

/// A plugin that does not declare THREAD_SAFE is serialised: calling the (stateful,
/// data-scribbling) echo plugin from 4 threads still gives exact results.
#[test]
fn calls_to_a_plugin_that_is_not_thread_safe_are_serialised() {
    let plugin = Plugin::load_with(&c_plugins().echo, &data(&[2.0, 3.0], &[1])).unwrap();
    let points = vec![point(1e-5, 1e6, 300.0, 310.0); 600];
    std::thread::scope(|s| {
        for _ in 0..4 {
            s.spawn(|| {
                for _ in 0..20 {
                    let r = eval(&plugin, &points).unwrap();
                    assert!(
                        r.iter().all(|o| o.value == 6.0),
                        "a call saw another's scribbles"
                    );
                }
            });
        }
    });
}

// --- the examples ----------------------------------------------------------------------

/// Table used in the c_table tests: (pressure, conductance) pairs.
pub(crate) const TABLE: [(f64, f64); 4] = [(0.0, 1e3), (1e6, 5e3), (4e6, 6.5e3), (1e7, 6.5e3)];

pub(crate) fn table_real() -> Vec<f64> {
    TABLE.iter().flat_map(|&(p, h)| [p, h]).collect()
}

/// h(p) by linear interpolation, flat outside, written independently of the plugin.
fn table_h(p: f64) -> f64 {
    if p <= TABLE[0].0 {
        return TABLE[0].1;
    }
    for w in TABLE.windows(2) {
        let ((p0, h0), (p1, h1)) = (w[0], w[1]);
        if p <= p1 {
            return h0 + (h1 - h0) * (p - p0) / (p1 - p0);
        }
    }
    TABLE[TABLE.len() - 1].1
}

#[test]
fn c_table_reproduces_its_table_with_exact_derivatives() {
    let plugin = Plugin::load_with(&c_plugins().table, &data(&table_real(), &[])).unwrap();
    assert_eq!(plugin.info().name, "c_table");
    let pressures = [-5.0, 0.0, 2.5e5, 1e6, 2e6, 3.999e6, 4e6, 7e6, 1e7, 2e7];
    let points: Vec<_> = pressures
        .iter()
        .map(|&p| point(1e-6, p, 300.0, 400.0))
        .collect();
    let r = eval(&plugin, &points).unwrap();
    for (p, o) in pressures.iter().zip(&r) {
        assert!(
            close(o.value, table_h(*p), 1e-14),
            "h({p}) = {} vs {}",
            o.value,
            table_h(*p)
        );
        // Finite differences of the independent table, away from breakpoints one-sided
        // differences of a linear segment are exact; step 1 Pa.
        let fd = (table_h(p + 1.0) - table_h(*p)) / 1.0;
        assert!(
            (o.d_pressure - fd).abs() <= 1e-9 * fd.abs().max(1e-3),
            "dh/dp({p}) = {} vs FD {fd}",
            o.d_pressure
        );
        assert_eq!((o.d_temp_a, o.d_temp_b, o.d_gap), (0.0, 0.0, 0.0));
    }
    // Bad tables are refused at set-up with the plugin's message.
    let err = Plugin::load_with(&c_plugins().table, &data(&[0.0, 1.0, 5.0], &[])).unwrap_err();
    assert!(err.to_string().contains("pairs p0 h0 p1 h1"), "{err}");
    assert!(matches!(err, PluginError::Init { .. }));
    let err = Plugin::load_with(&c_plugins().table, &data(&[1.0, 1.0, 0.5, 2.0], &[])).unwrap_err();
    assert!(err.to_string().contains("increase strictly"), "{err}");
}

/// CMY parameters (Real Data order): k_s m sigma H_c k_g M eps_A eps_B.
const CMY: [f64; 8] = [20.0, 0.1, 1e-6, 1e9, 0.026, 1e-5, 0.8, 0.6];

#[test]
fn rust_cmy_matches_the_formula() {
    let plugin = Plugin::load_with(&rust_plugins().cmy, &data(&CMY, &[])).unwrap();
    assert_eq!(plugin.info().name, "cmy");
    let [k_s, m, sigma, h_c, k_g, gm, ea, eb] = CMY;
    let sb = 5.670374419e-8;
    let states = [
        (1e-6, 1e5, 300.0, 350.0),
        (1e-4, 3e7, 900.0, 310.0),
        (0.0, 1.0, 1000.0, 1000.0),
        (5e-5, 0.0, 400.0, 200.0),
    ];
    let points: Vec<_> = states
        .iter()
        .map(|&(g, p, a, b)| point(g, p, a, b))
        .collect();
    let r = eval(&plugin, &points).unwrap();
    for (&(g, p, ta, tb), o) in states.iter().zip(&r) {
        let e = 1.0 / ea + 1.0 / eb - 1.0;
        let hc = if p > 0.0 {
            1.25 * k_s * m / sigma * (p / h_c).powf(0.95)
        } else {
            0.0
        };
        let h = hc + k_g / (g + gm) + sb * (ta * ta + tb * tb) * (ta + tb) / e;
        let dta = sb * (3.0 * ta * ta + 2.0 * ta * tb + tb * tb) / e;
        let dtb = sb * (ta * ta + 2.0 * ta * tb + 3.0 * tb * tb) / e;
        let dg = if g > 0.0 {
            -k_g / ((g + gm) * (g + gm))
        } else {
            0.0
        };
        let dp = if p > 0.0 { 0.95 * hc / p } else { 0.0 };
        for (name, got, want) in [
            ("h", o.value, h),
            ("dT_A", o.d_temp_a, dta),
            ("dT_B", o.d_temp_b, dtb),
            ("dgap", o.d_gap, dg),
            ("dp", o.d_pressure, dp),
        ] {
            assert!(
                close(got, want, 1e-12),
                "{name} at {g} {p} {ta} {tb}: {got} vs {want}"
            );
        }
    }
    // Wrong Real Data: the SDK turns the model's error into a set-up error.
    let err = Plugin::load_with(&rust_plugins().cmy, &data(&[1.0], &[])).unwrap_err();
    assert!(
        err.to_string().contains("needs 8 Real Data values"),
        "{err}"
    );
}

#[test]
fn batch_and_per_point_calls_agree() {
    let table = Plugin::load_with(&c_plugins().table, &data(&table_real(), &[])).unwrap();
    let cmy = Plugin::load_with(&rust_plugins().cmy, &data(&CMY, &[])).unwrap();
    let points: Vec<_> = (0..1000)
        .map(|i| point(1e-7 * i as f64, 1.2e4 * i as f64, 300.0 + i as f64, 400.0))
        .collect();
    for plugin in [&table, &cmy] {
        assert!(plugin.info().has_batch);
        let batch = eval(plugin, &points).unwrap();
        let mut single = vec![PointResult::default(); points.len()];
        plugin
            .evaluate_per_point(&ctx(), &points, &mut single, None)
            .unwrap();
        assert_eq!(batch, single, "{}", plugin.info().name);
    }
}

/// The smooth plugin gives no derivatives: seam forms them by central differences.
#[test]
fn derivatives_are_formed_by_finite_differences_when_missing() {
    let plugin = Plugin::load(&c_plugins().smooth).unwrap();
    assert!(plugin.uses_finite_differences());
    let notice = plugin.derivative_notice().expect("a notice the first time");
    assert!(notice.contains("finite differences"), "{notice}");
    assert!(
        plugin.derivative_notice().is_none(),
        "the notice is given once"
    );
    let (g, p, ta, tb) = (2e-3, 3.0, 310.0, 290.0);
    let r = eval(&plugin, &[point(g, p, ta, tb)]).unwrap()[0];
    assert!(close(r.value, 1.0 + p * p + ta * tb + (-g).exp(), 1e-15));
    // Central differences: error O(δ²) with δ = ε^{1/3}·max(|x|, floor); 1e-7 relative
    // leaves a wide margin for round-off on a value of ~9e4.
    assert!(close(r.d_pressure, 2.0 * p, 1e-6), "{}", r.d_pressure);
    assert!(close(r.d_temp_a, tb, 1e-7), "{}", r.d_temp_a);
    assert!(close(r.d_temp_b, ta, 1e-7), "{}", r.d_temp_b);
    // In the gap the step is δ = ε^{1/3}·2e-3 ≈ 1.2e-8 while h ≈ 9e4, so round-off
    // bounds the error by about 2ε|h|/(2δ) ≈ 1.6e-3: allow twice that.
    let delta = f64::EPSILON.cbrt() * g;
    let bound = 2.0 * f64::EPSILON * r.value / delta;
    assert!(
        (r.d_gap + (-g).exp()).abs() < bound,
        "{} vs {} (bound {bound:e})",
        r.d_gap,
        -(-g).exp()
    );
}

// --- faults ----------------------------------------------------------------------------

fn load_err(path: &Path) -> String {
    match Plugin::load(path) {
        Ok(_) => panic!("{} loaded", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn load_faults_are_clear_errors_naming_the_plugin() {
    let missing = tmp().join("no/such/libplugin.so");
    let msg = load_err(&missing);
    assert!(
        msg.contains("does not exist") && msg.contains("libplugin.so"),
        "{msg}"
    );

    let text = tmp().join("plugins-c/not_a_library.so");
    std::fs::create_dir_all(text.parent().unwrap()).unwrap();
    std::fs::write(&text, "this is a text file, not ELF\n").unwrap();
    let msg = load_err(&text);
    assert!(
        msg.contains("could not be loaded as a shared library") && msg.contains("not_a_library.so"),
        "{msg}"
    );

    for (fault, needles) in [
        (
            "NO_ENTRY",
            &[
                "does not export the entry symbol `seam_plugin_v1`",
                "faulty_no_entry",
            ][..],
        ),
        (
            "V2_ONLY",
            &[
                "built for plugin ABI 2.0",
                "seam speaks ABI 1.0",
                "major versions must be equal",
            ],
        ),
        (
            "MAJOR",
            &["built for plugin ABI 2.0", "seam speaks ABI 1.0"],
        ),
        (
            "MINOR",
            &[
                "built for plugin ABI 1.99",
                "newer than this seam's ABI 1.0",
            ],
        ),
        ("SMALL", &["struct_size 16 bytes", "needs at least 72"]),
        ("NULL_EVALUATE", &["`evaluate_point` is NULL"]),
    ] {
        let path = faulty(fault);
        let msg = load_err(&path);
        assert!(
            msg.contains(&*path.display().to_string()),
            "{fault}: path missing in {msg}"
        );
        for n in needles {
            assert!(msg.contains(n), "{fault}: `{n}` missing in: {msg}");
        }
    }
    let err = Plugin::load_with(
        &c_plugins().table,
        &PluginData {
            model: Some("cmy".into()),
            ..data(&table_real(), &[])
        },
    )
    .unwrap_err();
    assert!(
        err.to_string()
            .contains("provides model `c_table`, but the deck asks for model `cmy`"),
        "{err}"
    );
}

#[test]
fn evaluation_faults_name_the_plugin_and_the_point_and_the_host_carries_on() {
    // Points 0..3 fine, point 3 triggers the fault (pressure >= 100).
    let points = [
        point(0.0, 1.0, 300.0, 300.0),
        point(0.0, 2.0, 300.0, 300.0),
        point(0.0, 3.0, 300.0, 300.0),
        point(0.0, 150.0, 300.0, 300.0),
    ];
    let cases: [(&str, &[&str]); 6] = [
        ("NAN", &["point 3", "value is NaN"]),
        ("NAN_DERIVATIVE", &["point 3", "dvalue/dgap is NaN"]),
        ("NEGATIVE", &["point 3", "conductance -2.5 is negative"]),
        (
            "ERROR",
            &[
                "point 3",
                "reported an error",
                "pressure 150 is beyond the measured range",
            ],
        ),
        (
            "CUTBACK",
            &[
                "point 3",
                "smaller time step (factor 0.25)",
                "coating creep increment too large",
            ],
        ),
        ("BAD_STATUS", &["point 3", "unknown status code 42"]),
    ];
    for (fault, needles) in cases {
        let plugin = Plugin::load(&faulty(fault)).unwrap();
        let err = eval(&plugin, &points).unwrap_err();
        let msg = err.to_string();
        assert!(
            msg.contains("`faulty`") && msg.contains(&format!("faulty_{}", fault.to_lowercase())),
            "{msg}"
        );
        for n in needles {
            assert!(msg.contains(n), "{fault}: `{n}` missing in: {msg}");
        }
        assert_eq!(err.point(), Some(3));
        assert_eq!(err.is_cutback(), fault == "CUTBACK", "{fault}");
        // The host is alive and the plugin still answers for good points.
        assert_eq!(eval(&plugin, &points[..3]).unwrap()[2].value, 1.0);
    }
    // The fault's exact content for the cutback request.
    let plugin = Plugin::load(&faulty("CUTBACK")).unwrap();
    match eval(&plugin, &points).unwrap_err() {
        PluginFault::Cutback { factor, point, .. } => assert_eq!((factor, point), (0.25, 3)),
        other => panic!("expected a cutback, got {other:?}"),
    }
}

#[test]
fn a_panic_in_a_rust_plugin_is_caught_and_reported() {
    let plugin = Plugin::load(&rust_plugins().panicky).unwrap();
    let err = eval(
        &plugin,
        &[point(0.0, 0.5, 300.0, 300.0), point(0.0, 5.0, 300.0, 300.0)],
    )
    .unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("point 1") && msg.contains("panic: deliberate panic at pressure 5"),
        "{msg}"
    );
    // Still alive, still usable.
    assert_eq!(
        eval(&plugin, &[point(0.0, 0.5, 300.0, 300.0)]).unwrap()[0].value,
        1.0
    );
}

// --- conformance kit and check-plugin --------------------------------------------------

#[test]
fn conformance_kit_passes_the_examples_and_fails_every_faulty_plugin() {
    let table = Config {
        real_data: table_real(),
        ..Config::default()
    };
    let report = seam_plugin_testkit::run(
        &seam_plugin_testkit::load(&c_plugins().table).unwrap(),
        &table,
    );
    assert!(report.passed(), "{report}");
    assert!(report.batch_checked && report.threads_checked && report.derivatives_checked == 216);
    let cmy = Config {
        real_data: CMY.to_vec(),
        ..Config::default()
    };
    let report = seam_plugin_testkit::run(
        &seam_plugin_testkit::load(&rust_plugins().cmy).unwrap(),
        &cmy,
    );
    assert!(report.passed(), "{report}");
    assert!(report.max_derivative_error < 1e-8, "{report}");
    for fault in [
        "NAN",
        "NAN_DERIVATIVE",
        "NEGATIVE",
        "ERROR",
        "CUTBACK",
        "BAD_STATUS",
    ] {
        let report = seam_plugin_testkit::run(
            &seam_plugin_testkit::load(&faulty(fault)).unwrap(),
            &Config::default(),
        );
        assert!(!report.passed(), "{fault} passed the kit:\n{report}");
    }
    let report = seam_plugin_testkit::run(
        &seam_plugin_testkit::load(&rust_plugins().panicky).unwrap(),
        &Config::default(),
    );
    assert!(
        !report.passed() && report.to_string().contains("deliberate panic"),
        "{report}"
    );
    for fault in ["MAJOR", "MINOR", "SMALL", "NULL_EVALUATE", "NO_ENTRY"] {
        assert!(
            seam_plugin_testkit::load(&faulty(fault)).is_err(),
            "{fault} loaded in the kit"
        );
    }
    // A derivative off by a factor 2 is caught (the host cannot see it; the kit must).
    let report = seam_plugin_testkit::run(
        &seam_plugin_testkit::load(&faulty("WRONG_DERIVATIVE")).unwrap(),
        &Config::default(),
    );
    assert!(
        !report.passed() && report.to_string().contains("d/dpressure = 2e-6"),
        "{report}"
    );
    // And the comparison's tolerance is real: at rtol 1e-14 round-off alone fails CMY.
    let strict = Config {
        rtol: 1e-14,
        grid: Grid {
            gaps: vec![1e-5],
            pressures: vec![3e6],
            temps_a: vec![500.0],
            temps_b: vec![400.0],
        },
        ..cmy
    };
    let report = seam_plugin_testkit::run(
        &seam_plugin_testkit::load(&rust_plugins().cmy).unwrap(),
        &strict,
    );
    assert!(
        !report.passed() && report.to_string().contains("finite differences give"),
        "{report}"
    );
}

#[test]
fn check_plugin_reports_pass_and_fault_with_exit_codes() {
    let mut out = Vec::new();
    let report = check_plugin(&rust_plugins().cmy, &CMY, &[], &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert_eq!(report.exit_code(), 0, "{text}");
    for n in [
        "model         cmy 1.0.0",
        "ABI           1.0",
        "THREAD_SAFE | PROVIDES_DERIVATIVES",
        "PASS",
    ] {
        assert!(text.contains(n), "`{n}` missing in:\n{text}");
    }
    let mut out = Vec::new();
    let report = check_plugin(&faulty("NEGATIVE"), &[], &[], &mut out).unwrap();
    let text = String::from_utf8(out).unwrap();
    assert_eq!(report.exit_code(), 3, "{text}");
    assert!(
        text.contains("conductance -2.5 is negative") && text.contains("FAIL"),
        "{text}"
    );
    let mut out = Vec::new();
    let report = check_plugin(&c_plugins().smooth, &[], &[], &mut out).unwrap();
    assert!(report.finite_difference_derivatives && report.passed());
    assert!(
        String::from_utf8(out)
            .unwrap()
            .contains("does not provide derivatives")
    );
    let err = check_plugin(&faulty("MAJOR"), &[], &[], &mut Vec::new()).unwrap_err();
    assert!(err.to_string().contains("ABI 2.0"), "{err}");
}

/// `seam check-plugin`: exit 0 and PASS for a good plugin with its data, 3 for a plugin
/// whose outputs are wrong and for one that cannot be loaded.
#[test]
fn check_plugin_command_exit_codes() {
    let seam = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(args)
            .output()
            .expect("seam runs")
    };
    let table = c_plugins().table.to_str().unwrap().to_string();
    let real: Vec<String> = table_real().iter().map(|v| v.to_string()).collect();
    let mut args = vec!["check-plugin", table.as_str(), "--real"];
    args.extend(real.iter().map(String::as_str));
    let out = seam(&args);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("PASS") && text.contains("c_table"), "{text}");

    let out = seam(&["check-plugin", faulty("NAN").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stdout).contains("NaN"));

    let out = seam(&["check-plugin", faulty("MAJOR").to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("ABI 2.0") && err.contains("ABI 1.0"), "{err}");
    // --json: the same findings as one object on stdout, the same exit codes.
    args.push("--json");
    let out = seam(&args);
    assert_eq!(out.status.code(), Some(0));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["passed"], true);
    assert_eq!(report["name"], "c_table");
    assert!(
        report["derivatives_checked"].as_u64().unwrap() > 0,
        "{report}"
    );
    let out = seam(&["check-plugin", faulty("NAN").to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(3));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["passed"], false);
    assert!(report["failure_count"].as_u64().unwrap() > 0, "{report}");
    let out = seam(&["check-plugin", faulty("MAJOR").to_str().unwrap(), "--json"]);
    assert_eq!(out.status.code(), Some(3));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["diagnostics"][0]["code"], "E0500", "{report}");
}

/// Run a two-block problem whose interface enforcement is `enforcement` (the lines
/// inside `begin enforcement`), with the bottom at `t_low` and the top at `t_high`.
fn run_with(enforcement: &str, t_low: f64, t_high: f64, tag: &str) -> Vec<f64> {
    let tmp = crate::scratch(&format!("plugin-run-{tag}"));
    let dir = tmp.path();
    let mesh = root().join("examples/two_blocks/two_blocks.exo");
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = {mesh:?}\n[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = {t_low}\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = {t_high}\n\
             [contact]\nfile = \"contact.i\"\n[solve]\nkind = \"steady\"\ntolerance = 1e-13\n",
            mesh = mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n contact surface lid_face contains lid_bottom\n contact surface base_face contains base_top\n\
             begin interaction\n side a base_face\n side b lid_face\n end\n begin enforcement\n{enforcement}\n end\nend\n"
        ),
    )
    .unwrap();
    match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => {
            assert!(r.summary.converged);
            r.solution.temperature
        }
        Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A plugin returning a constant h (the C table plugin with a flat table), and a Lua
/// expression `10`, give the temperatures of the built-in Contact_Resistance with h = 10
/// to round-off (1e-12: the parallel factorisation may sum in another order from run to
/// run, a few 1e-15 on temperatures of order 1); the Rust example plugin reduced to its radiation part (no gas, no
/// contact pressure) gives those of the built-in radiation model, a nonlinear case.
#[test]
fn plugin_and_lua_models_match_the_built_in_ones_in_a_run() {
    let table = c_plugins().table.to_str().unwrap().to_string();
    let builtin = run_with(
        "  enforcement for energy = contact_resistance h = 10",
        0.0,
        1.0,
        "builtin",
    );
    let plugin = run_with(
        &format!(
            "  enforcement for energy = plugin library = \"{table}\"\n  real data 0 10 1e6 10"
        ),
        0.0,
        1.0,
        "plugin",
    );
    let lua = run_with(
        "  enforcement for energy = contact_resistance\n  gap conductance coefficient = lua \"10\"",
        0.0,
        1.0,
        "lua",
    );
    assert!(
        max_diff(&builtin, &plugin) <= 1e-12,
        "{}",
        max_diff(&builtin, &plugin)
    );
    assert!(
        max_diff(&builtin, &lua) <= 1e-12,
        "{}",
        max_diff(&builtin, &lua)
    );

    let cmy = rust_plugins().cmy.to_str().unwrap().to_string();
    let radiation = run_with(
        "  enforcement for energy = contact_resistance\n  gap conductance coefficient = radiation emissivity_a = 0.8 emissivity_b = 0.6",
        300.0,
        1300.0,
        "radiation",
    );
    let plugin = run_with(
        &format!(
            "  enforcement for energy = plugin library = \"{cmy}\"\n  real data 16 0.1 1e-6 3e9 0 1e-6 0.8 0.6"
        ),
        300.0,
        1300.0,
        "cmy",
    );
    // Both solve the same nonlinear problem with exact derivatives to a 1e-13 residual.
    assert!(
        max_diff(&radiation, &plugin) <= 1e-9,
        "{}",
        max_diff(&radiation, &plugin)
    );
    // And the radiation conductance is not trivial: the interface jump is large.
    let spread = radiation.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
        - radiation.iter().cloned().fold(f64::INFINITY, f64::min);
    assert!(spread > 900.0);
}

/// Integer Data and Real Data written in a deck (with commas, `=`, and a Fortran
/// exponent) reach the plugin exactly: the echo plugin returns Σ real + Σ integer and
/// encodes the counts in dT_A (n_real + 1e3 n_integer).
#[test]
fn deck_data_arrives_at_the_plugin_as_written() {
    let echo = c_plugins().echo.clone();
    let deck = format!(
        "begin contact definition\n begin enforcement\n  enforcement for energy = plugin library = \"{}\"\n  integer data 1 2, 3\n  real data = 1.5, 2e3 1d2 -0.25\n end\nend\n",
        echo.file_name().unwrap().to_str().unwrap()
    );
    let (d, diags) = seam::deck::parse_sierra(&std::sync::Arc::from("deck.i"), &deck);
    assert!(!diags.has_errors(), "{diags:?}");
    let enf = &d.contact_definitions[0].enforcements[0];
    let spec = seam::scene::plugin::plugin_spec(enf, echo.parent().unwrap()).unwrap();
    assert_eq!(spec.data.integer_data, [1, 2, 3]);
    assert_eq!(spec.data.real_data, [1.5, 2000.0, 100.0, -0.25]);
    let plugin = spec.load().unwrap();
    let mut state = seam::plugin::StateStore::new(1, plugin.info().state_size);
    let mut r = vec![PointResult::default(); 1];
    plugin
        .evaluate(
            &ctx(),
            &[point(0.0, 0.0, 1.0, 2.0)],
            &mut r,
            Some(&mut state),
        )
        .unwrap();
    assert_eq!(r[0].value, 1.5 + 2000.0 + 100.0 - 0.25 + 6.0);
    assert_eq!(r[0].d_temp_a.rem_euclid(1e6), 4.0 + 3.0e3);
}

/// A plugin that returns NaN (the faulty test plugin does so at pressures ≥ 100, hence the
/// contact pressure) stops a run with an error naming the plugin, the interaction, the
/// face and the point; with `Quarantine Faulty Points` the run goes on,
/// the points carry no heat, and a warning reports them.
#[test]
fn faulty_plugin_in_a_run_stops_it_or_is_quarantined() {
    let nan = faulty("NAN").to_str().unwrap().to_string();
    let tmp = crate::scratch("plugin-run-faulty");
    let dir = tmp.path();
    let mesh = root().join("examples/two_blocks/two_blocks.exo");
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = {:?}\n[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 1\n[contact]\nfile = \"contact.i\"\n",
            mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    let deck = |extra: &str| {
        format!(
            "begin contact definition\n contact surface lid_face contains lid_bottom\n contact surface base_face contains base_top\n\
             begin interaction\n side a base_face\n side b lid_face\n end\n begin enforcement\n  enforcement for energy = plugin library = \"{nan}\"\n  contact pressure = 1000\n{extra} end\nend\n"
        )
    };
    std::fs::write(dir.join("contact.i"), deck("")).unwrap();
    match seam::run::run(&dir.join("problem.toml")) {
        Err(seam::run::RunError::Solve(e)) => {
            for needle in [
                "faulty",
                "base_face / lid_face",
                "side-A face (element",
                "at point (",
                "NaN",
            ] {
                assert!(e.contains(needle), "`{needle}` missing from: {e}");
            }
        }
        Ok(_) => panic!("a NaN plugin must stop the run"),
        Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
    }
    std::fs::write(dir.join("contact.i"), deck("  quarantine faulty points\n")).unwrap();
    let r = match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => r,
        Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
        Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
    };
    assert!(
        r.warnings.0.iter().any(|d| d.code == "W0501"),
        "{:?}",
        r.warnings
    );
    assert_eq!(
        r.summary.interactions[0].heat_side_a, 0.0,
        "quarantined points carry no heat"
    );
}

/// The TOML twin of the plugin enforcement gives the same plugin spec as the Sierra line.
#[test]
fn plugin_enforcement_in_toml_matches_the_sierra_line() {
    let sierra = "begin contact definition\n begin enforcement\n  enforcement for energy = plugin library = \"lib/libModel.so\" model = table\n  integer data 4 5\n  real data 0.5 2\n end\nend\n";
    let toml = r#"
[[contact_definition]]
[[contact_definition.enforcement]]
integer_data = [4, 5]
real_data = [0.5, 2.0]
model = [{ equation = "energy", model = "plugin", args = [{ key = "library", value = "lib/libModel.so" }, { key = "model", value = "table" }] }]
"#;
    let (a, da) = seam::deck::parse_sierra(&std::sync::Arc::from("d.i"), sierra);
    let (b, db) = seam::deck::parse_toml(&std::sync::Arc::from("d.toml"), toml);
    assert!(!da.has_errors() && !db.has_errors(), "{da:?} {db:?}");
    let dir = std::path::Path::new("/decks");
    let sa =
        seam::scene::plugin::plugin_spec(&a.contact_definitions[0].enforcements[0], dir).unwrap();
    let sb =
        seam::scene::plugin::plugin_spec(&b.contact_definitions[0].enforcements[0], dir).unwrap();
    assert_eq!(sa, sb);
    assert_eq!(sa.path, dir.join("lib/libModel.so"));
}

/// A plugin without derivatives works in a run, and the log says once that seam forms
/// them by finite differences.
#[test]
fn plugin_without_derivatives_in_a_run_is_noted_once() {
    let smooth = c_plugins().smooth.to_str().unwrap().to_string();
    let tmp = crate::scratch("plugin-run-smooth");
    let dir = tmp.path();
    let mesh = root().join("examples/two_blocks/two_blocks.exo");
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = {:?}\n[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400\n[contact]\nfile = \"contact.i\"\n",
            mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n contact surface lid_face contains lid_bottom\n contact surface base_face contains base_top\n\
             begin interaction\n side a base_face\n side b lid_face\n end\n begin enforcement\n  enforcement for energy = plugin library = \"{smooth}\"\n end\nend\n"
        ),
    )
    .unwrap();
    let r = match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => r,
        Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
        Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
    };
    assert!(r.summary.converged);
    let notes = r.warnings.0.iter().filter(|d| d.code == "W0502").count();
    assert_eq!(notes, 1, "{:?}", r.warnings);
}

/// A plugin that crashes (a null pointer) or ends the process (`exit(0)`, as a Fortran
/// `STOP` does) inside a call cannot be survived in-process, but it is reported — the
/// library, the entry point, the interaction and the point — and the exit code is 3,
/// in `seam run` and in `seam check-plugin`.
#[test]
fn plugin_that_kills_the_process_is_reported_with_exit_code_3() {
    for (fault, what) in [("SEGFAULT", "SIGSEGV"), ("EXIT", "exit")] {
        let lib = cc_shared(
            "plugins/tests/faulty/faulty.c",
            &[&format!("-DFAULT_{fault}")],
            &format!("faulty_{}", fault.to_lowercase()),
        );
        let dir = kill_problem(&lib, &format!("in-process-{}", fault.to_lowercase()), "");
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(["run", "problem.toml"])
            .current_dir(&dir)
            .output()
            .expect("seam runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{fault}: {err}");
        for needle in [
            "error[E0503]: plugin `faulty`",
            what,
            "evaluate_",
            "on interaction base_face / lid_face",
        ] {
            assert!(err.contains(needle), "{fault}: no `{needle}` in\n{err}");
        }
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(["check-plugin", lib.to_str().unwrap()])
            .output()
            .expect("seam runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{fault}: check-plugin: {err}");
        assert!(err.contains("E0503") && err.contains(what), "{err}");
    }
}

// --- isolation: the plugin in a worker process --------------------------------------------

/// The worker for in-process library calls: this test binary is not `seam`.
fn isolated(path: &Path, data: &PluginData) -> Result<Plugin, PluginError> {
    seam::plugin::set_worker_program(env!("CARGO_BIN_EXE_seam"));
    Plugin::load_isolated(path, data)
}

fn bits(r: &[PointResult]) -> Vec<[u64; 5]> {
    r.iter()
        .map(|r| [r.value, r.d_temp_a, r.d_temp_b, r.d_gap, r.d_pressure].map(f64::to_bits))
        .collect()
}

/// In a worker process the C table plugin (batch entry, exact derivatives), the smooth
/// plugin (derivatives by finite differences, 9 calls a point) and the echo plugin (state
/// and data) give the in-process results to the last bit, over more than one chunk of
/// 256 points, batched and point by point; the state a stateful plugin writes comes back.
#[test]
fn isolated_plugins_give_the_in_process_results_to_the_last_bit() {
    let c = c_plugins();
    let points: Vec<_> = (0..600)
        .map(|i| {
            point(
                1e-7 * i as f64,
                1.7e4 * i as f64,
                300.0 + 0.5 * i as f64,
                410.0,
            )
        })
        .collect();
    let cases = [
        (&c.table, data(&table_real(), &[])),
        (&c.smooth, data(&[], &[])),
        (&c.echo, data(&[1.5, -2.0], &[3, 4])),
    ];
    for (path, d) in cases {
        let here = Plugin::load_with(path, &d).unwrap();
        let there = isolated(path, &d).unwrap();
        assert_eq!(here.info(), there.info());
        assert_eq!(there.isolation(), seam::plugin::Isolation::Process);
        assert!(there.descriptor().is_none());
        let ns = here.info().state_size;
        let run = |p: &Plugin, per_point: bool| {
            let mut r = vec![PointResult::default(); points.len()];
            let mut s = StateStore::new(points.len(), ns);
            if per_point {
                p.evaluate_per_point(&ctx(), &points, &mut r, Some(&mut s))
            } else {
                p.evaluate(&ctx(), &points, &mut r, Some(&mut s))
            }
            .unwrap();
            s.commit();
            (bits(&r), s)
        };
        for per_point in [false, true] {
            let (a, sa) = run(&here, per_point);
            let (b, sb) = run(&there, per_point);
            assert!(a == b, "{}: results differ", path.display());
            assert_eq!(sa, sb, "{}: states differ", path.display());
        }
    }
}

/// A worker that crashes (SIGSEGV) or calls `exit(0)` at the points with pressure ≥ 100
/// is an ordinary fault naming the plugin, the interaction, the point and how the worker
/// died; the host is alive, and the next call is served by a new worker. (The faulty
/// plugin has no batch entry: the worker calls it point by point and knows the point; a
/// batch entry's crash names the points of the call.)
#[test]
fn a_crashing_isolated_plugin_is_an_ordinary_fault_and_the_host_goes_on() {
    for (fault, how) in [
        ("SEGFAULT", "killed by SIGSEGV"),
        ("EXIT", "ended with exit status 0"),
    ] {
        let lib = cc_shared(
            "plugins/tests/faulty/faulty.c",
            &[&format!("-DFAULT_{fault}")],
            &format!("faulty_{}", fault.to_lowercase()),
        );
        let plugin = isolated(&lib, &data(&[], &[])).unwrap();
        let mut points: Vec<_> = (0..300).map(|_| point(0.0, 1.0, 300.0, 300.0)).collect();
        points[280].pressure = 150.0;
        let mut r = vec![PointResult::default(); points.len()];
        let err = plugin
            .evaluate(&ctx(), &points, &mut r, None)
            .expect_err("the worker dies");
        let msg = err.to_string();
        for needle in [
            "`faulty`",
            &format!("faulty_{}", fault.to_lowercase()),
            "point 280 on interaction block_1_top / block_2_bottom",
            "on interaction block_1_top / block_2_bottom",
            "isolated plugin process",
            how,
            "evaluate_point",
            "a new process serves the next call",
        ] {
            assert!(msg.contains(needle), "{fault}: no `{needle}` in {msg}");
        }
        assert!(
            matches!(err, PluginFault::ProcessDied { ref points, .. } if *points == (280..281)),
            "{err:?}"
        );
        assert_eq!(err.point(), Some(280));
        // The first chunk was served before the death; a new worker serves the next call.
        assert_eq!(r[0].value, 1.0);
        let good = eval(&plugin, &points[..10]).unwrap();
        assert!(good.iter().all(|r| r.value == 1.0));
        // The point is counted in the caller's call.
        let err = plugin
            .evaluate_per_point(&ctx(), &points[275..285], &mut r[..10], None)
            .unwrap_err();
        assert!(err.to_string().contains("point 5 on"), "{err}");
        let err = plugin
            .evaluate(&ctx(), &points[280..281], &mut r[..1], None)
            .unwrap_err();
        assert!(err.to_string().contains("point 0 on interaction"), "{err}");
    }
}

/// Load errors met in the worker are the in-process messages, word for word; a worker
/// executable that does not speak the protocol is a clear error.
#[test]
fn isolated_load_errors_are_the_in_process_ones() {
    for fault in ["MAJOR", "NO_ENTRY", "NULL_EVALUATE"] {
        let here = load_err(&faulty(fault));
        let there = match isolated(&faulty(fault), &data(&[], &[])) {
            Ok(_) => panic!("{fault} loaded in the worker"),
            Err(e) => e.to_string(),
        };
        assert_eq!(here, there);
    }
    let missing = tmp().join("no-such-plugin.so");
    let err = isolated(&missing, &data(&[], &[])).unwrap_err();
    assert!(matches!(err, PluginError::NotFound { .. }), "{err}");
}

/// Write the two-block problem whose enforcement uses `lib` at contact pressure 1000
/// plus `extra` lines (e.g. `plugin isolation = process`) into a scratch folder; that
/// folder.
const ISOLATED: &str = "  plugin isolation = process\n";

fn kill_problem(lib: &Path, tag: &str, extra: &str) -> TempDir {
    let mesh = root().join("examples/two_blocks/two_blocks.exo");
    let tmp = crate::scratch(&format!("plugin-run-isolated-{tag}"));
    let dir = tmp.path();
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = {:?}\n[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 1\n[contact]\nfile = \"contact.i\"\n[output]\ndir = \"out\"\n",
            mesh.to_str().unwrap()
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("contact.i"),
        format!(
            "begin contact definition\n contact surface lid_face contains lid_bottom\n contact surface base_face contains base_top\n\
             begin interaction\n side a base_face\n side b lid_face\n end\n begin enforcement\n  enforcement for energy = plugin library = \"{}\"\n  contact pressure = 1000\n{extra} end\nend\n",
            lib.display()
        ),
    )
    .unwrap();
    tmp
}

/// A plugin that returns a value that is not a number during `seam run` is a plugin
/// fault: the message names the plugin and the point, and the exit code is 3 (as for a
/// crash), in text and in `--json` mode.
#[test]
fn plugin_fault_during_a_run_exits_with_3() {
    let lib = cc_shared(
        "plugins/tests/faulty/faulty.c",
        &["-DFAULT_NAN"],
        "faulty_nan_run",
    );
    let dir = kill_problem(&lib, "nan-run", "");
    for json in [false, true] {
        let mut args = vec!["run", "problem.toml"];
        if json {
            args.push("--json");
        }
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(&args)
            .current_dir(&dir)
            .output()
            .expect("seam runs");
        let text = if json { &out.stdout } else { &out.stderr };
        let text = String::from_utf8_lossy(text);
        assert_eq!(out.status.code(), Some(3), "{text}");
        assert!(
            text.contains("plugin fault") && text.contains("NaN"),
            "{text}"
        );
    }
}

/// `Plugin Isolation = Process` in `seam run`: a plugin that segfaults or calls `exit(0)`
/// stops the run with an ordinary error naming the plugin, the interaction, the point and
/// how its worker died, exit code 3; with `Quarantine Faulty Points` the run completes
/// and reports the points. `seam check-plugin --isolate` gives a FAILED report, exit 3.
#[test]
fn isolated_plugin_that_kills_its_process_stops_the_run_or_is_quarantined() {
    for (fault, how) in [
        ("SEGFAULT", "killed by SIGSEGV"),
        ("EXIT", "ended with exit status 0"),
    ] {
        let lib = cc_shared(
            "plugins/tests/faulty/faulty.c",
            &[&format!("-DFAULT_{fault}")],
            &format!("faulty_{}", fault.to_lowercase()),
        );
        let tag = fault.to_lowercase();
        let dir = kill_problem(&lib, &tag, ISOLATED);
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(["run", "problem.toml"])
            .current_dir(&dir)
            .output()
            .expect("seam runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{fault}: {err}");
        for needle in [
            "error[E0800]",
            "plugin `faulty`",
            "interaction base_face / lid_face",
            "at (gap",
            "isolated plugin process",
            how,
            "Quarantine Faulty Points",
        ] {
            assert!(err.contains(needle), "{fault}: no `{needle}` in\n{err}");
        }
        assert!(!err.contains("E0503"), "not the in-process report: {err}");

        let dir = kill_problem(
            &lib,
            &format!("{tag}-quarantine"),
            &format!("{ISOLATED}  quarantine faulty points\n"),
        );
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(["run", "problem.toml"])
            .current_dir(&dir)
            .output()
            .expect("seam runs");
        let err = String::from_utf8_lossy(&out.stderr);
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(0), "{fault}: {text}\n{err}");
        for needle in ["W0501", "quarantined", how] {
            assert!(err.contains(needle), "{fault}: no `{needle}` in\n{err}");
        }
        assert!(text.contains("heat out of A 0.0"), "{text}");

        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(["check-plugin", "--isolate", lib.to_str().unwrap()])
            .output()
            .expect("seam runs");
        let text = String::from_utf8_lossy(&out.stdout);
        assert_eq!(out.status.code(), Some(3), "{fault}: {text}");
        for needle in [
            "isolation     a worker process",
            "the conformance checks",
            how,
            "FAIL",
            "host validation FAILED",
        ] {
            assert!(text.contains(needle), "{fault}: no `{needle}` in\n{text}");
        }
    }
    // A good plugin passes the isolated check.
    let table = c_plugins().table.to_str().unwrap().to_string();
    let mut args = vec![
        "check-plugin".to_string(),
        "--isolate".into(),
        table,
        "--real".into(),
    ];
    args.extend(table_real().iter().map(|v| v.to_string()));
    let out = Command::new(env!("CARGO_BIN_EXE_seam"))
        .args(&args)
        .output()
        .expect("seam runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("PASS"), "{text}");
}

/// The C table plugin (linear problem) and the Rust CMY plugin with radiation (nonlinear,
/// several Newton iterations) give the same temperatures in a run in a worker process as
/// in seam's own process. Both modes see bit-identical conductances (the tests above);
/// the solve itself may add in another order from run to run (the parallel
/// factorisation), so the temperatures are compared with what two in-process runs meet:
/// bit for bit when those agree to the bit.
#[test]
fn isolated_plugin_in_a_run_gives_the_in_process_temperatures() {
    seam::plugin::set_worker_program(env!("CARGO_BIN_EXE_seam"));
    let table = c_plugins().table.to_str().unwrap().to_string();
    let real = table_real()
        .iter()
        .map(|v| format!("{v:e}"))
        .collect::<Vec<_>>()
        .join(" ");
    let cmy = rust_plugins().cmy.to_str().unwrap().to_string();
    for (tag, line) in [
        (
            "table",
            format!(
                "  enforcement for energy = plugin library = \"{table}\"\n  contact pressure = 2e5\n  real data {real}"
            ),
        ),
        (
            "cmy",
            format!(
                "  enforcement for energy = plugin library = \"{cmy}\"\n  real data 16 0.1 1e-6 3e9 0 1e-6 0.8 0.6"
            ),
        ),
    ] {
        let a = run_with(&line, 300.0, 1300.0, &format!("iso-{tag}-none"));
        let b = run_with(
            &format!("{line}\n  plugin isolation = process"),
            300.0,
            1300.0,
            &format!("iso-{tag}-process"),
        );
        let again = run_with(&line, 300.0, 1300.0, &format!("iso-{tag}-none-again"));
        let floor = max_diff(&a, &again);
        assert!(
            max_diff(&a, &b) <= floor.max(1e-12),
            "{tag}: {} (floor {floor:e})",
            max_diff(&a, &b)
        );
        if floor == 0.0 {
            assert!(
                a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "{tag}: a deterministic solve gives bit-identical temperatures"
            );
        }
    }
}

/// `Plugin Isolation = Process` in Sierra and `plugin_isolation = "process"` in TOML give
/// the same plugin spec; the default is in process; a misspelt choice is an error with a
/// did-you-mean.
#[test]
fn plugin_isolation_line_in_sierra_and_toml() {
    let sierra = |extra: &str| {
        format!(
            "begin contact definition\n begin enforcement\n  enforcement for energy = plugin library = \"lib/m.so\"\n{extra} end\nend\n"
        )
    };
    let toml = |extra: &str| {
        format!(
            "[[contact_definition]]\n[[contact_definition.enforcement]]\n{extra}model = [{{ equation = \"energy\", model = \"plugin\", args = [{{ key = \"library\", value = \"lib/m.so\" }}] }}]\n"
        )
    };
    let file = std::sync::Arc::from("d");
    let spec = |d: &seam::deck::spec::Deck| {
        seam::scene::plugin::plugin_spec(
            &d.contact_definitions[0].enforcements[0],
            Path::new("/decks"),
        )
        .unwrap()
    };
    for (line, key, isolation) in [
        ("", "", seam::plugin::Isolation::None),
        (
            "  Plugin Isolation = Process\n",
            "plugin_isolation = \"process\"\n",
            seam::plugin::Isolation::Process,
        ),
        (
            "  plugin isolation none\n",
            "plugin_isolation = \"none\"\n",
            seam::plugin::Isolation::None,
        ),
    ] {
        let (a, da) = seam::deck::parse_sierra(&file, &sierra(line));
        let (b, db) = seam::deck::parse_toml(&file, &toml(key));
        assert!(!da.has_errors() && !db.has_errors(), "{da:?} {db:?}");
        assert_eq!(spec(&a), spec(&b));
        assert_eq!(spec(&a).isolation, isolation, "{line}");
    }
    let (_, d) = seam::deck::parse_sierra(&file, &sierra("  plugin isolation = proces\n"));
    let e = d.errors().next().expect("a bad choice is an error");
    assert_eq!(e.code, "E0217");
    let text = format!("{e:?}");
    assert!(text.contains("did you mean `process`"), "{text}");
}

/// A worker that cannot be found, or a program that is not a worker, is a clear load
/// error naming the plugin and what was tried (`SEAM_PLUGIN_WORKER` overrides the
/// lookup), and `seam check-plugin --isolate` exits 3 with it.
#[test]
fn a_missing_or_wrong_plugin_worker_is_a_clear_error() {
    let table = c_plugins().table.to_str().unwrap().to_string();
    for (worker, needle) in [
        (
            "/nonexistent/seam",
            "SEAM_PLUGIN_WORKER=/nonexistent/seam: no such file",
        ),
        (
            "/bin/false",
            "is not a seam plugin worker (no greeting): it ended with exit status 1",
        ),
    ] {
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .args(["check-plugin", "--isolate", &table])
            .env("SEAM_PLUGIN_WORKER", worker)
            .output()
            .expect("seam runs");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{err}");
        assert!(err.contains("error[E0500]: plugin"), "{err}");
        assert!(err.contains("seam_c_table"), "{err}");
        assert!(err.contains(needle), "{worker}: no `{needle}` in {err}");
    }
}

/// The faults a plugin reports or seam's checks find (NaN, negative, an error with its
/// message, a cutback with its factor, an unknown status) are the same, field for field,
/// when the plugin runs in a worker, and the worker goes on serving.
#[test]
fn isolated_plugin_faults_are_the_in_process_ones() {
    let points = [
        point(0.0, 1.0, 300.0, 300.0),
        point(0.0, 2.0, 300.0, 300.0),
        point(0.0, 150.0, 300.0, 300.0),
    ];
    for fault in [
        "NAN",
        "NAN_DERIVATIVE",
        "NEGATIVE",
        "ERROR",
        "CUTBACK",
        "BAD_STATUS",
    ] {
        let here = Plugin::load(&faulty(fault)).unwrap();
        let there = isolated(&faulty(fault), &data(&[], &[])).unwrap();
        let a = eval(&here, &points).unwrap_err();
        let b = eval(&there, &points).unwrap_err();
        // (Debug, not ==: a NaN value is not equal to itself.)
        assert_eq!(format!("{a:?}"), format!("{b:?}"), "{fault}");
        assert_eq!(a.point(), Some(2));
        assert_eq!(eval(&there, &points[..2]).unwrap()[1].value, 1.0);
    }
}

/// The interface heat through a plugin conductance (the C table plugin with a flat
/// table h) is exact for every finite h from 0 to 1e300 and 1e8 contrasts, as the
/// built-in models are (see `hard_cases`).
#[test]
fn plugin_conductance_heat_is_exact_for_every_finite_h() {
    let table = c_plugins().table.to_str().unwrap().to_string();
    let worst = crate::hard_cases::sweep(
        "plugin",
        &format!("  enforcement for energy = plugin library = \"{table}\"\n  real data 0 H 1e6 H"),
        &crate::hard_cases::H_SWEEP,
    );
    assert!(worst <= 1e-9, "worst relative error {worst:e}");
}
