//! Species diffusion beside the temperature: the concentration c (mol/m³) of one
//! diffusing species, in blocks with a diffusivity D(T) (m²/s), solved by the same
//! Newton as the temperature — the heat equation with k → D, ρc → a capacity φ, T → c.
//! The coupling is one way (D depends on T, the temperature equation does not see c), so
//! the coupled Jacobian is block lower triangular and its answer the staggered one.
//!
//! In a block with a species the element residual of the concentration rows is
//!
//! ```text
//! R_c,a = ∫ D(T) ∇N_a·∇c
//! ```
//!
//! with the Jacobian blocks
//!
//! ```text
//! ∂R_c,a/∂c_b = ∫ D ∇N_a·∇N_b
//! ∂R_c,a/∂T_b = ∫ D'(T) N_b ∇N_a·∇c
//! ```
//!
//! and the lumped capacity `∫ φ N_a` times the time derivative of c_a. A flux j (mol/m²/s)
//! into the body on a face adds `−∫ j N_a`.
//!
//! Conventions: an element's dofs are its fields' in [`DofMap`](crate::assembly::DofMap)
//! order, the temperature first and the species last; the kernel writes the species rows
//! at offset `off` of an element matrix of width `w` (row-major) and adds into its output.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::fem::{BadJacobian, Basis};

/// Name of the species field in a [`DofMap`](crate::assembly::DofMap).
pub const SPECIES: &str = "species";

/// The species rows of an element of a block with D(T): see the module docs. `t` and
/// `c` are the element's nodal temperatures and concentrations, `d` the law D(T, x) with
/// its T-derivative; the temperature's columns are `0..nn`, the concentration's rows and
/// columns `off..off + nn` of the `w`-wide `je`; `re` has `w` entries.
#[allow(clippy::too_many_arguments)]
pub fn species_residual_jacobian(
    basis: &Basis,
    coords: &[[f64; 3]],
    t: &[f64],
    c: &[f64],
    d: impl Fn(f64, [f64; 3]) -> (f64, f64),
    (off, w): (usize, usize),
    re: &mut [f64],
    je: &mut [f64],
) -> Result<(), BadJacobian> {
    let nn = basis.topology.node_count();
    for q in 0..basis.len() {
        let pv = basis.eval(q, coords)?;
        let mut tq = 0.0;
        let mut gc = [0.0; 3];
        for a in 0..nn {
            tq += pv.n[a] * t[a];
            for i in 0..3 {
                gc[i] += pv.grad[a][i] * c[a];
            }
        }
        let (dq, dd) = d(tq, pv.x);
        let jxw = pv.jxw;
        for a in 0..nn {
            let ga = pv.grad[a];
            let ga_gc = ga[0] * gc[0] + ga[1] * gc[1] + ga[2] * gc[2];
            re[off + a] += dq * ga_gc * jxw;
            for b in 0..nn {
                let gb = pv.grad[b];
                let gg = ga[0] * gb[0] + ga[1] * gb[1] + ga[2] * gb[2];
                je[(off + a) * w + off + b] += dq * gg * jxw;
                je[(off + a) * w + b] += dd * pv.n[b] * ga_gc * jxw;
            }
        }
    }
    Ok(())
}
