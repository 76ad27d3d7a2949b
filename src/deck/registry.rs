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
    /// False for commands read into the spec but not yet acted on downstream.
    pub implemented: bool,
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

macro_rules! cmd {
    ($phrase:literal, $key:literal, [$($b:expr),+], $args:literal, $desc:literal) => {
        CommandSpec { phrase: $phrase, key: $key, blocks: &[$($b),+], args: $args, description: $desc, implemented: true }
    };
    ($phrase:literal, $key:literal, [$($b:expr),+], $args:literal, $desc:literal, planned) => {
        CommandSpec { phrase: $phrase, key: $key, blocks: &[$($b),+], args: $args, description: $desc, implemented: false }
    };
}

pub static COMMANDS: &[CommandSpec] = &[
    // Contact Definition (Aria, and Sierra/SM surface commands).
    cmd!(
        "contact surface",
        "contact_surface",
        [CD],
        "<name> contains <block|side set|assembly>...",
        "Surface from the exterior faces of blocks, or from side sets or assemblies, by name."
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
        "= on|off [exclude <block>...]",
        "One surface per element block, named after the block, from its exterior faces."
    ),
    cmd!(
        "restrict contact to subdomain",
        "restrict_contact_to_subdomain",
        [CD],
        "defined by radius <r> and point <x> <y> <z>",
        "Search only inside this sphere."
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
        "<n> steps",
        "Redo the search every n steps (1: every step)."
    ),
    cmd!(
        "opposed normal threshold angle",
        "opposed_normal_threshold_angle",
        [CD],
        "= <degrees>",
        "Faces interact only if their normals are at least this far apart (>= 90)."
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
        "Penalty scale factor for the whole domain, one surface's self-contact, or one pair (Abaqus control assignment; the last that applies wins)."
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
        "<surface> = rectangular offset = <dx> <dy> [<dz>] | cylindrical axis = <a>... center = <c>... angle = <deg> | align_surface destination = <surface> [invert_normals = 0|1] | mapped x_map = <f> y_map = <g> [z_map = <h>]",
        "Tie a surface to the image of another under a periodic transform."
    ),
    // Enforcement.
    cmd!(
        "enforcement for",
        "model",
        [ENF],
        "<equation> = <model> [<key> = <value> | <word>]...",
        "The enforcement model for one equation, with its arguments."
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
        "Penalty factor of the Dash (mortar penalty) model."
    ),
    cmd!(
        "offset temperature",
        "offset_temperature",
        [ENF],
        "= <t>",
        "Temperature offset added across the interface."
    ),
    cmd!(
        "quarantine faulty points",
        "quarantine_faulty_points",
        [ENF],
        "[= on|off]",
        "A point where the conductance model (plugin, Lua) fails contributes nothing and is reported, instead of stopping the run."
    ),
    cmd!(
        "contact pressure",
        "contact_pressure",
        [ENF],
        "= <p>",
        "Contact pressure (Pa) seen by pressure-dependent conductance models (CMY, tables of pressure, plugins)."
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
        "= <name>",
        "Switch the enforcement on and off in time with this toggle block (a `[[toggle]]` of the problem file)."
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
        "Largest normal gap at which a pair is found (> 0)."
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
        "= on|off",
        "Every listed surface interacts with every other."
    ),
    cmd!(
        "self contact",
        "self_contact",
        [DEF, SO],
        "= on|off",
        "A surface may interact with itself."
    ),
    // Search Options.
    cmd!(
        "tangential tolerance",
        "tangential_tolerance",
        [SO],
        "[=] <distance>",
        "How far outside a face a projection still counts."
    ),
    cmd!(
        "buffer factor",
        "buffer_factor",
        [SO],
        "[=] <f>",
        "Growth of the search boxes, relative to the face size."
    ),
    cmd!(
        "field factor",
        "field_factor",
        [SO],
        "[=] <f>",
        "Scale of the search field around each face."
    ),
    cmd!(
        "normal check angle",
        "normal_check_angle",
        [SO],
        "[=] <degrees>",
        "Largest angle between normals of a pair."
    ),
    cmd!(
        "search update frequency",
        "search_update_frequency",
        [SO],
        "[=] <n>",
        "Redo the search every n steps."
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
        "Split off the faces whose normal is closest to this direction."
    ),
    cmd!(
        "auto subset",
        "auto_subset",
        [CS],
        "<name> [number of subsets <n>] [angle <degrees>]",
        "Split the surface into subsets by normal direction."
    ),
    cmd!(
        "contact type",
        "contact_type",
        [CS],
        "= face|node",
        "Whether the surface is made of faces or of their nodes."
    ),
];

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
         `enforcement for` lines are `model` entries and material property lines `property` \
         entries of an enforcement. Generated from the keyword registry \
         (`src/deck/registry.rs`).\n"
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
        let _ = writeln!(
            out,
            "| command | key | arguments | description | implemented |"
        );
        let _ = writeln!(out, "|---|---|---|---|---|");
        for sub in BLOCKS.iter().filter(|s| s.parent == b.key) {
            // A block is carried out when any of its commands is.
            let done = COMMANDS
                .iter()
                .any(|c| c.implemented && c.blocks.contains(&sub.key));
            let _ = writeln!(
                out,
                "| `begin {}` | `{}` | block | {} | {} |",
                sub.phrase,
                sub.key,
                sub.description,
                if done { "yes" } else { "parsed only" }
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
                if c.implemented { "yes" } else { "parsed only" }
            );
        }
        if b.key == ENF {
            let _ = writeln!(
                out,
                "| `<material property>` | `property` | `= <model> [<key> = <value> \\| <word>]...` | Any other `words = model args` line, e.g. `gap conductance coefficient = constant h = 10`. | parsed only |"
            );
        }
        let _ = writeln!(out);
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
