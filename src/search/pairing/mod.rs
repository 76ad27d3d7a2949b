//! The contact search of one interaction: side-A points paired with side-B faces.
//!
//! Entry points: [`SurfaceGeometry`] (the faces of a surface as coordinates: lofted,
//! or mapped to a periodic image), [`Searcher`] (a BVH over the side-B faces, refitted
//! when only coordinates move) and [`Searcher::search`], which returns a
//! [`SearchResult`]: one [`ContactPoint`] per side-A integration point (or mortar
//! segment point) with its side-B face, parametric coordinates, gap and normals, and
//! the statistics an analyst needs to trust it.
//!
//! A node surface (contact node set, `Contact Type = node`) gives one point per node,
//! weighted by its tributary area and carrying its normal
//! ([`SurfaceGeometry::tributary_of_nodes`]), whatever the integration mode.
//!
//! Two integration modes ([`Integration`]): `Quadrature` places Gauss points on each
//! side-A face and projects each onto side B (fast; not exact on non-matching meshes);
//! `Segments` clips every side-A face against the side-B faces projected onto it and
//! places points on the overlap polygons (exact for polynomials of the rule's degree).
//!
//! Acceptance of a side-B face for a point, in this order:
//! 1. the point projects inside the face (within its tangential tolerance);
//! 2. normals: the side-B normal makes at most `normal_check_angle` with the opposite of
//!    the side-A normal, and (unless culling is disabled) at least
//!    `opposed_normal_threshold_angle` with the side-A normal;
//! 3. distance: |gap| ≤ the normal tolerance, or, without one, ≤ field factor × the
//!    target face's size (√area).
//!
//! Among accepted faces one that has the point inside beats one accepted by the
//! tangential tolerance only; then the smallest |gap| wins, ties going to the lowest
//! face index, so
//! a point on a shared edge or vertex is paired exactly once, the same way every run.
//! Gaps are positive when open (side A lies on the side side B's normal points to).
//! Results do not depend on the number of threads: side-A faces are processed in fixed
//! chunks whose results are concatenated in order.
//!
//! The parts: `geometry` (faces as coordinates, the reference-face helpers) and `points`
//! (the acceptance tests and best face of each point of a chunk); this file holds the
//! result types, the [`Searcher`] and its schedule.

mod geometry;
mod points;

pub(crate) use geometry::face_shapes;
pub use geometry::{FaceGeom, SearchError, SurfaceGeometry};

use std::sync::Arc;

use rayon::prelude::*;
use serde::Serialize;

use super::bvh::{Aabb, Bvh};
use super::settings::{Overclosure, SearchSettings};
use crate::vec3::{V3, dot, scale, sub};

use points::{Ctx, FaceTally, Rules, Scratch};

/// The highest integration order accepted from input. A segment rule of order p on a
/// triangle has ((p + 2)/2)² points built in O(p³) work, so an order in the thousands
/// would run for hours per segment; 20 integrates polynomials far beyond any contact
/// law's.
pub const MAX_ORDER: usize = 20;

/// How side-A points are placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Integration {
    /// Gauss points of each side-A face (order 1: centroid; 2: 3-point triangle and
    /// 2×2 quad; 3+: 6-point triangle and 3×3 quad), each projected onto side B.
    Quadrature { order: usize },
    /// Points of the overlap polygons of side-A faces with side-B faces, exact for
    /// polynomials of degree `order`.
    Segments { order: usize },
}

/// Outcome of one side-A point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PointStatus {
    Matched,
    /// No side-B face within the search box had the point inside it.
    Unmatched,
    /// A face had the point inside, but too far along the normal.
    RejectedDistance,
    /// A face had the point inside, but its normal was not opposed enough.
    RejectedAngle,
    /// The point lies outside the `Restrict Contact To Subdomain` sphere.
    RejectedSubdomain,
}

/// One side-A point and its pairing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactPoint {
    /// Index of the side-A face in its [`SurfaceGeometry`] (`None` for a node point).
    pub a_face: Option<u32>,
    /// Index of the side-A node for node surfaces (`None` for a face point).
    pub a_node: Option<u32>,
    pub xi_a: [f64; 2],
    /// The point on side A.
    pub x: V3,
    /// Integration weight (area); a node point's tributary area.
    pub weight: f64,
    pub status: PointStatus,
    /// Index of the side-B face (`None` when unmatched).
    pub b_face: Option<u32>,
    pub xi_b: [f64; 2],
    /// Signed gap, positive when open.
    pub gap: f64,
    /// Initial gap recorded by `Initial Overclosure = Store Offsets` (the enforcement
    /// sees `gap − offset`); 0 otherwise.
    pub offset: f64,
    pub normal_a: V3,
    pub normal_b: V3,
}

impl ContactPoint {
    /// The side-B face of a matched point.
    pub fn matched_b_face(&self) -> Option<usize> {
        match (self.status, self.b_face) {
            (PointStatus::Matched, Some(j)) => Some(j as usize),
            _ => None,
        }
    }

    /// (side-A face, side-B face) of a matched face point.
    pub fn matched_faces(&self) -> Option<(usize, usize)> {
        Some((self.a_face? as usize, self.matched_b_face()?))
    }

    /// (side-A node, side-B face) of a matched node point.
    pub fn matched_node(&self) -> Option<(usize, usize)> {
        Some((self.a_node? as usize, self.matched_b_face()?))
    }
}

/// Counts and measures of one interaction's search.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SearchStats {
    pub points: usize,
    pub matched: usize,
    pub unmatched: usize,
    pub rejected_distance: usize,
    pub rejected_angle: usize,
    pub rejected_subdomain: usize,
    /// Area of side A covered by side B (clipped overlap polygons of matched pairs; for
    /// a node surface, the tributary areas of its matched nodes).
    pub overlap_area: f64,
    pub side_a_area: f64,
    /// Over matched points; `None` when nothing matched.
    pub gap_min: Option<f64>,
    pub gap_max: Option<f64>,
}

/// The pairing of one interaction.
#[derive(Clone, Debug, Default)]
pub struct SearchResult {
    /// Shared, not copied, by the clones of a result (the run's and its embedding's):
    /// at 1e6 points they are 150 MB. A change to one clone's points copies them
    /// ([`Arc::make_mut`]).
    pub points: Arc<Vec<ContactPoint>>,
    pub stats: SearchStats,
    /// Per side-A face: the fraction (0…1) of its integration weight that is matched
    /// (`Visualize Contact`).
    pub contact_fraction: Vec<f64>,
}

/// A sphere outside which points take no part.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sphere {
    pub center: V3,
    pub radius: f64,
}

/// The side-B half of a search: a BVH over the faces, kept between searches.
pub struct Searcher {
    bvh: Bvh,
    /// Box inflation: the search buffer (mean face size × buffer factor, or more).
    margin: f64,
    /// The farthest a point may be from a face's own box and still pair with it (the
    /// largest distance acceptance plus the tangential tolerance): candidates beyond it
    /// are skipped before the (much dearer) projection.
    reach: f64,
}

/// One chunk's points and its faces' tallies.
type ChunkOut = (Vec<ContactPoint>, Vec<FaceTally>);

/// Side-A faces per parallel chunk: large enough to amortise scheduling, fixed so
/// results never depend on the thread count.
const CHUNK: usize = 512;

impl Searcher {
    /// Build the tree over `b`'s faces for `settings`.
    pub fn new(b: &SurfaceGeometry, settings: &SearchSettings) -> Searcher {
        let extent = Extent::of(b.mean_face_size(), max_face_size(b), settings);
        Searcher::with_extent(b, extent)
    }

    /// Build the tree over `b`'s faces with a given extent: that of a larger surface of
    /// which `b` holds the faces near the points to be searched (a distributed search,
    /// whose ranks hold parts of side B), so that the pairing is the larger one's.
    pub fn with_extent(b: &SurfaceGeometry, extent: Extent) -> Searcher {
        let margin = extent.margin;
        let boxes: Vec<Aabb> = (b.faces.par_iter())
            .map(|f| f.aabb().inflate(margin))
            .collect();
        Searcher {
            bvh: Bvh::build(&boxes),
            margin,
            reach: extent.reach,
        }
    }

    /// The side-B faces moved (same faces, new coordinates): refit the tree.
    pub fn refit(&mut self, b: &SurfaceGeometry) {
        let boxes: Vec<Aabb> = b
            .faces
            .iter()
            .map(|f| f.aabb().inflate(self.margin))
            .collect();
        self.bvh.refit(&boxes);
    }

    /// Pair `a`'s points with `b`'s faces.
    pub fn search(
        &self,
        a: &SurfaceGeometry,
        b: &SurfaceGeometry,
        settings: &SearchSettings,
        integration: Integration,
        subdomain: Option<Sphere>,
    ) -> SearchResult {
        self.run(a, b, settings, integration, subdomain, true)
    }

    /// [`Self::search`] without the overlap-area diagnostic (`stats.overlap_area` stays
    /// 0 in quadrature mode): the pairing alone, for callers that redo it every step.
    pub fn search_points(
        &self,
        a: &SurfaceGeometry,
        b: &SurfaceGeometry,
        settings: &SearchSettings,
        integration: Integration,
        subdomain: Option<Sphere>,
    ) -> SearchResult {
        self.run(a, b, settings, integration, subdomain, false)
    }

    fn run(
        &self,
        a: &SurfaceGeometry,
        b: &SurfaceGeometry,
        settings: &SearchSettings,
        integration: Integration,
        subdomain: Option<Sphere>,
        overlap: bool,
    ) -> SearchResult {
        let ctx = Ctx {
            bvh: &self.bvh,
            margin: self.margin,
            reach2: self.reach * self.reach,
            b,
            settings,
            subdomain,
            cos_check: settings.normal_check_angle.to_radians().cos(),
            cos_opposed: settings
                .cull_opposed_normals
                .then(|| settings.opposed_normal_threshold_angle.to_radians().cos()),
        };
        let mut result = SearchResult::default();
        let mut points: Vec<ContactPoint> = Vec::new();
        let rules = Rules::new(integration, a.axisymmetric);
        // Faces, in fixed chunks, in parallel; each chunk gives its points and, per face,
        // the matched weight, total weight and overlap area. Quadrature faces have a
        // known number of points each, so they are written straight into the result
        // (one allocation, no copy); mortar segments come in per chunk.
        let per_face = match &rules {
            Rules::Quadrature(_) => {
                let counts: Vec<usize> = (a.faces.iter())
                    .map(|f| rules.quadrature(f.len).len())
                    .collect();
                let total: usize = counts.iter().sum();
                // Room for the points, left unwritten here: each chunk's thread writes its
                // own (once, and the first touch of fresh memory happens in parallel).
                points = Vec::with_capacity(total + a.nodes.len());
                let mut rest = &mut points.spare_capacity_mut()[..total];
                let mut slices = Vec::with_capacity(a.faces.len().div_ceil(CHUNK));
                for start in (0..a.faces.len()).step_by(CHUNK) {
                    let end = (start + CHUNK).min(a.faces.len());
                    let (head, tail) = rest.split_at_mut(counts[start..end].iter().sum());
                    slices.push((start, end, head));
                    rest = tail;
                }
                // One thread's scratch serves the chunks it takes (`map_init`): its
                // buffers and side-B faces' data are kept from chunk to chunk.
                let chunks: Vec<_> = slices
                    .into_par_iter()
                    .map_init(Scratch::default, |scratch, (start, end, slice)| {
                        let (written, per_face) =
                            ctx.quadrature_faces(a, start..end, &rules, overlap, slice, scratch);
                        (slice.len() - written, per_face)
                    })
                    .collect();
                // Every chunk wrote as many points as its faces' rules have (`counts`).
                assert!(chunks.iter().all(|(short, _)| *short == 0));
                // SAFETY: the first `total` slots were cut into the chunks' slices, in
                // order and without gaps, and each chunk wrote every slot of its slice
                // (`quadrature_faces` writes one per point of each face's rule, `counts`).
                unsafe { points.set_len(total) };
                chunks.into_iter().map(|(_, f)| f).collect::<Vec<_>>()
            }
            Rules::Segments { line, triangle } => {
                let chunks: Vec<ChunkOut> = (0..a.faces.len())
                    .step_by(CHUNK)
                    .collect::<Vec<_>>()
                    .into_par_iter()
                    .map(|start| {
                        let end = (start + CHUNK).min(a.faces.len());
                        let mut points = Vec::new();
                        let mut per_face = Vec::with_capacity(end - start);
                        let mut scratch = Scratch::default();
                        for fa in start..end {
                            let before = points.len();
                            ctx.segment_points(a, fa, (line, triangle), &mut points, &mut scratch);
                            // The matched points' weights sum to the overlap exactly.
                            let area = points[before..]
                                .iter()
                                .filter(|p| p.status == PointStatus::Matched)
                                .map(|p| p.weight)
                                .sum();
                            let (hit, total) = face_weights(&points[before..]);
                            per_face.push(FaceTally {
                                hit,
                                total,
                                area,
                                measure: a.faces[fa].measure(a.axisymmetric),
                            });
                        }
                        (points, per_face)
                    })
                    .collect();
                let total: usize = chunks.iter().map(|(points, _)| points.len()).sum();
                points.reserve_exact(total + a.nodes.len());
                let mut per_face = Vec::with_capacity(chunks.len());
                for (chunk, faces) in chunks {
                    points.extend(chunk);
                    per_face.push(faces);
                }
                per_face
            }
        };
        // The chunks' tallies, face after face.
        let per_face = || per_face.iter().flatten();
        result.contact_fraction.reserve_exact(a.faces.len());
        for f in per_face() {
            result
                .contact_fraction
                .push(if f.total > 0.0 { f.hit / f.total } else { 0.0 });
            result.stats.overlap_area += f.area;
        }
        // `a.area()`, from the measures the faces' tallies hold: the same terms in the
        // same order.
        let faces_area: f64 = per_face().map(|f| f.measure).sum();
        let side_a_area = faces_area + a.node_area.iter().sum::<f64>();
        for k in 0..a.nodes.len() {
            let p = ctx.pair_node(a, k);
            if overlap && p.status == PointStatus::Matched {
                // A node surface's covered area: its matched nodes' tributary areas.
                result.stats.overlap_area += p.weight;
            }
            points.push(p);
        }
        result.points = Arc::new(points);
        result.stats.side_a_area = side_a_area;
        tally(&mut result);
        result
    }
}

/// A face's matched weight and total weight, from its `points`.
fn face_weights(points: &[ContactPoint]) -> (f64, f64) {
    let (mut hit, mut total) = (0.0, 0.0);
    for p in points {
        total += p.weight;
        if p.status == PointStatus::Matched {
            hit += p.weight;
        }
    }
    (hit, total)
}

/// How far a search looks from each side-B face, fixed by side B's face sizes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    /// Box inflation: the larger of the distance acceptance and the buffer (mean face
    /// size × buffer factor), so the box query never misses an acceptable face.
    pub margin: f64,
    /// The farthest a point may be from a face's own box and still pair with it (the
    /// largest distance acceptance plus the tangential tolerance), at most the margin.
    pub reach: f64,
}

impl Extent {
    /// The extent of a side B whose faces have mean size `mean` and largest size
    /// `largest` ([`FaceGeom::size`]).
    pub fn of(mean: f64, largest: f64, s: &SearchSettings) -> Extent {
        let distance = s
            .normal_tolerance
            .unwrap_or(0.0)
            .max(s.field_factor * largest);
        let margin = (mean * s.buffer_factor).max(distance);
        let reach = distance + s.tangential_tolerance * largest;
        Extent {
            margin,
            reach: reach.min(margin),
        }
    }
}

/// The largest face size of `b` ([`FaceGeom::size`]), 0 without faces.
pub fn max_face_size(b: &SurfaceGeometry) -> f64 {
    b.faces.iter().map(FaceGeom::size).fold(0.0, f64::max)
}

/// `Update Search Every n Steps`: a full search on the first step and every n-th step
/// after it; on the steps between, the pairing is kept and only the geometry is
/// refreshed ([`SearchResult::update_geometry`], [`Searcher::refit`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SearchSchedule {
    every: u32,
}

impl SearchSchedule {
    /// `None` (no such line) searches every step.
    pub fn new(every: Option<u32>) -> Self {
        SearchSchedule {
            every: every.unwrap_or(1).max(1),
        }
    }

    /// Whether step `step` (0-based) does a full search.
    pub fn full_search(&self, step: u64) -> bool {
        step.is_multiple_of(u64::from(self.every))
    }
}

impl SearchResult {
    /// Keep the pairing, refresh the geometry: every matched point is placed again at
    /// its parametric coordinates on its side-A face and side-B face of the moved
    /// surfaces, and its gap and normals are measured anew (quadrature points: along
    /// side B's normal; node points likewise). Statistics follow.
    pub fn update_geometry(&mut self, a: &SurfaceGeometry, b: &SurfaceGeometry) {
        for p in Arc::make_mut(&mut self.points) {
            if let Some(f) = p.a_face {
                let fa = &a.faces[f as usize];
                p.x = fa.map(p.xi_a);
                p.normal_a = fa.normal();
            } else if let Some(k) = p.a_node.map(|k| k as usize)
                && let Some((_, x)) = a.nodes.get(k)
            {
                p.x = *x;
                p.weight = a.node_area.get(k).copied().unwrap_or(0.0);
                p.normal_a = a.node_normal.get(k).copied().unwrap_or([0.0; 3]);
            }
            let (PointStatus::Matched, Some(j)) = (p.status, p.b_face) else {
                continue;
            };
            let fb = &b.faces[j as usize];
            let on_b = fb.map(p.xi_b);
            p.normal_b = fb.normal();
            p.gap = dot(sub(p.x, on_b), p.normal_b);
        }
        let (overlap, area) = (self.stats.overlap_area, self.stats.side_a_area);
        self.stats = SearchStats {
            overlap_area: overlap,
            side_a_area: area,
            ..SearchStats::default()
        };
        tally(self);
    }

    /// Apply the initial-overclosure treatment to matched points with a negative gap:
    /// `AdjustNodes` moves the side-A point onto side B along side B's normal (gap 0);
    /// `StoreOffsets` keeps the geometry and records the gap as the point's offset.
    /// Statistics are recomputed.
    pub fn treat_overclosure(&mut self, treatment: Overclosure) {
        for p in Arc::make_mut(&mut self.points) {
            if p.status != PointStatus::Matched || p.gap >= 0.0 {
                continue;
            }
            match treatment {
                Overclosure::AdjustNodes => {
                    p.x = sub(p.x, scale(p.normal_b, p.gap));
                    p.gap = 0.0;
                }
                Overclosure::StoreOffsets => p.offset = p.gap,
            }
        }
        let (overlap, area) = (self.stats.overlap_area, self.stats.side_a_area);
        self.stats = SearchStats {
            overlap_area: overlap,
            side_a_area: area,
            ..SearchStats::default()
        };
        tally(self);
    }
}

/// Count the points of `r` by status and their gap range into its statistics (which
/// must start at their defaults, but for the areas).
pub(crate) fn tally(r: &mut SearchResult) {
    let s = &mut r.stats;
    s.points = r.points.len();
    for p in r.points.iter() {
        match p.status {
            PointStatus::Matched => {
                s.matched += 1;
                s.gap_min = Some(s.gap_min.map_or(p.gap, |g| g.min(p.gap)));
                s.gap_max = Some(s.gap_max.map_or(p.gap, |g| g.max(p.gap)));
            }
            PointStatus::Unmatched => s.unmatched += 1,
            PointStatus::RejectedDistance => s.rejected_distance += 1,
            PointStatus::RejectedAngle => s.rejected_angle += 1,
            PointStatus::RejectedSubdomain => s.rejected_subdomain += 1,
        }
    }
}
