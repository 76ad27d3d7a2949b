//! The keyword registry: every block type and every line command of the deck, in one
//! table that the parser, the did-you-mean help, the wrong-block check and the generated
//! reference ([`reference_markdown`]) all read.
//!
//! Conventions: phrases are lower case, words separated by one space; keys are the
//! snake_case form, which is also the TOML key. A command's `blocks` lists the keys of
//! the blocks it may appear in. The parser matches the longest phrase at the start of a
//! line (so `auto subset` wins over `subset`, `side b variable` over `side b`).

mod commands;
mod reference;

pub use commands::COMMANDS;
pub use reference::reference_markdown;

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
    ("species", Status::Implemented),
    ("voltage", Status::Implemented),
];

const NOT_ENERGY: &str = "seam solves Energy, Voltage and Species only";
const CVFEM: &str =
    "seam solves Energy, Voltage and Species only, with finite elements (no control-volume form)";

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
        assert_eq!(equation("species"), Some(Status::Implemented));
        assert_eq!(
            equation("porous_species"),
            Some(Status::Refused(NOT_ENERGY))
        );
        assert_eq!(equation("voltage"), Some(Status::Implemented));
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
