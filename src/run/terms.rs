//! The contact terms of a run's solve, over its scene: per interaction the conductance as
//! the interface forms see it (the model at the point's gap, temperatures and pressure,
//! with quarantine and cutbacks), the terms and ties the solvers assemble, and what a
//! solved state derives from them — the flux at each contact point, the heat of each
//! mechanism of a summed conductance, the contact faces of the output.
//!
//! The solvers order the terms contact terms first, then multiplier ties
//! ([`ContactTerms::term_choice`] maps that order to the interactions').

use std::cell::{Cell, OnceCell, RefCell};

use crate::assembly::DofMap;
use crate::diag::{Diagnostic, Diagnostics};
use crate::enforce::conductance::PointState;
use crate::enforce::interface::{
    DEFAULT_BETA, HFn, HInput, HValue, InterfaceError, InterfaceForm, InterfacePoints, PointFlux,
};
use crate::enforce::mortar::MortarTie;
use crate::heat::steady::{ContactTerm, TieTerm};
use crate::mesh::{Mesh, NodeId};
use crate::search::scene::Pairing;

use super::contact::{Choice, Couplings, RunContact};
use super::fields::{self, Derived};
use super::physics::Physics;

/// Per interaction, the points a conductance model failed at, with the reason.
type Quarantined = RefCell<Vec<([f64; 3], String)>>;

/// What the conductance models of a run share while it runs: the time they see (set by
/// the solver through the loads), a smaller step one asked for, and per interaction the
/// points quarantined.
pub(super) struct ModelState {
    clock: Cell<f64>,
    cutback: Cell<bool>,
    quarantined: Vec<Quarantined>,
}

impl ModelState {
    /// At time `start`, for `interactions` interactions.
    pub(super) fn new(start: f64, interactions: usize) -> Self {
        ModelState {
            clock: Cell::new(start),
            cutback: Cell::new(false),
            quarantined: (0..interactions).map(|_| Default::default()).collect(),
        }
    }
}

/// The contact of a run as its solvers see it, and what its states derive from it.
pub(super) struct ContactTerms<'a> {
    mesh: &'a Mesh,
    physics: &'a Physics<'a>,
    pub contact: &'a RunContact,
    pub couplings: &'a Couplings,
    models: &'a ModelState,
    /// One conductivity per block, for the Nitsche weights: the law at the probe
    /// temperature.
    conductivity: Vec<f64>,
    /// Per interaction, its conductance model seen by the interface forms: the point's
    /// gap and temperatures and the enforcement's contact pressure in, h and dh/dT out.
    h_fns: Vec<Box<HFn<'a>>>,
    /// The solver's term order (contact terms, then ties) → interaction index.
    pub term_choice: Vec<usize>,
    /// Per interaction: the names of its conductance's mechanisms (empty unless a sum).
    pub mechanism_names: Vec<Vec<String>>,
    /// The mortar ties as the solver built them, for their multipliers' fluxes (made at
    /// the first state that asks).
    tie_geometry: OnceCell<Result<Vec<MortarTie>, String>>,
    /// Per interaction, the geometry at its points, for the point fluxes.
    point_geometry: Vec<OnceCell<Result<InterfacePoints, String>>>,
}

impl<'a> ContactTerms<'a> {
    /// The terms of `contact` with the `couplings` of the problem file, their
    /// conductances sharing `models`.
    pub(super) fn new(
        physics: &'a Physics<'a>,
        contact: &'a RunContact,
        couplings: &'a Couplings,
        models: &'a ModelState,
    ) -> Self {
        let choices = &contact.choices;
        let h_fns = choices
            .iter()
            .zip(&models.quarantined)
            .zip(&contact.pairings)
            .zip(&couplings.pressures)
            .map(|(((choice, log), pairing), at_points)| {
                conductance(choice, log, pairing, at_points, models)
            })
            .collect();
        let term_choice: Vec<usize> = (0..choices.len())
            .filter(|&k| !choices[k].0.mortar)
            .chain((0..choices.len()).filter(|&k| choices[k].0.mortar))
            .collect();
        let mechanism_names = choices
            .iter()
            .map(|(_, _, m)| {
                m.as_ref()
                    .map_or_else(Vec::new, |m| fields::mechanism_names(m.as_ref()))
            })
            .collect();
        ContactTerms {
            mesh: physics.mesh,
            physics,
            contact,
            couplings,
            models,
            conductivity: physics.conductivity(),
            h_fns,
            term_choice,
            mechanism_names,
            tie_geometry: Default::default(),
            point_geometry: contact
                .pairings
                .iter()
                .map(|_| Default::default())
                .collect(),
        }
    }

    /// The flux-type terms (every interaction but the multiplier ties).
    pub(super) fn contact_terms(&self) -> Vec<ContactTerm<'_>> {
        let conductivity = &self.conductivity;
        self.contact
            .pairings
            .iter()
            .zip(&self.contact.choices)
            .zip(&self.h_fns)
            .filter(|((_, (c, _, _)), _)| !c.mortar)
            .map(|((p, (c, scale, model)), h)| ContactTerm {
                side_a: &p.side_a_geometry,
                side_b: &p.side_b_geometry,
                points: &p.result.points,
                form: InterfaceForm {
                    form: c.form,
                    h: h.as_ref(),
                    offset: c.offset,
                    beta: c.penalty_factor.unwrap_or(DEFAULT_BETA) * scale,
                    conductivity,
                },
                // A conductance independent of T keeps the system linear and symmetric.
                linear: model.as_ref().is_none_or(|m| !m.depends_on_temperature()),
            })
            .collect()
    }

    /// The multiplier (mortar) ties.
    pub(super) fn tie_terms(&self) -> Vec<TieTerm<'_>> {
        self.contact
            .pairings
            .iter()
            .zip(&self.contact.choices)
            .filter(|(_, (c, _, _))| c.mortar)
            .map(|(p, (c, _, _))| TieTerm {
                side_a: &p.side_a_geometry,
                side_b: &p.side_b_geometry,
                points: &p.result.points,
                offset: c.offset,
                multipliers: if c.dual {
                    crate::enforce::mortar::Multipliers::Dual
                } else {
                    crate::enforce::mortar::Multipliers::Standard
                },
            })
            .collect()
    }

    /// The time the conductance models see.
    pub(super) fn set_time(&self, t: f64) {
        self.models.clock.set(t);
    }

    /// Set by a conductance model that asks for a smaller step.
    pub(super) fn cutback(&self) -> &Cell<bool> {
        &self.models.cutback
    }

    /// Whether solver term `k` (contact terms, then ties) is on at time `t`.
    pub(super) fn term_on(&self, k: usize, t: f64) -> bool {
        self.couplings.on(self.term_choice[k], t)
    }

    /// Per solver term, its (side-A field, side-B field).
    pub(super) fn term_fields(&self) -> Vec<(usize, usize)> {
        self.term_choice
            .iter()
            .map(|&k| self.couplings.fields[k])
            .collect()
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
        let (pairings, choices, views) = (
            &self.contact.pairings,
            &self.contact.choices,
            &self.contact.views,
        );
        let (field_names, conductivity) = (&self.physics.field_names, &self.conductivity);
        let mechanism_names = &self.mechanism_names;
        let pressures = &self.couplings.pressures;
        self.set_time(time);
        let mut out = Derived::default();
        for (k, ((p, (c, scale, model)), h)) in
            pairings.iter().zip(choices).zip(&self.h_fns).enumerate()
        {
            let split = !mechanism_names[k].is_empty();
            if c.mortar && faces && views[k].faces {
                // A multiplier tie: the flux is its multiplier field λ_h at the points.
                let ties = self.tie_geometry.get_or_init(|| self.rebuild_ties(dofs));
                let ties = ties.as_ref().map_err(Clone::clone)?;
                let t = choices[..k].iter().filter(|(c, _, _)| c.mortar).count();
                let (Some(tie), Some(range)) = (ties.get(t), dofs.extra_ranges().get(t)) else {
                    return Err(format!(
                        "interaction {} / {}: no multipliers in the state",
                        p.side_a, p.side_b
                    ));
                };
                let on = self.couplings.on(k, time);
                let q = tie
                    .point_flux(&u[range.clone()], p.result.points.len())
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
            let field = |i: usize| {
                dofs.field(&field_names[i])
                    .ok_or_else(|| format!("no dofs of field `{}`", field_names[i]))
            };
            let (fa, fb) = self.couplings.fields[k];
            let pair = crate::enforce::interface::FieldPair {
                a: field(fa)?,
                b: field(fb)?,
            };
            let form = InterfaceForm {
                form: c.form,
                h: h.as_ref(),
                offset: c.offset,
                beta: c.penalty_factor.unwrap_or(DEFAULT_BETA) * scale,
                conductivity,
            };
            let named = |e: InterfaceError| format!("interaction {} / {}: {e}", p.side_a, p.side_b);
            // The points' geometry is made at the first state that asks and kept: the
            // pairing and the dofs do not change over a run.
            let points = self.point_geometry[k].get_or_init(|| {
                InterfacePoints::new(
                    self.mesh,
                    dofs,
                    pair,
                    &p.side_a_geometry,
                    &p.side_b_geometry,
                    &p.result.points,
                    &form,
                )
                .map_err(named)
            });
            let points = points.as_ref().map_err(Clone::clone)?;
            let q = points
                .point_flux(&form, u, p.result.points.len())
                .map_err(named);
            // The output evaluates the models once more; a cutback asked for here is not
            // the next step's.
            self.models.cutback.set(false);
            let mut q = q?;
            let on = self.couplings.on(k, time);
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
        let (pairings, views) = (&self.contact.pairings, &self.contact.views);
        if !views.iter().any(|v| v.faces) {
            return None;
        }
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

    /// Mechanism heats in the solver's term order.
    pub(super) fn term_mechanisms(&self, d: &Derived) -> Vec<Vec<f64>> {
        self.term_choice
            .iter()
            .map(|&k| d.mechanisms[k].clone())
            .collect()
    }

    /// Per solver term, (side A, side B) surface names.
    pub(super) fn term_sides(&self) -> Vec<(&str, &str)> {
        self.term_choice
            .iter()
            .map(|&k| {
                let p = &self.contact.pairings[k];
                (p.side_a.as_str(), p.side_b.as_str())
            })
            .collect()
    }

    /// Per solver term, (side A, side B, model) for the heat histories.
    pub(super) fn term_labels(&self) -> Vec<(String, String, String)> {
        self.term_choice
            .iter()
            .map(|&k| {
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
        self.term_choice
            .iter()
            .map(|&k| self.mechanism_names[k].clone())
            .collect()
    }

    /// A warning per interaction whose model failed at some points (quarantined).
    pub(super) fn report_quarantined(&self, diags: &mut Diagnostics) {
        let contact = self.contact;
        for ((p, (c, _, _)), log) in contact
            .pairings
            .iter()
            .zip(&contact.choices)
            .zip(&self.models.quarantined)
        {
            let log = log.borrow();
            if let Some((x, first)) = log.first() {
                diags.push(
                    Diagnostic::warning(
                        "W0501",
                        format!(
                            "interaction {} / {} ({}): {} point(s) quarantined; the first at ({:.6}, {:.6}, {:.6}): {first}",
                            p.side_a, p.side_b, c.name, log.len(), x[0], x[1], x[2]
                        ),
                    )
                    .help("the conductance model failed there; those points carry no heat"),
                );
            }
        }
    }

    /// The mortar ties of the run, built as the solvers build them: in interaction order,
    /// with the Dirichlet nodes and the earlier ties' nodes left without multipliers, so
    /// multiplier `k` of tie `t` is entry `k` of the state's `t`-th extra range.
    fn rebuild_ties(&self, dofs: &DofMap) -> Result<Vec<MortarTie>, String> {
        let field_names = &self.physics.field_names;
        let mut constrained: std::collections::HashSet<NodeId> =
            self.physics.dirichlet.iter().map(|&(n, _)| n).collect();
        let field = |i: usize| {
            dofs.field(&field_names[i])
                .ok_or_else(|| format!("no dofs of field `{}`", field_names[i]))
        };
        let mut out = Vec::new();
        for (k, (p, (c, _, _))) in self
            .contact
            .pairings
            .iter()
            .zip(&self.contact.choices)
            .enumerate()
        {
            if !c.mortar {
                continue;
            }
            let (fa, fb) = self.couplings.fields[k];
            let pair = crate::enforce::interface::FieldPair {
                a: field(fa)?,
                b: field(fb)?,
            };
            let multipliers = if c.dual {
                crate::enforce::mortar::Multipliers::Dual
            } else {
                crate::enforce::mortar::Multipliers::Standard
            };
            let tie = crate::enforce::mortar::mortar_tie(
                self.mesh,
                dofs,
                pair,
                &p.side_a_geometry,
                &p.side_b_geometry,
                &p.result.points,
                &self.conductivity,
                &mut constrained,
                multipliers,
            )
            .map_err(|e| format!("interaction {} / {}: {e}", p.side_a, p.side_b))?;
            out.push(tie);
        }
        Ok(out)
    }
}

/// One interaction's conductance as the interface forms call it: its model at the
/// point's state, with the contact pressure of the point (`at_points`) or of the
/// enforcement. A failing point is quarantined (kept in `log`, contributing nothing) when
/// the enforcement says so, asks for a smaller step when the model says so, and is an
/// error otherwise.
fn conductance<'a>(
    (choice, _, model): &'a Choice,
    log: &'a Quarantined,
    pairing: &Pairing,
    at_points: &'a Option<Vec<f64>>,
    models: &'a ModelState,
) -> Box<HFn<'a>> {
    let pressure = choice.pressure;
    let quarantine = choice.quarantine;
    let label = format!(
        "interaction {} / {} ({})",
        pairing.side_a, pairing.side_b, choice.name
    );
    let (clock, cutback) = (&models.clock, &models.cutback);
    let f = move |p: &HInput| -> Result<HValue, String> {
        let Some(m) = model else {
            return Ok(HValue::default());
        };
        let state = PointState {
            gap: p.gap,
            pressure: at_points.as_ref().map_or(pressure, |v| v[p.point]),
            temp_a: p.temp_a,
            temp_b: p.temp_b,
            x: p.x,
            time: clock.get(),
        };
        let c = match m.evaluate(&state) {
            Ok(c) => c,
            Err(e) if e.is_cutback() => {
                cutback.set(true);
                return Err(format!("{label}: {e}"));
            }
            // Quarantine: the point contributes nothing; it is reported after the
            // run. Each Newton step evaluates it again, so keep it once.
            Err(e) if quarantine => {
                let mut log = log.borrow_mut();
                if !log.iter().any(|(x, _)| *x == p.x) {
                    log.push((p.x, e.to_string()));
                }
                return Ok(HValue::default());
            }
            Err(e) => {
                return Err(format!(
                    "{label}: {e} (add `Quarantine Faulty Points` to the enforcement to skip such points)"
                ));
            }
        };
        Ok(HValue {
            h: c.h,
            dh_dtemp_a: c.dh_dtemp_a,
            dh_dtemp_b: c.dh_dtemp_b,
        })
    };
    Box::new(f)
}
