//! The line commands of the deck: one [`CommandSpec`] per command, by block, in the
//! order the reference lists them.

use super::{CD, CS, CommandSpec, DEF, ENF, INT, SO, Status};

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
        "Redo the search every n steps (1: every step). In `seam run` with a `[displacement]` that moves the mesh: a full search where the run starts and at every n-th step, the pairing kept and its points placed on the moved faces in between; without one the mesh does not move and warning W0703 says the line has no effect. Range: n >= 1 (else E0227)."
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
    cmd!(
        "contact gap voltage",
        "contact_gap_voltage",
        [ENF],
        "= side_a|side_b|mean",
        "The voltage a voltage-dependent electrical contact conductance (a Lua coefficient naming `volt_a`/`volt_b`) sees at a contact point: side A's, side B's, or their mean (`average`). In an `Enforcement for Voltage` block only (else E0431)."
    ),
    refused!(
        "offset darcy potential",
        "offset_darcy_potential",
        "porous flow (Darcy potential), which seam does not solve (seam solves energy, voltage and species only)"
    ),
    refused!(
        "offset mesh displacements",
        "offset_mesh_displacements",
        "mesh motion, which seam does not solve (its meshes do not move)"
    ),
    refused!(
        "offset pressure",
        "offset_pressure",
        "fluid flow (pressure), which seam does not solve (seam solves energy, voltage and species only)"
    ),
    refused!(
        "offset solid displacements",
        "offset_solid_displacements",
        "solid mechanics (displacements), which seam does not solve (its meshes do not move)"
    ),
    cmd!(
        "offset species",
        "offset_species",
        [ENF],
        "= [constant [value =]] <dc>",
        "Concentration jump across the interface of an `Enforcement for Species` (mol/m³; material model `Offset Species = Constant Value = <dc>`): a tie holds c_A = K c_B + dc, a mass-transfer interface carries j = h (c_A - K c_B - dc). Range: finite (else E0227)."
    ),
    cmd!(
        "partition coefficient",
        "partition_coefficient",
        [ENF],
        "= [constant [value =]] <K>",
        "seam: the partition coefficient K of an `Enforcement for Species` interface (the ratio of the two sides' solubilities): a tie holds c_A = K c_B, a mass-transfer interface carries j = h (c_A - K c_B). Default 1. Range: finite and > 0 (else E0227)."
    ),
    refused!(
        "offset velocity",
        "offset_velocity",
        "fluid flow (velocity), which seam does not solve (seam solves energy, voltage and species only)"
    ),
    cmd!(
        "offset voltage",
        "offset_voltage",
        [ENF],
        "= [constant [value =]] <v>",
        "Voltage offset across the interface of an `Enforcement for Voltage` (material model `Offset Voltage = Constant Value = <v>`): the current is h_e (V_A - V_B - v) through a contact conductance; a voltage tie holds V_A = V_B + v. Range: finite (else E0227)."
    ),
    cmd!(
        "joule heat fraction side a",
        "joule_fraction_side_a",
        [ENF],
        "= <f>",
        "seam: the share of an electrical contact's Joule heat h_e (V_A - V_B)^2 given to side A's temperature (the rest to side B). Default 0.5. Range: [0, 1] (else E0227)."
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
        "Redo the search every n steps (ELFEN: `Global_update_frequency`), as `update search every`; `update search every` wins when both are given. Range: n >= 1 (else E0227)."
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
