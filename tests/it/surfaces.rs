//! Contact surfaces by the Sierra rules, on small meshes built for each situation.
//! Expected counts come from the geometry of the mesh (faces of a box, of a shared
//! interface), not from the code under test.

use std::collections::HashSet;

use proptest::prelude::*;
use seam::deck::spec::{
    AutoSubset, ContactDefinition, ContactType, Subdomain, Subset, SurfaceBlock, SurfaceDef,
};
use seam::diag::{Loc, SourceMap};
use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{ElemId, Mesh, NodeId, NodeSet, Side, SideSet, Topology};
use seam::scene::surfaces;
use seam::surface::{SurfaceKind, SurfaceSet};

fn contains(name: &str, items: &[&str]) -> SurfaceDef {
    SurfaceDef::Contains {
        name: name.into(),
        contains: items.iter().map(|s| s.to_string()).collect(),
        at: Loc::default(),
    }
}

fn skin_all(exclude: &[&str]) -> SurfaceDef {
    SurfaceDef::SkinAllBlocks {
        exclude: exclude.iter().map(|s| s.to_string()).collect(),
        at: Loc::default(),
    }
}

fn surface_block(name: &str) -> SurfaceBlock {
    SurfaceBlock {
        name: name.into(),
        ..SurfaceBlock::default()
    }
}

fn def(surfaces: Vec<SurfaceDef>) -> ContactDefinition {
    ContactDefinition {
        surfaces,
        ..ContactDefinition::default()
    }
}

fn build(mesh: &Mesh, surfaces: Vec<SurfaceDef>) -> SurfaceSet {
    surfaces::build(mesh, &def(surfaces), &SourceMap::default())
}

fn faces(set: &SurfaceSet, name: &str) -> usize {
    set.get(name)
        .unwrap_or_else(|| panic!("no surface {name}"))
        .faces
        .len()
}

fn codes(set: &SurfaceSet) -> Vec<&'static str> {
    set.diagnostics.0.iter().map(|d| d.code).collect()
}

/// Two boxes stacked in z, `[0,1]²×[0,1]` (block 1, 2×2×2 cells) and `[0,1]²×[1,2]`
/// (block 2, 2×2×2 cells), sharing the interface nodes when `merge`.
/// Side sets: 1 = bottom of block 1 (4 faces), 2 = top of block 1 (the interface, 4).
fn stack(merge: bool) -> Mesh {
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 1.0], [2, 2, 2], 1)
                .with_side_sets([0, 0, 0, 0, 1, 2]),
            BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [2, 2, 2], 2),
        ],
        merge,
    )
}

const CUBE_FACES: usize = 6 * 4; // a 2×2×2 box has 4 faces on each of its 6 sides

#[test]
fn skinning_one_block_gives_its_boundary() {
    let mesh = generate::single_box(BoxSpec::hex([0.0; 3], [1.0, 2.0, 3.0], [3, 4, 5], 1));
    let set = build(&mesh, vec![contains("all", &["block_1"])]);
    let s = set.get("all").unwrap();
    assert_eq!(s.faces.len(), 2 * (3 * 4 + 4 * 5 + 3 * 5));
    assert!((s.area(&mesh) - 2.0 * (2.0 + 6.0 + 3.0)).abs() < 1e-12);
    // Every boundary node: (4·5·6) grid minus the (2·3·4) interior nodes.
    assert_eq!(s.nodes.len(), 4 * 5 * 6 - 2 * 3 * 4);
    assert!(set.diagnostics.is_empty());
}

#[test]
fn faces_between_two_included_blocks_are_interior() {
    let mesh = stack(true);
    let set = build(
        &mesh,
        vec![contains("a", &["block_1"]), contains("b", &["block_2"])],
    );
    assert_eq!(faces(&set, "a"), CUBE_FACES - 4);
    assert_eq!(faces(&set, "b"), CUBE_FACES - 4);
}

#[test]
fn faces_against_an_excluded_block_are_exterior() {
    let mesh = stack(true);
    let set = build(&mesh, vec![contains("a", &["block_1"])]);
    assert_eq!(faces(&set, "a"), CUBE_FACES);
}

#[test]
fn parts_meshed_apart_keep_their_whole_skins() {
    let mesh = stack(false);
    let set = build(
        &mesh,
        vec![contains("a", &["block_1"]), contains("b", &["block_2"])],
    );
    assert_eq!(faces(&set, "a"), CUBE_FACES);
    assert_eq!(faces(&set, "b"), CUBE_FACES);
}

#[test]
fn side_sets_may_hold_interior_faces() {
    let mesh = stack(true);
    let set = build(
        &mesh,
        vec![skin_all(&[]), contains("iface", &["surface_2"])],
    );
    assert_eq!(faces(&set, "iface"), 4);
    assert_eq!(faces(&set, "block_1"), CUBE_FACES - 4);
    assert!(set.diagnostics.is_empty(), "{:?}", set.diagnostics);
}

#[test]
fn first_definition_owns_a_face_and_later_ones_are_warned() {
    let mesh = stack(false);
    let set = build(
        &mesh,
        vec![
            contains("bottom", &["surface_1"]),
            contains("rest", &["block_1"]),
        ],
    );
    assert_eq!(faces(&set, "bottom"), 4);
    assert_eq!(faces(&set, "rest"), CUBE_FACES - 4);
    let w = &set.diagnostics.0;
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].code, "W0301");
    assert!(
        w[0].message.contains("4 faces") && w[0].message.contains("`bottom`"),
        "{}",
        w[0].message
    );
}

/// Skin All Blocks first: it owns every skin face, so a later surface over the same
/// faces ends up empty — a warning, not an error (the documented ownership outcome).
#[test]
fn skin_all_blocks_first_leaves_a_later_surface_empty() {
    let mesh = stack(false);
    let set = build(
        &mesh,
        vec![skin_all(&[]), contains("bottom", &["surface_1"])],
    );
    assert_eq!(faces(&set, "block_1"), CUBE_FACES);
    assert_eq!(faces(&set, "bottom"), 0);
    assert_eq!(codes(&set), ["W0301", "W0302"]);
    assert!(!set.diagnostics.has_errors());
}

/// A surface defined before Skin All Blocks keeps its faces; the block surface gets the rest.
#[test]
fn surface_before_skin_all_blocks_keeps_its_faces() {
    let mesh = stack(false);
    let set = build(
        &mesh,
        vec![contains("bottom", &["surface_1"]), skin_all(&[])],
    );
    assert_eq!(faces(&set, "bottom"), 4);
    assert_eq!(faces(&set, "block_1"), CUBE_FACES - 4);
    assert_eq!(faces(&set, "block_2"), CUBE_FACES);
    assert_eq!(codes(&set), ["W0301"]);
}

#[test]
fn skin_all_blocks_names_surfaces_after_blocks_and_honours_exclude() {
    let mut mesh = stack(true);
    mesh.blocks[1].name = "Lid".into();
    let set = build(&mesh, vec![skin_all(&["lid"])]);
    let names: Vec<&str> = set.surfaces.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["block_1"]);
    // The excluded block is not included, so the shared faces are exterior to block 1.
    assert_eq!(faces(&set, "block_1"), CUBE_FACES);
}

#[test]
fn remove_block_remove_surface_include_all_blocks() {
    let mesh = stack(false);
    let mut sb = surface_block("s");
    sb.include_all_blocks = true;
    sb.remove_blocks = vec!["block_2".into()];
    sb.remove_surfaces = vec!["surface_1".into()];
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    assert_eq!(faces(&set, "s"), CUBE_FACES - 4);
}

#[test]
fn element_command_takes_exterior_faces_of_listed_elements() {
    let mesh = generate::single_box(BoxSpec::hex([0.0; 3], [2.0, 1.0, 1.0], [2, 1, 1], 1));
    let mut sb = surface_block("e");
    sb.elements = vec![1];
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    // Element 1 alone is included: all six of its sides are exterior to the definition.
    assert_eq!(faces(&set, "e"), 6);
}

#[test]
fn unknown_names_are_errors_with_suggestions() {
    let mesh = stack(false);
    let set = build(&mesh, vec![contains("a", &["blok_1", "surface_9"])]);
    let errs: Vec<_> = set.diagnostics.errors().collect();
    // Two unknown names; the surface is then empty, but that is no news: no E0303.
    assert_eq!(errs.len(), 2, "{:?}", set.diagnostics);
    assert_eq!(errs[0].code, "E0301");
    assert_eq!(errs[0].help.as_deref(), Some("did you mean `block_1`?"));
    assert!(errs[1].message.contains("surface_9"));
}

#[test]
fn empty_side_set_makes_an_empty_surface_error() {
    let mut mesh = stack(false);
    mesh.side_sets.push(SideSet {
        id: 7,
        name: String::new(),
        sides: vec![],
    });
    let set = build(&mesh, vec![contains("e", &["surface_7"])]);
    assert_eq!(codes(&set), ["E0303"]);
}

#[test]
fn node_set_surfaces_and_their_ownership() {
    let mut mesh = stack(false);
    mesh.node_sets.push(NodeSet {
        id: 3,
        name: "pins".into(),
        nodes: vec![NodeId(0), NodeId(1), NodeId(2)],
    });
    mesh.node_sets.push(NodeSet {
        id: 4,
        name: String::new(),
        nodes: vec![NodeId(2), NodeId(3)],
    });
    let set = build(
        &mesh,
        vec![
            SurfaceDef::NodeSet {
                name: "p".into(),
                contains: vec!["pins".into()],
                at: Loc::default(),
            },
            SurfaceDef::NodeSet {
                name: "q".into(),
                contains: vec!["nodelist_4".into()],
                at: Loc::default(),
            },
        ],
    );
    assert_eq!(set.get("p").unwrap().kind, SurfaceKind::Nodes);
    assert_eq!(set.get("p").unwrap().nodes.len(), 3);
    assert_eq!(set.get("q").unwrap().nodes, vec![NodeId(3)]);
    // Nodes along one edge make no whole face: they have no tributary area (W0308).
    assert_eq!(codes(&set), ["W0308", "W0301", "W0308"]);
}

#[test]
fn contact_type_node_turns_faces_into_nodes() {
    let mesh = generate::unit_hex();
    let mut sb = surface_block("n");
    sb.blocks = vec!["block_1".into()];
    sb.contact_type = ContactType::Node;
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    let s = set.get("n").unwrap();
    assert_eq!(
        (s.kind, s.faces.len(), s.nodes.len()),
        (SurfaceKind::Nodes, 0, 8)
    );
}

/// A hex with a shell on its top face sharing its nodes, and the shell block defined
/// before or after the solid block: the solid's top is sandwiched; the shell keeps only
/// its upward side (the one facing away from the solid).
#[test]
fn shell_on_solid_face_is_sandwiched_whatever_the_order() {
    for shell_first in [false, true] {
        let base = generate::unit_hex();
        let mut mesh = Mesh {
            dim: 3,
            coords: base.coords.clone(),
            node_numbers: base.node_numbers.clone(),
            ..Mesh::default()
        };
        let hex = base.blocks[0].connectivity.clone();
        // The hex's top side (its local nodes 5..8), counter-clockwise seen from above.
        let shell = hex[4..8].to_vec();
        if shell_first {
            mesh.push_block(2, "", Topology::Shell4, shell, None);
            mesh.push_block(1, "", Topology::Hex8, hex, None);
        } else {
            mesh.push_block(1, "", Topology::Hex8, hex, None);
            mesh.push_block(2, "", Topology::Shell4, shell, None);
        }
        let solid_cmd = || contains("solid", &["block_1"]);
        let shell_cmd = || contains("shell", &["block_2"]);
        for cmds in [
            vec![solid_cmd(), shell_cmd()],
            vec![shell_cmd(), solid_cmd()],
        ] {
            let set = build(&mesh, cmds);
            let solid = set.get("solid").unwrap();
            let shell = set.get("shell").unwrap();
            assert_eq!(solid.faces.len(), 5, "shell_first={shell_first}");
            assert_eq!(shell.faces.len(), 1);
            let up = surface_normal(&mesh, shell.faces[0].side);
            assert!(up[2] > 0.99, "the kept shell side must face +z, got {up:?}");
        }
    }
}

fn surface_normal(mesh: &Mesh, side: Side) -> [f64; 3] {
    let p: Vec<[f64; 3]> = mesh
        .side_nodes(side)
        .map(|n| mesh.coords[n.index()])
        .collect();
    let a = [p[1][0] - p[0][0], p[1][1] - p[0][1], p[1][2] - p[0][2]];
    let b = [p[2][0] - p[0][0], p[2][1] - p[0][1], p[2][2] - p[0][2]];
    let n = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    n.map(|c| c / l)
}

#[test]
fn lone_shell_gives_top_and_bottom_lofted_by_half_thickness() {
    let base = generate::unit_hex();
    let mut mesh = Mesh {
        dim: 3,
        coords: base.coords.clone(),
        node_numbers: base.node_numbers.clone(),
        ..Mesh::default()
    };
    let top = base.blocks[0].connectivity[4..8].to_vec();
    mesh.push_block(5, "skin", Topology::Shell4, top, None);
    mesh.blocks[0].thickness = Some(0.2);
    let set = build(&mesh, vec![contains("s", &["skin"])]);
    let s = set.get("s").unwrap();
    assert_eq!(s.faces.len(), 2);
    assert!(s.faces.iter().all(|f| (f.loft - 0.1).abs() < 1e-15));
}

#[test]
fn subset_with_normal_moves_matching_faces() {
    let mesh = generate::single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [3, 3, 3], 1));
    let mut sb = surface_block("box");
    sb.blocks = vec!["block_1".into()];
    sb.subsets = vec![Subset {
        name: "Top".into(),
        normal: [0.0, 0.0, 2.0],
        at: Loc::default(),
    }];
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    assert_eq!(faces(&set, "box_top"), 9);
    assert_eq!(faces(&set, "box"), 45);
    assert_eq!(set.get("box_top").unwrap().parent.as_deref(), Some("box"));
}

/// The worked example: a unit hex with `Number Of Subsets 6 Angle 45` gives six subsets
/// of one face each, in side order, and the eight nodes shared out lowest-first.
#[test]
fn auto_subset_of_a_unit_hex_gives_six_single_faces() {
    let mesh = generate::unit_hex();
    let mut sb = surface_block("cube");
    sb.blocks = vec!["block_1".into()];
    sb.auto_subset = Some(AutoSubset {
        name: "side".into(),
        number_of_subsets: Some(6),
        angle: Some(45.0),
        at: Loc::default(),
    });
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    for k in 1..=6 {
        let s = set.get(&format!("cube_side_auto_{k}")).unwrap();
        assert_eq!(s.faces.len(), 1);
        assert_eq!(
            s.faces[0].side.side, k as u8,
            "groups ordered by lowest face"
        );
    }
    assert_eq!(faces(&set, "cube"), 0);
    // Side 1 (nodes 1 2 6 5) takes four nodes; side 2 (2 3 7 6) only the two new ones.
    assert_eq!(set.get("cube_side_auto_1").unwrap().nodes.len(), 4);
    assert_eq!(set.get("cube_side_auto_2").unwrap().nodes.len(), 2);
    let total: usize = set.surfaces.iter().map(|s| s.nodes.len()).sum();
    assert_eq!(total, 8);
    assert_eq!(codes(&set), ["W0306"]);
}

#[test]
fn auto_subset_groups_beyond_the_count_stay_in_the_parent() {
    let mesh = generate::unit_hex();
    let mut sb = surface_block("cube");
    sb.blocks = vec!["block_1".into()];
    sb.auto_subset = Some(AutoSubset {
        name: "g".into(),
        number_of_subsets: Some(4),
        angle: None,
        at: Loc::default(),
    });
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    assert_eq!(faces(&set, "cube"), 2);
    assert!(set.get("cube_g_auto_5").is_none());
    assert_eq!(codes(&set), ["W0304"]);
}

/// On a 12-facet half cylinder the facet normals are 15° apart. With a 50° angle a group
/// takes the facets within 50° of its seed — 0°, 15°, 30°, 45° — so three groups of four.
/// (Chaining neighbour to neighbour would have made one group of twelve.)
#[test]
fn auto_subset_on_a_faceted_curve_bounds_each_group_by_the_angle() {
    let mesh = generate::annulus(
        1.0,
        2.0,
        180.0,
        [0.0, 1.0],
        [1, 12, 1],
        1,
        [1, 0, 0, 0, 0, 0],
    );
    let mut sb = surface_block("c");
    sb.side_sets = vec!["surface_1".into()];
    sb.auto_subset = Some(AutoSubset {
        name: "a".into(),
        number_of_subsets: None,
        angle: Some(50.0),
        at: Loc::default(),
    });
    let set = build(&mesh, vec![SurfaceDef::Block(sb)]);
    let sizes: Vec<usize> = (1..=6)
        .filter_map(|k| set.get(&format!("c_a_auto_{k}")))
        .map(|s| s.faces.len())
        .collect();
    assert_eq!(sizes, [4, 4, 4]);
}

#[test]
fn restrict_to_subdomain_keeps_faces_inside_the_sphere() {
    let mesh = generate::single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [4, 4, 4], 1));
    let mut d = def(vec![contains("s", &["block_1"])]);
    // A sphere around the corner (0,0,0) of radius 0.3 holds the centroids (0.125, 0.125, 0)
    // of the three corner faces only (distance 0.177); the next ones are at 0.395.
    d.restrict_contact_to_subdomain = Some(Subdomain {
        radius: 0.3,
        point: [0.0; 3],
    });
    let set = surfaces::build(&mesh, &d, &SourceMap::default());
    assert_eq!(faces(&set, "s"), 3);
}

#[test]
fn element_death_exposes_faces_of_skins_and_shrinks_side_sets() {
    let mesh = generate::single_box(
        BoxSpec::hex([0.0; 3], [3.0, 1.0, 1.0], [3, 1, 1], 1).with_side_sets([0, 0, 0, 0, 5, 0]),
    );
    let d = def(vec![
        contains("bottom", &["surface_5"]),
        contains("skin", &["block_1"]),
    ]);
    let alive = surfaces::build(&mesh, &d, &SourceMap::default());
    assert_eq!(faces(&alive, "skin"), 14 - 3);
    // Kill the middle element: the two end cubes have 6 faces each, 2 of them in the side set.
    let dead: HashSet<ElemId> = [ElemId(1)].into();
    let set = surfaces::build_with_dead(&mesh, &d, &SourceMap::default(), &dead);
    assert_eq!(faces(&set, "bottom"), 2);
    assert_eq!(faces(&set, "skin"), 12 - 2);
}

#[test]
fn two_dimensional_skins_are_edges() {
    let mut mesh = Mesh {
        dim: 2,
        coords: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.0],
        ],
        node_numbers: (1..=6).collect(),
        ..Mesh::default()
    };
    let q = |a: u32, b: u32, c: u32, d: u32| [NodeId(a), NodeId(b), NodeId(c), NodeId(d)];
    mesh.push_block(
        1,
        "",
        Topology::Quad4,
        [q(0, 1, 4, 3), q(1, 2, 5, 4)].concat(),
        None,
    );
    let set = build(&mesh, vec![contains("edge", &["block_1"])]);
    let s = set.get("edge").unwrap();
    assert_eq!(s.faces.len(), 6);
    assert!((s.area(&mesh) - 6.0).abs() < 1e-14, "perimeter");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// However commands are combined, no face is counted twice: the faces of all
    /// surfaces never exceed the exterior faces plus the side-set faces.
    #[test]
    fn surfaces_never_hold_more_than_exterior_plus_side_set_faces(
        cmds in proptest::collection::vec(0usize..5, 1..6),
        merge in any::<bool>(),
    ) {
        let mesh = stack(merge);
        let pool = [
            contains("s0", &["block_1"]),
            contains("s1", &["block_2"]),
            contains("s2", &["surface_1"]),
            contains("s3", &["surface_2", "block_1"]),
            skin_all(&[]),
        ];
        let mut chosen = Vec::new();
        let mut seen = HashSet::new();
        for c in cmds {
            if seen.insert(c) {
                chosen.push(pool[c].clone());
            }
        }
        let set = build(&mesh, chosen);
        let total: usize = set.surfaces.iter().map(|s| s.faces.len()).sum();
        let bound = if merge { 2 * (CUBE_FACES - 4) } else { 2 * CUBE_FACES } + 8;
        prop_assert!(total <= bound);
        let mut all = HashSet::new();
        for s in &set.surfaces {
            for f in &s.faces {
                prop_assert!(all.insert(f.side), "face {:?} in two surfaces", f.side);
            }
        }
    }

    /// Without overlap, the order of definitions does not change any surface.
    #[test]
    fn ownership_is_order_independent_without_overlap(swap in any::<bool>(), merge in any::<bool>()) {
        let mesh = stack(merge);
        let a = contains("a", &["block_1"]);
        let b = contains("b", &["block_2"]);
        let set = if swap { build(&mesh, vec![b, a]) } else { build(&mesh, vec![a, b]) };
        let reference = build(&mesh, vec![contains("a", &["block_1"]), contains("b", &["block_2"])]);
        for name in ["a", "b"] {
            prop_assert_eq!(&set.get(name).unwrap().faces, &reference.get(name).unwrap().faces);
        }
    }
}
