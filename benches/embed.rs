//! Benchmark: the embedding API's two Jacobian paths on a 1e5-point interface — the
//! triplets of `contributions` (made anew at every call, entries repeated) against the
//! CSR of `evaluate` (pattern made once after the search, values refreshed in place) —
//! with the difference between the two matrices as the error column.
//!
//! Scene: a 158 × 158 × 1 hex slab under a 101 × 101 × 1 slab (non-matching), side A
//! integrated by 2 × 2 Gauss points per face: 99 856 points. The conductance depends on
//! both temperatures, so every call does the full nonlinear work. A host that takes
//! triplets must still sum them into its matrix; that cost (sort and merge into CSR,
//! what a COO → CSR conversion does) is timed too.
//!
//! `cargo bench --bench embed`; medians over `SEAM_BENCH_REPS` calls (default 5).

use std::sync::Arc;
use std::time::Instant;

use seam::embed::{
    Conductance, Embedding, FnConductance, Integration, Interaction, Model, PointState,
};
use seam::mesh::generate::{self, BoxSpec};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Triplets summed into CSR as a host would: sort by (row, col), merge repeats.
fn triplets_to_csr(
    n: usize,
    mut t: Vec<(usize, usize, f64)>,
) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    t.sort_unstable_by_key(|&(i, j, _)| (i, j));
    let mut offsets = vec![0usize; n + 1];
    let (mut cols, mut vals) = (Vec::with_capacity(t.len()), Vec::with_capacity(t.len()));
    let mut last = None;
    for (i, j, v) in t {
        if last == Some((i, j)) {
            *vals.last_mut().unwrap() += v;
        } else {
            offsets[i + 1] += 1;
            cols.push(j);
            vals.push(v);
            last = Some((i, j));
        }
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    (offsets, cols, vals)
}

fn main() {
    let reps: usize = std::env::var("SEAM_BENCH_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.1], [158, 158, 1], 1)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0, 0.0, 0.1], [1.0, 1.0, 0.2], [101, 101, 1], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    );
    let n = mesh.num_nodes();
    let mut builder =
        Embedding::builder(&mesh.coords).integration(Integration::Quadrature { order: 2 });
    for (k, block) in mesh.blocks.iter().enumerate() {
        let conn: Vec<usize> = block.connectivity.iter().map(|v| v.index()).collect();
        builder = builder.block(&format!("b{k}"), block.topology, &conn, 16.0);
    }
    for set in &mesh.side_sets {
        let sides: Vec<(usize, u8)> = set.sides.iter().map(|s| (s.elem.index(), s.side)).collect();
        builder = builder.side_set(if set.id == 1 { "a" } else { "b" }, &sides);
    }
    let dofs: Vec<usize> = (0..n).collect();
    let mut seam = builder.dofs(&dofs).build().expect("the slabs");
    let h = Arc::new(FnConductance::new("h(T)", true, |s: &PointState| {
        let t = 0.5 * (s.temp_a + s.temp_b);
        Ok(Conductance {
            h: 500.0 + 1e-3 * t * t,
            dh_dtemp_a: 1e-3 * t,
            dh_dtemp_b: 1e-3 * t,
            ..Conductance::default()
        })
    }));
    seam.add_interaction(
        Interaction::new("a", "b", Model::GapConductance { h: 0.0 }).conductance(h),
    )
    .unwrap();
    let t = Instant::now();
    seam.search().unwrap();
    let search_s = t.elapsed().as_secs_f64();
    let points = seam.coverage(0).unwrap().points;
    let u: Vec<f64> = (0..n)
        .map(|i| 300.0 + 50.0 * ((i as f64) * 0.37).sin())
        .collect();
    // The first call of each path also makes the interface geometry: not timed.
    let first = Instant::now();
    seam.evaluate(&u).unwrap();
    let first_csr_s = first.elapsed().as_secs_f64();
    let (mut triplets_s, mut host_csr_s, mut refresh_s) = (Vec::new(), Vec::new(), Vec::new());
    let mut count = 0;
    let mut worst = 0.0f64;
    for rep in 0..reps {
        let t = Instant::now();
        let c = seam.contributions(&u).unwrap();
        triplets_s.push(t.elapsed().as_secs_f64());
        count = c.jacobian.len();
        let t = Instant::now();
        let (offsets, cols, vals) = triplets_to_csr(n, c.jacobian);
        host_csr_s.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let e = seam.evaluate(&u).unwrap();
        refresh_s.push(t.elapsed().as_secs_f64());
        if rep == 0 {
            assert_eq!(e.jacobian.row_offsets, offsets, "same pattern");
            let scale = vals.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (k, &col) in cols.iter().enumerate() {
                assert_eq!(e.jacobian.columns[k], col);
                worst = worst.max((e.jacobian.values[k] - vals[k]).abs() / scale);
            }
        }
    }
    let nnz = seam.evaluation().unwrap().jacobian.columns.len();
    let (tr, hc, re) = (median(triplets_s), median(host_csr_s), median(refresh_s));
    println!("embed Jacobian paths: {points} side-A points, {n} nodes, search {search_s:.3} s");
    println!(
        "  triplets: {count} ({:.2} per entry of {nnz})",
        count as f64 / nnz as f64
    );
    println!("  first evaluate (geometry + pattern): {first_csr_s:.3} s");
    println!("  triplets (contributions):            {tr:.4} s");
    println!("  triplets + host COO → CSR:           {:.4} s", tr + hc);
    println!("  CSR refresh (evaluate):              {re:.4} s");
    println!(
        "  ratio refresh / triplets: {:.2}, refresh / (triplets + CSR): {:.2}; largest difference {worst:.1e} of the largest entry",
        re / tr,
        re / (tr + hc)
    );
}
