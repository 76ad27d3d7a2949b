//! Embedding seam in a host code that owns its mesh, its unknowns and its matrix.
//!
//! Entry point: [`Embedding::builder`]. The host hands over its node coordinates, its
//! element blocks (topology, connectivity, conductivity), the faces its interfaces are
//! made of — as (element, local side) pairs or as face node lists — and its own DOF
//! number of each node. It then adds interactions, either in code ([`Interaction`]) or
//! from a Sierra contact deck ([`Embedding::add_deck`]), searches them
//! ([`Embedding::search`]), and at each Newton step asks for the interface terms at its
//! current field ([`Embedding::contributions`]): residual entries `(dof, value)` and
//! Jacobian triplets `(row, col, value)` in the host's own numbering, plus the heat
//! through each side. Mortar ties give constraint rows instead
//! ([`Embedding::constraints`]); dual multipliers give them in the condensed form
//! `u_A = g + Σ c_j u_j`, for hosts that carry no multipliers.
//!
//! Periodic conditions pair the image of a surface under a map with its partner, from a
//! deck's `Periodicity For S = …` or in code ([`Interaction::periodic`]); the terms
//! couple each side-A node with the side-B nodes its image lands between, in host dof
//! numbers, like any other interaction. Plugin enforcements (`Enforcement for Energy =
//! Plugin Library = …`) load their library when the deck is added; a plugin that fails
//! at a point is [`EmbedError::Plugin`], one that asks for a smaller step is
//! [`EmbedError::Cutback`].
//!
//! ```no_run
//! use seam::embed::{Embedding, Interaction, Model, Topology};
//! # fn host() -> Result<(), seam::embed::EmbedError> {
//! # let (coords, conn, top, bottom, dof_of_node, u): (Vec<[f64; 3]>, Vec<usize>,
//! #   Vec<(usize, u8)>, Vec<[usize; 4]>, Vec<usize>, Vec<f64>) = Default::default();
//! let mut seam = Embedding::builder(&coords)
//!     .block("solid", Topology::Hex8, &conn, 16.0)
//!     .side_set("top", &top)        // (element, 1-based Exodus side)
//!     .face_set("bottom", &bottom)  // face node lists
//!     .dofs(&dof_of_node)
//!     .build()?;
//! seam.add_interaction(Interaction::new("top", "bottom", Model::GapConductance { h: 500.0 }))?;
//! seam.search()?;
//! let c = seam.contributions(&u)?;
//! for &(row, col, v) in &c.jacobian { /* K[row][col] += v */ }
//! # Ok(()) }
//! ```
//!
//! Conventions:
//! - Node and element indices are the host's, 0-based: nodes index `coords`, elements
//!   are numbered block after block in the order the blocks were given. Messages use
//!   these numbers. Local sides are 1-based, Exodus II order ([`crate::mesh::topology`]).
//! - Residual and Jacobian: the host adds `residual` to its residual `R(u) = K u − F`
//!   and `jacobian` to `∂R/∂u`. For a linear model `residual = J_Γ u − load`, so a host
//!   that assembles `K u = F` once adds `jacobian` to `K` and `load` to `F`.
//! - Heat: W leaving side A and leaving side B through the interface (their sum is zero
//!   to round-off); positive side A means heat flows from A to B.
//! - Nothing here panics on host input: every check returns an [`EmbedError`] that says
//!   what is wrong, where, and how to fix it.

use std::cell::Cell;
use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use std::sync::{Arc, OnceLock};

use crate::assembly::{DofMap, FieldId};
use crate::deck::spec::{ContactDefinition, Enforcement as DeckEnforcement};
use crate::deck::{self, Deck};
use crate::diag::{Diagnostics, SourceMap, did_you_mean};
use crate::enforce::conductance::SeenTemperature;
use crate::enforce::conductance::{
    ConductanceError, ConductanceModel, PluginConductance, PointState,
};
use crate::enforce::interface::{
    DEFAULT_BETA, Form, HInput, HValue, InterfaceError, InterfaceForm, InterfacePoints,
};
use crate::enforce::model::ConductanceLaw;
use crate::enforce::mortar::mortar_tie;
use crate::mesh::{ElemId, Mesh, NodeId, Side, SideSet, ValidationError};
use crate::periodic::PeriodicMap;
use crate::scene::enforcement::resolve as resolve_model;
use crate::scene::search::search_periodicity;
use crate::search::SearchSettings;
use crate::search::pairing::{SearchResult, SearchStats, Searcher, Sphere, SurfaceGeometry};
use crate::search::periodic::{
    PeriodicError, PeriodicTransform, check_closure, landing, periodic_map,
};
use crate::search::scene::{SceneSearch, surface_geometries};
use crate::surface::{ContactSurface, SurfaceFace, SurfaceKind};

pub use crate::enforce::mortar::Multipliers;
pub use crate::mesh::Topology;
pub use crate::search::Overclosure;
pub use crate::search::pairing::Integration;

/// Everything that can go wrong between a host and seam.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EmbedError {
    /// The host's mesh arrays are inconsistent.
    #[error("host mesh: {what}\n  help: {help}")]
    Mesh { what: String, help: String },
    /// The mesh is well formed but fails seam's checks (inverted element, …).
    #[error("host mesh: {0}")]
    Invalid(#[from] ValidationError),
    #[error("unknown surface `{name}`\n  help: {help}")]
    UnknownSurface { name: String, help: String },
    /// A contact deck with errors: the rendered diagnostics.
    #[error("contact deck:\n{0}")]
    Deck(String),
    /// An argument out of range (a model parameter, a field vector too short, …).
    #[error("{what}\n  help: {help}")]
    Argument { what: String, help: String },
    /// A call out of order, e.g. contributions before the first search.
    #[error("{what}\n  help: {help}")]
    Order { what: String, help: String },
    /// An enforcement failed at a contact point (bad element, failing conductance model).
    #[error("interaction {side_a} / {side_b}: {source}")]
    Enforcement {
        side_a: String,
        side_b: String,
        source: InterfaceError,
    },
    /// A plugin enforcement could not be loaded (`add_deck`), or its plugin failed at a
    /// contact point (`contributions`): an error status, a non-finite or negative value.
    /// The message names the plugin's library and, at a point, where it is.
    #[error(
        "interaction {side_a} / {side_b}: {message}\n  help: `seam check-plugin LIB` loads and probes a plugin on its own"
    )]
    Plugin {
        side_a: String,
        side_b: String,
        message: String,
    },
    /// A plugin asks for a smaller step (`SEAM_STATUS_CUTBACK`): not a failure of the
    /// model, a request to the host to retry its time (or load) step with a smaller one.
    #[error(
        "interaction {side_a} / {side_b}: {message}\n  help: retry the step with a smaller one (suggested new/old step {factor}; 0: the host decides)"
    )]
    Cutback {
        side_a: String,
        side_b: String,
        /// The plugin's suggested new/old step in (0, 1), or 0: the host decides.
        factor: f64,
        message: String,
    },
}

fn mesh_error(what: String, help: &str) -> EmbedError {
    EmbedError::Mesh {
        what,
        help: help.into(),
    }
}

fn argument(what: String, help: &str) -> EmbedError {
    EmbedError::Argument {
        what,
        help: help.into(),
    }
}

/// How an interaction enforces the energy equation (see [`crate::enforce::interface`]
/// for the forms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Model {
    /// `q = h [u]`, integrated on side A (contact resistance).
    Conductance { h: f64 },
    /// Robin–Nitsche gap conductance: stable for every `h` in `[0, ∞]`.
    GapConductance { h: f64 },
    /// Weighted symmetric Nitsche tie `[u] = 0` (no extra unknowns).
    TiedNitsche,
    /// Mortar tie with Lagrange multipliers on side A: constraint rows
    /// ([`Embedding::constraints`]) instead of residual terms.
    TiedMortar { multipliers: Multipliers },
}

/// A periodic map of an interaction built in code: side A's image under the map is
/// paired with side B, as `Periodicity For A = …` pairs it with its destination in a deck
/// ([`crate::periodic`]). Side A keeps its own nodes and dofs: the interaction couples
/// each point of A with the point of B its image lands on.
#[derive(Clone, Debug, PartialEq)]
pub enum Periodic {
    /// `Rectangular Offset`: `x ↦ x + offset`.
    Rectangular { offset: [f64; 3] },
    /// `Cylindrical`: a turn by `angle` degrees (counter-clockwise, right-hand rule)
    /// about the line through `center` along `axis`. An N-fold turn (`360/angle` an
    /// integer N) must come back to the start after N turns.
    Cylindrical {
        axis: [f64; 3],
        center: [f64; 3],
        angle: f64,
    },
    /// `Align_Surface`: the rigid map taking A's centroid and mean normal onto B's,
    /// normals opposed when `invert_normals` (two sides of an interface face each other).
    AlignSurface { invert_normals: bool },
    /// `Mapped`: each component a Lua expression in `x`, `y`, `z` or
    /// `file.lua:function` (a file under the working directory); without `z`, z is kept.
    Mapped {
        x: String,
        y: String,
        z: Option<String>,
    },
}

impl Periodic {
    /// The deck's transform, with `side_b` as the destination.
    fn transform(&self, side_b: &str) -> PeriodicTransform {
        match self {
            Periodic::Rectangular { offset } => PeriodicTransform::Rectangular {
                offset: offset.to_vec(),
            },
            Periodic::Cylindrical {
                axis,
                center,
                angle,
            } => PeriodicTransform::Cylindrical {
                axis: axis.to_vec(),
                center: center.to_vec(),
                angle: *angle,
            },
            Periodic::AlignSurface { invert_normals } => PeriodicTransform::AlignSurface {
                destination: side_b.to_string(),
                invert_normals: *invert_normals,
            },
            Periodic::Mapped { x, y, z } => PeriodicTransform::Mapped {
                x_map: x.clone(),
                y_map: y.clone(),
                z_map: z.clone(),
            },
        }
    }
}

/// One interaction built in code: two surfaces and a model.
#[derive(Clone, Debug)]
pub struct Interaction {
    side_a: String,
    side_b: String,
    model: Model,
    offset: f64,
    beta: f64,
    settings: Option<SearchSettings>,
    periodic: Option<Periodic>,
}

impl Interaction {
    /// Side A carries the integration points; side B is projected onto.
    pub fn new(side_a: &str, side_b: &str, model: Model) -> Self {
        Interaction {
            side_a: side_a.to_string(),
            side_b: side_b.to_string(),
            model,
            offset: 0.0,
            beta: DEFAULT_BETA,
            settings: None,
            periodic: None,
        }
    }

    /// Pair the image of side A under `map` with side B (a periodic condition).
    pub fn periodic(mut self, map: Periodic) -> Self {
        self.periodic = Some(map);
        self
    }

    /// A prescribed jump `u_A − u_B = ΔT` (`Offset Temperature`).
    pub fn offset(mut self, delta_t: f64) -> Self {
        self.offset = delta_t;
        self
    }

    /// The Nitsche penalty factor β (default [`DEFAULT_BETA`]).
    pub fn penalty_factor(mut self, beta: f64) -> Self {
        self.beta = beta;
        self
    }

    /// Search tolerances other than the defaults of [`SearchSettings::defaults`].
    pub fn search_settings(mut self, settings: SearchSettings) -> Self {
        self.settings = Some(settings);
        self
    }
}

/// Heat through one interaction, W.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Heat {
    pub side_a: f64,
    pub side_b: f64,
}

/// The interface terms at one field, in the host's numbering.
#[derive(Clone, Debug, Default)]
pub struct Contributions {
    /// `(dof, value)`, to add to the host's residual; a dof may repeat.
    pub residual: Vec<(usize, f64)>,
    /// `(row, col, value)`, to add to the host's Jacobian; pairs may repeat.
    pub jacobian: Vec<(usize, usize, f64)>,
    /// `(dof, value)`, the right-hand side of linear models (offset terms).
    pub load: Vec<(usize, f64)>,
    /// Per interaction, in the order they were added; `None` for mortar ties (see
    /// [`TieConstraints::heat`]).
    pub heat: Vec<Option<Heat>>,
}

/// One side-A dof of a dual mortar tie in condensed form: `u[dof] = constant + Σ c u[j]`.
#[derive(Clone, Debug, PartialEq)]
pub struct Condensed {
    pub dof: usize,
    pub constant: f64,
    pub terms: Vec<(usize, f64)>,
}

/// The constraint rows of one mortar tie, in the host's numbering.
#[derive(Clone, Debug, Default)]
pub struct TieConstraints {
    /// Index of the interaction.
    pub interaction: usize,
    /// The host dof of each multiplier's side-A node, in multiplier order.
    pub multiplier_dofs: Vec<usize>,
    /// `(multiplier k, dof j, C_kj)`: the rows of `C u = g`.
    pub entries: Vec<(usize, usize, f64)>,
    /// `g_k = ΔT ∫ψ_k`.
    pub rhs: Vec<f64>,
    /// Dual multipliers only: each multiplier's side-A dof in condensed form (a host
    /// without multipliers substitutes these rows; the system stays SPD).
    pub condensed: Vec<Condensed>,
    /// `C_kk` of each multiplier's own dof (dual: the diagonal `D`).
    diagonal: Vec<f64>,
    side_a_dofs: Vec<usize>,
    side_b_dofs: Vec<usize>,
}

impl TieConstraints {
    /// Heat leaving each side for multipliers `lambda` (the flux from A to B), one per
    /// multiplier: `Σ_{i ∈ side} (Cᵀλ)_i`.
    pub fn heat(&self, lambda: &[f64]) -> Result<Heat, EmbedError> {
        if lambda.len() != self.multiplier_dofs.len() {
            return Err(argument(
                format!(
                    "{} multipliers given, the tie has {}",
                    lambda.len(),
                    self.multiplier_dofs.len()
                ),
                "pass one value per entry of `multiplier_dofs`",
            ));
        }
        let mut ct: HashMap<usize, f64> = HashMap::new();
        for &(k, j, c) in &self.entries {
            *ct.entry(j).or_default() += c * lambda[k];
        }
        let sum = |set: &[usize]| set.iter().filter_map(|d| ct.get(d)).sum::<f64>();
        Ok(Heat {
            side_a: sum(&self.side_a_dofs),
            side_b: sum(&self.side_b_dofs),
        })
    }

    /// Dual multipliers of a host that condensed the tie: `λ_k = −r_k / D_k`, with `r`
    /// the host's own residual `K u − F` (without the tie) at its solution, by host dof.
    pub fn dual_multipliers(&self, residual: &[f64]) -> Result<Vec<f64>, EmbedError> {
        if self.condensed.is_empty() && !self.multiplier_dofs.is_empty() {
            return Err(argument(
                "this tie has standard multipliers; they are unknowns of the host's system".into(),
                "read λ from the host's solution, or build the tie with Multipliers::Dual",
            ));
        }
        self.multiplier_dofs
            .iter()
            .zip(&self.diagonal)
            .map(|(&d, &diag)| {
                let r = residual.get(d).ok_or_else(|| {
                    argument(
                        format!("residual has {} entries, dof {d} is needed", residual.len()),
                        "pass the host's whole residual vector",
                    )
                })?;
                Ok(if diag == 0.0 { 0.0 } else { -r / diag })
            })
            .collect()
    }
}

/// Faces of a surface as the host gave them.
#[derive(Clone, Debug)]
enum Faces {
    Sides(Vec<(usize, u8)>),
    Nodes(Vec<Vec<usize>>),
}

#[derive(Clone, Debug)]
struct BlockInput {
    name: String,
    topology: Topology,
    connectivity: Vec<usize>,
    conductivity: f64,
}

/// The host's mesh and numbering, checked by [`EmbeddingBuilder::build`].
#[derive(Clone, Debug)]
pub struct EmbeddingBuilder {
    coords: Vec<[f64; 3]>,
    blocks: Vec<BlockInput>,
    surfaces: Vec<(String, Faces)>,
    dofs: Option<Vec<Option<usize>>>,
    fixed: Vec<usize>,
    integration: Integration,
}

impl EmbeddingBuilder {
    /// An element block: `connectivity` holds `topology.node_count()` node indices per
    /// element; `conductivity` (W/m/K) weighs the Nitsche forms.
    pub fn block(
        mut self,
        name: &str,
        topology: Topology,
        connectivity: &[usize],
        conductivity: f64,
    ) -> Self {
        self.blocks.push(BlockInput {
            name: name.to_string(),
            topology,
            connectivity: connectivity.to_vec(),
            conductivity,
        });
        self
    }

    /// A surface of (element, 1-based local side) pairs.
    pub fn side_set(mut self, name: &str, sides: &[(usize, u8)]) -> Self {
        self.surfaces
            .push((name.to_string(), Faces::Sides(sides.to_vec())));
        self
    }

    /// A surface of faces given by their nodes (any order, any rotation): each must be a
    /// side of exactly one element. Its orientation is taken from that element.
    pub fn face_set<F: AsRef<[usize]>>(mut self, name: &str, faces: &[F]) -> Self {
        let faces = faces.iter().map(|f| f.as_ref().to_vec()).collect();
        self.surfaces.push((name.to_string(), Faces::Nodes(faces)));
        self
    }

    /// The host's dof number of every node (`dofs[node]`).
    pub fn dofs(mut self, dofs: &[usize]) -> Self {
        self.dofs = Some(dofs.iter().map(|&d| Some(d)).collect());
        self
    }

    /// As [`Self::dofs`], `None` for nodes without a temperature dof (they must not
    /// belong to any block).
    pub fn partial_dofs(mut self, dofs: &[Option<usize>]) -> Self {
        self.dofs = Some(dofs.to_vec());
        self
    }

    /// Nodes whose value the host prescribes (Dirichlet): mortar ties give them no
    /// multiplier (they would constrain them twice).
    pub fn fixed_nodes(mut self, nodes: &[usize]) -> Self {
        self.fixed = nodes.to_vec();
        self
    }

    /// How side-A points are placed (default: mortar segments, order 5, as `seam run`).
    pub fn integration(mut self, integration: Integration) -> Self {
        self.integration = integration;
        self
    }

    /// Check everything and make the embedding.
    pub fn build(self) -> Result<Embedding, EmbedError> {
        let n = self.coords.len();
        if n == 0 {
            return Err(mesh_error(
                "no nodes".into(),
                "pass the node coordinates to Embedding::builder",
            ));
        }
        if self.blocks.is_empty() {
            return Err(mesh_error(
                "no element blocks".into(),
                "add the blocks whose faces make the interfaces with .block(…)",
            ));
        }
        let mut mesh = Mesh {
            dim: 3,
            coords: self.coords.clone(),
            node_numbers: (0..n as i64).collect(),
            ..Mesh::default()
        };
        let mut conductivity = Vec::with_capacity(self.blocks.len());
        for (b, block) in self.blocks.iter().enumerate() {
            let nn = block.topology.node_count();
            if block.topology.parametric_dim() != 3 || !block.topology.is_solid() {
                return Err(mesh_error(
                    format!(
                        "block `{}` has topology {:?}; interfaces are searched between 3-D solids",
                        block.name, block.topology
                    ),
                    "give Hex8, Tet4, Wedge6 or Pyramid5 blocks",
                ));
            }
            if block.connectivity.len() % nn != 0 {
                return Err(mesh_error(
                    format!(
                        "block `{}`: {} connectivity entries is not a multiple of {nn} ({:?})",
                        block.name,
                        block.connectivity.len(),
                        block.topology
                    ),
                    "give topology.node_count() node indices per element",
                ));
            }
            if let Some((k, &node)) = block
                .connectivity
                .iter()
                .enumerate()
                .find(|(_, node)| **node >= n)
            {
                return Err(mesh_error(
                    format!(
                        "block `{}`, element {} (local node {}): node {node} does not exist, there are {n} nodes",
                        block.name,
                        k / nn,
                        k % nn + 1
                    ),
                    "node indices are 0-based positions in the coordinate array",
                ));
            }
            if !(block.conductivity.is_finite() && block.conductivity > 0.0) {
                return Err(mesh_error(
                    format!(
                        "block `{}`: conductivity {} is not a positive number",
                        block.name, block.conductivity
                    ),
                    "give k > 0 in W/m/K",
                ));
            }
            let first = mesh.elem_numbers.len() as i64;
            let count = (block.connectivity.len() / nn) as i64;
            mesh.push_block(
                b as i64 + 1,
                block.name.clone(),
                block.topology,
                block
                    .connectivity
                    .iter()
                    .map(|&i| NodeId(i as u32))
                    .collect(),
                Some((first..first + count).collect()),
            );
            conductivity.push(block.conductivity);
        }
        if n > u32::MAX as usize || mesh.num_elems() > u32::MAX as usize {
            return Err(mesh_error(
                format!("{n} nodes, {} elements", mesh.num_elems()),
                "seam numbers nodes and elements with 32-bit indices",
            ));
        }
        let mut by_nodes: Option<HashMap<[u32; 4], Vec<Side>>> = None;
        let mut names = HashSet::new();
        for (s, (name, faces)) in self.surfaces.iter().enumerate() {
            if !names.insert(name.to_ascii_lowercase()) {
                return Err(mesh_error(
                    format!("surface `{name}` is given twice"),
                    "give every surface its own name (names are case-insensitive)",
                ));
            }
            let sides = match faces {
                Faces::Sides(list) => sides_by_number(&mesh, name, list)?,
                Faces::Nodes(list) => {
                    let table = by_nodes.get_or_insert_with(|| face_table(&mesh));
                    sides_by_nodes(table, name, list)?
                }
            };
            mesh.side_sets.push(SideSet {
                id: s as i64 + 1,
                name: name.clone(),
                sides,
            });
        }
        mesh.validate()?;
        // Seam's own numbering of the temperature dofs, mapped to the host's.
        let solid: Vec<usize> = (0..mesh.blocks.len()).collect();
        let dofs = DofMap::new(&mesh, &[("temperature", &solid)])
            .map_err(|e| mesh_error(e.to_string(), "check the blocks"))?;
        let field = FieldId(0);
        let host = self.dofs.ok_or_else(|| {
            mesh_error(
                "no dof numbers".into(),
                "pass the host's dof number of every node with .dofs(…)",
            )
        })?;
        if host.len() != n {
            return Err(mesh_error(
                format!("{} dof numbers for {n} nodes", host.len()),
                "pass one dof number per node, in node order",
            ));
        }
        let mut host_dof = vec![0usize; dofs.len()];
        for (node, number) in host.iter().enumerate() {
            if let Some(d) = dofs.dof(field, NodeId(node as u32)) {
                host_dof[d.index()] = number.ok_or_else(|| {
                    mesh_error(
                        format!("node {node} belongs to an element block but has no dof number"),
                        "every node of a block needs the host's dof number",
                    )
                })?;
            }
        }
        if let Some(&bad) = self.fixed.iter().find(|&&f| f >= n) {
            return Err(mesh_error(
                format!("fixed node {bad} does not exist, there are {n} nodes"),
                "node indices are 0-based positions in the coordinate array",
            ));
        }
        Ok(Embedding {
            mesh,
            dofs,
            field,
            host_dof,
            conductivity,
            fixed: self.fixed.iter().map(|&f| NodeId(f as u32)).collect(),
            integration: self.integration,
            pairs: Vec::new(),
            time: 0.0,
        })
    }
}

fn sides_by_number(mesh: &Mesh, name: &str, list: &[(usize, u8)]) -> Result<Vec<Side>, EmbedError> {
    let elems = mesh.num_elems();
    list.iter()
        .enumerate()
        .map(|(k, &(elem, side))| {
            if elem >= elems {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: element {elem} does not exist, there are {elems}"),
                    "element indices are 0-based, numbered block after block",
                ));
            }
            let topology = mesh.topology(ElemId(elem as u32));
            let count = topology.face_side_count();
            if side == 0 || usize::from(side) > count {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: element {elem} ({topology:?}) has no side {side}"),
                    &format!("local sides are 1-based, Exodus order: 1 to {count}"),
                ));
            }
            Ok(Side {
                elem: ElemId(elem as u32),
                side,
            })
        })
        .collect()
}

/// Sorted node indices of a face, padded with `u32::MAX`.
fn face_key(nodes: impl Iterator<Item = u32>) -> [u32; 4] {
    let mut key = [u32::MAX; 4];
    for (k, n) in nodes.take(4).enumerate() {
        key[k] = n;
    }
    key.sort_unstable();
    key
}

/// Every element side, by its sorted nodes.
fn face_table(mesh: &Mesh) -> HashMap<[u32; 4], Vec<Side>> {
    let mut table: HashMap<[u32; 4], Vec<Side>> = HashMap::new();
    for block in &mesh.blocks {
        for elem in block.elems() {
            for s in 1..=block.topology.face_side_count() as u8 {
                let side = Side { elem, side: s };
                table
                    .entry(face_key(mesh.side_nodes(side).map(|n| n.0)))
                    .or_default()
                    .push(side);
            }
        }
    }
    table
}

fn sides_by_nodes(
    table: &HashMap<[u32; 4], Vec<Side>>,
    name: &str,
    list: &[Vec<usize>],
) -> Result<Vec<Side>, EmbedError> {
    list.iter()
        .enumerate()
        .map(|(k, nodes)| {
            if !matches!(nodes.len(), 3 | 4) || nodes.iter().any(|&n| n >= u32::MAX as usize) {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: nodes {nodes:?} are no triangle or quadrilateral"),
                    "give the 3 or 4 corner nodes of each face",
                ));
            }
            let key = face_key(nodes.iter().map(|&n| n as u32));
            match table.get(&key).map(Vec::as_slice) {
                Some([side]) => Ok(*side),
                Some([a, b, ..]) => Err(mesh_error(
                    format!(
                        "surface `{name}`, face {k} (nodes {nodes:?}) lies between elements {} and {}",
                        a.elem.0, b.elem.0
                    ),
                    "an interface face must be on the boundary of its block; give it as (element, side) to choose one",
                )),
                _ => Err(mesh_error(
                    format!("surface `{name}`, face {k}: nodes {nodes:?} are no side of any element"),
                    "give the corner nodes of one element face (0-based node indices)",
                )),
            }
        })
        .collect()
}

/// The conductance of a flux-type interaction.
enum Law {
    Constant(f64),
    /// A model from the deck (`Gap Conductance Coefficient = …`) and the contact
    /// pressure it sees.
    Model(Box<dyn ConductanceModel>, f64),
    /// A plugin (`Enforcement for Energy = Plugin …`) and the contact pressure it sees:
    /// its faults and cutback requests become [`EmbedError::Plugin`] and
    /// [`EmbedError::Cutback`].
    Plugin(Box<PluginConductance>, f64),
}

enum Enforcement {
    Flux {
        form: Form,
        law: Law,
        offset: f64,
        beta: f64,
    },
    Tie {
        multipliers: Multipliers,
        offset: f64,
    },
}

/// The map of a periodic pair: side A is the image of its surface under it.
struct Image {
    map: Box<dyn PeriodicMap>,
    name: String,
}

/// One interaction and its search state.
struct Pair {
    side_a: ContactSurface,
    side_b: ContactSurface,
    /// Side A's geometry as searched (for a periodic pair: the image).
    a: SurfaceGeometry,
    b: SurfaceGeometry,
    settings: SearchSettings,
    /// `None` for periodic pairs, which keep their gaps as found (as `seam run`).
    overclosure: Option<Overclosure>,
    /// `Restrict Contact To Subdomain` of the deck's definition.
    subdomain: Option<Sphere>,
    image: Option<Image>,
    enforcement: Enforcement,
    searcher: Option<Searcher>,
    result: Option<SearchResult>,
    /// The interface geometry at the points of `result`, made at the first
    /// `contributions` after a search or a move and reused until the next.
    points: OnceLock<InterfacePoints>,
}

/// seam inside a host: the host's mesh and numbering, its interactions and their search.
pub struct Embedding {
    mesh: Mesh,
    dofs: DofMap,
    field: FieldId,
    /// The host's dof of each of seam's dofs.
    host_dof: Vec<usize>,
    conductivity: Vec<f64>,
    fixed: Vec<NodeId>,
    integration: Integration,
    pairs: Vec<Pair>,
    /// The host's time, passed to conductance models and plugins (0 until set).
    time: f64,
}

impl Embedding {
    /// Start from the host's node coordinates (3-D).
    pub fn builder(coords: &[[f64; 3]]) -> EmbeddingBuilder {
        EmbeddingBuilder {
            coords: coords.to_vec(),
            blocks: Vec::new(),
            surfaces: Vec::new(),
            dofs: None,
            fixed: Vec::new(),
            integration: Integration::Segments { order: 5 },
        }
    }

    /// The mesh seam built from the host's arrays (for inspection and output).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    fn surface(&self, name: &str) -> Result<ContactSurface, EmbedError> {
        let Some(set) = self.mesh.find_side_set(name) else {
            let names: Vec<String> = self.mesh.side_sets.iter().map(|s| s.name.clone()).collect();
            let help = did_you_mean(name, names.iter().map(String::as_str)).map_or_else(
                || format!("the surfaces are: {}", names.join(", ")),
                |s| format!("did you mean `{s}`?"),
            );
            return Err(EmbedError::UnknownSurface {
                name: name.into(),
                help,
            });
        };
        let ss = &self.mesh.side_sets[set];
        Ok(ContactSurface {
            name: ss.sierra_name(),
            kind: SurfaceKind::Faces,
            faces: ss
                .sides
                .iter()
                .map(|&side| SurfaceFace {
                    side,
                    loft: 0.0,
                    origin: 0,
                })
                .collect(),
            tributary: Vec::new(),
            nodes: Vec::new(),
            origins: vec![(format!("surface {}", ss.name), ss.sides.len())],
            parent: None,
        })
    }

    fn geometry(&self, s: &ContactSurface) -> Result<SurfaceGeometry, EmbedError> {
        SurfaceGeometry::from_surface(&self.mesh, s, &self.mesh.coords)
            .map_err(|e| argument(e.to_string(), "interfaces are searched in 3-D"))
    }

    fn pair(
        &self,
        side_a: ContactSurface,
        side_b: ContactSurface,
        settings: SearchSettings,
        overclosure: Overclosure,
        subdomain: Option<Sphere>,
        enforcement: Enforcement,
    ) -> Result<Pair, EmbedError> {
        let (a, b) = (self.geometry(&side_a)?, self.geometry(&side_b)?);
        Ok(Pair {
            side_a,
            side_b,
            a,
            b,
            settings,
            overclosure: Some(overclosure),
            subdomain,
            image: None,
            enforcement,
            searcher: None,
            result: None,
            points: OnceLock::new(),
        })
    }

    /// A periodic pair built in code: side A's image under `periodic`, checked to land
    /// on side B (the checks of a deck's periodicity: an N-fold turn closes up, the
    /// worst image node is within 5 % of B's mean face size).
    fn periodic_pair(
        &self,
        side_a: ContactSurface,
        side_b: ContactSurface,
        settings: SearchSettings,
        periodic: &Periodic,
        enforcement: Enforcement,
    ) -> Result<Pair, EmbedError> {
        let label = format!("periodic interaction {} / {}", side_a.name, side_b.name);
        let fail = |e: &dyn std::fmt::Display, help: &str| argument(format!("{label}: {e}"), help);
        let (source, b) = (self.geometry(&side_a)?, self.geometry(&side_b)?);
        let transform = periodic.transform(&side_b.name);
        let model_size = self.mesh.model_size();
        check_closure(&transform, &source, model_size).map_err(|e| {
            fail(
                &e,
                "give the angle to full precision (e.g. 360/7 as 51.428571428571431)",
            )
        })?;
        let mut map = periodic_map(
            &transform,
            &source,
            Some(&b),
            Path::new("."),
            &label,
            model_size,
        )
        .map_err(|e| {
            let help = match e {
                PeriodicError::ZeroAxis => "give a non-zero axis",
                PeriodicError::NoMeanNormal => "`AlignSurface` needs two roughly planar surfaces",
                _ => {
                    "fix the Lua map: each component is an expression in x, y, z or `file.lua:function` (under the working directory)"
                }
            };
            fail(&e, help)
        })?;
        let name = format!("{}_image", side_a.name);
        let a = source
            .mapped(map.as_mut(), &name)
            .map_err(|e| fail(&e, "the map failed while mapping side A's nodes"))?;
        if let Some(fold) =
            crate::search::periodic::check_one_to_one(&source, &a, |n| self.mesh.node_number(n))
        {
            return Err(fail(
                &PeriodicError::Folds(Box::new(fold)),
                "a periodic map carries each node to its own place on side B; check the map",
            ));
        }
        landing(&a, &b).check(&side_b.name).map_err(|e| {
            fail(
                &e,
                "the map must carry side A exactly onto side B; check the offset, axis, centre, angle or map",
            )
        })?;
        Ok(Pair {
            side_a,
            side_b,
            a,
            b,
            settings,
            overclosure: None,
            subdomain: None,
            image: Some(Image { map, name }),
            enforcement,
            searcher: None,
            result: None,
            points: OnceLock::new(),
        })
    }

    /// Add an interaction built in code; returns its index.
    pub fn add_interaction(&mut self, i: Interaction) -> Result<usize, EmbedError> {
        let check = |what: &str, v: f64, allow_inf: bool| {
            if v.is_nan() || v < 0.0 || (v.is_infinite() && !allow_inf) {
                Err(argument(
                    format!("{what} = {v} on interaction {} / {}", i.side_a, i.side_b),
                    "give a non-negative number",
                ))
            } else {
                Ok(())
            }
        };
        let enforcement = match i.model {
            Model::Conductance { h } | Model::GapConductance { h } => {
                let gap = matches!(i.model, Model::GapConductance { .. });
                // h = ∞ is the tied limit of the Robin–Nitsche form only.
                check("h", h, gap)?;
                check("penalty factor", i.beta, false)?;
                Enforcement::Flux {
                    form: if gap {
                        Form::GapConductance
                    } else {
                        Form::Conductance
                    },
                    law: Law::Constant(h),
                    offset: i.offset,
                    beta: i.beta,
                }
            }
            Model::TiedNitsche => {
                check("penalty factor", i.beta, false)?;
                Enforcement::Flux {
                    form: Form::TiedNitsche,
                    law: Law::Constant(0.0),
                    offset: i.offset,
                    beta: i.beta,
                }
            }
            Model::TiedMortar { multipliers } => Enforcement::Tie {
                multipliers,
                offset: i.offset,
            },
        };
        if !i.offset.is_finite() {
            return Err(argument(
                format!(
                    "offset {} on interaction {} / {}",
                    i.offset, i.side_a, i.side_b
                ),
                "give a finite temperature jump",
            ));
        }
        let (a, b) = (self.surface(&i.side_a)?, self.surface(&i.side_b)?);
        let settings = i.settings.unwrap_or_else(|| SearchSettings::defaults(3));
        let pair = match &i.periodic {
            None => self.pair(a, b, settings, Overclosure::StoreOffsets, None, enforcement)?,
            Some(periodic) => self.periodic_pair(a, b, settings, periodic, enforcement)?,
        };
        self.pairs.push(pair);
        Ok(self.pairs.len() - 1)
    }

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

    /// Number of interactions.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// The surface names (side A, side B) of interaction `i`.
    pub fn surfaces(&self, i: usize) -> Option<(&str, &str)> {
        self.pairs
            .get(i)
            .map(|p| (p.side_a.name.as_str(), p.side_b.name.as_str()))
    }

    /// Pair every interaction's side-A points with side-B faces anew (a full search).
    pub fn search(&mut self) -> Result<(), EmbedError> {
        for p in &mut self.pairs {
            if p.b.faces.is_empty() {
                return Err(argument(
                    format!("side B `{}` has no faces", p.side_b.name),
                    "check the surface's faces",
                ));
            }
            let searcher = Searcher::new(&p.b, &p.settings);
            let mut result =
                searcher.search(&p.a, &p.b, &p.settings, self.integration, p.subdomain);
            if let Some(treatment) = p.overclosure {
                result.treat_overclosure(treatment);
            }
            let tie = match &p.enforcement {
                Enforcement::Tie { .. } => true,
                Enforcement::Flux { form, .. } => matches!(
                    form,
                    Form::TiedNitsche | Form::TiedInteriorPenalty | Form::Penalty
                ),
            };
            if tie && result.stats.matched == 0 {
                return Err(argument(
                    format!(
                        "interaction {} / {} ties two surfaces that do not overlap anywhere ({} points, none paired)",
                        p.side_a.name, p.side_b.name, result.stats.points
                    ),
                    "check the surfaces' faces and the search tolerances (normal tolerance, field factor)",
                ));
            }
            p.searcher = Some(searcher);
            p.result = Some(result);
            p.points = OnceLock::new();
        }
        Ok(())
    }

    /// The host's time for the next [`Self::contributions`]: conductance models and
    /// plugins that depend on t (a Lua expression of `t`, a plugin's time argument)
    /// see it. Must be finite.
    pub fn set_time(&mut self, time: f64) -> Result<(), EmbedError> {
        if !time.is_finite() {
            return Err(argument(
                format!("the time {time} is not finite"),
                "pass the host's current time in seconds",
            ));
        }
        self.time = time;
        Ok(())
    }

    /// The time set by [`Self::set_time`] (0 until then).
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The nodes moved: keep every pairing, place its points again on the moved faces
    /// and measure gaps anew (`Update Search Every n Steps` between full searches).
    /// Call [`Self::search`] to pair anew.
    pub fn move_nodes(&mut self, coords: &[[f64; 3]]) -> Result<(), EmbedError> {
        if coords.len() != self.mesh.coords.len() {
            return Err(argument(
                format!(
                    "{} coordinates for {} nodes",
                    coords.len(),
                    self.mesh.coords.len()
                ),
                "pass every node's new coordinates, in node order",
            ));
        }
        if let Some(k) = coords.iter().position(|x| x.iter().any(|c| !c.is_finite())) {
            return Err(argument(
                format!("node {k} moved to a non-finite position {:?}", coords[k]),
                "check the host's displacement field",
            ));
        }
        self.mesh.coords = coords.to_vec();
        for p in &mut self.pairs {
            for (surface, geometry) in [(&p.side_a, &mut p.a), (&p.side_b, &mut p.b)] {
                *geometry = SurfaceGeometry::from_surface(&self.mesh, surface, coords)
                    .map_err(|e| argument(e.to_string(), "interfaces are searched in 3-D"))?;
            }
            // A periodic pair's side A is the image of the moved surface.
            if let Some(image) = &mut p.image {
                p.a = p.a.mapped(image.map.as_mut(), &image.name).map_err(|e| {
                    argument(
                        format!(
                            "periodic interaction {} / {}: {e}",
                            p.side_a.name, p.side_b.name
                        ),
                        "the map failed on the moved nodes of side A",
                    )
                })?;
            }
            if let Some(r) = &mut p.result {
                r.update_geometry(&p.a, &p.b);
            }
            p.points = OnceLock::new();
            if let Some(s) = &mut p.searcher {
                s.refit(&p.b);
            }
        }
        Ok(())
    }

    /// The search statistics of interaction `i` (after a search).
    pub fn search_stats(&self, i: usize) -> Option<&SearchStats> {
        self.pairs
            .get(i)
            .and_then(|p| p.result.as_ref())
            .map(|r| &r.stats)
    }

    fn searched(p: &Pair) -> Result<&SearchResult, EmbedError> {
        p.result.as_ref().ok_or_else(|| EmbedError::Order {
            what: format!(
                "interaction {} / {} has not been searched",
                p.side_a.name, p.side_b.name
            ),
            help: "call search() after adding interactions".into(),
        })
    }

    /// The interface terms of every flux-type interaction at the host's field `u` (by
    /// host dof): residual, Jacobian (exact, including dh/dT) and heat.
    pub fn contributions(&self, u: &[f64]) -> Result<Contributions, EmbedError> {
        let mut local = vec![0.0; self.dofs.len()];
        for (d, &h) in self.host_dof.iter().enumerate() {
            local[d] = *u.get(h).ok_or_else(|| {
                argument(
                    format!("the field has {} entries, dof {h} is needed", u.len()),
                    "pass the host's whole field vector, indexed by host dof",
                )
            })?;
        }
        if let Some(k) = u.iter().position(|v| !v.is_finite()) {
            return Err(argument(
                format!("the field is not finite at dof {k} ({})", u[k]),
                "check the host's solve",
            ));
        }
        let mut out = Contributions::default();
        for p in &self.pairs {
            let result = Self::searched(p)?;
            let Enforcement::Flux {
                form,
                law,
                offset,
                beta,
            } = &p.enforcement
            else {
                out.heat.push(None);
                continue;
            };
            // A plugin's fault, kept to tell a plugin failure or cutback request from
            // the other failures once the interface terms stop at it.
            let fault: Cell<Option<ConductanceError>> = Cell::new(None);
            let h = |x: &HInput| -> Result<HValue, String> {
                let (model, pressure): (&dyn ConductanceModel, f64) = match law {
                    Law::Constant(h) => {
                        return Ok(HValue {
                            h: *h,
                            ..HValue::default()
                        });
                    }
                    Law::Model(m, pressure) => (m.as_ref(), *pressure),
                    Law::Plugin(m, pressure) => (m.as_ref(), *pressure),
                };
                let state = PointState {
                    gap: x.gap,
                    pressure,
                    temp_a: x.temp_a,
                    temp_b: x.temp_b,
                    x: x.x,
                    time: self.time,
                };
                match model.evaluate(&state) {
                    Ok(c) => Ok(HValue {
                        h: c.h,
                        dh_dtemp_a: c.dh_dtemp_a,
                        dh_dtemp_b: c.dh_dtemp_b,
                    }),
                    Err(e) => {
                        let message = e.to_string();
                        if matches!(law, Law::Plugin(..)) {
                            fault.set(Some(e));
                        }
                        Err(message)
                    }
                }
            };
            let form = InterfaceForm {
                form: *form,
                h: &h,
                offset: *offset,
                beta: *beta,
                conductivity: &self.conductivity,
            };
            let points = match p.points.get() {
                Some(points) => points,
                None => {
                    let made = InterfacePoints::new(
                        &self.mesh,
                        &self.dofs,
                        self.field,
                        &p.a,
                        &p.b,
                        &result.points,
                        &form,
                    )
                    .map_err(|source| EmbedError::Enforcement {
                        side_a: p.side_a.name.clone(),
                        side_b: p.side_b.name.clone(),
                        source,
                    })?;
                    p.points.get_or_init(|| made)
                }
            };
            let s = points.evaluate(&form, &local).map_err(|source| {
                let (side_a, side_b) = (p.side_a.name.clone(), p.side_b.name.clone());
                match fault.take() {
                    Some(ConductanceError::Cutback { factor, .. }) => EmbedError::Cutback {
                        side_a,
                        side_b,
                        factor,
                        message: source.to_string(),
                    },
                    Some(_) => EmbedError::Plugin {
                        side_a,
                        side_b,
                        message: source.to_string(),
                    },
                    None => EmbedError::Enforcement {
                        side_a,
                        side_b,
                        source,
                    },
                }
            })?;
            let host = |d: u32| self.host_dof[d as usize];
            for (dofs, m) in &s.blocks {
                let n = dofs.len();
                for (r, &i) in dofs.iter().enumerate() {
                    for (c, &j) in dofs.iter().enumerate() {
                        let v = m[r * n + c];
                        if v != 0.0 {
                            out.jacobian.push((host(i), host(j), v));
                        }
                    }
                }
            }
            out.residual
                .extend(s.residual.iter().map(|&(d, v)| (host(d), v)));
            out.load.extend(
                s.rhs
                    .iter()
                    .filter(|x| x.1 != 0.0)
                    .map(|&(d, v)| (host(d), v)),
            );
            let (a, b) = s.heat();
            out.heat.push(Some(Heat {
                side_a: a,
                side_b: b,
            }));
        }
        Ok(out)
    }

    /// The constraint rows of every mortar tie, in interaction order. Fixed nodes and
    /// nodes of an earlier tie get no multiplier (crosspoints).
    pub fn constraints(&self) -> Result<Vec<TieConstraints>, EmbedError> {
        let mut constrained: HashSet<NodeId> = self.fixed.iter().copied().collect();
        let mut out = Vec::new();
        for (index, p) in self.pairs.iter().enumerate() {
            let result = Self::searched(p)?;
            let Enforcement::Tie {
                multipliers,
                offset,
            } = &p.enforcement
            else {
                continue;
            };
            let tie = mortar_tie(
                &self.mesh,
                &self.dofs,
                self.field,
                &p.a,
                &p.b,
                &result.points,
                &self.conductivity,
                &mut constrained,
                *multipliers,
            )
            .map_err(|source| EmbedError::Enforcement {
                side_a: p.side_a.name.clone(),
                side_b: p.side_b.name.clone(),
                source,
            })?;
            let host = |d: u32| self.host_dof[d as usize];
            let own: Vec<u32> = tie
                .nodes
                .iter()
                .map(|&n| self.dofs.dof(self.field, n).map_or(u32::MAX, |d| d.0))
                .collect();
            let mut rows: Vec<BTreeMap<u32, f64>> = vec![BTreeMap::new(); tie.nodes.len()];
            for &(k, d, c) in &tie.entries {
                *rows[k as usize].entry(d).or_default() += c;
            }
            let diagonal: Vec<f64> = rows
                .iter()
                .zip(&own)
                .map(|(row, d)| row.get(d).copied().unwrap_or(0.0))
                .collect();
            let mut t = TieConstraints {
                interaction: index,
                multiplier_dofs: own.iter().map(|&d| host(d)).collect(),
                entries: tie
                    .entries
                    .iter()
                    .map(|&(k, d, c)| (k as usize, host(d), c))
                    .collect(),
                rhs: tie.psi_integral.iter().map(|psi| offset * psi).collect(),
                condensed: Vec::new(),
                diagonal,
                side_a_dofs: tie.side_a_dofs.iter().map(|&d| host(d)).collect(),
                side_b_dofs: tie.side_b_dofs.iter().map(|&d| host(d)).collect(),
            };
            if *multipliers == Multipliers::Dual {
                t.condensed = condense(&t, &rows, &own, &host, &p.side_a.name)?;
            }
            out.push(t);
        }
        Ok(out)
    }
}

/// The dual rows solved for their own dof: `u_k = (g_k − Σ_{j≠k} C_kj u_j) / D_k`.
fn condense(
    t: &TieConstraints,
    rows: &[BTreeMap<u32, f64>],
    own: &[u32],
    host: &dyn Fn(u32) -> usize,
    side_a: &str,
) -> Result<Vec<Condensed>, EmbedError> {
    let condensed: HashSet<u32> = own
        .iter()
        .zip(&t.diagonal)
        .filter(|(_, d)| **d != 0.0)
        .map(|(o, _)| *o)
        .collect();
    let mut out = Vec::new();
    for (k, row) in rows.iter().enumerate() {
        let d = t.diagonal[k];
        if d == 0.0 {
            continue; // a node no point reached: left free
        }
        let mut terms = Vec::new();
        for (&j, &c) in row {
            if j == own[k] {
                continue;
            }
            let coefficient = -c / d;
            // Biorthogonality keeps side-A rows apart; a coupling means a side-A face
            // only partly covered by side B.
            if condensed.contains(&j) && coefficient.abs() > 1e-9 {
                return Err(argument(
                    format!(
                        "dual mortar on side A `{side_a}`: the rows of dofs {} and {} are coupled ({coefficient:.3e}); a side-A face is only partly covered by side B",
                        host(own[k]),
                        host(j)
                    ),
                    "use standard multipliers (Multipliers::Standard) for this tie",
                ));
            }
            if !condensed.contains(&j) {
                terms.push((host(j), coefficient));
            }
        }
        out.push(Condensed {
            dof: host(own[k]),
            constant: t.rhs[k] / d,
            terms,
        });
    }
    Ok(out)
}
