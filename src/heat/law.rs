//! Material laws of temperature: k(T), ρc(T) as a number, a piecewise-linear table or
//! a Lua expression of `T, x, y, z, t`.
//!
//! Entry point: [`Law::eval`], which returns the value and its derivative in T. Tables
//! are held constant beyond their ends (no jump to zero); Lua expressions are
//! differentiated by central differences. Laws are evaluated inside the parallel
//! element loops, so a Lua law compiles its expression once per worker thread, in a
//! sandbox of that thread.

use std::cell::RefCell;
use std::collections::HashMap;

use crate::script::{Limits, Sandbox, ScriptFn};

/// A scalar law of temperature.
#[derive(Clone, Debug, PartialEq)]
pub enum Law {
    Constant(f64),
    /// `(T, value)` points, T strictly increasing.
    Table(Vec<(f64, f64)>),
    /// A Lua expression of `T, x, y, z, t`; `chunk` names it in messages.
    Lua {
        expr: String,
        chunk: String,
    },
}

thread_local! {
    /// This thread's sandbox and the expressions it has compiled.
    static SANDBOX: RefCell<Option<(Sandbox, HashMap<String, ScriptFn>)>> =
        const { RefCell::new(None) };
}

impl Law {
    /// A table law, checked: at least one point, T strictly increasing, finite values.
    pub fn table(points: Vec<(f64, f64)>) -> Result<Law, String> {
        if points.is_empty() {
            return Err("a table needs at least one (T, value) point".into());
        }
        if let Some(p) = points
            .iter()
            .find(|(t, v)| !t.is_finite() || !v.is_finite())
        {
            return Err(format!("table point ({}, {}) is not finite", p.0, p.1));
        }
        if let Some(w) = points.windows(2).find(|w| w[1].0 <= w[0].0) {
            return Err(format!(
                "table temperatures must increase strictly: {} is followed by {}",
                w[0].0, w[1].0
            ));
        }
        Ok(Law::Table(points))
    }

    /// Does the value depend on temperature (or place and time)?
    pub fn is_constant(&self) -> bool {
        match self {
            Law::Constant(_) => true,
            Law::Table(p) => p.len() == 1,
            Law::Lua { .. } => false,
        }
    }

    /// The value and its derivative in T at temperature `t`, point `x` and time `time`.
    pub fn eval(&self, t: f64, x: [f64; 3], time: f64) -> Result<(f64, f64), String> {
        match self {
            Law::Constant(v) => Ok((*v, 0.0)),
            Law::Table(p) => Ok(table(p, t)),
            Law::Lua { expr, chunk } => {
                let h = 1e-6 * t.abs().max(1.0);
                let v = lua_value(expr, chunk, [t, x[0], x[1], x[2], time])?;
                let up = lua_value(expr, chunk, [t + h, x[0], x[1], x[2], time])?;
                let down = lua_value(expr, chunk, [t - h, x[0], x[1], x[2], time])?;
                Ok((v, (up - down) / (2.0 * h)))
            }
        }
    }

    /// Check the law once, on the calling thread: a Lua expression compiles and gives
    /// a finite number at `t`.
    pub fn check(&self, t: f64) -> Result<(), String> {
        self.eval(t, [0.0; 3], 0.0).map(|_| ())
    }
}

/// Piecewise-linear interpolation, constant beyond the ends.
fn table(p: &[(f64, f64)], t: f64) -> (f64, f64) {
    let first = p[0];
    let last = p[p.len() - 1];
    if t <= first.0 {
        return (first.1, 0.0);
    }
    if t >= last.0 {
        return (last.1, 0.0);
    }
    let k = p.partition_point(|q| q.0 <= t);
    let (a, b) = (p[k - 1], p[k]);
    let slope = (b.1 - a.1) / (b.0 - a.0);
    (a.1 + slope * (t - a.0), slope)
}

fn lua_value(expr: &str, chunk: &str, args: [f64; 5]) -> Result<f64, String> {
    SANDBOX.with(|cell| {
        let mut slot = cell.borrow_mut();
        if slot.is_none() {
            let sandbox = Sandbox::new(Limits::default()).map_err(|e| e.to_string())?;
            *slot = Some((sandbox, HashMap::new()));
        }
        let (sandbox, compiled) = slot.as_mut().expect("just made");
        let f = match compiled.get(expr) {
            Some(f) => f.clone(),
            None => {
                let f = sandbox
                    .expression(chunk, expr, &["T", "x", "y", "z", "t"])
                    .map_err(|e| e.to_string())?;
                compiled.insert(expr.to_string(), f.clone());
                f
            }
        };
        sandbox.call(&f, &args).map_err(|e| e.to_string())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tables interpolate linearly, hold their end values, and give the slope as the
    /// derivative inside.
    #[test]
    fn tables_interpolate_and_hold_their_ends() {
        let law = Law::table(vec![(300.0, 10.0), (400.0, 20.0), (500.0, 20.0)]).unwrap();
        assert_eq!(law.eval(350.0, [0.0; 3], 0.0).unwrap(), (15.0, 0.1));
        assert_eq!(law.eval(200.0, [0.0; 3], 0.0).unwrap(), (10.0, 0.0));
        assert_eq!(law.eval(900.0, [0.0; 3], 0.0).unwrap(), (20.0, 0.0));
        assert!(Law::table(vec![(1.0, 1.0), (1.0, 2.0)]).is_err());
        assert!(Law::table(vec![]).is_err());
    }

    /// A Lua law's central-difference derivative of a cubic is exact to round-off of
    /// the step (1e-6 relative step: error ~ h² T = 1e-9 relative).
    #[test]
    fn lua_law_differentiates() {
        let law = Law::Lua {
            expr: "1 + 2e-3*T + 1e-6*T^3 + x".into(),
            chunk: "test".into(),
        };
        let (v, d) = law.eval(300.0, [0.5, 0.0, 0.0], 0.0).unwrap();
        assert!((v - (1.0 + 0.6 + 27.0 + 0.5)).abs() < 1e-12);
        let exact = 2e-3 + 3e-6 * 300.0 * 300.0;
        assert!((d - exact).abs() < 1e-7 * exact, "{d} vs {exact}");
        let bad = Law::Lua {
            expr: "T +".into(),
            chunk: "material 1".into(),
        };
        let e = bad.check(300.0).unwrap_err();
        assert!(e.contains("material 1"), "{e}");
    }
}
