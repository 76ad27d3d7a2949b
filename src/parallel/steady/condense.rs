//! Dual mortar ties condensed on ranks, as the serial solve condenses them
//! (`crate::heat::dual`): a side-A dof that carries a dual multiplier is the known
//! combination `u_a = (g_a − Σ_j C_aj u_j) / D_a` of free dofs, so with `u = P ũ + c`
//! a linear steady solve's Newton step solves `Pᵀ J P Δũ = −Pᵀ R` — symmetric positive
//! definite, so CG + BoomerAMG from the AMG threshold (MUMPS below it) — and steps
//! `Δu = P Δũ`; the multipliers come back from the condensed rows of the residual,
//! `λ_a = −R_a / D_a`.
//!
//! A tie's rows are sums over the side-A points of every rank, so `C` and `g` are first
//! summed into the rows of the side-A nodes' owners (a PETSc matrix and vector, each
//! rank adding its points' entries); each owner then makes its rows of `P`. The
//! product `Pᵀ J P` is PETSc's (`MatPtAP`). The multiplier rows keep their places (all
//! on the last rank, as for a saddle point), held at the identity in the condensed
//! system and filled with the multipliers at the end, so the gathered solution is laid
//! out as the serial one.

use mpi::traits::AsRaw;

use crate::heat::HeatError;
use crate::parallel::petsc::{Ksp, Mat, PetscInt, Vector};

use super::{Built, petsc_err};

/// The condensation of a linear steady solve's dual ties on this rank.
pub(super) struct Condensed {
    /// `P` over every PETSc row: the identity's rows on the free dofs, `−C_aj / D_a` on
    /// a condensed side-A row `a`, and an explicit 0 on the diagonal of the condensed
    /// and the multiplier rows (so that `Pᵀ J P` stores the entry the identity row
    /// takes there).
    p: Mat,
    /// `c`: `g_a / D_a` on the condensed rows.
    c: Vector,
    /// `Pᵀ J P`, once made.
    reduced: Option<Mat>,
    /// The rows owned here that the condensed system holds at the identity (Dirichlet,
    /// condensed, multipliers), global and among this rank's rows.
    held: Vec<PetscInt>,
    held_local: Vec<usize>,
    /// Per condensed row owned here: its place among this rank's rows, `D_a` and its
    /// multiplier's PETSc row.
    own: Vec<(usize, f64, PetscInt)>,
    /// The residual before its condensation, this rank's rows (the multipliers read
    /// its condensed rows).
    full: Vec<f64>,
    x: Vector,
    y: Vector,
}

impl Condensed {
    /// The condensation of `built`'s ties, when it has them, every one dual, and the
    /// solve is a linear steady one (not `stepping`); else `None` (a saddle point).
    /// Collective.
    pub(super) fn new(built: &Built<'_>, stepping: bool) -> Result<Option<Condensed>, HeatError> {
        let linear = built.iface.is_some_and(|i| i.is_linear()) && !built.nonlinear;
        let Some(ties) = built
            .ties
            .as_ref()
            .filter(|t| t.dual() && linear && !stepping)
        else {
            return Ok(None);
        };
        let layout = &built.layout;
        let comm = built.world.as_raw();
        let rows = layout.rows();
        let (local, global) = (rows.len(), layout.starts[layout.size]);
        let mine = |row: PetscInt| rows.contains(&(row as usize));
        // C and g summed into the side-A owners' rows.
        let mut carried = vec![false; local];
        for &(row, _) in ties.carried().iter().filter(|&&(row, _)| mine(row)) {
            carried[row as usize - rows.start] = true;
        }
        let guess = |room: usize| -> Vec<PetscInt> {
            (carried.iter())
                .map(|&c| if c { room.min(32) as PetscInt } else { 0 })
                .collect()
        };
        let mut cmat = Mat::aij(comm, local, global, &guess(local), &guess(global - local))
            .map_err(petsc_err)?;
        cmat.allow_new_entries().map_err(petsc_err)?;
        let mut g = Vector::new(comm, local, global).map_err(petsc_err)?;
        let petsc = &layout.petsc;
        let mut run: Option<(PetscInt, Vec<PetscInt>, Vec<f64>)> = None;
        for (a, d, c) in ties.by_side_a().map(|(a, d, c)| (petsc[a], petsc[d], c)) {
            match &mut run {
                Some((row, cols, vals)) if *row == a => {
                    cols.push(d);
                    vals.push(c);
                }
                _ => {
                    if let Some((row, cols, vals)) = run.take() {
                        cmat.add_row(row, &cols, &vals).map_err(petsc_err)?;
                    }
                    run = Some((a, vec![d], vec![c]));
                }
            }
        }
        if let Some((row, cols, vals)) = run {
            cmat.add_row(row, &cols, &vals).map_err(petsc_err)?;
        }
        cmat.assemble().map_err(petsc_err)?;
        let (at, values): (Vec<PetscInt>, Vec<f64>) =
            ties.g_by_side_a().map(|(a, v)| (petsc[a], v)).unzip();
        g.add(&at, &values).map_err(petsc_err)?;
        g.assemble().map_err(petsc_err)?;
        let g_local = g.with_local(local, |v| v.to_vec()).map_err(petsc_err)?;
        // The rows of P: a condensed row's terms in other condensed dofs are left out,
        // as serially (below 1e-9 by rank 0's check of the whole ties).
        let mut condensed: Vec<PetscInt> = ties.carried().iter().map(|&(row, _)| row).collect();
        condensed.sort_unstable();
        let mut p_rows: Vec<(PetscInt, Vec<PetscInt>, Vec<f64>)> = Vec::with_capacity(local);
        let mut own = Vec::new();
        let mut c_at = Vec::new();
        for &(row, multiplier) in ties.carried().iter().filter(|&&(row, _)| mine(row)) {
            let (cols, vals) = cmat.row(row).map_err(petsc_err)?;
            let d: f64 = (cols.iter().zip(&vals))
                .filter(|&(&j, _)| j == row)
                .map(|(_, v)| v)
                .sum();
            if d == 0.0 {
                continue; // a node no point reached: left free, as serially
            }
            let mut p_cols = vec![row];
            let mut p_vals = vec![0.0];
            for (&j, &v) in cols.iter().zip(&vals) {
                if j != row && condensed.binary_search(&j).is_err() {
                    p_cols.push(j);
                    p_vals.push(-v / d);
                }
            }
            let at = row as usize - rows.start;
            own.push((at, d, petsc[multiplier]));
            c_at.push((row, g_local[at] / d));
            p_rows.push((row, p_cols, p_vals));
        }
        drop(cmat);
        let multipliers: Vec<PetscInt> = (ties.multiplier_dofs())
            .map(|l| petsc[l])
            .filter(|&row| mine(row))
            .collect();
        // The other rows: the identity's, an explicit 0 on a multiplier's.
        let mut one = vec![1.0; local];
        p_rows
            .iter()
            .for_each(|r| one[r.0 as usize - rows.start] = f64::NAN);
        multipliers
            .iter()
            .for_each(|&r| one[r as usize - rows.start] = 0.0);
        for (at, &v) in one.iter().enumerate().filter(|(_, v)| !v.is_nan()) {
            let row = (rows.start + at) as PetscInt;
            p_rows.push((row, vec![row], vec![v]));
        }
        let (mut diagonal, mut off) = (vec![0; local], vec![0; local]);
        for (row, cols, _) in &p_rows {
            let at = *row as usize - rows.start;
            for &j in cols {
                match mine(j) {
                    true => diagonal[at] += 1,
                    false => off[at] += 1,
                }
            }
        }
        let mut p = Mat::aij(comm, local, global, &diagonal, &off).map_err(petsc_err)?;
        for (row, cols, vals) in &p_rows {
            p.set_row(*row, cols, vals).map_err(petsc_err)?;
        }
        p.assemble().map_err(petsc_err)?;
        let mut c = Vector::new(comm, local, global).map_err(petsc_err)?;
        let (at, values): (Vec<PetscInt>, Vec<f64>) = c_at.into_iter().unzip();
        c.set(&at, &values).map_err(petsc_err)?;
        c.assemble().map_err(petsc_err)?;
        let mut held: Vec<PetscInt> = (built.bc_rows.iter().copied())
            .chain(own.iter().map(|&(at, _, _)| (rows.start + at) as PetscInt))
            .chain(multipliers)
            .collect();
        held.sort_unstable();
        held.dedup();
        let held_local = held.iter().map(|&r| r as usize - rows.start).collect();
        Ok(Some(Condensed {
            p,
            c,
            reduced: None,
            held,
            held_local,
            own,
            full: Vec::new(),
            x: Vector::new(comm, local, global).map_err(petsc_err)?,
            y: Vector::new(comm, local, global).map_err(petsc_err)?,
        }))
    }

    /// Move the start `u` (its Dirichlet values set, up to date where this rank reads)
    /// onto the ties' constraints: `P u + c`. Collective.
    pub(super) fn start(&mut self, built: &Built<'_>, u: &mut [f64]) -> Result<(), HeatError> {
        let layout = &built.layout;
        let (first, local) = (layout.rows().start, layout.rows().len());
        let mine: Vec<f64> = {
            let mut v = vec![0.0; local];
            for &d in &layout.owned {
                v[layout.petsc[d] as usize - first] = u[d];
            }
            v
        };
        (self.x)
            .with_local(local, |x| x.copy_from_slice(&mine))
            .map_err(petsc_err)?;
        self.p.mult(&self.x, &mut self.y).map_err(petsc_err)?;
        let c = self
            .c
            .with_local(local, |c| c.to_vec())
            .map_err(petsc_err)?;
        let step: Vec<f64> = (self.y)
            .with_local(local, |y| {
                (y.iter().zip(&c).zip(&mine))
                    .map(|((y, c), x)| y + c - x)
                    .collect()
            })
            .map_err(petsc_err)?;
        built.scatter.update(&built.world, layout, &step, u);
        Ok(())
    }

    /// Condense the residual in `r` (this rank's rows, Dirichlet rows zero), keeping it
    /// whole for [`Self::multipliers`]: `Pᵀ r`, zero on the held rows. Collective.
    pub(super) fn reduce(&mut self, r: &mut Vector, local: usize) -> Result<(), HeatError> {
        self.full = r.with_local(local, |v| v.to_vec()).map_err(petsc_err)?;
        self.p.mult_transpose(r, &mut self.y).map_err(petsc_err)?;
        let reduced = self
            .y
            .with_local(local, |v| v.to_vec())
            .map_err(petsc_err)?;
        let held = &self.held_local;
        r.with_local(local, |v| {
            v.copy_from_slice(&reduced);
            held.iter().for_each(|&i| v[i] = 0.0);
        })
        .map_err(petsc_err)
    }

    /// The condensed matrix `Pᵀ J P` of `j` (set, its Dirichlet rows replaced), with
    /// the held rows and columns the identity's, made the operator of `ksp`.
    /// Collective.
    pub(super) fn set_matrix(&mut self, j: &Mat, ksp: &mut Ksp) -> Result<(), HeatError> {
        j.ptap_into(&self.p, &mut self.reduced).map_err(petsc_err)?;
        let reduced = self.reduced.as_mut().expect("made");
        reduced.zero_rows_columns(&self.held).map_err(petsc_err)?;
        ksp.set_operators(reduced).map_err(petsc_err)
    }

    /// The step `P Δũ` of the condensed system's solution `du`, in place. Collective.
    pub(super) fn expand(&mut self, du: &mut Vector, local: usize) -> Result<(), HeatError> {
        let solved = du.with_local(local, |v| v.to_vec()).map_err(petsc_err)?;
        (self.x)
            .with_local(local, |x| x.copy_from_slice(&solved))
            .map_err(petsc_err)?;
        self.p.mult(&self.x, du).map_err(petsc_err)
    }

    /// The multipliers of the residual last condensed, `λ_a = −R_a / D_a`, into `u` at
    /// their dofs (on their owner and where read). Collective.
    pub(super) fn multipliers(
        &mut self,
        built: &Built<'_>,
        u: &mut [f64],
    ) -> Result<(), HeatError> {
        let layout = &built.layout;
        let local = layout.rows().len();
        let (at, values): (Vec<PetscInt>, Vec<f64>) = (self.own.iter())
            .map(|&(i, d, multiplier)| (multiplier, -self.full[i] / d))
            .unzip();
        self.y.zero().map_err(petsc_err)?;
        self.y.set(&at, &values).map_err(petsc_err)?;
        self.y.assemble().map_err(petsc_err)?;
        let step = self
            .y
            .with_local(local, |v| v.to_vec())
            .map_err(petsc_err)?;
        built.scatter.update(&built.world, layout, &step, u);
        Ok(())
    }
}
