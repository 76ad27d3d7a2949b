//! Benchmark of the search kernels on a planar non-matching interface, on one thread.
//!
//! Side B: an m × m grid of Quad4 faces on the unit square at z = 0, interior nodes
//! jittered by up to ±20 % of the spacing in x and y (so the faces are general planar
//! quads, not parallelograms). Side A: the 2 × 2 Gauss points of a coarser grid of
//! (m/2 + 3)² faces at height z = 1e-3 h (h the spacing of B), about m² points.
//!
//! For m² = 1e4, 1e5, 1e6 faces it reports the BVH build time (median of runs), then the
//! search time per side-A point — query the BVH with the point's box inflated by a
//! search radius, project onto every candidate whose box is nearer than the best point
//! found so far, keep the closest — with the points in three orders: random
//! (shuffled), as generated (row-major) and sorted by a Morton (Z-order) code, whose
//! sort time is reported apart; `+h` marks queries that start from the previous
//! query's leaf (`Bvh::query_with_hint`) instead of the root. Speed comes with error: the
//! largest |gap − z| over all points (the exact gap of a point above the plane z = 0 is
//! its z), the number of points with no face found and the number whose closest face
//! does not hold their foot (`outside`; both must be 0, as B tiles the square).
//!
//! Times are the median and the minimum of 5 passes (the minimum is the better estimate
//! of the kernels' own cost on a machine shared with other work).
//!
//! Run: `cargo bench --bench search_kernels` (add `-- 10000 100000` for chosen sizes).

use std::hint::black_box;
use std::time::Instant;

use seam::search::bvh::{Aabb, Bvh, QueryHint};
use seam::search::project::project_point_quad4;

/// SplitMix64: a small deterministic generator, so every run meshes the same interface.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [-1, 1).
    fn sym(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

struct Interface {
    nodes: Vec<[f64; 3]>,
    faces: Vec<[u32; 4]>,
    h: f64,
}

fn side_b(m: usize, rng: &mut Rng) -> Interface {
    let h = 1.0 / m as f64;
    let mut nodes = Vec::with_capacity((m + 1) * (m + 1));
    for j in 0..=m {
        for i in 0..=m {
            let (mut x, mut y) = (i as f64 * h, j as f64 * h);
            if i > 0 && i < m {
                x += 0.2 * h * rng.sym();
            }
            if j > 0 && j < m {
                y += 0.2 * h * rng.sym();
            }
            nodes.push([x, y, 0.0]);
        }
    }
    let mut faces = Vec::with_capacity(m * m);
    let id = |i: usize, j: usize| (j * (m + 1) + i) as u32;
    for j in 0..m {
        for i in 0..m {
            faces.push([id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    Interface { nodes, faces, h }
}

/// The 2 × 2 Gauss points of an ma × ma grid on the unit square, at height z.
fn side_a_points(ma: usize, z: f64) -> Vec<[f64; 3]> {
    let ha = 1.0 / ma as f64;
    let g = 0.5 / 3f64.sqrt();
    let mut pts = Vec::with_capacity(4 * ma * ma);
    for j in 0..ma {
        for i in 0..ma {
            let (cx, cy) = ((i as f64 + 0.5) * ha, (j as f64 + 0.5) * ha);
            for (sx, sy) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
                pts.push([cx + sx * ha, cy + sy * ha, z]);
            }
        }
    }
    pts
}

fn face_coords(b: &Interface, f: usize) -> [[f64; 3]; 4] {
    b.faces[f].map(|n| b.nodes[n as usize])
}

fn face_boxes(b: &Interface) -> Vec<Aabb> {
    (0..b.faces.len())
        .map(|f| Aabb::from_points(&face_coords(b, f)))
        .collect()
}

/// Spreads the low 21 bits of `v` to every third bit.
fn spread3(v: u64) -> u64 {
    let mut x = v & 0x1f_ffff;
    x = (x | x << 32) & 0x1f_0000_0000_ffff;
    x = (x | x << 16) & 0x1f_0000_ff00_00ff;
    x = (x | x << 8) & 0x100f_00f0_0f00_f00f;
    x = (x | x << 4) & 0x10c3_0c30_c30c_30c3;
    x = (x | x << 2) & 0x1249_2492_4924_9249;
    x
}

/// Sorts points by their 63-bit Morton code in their bounding box.
fn morton_sort(pts: &mut [[f64; 3]]) {
    let b = Aabb::from_points(pts);
    let scale: [f64; 3] =
        std::array::from_fn(|k| ((1u64 << 21) - 1) as f64 / (b.max[k] - b.min[k]).max(1e-300));
    let code = |p: &[f64; 3]| {
        let q: [u64; 3] = std::array::from_fn(|k| ((p[k] - b.min[k]) * scale[k]) as u64);
        spread3(q[0]) | spread3(q[1]) << 1 | spread3(q[2]) << 2
    };
    let mut keyed: Vec<(u64, [f64; 3])> = pts.iter().map(|p| (code(p), *p)).collect();
    keyed.sort_unstable_by_key(|k| k.0);
    for (dst, (_, p)) in pts.iter_mut().zip(keyed) {
        *dst = p;
    }
}

struct SearchStats {
    seconds: f64,
    candidates: usize,
    projections: usize,
    missed: usize,
    outside: usize,
    max_gap_error: f64,
    checksum: f64,
}

/// For every point: query the inflated box, project onto each candidate, keep the
/// closest.
fn search(bvh: &Bvh, b: &Interface, pts: &[[f64; 3]], radius: f64, hinted: bool) -> SearchStats {
    let t = Instant::now();
    let mut candidates = 0;
    let mut projections = 0;
    let mut missed = 0;
    let mut outside = 0;
    let mut max_gap_error = 0.0f64;
    let mut checksum = 0.0;
    let mut hint = QueryHint::default();
    for p in pts {
        let q = Aabb::from_point(*p).inflate(radius);
        let mut best: Option<(usize, f64, f64, bool)> = None;
        let narrow = |f: usize, bx: &Aabb| {
            candidates += 1;
            // A face whose box is no nearer than the best point found cannot win
            // (ties keep the first, as the strict `<` below does).
            if let Some((_, d, _, _)) = best
                && bx.distance2_to_point(*p) >= d * d
            {
                return;
            }
            projections += 1;
            let pr = project_point_quad4(*p, &face_coords(b, f));
            if best.is_none_or(|(_, d, _, _)| pr.distance < d) {
                best = Some((f, pr.distance, pr.gap, pr.inside));
            }
        };
        if hinted {
            bvh.query_with_hint(&mut hint, &q, narrow);
        } else {
            bvh.query_with_box(&q, narrow);
        }
        match best {
            Some((f, _, gap, inside)) => {
                max_gap_error = max_gap_error.max((gap - p[2]).abs());
                // Side B tiles the square that holds every point: the closest face
                // must hold the point's foot.
                outside += usize::from(!inside);
                checksum += f as f64;
            }
            None => missed += 1,
        }
    }
    black_box(checksum);
    SearchStats {
        seconds: t.elapsed().as_secs_f64(),
        candidates,
        projections,
        missed,
        outside,
        max_gap_error,
        checksum,
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let sizes: Vec<usize> = {
        let v: Vec<usize> = std::env::args()
            .skip(1)
            .filter_map(|a| a.parse().ok())
            .collect();
        if v.is_empty() {
            vec![10_000, 100_000, 1_000_000]
        } else {
            v
        }
    };
    println!(
        "{:>9} {:>9} {:>9} {:>8} {:>10} {:>7} {:>7} {:>10} {:>10} {:>10} {:>10} {:>9} {:>6} {:>7} {:>9}",
        "faces",
        "points",
        "build_ms",
        "radius/h",
        "order",
        "cand/pt",
        "proj/pt",
        "ns/pt_med",
        "ns/pt_min",
        "Mpts/s_med",
        "sort_ms",
        "max|gapE|",
        "missed",
        "outside",
        "refit_ms"
    );
    for &n in &sizes {
        let m = (n as f64).sqrt().round() as usize;
        let mut rng = Rng(0x5EA3_0000 + n as u64);
        let b = side_b(m, &mut rng);
        let boxes = face_boxes(&b);
        let runs = if n >= 1_000_000 { 3 } else { 7 };
        let mut build_s = Vec::new();
        let mut bvh = Bvh::build(&boxes);
        for _ in 0..runs {
            let t = Instant::now();
            bvh = black_box(Bvh::build(black_box(&boxes)));
            build_s.push(t.elapsed().as_secs_f64());
        }
        let t = Instant::now();
        bvh.refit(&boxes);
        let refit_s = t.elapsed().as_secs_f64();

        let ma = m / 2 + 3;
        let z = 1e-3 * b.h;
        let generated = side_a_points(ma, z);
        let mut shuffled = generated.clone();
        for i in (1..shuffled.len()).rev() {
            let j = (rng.next_u64() % (i as u64 + 1)) as usize;
            shuffled.swap(i, j);
        }
        let mut sorted = shuffled.clone();
        let t = Instant::now();
        morton_sort(&mut sorted);
        let sort_s = t.elapsed().as_secs_f64();

        for radius_h in [0.1, 0.25] {
            let radius = radius_h * b.h;
            let orders: [(&str, &[[f64; 3]], f64, bool); 5] = [
                ("random", &shuffled, 0.0, false),
                ("random+h", &shuffled, 0.0, true),
                ("generated+h", &generated, 0.0, true),
                ("morton", &sorted, sort_s, false),
                ("morton+h", &sorted, sort_s, true),
            ];
            let mut checks = Vec::new();
            for (name, pts, sort, hinted) in orders {
                let mut times = Vec::new();
                let mut last = None;
                for _ in 0..5 {
                    let s = search(&bvh, &b, pts, radius, hinted);
                    times.push(s.seconds);
                    last = Some(s);
                }
                let s = last.unwrap();
                checks.push(s.checksum);
                let t_min = times.iter().copied().fold(f64::INFINITY, f64::min);
                let t = median(times);
                println!(
                    "{:>9} {:>9} {:>9.2} {:>8} {:>10} {:>7.2} {:>7.2} {:>10.1} {:>10.1} {:>10.2} {:>10.2} {:>9.1e} {:>6} {:>7} {:>9.2}",
                    b.faces.len(),
                    pts.len(),
                    1e3 * median(build_s.clone()),
                    radius_h,
                    name,
                    s.candidates as f64 / pts.len() as f64,
                    s.projections as f64 / pts.len() as f64,
                    1e9 * t / pts.len() as f64,
                    1e9 * t_min / pts.len() as f64,
                    pts.len() as f64 / t / 1e6,
                    1e3 * sort,
                    s.max_gap_error,
                    s.missed,
                    s.outside,
                    1e3 * refit_s,
                );
            }
            // Every order finds the same faces (the sum of face ids agrees).
            assert!(
                checks.iter().all(|c| *c == checks[0]),
                "orders disagree: {checks:?}"
            );
        }
    }
}
