//! The contact search end to end: decks parsed from Sierra text, meshes from the
//! generators, pairs checked against geometry worked out independently.

use std::path::Path;
use std::sync::Arc;

use seam::deck::parse_sierra;
use seam::diag::SourceMap;
use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{Mesh, NodeSet};
use seam::scene::interaction;
use seam::scene::search::search_definition;
use seam::scene::surfaces;
use seam::search::pairing::{Integration, PointStatus, Searcher, SurfaceGeometry};
use seam::search::scene::SceneSearch;

fn run(mesh: &Mesh, deck: &str, integration: Integration) -> SceneSearch {
    run_in(mesh, deck, integration, Path::new("."))
}

fn run_in(mesh: &Mesh, deck: &str, integration: Integration, dir: &Path) -> SceneSearch {
    let (d, diags) = parse_sierra(&Arc::from("deck.i"), deck);
    assert!(!diags.has_errors(), "{diags:?}");
    let def = &d.contact_definitions[0];
    let set = surfaces::build(mesh, def, &SourceMap::default());
    assert!(!set.diagnostics.has_errors(), "{:?}", set.diagnostics);
    let (list, diags) = interaction::resolve(def, &set, mesh.dim, &SourceMap::default());
    assert!(!diags.has_errors(), "{diags:?}");
    search_definition(
        mesh,
        def,
        &set,
        &list,
        dir,
        &SourceMap::default(),
        integration,
    )
}

/// Block 1 on the unit cube (n1 × n1 × 1 cells), block 2 above it on [0,1]² × [1,2]
/// (n2 × n2 × 1), meshed apart. Side sets: 1 = top of block 1, 2 = bottom of block 2.
fn two_boxes(n1: usize, n2: usize) -> Mesh {
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [n1, n1, 1], 1).with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [n2, n2, 1], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    )
}

const PAIR: &str = "begin contact definition
  contact surface top contains surface_1
  contact surface bottom contains surface_2
  begin interaction
    side a bottom
    side b top
  end
end";

#[test]
fn planar_non_matching_interface_is_fully_covered() {
    let mesh = two_boxes(7, 3);
    for integration in [
        Integration::Quadrature { order: 2 },
        Integration::Segments { order: 2 },
    ] {
        let s = run(&mesh, PAIR, integration);
        let p = &s.pairings[0];
        let st = &p.result.stats;
        assert_eq!(st.matched, st.points, "{integration:?}: {st:?}");
        assert!(
            (st.overlap_area - 1.0).abs() < 1e-13,
            "{integration:?}: {st:?}"
        );
        assert!((st.side_a_area - 1.0).abs() < 1e-13);
        assert!(st.gap_min.unwrap().abs() < 1e-14 && st.gap_max.unwrap().abs() < 1e-14);
        assert!(p.result.contact_fraction.iter().all(|&f| f == 1.0));
    }
    // Quadrature: 2×2 points on each of the 9 side-A faces.
    assert_eq!(
        run(&mesh, PAIR, Integration::Quadrature { order: 2 }).pairings[0]
            .result
            .stats
            .points,
        36
    );
}

/// Side-B nodes (3×3 cells: 16 nodes at multiples of 1/3) all sit on vertices or edges of
/// the 6×6 side-A grid below. Each must pair exactly once, with the lowest-numbered
/// face among those containing it.
#[test]
fn points_on_edges_and_vertices_pair_exactly_once() {
    let mut mesh = two_boxes(6, 3);
    let nodes: Vec<_> = (0..mesh.num_nodes())
        .filter(|&i| mesh.coords[i][2] == 1.0 && i >= 7 * 7 * 2)
        .map(|i| seam::mesh::NodeId(i as u32))
        .collect();
    assert_eq!(nodes.len(), 16);
    mesh.node_sets.push(NodeSet {
        id: 1,
        name: "pins".into(),
        nodes: nodes.clone(),
    });
    let deck = "begin contact definition
      contact surface top contains surface_1
      contact node set pins contains pins
      begin interaction
        side a pins
        side b top
      end
    end";
    let s = run(&mesh, deck, Integration::Quadrature { order: 1 });
    let p = &s.pairings[0];
    assert_eq!(p.result.points.len(), 16);
    let top = &s.pairings[0];
    let _ = top;
    // Side-B faces in order: 6×6 cells of the top side set, cell (i, j) at index 6j + i.
    for q in p.result.points.iter() {
        assert_eq!(q.status, PointStatus::Matched);
        let (x, y) = (q.x[0], q.x[1]);
        // Lowest cell index containing (x, y): smallest j then smallest i with the
        // point in [i/6, (i+1)/6] × [j/6, (j+1)/6].
        let lo = |v: f64| (((v * 6.0) - 1e-9).floor().max(0.0)) as u32;
        let expect = 6 * lo(y) + lo(x);
        assert_eq!(q.b_face, Some(expect), "point ({x}, {y})");
        assert!(q.gap.abs() < 1e-15);
    }
}

#[test]
fn results_do_not_depend_on_the_thread_count() {
    let mesh = two_boxes(40, 27);
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    let two = rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build()
        .unwrap();
    for integration in [
        Integration::Quadrature { order: 2 },
        Integration::Segments { order: 3 },
    ] {
        let a = one.install(|| run(&mesh, PAIR, integration));
        let b = two.install(|| run(&mesh, PAIR, integration));
        assert_eq!(a.pairings[0].result.points, b.pairings[0].result.points);
        assert_eq!(a.pairings[0].result.stats, b.pairings[0].result.stats);
    }
}

/// Two concentric cylinders touching at r = 1, faceted independently (24 and 36 facets
/// round, 3 and 4 layers over the height 2). The overlap is the faceted interface, whose
/// area differs from 2πrL by the faceting error; gaps are bounded by the two sagittas
/// r(1 − cos(π/n)).
#[test]
fn concentric_cylinders_overlap_and_gap_statistics() {
    let (na, nb) = (24usize, 36usize);
    let inner = generate::annulus(
        0.5,
        1.0,
        360.0,
        [0.0, 2.0],
        [2, na, 3],
        1,
        [0, 1, 0, 0, 0, 0],
    );
    let outer = generate::annulus(
        1.0,
        1.5,
        360.0,
        [0.0, 2.0],
        [2, nb, 4],
        2,
        [2, 0, 0, 0, 0, 0],
    );
    let mesh = merge_apart(&inner, &outer);
    let deck = "begin contact definition
      contact surface inner contains surface_1
      contact surface outer contains surface_2
      begin interaction
        side a inner
        side b outer
      end
    end";
    let sag = |n: usize| 1.0 - (std::f64::consts::PI / n as f64).cos();
    for integration in [
        Integration::Quadrature { order: 2 },
        Integration::Segments { order: 2 },
    ] {
        let s = run(&mesh, deck, integration);
        let st = &s.pairings[0].result.stats;
        assert_eq!(st.matched, st.points, "{st:?}");
        let faceted_a = 2.0 * na as f64 * (std::f64::consts::PI / na as f64).sin() * 2.0;
        let exact = 2.0 * std::f64::consts::PI * 2.0;
        // The clipped overlap is side A's faceted area (to the projection's cosine).
        assert!(
            (st.overlap_area - faceted_a).abs() < sag(nb) * faceted_a,
            "{st:?}"
        );
        assert!(
            (st.overlap_area - exact).abs() / exact
                < 2.0 * (std::f64::consts::PI / na as f64).powi(2) / 6.0 + 1e-3
        );
        let bound = sag(na) + sag(nb);
        assert!(
            st.gap_min.unwrap() >= -bound && st.gap_max.unwrap() <= bound,
            "{st:?} bound {bound}"
        );
        // Each gap, worked out from the facet geometry: side-B facet j (face index
        // 36k + j over the layers k) is the plane x·e_j = cos(π/36), facing inwards, with
        // e_j the radial direction at its mid-angle (j + ½)·10°. Quadrature measures the
        // gap along side B's normal, cos(π/36) − x·e_j; segments along side A's normal
        // n_A, which divides that by n_A·e_j. And the point's angle lies in the facet's.
        for q in s.pairings[0].result.points.iter() {
            let j = (q.b_face.expect("matched") as usize % nb) as f64;
            let mid = ((j + 0.5) * 360.0 / nb as f64).to_radians();
            let e = [mid.cos(), mid.sin(), 0.0];
            let along_b =
                (std::f64::consts::PI / nb as f64).cos() - (q.x[0] * e[0] + q.x[1] * e[1]);
            let expect = match integration {
                Integration::Quadrature { .. } => along_b,
                Integration::Segments { .. } => {
                    along_b / (q.normal_a[0] * e[0] + q.normal_a[1] * e[1])
                }
            };
            assert!(
                (q.gap - expect).abs() < 1e-12,
                "gap {} expected {expect}",
                q.gap
            );
            let angle = q.x[1]
                .atan2(q.x[0])
                .rem_euclid(std::f64::consts::TAU)
                .to_degrees();
            let (lo, hi) = (j * 10.0, (j + 1.0) * 10.0);
            assert!(
                angle >= lo - 1e-9 && angle <= hi + 1e-9,
                "point at {angle}° paired with facet [{lo}, {hi}]"
            );
        }
    }
}

use generate::disjoint_union as merge_apart;

#[test]
fn rectangular_periodicity_ties_opposite_faces() {
    let mesh = generate::single_box(
        BoxSpec::hex([0.0; 3], [2.0, 1.0, 1.0], [4, 3, 3], 1).with_side_sets([1, 2, 0, 0, 0, 0]),
    );
    let deck = "begin contact definition
      contact surface left contains surface_1
      contact surface right contains surface_2
      periodicity for left = rectangular offset = 2 0 0
    end";
    let s = run(&mesh, deck, Integration::Segments { order: 2 });
    let p = s
        .pairings
        .iter()
        .find(|p| p.periodic)
        .expect("a periodic pair");
    assert_eq!((p.side_a.as_str(), p.side_b.as_str()), ("left", "right"));
    assert_eq!(p.result.stats.matched, p.result.stats.points);
    assert!((p.result.stats.overlap_area - 1.0).abs() < 1e-13);
    assert!(p.worst_image_distance.unwrap() < 1e-14);
    assert!(s.diagnostics.is_empty(), "{:?}", s.diagnostics);
}

/// A 30° sector of an annulus: its two radial faces are periodic under a 30° turn about
/// z. A Lua map giving the same rotation must give the same pairs.
#[test]
fn cylindrical_periodicity_and_an_equal_lua_map() {
    let mesh = generate::annulus(1.0, 2.0, 30.0, [0.0, 1.0], [3, 4, 2], 1, [0, 0, 1, 2, 0, 0]);
    let cyl = "begin contact definition
      contact surface start contains surface_1
      contact surface finish contains surface_2
      periodicity for start = cylindrical axis = 0 0 1 center = 0 0 0 angle = 30
    end";
    let (s, c) = 30f64.to_radians().sin_cos();
    let lua = format!(
        "begin contact definition
      contact surface start contains surface_1
      contact surface finish contains surface_2
      periodicity for start = mapped x_map = \"{c:.17}*x - {s:.17}*y\" y_map = \"{s:.17}*x + {c:.17}*y\"
    end"
    );
    let a = run(&mesh, cyl, Integration::Quadrature { order: 2 });
    let b = run(&mesh, &lua, Integration::Quadrature { order: 2 });
    assert_eq!(
        (a.pairings.len(), b.pairings.len()),
        (1, 1),
        "only the periodic pair"
    );
    let (pa, pb) = (&a.pairings[0], &b.pairings[0]);
    assert!(pa.periodic && pb.periodic);
    assert_eq!(pa.side_b, "finish");
    assert_eq!(pa.result.stats.matched, pa.result.stats.points);
    assert!(pa.worst_image_distance.unwrap() < 1e-12);
    assert_eq!(pa.result.points.len(), pb.result.points.len());
    for (x, y) in pa.result.points.iter().zip(pb.result.points.iter()) {
        assert_eq!(x.b_face, y.b_face);
        assert!((x.xi_b[0] - y.xi_b[0]).abs() < 1e-12 && (x.xi_b[1] - y.xi_b[1]).abs() < 1e-12);
    }
    assert!(a.diagnostics.is_empty(), "{:?}", a.diagnostics);
}

#[test]
fn maps_that_miss_or_do_not_close_are_errors() {
    let mesh = generate::annulus(1.0, 2.0, 30.0, [0.0, 1.0], [3, 4, 2], 1, [0, 0, 1, 2, 0, 0]);
    let deck = |angle: &str| {
        format!(
            "begin contact definition
      contact surface start contains surface_1
      contact surface finish contains surface_2
      periodicity for start = cylindrical axis = 0 0 1 center = 0 0 0 angle = {angle}
    end"
        )
    };
    // 31°: lands beside the destination.
    let s = run(&mesh, &deck("31"), Integration::Quadrature { order: 2 });
    let codes: Vec<&str> = s.diagnostics.0.iter().map(|d| d.code).collect();
    assert!(codes.contains(&"W0320"), "{codes:?}");
    assert!(
        codes.contains(&"E0324") || codes.contains(&"E0323"),
        "{codes:?}"
    );
    // 30.0001°: 12 turns do not close.
    let s = run(
        &mesh,
        &deck("30.0001"),
        Integration::Quadrature { order: 2 },
    );
    assert!(s.diagnostics.0.iter().any(|d| d.code == "W0320"));
}

#[test]
fn refit_after_a_move_equals_a_rebuild() {
    let mesh = two_boxes(5, 4);
    let set = surfaces::build(
        &mesh,
        &parse_sierra(&Arc::from("d"), PAIR).0.contact_definitions[0],
        &SourceMap::default(),
    );
    let settings = seam::search::SearchSettings::defaults(3);
    let a = SurfaceGeometry::from_surface(&mesh, set.get("bottom").unwrap(), &mesh.coords).unwrap();
    let b0 = SurfaceGeometry::from_surface(&mesh, set.get("top").unwrap(), &mesh.coords).unwrap();
    let mut searcher = Searcher::new(&b0, &settings);
    // Move side B by a small rigid shift in x and a small gap in z.
    let moved: Vec<[f64; 3]> = mesh
        .coords
        .iter()
        .map(|p| [p[0] + 0.03, p[1], p[2] - 0.01])
        .collect();
    let b1 = SurfaceGeometry::from_surface(&mesh, set.get("top").unwrap(), &moved).unwrap();
    searcher.refit(&b1);
    let refit = searcher.search(
        &a,
        &b1,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    let rebuilt = Searcher::new(&b1, &settings).search(
        &a,
        &b1,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    assert_eq!(refit.points, rebuilt.points);
    assert!((refit.stats.gap_min.unwrap() - 0.01).abs() < 1e-14);
}

#[test]
fn angle_and_distance_rejections_are_counted() {
    // Block 2 overlaps block 1 exactly; their tops coincide at z = 1 and both face +z,
    // so the normals are not opposed.
    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [4, 4, 1], 1).with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0; 3], [1.0; 3], [3, 3, 1], 2).with_side_sets([0, 0, 0, 0, 0, 2]),
        ],
        false,
    );
    let s = run(&mesh, PAIR, Integration::Quadrature { order: 1 });
    let st = &s.pairings[0].result.stats;
    assert_eq!((st.matched, st.rejected_angle), (0, 9), "{st:?}");
    assert_eq!(st.overlap_area, 0.0);
    // Side B moved 0.02 below an opposed side A, with a normal tolerance of 0.01.
    let mut mesh = two_boxes(4, 3);
    for p in mesh.coords.iter_mut().take(5 * 5 * 2) {
        p[2] -= 0.02;
    }
    let tight = PAIR.replace("side b top", "side b top\n normal tolerance 0.01");
    let st = &run(&mesh, &tight, Integration::Quadrature { order: 1 }).pairings[0]
        .result
        .stats;
    assert_eq!((st.matched, st.rejected_distance), (0, 9), "{st:?}");
    let st = &run(&mesh, PAIR, Integration::Quadrature { order: 1 }).pairings[0]
        .result
        .stats;
    assert_eq!(
        st.matched, 9,
        "0.02 is within the default 0.2 × face size: {st:?}"
    );
}

#[test]
fn subdomain_restricts_surfaces_and_points() {
    let mesh = two_boxes(4, 4);
    let deck = "begin contact definition
      contact surface top contains surface_1
      contact surface bottom contains surface_2
      restrict contact to subdomain defined by radius 0.5 and point 0 0 1
      begin interaction
        side a bottom
        side b top
      end
    end";
    let s = run(&mesh, deck, Integration::Quadrature { order: 2 });
    let st = &s.pairings[0].result.stats;
    // Faces whose centroids lie within 0.5 of (0, 0, 1): the 2×2 cells in the corner
    // (centroids at distance ≤ √2·0.375 = 0.53? no: (0.375, 0.375) is 0.530 away, so
    // only three: (0.125, 0.125), (0.375, 0.125), (0.125, 0.375)). Their 2×2 Gauss
    // points: those farther than 0.5 from the corner are rejected.
    let inside = |x: f64, y: f64| x * x + y * y <= 0.25;
    let g = 0.125 / 3f64.sqrt();
    let mut expect_in = 0;
    for (cx, cy) in [(0.125, 0.125), (0.375, 0.125), (0.125, 0.375)] {
        for (dx, dy) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
            expect_in += usize::from(inside(cx + dx, cy + dy));
        }
    }
    assert_eq!(st.points, 12, "{st:?}");
    assert_eq!(st.matched, expect_in, "{st:?}");
    assert_eq!(st.rejected_subdomain, 12 - expect_in);
}

#[test]
fn overclosure_offsets_or_adjustments() {
    // Block 2 pushed 0.01 into block 1: a negative gap everywhere.
    let mut mesh = two_boxes(3, 2);
    let first_b2 = 4 * 4 * 2;
    for p in &mut mesh.coords[first_b2..] {
        p[2] -= 0.01;
    }
    let deck = |treatment: &str| {
        format!(
            "begin contact definition
      contact surface top contains surface_1
      contact surface bottom contains surface_2
      initial overclosure = {treatment}
      begin interaction
        side a bottom
        side b top
      end
    end"
        )
    };
    let s = run(
        &mesh,
        &deck("store offsets"),
        Integration::Quadrature { order: 1 },
    );
    for q in s.pairings[0].result.points.iter() {
        assert!((q.gap + 0.01).abs() < 1e-14 && (q.offset + 0.01).abs() < 1e-14);
    }
    let s = run(
        &mesh,
        &deck("adjust nodes"),
        Integration::Quadrature { order: 1 },
    );
    for q in s.pairings[0].result.points.iter() {
        assert_eq!((q.gap, q.offset), (0.0, 0.0));
        assert!((q.x[2] - 1.0).abs() < 1e-14, "moved onto side B: {:?}", q.x);
    }
}

/// `Update Search Every 3 Steps`: steps 0, 3, 6 search; between them the pairing is kept
/// and the geometry refreshed, so a side B lowered by 0.003 opens every gap by 0.003
/// with the same faces, and a later full search agrees while the motion is small.
#[test]
fn pairing_is_reused_between_search_updates() {
    use seam::search::pairing::SearchSchedule;
    let schedule = SearchSchedule::new(Some(3));
    let full: Vec<bool> = (0..7).map(|s| schedule.full_search(s)).collect();
    assert_eq!(full, [true, false, false, true, false, false, true]);
    assert!(SearchSchedule::new(None).full_search(5));
    let deck = |text: &str| {
        parse_sierra(&Arc::from("d"), text)
            .0
            .contact_definitions
            .remove(0)
    };
    let elfen = deck(
        "begin contact definition\n begin search options\n search update frequency 4\n end\nend\n",
    );
    assert_eq!(
        seam::scene::search::search_schedule(&elfen),
        SearchSchedule::new(Some(4))
    );
    let aria = deck(
        "begin contact definition\n update search every 2 steps\n begin search options\n search update frequency 4\n end\nend\n",
    );
    assert_eq!(
        seam::scene::search::search_schedule(&aria),
        SearchSchedule::new(Some(2))
    );

    let mesh = two_boxes(5, 4);
    let def = parse_sierra(&Arc::from("d"), PAIR)
        .0
        .contact_definitions
        .remove(0);
    let set = surfaces::build(&mesh, &def, &SourceMap::default());
    let settings = seam::search::SearchSettings::defaults(3);
    let geo = |coords: &[[f64; 3]], name: &str| {
        SurfaceGeometry::from_surface(&mesh, set.get(name).unwrap(), coords).unwrap()
    };
    let (a, b0) = (geo(&mesh.coords, "bottom"), geo(&mesh.coords, "top"));
    let mut r = Searcher::new(&b0, &settings).search(
        &a,
        &b0,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    let before = r.points.clone();
    let lowered: Vec<[f64; 3]> = mesh
        .coords
        .iter()
        .map(|p| [p[0], p[1], p[2] - 0.003])
        .collect();
    let b1 = geo(&lowered, "top");
    r.update_geometry(&a, &b1);
    for (p, q) in r.points.iter().zip(before.iter()) {
        assert_eq!(p.b_face, q.b_face);
        assert!(
            (p.gap - (q.gap + 0.003)).abs() < 1e-15,
            "{} vs {}",
            p.gap,
            q.gap
        );
    }
    let fresh = Searcher::new(&b1, &settings).search(
        &a,
        &b1,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    assert_eq!(
        fresh.points.iter().map(|p| p.b_face).collect::<Vec<_>>(),
        r.points.iter().map(|p| p.b_face).collect::<Vec<_>>()
    );
}

/// The overlap diagnostic where side B covers side A partly, and twice over: a side B
/// on x ≤ 0.55 under the unit square (its edge crossing side-A faces) covers 0.55;
/// two sheets of side B, 1e-3 apart, cover it twice (the clipped sums count each
/// sheet).
#[test]
fn overlap_area_counts_a_partial_and_a_double_cover() {
    let above = BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [7, 7, 1], 2)
        .with_side_sets([0, 0, 0, 0, 2, 0]);
    let partial = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [0.55, 1.0, 1.0], [3, 5, 1], 1)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            above.clone(),
        ],
        false,
    );
    let double = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [3, 3, 1], 1).with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.999], [4, 4, 1], 3)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            above,
        ],
        false,
    );
    for (mesh, covered) in [(&partial, 0.55), (&double, 2.0)] {
        for order in [1, 2] {
            let s = run(mesh, PAIR, Integration::Quadrature { order });
            let st = &s.pairings[0].result.stats;
            assert!(
                (st.overlap_area - covered).abs() < 1e-13,
                "order {order}: {} for {covered}: {st:?}",
                st.overlap_area
            );
        }
    }
}
