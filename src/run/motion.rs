//! `[displacement]`: a nodal displacement field u(X, t) that moves a run's contact
//! surfaces in time — Lua expressions of the node's place X as read and t, or the nodal
//! variables of a structural result (`DISPLX`, `DISPLY`, `DISPLZ`) read at its stored
//! times and interpolated linearly between them.
//!
//! The contact geometry follows the nodes at X + u(X, t): gaps, projections and
//! overlaps, so the conductances that depend on the gap follow too. `Update Search
//! Every n Steps` says when the pairing is searched anew; on the steps between, the
//! pairing is kept and the points are placed again on the moved faces (a refit).
//! Conduction stays on the mesh as read (the strains of a structural result are small
//! against a conduction path; its gaps are not small against themselves).

use std::path::Path;

use crate::diag::{Diagnostic, Diagnostics};
use crate::mesh::Mesh;

use super::contact::{Couplings, RunContact};
use super::nodal_field::read_nodal_field;
use super::physics::{SharedSandbox, evaluate};
use super::problem::{DisplacementSpec, NodalFieldSpec, ProblemText, Value};

/// Where the displacement comes from.
enum Source {
    /// One value per coordinate, at each node.
    Values(Vec<Value>),
    /// The stored times and, per stored time, per coordinate, one value per node.
    Stored {
        times: Vec<f64>,
        values: Vec<Vec<Vec<f64>>>,
    },
}

/// The displacement of a run's nodes, checked.
pub(super) struct Motion {
    source: Source,
    /// The nodes as read.
    reference: Vec<[f64; 3]>,
    sandbox: SharedSandbox,
}

/// The Exodus variables of a displacement by default, per coordinate.
const DEFAULT_VARIABLES: [&str; 3] = ["DISPLX", "DISPLY", "DISPLZ"];

impl Motion {
    /// The `[displacement]` of the problem on `mesh` (`dir` the problem file's folder),
    /// or `None` without one; errors go into `diags` at their line.
    pub(super) fn new(
        spec: Option<&DisplacementSpec>,
        dir: &Path,
        mesh: &Mesh,
        start: f64,
        text: &ProblemText,
        diags: &mut Diagnostics,
    ) -> Option<Motion> {
        let spec = spec?;
        let dim = mesh.dim.clamp(2, 3);
        let mut error = |key: &str, message: String, help: &str| {
            diags.push(
                Diagnostic::error("E0730", format!("[displacement]: {message}"))
                    .at(text.loc_in_table("displacement", key))
                    .help(help.to_string()),
            );
        };
        let source = match (&spec.value, &spec.file) {
            (Some(_), Some(_)) | (None, None) => {
                error(
                    "",
                    "give either `value` or `file`".into(),
                    "value = [\"ux\", \"uy\", \"uz\"] (numbers or Lua expressions of x, y, z, t, in m), or file = \"result.exo\" with its nodal variables",
                );
                return None;
            }
            (Some(_), None) if spec.variables.is_some() => {
                error(
                    "variables",
                    "`variables` names the nodal variables of a `file`, and there is none".into(),
                    "remove `variables`, or give the Exodus result as file = \"…\"",
                );
                return None;
            }
            (Some(values), None) => {
                if values.len() != dim {
                    error(
                        "value",
                        format!(
                            "{} value(s) for a {dim}-D mesh, whose nodes move in {dim} coordinates",
                            values.len()
                        ),
                        "give one value per coordinate: [ux, uy] in 2-D, [ux, uy, uz] in 3-D",
                    );
                    return None;
                }
                Source::Values(values.clone())
            }
            (None, Some(file)) => {
                let names: Vec<String> = match &spec.variables {
                    Some(v) => v.clone(),
                    None => DEFAULT_VARIABLES[..dim]
                        .iter()
                        .map(|s| s.to_string())
                        .collect(),
                };
                if names.len() != dim {
                    error(
                        "variables",
                        format!("{} variable(s) for a {dim}-D mesh", names.len()),
                        "name one nodal variable per coordinate, e.g. [\"DISPLX\", \"DISPLY\", \"DISPLZ\"]",
                    );
                    return None;
                }
                match stored(&dir.join(file), &names, mesh) {
                    Ok(s) => s,
                    Err((message, help)) => {
                        error("file", message, &help);
                        return None;
                    }
                }
            }
        };
        let motion = Motion {
            source,
            reference: mesh.coords.clone(),
            sandbox: SharedSandbox::default(),
        };
        // Every expression is tried once, where the run starts, so a bad one stops the
        // run before it solves.
        if let Err(e) = motion.coords_at(start) {
            error(
                "value",
                e,
                "check the expressions: numbers or Lua of x, y, z, t",
            );
            return None;
        }
        Some(motion)
    }

    /// The nodes' places at time `t`: as read, displaced.
    pub(super) fn coords_at(&self, t: f64) -> Result<Vec<[f64; 3]>, String> {
        let mut out = self.reference.clone();
        match &self.source {
            Source::Values(values) => {
                for (x, moved) in self.reference.iter().zip(&mut out) {
                    for (d, v) in values.iter().enumerate() {
                        let u = evaluate(v, *x, t, &self.sandbox, "displacement")?;
                        if !u.is_finite() {
                            return Err(format!(
                                "the displacement's component {} is {u} at ({}, {}, {}), t = {t}",
                                d + 1,
                                x[0],
                                x[1],
                                x[2]
                            ));
                        }
                        moved[d] += u;
                    }
                }
            }
            Source::Stored { times, values } => {
                let n = times.len();
                let (i, j, w) = if t <= times[0] {
                    (0, 0, 0.0)
                } else if t >= times[n - 1] {
                    (n - 1, n - 1, 0.0)
                } else {
                    let i = times.partition_point(|&v| v <= t) - 1;
                    (i, i + 1, (t - times[i]) / (times[i + 1] - times[i]))
                };
                for (d, (a, b)) in values[i].iter().zip(&values[j]).enumerate() {
                    for (k, moved) in out.iter_mut().enumerate() {
                        moved[d] += (1.0 - w) * a[k] + w * b[k];
                    }
                }
            }
        }
        Ok(out)
    }
}

/// Every stored step of the displacement variables `names` of the Exodus file `file` on
/// `mesh`.
fn stored(file: &Path, names: &[String], mesh: &Mesh) -> Result<Source, (String, String)> {
    let shown = file.display();
    let times = crate::mesh::exodus::read_times(file).map_err(|e| {
        (
            format!("{shown}: {e}"),
            "give an Exodus II result on the run's mesh".to_string(),
        )
    })?;
    if times.is_empty() {
        return Err((
            format!("{shown} holds no time steps"),
            "write the displacement as nodal variables with at least one step".into(),
        ));
    }
    if times.windows(2).any(|w| w[1] <= w[0]) {
        return Err((
            format!("{shown}: its stored times do not increase"),
            "give a result whose steps are in time order".into(),
        ));
    }
    let mut values = Vec::with_capacity(times.len());
    for step in 1..=times.len() {
        let mut per_coordinate = Vec::with_capacity(names.len());
        for name in names {
            let spec = NodalFieldSpec {
                name: name.clone(),
                value: None,
                file: Some(file.to_path_buf()),
                variable: Some(name.clone()),
                time: None,
                step: Some(step),
            };
            per_coordinate.push(read_nodal_field(&spec, file, mesh)?);
        }
        values.push(per_coordinate);
    }
    Ok(Source::Stored { times, values })
}

/// What seam does not move yet, refused at the `[displacement]` (or the `[[death]]`):
/// multiplier ties (their rows are made once), periodic pairs of the species, voltage
/// and electrical contacts, and contact pressures given per point from a
/// `[[nodal_field]]` (a search makes new points).
pub(super) fn refuse_what_cannot_move(
    text: &ProblemText,
    contact: &RunContact,
    couplings: &Couplings,
    displaced: bool,
    diags: &mut Diagnostics,
) {
    // The surfaces move under a [displacement], or element death makes them again.
    let (why, cause, at) = if displaced {
        (
            "[displacement] moves the contact surfaces",
            "the [displacement]",
            text.loc_in_table("displacement", ""),
        )
    } else {
        (
            "[[death]] makes the contact surfaces again",
            "the [[death]]",
            text.loc("death", 0, "time"),
        )
    };
    let mut refuse = |what: String, help: &str| {
        diags.push(
            Diagnostic::error("E0731", format!("{why}, but {what}"))
                .at(at.clone())
                .help(help.replace("the [displacement]", cause)),
        );
    };
    for (k, (choice, _, _)) in contact.choices.iter().enumerate() {
        let p = &contact.pairings[k];
        if choice.mortar {
            refuse(
                format!(
                    "interaction {} / {} is a tie with Lagrange multipliers ({}), whose rows are made once for the run",
                    p.side_a, p.side_b, choice.name
                ),
                "tie moving surfaces with Nitsche (`Tied_Temperature`, the default tie), or remove the [displacement]",
            );
        }
        if couplings.pressures[k].is_some() {
            refuse(
                format!(
                    "interaction {} / {} takes its contact pressure per point from a [[nodal_field]], whose points a search replaces",
                    p.side_a, p.side_b
                ),
                "give the pressure as a number in the enforcement (`Contact Surface Pressure`), or remove the [displacement]",
            );
        }
    }
    // Electrical contacts move as the Energy interactions do, except periodic ones.
    if let Some(e) = contact.electrical.iter().find(|e| e.pairing.periodic) {
        refuse(
            format!(
                "electrical contact {} / {} is a periodic pair",
                e.side_a, e.side_b
            ),
            "periodic electrical contacts do not move yet: remove the [displacement]",
        );
    }
    // Species interfaces and voltage ties move as the Energy interactions do, except
    // multiplier ties and periodic pairs.
    let fields = (contact.species.iter().map(|s| ("species interface", s)))
        .chain(contact.voltage_ties.iter().map(|t| ("voltage tie", t)));
    for (what, f) in fields {
        let p = &f.pairing;
        if f.choice.mortar {
            refuse(
                format!(
                    "{what} {} / {} is a tie with Lagrange multipliers ({}), whose rows are made once for the run",
                    p.side_a, p.side_b, f.choice.name
                ),
                "tie moving surfaces with Nitsche (`Tied_Species`, `Tied_Voltage`), or remove the [displacement]",
            );
        } else if p.periodic {
            refuse(
                format!("{what} {} / {} is a periodic pair", p.side_a, p.side_b),
                "periodic species and voltage interfaces do not move yet: remove the [displacement]",
            );
        }
    }
}
