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
//! Newton-nonlinear steady solve), [`not_distributed`] (what a run under MPI refuses)
//! and [`linear_solver`] (the summary's linear solver).
//!
//! Without the feature, or without a launcher, every hook is the serial path: one
//! process, rank 0, nothing refused.

use crate::diag::Diagnostic;
use crate::heat::HeatError;
use crate::heat::steady::{SteadyProblem, SteadySolution};

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
pub use session::{Session, start};

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

/// Under MPI, the diagnostic refusing a run the distributed solve does not cover: one
/// that the general (stepped) solver would solve — a transient run, or a steady one with
/// temperature-dependent materials, several fields, a voltage or a species, radiation,
/// toggles. `None` when the run is not distributed.
pub fn not_distributed(transient: bool) -> Option<Diagnostic> {
    let (_, size) = world()?;
    let what = if transient {
        "a transient run"
    } else {
        "a steady run the general solver takes (temperature-dependent materials, several fields, a voltage or a species, radiation, toggles)"
    };
    Some(
        Diagnostic::error(
            "E0901",
            format!("{what} is not yet distributed: under MPI ({size} rank(s)) seam solves steady single-field conduction with constant materials"),
        )
        .help("run it without mpirun (serially); docs/parallel.md lists what is distributed today"),
    )
}

/// The name and the reason of the linear solver the last distributed solve ran (PETSc's
/// method and the ranks), for the run's summary; `None` when the run is not distributed.
pub fn linear_solver() -> Option<(String, String)> {
    #[cfg(feature = "mpi")]
    {
        let (_, size) = world()?;
        let (method, symmetric) = steady::last_method()?;
        let why = match (method, symmetric) {
            (petsc::Method::CgGamg, _) => {
                "symmetric positive definite, at or above the AMG threshold → CG + GAMG"
            }
            (petsc::Method::MumpsLu, true) => {
                "below the AMG threshold (or linear_solver = \"direct\") → MUMPS LU"
            }
            (petsc::Method::MumpsLu, false) => {
                "a temperature-dependent conductance makes the Jacobian unsymmetric → MUMPS LU"
            }
        };
        Some((method.name().into(), format!("MPI, {size} rank(s): {why}")))
    }
    #[cfg(not(feature = "mpi"))]
    {
        None
    }
}
