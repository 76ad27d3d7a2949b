//! One step's Newton iteration: the time history it needs, the linear solvers kept
//! between iterations and steps, and the test for a linear step.

use std::cell::RefCell;

use crate::assembly::Assembler;
use crate::heat::{FaceBc, HeatError};
use crate::parallel::{GeneralSolve, System};
use crate::solve::{
    AmgCg, AmgOptions, BlockGmres, Cholesky, LinearSolver, Lu, Ordering, SaddleLdlt, SolveError,
    apply_dirichlet, apply_dirichlet_parts, spmv,
};
use faer::sparse::SparseColMat;

use super::setup::Setup;
use super::{Failure, Loads, StepReport, TransientProblem};
use crate::heat::dual::CondensedSteps;

/// The time history a step needs.
pub(super) struct History<'s> {
    pub(super) dt: f64,
    pub(super) alpha: [f64; 3],
    pub(super) current: &'s [f64],
    pub(super) previous: Option<&'s [f64]>,
}

/// The linear solvers, kept across steps (symbolic analyses are reused).
pub(super) struct Solvers {
    pub(super) chol: Cholesky,
    pub(super) saddle: SaddleLdlt,
    pub(super) lu: Lu,
    pub(super) amg: AmgCg,
    /// GMRES preconditioned block by block (temperatures, voltages) for a coupled
    /// thermal–electrical Jacobian, or by one V-cycle for an unsymmetric one of a
    /// single field; made at its first use.
    pub(super) gmres: Option<BlockGmres>,
    /// The values of the matrix factored last and which solver holds it: a linear
    /// problem stepping with a fixed step reuses the factorisation (bit for bit the
    /// same as factoring again).
    pub(super) factored: Option<(Vec<f64>, Which)>,
    /// The step matrix of the last assembly: later ones refresh its values in place
    /// (the pattern does not change over a run).
    pub(super) matrix: Option<SparseColMat<usize, f64>>,
    /// For AMG-CG on one process, the step matrix's values over the pattern's own
    /// structure instead (no 64-bit copy of it): the hierarchy's finest level is the
    /// matrix, so these serve only to hand it over and are let go once it has.
    pub(super) values: Vec<f64>,
    /// Under MPI, the solves by PETSc over every rank in place of the solvers above.
    pub(super) distributed: Option<GeneralSolve>,
    /// Dual ties condensed out of symmetric step systems from the threshold on; made at
    /// its first use.
    pub(super) dual: Option<CondensedSteps>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Which {
    Saddle,
    Cholesky,
    Lu,
    Amg,
    Gmres,
}

impl Solvers {
    pub(super) fn new(setup: &Setup, sequential: bool) -> Self {
        let mut chol = Cholesky::new(Ordering::Metis);
        chol.sequential = sequential;
        let mut saddle = SaddleLdlt::with_primal(setup.n_primal, setup.n, Ordering::Metis);
        saddle.sequential = sequential;
        Solvers {
            chol,
            saddle,
            lu: Lu::new(),
            amg: AmgCg::new(AmgOptions {
                tolerance: crate::heat::steady::AMG_TOLERANCE,
                ..AmgOptions::default()
            }),
            gmres: None,
            factored: None,
            matrix: None,
            values: Vec::new(),
            distributed: crate::parallel::general_solve(),
            dual: None,
        }
    }
}

pub(super) struct Context<'c, 'a> {
    pub(super) p: &'c TransientProblem<'a>,
    pub(super) setup: &'c Setup,
    /// Where the interfaces' couplings start in the assembler.
    pub(super) first: usize,
    /// The face-derivative signature under which the element matrix slots were last
    /// computed for a linear problem (None: not kept).
    pub(super) element_matrices: RefCell<Option<Vec<(u32, u8, f64)>>>,
    /// What the last element loop over kept matrices read (the assembler's element
    /// vectors are what it made): a loop asked again with the same is not run.
    pub(super) element_inputs: RefCell<Option<super::assemble::ElementInputs>>,
    /// Scratch of the capacity terms, (residual, diagonal) per lumped dof.
    pub(super) capacity_terms: RefCell<Vec<(f64, f64)>>,
    pub(super) tie_first: &'c [usize],
    /// Where each electrical contact's couplings start in the assembler.
    pub(super) electric_first: &'c [usize],
    /// The electrical contacts' current and Joule heat at the last assembly.
    pub(super) power: RefCell<Vec<crate::heat::electric::ContactPower>>,
    /// The report of the last Newton attempt that ran out of iterations (its
    /// `diagnosis` set), for a steady solve to hand on with its last iterate.
    pub(super) unconverged: RefCell<Option<StepReport>>,
    /// The live part of the problem once elements have died.
    pub(super) alive: RefCell<Option<super::death::Alive>>,
    /// The voltage has not been solved yet (a fresh start, until a Newton solve
    /// converges): a Newton solve's first iteration solves for the voltages alone, the
    /// temperatures held (see [`Context::newton`]).
    pub(super) settle_voltage: &'c std::cell::Cell<bool>,
}

/// Why Newton ran out of iterations, from its residual history: the history itself and
/// the likely cause.
pub(crate) fn unconverged(iterations: usize, t: f64, history: &[f64]) -> String {
    let shown: Vec<String> = history.iter().map(|r| format!("{r:.3e}")).collect();
    let (first, last) = (history[0], history[history.len() - 1]);
    let falling = history.len() >= 2 && last < 0.5 * history[history.len() - 2];
    let cause = if last > first {
        "the residual grew: the iterates move away from the answer, as a strongly nonlinear law (radiation, k(T), a temperature-dependent conductance) does from a guess far from it; give an [initial] temperature nearer the expected one, or reach the steady state through a transient run".to_string()
    } else if falling {
        format!("the residual is still falling: raise [solve] max_iterations (now {iterations})")
    } else {
        "the residual stalls: the Jacobian does not match the residual (a plugin whose derivatives are wrong, a law that is not smooth), or the tolerance asks for more than round-off allows; `seam check-plugin` checks a plugin's derivatives".to_string()
    };
    format!(
        "Newton did not converge in {iterations} iterations at t = {t}: ‖R‖ = {}; {cause}",
        shown.join(" → ")
    )
}

/// AMG hierarchies set up and refreshed by the solvers so far.
fn solvers_counts(s: &Solvers) -> (usize, usize) {
    let (a, b) = s.amg.reuse_counts();
    let (c, d) = s.gmres.as_ref().map_or((0, 0), BlockGmres::reuse_counts);
    let (e, f) = s.dual.as_ref().map_or((0, 0), CondensedSteps::reuse_counts);
    (a + c + e, b + d + f)
}

/// The right-hand side `J u + Δb` of a linear step's own system `J x = b`, from its
/// increment's system `J Δu = Δb` at `u`.
/// `product(x, y)` sets `y = J x`.
fn step_system(product: impl Fn(&[f64], &mut [f64]), rhs: &[f64], u: &[f64]) -> Vec<f64> {
    let mut b = vec![0.0; rhs.len()];
    product(u, &mut b);
    b.iter_mut().zip(rhs).for_each(|(b, r)| *b += r);
    b
}

/// `y = J x`: by the step matrix, or without one (AMG-CG over the pattern's values) by
/// the hierarchy's finest level, which is that matrix.
fn multiply(jac: &Option<SparseColMat<usize, f64>>, amg: &AmgCg, x: &[f64], y: &mut [f64]) {
    match jac {
        Some(jac) => spmv(jac, x, y),
        None => amg.apply(x, y),
    }
}

/// Under MPI: the increment's system `jac Δu = rhs` solved by PETSc over every rank
/// (`rhs` becomes Δu) — or, from `predictor` `u`, the step's own system `jac x = jac u +
/// rhs` from `x = u`, as the serial AMG-CG does. The set-up and solve seconds and the
/// Krylov iterations.
fn solve_distributed(
    d: &mut GeneralSolve,
    jac: &SparseColMat<usize, f64>,
    rhs: &mut [f64],
    predictor: Option<&[f64]>,
    system: System,
) -> Result<(f64, f64, usize), HeatError> {
    let solved = match predictor {
        Some(u) => {
            let b = step_system(|x, y| spmv(jac, x, y), rhs, u);
            let s = d.solve(jac, &b, Some(u), system)?;
            for ((d, x), u) in rhs.iter_mut().zip(&s.x).zip(u) {
                *d = x - u;
            }
            s
        }
        None => {
            let s = d.solve(jac, rhs, None, system)?;
            rhs.copy_from_slice(&s.x);
            s
        }
    };
    Ok((solved.setup_s, solved.solve_s, solved.iterations))
}

impl Context<'_, '_> {
    /// Newton at time `t` from the guess `u` (updated in place). `Ok(Err(msg))`: the
    /// attempt failed and may be retried with a smaller step.
    pub(super) fn newton(
        &self,
        asm: &mut Assembler<'_>,
        solvers: &mut Solvers,
        u: &mut [f64],
        t: f64,
        history: Option<History<'_>>,
    ) -> Result<Result<StepReport, String>, HeatError> {
        let p = self.p;
        let setup = self.setup;
        let loads = (p.loads)(t)?;
        let bcs = setup.dirichlet(p.mesh, &loads)?;
        if bcs.len() != setup.dirichlet_dofs.len() {
            return Err(HeatError::Step(format!(
                "the Dirichlet nodes changed at t = {t}: {} now against {} at the start",
                bcs.len(),
                setup.dirichlet_dofs.len()
            )));
        }
        for &(d, g) in &bcs {
            u[d] = g;
        }
        let linear = self.is_linear(&loads);
        let mut report = StepReport {
            step: 0,
            time: t,
            dt: history.as_ref().map_or(0.0, |h| h.dt),
            newton_iterations: 0,
            residual_history: Vec::new(),
            rejected: 0,
            error_estimate: None,
            heat: Vec::new(),
            assembly_s: 0.0,
            factor_s: 0.0,
            solve_s: 0.0,
            cg_iterations: 0,
            gmres: false,
            hierarchy_setups: 0,
            hierarchy_refreshes: 0,
            electric: Vec::new(),
            diagnosis: None,
        };
        let zero: Vec<(usize, f64)> = bcs.iter().map(|&(d, _)| (d, 0.0)).collect();
        // A fresh voltage is 0 inside and its boundary values at the ends, and Joule
        // heat linearised about that jump is far from the truth (a first Newton step
        // from it overshoots the temperatures by hundreds of kelvin, enough to turn a
        // σ(T) negative). So the first iteration solves the current's equations alone
        // at the starting temperatures, which is linear for a conductivity that does
        // not depend on V; Newton goes on from that voltage.
        let mut settle = self.settle_voltage.get().then(|| {
            let mut held = zero.clone();
            held.extend(setup.outside_voltage().into_iter().map(|d| (d, 0.0)));
            held
        });
        // The last Newton update relative to max|u|.
        let mut last_update = f64::INFINITY;
        // A linear step's residual after its solve, and its interface systems.
        let mut carried = None;
        // AMG-CG for a symmetric positive definite step system from the threshold on.
        let large = setup.ties.is_empty() && p.amg_threshold.is_some_and(|k| setup.n >= k);
        let symmetric = linear;
        let amg = large && symmetric;
        // Dual ties, every one switched on, in a symmetric step system from the
        // threshold on: condensed, the step starting on their constraints.
        let dual = symmetric
            && solvers.distributed.is_none()
            && !setup.ties.is_empty()
            && setup.ties.iter().all(|t| t.dual)
            && p.amg_threshold.is_some_and(|k| setup.n_primal >= k)
            && (p.interfaces).is_some_and(|i| (0..setup.ties.len()).all(|k| i.tie_on(k, t)));
        if dual {
            let steps = match solvers.dual.take() {
                Some(steps) => steps,
                None => CondensedSteps::new(&setup.ties, setup.n_primal)?,
            };
            steps.constrain(u);
            solvers.dual = Some(steps);
        }
        // A linear time step by AMG-CG on one process solves the step's own system
        // `J x = b` from the predictor (below). Its right-hand side is the residual at
        // `u₀`, `u` with every unknown but the held ones set to 0: `R(x) = R(u₀) +
        // J (x − u₀)` and `x − u₀` vanishes on the held rows, so `b = −R(u₀)` there
        // (and the held values on theirs). An assembly at `u₀` reads no kept element
        // matrix but those of the elements with a held node (`K_e T_e` is zero
        // elsewhere): the 600 MB of them at 1.17 M hexes are not read every step.
        let from_zero = amg
            && history.is_some()
            && solvers.distributed.is_none()
            && settle.is_none()
            && p.max_iterations > 0;
        let at_zero = from_zero.then(|| {
            let mut z = vec![0.0; u.len()];
            for &(d, _) in &bcs {
                z[d] = u[d];
            }
            z
        });
        for it in 0..=p.max_iterations {
            let clock = std::time::Instant::now();
            // The flux terms' heat at u: known from an assembly at u, not after a
            // linear step moved u without one.
            let at = match (&at_zero, it) {
                (Some(z), 0) => z.as_slice(),
                _ => &*u,
            };
            let (mut r, flux) = match carried.take() {
                Some(r) => (r, None),
                None => match self.assemble(asm, at, t, &loads, history.as_ref(), linear) {
                    Ok((r, flux)) => (r, Some(flux)),
                    Err(Failure::Retry(msg)) => return Ok(Err(msg)),
                    Err(Failure::Fatal(e)) => return Err(e),
                },
            };
            for &(d, _) in &bcs {
                r[d] = 0.0;
            }
            if let Some(steps) = solvers.dual.as_ref().filter(|_| dual && it > 0) {
                steps.multipliers(&setup.ties, &setup.lambda_first, u, &mut r);
            }
            // (From u₀: replaced by the predictor's residual once the solve has it.)
            let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
            report.residual_history.push(rn);
            report.assembly_s += clock.elapsed().as_secs_f64();
            if !rn.is_finite() {
                return Ok(Err(format!("the residual is not finite at t = {t}")));
            }
            let done = it > 0 && (linear || last_update <= p.tolerance);
            if done || it == p.max_iterations {
                let flux = match flux {
                    Some(flux) => flux,
                    None => match p.interfaces.map_or(Ok(Vec::new()), |i| i.heat(u, t)) {
                        Ok(flux) => flux,
                        Err(e) => return Err(HeatError::Contact(e.to_string())),
                    },
                };
                report.heat = self.heat(flux, u);
                report.electric = self.power.borrow().clone();
                if !done {
                    let message = unconverged(p.max_iterations, t, &report.residual_history);
                    report.diagnosis = Some(message.clone());
                    *self.unconverged.borrow_mut() = Some(report);
                    return Ok(Err(message));
                }
                // Solved: later steps start from a voltage that is one.
                self.settle_voltage.set(false);
                return Ok(Ok(report));
            }
            let clock = std::time::Instant::now();
            // An unsymmetric Jacobian (a nonlinear law; coupled thermal–electrical
            // fields): GMRES preconditioned by AMG, block by block.
            let gmres = large && !symmetric;
            let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            let settling = settle.take();
            let held = settling.as_ref().unwrap_or(&zero);
            // AMG-CG on one process takes the values over the pattern's structure; every
            // other solve a matrix of its own. Values that are the bits handed over last
            // time (a linear step with the step size of the last: the element matrices
            // kept, the capacity and interface terms the same) are the matrix the
            // hierarchy holds already: neither summed nor compared again.
            let mut values_changed = true;
            let jac = if amg && solvers.distributed.is_none() {
                let mut values = std::mem::take(&mut solvers.values);
                values_changed = asm.values_into_if_changed(&mut values)?;
                if values_changed {
                    let (col_ptr, rows) = asm.pattern().structure().expect("built");
                    apply_dirichlet_parts(col_ptr, rows, &mut values, &mut rhs, held)?;
                } else {
                    // The elimination's part in the right-hand side: the held values
                    // are zeros, so only their own rows.
                    for &(d, g) in held {
                        debug_assert_eq!(g, 0.0);
                        rhs[d] = g;
                    }
                }
                solvers.values = values;
                None
            } else {
                let mut jac = match solvers.matrix.take() {
                    Some(mut kept) => {
                        asm.refresh_matrix(&mut kept)?;
                        kept
                    }
                    None => asm.matrix()?,
                };
                apply_dirichlet(&mut jac, &mut rhs, held)?;
                Some(jac)
            };
            report.assembly_s += clock.elapsed().as_secs_f64();
            // A linear time step by AMG-CG solves the step's own system from the
            // predictor (below).
            let from_predictor = linear && history.is_some();
            // From u₀: the residuals `b − J x` at the predictor and at the solution.
            let mut residuals = None;
            let solved = (|| -> Result<(f64, f64, usize), HeatError> {
                if let Some(d) = solvers.distributed.as_mut() {
                    let system = match setup.voltage {
                        _ if amg => System::Spd,
                        Some(v) if gmres => System::Coupled {
                            at: setup.dofs.field_range(v).start,
                        },
                        None if gmres => System::Unsymmetric,
                        _ => System::Direct,
                    };
                    let predictor = from_predictor && system == System::Spd;
                    let jac = jac.as_ref().expect("a matrix of its own under MPI");
                    return solve_distributed(d, jac, &mut rhs, predictor.then_some(&*u), system);
                }
                if let Some(steps) = solvers.dual.as_mut().filter(|_| dual) {
                    let jac = jac.as_ref().expect("a step matrix of its own");
                    let before = steps.reuse_counts();
                    let solved = steps.solve(jac, &mut rhs, held)?;
                    let after = steps.reuse_counts();
                    report.hierarchy_setups += after.0 - before.0;
                    report.hierarchy_refreshes += after.1 - before.1;
                    return Ok(solved);
                }
                let t0 = std::time::Instant::now();
                let same = jac.as_ref().and_then(|jac| {
                    solvers
                        .factored
                        .as_ref()
                        .filter(|(v, _)| v.as_slice() == jac.val())
                        .map(|(_, w)| *w)
                });
                let which = match (same, jac.as_ref()) {
                    (Some(w), _) => w,
                    // The values handed over last time: the hierarchy holds them.
                    (None, None) if !values_changed && !solvers.amg.hierarchy().rows.is_empty() => {
                        Which::Amg
                    }
                    // AMG-CG over the pattern's values (a kept hierarchy tells an
                    // unchanged matrix itself).
                    (None, None) => {
                        let before = solvers_counts(solvers);
                        let (col_ptr, rows) = asm.pattern().structure().expect("built");
                        (solvers.amg).factor_or_refresh_parts(
                            col_ptr,
                            rows,
                            &mut solvers.values,
                        )?;
                        // The hierarchy's finest level holds the matrix now: the values
                        // (260 MB at 1.25 M unknowns) are not kept beside it.
                        solvers.values = Vec::new();
                        let after = solvers_counts(solvers);
                        report.hierarchy_setups += after.0 - before.0;
                        report.hierarchy_refreshes += after.1 - before.1;
                        Which::Amg
                    }
                    (None, Some(jac)) => {
                        solvers.factored = None;
                        let tied = !setup.ties.is_empty();
                        let before = solvers_counts(solvers);
                        let w = if gmres {
                            let split = setup
                                .voltage
                                .map_or(setup.n, |v| setup.dofs.field_range(v).start);
                            let g = solvers.gmres.get_or_insert_with(|| {
                                BlockGmres::new(split, crate::heat::steady::AMG_TOLERANCE)
                            });
                            g.factor(jac)?;
                            Which::Gmres
                        } else if tied && symmetric && solvers.saddle.factor(jac).is_ok() {
                            Which::Saddle
                        } else if !tied && symmetric && solvers.chol.factor(jac).is_ok() {
                            Which::Cholesky
                        } else {
                            solvers.lu.factor(jac)?;
                            Which::Lu
                        };
                        if linear {
                            solvers.factored = Some((jac.val().to_vec(), w));
                        }
                        let after = solvers_counts(solvers);
                        report.hierarchy_setups += after.0 - before.0;
                        report.hierarchy_refreshes += after.1 - before.1;
                        w
                    }
                };
                let factor_s = t0.elapsed().as_secs_f64();
                let t1 = std::time::Instant::now();
                let cg = match which {
                    Which::Saddle => {
                        solvers.saddle.solve(&mut rhs)?;
                        0
                    }
                    Which::Cholesky => {
                        solvers.chol.solve(&mut rhs)?;
                        0
                    }
                    Which::Lu => {
                        solvers.lu.solve(&mut rhs)?;
                        0
                    }
                    // A linear time step is the system J u = b of the step itself: CG
                    // starts from the predictor and stops at the tolerance relative to
                    // ‖b‖, as a direct solve's backward error is, rather than relative
                    // to the predictor's residual, which a good predictor has already
                    // made small (the default stopping rule of PETSc's KSP). The start
                    // is the predictor moved to its best point in the span of the
                    // earlier steps' solutions of the same matrix (`rhs` is the
                    // predictor's residual `b − J u`). `rhs` is `−R(u₀)`: `b` but on
                    // the held rows (see `from_zero`).
                    Which::Amg if from_zero && it == 0 => {
                        let mut b = std::mem::take(&mut rhs);
                        for &(d, _) in held {
                            b[d] = u[d];
                        }
                        let mut x = u.to_vec();
                        let solved = solvers.amg.pcg_successive(&b, &mut x)?;
                        rhs = b;
                        for ((d, x), u) in rhs.iter_mut().zip(&x).zip(u.iter()) {
                            *d = x - u;
                        }
                        let iterations = solved.report.iterations;
                        solvers.amg.note_iterations(iterations);
                        residuals = Some((solved.at_guess, solved.at_solution));
                        iterations
                    }
                    Which::Amg => {
                        let its = solvers.amg.solve(&mut rhs)?.iterations;
                        solvers.amg.note_iterations(its);
                        its
                    }
                    Which::Gmres => {
                        report.gmres = true;
                        let g = solvers.gmres.as_mut().ok_or(SolveError::NotFactored)?;
                        g.solve(&mut rhs)?.iterations
                    }
                };
                Ok((factor_s, t1.elapsed().as_secs_f64(), cg))
            })();
            let (factor_s, solve_s, cg) = match solved {
                Ok(x) => x,
                Err(HeatError::Solve(e)) => {
                    return Ok(Err(format!("the linear solve failed at t = {t}: {e}")));
                }
                Err(e) => return Err(e),
            };
            // R = −(b − J x): at the predictor (the first residual of the history, in
            // place of u₀'s), and after the step (carried below).
            let after = residuals.map(|(at_guess, at_solution)| {
                let rn = at_guess.iter().map(|v| v * v).sum::<f64>().sqrt();
                *report.residual_history.last_mut().expect("pushed above") = rn;
                at_solution.into_iter().map(|v| -v).collect::<Vec<f64>>()
            });
            let rn = report.residual_history.last().copied().unwrap_or(rn);
            log::debug!(
                "t = {t}: Newton iteration {} from ‖R‖ = {rn:.3e}: linear set-up {factor_s:.3} s, solve {solve_s:.3} s, {cg} Krylov iterations",
                it + 1
            );
            report.factor_s += factor_s;
            report.solve_s += solve_s;
            report.cg_iterations += cg;
            report.newton_iterations += 1;
            // The update relative to the field's size: the species (other units) apart
            // from the temperatures, voltages and multipliers.
            let species = setup.species_start()..setup.n_primal;
            let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let step = largest(&rhs[..species.start]).max(largest(&rhs[species.end..]));
            let species_step = largest(&rhs[species.clone()]);
            for (ui, d) in u.iter_mut().zip(&rhs) {
                *ui += d;
            }
            if let Some(after) = after {
                carried = Some(after);
            } else if linear {
                // The residual of a linear system at u + du is R + J du: no second
                // assembly (J's Dirichlet rows and columns are the identity, and du
                // vanishes there).
                let clock = std::time::Instant::now();
                let mut jdu = vec![0.0; r.len()];
                multiply(&jac, &solvers.amg, &rhs, &mut jdu);
                r.iter_mut().zip(&jdu).for_each(|(r, j)| *r += j);
                carried = Some(r);
                report.assembly_s += clock.elapsed().as_secs_f64();
            }
            if jac.is_some() {
                solvers.matrix = jac;
            }
            let u_max = largest(&u[..species.start]).max(f64::MIN_POSITIVE);
            let c_max = largest(&u[species]).max(f64::MIN_POSITIVE);
            last_update = (step / u_max).max(species_step / c_max);
            if settling.is_some() {
                // Only the voltages moved: no measure of the temperatures' convergence.
                last_update = f64::INFINITY;
            }
        }
        unreachable!("the loop returns at its last iteration")
    }

    /// Is the step's system linear (constant laws, linear faces, constant conductances,
    /// sources that do not depend on T)?
    pub(super) fn is_linear(&self, loads: &Loads) -> bool {
        self.p
            .laws
            .iter()
            .all(|l| l.conductivity.is_constant() && l.capacity.is_constant())
            && loads
                .faces
                .iter()
                .all(|f| !matches!(f, FaceBc::Radiation { .. }))
            && self.p.interfaces.is_none_or(|i| i.is_linear())
            && (self.p.block_source).is_none_or(|s| s.iter().all(|q| !q.uses_temperature()))
            && self.p.electric.is_none()
            && (self.p.species.as_ref())
                .is_none_or(|s| s.diffusivity.iter().flatten().all(|d| d.is_constant()))
    }
}
