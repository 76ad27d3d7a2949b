//! Direct solvers on faer's low-level sparse Cholesky (LLᵀ and sign-regularised LDLᵀ)
//! and sparse LU, with a METIS nested-dissection ordering.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::cholesky::llt::factor::LltError;
use faer::linalg::cholesky::llt::factor::LltRegularization;
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{
    CholeskySymbolicParams, LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering, factorize_symbolic_cholesky,
};
use faer::sparse::linalg::solvers::{Lu as FaerLu, SymbolicLu};
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Side};

use super::{LinearSolver, SolveError, SolveReport, check_finite, check_rhs, norm, spmv};

/// Fill-reducing ordering for the symmetric factorisations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Ordering {
    /// METIS nested dissection (`METIS_NodeND`) on the graph of the matrix; AMD if
    /// METIS fails. Less fill than AMD on 3-D meshes.
    #[default]
    Metis,
    /// faer's approximate minimum degree.
    Amd,
}

/// Held around every METIS call. METIS draws its random numbers from one generator in
/// process-global state (GKlib's `static uint64_t mt[]`, seeded at each call), so two
/// calls on two threads at once (a host factoring on several threads, or tests in one
/// process) interleave their draws and may get another ordering than the same call
/// alone — and race on that state. One call at a time keeps each ordering the one its
/// graph gives, so runs stay bit-for-bit repeatable.
pub(crate) fn metis_lock() -> std::sync::MutexGuard<'static, ()> {
    static METIS: std::sync::Mutex<()> = std::sync::Mutex::new(());
    // A panic while held cannot leave METIS's state inconsistent for the next seeded call.
    METIS
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// Nested-dissection permutation `(perm, iperm)` of the graph of `a` (off-diagonal
/// pattern, symmetrised): position `i` of the reordered matrix holds row `perm[i]`.
/// `None` if METIS reports an error or the size does not fit METIS's 32-bit indices.
pub fn metis_ordering(a: &SymbolicSparseColMat<usize>) -> Option<(Vec<usize>, Vec<usize>)> {
    let n = a.nrows();
    if n == 0 || n > i32::MAX as usize / 2 {
        return None;
    }
    // The graph of a symmetric-pattern matrix: column j's rows are j's neighbours.
    // Symmetrise anyway (an unsymmetric coupling must still give an undirected graph).
    let mut deg = vec![0usize; n];
    for j in 0..n {
        for &i in &a.row_idx()[a.col_range(j)] {
            if i != j {
                deg[i] += 1;
                deg[j] += 1;
            }
        }
    }
    let mut adj_ptr = vec![0usize; n + 1];
    for i in 0..n {
        adj_ptr[i + 1] = adj_ptr[i] + deg[i];
    }
    let mut fill = adj_ptr.clone();
    let mut adj = vec![0usize; adj_ptr[n]];
    for j in 0..n {
        for &i in &a.row_idx()[a.col_range(j)] {
            if i != j {
                adj[fill[i]] = j;
                fill[i] += 1;
                adj[fill[j]] = i;
                fill[j] += 1;
            }
        }
    }
    let mut xadj: Vec<i32> = Vec::with_capacity(n + 1);
    let mut adjncy: Vec<i32> = Vec::with_capacity(adj.len());
    xadj.push(0);
    let mut seen = vec![usize::MAX; n];
    for i in 0..n {
        for &j in &adj[adj_ptr[i]..adj_ptr[i + 1]] {
            if seen[j] != i {
                seen[j] = i;
                adjncy.push(j as i32);
            }
        }
        if adjncy.len() > i32::MAX as usize {
            return None;
        }
        xadj.push(adjncy.len() as i32);
    }
    let mut nvtxs = n as i32;
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut perm = vec![0i32; n];
    let mut iperm = vec![0i32; n];
    // SAFETY: all arrays have the sizes METIS_NodeND documents (xadj n+1, adjncy
    // xadj[n], perm and iperm n, options METIS_NOPTIONS); vwgt may be null.
    let _one_at_a_time = metis_lock();
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        metis_sys::METIS_NodeND(
            &mut nvtxs,
            xadj.as_mut_ptr(),
            adjncy.as_mut_ptr(),
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            perm.as_mut_ptr(),
            iperm.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return None;
    }
    let perm: Vec<usize> = perm.into_iter().map(|p| p as usize).collect();
    let iperm: Vec<usize> = iperm.into_iter().map(|p| p as usize).collect();
    // Trust but verify: a bad permutation would make faer panic.
    let mut check = vec![false; n];
    for (i, &p) in perm.iter().enumerate() {
        if p >= n || check[p] || iperm[p] != i {
            return None;
        }
        check[p] = true;
    }
    Some((perm, iperm))
}

/// Symbolic analysis shared by LLᵀ and LDLᵀ, kept with a copy of the pattern it was
/// made for.
struct Analysis {
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// Whether METIS was used (false: AMD, asked for or fallen back to).
    metis: bool,
}

impl Analysis {
    fn matches(&self, a: &SparseColMat<usize, f64>) -> bool {
        let s = a.symbolic();
        s.col_ptr() == self.col_ptr.as_slice() && s.row_idx() == self.row_idx.as_slice()
    }

    fn new(a: &SparseColMat<usize, f64>, ordering: Ordering) -> Result<Self, SolveError> {
        let s = a.symbolic();
        let n = a.nrows();
        let metis = match ordering {
            Ordering::Metis => metis_ordering(&s.to_owned().map_err(faer_err)?),
            Ordering::Amd => None,
        };
        let symbolic = match &metis {
            Some((perm, iperm)) => factorize_symbolic_cholesky(
                s,
                Side::Lower,
                SymmetricOrdering::Custom(PermRef::new_checked(perm, iperm, n)),
                CholeskySymbolicParams::default(),
            ),
            None => factorize_symbolic_cholesky(
                s,
                Side::Lower,
                SymmetricOrdering::Amd,
                CholeskySymbolicParams::default(),
            ),
        }
        .map_err(faer_err)?;
        Ok(Analysis {
            col_ptr: s.col_ptr().to_vec(),
            row_idx: s.row_idx().to_vec(),
            symbolic,
            metis: metis.is_some(),
        })
    }

    /// Original row of the failed pivot that faer reports as `k`.
    fn original_row(&self, k: usize) -> usize {
        // faer 0.24's simplicial kernels report the failed pivot one past its 0-based
        // position (`index: k + 1`), the supernodal ones 0-based; observed on a matrix
        // with one negative diagonal entry (tests/it/fem.rs).
        let k = match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(_) => k.saturating_sub(1),
            SymbolicCholeskyRaw::Supernodal(_) => k,
        };
        match self.symbolic.perm() {
            Some(p) => p.arrays().0[k],
            None => k,
        }
    }
}

fn faer_err(e: impl std::fmt::Debug) -> SolveError {
    SolveError::Faer(format!("{e:?}"))
}

fn ensure_analysis(
    slot: &mut Option<Analysis>,
    a: &SparseColMat<usize, f64>,
    ordering: Ordering,
) -> Result<(), SolveError> {
    if a.nrows() != a.ncols() {
        return Err(SolveError::Dimension {
            matrix: a.nrows(),
            vector: a.ncols(),
        });
    }
    if !slot.as_ref().is_some_and(|an| an.matches(a)) {
        *slot = Some(Analysis::new(a, ordering)?);
    }
    Ok(())
}

/// One thread when asked, else faer's global setting.
fn parallelism(sequential: bool) -> faer::Par {
    if sequential {
        faer::Par::Seq
    } else {
        faer::get_global_parallelism()
    }
}

/// Sparse Cholesky LLᵀ for symmetric positive definite matrices.
pub struct Cholesky {
    ordering: Ordering,
    analysis: Option<Analysis>,
    values: Vec<f64>,
    factored: bool,
    /// Run the numeric factorisation and solves on one thread (bit-for-bit
    /// reproducible); the global faer setting otherwise.
    pub sequential: bool,
    /// Number of symbolic analyses done (1 while the pattern holds).
    pub symbolic_count: usize,
}

impl Cholesky {
    pub fn new(ordering: Ordering) -> Self {
        Cholesky {
            ordering,
            analysis: None,
            values: Vec::new(),
            factored: false,
            symbolic_count: 0,
            sequential: false,
        }
    }

    /// Stored values of L (faer's `len_val`), the fill measure; 0 before `factor`.
    pub fn factor_nnz(&self) -> usize {
        self.analysis.as_ref().map_or(0, |a| a.symbolic.len_val())
    }

    /// Whether faer chose its supernodal (blocked) kernels rather than simplicial ones.
    pub fn is_supernodal(&self) -> bool {
        self.analysis
            .as_ref()
            .is_some_and(|a| matches!(a.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_)))
    }

    /// Whether the current analysis uses METIS (false: AMD).
    pub fn uses_metis(&self) -> bool {
        self.analysis.as_ref().is_some_and(|a| a.metis)
    }

    /// Symbolic analysis only (ordering + elimination tree), e.g. to time it apart.
    pub fn analyse(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
        let before = self.analysis.is_some() && self.analysis.as_ref().unwrap().matches(a);
        ensure_analysis(&mut self.analysis, a, self.ordering)?;
        if !before {
            self.symbolic_count += 1;
            self.factored = false;
        }
        Ok(())
    }
}

impl LinearSolver for Cholesky {
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
        check_finite(a)?;
        self.analyse(a)?;
        let an = self.analysis.as_ref().unwrap();
        let sym = &an.symbolic;
        self.values.resize(sym.len_val(), 0.0);
        let par = parallelism(self.sequential);
        let mut mem =
            MemBuffer::try_new(sym.factorize_numeric_llt_scratch::<f64>(par, Default::default()))
                .map_err(faer_err)?;
        self.factored = false;
        match sym.factorize_numeric_llt(
            &mut self.values,
            a.as_ref(),
            Side::Lower,
            LltRegularization::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        ) {
            Ok(_) => {}
            Err(LltError::NonPositivePivot { index }) => {
                return Err(SolveError::NotPositiveDefinite {
                    row: an.original_row(index),
                });
            }
        }
        self.factored = true;
        Ok(())
    }

    fn solve(&mut self, b: &mut [f64]) -> Result<SolveReport, SolveError> {
        let an = self.analysis.as_ref().ok_or(SolveError::NotFactored)?;
        if !self.factored {
            return Err(SolveError::NotFactored);
        }
        let sym = &an.symbolic;
        check_rhs(sym.nrows(), b)?;
        let par = parallelism(self.sequential);
        let mut mem =
            MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
        let n = b.len();
        LltRef::new(sym, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, n, 1),
            par,
            MemStack::new(&mut mem),
        );
        Ok(SolveReport {
            iterations: 0,
            residual: f64::NAN,
        })
    }
}

/// LDLᵀ for symmetric quasi-definite and saddle-point matrices `[K Cᵀ; C 0]`.
///
/// Pivots are forced to the expected sign (`+1` primal, `−1` multiplier) with faer's
/// dynamic regularisation: a pivot `d` with `sign·d ≤ ε` is replaced by `sign·δ`. That
/// factorises `A + E` (E small, diagonal, on the zero block) whatever the ordering, so
/// the solution is refined against the unregularised `A`:
/// `x ← x + (A+E)⁻¹ (b − A x)` until `‖b − A x‖/‖b‖ ≤ 1e-13` or 5 steps. The iteration
/// contracts like `‖(A+E)⁻¹E‖ = O(δ·‖A⁻¹‖)`, so with δ = 1e-8 (relative to the largest
/// diagonal entry) each step gains about 8 digits; 1e-13 is a few hundred ulps of a
/// well-scaled residual, reachable in 1–3 steps.
///
/// That holds for a well-scaled matrix only, so the factorisation is of `S A S`, with
/// `S` diagonal: `1/√|a_ii|` on a primal row, `1/√(Σ_j (a_ij s_j)²)` on a multiplier row
/// (its Schur pivot then near −1). Unscaled, a mortar tie's multiplier pivots
/// `−C K⁻¹ Cᵀ` sit orders of magnitude below δ relative to K's diagonal (C scales
/// with the face areas): a pivot regularised to −δ then is a perturbation larger than
/// itself, and the refinement stalled — on the two-block tie of two fields at 2.6e-11
/// relative after its 5 steps, 1.9e-4 K off. Should the refinement still fall short of
/// 1e-10, the solve is made by LU with partial pivoting instead (kept for later
/// solves of the same factorisation), never left inexact.
pub struct SaddleLdlt {
    signs: Vec<i8>,
    ordering: Ordering,
    /// Regularisation δ relative to the largest |diagonal| of the matrix.
    pub delta: f64,
    /// Stop refining at this relative residual.
    pub tolerance: f64,
    /// At most this many refinement steps.
    pub max_refinement: usize,
    analysis: Option<Analysis>,
    values: Vec<f64>,
    matrix: Option<SparseColMat<usize, f64>>,
    /// The symmetric scaling `S` of the factorised `S A S`.
    scale: Vec<f64>,
    /// LU of the matrix, made when the refinement fell short.
    fallback: Option<Lu>,
    /// As [`Cholesky::sequential`].
    pub sequential: bool,
}

/// The relative residual a refined solve must reach, else the LU of the matrix solves.
const SADDLE_ACCEPT: f64 = 1e-10;

impl SaddleLdlt {
    /// `signs[i]` is `+1` for a primal row, `−1` for a multiplier row.
    pub fn new(signs: Vec<i8>, ordering: Ordering) -> Self {
        SaddleLdlt {
            signs,
            ordering,
            delta: 1e-8,
            tolerance: 1e-13,
            max_refinement: 5,
            sequential: false,
            analysis: None,
            values: Vec::new(),
            matrix: None,
            scale: Vec::new(),
            fallback: None,
        }
    }

    /// The report of a solve `x` of `A x = rhs` after `steps` refinement steps.
    fn residual_of(&self, x: &[f64], rhs: &[f64], steps: usize) -> Result<SolveReport, SolveError> {
        let a = self.matrix.as_ref().ok_or(SolveError::NotFactored)?;
        let mut r = vec![0.0; x.len()];
        spmv(a, x, &mut r);
        let diff: Vec<f64> = rhs.iter().zip(&r).map(|(b, ax)| b - ax).collect();
        let bnorm = norm(rhs);
        Ok(SolveReport {
            iterations: steps,
            residual: if bnorm > 0.0 {
                norm(&diff) / bnorm
            } else {
                norm(&diff)
            },
        })
    }

    /// Whether the last solve fell back to LU (the refinement fell short).
    pub fn fell_back(&self) -> bool {
        self.fallback.is_some()
    }

    /// Signs for `n_primal` primal rows followed by multiplier rows up to `n`.
    pub fn with_primal(n_primal: usize, n: usize, ordering: Ordering) -> Self {
        let signs = (0..n).map(|i| if i < n_primal { 1 } else { -1 }).collect();
        Self::new(signs, ordering)
    }

    fn solve_once(&self, b: &mut [f64]) -> Result<(), SolveError> {
        let an = self.analysis.as_ref().ok_or(SolveError::NotFactored)?;
        let sym = &an.symbolic;
        let par = parallelism(self.sequential);
        let mut mem =
            MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, par)).map_err(faer_err)?;
        let n = b.len();
        for (x, s) in b.iter_mut().zip(&self.scale) {
            *x *= s;
        }
        LdltRef::new(sym, &self.values).solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, n, 1),
            par,
            MemStack::new(&mut mem),
        );
        for (x, s) in b.iter_mut().zip(&self.scale) {
            *x *= s;
        }
        Ok(())
    }
}

/// The scaling `S` of [`SaddleLdlt`]: `1/√|a_ii|` on a row with a diagonal, and on a
/// multiplier row without one (`signs` −1) `1/√(Σ_j (a_ij s_j)²)` over its entries in
/// primal columns; 1 on a row with neither.
fn saddle_scaling(a: &SparseColMat<usize, f64>, signs: &[i8]) -> Vec<f64> {
    let s = a.symbolic();
    let (rows, vals) = (s.row_idx(), a.val());
    let n = a.nrows();
    let mut scale = vec![1.0; n];
    for j in 0..n {
        for p in s.col_range(j) {
            if rows[p] == j && vals[p] != 0.0 {
                scale[j] = 1.0 / vals[p].abs().sqrt();
            }
        }
    }
    let mut sum = vec![0.0; n];
    for j in (0..n).filter(|&j| signs[j] > 0) {
        for p in s.col_range(j) {
            let i = rows[p];
            if signs[i] < 0 {
                sum[i] += (vals[p] * scale[j]).powi(2);
            }
        }
    }
    for i in (0..n).filter(|&i| signs[i] < 0 && sum[i] > 0.0) {
        let has_diagonal = s.col_range(i).any(|p| rows[p] == i && vals[p] != 0.0);
        if !has_diagonal {
            scale[i] = 1.0 / sum[i].sqrt();
        }
    }
    scale
}

impl LinearSolver for SaddleLdlt {
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
        check_finite(a)?;
        if self.signs.len() != a.nrows() {
            return Err(SolveError::Dimension {
                matrix: a.nrows(),
                vector: self.signs.len(),
            });
        }
        ensure_analysis(&mut self.analysis, a, self.ordering)?;
        let an = self.analysis.as_ref().unwrap();
        let sym = &an.symbolic;
        self.values.resize(sym.len_val(), 0.0);
        self.scale = saddle_scaling(a, &self.signs);
        // The scaled values over the matrix's own structure (no copy of it).
        let s = a.symbolic();
        let mut scaled_values = a.val().to_vec();
        for j in 0..a.ncols() {
            for p in s.col_range(j) {
                scaled_values[p] *= self.scale[s.row_idx()[p]] * self.scale[j];
            }
        }
        let scaled = SparseColMatRef::new(s, &scaled_values);
        let mut dmax: f64 = 0.0;
        for j in 0..a.ncols() {
            for p in s.col_range(j) {
                if s.row_idx()[p] == j {
                    dmax = dmax.max(scaled.val()[p].abs());
                }
            }
        }
        let scale = if dmax > 0.0 { dmax } else { 1.0 };
        let par = parallelism(self.sequential);
        let mut mem =
            MemBuffer::try_new(sym.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()))
                .map_err(faer_err)?;
        let delta = self.delta * scale;
        let reg = LdltRegularization {
            dynamic_regularization_signs: Some(&self.signs),
            dynamic_regularization_delta: delta,
            // Pivots smaller than 1e-3·δ in the expected direction count as zero.
            dynamic_regularization_epsilon: 1e-3 * delta,
        };
        self.matrix = None;
        self.fallback = None;
        match sym.factorize_numeric_ldlt(
            &mut self.values,
            scaled,
            Side::Lower,
            reg,
            par,
            MemStack::new(&mut mem),
            Default::default(),
        ) {
            Ok(_) => {}
            Err(faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index }) => {
                return Err(SolveError::ZeroPivot {
                    row: an.original_row(index),
                });
            }
        }
        self.matrix = Some(a.clone());
        Ok(())
    }

    fn solve(&mut self, b: &mut [f64]) -> Result<SolveReport, SolveError> {
        let a = self.matrix.as_ref().ok_or(SolveError::NotFactored)?;
        check_rhs(a.nrows(), b)?;
        let rhs = b.to_vec();
        if let Some(lu) = self.fallback.as_mut() {
            lu.solve(b)?;
            return self.residual_of(b, &rhs, 0);
        }
        let bnorm = norm(&rhs);
        self.solve_once(b)?;
        let mut r = vec![0.0; b.len()];
        let mut steps = 0;
        let mut rel;
        loop {
            spmv(a, b, &mut r);
            for (ri, bi) in r.iter_mut().zip(&rhs) {
                *ri = bi - *ri;
            }
            rel = if bnorm > 0.0 {
                norm(&r) / bnorm
            } else {
                norm(&r)
            };
            if rel <= self.tolerance || steps == self.max_refinement {
                break;
            }
            self.solve_once(&mut r)?;
            for (x, d) in b.iter_mut().zip(&r) {
                *x += d;
            }
            steps += 1;
        }
        if rel > SADDLE_ACCEPT {
            log::debug!(
                "saddle-point LDLᵀ: refinement stopped at {rel:.3e} relative after {steps} steps; solving by LU"
            );
            let mut lu = Lu::new();
            lu.factor(a)?;
            b.copy_from_slice(&rhs);
            lu.solve(b)?;
            self.fallback = Some(lu);
            return self.residual_of(b, &rhs, steps);
        }
        Ok(SolveReport {
            iterations: steps,
            residual: rel,
        })
    }
}

/// Sparse LU with partial pivoting (faer, COLAMD): for non-symmetric matrices and as a
/// reference solve.
#[derive(Default)]
pub struct Lu {
    symbolic: Option<(Vec<usize>, Vec<usize>, SymbolicLu<usize>)>,
    lu: Option<FaerLu<usize, f64>>,
}

impl Lu {
    pub fn new() -> Self {
        Self::default()
    }
}

impl LinearSolver for Lu {
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
        check_finite(a)?;
        let s = a.symbolic();
        let same = self
            .symbolic
            .as_ref()
            .is_some_and(|(c, r, _)| c.as_slice() == s.col_ptr() && r.as_slice() == s.row_idx());
        if !same {
            let sym = SymbolicLu::try_new(s).map_err(faer_err)?;
            self.symbolic = Some((s.col_ptr().to_vec(), s.row_idx().to_vec(), sym));
        }
        let sym = self.symbolic.as_ref().unwrap().2.clone();
        self.lu = None;
        self.lu = Some(
            FaerLu::try_new_with_symbolic(sym, a.as_ref())
                .map_err(|e| SolveError::Singular(format!("{e:?}")))?,
        );
        Ok(())
    }

    fn solve(&mut self, b: &mut [f64]) -> Result<SolveReport, SolveError> {
        use faer::linalg::solvers::{ShapeCore, Solve};
        let lu = self.lu.as_ref().ok_or(SolveError::NotFactored)?;
        let n = b.len();
        check_rhs(lu.nrows(), b)?;
        lu.solve_in_place(MatMut::from_column_major_slice_mut(b, n, 1));
        if let Some(row) = b.iter().position(|x| !x.is_finite()) {
            return Err(SolveError::Singular(format!(
                "the solution is not finite at row {row}: the matrix is singular"
            )));
        }
        Ok(SolveReport {
            iterations: 0,
            residual: f64::NAN,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// METIS orderings made on several threads at once equal the one made alone: its
    /// random numbers come from process-global state, which [`metis_lock`] keeps to one
    /// call at a time.
    #[test]
    fn metis_orderings_on_several_threads_equal_the_one_made_alone() {
        let matrix = crate::solve::laplacian_7pt(14);
        let a = matrix.symbolic().to_owned().unwrap();
        let alone = metis_ordering(&a).expect("METIS orders a Laplacian");
        let orderings: Vec<_> = std::thread::scope(|s| {
            let workers: Vec<_> = (0..4)
                .map(|_| {
                    s.spawn(|| {
                        (0..10)
                            .map(|_| metis_ordering(&a).unwrap())
                            .collect::<Vec<_>>()
                    })
                })
                .collect();
            workers
                .into_iter()
                .flat_map(|w| w.join().unwrap())
                .collect()
        });
        let differ = orderings.iter().filter(|o| **o != alone).count();
        assert_eq!(
            differ,
            0,
            "{differ} of {} orderings differ",
            orderings.len()
        );
    }
}
