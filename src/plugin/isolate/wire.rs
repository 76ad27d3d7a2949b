//! The wire format between parent and worker: length-prefixed frames, numbers
//! little-endian, `f64` as their bits; the plugin's descriptor, the conformance kit's
//! configuration and report, and a call's points with the contents of their pointers.

use std::io::Read;
use std::path::Path;

use seam_plugin_abi::SeamPointIn;
use seam_plugin_testkit::{Config, Grid, Report};

use crate::plugin::PluginInfo;

use super::{EVALUATE, MAX_FRAME};

/// A frame being written: 4 bytes kept for the length, then the payload.
pub(super) struct Wire(pub(super) Vec<u8>);

impl Default for Wire {
    fn default() -> Self {
        Wire::with_capacity(64)
    }
}

impl Wire {
    pub(super) fn with_capacity(n: usize) -> Self {
        let mut v = Vec::with_capacity(n + 4);
        v.extend_from_slice(&[0; 4]);
        Wire(v)
    }

    pub(super) fn u8(&mut self, v: u8) {
        self.0.push(v);
    }
    pub(super) fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(super) fn usize(&mut self, v: usize) {
        self.u64(v as u64);
    }
    pub(super) fn i64(&mut self, v: i64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(super) fn i32(&mut self, v: i32) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(super) fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_bits().to_le_bytes());
    }
    pub(super) fn f64s(&mut self, v: &[f64]) {
        for &x in v {
            self.f64(x);
        }
    }
    pub(super) fn i64s(&mut self, v: &[i64]) {
        for &x in v {
            self.i64(x);
        }
    }
    pub(super) fn bytes(&mut self, v: &[u8]) {
        self.usize(v.len());
        self.0.extend_from_slice(v);
    }
    pub(super) fn str(&mut self, v: &str) {
        self.bytes(v.as_bytes());
    }
    pub(super) fn list_f64(&mut self, v: &[f64]) {
        self.usize(v.len());
        self.f64s(v);
    }
    pub(super) fn list_i64(&mut self, v: &[i64]) {
        self.usize(v.len());
        self.i64s(v);
    }
}

/// Reading a payload; `None` when it ends early (a protocol error).
pub(super) struct Parse<'a> {
    pub(super) buf: &'a [u8],
}

impl<'a> Parse<'a> {
    pub(super) fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if n > self.buf.len() {
            return None;
        }
        let (head, tail) = self.buf.split_at(n);
        self.buf = tail;
        Some(head)
    }
    pub(super) fn u8(&mut self) -> Option<u8> {
        self.take(1).map(|b| b[0])
    }
    pub(super) fn u64(&mut self) -> Option<u64> {
        self.take(8)
            .map(|b| u64::from_le_bytes(b.try_into().unwrap_or_default()))
    }
    pub(super) fn usize(&mut self) -> Option<usize> {
        self.u64().and_then(|v| usize::try_from(v).ok())
    }
    /// A count of items of `size` bytes that the rest of the payload can hold.
    pub(super) fn count(&mut self, size: usize) -> Option<usize> {
        self.usize()
            .filter(|&n| n.checked_mul(size).is_some_and(|b| b <= self.buf.len()))
    }
    pub(super) fn i64(&mut self) -> Option<i64> {
        self.u64().map(|v| v as i64)
    }
    pub(super) fn i32(&mut self) -> Option<i32> {
        self.take(4)
            .map(|b| i32::from_le_bytes(b.try_into().unwrap_or_default()))
    }
    pub(super) fn f64(&mut self) -> Option<f64> {
        self.u64().map(f64::from_bits)
    }
    pub(super) fn f64s_into(&mut self, n: usize, out: &mut Vec<f64>) -> Option<()> {
        let b = self.take(n.checked_mul(8)?)?;
        out.extend(
            b.chunks_exact(8)
                .map(|c| f64::from_bits(u64::from_le_bytes(c.try_into().unwrap_or_default()))),
        );
        Some(())
    }
    pub(super) fn i64s_into(&mut self, n: usize, out: &mut Vec<i64>) -> Option<()> {
        let b = self.take(n.checked_mul(8)?)?;
        out.extend(
            b.chunks_exact(8)
                .map(|c| i64::from_le_bytes(c.try_into().unwrap_or_default())),
        );
        Some(())
    }
    pub(super) fn bytes(&mut self) -> Option<&'a [u8]> {
        let n = self.count(1)?;
        self.take(n)
    }
    pub(super) fn string(&mut self) -> Option<String> {
        self.bytes()
            .map(|b| String::from_utf8_lossy(b).into_owned())
    }
    pub(super) fn list_f64(&mut self) -> Option<Vec<f64>> {
        let n = self.count(8)?;
        let mut v = Vec::with_capacity(n);
        self.f64s_into(n, &mut v)?;
        Some(v)
    }
    pub(super) fn list_i64(&mut self) -> Option<Vec<i64>> {
        let n = self.count(8)?;
        let mut v = Vec::with_capacity(n);
        self.i64s_into(n, &mut v)?;
        Some(v)
    }
}

/// Write all of `bytes` to `fd`; `MSG_NOSIGNAL` on sockets turns a closed peer into
/// `EPIPE` instead of a `SIGPIPE`.
pub(super) fn send_all(fd: libc::c_int, mut bytes: &[u8], socket: bool) -> std::io::Result<()> {
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
pub(super) fn send_frame(fd: libc::c_int, w: &mut Wire, socket: bool) -> std::io::Result<()> {
    let len = u32::try_from(w.0.len() - 4)
        .map_err(|_| std::io::Error::new(std::io::ErrorKind::InvalidInput, "a frame over 4 GiB"))?;
    w.0[..4].copy_from_slice(&len.to_le_bytes());
    send_all(fd, &w.0, socket)
}

pub(super) fn read_frame(r: &mut impl Read, buf: &mut Vec<u8>) -> std::io::Result<()> {
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

pub(super) fn write_info(w: &mut Wire, info: &PluginInfo) {
    w.str(&info.name);
    w.str(&info.model_version);
    w.u64(info.abi_major.into());
    w.u64(info.abi_minor.into());
    w.u64(info.capabilities);
    w.usize(info.state_size);
    w.u8(info.has_batch.into());
}

pub(super) fn read_info(p: &mut Parse<'_>, path: &Path) -> Option<PluginInfo> {
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

pub(super) fn write_config(w: &mut Wire, c: &Config) {
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

pub(super) fn read_config(p: &mut Parse<'_>) -> Option<Config> {
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

pub(super) fn write_report(w: &mut Wire, r: &Report) {
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

pub(super) fn read_report(p: &mut Parse<'_>) -> Option<Report> {
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
pub(super) const POINT_F64S: usize = 16;

/// # Safety
/// Every pointer of every input is valid for its count (as the host builds them).
pub(super) unsafe fn write_points(w: &mut Wire, ins: &[SeamPointIn], batch: bool) {
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
}
