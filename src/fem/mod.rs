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
//! rules and points leave the third coordinate 0. A 2-D model's integrals are per unit
//! depth or, axisymmetric, per full revolution ([`Measure`]). Nothing here knows about
//! decks, searches or physics.

pub mod element;
pub mod quadrature;
pub mod shape;

pub use element::{BadJacobian, Basis, Hex8Points, MAX_NODES, PointValues, eval_point};
pub use quadrature::QuadratureRule;

/// How the integrals of a model are measured. 3-D and plane 2-D models integrate over
/// their volume and surfaces as they are (a 2-D one per unit depth); an axisymmetric
/// 2-D model (x the radius r ≥ 0, y the axis) is the section of a body of revolution,
/// and its integrals are per full revolution: `dV = 2πr dA`, `dS = 2πr ds`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Measure {
    #[default]
    Plane,
    Axisymmetric,
}

impl Measure {
    /// `Axisymmetric` when `axisymmetric`, else `Plane` (from [`crate::mesh::Mesh::axisymmetric`]).
    pub fn of(axisymmetric: bool) -> Self {
        if axisymmetric {
            Measure::Axisymmetric
        } else {
            Measure::Plane
        }
    }

    /// The factor of a weight at point `x`: 1, or `2πr` with r = x[0]. On the axis it
    /// is 0 — no division anywhere, so nodes at r = 0 need no special case.
    #[inline]
    pub fn factor(self, x: [f64; 3]) -> f64 {
        match self {
            Measure::Plane => 1.0,
            Measure::Axisymmetric => std::f64::consts::TAU * x[0],
        }
    }
}
