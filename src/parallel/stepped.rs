//! A linear transient run on MPI with its assembly distributed: the steady path's
//! set-up and Newton iteration ([`super::steady`]: each rank its own elements, the
//! interface points it owns, PETSc's rows of its nodes) with the lumped capacity of
//! the serial general solver, stepped by backward Euler or BDF2 with the serial time
//! loop's steps — fixed, or chosen by its local error estimate (the largest over every
//! rank's own dofs), attempts above the tolerance taken again with a smaller step.
//!
//! Every rank keeps its local dofs' last two states (the history of BDF2 and the
//! predictor), up to date at the dofs it reads. After each accepted step the field is
//! gathered on rank 0, which holds the whole mesh, evaluates every interface point
//! again and hands the whole state to the run (outputs, checkpoints); the other ranks
//! hand their own.
//!
//! The run takes this path where the steady solver's conditions hold
//! ([`super::Stepping`]): constant materials, sources of x alone, interface terms
//! linear or Newton-nonlinear through a temperature-dependent conductance. A step whose
//! Newton iteration does not converge (or meets a residual that is not finite, or a
//! Krylov solve that diverges) is cut in half and taken again, as the serial loop cuts
//! it, down to the run's `dt_min`; every rank sees the same failure, so they cut
//! together.

use crate::assembly::DofMap;
use crate::heat::steady::SteadyProblem;
use crate::heat::transient::{Outcome, State, StepReport, factor, predictor, unconverged, weights};
use crate::heat::{HeatError, dirichlet_dofs};

use super::Stepping;
use super::petsc::Method;
use super::steady::{Built, Capacity, Newton, agreed};

/// The run's steps over the MPI world from `s.start` to `s.end`; `on_step` gets each
/// accepted step: on rank 0 the whole state, on every other rank its own dofs. Rank 0's
/// outcome holds the whole final state, every other rank's its own dofs.
pub(super) fn solve(
    p: &SteadyProblem<'_>,
    s: &Stepping<'_>,
    on_step: &mut dyn FnMut(&StepReport, &State, &DofMap) -> Result<(), HeatError>,
) -> Result<Outcome, HeatError> {
    let built = Built::new(p, s.start)?;
    let mut newton = Newton::new(&built, true)?;
    let (n, field, root) = (built.n, built.field, built.is_root());
    let m = built.capacity(s.rho_c)?;
    // The initial field at the rank's nodes; a contact partner's nodes from their owners.
    let mut u = vec![0.0; n];
    for (node, &v) in s.initial.iter().enumerate() {
        if let Some(d) = built.dofs.dof(field, crate::mesh::NodeId(node as u32)) {
            u[d.index()] = v;
        }
    }
    built.start(&mut u, &[]);
    // This rank's state: its local dofs, up to date at those it reads, and its last two
    // accepted states before (BDF2 and the predictor read them).
    let mut mine = State {
        step: 0,
        time: s.start,
        dt: s.dt,
        u,
        past: Vec::new(),
    };
    // What the run sees: the whole state on rank 0, its own dofs elsewhere.
    let mut state = mine.clone();
    built.gather(&mut state.u);
    let mut faces = p.face_bcs.to_vec();
    let mut steps = 0;
    let eps = 1e-12 * s.end.abs().max(s.dt);
    let mut rejected_total = 0;
    while mine.time < s.end - eps {
        let time = mine.time;
        let mut rejected = 0;
        // The serial loop's attempts: the step to try (at most `dt_max`), the last one
        // to the end without a sliver before it; with adaptive steps an attempt whose
        // local error is above the tolerance is taken again with a smaller step.
        let (solved, dt, estimate, next) = loop {
            let mut dt = mine.dt.min(s.end - time);
            if let Some(a) = s.adaptive {
                dt = dt.min(a.dt_max);
            }
            if s.end - time - dt < 1e-6 * dt {
                dt = s.end - time;
            }
            let t_new = time + dt;
            log::debug!("rank step {} from t = {time} by {dt}", mine.step + 1);
            let dt_prev = mine.past.first().map(|(t, _)| time - t);
            let alpha = weights(s.scheme, dt, dt_prev);
            // The step's loads; a rank that cannot make them stops every rank.
            let loads = (s.loads)(t_new).and_then(|(dirichlet, now)| {
                let bcs = dirichlet_dofs(p.mesh, &built.dofs, field, &dirichlet)?;
                let conduction = match now != faces {
                    true => Some(built.conduction(&now)?),
                    false => None,
                };
                Ok((bcs, now, conduction))
            });
            let (bcs, now, conduction) = agreed(loads)?;
            if let Some(kf) = conduction {
                newton.set_conduction(kf);
                faces = now;
            }
            let (u, previous) = (&mine.u, mine.past.first().map(|(_, v)| v.as_slice()));
            let rest: Vec<f64> = (0..n)
                .map(|d| match m[d] != 0.0 {
                    true => (alpha[1] * u[d] + previous.map_or(0.0, |v| alpha[2] * v[d])) / dt,
                    false => 0.0,
                })
                .collect();
            let capacity = Capacity {
                m: &m,
                c0: alpha[0] / dt,
                rest: &rest,
            };
            // From the serial step's predictor (its extrapolation is local to each dof).
            let predicted = predictor(&mine, dt, s.scheme.order() as usize);
            let mut next = predicted.clone();
            built.start(&mut next, &bcs);
            let solved = newton.solve(&mut next, t_new, Some(&capacity))?;
            // A failed attempt: the serial loop's cut, the same on every rank (the
            // residual norms and the Krylov solve's outcome are global).
            let failure = (solved.failure.clone()).or_else(|| {
                (!solved.converged).then(|| unconverged(p.max_iterations, t_new, &solved.history))
            });
            if let Some(why) = failure {
                log::debug!("rank step at t = {t_new} failed, cut: {why}");
                rejected += 1;
                rejected_total += 1;
                mine.dt = dt * 0.5;
                let floor = s.adaptive.map_or(s.dt_min, |a| a.dt_min);
                if mine.dt < floor {
                    return Err(HeatError::Step(format!(
                        "at t = {time}: {why}; the step was cut to {} and may not go below {floor}",
                        mine.dt
                    )));
                }
                continue;
            }
            let Some(a) = s.adaptive else {
                break (solved, dt, None, next);
            };
            let estimate = built.local_error(s.scheme, &mine, &next, &predicted, dt);
            match estimate {
                Some(e) if e > a.tolerance => {
                    mine.dt = dt * factor(a.tolerance, e, s.scheme).clamp(0.2, 0.9);
                    rejected += 1;
                    rejected_total += 1;
                    if mine.dt < a.dt_min {
                        return Err(HeatError::Step(format!(
                            "at t = {time}: the local error {e:.3e} K stays above the tolerance {:.3e} K down to dt_min = {}",
                            a.tolerance, a.dt_min
                        )));
                    }
                }
                _ => {
                    if let Some(e) = estimate {
                        mine.dt = (dt * factor(a.tolerance, e, s.scheme).clamp(0.2, 2.0))
                            .clamp(a.dt_min, a.dt_max);
                    }
                    break (solved, dt, estimate, next);
                }
            }
            // (Rejected: `next` is dropped, the state stays.)
        };
        let t_new = time + dt;
        // Accepted: the history shifts.
        let old = std::mem::replace(&mut mine.u, next);
        mine.past.insert(0, (time, old));
        mine.past.truncate(2);
        mine.time = t_new;
        mine.step += 1;
        steps += 1;
        let mut now_u = mine.u.clone();
        built.gather(&mut now_u);
        if root {
            let old = std::mem::replace(&mut state.u, now_u);
            state.past.insert(0, (time, old));
            state.past.truncate(2);
        } else {
            state.u = now_u;
        }
        state.time = t_new;
        state.step += 1;
        state.dt = mine.dt;
        let cg = solved.cg_iterations.iter().sum();
        let report = StepReport {
            step: state.step,
            time: t_new,
            dt,
            newton_iterations: solved.iterations,
            residual_history: solved.history,
            rejected,
            error_estimate: estimate,
            heat: solved.heat,
            assembly_s: solved.timing.assembly_s,
            factor_s: solved.timing.factor_s,
            solve_s: solved.timing.solve_s,
            cg_iterations: cg,
            gmres: false,
            hierarchy_setups: match newton.method {
                Method::CgAmg => solved.setups,
                _ => 0,
            },
            hierarchy_refreshes: 0,
            electric: Vec::new(),
            diagnosis: None,
        };
        // Rank 0's outputs see every interface point; a failure there stops every rank.
        let mut clock = [std::time::Instant::now(); 3];
        let handed = match root {
            true => built
                .all_points()
                .and_then(|()| {
                    clock[1] = std::time::Instant::now();
                    on_step(&report, &state, &built.dofs)
                })
                .and_then(|()| {
                    clock[2] = std::time::Instant::now();
                    built.own_points_again(&mine.u, t_new)
                }),
            false => on_step(&report, &state, &built.dofs),
        };
        log::debug!(
            "step {}: handed to the run's outputs in {:.3} s (every point {:.3} s, outputs {:.3} s, own points again {:.3} s)",
            state.step,
            clock[0].elapsed().as_secs_f64(),
            (clock[1] - clock[0]).as_secs_f64(),
            (clock[2] - clock[1]).as_secs_f64(),
            clock[2].elapsed().as_secs_f64(),
        );
        agreed(handed)?;
    }
    let why = match (newton.method, newton.symmetric) {
        (Method::CgAmg, _) => {
            "transient steps assembled per rank, symmetric positive definite, at or above the AMG threshold → CG + BoomerAMG (hierarchy kept while the step size holds, each step started from the earlier steps' solutions)"
        }
        (_, true) => {
            "transient steps assembled per rank, below the AMG threshold (or linear_solver = \"direct\") → MUMPS LU (factorisation kept while the step size holds)"
        }
        (_, false) => {
            "transient steps assembled per rank, a temperature-dependent conductance makes the Jacobian unsymmetric → MUMPS LU at each Newton iteration"
        }
    };
    super::record(newton.method, why);
    drop(newton);
    let dofs = built.dofs.clone();
    Ok(Outcome {
        dofs,
        fields: vec![field],
        state,
        steps,
        rejected: rejected_total,
        crosspoints: Vec::new(),
    })
}
