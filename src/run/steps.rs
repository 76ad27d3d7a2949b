//! What a transient (or nonlinear) run writes as it goes: the fields every few steps
//! (`.vtu` and a `.pvd` series), checkpoints, and the histories (`steps.csv`,
//! `interface_heat.csv`).

use std::io::Write as _;
use std::path::{Path, PathBuf};

use crate::assembly::DofMap;
use crate::heat::steady::{SolveTiming, SteadySolution};
use crate::heat::transient::{Outcome, State, StepReport};
use crate::mesh::Mesh;
use crate::output::vtu::write_vtu;

use super::{OutputSpec, RunError};

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

/// Writes a run's steps into the output directory.
pub(super) struct StepWriter<'m> {
    dir: Option<PathBuf>,
    mesh: &'m Mesh,
    every: usize,
    checkpoint_every: Option<usize>,
    transient: bool,
    /// (time, file name) of the fields written, for the `.pvd`.
    series: Vec<(f64, String)>,
    last_written: Option<usize>,
}

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
            series: Vec::new(),
            last_written: None,
        }
    }

    pub(super) fn step(
        &mut self,
        r: &StepReport,
        state: &State,
        dofs: &DofMap,
        fields: &[String],
    ) -> std::io::Result<()> {
        if !self.transient || self.dir.is_none() {
            return Ok(());
        }
        if r.step.is_multiple_of(self.every) {
            self.write_fields(state, dofs, fields)?;
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

    fn write_fields(
        &mut self,
        state: &State,
        dofs: &DofMap,
        fields: &[String],
    ) -> std::io::Result<()> {
        let Some(dir) = &self.dir else { return Ok(()) };
        let name = format!("temperature_{:05}.vtu", state.step);
        let t = nodal_temperature(dofs, &state.u, fields);
        write_vtu(&dir.join(&name), self.mesh, &[("temperature", &t)])?;
        self.series.push((state.time, name));
        self.last_written = Some(state.step);
        write_pvd(&dir.join("temperature.pvd"), &self.series)
    }

    /// The last step's fields (if not written yet) and the final checkpoint.
    pub(super) fn finish(
        &mut self,
        state: &State,
        dofs: &DofMap,
        fields: &[String],
    ) -> std::io::Result<()> {
        if !self.transient || self.dir.is_none() {
            return Ok(());
        }
        if self.last_written != Some(state.step) {
            self.write_fields(state, dofs, fields)?;
        }
        let dir = self.dir.as_ref().expect("checked");
        write_checkpoint(&dir.join("checkpoint.seam"), state)
    }
}

/// A ParaView collection of the steps written so far (rewritten each time, so a run
/// stopped midway leaves a valid series).
fn write_pvd(path: &Path, series: &[(f64, String)]) -> std::io::Result<()> {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
    );
    for (t, f) in series {
        s.push_str(&format!(
            "<DataSet timestep=\"{t:e}\" part=\"0\" file=\"{f}\"/>\n"
        ));
    }
    s.push_str("</Collection>\n</VTKFile>\n");
    std::fs::write(path, s)
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

/// `steps.csv` (one row per step) and `interface_heat.csv` (one row per step and
/// interaction: the heat through side A and side B and the imbalance).
pub(super) fn write_history(
    dir: &Path,
    history: &[StepReport],
    labels: &[(String, String, String)],
) -> std::io::Result<()> {
    let mut s = String::from("step,time,dt,newton_iterations,rejected,residual\n");
    for r in history {
        s.push_str(&format!(
            "{},{:e},{:e},{},{},{:e}\n",
            r.step,
            r.time,
            r.dt,
            r.newton_iterations,
            r.rejected,
            r.residual_history.last().copied().unwrap_or(0.0)
        ));
    }
    std::fs::write(dir.join("steps.csv"), s)?;
    let mut s =
        String::from("step,time,side_a,side_b,mechanism,heat_side_a,heat_side_b,imbalance\n");
    for r in history {
        for ((a, b, m), (qa, qb)) in labels.iter().zip(&r.heat) {
            s.push_str(&format!(
                "{},{:e},{a},{b},{m},{:e},{:e},{:e}\n",
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
        converged: true,
        residual_history: last.map(|r| r.residual_history.clone()).unwrap_or_default(),
        heat: flux.to_vec(),
        tie_heat: ties.to_vec(),
        crosspoints: outcome.crosspoints,
        timing,
    }
}
