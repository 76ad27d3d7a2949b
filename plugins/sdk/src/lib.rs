//! Write a seam enforcement plugin in safe Rust.
//!
//! Implement [`EnforcementModel`] for a type and export it with [`export_plugin!`]; build
//! the crate as a `cdylib`. The macro generates the entry symbol `seam_plugin_v1`, a
//! static descriptor and `extern "C"` trampolines. Every trampoline runs the model inside
//! [`std::panic::catch_unwind`]: a panic becomes `SEAM_STATUS_ERROR` with the panic
//! message, and never unwinds into the host (which would abort it). Do not build plugins
//! with `panic = "abort"`: that turns every panic into a host crash.
//!
//! ```ignore
//! use seam_plugin_sdk::{EnforcementModel, InstanceData, ModelError, Output, PointIn, caps};
//!
//! struct Constant(f64);
//!
//! impl EnforcementModel for Constant {
//!     fn new(data: &InstanceData<'_>) -> Result<Self, ModelError> {
//!         let h = *data.real_data.first().ok_or_else(|| ModelError::new("Real Data: h"))?;
//!         Ok(Constant(h))
//!     }
//!     fn evaluate(&self, _p: &PointIn<'_>, _state: &mut [f64]) -> Result<Output, ModelError> {
//!         Ok(Output { value: self.0, ..Output::default() })
//!     }
//! }
//!
//! seam_plugin_sdk::export_plugin!(Constant, "constant", "1.0.0",
//!     caps::THREAD_SAFE | caps::PROVIDES_DERIVATIVES);
//! ```

use std::any::Any;
use std::ffi::{CStr, c_char, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

pub use seam_plugin_abi as abi;
use seam_plugin_abi::{
    SEAM_CAP_HAS_STATE, SEAM_MESSAGE_LEN, SEAM_PLUGIN_ABI_MAJOR, SEAM_PLUGIN_ABI_MINOR,
    SEAM_STATUS_CUTBACK, SEAM_STATUS_ERROR, SEAM_STATUS_OK, SeamInstanceIn, SeamPluginDescriptor,
    SeamPointIn, SeamPointOut,
};

/// Capability flags for [`export_plugin!`]; `HAS_STATE` is added by the macro when
/// [`EnforcementModel::STATE_SIZE`] is not zero.
pub mod caps {
    pub use seam_plugin_abi::SEAM_CAP_PROVIDES_DERIVATIVES as PROVIDES_DERIVATIVES;
    pub use seam_plugin_abi::SEAM_CAP_RETURNS_FLUX as RETURNS_FLUX;
    pub use seam_plugin_abi::SEAM_CAP_THREAD_SAFE as THREAD_SAFE;
}

/// The enforcement's data, given once when the host creates the instance.
#[derive(Clone, Copy, Debug)]
pub struct InstanceData<'a> {
    /// The deck's `Model = name`.
    pub model: &'a str,
    pub integer_data: &'a [i64],
    pub real_data: &'a [f64],
}

/// One contact point, as safe views of the host's [`SeamPointIn`].
#[derive(Clone, Copy, Debug)]
pub struct PointIn<'a> {
    pub gap: f64,
    pub pressure: f64,
    pub temp_a: f64,
    pub temp_b: f64,
    pub x: [f64; 3],
    pub normal_a: [f64; 3],
    pub normal_b: [f64; 3],
    pub weight: f64,
    pub time: f64,
    pub dt: f64,
    pub step: i64,
    pub iteration: i64,
    /// Surface names; empty if the host passed none or they are not UTF-8.
    pub surface_a: &'a str,
    pub surface_b: &'a str,
    pub fields: &'a [f64],
    pub integer_data: &'a [i64],
    pub real_data: &'a [f64],
    /// State of the last accepted step; the new state is the `state` argument of
    /// [`EnforcementModel::evaluate`], which starts as a copy of this.
    pub state_old: &'a [f64],
}

/// Value (conductance or flux) and its derivatives.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Output {
    pub value: f64,
    pub d_temp_a: f64,
    pub d_temp_b: f64,
    pub d_gap: f64,
    pub d_pressure: f64,
}

/// Why a point could not be evaluated.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelError {
    /// The host stops with this message.
    Error(String),
    /// Ask the host for a smaller step; `factor` is the suggested new/old step ratio in
    /// (0, 1), or 0 to let the host choose.
    Cutback { factor: f64, reason: String },
}

impl ModelError {
    pub fn new(message: impl Into<String>) -> Self {
        ModelError::Error(message.into())
    }
    pub fn cutback(factor: f64, reason: impl Into<String>) -> Self {
        ModelError::Cutback {
            factor,
            reason: reason.into(),
        }
    }
}

/// A user enforcement model. One value per enforcement in the deck; `evaluate` takes
/// `&self`, so a model that declares `THREAD_SAFE` may be called from several threads.
pub trait EnforcementModel: Sized + Send + Sync + 'static {
    /// Doubles of state per contact point.
    const STATE_SIZE: u32 = 0;
    /// Build the model from the enforcement's `Integer Data` / `Real Data`; an error here
    /// is reported by the host at set-up, before any point is evaluated.
    fn new(data: &InstanceData<'_>) -> Result<Self, ModelError>;
    /// Evaluate one point; `state` (length `STATE_SIZE`) is the new state, a copy of
    /// `p.state_old` on entry.
    fn evaluate(&self, p: &PointIn<'_>, state: &mut [f64]) -> Result<Output, ModelError>;
}

/// Build the descriptor for `T`; used by [`export_plugin!`].
#[doc(hidden)]
pub const fn descriptor<T: EnforcementModel>(
    name: &'static CStr,
    version: &'static CStr,
    capabilities: u64,
) -> SeamPluginDescriptor {
    let state = if T::STATE_SIZE > 0 {
        SEAM_CAP_HAS_STATE
    } else {
        0
    };
    SeamPluginDescriptor {
        abi_major: SEAM_PLUGIN_ABI_MAJOR,
        abi_minor: SEAM_PLUGIN_ABI_MINOR,
        struct_size: size_of::<SeamPluginDescriptor>() as u32,
        state_size: T::STATE_SIZE,
        name: name.as_ptr(),
        model_version: version.as_ptr(),
        capabilities: capabilities | state,
        init: Some(init::<T>),
        finalize: Some(finalize::<T>),
        evaluate_point: Some(evaluate_point::<T>),
        evaluate_batch: Some(evaluate_batch::<T>),
    }
}

/// Export `$ty` as the plugin's model: `export_plugin!(Type, "name", "version", caps)`.
#[macro_export]
macro_rules! export_plugin {
    ($ty:ty, $name:literal, $version:literal, $caps:expr $(,)?) => {
        /// The seam plugin entry point (ABI major 1).
        #[unsafe(no_mangle)]
        pub extern "C" fn seam_plugin_v1() -> *const $crate::abi::SeamPluginDescriptor {
            static DESCRIPTOR: $crate::abi::SeamPluginDescriptor = $crate::descriptor::<$ty>(
                match ::std::ffi::CStr::from_bytes_with_nul(concat!($name, "\0").as_bytes()) {
                    Ok(s) => s,
                    Err(_) => panic!("plugin name contains a NUL byte"),
                },
                match ::std::ffi::CStr::from_bytes_with_nul(concat!($version, "\0").as_bytes()) {
                    Ok(s) => s,
                    Err(_) => panic!("plugin version contains a NUL byte"),
                },
                $caps,
            );
            &DESCRIPTOR
        }
    };
}

/// The text of a panic payload.
fn panic_text(payload: &(dyn Any + Send)) -> &str {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s
    } else {
        "panic with a non-string payload"
    }
}

/// Copy `text` into a C message buffer of [`SEAM_MESSAGE_LEN`] bytes, truncated on a
/// character boundary and NUL-terminated.
fn write_message(buf: &mut [c_char], text: &str) {
    let room = buf.len().min(SEAM_MESSAGE_LEN).saturating_sub(1);
    let mut end = text.len().min(room);
    while !text.is_char_boundary(end) {
        end -= 1;
    }
    for (dst, &b) in buf.iter_mut().zip(&text.as_bytes()[..end]) {
        *dst = b as c_char;
    }
    if let Some(nul) = buf.get_mut(end) {
        *nul = 0;
    }
}

/// A slice from a pointer and a length; NULL or 0 gives the empty slice.
///
/// # Safety
/// Unless NULL, `ptr` must point to `len` initialised values that stay valid and
/// unmodified for `'a`.
unsafe fn view<'a, T>(ptr: *const T, len: usize) -> &'a [T] {
    if ptr.is_null() || len == 0 {
        &[]
    } else {
        // SAFETY: non-NULL and `len` valid values, by the caller's contract.
        unsafe { std::slice::from_raw_parts(ptr, len) }
    }
}

/// A string from a C string pointer; NULL or invalid UTF-8 gives "".
///
/// # Safety
/// Unless NULL, `ptr` must be a NUL-terminated string valid for `'a`.
unsafe fn text<'a>(ptr: *const c_char) -> &'a str {
    if ptr.is_null() {
        return "";
    }
    // SAFETY: NUL-terminated and valid for 'a, by the caller's contract.
    unsafe { CStr::from_ptr(ptr) }.to_str().unwrap_or("")
}

#[doc(hidden)]
/// # Safety
/// Called by the host per the ABI: `input` valid, `instance` and `message` writable.
pub unsafe extern "C" fn init<T: EnforcementModel>(
    input: *const SeamInstanceIn,
    instance: *mut *mut c_void,
    message: *mut c_char,
) -> i32 {
    let result = catch_unwind(AssertUnwindSafe(|| {
        if input.is_null() {
            return Err(ModelError::new("init called without instance data"));
        }
        // SAFETY: the host passes a valid SeamInstanceIn for the duration of the call.
        let raw = unsafe { &*input };
        // SAFETY: the arrays and the model name are valid during the call (ABI rule).
        let data = unsafe {
            InstanceData {
                model: text(raw.model),
                integer_data: view(raw.integer_data, raw.n_integer),
                real_data: view(raw.real_data, raw.n_real),
            }
        };
        T::new(&data)
    }));
    let outcome = match result {
        Ok(Ok(model)) => {
            let boxed = Box::into_raw(Box::new(model));
            // SAFETY: the host passes a writable pointer for the instance.
            unsafe { *instance = boxed.cast() };
            return SEAM_STATUS_OK;
        }
        Ok(Err(ModelError::Error(m))) => m,
        Ok(Err(ModelError::Cutback { reason, .. })) => {
            format!("cutback requested at set-up: {reason}")
        }
        Err(payload) => format!("panic in init: {}", panic_text(&*payload)),
    };
    if !message.is_null() {
        // SAFETY: the host passes a buffer of SEAM_MESSAGE_LEN bytes.
        let buf = unsafe { std::slice::from_raw_parts_mut(message, SEAM_MESSAGE_LEN) };
        write_message(buf, &outcome);
    }
    SEAM_STATUS_ERROR
}

#[doc(hidden)]
/// # Safety
/// `instance` is NULL or was made by `init::<T>` and is not used afterwards.
pub unsafe extern "C" fn finalize<T: EnforcementModel>(instance: *mut c_void) {
    if instance.is_null() {
        return;
    }
    // A panicking Drop is swallowed: there is nobody to report it to.
    let _ = catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: made by Box::into_raw in init::<T>, released exactly once here.
        drop(unsafe { Box::from_raw(instance.cast::<T>()) });
    }));
}

/// Evaluate one point and fill `out`; never unwinds.
///
/// # Safety
/// `instance` made by `init::<T>`; `input` valid per the ABI.
unsafe fn evaluate_one<T: EnforcementModel>(
    instance: *mut c_void,
    input: &SeamPointIn,
    out: &mut SeamPointOut,
) {
    let result = catch_unwind(AssertUnwindSafe(|| {
        if instance.is_null() {
            return Err(ModelError::new(
                "evaluate called without an instance (init failed?)",
            ));
        }
        // SAFETY: a live instance made by init::<T>; only shared access here.
        let model = unsafe { &*instance.cast::<T>() };
        // SAFETY: every pointer in `input` is valid for its length during the call (ABI).
        let (p, state) = unsafe {
            let state: &mut [f64] = if input.state_new.is_null() || input.n_state == 0 {
                &mut []
            } else {
                std::slice::from_raw_parts_mut(input.state_new, input.n_state)
            };
            let p = PointIn {
                gap: input.gap,
                pressure: input.pressure,
                temp_a: input.temp_a,
                temp_b: input.temp_b,
                x: input.x,
                normal_a: input.normal_a,
                normal_b: input.normal_b,
                weight: input.weight,
                time: input.time,
                dt: input.dt,
                step: input.step,
                iteration: input.iteration,
                surface_a: text(input.surface_a),
                surface_b: text(input.surface_b),
                fields: view(input.fields, input.n_fields),
                integer_data: view(input.integer_data, input.n_integer),
                real_data: view(input.real_data, input.n_real),
                state_old: view(input.state_old, input.n_state),
            };
            (p, state)
        };
        model.evaluate(&p, state)
    }));
    match result {
        Ok(Ok(o)) => {
            out.status = SEAM_STATUS_OK;
            out.value = o.value;
            out.d_temp_a = o.d_temp_a;
            out.d_temp_b = o.d_temp_b;
            out.d_gap = o.d_gap;
            out.d_pressure = o.d_pressure;
        }
        Ok(Err(ModelError::Error(m))) => {
            out.status = SEAM_STATUS_ERROR;
            write_message(&mut out.message, &m);
        }
        Ok(Err(ModelError::Cutback { factor, reason })) => {
            out.status = SEAM_STATUS_CUTBACK;
            out.cutback_factor = factor;
            write_message(&mut out.message, &reason);
        }
        Err(payload) => {
            out.status = SEAM_STATUS_ERROR;
            write_message(
                &mut out.message,
                &format!("panic: {}", panic_text(&*payload)),
            );
        }
    }
}

#[doc(hidden)]
/// # Safety
/// Called by the host per the ABI.
pub unsafe extern "C" fn evaluate_point<T: EnforcementModel>(
    instance: *mut c_void,
    input: *const SeamPointIn,
    output: *mut SeamPointOut,
) {
    if input.is_null() || output.is_null() {
        return;
    }
    // SAFETY: non-NULL, valid and exclusive for the call (ABI); evaluate_one never unwinds.
    unsafe { evaluate_one::<T>(instance, &*input, &mut *output) }
}

#[doc(hidden)]
/// # Safety
/// Called by the host per the ABI: `n` inputs and outputs.
pub unsafe extern "C" fn evaluate_batch<T: EnforcementModel>(
    instance: *mut c_void,
    input: *const SeamPointIn,
    output: *mut SeamPointOut,
    n: usize,
) {
    if input.is_null() || output.is_null() || n == 0 {
        return;
    }
    // SAFETY: the host passes n valid inputs and n writable, non-overlapping outputs.
    let (inputs, outputs) = unsafe {
        (
            std::slice::from_raw_parts(input, n),
            std::slice::from_raw_parts_mut(output, n),
        )
    };
    for (i, o) in inputs.iter().zip(outputs) {
        // SAFETY: as above, point by point.
        unsafe { evaluate_one::<T>(instance, i, o) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_truncated_on_a_char_boundary_and_terminated() {
        let mut buf = [1 as c_char; SEAM_MESSAGE_LEN];
        let long = "é".repeat(200); // 400 bytes
        write_message(&mut buf, &long);
        // SAFETY: write_message always NUL-terminates inside the buffer.
        let s = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
        assert_eq!(s.len(), 254, "127 two-byte characters fit in 255 bytes");
        write_message(&mut buf, "short");
        // SAFETY: as above.
        let s = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
        assert_eq!(s, "short");
    }

    /// Counts calls in its state, errors at gap < 0, asks for a cutback at gap > 1 and
    /// panics at gap > 2.
    struct Probe;

    impl EnforcementModel for Probe {
        const STATE_SIZE: u32 = 1;
        fn new(data: &InstanceData<'_>) -> Result<Self, ModelError> {
            if data.real_data.is_empty() {
                return Err(ModelError::new("need one real"));
            }
            Ok(Probe)
        }
        fn evaluate(&self, p: &PointIn<'_>, state: &mut [f64]) -> Result<Output, ModelError> {
            state[0] = p.state_old[0] + 1.0;
            if p.gap > 2.0 {
                panic!("boom {}", p.surface_a);
            } else if p.gap > 1.0 {
                return Err(ModelError::cutback(0.5, "too far"));
            } else if p.gap < 0.0 {
                return Err(ModelError::new("negative gap"));
            }
            Ok(Output {
                value: p.real_data[0],
                ..Output::default()
            })
        }
    }

    fn message(out: &SeamPointOut) -> String {
        // SAFETY: the trampolines always NUL-terminate the message they write, and
        // SeamPointOut::new() starts all-zero.
        unsafe { CStr::from_ptr(out.message.as_ptr()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn trampolines_map_results_errors_cutbacks_and_panics_to_statuses() {
        let d = descriptor::<Probe>(c"probe", c"1", caps::THREAD_SAFE);
        assert_eq!(d.state_size, 1);
        assert_eq!(d.capabilities, caps::THREAD_SAFE | SEAM_CAP_HAS_STATE);
        let real = [4.5];
        let mut instance = std::ptr::null_mut();
        let mut msg = [0 as c_char; SEAM_MESSAGE_LEN];
        let bad = SeamInstanceIn {
            struct_size: size_of::<SeamInstanceIn>() as u32,
            reserved: 0,
            model: c"probe".as_ptr(),
            integer_data: std::ptr::null(),
            n_integer: 0,
            real_data: std::ptr::null(),
            n_real: 0,
        };
        // SAFETY: valid input, slot and 256-byte buffer.
        let status = unsafe { d.init.unwrap()(&bad, &mut instance, msg.as_mut_ptr()) };
        assert_eq!(status, SEAM_STATUS_ERROR);
        // SAFETY: NUL-terminated by init.
        assert_eq!(
            unsafe { CStr::from_ptr(msg.as_ptr()) }.to_str().unwrap(),
            "need one real"
        );
        let good = SeamInstanceIn {
            real_data: real.as_ptr(),
            n_real: 1,
            ..bad
        };
        // SAFETY: as above.
        let status = unsafe { d.init.unwrap()(&good, &mut instance, msg.as_mut_ptr()) };
        assert_eq!(status, SEAM_STATUS_OK);
        let old = [[2.0], [0.0], [0.0], [0.0]];
        let mut new = [[0.0]; 4];
        let gaps = [0.5, 1.5, -1.0, 3.0];
        let ins: Vec<SeamPointIn> = (0..4)
            .map(|i| {
                let mut p = SeamPointIn::new();
                p.gap = gaps[i];
                p.surface_a = c"top".as_ptr();
                p.real_data = real.as_ptr();
                p.n_real = 1;
                p.state_old = old[i].as_ptr();
                p.state_new = new[i].as_mut_ptr();
                p.n_state = 1;
                p
            })
            .collect();
        let mut outs = vec![SeamPointOut::new(); 4];
        // SAFETY: 4 valid inputs (their arrays outlive the call) and 4 outputs.
        unsafe { d.evaluate_batch.unwrap()(instance, ins.as_ptr(), outs.as_mut_ptr(), 4) };
        assert_eq!((outs[0].status, outs[0].value), (SEAM_STATUS_OK, 4.5));
        assert_eq!(new[0], [3.0], "state_new = state_old + 1");
        assert_eq!(
            (outs[1].status, outs[1].cutback_factor),
            (SEAM_STATUS_CUTBACK, 0.5)
        );
        assert_eq!(message(&outs[1]), "too far");
        assert_eq!(
            (outs[2].status, message(&outs[2]).as_str()),
            (SEAM_STATUS_ERROR, "negative gap")
        );
        assert_eq!(
            (outs[3].status, message(&outs[3]).as_str()),
            (SEAM_STATUS_ERROR, "panic: boom top")
        );
        // SAFETY: the instance from init, released once.
        unsafe { d.finalize.unwrap()(instance) };
    }
}
