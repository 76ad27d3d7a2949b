//! Whether a steady problem has a unique answer: every part of the mesh — its elements'
//! nodes joined through shared nodes and through the contact interfaces that paired
//! points — must meet a condition that fixes the temperature level (a prescribed
//! temperature, a convection or a radiation). A part that meets none floats: with only
//! fluxes and sources its temperature is undetermined up to a constant, and unless they
//! balance exactly, no steady state exists. Checked before the solve, so the answer is an
//! input error naming the blocks, not a singular matrix or a temperature of 1e16.

use crate::diag::{Diagnostic, Diagnostics};
use crate::mesh::{Mesh, NodeId};
use crate::search::scene::Pairing;

use super::physics::Physics;
use super::problem::{BcKind, Value};

/// A steady problem needs every part of the mesh held at some temperature level: error
/// E0715 naming the blocks of the first part that floats (with the contact `pairings`
/// joining parts).
pub(super) fn check_steady(physics: &Physics<'_>, pairings: &[Pairing], diags: &mut Diagnostics) {
    let mesh = physics.mesh;
    let mut anchored: Vec<NodeId> = physics.dirichlet.iter().map(|&(n, _)| n).collect();
    for f in &physics.face_sites {
        let bc = &physics.problem.bc[f.bc];
        let exchange = matches!(bc.kind, BcKind::Convection | BcKind::Radiation);
        if exchange && bc.value != Value::Number(0.0) {
            anchored.extend(mesh.side_nodes(f.side));
        }
    }
    let floating = floating_parts(mesh, anchored, pairings);
    if let Some(first) = floating.first() {
        let more = match floating.len() {
            1 => String::new(),
            n => format!(" (and {} more parts)", n - 1),
        };
        diags.push(
            Diagnostic::error(
                "E0715",
                format!(
                    "the steady problem has no unique answer: {} nodes in block(s) {}{more} meet no temperature, convection or radiation condition, through the mesh or a contact interface, so their temperature is fixed only up to a constant (and with fluxes or sources that do not balance, no steady state exists)",
                    first.nodes,
                    first.blocks.join(", ")
                ),
            )
            .help("add a [[bc]] of kind temperature, convection or radiation that reaches those blocks, join them to the rest by a contact interaction, or solve kind = \"transient\""),
        );
    }
}

/// Union–find over the nodes, path-halving, union by index.
struct Parts(Vec<u32>);

impl Parts {
    fn root(&mut self, mut i: u32) -> u32 {
        while self.0[i as usize] != i {
            let up = self.0[self.0[i as usize] as usize];
            self.0[i as usize] = up;
            i = up;
        }
        i
    }

    fn join(&mut self, a: NodeId, b: NodeId) {
        let (ra, rb) = (self.root(a.0), self.root(b.0));
        if ra != rb {
            let (lo, hi) = (ra.min(rb), ra.max(rb));
            self.0[hi as usize] = lo;
        }
    }
}

/// One floating part: its node count and the names of the blocks it touches.
#[derive(Debug, PartialEq)]
pub(super) struct Floating {
    pub nodes: usize,
    pub blocks: Vec<String>,
}

/// The parts of `mesh`, joined through the matched points of `pairings`, that hold none
/// of the `anchored` nodes.
fn floating_parts(
    mesh: &Mesh,
    anchored: impl IntoIterator<Item = NodeId>,
    pairings: &[Pairing],
) -> Vec<Floating> {
    let mut parts = Parts((0..mesh.num_nodes() as u32).collect());
    for e in 0..mesh.num_elems() {
        let nodes = mesh.elem_nodes(crate::mesh::ElemId(e as u32));
        for w in nodes.windows(2) {
            parts.join(w[0], w[1]);
        }
    }
    for p in pairings {
        let (a, b) = (&p.side_a_geometry, &p.side_b_geometry);
        for q in p.result.points.iter() {
            let Some(face_b) = q.matched_b_face() else {
                continue;
            };
            let on_a = match (q.a_face, q.a_node) {
                (Some(f), _) => a.faces[f as usize].nodes[0],
                (None, Some(k)) => match a.nodes.get(k as usize) {
                    Some(n) => n.0,
                    None => continue,
                },
                (None, None) => continue,
            };
            parts.join(on_a, b.faces[face_b].nodes[0]);
        }
    }
    let mut fixed = vec![false; mesh.num_nodes()];
    for n in anchored {
        let r = parts.root(n.0);
        fixed[r as usize] = true;
    }
    // Per floating root: node count and blocks.
    let mut found: std::collections::BTreeMap<u32, (usize, Vec<usize>)> = Default::default();
    let mut used = vec![false; mesh.num_nodes()];
    for e in 0..mesh.num_elems() {
        let elem = crate::mesh::ElemId(e as u32);
        let nodes = mesh.elem_nodes(elem);
        let Some(&first) = nodes.first() else {
            continue;
        };
        let r = parts.root(first.0);
        if fixed[r as usize] {
            continue;
        }
        let entry = found.entry(r).or_default();
        let b = mesh.block_of(elem);
        if !entry.1.contains(&b) {
            entry.1.push(b);
        }
        for n in nodes {
            if !used[n.index()] {
                used[n.index()] = true;
                entry.0 += 1;
            }
        }
    }
    found
        .into_values()
        .map(|(nodes, mut blocks)| {
            blocks.sort_unstable();
            Floating {
                nodes,
                blocks: blocks
                    .into_iter()
                    .map(|b| mesh.blocks[b].sierra_name())
                    .collect(),
            }
        })
        .collect()
}
