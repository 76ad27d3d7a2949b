//! The host's global system: which unknown (degree of freedom, dof) belongs to which
//! node and field, the sparse pattern those unknowns couple through, and the assembly
//! of element matrices and vectors into a faer [`SparseColMat`].
//!
//! Entry points: [`DofMap::new`] (named scalar fields on sets of blocks, plus
//! [`DofMap::add_extra`] for Lagrange multipliers), [`Pattern::new`] with
//! [`Pattern::add_couplings`] (node–node couplings across an interface) and
//! [`Pattern::build`], then an [`Assembler`] per assembly.
//!
//! Conventions:
//! - Dofs are numbered field after field; inside a field, by increasing [`NodeId`] over
//!   the nodes of the field's blocks. Extra dofs follow all field dofs.
//! - The matrix is stored in full (both triangles), columns sorted, and its pattern
//!   always holds the diagonal, so Dirichlet elimination and multiplier rows never
//!   change the pattern.
//! - Every element owns a fixed slot of `ne × ne` values (`ne` = element dofs, fields
//!   of the block one after the other, nodes in connectivity order, row-major), every
//!   coupling a slot of two values `(i, j)` and `(j, i)`, every dof a diagonal slot.
//!   The symbolic CSC matrix ([`SymbolicSparseColMat`]) is built once from the
//!   element connectivity, couplings and diagonal, together with each slot's
//!   position in the CSC value array; each assembly only writes slot values and adds
//!   them into a fresh value array, slot after slot.
//! - A pattern built for direct assembly ([`Pattern::build_direct`], [`Assembler::direct`])
//!   keeps no element slots: element matrices are added into the CSC value array as
//!   they are made (in element order, so the sums have the bits of the slot path) and
//!   are not kept — for a matrix whose element part is assembled once. Couplings and
//!   diagonal entries keep their slots.
//! - Determinism and symmetry: element kernels run in parallel (rayon) but write only
//!   their own slot, and slots are summed in slot order, so the matrix is
//!   bit-identical whatever the number of threads, and entries `(i, j)` and `(j, i)`
//!   receive the same terms in the same order (exactly symmetric when the element
//!   matrices are). faer's own `new_from_argsort` is not used because it sums
//!   duplicates in the order of an unstable sort, which leaves `a_ij` and `a_ji`
//!   differing in the last bit.

use std::ops::Range;

use faer::sparse::{SparseColMat, SymbolicSparseColMat};
use rayon::prelude::*;

use crate::mesh::{ElemId, Mesh, NodeId};

mod direct;

/// A named field of a [`DofMap`], by position.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FieldId(pub u32);

/// A global unknown: a row (and column) of the assembled system.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Dof(pub u32);

impl Dof {
    pub fn index(self) -> usize {
        self.0 as usize
    }
}

/// Errors of DOF numbering, pattern building and assembly.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum AssemblyError {
    #[error("field `{field}`: block index {block} does not exist (the mesh has {count} blocks)")]
    NoSuchBlock {
        field: String,
        block: usize,
        count: usize,
    },
    #[error("field `{0}` is defined twice")]
    DuplicateField(String),
    #[error("coupling ({row}, {col}) names a dof outside 0..{n}")]
    CouplingOutOfRange { row: usize, col: usize, n: usize },
    #[error(
        "element {elem} (number {number}) produced a non-finite matrix entry {value} at local ({row}, {col})"
    )]
    NonFiniteElement {
        elem: u32,
        number: i64,
        row: usize,
        col: usize,
        value: f64,
    },
    #[error("the sparse matrix could not be created: {0}")]
    Faer(String),
}

const NONE: u32 = u32::MAX;

#[derive(Clone, Debug)]
struct Field {
    name: String,
    blocks: Vec<usize>,
    /// Node index → dof, `NONE` where the field has no dof.
    node_dof: Vec<u32>,
    range: Range<usize>,
}

/// Node → dof numbering for named scalar fields, plus extra (multiplier) dofs.
#[derive(Clone, Debug)]
pub struct DofMap {
    fields: Vec<Field>,
    /// For each block: the fields defined on it, in field order.
    block_fields: Vec<Vec<FieldId>>,
    extra: Vec<Range<usize>>,
    len: usize,
}

impl DofMap {
    /// Number the dofs of `fields`, each a name and the indices (into `mesh.blocks`) of
    /// the blocks it lives on.
    pub fn new(mesh: &Mesh, fields: &[(&str, &[usize])]) -> Result<Self, AssemblyError> {
        let mut out = DofMap {
            fields: Vec::new(),
            block_fields: vec![Vec::new(); mesh.blocks.len()],
            extra: Vec::new(),
            len: 0,
        };
        for (name, blocks) in fields {
            if out.fields.iter().any(|f| f.name == *name) {
                return Err(AssemblyError::DuplicateField(name.to_string()));
            }
            let mut on = vec![false; mesh.num_nodes()];
            for &b in *blocks {
                let block = mesh.blocks.get(b).ok_or(AssemblyError::NoSuchBlock {
                    field: name.to_string(),
                    block: b,
                    count: mesh.blocks.len(),
                })?;
                for n in &block.connectivity {
                    on[n.index()] = true;
                }
            }
            let start = out.len;
            let mut next = start as u32;
            let node_dof = on
                .iter()
                .map(|&o| {
                    if o {
                        next += 1;
                        next - 1
                    } else {
                        NONE
                    }
                })
                .collect();
            out.len = next as usize;
            let id = FieldId(out.fields.len() as u32);
            let mut blocks = blocks.to_vec();
            blocks.sort_unstable();
            blocks.dedup();
            for &b in &blocks {
                out.block_fields[b].push(id);
            }
            out.fields.push(Field {
                name: name.to_string(),
                blocks,
                node_dof,
                range: start..out.len,
            });
        }
        Ok(out)
    }

    /// Total number of dofs (fields and extra).
    pub fn len(&self) -> usize {
        self.len
    }

    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Append `n` extra dofs (Lagrange multipliers) after everything numbered so far.
    /// A [`Pattern`] built before this call does not know them: build a new one.
    pub fn add_extra(&mut self, n: usize) -> Range<usize> {
        let r = self.len..self.len + n;
        self.len += n;
        self.extra.push(r.clone());
        r
    }

    /// The ranges handed out by [`DofMap::add_extra`], in order.
    pub fn extra_ranges(&self) -> &[Range<usize>] {
        &self.extra
    }

    pub fn field(&self, name: &str) -> Option<FieldId> {
        self.fields
            .iter()
            .position(|f| f.name == name)
            .map(|i| FieldId(i as u32))
    }

    pub fn field_name(&self, field: FieldId) -> &str {
        &self.fields[field.0 as usize].name
    }

    /// The contiguous dof range of a field.
    pub fn field_range(&self, field: FieldId) -> Range<usize> {
        self.fields[field.0 as usize].range.clone()
    }

    /// Block indices a field lives on (sorted).
    pub fn field_count(&self) -> usize {
        self.fields.len()
    }

    pub fn field_blocks(&self, field: FieldId) -> &[usize] {
        &self.fields[field.0 as usize].blocks
    }

    /// The dof of `field` at `node`, if the field lives there.
    pub fn dof(&self, field: FieldId, node: NodeId) -> Option<Dof> {
        match self.fields[field.0 as usize].node_dof.get(node.index()) {
            Some(&d) if d != NONE => Some(Dof(d)),
            _ => None,
        }
    }

    /// Fields defined on a block, in field order.
    pub fn block_fields(&self, block: usize) -> &[FieldId] {
        &self.block_fields[block]
    }

    /// Number of dofs of one element of `block`.
    pub fn elem_dof_count(&self, mesh: &Mesh, block: usize) -> usize {
        self.block_fields[block].len() * mesh.blocks[block].topology.node_count()
    }

    /// The dofs of the first field of `elem`'s block at its nodes, in connectivity
    /// order (the leading part of [`Self::elem_dofs`]), into `out`; their number.
    pub fn first_field_dofs(&self, mesh: &Mesh, elem: ElemId, out: &mut [u32]) -> usize {
        let nodes = mesh.elem_nodes(elem);
        let Some(f) = self.block_fields[mesh.block_of(elem)].first() else {
            return 0;
        };
        let map = &self.fields[f.0 as usize].node_dof;
        for (o, n) in out.iter_mut().zip(nodes) {
            *o = map[n.index()];
        }
        nodes.len()
    }

    /// Dofs of an element: for each field of its block, its nodes' dofs in
    /// connectivity order. `out` is cleared first.
    pub fn elem_dofs(&self, mesh: &Mesh, elem: ElemId, out: &mut Vec<u32>) {
        out.clear();
        let b = mesh.block_of(elem);
        let nodes = mesh.elem_nodes(elem);
        for f in &self.block_fields[b] {
            let map = &self.fields[f.0 as usize].node_dof;
            out.extend(nodes.iter().map(|n| map[n.index()]));
        }
    }

    /// Nodal values of `field` from a dof vector (`NaN` where the field has no dof).
    pub fn nodal_values(&self, field: FieldId, x: &[f64]) -> Vec<f64> {
        self.fields[field.0 as usize]
            .node_dof
            .iter()
            .map(|&d| if d == NONE { f64::NAN } else { x[d as usize] })
            .collect()
    }
}

/// The sparse pattern of the global matrix: element connectivity, extra couplings and
/// the diagonal, with the faer symbolic structure and slot positions once
/// [`Pattern::build`] has run.
#[derive(Clone, Debug)]
pub struct Pattern {
    n: usize,
    /// Per block: (first slot offset, element dof count, element count); elements of a
    /// block are contiguous in the slot array.
    block_slots: Vec<(usize, usize, usize)>,
    elem_values: usize,
    /// Global dofs of each element slot row, concatenated block after block.
    elem_dofs: Vec<u32>,
    couplings: Vec<(u32, u32)>,
    /// The CSC structure and the slot positions.
    built: Option<Built>,
}

/// A built pattern: the CSC structure (32-bit row indices: a dof is 32 bits) and, for
/// every slot, its position in the value array — element slots first unless built for
/// direct assembly. faer's symbolic matrix (with `usize` row indices, twice the bytes)
/// is made from it when first asked for: a solve by AMG-CG never needs it.
#[derive(Clone, Debug)]
struct Built {
    col_ptr: Vec<usize>,
    row_idx: Vec<u32>,
    sym: std::sync::OnceLock<SymbolicSparseColMat<usize>>,
    positions: Vec<u32>,
    element_slots: bool,
}

impl Pattern {
    /// The element part of the pattern for every element of every block that carries a
    /// field of `dofs`.
    pub fn new(mesh: &Mesh, dofs: &DofMap) -> Self {
        let mut block_slots = Vec::with_capacity(mesh.blocks.len());
        let mut elem_values = 0;
        // Sized at once, not grown by doubling (copied, its pages faulted in again).
        let total = (0..mesh.blocks.len())
            .map(|b| mesh.blocks[b].len() * dofs.elem_dof_count(mesh, b))
            .sum();
        let mut elem_dofs = Vec::with_capacity(total);
        let mut buf = Vec::new();
        for (b, block) in mesh.blocks.iter().enumerate() {
            let ne = dofs.elem_dof_count(mesh, b);
            let count = if ne == 0 { 0 } else { block.len() };
            block_slots.push((elem_values, ne, count));
            elem_values += count * ne * ne;
            for e in block.elems().take(count) {
                dofs.elem_dofs(mesh, e, &mut buf);
                elem_dofs.extend_from_slice(&buf);
            }
        }
        Pattern {
            n: dofs.len(),
            block_slots,
            elem_values,
            elem_dofs,
            couplings: Vec::new(),
            built: None,
        }
    }

    /// Add couplings `(i, j)`; each makes entries `(i, j)` and `(j, i)`. Coupling `k`
    /// (counting all calls) is filled by [`Assembler::add_coupling`]`(k, ..)`. Returns
    /// the index range of the added couplings. Invalidates a built pattern.
    pub fn add_couplings(
        &mut self,
        pairs: &[(usize, usize)],
    ) -> Result<Range<usize>, AssemblyError> {
        let start = self.couplings.len();
        for &(row, col) in pairs {
            if row >= self.n || col >= self.n {
                return Err(AssemblyError::CouplingOutOfRange {
                    row,
                    col,
                    n: self.n,
                });
            }
            self.couplings.push((row as u32, col as u32));
        }
        self.built = None;
        Ok(start..self.couplings.len())
    }

    /// Number of rows (= columns).
    pub fn len(&self) -> usize {
        self.n
    }

    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    pub fn coupling_count(&self) -> usize {
        self.couplings.len()
    }

    /// Length of the value array an [`Assembler`] fills: element slots, two per
    /// coupling, one per diagonal entry.
    pub fn value_count(&self) -> usize {
        self.elem_values + 2 * self.couplings.len() + self.n
    }

    /// Build the faer symbolic matrix and the slot positions. Column `j` holds `j`
    /// itself, every dof of every element that has `j`, and the coupling partners of
    /// `j`; columns are built in parallel from a dof → element map (no global sort of
    /// all slots), then each slot finds its position by binary search in its column.
    pub fn build(&mut self) -> Result<(), AssemblyError> {
        self.build_with(true)
    }

    /// As [`Self::build`] without the element slots' positions (4 bytes per element
    /// matrix entry), for [`Assembler::direct`] only.
    pub fn build_direct(&mut self) -> Result<(), AssemblyError> {
        self.build_with(false)
    }

    fn build_with(&mut self, element_slots: bool) -> Result<(), AssemblyError> {
        if self
            .built
            .as_ref()
            .is_some_and(|b| b.element_slots || !element_slots)
        {
            return Ok(());
        }
        let n = self.n;
        // Every element's range in `elem_dofs`, in slot order.
        let mut elems: Vec<(usize, usize)> = Vec::new();
        let mut off = 0;
        for &(_, ne, count) in &self.block_slots {
            for _ in 0..count {
                elems.push((off, ne));
                off += ne;
            }
        }
        // dof → elements holding it (CSR by counting).
        let mut d2e_ptr = vec![0usize; n + 1];
        for &d in &self.elem_dofs {
            if d != NONE {
                d2e_ptr[d as usize + 1] += 1;
            }
        }
        for i in 0..n {
            d2e_ptr[i + 1] += d2e_ptr[i];
        }
        let mut d2e = vec![0u32; d2e_ptr[n]];
        let mut next = d2e_ptr.clone();
        for (e, &(o, ne)) in elems.iter().enumerate() {
            for &d in &self.elem_dofs[o..o + ne] {
                if d != NONE {
                    d2e[next[d as usize]] = e as u32;
                    next[d as usize] += 1;
                }
            }
        }
        // Coupling partners per column (both directions).
        let mut c_ptr = vec![0usize; n + 1];
        for &(i, j) in &self.couplings {
            c_ptr[j as usize + 1] += 1;
            c_ptr[i as usize + 1] += 1;
        }
        for i in 0..n {
            c_ptr[i + 1] += c_ptr[i];
        }
        let mut partners = vec![0u32; c_ptr[n]];
        let mut next = c_ptr.clone();
        for &(i, j) in &self.couplings {
            partners[next[j as usize]] = i;
            next[j as usize] += 1;
            partners[next[i as usize]] = j;
            next[i as usize] += 1;
        }
        // Each column's rows gathered once (a marker per dof holds the last column
        // that took it: no sort of the repeats) and then sorted, as 32-bit indices.
        const CHUNK: usize = 4096;
        let chunks: Vec<(Vec<usize>, Vec<u32>)> = (0..n.div_ceil(CHUNK))
            .into_par_iter()
            .map_init(
                || vec![0u32; n],
                |seen, c| {
                    let (mut lens, mut rows) = (Vec::new(), Vec::new());
                    let mut col: Vec<u32> = Vec::new();
                    for j in c * CHUNK..((c + 1) * CHUNK).min(n) {
                        // `seen[d] == j + 1`: d is already in column j.
                        let mark = j as u32 + 1;
                        col.clear();
                        let mut take = |d: u32| {
                            if seen[d as usize] != mark {
                                seen[d as usize] = mark;
                                col.push(d);
                            }
                        };
                        take(j as u32);
                        for &e in &d2e[d2e_ptr[j]..d2e_ptr[j + 1]] {
                            let (o, ne) = elems[e as usize];
                            for &d in &self.elem_dofs[o..o + ne] {
                                if d != NONE {
                                    take(d);
                                }
                            }
                        }
                        for &i in &partners[c_ptr[j]..c_ptr[j + 1]] {
                            take(i);
                        }
                        col.sort_unstable();
                        lens.push(col.len());
                        rows.extend_from_slice(&col);
                    }
                    (lens, rows)
                },
            )
            .collect();
        drop((d2e, d2e_ptr, partners, c_ptr, elems));
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0usize);
        let mut row_idx = Vec::with_capacity(chunks.iter().map(|c| c.1.len()).sum());
        for (lens, rows) in chunks {
            for l in lens {
                col_ptr.push(col_ptr.last().unwrap() + l);
            }
            row_idx.extend(rows);
        }
        if row_idx.len() > u32::MAX as usize {
            return Err(AssemblyError::Faer(format!(
                "{} stored entries exceed the 32-bit slot positions",
                row_idx.len()
            )));
        }
        let pos = |row: usize, col: usize| -> u32 {
            let rows = &row_idx[col_ptr[col]..col_ptr[col + 1]];
            (col_ptr[col] + direct::lower_bound(rows, row as u32)) as u32
        };
        let elem_len = if element_slots { self.elem_values } else { 0 };
        let mut positions = vec![0u32; self.value_count() - self.elem_values + elem_len];
        let (elem_part, rest) = positions.split_at_mut(elem_len);
        let mut elem_part = elem_part;
        let mut dof_off = 0;
        for &(_, ne, count) in self.block_slots.iter().filter(|_| element_slots) {
            let (block_part, tail) = elem_part.split_at_mut(count * ne * ne);
            elem_part = tail;
            let dofs = &self.elem_dofs[dof_off..dof_off + count * ne];
            direct::element_slots(&col_ptr, &row_idx, dofs, ne, block_part);
            dof_off += count * ne;
        }
        let (coupling_part, diag_part) = rest.split_at_mut(2 * self.couplings.len());
        for (k, &(i, j)) in self.couplings.iter().enumerate() {
            coupling_part[2 * k] = pos(i as usize, j as usize);
            coupling_part[2 * k + 1] = pos(j as usize, i as usize);
        }
        for (i, p) in diag_part.iter_mut().enumerate() {
            *p = pos(i, i);
        }
        self.built = Some(Built {
            col_ptr,
            row_idx,
            sym: std::sync::OnceLock::new(),
            positions,
            element_slots,
        });
        Ok(())
    }

    /// The symbolic CSC structure (after [`Pattern::build`]) as faer's matrix, made on
    /// the first call (a copy of the structure with `usize` row indices).
    pub fn symbolic(&self) -> Option<&SymbolicSparseColMat<usize>> {
        self.built.as_ref().map(|b| {
            b.sym.get_or_init(|| {
                let rows = b.row_idx.iter().map(|&r| r as usize).collect();
                SymbolicSparseColMat::new_checked(self.n, self.n, b.col_ptr.clone(), None, rows)
            })
        })
    }

    /// The CSC structure (after [`Pattern::build`]): column pointers and the rows of
    /// each column, ascending.
    pub fn structure(&self) -> Option<(&[usize], &[u32])> {
        self.built
            .as_ref()
            .map(|b| (b.col_ptr.as_slice(), b.row_idx.as_slice()))
    }

    /// The CSC structure, the pattern given up: for a caller that keeps the matrix
    /// (e.g. in row storage, the structure being symmetric) after the pattern is gone.
    pub fn into_structure(self) -> Option<(Vec<usize>, Vec<u32>)> {
        self.built.map(|b| (b.col_ptr, b.row_idx))
    }

    /// Stored entries of the matrix (after [`Pattern::build`]).
    pub fn nnz(&self) -> usize {
        self.structure().map_or(0, |(_, rows)| rows.len())
    }
}

/// A value slot outside the element slots, fixed before its values are known: one
/// direction of a coupling, or a diagonal entry ([`Assembler::add_at_all`]). Worked out
/// once per pattern, it saves a caller that adds many values the choice between
/// [`Assembler::add_coupling`] and [`Assembler::add_diagonal`] for each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ExtraSlot(u32);

impl ExtraSlot {
    /// The high bit marks a diagonal slot; the rest is the coupling slot or the dof.
    const DIAGONAL: u32 = 1 << 31;

    /// Entry `(i, j)` of coupling `k` or, `transposed`, its `(j, i)`. Panics beyond
    /// 2³⁰ couplings (a pattern that size does not fit the 32-bit slot positions).
    pub fn coupling(k: usize, transposed: bool) -> Self {
        let slot = 2 * k + usize::from(transposed);
        assert!(slot < Self::DIAGONAL as usize, "coupling {k} beyond 2^30");
        ExtraSlot(slot as u32)
    }

    /// The diagonal entry of `dof`. Panics for dofs beyond 2³¹.
    pub fn diagonal(dof: usize) -> Self {
        assert!(dof < Self::DIAGONAL as usize, "dof {dof} beyond 2^31");
        ExtraSlot(Self::DIAGONAL | dof as u32)
    }
}

/// Collects element matrices and vectors, couplings and diagonal terms into the slot
/// arrays of a [`Pattern`], then makes the sparse matrix by values only.
pub struct Assembler<'p> {
    pattern: &'p Pattern,
    /// The slot values: element slots (unless direct), then couplings and diagonal.
    values: Vec<f64>,
    /// Direct assembly: the element matrices summed into the CSC value array.
    direct: Option<direct::Summed>,
    /// Element vector slots (`ne` per element), then one per dof for direct loads.
    vector: Vec<f64>,
    vec_elem_len: usize,
    /// Element matrices were computed (not kept) since the last
    /// [`Self::values_into_if_changed`] wrote the values.
    elements_touched: bool,
    /// The coupling and diagonal slots when [`Self::values_into_if_changed`] last wrote
    /// the values.
    extras_written: Option<Vec<f64>>,
}

impl<'p> Assembler<'p> {
    /// The pattern this assembler fills.
    pub fn pattern(&self) -> &'p Pattern {
        self.pattern
    }

    pub fn new(pattern: &'p Pattern) -> Self {
        let vec_elem_len = pattern.block_slots.iter().map(|s| s.1 * s.2).sum();
        Assembler {
            pattern,
            values: vec![0.0; pattern.value_count()],
            direct: None,
            vector: vec![0.0; vec_elem_len + pattern.n],
            vec_elem_len,
            elements_touched: true,
            extras_written: None,
        }
    }

    /// First slot of the couplings in `values`.
    fn extra_base(&self) -> usize {
        if self.direct.is_some() {
            0
        } else {
            self.pattern.elem_values
        }
    }

    /// Run `kernel(elem, ke, fe)` for every element of the blocks listed (all blocks
    /// carrying a field when `blocks` is `None`), in parallel. `ke` (`ne × ne`,
    /// row-major, zeroed) and `fe` (`ne`, zeroed) are that element's slots; the kernel
    /// overwrites them, so calling twice replaces, not adds.
    pub fn elements<F>(&mut self, mesh: &Mesh, blocks: Option<&[usize]>, kernel: F)
    where
        F: Fn(ElemId, &mut [f64], &mut [f64]) + Sync,
    {
        self.elements_with(mesh, blocks, false, kernel)
    }

    /// As [`Self::elements`]; with `keep_matrix` the element matrix slots are handed to
    /// the kernel as they are (not zeroed), for kernels that reuse the element matrices
    /// of the last call and only compute the vectors: such a kernel leaves them as they
    /// are ([`Self::values_into_if_changed`] counts on it).
    pub fn elements_with<F>(
        &mut self,
        mesh: &Mesh,
        blocks: Option<&[usize]>,
        keep_matrix: bool,
        kernel: F,
    ) where
        F: Fn(ElemId, &mut [f64], &mut [f64]) + Sync,
    {
        self.elements_touched |= !keep_matrix;
        if self.direct.is_some() {
            assert!(!keep_matrix, "a direct assembler keeps no element matrices");
            return self.elements_direct(mesh, blocks, kernel);
        }
        let pattern = self.pattern;
        let mut vec_off = 0;
        for (b, block) in mesh.blocks.iter().enumerate() {
            let (off, ne, count) = pattern.block_slots[b];
            let run = blocks.is_none_or(|l| l.contains(&b));
            if run && count > 0 {
                let mat = &mut self.values[off..off + count * ne * ne];
                let vec = &mut self.vector[vec_off..vec_off + count * ne];
                let first = block.first_elem.0;
                // Fixed-size chunks of elements: the result does not depend on how rayon
                // splits the work because each element writes only its own slot.
                mat.par_chunks_mut(ne * ne)
                    .zip(vec.par_chunks_mut(ne))
                    .enumerate()
                    .with_min_len(256)
                    .for_each(|(k, (ke, fe))| {
                        if !keep_matrix {
                            ke.fill(0.0);
                        }
                        fe.fill(0.0);
                        kernel(ElemId(first + k as u32), ke, fe);
                    });
            }
            vec_off += count * ne;
        }
    }

    /// Zero the coupling and diagonal slots (keeping the element slots), so interface
    /// terms can be assembled again without re-running the element kernels.
    pub fn reset_couplings(&mut self) {
        let start = self.extra_base();
        self.values[start..].fill(0.0);
    }

    /// Add values to coupling `k`: `v_ij` at `(i, j)` and `v_ji` at `(j, i)`.
    pub fn add_coupling(&mut self, k: usize, v_ij: f64, v_ji: f64) {
        let base = self.extra_base() + 2 * k;
        self.values[base] += v_ij;
        self.values[base + 1] += v_ji;
    }

    /// Add `v` to the diagonal entry of `dof`.
    pub fn add_diagonal(&mut self, dof: usize, v: f64) {
        let base = self.extra_base() + 2 * self.pattern.couplings.len();
        self.values[base + dof] += v;
    }

    /// Add `values[k]` at `slots[k]` for every k, in order: each as
    /// [`Self::add_coupling`] with one of its two values, or [`Self::add_diagonal`];
    /// coupling slots count from coupling `first` (where a caller's list of couplings
    /// was registered).
    #[inline]
    pub fn add_at_all(&mut self, slots: &[ExtraSlot], values: &[f64], first: usize) {
        assert_eq!(slots.len(), values.len(), "one value per slot");
        let couplings = self.extra_base() + 2 * first;
        let diagonal = self.extra_base() + 2 * self.pattern.couplings.len();
        for (&slot, &v) in slots.iter().zip(values) {
            let base = if slot.0 & ExtraSlot::DIAGONAL != 0 {
                diagonal
            } else {
                couplings
            };
            self.values[base + (slot.0 & !ExtraSlot::DIAGONAL) as usize] += v;
        }
    }

    /// Add `v` to the right-hand side at `dof`.
    pub fn add_rhs(&mut self, dof: usize, v: f64) {
        self.vector[self.vec_elem_len + dof] += v;
    }

    /// Check every element slot for non-finite values and name the first bad one.
    pub fn check_finite(&self, mesh: &Mesh) -> Result<(), AssemblyError> {
        if let Some(d) = &self.direct {
            return d.check_finite(mesh);
        }
        for (b, block) in mesh.blocks.iter().enumerate() {
            let (off, ne, count) = self.pattern.block_slots[b];
            let vals = &self.values[off..off + count * ne * ne];
            if let Some(p) = vals.iter().position(|v| !v.is_finite()) {
                let k = p / (ne * ne);
                let e = ElemId(block.first_elem.0 + k as u32);
                return Err(AssemblyError::NonFiniteElement {
                    elem: e.0,
                    number: mesh.elem_number(e),
                    row: (p % (ne * ne)) / ne,
                    col: p % ne,
                    value: vals[p],
                });
            }
        }
        Ok(())
    }

    /// The assembled matrix (the slots added into their positions in slot order), with
    /// a structure of its own: the pattern's faer structure when it has been made (a
    /// copy), else one made for the matrix alone and not kept by the pattern, so a
    /// caller that keeps the matrix holds the `usize` structure once, not twice.
    pub fn matrix(&self) -> Result<SparseColMat<usize, f64>, AssemblyError> {
        self.built()?;
        let b = self.pattern.built.as_ref().expect("built");
        let sym = match b.sym.get() {
            Some(sym) => sym.clone(),
            None => {
                let rows = b.row_idx.iter().map(|&r| r as usize).collect();
                let n = self.pattern.n;
                SymbolicSparseColMat::new_checked(n, n, b.col_ptr.clone(), None, rows)
            }
        };
        let mut vals = Vec::new();
        self.values_into(&mut vals)?;
        Ok(SparseColMat::new(sym, vals))
    }

    /// The assembled values in the CSC order of [`Pattern::symbolic`] (the bits of
    /// [`Self::matrix`]) written into `vals`, resized to the entry count: a matrix
    /// without a copy of the structure.
    pub fn values_into(&self, vals: &mut Vec<f64>) -> Result<(), AssemblyError> {
        self.built()?;
        let nnz = self.pattern.nnz();
        vals.clear();
        match &self.direct {
            Some(d) if d.values.len() != nnz => {
                return Err(AssemblyError::Faer("the element values were taken".into()));
            }
            Some(d) => vals.extend_from_slice(&d.values),
            None => vals.resize(nnz, 0.0),
        }
        self.sum_slots(vals)
    }

    /// [`Self::values_into`], unless the values are the bits this method wrote at its
    /// last call: no element matrix computed since (kernels that kept them, see
    /// [`Self::elements_with`]) and the coupling and diagonal slots equal to theirs
    /// then. In that case `vals` is left as it is and the answer is `false`. A linear
    /// time step with a fixed step assembles the same matrix every step; this tells so
    /// by comparing the few slots outside the elements (one per dof and two per
    /// coupling), not the whole matrix.
    pub fn values_into_if_changed(&mut self, vals: &mut Vec<f64>) -> Result<bool, AssemblyError> {
        let base = self.extra_base();
        let extras = &self.values[base..];
        if !self.elements_touched && self.extras_written.as_deref() == Some(extras) {
            return Ok(false);
        }
        self.values_into(vals)?;
        let written = self.extras_written.get_or_insert_with(Vec::new);
        written.clear();
        written.extend_from_slice(&self.values[base..]);
        self.elements_touched = false;
        Ok(true)
    }

    /// The assembled values written into `matrix`, which holds this pattern's structure
    /// (made by [`Self::matrix`] from the same pattern): the values refreshed in place,
    /// with no allocation and no copy of the structure; the same bits as
    /// [`Self::matrix`]. A matrix of another size or entry count is an error.
    pub fn refresh_matrix(
        &self,
        matrix: &mut SparseColMat<usize, f64>,
    ) -> Result<(), AssemblyError> {
        self.built()?;
        let (col_ptr, _) = self.pattern.structure().expect("built");
        let n = self.pattern.n;
        let (have, vals) = matrix.parts_mut();
        if have.nrows() != n || have.ncols() != n || have.col_ptr() != col_ptr {
            return Err(AssemblyError::Faer(format!(
                "the matrix to refresh ({}×{}, {} entries) is not this pattern's ({}×{}, {} entries)",
                have.nrows(),
                have.ncols(),
                vals.len(),
                n,
                n,
                self.pattern.nnz()
            )));
        }
        match &self.direct {
            Some(d) if d.values.len() != vals.len() => {
                return Err(AssemblyError::Faer("the element values were taken".into()));
            }
            Some(d) => vals.copy_from_slice(&d.values),
            None => vals.fill(0.0),
        }
        self.sum_slots(vals)
    }

    /// The slots' positions in the value array.
    fn built(&self) -> Result<&[u32], AssemblyError> {
        match &self.pattern.built {
            // A direct assembler skips the element slots of a pattern that has them.
            Some(b) if self.direct.is_some() => {
                let skip = if b.element_slots {
                    self.pattern.elem_values
                } else {
                    0
                };
                Ok(&b.positions[skip..])
            }
            Some(b) if b.element_slots => Ok(&b.positions),
            Some(_) => Err(AssemblyError::Faer(
                "the pattern was built for direct assembly (Pattern::build_direct)".into(),
            )),
            None => Err(AssemblyError::Faer("Pattern::build was not called".into())),
        }
    }

    /// Adds every slot into its position of the CSC value array `vals`, slot after slot
    /// (after the element sums of a direct assembler).
    fn sum_slots(&self, vals: &mut [f64]) -> Result<(), AssemblyError> {
        let positions = self.built()?;
        for (&p, &v) in positions.iter().zip(&self.values) {
            vals[p as usize] += v;
        }
        Ok(())
    }

    /// The assembled right-hand side: the direct loads, then the element vectors added
    /// in element order.
    pub fn rhs(&self) -> Vec<f64> {
        let mut f = self.vector[self.vec_elem_len..].to_vec();
        for (d, v) in self
            .pattern
            .elem_dofs
            .iter()
            .zip(&self.vector[..self.vec_elem_len])
        {
            if *d != NONE {
                f[*d as usize] += v;
            }
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{BoxSpec, single_box};

    /// Element slots filled with values that depend on the element, the entry and a
    /// round number, so two rounds differ everywhere.
    fn assemble(asm: &mut Assembler<'_>, mesh: &Mesh, round: f64) {
        asm.elements(mesh, None, |e, ke, fe| {
            for (k, v) in ke.iter_mut().enumerate() {
                *v = round + e.0 as f64 * 0.1 + k as f64 * 1e-3;
            }
            fe.fill(round);
        });
    }

    /// Four hexes with one temperature field and one coupling, (0, 17), built.
    fn four_hexes_coupled() -> (Mesh, Pattern) {
        let mesh = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [2, 2, 1], 1));
        let dofs = DofMap::new(&mesh, &[("t", &[0])]).unwrap();
        let mut pattern = Pattern::new(&mesh, &dofs);
        pattern.add_couplings(&[(0, 17)]).unwrap();
        pattern.build().unwrap();
        (mesh, pattern)
    }

    /// A refresh in place gives the bits a new matrix gives, keeps the structure, and
    /// refuses a matrix of another pattern.
    #[test]
    fn refreshed_matrix_equals_a_new_one() {
        let (mesh, pattern) = four_hexes_coupled();
        let mut asm = Assembler::new(&pattern);
        assemble(&mut asm, &mesh, 1.0);
        asm.add_coupling(0, 2.5, -1.5);
        let mut kept = asm.matrix().unwrap();
        assemble(&mut asm, &mesh, 7.0);
        asm.reset_couplings();
        asm.add_coupling(0, 0.25, 3.0);
        asm.add_diagonal(4, 9.0);
        asm.refresh_matrix(&mut kept).unwrap();
        let fresh = asm.matrix().unwrap();
        let bits = |m: &SparseColMat<usize, f64>| -> Vec<u64> {
            m.val().iter().map(|v| v.to_bits()).collect()
        };
        assert_eq!(bits(&kept), bits(&fresh));
        assert_eq!(kept.symbolic().row_idx(), fresh.symbolic().row_idx());
        let other = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [3, 1, 1], 1));
        let other_dofs = DofMap::new(&other, &[("t", &[0])]).unwrap();
        let mut other_pattern = Pattern::new(&other, &other_dofs);
        other_pattern.build().unwrap();
        let mut wrong = Assembler::new(&other_pattern).matrix().unwrap();
        assert!(asm.refresh_matrix(&mut wrong).is_err());
    }

    /// Values unchanged since the last write are told without writing them: element
    /// matrices kept and the same coupling and diagonal slots leave `vals` alone; a
    /// changed diagonal, a changed coupling or recomputed element matrices (even to
    /// the same values) write them again, the bits of [`Assembler::values_into`].
    #[test]
    fn unchanged_values_are_not_written_again() {
        let (mesh, pattern) = four_hexes_coupled();
        let mut asm = Assembler::new(&pattern);
        let step = |asm: &mut Assembler<'_>, keep: bool, diagonal: f64, coupling: f64| {
            if keep {
                asm.elements_with(&mesh, None, true, |_, _, fe| fe.fill(1.0));
            } else {
                assemble(asm, &mesh, 1.0);
            }
            asm.reset_couplings();
            asm.add_coupling(0, coupling, coupling);
            asm.add_diagonal(4, diagonal);
        };
        let fresh = |asm: &Assembler<'_>| {
            let mut v = Vec::new();
            asm.values_into(&mut v).unwrap();
            v
        };
        let marker = vec![f64::NAN; 3];
        let mut vals = Vec::new();
        step(&mut asm, false, 2.0, 0.5);
        assert!(asm.values_into_if_changed(&mut vals).unwrap());
        assert_eq!(vals, fresh(&asm));
        // Kept element matrices, the same extras: not written.
        step(&mut asm, true, 2.0, 0.5);
        vals.clone_from(&marker);
        assert!(!asm.values_into_if_changed(&mut vals).unwrap());
        assert!(vals.iter().all(|v| v.is_nan()) && vals.len() == 3);
        // A diagonal term changed; then a coupling.
        for (diagonal, coupling) in [(2.5, 0.5), (2.5, 0.75)] {
            step(&mut asm, true, diagonal, coupling);
            assert!(asm.values_into_if_changed(&mut vals).unwrap());
            assert_eq!(vals, fresh(&asm));
        }
        // Element matrices computed again, to the same values.
        step(&mut asm, false, 2.5, 0.75);
        vals.clone_from(&marker);
        assert!(asm.values_into_if_changed(&mut vals).unwrap());
        assert_eq!(vals, fresh(&asm));
        assert!(!asm.values_into_if_changed(&mut vals).unwrap());
    }
}
