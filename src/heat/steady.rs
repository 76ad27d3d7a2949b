//! The steady heat solve with contact: conduction in every block, interface forms on
//! every contact pairing, Dirichlet data, Newton.
//!
//! Entry point: [`solve_steady`]. Each Newton step assembles `J = K + Σ J_Γ` and
//! `R = K u − F + Σ R_Γ(u)` (the interface terms of [`crate::enforce::interface`] are
//! exact in u, including dh/dT), imposes Dirichlet rows on the increment, and solves
//! with sparse Cholesky (METIS ordering) while the system is symmetric — every
//! interface with a constant conductance — else with sparse LU. The symbolic analysis
//! is kept across iterations. Linear problems converge in one step (a second assembly
//! confirms the residual).

use std::time::Instant;

use crate::assembly::{Assembler, DofMap, Pattern};
use crate::enforce::interface::{InterfaceForm, InterfaceSystem, interface_terms};
use crate::mesh::{Mesh, NodeId};
use crate::search::pairing::{ContactPoint, SurfaceGeometry};
use crate::solve::{Cholesky, LinearSolver, Lu, Ordering, apply_dirichlet, spmv};

use super::{
    FaceBc, HeatError, Material, SourceFn, TEMPERATURE, assemble_conduction, dirichlet_dofs,
};

/// One enforced interface: a pairing and its form.
pub struct ContactTerm<'a> {
    pub side_a: &'a SurfaceGeometry,
    pub side_b: &'a SurfaceGeometry,
    pub points: &'a [ContactPoint],
    pub form: InterfaceForm<'a>,
    /// The conductance does not depend on the field (the system stays linear and
    /// symmetric).
    pub linear: bool,
}

/// A steady problem on a mesh.
pub struct SteadyProblem<'a> {
    pub mesh: &'a Mesh,
    pub materials: &'a [Material],
    pub source: Option<SourceFn<'a>>,
    pub dirichlet: &'a [(NodeId, f64)],
    pub face_bcs: &'a [FaceBc],
    pub contact: Vec<ContactTerm<'a>>,
    /// Relative tolerance on the residual norm.
    pub tolerance: f64,
    pub max_iterations: usize,
}

/// Wall time of the phases, seconds.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct SolveTiming {
    pub assembly_s: f64,
    pub factor_s: f64,
    pub solve_s: f64,
}

/// The result of a steady solve.
#[derive(Debug)]
pub struct SteadySolution {
    pub dofs: DofMap,
    /// The global dof vector.
    pub u: Vec<f64>,
    /// Nodal temperature (NaN on nodes without a temperature dof).
    pub temperature: Vec<f64>,
    pub newton_iterations: usize,
    pub converged: bool,
    pub residual_history: Vec<f64>,
    /// Per contact term: heat leaving side A and heat leaving side B through Γ.
    pub heat: Vec<(f64, f64)>,
    pub timing: SolveTiming,
}

/// Solve the steady problem.
pub fn solve_steady(p: &SteadyProblem<'_>) -> Result<SteadySolution, HeatError> {
    let mesh = p.mesh;
    let blocks: Vec<usize> = (0..mesh.blocks.len())
        .filter(|&b| mesh.blocks[b].topology.is_solid())
        .collect();
    let dofs = DofMap::new(mesh, &[(TEMPERATURE, &blocks)])?;
    let field = dofs
        .field(TEMPERATURE)
        .ok_or(HeatError::NoTemperatureField)?;
    let n = dofs.len();
    let bcs = dirichlet_dofs(mesh, &dofs, field, p.dirichlet)?;
    let mut u = vec![0.0; n];
    for &(d, g) in &bcs {
        u[d] = g;
    }
    let mut timing = SolveTiming::default();

    // The pattern: elements plus every interface coupling (fixed by the pairing).
    let t = Instant::now();
    let mut pattern = Pattern::new(mesh, &dofs);
    let mut first = Vec::with_capacity(p.contact.len());
    let mut couplings = Vec::with_capacity(p.contact.len());
    let mut terms: Vec<InterfaceSystem> = Vec::with_capacity(p.contact.len());
    for c in &p.contact {
        let s = interface_terms(
            mesh, &dofs, field, c.side_a, c.side_b, c.points, &c.form, &u,
        )
        .map_err(|e| HeatError::Contact(e.to_string()))?;
        let cp = s.couplings();
        first.push(pattern.add_couplings(&cp)?.start);
        couplings.push(cp);
        terms.push(s);
    }
    pattern.build()?;
    // The conduction part is linear: assemble it once, keep K and F.
    let mut vol = Assembler::new(&pattern);
    assemble_conduction(&mut vol, mesh, &dofs, p.materials, p.source, p.face_bcs)?;
    let k_vol = vol.matrix()?;
    let f_vol = vol.rhs();
    drop(vol);
    timing.assembly_s += t.elapsed().as_secs_f64();

    let symmetric = p.contact.iter().all(|c| c.linear);
    let mut chol = Cholesky::new(Ordering::Metis);
    let mut lu = Lu::new();
    let mut history = Vec::new();
    let mut converged = false;
    let mut iterations = 0;
    let mut target = None;
    let mut last_step = f64::INFINITY;
    for it in 0..=p.max_iterations {
        let t = Instant::now();
        if it > 0 {
            for (k, c) in p.contact.iter().enumerate() {
                terms[k] = interface_terms(
                    mesh, &dofs, field, c.side_a, c.side_b, c.points, &c.form, &u,
                )
                .map_err(|e| HeatError::Contact(e.to_string()))?;
            }
        }
        // R = K u − F + Σ R_Γ.
        let mut r = vec![0.0; n];
        spmv(&k_vol, &u, &mut r);
        for (ri, fi) in r.iter_mut().zip(&f_vol) {
            *ri -= fi;
        }
        for s in &terms {
            for &(d, v) in &s.residual {
                r[d as usize] += v;
            }
        }
        for &(d, _) in &bcs {
            r[d] = 0.0;
        }
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        history.push(rn);
        let scale = f_vol
            .iter()
            .map(|v| v * v)
            .sum::<f64>()
            .sqrt()
            .max(rn)
            .max(1e-300);
        let goal = *target.get_or_insert(p.tolerance * scale);
        timing.assembly_s += t.elapsed().as_secs_f64();
        // Converged: the residual is at its goal; or, after a step, the step changed u
        // by round-off only (stiff interface terms floor the residual well above
        // 1e-13 ‖F‖ while the solution is exact); or the problem is linear and one
        // step has left only round-off.
        let u_max = u
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        if rn <= goal
            || (it > 0 && last_step <= 1e-13 * u_max)
            || (it > 0 && symmetric && rn <= 1e-8 * scale)
        {
            converged = true;
            break;
        }
        if it == p.max_iterations {
            break;
        }
        iterations += 1;
        let t = Instant::now();
        let mut asm = Assembler::new(&pattern);
        // The element slots repeat the conduction terms (cheap, and keeps one pattern).
        assemble_conduction(&mut asm, mesh, &dofs, p.materials, p.source, p.face_bcs)?;
        for (k, s) in terms.iter().enumerate() {
            s.add_to(&mut asm, &couplings[k], first[k]);
        }
        let mut jac = asm.matrix()?;
        drop(asm);
        let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
        let zero: Vec<(usize, f64)> = bcs.iter().map(|&(d, _)| (d, 0.0)).collect();
        apply_dirichlet(&mut jac, &mut rhs, &zero)?;
        timing.assembly_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let use_chol = symmetric && chol.factor(&jac).is_ok();
        if !use_chol {
            lu.factor(&jac)?;
        }
        timing.factor_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        if use_chol {
            chol.solve(&mut rhs)?;
        } else {
            lu.solve(&mut rhs)?;
        }
        timing.solve_s += t.elapsed().as_secs_f64();
        last_step = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (ui, d) in u.iter_mut().zip(&rhs) {
            *ui += d;
        }
    }
    let heat = terms.iter().map(InterfaceSystem::heat).collect();
    let temperature = dofs.nodal_values(field, &u);
    Ok(SteadySolution {
        dofs,
        u,
        temperature,
        newton_iterations: iterations,
        converged,
        residual_history: history,
        heat,
        timing,
    })
}
