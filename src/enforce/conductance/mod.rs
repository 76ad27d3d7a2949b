//! Conductance-coefficient models: h(g, p, T_A, T_B, x, t) at one contact point, with
//! its exact partial derivatives, for gap-conductance enforcement (q = h (T_B − T_A)
//! into side A).
//!
//! Entry points:
//! - [`ConductanceModel`]: the trait, `evaluate(&PointState) -> Conductance`;
//! - the built-in models [`Constant`], [`GasGap`], [`Radiation`], [`Cmy`], [`Table`]
//!   and their [`Sum`];
//! - [`LuaConductance`]: a sandboxed Lua expression or file function (derivatives by
//!   central finite differences);
//! - [`PluginConductance`]: a user plugin (`seam::plugin::Plugin`) that returns
//!   conductance.
//!
//! The deck's `Gap Conductance Coefficient = …` lines are turned into these models by
//! the scene, above (several lines add up into a [`Sum`]).
//!
//! Units (SI, as the deck): h in W/(m²·K), gap g in m (g > 0 open, g ≤ 0 closed or
//! penetrating), temperatures in K, pressure p in Pa (≥ 0 in compression), x in m,
//! time in s. Every evaluation checks its result: a non-finite h or derivative, or a
//! negative h, is a [`ConductanceError`] that names the model and the point.

mod lua;
mod plugin;

use std::fmt;

pub use lua::{FD_FLOOR_GAP, FD_FLOOR_PRESSURE, FD_FLOOR_TEMPERATURE, LuaConductance};
pub use plugin::{PluginConductance, PluginLoadError};

/// The Stefan–Boltzmann constant σ in W/(m²·K⁴), CODATA 2018 (exact in the 2019 SI).
pub const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;

/// MOOSE `GapConductance` default for `min_gap` (m).
pub const DEFAULT_MIN_GAP: f64 = 1e-6;
/// MOOSE `GapConductance` default for `max_gap` (m).
pub const DEFAULT_MAX_GAP: f64 = 1e6;

/// The state at one contact point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointState {
    /// Normal gap (m); > 0 open.
    pub gap: f64,
    /// Contact pressure (Pa); > 0 in compression.
    pub pressure: f64,
    /// Temperature on side A (K).
    pub temp_a: f64,
    /// Temperature on side B at the projection (K).
    pub temp_b: f64,
    /// Position of the point (m).
    pub x: [f64; 3],
    /// Time (s).
    pub time: f64,
}

impl PointState {
    /// Mean temperature T̄ = (T_A + T_B)/2, the argument of temperature-dependent
    /// properties.
    pub fn mean_temperature(&self) -> f64 {
        0.5 * (self.temp_a + self.temp_b)
    }
}

impl fmt::Display for PointState {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "gap = {:e}, pressure = {:e}, T_A = {}, T_B = {}, x = ({}, {}, {}), t = {}",
            self.gap,
            self.pressure,
            self.temp_a,
            self.temp_b,
            self.x[0],
            self.x[1],
            self.x[2],
            self.time
        )
    }
}

/// h and its partial derivatives at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Conductance {
    pub h: f64,
    pub dh_dgap: f64,
    pub dh_dpressure: f64,
    pub dh_dtemp_a: f64,
    pub dh_dtemp_b: f64,
}

impl std::ops::Add for Conductance {
    type Output = Conductance;
    fn add(self, o: Conductance) -> Conductance {
        Conductance {
            h: self.h + o.h,
            dh_dgap: self.dh_dgap + o.dh_dgap,
            dh_dpressure: self.dh_dpressure + o.dh_dpressure,
            dh_dtemp_a: self.dh_dtemp_a + o.dh_dtemp_a,
            dh_dtemp_b: self.dh_dtemp_b + o.dh_dtemp_b,
        }
    }
}

/// Why a model could not be built or evaluated. Evaluation errors name the model and
/// the point.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConductanceError {
    #[error("conductance model `{model}`: {message}")]
    Parameter { model: String, message: String },
    #[error("conductance model `{model}` at ({state}): {what} is {value}, not a finite number")]
    NotFinite {
        model: String,
        state: PointState,
        what: &'static str,
        value: f64,
    },
    #[error("conductance model `{model}` at ({state}): h = {value} is negative")]
    Negative {
        model: String,
        state: PointState,
        value: f64,
    },
    #[error("conductance model `{model}` at ({state}): {message}")]
    Evaluation {
        model: String,
        state: PointState,
        message: String,
    },
    /// The model asks for a smaller time step (a plugin's `SEAM_STATUS_CUTBACK`): the
    /// step is retried, it is not an error of the run.
    #[error("conductance model `{model}` at ({state}): {message}")]
    Cutback {
        model: String,
        state: PointState,
        /// The suggested new/old step in (0, 1), or 0: the host decides.
        factor: f64,
        message: String,
    },
}

impl ConductanceError {
    /// Whether the model asks for a smaller step rather than failing.
    pub fn is_cutback(&self) -> bool {
        matches!(self, ConductanceError::Cutback { .. })
    }
}

/// A conductance coefficient h(g, p, T_A, T_B, x, t) ≥ 0 with its exact (or, for user
/// scripts, finite-difference) partial derivatives.
///
/// Implementations are not required to be `Send`: the Lua model holds a Lua state,
/// which stays on the thread that made it. Build one model per thread when
/// evaluating in parallel (the built-in models are `Send + Sync`).
pub trait ConductanceModel {
    /// A short label for messages, e.g. `gas_gap` or `lua \`100 + gap\` (deck.i:7)`.
    fn name(&self) -> String;

    /// h and its derivatives at `state`; an error if h is negative or anything is not
    /// finite.
    fn evaluate(&self, state: &PointState) -> Result<Conductance, ConductanceError>;

    /// h alone (residual-only passes, line searches), checked like
    /// [`ConductanceModel::evaluate`]. Models whose derivatives cost extra calls (Lua)
    /// override it.
    fn value(&self, state: &PointState) -> Result<f64, ConductanceError> {
        self.evaluate(state).map(|c| c.h)
    }

    /// Whether h may change with the temperatures. A model that says no keeps the
    /// heat problem linear in T (one Newton step, a symmetric factorisation reused
    /// while the matrix stays the same), so the default is the safe yes.
    fn depends_on_temperature(&self) -> bool {
        true
    }

    /// Whether h may change with the time alone (`PointState::time`). One that says no
    /// is not evaluated again at the same field (`Embedding::evaluate`): default yes.
    fn depends_on_time(&self) -> bool {
        true
    }

    /// The mechanisms this model adds up, when it is a [`Sum`] (for reports that split
    /// the heat by mechanism); empty for a single mechanism.
    fn mechanisms(&self) -> &[Box<dyn ConductanceModel>] {
        &[]
    }

    /// Whether h may change with the voltages of the two sides (an electrical contact
    /// conductance of `Contact Gap Voltage`): only a Lua model that names them does.
    fn depends_on_voltage(&self) -> bool {
        false
    }

    /// h and its derivatives at `state` with the voltages `volts` = [V_A, V_B] of an
    /// electrical contact, and [dh/dV_A, dh/dV_B]. A model that does not see voltages
    /// ignores them.
    fn evaluate_with_voltage(
        &self,
        state: &PointState,
        volts: [f64; 2],
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        let _ = volts;
        Ok((self.evaluate(state)?, [0.0; 2]))
    }
}

/// Which temperature a conductance sees at a point (`Contact Gap Temperature`), or which
/// voltage (`Contact Gap Voltage`, [`SeenTemperature::wrap_voltage`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum SeenTemperature {
    /// Both sides' temperatures, each model using them as it defines (most take the
    /// mean; radiation takes both).
    #[default]
    Both,
    /// Side A's temperature, as both T_A and T_B.
    SideA,
    /// Side B's temperature (at the projection), as both T_A and T_B.
    SideB,
    /// The mean (T_A + T_B)/2, as both T_A and T_B.
    Mean,
    /// A constant, as both T_A and T_B (the conductance then does not change with the
    /// temperatures).
    Constant(f64),
}

impl SeenTemperature {
    /// `model` seeing this temperature (itself for [`SeenTemperature::Both`]).
    pub fn wrap(self, model: Box<dyn ConductanceModel>) -> Box<dyn ConductanceModel> {
        match self {
            SeenTemperature::Both => model,
            seen => Box::new(Seeing { inner: model, seen }),
        }
    }

    /// `model` seeing this voltage on both sides (itself for [`SeenTemperature::Both`]).
    pub fn wrap_voltage(self, model: Box<dyn ConductanceModel>) -> Box<dyn ConductanceModel> {
        match self {
            SeenTemperature::Both => model,
            seen => Box::new(SeeingVoltage { inner: model, seen }),
        }
    }

    /// The temperature seen and its derivatives with respect to T_A and T_B.
    fn of(self, s: &PointState) -> (f64, f64, f64) {
        self.of_pair(s.temp_a, s.temp_b)
    }

    /// The value seen of the sides' `a` and `b`, and its derivatives with respect to
    /// them.
    fn of_pair(self, a: f64, b: f64) -> (f64, f64, f64) {
        match self {
            SeenTemperature::Both | SeenTemperature::Mean => (0.5 * (a + b), 0.5, 0.5),
            SeenTemperature::SideA => (a, 1.0, 0.0),
            SeenTemperature::SideB => (b, 0.0, 1.0),
            SeenTemperature::Constant(v) => (v, 0.0, 0.0),
        }
    }
}

/// A model evaluated at one voltage V_s on both sides; by the chain rule
/// dh/dV_A = (∂h/∂V_A + ∂h/∂V_B) dV_s/dV_A, and the same for B.
struct SeeingVoltage {
    inner: Box<dyn ConductanceModel>,
    seen: SeenTemperature,
}

impl ConductanceModel for SeeingVoltage {
    fn name(&self) -> String {
        self.inner.name()
    }

    fn evaluate(&self, state: &PointState) -> Result<Conductance, ConductanceError> {
        self.inner.evaluate(state)
    }

    fn value(&self, state: &PointState) -> Result<f64, ConductanceError> {
        self.inner.value(state)
    }

    fn depends_on_temperature(&self) -> bool {
        self.inner.depends_on_temperature()
    }

    fn depends_on_time(&self) -> bool {
        self.inner.depends_on_time()
    }

    fn depends_on_voltage(&self) -> bool {
        self.inner.depends_on_voltage()
    }

    fn evaluate_with_voltage(
        &self,
        state: &PointState,
        [va, vb]: [f64; 2],
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        let (v, da, db) = self.seen.of_pair(va, vb);
        let (c, [dva, dvb]) = self.inner.evaluate_with_voltage(state, [v, v])?;
        let d = dva + dvb;
        Ok((c, [d * da, d * db]))
    }
}

/// A model evaluated at one temperature T_s on both sides; by the chain rule
/// dh/dT_A = (∂h/∂T_A + ∂h/∂T_B) dT_s/dT_A, and the same for B.
struct Seeing {
    inner: Box<dyn ConductanceModel>,
    seen: SeenTemperature,
}

impl Seeing {
    fn state(&self, s: &PointState) -> (PointState, f64, f64) {
        let (t, da, db) = self.seen.of(s);
        (
            PointState {
                temp_a: t,
                temp_b: t,
                ..*s
            },
            da,
            db,
        )
    }
}

impl ConductanceModel for Seeing {
    fn name(&self) -> String {
        self.inner.name()
    }

    fn evaluate(&self, state: &PointState) -> Result<Conductance, ConductanceError> {
        let (seen, da, db) = self.state(state);
        let c = self.inner.evaluate(&seen)?;
        let d = c.dh_dtemp_a + c.dh_dtemp_b;
        Ok(Conductance {
            dh_dtemp_a: d * da,
            dh_dtemp_b: d * db,
            ..c
        })
    }

    fn value(&self, state: &PointState) -> Result<f64, ConductanceError> {
        self.inner.value(&self.state(state).0)
    }

    fn depends_on_temperature(&self) -> bool {
        !matches!(self.seen, SeenTemperature::Constant(_)) && self.inner.depends_on_temperature()
    }

    fn depends_on_time(&self) -> bool {
        self.inner.depends_on_time()
    }

    fn depends_on_voltage(&self) -> bool {
        self.inner.depends_on_voltage()
    }

    fn evaluate_with_voltage(
        &self,
        state: &PointState,
        volts: [f64; 2],
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        let (seen, da, db) = self.state(state);
        let (c, dv) = self.inner.evaluate_with_voltage(&seen, volts)?;
        let d = c.dh_dtemp_a + c.dh_dtemp_b;
        let c = Conductance {
            dh_dtemp_a: d * da,
            dh_dtemp_b: d * db,
            ..c
        };
        Ok((c, dv))
    }
}

/// The result check every model applies: finite values, h ≥ 0.
pub(crate) fn check(
    model: &dyn ConductanceModel,
    state: &PointState,
    c: Conductance,
) -> Result<Conductance, ConductanceError> {
    for (what, value) in [
        ("h", c.h),
        ("dh/dgap", c.dh_dgap),
        ("dh/dpressure", c.dh_dpressure),
        ("dh/dT_A", c.dh_dtemp_a),
        ("dh/dT_B", c.dh_dtemp_b),
    ] {
        if !value.is_finite() {
            return Err(ConductanceError::NotFinite {
                model: model.name(),
                state: *state,
                what,
                value,
            });
        }
    }
    if c.h < 0.0 {
        return Err(ConductanceError::Negative {
            model: model.name(),
            state: *state,
            value: c.h,
        });
    }
    Ok(c)
}

fn parameter(model: &str, message: impl Into<String>) -> ConductanceError {
    ConductanceError::Parameter {
        model: model.into(),
        message: message.into(),
    }
}

fn require(
    model: &str,
    name: &str,
    value: f64,
    ok: bool,
    rule: &str,
) -> Result<(), ConductanceError> {
    if value.is_finite() && ok {
        Ok(())
    } else {
        Err(parameter(model, format!("{name} = {value} must be {rule}")))
    }
}

/// A constant conductance h ≥ 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constant {
    h: f64,
}

impl Constant {
    /// h ≥ 0, or +∞ for a perfect joint (the interface forms take the tied limit).
    pub fn new(h: f64) -> Result<Constant, ConductanceError> {
        if h == f64::INFINITY {
            return Ok(Constant { h });
        }
        require(
            "constant",
            "h",
            h,
            h >= 0.0,
            "≥ 0 (or inf for a perfect joint)",
        )?;
        Ok(Constant { h })
    }
}

impl ConductanceModel for Constant {
    fn name(&self) -> String {
        "constant".into()
    }
    fn depends_on_temperature(&self) -> bool {
        false
    }
    fn depends_on_time(&self) -> bool {
        false
    }
    fn evaluate(&self, _state: &PointState) -> Result<Conductance, ConductanceError> {
        // h was checked (finite, ≥ 0) at construction.
        Ok(Conductance {
            h: self.h,
            ..Conductance::default()
        })
    }
}

/// How the gas-gap model treats gaps below `min_gap` (MOOSE `min_gap_order`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MinGapOrder {
    /// 1/g is frozen at 1/g_min: h is C⁰ at g_min and flat below (dh/dg = 0).
    Zero,
    /// First-order Taylor extension 1/g_min − (g − g_min)/g_min²: h is C¹ at g_min.
    One,
}

/// Conduction through the gas in the gap: h = k_gas(T̄) · A(g), with
/// k_gas = k0 (1 + β (T̄ − T0)), T̄ = (T_A + T_B)/2, and the inverse length
/// A(g) = 1/min(max(g, g_min), g_max) (MOOSE `GapConductance`, `gap_geometry_type =
/// PLATE`), or below g_min the first-order Taylor extension of 1/g when
/// [`MinGapOrder::One`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GasGap {
    k0: f64,
    beta: f64,
    t0: f64,
    min_gap: f64,
    max_gap: f64,
    order: MinGapOrder,
}

impl GasGap {
    /// A gas of constant conductivity `k` (W/(m·K)) with the MOOSE gap limits.
    pub fn new(k: f64) -> Result<GasGap, ConductanceError> {
        GasGap::with(
            k,
            0.0,
            0.0,
            DEFAULT_MIN_GAP,
            DEFAULT_MAX_GAP,
            MinGapOrder::Zero,
        )
    }

    /// All parameters: k0 ≥ 0, β finite (1/K), T0 finite (K), 0 < g_min < g_max.
    pub fn with(
        k0: f64,
        beta: f64,
        t0: f64,
        min_gap: f64,
        max_gap: f64,
        order: MinGapOrder,
    ) -> Result<GasGap, ConductanceError> {
        let m = "gas_gap";
        require(m, "k", k0, k0 >= 0.0, "finite and ≥ 0")?;
        require(m, "beta", beta, true, "finite")?;
        require(m, "t0", t0, true, "finite")?;
        require(m, "min_gap", min_gap, min_gap > 0.0, "finite and > 0")?;
        require(
            m,
            "max_gap",
            max_gap,
            max_gap > min_gap,
            "finite and > min_gap",
        )?;
        Ok(GasGap {
            k0,
            beta,
            t0,
            min_gap,
            max_gap,
            order,
        })
    }

    /// A(g) and dA/dg.
    fn inverse_length(&self, g: f64) -> (f64, f64) {
        let gm = self.min_gap;
        if g > self.max_gap {
            (1.0 / self.max_gap, 0.0)
        } else if g >= gm {
            (1.0 / g, -1.0 / (g * g))
        } else {
            match self.order {
                MinGapOrder::Zero => (1.0 / gm, 0.0),
                MinGapOrder::One => ((2.0 * gm - g) / (gm * gm), -1.0 / (gm * gm)),
            }
        }
    }
}

impl ConductanceModel for GasGap {
    fn name(&self) -> String {
        "gas_gap".into()
    }
    fn depends_on_temperature(&self) -> bool {
        self.beta != 0.0
    }
    fn depends_on_time(&self) -> bool {
        false
    }
    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        let (a, da) = self.inverse_length(s.gap);
        let k = self.k0 * (1.0 + self.beta * (s.mean_temperature() - self.t0));
        let dk_dt = 0.5 * self.k0 * self.beta;
        check(
            self,
            s,
            Conductance {
                h: k * a,
                dh_dgap: k * da,
                dh_dpressure: 0.0,
                dh_dtemp_a: dk_dt * a,
                dh_dtemp_b: dk_dt * a,
            },
        )
    }
}

/// Radiation across the gap between two grey parallel plates:
/// h = σ (T_A² + T_B²)(T_A + T_B) / (1/ε_A + 1/ε_B − 1), the linearisation
/// σ (T_A⁴ − T_B⁴) = h (T_A − T_B).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Radiation {
    /// σ / (1/ε_A + 1/ε_B − 1).
    factor: f64,
}

impl Radiation {
    /// Emissivities in (0, 1].
    pub fn new(emissivity_a: f64, emissivity_b: f64) -> Result<Radiation, ConductanceError> {
        for (name, e) in [
            ("emissivity_a", emissivity_a),
            ("emissivity_b", emissivity_b),
        ] {
            require("radiation", name, e, e > 0.0 && e <= 1.0, "in (0, 1]")?;
        }
        Ok(Radiation {
            factor: STEFAN_BOLTZMANN / (1.0 / emissivity_a + 1.0 / emissivity_b - 1.0),
        })
    }
}

impl ConductanceModel for Radiation {
    fn name(&self) -> String {
        "radiation".into()
    }
    fn depends_on_time(&self) -> bool {
        false
    }
    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        let (a, b, f) = (s.temp_a, s.temp_b, self.factor);
        // ∂/∂T_A of (T_A² + T_B²)(T_A + T_B) = 3T_A² + 2T_A T_B + T_B², symmetric for T_B.
        check(
            self,
            s,
            Conductance {
                h: f * (a * a + b * b) * (a + b),
                dh_dgap: 0.0,
                dh_dpressure: 0.0,
                dh_dtemp_a: f * (3.0 * a * a + 2.0 * a * b + b * b),
                dh_dtemp_b: f * (a * a + 2.0 * a * b + 3.0 * b * b),
            },
        )
    }
}

/// Cooper–Mikic–Yovanovich plastic constriction conductance:
/// h_c = 1.25 k_s (m/σ_s) (p/H_c)^0.95, with k_s = 2 k_A k_B/(k_A + k_B) the harmonic
/// mean of the solids' conductivities, m the mean asperity slope, σ_s the RMS
/// roughness (m) and H_c the microhardness (Pa).
///
/// For p ≤ 0 (no contact) h_c = 0 with derivative 0. h_c is C⁰ at p = 0: dh/dp =
/// 0.95 h_c/p grows like p^−0.05 as p → 0⁺ (finite for every p > 0, unbounded in the
/// limit), and the one-sided value 0 is used at and below p = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cmy {
    /// 1.25 k_s m / σ_s.
    coefficient: f64,
    hardness: f64,
}

/// The CMY pressure exponent.
const CMY_EXPONENT: f64 = 0.95;

impl Cmy {
    pub fn new(
        k_a: f64,
        k_b: f64,
        slope: f64,
        roughness: f64,
        hardness: f64,
    ) -> Result<Cmy, ConductanceError> {
        let m = "cmy";
        require(m, "k_a", k_a, k_a > 0.0, "finite and > 0")?;
        require(m, "k_b", k_b, k_b > 0.0, "finite and > 0")?;
        require(m, "slope", slope, slope > 0.0, "finite and > 0")?;
        require(m, "roughness", roughness, roughness > 0.0, "finite and > 0")?;
        require(m, "hardness", hardness, hardness > 0.0, "finite and > 0")?;
        let k_s = 2.0 * k_a * k_b / (k_a + k_b);
        Ok(Cmy {
            coefficient: 1.25 * k_s * slope / roughness,
            hardness,
        })
    }
}

impl ConductanceModel for Cmy {
    fn name(&self) -> String {
        "cmy".into()
    }
    fn depends_on_temperature(&self) -> bool {
        false
    }
    fn depends_on_time(&self) -> bool {
        false
    }
    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        let p = s.pressure;
        let c = if p > 0.0 {
            let h = self.coefficient * (p / self.hardness).powf(CMY_EXPONENT);
            Conductance {
                h,
                dh_dpressure: CMY_EXPONENT * h / p,
                ..Conductance::default()
            }
        } else {
            Conductance::default()
        };
        check(self, s, c)
    }
}

/// The variable a [`Table`] is tabulated in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TableVariable {
    Gap,
    Pressure,
    /// The mean temperature T̄ = (T_A + T_B)/2.
    Temperature,
}

impl TableVariable {
    fn as_str(self) -> &'static str {
        match self {
            TableVariable::Gap => "gap",
            TableVariable::Pressure => "pressure",
            TableVariable::Temperature => "temperature",
        }
    }
}

/// Piecewise-linear h(v) through (x_i, y_i), v one of gap, pressure or T̄.
///
/// Outside [x_0, x_n] h stays at the end value (flat extension, dh/dv = 0). Unlike
/// Abaqus `*GAP CONDUCTANCE`, which drops h to zero past the last gap point, seam
/// never jumps: a jump to zero would make h discontinuous in the gap. At a breakpoint
/// the derivative is the right-hand slope (0 at the last point).
#[derive(Clone, Debug, PartialEq)]
pub struct Table {
    variable: TableVariable,
    xs: Vec<f64>,
    ys: Vec<f64>,
}

impl Table {
    /// At least one point; abscissae finite and strictly increasing; ordinates finite
    /// and ≥ 0.
    pub fn new(variable: TableVariable, points: &[(f64, f64)]) -> Result<Table, ConductanceError> {
        let m = "table";
        if points.is_empty() {
            return Err(parameter(m, "the table has no points"));
        }
        for (i, &(x, y)) in points.iter().enumerate() {
            require(m, &format!("x[{i}]"), x, true, "finite")?;
            require(m, &format!("h[{i}]"), y, y >= 0.0, "finite and ≥ 0")?;
        }
        if let Some(i) = points.windows(2).position(|w| w[1].0 <= w[0].0) {
            return Err(parameter(
                m,
                format!(
                    "{} values must increase strictly, but x[{}] = {} follows x[{}] = {}",
                    variable.as_str(),
                    i + 1,
                    points[i + 1].0,
                    i,
                    points[i].0
                ),
            ));
        }
        Ok(Table {
            variable,
            xs: points.iter().map(|p| p.0).collect(),
            ys: points.iter().map(|p| p.1).collect(),
        })
    }

    /// h(v) and dh/dv.
    pub fn lookup(&self, v: f64) -> (f64, f64) {
        // k = number of abscissae ≤ v: segment k−1 holds v with the right-hand rule.
        let k = self.xs.partition_point(|&x| x <= v);
        let n = self.xs.len();
        if k == 0 {
            (self.ys[0], 0.0)
        } else if k == n {
            (self.ys[n - 1], 0.0)
        } else {
            let (x0, x1, y0, y1) = (self.xs[k - 1], self.xs[k], self.ys[k - 1], self.ys[k]);
            let slope = (y1 - y0) / (x1 - x0);
            (y0 + slope * (v - x0), slope)
        }
    }
}

impl ConductanceModel for Table {
    fn name(&self) -> String {
        format!("table of {}", self.variable.as_str())
    }
    fn depends_on_temperature(&self) -> bool {
        self.variable == TableVariable::Temperature
    }
    fn depends_on_time(&self) -> bool {
        false
    }
    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        let mut c = Conductance::default();
        match self.variable {
            TableVariable::Gap => (c.h, c.dh_dgap) = self.lookup(s.gap),
            TableVariable::Pressure => (c.h, c.dh_dpressure) = self.lookup(s.pressure),
            TableVariable::Temperature => {
                let (h, d) = self.lookup(s.mean_temperature());
                (c.h, c.dh_dtemp_a, c.dh_dtemp_b) = (h, 0.5 * d, 0.5 * d);
            }
        }
        check(self, s, c)
    }
}

/// Several mechanisms in parallel (e.g. constriction + gas + radiation): values and
/// derivatives add.
pub struct Sum {
    parts: Vec<Box<dyn ConductanceModel>>,
}

impl Sum {
    pub fn new(parts: Vec<Box<dyn ConductanceModel>>) -> Sum {
        Sum { parts }
    }

    pub fn parts(&self) -> &[Box<dyn ConductanceModel>] {
        &self.parts
    }
}

impl ConductanceModel for Sum {
    fn name(&self) -> String {
        let names: Vec<String> = self.parts.iter().map(|p| p.name()).collect();
        format!("sum of {}", names.join(" + "))
    }
    fn depends_on_temperature(&self) -> bool {
        self.parts.iter().any(|p| p.depends_on_temperature())
    }
    fn depends_on_time(&self) -> bool {
        self.parts.iter().any(|p| p.depends_on_time())
    }
    fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
        let mut total = Conductance::default();
        for p in &self.parts {
            total = total + p.evaluate(s)?;
        }
        check(self, s, total)
    }
    fn mechanisms(&self) -> &[Box<dyn ConductanceModel>] {
        &self.parts
    }
    fn depends_on_voltage(&self) -> bool {
        self.parts.iter().any(|p| p.depends_on_voltage())
    }
    fn evaluate_with_voltage(
        &self,
        s: &PointState,
        volts: [f64; 2],
    ) -> Result<(Conductance, [f64; 2]), ConductanceError> {
        let (mut total, mut dv) = (Conductance::default(), [0.0; 2]);
        for p in &self.parts {
            let (c, d) = p.evaluate_with_voltage(s, volts)?;
            total = total + c;
            dv = [dv[0] + d[0], dv[1] + d[1]];
        }
        Ok((check(self, s, total)?, dv))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// h = T_A² + 3 T_B: depends on each side differently.
    struct Lopsided;

    impl ConductanceModel for Lopsided {
        fn name(&self) -> String {
            "lopsided".into()
        }
        fn evaluate(&self, s: &PointState) -> Result<Conductance, ConductanceError> {
            Ok(Conductance {
                h: s.temp_a * s.temp_a + 3.0 * s.temp_b,
                dh_dtemp_a: 2.0 * s.temp_a,
                dh_dtemp_b: 3.0,
                ..Conductance::default()
            })
        }
    }

    #[test]
    fn seen_temperature_picks_the_side_and_chains_the_derivatives() {
        let s = state(0.0, 0.0, 10.0, 20.0);
        let cases = [
            (SeenTemperature::Both, 10.0 * 10.0 + 60.0),
            (SeenTemperature::SideA, 100.0 + 30.0),
            (SeenTemperature::SideB, 400.0 + 60.0),
            (SeenTemperature::Mean, 225.0 + 45.0),
        ];
        for (seen, h) in cases {
            let m = seen.wrap(Box::new(Lopsided));
            let c = m.evaluate(&s).unwrap();
            assert_eq!(c.h, h, "{seen:?}");
            // Central differences of h in T_A and T_B (h is quadratic: exact but for
            // round-off).
            let e = 1e-3;
            let fd = |da: f64, db: f64| {
                let up = m.value(&state(0.0, 0.0, 10.0 + da, 20.0 + db)).unwrap();
                let down = m.value(&state(0.0, 0.0, 10.0 - da, 20.0 - db)).unwrap();
                (up - down) / (2.0 * e)
            };
            assert!((c.dh_dtemp_a - fd(e, 0.0)).abs() < 1e-8, "{seen:?} dT_A");
            assert!((c.dh_dtemp_b - fd(0.0, e)).abs() < 1e-8, "{seen:?} dT_B");
        }
    }

    fn state(gap: f64, pressure: f64, temp_a: f64, temp_b: f64) -> PointState {
        PointState {
            gap,
            pressure,
            temp_a,
            temp_b,
            ..PointState::default()
        }
    }

    #[test]
    fn built_in_models_and_the_plugin_adapter_are_send_and_sync() {
        fn send_sync<T: Send + Sync>() {}
        send_sync::<Constant>();
        send_sync::<GasGap>();
        send_sync::<Radiation>();
        send_sync::<Cmy>();
        send_sync::<Table>();
        send_sync::<PluginConductance>();
    }

    #[test]
    fn a_sum_lists_its_mechanisms_and_a_single_model_none() {
        let sum = Sum::new(vec![
            Box::new(Constant::new(300.0).unwrap()),
            Box::new(Radiation::new(0.5, 0.5).unwrap()),
        ]);
        let names: Vec<String> = sum.mechanisms().iter().map(|m| m.name()).collect();
        assert_eq!(names, ["constant", "radiation"]);
        let s = state(1e-4, 0.0, 300.0, 400.0);
        let parts: f64 = sum.mechanisms().iter().map(|m| m.value(&s).unwrap()).sum();
        assert_eq!(parts, sum.value(&s).unwrap());
        assert!(Constant::new(1.0).unwrap().mechanisms().is_empty());
    }

    #[test]
    fn bad_parameters_are_refused() {
        assert!(Constant::new(-1.0).is_err());
        assert!(Constant::new(f64::NAN).is_err());
        assert!(GasGap::with(0.1, 0.0, 0.0, 1e-3, 1e-4, MinGapOrder::Zero).is_err());
        assert!(Radiation::new(0.0, 0.5).is_err());
        assert!(Radiation::new(1.1, 0.5).is_err());
        assert!(Cmy::new(1.0, 1.0, 0.1, 0.0, 1e9).is_err());
        let e = Table::new(TableVariable::Gap, &[(0.0, 1.0), (0.0, 2.0)]).unwrap_err();
        assert!(e.to_string().contains("increase strictly"), "{e}");
    }

    #[test]
    fn gas_gap_order_one_is_c1_at_min_gap() {
        let g = GasGap::with(0.025, 0.0, 0.0, 1e-6, 1e6, MinGapOrder::One).unwrap();
        let below = g
            .evaluate(&state(1e-6 * (1.0 - 1e-12), 0.0, 300.0, 300.0))
            .unwrap();
        let at = g.evaluate(&state(1e-6, 0.0, 300.0, 300.0)).unwrap();
        assert!((below.h - at.h).abs() <= 1e-9 * at.h);
        assert!((below.dh_dgap - at.dh_dgap).abs() <= 1e-9 * at.dh_dgap.abs());
    }

    #[test]
    fn negative_h_names_the_model_and_the_point() {
        let g = GasGap::with(1.0, -0.01, 300.0, 1e-6, 1e6, MinGapOrder::Zero).unwrap();
        let e = g.evaluate(&state(1e-3, 0.0, 500.0, 500.0)).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("gas_gap") && m.contains("T_A = 500") && m.contains("negative"),
            "{m}"
        );
    }

    /// A model that says it does not depend on T (so the heat problem is solved as
    /// linear) must give the same h, with zero temperature derivatives, at every
    /// temperature; the ones that say they do must show it somewhere in the sweep.
    #[test]
    fn temperature_independence_is_claimed_only_when_true() {
        let models: Vec<Box<dyn ConductanceModel>> = vec![
            Box::new(Constant::new(500.0).unwrap()),
            Box::new(GasGap::new(0.025).unwrap()),
            Box::new(GasGap::with(0.025, 2e-3, 300.0, 1e-6, 1e6, MinGapOrder::Zero).unwrap()),
            Box::new(Radiation::new(0.8, 0.6).unwrap()),
            Box::new(Cmy::new(150.0, 200.0, 0.1, 1e-6, 1e9).unwrap()),
            Box::new(Table::new(TableVariable::Gap, &[(0.0, 1e4), (1e-3, 10.0)]).unwrap()),
            Box::new(
                Table::new(TableVariable::Temperature, &[(300.0, 10.0), (600.0, 90.0)]).unwrap(),
            ),
            Box::new(LuaConductance::expression("test", "1e4 / (1 + gap * 1e3)").unwrap()),
            Box::new(LuaConductance::expression("test", "10 + 0.1 * T_A").unwrap()),
        ];
        for m in &models {
            let at = |ta: f64, tb: f64| m.evaluate(&state(2e-4, 5e5, ta, tb)).unwrap();
            let base = at(300.0, 300.0);
            let sweep = [(350.0, 320.0), (500.0, 450.0), (900.0, 700.0)].map(|(a, b)| at(a, b));
            let varies = sweep
                .iter()
                .any(|c| c.h != base.h || c.dh_dtemp_a != 0.0 || c.dh_dtemp_b != 0.0)
                || base.dh_dtemp_a != 0.0;
            assert_eq!(m.depends_on_temperature(), varies, "{}", m.name());
        }
    }
}
