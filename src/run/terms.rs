//! The contact terms of a run's solve, over its scene: the run is a host of seam's own
//! embedding API. Its interactions go into an [`Embedding`] over the run's mesh and
//! dofs (with the point pressures of the problem file, switched by its toggles, with
//! quarantine and cutbacks as their enforcements say), and the solvers take the terms
//! from it through [`Interfaces`] — the Jacobian as the embedding's CSR, refreshed in
//! place, scattered into the solver's coupling slots; the ties as its constraint rows.
//! What a solved state derives from them — the flux at each contact point, the heat of
//! each mechanism of a summed conductance, the contact faces of the output — comes
//! from the same embedding.
//!
//! The solvers order the terms contact terms first, then multiplier ties
//! ([`ContactTerms::term_choice`] maps that order to the interactions').

use std::cell::{OnceCell, Ref, RefCell};
use std::cmp::Ordering;

use rayon::prelude::*;

use crate::assembly::{Assembler, DofMap};
use crate::diag::{Diagnostic, Diagnostics};
use crate::embed::{EmbedError, Embedding, TieConstraints};
use crate::enforce::interface::{FieldPair, PointFlux};
use crate::heat::interfaces::{InterfaceFailure, Interfaces, TieRows};
use crate::mesh::NodeId;
use crate::search::pairing::{Integration, SearchSchedule};
use crate::search::scene::Pairing;
use crate::slices::filled_pieces;

use super::contact::{Couplings, RunContact};
use super::death::Death;
use super::electric_search::ElectricSearch;
use super::fields::{self, Derived};
use super::motion::Motion;
use super::physics::Physics;
use crate::enforce::electric::ElectricContact;

/// Where an entry of the embedding's CSR Jacobian goes among the solver's couplings
/// (numbered from the interfaces' first).
#[derive(Clone, Copy, Debug)]
enum Slot {
    Diagonal(usize),
    /// `(i, j)` of coupling k.
    Upper(usize),
    /// `(j, i)` of coupling k.
    Lower(usize),
}

/// The run's contact as an embedding over the solve's dofs.
struct Embedded {
    embedding: RefCell<Embedding>,
    /// The CSR pattern the slots were made for, and the slot of each entry.
    slots: RefCell<(u64, Vec<Slot>)>,
    /// The ties' rows, made once.
    ties: OnceCell<Result<Vec<TieConstraints>, String>>,
    /// The number of dofs (fields, no multipliers) it was made over.
    dofs: usize,
    /// The electrical contacts' pairings, when the surfaces move or die.
    electric: Option<RefCell<ElectricSearch>>,
}

/// The contact of a run as its solvers see it, and what its states derive from it.
pub(super) struct ContactTerms<'a> {
    physics: &'a Physics<'a>,
    pub contact: &'a RunContact,
    pub couplings: &'a Couplings,
    /// One conductivity per block, for the Nitsche weights: the law at the probe
    /// temperature.
    conductivity: Vec<f64>,
    /// The solver's term order (contact terms, then ties) → interaction index.
    pub term_choice: Vec<usize>,
    /// How many of them are flux-type terms.
    flux_count: usize,
    /// Per interaction: the names of its conductance's mechanisms (empty unless a sum).
    pub mechanism_names: Vec<Vec<String>>,
    /// Made when the solve starts, over its dofs ([`Self::prepare`]).
    embedded: OnceCell<Embedded>,
    /// The displacement that moves the contact surfaces, if any.
    motion: Option<&'a Motion>,
    /// Element death, which makes the contact surfaces again.
    death: Option<&'a Death>,
    /// What the moving surfaces did.
    moving: RefCell<Moving>,
}

/// The record of moving contact surfaces.
#[derive(Default)]
struct Moving {
    /// The last step whose due searches were done.
    searched_step: Option<u64>,
    /// Full searches (of one interaction or more) and refits, counted.
    counts: MotionCounts,
    /// The couplings the solver's pattern was last made with.
    pairs: Vec<(usize, usize)>,
    /// The pairings as the last move or search left them (made when asked for).
    current: Option<Vec<Pairing>>,
    /// How many elements were dead when the surfaces were last made.
    dead: usize,
    /// Interactions whose surfaces element death emptied: off from then on.
    gone: Vec<bool>,
}

/// The pairings of a state: the scene's, or those the surfaces' motion made.
enum Pairings<'p> {
    Scene(&'p [Pairing]),
    Moved(Ref<'p, [Pairing]>),
}

impl std::ops::Deref for Pairings<'_> {
    type Target = [Pairing];
    fn deref(&self) -> &[Pairing] {
        match self {
            Pairings::Scene(p) => p,
            Pairings::Moved(p) => p,
        }
    }
}

/// What moving contact surfaces did in a run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct MotionCounts {
    /// Full searches: the one where the run starts, then each step at which the
    /// schedule of some interaction was due (`Update Search Every n Steps`).
    pub searches: usize,
    /// Placements of the points on the moved faces with the pairing kept.
    pub refits: usize,
    /// Times the solver made its pattern again because a search changed the couplings.
    pub repatterns: usize,
    /// Times element death made the contact surfaces again.
    pub surface_updates: usize,
}

impl<'a> ContactTerms<'a> {
    /// The terms of `contact` with the `couplings` of the problem file.
    pub(super) fn new(
        physics: &'a Physics<'a>,
        contact: &'a RunContact,
        couplings: &'a Couplings,
        (motion, death): (Option<&'a Motion>, Option<&'a Death>),
    ) -> Self {
        // The embedding's interactions: the energy ones, then the species interfaces,
        // then the voltage ties.
        let mortar: Vec<bool> = (contact.choices.iter().map(|c| c.0.mortar))
            .chain(contact.species.iter().map(|s| s.choice.mortar))
            .chain(contact.voltage_ties.iter().map(|s| s.choice.mortar))
            .collect();
        let choices = &contact.choices;
        let term_choice: Vec<usize> = (0..mortar.len())
            .filter(|&k| !mortar[k])
            .chain((0..mortar.len()).filter(|&k| mortar[k]))
            .collect();
        let mechanism_names = choices
            .iter()
            .map(|(_, _, m)| {
                m.as_ref()
                    .map_or_else(Vec::new, |m| fields::mechanism_names(m.as_ref()))
            })
            .collect();
        ContactTerms {
            physics,
            contact,
            couplings,
            conductivity: physics.conductivity(),
            flux_count: mortar.iter().filter(|m| !**m).count(),
            term_choice,
            mechanism_names,
            embedded: OnceCell::new(),
            motion,
            death,
            moving: RefCell::new(Moving {
                gone: vec![false; mortar.len()],
                ..Moving::default()
            }),
        }
    }

    /// Per mesh element its death time, when elements die.
    pub(super) fn death_times(&self) -> Option<&'a [f64]> {
        self.death.map(|d| d.times.as_slice())
    }

    /// What the moving surfaces did (all zero when nothing moves).
    pub(super) fn motion_counts(&self) -> Option<MotionCounts> {
        (self.motion.is_some() || self.death.is_some()).then(|| self.moving.borrow().counts)
    }

    /// The pairings as they are now: as the scene found them, or, when the surfaces
    /// move, as the last move or search of the embedding left them.
    fn pairings(&self) -> Result<Pairings<'_>, String> {
        if self.motion.is_none() && self.death.is_none() {
            return Ok(Pairings::Scene(&self.contact.pairings));
        }
        if self.moving.borrow().current.is_none() {
            let e = self.embedded().map_err(|e| e.to_string())?;
            let embedding = e.embedding.borrow();
            let mut now = Vec::with_capacity(self.contact.pairings.len());
            for (k, p) in self.contact.pairings.iter().enumerate() {
                let (a, b, result) = embedding.pairing_of(k).ok_or_else(|| {
                    format!("interaction {} / {} not searched", p.side_a, p.side_b)
                })?;
                now.push(Pairing {
                    side_a_geometry: a.clone(),
                    side_b_geometry: b.clone(),
                    result: result.clone(),
                    ..p.clone()
                });
            }
            self.moving.borrow_mut().current = Some(now);
        }
        Ok(Pairings::Moved(Ref::map(self.moving.borrow(), |m| {
            m.current.as_deref().expect("just made")
        })))
    }

    /// The surfaces placed at time `t`, and the interactions whose schedule is due at
    /// `step` searched anew (once per step), the electrical contacts' with them. True
    /// when the couplings changed.
    fn place(&self, e: &Embedded, u: &[f64], t: f64, step: u64) -> Result<bool, InterfaceFailure> {
        if self.motion.is_none() && self.death.is_none() {
            return Ok(false);
        }
        let mut moving = self.moving.borrow_mut();
        let coords = match self.motion {
            Some(motion) => Some(motion.coords_at(t).map_err(InterfaceFailure::Failed)?),
            None => None,
        };
        // A step taken again (a cutback, a new pattern) is placed again, not searched
        // or counted again.
        let again = moving.searched_step == Some(step);
        let due = |schedule: SearchSchedule| {
            !again && self.motion.is_some() && schedule.full_search(step)
        };
        // Element death makes the surfaces again (by each definition's rules), and
        // they are searched.
        let mut sets = None;
        if let Some(death) = self.death {
            let dead = death.dead_at(t);
            if dead.len() != moving.dead {
                let mesh = self.physics.mesh;
                sets = Some(crate::scene::ContactScene::surfaces(
                    mesh,
                    &self.contact.loaded,
                    &dead,
                ));
                moving.dead = dead.len();
                moving.counts.surface_updates += 1;
            }
        }
        let mut searched = false;
        {
            let mut embedding = e.embedding.borrow_mut();
            if let Some(coords) = &coords {
                embedding.move_nodes(coords).map_err(failure)?;
            }
            // Every interaction of the embedding: the Energy ones, then the species
            // interfaces and voltage ties.
            let mut search: Vec<usize> = (0..self.term_choice.len())
                .filter(|&k| due(self.schedule(k)))
                .collect();
            if let Some(sets) = &sets {
                let remade =
                    remake_surfaces(&mut embedding, sets, self.interactions(), &mut moving.gone)?;
                search.extend(remade);
                search.sort_unstable();
                search.dedup();
            }
            search.retain(|&k| !moving.gone.get(k).copied().unwrap_or(false));
            if !search.is_empty() {
                embedding.search_some(&search).map_err(failure)?;
                searched = true;
                log::debug!(
                    "step {step}, t = {t}: {} interaction(s) searched anew",
                    search.len()
                );
            }
        }
        if let Some(electric) = &e.electric {
            let every = &self.contact.electrical_every;
            let due = |k: usize| due(SearchSchedule::new(every[k]));
            searched |= electric.borrow_mut().place(
                self.contact,
                coords.as_deref(),
                sets.as_deref(),
                &due,
            )?;
        }
        moving.searched_step = Some(step);
        if searched {
            moving.counts.searches += 1;
        } else if !again && self.motion.is_some() {
            moving.counts.refits += 1;
        }
        moving.current = None;
        if step == 0 {
            // The solver asks for the couplings as it starts.
            return Ok(false);
        }
        let before = std::mem::take(&mut moving.pairs);
        drop(moving);
        let after = self.couplings(u, t)?;
        let changed = after != before;
        if changed {
            self.moving.borrow_mut().counts.repatterns += 1;
        }
        Ok(changed)
    }

    /// The embedding's interactions in its order, each with its definition: the Energy
    /// ones, then the species interfaces and voltage ties.
    fn interactions(&self) -> impl Iterator<Item = (&Pairing, usize)> {
        let fields = (self.contact.species.iter()).chain(&self.contact.voltage_ties);
        (self.contact.pairings.iter())
            .zip(self.contact.definition.iter().copied())
            .chain(fields.map(|f| (&f.pairing, f.definition)))
    }

    /// The search schedule of interaction `k`'s definition.
    /// The search schedule of embedding interaction `k`: an Energy interaction's, or
    /// a species interface's or voltage tie's (after them).
    fn schedule(&self, k: usize) -> SearchSchedule {
        let energy = self.contact.search_every.len();
        let species = self.contact.species.len();
        let every = match k.checked_sub(energy) {
            None => self.contact.search_every[k],
            Some(s) if s < species => self.contact.species[s].search_every,
            Some(s) => (self.contact.voltage_ties.get(s - species)).and_then(|v| v.search_every),
        };
        SearchSchedule::new(every)
    }

    /// Hand the run's interactions to an embedding over the solve's `dofs` (the fields,
    /// before any multiplier), with the Dirichlet nodes at the start fixed; once.
    pub(super) fn prepare(&self, dofs: &DofMap) -> Result<&dyn Interfaces, String> {
        self.prepare_on(self.physics.mesh, None, dofs)
    }

    /// As [`Self::prepare`], over `mesh` — the physics' mesh, or on a rank holding a part
    /// of it that part with the side-B elements of other ranks its points paired with,
    /// whose block `b` copies block `origin[b]`.
    pub(super) fn prepare_on(
        &self,
        mesh: &crate::mesh::Mesh,
        origin: Option<&[usize]>,
        dofs: &DofMap,
    ) -> Result<&dyn Interfaces, String> {
        match self.embedded.get() {
            None => {
                let made = self.embed(mesh, origin, dofs)?;
                let e = self.embedded.get_or_init(|| made);
                // Moving surfaces start where the displacement puts them at the start.
                self.place(e, &[], self.physics.time.start, 0)
                    .map_err(|e| e.to_string())?;
            }
            Some(e) if e.dofs != dofs.len() => {
                return Err(format!(
                    "the contact terms were made for {} dofs, the solve has {}",
                    e.dofs,
                    dofs.len()
                ));
            }
            Some(_) => {}
        }
        Ok(self)
    }

    fn embed(
        &self,
        mesh: &crate::mesh::Mesh,
        origin: Option<&[usize]>,
        dofs: &DofMap,
    ) -> Result<Embedded, String> {
        let physics = self.physics;
        let fixed: Vec<NodeId> = physics
            .loads_at(physics.time.start)?
            .dirichlet
            .iter()
            .map(|&(n, _)| n)
            .collect();
        // A search anew integrates as the scene's first search did.
        let integration = (self.contact.integration).unwrap_or(Integration::Segments { order: 5 });
        let mut embedding = Embedding::over_dofs(
            mesh.clone(),
            dofs.clone(),
            super::solve::per_block(&self.conductivity, origin),
            fixed,
            integration,
        );
        // A conductivity that is not one number (of T, or of x by Lua): the Nitsche forms
        // take it at each point's temperature and position.
        let laws: Vec<crate::heat::law::Law> = (physics.materials.laws.iter())
            .map(|l| l.conductivity.clone())
            .collect();
        let laws = super::solve::per_block(&laws, origin);
        if laws
            .iter()
            .any(|l| !matches!(l, crate::heat::law::Law::Constant(_)))
        {
            embedding.set_conductivity_law(std::sync::Arc::new(move |b, t, x, time| {
                laws[b].eval(t, x, time)
            }));
        }
        let field = |i: usize| {
            let name = &physics.field_names[i];
            dofs.field(name)
                .ok_or_else(|| format!("no dofs of field `{name}`"))
        };
        let (pairings, choices) = (&self.contact.pairings, &self.contact.choices);
        for (k, (p, (c, scale, model))) in pairings.iter().zip(choices).enumerate() {
            let (fa, fb) = self.couplings.fields[k];
            let fields = FieldPair {
                a: field(fa)?,
                b: field(fb)?,
            };
            let again = self
                .contact
                .again
                .borrow_mut()
                .get_mut(k)
                .and_then(Option::take);
            embedding.add_resolved(p.clone(), (c, *scale), model.clone(), again, fields);
            if let Some(v) = &self.couplings.pressures[k] {
                embedding
                    .set_point_pressures(k, Some(v.clone()))
                    .map_err(|e| e.to_string())?;
            }
        }
        // D(T) and σ(T) weigh the species and voltage forms at each point's temperature.
        let temperature = dofs
            .field(crate::heat::TEMPERATURE)
            .ok_or("no dofs of field `temperature`");
        let species = &physics.species;
        if !self.contact.species.is_empty() {
            let field = dofs
                .field(crate::heat::species::SPECIES)
                .ok_or("no dofs of field `species`")?;
            let coefficient = species.coefficient(physics.probe, physics.time.start);
            let fixed: Vec<NodeId> = species.dirichlet.iter().map(|&(n, _)| n).collect();
            embedding.set_fixed_of(field, fixed);
            for s in &self.contact.species {
                let s_a = species.side_a_scale(physics.mesh, s)?;
                let (choice, model) = s.scaled(s_a);
                let k = embedding.add_resolved(
                    s.pairing.clone(),
                    (&choice, s.penalty_scale),
                    model,
                    s.again.borrow_mut().take(),
                    field.into(),
                );
                embedding.set_coefficient(k, coefficient.clone());
                let law = field_law(&species.scaled_diffusivity());
                embedding.set_temperature_of(k, temperature?, law);
            }
        }
        if !self.contact.voltage_ties.is_empty() {
            let field = dofs
                .field(crate::heat::electric::VOLTAGE)
                .ok_or("no dofs of field `voltage`")?;
            // The Nitsche forms weigh the jump with σ at the probe temperature.
            let (probe, t0) = (physics.probe, physics.time.start);
            let coefficient: Vec<f64> = (physics.materials.sigma.iter())
                .map(|s| {
                    s.as_ref()
                        .and_then(|s| s.eval(probe, [0.0; 3], t0).ok())
                        .map_or(1.0, |v| v.0)
                })
                .collect();
            let fixed: Vec<NodeId> = physics.voltage.iter().map(|&(n, _)| n).collect();
            embedding.set_fixed_of(field, fixed);
            for v in &self.contact.voltage_ties {
                let k = embedding.add_resolved(
                    v.pairing.clone(),
                    (&v.choice, v.penalty_scale),
                    v.model.clone(),
                    v.again.borrow_mut().take(),
                    field.into(),
                );
                embedding.set_coefficient(k, coefficient.clone());
                let law = field_law(&physics.materials.sigma);
                embedding.set_temperature_of(k, temperature?, law);
            }
        }
        let moves = self.motion.is_some() || self.death.is_some();
        let electric = match moves {
            true => ElectricSearch::new(
                self.contact,
                physics.mesh,
                dofs,
                field(0)?.into(),
                integration,
            ),
            false => None,
        };
        Ok(Embedded {
            embedding: RefCell::new(embedding),
            slots: RefCell::new((0, Vec::new())),
            ties: OnceCell::new(),
            dofs: dofs.len(),
            electric: electric.map(RefCell::new),
        })
    }

    fn embedded(&self) -> Result<&Embedded, InterfaceFailure> {
        self.embedded.get().ok_or_else(|| {
            InterfaceFailure::Failed(
                "the contact terms were asked for before the solve's dofs".into(),
            )
        })
    }

    /// The embedding at time `t`, each interaction switched as its toggle says.
    fn at_time(&self, e: &Embedded, t: f64) -> Result<(), InterfaceFailure> {
        let mut embedding = e.embedding.borrow_mut();
        embedding.set_time(t).map_err(failure)?;
        let moving = self.moving.borrow();
        for k in 0..self.term_choice.len() {
            let gone = moving.gone.get(k).copied().unwrap_or(false);
            embedding
                .set_active(k, self.couplings.on(k, t) && !gone)
                .map_err(failure)?;
        }
        Ok(())
    }

    /// The flux terms' heat (in the solver's order) from the embedding's per-interaction
    /// heat.
    fn flux_heat(&self, heat: &[Option<crate::embed::Heat>]) -> Vec<(f64, f64)> {
        self.term_choice[..self.flux_count]
            .iter()
            .map(|&k| heat[k].map_or((0.0, 0.0), |h| (h.side_a, h.side_b)))
            .collect()
    }

    /// The ties' rows as the embedding makes them (once).
    fn ties_of(e: &Embedded) -> Result<&[TieConstraints], String> {
        e.ties
            .get_or_init(|| {
                e.embedding
                    .borrow()
                    .tie_rows(false)
                    .map_err(|e| e.to_string())
            })
            .as_deref()
            .map_err(Clone::clone)
    }

    /// What a state gives beyond its temperature: per interaction the flux at its points
    /// (where the contact output or a mechanism split needs it; `faces` asks for the
    /// contact output) and the heat of each mechanism.
    pub(super) fn derive(
        &self,
        u: &[f64],
        dofs: &DofMap,
        time: f64,
        faces: bool,
    ) -> Result<Derived, String> {
        let pairings = self.pairings()?;
        let (choices, views) = (&self.contact.choices, &self.contact.views);
        let pressures = &self.couplings.pressures;
        let mut out = Derived::default();
        let e = self.embedded().map_err(|e| e.to_string())?;
        self.at_time(e, time).map_err(|e| e.to_string())?;
        let named = |p: &crate::search::scene::Pairing, e: EmbedError| {
            format!("interaction {} / {}: {e}", p.side_a, p.side_b)
        };
        for (k, (p, (c, _, model))) in pairings.iter().zip(choices).enumerate() {
            let split = !self.mechanism_names[k].is_empty();
            let on = self.couplings.on(k, time);
            if c.mortar && faces && views[k].faces {
                // A multiplier tie: the flux is its multiplier field λ_h at the points.
                let ties = Self::ties_of(e)?;
                let t = choices[..k].iter().filter(|(c, _, _)| c.mortar).count();
                let (Some(tie), Some(range)) = (ties.get(t), dofs.extra_ranges().get(t)) else {
                    return Err(format!(
                        "interaction {} / {}: no multipliers in the state",
                        p.side_a, p.side_b
                    ));
                };
                let q = tie
                    .multiplier_field(&u[range.clone()], p.result.points.len())
                    .map_err(|e| named(p, e))?
                    .into_iter()
                    .map(|q| {
                        q.map(|q| PointFlux {
                            q: if on { q } else { 0.0 },
                            temp_a: f64::NAN,
                            temp_b: f64::NAN,
                        })
                    })
                    .collect();
                out.fluxes.push(Some(q));
                out.mechanisms.push(Vec::new());
                continue;
            }
            if c.mortar || !(split || (faces && views[k].faces)) {
                out.fluxes.push(None);
                out.mechanisms.push(Vec::new());
                continue;
            }
            // The points keep their places while the interaction is off; their flux is 0.
            let q = e.embedding.borrow().point_flux(k, u);
            let mut q = q.map_err(|e| named(p, e))?;
            if !on {
                q.iter_mut().flatten().for_each(|f| f.q = 0.0);
            }
            let mechanisms = match model {
                Some(m) if split => fields::mechanism_heat(
                    m.as_ref(),
                    p,
                    &q,
                    |i| pressures[k].as_ref().map_or(c.pressure, |v| v[i]),
                    time,
                ),
                _ => Vec::new(),
            };
            out.fluxes.push(Some(q));
            out.mechanisms.push(mechanisms);
        }
        Ok(out)
    }

    /// The contact faces of a derived state, when some interaction visualises contact.
    pub(super) fn contact_of(&self, d: &Derived) -> Option<fields::ContactFields> {
        let views = &self.contact.views;
        if !views.iter().any(|v| v.faces) {
            return None;
        }
        let pairings = self.pairings().ok()?;
        let mut out = fields::ContactFields::default();
        for (k, p) in pairings.iter().enumerate().filter(|(k, _)| views[*k].faces) {
            fields::contact_faces(
                p,
                k as u32 + 1,
                d.fluxes[k].as_deref(),
                views[k].side_b,
                &mut out,
            );
        }
        Some(out)
    }

    /// The energy interactions in the solver's term order (the species interfaces, after
    /// them in the embedding, left out).
    fn energy_terms(&self) -> impl Iterator<Item = usize> + '_ {
        let energy = self.contact.choices.len();
        self.term_choice
            .iter()
            .copied()
            .filter(move |&k| k < energy)
    }

    /// How many of the energy terms are flux terms (the rest are ties).
    pub(super) fn energy_flux_count(&self) -> usize {
        let energy = self.contact.choices.len();
        self.term_choice[..self.flux_count]
            .iter()
            .filter(|&&k| k < energy)
            .count()
    }

    /// A step's heat per solver term split into the energy terms' (kept in `heat`, in
    /// their order), the species interfaces' mass flux (in the order of
    /// `contact.species`: mol/s leaving side A, leaving side B) and the voltage ties'
    /// current (in the order of `contact.voltage_ties`: A leaving side A, side B).
    pub(super) fn split_fields(&self, heat: &mut Vec<(f64, f64)>) -> [Vec<(f64, f64)>; 2] {
        let energy = self.contact.choices.len();
        let species = self.contact.species.len();
        let mut out = [
            vec![(f64::NAN, f64::NAN); species],
            vec![(f64::NAN, f64::NAN); self.contact.voltage_ties.len()],
        ];
        let mut kept = Vec::with_capacity(heat.len());
        for (&k, &h) in self.term_choice.iter().zip(heat.iter()) {
            match k.checked_sub(energy) {
                Some(s) if s < species => out[0][s] = h,
                Some(s) => out[1][s - species] = h,
                None => kept.push(h),
            }
        }
        *heat = kept;
        out
    }

    /// The electrical contacts' and voltage ties' (side A, side B) names, in the order
    /// of a step's `electric` powers once [`Self::split_fields`] has added the ties'.
    pub(super) fn electrical_labels(&self) -> Vec<(&str, &str)> {
        let contacts = self.contact.electrical.iter();
        let contacts = contacts.map(|e| (e.side_a.as_str(), e.side_b.as_str()));
        let ties = self.contact.voltage_ties.iter();
        let ties = ties.map(|t| (t.pairing.side_a.as_str(), t.pairing.side_b.as_str()));
        contacts.chain(ties).collect()
    }

    /// Mechanism heats in the solver's term order.
    pub(super) fn term_mechanisms(&self, d: &Derived) -> Vec<Vec<f64>> {
        self.energy_terms()
            .map(|k| d.mechanisms[k].clone())
            .collect()
    }

    /// Per solver term, (side A, side B) surface names.
    pub(super) fn term_sides(&self) -> Vec<(&str, &str)> {
        self.energy_terms()
            .map(|k| {
                let p = &self.contact.pairings[k];
                (p.side_a.as_str(), p.side_b.as_str())
            })
            .collect()
    }

    /// Per solver term, (side A, side B, model) for the heat histories.
    pub(super) fn term_labels(&self) -> Vec<(String, String, String)> {
        self.energy_terms()
            .map(|k| {
                let p = &self.contact.pairings[k];
                (
                    p.side_a.clone(),
                    p.side_b.clone(),
                    self.contact.choices[k].0.name.clone(),
                )
            })
            .collect()
    }

    /// Per solver term, the names of its conductance's mechanisms.
    pub(super) fn term_mechanism_names(&self) -> Vec<Vec<String>> {
        self.energy_terms()
            .map(|k| self.mechanism_names[k].clone())
            .collect()
    }

    /// A warning per interaction whose model failed at some points (quarantined).
    pub(super) fn report_quarantined(&self, diags: &mut Diagnostics) {
        let Some(e) = self.embedded.get() else {
            return;
        };
        let embedding = e.embedding.borrow();
        let contact = self.contact;
        for (k, (p, (c, _, _))) in contact.pairings.iter().zip(&contact.choices).enumerate() {
            let kept = embedding.quarantined(k);
            if let Some(first) = kept.first() {
                let x = first.x;
                diags.push(
                    Diagnostic::warning(
                        "W0501",
                        format!(
                            "interaction {} / {} ({}): {} point(s) quarantined; the first at ({:.6}, {:.6}, {:.6}): {}",
                            p.side_a, p.side_b, c.name, kept.len(), x[0], x[1], x[2], first.message
                        ),
                    )
                    .help("the conductance model failed there; those points carry no heat"),
                );
            }
        }
    }
}

/// A failure of the embedding as the solvers take it: a cutback request retries the
/// step; a model that failed at a point names it, and how to go past such points.
pub(super) fn failure(e: EmbedError) -> InterfaceFailure {
    match e {
        EmbedError::Cutback { .. } => InterfaceFailure::Cutback(e.to_string()),
        EmbedError::Plugin { .. } => InterfaceFailure::Failed(format!(
            "{}: {e} (add `Quarantine Faulty Points` to the enforcement to skip such points)",
            super::PLUGIN_FAULT
        )),
        EmbedError::Enforcement { .. } => InterfaceFailure::Failed(format!(
            "{e} (add `Quarantine Faulty Points` to the enforcement to skip such points)"
        )),
        e => InterfaceFailure::Failed(e.to_string()),
    }
}

impl Interfaces for ContactTerms<'_> {
    fn flux_count(&self) -> usize {
        self.flux_count
    }

    fn is_linear(&self) -> bool {
        // A conductance independent of T keeps the system linear and symmetric.
        let species = self.contact.species.iter().map(|s| (&s.choice, &s.model));
        let ties = self
            .contact
            .voltage_ties
            .iter()
            .map(|s| (&s.choice, &s.model));
        (self.contact.choices.iter().map(|(c, _, m)| (c, m)))
            .chain(species)
            .chain(ties)
            .all(|(c, m)| c.mortar || m.as_ref().is_none_or(|m| !m.depends_on_temperature()))
    }

    fn ties(&self) -> Result<Vec<TieRows>, String> {
        let e = self.embedded().map_err(|e| e.to_string())?;
        Ok(Self::ties_of(e)?.iter().map(TieRows::from).collect())
    }

    fn own_ties(&self, carries: &dyn Fn(usize, NodeId) -> bool) -> Result<Vec<TieRows>, String> {
        let e = self.embedded().map_err(|e| e.to_string())?;
        let rows = e.embedding.borrow().own_tie_rows(carries);
        Ok(rows
            .map_err(|e| e.to_string())?
            .iter()
            .map(TieRows::from)
            .collect())
    }

    fn tie_on(&self, k: usize, t: f64) -> bool {
        self.couplings.on(self.term_choice[self.flux_count + k], t)
    }

    fn flux_on(&self, k: usize, t: f64) -> bool {
        self.couplings.on(self.term_choice[k], t)
    }

    fn couplings(&self, u: &[f64], t: f64) -> Result<Vec<(usize, usize)>, InterfaceFailure> {
        let e = self.embedded()?;
        self.at_time(e, t)?;
        let mut embedding = e.embedding.borrow_mut();
        // The structure only: `assemble` evaluates the terms into it.
        let ev = embedding.pattern(u.len()).map_err(failure)?;
        let (pattern, j) = (ev.pattern, &ev.jacobian);
        // Coupling c is the c-th entry right of the diagonal in row order; (j, i) is
        // the transpose of (i, j). Rows are sorted, so a row's couplings are its tail.
        let (offsets, columns) = (&j.row_offsets, &j.columns);
        // Where each row's couplings start, and how many rows before it hold.
        let upper: Vec<usize> = (0..j.n)
            .into_par_iter()
            .map(|i| {
                let row = &columns[offsets[i]..offsets[i + 1]];
                offsets[i] + row.partition_point(|&c| c <= i)
            })
            .collect();
        let mut start: Vec<usize> = (0..j.n).map(|i| offsets[i + 1] - upper[i]).collect();
        let mut total = 0;
        for s in start.iter_mut() {
            (*s, total) = (total, total + *s);
        }
        // Pairs and slots written in place, row by row in parallel.
        let mut pairs = vec![(0, 0); total];
        let rows = filled_pieces(&mut pairs, (0..j.n).map(|i| offsets[i + 1] - upper[i]));
        rows.into_par_iter().for_each(|(i, to)| {
            for (p, &c) in to.iter_mut().zip(&columns[upper[i]..offsets[i + 1]]) {
                *p = (i, c);
            }
        });
        // Every entry gets a slot: (i, i) its diagonal, (i, j) a coupling or its
        // transpose (the structure is symmetric: each block is dofs × dofs); `None`
        // for an entry whose transpose is missing.
        let mut slots = vec![None; columns.len()];
        let rows = filled_pieces(&mut slots, offsets.windows(2).map(|w| w[1] - w[0]));
        rows.into_par_iter().for_each(|(i, to)| {
            let a = offsets[i];
            for (k, (t, &c)) in to.iter_mut().zip(&columns[a..offsets[i + 1]]).enumerate() {
                *t = match c.cmp(&i) {
                    Ordering::Equal => Some(Slot::Diagonal(i)),
                    Ordering::Greater => Some(Slot::Upper(start[i] + a + k - upper[i])),
                    Ordering::Less => {
                        let transposed = &columns[upper[c]..offsets[c + 1]];
                        (transposed.binary_search(&i).ok()).map(|at| Slot::Lower(start[c] + at))
                    }
                };
            }
        });
        let slots: Option<Vec<Slot>> = slots.into_iter().collect();
        let slots = slots.ok_or_else(|| {
            InterfaceFailure::Failed("an interface Jacobian entry without a place".into())
        })?;
        *e.slots.borrow_mut() = (pattern, slots);
        drop(embedding);
        self.moving.borrow_mut().pairs = pairs.clone();
        Ok(pairs)
    }

    fn assemble(
        &self,
        u: &[f64],
        t: f64,
        r: &mut [f64],
        asm: &mut Assembler<'_>,
        first: usize,
    ) -> Result<Vec<(f64, f64)>, InterfaceFailure> {
        let e = self.embedded()?;
        self.at_time(e, t)?;
        let mut embedding = e.embedding.borrow_mut();
        let ev = embedding.evaluate(u).map_err(failure)?;
        let slots = e.slots.borrow();
        if ev.pattern != slots.0 || ev.jacobian.values.len() != slots.1.len() {
            return Err(InterfaceFailure::Failed(
                "the interface pattern changed during the solve".into(),
            ));
        }
        for (&slot, &v) in slots.1.iter().zip(&ev.jacobian.values) {
            match slot {
                Slot::Diagonal(i) => asm.add_diagonal(i, v),
                Slot::Upper(c) => asm.add_coupling(first + c, v, 0.0),
                Slot::Lower(c) => asm.add_coupling(first + c, 0.0, v),
            }
        }
        for (ri, v) in r.iter_mut().zip(&ev.residual) {
            *ri += v;
        }
        Ok(self.flux_heat(&ev.heat))
    }

    fn residual(
        &self,
        u: &[f64],
        t: f64,
        r: &mut [f64],
    ) -> Result<Option<Vec<(f64, f64)>>, InterfaceFailure> {
        let e = self.embedded()?;
        self.at_time(e, t)?;
        let heat = e.embedding.borrow().residual_into(u, r).map_err(failure)?;
        Ok(Some(self.flux_heat(&heat)))
    }

    fn heat(&self, u: &[f64], t: f64) -> Result<Vec<(f64, f64)>, InterfaceFailure> {
        let e = self.embedded()?;
        self.at_time(e, t)?;
        let heat = e.embedding.borrow().heat(u).map_err(failure)?;
        Ok(self.flux_heat(&heat))
    }

    fn advance(&self, u: &[f64], t: f64, step: u64) -> Result<bool, InterfaceFailure> {
        let e = self.embedded()?;
        self.at_time(e, t)?;
        self.place(e, u, t, step)
    }

    fn own_points(
        &self,
        owns: Option<&dyn Fn(Option<crate::mesh::ElemId>, Option<NodeId>) -> bool>,
    ) -> Result<(), InterfaceFailure> {
        self.embedded()?.embedding.borrow_mut().own_points(owns);
        Ok(())
    }

    fn electric_contacts(&self) -> Result<Option<Vec<ElectricContact>>, InterfaceFailure> {
        match &self.embedded()?.electric {
            Some(electric) => electric.borrow().contacts(self.contact).map(Some),
            None => Ok(None),
        }
    }
}

/// The surfaces of `interactions` (the embedding's, in its order, each with its
/// definition) made again from `sets` (each definition's surfaces without the dead
/// elements); an interaction left without faces on a side is gone. The interactions to
/// search.
pub(super) fn remake_surfaces<'p>(
    embedding: &mut Embedding,
    sets: &[(Option<String>, crate::surface::SurfaceSet)],
    interactions: impl Iterator<Item = (&'p Pairing, usize)>,
    gone: &mut [bool],
) -> Result<Vec<usize>, InterfaceFailure> {
    let mut out = Vec::new();
    for (k, (p, definition)) in interactions.enumerate() {
        if gone[k] {
            continue;
        }
        let set = &sets[definition].1;
        let side_a = &set.surfaces[p.side_a_surface];
        let side_b = &set.surfaces[p.side_b_surface];
        if side_a.faces.is_empty() && side_a.nodes.is_empty() || side_b.faces.is_empty() {
            log::info!(
                "interaction {} / {}: element death left a side without faces; it is off from now on",
                p.side_a,
                p.side_b
            );
            gone[k] = true;
            continue;
        }
        embedding
            .replace_surfaces(k, side_a.clone(), side_b.clone())
            .map_err(failure)?;
        out.push(k);
    }
    Ok(out)
}

/// A per-block coefficient law (D S or σ; 1 where a block has none) as the embedding takes
/// it, when some block's law is not one number.
fn field_law(
    laws: &[Option<crate::heat::law::Law>],
) -> Option<std::sync::Arc<crate::embed::ConductivityOfT>> {
    use crate::heat::law::Law;
    if laws.iter().flatten().all(|l| matches!(l, Law::Constant(_))) {
        return None;
    }
    let laws = laws.to_vec();
    Some(std::sync::Arc::new(move |b, t, x, time| match &laws[b] {
        Some(law) => law.eval(t, x, time),
        None => Ok((1.0, 0.0)),
    }))
}
