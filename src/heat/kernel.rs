//! Element and face kernels of heat conduction. Every kernel *adds* into its output
//! (`ke` row-major `nn × nn`, `fe` length `nn`, `nn` the element's node count), so
//! several terms can share one element slot.
//!
//! Formulas (N_a shape functions, J the isoparametric Jacobian, w_q weights):
//! - conductivity `K_ab = ∫ k ∇N_a·∇N_b dV`,
//! - capacity `M_ab = ∫ ρc N_a N_b dV` (consistent) or its row sums on the diagonal
//!   (lumped),
//! - source `f_a = ∫ Q N_a dV`,
//! - face flux `f_a = ∫_Γ q N_a dA` (q into the body), convection `K_ab = ∫_Γ h N_a N_b`
//!   and `f_a = ∫_Γ h T∞ N_a`,
//! - nonlinear conduction `R_a = ∫ k(T) ∇N_a·∇T dV` with the exact Jacobian
//!   `∂R_a/∂T_b = ∫ [k ∇N_a·∇N_b + (dk/dT) N_b ∇N_a·∇T] dV`.
//!
//! 2-D elements (`Quad4`, `Tri3`) use x and y and integrate per unit depth.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::mesh::{FaceShape, Topology};

use super::quadrature::QuadratureRule;
use super::shape::{face_shape, shape};

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

/// Evaluate shape functions, physical gradients and det J·w at reference point `xi`.
pub fn eval_point(
    topology: Topology,
    coords: &[[f64; 3]],
    xi: [f64; 3],
    weight: f64,
) -> Result<PointValues, BadJacobian> {
    let nn = topology.node_count();
    let mut pv = PointValues {
        n: [0.0; MAX_NODES],
        grad: [[0.0; 3]; MAX_NODES],
        x: [0.0; 3],
        jxw: 0.0,
    };
    let mut dn = [[0.0; 3]; MAX_NODES];
    shape(topology, xi, &mut pv.n, &mut dn);
    let dim = topology.parametric_dim();
    // J_ij = ∂x_i/∂ξ_j = Σ_a x_a,i ∂N_a/∂ξ_j
    let mut j = [[0.0; 3]; 3];
    for a in 0..nn {
        for i in 0..3 {
            pv.x[i] += pv.n[a] * coords[a][i];
        }
        for i in 0..dim {
            for k in 0..dim {
                j[i][k] += coords[a][i] * dn[a][k];
            }
        }
    }
    let (det, inv) = if dim == 3 {
        let det = j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
            - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
            + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
        let c = |r: usize, s: usize| {
            // cofactor-based inverse: inv[s][r] = cof(r, s) / det
            let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
            let (s1, s2) = ((s + 1) % 3, (s + 2) % 3);
            j[r1][s1] * j[r2][s2] - j[r1][s2] * j[r2][s1]
        };
        let mut inv = [[0.0; 3]; 3];
        for r in 0..3 {
            for s in 0..3 {
                inv[s][r] = c(r, s) / det;
            }
        }
        (det, inv)
    } else {
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        let mut inv = [[0.0; 3]; 3];
        inv[0][0] = j[1][1] / det;
        inv[0][1] = -j[0][1] / det;
        inv[1][0] = -j[1][0] / det;
        inv[1][1] = j[0][0] / det;
        (det, inv)
    };
    if det.is_nan() || det <= 0.0 {
        return Err(BadJacobian { det, point: xi });
    }
    // ∇_x N = J⁻ᵀ ∇_ξ N: (∇_x N)_i = Σ_k inv[k][i] ∂N/∂ξ_k
    for a in 0..nn {
        for i in 0..dim {
            pv.grad[a][i] = (0..dim).map(|k| inv[k][i] * dn[a][k]).sum();
        }
    }
    pv.jxw = det * weight;
    Ok(pv)
}

/// `K_ab += ∫ k(x) ∇N_a·∇N_b dV`.
pub fn conductivity(
    topology: Topology,
    coords: &[[f64; 3]],
    rule: &QuadratureRule,
    k: impl Fn([f64; 3]) -> f64,
    ke: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = topology.node_count();
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let pv = eval_point(topology, coords, *p, *w)?;
        let kw = k(pv.x) * pv.jxw;
        for a in 0..nn {
            for b in 0..nn {
                let g = pv.grad[a][0] * pv.grad[b][0]
                    + pv.grad[a][1] * pv.grad[b][1]
                    + pv.grad[a][2] * pv.grad[b][2];
                ke[a * nn + b] += kw * g;
            }
        }
    }
    Ok(())
}

/// Consistent capacity `M_ab += ∫ ρc N_a N_b dV`.
pub fn capacity_consistent(
    topology: Topology,
    coords: &[[f64; 3]],
    rule: &QuadratureRule,
    rho_c: f64,
    me: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = topology.node_count();
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let pv = eval_point(topology, coords, *p, *w)?;
        for a in 0..nn {
            for b in 0..nn {
                me[a * nn + b] += rho_c * pv.n[a] * pv.n[b] * pv.jxw;
            }
        }
    }
    Ok(())
}

/// Lumped capacity: the row sums of the consistent matrix on the diagonal,
/// `M_aa += ∫ ρc N_a dV` (positive for every element here, since ∫N_a > 0).
pub fn capacity_lumped(
    topology: Topology,
    coords: &[[f64; 3]],
    rule: &QuadratureRule,
    rho_c: f64,
    me: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = topology.node_count();
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let pv = eval_point(topology, coords, *p, *w)?;
        for a in 0..nn {
            me[a * nn + a] += rho_c * pv.n[a] * pv.jxw;
        }
    }
    Ok(())
}

/// `f_a += ∫ Q(x) N_a dV`.
pub fn source(
    topology: Topology,
    coords: &[[f64; 3]],
    rule: &QuadratureRule,
    q: impl Fn([f64; 3]) -> f64,
    fe: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = topology.node_count();
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let pv = eval_point(topology, coords, *p, *w)?;
        let qw = q(pv.x) * pv.jxw;
        for a in 0..nn {
            fe[a] += qw * pv.n[a];
        }
    }
    Ok(())
}

/// Element volume (area for 2-D elements): ∫ 1 dV.
pub fn measure(
    topology: Topology,
    coords: &[[f64; 3]],
    rule: &QuadratureRule,
) -> Result<f64, BadJacobian> {
    let mut v = 0.0;
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        v += eval_point(topology, coords, *p, *w)?.jxw;
    }
    Ok(v)
}

/// One quadrature point on a face: face shape values, position, dA·w.
struct FacePoint {
    n: [f64; 4],
    x: [f64; 3],
    jxw: f64,
}

fn face_points<'a>(
    face: FaceShape,
    fcoords: &'a [[f64; 3]],
    rule: &'a QuadratureRule,
) -> impl Iterator<Item = FacePoint> + 'a {
    rule.points.iter().zip(&rule.weights).map(move |(p, w)| {
        let mut n = [0.0; 4];
        let mut dn = [[0.0; 2]; 4];
        face_shape(face, [p[0], p[1]], &mut n, &mut dn);
        let mut x = [0.0; 3];
        let mut t = [[0.0; 3]; 2];
        for a in 0..face.node_count() {
            for i in 0..3 {
                x[i] += n[a] * fcoords[a][i];
                t[0][i] += dn[a][0] * fcoords[a][i];
                t[1][i] += dn[a][1] * fcoords[a][i];
            }
        }
        // dA = |∂x/∂s × ∂x/∂t| for surfaces, |∂x/∂s| for edges.
        let da = match face {
            FaceShape::Line2 => (t[0][0].powi(2) + t[0][1].powi(2) + t[0][2].powi(2)).sqrt(),
            _ => {
                let c = [
                    t[0][1] * t[1][2] - t[0][2] * t[1][1],
                    t[0][2] * t[1][0] - t[0][0] * t[1][2],
                    t[0][0] * t[1][1] - t[0][1] * t[1][0],
                ];
                (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
            }
        };
        FacePoint { n, x, jxw: da * w }
    })
}

/// The face shape, its local element nodes and its coordinates, for 1-based `side`.
fn side_geometry(
    topology: Topology,
    coords: &[[f64; 3]],
    side: u8,
) -> (FaceShape, &'static [u8], [[f64; 3]; 4]) {
    let s = side as usize - 1;
    let local = topology.sides()[s];
    let mut fc = [[0.0; 3]; 4];
    for (k, &l) in local.iter().enumerate() {
        fc[k] = coords[l as usize];
    }
    (topology.side_shape(s), local, fc)
}

/// Rule degree for face integrals: exact for N_a N_b h on flat faces (degree 2 per
/// direction; bilinear faces need degree 4 for the N N term times the area factor —
/// we take 4 so warped quads are still integrated accurately).
const FACE_DEGREE: usize = 4;

/// `f_a += ∫_side q(x) N_a dA` (q: flux into the body). `side` is 1-based (Exodus).
pub fn face_flux(
    topology: Topology,
    coords: &[[f64; 3]],
    side: u8,
    q: impl Fn([f64; 3]) -> f64,
    fe: &mut [f64],
) {
    let (face, local, fc) = side_geometry(topology, coords, side);
    let rule = QuadratureRule::face(face, FACE_DEGREE);
    for fp in face_points(face, &fc, &rule) {
        let qw = q(fp.x) * fp.jxw;
        for (k, &l) in local.iter().enumerate() {
            fe[l as usize] += qw * fp.n[k];
        }
    }
}

/// Convection on a side: `K_ab += ∫ h N_a N_b dA`, `f_a += ∫ h T∞ N_a dA`.
pub fn face_convection(
    topology: Topology,
    coords: &[[f64; 3]],
    side: u8,
    h: f64,
    t_inf: f64,
    ke: &mut [f64],
    fe: &mut [f64],
) {
    let nn = topology.node_count();
    let (face, local, fc) = side_geometry(topology, coords, side);
    let rule = QuadratureRule::face(face, FACE_DEGREE);
    for fp in face_points(face, &fc, &rule) {
        for (k, &a) in local.iter().enumerate() {
            fe[a as usize] += h * t_inf * fp.n[k] * fp.jxw;
            for (m, &b) in local.iter().enumerate() {
                ke[a as usize * nn + b as usize] += h * fp.n[k] * fp.n[m] * fp.jxw;
            }
        }
    }
}

/// Nonlinear conduction: `R_a += ∫ k(T) ∇N_a·∇T dV` and its exact Jacobian
/// `J_ab += ∫ [k ∇N_a·∇N_b + (dk/dT) N_b ∇N_a·∇T] dV`; `k(T, x)` returns `(k, dk/dT)`.
pub fn conduction_residual_jacobian(
    topology: Topology,
    coords: &[[f64; 3]],
    rule: &QuadratureRule,
    t: &[f64],
    k: impl Fn(f64, [f64; 3]) -> (f64, f64),
    re: &mut [f64],
    je: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = topology.node_count();
    for (p, w) in rule.points.iter().zip(&rule.weights) {
        let pv = eval_point(topology, coords, *p, *w)?;
        let mut tq = 0.0;
        let mut gt = [0.0; 3];
        for a in 0..nn {
            tq += pv.n[a] * t[a];
            for i in 0..3 {
                gt[i] += pv.grad[a][i] * t[a];
            }
        }
        let (kq, dk) = k(tq, pv.x);
        for a in 0..nn {
            let ga = pv.grad[a];
            let ga_gt = ga[0] * gt[0] + ga[1] * gt[1] + ga[2] * gt[2];
            re[a] += kq * ga_gt * pv.jxw;
            for b in 0..nn {
                let gb = pv.grad[b];
                let gg = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
                je[a * nn + b] += (kq * gg + dk * pv.n[b] * ga_gt) * pv.jxw;
            }
        }
    }
    Ok(())
}
