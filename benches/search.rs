//! Benchmark: the contact search of one interaction at 1e4, 1e5 and 1e6 side-A points
//! against about as many side-B faces, on a planar and on a curved non-matching
//! interface, with 1 and 2 threads.
//!
//! Side A has one Gauss point per face (`Quadrature { order: 1 }`), so points = faces.
//! Reported per case: tree build time, pairing time (points/s), and the full search with
//! the overlap-area diagnostic (points/s), in wall time; and the CPU time (user + system,
//! all threads) of the pairing and of the full search, which on a machine shared with
//! other work measures the work itself where the wall time also counts the waiting. Run: `cargo bench --bench search` (`-- quick` stops at
//! 1e5). Medians of 3 runs. Filters for profiling: a number keeps that size only
//! (`-- 1000000`), `planar` or `curved` that case, `threads=N` that thread count.

#[path = "common/mod.rs"]
mod common;

use std::time::Instant;

use seam::mesh::Mesh;
use seam::mesh::generate::{self, BoxSpec};
use seam::search::SearchSettings;
use seam::search::pairing::{Integration, Searcher, SurfaceGeometry};

/// Planar: side A is the top of an n×n-cell slab, side B the bottom of an m×m slab
/// above it, m ≈ 0.9 n (non-matching).
fn planar(n: usize) -> (Mesh, usize, usize) {
    let m = (n as f64 * 0.9).round() as usize;
    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.1], [n, n, 1], 1)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0, 0.0, 0.1], [1.0, 1.0, 0.2], [m, m, 1], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    );
    (mesh, 0, 1)
}

/// CPU time of the process so far (user + system, all threads), in seconds.
fn cpu_seconds() -> f64 {
    // SAFETY: getrusage writes the struct it is given; a zeroed rusage is valid.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "quick");
    let only_size: Option<usize> = args.iter().find_map(|a| a.parse().ok());
    let only_case = args
        .iter()
        .find(|a| *a == "planar" || *a == "curved")
        .cloned();
    let only_threads: Option<usize> = args
        .iter()
        .find_map(|a| a.strip_prefix("threads=").and_then(|t| t.parse().ok()));
    let sizes: Vec<usize> = match only_size {
        Some(s) => vec![s],
        None if quick => vec![10_000, 100_000],
        None => vec![10_000, 100_000, 1_000_000],
    };
    println!(
        "{:<7} {:>8} {:>8} {:>3} {:>8} {:>8} {:>9} {:>8} {:>9} {:>8} {:>8}",
        "case",
        "points",
        "B faces",
        "thr",
        "build s",
        "pair s",
        "pair p/s",
        "full s",
        "full p/s",
        "pair cpu",
        "full cpu"
    );
    for &size in &sizes {
        let n = (size as f64).sqrt().round() as usize;
        for label in ["planar", "curved"] {
            if only_case.as_ref().is_some_and(|c| c != label) {
                continue;
            }
            let (mesh, ia, ib) = if label == "planar" {
                planar(n)
            } else {
                (common::rings(size), 0, 1)
            };
            let a = SurfaceGeometry::from_side_set(&mesh, ia).unwrap();
            let b = SurfaceGeometry::from_side_set(&mesh, ib).unwrap();
            let settings = SearchSettings::defaults(3);
            for threads in [1, 2] {
                if only_threads.is_some_and(|t| t != threads) {
                    continue;
                }
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                let (mut build, mut pair, mut full) = (vec![], vec![], vec![]);
                let (mut pair_cpu, mut full_cpu) = (vec![], vec![]);
                let mut matched = 0;
                for _ in 0..3 {
                    pool.install(|| {
                        let t = Instant::now();
                        let searcher = Searcher::new(&b, &settings);
                        build.push(t.elapsed().as_secs_f64());
                        let (t, c) = (Instant::now(), cpu_seconds());
                        let r = searcher.search_points(
                            &a,
                            &b,
                            &settings,
                            Integration::Quadrature { order: 1 },
                            None,
                        );
                        pair.push(t.elapsed().as_secs_f64());
                        pair_cpu.push(cpu_seconds() - c);
                        matched = r.stats.matched;
                        drop(r);
                        let (t, c) = (Instant::now(), cpu_seconds());
                        let r = searcher.search(
                            &a,
                            &b,
                            &settings,
                            Integration::Quadrature { order: 1 },
                            None,
                        );
                        full.push(t.elapsed().as_secs_f64());
                        full_cpu.push(cpu_seconds() - c);
                        std::hint::black_box(r);
                    });
                }
                let (p, f) = (median(pair), median(full));
                println!(
                    "{:<7} {:>8} {:>8} {:>3} {:>8.4} {:>8.4} {:>9.3e} {:>8.4} {:>9.3e} {:>8.4} {:>8.4}  ({} matched)",
                    label,
                    a.faces.len(),
                    b.faces.len(),
                    threads,
                    median(build),
                    p,
                    a.faces.len() as f64 / p,
                    f,
                    a.faces.len() as f64 / f,
                    median(pair_cpu),
                    median(full_cpu),
                    matched
                );
            }
        }
    }
}
