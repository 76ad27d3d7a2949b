//! Block skinning: which sides of the included elements are exterior.
//!
//! The rule (Sierra/SM): a side is exterior if no other *included* element shares it.
//! Sides shared by two included solids are interior; a side against an excluded or dead
//! element is exterior. A shell lying on a solid side (same nodes, "equivalenced")
//! sandwiches it: the solid side and the shell side facing into the solid are dropped,
//! the shell's outer side stays — whichever of the two was defined first.
//!
//! Cost: O(number of sides). Sides are bucketed by their smallest node with a counting
//! sort, and matched inside each bucket (a handful of sides), so no hashing and no
//! global sort is needed; memory is 20 bytes per side.

use crate::mesh::{ElemId, Mesh, Side};

/// One side of an included element, keyed by its other nodes (sorted; `u32::MAX` pads
/// triangles and edges).
#[derive(Clone, Copy)]
struct Entry {
    rest: [u32; 3],
    elem: u32,
    side: u8,
}

/// The exterior sides of the elements for which `included` is true, sorted by
/// (element, side).
pub(crate) fn exterior_sides(mesh: &Mesh, included: &[bool]) -> Vec<Side> {
    let n_nodes = mesh.num_nodes();
    // Pass 1: count sides per smallest node.
    let mut start = vec![0u32; n_nodes + 1];
    for_each_side(mesh, included, |_, _, key| start[key[0] as usize + 1] += 1);
    for i in 0..n_nodes {
        start[i + 1] += start[i];
    }
    let total = start[n_nodes] as usize;
    // Pass 2: place every side in its bucket.
    let mut fill = start.clone();
    let mut entries = vec![
        Entry {
            rest: [0; 3],
            elem: 0,
            side: 0
        };
        total
    ];
    for_each_side(mesh, included, |elem, side, key| {
        let slot = &mut fill[key[0] as usize];
        entries[*slot as usize] = Entry {
            rest: [key[1], key[2], key[3]],
            elem: elem.0,
            side,
        };
        *slot += 1;
    });
    drop(fill);

    let mut exterior = Vec::new();
    let mut group: Vec<Entry> = Vec::with_capacity(8);
    for b in 0..n_nodes {
        let bucket = &mut entries[start[b] as usize..start[b + 1] as usize];
        if bucket.is_empty() {
            continue;
        }
        bucket.sort_unstable_by_key(|e| (e.rest, e.elem, e.side));
        let mut i = 0;
        while i < bucket.len() {
            let mut j = i + 1;
            while j < bucket.len() && bucket[j].rest == bucket[i].rest {
                j += 1;
            }
            group.clear();
            group.extend_from_slice(&bucket[i..j]);
            resolve_group(mesh, &group, &mut exterior);
            i = j;
        }
    }
    exterior.sort_unstable();
    exterior
}

/// Decide which sides of one group of coincident sides are exterior.
fn resolve_group(mesh: &Mesh, group: &[Entry], exterior: &mut Vec<Side>) {
    let side_of = |e: &Entry| Side {
        elem: ElemId(e.elem),
        side: e.side,
    };
    if group.len() == 1 {
        exterior.push(side_of(&group[0]));
        return;
    }
    let is_shell = |e: &Entry| mesh.topology(ElemId(e.elem)).is_shell();
    let solids: Vec<&Entry> = group.iter().filter(|e| !is_shell(e)).collect();
    match solids.len() {
        // Shells only: every shell face stays (a lone shell has two, top and bottom).
        0 => exterior.extend(group.iter().map(side_of)),
        // One solid side covered by shells: the solid side is sandwiched; each shell
        // keeps the side that points the same way as the solid's outward normal.
        1 => {
            let solid: Vec<_> = mesh.side_nodes(side_of(solids[0])).collect();
            for e in group.iter().filter(|e| is_shell(e)) {
                let shell: Vec<_> = mesh.side_nodes(side_of(e)).collect();
                if same_cycle_direction(&solid, &shell) {
                    exterior.push(side_of(e));
                }
            }
        }
        // Two solids share the side: interior, and so is any shell between them.
        _ => {}
    }
}

/// True if `b` is a rotation of `a` (same set, same cyclic direction).
fn same_cycle_direction<T: PartialEq>(a: &[T], b: &[T]) -> bool {
    let n = a.len();
    if n != b.len() || n == 0 {
        return false;
    }
    if n == 2 {
        // A segment's reverse is also a rotation of it: direction means equality.
        return a == b;
    }
    match b.iter().position(|x| *x == a[0]) {
        Some(k) => (0..n).all(|i| a[i] == b[(k + i) % n]),
        None => false,
    }
}

/// Visit every face-side of every included element with its sorted node key.
fn for_each_side(mesh: &Mesh, included: &[bool], mut f: impl FnMut(ElemId, u8, [u32; 4])) {
    for block in &mesh.blocks {
        let t = block.topology;
        let sides = &t.sides()[..t.face_side_count()];
        for (k, elem) in block.elems().enumerate() {
            if !included[elem.index()] {
                continue;
            }
            let nodes = block.elem_nodes(k);
            for (s, local) in sides.iter().enumerate() {
                let mut key = [u32::MAX; 4];
                for (slot, &l) in key.iter_mut().zip(local.iter()) {
                    *slot = nodes[l as usize].0;
                }
                key.sort_unstable();
                f(elem, s as u8 + 1, key);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cycle_direction() {
        assert!(same_cycle_direction(&[1, 2, 3, 4], &[3, 4, 1, 2]));
        assert!(!same_cycle_direction(&[1, 2, 3, 4], &[1, 4, 3, 2]));
        assert!(same_cycle_direction(&[1, 2], &[1, 2]));
        assert!(!same_cycle_direction(&[1, 2], &[2, 1]));
    }
}
