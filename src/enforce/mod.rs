//! Enforcement: turning contact points into residual and Jacobian contributions.
//!
//! Entry points: [`conductance`] (conductance-coefficient models h(g, T_A, T_B, p) with
//! their exact derivatives).

pub mod conductance;
