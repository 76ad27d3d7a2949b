//! The steady solve on MPI: the Newton iteration of [`crate::heat::steady`] (the same
//! residual, Jacobian, Dirichlet rows on the increment and stopping tests) with the
//! system distributed; its set-up ([`Built`]) and iteration ([`Newton`]) also step a
//! transient run ([`super::stepped`]), with the lumped capacity of a time step. With a
//! conductivity of T each rank assembles its elements' residual and tangent at every
//! iterate instead of keeping `K` ([`Built::conduction_at`]).
//!
//! Each rank assembles the conduction of its own elements (a mesh of only those,
//! [`Layout::local_mesh`]) with the serial kernels and adds every entry it made — rows of
//! any rank: PETSc sends those to their owners at assembly. The interface terms likewise:
//! each rank evaluates the points it owns (the side-A points of its elements' faces, or
//! its side-A nodes; [`crate::heat::interfaces::Interfaces::own_points`]) and adds their
//! entries, in global (PETSc) dof numbers, to the rows of any rank; the heats are summed
//! over the ranks. The increment is solved by PETSc; each rank then gets from their
//! owners only the values it reads (its elements' dofs, and its points' on both sides:
//! [`Scatter`]), and the whole solution is gathered once, at the end, for the output.
//! Mortar ties with multipliers add their rows as [`super::ties`] says. A failure on
//! one rank (an interface model, a load) is agreed on by every rank before the next
//! collective ([`agreed`](super::session::agreed)).

use std::time::Instant;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, Communicator, CommunicatorCollectives};

use crate::assembly::{Assembler, DofMap, Pattern};
use crate::heat::dual::DUAL_AMG_TOLERANCE;
use crate::heat::interfaces::InterfaceFailure;
use crate::heat::law::Law;
use crate::heat::nonlinear::conduction_at;
use crate::heat::steady::{
    AMG_TOLERANCE, LinearMethod, LinearSolves, STEADY_AMG_TOLERANCE, SolveTiming, SteadyProblem,
    SteadySolution,
};
use crate::heat::transient::LumpedWeight;
use crate::heat::{FaceBc, HeatError, TEMPERATURE, dirichlet_dofs};
use crate::mesh::{ElemId, Mesh};
use crate::solve::amg::KEPT_SOLUTIONS;
use crate::solve::spmv_ref;
use faer::sparse::SparseColMatRef;

use super::conduction::{Capacity, Conduction, conduction};
use super::part;
use super::petsc::{Ksp, Mat, Method, PetscError, PetscInt, Vector};
use super::reuse::Hierarchy;
use super::rows::{
    ByRows, Layout, Scatter, add_rows, couplings_to_owners, empty_mesh, local_faces, log_partition,
    preallocation, summed_heat,
};
use super::session::{AllPoints, Phases, agreed, refused};
use super::ties::Ties;
use super::{Laws, session};

mod condense;

fn petsc_err(e: PetscError) -> HeatError {
    HeatError::Contact(format!("distributed solve: {e}"))
}

/// Solve `p` over the MPI world: on a run whose mesh is distributed (`p.mesh` this
/// rank's local mesh with its contact partners), rank 0 returns the whole solution and
/// every other rank its own part (its owned dofs and those it reads; the rest as they
/// started); else every rank the whole solution.
pub(super) fn solve(p: &SteadyProblem<'_>) -> Result<SteadySolution, HeatError> {
    let built = Built::new(p, 0.0, None, false)?;
    let mut newton = Newton::new(&built, false)?;
    let mut u = vec![0.0; built.n];
    built.start(&mut u, &built.bcs);
    let solved = newton.solve(&mut u, 0.0, None)?;
    if let Some(why) = solved.failure {
        return Err(HeatError::Step(why));
    }
    built.gather(&mut u);
    let (method, symmetric) = (newton.method, newton.symmetric);
    let ties = built.has_ties().then_some(newton.condensed.is_some());
    super::record(method, super::steady_reason(method, symmetric, ties));
    let linear = LinearSolves {
        method: (solved.iterations > 0).then_some(match method {
            Method::CgAmg => LinearMethod::AmgCg,
            Method::GmresAmg => LinearMethod::Gmres,
            _ => LinearMethod::Lu,
        }),
        cg_iterations: solved.cg_iterations.clone(),
        ..LinearSolves::default()
    };
    let temperature = built.dofs.nodal_values(built.field, &u);
    let crosspoints = built.crosspoints();
    Ok(SteadySolution {
        dofs: built.dofs,
        u,
        temperature,
        newton_iterations: solved.iterations,
        converged: solved.converged,
        residual_history: solved.history,
        heat: solved.heat,
        tie_heat: solved.tie_heat,
        crosspoints,
        timing: solved.timing,
        linear,
    })
}

/// What one Newton solve ([`Newton::solve`]) ends with, the same on every rank.
pub(super) struct Solved {
    pub converged: bool,
    /// Why the iteration stopped short, where it could not go on (a residual that is
    /// not finite, a Krylov solve that diverged); the same on every rank. A time step
    /// that stops so, or does not converge, is cut and taken again.
    pub failure: Option<String>,
    /// Newton steps taken (linear solves).
    pub iterations: usize,
    /// ‖R‖ at every iterate.
    pub history: Vec<f64>,
    /// Per interaction, the heat leaving side A and side B, summed over the ranks.
    pub heat: Vec<(f64, f64)>,
    /// Per mortar tie with multipliers, the same.
    pub tie_heat: Vec<(f64, f64)>,
    /// Krylov iterations of each CG or GMRES solve.
    pub cg_iterations: Vec<usize>,
    /// Matrices set up for (each a new AMG hierarchy or MUMPS factorisation).
    pub setups: usize,
    /// Matrices solved on the AMG hierarchy of an earlier one.
    pub kept: usize,
    pub timing: SolveTiming,
}

/// What a distributed solve of one temperature field keeps from its set-up: the
/// layout of the dofs over the ranks, this rank's own elements and their conduction
/// pattern, the interface pattern of its points and what it reads from other ranks.
pub(super) struct Built<'p> {
    p: &'p SteadyProblem<'p>,
    world: SimpleCommunicator,
    pub dofs: DofMap,
    pub field: crate::assembly::FieldId,
    /// Local dofs.
    pub n: usize,
    /// The Dirichlet dofs of the set-up's loads and their values.
    pub bcs: Vec<(usize, f64)>,
    iface: Option<&'p dyn crate::heat::interfaces::Interfaces>,
    layout: Layout,
    /// The time of the set-up.
    start: f64,
    /// The mesh of this rank's own elements, and per element of `p.mesh` its element
    /// there.
    local: Mesh,
    to_local: Vec<Option<ElemId>>,
    /// The pattern of this rank's elements.
    k_pattern: Pattern,
    k_sym: faer::sparse::SymbolicSparseColMat<usize>,
    /// The run's laws per block of `p.mesh` (a stepped run's; `None`: the steady
    /// solve's constant materials and sources of x).
    laws: Option<Laws<'p>>,
    /// The conduction depends on u: a k, a ρc (stepping) or a source of T, or a
    /// radiation condition. It is then assembled at every Newton iterate
    /// ([`Built::conduction_at`]) and `p.materials`' conductivities are not read.
    pub nonlinear: bool,
    /// A source depends on time: the linear conduction's load is made again at each
    /// step's time ([`Built::conduction`]).
    sources_in_time: bool,
    /// ρc depends on T (stepping): the capacity is evaluated at every iterate.
    pub capacity_of_t: bool,
    /// The conduction's values and load of the set-up's face conditions.
    k_first: std::cell::RefCell<Option<(Vec<f64>, Vec<f64>)>>,
    /// The dofs whose residual this rank adds to (its elements' and its own), and their
    /// PETSc rows.
    touched: Vec<usize>,
    touched_petsc: Vec<PetscInt>,
    /// The interface couplings of this rank's points, and where they start in `ipattern`.
    ipattern: Pattern,
    first: usize,
    pairs_of_mine: Vec<(usize, usize)>,
    preallocated: (Vec<PetscInt>, Vec<PetscInt>),
    /// Own Dirichlet rows: PETSc indices and places among the rank's rows.
    bc_rows: Vec<PetscInt>,
    bc_local: Vec<usize>,
    scatter: Scatter,
    /// Mortar ties with multipliers ([`Ties`]).
    ties: Option<Ties>,
    _all_again: Option<AllPoints<'p>>,
}

impl<'p> Built<'p> {
    /// The set-up of `p` (its interfaces' couplings taken at time `t`), with a stepped
    /// run's `laws` (`transient`: time steps, whose capacity they hold too).
    pub(super) fn new(
        p: &'p SteadyProblem<'p>,
        t: f64,
        laws: Option<Laws<'p>>,
        transient: bool,
    ) -> Result<Built<'p>, HeatError> {
        let mesh = p.mesh;
        let world = session::comm();
        let blocks = part::solid_blocks(mesh);
        let mut dofs = DofMap::new(mesh, &[(TEMPERATURE, &blocks)])?;
        let field = dofs
            .field(TEMPERATURE)
            .ok_or(HeatError::NoTemperatureField)?;
        let bcs = dirichlet_dofs(mesh, &dofs, field, p.dirichlet)?;
        let iface = match p.interfaces {
            Some(i) if p.contact.is_empty() && p.ties.is_empty() => Some(i),
            None if p.contact.is_empty() && p.ties.is_empty() => None,
            _ => {
                return Err(refused(
                    "interface terms given as ContactTerm/TieTerm lists",
                ));
            }
        };
        let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());
        let start = Instant::now();
        part::ensure(mesh).map_err(HeatError::Contact)?;
        let mut layout = part::with(|part| Layout::new(part, mesh, &dofs, field))
            .ok_or_else(|| HeatError::Contact("distributed solve: no partition".into()))?
            .map_err(HeatError::Contact)?;
        // The interface terms of the points this rank owns (by their side-A face's
        // element or side-A node), all points again when the solve ends however it ends.
        let _all_again = match iface {
            Some(i) => {
                i.own_points(Some(&|e, n| layout.owns_point(e, n)))
                    .map_err(failed)?;
                Some(AllPoints(i))
            }
            None => None,
        };
        // Mortar ties' multipliers, after the nodes' dofs.
        let mut ties = match iface {
            Some(i) => Ties::new(&world, i, (&mut dofs, field), &mut layout)?,
            None => None,
        };
        let n = dofs.len();
        let mut phases = Phases::default();
        phases.mark("partition", start);
        let mut u = vec![0.0; n];
        for &(d, g) in &bcs {
            u[d] = g;
        }

        // This rank's conduction: its elements, their face conditions.
        let (local, to_local) = layout.local_mesh(mesh);
        let mut k_pattern = Pattern::new(&local, &dofs);
        k_pattern.build_direct()?;
        let k_sym = k_pattern.symbolic().expect("built").clone();
        let varies = |l: &[Law]| l.iter().any(|l| !matches!(l, Law::Constant(_)));
        let capacity_of_t = transient && laws.is_some_and(|l| varies(l.capacity));
        let radiation = (p.face_bcs.iter()).any(|f| matches!(f, FaceBc::Radiation { .. }));
        // (Radiation without laws — the linear steady solve's — is refused by its
        // conduction, as serially.)
        let nonlinear = laws.is_some_and(|l| {
            capacity_of_t
                || radiation
                || varies(l.conductivity)
                || l.source.iter().any(Law::uses_temperature)
        });
        let sources_in_time = laws.is_some_and(|l| l.source.iter().any(Law::depends_on_time));
        let k_first = match nonlinear {
            true => None,
            false => {
                let sources = laws.map(|l| l.source).filter(|_| sources_in_time);
                let local = (&local, to_local.as_slice());
                let terms = Conduction {
                    pattern: &k_pattern,
                    faces: p.face_bcs,
                    sources,
                    t,
                };
                Some(conduction(p, local, &dofs, terms)?)
            }
        };
        phases.mark("own elements", start);
        let mut touched: Vec<usize> = local
            .blocks
            .iter()
            .flat_map(|b| b.connectivity.iter())
            .filter_map(|&node| dofs.dof(field, node).map(|d| d.index()))
            .chain(layout.owned.iter().copied())
            .collect();
        touched.sort_unstable();
        touched.dedup();
        let touched_petsc: Vec<PetscInt> = touched.iter().map(|&d| layout.petsc[d]).collect();

        // Their pattern: this rank's couplings alone (no elements).
        let empty = empty_mesh(mesh);
        let mut ipattern = Pattern::new(&empty, &dofs);
        let pairs_of_mine = match iface {
            Some(i) => i.couplings(&u, t).map_err(failed)?,
            None => Vec::new(),
        };
        let first = ipattern.add_couplings(&pairs_of_mine)?.start;
        // With the ties' couplings of this rank's multipliers.
        let mut all_pairs = pairs_of_mine.clone();
        if let Some(t) = &mut ties {
            let pairs = t.couplings();
            t.at_slot(ipattern.add_couplings(&pairs)?.start);
            all_pairs.extend(pairs);
        }
        ipattern.build_direct()?;
        // The couplings of every rank's points that reach this rank's rows, for their
        // preallocation.
        let reaching = couplings_to_owners(&world, &layout, &all_pairs);
        let joined = ties.as_ref().map_or_else(Vec::new, Ties::joined);
        log_partition(
            &world,
            &layout,
            &[pairs_of_mine.as_slice(), &joined].concat(),
        );
        phases.mark("interface pattern", start);
        let preallocated = preallocation(mesh, &dofs, field, &layout, &reaching);
        drop(reaching);
        phases.mark("preallocation", start);
        let bc_rows: Vec<PetscInt> = bcs
            .iter()
            .filter(|&&(d, _)| layout.owns(d))
            .map(|&(d, _)| layout.petsc[d])
            .collect();
        let first_row = layout.rows().start;
        let bc_local: Vec<usize> = bc_rows.iter().map(|&i| i as usize - first_row).collect();
        // The dofs this rank reads: its elements' and its points' (side A and side B).
        let scatter = Scatter::new(&world, &layout, &touched, &all_pairs);
        phases.mark("what each rank reads", start);
        if layout.rank == 0 {
            log::info!(
                "distributed set-up on rank 0 (s from its start): {}",
                phases.0
            );
        }
        Ok(Built {
            p,
            world,
            dofs,
            field,
            n,
            bcs,
            iface,
            layout,
            local,
            to_local,
            start: t,
            k_pattern,
            k_sym,
            laws,
            nonlinear,
            sources_in_time,
            capacity_of_t,
            k_first: std::cell::RefCell::new(k_first),
            touched,
            touched_petsc,
            ipattern,
            first,
            pairs_of_mine,
            preallocated,
            bc_rows,
            bc_local,
            scatter,
            ties,
            _all_again,
        })
    }

    /// Put the Dirichlet values `bcs` into `u` and bring, from their owners, the values
    /// of the dofs this rank reads and does not own (a prescribed temperature at a node
    /// another rank holds, the starting field at a contact partner's node).
    pub(super) fn start(&self, u: &mut [f64], bcs: &[(usize, f64)]) {
        for &(d, g) in bcs {
            u[d] = g;
        }
        self.scatter.start(&self.world, &self.layout, u);
    }

    /// Rank 0 (when the mesh is distributed, else every rank) gets the whole solution
    /// in `u`.
    pub(super) fn gather(&self, u: &mut [f64]) {
        let layout = &self.layout;
        let mine: Vec<f64> = layout.owned.iter().map(|&d| u[d]).collect();
        let whole = if layout.distributed {
            session::gather_root(&self.world, &mine)
        } else {
            session::gather_all(&self.world, &mine)
        };
        if whole.len() == layout.starts[layout.size] {
            for (d, ui) in u.iter_mut().enumerate() {
                *ui = whole[layout.petsc[d] as usize];
            }
        }
    }

    /// The inverse of [`Self::gather`]: rank 0's `whole` (its dofs, the serial order) at
    /// this rank's dofs, its own from rank 0, those it reads from their owners.
    pub(super) fn scatter(&self, whole: &[f64]) -> Vec<f64> {
        (self.scatter).sent_by_root(&self.world, &self.layout, whole, self.n)
    }

    /// The local dofs before the multipliers (the temperatures).
    pub(super) fn primal(&self) -> usize {
        self.dofs.extra_ranges().first().map_or(self.n, |r| r.start)
    }

    /// Whether the solve holds mortar ties with multipliers (a saddle point).
    pub(super) fn has_ties(&self) -> bool {
        self.ties.is_some()
    }

    /// Per mortar tie, its side-A nodes without a multiplier (on rank 0).
    pub(super) fn crosspoints(&self) -> Vec<Vec<crate::mesh::NodeId>> {
        self.ties.as_ref().map_or_else(Vec::new, Ties::crosspoints)
    }

    /// Whether this is rank 0, which writes the outputs.
    pub(super) fn is_root(&self) -> bool {
        self.layout.rank == 0
    }

    /// Evaluate every interface point: the outputs of an accepted step, on rank 0. On
    /// one rank its points are every point already: nothing to do (nor for
    /// [`Self::own_points_again`]).
    pub(super) fn all_points(&self) -> Result<(), HeatError> {
        match self.iface {
            _ if self.world.size() == 1 => Ok(()),
            Some(i) => i
                .own_points(None)
                .map_err(|e| HeatError::Contact(e.to_string())),
            None => Ok(()),
        }
    }

    /// Evaluate this rank's points alone again after [`Self::all_points`], their
    /// couplings (at `u`, time `t`) those of the set-up: the interface pattern of the
    /// solve holds.
    pub(super) fn own_points_again(&self, u: &[f64], t: f64) -> Result<(), HeatError> {
        let Some(i) = self.iface.filter(|_| self.world.size() > 1) else {
            return Ok(());
        };
        let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());
        i.own_points(Some(&|e, n| self.layout.owns_point(e, n)))
            .map_err(failed)?;
        if i.couplings(u, t).map_err(failed)? != self.pairs_of_mine {
            return Err(HeatError::Contact(format!(
                "distributed solve: the interface couplings of rank {}'s points changed at t = {t}",
                self.layout.rank
            )));
        }
        Ok(())
    }

    /// The serial general solver's local error estimate of a step of size `dt` from
    /// `state` (this rank's) to `u_new`, `predicted` the predictor through the last
    /// states: the largest `|u_new − predicted|` over every rank's own dofs times the
    /// scheme's error constant relative to the predictor's (backward Euler
    /// `Δt/(Δt + Δtₙ₋₁)`, BDF2 2/11); `None` while the history is too short (collective).
    pub(super) fn local_error(
        &self,
        scheme: crate::heat::transient::Scheme,
        state: &crate::heat::transient::State,
        u_new: &[f64],
        predicted: &[f64],
        dt: f64,
    ) -> Option<f64> {
        use crate::heat::transient::Scheme;
        let c = match scheme {
            Scheme::BackwardEuler => {
                let (t1, _) = state.past.first()?;
                dt / (dt + (state.time - t1))
            }
            Scheme::Bdf2 => {
                state.past.get(1)?;
                2.0 / 11.0
            }
        };
        // (The temperatures alone, not the multipliers, as serially.)
        let own = self.layout.owned.iter().filter(|&&d| d < self.primal());
        let mine = own.fold(0.0f64, |m, &d| m.max((u_new[d] - predicted[d]).abs()));
        let mut worst = 0.0;
        self.world
            .all_reduce_into(&mine, &mut worst, SystemOperation::max());
        Some(worst * c)
    }

    /// The lumped capacity `∫ ρc N_a` of this rank's own elements at each local dof, of
    /// the blocks (of the problem's mesh) whose ρc in `capacity` is a constant, and the
    /// weights `∫ N_a` per (dof, block) (a ρc of T takes them at each iterate).
    pub(super) fn capacity(
        &self,
        capacity: &[Law],
    ) -> Result<(Vec<f64>, Vec<LumpedWeight>), HeatError> {
        let weights =
            crate::heat::transient::lumped_weights(&self.local, &self.dofs, None, &|_| true)?;
        let mut m = vec![0.0; self.n];
        for &(d, b, w, _) in &weights {
            if let Law::Constant(rho_c) = capacity[b as usize] {
                m[d as usize] += w * rho_c;
            }
        }
        Ok((m, weights))
    }

    /// This rank's conduction values and load under the face conditions `faces` (of the
    /// problem's mesh), on the set-up's pattern.
    /// (`t`: the time of sources that change with it.)
    pub(super) fn conduction(
        &self,
        faces: &[FaceBc],
        t: f64,
    ) -> Result<(Vec<f64>, Vec<f64>), HeatError> {
        let local = (&self.local, self.to_local.as_slice());
        let sources = self.laws.map(|l| l.source).filter(|_| self.sources_in_time);
        let terms = Conduction {
            pattern: &self.k_pattern,
            faces,
            sources,
            t,
        };
        conduction(self.p, local, &self.dofs, terms)
    }

    /// Whether the linear conduction's load changes with time (a source of t): made
    /// again at each step ([`Built::conduction`]).
    pub(super) fn sources_in_time(&self) -> bool {
        self.sources_in_time
    }

    /// This rank's conduction at the field `u` at time `t` under the face conditions
    /// `faces` (of the problem's mesh), with the run's laws (a conduction that depends
    /// on u): the tangent's values on the set-up's pattern, and `−R` of its elements.
    pub(super) fn conduction_at(
        &self,
        faces: &[FaceBc],
        u: &[f64],
        t: f64,
    ) -> Result<(Vec<f64>, Vec<f64>), HeatError> {
        let faces = local_faces(faces, &self.to_local);
        let laws = self.laws.ok_or_else(|| {
            HeatError::Step("distributed solve: a conduction of T without its laws".into())
        })?;
        let mut asm = Assembler::direct(&self.k_pattern)?;
        let terms = (laws.conductivity, laws.source);
        conduction_at(&mut asm, &self.local, &self.dofs, terms, &faces, (u, t))?;
        let f = asm.rhs();
        Ok((asm.take_values()?, f))
    }
}

/// The Newton iteration over a [`Built`] set-up, with the PETSc matrix, vectors and
/// solver it keeps: the matrix is set again only when its values change (a new `c₀`,
/// new conduction values, or an interface whose Jacobian depends on u), so a linear
/// run stepping with a fixed step keeps its BoomerAMG hierarchy or MUMPS factorisation.
pub(super) struct Newton<'b, 'p> {
    built: &'b Built<'p>,
    iasm: Assembler<'b>,
    /// The conduction's and the interfaces' entries by PETSc row.
    k_rows: ByRows,
    i_rows: ByRows,
    k_local: Vec<f64>,
    f_local: Vec<f64>,
    /// The face conditions in force (of the problem's mesh): read at every iterate when
    /// the conductivity depends on temperature.
    faces: Vec<FaceBc>,
    a: Mat,
    r_vec: Vector,
    du_vec: Vector,
    /// The iterate, for a time step's right-hand side ([`Self::step_tolerance`]).
    x_vec: Vector,
    ksp: Ksp,
    pub method: Method,
    /// Neither the interfaces' Jacobian nor the conductivity depends on u (and the
    /// matrix is symmetric).
    pub symmetric: bool,
    /// The `c₀` of the matrix set last and which flux terms were on in it (`None`: none
    /// set, or values to set again).
    matrix_for: Option<(u64, Vec<bool>)>,
    /// Per conduction diagonal entry `(dof, slot)`, where a capacity enters.
    diagonal: Vec<(usize, usize)>,
    /// The AMG hierarchy kept across matrices ([`Hierarchy`]).
    hierarchy: Hierarchy,
    /// Dual ties condensed out of a linear steady solve ([`condense`]).
    condensed: Option<condense::Condensed>,
}

impl<'b, 'p> Newton<'b, 'p> {
    /// The PETSc objects of `built`; `stepping`: the increments of time steps (CG to the
    /// tolerance of the serial time steps), else of a steady solve.
    pub(super) fn new(built: &'b Built<'p>, stepping: bool) -> Result<Self, HeatError> {
        let layout = &built.layout;
        let comm = built.world.as_raw();
        let iasm = Assembler::direct(&built.ipattern)?;
        let i_rows = ByRows::new(built.ipattern.symbolic().expect("built"), layout);
        let k_rows = ByRows::new(&built.k_sym, layout);
        // (A conduction of T is assembled at each iterate instead.)
        let (k_local, f_local) = match (built.k_first.borrow_mut().take(), built.nonlinear) {
            (Some(kf), _) => kf,
            (None, false) => built.conduction(built.p.face_bcs, built.start)?,
            (None, true) => (Vec::new(), Vec::new()),
        };
        let (diagonal, off) = &built.preallocated;
        let global = layout.starts[layout.size];
        let local_rows = layout.rows().len();
        let a = Mat::aij(comm, local_rows, global, diagonal, off).map_err(petsc_err)?;
        let r_vec = Vector::new(comm, local_rows, global).map_err(petsc_err)?;
        let du_vec = r_vec.duplicate().map_err(petsc_err)?;
        let x_vec = r_vec.duplicate().map_err(petsc_err)?;
        let symmetric = built.iface.is_none_or(|i| i.is_linear()) && !built.nonlinear;
        // The serial solvers' choice: AMG-CG, or AMG-GMRES for an unsymmetric Jacobian,
        // from the threshold on; a factorisation below it.
        let condensed = condense::Condensed::new(built, stepping)?;
        let method = match (symmetric, built.p.iterative) {
            _ if built.ties.is_some() && condensed.is_none() => Method::MumpsLu,
            (true, true) => Method::CgAmg,
            (false, true) => Method::GmresAmg,
            (_, false) => Method::MumpsLu,
        };
        let tolerance = match (method, stepping) {
            (Method::CgAmg, false) if condensed.is_some() => DUAL_AMG_TOLERANCE,
            (Method::CgAmg, false) => STEADY_AMG_TOLERANCE,
            _ => AMG_TOLERANCE,
        };
        let mut ksp = Ksp::new(comm, &a, method, tolerance).map_err(petsc_err)?;
        if stepping && method == Method::CgAmg {
            // From a zero increment, on the true residual (see `step_tolerance`), moved
            // to the best combination of the earlier steps' increments.
            ksp.start_from_x(false).map_err(petsc_err)?;
            ksp.remember_solutions(KEPT_SOLUTIONS).map_err(petsc_err)?;
        }
        let (col_ptr, row_idx) = (built.k_sym.col_ptr(), built.k_sym.row_idx());
        let diagonal = (0..built.k_sym.ncols())
            .filter_map(|j| {
                (col_ptr[j]..col_ptr[j + 1])
                    .find(|&k| row_idx[k] == j)
                    .map(|k| (j, k))
            })
            .collect();
        Ok(Newton {
            built,
            iasm,
            k_rows,
            i_rows,
            k_local,
            f_local,
            faces: built.p.face_bcs.to_vec(),
            a,
            r_vec,
            du_vec,
            x_vec,
            ksp,
            method,
            symmetric,
            matrix_for: None,
            diagonal,
            hierarchy: Hierarchy::default(),
            condensed,
        })
    }

    /// New face conditions (they changed with time), with the conduction's values and
    /// load under them when the conductivity is constant ([`Built::conduction`]).
    pub(super) fn set_faces(&mut self, faces: Vec<FaceBc>, linear: Option<(Vec<f64>, Vec<f64>)>) {
        if let Some((k, f)) = linear {
            if k != self.k_local {
                self.matrix_for = None;
            }
            (self.k_local, self.f_local) = (k, f);
        }
        self.faces = faces;
    }

    /// ‖v‖ over every rank of the vector each rank adds `values` at its touched dofs to.
    fn norm_of_added(&mut self, values: &[f64]) -> Result<f64, HeatError> {
        let built = self.built;
        let at: Vec<f64> = built.touched.iter().map(|&d| values[d]).collect();
        self.r_vec.zero().map_err(petsc_err)?;
        self.r_vec
            .add(&built.touched_petsc, &at)
            .map_err(petsc_err)?;
        self.r_vec.assemble().map_err(petsc_err)?;
        self.r_vec.norm().map_err(petsc_err)
    }

    /// Newton from `u` (its Dirichlet values set, up to date at the dofs this rank
    /// reads) at time `t`, with the capacity terms of a time step if any: the serial
    /// steady solve's residual, Jacobian, Dirichlet rows on the increment and stopping
    /// tests, relative to the norm of the load (of a time step: load and history).
    pub(super) fn solve(
        &mut self,
        u: &mut [f64],
        t: f64,
        capacity: Option<&Capacity<'_>>,
    ) -> Result<Solved, HeatError> {
        let built = self.built;
        let (p, layout, n) = (built.p, &built.layout, built.n);
        let failed = |e: InterfaceFailure| HeatError::Contact(e.to_string());
        let local_rows = layout.rows().len();
        let mut timing = SolveTiming::default();
        let start = Instant::now();
        // ‖F‖ over every rank (of a time step, ‖F − m rest‖), the scale of the steady
        // test (a conduction of T stops by the steps' test, on the update).
        let mut load = match built.nonlinear {
            true => vec![0.0; n],
            false => self.f_local.clone(),
        };
        if let Some(c) = capacity.filter(|c| c.of_t.is_none()) {
            for &d in &built.touched {
                load[d] -= c.m[d] * c.rest[d];
            }
        }
        let f_norm = self.norm_of_added(&load)?;
        drop(load);
        timing.assembly_s += start.elapsed().as_secs_f64();
        let mut record = crate::heat::steady::Record::with_norm(f_norm, p.tolerance);
        let mut heat = Vec::new();
        let (mut converged, mut iterations, mut setups, mut kept_pc) = (false, 0, 0, 0);
        let mut failure = None;
        let mut cg_iterations = Vec::new();
        let mut last_step = f64::INFINITY;
        let k_sym = &built.k_sym;
        (self.condensed.as_mut()).map_or(Ok(()), |c| c.start(built, u))?;
        for it in 0..=p.max_iterations {
            let start = Instant::now();
            // R = K u − F (+ m (c₀ u + rest)) + Σ R_Γ: this rank's elements, and its
            // own rows of the interfaces. With a k(T), the elements' R(u) and tangent
            // assembled at u.
            let mut r = vec![0.0; n];
            match built.nonlinear {
                true => {
                    let at_u = built.conduction_at(&self.faces, u, t);
                    (self.k_local, self.f_local) = agreed(at_u)?;
                    for (ri, fi) in r.iter_mut().zip(&self.f_local) {
                        *ri = -fi;
                    }
                }
                false => {
                    spmv_ref(
                        SparseColMatRef::new(k_sym.as_ref(), &self.k_local),
                        u,
                        &mut r,
                    );
                    for (ri, fi) in r.iter_mut().zip(&self.f_local) {
                        *ri -= fi;
                    }
                }
            }
            // (Only a ρc of T can fail, and only then do the ranks agree on it: no
            // collective on a linear step.)
            let stored = match capacity {
                Some(c) if c.of_t.is_some() => Some(agreed(c.terms(u, &built.touched))?),
                Some(c) => Some(c.terms(u, &built.touched)?),
                None => None,
            };
            if let Some((stored, _)) = &stored {
                for &d in &built.touched {
                    r[d] += stored[d];
                }
            }
            // A matrix that stays (linear interfaces, the same c₀, the same terms
            // switched on) needs the interfaces' residual alone.
            let c0 = capacity.map_or(0.0, |c| c.c0);
            // (The ties' after the flux terms'.)
            let on: Vec<bool> = built.iface.map_or_else(Vec::new, |i| {
                let ties = built.ties.as_ref().map_or(0, Ties::len);
                let flux = (0..i.flux_count()).map(|k| i.flux_on(k, t));
                flux.chain((0..ties).map(|k| i.tie_on(k, t))).collect()
            });
            let on_now = on.clone();
            let key = (self.symmetric).then_some((c0.to_bits(), on));
            let kept = key.is_some() && key == self.matrix_for;
            let values: Vec<f64> = built.touched.iter().map(|&d| r[d]).collect();
            self.r_vec.zero().map_err(petsc_err)?;
            self.r_vec
                .add(&built.touched_petsc, &values)
                .map_err(petsc_err)?;
            if let Some(i) = built.iface {
                // This rank's points' terms, into the rows of any rank.
                r.iter_mut().for_each(|x| *x = 0.0);
                let r_iface = &mut r;
                let residual = match kept {
                    true => i.residual(u, t, r_iface).map_err(failed),
                    false => Ok(None),
                };
                let iasm = &mut self.iasm;
                let mine = residual
                    .and_then(|heat| match heat {
                        Some(heat) => Ok(heat),
                        None => {
                            iasm.reset_couplings();
                            i.assemble(u, t, r_iface, iasm, built.first)
                                .map_err(failed)
                        }
                    })
                    .inspect(|_| {
                        if let (Some(ties), Some(i)) = (&built.ties, built.iface) {
                            let on = &on_now[i.flux_count()..];
                            ties.residual(u, r_iface, on);
                            if !kept {
                                ties.jacobian(iasm, on);
                            }
                        }
                    })
                    .and_then(|mine| {
                        // A point reads the field where it has terms: there it must be
                        // kept.
                        match (0..n).find(|&d| r_iface[d] != 0.0 && !built.scatter.kept[d]) {
                            Some(d) => Err(HeatError::Contact(format!(
                                "distributed solve: an interface point of rank {} reads dof {d}, which it was not sent",
                                layout.rank
                            ))),
                            None => Ok(mine),
                        }
                    });
                let mine = agreed(mine)?;
                let (rows, values): (Vec<PetscInt>, Vec<f64>) = (0..n)
                    .filter(|&d| r_iface[d] != 0.0)
                    .map(|d| (layout.petsc[d], r_iface[d]))
                    .unzip();
                self.r_vec.add(&rows, &values).map_err(petsc_err)?;
                heat = summed_heat(&built.world, &mine);
            }
            drop(r);
            self.r_vec.assemble().map_err(petsc_err)?;
            let bc_local = &built.bc_local;
            self.r_vec
                .with_local(local_rows, |v| bc_local.iter().for_each(|&i| v[i] = 0.0))
                .map_err(petsc_err)?;
            (self.condensed.as_mut()).map_or(Ok(()), |c| c.reduce(&mut self.r_vec, local_rows))?;
            let rn = self.r_vec.norm().map_err(petsc_err)?;
            timing.assembly_s += start.elapsed().as_secs_f64();
            if !rn.is_finite() {
                record.history.push(rn);
                failure = Some(format!("the residual is not finite at t = {t}"));
                break;
            }
            // The serial solve's stopping tests; they see |u| at its largest over the
            // ranks (they take only that). A time step's are the serial step's: done
            // after one solve of a linear step, else once the last update is within the
            // tolerance of max |u| — so the steps take the serial iterations and fail
            // (and are cut) where the serial ones do.
            // (A steady solve with a conductivity of T stops so too: the serial general
            // solver's test, on the size of the field without the multipliers.)
            let by_update = capacity.is_some() || built.nonlinear;
            let below = if by_update { built.primal() } else { n };
            let u_max = built.scatter.u_max(&built.world, layout, &u[..below]);
            let done = match by_update {
                true => {
                    record.history.push(rn);
                    let u_max = u_max.max(f64::MIN_POSITIVE);
                    it > 0 && (self.symmetric || last_step <= p.tolerance * u_max)
                }
                false => record.converged_at(it, rn, last_step, &[u_max], self.symmetric),
            };
            if done {
                converged = true;
                break;
            }
            if it == p.max_iterations {
                break;
            }
            iterations += 1;
            // J = K (+ c₀ m) + J_Γ: every entry this rank made, the interface rows it
            // owns; set again only when its values change.
            // A Krylov method keeps its hierarchy for a new matrix of the same c₀ while
            // its solves do not degrade.
            let mut reused = false;
            if !kept {
                let start = Instant::now();
                self.set_matrix(stored.as_ref().map(|(_, diagonal)| diagonal.as_slice()))?;
                timing.assembly_s += start.elapsed().as_secs_f64();
                let start = Instant::now();
                reused = self.method != Method::MumpsLu && self.hierarchy.serves(c0);
                match reused {
                    true => {
                        self.ksp.keep_preconditioner(true).map_err(petsc_err)?;
                        kept_pc += 1;
                    }
                    false => setups += self.set_up(c0)?,
                }
                timing.factor_s += start.elapsed().as_secs_f64();
                self.matrix_for = key;
            }
            let start = Instant::now();
            if capacity.is_some() && self.method == Method::CgAmg {
                self.step_tolerance(u)?;
            }
            // The increment: J Δu = −R (Δu = 0 on the Dirichlet rows, whose R is 0).
            self.r_vec
                .with_local(local_rows, |v| v.iter_mut().for_each(|x| *x = -*x))
                .map_err(petsc_err)?;
            let mut solved = self.ksp.solve(&self.r_vec, &mut self.du_vec);
            if reused && solved.as_ref().is_err_and(PetscError::is_divergence) {
                // The kept hierarchy failed: one for this matrix, and the solve again.
                setups += self.set_up(c0)?;
                solved = self.ksp.solve(&self.r_vec, &mut self.du_vec);
            }
            let its = match solved {
                Ok(its) => its,
                Err(e) if e.is_divergence() => {
                    failure = Some(format!("the linear solve failed at t = {t}: {e}"));
                    break;
                }
                Err(e) => return Err(petsc_err(e)),
            };
            (self.condensed.as_mut()).map_or(Ok(()), |c| c.expand(&mut self.du_vec, local_rows))?;
            let mine = self
                .du_vec
                .with_local(local_rows, |v| v.to_vec())
                .map_err(petsc_err)?;
            last_step = built.scatter.update(&built.world, layout, &mine, u);
            timing.solve_s += start.elapsed().as_secs_f64();
            if self.method != Method::MumpsLu {
                cg_iterations.push(its);
                self.hierarchy.solved(its);
            }
        }
        (self.condensed.as_mut().filter(|_| converged))
            .map_or(Ok(()), |c| c.multipliers(built, u))?;
        let ties = built.ties.as_ref();
        Ok(Solved {
            converged,
            failure,
            iterations,
            history: record.history,
            heat,
            tie_heat: ties.map_or_else(Vec::new, |t| t.heat(&built.world, u)),
            cg_iterations,
            setups,
            kept: kept_pc,
            timing,
        })
    }

    /// The preconditioner (or factorisation) made for the matrix set, of `c0`: one set-up.
    fn set_up(&mut self, c0: f64) -> Result<usize, HeatError> {
        self.ksp.keep_preconditioner(false).map_err(petsc_err)?;
        self.ksp.set_up().map_err(petsc_err)?;
        self.hierarchy.set_up(c0);
        Ok(1)
    }

    /// A time step's CG stops as the serial one, which solves the step's own system
    /// `J x = b` from the predictor `u` to ‖b − J x‖ ≤ 1e-11 ‖b‖: the increment from 0
    /// (`r_vec` holding `R(u)`, its Dirichlet rows 0) stops at the same true residual,
    /// 1e-11 ‖J u − R(u)‖. Relative to ‖R‖ instead, every step would reduce its small
    /// residual by 11 orders (tens of iterations where the serial takes a few).
    fn step_tolerance(&mut self, u: &[f64]) -> Result<(), HeatError> {
        let layout = &self.built.layout;
        let local_rows = layout.rows().len();
        self.x_vec
            .with_local(local_rows, |v| {
                for (x, &d) in v.iter_mut().zip(&layout.owned) {
                    *x = u[d];
                }
            })
            .map_err(petsc_err)?;
        self.a
            .mult(&self.x_vec, &mut self.du_vec)
            .map_err(petsc_err)?;
        let r = self
            .r_vec
            .with_local(local_rows, |v| v.to_vec())
            .map_err(petsc_err)?;
        self.du_vec
            .with_local(local_rows, |v| {
                v.iter_mut().zip(&r).for_each(|(b, r)| *b -= r)
            })
            .map_err(petsc_err)?;
        let b = self.du_vec.norm().map_err(petsc_err)?;
        // (Only rank 0 logs: nothing collective inside the macro.)
        log::debug!(
            "time step's system: ‖b‖ = {b:.3e}: CG to {:.3e}",
            AMG_TOLERANCE * b
        );
        self.ksp
            .set_tolerances(1e-300, AMG_TOLERANCE * b)
            .map_err(petsc_err)
    }

    /// The matrix `K + C + J_Γ`, `C` the capacity's diagonal per local dof (of a time
    /// step; Dirichlet rows and columns the identity's).
    fn set_matrix(&mut self, capacity: Option<&[f64]>) -> Result<(), HeatError> {
        let built = self.built;
        self.a.zero().map_err(petsc_err)?;
        // (A tangent of T: its zeros of one iterate are not those of the next.)
        let tangent = built.nonlinear;
        match capacity {
            Some(c) => {
                let mut k = self.k_local.clone();
                for &(d, slot) in &self.diagonal {
                    k[slot] += c[d];
                }
                add_rows(&mut self.a, &self.k_rows, &k, tangent)?;
            }
            None => add_rows(&mut self.a, &self.k_rows, &self.k_local, tangent)?,
        }
        let mut i_values = Vec::new();
        self.iasm.values_into(&mut i_values)?;
        // Its zeros too: a term switched off (a toggle, h = 0) leaves zeros where a later
        // matrix has values, and PETSc drops the places its first assembly leaves empty.
        add_rows(&mut self.a, &self.i_rows, &i_values, true)?;
        self.a.assemble().map_err(petsc_err)?;
        self.a
            .zero_rows_columns(&built.bc_rows)
            .map_err(petsc_err)?;
        (self.condensed.as_mut()).map_or(Ok(()), |c| c.set_matrix(&self.a, &mut self.ksp))
    }
}
