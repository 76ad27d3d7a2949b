//! Restarted GMRES for the unsymmetric Jacobians of coupled fields, preconditioned block
//! by block with algebraic multigrid.
//!
//! The unknowns split at `split` into a first block (the temperatures) and a second
//! (the voltages): `A = [A₁₁ A₁₂; A₂₁ A₂₂]`. The preconditioner is one block
//! Gauss–Seidel sweep, `z₁ = M₁⁻¹ r₁`, `z₂ = M₂⁻¹ (r₂ − A₂₁ z₁)`, with `Mᵢ⁻¹` a
//! smoothed-aggregation V-cycle of the diagonal block `Aᵢᵢ` ([`AmgCg`]). Each diagonal
//! block is a conduction operator (with the contact terms and, for the temperatures, the
//! Joule heat's T-derivative), for which the V-cycle is built; the coupling through
//! `A₁₂` (the Joule heat's V-derivative) is left to the Krylov iteration.
//!
//! With `split` equal to the size there is one block: GMRES preconditioned by one
//! V-cycle of the whole matrix, for the unsymmetric Jacobian of a single field (k(T), a
//! temperature-dependent conductance, radiation). Each block's hierarchy is kept from
//! one factorisation to the next while the matrix keeps its structure and the solves do
//! not degrade ([`AmgCg::setup_or_refresh`]): a Newton iteration or a time step
//! refreshes the finest level's values instead of setting the hierarchy up again.
//!
//! GMRES(m) with right preconditioning, modified Gram–Schmidt and Givens rotations: it
//! stops when `‖b − A x‖ ≤ tolerance ‖b‖` (the true residual, recomputed at each
//! restart), or when a restart cycle leaves a true residual within 100 × tolerance no
//! lower (its round-off floor: a Newton step late in the iteration, whose right-hand
//! side is small against the matrix times the solution). Reductions use the fixed-chunk [`dot`] and [`norm`], so the result does
//! not depend on the thread count.

use faer::sparse::SparseColMat;

use super::amg::{AmgCg, AmgOptions, Csr};
use super::{LinearSolver, SolveError, SolveReport, check_rhs, dot, norm};

/// How far above the tolerance a true residual that no longer falls (its round-off
/// floor: `A x` of a solution far larger than the right-hand side) is accepted.
const STAGNATION: f64 = 100.0;

/// GMRES with a two-block AMG preconditioner.
pub struct BlockGmres {
    /// Where the second block starts.
    pub split: usize,
    /// Krylov vectors kept before a restart.
    pub restart: usize,
    /// Stop at ‖b − Ax‖ ≤ tolerance ‖b‖.
    pub tolerance: f64,
    pub max_iterations: usize,
    a: Csr,
    /// The second block's rows, first block's columns.
    a21: Csr,
    first: AmgCg,
    second: AmgCg,
    /// The second block's right-hand side and `A₂₁ z₁`, kept between calls.
    r2: Vec<f64>,
    t2: Vec<f64>,
}

impl BlockGmres {
    pub fn new(split: usize, tolerance: f64) -> Self {
        // The temperature block of a k(T) Jacobian is unsymmetric.
        let options = AmgOptions {
            symmetric: false,
            ..AmgOptions::default()
        };
        BlockGmres {
            split,
            restart: 60,
            tolerance,
            max_iterations: 2000,
            a: Csr::default(),
            a21: Csr::default(),
            first: AmgCg::new(options),
            second: AmgCg::new(options),
            r2: Vec::new(),
            t2: Vec::new(),
        }
    }

    /// `z = P⁻¹ r`: the block Gauss–Seidel sweep of the module docs.
    fn precondition(&mut self, r: &[f64], z: &mut [f64]) {
        let s = self.split;
        if s == r.len() {
            self.first.apply_vcycle(r, z);
            return;
        }
        let (z1, z2) = z.split_at_mut(s);
        self.first.apply_vcycle(&r[..s], z1);
        self.t2.resize(r.len() - s, 0.0);
        self.a21.spmv(z1, &mut self.t2);
        self.r2.clear();
        self.r2
            .extend(r[s..].iter().zip(&self.t2).map(|(r, t)| r - t));
        self.second.apply_vcycle(&self.r2, z2);
    }

    /// GMRES on the factored matrix; `x` holds the initial guess and the result.
    pub fn gmres(&mut self, b: &[f64], x: &mut [f64]) -> Result<SolveReport, SolveError> {
        let n = b.len();
        let bnorm = norm(b);
        if bnorm == 0.0 {
            x.fill(0.0);
            return Ok(SolveReport {
                iterations: 0,
                residual: 0.0,
            });
        }
        let m = self.restart.max(1);
        let tol = self.tolerance;
        let mut total = 0;
        let mut r = vec![0.0; n];
        let mut w = vec![0.0; n];
        let mut z = vec![0.0; n];
        let mut last = f64::INFINITY;
        loop {
            // The true residual at x.
            self.a.spmv(x, &mut r);
            r.iter_mut().zip(b).for_each(|(r, b)| *r = b - *r);
            let beta = norm(&r);
            let rel = beta / bnorm;
            // Converged; or a cycle that the rotated residual called converged while the
            // true one stays put at its round-off floor, within STAGNATION × tol.
            let stalled = rel > 0.9 * last && rel <= STAGNATION * tol;
            if rel <= tol || stalled {
                return Ok(SolveReport {
                    iterations: total,
                    residual: rel,
                });
            }
            last = rel;
            if total >= self.max_iterations {
                return Err(SolveError::NotConverged {
                    iterations: total,
                    residual: rel,
                    tolerance: tol,
                });
            }
            let mut v: Vec<Vec<f64>> = vec![r.iter().map(|r| r / beta).collect()];
            let mut zs: Vec<Vec<f64>> = Vec::with_capacity(m);
            // Hessenberg columns, Givens rotations and the rotated right-hand side.
            let mut h: Vec<Vec<f64>> = Vec::with_capacity(m);
            let (mut cs, mut sn): (Vec<f64>, Vec<f64>) =
                (Vec::with_capacity(m), Vec::with_capacity(m));
            let mut g = vec![beta];
            let mut k = 0;
            while k < m && total < self.max_iterations {
                self.precondition(&v[k], &mut z);
                self.a.spmv(&z, &mut w);
                zs.push(z.clone());
                let mut col = Vec::with_capacity(k + 2);
                for vi in &v {
                    let hij = dot(&w, vi);
                    w.iter_mut().zip(vi).for_each(|(w, v)| *w -= hij * v);
                    col.push(hij);
                }
                let hn = norm(&w);
                col.push(hn);
                for i in 0..k {
                    let (a, b) = (col[i], col[i + 1]);
                    col[i] = cs[i] * a + sn[i] * b;
                    col[i + 1] = -sn[i] * a + cs[i] * b;
                }
                let (a, b) = (col[k], col[k + 1]);
                let d = a.hypot(b);
                let (c, s) = if d == 0.0 { (1.0, 0.0) } else { (a / d, b / d) };
                col[k] = d;
                col[k + 1] = 0.0;
                cs.push(c);
                sn.push(s);
                g.push(-s * g[k]);
                g[k] *= c;
                h.push(col);
                total += 1;
                k += 1;
                if g[k].abs() <= tol * bnorm || hn == 0.0 {
                    break;
                }
                v.push(w.iter().map(|w| w / hn).collect());
            }
            // y from the triangular system, x += Z y.
            let mut y = vec![0.0; k];
            for i in (0..k).rev() {
                let s: f64 = (i + 1..k).map(|j| h[j][i] * y[j]).sum();
                y[i] = (g[i] - s) / h[i][i];
            }
            for (zj, yj) in zs.iter().zip(&y) {
                x.iter_mut().zip(zj).for_each(|(x, z)| *x += yj * z);
            }
        }
    }
}

impl BlockGmres {
    /// The hierarchies set up and refreshed since the solver was made, over its blocks.
    pub fn reuse_counts(&self) -> (usize, usize) {
        let (a, b) = (self.first.reuse_counts(), self.second.reuse_counts());
        (a.0 + b.0, a.1 + b.1)
    }

    /// The blocks' AMG solvers: one when `split` is the size.
    fn blocks(&self) -> impl Iterator<Item = &AmgCg> {
        std::iter::once(&self.first).chain((self.split < self.a.nrows).then_some(&self.second))
    }

    fn blocks_mut(&mut self) -> impl Iterator<Item = &mut AmgCg> {
        let two = self.split < self.a.nrows;
        std::iter::once(&mut self.first).chain(two.then_some(&mut self.second))
    }
}

impl LinearSolver for BlockGmres {
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), SolveError> {
        super::check_finite_ref(a.as_ref())?;
        self.a = Csr::from_csc(a.as_ref());
        let (n, s) = (self.a.nrows, self.split);
        if s >= n {
            self.split = n;
            self.first.setup_or_refresh(self.a.clone())?;
            return Ok(());
        }
        self.first.setup_or_refresh(block(&self.a, 0..s, 0..s))?;
        self.second.setup_or_refresh(block(&self.a, s..n, s..n))?;
        self.a21 = block(&self.a, s..n, 0..s);
        Ok(())
    }

    /// GMRES from zero; a solve that fails on a refreshed hierarchy is made again on
    /// hierarchies set up anew.
    fn solve(&mut self, b: &mut [f64]) -> Result<SolveReport, SolveError> {
        check_rhs(self.a.nrows, b)?;
        let rhs = b.to_vec();
        b.fill(0.0);
        let report = match self.gmres(&rhs, b) {
            Err(SolveError::NotConverged { .. }) if self.blocks().any(AmgCg::is_refreshed) => {
                for block in self.blocks_mut() {
                    block.set_up_again()?;
                }
                b.fill(0.0);
                self.gmres(&rhs, b)?
            }
            other => other?,
        };
        for block in self.blocks_mut() {
            block.note_iterations(report.iterations);
        }
        Ok(report)
    }
}

/// The block of `a`'s rows `rows` and columns `cols`, renumbered from 0.
fn block(a: &Csr, rows: std::ops::Range<usize>, cols: std::ops::Range<usize>) -> Csr {
    let mut out = Csr {
        nrows: rows.len(),
        ncols: cols.len(),
        ptr: Vec::with_capacity(rows.len() + 1),
        idx: Vec::new(),
        val: Vec::new(),
    };
    out.ptr.push(0);
    let (lo, hi) = (cols.start as u32, cols.end as u32);
    for i in rows {
        for p in a.ptr[i]..a.ptr[i + 1] {
            let j = a.idx[p];
            if (lo..hi).contains(&j) {
                out.idx.push(j - lo);
                out.val.push(a.val[p]);
            }
        }
        out.ptr.push(out.idx.len());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// Two coupled 1-D Laplacians with an unsymmetric coupling, against LU.
    #[test]
    fn gmres_solves_a_coupled_unsymmetric_system() {
        let m = 400;
        let mut t = Vec::new();
        for blk in 0..2 {
            let o = blk * m;
            for i in 0..m {
                t.push(Triplet::new(o + i, o + i, 2.0 + 0.01 * blk as f64));
                if i + 1 < m {
                    t.push(Triplet::new(o + i, o + i + 1, -1.0));
                    t.push(Triplet::new(o + i + 1, o + i, -1.0));
                }
            }
        }
        for i in 0..m {
            // T rows see V (Joule), V rows see T (σ(T)), differently.
            t.push(Triplet::new(i, m + i, -0.3));
            t.push(Triplet::new(m + i, i, 0.05));
        }
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(2 * m, 2 * m, &t).unwrap();
        let b: Vec<f64> = (0..2 * m).map(|i| ((i * 37) % 11) as f64 - 5.0).collect();
        let mut lu = super::super::Lu::new();
        lu.factor(&a).unwrap();
        let mut exact = b.clone();
        lu.solve(&mut exact).unwrap();
        let mut g = BlockGmres::new(m, 1e-12);
        g.factor(&a).unwrap();
        let mut x = b.clone();
        let report = g.solve(&mut x).unwrap();
        let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let err = x
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(
            err < 1e-9 * scale,
            "error {err:e} after {} iterations",
            report.iterations
        );
        assert!(report.iterations < 100, "{} iterations", report.iterations);
    }
}
