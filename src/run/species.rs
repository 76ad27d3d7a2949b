//! The species of a run: a diffusing species (concentration c, mol/m³) in the blocks
//! whose `[[material]]` gives a `diffusivity`, solved in the same Newton as the
//! temperature ([`crate::heat::species`]), with its conditions (`kind = "species"`,
//! `"species_flux"`) and its interfaces (`Enforcement for Species`).
//!
//! **Why one Newton.** The coupling is one way (D(T); the temperature does not see c),
//! so a solve of c after T each step would be exact too. The species is one more field
//! of the monolithic step instead: it reuses the solver's every part — adaptive steps,
//! restarts from a checkpoint (c is in the state), output, the interfaces of the
//! embedding — and its Jacobian is block triangular, so Newton converges as the
//! temperature does (one step when D is constant and the temperature linear).
//!
//! **Partition coefficients.** An interface with partition coefficient K holds
//! `c_A = K c_B`. The run solves for `ĉ = c / S_b` instead of c, with a solubility scale
//! S_b per block chosen so that `S_A / S_B = K` across every species interface (and S
//! equal across blocks that share nodes): then ĉ is continuous where c jumps by K, and
//! every interface model of the Energy equation — Nitsche and interior-penalty ties,
//! mortar ties with standard or dual multipliers, Dash, conductance and Robin–Nitsche
//! gap conductance — applies to ĉ unchanged and stays symmetric. In ĉ the block's
//! diffusivity is `D S_b`, its capacity `φ S_b`, a prescribed concentration `c/S`, a flux
//! is unchanged (`−D∇c = −D S ∇ĉ`), and a mass-transfer interface
//! `j = h (c_A − K c_B − Δc) = h S_A (ĉ_A − ĉ_B − Δc/S_A)` has conductance `h S_A` and
//! offset `Δc/S_A`. The rows of the system are the mass balances of c itself, so the
//! interface fluxes read off them are mol/s. K of a loop of interfaces must multiply to
//! 1 (ratios of solubilities do); when they do not, the run says where.

use std::sync::Arc;

use crate::diag::{Diagnostic, Diagnostics};
use crate::enforce::conductance::{Conductance, ConductanceError, ConductanceModel, PointState};
use crate::enforce::model::{ConductanceLaw, ModelChoice};
use crate::heat::law::Law;
use crate::mesh::{Mesh, NodeId};
use crate::scene::species::FieldEnforced;

use super::physics::law;
use super::problem::{BcKind, Problem, ProblemText, Value};

/// The species part of a run's materials and conditions.
#[derive(Default)]
pub(super) struct Species {
    /// D(T) per block (m²/s, before scaling); `None`: no species there.
    pub diffusivity: Vec<Option<Law>>,
    /// φ per block (1 unless `species_capacity` says otherwise).
    pub capacity: Vec<f64>,
    /// The nodes of the `kind = "species"` conditions, with the condition.
    pub dirichlet: Vec<(NodeId, usize)>,
    /// The solubility scale S per block (1 until [`Species::resolve_scale`]).
    pub scale: Vec<f64>,
    /// S at each node (1 off the species blocks).
    pub node_scale: Vec<f64>,
}

impl Species {
    /// Whether some block carries a species.
    pub(super) fn any(&self) -> bool {
        self.diffusivity.iter().any(Option::is_some)
    }

    /// The nodal concentration c = S ĉ of the dof vector `u` (NaN at nodes without a
    /// species); `None` when `dofs` has no species.
    pub(super) fn nodal(&self, u: &[f64], dofs: &crate::assembly::DofMap) -> Option<Vec<f64>> {
        let c = dofs.field(crate::heat::species::SPECIES)?;
        let mut v = dofs.nodal_values(c, u);
        v.iter_mut()
            .zip(&self.node_scale)
            .for_each(|(v, s)| *v *= s);
        Some(v)
    }

    /// The blocks with a species (solid ones: a shell carries none).
    pub(super) fn blocks(&self, mesh: &Mesh) -> Vec<usize> {
        (0..mesh.blocks.len())
            .filter(|&b| mesh.blocks[b].topology.is_solid() && self.diffusivity[b].is_some())
            .collect()
    }

    /// The law each block's species sees: D(T) S_b.
    pub(super) fn scaled_diffusivity(&self) -> Vec<Option<Law>> {
        self.diffusivity
            .iter()
            .zip(&self.scale)
            .map(|(d, &s)| d.clone().map(|d| super::physics::scale_law(d, s)))
            .collect()
    }

    /// φ S_b per block.
    pub(super) fn scaled_capacity(&self) -> Vec<f64> {
        self.capacity
            .iter()
            .zip(&self.scale)
            .map(|(c, s)| c * s)
            .collect()
    }

    /// The coefficient per block weighing a species interface's Nitsche forms: D S_b at
    /// the probe temperature (1 where there is no species).
    pub(super) fn coefficient(&self, probe: f64, time: f64) -> Vec<f64> {
        self.diffusivity
            .iter()
            .zip(&self.scale)
            .map(|(d, s)| {
                d.as_ref()
                    .and_then(|d| d.eval(probe, [0.0; 3], time).ok())
                    .map_or(1.0, |v| v.0 * s)
            })
            .collect()
    }

    /// The solubility scales of the blocks from the interfaces' partition coefficients
    /// (module docs): S = 1 on the first block of each group joined by interfaces or
    /// shared nodes, `S_B = S_A / K` across an interface. Disagreeing coefficients, or a
    /// side A over blocks of different scales, go to `diags`.
    pub(super) fn resolve_scale(
        &mut self,
        mesh: &Mesh,
        entries: &[Interface],
        diags: &mut Diagnostics,
    ) {
        let n = mesh.blocks.len();
        // The joins: (block, block, K, where it comes from).
        let mut joins: Vec<(usize, usize, f64, Option<usize>)> = Vec::new();
        let mut first_block: Vec<u32> = vec![u32::MAX; mesh.num_nodes()];
        for b in self.blocks(mesh) {
            let block = &mesh.blocks[b];
            for k in 0..block.len() {
                let e = crate::mesh::ElemId(block.first_elem.0 + k as u32);
                for node in mesh.elem_nodes(e) {
                    let f = &mut first_block[node.index()];
                    if *f == u32::MAX {
                        *f = b as u32;
                    } else if *f as usize != b {
                        joins.push((*f as usize, b, 1.0, None));
                    }
                }
            }
        }
        joins.sort_by_key(|x| (x.0, x.1));
        joins.dedup_by(|x, y| (x.0, x.1) == (y.0, y.1));
        for (k, e) in entries.iter().enumerate() {
            let p = &e.pairing;
            for q in p.result.points.iter() {
                let (Some(fa), Some(fb)) = (q.a_face, q.matched_b_face()) else {
                    continue;
                };
                let a = mesh.block_of(p.side_a_geometry.faces[fa as usize].side.elem);
                let b = mesh.block_of(p.side_b_geometry.faces[fb].side.elem);
                if !joins.contains(&(a, b, e.partition, Some(k))) {
                    joins.push((a, b, e.partition, Some(k)));
                }
            }
        }
        let mut scale: Vec<Option<f64>> = vec![None; n];
        let species: Vec<bool> = self.diffusivity.iter().map(Option::is_some).collect();
        // Breadth first from each unscaled species block; every join checked once both
        // ends have a scale.
        for root in 0..n {
            if !species[root] || scale[root].is_some() {
                continue;
            }
            scale[root] = Some(1.0);
            let mut changed = true;
            while changed {
                changed = false;
                for &(a, b, kp, _) in &joins {
                    match (scale[a], scale[b]) {
                        (Some(sa), None) => {
                            scale[b] = Some(sa / kp);
                            changed = true;
                        }
                        (None, Some(sb)) => {
                            scale[a] = Some(sb * kp);
                            changed = true;
                        }
                        _ => {}
                    }
                }
            }
        }
        let name = |b: usize| mesh.blocks[b].sierra_name();
        for &(a, b, kp, from) in &joins {
            let (Some(sa), Some(sb)) = (scale[a], scale[b]) else {
                continue;
            };
            let implied = sa / sb;
            if (implied - kp).abs() <= 1e-12 * kp.max(implied) {
                continue;
            }
            let what = match from {
                Some(k) => format!(
                    "interaction {} / {} gives `Partition Coefficient = {kp}`",
                    entries[k].pairing.side_a, entries[k].pairing.side_b
                ),
                None => "they share nodes (K = 1)".to_string(),
            };
            diags.push(
                Diagnostic::error(
                    "E0432",
                    format!(
                        "species: the partition coefficients disagree between blocks {} and {}: {what}, but the other interfaces joining them give c_{} / c_{} = {implied}",
                        name(a),
                        name(b),
                        name(a),
                        name(b)
                    ),
                )
                .at(from.map(|k| entries[k].at.clone()))
                .help("partition coefficients are ratios of solubilities, S_A / S_B: around every loop of interfaces (and blocks meshed together, K = 1) they multiply to 1"),
            );
            break;
        }
        self.scale = scale.into_iter().map(|s| s.unwrap_or(1.0)).collect();
        self.node_scale = vec![1.0; mesh.num_nodes()];
        for (node, &b) in first_block.iter().enumerate() {
            if b != u32::MAX {
                self.node_scale[node] = self.scale[b as usize];
            }
        }
    }

    /// The scale S_A of side A of `entry`: every side-A face's block has the same, else
    /// the reason.
    pub(super) fn side_a_scale(&self, mesh: &Mesh, entry: &Interface) -> Result<f64, String> {
        let p = &entry.pairing;
        let mut found: Option<(f64, usize)> = None;
        for f in &p.side_a_geometry.faces {
            let b = mesh.block_of(f.side.elem);
            let s = self.scale[b];
            match found {
                None => found = Some((s, b)),
                Some((s0, b0)) if (s - s0).abs() > 1e-12 * s0 => {
                    return Err(format!(
                        "side A `{}` spans blocks {} and {}, whose solubility scales differ ({s0} and {s}): the flux h (c_A − K c_B) has no one K there",
                        p.side_a,
                        mesh.blocks[b0].sierra_name(),
                        mesh.blocks[b].sierra_name()
                    ));
                }
                Some(_) => {}
            }
        }
        Ok(found.map_or(1.0, |f| f.0))
    }
}

/// The species materials of `p` on `mesh`: D(T) and φ per block (checked as the other
/// material laws, at the probe temperature).
pub(super) fn materials(
    p: &Problem,
    mesh: &Mesh,
    probe: f64,
    diags: &mut Diagnostics,
) -> (Vec<Option<Law>>, Vec<f64>) {
    let mut diffusivity = vec![None; mesh.blocks.len()];
    let mut capacity = vec![1.0; mesh.blocks.len()];
    for (i, m) in p.material.iter().enumerate() {
        if m.species_capacity.is_some() && m.diffusivity.is_none() {
            diags.push(
                Diagnostic::error(
                    "E0704",
                    format!(
                        "[[material]] #{}: species_capacity without a diffusivity",
                        i + 1
                    ),
                )
                .help("a species lives in blocks with a diffusivity (m²/s): add one, or remove species_capacity"),
            );
            continue;
        }
        let Some(v) = &m.diffusivity else { continue };
        let what = format!("[[material]] #{} diffusivity", i + 1);
        let Some(d) = law(v, &what, probe, diags) else {
            continue;
        };
        let phi = m.species_capacity.unwrap_or(1.0);
        if !(phi > 0.0 && phi <= super::problem::MAX_MAGNITUDE) {
            diags.push(
                Diagnostic::error(
                    "E0704",
                    format!(
                        "[[material]] #{} species_capacity must be positive and at most 1e100, found {phi}",
                        i + 1
                    ),
                )
                .help("φ multiplies ∂c/∂t: 1 for c per unit volume of the body, the porosity for c per unit pore volume"),
            );
            continue;
        }
        for b in &m.blocks {
            if let Some(k) = mesh.find_block(b) {
                diffusivity[k] = Some(d.clone());
                capacity[k] = phi;
            }
        }
    }
    (diffusivity, capacity)
}

/// Species conditions need blocks with a diffusivity; a steady species needs a
/// prescribed concentration somewhere (else it floats).
pub(super) fn check_conditions(
    p: &Problem,
    at: &ProblemText,
    species: &Species,
    transient: bool,
    diags: &mut Diagnostics,
) {
    let bcs: Vec<usize> = (p.bc.iter().enumerate())
        .filter(|(_, b)| matches!(b.kind, BcKind::Species | BcKind::SpeciesFlux))
        .map(|(k, _)| k)
        .collect();
    if !species.any() {
        if let Some(&k) = bcs.first() {
            diags.push(
                Diagnostic::error(
                    "E0706",
                    format!(
                        "[[bc]] #{}: a {} condition, but no block carries a species",
                        k + 1,
                        p.bc[k].kind.name()
                    ),
                )
                .at(at.loc("bc", k, "kind"))
                .help("give the blocks' [[material]] a diffusivity (m²/s)"),
            );
        }
        return;
    }
    if !transient && species.dirichlet.is_empty() {
        diags.push(
            Diagnostic::error(
                "E0706",
                "blocks carry a species, but no [[bc]] of kind \"species\" fixes its concentration anywhere: the steady concentration would float",
            )
            .at(p
                .material
                .iter()
                .position(|m| m.diffusivity.is_some())
                .and_then(|i| at.loc("material", i, "diffusivity")))
            .help("add a [[bc]] with kind = \"species\" (a concentration, mol/m³), or solve a transient"),
        );
    }
}

/// Every species interface's two sides carry a species: a face of a block without a
/// diffusivity is refused at the enforcement block.
pub(super) fn check_interfaces(
    mesh: &Mesh,
    species: &Species,
    entries: &[Interface],
    diags: &mut Diagnostics,
) {
    let carries = |b: usize| species.diffusivity[b].is_some();
    let field = ("species", "E0432", "a diffusivity (m²/s)");
    check_sides(mesh, entries, &carries, field, diags);
}

/// Every face of `entries`' two sides lies in a block that `carries` the field (its
/// name, the code of the refusal, and the property that gives the field to a block).
pub(super) fn check_sides(
    mesh: &Mesh,
    entries: &[Interface],
    carries: &dyn Fn(usize) -> bool,
    (field, code, property): (&str, &'static str, &str),
    diags: &mut Diagnostics,
) {
    for e in entries {
        let p = &e.pairing;
        let faces = (p.side_a_geometry.faces.iter()).chain(&p.side_b_geometry.faces);
        let bare = faces
            .map(|f| mesh.block_of(f.side.elem))
            .find(|&b| !carries(b));
        if let Some(b) = bare {
            let name = mesh.blocks[b].sierra_name();
            diags.push(
                Diagnostic::error(
                    code,
                    format!(
                        "{field} interface {} / {}: block {name} carries no {field}",
                        p.side_a, p.side_b
                    ),
                )
                .at(Some(e.at.clone()))
                .help(format!(
                    "give block {name}'s [[material]] {property}, or take its surface out of the {field} interaction"
                )),
            );
        }
    }
}

/// The value of a species `[[bc]]` or initial concentration as the solve sees it, c/S.
pub(super) fn scaled(v: f64, node: NodeId, species: &Species) -> f64 {
    v / species.node_scale.get(node.index()).copied().unwrap_or(1.0)
}

/// The `[initial] species` concentration at each node (0 when not given), checked.
pub(super) fn initial(
    p: &Problem,
    mesh: &Mesh,
    sandbox: &super::physics::SharedSandbox,
    time: f64,
) -> Result<Vec<f64>, String> {
    let Some(v) = p.initial.as_ref().and_then(|i| i.species.as_ref()) else {
        return Ok(vec![0.0; mesh.num_nodes()]);
    };
    let value = |x: [f64; 3]| -> Result<f64, String> {
        let c = super::physics::evaluate(v, x, time, sandbox, "[initial] species")?;
        BcKind::Species
            .accepts(c)
            .map_err(|range| format!("{c:e} at ({}, {}, {}): {range}", x[0], x[1], x[2]))?;
        Ok(c)
    };
    if let Value::Number(c) = v {
        value([0.0; 3])?;
        return Ok(vec![*c; mesh.num_nodes()]);
    }
    mesh.coords.iter().map(|x| value(*x)).collect()
}

/// An interface of the run on a field other than the temperature — a species interface,
/// or a voltage tie (K = 1) — the scene's, its model shared with the terms.
pub(super) struct Interface {
    pub pairing: crate::search::scene::Pairing,
    pub choice: ModelChoice,
    pub penalty_scale: f64,
    pub model: Option<Arc<dyn ConductanceModel>>,
    /// The partition coefficient K.
    pub partition: f64,
    /// The enforcement block.
    pub at: crate::diag::Loc,
    /// What searching it again takes, when the surfaces move; taken by the embedding.
    pub again: std::cell::RefCell<Option<crate::scene::SearchAgain>>,
    /// Its definition's `Update Search Every n Steps`, when the surfaces move.
    pub search_every: Option<u32>,
    /// Its contact definition (whose rules make its surfaces again under death).
    pub definition: usize,
}

impl From<FieldEnforced> for Interface {
    fn from(e: FieldEnforced) -> Self {
        Interface {
            pairing: e.pairing,
            choice: e.choice,
            penalty_scale: e.penalty_scale,
            model: e.model.map(Arc::from),
            partition: e.partition,
            at: e.at,
            again: std::cell::RefCell::new(e.again),
            search_every: None,
            definition: e.definition,
        }
    }
}

impl Interface {
    /// The enforcement in the scaled unknown, with side A's scale `s_a`: the offset
    /// Δc/S_A and the mass-transfer coefficient h S_A (module docs).
    pub(super) fn scaled(&self, s_a: f64) -> (ModelChoice, Option<Arc<dyn ConductanceModel>>) {
        let mut choice = self.choice.clone();
        choice.offset /= s_a;
        if let Some(ConductanceLaw::Constant(h)) = choice.conductance {
            choice.conductance = Some(ConductanceLaw::Constant(h * s_a));
        }
        let model = self.model.as_ref().map(|m| {
            let scaled: Box<dyn ConductanceModel> = Box::new(Scaled {
                model: m.clone(),
                factor: s_a,
            });
            Arc::from(scaled)
        });
        (choice, model)
    }
}

/// A conductance model times a constant factor (its derivatives too).
struct Scaled {
    model: Arc<dyn ConductanceModel>,
    factor: f64,
}

impl ConductanceModel for Scaled {
    fn name(&self) -> String {
        self.model.name()
    }

    fn evaluate(&self, state: &PointState) -> Result<Conductance, ConductanceError> {
        let c = self.model.evaluate(state)?;
        let f = self.factor;
        Ok(Conductance {
            h: f * c.h,
            dh_dgap: f * c.dh_dgap,
            dh_dpressure: f * c.dh_dpressure,
            dh_dtemp_a: f * c.dh_dtemp_a,
            dh_dtemp_b: f * c.dh_dtemp_b,
        })
    }

    fn depends_on_temperature(&self) -> bool {
        self.model.depends_on_temperature()
    }

    fn depends_on_time(&self) -> bool {
        self.model.depends_on_time()
    }
}

/// Per species interface: (side A, side B, model), for the CSV and the summary.
pub(super) fn labels(interfaces: &[Interface]) -> Vec<(String, String, String)> {
    interfaces
        .iter()
        .map(|s| {
            let p = &s.pairing;
            (p.side_a.clone(), p.side_b.clone(), s.choice.name.clone())
        })
        .collect()
}
