//! The rows of a distributed solve of one temperature field: which rank owns each dof
//! and its PETSc index ([`Layout`]), the values each rank brings from the others
//! ([`Scatter`]), the preallocation of the PETSc matrix and the per-rank pieces of the
//! assembly (own elements' mesh and face conditions, the interface couplings sent to the
//! owners of their rows, the heats summed over the ranks).

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::CommunicatorCollectives;

use crate::assembly::DofMap;
use crate::heat::{FaceBc, HeatError};
use crate::mesh::{ElemId, Mesh, NodeId, Side};

use super::part;
use super::petsc::{Mat, PetscError, PetscInt};
use super::session;

fn petsc_err(e: PetscError) -> HeatError {
    HeatError::Contact(format!("distributed solve: {e}"))
}

/// The dofs of one solve as PETSc sees them, on this rank: per local dof its PETSc
/// index, the rows of every rank, the dofs this rank owns, per local element and node
/// its owner (from the run's [`part::Part`]).
pub(super) struct Layout {
    pub(super) rank: usize,
    pub(super) size: usize,
    /// Ranks other than 0 hold their part only (the solution is gathered on rank 0).
    pub(super) distributed: bool,
    /// Per local dof, its PETSc index.
    pub(super) petsc: Vec<PetscInt>,
    /// Rank `r`'s PETSc rows are `starts[r]..starts[r + 1]`.
    pub(super) starts: Vec<usize>,
    /// The local dofs this rank owns, by PETSc index (consecutive).
    pub(super) owned: Vec<usize>,
    pub(super) elem_owner: Vec<u32>,
    pub(super) node_owner: Vec<u32>,
}

impl Layout {
    pub(super) fn new(
        part: &part::Part,
        mesh: &Mesh,
        dofs: &DofMap,
        field: crate::assembly::FieldId,
    ) -> Result<Layout, String> {
        if part.node_petsc.len() < mesh.num_nodes() || part.elem_owner.len() < mesh.num_elems() {
            return Err(format!(
                "distributed solve: the mesh has {} nodes and {} elements, this rank's part {} and {}",
                mesh.num_nodes(),
                mesh.num_elems(),
                part.node_petsc.len(),
                part.elem_owner.len()
            ));
        }
        let mut petsc = vec![-1 as PetscInt; dofs.len()];
        for k in 0..mesh.num_nodes() {
            if let Some(d) = dofs.dof(field, NodeId(k as u32)) {
                petsc[d.index()] = part.node_petsc[k];
            }
        }
        if let Some(d) = petsc.iter().position(|&i| i < 0) {
            return Err(format!(
                "distributed solve: dof {d} has no PETSc row (its node is on no partitioned block)"
            ));
        }
        let rows = part.rows();
        let mut owned: Vec<usize> = (0..dofs.len())
            .filter(|&d| rows.contains(&(petsc[d] as usize)))
            .collect();
        owned.sort_unstable_by_key(|&d| petsc[d]);
        if owned.len() != rows.len() {
            return Err(format!(
                "distributed solve: rank {} holds {} of its {} rows",
                part.rank,
                owned.len(),
                rows.len()
            ));
        }
        Ok(Layout {
            rank: part.rank,
            size: part.size,
            distributed: part.distributed,
            petsc,
            starts: part.starts.clone(),
            owned,
            elem_owner: (0..mesh.num_elems())
                .map(|e| part.elem_rank(ElemId(e as u32)) as u32)
                .collect(),
            node_owner: (0..mesh.num_nodes())
                .map(|n| part.node_rank(NodeId(n as u32)) as u32)
                .collect(),
        })
    }

    /// `count` more local dofs, the last `count` of `dofs` (a tie's multipliers, which no
    /// element owns): PETSc rows after every node's, owned by the last rank, in their
    /// local (the serial) order. Every rank must hold the same multipliers.
    pub(super) fn append_last(&mut self, count: usize) {
        let global = self.starts[self.size];
        let first = self.petsc.len();
        self.petsc
            .extend((0..count).map(|k| (global + k) as PetscInt));
        self.starts[self.size] += count;
        if self.rank + 1 == self.size {
            self.owned.extend(first..first + count);
        }
    }

    /// Whether this rank owns an interface point on a side-A face of element `elem`, or
    /// at side-A node `node`.
    pub(super) fn owns_point(&self, elem: Option<ElemId>, node: Option<NodeId>) -> bool {
        match (elem, node) {
            (Some(e), _) => self.elem_owner.get(e.index()).copied() == Some(self.rank as u32),
            (None, Some(n)) => self.node_owner.get(n.index()).copied() == Some(self.rank as u32),
            (None, None) => false,
        }
    }

    /// This rank's PETSc rows.
    pub(super) fn rows(&self) -> std::ops::Range<usize> {
        self.starts[self.rank]..self.starts[self.rank + 1]
    }

    /// The rank owning local dof `d`.
    pub(super) fn owner(&self, d: usize) -> usize {
        let i = self.petsc[d] as usize;
        self.starts.partition_point(|&s| s <= i) - 1
    }

    /// Whether local dof `d` is owned here.
    pub(super) fn owns(&self, d: usize) -> bool {
        self.rows().contains(&(self.petsc[d] as usize))
    }

    /// The mesh of this rank's own elements: the same nodes and blocks (the blocks holding
    /// only this rank's elements, in their order), and per element of `mesh` its element
    /// there.
    pub(super) fn local_mesh(&self, mesh: &Mesh) -> (Mesh, Vec<Option<ElemId>>) {
        let mut local = vec![None; mesh.num_elems()];
        let mut blocks = Vec::with_capacity(mesh.blocks.len());
        let mut elem_numbers = Vec::new();
        let mut next = 0u32;
        for block in &mesh.blocks {
            let nn = block.topology.node_count();
            let first_elem = ElemId(next);
            let mut connectivity = Vec::new();
            for (k, e) in block.elems().enumerate() {
                if self.elem_owner[e.index()] as usize == self.rank {
                    connectivity.extend_from_slice(&block.connectivity[k * nn..(k + 1) * nn]);
                    elem_numbers.push(mesh.elem_numbers[e.index()]);
                    local[e.index()] = Some(ElemId(next));
                    next += 1;
                }
            }
            blocks.push(crate::mesh::Block {
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

/// The increment's values a rank needs, brought from their owners each Newton step
/// (`MPI_Alltoallv` of the requested dofs' values) instead of gathering it whole.
pub(super) struct Scatter {
    /// Per rank, the local dofs this rank asks of it, in the order its answers come.
    pub(super) asks: Vec<Vec<usize>>,
    /// Per rank, the local rows (PETSc index − this rank's first row) it asks of us.
    pub(super) asked: Vec<Vec<usize>>,
    /// Per local dof, whether this rank keeps it up to date (owned or asked).
    pub(super) kept: Vec<bool>,
}

impl Scatter {
    /// Ask the owners of the `elements`' dofs and the `couplings`' dofs not owned here.
    pub(super) fn new(
        world: &SimpleCommunicator,
        layout: &Layout,
        elements: &[usize],
        couplings: &[(usize, usize)],
    ) -> Scatter {
        let size = layout.size;
        let mut need: Vec<usize> = elements
            .iter()
            .copied()
            .chain(couplings.iter().flat_map(|&(i, j)| [i, j]))
            .filter(|&d| !layout.owns(d))
            .collect();
        need.sort_unstable();
        need.dedup();
        let mut asks = vec![Vec::new(); size];
        let mut kept = vec![false; layout.petsc.len()];
        for &d in &layout.owned {
            kept[d] = true;
        }
        for d in need {
            asks[layout.owner(d)].push(d);
            kept[d] = true;
        }
        let requests: Vec<Vec<i32>> = asks
            .iter()
            .map(|a| a.iter().map(|&d| layout.petsc[d]).collect())
            .collect();
        let first = layout.rows().start;
        let asked = session::exchange(world, &requests)
            .into_iter()
            .map(|r| r.into_iter().map(|i| i as usize - first).collect())
            .collect();
        Scatter { asks, asked, kept }
    }

    /// The owners' values of `mine` (this rank's rows) at the dofs this rank asked for,
    /// per rank in the order asked.
    pub(super) fn bring(&self, world: &SimpleCommunicator, mine: &[f64]) -> Vec<Vec<f64>> {
        let answers: Vec<Vec<f64>> = self
            .asked
            .iter()
            .map(|rows| rows.iter().map(|&i| mine[i]).collect())
            .collect();
        session::exchange(world, &answers)
    }

    /// The starting values of the dofs asked for, as their owners hold them (a
    /// prescribed temperature at a node another rank holds).
    pub(super) fn start(&self, world: &SimpleCommunicator, layout: &Layout, u: &mut [f64]) {
        let mine: Vec<f64> = layout.owned.iter().map(|&d| u[d]).collect();
        let got = self.bring(world, &mine);
        for (dofs, values) in self.asks.iter().zip(&got) {
            for (&d, &v) in dofs.iter().zip(values) {
                u[d] = v;
            }
        }
    }

    /// Rank 0's `whole` (its `n` dofs; read there alone) at this rank's `n` local dofs:
    /// its own rows from rank 0 (`MPI_Scatterv`), the dofs it asks for from their owners.
    pub(super) fn sent_by_root(
        &self,
        world: &SimpleCommunicator,
        layout: &Layout,
        whole: &[f64],
        n: usize,
    ) -> Vec<f64> {
        let mut by_row = vec![
            0.0;
            if layout.rank == 0 {
                layout.starts[layout.size]
            } else {
                0
            }
        ];
        for (d, &v) in whole.iter().enumerate() {
            by_row[layout.petsc[d] as usize] = v;
        }
        let mine = session::scatter_root(world, &by_row, &layout.starts);
        let first = layout.rows().start;
        let mut u = vec![0.0; n];
        for &d in &layout.owned {
            u[d] = mine[layout.petsc[d] as usize - first];
        }
        self.start(world, layout, &mut u);
        u
    }

    /// Add the increment (`mine`: this rank's rows) to `u` at the dofs owned or asked;
    /// returns its largest magnitude over every rank.
    pub(super) fn update(
        &self,
        world: &SimpleCommunicator,
        layout: &Layout,
        mine: &[f64],
        u: &mut [f64],
    ) -> f64 {
        let first = layout.rows().start;
        let got = self.bring(world, mine);
        let mut step = 0.0f64;
        for &d in &layout.owned {
            let du = mine[layout.petsc[d] as usize - first];
            u[d] += du;
            step = step.max(du.abs());
        }
        for (dofs, values) in self.asks.iter().zip(&got) {
            for (&d, &du) in dofs.iter().zip(values) {
                u[d] += du;
            }
        }
        let mut largest = 0.0;
        world.all_reduce_into(&step, &mut largest, SystemOperation::max());
        largest
    }

    /// The largest |u| over the owned dofs of every rank (of those `u` holds: the first
    /// ones).
    pub(super) fn u_max(&self, world: &SimpleCommunicator, layout: &Layout, u: &[f64]) -> f64 {
        let own = layout.owned.iter().filter_map(|&d| u.get(d));
        let mine = own.fold(0.0f64, |m, v| m.max(v.abs()));
        let mut largest = 0.0;
        world.all_reduce_into(&mine, &mut largest, SystemOperation::max());
        largest
    }
}

/// The couplings (PETSc rows and columns) of every rank's points that fall in this
/// rank's rows: each rank sends each of its couplings `(i, j)` to the owners of row `i`
/// and of row `j` (`MPI_Alltoallv`).
pub(super) fn couplings_to_owners(
    world: &SimpleCommunicator,
    layout: &Layout,
    mine: &[(usize, usize)],
) -> Vec<(usize, usize)> {
    let mut out: Vec<Vec<i32>> = vec![Vec::new(); layout.size];
    for &(i, j) in mine {
        let (pi, pj) = (layout.petsc[i], layout.petsc[j]);
        out[layout.owner(i)].extend_from_slice(&[pi, pj]);
        out[layout.owner(j)].extend_from_slice(&[pj, pi]);
    }
    session::exchange(world, &out)
        .into_iter()
        .flat_map(|v| {
            v.chunks_exact(2)
                .map(|c| (c[0] as usize, c[1] as usize))
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Each interaction's heat (side A, side B) summed over the ranks' points.
pub(super) fn summed_heat(world: &SimpleCommunicator, mine: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let flat: Vec<f64> = mine.iter().flat_map(|&(a, b)| [a, b]).collect();
    let mut sum = vec![0.0; flat.len()];
    world.all_reduce_into(&flat[..], &mut sum[..], SystemOperation::sum());
    sum.chunks_exact(2).map(|c| (c[0], c[1])).collect()
}

/// The face conditions of this rank's elements, on its local mesh.
pub(super) fn local_faces(faces: &[FaceBc], to_local: &[Option<ElemId>]) -> Vec<FaceBc> {
    faces
        .iter()
        .filter_map(|f| {
            let s = f.side();
            let elem = to_local.get(s.elem.index()).copied().flatten()?;
            let side = Side { elem, side: s.side };
            Some(match *f {
                FaceBc::Flux { q, .. } => FaceBc::Flux { side, q },
                FaceBc::Convection { h, t_inf, .. } => FaceBc::Convection { side, h, t_inf },
                FaceBc::Radiation {
                    emissivity, t_inf, ..
                } => FaceBc::Radiation {
                    side,
                    emissivity,
                    t_inf,
                },
            })
        })
        .collect()
}

/// `mesh` without elements: the pattern of the interface couplings alone.
pub(super) fn empty_mesh(mesh: &Mesh) -> Mesh {
    Mesh {
        dim: mesh.dim,
        coords: Vec::new(),
        node_numbers: Vec::new(),
        elem_numbers: Vec::new(),
        blocks: mesh
            .blocks
            .iter()
            .map(|b| crate::mesh::Block {
                id: b.id,
                name: b.name.clone(),
                topology: b.topology,
                connectivity: Vec::new(),
                first_elem: ElemId(0),
                thickness: b.thickness,
            })
            .collect(),
        side_sets: Vec::new(),
        node_sets: Vec::new(),
        assemblies: Vec::new(),
        source: None,
        axisymmetric: mesh.axisymmetric,
    }
}

/// A matrix's entries in column storage, listed by PETSc row with the columns ascending,
/// for [`add_rows`] (and the general solver's rows): PETSc finds each column of a row
/// from the place of the one before, where entries set a column at a time search every
/// row they touch anew. Made once per pattern.
pub(super) struct ByRows {
    /// The PETSc rows that hold entries, and where each row's entries start.
    rows: Vec<PetscInt>,
    start: Vec<usize>,
    /// Per entry, its PETSc column and its slot in the column storage's values.
    cols: Vec<PetscInt>,
    slots: Vec<u32>,
}

impl ByRows {
    /// The entries of a matrix over local dofs, by their PETSc rows and columns.
    pub(super) fn new(sym: &faer::sparse::SymbolicSparseColMat<usize>, layout: &Layout) -> ByRows {
        Self::of(sym.as_ref(), &|i| layout.petsc[i], &|_| true)
    }

    /// The entries of the rows `keep` accepts, each row and column `i` PETSc's
    /// `petsc(i)`.
    pub(super) fn of(
        sym: faer::sparse::SymbolicSparseColMatRef<'_, usize>,
        petsc: &dyn Fn(usize) -> PetscInt,
        keep: &dyn Fn(usize) -> bool,
    ) -> ByRows {
        let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
        let mut count = vec![0usize; sym.nrows() + 1];
        for &i in row_idx.iter().filter(|&&i| keep(i)) {
            count[i + 1] += 1;
        }
        for i in 0..sym.nrows() {
            count[i + 1] += count[i];
        }
        let mut at = count.clone();
        let mut entries = vec![(0 as PetscInt, 0u32); count[sym.nrows()]];
        for j in 0..sym.ncols() {
            let slots = col_ptr[j]..col_ptr[j + 1];
            for (k, &i) in slots.clone().zip(&row_idx[slots]).filter(|e| keep(*e.1)) {
                entries[at[i]] = (petsc(j), k as u32);
                at[i] += 1;
            }
        }
        let mut out = ByRows {
            rows: Vec::new(),
            start: vec![0],
            cols: Vec::with_capacity(entries.len()),
            slots: Vec::with_capacity(entries.len()),
        };
        for i in 0..sym.nrows() {
            let row = &mut entries[count[i]..count[i + 1]];
            if row.is_empty() {
                continue;
            }
            row.sort_unstable();
            out.rows.push(petsc(i));
            out.cols.extend(row.iter().map(|e| e.0));
            out.slots.extend(row.iter().map(|e| e.1));
            out.start.push(out.cols.len());
        }
        out
    }
}

impl ByRows {
    /// Each row: its PETSc index, its PETSc columns (ascending) and their slots in the
    /// column storage's values.
    pub(super) fn rows(&self) -> impl Iterator<Item = (PetscInt, &[PetscInt], &[u32])> {
        (self.rows.iter().zip(self.start.windows(2)))
            .map(|(&row, w)| (row, &self.cols[w[0]..w[1]], &self.slots[w[0]..w[1]]))
    }
}

/// Add a matrix's `values` (in the column storage `by` was made from) to `a`, a row at
/// a time. Its zeros are left out unless `zeros`: where a later matrix of the same
/// pattern may hold a value there (a tangent that depends on u: on a mesh of cubes the
/// conduction's entries between the ends of an element edge are exactly 0 at a constant
/// k, not at a k of T), since PETSc drops the preallocated places its first assembly
/// did not fill and refuses a new entry afterwards.
pub(super) fn add_rows(
    a: &mut Mat,
    by: &ByRows,
    values: &[f64],
    zeros: bool,
) -> Result<(), HeatError> {
    let (mut cols, mut vals) = (Vec::new(), Vec::new());
    for (row, row_cols, slots) in by.rows() {
        cols.clear();
        vals.clear();
        for (&c, &k) in row_cols.iter().zip(slots) {
            let v = values[k as usize];
            if zeros || v != 0.0 {
                cols.push(c);
                vals.push(v);
            }
        }
        if !cols.is_empty() {
            a.add_row(row, &cols, &vals).map_err(petsc_err)?;
        }
    }
    Ok(())
}

/// Exact preallocation of this rank's rows: per row, the columns of every element at
/// its node (all of them held here: a rank holds every element around the nodes it owns),
/// and the interface couplings `reaching` its rows (PETSc row, PETSc column), counted
/// inside and outside the rank's column block.
pub(super) fn preallocation(
    mesh: &Mesh,
    dofs: &DofMap,
    field: crate::assembly::FieldId,
    layout: &Layout,
    reaching: &[(usize, usize)],
) -> (Vec<PetscInt>, Vec<PetscInt>) {
    let rows = layout.rows();
    let mut cols: Vec<Vec<usize>> = vec![Vec::new(); rows.len()];
    let local_row = |i: usize| -> Option<usize> { rows.contains(&i).then(|| i - rows.start) };
    let mut buf = Vec::new();
    for &b in dofs.field_blocks(field) {
        let nn = mesh.blocks[b].topology.node_count();
        for (k, _) in mesh.blocks[b].elems().enumerate() {
            buf.clear();
            buf.extend(
                mesh.blocks[b].connectivity[k * nn..(k + 1) * nn]
                    .iter()
                    .filter_map(|&node| dofs.dof(field, node))
                    .map(|d| layout.petsc[d.index()] as usize),
            );
            for &i in &buf {
                if let Some(r) = local_row(i) {
                    cols[r].extend_from_slice(&buf);
                }
            }
        }
    }
    for &(i, j) in reaching {
        if let Some(r) = local_row(i) {
            cols[r].push(j);
        }
    }
    let (mut diagonal, mut off) = (vec![0; rows.len()], vec![0; rows.len()]);
    for (r, c) in cols.iter_mut().enumerate() {
        c.push(rows.start + r);
        c.sort_unstable();
        c.dedup();
        for &i in c.iter() {
            if rows.contains(&i) {
                diagonal[r] += 1;
            } else {
                off[r] += 1;
            }
        }
    }
    (diagonal, off)
}

/// How the partition meets the interfaces, in rank 0's log: couplings whose two dofs
/// sit on different ranks are those a per-rank solve would get wrong.
pub(super) fn log_partition(
    world: &SimpleCommunicator,
    layout: &Layout,
    pairs_of_mine: &[(usize, usize)],
) {
    let across = pairs_of_mine
        .iter()
        .filter(|&&(i, j)| layout.owner(i) != layout.owner(j))
        .count() as u64;
    let mine = [across, pairs_of_mine.len() as u64];
    let mut sum = [0u64; 2];
    world.all_reduce_into(&mine[..], &mut sum[..], SystemOperation::sum());
    let held = part::with(part::Part::counts).unwrap_or_default();
    let mut elems = vec![0u64; layout.size];
    world.all_gather_into(&(held.owned as u64), &mut elems[..]);
    if layout.rank == 0 {
        let dofs_per: Vec<usize> = layout.starts.windows(2).map(|w| w[1] - w[0]).collect();
        log::info!(
            "distributed over {} rank(s): elements per rank {elems:?}, dofs per rank {dofs_per:?}; {} of {} interface couplings join dofs of different ranks",
            elems.len(),
            sum[0],
            sum[1]
        );
    }
}
