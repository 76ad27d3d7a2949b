//! One chunk of side-A points paired with side B: the candidate faces from the tree,
//! the acceptance tests of the module documentation and the best face per point, for
//! quadrature points, mortar segment points and node points.
//!
//! The tree holds the side-B faces' boxes inflated by the margin. A face farther than
//! the reach from a point cannot pair with it, so every query shrinks the tree's boxes
//! by the margin again and prunes by the reach (`Ctx::near`): a face of side A makes
//! one query, for all its points and its overlap at once, which visits the few faces
//! within the reach instead of the many within the margin. The exact tests on each
//! candidate are those of a query per point, so the pairing does not change.

use crate::search::bvh::{Aabb, Bvh, QueryHint};
use crate::search::cover::Cover;
use crate::search::mortar::{
    FaceOverlap, MortarPoint, TriangleRule, overlap_length_line_line, rule_line, rule_triangle,
    segments_face_face_into, segments_line_line_into,
};
use crate::search::settings::SearchSettings;
use std::mem::MaybeUninit;

use crate::vec3::{V3, dot, norm, scale, sub};

use super::geometry::{FaceGeom, SurfaceGeometry, face_jacobian, face_rule, revolution};
use super::{ContactPoint, Integration, PointStatus, Sphere};

pub(super) struct Ctx<'a> {
    pub(super) bvh: &'a Bvh,
    pub(super) margin: f64,
    pub(super) reach2: f64,
    pub(super) b: &'a SurfaceGeometry,
    pub(super) settings: &'a SearchSettings,
    pub(super) subdomain: Option<Sphere>,
    pub(super) cos_check: f64,
    pub(super) cos_opposed: Option<f64>,
}

/// What the overlap diagnostic asks of a side-B face, made once per thread (see
/// [`BFaces`]) rather than once for each side-A face near it: its unit normal, centroid
/// and acceptance distance ([`Ctx::distance_limit`]), as `FaceGeom` makes them.
#[derive(Clone, Copy, Debug)]
pub(super) struct BFace {
    normal: V3,
    centroid: V3,
    limit: f64,
}

impl BFace {
    pub(super) fn new(face: &FaceGeom, settings: &SearchSettings) -> BFace {
        // One vector area for the normal and the size (`FaceGeom::normal`, `size`).
        let va = face.vector_area();
        let area = norm(va);
        let size = if face.len == 2 { area } else { area.sqrt() };
        BFace {
            normal: if area > 0.0 {
                scale(va, 1.0 / area)
            } else {
                [0.0; 3]
            },
            centroid: face.centroid(),
            limit: settings
                .normal_tolerance
                .unwrap_or(settings.field_factor * size),
        }
    }
}

/// The [`BFace`]s one thread has made, in a direct-mapped table by face index: side-A
/// faces come in mesh order, so the side-B faces near one are near the next ones too, and
/// the table (4096 faces: a few rows of a mesh) holds them while they are wanted. No
/// table for all of side B: one per search, written before it is read, cost a tenth of
/// the search in page faults and made the faces no side-A face overlaps.
#[derive(Default)]
pub(super) struct BFaces {
    tags: Vec<u32>,
    data: Vec<BFace>,
}

impl BFaces {
    const SLOTS: usize = 4096;

    fn get(&mut self, j: usize, face: &FaceGeom, settings: &SearchSettings) -> BFace {
        if self.tags.is_empty() {
            self.tags = vec![u32::MAX; Self::SLOTS];
            self.data = vec![
                BFace {
                    normal: [0.0; 3],
                    centroid: [0.0; 3],
                    limit: 0.0,
                };
                Self::SLOTS
            ];
        }
        let slot = j & (Self::SLOTS - 1);
        // Face indices are below u32::MAX (the tree's bound), so no face matches an
        // empty slot.
        if self.tags[slot] != j as u32 {
            self.data[slot] = BFace::new(face, settings);
            self.tags[slot] = j as u32;
        }
        self.data[slot]
    }
}

/// The best acceptable side-B face for one point so far, and the best reason for
/// rejection otherwise. `found` is ranked by (projected outside the face, |gap|, face
/// index): a face that has the point inside beats one accepted only by the tangential
/// tolerance.
pub(super) struct Best {
    found: Option<Candidate>,
    rejected: PointStatus,
}

/// (rank key: outside, |gap|, face), ξ_B, gap, n_B.
pub(super) type Candidate = ((bool, f64, u32), [f64; 2], f64, V3);

/// The reference rules of one search, made once for all its faces.
pub(super) enum Rules {
    /// Gauss rules of edges, triangles and quads ([`face_rule`]).
    Quadrature([Vec<([f64; 2], f64)>; 3]),
    /// The rules on the overlap intervals of edges and the overlap triangles.
    Segments {
        line: (Vec<f64>, Vec<f64>),
        triangle: TriangleRule,
    },
}

impl Rules {
    pub(super) fn new(integration: Integration, axisymmetric: bool) -> Rules {
        match integration {
            Integration::Quadrature { order } => {
                Rules::Quadrature([2, 3, 4].map(|len| face_rule(len, order)))
            }
            // Edges: a Gauss rule on the overlap interval, one degree higher when the
            // weight carries 2πr, so that it stays exact for the same integrands.
            Integration::Segments { order } => Rules::Segments {
                line: rule_line(order + usize::from(axisymmetric)),
                triangle: rule_triangle(order),
            },
        }
    }

    /// The quadrature rule of a face of `len` nodes (as [`face_rule`]: 2 an edge, 3 a
    /// triangle, else a quad).
    pub(super) fn quadrature(&self, len: u8) -> &[([f64; 2], f64)] {
        match self {
            Rules::Quadrature(r) => &r[usize::from(len.clamp(2, 4)) - 2],
            Rules::Segments { .. } => &[],
        }
    }
}

/// One side-A point of a face: ξ_A, x, weight, outside the subdomain.
type FacePoint = ([f64; 2], V3, f64, bool);

/// A candidate of one point: its place among the group's gathered faces and the squared
/// distance of its own box from the point.
#[derive(Clone, Copy, Debug)]
pub(super) struct Near {
    d2: f64,
    k: u32,
}

/// What a side-A face adds to the search's sums: its points' matched and total weight,
/// its overlap area and its measure ([`FaceGeom::measure`]).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct FaceTally {
    pub(super) hit: f64,
    pub(super) total: f64,
    pub(super) area: f64,
    pub(super) measure: f64,
}

/// The most side-A faces whose candidates one walk of the tree gathers
/// ([`Ctx::quadrature_faces`]).
const GROUP: usize = 8;

/// How far the faces of a group may spread: the extent of their boxes' union at most this
/// many times the first face's extent plus the margin (8 faces in a row of a regular
/// mesh). A mesh's next row starts far away and so starts a new group.
const GROUP_SPREAD: f64 = 4.0;

/// The largest side of a box (0 when empty).
fn extent(b: &Aabb) -> f64 {
    (0..3).fold(0.0, |e: f64, k| e.max(b.max[k] - b.min[k]))
}

/// A side-A face of a group, its points made ([`Ctx::prepare_face`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct GroupFace {
    fa: usize,
    n_a: V3,
    centroid: V3,
    measure: f64,
    area_wanted: bool,
    /// The face's box.
    bounds: Aabb,
    /// Its query box grown for the tree; `None` when it has none (every point outside
    /// the subdomain, and no overlap).
    grown: Option<Aabb>,
    /// Its points in the group's list, from and to.
    points: (usize, usize),
}

/// Buffers of one thread's faces, kept from face to face so that the search allocates
/// only when a face needs more room than any before it.
#[derive(Default)]
pub(super) struct Scratch {
    /// The points of the group's faces.
    points: Vec<FacePoint>,
    /// The group's faces.
    group: Vec<GroupFace>,
    /// Side-B faces (index, tree box) the group's walk gathered.
    gathered: Vec<(usize, Aabb)>,
    /// The face's candidates: those of `gathered` its own query box meets.
    near: Vec<u32>,
    /// One point's candidates among `near`, nearest first.
    order: Vec<Near>,
    /// The overlap's candidates, ascending.
    overlap: Vec<usize>,
    clip: Option<FaceOverlap>,
    /// The test that spares the clipping of a face inside side B.
    cover: Cover,
    /// The side-B faces' overlap data made so far.
    b_faces: BFaces,
    pub(super) mortar: Vec<MortarPoint>,
    /// Where the last face's tree query found its first face.
    hint: QueryHint,
}

impl Ctx<'_> {
    /// Calls `visit(j, tree box)` for (at least) the side-B faces whose own box comes
    /// within the reach of the query box `q`, which every exact test below requires.
    ///
    /// The own box of a face is its tree box shrunk by the margin (`own_box`): it meets
    /// `q` grown by the reach when the tree box meets `q` grown by `reach − margin` (a
    /// shrunk box if negative; the interval tests hold all the same). A node's box holds
    /// its faces' boxes, so testing it prunes nothing that passes. The grown query is
    /// widened by a slack far above the rounding of those sums (ε times the coordinates
    /// near `q`), and the reach by a relative and an absolute slack above the rounding of
    /// the squared distance it is compared as.
    fn near(&self, q: &Aabb, mut visit: impl FnMut(usize, &Aabb)) {
        let grown = self.grown(q);
        self.bvh
            .query_by(|tree| tree.intersects(&grown), |j, tree| visit(j, tree));
    }

    /// The box that [`Self::near`] tests the tree's boxes against for the query `q`:
    /// `q` grown by `reach − margin` and the slack.
    fn grown(&self, q: &Aabb) -> Aabb {
        let reach = self.reach2.sqrt() * (1.0 + 1e-9) + 1e-150;
        let size = q
            .min
            .iter()
            .chain(&q.max)
            .fold(0.0f64, |s, v| s.max(v.abs()));
        let slack = 1e-12 * (size + self.margin + reach);
        // Infinite margin and reach (no pruning possible) give NaN: then take all.
        let grow = reach - self.margin + slack;
        q.inflate(if grow.is_nan() { f64::INFINITY } else { grow })
    }

    /// Side-B faces whose tree box meets `face`'s box and whose own box comes within
    /// the reach of it, ascending.
    pub(super) fn face_candidates(&self, face: &FaceGeom, out: &mut Vec<usize>) {
        out.clear();
        let faces = face.aabb();
        self.near(&faces, |j, tree| {
            if self.overlap_candidate(&faces, tree) {
                out.push(j);
            }
        });
        out.sort_unstable();
    }

    /// Whether a side-B face with tree box `tree` is a candidate of the overlap of a
    /// side-A face with box `faces`: its tree box meets it, and its own box comes
    /// within the reach of it.
    fn overlap_candidate(&self, faces: &Aabb, tree: &Aabb) -> bool {
        let near = faces.inflate(self.reach2.sqrt());
        tree.intersects(faces) && own_box(tree, self.margin).intersects(&near)
    }

    pub(super) fn distance_limit(&self, face: &FaceGeom) -> f64 {
        distance_limit(self.settings, face)
    }

    /// Normals acceptable? `n_a` zero (node points) skips the test.
    pub(super) fn normals_ok(&self, n_a: V3, n_b: V3) -> bool {
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

    pub(super) fn outside(&self, x: V3) -> bool {
        self.subdomain.is_some_and(|s| {
            let d = sub(x, s.center);
            dot(d, d) > s.radius * s.radius
        })
    }

    /// Pair one point `x` with normal `n_a` against side B.
    pub(super) fn pair(&self, x: V3, n_a: V3) -> Best {
        let mut best = Best {
            found: None,
            rejected: PointStatus::Unmatched,
        };
        let query = Aabb::from_point(x);
        self.near(&query, |j, tree| {
            if tree.intersects(&query) {
                self.consider(j, tree, x, n_a, &mut best);
            }
        });
        best
    }

    /// Pair `x` among the candidates of a query that covered it: the same tests as
    /// [`Self::pair`] on the same faces, taken nearest first (by the distance of their
    /// own box), so that a face that has the point inside comes early and the distance
    /// bound of [`Self::consider`] ends the rest unprojected. The outcome does not depend
    /// on the order: the best face is the least by its rank key, and a face skipped by the
    /// bound could not have beaten it.
    ///
    /// The candidates are `gathered[k]` for `k` in `near`.
    fn pair_among(
        &self,
        (x, n_a): (V3, V3),
        gathered: &[(usize, Aabb)],
        near: &[u32],
        order: &mut Vec<Near>,
    ) -> Best {
        let mut best = Best {
            found: None,
            rejected: PointStatus::Unmatched,
        };
        let query = Aabb::from_point(x);
        order.clear();
        for &k in near {
            let (_, tree) = &gathered[k as usize];
            if tree.intersects(&query) {
                // Farther from the face's own box than the reach: no projection can pass.
                let d2 = own_box(tree, self.margin).distance2_to_point(x);
                if d2 <= self.reach2 {
                    order.push(Near { d2, k });
                }
            }
        }
        sort_by_distance(order);
        for c in order.iter() {
            let (j, _) = gathered[c.k as usize];
            if !self.consider_within(j, c.d2, x, n_a, &mut best) {
                break;
            }
        }
        best
    }

    /// The acceptance tests of side-B face `j` (tree box `tree`) for the point `x`, and
    /// `best` updated with it.
    #[inline]
    fn consider(&self, j: usize, tree: &Aabb, x: V3, n_a: V3, best: &mut Best) {
        // Farther from the face's own box than the reach: no projection can pass.
        let d2 = own_box(tree, self.margin).distance2_to_point(x);
        if d2 > self.reach2 {
            return;
        }
        self.consider_within(j, d2, x, n_a, best);
    }

    /// [`Self::consider`] of a face within the reach, its own box at squared distance
    /// `d2` from `x`; `false` when the face was skipped for being farther than the best
    /// face so far allows (and so is every face farther than it).
    #[inline]
    fn consider_within(&self, j: usize, d2: f64, x: V3, n_a: V3, best: &mut Best) -> bool {
        // A face that has the point inside loses only to another that has it inside at
        // a smaller or equal |gap|, which is then the distance to that face, at least
        // the distance to its box. The slack covers the rounding of the own box (ε of
        // the coordinates), a foot of the perpendicular up to `INSIDE_TOL` past an edge
        // (1e-10 of a face, and the reach is at least 1e-3 of one by default) and that
        // of the |gap| itself; only `found` decides a point that has one.
        if let Some(((false, g, _), ..)) = best.found {
            let size = x.iter().fold(self.margin, |s, v| s.max(v.abs()));
            let bound = g * (1.0 + 1e-9) + 1e-6 * self.reach2.sqrt() + 1e-12 * size;
            if d2 > bound * bound {
                return false;
            }
        }
        let face = &self.b.faces[j];
        let pr = face.project(x);
        if pr.degenerate || !(pr.inside || self.within_tangential(face, &pr.point, x)) {
            return true;
        }
        if !self.normals_ok(n_a, pr.normal) {
            best.rejected = PointStatus::RejectedAngle;
            return true;
        }
        if pr.gap.abs() > self.distance_limit(face) {
            if best.rejected != PointStatus::RejectedAngle {
                best.rejected = PointStatus::RejectedDistance;
            }
            return true;
        }
        let key = (!pr.inside, pr.gap.abs(), j as u32);
        if best.found.is_none_or(|(k, ..)| key < k) {
            best.found = Some((key, pr.xi, pr.gap, pr.normal));
        }
        true
    }

    /// A point that did not project inside may still pair if it lies within the
    /// tangential tolerance (× face size) of the face, measured in the face's plane.
    pub(super) fn within_tangential(&self, face: &FaceGeom, closest: &V3, x: V3) -> bool {
        let t = self.settings.tangential_tolerance * face.size();
        if t <= 0.0 {
            return false;
        }
        let n = face.normal();
        let d = sub(x, *closest);
        let tangential = sub(d, scale(n, dot(d, n)));
        norm(tangential) <= t
    }

    pub(super) fn point(
        &self,
        a_face: Option<u32>,
        a_node: Option<u32>,
        xi_a: [f64; 2],
        x: V3,
        w: f64,
        n_a: V3,
    ) -> ContactPoint {
        let best = (!self.outside(x)).then(|| self.pair(x, n_a));
        contact_point(a_face, a_node, xi_a, x, w, n_a, best)
    }

    /// A node point: its tributary area is its weight, its normal that of the faces
    /// around it (zero for a node on none, which skips the angle test).
    pub(super) fn pair_node(&self, a: &SurfaceGeometry, k: usize) -> ContactPoint {
        let x = a.nodes[k].1;
        let w = a.node_area.get(k).copied().unwrap_or(0.0);
        let n = a.node_normal.get(k).copied().unwrap_or([0.0; 3]);
        self.point(None, Some(k as u32), [0.0; 2], x, w, n)
    }

    /// The points of side-A faces `faces` (consecutive, each with its Gauss rule of
    /// `rules`), paired and written to `out` (one slot per point, face after face);
    /// returns the count written and each face's tally, with its overlap area (see
    /// [`Self::overlap_among`]) when `overlap`, else 0.
    ///
    /// One tree query per face serves its points and its overlap: its box holds them
    /// all, and each keeps the candidates its own query would have found. And one walk of
    /// the tree serves a group of up to [`GROUP`] faces that lie close together (as the
    /// faces of a mesh do, one after the other): it gathers the faces that the union of
    /// their query boxes meets, among which each face's query keeps those its own box
    /// meets — the same faces its own walk would have found, since a box that meets a
    /// face's box meets the union.
    pub(super) fn quadrature_faces(
        &self,
        a: &SurfaceGeometry,
        faces: std::ops::Range<usize>,
        rules: &Rules,
        overlap: bool,
        out: &mut [MaybeUninit<ContactPoint>],
        s: &mut Scratch,
    ) -> (usize, Vec<FaceTally>) {
        let mut tallies = Vec::with_capacity(faces.len());
        let mut at = 0;
        let mut next = faces.start;
        while next < faces.end {
            // The group: faces that stay within `GROUP_SPREAD` times the first one's
            // extent (plus the margin), their points and grown query boxes.
            s.group.clear();
            s.points.clear();
            let mut spread = Aabb::EMPTY;
            let mut limit = 0.0;
            let mut union = Aabb::EMPTY;
            while next < faces.end && s.group.len() < GROUP {
                let bounds = a.faces[next].aabb();
                let wider = spread.union(&bounds);
                let within = extent(&wider) <= limit;
                if s.group.is_empty() {
                    limit = GROUP_SPREAD * (extent(&bounds) + self.margin);
                } else if !within {
                    break;
                }
                spread = wider;
                let face = self.prepare_face(a, (next, bounds), rules, overlap, &mut s.points);
                if let Some(grown) = &face.grown {
                    union = union.union(grown);
                }
                s.group.push(face);
                next += 1;
            }
            s.gathered.clear();
            // (A grown box may be turned inside out, min above max: `is_empty` says
            // nothing of whether it meets a box.)
            if s.group.iter().any(|f| f.grown.is_some()) {
                let accept = |tree: &Aabb| tree.intersects(&union);
                let gathered = &mut s.gathered;
                self.bvh
                    .query_by_with_hint(&mut s.hint, accept, |j, tree| gathered.push((j, *tree)));
            }
            for g in 0..s.group.len() {
                let face = s.group[g];
                let count = face.points.1 - face.points.0;
                s.near.clear();
                if let Some(grown) = &face.grown {
                    // Every gathered face written, the count advanced by whether it is
                    // kept: no branch to guess per face.
                    s.near.resize(s.gathered.len(), 0);
                    let mut kept = 0;
                    for (k, (_, tree)) in s.gathered.iter().enumerate() {
                        s.near[kept] = k as u32;
                        kept += usize::from(tree.intersects(grown));
                    }
                    s.near.truncate(kept);
                }
                let slots = &mut out[at..at + count];
                at += count;
                tallies.push(self.quadrature_face(a, &face, slots, s));
            }
        }
        (at, tallies)
    }

    /// The points of side-A face `fa` (its box `bounds`) and its query box, grown for
    /// the tree ([`Self::grown`]); the points are appended to `points`.
    fn prepare_face(
        &self,
        a: &SurfaceGeometry,
        (fa, bounds): (usize, Aabb),
        rules: &Rules,
        overlap: bool,
        points: &mut Vec<FacePoint>,
    ) -> GroupFace {
        let face = &a.faces[fa];
        // The normal and the measure from one vector area (as `FaceGeom::normal` and
        // `FaceGeom::measure` make them).
        let va = face.vector_area();
        let length = norm(va);
        let n_a = if length > 0.0 {
            scale(va, 1.0 / length)
        } else {
            [0.0; 3]
        };
        let centroid = face.centroid();
        let measure = length * revolution(a.axisymmetric, centroid);
        let mut query = Aabb::EMPTY;
        let start = points.len();
        for &(xi, w) in rules.quadrature(face.len) {
            let x = face.map(xi);
            let w = w * face_jacobian(face, xi) * revolution(a.axisymmetric, x);
            let outside = self.outside(x);
            if !outside {
                query = query.union(&Aabb::from_point(x));
            }
            points.push((xi, x, w, outside));
        }
        let area_wanted = overlap && !self.outside(centroid);
        if area_wanted {
            query = query.union(&bounds);
        }
        GroupFace {
            fa,
            n_a,
            centroid,
            measure,
            area_wanted,
            bounds,
            grown: (!query.is_empty()).then(|| self.grown(&query)),
            points: (start, points.len()),
        }
    }

    /// One face of a group ([`Self::quadrature_faces`]), its candidates in `s.near`: its
    /// points paired and written to `out`, and its tally.
    fn quadrature_face(
        &self,
        a: &SurfaceGeometry,
        face: &GroupFace,
        out: &mut [MaybeUninit<ContactPoint>],
        s: &mut Scratch,
    ) -> FaceTally {
        let (fa, n_a) = (face.fa, face.n_a);
        let a_face = Some(fa as u32);
        let (mut hit, mut total) = (0.0, 0.0);
        let points = &s.points[face.points.0..face.points.1];
        for (slot, &(xi, x, w, outside)) in out.iter_mut().zip(points) {
            let best =
                (!outside).then(|| self.pair_among((x, n_a), &s.gathered, &s.near, &mut s.order));
            let p = contact_point(a_face, None, xi, x, w, n_a, best);
            total += p.weight;
            if p.status == PointStatus::Matched {
                hit += p.weight;
            }
            slot.write(p);
        }
        let mut tally = FaceTally {
            hit,
            total,
            area: 0.0,
            measure: face.measure,
        };
        if !face.area_wanted {
            return tally;
        }
        s.overlap.clear();
        for &k in &s.near {
            let (j, tree) = &s.gathered[k as usize];
            if self.overlap_candidate(&face.bounds, tree) {
                s.overlap.push(*j);
            }
        }
        sort_small(&mut s.overlap);
        tally.area = self.overlap_among(
            a,
            fa,
            (n_a, face.centroid),
            &s.overlap,
            (&mut s.clip, &mut s.cover, &mut s.b_faces),
        );
        tally
    }

    /// The mortar segment points of side-A face `fa` against the side-B faces near it
    /// (`line`, `triangle`: the rules of [`Rules::Segments`]), appended to `out`.
    pub(super) fn segment_points(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        (line, triangle): (&(Vec<f64>, Vec<f64>), &TriangleRule),
        out: &mut Vec<ContactPoint>,
        s: &mut Scratch,
    ) {
        let face = &a.faces[fa];
        let n_a = face.normal();
        self.face_candidates(face, &mut s.overlap);
        let outside = self.outside(face.centroid());
        for &j in &s.overlap {
            let fb = &self.b.faces[j];
            let scratch = &mut s.mortar;
            scratch.clear();
            if face.len == 2 {
                segments_line_line_into(face.coords(), fb.coords(), line, scratch);
            } else {
                segments_face_face_into(face.coords(), fb.coords(), triangle, scratch);
            }
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
                    a_face: Some(fa as u32),
                    a_node: None,
                    xi_a: m.xi_a,
                    x: m.x_a,
                    weight: m.weight * revolution(a.axisymmetric, m.x_a),
                    status,
                    b_face: Some(j as u32),
                    xi_b: m.xi_b,
                    gap: m.gap,
                    offset: 0.0,
                    normal_a: n_a,
                    normal_b: n_b,
                });
            }
        }
    }

    /// Overlap area of side-A face `fa` (its centroid inside the subdomain) with side B
    /// in quadrature mode: the clipped overlap with every side-B face among
    /// `candidates` (ascending) the pairing would accept for that face: opposed
    /// normals, and a centroid within the acceptance distance of the face's plane
    /// (`n_a`, `c_a`: the face's normal and centroid, as `FaceGeom` makes them).
    /// (In segment mode the matched points' weights sum to it exactly.) `clip` keeps
    /// the clipping buffers from face to face.
    fn overlap_among(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        (n_a, c_a): (V3, V3),
        candidates: &[usize],
        (clip, cover, b_faces): (&mut Option<FaceOverlap>, &mut Cover, &mut BFaces),
    ) -> f64 {
        let face = &a.faces[fa];
        if face.len != 2
            && let Some(area) = self.covered(face, (n_a, c_a), candidates, (cover, b_faces))
        {
            return area;
        }
        let mut clip = match face.len {
            2 => None,
            _ => {
                let clip = clip.get_or_insert_with(FaceOverlap::default);
                if !clip.set_face(face.coords()) {
                    return 0.0;
                }
                Some(clip)
            }
        };
        let mut area = 0.0;
        let mut scratch = Vec::new();
        // An axisymmetric edge's rule, made only for such a face.
        let mut midpoint = None;
        for &j in candidates {
            let fb = &self.b.faces[j];
            if !self.overlap_accepts((n_a, c_a), b_faces.get(j, fb, self.settings)) {
                continue;
            }
            area += match &mut clip {
                Some(clip) => clip.area_with(fb.coords()),
                None if !a.axisymmetric => overlap_length_line_line(face.coords(), fb.coords()),
                // ∫ 2πr over the interval: its midpoint rule is exact (r is linear).
                None => {
                    let midpoint = midpoint.get_or_insert_with(|| rule_line(1));
                    scratch.clear();
                    segments_line_line_into(face.coords(), fb.coords(), midpoint, &mut scratch);
                    scratch
                        .iter()
                        .map(|m| m.weight * revolution(true, m.x_a))
                        .sum()
                }
            };
        }
        area
    }

    /// Whether the overlap of a side-A face (normal and centroid `n_a`, `c_a`) counts
    /// side-B face `b`: opposed normals, and its centroid within the acceptance distance
    /// of the face's plane.
    #[inline]
    fn overlap_accepts(&self, (n_a, c_a): (V3, V3), b: BFace) -> bool {
        let far = dot(sub(b.centroid, c_a), n_a).abs() > b.limit;
        self.normals_ok(n_a, b.normal) && !far
    }

    /// The overlap area of side-A face `face` without clipping, when the side-B faces
    /// among `candidates` that the overlap accepts cover it exactly once ([`Cover`]): its
    /// own area. `None` when that is not shown, or when a face near it is not accepted.
    fn covered(
        &self,
        face: &FaceGeom,
        (n_a, c_a): (V3, V3),
        candidates: &[usize],
        (cover, b_faces): (&mut Cover, &mut BFaces),
    ) -> Option<f64> {
        if !cover.set_face(face.coords()) {
            return None;
        }
        for &j in candidates {
            let fb = &self.b.faces[j];
            let nodes = fb.nodes.map(|n| n.0);
            let Some(tile) = cover.tile(fb.coords(), &nodes[..fb.len as usize]) else {
                continue;
            };
            if !self.overlap_accepts((n_a, c_a), b_faces.get(j, fb, self.settings)) {
                return None;
            }
            cover.push(tile);
        }
        cover.area()
    }
}

/// The largest |gap| accepted on side-B face `face`: the normal tolerance, or the field
/// factor times the face's size.
fn distance_limit(settings: &SearchSettings, face: &FaceGeom) -> f64 {
    settings
        .normal_tolerance
        .unwrap_or(settings.field_factor * face.size())
}

/// Ascending order of a short list (a face's half-dozen candidates), by insertion.
fn sort_small(v: &mut [usize]) {
    for i in 1..v.len() {
        let x = v[i];
        let mut k = i;
        while k > 0 && v[k - 1] > x {
            v[k] = v[k - 1];
            k -= 1;
        }
        v[k] = x;
    }
}

/// Nearest first, by insertion (a point has a few candidates); equal distances keep
/// their order.
fn sort_by_distance(v: &mut [Near]) {
    for i in 1..v.len() {
        let x = v[i];
        let mut k = i;
        while k > 0 && v[k - 1].d2 > x.d2 {
            v[k] = v[k - 1];
            k -= 1;
        }
        v[k] = x;
    }
}

/// The own box of a side-B face from its tree box: shrunk by the margin again.
#[inline]
fn own_box(tree: &Aabb, margin: f64) -> Aabb {
    Aabb {
        min: tree.min.map(|v| v + margin),
        max: tree.max.map(|v| v - margin),
    }
}

/// A side-A point with the outcome of its pairing (`None`: outside the subdomain).
fn contact_point(
    a_face: Option<u32>,
    a_node: Option<u32>,
    xi_a: [f64; 2],
    x: V3,
    w: f64,
    n_a: V3,
    best: Option<Best>,
) -> ContactPoint {
    let mut p = ContactPoint {
        a_face,
        a_node,
        xi_a,
        x,
        weight: w,
        status: PointStatus::RejectedSubdomain,
        b_face: None,
        xi_b: [0.0; 2],
        gap: 0.0,
        offset: 0.0,
        normal_a: n_a,
        normal_b: [0.0; 3],
    };
    let Some(best) = best else {
        return p;
    };
    match best.found {
        Some(((_, _, j), xi_b, gap, n_b)) => {
            p.status = PointStatus::Matched;
            p.b_face = Some(j);
            p.xi_b = xi_b;
            p.gap = gap;
            p.normal_b = n_b;
        }
        None => p.status = best.rejected,
    }
    p
}
