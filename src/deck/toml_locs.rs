//! Locations for the TOML form: after serde has built the [`Deck`], walk the same text
//! once more as a spanned TOML tree and record where each checked value and each item
//! sits, so TOML diagnostics get line and column just like Sierra ones.
//!
//! Entry point: [`locate`]. It fills the spec's `at` fields (an item's location is the
//! start of its table) and returns the [`Locs`] table that [`super::check`] reads. A
//! value it cannot find simply stays unlocated.

use std::ops::Range;
use std::sync::Arc;

use ::toml::Spanned;
use ::toml::de::{DeTable, DeValue};

use super::check::Locs;
use super::spec::*;

type Node<'i> = Spanned<DeValue<'i>>;

/// Fill `deck`'s locations from `text` (which must be the TOML it was read from).
pub fn locate(file: &Arc<str>, text: &str, deck: &mut Deck) -> Locs {
    let mut locs = Locs::default();
    let Ok(root) = DeTable::parse(text) else {
        return locs;
    };
    let at = |r: Range<usize>| super::byte_span_loc(file, text, r);
    let defs = field(root.get_ref(), "contact_definition").and_then(|v| v.get_ref().as_array());
    let Some(defs) = defs else { return locs };
    for (d, (def, node)) in deck
        .contact_definitions
        .iter_mut()
        .zip(defs.iter())
        .enumerate()
    {
        let Some(t) = node.get_ref().as_table() else {
            continue;
        };
        def.at = at(node.span());
        let mut put = |key: String, v: Option<&Node>| {
            if let Some(v) = v {
                locs.set(key, at(v.span()));
            }
        };
        for key in [
            "opposed_normal_threshold_angle",
            "update_search_every_n_steps",
        ] {
            put(format!("{d}.{key}"), field(t, key));
        }
        if let Some(n) = field(t, "restrict_contact_to_subdomain") {
            for key in ["radius", "point"] {
                put(
                    format!("{d}.restrict_contact_to_subdomain.{key}"),
                    sub(n, key),
                );
            }
        }
        for (k, (c, n)) in def
            .control_assignments
            .iter_mut()
            .zip(items(t, "control_assignment"))
            .enumerate()
        {
            c.at = at(n.span());
            if let Some(control) = sub(n, "control") {
                put(
                    format!("{d}.control_assignment.{k}.factor"),
                    sub(control, "factor"),
                );
            }
        }
        for (s, (surf, n)) in def.surfaces.iter_mut().zip(items(t, "surface")).enumerate() {
            put(format!("{d}.surface.{s}.name"), sub(n, "name"));
            let loc = at(n.span());
            match surf {
                SurfaceDef::Contains { at, .. }
                | SurfaceDef::NodeSet { at, .. }
                | SurfaceDef::SkinAllBlocks { at, .. } => *at = loc,
                SurfaceDef::Block(b) => {
                    b.at = loc;
                    let subsets = n.get_ref().as_table().map(|t| items(t, "subset"));
                    for (k, (x, sn)) in b
                        .subsets
                        .iter_mut()
                        .zip(subsets.unwrap_or_default())
                        .enumerate()
                    {
                        x.at = at(sn.span());
                        put(
                            format!("{d}.surface.{s}.subset.{k}.normal"),
                            sub(sn, "normal"),
                        );
                    }
                    if let (Some(a), Some(an)) = (&mut b.auto_subset, sub(n, "auto_subset")) {
                        a.at = at(an.span());
                        for key in ["angle", "number_of_subsets"] {
                            put(format!("{d}.surface.{s}.auto_subset.{key}"), sub(an, key));
                        }
                    }
                }
            }
        }
        for (p, (per, n)) in def
            .periodicity
            .iter_mut()
            .zip(items(t, "periodicity"))
            .enumerate()
        {
            per.at = at(n.span());
            if let Some(tr) = sub(n, "transform") {
                for key in ["offset", "axis", "center", "angle"] {
                    put(format!("{d}.periodicity.{p}.{key}"), sub(tr, key));
                }
            }
        }
        for (k, (e, n)) in def
            .enforcements
            .iter_mut()
            .zip(items(t, "enforcement"))
            .enumerate()
        {
            e.at = at(n.span());
            for key in [
                "use_toggle_block",
                "dash_penalty_factor",
                "offset_temperature",
                "offset_voltage",
                "joule_fraction_side_a",
                "offset_species",
                "partition_coefficient",
                "contact_pressure",
            ] {
                put(format!("{d}.enforcement.{k}.{key}"), sub(n, key));
            }
            let table = n.get_ref().as_table();
            for (j, (m, mn)) in e
                .models
                .iter_mut()
                .zip(table.map(|t| items(t, "model")).unwrap_or_default())
                .enumerate()
            {
                m.at = at(mn.span());
                put(
                    format!("{d}.enforcement.{k}.model.{j}.equation"),
                    sub(mn, "equation"),
                );
            }
            for (m, mn) in e
                .properties
                .iter_mut()
                .zip(table.map(|t| items(t, "property")).unwrap_or_default())
            {
                m.at = at(mn.span());
            }
        }
        for (i, (x, n)) in def
            .interactions
            .iter_mut()
            .zip(items(t, "interaction"))
            .enumerate()
        {
            x.at = at(n.span());
            put(
                format!("{d}.interaction.{i}.normal_tolerance"),
                sub(n, "normal_tolerance"),
            );
            put(
                format!("{d}.interaction.{i}.enforcement"),
                sub(n, "enforcement"),
            );
        }
        if let (Some(x), Some(n)) = (
            &mut def.interaction_defaults,
            field(t, "interaction_defaults"),
        ) {
            x.at = at(n.span());
            put(
                format!("{d}.interaction_defaults.enforcement"),
                sub(n, "enforcement"),
            );
        }
        if let (Some(x), Some(n)) = (&mut def.search_options, field(t, "search_options")) {
            x.at = at(n.span());
            for key in [
                "normal_tolerance",
                "tangential_tolerance",
                "buffer_factor",
                "field_factor",
                "normal_check_angle",
                "search_update_frequency",
            ] {
                put(format!("{d}.search_options.{key}"), sub(n, key));
            }
        }
    }
    locs
}

fn field<'a, 'i>(t: &'a DeTable<'i>, key: &str) -> Option<&'a Node<'i>> {
    t.iter().find(|(k, _)| k.get_ref() == key).map(|(_, v)| v)
}

fn sub<'a, 'i>(n: &'a Node<'i>, key: &str) -> Option<&'a Node<'i>> {
    field(n.get_ref().as_table()?, key)
}

/// The elements of the array `key` of `t` (empty when absent or not an array).
fn items<'a, 'i>(t: &'a DeTable<'i>, key: &str) -> Vec<&'a Node<'i>> {
    field(t, key)
        .and_then(|v| v.get_ref().as_array())
        .map(|a| a.iter().collect())
        .unwrap_or_default()
}
