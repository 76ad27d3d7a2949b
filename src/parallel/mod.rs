//! `seam run` on MPI (`--features mpi`, started by `mpirun`): the mesh's elements
//! partitioned by METIS, the contact search distributed ([`search`]: each rank pairs the
//! side-A points of its own faces), each rank assembling its own elements' conduction and
//! its own side-A points' interface terms into a PETSc distributed matrix, the solve by
//! PETSc (CG + BoomerAMG, or MUMPS LU), the solution gathered at the end so that rank 0 writes
//! what a serial run writes. What is and is not distributed is listed in
//! `docs/parallel.md`.
//!
//! Entry points: [`start`] (the binary, before a run), then the hooks the run calls —
//! [`is_root`] (who writes files and prints), [`share_mesh`] and [`receive_mesh`] (rank
//! 0 reads the mesh and, for a run the distributed steady solve takes, sends every other
//! rank only its part: `part`), the checks every rank follows rank 0 in
//! ([`root_verdict`], [`any_rank`]), [`share_surfaces`] and [`faces_in_contact`] (what
//! rank 0 or the other ranks work out for the ranks holding parts), [`search_pair`] (the
//! contact search of one pair of surfaces, distributed), [`extended_mesh`] (a rank's part
//! with the side-B elements its points paired with), [`steady`] (the linear or
//! Newton-nonlinear steady solve), [`transient`] (a linear transient run's steps, its
//! assembly distributed as the steady solve's), [`general_solve`] (the linear solves of the general,
//! stepped, solver: its assembly replicated on every rank, each step's system solved by
//! PETSc over all ranks), [`linear_solver`] (the summary's linear solver) and
//! [`report_holdings`] (what each rank held, in rank 0's log).
//!
//! Without the feature, or without a launcher, every hook is the serial path: one
//! process, rank 0, nothing refused.

use crate::heat::HeatError;
use crate::heat::steady::{SteadyProblem, SteadySolution};

#[cfg(feature = "mpi")]
mod conduction;
#[cfg(feature = "mpi")]
mod general;
#[cfg(feature = "mpi")]
mod layout;
#[cfg(feature = "mpi")]
pub(crate) mod part;
#[cfg(feature = "mpi")]
pub mod petsc;
#[cfg(feature = "mpi")]
mod reuse;
#[cfg(feature = "mpi")]
mod rows;
#[cfg(feature = "mpi")]
pub mod search;
#[cfg(feature = "mpi")]
mod session;
#[cfg(feature = "mpi")]
mod share;
#[cfg(feature = "mpi")]
mod steady;
#[cfg(feature = "mpi")]
mod stepped;
#[cfg(feature = "mpi")]
mod ties;
#[cfg(feature = "mpi")]
mod wire;

#[cfg(feature = "mpi")]
pub use general::GeneralSolve;
#[cfg(feature = "mpi")]
pub use session::{Session, start};

/// Without the feature there is no distributed solve: [`general_solve`] never makes one.
#[cfg(not(feature = "mpi"))]
pub enum GeneralSolve {}

#[cfg(not(feature = "mpi"))]
impl GeneralSolve {
    pub fn solve(
        &mut self,
        _: &faer::sparse::SparseColMat<usize, f64>,
        _: &[f64],
        _: Option<&[f64]>,
        _: System,
    ) -> Result<Solution, HeatError> {
        match *self {}
    }
}

/// The kind of a step system, as the general solver's serial choice of method sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum System {
    /// Symmetric positive definite, at or above the AMG threshold.
    Spd,
    /// The coupled thermal–electrical Jacobian at or above the threshold; the voltages
    /// (and what follows them) from dof `at` on.
    Coupled { at: usize },
    /// Unsymmetric with no voltage (a temperature-dependent conductivity or
    /// conductance), at or above the threshold.
    Unsymmetric,
    /// Below the threshold, or indefinite (multiplier ties).
    Direct,
}

impl System {
    /// Why its method, for the run's summary.
    pub fn why(self) -> &'static str {
        match self {
            System::Spd => {
                "symmetric positive definite, at or above the AMG threshold → CG + BoomerAMG"
            }
            System::Coupled { .. } => {
                "unsymmetric coupled thermal–electrical Newton steps at or above the AMG threshold → GMRES, BoomerAMG on the temperature and voltage blocks"
            }
            System::Unsymmetric => {
                "unsymmetric Newton steps (a temperature-dependent law) at or above the AMG threshold → GMRES + BoomerAMG"
            }
            System::Direct => {
                "below the AMG threshold, or with multipliers (indefinite) → MUMPS LU"
            }
        }
    }
}

/// A distributed solve's answer: the whole solution on every rank.
#[derive(Clone, Debug, Default)]
pub struct Solution {
    pub x: Vec<f64>,
    /// Krylov iterations (0 for a direct solve).
    pub iterations: usize,
    /// Seconds setting up (matrix values, factorisation or AMG hierarchy) and solving.
    pub setup_s: f64,
    pub solve_s: f64,
}

/// The distributed linear solves of the general (stepped) solver when the run is
/// distributed, else `None` (the caller solves serially).
pub fn general_solve() -> Option<GeneralSolve> {
    #[cfg(feature = "mpi")]
    {
        world().map(|_| GeneralSolve::new())
    }
    #[cfg(not(feature = "mpi"))]
    {
        None
    }
}

#[cfg(feature = "mpi")]
thread_local! {
    /// The method of the last distributed solve and why, for the run's summary.
    static LAST: std::cell::RefCell<Option<(petsc::Method, std::borrow::Cow<'static, str>)>> =
        const { std::cell::RefCell::new(None) };
}

#[cfg(feature = "mpi")]
fn record(method: petsc::Method, why: impl Into<std::borrow::Cow<'static, str>>) {
    LAST.with(|l| *l.borrow_mut() = Some((method, why.into())));
}

/// Why the distributed steady solve took `method` for a Jacobian that is `symmetric`
/// or not, with mortar ties with multipliers (`Some(condensed)`: dual ones condensed)
/// or without.
#[cfg(feature = "mpi")]
fn steady_reason(method: petsc::Method, symmetric: bool, ties: Option<bool>) -> &'static str {
    use petsc::Method;
    match (method, symmetric, ties) {
        (Method::CgAmg, _, Some(_)) => {
            "dual mortar ties condensed to a symmetric positive definite system, at or above the AMG threshold → CG + BoomerAMG"
        }
        (_, true, Some(true)) => {
            "dual mortar ties condensed to a symmetric positive definite system, below the AMG threshold (or linear_solver = \"direct\") → MUMPS LU"
        }
        (_, _, Some(_)) => {
            "mortar ties with Lagrange multipliers make the system indefinite → MUMPS LU"
        }
        (Method::MumpsLu, true, None) => {
            "below the AMG threshold (or linear_solver = \"direct\") → MUMPS LU"
        }
        (Method::MumpsLu, false, None) => {
            "a temperature-dependent conductance makes the Jacobian unsymmetric → MUMPS LU"
        }
        (Method::GmresAmg, _, None) => {
            "a temperature-dependent conductance makes the Jacobian unsymmetric, at or above the AMG threshold → GMRES + BoomerAMG"
        }
        _ => "symmetric positive definite, at or above the AMG threshold → CG + BoomerAMG",
    }
}

/// This process's rank and the number of ranks, when a run is distributed.
pub fn world() -> Option<(usize, usize)> {
    #[cfg(feature = "mpi")]
    {
        session::world()
    }
    #[cfg(not(feature = "mpi"))]
    {
        None
    }
}

/// Whether this process writes the results and prints the summary: rank 0, or a run
/// that is not distributed.
pub fn is_root() -> bool {
    world().is_none_or(|(rank, _)| rank == 0)
}

/// The distributed steady solve when the run is distributed, else `None` (the caller
/// solves serially).
pub fn steady(p: &SteadyProblem<'_>) -> Option<Result<SteadySolution, HeatError>> {
    #[cfg(feature = "mpi")]
    {
        world().map(|_| steady::solve(p))
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = p;
        None
    }
}

/// The laws of a run per block of its (rank's) mesh, for the distributed steps.
#[derive(Clone, Copy, Debug)]
pub struct Laws<'s> {
    /// k(T, x, t), W/m/K.
    pub conductivity: &'s [crate::heat::law::Law],
    /// ρc(T, x, t), J/m³/K.
    pub capacity: &'s [crate::heat::law::Law],
    /// Q(T, x, t), W/m³ (a constant 0: none).
    pub source: &'s [crate::heat::law::Law],
}

/// A transient run's time stepping, for [`transient`] (or one steady solve: `steady`).
pub struct Stepping<'s> {
    /// The laws of the run's materials and sources per block of the problem's mesh: its
    /// conduction is assembled at every Newton iterate when one depends on temperature
    /// (or it has radiation), its sources taken at each step's time when they depend on
    /// time.
    pub laws: Laws<'s>,
    /// One steady solve at `start` instead of steps (the general solver's nonlinear
    /// steady solve: a conductivity of T), reported as its step 0.
    pub steady: bool,
    pub scheme: crate::heat::transient::Scheme,
    pub start: f64,
    pub end: f64,
    /// The first step (every step, without `adaptive`).
    pub dt: f64,
    /// Steps chosen by the local error estimate.
    pub adaptive: Option<crate::heat::transient::Adaptive>,
    /// The least step a failing step may be cut to, without `adaptive` (with it, its
    /// own `dt_min`).
    pub dt_min: f64,
    /// The temperature at each node of the rank's mesh at `start` (the nodes after it,
    /// a contact partner's, take their owners' values).
    pub initial: &'s [f64],
    /// A transient run from a checkpoint instead of `start` and `initial`: on rank 0 the
    /// checkpoint's state (the serial dof order, the whole problem's); on the other
    /// ranks any state (rank 0's is sent them).
    pub restart: Option<&'s crate::heat::transient::State>,
    /// The Dirichlet values and face conditions at a time.
    #[allow(clippy::type_complexity)]
    pub loads: &'s dyn Fn(
        f64,
    ) -> Result<
        (Vec<(crate::mesh::NodeId, f64)>, Vec<crate::heat::FaceBc>),
        HeatError,
    >,
}

/// The steps of a transient run (or the one steady solve of `s.steady`) with its
/// assembly distributed when the run is distributed, else `None` (the caller steps serially): `p` the problem at the start,
/// `on_step` each accepted step (on rank 0 the whole state, on any other rank its own
/// dofs).
pub fn transient(
    p: &SteadyProblem<'_>,
    s: &Stepping<'_>,
    on_step: &mut dyn FnMut(
        &crate::heat::transient::StepReport,
        &crate::heat::transient::State,
        &crate::assembly::DofMap,
    ) -> Result<(), HeatError>,
) -> Option<Result<crate::heat::transient::Outcome, HeatError>> {
    #[cfg(feature = "mpi")]
    {
        world().map(|_| stepped::solve(p, s, on_step))
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (p, s, on_step);
        None
    }
}

/// `a`'s points paired with `b`'s faces by the distributed search when the run is
/// distributed (the serial pairing, whole on every rank of a run that holds the whole
/// mesh; see [`search`]), else `None` (the caller searches serially).
pub fn search_pair(
    mesh: &crate::mesh::Mesh,
    a: &crate::search::pairing::SurfaceGeometry,
    b: &crate::search::pairing::SurfaceGeometry,
    settings: &crate::search::SearchSettings,
    integration: crate::search::pairing::Integration,
    subdomain: Option<crate::search::pairing::Sphere>,
) -> Option<Result<crate::search::pairing::SearchResult, String>> {
    #[cfg(feature = "mpi")]
    {
        world().map(|_| search::search_pair(mesh, a, b, settings, integration, subdomain))
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (mesh, a, b, settings, integration, subdomain);
        None
    }
}

/// The name and the reason of the linear solver the last distributed solve ran (PETSc's
/// method and the ranks), for the run's summary; `None` when the run is not distributed.
pub fn linear_solver() -> Option<(String, String)> {
    #[cfg(feature = "mpi")]
    {
        let (_, size) = world()?;
        let (method, why) = LAST.with(|l| l.borrow().clone())?;
        // PETSc applies the user's options over the choice: say so.
        let over = std::env::var("PETSC_OPTIONS")
            .ok()
            .filter(|o| !o.trim().is_empty())
            .map_or(String::new(), |o| {
                format!("; PETSC_OPTIONS \"{}\" applied over it", o.trim())
            });
        Some((
            method.name().into(),
            format!("MPI, {size} rank(s): {why}{over}"),
        ))
    }
    #[cfg(not(feature = "mpi"))]
    {
        None
    }
}

/// How rank 0 lets the other ranks have the mesh.
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub(crate) enum MeshPlan<'m> {
    /// The run stops (rank 0 found the problem or its mesh wrong).
    Stop,
    /// Every rank reads the whole mesh.
    Whole,
    /// Partition this mesh and send every other rank its part; with, per block, the work
    /// of assembling one of its elements when the blocks' differ (the parts then balance
    /// that work as well as their elements).
    Parts(&'m crate::mesh::Mesh, Option<Vec<u32>>),
}

/// What a rank other than 0 gets from [`receive_mesh`].
#[cfg_attr(not(feature = "mpi"), allow(dead_code))]
pub(crate) enum MeshShare {
    Stopped,
    Whole,
    /// Its local mesh (its elements and a ghost layer), its part kept.
    Local(Box<crate::mesh::Mesh>),
}

/// A new run starts: forget the part of an earlier one.
pub(crate) fn start_run() {
    #[cfg(feature = "mpi")]
    part::clear();
}

/// On rank 0 of a distributed run: carry out `plan` (collective with [`receive_mesh`] on
/// the others). With `Parts`, the mesh is partitioned first; a partition that fails
/// stops every rank (and is the error returned here). Nothing serially.
pub(crate) fn share_mesh(plan: MeshPlan<'_>) -> Result<(), String> {
    #[cfg(feature = "mpi")]
    {
        if world().is_none() {
            return Ok(());
        }
        match plan {
            MeshPlan::Stop => {
                part::broadcast_u8(0);
                Ok(())
            }
            MeshPlan::Whole => {
                part::broadcast_u8(1);
                Ok(())
            }
            MeshPlan::Parts(mesh, costs) => match part::partition_for_ranks(mesh, costs.as_deref())
            {
                Err(e) => {
                    part::broadcast_u8(0);
                    Err(e)
                }
                Ok(parts) => {
                    part::broadcast_u8(2);
                    if let Some(path) = std::env::var_os("SEAM_PARTITION_FILE") {
                        write_partition(&path, &parts);
                    }
                    let solid = part::solid_blocks(mesh);
                    let weighted = costs
                        .as_ref()
                        .filter(|c| solid.iter().any(|&b| c[b] != c[solid[0]]));
                    if let Some(costs) = weighted {
                        let mut work = vec![0u64; world().map_or(1, |(_, size)| size)];
                        for &b in &solid {
                            for e in mesh.blocks[b].elems() {
                                work[parts[e.index()] as usize] += u64::from(costs[b]);
                            }
                        }
                        log::info!(
                            "the parts balance their elements and their assembly work (per block {costs:?} a kernel's each): work per rank {work:?}"
                        );
                    }
                    let sent = part::distribute(mesh, parts);
                    log::info!(
                        "the mesh partitioned: each rank other than 0 holds its own elements and a ghost layer (elements per rank: own {:?}, ghosts {:?}; nodes {:?})",
                        sent.iter().map(|h| h.owned).collect::<Vec<_>>(),
                        sent.iter().skip(1).map(|h| h.ghost).collect::<Vec<_>>(),
                        sent.iter().skip(1).map(|h| h.nodes).collect::<Vec<_>>()
                    );
                    Ok(())
                }
            },
        }
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = plan;
        Ok(())
    }
}

/// The partition, one line per element (in the mesh's dense order): its rank
/// (`SEAM_PARTITION_FILE`, for tests that check what each rank holds).
#[cfg(feature = "mpi")]
fn write_partition(path: &std::ffi::OsStr, parts: &[u32]) {
    let text: String = parts.iter().map(|p| format!("{p}\n")).collect();
    if let Err(e) = std::fs::write(path, text) {
        log::warn!(
            "SEAM_PARTITION_FILE: cannot write {}: {e}",
            path.to_string_lossy()
        );
    }
}

/// On a rank other than 0 of a distributed run: how it gets the mesh, as rank 0 says
/// ([`share_mesh`]).
pub(crate) fn receive_mesh() -> Result<MeshShare, String> {
    #[cfg(feature = "mpi")]
    {
        if world().is_none() {
            return Ok(MeshShare::Whole);
        }
        match part::broadcast_u8(0) {
            0 => Ok(MeshShare::Stopped),
            1 => Ok(MeshShare::Whole),
            _ => part::receive().map(|m| MeshShare::Local(Box::new(m))),
        }
    }
    #[cfg(not(feature = "mpi"))]
    Ok(MeshShare::Whole)
}

/// Whether the ranks other than 0 hold only their part of the mesh in this run.
pub(crate) fn mesh_is_distributed() -> bool {
    #[cfg(feature = "mpi")]
    {
        part::distributed()
    }
    #[cfg(not(feature = "mpi"))]
    false
}

/// A nodal field read by rank 0 alone (`whole`, its values at the whole mesh's nodes,
/// `None` where it could not, and on the other ranks) at the nodes of this rank's mesh:
/// collective where the mesh is distributed, each rank getting its nodes' values from
/// rank 0, `None` on every rank when rank 0 has none. Otherwise `whole` itself.
pub(crate) fn nodal_from_root(whole: Option<Vec<f64>>) -> Option<Vec<f64>> {
    #[cfg(feature = "mpi")]
    {
        if part::distributed() {
            return part::nodal_from_root(whole);
        }
    }
    whole
}

/// Rank 0's `local` on every rank of a distributed run (collective), `local` serially:
/// the verdict of a check whose findings only rank 0 can trust (it holds the whole mesh)
/// or that only rank 0 makes (its output folder).
pub(crate) fn root_verdict(local: bool) -> bool {
    #[cfg(feature = "mpi")]
    {
        if world().is_some() {
            return part::broadcast_u8(local as u8) != 0;
        }
    }
    local
}

/// Whether `local` holds on some rank (collective under MPI): a surface has faces, say,
/// when each rank holds some of them.
pub(crate) fn any_rank(local: bool) -> bool {
    #[cfg(feature = "mpi")]
    {
        if world().is_some() {
            use mpi::traits::CommunicatorCollectives;
            let world = session::comm();
            let mut any = 0u8;
            world.all_reduce_into(
                &(local as u8),
                &mut any,
                mpi::collective::SystemOperation::max(),
            );
            return any != 0;
        }
    }
    local
}

/// Whether `ok` holds on every rank (collective under MPI); the lowest rank where it
/// does not, otherwise.
pub(crate) fn all_ranks_ok(ok: bool) -> Result<(), usize> {
    #[cfg(feature = "mpi")]
    {
        if world().is_some() {
            return share::all_ok(&session::comm(), ok);
        }
    }
    if ok { Ok(()) } else { Err(0) }
}

/// The whole mesh's size (bounding-box diagonal), on a rank that holds a part of it too.
pub(crate) fn model_size(mesh: &crate::mesh::Mesh) -> f64 {
    #[cfg(feature = "mpi")]
    {
        if let Some(size) = part::with(|p| p.distributed.then_some(p.model_size)).flatten() {
            return size;
        }
    }
    mesh.model_size()
}

/// The contact surfaces of one definition: `build` (on this rank's mesh), or on a
/// distributed mesh rank 0's, each other rank getting its share (collective).
pub(crate) fn share_surfaces(
    mesh: &crate::mesh::Mesh,
    build: impl FnOnce() -> crate::surface::SurfaceSet,
) -> crate::surface::SurfaceSet {
    #[cfg(feature = "mpi")]
    {
        if mesh_is_distributed() {
            return share::surfaces(mesh, build);
        }
    }
    let _ = mesh;
    build()
}

/// The faces in contact, as each rank's points found them (`local`), with on a
/// distributed mesh those of this rank's elements that other ranks' points touched
/// (collective).
pub(crate) fn faces_in_contact(
    local: std::collections::HashSet<crate::mesh::Side>,
) -> std::collections::HashSet<crate::mesh::Side> {
    #[cfg(feature = "mpi")]
    {
        if mesh_is_distributed() {
            return share::faces_in_contact(local);
        }
    }
    local
}

/// A pairing as the run's scene keeps it: the points, and on a rank other than 0 of a
/// distributed mesh the side-B faces they paired with (in its local numbers).
pub(crate) type RunPairing = (
    crate::search::pairing::SearchResult,
    Option<crate::search::pairing::SurfaceGeometry>,
);

/// The run's search of one pair when the run is distributed (see [`search`]): the
/// overclosure of matched points treated with `overclosure`; `None` serially.
pub(crate) fn search_in_run(
    mesh: &crate::mesh::Mesh,
    (a, b): (
        &crate::search::pairing::SurfaceGeometry,
        &crate::search::pairing::SurfaceGeometry,
    ),
    settings: &crate::search::SearchSettings,
    integration: crate::search::pairing::Integration,
    subdomain: Option<crate::search::pairing::Sphere>,
    overclosure: Option<crate::search::Overclosure>,
) -> Option<Result<RunPairing, String>> {
    #[cfg(feature = "mpi")]
    {
        world().map(|_| {
            search::search(mesh, a, b, settings, integration, subdomain, overclosure)
                .map(|f| (f.result, f.side_b))
        })
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = (mesh, a, b, settings, integration, subdomain, overclosure);
        None
    }
}

/// This rank's mesh with the side-B elements of other ranks its points paired with
/// appended, and per block the block of `mesh` it copies — on a rank holding a part
/// whose points paired with such elements; `None` otherwise (`mesh` is the one).
pub(crate) fn extended_mesh(mesh: &crate::mesh::Mesh) -> Option<(crate::mesh::Mesh, Vec<usize>)> {
    #[cfg(feature = "mpi")]
    {
        part::extended_mesh(mesh)
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = mesh;
        None
    }
}

/// Whether rank 0 can partition `mesh` and send each rank its part (why not, otherwise).
pub(crate) fn can_distribute(mesh: &crate::mesh::Mesh) -> Result<(), String> {
    #[cfg(feature = "mpi")]
    {
        part::can_distribute(mesh)
    }
    #[cfg(not(feature = "mpi"))]
    {
        let _ = mesh;
        Err("built without the `mpi` feature".into())
    }
}

/// What each rank holds — its elements (own, ghosts, contact partners), nodes, PETSc
/// rows — and its peak resident memory so far, in rank 0's log, one line per rank
/// (collective under MPI; nothing serially).
pub(crate) fn report_holdings(mesh: &crate::mesh::Mesh) {
    #[cfg(feature = "mpi")]
    {
        use mpi::traits::{Communicator, CommunicatorCollectives};
        if world().is_none() {
            return;
        }
        let world = session::comm();
        let h = part::with(part::Part::counts).unwrap_or(part::Holdings {
            owned: mesh.num_elems(),
            nodes: mesh.num_nodes(),
            ..Default::default()
        });
        let peak = peak_resident_mib().unwrap_or(f64::NAN);
        let distributed = mesh_is_distributed();
        let mine = [
            h.owned as f64,
            h.ghost as f64,
            h.partners as f64,
            h.nodes as f64,
            h.partner_nodes as f64,
            h.rows as f64,
            peak,
        ];
        let mut all = vec![0.0; mine.len() * world.size() as usize];
        world.all_gather_into(&mine[..], &mut all[..]);
        if world.rank() != 0 {
            return;
        }
        for (r, c) in all.chunks_exact(mine.len()).enumerate() {
            if r == 0 || !distributed {
                log::info!(
                    "rank {r} holds the whole mesh: {} elements ({} own), {} nodes, {} PETSc rows; peak resident memory {:.1} MiB",
                    c[0] + c[1] + c[2],
                    c[0],
                    c[3],
                    c[5],
                    c[6]
                );
            } else {
                log::info!(
                    "rank {r} holds its part: {} elements ({} own, {} ghosts, {} contact partners), {} nodes (and {} of contact partners), {} PETSc rows; peak resident memory {:.1} MiB",
                    c[0] + c[1] + c[2],
                    c[0],
                    c[1],
                    c[2],
                    c[3],
                    c[4],
                    c[5],
                    c[6]
                );
            }
        }
    }
    #[cfg(not(feature = "mpi"))]
    let _ = mesh;
}

/// The whole problem's temperature unknowns, from this rank's `local` count: on a rank
/// holding a part of the mesh, every rank's rows; `local` otherwise.
pub(crate) fn global_unknowns(local: usize) -> usize {
    #[cfg(feature = "mpi")]
    {
        if let Some(n) = part::with(|p| p.distributed.then(|| p.starts[p.size])).flatten() {
            return n;
        }
    }
    local
}

/// This process's peak resident memory (`VmHWM` of `/proc/self/status`), MiB.
#[cfg(feature = "mpi")]
fn peak_resident_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib / 1024.0)
}
