//! The faces of a surface as coordinates ([`FaceGeom`], [`SurfaceGeometry`]): built
//! from a contact surface or a side set, lofted, mapped to a periodic image, with node
//! surfaces' tributary areas and normals; and the reference-face helpers (shape values,
//! area Jacobian, Gauss rules) the search integrates with.
//!
//! Faces are Tri3 and Quad4 in 3-D, Line2 (the edges of Quad4 and Tri3 elements) in
//! 2-D, where a face's "area" is its length. An axisymmetric surface
//! ([`SurfaceGeometry::axisymmetric`], x the radius) measures its integrals per full
//! revolution: every weight, tributary area and surface area carries `2πr`
//! ([`revolution`]); the sizes that scale the search tolerances stay plain lengths.

use crate::fem::quadrature::gauss_legendre;
use crate::mesh::{Mesh, NodeId, Side};
use crate::periodic::PeriodicMap;
use crate::script::ScriptError;
use crate::search::bvh::Aabb;
use crate::search::mortar::rule_triangle;
use crate::search::project::{
    Projection, map_line2, map_quad4, map_tri3, normal_line2, project_point_line2,
    project_point_quad4, project_point_tri3, vector_area_quad4,
};
use crate::surface::{ContactSurface, SurfaceKind};
use crate::vec3::{V3, add, cross, norm, scale, sub};

/// One face as coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceGeom {
    /// The mesh side it came from.
    pub side: Side,
    /// Node count: 3 or 4, or 2 for an edge of a 2-D mesh.
    pub len: u8,
    pub nodes: [NodeId; 4],
    pub x: [V3; 4],
}

impl FaceGeom {
    pub fn coords(&self) -> &[V3] {
        &self.x[..self.len as usize]
    }

    /// Vector area (normal × area; for an edge, normal × length).
    pub fn vector_area(&self) -> V3 {
        match self.len {
            2 => {
                let e = [self.x[0], self.x[1]];
                scale(normal_line2(&e), norm(sub(e[1], e[0])))
            }
            3 => {
                let c = cross(sub(self.x[1], self.x[0]), sub(self.x[2], self.x[0]));
                scale(c, 0.5)
            }
            _ => {
                let q = [self.x[0], self.x[1], self.x[2], self.x[3]];
                vector_area_quad4(&q)
            }
        }
    }

    /// The face's area (an edge's length), on the plain geometry.
    pub fn area(&self) -> f64 {
        norm(self.vector_area())
    }

    /// The face's size, the length that scales the search tolerances: √area, or an
    /// edge's length.
    pub fn size(&self) -> f64 {
        match self.len {
            2 => self.area(),
            _ => self.area().sqrt(),
        }
    }

    /// The face's measure: its area, or per full revolution `∫ 2πr dA` when
    /// `axisymmetric` (an edge's `2π r̄ L`, exact since r is linear along it).
    pub fn measure(&self, axisymmetric: bool) -> f64 {
        self.area() * revolution(axisymmetric, self.centroid())
    }

    pub fn normal(&self) -> V3 {
        let v = self.vector_area();
        let n = norm(v);
        if n > 0.0 { scale(v, 1.0 / n) } else { [0.0; 3] }
    }

    pub fn centroid(&self) -> V3 {
        let k = self.len as usize;
        let mut c = [0.0; 3];
        for p in self.coords() {
            c = add(c, *p);
        }
        scale(c, 1.0 / k as f64)
    }

    /// The closest point of the face to `p` ([`project_point_line2`],
    /// [`project_point_tri3`] or [`project_point_quad4`] by node count).
    pub fn project(&self, p: V3) -> Projection {
        let x = &self.x;
        match self.len {
            2 => project_point_line2(p, &[x[0], x[1]]),
            3 => project_point_tri3(p, &[x[0], x[1], x[2]]),
            _ => project_point_quad4(p, x),
        }
    }

    pub(super) fn aabb(&self) -> Aabb {
        Aabb::from_points(self.coords())
    }

    pub(super) fn map(&self, xi: [f64; 2]) -> V3 {
        match self.len {
            2 => map_line2(&[self.x[0], self.x[1]], xi),
            3 => map_tri3(&[self.x[0], self.x[1], self.x[2]], xi),
            _ => map_quad4(&[self.x[0], self.x[1], self.x[2], self.x[3]], xi),
        }
    }
}

/// The faces (or nodes) of one surface, as coordinates.
#[derive(Clone, Debug, Default)]
pub struct SurfaceGeometry {
    pub name: String,
    pub faces: Vec<FaceGeom>,
    /// For node surfaces: the nodes and their coordinates.
    pub nodes: Vec<(NodeId, V3)>,
    /// For node surfaces, per node (parallel to `nodes`): its tributary area
    /// `A_i = Σ_f ∫_f N_i dA` and unit normal `n_i ∝ Σ_f ∫_f N_i n dA` over the tributary
    /// faces around it (zero area and normal for a node on none). See
    /// [`SurfaceGeometry::tributary_of_nodes`].
    pub node_area: Vec<f64>,
    pub node_normal: Vec<V3>,
    /// For node surfaces: the faces the areas and normals come from (not searched).
    pub tributary: Vec<FaceGeom>,
    /// A 2-D axisymmetric model (x the radius r ≥ 0, y the axis): weights, tributary
    /// areas and [`Self::area`] are per full revolution (× 2πr). Taken from the mesh.
    pub axisymmetric: bool,
}

/// The factor of a point's weight: `2πr` (r = x) per full revolution when
/// `axisymmetric`, else 1.
#[inline]
pub(crate) fn revolution(axisymmetric: bool, x: V3) -> f64 {
    crate::fem::Measure::of(axisymmetric).factor(x)
}

/// Why a surface cannot be searched.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SearchError {
    /// Not returned any more (2-D surfaces are searched since 2-D search came); kept so
    /// code that matches on it still builds.
    #[error("surface `{0}` is made of edges (a 2-D mesh): 2-D contact search is not supported yet")]
    TwoDimensional(String),
    #[error("periodic map of surface `{surface}`: {source}")]
    Map {
        surface: String,
        source: ScriptError,
    },
}

impl SurfaceGeometry {
    /// The geometry of a built surface on coordinates `coords` (the mesh's, or moved
    /// ones); shell faces are lofted along their normal by their `loft`.
    pub fn from_surface(
        mesh: &Mesh,
        surface: &ContactSurface,
        coords: &[V3],
    ) -> Result<Self, SearchError> {
        let mut out = SurfaceGeometry {
            name: surface.name.clone(),
            axisymmetric: mesh.axisymmetric,
            ..Default::default()
        };
        if surface.kind == SurfaceKind::Nodes {
            out.nodes = surface
                .nodes
                .iter()
                .map(|&n| (n, coords[n.index()]))
                .collect();
            for &side in &surface.tributary {
                out.tributary.push(face_geom(mesh, side, coords));
            }
            out.tributary_of_nodes();
            return Ok(out);
        }
        out.faces.reserve(surface.faces.len());
        for f in &surface.faces {
            let mut g = face_geom(mesh, f.side, coords);
            if f.loft != 0.0 {
                let n = g.normal();
                for p in &mut g.x[..g.len as usize] {
                    *p = add(*p, scale(n, f.loft));
                }
            }
            out.faces.push(g);
        }
        Ok(out)
    }

    /// Each node's tributary area and normal from the tributary faces (module docs of
    /// `enforce::interface`, node-to-face form): `A_i = Σ_f ∫_f N_i dA`, the row sum of the
    /// face mass matrix, so `Σ_i A_i` is the faces' area and a constant flux q gives
    /// `Σ_i A_i q = q A` exactly; `n_i = Σ_f ∫_f N_i n dA`, normalised. Tri3 faces are
    /// flat (`∫ N_i = A/3`); Quad4 faces use the 2×2 Gauss rule of the bilinear map, exact
    /// for `N_i |J|` on flat faces (N_i bilinear, |J| bilinear) and for `N_i J` on warped
    /// ones (both of degree ≤ 2 in each coordinate); edges the 2-point Gauss rule, exact
    /// for `N_i 2πr` (degree 2) when axisymmetric.
    pub fn tributary_of_nodes(&mut self) {
        let index: std::collections::HashMap<NodeId, usize> = self
            .nodes
            .iter()
            .enumerate()
            .map(|(k, &(n, _))| (n, k))
            .collect();
        let mut area = vec![0.0; self.nodes.len()];
        let mut vector = vec![[0.0; 3]; self.nodes.len()];
        for f in &self.tributary {
            let len = f.len as usize;
            // A triangle's N_i is linear and its Jacobian constant: the centroid rule is
            // exact.
            let rule: Vec<([f64; 2], f64)> = if len == 2 {
                let (g, w) = gauss_legendre(2);
                vec![([g[0], 0.0], w[0]), ([g[1], 0.0], w[1])]
            } else if len == 3 {
                vec![([1.0 / 3.0, 1.0 / 3.0], 0.5)]
            } else {
                let (g, w) = gauss_legendre(2);
                [(0, 0), (1, 0), (1, 1), (0, 1)]
                    .map(|(i, j)| ([g[i], g[j]], w[i] * w[j]))
                    .to_vec()
            };
            for &(xi, w) in &rule {
                let j = face_normal_jacobian(f, xi);
                let w = w * revolution(self.axisymmetric, f.map(xi));
                let shapes = face_shapes(len, xi);
                for (node, shape) in f.nodes.iter().zip(shapes).take(len) {
                    let Some(&i) = index.get(node) else {
                        continue;
                    };
                    let wn = w * shape;
                    area[i] += wn * norm(j);
                    vector[i] = add(vector[i], scale(j, wn));
                }
            }
        }
        self.node_normal = vector
            .iter()
            .map(|&v| {
                let l = norm(v);
                if l > 0.0 { scale(v, 1.0 / l) } else { [0.0; 3] }
            })
            .collect();
        self.node_area = area;
    }

    /// The geometry of side set `set` of the mesh taken whole as a surface, on the
    /// mesh's coordinates (for hosts and tests that name their interface faces directly).
    pub fn from_side_set(mesh: &Mesh, set: usize) -> Result<Self, SearchError> {
        let ss = &mesh.side_sets[set];
        let surface = ContactSurface {
            name: ss.sierra_name(),
            kind: SurfaceKind::Faces,
            faces: ss
                .sides
                .iter()
                .map(|&side| crate::surface::SurfaceFace {
                    side,
                    loft: 0.0,
                    origin: 0,
                })
                .collect(),
            tributary: Vec::new(),
            nodes: Vec::new(),
            origins: Vec::new(),
            parent: None,
        };
        Self::from_surface(mesh, &surface, &mesh.coords)
    }

    /// The image of this surface under a periodic map, named `name`.
    pub fn mapped(&self, map: &mut dyn PeriodicMap, name: &str) -> Result<Self, SearchError> {
        let fail = |source| SearchError::Map {
            surface: self.name.clone(),
            source,
        };
        let mut out = self.clone();
        out.name = name.to_string();
        for f in &mut out.faces {
            for p in &mut f.x[..f.len as usize] {
                *p = map.map_point(*p).map_err(fail)?;
            }
        }
        for (_, p) in &mut out.nodes {
            *p = map.map_point(*p).map_err(fail)?;
        }
        for f in &mut out.tributary {
            for p in &mut f.x[..f.len as usize] {
                *p = map.map_point(*p).map_err(fail)?;
            }
        }
        if !out.nodes.is_empty() {
            out.tributary_of_nodes();
        }
        Ok(out)
    }

    /// The area of the faces (per full revolution when axisymmetric), or for a node
    /// surface the sum of its nodes' tributary areas.
    pub fn area(&self) -> f64 {
        self.faces
            .iter()
            .map(|f| f.measure(self.axisymmetric))
            .sum::<f64>()
            + self.node_area.iter().sum::<f64>()
    }

    /// Mean face size (√area, an edge's length), the length scale of the search
    /// tolerances.
    pub fn mean_face_size(&self) -> f64 {
        if self.faces.is_empty() {
            return 0.0;
        }
        self.faces.iter().map(FaceGeom::size).sum::<f64>() / self.faces.len() as f64
    }
}

/// One face of the mesh as coordinates (unlofted).
pub(super) fn face_geom(mesh: &Mesh, side: Side, coords: &[V3]) -> FaceGeom {
    let mut g = FaceGeom {
        side,
        len: 0,
        nodes: [NodeId(0); 4],
        x: [[0.0; 3]; 4],
    };
    for (k, n) in mesh.side_nodes(side).enumerate().take(4) {
        g.nodes[k] = n;
        g.x[k] = coords[n.index()];
        g.len += 1;
    }
    g
}

/// Shape functions of a Line2 (`len` 2), Tri3 (3) or Quad4 face at `xi`, Exodus node
/// order (the values past `len` are 0).
pub(crate) fn face_shapes(len: usize, xi: [f64; 2]) -> [f64; 4] {
    let (s, t) = (xi[0], xi[1]);
    if len == 2 {
        [0.5 * (1.0 - s), 0.5 * (1.0 + s), 0.0, 0.0]
    } else if len == 3 {
        [1.0 - s - t, s, t, 0.0]
    } else {
        [
            0.25 * (1.0 - s) * (1.0 - t),
            0.25 * (1.0 + s) * (1.0 - t),
            0.25 * (1.0 + s) * (1.0 + t),
            0.25 * (1.0 - s) * (1.0 + t),
        ]
    }
}

/// ∂x/∂ξ × ∂x/∂η at ξ: the face's area Jacobian times its unit normal (an edge's
/// `|∂x/∂ξ| = L/2` times its normal).
pub(super) fn face_normal_jacobian(face: &FaceGeom, xi: [f64; 2]) -> V3 {
    let x = &face.x;
    match face.len {
        2 => scale(face.vector_area(), 0.5),
        3 => cross(sub(x[1], x[0]), sub(x[2], x[0])),
        _ => {
            let (s, t) = (xi[0], xi[1]);
            let d_xi: V3 = std::array::from_fn(|d| {
                0.25 * (-(1.0 - t) * x[0][d] + (1.0 - t) * x[1][d] + (1.0 + t) * x[2][d]
                    - (1.0 + t) * x[3][d])
            });
            let d_eta: V3 = std::array::from_fn(|d| {
                0.25 * (-(1.0 - s) * x[0][d] - (1.0 + s) * x[1][d]
                    + (1.0 + s) * x[2][d]
                    + (1.0 - s) * x[3][d])
            });
            cross(d_xi, d_eta)
        }
    }
}

/// Gauss rule on the reference element of a face of `len` nodes: (ξ, weight on the
/// reference element); an edge takes `order` Gauss points (1 to 3) on `[-1, 1]`, as
/// each direction of a quad.
pub(super) fn face_rule(len: u8, order: usize) -> Vec<([f64; 2], f64)> {
    match len {
        2 => {
            let (xs, ws) = gauss_legendre(order.clamp(1, 3));
            xs.iter().zip(ws).map(|(&x, w)| ([x, 0.0], w)).collect()
        }
        3 => {
            // Weights relative to the area, which is 1/2 on the reference triangle.
            rule_triangle(order.max(1))
                .points
                .iter()
                .map(|&(xi, w)| (xi, w * 0.5))
                .collect()
        }
        _ => {
            let (xs, ws) = gauss_legendre(order.clamp(1, 3));
            let mut out = Vec::with_capacity(xs.len() * xs.len());
            for (j, &eta) in xs.iter().enumerate() {
                for (i, &xi) in xs.iter().enumerate() {
                    out.push(([xi, eta], ws[i] * ws[j]));
                }
            }
            out
        }
    }
}

/// |∂x/∂ξ × ∂x/∂η| at ξ: the area Jacobian of the face's map (an edge's L/2).
pub(super) fn face_jacobian(face: &FaceGeom, xi: [f64; 2]) -> f64 {
    match face.len {
        2 => 0.5 * face.area(),
        3 => 2.0 * face.area(),
        _ => norm(face_normal_jacobian(face, xi)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn edge(nodes: [u32; 2], x: [V3; 2]) -> FaceGeom {
        FaceGeom {
            side: Side {
                elem: crate::mesh::ElemId(0),
                side: 1,
            },
            len: 2,
            nodes: [NodeId(nodes[0]), NodeId(nodes[1]), NodeId(0), NodeId(0)],
            x: [x[0], x[1], [0.0; 3], [0.0; 3]],
        }
    }

    /// The tributary lengths of a 2-D node surface: the row sums of the edge mass
    /// matrix, L/2 from each edge; per revolution `∫ N_i 2πr ds`, which for an edge from
    /// r₀ to r₁ gives node 0 `2π L (2r₀ + r₁)/6`. Normals are the edges' (+y here).
    #[test]
    fn edge_tributaries_per_unit_depth_and_per_revolution() {
        let xs = [[1.0, 2.0, 0.0], [0.5, 2.0, 0.0], [0.0, 2.0, 0.0]];
        for axisymmetric in [false, true] {
            let mut g = SurfaceGeometry {
                nodes: (0..3).map(|k| (NodeId(k), xs[k as usize])).collect(),
                tributary: vec![edge([0, 1], [xs[0], xs[1]]), edge([1, 2], [xs[1], xs[2]])],
                axisymmetric,
                ..Default::default()
            };
            g.tributary_of_nodes();
            let want = if axisymmetric {
                let tau = std::f64::consts::TAU;
                let half = |r0: f64, r1: f64| tau * 0.5 * (2.0 * r0 + r1) / 6.0;
                [
                    half(1.0, 0.5),
                    half(0.5, 1.0) + half(0.5, 0.0),
                    half(0.0, 0.5),
                ]
            } else {
                [0.25, 0.5, 0.25]
            };
            for (k, want) in want.iter().enumerate() {
                assert!((g.node_area[k] - want).abs() < 1e-15, "{axisymmetric} {k}");
                let n = g.node_normal[k];
                assert!(n[0].abs() < 1e-15 && (n[1] - 1.0).abs() < 1e-15 && n[2] == 0.0);
            }
            // The same total as the faces' own measure (2π r̄ L = 2π · 0.5 · 1).
            let total: f64 = g.node_area.iter().sum();
            let faces: f64 = g.tributary.iter().map(|f| f.measure(axisymmetric)).sum();
            assert!((total - faces).abs() < 1e-15);
        }
    }
}
