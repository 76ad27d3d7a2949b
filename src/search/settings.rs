//! The typed settings of one interaction's search: the tolerances and angles of
//! [`super::pairing::Searcher`] ([`SearchSettings`]) and what to do with points that start
//! overclosed ([`Overclosure`]).
//!
//! The search takes these and nothing else; the scene, above, fills them from a deck's `begin Search Options`, interaction and control-assignment lines, a host
//! builds them in code.

use serde::Serialize;

/// Search controls of one interaction, with their defaults resolved.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SearchSettings {
    /// Largest |gap| accepted, absolute length; `None`: set by the field factor.
    pub normal_tolerance: Option<f64>,
    /// How far outside a face (relative to its size) a projection still counts.
    pub tangential_tolerance: f64,
    /// Search box = mean facet length × buffer factor (ELFEN; 1.0 in 3-D, 5.0 in 2-D).
    pub buffer_factor: f64,
    /// Largest penetration or separation considered = target facet length × field factor.
    pub field_factor: f64,
    /// A target whose normal makes more than this angle (degrees) with the opposite of
    /// the contact point's normal is ignored.
    pub normal_check_angle: f64,
    /// Faces whose normals make less than this angle (degrees) are not opposed and are
    /// culled, unless culling is disabled.
    pub opposed_normal_threshold_angle: f64,
    pub cull_opposed_normals: bool,
}

impl SearchSettings {
    /// Defaults for a mesh of spatial dimension `dim`.
    pub fn defaults(dim: usize) -> Self {
        SearchSettings {
            normal_tolerance: None,
            tangential_tolerance: 1e-3,
            buffer_factor: if dim == 2 { 5.0 } else { 1.0 },
            field_factor: 0.2,
            normal_check_angle: 80.0,
            opposed_normal_threshold_angle: 90.0,
            cull_opposed_normals: true,
        }
    }
}

/// Treatment of an initial overclosure (a negative gap in the undeformed geometry), as
/// [`super::pairing::SearchResult::treat_overclosure`] applies it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Overclosure {
    /// Move side-A points onto side B: the enforcement then starts from gap 0.
    AdjustNodes,
    /// Keep the geometry and record the initial gap as an offset (the thermal default).
    StoreOffsets,
}
