//! Geometric kernels of the contact search: a bounding-volume hierarchy over boxes
//! ([`bvh`]), closest-point projection of a point onto a face ([`project`]) and the
//! segment geometry of mortar integration ([`mortar`]).
//!
//! The kernels take plain coordinates (`[f64; 3]`), not seam's mesh types, so they can be
//! tested and used anywhere; they are stateless apart from the [`bvh::Bvh`] itself.
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

pub mod bvh;
pub mod mortar;
pub mod project;

pub mod pairing;
pub mod scene;
mod vec3;
