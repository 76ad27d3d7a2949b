//! The interface terms of a rank's own points as a host with sparse matrices of fixed
//! pattern wants them ([`RankEmbedding::evaluate`]): the rank's share of the Jacobian in
//! CSR over the rows its points touch, in the host's global dofs, its pattern built at
//! the first evaluation after a search or a move and its values refreshed in place
//! afterwards; the residual and load at those rows.
//!
//! It is the serial [`crate::embed::Embedding::evaluate`] of the rank's inner embedding
//! (the rank's own points only), read through a map made once per pattern: each inner
//! row and entry to its place among the global rows and columns (sorted).

use super::{RankEmbedding, agree};
use crate::embed::{EmbedError, Heat};

/// One rank's interface terms in CSR ([`RankEmbedding::evaluate`]). Summed over the
/// ranks (each rank adding its rows with `ADD_VALUES`, as they may be other ranks'
/// rows), they are the serial embedding's [`crate::embed::Evaluation`].
#[derive(Clone, Debug, Default)]
pub struct RankEvaluation {
    /// The host's global dofs of the rows: every dof this rank's own points couple,
    /// ascending.
    pub rows: Vec<usize>,
    /// `rows.len() + 1` offsets into `columns` and `values`.
    pub row_offsets: Vec<usize>,
    /// The host's global dofs, ascending within each row (every entry the interface
    /// blocks can fill, zeros included: the pattern does not change with h).
    pub columns: Vec<usize>,
    pub values: Vec<f64>,
    /// This rank's share of `R_Γ(u)` at each of `rows`.
    pub residual: Vec<f64>,
    /// This rank's share of the right-hand side of linear models at each of `rows`.
    pub load: Vec<f64>,
    /// Per interaction, the heat summed over every rank (`None` for mortar ties).
    pub heat: Vec<Option<Heat>>,
    /// The inner embedding's pattern number these rows and columns were made from:
    /// it changes only when a search or a move made a new pattern, so a host may keep
    /// its preallocation while it stays.
    pub pattern: u64,
    /// Per inner CSR entry, its place in `values` (several inner entries may meet in
    /// one: two inner nodes the host gave the same global dof).
    entry_at: Vec<usize>,
    /// Per inner dof with entries, its row (`(inner dof, row)`).
    row_at: Vec<(usize, usize)>,
}

impl RankEmbedding {
    /// Evaluate this rank's own points at the host's field into CSR (collective;
    /// `u_local` as for [`Self::contributions`]): the rows its points touch, in the
    /// host's global dofs, with the residual and load there and the heats summed over
    /// the ranks. The rows and columns are made at the first call after a search or a
    /// move and kept; later calls refresh the values in place.
    pub fn evaluate(&mut self, u_local: &[f64]) -> Result<&RankEvaluation, EmbedError> {
        let u = self.whole_field(u_local)?;
        agree(&self.comm, self.inner.evaluate(&u).map(|_| ()))?;
        let inner = self.inner.evaluation().expect("evaluated above");
        let mut e = (self.evaluation.take())
            .filter(|e| e.pattern == inner.pattern)
            .unwrap_or_else(|| self.pattern_of(inner));
        let j = &inner.jacobian;
        e.values.iter_mut().for_each(|v| *v = 0.0);
        for (&at, &v) in e.entry_at.iter().zip(&j.values) {
            e.values[at] += v;
        }
        e.residual.iter_mut().for_each(|v| *v = 0.0);
        e.load.iter_mut().for_each(|v| *v = 0.0);
        for &(d, r) in &e.row_at {
            e.residual[r] += inner.residual[d];
            e.load[r] += inner.load[d];
        }
        e.heat = inner.heat.clone();
        self.sum_heat(&mut e.heat);
        Ok(self.evaluation.insert(e))
    }

    /// The rows and columns of the inner evaluation `inner` in global dofs, and the map
    /// from its entries to theirs.
    fn pattern_of(&self, inner: &crate::embed::Evaluation) -> RankEvaluation {
        let j = &inner.jacobian;
        let dof = |k: usize| self.global_dof[k];
        let touched: Vec<usize> = (0..j.n)
            .filter(|&i| j.row_offsets[i + 1] > j.row_offsets[i])
            .collect();
        let mut rows: Vec<usize> = touched.iter().map(|&i| dof(i)).collect();
        rows.sort_unstable();
        rows.dedup();
        let row_of = |g: usize| rows.binary_search(&g).expect("a touched row");
        // Per row its columns, sorted and unique.
        let mut columns_of: Vec<Vec<usize>> = vec![Vec::new(); rows.len()];
        for &i in &touched {
            let cols = &j.columns[j.row_offsets[i]..j.row_offsets[i + 1]];
            columns_of[row_of(dof(i))].extend(cols.iter().map(|&c| dof(c)));
        }
        let mut row_offsets = vec![0];
        for c in &mut columns_of {
            c.sort_unstable();
            c.dedup();
            row_offsets.push(row_offsets.last().unwrap() + c.len());
        }
        let mut entry_at = vec![0; j.columns.len()];
        let mut row_at = Vec::with_capacity(touched.len());
        for &i in &touched {
            let r = row_of(dof(i));
            row_at.push((i, r));
            let cols = &columns_of[r];
            let span = j.row_offsets[i]..j.row_offsets[i + 1];
            for (at, &c) in entry_at[span.clone()].iter_mut().zip(&j.columns[span]) {
                *at = row_offsets[r] + cols.binary_search(&dof(c)).expect("a column");
            }
        }
        let nnz = *row_offsets.last().unwrap();
        RankEvaluation {
            residual: vec![0.0; rows.len()],
            load: vec![0.0; rows.len()],
            rows,
            row_offsets,
            columns: columns_of.concat(),
            values: vec![0.0; nnz],
            heat: Vec::new(),
            pattern: inner.pattern,
            entry_at,
            row_at,
        }
    }

    /// The last [`Self::evaluate`] (local).
    pub fn evaluation(&self) -> Option<&RankEvaluation> {
        self.evaluation.as_ref()
    }
}
