//! Reference elements: the bottom layer every finite-element part of seam stands on.
//!
//! - [`shape`]: isoparametric shape functions of the linear solids (`Hex8`, `Tet4`,
//!   `Wedge6`, `Pyramid5`, `Quad4`, `Tri3`) and of their faces, on the reference cells;
//! - [`quadrature`]: quadrature rules on those cells, built on the one Gauss–Legendre
//!   rule of seam ([`quadrature::gauss_legendre`], and [`quadrature::gauss_legendre_01`]
//!   on `[0, 1]`);
//! - [`element`]: the isoparametric map of one element at a reference point
//!   ([`eval_point`]) or tabulated at a rule's points ([`Basis`]), and a `Hex8` at all
//!   eight points of its rule at once ([`Basis::map_hex8`]).
//!
//! Conventions: node order and reference cells as in [`shape`] (Exodus II order); 2-D
//! rules and points leave the third coordinate 0. Nothing here knows about decks,
//! searches or physics.

pub mod element;
pub mod quadrature;
pub mod shape;

pub use element::{BadJacobian, Basis, Hex8Points, MAX_NODES, PointValues, eval_point};
pub use quadrature::QuadratureRule;
