//! The interface terms as a host with a sparse matrix of fixed pattern wants them: the
//! Jacobian in CSR whose pattern is worked out at the first [`Embedding::evaluate`] after
//! a search (or a move) and kept, its values refreshed in place at every later call; the
//! residual and load as dense vectors in the host's dofs.
//!
//! The pattern holds every entry the interface blocks can fill — zeros included — so it
//! does not change between evaluations however h changes. Each block entry's place in
//! `values` is found once (`slots`); a refresh is then one pass over the blocks.

use rayon::prelude::*;

use super::{EmbedError, Embedding, Heat, argument};
use crate::slices::{filled_pieces, pieces, same_bits};

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

/// With the `sprs` feature: the Jacobian as an `sprs` matrix, for Rust hosts that keep
/// theirs in `sprs` (the CSR is taken as it is: the same pattern, zeros included).
#[cfg(feature = "sprs")]
impl CsrMatrix {
    pub fn to_sprs(&self) -> sprs::CsMat<f64> {
        sprs::CsMat::new(
            (self.n, self.n),
            self.row_offsets.clone(),
            self.columns.clone(),
            self.values.clone(),
        )
    }
}

/// With the `sprs` feature: the triplet Jacobian of [`super::Contributions`] as an
/// `sprs` CSR matrix of size `n`, repeated entries summed.
#[cfg(feature = "sprs")]
impl super::Contributions {
    pub fn jacobian_sprs(&self, n: usize) -> sprs::CsMat<f64> {
        let mut t = sprs::TriMat::new((n, n));
        for &(r, c, v) in &self.jacobian {
            t.add_triplet(r, c, v);
        }
        t.to_csr()
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
    /// The field (seam's numbering) and time these values were made at, while nothing
    /// else they depend on has changed since ([`Embedding::evaluate`] then gives them
    /// again as they are).
    made_at: Option<(Vec<f64>, f64)>,
}

impl Evaluation {
    /// A search or a move happened: the next evaluation builds a new pattern.
    pub(super) fn outdate(&mut self) {
        self.current = false;
        self.made_at = None;
    }

    /// Something the values depend on besides the field changed (a pressure, a
    /// switch, quarantine): the next evaluation makes them again.
    pub(super) fn forget_values(&mut self) {
        self.made_at = None;
    }
}

impl Embedding {
    /// Evaluate every flux-type interaction at the host's field `u` (by host dof; its
    /// length is the matrix size): the Jacobian in CSR, the residual and load as dense
    /// vectors, the heat. The CSR pattern is built at the first call after
    /// [`Self::search`] or [`Self::move_nodes`] and only its values change afterwards.
    ///
    /// An evaluation at the very field of the last one (bit for bit), with nothing else
    /// changed since — no search, move, pressure, switch or quarantine set, and the same
    /// time unless no model depends on it — gives the last values again without
    /// evaluating a point: a linear time step with fixed steps assembles its right-hand
    /// side at the same field every step. Host models (closures, C callbacks) and
    /// plugins, which may keep state of their own, are always evaluated.
    pub fn evaluate(&mut self, u: &[f64]) -> Result<&Evaluation, EmbedError> {
        let local = self.local_field(u)?;
        self.pattern(u.len())?;
        let repeatable = self.repeatable();
        let time = self.time;
        let mut e = self.evaluation.take().expect("made above");
        let same = repeatable
            && e.made_at.as_ref().is_some_and(|(at, t)| {
                (*t == time || !self.depends_on_time()) && same_bits(at, &local)
            });
        let refreshed = if same {
            Ok(())
        } else {
            // Each block is added into the CSR values as it is made (no block is kept).
            e.made_at = None;
            let refreshed = self.refresh(&mut e, &local);
            if refreshed.is_ok() && repeatable {
                e.made_at = Some((local, time));
            }
            refreshed
        };
        self.evaluation = Some(e);
        refreshed?;
        Ok(self.evaluation.as_ref().expect("just put back"))
    }

    /// The interface residual `R_Γ(u)` of every flux interaction at the host's field
    /// `u`, added into `r` (by host dof, as long as `u`), and the heats as
    /// [`Self::evaluate`] gives them — without the Jacobian, whose blocks are most of an
    /// evaluation's work: for a host that keeps its matrix (linear interfaces, a fixed
    /// step). Each point's residual is [`Self::evaluate`]'s, bit for bit.
    pub fn residual_into(&self, u: &[f64], r: &mut [f64]) -> Result<Vec<Option<Heat>>, EmbedError> {
        if r.len() != u.len() {
            return Err(argument(
                format!(
                    "the residual has {} entries, the field {}",
                    r.len(),
                    u.len()
                ),
                "pass a residual vector as long as the field, indexed by host dof",
            ));
        }
        let local = self.local_field(u)?;
        let mut heat = Vec::with_capacity(self.pairs.len());
        for p in &self.pairs {
            if !p.active {
                heat.push(p.is_flux().then(Heat::default));
                continue;
            }
            let Some(s) = self.with_form(p, |points, form| points.residual(form, &local))? else {
                heat.push(None);
                continue;
            };
            for &(d, v) in &s.residual {
                r[self.host_dof[d as usize]] += v;
            }
            let (side_a, side_b) = s.heat();
            heat.push(Some(Heat { side_a, side_b }));
        }
        Ok(heat)
    }

    /// Whether evaluating twice with the same inputs gives the same values: every
    /// flux interaction's law is a number or a model of seam's own (not a host's or a
    /// plugin's, which may keep state).
    fn repeatable(&self) -> bool {
        self.pairs.iter().all(|p| match &p.enforcement {
            super::Enforcement::Flux { law, .. } => match law {
                super::Law::Constant(_) => true,
                super::Law::Model { plugin, .. } => !plugin,
                super::Law::Host(_) => false,
            },
            super::Enforcement::Tie { .. } => true,
        })
    }

    /// Whether any interaction's terms may change with the time alone: a model that
    /// says so, or a conductivity (or a pair's coefficient) given as a law, which takes
    /// the time.
    fn depends_on_time(&self) -> bool {
        self.conductivity_law.is_some()
            || self.pairs.iter().any(|p| {
                p.coefficient_law.is_some()
                    || match &p.enforcement {
                        super::Enforcement::Flux { law, .. } => match law {
                            super::Law::Constant(_) => false,
                            super::Law::Model { model, .. } | super::Law::Host(model) => {
                                model.depends_on_time()
                            }
                        },
                        super::Enforcement::Tie { .. } => false,
                    }
            })
    }

    /// The pattern of [`Self::evaluate`] for `n` host dofs (the Jacobian's structure and
    /// its pattern number), built when a search or a move has outdated it, without
    /// evaluating any term: the values are those of the last evaluation, or zeros.
    pub fn pattern(&mut self, n: usize) -> Result<&Evaluation, EmbedError> {
        let reuse = self
            .evaluation
            .as_ref()
            .is_some_and(|e| e.current && e.jacobian.n == n && e.slots.len() == self.pairs.len());
        if !reuse {
            self.build_pattern(n)?;
        }
        Ok(self.evaluation.as_ref().expect("built above"))
    }

    /// The values of `e` at seam's field `local`, in place.
    fn refresh(&self, e: &mut Evaluation, local: &[f64]) -> Result<(), EmbedError> {
        let host_dof = &self.host_dof;
        e.jacobian.values.fill(0.0);
        e.residual.fill(0.0);
        e.load.fill(0.0);
        e.heat.clear();
        for (p, slots) in self.pairs.iter().zip(&e.slots) {
            if !p.active {
                e.heat.push(p.is_flux().then(Heat::default));
                continue;
            }
            let values = &mut e.jacobian.values;
            let mut k = 0;
            let system = self.with_form(p, |points, form| {
                points.for_each_block(form, local, |_, m| {
                    for &v in m {
                        if let Some(&at) = slots.get(k) {
                            values[at] += v;
                        }
                        k += 1;
                    }
                })
            })?;
            let Some(s) = system else {
                e.heat.push(None);
                continue;
            };
            if k != slots.len() {
                return Err(EmbedError::Order {
                    what: format!(
                        "interaction {} / {}: {k} Jacobian entries against a pattern of {}",
                        p.side_a.name,
                        p.side_b.name,
                        slots.len()
                    ),
                    help: "search again after changing the interactions".into(),
                });
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
        Ok(())
    }

    /// A new CSR pattern for `n` host dofs: every entry any interaction's blocks can
    /// fill (switched-off ones too, so switching does not change it), and each block
    /// entry's place in it.
    fn build_pattern(&mut self, n: usize) -> Result<(), EmbedError> {
        let host = |d: u32| self.host_dof[d as usize];
        // The blocks' dofs come from the points' groups: no conductance is evaluated.
        let mut blocks: Vec<Vec<Vec<u32>>> = Vec::with_capacity(self.pairs.len());
        for p in &self.pairs {
            let groups = self.with_form(p, |points, _| {
                Ok((0..points.groups())
                    .map(|g| points.group(g).to_vec())
                    .collect())
            })?;
            blocks.push(groups.unwrap_or_default());
        }
        let previous = self.evaluation.as_ref().map_or(0, |e| e.pattern);
        // Every block entry bucketed by its row (counting sort), then each row's
        // columns sorted and made unique in place: no global sort of all entries.
        let mut row_offsets = vec![0; n + 1];
        for dofs in blocks.iter().flatten() {
            for &i in dofs {
                row_offsets[host(i) + 1] += dofs.len();
            }
        }
        for i in 0..n {
            row_offsets[i + 1] += row_offsets[i];
        }
        let mut columns = vec![0usize; row_offsets[n]];
        let mut next = row_offsets.clone();
        for dofs in blocks.iter().flatten() {
            for &i in dofs {
                let at = &mut next[host(i)];
                for (c, &j) in columns[*at..*at + dofs.len()].iter_mut().zip(dofs) {
                    *c = host(j);
                }
                *at += dofs.len();
            }
        }
        // Rows sorted in parallel (each its own slice), then made unique in one pass.
        let lengths = row_offsets.windows(2).map(|w| w[1] - w[0]);
        let mut rows = filled_pieces(&mut columns, lengths);
        rows.par_iter_mut().for_each(|(_, row)| row.sort_unstable());
        drop(rows);
        let mut kept = 0;
        for i in 0..n {
            let (a, b) = (row_offsets[i], row_offsets[i + 1]);
            row_offsets[i] = kept;
            for k in a..b {
                if k == a || columns[k] != columns[k - 1] {
                    columns[kept] = columns[k];
                    kept += 1;
                }
            }
        }
        row_offsets[n] = kept;
        columns.truncate(kept);
        columns.shrink_to_fit();
        let slot = |i: usize, j: usize| {
            let (a, b) = (row_offsets[i], row_offsets[i + 1]);
            a + columns[a..b]
                .binary_search(&j)
                .expect("the pattern holds every block entry")
        };
        // Each group's entries written in place, group by group in parallel.
        let slots = blocks
            .iter()
            .map(|pair| {
                let mut out = vec![0; pair.iter().map(|dofs| dofs.len().pow(2)).sum()];
                let lengths = pair.iter().map(|dofs| dofs.len().pow(2));
                let groups = pieces(&mut out, lengths);
                groups.into_par_iter().zip(pair).for_each(|(to, dofs)| {
                    let row = |&i: &u32| dofs.iter().map(move |&j| slot(host(i), host(j)));
                    for (t, s) in to.iter_mut().zip(dofs.iter().flat_map(row)) {
                        *t = s;
                    }
                });
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
            made_at: None,
        });
        Ok(())
    }

    /// The last [`Self::evaluate`], until the next search or move.
    pub fn evaluation(&self) -> Option<&Evaluation> {
        self.evaluation.as_ref()
    }
}
