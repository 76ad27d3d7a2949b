//! `seam check-plugin PATH [--real …] [--integer …] [--isolate]`: load, describe, probe.

use std::io::Write;
use std::path::Path;

use seam_plugin_testkit::{Config, Report};

use super::{ContactPoint, Isolation, Plugin, PluginData, PluginError, PointResult, StepContext};

/// What [`check_plugin`] found.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckReport {
    /// The conformance kit's findings on its grid of states.
    pub conformance: Report,
    /// The first fault seam's own validation raised on the same grid, if any.
    pub host_fault: Option<String>,
    /// True when seam forms the derivatives itself (the plugin does not provide them).
    pub finite_difference_derivatives: bool,
}

impl CheckReport {
    pub fn passed(&self) -> bool {
        self.conformance.passed() && self.host_fault.is_none()
    }

    /// The findings as one JSON object (`seam check-plugin --json`): `passed`, the
    /// descriptor (`name`, `model_version`, `capabilities`), the grid's counts, the
    /// largest derivative error, the failures and seam's own fault, if any.
    pub fn to_json(&self) -> serde_json::Value {
        let c = &self.conformance;
        serde_json::json!({
            "passed": self.passed(),
            "name": c.name,
            "model_version": c.model_version,
            "capabilities": c.capabilities,
            "points": c.points,
            "derivatives_checked": c.derivatives_checked,
            "max_derivative_error": c.max_derivative_error,
            "finite_difference_derivatives": self.finite_difference_derivatives,
            "batch_checked": c.batch_checked,
            "threads_checked": c.threads_checked,
            "failures": c.failures,
            "failure_count": c.failure_count,
            "host_fault": self.host_fault,
        })
    }

    /// The command's exit code: 0 pass, 3 plugin fault. A load error (`Err` from
    /// [`check_plugin`]) is a plugin fault too: exit 3.
    pub fn exit_code(&self) -> i32 {
        if self.passed() { 0 } else { 3 }
    }
}

/// Load the plugin at `path` with `real` / `integer` as its Real / Integer Data, print
/// its descriptor, run the conformance checks (grid: gaps 1e-6–1e-4, pressures 1e5–1e7,
/// T_A 300–900, T_B 350–700, SI units) and seam's own output validation, and print the
/// findings to `out`. Write errors on `out` are ignored. In process: a plugin that
/// crashes ends the process (exit 3, see [`check_plugin_with`] for the isolated check).
pub fn check_plugin(
    path: &Path,
    real: &[f64],
    integer: &[i64],
    out: &mut impl Write,
) -> Result<CheckReport, PluginError> {
    check_plugin_with(path, real, integer, Isolation::None, out)
}

/// As [`check_plugin`], with the plugin in this process or in a worker process. Isolated,
/// a crash or an `exit` during the conformance checks is a failed check (the message
/// names how the worker died), and the host validation runs in a new worker.
pub fn check_plugin_with(
    path: &Path,
    real: &[f64],
    integer: &[i64],
    isolation: Isolation,
    out: &mut impl Write,
) -> Result<CheckReport, PluginError> {
    let data = PluginData {
        model: None,
        integer_data: integer.to_vec(),
        real_data: real.to_vec(),
    };
    let plugin = Plugin::load_with_isolation(path, &data, isolation)?;
    let info = plugin.info();
    let _ = writeln!(out, "plugin        {}", info.path.display());
    let _ = writeln!(out, "model         {} {}", info.name, info.model_version);
    let _ = writeln!(out, "ABI           {}.{}", info.abi_major, info.abi_minor);
    let _ = writeln!(out, "capabilities  {}", info.capability_names());
    let _ = writeln!(out, "state         {} doubles per point", info.state_size);
    let _ = writeln!(
        out,
        "entry points  evaluate_point{}",
        if info.has_batch {
            ", evaluate_batch"
        } else {
            ""
        }
    );
    if isolation == Isolation::Process {
        let _ = writeln!(out, "isolation     a worker process");
    }
    if let Some(notice) = plugin.derivative_notice() {
        let _ = writeln!(out, "note          {notice}");
    }
    let config = Config {
        integer_data: data.integer_data.clone(),
        real_data: data.real_data.clone(),
        ..Config::default()
    };
    let conformance = plugin.conformance(&config).unwrap_or_else(|fault| {
        let message = fault.to_string();
        Report {
            name: info.name.clone(),
            model_version: info.model_version.clone(),
            capabilities: info.capabilities,
            failures: vec![message],
            failure_count: 1,
            ..Report::default()
        }
    });
    let states = config.grid.states();
    let points: Vec<ContactPoint> = states
        .iter()
        .map(|s| ContactPoint {
            gap: s[0],
            pressure: s[1],
            temp_a: s[2],
            temp_b: s[3],
            normal_a: [0.0, 0.0, 1.0],
            normal_b: [0.0, 0.0, -1.0],
            weight: 1.0,
            ..ContactPoint::default()
        })
        .collect();
    let mut results = vec![PointResult::default(); points.len()];
    let ctx = StepContext {
        surface_a: "side_a",
        surface_b: "side_b",
        time: 1.0,
        dt: 1.0,
        step: 1,
        ..StepContext::default()
    };
    let host_fault = plugin
        .evaluate(&ctx, &points, &mut results, None)
        .err()
        .map(|f| f.to_string());
    let _ = writeln!(out, "{conformance}");
    if let Some(f) = &host_fault {
        let _ = writeln!(out, "host validation FAILED: {f}");
    }
    Ok(CheckReport {
        conformance,
        host_fault,
        finite_difference_derivatives: plugin.uses_finite_differences(),
    })
}
