//! A hierarchy kept while the matrix changes little: the finest level's operator (the
//! one the smoother sweeps and CG multiplies by) takes the new values, the coarser
//! levels, P and R stay, and the whole hierarchy is set up anew when the solves
//! degrade.
//!
//! Why it is sound: with the fine operator refreshed, the V-cycle is still a symmetric
//! positive definite preconditioner of the new matrix (forward and backward sweeps of
//! its own Gauss–Seidel around a coarse correction by any SPD coarse operator), so CG
//! converges to the new system's solution; only its rate depends on how far the coarse
//! levels have drifted from the new matrix's Galerkin ones. A time step's matrix
//! `M/Δt + K(T)` or a Newton Jacobian changes by a small relative amount from one
//! solve to the next, so the drift costs a few iterations where a set-up costs many.
//!
//! The rules: a matrix whose diagonal moved by more than [`DRIFT`] (relative, at any
//! row) from the one the hierarchy was set up for is not a small change (a new step
//! size, BDF1's `M/Δt` becoming BDF2's `3M/2Δt`) and gets a new set-up. The Krylov
//! iterations of the first solve after a set-up are the base; a later solve that needs
//! more than `base + base/2 + 3` marks the hierarchy as degraded, and the next matrix
//! is set up anew. A CG solve that fails to converge on a refreshed hierarchy is set up
//! anew at once and solved again.
//!
//! The 10 % is a bound on "little", not a tuned value: on the electronics warm-up at
//! 1.25 M unknowns BDF2's matrix moved no diagonal entry by more than that from BDF1's,
//! and its refreshed hierarchy took 27 iterations for the first BDF2 step against 26
//! for BDF1's own at refine 6 (`benches/electronics_scale.sh`).

use super::csr::Csr;
use super::{AmgCg, SolveError};

/// The largest relative change of a diagonal entry that a refresh serves.
pub const DRIFT: f64 = 0.1;

/// The state of a kept hierarchy.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Reuse {
    /// The Krylov iterations of the first solve after the last set-up.
    base: Option<usize>,
    /// A later solve took too many more: the next matrix gets a new set-up.
    degraded: bool,
    /// The finest level was refreshed since the last set-up.
    pub(super) refreshed: bool,
    /// Set-ups and refreshes since the solver was made.
    pub(super) setups: usize,
    pub(super) refreshes: usize,
    /// Whether the finest level's values are exactly symmetric (bit for bit): a matrix
    /// in column storage with the same values in the same order is then the same
    /// matrix. Found at the first comparison after a set-up or refresh.
    pub(super) symmetric: Option<bool>,
}

impl Reuse {
    /// A new hierarchy was set up.
    pub(super) fn set_up(&mut self) {
        self.base = None;
        self.degraded = false;
        self.refreshed = false;
        self.symmetric = None;
        self.setups += 1;
    }
}

/// Whether `diag` moved by more than [`DRIFT`] (relative, at any row) from the diagonal
/// whose inverse is `inv_diag` (the one a hierarchy was set up for).
pub(crate) fn drifted(inv_diag: &[f64], diag: &[f64]) -> bool {
    inv_diag
        .iter()
        .zip(diag)
        .any(|(&inv, &d)| (d * inv - 1.0).abs() > DRIFT)
}

/// How the last [`AmgCg::setup_or_refresh`] served its matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Served {
    /// A new hierarchy.
    SetUp,
    /// The kept hierarchy, its finest level refreshed.
    Refreshed,
    /// The kept hierarchy as it is: the matrix is its finest level's, bit for bit.
    Unchanged,
}

impl AmgCg {
    /// Serve `a`: refresh the finest level of the kept hierarchy when `a` has its
    /// structure and the solves since its set-up have not degraded (module docs),
    /// else set a new hierarchy up.
    pub fn setup_or_refresh(&mut self, a: Csr) -> Result<Served, SolveError> {
        let fits = !self.reuse.degraded
            && self.levels.first().is_some_and(|l| {
                l.a.nrows == a.nrows && l.a.ptr == a.ptr && l.a.idx == a.idx && !l.a.val.is_empty()
            });
        if !fits {
            self.setup(a)?;
            return Ok(Served::SetUp);
        }
        let diag = a.diagonal();
        if drifted(&self.levels[0].inv_diag, &diag) {
            self.setup(a)?;
            return Ok(Served::SetUp);
        }
        if let Some(row) = diag.iter().position(|&d| d <= 0.0 || !d.is_finite()) {
            return Err(SolveError::NotPositiveDefinite { row });
        }
        self.reuse.symmetric = None;
        let fine = &mut self.levels[0];
        fine.inv_diag = diag.iter().map(|d| 1.0 / d).collect();
        // (A finest level that sweeps in double precision keeps no single copy.)
        if !fine.a32.is_empty() {
            fine.a32 = a.val.iter().map(|&v| v as f32).collect();
        }
        fine.a = a;
        self.earlier.clear();
        self.reuse.refreshed = true;
        self.reuse.refreshes += 1;
        Ok(Served::Refreshed)
    }

    /// [`Self::setup_or_refresh`] of a matrix in column storage (its values checked
    /// finite, as [`LinearSolver::factor`](crate::solve::LinearSolver::factor) does).
    pub fn factor_or_refresh(
        &mut self,
        a: &faer::sparse::SparseColMat<usize, f64>,
    ) -> Result<Served, SolveError> {
        crate::solve::check_finite_ref(a.as_ref())?;
        let s = a.symbolic();
        let view = Csc {
            n: a.ncols(),
            col_ptr: s.col_ptr(),
            rows: s.row_idx(),
            val: a.val(),
        };
        match self.serve_kept(view)? {
            Some(served) => Ok(served),
            None => self.setup_or_refresh(Csr::from_csc(a.as_ref())),
        }
    }

    /// [`Self::factor_or_refresh`] of a square matrix given as its parts (column
    /// pointers, 32-bit rows ascending in each column, values): an assembler's pattern
    /// with its values apart, so no 64-bit copy of the structure is made. A new set-up
    /// takes the values (`val` is left empty) and copies the structure; a kept
    /// hierarchy leaves them.
    pub fn factor_or_refresh_parts(
        &mut self,
        col_ptr: &[usize],
        rows: &[u32],
        val: &mut Vec<f64>,
    ) -> Result<Served, SolveError> {
        let n = col_ptr.len() - 1;
        crate::solve::check_finite_parts(col_ptr, rows, val)?;
        let view = Csc {
            n,
            col_ptr,
            rows,
            val,
        };
        match self.serve_kept(view)? {
            Some(served) => Ok(served),
            None => self.setup_or_refresh(Csr::from_csc_parts(
                n,
                col_ptr.to_vec(),
                rows.to_vec(),
                std::mem::take(val),
            )),
        }
    }

    /// Serve `a` with the kept hierarchy as it is (the same matrix) or refreshed in
    /// its finest level's own arrays; `None` when it does not fit (none kept,
    /// degraded, another size or entry count).
    fn serve_kept<I: RowIndex>(&mut self, a: Csc<'_, I>) -> Result<Option<Served>, SolveError> {
        let Some(fine) = self.levels.first() else {
            return Ok(None);
        };
        let symmetric = *self
            .reuse
            .symmetric
            .get_or_insert_with(|| fine.a.is_exactly_symmetric());
        if same_matrix(&fine.a, symmetric, a) {
            return Ok(Some(Served::Unchanged));
        }
        self.refresh_in_place(a)
    }

    /// [`Self::setup_or_refresh`]'s refresh, written into the finest level's own
    /// arrays: no second copy of the matrix (at 1.25 M unknowns, 400 MB of rows and
    /// 130 MB of single-precision values) exists while the hierarchy is served. `None`
    /// when the kept hierarchy does not fit `a` (degraded, another structure): then
    /// the caller sets up anew. A diagonal that drifted sets up anew here, after the
    /// old hierarchy is let go.
    fn refresh_in_place<I: RowIndex>(
        &mut self,
        a: Csc<'_, I>,
    ) -> Result<Option<Served>, SolveError> {
        let Some(fine) = self.levels.first_mut() else {
            return Ok(None);
        };
        if self.reuse.degraded || fine.a.nrows != a.n || fine.a.val.len() != a.val.len() {
            return Ok(None);
        }
        let Some(diag) = a.diagonal() else {
            return Ok(None);
        };
        if drifted(&fine.inv_diag, &diag) {
            self.levels.clear();
            return Ok(None);
        }
        if let Some(row) = diag.iter().position(|&d| d <= 0.0 || !d.is_finite()) {
            return Err(SolveError::NotPositiveDefinite { row });
        }
        self.earlier.clear();
        if !a.transpose_into(&mut fine.a) {
            // Another structure met part-way: the finest level holds a mix, so the
            // hierarchy is let go and made anew from `a`.
            self.levels.clear();
            return Ok(None);
        }
        fine.inv_diag
            .iter_mut()
            .zip(&diag)
            .for_each(|(i, d)| *i = 1.0 / d);
        fine.a32
            .iter_mut()
            .zip(&fine.a.val)
            .for_each(|(s, &v)| *s = v as f32);
        self.reuse.symmetric = None;
        self.reuse.refreshed = true;
        self.reuse.refreshes += 1;
        Ok(Some(Served::Refreshed))
    }

    /// Record the Krylov iterations of a solve with the current hierarchy (the rule
    /// of the module docs).
    pub fn note_iterations(&mut self, iterations: usize) {
        match self.reuse.base {
            None => self.reuse.base = Some(iterations),
            Some(base) if iterations > base + base / 2 + 3 => self.reuse.degraded = true,
            Some(_) => {}
        }
    }

    /// The finest level was refreshed since the last set-up.
    pub fn is_refreshed(&self) -> bool {
        self.reuse.refreshed
    }

    /// Hierarchies set up and finest levels refreshed since the solver was made.
    pub fn reuse_counts(&self) -> (usize, usize) {
        (self.reuse.setups, self.reuse.refreshes)
    }

    /// After a failed solve on a refreshed hierarchy: set it up anew from the finest
    /// level's own (current) matrix. False when there is nothing to redo.
    pub(crate) fn set_up_again(&mut self) -> Result<bool, SolveError> {
        if !self.reuse.refreshed || self.levels.is_empty() || self.levels[0].a.val.is_empty() {
            return Ok(false);
        }
        let a = std::mem::take(&mut self.levels[0].a);
        self.setup(a)?;
        Ok(true)
    }
}

/// A row index of column storage: faer's 64-bit or a pattern's 32-bit.
pub(crate) trait RowIndex: Copy {
    fn ix(self) -> usize;
}

impl RowIndex for usize {
    fn ix(self) -> usize {
        self
    }
}

impl RowIndex for u32 {
    fn ix(self) -> usize {
        self as usize
    }
}

/// The diagonal of a square matrix in column storage, rows ascending in each column
/// (`None`: an entry missing): the distributed general solver's drift test.
#[cfg(feature = "mpi")]
pub(crate) fn diagonal_of(a: faer::sparse::SparseColMatRef<'_, usize, f64>) -> Option<Vec<f64>> {
    let s = a.symbolic();
    Csc {
        n: a.ncols(),
        col_ptr: s.col_ptr(),
        rows: s.row_idx(),
        val: a.val(),
    }
    .diagonal()
}

/// A square matrix in column storage, borrowed as its parts.
#[derive(Clone, Copy)]
pub(crate) struct Csc<'a, I> {
    pub(crate) n: usize,
    pub(crate) col_ptr: &'a [usize],
    pub(crate) rows: &'a [I],
    pub(crate) val: &'a [f64],
}

impl<I: RowIndex> Csc<'_, I> {
    fn col(&self, j: usize) -> std::ops::Range<usize> {
        self.col_ptr[j]..self.col_ptr[j + 1]
    }

    /// Column `j`'s entries `(row, value)`.
    pub(crate) fn column(&self, j: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        let range = self.col(j);
        (self.rows[range.clone()].iter().map(|&i| i.ix())).zip(self.val[range].iter().copied())
    }

    /// The diagonal (`None`: an entry missing).
    fn diagonal(&self) -> Option<Vec<f64>> {
        (0..self.n)
            .map(|j| {
                let r = self.col(j);
                let k = self.rows[r.clone()].partition_point(|&i| i.ix() < j);
                (r.start + k < r.end && self.rows[r.start + k].ix() == j)
                    .then(|| self.val[r.start + k])
            })
            .collect()
    }

    /// Write the matrix into `rows` (row storage) of the same structure, column by
    /// column through a cursor per row. False, with `rows` partly written, when the
    /// structures differ.
    fn transpose_into(&self, rows: &mut Csr) -> bool {
        if rows.ncols != self.n || rows.ptr.len() != self.n + 1 {
            return false;
        }
        let mut next: Vec<usize> = rows.ptr[..rows.nrows].to_vec();
        for j in 0..self.n {
            for p in self.col(j) {
                let i = self.rows[p].ix();
                let q = next[i];
                if q >= rows.ptr[i + 1] || rows.idx[q] as usize != j {
                    return false;
                }
                rows.val[q] = self.val[p];
                next[i] += 1;
            }
        }
        // Every row filled to its end: the same number of entries in each.
        next.iter().zip(&rows.ptr[1..]).all(|(n, end)| n == end)
    }
}

/// `a` (column storage) is `rows` (row storage), structure and values bit for bit: a
/// linear problem stepping with a fixed step needs no refresh, and no copy of the
/// values is kept to tell. When `rows` is exactly symmetric, `a`'s columns are its rows
/// and one pass in storage order tells; otherwise each column is walked into the rows.
fn same_matrix<I: RowIndex>(rows: &Csr, symmetric: bool, a: Csc<'_, I>) -> bool {
    if rows.nrows != a.n || rows.ncols != a.n || rows.val.len() != a.val.len() {
        return false;
    }
    let bits = |x: &f64, y: &f64| x.to_bits() == y.to_bits();
    if symmetric {
        return rows.ptr.as_slice() == a.col_ptr
            && rows
                .idx
                .iter()
                .zip(a.rows)
                .all(|(&i, &r)| i as usize == r.ix())
            && rows.val.iter().zip(a.val).all(|(x, y)| bits(x, y));
    }
    // Columns in order meet each row's entries in order: a cursor per row.
    let mut next: Vec<usize> = rows.ptr[..rows.nrows].to_vec();
    for j in 0..a.n {
        for p in a.col(j) {
            let i = a.rows[p].ix();
            let q = next[i];
            if q >= rows.ptr[i + 1] || rows.idx[q] as usize != j || !bits(&rows.val[q], &a.val[p]) {
                return false;
            }
            next[i] += 1;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::super::tests::{residual_norm, step_matrix};
    use super::*;
    use crate::solve::amg::AmgOptions;

    /// A matrix that changes a little is served by refreshing the kept hierarchy and
    /// solved to the tolerance all the same; a different structure, or solves that
    /// degrade, bring a new set-up.
    #[test]
    fn a_kept_hierarchy_serves_a_changed_matrix_and_is_set_up_again_when_it_degrades() {
        let n = 20_000;
        let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 100) as f64 / 100.0).collect();
        let mut s = AmgCg::new(AmgOptions {
            tolerance: 1e-10,
            ..AmgOptions::default()
        });
        let solve = |s: &mut AmgCg, a: &Csr| {
            let mut x = vec![0.0; n];
            let report = s.pcg(&b, &mut x).unwrap();
            let res = residual_norm(a, &x, &b);
            let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();
            assert!(res <= 1.01e-10 * bn, "residual {res:e} of {bn:e}");
            report.iterations
        };
        let a0 = step_matrix(n, 1.0);
        assert_eq!(s.setup_or_refresh(a0.clone()).unwrap(), Served::SetUp);
        let base = solve(&mut s, &a0);
        s.note_iterations(base);
        // Half as much mass again (BDF1 → BDF2): the diagonal moves by 17 %, set up anew.
        assert_eq!(
            s.setup_or_refresh(step_matrix(n, 1.5)).unwrap(),
            Served::SetUp
        );
        assert_eq!(s.setup_or_refresh(a0.clone()).unwrap(), Served::SetUp);
        let base = solve(&mut s, &a0);
        s.note_iterations(base);
        // 1 % more mass (the diagonal 0.3 %): refreshed, converges in about as many iterations.
        let a1 = step_matrix(n, 1.01);
        assert_eq!(s.setup_or_refresh(a1.clone()).unwrap(), Served::Refreshed);
        let its = solve(&mut s, &a1);
        assert!(its <= base + 2, "{its} iterations against {base}");
        s.note_iterations(its);
        assert_eq!(s.reuse_counts(), (3, 1));
        // A solve that needs many more marks the hierarchy degraded: set up anew.
        s.note_iterations(base * 3);
        assert_eq!(s.setup_or_refresh(a1.clone()).unwrap(), Served::SetUp);
        // The same matrix again, in column storage: served as it is.
        let csc = |a: &Csr| {
            let t: Vec<_> = (0..a.nrows)
                .flat_map(|i| (a.ptr[i]..a.ptr[i + 1]).map(move |p| (i, p)))
                .map(|(i, p)| faer::sparse::Triplet::new(i, a.idx[p] as usize, a.val[p]))
                .collect();
            faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(a.nrows, a.ncols, &t)
                .unwrap()
        };
        assert_eq!(s.factor_or_refresh(&csc(&a1)).unwrap(), Served::Unchanged);
        // Refreshed in the finest level's own arrays: CG then solves the new matrix
        // (its residual is measured against `a2` itself, not the hierarchy's copy).
        let a2 = step_matrix(n, 1.02);
        assert_eq!(s.factor_or_refresh(&csc(&a2)).unwrap(), Served::Refreshed);
        let its = solve(&mut s, &a2);
        s.note_iterations(its);
        // The same size and count of entries, another structure ((0, 1) moved to
        // (0, 2), and its transpose): found while writing, set up anew.
        let moved: Vec<_> = (0..n)
            .flat_map(|i| (a2.ptr[i]..a2.ptr[i + 1]).map(move |p| (i, p)))
            .map(|(i, p)| {
                let j = a2.idx[p] as usize;
                let (i, j) = match (i, j) {
                    (0, 1) => (0, 2),
                    (1, 0) => (2, 0),
                    ij => ij,
                };
                faer::sparse::Triplet::new(i, j, a2.val[p])
            })
            .collect();
        let moved =
            faer::sparse::SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &moved).unwrap();
        assert_eq!(s.factor_or_refresh(&moved).unwrap(), Served::SetUp);
        // The same served from a pattern's parts (32-bit rows, values apart): the
        // matrix the hierarchy holds is unchanged, a changed one is refreshed and its
        // values left to the caller, and a new set-up takes them.
        let parts = |a: &faer::sparse::SparseColMat<usize, f64>| {
            let s = a.symbolic();
            let rows: Vec<u32> = s.row_idx().iter().map(|&r| r as u32).collect();
            (s.col_ptr().to_vec(), rows, a.val().to_vec())
        };
        let (ptr, rows, mut val) = parts(&moved);
        assert_eq!(
            s.factor_or_refresh_parts(&ptr, &rows, &mut val).unwrap(),
            Served::Unchanged
        );
        let (ptr, rows, mut val) = parts(&csc(&a2));
        assert_eq!(
            s.factor_or_refresh_parts(&ptr, &rows, &mut val).unwrap(),
            Served::SetUp
        );
        assert!(val.is_empty(), "a set-up takes the values");
        let base = solve(&mut s, &a2);
        s.note_iterations(base);
        let a3 = step_matrix(n, 1.03);
        let (ptr, rows, mut val) = parts(&csc(&a3));
        assert_eq!(
            s.factor_or_refresh_parts(&ptr, &rows, &mut val).unwrap(),
            Served::Refreshed
        );
        assert_eq!(val.len(), a3.val.len(), "a refresh leaves the values");
        let its = solve(&mut s, &a3);
        s.note_iterations(its);
        // A drifted diagonal, and another structure, in column storage: set up anew.
        assert_eq!(
            s.factor_or_refresh(&csc(&step_matrix(n, 1.5))).unwrap(),
            Served::SetUp
        );
        assert_eq!(
            s.factor_or_refresh(&csc(&step_matrix(n - 1, 1.5))).unwrap(),
            Served::SetUp
        );
        // Another structure is always set up anew.
        assert_eq!(
            s.setup_or_refresh(step_matrix(n - 1, 1.0)).unwrap(),
            Served::SetUp
        );
        assert_eq!(s.reuse_counts(), (9, 3));
    }
}
