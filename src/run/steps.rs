//! What a run writes: the fields every few steps (`.vtu` and `.pvd` series of the
//! temperature and the contact faces, `results.exo`), checkpoints, and the histories
//! (`steps.csv`, `interface_heat.csv`).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::assembly::DofMap;
use crate::heat::steady::{LinearSolves, SolveTiming, SteadySolution};
use crate::heat::transient::{Outcome, State, StepReport};
use crate::mesh::Mesh;
use crate::output::exodus::ExodusWriter;
use crate::output::plot::{Plot, Series};
use crate::output::vtu::{Array, PvdSeries, VtuEncoding, write_vtu_arrays, write_vtu_polygons};

use super::fields::{ContactFace, ContactFields, PointsOf};
use super::{OutputSpec, RunError};
use crate::search::pairing::PointStatus;

/// Nodal temperature over every field (each node carries one field).
pub(super) fn nodal_temperature(dofs: &DofMap, u: &[f64], fields: &[String]) -> Vec<f64> {
    let mut out: Option<Vec<f64>> = None;
    for f in fields {
        let Some(id) = dofs.field(f) else { continue };
        let v = dofs.nodal_values(id, u);
        match &mut out {
            None => out = Some(v),
            Some(o) => o
                .iter_mut()
                .zip(v)
                .filter(|(a, _)| a.is_nan())
                .for_each(|(a, b)| *a = b),
        }
    }
    out.unwrap_or_default()
}

/// What the results files of one written state hold.
pub(super) struct StepFields<'a> {
    /// Nodal temperature (NaN on nodes without one).
    pub temperature: &'a [f64],
    /// −k∇T per element, x, y, z interleaved (NaN where there is no temperature).
    pub heat_flux: &'a [f64],
    /// The contact faces, when some interaction visualises contact.
    pub contact: Option<&'a ContactFields>,
    /// The global variables of `results.exo`, from [`interface_heat_names`].
    pub heat_names: &'a [String],
    /// Per term (contact terms, then ties): the heat leaving side A and side B; empty
    /// when the state has none (its globals are then written as NaN).
    pub heat: &'a [(f64, f64)],
    /// A thermal–electrical run's nodal voltage and −σ∇V per element (x, y, z
    /// interleaved; NaN where there is none).
    pub electric: Option<(&'a [f64], &'a [f64])>,
    /// A run with a species: its nodal concentration (mol/m³; NaN where there is none).
    pub species: Option<&'a [f64]>,
}

/// The names of the global variables of `results.exo`: per term (side A, side B
/// surface names), `heat_side_a:A/B` and `heat_side_b:A/B`, the columns of
/// `interface_heat.csv`; a pair that occurs again gets `:k` (its 1-based term) appended.
pub(super) fn interface_heat_names(terms: &[(&str, &str)]) -> Vec<String> {
    let mut out: Vec<String> = Vec::with_capacity(2 * terms.len());
    for (k, (a, b)) in terms.iter().enumerate() {
        let again = terms[..k].contains(&(*a, *b));
        for side in ["a", "b"] {
            let mut name = format!("heat_side_{side}:{a}/{b}");
            if again {
                name.push_str(&format!(":{}", k + 1));
            }
            out.push(name);
        }
    }
    out
}

/// Writes a run's steps into the output directory.
pub(super) struct StepWriter<'m> {
    dir: Option<PathBuf>,
    mesh: &'m Mesh,
    every: usize,
    checkpoint_every: Option<usize>,
    transient: bool,
    /// The `.pvd` of the fields written.
    series: Option<PvdSeries>,
    /// The `.pvd` of the contact faces written.
    contact_series: Option<PvdSeries>,
    /// `results.exo`: every step written, for ParaView and Sierra users.
    exodus: Option<ExodusWriter>,
    last_written: Option<usize>,
    /// The `[output]` table (the `.vtu` format).
    spec: OutputSpec,
}

/// The element variables of `results.exo`: the heat flux's components, x and y only in
/// a 2-D mesh (ParaView's Exodus reader joins them into the vector `heat_flux`).
const HEAT_FLUX: [&str; 3] = ["heat_flux_x", "heat_flux_y", "heat_flux_z"];
/// The element variables of the current density in `results.exo` (x and y in 2-D).
const CURRENT_DENSITY: [&str; 3] = [
    "current_density_x",
    "current_density_y",
    "current_density_z",
];
/// The nodal contact variables of `results.exo` (with contact output).
const CONTACT_NODAL: [&str; 3] = ["contact_gap", "contact_fraction", "interface_flux"];

impl<'m> StepWriter<'m> {
    pub(super) fn new(
        dir: Option<&Path>,
        mesh: &'m Mesh,
        spec: &OutputSpec,
        transient: bool,
    ) -> Self {
        StepWriter {
            dir: dir.map(Path::to_path_buf),
            mesh,
            every: spec.every.unwrap_or(1).max(1),
            checkpoint_every: spec.checkpoint_every.filter(|&n| n > 0),
            transient,
            series: None,
            contact_series: None,
            exodus: None,
            last_written: None,
            spec: spec.clone(),
        }
    }

    /// Whether accepted step `step` of a transient run writes its fields.
    pub(super) fn due(&self, step: usize) -> bool {
        self.transient && self.dir.is_some() && step.is_multiple_of(self.every)
    }

    /// Whether step `step` has been written.
    pub(super) fn written(&self, step: usize) -> bool {
        self.last_written == Some(step)
    }

    /// After an accepted step of a transient run: its checkpoint, when one is due.
    pub(super) fn checkpoint(&self, state: &State) -> std::io::Result<()> {
        if !self.transient {
            return Ok(());
        }
        if let (Some(n), Some(dir)) = (self.checkpoint_every, &self.dir)
            && state.step.is_multiple_of(n)
        {
            write_checkpoint(
                &dir.join(format!("checkpoint_{:05}.seam", state.step)),
                state,
            )?;
        }
        Ok(())
    }

    /// One step's fields: `temperature_<step>.vtu` (and `contact_<step>.vtu`) in the
    /// `.pvd` series (transient runs) and a step of `results.exo`.
    pub(super) fn write_step(
        &mut self,
        step: usize,
        time: f64,
        fields: &StepFields<'_>,
    ) -> std::io::Result<()> {
        let Some(dir) = self.dir.clone() else {
            return Ok(());
        };
        if self.transient {
            let name = format!("temperature_{step:05}.vtu");
            write_temperature_vtu(&dir.join(&name), self.mesh, fields, &[], &self.spec)?;
            self.series
                .get_or_insert_with(|| PvdSeries::new(&dir.join("temperature.pvd")))
                .add(time, Path::new(&name))?;
            if let Some(c) = fields.contact {
                let name = format!("contact_{step:05}.vtu");
                write_contact_vtu(&dir.join(&name), self.mesh, fields.temperature, c)?;
                self.contact_series
                    .get_or_insert_with(|| PvdSeries::new(&dir.join("contact.pvd")))
                    .add(time, Path::new(&name))?;
            }
        }
        if self.exodus.is_none() {
            let mut nodal = vec!["temperature"];
            if fields.contact.is_some() {
                nodal.extend(CONTACT_NODAL);
            }
            // One component per dimension: x and y only in a 2-D mesh.
            let dims = self.mesh.dim.clamp(2, 3);
            let mut element = HEAT_FLUX[..dims].to_vec();
            if fields.electric.is_some() {
                nodal.push("voltage");
                element.extend(&CURRENT_DENSITY[..dims]);
            }
            if fields.species.is_some() {
                nodal.push("species");
            }
            let global: Vec<&str> = fields.heat_names.iter().map(String::as_str).collect();
            self.exodus = Some(ExodusWriter::create_with_globals(
                &dir.join("results.exo"),
                self.mesh,
                &nodal,
                &element,
                &global,
            )?);
        }
        // Nodes without a temperature (shells, bars) and elements without a flux hold 0
        // in the Exodus file.
        let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
        let mut nodal: Vec<Vec<f64>> =
            vec![fields.temperature.iter().map(|&v| finite(v)).collect()];
        if let Some(c) = fields.contact {
            nodal.extend(c.nodal(self.mesh));
        }
        let dims = self.mesh.dim.clamp(2, 3);
        let components = |v: &[f64]| -> Vec<Vec<f64>> {
            (0..dims)
                .map(|d| v.iter().skip(d).step_by(3).map(|&v| finite(v)).collect())
                .collect()
        };
        let mut element = components(fields.heat_flux);
        if let Some((v, j)) = fields.electric {
            nodal.push(v.iter().map(|&v| finite(v)).collect());
            element.extend(components(j));
        }
        if let Some(c) = fields.species {
            nodal.push(c.iter().map(|&v| finite(v)).collect());
        }
        let nodal: Vec<&[f64]> = nodal.iter().map(Vec::as_slice).collect();
        let element: Vec<&[f64]> = element.iter().map(Vec::as_slice).collect();
        let global: Vec<f64> = if fields.heat.len() * 2 == fields.heat_names.len() {
            fields.heat.iter().flat_map(|&(a, b)| [a, b]).collect()
        } else {
            vec![f64::NAN; fields.heat_names.len()]
        };
        self.exodus
            .as_mut()
            .expect("just made")
            .write_step_with_globals(time, &nodal, &element, &global)?;
        self.last_written = Some(step);
        Ok(())
    }

    /// The end of a run: `results.exo` closed and (transient runs) the final
    /// checkpoint.
    pub(super) fn finish(&mut self, state: &State) -> std::io::Result<()> {
        if self.dir.is_none() {
            return Ok(());
        }
        self.close()?;
        if !self.transient {
            return Ok(());
        }
        let dir = self.dir.as_ref().expect("checked");
        write_checkpoint(&dir.join("checkpoint.seam"), state)
    }

    /// Close `results.exo`.
    pub(super) fn close(&mut self) -> std::io::Result<()> {
        match self.exodus.take() {
            Some(x) => x.finish(),
            None => Ok(()),
        }
    }
}

/// A temperature `.vtu`: point data `temperature` (and `extra` point arrays), cell data
/// `heat_flux` (3 components).
pub(super) fn write_temperature_vtu(
    path: &Path,
    mesh: &Mesh,
    fields: &StepFields<'_>,
    extra: &[(&str, &[f64])],
    spec: &OutputSpec,
) -> std::io::Result<()> {
    let mut point = vec![Array::scalar("temperature", fields.temperature)];
    point.extend(extra.iter().map(|&(n, v)| Array::scalar(n, v)));
    let mut cell = vec![Array::vector("heat_flux", fields.heat_flux)];
    if let Some((v, j)) = fields.electric {
        point.push(Array::scalar("voltage", v));
        cell.push(Array::vector("current_density", j));
    }
    if let Some(c) = fields.species {
        point.push(Array::scalar("species", c));
    }
    let encoding = spec.vtu_encoding(mesh.num_nodes());
    write_vtu_arrays(path, mesh, &point, &cell, encoding)
}

/// `contact.vtu`: the contact faces as polygon cells over their own points (the mesh
/// nodes they use, with point data `temperature`), cell data `interaction`, `side`,
/// `contact_gap`, `contact_fraction`, `contact_area`, `interface_flux`.
pub(super) fn write_contact_vtu(
    path: &Path,
    mesh: &Mesh,
    temperature: &[f64],
    contact: &ContactFields,
) -> std::io::Result<()> {
    let mut index = std::collections::HashMap::new();
    let mut points = Vec::new();
    let mut t = Vec::new();
    let mut polygons = Vec::with_capacity(contact.faces.len());
    for f in &contact.faces {
        let cell = f.nodes[..f.len as usize]
            .iter()
            .map(|n| {
                *index.entry(*n).or_insert_with(|| {
                    points.push(mesh.coords[n.index()]);
                    t.push(temperature.get(n.index()).copied().unwrap_or(f64::NAN));
                    (points.len() - 1) as u32
                })
            })
            .collect();
        polygons.push(cell);
    }
    let column = |g: fn(&ContactFace) -> f64| -> Vec<f64> { contact.faces.iter().map(g).collect() };
    let (gap, fraction, area, flux) = (
        column(|f| f.gap),
        column(|f| f.fraction),
        column(|f| f.area),
        column(|f| f.flux),
    );
    let interaction: Vec<i64> = contact
        .faces
        .iter()
        .map(|f| i64::from(f.interaction))
        .collect();
    let side: Vec<i64> = contact.faces.iter().map(|f| i64::from(f.side)).collect();
    write_vtu_polygons(
        path,
        &points,
        &polygons,
        &[Array::scalar("temperature", &t)],
        &[("interaction", &interaction), ("side", &side)],
        &[
            Array::scalar("contact_gap", &gap),
            Array::scalar("contact_fraction", &fraction),
            Array::scalar("contact_area", &area),
            Array::scalar("interface_flux", &flux),
        ],
        VtuEncoding::Ascii,
    )
}

/// `contact_points.vtu`: every side-A point of the given interactions (1-based index,
/// pairing, per-point flux) as a vertex cell at its position (for a periodic pair: on
/// the image), cell data `interaction`, `status` (0 matched, 1 unmatched, 2 rejected
/// by distance, 3 rejected by angle, 4 outside the subdomain), `weight`, `contact_gap`
/// and `interface_flux` (NaN at points that are not matched; NaN flux for an
/// interaction without per-point flux).
pub(super) fn write_contact_points_vtu(
    path: &Path,
    interactions: &[PointsOf<'_>],
) -> std::io::Result<()> {
    let mut points = Vec::new();
    let (mut interaction, mut status) = (Vec::new(), Vec::new());
    let (mut weight, mut gap, mut flux) = (Vec::new(), Vec::new(), Vec::new());
    for &(k, p, q) in interactions {
        for (i, c) in p.result.points.iter().enumerate() {
            points.push(c.x);
            interaction.push(i64::from(k));
            status.push(match c.status {
                PointStatus::Matched => 0,
                PointStatus::Unmatched => 1,
                PointStatus::RejectedDistance => 2,
                PointStatus::RejectedAngle => 3,
                PointStatus::RejectedSubdomain => 4,
            });
            weight.push(c.weight);
            let matched = c.status == PointStatus::Matched;
            gap.push(if matched { c.gap } else { f64::NAN });
            flux.push(match q.and_then(|q| q.get(i).copied().flatten()) {
                Some(f) if matched => f.q,
                _ => f64::NAN,
            });
        }
    }
    let cells: Vec<Vec<u32>> = (0..points.len() as u32).map(|i| vec![i]).collect();
    write_vtu_polygons(
        path,
        &points,
        &cells,
        &[],
        &[("interaction", &interaction), ("status", &status)],
        &[
            Array::scalar("weight", &weight),
            Array::scalar("contact_gap", &gap),
            Array::scalar("interface_flux", &flux),
        ],
        VtuEncoding::Ascii,
    )
}

const MAGIC: &[u8; 8] = b"SEAMCKP1";

/// A checkpoint: the state in raw little-endian binary (bit-exact).
pub(super) fn write_checkpoint(path: &Path, state: &State) -> std::io::Result<()> {
    let mut b = Vec::with_capacity(64 + 8 * state.u.len() * (1 + state.past.len()));
    b.extend_from_slice(MAGIC);
    b.extend_from_slice(&(state.step as u64).to_le_bytes());
    b.extend_from_slice(&state.time.to_le_bytes());
    b.extend_from_slice(&state.dt.to_le_bytes());
    b.extend_from_slice(&(state.u.len() as u64).to_le_bytes());
    b.extend_from_slice(&(state.past.len() as u64).to_le_bytes());
    for v in &state.u {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for (t, u) in &state.past {
        b.extend_from_slice(&t.to_le_bytes());
        for v in u {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    // Write beside, then rename: a run killed mid-write keeps the previous checkpoint.
    let tmp = path.with_extension("seam.part");
    let mut f = std::fs::File::create(&tmp)?;
    f.write_all(&b)?;
    f.sync_all()?;
    std::fs::rename(tmp, path)
}

/// Read a checkpoint written by [`write_checkpoint`].
pub(super) fn read_checkpoint(path: &Path) -> Result<State, RunError> {
    let bad = |m: String| {
        super::input_error(
            "E0713",
            format!("checkpoint {}: {m}", path.display()),
            "give a checkpoint.seam written by `seam run` for this problem",
        )
    };
    let b = std::fs::read(path).map_err(|e| bad(format!("cannot read it: {e}")))?;
    if b.len() < 48 || &b[..8] != MAGIC {
        return Err(bad("not a seam checkpoint (wrong header)".into()));
    }
    let mut at = 8;
    let mut word = || -> Result<[u8; 8], RunError> {
        let w = b
            .get(at..at + 8)
            .ok_or_else(|| bad("the file is truncated".into()))?;
        at += 8;
        Ok(w.try_into().expect("8 bytes"))
    };
    let step = u64::from_le_bytes(word()?) as usize;
    let time = f64::from_le_bytes(word()?);
    let dt = f64::from_le_bytes(word()?);
    let n = u64::from_le_bytes(word()?) as usize;
    let npast = u64::from_le_bytes(word()?) as usize;
    if npast > 2 || n > b.len() / 8 {
        return Err(bad("the header is inconsistent".into()));
    }
    let mut u = Vec::with_capacity(n);
    for _ in 0..n {
        u.push(f64::from_le_bytes(word()?));
    }
    let mut past = Vec::with_capacity(npast);
    for _ in 0..npast {
        let t = f64::from_le_bytes(word()?);
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            v.push(f64::from_le_bytes(word()?));
        }
        past.push((t, v));
    }
    Ok(State {
        step,
        time,
        dt,
        u,
        past,
    })
}

/// `steps.csv`: one row per accepted step, with its phase times and Krylov iterations.
pub(super) fn write_steps(dir: &Path, history: &[StepReport]) -> std::io::Result<()> {
    let mut s = String::from(
        "step,time,dt,newton_iterations,rejected,residual,assembly_s,factor_s,solve_s,krylov_iterations\n",
    );
    for r in history {
        s.push_str(&format!(
            "{},{:e},{:e},{},{},{:e},{:.6},{:.6},{:.6},{}\n",
            r.step,
            r.time,
            r.dt,
            r.newton_iterations,
            r.rejected,
            r.residual_history.last().copied().unwrap_or(0.0),
            r.assembly_s,
            r.factor_s,
            r.solve_s,
            r.cg_iterations
        ));
    }
    std::fs::write(dir.join("steps.csv"), s)
}

/// `electrical_contacts.csv`: per step and electrical contact (side A, side B surface
/// names), the current from side A to side B (A) and the contact's Joule heat (W).
pub(super) fn write_electrical_contacts(
    dir: &Path,
    history: &[StepReport],
    contacts: &[(&str, &str)],
) -> std::io::Result<()> {
    let mut s = String::from("step,time,side_a,side_b,current,joule_heat\n");
    for r in history {
        for ((a, b), p) in contacts.iter().zip(&r.electric) {
            s.push_str(&format!(
                "{},{:e},{a},{b},{:e},{:e}\n",
                r.step, r.time, p.current, p.joule
            ));
        }
    }
    std::fs::write(dir.join("electrical_contacts.csv"), s)
}

/// `species_contacts.csv`: per step and species interface (`labels`: side A, side B,
/// model) the mass flux leaving side A and side B (mol/s) and their sum.
pub(super) fn write_species_contacts(
    dir: &Path,
    history: &[StepReport],
    flux: &[Vec<(f64, f64)>],
    labels: &[(String, String, String)],
) -> std::io::Result<()> {
    let mut s = String::from("step,time,side_a,side_b,model,flux_side_a,flux_side_b,imbalance\n");
    for (r, step) in history.iter().zip(flux) {
        for ((a, b, m), (qa, qb)) in labels.iter().zip(step) {
            s.push_str(&format!(
                "{},{:e},{a},{b},{m},{qa:e},{qb:e},{:e}\n",
                r.step,
                r.time,
                qa + qb
            ));
        }
    }
    std::fs::write(dir.join("species_contacts.csv"), s)
}

/// One step's interface heat: per term (contact terms, then ties) the heat leaving
/// side A and side B, and the heat of each mechanism of a summed conductance (empty
/// for a term that is not a sum).
pub(super) struct HeatRow<'a> {
    pub step: usize,
    pub time: f64,
    pub heat: &'a [(f64, f64)],
    pub mechanisms: &'a [Vec<f64>],
}

/// `interface_heat.csv`: per step and term, one row labelled with the enforcement's
/// model; a term whose conductance is a sum of mechanisms gets one row per mechanism
/// (`mechanism` = its name from `names`, `heat_side_b` = −`heat_side_a`: the split is
/// of one integrand, so each mechanism balances by construction) and then a `total`
/// row with the interaction's measured heat and imbalance.
pub(super) fn write_interface_heat(
    dir: &Path,
    rows: &[HeatRow<'_>],
    labels: &[(String, String, String)],
    names: &[Vec<String>],
) -> std::io::Result<()> {
    let mut s =
        String::from("step,time,side_a,side_b,mechanism,heat_side_a,heat_side_b,imbalance\n");
    for r in rows {
        for (k, ((a, b, m), (qa, qb))) in labels.iter().zip(r.heat).enumerate() {
            let split = r.mechanisms.get(k).map_or(&[][..], Vec::as_slice);
            let names = names.get(k).map_or(&[][..], Vec::as_slice);
            let total = if split.is_empty() || split.len() != names.len() {
                m.as_str()
            } else {
                for (name, q) in names.iter().zip(split) {
                    s.push_str(&format!(
                        "{},{:e},{a},{b},{},{:e},{:e},{:e}\n",
                        r.step,
                        r.time,
                        csv_field(name),
                        q,
                        -q,
                        0.0
                    ));
                }
                "total"
            };
            s.push_str(&format!(
                "{},{:e},{a},{b},{total},{:e},{:e},{:e}\n",
                r.step,
                r.time,
                qa,
                qb,
                qa + qb
            ));
        }
    }
    std::fs::write(dir.join("interface_heat.csv"), s)
}

/// A CSV field, quoted (RFC 4180) when it holds a comma, a quote or a line break — a
/// Lua mechanism's name quotes its expression.
fn csv_field(s: &str) -> std::borrow::Cow<'_, str> {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\"")).into()
    } else {
        s.into()
    }
}

/// The run's final state in the form of a steady solution.
pub(super) fn final_solution(
    outcome: Outcome,
    history: &[StepReport],
    fields: &[String],
    contact_terms: usize,
) -> SteadySolution {
    let last = history.last();
    let heat = last.map(|r| r.heat.clone()).unwrap_or_default();
    let (flux, ties) = heat.split_at(contact_terms.min(heat.len()));
    let mut timing = SolveTiming::default();
    for r in history {
        timing.assembly_s += r.assembly_s;
        timing.factor_s += r.factor_s;
        timing.solve_s += r.solve_s;
    }
    let temperature = nodal_temperature(&outcome.dofs, &outcome.state.u, fields);
    SteadySolution {
        temperature,
        u: outcome.state.u,
        dofs: outcome.dofs,
        newton_iterations: history.iter().map(|r| r.newton_iterations).sum(),
        converged: last.is_none_or(|r| r.diagnosis.is_none()),
        residual_history: last.map(|r| r.residual_history.clone()).unwrap_or_default(),
        heat: flux.to_vec(),
        tie_heat: ties.to_vec(),
        crosspoints: outcome.crosspoints,
        timing,
        linear: LinearSolves::default(),
    }
}

/// Quick-look plots in `plots/`, each as `.png` and `.svg`: temperature along a line
/// through the first interface, interface heat over time (transient runs), and Newton
/// convergence. Axes carry SI units; heats are per full revolution in an axisymmetric
/// model and per unit depth (W/m) in a plane 2-D one. Returns the PNGs' paths.
pub(super) fn write_plots(
    dir: &Path,
    mesh: &Mesh,
    temperature: &[f64],
    history: &[StepReport],
    labels: &[(String, String, String)],
    line: Option<([f64; 3], [f64; 3])>,
) -> std::io::Result<Vec<PathBuf>> {
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots)?;
    let mut written = Vec::new();
    let mut write = |plot: Plot, name: &str| -> std::io::Result<()> {
        let png = plots.join(format!("{name}.png"));
        plot.write_png(&png)?;
        plot.write_svg(&plots.join(format!("{name}.svg")))?;
        written.push(png);
        Ok(())
    };
    if let Some((origin, axis)) = line {
        let series = line_samples(mesh, temperature, origin, axis);
        if !series.is_empty() {
            let plot = Plot {
                title: "Temperature along a line through the interface".into(),
                x_label: "distance along the interface normal (m)".into(),
                y_label: "temperature T (K)".into(),
                log_y: false,
                series,
            };
            write(plot, "temperature_line")?;
        }
    }
    if history.len() > 1 && !labels.is_empty() {
        let series = labels
            .iter()
            .enumerate()
            .map(|(k, (a, b, m))| Series {
                label: format!("{a} / {b} ({m})"),
                points: history
                    .iter()
                    .map(|r| (r.time, r.heat.get(k).map_or(f64::NAN, |h| h.0)))
                    .collect(),
            })
            .collect();
        let heat = if mesh.axisymmetric {
            "heat (W per revolution)"
        } else if mesh.dim == 2 {
            "heat (W/m of depth)"
        } else {
            "heat (W)"
        };
        let plot = Plot {
            title: "Heat out of side A".into(),
            x_label: "time t (s)".into(),
            y_label: heat.into(),
            log_y: false,
            series,
        };
        write(plot, "interface_heat")?;
    }
    if let Some(last) = history.last().filter(|r| !r.residual_history.is_empty()) {
        let plot = Plot {
            title: "Newton convergence (last step)".into(),
            x_label: "Newton iteration".into(),
            y_label: "residual 2-norm (W; A on voltage rows)".into(),
            log_y: true,
            series: vec![Series {
                label: format!("step {} (t = {:e} s)", last.step, last.time),
                points: last
                    .residual_history
                    .iter()
                    .enumerate()
                    .map(|(i, r)| (i as f64, *r))
                    .collect(),
            }],
        };
        write(plot, "newton")?;
    }
    Ok(written)
}

/// Nodal temperatures near the line `origin + s·axis`, per block, as (s, T): the nodes
/// of each block within 1.5 times that block's least distance to the line.
fn line_samples(mesh: &Mesh, t: &[f64], origin: [f64; 3], axis: [f64; 3]) -> Vec<Series> {
    let mut out = Vec::new();
    // A block's nodes, ascending and each once, by marking them (a sort of the 8
    // nodes of every hex took 0.2 s at 1.1 M elements).
    let mut mark = vec![false; mesh.coords.len()];
    for block in &mesh.blocks {
        mark.fill(false);
        for k in 0..block.len() {
            for n in block.elem_nodes(k) {
                mark[n.0 as usize] = true;
            }
        }
        let nodes: Vec<u32> = (0..mark.len() as u32)
            .filter(|&n| mark[n as usize])
            .collect();
        let at = |n: u32| {
            let x = mesh.coords[n as usize];
            let d = [x[0] - origin[0], x[1] - origin[1], x[2] - origin[2]];
            let s = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
            let r2 = (d[0] - s * axis[0]).powi(2)
                + (d[1] - s * axis[1]).powi(2)
                + (d[2] - s * axis[2]).powi(2);
            (s, r2.sqrt())
        };
        let least = nodes.iter().map(|&n| at(n).1).fold(f64::INFINITY, f64::min);
        let mut points: Vec<(f64, f64)> = nodes
            .iter()
            .filter(|&&n| at(n).1 <= 1.5 * least + 1e-12 && t[n as usize].is_finite())
            .map(|&n| (at(n).0, t[n as usize]))
            .collect();
        points.sort_by(|a, b| a.0.total_cmp(&b.0));
        if !points.is_empty() {
            out.push(Series {
                label: block.sierra_name(),
                points,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::interface_heat_names;

    #[test]
    fn interface_heat_names_are_unique_per_term() {
        let names = interface_heat_names(&[("a", "b"), ("c", "d"), ("a", "b")]);
        assert_eq!(
            names,
            [
                "heat_side_a:a/b",
                "heat_side_b:a/b",
                "heat_side_a:c/d",
                "heat_side_b:c/d",
                "heat_side_a:a/b:3",
                "heat_side_b:a/b:3"
            ]
        );
    }
}
