//! The C ABI between seam (the host) and enforcement plugins, version 1.0.
//!
//! Everything here is `#[repr(C)]` and mirrored field for field by the hand-kept header
//! `plugins/include/seam_plugin.h`; the root crate's tests compile the header and compare
//! every `sizeof`, `offsetof` and constant with this file.
//!
//! Entry point: a plugin exports [`ENTRY_SYMBOL`] (`seam_plugin_v1`), a function without
//! arguments returning a pointer to a static [`SeamPluginDescriptor`]. One symbol per ABI
//! major version, so a host can tell "not a seam plugin" from "a seam plugin for another
//! major version".
//!
//! Versioning rules:
//! - the major version changes when an existing field changes meaning, type or offset;
//!   host and plugin majors must be equal;
//! - the minor version changes when fields are appended to a struct; the host refuses a
//!   plugin whose minor is newer than its own (the plugin might rely on input fields the
//!   host does not fill);
//! - every struct starts with (or, for the descriptor, has at a fixed offset) a
//!   `struct_size` set by whoever fills it, so that either side can tell which appended
//!   fields the other knows about.
//!
//! Ownership: the host owns every input and output buffer; the plugin writes only into
//! the output struct it is handed and into `state_new`. Strings are NUL-terminated UTF-8.
//! The per-instance context returned by `init` is the plugin's, released by `finalize`.
//! The host never unloads a plugin library.
#![cfg_attr(not(test), no_std)]

use core::ffi::{c_char, c_void};

/// ABI major version spoken by this crate.
pub const SEAM_PLUGIN_ABI_MAJOR: u32 = 1;
/// ABI minor version spoken by this crate.
pub const SEAM_PLUGIN_ABI_MINOR: u32 = 0;
/// The entry symbol of ABI major 1, NUL-terminated for `dlsym`.
pub const ENTRY_SYMBOL: &[u8] = b"seam_plugin_v1\0";

/// Length of the message buffer in [`SeamPointOut`] and of `init`'s message argument,
/// including the terminating NUL.
pub const SEAM_MESSAGE_LEN: usize = 256;

/// The point was evaluated; the outputs are valid.
pub const SEAM_STATUS_OK: i32 = 0;
/// The plugin could not evaluate the point; `message` says why. The host stops.
pub const SEAM_STATUS_ERROR: i32 = 1;
/// The plugin asks for a smaller time step (Abaqus' `PNEWDT < 1`); `cutback_factor` may
/// suggest the ratio new/old step and `message` may say why.
pub const SEAM_STATUS_CUTBACK: i32 = 2;

/// Calls may come from several threads at once. Without it the host serialises calls.
pub const SEAM_CAP_THREAD_SAFE: u64 = 1 << 0;
/// The plugin fills the four derivatives. Without it the host forms them by central
/// finite differences.
pub const SEAM_CAP_PROVIDES_DERIVATIVES: u64 = 1 << 1;
/// `value` is a flux q (W/m²) into side A. Without it `value` is a conductance h (W/m²K)
/// and must be non-negative; the host forms q = h (T_B − T_A) itself.
pub const SEAM_CAP_RETURNS_FLUX: u64 = 1 << 2;
/// The plugin keeps `state_size` doubles of state per contact point.
pub const SEAM_CAP_HAS_STATE: u64 = 1 << 3;
/// Every capability bit this ABI version defines; other bits are reserved (zero).
pub const SEAM_CAP_ALL: u64 = SEAM_CAP_THREAD_SAFE
    | SEAM_CAP_PROVIDES_DERIVATIVES
    | SEAM_CAP_RETURNS_FLUX
    | SEAM_CAP_HAS_STATE;

/// Per-instance data, given once to `init` (one instance per enforcement in the deck).
/// The arrays are valid only during the `init` call: copy what you keep.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamInstanceIn {
    /// `size_of::<SeamInstanceIn>()` as the host knows it.
    pub struct_size: u32,
    pub reserved: u32,
    /// The deck's `Model = name` (NUL-terminated), or the descriptor's name if none given.
    pub model: *const c_char,
    /// The enforcement's `Integer Data`.
    pub integer_data: *const i64,
    pub n_integer: usize,
    /// The enforcement's `Real Data`.
    pub real_data: *const f64,
    pub n_real: usize,
}

/// One contact point: a side-A integration point and its side-B partner.
///
/// Gap is positive when open, negative when overlapping. Normals are outward unit
/// normals of each side. All pointers are valid only during the call.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamPointIn {
    /// `size_of::<SeamPointIn>()` as the host knows it.
    pub struct_size: u32,
    pub reserved: u32,
    pub gap: f64,
    /// Contact pressure, ≥ 0 in compression.
    pub pressure: f64,
    /// Temperature on side A at the point.
    pub temp_a: f64,
    /// Temperature on side B at the projected point.
    pub temp_b: f64,
    /// Coordinates of the side-A point.
    pub x: [f64; 3],
    pub normal_a: [f64; 3],
    pub normal_b: [f64; 3],
    /// Integration weight: the share of side-A face area this point stands for.
    pub weight: f64,
    /// Time at the end of the step being solved.
    pub time: f64,
    /// Step size.
    pub dt: f64,
    /// Step number, from 1.
    pub step: i64,
    /// Newton iteration within the step, from 0.
    pub iteration: i64,
    /// Names of the side-A and side-B contact surfaces, NUL-terminated.
    pub surface_a: *const c_char,
    pub surface_b: *const c_char,
    /// Values of other fields at the point, in the order the host documents.
    pub fields: *const f64,
    pub n_fields: usize,
    /// Copies of the enforcement's `Integer Data` and `Real Data`: writes are not kept.
    pub integer_data: *const i64,
    pub n_integer: usize,
    pub real_data: *const f64,
    pub n_real: usize,
    /// State at the start of the step (last accepted step), `n_state` doubles.
    pub state_old: *const f64,
    /// State at the end of the step; on entry a copy of `state_old`. The host keeps it
    /// only when the step is accepted.
    pub state_new: *mut f64,
    pub n_state: usize,
}

/// What the plugin returns for one contact point.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamPointOut {
    /// `size_of::<SeamPointOut>()` as the host knows it; set by the host.
    pub struct_size: u32,
    /// One of the `SEAM_STATUS_*` values; the host sets it to `SEAM_STATUS_OK` before
    /// the call.
    pub status: i32,
    /// Conductance h, or flux q into side A with [`SEAM_CAP_RETURNS_FLUX`].
    pub value: f64,
    /// ∂value/∂T_A, ∂value/∂T_B, ∂value/∂gap, ∂value/∂pressure.
    pub d_temp_a: f64,
    pub d_temp_b: f64,
    pub d_gap: f64,
    pub d_pressure: f64,
    /// With [`SEAM_STATUS_CUTBACK`]: suggested ratio new/old step in (0, 1); 0 lets the
    /// host choose.
    pub cutback_factor: f64,
    /// NUL-terminated message, written with a non-OK status.
    pub message: [c_char; SEAM_MESSAGE_LEN],
}

/// `init`: create an instance from the enforcement's data. Returns a `SEAM_STATUS_*`;
/// on error writes a NUL-terminated message of at most [`SEAM_MESSAGE_LEN`] bytes.
pub type SeamInitFn = unsafe extern "C" fn(
    input: *const SeamInstanceIn,
    instance: *mut *mut c_void,
    message: *mut c_char,
) -> i32;
/// `finalize`: release an instance made by `init`.
pub type SeamFinalizeFn = unsafe extern "C" fn(instance: *mut c_void);
/// `evaluate_point`: one point.
pub type SeamEvaluatePointFn = unsafe extern "C" fn(
    instance: *mut c_void,
    input: *const SeamPointIn,
    output: *mut SeamPointOut,
);
/// `evaluate_batch`: `n` points, `input[i]` → `output[i]`.
pub type SeamEvaluateBatchFn = unsafe extern "C" fn(
    instance: *mut c_void,
    input: *const SeamPointIn,
    output: *mut SeamPointOut,
    n: usize,
);

/// What `seam_plugin_v1` returns: a static, immutable description of the model.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct SeamPluginDescriptor {
    /// [`SEAM_PLUGIN_ABI_MAJOR`] and [`SEAM_PLUGIN_ABI_MINOR`] the plugin was built with.
    pub abi_major: u32,
    pub abi_minor: u32,
    /// `size_of::<SeamPluginDescriptor>()` as the plugin knows it.
    pub struct_size: u32,
    /// Doubles of state per contact point (with [`SEAM_CAP_HAS_STATE`]), else 0.
    pub state_size: u32,
    /// Model name (what the deck's `Model = name` refers to), NUL-terminated.
    pub name: *const c_char,
    /// The model's own version string, NUL-terminated.
    pub model_version: *const c_char,
    /// `SEAM_CAP_*` flags.
    pub capabilities: u64,
    /// May be NULL: the instance pointer is then NULL.
    pub init: Option<SeamInitFn>,
    /// May be NULL.
    pub finalize: Option<SeamFinalizeFn>,
    /// Required.
    pub evaluate_point: Option<SeamEvaluatePointFn>,
    /// May be NULL: the host loops over `evaluate_point`.
    pub evaluate_batch: Option<SeamEvaluateBatchFn>,
}

// SAFETY: a descriptor is immutable once built and its pointers refer to static,
// immutable strings and to functions; sharing it between threads reads only.
unsafe impl Sync for SeamPluginDescriptor {}

/// The type of the entry symbol [`ENTRY_SYMBOL`].
pub type SeamEntryFn = unsafe extern "C" fn() -> *const SeamPluginDescriptor;

/// The entry symbol name of ABI major `major` (`seam_plugin_v<major>`), without NUL; the
/// host uses it to recognise plugins built for another major version.
pub fn entry_symbol_for(major: u32, buf: &mut [u8; 32]) -> &str {
    const PREFIX: &[u8] = b"seam_plugin_v";
    buf[..PREFIX.len()].copy_from_slice(PREFIX);
    let mut digits = [0u8; 10];
    let mut n = major;
    let mut len = 0;
    loop {
        digits[len] = b'0' + (n % 10) as u8;
        len += 1;
        n /= 10;
        if n == 0 {
            break;
        }
    }
    for i in 0..len {
        buf[PREFIX.len() + i] = digits[len - 1 - i];
    }
    core::str::from_utf8(&buf[..PREFIX.len() + len]).unwrap_or("seam_plugin_v?")
}

impl SeamPointOut {
    /// An output ready for a call: sizes set, status OK, everything else zero.
    pub const fn new() -> Self {
        Self {
            struct_size: core::mem::size_of::<Self>() as u32,
            status: SEAM_STATUS_OK,
            value: 0.0,
            d_temp_a: 0.0,
            d_temp_b: 0.0,
            d_gap: 0.0,
            d_pressure: 0.0,
            cutback_factor: 0.0,
            message: [0; SEAM_MESSAGE_LEN],
        }
    }
}

impl Default for SeamPointOut {
    fn default() -> Self {
        Self::new()
    }
}

impl SeamPointIn {
    /// A point with every number zero and every pointer NULL (lengths 0), sized.
    pub const fn new() -> Self {
        Self {
            struct_size: core::mem::size_of::<Self>() as u32,
            reserved: 0,
            gap: 0.0,
            pressure: 0.0,
            temp_a: 0.0,
            temp_b: 0.0,
            x: [0.0; 3],
            normal_a: [0.0; 3],
            normal_b: [0.0; 3],
            weight: 0.0,
            time: 0.0,
            dt: 0.0,
            step: 0,
            iteration: 0,
            surface_a: core::ptr::null(),
            surface_b: core::ptr::null(),
            fields: core::ptr::null(),
            n_fields: 0,
            integer_data: core::ptr::null(),
            n_integer: 0,
            real_data: core::ptr::null(),
            n_real: 0,
            state_old: core::ptr::null(),
            state_new: core::ptr::null_mut(),
            n_state: 0,
        }
    }
}

impl Default for SeamPointIn {
    fn default() -> Self {
        Self::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn entry_symbol_names_follow_the_major() {
        let mut buf = [0u8; 32];
        assert_eq!(entry_symbol_for(1, &mut buf), "seam_plugin_v1");
        assert_eq!(entry_symbol_for(12, &mut buf), "seam_plugin_v12");
        assert_eq!(&ENTRY_SYMBOL[..ENTRY_SYMBOL.len() - 1], b"seam_plugin_v1");
    }
}
