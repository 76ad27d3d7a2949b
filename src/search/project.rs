//! Closest-point projection of a point onto a face, and the shape functions of the faces.
//!
//! Entry points: [`project_point_tri3`], [`project_point_quad4`] and, for the edges of a
//! 2-D mesh, [`project_point_line2`], giving a [`Projection`]; the helpers
//! [`shape_tri3`], [`map_tri3`], [`shape_quad4`], [`dshape_quad4`], [`map_quad4`],
//! [`tangents_quad4`], [`map_line2`], [`normal_line2`].
//!
//! Conventions:
//! - Line2 (an edge of a 2-D mesh, in the xy plane) parametric coordinate `ξ ∈ [-1, 1]`
//!   (the second is 0): `x = ½ (1 − ξ) x₀ + ½ (1 + ξ) x₁`; its normal is the edge direction
//!   turned clockwise by 90° in the xy plane, `(t_y, −t_x, 0)`, which points out of a
//!   counter-clockwise element (the convention of the surfaces' own geometry).
//! - Tri3 parametric coordinates `(ξ, η)`: `x = x₀ + ξ (x₁ − x₀) + η (x₂ − x₀)`, node 0 at
//!   `(0, 0)`, node 1 at `(1, 0)`, node 2 at `(0, 1)`.
//! - Quad4 parametric coordinates `(ξ, η) ∈ [-1, 1]²`, nodes in Exodus order at
//!   `(-1,-1), (1,-1), (1,1), (-1,1)`, bilinear map `x(ξ, η) = Σ Nᵢ(ξ, η) xᵢ` with
//!   `Nᵢ = ¼ (1 + ξ ξᵢ)(1 + η ηᵢ)`; the face may be warped (non-planar).
//! - The normal is the unit vector along `∂x/∂ξ × ∂x/∂η` (right-hand rule of the node
//!   order) at the closest point.
//! - The gap is signed: `gap = (p − point) · normal`, positive when `p` lies on the side
//!   the normal points to. For a side-B face whose normal points out of its body, a
//!   positive gap means `p` is outside that body (open), a negative one that it has
//!   penetrated.
//!
//! The result is the closest point of the *closed* face (the parametric domain is
//! clamped), so `point` is always on the face; `inside` says whether the unconstrained
//! (orthogonal) projection fell within the face. Degenerate faces (zero area) never give
//! NaN: they are flagged and projected onto their edges.

use crate::vec3::{V3, add, axpy, closest_on_segment, cross, dot, norm, norm2, scale, sub};

/// Tolerance on parametric coordinates for [`Projection::inside`]. Parametric
/// coordinates are relative to the face size, so this is a relative tolerance: 1e-10 sits
/// well above the round-off of a projection (≈ 1e-16 × the face's aspect ratio, so it
/// holds for aspect ratios up to ~1e5) and far below any geometric feature of interest,
/// so points snapped onto shared edges and vertices count as inside both faces.
pub const INSIDE_TOL: f64 = 1e-10;

/// A face is degenerate when `|vector area| ≤ DEGENERATE_AREA · (longest edge)²`. Below
/// that ratio the normal computed from the nodes carries a relative error above
/// ε / 1e-10 ≈ 2e-6 rad, so it is not a geometric normal any more.
pub const DEGENERATE_AREA: f64 = 1e-10;

/// An edge of a 2-D mesh is degenerate when its length is at most `DEGENERATE_LENGTH`
/// times its nodes' distance from the origin: 1e-12 is ~4000 ε, so such an edge is the
/// round-off of coordinates that were meant to coincide and its direction (its normal)
/// is noise.
pub const DEGENERATE_LENGTH: f64 = 1e-12;

/// The closest point of a face to a given point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Parametric coordinates of the closest point (see the module conventions).
    pub xi: [f64; 2],
    /// The closest point on the face.
    pub point: [f64; 3],
    /// Unit face normal at `point` (right-hand rule of the node order); zero for a
    /// degenerate face.
    pub normal: [f64; 3],
    /// `(p − point) · normal`: positive on the side the normal points to. For a
    /// degenerate face, the (unsigned) distance.
    pub gap: f64,
    /// `|p − point|`.
    pub distance: f64,
    /// Whether the unconstrained orthogonal projection fell inside the face, within
    /// [`INSIDE_TOL`] in parametric coordinates.
    pub inside: bool,
    /// The face has (almost) zero area ([`DEGENERATE_AREA`]); `point` is then the closest
    /// point on its edges and `normal` is zero.
    pub degenerate: bool,
}

/// Tri3 shape functions `[1 − ξ − η, ξ, η]`.
#[inline]
pub fn shape_tri3(xi: [f64; 2]) -> [f64; 3] {
    [1.0 - xi[0] - xi[1], xi[0], xi[1]]
}

/// The point of a Tri3 face at `xi`: `x₀ + ξ (x₁ − x₀) + η (x₂ − x₀)`.
#[inline]
pub fn map_tri3(x: &[[f64; 3]; 3], xi: [f64; 2]) -> [f64; 3] {
    let e1 = sub(x[1], x[0]);
    let e2 = sub(x[2], x[0]);
    axpy(axpy(x[0], xi[0], e1), xi[1], e2)
}

/// Parametric coordinates of the Quad4 nodes, Exodus order.
pub const QUAD4_NODES: [[f64; 2]; 4] = [[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]];

/// Quad4 shape functions `Nᵢ = ¼ (1 + ξ ξᵢ)(1 + η ηᵢ)`.
#[inline]
pub fn shape_quad4(xi: [f64; 2]) -> [f64; 4] {
    let (a0, a1) = (1.0 - xi[0], 1.0 + xi[0]);
    let (b0, b1) = (1.0 - xi[1], 1.0 + xi[1]);
    [
        0.25 * a0 * b0,
        0.25 * a1 * b0,
        0.25 * a1 * b1,
        0.25 * a0 * b1,
    ]
}

/// Derivatives of the Quad4 shape functions: `[∂N/∂ξ, ∂N/∂η]`.
#[inline]
pub fn dshape_quad4(xi: [f64; 2]) -> [[f64; 4]; 2] {
    let (a0, a1) = (1.0 - xi[0], 1.0 + xi[0]);
    let (b0, b1) = (1.0 - xi[1], 1.0 + xi[1]);
    [
        [-0.25 * b0, 0.25 * b0, 0.25 * b1, -0.25 * b1],
        [-0.25 * a0, -0.25 * a1, 0.25 * a1, 0.25 * a0],
    ]
}

/// The point of a Quad4 face at `xi`: `Σ Nᵢ(ξ, η) xᵢ`.
#[inline]
pub fn map_quad4(x: &[[f64; 3]; 4], xi: [f64; 2]) -> [f64; 3] {
    let n = shape_quad4(xi);
    let mut p = [0.0; 3];
    for (ni, xi_) in n.iter().zip(x) {
        p = axpy(p, *ni, *xi_);
    }
    p
}

/// The covariant tangents `[∂x/∂ξ, ∂x/∂η]` of a Quad4 face at `xi`.
#[inline]
pub fn tangents_quad4(x: &[[f64; 3]; 4], xi: [f64; 2]) -> [[f64; 3]; 2] {
    let d = dshape_quad4(xi);
    let mut t = [[0.0; 3]; 2];
    for i in 0..4 {
        t[0] = axpy(t[0], d[0][i], x[i]);
        t[1] = axpy(t[1], d[1][i], x[i]);
    }
    t
}

/// The vector area of a Quad4 face: `½ (x₂ − x₀) × (x₃ − x₁)` (exact for warped faces as
/// the area of the projection on the plane normal to it).
#[inline]
pub fn vector_area_quad4(x: &[[f64; 3]; 4]) -> [f64; 3] {
    scale(cross(sub(x[2], x[0]), sub(x[3], x[1])), 0.5)
}

/// The point of a Line2 face at `xi` (only `xi[0]` is used): `½ (1 − ξ) x₀ + ½ (1 + ξ) x₁`.
#[inline]
pub fn map_line2(x: &[[f64; 3]; 2], xi: [f64; 2]) -> [f64; 3] {
    let s = xi[0];
    axpy(scale(x[0], 0.5 * (1.0 - s)), 0.5 * (1.0 + s), x[1])
}

/// The unit normal of a Line2 face in the xy plane: its direction turned clockwise by
/// 90°, `(t_y, −t_x, 0)`; zero for an edge of zero length.
#[inline]
pub fn normal_line2(x: &[[f64; 3]; 2]) -> [f64; 3] {
    let d = sub(x[1], x[0]);
    let l = (d[0] * d[0] + d[1] * d[1]).sqrt();
    if l > 0.0 && l.is_finite() {
        [d[1] / l, -d[0] / l, 0.0]
    } else {
        [0.0; 3]
    }
}

/// Whether a face with vector-area norm `area` and longest squared edge `l2` is
/// degenerate ([`DEGENERATE_AREA`]); non-finite sizes count as degenerate.
pub(crate) fn is_degenerate(area: f64, l2: f64) -> bool {
    !l2.is_finite() || area.is_nan() || area <= DEGENERATE_AREA * l2
}

fn longest_edge2<const N: usize>(x: &[[f64; 3]; N]) -> f64 {
    (0..N)
        .map(|i| norm2(sub(x[(i + 1) % N], x[i])))
        .fold(0.0, f64::max)
}

/// Closest point on the boundary of a closed polygon (edges `x[i] → x[i+1]`): returns the
/// edge index, the edge parameter and the squared distance. The first minimum wins.
fn closest_on_boundary<const N: usize>(p: V3, x: &[[f64; 3]; N]) -> (usize, f64, f64) {
    let mut best = (0, 0.0, f64::INFINITY);
    for i in 0..N {
        let (t, d2) = closest_on_segment(p, x[i], x[(i + 1) % N]);
        if d2 < best.2 {
            best = (i, t, d2);
        }
    }
    best
}

fn finish(
    p: V3,
    xi: [f64; 2],
    point: V3,
    normal: V3,
    inside: bool,
    degenerate: bool,
) -> Projection {
    let d = sub(p, point);
    let distance = norm(d);
    let gap = if degenerate { distance } else { dot(d, normal) };
    Projection {
        xi,
        point,
        normal,
        gap,
        distance,
        inside,
        degenerate,
    }
}

/// Closest point of the Tri3 face `x` to `p`.
///
/// Exact: the orthogonal projection on the plane, `q = x₀ + ξ e₁ + η e₂`, solves the 2×2
/// normal equations `[e₁·e₁ e₁·e₂; e₁·e₂ e₂·e₂] (ξ, η) = (e₁·d, e₂·d)` with
/// `d = p − x₀`. If `q` lies in the triangle (barycentric region test) it is the closest
/// point; otherwise, since `|p − y|² = |p − q|² + |q − y|²` for every `y` of the plane,
/// the closest point is the closest point of the boundary, found edge by edge.
pub fn project_point_tri3(p: [f64; 3], x: &[[f64; 3]; 3]) -> Projection {
    let e1 = sub(x[1], x[0]);
    let e2 = sub(x[2], x[0]);
    let nv = cross(e1, e2);
    let l2 = longest_edge2(x);
    let degenerate = is_degenerate(norm(nv), l2);
    if degenerate {
        return project_degenerate(p, x, |edge, t| match edge {
            0 => [t, 0.0],
            1 => [1.0 - t, t],
            _ => [0.0, 1.0 - t],
        });
    }
    let normal = scale(nv, 1.0 / norm(nv));
    let d = sub(p, x[0]);
    let (a11, a12, a22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
    let (b1, b2) = (dot(e1, d), dot(e2, d));
    // det = |e₁ × e₂|², positive for a non-degenerate face.
    let det = norm2(nv);
    let xi = (a22 * b1 - a12 * b2) / det;
    let eta = (a11 * b2 - a12 * b1) / det;
    let inside = xi >= -INSIDE_TOL && eta >= -INSIDE_TOL && xi + eta <= 1.0 + INSIDE_TOL;
    if xi >= 0.0 && eta >= 0.0 && xi + eta <= 1.0 {
        // The foot of the perpendicular, `p − ((p − x₀)·n) n`, rather than `x(ξ, η)`: it
        // is the same point, but a `p` lying in the plane of an axis-aligned face comes
        // back exactly (distance 0, not the round-off of re-mapping ξ).
        let q = axpy(p, -dot(d, normal), normal);
        return finish(p, [xi, eta], q, normal, true, false);
    }
    let (edge, t, _) = closest_on_boundary(p, x);
    let xi = match edge {
        0 => [t, 0.0],
        1 => [1.0 - t, t],
        _ => [0.0, 1.0 - t],
    };
    finish(p, xi, map_tri3(x, xi), normal, inside, false)
}

/// Closest point of the Line2 face `x` (an edge of a 2-D mesh) to `p`.
///
/// Exact: the foot of the perpendicular on the edge's line, `ξ = 2 (p − c)·e / |e|²` with
/// `c` the midpoint and `e = x₁ − x₀`, clamped to `[-1, 1]`. `inside` when the unclamped
/// ξ lies within [`INSIDE_TOL`] of the edge. An edge whose length is not above
/// [`DEGENERATE_LENGTH`] times its nodes' distance from the origin (or not finite) is
/// degenerate: the closest point is taken and the normal is zero.
pub fn project_point_line2(p: [f64; 3], x: &[[f64; 3]; 2]) -> Projection {
    let e = sub(x[1], x[0]);
    let ee = dot(e, e);
    let size2 = norm2(x[0]).max(norm2(x[1]));
    let normal = normal_line2(x);
    let degenerate = !(ee > DEGENERATE_LENGTH * DEGENERATE_LENGTH * size2 && ee.is_finite());
    if degenerate || normal == [0.0; 3] {
        let (t, _) = closest_on_segment(p, x[0], x[1]);
        let xi = [2.0 * t - 1.0, 0.0];
        return finish(p, xi, map_line2(x, xi), [0.0; 3], false, true);
    }
    let c = scale(add(x[0], x[1]), 0.5);
    let xi = 2.0 * dot(sub(p, c), e) / ee;
    let inside = xi.abs() <= 1.0 + INSIDE_TOL;
    let clamped = [xi.clamp(-1.0, 1.0), 0.0];
    if xi.abs() <= 1.0 {
        // The foot of the perpendicular, `p − ((p − x₀)·n) n`, so a point on an
        // axis-aligned edge comes back exactly (as for the triangles).
        let q = axpy(p, -dot(sub(p, x[0]), normal), normal);
        return finish(p, clamped, q, normal, true, false);
    }
    finish(p, clamped, map_line2(x, clamped), normal, inside, false)
}

/// Closest point on the edges of a degenerate face; `to_xi(edge, t)` gives the
/// parametric coordinates of the point at parameter `t` on `edge`.
fn project_degenerate<const N: usize>(
    p: V3,
    x: &[[f64; 3]; N],
    to_xi: impl Fn(usize, f64) -> [f64; 2],
) -> Projection {
    let (edge, t, _) = closest_on_boundary(p, x);
    let point = axpy(x[edge], t, sub(x[(edge + 1) % N], x[edge]));
    finish(p, to_xi(edge, t), point, [0.0; 3], false, true)
}

/// Parametric coordinates of the point at parameter `t` on edge `e` of a Quad4
/// (edge `e` runs from node `e` to node `e + 1`).
fn quad4_edge_xi(e: usize, t: f64) -> [f64; 2] {
    let a = QUAD4_NODES[e];
    let b = QUAD4_NODES[(e + 1) % 4];
    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
}

/// Maximum Newton iterations of [`project_point_quad4`]; quadratic convergence needs
/// ~5 from a reasonable start, the rest is room for damped steps on warped faces.
const QUAD4_MAX_ITER: usize = 30;

/// Newton stops when the parametric step is below this: the step of the next iteration
/// would be ~1e-24, so the last accepted iterate is converged to round-off.
const QUAD4_STEP_TOL: f64 = 1e-12;

/// Unit normal of a Quad4 at `xi`: along `∂x/∂ξ × ∂x/∂η`, falling back to the vector
/// area where the tangents are (near) parallel, as at a collapsed corner.
fn normal_quad4(x: &[[f64; 3]; 4], xi: [f64; 2], area_normal: V3) -> V3 {
    let t = tangents_quad4(x, xi);
    let c = cross(t[0], t[1]);
    if norm(c) > DEGENERATE_AREA * (norm2(t[0]) + norm2(t[1])) {
        scale(c, 1.0 / norm(c))
    } else {
        area_normal
    }
}

/// Closest point of the bilinear Quad4 face `x` (possibly warped) to `p`.
///
/// A planar, convex face (the common case) takes a fast exact path: see
/// `project_planar_quad4` (edge-line tests, then the inverse bilinear map of the foot of
/// the perpendicular). Otherwise the general path below runs.
///
/// General path: minimises `f(ξ) = ½ |x(ξ) − p|²` over `[-1, 1]²`. Interior stationary points solve
/// `g = (x_ξ · r, x_η · r) = 0`, `r = x(ξ) − p`, by Newton with the Hessian
/// `H = [x_ξ·x_ξ, x_ξ·x_η + x_ξη·r; ·, x_η·x_η]` (`x_ξξ = x_ηη = 0` for a bilinear map,
/// `x_ξη = ¼ (x₀ − x₁ + x₂ − x₃)`), switching to the Gauss–Newton matrix `JᵀJ` where `H`
/// is not positive definite, with the step limited to the square's size and halved until
/// `f` does not increase. The start is the better of the projections on the two
/// triangles `(0, 1, 2)` and `(0, 2, 3)`.
///
/// The edges of a bilinear face are straight segments, so the minimum on the boundary is
/// found exactly; it is taken when Newton fails or converges outside the square, and
/// compared with the interior point on a warped face (which can have several local
/// minima; when the boundary wins, `inside` is false). Never NaN for finite input.
pub fn project_point_quad4(p: [f64; 3], x: &[[f64; 3]; 4]) -> Projection {
    let va = vector_area_quad4(x);
    let l2 = longest_edge2(x);
    if is_degenerate(norm(va), l2) {
        return project_degenerate(p, x, quad4_edge_xi);
    }
    let area_normal = scale(va, 1.0 / norm(va));
    // `w = x₀ − x₁ + x₂ − x₃` measures the twist out of the plane; 1e-12 of the size is
    // round-off of coordinates that were meant to be coplanar.
    let w_n = dot(sub(add(x[0], x[2]), add(x[1], x[3])), area_normal).abs();
    let warped = w_n > 1e-12 * l2.sqrt();
    if !warped && let Some(pr) = project_planar_quad4(p, x, area_normal, l2) {
        return pr;
    }

    // Interior stationary points from Newton; the closest one found competes with the
    // closest boundary point (exact: the edges are straight).
    let (edge, t, d2_edge) = closest_on_boundary(p, x);
    type Stationary = Option<([f64; 2], V3, f64)>;
    let stationary = |xi0: [f64; 2]| -> Stationary {
        let (xi, converged) = newton_quad4(p, x, xi0);
        if !(converged && xi[0].abs() <= 1.0 + INSIDE_TOL && xi[1].abs() <= 1.0 + INSIDE_TOL) {
            return None;
        }
        let xi_c = [xi[0].clamp(-1.0, 1.0), xi[1].clamp(-1.0, 1.0)];
        let q = if warped {
            map_quad4(x, xi_c)
        } else {
            // Planar: the foot of the perpendicular, as in `project_point_tri3`.
            axpy(p, -dot(sub(p, x[0]), area_normal), area_normal)
        };
        Some((xi_c, q, norm2(sub(p, q))))
    };
    let closer = |a: Stationary, b: Stationary| match (a, b) {
        (Some(u), Some(v)) => Some(if v.2 < u.2 { v } else { u }),
        (u, v) => u.or(v),
    };
    let mut best = stationary(start_quad4(p, x));
    // One start finds the global minimum when p is well inside the face's tubular
    // neighbourhood: the curvature of a bilinear patch is about κ = |x_ξη·n| / (|x_ξ||x_η|)
    // ≈ |w·n| / A (twist over area), and within a quarter of 1/κ the stationary point is
    // unique. Farther out, and for folded faces (the Jacobian turns against the normal
    // at a corner, as for a non-convex or bow-tie quad), several local minima can exist:
    // restart from a 3 × 3 grid of the square and keep the closest.
    let folded = (0..4).any(|k| {
        let e_prev = sub(x[k], x[(k + 3) % 4]);
        let e = sub(x[(k + 1) % 4], x[k]);
        dot(cross(e_prev, e), area_normal) <= 0.0
    });
    let d_now = best.map_or(d2_edge, |b| b.2.min(d2_edge)).sqrt();
    // A first start that finds no stationary point inside says nothing about the
    // others: restart too.
    if !warped || folded || best.is_none() || d_now * w_n > 0.25 * norm(va) {
        for a in [-0.5, 0.0, 0.5] {
            for b in [-0.5, 0.0, 0.5] {
                best = closer(best, stationary([a, b]));
            }
        }
    }
    // A strongly twisted face can hide its closest point in a valley a 3 × 3 grid does
    // not start in: where a 5 × 5 sample of the face is closer than what was found,
    // start Newton from that sample too.
    if warped {
        let found = best.map_or(d2_edge, |b| b.2.min(d2_edge));
        let mut seed = None;
        let mut d2_seed = found;
        for a in [-0.8, -0.4, 0.0, 0.4, 0.8] {
            for b in [-0.8, -0.4, 0.0, 0.4, 0.8] {
                let d2 = norm2(sub(p, map_quad4(x, [a, b])));
                if d2 < d2_seed {
                    d2_seed = d2;
                    seed = Some([a, b]);
                }
            }
        }
        if let Some(xi0) = seed {
            best = closer(best, stationary(xi0));
        }
    }
    if let Some((xi_c, q, d2)) = best
        && d2 <= d2_edge
    {
        let normal = if warped {
            normal_quad4(x, xi_c, area_normal)
        } else {
            area_normal
        };
        return finish(p, xi_c, q, normal, true, false);
    }
    let xi_b = quad4_edge_xi(edge, t);
    let q_b = axpy(x[edge], t, sub(x[(edge + 1) % 4], x[edge]));
    let normal = normal_quad4(x, xi_b, area_normal);
    finish(p, xi_b, q_b, normal, false, false)
}

/// Iterations of the planar inverse map: from the centre of a convex quad Newton
/// converges quadratically in ≤ 5 steps; more means the point is far outside.
const PLANAR_MAX_ITER: usize = 12;

/// The fast path of [`project_point_quad4`] for a planar, strictly convex quad: the
/// closest point is the in-plane closest point of the foot `q = p − ((p − x₀)·n) n`
/// (Pythagoras).
///
/// - If `p` lies clearly outside one of the edge lines (by more than
///   [`PLANAR_OUTSIDE`] × the edge × the longest edge, far beyond the parametric
///   [`INSIDE_TOL`] band), it is outside the face and its closest point is on an edge whose
///   line it lies outside of (for a convex polygon the normal cone at the closest
///   boundary point contains `p − y`, and at a corner `p` is outside at least one of the
///   two adjacent edge lines), so only those edges are searched.
/// - Otherwise `x(ξ) = q` is inverted by Newton from the centre (`J Δ = −r` through
///   `JᵀJ Δ = −Jᵀr`, exact as `r` lies in the plane of `J`'s columns); convexity makes the
///   inverse unique. Outside the square (beyond [`INSIDE_TOL`]) the boundary is searched.
///
/// `None` for a non-convex quad or no convergence: the general path then runs.
fn project_planar_quad4(p: V3, x: &[[f64; 3]; 4], n: V3, l2: f64) -> Option<Projection> {
    let mut side = [0.0; 4];
    let mut len2 = [0.0; 4];
    for k in 0..4 {
        let e = sub(x[(k + 1) % 4], x[k]);
        let e_prev = sub(x[k], x[(k + 3) % 4]);
        // Strictly convex and oriented with n: every corner turns left about n.
        if dot(cross(e_prev, e), n) <= 0.0 {
            return None;
        }
        // |e| × signed distance of p to the left of edge k (positive inside).
        side[k] = dot(cross(e, sub(p, x[k])), n);
        len2[k] = norm2(e);
    }
    // side < −PLANAR_OUTSIDE |e| l, squared to spare four square roots.
    let tol2 = PLANAR_OUTSIDE * PLANAR_OUTSIDE * l2;
    let clearly_outside = (0..4).any(|k| side[k] < 0.0 && side[k] * side[k] > tol2 * len2[k]);
    if !clearly_outside {
        let h = dot(sub(p, x[0]), n);
        let q = axpy(p, -h, n);
        if let Some(xi) = invert_planar_quad4(x, q, n) {
            if xi[0].abs() <= 1.0 + INSIDE_TOL && xi[1].abs() <= 1.0 + INSIDE_TOL {
                let xi_c = [xi[0].clamp(-1.0, 1.0), xi[1].clamp(-1.0, 1.0)];
                return Some(finish(p, xi_c, q, n, true, false));
            }
        } else {
            return None;
        }
    }
    // Closest point on the edges p lies outside of (all four if round-off left none).
    let any_facing = side.iter().any(|&s| s <= 0.0);
    let mut best = (0, 0.0, f64::INFINITY);
    for k in 0..4 {
        if any_facing && side[k] > 0.0 {
            continue;
        }
        let (t, d2) = closest_on_segment(p, x[k], x[(k + 1) % 4]);
        if d2 < best.2 {
            best = (k, t, d2);
        }
    }
    let (edge, t, _) = best;
    let xi_b = quad4_edge_xi(edge, t);
    let q_b = axpy(x[edge], t, sub(x[(edge + 1) % 4], x[edge]));
    Some(finish(p, xi_b, q_b, n, false, false))
}

/// Relative distance beyond an edge line above which a point is surely outside a planar
/// quad (see [`project_planar_quad4`]): 1e-8 is far above round-off, and as a parametric
/// distance (≥ 1e-8 / 2 for any shape) far above [`INSIDE_TOL`].
const PLANAR_OUTSIDE: f64 = 1e-8;

/// Inverts the bilinear map of a planar convex quad at the in-plane point `q` by Newton
/// from the centre; `None` when the Jacobian is singular or Newton does not converge.
///
/// Monomial form `x(ξ, η) = c₀ + c₁ ξ + c₂ η + c₃ ξη` (the shape functions expanded),
/// written in the in-plane basis `t₁ = c₁/|c₁|`, `t₂ = n × t₁`: all `cₖ` lie in the
/// plane, so the 2-D system `C₀ + C₁ ξ + C₂ η + C₃ ξη = Q` is equivalent and each Newton
/// step is a 2×2 solve of a dozen flops.
fn invert_planar_quad4(x: &[[f64; 3]; 4], q: V3, n: V3) -> Option<[f64; 2]> {
    let c0 = sub(scale(add(add(x[0], x[1]), add(x[2], x[3])), 0.25), q);
    let c1 = scale(sub(add(x[1], x[2]), add(x[0], x[3])), 0.25);
    let c2 = scale(sub(add(x[2], x[3]), add(x[0], x[1])), 0.25);
    let c3 = scale(sub(add(x[0], x[2]), add(x[1], x[3])), 0.25);
    let t1 = scale(c1, 1.0 / norm(c1));
    let t2 = cross(n, t1);
    let to2 = |c: V3| [dot(c, t1), dot(c, t2)];
    let (r0, a, b, w) = (to2(c0), to2(c1), to2(c2), to2(c3));
    let mut xi = [0.0f64, 0.0];
    for _ in 0..PLANAR_MAX_ITER {
        // J = [a + w η | b + w ξ], r = r₀ + a ξ + b η + w ξη.
        let ja = [a[0] + w[0] * xi[1], a[1] + w[1] * xi[1]];
        let jb = [b[0] + w[0] * xi[0], b[1] + w[1] * xi[0]];
        let r = [
            r0[0] + ja[0] * xi[0] + b[0] * xi[1],
            r0[1] + ja[1] * xi[0] + b[1] * xi[1],
        ];
        let det = ja[0] * jb[1] - jb[0] * ja[1];
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let mut step = [
            -(jb[1] * r[0] - jb[0] * r[1]) * inv,
            -(ja[0] * r[1] - ja[1] * r[0]) * inv,
        ];
        let s = step[0].abs().max(step[1].abs());
        if s > 1.0 {
            step = [step[0] / s, step[1] / s];
        }
        xi = [xi[0] + step[0], xi[1] + step[1]];
        // The step that follows one of 1e-13 is ~1e-26: xi is at round-off.
        if s < 1e-13 {
            return Some(xi);
        }
    }
    None
}

/// Starting guess for the Quad4 Newton: (ξ, η) at the plane projection on the better of
/// the two triangles `(0, 1, 2)`, `(0, 2, 3)`, unclamped. For a parallelogram the
/// bilinear map is affine and this is already the answer.
fn start_quad4(p: V3, x: &[[f64; 3]; 4]) -> [f64; 2] {
    // Barycentric (λ₁, λ₂) of the plane projection on triangle (x₀, xₐ, x_b).
    let plane = |a: V3, b: V3| -> Option<[f64; 2]> {
        let e1 = sub(a, x[0]);
        let e2 = sub(b, x[0]);
        let d = sub(p, x[0]);
        let (a11, a12, a22) = (dot(e1, e1), dot(e1, e2), dot(e2, e2));
        let det = a11 * a22 - a12 * a12;
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let (b1, b2) = (dot(e1, d), dot(e2, d));
        Some([(a22 * b1 - a12 * b2) / det, (a11 * b2 - a12 * b1) / det])
    };
    // Triangle (0,1,2): ξ = -1 + 2λ₁ + 2λ₂, η = -1 + 2λ₂.
    // Triangle (0,2,3): ξ = -1 + 2λ₁,       η = -1 + 2λ₁ + 2λ₂.
    let t1 = plane(x[1], x[2]).map(|[l1, l2]| [-1.0 + 2.0 * (l1 + l2), -1.0 + 2.0 * l2]);
    let t2 = plane(x[2], x[3]).map(|[l1, l2]| [-1.0 + 2.0 * l1, -1.0 + 2.0 * (l1 + l2)]);
    // Prefer the triangle whose half of the square (ξ ≥ η for the first) holds the guess.
    match (t1, t2) {
        (Some(a), _) if a[0] >= a[1] => a,
        (_, Some(b)) if b[1] >= b[0] => b,
        (Some(a), _) => a,
        (_, Some(b)) => b,
        _ => [0.0, 0.0],
    }
    .map(|v| {
        if v.is_finite() {
            v.clamp(-3.0, 3.0)
        } else {
            0.0
        }
    })
}

/// Damped Newton for the stationary point of `½ |x(ξ) − p|²`; returns the last iterate
/// and whether the step fell below [`QUAD4_STEP_TOL`].
fn newton_quad4(p: V3, x: &[[f64; 3]; 4], mut xi: [f64; 2]) -> ([f64; 2], bool) {
    let x_xe = scale(add(sub(x[0], x[1]), sub(x[2], x[3])), 0.25);
    let mut r = sub(map_quad4(x, xi), p);
    let mut f = norm2(r);
    for _ in 0..QUAD4_MAX_ITER {
        let [ta, tb] = tangents_quad4(x, xi);
        let g = [dot(ta, r), dot(tb, r)];
        let (a11, a22) = (dot(ta, ta), dot(tb, tb));
        let a12_gn = dot(ta, tb);
        let a12 = a12_gn + dot(x_xe, r);
        let solve = |h12: f64| -> Option<[f64; 2]> {
            let det = a11 * a22 - h12 * h12;
            (a11 > 0.0 && det > 1e-14 * a11 * a22).then(|| {
                [
                    -(a22 * g[0] - h12 * g[1]) / det,
                    -(a11 * g[1] - h12 * g[0]) / det,
                ]
            })
        };
        let Some(mut step) = solve(a12).or_else(|| solve(a12_gn)) else {
            return (xi, false);
        };
        // Limit the step to the size of the square.
        let s_max = step[0].abs().max(step[1].abs());
        if s_max > 2.0 {
            step = [step[0] * 2.0 / s_max, step[1] * 2.0 / s_max];
        }
        // Backtracking: halve until f does not increase (at most 2⁻³⁰). Near the solution
        // (steps below 1e-4, inside the region of quadratic convergence) the full step is
        // taken: f is flat to round-off there (δf ≈ |x_ξ|² δξ² is below ε |x|² for δξ
        // below ~1e-8), so comparing f would stall ξ at ~1e-8 instead of ~1e-15.
        let mut accepted = false;
        let near = step[0].abs().max(step[1].abs()) < 1e-4;
        for _ in 0..30 {
            let trial = [xi[0] + step[0], xi[1] + step[1]];
            let r_t = sub(map_quad4(x, trial), p);
            let f_t = norm2(r_t);
            if near || f_t <= f {
                xi = trial;
                r = r_t;
                f = f_t;
                accepted = true;
                break;
            }
            step = [0.5 * step[0], 0.5 * step[1]];
        }
        let s = step[0].abs().max(step[1].abs());
        if s < QUAD4_STEP_TOL || (!accepted && s < 1e-8) {
            return (xi, true);
        }
        if !accepted {
            return (xi, false);
        }
    }
    (xi, false)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TOL: f64 = 1e-13;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    const SQUARE: [[f64; 3]; 4] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];

    #[test]
    fn shape_functions_partition_unity_and_interpolate_nodes() {
        for (k, xk) in QUAD4_NODES.iter().enumerate() {
            let n = shape_quad4(*xk);
            for (i, ni) in n.iter().enumerate() {
                assert_eq!(*ni, if i == k { 1.0 } else { 0.0 });
            }
        }
        let n = shape_quad4([0.3, -0.7]);
        assert!(close(n.iter().sum::<f64>(), 1.0, 1e-15));
        assert_eq!(shape_tri3([0.25, 0.5]), [0.25, 0.25, 0.5]);
    }

    #[test]
    fn unit_square_interior_edge_corner() {
        let pr = project_point_quad4([0.25, 0.75, 0.5], &SQUARE);
        assert!(pr.inside && !pr.degenerate);
        assert!(close(pr.xi[0], -0.5, TOL) && close(pr.xi[1], 0.5, TOL));
        assert!(close(pr.gap, 0.5, TOL) && close(pr.distance, 0.5, TOL));
        assert_eq!(pr.normal, [0.0, 0.0, 1.0]);
        // Below the face: negative gap.
        let pr = project_point_quad4([0.5, 0.5, -2.0], &SQUARE);
        assert!(close(pr.gap, -2.0, TOL) && pr.inside);
        // Beyond edge x = 1: closest point on the edge, outside.
        let pr = project_point_quad4([3.0, 0.5, 4.0], &SQUARE);
        assert!(!pr.inside);
        assert!(close(pr.xi[0], 1.0, TOL) && close(pr.xi[1], 0.0, TOL));
        assert!(close(pr.distance, 20f64.sqrt(), TOL) && close(pr.gap, 4.0, TOL));
        // Beyond a corner.
        let pr = project_point_quad4([-1.0, -1.0, 0.0], &SQUARE);
        assert_eq!(pr.xi, [-1.0, -1.0]);
        assert!(close(pr.distance, 2f64.sqrt(), TOL));
    }

    #[test]
    fn warped_quad_hyperbolic_paraboloid() {
        // Nodes on z = x y over [-1,1]²: the bilinear map is x = ξ, y = η, z = ξ η (the
        // saddle itself). Its normal at (ξ, η) is (−η, −ξ, 1)/√(1+ξ²+η²), so the point
        // p = x(ξ*, η*) + s n(ξ*, η*) has closest point x(ξ*, η*) for small s (|s| below
        // the radius of curvature, which is ≥ 1 on this patch).
        let x = [
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, 1.0],
            [-1.0, 1.0, -1.0],
        ];
        let (a, b): (f64, f64) = (0.3, -0.4);
        let m = 1.0 + a * a + b * b;
        let n = [-b / m.sqrt(), -a / m.sqrt(), 1.0 / m.sqrt()];
        for s in [0.2, -0.2, 0.0] {
            let p = [a + s * n[0], b + s * n[1], a * b + s * n[2]];
            let pr = project_point_quad4(p, &x);
            assert!(pr.inside);
            assert!(
                close(pr.xi[0], a, 1e-12) && close(pr.xi[1], b, 1e-12),
                "{pr:?}"
            );
            assert!(close(pr.gap, s, 1e-12) && close(pr.distance, s.abs(), 1e-12));
            for (got, want) in pr.normal.iter().zip(&n) {
                assert!(close(*got, *want, 1e-12));
            }
        }
    }

    #[test]
    fn planar_quad_outside_acute_corner() {
        // A convex quad with an acute corner at node 1 (interior angle ≈ 18°). Points
        // around that corner are compared with a fine sampling of the closed face.
        let x = [
            [0.0, 0.0, 0.0],
            [3.0, 0.5, 0.0],
            [0.0, 1.0, 0.0],
            [-0.5, 0.5, 0.0],
        ];
        for p in [
            [4.0, 0.5, 0.3],
            [3.5, 0.0, -0.2],
            [3.2, 1.5, 0.0],
            [2.0, -1.0, 0.1],
        ] {
            let pr = project_point_quad4(p, &x);
            assert!(!pr.inside && !pr.degenerate);
            let mut best = f64::INFINITY;
            for i in 0..=400 {
                for j in 0..=400 {
                    let xi = [-1.0 + i as f64 / 200.0, -1.0 + j as f64 / 200.0];
                    best = best.min(norm(sub(p, map_quad4(&x, xi))));
                }
            }
            assert!(
                pr.distance <= best + 1e-14 && pr.distance >= best - 1e-3,
                "{p:?}"
            );
            assert!(norm(sub(pr.point, map_quad4(&x, pr.xi))) < 1e-14);
        }
    }

    #[test]
    fn folded_quad_finds_the_interior_minimum() {
        // Found by the property test on arbitrary quads: a strongly warped, folded face
        // whose closest point (ξ ≈ (−0.265, −0.106), by sampling) a single Newton start
        // misses, returning a boundary point 0.0048 farther away.
        let x = [
            [-0.567847524576703, 0.825426595631995, -0.21438333220437528],
            [
                0.5108355663097093,
                -0.7206922048406489,
                -0.22020777530687866,
            ],
            [0.2274357683533758, -0.3331669944504791, -0.362425769411658],
            [
                -0.13779206830358143,
                0.7565022146436776,
                -0.4241812587545802,
            ],
        ];
        let p = [-0.6079691828968687, 0.0, -0.9242297518048601];
        let pr = project_point_quad4(p, &x);
        assert!(pr.inside && pr.distance < 0.86210, "{pr:?}");
        assert!(close(pr.xi[0], -0.2645, 1e-3) && close(pr.xi[1], -0.1061, 1e-3));
        // Stationary: p − point is along the normal.
        let d = sub(p, pr.point);
        assert!(norm(cross(d, pr.normal)) < 1e-12);
    }

    #[test]
    fn tri3_regions() {
        let x = [[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.0]];
        let pr = project_point_tri3([0.5, 0.5, -1.0], &x);
        assert!(pr.inside);
        assert!(close(pr.xi[0], 0.25, TOL) && close(pr.xi[1], 0.25, TOL));
        assert!(close(pr.gap, -1.0, TOL));
        // Closest to the hypotenuse's midpoint.
        let pr = project_point_tri3([2.0, 2.0, 0.0], &x);
        assert!(!pr.inside);
        assert!(close(pr.xi[0], 0.5, TOL) && close(pr.xi[1], 0.5, TOL));
        assert!(close(pr.distance, 2f64.sqrt(), TOL));
        // Vertex region of node 2.
        let pr = project_point_tri3([-1.0, 3.0, 1.0], &x);
        assert_eq!(pr.xi, [0.0, 1.0]);
        assert!(close(pr.distance, 3f64.sqrt(), TOL));
    }

    #[test]
    fn degenerate_faces_are_flagged_not_nan() {
        let line = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
        let pr = project_point_tri3([1.5, 1.0, 0.0], &line);
        assert!(pr.degenerate && !pr.inside);
        assert!(close(pr.distance, 1.0, TOL) && pr.point == [1.5, 0.0, 0.0]);
        let point = [[1.0, 1.0, 1.0]; 4];
        let pr = project_point_quad4([1.0, 1.0, 2.0], &point);
        assert!(pr.degenerate && close(pr.distance, 1.0, TOL));
        assert!(pr.xi.iter().chain(&pr.normal).all(|v| v.is_finite()));
        // A quad collapsed to a triangle (nodes 2 and 3 coincide) is not degenerate.
        let collapsed = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let pr = project_point_quad4([0.2, 0.2, 1.0], &collapsed);
        assert!(!pr.degenerate && pr.inside && close(pr.gap, 1.0, TOL));
        assert!(close(pr.point[0], 0.2, TOL) && close(pr.point[1], 0.2, TOL));
    }

    /// An edge of a 2-D mesh: interior, beyond either end, on the edge, and degenerate.
    /// The edge (2, 1) → (0, 1) runs in −x, so its normal (t_y, −t_x) is +y.
    #[test]
    fn line2_interior_ends_and_degenerate() {
        let e = [[2.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        assert_eq!(normal_line2(&e), [0.0, 1.0, 0.0]);
        let pr = project_point_line2([0.5, 1.25, 0.0], &e);
        assert!(pr.inside && !pr.degenerate);
        assert!(close(pr.xi[0], 0.5, TOL) && pr.xi[1] == 0.0);
        assert_eq!(pr.point, [0.5, 1.0, 0.0]);
        assert!(close(pr.gap, 0.25, TOL) && close(pr.distance, 0.25, TOL));
        // Below the edge: a negative gap.
        let pr = project_point_line2([1.5, 0.5, 0.0], &e);
        assert!(pr.inside && close(pr.gap, -0.5, TOL) && close(pr.xi[0], -0.5, TOL));
        // Beyond node 1 (ξ = 1.5): clamped onto the node, not inside.
        let pr = project_point_line2([-0.5, 2.0, 0.0], &e);
        assert!(!pr.inside && pr.xi[0] == 1.0 && pr.point == [0.0, 1.0, 0.0]);
        assert!(close(pr.distance, 1.25f64.sqrt(), TOL) && close(pr.gap, 1.0, TOL));
        // Just past node 0, within the tolerance: inside.
        let pr = project_point_line2([2.0 + 1e-12, 1.0, 0.0], &e);
        assert!(pr.inside && pr.xi[0] == -1.0);
        // The point maps back to itself on the edge.
        let q = map_line2(&e, [0.3, 0.0]);
        assert!(close(q[0], 0.7, TOL) && q[1] == 1.0);
        // A zero-length edge: degenerate, finite, the node itself.
        let pr = project_point_line2([1.0, 2.0, 0.0], &[[1.0, 1.0, 0.0]; 2]);
        assert!(pr.degenerate && !pr.inside && pr.normal == [0.0; 3]);
        assert!(close(pr.distance, 1.0, TOL) && close(pr.gap, 1.0, TOL));
        let nan = project_point_line2([0.0; 3], &[[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0]]);
        assert!(nan.degenerate);
    }
}
