//! Which part of the mesh each rank holds, and how its local numbers map to the whole
//! mesh's.
//!
//! A run the distributed steady solve takes has its mesh read by rank 0 alone
//! ([`distribute`]), partitioned by METIS, and every other rank sent only its **local
//! mesh** ([`receive`]): the elements it owns, one layer of ghost elements (every element
//! sharing a node with one it owns), their nodes, and the side sets and node sets
//! restricted to them. Local numbers follow the whole mesh's order (blocks in order, each
//! block's elements and every node list ascending by global index), so faces and nodes
//! keep their relative order and "lowest id first" means the same on every rank. Rank 0
//! keeps the whole mesh, which it writes the outputs on. Every rank keeps a [`Part`]: per
//! local element and node its global index and owner, per node the PETSc index of its
//! temperature dof, the PETSc rows of every rank.
//!
//! The contact search adds **contact partners** ([`add_remote`]): the side-B elements,
//! held by no other rule, whose faces a rank's own side-A points paired with. They are
//! appended after the local mesh's elements and nodes, in extra blocks (one per run of
//! elements of one block), so that every local number made before stays; the steady solve
//! and the interface terms run on [`extended_mesh`].
//!
//! A run that does not distribute its mesh (the general solver, `seam search`) has a part
//! too, over the whole mesh on every rank ([`ensure`] makes it: the partition is then
//! computed on rank 0 and broadcast).
//!
//! Ownership, as in the rest of `parallel`: an element belongs to its METIS part, a node
//! to the lowest rank among its elements', a dof to its node's owner; PETSc numbers the
//! dofs rank after rank, the serial order inside, so that each rank's rows are one
//! contiguous range.

use std::cell::RefCell;
use std::collections::HashMap;

use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, Root};

use crate::mesh::{Block, ElemId, Mesh, NodeId, NodeSet, Side, SideSet};

use super::layout::{NO_PART, element_parts, node_owners, partition};
use super::petsc::PetscInt;
use super::{session, wire};

/// This rank's part of the mesh.
pub(crate) struct Part {
    pub rank: usize,
    pub size: usize,
    /// Ranks other than 0 hold their local mesh only (rank 0 the whole one); false when
    /// every rank holds the whole mesh.
    pub distributed: bool,
    pub global_elems: usize,
    pub global_nodes: usize,
    /// Elements and nodes of the local mesh; contact partners are numbered after them.
    pub mesh_elems: usize,
    pub mesh_nodes: usize,
    /// Per local element (then contact partner), its global index.
    pub elem_global: Vec<u32>,
    /// Per local element, its rank ([`NO_PART`] outside the partitioned blocks).
    pub elem_owner: Vec<u32>,
    /// Per local node (then contact partners' nodes), its global index.
    pub node_global: Vec<u32>,
    /// Per local node, its rank (the lowest among its elements'; 0 for a node on none).
    pub node_owner: Vec<u32>,
    /// Per local node, the PETSc index of its temperature dof (−1: none).
    pub node_petsc: Vec<PetscInt>,
    /// Rank `r`'s PETSc rows are `starts[r]..starts[r + 1]`.
    pub starts: Vec<usize>,
    /// The whole mesh's bounding-box diagonal.
    pub model_size: f64,
    /// The contact partners appended.
    remote: Remote,
    /// The blocks partitioned, and the mesh's element and node counts (a replicated
    /// part is made again for another mesh).
    key: (usize, usize, Vec<usize>),
}

/// Side-B elements of other ranks a rank's points paired with.
#[derive(Default)]
struct Remote {
    elems: HashMap<u32, u32>,
    nodes: HashMap<u32, u32>,
    /// Per element: its block in the whole mesh, its user number and its local nodes.
    block: Vec<u32>,
    number: Vec<i64>,
    connectivity: Vec<Vec<NodeId>>,
    /// Per node appended: coordinates and user number.
    coords: Vec<[f64; 3]>,
    node_numbers: Vec<i64>,
}

/// A side-B element as its owner sends it.
pub(crate) struct RemoteElem {
    pub global: u32,
    /// The rank owning it (which sent it).
    pub owner: u32,
    pub block: u32,
    pub number: i64,
    /// Per node: global index, coordinates, user number, PETSc index of its dof.
    pub nodes: Vec<(u32, [f64; 3], i64, PetscInt)>,
}

thread_local! {
    static PART: RefCell<Option<Part>> = const { RefCell::new(None) };
}

/// `f` of this process's part (made by [`ensure`], [`distribute`] or [`receive`]).
pub(crate) fn with<R>(f: impl FnOnce(&Part) -> R) -> Option<R> {
    PART.with(|p| p.borrow().as_ref().map(f))
}

fn with_mut<R>(f: impl FnOnce(&mut Part) -> R) -> Option<R> {
    PART.with(|p| p.borrow_mut().as_mut().map(f))
}

/// Whether ranks other than 0 hold only their part of the mesh in this run.
pub(crate) fn distributed() -> bool {
    with(|p| p.distributed).unwrap_or(false)
}

/// Forget the part (a new run starts).
pub(crate) fn clear() {
    PART.with(|p| *p.borrow_mut() = None);
}

/// The solid blocks of `mesh`: those partitioned.
pub(crate) fn solid_blocks(mesh: &Mesh) -> Vec<usize> {
    (0..mesh.blocks.len())
        .filter(|&b| mesh.blocks[b].topology.is_solid())
        .collect()
}

/// Make sure a part over `mesh` exists: a distributed run's (made when the mesh was
/// shared), else the whole mesh on every rank, partitioned on rank 0 (collective then).
pub(crate) fn ensure(mesh: &Mesh) -> Result<(), String> {
    let blocks = solid_blocks(mesh);
    let key = (mesh.num_elems(), mesh.num_nodes(), blocks.clone());
    let fits = with(|p| p.distributed || p.key == key).unwrap_or(false);
    if fits {
        return Ok(());
    }
    let part = element_parts(mesh, &blocks)?;
    let world = session::comm();
    let made = Part::whole(mesh, &blocks, part, &world, false);
    PART.with(|p| *p.borrow_mut() = Some(made));
    Ok(())
}

impl Part {
    /// The whole mesh as one rank's part: local numbers are global ones.
    fn whole(
        mesh: &Mesh,
        blocks: &[usize],
        part: Vec<u32>,
        world: &SimpleCommunicator,
        distributed: bool,
    ) -> Part {
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        let node_owner: Vec<u32> = node_owners(mesh, blocks, &part)
            .into_iter()
            .map(|o| if o == NO_PART { 0 } else { o })
            .collect();
        let (node_petsc, starts) = petsc_numbering(mesh, blocks, &node_owner, size);
        Part {
            rank,
            size,
            distributed,
            global_elems: mesh.num_elems(),
            global_nodes: mesh.num_nodes(),
            mesh_elems: mesh.num_elems(),
            mesh_nodes: mesh.num_nodes(),
            elem_global: (0..mesh.num_elems() as u32).collect(),
            elem_owner: part,
            node_global: (0..mesh.num_nodes() as u32).collect(),
            node_owner,
            node_petsc,
            starts,
            model_size: mesh.model_size(),
            remote: Remote::default(),
            key: (mesh.num_elems(), mesh.num_nodes(), blocks.to_vec()),
        }
    }

    /// This rank's PETSc rows.
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.starts[self.rank]..self.starts[self.rank + 1]
    }

    /// The rank owning PETSc row `i`.
    pub fn row_owner(&self, i: usize) -> usize {
        self.starts.partition_point(|&s| s <= i) - 1
    }

    /// The rank owning local element `e` (0 outside the partitioned blocks).
    pub fn elem_rank(&self, e: ElemId) -> usize {
        match self.elem_owner.get(e.index()) {
            Some(&o) if o != NO_PART => o as usize,
            _ => 0,
        }
    }

    /// The rank owning local node `n`.
    pub fn node_rank(&self, n: NodeId) -> usize {
        self.node_owner.get(n.index()).map_or(0, |&o| o as usize)
    }

    /// The local element of global element `g`, if this rank holds it.
    pub fn local_elem(&self, g: u32) -> Option<ElemId> {
        match self.elem_global[..self.mesh_elems].binary_search(&g) {
            Ok(k) => Some(ElemId(k as u32)),
            Err(_) => self.remote.elems.get(&g).map(|&e| ElemId(e)),
        }
    }

    /// The local node of global node `g`, if this rank holds it.
    pub fn local_node(&self, g: u32) -> Option<NodeId> {
        match self.node_global[..self.mesh_nodes].binary_search(&g) {
            Ok(k) => Some(NodeId(k as u32)),
            Err(_) => self.remote.nodes.get(&g).map(|&n| NodeId(n)),
        }
    }

    /// Elements held by the local mesh: owned, then ghosts.
    pub fn counts(&self) -> Holdings {
        let owned = (0..self.mesh_elems)
            .filter(|&e| self.elem_owner[e] as usize == self.rank)
            .count();
        Holdings {
            owned,
            ghost: self.mesh_elems - owned,
            partners: self.remote.block.len(),
            nodes: self.mesh_nodes,
            partner_nodes: self.remote.coords.len(),
            rows: self.rows().len(),
        }
    }
}

/// What a rank holds, counted.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Holdings {
    pub owned: usize,
    pub ghost: usize,
    /// Contact partners (side-B elements of other ranks).
    pub partners: usize,
    pub nodes: usize,
    pub partner_nodes: usize,
    pub rows: usize,
}

/// Per node its PETSc index (−1 for a node on no block of `blocks`) and every rank's
/// first row: the serial dofs (nodes of `blocks`, in node order) rank after rank.
fn petsc_numbering(
    mesh: &Mesh,
    blocks: &[usize],
    node_owner: &[u32],
    size: usize,
) -> (Vec<PetscInt>, Vec<usize>) {
    let mut on = vec![false; mesh.num_nodes()];
    for &b in blocks {
        for n in &mesh.blocks[b].connectivity {
            on[n.index()] = true;
        }
    }
    let mut count = vec![0usize; size];
    for (n, &o) in node_owner.iter().enumerate() {
        if on[n] {
            count[o as usize] += 1;
        }
    }
    let mut starts = vec![0usize; size + 1];
    for r in 0..size {
        starts[r + 1] = starts[r] + count[r];
    }
    let mut next = starts[..size].to_vec();
    let petsc = node_owner
        .iter()
        .enumerate()
        .map(|(n, &o)| {
            if on[n] {
                next[o as usize] += 1;
                (next[o as usize] - 1) as PetscInt
            } else {
                -1
            }
        })
        .collect();
    (petsc, starts)
}

/// Per node, the ranks of its elements of `blocks`, ascending (offsets, ranks).
fn node_ranks(mesh: &Mesh, blocks: &[usize], part: &[u32]) -> (Vec<usize>, Vec<u32>) {
    let mut count = vec![0usize; mesh.num_nodes() + 1];
    for &b in blocks {
        for n in &mesh.blocks[b].connectivity {
            count[n.index() + 1] += 1;
        }
    }
    for k in 0..mesh.num_nodes() {
        count[k + 1] += count[k];
    }
    let mut ranks = vec![0u32; count[mesh.num_nodes()]];
    let mut next = count.clone();
    for &b in blocks {
        let block = &mesh.blocks[b];
        for (k, e) in block.elems().enumerate() {
            for n in block.elem_nodes(k) {
                ranks[next[n.index()]] = part[e.index()];
                next[n.index()] += 1;
            }
        }
    }
    // Each node's list sorted and its repeats dropped, in place.
    let mut offsets = vec![0usize; mesh.num_nodes() + 1];
    let mut write = 0;
    for n in 0..mesh.num_nodes() {
        let list = &mut ranks[count[n]..count[n + 1]];
        list.sort_unstable();
        let mut last = None;
        for k in count[n]..count[n + 1] {
            let r = ranks[k];
            if last != Some(r) {
                ranks[write] = r;
                write += 1;
                last = Some(r);
            }
        }
        offsets[n + 1] = write;
    }
    ranks.truncate(write);
    (offsets, ranks)
}

/// Whether rank 0 can partition `mesh` and send each rank its local mesh: every block
/// solid (shells, bars and their lofted faces are left to the whole-mesh path), some
/// element, and element and node counts a `u32` holds.
pub(crate) fn can_distribute(mesh: &Mesh) -> Result<(), String> {
    if let Some(b) = mesh.blocks.iter().find(|b| !b.topology.is_solid()) {
        return Err(format!(
            "block {} is made of {:?} elements",
            b.sierra_name(),
            b.topology
        ));
    }
    if mesh.num_elems() == 0 {
        return Err("the mesh has no element".into());
    }
    if mesh.num_elems() >= u32::MAX as usize || mesh.num_nodes() >= u32::MAX as usize {
        return Err("the mesh has more than 2³² − 2 elements or nodes".into());
    }
    Ok(())
}

/// On rank 0: partition `mesh` (METIS, its solid blocks), send every other rank its local
/// mesh and part ([`receive`] takes them), and keep the whole mesh as rank 0's part. The
/// partition is made before anything is sent, so that its failure stops rank 0 before
/// the others wait for a mesh (the caller tells them). `costs`: per block, the work of
/// assembling one of its elements ([`super::layout::partition`]).
pub(crate) fn partition_for_ranks(mesh: &Mesh, costs: Option<&[u32]>) -> Result<Vec<u32>, String> {
    let world = session::comm();
    let blocks = solid_blocks(mesh);
    partition(mesh, &blocks, world.size() as usize, costs)
}

/// On rank 0, after [`partition_for_ranks`]: send every other rank its local mesh and
/// part, and keep the whole mesh as rank 0's part. Returns each rank's holdings as sent.
pub(crate) fn distribute(mesh: &Mesh, part: Vec<u32>) -> Vec<Holdings> {
    let world = session::comm();
    let size = world.size() as usize;
    let blocks = solid_blocks(mesh);
    let own = Part::whole(mesh, &blocks, part, &world, true);
    let (offsets, ranks) = node_ranks(mesh, &blocks, &own.elem_owner);
    let mut sent = vec![own.counts(); size];
    let mut to_local_node = vec![u32::MAX; mesh.num_nodes()];
    let mut to_local_elem = vec![u32::MAX; mesh.num_elems()];
    for (r, holdings) in sent.iter_mut().enumerate().skip(1) {
        let held =
            |n: NodeId| ranks[offsets[n.index()]..offsets[n.index() + 1]].contains(&(r as u32));
        let (local, arrays) =
            local_mesh(mesh, &own, &held, (&mut to_local_node, &mut to_local_elem));
        let owned = arrays
            .elem_owner
            .iter()
            .filter(|&&o| o as usize == r)
            .count();
        *holdings = Holdings {
            owned,
            ghost: local.num_elems() - owned,
            partners: 0,
            nodes: local.num_nodes(),
            partner_nodes: 0,
            rows: own.starts[r + 1] - own.starts[r],
        };
        let mut w = wire::Writer::default();
        wire::encode_mesh(&local, &mut w);
        encode_arrays(&arrays, &own, &mut w);
        drop(local);
        wire::send_bytes(&world, r, &w.0);
    }
    PART.with(|p| *p.borrow_mut() = Some(own));
    sent
}

/// The local mesh of one rank (its elements: those with a node `held`) and its arrays.
fn local_mesh(
    mesh: &Mesh,
    whole: &Part,
    held: &dyn Fn(NodeId) -> bool,
    (to_node, to_elem): (&mut [u32], &mut [u32]),
) -> (Mesh, LocalArrays) {
    // The local nodes, ascending.
    let mut keep_node = vec![false; mesh.num_nodes()];
    let mut elems: Vec<ElemId> = Vec::new();
    for block in &mesh.blocks {
        for (k, e) in block.elems().enumerate() {
            let nodes = block.elem_nodes(k);
            if nodes.iter().any(|&n| held(n)) {
                elems.push(e);
                nodes.iter().for_each(|n| keep_node[n.index()] = true);
            }
        }
    }
    let nodes: Vec<u32> = (0..mesh.num_nodes() as u32)
        .filter(|&n| keep_node[n as usize])
        .collect();
    drop(keep_node);
    for (k, &n) in nodes.iter().enumerate() {
        to_node[n as usize] = k as u32;
    }
    for (k, e) in elems.iter().enumerate() {
        to_elem[e.index()] = k as u32;
    }
    let mut blocks = Vec::with_capacity(mesh.blocks.len());
    let mut next = 0u32;
    for block in &mesh.blocks {
        let first_elem = ElemId(next);
        let mut connectivity = Vec::new();
        for (k, e) in block.elems().enumerate() {
            if to_elem[e.index()] != u32::MAX {
                connectivity.extend(
                    block
                        .elem_nodes(k)
                        .iter()
                        .map(|n| NodeId(to_node[n.index()])),
                );
                next += 1;
            }
        }
        blocks.push(Block {
            id: block.id,
            name: block.name.clone(),
            topology: block.topology,
            connectivity,
            first_elem,
            thickness: block.thickness,
        });
    }
    let side_sets = mesh
        .side_sets
        .iter()
        .map(|s| SideSet {
            id: s.id,
            name: s.name.clone(),
            sides: s
                .sides
                .iter()
                .filter(|x| to_elem[x.elem.index()] != u32::MAX)
                .map(|x| Side {
                    elem: ElemId(to_elem[x.elem.index()]),
                    side: x.side,
                })
                .collect(),
        })
        .collect();
    let node_sets = mesh
        .node_sets
        .iter()
        .map(|s| NodeSet {
            id: s.id,
            name: s.name.clone(),
            nodes: s
                .nodes
                .iter()
                .filter(|n| to_node[n.index()] != u32::MAX)
                .map(|n| NodeId(to_node[n.index()]))
                .collect(),
        })
        .collect();
    let local = Mesh {
        dim: mesh.dim,
        coords: nodes.iter().map(|&n| mesh.coords[n as usize]).collect(),
        node_numbers: nodes
            .iter()
            .map(|&n| mesh.node_numbers[n as usize])
            .collect(),
        elem_numbers: elems.iter().map(|e| mesh.elem_numbers[e.index()]).collect(),
        blocks,
        side_sets,
        node_sets,
        assemblies: mesh.assemblies.clone(),
        source: mesh.source.clone(),
        axisymmetric: mesh.axisymmetric,
    };
    let arrays = LocalArrays {
        elem_global: elems.iter().map(|e| e.0).collect(),
        elem_owner: elems.iter().map(|e| whole.elem_owner[e.index()]).collect(),
        node_owner: nodes
            .iter()
            .map(|&n| whole.node_owner[n as usize])
            .collect(),
        node_petsc: nodes
            .iter()
            .map(|&n| whole.node_petsc[n as usize])
            .collect(),
        node_global: nodes,
    };
    // The maps back to unused, for the next rank.
    for &n in &arrays.node_global {
        to_node[n as usize] = u32::MAX;
    }
    for &e in &arrays.elem_global {
        to_elem[e as usize] = u32::MAX;
    }
    (local, arrays)
}

/// A local mesh's per-element and per-node arrays.
struct LocalArrays {
    elem_global: Vec<u32>,
    elem_owner: Vec<u32>,
    node_global: Vec<u32>,
    node_owner: Vec<u32>,
    node_petsc: Vec<PetscInt>,
}

/// On a rank other than 0: the local mesh rank 0 sends ([`distribute`]), its part kept.
pub(crate) fn receive() -> Result<Mesh, String> {
    let world = session::comm();
    let bytes = wire::receive_bytes(&world);
    let mut r = wire::Reader { b: &bytes, at: 0 };
    let mesh = wire::decode_mesh(&mut r)?;
    let elem_global = r.u32s()?;
    let elem_owner = r.u32s()?;
    let node_global = r.u32s()?;
    let node_owner = r.u32s()?;
    let node_petsc = r.i32s()?;
    let starts: Vec<usize> = r.u64s()?.into_iter().map(|s| s as usize).collect();
    let global_elems = r.u64()? as usize;
    let global_nodes = r.u64()? as usize;
    let model_size = r.f64()?;
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    if elem_global.len() != mesh.num_elems()
        || elem_owner.len() != mesh.num_elems()
        || node_global.len() != mesh.num_nodes()
        || node_owner.len() != mesh.num_nodes()
        || node_petsc.len() != mesh.num_nodes()
        || starts.len() != size + 1
    {
        return Err("the local mesh received does not match its part".into());
    }
    let key = (mesh.num_elems(), mesh.num_nodes(), solid_blocks(&mesh));
    let part = Part {
        rank,
        size,
        distributed: true,
        global_elems,
        global_nodes,
        mesh_elems: mesh.num_elems(),
        mesh_nodes: mesh.num_nodes(),
        elem_global,
        elem_owner,
        node_global,
        node_owner,
        node_petsc,
        starts,
        model_size,
        remote: Remote::default(),
        key,
    };
    PART.with(|p| *p.borrow_mut() = Some(part));
    Ok(mesh)
}

/// Append contact partners `elems` (each once; those already held are skipped) and
/// return the local element of each, in order.
pub(crate) fn add_remote(elems: &[RemoteElem]) -> Vec<ElemId> {
    with_mut(|p| {
        elems
            .iter()
            .map(|e| {
                if let Some(local) = p.local_elem(e.global) {
                    return local;
                }
                let mut connectivity = Vec::with_capacity(e.nodes.len());
                for &(g, x, number, petsc) in &e.nodes {
                    let n = match p.local_node(g) {
                        Some(n) => n,
                        None => {
                            let n = NodeId(p.node_global.len() as u32);
                            p.node_global.push(g);
                            p.node_owner.push(p.row_owner(petsc.max(0) as usize) as u32);
                            p.node_petsc.push(petsc);
                            p.remote.nodes.insert(g, n.0);
                            p.remote.coords.push(x);
                            p.remote.node_numbers.push(number);
                            n
                        }
                    };
                    connectivity.push(n);
                }
                let local = ElemId(p.elem_global.len() as u32);
                p.elem_global.push(e.global);
                p.elem_owner.push(e.owner);
                p.remote.elems.insert(e.global, local.0);
                p.remote.block.push(e.block);
                p.remote.number.push(e.number);
                p.remote.connectivity.push(connectivity);
                local
            })
            .collect()
    })
    .unwrap_or_default()
}

/// The element data of local elements `elems` (this rank's own), to send to a rank whose
/// points paired with their faces.
pub(crate) fn remote_elems(mesh: &Mesh, elems: &[ElemId]) -> Vec<RemoteElem> {
    with(|p| {
        elems
            .iter()
            .map(|&e| RemoteElem {
                global: p.elem_global[e.index()],
                owner: p.rank as u32,
                block: mesh.block_of(e) as u32,
                number: mesh.elem_number(e),
                nodes: mesh
                    .elem_nodes(e)
                    .iter()
                    .map(|&n| {
                        (
                            p.node_global[n.index()],
                            mesh.coords[n.index()],
                            mesh.node_number(n),
                            p.node_petsc[n.index()],
                        )
                    })
                    .collect(),
            })
            .collect()
    })
    .unwrap_or_default()
}

/// `mesh` (this rank's local mesh) with the contact partners appended, and per block of
/// it the block of `mesh` it copies; `None` when there are no partners (`mesh` is then
/// the one to use).
pub(crate) fn extended_mesh(mesh: &Mesh) -> Option<(Mesh, Vec<usize>)> {
    with(|p| {
        let r = &p.remote;
        if r.block.is_empty() || mesh.num_elems() != p.mesh_elems {
            return None;
        }
        let mut out = mesh.clone();
        out.coords.extend_from_slice(&r.coords);
        out.node_numbers.extend_from_slice(&r.node_numbers);
        let mut origin: Vec<usize> = (0..mesh.blocks.len()).collect();
        // One extra block per run of partners of one block, so that their numbers (given
        // as they came) stay.
        let mut k = 0;
        while k < r.block.len() {
            let b = r.block[k] as usize;
            let end = (k..r.block.len())
                .find(|&j| r.block[j] as usize != b)
                .unwrap_or(r.block.len());
            let template = &mesh.blocks[b.min(mesh.blocks.len() - 1)];
            let connectivity: Vec<NodeId> = r.connectivity[k..end].concat();
            out.push_block(
                template.id,
                template.name.clone(),
                template.topology,
                connectivity,
                Some(r.number[k..end].to_vec()),
            );
            if let Some(last) = out.blocks.last_mut() {
                last.thickness = template.thickness;
            }
            origin.push(b);
            k = end;
        }
        Some((out, origin))
    })
    .flatten()
}

/// Rank 0's `value` on every rank.
pub(crate) fn broadcast_u8(value: u8) -> u8 {
    let world = session::comm();
    let mut v = value;
    world.process_at_rank(0).broadcast_into(&mut v);
    v
}

/// Rank 0's nodal field over the whole mesh (`whole`: `None` where it has none, and on
/// the other ranks) at the nodes of this rank's local mesh, on a run whose mesh is
/// distributed: each rank asks rank 0 for the values at its nodes' global indices
/// (`MPI_Alltoallv`, 4 B a node, and 8 B a node back). `None` on every rank when rank 0
/// has none.
pub(crate) fn nodal_from_root(whole: Option<Vec<f64>>) -> Option<Vec<f64>> {
    if broadcast_u8(whole.is_some() as u8) == 0 {
        return None;
    }
    let world = session::comm();
    let root = world.rank() == 0;
    let mut asks = vec![Vec::new(); world.size() as usize];
    if !root {
        asks[0] = with(|p| p.node_global[..p.mesh_nodes].to_vec()).unwrap_or_default();
    }
    let asked = session::exchange(&world, &asks);
    let values: Vec<Vec<f64>> = match &whole {
        Some(w) => (asked.iter())
            .map(|nodes| nodes.iter().map(|&g| w[g as usize]).collect())
            .collect(),
        None => vec![Vec::new(); asked.len()],
    };
    let mut got = session::exchange(&world, &values);
    match root {
        true => whole,
        false => Some(std::mem::take(&mut got[0])),
    }
}

fn encode_arrays(a: &LocalArrays, whole: &Part, w: &mut wire::Writer) {
    w.u32s(&a.elem_global);
    w.u32s(&a.elem_owner);
    w.u32s(&a.node_global);
    w.u32s(&a.node_owner);
    w.i32s(&a.node_petsc);
    w.u64s(&whole.starts.iter().map(|&s| s as u64).collect::<Vec<_>>());
    w.u64(whole.global_elems as u64);
    w.u64(whole.global_nodes as u64);
    w.f64(whole.model_size);
}
