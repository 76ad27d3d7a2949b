//! A transient run of one field on MPI with its assembly distributed: the steady path's
//! set-up and Newton iteration ([`super::steady`]: each rank its own elements, the
//! interface points it owns, PETSc's rows of its nodes) with the lumped capacity of
//! the serial general solver, stepped by backward Euler or BDF2 with the serial time
//! loop's steps — fixed, or chosen by its local error estimate (the largest over every
//! rank's own dofs), attempts above the tolerance taken again with a smaller step. A
//! steady run whose conductivity depends on T is its one Newton solve at the start time
//! (the serial general solver's steady solve, reported as step 0).
//!
//! Every rank keeps its local dofs' last two states (the history of BDF2 and the
//! predictor), up to date at the dofs it reads. After each accepted step the field is
//! gathered on rank 0, which holds the whole mesh, evaluates every interface point
//! again and hands the whole state to the run (outputs, checkpoints); the other ranks
//! hand their own.
//!
//! The run takes this path where the steady solver's conditions hold but for k
//! ([`super::Stepping`]): constant ρc, k constant or a law of T (then assembled at every
//! iterate), sources of x alone, interface terms linear or Newton-nonlinear through a
//! temperature-dependent conductance. A step whose
//! Newton iteration does not converge (or meets a residual that is not finite, or a
//! Krylov solve that diverges) is cut in half and taken again, as the serial loop cuts
//! it, down to the run's `dt_min`; every rank sees the same failure, so they cut
//! together.

use crate::assembly::DofMap;
use crate::heat::steady::SteadyProblem;
use crate::heat::transient::{Outcome, State, StepReport, factor, predictor, unconverged, weights};
use crate::heat::{HeatError, dirichlet_dofs};

use super::Stepping;
use super::conduction::Capacity;
use super::petsc::Method;
use super::session::agreed;
use super::steady::{Built, Newton, Solved};

/// The run's steps over the MPI world from `s.start` to `s.end`; `on_step` gets each
/// accepted step: on rank 0 the whole state, on every other rank its own dofs. Rank 0's
/// outcome holds the whole final state, every other rank's its own dofs.
pub(super) fn solve(
    p: &SteadyProblem<'_>,
    s: &Stepping<'_>,
    on_step: &mut dyn FnMut(&StepReport, &State, &DofMap) -> Result<(), HeatError>,
) -> Result<Outcome, HeatError> {
    // From a checkpoint: its step, time and step size, from rank 0.
    let header = s.restart.map(Header::of);
    let start = header.as_ref().map_or(s.start, |h| h.time);
    let built = Built::new(p, start, Some(s.laws), !s.steady)?;
    let mut newton = Newton::new(&built, !s.steady)?;
    let (n, field, root) = (built.n, built.field, built.is_root());
    let (m, lumped) = built.capacity(s.laws.capacity)?;
    // This rank's state: its local dofs, up to date at those it reads, and its last two
    // accepted states before (BDF2 and the predictor read them).
    let mut mine = match (s.restart, &header) {
        (Some(checkpoint), Some(h)) => h.state(&built, checkpoint)?,
        _ => {
            // The initial field at the rank's nodes; a contact partner's nodes from
            // their owners.
            let mut u = vec![0.0; n];
            for (node, &v) in s.initial.iter().enumerate() {
                if let Some(d) = built.dofs.dof(field, crate::mesh::NodeId(node as u32)) {
                    u[d.index()] = v;
                }
            }
            built.start(&mut u, &[]);
            State {
                step: 0,
                time: s.start,
                dt: s.dt,
                u,
                past: Vec::new(),
            }
        }
    };
    // What the run sees: the whole state on rank 0, its own dofs elsewhere (a
    // checkpoint's is rank 0's already: no rank gathers).
    let mut state = mine.clone();
    match s.restart {
        Some(checkpoint) if root => state = checkpoint.clone(),
        Some(_) => {}
        None => built.gather(&mut state.u),
    }
    if s.steady {
        // (From a checkpoint too, the steady solve is at the run's start, from the
        // checkpoint's state, as serially.)
        mine.time = s.start;
        return steady(p, (&built, &mut newton), mine, on_step);
    }
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
                // New face conditions or sources of time: the conduction again, unless
                // it is assembled at every iterate (a conduction of T).
                let conduction = if built.nonlinear {
                    (now != faces).then_some(None)
                } else if now != faces || built.sources_in_time() {
                    Some(Some(built.conduction(&now, t_new)?))
                } else {
                    None
                };
                Ok((bcs, now, conduction))
            });
            let (bcs, now, conduction) = agreed(loads)?;
            if let Some(linear) = conduction {
                newton.set_faces(now.clone(), linear);
                faces = now;
            }
            let (u, previous) = (&mine.u, mine.past.first().map(|(_, v)| v.as_slice()));
            let rest: Vec<f64> = (0..n)
                .map(|d| (alpha[1] * u[d] + previous.map_or(0.0, |v| alpha[2] * v[d])) / dt)
                .collect();
            let capacity = Capacity {
                m: &m,
                c0: alpha[0] / dt,
                rest: &rest,
                of_t: (built.capacity_of_t).then_some((&lumped, s.laws.capacity, t_new)),
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
        let report = StepReport {
            step: state.step,
            time: t_new,
            dt,
            rejected,
            error_estimate: estimate,
            ..report(solved, newton.method)
        };
        hand_over(&built, &report, (&state, &mine.u), on_step)?;
    }
    record(&newton, &built, "transient steps assembled per rank");
    drop(newton);
    let dofs = built.dofs.clone();
    Ok(Outcome {
        dofs,
        fields: vec![field],
        state,
        steps,
        rejected: rejected_total,
        crosspoints: built.crosspoints(),
    })
}

/// A checkpoint's step, time, next step size and past times, as rank 0 read them.
struct Header {
    step: usize,
    time: f64,
    dt: f64,
    past: Vec<f64>,
}

impl Header {
    /// Rank 0's `checkpoint` (any state on the other ranks), on every rank
    /// (`MPI_Bcast`, 48 B).
    fn of(checkpoint: &State) -> Header {
        use mpi::traits::{Communicator, Root};
        let world = super::session::comm();
        let mut h = [0.0; 6];
        if world.rank() == 0 {
            h[..4].copy_from_slice(&[
                checkpoint.step as f64,
                checkpoint.time,
                checkpoint.dt,
                checkpoint.past.len().min(2) as f64,
            ]);
            for (k, (t, _)) in checkpoint.past.iter().take(2).enumerate() {
                h[4 + k] = *t;
            }
        }
        world.process_at_rank(0).broadcast_into(&mut h[..]);
        Header {
            step: h[0] as usize,
            time: h[1],
            dt: h[2],
            past: h[4..4 + h[3] as usize].to_vec(),
        }
    }

    /// This rank's part of rank 0's `checkpoint`: its values and its past states' at
    /// the rank's local dofs. A checkpoint whose states do not hold one value per dof of
    /// the problem (another problem's) stops every rank, as serially.
    fn state(&self, built: &Built<'_>, checkpoint: &State) -> Result<State, HeatError> {
        let whole = built.dofs.len();
        let fits = !built.is_root()
            || std::iter::once(&checkpoint.u)
                .chain(checkpoint.past.iter().map(|(_, v)| v))
                .all(|v| v.len() == whole);
        agreed(match fits {
            true => Ok(()),
            false => Err(HeatError::Step(format!(
                "the state has {} values but the problem has {whole} dofs (a checkpoint of another problem?)",
                checkpoint.u.len()
            ))),
        })?;
        let past = (self.past.iter().enumerate())
            .map(|(k, &t)| {
                (
                    t,
                    built.scatter(checkpoint.past.get(k).map_or(&[][..], |p| &p.1)),
                )
            })
            .collect();
        Ok(State {
            step: self.step,
            time: self.time,
            dt: self.dt,
            u: built.scatter(&checkpoint.u),
            past,
        })
    }
}

/// The one steady solve of a run whose conductivity depends on temperature, from the
/// state `mine` at its start: the serial general solver's steady solve, reported as its
/// step 0 (a Newton iteration that runs out goes on marked not converged, as there).
fn steady(
    p: &SteadyProblem<'_>,
    (built, newton): (&Built<'_>, &mut Newton<'_, '_>),
    mut mine: State,
    on_step: &mut dyn FnMut(&StepReport, &State, &DofMap) -> Result<(), HeatError>,
) -> Result<Outcome, HeatError> {
    let t = mine.time;
    built.start(&mut mine.u, &built.bcs);
    let solved = newton.solve(&mut mine.u, t, None)?;
    if let Some(why) = &solved.failure {
        return Err(HeatError::Step(why.clone()));
    }
    let diagnosis = (!solved.converged).then(|| unconverged(p.max_iterations, t, &solved.history));
    let report = StepReport {
        step: 0,
        time: t,
        dt: 0.0,
        diagnosis,
        ..report(solved, newton.method)
    };
    let mut state = mine.clone();
    built.gather(&mut state.u);
    hand_over(built, &report, (&state, &mine.u), on_step)?;
    record(newton, built, "a steady solve assembled per rank");
    Ok(Outcome {
        dofs: built.dofs.clone(),
        fields: vec![built.field],
        state,
        steps: 1,
        rejected: 0,
        crosspoints: built.crosspoints(),
    })
}

/// A step's report from its Newton solve (its step, time and size, rejections and
/// error estimate left to the caller).
fn report(solved: Solved, method: Method) -> StepReport {
    StepReport {
        step: 0,
        time: 0.0,
        dt: 0.0,
        newton_iterations: solved.iterations,
        residual_history: solved.history,
        rejected: 0,
        error_estimate: None,
        heat: [solved.heat, solved.tie_heat].concat(),
        assembly_s: solved.timing.assembly_s,
        factor_s: solved.timing.factor_s,
        solve_s: solved.timing.solve_s,
        cg_iterations: solved.cg_iterations.iter().sum(),
        gmres: method == Method::GmresAmg,
        hierarchy_setups: match method {
            Method::CgAmg | Method::GmresAmg => solved.setups,
            _ => 0,
        },
        // (PETSc's hierarchy kept whole, where the serial one refreshes its finest level.)
        hierarchy_refreshes: match method {
            Method::CgAmg | Method::GmresAmg => solved.kept,
            _ => 0,
        },
        electric: Vec::new(),
        diagnosis: None,
    }
}

/// Hand an accepted step to the run: on rank 0 `state` is the whole state, and its
/// outputs see every interface point (this rank's own `mine` again afterwards); on the
/// other ranks their own. A failure there stops every rank.
fn hand_over(
    built: &Built<'_>,
    report: &StepReport,
    (state, mine): (&State, &[f64]),
    on_step: &mut dyn FnMut(&StepReport, &State, &DofMap) -> Result<(), HeatError>,
) -> Result<(), HeatError> {
    let mut clock = [std::time::Instant::now(); 3];
    let handed = match built.is_root() {
        true => built
            .all_points()
            .and_then(|()| {
                clock[1] = std::time::Instant::now();
                on_step(report, state, &built.dofs)
            })
            .and_then(|()| {
                clock[2] = std::time::Instant::now();
                built.own_points_again(mine, state.time)
            }),
        false => on_step(report, state, &built.dofs),
    };
    log::debug!(
        "step {}: handed to the run's outputs in {:.3} s (every point {:.3} s, outputs {:.3} s, own points again {:.3} s)",
        state.step,
        clock[0].elapsed().as_secs_f64(),
        (clock[1] - clock[0]).as_secs_f64(),
        (clock[2] - clock[1]).as_secs_f64(),
        clock[2].elapsed().as_secs_f64(),
    );
    agreed(handed)
}

/// The run's summary: the method of `newton`'s solves (over `built`) and why (`what`:
/// the steps or the steady solve).
fn record(newton: &Newton<'_, '_>, built: &Built<'_>, what: &str) {
    let (method, symmetric) = (newton.method, newton.symmetric);
    let unsymmetric = match built.nonlinear {
        true => {
            "a conduction of T (conductivity, capacity, source or radiation) makes the Jacobian unsymmetric"
        }
        false => "a temperature-dependent conductance makes the Jacobian unsymmetric",
    };
    let why = match (method, symmetric) {
        _ if built.has_ties() => format!(
            "{what}, mortar ties with Lagrange multipliers make the system indefinite → MUMPS LU"
        ),
        (Method::CgAmg, _) => format!(
            "{what}, symmetric positive definite, at or above the AMG threshold → CG + BoomerAMG (hierarchy kept while the step size holds, each step started from the earlier steps' solutions)"
        ),
        (Method::GmresAmg, _) => format!(
            "{what}, {unsymmetric}, at or above the AMG threshold → GMRES + BoomerAMG at each Newton iteration"
        ),
        (_, true) => format!(
            "{what}, below the AMG threshold (or linear_solver = \"direct\") → MUMPS LU (factorisation kept while the step size holds)"
        ),
        (_, false) => format!("{what}, {unsymmetric} → MUMPS LU at each Newton iteration"),
    };
    super::record(method, why);
}
