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

use rayon::prelude::*;
use serde::Serialize;

use super::bvh::{Aabb, Bvh};
use super::mortar::{overlap_area_face_face, rule_triangle, segments_face_face_into};
use super::project::{
    map_quad4, map_tri3, project_point_quad4, project_point_tri3, vector_area_quad4,
};
use super::settings::{Overclosure, SearchSettings};
use crate::fem::quadrature::gauss_legendre;
use crate::mesh::{Mesh, NodeId, Side};
use crate::periodic::PeriodicMap;
use crate::script::ScriptError;
use crate::surface::{ContactSurface, SurfaceKind};

use crate::vec3::{V3, add, cross, dot, norm, scale, sub};

/// One face as coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceGeom {
    /// The mesh side it came from.
    pub side: Side,
    /// Node count: 3 or 4 (2-D edges are not searched yet).
    pub len: u8,
    pub nodes: [NodeId; 4],
    pub x: [V3; 4],
}

impl FaceGeom {
    pub fn coords(&self) -> &[V3] {
        &self.x[..self.len as usize]
    }

    /// Vector area (normal × area).
    pub fn vector_area(&self) -> V3 {
        match self.len {
            3 => {
                let c = cross(sub(self.x[1], self.x[0]), sub(self.x[2], self.x[0]));
                scale(c, 0.5)
            }
            _ => {
                let q = [self.x[0], self.x[1], self.x[2], self.x[3]];
                vector_area_quad4(&q)
            }
        }
    }

    pub fn area(&self) -> f64 {
        norm(self.vector_area())
    }

    pub fn normal(&self) -> V3 {
        let v = self.vector_area();
        let n = norm(v);
        if n > 0.0 { scale(v, 1.0 / n) } else { [0.0; 3] }
    }

    pub fn centroid(&self) -> V3 {
        let k = self.len as usize;
        let mut c = [0.0; 3];
        for p in self.coords() {
            c = add(c, *p);
        }
        scale(c, 1.0 / k as f64)
    }

    fn aabb(&self) -> Aabb {
        Aabb::from_points(self.coords())
    }

    fn map(&self, xi: [f64; 2]) -> V3 {
        match self.len {
            3 => map_tri3(&[self.x[0], self.x[1], self.x[2]], xi),
            _ => map_quad4(&[self.x[0], self.x[1], self.x[2], self.x[3]], xi),
        }
    }
}

/// The faces (or nodes) of one surface, as coordinates.
#[derive(Clone, Debug, Default)]
pub struct SurfaceGeometry {
    pub name: String,
    pub faces: Vec<FaceGeom>,
    /// For node surfaces: the nodes and their coordinates.
    pub nodes: Vec<(NodeId, V3)>,
    /// For node surfaces, per node (parallel to `nodes`): its tributary area
    /// `A_i = Σ_f ∫_f N_i dA` and unit normal `n_i ∝ Σ_f ∫_f N_i n dA` over the tributary
    /// faces around it (zero area and normal for a node on none). See
    /// [`SurfaceGeometry::tributary_of_nodes`].
    pub node_area: Vec<f64>,
    pub node_normal: Vec<V3>,
    /// For node surfaces: the faces the areas and normals come from (not searched).
    pub tributary: Vec<FaceGeom>,
}

/// Why a surface cannot be searched.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SearchError {
    #[error("surface `{0}` is made of edges (a 2-D mesh): 2-D contact search is not supported yet")]
    TwoDimensional(String),
    #[error("periodic map of surface `{surface}`: {source}")]
    Map {
        surface: String,
        source: ScriptError,
    },
}

impl SurfaceGeometry {
    /// The geometry of a built surface on coordinates `coords` (the mesh's, or moved
    /// ones); shell faces are lofted along their normal by their `loft`.
    pub fn from_surface(
        mesh: &Mesh,
        surface: &ContactSurface,
        coords: &[V3],
    ) -> Result<Self, SearchError> {
        let mut out = SurfaceGeometry {
            name: surface.name.clone(),
            ..Default::default()
        };
        if surface.kind == SurfaceKind::Nodes {
            out.nodes = surface
                .nodes
                .iter()
                .map(|&n| (n, coords[n.index()]))
                .collect();
            for &side in &surface.tributary {
                let g = face_geom(mesh, side, coords);
                // Edges (2-D meshes) are not searched; as tributaries they give nothing.
                if g.len >= 3 {
                    out.tributary.push(g);
                }
            }
            out.tributary_of_nodes();
            return Ok(out);
        }
        out.faces.reserve(surface.faces.len());
        for f in &surface.faces {
            let mut g = face_geom(mesh, f.side, coords);
            if g.len == 2 {
                return Err(SearchError::TwoDimensional(surface.name.clone()));
            }
            if f.loft != 0.0 {
                let n = g.normal();
                for p in &mut g.x[..g.len as usize] {
                    *p = add(*p, scale(n, f.loft));
                }
            }
            out.faces.push(g);
        }
        Ok(out)
    }

    /// Each node's tributary area and normal from the tributary faces (module docs of
    /// `enforce::interface`, node-to-face form): `A_i = Σ_f ∫_f N_i dA`, the row sum of the
    /// face mass matrix, so `Σ_i A_i` is the faces' area and a constant flux q gives
    /// `Σ_i A_i q = q A` exactly; `n_i = Σ_f ∫_f N_i n dA`, normalised. Tri3 faces are
    /// flat (`∫ N_i = A/3`); Quad4 faces use the 2×2 Gauss rule of the bilinear map, exact
    /// for `N_i |J|` on flat faces (N_i bilinear, |J| bilinear) and for `N_i J` on warped
    /// ones (both of degree ≤ 2 in each coordinate).
    pub fn tributary_of_nodes(&mut self) {
        let index: std::collections::HashMap<NodeId, usize> = self
            .nodes
            .iter()
            .enumerate()
            .map(|(k, &(n, _))| (n, k))
            .collect();
        let mut area = vec![0.0; self.nodes.len()];
        let mut vector = vec![[0.0; 3]; self.nodes.len()];
        for f in &self.tributary {
            let len = f.len as usize;
            // A triangle's N_i is linear and its Jacobian constant: the centroid rule is
            // exact.
            let rule: Vec<([f64; 2], f64)> = if len == 3 {
                vec![([1.0 / 3.0, 1.0 / 3.0], 0.5)]
            } else {
                let (g, w) = gauss_legendre(2);
                [(0, 0), (1, 0), (1, 1), (0, 1)]
                    .map(|(i, j)| ([g[i], g[j]], w[i] * w[j]))
                    .to_vec()
            };
            for &(xi, w) in &rule {
                let j = face_normal_jacobian(f, xi);
                let shapes = face_shapes(len, xi);
                for (node, shape) in f.nodes.iter().zip(shapes).take(len) {
                    let Some(&i) = index.get(node) else {
                        continue;
                    };
                    let wn = w * shape;
                    area[i] += wn * norm(j);
                    vector[i] = add(vector[i], scale(j, wn));
                }
            }
        }
        self.node_normal = vector
            .iter()
            .map(|&v| {
                let l = norm(v);
                if l > 0.0 { scale(v, 1.0 / l) } else { [0.0; 3] }
            })
            .collect();
        self.node_area = area;
    }

    /// The geometry of side set `set` of the mesh taken whole as a surface, on the
    /// mesh's coordinates (for hosts and tests that name their interface faces directly).
    pub fn from_side_set(mesh: &Mesh, set: usize) -> Result<Self, SearchError> {
        let ss = &mesh.side_sets[set];
        let surface = ContactSurface {
            name: ss.sierra_name(),
            kind: SurfaceKind::Faces,
            faces: ss
                .sides
                .iter()
                .map(|&side| crate::surface::SurfaceFace {
                    side,
                    loft: 0.0,
                    origin: 0,
                })
                .collect(),
            tributary: Vec::new(),
            nodes: Vec::new(),
            origins: Vec::new(),
            parent: None,
        };
        Self::from_surface(mesh, &surface, &mesh.coords)
    }

    /// The image of this surface under a periodic map, named `name`.
    pub fn mapped(&self, map: &mut dyn PeriodicMap, name: &str) -> Result<Self, SearchError> {
        let fail = |source| SearchError::Map {
            surface: self.name.clone(),
            source,
        };
        let mut out = self.clone();
        out.name = name.to_string();
        for f in &mut out.faces {
            for p in &mut f.x[..f.len as usize] {
                *p = map.map_point(*p).map_err(fail)?;
            }
        }
        for (_, p) in &mut out.nodes {
            *p = map.map_point(*p).map_err(fail)?;
        }
        for f in &mut out.tributary {
            for p in &mut f.x[..f.len as usize] {
                *p = map.map_point(*p).map_err(fail)?;
            }
        }
        if !out.nodes.is_empty() {
            out.tributary_of_nodes();
        }
        Ok(out)
    }

    /// The area of the faces, or for a node surface the sum of its nodes' tributary areas.
    pub fn area(&self) -> f64 {
        self.faces.iter().map(FaceGeom::area).sum::<f64>() + self.node_area.iter().sum::<f64>()
    }

    /// Mean face size (√area), the length scale of the search tolerances.
    pub fn mean_face_size(&self) -> f64 {
        if self.faces.is_empty() {
            return 0.0;
        }
        self.faces.iter().map(|f| f.area().sqrt()).sum::<f64>() / self.faces.len() as f64
    }
}

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
    /// Index of the side-A face in its [`SurfaceGeometry`] (`u32::MAX` for a node point).
    pub a_face: u32,
    /// Index of the side-A node for node surfaces, else `u32::MAX`.
    pub a_node: u32,
    pub xi_a: [f64; 2],
    /// The point on side A.
    pub x: V3,
    /// Integration weight (area); a node point's tributary area.
    pub weight: f64,
    pub status: PointStatus,
    /// Index of the side-B face (`u32::MAX` when unmatched).
    pub b_face: u32,
    pub xi_b: [f64; 2],
    /// Signed gap, positive when open.
    pub gap: f64,
    /// Initial gap recorded by `Initial Overclosure = Store Offsets` (the enforcement
    /// sees `gap − offset`); 0 otherwise.
    pub offset: f64,
    pub normal_a: V3,
    pub normal_b: V3,
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
    pub points: Vec<ContactPoint>,
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

/// One chunk's points and, per face, (matched weight, total weight, overlap area).
type ChunkOut = (Vec<ContactPoint>, Vec<(f64, f64, f64)>);

/// Side-A faces per parallel chunk: large enough to amortise scheduling, fixed so
/// results never depend on the thread count.
const CHUNK: usize = 512;

impl Searcher {
    /// Build the tree over `b`'s faces for `settings`.
    pub fn new(b: &SurfaceGeometry, settings: &SearchSettings) -> Searcher {
        let margin = margin_for(b, settings);
        let boxes: Vec<Aabb> = b.faces.iter().map(|f| f.aabb().inflate(margin)).collect();
        let largest = max_face_size(b);
        let reach = settings
            .normal_tolerance
            .unwrap_or(0.0)
            .max(settings.field_factor * largest)
            + settings.tangential_tolerance * largest;
        Searcher {
            bvh: Bvh::build(&boxes),
            margin,
            reach: reach.min(margin),
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
        // Faces, in fixed chunks, in parallel; each chunk gives its points and, per face,
        // the matched weight, total weight and overlap area.
        let chunks: Vec<ChunkOut> = (0..a.faces.len())
            .step_by(CHUNK)
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(|start| {
                let end = (start + CHUNK).min(a.faces.len());
                let mut points = Vec::new();
                let mut per_face = Vec::with_capacity(end - start);
                let mut scratch = Vec::new();
                for fa in start..end {
                    let before = points.len();
                    match integration {
                        Integration::Quadrature { order } => {
                            ctx.quadrature_points(a, fa, order, &mut points)
                        }
                        Integration::Segments { order } => {
                            ctx.segment_points(a, fa, order, &mut points, &mut scratch)
                        }
                    }
                    let (mut hit, mut total) = (0.0, 0.0);
                    for p in &points[before..] {
                        total += p.weight;
                        if p.status == PointStatus::Matched {
                            hit += p.weight;
                        }
                    }
                    let area = if overlap || matches!(integration, Integration::Segments { .. }) {
                        ctx.overlap_of(a, fa, &points[before..], integration)
                    } else {
                        0.0
                    };
                    per_face.push((hit, total, area));
                }
                (points, per_face)
            })
            .collect();
        for (points, per_face) in chunks {
            result.points.extend(points);
            for (hit, total, overlap) in per_face {
                result
                    .contact_fraction
                    .push(if total > 0.0 { hit / total } else { 0.0 });
                result.stats.overlap_area += overlap;
            }
        }
        for k in 0..a.nodes.len() {
            let p = ctx.pair_node(a, k);
            if overlap && p.status == PointStatus::Matched {
                // A node surface's covered area: its matched nodes' tributary areas.
                result.stats.overlap_area += p.weight;
            }
            result.points.push(p);
        }
        result.stats.side_a_area = a.area();
        tally(&mut result);
        result
    }
}

/// The search margin: the larger of the distance acceptance and the buffer (mean face
/// size × buffer factor), so the box query never misses an acceptable face.
fn margin_for(b: &SurfaceGeometry, s: &SearchSettings) -> f64 {
    let size = b.mean_face_size();
    let distance = s
        .normal_tolerance
        .unwrap_or(0.0)
        .max(s.field_factor * max_face_size(b));
    (size * s.buffer_factor).max(distance)
}

fn max_face_size(b: &SurfaceGeometry) -> f64 {
    b.faces.iter().map(|f| f.area().sqrt()).fold(0.0, f64::max)
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
        for p in &mut self.points {
            if p.a_face != u32::MAX {
                let fa = &a.faces[p.a_face as usize];
                p.x = fa.map(p.xi_a);
                p.normal_a = fa.normal();
            } else if let Some((_, x)) = a.nodes.get(p.a_node as usize) {
                let k = p.a_node as usize;
                p.x = *x;
                p.weight = a.node_area.get(k).copied().unwrap_or(0.0);
                p.normal_a = a.node_normal.get(k).copied().unwrap_or([0.0; 3]);
            }
            if p.status != PointStatus::Matched {
                continue;
            }
            let fb = &b.faces[p.b_face as usize];
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
        for p in &mut self.points {
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

fn tally(r: &mut SearchResult) {
    let s = &mut r.stats;
    s.points = r.points.len();
    for p in &r.points {
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

struct Ctx<'a> {
    bvh: &'a Bvh,
    margin: f64,
    reach2: f64,
    b: &'a SurfaceGeometry,
    settings: &'a SearchSettings,
    subdomain: Option<Sphere>,
    cos_check: f64,
    cos_opposed: Option<f64>,
}

/// The best acceptable side-B face for one point so far, and the best reason for
/// rejection otherwise. `found` is ranked by (projected outside the face, |gap|, face
/// index): a face that has the point inside beats one accepted only by the tangential
/// tolerance.
struct Best {
    found: Option<Candidate>,
    rejected: PointStatus,
}

/// (rank key: outside, |gap|, face), ξ_B, gap, n_B.
type Candidate = ((bool, f64, u32), [f64; 2], f64, V3);

impl Ctx<'_> {
    /// Side-B faces whose own box comes within the reach of `face`'s box, ascending.
    fn face_candidates(&self, face: &FaceGeom, out: &mut Vec<usize>) {
        out.clear();
        let reach = self.reach2.sqrt();
        let near = face.aabb().inflate(reach);
        let m = self.margin;
        self.bvh.query_with_box(&face.aabb(), |j, inflated| {
            let own = Aabb {
                min: inflated.min.map(|v| v + m),
                max: inflated.max.map(|v| v - m),
            };
            if own.intersects(&near) {
                out.push(j);
            }
        });
        out.sort_unstable();
    }

    fn distance_limit(&self, face: &FaceGeom) -> f64 {
        self.settings
            .normal_tolerance
            .unwrap_or(self.settings.field_factor * face.area().sqrt())
    }

    /// Normals acceptable? `n_a` zero (node points) skips the test.
    fn normals_ok(&self, n_a: V3, n_b: V3) -> bool {
        if n_a == [0.0; 3] {
            return true;
        }
        let c = dot(n_a, n_b);
        // angle(n_b, −n_a) ≤ check angle  ⇔  −c ≥ cos(check).
        if -c < self.cos_check {
            return false;
        }
        // angle(n_a, n_b) ≥ threshold  ⇔  c ≤ cos(threshold).
        self.cos_opposed.is_none_or(|limit| c <= limit + 1e-12)
    }

    fn outside(&self, x: V3) -> bool {
        self.subdomain.is_some_and(|s| {
            let d = sub(x, s.center);
            dot(d, d) > s.radius * s.radius
        })
    }

    /// Pair one point `x` with normal `n_a` against side B.
    fn pair(&self, x: V3, n_a: V3) -> Best {
        let mut best = Best {
            found: None,
            rejected: PointStatus::Unmatched,
        };
        let query = Aabb::from_point(x);
        let m = self.margin;
        self.bvh.query_with_box(&query, |j, inflated| {
            // The face's own box is the tree's box less the margin.
            let own = Aabb {
                min: inflated.min.map(|v| v + m),
                max: inflated.max.map(|v| v - m),
            };
            if own.distance2_to_point(x) > self.reach2 {
                return;
            }
            let face = &self.b.faces[j];
            let pr = match face.len {
                3 => project_point_tri3(x, &[face.x[0], face.x[1], face.x[2]]),
                _ => project_point_quad4(x, &[face.x[0], face.x[1], face.x[2], face.x[3]]),
            };
            if pr.degenerate || !(pr.inside || self.within_tangential(face, &pr.point, x)) {
                return;
            }
            if !self.normals_ok(n_a, pr.normal) {
                best.rejected = PointStatus::RejectedAngle;
                return;
            }
            if pr.gap.abs() > self.distance_limit(face) {
                if best.rejected != PointStatus::RejectedAngle {
                    best.rejected = PointStatus::RejectedDistance;
                }
                return;
            }
            let key = (!pr.inside, pr.gap.abs(), j as u32);
            if best.found.is_none_or(|(k, ..)| key < k) {
                best.found = Some((key, pr.xi, pr.gap, pr.normal));
            }
        });
        best
    }

    /// A point that did not project inside may still pair if it lies within the
    /// tangential tolerance (× face size) of the face, measured in the face's plane.
    fn within_tangential(&self, face: &FaceGeom, closest: &V3, x: V3) -> bool {
        let t = self.settings.tangential_tolerance * face.area().sqrt();
        if t <= 0.0 {
            return false;
        }
        let n = face.normal();
        let d = sub(x, *closest);
        let tangential = sub(d, scale(n, dot(d, n)));
        norm(tangential) <= t
    }

    fn point(
        &self,
        a_face: u32,
        a_node: u32,
        xi_a: [f64; 2],
        x: V3,
        w: f64,
        n_a: V3,
    ) -> ContactPoint {
        let mut p = ContactPoint {
            a_face,
            a_node,
            xi_a,
            x,
            weight: w,
            status: PointStatus::Unmatched,
            b_face: u32::MAX,
            xi_b: [0.0; 2],
            gap: 0.0,
            offset: 0.0,
            normal_a: n_a,
            normal_b: [0.0; 3],
        };
        if self.outside(x) {
            p.status = PointStatus::RejectedSubdomain;
            return p;
        }
        let best = self.pair(x, n_a);
        match best.found {
            Some(((_, _, j), xi_b, gap, n_b)) => {
                p.status = PointStatus::Matched;
                p.b_face = j;
                p.xi_b = xi_b;
                p.gap = gap;
                p.normal_b = n_b;
            }
            None => p.status = best.rejected,
        }
        p
    }

    /// A node point: its tributary area is its weight, its normal that of the faces
    /// around it (zero for a node on none, which skips the angle test).
    fn pair_node(&self, a: &SurfaceGeometry, k: usize) -> ContactPoint {
        let x = a.nodes[k].1;
        let w = a.node_area.get(k).copied().unwrap_or(0.0);
        let n = a.node_normal.get(k).copied().unwrap_or([0.0; 3]);
        self.point(u32::MAX, k as u32, [0.0; 2], x, w, n)
    }

    fn quadrature_points(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        order: usize,
        out: &mut Vec<ContactPoint>,
    ) {
        let face = &a.faces[fa];
        let n_a = face.normal();
        for (xi, w) in face_rule(face, order) {
            let x = face.map(xi);
            let jac = face_jacobian(face, xi);
            out.push(self.point(fa as u32, u32::MAX, xi, x, w * jac, n_a));
        }
    }

    fn segment_points(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        order: usize,
        out: &mut Vec<ContactPoint>,
        scratch: &mut Vec<super::mortar::MortarPoint>,
    ) {
        let face = &a.faces[fa];
        let n_a = face.normal();
        let rule = rule_triangle(order);
        let mut candidates = Vec::new();
        self.face_candidates(face, &mut candidates);
        let outside = self.outside(face.centroid());
        for j in candidates {
            let fb = &self.b.faces[j];
            scratch.clear();
            segments_face_face_into(face.coords(), fb.coords(), &rule, scratch);
            if scratch.is_empty() {
                continue;
            }
            let n_b = fb.normal();
            let angle_ok = self.normals_ok(n_a, n_b);
            let limit = self.distance_limit(fb);
            for m in scratch.iter() {
                let status = if outside {
                    PointStatus::RejectedSubdomain
                } else if !angle_ok {
                    PointStatus::RejectedAngle
                } else if m.gap.abs() > limit {
                    PointStatus::RejectedDistance
                } else {
                    PointStatus::Matched
                };
                out.push(ContactPoint {
                    a_face: fa as u32,
                    a_node: u32::MAX,
                    xi_a: m.xi_a,
                    x: m.x_a,
                    weight: m.weight,
                    status,
                    b_face: j as u32,
                    xi_b: m.xi_b,
                    gap: m.gap,
                    offset: 0.0,
                    normal_a: n_a,
                    normal_b: n_b,
                });
            }
        }
    }

    /// Overlap area of side-A face `fa` with side B. In segment mode the matched points'
    /// weights sum to it exactly. In quadrature mode it is the clipped overlap with every
    /// side-B face the pairing would accept for that face: opposed normals, and a
    /// centroid within the acceptance distance of the face's plane.
    fn overlap_of(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        points: &[ContactPoint],
        integration: Integration,
    ) -> f64 {
        if let Integration::Segments { .. } = integration {
            return points
                .iter()
                .filter(|p| p.status == PointStatus::Matched)
                .map(|p| p.weight)
                .sum();
        }
        let face = &a.faces[fa];
        if self.outside(face.centroid()) {
            return 0.0;
        }
        let (n_a, c_a) = (face.normal(), face.centroid());
        let mut area = 0.0;
        let mut candidates = Vec::new();
        self.face_candidates(face, &mut candidates);
        for j in candidates {
            let fb = &self.b.faces[j];
            if !self.normals_ok(n_a, fb.normal())
                || dot(sub(fb.centroid(), c_a), n_a).abs() > self.distance_limit(fb)
            {
                continue;
            }
            area += overlap_area_face_face(face.coords(), fb.coords());
        }
        area
    }
}

/// One face of the mesh as coordinates (unlofted).
fn face_geom(mesh: &Mesh, side: Side, coords: &[V3]) -> FaceGeom {
    let mut g = FaceGeom {
        side,
        len: 0,
        nodes: [NodeId(0); 4],
        x: [[0.0; 3]; 4],
    };
    for (k, n) in mesh.side_nodes(side).enumerate().take(4) {
        g.nodes[k] = n;
        g.x[k] = coords[n.index()];
        g.len += 1;
    }
    g
}

/// Shape functions of a Tri3 (`len` 3) or Quad4 face at `xi`, Exodus node order (the
/// fourth value is 0 for a triangle).
pub(crate) fn face_shapes(len: usize, xi: [f64; 2]) -> [f64; 4] {
    let (s, t) = (xi[0], xi[1]);
    if len == 3 {
        [1.0 - s - t, s, t, 0.0]
    } else {
        [
            0.25 * (1.0 - s) * (1.0 - t),
            0.25 * (1.0 + s) * (1.0 - t),
            0.25 * (1.0 + s) * (1.0 + t),
            0.25 * (1.0 - s) * (1.0 + t),
        ]
    }
}

/// ∂x/∂ξ × ∂x/∂η at ξ: the face's area Jacobian times its unit normal.
fn face_normal_jacobian(face: &FaceGeom, xi: [f64; 2]) -> V3 {
    let x = &face.x;
    match face.len {
        3 => cross(sub(x[1], x[0]), sub(x[2], x[0])),
        _ => {
            let (s, t) = (xi[0], xi[1]);
            let d_xi: V3 = std::array::from_fn(|d| {
                0.25 * (-(1.0 - t) * x[0][d] + (1.0 - t) * x[1][d] + (1.0 + t) * x[2][d]
                    - (1.0 + t) * x[3][d])
            });
            let d_eta: V3 = std::array::from_fn(|d| {
                0.25 * (-(1.0 - s) * x[0][d] - (1.0 + s) * x[1][d]
                    + (1.0 + s) * x[2][d]
                    + (1.0 - s) * x[3][d])
            });
            cross(d_xi, d_eta)
        }
    }
}

/// Gauss rule on a face's reference element: (ξ, weight on the reference element).
fn face_rule(face: &FaceGeom, order: usize) -> Vec<([f64; 2], f64)> {
    match face.len {
        3 => {
            // Weights relative to the area, which is 1/2 on the reference triangle.
            rule_triangle(order.max(1))
                .points
                .iter()
                .map(|&(xi, w)| (xi, w * 0.5))
                .collect()
        }
        _ => {
            let (xs, ws) = gauss_legendre(order.clamp(1, 3));
            let mut out = Vec::with_capacity(xs.len() * xs.len());
            for (j, &eta) in xs.iter().enumerate() {
                for (i, &xi) in xs.iter().enumerate() {
                    out.push(([xi, eta], ws[i] * ws[j]));
                }
            }
            out
        }
    }
}

/// |∂x/∂ξ × ∂x/∂η| at ξ: the area Jacobian of the face's map.
fn face_jacobian(face: &FaceGeom, xi: [f64; 2]) -> f64 {
    match face.len {
        3 => 2.0 * face.area(),
        _ => norm(face_normal_jacobian(face, xi)),
    }
}
