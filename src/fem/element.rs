//! Shape functions mapped to physical space: the isoparametric map of one element at a
//! reference point, untabulated ([`eval_point`]) or tabulated at the points of a rule
//! ([`Basis`]); for a `Hex8` with its standard 2×2×2 rule, all eight points at once
//! ([`Basis::map_hex8`], the fast path of the element kernels).
//!
//! Formulas: `J_ij = Σ_a x_a,i ∂N_a/∂ξ_j`, `∇_x N = J⁻ᵀ ∇_ξ N`, `jxw = det J · w`; a
//! non-positive det J is a [`BadJacobian`]. 2-D elements (`Quad4`, `Tri3`) use x and y.
//!
//! The `Hex8` map does the arithmetic of the general one operation for operation, in
//! the same order, only laid out across the eight points (J, det J, J⁻¹, positions) and
//! across the eight nodes (gradients) so that fixed-length loops vectorise; its values
//! are therefore the general map's to the last bit, and kernels built on it need no
//! tolerance of their own.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::mesh::Topology;

use super::Measure;
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
    /// The same tables laid out for [`Basis::map_hex8`]; `None` unless the basis is a
    /// `Hex8` on an eight-point rule.
    hex8: Option<Box<Hex8Tables>>,
    /// Per unit depth (plane) or per revolution: [`Basis::eval`]'s `jxw` carries 2πr.
    measure: Measure,
}

/// Reference values of a `Hex8` at the eight points of its rule, in the layouts the
/// vectorised map reads: by node then point (sums over nodes, across points) and by
/// point then node (gradients, across nodes).
#[derive(Clone, Debug)]
struct Hex8Tables {
    /// `n_by_node[a][q] = N_a(ξ_q)`.
    n_by_node: [[f64; 8]; 8],
    /// `dn_by_node[a][8k + q] = ∂N_a/∂ξ_k (ξ_q)`.
    dn_by_node: [[f64; 24]; 8],
    /// `dn_by_point[q][k][a] = ∂N_a/∂ξ_k (ξ_q)`.
    dn_by_point: [[[f64; 8]; 3]; 8],
    weights: [f64; 8],
    /// The rule's reference stiffness parts, for affine elements: per pair `k ≤ l`
    /// (in the order of [`HEX8_PAIRS`]) the upper triangle, row by row, of
    /// `Σ_q w_q (∂_k N_a ∂_l N_b + ∂_l N_a ∂_k N_b)` (halved for `k = l`).
    stiffness: Hex8Stiffness,
}

/// The reference stiffness parts of a `Hex8` rule (see [`Basis::affine_hex8`]).
pub type Hex8Stiffness = [[f64; 36]; 6];

/// The pairs `(k, l)`, `k ≤ l`, of reference directions, in the order of the tables.
pub const HEX8_PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// A `Hex8` mapped at the eight points of its rule ([`Basis::map_hex8`]).
#[derive(Clone, Copy, Debug)]
pub struct Hex8Points {
    /// `grad[q][i][a] = ∂N_a/∂x_i` at point q (component-major, so that the loops over
    /// the nodes a are contiguous).
    pub grad: [[[f64; 8]; 3]; 8],
    /// Physical position of each point.
    pub x: [[f64; 3]; 8],
    /// det J · w at each point.
    pub jxw: [f64; 8],
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
        let hex8 = (topology == Topology::Hex8 && rule.len() == 8).then(|| {
            let mut t = Hex8Tables {
                n_by_node: [[0.0; 8]; 8],
                dn_by_node: [[0.0; 24]; 8],
                dn_by_point: [[[0.0; 8]; 3]; 8],
                weights: [0.0; 8],
                stiffness: [[0.0; 36]; 6],
            };
            for q in 0..8 {
                t.weights[q] = rule.weights[q];
                for a in 0..8 {
                    t.n_by_node[a][q] = n[q][a];
                    for k in 0..3 {
                        t.dn_by_node[a][8 * k + q] = dn[q][a][k];
                        t.dn_by_point[q][k][a] = dn[q][a][k];
                    }
                }
            }
            for (m, &(k, l)) in t.stiffness.iter_mut().zip(&HEX8_PAIRS) {
                let mut at = 0;
                for a in 0..8 {
                    for b in a..8 {
                        m[at] = (0..8)
                            .map(|q| {
                                let d = &t.dn_by_point[q];
                                let v = d[k][a] * d[l][b] + d[l][a] * d[k][b];
                                t.weights[q] * if k == l { 0.5 * v } else { v }
                            })
                            .sum();
                        at += 1;
                    }
                }
            }
            Box::new(t)
        });
        Basis {
            topology,
            rule,
            n,
            dn,
            hex8,
            measure: Measure::Plane,
        }
    }

    /// The same basis measured by `measure`: axisymmetric, [`Basis::eval`]'s `jxw` is
    /// `det J · w · 2πr` at the point, so every kernel built on it integrates per full
    /// revolution. Only 2-D topologies are axisymmetric; a 3-D basis stays plane.
    pub fn with_measure(mut self, measure: Measure) -> Self {
        if self.topology.parametric_dim() == 2 {
            self.measure = measure;
        }
        self
    }

    /// The basis of a block of a mesh whose integrals are measured by `measure`: the
    /// standard rule, plane; axisymmetric, a rule one degree higher for `Tri3` (3
    /// instead of 2) so the capacity's `N_a N_b r` stays exact — `Quad4`'s 2×2 rule is
    /// exact to degree 3 in each direction already.
    pub fn for_measure(topology: Topology, measure: Measure) -> Option<Self> {
        let rule = match (topology, measure) {
            (Topology::Tri3, Measure::Axisymmetric) => QuadratureRule::with_degree(topology, 3)?,
            _ => QuadratureRule::standard(topology)?,
        };
        Some(Self::new(topology, rule).with_measure(measure))
    }

    /// The same basis without its `Hex8` tables: kernels then take the general path
    /// (for tests that hold the fast path against it).
    pub fn without_fast_path(mut self) -> Self {
        self.hex8 = None;
        self
    }

    /// Whether [`Basis::map_hex8`] applies (a `Hex8` on an eight-point rule).
    pub fn has_hex8_path(&self) -> bool {
        self.hex8.is_some()
    }

    /// Shape-function values at point `q`.
    pub fn values(&self, q: usize) -> &[f64; MAX_NODES] {
        &self.n[q]
    }

    /// All eight points of a `Hex8` mapped at once: gradients, positions and det J · w,
    /// equal to the last bit to [`Basis::eval`] at each point (module docs). `None`
    /// when the basis has no `Hex8` tables; a [`BadJacobian`] names the first point (in
    /// rule order) with det J ≤ 0 or NaN, as [`Basis::eval`] would.
    #[inline(always)]
    pub fn map_hex8(&self, coords: &[[f64; 3]; 8]) -> Option<Result<Hex8Points, BadJacobian>> {
        let t = self.hex8.as_deref()?;
        // J_ik and x_i at every point, summed over the nodes in node order
        // (`j[i][8k + q]`, `x[i][q]`).
        let mut j = [[0.0; 24]; 3];
        let mut x = [[0.0; 8]; 3];
        for a in 0..8 {
            let (c, n, dn) = (coords[a], &t.n_by_node[a], &t.dn_by_node[a]);
            for i in 0..3 {
                for q in 0..8 {
                    x[i][q] += n[q] * c[i];
                }
                for kq in 0..24 {
                    j[i][kq] += c[i] * dn[kq];
                }
            }
        }
        // det J and J⁻¹ by cofactors, as `map_point`.
        let mut det = [0.0; 8];
        let mut inv = [[[0.0; 8]; 3]; 3];
        for q in 0..8 {
            let m = |i: usize, k: usize| j[i][8 * k + q];
            let c00 = m(1, 1) * m(2, 2) - m(1, 2) * m(2, 1);
            let c01 = m(1, 2) * m(2, 0) - m(1, 0) * m(2, 2);
            let c02 = m(1, 0) * m(2, 1) - m(1, 1) * m(2, 0);
            let d = m(0, 0) * c00 + m(0, 1) * c01 + m(0, 2) * c02;
            let r = 1.0 / d;
            det[q] = d;
            inv[0][0][q] = c00 * r;
            inv[1][0][q] = c01 * r;
            inv[2][0][q] = c02 * r;
            inv[0][1][q] = (m(0, 2) * m(2, 1) - m(0, 1) * m(2, 2)) * r;
            inv[1][1][q] = (m(0, 0) * m(2, 2) - m(0, 2) * m(2, 0)) * r;
            inv[2][1][q] = (m(0, 1) * m(2, 0) - m(0, 0) * m(2, 1)) * r;
            inv[0][2][q] = (m(0, 1) * m(1, 2) - m(0, 2) * m(1, 1)) * r;
            inv[1][2][q] = (m(0, 2) * m(1, 0) - m(0, 0) * m(1, 2)) * r;
            inv[2][2][q] = (m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0)) * r;
        }
        if let Some(q) = (0..8).find(|&q| det[q].is_nan() || det[q] <= 0.0) {
            return Some(Err(BadJacobian {
                det: det[q],
                point: self.rule.points[q],
            }));
        }
        let mut out = Hex8Points {
            grad: [[[0.0; 8]; 3]; 8],
            x: [[0.0; 3]; 8],
            jxw: [0.0; 8],
        };
        for q in 0..8 {
            let d = &t.dn_by_point[q];
            for i in 0..3 {
                let (r0, r1, r2) = (inv[0][i][q], inv[1][i][q], inv[2][i][q]);
                for a in 0..8 {
                    out.grad[q][i][a] = r0 * d[0][a] + r1 * d[1][a] + r2 * d[2][a];
                }
                out.x[q][i] = x[i][q];
            }
            out.jxw[q] = det[q] * t.weights[q];
        }
        Some(Ok(out))
    }

    /// The Jacobian `J_ik = ∂x_i/∂ξ_k` of a `Hex8` whose map is affine — a
    /// parallelepiped — to within the round-off of its coordinates, with the reference
    /// stiffness parts of the rule (per pair of [`HEX8_PAIRS`]); `None` for another basis or a map
    /// that is not affine. Affine: the coefficients of ξη, ξζ, ηζ and ξηζ in the map
    /// are at most 8ε times the largest coordinate, the size of the rounding of the
    /// coordinates themselves, so the element is a parallelepiped as far as its
    /// coordinates can say.
    pub fn affine_hex8(&self, coords: &[[f64; 3]; 8]) -> Option<([[f64; 3]; 3], &Hex8Stiffness)> {
        let t = self.hex8.as_deref()?;
        let nodes = super::shape::reference_nodes(Topology::Hex8)?;
        let mut j = [[0.0; 3]; 3];
        let mut bend = [[0.0; 3]; 4];
        let mut size = 0.0f64;
        for (c, r) in coords.iter().zip(nodes) {
            let signs = [r[0] * r[1], r[0] * r[2], r[1] * r[2], r[0] * r[1] * r[2]];
            for i in 0..3 {
                size = size.max(c[i].abs());
                for k in 0..3 {
                    j[i][k] += r[k] * c[i];
                }
                for (b, s) in bend.iter_mut().zip(signs) {
                    b[i] += s * c[i];
                }
            }
        }
        let limit = 64.0 * f64::EPSILON * size;
        // (A NaN coordinate is not affine either.)
        if !bend.iter().flatten().all(|v| v.abs() <= limit) {
            return None;
        }
        // Σ_a ξ_a x_a = 8 ∂x/∂ξ for the map Σ_a ⅛(1 + ξ_a ξ)(1 + η_a η)(1 + ζ_a ζ) x_a.
        j.iter_mut().flatten().for_each(|v| *v *= 0.125);
        Some((j, &t.stiffness))
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
    /// Axisymmetric ([`Basis::with_measure`]), `jxw` carries 2πr at the point.
    pub fn eval(&self, q: usize, coords: &[[f64; 3]]) -> Result<PointValues, BadJacobian> {
        let mut pv = map_point(
            self.topology,
            coords,
            &self.n[q],
            &self.dn[q],
            self.rule.points[q],
            self.rule.weights[q],
        )?;
        if self.measure == Measure::Axisymmetric {
            pv.jxw *= self.measure.factor(pv.x);
        }
        Ok(pv)
    }
}

/// `(det J, J⁻¹)` of a 3 × 3 Jacobian by cofactors (not finite for a singular J:
/// callers test the determinant).
pub(crate) fn inverse3(j: &[[f64; 3]; 3]) -> (f64, [[f64; 3]; 3]) {
    let c00 = j[1][1] * j[2][2] - j[1][2] * j[2][1];
    let c01 = j[1][2] * j[2][0] - j[1][0] * j[2][2];
    let c02 = j[1][0] * j[2][1] - j[1][1] * j[2][0];
    let det = j[0][0] * c00 + j[0][1] * c01 + j[0][2] * c02;
    let r = 1.0 / det;
    let inv = [
        [
            c00 * r,
            (j[0][2] * j[2][1] - j[0][1] * j[2][2]) * r,
            (j[0][1] * j[1][2] - j[0][2] * j[1][1]) * r,
        ],
        [
            c01 * r,
            (j[0][0] * j[2][2] - j[0][2] * j[2][0]) * r,
            (j[0][2] * j[1][0] - j[0][0] * j[1][2]) * r,
        ],
        [
            c02 * r,
            (j[0][1] * j[2][0] - j[0][0] * j[2][1]) * r,
            (j[0][0] * j[1][1] - j[0][1] * j[1][0]) * r,
        ],
    ];
    (det, inv)
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
        let det;
        (det, inv) = inverse3(&j);
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
