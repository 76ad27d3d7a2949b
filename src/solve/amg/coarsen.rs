//! The coarsening of one level of smoothed aggregation: strength of connection and
//! aggregates, the smoothed prolongator, the Galerkin product (see the parent module
//! for the method and its references).

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use super::csr::Csr;
use crate::solve::norm;

/// ρ(D⁻¹A) by 20 power iterations from a fixed start; enlarged by 5% because power
/// iteration approaches ρ from below and ω must not overshoot 4/(3ρ) by much.
pub(super) fn spectral_radius_dinv_a(a: &Csr, inv_diag: &[f64]) -> f64 {
    power_iteration(a.nrows, |v, w| {
        a.spmv(v, w);
        w.iter_mut().zip(inv_diag).for_each(|(x, d)| *x *= d);
    })
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

/// `(A_F x)_i` of [`filtered_diagonal`]'s `A_F`, summed in storage order.
#[inline]
fn filtered_row(a: &Csr, filtered_diag: &[f64], i: usize, x: &[f64]) -> f64 {
    let mut s = 0.0;
    for p in a.ptr[i]..a.ptr[i + 1] {
        let (j, v) = (a.idx[p] as usize, a.val[p]);
        if j == i {
            s += filtered_diag[i] * x[i];
        } else if v <= 0.0 {
            s += v * x[j];
        }
    }
    s
}

/// ρ(D_F⁻¹A_F) of the filtered matrix, as [`spectral_radius_dinv_a`] makes ρ(D⁻¹A).
pub(super) fn spectral_radius_filtered(a: &Csr, filtered_diag: &[f64]) -> f64 {
    use rayon::prelude::*;
    power_iteration(a.nrows, |v, w| {
        w.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, wi)| *wi = filtered_row(a, filtered_diag, i, v) / filtered_diag[i]);
    })
}

/// 20 steps of the power method for the operator `apply(v, w): w = M v`, from a fixed
/// start, its largest |eigenvalue| enlarged by 5%.
fn power_iteration(n: usize, mut apply: impl FnMut(&[f64], &mut [f64])) -> f64 {
    let mut v: Vec<f64> = (0..n)
        .map(|i| 1.0 + ((i * 7919) % 13) as f64 / 13.0)
        .collect();
    let mut w = vec![0.0; n];
    let mut rho = 1.0;
    for _ in 0..20 {
        let nv = norm(&v);
        if nv == 0.0 {
            break;
        }
        v.iter_mut().for_each(|x| *x /= nv);
        apply(&v, &mut w);
        rho = norm(&w);
        std::mem::swap(&mut v, &mut w);
    }
    1.05 * rho.max(1e-300)
}

/// Aggregates of the strong-connection graph: `agg[i]` is the aggregate of node `i`
/// or `usize::MAX` for a node left out (no strong neighbour).
pub(super) fn aggregate(a: &Csr, theta: f64) -> (Vec<usize>, usize) {
    let n = a.nrows;
    let diag_values = a.diagonal();
    let diag = diag_values.as_slice();
    let strong = |i: usize| {
        let di = diag[i].abs();
        (a.ptr[i]..a.ptr[i + 1]).filter_map(move |p| {
            let j = a.idx[p] as usize;
            (j != i && a.val[p] != 0.0 && a.val[p].abs() >= theta * (di * diag[j].abs()).sqrt())
                .then_some(j)
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
pub(super) fn smoothed_prolongator(
    a: &Csr,
    filtered_diag: &[f64],
    agg: &[usize],
    nagg: usize,
    omega: f64,
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
        p.ptr.push(p.idx.len());
    }
    p
}

/// The Galerkin product `R (A P)`, a block of coarse rows at a time: each block makes
/// only the rows of `A P` its rows of `R` reach, so the whole of `A P` (about as large
/// as A) is never held. Each row of `A P` and of the product is made as
/// [`Csr::matmul`] makes it, and the block's rows of `R` keep their order, so the bits
/// are those of `R.matmul(&A.matmul(&P))`.
pub(super) fn galerkin(r: &Csr, a: &Csr, p: &Csr) -> Csr {
    const BLOCK: usize = 2048;
    let mut out = Csr {
        nrows: r.nrows,
        ncols: p.ncols,
        ptr: vec![0],
        ..Csr::default()
    };
    // Fine row → its row in the block's `A P`.
    let mut local = vec![u32::MAX; a.nrows];
    for start in (0..r.nrows).step_by(BLOCK) {
        let end = (start + BLOCK).min(r.nrows);
        let span = r.ptr[start]..r.ptr[end];
        let mut fine = r.idx[span.clone()].to_vec();
        fine.sort_unstable();
        fine.dedup();
        for (k, &i) in fine.iter().enumerate() {
            local[i as usize] = k as u32;
        }
        let ap = a.matmul_rows(Some(&fine), p);
        let block = Csr {
            nrows: end - start,
            ncols: fine.len(),
            ptr: r.ptr[start..=end]
                .iter()
                .map(|&q| q - r.ptr[start])
                .collect(),
            idx: r.idx[span.clone()]
                .iter()
                .map(|&i| local[i as usize])
                .collect(),
            val: r.val[span].to_vec(),
        };
        let c = block.matmul(&ap);
        let base = out.idx.len();
        out.ptr.extend(c.ptr[1..].iter().map(|&q| base + q));
        out.idx.extend(c.idx);
        out.val.extend(c.val);
    }
    out
}
