//! Element and face kernels of heat conduction. Every kernel *adds* into its output
//! (`ke` row-major `nn × nn`, `fe` length `nn`, `nn` the element's node count), so
//! several terms can share one element slot.
//!
//! Formulas (N_a shape functions, J the isoparametric Jacobian, w_q weights):
//! - conductivity `K_ab = ∫ k ∇N_a·∇N_b dV`,
//! - capacity `M_ab = ∫ ρc N_a N_b dV` (consistent) or its row sums on the diagonal
//!   (lumped),
//! - source `f_a = ∫ Q N_a dV`; a source Q(T) enters a residual as `R_a = −∫ Q N_a dV`
//!   with `∂R_a/∂T_b = −∫ (dQ/dT) N_a N_b dV`,
//! - face flux `f_a = ∫_Γ q N_a dA` (q into the body), convection `K_ab = ∫_Γ h N_a N_b`
//!   and `f_a = ∫_Γ h T∞ N_a`,
//! - nonlinear conduction `R_a = ∫ k(T) ∇N_a·∇T dV` with the exact Jacobian
//!   `∂R_a/∂T_b = ∫ [k ∇N_a·∇N_b + (dk/dT) N_b ∇N_a·∇T] dV`.
//!
//! 2-D elements (`Quad4`, `Tri3`) use x and y and integrate per unit depth.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::fem::quadrature::QuadratureRule;
use crate::fem::shape::face_shape;
use crate::fem::{BadJacobian, Basis};
use crate::mesh::{FaceShape, Topology};

/// `K_ab += ∫ k(x) ∇N_a·∇N_b dV`.
pub fn conductivity(
    basis: &Basis,
    coords: &[[f64; 3]],
    k: impl Fn([f64; 3]) -> f64,
    ke: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
        let kw = k(pv.x) * pv.jxw;
        // Upper triangle, mirrored: exactly symmetric and half the work.
        for a in 0..nn {
            let ga = pv.grad[a];
            for b in a..nn {
                let gb = pv.grad[b];
                let v = kw * (ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2]);
                ke[a * nn + b] += v;
                if b != a {
                    ke[b * nn + a] += v;
                }
            }
        }
    }
    Ok(())
}

/// Consistent capacity `M_ab += ∫ ρc N_a N_b dV`.
pub fn capacity_consistent(
    basis: &Basis,
    coords: &[[f64; 3]],
    rho_c: f64,
    me: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
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
    basis: &Basis,
    coords: &[[f64; 3]],
    rho_c: f64,
    me: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
        for a in 0..nn {
            me[a * nn + a] += rho_c * pv.n[a] * pv.jxw;
        }
    }
    Ok(())
}

/// `f_a += ∫ Q(x) N_a dV`.
pub fn source(
    basis: &Basis,
    coords: &[[f64; 3]],
    q: impl Fn([f64; 3]) -> f64,
    fe: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for i in 0..basis.len() {
        let pv = basis.eval(i, coords)?;
        let qw = q(pv.x) * pv.jxw;
        for a in 0..nn {
            fe[a] += qw * pv.n[a];
        }
    }
    Ok(())
}

/// A source that depends on temperature, as a residual: `R_a −= ∫ Q(T, x) N_a dV` and
/// `J_ab −= ∫ (dQ/dT) N_a N_b dV` with `T = Σ N_b t_b` at each point; `q(T, x)` returns
/// `(Q, dQ/dT)`.
pub fn source_residual_jacobian(
    basis: &Basis,
    coords: &[[f64; 3]],
    t: &[f64],
    q: impl Fn(f64, [f64; 3]) -> (f64, f64),
    re: &mut [f64],
    je: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for i in 0..basis.len() {
        let pv = basis.eval(i, coords)?;
        let tq: f64 = (0..nn).map(|a| pv.n[a] * t[a]).sum();
        let (qv, dq) = q(tq, pv.x);
        for a in 0..nn {
            re[a] -= qv * pv.n[a] * pv.jxw;
            for b in 0..nn {
                je[a * nn + b] -= dq * pv.n[a] * pv.n[b] * pv.jxw;
            }
        }
    }
    Ok(())
}

/// Element volume (area for 2-D elements): ∫ 1 dV.
pub fn measure(basis: &Basis, coords: &[[f64; 3]]) -> Result<f64, BadJacobian> {
    let mut v = 0.0;
    for q in 0..basis.len() {
        v += basis.eval(q, coords)?.jxw;
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

/// The face rule of each face shape, made once.
fn face_rule(face: FaceShape) -> &'static QuadratureRule {
    use std::sync::OnceLock;
    static RULES: [OnceLock<QuadratureRule>; 3] =
        [OnceLock::new(), OnceLock::new(), OnceLock::new()];
    let k = match face {
        FaceShape::Line2 => 0,
        FaceShape::Tri3 => 1,
        FaceShape::Quad4 => 2,
    };
    RULES[k].get_or_init(|| QuadratureRule::face(face, FACE_DEGREE))
}

/// `f_a += ∫_side q(x) N_a dA` (q: flux into the body). `side` is 1-based (Exodus).
pub fn face_flux(
    topology: Topology,
    coords: &[[f64; 3]],
    side: u8,
    q: impl Fn([f64; 3]) -> f64,
    fe: &mut [f64],
) {
    let (face, local, fc) = side_geometry(topology, coords, side);
    for fp in face_points(face, &fc, face_rule(face)) {
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
    for fp in face_points(face, &fc, face_rule(face)) {
        for (k, &a) in local.iter().enumerate() {
            fe[a as usize] += h * t_inf * fp.n[k] * fp.jxw;
            for (m, &b) in local.iter().enumerate() {
                ke[a as usize * nn + b as usize] += h * fp.n[k] * fp.n[m] * fp.jxw;
            }
        }
    }
}

/// A face load that depends on the face temperature: `R_a += ∫_side N_a g(T) dA` and
/// `J_ab += ∫_side N_a N_b g'(T) dA`, where `g(T, x)` returns `(g, dg/dT)` — the heat
/// leaving the body per area (convection `h (T − T∞)`, radiation `εσ(T⁴ − T∞⁴)`, a
/// flux `−q`). `t` holds the element's nodal temperatures; `side` is 1-based.
pub fn face_load(
    topology: Topology,
    coords: &[[f64; 3]],
    side: u8,
    t: &[f64],
    g: impl Fn(f64, [f64; 3]) -> (f64, f64),
    re: &mut [f64],
    je: &mut [f64],
) {
    let nn = topology.node_count();
    let (face, local, fc) = side_geometry(topology, coords, side);
    for fp in face_points(face, &fc, face_rule(face)) {
        let tq: f64 = local
            .iter()
            .enumerate()
            .map(|(k, &a)| fp.n[k] * t[a as usize])
            .sum();
        let (gq, dg) = g(tq, fp.x);
        for (k, &a) in local.iter().enumerate() {
            re[a as usize] += gq * fp.n[k] * fp.jxw;
            for (m, &b) in local.iter().enumerate() {
                je[a as usize * nn + b as usize] += dg * fp.n[k] * fp.n[m] * fp.jxw;
            }
        }
    }
}

/// Nonlinear conduction: `R_a += ∫ k(T) ∇N_a·∇T dV` and its exact Jacobian
/// `J_ab += ∫ [k ∇N_a·∇N_b + (dk/dT) N_b ∇N_a·∇T] dV`; `k(T, x)` returns `(k, dk/dT)`.
pub fn conduction_residual_jacobian(
    basis: &Basis,
    coords: &[[f64; 3]],
    t: &[f64],
    k: impl Fn(f64, [f64; 3]) -> (f64, f64),
    re: &mut [f64],
    je: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The Jacobian of a temperature-dependent source matches central differences of
    /// its residual on a distorted hex (Q = 1e-3 T² + x is quadratic in T, so central
    /// differences with a step of 1 K are exact but for round-off: 1e-9 relative).
    #[test]
    fn source_jacobian_matches_differences() {
        let basis = Basis::standard(Topology::Hex8).unwrap();
        let mut x = [[0.0; 3]; 8];
        for (a, p) in [
            [0.0, 0.0, 0.0],
            [1.1, 0.0, 0.1],
            [1.0, 0.9, 0.0],
            [0.1, 1.0, 0.0],
            [0.0, 0.1, 1.0],
            [1.0, 0.0, 1.2],
            [1.2, 1.1, 1.0],
            [0.0, 1.0, 0.9],
        ]
        .into_iter()
        .enumerate()
        {
            x[a] = p;
        }
        let t: Vec<f64> = (0..8).map(|a| 300.0 + 7.0 * a as f64).collect();
        let q = |temp: f64, p: [f64; 3]| (1e-3 * temp * temp + p[0], 2e-3 * temp);
        let residual = |t: &[f64]| {
            let (mut re, mut je) = ([0.0; 8], [0.0; 64]);
            source_residual_jacobian(&basis, &x, t, q, &mut re, &mut je).unwrap();
            (re, je)
        };
        let (_, je) = residual(&t);
        let h = 1.0;
        for b in 0..8 {
            let (mut up, mut down) = (t.clone(), t.clone());
            up[b] += h;
            down[b] -= h;
            let (ru, rd) = (residual(&up).0, residual(&down).0);
            for a in 0..8 {
                let fd = (ru[a] - rd[a]) / (2.0 * h);
                let j = je[a * 8 + b];
                assert!(
                    (fd - j).abs() <= 1e-9 * j.abs(),
                    "J[{a}][{b}] = {j}, differences {fd}"
                );
            }
        }
    }
}
