//! Cooper–Mikic–Yovanovich gap conductance as a seam plugin.
//!
//! h = h_c + h_g + h_r with
//! - constriction (CMY, plastic contact): h_c = 1.25 k_s (m/σ) (p/H_c)^0.95 for p > 0, else 0;
//! - gas gap: h_g = k_g / (max(g, 0) + M);
//! - radiation between grey parallel plates:
//!   h_r = σ_SB (T_A² + T_B²)(T_A + T_B) / (1/ε_A + 1/ε_B − 1), temperatures in kelvin.
//!
//! `Real Data` order (SI units): `k_s m sigma H_c k_g M eps_A eps_B`
//! (harmonic-mean solid conductivity W/m/K, mean asperity slope, RMS roughness m,
//! microhardness Pa, gas conductivity W/m/K, gas rarefaction parameter m, emissivities).
//!
//! Exact derivatives: ∂h/∂p = 0.95 h_c / p (p > 0, else 0); ∂h/∂g = −k_g/(g + M)² (g > 0,
//! else 0); ∂h/∂T_A = σ_SB (3T_A² + 2T_A T_B + T_B²)/E and symmetrically for T_B.

use seam_plugin_sdk::{EnforcementModel, InstanceData, ModelError, Output, PointIn, caps};

/// Stefan–Boltzmann constant, W/m²/K⁴ (CODATA 2018).
pub const STEFAN_BOLTZMANN: f64 = 5.670_374_419e-8;

/// The eight parameters, in `Real Data` order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cmy {
    pub k_s: f64,
    pub m: f64,
    pub sigma: f64,
    pub h_c: f64,
    pub k_g: f64,
    pub gas_m: f64,
    pub eps_a: f64,
    pub eps_b: f64,
}

impl Cmy {
    /// Conductance and derivatives at (gap, pressure, T_A, T_B).
    pub fn conductance(&self, gap: f64, pressure: f64, temp_a: f64, temp_b: f64) -> Output {
        let (h_c, dh_c) = if pressure > 0.0 {
            let h = 1.25 * self.k_s * (self.m / self.sigma) * (pressure / self.h_c).powf(0.95);
            (h, 0.95 * h / pressure)
        } else {
            (0.0, 0.0)
        };
        let g = gap.max(0.0);
        let h_g = self.k_g / (g + self.gas_m);
        let dh_g = if gap > 0.0 {
            -h_g / (g + self.gas_m)
        } else {
            0.0
        };
        let e = 1.0 / self.eps_a + 1.0 / self.eps_b - 1.0;
        let (ta, tb) = (temp_a, temp_b);
        let h_r = STEFAN_BOLTZMANN * (ta * ta + tb * tb) * (ta + tb) / e;
        Output {
            value: h_c + h_g + h_r,
            d_temp_a: STEFAN_BOLTZMANN * (3.0 * ta * ta + 2.0 * ta * tb + tb * tb) / e,
            d_temp_b: STEFAN_BOLTZMANN * (3.0 * tb * tb + 2.0 * ta * tb + ta * ta) / e,
            d_gap: dh_g,
            d_pressure: dh_c,
        }
    }
}

impl EnforcementModel for Cmy {
    fn new(data: &InstanceData<'_>) -> Result<Self, ModelError> {
        let r = data.real_data;
        let [k_s, m, sigma, h_c, k_g, gas_m, eps_a, eps_b] = r else {
            return Err(ModelError::new(format!(
                "cmy needs 8 Real Data values (k_s m sigma H_c k_g M eps_A eps_B), got {}",
                r.len()
            )));
        };
        let model = Cmy {
            k_s: *k_s,
            m: *m,
            sigma: *sigma,
            h_c: *h_c,
            k_g: *k_g,
            gas_m: *gas_m,
            eps_a: *eps_a,
            eps_b: *eps_b,
        };
        let positive = [
            ("k_s", *k_s),
            ("m", *m),
            ("sigma", *sigma),
            ("H_c", *h_c),
            ("M", *gas_m),
        ];
        for (name, v) in positive {
            if !(v > 0.0 && v.is_finite()) {
                return Err(ModelError::new(format!(
                    "cmy: {name} must be positive, got {v}"
                )));
            }
        }
        for (name, v) in [("k_g", *k_g)] {
            if !(v >= 0.0 && v.is_finite()) {
                return Err(ModelError::new(format!(
                    "cmy: {name} must be >= 0, got {v}"
                )));
            }
        }
        for (name, v) in [("eps_A", *eps_a), ("eps_B", *eps_b)] {
            if !(v > 0.0 && v <= 1.0) {
                return Err(ModelError::new(format!(
                    "cmy: {name} must be in (0, 1], got {v}"
                )));
            }
        }
        Ok(model)
    }

    fn evaluate(&self, p: &PointIn<'_>, _state: &mut [f64]) -> Result<Output, ModelError> {
        Ok(self.conductance(p.gap, p.pressure, p.temp_a, p.temp_b))
    }
}

seam_plugin_sdk::export_plugin!(
    Cmy,
    "cmy",
    "1.0.0",
    caps::THREAD_SAFE | caps::PROVIDES_DERIVATIVES
);
