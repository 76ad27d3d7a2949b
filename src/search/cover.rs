//! The overlap diagnostic without clipping, where it can be shown to be the side-A
//! face's own area: [`Cover`].
//!
//! The overlap of side-A face A with side B is `Σ_j |A ∩ B_j|`, each side-B face `B_j`
//! projected onto the plane of A along A's normal (as [`super::overlap::FaceOverlap`]
//! clips them). That sum is `∫_A c(p) dp`, where `c(p)` counts the projected faces that
//! hold `p`. Crossing an edge that two faces share moves `p` out of one face and into
//! the other, provided the two lie on opposite sides of it, so `c` changes only across
//! edges no other face takes up. Hence: when every side-B face edge that comes near A
//! is shared by exactly two of the faces, each projected convex and with the
//! orientation of a side-B face opposed to A (so that neighbours lie on opposite sides
//! of their common edge), `c` is one number over A, read off at A's centroid — and when
//! it is 1 the sum is A's area, to round-off. Everywhere else (an edge of side B's
//! boundary or of a rejected face crossing A, an edge of three faces, a fold, two
//! sheets, a corner on the centroid) the test says nothing and the faces are clipped.
//!
//! Within a side B, most side-A faces pass, so the diagnostic costs a projection of the
//! few faces near each instead of their clipping. The tests are in A's plane
//! coordinates, with tolerances that err towards clipping.

use crate::vec3::V3;

use super::mortar::{P2, Plane, area2, cross2, plane_of, sub2};
use super::overlap::{larger, smaller};

/// The most side-B faces near one side-A face that the test takes; more, and the faces
/// are clipped.
const TILES: usize = 16;

/// A side-B face projected onto A's plane: its corners, and its edges by node numbers
/// ([`edge_key`]; [`NO_EDGE`] past the last).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Tile {
    q: [P2; 4],
    edges: [u64; 4],
    len: usize,
}

/// The key of no edge: node numbers are below `u32::MAX`.
const NO_EDGE: u64 = u64::MAX;

impl Default for Tile {
    fn default() -> Self {
        Tile {
            q: [[0.0; 2]; 4],
            edges: [NO_EDGE; 4],
            len: 0,
        }
    }
}

/// The edge from node `from` to node `to` as one number.
#[inline(always)]
fn edge_key(from: u32, to: u32) -> u64 {
    (u64::from(from) << 32) | u64::from(to)
}

/// The corner after `k` of a polygon of `n` corners.
#[inline(always)]
fn next(k: usize, n: usize) -> usize {
    if k + 1 == n { 0 } else { k + 1 }
}

/// Side-A face A made ready for [`Cover::area`]: its plane, projected corners and box;
/// then the side-B faces near it, one [`Cover::tile`] and [`Cover::push`] each.
#[derive(Clone, Debug)]
pub(crate) struct Cover {
    /// A's plane.
    plane: Plane,
    /// A's projected box, widened by the tolerance of the projections.
    lo: P2,
    hi: P2,
    /// A's area (its projection onto its own plane).
    area: f64,
    tiles: [Tile; TILES],
    /// The edges of `tiles`, four slots a face, side by side for [`shared_once`].
    keys: [u64; 4 * TILES],
    count: usize,
    /// Whether a face pushed could not be taken: then [`Cover::area`] is `None`.
    refused: bool,
}

impl Default for Cover {
    fn default() -> Self {
        Cover {
            plane: Plane::default(),
            lo: [0.0; 2],
            hi: [0.0; 2],
            area: 0.0,
            tiles: [Tile::default(); TILES],
            keys: [NO_EDGE; 4 * TILES],
            count: 0,
            refused: true,
        }
    }
}

/// Whether the polygon `p` (3 or 4 corners) is strictly convex with the orientation
/// `sign` (+1 counter-clockwise, −1 clockwise): every corner turns that way by more
/// than a rounding error.
#[inline(always)]
fn convex(p: &[P2], sign: f64) -> bool {
    let n = p.len();
    let mut e = [[0.0; 2]; 4];
    let mut l2 = 0.0;
    for k in 0..n {
        e[k] = sub2(p[next(k, n)], p[k]);
        l2 = larger(l2, e[k][0] * e[k][0] + e[k][1] * e[k][1]);
    }
    let tol = 1e-10 * l2;
    let mut turns = true;
    for k in 0..n {
        turns &= sign * cross2(e[k], e[next(k, n)]) > tol;
    }
    turns
}

impl Cover {
    /// Make ready for side-A face `a` (3 or 4 corners); `false` for a face the test does
    /// not take (degenerate, or not convex in its plane), whose overlap is then clipped.
    pub(crate) fn set_face(&mut self, a: &[V3]) -> bool {
        self.count = 0;
        self.refused = true;
        // The plane the clipping projects onto (`None`: degenerate, or not 3 or 4
        // corners).
        let Some(plane) = plane_of(a) else {
            return false;
        };
        self.plane = plane;
        let m = a.len();
        let mut p = [[0.0; 2]; 4];
        for (k, x) in a.iter().enumerate() {
            p[k] = self.plane.to2(*x);
        }
        // Also false for NaN coordinates.
        if !convex(&p[..m], 1.0) {
            return false;
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for q in &p[..m] {
            for d in 0..2 {
                lo[d] = smaller(lo[d], q[d]);
                hi[d] = larger(hi[d], q[d]);
            }
        }
        // Round-off of the projections: ε of the coordinates, far below the pad.
        let size = (self.plane.origin().iter()).fold(0.0, |s, v| larger(s, v.abs()));
        let extent = (hi[0] - lo[0]).max(hi[1] - lo[1]);
        let pad = 1e-9 * extent + 1e-12 * size;
        self.lo = [lo[0] - pad, lo[1] - pad];
        self.hi = [hi[0] + pad, hi[1] + pad];
        // A's projection, as the clipped pieces of a face that covers it sum to.
        self.area = 0.5 * area2(&p[..m]);
        self.refused = false;
        true
    }

    /// Whether the box `(lo, hi)` meets A's.
    #[inline(always)]
    fn meets(&self, lo: P2, hi: P2) -> bool {
        lo[0] <= self.hi[0] && hi[0] >= self.lo[0] && lo[1] <= self.hi[1] && hi[1] >= self.lo[1]
    }

    /// Side-B face `b` (its corners and node numbers) projected onto A's plane, or
    /// `None` when its box misses A's (it adds nothing to the overlap).
    pub(crate) fn tile(&self, b: &[V3], nodes: &[u32]) -> Option<Tile> {
        let mut t = Tile {
            len: b.len().min(4),
            ..Tile::default()
        };
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for k in 0..t.len {
            let q = self.plane.to2(b[k]);
            // A NaN coordinate leaves the box to the other corners; `push` then
            // refuses the face (its turns are not above the tolerance).
            for d in 0..2 {
                lo[d] = smaller(lo[d], q[d]);
                hi[d] = larger(hi[d], q[d]);
            }
            t.q[k] = q;
            t.edges[k] = edge_key(nodes[k], nodes[next(k, t.len)]);
        }
        self.meets(lo, hi).then_some(t)
    }

    /// Take a side-B face near A that the overlap accepts. It must be convex and
    /// opposed to A (clockwise in A's plane), and there must be room; otherwise the
    /// test gives up.
    pub(crate) fn push(&mut self, t: Tile) {
        if self.refused || t.len < 3 || self.count == TILES || !convex(&t.q[..t.len], -1.0) {
            self.refused = true;
            return;
        }
        self.tiles[self.count] = t;
        self.keys[4 * self.count..4 * self.count + 4].copy_from_slice(&t.edges);
        self.count += 1;
    }

    /// A's area when the faces pushed cover it exactly once (see the module
    /// documentation), else `None`.
    pub(crate) fn area(&self) -> Option<f64> {
        if self.refused {
            return None;
        }
        let tiles = &self.tiles[..self.count];
        // Every edge near A shared, in reverse, by exactly one other face, and by none
        // the same way round: a third face on an edge (a fin, a slit) would lie over one
        // of the two.
        for t in tiles {
            for k in 0..t.len {
                let (u, v) = (t.q[k], t.q[next(k, t.len)]);
                let lo = [smaller(u[0], v[0]), smaller(u[1], v[1])];
                let hi = [larger(u[0], v[0]), larger(u[1], v[1])];
                if self.meets(lo, hi) && !shared_once(&self.keys[..4 * self.count], t.edges[k]) {
                    return None;
                }
            }
        }
        // The count at A's centroid, the origin: inside a clockwise face is right of
        // every edge. A centroid on an edge (within the tolerance) says nothing.
        let mut holders = 0;
        for t in tiles {
            let (mut out, mut on) = (false, false);
            for k in 0..t.len {
                let (u, v) = (t.q[k], t.q[next(k, t.len)]);
                let e = sub2(v, u);
                let c = cross2(e, [-u[0], -u[1]]);
                let tol = 1e-10 * (e[0] * e[0] + e[1] * e[1] + u[0] * u[0] + u[1] * u[1]);
                out |= c > tol;
                on |= c.abs() <= tol;
            }
            if out {
                continue;
            }
            if on {
                return None;
            }
            holders += 1;
        }
        (holders == 1).then_some(self.area)
    }
}

/// Whether, besides the face it came from, exactly one face has the edge `key`
/// ([`edge_key`]) in reverse and none has it the same way round; `keys` are the faces'
/// edges, four slots a face.
fn shared_once(keys: &[u64], key: u64) -> bool {
    let reverse = key.rotate_left(32);
    // Every slot, without branches (the unused ones match nothing). The face `key`
    // came from counts once the same way round and never in reverse: a convex face's
    // edges are distinct.
    let (mut opposite, mut same) = (0u32, 0u32);
    for &e in keys {
        opposite += u32::from(e == reverse);
        same += u32::from(e == key);
    }
    opposite == 1 && same == 1
}

#[cfg(test)]
mod tests {
    use super::super::overlap::FaceOverlap;
    use super::*;
    use crate::vec3::{cross, norm, sub};

    /// A jittered, slightly warped grid of `n × n` quads on `[0, w] × [0, 1]`, wound
    /// clockwise seen from above (opposed to a side A facing up), its nodes numbered
    /// from `first`.
    fn sheet(
        n: usize,
        w: f64,
        z: f64,
        first: u32,
        rand: &mut impl FnMut() -> f64,
    ) -> Vec<(Vec<V3>, Vec<u32>)> {
        let mut x = vec![[0.0; 3]; (n + 1) * (n + 1)];
        for j in 0..=n {
            for i in 0..=n {
                let interior = |k: usize| k > 0 && k < n;
                let (mut u, mut v) = (i as f64 / n as f64, j as f64 / n as f64);
                if interior(i) {
                    u += 0.3 * (rand() - 0.5) / n as f64;
                }
                if interior(j) {
                    v += 0.3 * (rand() - 0.5) / n as f64;
                }
                x[j * (n + 1) + i] = [w * u, v, z + 0.02 * u * v + 1e-3 * rand()];
            }
        }
        let mut faces = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let k = j * (n + 1) + i;
                let ids = [k, k + n + 1, k + n + 2, k + 1];
                faces.push((
                    ids.iter().map(|&k| x[k]).collect(),
                    ids.iter().map(|&k| first + k as u32).collect(),
                ));
            }
        }
        faces
    }

    /// The cover test over all of `b` for side-A face `a`.
    fn cover_area(cover: &mut Cover, a: &[V3], b: &[(Vec<V3>, Vec<u32>)]) -> Option<f64> {
        assert!(cover.set_face(a));
        for (x, ids) in b {
            if let Some(t) = cover.tile(x, ids) {
                cover.push(t);
            }
        }
        cover.area()
    }

    /// The clipped sum the cover test stands in for.
    fn clipped(a: &[V3], b: &[(Vec<V3>, Vec<u32>)]) -> f64 {
        let mut clip = FaceOverlap::new(a).unwrap();
        b.iter().map(|(x, _)| clip.area_with(x)).sum()
    }

    fn rng() -> impl FnMut() -> f64 {
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// Side-A quads (some tilted out of plane, some triangles) over a side B that
    /// covers x ≤ 0.7 only: where the test speaks it gives the clipped sum to
    /// round-off, it speaks for most faces inside, and never for a face that side B's
    /// edge crosses.
    #[test]
    fn a_face_inside_side_b_has_its_own_area() {
        let mut rand = rng();
        let b = sheet(9, 0.7, 0.0, 0, &mut rand);
        let mut cover = Cover::default();
        let (mut spoke, mut inside, mut crossing) = (0, 0, 0);
        for case in 0..3000 {
            let (c, s) = ([0.9 * rand(), 0.05 + 0.9 * rand()], 0.02 + 0.1 * rand());
            let tilt = 0.1 * (rand() - 0.5);
            let mut a: Vec<V3> = [[0.0, 0.0], [1.0, 0.1], [1.1, 1.0], [-0.1, 0.9]]
                .iter()
                .map(|q| {
                    let (x, y) = (c[0] + s * q[0], c[1] + s * q[1]);
                    [x, y, 1e-3 + tilt * (x - c[0])]
                })
                .collect();
            if case % 4 == 0 {
                a.pop();
            }
            let exact = clipped(&a, &b);
            let own = 0.5
                * norm(match a.len() {
                    3 => cross(sub(a[1], a[0]), sub(a[2], a[0])),
                    _ => cross(sub(a[2], a[0]), sub(a[3], a[1])),
                });
            let got = cover_area(&mut cover, &a, &b);
            // Side B's edge at x = 0.7, seen from a tilted A up to 1e-3 away.
            let max_x = a.iter().fold(0.0f64, |m, p| m.max(p[0]));
            let min_x = a.iter().fold(1.0f64, |m, p| m.min(p[0]));
            if max_x < 0.69 {
                inside += 1;
            } else if min_x < 0.69 && max_x > 0.71 {
                crossing += 1;
                assert!(got.is_none(), "case {case}: side B's edge crosses A");
                assert!(exact < own * (1.0 - 1e-6), "case {case}: {exact} vs {own}");
            }
            if let Some(area) = got {
                spoke += 1;
                assert!(
                    (area - exact).abs() <= 1e-13 * own,
                    "case {case}: {area} vs {exact}"
                );
            }
        }
        assert!(
            crossing > 100 && inside > 1000,
            "{crossing} crossing, {inside} inside"
        );
        assert!(spoke > inside * 9 / 10, "{spoke} of {inside} inside");
    }

    /// Two sheets of side B over A (a double cover, twice A's area when clipped), a
    /// hole, and a face wound the wrong way: the test says nothing.
    #[test]
    fn two_sheets_a_hole_or_a_fold_say_nothing() {
        let mut rand = rng();
        let b = sheet(4, 1.0, 0.0, 0, &mut rand);
        let a: Vec<V3> = vec![
            [0.4, 0.4, 0.01],
            [0.6, 0.4, 0.01],
            [0.6, 0.6, 0.01],
            [0.4, 0.6, 0.01],
        ];
        let mut cover = Cover::default();
        let own = cover_area(&mut cover, &a, &b).expect("one sheet covers A");
        assert!((own - 0.04).abs() < 1e-15);
        let mut two = b.clone();
        two.extend(sheet(4, 1.0, -0.005, 1000, &mut rand));
        assert!((clipped(&a, &two) - 0.08).abs() < 1e-14);
        assert_eq!(cover_area(&mut cover, &a, &two), None);
        let near = |f: &(Vec<V3>, Vec<u32>)| {
            let c =
                f.0.iter()
                    .fold([0.0; 2], |c, p| [c[0] + p[0] / 4.0, c[1] + p[1] / 4.0]);
            (c[0] - 0.5).abs() < 0.2 && (c[1] - 0.5).abs() < 0.2
        };
        let hole: Vec<_> = b.iter().filter(|f| !near(f)).cloned().collect();
        assert_eq!(cover_area(&mut cover, &a, &hole), None);
        let mut fold = b.clone();
        let k = fold.iter().position(near).unwrap();
        fold[k].0.reverse();
        fold[k].1.reverse();
        assert_eq!(cover_area(&mut cover, &a, &fold), None);
        // A slit: a third face on the edge near x = 0.5 of a face left of it, lying over
        // the face right of it (an edge of three faces), which the clipped sum counts.
        let (at, ids) = {
            let f = &b[b
                .iter()
                .position(|f| {
                    let c =
                        f.0.iter()
                            .fold([0.0; 2], |c, p| [c[0] + p[0] / 4.0, c[1] + p[1] / 4.0]);
                    c[0] < 0.5 && c[0] > 0.25 && c[1] > 0.25 && c[1] < 0.5
                })
                .unwrap()];
            (f.0.clone(), f.1.clone())
        };
        // Its edge along x = 0.5 (as wound in this face), and the slit face past it,
        // wound clockwise from above like the rest.
        let k = (0..4)
            .find(|&k| at[k][0] > 0.4 && at[(k + 1) % 4][0] > 0.4)
            .unwrap();
        let (p, q) = (at[k], at[(k + 1) % 4]);
        let (ip, iq) = (ids[k], ids[(k + 1) % 4]);
        let slit = (
            vec![
                q,
                p,
                [p[0] + 0.2, p[1], p[2] - 0.002],
                [q[0] + 0.2, q[1], q[2] - 0.002],
            ],
            vec![iq, ip, 5000, 5001],
        );
        let mut three = b.clone();
        three.push(slit);
        // A side-A face across that edge with its centroid left of it, where one face
        // covers it: only the edge's count of faces tells the double cover right of it.
        let (x0, x1) = (p[0].min(q[0]) - 0.12, p[0].max(q[0]) + 0.02);
        let (y0, y1) = (p[1].min(q[1]) + 0.05, p[1].max(q[1]) - 0.05);
        let a_slit: Vec<V3> = vec![
            [x0, y0, 0.01],
            [x1, y0, 0.01],
            [x1, y1, 0.01],
            [x0, y1, 0.01],
        ];
        let own = (x1 - x0) * (y1 - y0);
        assert!((clipped(&a_slit, &b) - own).abs() < 1e-14);
        assert!(clipped(&a_slit, &three) > own + 1e-4);
        assert_eq!(cover_area(&mut cover, &a_slit, &three), None);
    }
}
