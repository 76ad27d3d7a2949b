//! What a run writes, as it goes and at its end: the output folder (`[output] dir`), each
//! written state's fields (temperature, heat flux, contact faces) as a step of the
//! results, and at the end the final fields (`temperature.vtu`, `contact.vtu`,
//! `contact_points.vtu`), the histories (`steps.csv`, `interface_heat.csv`), the plots
//! and, for a run that did not converge, the [`NOT_CONVERGED`] mark. The file formats are
//! `steps`'s; the fields `fields`'s.

use std::path::{Path, PathBuf};

use crate::assembly::DofMap;
use crate::heat::electric::VOLTAGE;
use crate::heat::transient::{self, StepReport};
use crate::search::pairing::PointStatus;

use super::RunError;
use super::fields::{self, Derived};
use super::physics::Physics;
use super::problem::ProblemFile;
use super::solve::Solved;
use super::steps;
use super::terms::ContactTerms;

/// The file a run that did not converge leaves in its output folder, holding the
/// residual history and the likely cause.
/// A state's nodal voltage and current density per element (x, y, z interleaved).
type ElectricFields = (Vec<f64>, Vec<f64>);

pub const NOT_CONVERGED: &str = "NOT_CONVERGED";

/// The results of a run being written.
pub(super) struct Output<'a> {
    /// The output folder; `None` when the problem asks for no output.
    dir: Option<PathBuf>,
    writer: steps::StepWriter<'a>,
    physics: &'a Physics<'a>,
    terms: &'a ContactTerms<'a>,
    /// The global variables of `results.exo`: the heat leaving each side of every term.
    heat_names: Vec<String>,
}

impl<'a> Output<'a> {
    /// The output folder of `file`, made (and cleared of an earlier run's
    /// [`NOT_CONVERGED`] mark).
    pub(super) fn open(
        file: &ProblemFile,
        physics: &'a Physics<'a>,
        terms: &'a ContactTerms<'a>,
    ) -> Result<Self, RunError> {
        // Under MPI, rank 0 alone writes (every rank holds the whole solution).
        let dir = match &file.problem.output.dir {
            Some(d) if crate::parallel::is_root() => {
                let out_dir = file.dir.join(d);
                std::fs::create_dir_all(&out_dir).map_err(|e| {
                    RunError::Solve(format!("cannot create {}: {e}", out_dir.display()))
                })?;
                // A mark left by an earlier run that did not converge.
                let _ = std::fs::remove_file(out_dir.join(NOT_CONVERGED));
                Some(out_dir)
            }
            _ => None,
        };
        let writer = steps::StepWriter::new(
            dir.as_deref(),
            physics.mesh,
            &file.problem.output,
            file.transient,
        );
        let heat_names = steps::interface_heat_names(&terms.term_sides());
        Ok(Output {
            dir,
            writer,
            physics,
            terms,
            heat_names,
        })
    }

    /// Whether the fields of accepted step `step` are written.
    pub(super) fn due(&self, step: usize) -> bool {
        self.writer.due(step)
    }

    /// One state's fields as step `step` of the results (temperature, heat flux, contact
    /// faces), from its derived values when they were made with the faces.
    pub(super) fn write_state(
        &mut self,
        u: &[f64],
        dofs: &DofMap,
        step: usize,
        time: f64,
        derived: Option<Derived>,
        heat: &[(f64, f64)],
    ) -> Result<(), String> {
        let derived = match derived {
            Some(d) => d,
            None => self.terms.derive(u, dofs, time, true)?,
        };
        let t = steps::nodal_temperature(dofs, u, &self.physics.field_names);
        let q =
            fields::element_heat_flux(self.physics.mesh, &self.physics.materials.laws, &t, time)?;
        let contact = self.terms.contact_of(&derived);
        let electric = self.electric_fields(u, dofs, &t, time)?;
        let species = self.species_values(u, dofs);
        let fields = steps::StepFields {
            temperature: &t,
            heat_flux: &q,
            contact: contact.as_ref(),
            heat_names: &self.heat_names,
            heat,
            electric: electric.as_ref().map(|(v, j)| (v.as_slice(), j.as_slice())),
            species: species.as_deref(),
        };
        self.writer
            .write_step(step, time, &fields)
            .map_err(|e| format!("cannot write the results of step {step}: {e}"))
    }

    /// A thermal–electrical state's nodal voltage and current density per element
    /// (`None` for a run without a voltage).
    fn electric_fields(
        &self,
        u: &[f64],
        dofs: &DofMap,
        temperature: &[f64],
        time: f64,
    ) -> Result<Option<ElectricFields>, String> {
        let Some(v) = dofs.field(VOLTAGE) else {
            return Ok(None);
        };
        let voltage = dofs.nodal_values(v, u);
        let sigma = &self.physics.materials.sigma;
        let j =
            fields::element_current_density(self.physics.mesh, sigma, temperature, &voltage, time)?;
        Ok(Some((voltage, j)))
    }

    /// A state's nodal concentration, c = S ĉ from the solved ĉ ([`super::species`]);
    /// `None` for a run without a species.
    fn species_values(&self, u: &[f64], dofs: &DofMap) -> Option<Vec<f64>> {
        self.physics.species.nodal(u, dofs)
    }

    /// After an accepted step: its checkpoint, when one is due.
    pub(super) fn checkpoint(&self, state: &transient::State) -> std::io::Result<()> {
        self.writer.checkpoint(state)
    }

    /// The end of the steps: the last state written if it was not, `results.exo` closed
    /// and the final checkpoint.
    pub(super) fn finish_steps(
        &mut self,
        outcome: &transient::Outcome,
        history: &[StepReport],
    ) -> Result<(), RunError> {
        let last = &outcome.state;
        if self.dir.is_some() && !self.writer.written(last.step) {
            self.write_state(
                &last.u,
                &outcome.dofs,
                last.step,
                last.time,
                None,
                history.last().map_or(&[][..], |r| &r.heat),
            )
            .map_err(RunError::Solve)?;
        }
        self.writer
            .finish(last)
            .map_err(|e| RunError::Solve(e.to_string()))
    }

    /// The final state's files: the fields, the contact, the histories and the plots.
    /// Their main file (`temperature.vtu`), or `None` without an output folder.
    pub(super) fn write_final(&mut self, solved: &Solved) -> Result<Option<PathBuf>, RunError> {
        let Some(dir) = self.dir.clone() else {
            return Ok(None);
        };
        let (solution, history) = (&solved.solution, &solved.history);
        let final_time = history.last().map_or(self.physics.time.start, |r| r.time);
        let derived = self
            .terms
            .derive(&solution.u, &solution.dofs, final_time, true)
            .map_err(RunError::Solve)?;
        let file = self.write_final_fields(&dir, solved, &derived, final_time)?;
        self.write_histories(&dir, solved, &derived)
            .map_err(|e| io_error(&dir, e))?;
        Ok(Some(file))
    }

    /// The final fields in `dir`: `temperature.vtu` (returned), `contact.vtu`,
    /// `contact_points.vtu`, and a linear steady solve's step of `results.exo`.
    fn write_final_fields(
        &mut self,
        dir: &Path,
        solved: &Solved,
        derived: &Derived,
        final_time: f64,
    ) -> Result<PathBuf, RunError> {
        let (terms, physics, mesh) = (self.terms, self.physics, self.physics.mesh);
        let (pairings, views) = (&terms.contact.pairings, &terms.contact.views);
        let field_names = &physics.field_names;
        let io = |e: std::io::Error| io_error(dir, e);
        let solution = &solved.solution;
        let heat_flux = fields::element_heat_flux(
            mesh,
            &physics.materials.laws,
            &solution.temperature,
            final_time,
        )
        .map_err(RunError::Solve)?;
        let contact = terms.contact_of(derived);
        let steady_heat: Vec<(f64, f64)> = solution
            .heat
            .iter()
            .chain(&solution.tie_heat)
            .copied()
            .collect();
        let electric = self
            .electric_fields(
                &solution.u,
                &solution.dofs,
                &solution.temperature,
                final_time,
            )
            .map_err(RunError::Solve)?;
        let species = self.species_values(&solution.u, &solution.dofs);
        let state = steps::StepFields {
            temperature: &solution.temperature,
            heat_flux: &heat_flux,
            contact: contact.as_ref(),
            heat_names: &self.heat_names,
            heat: &steady_heat,
            electric: electric.as_ref().map(|(v, j)| (v.as_slice(), j.as_slice())),
            species: species.as_deref(),
        };
        let file = dir.join("temperature.vtu");
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
        steps::write_temperature_vtu(&file, mesh, &state, &extra, &self.physics.problem.output)
            .map_err(|e| RunError::Solve(format!("cannot write {}: {e}", file.display())))?;
        if let Some(c) = &contact {
            steps::write_contact_vtu(&dir.join("contact.vtu"), mesh, &solution.temperature, c)
                .map_err(io)?;
        }
        let points: Vec<fields::PointsOf<'_>> = pairings
            .iter()
            .enumerate()
            .filter(|(k, _)| views[*k].points)
            .map(|(k, p)| (k as u32 + 1, p, derived.fluxes[k].as_deref()))
            .collect();
        if !points.is_empty() {
            steps::write_contact_points_vtu(&dir.join("contact_points.vtu"), &points)
                .map_err(io)?;
        }
        if solved.linear_steady {
            self.writer
                .write_step(0, physics.time.start, &state)
                .map_err(io)?;
            self.writer.close().map_err(io)?;
        }
        Ok(file)
    }

    /// The histories in `dir` (`steps.csv` of a stepped run, `interface_heat.csv`) and
    /// the plots.
    fn write_histories(
        &self,
        dir: &Path,
        solved: &Solved,
        derived: &Derived,
    ) -> std::io::Result<()> {
        let terms = self.terms;
        let (solution, history) = (&solved.solution, &solved.history);
        let labels = terms.term_labels();
        let names = terms.term_mechanism_names();
        if !history.is_empty() {
            steps::write_steps(dir, history)?;
            let contacts = terms.electrical_labels();
            if !contacts.is_empty() {
                steps::write_electrical_contacts(dir, history, &contacts)?;
            }
            if !terms.contact.species.is_empty() {
                let labels = super::species::labels(&terms.contact.species);
                steps::write_species_contacts(dir, history, &solved.species_flux, &labels)?;
            }
            let rows: Vec<steps::HeatRow<'_>> = history
                .iter()
                .zip(&solved.mechanisms)
                .map(|(r, m)| steps::HeatRow {
                    step: r.step,
                    time: r.time,
                    heat: &r.heat,
                    mechanisms: m,
                })
                .collect();
            steps::write_interface_heat(dir, &rows, &labels, &names)?;
        } else if !labels.is_empty() {
            // A linear steady solve: one row per interaction, as step 0.
            let heat: Vec<(f64, f64)> = solution
                .heat
                .iter()
                .chain(&solution.tie_heat)
                .copied()
                .collect();
            let mechanisms = terms.term_mechanisms(derived);
            let row = steps::HeatRow {
                step: 0,
                time: self.physics.time.start,
                heat: &heat,
                mechanisms: &mechanisms,
            };
            steps::write_interface_heat(dir, &[row], &labels, &names)?;
        }
        // The plotted line: through the first matched point of the first
        // interaction, along its side-A normal.
        let line = terms.contact.pairings.iter().find_map(|p| {
            p.result
                .points
                .iter()
                .find(|q| q.status == PointStatus::Matched)
                .map(|q| (q.x, q.normal_a))
        });
        steps::write_plots(
            dir,
            self.physics.mesh,
            &solution.temperature,
            history,
            &labels,
            line,
        )?;
        Ok(())
    }

    /// A result that did not converge says so next to its files.
    pub(super) fn mark_not_converged(&self, diagnosis: Option<&str>) -> Result<(), RunError> {
        if let (Some(dir), Some(d)) = (&self.dir, diagnosis) {
            std::fs::write(dir.join(NOT_CONVERGED), format!("{d}\n")).map_err(|e| {
                RunError::Solve(format!(
                    "cannot write {}: {e}",
                    dir.join(NOT_CONVERGED).display()
                ))
            })?;
        }
        Ok(())
    }
}

/// An error writing the results in `dir`.
fn io_error(dir: &Path, e: std::io::Error) -> RunError {
    RunError::Solve(format!(
        "cannot write the results in {}: {e}",
        dir.display()
    ))
}
