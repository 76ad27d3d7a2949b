//! A deck's contact resolved on a mesh: for every contact definition its surfaces,
//! interactions and search, and per pairing the enforcement that applies with its
//! conductance model loaded — the one place where `seam run`, `seam search` and
//! `seam check` turn a typed deck into contact terms.
//!
//! Entry points: [`ContactScene::build`] (with a mesh) and [`check_enforcements`] (the
//! mesh-free part of the same validation, for `seam check` without `--mesh`). Both load
//! what a run loads — Lua conductances compiled in their sandbox, plugins opened and
//! probed — so a deck that passes here does not fail when a run starts.
//!
//! Which enforcement block applies to a pair ([`enforcement_for`]): the one an interaction
//! names with `Enforcement = name`; otherwise the definition's blocks together, one per
//! equation. Two blocks claiming the same equation on one pair, with no interaction
//! naming one, is an error (which one was meant is not written anywhere).
//!
//! The scene is the one consumer of the typed deck spec: its parts lower the deck to
//! the typed settings of the layers below it, which never see a deck —
//! [`interaction`] (which surfaces pair, with the search's
//! [`SearchSettings`](crate::search::SearchSettings)), [`search`] (the searches of a
//! definition and its periodic conditions), [`enforcement`] (an enforcement block's
//! [`ModelChoice`]), [`conductance`] (`Gap Conductance Coefficient` lines to conductance
//! models) and [`plugin`] (a plugin enforcement to a
//! [`PluginSpec`](crate::plugin::PluginSpec)).

pub mod conductance;
pub mod electric;
pub mod enforcement;
pub mod interaction;
pub mod plugin;
pub mod search;
pub mod species;
pub mod surfaces;

use std::path::Path;
use std::time::Instant;

use crate::deck::LoadedDeck;
use crate::deck::spec::{ContactDefinition, Enforcement};
use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::enforce::conductance::{self as models, ConductanceModel};
use crate::enforce::interface::Form;
use crate::enforce::model::{ConductanceLaw, ModelChoice};
use crate::mesh::Mesh;
use crate::search::pairing::{Integration, SearchStats};
use crate::search::scene::{Pairing, SceneSearch, Timing as SearchTiming};
use crate::surface;

use enforcement::{resolve_for, seen_temperature};
use interaction::Interaction;
use species::FieldEnforced;

/// The equation every supported enforcement applies to.
const ENERGY: &str = "energy";

/// One pairing with the enforcement that applies to it.
pub struct Enforced {
    pub pairing: Pairing,
    pub choice: ModelChoice,
    /// The interaction's penalty scale (Abaqus `Scale Penalty`), 1 by default.
    pub penalty_scale: f64,
    /// The conductance model of a `Conductance`/`Gap_Conductance`/plugin enforcement.
    pub model: Option<Box<dyn ConductanceModel>>,
    /// Index of the contact definition in the deck.
    pub definition: usize,
    /// What the definition's contact output holds.
    pub view: ContactView,
    /// What searching this pair again takes (a host that moves nodes):
    /// [`ContactScene::build_for_host`] keeps it, [`ContactScene::build`] does not.
    pub again: Option<SearchAgain>,
}

/// A pairing's surfaces and search options, to search it again after the nodes move.
pub struct SearchAgain {
    pub side_a: surface::ContactSurface,
    pub side_b: surface::ContactSurface,
    pub settings: crate::search::SearchSettings,
    /// `None` for a periodic pair, which keeps its gaps as found.
    pub overclosure: Option<crate::search::Overclosure>,
    pub subdomain: Option<crate::search::pairing::Sphere>,
    /// A periodic pair's map: side A is the image of `side_a` under it.
    pub map: Option<Box<dyn crate::periodic::PeriodicMap>>,
}

/// How to build a scene.
pub struct SceneOptions<'a> {
    pub integration: Integration,
    /// The fields of the problem, which `Side B Variable` must name; `None` when they
    /// are not known (a deck checked without its problem file).
    pub fields: Option<&'a [&'a str]>,
    /// Called as each phase starts (progress displays).
    pub phase: Option<&'a dyn Fn(&str)>,
    /// A definition with no `begin Enforcement` block at all is searched and reported
    /// with one warning instead of an error (a deck written for `seam search`).
    pub search_only: bool,
}

/// Wall-clock seconds of the scene's phases.
#[derive(Clone, Copy, Debug, Default)]
pub struct SceneTiming {
    pub surfaces_s: f64,
    pub search_s: f64,
}

pub use crate::deck::spec::OutputRule;

/// What a definition's contact output holds, from `Visualize Contact` and `Output Rule`:
///
/// | rule | with `Visualize Contact` |
/// |---|---|
/// | `none` | nothing (and a warning: the two lines disagree) |
/// | `summary` (default) | the side-A faces: gap, contact fraction, flux |
/// | `verbose` | and the side-B faces with their own values |
/// | `more verbose` | and every side-A point |
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactView {
    /// `Visualize Contact`.
    pub visualize: bool,
    /// `Output Rule`, `summary` when not given.
    pub rule: OutputRule,
    pub faces: bool,
    pub side_b: bool,
    pub points: bool,
    /// `Visualize Contact` on and `Output Rule = none`.
    pub silenced: bool,
}

impl ContactView {
    fn of(def: &ContactDefinition) -> Self {
        let rule = def.output_rule.unwrap_or(OutputRule::Summary);
        let on = def.visualize_contact && rule != OutputRule::None;
        ContactView {
            visualize: def.visualize_contact,
            rule,
            faces: on,
            side_b: on && matches!(rule, OutputRule::Verbose | OutputRule::MoreVerbose),
            points: on && rule == OutputRule::MoreVerbose,
            silenced: def.visualize_contact && rule == OutputRule::None,
        }
    }
}

impl Default for ContactView {
    fn default() -> Self {
        ContactView::of(&ContactDefinition::default())
    }
}

/// What a host needs of a contact definition beyond its pairings.
#[derive(Clone, Debug)]
pub struct DefinitionNotes {
    /// Where the definition is (its `begin Contact Definition` line).
    pub at: crate::diag::Loc,
    pub view: ContactView,
    /// `Update Search Every n Steps` (or `Search Update Frequency`) when given.
    pub search_every: Option<u32>,
}

/// An enforcement line that refers to `seam run`'s problem file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ProblemFileLine {
    /// `Contact Pressure Variable = name`: a `[[nodal_field]]`.
    ContactPressureVariable,
    /// `Use Toggle Block t`: a `[[toggle]]`.
    UseToggleBlock,
}

/// Every enforcement line of `loaded` that refers to `seam run`'s problem file, at its
/// enforcement block (a host without one refuses them).
pub fn problem_file_lines(loaded: &LoadedDeck) -> Vec<(crate::diag::Loc, ProblemFileLine)> {
    let mut out = Vec::new();
    for enf in loaded
        .deck
        .contact_definitions
        .iter()
        .flat_map(|d| &d.enforcements)
    {
        if enf.contact_pressure_variable.is_some() {
            out.push((enf.at.clone(), ProblemFileLine::ContactPressureVariable));
        }
        if enf.use_toggle_block.is_some() {
            out.push((enf.at.clone(), ProblemFileLine::UseToggleBlock));
        }
    }
    out
}

/// Every pairing of a deck on a mesh, with its enforcement.
#[derive(Default)]
pub struct ContactScene {
    pub entries: Vec<Enforced>,
    /// The electrical contacts of the definitions' `Enforcement for Voltage` blocks.
    pub electrical: Vec<electric::ElectricalEnforced>,
    /// The species interfaces of the definitions' `Enforcement for Species` blocks.
    pub species: Vec<FieldEnforced>,
    /// The voltage ties of the definitions' `Enforcement for Voltage` blocks (a tie model
    /// in place of a contact conductance).
    pub voltage_ties: Vec<FieldEnforced>,
    /// Per contact definition of the deck, in deck order.
    pub definitions: Vec<DefinitionNotes>,
    /// Number of contact surfaces built, over every definition.
    pub surfaces: usize,
    /// Plugin enforcements whose library could not be loaded (their E0500 is in the
    /// diagnostics): side A, side B, why.
    pub plugins_refused: Vec<(String, String, String)>,
    pub timing: SceneTiming,
}

impl ContactScene {
    /// Build the surfaces, interactions and searches of every contact definition of
    /// `loaded` on `mesh` and resolve each pairing's enforcement. Problems go to `diags`;
    /// a pairing whose enforcement fails is left out.
    pub fn build(
        mesh: &Mesh,
        loaded: &LoadedDeck,
        deck_dir: &Path,
        options: &SceneOptions<'_>,
        diags: &mut Diagnostics,
    ) -> ContactScene {
        Self::build_with(mesh, loaded, deck_dir, options, diags, false)
    }

    /// As [`Self::build`], each entry keeping what searching it again takes
    /// ([`Enforced::again`]): the scene of a host that moves its nodes.
    pub fn build_for_host(
        mesh: &Mesh,
        loaded: &LoadedDeck,
        deck_dir: &Path,
        options: &SceneOptions<'_>,
        diags: &mut Diagnostics,
    ) -> ContactScene {
        Self::build_with(mesh, loaded, deck_dir, options, diags, true)
    }

    fn build_with(
        mesh: &Mesh,
        loaded: &LoadedDeck,
        deck_dir: &Path,
        options: &SceneOptions<'_>,
        diags: &mut Diagnostics,
        keep: bool,
    ) -> ContactScene {
        let definitions = loaded
            .deck
            .contact_definitions
            .iter()
            .map(|def| DefinitionNotes {
                at: def.at.clone(),
                view: ContactView::of(def),
                search_every: def.update_search_every_n_steps.or(def
                    .search_options
                    .as_ref()
                    .and_then(|o| o.search_update_frequency)),
            })
            .collect();
        let mut scene = ContactScene {
            definitions,
            ..ContactScene::default()
        };
        for (d, def) in loaded.deck.contact_definitions.iter().enumerate() {
            let Some((list, searched, set, found_maps)) =
                scene.search_one(mesh, loaded, def, deck_dir, options, diags)
            else {
                continue;
            };
            let mut maps: Vec<Option<Box<dyn crate::periodic::PeriodicMap>>> =
                searched.pairings.iter().map(|_| None).collect();
            for (k, map) in found_maps {
                maps[k] = Some(map);
            }
            if options.search_only && def.enforcements.is_empty() {
                diags.push(
                    Diagnostic::warning(
                        "W0426",
                        "this definition has no `begin Enforcement` block: its pairs can be searched, but `seam run` refuses it",
                    )
                    .at(Some(def.at.clone()))
                    .help("add a `begin Enforcement` block with `Enforcement for Energy = …` to run it"),
                );
                continue;
            }
            let voltage = electric::voltage_block(def).unwrap_or_else(|e| {
                diags.push(e);
                None
            });
            let species_block = species::species_block(def).unwrap_or_else(|e| {
                diags.push(e);
                None
            });
            let energy = def
                .enforcements
                .iter()
                .any(|e| e.models.iter().any(|m| m.equation == ENERGY));
            // A voltage or species block that fails says so once, not once per pair.
            let (mut voltage_failed, mut species_failed) = (false, false);
            for (pairing, map) in searched.pairings.into_iter().zip(maps) {
                let interaction = list
                    .iter()
                    .find(|i| i.side_a_name == pairing.side_a && i.side_b_name == pairing.side_b);
                // What searching a species interface, voltage tie or electrical contact
                // again takes (surfaces that move; a periodic pair's map stays with its
                // Energy entry).
                let field_again = || {
                    (keep && !pairing.periodic)
                        .then(|| search_again((&set, def, mesh), &pairing, interaction, None))
                };
                if let Some(v) = voltage.filter(|_| !voltage_failed) {
                    let scale = interaction.map_or(1.0, |i| i.penalty_scale);
                    let sources = &loaded.sources;
                    match electric::electrical(v, (d, scale), &pairing, deck_dir, sources, diags) {
                        Some(electric::Electrical::Contact(e)) => {
                            scene.electrical.push(electric::ElectricalEnforced {
                                again: field_again(),
                                ..*e
                            })
                        }
                        Some(electric::Electrical::Tie(t)) => {
                            scene.voltage_ties.push(FieldEnforced {
                                again: field_again(),
                                ..*t
                            })
                        }
                        None => voltage_failed = true,
                    }
                }
                if let Some(s) = species_block.filter(|_| !species_failed) {
                    let scale = interaction.map_or(1.0, |i| i.penalty_scale);
                    let sources = &loaded.sources;
                    match species::species(s, d, &pairing, scale, deck_dir, sources, diags) {
                        Some(e) => scene.species.push(FieldEnforced {
                            again: field_again(),
                            ..e
                        }),
                        None => species_failed = true,
                    }
                }
                // A definition with a Voltage or Species block and no Energy one joins no
                // temperatures.
                if (voltage.is_some() || species_block.is_some()) && !energy {
                    continue;
                }
                let named = interaction.and_then(|i| i.enforcement.as_deref());
                let pair = (pairing.side_a.as_str(), pairing.side_b.as_str());
                let enf = match enforcement_for(def, named, pair) {
                    Ok(e) => e,
                    Err(e) => {
                        diags.push(e);
                        continue;
                    }
                };
                let choice = match resolve_for(enf, options.fields) {
                    Ok(c) => c,
                    Err(ds) => {
                        ds.into_iter().for_each(|x| diags.push(x));
                        continue;
                    }
                };
                let tied = matches!(
                    choice.form,
                    Form::TiedNitsche | Form::TiedInteriorPenalty | Form::Penalty
                );
                if tied && pairing.result.stats.matched == 0 {
                    diags.push(
                        Diagnostic::error(
                            "E0427",
                            format!(
                                "`{}` ties {} / {}, but the two surfaces do not overlap anywhere",
                                choice.name, pairing.side_a, pairing.side_b
                            ),
                        )
                        .at(Some(enf.at.clone()))
                        .help("check the surfaces of the interaction; `seam search` shows why points did not pair"),
                    );
                    continue;
                }
                if pairing.result.stats.matched == 0 {
                    diags.push(
                        Diagnostic::warning(
                            "W0428",
                            format!(
                                "interaction {} / {} pairs no point, so `{}` carries no heat: {}",
                                pairing.side_a,
                                pairing.side_b,
                                choice.name,
                                if pairing.side_a == pairing.side_b {
                                    "side A and side B are the same surface, which pairs with itself only where it folds back on itself".to_string()
                                } else {
                                    why_nothing_paired(&pairing.result.stats)
                                }
                            ),
                        )
                        .at(Some(enf.at.clone()))
                        .help("check the surfaces and the search options (`Normal Tolerance`, `Normal Check Angle`); `seam search --json` gives each point's status"),
                    );
                }
                let Ok(model) =
                    conductance_model(enf, &choice, deck_dir, &loaded.sources, pair, diags)
                else {
                    if let Some(d) = diags.0.last().filter(|d| d.code == "E0500") {
                        scene.plugins_refused.push((
                            pairing.side_a.clone(),
                            pairing.side_b.clone(),
                            d.message.clone(),
                        ));
                    }
                    continue;
                };
                if electric::refuse_voltage(enf, model.as_deref(), diags) {
                    continue;
                }
                let again =
                    keep.then(|| search_again((&set, def, mesh), &pairing, interaction, map));
                scene.entries.push(Enforced {
                    pairing,
                    choice,
                    penalty_scale: interaction.map_or(1.0, |i| i.penalty_scale),
                    model,
                    definition: d,
                    view: ContactView::of(def),
                    again,
                });
            }
        }
        scene
    }

    /// The contact surfaces of every definition of `loaded` — the scene's first stage
    /// alone — as if the `dead` elements (dense ids) never existed: per definition its
    /// name and its surfaces with their diagnostics.
    pub fn surfaces(
        mesh: &Mesh,
        loaded: &LoadedDeck,
        dead: &std::collections::HashSet<crate::mesh::ElemId>,
    ) -> Vec<(Option<String>, surface::SurfaceSet)> {
        loaded
            .deck
            .contact_definitions
            .iter()
            .map(|def| {
                let set = surfaces::build_with_dead(mesh, def, &loaded.sources, dead);
                (def.name.clone(), set)
            })
            .collect()
    }

    /// The surfaces, interactions and search of every contact definition of `loaded` on
    /// `mesh` — the first stage of [`ContactScene::build`] — without resolving any
    /// enforcement: every pairing is kept, with its definition (what `seam search`
    /// reports). As in `build`, no definition is searched once `diags` holds an error.
    pub fn search(
        mesh: &Mesh,
        loaded: &LoadedDeck,
        deck_dir: &Path,
        options: &SceneOptions<'_>,
        diags: &mut Diagnostics,
    ) -> Vec<SearchedDefinition> {
        let mut scene = ContactScene::default();
        let mut out = Vec::new();
        for (d, def) in loaded.deck.contact_definitions.iter().enumerate() {
            if let Some((_, searched, _, _)) =
                scene.search_one(mesh, loaded, def, deck_dir, options, diags)
            {
                out.push(SearchedDefinition {
                    definition: d,
                    view: ContactView::of(def),
                    pairings: searched.pairings,
                    timing: searched.timing,
                });
            }
        }
        out
    }

    /// One definition's surfaces and interactions, then (unless `diags` holds an error
    /// by then) its search, with their diagnostics moved to `diags` and their times and
    /// surfaces counted in `self`.
    fn search_one(
        &mut self,
        mesh: &Mesh,
        loaded: &LoadedDeck,
        def: &ContactDefinition,
        deck_dir: &Path,
        options: &SceneOptions<'_>,
        diags: &mut Diagnostics,
    ) -> Option<(
        Vec<Interaction>,
        SceneSearch,
        surface::SurfaceSet,
        search::PairingMaps,
    )> {
        let phase = |what: &str| {
            if let Some(f) = options.phase {
                f(what);
            }
        };
        phase("building the contact surfaces");
        let t = Instant::now();
        // On a distributed mesh (`seam run` under mpirun) rank 0 builds them on the whole
        // mesh and each other rank gets its share.
        let set =
            crate::parallel::share_surfaces(mesh, || surfaces::build(mesh, def, &loaded.sources));
        self.timing.surfaces_s += t.elapsed().as_secs_f64();
        self.surfaces += set.surfaces.len();
        diags.extend(set.diagnostics.clone());
        let (list, found) = interaction::resolve(def, &set, mesh.dim, &loaded.sources);
        diags.extend(found);
        // Every rank of a distributed mesh follows rank 0, which checks the whole.
        if crate::parallel::mesh_is_distributed() {
            if crate::parallel::root_verdict(diags.has_errors()) {
                return None;
            }
        } else if diags.has_errors() {
            return None;
        }
        phase("contact search");
        let t = Instant::now();
        let mut maps = Vec::new();
        let mut searched = search::search_definition_with_maps(
            mesh,
            def,
            &set,
            &list,
            deck_dir,
            &loaded.sources,
            options.integration,
            &mut maps,
        );
        self.timing.search_s += t.elapsed().as_secs_f64();
        diags.extend(std::mem::take(&mut searched.diagnostics));
        Some((list, searched, set, maps))
    }
}

/// One contact definition's pairings as its search made them, before any enforcement
/// is resolved ([`ContactScene::search`]).
pub struct SearchedDefinition {
    /// Index of the contact definition in the deck.
    pub definition: usize,
    /// What the definition's contact output holds.
    pub view: ContactView,
    pub pairings: Vec<Pairing>,
    /// The search's own times (bounding-volume hierarchies built, queries).
    pub timing: SearchTiming,
}

/// Why a search paired nothing, from its counts.
pub fn why_nothing_paired(stats: &SearchStats) -> String {
    if stats.side_a_area == 0.0 {
        return "side A is empty (its definition found no face, or every face went to an earlier surface)".into();
    }
    if stats.points == 0 {
        return "no side-B face came within reach of any side-A face (the surfaces are apart: check their names, the normal tolerance and the buffer)".into();
    }
    let mut parts = Vec::new();
    for (n, what) in [
        (stats.unmatched, "found no side-B face within reach"),
        (
            stats.rejected_distance,
            "lay farther from side B along the normal than the normal tolerance",
        ),
        (
            stats.rejected_angle,
            "met side-B faces whose normals are not opposed enough",
        ),
        (
            stats.rejected_subdomain,
            "lie outside the `Restrict Contact To Subdomain` sphere",
        ),
    ] {
        if n > 0 {
            parts.push(format!("{n} {what}"));
        }
    }
    format!(
        "of its {} side-A points, {}",
        stats.points,
        parts.join("; ")
    )
}

/// The enforcement block that applies to the pair `(side A, side B)` of `def`: the block
/// an interaction names, else the definition's block for Energy. Two blocks for Energy
/// with none named is an error, as is a named block that does not exist.
pub fn enforcement_for<'d>(
    def: &'d ContactDefinition,
    named: Option<&str>,
    (side_a, side_b): (&str, &str),
) -> Result<&'d Enforcement, Diagnostic> {
    if let Some(name) = named {
        return def
            .enforcements
            .iter()
            .find(|e| e.name.as_deref() == Some(name))
            .ok_or_else(|| {
                Diagnostic::error(
                    "E0426",
                    format!("interaction {side_a} / {side_b} names enforcement `{name}`, which this definition does not have"),
                )
                .at(Some(def.at.clone()))
                .help("name one of the definition's `begin Enforcement` blocks")
            });
    }
    let claims: Vec<&Enforcement> = def
        .enforcements
        .iter()
        .filter(|e| e.models.iter().any(|m| m.equation == ENERGY))
        .collect();
    match claims.as_slice() {
        [one] => Ok(one),
        [] => match def.enforcements.as_slice() {
            // One block with no Energy line: let the model resolution say what is missing.
            [only] => Ok(only),
            [] => Err(Diagnostic::error(
                "E0426",
                format!("interaction {side_a} / {side_b} has no enforcement"),
            )
            .at(Some(def.at.clone()))
            .help("add a `begin Enforcement` block with `Enforcement for Energy = …`")),
            _ => Err(Diagnostic::error(
                "E0420",
                format!("no enforcement block of this definition has an `Enforcement for Energy` line (interaction {side_a} / {side_b})"),
            )
            .at(Some(def.at.clone()))
            .help("add e.g. `Enforcement for Energy = Gap_Conductance` to one of the blocks")),
        },
        [first, second, ..] => Err(double_claim(first, second, Some((side_a, side_b)))),
    }
}

/// Two blocks claim Energy, on the pair named or on every pair of the definition.
fn double_claim(
    first: &Enforcement,
    second: &Enforcement,
    pair: Option<(&str, &str)>,
) -> Diagnostic {
    let name = |e: &Enforcement| e.name.clone().unwrap_or_else(|| "(unnamed)".into());
    let on = pair.map_or_else(
        || "with no interaction naming one".to_string(),
        |(a, b)| format!("on interaction {a} / {b}"),
    );
    Diagnostic::error(
        "E0429",
        format!(
            "enforcement blocks `{}` and `{}` both claim Energy {on}",
            name(first),
            name(second)
        ),
    )
    .at(Some(second.at.clone()))
    .help(format!(
        "keep one block per equation, or say which applies with `Enforcement = {}` in the `begin Interaction` block of each pair",
        first.name.as_deref().unwrap_or("<name>")
    ))
}

/// A model that could not be made; the diagnostics say why.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Refused;

/// What searching `pairing` of definition `def` again takes, with its surfaces from
/// `set`, its interaction's settings and, for a periodic pair, its `map`.
fn search_again(
    (set, def, mesh): (&surface::SurfaceSet, &ContactDefinition, &Mesh),
    pairing: &Pairing,
    interaction: Option<&Interaction>,
    map: Option<Box<dyn crate::periodic::PeriodicMap>>,
) -> SearchAgain {
    SearchAgain {
        side_a: set.surfaces[pairing.side_a_surface].clone(),
        side_b: set.surfaces[pairing.side_b_surface].clone(),
        settings: match (interaction, pairing.periodic) {
            (Some(i), false) => i.settings.clone(),
            _ => search::base_settings(def, mesh.dim),
        },
        overclosure: match (interaction, pairing.periodic) {
            (Some(i), false) => Some(i.overclosure),
            _ => None,
        },
        subdomain: search::subdomain(def),
        map,
    }
}

/// The conductance model of an enforcement: from its `Gap Conductance Coefficient` lines
/// (Lua compiled, tables checked) or its plugin (loaded and probed). `Err` when it could
/// not be made; the reasons are in `diags`.
pub fn conductance_model(
    enf: &Enforcement,
    choice: &ModelChoice,
    deck_dir: &Path,
    sources: &SourceMap,
    (side_a, side_b): (&str, &str),
    diags: &mut Diagnostics,
) -> Result<Option<Box<dyn ConductanceModel>>, Refused> {
    match &choice.conductance {
        None => Ok(None),
        Some(ConductanceLaw::Constant(h)) => match models::Constant::new(*h) {
            Ok(c) => Ok(Some(Box::new(c))),
            Err(e) => {
                diags.push(
                    Diagnostic::error("E0424", e.to_string())
                        .at(Some(enf.at.clone()))
                        .help("a conductance h ≥ 0 (W/m²K); h = 0 means no heat crosses"),
                );
                Err(Refused)
            }
        },
        Some(ConductanceLaw::Coefficient) => {
            let (m, d) = conductance::from_properties(enf, deck_dir, sources);
            diags.extend(d);
            m.map(Some).ok_or(Refused)
        }
        Some(ConductanceLaw::Plugin) => {
            match plugin::plugin_conductance(enf, deck_dir, side_a, side_b) {
                Ok(c) => {
                    if let Some(notice) = c.plugin().derivative_notice() {
                        diags.push(
                            Diagnostic::warning("W0502", notice)
                                .at(Some(enf.at.clone()))
                                .help("a plugin that returns its own derivatives (PROVIDES_DERIVATIVES) saves those calls"),
                        );
                    }
                    Ok(Some(seen_temperature(enf).wrap(Box::new(c))))
                }
                Err(e) => {
                    diags.push(
                        Diagnostic::error("E0500", e.to_string())
                            .at(Some(enf.at.clone()))
                            .help("`seam check-plugin LIB` loads and probes a plugin on its own"),
                    );
                    Err(Refused)
                }
            }
        }
    }
}

/// Why the contact of `loaded` needs every rank of a distributed `seam run` to hold the
/// whole mesh (docs/parallel.md), or `None` when each rank can hold its part: surfaces
/// or maps made from whole surfaces (`Auto Subset`, an `Align_Surface` periodicity), a
/// voltage or species enforcement, or an Energy enforcement that does not resolve with
/// the problem's `fields`. (A mortar tie with multipliers does not: each rank makes its
/// share of the rows.)
pub fn needs_whole_mesh(loaded: &LoadedDeck, fields: &[&str]) -> Option<&'static str> {
    use crate::deck::spec::{PeriodicTransform, SurfaceDef};
    for def in &loaded.deck.contact_definitions {
        let auto = def
            .surfaces
            .iter()
            .any(|s| matches!(s, SurfaceDef::Block(b) if b.auto_subset.is_some()));
        if auto {
            return Some("an `Auto Subset` (its groups follow the whole surface)");
        }
        let align = (def.periodicity.iter())
            .any(|q| matches!(q.transform, PeriodicTransform::AlignSurface { .. }));
        if align {
            return Some("an `Align_Surface` periodicity (its map follows the whole surfaces)");
        }
        for enf in &def.enforcements {
            if enf.models.iter().any(|m| m.equation != ENERGY) {
                return Some("a voltage or species enforcement");
            }
            if resolve_for(enf, Some(fields)).is_err() {
                return Some("an enforcement with errors");
            }
        }
    }
    None
}

/// Without a mesh: resolve every enforcement block of the deck and make its conductance
/// model, as a run would, so `seam check DECK` reports what `seam run` would refuse.
pub fn check_enforcements(
    loaded: &LoadedDeck,
    deck_dir: &Path,
    fields: Option<&[&str]>,
    diags: &mut Diagnostics,
) {
    for def in &loaded.deck.contact_definitions {
        // Two Energy blocks and no interaction naming one: every pair is ambiguous.
        let energy: Vec<&Enforcement> = def
            .enforcements
            .iter()
            .filter(|e| e.models.iter().any(|m| m.equation == ENERGY))
            .collect();
        if let [first, second, ..] = energy.as_slice()
            && def.interactions.iter().all(|i| i.enforcement.is_none())
        {
            diags.push(double_claim(first, second, None));
        }
        match electric::voltage_block(def) {
            Ok(Some(enf)) => {
                let name = enf.name.as_deref().unwrap_or("(check)");
                electric::check_voltage_block(enf, deck_dir, &loaded.sources, (name, name), diags);
            }
            Ok(None) => {}
            Err(e) => diags.push(e),
        }
        match species::species_block(def) {
            Ok(Some(enf)) => {
                let name = enf.name.as_deref().unwrap_or("(check)");
                let _ = species::species_model(enf, deck_dir, &loaded.sources, (name, name), diags);
            }
            Ok(None) => {}
            Err(e) => diags.push(e),
        }
        for enf in &def.enforcements {
            if enf.models.iter().any(|m| {
                m.equation == electric::VOLTAGE_EQUATION || m.equation == species::SPECIES_EQUATION
            }) {
                continue;
            }
            match resolve_for(enf, fields) {
                Ok(choice) => {
                    let name = enf.name.as_deref().unwrap_or("(check)");
                    let sources = &loaded.sources;
                    let pair = (name, name);
                    if let Ok(m) = conductance_model(enf, &choice, deck_dir, sources, pair, diags) {
                        electric::refuse_voltage(enf, m.as_deref(), diags);
                    }
                }
                Err(ds) => ds.into_iter().for_each(|d| diags.push(d)),
            }
        }
    }
}
