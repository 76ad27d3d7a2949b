//! `Plugin Isolation = Process`: the plugin runs in a child process, so that a crash or an
//! `exit` inside it is an ordinary [`PluginFault`](super::PluginFault) and the host goes
//! on.
//!
//! Entry points: [`Plugin::load_isolated`](super::Plugin::load_isolated) (the parent's
//! side, through `Worker`); [`serve_worker`] (the child's side, what `seam plugin-worker`
//! runs); [`worker_program`] / [`set_worker_program`] (which executable is the worker).
//!
//! The child is a *plugin worker*: the `seam` executable started as `seam plugin-worker`.
//! It loads the library and the instance in process (the checks of
//! [`Plugin::load_with`], its errors word for word), then serves requests on its standard
//! input, a Unix socket shared with the parent: evaluate a call's points (the
//! `SeamPointIn` / `SeamPointOut` data, pointers' contents sent with them and re-created
//! in the child), or run the conformance kit. The parent builds the points, validates the
//! outputs and forms finite differences exactly as in process, so both modes give
//! bit-identical results.
//!
//! Wire format: frames of a `u32` length and a payload, numbers little-endian, `f64` as
//! their bits. The parent opens with [`MAGIC`] and a load request; the child greets with
//! [`MAGIC`] (so a program that is not a worker is told from a worker that died while
//! loading), then answers with the plugin's descriptor or the load error. The child
//! speaks on a duplicate of its standard input and sends its standard output to standard
//! error, so a plugin's `printf` cannot corrupt the channel. The parent writes with
//! `MSG_NOSIGNAL`: a dead child is an error, not a `SIGPIPE` for an embedding host.
//!
//! A child that dies (signal or exit) during a request is reaped and described (`was
//! killed by SIGSEGV (invalid memory access)`, `ended with exit status 0`). It is started
//! again on the next call, up to [`MAX_DEATHS`] deaths (failed starts included); after
//! that the plugin is dead and every call faults at once. No timeout: a plugin that
//! hangs, hangs the call.

use std::ffi::CString;
use std::io::{BufReader, Read};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::net::UnixStream;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use seam_plugin_abi::{SEAM_MESSAGE_LEN, SEAM_STATUS_OK, SeamPointIn, SeamPointOut};
use seam_plugin_testkit::{Config, Grid, Report};

use super::guard::DIED_TAG;
use super::{Plugin, PluginData, PluginError, PluginInfo};

/// Opens both directions of the conversation; the digits are the protocol's version.
pub const MAGIC: &[u8; 8] = b"SEAMPW01";

/// Deaths of a plugin's worker after which it is not started again.
pub const MAX_DEATHS: usize = 100;

/// The environment variable naming the worker executable (overrides everything else).
pub const WORKER_ENV: &str = "SEAM_PLUGIN_WORKER";

/// The hidden subcommand of `seam` that serves a plugin.
pub const WORKER_SUBCOMMAND: &str = "plugin-worker";

/// The phrase every fault of a dead worker carries (the binary maps it to exit code 3).
pub const PROCESS_DEATH: &str = "isolated plugin process";

const LOAD: u8 = 1;
const EVALUATE: u8 = 2;
const CONFORMANCE: u8 = 3;
const OK: u8 = 0;
const ERR: u8 = 1;

/// Frames larger than this are a protocol error, not an allocation.
const MAX_FRAME: usize = 1 << 30;

static WORKER_PROGRAM: Mutex<Option<PathBuf>> = Mutex::new(None);

/// Use `program` as the plugin worker (an executable that runs [`serve_worker`] when given
/// the argument `plugin-worker`, such as `seam`). For hosts that are not the `seam`
/// binary: tests (`env!("CARGO_BIN_EXE_seam")`), embedding programs. The environment
/// variable `SEAM_PLUGIN_WORKER` still takes precedence.
pub fn set_worker_program(program: impl Into<PathBuf>) {
    *WORKER_PROGRAM.lock().unwrap_or_else(|e| e.into_inner()) = Some(program.into());
}

/// The worker executable: `$SEAM_PLUGIN_WORKER`; else the one set with
/// [`set_worker_program`]; else this executable if it is `seam`; else a `seam` next to
/// this executable or one directory up (where cargo puts it for tests and benchmarks).
/// The error says what was tried.
pub fn worker_program() -> Result<PathBuf, String> {
    let mut tried = Vec::new();
    if let Some(p) = std::env::var_os(WORKER_ENV).filter(|p| !p.is_empty()) {
        let p = PathBuf::from(p);
        if p.is_file() {
            return Ok(p);
        }
        return Err(format!("{WORKER_ENV}={}: no such file", p.display()));
    }
    if let Some(p) = WORKER_PROGRAM
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .clone()
    {
        if p.is_file() {
            return Ok(p);
        }
        tried.push(format!("{} (set by the host; no such file)", p.display()));
    }
    let exe_name = format!("seam{}", std::env::consts::EXE_SUFFIX);
    if let Ok(exe) = std::env::current_exe() {
        if exe.file_name().is_some_and(|n| n == exe_name.as_str()) {
            return Ok(exe);
        }
        for dir in exe.ancestors().skip(1).take(2) {
            let candidate = dir.join(&exe_name);
            if candidate.is_file() {
                return Ok(candidate);
            }
            tried.push(candidate.display().to_string());
        }
    }
    Err(format!("tried {}", tried.join(", ")))
}

// --- wire format -------------------------------------------------------------------------

/// A frame being written: 4 bytes kept for the length, then the payload.
struct Wire(Vec<u8>);

impl Default for Wire {
    fn default() -> Self {
        Wire::with_capacity(64)
    }
}

impl Wire {
    fn with_capacity(n: usize) -> Self {
        let mut v = Vec::with_capacity(n + 4);
        v.extend_from_slice(&[0; 4]);
        Wire(v)
    }

    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    fn i64(&mut self, v: i64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn i32(&mut self, v: i32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    fn f64s(&mut self, v: &[f64]) {
        for &x in v {
            self.f64(x);
        }
    }
    fn i64s(&mut self, v: &[i64]) {
        for &x in v {
            self.i64(x);
        }
    }
    fn bytes(&mut self, v: &[u8]) {
        self.usize(v.len());
        self.0.extend_from_slice(v);
    }
    fn str(&mut self, v: &str) {
        self.bytes(v.as_bytes());
    }
    fn list_f64(&mut self, v: &[f64]) {
        self.usize(v.len());
        self.f64s(v);
    }
    fn list_i64(&mut self, v: &[i64]) {
        self.usize(v.len());
        self.i64s(v);
    }
}

/// Reading a payload; `None` when it ends early (a protocol error).
struct Parse<'a> {
    buf: &'a [u8],
}

impl<'a> Parse<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if n > self.buf.len() {
            return None;
        }
        let (head, tail) = self.buf.split_at(n);
        self.buf = tail;
        Some(head)
    }
    fn u8(&mut self) -> Option<u8> {
        self.take(1).map(|b| b[0])
    }
    fn u64(&mut self) -> Option<u64> {
        self.take(8)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
    }
    fn usize(&mut self) -> Option<usize> {
        self.u64().and_then(|v| usize::try_from(v).ok())
    }
    /// A count of items of `size` bytes that the rest of the payload can hold.
    fn count(&mut self, size: usize) -> Option<usize> {
        self.usize()
            .filter(|&n| n.checked_mul(size).is_some_and(|b| b <= self.buf.len()))
    }
    fn i64(&mut self) -> Option<i64> {
        self.u64().map(|v| v as i64)
    }
    fn i32(&mut self) -> Option<i32> {
        self.take(4)
            .map(|b| i32::from_le_bytes(b.try_into().unwrap_or_default()))
    }
    fn f64(&mut self) -> Option<f64> {
        self.u64().map(f64::from_bits)
    }
    fn f64s_into(&mut self, n: usize, out: &mut Vec<f64>) -> Option<()> {
        let b = self.take(n.checked_mul(8)?)?;
        out.extend(
            b.chunks_exact(8)
                .map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().unwrap_or_default()))),
        );
        Some(())
    }
    fn i64s_into(&mut self, n: usize, out: &mut Vec<i64>) -> Option<()> {
        let b = self.take(n.checked_mul(8)?)?;
        out.extend(
            b.chunks_exact(8)
                .map(|c| i64::from_le_bytes(c.try_into().unwrap_or_default())),
        );
        Some(())
    }
    fn bytes(&mut self) -> Option<&'a [u8]> {
        let n = self.count(1)?;
        self.take(n)
    }
    fn string(&mut self) -> Option<String> {
        self.bytes()
            .map(|b| String::from_utf8_lossy(b).into_owned())
    }
    fn list_f64(&mut self) -> Option<Vec<f64>> {
        let n = self.count(8)?;
        let mut v = Vec::with_capacity(n);
        self.f64s_into(n, &mut v)?;
        Some(v)
    }
    fn list_i64(&mut self) -> Option<Vec<i64>> {
        let n = self.count(8)?;
        let mut v = Vec::with_capacity(n);
        self.i64s_into(n, &mut v)?;
        Some(v)
    }
}

/// Write all of `bytes` to `fd`; `MSG_NOSIGNAL` on sockets turns a closed peer into
/// `EPIPE` instead of a `SIGPIPE`.
fn send_all(fd: libc::c_int, mut bytes: &[u8], socket: bool) -> std::io::Result<()> {
    while !bytes.is_empty() {
        // SAFETY: a valid buffer of bytes.len() bytes; fd is open for the call.
        let n = unsafe {
            if socket {
                libc::send(fd, bytes.as_ptr().cast(), bytes.len(), libc::MSG_NOSIGNAL)
            } else {
                libc::write(fd, bytes.as_ptr().cast(), bytes.len())
            }
        };
        if n < 0 {
            let e = std::io::Error::last_os_error();
            if e.kind() == std::io::ErrorKind::Interrupted {
                continue;
            }
            return Err(e);
        }
        bytes = &bytes[n as usize..];
    }
    Ok(())
}

/// Send `w`'s frame (its length written into the 4 bytes kept for it).
fn send_frame(fd: libc::c_int, w: &mut Wire, socket: bool) -> std::io::Result<()> {
    let len = u32::try_from(w.0.len() - 4)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidInput, "a frame over 4 GiB"))?;
    w.0[..4].copy_from_slice(&len.to_le_bytes());
    send_all(fd, &w.0, socket)
}

fn read_frame(r: &mut impl Read, buf: &mut Vec<u8>) -> std::io::Result<()> {
    let mut len = [0u8; 4];
    r.read_exact(&mut len)?;
    let len = u32::from_le_bytes(len) as usize;
    if len > MAX_FRAME {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("a frame of {len} bytes"),
        ));
    }
    buf.clear();
    buf.resize(len, 0);
    r.read_exact(buf)
}

fn write_info(w: &mut Wire, info: &PluginInfo) {
    w.str(&info.name);
    w.str(&info.model_version);
    w.u64(info.abi_major.into());
    w.u64(info.abi_minor.into());
    w.u64(info.capabilities);
    w.usize(info.state_size);
    w.u8(info.has_batch.into());
}

fn read_info(p: &mut Parse<'_>, path: &Path) -> Option<PluginInfo> {
    Some(PluginInfo {
        path: path.to_owned(),
        name: p.string()?,
        model_version: p.string()?,
        abi_major: p.u64()?.try_into().ok()?,
        abi_minor: p.u64()?.try_into().ok()?,
        capabilities: p.u64()?,
        state_size: p.usize()?,
        has_batch: p.u8()? != 0,
    })
}

fn write_config(w: &mut Wire, c: &Config) {
    w.list_i64(&c.integer_data);
    w.list_f64(&c.real_data);
    for list in [
        &c.grid.gaps,
        &c.grid.pressures,
        &c.grid.temps_a,
        &c.grid.temps_b,
    ] {
        w.list_f64(list);
    }
    w.f64(c.rtol);
}

fn read_config(p: &mut Parse<'_>) -> Option<Config> {
    Some(Config {
        integer_data: p.list_i64()?,
        real_data: p.list_f64()?,
        grid: Grid {
            gaps: p.list_f64()?,
            pressures: p.list_f64()?,
            temps_a: p.list_f64()?,
            temps_b: p.list_f64()?,
        },
        rtol: p.f64()?,
    })
}

fn write_report(w: &mut Wire, r: &Report) {
    w.str(&r.name);
    w.str(&r.model_version);
    w.u64(r.capabilities);
    w.usize(r.points);
    w.usize(r.derivatives_checked);
    w.f64(r.max_derivative_error);
    w.u8(r.batch_checked.into());
    w.u8(r.threads_checked.into());
    w.usize(r.failures.len());
    for f in &r.failures {
        w.str(f);
    }
    w.usize(r.failure_count);
}

fn read_report(p: &mut Parse<'_>) -> Option<Report> {
    let mut r = Report {
        name: p.string()?,
        model_version: p.string()?,
        capabilities: p.u64()?,
        points: p.usize()?,
        derivatives_checked: p.usize()?,
        max_derivative_error: p.f64()?,
        batch_checked: p.u8()? != 0,
        threads_checked: p.u8()? != 0,
        ..Report::default()
    };
    let n = p.count(8)?;
    for _ in 0..n {
        r.failures.push(p.string()?);
    }
    r.failure_count = p.usize()?;
    Some(r)
}

/// The fixed-size numbers of one point, in wire order.
const POINT_F64S: usize = 16;

/// # Safety
/// Every pointer of every input is valid for its count (as the host builds them).
unsafe fn write_points(w: &mut Wire, ins: &[SeamPointIn], batch: bool) {
    let first = ins.first().copied().unwrap_or_else(SeamPointIn::new);
    let text = |p: *const std::ffi::c_char| {
        if p.is_null() {
            Vec::new()
        } else {
            // SAFETY: the host's surface names are NUL-terminated and live for the call.
            unsafe { std::ffi::CStr::from_ptr(p) }.to_bytes().to_vec()
        }
    };
    w.u8(EVALUATE);
    w.u8(batch.into());
    w.usize(ins.len());
    w.usize(first.n_fields);
    w.usize(first.n_integer);
    w.usize(first.n_real);
    w.usize(first.n_state);
    // The host passes one interaction per call: the names of the first point.
    w.bytes(&text(first.surface_a));
    w.bytes(&text(first.surface_b));
    let slice_f64 = |p: *const f64, n: usize| -> &[f64] {
        if n == 0 || p.is_null() {
            &[]
        } else {
            // SAFETY: by the caller's contract.
            unsafe { std::slice::from_raw_parts(p, n) }
        }
    };
    for s in ins {
        w.f64s(&[s.gap, s.pressure, s.temp_a, s.temp_b]);
        w.f64s(&s.x);
        w.f64s(&s.normal_a);
        w.f64s(&s.normal_b);
        w.f64s(&[s.weight, s.time, s.dt]);
        w.i64(s.step);
        w.i64(s.iteration);
        w.f64s(slice_f64(s.fields, first.n_fields));
        if first.n_integer > 0 && !s.integer_data.is_null() {
            // SAFETY: by the caller's contract.
            w.i64s(unsafe { std::slice::from_raw_parts(s.integer_data, first.n_integer) });
        } else {
            w.i64s(&vec![0; first.n_integer]);
        }
        w.f64s(slice_f64(s.real_data, first.n_real));
        w.f64s(slice_f64(s.state_old, first.n_state));
        w.f64s(slice_f64(s.state_new, first.n_state));
    }
}

// --- the parent's side -------------------------------------------------------------------

/// How a request to the worker failed: the child died, or could not be (re)started.
pub(super) struct Death {
    pub how: String,
    /// The point of the request being evaluated when it died, when the worker knew it.
    pub point: Option<usize>,
}

struct Live {
    child: Child,
    /// Buffered: a frame's length and payload in one read.
    stream: BufReader<UnixStream>,
}

/// A plugin instance in a worker process, started again after it dies.
pub(super) struct Worker {
    program: PathBuf,
    path: PathBuf,
    data: PluginData,
    live: Option<Live>,
    deaths: usize,
    buf: Vec<u8>,
}

impl Drop for Worker {
    fn drop(&mut self) {
        if let Some(mut live) = self.live.take() {
            // End of input: the worker finalises the instance and exits.
            let _ = live.stream.get_ref().shutdown(std::net::Shutdown::Both);
            drop(live.stream);
            let _ = reap(&mut live.child, Duration::from_secs(2));
        }
    }
}

/// Wait for `child` up to `patience`, then kill it; its status.
fn reap(child: &mut Child, patience: Duration) -> std::io::Result<ExitStatus> {
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait()? {
            return Ok(status);
        }
        if start.elapsed() >= patience {
            let _ = child.kill();
            return child.wait();
        }
        std::thread::sleep(Duration::from_millis(1));
    }
}

/// `was killed by SIGSEGV (invalid memory access)`, `ended with exit status 0`; with
/// `in_plugin` (it died in a plugin call) an exit says what ends a process there.
fn describe(status: &ExitStatus, in_plugin: bool) -> String {
    if let Some(sig) = status.signal() {
        let Some(name) = super::guard::signal_name(sig) else {
            return format!("was killed by signal {sig}");
        };
        return format!("was killed by {name}");
    }
    match status.code() {
        Some(code) if in_plugin => format!(
            "ended with exit status {code} (the plugin called exit, as a Fortran STOP does)"
        ),
        Some(code) => format!("ended with exit status {code}"),
        None => format!("ended ({status})"),
    }
}

impl Worker {
    /// Start a worker for the library at `path` with `data`; the plugin's descriptor, or
    /// the load error the worker met (the in-process message).
    pub(super) fn start(
        path: &Path,
        data: &PluginData,
    ) -> Result<(Worker, PluginInfo), PluginError> {
        let program = worker_program().map_err(|tried| PluginError::NoWorker {
            path: path.to_owned(),
            tried,
        })?;
        let mut w = Worker {
            program,
            path: path.to_owned(),
            data: data.clone(),
            live: None,
            deaths: 0,
            buf: Vec::new(),
        };
        let info = w.spawn()?;
        Ok((w, info))
    }

    fn spawn(&mut self) -> Result<PluginInfo, PluginError> {
        let (path, program) = (self.path.clone(), self.program.clone());
        let worker_error = |how: String| PluginError::Worker {
            path: path.clone(),
            program: program.clone(),
            how,
        };
        let (mine, theirs) =
            UnixStream::pair().map_err(|e| worker_error(format!("has no socket: {e}")))?;
        let theirs: OwnedFd = theirs.into();
        let child = Command::new(&program)
            .arg(WORKER_SUBCOMMAND)
            .stdin(Stdio::from(theirs))
            .stdout(Stdio::inherit())
            .stderr(Stdio::inherit())
            .spawn()
            .map_err(|e| worker_error(format!("could not be started: {e}")))?;
        let mut live = Live {
            child,
            stream: BufReader::new(mine),
        };
        let mut w = Wire::default();
        w.0.extend_from_slice(MAGIC);
        w.u8(LOAD);
        w.str(&path.to_string_lossy());
        match &self.data.model {
            Some(m) => {
                w.u8(1);
                w.str(m);
            }
            None => w.u8(0),
        }
        w.list_i64(&self.data.integer_data);
        w.list_f64(&self.data.real_data);
        let fd = live.stream.get_ref().as_raw_fd();
        // The worker greets before it loads, then answers the load.
        let hello =
            send_frame(fd, &mut w, true).and_then(|()| read_frame(&mut live.stream, &mut self.buf));
        // Killed when it may still be running (it said something else); else reaped as it
        // ends (`reap` kills it after a while all the same).
        let fail = |mut live: Live, what: &str, kill: bool| {
            if kill {
                let _ = live.child.kill();
            }
            let how = reap(&mut live.child, Duration::from_secs(2)).map_or_else(
                |e| format!("could not be waited for: {e}"),
                |s| describe(&s, false),
            );
            worker_error(format!("{what}: it {how}"))
        };
        if hello.is_err() || self.buf != MAGIC {
            return Err(fail(
                live,
                "is not a seam plugin worker (no greeting)",
                hello.is_ok(),
            ));
        }
        let loaded = read_frame(&mut live.stream, &mut self.buf);
        if loaded.is_err() || self.buf.first() == Some(&DIED_TAG) {
            return Err(fail(
                live,
                "died while loading the plugin (its initialisers, entry point or init)",
                false,
            ));
        }
        let mut p = Parse { buf: &self.buf };
        let fail = |live: Live| fail(live, "answered the load out of protocol", true);
        match p.u8() {
            Some(OK) => match read_info(&mut p, &path) {
                Some(info) => {
                    self.live = Some(live);
                    Ok(info)
                }
                None => Err(fail(live)),
            },
            Some(ERR) => {
                let message = p.string().unwrap_or_default();
                let _ = reap(&mut live.child, Duration::from_secs(2));
                Err(PluginError::Isolated { message })
            }
            _ => Err(fail(live)),
        }
    }

    /// Send `request`, read the answer into `self.buf`; on any failure, reap the child
    /// and say how it died.
    fn request(&mut self, request: &mut Wire) -> Result<(), Death> {
        if self.live.is_none() {
            if self.deaths >= MAX_DEATHS {
                return Err(Death {
                    how: format!("has died {} times; it is not started again", self.deaths),
                    point: None,
                });
            }
            if let Err(e) = self.spawn() {
                // A failed start counts as a death: no endless restarts.
                self.deaths += 1;
                return Err(Death {
                    how: format!("could not be started again: {e}"),
                    point: None,
                });
            }
        }
        let Some(live) = self.live.as_mut() else {
            return Err(Death {
                how: "is not running".into(),
                point: None,
            });
        };
        let fd = live.stream.get_ref().as_raw_fd();
        let result = send_frame(fd, request, true)
            .and_then(|()| read_frame(&mut live.stream, &mut self.buf));
        // A worker dying in the plugin leaves a note first: the point it was at.
        let mut point = None;
        let result = match result {
            Ok(()) if self.buf.first() == Some(&DIED_TAG) => {
                let mut p = Parse {
                    buf: &self.buf[1..],
                };
                point = p.u64().and_then(|k| usize::try_from(k).ok());
                // Then the end of the channel, when the process is gone.
                read_frame(&mut live.stream, &mut self.buf)
            }
            other => other,
        };
        match result {
            Ok(()) if self.buf.first() == Some(&OK) && point.is_none() => Ok(()),
            other => {
                let Some(mut live) = self.live.take() else {
                    return Err(Death {
                        how: "is not running".into(),
                        point,
                    });
                };
                let protocol = other.is_ok();
                if protocol {
                    let _ = live.child.kill();
                }
                self.deaths += 1;
                let status = reap(&mut live.child, Duration::from_secs(2));
                let mut how = status.map_or_else(
                    |e| format!("could not be waited for: {e}"),
                    |s| describe(&s, true),
                );
                if protocol {
                    how = format!("answered out of protocol and {how}");
                }
                how.push_str(if self.deaths >= MAX_DEATHS {
                    "; it is not started again"
                } else {
                    "; a new process serves the next call"
                });
                Err(Death { how, point })
            }
        }
    }

    /// Evaluate `ins` in the worker; write `outs` and each point's new state.
    ///
    /// # Safety
    /// Every pointer of every input is valid for its count, `state_new` writable.
    pub(super) unsafe fn evaluate(
        &mut self,
        ins: &[SeamPointIn],
        outs: &mut [SeamPointOut],
        batch: bool,
    ) -> Result<(), Death> {
        let mut w = Wire::with_capacity(64 + ins.len() * 200);
        // SAFETY: by the caller's contract.
        unsafe { write_points(&mut w, ins, batch) };
        self.request(&mut w)?;
        let ns = ins.first().map_or(0, |s| s.n_state);
        let mut p = Parse {
            buf: &self.buf[1..],
        };
        let mut state = Vec::with_capacity(ns);
        for (s, o) in ins.iter().zip(outs.iter_mut()) {
            let ok = (|| {
                o.status = p.i32()?;
                o.value = p.f64()?;
                o.d_temp_a = p.f64()?;
                o.d_temp_b = p.f64()?;
                o.d_gap = p.f64()?;
                o.d_pressure = p.f64()?;
                o.cutback_factor = p.f64()?;
                let message = p.bytes()?;
                let n = message.len().min(SEAM_MESSAGE_LEN - 1);
                for (c, &b) in o.message.iter_mut().zip(&message[..n]) {
                    *c = b as std::ffi::c_char;
                }
                o.message[n] = 0;
                state.clear();
                p.f64s_into(ns, &mut state)
            })();
            if ok.is_none() {
                return Err(Death {
                    how: "answered out of protocol (a short reply)".into(),
                    point: None,
                });
            }
            if ns > 0 && !s.state_new.is_null() {
                // SAFETY: by the caller's contract, state_new holds n_state doubles.
                unsafe { std::slice::from_raw_parts_mut(s.state_new, ns) }.copy_from_slice(&state);
            }
        }
        Ok(())
    }

    /// The conformance kit, run in the worker.
    pub(super) fn conformance(&mut self, config: &Config) -> Result<Report, Death> {
        let mut w = Wire::default();
        w.u8(CONFORMANCE);
        write_config(&mut w, config);
        self.request(&mut w)?;
        read_report(&mut Parse {
            buf: &self.buf[1..],
        })
        .ok_or_else(|| Death {
            how: "answered out of protocol (a short report)".into(),
            point: None,
        })
    }
}

// --- the child's side --------------------------------------------------------------------

/// Serve one plugin on standard input (see the module's documentation); the process's
/// exit code. What `seam plugin-worker` runs. Crashes inside the plugin are not caught
/// here: the process dies and the parent reports how.
pub fn serve_worker() -> i32 {
    // The protocol on a duplicate of stdin; stdout to stderr, stdin from /dev/null.
    // SAFETY: plain descriptor calls on the process's own standard descriptors.
    let chan = unsafe {
        let chan = libc::dup(0);
        libc::dup2(2, 1);
        let null = libc::open(c"/dev/null".as_ptr(), libc::O_RDONLY);
        if null >= 0 {
            libc::dup2(null, 0);
            libc::close(null);
        }
        chan
    };
    if chan < 0 {
        eprintln!("seam plugin-worker: no protocol channel on standard input");
        return 2;
    }
    // A crash or an exit in the plugin leaves a note with the point on the channel.
    super::guard::report_to_worker(chan);
    // SAFETY: `chan` was just duplicated and is owned here.
    let mut input = BufReader::new(unsafe { std::fs::File::from_raw_fd(chan) });
    let mut buf = Vec::new();
    if read_frame(&mut input, &mut buf).is_err() {
        return 2;
    }
    let mut p = Parse { buf: &buf };
    if p.take(MAGIC.len()) != Some(MAGIC.as_slice()) || p.u8() != Some(LOAD) {
        eprintln!("seam plugin-worker: not spoken to by a seam host (protocol {MAGIC:?})");
        return 2;
    }
    let request = (|| {
        let path = PathBuf::from(p.string()?);
        let model = match p.u8()? {
            0 => None,
            _ => Some(p.string()?),
        };
        let data = PluginData {
            model,
            integer_data: p.list_i64()?,
            real_data: p.list_f64()?,
        };
        Some((path, data))
    })();
    let Some((path, data)) = request else {
        return 2;
    };
    let mut w = Wire::default();
    w.0.extend_from_slice(MAGIC);
    if send_frame(chan, &mut w, false).is_err() {
        return 2;
    }
    let mut w = Wire::default();
    let plugin = match Plugin::load_with(&path, &data) {
        Ok(plugin) => {
            w.u8(OK);
            write_info(&mut w, plugin.info());
            plugin
        }
        Err(e) => {
            w.u8(ERR);
            w.str(&e.to_string());
            let _ = send_frame(chan, &mut w, false);
            return 0;
        }
    };
    if send_frame(chan, &mut w, false).is_err() {
        return 2;
    }
    let mut scratch = Scratch::default();
    loop {
        if read_frame(&mut input, &mut buf).is_err() {
            // The parent closed the channel (or went away): finalise and end.
            return 0;
        }
        let mut p = Parse { buf: &buf };
        let mut w = Wire::with_capacity(buf.len());
        w.u8(OK);
        let served = match p.u8() {
            Some(EVALUATE) => scratch.evaluate(&plugin, &mut p, &mut w),
            Some(CONFORMANCE) => read_config(&mut p).map(|config| {
                write_report(&mut w, &plugin.conformance_in_process(&config));
            }),
            _ => None,
        };
        if served.is_none() {
            eprintln!("seam plugin-worker: a request out of protocol");
            return 2;
        }
        if send_frame(chan, &mut w, false).is_err() {
            return 0;
        }
    }
}

/// The child's buffers, kept between calls.
#[derive(Default)]
struct Scratch {
    numbers: Vec<f64>,
    steps: Vec<i64>,
    fields: Vec<f64>,
    integer: Vec<i64>,
    real: Vec<f64>,
    old: Vec<f64>,
    new: Vec<f64>,
    surface_a: CString,
    surface_b: CString,
    ins: Vec<SeamPointIn>,
    outs: Vec<SeamPointOut>,
}

impl Scratch {
    /// One evaluate request: re-create the points, call the plugin, write the outputs.
    fn evaluate(&mut self, plugin: &Plugin, p: &mut Parse<'_>, w: &mut Wire) -> Option<()> {
        let batch = self.decode(p)?;
        let s = self;
        let ns = s.ins.first().map_or(0, |q| q.n_state);
        s.outs.clear();
        s.outs.resize(s.ins.len(), SeamPointOut::new());
        plugin.call_in_process(&s.ins, &mut s.outs, batch);
        for (i, o) in s.outs.iter().enumerate() {
            w.i32(o.status);
            w.f64s(&[
                o.value,
                o.d_temp_a,
                o.d_temp_b,
                o.d_gap,
                o.d_pressure,
                o.cutback_factor,
            ]);
            let message: Vec<u8> = if o.status == SEAM_STATUS_OK {
                Vec::new()
            } else {
                o.message
                    .iter()
                    .take_while(|&&c| c != 0)
                    .map(|&c| c as u8)
                    .collect()
            };
            w.bytes(&message);
            w.f64s(&s.new[i * ns..(i + 1) * ns]);
        }
        Some(())
    }

    /// Re-create the points of an evaluate request (after its tag) in `self.ins`; whether
    /// to use the batch entry. `None`: out of protocol (sizes and length disagree).
    fn decode(&mut self, p: &mut Parse<'_>) -> Option<bool> {
        let batch = p.u8()? != 0;
        let n = p.usize()?;
        let (nf, ni, nr, ns) = (p.usize()?, p.usize()?, p.usize()?, p.usize()?);
        let per_point = POINT_F64S
            .checked_add(2)?
            .checked_add(nf)?
            .checked_add(ni)?
            .checked_add(nr)?
            .checked_add(ns.checked_mul(2)?)?
            .checked_mul(8)?;
        self.surface_a = CString::new(p.bytes()?).ok()?;
        self.surface_b = CString::new(p.bytes()?).ok()?;
        if n.checked_mul(per_point)? != p.buf.len() {
            return None;
        }
        let s = self;
        for v in [
            &mut s.numbers,
            &mut s.fields,
            &mut s.real,
            &mut s.old,
            &mut s.new,
        ] {
            v.clear();
        }
        s.steps.clear();
        s.integer.clear();
        for _ in 0..n {
            p.f64s_into(POINT_F64S, &mut s.numbers)?;
            s.steps.push(p.i64()?);
            s.steps.push(p.i64()?);
            p.f64s_into(nf, &mut s.fields)?;
            p.i64s_into(ni, &mut s.integer)?;
            p.f64s_into(nr, &mut s.real)?;
            p.f64s_into(ns, &mut s.old)?;
            p.f64s_into(ns, &mut s.new)?;
        }
        s.ins.clear();
        for i in 0..n {
            let v = &s.numbers[i * POINT_F64S..(i + 1) * POINT_F64S];
            let mut q = SeamPointIn::new();
            (q.gap, q.pressure, q.temp_a, q.temp_b) = (v[0], v[1], v[2], v[3]);
            q.x = [v[4], v[5], v[6]];
            q.normal_a = [v[7], v[8], v[9]];
            q.normal_b = [v[10], v[11], v[12]];
            (q.weight, q.time, q.dt) = (v[13], v[14], v[15]);
            (q.step, q.iteration) = (s.steps[2 * i], s.steps[2 * i + 1]);
            q.surface_a = s.surface_a.as_ptr();
            q.surface_b = s.surface_b.as_ptr();
            if nf > 0 {
                q.fields = s.fields[i * nf..].as_ptr();
                q.n_fields = nf;
            }
            q.integer_data = s.integer[i * ni..].as_ptr();
            q.n_integer = ni;
            q.real_data = s.real[i * nr..].as_ptr();
            q.n_real = nr;
            if ns > 0 {
                q.state_old = s.old[i * ns..].as_ptr();
                q.state_new = s.new[i * ns..].as_mut_ptr();
                q.n_state = ns;
            }
            s.ins.push(q);
        }
        Some(batch)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_and_config_survive_the_wire() {
        let report = Report {
            name: "m".into(),
            model_version: "1.2".into(),
            capabilities: 5,
            points: 54,
            derivatives_checked: 216,
            max_derivative_error: 3.5e-9,
            batch_checked: true,
            threads_checked: false,
            failures: vec!["a".into(), "b é".into()],
            failure_count: 7,
        };
        let mut w = Wire::default();
        write_report(&mut w, &report);
        assert_eq!(read_report(&mut Parse { buf: &w.0[4..] }), Some(report));
        let config = Config {
            integer_data: vec![-1, 2],
            real_data: vec![f64::MIN_POSITIVE, -0.0],
            ..Config::default()
        };
        let mut w = Wire::default();
        write_config(&mut w, &config);
        let back = read_config(&mut Parse { buf: &w.0[4..] }).unwrap();
        assert_eq!(back, config);
        assert!(back.real_data[1].is_sign_negative(), "bits, not values");
    }

    /// Every cut of a valid payload, and a count larger than the payload, is refused
    /// without a panic or a huge allocation.
    #[test]
    fn short_or_lying_payloads_are_refused() {
        let mut w = Wire::default();
        write_report(
            &mut w,
            &Report {
                failures: vec!["x".into()],
                failure_count: 1,
                ..Report::default()
            },
        );
        let payload = &w.0[4..];
        for cut in 0..payload.len() {
            assert_eq!(
                read_report(&mut Parse {
                    buf: &payload[..cut]
                }),
                None,
                "{cut}"
            );
        }
        let mut lying = Wire::default();
        lying.u64(u64::MAX);
        assert_eq!(Parse { buf: &lying.0[4..] }.list_f64(), None);
        assert_eq!(Parse { buf: &lying.0[4..] }.string(), None);
    }

    /// A request whose sizes disagree with its length is refused by the worker before
    /// any call; a consistent one is re-created with the sender's numbers.
    #[test]
    fn evaluate_requests_are_checked_and_recreated() {
        let data = [1.5, 2.5];
        let mut state_new = [0.0; 1];
        let old = [7.0];
        let mut q = SeamPointIn::new();
        (q.gap, q.pressure, q.x, q.step) = (1e-6, 3e5, [1.0, 2.0, 3.0], 4);
        q.surface_a = c"top".as_ptr();
        q.surface_b = c"bottom".as_ptr();
        (q.real_data, q.n_real) = (data.as_ptr(), 2);
        (q.state_old, q.state_new, q.n_state) = (old.as_ptr(), state_new.as_mut_ptr(), 1);
        let mut w = Wire::default();
        // SAFETY: the pointers above are valid for their counts.
        unsafe { write_points(&mut w, &[q, q], true) };
        let payload = &w.0[5..]; // after the length and the request tag
        let mut scratch = Scratch::default();
        let batch = scratch.decode(&mut Parse { buf: payload });
        assert_eq!(batch, Some(true));
        assert_eq!(scratch.ins.len(), 2);
        let r = scratch.ins[1];
        assert_eq!(
            (r.gap, r.pressure, r.x, r.step),
            (q.gap, q.pressure, q.x, q.step)
        );
        // SAFETY: re-created by `decode`, alive in `scratch`.
        unsafe {
            assert_eq!(std::ffi::CStr::from_ptr(r.surface_b), c"bottom");
            assert_eq!(*r.real_data.add(1), 2.5);
            assert_eq!(*r.state_old, 7.0);
        }
        for cut in [0, 1, payload.len() - 1] {
            let mut short = Scratch::default();
            assert_eq!(
                short.decode(&mut Parse {
                    buf: &payload[..cut]
                }),
                None
            );
        }
        let mut long = payload.to_vec();
        long.push(0);
        assert_eq!(Scratch::default().decode(&mut Parse { buf: &long }), None);
    }
}
