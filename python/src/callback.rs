//! Conductances computed by the host in Python: a function of the contact point's
//! state ([`PointState`]) returning h, or h with its temperature derivatives. It is
//! called on the caller's thread during `evaluate`, `contributions`, `heat` and the
//! field queries, one point at a time.
//!
//! A function that raises, or returns something that is not one or three finite
//! numbers, makes the evaluation fail with `EnforcementError` naming the point; the
//! function's own exception is its `__cause__`.

use std::sync::{Arc, Mutex};

use pyo3::prelude::*;

use seam::embed::{Conductance, ConductanceModel, FnConductance};

/// The state of one contact point, as a conductance function sees it.
#[pyclass(module = "seam", frozen, get_all)]
pub struct PointState {
    /// Normal gap (m); > 0 open.
    pub gap: f64,
    /// Contact pressure (Pa); > 0 in compression (0 unless set).
    pub pressure: f64,
    /// Temperature on side A (K).
    pub temp_a: f64,
    /// Temperature on side B at the projection (K).
    pub temp_b: f64,
    /// Position of the point (m).
    pub x: (f64, f64, f64),
    /// The host's time (s), as last given to `set_time`.
    pub time: f64,
}

#[pymethods]
impl PointState {
    /// (T_A + T_B) / 2, the usual argument of temperature-dependent properties.
    #[getter]
    fn mean_temperature(&self) -> f64 {
        0.5 * (self.temp_a + self.temp_b)
    }

    fn __repr__(&self) -> String {
        format!(
            "PointState(gap={}, pressure={}, temp_a={}, temp_b={}, x={:?}, time={})",
            self.gap, self.pressure, self.temp_a, self.temp_b, self.x, self.time
        )
    }
}

/// Where a failing function's exception waits until the evaluation that called it
/// returns its error.
pub type Raised = Arc<Mutex<Option<PyErr>>>;

/// A conductance model calling `function`; `raised` keeps the exception it raises.
pub fn model(
    function: Py<PyAny>,
    depends_on_temperature: bool,
    raised: Raised,
) -> Arc<dyn ConductanceModel> {
    let name = Python::attach(|py| {
        function
            .bind(py)
            .getattr("__qualname__")
            .and_then(|n| n.extract::<String>())
            .unwrap_or_else(|_| "callable".into())
    });
    let label = format!("Python function {name}");
    let call = move |s: &seam::embed::PointState| -> Result<Conductance, String> {
        Python::attach(|py| {
            let state = PointState {
                gap: s.gap,
                pressure: s.pressure,
                temp_a: s.temp_a,
                temp_b: s.temp_b,
                x: (s.x[0], s.x[1], s.x[2]),
                time: s.time,
            };
            let result = function.bind(py).call1((state,)).and_then(|r| read(&r));
            result.map_err(|e| {
                let text = e.to_string();
                if let Ok(mut slot) = raised.lock()
                    && slot.is_none()
                {
                    *slot = Some(e);
                }
                text
            })
        })
    };
    Arc::new(FnConductance::new(&label, depends_on_temperature, call))
}

/// A function's answer: `h` or `(h, dh_dtemp_a, dh_dtemp_b)`.
fn read(r: &Bound<'_, PyAny>) -> PyResult<Conductance> {
    if let Ok(h) = r.extract::<f64>() {
        return Ok(Conductance {
            h,
            ..Conductance::default()
        });
    }
    match r.extract::<(f64, f64, f64)>() {
        Ok((h, dh_dtemp_a, dh_dtemp_b)) => Ok(Conductance {
            h,
            dh_dtemp_a,
            dh_dtemp_b,
            ..Conductance::default()
        }),
        Err(_) => Err(pyo3::exceptions::PyTypeError::new_err(format!(
            "a conductance function returns h or (h, dh_dtemp_a, dh_dtemp_b), not {}",
            r.repr().map_or_else(|_| "this".into(), |s| s.to_string())
        ))),
    }
}
