//! The typed contact specification: what a deck means, independent of how it was spelled.
//!
//! Both front ends produce it: the Sierra-syntax parser ([`super::parse_sierra`]) and the
//! TOML reader ([`super::parse_toml`]). TOML keys are the canonical snake_case names of
//! the deck phrases (`Skin All Blocks` → `skin_all_blocks`). Names of blocks, side sets,
//! node sets and surfaces are stored lower-case (Sierra names are case-insensitive);
//! file names keep their case. `at` fields carry the deck location for later messages
//! and are not part of the TOML form.

use serde::{Deserialize, Serialize};

use crate::diag::Loc;

/// Everything in one deck file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Deck {
    #[serde(default, rename = "contact_definition")]
    pub contact_definitions: Vec<ContactDefinition>,
}

/// `begin Contact Definition [name]` … `end`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactDefinition {
    #[serde(default)]
    pub name: Option<String>,
    /// Surface-making commands in deck order: order decides ownership.
    #[serde(default, rename = "surface")]
    pub surfaces: Vec<SurfaceDef>,
    #[serde(default)]
    pub restrict_contact_to_subdomain: Option<Subdomain>,
    #[serde(default)]
    pub visualize_contact: bool,
    #[serde(default)]
    pub output_rule: Option<OutputRule>,
    /// `Update Search Every n Steps`: the search schedule of surfaces that move (`seam
    /// run` with a `[displacement]`, or a host that moves its nodes).
    #[serde(default)]
    pub update_search_every_n_steps: Option<u32>,
    #[serde(default)]
    pub opposed_normal_threshold_angle: Option<f64>,
    #[serde(default)]
    pub disable_opposed_normal_interaction_culling: bool,
    #[serde(default)]
    pub periodicity: Vec<Periodicity>,
    #[serde(default, rename = "enforcement")]
    pub enforcements: Vec<Enforcement>,
    #[serde(default, rename = "interaction")]
    pub interactions: Vec<Interaction>,
    #[serde(default)]
    pub interaction_defaults: Option<InteractionDefaults>,
    #[serde(default)]
    pub search_options: Option<SearchOptions>,
    /// Per-pair control assignments (Abaqus style), in deck order: where they overlap,
    /// the last one applies.
    #[serde(default, rename = "control_assignment")]
    pub control_assignments: Vec<ControlAssignment>,
    #[serde(skip)]
    pub at: Loc,
}

impl ContactDefinition {
    /// The enforcement an interaction uses: the one it names, or else the definition's
    /// first (a periodic pair names none).
    pub fn enforcement(&self, name: Option<&str>) -> Option<&Enforcement> {
        match name {
            Some(n) => self
                .enforcements
                .iter()
                .find(|e| e.name.as_deref() == Some(n)),
            None => self.enforcements.first(),
        }
    }
}

/// `Scale Penalty [For s1 [With s2]] = f` or `Initial Overclosure [For s1 [With s2]] = …`.
/// No `surface_1`: the whole contact domain; no `surface_2` (or the same name twice):
/// the self-interaction of `surface_1`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ControlAssignment {
    #[serde(default)]
    pub surface_1: Option<String>,
    #[serde(default)]
    pub surface_2: Option<String>,
    pub control: Control,
    #[serde(skip)]
    pub at: Loc,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Control {
    /// Multiplies the penalty of penalty-type enforcements.
    ScalePenalty { factor: f64 },
    /// What to do with a gap that is negative at the start.
    InitialOverclosure { treatment: Overclosure },
}

/// Treatment of an initial overclosure (a negative gap in the undeformed geometry).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Overclosure {
    /// Move side-A points onto side B: the enforcement then starts from gap 0.
    AdjustNodes,
    /// Keep the geometry and record the initial gap as an offset (the thermal default).
    StoreOffsets,
}

/// One surface-making command. Commands are applied in this order; the first one that
/// includes a face (or node) owns it.
// A deck holds a handful of these; boxing the block variant would buy nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SurfaceDef {
    /// `Contact Surface S Contains a b …`: blocks (skinned), side sets or assemblies by name.
    Contains {
        name: String,
        contains: Vec<String>,
        #[serde(skip)]
        at: Loc,
    },
    /// `Contact Node Set S Contains ns …`.
    NodeSet {
        name: String,
        contains: Vec<String>,
        #[serde(skip)]
        at: Loc,
    },
    /// `Skin All Blocks = On [Exclude b …]`: one surface per block, named after it.
    SkinAllBlocks {
        #[serde(default)]
        exclude: Vec<String>,
        #[serde(skip)]
        at: Loc,
    },
    /// `begin Contact Surface S` … `end`.
    Block(SurfaceBlock),
}

impl SurfaceDef {
    pub fn at(&self) -> &Loc {
        match self {
            SurfaceDef::Contains { at, .. }
            | SurfaceDef::NodeSet { at, .. }
            | SurfaceDef::SkinAllBlocks { at, .. } => at,
            SurfaceDef::Block(b) => &b.at,
        }
    }
}

/// `begin Contact Surface S` with its line commands.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceBlock {
    pub name: String,
    #[serde(default)]
    pub include_all_blocks: bool,
    /// `Block = …` (skinned).
    #[serde(default, rename = "block")]
    pub blocks: Vec<String>,
    /// `Element = ids…`: the exterior faces of these elements (user element numbers).
    #[serde(default, rename = "element")]
    pub elements: Vec<i64>,
    /// `Surface = …`: side sets.
    #[serde(default, rename = "surface")]
    pub side_sets: Vec<String>,
    #[serde(default, rename = "assembly")]
    pub assemblies: Vec<String>,
    #[serde(default, rename = "remove_block")]
    pub remove_blocks: Vec<String>,
    #[serde(default, rename = "remove_surface")]
    pub remove_surfaces: Vec<String>,
    #[serde(default, rename = "subset")]
    pub subsets: Vec<Subset>,
    #[serde(default)]
    pub auto_subset: Option<AutoSubset>,
    #[serde(default)]
    pub contact_type: ContactType,
    #[serde(skip)]
    pub at: Loc,
    /// Where each name (or element number) of the line commands was written, for
    /// messages about one of them.
    #[serde(skip)]
    pub name_locs: Vec<(String, Loc)>,
}

impl SurfaceBlock {
    /// The location of a name written in one of the block's commands, else the block's.
    pub fn loc_of(&self, name: &str) -> &Loc {
        self.name_locs
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(name))
            .map_or(&self.at, |(_, l)| l)
    }
}

/// `Subset name With Normal nx ny nz`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Subset {
    pub name: String,
    pub normal: [f64; 3],
    #[serde(skip)]
    pub at: Loc,
}

/// `Auto Subset name [Number Of Subsets n] [Angle a]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AutoSubset {
    pub name: String,
    #[serde(default)]
    pub number_of_subsets: Option<u32>,
    /// Degrees; default 60.
    #[serde(default)]
    pub angle: Option<f64>,
    #[serde(skip)]
    pub at: Loc,
}

/// `Contact Type = Face | Node`: whether the surface is made of faces or of their nodes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ContactType {
    #[default]
    Face,
    Node,
}

/// `Restrict Contact To Subdomain Defined By Radius r And Point x y z`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Subdomain {
    pub radius: f64,
    pub point: [f64; 3],
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum OutputRule {
    None,
    Summary,
    Verbose,
    MoreVerbose,
}

/// `Periodicity For S = …`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Periodicity {
    pub surface: String,
    pub transform: PeriodicTransform,
    #[serde(skip)]
    pub at: Loc,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum PeriodicTransform {
    Rectangular {
        offset: Vec<f64>,
    },
    Cylindrical {
        axis: Vec<f64>,
        center: Vec<f64>,
        /// Degrees.
        angle: f64,
    },
    AlignSurface {
        destination: String,
        #[serde(default = "default_true")]
        invert_normals: bool,
    },
    /// Each map is a Lua expression in x, y, z or the name of a function in a Lua file;
    /// a map left out is the identity (`x_map = x`, `y_map = y`, no `z_map`: z kept).
    Mapped {
        #[serde(default = "identity_x")]
        x_map: String,
        #[serde(default = "identity_y")]
        y_map: String,
        #[serde(default)]
        z_map: Option<String>,
    },
}

fn default_true() -> bool {
    true
}

fn identity_x() -> String {
    "x".to_string()
}

fn identity_y() -> String {
    "y".to_string()
}

/// `begin Enforcement [name]` … `end`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Enforcement {
    #[serde(default)]
    pub name: Option<String>,
    /// `Enforcement for EQ = MODEL args…`, one per equation. Any equation name is
    /// carried; the deck's checks refuse those seam does not solve.
    #[serde(default, rename = "model")]
    pub models: Vec<EnforcementModel>,
    /// Material-model lines kept as written: `Gap Conductance Coefficient = Constant H = 10`
    /// (the ones with their own field, such as `Contact Surface Pressure`, are lowered
    /// into it; the others of Aria's list are refused by the deck's checks).
    #[serde(default, rename = "property")]
    pub properties: Vec<PropertyModel>,
    #[serde(default)]
    pub integer_data: Vec<i64>,
    #[serde(default)]
    pub real_data: Vec<f64>,
    /// `Side B Variable b To a` (deprecated alias `Slave Variable`).
    #[serde(default)]
    pub side_b_variable: Option<VariableMap>,
    #[serde(default)]
    pub dash_penalty_factor: Option<f64>,
    #[serde(default)]
    pub offset_temperature: Option<f64>,
    /// `Offset Voltage = v`: the voltage jump of an `Enforcement for Voltage`.
    #[serde(default)]
    pub offset_voltage: Option<f64>,
    /// `Joule Heat Fraction Side A = f`: the share of an electrical contact's Joule heat
    /// given to side A (0.5 when absent).
    #[serde(default)]
    pub joule_fraction_side_a: Option<f64>,
    /// `Offset Species = dc`: the concentration jump of an `Enforcement for Species`
    /// (mol/m³).
    #[serde(default)]
    pub offset_species: Option<f64>,
    /// `Partition Coefficient = K`: c_A = K c_B across an `Enforcement for Species`
    /// interface (1 when absent).
    #[serde(default)]
    pub partition_coefficient: Option<f64>,
    /// `Contact Pressure = p` (Pa), for pressure-dependent conductance models.
    #[serde(default)]
    pub contact_pressure: Option<f64>,
    /// `Contact Pressure Variable = name`: the pressure from a nodal field of the run.
    #[serde(default)]
    pub contact_pressure_variable: Option<String>,
    /// `Quarantine Faulty Points`: a failing model point contributes nothing and is
    /// reported instead of stopping the run.
    #[serde(default)]
    pub quarantine_faulty_points: bool,
    #[serde(default)]
    pub use_toggle_block: Option<String>,
    /// The element blocks listed after the toggle's name in `Use Toggle Block T b…`
    /// (needed by Aria at region level only; in an enforcement the toggle switches the
    /// whole enforcement).
    #[serde(default)]
    pub toggle_element_blocks: Vec<String>,
    /// `Contact Gap Temperature = side_a | side_b | mean`: the temperature a
    /// temperature-dependent conductance sees at a contact point.
    #[serde(default)]
    pub contact_gap_temperature: Option<GapTemperature>,
    /// `Contact Gap Voltage = side_a | side_b | mean`: the voltage a voltage-dependent
    /// electrical contact conductance sees at a contact point (an `Enforcement for
    /// Voltage` block only).
    #[serde(default)]
    pub contact_gap_voltage: Option<GapTemperature>,
    /// `Plugin Isolation = Process | None`: run the enforcement's plugin in a worker
    /// process (a crash is an ordinary fault) or in seam's own process (the default).
    #[serde(default)]
    pub plugin_isolation: PluginIsolation,
    #[serde(skip)]
    pub at: Loc,
}

/// Where an enforcement's plugin runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum PluginIsolation {
    /// In seam's own process: fastest; a crash in the plugin ends the run (exit 3).
    #[default]
    None,
    /// In a worker process: a crash or an `exit` in the plugin is an ordinary fault.
    Process,
}

/// Which temperature (or voltage) a temperature-dependent (voltage-dependent)
/// conductance sees at a contact point: side A's, side B's (interpolated at the
/// projection), their mean, or a constant.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GapTemperature {
    SideA,
    SideB,
    Mean,
    Constant(f64),
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnforcementModel {
    /// Equation, lower case (`energy`, `current`, …).
    pub equation: String,
    /// Model, lower case (`gap_conductance`, `tied_temperature`, `plugin`, …).
    pub model: String,
    /// The remaining words of the line, as `key = value` pairs where the deck wrote them
    /// so and as bare words (key without value) otherwise.
    #[serde(default)]
    pub args: Vec<Arg>,
    #[serde(skip)]
    pub at: Loc,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropertyModel {
    /// Property, snake_case (`gap_conductance_coefficient`).
    pub property: String,
    /// Model, snake_case (`constant`).
    pub model: String,
    #[serde(default)]
    pub args: Vec<Arg>,
    #[serde(skip)]
    pub at: Loc,
}

/// One argument of a model line: `key = value`, or a bare value (`key` empty).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Arg {
    #[serde(default)]
    pub key: String,
    pub value: String,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VariableMap {
    pub side_b: String,
    pub side_a: String,
}

/// `begin Interaction [name]` … `end`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Interaction {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub side_a: Vec<String>,
    #[serde(default)]
    pub side_b: Vec<String>,
    #[serde(default)]
    pub surfaces: Vec<String>,
    #[serde(default)]
    pub normal_tolerance: Option<f64>,
    #[serde(default)]
    pub enforcement: Option<String>,
    #[serde(skip)]
    pub at: Loc,
}

/// `begin Interaction Defaults` … `end`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InteractionDefaults {
    #[serde(default)]
    pub general_contact: Option<bool>,
    #[serde(default)]
    pub self_contact: Option<bool>,
    #[serde(default)]
    pub surfaces: Vec<String>,
    #[serde(default)]
    pub enforcement: Option<String>,
    #[serde(skip)]
    pub at: Loc,
}

/// `begin Search Options` … `end`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SearchOptions {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub normal_tolerance: Option<f64>,
    #[serde(default)]
    pub tangential_tolerance: Option<f64>,
    #[serde(default)]
    pub buffer_factor: Option<f64>,
    #[serde(default)]
    pub field_factor: Option<f64>,
    /// Degrees.
    #[serde(default)]
    pub normal_check_angle: Option<f64>,
    #[serde(default)]
    pub self_contact: Option<bool>,
    /// `Search Update Frequency` (ELFEN `Global_update_frequency`): as
    /// [`ContactDefinition::update_search_every_n_steps`].
    #[serde(default)]
    pub search_update_frequency: Option<u32>,
    #[serde(skip)]
    pub at: Loc,
}

impl Deck {
    /// The same deck with every `at` reset to the unknown location: for comparing decks
    /// read from different files or front ends.
    pub fn without_locations(&self) -> Deck {
        let mut d = self.clone();
        for cd in &mut d.contact_definitions {
            cd.at = Loc::default();
            for s in &mut cd.surfaces {
                match s {
                    SurfaceDef::Contains { at, .. }
                    | SurfaceDef::NodeSet { at, .. }
                    | SurfaceDef::SkinAllBlocks { at, .. } => *at = Loc::default(),
                    SurfaceDef::Block(b) => {
                        b.at = Loc::default();
                        b.name_locs.clear();
                        for sub in &mut b.subsets {
                            sub.at = Loc::default();
                        }
                        if let Some(a) = &mut b.auto_subset {
                            a.at = Loc::default();
                        }
                    }
                }
            }
            for p in &mut cd.periodicity {
                p.at = Loc::default();
            }
            for c in &mut cd.control_assignments {
                c.at = Loc::default();
            }
            for e in &mut cd.enforcements {
                e.at = Loc::default();
                for m in &mut e.models {
                    m.at = Loc::default();
                }
                for p in &mut e.properties {
                    p.at = Loc::default();
                }
            }
            for i in &mut cd.interactions {
                i.at = Loc::default();
            }
            if let Some(x) = &mut cd.interaction_defaults {
                x.at = Loc::default();
            }
            if let Some(x) = &mut cd.search_options {
                x.at = Loc::default();
            }
        }
        d
    }
}
