//! The AMG's own sparse storage: compressed sparse rows with 32-bit column indices,
//! built from faer's CSC (copying, or transposing the values of a structurally
//! symmetric matrix in place), with the products the set-up needs (`spmv`, Gustavson's
//! row-by-row `matmul`, `transpose`).

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use rayon::prelude::*;

/// Columns per block of [`Csr::transpose`]'s first pass: a block's entries (a few
/// hundred thousand at most on a fine level) are scattered to their columns within the
/// cache.
const TRANSPOSE_BLOCK_COLUMNS: usize = 1024;

/// A compressed sparse row matrix, the AMG's own storage (row access for smoothing).
#[derive(Clone, Debug, Default)]
pub struct Csr {
    pub nrows: usize,
    pub ncols: usize,
    pub ptr: Vec<usize>,
    /// Column indices, 32 bits (a dof is 32 bits): a third less memory traffic per
    /// stored entry than `usize` in every product and smoothing sweep.
    pub idx: Vec<u32>,
    pub val: Vec<f64>,
}

impl Csr {
    /// Row storage of a faer CSC matrix (a transpose of index arrays).
    pub fn from_csc(a: SparseColMatRef<'_, usize, f64>) -> Csr {
        let s = a.symbolic();
        let (m, n) = (a.nrows(), a.ncols());
        let mut ptr = vec![0usize; m + 1];
        for j in 0..n {
            for &i in &s.row_idx()[s.col_range(j)] {
                ptr[i + 1] += 1;
            }
        }
        for i in 0..m {
            ptr[i + 1] += ptr[i];
        }
        let nnz = ptr[m];
        let mut idx = vec![0; nnz];
        let mut val = vec![0.0; nnz];
        let mut next = ptr.clone();
        for j in 0..n {
            for p in s.col_range(j) {
                let i = s.row_idx()[p];
                idx[next[i]] = j as u32;
                val[next[i]] = a.val()[p];
                next[i] += 1;
            }
        }
        Csr {
            nrows: m,
            ncols: n,
            ptr,
            idx,
            val,
        }
    }

    /// Row storage of a CSC matrix given as its structure and values, taking the
    /// values. A structurally symmetric matrix (each stored `(i, j)` has its `(j, i)`,
    /// as assembled patterns do) has its columns' structure as rows: its values are
    /// transposed in place, pair by pair, and nothing else is copied but the indices.
    /// Any other matrix goes through [`Self::from_csc`]. The same result either way.
    pub fn from_csc_values(sym: SymbolicSparseColMatRef<'_, usize>, val: Vec<f64>) -> Csr {
        assert_eq!(sym.row_idx().len(), val.len(), "one value per stored entry");
        if sym.nrows() != sym.ncols() || sym.col_nnz().is_some() {
            return Csr::from_csc(SparseColMatRef::new(sym, &val));
        }
        let rows = sym.row_idx().iter().map(|&i| i as u32).collect();
        Csr::from_csc_parts(sym.ncols(), sym.col_ptr().to_vec(), rows, val)
    }

    /// [`Self::from_csc_values`] of a square CSC matrix given as its parts (column
    /// pointers, 32-bit rows ascending in each column, values), all taken: for a
    /// structurally symmetric matrix they become the rows as they are, its values
    /// transposed in place, with no copy at all.
    pub fn from_csc_parts(n: usize, ptr: Vec<usize>, ri: Vec<u32>, mut val: Vec<f64>) -> Csr {
        assert_eq!(
            ptr.len(),
            n + 1,
            "one column pointer per column, and the end"
        );
        assert_eq!(ri.len(), val.len(), "one value per stored entry");
        // Each stored (i, j) below the diagonal meets its (j, i) in column i: the rows
        // asked of column i come in increasing j, so one cursor per column suffices.
        // The values are swapped as the pairs are found, the first `limit` pairs only;
        // returns the pairs swapped, the entries above the diagonal seen, and whether
        // every pair was found. Swapping the same pairs again undoes it.
        let walk = |val: &mut [f64], limit: usize| -> (usize, usize, bool) {
            let mut cursor: Vec<usize> = ptr[..n].to_vec();
            let (mut lower, mut upper) = (0usize, 0usize);
            for j in 0..n {
                for p in ptr[j]..ptr[j + 1] {
                    let i = ri[p] as usize;
                    if i < j {
                        upper += 1;
                        continue;
                    }
                    if i == j {
                        continue;
                    }
                    if lower == limit {
                        return (lower, upper, true);
                    }
                    let end = ptr[i + 1];
                    while cursor[i] < end && (ri[cursor[i]] as usize) < j {
                        cursor[i] += 1;
                    }
                    if cursor[i] == end || ri[cursor[i]] as usize != j {
                        return (lower, upper, false);
                    }
                    val.swap(p, cursor[i]);
                    lower += 1;
                }
            }
            (lower, upper, true)
        };
        // One pass for a symmetric structure (the usual case); another to undo the
        // swaps of any other before transposing it.
        let (lower, upper, paired) = walk(&mut val, usize::MAX);
        if !paired || lower != upper {
            walk(&mut val, lower);
            let rows: Vec<usize> = ri.iter().map(|&i| i as usize).collect();
            let sym = SymbolicSparseColMatRef::new_checked(n, n, &ptr, None, &rows);
            return Csr::from_csc(SparseColMatRef::new(sym, &val));
        }
        Csr {
            nrows: n,
            ncols: n,
            ptr,
            idx: ri,
            val,
        }
    }

    pub fn nnz(&self) -> usize {
        self.idx.len()
    }

    pub fn transpose(&self) -> Csr {
        let (m, n, nnz) = (self.nrows, self.ncols, self.nnz());
        let mut ptr = vec![0usize; n + 1];
        for &j in &self.idx {
            ptr[j as usize + 1] += 1;
        }
        for j in 0..n {
            ptr[j + 1] += ptr[j];
        }
        // In two passes: the entries first go to their block of columns, in row order,
        // then each block's to their columns. Written straight to their columns, the
        // entries of a row of the fine level's P (1.16 M × 46 000, 6.7 M entries) went
        // to thousands of places at once, each on its own page, and took 0.21 s; a
        // block's columns fit in the cache and the blocks are few.
        let block = TRANSPOSE_BLOCK_COLUMNS;
        let nblocks = n.div_ceil(block).max(1);
        let mut start: Vec<usize> = (0..=nblocks).map(|b| ptr[(b * block).min(n)]).collect();
        let mut staged: Vec<(u32, u32, f64)> = vec![(0, 0, 0.0); nnz];
        for i in 0..m {
            for p in self.ptr[i]..self.ptr[i + 1] {
                let j = self.idx[p];
                let b = j as usize / block;
                staged[start[b]] = (j, i as u32, self.val[p]);
                start[b] += 1;
            }
        }
        let mut idx = vec![0u32; nnz];
        let mut val = vec![0.0; nnz];
        let mut next = ptr.clone();
        for &(j, i, v) in &staged {
            let at = &mut next[j as usize];
            idx[*at] = i;
            val[*at] = v;
            *at += 1;
        }
        Csr {
            nrows: n,
            ncols: m,
            ptr,
            idx,
            val,
        }
    }

    /// `y = A x`, rows in parallel.
    pub fn spmv(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, yi)| {
                let row = self.ptr[i]..self.ptr[i + 1];
                *yi = dot_row(&self.idx[row.clone()], &self.val[row], x);
            });
    }

    /// `self · b` by Gustavson's row-by-row product; rows in parallel chunks,
    /// concatenated in order (deterministic).
    pub fn matmul(&self, b: &Csr) -> Csr {
        self.matmul_rows(None, b, true)
    }

    /// Rows `rows` (all when `None`) of `self · b`, each made as [`Self::matmul`]
    /// makes it; with `sorted` false each row keeps its columns in the order they were
    /// first reached (the same values: only the final sort is left out), for a product
    /// that reads the rows through a scatter and never needs them in order.
    pub(super) fn matmul_rows(&self, rows: Option<&[u32]>, b: &Csr, sorted: bool) -> Csr {
        const CHUNK: usize = 2048;
        let m = rows.map_or(self.nrows, <[u32]>::len);
        let chunks: Vec<(Vec<usize>, Vec<u32>, Vec<f64>)> = (0..m.div_ceil(CHUNK))
            .into_par_iter()
            // The scatter's marker and sums, made once per worker: a row's marker is
            // its own index, so a row never sees another's marks.
            .map_init(
                || (vec![usize::MAX; b.ncols], vec![0.0; b.ncols]),
                |(marker, acc), c| {
                    let rows = (c * CHUNK..((c + 1) * CHUNK).min(m))
                        .map(|k| rows.map_or(k, |r| r[k] as usize));
                    let (mut lens, mut idx, mut val) = (Vec::new(), Vec::new(), Vec::new());
                    for (k, i) in rows.enumerate() {
                        // The mark of output row `c·CHUNK + k`: distinct for every row
                        // of this product, even where `rows` repeats a row.
                        let mark = c * CHUNK + k;
                        let start = idx.len();
                        for p in self.ptr[i]..self.ptr[i + 1] {
                            let (k, aik) = (self.idx[p] as usize, self.val[p]);
                            for q in b.ptr[k]..b.ptr[k + 1] {
                                let j = b.idx[q] as usize;
                                if marker[j] != mark {
                                    marker[j] = mark;
                                    acc[j] = 0.0;
                                    idx.push(j as u32);
                                }
                                acc[j] += aik * b.val[q];
                            }
                        }
                        if sorted {
                            idx[start..].sort_unstable();
                        }
                        val.extend(idx[start..].iter().map(|&j| acc[j as usize]));
                        lens.push(idx.len() - start);
                    }
                    (lens, idx, val)
                },
            )
            .collect();
        let mut out = Csr {
            nrows: m,
            ncols: b.ncols,
            ptr: Vec::with_capacity(m + 1),
            ..Csr::default()
        };
        out.ptr.push(0);
        for (lens, idx, val) in chunks {
            for l in lens {
                let last = *out.ptr.last().unwrap();
                out.ptr.push(last + l);
            }
            out.idx.extend(idx);
            out.val.extend(val);
        }
        out
    }

    /// Square, with `a_ji` equal to `a_ij` bit for bit wherever either is stored.
    pub(super) fn is_exactly_symmetric(&self) -> bool {
        if self.nrows != self.ncols {
            return false;
        }
        // Rows in order meet each column's entries in order: a cursor per row.
        let mut next: Vec<usize> = self.ptr[..self.nrows].to_vec();
        for i in 0..self.nrows {
            for p in self.ptr[i]..self.ptr[i + 1] {
                let j = self.idx[p] as usize;
                let q = next[j];
                if q >= self.ptr[j + 1]
                    || self.idx[q] as usize != i
                    || self.val[q].to_bits() != self.val[p].to_bits()
                {
                    return false;
                }
                next[j] += 1;
            }
        }
        true
    }

    /// Per row, how many of its entries lie left of the diagonal (columns below the
    /// row's index, the columns ascending): the diagonal's offset in the row.
    pub(super) fn diagonal_offsets(&self) -> Vec<u32> {
        (0..self.nrows)
            .map(|i| {
                let row = &self.idx[self.ptr[i]..self.ptr[i + 1]];
                row.partition_point(|&j| (j as usize) < i) as u32
            })
            .collect()
    }

    pub(super) fn diagonal(&self) -> Vec<f64> {
        (0..self.nrows)
            .map(|i| {
                (self.ptr[i]..self.ptr[i + 1])
                    .find(|&p| self.idx[p] as usize == i)
                    .map_or(0.0, |p| self.val[p])
            })
            .collect()
    }
}

/// `Σ_k val_k x[idx_k]`, a row of a sparse matrix times `x`, in four interleaved partial
/// sums added pairwise at the end. One running sum makes each product wait for the
/// last addition: a hex mesh's row has 27 entries, and that chain, not the memory,
/// bounded the sweeps. Four chains took a forward Gauss–Seidel sweep of a 1.09 M-row,
/// 28.9 M-entry Q1 matrix from 20.8 to 17.7 ms and a product from 21.7 to 18 ms. The
/// order of the sums is fixed, so the bits do not depend on the thread count.
#[inline(always)]
pub(super) fn dot_row<V: Copy + Into<f64>>(idx: &[u32], val: &[V], x: &[f64]) -> f64 {
    dot_row_of(idx, val, x, |v| v.into())
}

/// [`dot_row`] of the values `f(val_k)`.
#[inline(always)]
pub(super) fn dot_row_of<V: Copy>(idx: &[u32], val: &[V], x: &[f64], f: impl Fn(V) -> f64) -> f64 {
    dot_row_by(idx, val, f, |j| x[j as usize])
}

/// [`dot_row`] of the values `f(val_k)` and the entries `at(idx_k)` (a vector that
/// holds only some rows, say).
#[inline(always)]
pub(super) fn dot_row_by<V: Copy>(
    idx: &[u32],
    val: &[V],
    f: impl Fn(V) -> f64,
    at: impl Fn(u32) -> f64,
) -> f64 {
    let mut acc = [0.0f64; 4];
    let (mut ci, mut cv) = (idx.chunks_exact(4), val.chunks_exact(4));
    for (j, v) in (&mut ci).zip(&mut cv) {
        for k in 0..4 {
            acc[k] += f(v[k]) * at(j[k]);
        }
    }
    // The last entries into the sums they would have gone to in a longer row: a
    // row's leading part (a sweep from zero reads the entries left of the diagonal)
    // then sums as the whole row does where the rest multiplies zeros.
    for (k, (&j, &v)) in ci.remainder().iter().zip(cv.remainder()).enumerate() {
        acc[k] += f(v) * at(j);
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// A matrix's rows with values of type `V` over a [`Csr`]'s structure: the V-cycle
/// reads its levels through these, with the single-precision copies of their values.
#[derive(Clone, Copy)]
pub(super) struct Rows<'a, V> {
    pub(super) nrows: usize,
    pub(super) ptr: &'a [usize],
    pub(super) idx: &'a [u32],
    pub(super) val: &'a [V],
    /// Per row, the offset of its diagonal entry in the row ([`Csr::diagonal_offsets`]):
    /// the sweeps that split a row at its diagonal read it ([`Rows::with_diagonal`]);
    /// empty for rows only multiplied.
    pub(super) diag: &'a [u32],
}

impl<'a> Csr {
    /// The rows of `self`'s structure with the values `val` (one per stored entry).
    pub(super) fn with_values<V>(&'a self, val: &'a [V]) -> Rows<'a, V> {
        assert_eq!(val.len(), self.idx.len(), "one value per stored entry");
        Rows {
            nrows: self.nrows,
            ptr: &self.ptr,
            idx: &self.idx,
            val,
            diag: &[],
        }
    }
}

impl<'a, V> Rows<'a, V> {
    /// The same rows, with the offsets of their diagonals as
    /// [`Csr::diagonal_offsets`] made them, for the sweeps that split each row there
    /// (made once per level rather than searched for in every row on every sweep).
    pub(super) fn with_diagonal(self, diag: &'a [u32]) -> Self {
        assert_eq!(diag.len(), self.nrows, "one diagonal offset per row");
        Rows { diag, ..self }
    }

    /// How many entries of row `i` lie left of its diagonal (columns below `i`): the
    /// diagonal's offset in the row. Needs [`Self::with_diagonal`].
    #[inline(always)]
    pub(super) fn lower_len(&self, i: usize) -> usize {
        self.diag[i] as usize
    }
}

impl<V: Copy + Into<f64> + Sync> Rows<'_, V> {
    /// `y = A x`, rows in parallel (as [`Csr::spmv`]).
    pub(super) fn spmv(&self, x: &[f64], y: &mut [f64]) {
        y.par_iter_mut()
            .with_min_len(1024)
            .enumerate()
            .for_each(|(i, yi)| {
                let row = self.ptr[i]..self.ptr[i + 1];
                *yi = dot_row(&self.idx[row.clone()], &self.val[row], x);
            });
    }
}
