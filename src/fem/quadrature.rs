//! Quadrature rules on the reference cells of [`super::shape`].
//!
//! Standard rules ([`QuadratureRule::standard`]): `Hex8` 2×2×2 Gauss, `Tet4` 4-point
//! (degree 2; [`QuadratureRule::tet4_one_point`] for the centroid rule), `Wedge6` 3-point
//! triangle × 2-point Gauss, `Pyramid5` 2×2×3 collapsed (Duffy) Gauss, `Quad4` 2×2,
//! `Tri3` 3-point (degree 2). [`QuadratureRule::with_degree`] gives a rule exact for
//! polynomials of a chosen total degree (tensor Gauss on cubes, Stroud's conical
//! product — Gauss rules on the collapsed cube — on simplices and the pyramid), used for
//! error norms.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::mesh::{FaceShape, Topology};

/// Points (reference coordinates, 2-D rules leave the third 0) and weights.
#[derive(Clone, Debug, PartialEq)]
pub struct QuadratureRule {
    pub points: Vec<[f64; 3]>,
    pub weights: Vec<f64>,
}

/// Gauss–Legendre nodes and weights on [−1, 1] with `n` points (exact to degree
/// 2n − 1), nodes ascending: the one Gauss rule of seam, which every other rule and
/// every Gauss loop (element, face, mortar segment, tributary area) is built on.
///
/// Up to three points in closed form (0 and 2; ±1/√3 and 1; 0, ±√(3/5) and 5/9, 8/9),
/// so the rules of the common low orders are exact to the last bit; above, by Newton's
/// method on the Legendre polynomial P_n from the Tricomi-type initial guess
/// cos(π(i + ¾)/(n + ½)), converged to round-off in < 10 steps.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    match n {
        1 => return (vec![0.0], vec![2.0]),
        2 => {
            let g = 1.0 / 3f64.sqrt();
            return (vec![-g, g], vec![1.0, 1.0]);
        }
        3 => {
            let g = 0.6f64.sqrt();
            return (vec![-g, 0.0, g], vec![5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0]);
        }
        _ => {}
    }
    let mut x = vec![0.0; n];
    let mut w = vec![0.0; n];
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // Three-term recurrence for P_n(z) and P_{n−1}(z).
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * z * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            // P_n'(z) = n (z P_n − P_{n−1}) / (z² − 1)
            dp = n as f64 * (z * p1 - p0) / (z * z - 1.0);
            let dz = p1 / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x[i] = -z;
        w[i] = 2.0 / ((1.0 - z * z) * dp * dp);
    }
    (x, w)
}

/// [`gauss_legendre`] mapped to [0, 1]: nodes `(1 + x)/2`, weights `w/2`.
pub fn gauss_legendre_01(n: usize) -> (Vec<f64>, Vec<f64>) {
    let (x, w) = gauss_legendre(n);
    (
        x.iter().map(|x| 0.5 * (x + 1.0)).collect(),
        w.iter().map(|w| 0.5 * w).collect(),
    )
}

fn points_for(degree: usize) -> usize {
    degree / 2 + 1
}

impl QuadratureRule {
    fn push(&mut self, p: [f64; 3], w: f64) {
        self.points.push(p);
        self.weights.push(w);
    }

    fn empty() -> Self {
        QuadratureRule {
            points: Vec::new(),
            weights: Vec::new(),
        }
    }

    pub fn len(&self) -> usize {
        self.weights.len()
    }

    pub fn is_empty(&self) -> bool {
        self.weights.is_empty()
    }

    /// The element's standard rule (see the module doc). `None` for shells and beams.
    pub fn standard(topology: Topology) -> Option<Self> {
        Some(match topology {
            Topology::Hex8 => Self::tensor(2, 3),
            Topology::Quad4 => Self::tensor(2, 2),
            Topology::Tet4 => {
                // Degree-2 rule: a = (5 + 3√5)/20, b = (5 − √5)/20, weights 1/24.
                let a = (5.0 + 3.0 * 5f64.sqrt()) / 20.0;
                let b = (5.0 - 5f64.sqrt()) / 20.0;
                let mut r = Self::empty();
                for p in [[b, b, b], [a, b, b], [b, a, b], [b, b, a]] {
                    r.push(p, 1.0 / 24.0);
                }
                r
            }
            Topology::Tri3 => Self::tri3_three_point(),
            Topology::Wedge6 => {
                let tri = Self::tri3_three_point();
                let (z, wz) = gauss_legendre(2);
                let mut r = Self::empty();
                for (k, zk) in z.iter().enumerate() {
                    for (p, w) in tri.points.iter().zip(&tri.weights) {
                        r.push([p[0], p[1], *zk], w * wz[k]);
                    }
                }
                r
            }
            Topology::Pyramid5 => Self::pyramid(2, 3),
            _ => return None,
        })
    }

    /// The centroid rule on the reference tetrahedron (degree 1).
    pub fn tet4_one_point() -> Self {
        QuadratureRule {
            points: vec![[0.25; 3]],
            weights: vec![1.0 / 6.0],
        }
    }

    /// The 3-point edge-midpoint-free rule (1/6, 1/6), (2/3, 1/6), (1/6, 2/3), degree 2.
    fn tri3_three_point() -> Self {
        let (a, b) = (1.0 / 6.0, 2.0 / 3.0);
        QuadratureRule {
            points: vec![[a, a, 0.0], [b, a, 0.0], [a, b, 0.0]],
            weights: vec![1.0 / 6.0; 3],
        }
    }

    /// Exact for polynomials of total degree ≤ `degree` on the reference cell.
    pub fn with_degree(topology: Topology, degree: usize) -> Option<Self> {
        let n = points_for(degree);
        Some(match topology {
            Topology::Hex8 => Self::tensor(n, 3),
            Topology::Quad4 => Self::tensor(n, 2),
            // Collapsing adds the Jacobian's powers of (1 − u) to the degree.
            Topology::Tri3 => Self::triangle(points_for(degree + 1)),
            Topology::Tet4 => Self::tetrahedron(points_for(degree + 2)),
            Topology::Wedge6 => {
                let tri = Self::triangle(points_for(degree + 1));
                let (z, wz) = gauss_legendre(n);
                let mut r = Self::empty();
                for (k, zk) in z.iter().enumerate() {
                    for (p, w) in tri.points.iter().zip(&tri.weights) {
                        r.push([p[0], p[1], *zk], w * wz[k]);
                    }
                }
                r
            }
            Topology::Pyramid5 => Self::pyramid(n, points_for(degree + 2)),
            _ => return None,
        })
    }

    /// A rule on a face's reference shape, exact to `degree`.
    pub fn face(face: FaceShape, degree: usize) -> Self {
        let n = points_for(degree);
        match face {
            FaceShape::Line2 => Self::tensor(n, 1),
            FaceShape::Quad4 => Self::tensor(n, 2),
            FaceShape::Tri3 => Self::triangle(points_for(degree + 1)),
        }
    }

    /// n^dim tensor Gauss rule on [−1,1]^dim.
    fn tensor(n: usize, dim: usize) -> Self {
        let (x, w) = gauss_legendre(n);
        let mut r = Self::empty();
        let nz = if dim == 3 { n } else { 1 };
        let ny = if dim >= 2 { n } else { 1 };
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..n {
                    let p = [
                        x[i],
                        if dim >= 2 { x[j] } else { 0.0 },
                        if dim == 3 { x[k] } else { 0.0 },
                    ];
                    let wt = w[i]
                        * if dim >= 2 { w[j] } else { 1.0 }
                        * if dim == 3 { w[k] } else { 1.0 };
                    r.push(p, wt);
                }
            }
        }
        r
    }

    /// Collapsed rule on the unit triangle: ξ = u, η = v(1 − u), dξdη = (1 − u) du dv.
    fn triangle(n: usize) -> Self {
        let (x, w) = gauss_legendre_01(n);
        let mut r = Self::empty();
        for i in 0..n {
            for j in 0..n {
                let u = x[i];
                r.push([u, x[j] * (1.0 - u), 0.0], w[i] * w[j] * (1.0 - u));
            }
        }
        r
    }

    /// Collapsed rule on the unit tetrahedron: ξ = u, η = v(1 − u), ζ = w(1 − u)(1 − v),
    /// Jacobian (1 − u)²(1 − v).
    fn tetrahedron(n: usize) -> Self {
        let (x, w) = gauss_legendre_01(n);
        let mut r = Self::empty();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let (u, v) = (x[i], x[j]);
                    r.push(
                        [u, v * (1.0 - u), x[k] * (1.0 - u) * (1.0 - v)],
                        w[i] * w[j] * w[k] * (1.0 - u).powi(2) * (1.0 - v),
                    );
                }
            }
        }
        r
    }

    /// Collapsed rule on the pyramid: ξ = a(1 − c), η = b(1 − c), ζ = c, Jacobian
    /// (1 − c)²; `n` Gauss points in a and b, `nc` in c.
    fn pyramid(n: usize, nc: usize) -> Self {
        let (x, w) = gauss_legendre(n);
        let (c, wc) = gauss_legendre_01(nc);
        let mut r = Self::empty();
        for k in 0..nc {
            let s = 1.0 - c[k];
            for j in 0..n {
                for i in 0..n {
                    r.push([x[i] * s, x[j] * s, c[k]], w[i] * w[j] * wc[k] * s * s);
                }
            }
        }
        r
    }
}

/// Exact integrals of monomials, for tests: ∫ ξ^a η^b ζ^c over a reference cell.
#[cfg(test)]
pub(crate) fn exact_monomial(topology: Topology, e: [u32; 3]) -> f64 {
    fn fact(n: u32) -> f64 {
        (1..=n).map(f64::from).product()
    }
    // ∫_{-1}^{1} x^k dx
    let line = |k: u32| {
        if k % 2 == 1 {
            0.0
        } else {
            2.0 / (k as f64 + 1.0)
        }
    };
    // Dirichlet integral over the unit simplex: a! b! c! / (a + b + c + d)!.
    let simplex = |d: u32| fact(e[0]) * fact(e[1]) * fact(e[2]) / fact(e[0] + e[1] + e[2] + d);
    match topology {
        Topology::Hex8 => line(e[0]) * line(e[1]) * line(e[2]),
        Topology::Quad4 => line(e[0]) * line(e[1]) * if e[2] == 0 { 1.0 } else { 0.0 },
        Topology::Tet4 => simplex(3),
        Topology::Tri3 => {
            if e[2] == 0 {
                simplex(2)
            } else {
                0.0
            }
        }
        Topology::Wedge6 => fact(e[0]) * fact(e[1]) / fact(e[0] + e[1] + 2) * line(e[2]),
        Topology::Pyramid5 => {
            // ∫₀¹ ζ^c (1−ζ)^{a+b+2} dζ · ∫ x^a ∫ y^b over [−1,1]² (after scaling by 1−ζ).
            let (a, b, c) = (e[0], e[1], e[2]);
            let beta = fact(c) * fact(a + b + 2) / fact(a + b + c + 3);
            line(a) * line(b) * beta
        }
        _ => unreachable!(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each rule integrates every monomial up to its degree to round-off (1e-13
    /// relative: sums of ≤ 100 terms of size ≤ 2).
    #[test]
    fn rules_integrate_monomials_to_their_degree() {
        let cases: Vec<(Topology, QuadratureRule, u32)> = vec![
            (
                Topology::Hex8,
                QuadratureRule::standard(Topology::Hex8).unwrap(),
                3,
            ),
            (
                Topology::Quad4,
                QuadratureRule::standard(Topology::Quad4).unwrap(),
                3,
            ),
            (
                Topology::Tet4,
                QuadratureRule::standard(Topology::Tet4).unwrap(),
                2,
            ),
            (Topology::Tet4, QuadratureRule::tet4_one_point(), 1),
            (
                Topology::Tri3,
                QuadratureRule::standard(Topology::Tri3).unwrap(),
                2,
            ),
            (
                Topology::Wedge6,
                QuadratureRule::standard(Topology::Wedge6).unwrap(),
                2,
            ),
            (
                Topology::Pyramid5,
                QuadratureRule::standard(Topology::Pyramid5).unwrap(),
                3,
            ),
        ];
        let mut all = cases;
        for t in [
            Topology::Hex8,
            Topology::Quad4,
            Topology::Tet4,
            Topology::Tri3,
            Topology::Wedge6,
            Topology::Pyramid5,
        ] {
            for d in [1, 4, 6] {
                all.push((t, QuadratureRule::with_degree(t, d as usize).unwrap(), d));
            }
        }
        for (t, rule, deg) in all {
            let three = t.parametric_dim() == 3;
            for a in 0..=deg {
                for b in 0..=deg - a {
                    for c in 0..=if three { deg - a - b } else { 0 } {
                        let q: f64 = rule
                            .points
                            .iter()
                            .zip(&rule.weights)
                            .map(|(p, w)| {
                                w * p[0].powi(a as i32) * p[1].powi(b as i32) * p[2].powi(c as i32)
                            })
                            .sum();
                        let exact = exact_monomial(t, [a, b, c]);
                        assert!(
                            (q - exact).abs() <= 1e-13 * exact.abs().max(1.0),
                            "{t:?} degree {deg}: ∫ξ^{a}η^{b}ζ^{c} = {q}, exact {exact}"
                        );
                    }
                }
            }
        }
    }

    /// The standard tet rule is *not* exact beyond its degree: a test that can fail.
    #[test]
    fn four_point_tet_rule_misses_degree_four() {
        let rule = QuadratureRule::standard(Topology::Tet4).unwrap();
        let q: f64 = rule
            .points
            .iter()
            .zip(&rule.weights)
            .map(|(p, w)| w * p[0].powi(4))
            .sum();
        assert!((q - exact_monomial(Topology::Tet4, [4, 0, 0])).abs() > 1e-6);
    }
}
