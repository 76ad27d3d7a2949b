//! Panics on every point with pressure above 1 (and evaluates fine below), so a test can
//! see both that the panic is caught and that the host keeps working afterwards.

use seam_plugin_sdk::{EnforcementModel, InstanceData, ModelError, Output, PointIn, caps};

pub struct Panicky;

impl EnforcementModel for Panicky {
    fn new(_data: &InstanceData<'_>) -> Result<Self, ModelError> {
        Ok(Panicky)
    }

    fn evaluate(&self, p: &PointIn<'_>, _state: &mut [f64]) -> Result<Output, ModelError> {
        if p.pressure > 1.0 {
            panic!("deliberate panic at pressure {}", p.pressure);
        }
        Ok(Output {
            value: 1.0,
            ..Output::default()
        })
    }
}

seam_plugin_sdk::export_plugin!(
    Panicky,
    "panicky",
    "0.0.1",
    caps::THREAD_SAFE | caps::PROVIDES_DERIVATIVES
);
