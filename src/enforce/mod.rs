//! Enforcement: turning contact points into residual and Jacobian contributions.
//!
//! Entry points: [`conductance`] (conductance-coefficient models h(g, T_A, T_B, p) with
//! their exact derivatives) and [`interface`] (the interface forms — resistance, gap
//! conductance, tied Nitsche and interior penalty — assembled at contact points).

pub mod conductance;
pub mod electric;
pub mod interface;
pub mod model;
pub mod mortar;
