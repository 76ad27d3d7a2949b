//! Mortar ties with Lagrange multipliers in the distributed steady solve.
//!
//! A tie's rows `C u = g` are sums over side-A faces (a dual basis too is made face by
//! face), so each rank makes those of the points it owns, on its part of the mesh with
//! its contact partners ([`Interfaces::own_ties`]), and adds them — rows and columns,
//! in PETSc's numbers, into rows of any rank — as it adds its points' flux terms. Which
//! side-A nodes carry a multiplier (none where fixed or tied by an earlier tie) rank 0
//! decides on the whole interface, as the serial solve does, and sends every rank,
//! with each multiplier's number: its place in the serial tie. The multipliers are PETSc
//! rows after every node's, on the last rank, in the serial order, so the gathered
//! solution is the serial one's. The saddle point is solved by MUMPS. Dual ties pass
//! the serial solve's checks on their condensation first; in a linear steady solve they
//! are condensed as serially (`steady::condense`), elsewhere (time steps, laws of T)
//! solved as a saddle point. A multiplier held at 0 (an empty row, or a tie switched
//! off) gets its identity row from the last rank, which owns the multipliers and reads
//! their values.

use std::collections::HashMap;

use mpi::topology::SimpleCommunicator;

use crate::assembly::{Assembler, DofMap, FieldId};
use crate::heat::HeatError;
use crate::heat::dual::{dual_condensation, dual_ties};
use crate::heat::interfaces::{Interfaces, TieRows};
use crate::mesh::NodeId;

use super::petsc::PetscInt;
use super::rows::{Layout, summed_heat};
use super::session::{self, agreed};

/// The ties of a distributed steady solve, and this rank's share of their terms.
pub(super) struct Ties {
    /// Per tie: this rank's share of its rows, and per multiplier of the share its
    /// multiplier's local dof.
    shares: Vec<(TieRows, Vec<usize>)>,
    /// Per tie: where its entries, its `g`s and its empty rows start in `entries`,
    /// `rhs` and `empty` (one more at the end), and its multipliers' local dofs.
    spans: Vec<(usize, usize, usize)>,
    multipliers: Vec<std::ops::Range<usize>>,
    /// This is the multipliers' owner (the last rank, which holds their values): it
    /// holds a switched-off tie's multipliers at 0 (identity rows).
    holder: bool,
    /// The entries of this rank's share: `(multiplier dof, primal dof, C)`.
    entries: Vec<(usize, usize, f64)>,
    /// Per entry, its multiplier's side-A dof.
    side_a: Vec<usize>,
    /// `g` of this rank's share: `(multiplier dof, g)`.
    rhs: Vec<(usize, f64)>,
    /// Multipliers whose row is empty (no point reached their node), on their owner
    /// (the last rank): an identity row holds them at 0.
    empty: Vec<usize>,
    /// Per tie, the side-A nodes without a multiplier (rank 0's, of the whole tie).
    crosspoints: Vec<Vec<NodeId>>,
    /// Where the entries' couplings start in the interface pattern.
    slot: usize,
    /// Every tie is dual (condensed in a linear steady solve: `steady::condense`).
    dual: bool,
    /// Per `g` of `rhs`, its multiplier's side-A dof.
    rhs_side_a: Vec<usize>,
    /// Every multiplier some point reaches: its side-A node's PETSc row and its dof.
    carried: Vec<(PetscInt, usize)>,
}

/// Per tie, rank 0's word on its multipliers: the PETSc index of each multiplier's
/// side-A dof (the serial order), the multipliers with an empty row.
struct Decided {
    nodes: Vec<PetscInt>,
    empty: Vec<usize>,
}

impl Ties {
    /// The mortar ties of `iface` (`None` without any; collective), their multipliers
    /// appended to `dofs` and to `layout`; `iface` evaluates this rank's points only.
    pub(super) fn new(
        world: &SimpleCommunicator,
        iface: &dyn Interfaces,
        (dofs, field): (&mut DofMap, FieldId),
        layout: &mut Layout,
    ) -> Result<Option<Ties>, HeatError> {
        // Rank 0 holds the whole interface: the whole ties, as serially.
        let whole = match layout.rank {
            0 => whole_ties(iface, dofs.len()),
            _ => Ok(Vec::new()),
        };
        let whole = agreed(whole)?;
        let decided = decide(world, &whole, layout);
        if decided.is_empty() {
            return Ok(None);
        }
        let places: Vec<HashMap<PetscInt, usize>> = (decided.iter())
            .map(|d| d.nodes.iter().enumerate().map(|(m, &i)| (i, m)).collect())
            .collect();
        let carries = |t: usize, node: NodeId| {
            (dofs.dof(field, node))
                .is_some_and(|d| places[t].contains_key(&layout.petsc[d.index()]))
        };
        let own = agreed(iface.own_ties(&carries).map_err(HeatError::Contact))?;
        if own.len() != decided.len() || own.iter().any(|t| t.own.contains(&usize::MAX)) {
            return Err(HeatError::Contact(format!(
                "distributed solve: rank {} made {} ties' rows, rank 0 {}",
                layout.rank,
                own.len(),
                decided.len()
            )));
        }
        let mut ties = Ties {
            shares: Vec::with_capacity(own.len()),
            spans: Vec::with_capacity(own.len() + 1),
            multipliers: Vec::with_capacity(own.len()),
            holder: layout.rank + 1 == layout.size,
            entries: Vec::new(),
            side_a: Vec::new(),
            rhs: Vec::new(),
            empty: Vec::new(),
            crosspoints: whole.iter().map(|t| t.crosspoints.clone()).collect(),
            slot: 0,
            dual: own.iter().all(|t| t.dual),
            rhs_side_a: Vec::new(),
            carried: Vec::new(),
        };
        ties.crosspoints.resize(own.len(), Vec::new());
        for ((share, decided), places) in own.into_iter().zip(&decided).zip(&places) {
            (ties.spans).push((ties.entries.len(), ties.rhs.len(), ties.empty.len()));
            let range = dofs.add_extra(decided.nodes.len());
            ties.multipliers.push(range.clone());
            layout.append_last(range.len());
            let at: Vec<usize> = (share.own.iter())
                .map(|&d| range.start + places[&layout.petsc[d]])
                .collect();
            for &(k, d, c) in &share.entries {
                ties.entries.push((at[k], d, c));
                ties.side_a.push(share.own[k]);
            }
            (ties.rhs).extend(at.iter().zip(&share.rhs).map(|(&l, &g)| (l, g)));
            ties.rhs_side_a.extend_from_slice(&share.own);
            let mut reached = vec![true; decided.nodes.len()];
            decided.empty.iter().for_each(|&m| reached[m] = false);
            let carried = (decided.nodes.iter().enumerate()).filter(|&(m, _)| reached[m]);
            (ties.carried).extend(carried.map(|(m, &row)| (row, range.start + m)));
            let empty = decided.empty.iter().filter(|_| ties.holder);
            (ties.empty).extend(empty.map(|&m| range.start + m));
            ties.shares.push((share, at));
        }
        (ties.spans).push((ties.entries.len(), ties.rhs.len(), ties.empty.len()));
        Ok(Some(ties))
    }

    /// The couplings `(primal dof, multiplier dof)` of this rank's entries, in their
    /// order.
    pub(super) fn couplings(&self) -> Vec<(usize, usize)> {
        self.entries.iter().map(|&(l, d, _)| (d, l)).collect()
    }

    /// The couplings `(side-A dof, primal dof)` of this rank's entries: those across
    /// ranks join dofs of different ranks as a cut interface's points do.
    pub(super) fn joined(&self) -> Vec<(usize, usize)> {
        (self.side_a.iter().zip(&self.entries))
            .map(|(&a, &(_, d, _))| (a, d))
            .collect()
    }

    /// The interface pattern's slot of the first of [`Self::couplings`].
    pub(super) fn at_slot(&mut self, slot: usize) {
        self.slot = slot;
    }

    /// This rank's part of the residual at `u`, the ties switched on where `on` says:
    /// `Cᵀλ` on the primal rows, `C u − g` on the multiplier rows (λ on an empty one,
    /// and on every one of a tie switched off, as serially).
    pub(super) fn residual(&self, u: &[f64], r: &mut [f64], on: &[bool]) {
        for (t, w) in self.spans.windows(2).enumerate() {
            if !on[t] {
                let held = self.multipliers[t].clone().filter(|_| self.holder);
                held.for_each(|l| r[l] += u[l]);
                continue;
            }
            for &(l, d, c) in &self.entries[w[0].0..w[1].0] {
                r[d] += c * u[l];
                r[l] += c * u[d];
            }
            for &(l, g) in &self.rhs[w[0].1..w[1].1] {
                r[l] -= g;
            }
            for &l in &self.empty[w[0].2..w[1].2] {
                r[l] += u[l];
            }
        }
    }

    /// This rank's part of the Jacobian, into the interface assembler (its coupling
    /// slots reset), the ties switched on where `on` says.
    pub(super) fn jacobian(&self, asm: &mut Assembler<'_>, on: &[bool]) {
        for (t, w) in self.spans.windows(2).enumerate() {
            if !on[t] {
                let held = self.multipliers[t].clone().filter(|_| self.holder);
                held.for_each(|l| asm.add_diagonal(l, 1.0));
                continue;
            }
            for e in w[0].0..w[1].0 {
                asm.add_coupling(self.slot + e, self.entries[e].2, self.entries[e].2);
            }
            for &l in &self.empty[w[0].2..w[1].2] {
                asm.add_diagonal(l, 1.0);
            }
        }
    }

    /// Whether every tie is dual.
    pub(super) fn dual(&self) -> bool {
        self.dual
    }

    /// This rank's entries of `C` by side-A dof: `(side-A dof, primal dof, C)`, a
    /// multiplier's in a run.
    pub(super) fn by_side_a(&self) -> impl Iterator<Item = (usize, usize, f64)> + '_ {
        (self.side_a.iter().zip(&self.entries)).map(|(&a, &(_, d, c))| (a, d, c))
    }

    /// This rank's `g`s by side-A dof.
    pub(super) fn g_by_side_a(&self) -> impl Iterator<Item = (usize, f64)> + '_ {
        (self.rhs_side_a.iter().zip(&self.rhs)).map(|(&a, &(_, g))| (a, g))
    }

    /// Every multiplier some point reaches: its side-A node's PETSc row and its dof.
    pub(super) fn carried(&self) -> &[(PetscInt, usize)] {
        &self.carried
    }

    /// Every multiplier's dof.
    pub(super) fn multiplier_dofs(&self) -> impl Iterator<Item = usize> + '_ {
        self.multipliers.iter().flat_map(|r| r.clone())
    }

    /// How many ties.
    pub(super) fn len(&self) -> usize {
        self.shares.len()
    }

    /// Per tie, the heat leaving side A and side B at `u` (this rank's, its multipliers
    /// up to date), summed over the ranks (collective).
    pub(super) fn heat(&self, world: &SimpleCommunicator, u: &[f64]) -> Vec<(f64, f64)> {
        let mine: Vec<(f64, f64)> = (self.shares.iter())
            .map(|(share, at)| share.heat(&at.iter().map(|&l| u[l]).collect::<Vec<_>>()))
            .collect();
        summed_heat(world, &mine)
    }

    /// Per tie, its side-A nodes left without a multiplier (crosspoints; on rank 0).
    pub(super) fn crosspoints(&self) -> Vec<Vec<NodeId>> {
        self.crosspoints.clone()
    }
}

/// The whole ties (rank 0), after the serial solve's refusals: dual ties mixed with
/// others or with a conductance of T, dual rows that couple (a side-A face partly
/// covered by side B). `n`: the dofs of the mesh.
fn whole_ties(iface: &dyn Interfaces, n: usize) -> Result<Vec<TieRows>, HeatError> {
    let ties = iface.ties().map_err(HeatError::Contact)?;
    if dual_ties(&ties, iface.is_linear())? {
        dual_condensation(&ties, n)?;
    }
    Ok(ties)
}

/// Rank 0's word on the multipliers of its `whole` ties, on every rank (collective).
fn decide(world: &SimpleCommunicator, whole: &[TieRows], layout: &Layout) -> Vec<Decided> {
    // [ties, then per tie: multipliers, their PETSc indices, empty ones, them].
    let mut word: Vec<i64> = vec![whole.len() as i64];
    for t in whole {
        let mut reached = vec![false; t.own.len()];
        t.entries.iter().for_each(|e| reached[e.0] = true);
        word.push(t.own.len() as i64);
        word.extend(t.own.iter().map(|&d| i64::from(layout.petsc[d])));
        let empty: Vec<i64> = (0..t.own.len())
            .filter(|&k| !reached[k])
            .map(|k| k as i64)
            .collect();
        word.push(empty.len() as i64);
        word.extend(empty);
    }
    // (Every rank gets rank 0's list alone.)
    let word = session::gather_all(world, if layout.rank == 0 { &word[..] } else { &[] });
    let mut it = word.into_iter();
    let mut next = move || it.next().unwrap_or(0);
    let ties = next() as usize;
    let mut decided = Vec::with_capacity(ties);
    for _ in 0..ties {
        let nodes = (0..next()).map(|_| next() as PetscInt).collect();
        let empty = (0..next()).map(|_| next() as usize).collect();
        decided.push(Decided { nodes, empty });
    }
    decided
}
