//! The partition: the elements of the solid blocks split by METIS into one part per
//! rank ([`partition`]; for a run whose every rank holds the whole mesh, made on rank 0
//! and broadcast by [`element_parts`], so every rank holds the same), and each node's
//! owner, the lowest rank among its elements' parts ([`node_owners`]). What each rank
//! then holds and how PETSc numbers the dofs is [`super::part`]'s.

use std::cell::RefCell;

use mpi::traits::{Communicator, Root};

use crate::mesh::{ElemId, Mesh};

use super::session;

/// Part of an element outside the partitioned blocks (no temperature).
pub(super) const NO_PART: u32 = u32::MAX;

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
        match partition(mesh, blocks, world.size() as usize, None) {
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
/// [`NO_PART`]. Fewer elements than parts: one element per part. `costs`, per block of
/// the mesh: the work of assembling one of its elements; where the blocks' differ, the
/// parts balance both their elements and that work (METIS's two-constraint k-way
/// partition of the dual graph), else their elements alone.
pub(super) fn partition(
    mesh: &Mesh,
    blocks: &[usize],
    parts: usize,
    costs: Option<&[u32]>,
) -> Result<Vec<u32>, String> {
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
    let (ne, nn) = (elems.len() as i32, mesh.num_nodes() as i32);
    let ncommon: i32 = if mesh.dim == 3 { 3 } else { 2 };
    let mut epart = vec![0i32; elems.len()];
    // Blocks whose elements cost different work to assemble: balance both the elements
    // (the solve's rows) and that work.
    match costs.filter(|c| blocks.iter().any(|&b| c[b] != c[blocks[0]])) {
        Some(costs) => {
            let vwgt: Vec<i32> = (blocks.iter())
                .flat_map(|&b| std::iter::repeat_n([1, costs[b] as i32], mesh.blocks[b].len()))
                .flatten()
                .collect();
            let dual = DualGraph::new(ne, nn, (&mut eptr, &mut eind), ncommon)?;
            dual.partition(vwgt, parts as i32, &mut epart)?;
        }
        None => part_mesh_dual((ne, nn), (&mut eptr, &mut eind), ncommon, parts, &mut epart)?,
    }
    for (e, &p) in elems.iter().zip(&epart) {
        part[e.index()] = p as u32;
    }
    Ok(part)
}

/// The dual graph of a mesh (elements joined when they share `ncommon` nodes), as METIS
/// makes it and frees it.
struct DualGraph {
    n: i32,
    xadj: *mut i32,
    adjncy: *mut i32,
}

impl DualGraph {
    /// The dual graph of the `ne` elements over `nn` nodes in `(eptr, eind)`.
    fn new(
        mut ne: i32,
        mut nn: i32,
        (eptr, eind): (&mut [i32], &mut [i32]),
        mut ncommon: i32,
    ) -> Result<DualGraph, String> {
        let mut g = DualGraph {
            n: ne,
            xadj: std::ptr::null_mut(),
            adjncy: std::ptr::null_mut(),
        };
        let mut numflag = 0;
        let _one_at_a_time = crate::solve::metis_lock();
        // SAFETY: eptr has ne + 1 entries and eind eptr[ne]; METIS allocates the graph's
        // arrays into the two pointers, freed by `Drop` with METIS_Free.
        let status = unsafe {
            metis_sys::METIS_MeshToDual(
                &mut ne,
                &mut nn,
                eptr.as_mut_ptr(),
                eind.as_mut_ptr(),
                &mut ncommon,
                &mut numflag,
                &mut g.xadj,
                &mut g.adjncy,
            )
        };
        if status != metis_sys::rstatus_et_METIS_OK || g.xadj.is_null() {
            return Err(format!(
                "METIS_MeshToDual failed (status {status}) on {ne} elements"
            ));
        }
        Ok(g)
    }

    /// Its vertices into `nparts` parts (`part`, one per vertex), balancing each of the
    /// weights `vwgt` gives every vertex (two per vertex, side by side).
    fn partition(
        &self,
        mut vwgt: Vec<i32>,
        mut nparts: i32,
        part: &mut [i32],
    ) -> Result<(), String> {
        let (mut n, mut ncon, mut objval) = (self.n, 2i32, 0i32);
        assert!(vwgt.len() == 2 * n as usize && part.len() == n as usize);
        let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
        let _one_at_a_time = crate::solve::metis_lock();
        // SAFETY: xadj/adjncy are METIS's own graph of n vertices; vwgt has ncon·n
        // entries and part n; the other weights may be null.
        let status = unsafe {
            metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
            metis_sys::METIS_PartGraphKway(
                &mut n,
                &mut ncon,
                self.xadj,
                self.adjncy,
                vwgt.as_mut_ptr(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                &mut nparts,
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                options.as_mut_ptr(),
                &mut objval,
                part.as_mut_ptr(),
            )
        };
        match status == metis_sys::rstatus_et_METIS_OK {
            true => Ok(()),
            false => Err(format!(
                "METIS_PartGraphKway failed (status {status}) on {n} elements into {nparts} parts, two weights each"
            )),
        }
    }
}

impl Drop for DualGraph {
    fn drop(&mut self) {
        // SAFETY: both were allocated by METIS_MeshToDual (or are null, which
        // METIS_Free ignores).
        unsafe {
            metis_sys::METIS_Free(self.xadj.cast());
            metis_sys::METIS_Free(self.adjncy.cast());
        }
    }
}

/// METIS's partition of the dual graph of the `ne` elements over `nn` nodes in
/// `(eptr, eind)` into `parts` parts (`epart`, one per element), the elements weighing
/// alike.
fn part_mesh_dual(
    (mut ne, mut nn): (i32, i32),
    (eptr, eind): (&mut [i32], &mut [i32]),
    mut ncommon: i32,
    parts: usize,
    epart: &mut [i32],
) -> Result<(), String> {
    let mut nparts = parts as i32;
    let mut objval = 0i32;
    let mut npart = vec![0i32; nn as usize];
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
    match status == metis_sys::rstatus_et_METIS_OK {
        true => Ok(()),
        false => Err(format!(
            "METIS_PartMeshDual failed (status {status}) on {ne} elements into {parts} parts"
        )),
    }
}
