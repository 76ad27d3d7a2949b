//! Thermal–electrical coupling: the voltage field V beside the temperature T, solved
//! monolithically by the same Newton with exact cross Jacobians.
//!
//! In a block with an electrical conductivity σ(T) (S/m) the element residuals are
//!
//! ```text
//! R_T,a = ∫ k(T) ∇N_a·∇T − ∫ σ(T) |∇V|² N_a        (conduction, Joule heat)
//! R_V,a = ∫ σ(T) ∇N_a·∇V                          (charge conservation)
//! ```
//!
//! with the Jacobian blocks
//!
//! ```text
//! ∂R_T,a/∂T_b = ∫ k ∇N_a·∇N_b + k' N_b ∇N_a·∇T − σ' N_b |∇V|² N_a
//! ∂R_T,a/∂V_b = −∫ 2σ (∇V·∇N_b) N_a
//! ∂R_V,a/∂T_b = ∫ σ' N_b ∇N_a·∇V
//! ∂R_V,a/∂V_b = ∫ σ ∇N_a·∇N_b
//! ```
//!
//! At an electrical contact ([`ElectricContact`], in [`crate::enforce::electric`]) the current density from side A to side
//! B is `j = h_e(T_A, T_B, g) ([V] − ΔV)`, `[V] = V_A − V_B`, and the contact's Joule
//! heat `h_e ([V] − ΔV)²` per unit area goes to the temperature equations, the fraction
//! `f_A` to side A and `1 − f_A` to side B, each spread by its face's shape functions.
//!
//! Conventions: an element's dofs are its temperature dofs then its voltage dofs (the
//! [`DofMap`](crate::assembly::DofMap) order when `temperature` is numbered first);
//! element vectors have `2 nn` entries, matrices `2 nn × 2 nn` row-major; every kernel
//! adds into its output. Currents are A, current densities A/m², heats W.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::fem::{BadJacobian, Basis};

pub use crate::enforce::electric::{ContactPower, ElectricContact};

/// Name of the voltage field in a [`DofMap`](crate::assembly::DofMap).
pub const VOLTAGE: &str = "voltage";

/// The coupled element residual and Jacobian of a block with k(T) and σ(T): see the
/// module docs. `t` and `v` are the element's nodal temperatures and voltages, `(k,
/// sigma)` the laws k(T, x) and σ(T, x) with their T-derivatives; `re` has
/// `2 nn` entries, `je` `4 nn²`.
pub fn joule_residual_jacobian(
    basis: &Basis,
    coords: &[[f64; 3]],
    t: &[f64],
    v: &[f64],
    (k, sigma): (
        impl Fn(f64, [f64; 3]) -> (f64, f64),
        impl Fn(f64, [f64; 3]) -> (f64, f64),
    ),
    re: &mut [f64],
    je: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    let w = 2 * nn;
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
        let mut tq = 0.0;
        let mut gt = [0.0; 3];
        let mut gv = [0.0; 3];
        for a in 0..nn {
            tq += pv.n[a] * t[a];
            for i in 0..3 {
                gt[i] += pv.grad[a][i] * t[a];
                gv[i] += pv.grad[a][i] * v[a];
            }
        }
        let (kq, dk) = k(tq, pv.x);
        let (sq, ds) = sigma(tq, pv.x);
        let gv2 = gv[0] * gv[0] + gv[1] * gv[1] + gv[2] * gv[2];
        let jxw = pv.jxw;
        for a in 0..nn {
            let ga = pv.grad[a];
            let na = pv.n[a];
            let ga_gt = ga[0] * gt[0] + ga[1] * gt[1] + ga[2] * gt[2];
            let ga_gv = ga[0] * gv[0] + ga[1] * gv[1] + ga[2] * gv[2];
            re[a] += (kq * ga_gt - sq * gv2 * na) * jxw;
            re[nn + a] += sq * ga_gv * jxw;
            for b in 0..nn {
                let gb = pv.grad[b];
                let nb = pv.n[b];
                let gg = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
                let gb_gv = gb[0] * gv[0] + gb[1] * gv[1] + gb[2] * gv[2];
                je[a * w + b] += (kq * gg + dk * nb * ga_gt - ds * nb * gv2 * na) * jxw;
                je[a * w + nn + b] += -2.0 * sq * gb_gv * na * jxw;
                je[(nn + a) * w + b] += ds * nb * ga_gv * jxw;
                je[(nn + a) * w + nn + b] += sq * gg * jxw;
            }
        }
    }
    Ok(())
}
