//! One chunk of side-A points paired with side B: the candidate faces from the tree,
//! the acceptance tests of the module documentation and the best face per point, for
//! quadrature points, mortar segment points and node points.

use crate::search::bvh::{Aabb, Bvh};
use crate::search::mortar::{
    FaceOverlap, MortarPoint, overlap_length_line_line, rule_line, rule_triangle,
    segments_face_face_into, segments_line_line_into,
};
use crate::search::settings::SearchSettings;
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

impl Ctx<'_> {
    /// Side-B faces whose own box comes within the reach of `face`'s box, ascending.
    pub(super) fn face_candidates(&self, face: &FaceGeom, out: &mut Vec<usize>) {
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

    pub(super) fn distance_limit(&self, face: &FaceGeom) -> f64 {
        self.settings
            .normal_tolerance
            .unwrap_or(self.settings.field_factor * face.size())
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
            let pr = face.project(x);
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
        let mut p = ContactPoint {
            a_face,
            a_node,
            xi_a,
            x,
            weight: w,
            status: PointStatus::Unmatched,
            b_face: None,
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
                p.b_face = Some(j);
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
    pub(super) fn pair_node(&self, a: &SurfaceGeometry, k: usize) -> ContactPoint {
        let x = a.nodes[k].1;
        let w = a.node_area.get(k).copied().unwrap_or(0.0);
        let n = a.node_normal.get(k).copied().unwrap_or([0.0; 3]);
        self.point(None, Some(k as u32), [0.0; 2], x, w, n)
    }

    pub(super) fn quadrature_points(
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
            let w = w * face_jacobian(face, xi) * revolution(a.axisymmetric, x);
            out.push(self.point(Some(fa as u32), None, xi, x, w, n_a));
        }
    }

    pub(super) fn segment_points(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        order: usize,
        out: &mut Vec<ContactPoint>,
        scratch: &mut Vec<MortarPoint>,
    ) {
        let face = &a.faces[fa];
        let n_a = face.normal();
        // Edges: a Gauss rule on the overlap interval, one degree higher when the weight
        // carries 2πr, so that it stays exact for the same integrands.
        let (line, triangle) = match face.len {
            2 => (Some(rule_line(order + usize::from(a.axisymmetric))), None),
            _ => (None, Some(rule_triangle(order))),
        };
        let mut candidates = Vec::new();
        self.face_candidates(face, &mut candidates);
        let outside = self.outside(face.centroid());
        for j in candidates {
            let fb = &self.b.faces[j];
            scratch.clear();
            match (&line, &triangle) {
                (Some(line), _) => {
                    segments_line_line_into(face.coords(), fb.coords(), line, scratch)
                }
                (_, Some(tri)) => segments_face_face_into(face.coords(), fb.coords(), tri, scratch),
                _ => 0,
            };
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

    /// Overlap area of side-A face `fa` with side B. In segment mode the matched points'
    /// weights sum to it exactly. In quadrature mode it is the clipped overlap with every
    /// side-B face the pairing would accept for that face: opposed normals, and a
    /// centroid within the acceptance distance of the face's plane.
    pub(super) fn overlap_of(
        &self,
        a: &SurfaceGeometry,
        fa: usize,
        points: &[ContactPoint],
        integration: Integration,
        candidates: &mut Vec<usize>,
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
        let mut clip = match face.len {
            2 => None,
            _ => match FaceOverlap::new(face.coords()) {
                Some(c) => Some(c),
                None => return 0.0,
            },
        };
        let (n_a, c_a) = (face.normal(), face.centroid());
        let mut area = 0.0;
        let mut scratch = Vec::new();
        let midpoint = rule_line(1);
        self.face_candidates(face, candidates);
        for &j in candidates.iter() {
            let fb = &self.b.faces[j];
            if !self.normals_ok(n_a, fb.normal())
                || dot(sub(fb.centroid(), c_a), n_a).abs() > self.distance_limit(fb)
            {
                continue;
            }
            area += match &mut clip {
                Some(clip) => clip.area_with(fb.coords()),
                None if !a.axisymmetric => overlap_length_line_line(face.coords(), fb.coords()),
                // ∫ 2πr over the interval: its midpoint rule is exact (r is linear).
                None => {
                    scratch.clear();
                    segments_line_line_into(face.coords(), fb.coords(), &midpoint, &mut scratch);
                    scratch
                        .iter()
                        .map(|m| m.weight * revolution(true, m.x_a))
                        .sum()
                }
            };
        }
        area
    }
}
