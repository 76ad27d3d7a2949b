//! Interactions from a contact deck, through the same [`ContactScene`] `seam run`,
//! `seam search` and `seam check` build: the deck's surfaces, interactions, searches,
//! periodic conditions and enforcements resolved on the host's mesh, each pairing with
//! what searching it again takes.

use super::{EmbedError, Embedding, Enforcement, Image, Law, Multipliers, Pair, argument};
use std::path::Path;
use std::sync::Arc;

use crate::deck::{self, LoadedDeck};
use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::enforce::conductance::ConductanceModel;
use crate::enforce::interface::{DEFAULT_BETA, FieldPair};
use crate::enforce::model::ConductanceLaw;
use crate::enforce::model::ModelChoice;
use crate::scene::{ContactScene, Enforced, ProblemFileLine, SceneOptions, SearchAgain};
use crate::search::SearchSettings;
use crate::search::scene::Pairing;
use crate::surface::{ContactSurface, SurfaceKind};

/// The one field of an embedding: what `Side B Variable` may name.
const FIELDS: [&str; 1] = ["temperature"];

impl Embedding {
    /// Add the interactions of a Sierra-syntax contact deck (`name` labels messages;
    /// relative paths in the deck — Lua files, plugin libraries — are taken from the
    /// working directory). Contact surfaces name the host's surfaces (`Contact Surface s
    /// Contains base_top`) or blocks (the block's skin). Periodic conditions add one
    /// interaction each, after the definition's own. Returns the new interactions'
    /// indices; on an error none is added.
    pub fn add_deck(&mut self, name: &str, text: &str) -> Result<Vec<usize>, EmbedError> {
        let file: Arc<str> = Arc::from(name);
        let (deck, diagnostics) = deck::parse_sierra(&file, text);
        let mut sources = SourceMap::default();
        sources.add(&file, text);
        let loaded = LoadedDeck {
            deck,
            diagnostics,
            sources,
        };
        self.add_loaded(loaded, Path::new("."))
    }

    /// Add the interactions of a deck file (`.toml` or Sierra syntax); relative paths in
    /// it are taken from its folder.
    pub fn add_deck_file(&mut self, path: &Path) -> Result<Vec<usize>, EmbedError> {
        let loaded = deck::load(path);
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        self.add_loaded(loaded, &dir)
    }

    fn add_loaded(&mut self, loaded: LoadedDeck, dir: &Path) -> Result<Vec<usize>, EmbedError> {
        let mut diags = loaded.diagnostics.clone();
        let fail = |d: &Diagnostics| EmbedError::Deck(d.render(&loaded.sources));
        if diags.has_errors() {
            return Err(fail(&diags));
        }
        let options = SceneOptions {
            integration: self.integration,
            fields: Some(&FIELDS),
            phase: None,
            search_only: false,
        };
        let scene = ContactScene::build_for_host(&self.mesh, &loaded, dir, &options, &mut diags);
        if let Some((side_a, side_b, message)) = scene.plugins_refused.first() {
            return Err(EmbedError::Plugin {
                side_a: side_a.clone(),
                side_b: side_b.clone(),
                message: message.clone(),
            });
        }
        // What an embedding cannot honour: lines about `seam run`'s problem file (whose
        // host gives them through `set_point_pressures` and `set_active`).
        for (at, line) in crate::scene::problem_file_lines(&loaded) {
            let (what, help) = match line {
                ProblemFileLine::ContactPressureVariable => (
                    "`Contact Pressure Variable` names a nodal field of `seam run`'s problem file",
                    "give `Contact Pressure = p`, or pass h from the host's own model (Interaction::conductance)",
                ),
                ProblemFileLine::UseToggleBlock => (
                    "`Use Toggle Block` switches an enforcement by `seam run`'s [[toggle]] times",
                    "leave the line out and add or drop the interaction's terms in the host",
                ),
            };
            diags.push(
                Diagnostic::error("E0430", format!("{what}; an embedding has none"))
                    .at(Some(at))
                    .help(help),
            );
        }
        // An electrical contact couples a voltage with the temperature; an embedding
        // joins one field per interaction.
        for e in &scene.electrical {
            diags.push(
                Diagnostic::error(
                    "E0430",
                    format!(
                        "`Enforcement for Voltage` on {} / {}: an embedding joins one field and has no voltage",
                        e.side_a, e.side_b
                    ),
                )
                .at(Some(e.at.clone()))
                .help("leave the voltage block out of the deck an embedding reads; `seam run` solves the thermal–electrical problem"),
            );
        }
        if diags.has_errors() {
            return Err(fail(&diags));
        }
        let field = self.field.into();
        let added: Vec<Pair> = scene
            .entries
            .into_iter()
            .map(|e| scene_pair(e, field))
            .collect();
        if added.is_empty() {
            return Err(argument(
                "the deck defines no interaction".into(),
                "add a `begin Contact Definition` block with two contact surfaces",
            ));
        }
        let first = self.pairs.len();
        self.pairs.extend(added);
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
        Ok((first..self.pairs.len()).collect())
    }
}

/// The pair of one resolved scene entry (kept for searching again), over `fields`.
pub(super) fn scene_pair(e: Enforced, fields: FieldPair) -> Pair {
    let again = e.again.expect("kept by build_for_host");
    let model = e.model.map(Arc::from);
    resolved_pair(
        e.pairing,
        &e.choice,
        e.penalty_scale,
        model,
        Some(again),
        fields,
    )
}

/// The pair of a pairing and its resolved enforcement over `fields`, searched already;
/// without `again` (`seam run`, whose mesh does not move) it keeps only its surfaces'
/// names and is not searched again.
pub(super) fn resolved_pair(
    p: Pairing,
    c: &ModelChoice,
    penalty_scale: f64,
    model: Option<Arc<dyn ConductanceModel>>,
    again: Option<SearchAgain>,
    fields: FieldPair,
) -> Pair {
    let enforcement = if c.mortar {
        Enforcement::Tie {
            multipliers: if c.dual {
                Multipliers::Dual
            } else {
                Multipliers::Standard
            },
            offset: c.offset,
        }
    } else {
        let law = match (&c.conductance, model) {
            (Some(ConductanceLaw::Constant(h)), _) => Law::Constant(*h),
            (Some(law), Some(model)) => Law::Model {
                model,
                pressure: c.pressure,
                plugin: *law == ConductanceLaw::Plugin,
            },
            _ => Law::Constant(0.0),
        };
        Enforcement::Flux {
            form: c.form,
            law,
            offset: c.offset,
            beta: c.penalty_factor.unwrap_or(DEFAULT_BETA) * penalty_scale,
        }
    };
    let named = |name: &str| ContactSurface {
        name: name.to_string(),
        kind: SurfaceKind::Faces,
        faces: Vec::new(),
        tributary: Vec::new(),
        nodes: Vec::new(),
        origins: Vec::new(),
        parent: None,
    };
    let (side_a, side_b, settings, overclosure, subdomain, image) = match again {
        Some(again) => (
            again.side_a,
            again.side_b,
            again.settings,
            again.overclosure,
            again.subdomain,
            again.map.map(|map| Image {
                map,
                name: format!("{}_image", p.side_a),
            }),
        ),
        None => (
            named(&p.side_a),
            named(&p.side_b),
            SearchSettings::defaults(3),
            None,
            None,
            None,
        ),
    };
    let mut pair = Pair::new(
        side_a,
        side_b,
        (p.side_a_geometry, p.side_b_geometry),
        settings,
        overclosure,
        subdomain,
        image,
        enforcement,
        fields,
    );
    pair.result = Some(p.result);
    pair.quarantine = c.quarantine;
    pair
}
