//! VTK XML unstructured grid (`.vtu`) writer: the mesh's blocks with point and cell
//! data, readable by ParaView and meshio; and `.pvd` collections that make a time series
//! of them.
//!
//! Entry points: [`write_vtu`] (point data, ASCII: small files stay inspectable),
//! [`write_vtu_cells`] (point and cell data, base64 "binary" inline data: computed doubles
//! take 10.7 characters instead of ~22, exact to the bit), [`write_vtu_arrays`] (arrays
//! of several components, e.g. a flux vector per cell), [`write_vtu_polygons`] (a
//! surface grid of its own, e.g. contact faces), [`PvdSeries`]. Mesh cells are written block
//! after block in mesh order, i.e. in dense element order, so cell data is indexed like
//! [`crate::mesh::ElemId`]; every mesh file carries the cell data `block_id`. Cell types by
//! topology: Hex8 12, Tet4 10, Wedge6 13, Pyramid5 14, Quad4 9 (shells too), Tri3 5,
//! Bar2 3; the node orders of Exodus and VTK coincide for these linear cells.
//!
//! Binary encoding (VTK XML file format, `format="binary"` without compression): each
//! array is one base64 stream of a UInt64 byte count followed by the little-endian
//! values, as VTK and meshio write it.

use std::fmt::Write as _;
use std::io::{self, Write as _};
use std::path::{Path, PathBuf};

use crate::mesh::{Mesh, Topology};

fn vtk_type(t: Topology) -> u8 {
    match t {
        Topology::Hex8 => 12,
        Topology::Tet4 => 10,
        Topology::Wedge6 => 13,
        Topology::Pyramid5 => 14,
        Topology::Quad4 | Topology::Shell4 => 9,
        Topology::Tri3 | Topology::Shell3 => 5,
        Topology::Bar2 => 3,
    }
}

/// Write `mesh` with nodal fields `(name, values)` (one value per node; NaN for nodes
/// without a value) to `path`, in ASCII.
pub fn write_vtu(path: &Path, mesh: &Mesh, fields: &[(&str, &[f64])]) -> io::Result<()> {
    write_vtu_with(path, mesh, fields, &[], VtuEncoding::Ascii)
}

/// How array values are stored in a `.vtu`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VtuEncoding {
    /// Decimal text (`format="ascii"`).
    Ascii,
    /// Base64 of the raw little-endian values (`format="binary"`).
    Base64,
}

/// Write `mesh` with point data and cell data `(name, values)`: one value per node, one
/// per element in dense element order (blocks concatenated in mesh order). Base64
/// encoded; see [`write_vtu_with`].
pub fn write_vtu_cells(
    path: &Path,
    mesh: &Mesh,
    point: &[(&str, &[f64])],
    cell: &[(&str, &[f64])],
) -> io::Result<()> {
    write_vtu_with(path, mesh, point, cell, VtuEncoding::Base64)
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// Escape text for an XML attribute value.
fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// Appends `DataArray` elements in one encoding, each handed to `out` once made: the
/// file is never whole in memory (at a million nodes it is about 150 MB), only its
/// largest array.
struct Arrays<'w> {
    s: String,
    encoding: VtuEncoding,
    bytes: Vec<u8>,
    out: &'w mut dyn io::Write,
    /// The first failure to write (later writes are skipped).
    failed: Option<io::Error>,
}

impl Arrays<'_> {
    /// Hand what is made so far to the writer.
    fn flush(&mut self) {
        if self.failed.is_none()
            && let Err(e) = self.out.write_all(self.s.as_bytes())
        {
            self.failed = Some(e);
        }
        self.s.clear();
    }

    fn open(&mut self, ty: &str, name: Option<&str>, components: usize) {
        let format = match self.encoding {
            VtuEncoding::Ascii => "ascii",
            VtuEncoding::Base64 => "binary",
        };
        let _ = write!(self.s, "<DataArray type=\"{ty}\"");
        if let Some(name) = name {
            let _ = write!(self.s, " Name=\"{}\"", xml_escape(name));
        }
        if components > 1 {
            let _ = write!(self.s, " NumberOfComponents=\"{components}\"");
        }
        let _ = writeln!(self.s, " format=\"{format}\">");
    }

    /// One array of `T`; in ASCII, `per_line` values to a line.
    fn array<T: Copy + std::fmt::Display>(
        &mut self,
        ty: &str,
        name: Option<&str>,
        components: usize,
        values: impl Iterator<Item = T>,
        le: impl Fn(T, &mut Vec<u8>),
    ) {
        self.open(ty, name, components);
        match self.encoding {
            VtuEncoding::Ascii => {
                for (k, v) in values.enumerate() {
                    let sep = if (k + 1) % components.max(1) == 0 {
                        '\n'
                    } else {
                        ' '
                    };
                    let _ = write!(self.s, "{v}{sep}");
                }
            }
            VtuEncoding::Base64 => {
                self.bytes.clear();
                self.bytes.extend_from_slice(&[0; 8]);
                for v in values {
                    le(v, &mut self.bytes);
                }
                let n = (self.bytes.len() - 8) as u64;
                self.bytes[..8].copy_from_slice(&n.to_le_bytes());
                base64_into(&self.bytes, &mut self.s);
                self.s.push('\n');
            }
        }
        self.s.push_str("</DataArray>\n");
        self.flush();
    }

    fn f64s(&mut self, name: Option<&str>, components: usize, values: impl Iterator<Item = f64>) {
        match self.encoding {
            // `{:e}` keeps every digit needed to round-trip.
            VtuEncoding::Ascii => {
                self.array("Float64", name, components, values.map(Sci), |_, _| {})
            }
            VtuEncoding::Base64 => self.array("Float64", name, components, values, |v, b| {
                b.extend_from_slice(&v.to_le_bytes())
            }),
        }
    }

    fn i64s(&mut self, name: &str, values: impl Iterator<Item = i64>) {
        self.array("Int64", Some(name), 1, values, |v, b| {
            b.extend_from_slice(&v.to_le_bytes())
        });
    }

    /// Int32 when every value fits (half the bytes of Int64), else Int64.
    fn ints(&mut self, name: &str, values: impl Iterator<Item = i64> + Clone) {
        let fits = values.clone().all(|v| i32::try_from(v).is_ok());
        if fits {
            self.array("Int32", Some(name), 1, values.map(|v| v as i32), |v, b| {
                b.extend_from_slice(&v.to_le_bytes())
            });
        } else {
            self.i64s(name, values);
        }
    }

    fn u8s(&mut self, name: &str, values: impl Iterator<Item = u8>) {
        self.array("UInt8", Some(name), 1, values, |v, b| b.push(v));
    }
}

/// An f64 printed in shortest round-trip scientific notation.
#[derive(Clone, Copy)]
struct Sci(f64);

impl std::fmt::Display for Sci {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{:e}", self.0)
    }
}

const BASE64: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

/// Standard base64 (RFC 4648, with `=` padding) of `bytes`, appended to `out`. The
/// characters are made as bytes into a small buffer and appended a buffer at a time
/// (the alphabet is ASCII), not pushed one `char` at a time.
fn base64_into(bytes: &[u8], out: &mut String) {
    let sextet = |n: u32, k: u32| BASE64[(n >> (18 - 6 * k) & 63) as usize];
    out.reserve(bytes.len().div_ceil(3) * 4);
    let mut buf = [0u8; 4096];
    let mut k = 0;
    let mut chunks = bytes.chunks_exact(3);
    for c in &mut chunks {
        let n = (u32::from(c[0]) << 16) | (u32::from(c[1]) << 8) | u32::from(c[2]);
        buf[k..k + 4].copy_from_slice(&[sextet(n, 0), sextet(n, 1), sextet(n, 2), sextet(n, 3)]);
        k += 4;
        if k == buf.len() {
            out.push_str(ascii(&buf));
            k = 0;
        }
    }
    out.push_str(ascii(&buf[..k]));
    match *chunks.remainder() {
        [a] => {
            let n = u32::from(a) << 16;
            out.push_str(ascii(&[sextet(n, 0), sextet(n, 1), b'=', b'=']));
        }
        [a, b] => {
            let n = (u32::from(a) << 16) | (u32::from(b) << 8);
            out.push_str(ascii(&[sextet(n, 0), sextet(n, 1), sextet(n, 2), b'=']));
        }
        _ => {}
    }
}

fn ascii(b: &[u8]) -> &str {
    std::str::from_utf8(b).expect("the base64 alphabet is ASCII")
}

/// Write `mesh` with point and cell data in the given encoding. Lengths are checked:
/// a wrong one is an `InvalidInput` error naming the array.
pub fn write_vtu_with(
    path: &Path,
    mesh: &Mesh,
    point: &[(&str, &[f64])],
    cell: &[(&str, &[f64])],
    encoding: VtuEncoding,
) -> io::Result<()> {
    let point: Vec<Array<'_>> = point.iter().map(|&(n, v)| Array::scalar(n, v)).collect();
    let cell: Vec<Array<'_>> = cell.iter().map(|&(n, v)| Array::scalar(n, v)).collect();
    write_vtu_arrays(path, mesh, &point, &cell, encoding)
}

/// A named array of `components` values per point or per cell (interleaved: the
/// components of one point or cell together, as VTK stores them).
#[derive(Clone, Copy, Debug)]
pub struct Array<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: &'a [f64],
}

impl<'a> Array<'a> {
    /// One value per point or cell.
    pub fn scalar(name: &'a str, values: &'a [f64]) -> Self {
        Array {
            name,
            components: 1,
            values,
        }
    }

    /// Three values (x, y, z) per point or cell.
    pub fn vector(name: &'a str, values: &'a [f64]) -> Self {
        Array {
            name,
            components: 3,
            values,
        }
    }
}

/// Check that every array has `components × expect` values and a usable name; cell
/// data may not be called `reserved` (an array the file carries anyway).
fn check_multi(
    kind: &str,
    arrays: &[Array<'_>],
    expect: usize,
    per: &str,
    reserved: Option<&str>,
) -> io::Result<()> {
    for (k, a) in arrays.iter().enumerate() {
        if a.name.is_empty() {
            return Err(invalid(format!(
                "{kind} array {} has an empty name; name every array",
                k + 1
            )));
        }
        if a.components == 0 {
            return Err(invalid(format!(
                "{kind} array `{}` has 0 components",
                a.name
            )));
        }
        if a.values.len() != a.components * expect {
            let each = match a.components {
                1 => format!("one per {per}"),
                c => format!("{c} per {per}"),
            };
            return Err(invalid(format!(
                "{kind} array `{}` has {} values, expected {} ({each})",
                a.name,
                a.values.len(),
                a.components * expect,
            )));
        }
        if Some(a.name) == reserved {
            return Err(invalid(format!(
                "{kind} array `{}` clashes with the {} every .vtu carries; rename it",
                a.name, a.name
            )));
        }
    }
    Ok(())
}

/// Write `mesh` with point and cell arrays of any number of components (e.g. a heat
/// flux vector per cell), base64 or ASCII. Lengths are checked as in
/// [`write_vtu_with`].
pub fn write_vtu_arrays(
    path: &Path,
    mesh: &Mesh,
    point: &[Array<'_>],
    cell: &[Array<'_>],
    encoding: VtuEncoding,
) -> io::Result<()> {
    check_multi("point data", point, mesh.num_nodes(), "mesh node", None)?;
    let cells: usize = mesh.blocks.iter().map(|b| b.len()).sum();
    check_multi("cell data", cell, cells, "element", Some("block_id"))?;
    let blocks = || mesh.blocks.iter();
    let offsets = blocks()
        .flat_map(|b| std::iter::repeat_n(b.topology.node_count() as i64, b.len()))
        .scan(0i64, |off, n| {
            *off += n;
            Some(*off)
        });
    let block_id: Vec<i64> = blocks()
        .flat_map(|b| std::iter::repeat_n(b.id, b.len()))
        .collect();
    write_piece(
        path,
        Piece {
            points: &mesh.coords,
            cells,
            connectivity: blocks().flat_map(|b| b.connectivity.iter().map(|n| i64::from(n.0))),
            offsets,
            types: blocks().flat_map(|b| std::iter::repeat_n(vtk_type(b.topology), b.len())),
            point,
            cell_ints: &[("block_id", &block_id)],
            cell,
        },
        encoding,
    )
}

/// Write a grid of its own — `points` and polygon cells, each a list of 3 (triangle,
/// VTK type 5), 4 (quad, 9), 2 (line, 3) or 1 (vertex, 1) indices into `points` — with
/// point arrays, integer cell arrays and real cell arrays: e.g. the faces of contact
/// surfaces, or contact points.
pub fn write_vtu_polygons(
    path: &Path,
    points: &[[f64; 3]],
    polygons: &[Vec<u32>],
    point: &[Array<'_>],
    cell_ints: &[(&str, &[i64])],
    cell: &[Array<'_>],
    encoding: VtuEncoding,
) -> io::Result<()> {
    check_multi("point data", point, points.len(), "point", None)?;
    check_multi("cell data", cell, polygons.len(), "cell", None)?;
    for (name, v) in cell_ints {
        if v.len() != polygons.len() {
            return Err(invalid(format!(
                "cell data array `{name}` has {} values, expected {} (one per cell)",
                v.len(),
                polygons.len()
            )));
        }
    }
    let mut types = Vec::with_capacity(polygons.len());
    for (k, p) in polygons.iter().enumerate() {
        types.push(match p.len() {
            1 => 1,
            2 => 3,
            3 => 5,
            4 => 9,
            n => {
                return Err(invalid(format!(
                    "cell {k} has {n} points; a cell here has 1 (vertex), 2, 3 or 4"
                )));
            }
        });
        if let Some(&i) = p.iter().find(|&&i| i as usize >= points.len()) {
            return Err(invalid(format!(
                "cell {k} names point {i}, but there are {} points",
                points.len()
            )));
        }
    }
    let offsets = polygons.iter().scan(0i64, |off, p| {
        *off += p.len() as i64;
        Some(*off)
    });
    write_piece(
        path,
        Piece {
            points,
            cells: polygons.len(),
            connectivity: polygons.iter().flatten().map(|&i| i64::from(i)),
            offsets,
            types: types.iter().copied(),
            point,
            cell_ints,
            cell,
        },
        encoding,
    )
}

/// Everything one `<Piece>` holds.
struct Piece<'a, C, O, T> {
    points: &'a [[f64; 3]],
    cells: usize,
    connectivity: C,
    offsets: O,
    types: T,
    point: &'a [Array<'a>],
    cell_ints: &'a [(&'a str, &'a [i64])],
    cell: &'a [Array<'a>],
}

/// The whole file of one piece, arrays already checked, written to `out` an array at a
/// time.
fn piece<C, O, T>(
    p: Piece<'_, C, O, T>,
    encoding: VtuEncoding,
    out: &mut dyn io::Write,
) -> io::Result<()>
where
    C: Iterator<Item = i64> + Clone,
    O: Iterator<Item = i64> + Clone,
    T: Iterator<Item = u8>,
{
    let mut a = Arrays {
        s: String::new(),
        encoding,
        bytes: Vec::new(),
        out,
        failed: None,
    };
    a.s.push_str("<?xml version=\"1.0\"?>\n");
    a.s.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    a.s.push_str("<UnstructuredGrid>\n");
    let _ = writeln!(
        a.s,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        p.points.len(),
        p.cells
    );
    a.s.push_str("<PointData>\n");
    for x in p.point {
        a.f64s(Some(x.name), x.components, x.values.iter().copied());
    }
    a.s.push_str("</PointData>\n<Points>\n");
    a.f64s(None, 3, p.points.iter().flatten().copied());
    a.s.push_str("</Points>\n<Cells>\n");
    a.ints("connectivity", p.connectivity);
    a.ints("offsets", p.offsets);
    a.u8s("types", p.types);
    a.s.push_str("</Cells>\n<CellData>\n");
    for (name, v) in p.cell_ints {
        a.i64s(name, v.iter().copied());
    }
    for x in p.cell {
        a.f64s(Some(x.name), x.components, x.values.iter().copied());
    }
    a.s.push_str("</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    a.flush();
    match a.failed {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

/// Create `path` and write one piece into it through a buffer.
fn write_piece<C, O, T>(path: &Path, p: Piece<'_, C, O, T>, encoding: VtuEncoding) -> io::Result<()>
where
    C: Iterator<Item = i64> + Clone,
    O: Iterator<Item = i64> + Clone,
    T: Iterator<Item = u8>,
{
    let mut file = io::BufWriter::new(std::fs::File::create(path)?);
    piece(p, encoding, &mut file)?;
    file.flush()
}

/// A ParaView time series (`.pvd`): a list of `(time, file)` rewritten whole on every
/// [`add`](Self::add), through a temporary file renamed into place, so the series on disk
/// is always complete.
#[derive(Clone, Debug)]
pub struct PvdSeries {
    path: PathBuf,
    entries: Vec<(f64, String)>,
}

impl PvdSeries {
    /// A series to be written at `path` (nothing is written until the first `add`).
    pub fn new(path: &Path) -> Self {
        PvdSeries {
            path: path.to_path_buf(),
            entries: Vec::new(),
        }
    }

    /// Add `file` at `time` and rewrite the `.pvd`. A relative `file` is taken relative
    /// to the `.pvd`'s directory; an absolute one under that directory is made relative
    /// to it (so the output directory can be moved), any other is kept as is.
    pub fn add(&mut self, time: f64, file: &Path) -> io::Result<()> {
        if !time.is_finite() {
            return Err(invalid(format!(
                "time {time} for {} in series {} is not finite",
                file.display(),
                self.path.display()
            )));
        }
        let dir = self.path.parent().unwrap_or(Path::new(""));
        let rel = if file.is_absolute() {
            let abs_dir = std::path::absolute(dir)?;
            file.strip_prefix(&abs_dir).unwrap_or(file)
        } else {
            file
        };
        // ParaView reads `/` on every platform.
        let rel = rel
            .components()
            .map(|c| c.as_os_str().to_string_lossy())
            .collect::<Vec<_>>()
            .join("/");
        self.entries.push((time, rel));
        let mut s = String::new();
        s.push_str("<?xml version=\"1.0\"?>\n");
        s.push_str("<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n<Collection>\n");
        for (t, f) in &self.entries {
            let _ = writeln!(
                s,
                "<DataSet timestep=\"{}\" part=\"0\" file=\"{}\"/>",
                Sci(*t),
                xml_escape(f)
            );
        }
        s.push_str("</Collection>\n</VTKFile>\n");
        let mut tmp = self.path.clone().into_os_string();
        tmp.push(".tmp");
        std::fs::write(&tmp, s)?;
        std::fs::rename(&tmp, &self.path)
    }

    /// Number of entries so far.
    pub fn len(&self) -> usize {
        self.entries.len()
    }

    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// RFC 4648 section 10 test vectors.
    #[test]
    fn base64_matches_the_rfc_vectors() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            let mut s = String::new();
            base64_into(plain.as_bytes(), &mut s);
            assert_eq!(s, coded, "{plain}");
        }
        // Longer than the encoder's buffer: base64 of a concatenation cut at a
        // multiple of 3 bytes is the concatenation of the two encodings.
        let long: Vec<u8> = (0..10_001u32).map(|i| (i * 7919 % 251) as u8).collect();
        let (mut whole, mut parts) = (String::new(), String::new());
        base64_into(&long, &mut whole);
        base64_into(&long[..3000], &mut parts);
        base64_into(&long[3000..], &mut parts);
        assert_eq!(whole.len(), 10_001usize.div_ceil(3) * 4);
        assert_eq!(whole, parts);
    }
}
