//! MPI and PETSc for the life of a distributed run: started by [`start`] when the process
//! was launched by `mpirun` (or another MPI launcher), ended when the [`Session`] drops —
//! PETSc first, then MPI.

use std::sync::OnceLock;

use mpi::environment::Universe;
use mpi::topology::{Communicator, SimpleCommunicator};

use super::petsc;

/// (rank, size) of the running session.
static WORLD: OnceLock<(usize, usize)> = OnceLock::new();

/// MPI and PETSc, up while this lives.
pub struct Session {
    _universe: Universe,
}

impl Drop for Session {
    fn drop(&mut self) {
        petsc::finalize();
        // The universe ends MPI when it drops, after this.
    }
}

/// Whether an MPI launcher started this process (OpenMPI's `mpirun`, or a PMI/PMIx one):
/// a plain `seam run` of a binary built with `--features mpi` stays serial.
fn launched() -> bool {
    ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"]
        .iter()
        .any(|v| std::env::var_os(v).is_some())
}

/// Start MPI (threads funnelled: only the main thread calls MPI; rayon's threads do
/// not) and PETSc when an MPI launcher started the process; `None` otherwise.
pub fn start() -> Result<Option<Session>, String> {
    if !launched() {
        return Ok(None);
    }
    let (universe, _) = mpi::initialize_with_threading(mpi::Threading::Funneled)
        .ok_or("MPI was already initialised")?;
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    petsc::initialize().map_err(|e| e.to_string())?;
    let _ = WORLD.set((rank, size));
    if rank == 0 {
        log::info!("MPI: {size} rank(s)");
    }
    Ok(Some(Session {
        _universe: universe,
    }))
}

pub(super) fn world() -> Option<(usize, usize)> {
    WORLD.get().copied()
}

/// The world communicator (a session is running).
pub(super) fn comm() -> SimpleCommunicator {
    SimpleCommunicator::world()
}
