//! Linear-solver and assembly benchmark for the heat host (plain `main`, run with
//! `cargo bench --bench solvers`; release profile).
//!
//! Cases:
//! - 7-point Laplacian at 40³ (64k) and 60³ (216k) unknowns: faer Cholesky with AMD
//!   vs METIS nested dissection (symbolic, numeric, solve times, stored L values);
//! - smoothed-aggregation AMG-CG at 60³ and 100³ (1M) unknowns (set-up, iterations,
//!   solve time), and on the Q1 hex conduction matrix at 1M unknowns;
//! - assembly of the Hex8 conduction matrix with 1M unknowns: first assembly (pattern
//!   + values) and values-only reassembly.
//!
//! Every solve reports its relative residual ‖b − Ax‖/‖b‖ next to its time. Times are
//! medians over `SEAM_BENCH_REPS` repetitions (default 3; the 216k factorisations run
//! once unless `SEAM_BENCH_REPS` is set, as AMD's alone takes tens of seconds).
//! `SEAM_BENCH_QUICK=1` shrinks every case for a smoke run.

use std::time::Instant;

use faer::sparse::SparseColMat;
use seam::assembly::{Assembler, DofMap, Pattern};
use seam::heat::{Basis, TEMPERATURE, kernel};
use seam::mesh::Topology;
use seam::mesh::generate::{BoxSpec, single_box};
use seam::solve::{
    AmgCg, AmgOptions, Cholesky, LinearSolver, Ordering, apply_dirichlet, laplacian_7pt,
    relative_residual,
};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn time<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let t = Instant::now();
    let r = f();
    (r, t.elapsed().as_secs_f64())
}

fn rhs(n: usize) -> Vec<f64> {
    (0..n).map(|i| 1.0 + (i % 11) as f64 / 11.0).collect()
}

struct Row {
    case: String,
    unknowns: usize,
    phase: String,
    seconds: f64,
    extra: String,
}

fn cholesky_rows(rows: &mut Vec<Row>, n: usize, reps: usize) {
    let a = laplacian_7pt(n);
    let b = rhs(a.nrows());
    for (name, ordering) in [("AMD", Ordering::Amd), ("METIS", Ordering::Metis)] {
        let (mut sym, mut num, mut sol) = (Vec::new(), Vec::new(), Vec::new());
        let mut nnz = 0;
        let mut res = 0.0;
        for _ in 0..reps {
            let mut chol = Cholesky::new(ordering);
            sym.push(time(|| chol.analyse(&a).unwrap()).1);
            num.push(time(|| chol.factor(&a).unwrap()).1);
            let mut x = b.clone();
            sol.push(time(|| chol.solve(&mut x).unwrap()).1);
            nnz = chol.factor_nnz();
            res = relative_residual(&a, &x, &b);
        }
        let case = format!("7-pt {n}³ Cholesky {name}");
        for (phase, t, extra) in [
            ("symbolic", median(sym), String::new()),
            (
                "numeric",
                median(num),
                format!("L values {:.1}M", nnz as f64 / 1e6),
            ),
            ("solve", median(sol), format!("relres {res:.1e}")),
        ] {
            rows.push(Row {
                case: case.clone(),
                unknowns: a.nrows(),
                phase: phase.into(),
                seconds: t,
                extra,
            });
        }
    }
}

fn amg_rows(rows: &mut Vec<Row>, case: &str, a: &SparseColMat<usize, f64>, b: &[f64], reps: usize) {
    let (mut setup, mut solve) = (Vec::new(), Vec::new());
    let (mut its, mut res, mut levels, mut oc) = (0, 0.0, 0, 0.0);
    for _ in 0..reps {
        let mut amg = AmgCg::new(AmgOptions::default());
        setup.push(time(|| amg.factor(a).unwrap()).1);
        let mut x = b.to_vec();
        let (rep, t) = time(|| amg.solve(&mut x).unwrap());
        solve.push(t);
        its = rep.iterations;
        res = relative_residual(a, &x, b);
        let h = amg.hierarchy();
        levels = h.rows.len();
        oc = h.operator_complexity();
    }
    rows.push(Row {
        case: case.into(),
        unknowns: a.nrows(),
        phase: "AMG setup".into(),
        seconds: median(setup),
        extra: format!("{levels} levels, operator complexity {oc:.2}"),
    });
    rows.push(Row {
        case: case.into(),
        unknowns: a.nrows(),
        phase: "PCG solve".into(),
        seconds: median(solve),
        extra: format!("{its} iterations, relres {res:.1e}"),
    });
}

/// Q1 conduction matrix of a `c³`-cell unit cube (Dirichlet on the whole boundary):
/// times of the first assembly (pattern + values) and of values-only reassembly.
fn assembly_rows(
    rows: &mut Vec<Row>,
    c: usize,
    reps: usize,
) -> (SparseColMat<usize, f64>, Vec<f64>) {
    let (mesh, t_mesh) = time(|| single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [c, c, c], 1)));
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
    let rule = Basis::standard(Topology::Hex8).unwrap();
    let kernel = |e: seam::mesh::ElemId, ke: &mut [f64], fe: &mut [f64]| {
        let mut x = [[0.0; 3]; 8];
        for (k, n) in mesh.elem_nodes(e).iter().enumerate() {
            x[k] = mesh.coords[n.index()];
        }
        kernel::conductivity(&rule, &x, |_| 1.0, ke).unwrap();
        kernel::source(&rule, &x, |_| 1.0, fe).unwrap();
    };
    let mut first = Vec::new();
    let mut pattern_t = Vec::new();
    let mut result = None;
    for _ in 0..reps {
        let t0 = Instant::now();
        let mut pattern = Pattern::new(&mesh, &dofs);
        pattern.build().unwrap();
        pattern_t.push(t0.elapsed().as_secs_f64());
        let (a, f) = {
            let mut asm = Assembler::new(&pattern);
            asm.elements(&mesh, None, kernel);
            (asm.matrix().unwrap(), asm.rhs())
        };
        first.push(t0.elapsed().as_secs_f64());
        result = Some((pattern, a, f));
    }
    let (pattern, a, f) = result.unwrap();
    let mut again = Vec::new();
    let mut asm = Assembler::new(&pattern);
    for _ in 0..reps {
        let (_, t) = time(|| {
            asm.elements(&mesh, None, kernel);
            asm.matrix().unwrap()
        });
        again.push(t);
    }
    // The values-only step alone: slots added into the kept CSC structure.
    let mut sum_only = Vec::new();
    for _ in 0..reps {
        sum_only.push(time(|| asm.matrix().unwrap()).1);
    }
    let case = format!("Q1 hex {c}³ cells assembly");
    let n = dofs.len();
    rows.push(Row {
        case: case.clone(),
        unknowns: n,
        phase: "mesh generation".into(),
        seconds: t_mesh,
        extra: String::new(),
    });
    rows.push(Row {
        case: case.clone(),
        unknowns: n,
        phase: "pattern build".into(),
        seconds: median(pattern_t),
        extra: format!("nnz {:.1}M", pattern.nnz() as f64 / 1e6),
    });
    rows.push(Row {
        case: case.clone(),
        unknowns: n,
        phase: "first assembly (pattern + values)".into(),
        seconds: median(first),
        extra: format!("{} elements", mesh.num_elems()),
    });
    rows.push(Row {
        case: case.clone(),
        unknowns: n,
        phase: "values-only reassembly".into(),
        seconds: median(again),
        extra: "element kernels + slot sum".into(),
    });
    rows.push(Row {
        case,
        unknowns: n,
        phase: "slot sum into CSC only".into(),
        seconds: median(sum_only),
        extra: format!("{:.1}M slots", pattern.value_count() as f64 / 1e6),
    });
    (a, f)
}

/// Where AMG-CG overtakes Cholesky: the Q1 conduction matrix of a `c³`-cell cube with
/// T = 0 on its boundary, solved by METIS Cholesky (factor + solve) and by AMG-CG at the
/// tolerance `seam run` uses (set-up + solve), for `c` from 8 to 40 cells. The crossover
/// sets `seam::heat::steady::AUTO_AMG_THRESHOLD`.
fn crossover(reps: usize) {
    println!("| cells | unknowns | Cholesky s | AMG-CG s | CG iterations | max |x_chol − x_amg| |");
    println!("|---:|---:|---:|---:|---:|---:|");
    for cells in [8, 12, 16, 20, 24, 28, 32, 40] {
        let (mut a, mut f) = assembly_rows(&mut Vec::new(), cells, 1);
        let c = cells + 1;
        let bcs: Vec<(usize, f64)> = (0..c * c * c)
            .filter(|&d| {
                let (i, j, k) = (d % c, (d / c) % c, d / (c * c));
                [i, j, k].iter().any(|&v| v == 0 || v == c - 1)
            })
            .map(|d| (d, 0.0))
            .collect();
        apply_dirichlet(&mut a, &mut f, &bcs).unwrap();
        let (mut tc, mut ta) = (Vec::new(), Vec::new());
        let (mut xc, mut xa, mut its) = (f.clone(), f.clone(), 0);
        for _ in 0..reps {
            tc.push(
                time(|| {
                    let mut chol = Cholesky::new(Ordering::Metis);
                    chol.factor(&a).unwrap();
                    xc = f.clone();
                    chol.solve(&mut xc).unwrap();
                })
                .1,
            );
            ta.push(
                time(|| {
                    let mut amg = AmgCg::new(AmgOptions {
                        tolerance: seam::heat::steady::AMG_TOLERANCE,
                        ..AmgOptions::default()
                    });
                    amg.factor(&a).unwrap();
                    xa = f.clone();
                    its = amg.solve(&mut xa).unwrap().iterations;
                })
                .1,
            );
        }
        let diff = xc
            .iter()
            .zip(&xa)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
        println!(
            "| {cells} | {} | {:.4} | {:.4} | {its} | {diff:.1e} |",
            a.nrows(),
            median(tc),
            median(ta)
        );
    }
}

fn main() {
    let quick = std::env::var("SEAM_BENCH_QUICK").is_ok();
    let reps_env = std::env::var("SEAM_BENCH_REPS")
        .ok()
        .and_then(|s| s.parse().ok());
    let reps = reps_env.unwrap_or(3);
    let (small, mid, big, cells) = if quick {
        (12, 16, 24, 20)
    } else {
        (40, 60, 100, 99)
    };
    eprintln!(
        "rayon threads: {}, faer parallelism: {:?}",
        rayon::current_num_threads(),
        faer::get_global_parallelism()
    );
    // `SEAM_BENCH_ONLY=crossover`: only the Cholesky / AMG-CG crossover on Q1 hexes.
    if std::env::var("SEAM_BENCH_ONLY").is_ok_and(|s| s == "crossover") {
        crossover(reps);
        return;
    }
    // `SEAM_BENCH_ONLY=assembly` skips the Laplacian cases (for profiling assembly).
    let only_assembly = std::env::var("SEAM_BENCH_ONLY").is_ok_and(|s| s == "assembly");
    let mut rows = Vec::new();
    if !only_assembly {
        cholesky_rows(&mut rows, small, reps);
        cholesky_rows(&mut rows, mid, reps_env.unwrap_or(1));
        for n in [mid, big] {
            let a = laplacian_7pt(n);
            let b = rhs(a.nrows());
            amg_rows(&mut rows, &format!("7-pt {n}³ AMG-CG"), &a, &b, reps);
        }
    }
    let (mut a, mut f) = assembly_rows(&mut rows, cells, reps);
    // Dirichlet T = 0 on the boundary of the cube, then AMG-CG on the Q1 matrix.
    let c = cells + 1;
    let bcs: Vec<(usize, f64)> = (0..c * c * c)
        .filter(|&d| {
            let (i, j, k) = (d % c, (d / c) % c, d / (c * c));
            [i, j, k].iter().any(|&v| v == 0 || v == c - 1)
        })
        .map(|d| (d, 0.0))
        .collect();
    apply_dirichlet(&mut a, &mut f, &bcs).unwrap();
    amg_rows(&mut rows, &format!("Q1 hex {cells}³ AMG-CG"), &a, &f, reps);

    println!("| case | unknowns | phase | median s | notes |");
    println!("|---|---:|---|---:|---|");
    for r in rows {
        println!(
            "| {} | {} | {} | {:.3} | {} |",
            r.case, r.unknowns, r.phase, r.seconds, r.extra
        );
    }
}
