//! Shape functions mapped to physical space: the isoparametric map of one element at a
//! reference point, untabulated ([`eval_point`]) or tabulated at the points of a rule
//! ([`Basis`]).
//!
//! Formulas: `J_ij = Σ_a x_a,i ∂N_a/∂ξ_j`, `∇_x N = J⁻ᵀ ∇_ξ N`, `jxw = det J · w`; a
//! non-positive det J is a [`BadJacobian`]. 2-D elements (`Quad4`, `Tri3`) use x and y.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::mesh::Topology;

use super::quadrature::QuadratureRule;
use super::shape::shape;

/// Largest element node count handled (Hex8).
pub const MAX_NODES: usize = 8;

/// A non-positive Jacobian determinant at a quadrature point: the element is inverted
/// or degenerate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BadJacobian {
    pub det: f64,
    pub point: [f64; 3],
}

/// Shape functions mapped to physical space at one quadrature point.
#[derive(Clone, Copy, Debug)]
pub struct PointValues {
    pub n: [f64; MAX_NODES],
    /// ∇N_a in physical coordinates.
    pub grad: [[f64; 3]; MAX_NODES],
    /// Physical position of the point.
    pub x: [f64; 3],
    /// det J · w.
    pub jxw: f64,
}

/// Shape functions of one topology tabulated at the points of a quadrature rule, so
/// element loops map them to physical space without re-evaluating them.
#[derive(Clone, Debug)]
pub struct Basis {
    pub topology: Topology,
    pub rule: QuadratureRule,
    n: Vec<[f64; MAX_NODES]>,
    dn: Vec<[[f64; 3]; MAX_NODES]>,
}

impl Basis {
    /// Tabulate `topology`'s shape functions at the points of `rule`. Panics for
    /// topologies without shape functions (see [`super::shape::reference_nodes`]).
    pub fn new(topology: Topology, rule: QuadratureRule) -> Self {
        let mut n = Vec::with_capacity(rule.len());
        let mut dn = Vec::with_capacity(rule.len());
        for p in &rule.points {
            let (mut v, mut g) = ([0.0; MAX_NODES], [[0.0; 3]; MAX_NODES]);
            shape(topology, *p, &mut v, &mut g);
            n.push(v);
            dn.push(g);
        }
        Basis {
            topology,
            rule,
            n,
            dn,
        }
    }

    /// The element's standard rule ([`QuadratureRule::standard`]); `None` for shells
    /// and beams.
    pub fn standard(topology: Topology) -> Option<Self> {
        QuadratureRule::standard(topology).map(|r| Self::new(topology, r))
    }

    /// Number of quadrature points.
    pub fn len(&self) -> usize {
        self.rule.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rule.is_empty()
    }

    /// Values at quadrature point `q` of the element with nodes at `coords`.
    pub fn eval(&self, q: usize, coords: &[[f64; 3]]) -> Result<PointValues, BadJacobian> {
        map_point(
            self.topology,
            coords,
            &self.n[q],
            &self.dn[q],
            self.rule.points[q],
            self.rule.weights[q],
        )
    }
}

/// Evaluate shape functions, physical gradients and det J·w at reference point `xi`
/// (untabulated; [`Basis::eval`] is the fast path).
pub fn eval_point(
    topology: Topology,
    coords: &[[f64; 3]],
    xi: [f64; 3],
    weight: f64,
) -> Result<PointValues, BadJacobian> {
    let (mut n, mut dn) = ([0.0; MAX_NODES], [[0.0; 3]; MAX_NODES]);
    shape(topology, xi, &mut n, &mut dn);
    map_point(topology, coords, &n, &dn, xi, weight)
}

/// Map reference values to physical space: `J_ij = Σ_a x_a,i ∂N_a/∂ξ_j`,
/// `∇_x N = J⁻ᵀ ∇_ξ N`, `jxw = det J · w`.
fn map_point(
    topology: Topology,
    coords: &[[f64; 3]],
    n: &[f64; MAX_NODES],
    dn: &[[f64; 3]; MAX_NODES],
    xi: [f64; 3],
    weight: f64,
) -> Result<PointValues, BadJacobian> {
    let nn = topology.node_count();
    let mut pv = PointValues {
        n: *n,
        grad: [[0.0; 3]; MAX_NODES],
        x: [0.0; 3],
        jxw: 0.0,
    };
    let dim = topology.parametric_dim();
    let mut j = [[0.0; 3]; 3];
    for a in 0..nn {
        let (c, d) = (coords[a], dn[a]);
        for i in 0..3 {
            pv.x[i] += n[a] * c[i];
            for k in 0..3 {
                j[i][k] += c[i] * d[k];
            }
        }
    }
    // inv = J⁻¹ by cofactors.
    let mut inv = [[0.0; 3]; 3];
    let det = if dim == 3 {
        let c00 = j[1][1] * j[2][2] - j[1][2] * j[2][1];
        let c01 = j[1][2] * j[2][0] - j[1][0] * j[2][2];
        let c02 = j[1][0] * j[2][1] - j[1][1] * j[2][0];
        let det = j[0][0] * c00 + j[0][1] * c01 + j[0][2] * c02;
        let r = 1.0 / det;
        inv[0][0] = c00 * r;
        inv[1][0] = c01 * r;
        inv[2][0] = c02 * r;
        inv[0][1] = (j[0][2] * j[2][1] - j[0][1] * j[2][2]) * r;
        inv[1][1] = (j[0][0] * j[2][2] - j[0][2] * j[2][0]) * r;
        inv[2][1] = (j[0][1] * j[2][0] - j[0][0] * j[2][1]) * r;
        inv[0][2] = (j[0][1] * j[1][2] - j[0][2] * j[1][1]) * r;
        inv[1][2] = (j[0][2] * j[1][0] - j[0][0] * j[1][2]) * r;
        inv[2][2] = (j[0][0] * j[1][1] - j[0][1] * j[1][0]) * r;
        det
    } else {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        inv[0][0] = j[1][1] / det;
        inv[0][1] = -j[0][1] / det;
        inv[1][0] = -j[1][0] / det;
        inv[1][1] = j[0][0] / det;
        det
    };
    if det.is_nan() || det <= 0.0 {
        return Err(BadJacobian { det, point: xi });
    }
    // (∇_x N)_i = Σ_k inv[k][i] ∂N/∂ξ_k
    for a in 0..nn {
        let d = dn[a];
        for i in 0..dim {
            pv.grad[a][i] = inv[0][i] * d[0] + inv[1][i] * d[1] + inv[2][i] * d[2];
        }
    }
    pv.jxw = det * weight;
    Ok(pv)
}
