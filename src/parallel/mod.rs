//! `seam run` on MPI (`--features mpi`, started by `mpirun`): the mesh's elements
//! partitioned by METIS, the contact search distributed ([`search`]: each rank pairs the
//! side-A points of its own faces), each rank assembling its own elements' conduction and
//! its own side-A points' interface terms into a PETSc distributed matrix, the solve by
//! PETSc (CG + GAMG, or MUMPS LU), the solution gathered at the end so that rank 0 writes
//! what a serial run writes. What is and is not distributed is listed in
//! `docs/parallel.md`.
//!
//! Entry points: [`start`] (the binary, before a run), then the hooks the run calls —
//! [`is_root`] (who writes files and prints), [`search_pair`] (the contact search of
//! one pair of surfaces, distributed), [`steady`] (the linear or
//! Newton-nonlinear steady solve), [`general_solve`] (the linear solves of the general,
//! stepped, solver: its assembly replicated on every rank, each step's system solved by
//! PETSc over all ranks) and [`linear_solver`] (the summary's linear solver).
//!
//! Without the feature, or without a launcher, every hook is the serial path: one
//! process, rank 0, nothing refused.

use crate::heat::HeatError;
use crate::heat::steady::{SteadyProblem, SteadySolution};

#[cfg(feature = "mpi")]
mod general;
#[cfg(feature = "mpi")]
mod layout;
#[cfg(feature = "mpi")]
pub mod petsc;
#[cfg(feature = "mpi")]
pub mod search;
#[cfg(feature = "mpi")]
mod session;
#[cfg(feature = "mpi")]
mod steady;

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
    /// Below the threshold, unsymmetric, or indefinite (multiplier ties).
    Direct,
}

impl System {
    /// Why its method, for the run's summary.
    pub fn why(self) -> &'static str {
        match self {
            System::Spd => "symmetric positive definite, at or above the AMG threshold → CG + GAMG",
            System::Coupled { .. } => {
                "unsymmetric coupled thermal–electrical Newton steps at or above the AMG threshold → GMRES, GAMG on the temperature and voltage blocks"
            }
            System::Direct => {
                "below the AMG threshold, unsymmetric, or with multipliers (indefinite) → MUMPS LU"
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
    static LAST: std::cell::Cell<Option<(petsc::Method, &'static str)>> =
        const { std::cell::Cell::new(None) };
}

#[cfg(feature = "mpi")]
fn record(method: petsc::Method, why: &'static str) {
    LAST.with(|l| l.set(Some((method, why))));
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

/// `a`'s points paired with `b`'s faces by the distributed search when the run is
/// distributed (the serial pairing, whole on every rank; see [`search`]), else `None`
/// (the caller searches serially).
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
        let (method, why) = LAST.with(std::cell::Cell::get)?;
        Some((method.name().into(), format!("MPI, {size} rank(s): {why}")))
    }
    #[cfg(not(feature = "mpi"))]
    {
        None
    }
}
