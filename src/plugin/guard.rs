//! A plugin's last word: a plugin that crashes (a null pointer, an abort) or ends the
//! process (`exit`, as a Fortran `STOP` does) inside one of seam's calls takes the
//! process with it — that cannot be undone in-process — but it must not go silently.
//! While a plugin call runs, this module keeps on the calling thread what it is calling
//! (the library, the entry point, the interaction and the point); a signal handler and an
//! `atexit` hook print that and end the process with exit code 3 (plugin fault).
//! A crash outside a plugin call goes to the handler that was there before.
//!
//! In a plugin worker process (`Plugin Isolation = Process`, see [`super::isolate`]) the
//! report is instead a short note to the parent — the point being evaluated — and the
//! process then dies as it would have, so that the parent can say how.
//!
//! Entry points: [`guarded`]; [`report_to_worker`] in a worker. The handlers are
//! installed once, when the first plugin is loaded. What they do is async-signal-safe in practice: read a thread-local pointer,
//! format into a stack buffer (no allocation), `write(2)`, `_exit(2)`.

use std::cell::Cell;
use std::fmt::Write as _;
use std::sync::Once;
use std::sync::atomic::{AtomicI32, Ordering};

use seam_plugin_abi::SeamPointIn;

/// What the current plugin call is about.
pub(super) struct CallSite<'a> {
    /// The library's path and model name.
    pub plugin: &'a str,
    /// The entry point: `init`, `evaluate_point`, …
    pub entry: &'a str,
    /// The points of the call (empty outside evaluation).
    pub points: &'a [SeamPointIn],
    /// The point being evaluated, for per-point calls.
    pub current: Cell<Option<usize>>,
}

thread_local! {
    static SITE: Cell<*const CallSite<'static>> = const { Cell::new(std::ptr::null()) };
}

/// The signals a crashing plugin raises, and the handlers that were there before.
const SIGNALS: [libc::c_int; 5] = [
    libc::SIGSEGV,
    libc::SIGBUS,
    libc::SIGFPE,
    libc::SIGILL,
    libc::SIGABRT,
];
static mut PREVIOUS: [std::mem::MaybeUninit<libc::sigaction>; 5] =
    [const { std::mem::MaybeUninit::uninit() }; 5];
static INSTALL: Once = Once::new();
/// In a plugin worker process (see [`super::isolate`]): the protocol channel. There the
/// report is a note to the parent on that channel — the point being evaluated — and the
/// process then dies as it would have (the signal's default action, or the `exit`), so
/// that the parent sees how.
static WORKER_CHANNEL: AtomicI32 = AtomicI32::new(-1);

/// Report faults as notes on `fd` (a plugin worker's channel) from here on.
pub(super) fn report_to_worker(fd: libc::c_int) {
    WORKER_CHANNEL.store(fd, Ordering::Relaxed);
}

/// The note a worker leaves before it dies: a frame of [`DIED_TAG`] and the point of the
/// call being evaluated (`u64::MAX` when not known: a batch entry, the conformance kit).
pub(super) const DIED_TAG: u8 = 9;

/// Run `f` (a call into a plugin) with `site` on record, so that a crash or an `exit`
/// during it is reported.
pub(super) fn guarded<R>(site: &CallSite<'_>, f: impl FnOnce() -> R) -> R {
    install();
    // SAFETY: the pointer is cleared before `site` goes out of scope (below, also on
    // unwind via the reset guard); the handlers only read it while it is set.
    let erased: *const CallSite<'static> = std::ptr::from_ref(site).cast();
    let previous = SITE.with(|s| s.replace(erased));
    struct Reset(*const CallSite<'static>);
    impl Drop for Reset {
        fn drop(&mut self) {
            SITE.with(|s| s.set(self.0));
        }
    }
    let _reset = Reset(previous);
    f()
}

fn install() {
    INSTALL.call_once(|| {
        // SAFETY: installing handlers with sigaction; the previous ones are kept in
        // PREVIOUS (written here once, before any handler can run, read by the handler).
        unsafe {
            for (k, &sig) in SIGNALS.iter().enumerate() {
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = on_signal as *const () as usize;
                // On the alternate stack where the thread has one (Rust gives each of its
                // threads a small one for its stack-overflow report): the message is
                // formatted without floating-point formatting's large buffers.
                action.sa_flags = libc::SA_SIGINFO | libc::SA_ONSTACK;
                libc::sigemptyset(&mut action.sa_mask);
                let previous = &raw mut PREVIOUS;
                libc::sigaction(sig, &action, (*previous)[k].as_mut_ptr());
            }
            libc::atexit(on_exit);
        }
    });
}

/// The name of a signal that ends a process, with what it means.
pub(super) fn signal_name(sig: libc::c_int) -> Option<&'static str> {
    Some(match sig {
        libc::SIGSEGV => "SIGSEGV (invalid memory access)",
        libc::SIGBUS => "SIGBUS (bus error)",
        libc::SIGFPE => "SIGFPE (arithmetic fault)",
        libc::SIGILL => "SIGILL (illegal instruction)",
        libc::SIGABRT => "SIGABRT (abort)",
        libc::SIGKILL => "SIGKILL (killed, e.g. out of memory)",
        libc::SIGTERM => "SIGTERM (terminated)",
        _ => return None,
    })
}

extern "C" fn on_signal(sig: libc::c_int, info: *mut libc::siginfo_t, context: *mut libc::c_void) {
    let name = signal_name(sig).unwrap_or("a fatal signal");
    if report(name, "crashed with") {
        // SAFETY: ending the process without running anything else; in a worker, by the
        // signal itself (delivered with its default action when the handler returns).
        unsafe {
            if WORKER_CHANNEL.load(Ordering::Relaxed) >= 0 {
                libc::signal(sig, libc::SIG_DFL);
                libc::raise(sig);
                return;
            }
            libc::_exit(3)
        };
    }
    // Not in a plugin call: hand the signal to whoever had it before.
    // SAFETY: PREVIOUS was filled before this handler was installed.
    unsafe {
        let Some(k) = SIGNALS.iter().position(|&s| s == sig) else {
            libc::_exit(128 + sig);
        };
        let previous = &raw const PREVIOUS;
        let old = (*previous)[k].assume_init_ref();
        if old.sa_flags & libc::SA_SIGINFO != 0 && old.sa_sigaction > 1 {
            let f: extern "C" fn(libc::c_int, *mut libc::siginfo_t, *mut libc::c_void) =
                std::mem::transmute(old.sa_sigaction);
            f(sig, info, context);
        } else if old.sa_sigaction == libc::SIG_IGN {
        } else if old.sa_sigaction > 1 {
            let f: extern "C" fn(libc::c_int) = std::mem::transmute(old.sa_sigaction);
            f(sig);
        } else {
            libc::signal(sig, libc::SIG_DFL);
            libc::raise(sig);
        }
    }
}

extern "C" fn on_exit() {
    if report(
        "exit (a Fortran STOP or a call to exit)",
        "ended the process by",
    ) && WORKER_CHANNEL.load(Ordering::Relaxed) < 0
    {
        // SAFETY: as in on_signal. (A worker lets the exit go on with its status.)
        unsafe { libc::_exit(3) };
    }
}

/// A message in a fixed buffer (no allocation in a signal handler).
struct Buffer {
    bytes: [u8; 1024],
    len: usize,
}

impl std::fmt::Write for Buffer {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        let room = self.bytes.len() - self.len;
        let n = s.len().min(room);
        self.bytes[self.len..self.len + n].copy_from_slice(&s.as_bytes()[..n]);
        self.len += n;
        Ok(())
    }
}

/// Print the fault of the current plugin call; false when no plugin call is running.
fn report(what: &str, verb: &str) -> bool {
    let site = SITE.with(|s| s.get());
    if site.is_null() {
        return false;
    }
    // SAFETY: set by `guarded` for the duration of the call that faulted.
    let site = unsafe { &*site };
    let channel = WORKER_CHANNEL.load(Ordering::Relaxed);
    if channel >= 0 {
        let point = site.current.get().map_or(u64::MAX, |k| k as u64);
        let mut note = [0u8; 13];
        note[..4].copy_from_slice(&9u32.to_le_bytes());
        note[4] = DIED_TAG;
        note[5..].copy_from_slice(&point.to_le_bytes());
        // SAFETY: write(2) of a valid buffer to the worker's channel.
        unsafe {
            libc::write(channel, note.as_ptr().cast(), note.len());
        }
        return true;
    }
    let mut b = Buffer {
        bytes: [0; 1024],
        len: 0,
    };
    let _ = write!(
        b,
        "error[E0503]: plugin {} {verb} {what} in `{}`",
        site.plugin, site.entry
    );
    if let Some(p) = site.points.first() {
        let _ = write!(b, " on interaction ");
        // SAFETY: the host passes NUL-terminated surface names that live for the call.
        unsafe {
            write_c_str(&mut b, p.surface_a);
            let _ = write!(b, " / ");
            write_c_str(&mut b, p.surface_b);
        }
        match site
            .current
            .get()
            .and_then(|k| site.points.get(k).map(|q| (k, q)))
        {
            Some((k, q)) => {
                let _ = write!(b, ", at point {} of the call ", k + 1);
                write_point(&mut b, q.x);
            }
            None => {
                let last = &site.points[site.points.len() - 1];
                let _ = write!(b, ", in a batch of {} points from ", site.points.len());
                write_point(&mut b, p.x);
                let _ = b.write_str(" to ");
                write_point(&mut b, last.x);
            }
        }
    }
    let _ = write!(
        b,
        "\n  = help: the plugin took the process down with it; `seam check-plugin LIB` probes it on its own\n"
    );
    // SAFETY: write(2) of a valid buffer to stderr.
    unsafe {
        libc::write(2, b.bytes.as_ptr().cast(), b.len);
    }
    true
}

/// # Safety
/// `p` is NULL or a NUL-terminated string.
unsafe fn write_c_str(b: &mut Buffer, p: *const std::ffi::c_char) {
    if p.is_null() {
        let _ = b.write_str("?");
        return;
    }
    // SAFETY: as the caller promises.
    let s = unsafe { std::ffi::CStr::from_ptr(p) };
    let _ = b.write_str(std::str::from_utf8(s.to_bytes()).unwrap_or("?"));
}

/// `(x, y, z)` in `d.dddddde±k` form, by integer arithmetic: the standard float
/// formatting may need more stack than a signal's alternate stack has.
fn write_point(b: &mut Buffer, x: [f64; 3]) {
    let _ = b.write_str("(");
    for (k, v) in x.iter().enumerate() {
        if k > 0 {
            let _ = b.write_str(", ");
        }
        write_f64(b, *v);
    }
    let _ = b.write_str(")");
}

fn write_f64(b: &mut Buffer, v: f64) {
    if !v.is_finite() {
        let _ = b.write_str(if v.is_nan() { "NaN" } else { "inf" });
        return;
    }
    if v < 0.0 {
        let _ = b.write_str("-");
    }
    let a = v.abs();
    if a == 0.0 {
        let _ = b.write_str("0");
        return;
    }
    let mut e = a.log10().floor() as i32;
    let mut digits = (a / 10f64.powi(e) * 1e6).round() as u64;
    if digits >= 10_000_000 {
        digits /= 10;
        e += 1;
    }
    let _ = write!(b, "{}.{:06}e{}", digits / 1_000_000, digits % 1_000_000, e);
}
