//! The Lua conductance model: an expression or a file function, evaluated in its own
//! sandbox, with derivatives by central finite differences.

use std::path::Path;

use super::{Conductance, ConductanceError, ConductanceModel, PointState, check};
use crate::script::{Limits, Sandbox, ScriptError, ScriptFn};

/// Finite-difference step floors (same as the plugin host's): the step for variable
/// x_i is δ_i = ε^{1/3} · max(|x_i|, floor_i), made exactly representable as
/// (x_i + δ_i) − x_i. Central differences then have truncation error O(δ²) and
/// round-off O(ε/δ), both ≈ ε^{2/3} ≈ 4e-11 relative for a smooth h whose scale in
/// x_i is |x_i| or the floor. Floors: 1 K, 1 Pa, 1 nm.
pub const FD_FLOOR_TEMPERATURE: f64 = 1.0;
pub const FD_FLOOR_PRESSURE: f64 = 1.0;
pub const FD_FLOOR_GAP: f64 = 1e-9;

/// Floor of the finite-difference step in a voltage (V).
pub const FD_FLOOR_VOLTAGE: f64 = 1e-3;

/// The parameters of an expression, in call order. `T_A`/`T_B` are aliases of
/// `temp_a`/`temp_b` (the same values are passed twice), `V_A`/`V_B` of
/// `volt_a`/`volt_b`, which only an electrical contact passes (elsewhere they are nil).
const PARAMS: [&str; 14] = [
    "gap", "temp_a", "temp_b", "pressure", "x", "y", "z", "t", "T_A", "T_B", "volt_a", "volt_b",
    "V_A", "V_B",
];

/// Which of (gap, pressure, temp_a, temp_b) the code may depend on: an expression
/// that never names a parameter cannot depend on it (its only access is by name),
/// so that derivative is exactly 0 and costs no calls. A file function may depend on
/// anything.
#[derive(Clone, Copy, Debug)]
struct Uses {
    gap: bool,
    pressure: bool,
    temp_a: bool,
    temp_b: bool,
    volt_a: bool,
    volt_b: bool,
}

impl Uses {
    const ALL: Uses = Uses {
        gap: true,
        pressure: true,
        temp_a: true,
        temp_b: true,
        volt_a: true,
        volt_b: true,
    };

    fn of_expression(expr: &str) -> Uses {
        let idents: Vec<&str> = expr
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .filter(|w| !w.is_empty())
            .collect();
        let named = |n: &[&str]| idents.iter().any(|w| n.contains(w));
        Uses {
            gap: named(&["gap"]),
            pressure: named(&["pressure"]),
            temp_a: named(&["temp_a", "T_A"]),
            temp_b: named(&["temp_b", "T_B"]),
            volt_a: named(&["volt_a", "V_A"]),
            volt_b: named(&["volt_b", "V_B"]),
        }
    }
}

/// h from Lua: an expression in `gap, temp_a, temp_b, pressure, x, y, z, t` (with
/// `T_A`, `T_B` as aliases) and, at an electrical contact, `volt_a, volt_b` (`V_A`,
/// `V_B`), or a global function of a file called with `(gap, temp_a, temp_b, pressure,
/// x, y, z, t)`, and `volt_a, volt_b` after them at an electrical contact.
///
/// One sandbox per model (limits [`Limits::default`]: 16 MiB, 10⁷ instructions per
/// call). Not `Send`: the Lua state stays on the thread that built the model; build
/// one model per thread for parallel loops.
///
/// Derivatives are central finite differences with the step rule of
/// [`FD_FLOOR_GAP`]; a derivative costs two calls, skipped (exactly 0) for variables an
/// expression does not name. Each value must be a finite number; h at the point must
/// be ≥ 0 (perturbed values may dip below 0 near a zero of h, they only enter
/// differences). A Lua error names the model and the point.
pub struct LuaConductance {
    sandbox: Sandbox,
    f: ScriptFn,
    label: String,
    uses: Uses,
    alias_args: bool,
}

impl LuaConductance {
    /// Compile `expr`; `chunk` names it in messages (e.g. `deck.i:12`).
    pub fn expression(chunk: &str, expr: &str) -> Result<LuaConductance, ScriptError> {
        LuaConductance::expression_with(chunk, expr, Limits::default())
    }

    pub fn expression_with(
        chunk: &str,
        expr: &str,
        limits: Limits,
    ) -> Result<LuaConductance, ScriptError> {
        let sandbox = Sandbox::new(limits)?;
        let f = sandbox.expression(chunk, expr, &PARAMS)?;
        Ok(LuaConductance {
            sandbox,
            f,
            label: format!("lua `{expr}` ({chunk})"),
            uses: Uses::of_expression(expr),
            alias_args: true,
        })
    }

    /// Run `path` and use its global function `function`.
    pub fn file(path: &Path, function: &str) -> Result<LuaConductance, ScriptError> {
        LuaConductance::file_with(path, function, Limits::default())
    }

    pub fn file_with(
        path: &Path,
        function: &str,
        limits: Limits,
    ) -> Result<LuaConductance, ScriptError> {
        let text = crate::script::read_lua_file(path)?;
        LuaConductance::source_with(&path.display().to_string(), &text, function, limits)
    }

    /// Run the Lua source `text` (named `chunk` in messages, e.g. the file name as the
    /// deck wrote it) and use its global function `function`.
    pub fn source_with(
        chunk: &str,
        text: &str,
        function: &str,
        limits: Limits,
    ) -> Result<LuaConductance, ScriptError> {
        let sandbox = Sandbox::new(limits)?;
        sandbox.run_source(chunk, text)?;
        let f = sandbox.function(function, chunk)?;
        Ok(LuaConductance {
            sandbox,
            f,
            label: format!("lua {chunk}:{function}"),
            uses: Uses::ALL,
            alias_args: false,
        })
    }

    fn call(&self, (s, volts): (&PointState, Option<[f64; 2]>)) -> Result<f64, ConductanceError> {
        let [va, vb] = volts.unwrap_or([0.0; 2]);
        let all = [
            s.gap, s.temp_a, s.temp_b, s.pressure, s.x[0], s.x[1], s.x[2], s.time, s.temp_a,
            s.temp_b, va, vb, va, vb,
        ];
        let file = [
            s.gap, s.temp_a, s.temp_b, s.pressure, s.x[0], s.x[1], s.x[2], s.time, va, vb,
        ];
        // Without voltages the voltage parameters are left out: nil to the code.
        let args: &[f64] = match (self.alias_args, volts.is_some()) {
            (true, true) => &all,
            (true, false) => &all[..10],
            (false, true) => &file,
            (false, false) => &file[..8],
        };
        self.sandbox
            .call(&self.f, args)
            .map_err(|e| ConductanceError::Evaluation {
                model: self.label.clone(),
                state: *s,
                message: e.to_string(),
            })
    }

    /// Central difference in the variable `field` selects.
    fn central(
        &self,
        at: (&PointState, Option<[f64; 2]>),
        floor: f64,
        field: fn(&mut (PointState, [f64; 2])) -> &mut f64,
    ) -> Result<f64, ConductanceError> {
        let mut p = (*at.0, at.1.unwrap_or([0.0; 2]));
        let volts = at.1.is_some();
        let x = *field(&mut p);
        let step = f64::EPSILON.cbrt() * x.abs().max(floor);
        let step = (x + step) - x;
        *field(&mut p) = x + step;
        let up = self.call((&p.0, volts.then_some(p.1)))?;
        *field(&mut p) = x - step;
        let down = self.call((&p.0, volts.then_some(p.1)))?;
        Ok((up - down) / (2.0 * step))
    }

    /// h and its derivatives at `s` (with the voltages, at an electrical contact).
    fn evaluate_at(
        &self,
        s: &PointState,
        volts: Option<[f64; 2]>,
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        let at = (s, volts);
        let mut c = Conductance {
            h: self.call(at)?,
            ..Conductance::default()
        };
        if c.h < 0.0 {
            return check(self, s, c).map(|c| (c, [0.0; 2]));
        }
        if self.uses.gap {
            c.dh_dgap = self.central(at, FD_FLOOR_GAP, |p| &mut p.0.gap)?;
        }
        if self.uses.pressure {
            c.dh_dpressure = self.central(at, FD_FLOOR_PRESSURE, |p| &mut p.0.pressure)?;
        }
        if self.uses.temp_a {
            c.dh_dtemp_a = self.central(at, FD_FLOOR_TEMPERATURE, |p| &mut p.0.temp_a)?;
        }
        if self.uses.temp_b {
            c.dh_dtemp_b = self.central(at, FD_FLOOR_TEMPERATURE, |p| &mut p.0.temp_b)?;
        }
        let mut dv = [0.0; 2];
        if volts.is_some() {
            if self.uses.volt_a {
                dv[0] = self.central(at, FD_FLOOR_VOLTAGE, |p| &mut p.1[0])?;
            }
            if self.uses.volt_b {
                dv[1] = self.central(at, FD_FLOOR_VOLTAGE, |p| &mut p.1[1])?;
            }
            if let Some((what, &value)) = (["dh/dV_A", "dh/dV_B"].iter())
                .zip(&dv)
                .find(|(_, v)| !v.is_finite())
            {
                return Err(ConductanceError::NotFinite {
                    model: self.name(),
                    state: *s,
                    what,
                    value,
                });
            }
        }
        Ok((check(self, s, c)?, dv))
    }
}

impl ConductanceModel for LuaConductance {
    fn name(&self) -> String {
        self.label.clone()
    }

    /// An expression that never names `temp_a`/`temp_b` (`T_A`/`T_B`) cannot depend on
    /// them; a file function may.
    fn depends_on_temperature(&self) -> bool {
        self.uses.temp_a || self.uses.temp_b
    }

    fn value(&self, s: &PointState) -> Result<f64, ConductanceError> {
        let c = Conductance {
            h: self.call((s, None))?,
            ..Conductance::default()
        };
        check(self, s, c).map(|c| c.h)
    }

    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        self.evaluate_at(s, None).map(|(c, _)| c)
    }

    /// An expression that names `volt_a`/`volt_b` (`V_A`/`V_B`). A file function is not
    /// known to: it is passed the voltages (and differentiated in them) at an electrical
    /// contact, and gets nil for them elsewhere, so using them there is a Lua error that
    /// names the model and the point.
    fn depends_on_voltage(&self) -> bool {
        self.alias_args && (self.uses.volt_a || self.uses.volt_b)
    }

    fn evaluate_with_voltage(
        &self,
        s: &PointState,
        volts: [f64; 2],
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        self.evaluate_at(s, Some(volts))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unnamed_parameters_are_not_differentiated() {
        let u = Uses::of_expression("100 + 0.1*(temp_a + T_B)/2 + math.gap_like");
        assert!(!u.gap && !u.pressure && u.temp_a && u.temp_b);
        let u = Uses::of_expression("k/gap + pressure_x");
        assert!(u.gap && !u.pressure);
    }
}
