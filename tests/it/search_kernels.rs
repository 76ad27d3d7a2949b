//! Property tests of the search kernels against independent truth: brute force for the
//! BVH, rigid-motion and scaling invariance plus sampled minimum distance for the
//! projections, analytic areas and polygon moments (shoelace-type formulas) for the
//! mortar clipping and quadrature, and non-matching tilings of a square.

use proptest::prelude::*;
use seam::search::bvh::{Aabb, Bvh, QueryHint};
use seam::search::mortar::{
    clip_polygon_polygon, overlap_area_face_face, overlap_length_line_line, rule_line,
    rule_triangle, segments_face_face, segments_face_face_into, segments_line_line_into,
    signed_area_polygon,
};
use seam::search::project::{
    map_line2, map_quad4, normal_line2, project_point_line2, project_point_quad4,
    project_point_tri3,
};

type V3 = [f64; 3];

fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn norm(a: V3) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

// ---------------------------------------------------------------------------------------
// (a) BVH against brute force
// ---------------------------------------------------------------------------------------

fn boxes_strategy() -> impl Strategy<Value = Vec<Aabb>> {
    // Some boxes flat (zero extent) and some duplicated, to exercise degenerate splits.
    prop::collection::vec(
        (
            prop::array::uniform3(-10.0..10.0f64),
            prop::array::uniform3(prop_oneof![Just(0.0), 0.0..3.0f64]),
            0usize..3,
        ),
        0..160,
    )
    .prop_map(|v| {
        let mut out = Vec::new();
        for (c, e, dup) in v {
            let b = Aabb {
                min: c,
                max: [c[0] + e[0], c[1] + e[1], c[2] + e[2]],
            };
            for _ in 0..=dup {
                out.push(b);
            }
        }
        out
    })
}

/// Closed boxes overlap iff their intervals overlap on every axis (written out here, not
/// `Aabb::intersects`, so the test does not trust the code under test).
fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    (0..3).all(|k| a.min[k] <= b.max[k] && b.min[k] <= a.max[k])
}

/// Squared distance from a point to a box, clamping per axis.
fn box_distance2(b: &Aabb, p: V3) -> f64 {
    (0..3)
        .map(|k| {
            let c = p[k].clamp(b.min[k], b.max[k]);
            (p[k] - c) * (p[k] - c)
        })
        .sum()
}

fn brute(items: &[Aabb], q: &Aabb) -> Vec<usize> {
    (0..items.len())
        .filter(|&i| overlaps(&items[i], q))
        .collect()
}

fn queried(bvh: &Bvh, q: &Aabb) -> Vec<usize> {
    let mut v = Vec::new();
    bvh.query(q, |i| v.push(i));
    v.sort_unstable();
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn bvh_query_equals_brute_force_also_after_refit(
        items in boxes_strategy(),
        queries in prop::collection::vec(
            (prop::array::uniform3(-12.0..12.0f64), prop::array::uniform3(0.0..6.0f64)), 1..12),
        moves in prop::collection::vec(prop::array::uniform3(-4.0..4.0f64), 0..400),
        radius in 0.0..4.0f64,
    ) {
        let mut bvh = Bvh::build(&items);
        prop_assert_eq!(bvh.len(), items.len());
        let mut perm: Vec<usize> = bvh.item_order().collect();
        perm.sort_unstable();
        prop_assert_eq!(perm, (0..items.len()).collect::<Vec<_>>());
        let check = |bvh: &Bvh, items: &[Aabb]| -> Result<(), TestCaseError> {
            // Boxes that touch items exactly at a corner (closed boxes must report them),
            // besides the random ones.
            let touching = items.iter().take(8).flat_map(|b| {
                [
                    Aabb { min: [b.min[0] - 1.0, b.min[1] - 1.0, b.min[2] - 1.0], max: b.min },
                    Aabb { min: b.max, max: [b.max[0] + 1.0, b.max[1] + 1.0, b.max[2] + 1.0] },
                ]
            });
            // One hint carried across all queries, as a search loop would.
            let mut hint = QueryHint::default();
            let mut hinted = |q: &Aabb| {
                let mut v = Vec::new();
                bvh.query_with_hint(&mut hint, q, |i, _| v.push(i));
                v.sort_unstable();
                v
            };
            for q in touching {
                prop_assert_eq!(queried(bvh, &q), brute(items, &q));
                prop_assert_eq!(hinted(&q), brute(items, &q));
            }
            for (c, e) in &queries {
                let q = Aabb { min: *c, max: [c[0] + e[0], c[1] + e[1], c[2] + e[2]] };
                prop_assert_eq!(queried(bvh, &q), brute(items, &q));
                prop_assert_eq!(hinted(&q), brute(items, &q));
                let mut with_box = Vec::new();
                bvh.query_with_box(&q, |i, b| with_box.push((i, *b)));
                with_box.sort_unstable_by_key(|x| x.0);
                prop_assert_eq!(
                    with_box,
                    brute(items, &q).into_iter().map(|i| (i, items[i])).collect::<Vec<_>>()
                );
                let mut near = Vec::new();
                bvh.query_point_within(*c, radius, |i| near.push(i));
                near.sort_unstable();
                let want: Vec<usize> = (0..items.len())
                    .filter(|&i| box_distance2(&items[i], *c) <= radius * radius)
                    .collect();
                prop_assert_eq!(near, want);
            }
            Ok(())
        };
        check(&bvh, &items)?;
        // Same input, same tree: the reported order (before sorting) is identical.
        let again = Bvh::build(&items);
        let q = Aabb { min: [-3.0; 3], max: [3.0; 3] };
        let (mut o1, mut o2) = (Vec::new(), Vec::new());
        bvh.query(&q, |i| o1.push(i));
        again.query(&q, |i| o2.push(i));
        prop_assert_eq!(o1, o2);
        // Move the boxes (large motions included), refit, compare again.
        let moved: Vec<Aabb> = items
            .iter()
            .enumerate()
            .map(|(i, b)| {
                let d = moves.get(i).copied().unwrap_or([0.0; 3]);
                Aabb {
                    min: [b.min[0] + d[0], b.min[1] + d[1], b.min[2] + d[2]],
                    max: [b.max[0] + d[0], b.max[1] + d[1], b.max[2] + d[2]],
                }
            })
            .collect();
        bvh.refit(&moved);
        check(&bvh, &moved)?;
    }
}

// ---------------------------------------------------------------------------------------
// (b) projection: invariance under rigid motion and scaling; closest point truly closest
// ---------------------------------------------------------------------------------------

/// Rotation matrix of a unit quaternion (w, x, y, z).
fn rotation(q: [f64; 4]) -> [[f64; 3]; 3] {
    let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
    let [w, x, y, z] = q.map(|c| c / n);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - w * z),
            2.0 * (x * z + w * y),
        ],
        [
            2.0 * (x * y + w * z),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - w * x),
        ],
        [
            2.0 * (x * z - w * y),
            2.0 * (y * z + w * x),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

fn apply(r: &[[f64; 3]; 3], t: V3, s: f64, p: V3) -> V3 {
    let mut out = t;
    for i in 0..3 {
        for j in 0..3 {
            out[i] += s * r[i][j] * p[j];
        }
    }
    out
}

fn quaternion() -> impl Strategy<Value = [f64; 4]> {
    prop::array::uniform4(-1.0..1.0f64).prop_filter("non-zero quaternion", |q| {
        q.iter().map(|c| c * c).sum::<f64>() > 0.01
    })
}

/// A convex-in-projection quad around the unit square: planar (half the cases, which
/// takes the planar fast path) or mildly warped.
fn quad_strategy() -> impl Strategy<Value = [V3; 4]> {
    (
        prop::array::uniform4((-0.2..0.2f64, -0.2..0.2f64, -0.15..0.15f64)),
        any::<bool>(),
    )
        .prop_map(|(d, planar)| {
            let base = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
            let mut x = [[0.0; 3]; 4];
            for k in 0..4 {
                let z = if planar { 0.0 } else { d[k].2 };
                x[k] = [base[k][0] + d[k].0, base[k][1] + d[k].1, z];
            }
            x
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn quad4_projection_is_rigid_and_scale_invariant(
        x in quad_strategy(),
        p in prop::array::uniform3(-0.5..1.5f64),
        q in quaternion(),
        t in prop::array::uniform3(-100.0..100.0f64),
        s in prop_oneof![0.01..1.0f64, 1.0..100.0f64],
    ) {
        let r = rotation(q);
        let pr0 = project_point_quad4(p, &x);
        let xm = x.map(|v| apply(&r, t, s, v));
        let pm = apply(&r, t, s, p);
        let pr1 = project_point_quad4(pm, &xm);
        // Tolerances: coordinates up to 100 after translation carry ~1e-14 absolute
        // round-off, i.e. ~1e-12 relative to a face scaled down to 0.01; ξ solves the
        // well-conditioned stationarity equation, so it agrees to ~1e-12 as well.
        prop_assert!(!pr0.degenerate && !pr1.degenerate);
        for k in 0..2 {
            prop_assert!((pr0.xi[k] - pr1.xi[k]).abs() < 1e-11, "{pr0:?} {pr1:?}");
        }
        prop_assert!((pr1.gap - s * pr0.gap).abs() < 1e-9 * s.max(1.0) + 1e-10, "{pr0:?} {pr1:?}");
        prop_assert!((pr1.distance - s * pr0.distance).abs() < 1e-9 * s.max(1.0) + 1e-10);
        prop_assert_eq!(pr0.inside, pr1.inside);
        // The reported point is on the face at xi and is the closest: no sample of the
        // face is closer (up to the sampling's own error, which is only one-sided).
        let on_face = map_quad4(&x, pr0.xi);
        prop_assert!(norm(sub(on_face, pr0.point)) < 1e-12);
        prop_assert!((norm(sub(p, pr0.point)) - pr0.distance).abs() < 1e-12);
        let m = 40;
        for i in 0..=m {
            for j in 0..=m {
                let xi = [-1.0 + 2.0 * i as f64 / m as f64, -1.0 + 2.0 * j as f64 / m as f64];
                let d = norm(sub(p, map_quad4(&x, xi)));
                prop_assert!(pr0.distance <= d + 1e-12, "sample {xi:?} at {d} < {}", pr0.distance);
            }
        }
        // Normal is a unit vector and the gap is its component of p − point.
        prop_assert!((norm(pr0.normal) - 1.0).abs() < 1e-12);
        if pr0.inside {
            prop_assert!((pr0.gap.abs() - pr0.distance).abs() < 1e-12);
        }
    }

    #[test]
    fn quad4_projection_on_arbitrary_quads_is_finite_and_closest(
        x in prop::array::uniform4(prop::array::uniform3(-1.0..1.0f64)),
        p in prop::array::uniform3(-1.5..1.5f64),
    ) {
        // Any four points: warped, non-convex, bow-tie or nearly degenerate faces.
        let pr = project_point_quad4(p, &x);
        let all = pr.xi.iter().chain(&pr.point).chain(&pr.normal).chain([&pr.gap, &pr.distance]);
        prop_assert!(all.into_iter().all(|v| v.is_finite()), "{pr:?}");
        prop_assert!(pr.xi.iter().all(|v| v.abs() <= 1.0), "{pr:?}");
        prop_assert!(norm(sub(map_quad4(&x, pr.xi), pr.point)) < 1e-12, "{pr:?}");
        let m = 60;
        let mut best = f64::INFINITY;
        for i in 0..=m {
            for j in 0..=m {
                let xi = [-1.0 + 2.0 * i as f64 / m as f64, -1.0 + 2.0 * j as f64 / m as f64];
                best = best.min(norm(sub(p, map_quad4(&x, xi))));
            }
        }
        prop_assert!(pr.distance <= best + 1e-12, "{pr:?} vs sampled {best}");
    }

    #[test]
    fn tri3_projection_is_rigid_and_scale_invariant(
        x in prop::array::uniform3(prop::array::uniform3(-1.0..1.0f64)),
        p in prop::array::uniform3(-1.5..1.5f64),
        q in quaternion(),
        t in prop::array::uniform3(-100.0..100.0f64),
        s in prop_oneof![0.01..1.0f64, 1.0..100.0f64],
    ) {
        let e1 = sub(x[1], x[0]);
        let e2 = sub(x[2], x[0]);
        let c = [e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]];
        // Well-shaped enough that ξ is determined to 1e-8 after the motion.
        prop_assume!(norm(c) > 0.05);
        let r = rotation(q);
        let pr0 = project_point_tri3(p, &x);
        let pr1 = project_point_tri3(apply(&r, t, s, p), &x.map(|v| apply(&r, t, s, v)));
        for k in 0..2 {
            prop_assert!((pr0.xi[k] - pr1.xi[k]).abs() < 1e-11, "{pr0:?} {pr1:?}");
        }
        prop_assert!((pr1.gap - s * pr0.gap).abs() < 1e-9 * s.max(1.0) + 1e-10);
        prop_assert!((pr1.distance - s * pr0.distance).abs() < 1e-9 * s.max(1.0) + 1e-10);
        // Closest against samples of the triangle.
        let m = 40;
        for i in 0..=m {
            for j in 0..=(m - i) {
                let (a, b) = (i as f64 / m as f64, j as f64 / m as f64);
                let y = [0, 1, 2].map(|k| x[0][k] + a * e1[k] + b * e2[k]);
                prop_assert!(pr0.distance <= norm(sub(p, y)) + 1e-12);
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// (c) clipping and mortar quadrature against analytic areas and moments
// ---------------------------------------------------------------------------------------

/// Exact moments of a counter-clockwise polygon, [1, x, y, x², xy, y², x³, x²y],
/// by the Green's theorem (shoelace-type) formulas, with cᵢ = xᵢ yᵢ₊₁ − xᵢ₊₁ yᵢ:
/// ∫1 = ½Σc, ∫x = ⅙Σ(xᵢ+xᵢ₊₁)c, ∫x² = 1/12 Σ(xᵢ²+xᵢxᵢ₊₁+xᵢ₊₁²)c,
/// ∫xy = 1/24 Σ(xᵢyᵢ₊₁+2xᵢyᵢ+2xᵢ₊₁yᵢ₊₁+xᵢ₊₁yᵢ)c, ∫x³ = 1/20 Σ(xᵢ³+xᵢ²xᵢ₊₁+xᵢxᵢ₊₁²+xᵢ₊₁³)c,
/// ∫x²y = 1/60 Σ c (xᵢ₊₁²(3yᵢ₊₁+yᵢ) + 2xᵢxᵢ₊₁(yᵢ+yᵢ₊₁) + xᵢ²(3yᵢ+yᵢ₊₁)).
fn polygon_moments(poly: &[[f64; 2]]) -> [f64; 8] {
    let mut m = [0.0; 8];
    let n = poly.len();
    for i in 0..n {
        let [x0, y0] = poly[i];
        let [x1, y1] = poly[(i + 1) % n];
        let c = x0 * y1 - x1 * y0;
        m[0] += c / 2.0;
        m[1] += (x0 + x1) * c / 6.0;
        m[2] += (y0 + y1) * c / 6.0;
        m[3] += (x0 * x0 + x0 * x1 + x1 * x1) * c / 12.0;
        m[4] += (x0 * y1 + 2.0 * x0 * y0 + 2.0 * x1 * y1 + x1 * y0) * c / 24.0;
        m[5] += (y0 * y0 + y0 * y1 + y1 * y1) * c / 12.0;
        m[6] += (x0 * x0 * x0 + x0 * x0 * x1 + x0 * x1 * x1 + x1 * x1 * x1) * c / 20.0;
        m[7] += (x1 * x1 * (3.0 * y1 + y0) + 2.0 * x0 * x1 * (y0 + y1) + x0 * x0 * (3.0 * y0 + y1))
            * c
            / 60.0;
    }
    m
}

/// The same moments by the mortar points of faces a (side A) and b.
fn quadrature_moments(a: &[V3], b: &[V3], order: usize) -> [f64; 8] {
    let mut m = [0.0; 8];
    for pt in segments_face_face(a, b, order) {
        let [x, y, _] = pt.x_a;
        let f = [1.0, x, y, x * x, x * y, y * y, x * x * x, x * x * y];
        for k in 0..8 {
            m[k] += pt.weight * f[k];
        }
    }
    m
}

fn rect(x0: f64, y0: f64, x1: f64, y1: f64, z: f64) -> Vec<V3> {
    vec![[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]]
}

fn close_moments(got: &[f64; 8], want: &[f64; 8], upto: usize, tol: f64) -> bool {
    (0..upto).all(|k| (got[k] - want[k]).abs() <= tol * (1.0 + want[k].abs()))
}

/// Points on an ellipse at sorted angles: a convex polygon, counter-clockwise.
fn convex_polygon(n: usize) -> impl Strategy<Value = Vec<[f64; 2]>> {
    (
        prop::collection::vec(0.0..1.0f64, n),
        0.3..2.0f64,
        0.3..2.0f64,
        prop::array::uniform2(-1.0..1.0f64),
    )
        .prop_map(move |(mut t, ra, rb, c)| {
            t.sort_by(f64::total_cmp);
            // Spread the angles so no two nodes coincide.
            t.iter()
                .enumerate()
                .map(|(k, u)| {
                    let ang = std::f64::consts::TAU * (k as f64 + 0.8 * u) / n as f64;
                    [c[0] + ra * ang.cos(), c[1] + rb * ang.sin()]
                })
                .collect()
        })
}

fn lift(p: &[[f64; 2]], z: f64) -> Vec<V3> {
    p.iter().map(|q| [q[0], q[1], z]).collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn overlap_is_symmetric_and_weights_sum_to_it(
        pa in prop_oneof![convex_polygon(3), convex_polygon(4)],
        pb in prop_oneof![convex_polygon(3), convex_polygon(4)],
        flip_b in any::<bool>(),
        order in prop_oneof![Just(1usize), Just(2), Just(3), Just(5), Just(7)],
    ) {
        let a = lift(&pa, 0.0);
        let mut b = lift(&pb, 0.0);
        if flip_b {
            b.reverse(); // facing the other way, as a contact partner
        }
        let ab = overlap_area_face_face(&a, &b);
        let ba = overlap_area_face_face(&b, &a);
        prop_assert!((ab - ba).abs() <= 1e-14 * (1.0 + ab));
        prop_assert!(ab <= signed_area_polygon(&pa) + 1e-14 && ab <= signed_area_polygon(&pb).abs() + 1e-14);
        let pts = segments_face_face(&a, &b, order);
        let w: f64 = pts.iter().map(|p| p.weight).sum();
        prop_assert!((w - ab).abs() <= 1e-14 * (1.0 + ab));
        for p in &pts {
            prop_assert!(p.weight > 0.0 && p.gap.abs() < 1e-14);
            prop_assert!(norm(sub(p.x_a, p.x_b)) < 1e-13);
        }
        // The 2-D clip itself is orientation-robust and counter-clockwise.
        let c = clip_polygon_polygon(&pb, &pa);
        let mut pbr = pb.clone();
        pbr.reverse();
        let mut par = pa.clone();
        par.reverse();
        let cr = clip_polygon_polygon(&pbr, &par);
        prop_assert!(signed_area_polygon(&c) >= 0.0 && signed_area_polygon(&cr) >= 0.0);
        prop_assert!((signed_area_polygon(&c) - signed_area_polygon(&cr)).abs() <= 1e-14 * (1.0 + ab));
    }

    #[test]
    fn rectangles_overlap_exactly_with_exact_moments(
        r1 in (prop::array::uniform2(-2.0..2.0f64), prop::array::uniform2(0.1..3.0f64)),
        r2 in (prop::array::uniform2(-2.0..2.0f64), prop::array::uniform2(0.1..3.0f64)),
        gap in -0.5..0.5f64,
    ) {
        let (c1, e1) = r1;
        let (c2, e2) = r2;
        let a = rect(c1[0], c1[1], c1[0] + e1[0], c1[1] + e1[1], 0.0);
        // B faces A (reversed winding) at height `gap` above it.
        let mut b = rect(c2[0], c2[1], c2[0] + e2[0], c2[1] + e2[1], gap);
        b.reverse();
        let lo = [c1[0].max(c2[0]), c1[1].max(c2[1])];
        let hi = [(c1[0] + e1[0]).min(c2[0] + e2[0]), (c1[1] + e1[1]).min(c2[1] + e2[1])];
        let exact = (hi[0] - lo[0]).max(0.0) * (hi[1] - lo[1]).max(0.0);
        let area = overlap_area_face_face(&a, &b);
        prop_assert!((area - exact).abs() <= 1e-14 * (1.0 + exact), "{area} vs {exact}");
        if hi[0] - lo[0] > 1e-9 && hi[1] - lo[1] > 1e-9 {
            let want = polygon_moments(&[lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]]);
            // Degree 2 rule: exact up to quadratics; degree 5: up to cubics.
            prop_assert!(close_moments(&quadrature_moments(&a, &b, 2), &want, 6, 1e-13));
            prop_assert!(close_moments(&quadrature_moments(&a, &b, 5), &want, 8, 1e-13));
            for p in segments_face_face(&a, &b, 1) {
                prop_assert!((p.gap - gap).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn triangle_inside_big_square_gives_its_area_and_moments(
        t in prop::array::uniform3(prop::array::uniform2(-3.0..3.0f64)),
        as_side_a in any::<bool>(),
    ) {
        let mut tri = t.to_vec();
        let area = signed_area_polygon(&tri);
        prop_assume!(area.abs() > 1e-3);
        if area < 0.0 {
            tri.reverse();
        }
        let square = rect(-5.0, -5.0, 5.0, 5.0, 0.0);
        let tri3 = lift(&tri, 0.0);
        let got = if as_side_a {
            overlap_area_face_face(&tri3, &square)
        } else {
            overlap_area_face_face(&square, &tri3)
        };
        prop_assert!((got - area.abs()).abs() <= 1e-13);
        let want = polygon_moments(&tri);
        let (fa, fb) = if as_side_a { (&tri3, &square) } else { (&square, &tri3) };
        prop_assert!(close_moments(&quadrature_moments(fa, fb, 1), &want, 3, 1e-13));
        prop_assert!(close_moments(&quadrature_moments(fa, fb, 2), &want, 6, 1e-13));
        prop_assert!(close_moments(&quadrature_moments(fa, fb, 3), &want, 8, 1e-13));
        prop_assert!(close_moments(&quadrature_moments(fa, fb, 8), &want, 8, 1e-13));
    }

    #[test]
    fn tilted_planar_b_gives_linear_gap_and_points_on_b(
        slope in prop::array::uniform2(-0.5..0.5f64),
        z0 in -0.3..0.3f64,
        order in 1usize..6,
    ) {
        // B: the plane z = z0 + sx x + sy y over [0.2, 1.4]²; A the unit square at z = 0.
        let a = rect(0.0, 0.0, 1.0, 1.0, 0.0);
        let h = |x: f64, y: f64| z0 + slope[0] * x + slope[1] * y;
        let b: Vec<V3> = rect(0.2, 0.2, 1.4, 1.4, 0.0)
            .into_iter()
            .rev()
            .map(|p| [p[0], p[1], h(p[0], p[1])])
            .collect();
        let pts = segments_face_face(&a, &b, order);
        let w: f64 = pts.iter().map(|p| p.weight).sum();
        prop_assert!((w - 0.64).abs() < 1e-14);
        for p in &pts {
            prop_assert!((p.gap - h(p.x_a[0], p.x_a[1])).abs() < 1e-14);
            prop_assert!((p.x_b[2] - h(p.x_b[0], p.x_b[1])).abs() < 1e-14);
            prop_assert!((p.x_b[0] - p.x_a[0]).abs() < 1e-14 && (p.x_b[1] - p.x_a[1]).abs() < 1e-14);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn warped_face_against_its_offset_copy(
        x in quad_strategy(),
        s in -0.3..0.3f64,
        q in quaternion(),
        t in prop::array::uniform3(-10.0..10.0f64),
        order in 1usize..6,
    ) {
        // B is A moved by s along A's unit vector-area normal n (same node order, so B
        // faces the same way). Exact: the overlap is A's projected area |½ d₁ × d₂|, and
        // every line along n meets B exactly s beyond A, so each gap is s.
        let r = rotation(q);
        let a = x.map(|v| apply(&r, t, 1.0, v));
        let d1 = sub(a[2], a[0]);
        let d2 = sub(a[3], a[1]);
        let va = [
            0.5 * (d1[1] * d2[2] - d1[2] * d2[1]),
            0.5 * (d1[2] * d2[0] - d1[0] * d2[2]),
            0.5 * (d1[0] * d2[1] - d1[1] * d2[0]),
        ];
        let area = norm(va);
        let n = va.map(|c| c / area);
        let b = a.map(|v| [v[0] + s * n[0], v[1] + s * n[1], v[2] + s * n[2]]);
        prop_assert!((overlap_area_face_face(&a, &b) - area).abs() < 1e-13);
        let pts = segments_face_face(&a, &b, order);
        let w: f64 = pts.iter().map(|p| p.weight).sum();
        prop_assert!((w - area).abs() < 1e-13);
        for p in &pts {
            prop_assert!((p.gap - s).abs() < 1e-12, "{p:?}");
            // Same shape: the same parametric point on both faces.
            prop_assert!((p.xi_a[0] - p.xi_b[0]).abs() < 1e-11 && (p.xi_a[1] - p.xi_b[1]).abs() < 1e-11);
            prop_assert!(norm(sub(p.x_a, map_quad4(&a, p.xi_a))) < 1e-12);
            prop_assert!(p.xi_a.iter().all(|v| v.abs() <= 1.0 + 1e-12));
        }
    }
}

// ---------------------------------------------------------------------------------------
// (d) and (e): non-matching tilings of the unit square
// ---------------------------------------------------------------------------------------

/// Faces of a grid on [0,1]² with interior lines at `xs`, `ys` (sorted, in (0, 1)).
fn grid(xs: &[f64], ys: &[f64], z: f64) -> Vec<Vec<V3>> {
    let mut gx = vec![0.0];
    gx.extend_from_slice(xs);
    gx.push(1.0);
    let mut gy = vec![0.0];
    gy.extend_from_slice(ys);
    gy.push(1.0);
    let mut faces = Vec::new();
    for j in 0..gy.len() - 1 {
        for i in 0..gx.len() - 1 {
            faces.push(rect(gx[i], gy[j], gx[i + 1], gy[j + 1], z));
        }
    }
    faces
}

fn uniform_lines(n: usize) -> Vec<f64> {
    (1..n).map(|k| k as f64 / n as f64).collect()
}

#[test]
fn square_against_7x3_grid_sums_to_one() {
    let a = rect(0.0, 0.0, 1.0, 1.0, 0.0);
    let b = grid(&uniform_lines(7), &uniform_lines(3), 0.0);
    let area: f64 = b.iter().map(|f| overlap_area_face_face(&a, f)).sum();
    assert!((area - 1.0).abs() <= 1e-14, "{area}");
    let w: f64 = b
        .iter()
        .flat_map(|f| segments_face_face(&a, f, 2))
        .map(|p| p.weight)
        .sum();
    assert!((w - 1.0).abs() <= 1e-14, "{w}");
}

#[test]
fn grid_3x2_against_grid_7x3_sums_to_one_with_exact_moments() {
    let a = grid(&uniform_lines(3), &uniform_lines(2), 0.0);
    let b = grid(&uniform_lines(7), &uniform_lines(3), 0.0);
    let mut area = 0.0;
    let mut m = [0.0; 8];
    // The buffer-reusing variant over all pairs gives the same points as per-pair calls.
    let rule = rule_triangle(3);
    let mut all = Vec::new();
    let mut per_pair = Vec::new();
    for fa in &a {
        for fb in &b {
            area += overlap_area_face_face(fa, fb);
            let q = quadrature_moments(fa, fb, 3);
            for k in 0..8 {
                m[k] += q[k];
            }
            let n = segments_face_face_into(fa, fb, &rule, &mut all);
            let pts = segments_face_face(fa, fb, 3);
            assert_eq!(n, pts.len());
            per_pair.extend(pts);
        }
    }
    assert_eq!(all, per_pair);
    assert!((area - 1.0).abs() <= 1e-14, "{area}");
    // Moments of the unit square: ∫x = ½, ∫x² = ⅓, ∫xy = ¼, ∫x³ = ¼, ∫x²y = ⅙.
    let want = [1.0, 0.5, 0.5, 1.0 / 3.0, 0.25, 1.0 / 3.0, 0.25, 1.0 / 6.0];
    assert!(close_moments(&m, &want, 8, 1e-14), "{m:?}");
}

fn lines(n: usize) -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.01..0.99f64, n).prop_map(|mut v| {
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    #[test]
    fn random_tilings_sum_to_one_and_snapped_points_project_inside(
        ax in lines(2), ay in lines(1), bx in lines(6), by in lines(2),
        q in quaternion(),
        t in prop::array::uniform3(-3.0..3.0f64),
    ) {
        let a = grid(&ax, &ay, 0.0);
        let b = grid(&bx, &by, 0.0);
        let mut area = 0.0;
        let mut w = 0.0;
        for fa in &a {
            for fb in &b {
                area += overlap_area_face_face(fa, fb);
                w += segments_face_face(fa, fb, 1).iter().map(|p| p.weight).sum::<f64>();
            }
        }
        prop_assert!((area - 1.0).abs() <= 1e-14, "{area}");
        prop_assert!((w - 1.0).abs() <= 1e-14, "{w}");

        // (e) Nodes and edge points of A's grid snapped onto B's grid lines: in the plane
        // they project with distance 0 and inside at least one face of B, also after a
        // rigid motion of everything (distance then at round-off of the motion).
        let r = rotation(q);
        let mut probes: Vec<V3> = Vec::new();
        let mut gx = vec![0.0];
        gx.extend(&bx);
        gx.push(1.0);
        let mut gy = vec![0.0];
        gy.extend(&by);
        gy.push(1.0);
        for &x in &gx {
            for &y in &gy {
                probes.push([x, y, 0.0]); // vertices of B
            }
            for &y in ay.iter().chain(&[0.5]) {
                probes.push([x, y, 0.0]); // on a vertical edge line of B
            }
        }
        for &y in &gy {
            for &x in ax.iter().chain(&[0.5]) {
                probes.push([x, y, 0.0]); // on a horizontal edge line of B
            }
        }
        for (moved, tol) in [(false, 0.0), (true, 1e-14)] {
            let tf = |v: V3| if moved { apply(&r, t, 1.0, v) } else { v };
            for p in &probes {
                let p = tf(*p);
                let hit = b.iter().any(|f| {
                    let x = [tf(f[0]), tf(f[1]), tf(f[2]), tf(f[3])];
                    let pr = project_point_quad4(p, &x);
                    pr.inside && pr.distance <= tol
                });
                prop_assert!(hit, "probe {p:?} (moved {moved}) found no face");
            }
        }
    }
}

// ---------------------------------------------------------------------------------------
// (e) 2-D: edges (Line2) — projection against sampled distances and rigid motions of the
// plane, 1-D overlaps against interval arithmetic and the monomials' exact integrals
// ---------------------------------------------------------------------------------------

/// A rotation by `angle` about z, then a translation and a scaling, in the xy plane.
fn apply_2d(angle: f64, t: [f64; 2], s: f64, p: V3) -> V3 {
    let (c, n) = (angle.cos(), angle.sin());
    [
        s * (c * p[0] - n * p[1]) + t[0],
        s * (n * p[0] + c * p[1]) + t[1],
        0.0,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn line2_projection_is_closest_and_rigid_in_the_plane(
        a in prop::array::uniform2(-1.0..1.0f64),
        b in prop::array::uniform2(-1.0..1.0f64),
        p in prop::array::uniform2(-2.0..2.0f64),
        angle in -3.2..3.2f64,
        t in prop::array::uniform2(-100.0..100.0f64),
        s in prop_oneof![0.01..1.0f64, 1.0..100.0f64],
    ) {
        let x = [[a[0], a[1], 0.0], [b[0], b[1], 0.0]];
        let p = [p[0], p[1], 0.0];
        prop_assume!(norm(sub(x[1], x[0])) > 0.05);
        let pr = project_point_line2(p, &x);
        prop_assert!(!pr.degenerate && pr.xi[0].abs() <= 1.0 && pr.xi[1] == 0.0);
        // The closest point of the closed edge, against 400 samples of it.
        for k in 0..=400 {
            let y = map_line2(&x, [-1.0 + k as f64 / 200.0, 0.0]);
            prop_assert!(pr.distance <= norm(sub(p, y)) + 1e-12);
        }
        // |gap| is the distance when the foot lies on the edge; its sign is the side of
        // the normal (t_y, −t_x).
        let n = normal_line2(&x);
        prop_assert!((norm(n) - 1.0).abs() < 1e-14);
        if pr.inside {
            prop_assert!((pr.gap.abs() - pr.distance).abs() < 1e-12);
        }
        // A rigid motion and scaling of the plane: the same ξ, gap scaled by s.
        let m = |v: V3| apply_2d(angle, t, s, v);
        let pr1 = project_point_line2(m(p), &[m(x[0]), m(x[1])]);
        prop_assert!((pr1.xi[0] - pr.xi[0]).abs() < 1e-9, "{pr:?} {pr1:?}");
        prop_assert!((pr1.gap - s * pr.gap).abs() < 1e-9 * s.max(1.0) + 1e-10);
        // `inside` too, unless the foot lies at an end (within round-off of the tolerance).
        let e = sub(x[1], x[0]);
        let c = [0.5 * (x[0][0] + x[1][0]), 0.5 * (x[0][1] + x[1][1]), 0.0];
        let free = 2.0 * (sub(p, c)[0] * e[0] + sub(p, c)[1] * e[1]) / (e[0] * e[0] + e[1] * e[1]);
        if (free.abs() - 1.0).abs() > 1e-6 {
            prop_assert_eq!(pr1.inside, pr.inside);
            prop_assert_eq!(pr.inside, free.abs() <= 1.0);
        }
    }

    #[test]
    fn edges_overlap_as_intervals_with_exact_moments(
        a0 in -2.0..2.0f64, la in 0.1..2.0f64,
        b0 in -2.0..2.0f64, lb in 0.1..2.0f64,
        gap in -0.5..0.5f64,
        flip_b in any::<bool>(),
        order in 1usize..9,
    ) {
        // A along +x at y = 0 (normal −y); B on y = −gap (open when gap > 0), either way.
        let a = [[a0, 0.0, 0.0], [a0 + la, 0.0, 0.0]];
        let mut b = [[b0, -gap, 0.0], [b0 + lb, -gap, 0.0]];
        if flip_b {
            b.reverse();
        }
        let (lo, hi) = (a0.max(b0), (a0 + la).min(b0 + lb));
        let want = (hi - lo).max(0.0);
        prop_assert!((overlap_length_line_line(&a, &b) - want).abs() < 1e-14);
        let mut pts = Vec::new();
        segments_line_line_into(&a, &b, &rule_line(order), &mut pts);
        prop_assert_eq!(pts.is_empty(), want == 0.0);
        // ∫ x^p over [lo, hi], exact up to the rule's degree.
        for p in 0..=order as i32 {
            let got: f64 = pts.iter().map(|m| m.weight * m.x_a[0].powi(p)).sum();
            let exact = if want > 0.0 {
                (hi.powi(p + 1) - lo.powi(p + 1)) / (p + 1) as f64
            } else {
                0.0
            };
            prop_assert!((got - exact).abs() <= 1e-12 * (1.0 + exact.abs()), "x^{p}: {got} vs {exact}");
        }
        for m in &pts {
            prop_assert!((m.gap - gap).abs() < 1e-14);
            prop_assert!((m.x_b[0] - m.x_a[0]).abs() < 1e-13);
            prop_assert!((map_line2(&b, m.xi_b)[0] - m.x_a[0]).abs() < 1e-13);
        }
    }
}
