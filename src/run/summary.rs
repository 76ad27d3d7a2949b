//! The summary of a run (`seam run --json` prints it; its keys are an interface): the
//! unknowns, Newton iterations and convergence, each interaction's heat, the timings,
//! the linear solver and, for transient runs, the steps. Also the warnings a solve leaves
//! for the summary's reader (crosspoints without multipliers).

use std::path::PathBuf;
use std::time::Instant;

use serde::Serialize;

use crate::diag::{Diagnostic, Diagnostics};
use crate::heat::steady::{SolveTiming, SteadySolution};
use crate::mesh::Mesh;

use super::contact::RunContact;
use super::solve::Solved;
use super::terms::ContactTerms;

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

/// One electrical contact's line in the summary (`Enforcement for Voltage`).
#[derive(Clone, Debug, Serialize)]
pub struct ElectricalContact {
    pub side_a: String,
    pub side_b: String,
    /// The current from side A to side B through the contact (A).
    pub current: f64,
    /// The Joule heat released at the contact, h_e (V_A − V_B − ΔV)² over its area (W).
    pub joule_heat: f64,
}

/// One species interface's line in the summary (`Enforcement for Species`).
#[derive(Clone, Debug, Serialize)]
pub struct SpeciesContact {
    pub side_a: String,
    pub side_b: String,
    pub model: String,
    /// The mass flux leaving side A through the interface (mol/s).
    pub flux_side_a: f64,
    /// The mass flux leaving side B (mol/s): −`flux_side_a` to round-off.
    pub flux_side_b: f64,
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
    /// Thermal–electrical runs: each electrical contact's current and Joule heat at the
    /// end.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub electrical_contacts: Vec<ElectricalContact>,
    /// Runs with a species: each species interface's mass flux at the end.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub species_contacts: Vec<SpeciesContact>,
    /// An axisymmetric run (`[mesh] axisymmetric`): its heats are per full revolution.
    /// Written to the JSON only when true.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub axisymmetric: bool,
    /// A run whose contact surfaces move (`[displacement]`): its searches and refits.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motion: Option<super::terms::MotionCounts>,
}

/// The linear solver of a run, the reason it was chosen, and its CG iterations.
#[derive(Clone, Debug, Serialize)]
pub struct LinearSolverSummary {
    /// `Cholesky`, `LDLᵀ`, `LU`, `AMG-CG`, `GMRES`, or `direct` (transient and nonlinear runs,
    /// which factor each step's system with the solver its kind needs).
    pub name: String,
    /// Why: `requested by linear_solver`, or `auto: …` with the size and kind.
    pub reason: String,
    /// CG iterations in total (0 for factorisations).
    pub iterations: usize,
    /// CG iterations of each solve.
    pub iterations_per_solve: Vec<usize>,
    /// Iterative runs: AMG hierarchies set up, and kept hierarchies whose finest level
    /// took a new matrix's values instead (time steps, Newton iterations); under MPI,
    /// matrices solved on a BoomerAMG hierarchy PETSc kept whole from an earlier one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hierarchy_setups: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub hierarchy_refreshes: Option<usize>,
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

impl Timing {
    /// The phases' times: reading the mesh (`mesh_s`), the scene's, the solve's, and the
    /// whole run since `start`.
    pub(super) fn of(
        mesh_s: f64,
        contact: &RunContact,
        solve: &SolveTiming,
        start: Instant,
    ) -> Self {
        Timing {
            mesh_s,
            surfaces_s: contact.surfaces_s,
            search_s: contact.search_s,
            assembly_s: solve.assembly_s,
            factor_s: solve.factor_s,
            solve_s: solve.solve_s,
            total_s: start.elapsed().as_secs_f64(),
        }
    }
}

impl Summary {
    /// The summary of a solved run whose main output file is `output`.
    pub(super) fn new(
        terms: &ContactTerms<'_>,
        solved: &Solved,
        timing: Timing,
        output: Option<PathBuf>,
        transient: bool,
        start_time: f64,
    ) -> Self {
        let (solution, history) = (&solved.solution, &solved.history);
        let (pairings, choices) = (&terms.contact.pairings, &terms.contact.choices);
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
        let transient_summary = transient.then(|| TransientSummary {
            steps: history.len(),
            rejected_steps: history.iter().map(|r| r.rejected).sum(),
            end_time: history.last().map_or(start_time, |r| r.time),
        });
        Summary {
            dofs: solution.dofs.len(),
            newton_iterations: solution.newton_iterations,
            converged: solution.converged,
            interactions,
            timing,
            output,
            transient: transient_summary,
            peak_memory_mib: peak_memory_mib(),
            diagnosis: history.last().and_then(|r| r.diagnosis.clone()),
            linear_solver: solved.linear_solver.clone(),
            electrical_contacts: electrical_contacts(terms, history.last()),
            species_contacts: super::species::labels(&terms.contact.species)
                .into_iter()
                .zip(solved.species_flux.last().map_or(&[][..], Vec::as_slice))
                .map(|((side_a, side_b, model), &(a, b))| SpeciesContact {
                    side_a,
                    side_b,
                    model,
                    flux_side_a: a,
                    flux_side_b: b,
                    imbalance: a + b,
                })
                .collect(),
            axisymmetric: false,
            motion: None,
        }
    }
}

/// A warning per tie whose side-A nodes were already constrained (Dirichlet data or an
/// earlier tie) and got no multiplier.
pub(super) fn report_crosspoints(mesh: &Mesh, solution: &SteadySolution, diags: &mut Diagnostics) {
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
}

/// The electrical contacts of `terms` with their current and Joule heat in `last`.
pub(super) fn electrical_contacts(
    terms: &ContactTerms<'_>,
    last: Option<&crate::heat::transient::StepReport>,
) -> Vec<ElectricalContact> {
    let power = last.map_or(&[][..], |r| r.electric.as_slice());
    terms
        .electrical_labels()
        .into_iter()
        .zip(power)
        .map(|((side_a, side_b), p)| ElectricalContact {
            side_a: side_a.to_string(),
            side_b: side_b.to_string(),
            current: p.current,
            joule_heat: p.joule,
        })
        .collect()
}
