//! Contact surfaces: the faces (or nodes) that make each surface, their origins and
//! geometry. The Sierra rules that build them from a contact definition live in
//! [`crate::scene::surfaces`], the one consumer of the deck spec; this module knows
//! nothing of the deck.

pub(crate) mod geometry;
pub(crate) mod skin;

use serde::Serialize;

use crate::diag::Diagnostics;
use crate::mesh::{Mesh, NodeId, Side};

use geometry::{Vec3, measure_and_normal};

/// Whether a surface is made of faces or of nodes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SurfaceKind {
    Faces,
    Nodes,
}

/// One face of a contact surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceFace {
    pub side: Side,
    /// Offset along the face normal (shell faces: half the thickness), else 0.
    pub loft: f64,
    /// Index into the surface's `origins`.
    pub origin: u32,
}

/// A named contact surface.
#[derive(Clone, Debug)]
pub struct ContactSurface {
    /// Lower case.
    pub name: String,
    pub kind: SurfaceKind,
    /// Faces in (element, side) order; empty for node surfaces.
    pub faces: Vec<SurfaceFace>,
    /// For node surfaces: the faces that give each node its tributary area and normal,
    /// in (element, side) order — the surface's own faces for `Contact Type = node`, the
    /// exterior faces of the mesh whose nodes all lie in the node sets for a contact node
    /// set. They are not searched and not owned. Empty for face surfaces.
    pub tributary: Vec<Side>,
    /// The nodes this surface owns, ascending: for a face surface the nodes of its faces
    /// not owned by an earlier surface; for a node surface its nodes.
    pub nodes: Vec<NodeId>,
    /// Where the faces (or nodes) came from, with counts, e.g. `skin of block_1`.
    pub origins: Vec<(String, usize)>,
    /// For subsets: the surface they were split from.
    pub parent: Option<String>,
}

impl ContactSurface {
    /// Total area (length in 2-D, per full revolution `2π r̄ L` when the mesh is
    /// axisymmetric) of the faces, evaluated on the unlofted geometry; for a node surface,
    /// of its tributary faces (the sum of its nodes' tributary areas when it owns every
    /// node of those faces).
    pub fn area(&self, mesh: &Mesh) -> f64 {
        let revolution = crate::fem::Measure::of(mesh.axisymmetric);
        let measure = |side: Side| {
            let nodes: Vec<NodeId> = mesh.side_nodes(side).collect();
            measure_and_normal(mesh, &nodes).0 * revolution.factor(geometry::centroid(mesh, &nodes))
        };
        self.faces.iter().map(|f| measure(f.side)).sum::<f64>()
            + self.tributary.iter().map(|&s| measure(s)).sum::<f64>()
    }
}

/// The result of building: surfaces in deck order and the diagnostics.
#[derive(Clone, Debug, Default)]
pub struct SurfaceSet {
    pub surfaces: Vec<ContactSurface>,
    pub diagnostics: Diagnostics,
}

impl SurfaceSet {
    pub fn get(&self, name: &str) -> Option<&ContactSurface> {
        let name = name.to_ascii_lowercase();
        self.surfaces.iter().find(|s| s.name == name)
    }
}

/// The unit normal of a face (for subsets and checks).
pub(crate) fn face_normal(mesh: &Mesh, side: Side) -> Vec3 {
    let nodes: Vec<NodeId> = mesh.side_nodes(side).collect();
    measure_and_normal(mesh, &nodes).1
}
