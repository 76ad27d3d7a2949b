//! Plugins in Fortran: the module `seam_plugin` (plugins/include/seam_plugin.f90) against
//! the C header, and the example plugin fortran_table (plugins/examples/fortran_table)
//! built with `$FC` (default `gfortran`), loaded, probed and run in a scene beside the C
//! table plugin.
//!
//! Everything is compiled once per test process into `$CARGO_TARGET_TMPDIR/plugins-fortran/`
//! with `-std=f2008 -Wall -Wextra -Werror`, the flags CI holds C plugins to.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use seam::plugin::{Plugin, check_plugin};

use crate::plugin::{TABLE, data, eval, point, table_real};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn dir() -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("plugins-fortran");
    std::fs::create_dir_all(&dir).expect("create plugins-fortran");
    dir
}

/// Compile `sources` (under the repository's root) with `compiler` and `flags` into
/// `out`; a Fortran compile (`modules`: a tag) writes its module files into a scratch
/// folder of its own, so builds do not meet.
fn compile(compiler: &str, flags: &[&str], sources: &[&str], out: &Path, modules: Option<&str>) {
    let mut cmd = Command::new(compiler);
    cmd.args(flags);
    let modules = modules.map(|tag| crate::scratch(&format!("fortran-mod-{tag}")));
    if let Some(m) = &modules {
        cmd.arg("-J").arg(m.path());
    }
    let status = cmd
        .arg("-I")
        .arg(root().join("plugins/include"))
        .args(sources.iter().map(|s| root().join(s)))
        .arg("-o")
        .arg(out)
        .status()
        .unwrap_or_else(|e| {
            panic!("cannot run `{compiler}` (gfortran: apt-get install gfortran): {e}")
        });
    assert!(status.success(), "`{compiler}` failed on {sources:?}");
}

/// A file name no other compile of this test process uses at the same time (tests build
/// the same plugin concurrently: one for its own checks, one for a scene).
fn unique() -> String {
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    format!("{}-{call}", std::process::id())
}

fn fortran() -> String {
    std::env::var("FC").unwrap_or_else(|_| "gfortran".into())
}

const FORTRAN_FLAGS: [&str; 4] = ["-std=f2008", "-Wall", "-Wextra", "-Werror"];
const MODULE: &str = "plugins/include/seam_plugin.f90";
pub(crate) const FORTRAN_LIBRARY: &str = "libseam_fortran_table.so";

/// Build the Fortran example plugin into `dir`; returns its path.
pub(crate) fn compile_fortran_table(dir: &Path) -> PathBuf {
    let out = dir.join(FORTRAN_LIBRARY);
    let partial = dir.join(format!("{FORTRAN_LIBRARY}.{}.partial", unique()));
    let flags: Vec<&str> = FORTRAN_FLAGS
        .iter()
        .copied()
        .chain(["-O2", "-shared", "-fPIC"])
        .collect();
    let sources = [MODULE, "plugins/examples/fortran_table/fortran_table.f90"];
    compile(&fortran(), &flags, &sources, &partial, Some("table"));
    std::fs::rename(&partial, &out).expect("move the compiled plugin into place");
    out
}

fn fortran_table() -> &'static Path {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| compile_fortran_table(&dir()))
}

fn c_table() -> &'static Path {
    static BUILT: OnceLock<PathBuf> = OnceLock::new();
    BUILT.get_or_init(|| {
        let dir = dir().join("c");
        std::fs::create_dir_all(&dir).unwrap();
        crate::examples::compile_c_table(&dir)
    })
}

/// The output of one of the layout programs.
fn run(program: &Path) -> String {
    let out = Command::new(program)
        .output()
        .expect("run the layout program");
    assert!(out.status.success(), "{} failed", program.display());
    String::from_utf8(out.stdout).unwrap()
}

/// Every struct size, field offset and constant the Fortran module declares equals the
/// C header's: the same lines printed by a C and a Fortran program.
#[test]
fn fortran_module_matches_the_c_header() {
    let c = dir().join("abi_layout_c");
    let f = dir().join("abi_layout_f");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    compile(
        &cc,
        &["-std=c99", "-Wall", "-Wextra", "-Werror"],
        &["plugins/tests/fortran/abi_layout.c"],
        &c,
        None,
    );
    compile(
        &fortran(),
        &FORTRAN_FLAGS,
        &[MODULE, "plugins/tests/fortran/abi_layout.f90"],
        &f,
        Some("layout"),
    );
    let (from_c, from_fortran) = (run(&c), run(&f));
    assert_eq!(
        from_c, from_fortran,
        "the Fortran module and seam_plugin.h differ"
    );
    // The C sizes are the ones the Rust ABI is checked against (plugin.rs).
    for line in [
        "SeamInstanceIn size 48",
        "SeamPointIn size 240",
        "SeamPointOut size 312",
        "SeamPluginDescriptor size 72",
        "SEAM_CAP_ALL 15",
    ] {
        assert!(from_c.lines().any(|l| l == line), "`{line}` in\n{from_c}");
    }
    assert_eq!(from_c.lines().count(), 68, "{from_c}");
}

/// h(x) and dh/dx of the C table tests' TABLE read as (x, h) pairs: linear between the
/// points, flat outside; written apart from the plugin.
fn table(x: f64) -> (f64, f64) {
    let last = TABLE.len() - 1;
    if x < TABLE[0].0 {
        return (TABLE[0].1, 0.0);
    }
    if x >= TABLE[last].0 {
        return (TABLE[last].1, 0.0);
    }
    let k = TABLE.iter().rposition(|t| t.0 <= x).unwrap();
    let ((x0, h0), (x1, h1)) = (TABLE[k], TABLE[k + 1]);
    let slope = (h1 - h0) / (x1 - x0);
    (h0 + slope * (x - x0), slope)
}

#[test]
fn fortran_table_reproduces_its_table_in_each_variable_with_exact_derivatives() {
    let xs = [-5.0, 0.0, 2.5e5, 1e6, 2e6, 3.999e6, 4e6, 7e6, 1e7, 2e7];
    for variable in 1..=3 {
        let plugin = Plugin::load_with(fortran_table(), &data(&table_real(), &[variable])).unwrap();
        assert_eq!(plugin.info().name, "fortran_table");
        let points: Vec<_> = xs
            .iter()
            .map(|&x| match variable {
                1 => point(1e-6, x, 300.0, 400.0),
                2 => point(1e-6, 0.0, x - 50.0, x + 50.0),
                _ => point(x, 0.0, 300.0, 400.0),
            })
            .collect();
        let r = eval(&plugin, &points).unwrap();
        for (x, o) in xs.iter().zip(&r) {
            let (h, slope) = table(*x);
            assert!(
                (o.value - h).abs() <= 1e-12 * h,
                "v{variable}: h({x}) = {}",
                o.value
            );
            let (dp, dt, dg) = match variable {
                1 => (slope, 0.0, 0.0),
                2 => (0.0, 0.5 * slope, 0.0),
                _ => (0.0, 0.0, slope),
            };
            let tol = 1e-12 * slope.abs().max(1e-9);
            assert!(
                (o.d_pressure - dp).abs() <= tol,
                "v{variable}: dh/dp at {x}"
            );
            assert!(
                (o.d_temp_a - dt).abs() <= tol,
                "v{variable}: dh/dT_A at {x}"
            );
            assert!(
                (o.d_temp_b - dt).abs() <= tol,
                "v{variable}: dh/dT_B at {x}"
            );
            assert!((o.d_gap - dg).abs() <= tol, "v{variable}: dh/dgap at {x}");
        }
    }
}

/// In pressure it is the C example to the last bit.
#[test]
fn fortran_table_in_pressure_equals_the_c_table() {
    let f = Plugin::load_with(fortran_table(), &data(&table_real(), &[1])).unwrap();
    let c = Plugin::load_with(c_table(), &data(&table_real(), &[])).unwrap();
    let points: Vec<_> = (0..200)
        .map(|k| point(1e-6, -1e5 + 6e4 * k as f64, 300.0, 400.0))
        .collect();
    let (rf, rc) = (eval(&f, &points).unwrap(), eval(&c, &points).unwrap());
    for (a, b) in rf.iter().zip(&rc) {
        assert_eq!((a.value, a.d_pressure), (b.value, b.d_pressure));
    }
}

#[test]
fn fortran_table_passes_check_plugin_and_refuses_bad_data_with_its_message() {
    for variable in 1..=3 {
        let mut out = Vec::new();
        let report = check_plugin(fortran_table(), &table_real(), &[variable], &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(report.exit_code(), 0, "{text}");
        for n in [
            "model         fortran_table 1.0.0",
            "THREAD_SAFE | PROVIDES_DERIVATIVES",
            "entry points  evaluate_point, evaluate_batch",
            "PASS",
        ] {
            assert!(text.contains(n), "`{n}` missing in:\n{text}");
        }
    }
    for (real, integer, says) in [
        (table_real(), vec![], "needs one Integer Data value"),
        (table_real(), vec![7], "Integer Data 7 is no variable"),
        (
            vec![0.0, 1.0, 2.0],
            vec![1],
            "pairs x0 h0 x1 h1 ..., got 3 values",
        ),
        (
            vec![1.0, 1.0, 0.0, 2.0],
            vec![1],
            "x must increase strictly (pair 1",
        ),
        (vec![0.0, -1.0], vec![1], "conductance of pair 0 is -1"),
    ] {
        let err = Plugin::load_with(fortran_table(), &data(&real, &integer))
            .err()
            .unwrap_or_else(|| panic!("{real:?} {integer:?} accepted"))
            .to_string();
        assert!(err.contains(says), "{err}");
    }
}

/// The plugin-conductance scene (two plates, h from a pressure table at 2 MPa) run by
/// `seam run` with the C table plugin and with the Fortran one reading the same table:
/// the same interface heat (the plugins give the same h to the bit; 1e-12 leaves room
/// for nothing but round-off in the solve).
#[test]
fn fortran_table_carries_the_heat_of_the_c_table_in_a_run() {
    let scene = root().join("examples/plugin_conductance");
    let tmp = crate::examples::copy_scene_as("plugin_conductance", "fortran-plugin");
    let deck_dir = tmp.path();
    crate::examples::compile_c_table(deck_dir);
    compile_fortran_table(deck_dir);
    let c = crate::embed::run_scene(&scene, deck_dir, "problem.toml");
    let deck = std::fs::read_to_string(deck_dir.join("contact.i")).unwrap();
    let fortran_deck = deck
        .replace(
            "library = \"libseam_c_table.so\" model = c_table",
            &format!("library = \"{FORTRAN_LIBRARY}\" model = fortran_table"),
        )
        .replace("    real data =", "    integer data = 1\n    real data =");
    assert_ne!(deck, fortran_deck);
    std::fs::write(deck_dir.join("contact.i"), fortran_deck).unwrap();
    let f = crate::embed::run_scene(&scene, deck_dir, "problem.toml");
    let (qc, qf) = (
        c.summary.interactions[0].heat_side_a,
        f.summary.interactions[0].heat_side_a,
    );
    println!("plugin conductance: C table {qc:.15e} W, Fortran table {qf:.15e} W");
    assert!(qc > 0.0);
    assert!((qf - qc).abs() <= 1e-12 * qc.abs(), "{qf} vs {qc}");
}
