//! Exodus II reader (netCDF classic, 64-bit offset, CDF-5 and netCDF-4/HDF5), on the
//! pure-Rust `netcdf-reader` crate, with the names of the Exodus II format (the reference
//! C library's `exodusII_int.h`; the full list, each with the test that checks it
//! against files written by that library, is in `docs/exodus.md`).
//!
//! Entry points: [`read`] for the mesh; [`read_times`], [`read_nodal_variable`],
//! [`read_element_variable`], [`read_global_variable`], [`read_side_set_variable`],
//! [`read_node_set_variable`] for results; [`read_records`] for the QA and information
//! records. The mesh is read from the coordinates (`coordx/coordy/coordz`, or the older
//! combined `coord`), the number maps (`node_num_map`, `elem_num_map`; 1..n when absent),
//! element blocks (`connectN` with its `elem_type`, ids `eb_prop1`, names `eb_names`,
//! shell thickness from `attribN`/`attrib_nameN`), side sets (`elem_ssN`/`side_ssN`,
//! `num_side_ssN`, `ss_prop1`, `ss_names`; the `ss_elemN`/`ss_sideN` of earlier seam
//! versions too), node sets (`node_nsN`, `num_nod_nsN`, `ns_prop1`, `ns_names`) and
//! assemblies (`assembly_entityN`). Distribution factors, status arrays and extra maps
//! are not needed and not read.
//!
//! Conventions, as in the Exodus II API: node indices in `connectN` and `node_nsN`, and
//! element indices in `elem_ssN`, are 1-based *positions* (not the numbers of the maps);
//! they become dense 0-based [`NodeId`]/[`ElemId`] here. Integer variables may be 8-,
//! 16-, 32- or 64-bit. An empty ("NULL") block has no `num_el_in_blkN` dimension and no
//! `connectN`; it is kept, with the topology of its `elem_type` if given, else `Hex8`
//! (3-D) / `Quad4` (2-D). Every index is range-checked while reading, so a corrupt file
//! gives an error naming the file and the variable, never a panic.

use std::path::Path;

use netcdf_reader::{NcFile, NcSliceInfo, NcSliceInfoElem, NcType};

use super::{Assembly, AssemblyKind, Mesh, MeshError, NodeId, NodeSet, Side, SideSet, Topology};
use crate::mesh::ElemId;

/// Read an Exodus II file. The mesh is not validated here; [`super::read`] does that.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    open(path)?.read_mesh()
}

/// Open `path` as netCDF, with the data bound its size allows.
fn open(path: &Path) -> Result<ExoFile<'_>, MeshError> {
    let file = NcFile::open(path).map_err(|e| match e {
        netcdf_reader::Error::Io(source) => MeshError::Open {
            path: path.to_path_buf(),
            source,
        },
        other if looks_truncated(&other) => MeshError::format(
            path,
            format!("the file is truncated: {other}"),
            "the file is shorter than its header says; re-export it or check that the copy finished",
        ),
        other => MeshError::format(
            path,
            format!("not a readable netCDF/Exodus II file: {other}"),
            "the file may be corrupt or not an Exodus file; re-export it from Cubit/SEACAS",
        ),
    })?;
    let file_len = std::fs::metadata(path).map(|m| m.len()).unwrap_or(u64::MAX);
    // Classic data is stored uncompressed; netCDF-4 data may be deflated, which shrinks
    // data at most ~1032:1 (zlib's limit), so allow 1100x.
    let max_bytes = if file.as_classic().is_some() {
        file_len
    } else {
        file_len.saturating_mul(1100).saturating_add(1 << 20)
    };
    Ok(ExoFile {
        path,
        file,
        max_bytes,
    })
}

/// The times of the steps stored in an Exodus file (`time_whole`); empty when the file
/// holds no steps.
pub fn read_times(path: &Path) -> Result<Vec<f64>, MeshError> {
    let ex = open(path)?;
    let steps = ex.dim_opt("time_step").unwrap_or(0);
    if steps == 0 || !ex.has_var("time_whole") {
        return Ok(Vec::new());
    }
    ex.floats("time_whole", steps)
}

/// The values of nodal variable `name` at step `step` (0-based, as in [`read_times`]), one
/// per node in the order [`super::read`] numbers the nodes. Reads `vals_nod_varK` (or the
/// older combined `vals_nod_var`) named by `name_nod_var`; names match exactly, else
/// ignoring case.
pub fn read_nodal_variable(path: &Path, name: &str, step: usize) -> Result<Vec<f64>, MeshError> {
    let ex = open(path)?;
    let nvar = ex.dim_opt("num_nod_var").unwrap_or(0);
    let names = ex.names("name_nod_var", nvar)?;
    let k = names
        .iter()
        .position(|n| n == name)
        .or_else(|| names.iter().position(|n| n.eq_ignore_ascii_case(name)));
    let Some(k) = k else {
        let have = if names.is_empty() {
            "the file has no nodal variables".to_string()
        } else {
            format!(
                "the file has {}",
                names
                    .iter()
                    .map(|n| format!("`{n}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        };
        return Err(ex.err(
            format!("no nodal variable `{name}`: {have}"),
            "use one of the names the file has (`seam run` writes `temperature`)",
        ));
    };
    let steps = ex.dim_opt("time_step").unwrap_or(0);
    if step >= steps {
        return Err(ex.err(
            format!("step {step} asked for, but the file holds {steps} step(s) (numbered from 0)"),
            "ask for a step below the count; a run that stopped early holds fewer steps",
        ));
    }
    let nodes = ex.dim_opt("num_nodes").unwrap_or(0);
    if nodes == 0 {
        return Ok(Vec::new());
    }
    let (var, selection) = if ex.has_var(&format!("vals_nod_var{}", k + 1)) {
        (
            format!("vals_nod_var{}", k + 1),
            vec![
                NcSliceInfoElem::Index(step as u64),
                NcSliceInfoElem::Slice {
                    start: 0,
                    end: nodes as u64,
                    step: 1,
                },
            ],
        )
    } else {
        (
            "vals_nod_var".to_string(),
            vec![
                NcSliceInfoElem::Index(step as u64),
                NcSliceInfoElem::Index(k as u64),
                NcSliceInfoElem::Slice {
                    start: 0,
                    end: nodes as u64,
                    step: 1,
                },
            ],
        )
    };
    if !ex.has_var(&var) {
        return Err(ex.err(
            format!("nodal variable `{name}` is named but its values (`{var}`) are missing"),
            MISSING_HELP,
        ));
    }
    ex.bound(&var, nodes, 4)?;
    let values = ex
        .file
        .read_variable_slice_as_f64(
            &var,
            &NcSliceInfo {
                selections: selection,
            },
        )
        .map_err(|e| ex.nc_err(&var, e))?;
    if values.len() != nodes {
        return Err(ex.err(
            format!(
                "`{var}` gives {} values at step {step}, expected {nodes}",
                values.len()
            ),
            "the file's dimensions disagree with its data; re-export it",
        ));
    }
    Ok(values.iter().copied().collect())
}

/// The QA records (code name, version, date, time) and information lines of a file.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Records {
    /// `qa_records`: one `[code, version, date, time]` per record.
    pub qa: Vec<[String; 4]>,
    /// `info_records`: one line per record.
    pub info: Vec<String>,
}

/// The QA records (`qa_records`, `num_qa_rec`) and information records (`info_records`,
/// `num_info`) of an Exodus file; empty when it has none.
pub fn read_records(path: &Path) -> Result<Records, MeshError> {
    let ex = open(path)?;
    let mut out = Records::default();
    let nqa = ex.dim_opt("num_qa_rec").unwrap_or(0);
    if nqa > 0 && ex.has_var("qa_records") {
        let flat = ex.names("qa_records", 4 * nqa)?;
        out.qa = flat
            .chunks_exact(4)
            .map(|c| [c[0].clone(), c[1].clone(), c[2].clone(), c[3].clone()])
            .collect();
    }
    let ninfo = ex.dim_opt("num_info").unwrap_or(0);
    if ninfo > 0 && ex.has_var("info_records") {
        out.info = ex.names("info_records", ninfo)?;
    }
    Ok(out)
}

/// The values of global variable `name` (named by `name_glo_var`, stored in
/// `vals_glo_var`), one per step.
pub fn read_global_variable(path: &Path, name: &str) -> Result<Vec<f64>, MeshError> {
    let ex = open(path)?;
    let nvar = ex.dim_opt("num_glo_var").unwrap_or(0);
    let k = ex.variable_index("name_glo_var", nvar, name, "global")?;
    let steps = ex.dim_opt("time_step").unwrap_or(0);
    let all = ex.floats("vals_glo_var", steps * nvar)?;
    Ok(all.iter().skip(k).step_by(nvar).copied().collect())
}

/// The values of element variable `name` (named by `name_elem_var`, stored per block in
/// `vals_elem_varVebB`) at step `step` (0-based), one per element in the order
/// [`super::read`] numbers them; NaN in blocks where the truth table `elem_var_tab` says
/// the variable is not stored.
pub fn read_element_variable(path: &Path, name: &str, step: usize) -> Result<Vec<f64>, MeshError> {
    let ex = open(path)?;
    let nvar = ex.dim_opt("num_elem_var").unwrap_or(0);
    let v = ex.variable_index("name_elem_var", nvar, name, "element")? + 1;
    ex.check_step(step)?;
    let nblk = ex.dim_opt("num_el_blk").unwrap_or(0);
    let mut out = Vec::new();
    for b in 1..=nblk {
        let count = ex.dim_opt(&format!("num_el_in_blk{b}")).unwrap_or(0);
        let var = format!("vals_elem_var{v}eb{b}");
        if count == 0 {
            continue;
        }
        if ex.has_var(&var) {
            out.extend(ex.step_slice(&var, step, count)?);
        } else {
            out.extend(std::iter::repeat_n(f64::NAN, count));
        }
    }
    Ok(out)
}

/// The values of side-set variable `name` (named by `name_sset_var`, stored per set in
/// `vals_sset_varVssS`) on side set `id` (its `ss_prop1` id) at step `step` (0-based),
/// one per side in the order of the set; `None` when the variable is not stored on that
/// set (its `sset_var_tab` entry is 0).
pub fn read_side_set_variable(
    path: &Path,
    name: &str,
    id: i64,
    step: usize,
) -> Result<Option<Vec<f64>>, MeshError> {
    open(path)?.set_variable(SetKind::Side, name, id, step)
}

/// As [`read_side_set_variable`], for node-set variables (`name_nset_var`,
/// `vals_nset_varVnsS`, `nset_var_tab`) on node set `id` (its `ns_prop1` id), one value
/// per node of the set.
pub fn read_node_set_variable(
    path: &Path,
    name: &str,
    id: i64,
    step: usize,
) -> Result<Option<Vec<f64>>, MeshError> {
    open(path)?.set_variable(SetKind::Node, name, id, step)
}

#[derive(Clone, Copy)]
enum SetKind {
    Side,
    Node,
}

impl SetKind {
    /// (kind, set count, `num_*_var`, `name_*_var`, ids, `vals_*_var` stem, set tag,
    /// set size stem)
    fn names(self) -> [&'static str; 8] {
        match self {
            SetKind::Side => [
                "side-set",
                "num_side_sets",
                "num_sset_var",
                "name_sset_var",
                "ss_prop1",
                "vals_sset_var",
                "ss",
                "num_side_ss",
            ],
            SetKind::Node => [
                "node-set",
                "num_node_sets",
                "num_nset_var",
                "name_nset_var",
                "ns_prop1",
                "vals_nset_var",
                "ns",
                "num_nod_ns",
            ],
        }
    }
}

struct ExoFile<'a> {
    path: &'a Path,
    file: NcFile,
    /// Most bytes of data the file can hold; counts beyond it are corruption, refused
    /// before allocating.
    max_bytes: u64,
}

/// Exodus `ex_entity_type` codes used in assemblies.
const EX_ELEM_BLOCK: i64 = 1;
const EX_SIDE_SET: i64 = 3;
const EX_ASSEMBLY: i64 = 16;

impl ExoFile<'_> {
    fn err(&self, message: impl Into<String>, help: impl Into<String>) -> MeshError {
        MeshError::format(self.path, message, help)
    }

    /// Wrap a netCDF error raised while reading `what`.
    fn nc_err(&self, what: &str, e: netcdf_reader::Error) -> MeshError {
        if looks_truncated(&e) {
            self.err(
                format!("cannot read `{what}`: the file is truncated ({e})"),
                "the file is shorter than its header says; re-export it or check that the copy finished",
            )
        } else {
            self.err(
                format!("cannot read `{what}`: {e}"),
                "the file may be corrupt; re-export it from Cubit/SEACAS",
            )
        }
    }

    /// The 0-based index of variable `name` in the name table `table` of `count` names;
    /// exact match first, then ignoring case.
    fn variable_index(
        &self,
        table: &str,
        count: usize,
        name: &str,
        kind: &str,
    ) -> Result<usize, MeshError> {
        let names = self.names(table, count)?;
        names
            .iter()
            .position(|n| n == name)
            .or_else(|| names.iter().position(|n| n.eq_ignore_ascii_case(name)))
            .ok_or_else(|| {
                self.err(
                    format!("no {kind} variable `{name}` (`{table}` holds {names:?})"),
                    "use one of the names the file has",
                )
            })
    }

    fn check_step(&self, step: usize) -> Result<(), MeshError> {
        let steps = self.dim_opt("time_step").unwrap_or(0);
        if step >= steps {
            return Err(self.err(
                format!(
                    "step {step} asked for, but the file holds {steps} step(s) (numbered from 0)"
                ),
                "ask for a step below the count; a run that stopped early holds fewer steps",
            ));
        }
        Ok(())
    }

    /// Step `step` of the record variable `var(time_step, n)`.
    fn step_slice(&self, var: &str, step: usize, n: usize) -> Result<Vec<f64>, MeshError> {
        self.bound(var, n, 4)?;
        let values = self
            .file
            .read_variable_slice_as_f64(
                var,
                &NcSliceInfo {
                    selections: vec![
                        NcSliceInfoElem::Index(step as u64),
                        NcSliceInfoElem::Slice {
                            start: 0,
                            end: n as u64,
                            step: 1,
                        },
                    ],
                },
            )
            .map_err(|e| self.nc_err(var, e))?;
        if values.len() != n {
            return Err(self.err(
                format!(
                    "`{var}` gives {} values at step {step}, expected {n}",
                    values.len()
                ),
                "the file's dimensions disagree with its data; re-export it",
            ));
        }
        Ok(values.iter().copied().collect())
    }

    /// A set variable's values on set `id` at `step`; `None` where it is not stored.
    fn set_variable(
        &self,
        kind: SetKind,
        name: &str,
        id: i64,
        step: usize,
    ) -> Result<Option<Vec<f64>>, MeshError> {
        let [what, num_sets, num_var, table, prop, vals, tag, size] = kind.names();
        let nvar = self.dim_opt(num_var).unwrap_or(0);
        let v = self.variable_index(table, nvar, name, what)? + 1;
        self.check_step(step)?;
        let nsets = self.dim_opt(num_sets).unwrap_or(0);
        let ids = self.ids(prop, nsets)?;
        let Some(s) = ids.iter().position(|&i| i == id) else {
            return Err(self.err(
                format!("no {what} with id {id} (`{prop}` holds {ids:?})"),
                "use the id of a set in the file",
            ));
        };
        let var = format!("{vals}{v}{tag}{}", s + 1);
        if !self.has_var(&var) {
            return Ok(None);
        }
        let count = self.dim_opt(&format!("{size}{}", s + 1)).unwrap_or(0);
        self.step_slice(&var, step, count).map(Some)
    }

    /// Refuse `n` entries of `size` bytes when the file cannot hold them.
    fn bound(&self, what: &str, n: usize, size: usize) -> Result<(), MeshError> {
        if (n as u64).saturating_mul(size as u64) > self.max_bytes {
            return Err(self.err(
                format!("`{what}` claims {n} entries, more than the file can hold"),
                "the file is corrupt; re-export it from Cubit/SEACAS",
            ));
        }
        Ok(())
    }

    fn dim_opt(&self, name: &str) -> Option<usize> {
        self.file.dimension(name).ok().map(|d| d.size as usize)
    }

    fn dim(&self, name: &str, help: &str) -> Result<usize, MeshError> {
        self.dim_opt(name)
            .ok_or_else(|| self.err(format!("missing dimension `{name}`"), help))
    }

    fn has_var(&self, name: &str) -> bool {
        self.file.variable(name).is_ok()
    }

    /// Read an integer variable of any integer type as i64, checking its length.
    fn ints(&self, name: &str, expect: usize) -> Result<Vec<i64>, MeshError> {
        let var = self
            .file
            .variable(name)
            .map_err(|_| self.err(format!("missing variable `{name}`"), MISSING_HELP))?;
        let n = var
            .num_elements()
            .map_err(|e| self.nc_err(name, e.into()))? as usize;
        if n != expect {
            return Err(self.err(
                format!("variable `{name}` has {n} entries, expected {expect}"),
                "the file's dimensions disagree with its data; re-export it",
            ));
        }
        let size = var.dtype().size().unwrap_or(8);
        self.bound(name, n, size)?;
        macro_rules! via {
            ($t:ty) => {{
                let mut buf = vec![<$t>::default(); n];
                self.file
                    .read_variable_into::<$t>(name, &mut buf)
                    .map_err(|e| self.nc_err(name, e))?;
                buf.into_iter().map(|v| v as i64).collect()
            }};
        }
        let out: Vec<i64> = match var.dtype() {
            NcType::Int => via!(i32),
            NcType::Int64 => {
                let mut buf = vec![0i64; n];
                self.file
                    .read_variable_into::<i64>(name, &mut buf)
                    .map_err(|e| self.nc_err(name, e))?;
                buf
            }
            NcType::Short => via!(i16),
            NcType::Byte => via!(i8),
            NcType::UInt => via!(u32),
            NcType::UShort => via!(u16),
            NcType::UByte => via!(u8),
            other => {
                return Err(self.err(
                    format!("variable `{name}` has type {other:?}, expected an integer type"),
                    "the file does not follow the Exodus II layout; re-export it",
                ));
            }
        };
        Ok(out)
    }

    /// 1-based positions in `1..=count` → dense 0-based indices, checked.
    /// `describe(k)` names entry `k` (0-based) for messages.
    fn positions(
        &self,
        name: &str,
        expect: usize,
        count: usize,
        what: &str,
        describe: &dyn Fn(usize) -> String,
    ) -> Result<Vec<u32>, MeshError> {
        let var = self
            .file
            .variable(name)
            .map_err(|_| self.err(format!("missing variable `{name}`"), MISSING_HELP))?;
        let check = |k: usize, v: i64| -> Result<u32, MeshError> {
            if v < 1 || v as u64 > count as u64 {
                Err(self.err(
                    format!(
                        "{} refers to {what} position {v}, but the file has {count} {what}s \
                         (`{name}` entry {}; positions are 1-based)",
                        describe(k),
                        k + 1
                    ),
                    "the file is corrupt or was written with 0-based indices; re-export it",
                ))
            } else {
                Ok((v - 1) as u32)
            }
        };
        // Fast path for the common 32-bit case: no intermediate i64 vector.
        if *var.dtype() == NcType::Int {
            let n = var
                .num_elements()
                .map_err(|e| self.nc_err(name, e.into()))? as usize;
            if n != expect {
                return Err(self.err(
                    format!("variable `{name}` has {n} entries, expected {expect}"),
                    "the file's dimensions disagree with its data; re-export it",
                ));
            }
            self.bound(name, n, 4)?;
            let mut buf = vec![0i32; n];
            self.file
                .read_variable_into::<i32>(name, &mut buf)
                .map_err(|e| self.nc_err(name, e))?;
            let mut out = Vec::with_capacity(n);
            for (k, &v) in buf.iter().enumerate() {
                out.push(check(k, v as i64)?);
            }
            return Ok(out);
        }
        let vals = self.ints(name, expect)?;
        vals.iter().enumerate().map(|(k, &v)| check(k, v)).collect()
    }

    fn floats(&self, name: &str, expect: usize) -> Result<Vec<f64>, MeshError> {
        let var = self
            .file
            .variable(name)
            .map_err(|_| self.err(format!("missing variable `{name}`"), MISSING_HELP))?;
        let n = var
            .num_elements()
            .map_err(|e| self.nc_err(name, e.into()))? as usize;
        if n != expect {
            return Err(self.err(
                format!("variable `{name}` has {n} entries, expected {expect}"),
                "the file's dimensions disagree with its data; re-export it",
            ));
        }
        self.bound(name, n, var.dtype().size().unwrap_or(4))?;
        if *var.dtype() == NcType::Double {
            let mut buf = vec![0.0; n];
            self.file
                .read_variable_into::<f64>(name, &mut buf)
                .map_err(|e| self.nc_err(name, e))?;
            Ok(buf)
        } else {
            let arr = self
                .file
                .read_variable_as_f64(name)
                .map_err(|e| self.nc_err(name, e))?;
            Ok(arr.iter().copied().collect())
        }
    }

    /// Names from a char array such as `eb_names`; empty strings when absent.
    fn names(&self, name: &str, count: usize) -> Result<Vec<String>, MeshError> {
        if !self.has_var(name) {
            return Ok(vec![String::new(); count]);
        }
        if let Ok(var) = self.file.variable(name) {
            let n = var.num_elements().unwrap_or(u64::MAX);
            self.bound(name, usize::try_from(n).unwrap_or(usize::MAX), 1)?;
        }
        let mut v = self
            .file
            .read_variable_as_strings(name)
            .map_err(|e| self.nc_err(name, e))?;
        for s in &mut v {
            *s = s
                .trim_matches(|c: char| c == '\0' || c.is_whitespace())
                .to_string();
        }
        v.resize(count, String::new());
        Ok(v)
    }

    /// Ids from `xx_prop1`, or 1..=count when absent.
    fn ids(&self, name: &str, count: usize) -> Result<Vec<i64>, MeshError> {
        if self.has_var(name) {
            self.ints(name, count)
        } else {
            Ok((1..=count as i64).collect())
        }
    }

    fn read_mesh(&self) -> Result<Mesh, MeshError> {
        let dim = self.dim(
            "num_dim",
            "this does not look like an Exodus II file (netCDF without `num_dim`)",
        )?;
        if !(1..=3).contains(&dim) {
            return Err(self.err(
                format!("num_dim is {dim}; seam reads 2-D and 3-D meshes"),
                "export the mesh in 2-D or 3-D",
            ));
        }
        let num_nodes = self.dim_opt("num_nodes").unwrap_or(0);
        let num_elem = self.dim_opt("num_elem").unwrap_or(0);
        // Every node has `dim` coordinates of at least 4 bytes, every element at least
        // one 4-byte connectivity entry, every block or set at least a 4-byte id.
        self.bound("num_nodes", num_nodes, 4 * dim)?;
        self.bound("num_elem", num_elem, 4)?;
        for d in ["num_el_blk", "num_side_sets", "num_node_sets"] {
            self.bound(d, self.dim_opt(d).unwrap_or(0), 4)?;
        }
        if num_nodes > u32::MAX as usize || num_elem > u32::MAX as usize {
            return Err(self.err(
                "more than 2^32 nodes or elements",
                "split the model; seam indexes nodes and elements with 32 bits",
            ));
        }

        let mut mesh = Mesh {
            dim: dim.max(2),
            ..Mesh::default()
        };
        self.read_coords(&mut mesh, dim, num_nodes)?;

        mesh.node_numbers = if num_nodes > 0 && self.has_var("node_num_map") {
            self.ints("node_num_map", num_nodes)?
        } else {
            (1..=num_nodes as i64).collect()
        };
        let elem_numbers = if num_elem > 0 && self.has_var("elem_num_map") {
            Some(self.ints("elem_num_map", num_elem)?)
        } else {
            None
        };

        self.read_blocks(&mut mesh, dim, num_nodes, elem_numbers.as_deref())?;
        if mesh.elem_numbers.len() != num_elem {
            return Err(self.err(
                format!(
                    "the element blocks hold {} elements but num_elem is {num_elem}",
                    mesh.elem_numbers.len()
                ),
                "the file is inconsistent; re-export it",
            ));
        }
        if let Some(map) = elem_numbers {
            mesh.elem_numbers = map;
        }
        self.read_side_sets(&mut mesh, num_elem)?;
        self.read_node_sets(&mut mesh, num_nodes)?;
        self.read_assemblies(&mut mesh)?;
        Ok(mesh)
    }

    fn read_coords(&self, mesh: &mut Mesh, dim: usize, n: usize) -> Result<(), MeshError> {
        mesh.coords = vec![[0.0; 3]; n];
        if n == 0 {
            return Ok(());
        }
        let axes = ["coordx", "coordy", "coordz"];
        if self.has_var("coordx") {
            for (d, name) in axes.iter().enumerate().take(dim) {
                let v = self.floats(name, n)?;
                for (p, x) in mesh.coords.iter_mut().zip(v) {
                    p[d] = x;
                }
            }
        } else if self.has_var("coord") {
            let v = self.floats("coord", n * dim)?;
            for d in 0..dim {
                for (p, &x) in mesh.coords.iter_mut().zip(&v[d * n..(d + 1) * n]) {
                    p[d] = x;
                }
            }
        } else {
            return Err(self.err(
                "missing coordinates: neither `coordx` nor `coord` is present",
                MISSING_HELP,
            ));
        }
        Ok(())
    }

    /// `map` is `elem_num_map`, used to name elements in messages.
    fn read_blocks(
        &self,
        mesh: &mut Mesh,
        dim: usize,
        num_nodes: usize,
        map: Option<&[i64]>,
    ) -> Result<(), MeshError> {
        let nblk = self.dim_opt("num_el_blk").unwrap_or(0);
        let ids = self.ids("eb_prop1", nblk)?;
        let names = self.names("eb_names", nblk)?;
        for i in 1..=nblk {
            let (id, name) = (ids[i - 1], names[i - 1].clone());
            let label = if name.is_empty() {
                format!("block {id}")
            } else {
                format!("block {id} (`{name}`)")
            };
            let count = self.dim_opt(&format!("num_el_in_blk{i}")).unwrap_or(0);
            let conn_name = format!("connect{i}");
            let conn_var = self.file.variable(&conn_name).ok();
            let elem_type = conn_var
                .and_then(|v| v.attribute("elem_type"))
                .and_then(|a| a.value.as_string())
                .map(|s| {
                    s.trim_matches(|c: char| c == '\0' || c.is_whitespace())
                        .to_string()
                });
            if count == 0 {
                let npe = self.dim_opt(&format!("num_nod_per_el{i}")).unwrap_or(0);
                let topology = elem_type
                    .as_deref()
                    .and_then(|t| Topology::from_exodus_name(t, npe, dim))
                    .unwrap_or(if dim == 3 {
                        Topology::Hex8
                    } else {
                        Topology::Quad4
                    });
                mesh.push_block(id, name, topology, Vec::new(), Some(Vec::new()));
                continue;
            }
            let npe = self.dim(
                &format!("num_nod_per_el{i}"),
                "the file is incomplete; re-export it",
            )?;
            let Some(elem_type) = elem_type else {
                return Err(self.err(
                    format!("{label}: `{conn_name}` is missing or has no `elem_type` attribute"),
                    MISSING_HELP,
                ));
            };
            let Some(topology) = Topology::from_exodus_name(&elem_type, npe, dim) else {
                return Err(self.err(
                    format!(
                        "{label}: element type `{elem_type}` with {npe} nodes is not supported"
                    ),
                    "seam supports HEX8, TETRA4, WEDGE6, PYRAMID5, QUAD4/TRI3 (2-D), \
                     SHELL4/TRISHELL3 and BAR2; convert higher-order blocks to linear ones \
                     (e.g. Cubit `block N element type hex8`)",
                ));
            };
            let first = mesh.elem_numbers.len() as i64;
            let describe = |k: usize| {
                let pos = first as usize + k / npe;
                let number = map
                    .and_then(|m| m.get(pos).copied())
                    .unwrap_or(pos as i64 + 1);
                format!("element {number} in {label}, local node {}", k % npe + 1)
            };
            let idx = self.positions(&conn_name, count * npe, num_nodes, "node", &describe)?;
            let connectivity: Vec<NodeId> = idx.into_iter().map(NodeId).collect();
            mesh.push_block(
                id,
                name,
                topology,
                connectivity,
                Some((first + 1..=first + count as i64).collect()),
            );
            if topology.is_shell() {
                let t = self.shell_thickness(i, count)?;
                if let Some(b) = mesh.blocks.last_mut() {
                    b.thickness = t;
                }
            }
        }
        Ok(())
    }

    /// Thickness of a shell block: the attribute named `thickness`, or the only attribute
    /// when unnamed (the Exodus convention for shells). The first element's value is used.
    fn shell_thickness(&self, i: usize, count: usize) -> Result<Option<f64>, MeshError> {
        let Some(natt) = self.dim_opt(&format!("num_att_in_blk{i}")) else {
            return Ok(None);
        };
        let attr = format!("attrib{i}");
        if natt == 0 || !self.has_var(&attr) {
            return Ok(None);
        }
        let names = self.names(&format!("attrib_name{i}"), natt)?;
        let k = match names
            .iter()
            .position(|n| n.eq_ignore_ascii_case("thickness"))
        {
            Some(k) => k,
            None if natt == 1 && names[0].is_empty() => 0,
            None => return Ok(None),
        };
        let vals = self.floats(&attr, count * natt)?;
        Ok(vals.get(k).copied())
    }

    fn read_side_sets(&self, mesh: &mut Mesh, num_elem: usize) -> Result<(), MeshError> {
        let nss = self.dim_opt("num_side_sets").unwrap_or(0);
        let ids = self.ids("ss_prop1", nss)?;
        let names = self.names("ss_names", nss)?;
        for i in 1..=nss {
            let count = self.dim_opt(&format!("num_side_ss{i}")).unwrap_or(0);
            let mut sides = Vec::new();
            if count > 0 {
                let label = set_label("side set", ids[i - 1], &names[i - 1]);
                let describe = |k: usize| format!("{label}, entry {}", k + 1);
                // The Exodus II names are `elem_ssN`/`side_ssN`; `ss_elemN`/`ss_sideN`
                // are read too: earlier seam versions wrote them.
                let (elem_name, side_name) = if !self.has_var(&format!("elem_ss{i}"))
                    && self.has_var(&format!("ss_elem{i}"))
                {
                    (format!("ss_elem{i}"), format!("ss_side{i}"))
                } else {
                    (format!("elem_ss{i}"), format!("side_ss{i}"))
                };
                let elems = self.positions(&elem_name, count, num_elem, "element", &describe)?;
                let nums = self.ints(&side_name, count)?;
                sides.reserve_exact(count);
                for (k, (&e, &s)) in elems.iter().zip(&nums).enumerate() {
                    if !(1..=u8::MAX as i64).contains(&s) {
                        return Err(self.err(
                            format!(
                                "`{side_name}` entry {} is side {s}; sides are 1-based and small",
                                k + 1
                            ),
                            "the file is corrupt; re-export it",
                        ));
                    }
                    sides.push(Side {
                        elem: ElemId(e),
                        side: s as u8,
                    });
                }
            }
            mesh.side_sets.push(SideSet {
                id: ids[i - 1],
                name: names[i - 1].clone(),
                sides,
            });
        }
        Ok(())
    }

    fn read_node_sets(&self, mesh: &mut Mesh, num_nodes: usize) -> Result<(), MeshError> {
        let nns = self.dim_opt("num_node_sets").unwrap_or(0);
        let ids = self.ids("ns_prop1", nns)?;
        let names = self.names("ns_names", nns)?;
        for i in 1..=nns {
            let count = self.dim_opt(&format!("num_nod_ns{i}")).unwrap_or(0);
            let nodes = if count > 0 {
                let label = set_label("node set", ids[i - 1], &names[i - 1]);
                let describe = |k: usize| format!("{label}, entry {}", k + 1);
                self.positions(&format!("node_ns{i}"), count, num_nodes, "node", &describe)?
                    .into_iter()
                    .map(NodeId)
                    .collect()
            } else {
                Vec::new()
            };
            mesh.node_sets.push(NodeSet {
                id: ids[i - 1],
                name: names[i - 1].clone(),
                nodes,
            });
        }
        Ok(())
    }

    /// Exodus assemblies: variables `assembly_entity<ID>` with attributes `_id`, `_name`,
    /// `_type`; their values are the member ids. Other member kinds are skipped.
    fn read_assemblies(&self, mesh: &mut Mesh) -> Result<(), MeshError> {
        let vars = match self.file.variables() {
            Ok(v) => v,
            Err(_) => return Ok(()),
        };
        for var in vars {
            let Some(suffix) = var.name().strip_prefix("assembly_entity") else {
                continue;
            };
            let attr_i64 = |a: &str| {
                var.attribute(a)
                    .and_then(|a| a.value.as_f64())
                    .map(|v| v as i64)
            };
            let id = attr_i64("_id").or_else(|| suffix.parse().ok()).unwrap_or(0);
            let kind = match attr_i64("_type") {
                Some(EX_ELEM_BLOCK) => AssemblyKind::Blocks,
                Some(EX_SIDE_SET) => AssemblyKind::SideSets,
                Some(EX_ASSEMBLY) => AssemblyKind::Assemblies,
                _ => continue,
            };
            let name = var
                .attribute("_name")
                .and_then(|a| a.value.as_string())
                .map(|s| s.trim_matches('\0').trim().to_string())
                .unwrap_or_default();
            let n = var
                .num_elements()
                .map_err(|e| self.nc_err(var.name(), e.into()))? as usize;
            let members = if n > 0 {
                self.ints(var.name(), n)?
            } else {
                Vec::new()
            };
            mesh.assemblies.push(Assembly {
                id,
                name,
                kind,
                members,
            });
        }
        Ok(())
    }
}

/// netcdf-reader reports a short file as an EOF, or (classic header check) as invalid
/// data saying the file "has only" so many bytes.
fn looks_truncated(e: &netcdf_reader::Error) -> bool {
    match e {
        netcdf_reader::Error::UnexpectedEof { .. } => true,
        netcdf_reader::Error::Io(io) => io.kind() == std::io::ErrorKind::UnexpectedEof,
        netcdf_reader::Error::InvalidData(m) => m.contains("file has only"),
        _ => false,
    }
}

fn set_label(kind: &str, id: i64, name: &str) -> String {
    if name.is_empty() {
        format!("{kind} {id}")
    } else {
        format!("{kind} {id} (`{name}`)")
    }
}

const MISSING_HELP: &str =
    "the file is incomplete or not an Exodus II mesh; re-export it from Cubit/SEACAS";
