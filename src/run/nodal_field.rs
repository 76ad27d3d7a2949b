//! `[[nodal_field]]`s: named nodal fields of a run (a contact pressure for `Contact
//! Pressure Variable`), given by a value or read from a nodal variable of an Exodus II
//! file on the run's mesh.

use std::path::Path;

use crate::diag::{Diagnostic, Diagnostics};
use crate::mesh::Mesh;

use super::problem::{NodalFieldSpec, Problem, ProblemText};

/// Each `[[nodal_field]]` has a `value` or a `file`, and the file's `variable`, `time`
/// and `step` only with a file.
pub(super) fn check_nodal_fields(p: &Problem, at: &ProblemText, diags: &mut Diagnostics) {
    for (k, f) in p.nodal_field.iter().enumerate() {
        let by_file = f.variable.is_some() || f.time.is_some() || f.step.is_some();
        let wrong = match (&f.value, &f.file) {
            (Some(_), Some(_)) => Some("has both `value` and `file`"),
            (None, None) => Some("needs a `value` or a `file`"),
            (Some(_), None) if by_file => Some("has `variable`, `time` or `step` without `file`"),
            _ if f.time.is_some() && f.step.is_some() => Some("has both `time` and `step`"),
            _ => None,
        };
        if let Some(m) = wrong {
            diags.push(
                Diagnostic::error("E0712", format!("[[nodal_field]] {}: {m}", f.name))
                    .at(at.loc("nodal_field", k, ""))
                    .help("value = a number or a Lua expression; or file = \"f.exo\", variable = \"v\" and time = t or step = n (default the last step)"),
            );
        }
    }
}

/// A `[[nodal_field]]` read from a nodal variable of an Exodus II file, one value per
/// mesh node, at `step` (1 = the first stored), at `time` (a stored time, or linearly
/// interpolated between the two around it), or at the last step. The file's nodes are matched to the mesh's by their node numbers and must sit
/// where the mesh's do (to 1e-6 of the mesh's size, so coordinates stored in single
/// precision pass and another mesh with as many nodes does not). Errors: message, help.
pub(super) fn read_nodal_field(
    f: &NodalFieldSpec,
    file: &Path,
    mesh: &Mesh,
) -> Result<Vec<f64>, (String, String)> {
    use crate::mesh::{MeshError, exodus};
    let split = |e: MeshError| match e {
        MeshError::Format {
            path,
            message,
            help,
        } => (format!("{}: {message}", path.display()), help),
        MeshError::Open { path, source } => (
            format!("cannot open {}: {source}", path.display()),
            "the file is relative to the problem file".into(),
        ),
        other => (other.to_string(), "check the file".into()),
    };
    let name = f.variable.as_deref().unwrap_or(&f.name);
    let shown = file.display();
    let times = exodus::read_times(file).map_err(split)?;
    let n = times.len();
    // The stored steps to read and the weight of the second: a stored time or step is
    // read as it is; a time between two stored times is interpolated linearly.
    let (first, second, w) = match (f.step, f.time) {
        _ if n == 0 => {
            return Err((
                format!("{shown} holds no time steps, so no values of `{name}`"),
                "write the field as a nodal variable with at least one step".into(),
            ));
        }
        (Some(s), _) if s == 0 || s > n => {
            return Err((
                format!(
                    "{shown}: step {s} asked for, but the file holds {n} step(s), numbered from 1"
                ),
                format!("give step = 1 … {n}, or leave it out for the last"),
            ));
        }
        (Some(s), _) => (s - 1, s - 1, 0.0),
        (None, Some(t)) => {
            let scale = times.iter().fold(t.abs(), |m, v| m.max(v.abs()));
            let nearest = (0..n)
                .min_by(|&a, &b| (times[a] - t).abs().total_cmp(&(times[b] - t).abs()))
                .expect("n > 0");
            let increasing = times.windows(2).all(|w| w[1] > w[0]);
            if (times[nearest] - t).abs() <= 1e-9 * scale {
                (nearest, nearest, 0.0)
            } else if increasing && times[0] < t && t < times[n - 1] {
                let i = times.partition_point(|&v| v <= t) - 1;
                (i, i + 1, (t - times[i]) / (times[i + 1] - times[i]))
            } else {
                return Err((
                    format!(
                        "{shown}: time {t} for `{name}` is outside the stored times (or they do not increase): {n} step(s) from t = {} to {}; the nearest is t = {} (step {})",
                        times[0],
                        times[n - 1],
                        times[nearest],
                        nearest + 1
                    ),
                    "give a time within the stored ones (between two, the field is interpolated linearly), or the step as step = n".into(),
                ));
            }
        }
        (None, None) => (n - 1, n - 1, 0.0),
    };
    let mut values = exodus::read_nodal_variable(file, name, first).map_err(split)?;
    if second != first {
        let next = exodus::read_nodal_variable(file, name, second).map_err(split)?;
        values
            .iter_mut()
            .zip(&next)
            .for_each(|(v, u)| *v = (1.0 - w) * *v + w * u);
    }
    let source = exodus::read(file).map_err(split)?;
    let help = "write the field on the run's mesh: the same nodes, paired by the node number map";
    if source.num_nodes() != mesh.num_nodes() {
        return Err((
            format!(
                "{shown}: `{name}` has values at {} nodes, but the mesh has {} nodes",
                source.num_nodes(),
                mesh.num_nodes()
            ),
            help.into(),
        ));
    }
    let by_number: std::collections::HashMap<i64, usize> = (source.node_numbers.iter())
        .enumerate()
        .map(|(j, &number)| (number, j))
        .collect();
    let (lo, hi) = mesh.coords.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(lo, hi), x| {
            (
                std::array::from_fn(|d| lo[d].min(x[d])),
                std::array::from_fn(|d| hi[d].max(x[d])),
            )
        },
    );
    let size = (0..3).map(|d| (hi[d] - lo[d]).powi(2)).sum::<f64>().sqrt();
    let mut out = Vec::with_capacity(mesh.num_nodes());
    for (x, &number) in mesh.coords.iter().zip(&mesh.node_numbers) {
        let Some(&j) = by_number.get(&number) else {
            return Err((
                format!("{shown}: node {number} of the mesh is not in the file's node number map"),
                help.into(),
            ));
        };
        let y = source.coords[j];
        let d = (0..3).map(|k| (x[k] - y[k]).powi(2)).sum::<f64>().sqrt();
        if d > 1e-6 * size {
            return Err((
                format!(
                    "{shown}: node {number} is at ({}, {}, {}) there but at ({}, {}, {}) in the mesh",
                    y[0], y[1], y[2], x[0], x[1], x[2]
                ),
                help.into(),
            ));
        }
        if !values[j].is_finite() {
            return Err((
                format!("{shown}: `{name}` is {} at node {number}", values[j]),
                "the field must be finite at every node".into(),
            ));
        }
        out.push(values[j]);
    }
    Ok(out)
}
