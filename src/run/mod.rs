//! `seam run`: a heat-transfer problem file (TOML) solved end to end — mesh, materials,
//! boundary conditions, sources, the Sierra contact definition, the steady solve, the
//! results (`.vtu`, Exodus; the heat flux and, with `Visualize Contact`, the contact
//! fields: `fields`; the files and histories: `steps`) and a summary.
//!
//! Entry point: [`run`]. Field by field:
//!
//! ```toml
//! [mesh]
//! file = "two_blocks.exo"            # Exodus II or Gmsh 4.1, relative to this file
//! [[material]]
//! blocks = ["block_1", "block_2"]
//! conductivity = 1.0                 # W/m/K
//! [[bc]]
//! kind = "temperature"               # temperature | flux | convection
//! surfaces = ["surface_1"]           # side sets (or node sets, for temperature)
//! value = "1 + x + 2*y - 3*z"        # a number or a Lua expression of x, y, z, t
//! ambient = 300.0                    # convection only: T∞ (value is then h)
//! [[source]]                         # optional volumetric source Q (W/m³)
//! blocks = ["block_1"]
//! value = "1e3*x"                    # a number, a Lua expression of x, y, z, t and T, or
//!                                    # { table = [[t, Q], …] } in time
//! [contact]
//! file = "contact.i"                 # Sierra-syntax contact definition(s)
//! integration = "segments"           # segments (exact, default) | quadrature
//! order = 5
//! [solve]
//! kind = "steady"
//! tolerance = 1e-10
//! max_iterations = 20
//! [output]
//! dir = "out"
//! ```
//!
//! A flux or convection value given as a Lua expression is evaluated at each face's
//! centroid; temperature values at the nodes; sources at the quadrature points, where a
//! source that names `T` sees the interpolated temperature (and makes the problem
//! nonlinear). The time `t` is 0 in a steady solve.

mod contact;
mod fields;
mod nodal_field;
mod physics;
mod posed;
mod problem;
mod steps;

use contact::{Choice, Couplings, RunContact};
use physics::Physics;
use problem::ProblemFile;
pub use problem::{
    BcKind, BcSpec, ContactSpec, InitialSpec, MAX_MAGNITUDE, MAX_TEMPERATURE, MaterialSpec,
    MeshSpec, NodalFieldSpec, OutputSpec, Problem, RestartSpec, SolveSpec, SourceSpec, ToggleSpec,
    Value,
};

use crate::enforce::interface::{InterfaceError, InterfacePoints, PointFlux};
use crate::enforce::mortar::MortarTie;
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::Serialize;

use crate::assembly::DofMap;
use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::enforce::conductance::PointState;
use crate::enforce::interface::{DEFAULT_BETA, HFn, HInput, HValue, InterfaceForm};
use crate::heat::steady::{ContactTerm, SteadyProblem, SteadySolution, TieTerm, solve_steady};
use crate::heat::transient::{
    self, FieldSpec, Loads, Start, State, StepReport, TimeMode, TransientProblem,
};
use crate::heat::{HeatError, TEMPERATURE};

use crate::mesh::{self, Mesh, NodeId};
use crate::search::pairing::PointStatus;
use crate::search::scene::Pairing;

use fields::Derived;

/// The file a run that did not converge leaves in its output folder, holding the
/// residual history and the likely cause.
pub const NOT_CONVERGED: &str = "NOT_CONVERGED";

/// One interaction's line in the summary.
#[derive(Clone, Debug, Serialize)]
pub struct InteractionHeat {
    pub side_a: String,
    pub side_b: String,
    pub model: String,
    pub heat_side_a: f64,
    pub heat_side_b: f64,
    pub imbalance: f64,
}

#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Timing {
    /// Reading the mesh.
    pub mesh_s: f64,
    pub surfaces_s: f64,
    pub search_s: f64,
    pub assembly_s: f64,
    pub factor_s: f64,
    pub solve_s: f64,
    pub total_s: f64,
}

/// The `--json` summary (an interface: keys are stable).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub dofs: usize,
    pub newton_iterations: usize,
    pub converged: bool,
    pub interactions: Vec<InteractionHeat>,
    pub timing: Timing,
    pub output: Option<PathBuf>,
    /// Transient runs only.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub transient: Option<TransientSummary>,
    /// The process's peak resident memory (MiB) at the end of the run, where the
    /// system reports it (Linux: `VmHWM` in `/proc/self/status`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_memory_mib: Option<f64>,
    /// When `converged` is false: the residual history and the likely cause.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub diagnosis: Option<String>,
    /// Which linear solver ran and why.
    pub linear_solver: LinearSolverSummary,
}

/// The linear solver of a run, the reason it was chosen, and its CG iterations.
#[derive(Clone, Debug, Serialize)]
pub struct LinearSolverSummary {
    /// `Cholesky`, `LDLᵀ`, `LU`, `AMG-CG`, or `direct` (transient and nonlinear runs,
    /// which factor each step's system with the solver its kind needs).
    pub name: String,
    /// Why: `requested by linear_solver`, or `auto: …` with the size and kind.
    pub reason: String,
    /// CG iterations in total (0 for factorisations).
    pub iterations: usize,
    /// CG iterations of each solve.
    pub iterations_per_solve: Vec<usize>,
}

/// The summary of a linear steady solve's solver: `requested` is the `linear_solver`
/// field (`None` or `auto` for the automatic choice), `n` the unknowns.
fn linear_solver_summary(
    requested: Option<&str>,
    threshold: usize,
    n: usize,
    ties: bool,
    linear: &crate::heat::steady::LinearSolves,
) -> LinearSolverSummary {
    use crate::heat::steady::LinearMethod;
    let auto = matches!(requested, None | Some("auto"));
    let why = match linear.method {
        Some(LinearMethod::AmgCg) => {
            format!("{n:.1e} unknowns, symmetric positive definite → AMG-CG")
        }
        Some(LinearMethod::SaddleLdlt) => "multipliers make the system indefinite → LDLᵀ".into(),
        Some(LinearMethod::Lu) => {
            "a temperature-dependent conductance makes the Jacobian unsymmetric → LU".into()
        }
        Some(LinearMethod::Cholesky) if ties => {
            "dual mortar ties condensed to a symmetric positive definite system → Cholesky".into()
        }
        Some(LinearMethod::Cholesky) => format!("{n} unknowns (< {threshold}) → Cholesky"),
        None => "no linear solve was needed".into(),
    };
    let asked_amg = requested == Some("amg");
    let reason = if auto {
        format!("auto: {why}")
    } else if asked_amg && linear.method.is_some_and(|m| m != LinearMethod::AmgCg) {
        format!("linear_solver = \"amg\" requested, but {why}")
    } else {
        "requested by linear_solver".into()
    };
    LinearSolverSummary {
        name: linear.method.map_or("none", LinearMethod::name).into(),
        reason,
        iterations: linear.cg_iterations.iter().sum(),
        iterations_per_solve: linear.cg_iterations.clone(),
    }
}

/// Peak resident memory of this process in MiB (Linux only; None elsewhere).
pub fn peak_memory_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}

/// What a transient run did.
#[derive(Clone, Debug, Serialize)]
pub struct TransientSummary {
    pub steps: usize,
    pub rejected_steps: usize,
    pub end_time: f64,
}

/// What went wrong: bad input (diagnostics) or a solve that failed.
#[derive(Debug)]
pub enum RunError {
    Input(Diagnostics, SourceMap),
    Solve(String),
}

/// Everything a run made, for callers that want more than the summary.
pub struct RunResult {
    pub summary: Summary,
    pub mesh: Mesh,
    /// The final state (the last step of a transient run).
    pub solution: SteadySolution,
    /// Every accepted step (transient and nonlinear runs; empty for linear steady).
    pub history: Vec<StepReport>,
    pub warnings: Diagnostics,
    pub sources: SourceMap,
}

fn input_error(code: &'static str, message: String, help: &str) -> RunError {
    let mut d = Diagnostics::default();
    d.push(Diagnostic::error(code, message).help(help));
    RunError::Input(d, SourceMap::default())
}

/// Solve the problem in `path`.
pub fn run(path: &Path) -> Result<RunResult, RunError> {
    run_with(path, &RunOptions::default())
}

/// How to run beyond the problem file.
#[derive(Default)]
pub struct RunOptions {
    /// Continue from this checkpoint (overrides `[restart]`).
    pub restart: Option<PathBuf>,
    /// Called after every accepted step (progress display).
    #[allow(clippy::type_complexity)]
    pub progress: Option<Box<dyn Fn(&StepReport)>>,
    /// Called when a phase of the run starts (`reading the mesh`, `search`, `solve`…),
    /// so long set-up work shows on a progress display too.
    #[allow(clippy::type_complexity)]
    pub phase: Option<Box<dyn Fn(&str)>>,
}

impl RunOptions {
    fn phase(&self, what: &str) {
        if let Some(f) = &self.phase {
            f(what);
        }
    }
}

/// Solve the problem in `path` with `options`.
pub fn run_with(path: &Path, options: &RunOptions) -> Result<RunResult, RunError> {
    match run_until(path, options, Stop::AfterRun)? {
        Outcome::Ran(result) => Ok(*result),
        Outcome::Checked(warnings) => Err(RunError::Input(warnings.diagnostics, warnings.sources)),
    }
}

/// What a pre-flight found: the warnings, with the sources they point into.
pub struct Checked {
    pub diagnostics: Diagnostics,
    pub sources: SourceMap,
}

/// Every validation `seam run` makes before it solves — the problem file, the mesh,
/// materials, conditions, sources, the contact scene with its models (Lua compiled,
/// plugins loaded) — without solving or writing anything. A problem that passes does
/// not fail at the start of a run.
pub fn check(path: &Path) -> Result<Checked, RunError> {
    match run_until(path, &RunOptions::default(), Stop::BeforeSolve)? {
        Outcome::Checked(c) => Ok(c),
        Outcome::Ran(r) => Ok(Checked {
            diagnostics: r.warnings,
            sources: r.sources,
        }),
    }
}

/// Where [`run_until`] stops.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Stop {
    BeforeSolve,
    AfterRun,
}

enum Outcome {
    Ran(Box<RunResult>),
    Checked(Checked),
}

/// The run, up to `stop`: the checks and set-up, then (unless stopped) the solve and output.
fn run_until(path: &Path, options: &RunOptions, stop: Stop) -> Result<Outcome, RunError> {
    let start = Instant::now();
    let file = ProblemFile::read(path)?;
    let (problem, at, dir, transient) = (&file.problem, &file.text, &file.dir, file.transient);
    let clock = Instant::now();
    options.phase("reading the mesh");
    let mesh = mesh::read(&dir.join(&problem.mesh.file))
        .map_err(|e| input_error("E0400", e.to_string(), "check [mesh] file"))?;
    let mesh_s = clock.elapsed().as_secs_f64();
    let mut diags = Diagnostics::default();
    let mut physics = Physics::new(&file, &mesh, &mut diags);
    if diags.has_errors() {
        return Err(RunError::Input(diags, at.sources()));
    }
    physics.try_start()?;
    let start_time = physics.time.start;
    let field_names = physics.field_names.clone();
    let materials = &physics.materials;
    let dirichlet = &physics.dirichlet;

    let contact = RunContact::build(&file, &mesh, &physics.field_names, options, &mut diags)?;
    contact.mask_face_conditions(&mut physics.face_sites, &mut diags);
    if !transient {
        posed::check_steady(&physics, &contact.pairings, &mut diags);
    }
    let couplings = Couplings::resolve(&file, &physics, &contact, &mut diags);
    if diags.has_errors() {
        return Err(RunError::Input(diags, contact.loaded.sources));
    }
    // The initial state is checked here (transient runs start from it).
    let initial_state = physics.initial_state()?;
    if stop == Stop::BeforeSolve {
        return Ok(Outcome::Checked(Checked {
            diagnostics: diags,
            sources: contact.loaded.sources,
        }));
    }
    let mut timing = Timing {
        surfaces_s: contact.surfaces_s,
        search_s: contact.search_s,
        ..Timing::default()
    };
    let (pairings, choices, views) = (&contact.pairings, &contact.choices, &contact.views);
    let (toggles, term_fields, pressures) =
        (&couplings.toggles, &couplings.fields, &couplings.pressures);
    // Nitsche weights need one k per block: the law at the probe temperature.
    let conductivity: Vec<f64> = physics.conductivity();
    // The time every conductance model sees (set by the solver through the loads).
    let clock = std::cell::Cell::new(start_time);
    let cutback = std::cell::Cell::new(false);
    // Each conductance model seen by the interface forms: the point's gap and
    // temperatures and the enforcement's contact pressure in, h and dh/dT out.
    // Per interaction: the points a model failed at, with the reason (quarantine).
    type Quarantined = std::cell::RefCell<Vec<([f64; 3], String)>>;
    let quarantined: Vec<Quarantined> = choices.iter().map(|_| Default::default()).collect();
    let h_fns: Vec<Box<HFn<'_>>> = choices
        .iter()
        .zip(&quarantined)
        .zip(pairings)
        .zip(pressures)
        .map(|((((choice, _, model), log), pairing), at_points)| {
            let pressure = choice.pressure;
            let quarantine = choice.quarantine;
            let label = format!(
                "interaction {} / {} ({})",
                pairing.side_a, pairing.side_b, choice.name
            );
            let (clock, cutback) = (&clock, &cutback);
            let f = move |p: &HInput| -> Result<HValue, String> {
                let Some(m) = model else {
                    return Ok(HValue::default());
                };
                let state = PointState {
                    gap: p.gap,
                    pressure: at_points.as_ref().map_or(pressure, |v| v[p.point]),
                    temp_a: p.temp_a,
                    temp_b: p.temp_b,
                    x: p.x,
                    time: clock.get(),
                };
                let c = match m.evaluate(&state) {
                    Ok(c) => c,
                    Err(e) if e.is_cutback() => {
                        cutback.set(true);
                        return Err(format!("{label}: {e}"));
                    }
                    // Quarantine: the point contributes nothing; it is reported after the
                    // run. Each Newton step evaluates it again, so keep it once.
                    Err(e) if quarantine => {
                        let mut log = log.borrow_mut();
                        if !log.iter().any(|(x, _)| *x == p.x) {
                            log.push((p.x, e.to_string()));
                        }
                        return Ok(HValue::default());
                    }
                    Err(e) => {
                        return Err(format!(
                            "{label}: {e} (add `Quarantine Faulty Points` to the enforcement to skip such points)"
                        ));
                    }
                };
                Ok(HValue {
                    h: c.h,
                    dh_dtemp_a: c.dh_dtemp_a,
                    dh_dtemp_b: c.dh_dtemp_b,
                })
            };
            Box::new(f) as Box<HFn<'_>>
        })
        .collect();
    let contact_terms = || -> Vec<ContactTerm<'_>> {
        pairings
            .iter()
            .zip(choices)
            .zip(&h_fns)
            .filter(|((_, (c, _, _)), _)| !c.mortar)
            .map(|((p, (c, scale, model)), h)| ContactTerm {
                side_a: &p.side_a_geometry,
                side_b: &p.side_b_geometry,
                points: &p.result.points,
                form: InterfaceForm {
                    form: c.form,
                    h: h.as_ref(),
                    offset: c.offset,
                    beta: c.penalty_factor.unwrap_or(DEFAULT_BETA) * scale,
                    conductivity: &conductivity,
                },
                // A conductance independent of T keeps the system linear and symmetric.
                linear: model.as_ref().is_none_or(|m| !m.depends_on_temperature()),
            })
            .collect()
    };
    let tie_terms = || -> Vec<TieTerm<'_>> {
        pairings
            .iter()
            .zip(choices)
            .filter(|(_, (c, _, _))| c.mortar)
            .map(|(p, (c, _, _))| TieTerm {
                side_a: &p.side_a_geometry,
                side_b: &p.side_b_geometry,
                points: &p.result.points,
                offset: c.offset,
                multipliers: if c.dual {
                    crate::enforce::mortar::Multipliers::Dual
                } else {
                    crate::enforce::mortar::Multipliers::Standard
                },
            })
            .collect()
    };
    // The solver's term order (contact terms, then ties) → choice index.
    let term_choice: Vec<usize> = (0..choices.len())
        .filter(|&k| !choices[k].0.mortar)
        .chain((0..choices.len()).filter(|&k| choices[k].0.mortar))
        .collect();
    // Per interaction: the names of its conductance's mechanisms (empty unless a sum).
    let mechanism_names: Vec<Vec<String>> = choices
        .iter()
        .map(|(_, _, m)| {
            m.as_ref()
                .map_or_else(Vec::new, |m| fields::mechanism_names(m.as_ref()))
        })
        .collect();
    // What a state gives beyond its temperature: per interaction the flux at its points
    // (where the contact output or a mechanism split needs it; `faces` asks for the
    // contact output) and the heat of each mechanism.
    // The mortar ties as the solver built them, for their multipliers' fluxes (made at
    // the first state that asks).
    let tie_geometry: std::cell::OnceCell<Result<Vec<MortarTie>, String>> = Default::default();
    // Per interaction, the geometry at its points, for the point fluxes.
    let point_geometry: Vec<std::cell::OnceCell<Result<InterfacePoints, String>>> =
        pairings.iter().map(|_| Default::default()).collect();
    let derive = |u: &[f64], dofs: &DofMap, time: f64, faces: bool| -> Result<Derived, String> {
        clock.set(time);
        let mut out = Derived::default();
        for (k, ((p, (c, scale, model)), h)) in pairings.iter().zip(choices).zip(&h_fns).enumerate()
        {
            let split = !mechanism_names[k].is_empty();
            if c.mortar && faces && views[k].faces {
                // A multiplier tie: the flux is its multiplier field λ_h at the points.
                let ties = tie_geometry.get_or_init(|| {
                    rebuild_ties(
                        &mesh,
                        dofs,
                        pairings,
                        choices,
                        term_fields,
                        &field_names,
                        dirichlet,
                        &conductivity,
                    )
                });
                let ties = ties.as_ref().map_err(Clone::clone)?;
                let t = choices[..k].iter().filter(|(c, _, _)| c.mortar).count();
                let (Some(tie), Some(range)) = (ties.get(t), dofs.extra_ranges().get(t)) else {
                    return Err(format!(
                        "interaction {} / {}: no multipliers in the state",
                        p.side_a, p.side_b
                    ));
                };
                let on = couplings.on(k, time);
                let q = tie
                    .point_flux(&u[range.clone()], p.result.points.len())
                    .into_iter()
                    .map(|q| {
                        q.map(|q| PointFlux {
                            q: if on { q } else { 0.0 },
                            temp_a: f64::NAN,
                            temp_b: f64::NAN,
                        })
                    })
                    .collect();
                out.fluxes.push(Some(q));
                out.mechanisms.push(Vec::new());
                continue;
            }
            if c.mortar || !(split || (faces && views[k].faces)) {
                out.fluxes.push(None);
                out.mechanisms.push(Vec::new());
                continue;
            }
            let field = |i: usize| {
                dofs.field(&field_names[i])
                    .ok_or_else(|| format!("no dofs of field `{}`", field_names[i]))
            };
            let (fa, fb) = term_fields[k];
            let pair = crate::enforce::interface::FieldPair {
                a: field(fa)?,
                b: field(fb)?,
            };
            let form = InterfaceForm {
                form: c.form,
                h: h.as_ref(),
                offset: c.offset,
                beta: c.penalty_factor.unwrap_or(DEFAULT_BETA) * scale,
                conductivity: &conductivity,
            };
            let named = |e: InterfaceError| format!("interaction {} / {}: {e}", p.side_a, p.side_b);
            // The points' geometry is made at the first state that asks and kept: the
            // pairing and the dofs do not change over a run.
            let points = point_geometry[k].get_or_init(|| {
                InterfacePoints::new(
                    &mesh,
                    dofs,
                    pair,
                    &p.side_a_geometry,
                    &p.side_b_geometry,
                    &p.result.points,
                    &form,
                )
                .map_err(named)
            });
            let points = points.as_ref().map_err(Clone::clone)?;
            let q = points
                .point_flux(&form, u, p.result.points.len())
                .map_err(named);
            // The output evaluates the models once more; a cutback asked for here is not
            // the next step's.
            cutback.set(false);
            let mut q = q?;
            let on = couplings.on(k, time);
            if !on {
                q.iter_mut().flatten().for_each(|f| f.q = 0.0);
            }
            let mechanisms = match model {
                Some(m) if split => fields::mechanism_heat(
                    m.as_ref(),
                    p,
                    &q,
                    |i| pressures[k].as_ref().map_or(c.pressure, |v| v[i]),
                    time,
                ),
                _ => Vec::new(),
            };
            out.fluxes.push(Some(q));
            out.mechanisms.push(mechanisms);
        }
        Ok(out)
    };
    // The contact faces of a derived state, when some interaction visualises contact.
    let contact_of = |d: &Derived| -> Option<fields::ContactFields> {
        if !views.iter().any(|v| v.faces) {
            return None;
        }
        let mut out = fields::ContactFields::default();
        for (k, p) in pairings.iter().enumerate().filter(|(k, _)| views[*k].faces) {
            fields::contact_faces(
                p,
                k as u32 + 1,
                d.fluxes[k].as_deref(),
                views[k].side_b,
                &mut out,
            );
        }
        Some(out)
    };
    // Mechanism heats in the solver's term order.
    let term_mechanisms = |d: &Derived| -> Vec<Vec<f64>> {
        term_choice
            .iter()
            .map(|&k| d.mechanisms[k].clone())
            .collect()
    };
    let mut split_history: Vec<Vec<Vec<f64>>> = Vec::new();
    // The global variables of results.exo: the heat leaving each side of every term.
    let heat_names = steps::interface_heat_names(
        &term_choice
            .iter()
            .map(|&k| (pairings[k].side_a.as_str(), pairings[k].side_b.as_str()))
            .collect::<Vec<_>>(),
    );
    // One state's fields as step `step` of the results (temperature, heat flux, contact
    // faces), from its derived values when they were made with the faces.
    let write_state = |writer: &mut steps::StepWriter<'_>,
                       u: &[f64],
                       dofs: &DofMap,
                       step: usize,
                       time: f64,
                       derived: Option<Derived>,
                       heat: &[(f64, f64)]|
     -> Result<(), String> {
        let derived = match derived {
            Some(d) => d,
            None => derive(u, dofs, time, true)?,
        };
        let t = steps::nodal_temperature(dofs, u, &field_names);
        let q = fields::element_heat_flux(&mesh, &materials.laws, &t, time)?;
        let contact = contact_of(&derived);
        let fields = steps::StepFields {
            temperature: &t,
            heat_flux: &q,
            contact: contact.as_ref(),
            heat_names: &heat_names,
            heat,
        };
        writer
            .write_step(step, time, &fields)
            .map_err(|e| format!("cannot write the results of step {step}: {e}"))
    };
    let out_dir = match &problem.output.dir {
        Some(d) => {
            let out_dir = dir.join(d);
            std::fs::create_dir_all(&out_dir).map_err(|e| {
                RunError::Solve(format!("cannot create {}: {e}", out_dir.display()))
            })?;
            // A mark left by an earlier run that did not converge.
            let _ = std::fs::remove_file(out_dir.join(NOT_CONVERGED));
            Some(out_dir)
        }
        None => None,
    };

    let linear_steady = !transient
        && physics.uniform
        && materials.constant().is_some()
        && field_names.len() == 1
        && toggles.iter().all(Option::is_none)
        && problem.bc.iter().all(|b| b.kind != BcKind::Radiation);
    let mut history = Vec::new();
    let mut writer = steps::StepWriter::new(out_dir.as_deref(), &mesh, &problem.output, transient);
    let requested = problem.solve.linear_solver.as_deref();
    let threshold = problem
        .solve
        .auto_threshold
        .unwrap_or(crate::heat::steady::AUTO_AMG_THRESHOLD);
    let mut linear_summary = LinearSolverSummary {
        name: "direct".into(),
        reason: if matches!(requested, None | Some("auto")) {
            format!(
                "auto: step systems below {threshold} unknowns or not symmetric positive definite are factored (Cholesky, LDLᵀ or LU by their kind)"
            )
        } else {
            "requested by linear_solver".into()
        },
        iterations: 0,
        iterations_per_solve: Vec::new(),
    };
    let solution = if linear_steady {
        let source_failed = std::sync::Mutex::new(None::<String>);
        let source = physics.source_of_x(&source_failed);
        let source_fn = source.as_deref();
        let materials = materials.constant().expect("checked constant");
        // The temperature unknowns (multipliers aside) decide the automatic choice.
        let solid: Vec<usize> = (0..mesh.blocks.len())
            .filter(|&b| mesh.blocks[b].topology.is_solid())
            .collect();
        let unknowns = DofMap::new(&mesh, &[(TEMPERATURE, &solid)])
            .map_err(|e| RunError::Solve(e.to_string()))?
            .len();
        let iterative = match requested {
            Some("amg") => true,
            Some("direct") => false,
            _ => unknowns >= threshold,
        };
        let loads = physics.loads_at(start_time).map_err(RunError::Solve)?;
        let steady = SteadyProblem {
            mesh: &mesh,
            materials: &materials,
            source: source_fn,
            dirichlet: &loads.dirichlet,
            face_bcs: &loads.faces,
            contact: contact_terms(),
            ties: tie_terms(),
            iterative,
            tolerance: problem.solve.tolerance,
            max_iterations: problem.solve.max_iterations,
        };
        options.phase(&format!(
            "assembling and solving ({} nodes)",
            mesh.num_nodes()
        ));
        let solved = solve_steady(&steady).map_err(|e| RunError::Solve(e.to_string()))?;
        linear_summary = linear_solver_summary(
            requested,
            threshold,
            unknowns,
            !steady.ties.is_empty(),
            &solved.linear,
        );
        if let Some(e) = source_failed.lock().ok().and_then(|mut s| s.take()) {
            return Err(RunError::Solve(format!("[[source]]: {e}")));
        }
        solved
    } else {
        let loads = |t: f64| -> Result<Loads, HeatError> {
            clock.set(t);
            physics.loads_at(t).map_err(HeatError::Step)
        };
        let active = |k: usize, t: f64| -> bool { couplings.on(term_choice[k], t) };
        let tp = TransientProblem {
            mesh: &mesh,
            fields: field_names
                .iter()
                .map(|f| FieldSpec {
                    name: f.clone(),
                    blocks: (0..mesh.blocks.len())
                        .filter(|&b| {
                            mesh.blocks[b].topology.is_solid() && materials.fields[b] == *f
                        })
                        .collect(),
                })
                .collect(),
            laws: &materials.laws,
            source: None,
            block_source: Some(&physics.block_source),
            loads: &loads,
            contact: contact_terms(),
            ties: tie_terms(),
            term_fields: term_choice.iter().map(|&k| term_fields[k]).collect(),
            active: Some(&active),
            cutback: Some(&cutback),
            tolerance: problem.solve.tolerance,
            max_iterations: problem.solve.max_iterations,
            reproducible: problem.solve.reproducible.unwrap_or(true),
            amg_threshold: match requested {
                Some("direct") => None,
                Some("amg") => Some(0),
                _ => Some(threshold),
            },
        };
        let restart = match (&problem.restart, options.restart.as_ref()) {
            (_, Some(file)) => Some(steps::read_checkpoint(file)?),
            (Some(r), None) => Some(steps::read_checkpoint(&dir.join(&r.file))?),
            (None, None) => None,
        };
        let initial = match restart {
            Some(_) => Vec::new(),
            None => match initial_state {
                Some(v) => v,
                None => physics.initial_values()?,
            },
        };
        let at_node = |n: NodeId| initial[n.index()];
        let start = match restart {
            Some(state) => Start::Restart(state),
            None => Start::Fresh {
                time: start_time,
                dt: physics.time.dt,
                initial: &at_node,
            },
        };
        let mode = if transient {
            TimeMode::Transient {
                scheme: physics.time.scheme,
                end: physics.time.end,
                adaptive: physics.time.adaptive,
                dt_min: physics.time.dt_min,
            }
        } else {
            TimeMode::Steady { time: start_time }
        };
        let mut writer =
            steps::StepWriter::new(out_dir.as_deref(), &mesh, &problem.output, transient);
        let mut on_step = |r: &StepReport, st: &State, dofs: &DofMap| -> Result<(), HeatError> {
            if let Some(progress) = options.progress.as_ref() {
                progress(r);
            }
            let due = writer.due(r.step);
            let derived = derive(&st.u, dofs, st.time, due).map_err(HeatError::Step)?;
            split_history.push(term_mechanisms(&derived));
            if due {
                write_state(
                    &mut writer,
                    &st.u,
                    dofs,
                    st.step,
                    st.time,
                    Some(derived),
                    &r.heat,
                )
                .map_err(HeatError::Step)?;
            }
            writer
                .checkpoint(st)
                .map_err(|e| HeatError::Step(e.to_string()))?;
            history.push(r.clone());
            Ok(())
        };
        options.phase(&format!(
            "assembling and factorising the first step ({} nodes)",
            mesh.num_nodes()
        ));
        let outcome = transient::solve(&tp, mode, start, &mut on_step)
            .map_err(|e| RunError::Solve(e.to_string()))?;
        let last = &outcome.state;
        if out_dir.is_some() && !writer.written(last.step) {
            write_state(
                &mut writer,
                &last.u,
                &outcome.dofs,
                last.step,
                last.time,
                None,
                history.last().map_or(&[][..], |r| &r.heat),
            )
            .map_err(RunError::Solve)?;
        }
        writer
            .finish(last)
            .map_err(|e| RunError::Solve(e.to_string()))?;
        // CG iterations per accepted step, when the steps were solved by AMG-CG.
        let per_step: Vec<usize> = history.iter().map(|r| r.cg_iterations).collect();
        if per_step.iter().any(|&k| k > 0) {
            let n = outcome.dofs.len();
            linear_summary = LinearSolverSummary {
                name: "AMG-CG".into(),
                reason: if matches!(requested, None | Some("auto")) {
                    format!(
                        "auto: {n:.1e} unknowns, symmetric positive definite steps → AMG-CG (hierarchy kept while the matrix is unchanged)"
                    )
                } else {
                    "requested by linear_solver".into()
                },
                iterations: per_step.iter().sum(),
                iterations_per_solve: per_step,
            };
        }
        steps::final_solution(outcome, &history, &field_names, tp.contact.len())
    };
    for ((p, (c, _, _)), log) in pairings.iter().zip(choices).zip(&quarantined) {
        let log = log.borrow();
        if let Some((x, first)) = log.first() {
            diags.push(
                Diagnostic::warning(
                    "W0501",
                    format!(
                        "interaction {} / {} ({}): {} point(s) quarantined; the first at ({:.6}, {:.6}, {:.6}): {first}",
                        p.side_a, p.side_b, c.name, log.len(), x[0], x[1], x[2]
                    ),
                )
                .help("the conductance model failed there; those points carry no heat"),
            );
        }
    }
    timing.assembly_s = solution.timing.assembly_s;
    timing.factor_s = solution.timing.factor_s;
    timing.solve_s = solution.timing.solve_s;

    let output = match &out_dir {
        Some(out_dir) => {
            let io = |e: std::io::Error| {
                RunError::Solve(format!(
                    "cannot write the results in {}: {e}",
                    out_dir.display()
                ))
            };
            let final_time = history.last().map_or(start_time, |r| r.time);
            let derived =
                derive(&solution.u, &solution.dofs, final_time, true).map_err(RunError::Solve)?;
            let heat_flux = fields::element_heat_flux(
                &mesh,
                &materials.laws,
                &solution.temperature,
                final_time,
            )
            .map_err(RunError::Solve)?;
            let contact = contact_of(&derived);
            let steady_heat: Vec<(f64, f64)> = solution
                .heat
                .iter()
                .chain(&solution.tie_heat)
                .copied()
                .collect();
            let state = steps::StepFields {
                temperature: &solution.temperature,
                heat_flux: &heat_flux,
                contact: contact.as_ref(),
                heat_names: &heat_names,
                heat: &steady_heat,
            };
            let file = out_dir.join("temperature.vtu");
            let per_field: Vec<(String, Vec<f64>)> = if field_names.len() > 1 {
                field_names
                    .iter()
                    .filter_map(|f| {
                        solution
                            .dofs
                            .field(f)
                            .map(|id| (f.clone(), solution.dofs.nodal_values(id, &solution.u)))
                    })
                    .collect()
            } else {
                Vec::new()
            };
            let extra: Vec<(&str, &[f64])> = per_field
                .iter()
                .map(|(name, v)| (name.as_str(), v.as_slice()))
                .collect();
            steps::write_temperature_vtu(&file, &mesh, &state, &extra)
                .map_err(|e| RunError::Solve(format!("cannot write {}: {e}", file.display())))?;
            if let Some(c) = &contact {
                steps::write_contact_vtu(
                    &out_dir.join("contact.vtu"),
                    &mesh,
                    &solution.temperature,
                    c,
                )
                .map_err(io)?;
            }
            let points: Vec<fields::PointsOf<'_>> = pairings
                .iter()
                .enumerate()
                .filter(|(k, _)| views[*k].points)
                .map(|(k, p)| (k as u32 + 1, p, derived.fluxes[k].as_deref()))
                .collect();
            if !points.is_empty() {
                steps::write_contact_points_vtu(&out_dir.join("contact_points.vtu"), &points)
                    .map_err(io)?;
            }
            if linear_steady {
                writer.write_step(0, start_time, &state).map_err(io)?;
                writer.close().map_err(io)?;
            }
            let labels: Vec<(String, String, String)> = term_choice
                .iter()
                .map(|&k| {
                    (
                        pairings[k].side_a.clone(),
                        pairings[k].side_b.clone(),
                        choices[k].0.name.clone(),
                    )
                })
                .collect();
            let names: Vec<Vec<String>> = term_choice
                .iter()
                .map(|&k| mechanism_names[k].clone())
                .collect();
            if !history.is_empty() {
                steps::write_steps(out_dir, &history).map_err(io)?;
                let rows: Vec<steps::HeatRow<'_>> = history
                    .iter()
                    .zip(&split_history)
                    .map(|(r, m)| steps::HeatRow {
                        step: r.step,
                        time: r.time,
                        heat: &r.heat,
                        mechanisms: m,
                    })
                    .collect();
                steps::write_interface_heat(out_dir, &rows, &labels, &names).map_err(io)?;
            } else if !labels.is_empty() {
                // A linear steady solve: one row per interaction, as step 0.
                let heat: Vec<(f64, f64)> = solution
                    .heat
                    .iter()
                    .chain(&solution.tie_heat)
                    .copied()
                    .collect();
                let mechanisms = term_mechanisms(&derived);
                let row = steps::HeatRow {
                    step: 0,
                    time: start_time,
                    heat: &heat,
                    mechanisms: &mechanisms,
                };
                steps::write_interface_heat(out_dir, &[row], &labels, &names).map_err(io)?;
            }
            // The plotted line: through the first matched point of the first
            // interaction, along its side-A normal.
            let line = pairings.iter().find_map(|p| {
                p.result
                    .points
                    .iter()
                    .find(|q| q.status == PointStatus::Matched)
                    .map(|q| (q.x, q.normal_a))
            });
            steps::write_plots(
                out_dir,
                &mesh,
                &solution.temperature,
                &history,
                &labels,
                line,
            )
            .map_err(io)?;
            Some(file)
        }
        None => None,
    };
    // Heat per pairing, in pairing order: flux-type terms and ties were solved apart.
    let (mut flux_heat, mut tie_heat) = (solution.heat.iter(), solution.tie_heat.iter());
    let heats: Vec<(f64, f64)> = choices
        .iter()
        .map(|(c, _, _)| {
            let next = if c.mortar {
                tie_heat.next()
            } else {
                flux_heat.next()
            };
            next.copied().unwrap_or((0.0, 0.0))
        })
        .collect();
    for (t, cps) in solution.crosspoints.iter().enumerate() {
        if !cps.is_empty() {
            let numbers: Vec<String> = cps
                .iter()
                .take(10)
                .map(|n| mesh.node_number(*n).to_string())
                .collect();
            diags.push(
                Diagnostic::warning(
                    "W0430",
                    format!(
                        "tie #{}: {} side-A node(s) already constrained (Dirichlet data or an earlier tie) get no multiplier: {}{}",
                        t + 1,
                        cps.len(),
                        numbers.join(", "),
                        if cps.len() > 10 { ", …" } else { "" }
                    ),
                )
                .help("a crosspoint keeps its Dirichlet value (or its first tie); this keeps the system non-singular"),
            );
        }
    }
    let interactions = pairings
        .iter()
        .zip(choices)
        .zip(&heats)
        .map(|((p, (c, _, _)), &(a, b))| InteractionHeat {
            side_a: p.side_a.clone(),
            side_b: p.side_b.clone(),
            model: c.name.clone(),
            heat_side_a: a,
            heat_side_b: b,
            imbalance: a + b,
        })
        .collect();
    timing.mesh_s = mesh_s;
    timing.total_s = start.elapsed().as_secs_f64();
    let transient_summary = transient.then(|| TransientSummary {
        steps: history.len(),
        rejected_steps: history.iter().map(|r| r.rejected).sum(),
        end_time: history.last().map_or(start_time, |r| r.time),
    });
    let summary = Summary {
        dofs: solution.dofs.len(),
        newton_iterations: solution.newton_iterations,
        converged: solution.converged,
        interactions,
        timing,
        output,
        transient: transient_summary,
        peak_memory_mib: peak_memory_mib(),
        diagnosis: history.last().and_then(|r| r.diagnosis.clone()),
        linear_solver: linear_summary,
    };
    // A result that did not converge says so next to its files.
    if let (Some(dir), Some(d)) = (&out_dir, &summary.diagnosis) {
        std::fs::write(dir.join(NOT_CONVERGED), format!("{d}\n")).map_err(|e| {
            RunError::Solve(format!(
                "cannot write {}: {e}",
                dir.join(NOT_CONVERGED).display()
            ))
        })?;
    }
    Ok(Outcome::Ran(Box::new(RunResult {
        summary,
        mesh,
        solution,
        history,
        warnings: diags,
        sources: contact.loaded.sources,
    })))
}

/// The mortar ties of the run, built as the solvers build them: in interaction order,
/// with the Dirichlet nodes and the earlier ties' nodes left without multipliers, so
/// multiplier `k` of tie `t` is entry `k` of the state's `t`-th extra range.
#[allow(clippy::too_many_arguments)]
fn rebuild_ties(
    mesh: &Mesh,
    dofs: &DofMap,
    pairings: &[Pairing],
    choices: &[Choice],
    term_fields: &[(usize, usize)],
    field_names: &[String],
    dirichlet: &[(NodeId, usize)],
    conductivity: &[f64],
) -> Result<Vec<MortarTie>, String> {
    let mut constrained: std::collections::HashSet<NodeId> =
        dirichlet.iter().map(|&(n, _)| n).collect();
    let field = |i: usize| {
        dofs.field(&field_names[i])
            .ok_or_else(|| format!("no dofs of field `{}`", field_names[i]))
    };
    let mut out = Vec::new();
    for (k, (p, (c, _, _))) in pairings.iter().zip(choices).enumerate() {
        if !c.mortar {
            continue;
        }
        let (fa, fb) = term_fields[k];
        let pair = crate::enforce::interface::FieldPair {
            a: field(fa)?,
            b: field(fb)?,
        };
        let multipliers = if c.dual {
            crate::enforce::mortar::Multipliers::Dual
        } else {
            crate::enforce::mortar::Multipliers::Standard
        };
        let tie = crate::enforce::mortar::mortar_tie(
            mesh,
            dofs,
            pair,
            &p.side_a_geometry,
            &p.side_b_geometry,
            &p.result.points,
            conductivity,
            &mut constrained,
            multipliers,
        )
        .map_err(|e| format!("interaction {} / {}: {e}", p.side_a, p.side_b))?;
        out.push(tie);
    }
    Ok(out)
}
