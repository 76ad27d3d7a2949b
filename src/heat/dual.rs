//! Dual mortar ties in a linear steady solve: condensed out.
//!
//! With a dual multiplier basis a tie's side-A block `D` of `C` is diagonal, so each
//! side-A dof that carries a multiplier is a known combination of free dofs,
//! `u_a = (g_a − Σ_j C_aj u_j) / D_a`. Written `u = P ũ + c` (P the identity on the free
//! dofs and those rows on the condensed ones, c their constants), the saddle point
//! becomes `Pᵀ K P ũ = Pᵀ (F − K c)`: symmetric positive definite, the size of the
//! primal problem, solved like any other steady system — Cholesky below the size for
//! AMG, AMG-CG from it. The multipliers come back from the condensed rows,
//! `D_a λ_a = −(K u − F)_a`.

use std::time::Instant;

use faer::sparse::{SparseColMat, SymbolicSparseColMat};

use crate::assembly::{Assembler, DofMap, FieldId, Pattern};
use crate::solve::amg::reuse::{Csc, RowIndex};
use crate::solve::{
    AmgCg, AmgOptions, Cholesky, FineRadius, LinearSolver, Ordering, apply_dirichlet_parts,
};

use super::HeatError;
use super::interfaces::{InterfaceFailure, Interfaces, TieRows};
use super::steady::{LinearMethod, LinearSolves, SolveTiming, SteadyProblem, SteadySolution};

/// Whether the ties are dual ones (condensed in a linear solve); refused mixed with
/// standard ties or with a temperature-dependent conductance (not `linear`).
pub(crate) fn dual_ties(ties: &[TieRows], linear: bool) -> Result<bool, HeatError> {
    if !ties.iter().any(|t| t.dual) {
        return Ok(false);
    }
    if ties.iter().any(|t| !t.dual) || !linear {
        return Err(HeatError::Contact(
            "dual mortar ties are condensed in a linear solve: do not mix them with standard ties or temperature-dependent conductances".into(),
        ));
    }
    Ok(true)
}

/// Relative residual at which the condensed system's AMG-CG stops, ‖b − Ax‖ ≤ 1e-15
/// ‖b‖: at the steady solve's tolerance its error stays smooth and far larger than the
/// primal steady solve's at the same residual (`super::steady::STEADY_AMG_TOLERANCE`). Measured on the tied boxes of
/// `benches/peers/seam_case.py dual` (exact T = 1 − z), max error against iterations:
/// 110 711 nodes (54:36), 1e-13 1.2e-11 after 13, 1e-14 3.4e-13 after 15, 1e-15 2.7e-14
/// after 16; 1.16 M nodes (120:80), 1e-13 5.3e-11 after 14, 1e-14 1.3e-12 after 16,
/// 1e-15 1.9e-13 after 17. CG's recursive residual goes on falling below the true
/// one's floor, so the test is met where the error has reached round-off.
pub const DUAL_AMG_TOLERANCE: f64 = 1e-15;

/// A condensed dof's row: its constant and its terms `(dof, coefficient)`.
pub(crate) type Condensed = Option<(f64, Vec<(usize, f64)>)>;

/// A dual tie's condensation: per dof, the condensed row `(constant, [(dof,
/// coefficient)])` of the side-A dofs that carry a multiplier, and the rows' diagonals.
/// Refused where two condensed rows couple (a side-A face only partly covered by side
/// B), as the distributed solve (which keeps the multipliers) refuses it too.
pub(crate) fn dual_condensation(
    ties: &[TieRows],
    n: usize,
) -> Result<(Vec<Condensed>, Vec<f64>), HeatError> {
    let mut map: Vec<Condensed> = vec![None; n];
    let mut diag = vec![0.0; n];
    for tie in ties {
        let mut rows: Vec<Vec<(usize, f64)>> = vec![Vec::new(); tie.own.len()];
        for &(kk, d, c) in &tie.entries {
            rows[kk].push((d, c));
        }
        for (kk, &own) in tie.own.iter().enumerate() {
            if own == usize::MAX {
                return Err(HeatError::NoTemperatureField);
            }
            let d = rows[kk]
                .iter()
                .filter(|(j, _)| *j == own)
                .map(|(_, c)| c)
                .sum::<f64>();
            if d == 0.0 {
                continue; // a node no point reached: left free
            }
            diag[own] = d;
            let others = rows[kk]
                .iter()
                .filter(|(j, _)| *j != own)
                .map(|&(j, c)| (j, -c / d))
                .collect();
            map[own] = Some((tie.rhs[kk] / d, others));
        }
    }
    // Side-A rows of a dual basis reference no other condensed dof (biorthogonality);
    // a non-negligible one means a face without full overlap.
    for (i, m) in map.iter().enumerate() {
        if let Some((_, row)) = m {
            for &(j, a) in row {
                if map[j].is_some() && a.abs() > 1e-9 {
                    return Err(HeatError::Contact(format!(
                        "dual mortar: the side-A rows of dofs {i} and {j} are coupled ({a:.3e}); a side-A face is only partly covered by side B — use standard multipliers (`Multipliers = Standard`) there"
                    )));
                }
            }
        }
    }
    Ok((map, diag))
}

/// The operator `P` of `u = P ũ + c`, read both ways: a dof's free dofs with their
/// weights (its row of P), and the condensed dofs whose rows name a free dof (its
/// column of P beyond its own 1).
pub(crate) struct Condensation {
    map: Vec<Condensed>,
    /// Per dof, the diagonal `D_a` of its condensed row (0 on the free dofs).
    diag: Vec<f64>,
    /// Free dof `j`'s condensed dofs `(a, P_aj)` are `named[start[j]..start[j + 1]]`.
    start: Vec<usize>,
    named: Vec<(usize, f64)>,
}

impl Condensation {
    /// The condensation of the dual `ties` over the first `n` dofs (the primal ones;
    /// refused as [`dual_condensation`] refuses).
    pub(crate) fn of(ties: &[TieRows], n: usize) -> Result<Self, HeatError> {
        let (map, diag) = dual_condensation(ties, n)?;
        Ok(Self::new(map, diag))
    }

    fn new(map: Vec<Condensed>, diag: Vec<f64>) -> Self {
        let free = |j: &&(usize, f64)| map[j.0].is_none();
        let mut start = vec![0usize; map.len() + 1];
        for (_, row) in map.iter().flatten() {
            for &(j, _) in row.iter().filter(free) {
                start[j + 1] += 1;
            }
        }
        for j in 0..map.len() {
            start[j + 1] += start[j];
        }
        let mut next = start.clone();
        let mut named = vec![(0, 0.0); start[map.len()]];
        for (a, m) in map.iter().enumerate() {
            if let Some((_, row)) = m {
                for &(j, w) in row.iter().filter(free) {
                    named[next[j]] = (a, w);
                    next[j] += 1;
                }
            }
        }
        Condensation {
            map,
            diag,
            start,
            named,
        }
    }

    /// `f(j, P_ij)` for every free dof `j` of row `i` of P: `i` itself with 1 when it
    /// is free. (A condensed row's terms in other condensed dofs are below 1e-9 by
    /// [`dual_condensation`]'s check, and left out.)
    #[inline]
    fn row(&self, i: usize, mut f: impl FnMut(usize, f64)) {
        match &self.map[i] {
            None => f(i, 1.0),
            Some((_, row)) => {
                for &(j, w) in row {
                    if self.map[j].is_none() {
                        f(j, w);
                    }
                }
            }
        }
    }

    /// `Pᵀ K P` with the identity's rows and columns on the condensed dofs, as CSC
    /// parts. A column away from the ties is K's as it is; the others are summed in a
    /// dense accumulator: `K e_j + Σ_a P_aj K e_a`, each entry's row spread over its
    /// row of P.
    ///
    /// K's rows and columns past the first `n` (a saddle point's multipliers) are left
    /// out.
    pub(crate) fn matrix<I: RowIndex>(&self, k: Csc<'_, I>) -> (Vec<usize>, Vec<u32>, Vec<f64>) {
        let n = self.map.len();
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut rows: Vec<u32> = Vec::with_capacity(k.rows.len());
        let mut vals = Vec::with_capacity(k.rows.len());
        let mut sum = Sparse::new(n);
        for j in 0..n {
            if self.map[j].is_some() {
                rows.push(j as u32);
                vals.push(1.0);
                col_ptr.push(rows.len());
                continue;
            }
            let range = k.col_ptr[j]..k.col_ptr[j + 1];
            let named = &self.named[self.start[j]..self.start[j + 1]];
            let plain = named.is_empty()
                && k.rows[range.clone()]
                    .iter()
                    .all(|&i| i.ix() < n && self.map[i.ix()].is_none());
            if plain {
                rows.extend(k.rows[range.clone()].iter().map(|&i| i.ix() as u32));
                vals.extend_from_slice(&k.val[range]);
            } else {
                for (i, v) in k.column(j).filter(|&(i, _)| i < n) {
                    self.row(i, |r, w| sum.add(r, w * v));
                }
                for &(a, p) in named {
                    for (i, v) in k.column(a).filter(|&(i, _)| i < n) {
                        self.row(i, |r, w| sum.add(r, w * (p * v)));
                    }
                }
                sum.drain_into(&mut rows, &mut vals);
            }
            col_ptr.push(rows.len());
        }
        (col_ptr, rows, vals)
    }

    /// `Pᵀ x` over the first `n` dofs (zero on the condensed ones).
    pub(crate) fn transpose_times(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.map.len()];
        for (i, &xi) in x.iter().enumerate().take(self.map.len()) {
            self.row(i, |j, w| y[j] += w * xi);
        }
        y
    }

    /// `P x` into the first `n` entries of `y` (whose others are left alone): `x` on the
    /// free dofs, a condensed dof's terms in them on the others.
    pub(crate) fn times(&self, x: &[f64], y: &mut [f64]) {
        for (i, y) in y.iter_mut().enumerate().take(self.map.len()) {
            let mut sum = 0.0;
            self.row(i, |j, w| sum += w * x[j]);
            *y = sum;
        }
    }

    /// `u` put on the ties' constraints: each condensed dof set to its row's value,
    /// `c_a + Σ_j P_aj u_j`.
    pub(crate) fn constrain(&self, u: &mut [f64]) {
        for (i, m) in self.map.iter().enumerate() {
            if let Some((c, row)) = m {
                u[i] = c + row.iter().map(|&(j, a)| a * u[j]).sum::<f64>();
            }
        }
    }

    /// The multiplier of condensed dof `a` from the residual `r_a` of the primal rows
    /// at a solution: `λ_a = −r_a / D_a` (0 for a free dof).
    pub(crate) fn multiplier(&self, a: usize, r_a: f64) -> f64 {
        match self.diag[a] {
            0.0 => 0.0,
            d => -r_a / d,
        }
    }
}

/// A transient run's steps with dual ties condensed: the Newton step `J Δu = −R` of a
/// symmetric step system solved as `Pᵀ J P Δũ = −Pᵀ R`, `Δu = P Δũ` (the multipliers'
/// rows and columns of `J` left out), by AMG-CG with its hierarchy kept across steps
/// as the steps' own; the start put on the ties' constraints first, and the
/// multipliers recovered from the condensed rows of the residual after the step.
pub(crate) struct CondensedSteps {
    condensation: Condensation,
    amg: AmgCg,
}

impl CondensedSteps {
    /// For the dual `ties` over the first `n` (primal) dofs.
    pub(crate) fn new(ties: &[TieRows], n: usize) -> Result<Self, HeatError> {
        Ok(CondensedSteps {
            condensation: Condensation::of(ties, n)?,
            // Relative to the step's residual: the steady solve's tolerance.
            amg: AmgCg::new(AmgOptions {
                tolerance: super::steady::STEADY_AMG_TOLERANCE,
                ..AmgOptions::default()
            }),
        })
    }

    /// `u` put on the ties' constraints.
    pub(crate) fn constrain(&self, u: &mut [f64]) {
        self.condensation.constrain(u);
    }

    /// The step of `jac Δu = rhs` (`rhs` on entry, the step on return; the rows `held`
    /// kept at their values, zero for an increment), condensed: the seconds of the
    /// condensed matrix and its hierarchy, of the solve, and the CG iterations.
    pub(crate) fn solve(
        &mut self,
        jac: &SparseColMat<usize, f64>,
        rhs: &mut [f64],
        held: &[(usize, f64)],
    ) -> Result<(f64, f64, usize), HeatError> {
        let t = Instant::now();
        let s = jac.symbolic();
        let k = Csc {
            n: jac.ncols(),
            col_ptr: s.col_ptr(),
            rows: s.row_idx(),
            val: jac.val(),
        };
        // (The values are the hierarchy's after a set-up, and let go after a refresh:
        // nothing of them is kept between steps.)
        let (col_ptr, rows, mut values) = self.condensation.matrix(k);
        let mut b = self.condensation.transpose_times(rhs);
        apply_dirichlet_parts(&col_ptr, &rows, &mut values, &mut b, held)?;
        (self.amg).factor_or_refresh_parts(&col_ptr, &rows, &mut values)?;
        let set_up = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let its = self.amg.solve(&mut b)?.iterations;
        self.amg.note_iterations(its);
        let n = b.len();
        self.condensation.times(&b, &mut rhs[..n]);
        rhs[n..].fill(0.0);
        Ok((set_up, t.elapsed().as_secs_f64(), its))
    }

    /// After the step: each multiplier moved by `−r_a / D_a` of its condensed row in
    /// the residual `r` at `u` (multipliers in `u` after the primal dofs, tie `t`'s from
    /// `first[t]`), and `r` by `Cᵀ` of that move, so that it is the residual at the new
    /// multipliers.
    pub(crate) fn multipliers(
        &self,
        ties: &[TieRows],
        first: &[usize],
        u: &mut [f64],
        r: &mut [f64],
    ) {
        for (tie, &first) in ties.iter().zip(first) {
            let step: Vec<f64> = (tie.own.iter())
                .map(|&a| self.condensation.multiplier(a, r[a]))
                .collect();
            for (k, d) in step.iter().enumerate() {
                u[first + k] += d;
            }
            for &(k, j, c) in &tie.entries {
                r[j] += c * step[k];
            }
        }
    }

    /// The hierarchy's set-ups and refreshes so far.
    pub(crate) fn reuse_counts(&self) -> (usize, usize) {
        self.amg.reuse_counts()
    }
}

/// A sparse vector summed in a dense array: the rows touched, in order of first touch.
struct Sparse {
    values: Vec<f64>,
    seen: Vec<bool>,
    touched: Vec<usize>,
}

impl Sparse {
    fn new(n: usize) -> Self {
        Sparse {
            values: vec![0.0; n],
            seen: vec![false; n],
            touched: Vec::new(),
        }
    }

    #[inline]
    fn add(&mut self, i: usize, v: f64) {
        if !self.seen[i] {
            self.seen[i] = true;
            self.touched.push(i);
        }
        self.values[i] += v;
    }

    /// Its entries, rows ascending, appended; left empty.
    fn drain_into(&mut self, rows: &mut Vec<u32>, vals: &mut Vec<f64>) {
        self.touched.sort_unstable();
        for &i in &self.touched {
            rows.push(i as u32);
            vals.push(self.values[i]);
            self.values[i] = 0.0;
            self.seen[i] = false;
        }
        self.touched.clear();
    }
}

/// The dual-mortar path: every tie's side-A interface values are condensed out
/// (module documentation); the reduced system is solved by Cholesky, or by AMG-CG when
/// the problem asks for the iterative path (its size at or above the threshold); the
/// multipliers are recovered from the condensed rows.
pub(super) fn solve_dual(
    p: &SteadyProblem<'_>,
    iface: &dyn Interfaces,
    dofs: DofMap,
    field: FieldId,
    bcs: Vec<(usize, f64)>,
    ties: Vec<TieRows>,
) -> Result<SteadySolution, HeatError> {
    let n = dofs.len();
    let mut timing = SolveTiming::default();
    let mut linear = LinearSolves::default();
    let t = Instant::now();
    let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());
    let condensation = Condensation::of(&ties, n)?;
    // K and F with the flux-type contact terms (linear: evaluated at u = 0, where the
    // residual is −F_Γ).
    let zero = vec![0.0; n];
    let mut pattern = Pattern::new(p.mesh, &dofs);
    let first = pattern
        .add_couplings(&iface.couplings(&zero, 0.0).map_err(failed)?)?
        .start;
    pattern.build_direct()?;
    let (f, reduced, mut rhs, condensed_rows) = {
        let (col_ptr, rows) = pattern.structure().expect("built");
        let mut asm = Assembler::direct(&pattern)?;
        p.conduction(&mut asm, p.mesh, &dofs)?;
        let mut f = asm.rhs();
        let mut r_contact = vec![0.0; n];
        iface
            .assemble(&zero, 0.0, &mut r_contact, &mut asm, first)
            .map_err(failed)?;
        for (fi, ri) in f.iter_mut().zip(&r_contact) {
            *fi -= ri;
        }
        let vals = asm.take_values()?;
        let k = Csc {
            n,
            col_ptr,
            rows,
            val: &vals,
        };
        // F − K c, c nonzero on the condensed dofs alone; then Pᵀ of it.
        let mut r = f.clone();
        for (a, m) in condensation.map.iter().enumerate() {
            if let Some((c, _)) = m {
                for (i, v) in k.column(a) {
                    r[i] -= v * c;
                }
            }
        }
        let rhs = condensation.transpose_times(&r);
        // The condensed dofs' rows of K, kept for the multipliers (column order, as a
        // product with K sums them).
        let mut condensed_rows = Vec::new();
        for j in 0..n {
            for (i, v) in k.column(j) {
                if condensation.map[i].is_some() {
                    condensed_rows.push((i, j, v));
                }
            }
        }
        (f, condensation.matrix(k), rhs, condensed_rows)
    };
    drop(pattern);
    let (col_ptr, rows, mut vals) = reduced;
    apply_dirichlet_parts(&col_ptr, &rows, &mut vals, &mut rhs, &bcs)?;
    timing.assembly_s += t.elapsed().as_secs_f64();
    let t = Instant::now();
    if p.iterative {
        let mut amg = AmgCg::new(AmgOptions {
            tolerance: DUAL_AMG_TOLERANCE,
            fine_radius: FineRadius::Bound,
            ..AmgOptions::default()
        });
        amg.setup(AmgCg::rows_of_parts(n, col_ptr, rows, vals)?)?;
        timing.factor_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let report = amg.solve(&mut rhs)?;
        timing.solve_s += t.elapsed().as_secs_f64();
        linear.method = Some(LinearMethod::AmgCg);
        linear.cg_iterations.push(report.iterations);
        linear.hierarchy_setups = Some(1);
    } else {
        let rows = rows.into_iter().map(|i| i as usize).collect();
        // The parts are a valid CSC by construction (columns ascending, rows sorted).
        let sym = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, rows);
        let reduced = SparseColMat::new(sym, vals);
        let mut chol = Cholesky::new(Ordering::Metis);
        chol.sequential = p.reproducible;
        chol.factor(&reduced)?;
        timing.factor_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        chol.solve(&mut rhs)?;
        timing.solve_s += t.elapsed().as_secs_f64();
        linear.method = Some(LinearMethod::Cholesky);
    }
    let mut u = rhs;
    condensation.constrain(&mut u);
    // Multipliers from the condensed rows: D_a λ_a = −(K u − F)_a.
    let mut ku = vec![0.0; n];
    for &(i, j, v) in &condensed_rows {
        ku[i] += v * u[j];
    }
    let lambdas: Vec<Vec<f64>> = (ties.iter())
        .map(|tie| {
            (tie.own.iter())
                .map(|&d| condensation.multiplier(d, ku[d] - f[d]))
                .collect()
        })
        .collect();
    let tie_heat = (ties.iter().zip(&lambdas))
        .map(|(tie, lambda)| tie.heat(lambda))
        .collect();
    let heat = iface.heat(&u, 0.0).map_err(failed)?;
    let temperature = dofs.nodal_values(field, &u);
    // The multipliers after the primal dofs, as the saddle-point path stores them.
    let mut dofs = dofs;
    for lambda in &lambdas {
        dofs.add_extra(lambda.len());
        u.extend_from_slice(lambda);
    }
    Ok(SteadySolution {
        crosspoints: ties.iter().map(|t| t.crosspoints.clone()).collect(),
        dofs,
        u,
        temperature,
        newton_iterations: 1,
        converged: true,
        residual_history: Vec::new(),
        heat,
        tie_heat,
        timing,
        linear,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `Pᵀ K P` made densely, entry by entry from its definition, against
    /// [`Condensation::matrix`] on a small symmetric K with two condensed dofs, one of
    /// them naming a dof whose K column holds no condensed row, and two dofs away from
    /// both.
    #[test]
    fn condensed_matrix_is_pt_k_p() {
        let n = 8;
        // A symmetric K with a full diagonal and some couplings.
        let mut dense = vec![vec![0.0; n]; n];
        for i in 0..n {
            dense[i][i] = 4.0 + i as f64;
        }
        for &(i, j, v) in &[
            (0, 1, -1.0),
            (1, 2, -0.5),
            (2, 3, -1.5),
            (3, 4, -0.25),
            (0, 5, -2.0),
            (6, 7, -1.0),
        ] {
            dense[i][j] = v;
            dense[j][i] = v;
        }
        let (mut col_ptr, mut rows, mut vals) = (vec![0], Vec::new(), Vec::new());
        for j in 0..n {
            for i in 0..n {
                if dense[i][j] != 0.0 {
                    rows.push(i as u32);
                    vals.push(dense[i][j]);
                }
            }
            col_ptr.push(rows.len());
        }
        // Dof 1 condensed onto 4 and 5 (5's column holds no row of 1), dof 3 onto 0;
        // the columns of 6 and 7 are K's as they are.
        let mut map: Vec<Condensed> = vec![None; n];
        map[1] = Some((0.5, vec![(4, 0.25), (5, 0.75)]));
        map[3] = Some((-1.0, vec![(0, 2.0)]));
        let condensation = Condensation::new(map.clone(), vec![0.0; n]);
        let k = Csc {
            n,
            col_ptr: &col_ptr,
            rows: &rows,
            val: &vals,
        };
        let (cp, ri, va) = condensation.matrix(k);
        let mut p = vec![vec![0.0; n]; n];
        for i in 0..n {
            condensation.row(i, |j, w| p[i][j] += w);
        }
        for j in 0..n {
            let mut got = vec![0.0; n];
            for q in cp[j]..cp[j + 1] {
                got[ri[q] as usize] = va[q];
            }
            assert!(
                ri[cp[j]..cp[j + 1]].windows(2).all(|w| w[0] < w[1]),
                "column {j}"
            );
            for i in 0..n {
                let want = if map[i].is_some() || map[j].is_some() {
                    f64::from(u8::from(i == j))
                } else {
                    (0..n)
                        .flat_map(|a| (0..n).map(move |b| (a, b)))
                        .map(|(a, b)| p[a][i] * dense[a][b] * p[b][j])
                        .sum()
                };
                assert!(
                    (got[i] - want).abs() < 1e-14,
                    "({i}, {j}): {} against {want}",
                    got[i]
                );
            }
        }
        assert_eq!(condensation.transpose_times(&[1.0; 8]), {
            let mut y = vec![0.0; n];
            for i in 0..n {
                for j in 0..n {
                    y[j] += p[i][j];
                }
            }
            y
        });
    }
}
