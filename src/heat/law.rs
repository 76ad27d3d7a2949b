//! Material laws of temperature: k(T), ρc(T) as a number, a piecewise-linear table or
//! a Lua expression of `T, x, y, z, t`; a volumetric source Q(T, x, t) the same way, or
//! as a table in time.
//!
//! Entry point: [`Law::eval`], which returns the value and its derivative in T. Tables
//! are held constant beyond their ends (no jump to zero); Lua expressions that name `T`
//! are differentiated by central differences (the others have dQ/dT = 0 and cost one
//! call). Laws are evaluated inside the parallel
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
    /// `(t, value)` points in time t (strictly increasing), the same at every
    /// temperature: a source given as a table.
    TimeTable(Vec<(f64, f64)>),
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
            return Err("a table needs at least one (T or t, value) point".into());
        }
        if let Some(p) = points
            .iter()
            .find(|(t, v)| !t.is_finite() || !v.is_finite())
        {
            return Err(format!("table point ({}, {}) is not finite", p.0, p.1));
        }
        if let Some(w) = points.windows(2).find(|w| w[1].0 <= w[0].0) {
            return Err(format!(
                "the first values of a table (T or t) must increase strictly: {} is followed by {}",
                w[0].0, w[1].0
            ));
        }
        Ok(Law::Table(points))
    }

    /// Does the value depend on temperature (or place and time)?
    pub fn is_constant(&self) -> bool {
        match self {
            Law::Constant(_) => true,
            Law::Table(p) | Law::TimeTable(p) => p.len() == 1,
            Law::Lua { .. } => false,
        }
    }

    /// May the value change with the time alone? A table in time does, and a Lua
    /// expression may (it is not read for `t`: the safe answer).
    pub fn depends_on_time(&self) -> bool {
        match self {
            Law::Constant(_) | Law::Table(_) => false,
            Law::TimeTable(p) => p.len() > 1,
            Law::Lua { .. } => true,
        }
    }

    /// Does the value depend on temperature? (A source that does makes the problem
    /// nonlinear.) A Lua expression does when it names the variable `T`.
    pub fn uses_temperature(&self) -> bool {
        match self {
            Law::Constant(_) | Law::TimeTable(_) => false,
            Law::Table(p) => p.len() > 1,
            Law::Lua { expr, .. } => names_temperature(expr),
        }
    }

    /// The value and its derivative in T at temperature `t`, point `x` and time `time`.
    pub fn eval(&self, t: f64, x: [f64; 3], time: f64) -> Result<(f64, f64), String> {
        match self {
            Law::Constant(v) => Ok((*v, 0.0)),
            Law::Table(p) => Ok(table(p, t)),
            Law::TimeTable(p) => Ok((table(p, time).0, 0.0)),
            Law::Lua { expr, chunk } => {
                let at = |t: f64| [t, x[0], x[1], x[2], time];
                if !names_temperature(expr) {
                    let [v] = lua_values(expr, chunk, [at(t)])?;
                    return Ok((v, 0.0));
                }
                let h = 1e-6 * t.abs().max(1.0);
                let [v, up, down] = lua_values(expr, chunk, [at(t), at(t + h), at(t - h)])?;
                Ok((v, (up - down) / (2.0 * h)))
            }
        }
    }

    /// A source's Q(T, x, t) and dQ/dT where both are finite; else what went wrong there,
    /// on one line with the place, T and t (what the solvers report).
    pub(crate) fn source_at(
        &self,
        temp: f64,
        x: [f64; 3],
        time: f64,
    ) -> Result<(f64, f64), String> {
        let what = match self.eval(temp, x, time) {
            Ok((q, dq)) if q.is_finite() && dq.is_finite() => return Ok((q, dq)),
            Ok((q, dq)) => format!("Q = {q}, dQ/dT = {dq}"),
            Err(m) => m.lines().next().unwrap_or_default().to_string(),
        };
        let [x0, x1, x2] = x;
        Err(format!(
            "{what} at ({x0:.6}, {x1:.6}, {x2:.6}), T = {temp}, t = {time}"
        ))
    }

    /// The source at time `time` as a function of x alone (T not read), for the linear
    /// solves: 0 where it fails or is not finite, the first such place kept in `failed`
    /// (reported after the assembly).
    pub(crate) fn source_of_x<'a>(
        &'a self,
        time: f64,
        failed: &'a std::sync::Mutex<Option<String>>,
    ) -> impl Fn([f64; 3]) -> f64 + Sync + 'a {
        move |x| match self.eval(0.0, x, time) {
            Ok((v, _)) if v.is_finite() => v,
            r => {
                let mut slot = failed.lock().unwrap_or_else(|p| p.into_inner());
                let what = match r {
                    Err(e) => e.lines().next().unwrap_or_default().to_string(),
                    Ok((v, _)) => format!("Q = {v}"),
                };
                let [x0, x1, x2] = x;
                slot.get_or_insert_with(|| format!("{what} at ({x0:.6}, {x1:.6}, {x2:.6})"));
                0.0
            }
        }
    }

    /// Check the law once, on the calling thread: a Lua expression compiles and gives
    /// a finite number at `t`.
    pub fn check(&self, t: f64) -> Result<(), String> {
        self.eval(t, [0.0; 3], 0.0).map(|_| ())
    }
}

/// Does `expr` name the variable `T`: a `T` not inside a longer name and not a field
/// (`a.T`; the concatenation `..T` is the variable)? A `T` in a string or comment
/// counts too: that only costs Newton iterations, never a wrong derivative.
fn names_temperature(expr: &str) -> bool {
    let b = expr.as_bytes();
    let word = |c: u8| c.is_ascii_alphanumeric() || c == b'_';
    (0..b.len()).any(|i| {
        let field = i >= 1 && b[i - 1] == b'.' && (i < 2 || b[i - 2] != b'.');
        b[i] == b'T'
            && !field
            && (i == 0 || !word(b[i - 1]))
            && b.get(i + 1).is_none_or(|&c| !word(c))
    })
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

/// `expr` at each of `args` in turn (`T, x, y, z, t`), compiled once per thread: the
/// thread's sandbox borrowed and the compiled function looked up once for all of them
/// (a k(T)'s value and its two differences are one lookup, not three).
fn lua_values<const N: usize>(
    expr: &str,
    chunk: &str,
    args: [[f64; 5]; N],
) -> Result<[f64; N], String> {
    SANDBOX.with(|cell| {
        let mut slot = cell.borrow_mut();
        if slot.is_none() {
            let sandbox = Sandbox::new(Limits::default()).map_err(|e| e.to_string())?;
            *slot = Some((sandbox, HashMap::new()));
        }
        let (sandbox, compiled) = slot.as_mut().expect("just made");
        if !compiled.contains_key(expr) {
            let f = sandbox
                .expression(chunk, expr, &["T", "x", "y", "z", "t"])
                .map_err(|e| e.to_string())?;
            compiled.insert(expr.to_string(), f);
        }
        let f = &compiled[expr];
        let mut out = [0.0; N];
        for (o, a) in out.iter_mut().zip(&args) {
            *o = sandbox.call(f, a).map_err(|e| e.to_string())?;
        }
        Ok(out)
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

    /// Only a `T` of its own is the temperature; a law without one has dQ/dT = 0, and a
    /// time table follows t whatever the temperature.
    #[test]
    fn temperature_dependence_is_seen() {
        let lua = |e: &str| Law::Lua {
            expr: e.into(),
            chunk: "test".into(),
        };
        for e in ["T", "2*T^2", "math.exp(-T/300)", "x+(T)", "'a'..T"] {
            assert!(lua(e).uses_temperature(), "{e}");
        }
        for e in ["x*t", "Tx + 1", "math.T", "x_T", "t"] {
            assert!(!lua(e).uses_temperature(), "{e}");
        }
        assert_eq!(
            lua("1e3*x + t").eval(500.0, [2.0, 0.0, 0.0], 1.0).unwrap(),
            (2001.0, 0.0)
        );
        let q = Law::TimeTable(vec![(0.0, 0.0), (2.0, 10.0)]);
        assert_eq!(q.eval(900.0, [0.0; 3], 0.5).unwrap(), (2.5, 0.0));
        assert!(!q.uses_temperature() && !q.is_constant());
    }
}
