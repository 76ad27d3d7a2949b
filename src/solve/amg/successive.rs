//! Successive right-hand sides of one matrix: a linear time stepping with a fixed step
//! solves `A x = b` with the same `A` and a new `b` every step. The solutions of the
//! earlier steps, kept orthonormal in the energy inner product `⟨x, y⟩_A = xᵀAy`,
//! give each new solve a start: with `X` that basis and `x₀` the caller's guess (a
//! predictor),
//!
//! `x₀ + X Xᵀ (b − A x₀)`
//!
//! is the point of `x₀ + span X` closest to the solution in the energy norm (Fischer,
//! *Projection techniques for iterative solution of Ax = b with successive right-hand
//! sides*, Comput. Methods Appl. Mech. Engrg. 163, 1998). The predictor is a point of
//! that set, so the start is never farther from the solution, in that norm, than the
//! predictor; for a field that evolves smoothly it is much nearer, and CG needs fewer
//! iterations to reach the same stopping test (the test itself does not change).
//!
//! After a solve, the new solution's part A-orthogonal to the basis joins it (one
//! product with `A` to normalise it); when the basis is full its oldest vector goes
//! (what is left is still A-orthonormal). A change of the matrix (a set-up or a
//! refresh of the finest level) empties it: the basis is orthonormal only for the
//! matrix it was made with.
//!
//! On the electronics warm-up at refine 6 (131 528 unknowns, 50 BDF2 steps of 5 s),
//! the CG iterations of the 50 steps went from 667 to 230 with 8 solutions kept (223
//! with 16; with 4, 463 when the oldest goes and 298 when a full basis restarts from
//! the last solution), and the temperatures at t = 250 s from 1.7e-10 to 5.5e-11 K of
//! a direct solve's.

use super::{AmgCg, SolveError, SolveReport};
use crate::solve::{REDUCE_CHUNK, dot};
use rayon::prelude::*;

/// Solutions kept for projection, at most: 8 vectors of the unknowns and their
/// products with `A` (160 MB at 1.25 M unknowns). Twice as many saved 3 % of the
/// iterations on the electronics warm-up (module docs).
pub const KEPT_SOLUTIONS: usize = 8;

/// A new solution's part outside the basis smaller than this, relative to the solution
/// in the energy norm, is round-off (the part is computed from `x` to about 1e-16 of
/// it) and is not kept.
const NEGLIGIBLE: f64 = 1e-12;

/// The A-orthonormal basis of earlier solutions of the finest level's matrix, with
/// each vector's product with `A`.
#[derive(Debug, Default)]
pub(super) struct Earlier {
    basis: Vec<Vec<f64>>,
    /// `A v` for each `v` of `basis`: each made by a product with `A` when its vector
    /// joined, so a start's residual and a solution's product need no product of their
    /// own.
    products: Vec<Vec<f64>>,
}

impl Earlier {
    /// Forget the basis: the matrix changed.
    pub(super) fn clear(&mut self) {
        self.basis.clear();
        self.products.clear();
    }

    pub(super) fn len(&self) -> usize {
        self.basis.len()
    }
}

/// What [`AmgCg::pcg_successive`] reports beside the solve's iterations: the residuals
/// `b − A x` at the caller's guess and at the solution (both true residuals, to
/// round-off: made from products with the matrix, not CG's own recursion).
#[derive(Debug)]
pub struct Successive {
    pub report: SolveReport,
    pub at_guess: Vec<f64>,
    pub at_solution: Vec<f64>,
}

impl AmgCg {
    /// PCG for one of successive right-hand sides of the same matrix (module docs):
    /// `x` holds the caller's guess. The guess is moved to the best point of its span
    /// with the earlier solutions, CG solves from there to
    /// [`AmgOptions::tolerance`](super::AmgOptions::tolerance) of ‖b‖ as
    /// [`Self::pcg`] does, and the solution joins the basis.
    ///
    /// Two products with `A` besides CG's own: the guess's residual, and the one the
    /// new basis vector needs; the moved start's residual and the solution's come from
    /// the kept products `A v` (at the cost of round-off of `A`'s size times `x`'s,
    /// as a product's own).
    pub fn pcg_successive(&mut self, b: &[f64], x: &mut [f64]) -> Result<Successive, SolveError> {
        let Some(fine) = self.levels.first() else {
            return Err(SolveError::NotFactored);
        };
        let mut at_guess = vec![0.0; b.len()];
        fine.a.spmv(x, &mut at_guess);
        at_guess
            .par_iter_mut()
            .zip(b)
            .for_each(|(r, b)| *r = b - *r);
        let mut r = self.spare.pop().unwrap_or_default();
        r.clear();
        r.extend_from_slice(&at_guess);
        let earlier = &self.earlier;
        // Each basis vector's coefficient from the guess's residual, then x and r moved
        // by all of them in one pass each.
        let c = dots(&earlier.basis, &at_guess);
        add_combination(x, &earlier.basis, &c, 1.0);
        add_combination(&mut r, &earlier.products, &c, -1.0);
        let report = self.pcg_from(b, x, r)?;
        let at_solution = self.remember(x, b);
        Ok(Successive {
            report,
            at_guess,
            at_solution,
        })
    }

    /// Earlier solutions kept for [`Self::pcg_successive`] (0 after a change of the
    /// matrix).
    pub fn kept_solutions(&self) -> usize {
        self.earlier.len()
    }

    /// Add `x`'s part A-orthogonal to the basis, `b` its right-hand side; a full
    /// basis lets its oldest vector go (the rest stay A-orthonormal). Gram–Schmidt
    /// twice: the first pass takes `Ax` as `b` (they differ by CG's residual, 1e-11 of
    /// ‖b‖), the second reads the product the norm needs anyway and removes what the
    /// first left. Late in a run a step's solution differs from the span of the
    /// earlier ones by a part many orders below `x` itself (a field near 293 K moving by
    /// millikelvin), which one pass would leave with its orthogonality to the basis at
    /// the level of `x`'s round-off: so the second pass reads a product of the part
    /// itself, never one made up from the kept products. A part below [`NEGLIGIBLE`]
    /// of `x` in the energy norm is round-off and is not added.
    ///
    /// Returns `b − A x`, with `A x` as that product plus the kept products of the
    /// first pass's coefficients.
    fn remember(&mut self, x: &[f64], b: &[f64]) -> Vec<f64> {
        let fine = &self.levels[0];
        // The oldest goes before the new part is made, so the span keeps `x` itself
        // whole (its component along the dropped vector, the bulk of the field, moves
        // into the new one). Dropping it after instead leaves the span without that
        // direction: on the electronics warm-up at refine 6 that took 490 iterations
        // instead of 230, a spike every ninth step.
        let earlier = &mut self.earlier;
        // The oldest vector and its product, when they go, lend their memory to the
        // new ones (fresh arrays of this size are paged in by the system each step).
        let (mut part, mut ap) = if earlier.basis.len() >= KEPT_SOLUTIONS {
            (earlier.basis.remove(0), earlier.products.remove(0))
        } else {
            (Vec::new(), Vec::new())
        };
        let (basis, products) = (&earlier.basis, &earlier.products);
        let energy = dot(x, b);
        let first = dots(basis, b);
        part.clear();
        part.extend_from_slice(x);
        add_combination(&mut part, basis, &first, -1.0);
        ap.resize(x.len(), 0.0);
        fine.a.spmv(&part, &mut ap);
        // b − A x = b − A part − Σ c_k A v_k; with the second pass's coefficients and
        // the part's energy, in the same pass over A part.
        let (at_solution, second, energy_of_part) =
            residual_and_dots(b, &ap, products, &first, basis, &part);
        // ‖p − Xc‖²_A = pᵀAp − |c|² for an A-orthonormal X.
        let norm2 = energy_of_part - second.iter().map(|c| c * c).sum::<f64>();
        // (A NaN anywhere fails the first test too.)
        let significant = norm2 > NEGLIGIBLE * NEGLIGIBLE * energy;
        if !significant || !energy.is_finite() {
            return at_solution;
        }
        let scale = 1.0 / norm2.sqrt();
        remove_and_scale(&mut part, basis, &mut ap, products, &second, scale);
        earlier.basis.push(part);
        earlier.products.push(ap);
        at_solution
    }
}

/// `[w · y for w in ws]`, in one pass over `y`: each dot product summed as
/// [`crate::solve::dot`] sums it (in fixed chunks, then the chunks' sums in order), so
/// with the same bits, whatever the thread count.
fn dots(ws: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    if ws.is_empty() {
        return Vec::new();
    }
    let parts: Vec<Vec<f64>> = y
        .par_chunks(REDUCE_CHUNK)
        .enumerate()
        .map(|(c, y)| {
            let at = c * REDUCE_CHUNK;
            ws.iter()
                .map(|w| {
                    (w[at..at + y.len()].iter())
                        .zip(y)
                        .map(|(w, y)| w * y)
                        .sum::<f64>()
                })
                .collect()
        })
        .collect();
    (0..ws.len())
        .map(|k| parts.iter().map(|p| p[k]).sum())
        .collect()
}

/// One pass over `A p` (`ap`) for [`AmgCg::remember`]: the residual
/// `b − ap − Σ_k c_k P_k` (the products `P` of the basis `X`), each `X_k · ap`, and
/// `p · ap` — summed as [`dots`] and [`crate::solve::dot`] sum, and the residual's
/// terms taken in the order of `k`, so the bits of the passes one after another.
fn residual_and_dots(
    b: &[f64],
    ap: &[f64],
    products: &[Vec<f64>],
    c: &[f64],
    basis: &[Vec<f64>],
    p: &[f64],
) -> (Vec<f64>, Vec<f64>, f64) {
    let mut residual = vec![0.0; b.len()];
    let k = basis.len();
    let parts: Vec<Vec<f64>> = residual
        .par_chunks_mut(REDUCE_CHUNK)
        .enumerate()
        .map(|(chunk, out)| {
            let at = chunk * REDUCE_CHUNK;
            let range = at..at + out.len();
            let ap = &ap[range.clone()];
            for ((o, b), ap) in out.iter_mut().zip(&b[range.clone()]).zip(ap) {
                *o = b - ap;
            }
            subtract_at(out, at, products, c);
            let mut sums: Vec<f64> = basis
                .iter()
                .map(|w| w[range.clone()].iter().zip(ap).map(|(w, y)| w * y).sum())
                .collect();
            sums.push(p[range].iter().zip(ap).map(|(p, y)| p * y).sum());
            sums
        })
        .collect();
    let mut sums: Vec<f64> = (0..=k).map(|j| parts.iter().map(|s| s[j]).sum()).collect();
    let energy = sums.pop().expect("k + 1 sums");
    (residual, sums, energy)
}

/// `p ← (p − Σ_k c_k X_k)·s` and `y ← (y − Σ_k c_k P_k)·s` in one pass over both,
/// each entry as [`add_combination`] and a scaling after it would leave it.
fn remove_and_scale(
    p: &mut [f64],
    basis: &[Vec<f64>],
    y: &mut [f64],
    products: &[Vec<f64>],
    c: &[f64],
    s: f64,
) {
    p.par_chunks_mut(REDUCE_CHUNK)
        .zip(y.par_chunks_mut(REDUCE_CHUNK))
        .enumerate()
        .for_each(|(chunk, (p, y))| {
            let at = chunk * REDUCE_CHUNK;
            for (out, ws) in [(&mut *p, basis), (&mut *y, products)] {
                subtract_at(out, at, ws, c);
                out.iter_mut().for_each(|o| *o *= s);
            }
        });
}

/// `y += sign Σ_k c_k w_k`, in one pass over `y`: each entry takes the terms in the
/// order of `k`, as one axpy after another would.
fn add_combination(y: &mut [f64], ws: &[Vec<f64>], c: &[f64], sign: f64) {
    if ws.is_empty() {
        return;
    }
    y.par_chunks_mut(REDUCE_CHUNK)
        .enumerate()
        .for_each(|(chunk, y)| {
            let at = chunk * REDUCE_CHUNK;
            if sign > 0.0 {
                for (w, &c) in ws.iter().zip(c) {
                    let w = &w[at..at + y.len()];
                    y.iter_mut().zip(w).for_each(|(y, w)| *y += c * w);
                }
            } else {
                subtract_at(y, at, ws, c);
            }
        });
}

/// `y −= Σ_k c_k w_k[at..]` for one chunk `y` starting at entry `at`, the terms in the
/// order of `k`.
#[inline(always)]
fn subtract_at(y: &mut [f64], at: usize, ws: &[Vec<f64>], c: &[f64]) {
    for (w, &c) in ws.iter().zip(c) {
        let w = &w[at..at + y.len()];
        y.iter_mut().zip(w).for_each(|(y, w)| *y -= c * w);
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::{residual_norm, step_matrix};
    use super::*;
    use crate::solve::amg::{AmgOptions, Csr, Served};

    fn energy(a: &Csr, x: &[f64], y: &[f64]) -> f64 {
        let mut ay = vec![0.0; y.len()];
        a.spmv(y, &mut ay);
        x.iter().zip(&ay).map(|(x, y)| x * y).sum()
    }

    /// A cool-down by backward Euler (`(L + cI) u⁺ = c u + f`, from a parabola of
    /// height 300 towards the steady field of a small source), each step from the linear predictor: with the earlier
    /// solutions projected out, every step still meets the stopping test against the
    /// matrix itself, its start is never farther from the solution in the energy norm
    /// than the predictor, the basis stays A-orthonormal, and CG needs at most half the
    /// iterations once the basis is full. A changed matrix empties the basis. (The residuals are
    /// checked at 1.2× CG's tolerance: CG's own residual, which it stops on, drifts
    /// from the true one by about 1e-11 of ‖b‖ for a field near 300 with ‖b‖ near 2.)
    #[test]
    fn earlier_solutions_start_each_step_nearer_and_a_new_matrix_forgets_them() {
        let n = 4000;
        // Slow modes: those with eigenvalues of L below c (about 4 of them) decay over
        // many steps, the rest within a few.
        let c = 1e-5;
        let a = step_matrix(n, c);
        let f: Vec<f64> = (0..n)
            .map(|i| (std::f64::consts::PI * i as f64 / n as f64).sin() * 1e-3)
            .collect();
        let options = AmgOptions {
            tolerance: 1e-10,
            ..AmgOptions::default()
        };
        let (mut plain, mut projected) = (AmgCg::new(options), AmgCg::new(options));
        assert_eq!(plain.setup_or_refresh(a.clone()).unwrap(), Served::SetUp);
        assert_eq!(
            projected.setup_or_refresh(a.clone()).unwrap(),
            Served::SetUp
        );
        let mut exact_solver = AmgCg::new(AmgOptions {
            tolerance: 1e-15,
            ..AmgOptions::default()
        });
        exact_solver.setup(a.clone()).unwrap();
        let x = |i: usize| (i + 1) as f64 / (n + 1) as f64;
        let start: Vec<f64> = (0..n).map(|i| 1200.0 * x(i) * (1.0 - x(i))).collect();
        let (mut now, mut before) = (start.clone(), start);
        let (mut plain_its, mut projected_its) = (0, 0);
        for step in 0..30 {
            let b: Vec<f64> = now.iter().zip(&f).map(|(u, f)| c * u + f).collect();
            let predictor: Vec<f64> = now.iter().zip(&before).map(|(u, v)| 2.0 * u - v).collect();
            let mut ap = vec![0.0; n];
            a.spmv(&predictor, &mut ap);
            let residual: Vec<f64> = b.iter().zip(&ap).map(|(b, a)| b - a).collect();
            let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();

            let mut x = predictor.clone();
            let its = plain.pcg(&b, &mut x).unwrap().iterations;
            if step >= 10 {
                plain_its += its;
            }
            let rn = residual_norm(&a, &x, &b);
            assert!(rn <= 1.2e-10 * bn, "step {step}: {rn:e} of {bn:e}");

            // The start the projection gives, against the solution solved far tighter.
            let mut exact = predictor.clone();
            exact_solver.pcg(&b, &mut exact).unwrap();
            let mut start = predictor.clone();
            for v in &projected.earlier.basis {
                let cv: f64 = v.iter().zip(&residual).map(|(v, r)| v * r).sum();
                start.iter_mut().zip(v).for_each(|(s, v)| *s += cv * v);
            }
            let error = |y: &[f64]| {
                let e: Vec<f64> = exact.iter().zip(y).map(|(e, y)| e - y).collect();
                energy(&a, &e, &e).sqrt()
            };
            let (from_start, from_predictor) = (error(&start), error(&predictor));
            assert!(
                from_start <= from_predictor * (1.0 + 1e-9) + 1e-12,
                "step {step}: the projected start is {from_start:e} from the solution, the predictor {from_predictor:e}"
            );

            let mut y = predictor.clone();
            let solved = projected.pcg_successive(&b, &mut y).unwrap();
            if step >= 10 {
                projected_its += solved.report.iterations;
            }
            assert!(residual_norm(&a, &y, &b) <= 1.2e-10 * bn);
            // The residuals it reports are the true ones, to a few round-offs of a
            // product, ε ‖A‖∞ max|x| (the one at the solution is made up from the kept
            // products): below a tenth of the stopping test's 1e-10 ‖b‖.
            let round_off = |at: &[f64]| {
                let a_inf = (0..n)
                    .map(|i| {
                        a.val[a.ptr[i]..a.ptr[i + 1]]
                            .iter()
                            .map(|v| v.abs())
                            .sum::<f64>()
                    })
                    .fold(0.0, f64::max);
                f64::EPSILON * a_inf * at.iter().fold(0.0f64, |m, v| m.max(v.abs()))
            };
            let off = |reported: &[f64], at: &[f64]| {
                let mut ay = vec![0.0; n];
                a.spmv(at, &mut ay);
                (b.iter().zip(&ay).zip(reported))
                    .map(|((b, ay), r)| (b - ay - r).abs())
                    .fold(0.0, f64::max)
            };
            let (guess_off, solution_off) = (
                off(&solved.at_guess, &predictor),
                off(&solved.at_solution, &y),
            );
            assert!(guess_off <= 32.0 * round_off(&predictor), "{guess_off:e}");
            assert!(
                solution_off <= 32.0 * round_off(&y),
                "{solution_off:e} against {:e}",
                round_off(&y)
            );
            assert!(
                solution_off <= 0.1 * 1e-10 * bn,
                "{solution_off:e} of {bn:e}"
            );
            assert!(projected.kept_solutions() <= KEPT_SOLUTIONS);
            before = std::mem::replace(&mut now, y);
        }
        // The basis is A-orthonormal.
        let basis = &projected.earlier.basis;
        assert!(basis.len() >= 2, "{} kept", basis.len());
        for (i, v) in basis.iter().enumerate() {
            for (j, w) in basis.iter().enumerate() {
                let g = energy(&a, v, w);
                let want = if i == j { 1.0 } else { 0.0 };
                assert!((g - want).abs() < 1e-8, "⟨v{i}, v{j}⟩_A = {g:e}");
            }
        }
        // Once the basis is full (steps 10 to 29), half the iterations or fewer.
        assert!(
            2 * projected_its <= plain_its,
            "{projected_its} iterations with the earlier solutions, {plain_its} without"
        );
        // A refreshed matrix: the basis belonged to the old one.
        let changed = step_matrix(n, 1.01 * c);
        assert_eq!(
            projected.setup_or_refresh(changed.clone()).unwrap(),
            Served::Refreshed
        );
        assert_eq!(projected.kept_solutions(), 0);
        let b: Vec<f64> = now.iter().zip(&f).map(|(u, f)| 1.01 * c * u + f).collect();
        let mut y = now.clone();
        projected.pcg_successive(&b, &mut y).unwrap();
        let bn = b.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(residual_norm(&changed, &y, &b) <= 1.2e-10 * bn);
        assert_eq!(projected.kept_solutions(), 1);
    }
}
