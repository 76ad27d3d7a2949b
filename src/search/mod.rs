//! Geometric kernels of the contact search: a bounding-volume hierarchy over boxes
//! ([`bvh`]), closest-point projection of a point onto a face ([`project`]) and the
//! segment geometry of mortar integration ([`mortar`], with the overlap areas of one
//! face against many in `overlap`).
//!
//! The kernels take plain coordinates (`[f64; 3]`), not seam's mesh types, so they can be
//! tested and used anywhere; they are stateless apart from the [`bvh::Bvh`] itself.
//!
//! Above the kernels: [`pairing`] (the searcher of one interaction, over the typed
//! [`SearchSettings`]), [`periodic`] (periodic maps and their checks) and [`scene`] (the
//! searched pairs of a contact definition). Nothing here reads a deck: the scene, above,
//! lowers a deck to these settings; a host builds them in code.
//!
//! Conventions shared by all kernels:
//! - Side A carries integration points; side B is projected onto.
//! - A face's unit normal follows the right-hand rule of its node order (Exodus order,
//!   which points out of the element for a solid's side).
//! - Parametric coordinates: Tri3 `(ξ, η)` with node 0 at `(0, 0)`, node 1 at `(1, 0)`,
//!   node 2 at `(0, 1)`; Quad4 `(ξ, η) ∈ [-1, 1]²` with nodes at `(-1,-1), (1,-1), (1,1),
//!   (-1,1)`.
//! - Gaps are signed, positive on the side the normal points to; see each module for the
//!   exact definition.
//!
//! A closest-face search for one side-A point against side-B quads:
//!
//! ```
//! use seam::search::bvh::{Aabb, Bvh};
//! use seam::search::project::project_point_quad4;
//!
//! // Side B: two unit squares side by side at z = 0, normals +z.
//! let faces = [
//!     [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
//!     [[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [1.0, 1.0, 0.0]],
//! ];
//! let boxes: Vec<Aabb> = faces.iter().map(|f| Aabb::from_points(f)).collect();
//! let bvh = Bvh::build(&boxes);
//!
//! // A side-A point 0.01 above the second face: query a box around it, project onto
//! // each candidate, keep the closest.
//! let p = [1.25, 0.5, 0.01];
//! let mut best = None;
//! bvh.query(&Aabb::from_point(p).inflate(0.1), |f| {
//!     let pr = project_point_quad4(p, &faces[f]);
//!     if best.is_none_or(|(_, d)| pr.distance < d) {
//!         best = Some((f, pr.distance));
//!     }
//! });
//! let (face, _) = best.unwrap();
//! let pr = project_point_quad4(p, &faces[face]);
//! assert_eq!(face, 1);
//! assert!(pr.inside && (pr.gap - 0.01).abs() < 1e-15);
//! assert!((pr.xi[0] + 0.5).abs() < 1e-15 && pr.xi[1].abs() < 1e-15);
//! ```

pub mod bvh;
mod cover;
pub mod mortar;
mod overlap;
pub mod project;

pub mod pairing;
pub mod periodic;
pub mod scene;
pub mod settings;

pub use settings::{Overclosure, SearchSettings};
