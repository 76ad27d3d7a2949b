//! The contact of a run: the problem's `[contact]` deck resolved on its mesh into a
//! [`ContactScene`] ([`RunContact::build`]), the face conditions that contact masks
//! (Aria's rule), and per interaction what the problem file joins to the deck
//! ([`Couplings`]): its toggle, the fields of its two sides and its contact pressure.

use std::collections::HashSet;
use std::path::Path;
use std::sync::Arc;

use crate::deck::{self, LoadedDeck};
use crate::diag::{Diagnostic, Diagnostics, did_you_mean};
use crate::enforce::conductance::ConductanceModel;
use crate::enforce::model::ModelChoice;
use crate::heat::TEMPERATURE;
use crate::mesh::{Mesh, NodeId, Side};
use crate::scene::{ContactScene, SceneOptions};
use crate::search::pairing::Integration;
use crate::search::scene::Pairing;

use super::nodal_field::read_nodal_field;
use super::physics::{FaceSite, Materials, Physics, evaluate};
use super::problem::{ContactSpec, NodalFieldSpec, Problem, ProblemFile, Value};
use super::{RunError, RunOptions, input_error};
use crate::scene::ContactView;

/// An interaction's model, penalty scale and conductance model.
pub(super) type Choice = (ModelChoice, f64, Option<Arc<dyn ConductanceModel>>);

/// The contact of a run: the deck, and per interaction (in the scene's order) its
/// pairing, its enforcement and what its contact output holds.
#[derive(Default)]
pub(super) struct RunContact {
    /// The deck, whose sources also hold the problem file (for diagnostics).
    pub loaded: LoadedDeck,
    pub pairings: Vec<Pairing>,
    pub choices: Vec<Choice>,
    /// What each contact output holds (`Visualize Contact`, `Output Rule`).
    pub views: Vec<ContactView>,
    /// The electrical contacts (`Enforcement for Voltage`).
    pub electrical: Vec<crate::scene::electric::ElectricalEnforced>,
    /// Per interaction, its definition's `Update Search Every n Steps` (or `Search
    /// Update Frequency`), for surfaces that move.
    pub search_every: Vec<Option<u32>>,
    /// Per interaction, the index of its contact definition in the deck.
    pub definition: Vec<usize>,
    /// Per interaction, what searching it again takes (surfaces that move only); taken
    /// by the run's embedding.
    pub again: std::cell::RefCell<Vec<Option<crate::scene::SearchAgain>>>,
    /// The species interfaces (`Enforcement for Species`).
    pub species: Vec<super::species::Interface>,
    /// The voltage ties (`Enforcement for Voltage` with a tie model), after the species
    /// interfaces in the embedding.
    pub voltage_ties: Vec<super::species::Interface>,
    /// Per electrical contact, its definition's `Update Search Every n Steps`.
    pub electrical_every: Vec<Option<u32>>,
    /// How the scene integrated its interfaces (a search anew does the same).
    pub integration: Option<Integration>,
    /// Wall-clock seconds building the contact surfaces and searching.
    pub surfaces_s: f64,
    pub search_s: f64,
}

impl RunContact {
    /// The `[contact]` of `file` on `mesh` (nothing without one): the deck loaded and
    /// its scene built with the problem's fields. An unreadable deck, a bad `[contact]`
    /// field or an error in the scene ends the run here.
    pub(super) fn build(
        file: &ProblemFile,
        mesh: &Mesh,
        field_names: &[String],
        options: &RunOptions,
        diags: &mut Diagnostics,
    ) -> Result<RunContact, RunError> {
        let mut out = match &file.problem.contact {
            Some(c) => {
                let moving = file.problem.displacement.is_some() || !file.problem.death.is_empty();
                Self::scene(c, &file.dir, mesh, field_names, options, moving, diags)?
            }
            None => RunContact::default(),
        };
        out.loaded.sources.add(&file.text.file, &file.text.text);
        if super::ranks::stop(diags) {
            return Err(RunError::Input(
                std::mem::take(diags),
                std::mem::take(&mut out.loaded.sources),
            ));
        }
        Ok(out)
    }

    /// The deck of `[contact]` `c` and its scene on `mesh`.
    fn scene(
        c: &ContactSpec,
        dir: &Path,
        mesh: &Mesh,
        field_names: &[String],
        options: &RunOptions,
        moving: bool,
        diags: &mut Diagnostics,
    ) -> Result<RunContact, RunError> {
        let deck_path = dir.join(&c.file);
        let loaded = deck::load(&deck_path);
        if loaded.diagnostics.has_errors() {
            return Err(RunError::Input(loaded.diagnostics, loaded.sources));
        }
        let integration = match c.integration.as_deref() {
            None | Some("segments") => Integration::Segments {
                order: c.order.unwrap_or(5),
            },
            Some("quadrature") => Integration::Quadrature {
                order: c.order.unwrap_or(2),
            },
            Some(other) => {
                return Err(input_error(
                    "E0702",
                    format!("unknown integration `{other}`"),
                    "use \"segments\" or \"quadrature\"",
                ));
            }
        };
        if let Some(order) = c.order
            && !(1..=crate::search::pairing::MAX_ORDER).contains(&order)
        {
            return Err(input_error(
                "E0716",
                format!(
                    "[contact] order = {order}: the integration order must be 1 to {}",
                    crate::search::pairing::MAX_ORDER
                ),
                "orders 2 (quadrature) and 5 (segments) are the defaults; higher ones only cost time",
            ));
        }
        let deck_dir = deck_path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let diags_before = diags.0.len();
        let field_refs: Vec<&str> = field_names.iter().map(String::as_str).collect();
        let phase = |what: &str| options.phase(what);
        // The scene's own diagnostics follow the run's notes on its definitions.
        let mut found = std::mem::take(diags);
        let build = if moving {
            ContactScene::build_for_host
        } else {
            ContactScene::build
        };
        let scene = build(
            mesh,
            &loaded,
            &deck_dir,
            &SceneOptions {
                integration,
                fields: Some(&field_refs),
                phase: Some(&phase),
                search_only: false,
            },
            &mut found,
        );
        let (before, after) = found.0.split_at(diags_before);
        diags.0.extend_from_slice(before);
        for def in &scene.definitions {
            if def.view.silenced {
                diags.push(
                    Diagnostic::warning(
                        "W0702",
                        "`Visualize Contact` is on, but `Output Rule = none`: this definition writes no contact fields",
                    )
                    .at(Some(def.at.clone()))
                    .help("remove `Output Rule = none` (or `Visualize Contact`) to say which you mean"),
                );
            }
            if let Some(n) = def.search_every.filter(|_| !moving) {
                diags.push(
                    Diagnostic::warning(
                        "W0703",
                        format!("`Update Search Every {n} Steps` (or `Search Update Frequency`) has no effect in this run: the mesh does not move, so the first search holds for every step"),
                    )
                    .at(Some(def.at.clone()))
                    .help("remove the line, or give the problem a [displacement] that moves the mesh"),
                );
            }
        }
        diags.0.extend_from_slice(after);
        let mut out = RunContact {
            surfaces_s: scene.timing.surfaces_s,
            search_s: scene.timing.search_s,
            ..RunContact::default()
        };
        out.integration = Some(integration);
        out.electrical_every = (scene.electrical.iter())
            .map(|e| {
                scene
                    .definitions
                    .get(e.definition)
                    .and_then(|d| d.search_every)
            })
            .collect();
        out.electrical = scene.electrical;
        let field = |e: crate::scene::species::FieldEnforced| {
            let every = scene
                .definitions
                .get(e.definition)
                .and_then(|d| d.search_every);
            super::species::Interface {
                search_every: every,
                ..e.into()
            }
        };
        out.species = scene.species.into_iter().map(field).collect();
        out.voltage_ties = scene.voltage_ties.into_iter().map(field).collect();
        for e in scene.entries {
            out.again.get_mut().push(e.again);
            out.definition.push(e.definition);
            out.search_every.push(
                scene
                    .definitions
                    .get(e.definition)
                    .and_then(|d| d.search_every),
            );
            out.views.push(e.view);
            out.choices
                .push((e.choice, e.penalty_scale, e.model.map(Arc::from)));
            out.pairings.push(e.pairing);
        }
        out.loaded = loaded;
        Ok(out)
    }

    /// Aria masks ordinary flux and convection conditions on faces in contact: a side-A
    /// face with matched points (for a node surface, a tributary face with a matched
    /// node), or a side-B face some point paired with. A condition with
    /// `no_coverage_flux = true` stays.
    pub(super) fn mask_face_conditions(
        &self,
        face_sites: &mut Vec<FaceSite>,
        diags: &mut Diagnostics,
    ) {
        let mut in_contact: HashSet<Side> = HashSet::new();
        for p in &self.pairings {
            if p.periodic {
                continue;
            }
            let mut matched_nodes = HashSet::new();
            for q in p.result.points.iter() {
                let Some(face_b) = q.matched_b_face() else {
                    continue;
                };
                if let Some(fa) = q.a_face {
                    in_contact.insert(p.side_a_geometry.faces[fa as usize].side);
                } else if let Some(&(node, _)) = q
                    .a_node
                    .and_then(|k| p.side_a_geometry.nodes.get(k as usize))
                {
                    matched_nodes.insert(node);
                }
                in_contact.insert(p.side_b_geometry.faces[face_b].side);
            }
            for f in &p.side_a_geometry.tributary {
                if f.nodes[..f.len as usize]
                    .iter()
                    .any(|n| matched_nodes.contains(n))
                {
                    in_contact.insert(f.side);
                }
            }
        }
        // On a distributed mesh, a face of this rank's elements may be in contact through
        // another rank's points (a side-B face, a tributary face of a node it owns).
        let in_contact = crate::parallel::faces_in_contact(in_contact);
        let before = face_sites.len();
        face_sites.retain(|f| f.keep || !in_contact.contains(&f.side));
        let masked = before - face_sites.len();
        if masked > 0 {
            diags.push(
                Diagnostic::warning(
                    "W0701",
                    format!("{masked} face condition(s) on faces in contact are masked (Aria's rule)"),
                )
                .help("set `no_coverage_flux = true` in the [[bc]] to keep a condition on faces in contact"),
            );
        }
    }
}

/// Per interaction, what the problem file joins to its enforcement: its toggle
/// (`Use Toggle Block`), the fields of its two sides (`Side B Variable`) and the contact
/// pressure at its points (`Contact Pressure Variable`).
pub(super) struct Couplings {
    /// The intervals in which the interaction is on (always, when `None`): the energy
    /// interactions, then the species interfaces.
    pub toggles: Vec<Option<Vec<(f64, f64)>>>,
    /// (side-A field, side-B field), as indices into the problem's field names.
    pub fields: Vec<(usize, usize)>,
    /// The pressure at each point, from a `[[nodal_field]]`.
    pub pressures: Vec<Option<Vec<f64>>>,
}

impl Couplings {
    /// Each interaction's toggle, fields and pressures, in that order; problems go to
    /// `diags`.
    pub(super) fn resolve(
        file: &ProblemFile,
        physics: &Physics<'_>,
        contact: &RunContact,
        diags: &mut Diagnostics,
    ) -> Couplings {
        // The energy interactions', then the species interfaces' and the voltage ties'
        // (the embedding's order).
        let choices = (contact.choices.iter().map(|c| &c.0))
            .chain(contact.species.iter().map(|s| &s.choice))
            .chain(contact.voltage_ties.iter().map(|s| &s.choice));
        let toggles = resolve_toggles(&file.problem, choices, diags);
        let fields = interaction_fields(
            physics.mesh,
            &physics.materials,
            &physics.field_names,
            &contact.pairings,
            &contact.choices,
            diags,
        );
        let pressures = point_pressures(file, physics, contact, diags);
        Couplings {
            toggles,
            fields,
            pressures,
        }
    }

    /// Whether some interaction is switched on and off.
    pub(super) fn any_toggle(&self) -> bool {
        self.toggles.iter().any(Option::is_some)
    }

    /// Whether interaction `k` is on at time `t`.
    pub(super) fn on(&self, k: usize, t: f64) -> bool {
        self.toggles[k]
            .as_ref()
            .is_none_or(|on| on.iter().any(|&(a, b)| a <= t && t <= b))
    }
}

/// Each interaction's toggle intervals (`Use Toggle Block` → `[[toggle]]`).
fn resolve_toggles<'c>(
    p: &Problem,
    choices: impl Iterator<Item = &'c ModelChoice>,
    diags: &mut Diagnostics,
) -> Vec<Option<Vec<(f64, f64)>>> {
    choices
        .map(|c| {
            let name = c.toggle.as_ref()?;
            match p.toggle.iter().find(|t| t.name.eq_ignore_ascii_case(name)) {
                Some(t) => Some(t.on.clone()),
                None => {
                    let names = p.toggle.iter().map(|t| t.name.as_str());
                    let help = did_you_mean(name, names).map_or_else(
                        || format!("add [[toggle]] name = \"{name}\", on = [[t0, t1]] to the problem file"),
                        |s| format!("did you mean `{s}`?"),
                    );
                    diags.push(
                        Diagnostic::error("E0711", format!("`Use Toggle Block = {name}`: no [[toggle]] of that name"))
                            .help(help),
                    );
                    None
                }
            }
        })
        .collect()
}

/// Each interaction's (side-A field, side-B field), as indices into `field_names`,
/// checked against `Side B Variable`.
fn interaction_fields(
    mesh: &Mesh,
    materials: &Materials,
    field_names: &[String],
    pairings: &[Pairing],
    choices: &[Choice],
    diags: &mut Diagnostics,
) -> Vec<(usize, usize)> {
    let index = |f: &str| field_names.iter().position(|g| g == f).unwrap_or(0);
    pairings
        .iter()
        .zip(choices)
        .map(|(p, (c, _, _))| {
            // A face of this rank's mesh (on a rank holding a part of it, a side-B face
            // may be another rank's element's, which its mesh does not hold).
            let side_field = |g: &crate::search::pairing::SurfaceGeometry| {
                g.faces
                    .iter()
                    .find(|f| f.side.elem.index() < mesh.num_elems())
                    .map(|f| materials.fields[mesh.block_of(f.side.elem)].clone())
            };
            let fa = side_field(&p.side_a_geometry).unwrap_or_else(|| TEMPERATURE.into());
            let fb = side_field(&p.side_b_geometry).unwrap_or_else(|| TEMPERATURE.into());
            match &c.variables {
                Some((a, b)) if (a, b) != (&fa, &fb) => diags.push(
                    Diagnostic::error(
                        "E0428",
                        format!(
                            "interaction {} / {}: `Side B Variable {b} To {a}`, but side A carries `{fa}` and side B `{fb}`",
                            p.side_a, p.side_b
                        ),
                    )
                    .help(format!("write `Side B Variable {fb} To {fa}` (the fields come from [[material]] field)")),
                ),
                None if fa != fb => diags.push(
                    Diagnostic::error(
                        "E0428",
                        format!(
                            "interaction {} / {} joins two fields, `{fa}` on side A and `{fb}` on side B",
                            p.side_a, p.side_b
                        ),
                    )
                    .help(format!("say how they map: `Side B Variable {fb} To {fa}` in the enforcement")),
                ),
                _ => {}
            }
            (index(&fa), index(&fb))
        })
        .collect()
}

/// [`read_nodal_field`], read by rank 0 alone where the ranks hold their parts of the
/// mesh, each other rank getting the values at its nodes from rank 0 (collective); read
/// serially otherwise. A rank other than 0 whose rank 0 could not read it gets an error
/// without a message: rank 0 reports it, and the others follow its verdict.
fn read_on_root(
    field: &NodalFieldSpec,
    file: &Path,
    mesh: &Mesh,
) -> Result<Vec<f64>, (String, String)> {
    if !crate::parallel::mesh_is_distributed() {
        return read_nodal_field(field, file, mesh);
    }
    let read = crate::parallel::is_root().then(|| read_nodal_field(field, file, mesh));
    let whole = read.as_ref().and_then(|r| r.as_ref().ok()).cloned();
    match (read, crate::parallel::nodal_from_root(whole)) {
        (Some(Err(e)), _) => Err(e),
        (_, Some(v)) => Ok(v),
        (_, None) => Err((String::new(), String::new())),
    }
}

/// Per interaction with `Contact Pressure Variable`: the pressure at each of its
/// points, interpolated on side A from the named `[[nodal_field]]` (evaluated at the
/// nodes at the start time).
fn point_pressures(
    file: &ProblemFile,
    physics: &Physics<'_>,
    contact: &RunContact,
    diags: &mut Diagnostics,
) -> Vec<Option<Vec<f64>>> {
    let (p, dir, at) = (&file.problem, &file.dir, &file.text);
    let (mesh, sandbox, time) = (physics.mesh, &physics.sandbox, physics.time.start);
    let (pairings, choices) = (&contact.pairings, &contact.choices);
    pairings
        .iter()
        .zip(choices)
        .map(|(pairing, (c, _, _))| {
            let name = c.pressure_variable.as_ref()?;
            let Some(field) = p.nodal_field.iter().find(|f| f.name.eq_ignore_ascii_case(name)) else {
                let help = did_you_mean(name, p.nodal_field.iter().map(|f| f.name.as_str()))
                    .map_or_else(
                        || format!("add [[nodal_field]] name = \"{name}\", value = … to the problem file"),
                        |s| format!("did you mean `{s}`?"),
                    );
                diags.push(
                    Diagnostic::error(
                        "E0712",
                        format!("`Contact Pressure Variable = {name}`: no [[nodal_field]] of that name"),
                    )
                    .help(help),
                );
                return None;
            };
            // From a file: every node read at once; else evaluated at the nodes used.
            let read = field.file.as_ref().map(|f| read_on_root(field, &dir.join(f), mesh));
            let from_file = match read {
                Some(Err((m, help))) => {
                    let k = p.nodal_field.iter().position(|f| std::ptr::eq(f, field));
                    let loc = k.and_then(|k| at.loc("nodal_field", k, "file"));
                    diags.push(Diagnostic::error("E0712", format!("[[nodal_field]] {name}: {m}")).at(loc).help(help));
                    return None;
                }
                Some(Ok(v)) => Some(v),
                None => None,
            };
            let value = field.value.clone().unwrap_or(Value::Number(0.0));
            let mut nodal = std::collections::HashMap::new();
            let mut at = |n: NodeId| -> Result<f64, String> {
                if let Some(v) = from_file.as_ref().map(|v| v[n.index()]).or(nodal.get(&n).copied()) {
                    return Ok(v);
                }
                let v = evaluate(&value, mesh.coords[n.index()], time, sandbox, "[[nodal_field]] value")?;
                nodal.insert(n, v);
                Ok(v)
            };
            let mut out = Vec::with_capacity(pairing.result.points.len());
            for q in pairing.result.points.iter() {
                let Some(fa) = q.a_face else {
                    let node = q
                        .a_node
                        .and_then(|k| pairing.side_a_geometry.nodes.get(k as usize))
                        .map(|n| n.0);
                    out.push(node.map_or(Ok(0.0), &mut at));
                    continue;
                };
                let f = &pairing.side_a_geometry.faces[fa as usize];
                let n = crate::enforce::interface::face_shape_values(f.len as usize, q.xi_a);
                let mut v = Ok(0.0);
                for (node, nk) in f.nodes.iter().zip(n).take(f.len as usize) {
                    v = v.and_then(|acc| at(*node).map(|x| acc + nk * x));
                }
                out.push(v);
            }
            match out.into_iter().collect::<Result<Vec<f64>, String>>() {
                Ok(v) => Some(v),
                Err(e) => {
                    diags.push(
                        Diagnostic::error("E0712", format!("[[nodal_field]] {name}: {e}"))
                            .help("a number or a Lua expression of x, y, z, t"),
                    );
                    None
                }
            }
        })
        .collect()
}
