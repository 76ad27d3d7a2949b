//! One side of an interface at a contact point: the element behind a face, its dofs,
//! shape values and physical gradients at the point, the outward normal, k and the
//! penalty length h_e ([`side_eval`]); the part that is the same at every point of a
//! face is made once per face ([`FaceElement`]).

#![allow(clippy::needless_range_loop)] // index loops mirror the formulas' subscripts

use crate::assembly::{DofMap, FieldId};
use crate::fem::shape::reference_nodes;
use crate::fem::{MAX_NODES, eval_point};
use crate::mesh::{ElemId, Mesh, NodeId, Side, Topology};
use crate::vec3::{cross, norm, sub};

use super::{InterfaceError, face_shape_values};

/// Everything one contact point needs from one side: the element, its dofs, shape
/// values and physical gradients at the point, the outward normal, k and h_e.
#[derive(Clone, Copy, Debug)]
pub struct SideEval {
    pub elem: ElemId,
    pub len: usize,
    pub dofs: [u32; MAX_NODES],
    pub n: [f64; MAX_NODES],
    pub grad: [[f64; 3]; MAX_NODES],
    pub normal: [f64; 3],
    pub k: f64,
    /// Element volume / face area: the length of the Nitsche penalty.
    pub h_e: f64,
}

/// Evaluate one side at a point of face `side`, face coordinates `xi`.
pub fn side_eval(
    mesh: &Mesh,
    dofs: &DofMap,
    field: FieldId,
    side: Side,
    xi: [f64; 2],
    conductivity: &[f64],
) -> Result<SideEval, InterfaceError> {
    FaceElement::new(mesh, dofs, field, side, conductivity).eval(mesh, dofs, xi)
}

/// What every point of one face needs from the element behind it: the part of a
/// [`SideEval`] that does not depend on where on the face the point is, so an
/// interface evaluates it once per face. Its failures wait for [`FaceElement::eval`],
/// which reports them in the order [`side_eval`] always has (no shape functions, bad
/// element at the point, missing dof).
#[derive(Clone, Copy, Debug)]
pub(super) struct FaceElement {
    side: Side,
    topology: Topology,
    /// Reference coordinates of the face's nodes in the element (`None`: no shape
    /// functions), and the face's node count.
    face_nodes: Option<([[f64; 3]; 4], usize)>,
    len: usize,
    dofs: [u32; MAX_NODES],
    /// The first node without a dof of the field, if any.
    missing: Option<NodeId>,
    field: FieldId,
    normal: [f64; 3],
    k: f64,
    h_e: f64,
}

impl FaceElement {
    pub(super) fn new(
        mesh: &Mesh,
        dofs: &DofMap,
        field: FieldId,
        side: Side,
        conductivity: &[f64],
    ) -> Self {
        let elem = side.elem;
        let topology = mesh.topology(elem);
        let nodes = mesh.elem_nodes(elem);
        let mut out = FaceElement {
            side,
            topology,
            face_nodes: face_reference_nodes(topology, side.side),
            len: nodes.len(),
            dofs: [0; MAX_NODES],
            missing: None,
            field,
            normal: outward_normal(mesh, side),
            k: conductivity[mesh.block_of(elem)],
            h_e: element_length(mesh, elem, side),
        };
        for (k, &node) in nodes.iter().enumerate() {
            match dofs.dof(field, node) {
                Some(d) => out.dofs[k] = d.0,
                None => {
                    out.missing = Some(node);
                    break;
                }
            }
        }
        out
    }

    /// The side at face coordinates `xi`: shape values and physical gradients there.
    pub(super) fn eval(
        &self,
        mesh: &Mesh,
        dofs: &DofMap,
        xi: [f64; 2],
    ) -> Result<SideEval, InterfaceError> {
        let (elem, topology) = (self.side.elem, self.topology);
        let number = mesh.elem_number(elem);
        let (nodes, len) = self
            .face_nodes
            .ok_or(InterfaceError::NoShapes { number, topology })?;
        // The face's own shape functions interpolate its nodes' reference coordinates.
        let w = face_shape_values(len, xi);
        let mut xi3 = [0.0; 3];
        for k in 0..len {
            for d in 0..3 {
                xi3[d] += w[k] * nodes[k][d];
            }
        }
        let coords = elem_coords(mesh, elem);
        let pv = eval_point(topology, &coords[..self.len], xi3, 1.0)
            .map_err(|b| InterfaceError::BadElement { number, det: b.det })?;
        if let Some(node) = self.missing {
            return Err(InterfaceError::NoDof {
                number: mesh.node_number(node),
                elem: number,
                field: dofs.field_name(self.field).to_string(),
            });
        }
        Ok(SideEval {
            elem,
            len: self.len,
            dofs: self.dofs,
            n: pv.n,
            grad: pv.grad,
            normal: self.normal,
            k: self.k,
            h_e: self.h_e,
        })
    }
}

/// Reference coordinates, in an element of `topology`, of the nodes of its local side
/// `side` (1-based), and their count; `None` without shape functions or for a side
/// that is not an edge (2-D), a triangle or a quadrilateral.
fn face_reference_nodes(topology: Topology, side: u8) -> Option<([[f64; 3]; 4], usize)> {
    let nodes = reference_nodes(topology)?;
    let local = topology.sides().get((side as usize).checked_sub(1)?)?;
    if !matches!(local.len(), 2..=4) {
        return None;
    }
    let mut out = [[0.0; 3]; 4];
    for (k, &l) in local.iter().enumerate() {
        out[k] = nodes[l as usize];
    }
    Some((out, local.len()))
}

/// The coordinates of an element's nodes (the first `node_count` entries).
fn elem_coords(mesh: &Mesh, elem: ElemId) -> [[f64; 3]; MAX_NODES] {
    let mut coords = [[0.0; 3]; MAX_NODES];
    for (k, n) in mesh.elem_nodes(elem).iter().enumerate() {
        coords[k] = mesh.coords[n.index()];
    }
    coords
}

/// Twice the vector area of a (planar or nearly planar) side: the cross product of two
/// edges of a triangle, of the diagonals of a quadrilateral, twice an edge's length
/// times its normal (2-D); zero for other node counts.
fn side_vector(mesh: &Mesh, side: Side) -> [f64; 3] {
    let mut p = [[0.0; 3]; 4];
    let mut len = 0;
    for n in mesh.side_nodes(side) {
        if len < 4 {
            p[len] = mesh.coords[n.index()];
        }
        len += 1;
    }
    match len {
        2 => {
            let d = sub(p[1], p[0]);
            [2.0 * d[1], -2.0 * d[0], 0.0]
        }
        3 => cross(sub(p[1], p[0]), sub(p[2], p[0])),
        4 => cross(sub(p[2], p[0]), sub(p[3], p[1])),
        _ => [0.0; 3],
    }
}

/// Outward unit normal of a (planar or nearly planar) side: its vector area.
fn outward_normal(mesh: &Mesh, side: Side) -> [f64; 3] {
    let v = side_vector(mesh, side);
    let l = norm(v);
    if l > 0.0 { v.map(|c| c / l) } else { v }
}

/// Volume of the element over the area of the side: the element's thickness normal to
/// the interface. The volume is det J at the reference centroid times the reference
/// volume — exact for affine elements and a fair length scale for others, which is all
/// a penalty length needs (one shape-function evaluation, no quadrature).
fn element_length(mesh: &Mesh, elem: ElemId, side: Side) -> f64 {
    let topology = mesh.topology(elem);
    let Some(reference) = reference_nodes(topology) else {
        return 0.0;
    };
    let coords = elem_coords(mesh, elem);
    let mut center = [0.0; 3];
    for r in reference {
        for d in 0..3 {
            center[d] += r[d] / reference.len() as f64;
        }
    }
    let reference_volume = match topology {
        Topology::Hex8 => 8.0,
        Topology::Tet4 => 1.0 / 6.0,
        Topology::Wedge6 => 1.0,
        Topology::Pyramid5 => 4.0 / 3.0,
        Topology::Quad4 => 4.0,
        Topology::Tri3 => 0.5,
        _ => 0.0,
    };
    let volume = eval_point(
        topology,
        &coords[..reference.len()],
        center,
        reference_volume,
    )
    .map_or(0.0, |pv| pv.jxw.abs());
    // Triangle and quadrilateral areas, and edge lengths, are half the side vector's
    // length (a 2-D element's area over its edge's length: the same thickness).
    let area = 0.5 * norm(side_vector(mesh, side));
    if area > 0.0 { volume / area } else { 0.0 }
}
