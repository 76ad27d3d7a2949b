//! Loading, instantiating and calling a plugin; validating what it returns.

use std::ffi::{CStr, CString, c_char, c_void};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};

use seam_plugin_abi::{
    ENTRY_SYMBOL, SEAM_CAP_ALL, SEAM_CAP_HAS_STATE, SEAM_CAP_PROVIDES_DERIVATIVES,
    SEAM_CAP_RETURNS_FLUX, SEAM_CAP_THREAD_SAFE, SEAM_MESSAGE_LEN, SEAM_PLUGIN_ABI_MAJOR,
    SEAM_PLUGIN_ABI_MINOR, SEAM_STATUS_CUTBACK, SEAM_STATUS_ERROR, SEAM_STATUS_OK, SeamEntryFn,
    SeamInstanceIn, SeamPluginDescriptor, SeamPointIn, SeamPointOut, entry_symbol_for,
};

use std::cell::Cell;

use seam_plugin_testkit::{Config, Loaded, Report};

use super::guard::{CallSite, guarded};
use super::isolate::Worker;
use super::{Isolation, PluginError, PluginFault};

/// Finite-difference step floors for plugins without derivatives: the host perturbs x
/// by δ = ε^{1/3} max(|x|, floor) and takes central differences (truncation O(δ²),
/// round-off O(ε/δ), both near 1e-10 relative for smooth models). Units are the deck's.
pub const FD_FLOOR_TEMPERATURE: f64 = 1.0;
pub const FD_FLOOR_PRESSURE: f64 = 1.0;
pub const FD_FLOOR_GAP: f64 = 1e-9;

/// Points per plugin call: bounds the host's scratch memory (a `SeamPointOut` is 312
/// bytes) while keeping per-call overhead negligible.
const CHUNK: usize = 256;

/// An output before the call.
const RESET: SeamPointOut = SeamPointOut::new();

/// Libraries loaded so far, by canonical path. Never unloaded: function pointers copied
/// out of a library, thread-locals and plugin threads all outlive any safe unload point.
static LIBRARIES: Mutex<Vec<(PathBuf, &'static libloading::Library)>> = Mutex::new(Vec::new());

fn library(path: &Path) -> Result<&'static libloading::Library, PluginError> {
    let canonical = path.canonicalize().map_err(|_| PluginError::NotFound {
        path: path.to_owned(),
    })?;
    let mut libs = LIBRARIES.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((_, lib)) = libs.iter().find(|(p, _)| *p == canonical) {
        return Ok(lib);
    }
    // SAFETY: loading runs the library's initialisers; running the user's code is the
    // purpose of a plugin, and the user named the file.
    let lib =
        unsafe { libloading::Library::new(&canonical) }.map_err(|e| PluginError::NotLibrary {
            path: path.to_owned(),
            reason: e.to_string(),
        })?;
    let lib: &'static libloading::Library = Box::leak(Box::new(lib));
    libs.push((canonical, lib));
    Ok(lib)
}

/// What the deck gives a plugin instance.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PluginData {
    /// The deck's `Model = name`; checked against the plugin's name (case-insensitive).
    pub model: Option<String>,
    pub integer_data: Vec<i64>,
    pub real_data: Vec<f64>,
}

/// The descriptor, read once at load.
#[derive(Clone, Debug, PartialEq)]
pub struct PluginInfo {
    pub path: PathBuf,
    pub name: String,
    pub model_version: String,
    pub abi_major: u32,
    pub abi_minor: u32,
    pub capabilities: u64,
    /// Doubles of state per contact point.
    pub state_size: usize,
    pub has_batch: bool,
}

impl PluginInfo {
    pub fn thread_safe(&self) -> bool {
        self.capabilities & SEAM_CAP_THREAD_SAFE != 0
    }
    pub fn provides_derivatives(&self) -> bool {
        self.capabilities & SEAM_CAP_PROVIDES_DERIVATIVES != 0
    }
    pub fn returns_flux(&self) -> bool {
        self.capabilities & SEAM_CAP_RETURNS_FLUX != 0
    }
    /// The capability names, e.g. `THREAD_SAFE | PROVIDES_DERIVATIVES`.
    pub fn capability_names(&self) -> String {
        let names = [
            (SEAM_CAP_THREAD_SAFE, "THREAD_SAFE"),
            (SEAM_CAP_PROVIDES_DERIVATIVES, "PROVIDES_DERIVATIVES"),
            (SEAM_CAP_RETURNS_FLUX, "RETURNS_FLUX"),
            (SEAM_CAP_HAS_STATE, "HAS_STATE"),
        ];
        let mut out: Vec<&str> = names
            .iter()
            .filter(|(bit, _)| self.capabilities & bit != 0)
            .map(|(_, n)| *n)
            .collect();
        if !self.returns_flux() {
            out.push("(returns conductance)");
        }
        out.join(" | ")
    }
}

/// One contact point as the host knows it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPoint {
    pub gap: f64,
    pub pressure: f64,
    pub temp_a: f64,
    pub temp_b: f64,
    pub x: [f64; 3],
    pub normal_a: [f64; 3],
    pub normal_b: [f64; 3],
    pub weight: f64,
}

/// What is shared by the points of one call: the interaction, the step, other fields.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepContext<'a> {
    pub surface_a: &'a str,
    pub surface_b: &'a str,
    pub time: f64,
    pub dt: f64,
    pub step: i64,
    pub iteration: i64,
    /// Other fields' values, `n_fields` per point, point after point.
    pub fields: &'a [f64],
    pub n_fields: usize,
}

/// The value (conductance or flux) and its derivatives at one point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointResult {
    pub value: f64,
    pub d_temp_a: f64,
    pub d_temp_b: f64,
    pub d_gap: f64,
    pub d_pressure: f64,
}

/// Per-point plugin state: `old` is the last accepted step, `new` the step being solved.
/// Each evaluation starts `new` from `old`; [`StateStore::commit`] keeps `new` when the
/// step is accepted, a rejected step simply is not committed.
#[derive(Clone, Debug, PartialEq)]
pub struct StateStore {
    size: usize,
    old: Vec<f64>,
    new: Vec<f64>,
}

impl StateStore {
    /// `points` points of `size` doubles each, all zero.
    pub fn new(points: usize, size: usize) -> Self {
        StateStore {
            size,
            old: vec![0.0; points * size],
            new: vec![0.0; points * size],
        }
    }
    pub fn size(&self) -> usize {
        self.size
    }
    pub fn points(&self) -> usize {
        self.old.len().checked_div(self.size).unwrap_or(0)
    }
    /// The accepted state of point `i`.
    pub fn old(&self, i: usize) -> &[f64] {
        &self.old[i * self.size..(i + 1) * self.size]
    }
    /// The state of point `i` at the end of the step being solved.
    pub fn new_state(&self, i: usize) -> &[f64] {
        &self.new[i * self.size..(i + 1) * self.size]
    }
    /// The step was accepted: the new state becomes the old one.
    pub fn commit(&mut self) {
        self.old.copy_from_slice(&self.new);
    }
}

/// A loaded plugin with one instance of its model, in this process or in a worker
/// process ([`Isolation::Process`]).
pub struct Plugin {
    info: PluginInfo,
    /// `name (path)`, for fault messages.
    label: String,
    backend: Backend,
    data: PluginData,
    fd_notice_given: AtomicBool,
}

/// Where the instance lives.
enum Backend {
    InProcess {
        descriptor: &'static SeamPluginDescriptor,
        instance: *mut c_void,
        /// Held around every call unless the plugin is THREAD_SAFE.
        serial: Mutex<()>,
    },
    /// In a worker process; one call at a time.
    Process(Box<Mutex<Worker>>),
}

// SAFETY: the instance pointer is only used through the plugin's functions; calls are
// serialised by `serial` unless the plugin declares THREAD_SAFE, in which case the ABI
// lets any thread call at any time. The descriptor is static and immutable.
unsafe impl Send for Plugin {}
// SAFETY: as above.
unsafe impl Sync for Plugin {}

impl std::fmt::Debug for Plugin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Plugin")
            .field("info", &self.info)
            .finish_non_exhaustive()
    }
}

impl Drop for Plugin {
    fn drop(&mut self) {
        // A worker finalises its instance when its input ends (`Worker`'s drop).
        let finalize = match &self.backend {
            Backend::InProcess {
                descriptor,
                instance,
                ..
            } => descriptor.finalize.map(|f| (f, *instance)),
            Backend::Process(_) => None,
        };
        if let Some((finalize, instance)) = finalize {
            // SAFETY: the instance came from this descriptor's init and is released once;
            // the library is never unloaded.
            unsafe { finalize(instance) };
        }
    }
}

/// # Safety
/// `p` NULL or a NUL-terminated string valid for the call.
unsafe fn c_text(p: *const c_char) -> Option<String> {
    if p.is_null() {
        return None;
    }
    // SAFETY: by the caller's contract.
    unsafe { CStr::from_ptr(p) }
        .to_str()
        .ok()
        .map(str::to_owned)
}

fn message_text(buf: &[c_char; SEAM_MESSAGE_LEN]) -> String {
    let bytes: Vec<u8> = buf
        .iter()
        .take_while(|&&c| c != 0)
        .map(|&c| c as u8)
        .collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

impl Plugin {
    /// Load with no `Integer Data` / `Real Data` and no model name check.
    pub fn load(path: &Path) -> Result<Plugin, PluginError> {
        Plugin::load_with(path, &PluginData::default())
    }

    /// Load the library (once per process) and create an instance with `data`.
    pub fn load_with(path: &Path, data: &PluginData) -> Result<Plugin, PluginError> {
        if !path.exists() {
            return Err(PluginError::NotFound {
                path: path.to_owned(),
            });
        }
        let lib = library(path)?;
        let symbol = "seam_plugin_v1";
        // SAFETY: a seam plugin exports `seam_plugin_v1` with type SeamEntryFn; the
        // copied function pointer stays valid because the library is never unloaded.
        let entry: Option<SeamEntryFn> = unsafe { lib.get::<SeamEntryFn>(ENTRY_SYMBOL) }
            .ok()
            .map(|s| *s);
        let Some(entry) = entry else {
            return Err(other_major(lib, path).unwrap_or(PluginError::NoEntry {
                path: path.to_owned(),
                symbol,
                host_major: SEAM_PLUGIN_ABI_MAJOR,
            }));
        };
        let plugin = format!("{}", path.display());
        let site = CallSite {
            plugin: &plugin,
            entry: symbol,
            points: &[],
            current: Cell::new(None),
        };
        // SAFETY: the entry function takes nothing and returns a pointer to static data.
        let d = guarded(&site, || unsafe { entry() });
        if d.is_null() {
            return Err(PluginError::NullDescriptor {
                path: path.to_owned(),
                symbol,
            });
        }
        // SAFETY: every descriptor version starts with abi_major, abi_minor, struct_size;
        // read those before trusting struct_size for the rest of the struct.
        let (major, minor, size) = unsafe {
            (
                std::ptr::addr_of!((*d).abi_major).read(),
                std::ptr::addr_of!((*d).abi_minor).read(),
                std::ptr::addr_of!((*d).struct_size).read(),
            )
        };
        check_versions(path, major, minor, size)?;
        // SAFETY: struct_size covers the whole v1 descriptor; it is static and immutable.
        let d: &'static SeamPluginDescriptor = unsafe { &*d };
        // SAFETY: descriptor strings are static and NUL-terminated (ABI rule).
        let name = unsafe { c_text(d.name) }.ok_or_else(|| PluginError::BadDescriptor {
            path: path.to_owned(),
            reason: "`name` is NULL or not UTF-8".into(),
        })?;
        // SAFETY: as above.
        let model_version = unsafe { c_text(d.model_version) }.unwrap_or_default();
        if d.evaluate_point.is_none() {
            return Err(PluginError::NullFunction {
                path: path.to_owned(),
                field: "evaluate_point",
            });
        }
        if d.capabilities & !SEAM_CAP_ALL != 0 {
            return Err(PluginError::BadDescriptor {
                path: path.to_owned(),
                reason: format!(
                    "unknown capability bits {:#x}",
                    d.capabilities & !SEAM_CAP_ALL
                ),
            });
        }
        if (d.capabilities & SEAM_CAP_HAS_STATE != 0) != (d.state_size > 0) {
            return Err(PluginError::BadDescriptor {
                path: path.to_owned(),
                reason: format!(
                    "HAS_STATE and state_size disagree (state_size {})",
                    d.state_size
                ),
            });
        }
        // (No let-chain: the crate promises Rust 1.85.)
        if let Some(asked) = data
            .model
            .as_ref()
            .filter(|a| !a.eq_ignore_ascii_case(&name))
        {
            return Err(PluginError::ModelMismatch {
                path: path.to_owned(),
                provided: name,
                asked: asked.clone(),
            });
        }
        let info = PluginInfo {
            path: path.to_owned(),
            name,
            model_version,
            abi_major: major,
            abi_minor: minor,
            capabilities: d.capabilities,
            state_size: d.state_size as usize,
            has_batch: d.evaluate_batch.is_some(),
        };
        let instance = instantiate(d, &info, data)?;
        Ok(Plugin {
            label: format!("`{}` ({})", info.name, path.display()),
            info,
            backend: Backend::InProcess {
                descriptor: d,
                instance,
                serial: Mutex::new(()),
            },
            data: data.clone(),
            fd_notice_given: AtomicBool::new(false),
        })
    }

    /// Load in this process ([`Isolation::None`], as [`Plugin::load_with`]) or in a
    /// worker process ([`Isolation::Process`], as [`Plugin::load_isolated`]).
    pub fn load_with_isolation(
        path: &Path,
        data: &PluginData,
        isolation: Isolation,
    ) -> Result<Plugin, PluginError> {
        match isolation {
            Isolation::None => Plugin::load_with(path, data),
            Isolation::Process => Plugin::load_isolated(path, data),
        }
    }

    /// Start a worker process (see [`super::isolate`]) that loads the library and creates
    /// the instance with `data`; this process never maps the library. Load errors are
    /// those of [`Plugin::load_with`], word for word; a worker that cannot be found or
    /// dies while loading is a [`PluginError::Worker`] / [`PluginError::NoWorker`].
    pub fn load_isolated(path: &Path, data: &PluginData) -> Result<Plugin, PluginError> {
        if !path.exists() {
            return Err(PluginError::NotFound {
                path: path.to_owned(),
            });
        }
        let (worker, info) = Worker::start(path, data)?;
        Ok(Plugin {
            label: format!("`{}` ({})", info.name, path.display()),
            info,
            backend: Backend::Process(Box::new(Mutex::new(worker))),
            data: data.clone(),
            fd_notice_given: AtomicBool::new(false),
        })
    }

    pub fn info(&self) -> &PluginInfo {
        &self.info
    }

    /// How this plugin runs.
    pub fn isolation(&self) -> Isolation {
        match self.backend {
            Backend::InProcess { .. } => Isolation::None,
            Backend::Process(_) => Isolation::Process,
        }
    }

    /// The plugin's static descriptor (valid for the life of the process); `None` for an
    /// isolated plugin, whose library is mapped in the worker only.
    pub fn descriptor(&self) -> Option<&'static SeamPluginDescriptor> {
        match self.backend {
            Backend::InProcess { descriptor, .. } => Some(descriptor),
            Backend::Process(_) => None,
        }
    }

    /// Run the conformance kit on this plugin (in its worker when isolated). A crash
    /// during the kit is a [`PluginFault::ProcessDied`] when isolated; in process it ends
    /// the process with the guard's report.
    pub fn conformance(&self, config: &Config) -> Result<Report, PluginFault> {
        match &self.backend {
            Backend::InProcess { .. } => Ok(self.conformance_in_process(config)),
            Backend::Process(worker) => worker
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .conformance(config)
                .map_err(|d| PluginFault::ProcessDied {
                    plugin: self.label.clone(),
                    entry: "the conformance checks",
                    interaction: None,
                    points: 0..0,
                    how: d.how,
                }),
        }
    }

    pub(super) fn conformance_in_process(&self, config: &Config) -> Report {
        let Some(descriptor) = self.descriptor() else {
            return Report::default();
        };
        // SAFETY: the descriptor comes from a library seam never unloads, and `load_with`
        // checked its versions, size and evaluate_point.
        let loaded = unsafe { Loaded::from_descriptor(descriptor) };
        // The conformance kit calls the plugin itself: a crash or an `exit` there is
        // reported like one in the host's own calls.
        let site = CallSite {
            plugin: &self.label,
            entry: "the conformance checks",
            points: &[],
            current: Cell::new(None),
        };
        guarded(&site, || seam_plugin_testkit::run(&loaded, config))
    }

    /// True when seam forms the derivatives by finite differences (the plugin does not
    /// provide them).
    pub fn uses_finite_differences(&self) -> bool {
        !self.info.provides_derivatives()
    }

    /// A line to log, returned once per plugin, when seam forms the derivatives itself.
    pub fn derivative_notice(&self) -> Option<String> {
        if self.uses_finite_differences() && !self.fd_notice_given.swap(true, Ordering::Relaxed) {
            Some(format!(
                "plugin {} does not provide derivatives: seam forms them by central finite differences (5 calls per point)",
                self.label
            ))
        } else {
            None
        }
    }

    /// Evaluate `points`, writing `results`; `states` (one per point, `state_size`
    /// doubles each) is required only if the plugin has state, else a scratch state is
    /// used and discarded.
    pub fn evaluate(
        &self,
        ctx: &StepContext<'_>,
        points: &[ContactPoint],
        results: &mut [PointResult],
        states: Option<&mut StateStore>,
    ) -> Result<(), PluginFault> {
        self.evaluate_mode(ctx, points, results, states, true)
    }

    /// As [`Plugin::evaluate`], but always through `evaluate_point`, even if the plugin
    /// has a batch entry (for tests and benchmarks).
    pub fn evaluate_per_point(
        &self,
        ctx: &StepContext<'_>,
        points: &[ContactPoint],
        results: &mut [PointResult],
        states: Option<&mut StateStore>,
    ) -> Result<(), PluginFault> {
        self.evaluate_mode(ctx, points, results, states, false)
    }

    fn usage(&self, message: String) -> PluginFault {
        PluginFault::Usage {
            plugin: self.label.clone(),
            message,
        }
    }

    fn evaluate_mode(
        &self,
        ctx: &StepContext<'_>,
        points: &[ContactPoint],
        results: &mut [PointResult],
        states: Option<&mut StateStore>,
        batch: bool,
    ) -> Result<(), PluginFault> {
        let n = points.len();
        if results.len() != n {
            return Err(self.usage(format!("{n} points but {} results", results.len())));
        }
        if ctx.fields.len() != ctx.n_fields * n {
            return Err(self.usage(format!(
                "{} field values for {n} points of {} fields",
                ctx.fields.len(),
                ctx.n_fields
            )));
        }
        let ns = self.info.state_size;
        let mut scratch;
        let states = match states {
            Some(s) => {
                if s.size() != ns || s.points() != n && ns > 0 {
                    return Err(self.usage(format!(
                        "state store has {} points of {} doubles, the call {n} points of {ns}",
                        s.points(),
                        s.size()
                    )));
                }
                s
            }
            None => {
                scratch = StateStore::new(n, ns);
                &mut scratch
            }
        };
        states.new.copy_from_slice(&states.old);
        let surface_a = CString::new(ctx.surface_a.replace('\0', " ")).unwrap_or_default();
        let surface_b = CString::new(ctx.surface_b.replace('\0', " ")).unwrap_or_default();
        let conductance = !self.info.returns_flux();
        let fd = self.uses_finite_differences();
        let mut ins: Vec<SeamPointIn> = Vec::with_capacity(CHUNK);
        let mut outs: Vec<SeamPointOut> = Vec::with_capacity(CHUNK);
        // Every point of a call gets its own copy of the data: a plugin's writes are not
        // kept, nor seen by other points.
        let (ni, nr) = (self.data.integer_data.len(), self.data.real_data.len());
        let mut integer: Vec<i64> = Vec::with_capacity(CHUNK * ni);
        let mut real: Vec<f64> = Vec::with_capacity(CHUNK * nr);
        let mut fd_state = vec![0.0; ns];
        let mut start = 0;
        while start < n {
            let end = (start + CHUNK).min(n);
            let fill = |integer: &mut Vec<i64>, real: &mut Vec<f64>| {
                integer.clear();
                real.clear();
                for _ in start..end {
                    integer.extend_from_slice(&self.data.integer_data);
                    real.extend_from_slice(&self.data.real_data);
                }
            };
            fill(&mut integer, &mut real);
            ins.clear();
            let (old, new) = (&states.old, &mut states.new);
            for (i, p) in points.iter().enumerate().take(end).skip(start) {
                let mut s = SeamPointIn::new();
                s.gap = p.gap;
                s.pressure = p.pressure;
                s.temp_a = p.temp_a;
                s.temp_b = p.temp_b;
                s.x = p.x;
                s.normal_a = p.normal_a;
                s.normal_b = p.normal_b;
                s.weight = p.weight;
                s.time = ctx.time;
                s.dt = ctx.dt;
                s.step = ctx.step;
                s.iteration = ctx.iteration;
                s.surface_a = surface_a.as_ptr();
                s.surface_b = surface_b.as_ptr();
                if ctx.n_fields > 0 {
                    s.fields = ctx.fields[i * ctx.n_fields..].as_ptr();
                    s.n_fields = ctx.n_fields;
                }
                s.integer_data = integer[(i - start) * ni..].as_ptr();
                s.n_integer = ni;
                s.real_data = real[(i - start) * nr..].as_ptr();
                s.n_real = nr;
                if ns > 0 {
                    s.state_old = old[i * ns..].as_ptr();
                    s.state_new = new[i * ns..].as_mut_ptr();
                    s.n_state = ns;
                }
                ins.push(s);
            }
            // Reset what a plugin reads or may leave unwritten; the rest of the 256-byte
            // message buffer only matters after the plugin writes a message.
            outs.resize(end - start, SeamPointOut::new());
            outs.truncate(end - start);
            for o in outs.iter_mut() {
                o.struct_size = RESET.struct_size;
                o.status = SEAM_STATUS_OK;
                (o.value, o.d_temp_a, o.d_temp_b, o.d_gap, o.d_pressure) =
                    (0.0, 0.0, 0.0, 0.0, 0.0);
                o.cutback_factor = 0.0;
                o.message[0] = 0;
            }
            self.call(&ins, &mut outs, batch, start)?;
            for (k, o) in outs.iter().enumerate() {
                let point = start + k;
                self.validate(point, o, "value", conductance)?;
                results[point] = PointResult {
                    value: o.value,
                    d_temp_a: o.d_temp_a,
                    d_temp_b: o.d_temp_b,
                    d_gap: o.d_gap,
                    d_pressure: o.d_pressure,
                };
            }
            if fd {
                fill(&mut integer, &mut real);
                for (k, &input) in ins.iter().enumerate() {
                    let point = start + k;
                    let mut base = input;
                    if ns > 0 {
                        fd_state.copy_from_slice(&old[point * ns..(point + 1) * ns]);
                        base.state_new = fd_state.as_mut_ptr();
                    }
                    results[point] = self.finite_differences(point, base, results[point].value)?;
                }
            }
            start = end;
        }
        Ok(())
    }

    /// Call the plugin on `ins` (points `first…` of the caller's call), in process or in
    /// the worker. In process, a crash or an `exit` inside the call is reported with the
    /// point and ends the process (see [`super::guard`]); in a worker it is a
    /// [`PluginFault::ProcessDied`].
    fn call(
        &self,
        ins: &[SeamPointIn],
        outs: &mut [SeamPointOut],
        batch: bool,
        first: usize,
    ) -> Result<(), PluginFault> {
        let Backend::Process(worker) = &self.backend else {
            self.call_in_process(ins, outs, batch);
            return Ok(());
        };
        let mut worker = worker.lock().unwrap_or_else(|e| e.into_inner());
        // SAFETY: the inputs are built by `evaluate_mode` / `finite_differences`, their
        // pointers valid for the call and `state_new` writable.
        unsafe { worker.evaluate(ins, outs, batch) }.map_err(|d| {
            let names = |p: *const std::ffi::c_char| {
                // SAFETY: the host's surface names are NUL-terminated and live for the call.
                unsafe { c_text(p) }.unwrap_or_default()
            };
            PluginFault::ProcessDied {
                plugin: self.label.clone(),
                entry: if batch && self.info.has_batch {
                    "evaluate_batch"
                } else {
                    "evaluate_point"
                },
                interaction: ins
                    .first()
                    .map(|p| format!("{} / {}", names(p.surface_a), names(p.surface_b))),
                // The point the worker was at, when it knew (point by point), else the
                // points of the request.
                points: match d.point.filter(|&k| k < ins.len()) {
                    Some(k) => first + k..first + k + 1,
                    None => first..first + ins.len(),
                },
                how: d.how,
            }
        })
    }

    /// Call the plugin in this process, serialised unless it is thread-safe.
    pub(super) fn call_in_process(
        &self,
        ins: &[SeamPointIn],
        outs: &mut [SeamPointOut],
        batch: bool,
    ) {
        let Backend::InProcess {
            descriptor,
            instance,
            serial,
        } = &self.backend
        else {
            return;
        };
        let (descriptor, instance) = (*descriptor, *instance);
        let _guard =
            (!self.info.thread_safe()).then(|| serial.lock().unwrap_or_else(|e| e.into_inner()));
        let batched = batch && descriptor.evaluate_batch.is_some();
        let site = CallSite {
            plugin: &self.label,
            entry: if batched {
                "evaluate_batch"
            } else {
                "evaluate_point"
            },
            points: ins,
            current: Cell::new(None),
        };
        guarded(&site, || {
            match (batch, descriptor.evaluate_batch, descriptor.evaluate_point) {
                (true, Some(f), _) => {
                    // SAFETY: ins.len() valid inputs whose pointers live for the call and
                    // as many writable outputs; the instance is this plugin's.
                    unsafe { f(instance, ins.as_ptr(), outs.as_mut_ptr(), ins.len()) }
                }
                (_, _, Some(f)) => {
                    for (k, (i, o)) in ins.iter().zip(outs.iter_mut()).enumerate() {
                        site.current.set(Some(k));
                        // SAFETY: as above, one point.
                        unsafe { f(instance, i, o) }
                    }
                }
                // Checked non-NULL at load.
                (_, _, None) => {}
            }
        })
    }

    fn validate(
        &self,
        point: usize,
        o: &SeamPointOut,
        what: &'static str,
        conductance: bool,
    ) -> Result<(), PluginFault> {
        let plugin = || self.label.clone();
        match o.status {
            SEAM_STATUS_OK => {}
            SEAM_STATUS_ERROR => {
                return Err(PluginFault::Error {
                    plugin: plugin(),
                    point,
                    message: message_text(&o.message),
                });
            }
            SEAM_STATUS_CUTBACK => {
                return Err(PluginFault::Cutback {
                    plugin: plugin(),
                    point,
                    factor: o.cutback_factor,
                    message: message_text(&o.message),
                });
            }
            status => {
                return Err(PluginFault::BadStatus {
                    plugin: plugin(),
                    point,
                    status,
                });
            }
        }
        // Without derivatives only the value is the plugin's; the rest is seam's.
        let checks = [
            (what, o.value),
            ("dvalue/dT_A", o.d_temp_a),
            ("dvalue/dT_B", o.d_temp_b),
            ("dvalue/dgap", o.d_gap),
            ("dvalue/dpressure", o.d_pressure),
        ];
        let checked = if self.info.provides_derivatives() {
            5
        } else {
            1
        };
        for &(what, value) in &checks[..checked] {
            if !value.is_finite() {
                return Err(PluginFault::NotFinite {
                    plugin: plugin(),
                    point,
                    what,
                    value,
                });
            }
        }
        if conductance && o.value < 0.0 {
            return Err(PluginFault::Negative {
                plugin: plugin(),
                point,
                value: o.value,
            });
        }
        Ok(())
    }

    /// Central differences in T_A, T_B, gap and pressure around `base` (8 more calls).
    fn finite_differences(
        &self,
        point: usize,
        base: SeamPointIn,
        value: f64,
    ) -> Result<PointResult, PluginFault> {
        let steps = [
            (
                base.temp_a.abs().max(FD_FLOOR_TEMPERATURE),
                "value at T_A ± δ",
            ),
            (
                base.temp_b.abs().max(FD_FLOOR_TEMPERATURE),
                "value at T_B ± δ",
            ),
            (base.gap.abs().max(FD_FLOOR_GAP), "value at gap ± δ"),
            (
                base.pressure.abs().max(FD_FLOOR_PRESSURE),
                "value at pressure ± δ",
            ),
        ];
        let mut d = [0.0; 4];
        let cbrt_eps = f64::EPSILON.cbrt();
        for (j, &(scale, what)) in steps.iter().enumerate() {
            let h = cbrt_eps * scale;
            let mut ins = [base, base];
            for (s, sign) in ins.iter_mut().zip([1.0, -1.0]) {
                let x = match j {
                    0 => &mut s.temp_a,
                    1 => &mut s.temp_b,
                    2 => &mut s.gap,
                    _ => &mut s.pressure,
                };
                *x += sign * h;
            }
            let mut outs = [SeamPointOut::new(), SeamPointOut::new()];
            // One point at a time: the two calls share the scratch state.
            self.call(&ins[..1], &mut outs[..1], false, point)?;
            self.call(&ins[1..], &mut outs[1..], false, point)?;
            for o in &outs {
                // The sign is not checked here: x ± δ may leave the model's range.
                self.validate(point, o, what, false)?;
            }
            d[j] = (outs[0].value - outs[1].value) / (2.0 * h);
        }
        Ok(PointResult {
            value,
            d_temp_a: d[0],
            d_temp_b: d[1],
            d_gap: d[2],
            d_pressure: d[3],
        })
    }
}

/// The version and size checks, with messages naming both versions.
fn check_versions(path: &Path, major: u32, minor: u32, size: u32) -> Result<(), PluginError> {
    if major != SEAM_PLUGIN_ABI_MAJOR {
        return Err(PluginError::AbiMajor {
            path: path.to_owned(),
            plugin_major: major,
            plugin_minor: minor,
            host_major: SEAM_PLUGIN_ABI_MAJOR,
            host_minor: SEAM_PLUGIN_ABI_MINOR,
        });
    }
    if minor > SEAM_PLUGIN_ABI_MINOR {
        return Err(PluginError::AbiMinor {
            path: path.to_owned(),
            plugin_major: major,
            plugin_minor: minor,
            host_major: SEAM_PLUGIN_ABI_MAJOR,
            host_minor: SEAM_PLUGIN_ABI_MINOR,
        });
    }
    let need = size_of::<SeamPluginDescriptor>();
    if (size as usize) < need {
        return Err(PluginError::DescriptorTooSmall {
            path: path.to_owned(),
            size,
            need,
            major: SEAM_PLUGIN_ABI_MAJOR,
            minor: SEAM_PLUGIN_ABI_MINOR,
        });
    }
    Ok(())
}

/// A plugin without `seam_plugin_v1` may be one for another major version: look for
/// `seam_plugin_v0` and `seam_plugin_v2` … `v9` to say so.
fn other_major(lib: &libloading::Library, path: &Path) -> Option<PluginError> {
    (0..10u32)
        .filter(|&m| m != SEAM_PLUGIN_ABI_MAJOR)
        .find_map(|major| {
            let mut buf = [0u8; 32];
            let name = format!("{}\0", entry_symbol_for(major, &mut buf));
            // SAFETY: only the symbol's presence is tested; nothing is called.
            let found = unsafe { lib.get::<*const c_void>(name.as_bytes()) }.is_ok();
            found.then(|| PluginError::AbiMajor {
                path: path.to_owned(),
                plugin_major: major,
                plugin_minor: 0,
                host_major: SEAM_PLUGIN_ABI_MAJOR,
                host_minor: SEAM_PLUGIN_ABI_MINOR,
            })
        })
}

/// Call `init` (if any) with the deck's data.
fn instantiate(
    d: &'static SeamPluginDescriptor,
    info: &PluginInfo,
    data: &PluginData,
) -> Result<*mut c_void, PluginError> {
    let mut instance = std::ptr::null_mut();
    let Some(init) = d.init else {
        return Ok(instance);
    };
    let model = CString::new(
        data.model
            .clone()
            .unwrap_or_else(|| info.name.clone())
            .replace('\0', " "),
    )
    .unwrap_or_default();
    let input = SeamInstanceIn {
        struct_size: size_of::<SeamInstanceIn>() as u32,
        reserved: 0,
        model: model.as_ptr(),
        integer_data: data.integer_data.as_ptr(),
        n_integer: data.integer_data.len(),
        real_data: data.real_data.as_ptr(),
        n_real: data.real_data.len(),
    };
    let mut message = [0 as c_char; SEAM_MESSAGE_LEN];
    // SAFETY: input, the instance slot and a SEAM_MESSAGE_LEN buffer are valid for the
    // call, as the ABI requires.
    let plugin = format!("`{}` ({})", info.name, info.path.display());
    let site = CallSite {
        plugin: &plugin,
        entry: "init",
        points: &[],
        current: Cell::new(None),
    };
    let status = guarded(&site, || unsafe {
        init(&input, &mut instance, message.as_mut_ptr())
    });
    if status != SEAM_STATUS_OK {
        message[SEAM_MESSAGE_LEN - 1] = 0;
        return Err(PluginError::Init {
            path: info.path.clone(),
            name: info.name.clone(),
            message: message_text(&message),
        });
    }
    Ok(instance)
}
