//! Periodic maps between contact surfaces, and the checks that a map carries its surface
//! onto its partner.
//!
//! Entry points: [`periodic_map`] (the map of a [`PeriodicTransform`]), [`check_closure`],
//! [`check_one_to_one`] and [`landing`]. A periodic condition is an interaction between
//! the image of a surface `S` under the map (side A) and a destination surface (side B);
//! the scene finds the destination and searches the pair for a deck, a host pairs it in
//! code.
//!
//! Checks on periodic maps, each an error with the surface and the numbers:
//! - the image must land on its destination: the worst distance from an image node to
//!   the destination is reported, and must be below 5 % of the destination's mean face
//!   size ([`LANDING_TOLERANCE`]);
//! - the map must be one-to-one on the surface's nodes ([`check_one_to_one`]): two nodes
//!   at least [`FOLD_SOURCE_FRACTION`] of a face apart must not land within
//!   [`FOLD_IMAGE_FRACTION`] of a face of each other — a map that collapses the surface
//!   onto a point or folds it onto itself would otherwise land "on" its destination
//!   and pass every other check;
//! - an N-fold cylindrical rotation (`360/θ` an integer N) must close up: the map applied
//!   N times returns every node within 1e-12 × model size; an angle that does not divide
//!   360° is reported as such ([`Closure::AngleDoesNotDivide`]);
//! - in an axisymmetric model ([`check_axisymmetric`]) a cylindrical transform is
//!   refused (the model is already the full revolution about its axis), and any other
//!   map must keep every node's radius: a node stands for a ring of circumference 2πr,
//!   so a map that changes r would pair rings of different size and heat would not
//!   balance across the pair.

use std::path::Path;

use super::pairing::SurfaceGeometry;
use super::scene::Pairing;
use crate::mesh::NodeId;
use crate::periodic::{
    LuaMap, MapError, MapSource, PeriodicMap, Rigid, Rotation, Translation, align_surface,
    closure_error, fold_count,
};

/// A periodic transform: how the image of a surface is made.
#[derive(Clone, Debug, PartialEq)]
pub enum PeriodicTransform {
    /// `x ↦ x + offset` (missing components 0).
    Rectangular { offset: Vec<f64> },
    /// A turn by `angle` degrees (right-hand rule) about the line through `center` along
    /// `axis` (z when fewer than 3 components are given; missing centre components 0).
    Cylindrical {
        axis: Vec<f64>,
        center: Vec<f64>,
        angle: f64,
    },
    /// The rigid map taking the surface's centroid and mean normal onto those of
    /// `destination`, normals opposed when `invert_normals`.
    AlignSurface {
        destination: String,
        invert_normals: bool,
    },
    /// Each component a Lua expression in x, y, z or `file.lua:function`; no `z_map`:
    /// z kept.
    Mapped {
        x_map: String,
        y_map: String,
        z_map: Option<String>,
    },
}

/// One periodic condition as searched, with the map that made its image.
pub struct PeriodicPairing {
    pub pairing: Pairing,
    /// The map from the source surface to its image (side A of the pairing): callers
    /// that move nodes map the moved source again.
    pub map: Box<dyn PeriodicMap>,
}

/// Why a periodic map cannot be made, or does not carry its surface onto its partner.
/// Each message reads after "periodicity for `S`: ".
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PeriodicError {
    #[error("the cylindrical axis is the zero vector")]
    ZeroAxis,
    #[error("`Align_Surface` has no destination surface")]
    NoDestination,
    #[error("a surface has no mean normal (its faces cancel out)")]
    NoMeanNormal,
    #[error(transparent)]
    Map(#[from] MapError),
    #[error("{n} rotations by {angle}° miss the start by {miss:.3e}")]
    NotClosed { n: usize, angle: f64, miss: f64 },
    #[error(
        "the map is not one-to-one: nodes {} at {} and {} at {} land at {} and {}, {:.3e} apart (the surface's faces are {:.3e} across)",
        .0.numbers[0], point(.0.source[0]), .0.numbers[1], point(.0.source[1]),
        point(.0.image[0]), point(.0.image[1]), .0.image_distance(), .0.face_size
    )]
    Folds(Box<Fold>),
    #[error(
        "a cylindrical transform in an axisymmetric model: the model is already the full revolution about its axis (y), so there is no sector to repeat"
    )]
    CylindricalInAxisymmetric,
    #[error(
        "in an axisymmetric model the map must keep each node's radius (x): node {number} at r = {from} lands at r = {to}"
    )]
    ChangesRadius { number: i64, from: f64, to: f64 },
    #[error(
        "its image does not land on `{destination}`: the worst image node is {worst:.3e} away (accepted: {limit:.3e})"
    )]
    Landing {
        destination: String,
        worst: f64,
        limit: f64,
    },
}

/// Two distinct nodes of a surface that a periodic map sends (nearly) onto one point.
#[derive(Clone, Debug, PartialEq)]
pub struct Fold {
    pub nodes: [NodeId; 2],
    /// Their user-visible numbers (as [`Mesh::node_number`](crate::mesh::Mesh::node_number)); the dense ids plus one when
    /// the caller has no mesh.
    pub numbers: [i64; 2],
    pub source: [[f64; 3]; 2],
    pub image: [[f64; 3]; 2],
    /// The source's mean face size, the scale of the test.
    pub face_size: f64,
}

impl Fold {
    pub fn image_distance(&self) -> f64 {
        crate::vec3::norm(crate::vec3::sub(self.image[0], self.image[1]))
    }
}

fn point(p: [f64; 3]) -> String {
    format!("({}, {}, {})", short(p[0]), short(p[1]), short(p[2]))
}

/// A coordinate in a message: 6 significant digits, no trailing zeros.
fn short(x: f64) -> String {
    let t = format!("{x:.6}");
    let t = t.trim_end_matches('0').trim_end_matches('.');
    if t == "-0" { "0".into() } else { t.into() }
}

/// Two images closer than this fraction of the source's mean face size count as one
/// point. A periodic map is a rigid motion or close to one, so images of distinct nodes
/// stay about as far apart as the nodes; 1 % of a face is far below any node spacing of
/// a usable mesh and far above round-off.
pub const FOLD_IMAGE_FRACTION: f64 = 0.01;

/// Nodes closer than this fraction of the mean face size are taken as one place (a
/// duplicated node), whose images may coincide: only nodes at least this far apart
/// whose images coincide are a fold.
pub const FOLD_SOURCE_FRACTION: f64 = 0.1;

/// Check that `map` (which made `image` from `source`, face by face) keeps distinct nodes
/// distinct: the first two nodes at least [`FOLD_SOURCE_FRACTION`] of a face apart whose
/// images lie within [`FOLD_IMAGE_FRACTION`] of a face, or `None`. Images are hashed
/// into cells of that size and each is compared with the few kept in the 27 cells
/// around it; a kept image has no other within the distance, so a cell keeps at most
/// eight and the check is linear in the number of nodes. `numbers` gives the nodes'
/// user-visible numbers.
pub fn check_one_to_one(
    source: &SurfaceGeometry,
    image: &SurfaceGeometry,
    numbers: impl Fn(NodeId) -> i64,
) -> Option<Fold> {
    use std::collections::{HashMap, HashSet};
    let h = source.mean_face_size();
    if !(h > 0.0 && h.is_finite()) {
        return None;
    }
    let (near, far) = (FOLD_IMAGE_FRACTION * h, FOLD_SOURCE_FRACTION * h);
    let dist = |a: [f64; 3], b: [f64; 3]| crate::vec3::norm(crate::vec3::sub(a, b));
    let cell = |p: [f64; 3]| p.map(|x| (x / near).floor() as i64);
    let mut seen: HashSet<NodeId> = HashSet::new();
    let mut kept: Vec<(NodeId, [f64; 3], [f64; 3])> = Vec::new();
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (f, g) in source.faces.iter().zip(&image.faces) {
        for k in 0..f.len as usize {
            let (node, x, y) = (f.nodes[k], f.x[k], g.x[k]);
            if !seen.insert(node) || !y.iter().all(|c| c.is_finite()) {
                continue;
            }
            let c = cell(y);
            let mut duplicate = false;
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        let key = [c[0] + dx, c[1] + dy, c[2] + dz];
                        for &j in grid.get(&key).map_or(&[][..], Vec::as_slice) {
                            let (other, ox, oy) = kept[j];
                            if dist(y, oy) >= near {
                                continue;
                            }
                            if dist(x, ox) >= far {
                                return Some(Fold {
                                    nodes: [other, node],
                                    numbers: [numbers(other), numbers(node)],
                                    source: [ox, x],
                                    image: [oy, y],
                                    face_size: h,
                                });
                            }
                            duplicate = true;
                        }
                    }
                }
            }
            if !duplicate {
                grid.entry(c).or_default().push(kept.len());
                kept.push((node, x, y));
            }
        }
    }
    None
}

/// The map of a periodic transform from `source` (and, for `Align_Surface`, onto
/// `destination`). Lua files are read relative to `deck_dir` and must stay inside it;
/// `chunk` names the deck location in Lua messages; `model_size` scales the
/// finite-difference step of a Lua map's Jacobian.
pub fn periodic_map(
    transform: &PeriodicTransform,
    source: &SurfaceGeometry,
    destination: Option<&SurfaceGeometry>,
    deck_dir: &Path,
    chunk: &str,
    model_size: f64,
) -> Result<Box<dyn PeriodicMap>, PeriodicError> {
    Ok(match transform {
        PeriodicTransform::Rectangular { offset } => Box::new(Translation(padded(offset))),
        PeriodicTransform::Cylindrical { .. } => {
            Box::new(rotation(transform).ok_or(PeriodicError::ZeroAxis)?)
        }
        PeriodicTransform::AlignSurface { invert_normals, .. } => {
            let dg = destination.ok_or(PeriodicError::NoDestination)?;
            let (cs, ns) = centroid_and_normal(source);
            let (cd, nd) = centroid_and_normal(dg);
            let rigid = align_surface(cs, ns, cd, nd, *invert_normals)
                .ok_or(PeriodicError::NoMeanNormal)?;
            Box::new(rigid)
        }
        PeriodicTransform::Mapped {
            x_map,
            y_map,
            z_map,
        } => {
            let (x, y) = (MapSource::parse(x_map), MapSource::parse(y_map));
            let z = z_map.as_deref().map(MapSource::parse);
            Box::new(LuaMap::new(
                [Some(&x), Some(&y), z.as_ref()],
                deck_dir,
                chunk,
                model_size,
            )?)
        }
    })
}

/// The first three of a deck's numbers (missing ones 0).
fn padded(v: &[f64]) -> [f64; 3] {
    let mut o = [0.0; 3];
    for (slot, x) in o.iter_mut().zip(v) {
        *slot = *x;
    }
    o
}

/// The rigid map of a cylindrical transform (axis z when the deck gives fewer than 3
/// components); `None` for other transforms and a zero axis.
fn rotation(transform: &PeriodicTransform) -> Option<Rigid> {
    let PeriodicTransform::Cylindrical {
        axis,
        center,
        angle,
    } = transform
    else {
        return None;
    };
    let axis = if axis.len() >= 3 {
        [axis[0], axis[1], axis[2]]
    } else {
        [0.0, 0.0, 1.0]
    };
    Rotation::about(axis, padded(center), *angle)
}

/// What the closure check of a transform found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Closure {
    /// Not a cylindrical rotation (or no axis): nothing to check.
    NotARotation,
    /// An N-fold rotation that comes back to the start after N turns.
    Closes { n: usize },
    /// The angle does not divide 360°: a sector of no full ring (a warning).
    AngleDoesNotDivide,
}

/// An N-fold cylindrical rotation (`360/θ` an integer N) must close up: the map applied
/// N times returns every node of `source` (its first 64 faces) within 1e-12 × model size.
pub fn check_closure(
    transform: &PeriodicTransform,
    source: &SurfaceGeometry,
    model_size: f64,
) -> Result<Closure, PeriodicError> {
    let (Some(mut rot), PeriodicTransform::Cylindrical { angle, .. }) =
        (rotation(transform), transform)
    else {
        return Ok(Closure::NotARotation);
    };
    let Some(n) = fold_count(*angle) else {
        return Ok(Closure::AngleDoesNotDivide);
    };
    let mut worst: f64 = 0.0;
    for f in source.faces.iter().take(64) {
        for &x in f.coords() {
            if let Ok(e) = closure_error(&mut rot, x, n) {
                worst = worst.max(e);
            }
        }
    }
    if worst > 1e-12 * model_size {
        return Err(PeriodicError::NotClosed {
            n,
            angle: *angle,
            miss: worst,
        });
    }
    Ok(Closure::Closes { n })
}

/// The checks of a periodic map in an axisymmetric model (module docs): no cylindrical
/// transform, and every node of `source` keeps its radius in `image` (to 1e-12 ×
/// `model_size`, the round-off of a translation along y). Nothing to check when
/// `source` is not axisymmetric. `numbers` gives the nodes' user-visible numbers.
pub fn check_axisymmetric(
    transform: &PeriodicTransform,
    source: &SurfaceGeometry,
    image: &SurfaceGeometry,
    model_size: f64,
    numbers: impl Fn(NodeId) -> i64,
) -> Result<(), PeriodicError> {
    if !source.axisymmetric {
        return Ok(());
    }
    if matches!(transform, PeriodicTransform::Cylindrical { .. }) {
        return Err(PeriodicError::CylindricalInAxisymmetric);
    }
    for (f, g) in source.faces.iter().zip(&image.faces) {
        for k in 0..f.len as usize {
            let (from, to) = (f.x[k][0], g.x[k][0]);
            let kept = (from - to).abs() <= 1e-12 * model_size;
            if !kept {
                return Err(PeriodicError::ChangesRadius {
                    number: numbers(f.nodes[k]),
                    from,
                    to,
                });
            }
        }
    }
    Ok(())
}

/// How far an image lies from its destination: the worst distance from an image node to
/// the destination's faces, and the distance accepted.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Landing {
    pub worst: f64,
    pub limit: f64,
}

impl Landing {
    /// An error unless every image node is within the limit (NaN never is).
    pub fn check(&self, destination: &str) -> Result<(), PeriodicError> {
        if self.worst.is_nan() || self.worst > self.limit {
            return Err(PeriodicError::Landing {
                destination: destination.to_string(),
                worst: self.worst,
                limit: self.limit,
            });
        }
        Ok(())
    }
}

/// Measure where `image` lands on `destination` (limit: [`LANDING_TOLERANCE`] of the
/// destination's mean face size).
pub fn landing(image: &SurfaceGeometry, destination: &SurfaceGeometry) -> Landing {
    Landing {
        worst: worst_distance(image, destination),
        limit: LANDING_TOLERANCE * destination.mean_face_size(),
    }
}

/// How far an image node may be from its destination, relative to the destination's
/// mean face size: room for the faceting of a curved surface meshed differently on the
/// two sides (the sagitta h²/8R stays below 5 % of h while h < 0.4 R), none for a wrong
/// offset, angle or map.
pub const LANDING_TOLERANCE: f64 = 0.05;

fn centroid_and_normal(g: &SurfaceGeometry) -> ([f64; 3], [f64; 3]) {
    let mut c = [0.0; 3];
    let mut n = [0.0; 3];
    let mut area = 0.0;
    for f in &g.faces {
        let a = f.area();
        let fc = f.centroid();
        let v = f.vector_area();
        for d in 0..3 {
            c[d] += a * fc[d];
            n[d] += v[d];
        }
        area += a;
    }
    if area > 0.0 {
        c = c.map(|x| x / area);
    }
    (c, n)
}

/// Largest distance from a node of `image` to the nearest face of `dest`.
fn worst_distance(image: &SurfaceGeometry, dest: &SurfaceGeometry) -> f64 {
    use super::bvh::{Aabb, Bvh};
    let size = dest.mean_face_size();
    let boxes: Vec<Aabb> = dest
        .faces
        .iter()
        .map(|f| Aabb::from_points(f.coords()).inflate(size))
        .collect();
    let bvh = Bvh::build(&boxes);
    let mut worst: f64 = 0.0;
    for f in &image.faces {
        for &x in f.coords() {
            let mut nearest = f64::INFINITY;
            bvh.query(&Aabb::from_point(x), |j| {
                nearest = nearest.min(dest.faces[j].project(x).distance);
            });
            worst = worst.max(nearest);
        }
    }
    worst
}
