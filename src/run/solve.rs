//! The solve of a run: one linear steady solve ([`solve_steady`]) when the problem allows
//! it (one field, constant materials, a source of x, no toggles, no radiation), else the
//! time loop of the general solver ([`transient::solve`]), of which a nonlinear steady
//! solve is the one step — under MPI, the distributed steps of one field
//! ([`crate::parallel::transient`]) where their conditions hold. Each accepted step is recorded, written when due and
//! checkpointed; the linear solver that ran is summarised with the reason for it.

use crate::assembly::DofMap;
use crate::enforce::conductance::{ConductanceModel, PointState};
use crate::enforce::interface::{HInput, HValue};
use crate::heat::electric::{ContactPower, VOLTAGE};
use crate::heat::law::Law;
use crate::heat::species::SPECIES;
use crate::heat::steady::{SteadyProblem, SteadySolution, solve_steady};
use crate::heat::transient::{
    self, BlockLaws, FieldSpec, Loads, Start, State, StepReport, TimeMode, TransientProblem,
};
use crate::heat::{HeatError, Material, SourceFn, TEMPERATURE};
use crate::mesh::NodeId;

use super::output::Output;
use super::physics::Physics;
use super::problem::{BcKind, ProblemFile};
use super::steps;
use super::summary::LinearSolverSummary;
use super::terms::ContactTerms;
use super::{RunError, RunOptions};

/// What the solve gives.
pub(super) struct Solved {
    /// The final state (the last step of a stepped run).
    pub solution: SteadySolution,
    /// Every accepted step (empty for a linear steady solve).
    pub history: Vec<StepReport>,
    /// Per accepted step, the heat of each mechanism in the solver's term order.
    pub mechanisms: Vec<Vec<Vec<f64>>>,
    pub linear_solver: LinearSolverSummary,
    /// Solved by the linear steady solver: one solve, no steps.
    pub linear_steady: bool,
    /// Per accepted step, each species interface's mass flux (mol/s) leaving side A and
    /// side B.
    pub species_flux: Vec<Vec<(f64, f64)>>,
}

/// The solve of a run, over its physics and contact terms.
pub(super) struct TimeLoop<'a> {
    file: &'a ProblemFile,
    physics: &'a Physics<'a>,
    terms: &'a ContactTerms<'a>,
    options: &'a RunOptions,
    /// The `linear_solver` asked for (`None` or `auto` for the automatic choice).
    requested: Option<&'a str>,
    /// The size from which `auto` picks AMG-CG.
    threshold: usize,
}

impl<'a> TimeLoop<'a> {
    pub(super) fn new(
        file: &'a ProblemFile,
        physics: &'a Physics<'a>,
        terms: &'a ContactTerms<'a>,
        options: &'a RunOptions,
    ) -> Self {
        let solve = &file.problem.solve;
        TimeLoop {
            file,
            physics,
            terms,
            options,
            requested: solve.linear_solver.as_deref(),
            threshold: solve
                .auto_threshold
                .unwrap_or(crate::heat::steady::AUTO_AMG_THRESHOLD),
        }
    }

    /// Solve from `initial` (the checked initial state, if any), writing the steps to
    /// `output` as they are accepted.
    pub(super) fn run(
        &self,
        initial: Option<Vec<f64>>,
        output: &mut Output<'a>,
    ) -> Result<Solved, RunError> {
        if self.is_linear_steady() {
            self.linear_steady()
        } else if self.is_stepped_on_ranks() {
            self.steps_on_ranks(initial, output)
        } else {
            self.steps(initial, output)
        }
    }

    /// Whether a run under MPI steps with its assembly distributed: a transient run, or
    /// a steady one the linear steady solve does not take (one Newton solve, the general
    /// solver's steady solve), of one temperature field — its laws and sources of T, x
    /// and t, radiation or not — its interfaces linear, or Newton through a
    /// temperature-dependent conductance, mortar ties with multipliers or not; toggled
    /// or not, from a checkpoint or not — nothing moving or dying. (Every run whose mesh
    /// `ranks::distributable` splits and is not a linear steady one is one.)
    fn is_stepped_on_ranks(&self) -> bool {
        let (physics, problem) = (self.physics, &self.file.problem);
        crate::parallel::world().is_some()
            && physics.field_names.len() == 1
            && !physics.materials.electric()
            && !physics.species.any()
            && problem.displacement.is_none()
            && problem.death.is_empty()
    }

    /// Whether one linear steady solve answers the problem: steady, one field, constant
    /// materials, a source of x alone, no toggles, no radiation (mortar ties with
    /// multipliers too, on ranks as serially).
    fn is_linear_steady(&self) -> bool {
        let physics = self.physics;
        !self.file.transient
            && physics.source_of_x_only()
            && physics.materials.constant().is_some()
            && physics.field_names.len() == 1
            && !physics.materials.electric()
            && !physics.species.any()
            && !self.terms.couplings.any_toggle()
            && (self.file.problem.bc.iter()).all(|b| b.kind != BcKind::Radiation)
    }

    /// One linear steady solve, by a factorisation or AMG-CG as `linear_solver` and the
    /// size say.
    fn linear_steady(&self) -> Result<Solved, RunError> {
        let (physics, problem) = (self.physics, &self.file.problem);
        let (requested, threshold) = (self.requested, self.threshold);
        let source_failed = std::sync::Mutex::new(None::<String>);
        let sources = physics.sources_of_x(&source_failed);
        let sources: Vec<Option<SourceFn<'_>>> = sources.iter().map(|f| f.as_deref()).collect();
        let extended = crate::parallel::extended_mesh(physics.mesh);
        let linear = self.linear_problem(&extended, &sources)?;
        let (unknowns, steady) = (linear.unknowns, linear.problem(problem));
        self.options.phase(&format!(
            "assembling and solving ({} nodes)",
            physics.mesh.num_nodes()
        ));
        // Under MPI the distributed solve (crate::parallel), else the serial one.
        let solved = crate::parallel::steady(&steady)
            .unwrap_or_else(|| solve_steady(&steady))
            .map_err(|e| RunError::Solve(e.to_string()))?;
        log::debug!(
            "linear steady solve of {unknowns} unknowns: {:?}, {} CG iterations, assembly {:.3} s, set-up {:.3} s, solve {:.3} s",
            solved.linear.method,
            solved.linear.cg_iterations.iter().sum::<usize>(),
            solved.timing.assembly_s,
            solved.timing.factor_s,
            solved.timing.solve_s
        );
        let mut linear_solver = linear_solver_summary(
            requested,
            threshold,
            unknowns,
            !solved.tie_heat.is_empty(),
            &solved.linear,
        );
        if let Some((name, reason)) = crate::parallel::linear_solver() {
            (linear_solver.name, linear_solver.reason) = (name, reason);
        }
        if let Some(e) = source_failed.lock().ok().and_then(|mut s| s.take()) {
            return Err(RunError::Solve(format!("[[source]]: {e}")));
        }
        Ok(Solved {
            solution: solved,
            history: Vec::new(),
            mechanisms: Vec::new(),
            linear_solver,
            linear_steady: true,
            species_flux: Vec::new(),
        })
    }

    /// What a linear solve (steady, or a linear transient run's steps on ranks) is made
    /// of, at the start time: on a rank holding a part of the mesh (under mpirun), its
    /// part `extended` with the side-B elements of other ranks its contact points
    /// paired with, each in a copy of its block.
    fn linear_problem<'m>(
        &'m self,
        extended: &'m Option<(crate::mesh::Mesh, Vec<usize>)>,
        sources: &[Option<SourceFn<'m>>],
    ) -> Result<LinearProblem<'m>, RunError> {
        let physics = self.physics;
        // `origin`: per block, the block it copies.
        let (mesh, origin) = match extended {
            Some((m, origin)) => (m, Some(origin.as_slice())),
            None => (physics.mesh, None),
        };
        // The constants of the linear solve; a law of T or time is read from `laws`
        // instead (NaN or 0 here, never read).
        let constant = |law: &Law, otherwise: f64| match law {
            Law::Constant(v) => *v,
            _ => otherwise,
        };
        let laws = &physics.materials.laws;
        let materials: Vec<Material> = (laws.iter())
            .map(|l| Material {
                conductivity: constant(&l.conductivity, f64::NAN),
                rho_c: constant(&l.capacity, 0.0),
            })
            .collect();
        let of_blocks = |law: fn(&BlockLaws) -> &Law| -> Vec<Law> {
            per_block(
                &laws.iter().map(|l| law(l).clone()).collect::<Vec<_>>(),
                origin,
            )
        };
        let laws = (
            of_blocks(|l| &l.conductivity),
            of_blocks(|l| &l.capacity),
            per_block(&physics.block_source, origin),
        );
        // The temperature unknowns (multipliers aside) decide the automatic choice.
        let solid: Vec<usize> = (0..mesh.blocks.len())
            .filter(|&b| mesh.blocks[b].topology.is_solid())
            .collect();
        let dofs = DofMap::new(mesh, &[(TEMPERATURE, &solid)])
            .map_err(|e| RunError::Solve(e.to_string()))?;
        // Every rank chooses by the whole problem's count.
        let unknowns = crate::parallel::global_unknowns(dofs.len());
        let interfaces = self
            .terms
            .prepare_on(mesh, origin, &dofs)
            .map_err(RunError::Solve)?;
        let iterative = match self.requested {
            Some("amg") => true,
            Some("direct") => false,
            _ => unknowns >= self.threshold,
        };
        let loads = physics
            .loads_at(physics.time.start)
            .map_err(RunError::Solve)?;
        Ok(LinearProblem {
            mesh,
            materials: per_block(&materials, origin),
            laws,
            block_source: per_block(sources, origin),
            loads,
            interfaces,
            iterative,
            unknowns,
        })
    }

    /// A transient run under MPI of the kind [`Self::is_stepped_on_ranks`] says (or its
    /// steady solve with a conductivity of T): its steps with the assembly distributed
    /// ([`crate::parallel::transient`]), each accepted one recorded as the general
    /// solver's are — written by rank 0, which gets the whole state.
    fn steps_on_ranks(
        &self,
        initial: Option<Vec<f64>>,
        output: &mut Output<'a>,
    ) -> Result<Solved, RunError> {
        let (physics, problem, time) = (self.physics, &self.file.problem, &self.physics.time);
        let source_failed = std::sync::Mutex::new(None::<String>);
        let sources = physics.sources_of_x(&source_failed);
        let sources: Vec<Option<SourceFn<'_>>> = sources.iter().map(|f| f.as_deref()).collect();
        let extended = crate::parallel::extended_mesh(physics.mesh);
        let linear = self.linear_problem(&extended, &sources)?;
        let steady = linear.problem(problem);
        // From a checkpoint, read by rank 0 (which sends every rank its part); the other
        // ranks stop with it when it cannot read it.
        let checkpoint = match self.checkpoint() {
            Some(file) => {
                let read = crate::parallel::is_root().then(|| steps::read_checkpoint(&file));
                let failed = read.as_ref().is_some_and(Result::is_err);
                if crate::parallel::root_verdict(failed) {
                    return Err(read
                        .and_then(Result::err)
                        .unwrap_or_else(super::ranks::quiet));
                }
                Some(read.unwrap_or_else(|| Ok(State::default()))?)
            }
            None => None,
        };
        let initial = match (initial, &checkpoint) {
            (Some(v), _) => v,
            (None, Some(_)) => Vec::new(),
            (None, None) => physics.initial_values()?,
        };
        let loads = |t: f64| {
            (physics.loads_at(t))
                .map(|l| (l.dirichlet, l.faces))
                .map_err(HeatError::Step)
        };
        let stepping = crate::parallel::Stepping {
            laws: crate::parallel::Laws {
                conductivity: &linear.laws.0,
                capacity: &linear.laws.1,
                source: &linear.laws.2,
            },
            steady: !self.file.transient,
            scheme: time.scheme,
            start: time.start,
            end: time.end,
            dt: time.dt,
            adaptive: time.adaptive,
            dt_min: time.dt_min,
            initial: &initial,
            restart: checkpoint.as_ref(),
            loads: &loads,
        };
        let mut recorder = Recorder {
            output,
            terms: self.terms,
            progress: self.options.progress.as_deref(),
            history: Vec::new(),
            mechanisms: Vec::new(),
            species_flux: Vec::new(),
        };
        self.options.phase(&format!(
            "assembling and solving the steps ({} nodes)",
            physics.mesh.num_nodes()
        ));
        // Rank 0 records and writes each step; the other ranks keep its report.
        let root = crate::parallel::is_root();
        let mut on_step = |r: &StepReport, st: &State, dofs: &DofMap| match root {
            true => recorder.record(r, st, dofs),
            false => {
                recorder.history.push(r.clone());
                Ok(())
            }
        };
        let outcome = crate::parallel::transient(&steady, &stepping, &mut on_step)
            .ok_or_else(|| RunError::Solve("a run on ranks without MPI".into()))?
            .map_err(|e| RunError::Solve(e.to_string()))?;
        if let Some(e) = source_failed.lock().ok().and_then(|mut s| s.take()) {
            return Err(RunError::Solve(format!("[[source]]: {e}")));
        }
        self.stepped(recorder, outcome, linear.unknowns)
    }

    /// The general solver's steps: a transient run, or a nonlinear steady solve as one
    /// step; from a checkpoint when the run restarts.
    fn steps(
        &self,
        initial: Option<Vec<f64>>,
        output: &mut Output<'a>,
    ) -> Result<Solved, RunError> {
        let (physics, mesh, terms) = (self.physics, self.physics.mesh, self.terms);
        let (problem, requested) = (&self.file.problem, self.requested);
        let time = &physics.time;
        let loads =
            |t: f64| -> Result<Loads, HeatError> { physics.loads_at(t).map_err(HeatError::Step) };
        let fields: Vec<FieldSpec> = physics
            .field_names
            .iter()
            .map(|f| FieldSpec {
                name: f.clone(),
                blocks: (0..mesh.blocks.len())
                    .filter(|&b| {
                        mesh.blocks[b].topology.is_solid() && physics.materials.fields[b] == *f
                    })
                    .collect(),
            })
            .collect();
        // The solver's dofs, as it numbers them: the fields in order, then the voltage.
        let mut list: Vec<(&str, &[usize])> = fields
            .iter()
            .map(|f| (f.name.as_str(), f.blocks.as_slice()))
            .collect();
        let sigma = &physics.materials.sigma;
        let voltage_blocks: Vec<usize> = (0..mesh.blocks.len())
            .filter(|&b| mesh.blocks[b].topology.is_solid() && sigma[b].is_some())
            .collect();
        if physics.materials.electric() {
            list.push((VOLTAGE, &voltage_blocks));
        }
        let species_blocks = physics.species.blocks(mesh);
        if physics.species.any() {
            list.push((SPECIES, &species_blocks));
        }
        let dofs = DofMap::new(mesh, &list).map_err(|e| RunError::Solve(e.to_string()))?;
        let interfaces = terms.prepare(&dofs).map_err(RunError::Solve)?;
        let contact_conductances: Vec<_> = terms
            .contact
            .electrical
            .iter()
            .map(|e| electric_conductance(e.model.as_ref(), e.pressure))
            .collect();
        let (diffusivity, capacity) = (
            physics.species.scaled_diffusivity(),
            physics.species.scaled_capacity(),
        );
        let species_initial = match physics.species.any() {
            true => super::species::initial(&self.file.problem, mesh, &physics.sandbox, time.start)
                .map_err(|e| {
                    super::input_error(
                        "E0707",
                        format!("[initial] species: {e}"),
                        "a number or a Lua expression of x, y, z",
                    )
                })?,
            false => Vec::new(),
        };
        let species_at =
            |n: NodeId| super::species::scaled(species_initial[n.index()], n, &physics.species);
        let tp = TransientProblem {
            mesh,
            fields,
            laws: &physics.materials.laws,
            source: None,
            block_source: Some(&physics.block_source),
            loads: &loads,
            interfaces: Some(interfaces),
            tolerance: problem.solve.tolerance,
            max_iterations: problem.solve.max_iterations,
            reproducible: problem.solve.reproducible.unwrap_or(true),
            amg_threshold: match requested {
                Some("direct") => None,
                Some("amg") => Some(0),
                _ => Some(self.threshold),
            },
            electric: physics.materials.electric().then(|| transient::Electric {
                conductivity: sigma,
                contacts: terms
                    .contact
                    .electrical
                    .iter()
                    .zip(&contact_conductances)
                    .map(|(e, h)| (e.contact.clone(), h as &transient::ContactConductance<'_>))
                    .collect(),
            }),
            death: terms.death_times(),
            species: physics.species.any().then(|| transient::Species {
                diffusivity: &diffusivity,
                capacity: &capacity,
                initial: &species_at,
            }),
        };
        let restart = self
            .checkpoint()
            .map(|f| steps::read_checkpoint(&f))
            .transpose()?;
        let initial = match restart {
            Some(_) => Vec::new(),
            None => match initial {
                Some(v) => v,
                None => physics.initial_values()?,
            },
        };
        let at_node = |n: NodeId| initial[n.index()];
        let start = match restart {
            Some(state) => Start::Restart(state),
            None => Start::Fresh {
                time: time.start,
                dt: time.dt,
                initial: &at_node,
            },
        };
        let mode = if self.file.transient {
            TimeMode::Transient {
                scheme: time.scheme,
                end: time.end,
                adaptive: time.adaptive,
                dt_min: time.dt_min,
            }
        } else {
            TimeMode::Steady { time: time.start }
        };
        let mut recorder = Recorder {
            output,
            terms,
            progress: self.options.progress.as_deref(),
            history: Vec::new(),
            mechanisms: Vec::new(),
            species_flux: Vec::new(),
        };
        self.options.phase(&format!(
            "assembling and factorising the first step ({} nodes)",
            mesh.num_nodes()
        ));
        let mut on_step = |r: &StepReport, st: &State, dofs: &DofMap| recorder.record(r, st, dofs);
        let outcome = transient::solve(&tp, mode, start, &mut on_step)
            .map_err(|e| RunError::Solve(e.to_string()))?;
        let n = outcome.dofs.len();
        self.stepped(recorder, outcome, n)
    }

    /// The checkpoint the run restarts from (`--restart` over the problem's
    /// `[restart]`), if any.
    fn checkpoint(&self) -> Option<std::path::PathBuf> {
        match (&self.file.problem.restart, self.options.restart.as_ref()) {
            (_, Some(file)) => Some(file.clone()),
            (Some(r), None) => Some(self.file.dir.join(&r.file)),
            (None, None) => None,
        }
    }

    /// A stepped run's end: the last step written if it was not, the linear solver
    /// summarised (`unknowns`: the whole problem's), the final state as the solution.
    fn stepped(
        &self,
        recorder: Recorder<'_, 'a>,
        outcome: transient::Outcome,
        unknowns: usize,
    ) -> Result<Solved, RunError> {
        let Recorder {
            output,
            history,
            mechanisms,
            species_flux,
            ..
        } = recorder;
        output.finish_steps(&outcome, &history)?;
        let mut linear_solver = self.stepped_solver_summary(&history, unknowns);
        if let Some((name, reason)) = crate::parallel::linear_solver() {
            (linear_solver.name, linear_solver.reason) = (name, reason);
        }
        let solution = steps::final_solution(
            outcome,
            &history,
            &self.physics.field_names,
            self.terms.energy_flux_count(),
        );
        Ok(Solved {
            solution,
            history,
            mechanisms,
            linear_solver,
            linear_steady: false,
            species_flux,
        })
    }

    /// The linear solver of a stepped run with `n` unknowns: AMG-CG when its steps were
    /// solved by CG (with the iterations per accepted step), else factorisations.
    fn stepped_solver_summary(&self, history: &[StepReport], n: usize) -> LinearSolverSummary {
        let auto = matches!(self.requested, None | Some("auto"));
        let threshold = self.threshold;
        // CG iterations per accepted step, when the steps were solved by AMG-CG.
        let per_step: Vec<usize> = history.iter().map(|r| r.cg_iterations).collect();
        let setups = history.iter().map(|r| r.hierarchy_setups).sum();
        let refreshes = history.iter().map(|r| r.hierarchy_refreshes).sum();
        let iterative = |name: &str, reason: String| LinearSolverSummary {
            name: name.into(),
            reason,
            iterations: per_step.iter().sum(),
            iterations_per_solve: per_step.clone(),
            hierarchy_setups: Some(setups),
            hierarchy_refreshes: Some(refreshes),
        };
        let requested = "requested by linear_solver";
        if per_step.iter().any(|&k| k > 0) && self.physics.materials.electric() {
            iterative(
                "GMRES",
                match auto {
                    true => format!(
                        "auto: {n:.1e} unknowns, unsymmetric coupled thermal–electrical Newton steps → GMRES preconditioned by AMG on the temperature and voltage blocks (hierarchies kept across steps while the matrix changes little)"
                    ),
                    false => {
                        format!("{requested} (unsymmetric coupled steps → GMRES with block AMG)")
                    }
                },
            )
        } else if history.iter().any(|r| r.gmres) {
            iterative(
                "GMRES",
                match auto {
                    true => format!(
                        "auto: {n:.1e} unknowns, a nonlinear law makes the Newton Jacobian unsymmetric → GMRES preconditioned by AMG (hierarchy kept across iterations and steps while the matrix changes little)"
                    ),
                    false => format!("{requested} (unsymmetric Jacobian → GMRES with AMG)"),
                },
            )
        } else if per_step.iter().any(|&k| k > 0) {
            iterative(
                "AMG-CG",
                match auto {
                    true => format!(
                        "auto: {n:.1e} unknowns, symmetric positive definite steps → AMG-CG (hierarchy kept across steps while the matrix changes little)"
                    ),
                    false => requested.into(),
                },
            )
        } else {
            LinearSolverSummary {
                name: "direct".into(),
                reason: if auto {
                    format!(
                        "auto: step systems below {threshold} unknowns or with multipliers are factored (Cholesky, LDLᵀ or LU by their kind)"
                    )
                } else {
                    requested.into()
                },
                iterations: 0,
                iterations_per_solve: Vec::new(),
                hierarchy_setups: None,
                hierarchy_refreshes: None,
            }
        }
    }
}

/// A linear problem at the start time, over a rank's mesh (see
/// [`TimeLoop::linear_problem`]).
struct LinearProblem<'m> {
    mesh: &'m crate::mesh::Mesh,
    materials: Vec<crate::heat::Material>,
    /// k, ρc and Q per block, as laws.
    laws: (Vec<Law>, Vec<Law>, Vec<Law>),
    block_source: Vec<Option<SourceFn<'m>>>,
    loads: Loads,
    interfaces: &'m dyn crate::heat::interfaces::Interfaces,
    iterative: bool,
    /// The whole problem's unknowns.
    unknowns: usize,
}

impl LinearProblem<'_> {
    fn problem<'s>(&'s self, p: &super::problem::Problem) -> SteadyProblem<'s> {
        SteadyProblem {
            mesh: self.mesh,
            materials: &self.materials,
            source: None,
            block_source: Some(&self.block_source),
            dirichlet: &self.loads.dirichlet,
            face_bcs: &self.loads.faces,
            contact: Vec::new(),
            ties: Vec::new(),
            interfaces: Some(self.interfaces),
            iterative: self.iterative,
            reproducible: p.solve.reproducible.unwrap_or(true),
            tolerance: p.solve.tolerance,
            max_iterations: p.solve.max_iterations,
        }
    }
}

/// What happens at each accepted step: progress shown, the state derived (its point
/// fluxes when its fields are written, its mechanism heats always), written when due,
/// checkpointed, and kept in the history.
struct Recorder<'o, 'a> {
    output: &'o mut Output<'a>,
    terms: &'a ContactTerms<'a>,
    progress: Option<&'a dyn Fn(&StepReport)>,
    history: Vec<StepReport>,
    mechanisms: Vec<Vec<Vec<f64>>>,
    species_flux: Vec<Vec<(f64, f64)>>,
}

impl Recorder<'_, '_> {
    fn record(&mut self, r: &StepReport, st: &State, dofs: &DofMap) -> Result<(), HeatError> {
        // The species interfaces' mass flux and the voltage ties' current apart from the
        // energy terms' heat; a tie releases no contact Joule heat.
        let mut r = r.clone();
        let [species, ties] = self.terms.split_fields(&mut r.heat);
        self.species_flux.push(species);
        let ties = ties.iter().map(|&(current, _)| ContactPower {
            current,
            joule: 0.0,
        });
        r.electric.extend(ties);
        let r = &r;
        if let Some(progress) = self.progress {
            progress(r);
        }
        let due = self.output.due(r.step);
        let derived = self
            .terms
            .derive(&st.u, dofs, st.time, due)
            .map_err(HeatError::Step)?;
        self.mechanisms.push(self.terms.term_mechanisms(&derived));
        if due {
            self.output
                .write_state(&st.u, dofs, st.step, st.time, Some(derived), &r.heat)
                .map_err(HeatError::Step)?;
        }
        self.output
            .checkpoint(st)
            .map_err(|e| HeatError::Step(e.to_string()))?;
        self.history.push(r.clone());
        Ok(())
    }
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
        Some(LinearMethod::AmgCg) if ties => format!(
            "{n:.1e} unknowns, dual mortar ties condensed to a symmetric positive definite system → AMG-CG"
        ),
        Some(LinearMethod::AmgCg) => {
            format!("{n:.1e} unknowns, symmetric positive definite → AMG-CG")
        }
        Some(LinearMethod::SaddleLdlt) => "multipliers make the system indefinite → LDLᵀ".into(),
        Some(LinearMethod::Gmres) => format!(
            "{n:.1e} unknowns, a temperature-dependent conductance makes the Jacobian unsymmetric → GMRES preconditioned by AMG"
        ),
        Some(LinearMethod::Lu) => {
            "a temperature-dependent conductance makes the Jacobian unsymmetric → LU".into()
        }
        Some(LinearMethod::Cholesky) if ties => format!(
            "{n} unknowns (< {threshold}), dual mortar ties condensed to a symmetric positive definite system → Cholesky"
        ),
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
        hierarchy_setups: linear.hierarchy_setups,
        hierarchy_refreshes: linear.hierarchy_setups.map(|_| linear.hierarchy_refreshes),
    }
}

/// An electrical contact's conductance model as the solver calls it: h_e at a point's
/// gap, temperatures and voltages, the contact pressure and the time.
fn electric_conductance(
    model: &dyn ConductanceModel,
    pressure: f64,
) -> impl Fn(&HInput, f64) -> Result<HValue, String> + '_ {
    move |i, time| {
        let state = PointState {
            gap: i.gap,
            pressure,
            temp_a: i.temp_a,
            temp_b: i.temp_b,
            x: i.x,
            time,
        };
        let (c, [dva, dvb]) = model
            .evaluate_with_voltage(&state, [i.volt_a, i.volt_b])
            .map_err(|e| format!("electrical contact conductance `{}`: {e}", model.name()))?;
        Ok(HValue {
            h: c.h,
            dh_dtemp_a: c.dh_dtemp_a,
            dh_dtemp_b: c.dh_dtemp_b,
            dh_dvolt_a: dva,
            dh_dvolt_b: dvb,
        })
    }
}

/// `values` per block of the physics' mesh, for the blocks of a mesh whose block `b`
/// copies block `origin[b]` (as is without `origin`).
pub(super) fn per_block<T: Clone>(values: &[T], origin: Option<&[usize]>) -> Vec<T> {
    match origin {
        Some(origin) => origin.iter().map(|&b| values[b].clone()).collect(),
        None => values.to_vec(),
    }
}
