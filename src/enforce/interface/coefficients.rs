//! The coefficients (P, θ, S) of each form and their derivatives in h and α, and how a
//! point's flux entries and penalty scale with a conductivity of the temperature (the
//! parent module's docs, "Conductivity of the temperature").

use super::{CachedPoint, Form, InterfaceError, InterfaceForm, InterfacePoints, point_error};

/// Above this many times the penalty scale α, a resistance (`P = h`) gives way to the
/// Robin–Nitsche coefficients. The resistance form's matrix grows with h, so its heat
/// `h [u]` loses about `log10(h/α) + 2` digits to round-off in `[u]` (a 1e20 conductance
/// reports nothing meaningful); the Robin–Nitsche form is a consistent discretisation of
/// the same condition `q = h [u]` whose coefficients stay bounded by α for every h up to
/// ∞. Where h is 100 α the interface is practically tied: both forms are exact for fields
/// the elements hold (patch tests, one-dimensional heat), and elsewhere differ at the
/// discretisation error, the resistance form tending to a tie that locks on non-matching
/// meshes and the Robin–Nitsche one to the Nitsche tie that does not.
pub const RESISTANCE_LIMIT: f64 = 100.0;

/// The coefficients (P, θ, S) and their derivatives with respect to h.
pub(super) fn coefficients(form: Form, h: f64, alpha: f64) -> ([f64; 3], [f64; 3]) {
    match form {
        Form::Conductance if h <= RESISTANCE_LIMIT * alpha => ([h, 0.0, 0.0], [1.0, 0.0, 0.0]),
        Form::TiedNitsche | Form::TiedInteriorPenalty => ([alpha, 1.0, 0.0], [0.0; 3]),
        Form::Penalty => ([alpha, 0.0, 0.0], [0.0; 3]),
        Form::Conductance | Form::GapConductance => robin_nitsche(h, alpha),
    }
}

/// The α-derivatives (dP/dα, dθ/dα, dS/dα) of [`coefficients`]: how the form changes
/// when the conductivity that scales α changes with the temperature.
pub(super) fn alpha_derivatives(form: Form, h: f64, alpha: f64) -> [f64; 3] {
    match form {
        Form::Conductance if h <= RESISTANCE_LIMIT * alpha => [0.0; 3],
        Form::TiedNitsche | Form::TiedInteriorPenalty | Form::Penalty => [1.0, 0.0, 0.0],
        Form::Conductance | Form::GapConductance if !h.is_finite() => [1.0, 0.0, 0.0],
        Form::Conductance | Form::GapConductance => {
            let d = h + alpha;
            let (theta, s) = (h / d, 1.0 / d);
            [theta * theta, -theta * s, -s * s]
        }
    }
}

/// How a point's flux entries (side A's, side B's) and penalty scale with the
/// conductivity at its temperatures, against the conductivities its local vectors were
/// made with, and the derivatives of the three with respect to T_A and T_B.
#[derive(Clone, Copy, Debug)]
pub(super) struct Scale {
    pub flux: [f64; 2],
    pub alpha: f64,
    /// d(flux A, flux B, α)/d(T_A, T_B).
    pub d: [[f64; 2]; 3],
    pub varies: bool,
}

impl Scale {
    pub const ONE: Scale = Scale {
        flux: [1.0; 2],
        alpha: 1.0,
        d: [[0.0; 2]; 3],
        varies: false,
    };
}

/// `P = hα/(h+α)`, `θ = h/(h+α)`, `S = 1/(h+α)` and their h-derivatives, written so that
/// no product overflows for any h up to ∞ (the tie `(α, 1, 0)` at ∞).
fn robin_nitsche(h: f64, alpha: f64) -> ([f64; 3], [f64; 3]) {
    if !h.is_finite() {
        return ([alpha, 1.0, 0.0], [0.0; 3]);
    }
    let d = h + alpha;
    let (theta, r) = (h / d, alpha / d); // θ = h/(h+α), r = α/(h+α): both in [0, 1]
    (
        [alpha * theta, theta, 1.0 / d],
        [r * r, r / d, -(1.0 / d) / d],
    )
}

impl InterfacePoints {
    /// The scales of point `p`'s flux entries and penalty at its temperatures (module
    /// docs, "Conductivity of the temperature"): 1 without a law.
    pub(super) fn scale(
        &self,
        p: &CachedPoint,
        form: &InterfaceForm<'_>,
        temp_a: f64,
        temp_b: f64,
    ) -> Result<Scale, InterfaceError> {
        let Some(law) = form.conductivity_of_t else {
            return Ok(Scale::ONE);
        };
        let k = |b: u32, t: f64| {
            law(b as usize, t, p.x).map_err(|m| point_error(p, format!("conductivity: {m}")))
        };
        let [ka0, kb0] = p.k0;
        let (kb, dkb) = k(p.blocks[1], temp_b)?;
        if p.side == 0 {
            // A node point: side B's flux alone, α = β k_B / h_e.
            let (s, ds) = (kb / kb0, dkb / kb0);
            return Ok(Scale {
                flux: [s, s],
                alpha: s,
                d: [[0.0, ds]; 3],
                varies: true,
            });
        }
        let (ka, dka) = k(p.blocks[0], temp_a)?;
        Ok(match form.form {
            // Weights ½ and ½: each side's flux by its own k, α by their mean.
            Form::TiedInteriorPenalty => {
                let sum0 = ka0 + kb0;
                Scale {
                    flux: [ka / ka0, kb / kb0],
                    alpha: (ka + kb) / sum0,
                    d: [[dka / ka0, 0.0], [0.0, dkb / kb0], [dka / sum0, dkb / sum0]],
                    varies: true,
                }
            }
            // Weights k_B/(k_A+k_B) and k_A/(k_A+k_B): both sides' flux entries carry
            // κ = k_A k_B/(k_A+k_B), and α = 2βκ/h_e.
            _ => {
                let kappa0 = ka0 * kb0 / (ka0 + kb0);
                let (sum, kappa) = (ka + kb, ka * kb / (ka + kb));
                let s = kappa / kappa0;
                let ds = [
                    kb * kb / (sum * sum) * dka / kappa0,
                    ka * ka / (sum * sum) * dkb / kappa0,
                ];
                Scale {
                    flux: [s, s],
                    alpha: s,
                    d: [ds; 3],
                    varies: true,
                }
            }
        })
    }
}
