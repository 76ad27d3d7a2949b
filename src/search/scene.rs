//! The searched pairs of a contact definition: one [`Pairing`] per interaction or
//! periodic condition, with the geometry searched and its result, their JSON summary
//! ([`PairingSummary`]) and the time the search took.
//!
//! Entry point: [`surface_geometries`] (the geometry of every surface of a set). The
//! search of a whole deck definition — which pairs, with which settings — is made by the
//! layer above (the scene's `search` part); the checks of periodic maps are in
//! [`super::periodic`].

use serde::Serialize;

use super::pairing::{SearchResult, SearchStats, SurfaceGeometry};
use crate::diag::{Diagnostic, Diagnostics};
use crate::mesh::Mesh;
use crate::surface::SurfaceSet;

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
                        .help("check the surface's faces in `seam surfaces`"),
                );
                geometry.push(None);
            }
        }
    }
    geometry
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
