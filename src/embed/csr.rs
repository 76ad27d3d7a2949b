//! The interface terms as a host with a sparse matrix of fixed pattern wants them: the
//! Jacobian in CSR whose pattern is worked out at the first [`Embedding::evaluate`] after
//! a search (or a move) and kept, its values refreshed in place at every later call; the
//! residual and load as dense vectors in the host's dofs.
//!
//! The pattern holds every entry the interface blocks can fill — zeros included — so it
//! does not change between evaluations however h changes. Each block entry's place in
//! `values` is found once (`slots`); a refresh is then one pass over the blocks.

use super::{EmbedError, Embedding, Heat};

/// A square sparse matrix in compressed sparse row form, in the host's dof numbers:
/// row `i` holds `columns[row_offsets[i]..row_offsets[i + 1]]` (sorted, no repeats)
/// with `values` alongside.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CsrMatrix {
    /// Rows and columns: the length of the field vector given to `evaluate`.
    pub n: usize,
    /// `n + 1` offsets into `columns` and `values`.
    pub row_offsets: Vec<usize>,
    pub columns: Vec<usize>,
    pub values: Vec<f64>,
}

impl CsrMatrix {
    /// `y += A x`.
    pub fn multiply_add(&self, x: &[f64], y: &mut [f64]) {
        for (i, yi) in y.iter_mut().enumerate().take(self.n) {
            let (a, b) = (self.row_offsets[i], self.row_offsets[i + 1]);
            *yi += (a..b)
                .map(|k| self.values[k] * x[self.columns[k]])
                .sum::<f64>();
        }
    }

    /// The entry at (`row`, `col`), 0 outside the pattern.
    pub fn get(&self, row: usize, col: usize) -> f64 {
        if row >= self.n {
            return 0.0;
        }
        let (a, b) = (self.row_offsets[row], self.row_offsets[row + 1]);
        self.columns[a..b]
            .binary_search(&col)
            .map_or(0.0, |k| self.values[a + k])
    }
}

/// The interface terms of every flux-type interaction at one field, in the host's
/// numbering ([`Embedding::evaluate`]).
#[derive(Clone, Debug, Default)]
pub struct Evaluation {
    /// `∂R_Γ/∂u`, to add to the host's Jacobian (exact, including dh/dT).
    pub jacobian: CsrMatrix,
    /// `R_Γ(u)`, to add to the host's residual `K u − F` (length `n`).
    pub residual: Vec<f64>,
    /// The right-hand side of linear models (offset terms): `R_Γ = J u − load`.
    pub load: Vec<f64>,
    /// Per interaction, in the order they were added; `None` for mortar ties.
    pub heat: Vec<Option<Heat>>,
    /// Counts the patterns built: it changes only when a search or a move made a new
    /// one, so a host can keep its symbolic factorisation while it stays the same.
    pub pattern: u64,
    /// Per interaction, the CSR position of each of its block entries, in block order.
    slots: Vec<Vec<usize>>,
    /// False once a search or a move may have changed the blocks.
    current: bool,
}

impl Evaluation {
    /// A search or a move happened: the next evaluation builds a new pattern.
    pub(super) fn outdate(&mut self) {
        self.current = false;
    }
}

impl Embedding {
    /// Evaluate every flux-type interaction at the host's field `u` (by host dof; its
    /// length is the matrix size): the Jacobian in CSR, the residual and load as dense
    /// vectors, the heat. The CSR pattern is built at the first call after
    /// [`Self::search`] or [`Self::move_nodes`] and only its values change afterwards.
    pub fn evaluate(&mut self, u: &[f64]) -> Result<&Evaluation, EmbedError> {
        let local = self.local_field(u)?;
        let n = u.len();
        let host = |d: u32| self.host_dof[d as usize];
        let reuse = self
            .evaluation
            .as_ref()
            .is_some_and(|e| e.current && e.jacobian.n == n && e.slots.len() == self.pairs.len());
        // An interaction switched off is evaluated only to build a pattern, so the
        // pattern does not change when it is switched on again.
        let mut systems = Vec::with_capacity(self.pairs.len());
        for p in &self.pairs {
            systems.push(if p.active || !reuse {
                self.system(p, &local)?
            } else {
                None
            });
        }
        // The pattern holds while the blocks have the entry counts it was built from.
        let fits = reuse
            && self.evaluation.as_ref().is_some_and(|e| {
                e.slots
                    .iter()
                    .zip(&systems)
                    .zip(&self.pairs)
                    .all(|((slots, s), p)| {
                        let entries = s
                            .as_ref()
                            .map_or(0, |s| s.blocks.iter().map(|(d, _)| d.len() * d.len()).sum());
                        !p.active || slots.len() == entries
                    })
            });
        if !fits {
            for (s, p) in systems.iter_mut().zip(&self.pairs) {
                if s.is_none() && !p.active {
                    *s = self.system(p, &local)?;
                }
            }
            let previous = self.evaluation.as_ref().map_or(0, |e| e.pattern);
            let mut entries: Vec<(usize, usize)> = Vec::new();
            for s in systems.iter().flatten() {
                for (dofs, _) in &s.blocks {
                    for &i in dofs {
                        entries.extend(dofs.iter().map(|&j| (host(i), host(j))));
                    }
                }
            }
            entries.sort_unstable();
            entries.dedup();
            let mut row_offsets = vec![0; n + 1];
            for &(i, _) in &entries {
                row_offsets[i + 1] += 1;
            }
            for i in 0..n {
                row_offsets[i + 1] += row_offsets[i];
            }
            let columns: Vec<usize> = entries.iter().map(|e| e.1).collect();
            let slot = |i: usize, j: usize| {
                let (a, b) = (row_offsets[i], row_offsets[i + 1]);
                a + columns[a..b]
                    .binary_search(&j)
                    .expect("the pattern holds every block entry")
            };
            let slots = systems
                .iter()
                .map(|s| {
                    let mut out = Vec::new();
                    for (dofs, _) in s.iter().flat_map(|s| &s.blocks) {
                        for &i in dofs {
                            out.extend(dofs.iter().map(|&j| slot(host(i), host(j))));
                        }
                    }
                    out
                })
                .collect();
            let nnz = columns.len();
            self.evaluation = Some(Evaluation {
                jacobian: CsrMatrix {
                    n,
                    row_offsets,
                    columns,
                    values: vec![0.0; nnz],
                },
                residual: vec![0.0; n],
                load: vec![0.0; n],
                heat: Vec::new(),
                pattern: previous + 1,
                slots,
                current: true,
            });
        }
        let host_dof = &self.host_dof;
        let e = self.evaluation.as_mut().expect("made above");
        e.jacobian.values.fill(0.0);
        e.residual.fill(0.0);
        e.load.fill(0.0);
        e.heat.clear();
        for ((s, slots), p) in systems.iter().zip(&e.slots).zip(&self.pairs) {
            if !p.active {
                e.heat.push(p.is_flux().then(Heat::default));
                continue;
            }
            let Some(s) = s else {
                e.heat.push(None);
                continue;
            };
            let values = s.blocks.iter().flat_map(|(_, m)| m);
            for (&k, &v) in slots.iter().zip(values) {
                e.jacobian.values[k] += v;
            }
            for &(d, v) in &s.residual {
                e.residual[host_dof[d as usize]] += v;
            }
            for &(d, v) in &s.rhs {
                e.load[host_dof[d as usize]] += v;
            }
            let (side_a, side_b) = s.heat();
            e.heat.push(Some(Heat { side_a, side_b }));
        }
        Ok(e)
    }

    /// The last [`Self::evaluate`], until the next search or move.
    pub fn evaluation(&self) -> Option<&Evaluation> {
        self.evaluation.as_ref()
    }
}
