//! Mortar ties with Lagrange multipliers: `Tied` with `Side B Variable b To a`.
//!
//! The constraint `a = b` on Γ is imposed weakly with multipliers λ on side A: one per
//! side-A interface node, with the side-A trace shape functions as their basis
//! (standard mortar), integrated over the mortar segments:
//!
//! ```text
//! C_kj = Σ_points w ψ_k(x) J_j(x),   J_j = N_A,j on side A, −N_B,j on side B,
//! [K  Cᵀ] [u]   [F]
//! [C  0 ] [λ] = [ΔT ∫ψ]
//! ```
//!
//! λ is the flux from side A to side B; the heat leaving side A, `Σ_A (Cᵀλ)_i = ∫ λ`, is
//! read off the assembled residual like every other model, and the heat leaving side B
//! is minus the same, to round-off.
//!
//! **Crosspoints.** A side-A node that also carries a Dirichlet condition is already
//! constrained: a multiplier there would constrain it twice and make the system
//! singular (the LBB failure MOOSE users meet). Such nodes get no multiplier — the
//! Dirichlet value wins — and are reported. The same holds for a side-A node tied by two
//! mortar interfaces: the first interface in the deck keeps it. The dropped node's
//! basis function is shared equally among the kept nodes of each face it touches, so
//! the multiplier space still holds the constants (Wohlmuth's crosspoint modification)
//! and the patch test stays exact.
//!
//! **Node surfaces.** On a node surface (contact node set, `Contact Type = node`) the
//! multipliers are collocated: one per matched side-A node k with tributary area w_k,
//! `C_k· = w_k (e_k − Σ_j N_B,j(ξ_B) e_j)`, ψ_k = 1 at its own point. The side-A block of
//! C is then diagonal, so standard and dual multipliers coincide, and the constraint
//! holds at every node: `u_k = u_B(x_k)`. A Dirichlet node (or one tied earlier) gets no
//! multiplier, as above; a node without tributary area gets none either (its row would
//! be zero).

use std::collections::{BTreeMap, HashSet};

use crate::assembly::DofMap;
use crate::mesh::{Mesh, NodeId};
use crate::search::pairing::{ContactPoint, SurfaceGeometry};

use super::interface::{FieldPair, InterfaceError, face_shape_values, node_dof, side_eval};

/// The constraint rows of one mortar tie.
#[derive(Clone, Debug, Default)]
pub struct MortarTie {
    /// The side-A node of each multiplier, in multiplier order.
    pub nodes: Vec<NodeId>,
    /// Side-A interface nodes that got no multiplier because they are already
    /// constrained (Dirichlet data or an earlier tie): the crosspoints.
    pub crosspoints: Vec<NodeId>,
    /// (multiplier, dof, value) entries of C.
    pub entries: Vec<(u32, u32, f64)>,
    /// ∫ ψ_k, for a prescribed jump.
    pub psi_integral: Vec<f64>,
    pub side_a_dofs: Vec<u32>,
    pub side_b_dofs: Vec<u32>,
    /// `(point, multiplier, ψ)`: the multiplier basis at each matched face point of the
    /// pairing, for [`MortarTie::point_flux`].
    pub point_psi: Vec<(u32, u32, f64)>,
}

/// Heat leaving side A and side B through a tie for multipliers `lambda` (one per
/// multiplier, the flux from A to B): `Σ_{d ∈ side} (Cᵀλ)_d`, with `entries` the
/// `(multiplier, dof, C)` entries of C in any dof numbering. The one place the tie heat
/// is computed: the solvers, the embedding and its C face all call it.
pub fn tie_heat<D: Copy + Ord>(
    entries: impl IntoIterator<Item = (usize, D, f64)>,
    lambda: &[f64],
    side_a: &[D],
    side_b: &[D],
) -> (f64, f64) {
    let mut ct = std::collections::BTreeMap::<D, f64>::new();
    for (k, d, c) in entries {
        *ct.entry(d).or_default() += c * lambda[k];
    }
    let sum = |set: &[D]| {
        set.iter()
            .map(|d| ct.get(d).copied().unwrap_or(0.0))
            .sum::<f64>()
    };
    (sum(side_a), sum(side_b))
}

/// The multiplier field `λ_h = Σ_k ψ_k λ_k` at `count` points from the basis values
/// `(point, multiplier, ψ)` (`None` at points without a multiplier).
pub fn multiplier_field(
    point_psi: &[(u32, u32, f64)],
    lambda: &[f64],
    count: usize,
) -> Vec<Option<f64>> {
    let mut out = vec![None; count];
    for &(p, k, psi) in point_psi {
        if let Some(q) = out.get_mut(p as usize) {
            *q.get_or_insert(0.0) += psi * lambda[k as usize];
        }
    }
    out
}

impl MortarTie {
    /// Heat leaving side A and side B for multipliers `lambda` ([`tie_heat`]).
    pub fn heat(&self, lambda: &[f64]) -> (f64, f64) {
        tie_heat(
            self.entries.iter().map(|&(k, d, c)| (k as usize, d, c)),
            lambda,
            &self.side_a_dofs,
            &self.side_b_dofs,
        )
    }

    /// The multiplier field `λ_h = Σ_k ψ_k λ_k` at each of the pairing's `count` points
    /// (`None` where the tie has no multiplier: unmatched points, crosspoint nodes). It is
    /// the heat flux from side A to side B: the heat leaving side A is
    /// `Σ_{d∈A} (Cᵀλ)_d = Σ_points w λ_h`, since side A's shape functions sum to one (at a
    /// node point ψ = 1 and side A's entry is w).
    pub fn point_flux(&self, lambda: &[f64], count: usize) -> Vec<Option<f64>> {
        multiplier_field(&self.point_psi, lambda, count)
    }
}

/// Which multiplier basis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Multipliers {
    /// The side-A trace shape functions (standard mortar): a saddle-point solve.
    #[default]
    Standard,
    /// Biorthogonal to the trace shape functions face by face (Wohlmuth's dual
    /// mortar): the side-A block of C is diagonal, so side A's interface values are
    /// condensed out and the system stays symmetric positive definite.
    Dual,
}

/// Build the constraint rows. `constrained` holds nodes that must not get a multiplier
/// (Dirichlet nodes and nodes tied by earlier interfaces); the tie's own nodes are added
/// to it.
#[allow(clippy::too_many_arguments)]
pub fn mortar_tie(
    mesh: &Mesh,
    dofs: &DofMap,
    fields: impl Into<FieldPair>,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    points: &[ContactPoint],
    conductivity: &[f64],
    constrained: &mut HashSet<NodeId>,
    multipliers: Multipliers,
) -> Result<MortarTie, InterfaceError> {
    let fields = fields.into();
    if !a.nodes.is_empty() {
        return node_tie(mesh, dofs, fields, a, b, points, conductivity, constrained);
    }
    let mut index: BTreeMap<NodeId, u32> = BTreeMap::new();
    let mut crosspoints = Vec::new();
    // Multipliers on the side-A faces' nodes, in node order (deterministic).
    let mut face_nodes: Vec<NodeId> = a
        .faces
        .iter()
        .flat_map(|f| f.nodes[..f.len as usize].to_vec())
        .collect();
    face_nodes.sort_unstable();
    face_nodes.dedup();
    for n in face_nodes {
        if constrained.contains(&n) {
            crosspoints.push(n);
        } else {
            let k = index.len() as u32;
            index.insert(n, k);
        }
    }
    // Dual basis: per side-A face, ψ_k = Σ_l A_kl N_l with A = D M⁻¹, M_kl = ∫ N_k N_l and
    // D = diag(Σ_l M_kl), both integrated with the same points as the constraint, so
    // ∫ ψ_k N_l = δ_kl D_kk exactly.
    let dual: Vec<Option<[[f64; 4]; 4]>> = match multipliers {
        Multipliers::Standard => vec![None; a.faces.len()],
        Multipliers::Dual => {
            let mut m = vec![[[0.0f64; 4]; 4]; a.faces.len()];
            for p in points {
                let Some((fa, _)) = p.matched_faces() else {
                    continue;
                };
                let f = &a.faces[fa];
                let n = face_shape_values(f.len as usize, p.xi_a);
                for k in 0..f.len as usize {
                    for l in 0..f.len as usize {
                        m[fa][k][l] += p.weight * n[k] * n[l];
                    }
                }
            }
            a.faces
                .iter()
                .zip(m)
                .map(|(f, m)| dual_coefficients(&m, f.len as usize))
                .collect()
        }
    };
    // Per multiplier, its row `(dof, C_kd)` in order of first touch: a row holds a few
    // dozen dofs, so a scan finds an entry sooner than a map of every entry would (11 M
    // updates at 358 400 points), and each sum runs in point order as before.
    let mut rows: Vec<Vec<(u32, f64)>> = vec![Vec::new(); index.len()];
    let add = |row: &mut Vec<(u32, f64)>, d: u32, v: f64| match row.iter_mut().find(|e| e.0 == d) {
        Some(e) => e.1 += v,
        None => row.push((d, v)),
    };
    let mut psi_integral = vec![0.0; index.len()];
    let mut side_a = Vec::new();
    let mut side_b = Vec::new();
    let mut point_psi = Vec::new();
    for (at, p) in points.iter().enumerate() {
        let Some((face_a, face_b)) = p.matched_faces() else {
            continue;
        };
        let fa = &a.faces[face_a];
        let fb = &b.faces[face_b];
        let ea = side_eval(mesh, dofs, fields.a, fa.side, p.xi_a, conductivity)?;
        let eb = side_eval(mesh, dofs, fields.b, fb.side, p.xi_b, conductivity)?;
        let nodes_a = mesh.elem_nodes(ea.elem);
        // ψ on this face: each kept node's trace shape function, plus an equal share of
        // the dropped (crosspoint) nodes' — so the multipliers still sum to one and can
        // carry a constant flux up to the rim (the crosspoint modification of the
        // mortar basis; without it the patch test fails near Dirichlet rims).
        let shape_of = |node: NodeId| {
            nodes_a
                .iter()
                .position(|&n| n == node)
                .map_or(0.0, |i| ea.n[i])
        };
        let face = &fa.nodes[..fa.len as usize];
        // The multiplier basis at this point, per face node: N, or the dual ψ.
        let basis: Vec<f64> = match &dual[face_a] {
            None => face.iter().map(|&n| shape_of(n)).collect(),
            Some(c) => {
                let nf = face_shape_values(face.len(), p.xi_a);
                (0..face.len())
                    .map(|k| (0..face.len()).map(|l| c[k][l] * nf[l]).sum())
                    .collect()
            }
        };
        let kept: Vec<(u32, f64)> = face
            .iter()
            .zip(&basis)
            .filter_map(|(n, &b)| index.get(n).map(|&k| (k, b)))
            .collect();
        if kept.is_empty() {
            continue;
        }
        let dropped: f64 = face
            .iter()
            .zip(&basis)
            .filter(|(n, _)| !index.contains_key(n))
            .map(|(_, &b)| b)
            .sum();
        let share = dropped / kept.len() as f64;
        for &(k, n_k) in &kept {
            let psi = n_k + share;
            if psi == 0.0 {
                continue;
            }
            psi_integral[k as usize] += p.weight * psi;
            point_psi.push((at as u32, k, psi));
            let row = &mut rows[k as usize];
            for j in 0..ea.len {
                add(row, ea.dofs[j], p.weight * psi * ea.n[j]);
            }
            for j in 0..eb.len {
                add(row, eb.dofs[j], -(p.weight * psi * eb.n[j]));
            }
        }
        side_a.extend_from_slice(&ea.dofs[..ea.len]);
        side_b.extend_from_slice(&eb.dofs[..eb.len]);
    }
    side_a.sort_unstable();
    side_a.dedup();
    side_b.sort_unstable();
    side_b.dedup();
    let nodes: Vec<NodeId> = {
        let mut v = vec![NodeId(0); index.len()];
        for (&n, &k) in &index {
            v[k as usize] = n;
        }
        v
    };
    constrained.extend(nodes.iter().copied());
    Ok(MortarTie {
        nodes,
        crosspoints,
        entries: (rows.into_iter().enumerate())
            .flat_map(|(k, mut row)| {
                row.sort_unstable_by_key(|e| e.0);
                row.into_iter()
                    .filter(|e| e.1 != 0.0)
                    .map(move |(d, v)| (k as u32, d, v))
            })
            .collect(),
        psi_integral,
        side_a_dofs: side_a,
        side_b_dofs: side_b,
        point_psi,
    })
}

/// The collocated tie of a node surface (module docs, "Node surfaces").
#[allow(clippy::too_many_arguments)]
fn node_tie(
    mesh: &Mesh,
    dofs: &DofMap,
    fields: FieldPair,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    points: &[ContactPoint],
    conductivity: &[f64],
    constrained: &mut HashSet<NodeId>,
) -> Result<MortarTie, InterfaceError> {
    let mut tie = MortarTie::default();
    let mut side_a = Vec::new();
    let mut side_b = Vec::new();
    // Points in node order (a surface's nodes ascend), so multipliers do too.
    let mut node_points: Vec<(usize, &ContactPoint)> = points
        .iter()
        .enumerate()
        .filter(|(_, p)| p.matched_node().is_some() && p.weight > 0.0)
        .collect();
    node_points.sort_by_key(|(_, p)| p.a_node);
    for (at, p) in node_points {
        let Some((a_node, face_b)) = p.matched_node() else {
            continue;
        };
        let Some(&(node, _)) = a.nodes.get(a_node) else {
            continue;
        };
        if constrained.contains(&node) {
            tie.crosspoints.push(node);
            continue;
        }
        if tie.nodes.last() == Some(&node) {
            continue; // one multiplier per node
        }
        let own = node_dof(mesh, dofs, fields.a, node, &a.name)?;
        let fb = &b.faces[face_b];
        let eb = side_eval(mesh, dofs, fields.b, fb.side, p.xi_b, conductivity)?;
        let k = tie.nodes.len() as u32;
        tie.nodes.push(node);
        tie.psi_integral.push(p.weight);
        tie.point_psi.push((at as u32, k, 1.0));
        let mut row: BTreeMap<u32, f64> = BTreeMap::new();
        *row.entry(own).or_default() += p.weight;
        for j in 0..eb.len {
            *row.entry(eb.dofs[j]).or_default() -= p.weight * eb.n[j];
        }
        tie.entries.extend(
            row.into_iter()
                .filter(|(_, v)| *v != 0.0)
                .map(|(d, v)| (k, d, v)),
        );
        side_a.push(own);
        side_b.extend_from_slice(&eb.dofs[..eb.len]);
    }
    side_a.sort_unstable();
    side_a.dedup();
    side_b.sort_unstable();
    side_b.dedup();
    tie.side_a_dofs = side_a;
    tie.side_b_dofs = side_b;
    constrained.extend(tie.nodes.iter().copied());
    Ok(tie)
}

/// `A = D M⁻¹` for a face mass matrix `M` (n × n, n ≤ 4), by Gauss–Jordan elimination;
/// `None` for a face without integration points (no overlap).
fn dual_coefficients(m: &[[f64; 4]; 4], n: usize) -> Option<[[f64; 4]; 4]> {
    let scale = (0..n).map(|k| m[k][k].abs()).fold(0.0, f64::max);
    if scale == 0.0 {
        return None;
    }
    // Solve M X = I; then A = D X.
    let mut a = [[0.0f64; 8]; 4];
    for k in 0..n {
        for l in 0..n {
            a[k][l] = m[k][l];
        }
        a[k][n + k] = 1.0;
    }
    for col in 0..n {
        let pivot = (col..n).max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))?;
        if a[pivot][col].abs() <= 1e-14 * scale {
            return None;
        }
        a.swap(col, pivot);
        let d = a[col][col];
        for v in a[col].iter_mut().take(2 * n) {
            *v /= d;
        }
        for r in 0..n {
            if r != col {
                let f = a[r][col];
                if f != 0.0 {
                    let pivot_row = a[col];
                    for (x, p) in a[r].iter_mut().zip(pivot_row).take(2 * n) {
                        *x -= f * p;
                    }
                }
            }
        }
    }
    let mut out = [[0.0f64; 4]; 4];
    for k in 0..n {
        let d: f64 = (0..n).map(|l| m[k][l]).sum();
        for l in 0..n {
            out[k][l] = d * a[k][n + l];
        }
    }
    Some(out)
}
