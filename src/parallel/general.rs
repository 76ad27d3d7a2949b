//! The general (stepped) solver's linear solves on MPI: every rank runs the serial
//! general solver — its assembly replicated, each rank assembling the whole Jacobian
//! identically — and at each Newton iteration the step's system is solved by PETSc over
//! all ranks, the solution then gathered whole on every rank.
//!
//! Entry point: [`GeneralSolve::solve`], with the [`System`] the serial solver would
//! have chosen its method by: CG + BoomerAMG for a symmetric positive definite system at or
//! above the AMG threshold, GMRES preconditioned by BoomerAMG on the temperature and the
//! voltage blocks for the coupled thermal–electrical Jacobian there, GMRES by BoomerAMG
//! for another unsymmetric Jacobian there (a temperature-dependent law), MUMPS LU
//! otherwise (small, or indefinite: multiplier ties).
//!
//! Rows: rank `r` of `s` owns the contiguous block `[r n / s, (r + 1) n / s)` of the
//! serial dof order — not the element partition of [`super::layout`], which numbers one
//! temperature field's nodes: the general solver's unknowns also hold voltages, species
//! and multipliers, which no element owns, and with the assembly replicated the rows'
//! owners decide only how the solve communicates. The serial order keeps each field a
//! contiguous range, so a field's rows on a rank are a stride (the field split's index
//! sets), and PETSc's numbering is the serial one: the gathered solution needs no
//! permutation.
//!
//! The PETSc matrix, vectors and solver are kept while the pattern and the method hold;
//! the values are set again only when they changed, so an unchanged matrix (a linear
//! problem stepping with a fixed step) reuses its factorisation or AMG hierarchy, as the
//! serial solver's `factored` cache does. A Krylov method keeps its BoomerAMG hierarchy
//! for a changed matrix too, by the serial AMG's rules and tests
//! (`src/solve/amg/reuse.rs`): while no diagonal entry moved by more than
//! [`DRIFT`](crate::solve::amg::reuse::DRIFT) from the matrix it was set up for and the
//! solves have not degraded ([`Hierarchy`]).

use std::ops::Range;
use std::time::Instant;

use faer::sparse::SparseColMat;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{AsRaw, Communicator, CommunicatorCollectives};

use crate::heat::HeatError;
use crate::solve::SolveError;
use crate::solve::amg::reuse::{diagonal_of, drifted};

use super::petsc::{Ksp, Mat, Method, PetscError, PetscInt, Split, Vector};
use super::reuse::Hierarchy;
use super::rows::ByRows;
use super::{Solution, System, session};

/// The PETSc objects of one pattern and method.
struct Kept {
    method: Method,
    /// The pattern they were made for (column pointers, row indices of the CSC matrix).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// This rank's rows, by row (PETSc's numbers are the serial ones).
    by_rows: ByRows,
    /// The values set last (the whole CSC value array).
    values: Vec<f64>,
    /// The inverse diagonal of the matrix the preconditioner was made for (`None`: an
    /// entry missing), and its state.
    set_up_for: Option<Vec<f64>>,
    hierarchy: Hierarchy,
    a: Mat,
    ksp: Ksp,
    b: Vector,
    x: Vector,
}

/// The general solver's distributed linear solves, kept across iterations and steps.
pub struct GeneralSolve {
    world: SimpleCommunicator,
    kept: Option<Kept>,
}

fn failed(e: PetscError) -> HeatError {
    HeatError::Solve(SolveError::Distributed(e.to_string()))
}

/// Rank `rank`'s rows of `n` over `size` ranks.
fn block(n: usize, rank: usize, size: usize) -> Range<usize> {
    rank * n / size..(rank + 1) * n / size
}

/// A hash of the system's bits (pattern, values, right-hand side, guess), to check that
/// every rank assembled the same one.
fn fingerprint(a: &SparseColMat<usize, f64>, b: &[f64], guess: Option<&[f64]>) -> u64 {
    let sym = a.symbolic();
    let words = (sym.col_ptr().iter().chain(sym.row_idx()))
        .map(|&k| k as u64)
        .chain(a.val().iter().chain(b).map(|v| v.to_bits()))
        .chain(guess.into_iter().flatten().map(|v| v.to_bits()));
    words.fold(0xcbf2_9ce4_8422_2325, |h: u64, w| {
        (h.rotate_left(5) ^ w).wrapping_mul(0x517c_c1b7_2722_0a95)
    })
}

impl GeneralSolve {
    pub(super) fn new() -> GeneralSolve {
        GeneralSolve {
            world: session::comm(),
            kept: None,
        }
    }

    /// Solve `a x = b` over every rank by the method `system` calls for (Krylov methods
    /// from `guess`, else from 0, stopping at the serial solver's tolerance relative to
    /// ‖b‖); every rank gets the whole `x`.
    pub fn solve(
        &mut self,
        a: &SparseColMat<usize, f64>,
        b: &[f64],
        guess: Option<&[f64]>,
        system: System,
    ) -> Result<Solution, HeatError> {
        let t0 = Instant::now();
        let (rank, size) = (self.world.rank() as usize, self.world.size() as usize);
        // The assembly is replicated: a rank whose system differs would solve another
        // problem silently, so the ranks compare their systems' hashes first.
        let mut hashes = vec![0u64; size];
        self.world
            .all_gather_into(&fingerprint(a, b, guess), &mut hashes[..]);
        if let Some(r) = hashes.iter().position(|&h| h != hashes[0]) {
            return Err(HeatError::Step(format!(
                "distributed solve: rank {r} assembled a system different from rank 0's (the general solver's assembly must be the same on every rank)"
            )));
        }
        let n = a.nrows();
        let rows = block(n, rank, size);
        let method = match system {
            System::Spd => Method::CgAmg,
            System::Coupled { .. } => Method::GmresBlocks,
            System::Unsymmetric => Method::GmresAmg,
            System::Direct => Method::MumpsLu,
        };
        let sym = a.symbolic();
        let same = self.kept.as_ref().is_some_and(|k| {
            k.method == method && k.col_ptr == sym.col_ptr() && k.row_idx == sym.row_idx()
        });
        if !same {
            self.kept = None;
            let split = match system {
                System::Coupled { at } => Some(Split {
                    rows: rows.clone(),
                    at,
                }),
                _ => None,
            };
            let mut made = Kept::new(&self.world, a, &rows, method, split).map_err(failed)?;
            made.set_up(a).map_err(failed)?;
            self.kept = Some(made);
        }
        let kept = self.kept.as_mut().expect("made above");
        // A changed matrix: a new preconditioner, or a Krylov method's kept hierarchy.
        let mut reused = false;
        if kept.values != a.val() {
            kept.set_values(a).map_err(failed)?;
            // (No c₀ here: the diagonal's drift stands for it.)
            reused = method != Method::MumpsLu
                && kept.hierarchy.serves(0.0)
                && (kept.set_up_for.as_deref())
                    .zip(diagonal_of(a.as_ref()))
                    .is_some_and(|(inv, d)| !drifted(inv, &d));
            match reused {
                true => kept.ksp.keep_preconditioner(true).map_err(failed)?,
                false => kept.set_up(a).map_err(failed)?,
            }
        }
        let local = rows.len();
        kept.b
            .with_local(local, |v| v.copy_from_slice(&b[rows.clone()]))
            .map_err(failed)?;
        if method != Method::MumpsLu {
            kept.ksp.start_from_x(guess.is_some()).map_err(failed)?;
        }
        match guess {
            Some(g) => kept
                .x
                .with_local(local, |v| v.copy_from_slice(&g[rows.clone()])),
            None => kept.x.zero(),
        }
        .map_err(failed)?;
        let setup_s = t0.elapsed().as_secs_f64();
        let t1 = Instant::now();
        // (The start, for a solve again on a new hierarchy.)
        let x0 = match reused {
            true => Some(kept.x.with_local(local, |v| v.to_vec()).map_err(failed)?),
            false => None,
        };
        let mut solved = kept.ksp.solve(&kept.b, &mut kept.x);
        if let Some(x0) = x0.filter(|_| solved.as_ref().is_err_and(PetscError::is_divergence)) {
            // The kept hierarchy failed: one for this matrix, and the solve again.
            kept.set_up(a).map_err(failed)?;
            kept.x
                .with_local(local, |v| v.copy_from_slice(&x0))
                .map_err(failed)?;
            solved = kept.ksp.solve(&kept.b, &mut kept.x);
        }
        let its = solved.map_err(failed)?;
        if method != Method::MumpsLu {
            kept.hierarchy.solved(its);
        }
        let mine = kept.x.with_local(local, |v| v.to_vec()).map_err(failed)?;
        let x = session::gather_all(&self.world, &mine);
        super::record(method, system.why());
        Ok(Solution {
            x,
            iterations: if method == Method::MumpsLu { 0 } else { its },
            setup_s,
            solve_s: t1.elapsed().as_secs_f64(),
        })
    }
}

impl Kept {
    /// The preconditioner (or factorisation) made for the matrix set, `a`.
    fn set_up(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), PetscError> {
        self.ksp.keep_preconditioner(false)?;
        self.ksp.set_up()?;
        self.set_up_for = diagonal_of(a.as_ref()).map(|d| d.iter().map(|d| 1.0 / d).collect());
        self.hierarchy.set_up(0.0);
        Ok(())
    }

    /// The matrix of `a`'s pattern (this rank's `rows`, preallocated exactly), its
    /// vectors and its solver.
    fn new(
        world: &SimpleCommunicator,
        a: &SparseColMat<usize, f64>,
        rows: &Range<usize>,
        method: Method,
        split: Option<Split>,
    ) -> Result<Kept, PetscError> {
        let comm = world.as_raw();
        let n = a.nrows();
        let sym = a.symbolic();
        // This rank's rows, transposed out of the CSC columns.
        let local = rows.len();
        let identity = |i: usize| i as PetscInt;
        let by_rows = ByRows::of(sym, &identity, &|i| rows.contains(&i));
        let (mut diagonal, mut off) = (vec![0 as PetscInt; local], vec![0 as PetscInt; local]);
        for (row, cols, _) in by_rows.rows() {
            let r = row as usize - rows.start;
            for &j in cols {
                match rows.contains(&(j as usize)) {
                    true => diagonal[r] += 1,
                    false => off[r] += 1,
                }
            }
        }
        let a_petsc = Mat::aij(comm, local, n, &diagonal, &off)?;
        let b = Vector::new(comm, local, n)?;
        let x = b.duplicate()?;
        let tolerance = crate::heat::steady::AMG_TOLERANCE;
        let ksp = Ksp::with_split(comm, &a_petsc, method, tolerance, split.as_ref())?;
        let mut kept = Kept {
            method,
            col_ptr: sym.col_ptr().to_vec(),
            row_idx: sym.row_idx().to_vec(),
            by_rows,
            values: Vec::new(),
            set_up_for: None,
            hierarchy: Hierarchy::default(),
            a: a_petsc,
            ksp,
            b,
            x,
        };
        kept.set_values(a)?;
        Ok(kept)
    }

    /// `a`'s values into this rank's rows (collective).
    fn set_values(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), PetscError> {
        let val = a.val();
        let mut buf = Vec::new();
        for (row, cols, slots) in self.by_rows.rows() {
            buf.clear();
            buf.extend(slots.iter().map(|&k| val[k as usize]));
            self.a.set_row(row, cols, &buf)?;
        }
        self.a.assemble()?;
        self.values.clear();
        self.values.extend_from_slice(val);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::block;

    /// The blocks cover 0..n once, in rank order, whatever n and the ranks.
    #[test]
    fn blocks_tile_the_dofs() {
        for n in [0, 1, 5, 17, 1000] {
            for size in 1..=5 {
                let blocks: Vec<_> = (0..size).map(|r| block(n, r, size)).collect();
                assert_eq!(blocks[0].start, 0);
                assert_eq!(blocks[size - 1].end, n);
                assert!(blocks.windows(2).all(|w| w[0].end == w[1].start));
            }
        }
    }
}
