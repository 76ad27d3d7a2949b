//! Fingerprints of contact searches: every field of every point, the contact fractions
//! and the statistics, hashed (FNV-1a over the bits), for a set of cases that walk the
//! search's paths (planar and warped quads, curved rings, triangles, 2-D edges, a
//! tangential tolerance and a subdomain), quadrature orders 1 and 2 and segment orders
//! 1 and 2, full search and pairing alone. Two builds of the search that print the same
//! lines give the same bits. Run: `cargo bench --bench search_hash` (`-- quick` for
//! 1e4-face cases; `threads=N` for the thread count).

#[path = "common/mod.rs"]
mod common;

use seam::mesh::Mesh;
use seam::mesh::generate::{self, BoxSpec, RectSpec};
use seam::search::SearchSettings;
use seam::search::pairing::{Integration, SearchResult, Searcher, Sphere, SurfaceGeometry};

struct Fnv(u64);

impl Fnv {
    fn new() -> Fnv {
        Fnv(0xcbf2_9ce4_8422_2325)
    }
    fn u64(&mut self, v: u64) {
        for b in v.to_le_bytes() {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(0x0100_0000_01b3);
        }
    }
    fn f(&mut self, v: f64) {
        self.u64(v.to_bits());
    }
    fn opt(&mut self, v: Option<u32>) {
        self.u64(v.map_or(u64::MAX, u64::from));
    }
    fn optf(&mut self, v: Option<f64>) {
        match v {
            Some(v) => self.f(v),
            None => self.u64(u64::MAX - 1),
        }
    }
}

fn fingerprint(r: &SearchResult) -> u64 {
    let mut h = Fnv::new();
    for p in r.points.iter() {
        h.opt(p.a_face);
        h.opt(p.a_node);
        p.xi_a.iter().for_each(|v| h.f(*v));
        p.x.iter().for_each(|v| h.f(*v));
        h.f(p.weight);
        h.u64(p.status as u64);
        h.opt(p.b_face);
        p.xi_b.iter().for_each(|v| h.f(*v));
        h.f(p.gap);
        h.f(p.offset);
        p.normal_a.iter().for_each(|v| h.f(*v));
        p.normal_b.iter().for_each(|v| h.f(*v));
    }
    for f in &r.contact_fraction {
        h.f(*f);
    }
    let s = &r.stats;
    for n in [
        s.points,
        s.matched,
        s.unmatched,
        s.rejected_distance,
        s.rejected_angle,
        s.rejected_subdomain,
    ] {
        h.u64(n as u64);
    }
    h.f(s.overlap_area);
    h.f(s.side_a_area);
    h.optf(s.gap_min);
    h.optf(s.gap_max);
    h.0
}

/// Two slabs, n×n cells under m×m (m ≈ 0.9 n), side B lifted by `lift`.
fn planar(n: usize, tet: bool, lift: f64) -> Mesh {
    let m = (n as f64 * 0.9).round() as usize;
    let spec = |min, max, cells, id| {
        if tet {
            BoxSpec::tet(min, max, cells, id)
        } else {
            BoxSpec::hex(min, max, cells, id)
        }
    };
    generate::boxes(
        &[
            spec([0.0; 3], [1.0, 1.0, 0.1], [n, n, 1], 1).with_side_sets([0, 0, 0, 0, 0, 1]),
            spec([0.0, 0.0, 0.1 + lift], [1.0, 1.0, 0.2], [m, m, 1], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    )
}

/// 2-D: two rectangles, n cells under m along the interface, tied at y = 1.
fn edges(n: usize) -> Mesh {
    let m = (n as f64 * 0.9).round() as usize;
    generate::rectangles(
        &[
            RectSpec::quad([0.0, 0.0], [1.0, 1.0], [n, 4], 1).with_side_sets([0, 0, 0, 1]),
            RectSpec::quad([0.0, 1.0], [1.0, 1.2], [m, 4], 2).with_side_sets([0, 0, 2, 0]),
        ],
        false,
    )
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "quick");
    let threads: usize = args
        .iter()
        .find_map(|a| a.strip_prefix("threads=").and_then(|t| t.parse().ok()))
        .unwrap_or(1);
    let faces = if quick { 10_000 } else { 100_000 };
    let n = (faces as f64).sqrt().round() as usize;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap();
    let mut cases: Vec<(&str, Mesh, SearchSettings, Option<Sphere>)> = vec![
        (
            "planar",
            planar(n, false, 0.0),
            SearchSettings::defaults(3),
            None,
        ),
        (
            "curved",
            common::rings(faces),
            SearchSettings::defaults(3),
            None,
        ),
    ];
    // Warped quads: both slabs' faces on z = 0.1 + a wave, side B 0.0003 above.
    let mut warped = planar(n, false, 0.0003);
    for x in &mut warped.coords {
        if x[2] > 0.05 && x[2] < 0.15 {
            x[2] += 0.01 * (7.0 * x[0]).sin() * (5.0 * x[1] + 0.3).cos();
        }
    }
    cases.push(("warped", warped, SearchSettings::defaults(3), None));
    cases.push((
        "tet",
        planar(n / 3, true, 0.001),
        SearchSettings::defaults(3),
        None,
    ));
    let mut loose = SearchSettings::defaults(3);
    loose.tangential_tolerance = 0.05;
    loose.field_factor = 0.5;
    cases.push((
        "loose",
        planar(n, false, 0.0005),
        loose,
        Some(Sphere {
            center: [0.5, 0.4, 0.1],
            radius: 0.35,
        }),
    ));
    cases.push((
        "edges",
        edges(faces / 10),
        SearchSettings::defaults(2),
        None,
    ));
    for (label, mesh, settings, subdomain) in &cases {
        let a = SurfaceGeometry::from_side_set(mesh, 0).unwrap();
        let b = SurfaceGeometry::from_side_set(mesh, 1).unwrap();
        pool.install(|| {
            let searcher = Searcher::new(&b, settings);
            for integration in [
                Integration::Quadrature { order: 1 },
                Integration::Quadrature { order: 2 },
                Integration::Segments { order: 1 },
                Integration::Segments { order: 2 },
            ] {
                for full in [true, false] {
                    let r = if full {
                        searcher.search(&a, &b, settings, integration, *subdomain)
                    } else {
                        searcher.search_points(&a, &b, settings, integration, *subdomain)
                    };
                    println!(
                        "{label:<7} {:>7} {integration:?} {} points {} matched {} overlap {:.17e} hash {:016x}",
                        a.faces.len(),
                        if full { "full" } else { "pair" },
                        r.stats.points,
                        r.stats.matched,
                        r.stats.overlap_area,
                        fingerprint(&r)
                    );
                }
            }
        });
    }
}
