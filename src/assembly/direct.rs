//! Direct assembly ([`Assembler::direct`]): element matrices added into the CSC value
//! array as they are made, instead of kept in slots. Elements are computed in parallel
//! in fixed batches and added serially in element order, entries of an element
//! row-major — the order the slot path sums them in — so the values have the same bits
//! whatever the number of threads, and the same as [`Assembler::new`] would give.

use rayon::prelude::*;

use super::{Assembler, AssemblyError, NONE, Pattern};
use crate::mesh::{ElemId, Mesh};

/// Element-matrix entries made at once (in parallel, with their positions) before they
/// are added: 16 384 Hex8 elements, 8 MB of matrices and 8 MB of positions. Larger
/// batches share out better: on the tied 120:80 boxes (1.12 M Hex8), conduction took
/// 0.84–0.87 s on one thread and 0.65–0.66 s on two with batches of 1 024 elements,
/// 0.73–0.76 s and 0.60–0.61 s with 8 192, 0.73–0.76 s and 0.57 s with 16 384; the
/// one-thread time is that of building the positions serially (0.71–0.74 s).
const BATCH_ENTRIES: usize = 16384 * 64;

/// The element part of a direct assembler's matrix.
pub(super) struct Summed {
    /// The element matrices summed, in the CSC order of the pattern's structure.
    pub(super) values: Vec<f64>,
    /// The first non-finite element entry met: element, local row and column, value.
    bad: Option<(ElemId, usize, usize, f64)>,
    /// Whether every element matrix added was exactly symmetric (bit for bit).
    pub(super) symmetric: bool,
}

impl Summed {
    pub(super) fn check_finite(&self, mesh: &Mesh) -> Result<(), AssemblyError> {
        match self.bad {
            None => Ok(()),
            Some((e, row, col, value)) => Err(AssemblyError::NonFiniteElement {
                elem: e.0,
                number: mesh.elem_number(e),
                row,
                col,
                value,
            }),
        }
    }
}

impl<'p> Assembler<'p> {
    /// An assembler that adds each element matrix into the matrix values as it is made
    /// and keeps none: for a pattern (built by [`Pattern::build_direct`] or
    /// [`Pattern::build`]) whose element part is assembled once — [`Self::elements`]
    /// adds, so run each block once. Couplings, the diagonal and the right-hand side
    /// work as with [`Assembler::new`], and [`Self::matrix`] gives the same bits; so
    /// does [`Self::rhs`] when direct loads ([`Self::add_rhs`]) come before the
    /// elements (element vectors are added into the right-hand side as they are made),
    /// the same to round-off otherwise.
    pub fn direct(pattern: &'p Pattern) -> Result<Self, AssemblyError> {
        let nnz = pattern
            .structure()
            .ok_or_else(|| AssemblyError::Faer("Pattern::build was not called".into()))?
            .1
            .len();
        Ok(Assembler {
            pattern,
            values: vec![0.0; pattern.value_count() - pattern.elem_values],
            direct: Some(Summed {
                values: written_zeros(nnz),
                bad: None,
                symmetric: true,
            }),
            // No element vector slots: element vectors are added into the loads.
            vector: vec![0.0; pattern.n],
            vec_elem_len: 0,
            elements_touched: true,
            extras_written: None,
        })
    }

    /// The element matrices summed so far, in the CSC order of the pattern's structure
    /// (`None` for a slot assembler): the matrix without its coupling and diagonal
    /// slots, without a copy.
    pub fn element_values(&self) -> Option<&[f64]> {
        self.direct.as_ref().map(|d| d.values.as_slice())
    }

    /// The assembled values (those of [`Self::values_into`]) made in the element sums'
    /// own array, which the assembler gives up: a matrix needed once, without a copy.
    /// The assembler makes no matrix afterwards.
    pub fn take_values(&mut self) -> Result<Vec<f64>, AssemblyError> {
        let Some(d) = self.direct.as_mut() else {
            return Err(AssemblyError::Faer(
                "a slot assembler keeps its values".into(),
            ));
        };
        let mut vals = std::mem::take(&mut d.values);
        self.elements_touched = true;
        if vals.is_empty() {
            return Err(AssemblyError::Faer("the element values were taken".into()));
        }
        self.sum_slots(&mut vals)?;
        Ok(vals)
    }

    /// Whether the matrix this direct assembler makes is exactly symmetric, bit for
    /// bit, by how it was made: every element matrix added was, and every coupling got
    /// the same value in its two directions. Entries `(i, j)` and `(j, i)` then receive
    /// the same terms in the same order (the element sums in element order, the slots
    /// in slot order), so no comparison of the matrix itself is needed. False for a
    /// slot assembler (it does not keep the answer).
    pub fn exactly_symmetric(&self) -> bool {
        let Some(d) = &self.direct else {
            return false;
        };
        let couplings = 2 * self.pattern.couplings.len();
        d.symmetric
            && self.values[..couplings]
                .chunks_exact(2)
                .all(|v| v[0].to_bits() == v[1].to_bits())
    }

    /// [`Self::elements`] of a direct assembler.
    pub(super) fn elements_direct<F>(&mut self, mesh: &Mesh, blocks: Option<&[usize]>, kernel: F)
    where
        F: Fn(ElemId, &mut [f64], &mut [f64]) + Sync,
    {
        let pattern = self.pattern;
        let (col_ptr, row_idx) = pattern
            .structure()
            .expect("a direct assembler's pattern is built");
        let summed = self.direct.as_mut().expect("a direct assembler");
        let (mut vec_off, mut buf, mut fbuf, mut at) = (0, Vec::new(), Vec::new(), Vec::new());
        for (b, block) in mesh.blocks.iter().enumerate() {
            let (_, ne, count) = pattern.block_slots[b];
            let run = blocks.is_none_or(|l| l.contains(&b));
            if run && count > 0 {
                let first = block.first_elem.0;
                let rhs = &mut self.vector;
                let dofs = &pattern.elem_dofs[vec_off..vec_off + count * ne];
                let batch = (BATCH_ENTRIES / (ne * ne)).max(1);
                buf.resize(batch * ne * ne, 0.0);
                fbuf.resize(batch * ne, 0.0);
                at.resize(batch * ne * ne, usize::MAX);
                for start in (0..count).step_by(batch) {
                    let m = batch.min(count - start);
                    // The element matrices and where their entries go, in parallel; the
                    // additions below, in element order, so the sums do not depend on
                    // the thread count.
                    buf[..m * ne * ne]
                        .par_chunks_mut(ne * ne)
                        .zip(fbuf[..m * ne].par_chunks_mut(ne))
                        .zip(at[..m * ne * ne].par_chunks_mut(ne * ne))
                        .enumerate()
                        .with_min_len(256)
                        .for_each(|(k, ((ke, fe), at))| {
                            ke.fill(0.0);
                            fe.fill(0.0);
                            let e = start + k;
                            kernel(ElemId(first + e as u32), ke, fe);
                            positions(col_ptr, row_idx, &dofs[e * ne..(e + 1) * ne], at);
                        });
                    for (k, ke) in buf[..m * ne * ne].chunks_exact(ne * ne).enumerate() {
                        let e = start + k;
                        if summed.bad.is_none()
                            && let Some(p) = ke.iter().position(|v| !v.is_finite())
                        {
                            summed.bad = Some((ElemId(first + e as u32), p / ne, p % ne, ke[p]));
                        }
                        if summed.symmetric {
                            summed.symmetric = (0..ne).all(|a| {
                                (a + 1..ne)
                                    .all(|b| ke[a * ne + b].to_bits() == ke[b * ne + a].to_bits())
                            });
                        }
                        let at = &at[k * ne * ne..(k + 1) * ne * ne];
                        for (&p, &v) in at.iter().zip(ke) {
                            if p != usize::MAX {
                                summed.values[p] += v;
                            }
                        }
                        let fe = &fbuf[k * ne..(k + 1) * ne];
                        for (&d, &v) in dofs[e * ne..(e + 1) * ne].iter().zip(fe) {
                            if d != NONE {
                                rhs[d as usize] += v;
                            }
                        }
                    }
                }
            }
            vec_off += count * ne;
        }
    }
}

/// `n` zeros, written: an array that is read before it is written (sums `+=` into
/// it) gets each page once, as a write. `vec![0.0; n]` takes zeroed pages from the
/// system untouched, and the first `+=` on each then faults twice — a read that maps
/// the shared zero page, then a write that copies it (0.25 GB of matrix values at
/// 1.16 M unknowns: 62 000 pages).
pub(crate) fn written_zeros(n: usize) -> Vec<f64> {
    let mut v = Vec::with_capacity(n);
    v.resize(n, 0.0);
    v
}

/// The slot of every entry of a block's element matrices (`ne` dofs each, `dofs` in
/// element order) in the CSC structure, into `slots`: each column's rows read once for
/// all the element's dofs (the counting search of [`positions`]), not one binary search
/// per entry.
pub(super) fn element_slots(
    col_ptr: &[usize],
    row_idx: &[u32],
    dofs: &[u32],
    ne: usize,
    slots: &mut [u32],
) {
    slots
        .par_chunks_mut((ne * ne).max(1))
        .zip(dofs.par_chunks(ne.max(1)))
        .with_min_len(256)
        .for_each_init(
            || vec![0usize; ne * ne],
            |at, (slots, d)| {
                positions(col_ptr, row_idx, d, at);
                for (s, &p) in slots.iter_mut().zip(at.iter()) {
                    *s = p as u32;
                }
            },
        );
}

/// The CSC position of every entry `(d[a], d[b])` of an element, row-major into `at`
/// (`usize::MAX` where a dof is missing): in column `d[b]`, the count of its rows below
/// `d[a]`. Elements of 4 and 8 dofs count all their rows against a column in one pass
/// ([`positions_of`]); others search each.
fn positions(col_ptr: &[usize], row_idx: &[u32], d: &[u32], at: &mut [usize]) {
    if let Ok(d) = <&[u32; 8]>::try_from(d) {
        return positions_of(col_ptr, row_idx, d, at);
    }
    if let Ok(d) = <&[u32; 4]>::try_from(d) {
        return positions_of(col_ptr, row_idx, d, at);
    }
    let ne = d.len();
    for (b, &c) in d.iter().enumerate() {
        if c == NONE {
            (0..ne).for_each(|a| at[a * ne + b] = usize::MAX);
            continue;
        }
        let (lo, hi) = (col_ptr[c as usize], col_ptr[c as usize + 1]);
        let rows = &row_idx[lo..hi];
        for (a, &r) in d.iter().enumerate() {
            at[a * ne + b] = if r == NONE {
                usize::MAX
            } else {
                lo + lower_bound(rows, r)
            };
        }
    }
}

/// [`positions`] for `N` dofs known at compile time: each column's rows are read once
/// and compared with all `N` dofs, the counts kept in `N` lanes (independent compares
/// the compiler vectorises, where `N` binary searches wait on their loads one after
/// another; a Hex8 column holds 27 rows).
#[inline(always)]
fn positions_of<const N: usize>(
    col_ptr: &[usize],
    row_idx: &[u32],
    d: &[u32; N],
    at: &mut [usize],
) {
    for (b, &c) in d.iter().enumerate() {
        if c == NONE {
            (0..N).for_each(|a| at[a * N + b] = usize::MAX);
            continue;
        }
        let (lo, hi) = (col_ptr[c as usize], col_ptr[c as usize + 1]);
        let mut below = [0u32; N];
        for &x in &row_idx[lo..hi] {
            for a in 0..N {
                below[a] += u32::from(x < d[a]);
            }
        }
        for a in 0..N {
            at[a * N + b] = if d[a] == NONE {
                usize::MAX
            } else {
                lo + below[a] as usize
            };
        }
    }
}

/// The number of entries of the sorted `rows` below `r` (`partition_point(|x| x < r)`),
/// without a branch on the data: the halving steps are conditional moves, so the 64
/// searches of an element overlap instead of each waiting on mispredicted jumps (a
/// column of a hex mesh holds 27 rows; 5 steps).
#[inline(always)]
pub(super) fn lower_bound(rows: &[u32], r: u32) -> usize {
    let (mut base, mut len) = (0usize, rows.len());
    while len > 1 {
        let half = len / 2;
        base = if rows[base + half - 1] < r {
            base + half
        } else {
            base
        };
        len -= half;
    }
    base + usize::from(len == 1 && rows[base] < r)
}

#[cfg(test)]
mod tests {
    use super::super::DofMap;

    /// The branch-free search is `partition_point` on every length up to 40 and every
    /// value between and around the rows.
    #[test]
    fn lower_bound_is_the_partition_point() {
        for len in 0..40usize {
            let rows: Vec<u32> = (0..len as u32).map(|k| 3 * k + 1).collect();
            for r in 0..3 * len as u32 + 3 {
                assert_eq!(
                    lower_bound(&rows, r),
                    rows.partition_point(|&x| x < r),
                    "len {len}, r {r}"
                );
            }
        }
    }
    /// The counting positions of 8 and 4 dofs are the searched ones (3 dofs take the
    /// search), missing dofs included, on columns of different lengths.
    #[test]
    fn counted_positions_are_the_searched_ones() {
        // Column c holds the rows c, c + 1 .. and every third one beyond, so the dofs'
        // rows sit at different depths of each column.
        let n = 40u32;
        let mut col_ptr = vec![0usize];
        let mut rows = Vec::new();
        for c in 0..n {
            rows.extend((0..n).filter(|&r| r.abs_diff(c) < 2 || r % 3 == 0 || r == 37));
            col_ptr.push(rows.len());
        }
        let sets: [&[u32]; 4] = [
            &[0, 1, 3, 6, 9, 12, 37, 2],
            &[3, 2, NONE, 9, 4, 5, 27, 15],
            &[24, 23, 9, 12],
            &[30, NONE, 31],
        ];
        for d in sets {
            let ne = d.len();
            let mut at = vec![0; ne * ne];
            positions(&col_ptr, &rows, d, &mut at);
            for (a, &r) in d.iter().enumerate() {
                for (b, &c) in d.iter().enumerate() {
                    let want = if r == NONE || c == NONE {
                        usize::MAX
                    } else {
                        let (lo, hi) = (col_ptr[c as usize], col_ptr[c as usize + 1]);
                        lo + rows[lo..hi].partition_point(|&x| x < r)
                    };
                    assert_eq!(at[a * ne + b], want, "dofs {d:?}, entry ({a}, {b})");
                }
            }
        }
    }
    use super::*;
    use crate::mesh::generate::{BoxSpec, single_box};
    use faer::sparse::SparseColMat;

    fn bits(m: &SparseColMat<usize, f64>) -> Vec<u64> {
        m.val().iter().map(|v| v.to_bits()).collect()
    }

    /// Element matrices with values that differ per element and entry (not symmetric,
    /// so a transposed position would show), plus couplings and diagonal terms: the
    /// direct assembler gives the slot assembler's matrix and right-hand side bit for
    /// bit, on a pattern built either way, and names the first non-finite entry.
    #[test]
    fn direct_assembly_equals_slot_assembly() {
        let mesh = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [3, 2, 2], 1));
        let dofs = DofMap::new(&mesh, &[("t", &[0])]).unwrap();
        let kernel = |e: ElemId, ke: &mut [f64], fe: &mut [f64]| {
            for (k, v) in ke.iter_mut().enumerate() {
                *v = 0.1 + (e.0 as f64 * 0.37 + k as f64 * 1.3e-3).sin();
            }
            fe.iter_mut()
                .enumerate()
                .for_each(|(k, f)| *f = e.0 as f64 + k as f64);
        };
        let extras = |asm: &mut Assembler<'_>| {
            asm.add_coupling(0, 2.5, -1.5);
            asm.add_coupling(1, 0.125, 7.0);
            asm.add_diagonal(5, 9.0);
        };
        let mut slots = Pattern::new(&mesh, &dofs);
        slots.add_couplings(&[(0, 35), (7, 20)]).unwrap();
        let mut direct = slots.clone();
        slots.build().unwrap();
        direct.build_direct().unwrap();
        let mut reference = Assembler::new(&slots);
        reference.add_rhs(3, 4.0);
        reference.elements(&mesh, None, kernel);
        extras(&mut reference);
        let want = reference.matrix().unwrap();
        for pattern in [&direct, &slots] {
            let mut asm = Assembler::direct(pattern).unwrap();
            asm.add_rhs(3, 4.0);
            asm.elements(&mesh, None, kernel);
            extras(&mut asm);
            let got = asm.matrix().unwrap();
            assert_eq!(got.symbolic().row_idx(), want.symbolic().row_idx());
            assert_eq!(bits(&got), bits(&want));
            let bits_of = |v: Vec<f64>| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits_of(asm.rhs()), bits_of(reference.rhs()));
            asm.check_finite(&mesh).unwrap();
            // Taken values are the matrix's; the assembler makes none afterwards.
            let taken = asm.take_values().unwrap();
            assert_eq!(
                taken.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                bits(&want)
            );
            assert!(asm.matrix().is_err() && asm.take_values().is_err());
        }
        // A slot assembler cannot use a pattern built for direct assembly.
        assert!(Assembler::new(&direct).matrix().is_err());
        let mut bad = Assembler::direct(&direct).unwrap();
        bad.elements(&mesh, None, |e, ke, _| {
            if e.0 >= 4 {
                ke[9] = f64::NAN;
            }
        });
        match bad.check_finite(&mesh) {
            Err(AssemblyError::NonFiniteElement { elem, row, col, .. }) => {
                assert_eq!((elem, row, col), (4, 1, 1));
            }
            other => panic!("expected the first non-finite entry, got {other:?}"),
        }
    }
}
