//! Where an interaction's dense blocks go in the host's sparse pattern: the dof pairs its
//! groups couple, and each block entry's slot, worked out once per search.

use super::{InterfacePoints, Scatter};
use crate::assembly::ExtraSlot;
use crate::fem::MAX_NODES;

/// Calls `f(i, j)` for every pair of distinct values of `items` with i < j (a group's
/// dof positions, each pair once per group it appears in).
fn for_each_pair<'a>(
    items: impl Iterator<Item = &'a u32> + Clone,
    mut f: impl FnMut(usize, usize),
) {
    let mut rest = items;
    while let Some(&i) = rest.next() {
        for &j in rest.clone() {
            if i != j {
                f(i.min(j) as usize, i.max(j) as usize);
            }
        }
    }
}

impl InterfacePoints {
    /// The dof pairs (i < j) the groups couple, for [`Pattern::add_couplings`].
    ///
    /// [`Pattern::add_couplings`]: crate::assembly::Pattern::add_couplings
    pub fn couplings(&self) -> Vec<(usize, usize)> {
        // Each pair (i < j) under row i, rows made by counting, then each short row
        // sorted and freed of repeats: no sort of all pairs at once.
        let rows = self.touched.len();
        let row_of = |g: usize| self.position[self.group_dofs[g]..self.group_dofs[g + 1]].iter();
        let mut start = vec![0usize; rows + 1];
        for g in 0..self.groups() {
            for_each_pair(row_of(g), |i, _| start[i + 1] += 1);
        }
        for i in 0..rows {
            start[i + 1] += start[i];
        }
        let mut partners = vec![0u32; start[rows]];
        let mut next = start.clone();
        for g in 0..self.groups() {
            for_each_pair(row_of(g), |i, j| {
                partners[next[i]] = j as u32;
                next[i] += 1;
            });
        }
        let mut out = Vec::new();
        for i in 0..rows {
            let row = &mut partners[start[i]..start[i + 1]];
            row.sort_unstable();
            let mut last = None;
            for &j in row.iter() {
                if last != Some(j) {
                    out.push((self.touched[i] as usize, self.touched[j as usize] as usize));
                    last = Some(j);
                }
            }
        }
        out
    }

    /// Where every block entry goes in an assembler whose pattern holds `couplings`
    /// (as returned by [`Self::couplings`], registered at `first` onwards): worked out
    /// once, so [`InterfaceSystem::add_scattered`] adds without searching.
    pub fn scatter(&self, couplings: &[(usize, usize)], first: usize) -> Scatter {
        // The couplings are sorted by (i, j): each i's partners j are one run, found
        // through `row[i]..row[i + 1]`.
        let rows = couplings.last().map_or(0, |c| c.0 + 1);
        let mut row = vec![0usize; rows + 1];
        for c in couplings {
            row[c.0 + 1] += 1;
        }
        for i in 0..rows {
            row[i + 1] += row[i];
        }
        let mut slots = Vec::with_capacity(
            self.group_dofs
                .windows(2)
                .map(|w| (w[1] - w[0]).pow(2))
                .sum(),
        );
        let mut order = [0usize; 2 * MAX_NODES];
        for g in 0..self.groups() {
            let dofs = self.group(g);
            let nl = dofs.len();
            let block = slots.len();
            slots.resize(block + nl * nl, ExtraSlot::diagonal(0));
            // The group's entries by ascending dof: the partners of each dof are then
            // met in the order of its run of couplings, which one pass walks through
            // (no search). Entry (a, b) and its transpose (b, a) share one coupling.
            let order = &mut order[..nl];
            for (k, o) in order.iter_mut().enumerate() {
                *o = k;
            }
            order.sort_unstable_by_key(|&k| dofs[k]);
            for (p, &a) in order.iter().enumerate() {
                let lo = dofs[a] as usize;
                slots[block + a * nl + a] = ExtraSlot::diagonal(lo);
                let run = match row.get(lo..lo + 2) {
                    Some(&[start, end]) => &couplings[start..end],
                    _ => &[],
                };
                let mut r = 0;
                for &b in &order[p + 1..] {
                    let hi = dofs[b] as usize;
                    if hi == lo {
                        slots[block + a * nl + b] = ExtraSlot::diagonal(lo);
                        slots[block + b * nl + a] = ExtraSlot::diagonal(lo);
                        continue;
                    }
                    while run[r].1 < hi {
                        r += 1;
                    }
                    assert_eq!(run[r].1, hi, "coupling registered from the same groups");
                    let k = first + row[lo] + r;
                    // (a, b) is (lo, hi), the coupling as registered; (b, a) its transpose.
                    slots[block + a * nl + b] = ExtraSlot::coupling(k, false);
                    slots[block + b * nl + a] = ExtraSlot::coupling(k, true);
                }
            }
        }
        Scatter { slots }
    }
}
