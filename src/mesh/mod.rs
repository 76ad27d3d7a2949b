//! The in-memory mesh: nodes, element blocks, side sets, node sets and assemblies,
//! with ids exactly as in the file they came from.
//!
//! Entry points: [`read`] (by file extension: Exodus II or Gmsh 4.1), the generators in
//! [`generate`], and [`Mesh::validate`].
//!
//! Conventions: nodes and elements are addressed inside seam by dense 0-based indices
//! ([`NodeId`], [`ElemId`]; elements numbered block after block in file order). The
//! numbers a user sees — Exodus `node_num_map`/`elem_num_map` or Gmsh tags — are kept in
//! [`Mesh::node_numbers`] and [`Mesh::elem_numbers`] and used in every message. Local
//! sides are 1-based and follow Exodus II (see [`topology`]).

pub mod exodus;
pub mod generate;
pub mod gmsh;
pub mod topology;
mod validate;

use std::path::{Path, PathBuf};

use serde::Serialize;

pub use topology::{FaceShape, Topology};
pub use validate::ValidationError;

/// A node by its dense index in [`Mesh::coords`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct NodeId(pub u32);

/// An element by its dense index over all blocks, in block order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct ElemId(pub u32);

impl NodeId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

impl ElemId {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// One element block: elements of a single topology.
#[derive(Clone, Debug)]
pub struct Block {
    /// Id as in the file (Exodus `eb_prop1`, Gmsh physical tag).
    pub id: i64,
    /// Stored name (`eb_names`, Gmsh physical name); empty if the file gave none.
    pub name: String,
    pub topology: Topology,
    /// Connectivity, `topology.node_count()` entries per element.
    pub connectivity: Vec<NodeId>,
    /// First element of this block in the dense numbering.
    pub first_elem: ElemId,
    /// Shell thickness, when the file or the generator gives one.
    pub thickness: Option<f64>,
}

impl Block {
    pub fn len(&self) -> usize {
        self.connectivity.len() / self.topology.node_count()
    }

    pub fn is_empty(&self) -> bool {
        self.connectivity.is_empty()
    }

    /// Nodes of the `k`-th element of this block.
    pub fn elem_nodes(&self, k: usize) -> &[NodeId] {
        let n = self.topology.node_count();
        &self.connectivity[k * n..(k + 1) * n]
    }

    /// The name Sierra uses for this block: the stored name, or `block_<id>`.
    pub fn sierra_name(&self) -> String {
        sierra_name(&self.name, "block", self.id)
    }

    pub fn elems(&self) -> impl Iterator<Item = ElemId> + '_ {
        let first = self.first_elem.0;
        (0..self.len() as u32).map(move |k| ElemId(first + k))
    }
}

/// One side of one element: the unit a contact surface is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct Side {
    pub elem: ElemId,
    /// 1-based local side number, Exodus convention.
    pub side: u8,
}

#[derive(Clone, Debug)]
pub struct SideSet {
    pub id: i64,
    pub name: String,
    pub sides: Vec<Side>,
}

impl SideSet {
    /// The name Sierra uses: the stored name, or `surface_<id>`.
    pub fn sierra_name(&self) -> String {
        sierra_name(&self.name, "surface", self.id)
    }
}

#[derive(Clone, Debug)]
pub struct NodeSet {
    pub id: i64,
    pub name: String,
    pub nodes: Vec<NodeId>,
}

impl NodeSet {
    /// The name Sierra uses: the stored name, or `nodelist_<id>`.
    pub fn sierra_name(&self) -> String {
        sierra_name(&self.name, "nodelist", self.id)
    }
}

/// What an assembly groups.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum AssemblyKind {
    Blocks,
    SideSets,
    Assemblies,
}

/// A named group of blocks, side sets or other assemblies (Exodus assemblies).
#[derive(Clone, Debug)]
pub struct Assembly {
    pub id: i64,
    pub name: String,
    pub kind: AssemblyKind,
    /// Ids of the members (block ids, side-set ids or assembly ids).
    pub members: Vec<i64>,
}

/// A mesh as read from a file or made by a generator.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    /// Spatial dimension: 2 or 3. 2-D coordinates have `z = 0`.
    pub dim: usize,
    pub coords: Vec<[f64; 3]>,
    /// User-visible node numbers (Exodus `node_num_map`, Gmsh node tags).
    pub node_numbers: Vec<i64>,
    /// User-visible element numbers, in dense element order.
    pub elem_numbers: Vec<i64>,
    pub blocks: Vec<Block>,
    pub side_sets: Vec<SideSet>,
    pub node_sets: Vec<NodeSet>,
    pub assemblies: Vec<Assembly>,
    /// The file this mesh came from, for messages.
    pub source: Option<PathBuf>,
    /// A 2-D mesh read as axisymmetric: x is the radius r ≥ 0, y the axial coordinate,
    /// and every volume and surface integral is per full revolution (× 2πr). Files do
    /// not say so: `seam run` sets it from `[mesh] axisymmetric`, a host in code.
    pub axisymmetric: bool,
}

/// Errors while reading a mesh file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    #[error(
        "cannot open mesh file {path}: {source}\n  help: check the path and that the file is readable"
    )]
    Open {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{path}: unknown mesh format (extension `{ext}`)\n  help: use an Exodus II file (.e, .exo, .g, .gen) or a Gmsh 4.1 file (.msh)"
    )]
    UnknownFormat { path: PathBuf, ext: String },
    #[error("{path}: {message}\n  help: {help}")]
    Format {
        path: PathBuf,
        message: String,
        help: String,
    },
    #[error("{path}: {source}")]
    Invalid {
        path: PathBuf,
        source: ValidationError,
    },
}

impl MeshError {
    pub(crate) fn format(path: &Path, message: impl Into<String>, help: impl Into<String>) -> Self {
        MeshError::Format {
            path: path.to_path_buf(),
            message: message.into(),
            help: help.into(),
        }
    }
}

/// Why a mesh cannot be read as axisymmetric ([`Mesh::set_axisymmetric`]).
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AxisymmetricError {
    #[error("an axisymmetric model needs a 2-D mesh; this one is {0}-D")]
    NotTwoDimensional(usize),
    #[error(
        "x is the radius in an axisymmetric model, but node {number} lies at x = {x} ({count} node(s) at x < 0)"
    )]
    NegativeRadius { number: i64, x: f64, count: usize },
}

impl AxisymmetricError {
    /// The diagnostic code: E0717 (not 2-D), E0718 (a node at x < 0).
    pub fn code(&self) -> &'static str {
        match self {
            AxisymmetricError::NotTwoDimensional(_) => "E0717",
            AxisymmetricError::NegativeRadius { .. } => "E0718",
        }
    }

    /// How to fix it.
    pub fn help(&self) -> &'static str {
        match self {
            AxisymmetricError::NotTwoDimensional(_) => {
                "an axisymmetric model is the (r, z) section of a body of revolution, meshed in 2-D with x the radius; a 3-D mesh is modelled as it is (drop the setting)"
            }
            AxisymmetricError::NegativeRadius { .. } => {
                "mesh the section on the side x ≥ 0 of the axis x = 0 (the y axis is the axis of revolution)"
            }
        }
    }
}

/// Read a mesh by extension (`.e .exo .g .gen .ex2 .nc` → Exodus II, `.msh` → Gmsh 4.1)
/// and validate it.
pub fn read(path: &Path) -> Result<Mesh, MeshError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let mut mesh = match ext.as_str() {
        "e" | "exo" | "g" | "gen" | "ex2" | "exoii" | "nc" => exodus::read(path)?,
        "msh" => gmsh::read(path)?,
        _ => {
            return Err(MeshError::UnknownFormat {
                path: path.to_path_buf(),
                ext,
            });
        }
    };
    mesh.source = Some(path.to_path_buf());
    mesh.validate().map_err(|source| MeshError::Invalid {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(mesh)
}

fn sierra_name(stored: &str, prefix: &str, id: i64) -> String {
    if stored.trim().is_empty() {
        format!("{prefix}_{id}")
    } else {
        stored.trim().to_ascii_lowercase()
    }
}

impl Mesh {
    /// Read this mesh as axisymmetric ([`Mesh::axisymmetric`]): it must be 2-D with every
    /// node at x ≥ 0, the radius (within 1e-12 of the model's size, the round-off of a
    /// node meant to lie on the axis).
    pub fn set_axisymmetric(&mut self) -> Result<(), AxisymmetricError> {
        if self.dim != 2 {
            return Err(AxisymmetricError::NotTwoDimensional(self.dim));
        }
        let tolerance = 1e-12 * self.model_size();
        let off_side = |x: &&[f64; 3]| x[0] < -tolerance || x[0].is_nan();
        if let Some((n, x)) = self.coords.iter().enumerate().find(|(_, x)| off_side(x)) {
            return Err(AxisymmetricError::NegativeRadius {
                number: self.node_number(NodeId(n as u32)),
                x: x[0],
                count: self.coords.iter().filter(off_side).count(),
            });
        }
        self.axisymmetric = true;
        Ok(())
    }

    pub fn num_nodes(&self) -> usize {
        self.coords.len()
    }

    pub fn num_elems(&self) -> usize {
        self.elem_numbers.len()
    }

    /// The block holding `elem` and the element's position inside it.
    pub fn locate(&self, elem: ElemId) -> (&Block, usize) {
        // Blocks are few; a linear scan over their ranges is fine and allocation-free.
        let b = match self.blocks.binary_search_by(|b| b.first_elem.cmp(&elem)) {
            Ok(i) => i,
            Err(i) => i - 1,
        };
        let block = &self.blocks[b];
        (block, elem.index() - block.first_elem.index())
    }

    /// Index of the block holding `elem`.
    pub fn block_of(&self, elem: ElemId) -> usize {
        match self.blocks.binary_search_by(|b| b.first_elem.cmp(&elem)) {
            Ok(i) => {
                // Several empty blocks may start at the same element: take the non-empty one.
                let mut i = i;
                while self.blocks[i].is_empty() {
                    i += 1;
                }
                i
            }
            Err(i) => i - 1,
        }
    }

    pub fn elem_nodes(&self, elem: ElemId) -> &[NodeId] {
        let b = self.block_of(elem);
        let block = &self.blocks[b];
        block.elem_nodes(elem.index() - block.first_elem.index())
    }

    pub fn topology(&self, elem: ElemId) -> Topology {
        self.blocks[self.block_of(elem)].topology
    }

    /// The nodes of a side, in the orientation of the Exodus side table.
    pub fn side_nodes(&self, side: Side) -> impl Iterator<Item = NodeId> + '_ {
        let b = self.block_of(side.elem);
        let block = &self.blocks[b];
        let nodes = block.elem_nodes(side.elem.index() - block.first_elem.index());
        block.topology.sides()[side.side as usize - 1]
            .iter()
            .map(move |&l| nodes[l as usize])
    }

    pub fn node_number(&self, n: NodeId) -> i64 {
        self.node_numbers[n.index()]
    }

    pub fn elem_number(&self, e: ElemId) -> i64 {
        self.elem_numbers[e.index()]
    }

    pub fn find_block(&self, sierra_name: &str) -> Option<usize> {
        let want = sierra_name.to_ascii_lowercase();
        self.blocks
            .iter()
            .position(|b| b.sierra_name() == want || format!("block_{}", b.id) == want)
    }

    pub fn find_side_set(&self, sierra_name: &str) -> Option<usize> {
        let want = sierra_name.to_ascii_lowercase();
        self.side_sets
            .iter()
            .position(|s| s.sierra_name() == want || format!("surface_{}", s.id) == want)
    }

    pub fn find_node_set(&self, sierra_name: &str) -> Option<usize> {
        let want = sierra_name.to_ascii_lowercase();
        self.node_sets
            .iter()
            .position(|s| s.sierra_name() == want || format!("nodelist_{}", s.id) == want)
    }

    pub fn find_assembly(&self, name: &str) -> Option<usize> {
        let want = name.to_ascii_lowercase();
        self.assemblies.iter().position(|a| {
            a.name.to_ascii_lowercase() == want || format!("assembly_{}", a.id) == want
        })
    }

    /// Append a block, numbering its elements after the existing ones. `numbers` are the
    /// user-visible element numbers; `None` continues from the largest so far.
    pub fn push_block(
        &mut self,
        id: i64,
        name: impl Into<String>,
        topology: Topology,
        connectivity: Vec<NodeId>,
        numbers: Option<Vec<i64>>,
    ) {
        let count = connectivity.len() / topology.node_count();
        let first_elem = ElemId(self.elem_numbers.len() as u32);
        match numbers {
            Some(n) => self.elem_numbers.extend(n),
            None => {
                let start = self.elem_numbers.iter().copied().max().unwrap_or(0) + 1;
                self.elem_numbers.extend(start..start + count as i64);
            }
        }
        self.blocks.push(Block {
            id,
            name: name.into(),
            topology,
            connectivity,
            first_elem,
            thickness: None,
        });
    }

    /// Bounding-box diagonal: the model size used to scale geometric tolerances.
    pub fn model_size(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.coords {
            for d in 0..3 {
                lo[d] = lo[d].min(p[d]);
                hi[d] = hi[d].max(p[d]);
            }
        }
        if self.coords.is_empty() {
            return 0.0;
        }
        ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
    }
}
