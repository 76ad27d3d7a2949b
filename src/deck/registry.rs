//! The keyword registry: every block type and every line command of the deck, in one
//! table that the parser, the did-you-mean help, the wrong-block check and the generated
//! reference ([`reference_markdown`]) all read.
//!
//! Conventions: phrases are lower case, words separated by one space; keys are the
//! snake_case form, which is also the TOML key. A command's `blocks` lists the keys of
//! the blocks it may appear in. The parser matches the longest phrase at the start of a
//! line (so `auto subset` wins over `subset`, `side b variable` over `side b`).

use std::fmt::Write as _;

/// Where a block may be opened.
pub const TOP: &str = "";

/// Whether a block takes a name after its type phrase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Naming {
    Required,
    Optional,
    Forbidden,
}

#[derive(Debug)]
pub struct BlockSpec {
    pub phrase: &'static str,
    pub key: &'static str,
    /// Key of the block it must sit in ([`TOP`] for the top level).
    pub parent: &'static str,
    pub naming: Naming,
    pub description: &'static str,
}

#[derive(Debug)]
pub struct CommandSpec {
    pub phrase: &'static str,
    pub key: &'static str,
    pub blocks: &'static [&'static str],
    /// What follows the phrase, `<…>` for values, `[…]` optional, `a|b` choices.
    pub args: &'static str,
    pub description: &'static str,
    /// What seam does with the command.
    pub status: Status,
}

/// What seam does with a keyword, as the reference reports it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Status {
    /// Read into the spec and acted on.
    Implemented,
    /// Read into the spec, but it has no effect in some uses and a warning says so; the
    /// text says when.
    Warns(&'static str),
    /// Recognised and refused with an error that says why (the text).
    Refused(&'static str),
}

impl Status {
    /// The reference's status cell.
    pub fn describe(self) -> String {
        match self {
            Status::Implemented => "implemented".to_string(),
            Status::Warns(why) => format!("warns: {why}"),
            Status::Refused(why) => format!("refused: {why}"),
        }
    }

    pub fn is_implemented(self) -> bool {
        !matches!(self, Status::Refused(_))
    }
}

const CD: &str = "contact_definition";
const ENF: &str = "enforcement";
const INT: &str = "interaction";
const DEF: &str = "interaction_defaults";
const SO: &str = "search_options";
const CS: &str = "contact_surface";

pub static BLOCKS: &[BlockSpec] = &[
    BlockSpec {
        phrase: "contact definition",
        key: CD,
        parent: TOP,
        naming: Naming::Optional,
        description: "All contact input of one physics region: surfaces, enforcements, interactions, search options.",
    },
    BlockSpec {
        phrase: "enforcement",
        key: ENF,
        parent: CD,
        naming: Naming::Optional,
        description: "How each equation is enforced across an interaction (model, data, properties).",
    },
    BlockSpec {
        phrase: "interaction",
        key: INT,
        parent: CD,
        naming: Naming::Optional,
        description: "One pair of surfaces (side A, side B) with its tolerance and enforcement.",
    },
    BlockSpec {
        phrase: "interaction defaults",
        key: DEF,
        parent: CD,
        naming: Naming::Forbidden,
        description: "Interactions made automatically between the listed surfaces (general and self contact).",
    },
    BlockSpec {
        phrase: "search options",
        key: SO,
        parent: CD,
        naming: Naming::Optional,
        description: "Tolerances and update frequency of the contact search.",
    },
    BlockSpec {
        phrase: "contact surface",
        key: CS,
        parent: CD,
        naming: Naming::Required,
        description: "A contact surface built from blocks, elements, side sets and assemblies (Sierra/SM form).",
    },
];

/// A material-model line of an enforcement that seam recognises and refuses; the text
/// says what it would need.
macro_rules! refused {
    ($phrase:literal, $key:literal, $why:literal) => {
        CommandSpec {
            phrase: $phrase,
            key: $key,
            blocks: &[ENF],
            args: "= <model> [<key> = <value> | <word>]...",
            description: "Aria material model.",
            status: Status::Refused(concat!("needs ", $why)),
        }
    };
}

macro_rules! cmd {
    ($phrase:literal, $key:literal, [$($b:expr),+], $args:literal, $desc:literal) => {
        CommandSpec { phrase: $phrase, key: $key, blocks: &[$($b),+], args: $args, description: $desc, status: Status::Implemented }
    };
    ($phrase:literal, $key:literal, [$($b:expr),+], $args:literal, $desc:literal, warns $why:literal) => {
        CommandSpec { phrase: $phrase, key: $key, blocks: &[$($b),+], args: $args, description: $desc, status: Status::Warns($why) }
    };
}

pub static COMMANDS: &[CommandSpec] = &[
    // Contact Definition (Aria, and Sierra/SM surface commands).
    cmd!(
        "contact surface",
        "contact_surface",
        [CD],
        "<name> [contains <block|side set|assembly>...]",
        "Surface from the exterior faces of blocks, or from side sets or assemblies, by name; without `contains`, the mesh entity of the surface's own name (`contact surface s` is `contact surface s contains s`)."
    ),
    cmd!(
        "contact node set",
        "contact_node_set",
        [CD],
        "<name> contains <node set>...",
        "Node-based contact surface from node sets."
    ),
    cmd!(
        "skin all blocks",
        "skin_all_blocks",
        [CD],
        "[= on|off] [exclude <block>...]",
        "One surface per element block, named after the block, from its exterior faces (alone or with `exclude` only: on)."
    ),
    cmd!(
        "restrict contact to subdomain",
        "restrict_contact_to_subdomain",
        [CD],
        "defined by radius <r> and point <x> <y> <z>",
        "Search only inside this sphere. Range: r finite and > 0, the point finite (else E0227)."
    ),
    cmd!(
        "visualize contact",
        "visualize_contact",
        [CD],
        "[= on|off]",
        "Write the contact fields per face (gap, contact fraction, interface flux) to the results: `contact.vtu` and nodal variables in `results.exo` (`seam run`), each face's contact fraction in `seam search --json`."
    ),
    cmd!(
        "output rule",
        "output_rule",
        [CD],
        "= none|summary|verbose|more verbose",
        "How much contact reports: in the search log (`seam search`), and with `visualize contact` in the results of `seam run` (none: no contact fields; summary: side-A faces; verbose: and side-B faces; more verbose: and every contact point)."
    ),
    cmd!(
        "update search every",
        "update_search_every_n_steps",
        [CD],
        "[=] <n> [steps]",
        "Redo the search every n steps (1: every step); the value is kept in the spec. Range: n >= 1 (else E0227).",
        warns "seam's meshes do not move in `seam run`, so re-searching has no effect; a warning says so"
    ),
    cmd!(
        "opposed normal threshold angle",
        "opposed_normal_threshold_angle",
        [CD],
        "= <degrees>",
        "Faces interact only if their normals are at least this far apart. Range: 90 <= degrees <= 180 (else E0207)."
    ),
    cmd!(
        "disable opposed normal interaction culling",
        "disable_opposed_normal_interaction_culling",
        [CD],
        "",
        "Keep pairs whatever the angle between their normals."
    ),
    cmd!(
        "scale penalty",
        "scale_penalty",
        [CD],
        "[for <surface> [with <surface>]] = <factor>",
        "Penalty scale factor for the whole domain, one surface's self-contact, or one pair (Abaqus control assignment; the last that applies wins). Range: factor finite and > 0 (else E0216)."
    ),
    cmd!(
        "initial overclosure",
        "initial_overclosure",
        [CD],
        "[for <surface> [with <surface>]] = adjust nodes|store offsets",
        "Treatment of gaps that are negative at the start, for the whole domain, one surface or one pair (the last that applies wins)."
    ),
    cmd!(
        "periodicity for",
        "periodicity",
        [CD],
        "<surface> [=] rectangular offset = <dx> <dy> [<dz>] | cylindrical axis = <a>... center = <c>... angle = <deg> | align_surface destination = <surface> [invert_normals = 0|1] | mapped [x_map = <f>] [y_map = <g>] [z_map = <h>]",
        "Tie a surface to the image of another under a periodic transform. Defaults: `invert_normals = 1` (the image faces the destination); a map left out is the identity (`x_map = x`, `y_map = y`, z kept). `cylindrical` needs all of `axis`, `center` and `angle`: the manual gives no default for them. Range: every number finite (else E0227), the axis not zero (E0206); a map that sends two distinct nodes of the surface onto one point is refused when the image is made (E0326)."
    ),
    // Enforcement.
    cmd!(
        "enforcement for",
        "model",
        [ENF],
        "<equation> [=] <model> [<key> = <value> | <word>]...",
        "The enforcement model for one equation, with its arguments; one line per equation. Equations: see the table below."
    ),
    cmd!(
        "integer data",
        "integer_data",
        [ENF],
        "[=] <i>...",
        "Integers handed to a plugin model."
    ),
    cmd!(
        "real data",
        "real_data",
        [ENF],
        "[=] <r>...",
        "Reals handed to a plugin model."
    ),
    cmd!(
        "side b variable",
        "side_b_variable",
        [ENF],
        "<side B variable> to <side A variable>",
        "Tie a variable on side B to another on side A (Lagrange multipliers)."
    ),
    cmd!(
        "slave variable",
        "slave_variable",
        [ENF],
        "<side B variable> to <side A variable>",
        "Deprecated alias of `side b variable`."
    ),
    cmd!(
        "dash penalty factor",
        "dash_penalty_factor",
        [ENF],
        "= <f>",
        "Penalty factor of the Dash (mortar penalty) model. Range: finite and > 0 (else E0227)."
    ),
    cmd!(
        "offset temperature",
        "offset_temperature",
        [ENF],
        "= [constant [value =]] <t>",
        "Temperature offset added across the interface (material model `Offset Temperature = Constant Value = <t>`). Range: finite (else E0227)."
    ),
    cmd!(
        "quarantine faulty points",
        "quarantine_faulty_points",
        [ENF],
        "[= on|off]",
        "A point where the conductance model (plugin, Lua) fails contributes nothing and is reported, instead of stopping the run."
    ),
    cmd!(
        "plugin isolation",
        "plugin_isolation",
        [ENF],
        "= process|none",
        "Where the enforcement's plugin runs: `process`, in a worker process, so that a crash or an `exit` in the plugin is an ordinary fault naming the plugin, the interaction and the points (stopping the run with exit code 3, or quarantined); `none` (the default), in seam's own process, the fastest."
    ),
    cmd!(
        "contact pressure",
        "contact_pressure",
        [ENF],
        "= <p>",
        "Contact pressure (Pa) seen by pressure-dependent conductance models (CMY, tables of pressure, plugins). Range: finite and >= 0, a compressive pressure (else E0227)."
    ),
    cmd!(
        "contact surface pressure",
        "contact_pressure",
        [ENF],
        "= [constant [value =]] <p>",
        "Material model form of `contact pressure` (the same spec field); giving both in one block is an error."
    ),
    cmd!(
        "gap conductance coefficient",
        "gap_conductance_coefficient",
        [ENF],
        "= <model> [<key> = <value> | <word>]...",
        "The conductance law of the interface: `constant h = …`, `gas_gap`, `radiation`, `cmy`, `table`, `lua`, `plugin` (several lines add up). In TOML a `property` entry with `property = \"gap_conductance_coefficient\"`."
    ),
    cmd!(
        "contact gap temperature",
        "contact_gap_temperature",
        [ENF],
        "= side_a|side_b|mean",
        "The temperature a temperature-dependent conductance sees at a contact point: side A's, side B's, or their mean (`average`)."
    ),
    refused!(
        "contact gap voltage",
        "contact_gap_voltage",
        "the voltage equation, which seam does not solve (seam solves energy only)"
    ),
    refused!(
        "offset darcy potential",
        "offset_darcy_potential",
        "porous flow (Darcy potential), which seam does not solve (seam solves energy only)"
    ),
    refused!(
        "offset mesh displacements",
        "offset_mesh_displacements",
        "mesh motion, which seam does not solve (its meshes do not move)"
    ),
    refused!(
        "offset pressure",
        "offset_pressure",
        "fluid flow (pressure), which seam does not solve (seam solves energy only)"
    ),
    refused!(
        "offset solid displacements",
        "offset_solid_displacements",
        "solid mechanics (displacements), which seam does not solve (its meshes do not move)"
    ),
    refused!(
        "offset species",
        "offset_species",
        "species transport, which seam does not solve (seam solves energy only)"
    ),
    refused!(
        "offset velocity",
        "offset_velocity",
        "fluid flow (velocity), which seam does not solve (seam solves energy only)"
    ),
    refused!(
        "offset voltage",
        "offset_voltage",
        "the voltage equation, which seam does not solve (seam solves energy only)"
    ),
    refused!(
        "user expression",
        "user_expression",
        "Aria's expression system, which seam does not have; a conductance given by an expression is `gap conductance coefficient = lua \"…\"`"
    ),
    cmd!(
        "contact pressure variable",
        "contact_pressure_variable",
        [ENF],
        "= <nodal field>",
        "Contact pressure from a nodal field of the run (a `[[nodal_field]]` of the problem file), interpolated on side A at each contact point."
    ),
    cmd!(
        "use toggle block",
        "use_toggle_block",
        [ENF],
        "[=] <name> [<element block>...]",
        "Switch the enforcement on and off in time with this toggle block (a `[[toggle]]` of the problem file). The element blocks, which Aria needs at region level only, are kept in the spec (`toggle_element_blocks`); in an enforcement the toggle switches the whole enforcement."
    ),
    // Interaction, Interaction Defaults.
    cmd!(
        "side a",
        "side_a",
        [INT],
        "[=] <surface>...",
        "Surfaces that carry the integration points."
    ),
    cmd!(
        "side b",
        "side_b",
        [INT],
        "[=] <surface>...",
        "Surfaces projected onto."
    ),
    cmd!(
        "surfaces",
        "surfaces",
        [INT, DEF],
        "[=] <surface>...",
        "Surfaces that interact with each other (both sides)."
    ),
    cmd!(
        "normal tolerance",
        "normal_tolerance",
        [INT, SO],
        "[=] <distance>",
        "Largest normal gap at which a pair is found. Range: a finite distance > 0 (else E0208)."
    ),
    cmd!(
        "enforcement",
        "enforcement",
        [INT, DEF],
        "= <enforcement name>",
        "Which `begin enforcement` block applies."
    ),
    cmd!(
        "general contact",
        "general_contact",
        [DEF],
        "[= on|off]",
        "Every listed surface interacts with every other."
    ),
    cmd!(
        "self contact",
        "self_contact",
        [DEF, SO],
        "[= on|off]",
        "A surface may interact with itself (ELFEN: `Self_contact_flag = 0|1`)."
    ),
    // Search Options.
    cmd!(
        "tangential tolerance",
        "tangential_tolerance",
        [SO],
        "[=] <distance>",
        "How far outside a face a projection still counts, relative to the face size (default 0.001). Range: finite and >= 0 (else E0227)."
    ),
    cmd!(
        "buffer factor",
        "buffer_factor",
        [SO],
        "[=] <f>",
        "Growth of the search boxes, relative to the mean face size (ELFEN: `Buffer_factor`; default 1 in 3-D, 5 in 2-D). Range: finite and >= 0 (else E0227)."
    ),
    cmd!(
        "field factor",
        "field_factor",
        [SO],
        "[=] <f>",
        "Largest gap considered without a normal tolerance, relative to the face size (ELFEN: `Field_factor`; default 0.2). Range: finite and > 0 (else E0227)."
    ),
    cmd!(
        "normal check angle",
        "normal_check_angle",
        [SO],
        "[=] <degrees>",
        "Largest angle between the side-B normal and the reversed side-A normal of a pair (ELFEN: `Normal_dir_chk_angle`; default 80). Range: 0 < degrees <= 180, an angle between two directions (else E0227)."
    ),
    cmd!(
        "search update frequency",
        "search_update_frequency",
        [SO],
        "[=] <n>",
        "Redo the search every n steps (ELFEN: `Global_update_frequency`); the value is kept in the spec. Range: n >= 1 (else E0227).",
        warns "seam's meshes do not move in `seam run`, so re-searching has no effect; a warning says so"
    ),
    // Contact Surface block (Sierra/SM).
    cmd!(
        "include all blocks",
        "include_all_blocks",
        [CS],
        "",
        "Skin every element block into this surface."
    ),
    cmd!(
        "block",
        "block",
        [CS],
        "= <block>...",
        "Skin these element blocks."
    ),
    cmd!(
        "element",
        "element",
        [CS],
        "= <id>...",
        "Exterior faces of these elements (user element numbers)."
    ),
    cmd!(
        "surface",
        "surface",
        [CS],
        "= <side set>...",
        "Faces of these side sets."
    ),
    cmd!(
        "assembly",
        "assembly",
        [CS],
        "= <assembly>...",
        "Members of these assemblies."
    ),
    cmd!(
        "remove block",
        "remove_block",
        [CS],
        "= <block>...",
        "Drop faces of these blocks."
    ),
    cmd!(
        "remove surface",
        "remove_surface",
        [CS],
        "= <side set>...",
        "Drop faces of these side sets."
    ),
    cmd!(
        "subset",
        "subset",
        [CS],
        "<name> with normal <nx> <ny> <nz>",
        "Split off the faces whose normal is closest to this direction. Range: finite (else E0227) and not zero (else E0206)."
    ),
    cmd!(
        "auto subset",
        "auto_subset",
        [CS],
        "<name> [number of subsets <n>] [angle <degrees>]",
        "Split the surface into subsets by normal direction. Range: n >= 1 (else E0203), the angle finite and > 0 (else E0202)."
    ),
    cmd!(
        "contact type",
        "contact_type",
        [CS],
        "= face|node|standard",
        "Whether the surface is made of faces or of their nodes; Sierra/SM's `standard` is `face`, its `smooth` is refused (seam does not smooth surfaces)."
    ),
];

/// Other programs' names for seam's commands: `(alias, canonical phrase)`. Matching also
/// reads `_` as a space, so ELFEN's `Buffer_factor` is `buffer factor` without an entry.
pub static ALIASES: &[(&str, &str)] = &[
    ("normal dir chk angle", "normal check angle"),
    ("global update frequency", "search update frequency"),
    ("self contact flag", "self contact"),
];

/// ELFEN contact-set parameters that seam has no counterpart for: `(name as ELFEN
/// spells it, what it does in ELFEN and what seam offers instead)`.
pub static ELFEN_REFUSED: &[(&str, &str)] = &[
    (
        "Corner_projection_size",
        "a corner model of dense explicit contact; seam's implicit thermal contact has no corner treatment",
    ),
    (
        "Corner_region_size",
        "a corner model of dense explicit contact; seam's implicit thermal contact has no corner treatment",
    ),
    (
        "Corner_angle_tolerance",
        "a corner model of dense explicit contact; seam's implicit thermal contact has no corner treatment",
    ),
    (
        "Contactor_corner_model",
        "a corner model of dense explicit contact; seam's implicit thermal contact has no corner treatment",
    ),
    (
        "Trigger_search_velocity",
        "a search triggered by node velocity; seam's meshes do not move",
    ),
    (
        "All_geometry_flag",
        "contact on every external surface; in seam write `skin all blocks`",
    ),
    (
        "Print_search",
        "printing of the search; in seam write `output rule = summary` or `verbose`",
    ),
    (
        "Edge_search_frequency",
        "an edge-node search frequency; seam searches all points together",
    ),
    (
        "Thermal_advection_flag",
        "advection terms of the contact heat flux; seam's interfaces do not move",
    ),
    (
        "Memory_optimisation_flag",
        "freeing of global search data; seam keeps its search structures",
    ),
    (
        "Slip_update_model",
        "fault slip, a mechanics quantity seam does not compute",
    ),
    (
        "Slip_update_frequency",
        "fault slip, a mechanics quantity seam does not compute",
    ),
    (
        "Slip_ref_update_frequency",
        "fault slip, a mechanics quantity seam does not compute",
    ),
    (
        "Slip_rate_update_frequency",
        "fault slip, a mechanics quantity seam does not compute",
    ),
    (
        "Pore_force_no_contact_update",
        "pore-pressure forces, which seam does not compute",
    ),
    (
        "Geometry_sets",
        "ELFEN geometry sets; in seam name the surfaces with `contact surface`",
    ),
    (
        "Property_name",
        "an ELFEN contact property set; in seam give the law in `begin enforcement`",
    ),
    (
        "Property_number",
        "an ELFEN contact property set; in seam give the law in `begin enforcement`",
    ),
];

/// The equations of `Enforcement For <equation>` in Aria's list, with what seam does.
pub static EQUATIONS: &[(&str, Status)] = &[
    ("energy", Status::Implemented),
    ("continuity", Status::Refused(NOT_ENERGY)),
    ("current", Status::Refused(NOT_ENERGY)),
    ("cvfem_continuity", Status::Refused(NOT_ENERGY)),
    ("cvfem_energy", Status::Refused(CVFEM)),
    ("cvfem_lumped_projection", Status::Refused(NOT_ENERGY)),
    ("cvfem_momentum", Status::Refused(NOT_ENERGY)),
    ("cvfem_projection", Status::Refused(NOT_ENERGY)),
    (
        "cvfem_specific_dissipation_rate",
        Status::Refused(NOT_ENERGY),
    ),
    (
        "cvfem_turbulent_kinetic_energy",
        Status::Refused(NOT_ENERGY),
    ),
    ("mass_balance", Status::Refused(NOT_ENERGY)),
    ("mesh", Status::Refused(NOT_ENERGY)),
    ("momentum", Status::Refused(NOT_ENERGY)),
    ("porous_enthalpy", Status::Refused(NOT_ENERGY)),
    ("porous_species", Status::Refused(NOT_ENERGY)),
    ("species", Status::Refused(NOT_ENERGY)),
    ("voltage", Status::Refused(NOT_ENERGY)),
];

const NOT_ENERGY: &str = "seam solves Energy only";
const CVFEM: &str = "seam solves Energy only, with finite elements (no control-volume form)";

/// The status of equation `name` (lower case), `None` if it is not in Aria's list.
pub fn equation(name: &str) -> Option<Status> {
    EQUATIONS.iter().find(|(e, _)| *e == name).map(|(_, s)| *s)
}

/// The command that the first tokens of a line spell, and how many tokens it took:
/// the longest command phrase or alias, with `_` inside a token read as a space.
///
/// Commands allowed in block `key` win over longer ones that are not (so
/// `contact surface pressure contains b` is a surface named `pressure` in a contact
/// definition); with none allowed, the longest of all is returned, for a wrong-block
/// message.
pub fn match_tokens(tokens: &[&str], key: &str) -> Option<(&'static CommandSpec, usize)> {
    let here = match_tokens_where(tokens, |c| c.blocks.contains(&key));
    here.or_else(|| match_tokens_where(tokens, |_| true))
}

fn match_tokens_where(
    tokens: &[&str],
    keep: impl Fn(&CommandSpec) -> bool,
) -> Option<(&'static CommandSpec, usize)> {
    let mut best: Option<(&'static CommandSpec, usize, usize)> = None;
    let mut spelled = String::new();
    for (k, t) in tokens.iter().enumerate() {
        if k > 0 {
            spelled.push(' ');
        }
        spelled.push_str(&t.replace('_', " "));
        let words = word_count(&spelled);
        let hit = COMMANDS
            .iter()
            .find(|c| c.phrase == spelled)
            .or_else(|| {
                ALIASES
                    .iter()
                    .find(|(a, _)| *a == spelled)
                    .and_then(|(_, canon)| COMMANDS.iter().find(|c| c.phrase == *canon))
            })
            .filter(|c| keep(c));
        if let Some(c) = hit
            && best.is_none_or(|(_, _, w)| words > w)
        {
            best = Some((c, k + 1, words));
        }
    }
    best.map(|(c, n, _)| (c, n))
}

/// The ELFEN parameter (with its reason) that `token` names, `_` and case ignored.
pub fn elfen_refused(token: &str) -> Option<(&'static str, &'static str)> {
    let t = token.replace('_', " ");
    ELFEN_REFUSED
        .iter()
        .find(|(n, _)| n.replace('_', " ").eq_ignore_ascii_case(&t))
        .copied()
}

/// The words `begin`, `end`: reserved, listed in the reference only.
pub fn block(key: &str) -> Option<&'static BlockSpec> {
    BLOCKS.iter().find(|b| b.key == key)
}

/// Number of words in a phrase.
pub fn word_count(phrase: &str) -> usize {
    phrase.split(' ').count()
}

/// Does `phrase` equal the first words of `words` (already lower case)?
fn starts_with(words: &[&str], phrase: &str) -> bool {
    let n = word_count(phrase);
    words.len() >= n && phrase.split(' ').zip(words).all(|(p, w)| p == *w)
}

/// The longest command phrase (over all blocks) that starts `words`.
pub fn match_command(words: &[&str]) -> Option<&'static CommandSpec> {
    COMMANDS
        .iter()
        .filter(|c| starts_with(words, c.phrase))
        .max_by_key(|c| word_count(c.phrase))
}

/// The longest block phrase that starts `words`.
pub fn match_block(words: &[&str]) -> Option<&'static BlockSpec> {
    BLOCKS
        .iter()
        .filter(|b| starts_with(words, b.phrase))
        .max_by_key(|b| word_count(b.phrase))
}

/// The command phrases allowed in block `key`.
pub fn phrases_in(key: &str) -> Vec<&'static str> {
    COMMANDS
        .iter()
        .filter(|c| c.blocks.contains(&key))
        .map(|c| c.phrase)
        .collect()
}

/// What block `key` accepts, for help lines: its commands, then `begin …` for its
/// sub-blocks, each in backquotes.
pub fn accepted_in(key: &str) -> String {
    let mut v: Vec<String> = phrases_in(key).iter().map(|p| format!("`{p}`")).collect();
    v.extend(
        BLOCKS
            .iter()
            .filter(|b| b.parent == key)
            .map(|b| format!("`begin {}`", b.phrase)),
    );
    v.join(", ")
}

/// The closest phrase to the start of `words` among `candidates`, with the number of
/// words it was compared against (for the span of the diagnostic).
pub fn suggest(words: &[&str], candidates: &[&'static str]) -> Option<(&'static str, usize)> {
    let max = candidates.iter().map(|c| word_count(c)).max().unwrap_or(0);
    let mut best: Option<(usize, &'static str, usize)> = None;
    for k in 1..=max.min(words.len()) {
        let user = words.get(..k).unwrap_or_default().join(" ");
        let same_len = candidates.iter().copied().filter(|c| word_count(c) == k);
        if let Some(hit) = crate::diag::did_you_mean(&user, same_len) {
            let d = crate::diag::edit_distance(&user, hit);
            if best.is_none_or(|(bd, _, _)| d < bd) {
                best = Some((d, hit, k));
            }
        }
    }
    best.map(|(_, hit, k)| (hit, k))
}

/// Where a block may appear, in words: `begin contact definition` or `the top level`.
pub fn describe_block(key: &str) -> String {
    match block(key) {
        Some(b) => format!("`begin {}`", b.phrase),
        None => "the top level".to_string(),
    }
}

/// The deck reference, generated from the registry: one markdown table per block.
pub fn reference_markdown() -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# Deck reference\n");
    let _ = writeln!(
        out,
        "Keywords are case-insensitive; `=`, `is` and `are` are interchangeable; `#` and `$` \
         start comments; commas and tabs are whitespace; names are stored lower case, quoted \
         strings keep their case. The `key` column is the canonical snake_case name, which is \
         the TOML field name. In TOML the surface-making commands (`contact surface`, \
         `contact node set`, `skin all blocks`, `begin contact surface`) are entries of \
         `[[contact_definition.surface]]` with `kind = \"contains\" | \"node_set\" | \
         \"skin_all_blocks\" | \"block\"`; `periodicity for` is an entry of \
         `[[contact_definition.periodicity]]` with a `transform` table tagged by `kind`; \
         `enforcement for` lines are `model` entries and `gap conductance coefficient` lines \
         `property` entries of an enforcement. `_` inside a keyword reads as a space \
         (`Buffer_factor` is `buffer factor`). An `=` shown as `[=]` may be left out, as \
         the manuals' syntax lines do; a switch shown as `[= on|off]` alone means on. The \
         `status` column says what seam does: \
         *implemented*; *warns* (kept in the spec, but without effect where the reason \
         says, and a warning says so); *refused* (an error says why). Generated from the \
         keyword registry (`src/deck/registry.rs`).\n"
    );
    let _ = writeln!(
        out,
        "A deck file is either a contact deck (only `begin contact definition` blocks at the \
         top level; any other line is an error) or a whole Sierra input file (`begin sierra` \
         … `end`, or any file whose contact definitions sit inside other blocks such as \
         `begin procedure` and `begin aria region`). From a Sierra input file seam reads \
         every `begin contact definition` wherever it sits, and skips the other blocks and \
         lines, naming the skipped blocks in one warning (W0103). Aria's \
         `begin toggle block` is refused (E0226) in a contact deck, and in a Sierra input \
         file when an enforcement's `use toggle block` names it (an unused one is only \
         skipped): seam cannot read its schedule; give it as a `[[toggle]]` of the problem \
         file instead.\n"
    );
    let _ = writeln!(
        out,
        "Limits: a deck file (contact deck, whole Sierra input file or TOML) is read up to \
         {} MiB and a Lua file up to {} MiB; a larger file, or a device such as \
         `/dev/zero` that never ends, is refused (E0003) without being read to its end. A \
         deck is UTF-8 text (a leading byte-order mark is accepted); another encoding is \
         refused at the line and column of the first byte that is not UTF-8 (E0004). Blocks \
         nest at most {} deep (E0114). Of the blocks left open at the end of the file, the \
         {} outermost are reported one by one and the rest counted in one more E0101; any \
         run prints at most {} diagnostics, then one line counting the others. Every number \
         has the range given with its command: a value outside it is refused with the range \
         in the message, since it would not fail but change the answer.\n",
        crate::diag::MAX_DECK_BYTES >> 20,
        crate::diag::MAX_LUA_BYTES >> 20,
        super::tree::MAX_NESTING,
        super::tree::UNCLOSED_SHOWN,
        crate::diag::MAX_RENDERED,
    );
    for b in BLOCKS {
        let name = match b.naming {
            Naming::Required => " <name>",
            Naming::Optional => " [<name>]",
            Naming::Forbidden => "",
        };
        let _ = writeln!(out, "## `begin {}{name}` … `end`\n", b.phrase);
        let place = match block(b.parent) {
            Some(p) => format!("inside `begin {}`", p.phrase),
            None => "at the top level".to_string(),
        };
        let _ = writeln!(out, "{} Key `{}`; appears {place}.\n", b.description, b.key);
        let _ = writeln!(out, "| command | key | arguments | description | status |");
        let _ = writeln!(out, "|---|---|---|---|---|");
        for sub in BLOCKS.iter().filter(|s| s.parent == b.key) {
            // A block is carried out when any of its commands is.
            let done = COMMANDS
                .iter()
                .any(|c| c.status.is_implemented() && c.blocks.contains(&sub.key));
            let _ = writeln!(
                out,
                "| `begin {}` | `{}` | block | {} | {} |",
                sub.phrase,
                sub.key,
                sub.description,
                if done { "implemented" } else { "refused" }
            );
        }
        for c in COMMANDS.iter().filter(|c| c.blocks.contains(&b.key)) {
            let args = if c.args.is_empty() {
                "—".to_string()
            } else {
                format!("`{}`", c.args.replace('|', "\\|"))
            };
            let _ = writeln!(
                out,
                "| `{}` | `{}` | {} | {} | {} |",
                c.phrase,
                c.key,
                args,
                c.description,
                c.status.describe()
            );
        }
        let _ = writeln!(out);
        if b.key == ENF {
            let _ = writeln!(
                out,
                "Equations of `enforcement for` (Aria's list; any other name is an error, and \
                 one equation may appear once per block). The spec carries every equation; \
                 the deck refuses those seam does not solve.\n"
            );
            let _ = writeln!(out, "| equation | status |");
            let _ = writeln!(out, "|---|---|");
            for (e, st) in EQUATIONS {
                let _ = writeln!(out, "| `{e}` | {} |", st.describe());
            }
            let _ = writeln!(out);
        }
        if b.key == SO {
            let _ = writeln!(
                out,
                "ELFEN contact-set parameters: `Buffer_factor`, `Field_factor` are `buffer \
                 factor`, `field factor`; `Normal_dir_chk_angle` is `normal check angle`; \
                 `Global_update_frequency` is `search update frequency`; `Self_contact_flag` \
                 is `self contact`. The ELFEN parameters below have no counterpart in seam and are \
                 refused (E0224):\n"
            );
            let _ = writeln!(out, "| ELFEN parameter | status |");
            let _ = writeln!(out, "|---|---|");
            for (n, why) in ELFEN_REFUSED {
                let _ = writeln!(out, "| `{n}` | refused: {why} |");
            }
            let _ = writeln!(out);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_mentions_every_entry() {
        let r = reference_markdown();
        for b in BLOCKS {
            assert!(r.contains(&format!("`begin {}", b.phrase)), "{}", b.phrase);
        }
        for c in COMMANDS {
            assert!(
                r.contains(&format!("| `{}` | `{}` |", c.phrase, c.key)),
                "{}",
                c.phrase
            );
        }
    }

    #[test]
    fn phrases_are_unique_and_blocks_exist() {
        for (i, c) in COMMANDS.iter().enumerate() {
            assert!(
                COMMANDS.iter().skip(i + 1).all(|d| d.phrase != c.phrase),
                "{}",
                c.phrase
            );
            assert_eq!(c.phrase, c.phrase.to_lowercase());
            for b in c.blocks {
                assert!(block(b).is_some(), "{} in unknown block {b}", c.phrase);
            }
        }
    }

    #[test]
    fn underscores_and_aliases_match() {
        let m = |s: &str, b: &str| {
            match_tokens(&s.split(' ').collect::<Vec<_>>(), b).map(|(c, n)| (c.key, n))
        };
        assert_eq!(m("buffer_factor = 2", SO), Some(("buffer_factor", 1)));
        assert_eq!(
            m("normal_dir_chk_angle = 80", SO),
            Some(("normal_check_angle", 1))
        );
        assert_eq!(
            m("global_update_frequency = 10", SO),
            Some(("search_update_frequency", 1))
        );
        assert_eq!(m("self_contact_flag = 1", SO), Some(("self_contact", 1)));
        assert_eq!(
            m("contact surface pressure contains b", CD),
            Some(("contact_surface", 2))
        );
        assert_eq!(
            m("contact surface pressure = 5", ENF),
            Some(("contact_pressure", 3))
        );
        assert!(elfen_refused("corner_REGION_size").is_some());
        assert_eq!(equation("voltage"), Some(Status::Refused(NOT_ENERGY)));
        assert_eq!(equation("energy"), Some(Status::Implemented));
        assert_eq!(equation("enrgy"), None);
    }

    #[test]
    fn longest_phrase_wins() {
        let m = |s: &str| match_command(&s.split(' ').collect::<Vec<_>>()).map(|c| c.key);
        assert_eq!(m("auto subset x"), Some("auto_subset"));
        assert_eq!(m("subset x"), Some("subset"));
        assert_eq!(m("side b variable t to t"), Some("side_b_variable"));
        assert_eq!(m("side b s1"), Some("side_b"));
        assert_eq!(m("surfaces a"), Some("surfaces"));
        assert_eq!(m("gravity"), None);
    }

    #[test]
    fn suggestion_spans_the_compared_words() {
        let words = ["contact", "surfce", "top", "contains", "b"];
        let s = suggest(&words, &phrases_in(CD));
        assert_eq!(s, Some(("contact surface", 2)));
    }
}
