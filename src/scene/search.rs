//! The search of a whole contact definition: every interaction, and every periodic
//! image paired with its destination.
//!
//! Entry point: [`search_definition`]; [`search_periodicity`] searches one periodic
//! condition and keeps its map (for callers that move nodes and search again). Periodic
//! conditions (`Periodicity For S = …`) are interactions between the image of `S` (side
//! A) and a destination surface (side B): `Align_Surface` names it; for the other
//! transforms it is the face surface, other than `S`, on which most of the image's points
//! land. The inverse map is never asked of the user: the destination's side of the
//! pairing is found by the search itself.
//!
//! The checks of a periodic map ([`crate::search::periodic`]) are reported here with
//! their deck location: E0320 (unknown surface), E0321 (the map cannot be made or
//! fails), E0322 (no mean normal), E0323 (the image lands nowhere), E0324 (the image
//! misses its destination), E0325 (a rotation that does not close), E0326 (a map that is
//! not one-to-one, before the search), E0327 (in an axisymmetric model: a cylindrical
//! transform, or a map that changes a node's radius), W0320 (an angle that does not
//! divide 360°).
//!
//! This is also where the deck's search options become the typed
//! [`SearchSettings`] of periodic pairs ([`base_settings`]), its subdomain a
//! [`Sphere`] ([`subdomain`]), its update frequency a [`SearchSchedule`]
//! ([`search_schedule`]) and its transforms [`PeriodicTransform`]s.

use std::path::Path;
use std::time::Instant;

use super::interaction::Interaction;
use crate::deck::spec::{self, ContactDefinition, Periodicity};
use crate::diag::{Diagnostic, SourceMap};
use crate::mesh::Mesh;
use crate::periodic::MapError;
use crate::search::pairing::{
    Integration, SearchError, SearchSchedule, Searcher, Sphere, SurfaceGeometry,
};
use crate::search::periodic::{
    Closure, PeriodicError, PeriodicPairing, PeriodicTransform, check_axisymmetric, check_closure,
    check_one_to_one, landing, periodic_map,
};
use crate::search::scene::{Pairing, SceneSearch, surface_geometries};
use crate::search::{Overclosure, SearchSettings};
use crate::surface::{SurfaceKind, SurfaceSet};

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
    let mut maps = Vec::new();
    search_definition_with_maps(
        mesh,
        def,
        surfaces,
        interactions,
        deck_dir,
        sources,
        integration,
        &mut maps,
    )
}

/// The map of a periodic pairing, by the pairing's index in [`SceneSearch::pairings`].
pub type PairingMaps = Vec<(usize, Box<dyn crate::periodic::PeriodicMap>)>;

/// As [`search_definition`], keeping each periodic pairing's map in `maps` (for hosts
/// that move nodes and map side A again).
#[allow(clippy::too_many_arguments)]
pub fn search_definition_with_maps(
    mesh: &Mesh,
    def: &ContactDefinition,
    surfaces: &SurfaceSet,
    interactions: &[Interaction],
    deck_dir: &Path,
    sources: &SourceMap,
    integration: Integration,
    maps: &mut PairingMaps,
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
        // Under MPI every rank asks (a rank may hold none of side B's faces).
        if !crate::parallel::any_rank(!b.faces.is_empty()) {
            continue;
        }
        let pair = (a, b);
        let overclosure = Some(i.overclosure);
        let Some((result, side_b)) = search_pair(
            mesh,
            pair,
            (&i.settings, integration, subdomain, overclosure),
            &mut out,
        ) else {
            continue;
        };
        out.pairings.push(Pairing {
            side_a: i.side_a_name.clone(),
            side_b: i.side_b_name.clone(),
            side_a_surface: i.side_a,
            side_b_surface: i.side_b,
            periodic: false,
            side_a_geometry: a.clone(),
            side_b_geometry: side_b.unwrap_or_else(|| b.clone()),
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
            maps.push((out.pairings.len(), found.map));
            out.pairings.push(found.pairing);
        }
    }
    out
}

/// Pair `a`'s points with `b`'s faces, the matched points' overclosure treated with
/// `overclosure`: serially, or under MPI by the distributed search (the same pairing;
/// `crate::parallel::search`; on a rank holding a part of the mesh its own points, with
/// the side-B faces they paired with), timed into `out`. `None` (and an E0904 error) when
/// the distributed search fails.
fn search_pair(
    mesh: &Mesh,
    (a, b): (&SurfaceGeometry, &SurfaceGeometry),
    (settings, integration, subdomain, overclosure): (
        &SearchSettings,
        Integration,
        Option<Sphere>,
        Option<Overclosure>,
    ),
    out: &mut SceneSearch,
) -> Option<crate::parallel::RunPairing> {
    let t = Instant::now();
    let found =
        crate::parallel::search_in_run(mesh, (a, b), settings, integration, subdomain, overclosure);
    match found {
        Some(Ok(r)) => {
            out.timing.search_s += t.elapsed().as_secs_f64();
            Some(r)
        }
        Some(Err(e)) => {
            out.diagnostics.push(
                Diagnostic::error("E0904", format!("{} / {}: {e}", a.name, b.name)).help(
                    "run without mpirun (serially); docs/parallel.md lists what is distributed",
                ),
            );
            None
        }
        None => {
            let searcher = Searcher::new(b, settings);
            out.timing.build_s += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let mut r = searcher.search(a, b, settings, integration, subdomain);
            if let Some(treatment) = overclosure {
                r.treat_overclosure(treatment);
            }
            out.timing.search_s += t.elapsed().as_secs_f64();
            Some((r, None))
        }
    }
}

/// `Restrict Contact To Subdomain` of a definition: the sphere outside which nothing is
/// searched.
pub fn subdomain(def: &ContactDefinition) -> Option<Sphere> {
    def.restrict_contact_to_subdomain.as_ref().map(|s| Sphere {
        center: s.point,
        radius: s.radius,
    })
}

/// The search settings a definition gives every pair it searches — its interactions
/// (before their own overrides) and its periodic pairs: the search options, `Opposed
/// Normal Threshold Angle` and `Disable Opposed Normal Interaction Culling`.
pub fn base_settings(def: &ContactDefinition, dim: usize) -> SearchSettings {
    let mut s = SearchSettings::defaults(dim);
    if let Some(o) = &def.search_options {
        s.normal_tolerance = o.normal_tolerance.or(s.normal_tolerance);
        s.tangential_tolerance = o.tangential_tolerance.unwrap_or(s.tangential_tolerance);
        s.buffer_factor = o.buffer_factor.unwrap_or(s.buffer_factor);
        s.field_factor = o.field_factor.unwrap_or(s.field_factor);
        s.normal_check_angle = o.normal_check_angle.unwrap_or(s.normal_check_angle);
    }
    if let Some(a) = def.opposed_normal_threshold_angle {
        s.opposed_normal_threshold_angle = a;
    }
    s.cull_opposed_normals = !def.disable_opposed_normal_interaction_culling;
    s
}

fn face_surface(surfaces: &SurfaceSet, name: &str) -> Option<usize> {
    let name = name.to_ascii_lowercase();
    surfaces
        .surfaces
        .iter()
        .position(|s| s.name == name && s.kind == SurfaceKind::Faces)
}

/// The search schedule of a contact definition: `Update Search Every n Steps`, else the
/// search options' `Search Update Frequency` (ELFEN's name for the same), else 1.
pub fn search_schedule(def: &ContactDefinition) -> SearchSchedule {
    SearchSchedule::new(
        def.update_search_every_n_steps.or(def
            .search_options
            .as_ref()
            .and_then(|o| o.search_update_frequency)),
    )
}

impl From<&spec::PeriodicTransform> for PeriodicTransform {
    fn from(t: &spec::PeriodicTransform) -> Self {
        match t {
            spec::PeriodicTransform::Rectangular { offset } => PeriodicTransform::Rectangular {
                offset: offset.clone(),
            },
            spec::PeriodicTransform::Cylindrical {
                axis,
                center,
                angle,
            } => PeriodicTransform::Cylindrical {
                axis: axis.clone(),
                center: center.clone(),
                angle: *angle,
            },
            spec::PeriodicTransform::AlignSurface {
                destination,
                invert_normals,
            } => PeriodicTransform::AlignSurface {
                destination: destination.clone(),
                invert_normals: *invert_normals,
            },
            spec::PeriodicTransform::Mapped {
                x_map,
                y_map,
                z_map,
            } => PeriodicTransform::Mapped {
                x_map: x_map.clone(),
                y_map: y_map.clone(),
                z_map: z_map.clone(),
            },
        }
    }
}

impl From<spec::Overclosure> for Overclosure {
    fn from(o: spec::Overclosure) -> Self {
        match o {
            spec::Overclosure::AdjustNodes => Overclosure::AdjustNodes,
            spec::Overclosure::StoreOffsets => Overclosure::StoreOffsets,
        }
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
    let checked = periodic_image(mesh, p, surfaces, geometry, (deck_dir, sources), &at, out);
    // Under MPI every rank searches or none does: a rank holding part of the surface
    // checks that part, rank 0 the whole.
    let ok = checked.is_some();
    if let Err(r) = crate::parallel::all_ranks_ok(ok) {
        if ok {
            out.diagnostics.push(
                Diagnostic::error(
                    "E0904",
                    format!(
                        "periodicity for `{}`: its image failed on rank {r}",
                        p.surface
                    ),
                )
                .at(Some(at.clone()))
                .help("run without mpirun (serially) to see why"),
            );
        }
        return None;
    }
    let (s, image, map, destination) = checked?;

    // The destination: given, or the face surface that takes most image points.
    let candidates: Vec<usize> = match destination {
        Some(d) => vec![d],
        None => (0..surfaces.surfaces.len())
            .filter(|&d| {
                // Under MPI every rank asks (a rank may hold none of its faces).
                let faces = geometry[d].as_ref().is_some_and(|g| !g.faces.is_empty());
                d != s && crate::parallel::any_rank(faces)
            })
            .collect(),
    };
    let mut best: Option<(usize, crate::parallel::RunPairing)> = None;
    for d in candidates {
        let Some(dg) = &geometry[d] else { continue };
        let search = (&settings, integration, subdomain, None);
        let Some(r) = search_pair(mesh, (&image, dg), search, out) else {
            continue;
        };
        if best
            .as_ref()
            .is_none_or(|(_, b)| r.0.stats.matched > b.0.stats.matched)
        {
            best = Some((d, r));
        }
    }
    let Some((d, (result, side_b))) = best.filter(|(_, r)| r.0.stats.matched > 0) else {
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
            side_b_geometry: side_b.unwrap_or_else(|| dg.clone()),
            result,
            worst_image_distance: Some(landed.worst),
        },
        map,
    })
}

/// The checks of a periodicity and its image: (source surface, image, map, the
/// destination `Align_Surface` names), or `None` with the diagnostics in `out`.
#[allow(clippy::type_complexity)]
fn periodic_image(
    mesh: &Mesh,
    p: &Periodicity,
    surfaces: &SurfaceSet,
    geometry: &[Option<SurfaceGeometry>],
    (deck_dir, sources): (&Path, &SourceMap),
    at: &crate::diag::Loc,
    out: &mut SceneSearch,
) -> Option<(
    usize,
    SurfaceGeometry,
    Box<dyn crate::periodic::PeriodicMap>,
    Option<usize>,
)> {
    let at = at.clone();
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
    let transform = PeriodicTransform::from(&p.transform);
    // The whole mesh's, on a rank that holds a part of it.
    let model_size = crate::parallel::model_size(mesh);
    let axisymmetric_help = "in an axisymmetric model a periodicity repeats along the axis: `Rectangular Offset = 0 dy`";
    if mesh.axisymmetric && matches!(transform, PeriodicTransform::Cylindrical { .. }) {
        let e = PeriodicError::CylindricalInAxisymmetric;
        out.diagnostics.push(
            Diagnostic::error("E0327", format!("periodicity for `{}`: {e}", p.surface))
                .at(Some(p.at.clone()))
                .help(axisymmetric_help),
        );
        return None;
    }
    let mut destination = None;
    if let PeriodicTransform::AlignSurface {
        destination: dest, ..
    } = &transform
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
    match check_closure(&transform, source, model_size) {
        Ok(Closure::AngleDoesNotDivide) => {
            if let PeriodicTransform::Cylindrical { angle, .. } = &transform {
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
        &transform,
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
    let numbers = |n| mesh.node_number(n);
    if let Err(e) = check_axisymmetric(&transform, source, &image, model_size, numbers) {
        out.diagnostics.push(
            Diagnostic::error("E0327", format!("periodicity for `{}`: {e}", p.surface))
                .at(Some(at))
                .help(axisymmetric_help),
        );
        return None;
    }
    if let Some(fold) = check_one_to_one(source, &image, |n| mesh.node_number(n)) {
        let e = PeriodicError::Folds(Box::new(fold));
        out.diagnostics.push(
            Diagnostic::error("E0326", format!("periodicity for `{}`: {e}", p.surface))
                .at(Some(at))
                .help("a periodic map carries each node to its own place on the partner surface (a rigid motion or close to one); check the map: a constant (`x_map = 0`) or a folding formula (`x_map = math.abs(x)`) sends several nodes to one point"),
        );
        return None;
    }

    Some((s, image, map, destination))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Periodic pairs see the definition's opposed-normal settings, as its interactions
    /// do (they once took only the search options).
    #[test]
    fn periodic_pairs_take_the_definitions_opposed_normal_settings() {
        let def = ContactDefinition {
            opposed_normal_threshold_angle: Some(30.0),
            disable_opposed_normal_interaction_culling: true,
            ..ContactDefinition::default()
        };
        let s = base_settings(&def, 3);
        assert_eq!(s.opposed_normal_threshold_angle, 30.0);
        assert!(!s.cull_opposed_normals);
        let plain = base_settings(&ContactDefinition::default(), 3);
        assert_eq!(plain, SearchSettings::defaults(3));
    }
}
