//! MPI and PETSc for the life of a distributed run: started by [`start`] when the process
//! was launched by `mpirun` (or another MPI launcher), ended when the [`Session`] drops —
//! PETSc first, then MPI.

use std::sync::OnceLock;

use mpi::datatype::{Partition, PartitionMut};
use mpi::environment::Universe;
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::{CommunicatorCollectives, Root};

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

/// The displacements of consecutive blocks of `counts` items.
pub(super) fn displacements(counts: &[i32]) -> Vec<i32> {
    counts
        .iter()
        .scan(0, |s, &n| {
            let d = *s;
            *s += n;
            Some(d)
        })
        .collect()
}

/// Every rank's `mine`, concatenated in rank order, on every rank (`MPI_Allgather` of
/// the counts, then `MPI_Allgatherv`).
pub(super) fn gather_all<T>(world: &SimpleCommunicator, mine: &[T]) -> Vec<T>
where
    T: mpi::datatype::Equivalence + Copy + Default,
{
    let mut counts = vec![0i32; world.size() as usize];
    world.all_gather_into(&(mine.len() as i32), &mut counts[..]);
    let displs = displacements(&counts);
    let mut all = vec![T::default(); counts.iter().sum::<i32>() as usize];
    {
        let mut got = PartitionMut::new(&mut all[..], &counts[..], &displs[..]);
        world.all_gather_varcount_into(mine, &mut got);
    }
    all
}

/// Every rank's `mine`, concatenated in rank order, on rank 0 (`MPI_Gather` of the
/// counts, then `MPI_Gatherv`); empty on the other ranks.
pub(super) fn gather_root<T>(world: &SimpleCommunicator, mine: &[T]) -> Vec<T>
where
    T: mpi::datatype::Equivalence + Copy + Default,
{
    let root = world.process_at_rank(0);
    let count = mine.len() as i32;
    if world.rank() != 0 {
        root.gather_into(&count);
        root.gather_varcount_into(mine);
        return Vec::new();
    }
    let mut counts = vec![0i32; world.size() as usize];
    root.gather_into_root(&count, &mut counts[..]);
    let displs = displacements(&counts);
    let mut all = vec![T::default(); counts.iter().sum::<i32>() as usize];
    {
        let mut got = PartitionMut::new(&mut all[..], &counts[..], &displs[..]);
        root.gather_varcount_into_root(mine, &mut got);
    }
    all
}

/// The inverse of [`gather_root`]: rank `r` gets `whole[starts[r]..starts[r + 1]]` of
/// rank 0's `whole` (read on rank 0 alone; `MPI_Scatterv`). `starts`: the `P + 1`
/// block starts, the same on every rank.
pub(super) fn scatter_root<T>(world: &SimpleCommunicator, whole: &[T], starts: &[usize]) -> Vec<T>
where
    T: mpi::datatype::Equivalence + Copy + Default,
{
    let root = world.process_at_rank(0);
    let rank = world.rank() as usize;
    let mut mine = vec![T::default(); starts[rank + 1] - starts[rank]];
    if rank != 0 {
        root.scatter_varcount_into(&mut mine[..]);
        return mine;
    }
    let counts: Vec<i32> = starts.windows(2).map(|w| (w[1] - w[0]) as i32).collect();
    let displs = displacements(&counts);
    let sent = Partition::new(whole, &counts[..], &displs[..]);
    root.scatter_varcount_into_root(&sent, &mut mine[..]);
    mine
}

/// Send `out[r]` to rank `r`; returns what each rank sent here (`MPI_Alltoall` of the
/// counts, then `MPI_Alltoallv`).
pub(super) fn exchange<T>(world: &SimpleCommunicator, out: &[Vec<T>]) -> Vec<Vec<T>>
where
    T: mpi::datatype::Equivalence + Copy + Default,
{
    let size = out.len();
    let send_counts: Vec<i32> = out.iter().map(|v| v.len() as i32).collect();
    let mut recv_counts = vec![0i32; size];
    world.all_to_all_into(&send_counts[..], &mut recv_counts[..]);
    let send: Vec<T> = out.concat();
    let mut recv = vec![T::default(); recv_counts.iter().sum::<i32>() as usize];
    {
        let (sd, rd) = (displacements(&send_counts), displacements(&recv_counts));
        let sent = Partition::new(&send[..], &send_counts[..], &sd[..]);
        let mut got = PartitionMut::new(&mut recv[..], &recv_counts[..], &rd[..]);
        world.all_to_all_varcount_into(&sent, &mut got);
    }
    let mut start = 0;
    recv_counts
        .iter()
        .map(|&n| {
            let v = recv[start..start + n as usize].to_vec();
            start += n as usize;
            v
        })
        .collect()
}

/// `r` where it holds on every rank; else this rank's error, and on the ranks where it
/// held the failed ranks' errors (collective: a rank failing alone would leave the
/// others waiting in the next collective).
pub(super) fn agreed<T>(r: Result<T, crate::heat::HeatError>) -> Result<T, crate::heat::HeatError> {
    if !super::any_rank(r.is_err()) {
        return r;
    }
    let world = comm();
    let mine = r.err().map(|e| e.to_string()).unwrap_or_default();
    let lengths = gather_all(&world, &[mine.len() as u64]);
    let bytes = gather_all(&world, mine.as_bytes());
    let mut at = 0;
    let mut why = Vec::new();
    for (rank, &len) in lengths.iter().enumerate() {
        let piece = &bytes[at..at + len as usize];
        at += len as usize;
        if len > 0 {
            why.push(format!("rank {rank}: {}", String::from_utf8_lossy(piece)));
        }
    }
    Err(crate::heat::HeatError::Step(why.join("; ")))
}

/// The set-up's phases, as seconds from its start, for the log.
#[derive(Default)]
pub(super) struct Phases(pub(super) String);

impl Phases {
    pub(super) fn mark(&mut self, what: &str, since: std::time::Instant) {
        if !self.0.is_empty() {
            self.0.push_str(", ");
        }
        self.0
            .push_str(&format!("{what} {:.3}", since.elapsed().as_secs_f64()));
    }
}

/// Evaluates every point again when dropped (the run's output after the solve sees the
/// whole interface).
pub(super) struct AllPoints<'a>(pub(super) &'a dyn crate::heat::interfaces::Interfaces);

impl Drop for AllPoints<'_> {
    fn drop(&mut self) {
        // The run's interfaces accepted the restriction, so they accept its end.
        let _ = self.0.own_points(None);
    }
}

/// The error refusing what the distributed solve does not do yet.
pub(super) fn refused(what: &str) -> crate::heat::HeatError {
    crate::heat::HeatError::Contact(format!(
        "[E0902] {what}: not yet distributed under MPI (help: run without mpirun; docs/parallel.md lists what is distributed)"
    ))
}
