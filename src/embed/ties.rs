use super::{Condensed, EmbedError, Embedding, Enforcement, Heat, Multipliers, argument};
use std::collections::{BTreeMap, HashSet};

use crate::assembly::FieldId;
use crate::enforce::mortar::mortar_tie;
use crate::mesh::NodeId;

/// The constraint rows of one mortar tie, in the host's numbering.
#[derive(Clone, Debug, Default)]
pub struct TieConstraints {
    /// Index of the interaction.
    pub interaction: usize,
    /// The host dof of each multiplier's side-A node, in multiplier order.
    pub multiplier_dofs: Vec<usize>,
    /// `(multiplier k, dof j, C_kj)`: the rows of `C u = g`.
    pub entries: Vec<(usize, usize, f64)>,
    /// `g_k = ΔT ∫ψ_k`.
    pub rhs: Vec<f64>,
    /// Side-A nodes left without a multiplier because they were fixed or belong to an
    /// earlier tie (crosspoints), as host node indices.
    pub crosspoints: Vec<usize>,
    /// Standard or dual multipliers.
    pub multipliers: Multipliers,
    /// Dual multipliers only: each multiplier's side-A dof in condensed form (a host
    /// without multipliers substitutes these rows; the system stays SPD).
    pub condensed: Vec<Condensed>,
    /// `C_kk` of each multiplier's own dof (dual: the diagonal `D`).
    diagonal: Vec<f64>,
    pub(crate) side_a_dofs: Vec<usize>,
    pub(crate) side_b_dofs: Vec<usize>,
    /// `(point, multiplier, ψ)`: the multiplier basis at the pairing's points.
    point_psi: Vec<(u32, u32, f64)>,
}

impl TieConstraints {
    fn check_lambda(&self, lambda: &[f64]) -> Result<(), EmbedError> {
        if lambda.len() != self.multiplier_dofs.len() {
            return Err(argument(
                format!(
                    "{} multipliers given, the tie has {}",
                    lambda.len(),
                    self.multiplier_dofs.len()
                ),
                "pass one value per entry of `multiplier_dofs`",
            ));
        }
        if let Some(k) = lambda.iter().position(|v| !v.is_finite()) {
            return Err(argument(
                format!("multiplier {k} is not finite ({})", lambda[k]),
                "check the host's solve",
            ));
        }
        Ok(())
    }

    /// The multiplier field `λ_h = Σ ψ_k λ_k` at each of the pairing's `count` points
    /// (`None` where the tie has no multiplier): the heat flux from side A to side B.
    pub(crate) fn multiplier_field(
        &self,
        lambda: &[f64],
        count: usize,
    ) -> Result<Vec<Option<f64>>, EmbedError> {
        self.check_lambda(lambda)?;
        Ok(crate::enforce::mortar::multiplier_field(
            &self.point_psi,
            lambda,
            count,
        ))
    }

    /// A tie condensed by its host has dual multipliers.
    fn dual_only(&self) -> Result<(), EmbedError> {
        if self.condensed.is_empty() && !self.multiplier_dofs.is_empty() {
            return Err(argument(
                "this tie has standard multipliers; they are unknowns of the host's system".into(),
                "read λ from the host's solution, or build the tie with Multipliers::Dual",
            ));
        }
        Ok(())
    }

    /// Heat leaving each side for multipliers `lambda` (the flux from A to B), one per
    /// multiplier: `Σ_{i ∈ side} (Cᵀλ)_i`.
    pub fn heat(&self, lambda: &[f64]) -> Result<Heat, EmbedError> {
        self.check_lambda(lambda)?;
        let (side_a, side_b) = crate::enforce::mortar::tie_heat(
            self.entries.iter().copied(),
            lambda,
            &self.side_a_dofs,
            &self.side_b_dofs,
        );
        Ok(Heat { side_a, side_b })
    }

    /// Dual multipliers of a host that condensed the tie: `λ_k = −r_k / D_k`, with `r`
    /// the host's own residual `K u − F` (without the tie) at its solution, by host dof.
    pub fn dual_multipliers(&self, residual: &[f64]) -> Result<Vec<f64>, EmbedError> {
        self.dual_only()?;
        let at = (self.multiplier_dofs.iter())
            .map(|&d| {
                residual.get(d).copied().ok_or_else(|| {
                    argument(
                        format!("residual has {} entries, dof {d} is needed", residual.len()),
                        "pass the host's whole residual vector",
                    )
                })
            })
            .collect::<Result<Vec<f64>, _>>()?;
        self.dual_multipliers_at(&at)
    }

    /// [`Self::dual_multipliers`] from the residual at each multiplier's own dof, in
    /// multiplier order (`at[k]` at `multiplier_dofs[k]`): what a host on MPI has of
    /// its residual at the multipliers its rank owns.
    pub fn dual_multipliers_at(&self, at: &[f64]) -> Result<Vec<f64>, EmbedError> {
        self.dual_only()?;
        if at.len() != self.multiplier_dofs.len() {
            return Err(argument(
                format!(
                    "{} residual values given, the tie has {} multipliers",
                    at.len(),
                    self.multiplier_dofs.len()
                ),
                "pass the residual at each entry of `multiplier_dofs`, in order",
            ));
        }
        Ok((at.iter().zip(&self.diagonal))
            .map(|(r, &diag)| if diag == 0.0 { 0.0 } else { -r / diag })
            .collect())
    }
}

impl TieConstraints {
    /// The rows of the multipliers whose side-A node `mine` holds, renumbered in their
    /// order, with every dof mapped by `dof` and every crosspoint node by `node` (only
    /// those `mine` holds kept); and each kept multiplier's index in `self`. A tie's
    /// rows on one rank of a host on MPI ([`super::RankEmbedding::constraints`]), its
    /// dofs being the inner embedding's nodes.
    #[cfg(feature = "mpi")]
    pub(crate) fn restricted(
        &self,
        mine: &dyn Fn(usize) -> bool,
        dof: &dyn Fn(usize) -> usize,
        node: &dyn Fn(usize) -> usize,
    ) -> (TieConstraints, Vec<usize>) {
        let index: Vec<usize> = (0..self.multiplier_dofs.len())
            .filter(|&k| mine(self.multiplier_dofs[k]))
            .collect();
        let mut kept = vec![usize::MAX; self.multiplier_dofs.len()];
        for (i, &k) in index.iter().enumerate() {
            kept[k] = i;
        }
        let rows = TieConstraints {
            interaction: self.interaction,
            multiplier_dofs: index
                .iter()
                .map(|&k| dof(self.multiplier_dofs[k]))
                .collect(),
            entries: (self.entries.iter())
                .filter(|e| kept[e.0] != usize::MAX)
                .map(|&(k, d, c)| (kept[k], dof(d), c))
                .collect(),
            rhs: index.iter().map(|&k| self.rhs[k]).collect(),
            crosspoints: (self.crosspoints.iter())
                .filter(|&&n| mine(n))
                .map(|&n| node(n))
                .collect(),
            multipliers: self.multipliers,
            condensed: (self.condensed.iter())
                .filter(|c| mine(c.dof))
                .map(|c| Condensed {
                    dof: dof(c.dof),
                    constant: c.constant,
                    terms: c.terms.iter().map(|&(j, v)| (dof(j), v)).collect(),
                })
                .collect(),
            diagonal: index.iter().map(|&k| self.diagonal[k]).collect(),
            side_a_dofs: self.side_a_dofs.iter().map(|&d| dof(d)).collect(),
            side_b_dofs: self.side_b_dofs.iter().map(|&d| dof(d)).collect(),
            point_psi: (self.point_psi.iter())
                .filter(|e| kept[e.1 as usize] != usize::MAX)
                .map(|&(p, k, psi)| (p, kept[k as usize] as u32, psi))
                .collect(),
        };
        (rows, index)
    }
}

impl Embedding {
    /// The constraint rows of every mortar tie, in interaction order. Fixed nodes and
    /// nodes of an earlier tie get no multiplier (crosspoints).
    pub fn constraints(&self) -> Result<Vec<TieConstraints>, EmbedError> {
        self.tie_rows(true)
    }

    /// The constraint rows of every mortar tie; dual ties in condensed form too when
    /// `condensed_too` (a host that solves for the multipliers does not need it, and a
    /// partly covered side A cannot be condensed).
    pub(crate) fn tie_rows(&self, condensed_too: bool) -> Result<Vec<TieConstraints>, EmbedError> {
        self.tie_rows_of(condensed_too, None)
    }

    /// This process's share of every mortar tie's rows: those of the points it
    /// evaluates ([`Embedding::own_points`]), each tie's multipliers on the side-A nodes
    /// `carries(tie, node)` accepts (the ties' order; the whole tie's, decided where the
    /// whole interface is held). Summed over the processes that share the points, they
    /// are the whole tie's rows; dual bases are made face by face, so theirs too.
    pub(crate) fn own_tie_rows(
        &self,
        carries: &dyn Fn(usize, NodeId) -> bool,
    ) -> Result<Vec<TieConstraints>, EmbedError> {
        self.tie_rows_of(false, Some(carries))
    }

    fn tie_rows_of(
        &self,
        condensed_too: bool,
        carries: Option<&dyn Fn(usize, NodeId) -> bool>,
    ) -> Result<Vec<TieConstraints>, EmbedError> {
        // Per side-A field: its fixed nodes, then the nodes of its earlier ties.
        let mut constrained: std::collections::HashMap<FieldId, HashSet<NodeId>> =
            Default::default();
        let mut out = Vec::new();
        for (index, p) in self.pairs.iter().enumerate() {
            let result = Self::searched(p)?;
            let Enforcement::Tie {
                multipliers,
                offset,
            } = &p.enforcement
            else {
                continue;
            };
            // A share: the points kept, every side-A node but those carrying this
            // tie's multipliers held as constrained.
            let (points, mut share_constrained): (Vec<_>, HashSet<NodeId>);
            let (points, constrained) = match carries {
                None => (
                    &result.points[..],
                    constrained
                        .entry(p.fields.a)
                        .or_insert_with(|| self.fixed_of_field(p.fields.a)),
                ),
                Some(carries) => {
                    let t = out.len();
                    points = match &p.kept {
                        Some(kept) => kept.iter().map(|&k| result.points[k]).collect(),
                        None => result.points.to_vec(),
                    };
                    share_constrained = (p.a.faces.iter())
                        .flat_map(|f| f.nodes[..f.len as usize].iter().copied())
                        .chain(p.a.nodes.iter().map(|n| n.0))
                        .filter(|&n| !carries(t, n))
                        .collect();
                    (&points[..], &mut share_constrained)
                }
            };
            let tie = mortar_tie(
                &self.mesh,
                &self.dofs,
                p.fields,
                &p.a,
                &p.b,
                points,
                p.coefficient(&self.conductivity),
                constrained,
                *multipliers,
            )
            .map_err(|source| EmbedError::Enforcement {
                side_a: p.side_a.name.clone(),
                side_b: p.side_b.name.clone(),
                source,
            })?;
            let host = |d: u32| self.host_dof[d as usize];
            let own: Vec<u32> = tie
                .nodes
                .iter()
                .map(|&n| self.dofs.dof(p.fields.a, n).map_or(u32::MAX, |d| d.0))
                .collect();
            let mut rows: Vec<BTreeMap<u32, f64>> = vec![BTreeMap::new(); tie.nodes.len()];
            for &(k, d, c) in &tie.entries {
                *rows[k as usize].entry(d).or_default() += c;
            }
            let diagonal: Vec<f64> = rows
                .iter()
                .zip(&own)
                .map(|(row, d)| row.get(d).copied().unwrap_or(0.0))
                .collect();
            let mut t = TieConstraints {
                interaction: index,
                multiplier_dofs: own.iter().map(|&d| host(d)).collect(),
                entries: tie
                    .entries
                    .iter()
                    .map(|&(k, d, c)| (k as usize, host(d), c))
                    .collect(),
                rhs: tie.psi_integral.iter().map(|psi| offset * psi).collect(),
                crosspoints: tie.crosspoints.iter().map(|n| n.index()).collect(),
                multipliers: *multipliers,
                condensed: Vec::new(),
                diagonal,
                side_a_dofs: tie.side_a_dofs.iter().map(|&d| host(d)).collect(),
                side_b_dofs: tie.side_b_dofs.iter().map(|&d| host(d)).collect(),
                point_psi: tie.point_psi.clone(),
            };
            if condensed_too && *multipliers == Multipliers::Dual {
                t.condensed = condense(&t, &rows, &own, &host, &p.side_a.name)?;
            }
            out.push(t);
        }
        Ok(out)
    }
}

impl From<&TieConstraints> for crate::heat::interfaces::TieRows {
    fn from(t: &TieConstraints) -> Self {
        Self {
            own: t.multiplier_dofs.clone(),
            entries: t.entries.clone(),
            rhs: t.rhs.clone(),
            crosspoints: t.crosspoints.iter().map(|&n| NodeId(n as u32)).collect(),
            side_a_dofs: t.side_a_dofs.clone(),
            side_b_dofs: t.side_b_dofs.clone(),
            dual: t.multipliers == Multipliers::Dual,
        }
    }
}

impl Embedding {
    /// The nodes of `field` the host fixed (its own list, or the common one).
    fn fixed_of_field(&self, field: FieldId) -> HashSet<NodeId> {
        let own = self.fixed_of.iter().find(|(f, _)| *f == field);
        own.map_or(&self.fixed, |(_, n)| n)
            .iter()
            .copied()
            .collect()
    }
}

/// The dual rows solved for their own dof: `u_k = (g_k − Σ_{j≠k} C_kj u_j) / D_k`.
fn condense(
    t: &TieConstraints,
    rows: &[BTreeMap<u32, f64>],
    own: &[u32],
    host: &dyn Fn(u32) -> usize,
    side_a: &str,
) -> Result<Vec<Condensed>, EmbedError> {
    let condensed: HashSet<u32> = own
        .iter()
        .zip(&t.diagonal)
        .filter(|(_, d)| **d != 0.0)
        .map(|(o, _)| *o)
        .collect();
    let mut out = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        let d = t.diagonal[k];
        if d == 0.0 {
            continue; // a node no point reached: left free
        }
        let mut terms = Vec::new();
        for (&j, &c) in row {
            if j == own[k] {
                continue;
            }
            let coefficient = -c / d;
            // Biorthogonality keeps side-A rows apart; a coupling means a side-A face
            // only partly covered by side B.
            if condensed.contains(&j) && coefficient.abs() > 1e-9 {
                return Err(argument(
                    format!(
                        "dual mortar on side A `{side_a}`: the rows of dofs {} and {} are coupled ({coefficient:.3e}); a side-A face is only partly covered by side B",
                        host(own[k]),
                        host(j)
                    ),
                    "use standard multipliers (Multipliers::Standard) for this tie",
                ));
            }
            if !condensed.contains(&j) {
                terms.push((host(j), coefficient));
            }
        }
        out.push(Condensed {
            dof: host(own[k]),
            constant: t.rhs[k] / d,
            terms,
        });
    }
    Ok(out)
}
