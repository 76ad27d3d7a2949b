//! netCDF classic files in the 64-bit-offset variant (CDF-2), written without the C
//! library: a [`Schema`] of dimensions, attributes and variables is laid out once, its
//! header encoded, and the caller then writes each fixed variable's data in definition
//! order and appends records.
//!
//! Format (netCDF "classic format specification"): big-endian throughout; the header is
//! `CDF\x02`, `numrecs`, the dimension, global-attribute and variable lists; every name
//! and attribute value is padded to 4 bytes; each variable's header entry holds its
//! `vsize` (bytes of one variable, or of one record of it, padded to 4) and its `begin`
//! (64-bit file offset). Fixed-size data follows the header in definition order; record
//! data comes last, one record after another, each record holding a slice of every
//! record variable in definition order. A dimension of length 0 is the record
//! (unlimited) dimension, so a real dimension of length 0 cannot exist: callers leave
//! out what would be empty.

use std::io;

/// External types used by the writers (netCDF `nc_type` codes).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum NcType {
    Char = 2,
    Int = 4,
    Float = 5,
    Double = 6,
}

impl NcType {
    pub(crate) fn size(self) -> u64 {
        match self {
            NcType::Char => 1,
            NcType::Int | NcType::Float => 4,
            NcType::Double => 8,
        }
    }
}

/// An attribute value.
#[derive(Clone, Debug)]
pub(crate) enum AttrValue {
    Text(String),
    Ints(Vec<i32>),
    Floats(Vec<f32>),
}

#[derive(Clone, Debug)]
struct Dim {
    name: String,
    /// 0 for the record dimension.
    len: u64,
}

#[derive(Clone, Debug)]
struct Var {
    name: String,
    dims: Vec<usize>,
    ty: NcType,
    attrs: Vec<(String, AttrValue)>,
}

/// Dimensions, global attributes and variables of a file, in definition order.
#[derive(Clone, Debug, Default)]
pub(crate) struct Schema {
    dims: Vec<Dim>,
    gatts: Vec<(String, AttrValue)>,
    vars: Vec<Var>,
}

/// Where each variable lives: the result of [`Schema::layout`].
#[derive(Clone, Debug)]
pub(crate) struct Layout {
    /// Per variable, in definition order: `vsize` and `begin`.
    pub(crate) vsize: Vec<u64>,
    pub(crate) begin: Vec<u64>,
    /// Bytes of one record (all record variables' slices).
    pub(crate) record_size: u64,
    /// Offset of record 0.
    pub(crate) record_begin: u64,
    /// The encoded header with `numrecs = 0`.
    pub(crate) header: Vec<u8>,
}

/// Offset of `numrecs` in the header.
pub(crate) const NUMRECS_OFFSET: u64 = 4;

const NC_DIMENSION: u32 = 0x0A;
const NC_VARIABLE: u32 = 0x0B;
const NC_ATTRIBUTE: u32 = 0x0C;

impl Schema {
    /// Add a dimension; `len = 0` makes it the record dimension (at most one).
    pub(crate) fn dim(&mut self, name: &str, len: u64) -> usize {
        self.dims.push(Dim {
            name: name.to_string(),
            len,
        });
        self.dims.len() - 1
    }

    pub(crate) fn global(&mut self, name: &str, value: AttrValue) {
        self.gatts.push((name.to_string(), value));
    }

    pub(crate) fn var(&mut self, name: &str, dims: &[usize], ty: NcType) -> usize {
        self.vars.push(Var {
            name: name.to_string(),
            dims: dims.to_vec(),
            ty,
            attrs: Vec::new(),
        });
        self.vars.len() - 1
    }

    pub(crate) fn var_attr(&mut self, var: usize, name: &str, value: AttrValue) {
        self.vars[var].attrs.push((name.to_string(), value));
    }

    pub(crate) fn var_name(&self, var: usize) -> &str {
        &self.vars[var].name
    }

    pub(crate) fn var_type(&self, var: usize) -> NcType {
        self.vars[var].ty
    }

    pub(crate) fn is_record(&self, var: usize) -> bool {
        self.vars[var]
            .dims
            .first()
            .is_some_and(|&d| self.dims[d].len == 0)
    }

    /// Number of values of a fixed variable, or of one record of a record variable.
    pub(crate) fn count(&self, var: usize) -> u64 {
        self.vars[var]
            .dims
            .iter()
            .map(|&d| self.dims[d].len)
            .filter(|&l| l > 0)
            .product()
    }

    /// Place every variable: fixed ones after the header in definition order, record
    /// ones inside the record in definition order. Errors when a variable is too large
    /// for CDF-2 (a `vsize` is 32 bits).
    pub(crate) fn layout(&self) -> io::Result<Layout> {
        let mut vsize = Vec::with_capacity(self.vars.len());
        for (k, v) in self.vars.iter().enumerate() {
            let bytes = self.count(k) * v.ty.size();
            let padded = bytes.div_ceil(4) * 4;
            if padded > u32::MAX as u64 - 3 {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidInput,
                    format!(
                        "netCDF variable `{}` needs {bytes} bytes, more than the 4 GiB a \
                         64-bit-offset file allows per variable; split the model or write VTU",
                        v.name
                    ),
                ));
            }
            vsize.push(padded);
        }
        let header_len = self.encode(0, &vsize, &vec![0; self.vars.len()]).len() as u64;
        let mut begin = vec![0; self.vars.len()];
        let mut cursor = header_len;
        for k in 0..self.vars.len() {
            if !self.is_record(k) {
                begin[k] = cursor;
                cursor += vsize[k];
            }
        }
        let record_begin = cursor;
        let mut record_size = 0;
        for k in 0..self.vars.len() {
            if self.is_record(k) {
                begin[k] = record_begin + record_size;
                record_size += vsize[k];
            }
        }
        let header = self.encode(0, &vsize, &begin);
        debug_assert_eq!(header.len() as u64, header_len);
        Ok(Layout {
            vsize,
            begin,
            record_size,
            record_begin,
            header,
        })
    }

    fn encode(&self, numrecs: u32, vsize: &[u64], begin: &[u64]) -> Vec<u8> {
        let mut h = Vec::with_capacity(1024);
        h.extend_from_slice(b"CDF\x02");
        put_u32(&mut h, numrecs);
        if self.dims.is_empty() {
            put_u32(&mut h, 0);
            put_u32(&mut h, 0);
        } else {
            put_u32(&mut h, NC_DIMENSION);
            put_u32(&mut h, self.dims.len() as u32);
            for d in &self.dims {
                put_name(&mut h, &d.name);
                put_u32(&mut h, d.len as u32);
            }
        }
        put_attrs(&mut h, &self.gatts);
        if self.vars.is_empty() {
            put_u32(&mut h, 0);
            put_u32(&mut h, 0);
        } else {
            put_u32(&mut h, NC_VARIABLE);
            put_u32(&mut h, self.vars.len() as u32);
            for (k, v) in self.vars.iter().enumerate() {
                put_name(&mut h, &v.name);
                put_u32(&mut h, v.dims.len() as u32);
                for &d in &v.dims {
                    put_u32(&mut h, d as u32);
                }
                put_attrs(&mut h, &v.attrs);
                put_u32(&mut h, v.ty as u32);
                put_u32(&mut h, vsize[k] as u32);
                h.extend_from_slice(&begin[k].to_be_bytes());
            }
        }
        h
    }
}

fn put_u32(h: &mut Vec<u8>, v: u32) {
    h.extend_from_slice(&v.to_be_bytes());
}

fn pad4(h: &mut Vec<u8>) {
    while !h.len().is_multiple_of(4) {
        h.push(0);
    }
}

fn put_name(h: &mut Vec<u8>, name: &str) {
    put_u32(h, name.len() as u32);
    h.extend_from_slice(name.as_bytes());
    pad4(h);
}

fn put_attrs(h: &mut Vec<u8>, attrs: &[(String, AttrValue)]) {
    if attrs.is_empty() {
        put_u32(h, 0);
        put_u32(h, 0);
        return;
    }
    put_u32(h, NC_ATTRIBUTE);
    put_u32(h, attrs.len() as u32);
    for (name, value) in attrs {
        put_name(h, name);
        match value {
            AttrValue::Text(s) => {
                put_u32(h, NcType::Char as u32);
                put_u32(h, s.len() as u32);
                h.extend_from_slice(s.as_bytes());
            }
            AttrValue::Ints(v) => {
                put_u32(h, NcType::Int as u32);
                put_u32(h, v.len() as u32);
                for x in v {
                    h.extend_from_slice(&x.to_be_bytes());
                }
            }
            AttrValue::Floats(v) => {
                put_u32(h, NcType::Float as u32);
                put_u32(h, v.len() as u32);
                for x in v {
                    h.extend_from_slice(&x.to_be_bytes());
                }
            }
        }
        pad4(h);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The byte layout of a tiny file, worked out by hand from the format specification:
    /// one fixed `x(n=3)` int and one record `t(time)` double.
    #[test]
    fn header_and_layout_follow_the_specification() {
        let mut s = Schema::default();
        let time = s.dim("time", 0);
        let n = s.dim("n", 3);
        s.var("x", &[n], NcType::Int);
        s.var("t", &[time], NcType::Double);
        let l = s.layout().unwrap();
        // magic 4 + numrecs 4 + dim list (8 + "time" 8+4 + "n" 8+4) + absent gatts 8
        // + var list 8 + x (8 name + 4 ndims + 4 dimid + 8 no attrs + 4 type + 4 vsize + 8)
        // + t (same size).
        let expect_header = 4 + 4 + (8 + 12 + 12) + 8 + 8 + 2 * 40;
        assert_eq!(l.header.len(), expect_header);
        assert_eq!(&l.header[..4], b"CDF\x02");
        assert_eq!(l.vsize, vec![12, 8]);
        assert_eq!(l.begin[0], expect_header as u64);
        assert_eq!(l.record_begin, expect_header as u64 + 12);
        assert_eq!(l.begin[1], l.record_begin);
        assert_eq!(l.record_size, 8);
    }
}
