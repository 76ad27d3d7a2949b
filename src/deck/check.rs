//! Semantic checks on a typed [`Deck`], shared by both front ends.
//!
//! Entry point: [`check`]. The Sierra front end passes a [`Locs`] table with the exact
//! location of each value it read, so messages point at the token; the TOML front end
//! passes an empty table and messages fall back to the item's `at` (or no location) —
//! the message itself always names the definition and item.
//!
//! Location keys: `"{d}.opposed_normal_threshold_angle"`,
//! `"{d}.interaction.{i}.normal_tolerance"`, `"{d}.interaction.{i}.enforcement"`,
//! `"{d}.interaction_defaults.enforcement"`, `"{d}.search_options.{key}"`,
//! `"{d}.surface.{s}.name"`, `"{d}.surface.{s}.subset.{k}.normal"`,
//! `"{d}.surface.{s}.auto_subset.{angle|number_of_subsets}"`,
//! `"{d}.periodicity.{p}.{offset|axis|center|angle}"`,
//! `"{d}.control_assignment.{k}.factor"`, `"{d}.update_search_every_n_steps"`,
//! `"{d}.restrict_contact_to_subdomain.{radius|point}"`,
//! `"{d}.enforcement.{k}.{dash_penalty_factor|offset_temperature|contact_pressure}"`,
//! `"{d}.enforcement.{k}.model.{m}.equation"`, `"{d}.enforcement.{k}.model.{m}.arg.{a}"`,
//! `"{d}.enforcement.{k}.use_toggle_block"`, with `d`, `i`, `s`, `k`, `p`, `m`, `a`
//! 0-based indices into the spec's vectors.
//!
//! Ranges: every number the search or an enforcement reads is checked against the range
//! in which it means something, and refused outside it with the range in the message
//! (E0227, or the older codes E0202, E0203, E0207, E0208, E0216 for the values they
//! always covered): a value out of range does not fail later, it silently changes the
//! answer (`normal check angle = 720` is cos 720° = 1: only exactly opposed faces pair).
//! The ranges are listed in the deck reference, from the registry's descriptions.
//!
//! Enforcements: every `Enforcement For` equation must be in Aria's list and one seam
//! solves (the spec carries any), once per block; model arguments are checked where the
//! deck knows the model's keys; property lines must be `gap conductance coefficient`
//! (the material models seam lowers into their own fields never reach the list, and the
//! others are refused here, for both front ends).

use std::collections::HashMap;

use crate::diag::{Diagnostic, Diagnostics, Loc, did_you_mean};

use super::codes;
use super::registry::{self, Status};
use super::spec::*;

/// Locations of individual values, by the keys listed in the module docs.
#[derive(Clone, Debug, Default)]
pub struct Locs(HashMap<String, Loc>);

impl Locs {
    pub fn set(&mut self, key: String, loc: Loc) {
        self.0.insert(key, loc);
    }

    pub fn get(&self, key: &str) -> Option<Loc> {
        self.0.get(key).cloned()
    }

    /// The location for `key`, else `fallback` (if known).
    fn or(&self, key: &str, fallback: &Loc) -> Option<Loc> {
        self.get(key)
            .or_else(|| (!fallback.is_unknown()).then(|| fallback.clone()))
    }
}

/// Report `value` of `what` (as written in the deck) unless `ok`: E0227, with `range`
/// (e.g. `greater than 0`) in the message and `help` saying what the value means.
#[allow(clippy::too_many_arguments)]
fn range(
    out: &mut Diagnostics,
    ok: bool,
    who: &str,
    what: &str,
    value: impl std::fmt::Display,
    range: &str,
    at: Option<Loc>,
    help: &str,
) {
    if ok {
        return;
    }
    out.push(
        Diagnostic::error(
            codes::OUT_OF_RANGE,
            format!("{who}: `{what}` is {value}; it must be {range}"),
        )
        .at(at)
        .help(help),
    );
}

/// True for a finite number greater than 0.
fn positive(v: f64) -> bool {
    v > 0.0 && v.is_finite()
}

/// True for a finite number at least 0.
fn non_negative(v: f64) -> bool {
    v >= 0.0 && v.is_finite()
}

/// Every semantic problem in `deck`.
pub fn check(deck: &Deck, locs: &Locs) -> Diagnostics {
    let mut out = Diagnostics::default();
    for (d, def) in deck.contact_definitions.iter().enumerate() {
        let label = match &def.name {
            Some(n) => format!("contact definition `{n}`"),
            None => format!("contact definition #{}", d + 1),
        };
        let mut found = Diagnostics::default();
        check_definition(d, def, locs, &mut found);
        // A located message shows its line; an unlocated one (TOML, or a spec built in
        // code) must say which definition it is about.
        for mut diag in found.0 {
            if diag.loc.is_none() {
                diag.message = format!("{label}: {}", diag.message);
            }
            out.push(diag);
        }
    }
    out
}

fn check_definition(d: usize, def: &ContactDefinition, locs: &Locs, out: &mut Diagnostics) {
    if let Some(a) = def.opposed_normal_threshold_angle
        && !(90.0..=180.0).contains(&a)
    {
        out.push(
                Diagnostic::error(
                    codes::OPPOSED_ANGLE,
                    format!("opposed normal threshold angle is {a} degrees; it must be between 90 and 180"),
                )
                .at(locs.or(&format!("{d}.opposed_normal_threshold_angle"), &def.at))
                .help("it is the smallest angle between two face normals for the faces to interact; 180 means exactly opposed, 90 the most permissive"),
            );
    }

    if let Some(n) = def.update_search_every_n_steps {
        range(
            out,
            n >= 1,
            "contact definition",
            "update search every",
            n,
            "a whole number of steps of at least 1",
            locs.or(&format!("{d}.update_search_every_n_steps"), &def.at),
            "1 searches again every step; leave the line out to search once",
        );
    }
    if let Some(sd) = &def.restrict_contact_to_subdomain {
        range(
            out,
            positive(sd.radius),
            "contact definition",
            "restrict contact to subdomain … radius",
            sd.radius,
            "a finite length greater than 0",
            locs.or(
                &format!("{d}.restrict_contact_to_subdomain.radius"),
                &def.at,
            ),
            "the search keeps only the points inside this sphere: a radius of 0 or less keeps none",
        );
        let [x, y, z] = sd.point;
        range(
            out,
            sd.point.iter().all(|c| c.is_finite()),
            "contact definition",
            "restrict contact to subdomain … point",
            format!("{x} {y} {z}"),
            "three finite coordinates",
            locs.or(&format!("{d}.restrict_contact_to_subdomain.point"), &def.at),
            "the point is the centre of the sphere the search is restricted to",
        );
    }

    // Surface names: each defined once.
    let mut first: HashMap<&str, usize> = HashMap::new();
    for (s, surf) in def.surfaces.iter().enumerate() {
        let name = match surf {
            SurfaceDef::Contains { name, .. } | SurfaceDef::NodeSet { name, .. } => name,
            SurfaceDef::Block(b) => &b.name,
            SurfaceDef::SkinAllBlocks { .. } => continue,
        };
        if let Some(&prev) = first.get(name.as_str()) {
            let where_prev = def
                .surfaces
                .get(prev)
                .map(|p| p.at())
                .filter(|l| !l.is_unknown())
                .map(|l| format!(" on line {}", l.line))
                .unwrap_or_default();
            out.push(
                Diagnostic::error(
                    codes::DUPLICATE_SURFACE,
                    format!("contact surface `{name}` is defined twice"),
                )
                .at(locs.or(&format!("{d}.surface.{s}.name"), surf.at()))
                .help(format!(
                    "it was first defined{where_prev}; give this one another name or merge the two"
                )),
            );
        } else {
            first.insert(name, s);
        }
        if let SurfaceDef::Block(b) = surf {
            check_surface_block(d, s, b, locs, out);
        }
    }

    for (p, per) in def.periodicity.iter().enumerate() {
        let key = |k: &str| format!("{d}.periodicity.{p}.{k}");
        let count = |out: &mut Diagnostics, what: &str, v: &[f64]| {
            if !(2..=3).contains(&v.len()) {
                out.push(
                    Diagnostic::error(
                        codes::VALUE_COUNT,
                        format!(
                            "periodicity for `{}`: `{what}` needs 2 (2-D) or 3 (3-D) values, found {}",
                            per.surface,
                            v.len()
                        ),
                    )
                    .at(locs.or(&key(what), &per.at))
                    .help(format!("write `{what} = x y` or `{what} = x y z`")),
                );
            }
        };
        let who = format!("periodicity for `{}`", per.surface);
        let finite = |out: &mut Diagnostics, what: &str, v: &[f64]| {
            let words: Vec<String> = v.iter().map(f64::to_string).collect();
            range(
                out,
                v.iter().all(|x| x.is_finite()),
                &who,
                what,
                words.join(" "),
                "finite",
                locs.or(&key(what), &per.at),
                "a periodic transform with an infinite or NaN part maps every node to no point",
            );
        };
        match &per.transform {
            PeriodicTransform::Rectangular { offset } => {
                finite(out, "offset", offset);
                count(out, "offset", offset);
            }
            PeriodicTransform::Cylindrical {
                axis,
                center,
                angle,
            } => {
                finite(out, "axis", axis);
                finite(out, "center", center);
                finite(out, "angle", std::slice::from_ref(angle));
                count(out, "axis", axis);
                count(out, "center", center);
                if axis.iter().all(|&a| a == 0.0) && !axis.is_empty() {
                    out.push(
                        Diagnostic::error(
                            codes::ZERO_NORMAL,
                            format!(
                                "periodicity for `{}`: the axis is the zero vector",
                                per.surface
                            ),
                        )
                        .at(locs.or(&key("axis"), &per.at))
                        .help("give the direction of the rotation axis, e.g. `axis = 0 0 1`"),
                    );
                }
            }
            PeriodicTransform::AlignSurface { .. } | PeriodicTransform::Mapped { .. } => {}
        }
    }

    let enforcements: Vec<&str> = def
        .enforcements
        .iter()
        .filter_map(|e| e.name.as_deref())
        .collect();
    let mut refers = |name: &Option<String>, key: String, at: &Loc, who: &str| {
        let Some(name) = name else { return };
        if enforcements.contains(&name.as_str()) {
            return;
        }
        let hint = did_you_mean(name, enforcements.iter().copied())
            .map(|s| format!("did you mean `{s}`? "))
            .unwrap_or_default();
        let known = if enforcements.is_empty() {
            "no named `begin enforcement` block is defined".to_string()
        } else {
            let v: Vec<String> = enforcements.iter().map(|e| format!("`{e}`")).collect();
            format!("the enforcements are {}", v.join(", "))
        };
        out.push(
            Diagnostic::error(
                codes::UNKNOWN_ENFORCEMENT,
                format!("{who} uses enforcement `{name}`, which is not defined"),
            )
            .at(locs.or(&key, at))
            .help(format!("{hint}{known}")),
        );
    };
    for (i, x) in def.interactions.iter().enumerate() {
        let who = match &x.name {
            Some(n) => format!("interaction `{n}`"),
            None => format!("interaction #{}", i + 1),
        };
        refers(
            &x.enforcement,
            format!("{d}.interaction.{i}.enforcement"),
            &x.at,
            &who,
        );
    }
    if let Some(x) = &def.interaction_defaults {
        refers(
            &x.enforcement,
            format!("{d}.interaction_defaults.enforcement"),
            &x.at,
            "interaction defaults",
        );
    }

    let tolerance = |v: Option<f64>, key: String, at: &Loc, who: &str, out: &mut Diagnostics| {
        if let Some(t) = v.filter(|t| !positive(*t)) {
            out.push(
                Diagnostic::error(
                    codes::NORMAL_TOLERANCE,
                    format!("{who}: normal tolerance is {t}; it must be a finite distance greater than 0"),
                )
                .at(locs.or(&key, at))
                .help("the normal tolerance is the largest gap (a length) at which faces are paired; use a small positive distance"),
            );
        }
    };
    for (i, x) in def.interactions.iter().enumerate() {
        let who = match &x.name {
            Some(n) => format!("interaction `{n}`"),
            None => format!("interaction #{}", i + 1),
        };
        tolerance(
            x.normal_tolerance,
            format!("{d}.interaction.{i}.normal_tolerance"),
            &x.at,
            &who,
            out,
        );
    }
    if let Some(so) = &def.search_options {
        tolerance(
            so.normal_tolerance,
            format!("{d}.search_options.normal_tolerance"),
            &so.at,
            "search options",
            out,
        );
        check_search_options(d, so, locs, out);
    }
    for (k, e) in def.enforcements.iter().enumerate() {
        check_enforcement(d, k, e, locs, out);
    }
    for (k, c) in def.control_assignments.iter().enumerate() {
        if let Control::ScalePenalty { factor } = c.control
            && !(factor > 0.0 && factor.is_finite())
        {
            out.push(
                Diagnostic::error(
                    codes::NOT_POSITIVE,
                    format!("the penalty scale factor must be a finite number greater than 0, found {factor}"),
                )
                .at(locs.or(&format!("{d}.control_assignment.{k}.factor"), &c.at))
                .help("a factor of 1 keeps the enforcement's own penalty"),
            );
        }
    }
}

/// The ranges of the search options other than the normal tolerance.
fn check_search_options(d: usize, so: &SearchOptions, locs: &Locs, out: &mut Diagnostics) {
    let at = |key: &str| locs.or(&format!("{d}.search_options.{key}"), &so.at);
    let who = "search options";
    if let Some(a) = so.normal_check_angle {
        range(
            out,
            a > 0.0 && a <= 180.0,
            who,
            "normal check angle",
            a,
            "greater than 0 and at most 180 degrees",
            at("normal_check_angle"),
            "it is the largest angle between a side-B normal and the reversed side-A normal of a pair: an angle between two directions lies in [0, 180]; 0 would pair only exactly opposed faces, 180 pairs whatever the normals",
        );
    }
    if let Some(f) = so.field_factor {
        range(
            out,
            positive(f),
            who,
            "field factor",
            f,
            "a finite number greater than 0",
            at("field_factor"),
            "it sets the largest gap considered, as a multiple of the face size, when no normal tolerance is given (default 0.2): 0 or less accepts no gap at all",
        );
    }
    if let Some(f) = so.buffer_factor {
        range(
            out,
            non_negative(f),
            who,
            "buffer factor",
            f,
            "a finite number of at least 0",
            at("buffer_factor"),
            "the search boxes grow by the mean face size times this factor (default 1 in 3-D, 5 in 2-D): 0 adds no margin beyond the gap accepted, less would shrink the boxes",
        );
    }
    if let Some(t) = so.tangential_tolerance {
        range(
            out,
            non_negative(t),
            who,
            "tangential tolerance",
            t,
            "a finite number of at least 0",
            at("tangential_tolerance"),
            "it is how far outside a face, relative to the face size, a projection still counts (default 0.001): 0 is the face's own edge, less would cut points off inside the face",
        );
    }
    if let Some(n) = so.search_update_frequency {
        range(
            out,
            n >= 1,
            who,
            "search update frequency",
            n,
            "a whole number of steps of at least 1",
            at("search_update_frequency"),
            "1 searches again every step; leave the line out to search once",
        );
    }
}

fn check_surface_block(d: usize, s: usize, b: &SurfaceBlock, locs: &Locs, out: &mut Diagnostics) {
    let name = &b.name;
    for (k, sub) in b.subsets.iter().enumerate() {
        let [x, y, z] = sub.normal;
        range(
            out,
            sub.normal.iter().all(|c| c.is_finite()),
            &format!("subset `{}` of contact surface `{name}`", sub.name),
            "with normal",
            format!("{x} {y} {z}"),
            "three finite components",
            locs.or(&format!("{d}.surface.{s}.subset.{k}.normal"), &sub.at),
            "give the outward direction of the faces to pick, e.g. `with normal 0 0 1`",
        );
        if sub.normal.iter().all(|&c| c == 0.0) {
            out.push(
                Diagnostic::error(
                    codes::ZERO_NORMAL,
                    format!(
                        "subset `{}` of contact surface `{name}` has a zero normal",
                        sub.name
                    ),
                )
                .at(locs.or(&format!("{d}.surface.{s}.subset.{k}.normal"), &sub.at))
                .help("give the outward direction of the faces to pick, e.g. `with normal 0 0 1`"),
            );
        }
    }
    if let Some(auto) = &b.auto_subset {
        if let Some(sub) = b.subsets.first() {
            // Point at whichever of the two came second in the deck.
            let second = if !sub.at.is_unknown() && sub.at.line > auto.at.line {
                &sub.at
            } else {
                &auto.at
            };
            out.push(
                Diagnostic::error(
                    codes::SUBSET_AND_AUTO,
                    format!("contact surface `{name}` has both `subset` and `auto subset`"),
                )
                .at((!second.is_unknown()).then(|| second.clone()))
                .help("split the surface either by explicit normals (`subset`) or automatically (`auto subset`), not both"),
            );
        }
        if let Some(a) = auto.angle.filter(|a| !positive(*a)) {
            out.push(
                Diagnostic::error(
                    codes::NONPOSITIVE_ANGLE,
                    format!("auto subset `{}` of contact surface `{name}` has angle {a}; it must be positive (and finite)", auto.name),
                )
                .at(locs.or(&format!("{d}.surface.{s}.auto_subset.angle"), &auto.at))
                .help("the angle (degrees) is how far face normals may turn within one subset; the default is 60"),
            );
        }
        if auto.number_of_subsets == Some(0) {
            out.push(
                Diagnostic::error(
                    codes::NONPOSITIVE_SUBSETS,
                    format!(
                        "auto subset `{}` of contact surface `{name}` asks for 0 subsets",
                        auto.name
                    ),
                )
                .at(locs.or(
                    &format!("{d}.surface.{s}.auto_subset.number_of_subsets"),
                    &auto.at,
                ))
                .help("ask for at least one subset, or leave `number of subsets` out"),
            );
        }
    }
}

/// Keys of the models whose arguments the deck knows; other models' arguments are
/// checked by the code that reads them.
const MODEL_KEYS: &[(&str, &[&str], &str)] = &[
    (
        "contact_resistance",
        &["h"],
        "`h = <conductance>` (or a `gap conductance coefficient` line)",
    ),
    (
        "conductance",
        &["h"],
        "`h = <conductance>` (or a `gap conductance coefficient` line)",
    ),
    (
        "gap_conductance",
        &["h"],
        "`h = <conductance>` (or a `gap conductance coefficient` line)",
    ),
    ("tied", &["multipliers"], "`multipliers = standard|dual`"),
];

/// The material properties seam supports, as a help line lists them.
const SUPPORTED_PROPERTIES: &str = "seam supports `gap conductance coefficient`, `contact surface pressure` (or `contact pressure`), `offset temperature`, `offset voltage`, `offset species`, `partition coefficient` and `contact gap temperature`";

/// The lines of an `Enforcement for Species` block: `Partition Coefficient` (finite and
/// positive) and `Offset Species` (finite), each in a block that enforces Species — in
/// another block they would be read and do nothing.
fn check_species_lines(
    d: usize,
    k: usize,
    e: &Enforcement,
    who: &str,
    locs: &Locs,
    out: &mut Diagnostics,
) {
    let species = e.models.iter().any(|m| m.equation == "species");
    for (what, key, value) in [
        (
            "partition coefficient",
            "partition_coefficient",
            e.partition_coefficient,
        ),
        ("offset species", "offset_species", e.offset_species),
    ] {
        let Some(v) = value else { continue };
        let at = locs.or(&format!("{d}.enforcement.{k}.{key}"), &e.at);
        if !species {
            out.push(
                Diagnostic::error(
                    codes::NOT_THIS_EQUATION,
                    format!("{who}: `{what}` in a block that does not enforce Species"),
                )
                .at(at.clone())
                .help("it belongs to a block with `Enforcement for Species = …`: move it there, or add that line"),
            );
        }
        let (ok, range_text, help) = if key == "partition_coefficient" {
            (
                positive(v),
                "a finite number greater than 0",
                "K is the ratio of the solubilities of side A and side B (c_A = K c_B at the interface); 1 joins equal concentrations",
            )
        } else {
            (
                v.is_finite(),
                "finite",
                "the offset is a concentration difference added across the interface (mol/m³)",
            )
        };
        range(out, ok, who, what, v, range_text, at, help);
    }
}

fn check_enforcement(d: usize, k: usize, e: &Enforcement, locs: &Locs, out: &mut Diagnostics) {
    let who = match &e.name {
        Some(n) => format!("enforcement `{n}`"),
        None => format!("enforcement #{}", k + 1),
    };
    if let Some(f) = e.dash_penalty_factor {
        range(
            out,
            positive(f),
            &who,
            "dash penalty factor",
            f,
            "a finite number greater than 0",
            locs.or(&format!("{d}.enforcement.{k}.dash_penalty_factor"), &e.at),
            "it scales the Dash model's penalty: 0 ties nothing, a negative penalty pushes the sides apart",
        );
    }
    if let Some(p) = e.contact_pressure {
        range(
            out,
            non_negative(p),
            &who,
            "contact pressure",
            p,
            "a finite pressure of at least 0",
            locs.or(&format!("{d}.enforcement.{k}.contact_pressure"), &e.at),
            "the contact pressure presses the two sides together (Pa); a negative value is tension, under which the sides are not in contact",
        );
    }
    if let Some(t) = e.offset_temperature {
        range(
            out,
            t.is_finite(),
            &who,
            "offset temperature",
            t,
            "finite",
            locs.or(&format!("{d}.enforcement.{k}.offset_temperature"), &e.at),
            "the offset is a temperature difference added across the interface (K)",
        );
    }
    if let Some(v) = e.offset_voltage {
        range(
            out,
            v.is_finite(),
            &who,
            "offset voltage",
            v,
            "finite",
            locs.or(&format!("{d}.enforcement.{k}.offset_voltage"), &e.at),
            "the offset is a voltage difference added across the interface (V)",
        );
    }
    if let Some(f) = e.joule_fraction_side_a {
        range(
            out,
            (0.0..=1.0).contains(&f),
            &who,
            "joule heat fraction side a",
            f,
            "in [0, 1]",
            locs.or(&format!("{d}.enforcement.{k}.joule_fraction_side_a"), &e.at),
            "the share of the contact's Joule heat that goes to side A; the rest goes to side B",
        );
    }
    check_species_lines(d, k, e, &who, locs, out);
    let mut first: HashMap<&str, usize> = HashMap::new();
    for (m, model) in e.models.iter().enumerate() {
        let eq = model.equation.as_str();
        let at = locs.or(
            &format!("{d}.enforcement.{k}.model.{m}.equation"),
            &model.at,
        );
        match registry::equation(eq) {
            Some(Status::Implemented) | Some(Status::Warns(_)) => {}
            Some(Status::Refused(why)) => out.push(
                Diagnostic::error(
                    codes::REFUSED_EQUATION,
                    format!("{who}: `enforcement for {eq}`: seam does not solve the {eq} equation"),
                )
                .at(at.clone())
                .help(format!(
                    "{why}; write `enforcement for energy = <model>` (contact_resistance, conductance, gap_conductance, tied_temperature, dash, plugin, …)"
                )),
            ),
            None => {
                let names = registry::EQUATIONS.iter().map(|(n, _)| *n);
                let hint = did_you_mean(eq, names)
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                out.push(
                    Diagnostic::error(
                        codes::UNKNOWN_EQUATION,
                        format!("{who}: unknown equation `{eq}` in `enforcement for`"),
                    )
                    .at(at.clone())
                    .help(format!(
                        "{hint}Aria's equations are {}; seam solves `energy`, `voltage` and `species`",
                        registry::EQUATIONS
                            .iter()
                            .map(|(n, _)| format!("`{n}`"))
                            .collect::<Vec<_>>()
                            .join(", ")
                    )),
                );
            }
        }
        if let Some(&prev) = first.get(eq) {
            let prev_at = e.models.get(prev).map(|p| &p.at);
            let where_prev = prev_at
                .filter(|l| !l.is_unknown())
                .map(|l| format!(" on line {}", l.line))
                .unwrap_or_default();
            out.push(
                Diagnostic::error(
                    codes::DUPLICATE_EQUATION,
                    format!("{who}: a second `enforcement for {eq}` line in one block"),
                )
                .at(at)
                .help(format!(
                    "the first is{where_prev}; one equation has one model per enforcement block: keep one, or put the other in its own `begin enforcement` block"
                )),
            );
        } else {
            first.insert(eq, m);
        }
        let name = model.model.as_str();
        if let Some((_, keys, usage)) = MODEL_KEYS.iter().find(|(n, _, _)| *n == name) {
            for (a, arg) in model.args.iter().enumerate() {
                if arg.key.is_empty() || keys.contains(&arg.key.as_str()) {
                    continue;
                }
                let hint = did_you_mean(&arg.key, keys.iter().copied())
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                out.push(
                    Diagnostic::error(
                        codes::UNKNOWN_MODEL_KEY,
                        format!(
                            "{who}: `{}` is not an argument of the `{name}` model",
                            arg.key
                        ),
                    )
                    .at(locs.or(&format!("{d}.enforcement.{k}.model.{m}.arg.{a}"), &model.at))
                    .help(format!("{hint}`{name}` takes {usage}")),
                );
            }
        }
    }
    for p in &e.properties {
        let name = p.property.as_str();
        if name == "gap_conductance_coefficient" {
            continue;
        }
        let at = (!p.at.is_unknown()).then(|| p.at.clone());
        // By key, or by the phrase in snake_case (`contact_surface_pressure`).
        let spec = registry::COMMANDS.iter().find(|c| {
            c.blocks.contains(&"enforcement")
                && (c.key == name || c.phrase.replace(' ', "_") == name)
        });
        match spec {
            Some(c) if matches!(c.status, Status::Refused(_)) => {
                let Status::Refused(why) = c.status else {
                    continue;
                };
                out.push(
                    Diagnostic::error(
                        codes::REFUSED_MATERIAL_MODEL,
                        format!("{who}: seam cannot use the material model `{}`: it {why}", c.phrase),
                    )
                    .at(at)
                    .help(format!("remove the line; {SUPPORTED_PROPERTIES}")),
                );
            }
            Some(c) => out.push(
                Diagnostic::error(
                    codes::UNKNOWN_PROPERTY,
                    format!("{who}: `{}` is not a property line but a field of the enforcement", c.phrase),
                )
                .at(at)
                .help(format!(
                    "in TOML write `{} = …` in the enforcement table; `property` entries are `gap_conductance_coefficient` lines",
                    c.key
                )),
            ),
            None => {
                let known = registry::COMMANDS
                    .iter()
                    .filter(|c| c.blocks.contains(&"enforcement"))
                    .map(|c| c.key);
                let hint = did_you_mean(name, known)
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                out.push(
                    Diagnostic::error(
                        codes::UNKNOWN_PROPERTY,
                        format!("{who}: unknown material property `{name}`"),
                    )
                    .at(at)
                    .help(format!("{hint}{SUPPORTED_PROPERTIES}")),
                );
            }
        }
    }
}
