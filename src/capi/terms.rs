use super::*;

/// Evaluate the interface terms at the host's field `u` (`n` entries, by host dof).
/// Read them with `seam_residual`, `seam_jacobian`, `seam_load` and `seam_heat`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_evaluate(
    embedding: *mut SeamEmbedding,
    u: *const f64,
    n: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let u = unsafe { slice(u, n, "u") }?;
        e.evaluated = None;
        e.cutback = None;
        e.buffers.csr_current = false;
        match e.inner.contributions(u) {
            Ok(c) => e.evaluated = Some(Evaluated::from(c)),
            Err(err) => {
                if let EmbedError::Cutback { factor, .. } = &err {
                    e.cutback = Some(*factor);
                }
                return Err(err.into());
            }
        }
        Ok(())
    })
}

/// After `seam_evaluate` returned SEAM_CUTBACK: the new/old step the plugin suggests,
/// in (0, 1), or 0 when it leaves the choice to the host.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_cutback_factor(
    embedding: *const SeamEmbedding,
    out_factor: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        let factor = e.cutback.ok_or_else(|| {
            Failure(
                SeamStatus::Order,
                "the last evaluation asked for no cutback\n  help: call this after seam_evaluate returned SEAM_CUTBACK".into(),
            )
        })?;
        unsafe { out(out_factor, factor, "out_factor") }
    })
}

fn evaluated(e: &SeamEmbedding) -> Result<&Evaluated, Failure> {
    e.evaluated.as_ref().ok_or_else(|| {
        Failure(
            SeamStatus::Order,
            "nothing evaluated\n  help: call seam_evaluate first (after seam_search)".into(),
        )
    })
}

unsafe fn pairs(
    n: *mut usize,
    dofs: *mut *const i64,
    values: *mut *const f64,
    d: &[i64],
    v: &[f64],
) -> Result<(), Failure> {
    unsafe {
        out(n, d.len(), "out_n")?;
        out(dofs, d.as_ptr(), "out_dofs")?;
        out(values, v.as_ptr(), "out_values")
    }
}

/// Residual entries `(dofs[k], values[k])` of the last evaluation; dofs may repeat.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_residual(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { evaluated(e)?.write_residual(out_n, out_dofs, out_values) }
    })
}

/// Right-hand-side entries of linear models (offset terms) of the last evaluation.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_load(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_dofs: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { evaluated(e)?.write_load(out_n, out_dofs, out_values) }
    })
}

/// Jacobian triplets `(rows[k], cols[k], values[k])`; pairs may repeat (sum them).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_jacobian(
    embedding: *const SeamEmbedding,
    out_n: *mut usize,
    out_rows: *mut *const i64,
    out_cols: *mut *const i64,
    out_values: *mut *const f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { evaluated(e)?.write_jacobian(out_n, out_rows, out_cols, out_values) }
    })
}

/// Heat (W) leaving side A and side B of interaction `index` at the last evaluation.
/// For a mortar tie use `seam_tie_heat` or `seam_dual_tie_heat`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_heat(
    embedding: *const SeamEmbedding,
    index: usize,
    out_side_a: *mut f64,
    out_side_b: *mut f64,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        // The heat of the last evaluation, triplets or CSR.
        let heat: Vec<Option<(f64, f64)>> = match &e.evaluated {
            Some(ev) => ev.heat.clone(),
            None if e.buffers.csr_current => fields::csr(e)?
                .heat
                .iter()
                .map(|h| h.map(|h| (h.side_a, h.side_b)))
                .collect(),
            None => evaluated(e)?.heat.clone(),
        };
        let (a, b) = match heat.get(index) {
            Some(Some(h)) => *h,
            Some(None) => {
                return Err(bad(
                    format!("interaction {index} is a mortar tie"),
                    "read its heat with seam_tie_heat or seam_dual_tie_heat",
                ));
            }
            None => {
                return Err(bad(
                    format!("interaction {index} does not exist ({} in all)", heat.len()),
                    "indices are 0-based, in the order interactions were added",
                ));
            }
        };
        unsafe { write_heat((a, b), out_side_a, out_side_b) }
    })
}

impl Evaluated {
    /// The residual entries into a getter's out-parameters.
    pub(super) unsafe fn write_residual(
        &self,
        n: *mut usize,
        dofs: *mut *const i64,
        values: *mut *const f64,
    ) -> Result<(), Failure> {
        unsafe { pairs(n, dofs, values, &self.residual_dofs, &self.residual_values) }
    }

    /// The load entries into a getter's out-parameters.
    pub(super) unsafe fn write_load(
        &self,
        n: *mut usize,
        dofs: *mut *const i64,
        values: *mut *const f64,
    ) -> Result<(), Failure> {
        unsafe { pairs(n, dofs, values, &self.load_dofs, &self.load_values) }
    }

    /// The Jacobian triplets into a getter's out-parameters.
    pub(super) unsafe fn write_jacobian(
        &self,
        n: *mut usize,
        rows: *mut *const i64,
        cols: *mut *const i64,
        values: *mut *const f64,
    ) -> Result<(), Failure> {
        unsafe {
            out(n, self.rows.len(), "out_n")?;
            out(rows, self.rows.as_ptr(), "out_rows")?;
            out(cols, self.cols.as_ptr(), "out_cols")?;
            out(values, self.values.as_ptr(), "out_values")
        }
    }
}

/// A heat (side A, side B) into a getter's out-parameters.
pub(super) unsafe fn write_heat(
    (a, b): (f64, f64),
    side_a: *mut f64,
    side_b: *mut f64,
) -> Result<(), Failure> {
    unsafe {
        out(side_a, a, "out_side_a")?;
        out(side_b, b, "out_side_b")
    }
}
