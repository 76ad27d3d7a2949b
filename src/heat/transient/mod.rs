//! Transient (and nonlinear steady) conduction with contact: backward Euler or BDF2,
//! fixed or adaptive steps, Newton with exact Jacobians at every step.
//!
//! Entry point: [`solve`]. The discrete problem at each step, for the dof vector `u`:
//!
//! ```text
//! R(u) = M(u) (α₀ u + α₁ uⁿ + α₂ uⁿ⁻¹)/Δt + ∫ k(T) ∇N·∇T − ∫ Q(T) N + Σ_faces ∫ N g(T)
//!        + Σ_Γ R_Γ(u) + Cᵀλ          (and C u = ΔT ∫ψ on the multiplier rows)
//! ```
//!
//! with M the lumped capacity `∫ ρc(T_a) N_a` at each node, Q(T, x, t) the source of
//! the element's block (its dQ/dT enters the Jacobian), g the heat leaving through a
//! face (flux, convection, radiation; see [`FaceBc::outflow`]), R_Γ the interface forms
//! of [`crate::enforce::interface`] and C the mortar ties. Backward Euler has
//! `(α₀, α₁, α₂) = (1, −1, 0)`; BDF2 with step ratio ω = Δtₙ/Δtₙ₋₁ has
//! `((1+2ω)/(1+ω), −(1+ω), ω²/(1+ω))` and starts with one backward-Euler step. A steady
//! solve is the same Newton without the capacity term.
//!
//! A step is rejected and retried with half the step when Newton fails or a
//! conductance model (a plugin) asks for a smaller step; with adaptive steps also when
//! the local error estimate — the distance to the polynomial predictor, scaled by the
//! scheme's error constant — exceeds the tolerance (over the temperatures and voltages;
//! a species is integrated on the steps they choose). Only accepted steps reach the
//! caller's `on_step`, so contact state and output are committed on accepted steps
//! only.
//!
//! A linear step (constant laws, conductances independent of T, linear faces and
//! sources) costs one assembly: the element matrices are kept while the faces'
//! derivatives do not change, the residual after the solve is `R + J du`, and a fixed
//! step reuses its factorisation. The interfaces come through
//! [`Interfaces`](crate::heat::interfaces::Interfaces): `seam run` gives its contact
//! through the public embedding API, whose pattern is fixed after the search and whose
//! values are refreshed in place.
//!
//! Results are reproducible bit for bit: element loops write fixed slots, interface
//! sums run in a fixed order, and the factorisations run sequentially when
//! [`TransientProblem::reproducible`] is set — so a run restarted from a
//! [`State`] continues exactly as the uninterrupted run.
//!
//! The parts: `setup` (what a run keeps: dofs, ties, lumped weights, bases), `newton`
//! (one step's iteration and its solvers) and `assemble` (the residual and Jacobian at
//! a state, the interface heat); this file holds the problem types and the time loop.

mod assemble;
mod death;
mod newton;
mod setup;

use std::cell::RefCell;

use crate::assembly::{Assembler, DofMap, FieldId, Pattern};
use crate::mesh::{Mesh, NodeId};

use super::TEMPERATURE;
use super::electric::{ContactPower, ElectricContact};
use super::interfaces::{InterfaceFailure, Interfaces};
use super::law::Law;
use super::{FaceBc, HeatError, SourceFn};
use crate::enforce::interface::{HInput, HValue};

#[cfg(feature = "mpi")]
pub(crate) use newton::unconverged;
use newton::{Context, History, Solvers};
use setup::Setup;
#[cfg(feature = "mpi")]
pub(crate) use setup::{LumpedWeight, lumped_weights};

/// Time integration scheme.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    BackwardEuler,
    Bdf2,
}

impl Scheme {
    /// Order of accuracy.
    pub fn order(self) -> u32 {
        match self {
            Scheme::BackwardEuler => 1,
            Scheme::Bdf2 => 2,
        }
    }
}

/// The material laws of one block.
#[derive(Clone, Debug, PartialEq)]
pub struct BlockLaws {
    /// k(T), W/m/K.
    pub conductivity: Law,
    /// ρc(T), J/m³/K.
    pub capacity: Law,
}

/// Boundary data at one time: nodal temperatures and face conditions. The set of
/// Dirichlet nodes must not change over a run (their values may).
#[derive(Clone, Debug, Default)]
pub struct Loads {
    pub dirichlet: Vec<(NodeId, f64)>,
    pub faces: Vec<FaceBc>,
    /// Nodal voltages (V), with [`TransientProblem::electric`].
    pub voltage: Vec<(NodeId, f64)>,
    /// Current densities into the body (A/m²) on element sides, with
    /// [`TransientProblem::electric`].
    pub currents: Vec<(crate::mesh::Side, f64)>,
    /// Nodal concentrations (in the unknown of [`TransientProblem::species`]), with it.
    pub species: Vec<(NodeId, f64)>,
    /// Species fluxes into the body (mol/m²/s) on element sides, with
    /// [`TransientProblem::species`].
    pub species_fluxes: Vec<(crate::mesh::Side, f64)>,
}

/// The species of a problem ([`crate::heat::species`]): its field, numbered after every
/// other, on the blocks with a diffusivity.
pub struct Species<'a> {
    /// D(T) per mesh block (m²/s); `None`: the block carries no species.
    pub diffusivity: &'a [Option<Law>],
    /// The capacity φ per mesh block (the factor of ∂c/∂t).
    pub capacity: &'a [f64],
    /// The concentration at each node at the start of a fresh run.
    pub initial: &'a dyn Fn(NodeId) -> f64,
}

/// The electrical part of a thermal–electrical problem ([`crate::heat::electric`]).
pub struct Electric<'a> {
    /// σ(T) per mesh block (S/m); `None`: the block carries no voltage.
    pub conductivity: &'a [Option<Law>],
    /// The electrical contacts, each with its contact conductance h_e (S/m²) as a law of
    /// the point's gap and two temperatures and of the time.
    pub contacts: Vec<(ElectricContact, &'a ContactConductance<'a>)>,
}

/// An electrical contact conductance at a point and time: h_e and its temperature
/// derivatives, or why it failed.
pub type ContactConductance<'a> = dyn Fn(&HInput, f64) -> Result<HValue, String> + 'a;

/// A field and the blocks it lives on (each block carries one field).
#[derive(Clone, Debug)]
pub struct FieldSpec {
    pub name: String,
    pub blocks: Vec<usize>,
}

/// The problem: mesh, fields, laws, source, interfaces.
pub struct TransientProblem<'a> {
    pub mesh: &'a Mesh,
    /// The fields; `temperature` over every solid block when empty.
    pub fields: Vec<FieldSpec>,
    /// Laws per mesh block (entries of blocks without a field are not used).
    pub laws: &'a [BlockLaws],
    pub source: Option<SourceFn<'a>>,
    /// The source per mesh block, Q(T, x, t) in W/m³ (a [`Law`]: a number, a Lua
    /// expression, a table in time), used instead of `source` when given.
    pub block_source: Option<&'a [Law]>,
    /// Boundary data at time t.
    pub loads: &'a dyn Fn(f64) -> Result<Loads, HeatError>,
    /// The interfaces, over this problem's dofs (the fields in order, then one
    /// multiplier range per tie): flux terms switched on and off, and their models'
    /// requests for a smaller step, are theirs to give.
    pub interfaces: Option<&'a dyn Interfaces>,
    /// Newton stops when the update is below `tolerance × max|u|`.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Sequential factorisations: bit-for-bit reproducible runs and restarts.
    pub reproducible: bool,
    /// Solve a linear step's system by AMG-preconditioned CG (to
    /// [`AMG_TOLERANCE`](crate::heat::steady::AMG_TOLERANCE)) when it is symmetric positive
    /// definite (no multipliers) and has at least this many unknowns, keeping the
    /// hierarchy while the matrix is unchanged; `None`: always factor.
    pub amg_threshold: Option<usize>,
    /// The voltage field, its Joule heat and electrical contacts: the problem becomes a
    /// coupled thermal–electrical one, solved monolithically.
    pub electric: Option<Electric<'a>>,
    /// Element death: per mesh element the time from which it is dead (∞: never). A
    /// dead element adds nothing; the nodes no live element holds keep their values.
    pub death: Option<&'a [f64]>,
    /// A diffusing species beside the temperature, solved in the same Newton.
    pub species: Option<Species<'a>>,
}

/// Step-size control.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Adaptive {
    /// Largest local error accepted in a step (K, max norm).
    pub tolerance: f64,
    pub dt_min: f64,
    pub dt_max: f64,
}

/// What to integrate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeMode {
    /// One nonlinear steady solve at this time.
    Steady { time: f64 },
    Transient {
        scheme: Scheme,
        end: f64,
        adaptive: Option<Adaptive>,
        /// The least step a failing step may be cut to.
        dt_min: f64,
    },
}

/// The state of a run between steps: enough to continue it exactly.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct State {
    pub step: usize,
    pub time: f64,
    /// The next step size to try.
    pub dt: f64,
    /// The dof vector (fields, then multipliers).
    pub u: Vec<f64>,
    /// Earlier accepted states, newest first (at most two): `(time, u)`.
    pub past: Vec<(f64, Vec<f64>)>,
}

/// One accepted step (or the steady solve).
#[derive(Clone, Debug)]
pub struct StepReport {
    pub step: usize,
    pub time: f64,
    pub dt: f64,
    pub newton_iterations: usize,
    /// ‖R‖₂ at every Newton iterate of the accepted attempt.
    pub residual_history: Vec<f64>,
    /// Attempts rejected before this one.
    pub rejected: usize,
    /// Local error estimate (adaptive steps), K.
    pub error_estimate: Option<f64>,
    /// Per contact term then per tie: heat leaving side A and side B through Γ (W).
    pub heat: Vec<(f64, f64)>,
    pub assembly_s: f64,
    pub factor_s: f64,
    pub solve_s: f64,
    /// Krylov iterations of the step's AMG-CG or GMRES solves (0 when it factored).
    pub cg_iterations: usize,
    /// The step's Krylov solves were GMRES (an unsymmetric Jacobian), not CG.
    pub gmres: bool,
    /// AMG hierarchies set up, and kept ones refreshed with new values, in the step.
    pub hierarchy_setups: usize,
    pub hierarchy_refreshes: usize,
    /// Per electrical contact: the current through it and its Joule heat.
    pub electric: Vec<ContactPower>,
    /// `None` when Newton converged; for a steady solve that did not, what happened
    /// (the residual history and the likely cause): the state is the last iterate.
    pub diagnosis: Option<String>,
}

/// What [`solve`] hands back at the end.
#[derive(Debug)]
pub struct Outcome {
    pub dofs: DofMap,
    pub fields: Vec<FieldId>,
    pub state: State,
    pub steps: usize,
    pub rejected: usize,
    /// Per tie: side-A nodes left without a multiplier (crosspoints).
    pub crosspoints: Vec<Vec<NodeId>>,
}

/// Where a run starts.
pub enum Start<'s> {
    /// At `time` with first step `dt`, every field at the nodal `initial` value and the
    /// multipliers at 0.
    Fresh {
        time: f64,
        dt: f64,
        initial: &'s dyn Fn(NodeId) -> f64,
    },
    /// From a saved state (a checkpoint).
    Restart(State),
}

impl TransientProblem<'_> {
    fn fields_or_default(&self) -> Vec<FieldSpec> {
        if self.fields.is_empty() {
            vec![FieldSpec {
                name: TEMPERATURE.into(),
                blocks: (0..self.mesh.blocks.len())
                    .filter(|&b| self.mesh.blocks[b].topology.is_solid())
                    .collect(),
            }]
        } else {
            self.fields.clone()
        }
    }

    fn tie_on(&self, k: usize, t: f64) -> bool {
        self.interfaces.is_none_or(|i| i.tie_on(k, t))
    }
}

/// The time-derivative weights `(α₀, α₁, α₂)` of a step of size `dt` after a step of
/// size `dt_prev` (None: no history, backward Euler).
pub(crate) fn weights(scheme: Scheme, dt: f64, dt_prev: Option<f64>) -> [f64; 3] {
    match (scheme, dt_prev) {
        (Scheme::Bdf2, Some(prev)) => {
            let w = dt / prev;
            [(1.0 + 2.0 * w) / (1.0 + w), -(1.0 + w), w * w / (1.0 + w)]
        }
        _ => [1.0, -1.0, 0.0],
    }
}

/// Why an attempt did not give a step.
enum Failure {
    /// Retry with a smaller step.
    Retry(String),
    Fatal(HeatError),
}

impl From<HeatError> for Failure {
    fn from(e: HeatError) -> Self {
        Failure::Fatal(e)
    }
}

/// Solve the problem from `state`: a steady solve, or time steps until `end`. Each
/// accepted step is handed to `on_step` with the new state.
pub fn solve(
    p: &TransientProblem<'_>,
    mode: TimeMode,
    start: Start<'_>,
    on_step: &mut dyn FnMut(&StepReport, &State, &DofMap) -> Result<(), HeatError>,
) -> Result<Outcome, HeatError> {
    let time0 = match &start {
        Start::Fresh { time, .. } => *time,
        Start::Restart(s) => s.time,
    };
    let setup = Setup::new(p, time0)?;
    // A fresh start's voltage is not a solution yet (see `Context::newton`).
    let settle_voltage =
        std::cell::Cell::new(p.electric.is_some() && matches!(start, Start::Fresh { .. }));
    let mut state = match start {
        Start::Restart(s) => s,
        Start::Fresh { time, dt, initial } => {
            let mut u = vec![0.0; setup.n];
            for &f in &setup.fields {
                for node in (0..p.mesh.num_nodes()).map(|n| NodeId(n as u32)) {
                    if let Some(d) = setup.dofs.dof(f, node) {
                        u[d.index()] = initial(node);
                    }
                }
            }
            // The voltage starts at 0 (a linear equation: Newton's first step solves it).
            if let (Some(sp), Some(f)) = (&p.species, setup.species) {
                for node in (0..p.mesh.num_nodes()).map(|n| NodeId(n as u32)) {
                    if let Some(d) = setup.dofs.dof(f, node) {
                        u[d.index()] = (sp.initial)(node);
                    }
                }
            }
            State {
                step: 0,
                time,
                dt,
                u,
                past: Vec::new(),
            }
        }
    };
    if state.u.len() != setup.n {
        return Err(HeatError::Step(format!(
            "the state has {} values but the problem has {} dofs (a checkpoint of another problem?)",
            state.u.len(),
            setup.n
        )));
    }
    let mesh = p.mesh;
    let mut steps = 0;
    let mut rejected_total = 0;
    // Made again when moving interfaces change their couplings.
    'pattern: loop {
        // The pattern: elements, interface couplings (from a first evaluation), ties.
        let mut pattern = Pattern::new(mesh, &setup.dofs);
        let couplings = match p.interfaces {
            Some(i) => i
                .couplings(&state.u, state.time)
                .map_err(|e| HeatError::Contact(e.to_string()))?,
            None => Vec::new(),
        };
        let first = pattern.add_couplings(&couplings)?.start;
        let mut tie_first = Vec::with_capacity(setup.ties.len());
        for (t, tie) in setup.ties.iter().enumerate() {
            let pairs: Vec<(usize, usize)> = tie
                .entries
                .iter()
                .map(|&(k, d, _)| (d, setup.lambda_first[t] + k))
                .collect();
            tie_first.push(pattern.add_couplings(&pairs)?.start);
        }
        let mut electric_first = Vec::with_capacity(setup.electric().len());
        for c in setup.electric().iter() {
            electric_first.push(pattern.add_couplings(&c.couplings())?.start);
        }
        pattern.build()?;
        let mut solver = Solvers::new(&setup, p.reproducible);
        let mut asm = Assembler::new(&pattern);
        let ctx = Context {
            p,
            setup: &setup,
            first,
            element_matrices: RefCell::new(None),
            element_inputs: RefCell::new(None),
            capacity_terms: RefCell::new(Vec::new()),
            tie_first: &tie_first,
            electric_first: &electric_first,
            power: RefCell::new(Vec::new()),
            unconverged: RefCell::new(None),
            alive: RefCell::new(None),
            settle_voltage: &settle_voltage,
        };

        match mode {
            TimeMode::Steady { time } => {
                let mut guess = state.u.clone();
                let r = ctx.newton(&mut asm, &mut solver, &mut guess, time, None)?;
                let r = match r {
                    Ok(r) => r,
                    // Out of iterations: the last iterate goes on, marked not converged.
                    Err(msg) => ctx.unconverged.take().ok_or(HeatError::Step(msg))?,
                };
                state.u = guess;
                state.time = time;
                let report = StepReport {
                    step: 0,
                    time,
                    dt: 0.0,
                    rejected: 0,
                    error_estimate: None,
                    ..r
                };
                on_step(&report, &state, &setup.dofs)?;
                steps = 1;
            }
            TimeMode::Transient {
                scheme,
                end,
                adaptive,
                dt_min,
            } => {
                let eps = 1e-12 * end.abs().max(state.dt);
                while state.time < end - eps {
                    let mut rejected = 0;
                    loop {
                        let mut dt = state.dt.min(end - state.time);
                        if let Some(a) = adaptive {
                            dt = dt.min(a.dt_max);
                        }
                        // Do not leave a sliver of a step before the end.
                        if end - state.time - dt < 1e-6 * dt {
                            dt = end - state.time;
                        }
                        let t_new = state.time + dt;
                        // Moving interfaces are placed at t_new; new couplings need a new
                        // pattern, and the step is taken again over it.
                        if let Some(i) = p.interfaces {
                            let contact = |e: InterfaceFailure| HeatError::Contact(e.to_string());
                            let moved = i
                                .advance(&state.u, t_new, state.step as u64 + 1)
                                .map_err(contact)?;
                            // Electrical contacts on the moved surfaces, with new gaps.
                            let rewired = match i.electric_contacts().map_err(contact)? {
                                Some(made) => setup.rebind_electric(mesh, made)?,
                                None => false,
                            };
                            if moved || rewired {
                                continue 'pattern;
                            }
                        }
                        let dt_prev = state.past.first().map(|(t, _)| state.time - t);
                        let alpha = weights(scheme, dt, dt_prev);
                        let mut u = predictor(&state, dt, scheme.order() as usize);
                        let history = Some(History {
                            dt,
                            alpha,
                            current: &state.u,
                            previous: state.past.first().map(|(_, u)| u.as_slice()),
                        });
                        let attempt = ctx.newton(&mut asm, &mut solver, &mut u, t_new, history)?;
                        let failure = match attempt {
                            Err(msg) => Some(msg),
                            Ok(mut report) => {
                                let estimate = adaptive
                                    .and_then(|_| error_estimate(scheme, &state, &u, dt, &setup));
                                let too_big = match (adaptive, estimate) {
                                    (Some(a), Some(e)) => e > a.tolerance,
                                    _ => false,
                                };
                                if too_big {
                                    let (a, e) = (adaptive.unwrap(), estimate.unwrap());
                                    state.dt = dt * factor(a.tolerance, e, scheme).clamp(0.2, 0.9);
                                    rejected += 1;
                                    rejected_total += 1;
                                    if state.dt < a.dt_min {
                                        return Err(HeatError::Step(format!(
                                            "at t = {}: the local error {e:.3e} K stays above the tolerance {:.3e} K down to dt_min = {}",
                                            state.time, a.tolerance, a.dt_min
                                        )));
                                    }
                                    continue;
                                }
                                // Accept: shift the history and pick the next step.
                                let old = std::mem::replace(&mut state.u, u);
                                state.past.insert(0, (state.time, old));
                                state.past.truncate(2);
                                state.time = t_new;
                                state.step += 1;
                                state.dt = match (adaptive, estimate) {
                                    (Some(a), Some(e)) => (dt
                                        * factor(a.tolerance, e, scheme).clamp(0.2, 2.0))
                                    .clamp(a.dt_min, a.dt_max),
                                    _ => state.dt,
                                };
                                report.step = state.step;
                                report.time = t_new;
                                report.dt = dt;
                                report.rejected = rejected;
                                report.error_estimate = estimate;
                                on_step(&report, &state, &setup.dofs)?;
                                steps += 1;
                                None
                            }
                        };
                        match failure {
                            None => break,
                            Some(msg) => {
                                rejected += 1;
                                rejected_total += 1;
                                state.dt = dt * 0.5;
                                let floor = adaptive.map_or(dt_min, |a| a.dt_min);
                                if state.dt < floor {
                                    return Err(HeatError::Step(format!(
                                        "at t = {}: {msg}; the step was cut to {} and may not go below {floor}",
                                        state.time, state.dt
                                    )));
                                }
                            }
                        }
                    }
                }
            }
        }
        break 'pattern;
    }
    Ok(Outcome {
        crosspoints: setup.ties.iter().map(|t| t.crosspoints.clone()).collect(),
        fields: setup.fields.clone(),
        dofs: setup.dofs,
        state,
        steps,
        rejected: rejected_total,
    })
}

/// Step-size factor `(tol/err)^(1/(p+1))` with a safety factor 0.9.
pub(crate) fn factor(tol: f64, err: f64, scheme: Scheme) -> f64 {
    if err <= 0.0 {
        return f64::INFINITY;
    }
    0.9 * (tol / err).powf(1.0 / (scheme.order() as f64 + 1.0))
}

/// The starting guess of a step: the last state, extrapolated linearly when `order` ≥ 1
/// and a history exists, quadratically (through the last three states) when `order` ≥ 2
/// and two earlier states exist.
pub(crate) fn predictor(state: &State, dt: f64, order: usize) -> Vec<f64> {
    if let (2.., [(t1, u1), (t2, u2), ..]) = (order, state.past.as_slice())
        && state.time > *t1
        && *t1 > *t2
    {
        let (x0, x1, x2, x) = (state.time, *t1, *t2, state.time + dt);
        let l0 = (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2));
        let l1 = (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2));
        let l2 = (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1));
        return (state.u.iter().zip(u1).zip(u2))
            .map(|((u0, u1), u2)| l0 * u0 + l1 * u1 + l2 * u2)
            .collect();
    }
    match (order, state.past.first()) {
        (1.., Some((t_prev, u_prev))) if state.time > *t_prev => {
            let s = dt / (state.time - t_prev);
            state
                .u
                .iter()
                .zip(u_prev)
                .map(|(u, v)| u + s * (u - v))
                .collect()
        }
        _ => state.u.clone(),
    }
}

/// The local error estimate of the step just solved: the distance from the
/// solution to the predictor through the last `order + 1` states, times the scheme's
/// error constant relative to that of the predictor (backward Euler: Δt/(Δt + Δtₙ₋₁);
/// BDF2: 2/11 for equal steps). None while the history is too short.
fn error_estimate(
    scheme: Scheme,
    state: &State,
    u_new: &[f64],
    dt: f64,
    setup: &Setup,
) -> Option<f64> {
    // The step follows the temperature (and voltage): the species, in other units, is
    // integrated on the same steps.
    let n = setup.species_start();
    match scheme {
        Scheme::BackwardEuler => {
            let (t1, _) = state.past.first()?;
            let h1 = state.time - t1;
            let pred = predictor(state, dt, 1);
            let c = dt / (dt + h1);
            Some(max_diff(&u_new[..n], &pred[..n]) * c)
        }
        Scheme::Bdf2 => {
            let (t1, u1) = state.past.first()?;
            let (t2, u2) = state.past.get(1)?;
            // Quadratic extrapolation through (t2,u2), (t1,u1), (t0,u0) to t0 + dt.
            let (x0, x1, x2) = (state.time, *t1, *t2);
            let x = x0 + dt;
            let l0 = (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2));
            let l1 = (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2));
            let l2 = (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1));
            let mut worst = 0.0f64;
            for i in 0..n {
                let p = l0 * state.u[i] + l1 * u1[i] + l2 * u2[i];
                worst = worst.max((u_new[i] - p).abs());
            }
            Some(worst * 2.0 / 11.0)
        }
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}
