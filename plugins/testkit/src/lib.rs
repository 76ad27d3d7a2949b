//! Conformance checks for seam enforcement plugins.
//!
//! [`load`] a built plugin (or wrap a descriptor the host already loaded with
//! [`Loaded::from_descriptor`]), then [`run`] a [`Config`]: the plugin is instantiated
//! with the config's `Integer Data` / `Real Data` and evaluated on a grid of states
//! (every combination of the grid's gaps, pressures and temperatures). Checked:
//!
//! - the descriptor: known capability bits only, `HAS_STATE` iff `state_size > 0`;
//! - every point: status OK, finite value, value ≥ 0 for a conductance, finite
//!   derivatives;
//! - derivatives (when the plugin provides them) against finite differences with step
//!   δ = ε^{1/3} max(|x|, x_floor) (x_floor = [`FLOOR_TEMPERATURE`], [`FLOOR_PRESSURE`],
//!   [`FLOOR_GAP`]). A derivative d passes when it is within
//!   `rtol (|d| + |value| / max(|x|, x_floor))` of the central, the forward or the
//!   backward difference: the second term is the floor (a derivative is judged on the
//!   scale value/x, so a zero derivative is not held to zero absolute error), and the
//!   one-sided differences accept exact slopes of piecewise-linear models next to a
//!   breakpoint, where the central difference straddles a kink;
//! - batch against per-point results (relative 1e-12: a batch may reorder arithmetic);
//! - a `THREAD_SAFE` claim: the grid evaluated from two threads at once must give
//!   bit-identical results to the serial evaluation.

use std::ffi::{CStr, CString, c_char, c_void};
use std::fmt;
use std::path::Path;

use seam_plugin_abi::{
    ENTRY_SYMBOL, SEAM_CAP_ALL, SEAM_CAP_HAS_STATE, SEAM_CAP_PROVIDES_DERIVATIVES,
    SEAM_CAP_RETURNS_FLUX, SEAM_CAP_THREAD_SAFE, SEAM_MESSAGE_LEN, SEAM_PLUGIN_ABI_MAJOR,
    SEAM_PLUGIN_ABI_MINOR, SEAM_STATUS_CUTBACK, SEAM_STATUS_ERROR, SEAM_STATUS_OK, SeamEntryFn,
    SeamInstanceIn, SeamPluginDescriptor, SeamPointIn, SeamPointOut,
};

/// Finite-difference step floors: δ = ε^{1/3} max(|x|, floor).
pub const FLOOR_TEMPERATURE: f64 = 1.0;
pub const FLOOR_PRESSURE: f64 = 1.0;
pub const FLOOR_GAP: f64 = 1e-9;

/// Default relative tolerance of the derivative check. Central differences with the step
/// above have truncation and round-off errors near 1e-10 relative for smooth models, so
/// 1e-6 passes every correct derivative and fails any wrong one by more than 1 ppm.
pub const DEFAULT_RTOL: f64 = 1e-6;

/// A plugin descriptor that stays valid for the life of the process.
#[derive(Clone, Copy, Debug)]
pub struct Loaded {
    descriptor: &'static SeamPluginDescriptor,
}

impl Loaded {
    /// Wrap a descriptor loaded elsewhere (e.g. by the seam host).
    ///
    /// # Safety
    /// `descriptor` must come from a seam plugin whose library is never unloaded, have
    /// passed the version and size checks, and have a non-NULL `evaluate_point`.
    pub unsafe fn from_descriptor(descriptor: &'static SeamPluginDescriptor) -> Self {
        Loaded { descriptor }
    }

    pub fn descriptor(&self) -> &'static SeamPluginDescriptor {
        self.descriptor
    }

    /// The model name, or "?" if it is missing or not UTF-8.
    pub fn name(&self) -> &'static str {
        // SAFETY: the descriptor's strings are static and NUL-terminated (ABI rule).
        unsafe { static_text(self.descriptor.name) }
    }

    pub fn model_version(&self) -> &'static str {
        // SAFETY: as in `name`.
        unsafe { static_text(self.descriptor.model_version) }
    }
}

/// # Safety
/// `p` NULL or a static NUL-terminated string.
unsafe fn static_text(p: *const c_char) -> &'static str {
    if p.is_null() {
        return "?";
    }
    // SAFETY: by the caller's contract.
    unsafe { CStr::from_ptr(p) }.to_str().unwrap_or("?")
}

/// Load a plugin library (never unloaded) and check its descriptor's versions and size.
pub fn load(path: &Path) -> Result<Loaded, String> {
    // SAFETY: loading runs the library's initialisers; that is the point of a plugin, and
    // the caller chose the file.
    let lib = unsafe { libloading::Library::new(path) }
        .map_err(|e| format!("{}: cannot load: {e}", path.display()))?;
    let lib: &'static libloading::Library = Box::leak(Box::new(lib));
    // SAFETY: a seam plugin exports the entry symbol with type SeamEntryFn (ABI).
    let entry: SeamEntryFn = *unsafe { lib.get::<SeamEntryFn>(ENTRY_SYMBOL) }
        .map_err(|e| format!("{}: no entry symbol seam_plugin_v1: {e}", path.display()))?;
    // SAFETY: the entry function takes no arguments and returns a static descriptor.
    let d = unsafe { entry() };
    if d.is_null() {
        return Err(format!("{}: seam_plugin_v1 returned NULL", path.display()));
    }
    // SAFETY: the three leading u32 fields exist in every descriptor version; read them
    // before trusting struct_size for the rest.
    let (major, minor, size) = unsafe {
        (
            std::ptr::addr_of!((*d).abi_major).read(),
            std::ptr::addr_of!((*d).abi_minor).read(),
            std::ptr::addr_of!((*d).struct_size).read(),
        )
    };
    if major != SEAM_PLUGIN_ABI_MAJOR || minor > SEAM_PLUGIN_ABI_MINOR {
        return Err(format!(
            "{}: plugin ABI {major}.{minor}, this kit speaks {SEAM_PLUGIN_ABI_MAJOR}.{SEAM_PLUGIN_ABI_MINOR}",
            path.display()
        ));
    }
    if (size as usize) < size_of::<SeamPluginDescriptor>() {
        return Err(format!(
            "{}: descriptor of {size} bytes is too small",
            path.display()
        ));
    }
    // SAFETY: the size check above shows the whole struct is there; it is static.
    let d: &'static SeamPluginDescriptor = unsafe { &*d };
    if d.evaluate_point.is_none() {
        return Err(format!("{}: evaluate_point is NULL", path.display()));
    }
    Ok(Loaded { descriptor: d })
}

/// The states probed: every combination of the four lists.
#[derive(Clone, Debug, PartialEq)]
pub struct Grid {
    pub gaps: Vec<f64>,
    pub pressures: Vec<f64>,
    pub temps_a: Vec<f64>,
    pub temps_b: Vec<f64>,
}

impl Default for Grid {
    /// Gaps 1 µm–0.1 mm, pressures 0.1–10 MPa, temperatures 300–900 K (SI units).
    fn default() -> Self {
        Grid {
            gaps: vec![1e-6, 1e-5, 1e-4],
            pressures: vec![1e5, 1e6, 1e7],
            temps_a: vec![300.0, 600.0, 900.0],
            temps_b: vec![350.0, 700.0],
        }
    }
}

impl Grid {
    /// (gap, pressure, T_A, T_B) for every combination.
    pub fn states(&self) -> Vec<[f64; 4]> {
        let mut out = Vec::new();
        for &g in &self.gaps {
            for &p in &self.pressures {
                for &ta in &self.temps_a {
                    for &tb in &self.temps_b {
                        out.push([g, p, ta, tb]);
                    }
                }
            }
        }
        out
    }
}

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    pub integer_data: Vec<i64>,
    pub real_data: Vec<f64>,
    pub grid: Grid,
    pub rtol: f64,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            integer_data: Vec::new(),
            real_data: Vec::new(),
            grid: Grid::default(),
            rtol: DEFAULT_RTOL,
        }
    }
}

/// The outcome of [`run`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Report {
    pub name: String,
    pub model_version: String,
    pub capabilities: u64,
    /// Grid points evaluated.
    pub points: usize,
    /// Derivatives compared with finite differences.
    pub derivatives_checked: usize,
    /// Largest |d − FD| / (|d| + |value|/max(|x|, floor)) seen (best of the three
    /// differences), over all checked derivatives.
    pub max_derivative_error: f64,
    pub batch_checked: bool,
    pub threads_checked: bool,
    /// One line per failed check (the first [`MAX_LISTED`]), plus a count of the rest.
    pub failures: Vec<String>,
    pub failure_count: usize,
}

/// Failures listed one by one before they are only counted.
pub const MAX_LISTED: usize = 20;

impl Report {
    pub fn passed(&self) -> bool {
        self.failure_count == 0
    }

    fn fail(&mut self, message: String) {
        self.failure_count += 1;
        if self.failures.len() < MAX_LISTED {
            self.failures.push(message);
        }
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} {}: {} points, {} derivatives checked (max error {:.1e}), batch {}, threads {}",
            self.name,
            self.model_version,
            self.points,
            self.derivatives_checked,
            self.max_derivative_error,
            if self.batch_checked { "checked" } else { "n/a" },
            if self.threads_checked {
                "checked"
            } else {
                "n/a"
            },
        )?;
        for line in &self.failures {
            writeln!(f, "  FAIL {line}")?;
        }
        if self.failure_count > self.failures.len() {
            writeln!(
                f,
                "  … and {} more",
                self.failure_count - self.failures.len()
            )?;
        }
        write!(f, "{}", if self.passed() { "PASS" } else { "FAIL" })
    }
}

/// An instance of the model for the length of a run; finalized on drop.
struct Instance {
    d: &'static SeamPluginDescriptor,
    ptr: *mut c_void,
    integer: Vec<i64>,
    real: Vec<f64>,
}

// SAFETY: the instance is used from several threads only when the plugin declares
// THREAD_SAFE (checked in `run` before spawning).
unsafe impl Sync for Instance {}

impl Drop for Instance {
    fn drop(&mut self) {
        if let Some(fin) = self.d.finalize {
            // SAFETY: ptr came from this descriptor's init and is released once.
            unsafe { fin(self.ptr) };
        }
    }
}

/// One evaluation's result.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Eval {
    status: i32,
    v: [f64; 5],
}

impl Instance {
    fn new(d: &'static SeamPluginDescriptor, config: &Config) -> Result<Self, String> {
        let model = CString::new(
            // SAFETY: static descriptor string (ABI rule).
            unsafe { static_text(d.name) },
        )
        .unwrap_or_default();
        let mut ptr = std::ptr::null_mut();
        if let Some(init) = d.init {
            let input = SeamInstanceIn {
                struct_size: size_of::<SeamInstanceIn>() as u32,
                reserved: 0,
                model: model.as_ptr(),
                integer_data: config.integer_data.as_ptr(),
                n_integer: config.integer_data.len(),
                real_data: config.real_data.as_ptr(),
                n_real: config.real_data.len(),
            };
            let mut message = [0 as c_char; SEAM_MESSAGE_LEN];
            // SAFETY: valid input, instance slot and message buffer for the call.
            let status = unsafe { init(&input, &mut ptr, message.as_mut_ptr()) };
            if status != SEAM_STATUS_OK {
                message[SEAM_MESSAGE_LEN - 1] = 0;
                // SAFETY: NUL-terminated just above.
                let text = unsafe { CStr::from_ptr(message.as_ptr()) }.to_string_lossy();
                return Err(format!("init failed (status {status}): {text}"));
            }
        }
        Ok(Instance {
            d,
            ptr,
            integer: config.integer_data.clone(),
            real: config.real_data.clone(),
        })
    }

    /// Evaluate states; batch entry if `batch`, else point by point.
    fn eval(&self, states: &[[f64; 4]], batch: bool) -> Vec<(Eval, String)> {
        let n = states.len();
        let nstate = self.d.state_size as usize;
        let old = vec![0.0; nstate * n];
        let mut new = old.clone();
        let mut integer = self.integer.clone();
        let mut real = self.real.clone();
        let mut outs = vec![SeamPointOut::new(); n];
        let mut ins = Vec::with_capacity(n);
        for (i, s) in states.iter().enumerate() {
            let mut p = SeamPointIn::new();
            p.gap = s[0];
            p.pressure = s[1];
            p.temp_a = s[2];
            p.temp_b = s[3];
            p.normal_a = [0.0, 0.0, 1.0];
            p.normal_b = [0.0, 0.0, -1.0];
            p.weight = 1.0;
            p.time = 1.0;
            p.dt = 1.0;
            p.step = 1;
            p.surface_a = c"side_a".as_ptr();
            p.surface_b = c"side_b".as_ptr();
            p.integer_data = integer.as_mut_ptr();
            p.n_integer = integer.len();
            p.real_data = real.as_mut_ptr();
            p.n_real = real.len();
            if nstate > 0 {
                p.state_old = old[i * nstate..].as_ptr();
                p.state_new = new[i * nstate..].as_mut_ptr();
                p.n_state = nstate;
            }
            ins.push(p);
        }
        match (batch, self.d.evaluate_batch, self.d.evaluate_point) {
            (true, Some(f), _) => {
                // SAFETY: n valid inputs (their pointers live until the end of this
                // function) and n writable outputs.
                unsafe { f(self.ptr, ins.as_ptr(), outs.as_mut_ptr(), n) }
            }
            (_, _, Some(f)) => {
                for (p, o) in ins.iter().zip(outs.iter_mut()) {
                    // SAFETY: as above, one point.
                    unsafe { f(self.ptr, p, o) }
                }
            }
            _ => {}
        }
        outs.iter()
            .map(|o| {
                let mut msg = o.message;
                msg[SEAM_MESSAGE_LEN - 1] = 0;
                // SAFETY: NUL-terminated just above.
                let text = unsafe { CStr::from_ptr(msg.as_ptr()) }
                    .to_string_lossy()
                    .into_owned();
                (
                    Eval {
                        status: o.status,
                        v: [o.value, o.d_temp_a, o.d_temp_b, o.d_gap, o.d_pressure],
                    },
                    text,
                )
            })
            .collect()
    }
}

fn status_name(s: i32) -> String {
    match s {
        SEAM_STATUS_OK => "OK".into(),
        SEAM_STATUS_ERROR => "ERROR".into(),
        SEAM_STATUS_CUTBACK => "CUTBACK".into(),
        other => format!("unknown status {other}"),
    }
}

/// Run every check on `plugin` with `config`.
pub fn run(plugin: &Loaded, config: &Config) -> Report {
    let d = plugin.descriptor;
    let caps = d.capabilities;
    let mut report = Report {
        name: plugin.name().to_owned(),
        model_version: plugin.model_version().to_owned(),
        capabilities: caps,
        ..Report::default()
    };
    if caps & !SEAM_CAP_ALL != 0 {
        report.fail(format!(
            "unknown capability bits {:#x}",
            caps & !SEAM_CAP_ALL
        ));
    }
    if (caps & SEAM_CAP_HAS_STATE != 0) != (d.state_size > 0) {
        report.fail(format!(
            "HAS_STATE is {} but state_size is {}",
            caps & SEAM_CAP_HAS_STATE != 0,
            d.state_size
        ));
    }
    let instance = match Instance::new(d, config) {
        Ok(i) => i,
        Err(e) => {
            report.fail(e);
            return report;
        }
    };
    let states = config.grid.states();
    report.points = states.len();
    let serial = instance.eval(&states, false);
    let conductance = caps & SEAM_CAP_RETURNS_FLUX == 0;
    let derivatives = caps & SEAM_CAP_PROVIDES_DERIVATIVES != 0;
    const NAMES: [&str; 5] = ["value", "d/dT_A", "d/dT_B", "d/dgap", "d/dpressure"];
    // Which state component each derivative is taken with respect to, and its floor.
    const WRT: [(usize, f64); 4] = [
        (2, FLOOR_TEMPERATURE),
        (3, FLOOR_TEMPERATURE),
        (0, FLOOR_GAP),
        (1, FLOOR_PRESSURE),
    ];
    for (s, (e, msg)) in states.iter().zip(&serial) {
        let at = format!(
            "gap {:e} pressure {:e} T_A {} T_B {}",
            s[0], s[1], s[2], s[3]
        );
        if e.status != SEAM_STATUS_OK {
            report.fail(format!("{at}: status {}: {msg}", status_name(e.status)));
            continue;
        }
        let checked = if derivatives { 5 } else { 1 };
        let mut finite = true;
        for (name, v) in NAMES.iter().zip(&e.v).take(checked) {
            if !v.is_finite() {
                report.fail(format!("{at}: {name} is {v}"));
                finite = false;
            }
        }
        if !finite {
            continue;
        }
        if conductance && e.v[0] < 0.0 {
            report.fail(format!("{at}: conductance {} is negative", e.v[0]));
        }
        if !derivatives {
            continue;
        }
        for (k, &(j, floor)) in WRT.iter().enumerate() {
            let x = s[j];
            let scale = x.abs().max(floor);
            let h = f64::EPSILON.cbrt() * scale;
            let (mut plus, mut minus) = (*s, *s);
            plus[j] += h;
            minus[j] -= h;
            let r = instance.eval(&[plus, minus], false);
            if r.iter().any(|(q, _)| q.status != SEAM_STATUS_OK) {
                report.fail(format!("{at}: status not OK at x ± δ for {}", NAMES[k + 1]));
                continue;
            }
            let (fp, fm, f0) = (r[0].0.v[0], r[1].0.v[0], e.v[0]);
            let d = e.v[k + 1];
            let tol_scale = d.abs() + f0.abs() / scale;
            let candidates = [(fp - fm) / (2.0 * h), (fp - f0) / h, (f0 - fm) / h];
            let err = candidates
                .iter()
                .map(|c| (d - c).abs() / tol_scale.max(f64::MIN_POSITIVE))
                .fold(f64::INFINITY, f64::min);
            report.derivatives_checked += 1;
            report.max_derivative_error = report.max_derivative_error.max(err);
            if err > config.rtol {
                report.fail(format!(
                    "{at}: {} = {d:e} but finite differences give {:e} (relative error {err:.1e} > {:.0e})",
                    NAMES[k + 1],
                    candidates[0],
                    config.rtol
                ));
            }
        }
    }
    if d.evaluate_batch.is_some() {
        report.batch_checked = true;
        let batch = instance.eval(&states, true);
        for (i, ((a, _), (b, _))) in serial.iter().zip(&batch).enumerate() {
            let agree = a.status == b.status
                && a.v
                    .iter()
                    .zip(&b.v)
                    .all(|(x, y)| x == y || (x - y).abs() <= 1e-12 * x.abs().max(y.abs()));
            if !agree {
                report.fail(format!(
                    "point {i}: batch {b:?} differs from per-point {a:?}"
                ));
            }
        }
    }
    if caps & SEAM_CAP_THREAD_SAFE != 0 {
        report.threads_checked = true;
        let runs: Vec<Vec<(Eval, String)>> = std::thread::scope(|scope| {
            let handles: Vec<_> = (0..2)
                .map(|_| scope.spawn(|| instance.eval(&states, false)))
                .collect();
            handles.into_iter().filter_map(|h| h.join().ok()).collect()
        });
        if runs.len() != 2 {
            report.fail("a thread evaluating the grid did not finish".into());
        }
        for (t, run) in runs.iter().enumerate() {
            let same = run.iter().zip(&serial).all(|((a, _), (b, _))| {
                a.status == b.status
                    && a.v
                        .iter()
                        .zip(&b.v)
                        .all(|(x, y)| x.to_bits() == y.to_bits())
            });
            if !same {
                report.fail(format!(
                    "THREAD_SAFE claimed, but thread {t} got results different from the serial run"
                ));
            }
        }
    }
    report
}
