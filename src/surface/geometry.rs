//! Face geometry for surface building: vector area, unit normal, centroid.
//!
//! Conventions: a face's normal is the right-hand normal of its Exodus node order, which
//! for a solid's side points out of the element. For an edge of a 2-D mesh (in the xy
//! plane) the normal is the edge direction turned clockwise by 90°, again outward for a
//! counter-clockwise element.

use crate::fem::quadrature::gauss_legendre;
use crate::mesh::{Mesh, NodeId};

pub(crate) use crate::vec3::{V3 as Vec3, cross, dot, norm, scale, sub};

/// Measure (length, area) and unit normal of a face given by its nodes in order.
/// Quadrilaterals use 2×2 Gauss integration of the bilinear map, exact for planar
/// faces and accurate for warped ones; the normal is the normalised vector area.
pub(crate) fn measure_and_normal(mesh: &Mesh, nodes: &[NodeId]) -> (f64, Vec3) {
    let x = |k: usize| mesh.coords[nodes[k].index()];
    match nodes.len() {
        2 => {
            let d = sub(x(1), x(0));
            let len = norm(d);
            let n = if len > 0.0 {
                [d[1] / len, -d[0] / len, 0.0]
            } else {
                [0.0; 3]
            };
            (len, n)
        }
        3 => {
            let v = cross(sub(x(1), x(0)), sub(x(2), x(0)));
            let a = norm(v);
            (0.5 * a, scale(v, if a > 0.0 { 1.0 / a } else { 0.0 }))
        }
        _ => {
            let (p0, p1, p2, p3) = (x(0), x(1), x(2), x(3));
            let vector_area = scale(cross(sub(p2, p0), sub(p3, p1)), 0.5);
            let (g, w) = gauss_legendre(2);
            let mut area = 0.0;
            for (i, j) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                let (xi, eta, weight) = (g[i], g[j], w[i] * w[j]);
                // Tangents of the bilinear map on [-1,1]², each scaled by 4.
                let t_xi: Vec3 = std::array::from_fn(|d| {
                    -(1.0 - eta) * p0[d] + (1.0 - eta) * p1[d] + (1.0 + eta) * p2[d]
                        - (1.0 + eta) * p3[d]
                });
                let t_eta: Vec3 = std::array::from_fn(|d| {
                    -(1.0 - xi) * p0[d] - (1.0 + xi) * p1[d]
                        + (1.0 + xi) * p2[d]
                        + (1.0 - xi) * p3[d]
                });
                area += weight * norm(cross(t_xi, t_eta)) / 16.0;
            }
            let m = norm(vector_area);
            (
                area,
                scale(vector_area, if m > 0.0 { 1.0 / m } else { 0.0 }),
            )
        }
    }
}

pub(crate) fn centroid(mesh: &Mesh, nodes: &[NodeId]) -> Vec3 {
    let mut c = [0.0; 3];
    for n in nodes {
        let p = mesh.coords[n.index()];
        for d in 0..3 {
            c[d] += p[d];
        }
    }
    scale(c, 1.0 / nodes.len().max(1) as f64)
}
