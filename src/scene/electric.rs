//! `Enforcement for Voltage`: a definition's electrical contact on each of its pairings.
//!
//! The voltage block of a definition (one at most) applies to every pair of the
//! definition, beside the Energy block. Its model is either
//!
//! - a contact conductance (`Gap_Conductance`, `Conductance`, `Contact_Resistance` or a
//!   `Plugin`) whose `Gap Conductance Coefficient` lines give the electrical contact
//!   conductance h_e (S/m²) — every coefficient model, plugins included, as for Energy:
//!   the temperatures they see are the thermal ones at the point, and a model may see
//!   the voltages too (`Contact Gap Voltage`; a plugin gets (V_A, V_B) as its fields). `Offset Voltage` is the
//!   jump ΔV in `j = h_e (V_A − V_B − ΔV)`, `Joule Heat Fraction Side A` the share of the
//!   contact's Joule heat given to side A (0.5 by default); or
//! - a tie, any tie of the Energy equation with the voltage in place of the
//!   temperature: `Tied_Voltage` and `Tied_Ip_Voltage` (Nitsche), `Tied` with `Side B
//!   Variable voltage To voltage` (mortar multipliers, standard or dual) and `Dash`,
//!   holding `V_A = V_B + ΔV` (`Offset Voltage`). A tie is a perfect electrical joint: it
//!   has no contact resistance and releases no contact Joule heat.

use std::path::Path;

use crate::deck::spec::{ContactDefinition, Enforcement};
use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::enforce::conductance::ConductanceModel;
use crate::enforce::electric::ElectricContact;
use crate::search::scene::Pairing;

use super::enforcement::resolve_for;
use super::species::{FieldBlock, FieldEnforced, field_model};

/// The equation of an electrical contact.
pub const VOLTAGE_EQUATION: &str = "voltage";

/// A pairing's electrical contact.
pub struct ElectricalEnforced {
    pub side_a: String,
    pub side_b: String,
    pub contact: ElectricContact,
    /// The electrical contact conductance h_e (S/m²) as a law of the point's state.
    pub model: Box<dyn ConductanceModel>,
    /// The contact pressure its pressure-dependent models see (Pa).
    pub pressure: f64,
    /// Index of the contact definition in the deck.
    pub definition: usize,
    /// The voltage block, for messages.
    pub at: crate::diag::Loc,
    /// The pairing it was made from.
    pub pairing: Pairing,
    /// What searching it again takes (surfaces that move only).
    pub again: Option<super::SearchAgain>,
}

/// The voltage block of `def`, if it has one; two, or one that claims another equation
/// too, are an error.
pub(super) fn voltage_block(def: &ContactDefinition) -> Result<Option<&Enforcement>, Diagnostic> {
    let claims: Vec<&Enforcement> = def
        .enforcements
        .iter()
        .filter(|e| e.models.iter().any(|m| m.equation == VOLTAGE_EQUATION))
        .collect();
    match claims.as_slice() {
        [] => Ok(None),
        [one] if one.models.iter().any(|m| m.equation != VOLTAGE_EQUATION) => Err(
            Diagnostic::error(
                "E0431",
                "this enforcement block claims Voltage and another equation: its `Gap Conductance Coefficient` would be both the thermal (W/m²K) and the electrical (S/m²) contact conductance",
            )
            .at(Some(one.at.clone()))
            .help("put `Enforcement for Voltage = …` and its coefficient in a `begin Enforcement` block of its own"),
        ),
        [one] => Ok(Some(one)),
        [_, second, ..] => Err(Diagnostic::error(
            "E0431",
            "two enforcement blocks of this definition claim Voltage",
        )
        .at(Some(second.at.clone()))
        .help("give the definition one `Enforcement for Voltage` block")),
    }
}

/// What a voltage block makes of a pairing.
pub enum Electrical {
    /// A contact conductance, with its Joule heat.
    Contact(Box<ElectricalEnforced>),
    /// A tie of the voltage field (through the embedding, as a species interface).
    Tie(Box<FieldEnforced>),
}

/// Whether the voltage block `enf` joins its sides by a contact conductance (else by a
/// tie).
fn is_conductance(enf: &Enforcement) -> bool {
    enf.models
        .iter()
        .find(|m| m.equation == VOLTAGE_EQUATION)
        .is_some_and(|line| {
            matches!(
                line.model.to_ascii_lowercase().as_str(),
                "gap_conductance" | "conductance" | "contact_resistance" | "plugin"
            )
        })
}

/// The lowering of a voltage tie: the Energy equation's, with the voltage.
fn tie_block(enf: &Enforcement) -> FieldBlock {
    FieldBlock {
        equation: VOLTAGE_EQUATION,
        offset: enf.offset_voltage,
        code: "E0431",
        coefficient: "electrical contact conductance",
        tie_help: "write `Side B Variable voltage To voltage` (mortar multipliers), or leave the line out for a Nitsche tie",
    }
}

/// Check the voltage block `enf` alone (the deck check, without pairings).
pub(super) fn check_voltage_block(
    enf: &Enforcement,
    deck_dir: &Path,
    sources: &SourceMap,
    pair: (&str, &str),
    diags: &mut Diagnostics,
) {
    if is_conductance(enf) {
        let _ = voltage_model(enf, deck_dir, sources, pair, diags);
    } else {
        let _ = field_model(enf, &tie_block(enf), deck_dir, sources, pair, diags);
    }
}

/// The electrical contact or voltage tie of `pairing` under the voltage block `enf` of
/// definition `d` (the interaction's penalty scale `penalty_scale`), or `None` with the
/// reasons in `diags`.
pub(super) fn electrical(
    enf: &Enforcement,
    (d, penalty_scale): (usize, f64),
    pairing: &Pairing,
    deck_dir: &Path,
    sources: &SourceMap,
    diags: &mut Diagnostics,
) -> Option<Electrical> {
    let pair = (pairing.side_a.as_str(), pairing.side_b.as_str());
    if !is_conductance(enf) {
        let (choice, model) = field_model(enf, &tie_block(enf), deck_dir, sources, pair, diags)?;
        return Some(Electrical::Tie(Box::new(FieldEnforced {
            pairing: pairing.clone(),
            choice,
            penalty_scale,
            model,
            partition: 1.0,
            definition: d,
            at: enf.at.clone(),
            again: None,
        })));
    }
    let (conductance, pressure) = voltage_model(enf, deck_dir, sources, pair, diags)?;
    let fraction = enf.joule_fraction_side_a.unwrap_or(0.5);
    let contact = match ElectricContact::new(
        &pairing.side_a_geometry,
        &pairing.side_b_geometry,
        &pairing.result.points,
        enf.offset_voltage.unwrap_or(0.0),
        fraction,
    ) {
        Ok(c) => c,
        Err(m) => {
            diags.push(
                Diagnostic::error(
                    "E0431",
                    format!(
                        "electrical contact {} / {}: {m}",
                        pairing.side_a, pairing.side_b
                    ),
                )
                .at(Some(enf.at.clone()))
                .help("side A of an electrical contact is a face surface"),
            );
            return None;
        }
    };
    Some(Electrical::Contact(Box::new(ElectricalEnforced {
        side_a: pairing.side_a.clone(),
        side_b: pairing.side_b.clone(),
        contact,
        model: conductance,
        pressure,
        definition: d,
        at: enf.at.clone(),
        pairing: pairing.clone(),
        again: None,
    })))
}

/// The electrical contact conductance of the voltage block `enf` and its contact
/// pressure, lowered as an Energy block's conductance is (the same models and checks);
/// `None` with the reasons in `diags`.
fn voltage_model(
    enf: &Enforcement,
    deck_dir: &Path,
    sources: &SourceMap,
    pair: (&str, &str),
    diags: &mut Diagnostics,
) -> Option<(Box<dyn ConductanceModel>, f64)> {
    let line = enf.models.iter().find(|m| m.equation == VOLTAGE_EQUATION)?;
    let mut as_energy = enf.clone();
    as_energy.models = vec![crate::deck::spec::EnforcementModel {
        equation: "energy".into(),
        ..line.clone()
    }];
    let choice = match resolve_for(&as_energy, None) {
        Ok(c) => c,
        Err(ds) => {
            ds.into_iter().for_each(|x| diags.push(x));
            return None;
        }
    };
    let Some(model) =
        super::conductance_model(&as_energy, &choice, deck_dir, sources, pair, diags).ok()?
    else {
        diags.push(
            Diagnostic::error(
                "E0431",
                "this `Enforcement for Voltage` block has no `Gap Conductance Coefficient`",
            )
            .at(Some(enf.at.clone()))
            .help("give the electrical contact conductance, e.g. `Gap Conductance Coefficient = Constant H = 1e8` (S/m²)"),
        );
        return None;
    };
    // `Contact Gap Voltage`: the voltage a voltage-dependent conductance sees.
    let model = super::enforcement::seen_voltage(enf).wrap_voltage(model);
    Some((model, choice.pressure))
}

/// Refuse, at a block that is not an electrical contact (Energy, Species, a voltage
/// tie), a `Contact Gap Voltage` line and a coefficient that names the voltages: only an
/// electrical contact conductance sees them. Whether it refused.
pub(super) fn refuse_voltage(
    enf: &Enforcement,
    model: Option<&dyn ConductanceModel>,
    diags: &mut Diagnostics,
) -> bool {
    let help = "voltages are seen by an electrical contact conductance only: give the voltage-dependent coefficient in a `begin Enforcement` block of its own with `Enforcement for Voltage = Gap_Conductance`";
    if enf.contact_gap_voltage.is_some() {
        diags.push(
            Diagnostic::error(
                "E0431",
                "`Contact Gap Voltage` in a block that is not an electrical contact conductance: no model of this block sees a voltage",
            )
            .at(Some(enf.at.clone()))
            .help(help),
        );
        return true;
    }
    if let Some(m) = model.filter(|m| m.depends_on_voltage()) {
        diags.push(
            Diagnostic::error(
                "E0431",
                format!(
                    "the coefficient `{}` names the voltages (`volt_a`, `volt_b`), but this block is not an electrical contact conductance",
                    m.name()
                ),
            )
            .at(Some(enf.at.clone()))
            .help(help),
        );
        return true;
    }
    false
}
