//! The parent's side: the [`Worker`] that starts the child, sends requests, reaps and
//! describes a death, and starts the child again on the next call.

use std::io::BufReader;
use std::os::fd::{AsRawFd, OwnedFd};
use std::os::unix::net::UnixStream;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use seam_plugin_abi::{SEAM_MESSAGE_LEN, SeamPointIn, SeamPointOut};
use seam_plugin_testkit::{Config, Report};

use crate::plugin::guard::DIED_TAG;
use crate::plugin::{PluginData, PluginError, PluginInfo};

use super::wire::{
    Parse, Wire, read_frame, read_info, read_report, send_frame, write_config, write_points,
};
use super::{CONFORMANCE, ERR, LOAD, MAGIC, MAX_DEATHS, OK, WORKER_SUBCOMMAND, worker_program};

/// How a request to the worker failed: the child died, or could not be (re)started.
pub(in crate::plugin) struct Death {
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
pub(in crate::plugin) struct Worker {
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
        let Some(name) = crate::plugin::guard::signal_name(sig) else {
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
    pub(in crate::plugin) fn start(
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
    pub(in crate::plugin) unsafe fn evaluate(
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
    pub(in crate::plugin) fn conformance(&mut self, config: &Config) -> Result<Report, Death> {
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
