use super::*;

/// Compute the rows of every mortar tie (after `seam_search`) and return the
/// condensed rows of the dual ones:
/// `u[dofs[r]] = constants[r] + Σ_{k in offsets[r]..offsets[r+1]} coefficients[k] u[cols[k]]`.
/// `offsets` has `n_rows + 1` entries. Ties with standard multipliers add no condensed
/// rows; read their `C u = g` with `seam_tie_rows`.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_constraints(
    embedding: *mut SeamEmbedding,
    out_n_rows: *mut usize,
    out_dofs: *mut *const i64,
    out_constants: *mut *const f64,
    out_offsets: *mut *const usize,
    out_cols: *mut *const i64,
    out_coefficients: *mut *const f64,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.rows = None;
        let ties = e.inner.constraints()?;
        let r = e.rows.insert(Rows::of(ties));
        unsafe {
            r.write_condensed(
                out_n_rows,
                out_dofs,
                out_constants,
                out_offsets,
                out_cols,
                out_coefficients,
            )
        }
    })
}

impl Rows {
    /// The C arrays of `ties`: the dual ones' condensed rows, and each tie's `C u = g`.
    pub(super) fn of(ties: Vec<TieConstraints>) -> Rows {
        let mut r = Rows {
            offsets: vec![0],
            ..Rows::default()
        };
        for c in ties.iter().flat_map(|t| &t.condensed) {
            r.dofs.push(as_i64(c.dof));
            r.constants.push(c.constant);
            for &(j, v) in &c.terms {
                r.cols.push(as_i64(j));
                r.coefficients.push(v);
            }
            r.offsets.push(r.cols.len());
        }
        r.ties = ties
            .into_iter()
            .map(|t| {
                let arrays = TieArrays::from(&t);
                (t, arrays)
            })
            .collect();
        r
    }

    /// The condensed rows into the caller's out-pointers (`seam_constraints`).
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn write_condensed(
        &self,
        out_n_rows: *mut usize,
        out_dofs: *mut *const i64,
        out_constants: *mut *const f64,
        out_offsets: *mut *const usize,
        out_cols: *mut *const i64,
        out_coefficients: *mut *const f64,
    ) -> Result<(), Failure> {
        unsafe {
            out(out_n_rows, self.dofs.len(), "out_n_rows")?;
            out(out_dofs, self.dofs.as_ptr(), "out_dofs")?;
            out(out_constants, self.constants.as_ptr(), "out_constants")?;
            out(out_offsets, self.offsets.as_ptr(), "out_offsets")?;
            out(out_cols, self.cols.as_ptr(), "out_cols")?;
            out(
                out_coefficients,
                self.coefficients.as_ptr(),
                "out_coefficients",
            )
        }
    }

    /// Tie `index`, or why not.
    pub(super) fn tie(&self, index: usize) -> Result<&(TieConstraints, TieArrays), Failure> {
        self.ties.get(index).ok_or_else(|| {
            bad(
                format!("tie {index} does not exist ({} in all)", self.ties.len()),
                "ties are numbered from 0 in interaction order",
            )
        })
    }
}

/// Tie `t`'s `C u = g` into the caller's out-pointers (`seam_tie_rows`).
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn write_tie_rows(
    (t, a): &(TieConstraints, TieArrays),
    out_n_multipliers: *mut usize,
    out_multiplier_dofs: *mut *const i64,
    out_rhs: *mut *const f64,
    out_n_entries: *mut usize,
    out_multipliers: *mut *const i64,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> Result<(), Failure> {
    unsafe {
        out(
            out_n_multipliers,
            a.multiplier_dofs.len(),
            "out_n_multipliers",
        )?;
        out(
            out_multiplier_dofs,
            a.multiplier_dofs.as_ptr(),
            "out_multiplier_dofs",
        )?;
        out(out_rhs, t.rhs.as_ptr(), "out_rhs")?;
        out(out_n_entries, a.values.len(), "out_n_entries")?;
        out(out_multipliers, a.multipliers.as_ptr(), "out_multipliers")?;
        out(out_dofs, a.dofs.as_ptr(), "out_dofs")?;
        out(out_values, a.values.as_ptr(), "out_values")
    }
}

pub(super) fn tie<'a>(
    e: *const SeamEmbedding,
    index: usize,
) -> Result<&'a (TieConstraints, TieArrays), Failure> {
    // SAFETY: a non-null handle came from this library (module Safety).
    let e = unsafe { e.as_ref() }.ok_or_else(|| null("embedding"))?;
    let rows = e.rows.as_ref().ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "no constraints yet\n  help: call seam_constraints first (after seam_search)".into(),
        )
    })?;
    rows.tie(index)
}

/// Number of mortar ties (after `seam_constraints`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_tie_count(
    embedding: *const SeamEmbedding,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let n = e.rows.as_ref().map_or(0, |r| r.ties.len());
        unsafe { out(out_count, n, "out_count") }
    })
}

/// The rows `C u = g` of tie `index`: `n_multipliers` multipliers, the host dof of
/// each one's side-A node, `rhs` (g, one per multiplier), and `n_entries` entries
/// `C[multipliers[k]][dofs[k]] = values[k]`. For hosts that carry multipliers.
#[unsafe(no_mangle)]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn seam_tie_rows(
    embedding: *const SeamEmbedding,
    index: usize,
    out_n_multipliers: *mut usize,
    out_multiplier_dofs: *mut *const i64,
    out_rhs: *mut *const f64,
    out_n_entries: *mut usize,
    out_multipliers: *mut *const i64,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| unsafe {
        write_tie_rows(
            tie(embedding, index)?,
            out_n_multipliers,
            out_multiplier_dofs,
            out_rhs,
            out_n_entries,
            out_multipliers,
            out_dofs,
            out_values,
        )
    })
}

/// Heat through tie `index` for the host's multipliers `lambda` (one per multiplier).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_tie_heat(
    embedding: *const SeamEmbedding,
    index: usize,
    lambda: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let (t, _) = tie(embedding, index)?;
        let lambda = unsafe { slice(lambda, n, "lambda") }?;
        let heat = t.heat(lambda)?;
        unsafe { terms::write_heat((heat.side_a, heat.side_b), out_side_a, out_side_b) }
    })
}

/// Heat through dual tie `index` of a host that condensed it, from its own residual
/// `K u − F` without the tie (`n` entries, by host dof) at its solution.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_dual_tie_heat(
    embedding: *const SeamEmbedding,
    index: usize,
    residual: *const f64,
    n: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        let (t, _) = tie(embedding, index)?;
        let r = unsafe { slice(residual, n, "residual") }?;
        let heat = t.heat(&t.dual_multipliers(r)?)?;
        unsafe { terms::write_heat((heat.side_a, heat.side_b), out_side_a, out_side_b) }
    })
}
