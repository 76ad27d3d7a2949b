//! How a run's mesh reaches the ranks of a distributed run (`mpirun`, `--features mpi`;
//! docs/parallel.md). Rank 0 reads the mesh and checks the physics on it; then, when the
//! run is one the distributed steady solve takes from start to end ([`distributable`]),
//! it partitions the mesh and sends every other rank only its part (its elements, a
//! ghost layer, their side and node sets); otherwise every rank reads the whole mesh, as
//! the general solver (whose assembly is replicated) needs. The other ranks wait for rank
//! 0's word before they read anything ([`mesh_for_rank`]).
//!
//! Ranks other than 0 that hold a part check nothing themselves: what they find on their
//! part (a surface or a set that is empty there, a block with no condition on it) says
//! nothing about the problem, which rank 0 checks whole. They follow rank 0's verdict at
//! each check of the run ([`stop`]) and print nothing, as every rank other than 0 does.

use crate::diag::{Diagnostics, SourceMap};
use crate::mesh::Mesh;
use crate::parallel::{self, MeshPlan, MeshShare};

use super::physics::Physics;
use super::problem::ProblemFile;
use super::{RunError, RunOptions};

/// The mesh this rank runs on, and the seconds reading it took: rank 0 (and a serial
/// run) reads it whole; another rank gets its part from rank 0, or reads it whole when
/// rank 0 says so. A rank other than 0 that rank 0 stopped returns an input error with
/// no diagnostics (rank 0 reports them).
pub(super) fn mesh_for_rank(
    file: &ProblemFile,
    options: &RunOptions,
) -> Result<(Mesh, f64), RunError> {
    if parallel::is_root() {
        return file.read_mesh(options).inspect_err(|_| {
            // The others wait for the mesh: they stop too.
            let _ = parallel::share_mesh(MeshPlan::Stop);
        });
    }
    match parallel::receive_mesh().map_err(RunError::Solve)? {
        MeshShare::Stopped => Err(quiet()),
        MeshShare::Whole => file.read_mesh(options),
        MeshShare::Local(mesh) => Ok((*mesh, 0.0)),
    }
}

/// On rank 0 of a distributed run, once the physics is checked on the whole mesh
/// (`ready`): tell the others how they get the mesh — their parts, the whole mesh, or
/// nothing (the run stops). Nothing on other ranks or serially.
pub(super) fn share_mesh(
    file: &ProblemFile,
    physics: &Physics<'_>,
    ready: bool,
) -> Result<(), RunError> {
    if !parallel::is_root() || parallel::world().is_none() {
        return Ok(());
    }
    let plan = if !ready {
        MeshPlan::Stop
    } else {
        match distributable(file, physics) {
            Ok(()) => MeshPlan::Parts(physics.mesh, Some(assembly_costs(file, physics))),
            Err(why) => {
                log::info!("every rank reads the whole mesh: {why}");
                MeshPlan::Whole
            }
        }
    };
    parallel::share_mesh(plan).map_err(RunError::Solve)
}

/// What a law in Lua adds to the work of assembling an element, in units of the
/// element's kernel: an estimate. Each quadrature point calls it for its value and two
/// differences (the three took 0.34 µs when measured alone for 46c6fd9, so 2.7 µs over a
/// Hex8's 8 points); the weight was not fitted to kernel timings, but with it the
/// partition took the k(T) scaling case's assembly from 1.39× to 1.84× on 2 ranks
/// (docs/parallel.md).
const LUA_COST: u32 = 3;

/// Per block of the mesh, the work of assembling one of its elements, in kernels: one,
/// and [`LUA_COST`] for each of its conductivity, capacity (of a transient run) and
/// source that is a Lua expression. The partition balances it as well as the elements
/// where the blocks differ (a Lua k(T) in one block, a table in the other: each rank
/// would otherwise get equal elements and unequal work).
fn assembly_costs(file: &ProblemFile, physics: &Physics<'_>) -> Vec<u32> {
    use crate::heat::law::Law;
    let lua = |l: &Law| u32::from(matches!(l, Law::Lua { .. }));
    let laws = &physics.materials.laws;
    (0..physics.mesh.blocks.len())
        .map(|b| {
            let capacity = laws
                .get(b)
                .filter(|_| file.transient)
                .map_or(0, |l| lua(&l.capacity));
            let conductivity = laws.get(b).map_or(0, |l| lua(&l.conductivity));
            let source = physics.block_source.get(b).map_or(0, lua);
            1 + LUA_COST * (conductivity + capacity + source)
        })
        .collect()
}

/// Whether this rank follows rank 0's checks instead of its own: a rank other than 0
/// holding a part of the mesh.
pub(super) fn follows_root() -> bool {
    parallel::mesh_is_distributed() && !parallel::is_root()
}

/// Whether the run stops at a check that found `diags`: rank 0's verdict on every rank
/// of a distributed run (collective), the run's own otherwise. A rank that follows rank
/// 0 drops its own diagnostics (they say nothing of the problem; it prints none).
pub(super) fn stop(diags: &mut Diagnostics) -> bool {
    let stop = parallel::root_verdict(diags.has_errors());
    if follows_root() {
        *diags = Diagnostics::default();
    }
    stop
}

/// The error of a rank that stops because rank 0 did (rank 0 reports why).
pub(super) fn quiet() -> RunError {
    RunError::Input(Diagnostics::default(), SourceMap::default())
}

/// Whether the run is one the distributed steady solve, or the distributed linear
/// transient steps, take from start to end, so that the ranks other than 0 can hold
/// their part of the mesh only: steady or transient, one temperature field (its laws
/// and sources of T, x and t, radiation or not),
/// no moving or dying surfaces, every block solid, and a
/// contact deck whose enforcements need nothing whole (no voltage or species enforcement, no
/// `Align_Surface` periodicity, no `Auto Subset`). The reason why not, otherwise.
pub(super) fn distributable(file: &ProblemFile, physics: &Physics<'_>) -> Result<(), String> {
    let p = &file.problem;
    let refuse = |why: &str| Err(why.to_string());
    if p.displacement.is_some() || !p.death.is_empty() {
        return refuse("surfaces that move or die");
    }
    if physics.field_names.len() != 1 || physics.materials.electric() || physics.species.any() {
        return refuse("not one temperature field (the general solver)");
    }
    crate::parallel::can_distribute(physics.mesh)?;
    let Some(contact) = &p.contact else {
        return Ok(());
    };
    let loaded = crate::deck::load(&file.dir.join(&contact.file));
    if loaded.diagnostics.has_errors() {
        return refuse("the contact deck has errors");
    }
    let fields: Vec<&str> = physics.field_names.iter().map(String::as_str).collect();
    match crate::scene::needs_whole_mesh(&loaded, &fields) {
        Some(why) => refuse(why),
        None => Ok(()),
    }
}
