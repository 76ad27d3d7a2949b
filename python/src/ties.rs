//! Mortar ties: their constraint rows `C u = g` for hosts that carry multipliers, and,
//! for dual multipliers, the condensed rows `u[dofs] = constants + T u` for hosts that
//! do not (substitute them: the system stays symmetric positive definite).

use pyo3::prelude::*;

use seam::embed::{self, Multipliers};

use crate::array::{self, array};
use crate::embedding::{Embedding, Heat};
use crate::error::OrPy;

/// The constraint rows of one mortar tie, in the host's dof numbers
/// ([`Embedding::constraints`]).
#[pyclass(module = "seam", frozen)]
pub struct TieConstraints {
    pub(crate) inner: embed::TieConstraints,
}

#[pymethods]
impl TieConstraints {
    /// Index of the interaction.
    #[getter]
    fn interaction(&self) -> usize {
        self.inner.interaction
    }

    /// ``"standard"`` or ``"dual"``.
    #[getter]
    fn multipliers(&self) -> &'static str {
        match self.inner.multipliers {
            Multipliers::Standard => "standard",
            Multipliers::Dual => "dual",
        }
    }

    /// The host dof of each multiplier's side-A node, in multiplier order.
    #[getter]
    fn multiplier_dofs(&self, py: Python<'_>) -> Py<PyAny> {
        array(
            py,
            self.inner
                .multiplier_dofs
                .iter()
                .map(|&d| d as i64)
                .collect(),
        )
    }

    /// g, one entry per multiplier (ΔT ∫ψ_k for an offset tie, else 0).
    #[getter]
    fn rhs(&self, py: Python<'_>) -> Py<PyAny> {
        array(py, self.inner.rhs.clone())
    }

    /// Side-A nodes left without a multiplier (fixed, or on an earlier tie).
    #[getter]
    fn crosspoints(&self, py: Python<'_>) -> Py<PyAny> {
        array(
            py,
            self.inner.crosspoints.iter().map(|&d| d as i64).collect(),
        )
    }

    /// C as a (multipliers, n) csr_matrix over a field of n host dofs: the tie is
    /// ``C @ u == rhs``.
    fn matrix(&self, py: Python<'_>, n: usize) -> PyResult<Py<PyAny>> {
        let m = self.inner.multiplier_dofs.len();
        check_columns(self.inner.entries.iter().map(|e| e.1), n)?;
        array::csr_from_triplets(py, (m, n), self.inner.entries.iter().copied())
    }

    /// Dual ties: ``(dofs, constants, T)`` with ``u[dofs] = constants + T @ u``, T a
    /// (len(dofs), n) csr_matrix whose columns avoid ``dofs``. Empty for standard ties.
    fn condensed(&self, py: Python<'_>, n: usize) -> PyResult<(Py<PyAny>, Py<PyAny>, Py<PyAny>)> {
        let rows = &self.inner.condensed;
        check_columns(rows.iter().flat_map(|r| r.terms.iter().map(|t| t.0)), n)?;
        let triplets = rows
            .iter()
            .enumerate()
            .flat_map(|(k, r)| r.terms.iter().map(move |&(j, c)| (k, j, c)));
        Ok((
            array(py, rows.iter().map(|r| r.dof as i64).collect()),
            array(py, rows.iter().map(|r| r.constant).collect()),
            array::csr_from_triplets(py, (rows.len(), n), triplets)?,
        ))
    }

    /// Heat (W) leaving each side for multipliers ``lam`` (the flux from A to B).
    fn heat(&self, lam: &Bound<'_, PyAny>) -> PyResult<Heat> {
        let lam = array::f64s(lam, "lam")?;
        let h = self.inner.heat(&lam).py_err()?;
        Ok(Heat {
            side_a: h.side_a,
            side_b: h.side_b,
        })
    }

    /// A condensed dual tie's multipliers from the host's residual ``K u − F`` (without
    /// the tie) at its solution, by host dof.
    fn dual_multipliers(&self, py: Python<'_>, residual: &Bound<'_, PyAny>) -> PyResult<Py<PyAny>> {
        let r = array::f64s(residual, "residual")?;
        Ok(array(py, self.inner.dual_multipliers(&r).py_err()?))
    }

    fn __repr__(&self) -> String {
        format!(
            "TieConstraints(interaction={}, multipliers={:?}, {} multipliers)",
            self.inner.interaction,
            self.multipliers(),
            self.inner.multiplier_dofs.len()
        )
    }
}

/// Every column index below `n`.
fn check_columns(mut cols: impl Iterator<Item = usize>, n: usize) -> PyResult<()> {
    match cols.find(|&c| c >= n) {
        Some(c) => Err(crate::error::argument(
            format!("the tie couples dof {c}, beyond a field of {n} dofs"),
            "give n as the length of the host's field vector",
        )),
        None => Ok(()),
    }
}

#[pymethods]
impl Embedding {
    /// The constraint rows of every mortar tie, in interaction order.
    fn constraints(&self, py: Python<'_>) -> PyResult<Vec<TieConstraints>> {
        let ties = self.run(py, |e| e.constraints())?;
        Ok(ties
            .into_iter()
            .map(|inner| TieConstraints { inner })
            .collect())
    }
}
