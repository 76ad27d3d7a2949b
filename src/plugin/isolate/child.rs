//! The child's side: [`serve_worker`] loads the plugin and answers requests until the
//! parent hangs up.

use std::ffi::CString;
use std::io::BufReader;
use std::os::fd::FromRawFd;
use std::path::PathBuf;

use seam_plugin_abi::{SEAM_STATUS_OK, SeamPointIn, SeamPointOut};

use crate::plugin::{Plugin, PluginData};

use super::wire::{
    POINT_F64S, Parse, Wire, read_config, read_frame, send_frame, write_info, write_report,
};
use super::{CONFORMANCE, ERR, EVALUATE, LOAD, MAGIC, OK};

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
    crate::plugin::guard::report_to_worker(chan);
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
pub(super) struct Scratch {
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
    pub(super) fn evaluate(
        &mut self,
        plugin: &Plugin,
        p: &mut Parse<'_>,
        w: &mut Wire,
    ) -> Option<()> {
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
    pub(super) fn decode(&mut self, p: &mut Parse<'_>) -> Option<bool> {
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
    use super::super::wire::write_points;
    use super::*;

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
