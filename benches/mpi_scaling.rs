//! `seam run` serially and under `mpirun -n 1, 2` on one generated case, phase by phase
//! (`--features mpi`; docs/benchmarks.md has the numbers and the load they were taken
//! under):
//!
//!   cargo bench --features mpi --bench mpi_scaling
//!
//! The case: two non-matching boxes side by side, [0,1]×[0,3]×[0,0.5] and
//! [1,2]×[0,3]×[0,0.5], joined at x = 1 by a gap conductance, a source in y, T given on
//! the two far ends — `SEAM_BENCH_CELLS` cells per unit length in the first box (default
//! 40, about 1.6·10⁵ unknowns in all), 0.8 of that in the second. Every run is solved by
//! AMG-preconditioned CG (`linear_solver = "amg"`), one thread per process. The largest
//! temperature difference to the serial run is printed beside the times, and under MPI
//! rank 0's set-up phases and each rank's bytes sent and received by the distributed
//! search.
//! `SEAM_BENCH_KEEP=DIR` writes the case into DIR as well. `SEAM_BENCH_K_OF_T=1` makes
//! the conductivities laws of temperature (5 (1 + (T − 300)/600) W/m/K, a Lua
//! expression, in the first box; a table from 40 to 25 W/m/K over 300–600 K in the
//! second): one Newton solve, its tangent assembled per rank at every iterate, by GMRES
//! preconditioned by AMG (serial: seam's, MPI: BoomerAMG). `SEAM_BENCH_TIE=standard`
//! joins the boxes by a mortar tie with Lagrange multipliers instead: a saddle point,
//! factored (serial: LDLᵀ, MPI: MUMPS LU); `SEAM_BENCH_TIE=dual`, by a tie with dual
//! multipliers, condensed (serial: AMG-CG, MPI: CG + BoomerAMG from the threshold).

use std::path::Path;
use std::process::Command;

use seam::mesh::generate::{self, BoxSpec};
use seam::output::exodus::ExodusWriter;

#[path = "common/cut_deck.rs"]
mod cut_deck;

fn write_case(dir: &Path, cells: usize, k_of_t: bool, tie: Option<&str>) {
    let m2 = (cells as f64 * 0.8).round() as usize;
    let m = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 3.0, 0.5], [cells, 3 * cells, cells / 2], 1)
                .with_side_sets([1, 3, 0, 0, 0, 0]),
            BoxSpec::hex([1.0, 0.0, 0.0], [2.0, 3.0, 0.5], [m2, 3 * m2, m2 / 2], 2)
                .with_side_sets([4, 2, 0, 0, 0, 0]),
        ],
        false,
    );
    ExodusWriter::create(&dir.join("bar.exo"), &m, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    let enforcement = match tie {
        Some(m) => format!(
            "enforcement for energy = tied multipliers = {m}\n side b variable temperature to temperature"
        ),
        None => {
            "enforcement for energy = gap_conductance\n gap conductance coefficient = constant h = 2000"
                .to_string()
        }
    };
    std::fs::write(dir.join("contact.i"), cut_deck::cut_deck(&enforcement)).unwrap();
    let (k1, k2) = match k_of_t {
        true => (
            "\"5*(1 + (T - 300)/600)\"",
            "{ table = [[300.0, 40.0], [600.0, 25.0]] }",
        ),
        false => ("5.0", "40.0"),
    };
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"bar.exo\"\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = {k1}\n\
         [[material]]\nblocks = [\"block_2\"]\nconductivity = {k2}\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = \"300 + 10*y\"\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_2\"]\nvalue = 500.0\n\
         [[source]]\nblocks = [\"block_1\", \"block_2\"]\nvalue = \"2e3*y\"\n\
         [contact]\nfile = \"contact.i\"\n\
         [solve]\nkind = \"steady\"\nlinear_solver = \"amg\"\n\
         [output]\ndir = \"out\"\n"
        ),
    )
    .unwrap();
}

/// One run: its summary and nodal temperature; under MPI rank 0's set-up phases and the
/// search's bytes per rank are printed.
fn run(dir: &Path, ranks: Option<usize>) -> (serde_json::Value, Vec<f64>) {
    let seam = env!("CARGO_BIN_EXE_seam");
    let mut cmd = match ranks {
        None => {
            let mut c = Command::new(seam);
            c.args(["--threads", "1"]);
            c
        }
        Some(n) => {
            let mut c = Command::new("mpirun");
            c.args(["--oversubscribe", "-n", &n.to_string(), seam]);
            c
        }
    };
    let out = cmd
        .args(["-v", "run", "--json", "problem.toml"])
        .current_dir(dir)
        .env("RAYON_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .output()
        .expect("seam runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stderr = String::from_utf8_lossy(&out.stderr);
    for l in stderr.lines().filter(|l| l.contains("distributed")) {
        println!(
            "  -n {}: {}",
            ranks.unwrap_or(0),
            l.trim_start_matches("seam[INFO] ")
        );
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let line = stdout
        .lines()
        .find(|l| l.starts_with('{'))
        .expect("summary");
    let t = seam::mesh::exodus::read_nodal_variable(&dir.join("out/results.exo"), "temperature", 0)
        .expect("temperature");
    (serde_json::from_str(line).unwrap(), t)
}

fn main() {
    let cells: usize = std::env::var("SEAM_BENCH_CELLS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(40);
    let k_of_t = std::env::var("SEAM_BENCH_K_OF_T").is_ok_and(|v| v == "1");
    let tie = std::env::var("SEAM_BENCH_TIE").ok();
    let tie = tie.as_deref();
    let tmp = tempfile::tempdir().unwrap();
    write_case(tmp.path(), cells, k_of_t, tie);
    if let Some(keep) = std::env::var_os("SEAM_BENCH_KEEP") {
        // The case written where asked too, to run by hand.
        std::fs::create_dir_all(&keep).unwrap();
        write_case(Path::new(&keep), cells, k_of_t, tie);
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "cells {cells}, k(T) {k_of_t}, tie {tie:?}, load average before: {}",
        load.trim()
    );
    println!(
        "| run | dofs | search s | assembly s | set-up s | solve s | total s | Newton | Krylov its | max |ΔT| vs serial |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    let (serial, t0) = run(tmp.path(), None);
    let mut rows = vec![("serial, 1 thread".to_string(), serial, t0.clone())];
    for n in [1, 2] {
        let (s, t) = run(tmp.path(), Some(n));
        rows.push((format!("mpirun -n {n}"), s, t));
    }
    for (label, s, t) in rows {
        let tm = &s["timing"];
        let dt = t0
            .iter()
            .zip(&t)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        println!(
            "| {label} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {} | {} | {dt:.1e} |",
            s["dofs"],
            tm["search_s"].as_f64().unwrap(),
            tm["assembly_s"].as_f64().unwrap(),
            tm["factor_s"].as_f64().unwrap(),
            tm["solve_s"].as_f64().unwrap(),
            tm["total_s"].as_f64().unwrap(),
            s["newton_iterations"],
            s["linear_solver"]["iterations"],
        );
    }
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!("load average after: {}", load.trim());
}
