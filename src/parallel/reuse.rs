//! A BoomerAMG hierarchy kept from one matrix to the next of a distributed Newton solve
//! or run of time steps (PETSc's `KSPSetReusePreconditioner`), by the serial AMG's
//! rules (`src/solve/amg/reuse.rs`): a Jacobian of a conduction of T changes little
//! from one Newton iterate or step to the next, so the hierarchy set up for an earlier
//! one still preconditions it, and GMRES (or CG) pays a few iterations where a set-up
//! costs many.
//!
//! The rules: a new `c₀` (a new step size, backward Euler's `M/Δt` becoming BDF2's
//! `3M/2Δt`: the change the serial rule finds by the diagonal) gets a new set-up. The
//! Krylov iterations of the first solve after a set-up are the base; a later solve that
//! needs more than `base + base/2 + 3` marks the hierarchy as degraded, and the next
//! matrix is set up anew. A solve that fails on a kept hierarchy is set up anew and
//! solved again. Unlike the serial rule, PETSc keeps the whole hierarchy, its finest
//! level included: the V-cycle smooths with the earlier matrix.

/// The state of the hierarchy a distributed Krylov solver keeps.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Hierarchy {
    /// The `c₀` (bits) of the matrix it was set up for; `None` before the first.
    c0: Option<u64>,
    /// The Krylov iterations of the first solve after the set-up.
    base: Option<usize>,
    /// A later solve took too many more: the next matrix gets a new set-up.
    degraded: bool,
}

impl Hierarchy {
    /// Whether a new matrix of `c0` is solved on the hierarchy as it is.
    pub fn serves(&self, c0: f64) -> bool {
        !self.degraded && self.c0 == Some(c0.to_bits())
    }

    /// A hierarchy was set up for a matrix of `c0`.
    pub fn set_up(&mut self, c0: f64) {
        *self = Hierarchy {
            c0: Some(c0.to_bits()),
            ..Hierarchy::default()
        };
    }

    /// A solve on it took `iterations`.
    pub fn solved(&mut self, iterations: usize) {
        match self.base {
            None => self.base = Some(iterations),
            Some(base) => self.degraded |= iterations > base + base / 2 + 3,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Hierarchy;

    #[test]
    fn a_hierarchy_serves_its_c0_until_its_solves_degrade() {
        let mut h = Hierarchy::default();
        assert!(!h.serves(0.0), "nothing set up yet");
        h.set_up(2.0);
        assert!(h.serves(2.0) && !h.serves(3.0));
        h.solved(10);
        h.solved(18); // base + base/2 + 3 = 18: still served
        assert!(h.serves(2.0));
        h.solved(19);
        assert!(!h.serves(2.0), "degraded");
        h.set_up(2.0);
        assert!(h.serves(2.0), "a new set-up starts again");
    }
}
