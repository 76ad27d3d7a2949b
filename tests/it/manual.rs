//! The manuals' own input, pasted: every `- Syntax` line of Aria's contact chapter
//! (7.22) and the worked examples of Sierra/SM's contact-surface chapter (8.4) and its
//! auto-subset section (11.3), each checked for what it does — the spec value the
//! manual's words give, or the exact refusal (code and message).
//!
//! Placeholders (`Surface_name`, `n`, `Angle`, …) are replaced by concrete values; the
//! manuals' `[ … ]` and `a | b` notation is written out as the concrete forms it stands
//! for. Everything else is as printed, capitals included.

use std::sync::Arc;

use seam::deck::parse_sierra;
use seam::deck::spec::*;
use seam::diag::Diagnostics;

fn parse(text: &str) -> (Deck, Diagnostics) {
    parse_sierra(&Arc::from("deck.i"), text)
}

/// `(code, message)` of every diagnostic.
fn diags(d: &Diagnostics) -> Vec<(&'static str, String)> {
    d.0.iter().map(|x| (x.code, x.message.clone())).collect()
}

/// The one contact definition of `text`, which must parse without any diagnostic.
fn clean(text: &str) -> ContactDefinition {
    let (deck, d) = parse(text);
    assert!(d.is_empty(), "{text}\n{:?}", diags(&d));
    assert_eq!(deck.contact_definitions.len(), 1);
    deck.contact_definitions[0].clone()
}

/// A contact definition holding `lines`.
fn in_definition(lines: &str) -> String {
    format!("begin Contact Definition cd\n{lines}\nend Contact Definition cd\n")
}

/// An enforcement block holding `lines`, in a contact definition.
fn in_enforcement(lines: &str) -> String {
    in_definition(&format!(
        "  begin Enforcement gap\n{lines}\n  end Enforcement gap"
    ))
}

fn definition_line(line: &str) -> ContactDefinition {
    clean(&in_definition(line))
}

fn enforcement_line(line: &str) -> Enforcement {
    clean(&in_enforcement(line)).enforcements[0].clone()
}

/// The diagnostics of `text`, which must not be empty.
fn refusal(text: &str) -> Vec<(&'static str, String)> {
    let (_, d) = parse(text);
    assert!(!d.is_empty(), "{text}: no diagnostic");
    diags(&d)
}

fn strings(v: &[&str]) -> Vec<String> {
    v.iter().map(|s| s.to_string()).collect()
}

fn contains(name: &str, of: &[&str]) -> SurfaceDef {
    SurfaceDef::Contains {
        name: name.into(),
        contains: strings(of),
        at: Default::default(),
    }
}

fn surfaces(def: &ContactDefinition) -> Vec<SurfaceDef> {
    Deck {
        contact_definitions: vec![def.clone()],
    }
    .without_locations()
    .contact_definitions[0]
        .surfaces
        .clone()
}

fn transform(line: &str) -> PeriodicTransform {
    let def = definition_line(line);
    assert_eq!(def.periodicity.len(), 1, "{line}");
    assert_eq!(def.periodicity[0].surface, "lo");
    def.periodicity[0].transform.clone()
}

// ----- Aria 7.22.1: Contact Definition line commands -----

#[test]
fn contact_surface_with_and_without_contains() {
    // `Contact Surface Surface_name [ Contains List_of_instances… ]`
    let def = definition_line("Contact Surface surface_2");
    assert_eq!(surfaces(&def), [contains("surface_2", &["surface_2"])]);
    let def = definition_line("Contact Surface top Contains block_1 surface_3");
    assert_eq!(surfaces(&def), [contains("top", &["block_1", "surface_3"])]);
}

#[test]
fn opposed_normal_and_culling_lines() {
    // `Disable Opposed Normal Interaction Culling`
    let def = definition_line("Disable Opposed Normal Interaction Culling");
    assert!(def.disable_opposed_normal_interaction_culling);
    // `Opposed Normal Threshold Angle Angle`, `{= | are | is}` optional.
    for line in [
        "Opposed Normal Threshold Angle 120",
        "Opposed Normal Threshold Angle = 120",
        "Opposed Normal Threshold Angle is 120",
    ] {
        assert_eq!(
            definition_line(line).opposed_normal_threshold_angle,
            Some(120.0)
        );
    }
}

#[test]
fn output_rule_needs_one_of_its_values() {
    // `Output Rule`: the parameter table gives `{more verbose | none | summary | verbose}`
    // with no default, so the bare line is refused and each value is read.
    assert_eq!(
        refusal(&in_definition("Output Rule")),
        [("E0110", "`output rule` expects a rule".to_string())]
    );
    for (line, rule) in [
        ("Output Rule none", OutputRule::None),
        ("Output Rule = summary", OutputRule::Summary),
        ("Output Rule is verbose", OutputRule::Verbose),
        ("Output Rule more verbose", OutputRule::MoreVerbose),
    ] {
        assert_eq!(definition_line(line).output_rule, Some(rule), "{line}");
    }
}

#[test]
fn rectangular_periodicity() {
    // `Periodicity For surface Rectangular Offset = offset1 offset2[ offset3]`
    assert_eq!(
        transform("Periodicity For lo Rectangular Offset = 1 0 0"),
        PeriodicTransform::Rectangular {
            offset: vec![1.0, 0.0, 0.0]
        }
    );
    assert_eq!(
        transform("Periodicity For lo Rectangular Offset = 2.5 -1"),
        PeriodicTransform::Rectangular {
            offset: vec![2.5, -1.0]
        }
    );
    // The `=` after the surface that seam's own form writes is still read.
    assert_eq!(
        transform("Periodicity For lo = Rectangular Offset = 1 0 0"),
        PeriodicTransform::Rectangular {
            offset: vec![1.0, 0.0, 0.0]
        }
    );
}

#[test]
fn align_surface_periodicity_inverts_normals_by_default() {
    // `Periodicity For surface Align_Surface [Destination = destination |
    // Invert_Normals = invert_normals]`: "By default the original face's normal is
    // aligned to -1*destination normal, but this can be disabled by setting
    // invert_normals to 0."
    assert_eq!(
        transform("Periodicity For lo Align_Surface Destination = hi"),
        PeriodicTransform::AlignSurface {
            destination: "hi".into(),
            invert_normals: true
        }
    );
    assert_eq!(
        transform("Periodicity For lo Align_Surface Destination = hi Invert_Normals = 0"),
        PeriodicTransform::AlignSurface {
            destination: "hi".into(),
            invert_normals: false
        }
    );
    // The destination has no default: without it there is nothing to align to.
    assert_eq!(
        refusal(&in_definition(
            "Periodicity For lo Align_Surface Invert_Normals = 1"
        )),
        [(
            "E0214",
            "the `align_surface` periodicity needs `destination = …`".to_string()
        )]
    );
}

#[test]
fn cylindrical_periodicity_needs_axis_center_and_angle() {
    // `Periodicity For surface Cylindrical [Axis = axis1 axis2[ axis3] | Center =
    // center1 center2[ center3] | Angle = angle]`
    assert_eq!(
        transform("Periodicity For lo Cylindrical Axis = 0 0 1 Center = 0 0 0 Angle = 90"),
        PeriodicTransform::Cylindrical {
            axis: vec![0.0, 0.0, 1.0],
            center: vec![0.0, 0.0, 0.0],
            angle: 90.0
        }
    );
    // The manual gives no default for any of the three: a missing one is named.
    assert_eq!(
        refusal(&in_definition(
            "Periodicity For lo Cylindrical Axis = 0 0 1 Center = 0 0 0"
        )),
        [(
            "E0214",
            "the `cylindrical` periodicity needs `angle = …`".to_string()
        )]
    );
    let (_, d) = parse(&in_definition("Periodicity For lo Cylindrical Angle = 30"));
    assert_eq!(
        diags(&d),
        [
            (
                "E0214",
                "the `cylindrical` periodicity needs `axis = …`".to_string()
            ),
            (
                "E0214",
                "the `cylindrical` periodicity needs `center = …`".to_string()
            ),
        ]
    );
    assert!(
        d.0[0]
            .help
            .as_deref()
            .is_some_and(|h| h.contains("axis = <a1> <a2> [<a3>]"))
    );
}

#[test]
fn mapped_periodicity_defaults_to_the_identity() {
    // `Periodicity For surface Mapped [X_Map = x_map | Y_Map = y_map | Z_Map = z_map]`:
    // "Functions that are not specified default to a trivial mapping e.g. y->y".
    assert_eq!(
        transform(r#"Periodicity For lo Mapped X_Map = "x + 1""#),
        PeriodicTransform::Mapped {
            x_map: "x + 1".into(),
            y_map: "y".into(),
            z_map: None
        }
    );
    assert_eq!(
        transform(r#"Periodicity For lo Mapped Y_Map = "y - 2" Z_Map = "2*z""#),
        PeriodicTransform::Mapped {
            x_map: "x".into(),
            y_map: "y - 2".into(),
            z_map: Some("2*z".into())
        }
    );
}

#[test]
fn restrict_skin_update_visualize() {
    // `Restrict Contact To Subdomain Defined By Radius r And Point VecX VecY VecZ`
    let def =
        definition_line("Restrict Contact To Subdomain Defined By Radius 2.5 And Point 1 2 3");
    assert_eq!(
        def.restrict_contact_to_subdomain,
        Some(Subdomain {
            radius: 2.5,
            point: [1.0, 2.0, 3.0]
        })
    );
    // `Skin All Blocks [ Exclude Blocks_to_exlude… ]`
    let skin = |exclude: &[&str]| SurfaceDef::SkinAllBlocks {
        exclude: strings(exclude),
        at: Default::default(),
    };
    assert_eq!(surfaces(&definition_line("Skin All Blocks")), [skin(&[])]);
    assert_eq!(
        surfaces(&definition_line("Skin All Blocks Exclude block_3 block_4")),
        [skin(&["block_3", "block_4"])]
    );
    // `Update Search Every n Steps`
    let def = definition_line("Update Search Every 5 Steps");
    assert_eq!(def.update_search_every_n_steps, Some(5));
    // `Visualize Contact`
    assert!(definition_line("Visualize Contact").visualize_contact);
}

// ----- Aria 7.22.2–7.22.4: Interaction, Interaction Defaults, Search Options -----

#[test]
fn interaction_lines() {
    // `Normal Tolerance Distance`, `Side A Side a…`, `Side B Side b…`,
    // `Surfaces Surfaces…`
    let def = clean(&in_definition(
        "  begin Interaction i1\n    Normal Tolerance 0.01\n    Side A surface_1\n    Side B surface_2 surface_3\n    Surfaces surface_4 surface_5\n  end Interaction i1",
    ));
    let i = &def.interactions[0];
    assert_eq!(i.name.as_deref(), Some("i1"));
    assert_eq!(i.normal_tolerance, Some(0.01));
    assert_eq!(i.side_a, strings(&["surface_1"]));
    assert_eq!(i.side_b, strings(&["surface_2", "surface_3"]));
    assert_eq!(i.surfaces, strings(&["surface_4", "surface_5"]));
}

#[test]
fn interaction_defaults_lines() {
    // `General Contact`, `Self Contact`, `Surfaces Surfaces…`: a switch written alone
    // is on.
    let def = clean(&in_definition(
        "  begin Interaction Defaults\n    General Contact\n    Self Contact\n    Surfaces surface_1 surface_2\n  end Interaction Defaults",
    ));
    let x = def.interaction_defaults.expect("interaction defaults");
    assert_eq!(x.general_contact, Some(true));
    assert_eq!(x.self_contact, Some(true));
    assert_eq!(x.surfaces, strings(&["surface_1", "surface_2"]));
    let def = clean(&in_definition(
        "  begin Interaction Defaults\n    General Contact = off\n    Self Contact is off\n  end Interaction Defaults",
    ));
    let x = def.interaction_defaults.expect("interaction defaults");
    assert_eq!(
        (x.general_contact, x.self_contact),
        (Some(false), Some(false))
    );
}

#[test]
fn search_options_line() {
    // `Normal Tolerance Distance`
    let def = clean(&in_definition(
        "  begin Search Options so\n    Normal Tolerance 0.002\n  end Search Options so",
    ));
    let so = def.search_options.expect("search options");
    assert_eq!(so.name.as_deref(), Some("so"));
    assert_eq!(so.normal_tolerance, Some(0.002));
}

// ----- Aria 7.22.5: Enforcement -----

#[test]
fn enforcement_line_commands() {
    // `Dash Penalty Factor value`
    assert_eq!(
        enforcement_line("Dash Penalty Factor 10").dash_penalty_factor,
        Some(10.0)
    );
    // `Integer Data Values…`, `Real Data Values…`
    let e = enforcement_line("Integer Data 1 2 3\nReal Data 1.5 2e3");
    assert_eq!(e.integer_data, [1, 2, 3]);
    assert_eq!(e.real_data, [1.5, 2000.0]);
    // `Side B Variable b_field To a_field`
    let e = enforcement_line("Side B Variable temperature To temperature");
    assert_eq!(
        e.side_b_variable,
        Some(VariableMap {
            side_b: "temperature".into(),
            side_a: "temperature".into()
        })
    );
    // `Use Toggle Block ToggleName [ ElementBlockList… ]`
    let e = enforcement_line("Use Toggle Block tog");
    assert_eq!(e.use_toggle_block.as_deref(), Some("tog"));
    assert!(e.toggle_element_blocks.is_empty());
    let e = enforcement_line("Use Toggle Block tog block_1 block_2");
    assert_eq!(e.use_toggle_block.as_deref(), Some("tog"));
    assert_eq!(e.toggle_element_blocks, strings(&["block_1", "block_2"]));
}

#[test]
fn slave_variable_is_read_with_a_deprecation_warning() {
    // `Slave Variable Slave_field To Master_field`
    let (deck, d) = parse(&in_enforcement("Slave Variable temperature To temperature"));
    assert_eq!(
        diags(&d),
        [(
            "W0101",
            "`slave variable` is a deprecated name for `side b variable`".to_string()
        )]
    );
    assert_eq!(
        deck.contact_definitions[0].enforcements[0]
            .side_b_variable
            .as_ref()
            .map(|m| m.side_b.as_str()),
        Some("temperature")
    );
}

#[test]
fn enforcement_for_with_and_without_the_separator() {
    let model = |line: &str| {
        let e = enforcement_line(line);
        assert_eq!(e.models.len(), 1, "{line}");
        let m = e.models[0].clone();
        let args: Vec<(String, String)> = m.args.into_iter().map(|a| (a.key, a.value)).collect();
        (m.equation, m.model, args)
    };
    // `Enforcement For EquationName EnforcementModel [ ModelParams… ]`
    assert_eq!(
        model("Enforcement For Energy Gap_Conductance"),
        ("energy".into(), "gap_conductance".into(), vec![])
    );
    assert_eq!(
        model("Enforcement For Energy Contact_Resistance H = 100"),
        (
            "energy".into(),
            "contact_resistance".into(),
            vec![("h".into(), "100".into())]
        )
    );
    // `Enforcement for [EQ] = [MODEL] [MODEL ARGS...]`
    assert_eq!(
        model("Enforcement for Energy = Tied_Temperature"),
        ("energy".into(), "tied_temperature".into(), vec![])
    );
}

#[test]
fn equations_of_arias_list_other_than_energy_are_refused() {
    for eq in [
        "Continuity",
        "Current",
        "Cvfem_Continuity",
        "Cvfem_Lumped_Projection",
        "Cvfem_Momentum",
        "Cvfem_Projection",
        "Cvfem_Specific_Dissipation_Rate",
        "Cvfem_Turbulent_Kinetic_Energy",
        "Mass_Balance",
        "Mesh",
        "Momentum",
        "Porous_Enthalpy",
        "Porous_Species",
    ] {
        let lower = eq.to_lowercase();
        let text = in_enforcement(&format!("Enforcement For {eq} = Tied"));
        let (deck, d) = parse(&text);
        assert_eq!(
            diags(&d),
            [(
                "E0219",
                format!(
                    "enforcement `gap`: `enforcement for {lower}`: seam does not solve the {lower} equation"
                )
            )],
            "{eq}"
        );
        assert!(
            d.0[0]
                .help
                .as_deref()
                .is_some_and(|h| h.starts_with("seam solves Energy, Voltage and Species only")),
            "{eq}"
        );
        // The spec still carries the line.
        assert_eq!(
            deck.contact_definitions[0].enforcements[0].models[0].equation,
            lower
        );
    }
    assert_eq!(
        refusal(&in_enforcement("Enforcement For Cvfem_Energy = Tied"))[0].0,
        "E0219"
    );
}

#[test]
fn unknown_and_repeated_equations_are_errors() {
    let (_, d) = parse(&in_enforcement("Enforcement For Enrgy = Gap_Conductance"));
    assert_eq!(
        diags(&d),
        [(
            "E0220",
            "enforcement `gap`: unknown equation `enrgy` in `enforcement for`".to_string()
        )]
    );
    assert!(
        d.0[0]
            .help
            .as_deref()
            .is_some_and(|h| h.starts_with("did you mean `energy`?"))
    );
    let (_, d) = parse(&in_enforcement(
        "    Enforcement For Energy = Gap_Conductance H = 5\n    Enforcement For Energy = Contact_Resistance H = 6",
    ));
    assert_eq!(
        diags(&d),
        [(
            "E0221",
            "enforcement `gap`: a second `enforcement for energy` line in one block".to_string()
        )]
    );
    let loc = d.0[0].loc.clone().expect("located");
    assert_eq!((loc.line, loc.col), (4, 21));
    assert!(
        d.0[0]
            .help
            .as_deref()
            .is_some_and(|h| h.starts_with("the first is on line 3"))
    );
}

#[test]
fn model_keys_are_checked_where_the_deck_knows_them() {
    assert_eq!(
        refusal(&in_enforcement(
            "Enforcement For Energy = Gap_Conductance Hh = 5"
        )),
        [(
            "E0223",
            "enforcement `gap`: `hh` is not an argument of the `gap_conductance` model".to_string()
        )]
    );
    assert_eq!(
        refusal(&in_enforcement(
            "Enforcement For Energy = Tied Multiplier = dual"
        )),
        [(
            "E0223",
            "enforcement `gap`: `multiplier` is not an argument of the `tied` model".to_string()
        )]
    );
    // Plugin arguments are the plugin reader's business.
    let e = enforcement_line(r#"Enforcement For Energy = Plugin Library = "lib.so" Model = m"#);
    assert_eq!(e.models[0].args.len(), 2);
}

#[test]
fn material_models_that_seam_lowers() {
    // Gap Conductance Coefficient: a property line, read by the conductance module.
    let e = enforcement_line("Gap Conductance Coefficient = Constant H = 10");
    assert_eq!(e.properties.len(), 1);
    assert_eq!(e.properties[0].property, "gap_conductance_coefficient");
    assert_eq!(e.properties[0].model, "constant");
    assert_eq!(
        (
            e.properties[0].args[0].key.as_str(),
            e.properties[0].args[0].value.as_str()
        ),
        ("h", "10")
    );
    // Contact Surface Pressure: the same field as `Contact Pressure`.
    for line in [
        "Contact Surface Pressure = Constant Value = 5e5",
        "Contact Surface Pressure = Constant 5e5",
        "Contact Surface Pressure = 5e5",
        "Contact Pressure = 5e5",
    ] {
        let e = enforcement_line(line);
        assert_eq!(e.contact_pressure, Some(5e5), "{line}");
        assert!(e.properties.is_empty(), "{line}");
    }
    // Offset Temperature.
    for line in [
        "Offset Temperature = Constant Value = 2.5",
        "Offset Temperature = 2.5",
    ] {
        assert_eq!(
            enforcement_line(line).offset_temperature,
            Some(2.5),
            "{line}"
        );
    }
    // Contact Gap Temperature.
    for (line, want) in [
        ("Contact Gap Temperature = Side_A", GapTemperature::SideA),
        ("Contact Gap Temperature = Side A", GapTemperature::SideA),
        ("Contact Gap Temperature = side_b", GapTemperature::SideB),
        ("Contact Gap Temperature = Mean", GapTemperature::Mean),
        ("Contact Gap Temperature = Average", GapTemperature::Mean),
        ("Contact Gap Temperature = avg", GapTemperature::Mean),
        (
            "Contact Gap Temperature = Constant Value = 350",
            GapTemperature::Constant(350.0),
        ),
        (
            "Contact Gap Temperature = 350",
            GapTemperature::Constant(350.0),
        ),
    ] {
        assert_eq!(
            enforcement_line(line).contact_gap_temperature,
            Some(want),
            "{line}"
        );
    }
    // Contact Gap Voltage: the same choices, for the voltage.
    for (line, want) in [
        ("Contact Gap Voltage = Side_B", GapTemperature::SideB),
        ("Contact Gap Voltage = mean", GapTemperature::Mean),
        (
            "Contact Gap Voltage = Constant Value = 1",
            GapTemperature::Constant(1.0),
        ),
    ] {
        let e = enforcement_line(line);
        assert_eq!(e.contact_gap_voltage, Some(want), "{line}");
        assert_eq!(e.contact_gap_temperature, None, "{line}");
    }
    assert_eq!(
        refusal(&in_enforcement("Contact Gap Voltage = sidea")),
        [("E0217", "unknown contact gap voltage `sidea`".to_string())]
    );
    assert_eq!(
        refusal(&in_enforcement("Contact Gap Temperature = Sid_B")),
        [(
            "E0217",
            "unknown contact gap temperature `sid b`".to_string()
        )]
    );
}

#[test]
fn contact_pressure_given_twice_ways_is_an_error() {
    let (deck, d) = parse(&in_enforcement(
        "    Contact Pressure = 3\n    Contact Surface Pressure = Constant Value = 5e5",
    ));
    assert_eq!(
        diags(&d),
        [(
            "E0222",
            "`contact surface pressure` and `contact pressure` in one enforcement block"
                .to_string()
        )]
    );
    assert_eq!(
        deck.contact_definitions[0].enforcements[0].contact_pressure,
        Some(3.0)
    );
}

#[test]
fn material_models_that_seam_refuses() {
    for (line, phrase, why) in [
        (
            "Offset Darcy Potential = Constant Value = 1",
            "offset darcy potential",
            "porous flow",
        ),
        (
            "Offset Mesh Displacements = Constant Value = 1",
            "offset mesh displacements",
            "mesh motion",
        ),
        (
            "Offset Pressure = Constant Value = 1",
            "offset pressure",
            "fluid flow",
        ),
        (
            "Offset Solid Displacements = Constant Value = 1",
            "offset solid displacements",
            "solid mechanics",
        ),
        (
            "Offset Velocity = Constant Value = 1",
            "offset velocity",
            "fluid flow",
        ),
        (
            r#"User Expression = "h * 2""#,
            "user expression",
            "Aria's expression system",
        ),
    ] {
        let (_, d) = parse(&in_enforcement(line));
        let got = diags(&d);
        assert_eq!(got.len(), 1, "{line}: {got:?}");
        assert_eq!(got[0].0, "E0218", "{line}");
        assert!(
            got[0].1.starts_with(&format!(
                "enforcement `gap`: seam cannot use the material model `{phrase}`: it needs {why}"
            )),
            "{line}: {}",
            got[0].1
        );
        let loc = d.0[0].loc.clone().expect("located");
        assert_eq!(loc.line, 3, "{line}");
        assert!(
            d.0[0]
                .help
                .as_deref()
                .is_some_and(|h| h.contains("gap conductance coefficient")),
            "{line}"
        );
    }
}

#[test]
fn a_misspelt_property_line_is_an_error_next_to_a_correct_one() {
    let (deck, d) = parse(&in_enforcement(
        "    gap conductance coefficient = constant h = 10\n    gap conductence coefficient = constant h = 5",
    ));
    assert_eq!(
        diags(&d),
        [(
            "E0103",
            "unknown keyword `gap conductence coefficient` in `begin enforcement`".to_string()
        )]
    );
    assert!(
        d.0[0]
            .help
            .as_deref()
            .is_some_and(|h| h.starts_with("did you mean `gap conductance coefficient`?"))
    );
    assert_eq!(
        deck.contact_definitions[0].enforcements[0].properties.len(),
        1
    );
}

#[test]
fn several_enforcement_blocks_are_all_kept() {
    let def = clean(&in_definition(
        "  begin Enforcement a\n    Enforcement For Energy Gap_Conductance H = 1\n  end\n  begin Enforcement b\n    Enforcement For Energy Tied_Temperature\n  end\n  begin Enforcement c\n    Enforcement For Energy Contact_Resistance H = 2\n  end",
    ));
    let names: Vec<Option<&str>> = def.enforcements.iter().map(|e| e.name.as_deref()).collect();
    assert_eq!(names, [Some("a"), Some("b"), Some("c")]);
    assert_eq!(def.enforcements[1].models[0].model, "tied_temperature");
}

// ----- Sierra/SM 8.4 and 11.3: contact surfaces -----

#[test]
fn contact_surface_and_node_set_command_lines() {
    // 8.4.1 `CONTACT SURFACE <string>name CONTAINS <string list>surface_names`
    let def = definition_line("CONTACT SURFACE c3 CONTAINS surface_3");
    assert_eq!(surfaces(&def), [contains("c3", &["surface_3"])]);
    // 8.4.2 `CONTACT NODE SET <string>surface_name CONTAINS <string list>nodelist_names`
    let def = definition_line("CONTACT NODE SET tips CONTAINS nodelist_1 nodelist_2");
    assert_eq!(
        surfaces(&def),
        [SurfaceDef::NodeSet {
            name: "tips".into(),
            contains: strings(&["nodelist_1", "nodelist_2"]),
            at: Default::default()
        }]
    );
}

#[test]
fn contact_surface_command_block() {
    // 8.4.3, every line of the block.
    let def = definition_line(
        "BEGIN CONTACT SURFACE outer\nINCLUDE ALL BLOCKS\nBLOCK = block_1 block_2\nELEMENT = 10 11\nSURFACE = surface_1\nASSEMBLY = asm_1\nREMOVE BLOCK = block_3\nREMOVE SURFACE = surface_9\nSUBSET top WITH NORMAL 0 0 1\nEND CONTACT SURFACE outer",
    );
    let s = surfaces(&def);
    let [SurfaceDef::Block(b)] = s.as_slice() else {
        panic!("expected one contact surface block")
    };
    assert_eq!(b.name, "outer");
    assert!(b.include_all_blocks);
    assert_eq!(b.blocks, strings(&["block_1", "block_2"]));
    assert_eq!(b.elements, [10, 11]);
    assert_eq!(b.side_sets, strings(&["surface_1"]));
    assert_eq!(b.assemblies, strings(&["asm_1"]));
    assert_eq!(b.remove_blocks, strings(&["block_3"]));
    assert_eq!(b.remove_surfaces, strings(&["surface_9"]));
    assert_eq!(b.subsets.len(), 1);
    assert_eq!(
        (b.subsets[0].name.as_str(), b.subsets[0].normal),
        ("top", [0.0, 0.0, 1.0])
    );
}

#[test]
fn subset_example() {
    // 8.4.4.1
    let def = definition_line(
        "BEGIN CONTACT SURFACE surf1\nBLOCK = block_1\nSUBSET xp WITH NORMAL 1 0 0\nSUBSET zm WITH NORMAL 0 0 -1\nEND",
    );
    let s = surfaces(&def);
    let [SurfaceDef::Block(b)] = s.as_slice() else {
        panic!("expected one contact surface block")
    };
    let subsets: Vec<(&str, [f64; 3])> = b
        .subsets
        .iter()
        .map(|s| (s.name.as_str(), s.normal))
        .collect();
    assert_eq!(subsets, [("xp", [1.0, 0.0, 0.0]), ("zm", [0.0, 0.0, -1.0])]);
}

#[test]
fn auto_subset_example_and_its_forbidden_mix() {
    // 11.3
    let def = definition_line(
        "BEGIN CONTACT SURFACE surf1\n  BLOCK = block_1\n  AUTO SUBSET sub1 NUMBER OF SUBSETS 6 ANGLE 45.0\nEND",
    );
    let s = surfaces(&def);
    let [SurfaceDef::Block(b)] = s.as_slice() else {
        panic!("expected one contact surface block")
    };
    let a = b.auto_subset.clone().expect("auto subset");
    assert_eq!(
        (a.name.as_str(), a.number_of_subsets, a.angle),
        ("sub1", Some(6), Some(45.0))
    );
    // `AUTO SUBSET <string>subname [NUMBER OF SUBSETS <integer>] [ANGLE <real>(60)]`:
    // left out, both stay unset (the surface module applies 60 degrees and 360/angle).
    let def =
        definition_line("BEGIN CONTACT SURFACE surf1\n  BLOCK = block_1\n  AUTO SUBSET sub1\nEND");
    let s = surfaces(&def);
    let [SurfaceDef::Block(b)] = s.as_slice() else {
        panic!("expected one contact surface block")
    };
    let a = b.auto_subset.clone().expect("auto subset");
    assert_eq!((a.number_of_subsets, a.angle), (None, None));
    // "the following is not permitted"
    assert_eq!(
        refusal(&in_definition(
            "BEGIN CONTACT SURFACE surf1\n  BLOCK = block_1\n  SUBSET sub1 WITH NORMAL  1  0  0\n  AUTO SUBSET sub2 NUMBER OF SUBSETS 6 ANGLE 45.0\nEND"
        )),
        [(
            "E0204",
            "contact surface `surf1` has both `subset` and `auto subset`".to_string()
        )]
    );
}

#[test]
fn contact_type_standard_is_face_and_smooth_is_refused() {
    // 11.3 `CONTACT TYPE = STANDARD | SMOOTH (STANDARD)`
    let def = definition_line(
        "BEGIN CONTACT SURFACE s\n  BLOCK = block_1\n  CONTACT TYPE = STANDARD\nEND",
    );
    let s = surfaces(&def);
    let [SurfaceDef::Block(b)] = s.as_slice() else {
        panic!("expected one contact surface block")
    };
    assert_eq!(b.contact_type, ContactType::Face);
    assert_eq!(
        refusal(&in_definition(
            "BEGIN CONTACT SURFACE s\n  BLOCK = block_1\n  CONTACT TYPE = SMOOTH\nEND"
        )),
        [(
            "E0213",
            "seam does not smooth contact surfaces (`contact type = smooth`)".to_string()
        )]
    );
}

#[test]
fn skin_all_blocks_examples() {
    // 8.4.5 `SKIN ALL BLOCKS = <string>ON|OFF(OFF) [EXCLUDE <string list>block_names]`
    let def = definition_line("SKIN ALL BLOCKS = ON EXCLUDE block_2");
    assert_eq!(
        surfaces(&def),
        [SurfaceDef::SkinAllBlocks {
            exclude: strings(&["block_2"]),
            at: Default::default()
        }]
    );
    assert!(surfaces(&definition_line("SKIN ALL BLOCKS = OFF")).is_empty());
    // 8.4.8.3
    let def = definition_line("SKIN ALL BLOCKS = ON EXCLUDE block_3");
    assert_eq!(
        surfaces(&def),
        [SurfaceDef::SkinAllBlocks {
            exclude: strings(&["block_3"]),
            at: Default::default()
        }]
    );
}

#[test]
fn surface_order_examples_keep_deck_order() {
    // 8.4.6 example 2, contact surface definition 1, and the equivalent with skinning.
    let def = definition_line(
        "contact surface surfD contains surface_4\ncontact surface surfB contains surface_2\ncontact surface surfA contains block_1\ncontact surface surfC contains block_2",
    );
    assert_eq!(
        surfaces(&def),
        [
            contains("surfd", &["surface_4"]),
            contains("surfb", &["surface_2"]),
            contains("surfa", &["block_1"]),
            contains("surfc", &["block_2"]),
        ]
    );
    let def = definition_line(
        "contact surface surfB contains surface_2\nskin all blocks = on\ncontact surface surfD contains surface_4",
    );
    assert_eq!(
        surfaces(&def),
        [
            contains("surfb", &["surface_2"]),
            SurfaceDef::SkinAllBlocks {
                exclude: vec![],
                at: Default::default()
            },
            contains("surfd", &["surface_4"]),
        ]
    );
    // 8.4.6 example 1
    let def = definition_line(
        "contact surface surfB contains surface_2\ncontact surface surfA contains block_1",
    );
    assert_eq!(
        surfaces(&def),
        [
            contains("surfb", &["surface_2"]),
            contains("surfa", &["block_1"]),
        ]
    );
    // 8.4.8.1, 8.4.8.2 and 8.4.8.5
    let def = definition_line("CONTACT SURFACE block_1 CONTAINS block_1");
    assert_eq!(surfaces(&def), [contains("block_1", &["block_1"])]);
    let def = definition_line(
        "CONTACT SURFACE block_1 CONTAINS block_1\nCONTACT SURFACE block_2 CONTAINS block_2",
    );
    assert_eq!(
        surfaces(&def),
        [
            contains("block_1", &["block_1"]),
            contains("block_2", &["block_2"]),
        ]
    );
    let def =
        definition_line("CONTACT SURFACE c1 CONTAINS block_1\nCONTACT SURFACE c2 CONTAINS block_2");
    assert_eq!(
        surfaces(&def),
        [contains("c1", &["block_1"]), contains("c2", &["block_2"])]
    );
    // 8.4.8.4
    let def = definition_line(
        "CONTACT SURFACE c1 CONTAINS block_1\nCONTACT SURFACE c3 CONTAINS surface_3\nCONTACT SURFACE c2 CONTAINS block_2",
    );
    assert_eq!(
        surfaces(&def),
        [
            contains("c1", &["block_1"]),
            contains("c3", &["surface_3"]),
            contains("c2", &["block_2"]),
        ]
    );
    // 8.4.8.6
    let def = definition_line("CONTACT SURFACE surf_1 CONTAINS surface_1\nSKIN ALL BLOCKS = ON");
    assert_eq!(surfaces(&def).len(), 2);
    // 8.4.4
    let def = definition_line(
        "SKIN ALL BLOCKS = ON\nRESTRICT CONTACT TO SUBDOMAIN DEFINED BY RADIUS 0.5 AND POINT 0 0 0",
    );
    assert_eq!(
        def.restrict_contact_to_subdomain,
        Some(Subdomain {
            radius: 0.5,
            point: [0.0, 0.0, 0.0]
        })
    );
}

// ----- ELFEN contact-set parameters (Contact_set) -----

#[test]
fn elfen_parameter_names_are_aliases() {
    let def = clean(&in_definition(
        "  begin Search Options\n    Buffer_factor = 1.0\n    Field_factor = 0.2\n    Normal_dir_chk_angle = 80\n    Global_update_frequency = 10\n    Self_contact_flag = 1\n  end",
    ));
    let so = def.search_options.expect("search options");
    assert_eq!(so.buffer_factor, Some(1.0));
    assert_eq!(so.field_factor, Some(0.2));
    assert_eq!(so.normal_check_angle, Some(80.0));
    assert_eq!(so.search_update_frequency, Some(10));
    assert_eq!(so.self_contact, Some(true));
}

#[test]
fn elfen_parameters_without_a_counterpart_are_refused() {
    for name in [
        "Corner_projection_size",
        "Corner_region_size",
        "Corner_angle_tolerance",
        "Contactor_corner_model",
        "Trigger_search_velocity",
        "Print_search",
        "Edge_search_frequency",
        "Thermal_advection_flag",
        "Memory_optimisation_flag",
    ] {
        let text = in_definition(&format!("  begin Search Options\n    {name} = 1\n  end"));
        assert_eq!(
            refusal(&text),
            [(
                "E0224",
                format!("`{name}` is an ELFEN contact-set parameter with no counterpart in seam")
            )],
            "{name}"
        );
    }
}

// ----- A whole Sierra input file -----

const SIERRA_FILE: &str = "\
Begin Sierra thermal
  Title two blocks in contact
  Begin Finite Element Model mesh1
    Database Name = two_blocks.exo
  End
  Begin Aria Material steel
    Density = Constant rho = 7800
  End
  Begin Procedure AriaProcedure
    Begin Solution Control Description
      Use System Main
    End
    Begin Aria Region region_1
      Use Finite Element Model mesh1
      Begin Contact Definition cd1
        Contact Surface surface_1
        Contact Surface surface_2
        Begin Enforcement gap
          Enforcement For Energy Gap_Conductance
          Gap Conductance Coefficient = Constant H = 1000
        End
        Begin Interaction pair
          Side A surface_1
          Side B surface_2
          Enforcement = gap
        End
      End Contact Definition cd1
      Begin Contact Definition cd2
        Periodicity For lo Rectangular Offset = 1 0 0
      End
    End Aria Region region_1
  End Procedure AriaProcedure
End Sierra thermal
";

#[test]
fn a_sierra_input_file_gives_its_contact_definitions_and_one_note() {
    let (deck, d) = parse(SIERRA_FILE);
    assert_eq!(
        diags(&d),
        [(
            "W0103",
            "read 2 contact definitions from a Sierra input file; skipped 3 blocks: finite element model mesh1, aria material steel, solution control description, and 2 lines outside them".to_string()
        )]
    );
    let loc = d.0[0].loc.clone().expect("located");
    assert_eq!((loc.line, loc.col), (1, 1));
    let names: Vec<Option<&str>> = deck
        .contact_definitions
        .iter()
        .map(|c| c.name.as_deref())
        .collect();
    assert_eq!(names, [Some("cd1"), Some("cd2")]);
    let cd1 = &deck.contact_definitions[0];
    assert_eq!(
        surfaces(cd1),
        [
            contains("surface_1", &["surface_1"]),
            contains("surface_2", &["surface_2"]),
        ]
    );
    assert_eq!(cd1.interactions[0].enforcement.as_deref(), Some("gap"));
    assert_eq!(deck.contact_definitions[1].periodicity.len(), 1);
}

#[test]
fn a_sierra_input_file_keeps_contact_definitions_strict() {
    let text = SIERRA_FILE.replace(
        "Gap Conductance Coefficient = Constant H = 1000",
        "Gap Conductance Coefficient = Constant H = 1000\n          gap conductence coefficient = constant h = 5",
    );
    let (_, d) = parse(&text);
    let codes: Vec<&str> = d.0.iter().map(|x| x.code).collect();
    assert_eq!(codes, ["W0103", "E0103"]);
    // A misspelt contact definition is reported, not skipped.
    let text = SIERRA_FILE.replace(
        "Begin Contact Definition cd2",
        "Begin Contact Defintion cd2",
    );
    let (deck, d) = parse(&text);
    assert!(d.0.iter().any(|x| x.code == "E0105"), "{:?}", diags(&d));
    assert_eq!(deck.contact_definitions.len(), 1);
}

#[test]
fn a_sierra_input_file_may_hold_what_a_contact_deck_may_not() {
    // An unclosed quote on a skipped line ends at its line; block structure still counts.
    let text = SIERRA_FILE.replace(
        "Database Name = two_blocks.exo",
        "Database Name = \"two_blocks.exo",
    );
    let codes: Vec<&str> = parse(&text).1.0.iter().map(|x| x.code).collect();
    assert_eq!(codes, ["W0103"]);
    let text = SIERRA_FILE.replace("  End Procedure AriaProcedure\n", "");
    let codes: Vec<&str> = parse(&text).1.0.iter().map(|x| x.code).collect();
    assert_eq!(codes, ["E0101", "W0103"]);
}

#[test]
fn a_toggle_block_that_an_enforcement_uses_is_refused() {
    let text = SIERRA_FILE
        .replace(
            "  Begin Procedure AriaProcedure",
            "  Begin Toggle Block tog\n    Add Interval int_1\n  End\n  Begin Procedure AriaProcedure",
        )
        .replace(
            "Enforcement For Energy Gap_Conductance",
            "Enforcement For Energy Gap_Conductance\n          Use Toggle Block tog",
        );
    let (_, d) = parse(&text);
    let got = diags(&d);
    assert_eq!(got.len(), 2, "{got:?}");
    assert_eq!(
        got[0],
        (
            "W0103",
            "read 2 contact definitions from a Sierra input file; skipped 4 blocks: finite element model mesh1, aria material steel, toggle block tog, solution control description, and 2 lines outside them".to_string()
        )
    );
    assert_eq!(
        got[1],
        (
            "E0226",
            "toggle block `tog` (line 9) is used here, but seam cannot read a toggle block's schedule".to_string()
        )
    );
    // Unused, it is only skipped.
    let text = SIERRA_FILE.replace(
        "  Begin Procedure AriaProcedure",
        "  Begin Toggle Block tog\n  End\n  Begin Procedure AriaProcedure",
    );
    let codes: Vec<&str> = parse(&text).1.0.iter().map(|x| x.code).collect();
    assert_eq!(codes, ["W0103"]);
}

#[test]
fn a_contact_deck_stays_strict_at_the_top_level() {
    let (_, d) = parse("Title a deck\nbegin contact definition\n  contact surface s\nend\n");
    assert_eq!(
        diags(&d),
        [("E0109", "this line is outside every block".to_string())]
    );
    let (_, d) = parse("begin toggle block tog\nend\nbegin contact definition\nend\n");
    assert_eq!(
        diags(&d),
        [(
            "E0226",
            "seam cannot read the schedule of `begin toggle block tog`".to_string()
        )]
    );
}

// ----- The TOML twin -----

#[test]
fn toml_carries_the_new_fields_and_shares_the_checks() {
    let text = r#"
[[contact_definition]]
[[contact_definition.enforcement]]
name = "gap"
contact_gap_temperature = "side_b"
use_toggle_block = "tog"
toggle_element_blocks = ["block_1"]
[[contact_definition.enforcement.model]]
equation = "energy"
model = "gap_conductance"
args = [{ key = "h", value = "5" }]
[[contact_definition.enforcement.model]]
equation = "porous_species"
model = "tied"
[[contact_definition.enforcement.property]]
property = "offset_velocity"
model = "constant"
[[contact_definition.enforcement.property]]
property = "gap_conductence_coefficient"
model = "constant"
[[contact_definition.periodicity]]
surface = "lo"
transform = { kind = "mapped", z_map = "z + 1" }
"#;
    let (deck, d) = seam::deck::parse_toml(&Arc::from("deck.toml"), text);
    let e = &deck.contact_definitions[0].enforcements[0];
    assert_eq!(e.contact_gap_temperature, Some(GapTemperature::SideB));
    assert_eq!(e.toggle_element_blocks, strings(&["block_1"]));
    assert_eq!(
        deck.contact_definitions[0].periodicity[0].transform,
        PeriodicTransform::Mapped {
            x_map: "x".into(),
            y_map: "y".into(),
            z_map: Some("z + 1".into())
        }
    );
    let codes: Vec<&str> = d.0.iter().map(|x| x.code).collect();
    assert_eq!(codes, ["E0219", "E0218", "E0225"], "{:?}", diags(&d));
    assert_eq!(
        d.0[2].message,
        "enforcement `gap`: unknown material property `gap_conductence_coefficient`"
    );
    assert!(
        d.0[2]
            .help
            .as_deref()
            .is_some_and(|h| h.starts_with("did you mean `gap_conductance_coefficient`?"))
    );
}

/// `Enforcement For Voltage` and `Offset Voltage` are read: the equation seam solves
/// beside Energy, and the jump of its contact.
#[test]
fn voltage_enforcements_are_read() {
    let text = in_enforcement(
        "Enforcement For Voltage = Gap_Conductance\n    Offset Voltage = Constant Value = 0.25\n    Joule Heat Fraction Side A = 0.3",
    );
    let (deck, d) = parse(&text);
    assert!(diags(&d).is_empty(), "{:?}", diags(&d));
    let e = &deck.contact_definitions[0].enforcements[0];
    assert_eq!(e.models[0].equation, "voltage");
    assert_eq!(e.offset_voltage, Some(0.25));
    assert_eq!(e.joule_fraction_side_a, Some(0.3));
    let (_, d) = parse(&in_enforcement(
        "Enforcement For Voltage = Gap_Conductance\n    Joule Heat Fraction Side A = 1.5",
    ));
    assert_eq!(diags(&d).len(), 1, "{:?}", diags(&d));
    assert_eq!(diags(&d)[0].0, "E0227");
}

/// `Enforcement For Species`, `Partition Coefficient` and `Offset Species` are read:
/// the species interface and its jump c_A = K c_B + Δc.
#[test]
fn species_enforcements_are_read() {
    let text = in_enforcement(
        "Enforcement For Species = Tied_Species\n    Partition Coefficient = 2.5\n    Offset Species = Constant Value = 0.25",
    );
    let (deck, d) = parse(&text);
    assert!(diags(&d).is_empty(), "{:?}", diags(&d));
    let e = &deck.contact_definitions[0].enforcements[0];
    assert_eq!(e.models[0].equation, "species");
    assert_eq!(e.partition_coefficient, Some(2.5));
    assert_eq!(e.offset_species, Some(0.25));
}
