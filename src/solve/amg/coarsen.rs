//! The coarsening of one level of smoothed aggregation: strength of connection and
//! aggregates, the smoothed prolongator, the Galerkin product (see the parent module
//! for the method and its references).

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use super::csr::{Csr, Rows, dot_row_of};
use crate::solve::norm;

/// ρ(D⁻¹A) by [`largest_eigenvalue`] of the similar symmetric `D^{-1/2} A D^{-1/2}`.
pub(super) fn spectral_radius_dinv_a(a: &Csr, inv_diag: &[f64]) -> f64 {
    let scale: Vec<f64> = inv_diag.iter().map(|d| d.sqrt()).collect();
    let (mut scaled, mut product) = (vec![0.0; a.nrows], vec![0.0; a.nrows]);
    largest_eigenvalue(a.nrows, |v, beta, w| {
        scale_into(&mut scaled, v, &scale);
        a.spmv(&scaled, &mut product);
        w.iter_mut()
            .zip(&product)
            .zip(&scale)
            .for_each(|((w, p), c)| *w = c * p - beta * *w);
    })
}

/// `scaled = D^{-1/2} v`, `scale` holding the diagonal of `D^{-1/2}`.
fn scale_into(scaled: &mut [f64], v: &[f64], scale: &[f64]) {
    scaled
        .iter_mut()
        .zip(v)
        .zip(scale)
        .for_each(|((s, v), c)| *s = v * c);
}

/// The diagonal of the filtered matrix `A_F` that smooths the prolongator: `A` with
/// each positive off-diagonal coupling moved onto the diagonal of its row,
/// `d_F,i = a_ii + Σ_{j≠i, a_ij>0} a_ij`. Row sums are kept, so `A_F` annihilates the
/// constants `A` annihilates.
///
/// Why: a penalty or Nitsche interface (tied, gap conductance) couples the nodes of a
/// side to each other through its face mass matrix, with positive entries as large as
/// the diagonal; there `ρ(D⁻¹A)` is about 4 where the bulk of a Q1 mesh has 1.5, and
/// `ω = 4/(3ρ)` taken from it would leave the prolongator nearly unsmoothed everywhere.
/// A positive coupling is not one along which the error is smooth, so it is lumped
/// (the weak entries of Vaněk, Mandel & Brezina's filtered matrix). An M-matrix is its
/// own `A_F`.
pub(super) fn filtered_diagonal(a: &Csr) -> Vec<f64> {
    (0..a.nrows)
        .map(|i| {
            let mut d = 0.0;
            let mut positive = 0.0;
            for p in a.ptr[i]..a.ptr[i + 1] {
                let (j, v) = (a.idx[p] as usize, a.val[p]);
                if j == i {
                    d += v;
                } else if v > 0.0 {
                    positive += v;
                }
            }
            d + positive
        })
        .collect()
}

/// ρ(D_F⁻¹A_F) of the filtered matrix, as [`spectral_radius_dinv_a`] makes ρ(D⁻¹A).
pub(super) fn spectral_radius_filtered<V: Copy + Into<f64> + Sync>(
    a: Rows<'_, V>,
    filtered_diag: &[f64],
) -> f64 {
    use rayon::prelude::*;
    let scale: Vec<f64> = filtered_diag.iter().map(|d| 1.0 / d.sqrt()).collect();
    let mut scaled = vec![0.0; a.nrows];
    largest_eigenvalue(a.nrows, |v, beta, w| {
        scale_into(&mut scaled, v, &scale);
        w.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, wi)| {
                // A_F's row: the negative couplings (min(a_ij, 0) drops the positive
                // ones and the positive diagonal), then its own diagonal.
                let row = a.ptr[i]..a.ptr[i + 1];
                let off = dot_row_of(&a.idx[row.clone()], &a.val[row], &scaled, |v| {
                    v.into().min(0.0)
                });
                let s = off + filtered_diag[i] * scaled[i];
                *wi = scale[i] * s - beta * *wi;
            });
    })
}

/// Gershgorin's bound on ρ(D_F⁻¹A_F) of the filtered matrix: the largest row sum of
/// `|D_F⁻¹A_F|`, `max_i (d_F,i + Σ_{j≠i} max(−a_ij, 0)) / d_F,i`, in one pass over
/// the matrix where [`spectral_radius_filtered`] makes up to ten products. It is an
/// upper bound, so `ω = 4/(3ρ)` from it damps no more than the estimate would. Where
/// every row sum of `A` is at least 0 (an assembled conduction matrix: zero in the bulk,
/// positive where a capacity, a convection or an eliminated Dirichlet neighbour adds to
/// the diagonal; `A_F` keeps them), `d_F,i` is at least the row's negative couplings
/// and the bound is at most 2 — against 1.95 for the estimate on the tied 120:80 boxes
/// of `benches/peers.sh` and the electronics die, and 1.49 on their gap-conductance
/// boxes, whose bulk of Q1 hexes has 1.5. The finest level takes it for a hierarchy
/// that serves one solve (`FineRadius::Bound`); a Galerkin operator has no such
/// guarantee, so the coarser levels keep the estimate. The maximum does not depend on
/// the order, so neither on the threads.
pub(super) fn gershgorin_filtered(a: &Csr, filtered_diag: &[f64]) -> f64 {
    use rayon::prelude::*;
    (0..a.nrows)
        .into_par_iter()
        .with_min_len(4096)
        .map(|i| {
            let row = a.ptr[i]..a.ptr[i + 1];
            let negative: f64 = (a.idx[row.clone()].iter().zip(&a.val[row]))
                .filter(|&(&j, _)| j as usize != i)
                .map(|(_, &v)| (-v).max(0.0))
                .sum();
            (filtered_diag[i] + negative) / filtered_diag[i]
        })
        .reduce(|| 0.0, f64::max)
}

/// Lanczos steps of [`largest_eigenvalue`], each one product with the level's matrix
/// (every level's ρ but the finest one's under `FineRadius::Bound`, which takes
/// [`gershgorin_filtered`]). Ten give the top of the spectrum of a Q1 operator within
/// a few per cent: Lanczos converges to the extreme eigenvalues much faster than the
/// power method, whose twenty products (enlarged by 5 %) still estimated ρ(D_F⁻¹A_F)
/// of the tied 120:80 boxes of `benches/peers.sh` at 1.88 where ten Lanczos steps
/// find 1.95.
const LANCZOS_STEPS: usize = 10;

/// Lanczos stops before [`LANCZOS_STEPS`] once a step raises the largest Ritz value by
/// less than this fraction of it. The finest level of the tied 120:80 boxes of
/// `benches/peers.sh` (when it took the estimate) ran 1.9394, 1.9487, 1.9499, 1.9501,
/// 1.9502 from the fifth step on and stopped after seven products. Where the values
/// still climb all ten run: the tie's coarser levels; the electronics die's second
/// level (1.9864 → 1.9871 at its ninth) stops after nine.
const RITZ_SETTLED: f64 = 1e-3;

/// The largest eigenvalue of a symmetric operator `M` of size `n` (`D^{-1/2} B D^{-1/2}`,
/// whose eigenvalues are those of `D⁻¹B`, for symmetric B and a positive diagonal D),
/// given as `apply(v, β, w)`: `w ← M v − β w`. By at most [`LANCZOS_STEPS`] Lanczos
/// steps from a fixed start (Golub & Van Loan, *Matrix Computations*, § 10.1), in two
/// vectors of `n`: the largest Ritz value, found by bisection on the Sturm sequence of
/// the tridiagonal matrix after each step, until it settles ([`RITZ_SETTLED`]). It
/// approaches ρ from below, close enough to be used as it is (as PyAMG's
/// `approximate_spectral_radius` is). The dot products sum fixed chunks in order, so
/// the estimate does not depend on the thread count.
fn largest_eigenvalue(n: usize, mut apply: impl FnMut(&[f64], f64, &mut [f64])) -> f64 {
    use crate::solve::dot;
    let mut v: Vec<f64> = (0..n)
        .map(|i| 1.0 + ((i * 7919) % 13) as f64 / 13.0)
        .collect();
    let nv = norm(&v);
    if n == 0 || nv == 0.0 {
        return 1e-300;
    }
    v.iter_mut().for_each(|x| *x /= nv);
    // `w` holds the previous Lanczos vector on entry to each step.
    let mut w = vec![0.0; n];
    let (mut alpha, mut beta) = (Vec::new(), Vec::new());
    let mut ritz = 0.0;
    for step in 0..LANCZOS_STEPS.min(n) {
        apply(&v, beta.last().copied().unwrap_or(0.0), &mut w);
        let a = dot(&w, &v);
        w.iter_mut().zip(&v).for_each(|(w, v)| *w -= a * v);
        alpha.push(a);
        let last = ritz;
        ritz = tridiagonal_largest_eigenvalue(&alpha, &beta);
        // (n ≤ LANCZOS_STEPS runs n steps, whose Ritz values are the eigenvalues.)
        let settled = n > LANCZOS_STEPS && step > 0 && ritz - last <= RITZ_SETTLED * ritz.abs();
        let b = norm(&w);
        // Settled, an invariant subspace found (b at round-off of the step), or the
        // last step.
        if settled || step + 1 == LANCZOS_STEPS.min(n) || b.is_nan() || b <= 1e-12 * a.abs() {
            break;
        }
        beta.push(b);
        w.iter_mut().for_each(|w| *w /= b);
        std::mem::swap(&mut v, &mut w);
    }
    ritz.max(1e-300)
}

/// The largest eigenvalue of the symmetric tridiagonal matrix with diagonal `alpha` and
/// off-diagonal `beta` (one shorter), by bisection on the Sturm count (the number of
/// negative pivots of `T − x I` is the number of eigenvalues below x) between the
/// Gershgorin bounds, to round-off.
fn tridiagonal_largest_eigenvalue(alpha: &[f64], beta: &[f64]) -> f64 {
    let k = alpha.len();
    let off = |i: usize| {
        (if i > 0 { beta[i - 1].abs() } else { 0.0 }) + beta.get(i).map_or(0.0, |b| b.abs())
    };
    let mut lo = (0..k)
        .map(|i| alpha[i] - off(i))
        .fold(f64::INFINITY, f64::min);
    let mut hi = (0..k)
        .map(|i| alpha[i] + off(i))
        .fold(f64::NEG_INFINITY, f64::max);
    let below = |x: f64| {
        let mut count = 0;
        let mut q = 1.0;
        for i in 0..k {
            let b2 = if i > 0 {
                beta[i - 1] * beta[i - 1]
            } else {
                0.0
            };
            q = alpha[i] - x - if i > 0 { b2 / q } else { 0.0 };
            if q == 0.0 {
                q = -f64::EPSILON * (x.abs() + 1.0);
            }
            if q < 0.0 {
                count += 1;
            }
        }
        count
    };
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if below(mid) == k {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    hi
}

/// Aggregates of the strong-connection graph: `agg[i]` is the aggregate of node `i`
/// or `usize::MAX` for a node left out (no strong neighbour).
pub(super) fn aggregate(a: &Csr, theta: f64) -> (Vec<usize>, usize) {
    let n = a.nrows;
    // m_i: row i's largest negative coupling; only negative couplings can be strong.
    let largest: Vec<f64> = (0..n)
        .map(|i| {
            (a.ptr[i]..a.ptr[i + 1])
                .filter(|&p| a.idx[p] as usize != i)
                .map(|p| -a.val[p])
                .fold(0.0, f64::max)
        })
        .collect();
    let strong = |i: usize| {
        let (largest, mi) = (&largest, largest[i]);
        (a.ptr[i]..a.ptr[i + 1]).filter_map(move |p| {
            let j = a.idx[p] as usize;
            let c = -a.val[p];
            (j != i && c > 0.0 && c >= theta * (mi * largest[j]).sqrt()).then_some(j)
        })
    };
    const FREE: usize = usize::MAX;
    const ISOLATED: usize = usize::MAX - 1;
    let mut agg = vec![FREE; n];
    let mut count = 0;
    // Nodes without a strong neighbour stay out of every aggregate.
    for (i, a) in agg.iter_mut().enumerate() {
        if strong(i).next().is_none() {
            *a = ISOLATED;
        }
    }
    // Pass 1: a free node whose strong neighbours are all free seeds an aggregate.
    for i in 0..n {
        if agg[i] == FREE && strong(i).all(|j| agg[j] == FREE) {
            agg[i] = count;
            for j in strong(i) {
                agg[j] = count;
            }
            count += 1;
        }
    }
    // Pass 2: a free node joins the aggregate of a strong neighbour from pass 1.
    let after_pass1 = agg.clone();
    for i in 0..n {
        if agg[i] == FREE
            && let Some(j) = strong(i).find(|&j| after_pass1[j] < ISOLATED)
        {
            agg[i] = after_pass1[j];
        }
    }
    // Pass 3: what is left groups with its free strong neighbours.
    for i in 0..n {
        if agg[i] == FREE {
            agg[i] = count;
            for j in strong(i) {
                if agg[j] == FREE {
                    agg[j] = count;
                }
            }
            count += 1;
        }
    }
    for a in &mut agg {
        if *a == ISOLATED {
            *a = usize::MAX;
        }
    }
    (agg, count)
}

/// `P = (I − ω D_F⁻¹ A_F) P̂`, `P̂_{i,agg(i)} = 1`, with `A_F` the filtered matrix of
/// [`filtered_diagonal`] (`D_F` its diagonal), row by row without a copy of A: row i
/// of `S P̂` (`S = ω D_F⁻¹ A_F`) sums `a_ij (ω d_F,i⁻¹)` over the neighbours j of each
/// aggregate (the positive `a_ij`, j ≠ i, left out and `d_F,i` in place of `a_ii`), in
/// the order and with the rounding of the product `S · P̂`; then `P = P̂ − S P̂` (P̂'s
/// entry of row i is among those columns: A stores its diagonal).
///
/// With `truncation` τ > 0, a row's entries below τ times its largest (in magnitude)
/// are dropped and the rest scaled to keep the row's sum, so that P still carries the
/// constants P̂ carries (the near null space). See [`super::AmgOptions::truncation`].
pub(super) fn smoothed_prolongator(
    a: &Csr,
    filtered_diag: &[f64],
    agg: &[usize],
    nagg: usize,
    omega: f64,
    truncation: f64,
) -> Csr {
    let n = a.nrows;
    let mut p = Csr {
        nrows: n,
        ncols: nagg,
        ptr: Vec::with_capacity(n + 1),
        idx: Vec::new(),
        val: Vec::new(),
    };
    p.ptr.push(0);
    let mut marker = vec![usize::MAX; nagg];
    let mut acc = vec![0.0; nagg];
    for i in 0..n {
        let start = p.idx.len();
        let scale = omega * (1.0 / filtered_diag[i]);
        for q in a.ptr[i]..a.ptr[i + 1] {
            let j = a.idx[q] as usize;
            let v = if j == i { filtered_diag[i] } else { a.val[q] };
            let g = agg[j];
            if g == usize::MAX || (j != i && v > 0.0) {
                continue;
            }
            if marker[g] != i {
                marker[g] = i;
                acc[g] = 0.0;
                p.idx.push(g as u32);
            }
            acc[g] += v * scale;
        }
        p.idx[start..].sort_unstable();
        p.val
            .extend(p.idx[start..].iter().map(|&g| -acc[g as usize]));
        if agg[i] != usize::MAX
            && let Some(k) = (start..p.idx.len()).find(|&k| p.idx[k] as usize == agg[i])
        {
            p.val[k] += 1.0;
        }
        if truncation > 0.0 {
            truncate_row(&mut p.idx, &mut p.val, start, truncation);
        }
        p.ptr.push(p.idx.len());
    }
    // Single-precision values: the V-cycle applies P in single precision (module docs
    // of the parent), and the coarse operator is then the Galerkin product of the
    // very P it is used with.
    p.val.iter_mut().for_each(|v| *v = f64::from(*v as f32));
    p
}

/// Drop the entries of the row `idx[start..]`, `val[start..]` below `tau` times its
/// largest magnitude, in place, and scale the kept ones so the row sums as before.
/// A row whose kept entries sum to zero is left whole (no scale would restore it).
fn truncate_row(idx: &mut Vec<u32>, val: &mut Vec<f64>, start: usize, tau: f64) {
    let row = &val[start..];
    let largest = row.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let limit = tau * largest;
    if row.iter().all(|v| v.abs() >= limit) {
        return;
    }
    let sum: f64 = row.iter().sum();
    let kept: f64 = row.iter().filter(|v| v.abs() >= limit).sum();
    if kept == 0.0 || !(sum / kept).is_finite() {
        return;
    }
    let scale = sum / kept;
    let mut w = start;
    for k in start..idx.len() {
        if val[k].abs() >= limit {
            idx[w] = idx[k];
            val[w] = val[k] * scale;
            w += 1;
        }
    }
    idx.truncate(w);
    val.truncate(w);
}

/// The Galerkin product `R (A P)` of a symmetric `A` with `R = Pᵀ`: its upper
/// triangle made, a block of coarse rows at a time, and mirrored, so the coarse matrix
/// is exactly symmetric (as the fine one is) and the lower half costs nothing.
///
/// Each block makes the rows of `A P` its rows of `R` reach, in the order first
/// reached and unsorted (the product below reads them through a scatter), so the whole
/// of `A P` (about as large as A) is never held. A block is at least an eighth of the
/// coarse rows: aggregates are numbered along the fine numbering, so a block's rows of
/// `R` reach a slab of fine rows and the rows of `A P` made twice (those next to two
/// blocks) are a thin shell of it. On the 1.16 M-row Q1 matrix of the tied boxes of
/// `benches/peers.sh`, blocks of 2048 coarse rows made 73 % more rows of `A P` than A
/// has; eighths make 24 % more.
///
/// An upper entry `(g, h)`, `h ≥ g`, sums `R_gi (A P)_ih` over row g of R in order,
/// and each `(A P)_ih` over row i of A in order: the bits of `R.matmul(&A.matmul(&P))`
/// there. The lower entries are those bits mirrored.
pub(super) fn galerkin(r: &Csr, a: &Csr, p: &Csr) -> Csr {
    use rayon::prelude::*;
    const CHUNK: usize = 256;
    let nc = r.nrows;
    let block = nc.div_ceil(8).max(2048);
    // The upper triangle, row by row.
    let (mut up_ptr, mut up_idx, mut up_val) = (vec![0usize], Vec::new(), Vec::new());
    // Fine row → its row in the block's `A P`.
    let mut local = vec![u32::MAX; a.nrows];
    // P's entries as (column, value) pairs: a row of `A P` reads 27 rows of P, and
    // each packed row is one or two cache lines instead of one in each of two arrays.
    // Its values are single-precision numbers already (`smoothed_prolongator`), so
    // nothing is lost.
    let packed: Vec<(u32, f32)> = p
        .idx
        .iter()
        .zip(&p.val)
        .map(|(&j, &v)| (j, v as f32))
        .collect();
    for start in (0..nc).step_by(block) {
        let end = (start + block).min(nc);
        // The fine rows the block's rows of R reach, ascending: the rows of A and P
        // that make them are then read in order, not aggregate by aggregate.
        let mut fine: Vec<u32> = Vec::new();
        for &i in &r.idx[r.ptr[start]..r.ptr[end]] {
            if local[i as usize] == u32::MAX {
                local[i as usize] = 0;
                fine.push(i);
            }
        }
        fine.sort_unstable();
        for (k, &i) in fine.iter().enumerate() {
            local[i as usize] = k as u32;
        }
        let ap = product_rows(a, &fine, p, &packed);
        let rows: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = (start..end)
            .step_by(CHUNK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map_init(
                || (vec![usize::MAX; nc], vec![0.0; nc]),
                |(marker, acc), first| {
                    // A Q1 level's coarse rows hold about 80 entries, half of them upper.
                    let (mut lens, mut idx, mut val) = (
                        Vec::with_capacity(CHUNK),
                        Vec::with_capacity(64 * CHUNK),
                        Vec::with_capacity(64 * CHUNK),
                    );
                    for g in first..(first + CHUNK).min(end) {
                        let at = idx.len();
                        for q in r.ptr[g]..r.ptr[g + 1] {
                            let (i, rgi) = (local[r.idx[q] as usize] as usize, r.val[q]);
                            for s in ap.ptr[i]..ap.ptr[i + 1] {
                                let h = ap.idx[s] as usize;
                                if h < g {
                                    continue;
                                }
                                if marker[h] != g {
                                    marker[h] = g;
                                    acc[h] = 0.0;
                                    idx.push(h as u32);
                                }
                                acc[h] += rgi * ap.val[s];
                            }
                        }
                        idx[at..].sort_unstable();
                        val.extend(idx[at..].iter().map(|&h| acc[h as usize]));
                        lens.push(idx.len() - at);
                    }
                    (lens, idx, val)
                },
            )
            .collect();
        for (lens, idx, val) in rows {
            for l in lens {
                up_ptr.push(up_ptr.last().unwrap() + l);
            }
            up_idx.extend(idx);
            up_val.extend(val);
        }
        for &i in &fine {
            local[i as usize] = u32::MAX;
        }
    }
    mirror_upper(nc, &up_ptr, &up_idx, &up_val)
}

/// Rows `rows` of `A P`, P's entries read from `packed` (its (column, value) pairs),
/// each row's columns in the order first reached (as [`Csr::matmul_rows`] unsorted
/// makes them, the same values).
fn product_rows(a: &Csr, rows: &[u32], p: &Csr, packed: &[(u32, f32)]) -> Csr {
    use rayon::prelude::*;
    const CHUNK: usize = 2048;
    let (p_ptr, ncols) = (&p.ptr, p.ncols);
    let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = rows
        .par_chunks(CHUNK)
        .map_init(
            || (vec![u32::MAX; ncols], vec![0.0; ncols]),
            |(marker, acc), chunk| {
                let (mut lens, mut idx, mut val) = (
                    Vec::with_capacity(chunk.len()),
                    Vec::with_capacity(32 * chunk.len()),
                    Vec::with_capacity(32 * chunk.len()),
                );
                for &i in chunk {
                    let (i, start) = (i as usize, idx.len());
                    let row = a.ptr[i]..a.ptr[i + 1];
                    for (&k, &aik) in a.idx[row.clone()].iter().zip(&a.val[row]) {
                        let k = k as usize;
                        for &(j, pkj) in &packed[p_ptr[k]..p_ptr[k + 1]] {
                            let ju = j as usize;
                            if marker[ju] != i as u32 {
                                marker[ju] = i as u32;
                                acc[ju] = 0.0;
                                idx.push(j);
                            }
                            acc[ju] += aik * f64::from(pkj);
                        }
                    }
                    val.extend(idx[start..].iter().map(|&j| acc[j as usize]));
                    lens.push(idx.len() - start);
                }
                (lens, idx, val)
            },
        )
        .collect();
    let nnz = chunks.iter().map(|c| c.1.len()).sum();
    let mut out = Csr {
        nrows: rows.len(),
        ncols,
        ptr: Vec::with_capacity(rows.len() + 1),
        idx: Vec::with_capacity(nnz),
        val: Vec::with_capacity(nnz),
    };
    out.ptr.push(0);
    for (lens, idx, val) in chunks {
        for l in lens {
            out.ptr.push(out.ptr.last().unwrap() + l);
        }
        out.idx.extend(idx);
        out.val.extend(val);
    }
    out
}

/// The symmetric matrix whose upper triangle (diagonal included, each row sorted) is
/// given: row i is the entries `(g, i)`, `g < i`, of the rows above it, in order of g,
/// then its own upper entries — sorted.
fn mirror_upper(n: usize, ptr: &[usize], idx: &[u32], val: &[f64]) -> Csr {
    let mut count = vec![0usize; n + 1];
    for g in 0..n {
        count[g + 1] += ptr[g + 1] - ptr[g];
        for &h in &idx[ptr[g]..ptr[g + 1]] {
            if h as usize != g {
                count[h as usize + 1] += 1;
            }
        }
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let nnz = count[n];
    let (mut out_idx, mut out_val) = (vec![0u32; nnz], vec![0.0; nnz]);
    let mut next = count.clone();
    for g in 0..n {
        for p in ptr[g]..ptr[g + 1] {
            let h = idx[p] as usize;
            if h != g {
                out_idx[next[h]] = g as u32;
                out_val[next[h]] = val[p];
                next[h] += 1;
            }
        }
    }
    for g in 0..n {
        let (from, to) = (ptr[g]..ptr[g + 1], next[g]..count[g + 1]);
        out_idx[to.clone()].copy_from_slice(&idx[from.clone()]);
        out_val[to].copy_from_slice(&val[from]);
    }
    Csr {
        nrows: n,
        ncols: n,
        ptr: count,
        idx: out_idx,
        val: out_val,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    // tridiag(−1, 2, −1): ρ(D⁻¹A) = 1 + cos(π/(n+1)).
    use crate::solve::amg::tests::laplace_1d;

    /// With no more unknowns than Lanczos steps the Ritz values are the eigenvalues, so
    /// the estimate is ρ to round-off; on a large matrix it lies below ρ by the Lanczos
    /// shortfall, which for this worst case (the spectrum dense up to ρ) is under 2 %.
    #[test]
    fn lanczos_estimate_brackets_the_spectral_radius() {
        for n in [1, 5, 8] {
            let a = laplace_1d(n);
            let exact = 1.0 + (std::f64::consts::PI / (n + 1) as f64).cos();
            let got = spectral_radius_dinv_a(&a, &vec![0.5; n]);
            assert!(
                (got - exact).abs() <= 1e-12 * exact,
                "n = {n}: {got} vs {exact}"
            );
            let filtered = spectral_radius_filtered(a.with_values(&a.val), &filtered_diagonal(&a));
            assert!(
                (filtered - exact).abs() <= 1e-12 * exact,
                "n = {n}: {filtered}"
            );
        }
        let n = 100_000;
        let exact = 1.0 + (std::f64::consts::PI / (n + 1) as f64).cos();
        let got = spectral_radius_dinv_a(&laplace_1d(n), &vec![0.5; n]);
        assert!(
            got <= exact * (1.0 + 1e-12) && got >= 0.98 * exact,
            "{got} vs {exact}"
        );
    }

    /// An isolated top eigenvalue is found in a few products and Lanczos stops there
    /// (a spectrum dense up to ρ, the 1-D Laplacian above, stays within 2 %).
    #[test]
    fn lanczos_stops_once_the_estimate_settles() {
        let n = 10_000;
        // The diagonal operator with eigenvalues spread over [0, 1] and one at 2.
        let eigen: Vec<f64> = (0..n)
            .map(|i| if i == n / 2 { 2.0 } else { i as f64 / n as f64 })
            .collect();
        let mut products = 0;
        let got = largest_eigenvalue(n, |v, beta, w| {
            products += 1;
            for ((w, v), e) in w.iter_mut().zip(v).zip(&eigen) {
                *w = e * v - beta * *w;
            }
        });
        assert!((got - 2.0).abs() <= 2e-3, "{got}");
        assert!(products < LANCZOS_STEPS, "{products} products");
    }

    /// The bound lies above ρ and, for a matrix with zero row sums in its bulk, at 2;
    /// a positive coupling lumped onto the diagonal and a row made heavier by a
    /// capacity lower it, to their exact row sums.
    #[test]
    fn gershgorin_bound_lies_above_the_spectral_radius() {
        for n in [1, 5, 8, 1000] {
            let a = laplace_1d(n);
            let exact = 1.0 + (std::f64::consts::PI / (n + 1) as f64).cos();
            let bound = gershgorin_filtered(&a, &filtered_diagonal(&a));
            assert!(bound >= exact, "n = {n}: {bound} < {exact}");
            let expected = if n == 1 { 1.0 } else { 2.0 };
            assert_eq!(bound, expected, "n = {n}");
        }
        // [[3, −1, 1], [−1, 3, −1], [1, −1, 3]] plus 1 on the diagonal of row 1:
        // filtered diagonals 4, 4, 4; negative couplings 1, 2, 1.
        let mut a = Csr {
            nrows: 3,
            ncols: 3,
            ptr: vec![0, 3, 6, 9],
            idx: vec![0, 1, 2, 0, 1, 2, 0, 1, 2],
            val: vec![3.0, -1.0, 1.0, -1.0, 3.0, -1.0, 1.0, -1.0, 3.0],
        };
        a.val[4] += 1.0;
        let filtered = filtered_diagonal(&a);
        assert_eq!(filtered, vec![4.0, 4.0, 4.0]);
        assert_eq!(gershgorin_filtered(&a, &filtered), 1.5);
        let estimate = spectral_radius_filtered(a.with_values(&a.val), &filtered);
        assert!(estimate <= 1.5 * (1.0 + 1e-12), "{estimate}");
    }

    #[test]
    fn tridiagonal_bisection_finds_the_largest_eigenvalue() {
        // [[2, 1], [1, 2]]: 1 and 3; a 1 × 1 matrix is its entry.
        assert!((tridiagonal_largest_eigenvalue(&[2.0, 2.0], &[1.0]) - 3.0).abs() < 1e-14);
        assert_eq!(tridiagonal_largest_eigenvalue(&[-4.0], &[]), -4.0);
    }
}
