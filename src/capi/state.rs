//! What a host sets on its interactions between evaluations (on/off, point pressures,
//! quarantine) and the points a quarantine kept.

use std::ffi::{CString, c_char, c_int};

use super::fields::handle_ref;
use super::{Failure, SeamEmbedding, guard, handle, out, slice};

/// Switch interaction `index` on (`on` non-zero) or off: while off a flux interaction
/// adds nothing and reports 0 W; the CSR pattern is kept.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_set_active(
    embedding: *mut SeamEmbedding,
    index: usize,
    on: c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.inner.set_active(index, on != 0)?;
        e.values_changed();
        Ok(())
    })
}

/// The contact pressure (Pa) at each of the `n` contact points of interaction `index`
/// (in the order of `seam_point_fields`); `pressures` null and `n` 0 go back to the
/// enforcement's pressure. A search drops them.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_set_point_pressures(
    embedding: *mut SeamEmbedding,
    index: usize,
    pressures: *const f64,
    n: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let given = unsafe { pressures_arg(pressures, n) }?.map(<[f64]>::to_vec);
        e.inner.set_point_pressures(index, given)?;
        e.values_changed();
        Ok(())
    })
}

/// Quarantine the points where interaction `index`'s conductance fails (`on` non-zero):
/// they contribute nothing and are listed by `seam_quarantined`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_set_quarantine(
    embedding: *mut SeamEmbedding,
    index: usize,
    on: c_int,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        Ok(e.inner.set_quarantine(index, on != 0)?)
    })
}

/// The points of interaction `index` quarantined so far: `out_n` points, their xyz (3
/// per point) and the reasons, one line per point. Valid until the next
/// `seam_quarantined` on this handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_quarantined(
    embedding: *mut SeamEmbedding,
    index: usize,
    out_n: *mut usize,
    out_xyz: *mut *const f64,
    out_reasons: *mut *const c_char,
) -> c_int {
    guard(|| {
        let e = unsafe { handle_ref(embedding) }?;
        let kept = e.inner.quarantined(index);
        let b = &mut e.buffers;
        (b.quarantined_xyz, b.quarantined_reasons) = quarantined_arrays(&kept);
        let arrays = (&b.quarantined_xyz, &b.quarantined_reasons);
        unsafe { quarantined_out(arrays, out_n, out_xyz, out_reasons) }
    })
}

/// A setter's pressures: null with `n` 0 for none (back to the enforcement's
/// pressure), else `n` values.
pub(super) unsafe fn pressures_arg<'a>(
    pressures: *const f64,
    n: usize,
) -> Result<Option<&'a [f64]>, Failure> {
    match pressures.is_null() && n == 0 {
        true => Ok(None),
        false => unsafe { slice(pressures, n, "pressures") }.map(Some),
    }
}

/// Quarantined points as C arrays: their xyz (3 per point) and the reasons, one line
/// per point ('\n'-separated, NUL-terminated).
pub(super) fn quarantined_arrays(kept: &[crate::embed::Quarantined]) -> (Vec<f64>, CString) {
    let xyz = kept.iter().flat_map(|q| q.x).collect();
    let lines: Vec<String> = kept.iter().map(|q| q.message.replace('\n', " ")).collect();
    let reasons = CString::new(lines.join("\n").replace('\0', " ")).unwrap_or_default();
    (xyz, reasons)
}

/// Hand out the arrays of [`quarantined_arrays`] (kept by the handle).
pub(super) unsafe fn quarantined_out(
    (xyz, reasons): (&Vec<f64>, &CString),
    out_n: *mut usize,
    out_xyz: *mut *const f64,
    out_reasons: *mut *const c_char,
) -> Result<(), Failure> {
    unsafe {
        out(out_n, xyz.len() / 3, "out_n")?;
        out(out_xyz, xyz.as_ptr(), "out_xyz")?;
        out(out_reasons, reasons.as_ptr(), "out_reasons")
    }
}
