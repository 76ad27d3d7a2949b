use super::{EmbedError, Embedding, Enforcement, Image, Law, Multipliers, Pair, argument};
use std::path::Path;
use std::sync::{Arc, OnceLock};

use crate::deck::spec::{ContactDefinition, Enforcement as DeckEnforcement};
use crate::deck::{self, Deck};
use crate::diag::{Diagnostics, SourceMap};
use crate::enforce::conductance::SeenTemperature;
use crate::enforce::interface::DEFAULT_BETA;
use crate::enforce::model::ConductanceLaw;
use crate::scene::enforcement::resolve as resolve_model;
use crate::scene::search::search_periodicity;
use crate::search::scene::{SceneSearch, surface_geometries};

impl Embedding {
    /// Add the interactions of a Sierra-syntax contact deck (`name` labels messages;
    /// relative paths in the deck — Lua files, plugin libraries — are taken from the
    /// working directory). Contact surfaces name the host's surfaces (`Contact Surface s
    /// Contains base_top`) or blocks (the block's skin). Periodic conditions add one
    /// interaction each, after the definition's own. Returns the new interactions'
    /// indices; on an error none is added.
    pub fn add_deck(&mut self, name: &str, text: &str) -> Result<Vec<usize>, EmbedError> {
        let file: Arc<str> = Arc::from(name);
        let (deck, diags) = deck::parse_sierra(&file, text);
        let mut sources = SourceMap::default();
        sources.add(&file, text);
        self.add_parsed(deck, diags, sources, Path::new("."))
    }

    /// Add the interactions of a deck file (`.toml` or Sierra syntax); relative paths in
    /// it are taken from its folder.
    pub fn add_deck_file(&mut self, path: &Path) -> Result<Vec<usize>, EmbedError> {
        let loaded = deck::load(path);
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        self.add_parsed(loaded.deck, loaded.diagnostics, loaded.sources, &dir)
    }

    fn add_parsed(
        &mut self,
        deck: Deck,
        mut diags: Diagnostics,
        sources: SourceMap,
        dir: &Path,
    ) -> Result<Vec<usize>, EmbedError> {
        let fail = |d: &Diagnostics| EmbedError::Deck(d.render(&sources));
        if diags.has_errors() {
            return Err(fail(&diags));
        }
        let mut added = Vec::new();
        for def in &deck.contact_definitions {
            let set = crate::surface::build(&self.mesh, def, &sources);
            diags.extend(set.diagnostics.clone());
            let (list, d) = crate::scene::interaction::resolve(def, &set, 3, &sources);
            diags.extend(d);
            if diags.has_errors() {
                return Err(fail(&diags));
            }
            let subdomain = crate::scene::search::subdomain(def);
            for i in &list {
                let enforcement = self.deck_enforcement(
                    def,
                    i.enforcement.as_deref(),
                    (&i.side_a_name, &i.side_b_name),
                    i.penalty_scale,
                    dir,
                    &sources,
                )?;
                let a = set.surfaces[i.side_a].clone();
                let b = set.surfaces[i.side_b].clone();
                added.push(self.pair(
                    a,
                    b,
                    i.settings.clone(),
                    i.overclosure,
                    subdomain,
                    enforcement,
                )?);
            }
            // Periodic conditions: the image of a surface paired with its destination,
            // found and checked as `seam run` does.
            if def.periodicity.is_empty() {
                continue;
            }
            let mut scene = SceneSearch::default();
            let geometry = surface_geometries(&self.mesh, &set, &mut scene.diagnostics);
            let mut found = Vec::new();
            for p in &def.periodicity {
                found.extend(search_periodicity(
                    &self.mesh,
                    def,
                    p,
                    &set,
                    &geometry,
                    dir,
                    &sources,
                    self.integration,
                    &mut scene,
                ));
            }
            diags.extend(scene.diagnostics);
            if diags.has_errors() {
                return Err(fail(&diags));
            }
            for f in found {
                let p = f.pairing;
                // As in `seam run`: an interaction block of the same two surfaces names
                // the enforcement and the penalty scale, else the first enforcement.
                let named = list
                    .iter()
                    .find(|i| i.side_a_name == p.side_a && i.side_b_name == p.side_b);
                let enforcement = self.deck_enforcement(
                    def,
                    named.and_then(|i| i.enforcement.as_deref()),
                    (&p.side_a, &p.side_b),
                    named.map_or(1.0, |i| i.penalty_scale),
                    dir,
                    &sources,
                )?;
                added.push(Pair {
                    side_a: set.surfaces[p.side_a_surface].clone(),
                    side_b: set.surfaces[p.side_b_surface].clone(),
                    a: p.side_a_geometry,
                    b: p.side_b_geometry,
                    settings: crate::scene::search::base_settings(def, 3),
                    overclosure: None,
                    subdomain,
                    image: Some(Image {
                        map: f.map,
                        name: format!("{}_image", p.side_a),
                    }),
                    enforcement,
                    searcher: None,
                    result: None,
                    points: OnceLock::new(),
                    allow_unpaired: false,
                });
            }
        }
        if added.is_empty() {
            return Err(argument(
                "the deck defines no interaction".into(),
                "add a `begin Contact Definition` block with two contact surfaces",
            ));
        }
        let first = self.pairs.len();
        self.pairs.extend(added);
        Ok((first..self.pairs.len()).collect())
    }

    /// The enforcement of one deck interaction: its named `begin Enforcement` block (or
    /// the definition's first), resolved to a form and a conductance law; a plugin is
    /// loaded here.
    fn deck_enforcement(
        &self,
        def: &ContactDefinition,
        name: Option<&str>,
        (side_a, side_b): (&str, &str),
        penalty_scale: f64,
        dir: &Path,
        sources: &SourceMap,
    ) -> Result<Enforcement, EmbedError> {
        let fail = |d: &Diagnostics| EmbedError::Deck(d.render(sources));
        let enf: &DeckEnforcement = crate::scene::enforcement_for(def, name, (side_a, side_b))
            .map_err(|e| {
                let mut d = Diagnostics::default();
                d.push(e);
                fail(&d)
            })?;
        let choice = resolve_model(enf).map_err(|ds| {
            let mut d = Diagnostics::default();
            ds.into_iter().for_each(|x| d.push(x));
            fail(&d)
        })?;
        if choice.mortar {
            return Ok(Enforcement::Tie {
                multipliers: if choice.dual {
                    Multipliers::Dual
                } else {
                    Multipliers::Standard
                },
                offset: choice.offset,
            });
        }
        let law = match choice.conductance {
            None => Law::Constant(0.0),
            Some(ConductanceLaw::Constant(h)) => Law::Constant(h),
            Some(ConductanceLaw::Coefficient) => {
                let (m, d) = crate::scene::conductance::from_properties(enf, dir, sources);
                match m {
                    Some(m) => Law::Model(m, choice.pressure),
                    None => return Err(fail(&d)),
                }
            }
            Some(ConductanceLaw::Plugin) => {
                let plugin = crate::scene::plugin::plugin_conductance(enf, dir, side_a, side_b)
                    .map_err(|e| EmbedError::Plugin {
                        side_a: side_a.to_string(),
                        side_b: side_b.to_string(),
                        message: e.to_string(),
                    })?;
                match crate::scene::enforcement::seen_temperature(enf) {
                    SeenTemperature::Both => Law::Plugin(Box::new(plugin), choice.pressure),
                    seen => Law::Model(seen.wrap(Box::new(plugin)), choice.pressure),
                }
            }
        };
        Ok(Enforcement::Flux {
            form: choice.form,
            law,
            offset: choice.offset,
            beta: choice.penalty_factor.unwrap_or(DEFAULT_BETA) * penalty_scale,
        })
    }
}
