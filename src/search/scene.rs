//! The search of a whole contact definition: every interaction, and every periodic
//! image paired with its destination.
//!
//! Entry point: [`search_definition`]; [`search_periodicity`] searches one periodic
//! condition and keeps its map (for callers that move nodes and search again), and
//! [`periodic_map`], [`check_closure`] and [`landing`] are its parts, for periodic pairs
//! built in code (the embedding API). Periodic conditions (`Periodicity For S = …`) are
//! interactions between the image of `S` (side A) and a destination surface (side B):
//! `Align_Surface` names it; for the other transforms it is the face surface, other than
//! `S`, on which most of the image's points land. The inverse map is never asked of the
//! user: the destination's side of the pairing is found by the search itself.
//!
//! Checks on periodic maps, each an error with the surface and the numbers:
//! - the image must land on its destination: the worst distance from an image node to
//!   the destination is reported, and must be below 5 % of the destination's mean face
//!   size ([`LANDING_TOLERANCE`]);
//! - the map must be one-to-one on the surface's nodes ([`check_one_to_one`]): two nodes
//!   at least [`FOLD_SOURCE_FRACTION`] of a face apart must not land within
//!   [`FOLD_IMAGE_FRACTION`] of a face of each other — a map that collapses the surface
//!   onto a point or folds it onto itself would otherwise land "on" its destination
//!   and pass every other check (error E0326, before the search);
//! - an N-fold cylindrical rotation (`360/θ` an integer N) must close up: the map applied
//!   N times returns every node within 1e-12 × model size; an angle that does not divide
//!   360° is a warning.

use std::path::Path;
use std::time::Instant;

use serde::Serialize;

use super::pairing::{
    Integration, SearchError, SearchResult, SearchStats, Searcher, Sphere, SurfaceGeometry,
};
use crate::deck::spec::{ContactDefinition, PeriodicTransform, Periodicity};
use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::interaction::{Interaction, SearchSettings};
use crate::mesh::{Mesh, NodeId};
use crate::periodic::{
    LuaMap, MapError, MapSource, PeriodicMap, Rigid, Rotation, Translation, align_surface,
    closure_error, fold_count,
};
use crate::surface::{SurfaceKind, SurfaceSet};

/// One searched pair.
#[derive(Clone, Debug)]
pub struct Pairing {
    pub side_a: String,
    pub side_b: String,
    /// Index of side A's surface in the [`SurfaceSet`] (for a periodic pair: the source
    /// surface whose image is side A).
    pub side_a_surface: usize,
    pub side_b_surface: usize,
    /// True for a periodic image paired with its destination.
    pub periodic: bool,
    /// Side A's geometry as searched (for a periodic pair: the image).
    pub side_a_geometry: SurfaceGeometry,
    pub side_b_geometry: SurfaceGeometry,
    pub result: SearchResult,
    /// For periodic pairs: the largest distance from an image node to the destination.
    pub worst_image_distance: Option<f64>,
}

/// Wall-clock time of the two phases, seconds.
#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Timing {
    pub build_s: f64,
    pub search_s: f64,
}

#[derive(Debug, Default)]
pub struct SceneSearch {
    pub pairings: Vec<Pairing>,
    pub diagnostics: Diagnostics,
    pub timing: Timing,
}

/// Search every interaction and periodic pair of `def`.
#[allow(clippy::too_many_arguments)]
pub fn search_definition(
    mesh: &Mesh,
    def: &ContactDefinition,
    surfaces: &SurfaceSet,
    interactions: &[Interaction],
    deck_dir: &Path,
    sources: &SourceMap,
    integration: Integration,
) -> SceneSearch {
    let mut out = SceneSearch::default();
    let subdomain = subdomain(def);
    let t = Instant::now();
    let geometry = surface_geometries(mesh, surfaces, &mut out.diagnostics);
    out.timing.build_s += t.elapsed().as_secs_f64();

    for i in interactions {
        let (Some(a), Some(b)) = (&geometry[i.side_a], &geometry[i.side_b]) else {
            continue;
        };
        if b.faces.is_empty() {
            continue;
        }
        let t = Instant::now();
        let searcher = Searcher::new(b, &i.settings);
        out.timing.build_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut result = searcher.search(a, b, &i.settings, integration, subdomain);
        result.treat_overclosure(i.overclosure);
        out.timing.search_s += t.elapsed().as_secs_f64();
        out.pairings.push(Pairing {
            side_a: i.side_a_name.clone(),
            side_b: i.side_b_name.clone(),
            side_a_surface: i.side_a,
            side_b_surface: i.side_b,
            periodic: false,
            side_a_geometry: a.clone(),
            side_b_geometry: b.clone(),
            result,
            worst_image_distance: None,
        });
    }

    for p in &def.periodicity {
        if let Some(found) = search_periodicity(
            mesh,
            def,
            p,
            surfaces,
            &geometry,
            deck_dir,
            sources,
            integration,
            &mut out,
        ) {
            out.pairings.push(found.pairing);
        }
    }
    out
}

/// The geometry of every surface of the set on the mesh's coordinates; `None` (and an
/// E0312 error) for a surface that cannot be searched.
pub fn surface_geometries(
    mesh: &Mesh,
    surfaces: &SurfaceSet,
    diagnostics: &mut Diagnostics,
) -> Vec<Option<SurfaceGeometry>> {
    let mut geometry = Vec::with_capacity(surfaces.surfaces.len());
    for s in &surfaces.surfaces {
        match SurfaceGeometry::from_surface(mesh, s, &mesh.coords) {
            Ok(g) => geometry.push(Some(g)),
            Err(e) => {
                diagnostics.push(
                    Diagnostic::error("E0312", e.to_string())
                        .help("2-D meshes give surfaces of edges; search them in a later version"),
                );
                geometry.push(None);
            }
        }
    }
    geometry
}

/// `Restrict Contact To Subdomain` of a definition: the sphere outside which nothing is
/// searched.
pub fn subdomain(def: &ContactDefinition) -> Option<Sphere> {
    def.restrict_contact_to_subdomain.as_ref().map(|s| Sphere {
        center: s.point,
        radius: s.radius,
    })
}

/// Search settings of periodic pairs: the definition's search options.
pub fn base_settings(def: &ContactDefinition, dim: usize) -> SearchSettings {
    let mut s = SearchSettings::defaults(dim);
    if let Some(o) = &def.search_options {
        s.normal_tolerance = o.normal_tolerance.or(s.normal_tolerance);
        s.tangential_tolerance = o.tangential_tolerance.unwrap_or(s.tangential_tolerance);
        s.buffer_factor = o.buffer_factor.unwrap_or(s.buffer_factor);
        s.field_factor = o.field_factor.unwrap_or(s.field_factor);
        s.normal_check_angle = o.normal_check_angle.unwrap_or(s.normal_check_angle);
    }
    s
}

fn face_surface(surfaces: &SurfaceSet, name: &str) -> Option<usize> {
    let name = name.to_ascii_lowercase();
    surfaces
        .surfaces
        .iter()
        .position(|s| s.name == name && s.kind == SurfaceKind::Faces)
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
    /// Their user-visible numbers (as [`Mesh::node_number`]); the dense ids plus one when
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

/// Search one `Periodicity For S = …` of `def`: the image of `S` paired with its
/// destination (given by `Align_Surface`, else the face surface other than `S` on which
/// most image points land), and the map. `geometry` is [`surface_geometries`] of
/// `surfaces`. Diagnostics (E0320–E0326, W0320) and timing go to `out`; `None` when the
/// condition cannot be searched.
#[allow(clippy::too_many_arguments)]
pub fn search_periodicity(
    mesh: &Mesh,
    def: &ContactDefinition,
    p: &Periodicity,
    surfaces: &SurfaceSet,
    geometry: &[Option<SurfaceGeometry>],
    deck_dir: &Path,
    sources: &SourceMap,
    integration: Integration,
    out: &mut SceneSearch,
) -> Option<PeriodicPairing> {
    let settings = base_settings(def, mesh.dim);
    let subdomain = subdomain(def);
    let at = sources.narrow(&p.at, &p.surface);
    let Some(s) = face_surface(surfaces, &p.surface) else {
        out.diagnostics.push(
            Diagnostic::error(
                "E0320",
                format!("periodicity for `{}`: no contact surface of faces has that name", p.surface),
            )
            .at(Some(at))
            .help("define the surface with `Contact Surface` (or a side set) before using it in a periodicity"),
        );
        return None;
    };
    let source = geometry[s].as_ref()?;
    let model_size = mesh.model_size();
    let mut destination = None;
    if let PeriodicTransform::AlignSurface {
        destination: dest, ..
    } = &p.transform
    {
        let Some(d) = face_surface(surfaces, dest) else {
            out.diagnostics.push(
                Diagnostic::error(
                    "E0320",
                    format!(
                        "periodicity for `{}`: unknown destination surface `{dest}`",
                        p.surface
                    ),
                )
                .at(Some(sources.narrow(&p.at, dest)))
                .help("`Destination =` names a contact surface of faces"),
            );
            return None;
        };
        geometry[d].as_ref()?;
        destination = Some(d);
    }
    match check_closure(&p.transform, source, model_size) {
        Ok(Closure::AngleDoesNotDivide) => {
            if let PeriodicTransform::Cylindrical { angle, .. } = &p.transform {
                out.diagnostics.push(
                    Diagnostic::warning(
                        "W0320",
                        format!(
                            "periodicity for `{}`: the angle {angle}° does not divide 360°",
                            p.surface
                        ),
                    )
                    .at(Some(p.at.clone()))
                    .help("a sector of a full ring has an angle of 360/N degrees"),
                );
            }
        }
        Ok(_) => {}
        Err(e) => out.diagnostics.push(
            Diagnostic::error("E0325", format!("periodicity for `{}`: {e}", p.surface))
                .at(Some(p.at.clone()))
                .help("give the angle to full precision (e.g. 360/7 as 51.428571428571431)"),
        ),
    }
    let chunk = if p.at.is_unknown() {
        format!("periodicity for {}", p.surface)
    } else {
        format!("{}:{}", p.at.file, p.at.line)
    };
    let destination_geometry = destination.and_then(|d| geometry[d].as_ref());
    let mut map = match periodic_map(
        &p.transform,
        source,
        destination_geometry,
        deck_dir,
        &chunk,
        model_size,
    ) {
        Ok(m) => m,
        // A zero axis is rejected by the deck checks.
        Err(PeriodicError::ZeroAxis) => return None,
        Err(e @ PeriodicError::NoMeanNormal) => {
            out.diagnostics.push(
                Diagnostic::error("E0322", format!("periodicity for `{}`: {e}", p.surface))
                    .at(Some(at))
                    .help("`Align_Surface` needs two roughly planar surfaces"),
            );
            return None;
        }
        Err(e) => {
            let help = match &e {
                PeriodicError::Map(MapError::OutsideDeck(_)) => {
                    "put the Lua file in the deck's directory or below it"
                }
                _ => "fix the Lua map; each map is an expression in x, y, z or `file.lua:function`",
            };
            out.diagnostics.push(
                Diagnostic::error("E0321", format!("periodicity for `{}`: {e}", p.surface))
                    .at(Some(at))
                    .help(help),
            );
            return None;
        }
    };
    let image_name = format!("{}_image", p.surface);
    let t = Instant::now();
    let image = match source.mapped(map.as_mut(), &image_name) {
        Ok(g) => g,
        Err(SearchError::Map { source: e, .. }) => {
            out.diagnostics.push(
                Diagnostic::error("E0321", format!("periodicity for `{}`: {e}", p.surface))
                    .at(Some(at))
                    .help("the map failed while mapping the surface's nodes"),
            );
            return None;
        }
        Err(e) => {
            out.diagnostics
                .push(Diagnostic::error("E0312", e.to_string()).at(Some(at)));
            return None;
        }
    };
    out.timing.build_s += t.elapsed().as_secs_f64();
    if let Some(fold) = check_one_to_one(source, &image, |n| mesh.node_number(n)) {
        let e = PeriodicError::Folds(Box::new(fold));
        out.diagnostics.push(
            Diagnostic::error("E0326", format!("periodicity for `{}`: {e}", p.surface))
                .at(Some(at))
                .help("a periodic map carries each node to its own place on the partner surface (a rigid motion or close to one); check the map: a constant (`x_map = 0`) or a folding formula (`x_map = math.abs(x)`) sends several nodes to one point"),
        );
        return None;
    }

    // The destination: given, or the face surface that takes most image points.
    let candidates: Vec<usize> = match destination {
        Some(d) => vec![d],
        None => (0..surfaces.surfaces.len())
            .filter(|&d| d != s && geometry[d].as_ref().is_some_and(|g| !g.faces.is_empty()))
            .collect(),
    };
    let mut best: Option<(usize, SearchResult)> = None;
    for d in candidates {
        let Some(dg) = &geometry[d] else { continue };
        let t = Instant::now();
        let searcher = Searcher::new(dg, &settings);
        out.timing.build_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let r = searcher.search(&image, dg, &settings, integration, subdomain);
        out.timing.search_s += t.elapsed().as_secs_f64();
        if best
            .as_ref()
            .is_none_or(|(_, b)| r.stats.matched > b.stats.matched)
        {
            best = Some((d, r));
        }
    }
    let Some((d, result)) = best.filter(|(_, r)| r.stats.matched > 0) else {
        out.diagnostics.push(
            Diagnostic::error(
                "E0323",
                format!("periodicity for `{}`: its image lands on no contact surface", p.surface),
            )
            .at(Some(at))
            .help("check the transform (offset, axis, centre, angle or map): the image of the surface must lie on another contact surface"),
        );
        return None;
    };
    let dg = geometry[d].as_ref().expect("destination geometry exists");
    let landed = landing(&image, dg);
    if let Err(e) = landed.check(&surfaces.surfaces[d].name) {
        out.diagnostics.push(
            Diagnostic::error("E0324", format!("periodicity for `{}`: {e}", p.surface))
                .at(Some(at))
                .help("the transform must carry the surface exactly onto its partner; check the offset, angle or map"),
        );
    }
    Some(PeriodicPairing {
        pairing: Pairing {
            side_a: p.surface.to_ascii_lowercase(),
            side_b: surfaces.surfaces[d].name.clone(),
            side_a_surface: s,
            side_b_surface: d,
            periodic: true,
            side_a_geometry: image,
            side_b_geometry: dg.clone(),
            result,
            worst_image_distance: Some(landed.worst),
        },
        map,
    })
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
    use super::project::{project_point_quad4, project_point_tri3};
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
                let g = &dest.faces[j];
                let pr = match g.len {
                    3 => project_point_tri3(x, &[g.x[0], g.x[1], g.x[2]]),
                    _ => project_point_quad4(x, &[g.x[0], g.x[1], g.x[2], g.x[3]]),
                };
                nearest = nearest.min(pr.distance);
            });
            worst = worst.max(nearest);
        }
    }
    worst
}

/// The JSON-facing summary of one pairing.
#[derive(Clone, Debug, Serialize)]
pub struct PairingSummary {
    pub side_a: String,
    pub side_b: String,
    pub periodic: bool,
    #[serde(flatten)]
    pub stats: SearchStats,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_image_distance: Option<f64>,
    /// Per side-A face, the matched fraction (with `Visualize Contact`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_fraction: Option<Vec<f64>>,
}

impl Pairing {
    /// The summary; `visualize` adds the per-face contact fraction.
    pub fn summary(&self, visualize: bool) -> PairingSummary {
        PairingSummary {
            side_a: self.side_a.clone(),
            side_b: self.side_b.clone(),
            periodic: self.periodic,
            stats: self.result.stats.clone(),
            worst_image_distance: self.worst_image_distance,
            contact_fraction: visualize.then(|| self.result.contact_fraction.clone()),
        }
    }
}
