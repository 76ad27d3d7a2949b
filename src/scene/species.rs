//! `Enforcement for Species`: a definition's species interface on each of its pairings.
//!
//! The species block of a definition (one at most) applies to every pair of the
//! definition, beside its Energy (and Voltage) blocks. Its model is any of the Energy
//! models — `Tied_<field>` and `Tied_Ip_<field>` (Nitsche), `Tied` with `Side B Variable
//! species To species` (mortar multipliers, standard or dual), `Dash`, `Conductance`,
//! `Contact_Resistance` and `Gap_Conductance` — lowered exactly as for Energy, with the
//! concentration c in place of the temperature:
//!
//! - `Partition Coefficient = K` (default 1): the interface condition is `c_A = K c_B`
//!   for ties, and the mass flux from side A to side B is `j = h (c_A − K c_B − Δc)`
//!   through a mass-transfer (`Conductance`, `Gap_Conductance`) interface, whose `Gap
//!   Conductance Coefficient` is the mass-transfer coefficient h (m/s);
//! - `Offset Species = Δc` (mol/m³, default 0): the jump, `c_A = K c_B + Δc` for ties.
//!
//! What the host does with K (the scene only carries it): see [`crate::run`]'s species,
//! which solves for c/S with a solubility scale S per block so that every model here
//! applies unchanged. A coefficient model that depends on the temperature (tables or
//! Lua of T, plugins) sees the temperature field at the point, as at a thermal contact.

use std::path::Path;

use crate::deck::spec::{ContactDefinition, Enforcement, EnforcementModel};
use crate::diag::{Diagnostic, Diagnostics, Loc, SourceMap};
use crate::enforce::conductance::ConductanceModel;
use crate::enforce::model::ModelChoice;
use crate::search::scene::Pairing;

use super::enforcement::resolve_for;

/// The equation of a species interface.
pub const SPECIES_EQUATION: &str = "species";

/// The code of a species enforcement that cannot be solved.
const CODE: &str = "E0432";

/// A pairing's interface on a field other than the temperature by an Energy model: a
/// species interface, or a voltage tie (`Enforcement for Voltage = Tied_Voltage`, …, see
/// [`super::electric`]).
pub struct FieldEnforced {
    pub pairing: Pairing,
    /// The model, lowered as an Energy block's is; its `offset` is the jump of the field
    /// (Δc in mol/m³, ΔV in V).
    pub choice: ModelChoice,
    /// The interaction's penalty scale, 1 by default.
    pub penalty_scale: f64,
    /// The mass-transfer coefficient h (m/s) of a `Conductance`/`Gap_Conductance` model.
    pub model: Option<Box<dyn ConductanceModel>>,
    /// The partition coefficient K: `c_A = K c_B` (1 for a voltage).
    pub partition: f64,
    /// Index of the contact definition in the deck.
    pub definition: usize,
    /// The enforcement block, for messages.
    pub at: Loc,
    /// What searching it again takes, when the surfaces move (as an Energy entry's).
    pub again: Option<super::SearchAgain>,
}

/// The species block of `def`, if it has one; two, or one that claims another equation
/// too (its coefficient would be a heat-transfer and a mass-transfer coefficient at
/// once), are an error.
pub(super) fn species_block(def: &ContactDefinition) -> Result<Option<&Enforcement>, Diagnostic> {
    let claims: Vec<&Enforcement> = def
        .enforcements
        .iter()
        .filter(|e| e.models.iter().any(|m| m.equation == SPECIES_EQUATION))
        .collect();
    match claims.as_slice() {
        [] => Ok(None),
        [one] if one.models.iter().any(|m| m.equation != SPECIES_EQUATION) => Err(
            Diagnostic::error(
                CODE,
                "this enforcement block claims Species and another equation: its `Gap Conductance Coefficient` would be both a heat-transfer (W/m²K) and a mass-transfer (m/s) coefficient",
            )
            .at(Some(one.at.clone()))
            .help("put `Enforcement for Species = …` and its lines in a `begin Enforcement` block of its own"),
        ),
        [one] => Ok(Some(one)),
        [_, second, ..] => Err(Diagnostic::error(
            CODE,
            "two enforcement blocks of this definition claim Species",
        )
        .at(Some(second.at.clone()))
        .help("give the definition one `Enforcement for Species` block")),
    }
}

/// The species interface of `pairing` under the species block `enf` of definition `d`
/// (the interaction's penalty scale `penalty_scale`), or `None` with the reasons in
/// `diags`.
pub(super) fn species(
    enf: &Enforcement,
    d: usize,
    pairing: &Pairing,
    penalty_scale: f64,
    deck_dir: &Path,
    sources: &SourceMap,
    diags: &mut Diagnostics,
) -> Option<FieldEnforced> {
    let pair = (pairing.side_a.as_str(), pairing.side_b.as_str());
    let (choice, model) = species_model(enf, deck_dir, sources, pair, diags)?;
    Some(FieldEnforced {
        pairing: pairing.clone(),
        choice,
        penalty_scale,
        model,
        partition: enf.partition_coefficient.unwrap_or(1.0),
        definition: d,
        at: enf.at.clone(),
        again: None,
    })
}

/// The model of the species block `enf`, lowered as an Energy block's is (the same
/// models and checks), with its mass-transfer coefficient model; `None` with the
/// reasons in `diags`.
pub(super) fn species_model(
    enf: &Enforcement,
    deck_dir: &Path,
    sources: &SourceMap,
    pair: (&str, &str),
    diags: &mut Diagnostics,
) -> Option<(ModelChoice, Option<Box<dyn ConductanceModel>>)> {
    let field = FieldBlock {
        equation: SPECIES_EQUATION,
        offset: enf.offset_species,
        code: CODE,
        coefficient: "mass-transfer coefficient",
        tie_help: "write `Side B Variable species To species` (mortar multipliers), or leave the line out for a Nitsche tie",
    };
    field_model(enf, &field, deck_dir, sources, pair, diags)
}

/// What lowering a block of a field other than the temperature needs to know.
pub(super) struct FieldBlock {
    /// The equation its `Enforcement for` names.
    pub equation: &'static str,
    /// The jump its `Offset <field>` gives.
    pub offset: Option<f64>,
    /// The code of its refusals.
    pub code: &'static str,
    /// What its `Gap Conductance Coefficient` is, for messages.
    pub coefficient: &'static str,
    /// The help of a `Side B Variable` that maps another field.
    pub tie_help: &'static str,
}

/// The model of the `field` block `enf`, lowered as an Energy block's is (the same
/// models and checks) with the field in place of the temperature, and its coefficient
/// model; `None` with the reasons in `diags`.
pub(super) fn field_model(
    enf: &Enforcement,
    field: &FieldBlock,
    deck_dir: &Path,
    sources: &SourceMap,
    pair: (&str, &str),
    diags: &mut Diagnostics,
) -> Option<(ModelChoice, Option<Box<dyn ConductanceModel>>)> {
    let name = field.equation;
    let line = enf.models.iter().find(|m| m.equation == name)?;
    let refuse = |diags: &mut Diagnostics, at: &Loc, message: String, help: &str| {
        diags.push(
            Diagnostic::error(field.code, message)
                .at(Some(at.clone()))
                .help(help),
        );
    };
    if let Some(map) = &enf.side_b_variable
        && !(map.side_a.eq_ignore_ascii_case(name) && map.side_b.eq_ignore_ascii_case(name))
    {
        refuse(
            diags,
            &enf.at,
            format!(
                "`Side B Variable {} To {}` in a {name} block: a {name} tie joins the {name} field to itself",
                map.side_b, map.side_a
            ),
            field.tie_help,
        );
        return None;
    }
    if let Some(variable) = &enf.contact_pressure_variable {
        refuse(
            diags,
            &enf.at,
            format!("`Contact Pressure Variable = {variable}` in a {name} block is not supported"),
            &format!(
                "give a constant `Contact Pressure = p` for a pressure-dependent {}",
                field.coefficient
            ),
        );
        return None;
    }
    let mut as_energy = enf.clone();
    as_energy.models = vec![EnforcementModel {
        equation: "energy".into(),
        ..line.clone()
    }];
    as_energy.offset_temperature = field.offset;
    let choice = match resolve_for(&as_energy, None) {
        Ok(c) => c,
        Err(ds) => {
            ds.into_iter().for_each(|x| diags.push(x));
            return None;
        }
    };
    let model =
        super::conductance_model(&as_energy, &choice, deck_dir, sources, pair, diags).ok()?;
    if super::electric::refuse_voltage(enf, model.as_deref(), diags) {
        return None;
    }
    Some((choice, model))
}
