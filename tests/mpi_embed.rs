//! The embedding on MPI (`seam::embed::RankEmbedding`, `seam_rank_*` in `seam.h`): the C
//! host on PETSc (`examples/c_host/mpi_petsc.c`) under `mpirun -n 1, 2, 3, 4` against
//! the same problem through the serial embedding, and both against the 1-D answer
//! (needs OpenMPI and Debian's petsc-dev); run by `.ci/run`: `cargo test --features mpi
//! --test mpi_embed`.

#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::Command;

/// Largest difference allowed, relative to the largest |value|: the serial path solves
/// by dense Gaussian elimination, the distributed one by MUMPS LU over an MPIAIJ matrix
/// whose entries were summed in another order, which on 172 unknowns leaves round-off of
/// 1e-14–1e-13 relative; 1e-9 keeps orders of margin and still fails a rank's terms
/// dropped or counted twice (they move T by kelvins).
const REL: f64 = 1e-9;

/// The host's problem (mpi_petsc.c): k_a = 2 and k_b = 5 W/m/K over unit lengths,
/// h = 50 W/m²/K, 400 K at x = 0 and 300 K at x = 2, a unit cross-section.
const KA: f64 = 2.0;
const KB: f64 = 5.0;
const H: f64 = 50.0;
const T_LEFT: f64 = 400.0;
const T_RIGHT: f64 = 300.0;

/// What the host prints on rank 0.
struct Printed {
    ranks: usize,
    across: usize,
    heat: [f64; 2],
    x: Vec<f64>,
    temperature: Vec<f64>,
}

/// The folder of `libseam.so` this test binary was built with.
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    [deps, deps.parent().unwrap()]
        .into_iter()
        .find(|d| d.join("libseam.so").exists())
        .unwrap_or_else(|| panic!("libseam.so is in neither {} nor its parent", deps.display()))
        .to_path_buf()
}

/// `mpicc` with the CI's warning flags, against PETSc (pkg-config) and libseam.
fn build_host(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = library_dir();
    let pkg = |what: &str| -> Vec<String> {
        let out = Command::new("pkg-config")
            .args([what, "PETSc"])
            .output()
            .expect("pkg-config (petsc-dev)");
        assert!(out.status.success(), "pkg-config {what} PETSc failed");
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .map(String::from)
            .collect()
    };
    let host = dir.join("mpi_petsc");
    let build = Command::new("mpicc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2"])
        .args(pkg("--cflags"))
        .arg("-I")
        .arg(root.join("include"))
        .arg(root.join("examples/c_host/mpi_petsc.c"))
        .arg("-L")
        .arg(&lib)
        .arg("-lseam")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(pkg("--libs"))
        .arg("-lm")
        .arg("-o")
        .arg(&host)
        .output()
        .expect("mpicc (libopenmpi-dev)");
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    host
}

/// The host under `mpirun -n ranks` (with `serial`: the serial embedding, one rank).
fn run(host: &Path, ranks: usize, serial: bool) -> Printed {
    let mut cmd = Command::new("mpirun");
    cmd.args(["--oversubscribe", "-n", &ranks.to_string()])
        .arg(host)
        .args(serial.then_some("serial"))
        .env("LD_LIBRARY_PATH", library_dir())
        .env("RAYON_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1");
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let numbers = |prefix: &str| -> Vec<f64> {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line in:\n{stdout}"))
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect()
    };
    let heat = numbers("heat:");
    Printed {
        ranks: numbers("ranks:")[0] as usize,
        across: numbers("points across ranks:")[0] as usize,
        heat: [heat[0], heat[1]],
        x: numbers("x:"),
        temperature: numbers("temperature:"),
    }
}

/// Largest |a − b|.
fn difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The heat through the three resistances in series (unit lengths and cross-section).
fn heat_exact() -> f64 {
    (T_LEFT - T_RIGHT) / (1.0 / KA + 1.0 / H + 1.0 / KB)
}

/// Brick a's nodes come first: (3 + 1) × (4 + 1) × (4 + 1) of them.
const NODES_A: usize = 100;

/// The 1-D answer at every node, T linear in each brick (which trilinear elements and a
/// consistent interface form reproduce exactly); a's and b's nodes at x = 1 differ by
/// the jump q/h.
fn exact_temperatures(x: &[f64]) -> Vec<f64> {
    let q = heat_exact();
    x.iter()
        .enumerate()
        .map(|(k, &x)| {
            if k < NODES_A {
                T_LEFT - q * x / KA
            } else {
                T_RIGHT + q * (2.0 - x) / KB
            }
        })
        .collect()
}

#[test]
fn petsc_host_equals_the_serial_embedding_and_the_1d_answer_on_1_to_4_ranks() {
    let tmp = tempfile::Builder::new()
        .prefix("mpi-embed-")
        .tempdir_in(env!("CARGO_TARGET_TMPDIR"))
        .unwrap();
    let host = build_host(tmp.path());

    let serial = run(&host, 1, true);
    let t_scale = serial
        .temperature
        .iter()
        .fold(0.0f64, |m, t| m.max(t.abs()));
    let q = heat_exact();
    let dt = difference(&serial.temperature, &exact_temperatures(&serial.x));
    eprintln!(
        "serial embedding against the 1-D answer: max |ΔT| {dt:.2e} K, heat {:.12} / {:.12} W (exact {q:.12})",
        serial.heat[0], serial.heat[1]
    );
    assert!(dt <= REL * t_scale, "serial T off the 1-D answer by {dt:e}");
    assert!((serial.heat[0] - q).abs() <= REL * q);
    assert!((serial.heat[0] + serial.heat[1]).abs() <= REL * q);

    for n in 1..=4 {
        let par = run(&host, n, false);
        assert_eq!(par.ranks, n);
        let dt = difference(&serial.temperature, &par.temperature);
        let dq = difference(&serial.heat, &par.heat);
        eprintln!(
            "mpirun -n {n}: max |ΔT| {dt:.2e} K (of {t_scale:.0}), max |Δheat| {dq:.2e} W (of {q:.3}), points paired across ranks {}",
            par.across
        );
        assert!(dt <= REL * t_scale, "T differs by {dt:e} on {n} ranks");
        assert!(dq <= REL * q, "heat differs by {dq:e} on {n} ranks");
        if n > 1 {
            assert!(
                par.across > 0,
                "the partition should cut the interface on {n} ranks"
            );
        }
    }
}
