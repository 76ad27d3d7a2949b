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
//! scheme's error constant — exceeds the tolerance. Only accepted steps reach the
//! caller's `on_step`, so contact state and output are committed on accepted steps
//! only.
//!
//! A linear step (constant laws, conductances independent of T, linear faces and
//! sources) costs one assembly: the element matrices are kept while the faces'
//! derivatives do not change, the residual after the solve is `R + J du`, and a fixed
//! step reuses its factorisation. The interface geometry at the contact points is
//! evaluated once per run ([`InterfacePoints`]).
//!
//! Results are reproducible bit for bit: element loops write fixed slots, interface
//! sums run in a fixed order, and the factorisations run sequentially when
//! [`TransientProblem::reproducible`] is set — so a run restarted from a
//! [`State`] continues exactly as the uninterrupted run.

use std::cell::{Cell, RefCell};
use std::collections::HashSet;

use rayon::prelude::*;

use crate::assembly::{Assembler, DofMap, FieldId, Pattern};
use crate::enforce::interface::{FieldPair, InterfacePoints, InterfaceSystem, Scatter};
use crate::enforce::mortar::{MortarTie, mortar_tie};
use crate::fem::{Basis, MAX_NODES};
use crate::mesh::{Mesh, NodeId};
use crate::solve::{
    AmgCg, AmgOptions, Cholesky, LinearSolver, Lu, Ordering, SaddleLdlt, apply_dirichlet, spmv,
};

use super::law::Law;
use super::steady::{ContactTerm, TieTerm};
use super::{FaceBc, FirstError, HeatError, SourceFn, bad_jacobian, block_rules, elem_coords};
use super::{TEMPERATURE, kernel};

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
}

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
    pub contact: Vec<ContactTerm<'a>>,
    pub ties: Vec<TieTerm<'a>>,
    /// Per contact term, then per tie: indices into `fields` of side A's and side B's
    /// field (both 0 when empty).
    pub term_fields: Vec<(usize, usize)>,
    /// Whether term `k` (contact terms, then ties) is switched on at time t
    /// (`Use Toggle Block`); always on when `None`.
    pub active: Option<&'a dyn Fn(usize, f64) -> bool>,
    /// Set by a conductance model that asks for a smaller step; the step is retried.
    pub cutback: Option<&'a Cell<bool>>,
    /// Newton stops when the update is below `tolerance × max|u|`.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Sequential factorisations: bit-for-bit reproducible runs and restarts.
    pub reproducible: bool,
    /// Solve a linear step's system by AMG-preconditioned CG (to
    /// [`AMG_TOLERANCE`](super::steady::AMG_TOLERANCE)) when it is symmetric positive
    /// definite (no multipliers) and has at least this many unknowns, keeping the
    /// hierarchy while the matrix is unchanged; `None`: always factor.
    pub amg_threshold: Option<usize>,
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
#[derive(Clone, Debug, PartialEq)]
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
    /// CG iterations of the step's AMG-CG solves (0 when it factored).
    pub cg_iterations: usize,
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

    fn term_pair(&self, k: usize, fields: &[FieldId]) -> FieldPair {
        let (a, b) = self.term_fields.get(k).copied().unwrap_or((0, 0));
        FieldPair {
            a: fields[a],
            b: fields[b],
        }
    }

    fn is_active(&self, k: usize, t: f64) -> bool {
        self.active.is_none_or(|f| f(k, t))
    }
}

/// What does not change over a run: dofs, ties, the pattern's couplings, the lumped
/// capacity weights.
struct Setup {
    dofs: DofMap,
    fields: Vec<FieldId>,
    n_primal: usize,
    n: usize,
    ties: Vec<MortarTie>,
    lambda_first: Vec<usize>,
    dirichlet_dofs: Vec<usize>,
    lumped: Vec<LumpedWeight>,
    /// The blocks carrying a field, and the element basis of each.
    blocks: Vec<usize>,
    rules: Vec<Option<Basis>>,
}

impl Setup {
    fn new(p: &TransientProblem<'_>, time: f64) -> Result<Setup, HeatError> {
        let mesh = p.mesh;
        let specs = p.fields_or_default();
        let list: Vec<(&str, &[usize])> = specs
            .iter()
            .map(|f| (f.name.as_str(), f.blocks.as_slice()))
            .collect();
        let mut dofs = DofMap::new(mesh, &list)?;
        let fields: Vec<FieldId> = specs
            .iter()
            .map(|f| dofs.field(&f.name).expect("field just made"))
            .collect();
        let n_primal = dofs.len();
        let loads = (p.loads)(time)?;
        let dirichlet_dofs = node_dofs(mesh, &dofs, &fields, &loads.dirichlet)?
            .into_iter()
            .map(|(d, _)| d)
            .collect();
        let conductivity: Vec<f64> = p
            .laws
            .iter()
            .map(|l| l.conductivity.eval(300.0, [0.0; 3], time).map(|(k, _)| k))
            .collect::<Result<_, _>>()
            .map_err(HeatError::Step)?;
        let mut constrained: HashSet<NodeId> = loads.dirichlet.iter().map(|d| d.0).collect();
        let mut ties = Vec::with_capacity(p.ties.len());
        for (t, tie) in p.ties.iter().enumerate() {
            let pair = p.term_pair(p.contact.len() + t, &fields);
            ties.push(
                mortar_tie(
                    mesh,
                    &dofs,
                    pair,
                    tie.side_a,
                    tie.side_b,
                    tie.points,
                    &conductivity,
                    &mut constrained,
                    tie.multipliers,
                )
                .map_err(|e| HeatError::Contact(e.to_string()))?,
            );
        }
        let lambda_first = ties
            .iter()
            .map(|t| dofs.add_extra(t.nodes.len()).start)
            .collect();
        let lumped = lumped_weights(mesh, &dofs)?;
        let mut blocks: Vec<usize> = Vec::new();
        let mut rules = vec![None; mesh.blocks.len()];
        for &f in &fields {
            blocks.extend_from_slice(dofs.field_blocks(f));
            for (b, r) in block_rules(mesh, &dofs, f)?.into_iter().enumerate() {
                if r.is_some() {
                    rules[b] = r;
                }
            }
        }
        let n = dofs.len();
        Ok(Setup {
            dofs,
            fields,
            n_primal,
            n,
            ties,
            lambda_first,
            dirichlet_dofs,
            lumped,
            blocks,
            rules,
        })
    }
}

/// `(dof, value)` of nodal data on whichever field the node carries.
fn node_dofs(
    mesh: &Mesh,
    dofs: &DofMap,
    fields: &[FieldId],
    data: &[(NodeId, f64)],
) -> Result<Vec<(usize, f64)>, HeatError> {
    data.iter()
        .map(|&(n, v)| {
            fields
                .iter()
                .find_map(|&f| dofs.dof(f, n))
                .map(|d| (d.index(), v))
                .ok_or(HeatError::DirichletOffField(
                    mesh.node_numbers.get(n.index()).copied().unwrap_or(-1),
                ))
        })
        .collect()
}

/// (dof, block, ∫N_a dV over that block's elements at the node, node coordinates).
type LumpedWeight = (u32, u32, f64, [f64; 3]);

/// Lumped capacity weights `∫ N_a dV` per (dof, block), with the node's coordinates.
fn lumped_weights(mesh: &Mesh, dofs: &DofMap) -> Result<Vec<LumpedWeight>, HeatError> {
    let mut out: std::collections::BTreeMap<(u32, u32), f64> = Default::default();
    let mut elem_dofs = Vec::new();
    for (b, block) in mesh.blocks.iter().enumerate() {
        if dofs.block_fields(b).is_empty() {
            continue;
        }
        let basis = Basis::standard(block.topology).ok_or(HeatError::UnsupportedTopology {
            block: block.id,
            topology: block.topology,
        })?;
        let nn = block.topology.node_count();
        let mut me = vec![0.0; nn * nn];
        for k in 0..block.len() {
            let e = crate::mesh::ElemId(block.first_elem.0 + k as u32);
            let mut x = [[0.0; 3]; MAX_NODES];
            let m = elem_coords(mesh, e, &mut x);
            me.fill(0.0);
            kernel::capacity_lumped(&basis, &x[..m], 1.0, &mut me)
                .map_err(|bad| bad_jacobian(mesh, e, bad))?;
            dofs.elem_dofs(mesh, e, &mut elem_dofs);
            for a in 0..nn {
                *out.entry((elem_dofs[a], b as u32)).or_default() += me[a * nn + a];
            }
        }
    }
    // Coordinates of each dof's node.
    let mut coords = vec![[0.0; 3]; dofs.len()];
    for f in 0..dofs.field_count() {
        let f = FieldId(f as u32);
        for node in 0..mesh.num_nodes() {
            if let Some(d) = dofs.dof(f, NodeId(node as u32)) {
                coords[d.index()] = mesh.coords[node];
            }
        }
    }
    Ok(out
        .into_iter()
        .map(|((d, b), w)| (d, b, w, coords[d as usize]))
        .collect())
}

/// The time-derivative weights `(α₀, α₁, α₂)` of a step of size `dt` after a step of
/// size `dt_prev` (None: no history, backward Euler).
fn weights(scheme: Scheme, dt: f64, dt_prev: Option<f64>) -> [f64; 3] {
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
    // The pattern: elements, interface couplings (from a first evaluation), ties.
    let mut pattern = Pattern::new(mesh, &setup.dofs);
    let mut points = Vec::with_capacity(p.contact.len());
    let mut scatters = Vec::with_capacity(p.contact.len());
    for (k, c) in p.contact.iter().enumerate() {
        let cache = InterfacePoints::new(
            mesh,
            &setup.dofs,
            p.term_pair(k, &setup.fields),
            c.side_a,
            c.side_b,
            c.points,
            &c.form,
        )
        .map_err(|e| HeatError::Contact(e.to_string()))?;
        let cp = cache.couplings();
        let first = pattern.add_couplings(&cp)?.start;
        scatters.push(cache.scatter(&cp, first));
        points.push(cache);
    }
    let mut tie_first = Vec::with_capacity(setup.ties.len());
    for (t, tie) in setup.ties.iter().enumerate() {
        let pairs: Vec<(usize, usize)> = tie
            .entries
            .iter()
            .map(|&(k, d, _)| (d as usize, setup.lambda_first[t] + k as usize))
            .collect();
        tie_first.push(pattern.add_couplings(&pairs)?.start);
    }
    pattern.build()?;
    let mut solver = Solvers::new(&setup, p.reproducible);
    let mut asm = Assembler::new(&pattern);
    let ctx = Context {
        p,
        setup: &setup,
        points: &points,
        scatters: &scatters,
        element_matrices: RefCell::new(None),
        tie_first: &tie_first,
        unconverged: RefCell::new(None),
    };

    let mut steps = 0;
    let mut rejected_total = 0;
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
                    let dt_prev = state.past.first().map(|(t, _)| state.time - t);
                    let alpha = weights(scheme, dt, dt_prev);
                    let mut u = predictor(&state, dt, 1);
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
fn factor(tol: f64, err: f64, scheme: Scheme) -> f64 {
    if err <= 0.0 {
        return f64::INFINITY;
    }
    0.9 * (tol / err).powf(1.0 / (scheme.order() as f64 + 1.0))
}

/// The starting guess of a step: the last state, extrapolated linearly when `order` ≥ 1
/// and a history exists.
fn predictor(state: &State, dt: f64, order: usize) -> Vec<f64> {
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
    let n = setup.n_primal;
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

/// The time history a step needs.
struct History<'s> {
    dt: f64,
    alpha: [f64; 3],
    current: &'s [f64],
    previous: Option<&'s [f64]>,
}

/// The linear solvers, kept across steps (symbolic analyses are reused).
struct Solvers {
    chol: Cholesky,
    saddle: SaddleLdlt,
    lu: Lu,
    amg: AmgCg,
    /// The values of the matrix factored last and which solver holds it: a linear
    /// problem stepping with a fixed step reuses the factorisation (bit for bit the
    /// same as factoring again).
    factored: Option<(Vec<f64>, Which)>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Which {
    Saddle,
    Cholesky,
    Lu,
    Amg,
}

impl Solvers {
    fn new(setup: &Setup, sequential: bool) -> Self {
        let mut chol = Cholesky::new(Ordering::Metis);
        chol.sequential = sequential;
        let mut saddle = SaddleLdlt::with_primal(setup.n_primal, setup.n, Ordering::Metis);
        saddle.sequential = sequential;
        Solvers {
            chol,
            saddle,
            lu: Lu::new(),
            amg: AmgCg::new(AmgOptions {
                tolerance: super::steady::AMG_TOLERANCE,
                ..AmgOptions::default()
            }),
            factored: None,
        }
    }
}

struct Context<'c, 'a> {
    p: &'c TransientProblem<'a>,
    setup: &'c Setup,
    /// Per contact term: its points' geometry and where its blocks go.
    points: &'c [InterfacePoints],
    scatters: &'c [Scatter],
    /// The face-derivative signature under which the element matrix slots were last
    /// computed for a linear problem (None: not kept).
    element_matrices: RefCell<Option<Vec<(u32, u8, f64)>>>,
    tie_first: &'c [usize],
    /// The report of the last Newton attempt that ran out of iterations (its
    /// `diagnosis` set), for a steady solve to hand on with its last iterate.
    unconverged: RefCell<Option<StepReport>>,
}

/// Why Newton ran out of iterations, from its residual history: the history itself and
/// the likely cause.
fn unconverged(iterations: usize, t: f64, history: &[f64]) -> String {
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

impl Context<'_, '_> {
    /// Newton at time `t` from the guess `u` (updated in place). `Ok(Err(msg))`: the
    /// attempt failed and may be retried with a smaller step.
    fn newton(
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
        let bcs = node_dofs(p.mesh, &setup.dofs, &setup.fields, &loads.dirichlet)?;
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
            diagnosis: None,
        };
        let zero: Vec<(usize, f64)> = bcs.iter().map(|&(d, _)| (d, 0.0)).collect();
        // The last Newton update relative to max|u|.
        let mut last_update = f64::INFINITY;
        // A linear step's residual after its solve, and its interface systems.
        let mut carried = None;
        for it in 0..=p.max_iterations {
            let clock = std::time::Instant::now();
            let (mut r, mut terms) = match carried.take() {
                Some(x) => x,
                None => match self.assemble(asm, u, t, &loads, history.as_ref(), linear) {
                    Ok(x) => x,
                    Err(Failure::Retry(msg)) => return Ok(Err(msg)),
                    Err(Failure::Fatal(e)) => return Err(e),
                },
            };
            for &(d, _) in &bcs {
                r[d] = 0.0;
            }
            let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
            report.residual_history.push(rn);
            report.assembly_s += clock.elapsed().as_secs_f64();
            if !rn.is_finite() {
                return Ok(Err(format!("the residual is not finite at t = {t}")));
            }
            let done = it > 0 && (linear || last_update <= p.tolerance);
            if done || it == p.max_iterations {
                if !done {
                    let message = unconverged(p.max_iterations, t, &report.residual_history);
                    report.heat = self.heat(&terms, u);
                    report.diagnosis = Some(message.clone());
                    *self.unconverged.borrow_mut() = Some(report);
                    return Ok(Err(message));
                }
                report.heat = self.heat(&terms, u);
                return Ok(Ok(report));
            }
            let clock = std::time::Instant::now();
            let mut jac = asm.matrix()?;
            let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
            apply_dirichlet(&mut jac, &mut rhs, &zero)?;
            report.assembly_s += clock.elapsed().as_secs_f64();
            let symmetric = linear;
            // AMG-CG for a symmetric positive definite step system from the threshold on.
            let amg =
                setup.ties.is_empty() && symmetric && p.amg_threshold.is_some_and(|k| setup.n >= k);
            let solved = (|| -> Result<(f64, f64, usize), HeatError> {
                let t0 = std::time::Instant::now();
                let same = solvers
                    .factored
                    .as_ref()
                    .filter(|(v, _)| v.as_slice() == jac.val())
                    .map(|(_, w)| *w);
                let which = match same {
                    Some(w) => w,
                    None => {
                        solvers.factored = None;
                        let tied = !setup.ties.is_empty();
                        let w = if amg {
                            solvers.amg.factor(&jac)?;
                            Which::Amg
                        } else if tied && symmetric && solvers.saddle.factor(&jac).is_ok() {
                            Which::Saddle
                        } else if !tied && symmetric && solvers.chol.factor(&jac).is_ok() {
                            Which::Cholesky
                        } else {
                            solvers.lu.factor(&jac)?;
                            Which::Lu
                        };
                        if linear {
                            solvers.factored = Some((jac.val().to_vec(), w));
                        }
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
                    Which::Amg => solvers.amg.solve(&mut rhs)?.iterations,
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
            report.factor_s += factor_s;
            report.solve_s += solve_s;
            report.cg_iterations += cg;
            report.newton_iterations += 1;
            let step = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (ui, d) in u.iter_mut().zip(&rhs) {
                *ui += d;
            }
            if linear {
                // The residual of a linear system at u + du is R + J du: no second
                // assembly (J's Dirichlet rows and columns are the identity, and du
                // vanishes there).
                let clock = std::time::Instant::now();
                let mut jdu = vec![0.0; r.len()];
                spmv(&jac, &rhs, &mut jdu);
                r.iter_mut().zip(&jdu).for_each(|(r, j)| *r += j);
                for s in terms.iter_mut().flatten() {
                    s.advance(&rhs);
                }
                carried = Some((r, terms));
                report.assembly_s += clock.elapsed().as_secs_f64();
            }
            let u_max = u[..setup.n_primal]
                .iter()
                .fold(0.0f64, |m, v| m.max(v.abs()))
                .max(f64::MIN_POSITIVE);
            last_update = step / u_max;
        }
        unreachable!("the loop returns at its last iteration")
    }

    /// Is the step's system linear (constant laws, linear faces, constant conductances,
    /// sources that do not depend on T)?
    fn is_linear(&self, loads: &Loads) -> bool {
        self.p
            .laws
            .iter()
            .all(|l| l.conductivity.is_constant() && l.capacity.is_constant())
            && loads
                .faces
                .iter()
                .all(|f| !matches!(f, FaceBc::Radiation { .. }))
            && self.p.contact.iter().all(|c| c.linear)
            && (self.p.block_source).is_none_or(|s| s.iter().all(|q| !q.uses_temperature()))
    }

    /// Residual and Jacobian (left in `asm`) at `u`, and the interface systems.
    fn assemble(
        &self,
        asm: &mut Assembler<'_>,
        u: &[f64],
        t: f64,
        loads: &Loads,
        history: Option<&History<'_>>,
        linear: bool,
    ) -> Result<(Vec<f64>, Vec<Option<InterfaceSystem>>), Failure> {
        let p = self.p;
        let setup = self.setup;
        let mesh = p.mesh;
        let dofs = &setup.dofs;
        let (blocks, rules) = (&setup.blocks, &setup.rules);
        let mut faces: Vec<(u32, usize)> = loads
            .faces
            .iter()
            .enumerate()
            .map(|(k, f)| (f.side().elem.0, k))
            .collect();
        faces.sort_unstable();
        let errors = FirstError::new();
        let (laws, source, block_source) = (p.laws, p.source, p.block_source);
        // A linear problem's element matrices (conduction, and the faces' dg/dT) stay
        // the same while the face conditions' derivatives do: then they are kept in
        // their slots and only the vectors are computed. Either way a linear element's
        // residual is `K_e T_e + g(0) − f`, so keeping or recomputing gives the same bits.
        let signature: Option<Vec<(u32, u8, f64)>> = linear.then(|| {
            loads
                .faces
                .iter()
                .map(|f| (f.side().elem.0, f.side().side, f.outflow(0.0).1))
                .collect()
        });
        let keep = signature.is_some() && *self.element_matrices.borrow() == signature;
        asm.elements_with(mesh, Some(blocks), keep, |e, je, re| {
            let b = mesh.block_of(e);
            let topo = mesh.blocks[b].topology;
            let rule = rules[b].as_ref().expect("rule of a field block");
            let mut x = [[0.0; 3]; MAX_NODES];
            let nn = elem_coords(mesh, e, &mut x);
            let mut elem_dofs = Vec::with_capacity(nn);
            dofs.elem_dofs(mesh, e, &mut elem_dofs);
            let mut te = [0.0; MAX_NODES];
            for (k, d) in elem_dofs.iter().enumerate() {
                te[k] = u[*d as usize];
            }
            // Linear: the matrix at T = 0, then the residual from it.
            let t_eval = if linear { [0.0; MAX_NODES] } else { te };
            let law = &laws[b].conductivity;
            let failed = Cell::new(None);
            let k = |temp: f64, xq: [f64; 3]| match law.eval(temp, xq, t) {
                Ok(v) => v,
                Err(m) => {
                    failed.set(Some(m));
                    (0.0, 0.0)
                }
            };
            // Q(T, x, t) and dQ/dT; a failure or a non-finite value stops the run there.
            let q_failed = Cell::new(None);
            let q = |temp: f64, xq: [f64; 3]| {
                let v = block_source.map_or(Ok((0.0, 0.0)), |s| s[b].eval(temp, xq, t));
                let what = match v {
                    Ok((q, dq)) if q.is_finite() && dq.is_finite() => return (q, dq),
                    Ok((q, dq)) => format!("Q = {q}, dQ/dT = {dq}"),
                    Err(m) => m.lines().next().unwrap_or_default().to_string(),
                };
                let [x0, x1, x2] = xq;
                q_failed.set(Some(format!(
                    "{what} at ({x0:.6}, {x1:.6}, {x2:.6}), T = {temp}, t = {t}"
                )));
                (0.0, 0.0)
            };
            let conduction = if keep {
                Ok(())
            } else {
                kernel::conduction_residual_jacobian(rule, &x[..nn], &t_eval[..nn], k, re, je)
            };
            if let Err(bad) = conduction {
                errors.record(e, bad_jacobian(mesh, e, bad));
                return;
            }
            if let Some(m) = failed.take() {
                errors.record(
                    e,
                    HeatError::Material {
                        block: mesh.blocks[b].id,
                        message: m,
                    },
                );
                return;
            }
            let start = faces.partition_point(|f| f.0 < e.0);
            let mut scratch = [0.0; MAX_NODES * MAX_NODES];
            for &(_, k) in faces[start..].iter().take_while(|f| f.0 == e.0) {
                let bc = loads.faces[k];
                // Kept matrices hold the faces' dg/dT already.
                let jf = if keep {
                    &mut scratch[..nn * nn]
                } else {
                    &mut *je
                };
                kernel::face_load(
                    topo,
                    &x[..nn],
                    bc.side().side,
                    &t_eval[..nn],
                    |temp, _| bc.outflow(temp),
                    re,
                    jf,
                );
            }
            if linear {
                for a in 0..nn {
                    re[a] += (0..nn).map(|c| je[a * nn + c] * te[c]).sum::<f64>();
                }
            }
            // Sources at the element's temperatures (a linear problem's do not depend on
            // T, so their dQ/dT adds nothing to the kept matrices).
            let mut f = [0.0; MAX_NODES];
            let mut scratch = [0.0; MAX_NODES * MAX_NODES];
            let sourced = match (block_source, source) {
                (Some(qb), _) if !matches!(qb[b], Law::Constant(v) if v == 0.0) => {
                    let js = if keep {
                        &mut scratch[..nn * nn]
                    } else {
                        &mut *je
                    };
                    kernel::source_residual_jacobian(rule, &x[..nn], &te[..nn], q, re, js)
                }
                (None, Some(q)) => kernel::source(rule, &x[..nn], q, &mut f),
                _ => Ok(()),
            };
            if let Err(bad) = sourced {
                errors.record(e, bad_jacobian(mesh, e, bad));
                return;
            }
            if let Some(message) = q_failed.take() {
                let block = mesh.blocks[b].id;
                errors.record(e, HeatError::Source { block, message });
                return;
            }
            re.iter_mut().zip(&f).for_each(|(r, f)| *r -= f);
        });
        errors.into_result()?;
        if !keep {
            asm.check_finite(mesh).map_err(HeatError::from)?;
        }
        *self.element_matrices.borrow_mut() = signature;
        asm.reset_couplings();
        let mut r = asm.rhs();
        // Capacity (lumped): M(u)(α₀u + α₁uⁿ + α₂uⁿ⁻¹)/Δt on the diagonal.
        if let Some(h) = history {
            let terms: Vec<Result<(usize, f64, f64), String>> = setup
                .lumped
                .par_iter()
                .with_min_len(4096)
                .map(|&(d, b, w, xn)| {
                    let d = d as usize;
                    let (c, dc) = p.laws[b as usize].capacity.eval(u[d], xn, t)?;
                    let mut rate = h.alpha[0] * u[d] + h.alpha[1] * h.current[d];
                    if let Some(prev) = h.previous {
                        rate += h.alpha[2] * prev[d];
                    }
                    rate /= h.dt;
                    Ok((d, w * c * rate, w * (c * h.alpha[0] / h.dt + dc * rate)))
                })
                .collect();
            for term in terms {
                let (d, rv, jv) = term.map_err(|m| Failure::Fatal(HeatError::Step(m)))?;
                r[d] += rv;
                asm.add_diagonal(d, jv);
            }
        }
        // Interfaces.
        let mut systems = Vec::with_capacity(p.contact.len());
        for (k, c) in p.contact.iter().enumerate() {
            if !p.is_active(k, t) {
                systems.push(None);
                continue;
            }
            let s = self.points[k].evaluate(&c.form, u);
            let s = match s {
                Ok(s) => s,
                Err(e) => {
                    if p.cutback.is_some_and(|c| c.replace(false)) {
                        return Err(Failure::Retry(format!(
                            "a conductance model asked for a smaller step ({e})"
                        )));
                    }
                    return Err(Failure::Fatal(HeatError::Contact(e.to_string())));
                }
            };
            for &(d, v) in &s.residual {
                r[d as usize] += v;
            }
            s.add_scattered(asm, &self.scatters[k]);
            systems.push(Some(s));
        }
        // Ties: Cᵀλ and C u − ΔT ∫ψ; a tie switched off keeps λ = 0.
        for (ti, tie) in setup.ties.iter().enumerate() {
            let l0 = setup.lambda_first[ti];
            if !p.is_active(p.contact.len() + ti, t) {
                for k in 0..tie.nodes.len() {
                    r[l0 + k] = u[l0 + k];
                    asm.add_diagonal(l0 + k, 1.0);
                }
                continue;
            }
            for (e, &(k, d, c)) in tie.entries.iter().enumerate() {
                let l = l0 + k as usize;
                r[d as usize] += c * u[l];
                r[l] += c * u[d as usize];
                asm.add_coupling(self.tie_first[ti] + e, c, c);
            }
            for (k, w) in tie.psi_integral.iter().enumerate() {
                r[l0 + k] -= p.ties[ti].offset * w;
            }
        }
        Ok((r, systems))
    }

    /// Heat through each interface at `u`: contact terms from their residuals, ties
    /// from Cᵀλ.
    fn heat(&self, systems: &[Option<InterfaceSystem>], u: &[f64]) -> Vec<(f64, f64)> {
        let mut out: Vec<(f64, f64)> = systems
            .iter()
            .map(|s| s.as_ref().map_or((0.0, 0.0), InterfaceSystem::heat))
            .collect();
        for (ti, tie) in self.setup.ties.iter().enumerate() {
            let l0 = self.setup.lambda_first[ti];
            let mut ct = std::collections::BTreeMap::<u32, f64>::new();
            for &(k, d, c) in &tie.entries {
                *ct.entry(d).or_default() += c * u[l0 + k as usize];
            }
            let sum = |set: &[u32]| {
                set.iter()
                    .map(|d| ct.get(d).copied().unwrap_or(0.0))
                    .sum::<f64>()
            };
            out.push((sum(&tie.side_a_dofs), sum(&tie.side_b_dofs)));
        }
        out
    }
}
