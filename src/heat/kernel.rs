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
//! 2-D elements (`Quad4`, `Tri3`) use x and y and integrate per unit depth, or per full
//! revolution when axisymmetric: the volume kernels through their basis
//! ([`Basis::with_measure`]), the face kernels through their `_with` forms
//! ([`face_flux_with`], [`face_convection_with`], [`face_load_with`]) — every weight
//! times 2πr.
//!
//! Fast path: on a `Hex8` basis with its eight-point rule ([`Basis::has_hex8_path`]) the
//! volume kernels map all points at once ([`Basis::map_hex8`]) and accumulate into the
//! fixed 8 × 8 block a row at a time, in loops of constant length that the compiler
//! vectorises; no kernel allocates. Each entry receives the same terms, computed by the
//! same operations in the same order, as on the general path (point after point; `k
//! ∇N_a·∇N_b` as `k (∂₁N_a ∂₁N_b + ∂₂N_a ∂₂N_b + ∂₃N_a ∂₃N_b)`), so both paths give the
//! same bits and the matrices stay exactly symmetric (each product commutes exactly).
//! Two exceptions: the nonlinear kernel leaves out its dk/dT term where dk/dT = 0
//! (a linear law), which adds ±0 and so changes no value (at most the sign of a zero);
//! and the conductivity kernel sums its upper triangle over the points before adding
//! it (and its mirror) into the block — the same bits into a zeroed block, as every
//! caller passes, the same sum to round-off into one that already holds values.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::fem::quadrature::QuadratureRule;
use crate::fem::shape::face_shape;
use crate::fem::{BadJacobian, Basis, Hex8Points, MAX_NODES, Measure};
use crate::mesh::{FaceShape, Topology};

/// The `Hex8` fast path of `basis` for these coordinates, if it applies.
#[inline(always)]
fn hex8_points(basis: &Basis, coords: &[[f64; 3]]) -> Option<Result<Hex8Points, BadJacobian>> {
    basis.map_hex8(coords.try_into().ok()?)
}

/// The 8 × 8 block of a `Hex8` kernel.
fn block8(m: &mut [f64]) -> &mut [f64; 64] {
    (&mut m[..64])
        .try_into()
        .expect("a Hex8 element block has 64 entries")
}

/// `Σ_i g_i[a] g_i[b]` for one row a and all b, the three components summed in order.
#[inline(always)]
fn gradient_products(g: &[[f64; 8]; 3], a: usize) -> [f64; 8] {
    let [gx, gy, gz] = g;
    std::array::from_fn(|b| gx[a] * gx[b] + gy[a] * gy[b] + gz[a] * gz[b])
}

/// Calls `f(n, x, jxw)` at every quadrature point (shape values, position, det J·w):
/// the points of the kernels that need no gradients, on the fast path when it applies.
fn for_each_point(
    basis: &Basis,
    coords: &[[f64; 3]],
    mut f: impl FnMut(&[f64; MAX_NODES], [f64; 3], f64),
) -> Result<(), BadJacobian> {
    if let Some(m) = hex8_points(basis, coords) {
        let m = m?;
        for q in 0..8 {
            f(basis.values(q), m.x[q], m.jxw[q]);
        }
        return Ok(());
    }
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
        f(&pv.n, pv.x, pv.jxw);
    }
    Ok(())
}

/// `K_ab += k ∫ ∇N_a·∇N_b dV` for a conductivity `k` constant over the element. On a
/// `Hex8` whose map is affine (a parallelepiped, to the round-off of its coordinates:
/// [`Basis::affine_hex8`]), `∇N = J⁻ᵀ∇̂N` with J constant, so
/// `K = Σ_{k≤l} G_kl S_kl` with `G = k det J · J⁻¹J⁻ᵀ` and `S_kl` the rule's reference
/// stiffness parts, made once per basis: 6 × 36 products instead of the 8-point
/// quadrature's mapping, inverses and gradients (eight times the work). The rule is
/// exact for these integrands on an affine element, so both give the same matrix to
/// round-off (not to the bit). Any other element goes by [`conductivity`].
pub fn conductivity_uniform(
    basis: &Basis,
    coords: &[[f64; 3]],
    k: f64,
    ke: &mut [f64],
) -> Result<(), BadJacobian> {
    let affine = <&[[f64; 3]; 8]>::try_from(coords)
        .ok()
        .and_then(|c| basis.affine_hex8(c));
    let Some((j, parts)) = affine else {
        return conductivity(basis, coords, |_| k, ke);
    };
    let (det, inv) = crate::fem::element::inverse3(&j);
    if det.is_nan() || det <= 0.0 {
        return Err(BadJacobian {
            det,
            point: basis.rule.points[0],
        });
    }
    let kd = k * det;
    let g = crate::fem::element::HEX8_PAIRS
        .map(|(a, b)| kd * (inv[a][0] * inv[b][0] + inv[a][1] * inv[b][1] + inv[a][2] * inv[b][2]));
    let mut upper = [0.0; 36];
    for (gp, part) in g.iter().zip(parts) {
        for (u, s) in upper.iter_mut().zip(part) {
            *u += gp * s;
        }
    }
    add_mirrored8(block8(ke), &upper);
    Ok(())
}

/// `ke += U + Uᵀ − diag U` for the upper triangle `upper` of an 8 × 8 block (row by
/// row from the diagonal on): exactly symmetric.
fn add_mirrored8(ke: &mut [f64; 64], upper: &[f64; 36]) {
    let mut at = 0;
    for a in 0..8 {
        for b in a..8 {
            ke[a * 8 + b] += upper[at];
            if b != a {
                ke[b * 8 + a] += upper[at];
            }
            at += 1;
        }
    }
}

/// `K_ab += ∫ k(x) ∇N_a·∇N_b dV`.
pub fn conductivity(
    basis: &Basis,
    coords: &[[f64; 3]],
    k: impl Fn([f64; 3]) -> f64,
    ke: &mut [f64],
) -> Result<(), BadJacobian> {
    if let Some(m) = hex8_points(basis, coords) {
        let m = m?;
        let ke = block8(ke);
        // The upper triangle (row a from column a on), then mirrored: each entry
        // gets the terms the full block would give it (the products commute exactly),
        // in 36 entries' work instead of 64.
        let mut upper = [0.0; 36];
        for q in 0..8 {
            let kw = k(m.x[q]) * m.jxw[q];
            let mut at = 0;
            for a in 0..8 {
                let gg = gradient_products(&m.grad[q], a);
                for b in a..8 {
                    upper[at] += kw * gg[b];
                    at += 1;
                }
            }
        }
        add_mirrored8(ke, &upper);
        return Ok(());
    }
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
    for_each_point(basis, coords, |n, _, jxw| {
        for a in 0..nn {
            for b in 0..nn {
                me[a * nn + b] += rho_c * n[a] * n[b] * jxw;
            }
        }
    })
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
    for_each_point(basis, coords, |n, _, jxw| {
        for a in 0..nn {
            me[a * nn + a] += rho_c * n[a] * jxw;
        }
    })
}

/// `f_a += ∫ Q(x) N_a dV`.
pub fn source(
    basis: &Basis,
    coords: &[[f64; 3]],
    q: impl Fn([f64; 3]) -> f64,
    fe: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for_each_point(basis, coords, |n, x, jxw| {
        let qw = q(x) * jxw;
        for a in 0..nn {
            fe[a] += qw * n[a];
        }
    })
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
    for_each_point(basis, coords, |n, x, jxw| {
        let tq: f64 = (0..nn).map(|a| n[a] * t[a]).sum();
        let (qv, dq) = q(tq, x);
        for a in 0..nn {
            re[a] -= qv * n[a] * jxw;
            for b in 0..nn {
                je[a * nn + b] -= dq * n[a] * n[b] * jxw;
            }
        }
    })
}

/// Element volume (area for 2-D elements): ∫ 1 dV.
pub fn measure(basis: &Basis, coords: &[[f64; 3]]) -> Result<f64, BadJacobian> {
    let mut v = 0.0;
    for_each_point(basis, coords, |_, _, jxw| v += jxw)?;
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
    measure: Measure,
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
        FacePoint {
            n,
            x,
            jxw: da * w * measure.factor(x),
        }
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
    face_flux_with(Measure::Plane, topology, coords, side, q, fe)
}

/// [`face_flux`] measured by `measure` (per revolution: `dA = 2πr ds`).
pub fn face_flux_with(
    measure: Measure,
    topology: Topology,
    coords: &[[f64; 3]],
    side: u8,
    q: impl Fn([f64; 3]) -> f64,
    fe: &mut [f64],
) {
    let (face, local, fc) = side_geometry(topology, coords, side);
    for fp in face_points(face, &fc, face_rule(face), measure) {
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
    face_convection_with(Measure::Plane, topology, coords, side, h, t_inf, ke, fe)
}

/// [`face_convection`] measured by `measure` (per revolution: `dA = 2πr ds`).
#[allow(clippy::too_many_arguments)]
pub fn face_convection_with(
    measure: Measure,
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
    for fp in face_points(face, &fc, face_rule(face), measure) {
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
    face_load_with(Measure::Plane, topology, coords, side, t, g, re, je)
}

/// [`face_load`] measured by `measure` (per revolution: `dA = 2πr ds`).
#[allow(clippy::too_many_arguments)]
pub fn face_load_with(
    measure: Measure,
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
    for fp in face_points(face, &fc, face_rule(face), measure) {
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
    if let Some(m) = hex8_points(basis, coords) {
        let m = m?;
        let je = block8(je);
        for q in 0..8 {
            let [gx, gy, gz] = &m.grad[q];
            let n = basis.values(q);
            let mut tq = 0.0;
            let mut gt = [0.0; 3];
            for a in 0..8 {
                tq += n[a] * t[a];
                gt[0] += gx[a] * t[a];
                gt[1] += gy[a] * t[a];
                gt[2] += gz[a] * t[a];
            }
            let (kq, dk) = k(tq, m.x[q]);
            let jxw = m.jxw[q];
            for a in 0..8 {
                let ga_gt = gx[a] * gt[0] + gy[a] * gt[1] + gz[a] * gt[2];
                re[a] += kq * ga_gt * jxw;
                let gg = gradient_products(&m.grad[q], a);
                let row = &mut je[a * 8..a * 8 + 8];
                if dk == 0.0 {
                    // The dk/dT term is ±0 here: leaving it out changes no value.
                    for b in 0..8 {
                        row[b] += (kq * gg[b]) * jxw;
                    }
                } else {
                    for b in 0..8 {
                        row[b] += (kq * gg[b] + dk * n[b] * ga_gt) * jxw;
                    }
                }
            }
        }
        return Ok(());
    }
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

    /// Distorted Hex8s: the unit cube's corners moved by up to 0.3 in every direction
    /// (a different pattern per element), so J varies from point to point and has no
    /// zero entries; one is also scaled and rotated away from the axes.
    fn distorted_hexes() -> Vec<[[f64; 3]; 8]> {
        let cube = crate::fem::shape::reference_nodes(Topology::Hex8).unwrap();
        (0..6)
            .map(|e| {
                std::array::from_fn(|a| {
                    let p = cube[a];
                    let w = |s: usize| 0.3 * (((a * 7 + e * 13 + s * 5) % 11) as f64 / 10.0 - 0.5);
                    let q = [p[0] + w(0), 0.5 * p[1] + w(1), 2.0 * p[2] + w(2)];
                    // A rotation about z by 0.4 rad for every other element.
                    let (s, c) = if e % 2 == 0 {
                        (0.0, 1.0)
                    } else {
                        0.4f64.sin_cos()
                    };
                    [c * q[0] - s * q[1] + 3.0, s * q[0] + c * q[1] - 1.0, q[2]]
                })
            })
            .collect()
    }

    /// The Hex8 fast path gives the general path's values to the last bit (the same
    /// operations in the same order, module docs) on distorted elements, for every volume
    /// kernel, with position- and temperature-dependent coefficients; and an inverted
    /// element is the same error on both paths.
    #[test]
    fn hex8_fast_path_equals_general_path() {
        let fast = Basis::standard(Topology::Hex8).unwrap();
        assert!(fast.has_hex8_path());
        let general = fast.clone().without_fast_path();
        assert!(!general.has_hex8_path());
        let t: Vec<f64> = (0..8)
            .map(|a| 300.0 + 11.0 * a as f64 - (a * a) as f64)
            .collect();
        let k = |p: [f64; 3]| 2.0 + p[0] - 0.5 * p[2];
        let kt = |temp: f64, p: [f64; 3]| (1.0 + 1e-3 * temp * temp + p[1], 2e-3 * temp);
        let q = |temp: f64, p: [f64; 3]| (1e-2 * temp + p[0] * p[2], 1e-2);
        for x in distorted_hexes() {
            let run = |basis: &Basis| {
                let (mut ke, mut je, mut js, mut me) = ([0.0; 64], [0.0; 64], [0.0; 64], [0.0; 64]);
                let (mut re, mut rs, mut fe) = ([0.0; 8], [0.0; 8], [0.0; 8]);
                conductivity(basis, &x, k, &mut ke).unwrap();
                conduction_residual_jacobian(basis, &x, &t, kt, &mut re, &mut je).unwrap();
                // A law without dk/dT (the fast path's shortcut), into the same arrays.
                let linear = |_: f64, p: [f64; 3]| (k(p), 0.0);
                conduction_residual_jacobian(basis, &x, &t, linear, &mut re, &mut je).unwrap();
                source(basis, &x, |p| 1.0 + p[1], &mut fe).unwrap();
                source_residual_jacobian(basis, &x, &t, q, &mut rs, &mut js).unwrap();
                capacity_lumped(basis, &x, 3.0, &mut me).unwrap();
                capacity_consistent(basis, &x, 3.0, &mut me).unwrap();
                let v = measure(basis, &x).unwrap();
                [&ke[..], &je, &js, &me, &re, &rs, &fe, &[v]].concat()
            };
            let (a, b) = (run(&fast), run(&general));
            for (i, (u, v)) in a.iter().zip(&b).enumerate() {
                assert_eq!(u.to_bits(), v.to_bits(), "value {i}: fast {u}, general {v}");
            }
            // Exactly symmetric conductivity.
            for r in 0..8 {
                for c in 0..8 {
                    assert_eq!(a[r * 8 + c], a[c * 8 + r]);
                }
            }
        }
        let mut inverted = distorted_hexes()[1];
        inverted.swap(0, 4);
        let err = |basis: &Basis| conductivity(basis, &inverted, k, &mut [0.0; 64]).unwrap_err();
        assert_eq!(err(&fast), err(&general));
    }

    /// On parallelepipeds (a sheared, scaled and rotated cube, far from the origin) the
    /// affine path of `conductivity_uniform` gives the quadrature's matrix to round-off,
    /// exactly symmetric, annihilating constants; a distorted element takes the
    /// quadrature itself (the same bits), and an inverted parallelepiped is an error.
    #[test]
    fn affine_hex8_stiffness_equals_the_quadrature() {
        let basis = Basis::standard(Topology::Hex8).unwrap();
        let cube = crate::fem::shape::reference_nodes(Topology::Hex8).unwrap();
        let shear = [[0.7, 0.2, -0.1], [0.05, 0.4, 0.15], [0.1, -0.2, 1.3]];
        let parallelepiped = |scale: f64, origin: f64| -> [[f64; 3]; 8] {
            std::array::from_fn(|a| {
                let p = cube[a];
                std::array::from_fn(|i| {
                    origin + scale * (0..3).map(|k| shear[i][k] * p[k]).sum::<f64>()
                })
            })
        };
        for (scale, origin) in [(1.0, 0.0), (1e-3, 10.0), (40.0, -1e3)] {
            let x = parallelepiped(scale, origin);
            assert!(basis.affine_hex8(&x).is_some(), "{scale} {origin}");
            let (mut fast, mut quad) = ([0.0; 64], [0.0; 64]);
            conductivity_uniform(&basis, &x, 3.5, &mut fast).unwrap();
            conductivity(&basis, &x, |_| 3.5, &mut quad).unwrap();
            let largest = quad.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // Both are as exact as the coordinates: their rounding, ε |x|, against the
            // element's size, bounds how far either can be from the true matrix.
            let tol = 1e-13 * (origin.abs() / scale).max(1.0) * largest;
            for i in 0..64 {
                assert!(
                    (fast[i] - quad[i]).abs() <= tol,
                    "{i}: {} {}",
                    fast[i],
                    quad[i]
                );
                assert_eq!(fast[i].to_bits(), fast[(i % 8) * 8 + i / 8].to_bits());
            }
            for r in 0..8 {
                let sum: f64 = fast[r * 8..r * 8 + 8].iter().sum();
                assert!(sum.abs() <= 1e-14 * largest, "row {r}: {sum}");
            }
        }
        for x in distorted_hexes() {
            assert!(basis.affine_hex8(&x).is_none());
            let (mut fast, mut quad) = ([0.0; 64], [0.0; 64]);
            conductivity_uniform(&basis, &x, 3.5, &mut fast).unwrap();
            conductivity(&basis, &x, |_| 3.5, &mut quad).unwrap();
            assert!(
                fast.iter()
                    .zip(&quad)
                    .all(|(a, b)| a.to_bits() == b.to_bits())
            );
        }
        let mut inverted = parallelepiped(1.0, 0.0);
        inverted.swap(0, 4);
        inverted.swap(1, 5);
        inverted.swap(2, 6);
        inverted.swap(3, 7);
        assert!(basis.affine_hex8(&inverted).is_some());
        assert!(conductivity_uniform(&basis, &inverted, 1.0, &mut [0.0; 64]).is_err());
    }

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
