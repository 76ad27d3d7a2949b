//! Front-end tests: lowering of every command, the TOML twin, and properties that must
//! hold for any spelling of the same deck.

use std::sync::Arc;

use proptest::prelude::*;

use super::spec::*;
use super::{codes, parse_sierra, parse_toml};
use crate::diag::Diagnostics;

fn sierra(text: &str) -> (Deck, Diagnostics) {
    parse_sierra(&Arc::from("t.i"), text)
}

fn codes_of(d: &Diagnostics) -> Vec<&'static str> {
    d.0.iter().map(|x| x.code).collect()
}

/// Parse a deck that must be clean; its locations are dropped.
fn clean(text: &str) -> Deck {
    let (deck, d) = sierra(text);
    assert!(d.is_empty(), "unexpected diagnostics: {d:#?}");
    deck.without_locations()
}

fn one_def(text: &str) -> ContactDefinition {
    let mut deck = clean(text);
    assert_eq!(deck.contact_definitions.len(), 1);
    deck.contact_definitions.remove(0)
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn arg(key: &str, value: &str) -> Arg {
    Arg {
        key: key.into(),
        value: value.into(),
    }
}

/// A deck that touches every command, with mixed case, separators and comments.
const FULL: &str = r#"
# contact for the lid
Begin Contact Definition Lid   $ the only one
  Contact Surface Top Contains Block_1, SS_2
  Contact Node Set Pins Contains ns_1
  Skin All Blocks = On Exclude block_9 block_10
  Restrict Contact To Subdomain Defined By Radius 2.5 And Point 0 0 1
  Visualize Contact
  Output Rule = More Verbose
  Update Search Every 5 Steps
  Opposed Normal Threshold Angle is 120
  Disable Opposed Normal Interaction Culling
  Periodicity For left = Rectangular Offset = 1 0
  Periodicity For cyl = Cylindrical Axis = 0 0 1 Center = 0 0 0 Angle = 90
  Periodicity For a = Align_Surface Destination = B Invert_Normals = 0
  Periodicity For m = Mapped X_Map = "x + 1" Y_Map = "Shift(y)"
  Scale Penalty = 2
  Scale Penalty For Top With Bottom is 0.5
  Initial Overclosure For Top = Adjust Nodes
  Begin Enforcement Gap
    Enforcement For Energy = Plugin Library = "path/libModel.so" Model = Name
    Integer Data 1 2 3
    Real Data = 1.5, 2e3 1d2
    Side B Variable T To T
    Dash Penalty Factor = 10
    Offset Temperature = 273.15
    Use Toggle Block = tog
    Gap Conductance Coefficient = Constant H = 10
  End Enforcement Gap
  begin interaction i1
    side a top
    side b bottom
    normal tolerance 0.01
    enforcement = gap
  end interaction
  begin interaction defaults
    general contact = on
    self contact are off
    surfaces top bottom
    enforcement = gap
  end
  begin search options opts
    normal tolerance = 0.1
    tangential tolerance = 0.2
    buffer factor = 1.1
    field factor = 2
    normal check angle = 30
    self contact = on
    search update frequency 3
  end
  begin contact surface bottom
    include all blocks
    block = b1 b2
    element = 1 2 3
    surface = ss1
    assembly = as1
    remove block = b3
    remove surface = ss3
    subset up with normal 0 0 1
    contact type = node
  end contact surface bottom
  begin contact surface side
    auto subset parts number of subsets 4 angle 45
  end
end
"#;

fn full_expected() -> Deck {
    let def = ContactDefinition {
        name: Some("lid".into()),
        surfaces: vec![
            SurfaceDef::Contains {
                name: "top".into(),
                contains: strings(&["block_1", "ss_2"]),
                at: Default::default(),
            },
            SurfaceDef::NodeSet {
                name: "pins".into(),
                contains: strings(&["ns_1"]),
                at: Default::default(),
            },
            SurfaceDef::SkinAllBlocks {
                exclude: strings(&["block_9", "block_10"]),
                at: Default::default(),
            },
            SurfaceDef::Block(SurfaceBlock {
                name: "bottom".into(),
                include_all_blocks: true,
                blocks: strings(&["b1", "b2"]),
                elements: vec![1, 2, 3],
                side_sets: strings(&["ss1"]),
                assemblies: strings(&["as1"]),
                remove_blocks: strings(&["b3"]),
                remove_surfaces: strings(&["ss3"]),
                subsets: vec![Subset {
                    name: "up".into(),
                    normal: [0.0, 0.0, 1.0],
                    at: Default::default(),
                }],
                auto_subset: None,
                contact_type: ContactType::Node,
                at: Default::default(),
                name_locs: Vec::new(),
            }),
            SurfaceDef::Block(SurfaceBlock {
                name: "side".into(),
                auto_subset: Some(AutoSubset {
                    name: "parts".into(),
                    number_of_subsets: Some(4),
                    angle: Some(45.0),
                    at: Default::default(),
                }),
                ..Default::default()
            }),
        ],
        restrict_contact_to_subdomain: Some(Subdomain {
            radius: 2.5,
            point: [0.0, 0.0, 1.0],
        }),
        visualize_contact: true,
        output_rule: Some(OutputRule::MoreVerbose),
        update_search_every_n_steps: Some(5),
        opposed_normal_threshold_angle: Some(120.0),
        disable_opposed_normal_interaction_culling: true,
        periodicity: vec![
            Periodicity {
                surface: "left".into(),
                transform: PeriodicTransform::Rectangular {
                    offset: vec![1.0, 0.0],
                },
                at: Default::default(),
            },
            Periodicity {
                surface: "cyl".into(),
                transform: PeriodicTransform::Cylindrical {
                    axis: vec![0.0, 0.0, 1.0],
                    center: vec![0.0, 0.0, 0.0],
                    angle: 90.0,
                },
                at: Default::default(),
            },
            Periodicity {
                surface: "a".into(),
                transform: PeriodicTransform::AlignSurface {
                    destination: "b".into(),
                    invert_normals: false,
                },
                at: Default::default(),
            },
            Periodicity {
                surface: "m".into(),
                transform: PeriodicTransform::Mapped {
                    x_map: "x + 1".into(),
                    y_map: "Shift(y)".into(),
                    z_map: None,
                },
                at: Default::default(),
            },
        ],
        enforcements: vec![Enforcement {
            name: Some("gap".into()),
            models: vec![EnforcementModel {
                equation: "energy".into(),
                model: "plugin".into(),
                args: vec![arg("library", "path/libModel.so"), arg("model", "name")],
                at: Default::default(),
            }],
            properties: vec![PropertyModel {
                property: "gap_conductance_coefficient".into(),
                model: "constant".into(),
                args: vec![arg("h", "10")],
                at: Default::default(),
            }],
            integer_data: vec![1, 2, 3],
            real_data: vec![1.5, 2000.0, 100.0],
            side_b_variable: Some(VariableMap {
                side_b: "t".into(),
                side_a: "t".into(),
            }),
            dash_penalty_factor: Some(10.0),
            offset_temperature: Some(273.15),
            offset_voltage: None,
            joule_fraction_side_a: None,
            offset_species: None,
            partition_coefficient: None,
            contact_pressure: None,
            quarantine_faulty_points: false,
            use_toggle_block: Some("tog".into()),
            toggle_element_blocks: vec![],
            contact_gap_temperature: None,
            contact_gap_voltage: None,
            plugin_isolation: Default::default(),
            contact_pressure_variable: None,
            at: Default::default(),
        }],
        interactions: vec![Interaction {
            name: Some("i1".into()),
            side_a: strings(&["top"]),
            side_b: strings(&["bottom"]),
            surfaces: vec![],
            normal_tolerance: Some(0.01),
            enforcement: Some("gap".into()),
            at: Default::default(),
        }],
        interaction_defaults: Some(InteractionDefaults {
            general_contact: Some(true),
            self_contact: Some(false),
            surfaces: strings(&["top", "bottom"]),
            enforcement: Some("gap".into()),
            at: Default::default(),
        }),
        search_options: Some(SearchOptions {
            name: Some("opts".into()),
            normal_tolerance: Some(0.1),
            tangential_tolerance: Some(0.2),
            buffer_factor: Some(1.1),
            field_factor: Some(2.0),
            normal_check_angle: Some(30.0),
            self_contact: Some(true),
            search_update_frequency: Some(3),
            at: Default::default(),
        }),
        control_assignments: vec![
            ControlAssignment {
                surface_1: None,
                surface_2: None,
                control: Control::ScalePenalty { factor: 2.0 },
                at: Default::default(),
            },
            ControlAssignment {
                surface_1: Some("top".into()),
                surface_2: Some("bottom".into()),
                control: Control::ScalePenalty { factor: 0.5 },
                at: Default::default(),
            },
            ControlAssignment {
                surface_1: Some("top".into()),
                surface_2: None,
                control: Control::InitialOverclosure {
                    treatment: Overclosure::AdjustNodes,
                },
                at: Default::default(),
            },
        ],
        at: Default::default(),
    };
    Deck {
        contact_definitions: vec![def],
    }
}

#[test]
fn every_command_lowers_to_the_hand_written_spec() {
    assert_eq!(clean(FULL), full_expected());
}

/// The same deck as `FULL`, written by hand in TOML.
const FULL_TOML: &str = r#"
[[contact_definition]]
name = "lid"
restrict_contact_to_subdomain = { radius = 2.5, point = [0, 0, 1] }
visualize_contact = true
output_rule = "more_verbose"
update_search_every_n_steps = 5
opposed_normal_threshold_angle = 120
disable_opposed_normal_interaction_culling = true

[[contact_definition.surface]]
kind = "contains"
name = "top"
contains = ["block_1", "ss_2"]

[[contact_definition.surface]]
kind = "node_set"
name = "pins"
contains = ["ns_1"]

[[contact_definition.surface]]
kind = "skin_all_blocks"
exclude = ["block_9", "block_10"]

[[contact_definition.surface]]
kind = "block"
name = "bottom"
include_all_blocks = true
block = ["b1", "b2"]
element = [1, 2, 3]
surface = ["ss1"]
assembly = ["as1"]
remove_block = ["b3"]
remove_surface = ["ss3"]
subset = [{ name = "up", normal = [0, 0, 1] }]
contact_type = "node"

[[contact_definition.surface]]
kind = "block"
name = "side"
auto_subset = { name = "parts", number_of_subsets = 4, angle = 45 }

[[contact_definition.periodicity]]
surface = "left"
transform = { kind = "rectangular", offset = [1, 0] }

[[contact_definition.periodicity]]
surface = "cyl"
transform = { kind = "cylindrical", axis = [0, 0, 1], center = [0, 0, 0], angle = 90 }

[[contact_definition.periodicity]]
surface = "a"
transform = { kind = "align_surface", destination = "b", invert_normals = false }

[[contact_definition.periodicity]]
surface = "m"
transform = { kind = "mapped", x_map = "x + 1", y_map = "Shift(y)" }

[[contact_definition.enforcement]]
name = "gap"
integer_data = [1, 2, 3]
real_data = [1.5, 2000, 100]
side_b_variable = { side_b = "t", side_a = "t" }
dash_penalty_factor = 10
offset_temperature = 273.15
use_toggle_block = "tog"
model = [{ equation = "energy", model = "plugin", args = [{ key = "library", value = "path/libModel.so" }, { key = "model", value = "name" }] }]
property = [{ property = "gap_conductance_coefficient", model = "constant", args = [{ key = "h", value = "10" }] }]

[[contact_definition.interaction]]
name = "i1"
side_a = ["top"]
side_b = ["bottom"]
normal_tolerance = 0.01
enforcement = "gap"

[contact_definition.interaction_defaults]
general_contact = true
self_contact = false
surfaces = ["top", "bottom"]
enforcement = "gap"

[contact_definition.search_options]
name = "opts"
normal_tolerance = 0.1
tangential_tolerance = 0.2
buffer_factor = 1.1
field_factor = 2
normal_check_angle = 30
self_contact = true
search_update_frequency = 3

[[contact_definition.control_assignment]]
control = { kind = "scale_penalty", factor = 2.0 }

[[contact_definition.control_assignment]]
surface_1 = "top"
surface_2 = "bottom"
control = { kind = "scale_penalty", factor = 0.5 }

[[contact_definition.control_assignment]]
surface_1 = "top"
control = { kind = "initial_overclosure", treatment = "adjust_nodes" }
"#;

#[test]
fn toml_twin_gives_the_same_spec() {
    let (deck, d) = parse_toml(&Arc::from("t.toml"), FULL_TOML);
    assert!(d.is_empty(), "{d:#?}");
    assert_eq!(deck.without_locations(), clean(FULL));
}

#[test]
fn toml_runs_the_same_semantic_checks() {
    let text = "[[contact_definition]]\nopposed_normal_threshold_angle = 45.0\n\
                [contact_definition.search_options]\nnormal_tolerance = 0.0\n";
    let (_, d) = parse_toml(&Arc::from("t.toml"), text);
    assert_eq!(
        codes_of(&d),
        [codes::OPPOSED_ANGLE, codes::NORMAL_TOLERANCE]
    );
    // The values are located in the TOML text.
    let places: Vec<(u32, u32)> =
        d.0.iter()
            .filter_map(|x| x.loc.as_ref().map(|l| (l.line, l.col)))
            .collect();
    assert_eq!(places, [(2, 34), (4, 20)]);
}

#[test]
fn toml_items_get_locations() {
    let (deck, _) = parse_toml(&Arc::from("t.toml"), FULL_TOML);
    let def = &deck.contact_definitions[0];
    let lines: Vec<u32> = def.surfaces.iter().map(|s| s.at().line).collect();
    assert_eq!(lines, [11, 16, 21, 25, 38]);
    assert_eq!(def.interactions[0].at.line, 70);
}

#[test]
fn toml_errors_point_at_line_and_column() {
    let text = "[[contact_definition]]\nname = \"x\"\nvisualise_contact = true\n";
    let (_, d) = parse_toml(&Arc::from("t.toml"), text);
    assert_eq!(codes_of(&d), [codes::TOML_ERROR]);
    let loc = d.0[0].loc.clone().unwrap_or_default();
    assert_eq!((loc.line, loc.col), (3, 1));
}

#[test]
fn gap_conductance_property_as_written_in_aria() {
    let def = one_def(
        "begin contact definition\n begin enforcement\n  Gap Conductance Coefficient = Constant H = 10\n end\nend\n",
    );
    let p = &def.enforcements[0].properties;
    assert_eq!(p.len(), 1);
    assert_eq!(p[0].property, "gap_conductance_coefficient");
    assert_eq!(p[0].model, "constant");
    assert_eq!(p[0].args, vec![arg("h", "10")]);
}

#[test]
fn unknown_property_starting_with_another_blocks_keyword_is_unknown() {
    // `surface` is a contact-surface command; `surface emissivity = …` is no material
    // model of Aria's list, so it is an unknown keyword, not a misplaced `surface`.
    let (deck, d) = sierra(
        "begin contact definition\n begin enforcement\n  Surface Emissivity = Constant E = 0.5\n end\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::UNKNOWN_KEYWORD]);
    assert!(
        deck.contact_definitions[0].enforcements[0]
            .properties
            .is_empty()
    );
}

#[test]
fn misspelt_enforcement_command_is_not_a_property() {
    let (deck, d) = sierra(
        "begin contact definition\n begin enforcement\n  Dash Penalty Factr = 3\n end\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::UNKNOWN_KEYWORD]);
    assert!(
        deck.contact_definitions[0].enforcements[0]
            .properties
            .is_empty()
    );
    assert!(
        d.0[0]
            .help
            .as_deref()
            .unwrap_or("")
            .starts_with("did you mean `dash penalty factor`?")
    );
}

#[test]
fn skin_all_blocks_off_makes_no_surface_and_visualize_off_is_off() {
    let def = one_def(
        "begin contact definition\n skin all blocks = off\n visualize contact = off\nend\n",
    );
    assert!(def.surfaces.is_empty());
    assert!(!def.visualize_contact);
}

#[test]
fn slave_variable_is_a_warning_and_still_lowers() {
    let (deck, d) = sierra(
        "begin contact definition\n begin enforcement\n  slave variable a to b\n end\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::DEPRECATED_ALIAS]);
    assert!(!d.has_errors());
    let m = deck.contact_definitions[0].enforcements[0]
        .side_b_variable
        .clone();
    assert_eq!(
        m,
        Some(VariableMap {
            side_b: "a".into(),
            side_a: "b".into()
        })
    );
}

#[test]
fn locations_point_at_the_command_line() {
    let (deck, _) = sierra("begin contact definition\n\n   contact surface s contains b\nend\n");
    let at = deck.contact_definitions[0].surfaces[0].at().clone();
    assert_eq!((at.line, at.col, at.len), (3, 4, 28));
}

#[test]
fn second_auto_subset_and_zero_subsets_are_errors() {
    let (_, d) = sierra(
        "begin contact definition\n begin contact surface s\n  auto subset a number of subsets 0\n  auto subset b\n end\nend\n",
    );
    assert_eq!(
        codes_of(&d),
        [codes::NONPOSITIVE_SUBSETS, codes::SECOND_AUTO_SUBSET]
    );
    let lines: Vec<u32> =
        d.0.iter()
            .filter_map(|x| x.loc.as_ref().map(|l| l.line))
            .collect();
    assert_eq!(lines, [3, 4]);
}

#[test]
fn blocks_in_the_wrong_place() {
    let (_, d) = sierra(
        "begin interaction x\nend\nbegin contact definition\n begin contact definition inner\n end\n begin enforcement\n  begin search options\n  end\n end\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::MISPLACED_BLOCK; 3]);
}

#[test]
fn lines_outside_blocks() {
    let (_, d) = sierra("normal tolerance = 1\ngravity on\n");
    assert_eq!(codes_of(&d), [codes::WRONG_BLOCK, codes::OUTSIDE_BLOCK]);
}

#[test]
fn periodicity_parts_are_checked() {
    let (deck, d) = sierra(
        "begin contact definition\n periodicity for s = cylindrical axis = 0 0 1 centre = 0 0 0 angle = 30\n periodicity for s = helical\nend\n",
    );
    let c = codes_of(&d);
    assert!(c.iter().all(|&x| x == codes::PERIODICITY), "{c:?}");
    assert!(d.0.iter().any(|x| {
        x.help
            .as_deref()
            .unwrap_or("")
            .contains("did you mean `center`")
    }));
    assert!(deck.contact_definitions[0].periodicity.is_empty());
}

#[test]
fn missing_words_are_reported_past_the_line_end() {
    let (_, d) = sierra("begin contact definition\n contact surface top contains\nend\n");
    assert_eq!(codes_of(&d), [codes::MISSING_ARGUMENT]);
    let loc = d.0[0].loc.clone().unwrap_or_default();
    assert_eq!((loc.line, loc.col), (2, 31));
}

#[test]
fn extra_words_and_repeats() {
    let (deck, d) = sierra(
        "begin contact definition\n update search every 2 steps please\n output rule = none\n output rule = summary\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::EXTRA_WORDS, codes::REPEATED_COMMAND]);
    assert_eq!(
        deck.contact_definitions[0].output_rule,
        Some(OutputRule::Summary)
    );
}

#[test]
fn a_separator_inside_a_list_of_values_is_reported_and_passed_over() {
    // Each of these looped forever, pushing one diagnostic per turn.
    let text = "begin contact definition
  begin contact surface top
    element = 1 = 2
  end
  begin enforcement e
    real data = real data = 1 2
    integer data = 3 is 4
  end
end
";
    let (deck, d) = sierra(text);
    let def = &deck.contact_definitions[0];
    let SurfaceDef::Block(top) = &def.surfaces[0] else {
        panic!("a surface block: {:?}", def.surfaces)
    };
    assert_eq!(top.elements, [1, 2], "{d:?}");
    assert_eq!(def.enforcements[0].integer_data, [3, 4], "{d:?}");
    assert_eq!(def.enforcements[0].real_data, [1.0, 2.0], "{d:?}");
    // `element`'s `=`, `real`, `data`, `=` and `is`: one diagnostic each.
    assert_eq!(d.len(), 5, "{d:?}");
}

// ----- properties -----

/// A deck whose only case-sensitive text is inside quotes, so any re-spelling outside
/// quotes must give the same spec.
const RESPELL: &str = r#"begin contact definition main
  contact surface top contains block_1 ss_2
  skin all blocks = on exclude block_9
  output rule = summary
  opposed normal threshold angle = 150
  periodicity for top = mapped x_map = "X + 1" y_map = "y"
  begin enforcement gap
    enforcement for energy = plugin library = "lib/Model.so" model = m
    gap conductance coefficient = constant h = 1.5e1
    real data 1 2.5
  end enforcement gap
  begin interaction i
    side a top
    side b bottom
    normal tolerance = 0.01
    enforcement = gap
  end
  begin contact surface bottom
    block = b1 b2
    subset up with normal 0 0 1
  end contact surface bottom
end contact definition main
"#;

/// Re-spell `text` outside quoted strings: random case, `=` swapped for `is`/`are`,
/// each space widened with tabs and commas, and a comment appended to some lines.
fn respell(text: &str, seed: u64) -> String {
    let mut state = seed | 1;
    let mut next = move |n: u64| {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state % n
    };
    let mut out = String::new();
    for line in text.lines() {
        let mut quoted = false;
        for c in line.chars() {
            if c == '"' {
                quoted = !quoted;
                out.push(c);
            } else if quoted {
                out.push(c);
            } else if c == '=' {
                out.push_str(["=", "is", "are", "IS"][next(4) as usize]);
            } else if c == ' ' {
                for _ in 0..=next(3) {
                    out.push([' ', '\t', ','][next(3) as usize]);
                }
                out.push(' ');
            } else if next(2) == 0 {
                out.extend(c.to_uppercase());
            } else {
                out.push(c);
            }
        }
        match next(4) {
            0 => out.push_str(" # note = \"x\" begin end"),
            1 => out.push_str("\t$ is are"),
            _ => {}
        }
        out.push('\n');
        if next(5) == 0 {
            out.push_str("   # a comment line\n\n");
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn respelling_never_changes_the_deck(seed in any::<u64>()) {
        let base = clean(RESPELL);
        let text = respell(RESPELL, seed);
        let (deck, d) = sierra(&text);
        prop_assert!(d.is_empty(), "{}\n{:#?}", text, d);
        prop_assert_eq!(deck.without_locations(), base);
    }

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let text = String::from_utf8_lossy(&bytes);
        let _ = sierra(&text);
        let _ = parse_toml(&Arc::from("t.toml"), &text);
    }

    #[test]
    fn deck_shaped_noise_never_panics(words in proptest::collection::vec(prop_oneof![
        Just("begin".to_string()), Just("end".to_string()), Just("contact".to_string()), Just("definition".to_string()), Just("surface".to_string()),
        Just("enforcement".to_string()), Just("interaction".to_string()), Just("defaults".to_string()), Just("search".to_string()),
        Just("options".to_string()), Just("subset".to_string()), Just("auto".to_string()), Just("angle".to_string()), Just("number".to_string()),
        Just("of".to_string()), Just("subsets".to_string()), Just("with".to_string()), Just("normal".to_string()), Just("periodicity".to_string()),
        Just("for".to_string()), Just("=".to_string()), Just("is".to_string()), Just("\n".to_string()), Just("\n".to_string()), Just("\"".to_string()), Just("#".to_string()),
        Just("contains".to_string()), Just("skin".to_string()), Just("all".to_string()), Just("blocks".to_string()), Just("on".to_string()),
        Just("rectangular".to_string()), Just("offset".to_string()), Just("cylindrical".to_string()), Just("mapped".to_string()),
        Just("x_map".to_string()), Just("0".to_string()), Just("-1".to_string()), Just("1e400".to_string()), Just("nan".to_string()), Just("ü".to_string()),
        "[a-z0-9.,\t-]{0,6}",
    ], 0..80)) {
        let text = words.join(" ");
        let _ = sierra(&text);
    }
}

#[test]
fn alias_and_canonical_phrase_count_as_one_command() {
    let (_, d) = sierra(
        "begin contact definition\n begin enforcement\n  side b variable a to b\n  slave variable a to b\n end\nend\n",
    );
    assert_eq!(
        codes_of(&d),
        [codes::DEPRECATED_ALIAS, codes::REPEATED_COMMAND]
    );
}

#[test]
fn check_deck_works_on_a_spec_built_in_code() {
    let mut deck = clean(FULL);
    deck.contact_definitions[0].opposed_normal_threshold_angle = Some(10.0);
    let d = super::check_deck(&deck);
    assert_eq!(codes_of(&d), [codes::OPPOSED_ANGLE]);
    assert!(d.0[0].loc.is_none());
    // Unlocated, so the message names the definition.
    assert!(
        d.0[0].message.starts_with("contact definition `lid`: "),
        "{}",
        d.0[0].message
    );
}

#[test]
fn block_naming_and_duplicate_blocks() {
    let (_, d) = sierra(
        "begin contact definition\n begin contact surface\n end\n begin search options\n end\n begin search options again\n end\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::BLOCK_NAME, codes::DUPLICATE_BLOCK]);
    let lines: Vec<u32> =
        d.0.iter()
            .filter_map(|x| x.loc.as_ref().map(|l| l.line))
            .collect();
    assert_eq!(lines, [2, 6]);
}

#[test]
fn unterminated_string_surfaces_through_parse_sierra() {
    let (_, d) = sierra(
        "begin contact definition\n begin enforcement\n  enforcement for energy = plugin library = \"lib.so\n end\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::UNTERMINATED_STRING]);
}

#[test]
fn invert_normals_takes_zero_or_one_and_points_at_the_value() {
    let (_, d) = sierra(
        "begin contact definition\n periodicity for a = align_surface destination = b invert_normals = maybe\nend\n",
    );
    assert_eq!(codes_of(&d), [codes::ON_OFF]);
    let loc = d.0[0].loc.clone().unwrap_or_default();
    assert_eq!((loc.line, loc.col, loc.len), (2, 69, 5));
}

#[test]
fn a_deck_inside_a_sierra_input_file_gives_the_same_spec() {
    let base = clean(RESPELL);
    let wrapped = format!(
        "Begin Sierra job\n Begin Procedure p\n  Begin Aria Region r\n{RESPELL}  End Aria Region r\n End\nEnd Sierra job\n"
    );
    let (deck, d) = sierra(&wrapped);
    // Nothing but contact input: nothing skipped, so no note either.
    assert!(d.is_empty(), "{d:?}");
    assert_eq!(deck.without_locations(), base);
}

#[test]
fn underscores_spell_spaces_in_keywords() {
    let spaced = clean(
        "begin contact definition\n skin all blocks\n begin search options\n  normal check angle = 70\n  buffer factor = 2\n end\nend\n",
    );
    let underscored = clean(
        "begin contact definition\n Skin_All_Blocks\n begin search options\n  Normal_Check_Angle = 70\n  Buffer_Factor = 2\n end\nend\n",
    );
    assert_eq!(underscored, spaced);
    let so = spaced.contact_definitions[0].search_options.clone();
    assert_eq!(so.and_then(|s| s.normal_check_angle), Some(70.0));
}

#[test]
fn a_toggle_block_in_a_contact_deck_is_refused_not_unknown() {
    for text in [
        "begin toggle block tog\nend\n",
        "begin contact definition\n begin toggle block tog\n end\nend\n",
    ] {
        let (_, d) = sierra(text);
        assert_eq!(codes_of(&d), [codes::TOGGLE_BLOCK], "{text}");
    }
}

#[test]
fn a_misspelt_underscored_keyword_gets_a_suggestion() {
    let (_, d) =
        sierra("begin contact definition\n begin search options\n  Buffer_factr = 2\n end\nend\n");
    assert_eq!(codes_of(&d), [codes::UNKNOWN_KEYWORD]);
    assert_eq!(
        d.0[0].message,
        "unknown keyword `buffer_factr` in `begin search options`"
    );
    assert!(
        d.0[0]
            .help
            .as_deref()
            .is_some_and(|h| h.starts_with("did you mean `buffer factor`?"))
    );
}
