use super::{EmbedError, Embedding, Integration, Topology, mesh_error};
use std::collections::{HashMap, HashSet};

use crate::assembly::{DofMap, FieldId};
use crate::mesh::{ElemId, Mesh, NodeId, Side, SideSet};

/// Faces of a surface as the host gave them.
#[derive(Clone, Debug)]
enum Faces {
    Sides(Vec<(usize, u8)>),
    Nodes(Vec<Vec<usize>>),
}

#[derive(Clone, Debug)]
struct BlockInput {
    name: String,
    topology: Topology,
    connectivity: Vec<usize>,
    conductivity: f64,
}

/// The host's mesh and numbering, checked by [`EmbeddingBuilder::build`].
#[derive(Clone, Debug)]
pub struct EmbeddingBuilder {
    pub(super) coords: Vec<[f64; 3]>,
    blocks: Vec<BlockInput>,
    surfaces: Vec<(String, Faces)>,
    pub(super) dofs: Option<Vec<Option<usize>>>,
    pub(super) fixed: Vec<usize>,
    pub(super) integration: Integration,
    pub(super) axisymmetric: bool,
}

impl EmbeddingBuilder {
    /// An element block: `connectivity` holds `topology.node_count()` node indices per
    /// element; `conductivity` (W/m/K) weighs the Nitsche forms.
    pub fn block(
        mut self,
        name: &str,
        topology: Topology,
        connectivity: &[usize],
        conductivity: f64,
    ) -> Self {
        self.blocks.push(BlockInput {
            name: name.to_string(),
            topology,
            connectivity: connectivity.to_vec(),
            conductivity,
        });
        self
    }

    /// A surface of (element, 1-based local side) pairs.
    pub fn side_set(mut self, name: &str, sides: &[(usize, u8)]) -> Self {
        self.surfaces
            .push((name.to_string(), Faces::Sides(sides.to_vec())));
        self
    }

    /// A surface of faces given by their nodes (any order, any rotation): each must be a
    /// side of exactly one element. Its orientation is taken from that element.
    pub fn face_set<F: AsRef<[usize]>>(mut self, name: &str, faces: &[F]) -> Self {
        let faces = faces.iter().map(|f| f.as_ref().to_vec()).collect();
        self.surfaces.push((name.to_string(), Faces::Nodes(faces)));
        self
    }

    /// The host's dof number of every node (`dofs[node]`).
    pub fn dofs(mut self, dofs: &[usize]) -> Self {
        self.dofs = Some(dofs.iter().map(|&d| Some(d)).collect());
        self
    }

    /// As [`Self::dofs`], `None` for nodes without a temperature dof (they must not
    /// belong to any block).
    pub fn partial_dofs(mut self, dofs: &[Option<usize>]) -> Self {
        self.dofs = Some(dofs.to_vec());
        self
    }

    /// Nodes whose value the host prescribes (Dirichlet): mortar ties give them no
    /// multiplier (they would constrain them twice).
    pub fn fixed_nodes(mut self, nodes: &[usize]) -> Self {
        self.fixed = nodes.to_vec();
        self
    }

    /// How side-A points are placed (default: mortar segments, order 5, as `seam run`).
    pub fn integration(mut self, integration: Integration) -> Self {
        self.integration = integration;
        self
    }

    /// A 2-D mesh (Quad4, Tri3 blocks) read as axisymmetric: x the radius r ≥ 0, y the
    /// axis; every weight, heat and Jacobian entry is then per full revolution (× 2πr),
    /// as the host's own axisymmetric kernels must be.
    pub fn axisymmetric(mut self, on: bool) -> Self {
        self.axisymmetric = on;
        self
    }

    /// Check everything and make the embedding.
    pub fn build(self) -> Result<Embedding, EmbedError> {
        let n = self.coords.len();
        if n == 0 {
            return Err(mesh_error(
                "no nodes".into(),
                "pass the node coordinates to Embedding::builder",
            ));
        }
        if self.blocks.is_empty() {
            return Err(mesh_error(
                "no element blocks".into(),
                "add the blocks whose faces make the interfaces with .block(…)",
            ));
        }
        // 3-D solids, or 2-D ones (Quad4, Tri3) in the xy plane: the first block decides.
        let dim = if self.blocks[0].topology.parametric_dim() == 3 {
            3
        } else {
            2
        };
        let mut mesh = Mesh {
            dim,
            coords: self.coords.clone(),
            node_numbers: (0..n as i64).collect(),
            ..Mesh::default()
        };
        let mut conductivity = Vec::with_capacity(self.blocks.len());
        for (b, block) in self.blocks.iter().enumerate() {
            let nn = block.topology.node_count();
            let (kind, help) = match dim {
                3 => ("3-D solids", "give Hex8, Tet4, Wedge6 or Pyramid5 blocks"),
                _ => (
                    "2-D solids, as the first block is",
                    "give Quad4 or Tri3 blocks in a 2-D mesh (Hex8, Tet4, Wedge6 or Pyramid5 in a 3-D one), not both",
                ),
            };
            if block.topology.parametric_dim() != dim || !block.topology.is_solid() {
                return Err(mesh_error(
                    format!(
                        "block `{}` has topology {:?}; interfaces are searched between {kind}",
                        block.name, block.topology
                    ),
                    help,
                ));
            }
            if block.connectivity.len() % nn != 0 {
                return Err(mesh_error(
                    format!(
                        "block `{}`: {} connectivity entries is not a multiple of {nn} ({:?})",
                        block.name,
                        block.connectivity.len(),
                        block.topology
                    ),
                    "give topology.node_count() node indices per element",
                ));
            }
            if let Some((k, &node)) = block
                .connectivity
                .iter()
                .enumerate()
                .find(|(_, node)| **node >= n)
            {
                return Err(mesh_error(
                    format!(
                        "block `{}`, element {} (local node {}): node {node} does not exist, there are {n} nodes",
                        block.name,
                        k / nn,
                        k % nn + 1
                    ),
                    "node indices are 0-based positions in the coordinate array",
                ));
            }
            if !(block.conductivity.is_finite() && block.conductivity > 0.0) {
                return Err(mesh_error(
                    format!(
                        "block `{}`: conductivity {} is not a positive number",
                        block.name, block.conductivity
                    ),
                    "give k > 0 in W/m/K",
                ));
            }
            let first = mesh.elem_numbers.len() as i64;
            let count = (block.connectivity.len() / nn) as i64;
            mesh.push_block(
                b as i64 + 1,
                block.name.clone(),
                block.topology,
                block
                    .connectivity
                    .iter()
                    .map(|&i| NodeId(i as u32))
                    .collect(),
                Some((first..first + count).collect()),
            );
            conductivity.push(block.conductivity);
        }
        if n > u32::MAX as usize || mesh.num_elems() > u32::MAX as usize {
            return Err(mesh_error(
                format!("{n} nodes, {} elements", mesh.num_elems()),
                "seam numbers nodes and elements with 32-bit indices",
            ));
        }
        if dim == 2
            && let Some((k, x)) = mesh.coords.iter().enumerate().find(|(_, x)| x[2] != 0.0)
        {
            return Err(mesh_error(
                format!("node {k} of a 2-D mesh lies at z = {}", x[2]),
                "a 2-D mesh lies in the xy plane: give every node z = 0",
            ));
        }
        if self.axisymmetric
            && let Err(e) = mesh.set_axisymmetric()
        {
            return Err(mesh_error(format!("axisymmetric: {e}"), e.help()));
        }
        // The elements first: a host whose node order differs from seam's gets
        // inverted or tangled elements, and that — not the faces it then fails to find —
        // is what it must be told.
        mesh.validate()?;
        let mut by_nodes: Option<HashMap<[u32; 4], Vec<Side>>> = None;
        let mut names = HashSet::new();
        for (s, (name, faces)) in self.surfaces.iter().enumerate() {
            if !names.insert(name.to_ascii_lowercase()) {
                return Err(mesh_error(
                    format!("surface `{name}` is given twice"),
                    "give every surface its own name (names are case-insensitive)",
                ));
            }
            let sides = match faces {
                Faces::Sides(list) => sides_by_number(&mesh, name, list)?,
                Faces::Nodes(list) => {
                    let table = by_nodes.get_or_insert_with(|| face_table(&mesh));
                    sides_by_nodes(table, name, list)?
                }
            };
            mesh.side_sets.push(SideSet {
                id: s as i64 + 1,
                name: name.clone(),
                sides,
            });
        }
        // Seam's own numbering of the temperature dofs, mapped to the host's.
        let solid: Vec<usize> = (0..mesh.blocks.len()).collect();
        let dofs = DofMap::new(&mesh, &[("temperature", &solid)])
            .map_err(|e| mesh_error(e.to_string(), "check the blocks"))?;
        let field = FieldId(0);
        let host = self.dofs.ok_or_else(|| {
            mesh_error(
                "no dof numbers".into(),
                "pass the host's dof number of every node with .dofs(…)",
            )
        })?;
        if host.len() != n {
            return Err(mesh_error(
                format!("{} dof numbers for {n} nodes", host.len()),
                "pass one dof number per node, in node order",
            ));
        }
        let mut host_dof = vec![0usize; dofs.len()];
        for (node, number) in host.iter().enumerate() {
            if let Some(d) = dofs.dof(field, NodeId(node as u32)) {
                host_dof[d.index()] = number.ok_or_else(|| {
                    mesh_error(
                        format!("node {node} belongs to an element block but has no dof number"),
                        "every node of a block needs the host's dof number",
                    )
                })?;
            }
        }
        if let Some(&bad) = self.fixed.iter().find(|&&f| f >= n) {
            return Err(mesh_error(
                format!("fixed node {bad} does not exist, there are {n} nodes"),
                "node indices are 0-based positions in the coordinate array",
            ));
        }
        Ok(Embedding {
            mesh,
            dofs,
            field,
            host_dof,
            conductivity,
            fixed: self.fixed.iter().map(|&f| NodeId(f as u32)).collect(),
            fixed_of: Vec::new(),
            integration: self.integration,
            pairs: Vec::new(),
            time: 0.0,
            evaluation: None,
            conductivity_law: None,
        })
    }
}

fn sides_by_number(mesh: &Mesh, name: &str, list: &[(usize, u8)]) -> Result<Vec<Side>, EmbedError> {
    let elems = mesh.num_elems();
    list.iter()
        .enumerate()
        .map(|(k, &(elem, side))| {
            if elem >= elems {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: element {elem} does not exist, there are {elems}"),
                    "element indices are 0-based, numbered block after block",
                ));
            }
            let topology = mesh.topology(ElemId(elem as u32));
            let count = topology.face_side_count();
            if side == 0 {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: element {elem} has no side 0: local sides are 1-based"),
                    &format!("add 1 to 0-based side numbers: sides of a {topology:?} run 1 to {count}, Exodus order (docs/embedding.md, \"Element node order and sides\")"),
                ));
            }
            if usize::from(side) > count {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: element {elem} ({topology:?}) has no side {side}"),
                    &format!("local sides are 1-based, Exodus order: 1 to {count}"),
                ));
            }
            Ok(Side {
                elem: ElemId(elem as u32),
                side,
            })
        })
        .collect()
}

/// Sorted node indices of a face, padded with `u32::MAX`.
fn face_key(nodes: impl Iterator<Item = u32>) -> [u32; 4] {
    let mut key = [u32::MAX; 4];
    for (k, n) in nodes.take(4).enumerate() {
        key[k] = n;
    }
    key.sort_unstable();
    key
}

/// Every element side, by its sorted nodes.
fn face_table(mesh: &Mesh) -> HashMap<[u32; 4], Vec<Side>> {
    let mut table: HashMap<[u32; 4], Vec<Side>> = HashMap::new();
    for block in &mesh.blocks {
        for elem in block.elems() {
            for s in 1..=block.topology.face_side_count() as u8 {
                let side = Side { elem, side: s };
                table
                    .entry(face_key(mesh.side_nodes(side).map(|n| n.0)))
                    .or_default()
                    .push(side);
            }
        }
    }
    table
}

fn sides_by_nodes(
    table: &HashMap<[u32; 4], Vec<Side>>,
    name: &str,
    list: &[Vec<usize>],
) -> Result<Vec<Side>, EmbedError> {
    list.iter()
        .enumerate()
        .map(|(k, nodes)| {
            if !matches!(nodes.len(), 2..=4) || nodes.iter().any(|&n| n >= u32::MAX as usize) {
                return Err(mesh_error(
                    format!("surface `{name}`, face {k}: nodes {nodes:?} are no edge, triangle or quadrilateral"),
                    "give the 3 or 4 corner nodes of each face (the 2 end nodes of each edge of a 2-D mesh)",
                ));
            }
            let key = face_key(nodes.iter().map(|&n| n as u32));
            match table.get(&key).map(Vec::as_slice) {
                Some([side]) => Ok(*side),
                Some([a, b, ..]) => Err(mesh_error(
                    format!(
                        "surface `{name}`, face {k} (nodes {nodes:?}) lies between elements {} and {}",
                        a.elem.0, b.elem.0
                    ),
                    "an interface face must be on the boundary of its block; give it as (element, side) to choose one",
                )),
                _ => Err(mesh_error(
                    format!("surface `{name}`, face {k}: nodes {nodes:?} are no side of any element"),
                    "give the corner nodes of one element face (0-based node indices)",
                )),
            }
        })
        .collect()
}

impl Embedding {
    /// Start from the host's node coordinates (xyz; a 2-D mesh has z = 0).
    pub fn builder(coords: &[[f64; 3]]) -> EmbeddingBuilder {
        EmbeddingBuilder {
            coords: coords.to_vec(),
            blocks: Vec::new(),
            surfaces: Vec::new(),
            dofs: None,
            fixed: Vec::new(),
            integration: Integration::Segments { order: 5 },
            axisymmetric: false,
        }
    }
}
