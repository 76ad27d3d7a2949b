//! Small fixed-size vector helpers (3-vectors as `[f64; 3]`), shared by the geometric
//! code of every module (crate-private).

pub(crate) type V3 = [f64; 3];

#[inline]
pub(crate) fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

#[inline]
pub(crate) fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}

/// `a + s b`.
#[inline]
pub(crate) fn axpy(a: V3, s: f64, b: V3) -> V3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}

#[inline]
pub(crate) fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn cross(a: V3, b: V3) -> V3 {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

#[inline]
pub(crate) fn norm2(a: V3) -> f64 {
    dot(a, a)
}

#[inline]
pub(crate) fn norm(a: V3) -> f64 {
    dot(a, a).sqrt()
}

/// `a / |a|`, or `None` when `|a|` is zero or not finite.
#[inline]
pub(crate) fn normalize(a: V3) -> Option<V3> {
    let n = norm(a);
    (n > 0.0 && n.is_finite()).then(|| scale(a, 1.0 / n))
}

/// Closest point to `p` on the segment `a`–`b`: returns the segment parameter `t ∈ [0, 1]`
/// (`a + t (b − a)`) and the squared distance. A zero-length segment gives `t = 0`.
#[inline]
pub(crate) fn closest_on_segment(p: V3, a: V3, b: V3) -> (f64, f64) {
    let e = sub(b, a);
    let ee = dot(e, e);
    let t = if ee > 0.0 {
        (dot(sub(p, a), e) / ee).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = axpy(a, t, e);
    (t, norm2(sub(p, q)))
}
