//! Linear solvers for the assembled system, all behind one interface, [`LinearSolver`]:
//! `factor(&A)` (set-up; direct solvers keep their symbolic factorisation while the
//! pattern of `A` is unchanged) then `solve(&mut b)` (in place: `b` becomes `x`).
//!
//! Strategies:
//! - [`Cholesky`]: sparse LLᵀ (faer, supernodal) for SPD matrices, fed a METIS
//!   nested-dissection ordering ([`Ordering::Metis`], falling back to AMD if METIS
//!   fails) or AMD;
//! - [`SaddleLdlt`]: LDLᵀ with sign-regularised pivots for saddle-point systems
//!   `[K Cᵀ; C 0]` (signs +1 on primal rows, −1 on multiplier rows), followed by
//!   iterative refinement against the unregularised matrix;
//! - [`Lu`]: faer sparse LU with partial pivoting for non-symmetric matrices (Newton
//!   Jacobians with dk/dT) and as a reference;
//! - [`AmgCg`]: conjugate gradients preconditioned by a smoothed-aggregation algebraic
//!   multigrid V-cycle, for systems too large to factor (see [`amg`]).
//!
//! Dirichlet conditions are applied by symmetric elimination in place
//! ([`apply_dirichlet`]): the pattern and the symbolic factorisation stay valid.
//!
//! Conventions: matrices are faer `SparseColMat<usize, f64>` with both triangles stored
//! (as [`crate::assembly`] builds them); the direct SPD and LDLᵀ solvers read only the
//! lower triangle. Rows are plain `usize` indices of the matrix. Errors say where: the
//! row of a bad pivot in the original (unpermuted) numbering, the (row, column) of a
//! non-finite entry.

pub mod amg;
mod direct;
mod gmres;

pub use amg::{AmgCg, AmgOptions, FineRadius, Smoother};
#[cfg(feature = "mpi")]
pub(crate) use direct::metis_lock;
pub use direct::{Cholesky, Lu, Ordering, SaddleLdlt, metis_ordering};
pub use gmres::BlockGmres;

use faer::sparse::{SparseColMat, SparseColMatMut, SparseColMatRef};
use rayon::prelude::*;

/// Errors of factorisation and solution.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SolveError {
    #[error(
        "matrix entry ({row}, {col}) is not finite ({value})\n  help: check the element or coupling that writes this entry"
    )]
    NonFinite { row: usize, col: usize, value: f64 },
    #[error("right-hand side entry {row} is not finite ({value})")]
    NonFiniteRhs { row: usize, value: f64 },
    #[error(
        "zero or negative pivot at row {row}: the matrix is not positive definite\n  help: check for a missing Dirichlet condition (floating region) or a multiplier row given to Cholesky"
    )]
    NotPositiveDefinite { row: usize },
    #[error("zero pivot at row {row} in the LDLᵀ factorisation (regularisation failed)")]
    ZeroPivot { row: usize },
    #[error("LU factorisation failed: {0}")]
    Singular(String),
    #[error(
        "no convergence after {iterations} iterations: relative residual {residual:.3e} > {tolerance:.1e}"
    )]
    NotConverged {
        iterations: usize,
        residual: f64,
        tolerance: f64,
    },
    #[error("size mismatch: matrix has {matrix} rows, vector has {vector}")]
    Dimension { matrix: usize, vector: usize },
    #[error("Dirichlet dof {dof} is outside 0..{n}")]
    DirichletOutOfRange { dof: usize, n: usize },
    #[error("Dirichlet value for dof {dof} is not finite ({value})")]
    DirichletNonFinite { dof: usize, value: f64 },
    #[error("dof {dof} has no stored diagonal entry")]
    MissingDiagonal { dof: usize },
    #[error("solve called before factor")]
    NotFactored,
    #[error("{0}")]
    Faer(String),
    /// The distributed solve of a run under MPI (PETSc) failed.
    #[error("distributed solve: {0}")]
    Distributed(String),
}

/// What one solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    /// Krylov iterations or refinement steps.
    pub iterations: usize,
    /// Final relative residual ‖b − Ax‖/‖b‖ when the solver measures it, else `NaN`.
    pub residual: f64,
}

/// One interface for every strategy: factor (or set up) once per matrix, solve many.
pub trait LinearSolver {
    /// Set up for `a`; reuses the symbolic analysis when `a` has the pattern of the
    /// previous call.
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError>;
    /// Solve `A x = b` in place.
    fn solve(&mut self, b: &mut [f64]) -> Result<SolveReport, SolveError>;
}

/// Reject a matrix with a non-finite stored entry, naming it.
pub fn check_finite(a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
    check_finite_ref(a.as_ref())
}

/// [`check_finite`] of a borrowed matrix.
pub fn check_finite_ref(a: SparseColMatRef<'_, usize, f64>) -> Result<(), SolveError> {
    let s = a.symbolic();
    let (ri, v) = (s.row_idx(), a.val());
    for col in 0..a.ncols() {
        for p in s.col_range(col) {
            if !v[p].is_finite() {
                return Err(SolveError::NonFinite {
                    row: ri[p],
                    col,
                    value: v[p],
                });
            }
        }
    }
    Ok(())
}

/// [`check_finite`] of a square CSC matrix given as its parts (column pointers, 32-bit
/// rows, values).
pub fn check_finite_parts(col_ptr: &[usize], rows: &[u32], vals: &[f64]) -> Result<(), SolveError> {
    match vals.iter().position(|v| !v.is_finite()) {
        None => Ok(()),
        Some(p) => Err(SolveError::NonFinite {
            row: rows[p] as usize,
            col: col_ptr.partition_point(|&start| start <= p) - 1,
            value: vals[p],
        }),
    }
}

pub(crate) fn check_rhs(n: usize, b: &[f64]) -> Result<(), SolveError> {
    if b.len() != n {
        return Err(SolveError::Dimension {
            matrix: n,
            vector: b.len(),
        });
    }
    if let Some(row) = b.iter().position(|x| !x.is_finite()) {
        return Err(SolveError::NonFiniteRhs { row, value: b[row] });
    }
    Ok(())
}

/// `y = A x` for a CSC matrix with both triangles stored (general: no symmetry used).
pub fn spmv(a: &SparseColMat<usize, f64>, x: &[f64], y: &mut [f64]) {
    spmv_ref(a.as_ref(), x, y)
}

/// [`spmv`] of a borrowed matrix (e.g. a pattern's structure with values kept apart).
pub fn spmv_ref(a: SparseColMatRef<'_, usize, f64>, x: &[f64], y: &mut [f64]) {
    let s = a.symbolic();
    let (ri, v) = (s.row_idx(), a.val());
    y.fill(0.0);
    for (j, &xj) in x.iter().enumerate().take(a.ncols()) {
        for p in s.col_range(j) {
            y[ri[p]] += v[p] * xj;
        }
    }
}

/// [`spmv`] of a square CSC matrix given as its parts (column pointers, 32-bit rows,
/// values): the same sums in the same order, so the same bits.
pub fn spmv_parts(col_ptr: &[usize], rows: &[u32], vals: &[f64], x: &[f64], y: &mut [f64]) {
    y.fill(0.0);
    for (j, &xj) in x.iter().enumerate().take(col_ptr.len() - 1) {
        for p in col_ptr[j]..col_ptr[j + 1] {
            y[rows[p] as usize] += vals[p] * xj;
        }
    }
}

/// ‖b − A x‖₂ / ‖b‖₂ (or ‖b − A x‖₂ when b = 0).
pub fn relative_residual(a: &SparseColMat<usize, f64>, x: &[f64], b: &[f64]) -> f64 {
    let mut r = vec![0.0; b.len()];
    spmv(a, x, &mut r);
    let num: f64 = r
        .iter()
        .zip(b)
        .map(|(r, b)| (b - r).powi(2))
        .sum::<f64>()
        .sqrt();
    let den = norm(b);
    if den > 0.0 { num / den } else { num }
}

/// Entries per partial sum of the parallel reductions. Fixed, so a sum is made of the
/// same partial sums in the same order on any number of threads: results do not depend
/// on the thread count.
pub(crate) const REDUCE_CHUNK: usize = 4096;

/// `a · b`, in fixed chunks summed in order (the same bits on any number of threads).
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let parts: Vec<f64> = a
        .par_chunks(REDUCE_CHUNK)
        .zip(b.par_chunks(REDUCE_CHUNK))
        .map(|(a, b)| a.iter().zip(b).map(|(a, b)| a * b).sum::<f64>())
        .collect();
    parts.iter().sum()
}

pub(crate) fn norm(x: &[f64]) -> f64 {
    dot(x, x).sqrt()
}

/// Apply Dirichlet conditions `(dof, value)` by symmetric elimination, in place:
/// `b_i −= A_ik g_k` for free rows `i`, then row and column `k` are zeroed, `A_kk = 1`
/// and `b_k = g_k`. The matrix stays symmetric if it was, and its pattern is unchanged
/// (zeros stay stored), so a kept symbolic factorisation remains valid. A dof listed
/// twice takes its last value.
pub fn apply_dirichlet(
    a: &mut SparseColMat<usize, f64>,
    b: &mut [f64],
    bcs: &[(usize, f64)],
) -> Result<(), SolveError> {
    let (sym, vals) = a.parts_mut();
    apply_dirichlet_mut(SparseColMatMut::new(sym, vals), b, bcs)
}

/// [`apply_dirichlet`] on a borrowed matrix (e.g. a pattern's structure with values
/// kept apart).
pub fn apply_dirichlet_mut(
    a: SparseColMatMut<'_, usize, f64>,
    b: &mut [f64],
    bcs: &[(usize, f64)],
) -> Result<(), SolveError> {
    let n = a.nrows();
    let (sym, vals) = a.parts_mut();
    let ri = sym.row_idx();
    dirichlet_by(n, sym.col_ptr(), |p| ri[p], vals, b, bcs)
}

/// [`apply_dirichlet`] on a square CSC matrix given as its parts (column pointers,
/// 32-bit rows, values).
pub fn apply_dirichlet_parts(
    col_ptr: &[usize],
    rows: &[u32],
    vals: &mut [f64],
    b: &mut [f64],
    bcs: &[(usize, f64)],
) -> Result<(), SolveError> {
    dirichlet_by(
        col_ptr.len() - 1,
        col_ptr,
        |p| rows[p] as usize,
        vals,
        b,
        bcs,
    )
}

/// The elimination of [`apply_dirichlet`] over `n` columns, `row(p)` the row of stored
/// entry `p`.
// Entry positions index the values and name the rows alike.
#[allow(clippy::needless_range_loop)]
fn dirichlet_by(
    n: usize,
    col_ptr: &[usize],
    row: impl Fn(usize) -> usize,
    vals: &mut [f64],
    b: &mut [f64],
    bcs: &[(usize, f64)],
) -> Result<(), SolveError> {
    if b.len() != n {
        return Err(SolveError::Dimension {
            matrix: n,
            vector: b.len(),
        });
    }
    let mut fixed: Vec<Option<f64>> = vec![None; n];
    for &(dof, value) in bcs {
        if dof >= n {
            return Err(SolveError::DirichletOutOfRange { dof, n });
        }
        if !value.is_finite() {
            return Err(SolveError::DirichletNonFinite { dof, value });
        }
        fixed[dof] = Some(value);
    }
    // Move known values to the right-hand side (reads A before any entry is zeroed).
    for j in 0..n {
        if let Some(g) = fixed[j] {
            for p in col_ptr[j]..col_ptr[j + 1] {
                let i = row(p);
                if fixed[i].is_none() {
                    b[i] -= vals[p] * g;
                }
            }
        }
    }
    for j in 0..n {
        let mut has_diag = false;
        for p in col_ptr[j]..col_ptr[j + 1] {
            let i = row(p);
            if i == j && fixed[j].is_some() {
                vals[p] = 1.0;
                has_diag = true;
            } else if fixed[i].is_some() || fixed[j].is_some() {
                vals[p] = 0.0;
            }
        }
        if fixed[j].is_some() && !has_diag {
            return Err(SolveError::MissingDiagonal { dof: j });
        }
    }
    for (k, g) in fixed.iter().enumerate() {
        if let Some(g) = g {
            b[k] = *g;
        }
    }
    Ok(())
}

/// The 7-point finite-difference Laplacian on an `n × n × n` grid of interior unknowns
/// (homogeneous Dirichlet outside, h = 1): 6 on the diagonal, −1 to each grid
/// neighbour. A standard SPD test and benchmark matrix, both triangles stored.
pub fn laplacian_7pt(n: usize) -> SparseColMat<usize, f64> {
    use faer::sparse::Triplet;
    let id = |i: usize, j: usize, k: usize| i + n * (j + n * k);
    let mut t = Vec::with_capacity(7 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let r = id(i, j, k);
                t.push(Triplet::new(r, r, 6.0));
                let mut nb = |c: usize| t.push(Triplet::new(r, c, -1.0));
                if i > 0 {
                    nb(id(i - 1, j, k));
                }
                if i + 1 < n {
                    nb(id(i + 1, j, k));
                }
                if j > 0 {
                    nb(id(i, j - 1, k));
                }
                if j + 1 < n {
                    nb(id(i, j + 1, k));
                }
                if k > 0 {
                    nb(id(i, j, k - 1));
                }
                if k + 1 < n {
                    nb(id(i, j, k + 1));
                }
            }
        }
    }
    SparseColMat::try_new_from_triplets(n * n * n, n * n * n, &t).expect("valid triplets")
}
