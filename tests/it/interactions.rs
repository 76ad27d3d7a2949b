//! Interactions from the deck: which surfaces pair up, in which roles, with which
//! controls. Decks are parsed from Sierra text so the whole path is exercised.

use std::sync::Arc;

use seam::deck::parse_sierra;
use seam::diag::SourceMap;
use seam::mesh::generate::{self, BoxSpec};
use seam::scene::interaction::{self, Interaction};
use seam::scene::surfaces;
use seam::search::Overclosure;

/// Three boxes meshed apart, blocks 1..3, and a node set on block 1's nodes.
fn resolve(deck: &str) -> (Vec<(String, String)>, Vec<Interaction>, Vec<&'static str>) {
    let mut mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [1, 1, 1], 1),
            BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [1, 1, 1], 2),
            BoxSpec::hex([0.0, 0.0, 2.0], [1.0, 1.0, 3.0], [1, 1, 1], 3),
        ],
        false,
    );
    mesh.node_sets.push(seam::mesh::NodeSet {
        id: 1,
        name: "pins".into(),
        nodes: vec![seam::mesh::NodeId(0)],
    });
    let (d, diags) = parse_sierra(&Arc::from("deck.i"), deck);
    assert!(!diags.has_errors(), "{diags:?}");
    let def = &d.contact_definitions[0];
    let set = surfaces::build(&mesh, def, &SourceMap::default());
    let (list, diags) = interaction::resolve(def, &set, 3, &SourceMap::default());
    let pairs = list
        .iter()
        .map(|i| (i.side_a_name.clone(), i.side_b_name.clone()))
        .collect();
    (pairs, list, diags.0.iter().map(|d| d.code).collect())
}

fn p(a: &str, b: &str) -> (String, String) {
    (a.into(), b.into())
}

const SURFACES: &str = "contact surface a contains block_1\n contact surface b contains block_2\n contact surface c contains block_3\n";

#[test]
fn without_interaction_blocks_every_pair_interacts() {
    let (pairs, _, codes) = resolve(&format!("begin contact definition\n{SURFACES}end\n"));
    assert_eq!(pairs, [p("a", "b"), p("a", "c"), p("b", "c")]);
    assert!(codes.is_empty());
}

#[test]
fn side_a_side_b_pairs_each_with_each() {
    let (pairs, list, _) = resolve(&format!(
        "begin contact definition\n{SURFACES}begin interaction\n side a a\n side b b c\n normal tolerance 0.01\nend\nend\n"
    ));
    assert_eq!(pairs, [p("a", "b"), p("a", "c")]);
    assert_eq!(list[0].settings.normal_tolerance, Some(0.01));
}

#[test]
fn surfaces_line_pairs_every_two() {
    let (pairs, _, _) = resolve(&format!(
        "begin contact definition\n{SURFACES}begin interaction\n surfaces c b a\nend\nend\n"
    ));
    assert_eq!(pairs, [p("c", "b"), p("c", "a"), p("b", "a")]);
}

#[test]
fn general_and_self_contact_defaults() {
    let (pairs, _, _) = resolve(&format!(
        "begin contact definition\n{SURFACES}begin interaction defaults\n general contact = on\n self contact = on\n surfaces a b\nend\nend\n"
    ));
    assert_eq!(pairs, [p("a", "b"), p("a", "a"), p("b", "b")]);
}

#[test]
fn node_surfaces_go_on_side_a_and_never_pair_together() {
    let (pairs, _, _) = resolve(
        "begin contact definition\n contact node set n contains pins\n contact node set m contains pins\n contact surface b contains block_2\nend\n",
    );
    // n and m are both node surfaces (m owns nothing, but it is still a node surface).
    assert_eq!(pairs, [p("n", "b"), p("m", "b")]);
}

#[test]
fn unknown_surfaces_in_interactions_are_errors() {
    let (_, _, codes) = resolve(&format!(
        "begin contact definition\n{SURFACES}begin interaction\n side a a\n side b bb\nend\nend\n"
    ));
    assert_eq!(codes, ["E0310"]);
}

#[test]
fn control_assignments_last_one_applies() {
    let (_, list, codes) = resolve(&format!(
        "begin contact definition\n{SURFACES}begin interaction defaults\n general contact = on\n self contact = on\nend\n\
         scale penalty = 2\n scale penalty for a with b = 0.5\n scale penalty for a = 3\n\
         initial overclosure for b with a = adjust nodes\nend\n"
    ));
    assert!(codes.is_empty(), "{codes:?}");
    let get = |a: &str, b: &str| {
        list.iter()
            .find(|i| i.side_a_name == a && i.side_b_name == b)
            .unwrap()
    };
    assert_eq!(get("a", "b").penalty_scale, 0.5);
    assert_eq!(
        get("a", "a").penalty_scale,
        3.0,
        "one name: self-interaction"
    );
    assert_eq!(get("b", "c").penalty_scale, 2.0, "no name: whole domain");
    assert_eq!(
        get("a", "b").overclosure,
        Overclosure::AdjustNodes,
        "either role order"
    );
    assert_eq!(
        get("a", "c").overclosure,
        Overclosure::StoreOffsets,
        "the default"
    );
}
