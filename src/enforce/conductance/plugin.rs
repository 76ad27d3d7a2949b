//! The plugin adapter: a loaded enforcement plugin that returns conductance, used as a
//! conductance model.

use super::{Conductance, ConductanceError, ConductanceModel, PointState, check};
use crate::plugin::{
    ContactPoint, Plugin, PluginError, PluginFault, PluginSpec, PointResult, StepContext,
};

/// Why a plugin enforcement could not be made a conductance model: the library
/// (missing, not a plugin, refused its data) or the plugin's kind (returns flux, keeps
/// state). Both messages name the plugin's library.
#[derive(Debug, thiserror::Error)]
pub enum PluginLoadError {
    #[error(transparent)]
    Plugin(#[from] PluginError),
    #[error(transparent)]
    Conductance(#[from] ConductanceError),
}

/// A [`Plugin`] without `RETURNS_FLUX` and without per-point state, called one point at
/// a time. The host validates the plugin's output (finite, h ≥ 0) and forms finite
/// differences when the plugin does not provide derivatives; faults become
/// [`ConductanceError::Evaluation`] naming the plugin and the point. `Send + Sync`
/// (the host serialises calls to plugins that are not thread-safe).
///
/// The point has no normals or weight (a conductance does not depend on them): normals
/// are 0 and the weight 1. `surface_a` / `surface_b` are passed in the step context.
pub struct PluginConductance {
    plugin: Plugin,
    surface_a: String,
    surface_b: String,
}

impl PluginConductance {
    /// Refuses plugins that return flux or keep state (a coefficient model has
    /// neither).
    pub fn new(plugin: Plugin) -> Result<PluginConductance, ConductanceError> {
        let info = plugin.info();
        let model = format!("plugin {} ({})", info.name, info.path.display());
        if info.returns_flux() {
            return Err(ConductanceError::Parameter {
                model,
                message: "returns flux (RETURNS_FLUX), not a conductance coefficient".into(),
            });
        }
        if info.state_size > 0 {
            return Err(ConductanceError::Parameter {
                model,
                message: format!(
                    "keeps {} doubles of state per point; a conductance coefficient must be stateless",
                    info.state_size
                ),
            });
        }
        Ok(PluginConductance {
            plugin,
            surface_a: String::new(),
            surface_b: String::new(),
        })
    }

    /// Load `spec`'s plugin as a conductance model told the interaction's surfaces.
    pub fn load(
        spec: &PluginSpec,
        surface_a: &str,
        surface_b: &str,
    ) -> Result<PluginConductance, PluginLoadError> {
        Ok(PluginConductance::new(spec.load()?)?.on_surfaces(surface_a, surface_b))
    }

    /// The surfaces the plugin is told about.
    pub fn on_surfaces(mut self, surface_a: &str, surface_b: &str) -> Self {
        self.surface_a = surface_a.into();
        self.surface_b = surface_b.into();
        self
    }

    pub fn plugin(&self) -> &Plugin {
        &self.plugin
    }
}

impl ConductanceModel for PluginConductance {
    fn name(&self) -> String {
        format!("plugin {}", self.plugin.info().name)
    }

    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        self.evaluate_fields(s, &[])
    }

    /// At an electrical contact the plugin gets the voltages (V_A, V_B) as its two
    /// `fields`; h's derivatives in them are central differences (four calls more,
    /// exactly 0 for a plugin that does not read them).
    fn evaluate_with_voltage(
        &self,
        s: &PointState,
        volts: [f64; 2],
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        let c = self.evaluate_fields(s, &volts)?;
        let mut dv = [0.0; 2];
        for (i, d) in dv.iter_mut().enumerate() {
            let v = volts[i];
            let step = f64::EPSILON.cbrt() * v.abs().max(super::lua::FD_FLOOR_VOLTAGE);
            let step = (v + step) - v;
            let mut up = volts;
            up[i] = v + step;
            let mut down = volts;
            down[i] = v - step;
            let (hu, hd) = (
                self.evaluate_fields(s, &up)?.h,
                self.evaluate_fields(s, &down)?.h,
            );
            *d = (hu - hd) / (2.0 * step);
        }
        Ok((c, dv))
    }
}

impl PluginConductance {
    /// h at `s` with `fields` as the point's other fields.
    fn evaluate_fields(
        &self,
        s: &PointState,
        fields: &[f64],
    ) -> Result<Conductance, ConductanceError> {
        let ctx = StepContext {
            surface_a: &self.surface_a,
            surface_b: &self.surface_b,
            time: s.time,
            fields,
            n_fields: fields.len(),
            ..StepContext::default()
        };
        let point = ContactPoint {
            gap: s.gap,
            pressure: s.pressure,
            temp_a: s.temp_a,
            temp_b: s.temp_b,
            x: s.x,
            weight: 1.0,
            ..ContactPoint::default()
        };
        let mut out = [PointResult::default()];
        self.plugin
            .evaluate(&ctx, &[point], &mut out, None)
            .map_err(|e| {
                let (model, state, message) = (self.name(), *s, e.to_string());
                if let PluginFault::Cutback { factor, .. } = e {
                    ConductanceError::Cutback {
                        model,
                        state,
                        factor,
                        message,
                    }
                } else {
                    ConductanceError::Evaluation {
                        model,
                        state,
                        message,
                    }
                }
            })?;
        let r = out[0];
        check(
            self,
            s,
            Conductance {
                h: r.value,
                dh_dgap: r.d_gap,
                dh_dpressure: r.d_pressure,
                dh_dtemp_a: r.d_temp_a,
                dh_dtemp_b: r.d_temp_b,
            },
        )
    }
}
