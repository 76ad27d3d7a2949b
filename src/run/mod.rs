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
//!
//! A run is a short sequence of named steps, each a value handed to the next
//! (`run_until` reads as that sequence):
//!
//! 1. **problem** — the file read and checked (`problem`), its mesh read;
//! 2. **physics** — materials, conditions, sources, time controls on the mesh (`physics`);
//! 3. **scene** — the contact deck resolved on the mesh into a [`ContactScene`]
//!    (`contact`), the face conditions it masks, the steady problem checked posed
//!    (`posed`), and per interaction its toggle, fields and pressures (`Couplings`);
//!    `seam check` stops here;
//! 4. **time loop** — the contact terms over the scene (`terms`), solved by one linear
//!    steady solve or the general solver's steps (`solve`);
//! 5. **output** — the fields as they are accepted and the final files (`output`, with
//!    `steps` and `fields`), and the [`Summary`] (`summary`).
//!
//! [`ContactScene`]: crate::scene::ContactScene

pub mod bundled;
mod contact;
mod death;
mod electric_search;
mod fields;
mod motion;
mod nodal_field;
mod output;
mod physics;
mod posed;
mod problem;
mod ranks;
mod solve;
mod species;
mod steps;
mod summary;
mod terms;

use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::heat::steady::SteadySolution;
use crate::heat::transient::StepReport;
use crate::mesh::Mesh;

pub use output::NOT_CONVERGED;
pub use problem::{
    BcKind, BcSpec, ContactSpec, DeathSpec, DisplacementSpec, InitialSpec, MAX_MAGNITUDE,
    MAX_TEMPERATURE, MaterialSpec, MeshSpec, NodalFieldSpec, OutputSpec, Problem, RestartSpec,
    SolveSpec, SourceSpec, ToggleSpec, Value,
};
pub use summary::{
    InteractionHeat, LinearSolverSummary, SpeciesContact, Summary, Timing, TransientSummary,
    peak_memory_mib,
};
pub use terms::MotionCounts;

use contact::{Couplings, RunContact};
use death::Death;
use motion::Motion;
use output::Output;
use physics::Physics;
use problem::ProblemFile;
use solve::TimeLoop;
use terms::ContactTerms;

/// How a [`RunError::Solve`] message starts when a plugin failed at a point (an error
/// status, a value that is not finite or negative): the `seam` binary exits with 3 then.
pub const PLUGIN_FAULT: &str = "plugin fault";

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
    /// The nodal concentration of the final state (mol/m³; NaN at nodes without a
    /// species), for a run with a species.
    pub species: Option<Vec<f64>>,
    /// Per accepted step (one for a steady run), each species interface's mass flux
    /// (mol/s) leaving side A and side B, in the order of the summary's `species_contacts`.
    pub species_flux: Vec<Vec<(f64, f64)>>,
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

/// The run, up to `stop`: problem, physics, scene (the checks and set-up), then unless
/// stopped the time loop and the output.
fn run_until(path: &Path, options: &RunOptions, stop: Stop) -> Result<Outcome, RunError> {
    let start = Instant::now();
    crate::parallel::start_run();
    // Problem and physics: the file, its mesh, and what the file says on the mesh. Under
    // mpirun, rank 0 reads the mesh and, once the physics is checked on it, sends each
    // other rank its part or has it read the whole (`ranks`).
    let file = ProblemFile::read(path)?;
    let (mesh, mesh_s) = ranks::mesh_for_rank(&file, options)?;
    log::info!(
        "mesh read: {} nodes, {} elements, {} blocks ({mesh_s:.3} s)",
        mesh.num_nodes(),
        mesh.num_elems(),
        mesh.blocks.len()
    );
    let mut diags = Diagnostics::default();
    let mut physics = Physics::new(&file, &mesh, &mut diags);
    let ready = if diags.has_errors() {
        Err(RunError::Input(
            std::mem::take(&mut diags),
            file.text.sources(),
        ))
    } else {
        physics.try_start()
    };
    ranks::share_mesh(&file, &physics, ready.is_ok())?;
    if ranks::follows_root() {
        // Rank 0 checked the physics on the whole mesh.
        diags = Diagnostics::default();
    } else {
        ready?;
    }
    // Scene: the contact, the face conditions it masks, what the file joins to it.
    let contact = RunContact::build(&file, &mesh, &physics.field_names, options, &mut diags)?;
    contact.mask_face_conditions(&mut physics.face_sites, &mut diags);
    physics.resolve_species(&contact, &mut diags);
    let electrical = (contact
        .electrical
        .iter()
        .map(|e| (&e.side_a, &e.side_b, &e.at)))
    .chain((contact.voltage_ties.iter()).map(|t| (&t.pairing.side_a, &t.pairing.side_b, &t.at)));
    if let Some((a, b, at)) = electrical.into_iter().next()
        && !physics.materials.electric()
    {
        diags.push(
            Diagnostic::error(
                "E0431",
                format!("electrical contact {a} / {b}: no block of the problem carries a voltage"),
            )
            .at(Some(at.clone()))
            .help("give the blocks on both sides an electrical_conductivity (S/m) in their [[material]]"),
        );
    } else {
        let carries = |b: usize| physics.materials.sigma[b].is_some();
        let field = ("voltage", "E0431", "an electrical_conductivity (S/m)");
        species::check_sides(&mesh, &contact.voltage_ties, &carries, field, &mut diags);
    }
    if !file.transient && !ranks::follows_root() {
        posed::check_steady(&physics, &contact.pairings, &mut diags);
    }
    log::info!(
        "contact scene: {} interaction(s), {} electrical contact(s) (surfaces {:.3} s, search {:.3} s)",
        contact.pairings.len(),
        contact.electrical.len(),
        contact.surfaces_s,
        contact.search_s
    );
    let couplings = Couplings::resolve(&file, &physics, &contact, &mut diags);
    let motion = Motion::new(
        file.problem.displacement.as_ref(),
        &file.dir,
        &mesh,
        physics.time.start,
        &file.text,
        &mut diags,
    );
    let death = Death::new(
        &file.problem.death,
        &mesh,
        file.transient,
        &file.text,
        &mut diags,
    );
    if motion.is_some() || death.is_some() {
        motion::refuse_what_cannot_move(
            &file.text,
            &contact,
            &couplings,
            motion.is_some(),
            &mut diags,
        );
    }
    if ranks::stop(&mut diags) {
        return Err(match ranks::follows_root() {
            true => ranks::quiet(),
            false => RunError::Input(diags, contact.loaded.sources),
        });
    }
    let initial = physics.initial_state();
    if crate::parallel::root_verdict(initial.is_err()) {
        return Err(initial.err().unwrap_or_else(ranks::quiet));
    }
    let initial = initial?;
    if stop == Stop::BeforeSolve {
        return Ok(Outcome::Checked(Checked {
            diagnostics: diags,
            sources: contact.loaded.sources,
        }));
    }
    // Time loop: the contact terms over the scene, solved, each accepted step written.
    let terms = ContactTerms::new(
        &physics,
        &contact,
        &couplings,
        (motion.as_ref(), death.as_ref()),
    );
    let output = Output::open(&file, &physics, &terms);
    // Rank 0 alone makes the output folder; every rank stops if it could not.
    if crate::parallel::root_verdict(output.is_err()) {
        return Err(output.err().unwrap_or_else(ranks::quiet));
    }
    let mut output = output?;
    let solved = TimeLoop::new(&file, &physics, &terms, options).run(initial, &mut output)?;
    crate::parallel::report_holdings(&mesh);
    terms.report_quarantined(&mut diags);
    // Output: the final files and the summary.
    log::info!(
        "solved: {} unknowns, {} Newton iteration(s), linear solver {} ({} iterations)",
        solved.solution.dofs.len(),
        solved.solution.newton_iterations,
        solved.linear_solver.name,
        solved.linear_solver.iterations
    );
    let written = output.write_final(&solved)?;
    if let Some(w) = &written {
        log::info!("wrote {}", w.display());
    }
    summary::report_crosspoints(&mesh, &solved.solution, &mut diags);
    let timing = Timing::of(mesh_s, &contact, &solved.solution.timing, start);
    let mut summary = Summary::new(
        &terms,
        &solved,
        timing,
        written,
        file.transient,
        physics.time.start,
    );
    summary.axisymmetric = mesh.axisymmetric;
    summary.motion = terms.motion_counts();
    if let Some(m) = &summary.motion {
        log::info!(
            "moving contact: {} search(es), {} refit(s), {} new pattern(s), {} surface update(s)",
            m.searches,
            m.refits,
            m.repatterns,
            m.surface_updates
        );
    }
    output.mark_not_converged(summary.diagnosis.as_deref())?;
    let species = physics
        .species
        .nodal(&solved.solution.u, &solved.solution.dofs);
    // The conductance functions of the terms borrow the mesh, which the result takes.
    drop(terms);
    Ok(Outcome::Ran(Box::new(RunResult {
        summary,
        mesh,
        solution: solved.solution,
        history: solved.history,
        species,
        species_flux: solved.species_flux,
        warnings: diags,
        sources: contact.loaded.sources,
    })))
}
