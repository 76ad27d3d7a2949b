//! Who owns what: the elements partitioned by METIS (on rank 0, broadcast, so every rank
//! holds the same partition), each node owned by the lowest rank among its elements'
//! parts, each dof by its node's owner, and the PETSc numbering — the serial dofs in
//! order, rank after rank, so that each rank's rows are one contiguous range.

use std::cell::RefCell;

use mpi::traits::{Communicator, Root};

use crate::assembly::{DofMap, FieldId};
use crate::mesh::{Block, ElemId, Mesh, NodeId};

use super::petsc::PetscInt;
use super::session;

/// Part of an element outside the partitioned blocks (no temperature).
pub(super) const NO_PART: u32 = u32::MAX;

/// The partition of one solve.
pub(super) struct Layout {
    pub rank: usize,
    /// Per element, its rank (NO_PART outside the partitioned blocks).
    pub part: Vec<u32>,
    /// Per serial dof, its PETSc index.
    pub petsc: Vec<PetscInt>,
    /// Rank `r`'s PETSc rows are `starts[r]..starts[r + 1]`.
    pub starts: Vec<usize>,
    /// The serial dofs this rank owns, ascending (their PETSc indices are consecutive).
    pub owned: Vec<usize>,
}

impl Layout {
    /// Partition the elements of `blocks` into the world's ranks and number the dofs of
    /// `field` for PETSc.
    pub fn new(
        mesh: &Mesh,
        dofs: &DofMap,
        field: FieldId,
        blocks: &[usize],
    ) -> Result<Self, String> {
        let world = session::comm();
        let (rank, size) = (world.rank() as usize, world.size() as usize);
        let part = element_parts(mesh, blocks)?;
        let node_owner = node_owners(mesh, blocks, &part);
        let n = dofs.len();
        let mut owner = vec![0u32; n];
        for (i, &o) in node_owner.iter().enumerate() {
            if let Some(d) = dofs.dof(field, NodeId(i as u32)) {
                owner[d.index()] = if o == NO_PART { 0 } else { o };
            }
        }
        let mut count = vec![0usize; size];
        for &o in &owner {
            count[o as usize] += 1;
        }
        let mut starts = vec![0usize; size + 1];
        for r in 0..size {
            starts[r + 1] = starts[r] + count[r];
        }
        let mut next = starts[..size].to_vec();
        let mut petsc = vec![0 as PetscInt; n];
        for (d, &o) in owner.iter().enumerate() {
            petsc[d] = next[o as usize] as PetscInt;
            next[o as usize] += 1;
        }
        let owned = (0..n).filter(|&d| owner[d] as usize == rank).collect();
        Ok(Layout {
            rank,
            part,
            petsc,
            starts,
            owned,
        })
    }

    /// This rank's PETSc rows.
    pub fn rows(&self) -> std::ops::Range<usize> {
        self.starts[self.rank]..self.starts[self.rank + 1]
    }

    /// The rank owning serial dof `d`.
    pub fn owner(&self, d: usize) -> usize {
        let i = self.petsc[d] as usize;
        self.starts.partition_point(|&s| s <= i) - 1
    }

    /// Whether serial dof `d` is owned here.
    pub fn owns(&self, d: usize) -> bool {
        self.rows().contains(&(self.petsc[d] as usize))
    }

    /// The mesh of this rank's elements: the same nodes and blocks (the blocks holding
    /// only this rank's elements, in their serial order), and per serial element its
    /// local element.
    pub fn local_mesh(&self, mesh: &Mesh) -> (Mesh, Vec<Option<ElemId>>) {
        let mut local = vec![None; mesh.num_elems()];
        let mut blocks = Vec::with_capacity(mesh.blocks.len());
        let mut elem_numbers = Vec::new();
        let mut next = 0u32;
        for block in &mesh.blocks {
            let nn = block.topology.node_count();
            let first_elem = ElemId(next);
            let mut connectivity = Vec::new();
            for (k, e) in block.elems().enumerate() {
                if self.part[e.index()] as usize == self.rank {
                    connectivity.extend_from_slice(&block.connectivity[k * nn..(k + 1) * nn]);
                    elem_numbers.push(mesh.elem_numbers[e.index()]);
                    local[e.index()] = Some(ElemId(next));
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
        let m = Mesh {
            dim: mesh.dim,
            coords: mesh.coords.clone(),
            node_numbers: mesh.node_numbers.clone(),
            elem_numbers,
            blocks,
            side_sets: Vec::new(),
            node_sets: Vec::new(),
            assemblies: Vec::new(),
            source: mesh.source.clone(),
            axisymmetric: mesh.axisymmetric,
        };
        (m, local)
    }
}

thread_local! {
    /// The last partition made: (element count, node count, blocks) and the parts, so
    /// the search and the solve of a run partition once and alike.
    static PARTS: RefCell<Option<(PartsKey, Vec<u32>)>> = const { RefCell::new(None) };
}

type PartsKey = (usize, usize, Vec<usize>);

/// Per element of `mesh`, its rank: METIS's partition of the elements of `blocks`
/// (made on rank 0 and broadcast, so every rank holds the same), [`NO_PART`] for
/// elements of other blocks. Made once per mesh and blocks.
pub(super) fn element_parts(mesh: &Mesh, blocks: &[usize]) -> Result<Vec<u32>, String> {
    let key = (mesh.num_elems(), mesh.num_nodes(), blocks.to_vec());
    if let Some(part) = PARTS.with(|p| {
        p.borrow()
            .as_ref()
            .and_then(|(k, part)| (*k == key).then(|| part.clone()))
    }) {
        return Ok(part);
    }
    let world = session::comm();
    let mut part = vec![NO_PART; mesh.num_elems()];
    // Rank 0's METIS failure reaches every rank (as an empty broadcast flag) so that no
    // rank waits for a broadcast that never comes.
    let mut failed = 0u8;
    let mut error = String::new();
    if world.rank() == 0 {
        match partition(mesh, blocks, world.size() as usize) {
            Ok(p) => part = p,
            Err(e) => (failed, error) = (1, e),
        }
    }
    world.process_at_rank(0).broadcast_into(&mut failed);
    if failed != 0 {
        return Err(if error.is_empty() {
            "the partition failed on rank 0".into()
        } else {
            error
        });
    }
    world.process_at_rank(0).broadcast_into(&mut part[..]);
    PARTS.with(|p| *p.borrow_mut() = Some((key, part.clone())));
    Ok(part)
}

/// Per node, its owner: the lowest part among its elements of `blocks` ([`NO_PART`] for
/// a node on none).
pub(super) fn node_owners(mesh: &Mesh, blocks: &[usize], part: &[u32]) -> Vec<u32> {
    let mut node_owner = vec![NO_PART; mesh.num_nodes()];
    for &b in blocks {
        let block = &mesh.blocks[b];
        let nn = block.topology.node_count();
        for (k, e) in block.elems().enumerate() {
            let p = part[e.index()];
            for n in &block.connectivity[k * nn..(k + 1) * nn] {
                let o = &mut node_owner[n.index()];
                *o = (*o).min(p);
            }
        }
    }
    node_owner
}

/// METIS's k-way partition of the dual graph (elements sharing a face: 3 common nodes in
/// 3-D, 2 in 2-D) of the elements of `blocks` into `parts` parts; other elements get
/// [`NO_PART`]. Fewer elements than parts: one element per part.
fn partition(mesh: &Mesh, blocks: &[usize], parts: usize) -> Result<Vec<u32>, String> {
    let mut part = vec![NO_PART; mesh.num_elems()];
    let elems: Vec<ElemId> = blocks
        .iter()
        .flat_map(|&b| mesh.blocks[b].elems())
        .collect();
    if parts == 1 || elems.len() <= parts {
        for (k, e) in elems.iter().enumerate() {
            part[e.index()] = (k % parts) as u32;
        }
        return Ok(part);
    }
    let mut eptr: Vec<i32> = Vec::with_capacity(elems.len() + 1);
    let mut eind: Vec<i32> = Vec::new();
    eptr.push(0);
    for &b in blocks {
        let block = &mesh.blocks[b];
        eind.extend(block.connectivity.iter().map(|n| n.0 as i32));
        let nn = block.topology.node_count() as i32;
        for _ in 0..block.len() {
            eptr.push(eptr.last().expect("starts with 0") + nn);
        }
    }
    let (mut ne, mut nn) = (elems.len() as i32, mesh.num_nodes() as i32);
    let mut ncommon: i32 = if mesh.dim == 3 { 3 } else { 2 };
    let mut nparts = parts as i32;
    let mut objval = 0i32;
    let mut epart = vec![0i32; elems.len()];
    let mut npart = vec![0i32; mesh.num_nodes()];
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    // SAFETY: the arrays have the sizes METIS_PartMeshDual documents (eptr ne+1, eind
    // eptr[ne], epart ne, npart nn, options METIS_NOPTIONS); weights may be null.
    let _one_at_a_time = crate::solve::metis_lock();
    let status = unsafe {
        metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
        metis_sys::METIS_PartMeshDual(
            &mut ne,
            &mut nn,
            eptr.as_mut_ptr(),
            eind.as_mut_ptr(),
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            &mut ncommon,
            &mut nparts,
            std::ptr::null_mut(),
            options.as_mut_ptr(),
            &mut objval,
            epart.as_mut_ptr(),
            npart.as_mut_ptr(),
        )
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(format!(
            "METIS_PartMeshDual failed (status {status}) on {} elements into {parts} parts",
            elems.len()
        ));
    }
    for (e, &p) in elems.iter().zip(&epart) {
        part[e.index()] = p as u32;
    }
    Ok(part)
}
