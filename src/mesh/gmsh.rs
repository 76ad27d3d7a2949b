//! Gmsh MSH 4.1 reader, ASCII and binary (little-endian, 8-byte `size_t`).
//!
//! Entry point: [`read`]. Sections read: `$MeshFormat` (4.1 only; 2.2 is rejected with
//! the option that converts it), `$PhysicalNames`, `$Entities` (entity → physical tags),
//! `$Nodes` (tags may be sparse) and `$Elements`; other sections are skipped.
//!
//! Lowering to the Exodus-like [`Mesh`], for a mesh whose highest element dimension is
//! `D` (3, or 2 for a planar mesh):
//! - each physical group of dimension `D` becomes an element block (id = physical tag,
//!   name = physical name). A group mixing element types becomes one block per type; the
//!   first keeps the tag, the others get fresh ids above every physical tag and the name
//!   `<name>_<type>`. Without any physical group, each `D`-dimensional entity becomes a
//!   block with the entity's tag (Gmsh's own rule: when groups exist, only grouped
//!   elements are meaningful).
//! - each physical group of dimension `D - 1` becomes a side set: every surface (or
//!   curve) element is matched, by its node set, to a side of a block element. On an
//!   interior surface two elements share the face; the one whose Exodus side has the
//!   surface element's orientation (the surface normal points out of it) is taken.
//!   A surface element that matches no element side is an error.
//!
//! Node orderings: Gmsh's linear hex, tet, prism, pyramid, quad and triangle vertex
//! orders coincide with Exodus II, so connectivity is copied as is (the integration tests
//! check that every fixture element has positive volume). Errors give the line (ASCII)
//! or byte offset (binary) where reading stopped.

use std::collections::HashMap;
use std::path::Path;

use super::{ElemId, Mesh, MeshError, NodeId, Side, SideSet, Topology};

/// Read a Gmsh 4.1 file. The mesh is not validated here; [`super::read`] does that.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    let data = std::fs::read(path).map_err(|source| MeshError::Open {
        path: path.to_path_buf(),
        source,
    })?;
    let raw = parse(&data).map_err(|e| {
        let at = if e.binary {
            format!("at byte {}", e.offset)
        } else {
            format!("at line {}", e.line)
        };
        MeshError::format(path, format!("{at}: {}", e.message), e.help)
    })?;
    lower(raw).map_err(|(message, help)| MeshError::format(path, message, help))
}

// ---------------------------------------------------------------------------------------
// Raw form: what the file says, before lowering.

struct ElementGroup {
    entity_dim: i32,
    entity_tag: i32,
    etype: i32,
    tags: Vec<i64>,
    /// Dense node indices, `nodes_per_type(etype)` per element.
    nodes: Vec<u32>,
}

#[derive(Default)]
struct Raw {
    physical_names: HashMap<(i32, i32), String>,
    /// (dim, entity tag) → physical tags.
    entities: HashMap<(i32, i32), Vec<i32>>,
    coords: Vec<[f64; 3]>,
    node_tags: Vec<i64>,
    groups: Vec<ElementGroup>,
}

struct ParseError {
    binary: bool,
    line: usize,
    offset: usize,
    message: String,
    help: String,
}

/// Node count of a Gmsh element type, for the types seam may meet (including
/// higher-order ones, so that files holding them can be parsed and rejected clearly).
fn nodes_per_type(etype: i32) -> Option<usize> {
    Some(match etype {
        1 => 2,
        2 => 3,
        3 => 4,
        4 => 4,
        5 => 8,
        6 => 6,
        7 => 5,
        8 => 3,
        9 => 6,
        10 => 9,
        11 => 10,
        12 => 27,
        13 => 18,
        14 => 14,
        15 => 1,
        16 => 8,
        17 => 20,
        18 => 15,
        19 => 13,
        20 => 9,
        21 => 10,
        26 => 4,
        29 => 20,
        36 => 16,
        _ => return None,
    })
}

/// The topology of a linear Gmsh element in a mesh of top dimension `top`.
fn topology_of(etype: i32, top: i32) -> Option<Topology> {
    Some(match etype {
        1 => Topology::Bar2,
        2 if top == 2 => Topology::Tri3,
        3 if top == 2 => Topology::Quad4,
        2 => Topology::Shell3,
        3 => Topology::Shell4,
        4 => Topology::Tet4,
        5 => Topology::Hex8,
        6 => Topology::Wedge6,
        7 => Topology::Pyramid5,
        _ => return None,
    })
}

fn type_name(etype: i32) -> String {
    match etype {
        1 => "2-node line".into(),
        2 => "3-node triangle".into(),
        3 => "4-node quadrangle".into(),
        4 => "4-node tetrahedron".into(),
        5 => "8-node hexahedron".into(),
        6 => "6-node prism".into(),
        7 => "5-node pyramid".into(),
        15 => "point".into(),
        t => match nodes_per_type(t) {
            Some(n) => format!("type {t} ({n}-node, higher order)"),
            None => format!("type {t}"),
        },
    }
}

/// Reads tokens (ASCII) or fixed-size values (binary) from the file bytes.
struct Cursor<'a> {
    data: &'a [u8],
    pos: usize,
    line: usize,
    binary: bool,
}

type PResult<T> = Result<T, ParseError>;

impl<'a> Cursor<'a> {
    fn error(&self, message: impl Into<String>, help: impl Into<String>) -> ParseError {
        ParseError {
            binary: self.binary,
            line: self.line,
            offset: self.pos,
            message: message.into(),
            help: help.into(),
        }
    }

    fn corrupt(&self, message: impl Into<String>) -> ParseError {
        self.error(
            message,
            "the file is truncated or corrupt; write it again from Gmsh (File > Export, MSH 4.1)",
        )
    }

    fn skip_ws(&mut self) {
        while let Some(&c) = self.data.get(self.pos) {
            if c == b'\n' {
                self.line += 1;
            } else if !c.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
    }

    /// Next whitespace-separated ASCII token (also used for section markers in binary files).
    fn token(&mut self) -> PResult<&'a [u8]> {
        self.skip_ws();
        let start = self.pos;
        while let Some(&c) = self.data.get(self.pos) {
            if c.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.corrupt("unexpected end of file"));
        }
        Ok(&self.data[start..self.pos])
    }

    fn rest_of_line(&mut self) -> &'a [u8] {
        let start = self.pos;
        while let Some(&c) = self.data.get(self.pos) {
            if c == b'\n' {
                break;
            }
            self.pos += 1;
        }
        &self.data[start..self.pos]
    }

    /// Move past the newline that ends a section header, where binary data begins.
    fn end_line(&mut self) {
        self.rest_of_line();
        if self.pos < self.data.len() {
            self.pos += 1;
            self.line += 1;
        }
    }

    fn ascii_int(&mut self, what: &str) -> PResult<i64> {
        let t = self.token()?;
        let (neg, digits) = match t.first() {
            Some(b'-') => (true, &t[1..]),
            _ => (false, t),
        };
        let mut v: i64 = 0;
        if digits.is_empty() {
            return Err(self.corrupt(format!("expected an integer ({what})")));
        }
        for &c in digits {
            if !c.is_ascii_digit() {
                return Err(self.corrupt(format!(
                    "expected an integer ({what}), found `{}`",
                    String::from_utf8_lossy(t)
                )));
            }
            v = v
                .checked_mul(10)
                .and_then(|v| v.checked_add((c - b'0') as i64))
                .ok_or_else(|| self.corrupt(format!("integer too large ({what})")))?;
        }
        Ok(if neg { -v } else { v })
    }

    fn take<const N: usize>(&mut self, what: &str) -> PResult<[u8; N]> {
        let end = self.pos + N;
        let Some(bytes) = self.data.get(self.pos..end) else {
            return Err(self.corrupt(format!("unexpected end of file reading {what}")));
        };
        self.pos = end;
        Ok(bytes.try_into().expect("slice of length N"))
    }

    /// A C `int`.
    fn int(&mut self, what: &str) -> PResult<i32> {
        if self.binary {
            Ok(i32::from_le_bytes(self.take::<4>(what)?))
        } else {
            let v = self.ascii_int(what)?;
            i32::try_from(v).map_err(|_| self.corrupt(format!("{what} {v} out of range")))
        }
    }

    /// A `size_t` (8 bytes in binary).
    fn size(&mut self, what: &str) -> PResult<u64> {
        if self.binary {
            Ok(u64::from_le_bytes(self.take::<8>(what)?))
        } else {
            let v = self.ascii_int(what)?;
            u64::try_from(v).map_err(|_| self.corrupt(format!("{what} {v} is negative")))
        }
    }

    fn double(&mut self, what: &str) -> PResult<f64> {
        if self.binary {
            Ok(f64::from_le_bytes(self.take::<8>(what)?))
        } else {
            let t = self.token()?;
            std::str::from_utf8(t)
                .ok()
                .and_then(|s| s.parse::<f64>().ok())
                .ok_or_else(|| {
                    self.corrupt(format!(
                        "expected a number ({what}), found `{}`",
                        String::from_utf8_lossy(t)
                    ))
                })
        }
    }

    /// A count that sizes an allocation: bounded by what the remaining bytes can hold, so a
    /// corrupt count cannot request terabytes.
    fn count(&mut self, what: &str, min_bytes_each: usize) -> PResult<usize> {
        let n = self.size(what)?;
        let left = (self.data.len() - self.pos) as u64;
        // An ASCII item takes at least a digit and a separator.
        let each = if self.binary { min_bytes_each } else { 2 };
        if n.saturating_mul(each as u64) > left {
            return Err(self.corrupt(format!(
                "{what} is {n}, more than the rest of the file can hold"
            )));
        }
        Ok(n as usize)
    }

    fn expect_end(&mut self, section: &str) -> PResult<()> {
        let want = format!("$End{section}");
        let t = self.token()?;
        if t != want.as_bytes() {
            return Err(self.corrupt(format!(
                "expected `{want}`, found `{}`",
                String::from_utf8_lossy(&t[..t.len().min(40)])
            )));
        }
        Ok(())
    }
}

fn parse(data: &[u8]) -> PResult<Raw> {
    let mut c = Cursor {
        data,
        pos: 0,
        line: 1,
        binary: false,
    };
    let mut raw = Raw::default();
    let mut seen_format = false;
    let mut node_index: Option<NodeIndex> = None;
    loop {
        c.skip_ws();
        if c.pos >= data.len() {
            break;
        }
        let t = c.token()?;
        if !t.starts_with(b"$") {
            return Err(c.corrupt(format!(
                "expected a section such as `$Nodes`, found `{}`",
                String::from_utf8_lossy(&t[..t.len().min(40)])
            )));
        }
        let section = String::from_utf8_lossy(&t[1..]).into_owned();
        if !seen_format && section != "MeshFormat" {
            return Err(c.error(
                "the file does not start with `$MeshFormat`",
                "this is not a Gmsh .msh file",
            ));
        }
        match section.as_str() {
            "MeshFormat" => {
                parse_format(&mut c)?;
                seen_format = true;
            }
            "PhysicalNames" => parse_physical_names(&mut c, &mut raw)?,
            "Entities" => {
                c.end_line();
                parse_entities(&mut c, &mut raw)?;
            }
            "Nodes" => {
                c.end_line();
                node_index = Some(parse_nodes(&mut c, &mut raw)?);
            }
            "Elements" => {
                c.end_line();
                let Some(index) = &node_index else {
                    return Err(c.corrupt("`$Elements` comes before `$Nodes`"));
                };
                parse_elements(&mut c, &mut raw, index)?;
            }
            other => skip_section(&mut c, other)?,
        }
        if section != "MeshFormat" {
            c.expect_end(&section)?;
        }
    }
    if node_index.is_none() {
        return Err(c.error(
            "the file has no `$Nodes` section",
            "mesh the model before saving (gmsh -3 model.geo -o model.msh)",
        ));
    }
    Ok(raw)
}

fn parse_format(c: &mut Cursor) -> PResult<()> {
    let version = c.token()?;
    if version != b"4.1" {
        let v = String::from_utf8_lossy(version).into_owned();
        return Err(c.error(
            format!("MSH format version {v} is not supported; seam reads MSH 4.1"),
            "re-save the mesh as MSH 4.1: `gmsh model.msh -save -format msh41 -o new.msh`, \
             or set `Mesh.MshFileVersion = 4.1;` before saving",
        ));
    }
    let file_type = c.ascii_int("file type")?;
    let data_size = c.ascii_int("data size")?;
    if data_size != 8 {
        return Err(c.error(
            format!("data size {data_size} is not supported (seam reads 8-byte size_t)"),
            "save the mesh with a 64-bit Gmsh build, or in ASCII (`Mesh.Binary = 0`)",
        ));
    }
    if file_type == 1 {
        c.end_line();
        let one = c.take::<4>("endianness marker")?;
        if i32::from_le_bytes(one) != 1 {
            return Err(c.error(
                "the binary file is big-endian, which seam does not read",
                "save the mesh in ASCII (`Mesh.Binary = 0`) or on a little-endian machine",
            ));
        }
        c.binary = true;
    }
    c.expect_end("MeshFormat")
}

fn parse_physical_names(c: &mut Cursor, raw: &mut Raw) -> PResult<()> {
    // Always ASCII, even in binary files.
    let binary = std::mem::replace(&mut c.binary, false);
    let n = c.ascii_int("number of physical names")?;
    for _ in 0..n {
        let dim = c.ascii_int("physical dimension")? as i32;
        let tag = c.ascii_int("physical tag")? as i32;
        c.skip_ws();
        let line = String::from_utf8_lossy(c.rest_of_line()).into_owned();
        let name = line.trim().trim_matches('"').to_string();
        raw.physical_names.insert((dim, tag), name);
    }
    c.binary = binary;
    Ok(())
}

fn parse_entities(c: &mut Cursor, raw: &mut Raw) -> PResult<()> {
    let counts = [
        c.size("number of points")?,
        c.size("number of curves")?,
        c.size("number of surfaces")?,
        c.size("number of volumes")?,
    ];
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let tag = c.int("entity tag")?;
            // Points: X Y Z; others: a bounding box.
            let coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..coords {
                c.double("entity coordinate")?;
            }
            let nphys = c.count("number of physical tags", 4)?;
            let mut phys = Vec::with_capacity(nphys);
            for _ in 0..nphys {
                phys.push(c.int("physical tag")?);
            }
            if dim > 0 {
                let nb = c.count("number of bounding entities", 4)?;
                for _ in 0..nb {
                    c.int("bounding entity")?;
                }
            }
            if !phys.is_empty() {
                raw.entities.insert((dim as i32, tag), phys);
            }
        }
    }
    Ok(())
}

/// Node tag → dense index.
enum NodeIndex {
    /// Indexed by tag; `u32::MAX` for absent tags. Used when tags are reasonably dense.
    Table(Vec<u32>),
    Map(HashMap<i64, u32>),
}

impl NodeIndex {
    fn get(&self, tag: i64) -> Option<u32> {
        match self {
            NodeIndex::Table(t) => usize::try_from(tag)
                .ok()
                .and_then(|i| t.get(i))
                .copied()
                .filter(|&i| i != u32::MAX),
            NodeIndex::Map(m) => m.get(&tag).copied(),
        }
    }
}

fn parse_nodes(c: &mut Cursor, raw: &mut Raw) -> PResult<NodeIndex> {
    let nblocks = c.count("number of node blocks", 16)?;
    let total = c.count("number of nodes", 32)?;
    let _min_tag = c.size("minimum node tag")?;
    let max_tag = c.size("maximum node tag")?;
    if total > u32::MAX as usize - 1 {
        return Err(c.corrupt("more than 2^32 nodes"));
    }
    raw.coords.reserve(total);
    raw.node_tags.reserve(total);
    let dense = max_tag <= 4 * total as u64 + 1024;
    let mut index = if dense {
        NodeIndex::Table(vec![u32::MAX; max_tag as usize + 1])
    } else {
        NodeIndex::Map(HashMap::with_capacity(total))
    };
    for _ in 0..nblocks {
        let entity_dim = c.int("entity dimension")?;
        let _entity_tag = c.int("entity tag")?;
        let parametric = c.int("parametric flag")?;
        let n = c.count("number of nodes in block", 32)?;
        let first = raw.node_tags.len();
        for _ in 0..n {
            let tag = c.size("node tag")? as i64;
            let k = raw.node_tags.len() as u32;
            let dup = match &mut index {
                NodeIndex::Table(t) => match t.get_mut(tag as usize) {
                    Some(slot) if *slot == u32::MAX => {
                        *slot = k;
                        false
                    }
                    Some(_) => true,
                    None => {
                        return Err(c.corrupt(format!(
                            "node tag {tag} exceeds the maximum tag {max_tag} given in the header"
                        )));
                    }
                },
                NodeIndex::Map(m) => m.insert(tag, k).is_some(),
            };
            if dup {
                return Err(c.corrupt(format!("node tag {tag} appears twice")));
            }
            raw.node_tags.push(tag);
        }
        let extra = if parametric != 0 {
            entity_dim.clamp(0, 3) as usize
        } else {
            0
        };
        for _ in first..first + n {
            let x = c.double("x")?;
            let y = c.double("y")?;
            let z = c.double("z")?;
            for _ in 0..extra {
                c.double("parametric coordinate")?;
            }
            raw.coords.push([x, y, z]);
        }
    }
    if raw.coords.len() != total {
        return Err(c.corrupt(format!(
            "the header announces {total} nodes but the blocks hold {}",
            raw.coords.len()
        )));
    }
    Ok(index)
}

fn parse_elements(c: &mut Cursor, raw: &mut Raw, index: &NodeIndex) -> PResult<()> {
    let nblocks = c.count("number of element blocks", 16)?;
    let _total = c.size("number of elements")?;
    let _min = c.size("minimum element tag")?;
    let _max = c.size("maximum element tag")?;
    for _ in 0..nblocks {
        let entity_dim = c.int("entity dimension")?;
        let entity_tag = c.int("entity tag")?;
        let etype = c.int("element type")?;
        let n = c.count("number of elements in block", 16)?;
        let Some(npe) = nodes_per_type(etype) else {
            return Err(c.error(
                format!(
                    "element type {etype} (entity {entity_dim}-{entity_tag}) is not known to seam"
                ),
                "seam reads linear elements (line, triangle, quadrangle, tetrahedron, \
                 hexahedron, prism, pyramid); set `Mesh.ElementOrder = 1` in Gmsh",
            ));
        };
        let mut tags = Vec::with_capacity(n);
        let mut nodes = Vec::with_capacity(n * npe);
        for _ in 0..n {
            tags.push(c.size("element tag")? as i64);
            for _ in 0..npe {
                let t = c.size("element node tag")? as i64;
                let Some(k) = index.get(t) else {
                    let elem = tags.last().copied().unwrap_or(0);
                    return Err(c.corrupt(format!(
                        "element {elem} refers to node {t}, which is not in `$Nodes`"
                    )));
                };
                nodes.push(k);
            }
        }
        raw.groups.push(ElementGroup {
            entity_dim,
            entity_tag,
            etype,
            tags,
            nodes,
        });
    }
    Ok(())
}

fn skip_section(c: &mut Cursor, name: &str) -> PResult<()> {
    let end = format!("\n$End{name}");
    let rest = &c.data[c.pos..];
    let Some(at) = rest.windows(end.len()).position(|w| w == end.as_bytes()) else {
        return Err(c.corrupt(format!("section `${name}` has no `$End{name}`")));
    };
    if !c.binary {
        c.line += rest[..at].iter().filter(|&&b| b == b'\n').count();
    }
    c.pos += at;
    Ok(())
}

// ---------------------------------------------------------------------------------------
// Lowering.

type LowerError = (String, String);

fn lower(raw: Raw) -> Result<Mesh, LowerError> {
    let top = raw
        .groups
        .iter()
        .filter(|g| !g.tags.is_empty())
        .map(|g| g.entity_dim)
        .max()
        .unwrap_or(0);
    if top < 2 {
        return Err((
            "the file holds no surface or volume elements".into(),
            "mesh the model in 2-D or 3-D before saving (gmsh -3 model.geo)".into(),
        ));
    }
    let mut mesh = Mesh {
        dim: top as usize,
        coords: raw.coords,
        node_numbers: raw.node_tags,
        ..Mesh::default()
    };
    let has_physicals = !raw.entities.is_empty();
    let physicals_of = |dim: i32| -> Vec<i32> {
        let mut tags: Vec<i32> = raw
            .entities
            .iter()
            .filter(|((d, _), _)| *d == dim)
            .flat_map(|(_, p)| p.iter().copied())
            .collect();
        tags.sort_unstable();
        tags.dedup();
        tags
    };
    let name_of = |dim: i32, tag: i32| {
        raw.physical_names
            .get(&(dim, tag))
            .cloned()
            .unwrap_or_default()
    };
    let in_physical = |g: &ElementGroup, tag: i32| {
        raw.entities
            .get(&(g.entity_dim, g.entity_tag))
            .is_some_and(|p| p.contains(&tag))
    };

    // Blocks.
    let mut next_free_id = raw.entities.values().flatten().copied().max().unwrap_or(0) as i64 + 1;
    // (id, name, groups) for each block source.
    let mut sources: Vec<(i64, String, Vec<&ElementGroup>)> = Vec::new();
    if has_physicals {
        for tag in physicals_of(top) {
            let groups = raw
                .groups
                .iter()
                .filter(|g| g.entity_dim == top && in_physical(g, tag))
                .collect();
            sources.push((tag as i64, name_of(top, tag), groups));
        }
    } else {
        let mut tags: Vec<i32> = raw
            .groups
            .iter()
            .filter(|g| g.entity_dim == top)
            .map(|g| g.entity_tag)
            .collect();
        tags.sort_unstable();
        tags.dedup();
        for tag in tags {
            let groups = raw
                .groups
                .iter()
                .filter(|g| g.entity_dim == top && g.entity_tag == tag)
                .collect();
            sources.push((tag as i64, String::new(), groups));
        }
    }
    if sources.is_empty() {
        let (what, group) = if top == 3 {
            ("volume", "Physical Volume")
        } else {
            ("surface", "Physical Surface")
        };
        return Err((
            format!("the file has physical groups but no physical {what}, so no element block"),
            format!(
                "add the {what}s to a physical group (`{group}(\"name\") = {{...}};`), or remove \
                 all physical groups so that every {what} becomes a block"
            ),
        ));
    }
    for (id, name, groups) in sources {
        let what = if name.is_empty() {
            format!("physical group {id}")
        } else {
            format!("physical group {id} (\"{name}\")")
        };
        let mut types: Vec<i32> = groups.iter().map(|g| g.etype).collect();
        types.sort_unstable();
        types.dedup();
        for (k, &etype) in types.iter().enumerate() {
            let Some(topology) = topology_of(etype, top) else {
                return Err((
                    format!(
                        "{what} holds {} elements, which seam does not support",
                        type_name(etype)
                    ),
                    "seam reads linear elements (tetrahedron, hexahedron, prism, pyramid; \
                     quadrangle and triangle in 2-D); set `Mesh.ElementOrder = 1` in Gmsh"
                        .into(),
                ));
            };
            let mut conn = Vec::new();
            let mut numbers = Vec::new();
            for g in groups.iter().filter(|g| g.etype == etype) {
                conn.extend(g.nodes.iter().map(|&n| NodeId(n)));
                numbers.extend_from_slice(&g.tags);
            }
            let (bid, bname) = if k == 0 {
                (id, name.clone())
            } else {
                next_free_id += 1;
                let stem = if name.is_empty() {
                    format!("block_{id}")
                } else {
                    name.clone()
                };
                (
                    next_free_id - 1,
                    format!("{stem}_{}", topology.exodus_name().to_ascii_lowercase()),
                )
            };
            mesh.push_block(bid, bname, topology, conn, Some(numbers));
        }
    }

    // Side sets from physical groups one dimension down.
    if has_physicals {
        let tags = physicals_of(top - 1);
        // Every face of every group, flattened: (physical index, element tag, nodes).
        let mut faces: Vec<(usize, i64, &[u32])> = Vec::new();
        let mut names = Vec::with_capacity(tags.len());
        for (p, &tag) in tags.iter().enumerate() {
            let name = name_of(top - 1, tag);
            for g in raw
                .groups
                .iter()
                .filter(|g| g.entity_dim == top - 1 && in_physical(g, tag))
            {
                let Some(npe) = nodes_per_type(g.etype).filter(|_| (1..=3).contains(&g.etype))
                else {
                    return Err((
                        format!(
                            "physical group {tag} (\"{name}\") holds {} elements, which seam does not support",
                            type_name(g.etype)
                        ),
                        "set `Mesh.ElementOrder = 1` in Gmsh".into(),
                    ));
                };
                for (k, face) in g.nodes.chunks_exact(npe).enumerate() {
                    faces.push((p, g.tags[k], face));
                }
            }
            names.push(name);
        }
        let found = match_faces(&mesh, &faces);
        let mut sets: Vec<SideSet> = tags
            .iter()
            .zip(names)
            .map(|(&tag, name)| SideSet {
                id: tag as i64,
                name,
                sides: Vec::new(),
            })
            .collect();
        for (&(p, elem_tag, _), side) in faces.iter().zip(found) {
            let Some(side) = side else {
                let set = &sets[p];
                return Err((
                    format!(
                        "element {elem_tag} of physical {} {} (\"{}\") is not a side of any element in a physical {}",
                        if top == 3 { "surface" } else { "curve" },
                        set.id,
                        set.name,
                        if top == 3 { "volume" } else { "surface" },
                    ),
                    "put the volumes the surface bounds into physical groups, or remove the \
                     surface from its group; side sets must lie on element sides"
                        .into(),
                ));
            };
            sets[p].sides.push(side);
        }
        mesh.side_sets = sets;
    }
    Ok(mesh)
}

fn face_key(nodes: impl Iterator<Item = u32>) -> [u32; 4] {
    let mut k = [u32::MAX; 4];
    for (slot, n) in k.iter_mut().zip(nodes) {
        *slot = n;
    }
    k.sort_unstable();
    k
}

/// For each face (given by its nodes), the element side with the same node set. Of two
/// (an interior face), the side listing the nodes in the face's orientation. The hash map
/// holds only the faces, which are few; every element side is looked up once.
fn match_faces(mesh: &Mesh, faces: &[(usize, i64, &[u32])]) -> Vec<Option<Side>> {
    // Key → first face index; `chain` links faces with the same key (a face in two groups).
    let mut first: HashMap<[u32; 4], u32, FastHash> =
        HashMap::with_capacity_and_hasher(faces.len(), FastHash);
    let mut chain = vec![u32::MAX; faces.len()];
    for (f, (_, _, nodes)) in faces.iter().enumerate() {
        if let Some(prev) = first.insert(face_key(nodes.iter().copied()), f as u32) {
            chain[f] = prev;
        }
    }
    let mut found: Vec<Option<Side>> = vec![None; faces.len()];
    if faces.is_empty() {
        return found;
    }
    for block in &mesh.blocks {
        let table = block.topology.sides();
        let nside = block.topology.face_side_count();
        for (k, nodes) in block
            .connectivity
            .chunks_exact(block.topology.node_count())
            .enumerate()
        {
            for (s, local) in table.iter().enumerate().take(nside) {
                let key = face_key(local.iter().map(|&l| nodes[l as usize].0));
                let Some(&f0) = first.get(&key) else { continue };
                let side = Side {
                    elem: ElemId(block.first_elem.0 + k as u32),
                    side: s as u8 + 1,
                };
                let mut f = f0;
                while f != u32::MAX {
                    let slot = &mut found[f as usize];
                    if slot.is_none()
                        || same_orientation(
                            local.iter().map(|&l| nodes[l as usize].0),
                            faces[f as usize].2,
                        )
                    {
                        *slot = Some(side);
                    }
                    f = chain[f as usize];
                }
            }
        }
    }
    found
}

/// A multiplicative hash for small integer keys (FxHash-style): the keys are node
/// indices, not attacker-controlled, and SipHash would dominate the face matching time.
#[derive(Clone, Copy, Default)]
struct FastHash;

struct FastHasher(u64);

impl std::hash::BuildHasher for FastHash {
    type Hasher = FastHasher;
    fn build_hasher(&self) -> FastHasher {
        FastHasher(0)
    }
}

impl std::hash::Hasher for FastHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        let mut chunks = bytes.chunks_exact(8);
        for c in &mut chunks {
            self.write_u64(u64::from_le_bytes(c.try_into().expect("8 bytes")));
        }
        for &b in chunks.remainder() {
            self.write_u64(b as u64);
        }
    }
    fn write_u32(&mut self, v: u32) {
        self.write_u64(v as u64);
    }
    fn write_u64(&mut self, v: u64) {
        self.0 = (self.0.rotate_left(5) ^ v).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    fn write_usize(&mut self, v: usize) {
        self.write_u64(v as u64);
    }
}

/// True when `side` lists the same cycle as `face` in the same direction.
fn same_orientation(side: impl Iterator<Item = u32>, face: &[u32]) -> bool {
    let mut buf = [u32::MAX; 4];
    let mut n = 0;
    for (slot, v) in buf.iter_mut().zip(side) {
        *slot = v;
        n += 1;
    }
    if n != face.len() || n < 3 {
        return n == face.len() && buf[..n] == *face;
    }
    let Some(start) = buf[..n].iter().position(|&v| v == face[0]) else {
        return false;
    };
    (0..n).all(|i| buf[(start + i) % n] == face[i])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_str(text: &str) -> Result<Mesh, String> {
        let raw = parse(text.as_bytes()).map_err(|e| format!("line {}: {}", e.line, e.message))?;
        lower(raw).map_err(|(m, _)| m)
    }

    /// One tet with sparse node tags, its four faces, and a physical surface on one face.
    const ONE_TET: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
$PhysicalNames\n2\n2 7 \"base\"\n3 3 \"solid\"\n$EndPhysicalNames\n\
$Entities\n0 0 1 1\n\
4 0 0 0 1 1 0 1 7 0\n\
9 0 0 0 1 1 1 1 3 0\n$EndEntities\n\
$Nodes\n1 4 10 40\n3 9 0 4\n10\n20\n30\n40\n\
0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n\
$Elements\n2 2 5 6\n3 9 4 1\n5 10 20 30 40\n2 4 2 1\n6 10 30 20\n$EndElements\n";

    #[test]
    fn one_tet_with_sparse_tags_and_a_base_side_set() {
        let m = read_str(ONE_TET).unwrap();
        assert_eq!(m.dim, 3);
        assert_eq!(m.node_numbers, vec![10, 20, 30, 40]);
        assert_eq!(m.elem_numbers, vec![5]);
        assert_eq!(m.blocks.len(), 1);
        assert_eq!((m.blocks[0].id, m.blocks[0].name.as_str()), (3, "solid"));
        assert_eq!(m.blocks[0].topology, Topology::Tet4);
        assert_eq!(m.side_sets.len(), 1);
        let s = &m.side_sets[0];
        assert_eq!((s.id, s.name.as_str()), (7, "base"));
        // Nodes 10, 30, 20 are the Exodus tet side 4 (local 0, 2, 1).
        assert_eq!(
            s.sides,
            vec![Side {
                elem: ElemId(0),
                side: 4
            }]
        );
        assert_eq!(m.validate(), Ok(()));
    }

    #[test]
    fn surface_groups_without_volume_groups_are_refused() {
        let text = ONE_TET.replace("9 0 0 0 1 1 1 1 3 0", "9 0 0 0 1 1 1 0 0");
        let err = read_str(&text).unwrap_err();
        assert!(err.contains("no physical volume"), "{err}");
    }

    #[test]
    fn a_bad_number_gives_its_line() {
        let text = ONE_TET.replace("0 1 0\n", "0 one 0\n");
        let err = read_str(&text).unwrap_err();
        // The coordinate lines start at line 21 (1-based); `0 1 0` is the third.
        assert!(err.starts_with("line 23:"), "{err}");
        assert!(err.contains("`one`"), "{err}");
    }

    #[test]
    fn element_referring_to_a_missing_node_is_an_error() {
        let text = ONE_TET.replace("5 10 20 30 40", "5 10 20 30 41");
        let err = read_str(&text).unwrap_err();
        assert!(err.contains("element 5 refers to node 41"), "{err}");
    }

    #[test]
    fn orientation_of_cycles() {
        assert!(same_orientation([1, 2, 3].into_iter(), &[2, 3, 1]));
        assert!(!same_orientation([1, 2, 3].into_iter(), &[1, 3, 2]));
        assert!(same_orientation([1, 2, 3, 4].into_iter(), &[3, 4, 1, 2]));
    }
}
