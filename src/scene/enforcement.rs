//! From the deck's `begin Enforcement` blocks to the typed [`ModelChoice`] of an
//! interaction.
//!
//! Entry point: [`resolve`]. `Enforcement for Energy = MODEL [args]` names the model:
//!
//! | deck model | form |
//! |---|---|
//! | `Contact_Resistance`, `Conductance` | resistance, `h` from `H = …` or the conductance coefficient |
//! | `Gap_Conductance` | Robin–Nitsche, needs a `Gap Conductance Coefficient = …` line |
//! | `Tied_<field>`, `Nitche_Tied` | weighted symmetric Nitsche |
//! | `Tied_Ip_<field>` | symmetric interior penalty |
//! | `Dash` | mortar-integrated penalty `Dash Penalty Factor × k_eff / h_e` |
//! | `Plugin Library = "lib.so" [Model = m]` | resistance with the conductance the plugin returns |
//! | `Tied` with `Side B Variable b To a` | Lagrange multipliers on side A, mortar-integrated; `Tied Multipliers = Dual` condenses them (SPD) |
//!
//! `Offset Temperature = ΔT` prescribes the jump; `Integer Data`/`Real Data` are kept for
//! plugin models.

use crate::deck::spec::{Enforcement, EnforcementModel, GapTemperature};
use crate::diag::{Diagnostic, did_you_mean};
use crate::enforce::conductance::SeenTemperature;
use crate::enforce::interface::Form;
use crate::enforce::model::{ConductanceLaw, ModelChoice};

const MODELS: [&str; 7] = [
    "contact_resistance",
    "conductance",
    "gap_conductance",
    "tied_temperature",
    "tied_ip_temperature",
    "nitche_tied",
    "dash",
];

/// The energy model of an enforcement block, or the diagnostics that say why not, for a
/// problem whose only field is `temperature`.
pub fn resolve(e: &Enforcement) -> Result<ModelChoice, Vec<Diagnostic>> {
    resolve_with_fields(e, &["temperature"])
}

/// As [`resolve`], for a problem with the given fields (`Side B Variable` must name
/// two of them).
pub fn resolve_with_fields(
    e: &Enforcement,
    fields: &[&str],
) -> Result<ModelChoice, Vec<Diagnostic>> {
    resolve_for(e, Some(fields))
}

/// As [`resolve_with_fields`]; with `fields` `None` (a deck checked without its problem
/// file) the names in `Side B Variable` are not checked.
pub fn resolve_for(
    e: &Enforcement,
    fields: Option<&[&str]>,
) -> Result<ModelChoice, Vec<Diagnostic>> {
    let Some(m) = e.models.iter().find(|m| m.equation == "energy") else {
        let d = Diagnostic::error(
            "E0420",
            "this enforcement block has no `Enforcement for Energy = …` line",
        )
        .at(Some(e.at.clone()))
        .help("add e.g. `Enforcement for Energy = Gap_Conductance`");
        return Err(vec![d]);
    };
    let name = m.model.to_ascii_lowercase();
    let offset = e.offset_temperature.unwrap_or(0.0);
    let base = |form| ModelChoice {
        name: name.clone(),
        form,
        conductance: None,
        offset,
        penalty_factor: None,
        mortar: false,
        dual: false,
        pressure: e.contact_pressure.unwrap_or(0.0),
        quarantine: e.quarantine_faulty_points,
        pressure_variable: e.contact_pressure_variable.clone(),
        toggle: e.use_toggle_block.clone(),
        variables: e
            .side_b_variable
            .as_ref()
            .map(|m| (m.side_a.to_ascii_lowercase(), m.side_b.to_ascii_lowercase())),
    };
    if let (Some(map), Some(known)) = (&e.side_b_variable, fields) {
        let mut ds = Vec::new();
        for (role, field) in [("side B", &map.side_b), ("side A", &map.side_a)] {
            if !known.contains(&field.to_ascii_lowercase().as_str()) {
                let hint = did_you_mean(field, known.iter().copied())
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                ds.push(
                    Diagnostic::error(
                        "E0428",
                        format!("unknown {role} field `{field}` in `Side B Variable`"),
                    )
                    .at(Some(e.at.clone()))
                    .help(format!(
                        "{hint}the fields of this problem are: {}",
                        known.join(", ")
                    )),
                );
            }
        }
        if !ds.is_empty() {
            return Err(ds);
        }
    }
    if e.side_b_variable.is_some() || name == "tied" {
        let dual = m.args.iter().any(|a| {
            (a.key.eq_ignore_ascii_case("multipliers") && a.value.eq_ignore_ascii_case("dual"))
                || (a.key.is_empty() && a.value.eq_ignore_ascii_case("dual"))
        });
        return Ok(ModelChoice {
            mortar: true,
            dual,
            ..base(Form::TiedNitsche)
        });
    }
    match name.as_str() {
        "contact_resistance" | "conductance" => {
            let h = conductance(e, m)?;
            Ok(ModelChoice {
                conductance: Some(h),
                ..base(Form::Conductance)
            })
        }
        "gap_conductance" => {
            let h = conductance(e, m)?;
            Ok(ModelChoice {
                conductance: Some(h),
                ..base(Form::GapConductance)
            })
        }
        "dash" => {
            let f = e.dash_penalty_factor.unwrap_or(1.0);
            Ok(ModelChoice {
                penalty_factor: Some(f),
                ..base(Form::Penalty)
            })
        }
        n if n == "nitche_tied" || (n.starts_with("tied_") && !n.starts_with("tied_ip_")) => {
            Ok(base(Form::TiedNitsche))
        }
        n if n.starts_with("tied_ip_") => Ok(base(Form::TiedInteriorPenalty)),
        "plugin" => Ok(ModelChoice {
            conductance: Some(ConductanceLaw::Plugin),
            ..base(Form::Conductance)
        }),
        other => {
            let hint = did_you_mean(other, MODELS)
                .map(|s| format!("did you mean `{s}`? "))
                .unwrap_or_default();
            Err(vec![
                Diagnostic::error("E0421", format!("unknown enforcement model `{}`", m.model))
                    .at(Some(m.at.clone()))
                    .help(format!(
                        "{hint}the energy models are Contact_Resistance, Conductance, Gap_Conductance, Tied_Temperature, Tied_Ip_Temperature, Dash"
                    )),
            ])
        }
    }
}

/// The conductance: `H = …` on the model line, or the block's `Gap Conductance
/// Coefficient = …` lines (read by [`super::conductance::from_properties`]).
fn conductance(e: &Enforcement, m: &EnforcementModel) -> Result<ConductanceLaw, Vec<Diagnostic>> {
    if let Some(a) = m.args.iter().find(|a| a.key.eq_ignore_ascii_case("h")) {
        return match a.value.parse::<f64>() {
            // +∞ is a perfect joint: the forms take their tied limit.
            Ok(h) if h >= 0.0 => Ok(ConductanceLaw::Constant(h)),
            Ok(h) => Err(vec![
                Diagnostic::error(
                    "E0424",
                    format!("conductance must be ≥ 0 (or inf), found {h}"),
                )
                .at(Some(m.at.clone()))
                .help("a conductance h ≥ 0 (W/m²K); h = 0 means no heat crosses, h = inf a perfect joint"),
            ]),
            Err(_) => Err(vec![
                Diagnostic::error("E0425", format!("`{}` is not a number", a.value))
                    .at(Some(m.at.clone()))
                    .help("give the conductance as a number (W/m²K)"),
            ]),
        };
    }
    if e.properties
        .iter()
        .any(|p| p.property == "gap_conductance_coefficient")
    {
        return Ok(ConductanceLaw::Coefficient);
    }
    Err(vec![
        Diagnostic::error(
            "E0423",
            format!("`{}` needs a conductance and none is given", m.model),
        )
        .at(Some(m.at.clone()))
        .help("add `Gap Conductance Coefficient = Constant H = <value>` (or another model) to the enforcement block"),
    ])
}

/// The voltage the block's electrical contact conductance sees (`Contact Gap Voltage`).
pub fn seen_voltage(e: &Enforcement) -> SeenTemperature {
    match e.contact_gap_voltage {
        None => SeenTemperature::Both,
        Some(GapTemperature::SideA) => SeenTemperature::SideA,
        Some(GapTemperature::SideB) => SeenTemperature::SideB,
        Some(GapTemperature::Mean) => SeenTemperature::Mean,
        Some(GapTemperature::Constant(v)) => SeenTemperature::Constant(v),
    }
}

/// The temperature the block's conductance models see (`Contact Gap Temperature`).
pub fn seen_temperature(e: &Enforcement) -> SeenTemperature {
    match e.contact_gap_temperature {
        None => SeenTemperature::Both,
        Some(GapTemperature::SideA) => SeenTemperature::SideA,
        Some(GapTemperature::SideB) => SeenTemperature::SideB,
        Some(GapTemperature::Mean) => SeenTemperature::Mean,
        Some(GapTemperature::Constant(v)) => SeenTemperature::Constant(v),
    }
}
