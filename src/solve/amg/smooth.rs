//! Point smoothers of the V-cycle: Gauss–Seidel sweeps over all rows or over a chosen
//! set of them, and the choice of the rows that get extra sweeps (a penalty interface).

use super::csr::{Csr, Rows, dot_row};

/// Share of its diagonal that a row's positive off-diagonal couplings must reach for
/// the row to get extra sweeps ([`penalty_rows`]). A Q1 or P1 conduction matrix on
/// reasonable elements has no positive coupling at all, or small ones; the face mass
/// matrix of a Nitsche or penalty tie puts about half the diagonal there, and a gap
/// conductance of h = 10 on a 1/120 mesh none worth the name (2e-4).
pub(super) const PENALTY_ROW_SHARE: f64 = 0.05;

/// The rows of `a` whose positive off-diagonal couplings sum to at least
/// [`PENALTY_ROW_SHARE`] of the diagonal, together with their neighbours, ascending.
///
/// Why: a penalty or Nitsche interface makes its nodes a stiff, nearly constrained
/// group (each side's values held to the other's trace); a point smoother changes one
/// value at a time and so barely moves an error that keeps the constraint but is rough
/// for the bulk operator, in the interface nodes and the layer next to them, and the
/// aggregates cannot represent it either. Sweeping those few rows once more each way
/// costs little (they are a surface in a volume: 64 000 of 1.16 M rows in the tied
/// 120:80 boxes of `benches/peers.sh`) and takes that case's CG from 40 iterations to
/// 20 (from 44 to 27 without the filtered prolongator of `coarsen`). A second sweep
/// changes nothing there.
pub(super) fn penalty_rows(a: &Csr, diag: &[f64]) -> Vec<u32> {
    let n = a.nrows;
    let mut mark = vec![false; n];
    for i in 0..n {
        let positive: f64 = (a.ptr[i]..a.ptr[i + 1])
            .filter(|&p| a.idx[p] as usize != i && a.val[p] > 0.0)
            .map(|p| a.val[p])
            .sum();
        if positive >= PENALTY_ROW_SHARE * diag[i] {
            mark[i] = true;
        }
    }
    let seeds: Vec<u32> = (0..n).filter(|&i| mark[i]).map(|i| i as u32).collect();
    with_neighbours(a, &seeds)
}

/// `rows` and every row they couple to in `a`, ascending.
fn with_neighbours(a: &Csr, rows: &[u32]) -> Vec<u32> {
    let mut mark = vec![false; a.nrows];
    for &i in rows {
        let i = i as usize;
        mark[i] = true;
        for p in a.ptr[i]..a.ptr[i + 1] {
            mark[a.idx[p] as usize] = true;
        }
    }
    (0..a.nrows)
        .filter(|&i| mark[i])
        .map(|i| i as u32)
        .collect()
}

/// One Gauss–Seidel sweep, `x_i ← x_i + (b_i − (Ax)_i)/a_ii`, rows ascending or
/// descending.
pub(super) fn gauss_seidel<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
    forward: bool,
) {
    let mut row = |i: usize| gauss_seidel_row(a, inv_diag, x, b, i);
    if forward {
        (0..a.nrows).for_each(&mut row);
    } else {
        (0..a.nrows).rev().for_each(&mut row);
    }
}

/// A forward Gauss–Seidel sweep from `x = 0` (which `x` must hold): row i reads only
/// its entries left of the diagonal, since every `x_j`, j ≥ i, is still 0 there — half
/// the matrix read, the values of [`gauss_seidel`] (the skipped terms are products
/// with zero). Needs ascending columns in each row, as every [`Csr`] of the hierarchy
/// has.
pub(super) fn gauss_seidel_from_zero<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
) {
    for i in 0..a.nrows {
        let (start, end) = (a.ptr[i], a.ptr[i + 1]);
        debug_assert!(a.idx[start..end].is_sorted(), "row {i} is not sorted");
        let lower = start + a.lower_len(i);
        let s = b[i] - dot_row(&a.idx[start..lower], &a.val[start..lower], x);
        x[i] += s * inv_diag[i];
    }
}

/// [`gauss_seidel_from_zero`] that also leaves the residual `r = b − A x` after it, in
/// the same pass over the matrix, for a symmetric `a`. Row i's sweep leaves its own
/// residual at `b_i − Σ_{j≤i} a_ij x_j`, which is zero; every later row k
/// then takes `a_ki x_k` off it, which is `a_ik x_k` read from row k's entries left of
/// its diagonal as it is swept (those entries are in cache). This replaces a product
/// with the whole matrix after the sweep.
pub(super) fn gauss_seidel_from_zero_with_residual<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
    r: &mut [f64],
) {
    for i in 0..a.nrows {
        let start = a.ptr[i];
        let lower = a.lower_len(i);
        let (idx, val) = (&a.idx[start..start + lower], &a.val[start..start + lower]);
        let xi = (b[i] - dot_row(idx, val, x)) * inv_diag[i];
        x[i] = xi;
        // b_i − Σ_{j≤i} a_ij x_j: zero, but for rounding.
        r[i] = 0.0;
        for (&j, &v) in idx.iter().zip(val) {
            r[j as usize] -= v.into() * xi;
        }
    }
}

/// A backward Gauss–Seidel sweep (as [`gauss_seidel`] backward) that also leaves the
/// product `y = A x` of the swept `x`, in the same pass over a symmetric `a`: CG's
/// product with the fine matrix, made where the V-cycle reads the matrix anyway. Row
/// k, swept after every row above it, finds `x_j`, j > k, final: it sets
/// `y_k = Σ_{j>k} a_kj x_j + a_kk x_k` and adds `a_kj x_k` to each `y_j`, j > k, which
/// is `a_jk x_k` (symmetry) — the term of row j that the rows below it complete. Needs
/// ascending columns and a stored diagonal in each row, as every [`Csr`] of the
/// hierarchy has.
pub(super) fn gauss_seidel_backward_with_product<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
    y: &mut [f64],
) {
    for k in (0..a.nrows).rev() {
        let (start, end) = (a.ptr[k], a.ptr[k + 1]);
        let d = start + a.lower_len(k);
        debug_assert_eq!(a.idx[d] as usize, k, "row {k} stores no diagonal");
        let (lower, upper) = ((start..d), (d + 1..end));
        let below = dot_row(&a.idx[lower.clone()], &a.val[lower], x);
        let (idx, val) = (&a.idx[upper.clone()], &a.val[upper]);
        let above = dot_row(idx, val, x);
        let diag: f64 = a.val[d].into();
        let xk = x[k] + (b[k] - (below + diag * x[k] + above)) * inv_diag[k];
        x[k] = xk;
        y[k] = above + diag * xk;
        for (&j, &v) in idx.iter().zip(val) {
            y[j as usize] += v.into() * xk;
        }
    }
}

/// [`symmetric_gauss_seidel_rows`] keeping the residual `r = b − A x` of a symmetric
/// `a` up to date: each row's change `δ_k` takes `a_jk δ_k` off `r_j` for the rows j
/// it couples to. `saved` is scratch of at least `rows.len()` values.
pub(super) fn symmetric_gauss_seidel_rows_with_residual<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
    rows: &[u32],
    r: &mut [f64],
    saved: &mut Vec<f64>,
) {
    saved.clear();
    saved.extend(rows.iter().map(|&k| x[k as usize]));
    symmetric_gauss_seidel_rows(a, inv_diag, x, b, rows);
    for (&k, &old) in rows.iter().zip(saved.iter()) {
        let k = k as usize;
        let delta = x[k] - old;
        if delta != 0.0 {
            for p in a.ptr[k]..a.ptr[k + 1] {
                r[a.idx[p] as usize] -= a.val[p].into() * delta;
            }
        }
    }
}

/// A symmetric Gauss–Seidel sweep over `rows` only: forward through them, then
/// backward. Its error propagator is self-adjoint in the energy inner product, so it
/// may sit on either side of the coarse correction and keep the V-cycle symmetric.
pub(super) fn symmetric_gauss_seidel_rows<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
    rows: &[u32],
) {
    for &i in rows {
        gauss_seidel_row(a, inv_diag, x, b, i as usize);
    }
    for &i in rows.iter().rev() {
        gauss_seidel_row(a, inv_diag, x, b, i as usize);
    }
}

/// `x_i ← x_i + (b_i − (Ax)_i)/a_ii`: the body of every sweep, inlined into each (a
/// call per row costs a tenth of a sweep).
#[inline(always)]
fn gauss_seidel_row<V: Copy + Into<f64>>(
    a: Rows<'_, V>,
    inv_diag: &[f64],
    x: &mut [f64],
    b: &[f64],
    i: usize,
) {
    let (start, end) = (a.ptr[i], a.ptr[i + 1]);
    let s = b[i] - dot_row(&a.idx[start..end], &a.val[start..end], x);
    x[i] += s * inv_diag[i];
}
