//! Element death: elements whose death time has come add nothing (conduction,
//! capacity, sources, face conditions), and the dofs of nodes no live element holds
//! keep their value (`u − uⁿ = 0`, so the matrix stays regular).

use crate::heat::HeatError;
use crate::mesh::ElemId;

use super::newton::Context;
use super::setup::{LumpedWeight, lumped_weights};

/// What the dead elements at some time leave of the problem.
pub(super) struct Alive {
    /// How many elements are dead (death only grows in time, so the count names the set).
    pub(super) dead: usize,
    /// The lumped capacity weights of the live elements.
    pub(super) lumped: Vec<LumpedWeight>,
    /// The dofs of nodes that no live element holds.
    pub(super) orphans: Vec<usize>,
}

/// Whether element `e` is dead at time `t` under the per-element death times `death`.
pub(super) fn is_dead(death: Option<&[f64]>, e: ElemId, t: f64) -> bool {
    death.is_some_and(|d| d.get(e.index()).is_some_and(|&td| td <= t))
}

impl Context<'_, '_> {
    /// The live part of the problem at `t` (made again when more elements have died);
    /// `None` while every element lives.
    pub(super) fn refresh_alive(&self, t: f64) -> Result<(), HeatError> {
        let Some(death) = self.p.death else {
            return Ok(());
        };
        let dead = death.iter().filter(|&&td| td <= t).count();
        let known = self.alive.borrow().as_ref().map_or(0, |a| a.dead);
        if dead == known {
            return Ok(());
        }
        let mesh = self.p.mesh;
        let dofs = &self.setup.dofs;
        let live = |e: ElemId| !is_dead(Some(death), e, t);
        let lumped = lumped_weights(mesh, dofs, self.setup.species, &live)?;
        let mut held = vec![false; mesh.num_nodes()];
        for &b in &self.setup.blocks {
            for e in mesh.blocks[b].elems().filter(|&e| live(e)) {
                for n in mesh.elem_nodes(e) {
                    held[n.index()] = true;
                }
            }
        }
        let mut orphans = Vec::new();
        for &f in &self.setup.fields {
            for (n, _) in held.iter().enumerate().filter(|(_, h)| !**h) {
                if let Some(d) = dofs.dof(f, crate::mesh::NodeId(n as u32)) {
                    orphans.push(d.index());
                }
            }
        }
        for v in self.setup.voltage.into_iter().chain(self.setup.species) {
            for (n, _) in held.iter().enumerate().filter(|(_, h)| !**h) {
                if let Some(d) = dofs.dof(v, crate::mesh::NodeId(n as u32)) {
                    orphans.push(d.index());
                }
            }
        }
        orphans.sort_unstable();
        orphans.dedup();
        log::info!(
            "t = {t}: {dead} element(s) dead, {} dof(s) held at their value",
            orphans.len()
        );
        *self.alive.borrow_mut() = Some(Alive {
            dead,
            lumped,
            orphans,
        });
        Ok(())
    }
}
