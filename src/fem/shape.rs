//! Isoparametric shape functions of the linear elements on their reference cells, and
//! of the faces (sides) of those elements.
//!
//! Reference cells (node order = Exodus II, see [`crate::mesh::topology`]):
//! - `Hex8`: `[-1,1]³`, nodes 0–3 at ζ = −1 counter-clockwise from (−1,−1), 4–7 at ζ = +1;
//! - `Tet4`: (0,0,0), (1,0,0), (0,1,0), (0,0,1);
//! - `Wedge6`: triangle (0,0), (1,0), (0,1) in (ξ,η) times ζ ∈ [−1,1]; nodes 0–2 at
//!   ζ = −1, 3–5 at ζ = +1;
//! - `Pyramid5`: base square `[-1,1]²` at ζ = 0 (nodes 0–3), apex (0,0,1) (node 4);
//! - `Quad4`: `[-1,1]²`; `Tri3`: (0,0), (1,0), (0,1).
//!
//! Faces: `Line2` on s ∈ [−1,1], `Tri3` on the unit triangle, `Quad4` on `[-1,1]²`, node
//! order as the side tables list them.

use crate::mesh::{FaceShape, Topology};

const HEX8_NODES: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];
const TET4_NODES: [[f64; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];
const WEDGE6_NODES: [[f64; 3]; 6] = [
    [0.0, 0.0, -1.0],
    [1.0, 0.0, -1.0],
    [0.0, 1.0, -1.0],
    [0.0, 0.0, 1.0],
    [1.0, 0.0, 1.0],
    [0.0, 1.0, 1.0],
];
const PYRAMID5_NODES: [[f64; 3]; 5] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];
const QUAD4_NODES: [[f64; 3]; 4] = [
    [-1.0, -1.0, 0.0],
    [1.0, -1.0, 0.0],
    [1.0, 1.0, 0.0],
    [-1.0, 1.0, 0.0],
];
const TRI3_NODES: [[f64; 3]; 3] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];

/// Reference coordinates of the nodes of a solid (3-D or 2-D) topology; `None` for
/// shells and beams, which conduction does not handle.
pub fn reference_nodes(topology: Topology) -> Option<&'static [[f64; 3]]> {
    Some(match topology {
        Topology::Hex8 => &HEX8_NODES,
        Topology::Tet4 => &TET4_NODES,
        Topology::Wedge6 => &WEDGE6_NODES,
        Topology::Pyramid5 => &PYRAMID5_NODES,
        Topology::Quad4 => &QUAD4_NODES,
        Topology::Tri3 => &TRI3_NODES,
        _ => return None,
    })
}

/// Values `n[a]` and reference gradients `dn[a] = ∂N_a/∂(ξ,η,ζ)` at `xi` (2-D
/// elements leave the third component 0). Panics for topologies without
/// [`reference_nodes`]; callers check first.
pub fn shape(topology: Topology, xi: [f64; 3], n: &mut [f64], dn: &mut [[f64; 3]]) {
    let [x, y, z] = xi;
    match topology {
        Topology::Hex8 => {
            // N_a = ⅛ (1 + ξ_a ξ)(1 + η_a η)(1 + ζ_a ζ)
            for (a, p) in HEX8_NODES.iter().enumerate() {
                let (fx, fy, fz) = (1.0 + p[0] * x, 1.0 + p[1] * y, 1.0 + p[2] * z);
                n[a] = 0.125 * fx * fy * fz;
                dn[a] = [
                    0.125 * p[0] * fy * fz,
                    0.125 * fx * p[1] * fz,
                    0.125 * fx * fy * p[2],
                ];
            }
        }
        Topology::Tet4 => {
            n[..4].copy_from_slice(&[1.0 - x - y - z, x, y, z]);
            dn[..4].copy_from_slice(&[
                [-1.0, -1.0, -1.0],
                [1.0, 0.0, 0.0],
                [0.0, 1.0, 0.0],
                [0.0, 0.0, 1.0],
            ]);
        }
        Topology::Wedge6 => {
            // Triangle functions (1−ξ−η, ξ, η) times linear (1 ∓ ζ)/2.
            let l = [1.0 - x - y, x, y];
            let dl = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
            for (h, (zc, dz)) in [(0.5 * (1.0 - z), -0.5), (0.5 * (1.0 + z), 0.5)]
                .into_iter()
                .enumerate()
            {
                for t in 0..3 {
                    let a = 3 * h + t;
                    n[a] = l[t] * zc;
                    dn[a] = [dl[t][0] * zc, dl[t][1] * zc, l[t] * dz];
                }
            }
        }
        Topology::Pyramid5 => {
            // Bedrosian's rational pyramid (Int. J. Numer. Meth. Eng. 35, 1992):
            // N_a = ¼[(1 + ξ_a ξ)(1 + η_a η) − ζ + ξ_a η_a ξ η ζ/(1 − ζ)], N_4 = ζ.
            // The rational term vanishes on the base and keeps the base bilinear; the
            // apex (ζ = 1) is never a quadrature point.
            let s = 1.0 / (1.0 - z);
            for (a, p) in PYRAMID5_NODES[..4].iter().enumerate() {
                let (xa, ya) = (p[0], p[1]);
                n[a] = 0.25 * ((1.0 + xa * x) * (1.0 + ya * y) - z + xa * ya * x * y * z * s);
                dn[a] = [
                    0.25 * (xa * (1.0 + ya * y) + xa * ya * y * z * s),
                    0.25 * (ya * (1.0 + xa * x) + xa * ya * x * z * s),
                    0.25 * (-1.0 + xa * ya * x * y * s * s),
                ];
            }
            n[4] = z;
            dn[4] = [0.0, 0.0, 1.0];
        }
        Topology::Quad4 => {
            for (a, p) in QUAD4_NODES.iter().enumerate() {
                let (fx, fy) = (1.0 + p[0] * x, 1.0 + p[1] * y);
                n[a] = 0.25 * fx * fy;
                dn[a] = [0.25 * p[0] * fy, 0.25 * fx * p[1], 0.0];
            }
        }
        Topology::Tri3 => {
            n[..3].copy_from_slice(&[1.0 - x - y, x, y]);
            dn[..3].copy_from_slice(&[[-1.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]);
        }
        other => panic!("no shape functions for {other:?}"),
    }
}

/// Face shape functions and their gradients in the face coordinates `(s, t)`.
pub fn face_shape(face: FaceShape, st: [f64; 2], n: &mut [f64], dn: &mut [[f64; 2]]) {
    let [s, t] = st;
    match face {
        FaceShape::Line2 => {
            n[..2].copy_from_slice(&[0.5 * (1.0 - s), 0.5 * (1.0 + s)]);
            dn[..2].copy_from_slice(&[[-0.5, 0.0], [0.5, 0.0]]);
        }
        FaceShape::Tri3 => {
            n[..3].copy_from_slice(&[1.0 - s - t, s, t]);
            dn[..3].copy_from_slice(&[[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]]);
        }
        FaceShape::Quad4 => {
            for (a, p) in QUAD4_NODES.iter().enumerate() {
                let (fs, ft) = (1.0 + p[0] * s, 1.0 + p[1] * t);
                n[a] = 0.25 * fs * ft;
                dn[a] = [0.25 * p[0] * ft, 0.25 * fs * p[1]];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SOLIDS: [Topology; 6] = [
        Topology::Hex8,
        Topology::Tet4,
        Topology::Wedge6,
        Topology::Pyramid5,
        Topology::Quad4,
        Topology::Tri3,
    ];

    /// Points strictly inside every reference cell (the pyramid's need |ξ|,|η| < 1 − ζ).
    const POINTS: [[f64; 3]; 3] = [[0.1, 0.2, 0.3], [0.05, 0.15, 0.6], [0.3, 0.1, 0.05]];

    /// Partition of unity: ΣN = 1 and Σ∇N = 0 to round-off (1e-14: a handful of ulps
    /// of terms of size ≤ 1).
    #[test]
    fn shape_functions_sum_to_one_and_gradients_to_zero() {
        for t in SOLIDS {
            let nn = t.node_count();
            for p in POINTS {
                let (mut n, mut dn) = ([0.0; 8], [[0.0; 3]; 8]);
                shape(t, p, &mut n, &mut dn);
                let s: f64 = n[..nn].iter().sum();
                assert!((s - 1.0).abs() < 1e-14, "{t:?}: ΣN = {s}");
                for d in 0..3 {
                    let g: f64 = dn[..nn].iter().map(|g| g[d]).sum();
                    assert!(g.abs() < 1e-14, "{t:?}: Σ∂N/∂ξ{d} = {g}");
                }
            }
        }
    }

    /// Kronecker property N_a(x_b) = δ_ab (the pyramid checked at its base nodes and,
    /// for the apex, slightly below it where the rational term is finite).
    #[test]
    fn shape_functions_are_nodal() {
        for t in SOLIDS {
            let nodes = reference_nodes(t).unwrap();
            for (b, &p) in nodes.iter().enumerate() {
                let p = if t == Topology::Pyramid5 && b == 4 {
                    [0.0, 0.0, 1.0 - 1e-12]
                } else {
                    p
                };
                let (mut n, mut dn) = ([0.0; 8], [[0.0; 3]; 8]);
                shape(t, p, &mut n, &mut dn);
                for (a, &v) in n[..nodes.len()].iter().enumerate() {
                    let want = if a == b { 1.0 } else { 0.0 };
                    assert!((v - want).abs() < 1e-11, "{t:?}: N_{a}(x_{b}) = {v}");
                }
            }
        }
    }

    /// Gradients against central differences of the values (step 1e-6: error
    /// O(h²·N''') ≈ 1e-12 plus cancellation ≈ 1e-10; tolerance 1e-8).
    #[test]
    fn gradients_match_finite_differences() {
        for t in SOLIDS {
            let nn = t.node_count();
            for p in POINTS {
                let (mut n, mut dn) = ([0.0; 8], [[0.0; 3]; 8]);
                shape(t, p, &mut n, &mut dn);
                for d in 0..t.parametric_dim() {
                    let h = 1e-6;
                    let (mut np, mut nm, mut g) = ([0.0; 8], [0.0; 8], [[0.0; 3]; 8]);
                    let mut q = p;
                    q[d] += h;
                    shape(t, q, &mut np, &mut g);
                    q[d] -= 2.0 * h;
                    shape(t, q, &mut nm, &mut g);
                    for a in 0..nn {
                        let fd = (np[a] - nm[a]) / (2.0 * h);
                        assert!((fd - dn[a][d]).abs() < 1e-8, "{t:?} a={a} d={d}");
                    }
                }
            }
        }
    }
}
