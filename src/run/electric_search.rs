//! The electrical contacts of a run whose contact surfaces move or die. An electrical
//! contact (a contact conductance with its Joule heat) is assembled by the transient
//! solver from its matched points, not by the embedding; when the surfaces move its
//! pairing is kept in an embedding of its own that is only placed, searched and made
//! again — never evaluated — on the same schedule as the Energy interactions, and the
//! contacts are made anew from it after every placement (their gaps change even when
//! the pairing does not).

use crate::assembly::DofMap;
use crate::embed::Embedding;
use crate::enforce::electric::ElectricContact;
use crate::enforce::interface::{FieldPair, Form};
use crate::enforce::model::{ConductanceLaw, ModelChoice};
use crate::heat::interfaces::InterfaceFailure;
use crate::search::pairing::Integration;
use crate::surface::SurfaceSet;

use super::contact::RunContact;
use super::terms::{failure, remake_surfaces};

/// The electrical contacts' pairings, kept up with the moving surfaces.
pub(super) struct ElectricSearch {
    embedding: Embedding,
    /// Per contact: element death left a side without faces, so it carries nothing.
    gone: Vec<bool>,
}

impl ElectricSearch {
    /// The electrical contacts of `contact` over the run's mesh and `dofs` (which the
    /// embedding needs, though it never evaluates them); `None` without any.
    pub(super) fn new(
        contact: &RunContact,
        mesh: &crate::mesh::Mesh,
        dofs: &DofMap,
        field: FieldPair,
        integration: Integration,
    ) -> Option<ElectricSearch> {
        if contact.electrical.is_empty() {
            return None;
        }
        let blocks = mesh.blocks.len();
        let mut embedding = Embedding::over_dofs(
            mesh.clone(),
            dofs.clone(),
            vec![1.0; blocks],
            Vec::new(),
            integration,
        );
        // Placed and searched only: the form is never evaluated.
        let choice = ModelChoice {
            name: "electrical contact".into(),
            form: Form::Conductance,
            conductance: Some(ConductanceLaw::Constant(0.0)),
            offset: 0.0,
            penalty_factor: None,
            mortar: false,
            dual: false,
            pressure: 0.0,
            quarantine: false,
            pressure_variable: None,
            toggle: None,
            variables: None,
        };
        for e in &contact.electrical {
            let again = e.again.as_ref().map(|a| crate::scene::SearchAgain {
                side_a: a.side_a.clone(),
                side_b: a.side_b.clone(),
                settings: a.settings.clone(),
                overclosure: a.overclosure,
                subdomain: a.subdomain,
                map: None,
            });
            let k = embedding.add_resolved(e.pairing.clone(), (&choice, 1.0), None, again, field);
            // An electrical contact whose surfaces part carries no current, as a gap
            // conductance that pairs nothing carries no heat.
            let _ = embedding.allow_unpaired(Some(k), true);
        }
        Some(ElectricSearch {
            embedding,
            gone: vec![false; contact.electrical.len()],
        })
    }

    /// The nodes at `coords` (when they moved), the surfaces made again from `sets`
    /// (when element death changed them), and the contacts that are `due` searched
    /// anew. True when some contact was searched.
    pub(super) fn place(
        &mut self,
        contact: &RunContact,
        coords: Option<&[[f64; 3]]>,
        sets: Option<&[(Option<String>, SurfaceSet)]>,
        due: &dyn Fn(usize) -> bool,
    ) -> Result<bool, InterfaceFailure> {
        if let Some(coords) = coords {
            self.embedding.move_nodes(coords).map_err(failure)?;
        }
        let mut search: Vec<usize> = (0..self.gone.len()).filter(|&k| due(k)).collect();
        if let Some(sets) = sets {
            let pairings = (contact.electrical.iter()).map(|e| (&e.pairing, e.definition));
            search.extend(remake_surfaces(
                &mut self.embedding,
                sets,
                pairings,
                &mut self.gone,
            )?);
            search.sort_unstable();
            search.dedup();
        }
        search.retain(|&k| !self.gone[k]);
        if !search.is_empty() {
            self.embedding.search_some(&search).map_err(failure)?;
        }
        Ok(!search.is_empty())
    }

    /// The electrical contacts on the surfaces as they are now, in `contact`'s order;
    /// one that death emptied has no points.
    pub(super) fn contacts(
        &self,
        contact: &RunContact,
    ) -> Result<Vec<ElectricContact>, InterfaceFailure> {
        let made = |k: usize, e: &crate::scene::electric::ElectricalEnforced| {
            let (offset, fraction) = (e.contact.offset, e.contact.fraction_a);
            let (a, b, points) = match self.embedding.pairing_of(k) {
                Some((a, b, r)) if !self.gone[k] => (a, b, r.points.as_slice()),
                _ => (
                    &e.pairing.side_a_geometry,
                    &e.pairing.side_b_geometry,
                    &[][..],
                ),
            };
            ElectricContact::new(a, b, points, offset, fraction).map_err(|m| {
                InterfaceFailure::Failed(format!(
                    "electrical contact {} / {}: {m}",
                    e.side_a, e.side_b
                ))
            })
        };
        contact
            .electrical
            .iter()
            .enumerate()
            .map(|(k, e)| made(k, e))
            .collect()
    }
}
