//! What an interaction's enforcement asks for, as typed settings: the interface form,
//! the conductance law and the options of one enforcement ([`ModelChoice`]).
//!
//! The scene, above, fills it from a deck's `begin Enforcement` block (its `enforcement`
//! part lists the deck models and their forms); a host fills it in code.

use super::interface::Form;

/// What one enforcement block asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelChoice {
    /// The model's name, lower case (reported in summaries).
    pub name: String,
    pub form: Form,
    /// The conductance law, for `Conductance`/`GapConductance`; for `Dash`, the penalty
    /// factor as a constant.
    pub conductance: Option<ConductanceLaw>,
    pub offset: f64,
    /// For Dash: the penalty factor multiplying k_eff / h_e.
    pub penalty_factor: Option<f64>,
    /// `Tied` with `Side B Variable`: a Lagrange-multiplier mortar tie (`form` unused).
    pub mortar: bool,
    /// For mortar ties: `Multipliers = Dual` (condensed, SPD) instead of standard.
    pub dual: bool,
    /// `Contact Pressure = p`, seen by pressure-dependent conductance models (0 if none).
    pub pressure: f64,
    /// `Quarantine Faulty Points`.
    pub quarantine: bool,
    /// `Contact Pressure Variable`: the nodal field the pressure comes from.
    pub pressure_variable: Option<String>,
    /// `Use Toggle Block`: the toggle that switches the enforcement on and off.
    pub toggle: Option<String>,
    /// `Side B Variable b To a`: (side-A field a, side-B field b), as written.
    pub variables: Option<(String, String)>,
}

/// Where an enforcement's conductance comes from.
#[derive(Clone, Debug, PartialEq)]
pub enum ConductanceLaw {
    /// `H = …` on the `Enforcement for Energy` line.
    Constant(f64),
    /// The block's `Gap Conductance Coefficient = …` lines, which the scene makes into a
    /// [`ConductanceModel`](super::conductance::ConductanceModel).
    Coefficient,
    /// `Enforcement for Energy = Plugin Library = "…" [Model = …]`: the plugin returns the
    /// conductance, with the block's Integer Data and Real Data.
    Plugin,
}
