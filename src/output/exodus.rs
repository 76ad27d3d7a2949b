//! Exodus II results writer, in pure Rust on netCDF classic 64-bit-offset files (CDF-2),
//! with the names of the Exodus II format (the reference C library's `exodusII_int.h`;
//! the full list, each with the test that checks it, is in `docs/exodus.md`).
//!
//! Entry point: [`ExodusWriter`]: [`ExodusWriter::create`] writes the mesh (title and
//! the global attributes `api_version`, `version`, `floating_point_word_size`,
//! `file_size`, `maximum_name_length`, `int64_status`; one QA record `qa_records` and one
//! information record `info_records`; coordinates `coordx/coordy[/coordz]` named by
//! `coor_names`; number maps `node_num_map`, `elem_num_map`; element blocks `connectN`
//! with `elem_type`, `eb_status`, ids `eb_prop1` and names `eb_names`, shell thickness as
//! `attribN` named by `attrib_nameN`; node sets `node_nsN`, `ns_status`, `ns_prop1`,
//! `ns_names`; side sets `elem_ssN`/`side_ssN`, `ss_status`, `ss_prop1`, `ss_names`) and
//! declares the result variables: nodal `vals_nod_varK` named by `name_nod_var`, element
//! `vals_elem_varVebB` named by `name_elem_var` with the truth table `elem_var_tab`,
//! optional global variables `vals_glo_var` named by `name_glo_var`, and `time_whole`.
//! [`ExodusWriter::write_step`] appends one record (a time and every variable's values)
//! and then bumps `numrecs` in the header, so the file is complete and readable after
//! every step and a killed run keeps the steps written so far. Nothing of a step is kept
//! in memory after it is written.
//!
//! Conventions, as [`crate::mesh::exodus`] reads them back: indices in `connectN`,
//! `node_nsN` and `elem_ssN` are 1-based positions; ids and numbers are 32-bit (CDF-2
//! has no 64-bit integers), so a larger id is an input error. Empty blocks and sets get
//! no size dimension (a zero-length dimension would be the record dimension), as the
//! Exodus library writes "NULL" entities. Sets carry no distribution factors.
//! Assemblies are not written.

use std::fs::File;
use std::io::{self, BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use super::netcdf::{AttrValue, Layout, NUMRECS_OFFSET, NcType, Schema};
use crate::mesh::{Mesh, Topology};

/// Streams a transient result to an Exodus II file, one step at a time.
#[derive(Debug)]
pub struct ExodusWriter {
    file: File,
    path: PathBuf,
    record_begin: u64,
    record_size: u64,
    steps: u32,
    num_nodes: usize,
    num_elems: usize,
    nodal: Vec<String>,
    global: Vec<String>,
    element: Vec<String>,
    /// Element range (first, count) of every non-empty block, in file order.
    block_ranges: Vec<(usize, usize)>,
}

/// What goes into a fixed-size variable; large arrays are made only when written.
enum Fill {
    Chars(Vec<u8>),
    Ints(Vec<i32>),
    Coord(usize),
    NodeNumbers,
    ElemNumbers,
    Connect(usize),
    Thickness(usize, f64),
    NodeSet(usize),
    SideElems(usize),
    SideNumbers(usize),
}

/// `len_string`: QA record entries hold 32 characters and a NUL.
const LEN_STRING: u64 = 33;
/// `len_line`: information records hold 80 characters and a NUL.
const LEN_LINE: u64 = 81;

/// The QA record: code name, code version, and the date (`MM/DD/YY`) and time
/// (`HH:MM:SS`, UTC) the file was written.
fn qa_record() -> Vec<String> {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rest) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    vec![
        "seam".to_string(),
        env!("CARGO_PKG_VERSION").to_string(),
        format!("{m:02}/{d:02}/{:02}", y.rem_euclid(100)),
        format!("{:02}:{:02}:{:02}", rest / 3600, rest / 60 % 60, rest % 60),
    ]
}

/// The proleptic Gregorian date of `days` since 1970-01-01 (H. Hinnant's
/// `civil_from_days`, "chrono-Compatible Low-Level Date Algorithms").
fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let y = yoe + era * 400 + i64::from(m <= 2);
    (y, m, d)
}

fn invalid(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// `v` as a 32-bit integer, or an error naming `what`.
fn int32(v: i64, what: &dyn Fn() -> String) -> io::Result<i32> {
    i32::try_from(v).map_err(|_| {
        invalid(format!(
            "{} is {v}, beyond the 32-bit integers an Exodus (CDF-2) file holds; renumber the mesh",
            what()
        ))
    })
}

/// A char array of `names`, each padded with NULs to `len` bytes.
fn name_table(names: &[String], len: u64) -> Vec<u8> {
    let mut out = Vec::with_capacity(names.len() * len as usize);
    for n in names {
        let start = out.len();
        out.extend_from_slice(n.as_bytes());
        out.resize(start + len as usize, 0);
    }
    out
}

fn check_names(kind: &str, names: &[&str]) -> io::Result<()> {
    for (k, n) in names.iter().enumerate() {
        if n.is_empty() || n.contains('\0') {
            return Err(invalid(format!(
                "{kind} variable {} has the name `{n}`; names must be non-empty and without NUL",
                k + 1
            )));
        }
        if names[..k].contains(n) {
            return Err(invalid(format!(
                "{kind} variable `{n}` is named twice; give each variable its own name"
            )));
        }
    }
    Ok(())
}

impl ExodusWriter {
    /// Create `path` (overwriting it) with `mesh` and the names of the nodal and element
    /// variables that every [`write_step`](Self::write_step) will give.
    pub fn create(path: &Path, mesh: &Mesh, nodal: &[&str], element: &[&str]) -> io::Result<Self> {
        Self::create_with_globals(path, mesh, nodal, element, &[])
    }

    /// As [`create`](Self::create), with global (one value per step) variables too
    /// (`name_glo_var`, `vals_glo_var`), given to
    /// [`write_step_with_globals`](Self::write_step_with_globals).
    pub fn create_with_globals(
        path: &Path,
        mesh: &Mesh,
        nodal: &[&str],
        element: &[&str],
        global: &[&str],
    ) -> io::Result<Self> {
        check_names("nodal", nodal)?;
        check_names("element", element)?;
        check_names("global", global)?;
        let (schema, fills) = Self::schema(path, mesh, nodal, element, global)?;
        let layout = schema.layout()?;
        let file = File::create(path)?;
        let mut out = BufWriter::with_capacity(1 << 20, &file);
        out.write_all(&layout.header)?;
        write_fixed(&mut out, mesh, &schema, &layout, fills)?;
        out.flush()?;
        drop(out);
        Ok(ExodusWriter {
            file,
            path: path.to_path_buf(),
            record_begin: layout.record_begin,
            record_size: layout.record_size,
            steps: 0,
            num_nodes: mesh.num_nodes(),
            num_elems: mesh.num_elems(),
            nodal: nodal.iter().map(|s| s.to_string()).collect(),
            element: element.iter().map(|s| s.to_string()).collect(),
            global: global.iter().map(|s| s.to_string()).collect(),
            block_ranges: mesh
                .blocks
                .iter()
                .filter(|b| !b.is_empty())
                .map(|b| (b.first_elem.index(), b.len()))
                .collect(),
        })
    }

    /// The netCDF schema of the file and the data of its fixed variables, by variable.
    fn schema(
        path: &Path,
        mesh: &Mesh,
        nodal: &[&str],
        element: &[&str],
        global: &[&str],
    ) -> io::Result<(Schema, Vec<Option<Fill>>)> {
        if !(mesh.dim == 2 || mesh.dim == 3) {
            return Err(invalid(format!(
                "the mesh has dimension {}; Exodus output needs a 2-D or 3-D mesh",
                mesh.dim
            )));
        }
        check_indices(mesh)?;
        let mut names: Vec<&str> = Vec::new();
        names.extend(mesh.blocks.iter().map(|b| b.name.as_str()));
        names.extend(mesh.side_sets.iter().map(|s| s.name.as_str()));
        names.extend(mesh.node_sets.iter().map(|s| s.name.as_str()));
        names.extend(nodal);
        names.extend(element);
        names.extend(global);
        let longest = names.iter().map(|n| n.len()).max().unwrap_or(0);
        // Exodus' default name length is 32 (+ NUL); longer names widen the table.
        let max_name = longest.max(32);
        let name_len = max_name as u64 + 1;

        let mut s = Schema::default();
        let mut fills: Vec<Option<Fill>> = Vec::new();
        let title = path
            .file_stem()
            .map(|t| format!("seam results: {}", t.to_string_lossy()))
            .unwrap_or_else(|| "seam results".to_string());
        let title: String = title.chars().take(80).collect();
        s.global("api_version", AttrValue::Floats(vec![8.03]));
        s.global("version", AttrValue::Floats(vec![8.03]));
        s.global("floating_point_word_size", AttrValue::Ints(vec![8]));
        s.global("file_size", AttrValue::Ints(vec![1]));
        s.global(
            "maximum_name_length",
            AttrValue::Ints(vec![max_name as i32]),
        );
        s.global("int64_status", AttrValue::Ints(vec![0]));
        s.global("title", AttrValue::Text(title));

        let len_string = s.dim("len_string", LEN_STRING);
        let len_line = s.dim("len_line", LEN_LINE);
        let four = s.dim("four", 4);
        let len_name = s.dim("len_name", name_len);
        let time = s.dim("time_step", 0);
        let num_dim = s.dim("num_dim", mesh.dim as u64);
        let nn = mesh.num_nodes();
        let ne = mesh.num_elems();
        let num_nodes = (nn > 0).then(|| s.dim("num_nodes", nn as u64));
        let num_elem = (ne > 0).then(|| s.dim("num_elem", ne as u64));
        let nblk = mesh.blocks.len();
        let num_el_blk = (nblk > 0).then(|| s.dim("num_el_blk", nblk as u64));
        let nss = mesh.side_sets.len();
        let num_ss = (nss > 0).then(|| s.dim("num_side_sets", nss as u64));
        let nns = mesh.node_sets.len();
        let num_ns = (nns > 0).then(|| s.dim("num_node_sets", nns as u64));

        let mut add = |s: &mut Schema, name: &str, dims: &[usize], ty, fill: Option<Fill>| {
            let v = s.var(name, dims, ty);
            fills.push(fill);
            v
        };

        add(&mut s, "time_whole", &[time], NcType::Double, None);
        // One QA record (code name, version, date, time) and one information record, as
        // `ex_put_qa` and `ex_put_info` store them: NUL-padded char arrays.
        let num_qa = s.dim("num_qa_rec", 1);
        add(
            &mut s,
            "qa_records",
            &[num_qa, four, len_string],
            NcType::Char,
            Some(Fill::Chars(name_table(&qa_record(), LEN_STRING))),
        );
        let num_info = s.dim("num_info", 1);
        let info = format!("seam {} results", env!("CARGO_PKG_VERSION"));
        add(
            &mut s,
            "info_records",
            &[num_info, len_line],
            NcType::Char,
            Some(Fill::Chars(name_table(&[info], LEN_LINE))),
        );
        if !global.is_empty() {
            let num_glo_var = s.dim("num_glo_var", global.len() as u64);
            let names: Vec<String> = global.iter().map(|n| n.to_string()).collect();
            add(
                &mut s,
                "name_glo_var",
                &[num_glo_var, len_name],
                NcType::Char,
                Some(Fill::Chars(name_table(&names, name_len))),
            );
            add(
                &mut s,
                "vals_glo_var",
                &[time, num_glo_var],
                NcType::Double,
                None,
            );
        }

        let axes = ["x", "y", "z"].map(String::from);
        add(
            &mut s,
            "coor_names",
            &[num_dim, len_name],
            NcType::Char,
            Some(Fill::Chars(name_table(&axes[..mesh.dim], name_len))),
        );
        if let Some(num_nodes) = num_nodes {
            for (d, axis) in ["coordx", "coordy", "coordz"]
                .iter()
                .enumerate()
                .take(mesh.dim)
            {
                add(
                    &mut s,
                    axis,
                    &[num_nodes],
                    NcType::Double,
                    Some(Fill::Coord(d)),
                );
            }
            for (k, &n) in mesh.node_numbers.iter().enumerate() {
                int32(n, &|| format!("the number of node {}", k + 1))?;
            }
            add(
                &mut s,
                "node_num_map",
                &[num_nodes],
                NcType::Int,
                Some(Fill::NodeNumbers),
            );
        }
        if let Some(num_elem) = num_elem {
            for (k, &n) in mesh.elem_numbers.iter().enumerate() {
                int32(n, &|| format!("the number of element {}", k + 1))?;
            }
            add(
                &mut s,
                "elem_num_map",
                &[num_elem],
                NcType::Int,
                Some(Fill::ElemNumbers),
            );
        }

        if let Some(num_el_blk) = num_el_blk {
            let mut ids = Vec::with_capacity(nblk);
            for b in &mesh.blocks {
                ids.push(int32(b.id, &|| "a block id".to_string())?);
            }
            let status = mesh
                .blocks
                .iter()
                .map(|b| i32::from(!b.is_empty()))
                .collect();
            add(
                &mut s,
                "eb_status",
                &[num_el_blk],
                NcType::Int,
                Some(Fill::Ints(status)),
            );
            let v = add(
                &mut s,
                "eb_prop1",
                &[num_el_blk],
                NcType::Int,
                Some(Fill::Ints(ids)),
            );
            s.var_attr(v, "name", AttrValue::Text("ID".into()));
            let names: Vec<String> = mesh.blocks.iter().map(|b| b.name.clone()).collect();
            add(
                &mut s,
                "eb_names",
                &[num_el_blk, len_name],
                NcType::Char,
                Some(Fill::Chars(name_table(&names, name_len))),
            );
        }
        // Block dimensions are needed again by the element variables.
        let mut blk_dim = vec![None; nblk];
        for (i, b) in mesh.blocks.iter().enumerate() {
            let n = i + 1;
            if b.is_empty() {
                continue;
            }
            let count = s.dim(&format!("num_el_in_blk{n}"), b.len() as u64);
            let npe = s.dim(
                &format!("num_nod_per_el{n}"),
                b.topology.node_count() as u64,
            );
            blk_dim[i] = Some(count);
            let v = add(
                &mut s,
                &format!("connect{n}"),
                &[count, npe],
                NcType::Int,
                Some(Fill::Connect(i)),
            );
            s.var_attr(
                v,
                "elem_type",
                AttrValue::Text(elem_type(b.topology).into()),
            );
            if let Some(t) = b.thickness.filter(|_| b.topology.is_shell()) {
                let natt = s.dim(&format!("num_att_in_blk{n}"), 1);
                add(
                    &mut s,
                    &format!("attrib{n}"),
                    &[count, natt],
                    NcType::Double,
                    Some(Fill::Thickness(i, t)),
                );
                add(
                    &mut s,
                    &format!("attrib_name{n}"),
                    &[natt, len_name],
                    NcType::Char,
                    Some(Fill::Chars(name_table(
                        &["thickness".to_string()],
                        name_len,
                    ))),
                );
            }
        }

        if let Some(num_ss) = num_ss {
            let mut ids = Vec::with_capacity(nss);
            for ss in &mesh.side_sets {
                ids.push(int32(ss.id, &|| "a side-set id".to_string())?);
            }
            let status = mesh
                .side_sets
                .iter()
                .map(|s| i32::from(!s.sides.is_empty()))
                .collect();
            add(
                &mut s,
                "ss_status",
                &[num_ss],
                NcType::Int,
                Some(Fill::Ints(status)),
            );
            let v = add(
                &mut s,
                "ss_prop1",
                &[num_ss],
                NcType::Int,
                Some(Fill::Ints(ids)),
            );
            s.var_attr(v, "name", AttrValue::Text("ID".into()));
            let names: Vec<String> = mesh.side_sets.iter().map(|s| s.name.clone()).collect();
            add(
                &mut s,
                "ss_names",
                &[num_ss, len_name],
                NcType::Char,
                Some(Fill::Chars(name_table(&names, name_len))),
            );
            for (i, ss) in mesh.side_sets.iter().enumerate() {
                if ss.sides.is_empty() {
                    continue;
                }
                let d = s.dim(&format!("num_side_ss{}", i + 1), ss.sides.len() as u64);
                add(
                    &mut s,
                    &format!("elem_ss{}", i + 1),
                    &[d],
                    NcType::Int,
                    Some(Fill::SideElems(i)),
                );
                add(
                    &mut s,
                    &format!("side_ss{}", i + 1),
                    &[d],
                    NcType::Int,
                    Some(Fill::SideNumbers(i)),
                );
            }
        }

        if let Some(num_ns) = num_ns {
            let mut ids = Vec::with_capacity(nns);
            for ns in &mesh.node_sets {
                ids.push(int32(ns.id, &|| "a node-set id".to_string())?);
            }
            let status = mesh
                .node_sets
                .iter()
                .map(|s| i32::from(!s.nodes.is_empty()))
                .collect();
            add(
                &mut s,
                "ns_status",
                &[num_ns],
                NcType::Int,
                Some(Fill::Ints(status)),
            );
            let v = add(
                &mut s,
                "ns_prop1",
                &[num_ns],
                NcType::Int,
                Some(Fill::Ints(ids)),
            );
            s.var_attr(v, "name", AttrValue::Text("ID".into()));
            let names: Vec<String> = mesh.node_sets.iter().map(|s| s.name.clone()).collect();
            add(
                &mut s,
                "ns_names",
                &[num_ns, len_name],
                NcType::Char,
                Some(Fill::Chars(name_table(&names, name_len))),
            );
            for (i, ns) in mesh.node_sets.iter().enumerate() {
                if ns.nodes.is_empty() {
                    continue;
                }
                let d = s.dim(&format!("num_nod_ns{}", i + 1), ns.nodes.len() as u64);
                add(
                    &mut s,
                    &format!("node_ns{}", i + 1),
                    &[d],
                    NcType::Int,
                    Some(Fill::NodeSet(i)),
                );
            }
        }

        if !nodal.is_empty() {
            let num_nod_var = s.dim("num_nod_var", nodal.len() as u64);
            let names: Vec<String> = nodal.iter().map(|n| n.to_string()).collect();
            add(
                &mut s,
                "name_nod_var",
                &[num_nod_var, len_name],
                NcType::Char,
                Some(Fill::Chars(name_table(&names, name_len))),
            );
        }
        if !element.is_empty() && nblk > 0 {
            let num_elem_var = s.dim("num_elem_var", element.len() as u64);
            let names: Vec<String> = element.iter().map(|n| n.to_string()).collect();
            add(
                &mut s,
                "name_elem_var",
                &[num_elem_var, len_name],
                NcType::Char,
                Some(Fill::Chars(name_table(&names, name_len))),
            );
            let table = mesh
                .blocks
                .iter()
                .flat_map(|b| std::iter::repeat_n(i32::from(!b.is_empty()), element.len()))
                .collect();
            add(
                &mut s,
                "elem_var_tab",
                &[num_el_blk.unwrap_or(0), num_elem_var],
                NcType::Int,
                Some(Fill::Ints(table)),
            );
        }
        // Record variables last, in the order `write_step` writes them.
        if let Some(num_nodes) = num_nodes {
            for k in 1..=nodal.len() {
                add(
                    &mut s,
                    &format!("vals_nod_var{k}"),
                    &[time, num_nodes],
                    NcType::Double,
                    None,
                );
            }
        }
        for v in 1..=element.len() {
            for (i, d) in blk_dim.iter().enumerate() {
                if let Some(d) = *d {
                    add(
                        &mut s,
                        &format!("vals_elem_var{v}eb{}", i + 1),
                        &[time, d],
                        NcType::Double,
                        None,
                    );
                }
            }
        }
        Ok((s, fills))
    }

    /// Append one step: `time`, then `nodal[k]` (one value per mesh node) and
    /// `element[k]` (one value per element, blocks concatenated in mesh order), in the
    /// order of the names given to [`create`](Self::create). The step counts only once
    /// all of it is written.
    pub fn write_step(
        &mut self,
        time: f64,
        nodal: &[&[f64]],
        element: &[&[f64]],
    ) -> io::Result<()> {
        self.write_step_with_globals(time, nodal, element, &[])
    }

    /// As [`write_step`](Self::write_step), with one value per global variable declared
    /// in [`create_with_globals`](Self::create_with_globals).
    pub fn write_step_with_globals(
        &mut self,
        time: f64,
        nodal: &[&[f64]],
        element: &[&[f64]],
        global: &[f64],
    ) -> io::Result<()> {
        if global.len() != self.global.len() {
            return Err(invalid(format!(
                "{} global values given, but the file was created with {} global variables ({})",
                global.len(),
                self.global.len(),
                self.global.join(", ")
            )));
        }
        if !time.is_finite() {
            return Err(invalid(format!(
                "step {} has time {time}; Exodus times must be finite",
                self.steps + 1
            )));
        }
        check_values("nodal", &self.nodal, nodal, self.num_nodes, "mesh node")?;
        check_values("element", &self.element, element, self.num_elems, "element")?;
        let start = self.record_begin + self.steps as u64 * self.record_size;
        self.file.seek(SeekFrom::Start(start))?;
        let mut out = BufWriter::with_capacity(1 << 20, &self.file);
        out.write_all(&time.to_be_bytes())?;
        write_doubles(&mut out, global.iter().copied())?;
        if self.num_nodes > 0 {
            for values in nodal {
                write_doubles(&mut out, values.iter().copied())?;
            }
        }
        if !self.block_ranges.is_empty() {
            for values in element {
                for &(first, count) in &self.block_ranges {
                    write_doubles(&mut out, values[first..first + count].iter().copied())?;
                }
            }
        }
        out.flush()?;
        drop(out);
        let end = self.file.stream_position()?;
        if end != start + self.record_size {
            return Err(io::Error::other(format!(
                "{}: step {} wrote {} bytes, the record holds {}",
                self.path.display(),
                self.steps + 1,
                end - start,
                self.record_size
            )));
        }
        // Only now does the header announce the new step.
        self.steps += 1;
        self.file.seek(SeekFrom::Start(NUMRECS_OFFSET))?;
        self.file.write_all(&self.steps.to_be_bytes())?;
        Ok(())
    }

    /// Number of steps written so far.
    pub fn steps(&self) -> usize {
        self.steps as usize
    }

    /// Flush the file to disk and close it.
    pub fn finish(self) -> io::Result<()> {
        self.file.sync_all()
    }
}

/// Every node and element a block or set refers to must exist: the file stores them as
/// 1-based positions that readers trust.
fn check_indices(mesh: &Mesh) -> io::Result<()> {
    let (nn, ne) = (mesh.num_nodes(), mesh.num_elems());
    for b in &mesh.blocks {
        if let Some(n) = b.connectivity.iter().find(|n| n.index() >= nn) {
            return Err(invalid(format!(
                "block {} refers to node index {}, but the mesh has {nn} nodes; the mesh is \
                 inconsistent (validate it before writing)",
                b.id, n.0
            )));
        }
    }
    for s in &mesh.node_sets {
        if let Some(n) = s.nodes.iter().find(|n| n.index() >= nn) {
            return Err(invalid(format!(
                "node set {} refers to node index {}, but the mesh has {nn} nodes",
                s.id, n.0
            )));
        }
    }
    for s in &mesh.side_sets {
        if let Some(side) = s.sides.iter().find(|x| x.elem.index() >= ne || x.side == 0) {
            return Err(invalid(format!(
                "side set {} holds element index {} side {}, but the mesh has {ne} elements \
                 and sides count from 1",
                s.id, side.elem.0, side.side
            )));
        }
    }
    Ok(())
}

/// The `elem_type` attribute: the bare shape names that Cubit writes and every reader
/// knows (meshio, for one, maps `TETRA4` to no cell type but reads `TETRA`). A 3-node
/// shell is a `TRISHELL3` in Exodus (`SHELL3` would be a 3-node 2-D line shell).
fn elem_type(t: Topology) -> &'static str {
    match t {
        Topology::Tet4 => "TETRA",
        Topology::Wedge6 => "WEDGE",
        Topology::Pyramid5 => "PYRAMID",
        Topology::Shell3 => "TRISHELL3",
        other => other.exodus_name(),
    }
}

fn check_values(
    kind: &str,
    names: &[String],
    values: &[&[f64]],
    expect: usize,
    per: &str,
) -> io::Result<()> {
    if values.len() != names.len() {
        return Err(invalid(format!(
            "{} {kind} variables given, but the file was created with {} ({}); give one \
             array per declared variable, in that order",
            values.len(),
            names.len(),
            names.join(", ")
        )));
    }
    for (name, v) in names.iter().zip(values) {
        if v.len() != expect {
            return Err(invalid(format!(
                "{kind} variable `{name}` has {} values, expected {expect} (one per {per})",
                v.len()
            )));
        }
    }
    Ok(())
}

/// Big-endian values through a fixed buffer (one `write_all` per 64 KiB, not per value).
fn write_be<const N: usize>(
    out: &mut impl Write,
    values: impl Iterator<Item = [u8; N]>,
) -> io::Result<()> {
    let mut buf = [0u8; 1 << 16];
    let mut n = 0;
    for v in values {
        buf[n..n + N].copy_from_slice(&v);
        n += N;
        if n + N > buf.len() {
            out.write_all(&buf[..n])?;
            n = 0;
        }
    }
    out.write_all(&buf[..n])
}

fn write_doubles(out: &mut impl Write, values: impl Iterator<Item = f64>) -> io::Result<()> {
    write_be(out, values.map(f64::to_be_bytes))
}

fn write_ints(out: &mut impl Write, values: impl Iterator<Item = i32>) -> io::Result<()> {
    write_be(out, values.map(i32::to_be_bytes))
}

/// Write every fixed variable's data in definition order, each padded to its `vsize`.
fn write_fixed(
    out: &mut impl Write,
    mesh: &Mesh,
    schema: &Schema,
    layout: &Layout,
    fills: Vec<Option<Fill>>,
) -> io::Result<()> {
    let pos = |n: u32| n as i32 + 1;
    let mut cursor = layout.header.len() as u64;
    for (k, fill) in fills.into_iter().enumerate() {
        if schema.is_record(k) {
            continue;
        }
        if cursor != layout.begin[k] {
            return Err(io::Error::other(format!(
                "internal: variable `{}` would land at byte {cursor}, the header says {}",
                schema.var_name(k),
                layout.begin[k]
            )));
        }
        let Some(fill) = fill else {
            return Err(io::Error::other(format!(
                "internal: fixed variable `{}` has no data",
                schema.var_name(k)
            )));
        };
        let mut counter = Counter {
            out: &mut *out,
            n: 0,
        };
        match fill {
            Fill::Chars(bytes) => counter.write_all(&bytes)?,
            Fill::Ints(v) => write_ints(&mut counter, v.into_iter())?,
            Fill::Coord(d) => write_doubles(&mut counter, mesh.coords.iter().map(|p| p[d]))?,
            Fill::NodeNumbers => {
                write_ints(&mut counter, mesh.node_numbers.iter().map(|&n| n as i32))?
            }
            Fill::ElemNumbers => {
                write_ints(&mut counter, mesh.elem_numbers.iter().map(|&n| n as i32))?
            }
            Fill::Connect(b) => write_ints(
                &mut counter,
                mesh.blocks[b].connectivity.iter().map(|n| pos(n.0)),
            )?,
            Fill::Thickness(b, t) => {
                write_doubles(&mut counter, std::iter::repeat_n(t, mesh.blocks[b].len()))?
            }
            Fill::NodeSet(i) => write_ints(
                &mut counter,
                mesh.node_sets[i].nodes.iter().map(|n| pos(n.0)),
            )?,
            Fill::SideElems(i) => write_ints(
                &mut counter,
                mesh.side_sets[i].sides.iter().map(|s| pos(s.elem.0)),
            )?,
            Fill::SideNumbers(i) => write_ints(
                &mut counter,
                mesh.side_sets[i].sides.iter().map(|s| i32::from(s.side)),
            )?,
        }
        let written = counter.n;
        let expect = schema.count(k) * schema.var_type(k).size();
        if written != expect {
            return Err(io::Error::other(format!(
                "internal: variable `{}` has {written} bytes of data, its shape needs {expect}",
                schema.var_name(k)
            )));
        }
        let pad = layout.vsize[k] - written;
        out.write_all(&[0u8; 4][..pad as usize])?;
        cursor += layout.vsize[k];
    }
    Ok(())
}

/// Counts the bytes passing through to `out`.
struct Counter<'a, W: Write> {
    out: &'a mut W,
    n: u64,
}

impl<W: Write> Write for Counter<'_, W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.out.write(buf)?;
        self.n += n as u64;
        Ok(n)
    }

    fn flush(&mut self) -> io::Result<()> {
        self.out.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::civil_from_days;

    #[test]
    fn civil_dates_of_known_days() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(19_723), (2024, 1, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
    }
}
