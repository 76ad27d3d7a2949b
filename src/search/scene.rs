//! The search of a whole contact definition: every interaction, and every periodic
//! image paired with its destination.
//!
//! Entry point: [`search_definition`]. Periodic conditions (`Periodicity For S = …`) are
//! interactions between the image of `S` (side A) and a destination surface (side B):
//! `Align_Surface` names it; for the other transforms it is the face surface, other than
//! `S`, on which most of the image's points land. The inverse map is never asked of the
//! user: the destination's side of the pairing is found by the search itself.
//!
//! Checks on periodic maps, each an error with the surface and the numbers:
//! - the image must land on its destination: the worst distance from an image node to
//!   the destination is reported, and must be below 5 % of the destination's mean face
//!   size ([`LANDING_TOLERANCE`]);
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
use crate::diag::{Diagnostic, Diagnostics, Loc, SourceMap};
use crate::interaction::{Interaction, SearchSettings};
use crate::mesh::Mesh;
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
    let subdomain = def.restrict_contact_to_subdomain.as_ref().map(|s| Sphere {
        center: s.point,
        radius: s.radius,
    });
    let t = Instant::now();
    let mut geometry: Vec<Option<SurfaceGeometry>> = Vec::with_capacity(surfaces.surfaces.len());
    for s in &surfaces.surfaces {
        match SurfaceGeometry::from_surface(mesh, s, &mesh.coords) {
            Ok(g) => geometry.push(Some(g)),
            Err(e) => {
                out.diagnostics.push(
                    Diagnostic::error("E0312", e.to_string())
                        .help("2-D meshes give surfaces of edges; search them in a later version"),
                );
                geometry.push(None);
            }
        }
    }
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

    let base = base_settings(def, mesh.dim);
    for p in &def.periodicity {
        periodic_pair(
            mesh,
            p,
            surfaces,
            &geometry,
            &base,
            deck_dir,
            sources,
            integration,
            subdomain,
            &mut out,
        );
    }
    out
}

/// Search settings of periodic pairs: the definition's search options.
fn base_settings(def: &ContactDefinition, dim: usize) -> SearchSettings {
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

#[allow(clippy::too_many_arguments)]
fn periodic_pair(
    mesh: &Mesh,
    p: &Periodicity,
    surfaces: &SurfaceSet,
    geometry: &[Option<SurfaceGeometry>],
    settings: &SearchSettings,
    deck_dir: &Path,
    sources: &SourceMap,
    integration: Integration,
    subdomain: Option<Sphere>,
    out: &mut SceneSearch,
) {
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
        return;
    };
    let Some(source) = &geometry[s] else { return };
    let model_size = mesh.model_size();
    let mut destination = None;
    let map: Box<dyn PeriodicMap> = match &p.transform {
        PeriodicTransform::Rectangular { offset } => {
            let mut o = [0.0; 3];
            for (slot, v) in o.iter_mut().zip(offset) {
                *slot = *v;
            }
            Box::new(Translation(o))
        }
        PeriodicTransform::Cylindrical {
            axis,
            center,
            angle,
        } => {
            let axis = if axis.len() >= 3 {
                [axis[0], axis[1], axis[2]]
            } else {
                [0.0, 0.0, 1.0]
            };
            let mut c = [0.0; 3];
            for (slot, v) in c.iter_mut().zip(center) {
                *slot = *v;
            }
            let Some(rot) = Rotation::about(axis, c, *angle) else {
                return; // a zero axis is rejected by the deck checks
            };
            check_closure(rot, *angle, source, model_size, &p.surface, &p.at, out);
            Box::new(rot)
        }
        PeriodicTransform::AlignSurface {
            destination: dest,
            invert_normals,
        } => {
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
                return;
            };
            let Some(dg) = &geometry[d] else { return };
            let (cs, ns) = centroid_and_normal(source);
            let (cd, nd) = centroid_and_normal(dg);
            let Some(rigid) = align_surface(cs, ns, cd, nd, *invert_normals) else {
                out.diagnostics.push(
                    Diagnostic::error("E0322", format!("periodicity for `{}`: a surface has no mean normal (its faces cancel out)", p.surface))
                        .at(Some(at))
                        .help("`Align_Surface` needs two roughly planar surfaces"),
                );
                return;
            };
            destination = Some(d);
            Box::new(rigid) as Box<dyn PeriodicMap>
        }
        PeriodicTransform::Mapped {
            x_map,
            y_map,
            z_map,
        } => {
            let (x, y) = (MapSource::parse(x_map), MapSource::parse(y_map));
            let z = z_map.as_deref().map(MapSource::parse);
            let chunk = if p.at.is_unknown() {
                format!("periodicity for {}", p.surface)
            } else {
                format!("{}:{}", p.at.file, p.at.line)
            };
            match LuaMap::new(
                [Some(&x), Some(&y), z.as_ref()],
                deck_dir,
                &chunk,
                model_size,
            ) {
                Ok(m) => Box::new(m),
                Err(e) => {
                    let help = match &e {
                        MapError::OutsideDeck(_) => {
                            "put the Lua file in the deck's directory or below it"
                        }
                        _ => {
                            "fix the Lua map; each map is an expression in x, y, z or `file.lua:function`"
                        }
                    };
                    out.diagnostics.push(
                        Diagnostic::error("E0321", format!("periodicity for `{}`: {e}", p.surface))
                            .at(Some(at))
                            .help(help),
                    );
                    return;
                }
            }
        }
    };
    let mut map = map;
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
            return;
        }
        Err(e) => {
            out.diagnostics
                .push(Diagnostic::error("E0312", e.to_string()).at(Some(at)));
            return;
        }
    };
    out.timing.build_s += t.elapsed().as_secs_f64();

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
        let searcher = Searcher::new(dg, settings);
        out.timing.build_s += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let r = searcher.search(&image, dg, settings, integration, subdomain);
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
        return;
    };
    let dg = geometry[d].as_ref().expect("destination geometry exists");
    let worst = worst_distance(&image, dg);
    let limit = LANDING_TOLERANCE * dg.mean_face_size();
    if worst.is_nan() || worst > limit {
        out.diagnostics.push(
            Diagnostic::error(
                "E0324",
                format!(
                    "periodicity for `{}`: its image does not land on `{}`: the worst image node is {worst:.3e} away (accepted: {limit:.3e})",
                    p.surface, surfaces.surfaces[d].name
                ),
            )
            .at(Some(at))
            .help("the transform must carry the surface exactly onto its partner; check the offset, angle or map"),
        );
    }
    out.pairings.push(Pairing {
        side_a: p.surface.to_ascii_lowercase(),
        side_b: surfaces.surfaces[d].name.clone(),
        side_a_surface: s,
        side_b_surface: d,
        periodic: true,
        side_a_geometry: image,
        side_b_geometry: dg.clone(),
        result,
        worst_image_distance: Some(worst),
    });
}

/// How far an image node may be from its destination, relative to the destination's
/// mean face size: room for the faceting of a curved surface meshed differently on the
/// two sides (the sagitta h²/8R stays below 5 % of h while h < 0.4 R), none for a wrong
/// offset, angle or map.
const LANDING_TOLERANCE: f64 = 0.05;

/// An N-fold rotation must come back to the start after N turns.
fn check_closure(
    mut rot: Rigid,
    angle: f64,
    source: &SurfaceGeometry,
    model_size: f64,
    surface: &str,
    at: &Loc,
    out: &mut SceneSearch,
) {
    match fold_count(angle) {
        Some(n) => {
            let mut worst: f64 = 0.0;
            for f in source.faces.iter().take(64) {
                for &x in f.coords() {
                    if let Ok(e) = closure_error(&mut rot, x, n) {
                        worst = worst.max(e);
                    }
                }
            }
            if worst > 1e-12 * model_size {
                out.diagnostics.push(
                    Diagnostic::error(
                        "E0325",
                        format!("periodicity for `{surface}`: {n} rotations by {angle}° miss the start by {worst:.3e}"),
                    )
                    .at(Some(at.clone()))
                    .help("give the angle to full precision (e.g. 360/7 as 51.428571428571431)"),
                );
            }
        }
        None => out.diagnostics.push(
            Diagnostic::warning(
                "W0320",
                format!("periodicity for `{surface}`: the angle {angle}° does not divide 360°"),
            )
            .at(Some(at.clone()))
            .help("a sector of a full ring has an angle of 360/N degrees"),
        ),
    }
}

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
