//! The overlap area of one side-A face with many side-B faces, the kernel of the search's
//! overlap diagnostic: [`FaceOverlap`] gives, face pair by face pair, the numbers of
//! [`super::mortar::overlap_area_face_face`], bit for bit, at a fraction of the cost.
//!
//! What is made once per side-A face: the plane of A and its projected convex pieces,
//! each prepared as a clip polygon — its oriented edges, its twice-area and the largest
//! squared length of its points and edges, which `mortar::clip_into` works out again on
//! every call. Per side-B face: its projection, a box test against A's projected box, and
//! Sutherland–Hodgman clipping of its pieces in fixed buffers, with the arithmetic of
//! `mortar::clip_into` in the same order (the tolerances and their reasons are there).
//! Conventions as in [`super::mortar`]: areas in the plane of A, either winding.

use super::mortar::{
    Flat, P2, Plane, area2, area2_reversed, cross2, intersect, plane_of, sub2, valid_face,
};

/// The most vertices a clipped polygon can reach: a piece has at most 4 vertices and is
/// clipped by at most 4 edges, and each edge at most doubles the count (a crossing
/// before every vertex kept), so 4 · 2⁴. A convex piece never passes 8.
const CAP: usize = 64;

/// A convex piece of face A as a clip polygon: edge `k` runs from `c0[k]` along `e[k]`
/// with the inside on its left, in the order `clip_into` takes them.
#[derive(Clone, Copy, Debug, Default)]
struct ClipPiece {
    c0: [P2; 4],
    e: [P2; 4],
    m: usize,
    /// Twice the signed area of the piece in its given order.
    area2: f64,
    /// The largest squared norm of its points and of its edges (in the given order).
    scale2: f64,
}

impl ClipPiece {
    /// Made from `clip`, in place (the piece is too large to be moved for free).
    fn set(&mut self, clip: &[P2]) {
        let m = clip.len();
        let next = |i: usize| if i + 1 == m { 0 } else { i + 1 };
        self.m = m;
        self.scale2 = 0.0;
        for p in clip {
            self.scale2 = larger(self.scale2, p[0] * p[0] + p[1] * p[1]);
        }
        for i in 0..m {
            let e = sub2(clip[next(i)], clip[i]);
            self.scale2 = larger(self.scale2, e[0] * e[0] + e[1] * e[1]);
        }
        self.area2 = area2(clip);
        let ccw = self.area2 > 0.0;
        for k in 0..m {
            // Backwards: edge k runs from vertex m − 1 − k to the one before it.
            let (c0, c1) = if ccw {
                (clip[k], clip[next(k)])
            } else {
                let i = m - 1 - k;
                (clip[i], clip[if i == 0 { m - 1 } else { i - 1 }])
            };
            self.c0[k] = c0;
            self.e[k] = sub2(c1, c0);
        }
    }
}

/// `a.max(b)` for an `a` that is not NaN, as a comparison (`f64::max` also sorts out
/// NaNs, at four instructions more): the same value (of ±0 it may keep the other,
/// which compares equal).
#[inline(always)]
pub(super) fn larger(a: f64, b: f64) -> f64 {
    if b > a { b } else { a }
}

/// `a.min(b)` for an `a` that is not NaN, as [`larger`].
#[inline(always)]
pub(super) fn smaller(a: f64, b: f64) -> f64 {
    if b < a { b } else { a }
}

/// The box of `points`, as `Flat::bounds` makes it up to the sign of a zero (which
/// compares equal).
#[inline(always)]
fn bounds_of(points: &[P2]) -> (P2, P2) {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in points {
        for d in 0..2 {
            lo[d] = smaller(lo[d], p[d]);
            hi[d] = larger(hi[d], p[d]);
        }
    }
    (lo, hi)
}

/// Side-A face `a` made ready for the overlap areas of many side-B faces
/// ([`super::mortar::overlap_area_face_face`] for each, the same numbers): its plane
/// and projected pieces are made once, a face whose projection's box misses `a`'s is
/// skipped without clipping, and the clipping buffers are reused, also for the next
/// side-A face ([`FaceOverlap::set_face`]).
#[derive(Clone, Debug)]
pub struct FaceOverlap {
    /// Whether a face is set (a degenerate or unsupported one is not).
    ready: bool,
    plane: Plane,
    pieces: [ClipPiece; 2],
    count: usize,
    /// The box of `a`'s projected nodes.
    lo: P2,
    hi: P2,
    buffers: [[P2; CAP]; 2],
}

impl Default for FaceOverlap {
    fn default() -> Self {
        FaceOverlap {
            ready: false,
            plane: Plane::default(),
            pieces: [ClipPiece::default(); 2],
            count: 0,
            lo: [0.0; 2],
            hi: [0.0; 2],
            buffers: [[[0.0; 2]; CAP]; 2],
        }
    }
}

impl FaceOverlap {
    /// `None` for a degenerate or unsupported face (its overlaps are all 0).
    pub fn new(a: &[[f64; 3]]) -> Option<FaceOverlap> {
        let mut overlap = FaceOverlap::default();
        overlap.set_face(a).then_some(overlap)
    }

    /// Make ready for side-A face `a` instead, keeping the buffers; `false` (and every
    /// area 0) for a degenerate or unsupported face.
    pub fn set_face(&mut self, a: &[[f64; 3]]) -> bool {
        self.ready = false;
        if !valid_face(a) {
            return false;
        }
        let Some(plane) = plane_of(a) else {
            return false;
        };
        let flat = Flat::new(a, &plane);
        self.plane = plane;
        (self.lo, self.hi) = bounds_of(flat.nodes());
        let (index, len) = flat.pieces();
        self.count = 0;
        for (idx, &n) in index.iter().zip(&len) {
            if n > 0 {
                let (p, n) = flat.piece(idx, n);
                self.pieces[self.count].set(&p[..n]);
                self.count += 1;
            }
        }
        self.ready = true;
        true
    }

    /// The area of `b`'s overlap with `a`, in the plane of `a`.
    pub fn area_with(&mut self, b: &[[f64; 3]]) -> f64 {
        if !self.ready || !valid_face(b) {
            return 0.0;
        }
        let fb = Flat::new(b, &self.plane);
        let (lo, hi) = bounds_of(fb.nodes());
        // Boxes apart (strictly): the clip is empty.
        if (hi[0] < self.lo[0]) | (lo[0] > self.hi[0]) | (hi[1] < self.lo[1]) | (lo[1] > self.hi[1])
        {
            return 0.0;
        }
        let (index, len) = fb.pieces();
        if self.count == 1 && len[1] == 0 {
            // Both convex (the common case): one clip.
            let area = clip_piece_area(
                fb.piece(&index[0], len[0]),
                &self.pieces[0],
                &mut self.buffers,
            );
            return area.map_or(0.0, |a| 0.0 + a);
        }
        let mut area = 0.0;
        for piece in &self.pieces[..self.count] {
            for (idx, &n) in index.iter().zip(&len) {
                if n == 0 {
                    continue;
                }
                if let Some(a) = clip_piece_area(fb.piece(idx, n), piece, &mut self.buffers) {
                    area += a;
                }
            }
        }
        area
    }
}

/// The signed area of `mortar::clip_into(subject, clip)` for a prepared clip piece and a
/// subject of at most 4 vertices (the first `n` of `subject`), clipped in `buffers` (`None` where `clip_into` gives an
/// empty polygon): the same operations in the same order, so the same polygon and, as
/// `signed_area_polygon` takes it, the same area. The clockwise result (that of an
/// opposed side-B face, the common case) is measured with its vertices read backwards
/// instead of being reversed.
#[inline(always)]
fn clip_piece_area(
    (subject, n): ([P2; 4], usize),
    clip: &ClipPiece,
    buffers: &mut [[P2; CAP]; 2],
) -> Option<f64> {
    if n < 3 || clip.m < 3 {
        return None;
    }
    let mut scale2 = clip.scale2;
    for p in &subject[..n] {
        scale2 = larger(scale2, p[0] * p[0] + p[1] * p[1]);
    }
    if clip.area2.abs() <= 8.0 * f64::EPSILON * scale2 {
        return None;
    }
    let [a, b] = buffers;
    let (mut from, mut to) = (a, b);
    // All four slots (fixed size: moves, not a call to copy); the first `n` are the
    // subject's.
    from[..4].copy_from_slice(&subject);
    let mut n = n;
    for k in 0..clip.m {
        let (c0, e) = (clip.c0[k], clip.e[k]);
        let side = |p: P2| cross2(e, sub2(p, c0));
        let mut w = 0;
        let mut s = from[n - 1];
        let mut ds = side(s);
        for &q in &from[..n] {
            let dq = side(q);
            if dq >= 0.0 {
                if ds < 0.0 {
                    to[w] = intersect(s, q, ds, dq);
                    w += 1;
                }
                to[w] = q;
                w += 1;
            } else if ds >= 0.0 {
                to[w] = intersect(s, q, ds, dq);
                w += 1;
            }
            s = q;
            ds = dq;
        }
        std::mem::swap(&mut from, &mut to);
        n = w;
        if n == 0 {
            return None;
        }
    }
    let out = from;
    let tol2 = 1e-28 * scale2;
    let mut w = 0;
    for j in 0..n {
        let p = out[j];
        if w == 0 || {
            let d = sub2(p, out[w - 1]);
            d[0] * d[0] + d[1] * d[1] > tol2
        } {
            out[w] = p;
            w += 1;
        }
    }
    while w > 1 && {
        let d = sub2(out[0], out[w - 1]);
        d[0] * d[0] + d[1] * d[1] <= tol2
    } {
        w -= 1;
    }
    let poly = &out[..w];
    let a2 = area2(poly);
    if w < 3 || a2.abs() <= 8.0 * f64::EPSILON * scale2 {
        return None;
    }
    Some(0.5 * if a2 < 0.0 { area2_reversed(poly) } else { a2 })
}

#[cfg(test)]
mod tests {
    use super::super::mortar::{for_each_overlap, signed_area_polygon};
    use super::*;
    use crate::vec3::V3;

    /// The prepared face gives the same bits as clipping every pair in full, for faces
    /// that overlap, touch, miss by a hair or lie far apart, tilted out of plane; side-A
    /// faces convex, non-convex (two pieces) or triangles, one `FaceOverlap` reused.
    #[test]
    fn prepared_face_overlap_equals_clipping_every_pair() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut rand = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        let (mut skipped, mut overlapping) = (0, 0);
        let mut reused = FaceOverlap::default();
        for case in 0..4000 {
            let quad = |r: &mut dyn FnMut() -> f64, c: [f64; 2], s: f64| -> Vec<V3> {
                let tilt = 0.05 * (r() - 0.5);
                [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
                    .iter()
                    .map(|q| {
                        let (x, y) = (
                            c[0] + s * (q[0] + 0.2 * (r() - 0.5)),
                            c[1] + s * (q[1] + 0.2 * (r() - 0.5)),
                        );
                        [x, y, tilt * x + 0.01 * r()]
                    })
                    .collect()
            };
            let mut a = quad(&mut rand, [0.0, 0.0], 1.0);
            if case % 5 == 0 {
                // A reflex corner: node 2 pulled in past the diagonal 1–3.
                a[2] = [0.3 + 0.1 * rand(), 0.3 + 0.1 * rand(), a[2][2]];
            } else if case % 11 == 0 {
                a.pop();
            }
            // Centres from overlapping to far apart; every 7th exactly edge to edge.
            let d = if case % 7 == 0 { 1.0 } else { 3.0 * rand() };
            let y = 0.5 * rand();
            let mut b = quad(&mut rand, [d, y], 0.9);
            if case % 3 == 0 {
                b.pop();
            }
            let full = {
                let plane = plane_of(&a).unwrap();
                let (fa, fb) = (Flat::new(&a, &plane), Flat::new(&b, &plane));
                let mut area = 0.0;
                for_each_overlap(&fa, &fb, |poly| area += signed_area_polygon(poly));
                area
            };
            assert!(reused.set_face(&a));
            let prepared = reused.area_with(&b);
            assert_eq!(
                prepared.to_bits(),
                FaceOverlap::new(&a).unwrap().area_with(&b).to_bits()
            );
            assert_eq!(
                prepared.to_bits(),
                full.to_bits(),
                "case {case}: {prepared} vs {full}"
            );
            if full == 0.0 {
                skipped += 1;
            } else {
                overlapping += 1;
            }
        }
        assert!(
            skipped > 500 && overlapping > 500,
            "{skipped} apart, {overlapping} overlapping"
        );
    }
}
