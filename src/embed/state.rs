//! What a host sets on its interactions between evaluations — which are switched on,
//! the contact pressure at their points, quarantine — and what they kept: the
//! quarantined points.

use super::{EmbedError, Embedding, Pair, Quarantined, argument};
use std::sync::{Arc, OnceLock};

use crate::assembly::{DofMap, FieldId};
use crate::enforce::conductance::ConductanceModel;
use crate::enforce::interface::FieldPair;
use crate::enforce::model::ModelChoice;
use crate::mesh::{Mesh, NodeId};
use crate::search::pairing::Integration;
use crate::search::scene::Pairing;

impl Embedding {
    fn pair_mut(&mut self, i: usize) -> Result<&mut Pair, EmbedError> {
        let count = self.pairs.len();
        self.pairs.get_mut(i).ok_or_else(|| {
            argument(
                format!("no interaction {i}, there are {count}"),
                "interaction indices are 0-based, in the order they were added",
            )
        })
    }

    /// Switch interaction `i` on or off (`Use Toggle Block`): while off, a flux
    /// interaction adds no terms and reports 0 W; the CSR pattern of
    /// [`Self::evaluate`] keeps its entries, so it does not change when it comes back.
    /// A mortar tie's rows stay in [`Self::constraints`]: the host drops them (and keeps
    /// its multipliers at 0) while the tie is off.
    pub fn set_active(&mut self, i: usize, on: bool) -> Result<(), EmbedError> {
        let p = self.pair_mut(i)?;
        if p.active != on {
            p.active = on;
            self.forget_values();
        }
        Ok(())
    }

    /// Something the interface terms depend on besides the field changed: the next
    /// [`Self::evaluate`] makes them again.
    fn forget_values(&mut self) {
        if let Some(e) = &mut self.evaluation {
            e.forget_values();
        }
    }

    /// Whether interaction `i` is switched on (true unless [`Self::set_active`] said
    /// otherwise).
    pub fn is_active(&self, i: usize) -> bool {
        self.pairs.get(i).is_some_and(|p| p.active)
    }

    /// The contact pressure (Pa) a conductance model sees at each contact point of
    /// interaction `i`, in the order of its search's points (`Contact Pressure
    /// Variable`); `None` goes back to the enforcement's `Contact Pressure`. A search
    /// pairs new points and drops these.
    pub fn set_point_pressures(
        &mut self,
        i: usize,
        pressures: Option<Vec<f64>>,
    ) -> Result<(), EmbedError> {
        let p = self.pair_mut(i)?;
        if let Some(v) = &pressures {
            let points = Self::searched(p)?.points.len();
            if v.len() != points {
                return Err(argument(
                    format!(
                        "{} pressures for interaction {} / {}, which has {points} contact points",
                        v.len(),
                        p.side_a.name,
                        p.side_b.name
                    ),
                    "give one pressure per contact point, in the order of point_fields",
                ));
            }
            if let Some(k) = v.iter().position(|x| !x.is_finite() || *x < 0.0) {
                return Err(argument(
                    format!("pressure {} at point {k} is not a number ≥ 0", v[k]),
                    "give contact pressures in Pa",
                ));
            }
        }
        if p.pressures != pressures {
            p.pressures = pressures;
            self.forget_values();
        }
        Ok(())
    }

    /// Quarantine the failing points of interaction `i` (see
    /// [`super::Interaction::quarantine`]), or stop doing so; the points kept so far stay
    /// listed.
    pub fn set_quarantine(&mut self, i: usize, on: bool) -> Result<(), EmbedError> {
        let p = self.pair_mut(i)?;
        if p.quarantine != on {
            p.quarantine = on;
            self.forget_values();
        }
        Ok(())
    }

    /// Whether every interaction's terms are linear in the field (constant h, or a
    /// model that does not depend on temperature): the Jacobian is then constant and
    /// symmetric, and one linear solve answers a steady problem.
    pub fn is_linear(&self) -> bool {
        self.pairs.iter().all(|p| match &p.enforcement {
            super::Enforcement::Flux {
                law: super::Law::Model { model, .. },
                ..
            } => !model.depends_on_temperature(),
            super::Enforcement::Flux {
                law: super::Law::Host(model),
                ..
            } => !model.depends_on_temperature(),
            _ => true,
        })
    }

    /// The points of interaction `i` quarantined so far ([`super::Interaction::quarantine`]),
    /// in the order they failed.
    pub fn quarantined(&self, i: usize) -> Vec<Quarantined> {
        self.pairs.get(i).map_or_else(Vec::new, |p| {
            p.quarantined
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .clone()
        })
    }

    /// `seam run`'s embedding: over its mesh and its own dof numbering (one or several
    /// fields; the host's dofs are seam's), with `fixed` nodes (its Dirichlet data) and
    /// the block `conductivity` weighing the Nitsche forms. Its interactions come from
    /// the run's scene ([`Self::add_resolved`]); their terms then come through the
    /// public calls, as an external host's do.
    pub(crate) fn over_dofs(
        mesh: Mesh,
        dofs: DofMap,
        conductivity: Vec<f64>,
        fixed: Vec<NodeId>,
        integration: Integration,
    ) -> Embedding {
        Embedding {
            host_dof: (0..dofs.len()).collect(),
            field: FieldId(0),
            mesh,
            dofs,
            conductivity,
            fixed,
            fixed_of: Vec::new(),
            integration,
            pairs: Vec::new(),
            time: 0.0,
            evaluation: None,
            conductivity_law: None,
        }
    }

    /// Add a pairing of `seam run`'s scene with its resolved enforcement over
    /// `fields`; it is searched already, and can be searched again after its nodes move
    /// only with `again` (its surfaces and search options). Returns its index.
    pub(crate) fn add_resolved(
        &mut self,
        pairing: Pairing,
        (choice, penalty_scale): (&ModelChoice, f64),
        model: Option<Arc<dyn ConductanceModel>>,
        again: Option<crate::scene::SearchAgain>,
        fields: FieldPair,
    ) -> usize {
        self.pairs.push(super::from_deck::resolved_pair(
            pairing,
            choice,
            penalty_scale,
            model,
            again,
            fields,
        ));
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
        self.pairs.len() - 1
    }

    /// Weigh the Nitsche forms of the temperature's interactions with k(T) of each block
    /// at each point's temperatures (the embedding's `conductivity` being k at a probe
    /// temperature): consistent for a conductivity that changes with T, with the
    /// derivatives in the Jacobian.
    pub(crate) fn set_conductivity_law(&mut self, law: std::sync::Arc<super::ConductivityOfT>) {
        self.conductivity_law = Some(law);
        for p in &mut self.pairs {
            p.points = OnceLock::new();
        }
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
    }

    /// Interaction `i` (on a field other than the temperature) sees the temperature of
    /// `field` at its points: its conductance models take it, and its coefficient
    /// ([`Self::set_coefficient`], the value at a probe temperature) follows `law` of it
    /// when given.
    pub(crate) fn set_temperature_of(
        &mut self,
        i: usize,
        field: FieldId,
        law: Option<std::sync::Arc<super::ConductivityOfT>>,
    ) {
        if let Some(p) = self.pairs.get_mut(i) {
            p.temperature_field = Some(field);
            p.coefficient_law = law;
            p.points = OnceLock::new();
        }
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
    }

    /// Weigh the forms of interaction `i` with `coefficient` per block instead of the
    /// embedding's conductivity (a field other than the temperature, as `seam run`'s
    /// species with its diffusivities).
    pub(crate) fn set_coefficient(&mut self, i: usize, coefficient: Vec<f64>) {
        if let Some(p) = self.pairs.get_mut(i) {
            p.coefficient = Some(coefficient);
            p.points = OnceLock::new();
        }
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
    }

    /// The fixed nodes (Dirichlet data) of `field`, when they are not the embedding's
    /// `fixed`: the mortar ties over that field give them no multiplier.
    pub(crate) fn set_fixed_of(&mut self, field: FieldId, nodes: Vec<NodeId>) {
        self.fixed_of.retain(|(f, _)| *f != field);
        self.fixed_of.push((field, nodes));
    }
}
