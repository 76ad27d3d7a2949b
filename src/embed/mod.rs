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
//! A host on MPI makes one embedding per rank from its local part
//! (`EmbeddingBuilder::build_on_ranks` → `RankEmbedding`, `--features mpi`): each rank
//! gets its own side-A points' terms in the host's global dof numbers.
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

use std::sync::{Arc, Mutex, OnceLock};

use crate::assembly::{DofMap, FieldId};
use crate::enforce::interface::{DEFAULT_BETA, FieldPair, Form, InterfaceError, InterfacePoints};
use crate::mesh::{Mesh, NodeId, ValidationError};
use crate::periodic::PeriodicMap;
use crate::search::SearchSettings;
use crate::search::pairing::{SearchResult, Searcher, Sphere, SurfaceGeometry};
use crate::search::periodic::PeriodicTransform;
use crate::surface::ContactSurface;

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
    /// A flux interaction's search paired no point: wrong surfaces or side numbers, or
    /// surfaces apart, would otherwise pass as an interface that carries no heat.
    /// [`Interaction::allow_unpaired`] (or [`Embedding::allow_unpaired`]) lets it stand.
    #[error(
        "interaction {side_a} / {side_b} paired nothing: {why}\n  help: check the surfaces' faces (element numbers, 1-based sides) and the search tolerances; allow_unpaired() if the surfaces may really be apart"
    )]
    NothingPaired {
        side_a: String,
        side_b: String,
        /// What the search saw, from its counts.
        why: String,
    },
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
    /// On MPI ([`RankEmbedding`]): a collective call failed on another rank, whose own
    /// error says what and where; every rank returns an error, so none is left waiting.
    #[error("the call failed on rank {rank}\n  help: rank {rank}'s error says what and where")]
    OtherRank { rank: usize },
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
#[derive(Clone)]
pub struct Interaction {
    side_a: String,
    side_b: String,
    model: Model,
    offset: f64,
    beta: f64,
    settings: Option<SearchSettings>,
    periodic: Option<Periodic>,
    conductance: Option<Arc<dyn ConductanceModel>>,
    allow_unpaired: bool,
    quarantine: bool,
}

impl std::fmt::Debug for Interaction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Interaction")
            .field("side_a", &self.side_a)
            .field("side_b", &self.side_b)
            .field("model", &self.model)
            .field("offset", &self.offset)
            .field("beta", &self.beta)
            .field("periodic", &self.periodic)
            .field("conductance", &self.conductance.as_ref().map(|m| m.name()))
            .field("allow_unpaired", &self.allow_unpaired)
            .field("quarantine", &self.quarantine)
            .finish()
    }
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
            conductance: None,
            allow_unpaired: false,
            quarantine: false,
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

    /// h from the host's own model instead of the constant of [`Model::Conductance`] or
    /// [`Model::GapConductance`] (whose `h` is then ignored): h and its derivatives at
    /// each point, from its gap, temperatures, position and the host's time. See
    /// [`FnConductance`] for a closure, and the C API's `seam_add_interaction_with_conductance`.
    pub fn conductance(mut self, model: Arc<dyn ConductanceModel>) -> Self {
        self.conductance = Some(model);
        self
    }

    /// Let a flux interaction whose search pairs nothing stand (its terms are then 0):
    /// by default [`Embedding::search`] refuses it, since wrong side numbers or surfaces
    /// that are apart otherwise look like an interface that carries no heat.
    pub fn allow_unpaired(mut self) -> Self {
        self.allow_unpaired = true;
        self
    }

    /// A point where the conductance model fails contributes nothing and is kept for
    /// [`Embedding::quarantined`], instead of failing the evaluation (`Quarantine Faulty
    /// Points`). A model's request for a smaller step is still [`EmbedError::Cutback`].
    pub fn quarantine(mut self) -> Self {
        self.quarantine = true;
        self
    }

    /// Search tolerances other than the defaults of [`SearchSettings::defaults`].
    pub fn search_settings(mut self, settings: SearchSettings) -> Self {
        self.settings = Some(settings);
        self
    }
}

/// A conductance given by a closure: `f(state)` returns h and its derivatives with
/// respect to the two temperatures (`Conductance { h, dh_dtemp_a, dh_dtemp_b, .. }`),
/// or a message saying why it cannot.
pub struct FnConductance<F> {
    name: String,
    f: F,
    depends_on_temperature: bool,
}

impl<F> FnConductance<F>
where
    F: Fn(&PointState) -> Result<Conductance, String>,
{
    /// `name` labels messages; `depends_on_temperature` false keeps the host's problem
    /// linear (say so only when h does not change with T).
    pub fn new(name: &str, depends_on_temperature: bool, f: F) -> Self {
        FnConductance {
            name: name.to_string(),
            f,
            depends_on_temperature,
        }
    }
}

impl<F> ConductanceModel for FnConductance<F>
where
    F: Fn(&PointState) -> Result<Conductance, String>,
{
    fn name(&self) -> String {
        self.name.clone()
    }

    fn evaluate(&self, state: &PointState) -> Result<Conductance, ConductanceError> {
        let c = (self.f)(state).map_err(|message| ConductanceError::Evaluation {
            model: self.name.clone(),
            state: *state,
            message,
        })?;
        crate::enforce::conductance::check(self, state, c)
    }

    fn depends_on_temperature(&self) -> bool {
        self.depends_on_temperature
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

/// The conductance of a flux-type interaction.
enum Law {
    Constant(f64),
    /// A model from the deck (`Gap Conductance Coefficient = …`, or a plugin: its faults
    /// and cutback requests become [`EmbedError::Plugin`] and [`EmbedError::Cutback`])
    /// and the contact pressure it sees.
    Model {
        model: Arc<dyn ConductanceModel>,
        pressure: f64,
        plugin: bool,
    },
    /// A model the host gave in code (a Rust model or closure, a C callback).
    Host(Arc<dyn ConductanceModel>),
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
    /// The points of `result` this process evaluates, when not all
    /// ([`Embedding::own_points`]: a rank of a distributed run); cleared by a search.
    kept: Option<Vec<usize>>,
    /// A flux interaction whose search pairs nothing is an error unless this is set.
    allow_unpaired: bool,
    /// The host's fields on side A and on side B (one field unless the embedding was
    /// made over several, as `seam run`'s).
    fields: FieldPair,
    /// The contact pressure at each point of `result`, from the host; `None`: the
    /// enforcement's (cleared by a search, whose points are new).
    pressures: Option<Vec<f64>>,
    /// Quarantine: a point where the model fails contributes nothing and is kept in
    /// `quarantined` (each place once).
    quarantine: bool,
    quarantined: Mutex<Vec<Quarantined>>,
    /// Switched off by the host ([`Embedding::set_active`]): no terms, no heat.
    active: bool,
    /// The coefficient per block weighing this pair's Nitsche forms, instead of the
    /// embedding's conductivity (`seam run`'s species interfaces: the diffusivity).
    coefficient: Option<Vec<f64>>,
    /// The temperature field, when it is not this pair's own (a species interface or a
    /// voltage tie): its models see it, and `coefficient_law` takes it.
    temperature_field: Option<FieldId>,
    /// That coefficient as a law of the temperature (D(T), σ(T)): the forms take it at
    /// each point's temperatures.
    coefficient_law: Option<std::sync::Arc<ConductivityOfT>>,
}

impl Pair {
    /// The coefficient per block weighing this pair's forms.
    fn coefficient<'c>(&'c self, embedding: &'c [f64]) -> &'c [f64] {
        self.coefficient.as_deref().unwrap_or(embedding)
    }

    /// A flux-type interaction (not a mortar tie).
    fn is_flux(&self) -> bool {
        matches!(self.enforcement, Enforcement::Flux { .. })
    }

    /// A pair of searched (or yet unsearched) geometry with the defaults of the
    /// host-set state: one field, no point pressures, no quarantine, switched on.
    #[allow(clippy::too_many_arguments)]
    fn new(
        side_a: ContactSurface,
        side_b: ContactSurface,
        (a, b): (SurfaceGeometry, SurfaceGeometry),
        settings: SearchSettings,
        overclosure: Option<Overclosure>,
        subdomain: Option<Sphere>,
        image: Option<Image>,
        enforcement: Enforcement,
        fields: FieldPair,
    ) -> Pair {
        Pair {
            side_a,
            side_b,
            a,
            b,
            settings,
            overclosure,
            subdomain,
            image,
            enforcement,
            searcher: None,
            result: None,
            points: OnceLock::new(),
            kept: None,
            allow_unpaired: false,
            fields,
            pressures: None,
            quarantine: false,
            quarantined: Mutex::new(Vec::new()),
            active: true,
            coefficient: None,
            temperature_field: None,
            coefficient_law: None,
        }
    }
}

/// A contact point where an interaction's conductance model failed and which was
/// quarantined ([`Interaction::quarantine`]): it carries no heat.
#[derive(Clone, Debug, PartialEq)]
pub struct Quarantined {
    /// The point (side A).
    pub x: [f64; 3],
    /// Why the model failed there.
    pub message: String,
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
    /// Per field, fixed nodes other than `fixed` (the field's own Dirichlet data).
    fixed_of: Vec<(FieldId, Vec<NodeId>)>,
    integration: Integration,
    pairs: Vec<Pair>,
    /// The host's time, passed to conductance models and plugins (0 until set).
    time: f64,
    /// The last [`Embedding::evaluate`]: its CSR pattern is kept until the next search
    /// or move, its values are refreshed in place.
    evaluation: Option<Evaluation>,
    /// k(T, x, t) per block, when the Nitsche forms of the temperature weigh the flux
    /// with the conductivity at each point's temperatures (`None`: `conductivity`).
    conductivity_law: Option<std::sync::Arc<ConductivityOfT>>,
}

/// k and dk/dT of block `b` at temperature `t`, point `x` and time `time`.
pub(crate) type ConductivityOfT =
    dyn Fn(usize, f64, [f64; 3], f64) -> Result<(f64, f64), String> + Send + Sync;

mod add;
mod builder;
mod csr;
mod fields;
mod from_deck;
#[cfg(feature = "mpi")]
mod rank;
mod search;
mod state;
mod terms;
mod ties;

pub use crate::enforce::conductance::{
    Conductance, ConductanceError, ConductanceModel, PointState,
};
pub use builder::EmbeddingBuilder;
pub use csr::{CsrMatrix, Evaluation};
pub(crate) use fields::face_values;
pub use fields::{Coverage, FaceValues, HostFace, PointValues, Unpaired, UnpairedReason};
#[cfg(feature = "mpi")]
pub(crate) use rank::agree;
#[cfg(feature = "mpi")]
pub use rank::{RankEmbedding, RankEvaluation, RankPoint, RankTie, duplicate};
pub use ties::TieConstraints;
