//! What does not change over a run: the dofs and fields, the mortar ties and their
//! multiplier rows, the Dirichlet dofs, the lumped capacity weights and the element
//! bases.

use crate::assembly::{DofMap, FieldId};
use crate::fem::{Basis, MAX_NODES};
use crate::heat::interfaces::TieRows;
use crate::heat::kernel;
use crate::heat::{HeatError, bad_jacobian, block_rules, elem_coords};
use crate::mesh::{Mesh, NodeId};

use super::{Loads, TransientProblem};
use crate::heat::electric::{ElectricContact, VOLTAGE};
use crate::heat::species::SPECIES;

/// What does not change over a run: dofs, ties, the pattern's couplings, the lumped
/// capacity weights.
pub(super) struct Setup {
    pub(super) dofs: DofMap,
    pub(super) fields: Vec<FieldId>,
    pub(super) n_primal: usize,
    pub(super) n: usize,
    pub(super) ties: Vec<TieRows>,
    pub(super) lambda_first: Vec<usize>,
    pub(super) dirichlet_dofs: Vec<usize>,
    pub(super) lumped: Vec<LumpedWeight>,
    /// The blocks carrying a field, and the element basis of each.
    pub(super) blocks: Vec<usize>,
    pub(super) rules: Vec<Option<Basis>>,
    /// The voltage field of a thermal–electrical problem.
    pub(super) voltage: Option<FieldId>,
    /// Its electrical contacts, bound to the dofs (made again when their surfaces
    /// move: [`Self::rebind_electric`]).
    pub(super) electric: std::sync::RwLock<Vec<ElectricContact>>,
    /// The species field, numbered last.
    pub(super) species: Option<FieldId>,
}

impl Setup {
    pub(super) fn new(p: &TransientProblem<'_>, time: f64) -> Result<Setup, HeatError> {
        let mesh = p.mesh;
        counts_fit(p)?;
        let specs = p.fields_or_default();
        let mut list: Vec<(&str, &[usize])> = specs
            .iter()
            .map(|f| (f.name.as_str(), f.blocks.as_slice()))
            .collect();
        // The voltage is numbered after the thermal fields, so an element's dofs are its
        // temperatures then its voltages.
        let voltage_blocks: Vec<usize> = p.electric.as_ref().map_or_else(Vec::new, |e| {
            (0..mesh.blocks.len())
                .filter(|&b| {
                    mesh.blocks[b].topology.is_solid()
                        && e.conductivity.get(b).is_some_and(Option::is_some)
                })
                .collect()
        });
        if p.electric.is_some() {
            list.push((VOLTAGE, voltage_blocks.as_slice()));
        }
        // The species is numbered last: an element's species dofs close its list.
        let species_blocks: Vec<usize> = p.species.as_ref().map_or_else(Vec::new, |s| {
            (0..mesh.blocks.len())
                .filter(|&b| {
                    mesh.blocks[b].topology.is_solid()
                        && s.diffusivity.get(b).is_some_and(Option::is_some)
                })
                .collect()
        });
        if p.species.is_some() {
            list.push((SPECIES, species_blocks.as_slice()));
        }
        let mut dofs = DofMap::new(mesh, &list)?;
        let voltage = p.electric.as_ref().and_then(|_| dofs.field(VOLTAGE));
        let species = p.species.as_ref().and_then(|_| dofs.field(SPECIES));
        let fields: Vec<FieldId> = specs
            .iter()
            .map(|f| dofs.field(&f.name).expect("field just made"))
            .collect();
        let n_primal = dofs.len();
        let loads = (p.loads)(time)?;
        let mut dirichlet_dofs: Vec<usize> = node_dofs(mesh, &dofs, &fields, &loads.dirichlet)?
            .into_iter()
            .map(|(d, _)| d)
            .collect();
        if let Some(v) = voltage {
            dirichlet_dofs.extend(voltage_dofs(mesh, &dofs, v, &loads.voltage)?.map(|(d, _)| d));
        }
        if let Some(c) = species {
            dirichlet_dofs.extend(species_dofs(mesh, &dofs, c, &loads.species)?.map(|(d, _)| d));
        }
        let electric = match (&p.electric, voltage) {
            (Some(e), Some(v)) => {
                let contacts = e.contacts.iter().map(|(c, _)| c.clone()).collect();
                bind_electric(mesh, &dofs, (fields[0], v), contacts)?
            }
            _ => Vec::new(),
        };
        let ties = match p.interfaces {
            Some(i) => i.ties().map_err(HeatError::Contact)?,
            None => Vec::new(),
        };
        let lambda_first = ties
            .iter()
            .map(|t| dofs.add_extra(t.own.len()).start)
            .collect();
        let lumped = lumped_weights(mesh, &dofs, species, &|_| true)?;
        let mut blocks: Vec<usize> = Vec::new();
        let mut rules = vec![None; mesh.blocks.len()];
        for &f in &fields {
            blocks.extend_from_slice(dofs.field_blocks(f));
            for (b, r) in block_rules(mesh, &dofs, f)?.into_iter().enumerate() {
                if r.is_some() {
                    rules[b] = r;
                }
            }
        }
        let n = dofs.len();
        Ok(Setup {
            dofs,
            fields,
            n_primal,
            n,
            ties,
            lambda_first,
            dirichlet_dofs,
            lumped,
            blocks,
            rules,
            voltage,
            electric: std::sync::RwLock::new(electric),
            species,
        })
    }

    /// The dofs held still while a fresh voltage settles (every dof but the voltages
    /// and the multipliers of voltage ties): see [`Context::newton`].
    ///
    /// [`Context::newton`]: super::newton::Context::newton
    pub(super) fn outside_voltage(&self) -> Vec<usize> {
        let Some(v) = self.voltage else {
            return Vec::new();
        };
        let volts = self.dofs.field_range(v);
        let mut free = vec![false; self.n];
        free[volts.clone()].iter_mut().for_each(|f| *f = true);
        for (tie, &first) in self.ties.iter().zip(&self.lambda_first) {
            if tie.own.first().is_some_and(|d| volts.contains(d)) {
                free[first..first + tie.own.len()]
                    .iter_mut()
                    .for_each(|f| *f = true);
            }
        }
        (0..self.n).filter(|&d| !free[d]).collect()
    }

    /// The electrical contacts made again on moved surfaces (in the problem's order):
    /// bound to the dofs and kept. True when their couplings changed, so the solver
    /// makes its pattern again.
    pub(super) fn rebind_electric(
        &self,
        mesh: &Mesh,
        contacts: Vec<ElectricContact>,
    ) -> Result<bool, HeatError> {
        let (Some(v), Some(&t)) = (self.voltage, self.fields.first()) else {
            return Ok(false);
        };
        let bound = bind_electric(mesh, &self.dofs, (t, v), contacts)?;
        let mut kept = self.electric_mut();
        let changed = bound.len() != kept.len()
            || bound
                .iter()
                .zip(kept.iter())
                .any(|(a, b)| a.couplings() != b.couplings());
        *kept = bound;
        Ok(changed)
    }

    /// The electrical contacts (a poisoned lock cannot happen: nothing panics while
    /// holding it, and the data would be whole if it did).
    pub(super) fn electric(&self) -> std::sync::RwLockReadGuard<'_, Vec<ElectricContact>> {
        self.electric
            .read()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    fn electric_mut(&self) -> std::sync::RwLockWriteGuard<'_, Vec<ElectricContact>> {
        self.electric
            .write()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// Where the species dofs start (the end of the fields without one).
    pub(super) fn species_start(&self) -> usize {
        self.species
            .map_or(self.n_primal, |c| self.dofs.field_range(c).start)
    }

    /// The Dirichlet dofs and values of `loads`: the temperatures on whichever thermal
    /// field the node carries, then the voltages.
    pub(super) fn dirichlet(
        &self,
        mesh: &Mesh,
        loads: &Loads,
    ) -> Result<Vec<(usize, f64)>, HeatError> {
        let mut out = node_dofs(mesh, &self.dofs, &self.fields, &loads.dirichlet)?;
        if let Some(v) = self.voltage {
            out.extend(voltage_dofs(mesh, &self.dofs, v, &loads.voltage)?);
        }
        if let Some(c) = self.species {
            out.extend(species_dofs(mesh, &self.dofs, c, &loads.species)?);
        }
        Ok(out)
    }
}

/// `contacts` bound to the temperature and voltage dofs `(t, v)`.
fn bind_electric(
    mesh: &Mesh,
    dofs: &DofMap,
    (t, v): (FieldId, FieldId),
    contacts: Vec<ElectricContact>,
) -> Result<Vec<ElectricContact>, HeatError> {
    contacts
        .into_iter()
        .map(|mut c| {
            c.bind(mesh, dofs, t, v).map_err(HeatError::Contact)?;
            Ok(c)
        })
        .collect()
}

/// `(dof, value)` of nodal voltages; a node without a voltage is an error that names it.
fn voltage_dofs<'d>(
    mesh: &'d Mesh,
    dofs: &'d DofMap,
    v: FieldId,
    data: &'d [(NodeId, f64)],
) -> Result<impl Iterator<Item = (usize, f64)> + 'd, HeatError> {
    if let Some(&(n, _)) = data.iter().find(|(n, _)| dofs.dof(v, *n).is_none()) {
        return Err(HeatError::Step(format!(
            "node {} has a voltage condition but no voltage: its blocks have no electrical_conductivity",
            mesh.node_number(n)
        )));
    }
    Ok(data
        .iter()
        .map(move |&(n, val)| (dofs.dof(v, n).expect("checked above").index(), val)))
}

/// `(dof, value)` of nodal concentrations; a node without a species is an error that
/// names it.
fn species_dofs<'d>(
    mesh: &'d Mesh,
    dofs: &'d DofMap,
    c: FieldId,
    data: &'d [(NodeId, f64)],
) -> Result<impl Iterator<Item = (usize, f64)> + 'd, HeatError> {
    if let Some(&(n, _)) = data.iter().find(|(n, _)| dofs.dof(c, *n).is_none()) {
        return Err(HeatError::Step(format!(
            "node {} has a species condition but no species: its blocks have no diffusivity",
            mesh.node_number(n)
        )));
    }
    Ok(data
        .iter()
        .map(move |&(n, val)| (dofs.dof(c, n).expect("checked above").index(), val)))
}

/// `(dof, value)` of nodal data on whichever field the node carries.
pub(super) fn node_dofs(
    mesh: &Mesh,
    dofs: &DofMap,
    fields: &[FieldId],
    data: &[(NodeId, f64)],
) -> Result<Vec<(usize, f64)>, HeatError> {
    data.iter()
        .map(|&(n, v)| {
            fields
                .iter()
                .find_map(|&f| dofs.dof(f, n))
                .map(|d| (d.index(), v))
                .ok_or(HeatError::DirichletOffField(
                    mesh.node_numbers.get(n.index()).copied().unwrap_or(-1),
                ))
        })
        .collect()
}

/// (dof, block, ∫N_a dV over that block's elements at the node, node coordinates).
pub(crate) type LumpedWeight = (u32, u32, f64, [f64; 3]);

/// Lumped capacity weights `∫ N_a dV` per (dof, block) over the `live` elements, with
/// the node's coordinates: for each block's first field (its temperature) and, where it
/// lives, the `species` (the last of the block's fields); a voltage has none.
pub(crate) fn lumped_weights(
    mesh: &Mesh,
    dofs: &DofMap,
    species: Option<FieldId>,
    live: &dyn Fn(crate::mesh::ElemId) -> bool,
) -> Result<Vec<LumpedWeight>, HeatError> {
    // Summed block by block into a dense array over the dofs (each weight takes its
    // elements' terms in the order a map keyed by (dof, block) would), then listed by
    // dof and block.
    let mut out: Vec<(u32, u32, f64)> = Vec::new();
    let mut sum = vec![0.0; dofs.len()];
    let mut touched = vec![false; dofs.len()];
    let mut elem_dofs = Vec::new();
    for (b, block) in mesh.blocks.iter().enumerate() {
        if dofs.block_fields(b).is_empty() {
            continue;
        }
        let measure = crate::fem::Measure::of(mesh.axisymmetric);
        let basis =
            Basis::for_measure(block.topology, measure).ok_or(HeatError::UnsupportedTopology {
                block: block.id,
                topology: block.topology,
            })?;
        let nn = block.topology.node_count();
        let with_species = species.is_some_and(|c| dofs.block_fields(b).contains(&c));
        let mut me = vec![0.0; nn * nn];
        let mut listed = Vec::new();
        let mut add = |d: u32, w: f64| {
            let k = d as usize;
            if !touched[k] {
                touched[k] = true;
                listed.push(d);
            }
            sum[k] += w;
        };
        for k in 0..block.len() {
            let e = crate::mesh::ElemId(block.first_elem.0 + k as u32);
            if !live(e) {
                continue;
            }
            let mut x = [[0.0; 3]; MAX_NODES];
            let m = elem_coords(mesh, e, &mut x);
            me.fill(0.0);
            kernel::capacity_lumped(&basis, &x[..m], 1.0, &mut me)
                .map_err(|bad| bad_jacobian(mesh, e, bad))?;
            dofs.elem_dofs(mesh, e, &mut elem_dofs);
            for a in 0..nn {
                add(elem_dofs[a], me[a * nn + a]);
                if with_species {
                    add(elem_dofs[elem_dofs.len() - nn + a], me[a * nn + a]);
                }
            }
        }
        for d in listed {
            let k = d as usize;
            out.push((d, b as u32, sum[k]));
            (sum[k], touched[k]) = (0.0, false);
        }
    }
    // By dof, then block (each pair once).
    out.sort_unstable_by_key(|&(d, b, _)| (d, b));
    // Coordinates of each dof's node.
    let mut coords = vec![[0.0; 3]; dofs.len()];
    for f in 0..dofs.field_count() {
        let f = FieldId(f as u32);
        for node in 0..mesh.num_nodes() {
            if let Some(d) = dofs.dof(f, NodeId(node as u32)) {
                coords[d.index()] = mesh.coords[node];
            }
        }
    }
    Ok(out
        .into_iter()
        .map(|(d, b, w)| (d, b, w, coords[d as usize]))
        .collect())
}

/// The per-block data of `p` has one entry per mesh block: a shorter list would leave
/// a block without its law (and the assembly reading past its end).
fn counts_fit(p: &TransientProblem<'_>) -> Result<(), HeatError> {
    let blocks = p.mesh.blocks.len();
    if p.laws.len() != blocks {
        return Err(HeatError::MaterialCount {
            count: p.laws.len(),
            blocks,
        });
    }
    if let Some(s) = p.block_source.filter(|s| s.len() != blocks) {
        return Err(HeatError::SourceCount {
            count: s.len(),
            blocks,
        });
    }
    if let Some(s) = p.species.as_ref().filter(|s| s.capacity.len() != blocks) {
        return Err(HeatError::Step(format!(
            "{} species capacities given for {blocks} blocks",
            s.capacity.len()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::heat::law::Law;
    use crate::heat::transient::BlockLaws;
    use crate::mesh::generate::{BoxSpec, boxes};

    /// A law or source list shorter than the mesh's blocks is an error naming both
    /// counts, not a read past its end.
    #[test]
    fn per_block_lists_must_cover_every_block() {
        let mesh = boxes(
            &[
                BoxSpec::hex([0.0; 3], [1.0; 3], [1, 1, 1], 1),
                BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [1, 1, 1], 2),
            ],
            false,
        );
        let law = BlockLaws {
            conductivity: Law::Constant(1.0),
            capacity: Law::Constant(1.0),
        };
        let (two, one) = ([law.clone(), law.clone()], [law]);
        let sources = [Law::Constant(1.0)];
        let loads = |_t: f64| Ok(Loads::default());
        let problem = |laws, block_source| TransientProblem {
            mesh: &mesh,
            fields: Vec::new(),
            laws,
            source: None,
            block_source,
            loads: &loads,
            interfaces: None,
            tolerance: 1e-10,
            max_iterations: 5,
            reproducible: true,
            amg_threshold: None,
            electric: None,
            death: None,
            species: None,
        };
        let err = |p: TransientProblem<'_>| Setup::new(&p, 0.0).err().map(|e| e.to_string());
        assert_eq!(
            err(problem(&one, None)).as_deref(),
            Some("1 materials given for 2 blocks")
        );
        assert_eq!(
            err(problem(&two, Some(&sources))).as_deref(),
            Some("1 block sources given for 2 blocks")
        );
        assert_eq!(err(problem(&two, None)), None);
    }
}
