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
use crate::mesh::{Mesh, NodeId};
use crate::solve::{
    AmgCg, AmgOptions, BlockGmres, Cholesky, FineRadius, LinearSolver, Lu, Ordering, SaddleLdlt,
    apply_dirichlet_mut, apply_dirichlet_parts, spmv_parts, spmv_ref,
};
use faer::sparse::{SparseColMat, SparseColMatMut, SparseColMatRef};
use std::collections::HashSet;

pub use super::interfaces::{ContactTerm, TieTerm};
use super::interfaces::{InterfaceFailure, Interfaces, Terms, TieRows};
use super::{
    FaceBc, HeatError, Material, SourceFn, TEMPERATURE, assemble_conduction,
    assemble_conduction_by_block, dirichlet_dofs,
};

/// Relative residual at which AMG-preconditioned CG stops, ‖b − Ax‖ ≤ 1e-11 ‖b‖: three
/// orders below the default Newton tolerance (1e-10), so one CG solve finishes a linear
/// problem, and tight enough that temperatures and interface heat agree with a
/// factorisation's to about 1e-10 relative (4e-14 absolute on the crossover benchmark,
/// 1e-8 relative asserted on the two-block scene), the accuracy the verification cases
/// assert.
pub const AMG_TOLERANCE: f64 = 1e-11;

/// Relative residual at which a steady solve's AMG-CG stops, ‖b − Ax‖ ≤ 1e-13 ‖b‖,
/// tighter than [`AMG_TOLERANCE`] (which the time steps keep): a steady solve is one
/// CG solve whose error is the answer's. Measured on the 1.16 M-node tied boxes
/// (`benches/peers/seam_case.py tied --n1 120 --n2 80`, exact T = 1 − z): 1e-11 leaves
/// a max error of 2.0e-11 after 36 iterations, 4e-13 1.2e-12 after 41, 1e-13 1.4e-13
/// after 44 — round-off level for about 20% more CG time.
pub const STEADY_AMG_TOLERANCE: f64 = 1e-13;

/// The steady Newton's stopping test at iteration `it` (0 before any step), with the
/// residual norm `rn`, its `goal` and `scale`, the last step's largest change and the
/// field `u`; `symmetric`: a linear problem (one solve leaves only round-off). Through
/// [`Record`], the serial and the distributed solves stop alike.
fn newton_converged(
    it: usize,
    (rn, goal, scale): (f64, f64, f64),
    last_step: f64,
    u: &[f64],
    symmetric: bool,
) -> bool {
    let u_max = u
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
        .max(f64::MIN_POSITIVE);
    // A problem solved by Newton (a conductance that may depend on T) takes a second
    // step even when the first meets the goal: the goal is relative to the first
    // residual, which the Dirichlet lifting can make huge (k = 1e8), and the second step
    // refines the LU solution to round-off (heat to ~1e-12, not 1e-7).
    (rn <= goal && (symmetric || it != 1))
        || (it > 0 && last_step <= 1e-13 * u_max)
        || (it > 0 && symmetric && rn <= 1e-8 * scale)
}

/// Size (unknowns) from which `seam run`'s `linear_solver = "auto"` solves a symmetric
/// positive definite system by AMG-preconditioned CG instead of sparse Cholesky.
///
/// Measured (`SEAM_BENCH_ONLY=crossover cargo bench --bench solvers`, release, 2 threads,
/// medians of 3): the Q1 conduction matrix of a c³-cell cube, T = 0 on its boundary,
/// METIS Cholesky (factor + solve) against AMG-CG to 1e-11 (set-up + solve):
/// 729 unknowns 4.9 ms vs 5.1 ms, 2 197: 22 vs 8.7 ms, 9 261: 0.12 vs 0.033 s,
/// 24 389: 0.47 vs 0.078 s, 68 921: 2.4 vs 0.29 s (Cholesky grows as n^1.6, AMG-CG as
/// n^1.3, 11–13 CG iterations; answers agree to 4e-14). The time crossover is about
/// 1 000 unknowns, but below 20 000 a factorisation costs under 0.3 s, is exact to
/// round-off and does not mind the stiff interface conductances and penalties
/// (h = 1e8) that double CG's iterations on tied systems; from 20 000 on its growth
/// makes it the slow path (6–8× AMG-CG at 25 000–70 000 unknowns).
pub const AUTO_AMG_THRESHOLD: usize = 20_000;

/// The linear solver a steady solve used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinearMethod {
    /// Sparse LLᵀ (METIS ordering): symmetric positive definite systems.
    Cholesky,
    /// Sparse LU: unsymmetric Newton Jacobians (a conductance that depends on T), or
    /// a symmetric system Cholesky rejected.
    Lu,
    /// Saddle-point LDLᵀ: standard Lagrange-multiplier ties.
    SaddleLdlt,
    /// CG preconditioned by smoothed-aggregation AMG.
    AmgCg,
    /// GMRES preconditioned by AMG: an unsymmetric Jacobian beyond the size for
    /// factorisations.
    Gmres,
}

impl LinearMethod {
    /// The name `seam run` prints.
    pub fn name(self) -> &'static str {
        match self {
            LinearMethod::Cholesky => "Cholesky",
            LinearMethod::Lu => "LU",
            LinearMethod::SaddleLdlt => "LDLᵀ",
            LinearMethod::AmgCg => "AMG-CG",
            LinearMethod::Gmres => "GMRES",
        }
    }
}

/// What the linear solves of a steady solve did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LinearSolves {
    /// The solver of the last solve (`None` when nothing was solved, e.g. the initial
    /// state already met the tolerance, or a transient run).
    pub method: Option<LinearMethod>,
    /// Krylov iterations of each AMG-CG or GMRES solve (empty for factorisations).
    pub cg_iterations: Vec<usize>,
    /// Iterative solves: AMG hierarchies set up, and kept ones refreshed with a new
    /// matrix's values (Newton iterations).
    pub hierarchy_setups: Option<usize>,
    pub hierarchy_refreshes: usize,
}

/// A steady problem on a mesh.
pub struct SteadyProblem<'a> {
    pub mesh: &'a Mesh,
    pub materials: &'a [Material],
    pub source: Option<SourceFn<'a>>,
    /// The source per mesh block (`None` on a block without one), used instead of
    /// `source` when given: heat made in some parts and not in others.
    pub block_source: Option<&'a [Option<SourceFn<'a>>]>,
    pub dirichlet: &'a [(NodeId, f64)],
    pub face_bcs: &'a [FaceBc],
    pub contact: Vec<ContactTerm<'a>>,
    /// Mortar ties with multipliers (solved as a saddle-point system).
    pub ties: Vec<TieTerm<'a>>,
    /// The interfaces from elsewhere (`seam run`'s come through `seam::embed`), over
    /// this solve's dof numbering: the temperature over every solid block, then the
    /// multipliers. Instead of `contact` and `ties`, which must then be empty.
    pub interfaces: Option<&'a dyn Interfaces>,
    /// Solve the linear systems by CG with the algebraic-multigrid preconditioner
    /// instead of a factorisation (symmetric problems without multipliers; for sizes a
    /// factorisation does not fit).
    pub iterative: bool,
    /// Factor on one thread: the same bits on any number of threads (the iterative
    /// path is so anyway).
    pub reproducible: bool,
    /// Relative tolerance on the residual norm.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl SteadyProblem<'_> {
    /// The conduction terms of `mesh` (the problem's own, or a rank's part of it, with
    /// the problem's blocks) into `asm`: its materials, sources and face conditions.
    pub(crate) fn conduction(
        &self,
        asm: &mut Assembler<'_>,
        mesh: &Mesh,
        dofs: &DofMap,
    ) -> Result<(), HeatError> {
        self.conduction_with_faces(asm, mesh, dofs, self.face_bcs)
    }

    /// [`Self::conduction`] with the face conditions `faces` (a rank's own).
    pub(crate) fn conduction_with_faces(
        &self,
        asm: &mut Assembler<'_>,
        mesh: &Mesh,
        dofs: &DofMap,
        faces: &[FaceBc],
    ) -> Result<(), HeatError> {
        match self.block_source {
            Some(sources) => {
                assemble_conduction_by_block(asm, mesh, dofs, self.materials, sources, faces)
            }
            None => assemble_conduction(asm, mesh, dofs, self.materials, self.source, faces),
        }
    }
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
    /// Per tie: the same.
    pub tie_heat: Vec<(f64, f64)>,
    /// Per tie: side-A nodes left without a multiplier because they were already
    /// constrained (Dirichlet data or an earlier tie).
    pub crosspoints: Vec<Vec<NodeId>>,
    pub timing: SolveTiming,
    /// Which linear solver ran, and its CG iterations.
    pub linear: LinearSolves,
}

/// Solve the steady problem.
pub fn solve_steady(p: &SteadyProblem<'_>) -> Result<SteadySolution, HeatError> {
    let mesh = p.mesh;
    let blocks: Vec<usize> = (0..mesh.blocks.len())
        .filter(|&b| mesh.blocks[b].topology.is_solid())
        .collect();
    let mut dofs = DofMap::new(mesh, &[(TEMPERATURE, &blocks)])?;
    let field = dofs
        .field(TEMPERATURE)
        .ok_or(HeatError::NoTemperatureField)?;
    let n_primal = dofs.len();
    let bcs = dirichlet_dofs(mesh, &dofs, field, p.dirichlet)?;
    let conductivity: Vec<f64> = p.materials.iter().map(|m| m.conductivity).collect();
    let fixed: HashSet<NodeId> = p.dirichlet.iter().map(|&(node, _)| node).collect();
    let own;
    let iface: &dyn Interfaces = match p.interfaces {
        Some(_) if !p.contact.is_empty() || !p.ties.is_empty() => {
            return Err(HeatError::Contact(
                "give the interfaces either as terms or from elsewhere, not both".into(),
            ));
        }
        Some(i) => i,
        None => {
            let terms = (p.contact.as_slice(), p.ties.as_slice());
            own = Terms::new(mesh, &dofs, field.into(), terms, fixed, &conductivity)
                .map_err(HeatError::Contact)?;
            &own
        }
    };
    // Mortar ties: multipliers on side-A nodes not constrained already.
    // Their rows count as assembly.
    let t = Instant::now();
    let ties = iface.ties().map_err(HeatError::Contact)?;
    let ties_s = t.elapsed().as_secs_f64();
    if super::dual::dual_ties(&ties, iface.is_linear())? {
        let mut solved = super::dual::solve_dual(p, iface, dofs, field, bcs, ties)?;
        solved.timing.assembly_s += ties_s;
        return Ok(solved);
    }
    let mut lambda_first = Vec::with_capacity(ties.len());
    for tie in &ties {
        lambda_first.push(dofs.add_extra(tie.own.len()).start);
    }
    let n = dofs.len();
    let mut u = vec![0.0; n];
    for &(d, g) in &bcs {
        u[d] = g;
    }
    let mut timing = SolveTiming {
        assembly_s: ties_s,
        ..SolveTiming::default()
    };
    let mut linear = LinearSolves::default();
    let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());

    // The pattern: elements plus every interface coupling (fixed by the pairing).
    let t = Instant::now();
    let couplings = iface.couplings(&u, 0.0).map_err(failed)?;
    let t_couplings = t.elapsed().as_secs_f64();
    let (pattern, first, tie_coupling_first) =
        pattern_of(mesh, &dofs, &couplings, &ties, &lambda_first)?;
    drop(couplings);
    log::debug!(
        "steady: interface couplings {t_couplings:.3} s, pattern {:.3} s",
        t.elapsed().as_secs_f64() - t_couplings
    );
    timing.assembly_s += t.elapsed().as_secs_f64();
    let symmetric = iface.is_linear();
    // AMG-CG of a linear problem: its own path, which frees the pattern before the
    // hierarchy is made.
    if p.iterative && symmetric && ties.is_empty() {
        let pattern = (pattern, first);
        let solved = solve_amg(
            p,
            iface,
            &dofs,
            &bcs,
            &mut u,
            pattern,
            (&mut timing, &mut linear),
        )?;
        return Ok(SteadySolution {
            temperature: dofs.nodal_values(field, &u),
            dofs,
            u,
            newton_iterations: solved.steps,
            converged: solved.converged,
            residual_history: solved.history,
            heat: solved.heat,
            tie_heat: Vec::new(),
            crosspoints: Vec::new(),
            timing,
            linear,
        });
    }
    // The conduction part is linear: assemble it once, straight into the matrix values
    // (no element matrix is kept), and keep K and F for every Newton step (only the
    // interface slots change). K's values are the assembler's element sums, over the
    // pattern's structure: no copy of either.
    let t = Instant::now();
    let structure = pattern.symbolic().expect("built");
    let sym = structure.as_ref();
    let mut asm = Assembler::direct(&pattern)?;
    p.conduction(&mut asm, mesh, &dofs)?;
    let f_vol = asm.rhs();
    timing.assembly_s += t.elapsed().as_secs_f64();

    let mut chol = Cholesky::new(Ordering::Metis);
    chol.sequential = p.reproducible;
    let mut saddle = SaddleLdlt::with_primal(n_primal, n, Ordering::Metis);
    saddle.sequential = p.reproducible;
    let mut lu = Lu::new();
    // An unsymmetric Jacobian beyond the size for factorisations: GMRES with an AMG
    // hierarchy kept across the Newton iterations.
    let mut gmres =
        (p.iterative && !symmetric && ties.is_empty()).then(|| BlockGmres::new(n, AMG_TOLERANCE));
    let mut record = Record::new(&f_vol, p.tolerance);
    let mut converged = false;
    let mut iterations = 0;
    let mut last_step = f64::INFINITY;
    let mut heat = Vec::new();
    for it in 0..=p.max_iterations {
        let t = Instant::now();
        // R = K u − F + Σ R_Γ, the interface Jacobian into the coupling slots.
        let mut r = vec![0.0; n];
        let k_vol = asm.element_values().expect("K is kept");
        spmv_ref(SparseColMatRef::new(sym, k_vol), &u, &mut r);
        for (ri, fi) in r.iter_mut().zip(&f_vol) {
            *ri -= fi;
        }
        asm.reset_couplings();
        heat = iface
            .assemble(&u, 0.0, &mut r, &mut asm, first)
            .map_err(failed)?;
        // Ties: Cᵀλ on the primal rows, C u − ΔT ∫ψ on the multiplier rows.
        for (t, tie) in ties.iter().enumerate() {
            let l0 = lambda_first[t];
            for &(k, d, c) in &tie.entries {
                let l = l0 + k;
                r[d] += c * u[l];
                r[l] += c * u[d];
            }
            for (k, g) in tie.rhs.iter().enumerate() {
                r[l0 + k] -= g;
            }
        }
        let done = record.converged(it, &mut r, &bcs, last_step, &u, symmetric);
        timing.assembly_s += t.elapsed().as_secs_f64();
        if done {
            converged = true;
            break;
        }
        if it == p.max_iterations {
            break;
        }
        iterations += 1;
        let t = Instant::now();
        for (t, tie) in ties.iter().enumerate() {
            for (e, &(_, _, c)) in tie.entries.iter().enumerate() {
                asm.add_coupling(tie_coupling_first[t] + e, c, c);
            }
        }
        // The Jacobian's values over the pattern's structure, copied into a matrix only
        // for a factorisation (AMG-CG keeps its own copy in row storage).
        let mut jac_values = Vec::new();
        asm.values_into(&mut jac_values)?;
        let mut rhs: Vec<f64> = r.iter().map(|v| -v).collect();
        let zero: Vec<(usize, f64)> = bcs.iter().map(|&(d, _)| (d, 0.0)).collect();
        apply_dirichlet_mut(SparseColMatMut::new(sym, &mut jac_values), &mut rhs, &zero)?;
        timing.assembly_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let jac = SparseColMat::new(structure.clone(), jac_values);
        if let Some(g) = gmres.as_mut() {
            g.factor(&jac)?;
            timing.factor_s += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let report = g.solve(&mut rhs)?;
            timing.solve_s += t.elapsed().as_secs_f64();
            linear.method = Some(LinearMethod::Gmres);
            linear.cg_iterations.push(report.iterations);
            let (setups, refreshes) = g.reuse_counts();
            (linear.hierarchy_setups, linear.hierarchy_refreshes) = (Some(setups), refreshes);
            last_step = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (ui, d) in u.iter_mut().zip(&rhs) {
                *ui += d;
            }
            continue;
        }
        let saddle_ok = !ties.is_empty() && symmetric && saddle.factor(&jac).is_ok();
        let use_chol = !saddle_ok && ties.is_empty() && symmetric && chol.factor(&jac).is_ok();
        if !saddle_ok && !use_chol {
            lu.factor(&jac)?;
        }
        timing.factor_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        if saddle_ok {
            saddle.solve(&mut rhs)?;
            linear.method = Some(LinearMethod::SaddleLdlt);
        } else if use_chol {
            chol.solve(&mut rhs)?;
            linear.method = Some(LinearMethod::Cholesky);
        } else {
            lu.solve(&mut rhs)?;
            linear.method = Some(LinearMethod::Lu);
        }
        timing.solve_s += t.elapsed().as_secs_f64();
        last_step = rhs.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (ui, d) in u.iter_mut().zip(&rhs) {
            *ui += d;
        }
    }
    // `heat` is of the final state: the loop ends right after assembling at it.
    let tie_heat = ties
        .iter()
        .enumerate()
        .map(|(t, tie)| tie.heat(&u[lambda_first[t]..lambda_first[t] + tie.own.len()]))
        .collect();
    let crosspoints = ties.iter().map(|t| t.crosspoints.clone()).collect();
    let temperature = dofs.nodal_values(field, &u);
    Ok(SteadySolution {
        dofs,
        u,
        temperature,
        newton_iterations: iterations,
        converged,
        residual_history: record.history,
        heat,
        tie_heat,
        crosspoints,
        timing,
        linear,
    })
}

/// The steady pattern over `dofs`: the elements, the interface `couplings` and one
/// coupling per entry of each tie's C (primal dof, multiplier), built for direct
/// assembly. With where the interface couplings and each tie's start.
fn pattern_of(
    mesh: &Mesh,
    dofs: &DofMap,
    couplings: &[(usize, usize)],
    ties: &[TieRows],
    lambda_first: &[usize],
) -> Result<(Pattern, usize, Vec<usize>), HeatError> {
    let mut pattern = Pattern::new(mesh, dofs);
    let first = pattern.add_couplings(couplings)?.start;
    let mut tie_first = Vec::with_capacity(ties.len());
    for (t, tie) in ties.iter().enumerate() {
        let pairs: Vec<(usize, usize)> = tie
            .entries
            .iter()
            .map(|&(k, d, _)| (d, lambda_first[t] + k))
            .collect();
        tie_first.push(pattern.add_couplings(&pairs)?.start);
    }
    pattern.build_direct()?;
    Ok((pattern, first, tie_first))
}

/// The steady Newton's residual norms and its goal (fixed at the first residual),
/// kept alike by the serial and the distributed solves.
pub(crate) struct Record {
    pub(crate) history: Vec<f64>,
    /// ‖F‖, the scale of the goal.
    f_norm: f64,
    tolerance: f64,
    goal: Option<f64>,
}

impl Record {
    fn new(f: &[f64], tolerance: f64) -> Record {
        Record::with_norm(f.iter().map(|v| v * v).sum::<f64>().sqrt(), tolerance)
    }

    /// For a load vector of norm `f_norm`.
    pub(crate) fn with_norm(f_norm: f64, tolerance: f64) -> Record {
        Record {
            history: Vec::new(),
            f_norm,
            tolerance,
            goal: None,
        }
    }

    /// The residual `r` at iteration `it` (its Dirichlet rows zeroed here) recorded;
    /// whether Newton has converged ([`newton_converged`]): the residual is at its goal;
    /// or, after a step, the step changed u by round-off only (stiff interface terms
    /// floor the residual well above 1e-13 ‖F‖ while the solution is exact); or the
    /// problem is linear and one step has left only round-off.
    fn converged(
        &mut self,
        it: usize,
        r: &mut [f64],
        bcs: &[(usize, f64)],
        last_step: f64,
        u: &[f64],
        symmetric: bool,
    ) -> bool {
        for &(d, _) in bcs {
            r[d] = 0.0;
        }
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        self.converged_at(it, rn, last_step, u, symmetric)
    }

    /// As [`Self::converged`] for a residual of norm `rn` (its Dirichlet rows already
    /// zero); `u` may be just its largest magnitude.
    pub(crate) fn converged_at(
        &mut self,
        it: usize,
        rn: f64,
        last_step: f64,
        u: &[f64],
        symmetric: bool,
    ) -> bool {
        self.history.push(rn);
        let scale = self.f_norm.max(rn).max(1e-300);
        let goal = *self.goal.get_or_insert(self.tolerance * scale);
        newton_converged(it, (rn, goal, scale), last_step, u, symmetric)
    }
}

/// What a steady Newton solve ends with: the heat of each interface term, the steps,
/// whether it converged and the residual norms.
struct Solved {
    heat: Vec<(f64, f64)>,
    steps: usize,
    converged: bool,
    history: Vec<f64>,
}

/// A linear steady problem by AMG-CG: the Jacobian K + J_Γ is the same at every step,
/// so its hierarchy is set up once, from K's values (no copy), and the residual after a
/// step is R + J Δu (the hierarchy's matrix is J with the Dirichlet rows and columns
/// eliminated, and Δu is 0 on those rows). The pattern and its assembler are freed as
/// soon as the first residual and the Jacobian's values are made, before the hierarchy:
/// the set-up is the solve's peak of memory (about 300 MB less at 1.16 M unknowns).
fn solve_amg(
    p: &SteadyProblem<'_>,
    iface: &dyn Interfaces,
    dofs: &DofMap,
    bcs: &[(usize, f64)],
    u: &mut [f64],
    (pattern, first): (Pattern, usize),
    (timing, linear): (&mut SolveTiming, &mut LinearSolves),
) -> Result<Solved, HeatError> {
    let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());
    let n = u.len();
    let t = Instant::now();
    let mut fine_s = 0.0;
    let (mut record, mut r, mut heat, fine) = {
        let (col_ptr, rows) = pattern.structure().expect("built");
        let mut asm = Assembler::direct(&pattern)?;
        p.conduction(&mut asm, p.mesh, dofs)?;
        let f_vol = asm.rhs();
        let t_conduction = t.elapsed().as_secs_f64();
        // R = K u − F + Σ R_Γ, the interface Jacobian into the coupling slots.
        let mut r = vec![0.0; n];
        let k = asm.element_values().expect("K");
        spmv_parts(col_ptr, rows, k, u, &mut r);
        for (ri, fi) in r.iter_mut().zip(&f_vol) {
            *ri -= fi;
        }
        let t_residual = t.elapsed().as_secs_f64();
        let heat = iface
            .assemble(u, 0.0, &mut r, &mut asm, first)
            .map_err(failed)?;
        log::debug!(
            "steady: conduction {t_conduction:.3} s, residual {:.3} s, interfaces {:.3} s",
            t_residual - t_conduction,
            t.elapsed().as_secs_f64() - t_residual
        );
        let mut record = Record::new(&f_vol, p.tolerance);
        let fine = if record.converged(0, &mut r, bcs, f64::INFINITY, u, true) {
            None
        } else {
            // The matrix in the hierarchy's row storage counts as its set-up.
            let t = Instant::now();
            let mut values = asm.take_values()?;
            let zero: Vec<(usize, f64)> = bcs.iter().map(|&(d, _)| (d, 0.0)).collect();
            let mut rhs = vec![0.0; n];
            apply_dirichlet_parts(col_ptr, rows, &mut values, &mut rhs, &zero)?;
            fine_s = t.elapsed().as_secs_f64();
            Some((values, asm.exactly_symmetric()))
        };
        (record, r, heat, fine)
    };
    // The pattern given up: its structure becomes the hierarchy's rows (a symmetric
    // structure is its own transpose), with no copy.
    let (col_ptr, rows) = pattern.into_structure().expect("built");
    log::debug!(
        "steady: first assembly and residual {:.3} s",
        t.elapsed().as_secs_f64()
    );
    let t_rows = Instant::now();
    let fine = fine
        .map(|(values, symmetric)| match symmetric {
            true => AmgCg::rows_of_symmetric_parts(n, col_ptr, rows, values),
            false => AmgCg::rows_of_parts(n, col_ptr, rows, values),
        })
        .transpose()?;
    fine_s += t_rows.elapsed().as_secs_f64();
    timing.assembly_s += t.elapsed().as_secs_f64() - fine_s;
    timing.factor_s += fine_s;
    let Some(fine) = fine else {
        return Ok(Solved {
            heat,
            steps: 0,
            converged: true,
            history: record.history,
        });
    };
    let t = Instant::now();
    // A hierarchy for one linear solve (a further step, if the first falls short,
    // solves with the same): the finest level's ρ by its bound, one pass instead of up
    // to ten.
    let mut amg = AmgCg::new(AmgOptions {
        tolerance: STEADY_AMG_TOLERANCE,
        fine_radius: FineRadius::Bound,
        ..AmgOptions::default()
    });
    amg.setup(fine)?;
    timing.factor_s += t.elapsed().as_secs_f64();
    linear.method = Some(LinearMethod::AmgCg);
    linear.hierarchy_setups = Some(1);
    let mut steps = 0;
    for it in 1..=p.max_iterations {
        let t = Instant::now();
        let mut du: Vec<f64> = r.iter().map(|v| -v).collect();
        let report = amg.solve(&mut du)?;
        linear.cg_iterations.push(report.iterations);
        steps += 1;
        let last_step = du.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (ui, d) in u.iter_mut().zip(&du) {
            *ui += d;
        }
        let mut jdu = vec![0.0; n];
        amg.apply(&du, &mut jdu);
        r.iter_mut().zip(&jdu).for_each(|(ri, v)| *ri += v);
        timing.solve_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        heat = iface.heat(u, 0.0).map_err(failed)?;
        let done = record.converged(it, &mut r, bcs, last_step, u, true);
        timing.assembly_s += t.elapsed().as_secs_f64();
        if done {
            return Ok(Solved {
                heat,
                steps,
                converged: true,
                history: record.history,
            });
        }
    }
    Ok(Solved {
        heat,
        steps,
        converged: false,
        history: record.history,
    })
}
