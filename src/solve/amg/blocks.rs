//! Gauss–Seidel sweeps of a large level cut into consecutive row blocks that are swept
//! side by side (hybrid Gauss–Seidel): inside a block a sweep is Gauss–Seidel, and a
//! row that couples to another block reads that block's values from before the sweep.
//!
//! The blocks are a function of the matrix alone — never of the thread count — and a
//! block reads nothing another block writes during the sweep, so any number of threads
//! gives the same bits; one thread sweeps the blocks one after the other.
//!
//! The fused sweeps of [`super::smooth`] (the residual made in the forward sweep from
//! zero, CG's product in the backward sweep) keep their fusion inside a block. The terms
//! between two blocks, which a block cannot add into the other's rows while that one
//! is being swept, are added after the blocks, in a fixed order: they are a few rows
//! per cut (the rows a mesh ordered by position couples across a plane).

use rayon::prelude::*;

use super::csr::{Csr, Rows, dot_row, dot_row_by};

/// The default rows per block, at least ([`super::AmgOptions::block_rows`]): a level is
/// cut from twice this on. A cut costs the rows next to it, which read across it (two
/// planes of nodes in a mesh numbered plane by plane) and are swept again after the
/// blocks. Measured on the tied 120:80 boxes of `benches/peers.sh` (1.16 M rows, 17 CG
/// iterations whatever the cut): 2 blocks, 2.5 % of the rows across, CG 2.66 → 2.83 s on
/// one thread and 2.56 → 1.81 s on two; 4 blocks (2¹⁸ rows), 8.2 % across, 2.93 s on one.
pub(super) const BLOCK_ROWS: usize = 1 << 19;

/// The largest share of a level's rows that may read across cuts: a level numbered
/// with no locality (most rows coupling far away) is swept whole instead.
const MAX_CROSS_SHARE: f64 = 0.15;

/// A level's rows cut into blocks, with the rows that couple across the cuts.
#[derive(Clone, Debug, Default)]
pub(super) struct Blocks {
    /// Block `k` holds rows `starts[k]..starts[k + 1]`.
    starts: Vec<usize>,
    /// Per block, its rows with an entry left of the block, ascending.
    lower: Vec<Vec<u32>>,
    /// Per block, its rows with an entry left or right of the block, ascending.
    crossing: Vec<Vec<u32>>,
    /// Every column read across a cut, ascending: what a backward sweep keeps from
    /// before it, in `old`.
    kept: Vec<u32>,
    /// `x` before a backward sweep, at `kept` (other entries unused).
    old: Vec<f64>,
}

impl Blocks {
    /// The blocks of `a` (ascending columns in each row), at least `rows` rows each,
    /// or `None` when it is too small to cut (or `rows` is 0) or too many of its rows
    /// would read across the cuts.
    pub(super) fn new(a: &Csr, rows: usize) -> Option<Blocks> {
        let n = a.nrows;
        let count = n.checked_div(rows).unwrap_or(0);
        if count < 2 || a.ncols != n {
            return None;
        }
        let starts: Vec<usize> = (0..=count).map(|k| k * n / count).collect();
        let (lower, crossing): (Vec<Vec<u32>>, Vec<Vec<u32>>) = (0..count)
            .into_par_iter()
            .map(|k| {
                let (s, e) = (starts[k], starts[k + 1]);
                let (mut lower, mut crossing) = (Vec::new(), Vec::new());
                for i in s..e {
                    let row = &a.idx[a.ptr[i]..a.ptr[i + 1]];
                    let left = row.first().is_some_and(|&j| (j as usize) < s);
                    let right = row.last().is_some_and(|&j| (j as usize) >= e);
                    if left {
                        lower.push(i as u32);
                    }
                    if left || right {
                        crossing.push(i as u32);
                    }
                }
                (lower, crossing)
            })
            .unzip();
        let rows: usize = crossing.iter().map(Vec::len).sum();
        if rows as f64 > MAX_CROSS_SHARE * n as f64 {
            return None;
        }
        let mut kept: Vec<u32> = Vec::new();
        for (k, rows) in crossing.iter().enumerate() {
            let (s, e) = (starts[k], starts[k + 1]);
            for &i in rows {
                let row = &a.idx[a.ptr[i as usize]..a.ptr[i as usize + 1]];
                kept.extend(
                    row.iter()
                        .filter(|&&j| (j as usize) < s || (j as usize) >= e),
                );
            }
        }
        kept.sort_unstable();
        kept.dedup();
        Some(Blocks {
            starts,
            lower,
            crossing,
            kept,
            old: vec![0.0; n],
        })
    }

    /// The number of blocks.
    pub(super) fn count(&self) -> usize {
        self.starts.len() - 1
    }

    /// The number of rows that read across a cut.
    pub(super) fn crossing_rows(&self) -> usize {
        self.crossing.iter().map(Vec::len).sum()
    }

    /// `v` cut at the blocks' starts.
    fn split<'v>(&self, mut v: &'v mut [f64]) -> Vec<&'v mut [f64]> {
        let mut parts = Vec::with_capacity(self.count());
        for k in 0..self.count() {
            let (part, rest) = v.split_at_mut(self.starts[k + 1] - self.starts[k]);
            parts.push(part);
            v = rest;
        }
        parts
    }

    /// [`super::smooth::gauss_seidel_from_zero_with_residual`] by blocks: `x` (zero on
    /// entry) after a forward sweep from zero in which a row reads the rows left of its
    /// block as zero, and `r = b − A x` of that `x`, for a symmetric `a`.
    pub(super) fn forward_from_zero_with_residual<V: Copy + Into<f64> + Sync>(
        &self,
        a: Rows<'_, V>,
        inv_diag: &[f64],
        x: &mut [f64],
        b: &[f64],
        r: &mut [f64],
    ) {
        let (xs, rs) = (self.split(x), self.split(r));
        let both: Vec<_> = xs.into_iter().zip(rs).collect();
        for_each_block(both, |k, (x, r)| {
            let s = self.starts[k];
            let mut cross = self.lower[k].iter().peekable();
            for il in 0..x.len() {
                let i = s + il;
                let (start, end) = (a.ptr[i], a.ptr[i + 1]);
                let row = &a.idx[start..end];
                // Entries left of the block read zeros: skipped.
                let first = if cross.next_if_eq(&&(i as u32)).is_some() {
                    row.partition_point(|&j| (j as usize) < s)
                } else {
                    0
                };
                let diag = a.lower_len(i);
                let (idx, val) = (&row[first..diag], &a.val[start + first..start + diag]);
                let xi = (b[i] - dot_local(idx, val, x, s)) * inv_diag[i];
                x[il] = xi;
                // b_i − Σ_{j≤i} a_ij x_j: zero, but for rounding; the later rows
                // of the block take their terms off it.
                r[il] = 0.0;
                for (&j, &v) in idx.iter().zip(val) {
                    r[j as usize - s] -= v.into() * xi;
                }
            }
        });
        // The terms across the cuts: row i's entries left of its block, in both rows.
        for (k, rows) in self.lower.iter().enumerate() {
            let s = self.starts[k];
            for &i in rows {
                let i = i as usize;
                let start = a.ptr[i];
                let row = &a.idx[start..a.ptr[i + 1]];
                let left = row.partition_point(|&j| (j as usize) < s);
                let xi = x[i];
                let mut sum = 0.0;
                for (&j, &v) in row[..left].iter().zip(&a.val[start..start + left]) {
                    let v: f64 = v.into();
                    r[j as usize] -= v * xi;
                    sum += v * x[j as usize];
                }
                r[i] -= sum;
            }
        }
    }

    /// A backward Gauss–Seidel sweep by blocks, a row reading the rows of other blocks
    /// as they were before the sweep; with `y`, also `y = A x` of the swept `x` (as
    /// [`super::smooth::gauss_seidel_backward_with_product`], for a symmetric `a`).
    pub(super) fn backward<V: Copy + Into<f64> + Sync>(
        &mut self,
        a: Rows<'_, V>,
        inv_diag: &[f64],
        x: &mut [f64],
        b: &[f64],
        y: Option<&mut [f64]>,
    ) {
        for &j in &self.kept {
            self.old[j as usize] = x[j as usize];
        }
        let this = &*self;
        let xs = this.split(x);
        let Some(y) = y else {
            for_each_block(xs, |k, x| {
                this.backward_block::<V, false>(a, inv_diag, b, k, x, &mut []);
            });
            return;
        };
        let ys = this.split(y);
        let both: Vec<_> = xs.into_iter().zip(ys).collect();
        for_each_block(both, |k, (x, y)| {
            this.backward_block::<V, true>(a, inv_diag, b, k, x, y);
        });
        // The product's terms across the cuts: row i's entries right of its block, in
        // both rows, with the swept values.
        for (k, rows) in this.crossing.iter().enumerate() {
            let e = this.starts[k + 1];
            for &i in rows {
                let i = i as usize;
                let end = a.ptr[i + 1];
                let row = &a.idx[a.ptr[i]..end];
                let right = a.ptr[i] + row.partition_point(|&j| (j as usize) < e);
                let xi = x[i];
                let mut sum = 0.0;
                for (&j, &v) in a.idx[right..end].iter().zip(&a.val[right..end]) {
                    let v: f64 = v.into();
                    y[j as usize] += v * xi;
                    sum += v * x[j as usize];
                }
                y[i] += sum;
            }
        }
    }

    /// Block `k` of [`Self::backward`]: `x` its rows, and `y` with `PRODUCT` (else
    /// empty).
    fn backward_block<V: Copy + Into<f64>, const PRODUCT: bool>(
        &self,
        a: Rows<'_, V>,
        inv_diag: &[f64],
        b: &[f64],
        k: usize,
        x: &mut [f64],
        y: &mut [f64],
    ) {
        let (s, e) = (self.starts[k], self.starts[k + 1]);
        let mut cross = self.crossing[k].iter().rev().peekable();
        for il in (0..x.len()).rev() {
            let i = s + il;
            let (start, end) = (a.ptr[i], a.ptr[i + 1]);
            let row = &a.idx[start..end];
            let d = a.lower_len(i);
            debug_assert_eq!(row[d] as usize, i, "row {i} stores no diagonal");
            let diag: f64 = a.val[start + d].into();
            let (lower, vlower) = (&row[..d], &a.val[start..start + d]);
            let (upper, vupper) = (&row[d + 1..], &a.val[start + d + 1..end]);
            let xi_old = x[il];
            if cross.next_if_eq(&&(i as u32)).is_none() {
                let below = dot_local(lower, vlower, x, s);
                let above = dot_local(upper, vupper, x, s);
                let xi = xi_old + (b[i] - (below + diag * xi_old + above)) * inv_diag[i];
                x[il] = xi;
                if PRODUCT {
                    y[il] = above + diag * xi;
                    for (&j, &v) in upper.iter().zip(vupper) {
                        y[j as usize - s] += v.into() * xi;
                    }
                }
                continue;
            }
            // Entries outside the block read the values kept from before.
            let left = lower.partition_point(|&j| (j as usize) < s);
            let inside = upper.partition_point(|&j| (j as usize) < e);
            let below = dot_row(&lower[..left], &vlower[..left], &self.old)
                + dot_local(&lower[left..], &vlower[left..], x, s);
            let above = dot_local(&upper[..inside], &vupper[..inside], x, s);
            let outside = dot_row(&upper[inside..], &vupper[inside..], &self.old);
            let xi = xi_old + (b[i] - (below + diag * xi_old + above + outside)) * inv_diag[i];
            x[il] = xi;
            if PRODUCT {
                // The product's terms right of the block come after the sweep.
                y[il] = above + diag * xi;
                for (&j, &v) in upper[..inside].iter().zip(&vupper[..inside]) {
                    y[j as usize - s] += v.into() * xi;
                }
            }
        }
    }
}

/// `f(k, part)` for every block's part, side by side (on one thread, in order). The
/// blocks are independent: the order changes no value.
fn for_each_block<P: Send>(parts: Vec<P>, f: impl Fn(usize, P) + Sync) {
    parts.into_par_iter().enumerate().for_each(|(k, p)| f(k, p));
}

/// `Σ val_k x[idx_k − s]`: a row's dot product with the values of a block starting at
/// row `s`, summed as [`super::csr::dot_row`] sums.
#[inline(always)]
fn dot_local<V: Copy + Into<f64>>(idx: &[u32], val: &[V], x: &[f64], s: usize) -> f64 {
    dot_row_by(idx, val, |v| v.into(), |j| x[j as usize - s])
}
