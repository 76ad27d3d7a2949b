//! Interactions: which contact surfaces are paired, in which roles, with which options.
//!
//! Entry point: [`resolve`]. The rules (Aria, with Sierra/SM's interaction defaults):
//! - `begin Interaction`: `Side A a1 a2 …` with `Side B b1 b2 …` pairs each A with each B;
//!   `Surfaces s1 s2 …` pairs every two of them (the first listed is side A).
//! - `begin Interaction Defaults`: `General Contact = on` pairs every two distinct
//!   surfaces (of its `Surfaces` list, if given); `Self Contact = on` pairs each surface
//!   with itself.
//! - With neither block, every pair of distinct contact surfaces interacts, except that a
//!   surface with a `Periodicity For` pairs only through its periodic image.
//! - Node surfaces interact only with face surfaces, and only as side A; pairs of two
//!   node surfaces are dropped, and a node surface named as side B is an error.
//! - A pair named twice keeps one interaction: the later definition's options apply.
//!
//! Search options come from `begin Search Options` (defaults for every interaction) and
//! an interaction's own `Normal Tolerance`; they are lowered here to the search's typed
//! [`SearchSettings`], and `Initial Overclosure` control assignments to its
//! [`Overclosure`].

use serde::Serialize;

use crate::deck::spec::{
    ContactDefinition, Control, ControlAssignment, Interaction as InteractionSpec,
};
use crate::diag::{Diagnostic, Diagnostics, Loc, SourceMap, did_you_mean};
use crate::search::{Overclosure, SearchSettings};
use crate::surface::{SurfaceKind, SurfaceSet};

/// One resolved interaction between two surfaces (indices into the [`SurfaceSet`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Interaction {
    pub side_a: usize,
    pub side_b: usize,
    /// `side_a/side_b` names, for messages and reports.
    pub side_a_name: String,
    pub side_b_name: String,
    /// The enforcement this interaction uses, by name, if the deck says.
    pub enforcement: Option<String>,
    pub settings: SearchSettings,
    /// Penalty scale factor from the control assignments (1 when none applies).
    pub penalty_scale: f64,
    /// Initial-overclosure treatment from the control assignments (store offsets when
    /// none applies: a thermal analysis keeps its geometry).
    pub overclosure: Overclosure,
    /// Where the interaction was defined (unknown for defaults).
    #[serde(skip)]
    pub at: Loc,
}

impl Interaction {
    pub fn is_self_contact(&self) -> bool {
        self.side_a == self.side_b
    }
}

/// Resolve the interactions of one contact definition over its built surfaces.
pub fn resolve(
    def: &ContactDefinition,
    surfaces: &SurfaceSet,
    dim: usize,
    sources: &SourceMap,
) -> (Vec<Interaction>, Diagnostics) {
    let mut diags = Diagnostics::default();
    let base = super::search::base_settings(def, dim);

    let self_default = def
        .search_options
        .as_ref()
        .and_then(|o| o.self_contact)
        .unwrap_or(false);
    let mut out: Vec<Interaction> = Vec::new();
    let mut resolver = Resolver {
        surfaces,
        sources,
        diags: &mut diags,
    };
    let push = |out: &mut Vec<Interaction>,
                a: usize,
                b: usize,
                enforcement: Option<String>,
                settings: SearchSettings,
                at: Loc| {
        let item = Interaction {
            side_a: a,
            side_b: b,
            side_a_name: surfaces.surfaces[a].name.clone(),
            side_b_name: surfaces.surfaces[b].name.clone(),
            enforcement,
            settings,
            penalty_scale: 1.0,
            overclosure: Overclosure::StoreOffsets,
            at,
        };
        match out.iter_mut().find(|x| x.side_a == a && x.side_b == b) {
            Some(existing) => *existing = item,
            None => out.push(item),
        }
    };
    let face_surfaces: Vec<usize> = (0..surfaces.surfaces.len())
        .filter(|&i| surfaces.surfaces[i].kind == SurfaceKind::Faces)
        .collect();
    let all: Vec<usize> = (0..surfaces.surfaces.len()).collect();

    if let Some(d) = &def.interaction_defaults {
        let pool = if d.surfaces.is_empty() {
            all.clone()
        } else {
            resolver.names(&d.surfaces, &d.at)
        };
        if d.general_contact.unwrap_or(false) {
            for (i, &a) in pool.iter().enumerate() {
                for &b in &pool[i + 1..] {
                    if let Some((a, b)) = orient(surfaces, a, b) {
                        push(
                            &mut out,
                            a,
                            b,
                            d.enforcement.clone(),
                            base.clone(),
                            d.at.clone(),
                        );
                    }
                }
            }
        }
        if d.self_contact.unwrap_or(self_default) {
            for &a in &pool {
                if surfaces.surfaces[a].kind == SurfaceKind::Faces {
                    push(
                        &mut out,
                        a,
                        a,
                        d.enforcement.clone(),
                        base.clone(),
                        d.at.clone(),
                    );
                }
            }
        }
    }
    for spec in &def.interactions {
        let settings = settings_for(spec, &base);
        for (a, b) in resolver.pairs(spec) {
            push(
                &mut out,
                a,
                b,
                spec.enforcement.clone(),
                settings.clone(),
                spec.at.clone(),
            );
        }
    }
    if def.interactions.is_empty() && def.interaction_defaults.is_none() {
        // Surfaces tied by a periodicity pair through their image, not directly.
        let periodic: Vec<usize> = def
            .periodicity
            .iter()
            .filter_map(|p| {
                let name = p.surface.to_ascii_lowercase();
                surfaces.surfaces.iter().position(|s| s.name == name)
            })
            .collect();
        let all: Vec<usize> = all
            .iter()
            .copied()
            .filter(|i| !periodic.contains(i))
            .collect();
        for (i, &a) in all.iter().enumerate() {
            for &b in &all[i + 1..] {
                if let Some((a, b)) = orient(surfaces, a, b) {
                    push(&mut out, a, b, None, base.clone(), Loc::default());
                }
            }
        }
        if self_default {
            for &a in &face_surfaces {
                push(&mut out, a, a, None, base.clone(), Loc::default());
            }
        }
    }
    apply_controls(&def.control_assignments, &mut out, &mut resolver);
    (out, diags)
}

/// Abaqus-style control assignments, in deck order: an assignment with no surface
/// covers every interaction; one surface (or the same surface twice) covers its
/// self-interaction; two surfaces cover the interaction between them, in either role.
/// Where assignments overlap, the last one applies.
fn apply_controls(
    controls: &[ControlAssignment],
    out: &mut [Interaction],
    r: &mut Resolver<'_, '_>,
) {
    for c in controls {
        let s1 = c
            .surface_1
            .as_ref()
            .map(|n| r.names(std::slice::from_ref(n), &c.at));
        let s2 = c
            .surface_2
            .as_ref()
            .map(|n| r.names(std::slice::from_ref(n), &c.at));
        let target = match (s1.as_deref(), s2.as_deref()) {
            (None, _) => None,
            (Some([a]), None) => Some((*a, *a)),
            (Some([a]), Some([b])) => Some((*a, *b)),
            _ => continue, // an unknown name, reported above
        };
        for i in out.iter_mut() {
            let applies = match target {
                None => true,
                Some((a, b)) => {
                    (i.side_a == a && i.side_b == b) || (i.side_a == b && i.side_b == a)
                }
            };
            if applies {
                match c.control {
                    Control::ScalePenalty { factor } => i.penalty_scale = factor,
                    Control::InitialOverclosure { treatment } => i.overclosure = treatment.into(),
                }
            }
        }
    }
}

fn settings_for(spec: &InteractionSpec, base: &SearchSettings) -> SearchSettings {
    let mut s = base.clone();
    if let Some(t) = spec.normal_tolerance {
        s.normal_tolerance = Some(t);
    }
    s
}

/// Put a node surface on side A; drop node–node pairs.
fn orient(surfaces: &SurfaceSet, a: usize, b: usize) -> Option<(usize, usize)> {
    let kind = |i: usize| surfaces.surfaces[i].kind;
    match (kind(a), kind(b)) {
        (SurfaceKind::Nodes, SurfaceKind::Nodes) => None,
        (SurfaceKind::Faces, SurfaceKind::Nodes) => Some((b, a)),
        _ => Some((a, b)),
    }
}

struct Resolver<'a, 'd> {
    surfaces: &'a SurfaceSet,
    sources: &'a SourceMap,
    diags: &'d mut Diagnostics,
}

impl Resolver<'_, '_> {
    fn names(&mut self, names: &[String], at: &Loc) -> Vec<usize> {
        let mut out = Vec::new();
        for name in names {
            let lower = name.to_ascii_lowercase();
            match self.surfaces.surfaces.iter().position(|s| s.name == lower) {
                Some(i) => out.push(i),
                None => {
                    let known: Vec<&str> = self
                        .surfaces
                        .surfaces
                        .iter()
                        .map(|s| s.name.as_str())
                        .collect();
                    let help = match did_you_mean(name, known.iter().copied()) {
                        Some(s) => format!("did you mean `{s}`?"),
                        None => format!(
                            "the contact surfaces are: {}",
                            known
                                .iter()
                                .map(|k| format!("`{k}`"))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    };
                    self.diags.push(
                        Diagnostic::error(
                            "E0310",
                            format!("unknown contact surface `{name}` in an interaction"),
                        )
                        .at(Some(self.sources.narrow(at, name)))
                        .help(help),
                    );
                }
            }
        }
        out
    }

    fn pairs(&mut self, spec: &InteractionSpec) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        let a = self.names(&spec.side_a, &spec.at);
        let b = self.names(&spec.side_b, &spec.at);
        for &x in &a {
            for &y in &b {
                if self.surfaces.surfaces[y].kind == SurfaceKind::Nodes {
                    self.diags.push(
                        Diagnostic::error(
                            "E0311",
                            format!("node surface `{}` cannot be side B: side B is projected onto and needs faces", self.surfaces.surfaces[y].name),
                        )
                        .at(Some(self.sources.narrow(&spec.at, &self.surfaces.surfaces[y].name)))
                        .help("put the node surface on side A"),
                    );
                    continue;
                }
                out.push((x, y));
            }
        }
        let listed = self.names(&spec.surfaces, &spec.at);
        for (i, &x) in listed.iter().enumerate() {
            for &y in &listed[i + 1..] {
                if let Some(p) = orient(self.surfaces, x, y) {
                    out.push(p);
                }
            }
        }
        out
    }
}
