//! Mesh validation: the checks a mesh must pass before contact surfaces are built on it.
//!
//! Entry point: [`Mesh::validate`]. It checks, in one pass over each array and without
//! allocating per element: array lengths agree; coordinates are finite; node numbers,
//! element numbers and block / side-set / node-set ids are unique; connectivity, side-set
//! and node-set entries point at existing nodes, elements and sides; solid elements are
//! neither inverted nor degenerate.
//!
//! Conventions: element orientation follows Exodus II (see [`super::topology`]). A solid
//! is checked by its corner Jacobians — at each corner, the determinant of the three edge
//! vectors to its neighbours, ordered so that it is positive for a correctly ordered
//! element (for a tet this is six times its volume; for a pyramid the four base corners
//! are checked; 2-D quads and triangles use the signed area). Messages name the block by
//! its Sierra name, the element by its user-visible number, the 1-based local node, and
//! say how to fix it. Up to [`MAX_REPORTED`] problems are collected into one error.

use super::{Mesh, NodeId, Topology};

/// How many problems one validation error lists before summarising the rest.
pub const MAX_REPORTED: usize = 10;

/// A corner Jacobian with `|det| <= DEGENERATE_REL * h^3` (`h` the element's largest
/// bounding-box extent; `h^2` in 2-D) counts as zero. Coordinates carry ~1e-16 relative
/// round-off, a triple product of differences ~1e-15; 1e-10 leaves a wide margin above
/// that noise and only flags elements that are collapsed for practical purposes.
const DEGENERATE_REL: f64 = 1e-10;

/// One problem found in a mesh, or several.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ValidationError {
    #[error(
        "the mesh arrays disagree: {what}\n  help: this is a bug in the reader or generator that built the mesh"
    )]
    Inconsistent { what: String },
    #[error(
        "node {number} has a non-finite coordinate {coord:?}\n  help: fix the mesh generator's input; NaN or infinite coordinates cannot be meshed"
    )]
    NonFiniteCoordinate { number: i64, coord: [f64; 3] },
    #[error(
        "node number {number} is used by more than one node (positions {first} and {second}, 1-based)\n  help: renumber the nodes (e.g. with SEACAS `ejoin`/`grepos` or by re-exporting) so that every node number is unique"
    )]
    DuplicateNodeNumber {
        number: i64,
        first: usize,
        second: usize,
    },
    #[error(
        "element number {number} is used by more than one element (positions {first} and {second}, 1-based)\n  help: renumber the elements so that every element number is unique"
    )]
    DuplicateElemNumber {
        number: i64,
        first: usize,
        second: usize,
    },
    #[error(
        "{kind} id {id} is used twice\n  help: give every {kind} a distinct id in the mesh generator"
    )]
    DuplicateId { kind: &'static str, id: i64 },
    #[error(
        "element {elem} in {block}: local node {local} refers to node index {index}, but the mesh has {num_nodes} nodes\n  help: the connectivity is corrupt; regenerate or re-export the mesh"
    )]
    DanglingNode {
        block: String,
        elem: i64,
        local: usize,
        index: usize,
        num_nodes: usize,
    },
    #[error(
        "side set {side_set}, entry {entry}: element index {index} does not exist (the mesh has {num_elems} elements)\n  help: the side set is corrupt; regenerate it"
    )]
    SideSetElement {
        side_set: String,
        entry: usize,
        index: usize,
        num_elems: usize,
    },
    #[error(
        "side set {side_set}, entry {entry}: element {elem} in {block} is a {topology:?}, which has {max} sides, but the entry names side {side}\n  help: side numbers follow Exodus II (1-based); regenerate the side set"
    )]
    SideSetSide {
        side_set: String,
        entry: usize,
        elem: i64,
        block: String,
        topology: Topology,
        side: u8,
        max: usize,
    },
    #[error(
        "node set {node_set}, entry {entry}: node index {index} does not exist (the mesh has {num_nodes} nodes)\n  help: the node set is corrupt; regenerate it"
    )]
    NodeSetNode {
        node_set: String,
        entry: usize,
        index: usize,
        num_nodes: usize,
    },
    #[error(
        "element {elem} in {block} is inverted (corner Jacobian {det:.4e} at local node {local}): {cause}\n  help: {help}"
    )]
    Inverted {
        block: String,
        elem: i64,
        local: usize,
        det: f64,
        cause: &'static str,
        help: &'static str,
    },
    #[error(
        "element {elem} in {block} is degenerate (corner Jacobian {det:.4e} at local node {local}, element size {size:.4e}): nodes coincide or a face is collapsed\n  help: remesh the region around element {elem}; collapsed elements have no volume to integrate"
    )]
    Degenerate {
        block: String,
        elem: i64,
        local: usize,
        det: f64,
        size: f64,
    },
    #[error("{} problems in the mesh{}:\n{}", .total, if *.total > .problems.len() { format!(" (first {} shown)", .problems.len()) } else { String::new() }, list(.problems))]
    Several {
        problems: Vec<ValidationError>,
        total: usize,
    },
}

fn list(problems: &[ValidationError]) -> String {
    problems
        .iter()
        .map(|p| format!("  - {}", p.to_string().replace('\n', "\n    ")))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Collects problems up to [`MAX_REPORTED`] and counts the rest.
#[derive(Default)]
struct Problems {
    list: Vec<ValidationError>,
    total: usize,
}

impl Problems {
    fn push(&mut self, p: ValidationError) {
        self.total += 1;
        if self.list.len() < MAX_REPORTED {
            self.list.push(p);
        }
    }

    fn full(&self) -> bool {
        self.list.len() >= MAX_REPORTED
    }

    fn finish(mut self) -> Result<(), ValidationError> {
        match self.list.len() {
            0 => Ok(()),
            1 if self.total == 1 => Err(self.list.pop().expect("one problem")),
            _ => Err(ValidationError::Several {
                problems: self.list,
                total: self.total,
            }),
        }
    }
}

impl Mesh {
    /// Check the mesh; see the module docs for what is checked.
    pub fn validate(&self) -> Result<(), ValidationError> {
        let mut p = Problems::default();
        if !self.check_lengths(&mut p) {
            // Indexing below relies on consistent lengths.
            return p.finish();
        }
        for (k, c) in self.coords.iter().enumerate() {
            if !c.iter().all(|x| x.is_finite()) {
                p.push(ValidationError::NonFiniteCoordinate {
                    number: self.node_numbers[k],
                    coord: *c,
                });
                if p.full() {
                    break;
                }
            }
        }
        if let Some((number, first, second)) = first_duplicate(&self.node_numbers) {
            p.push(ValidationError::DuplicateNodeNumber {
                number,
                first,
                second,
            });
        }
        if let Some((number, first, second)) = first_duplicate(&self.elem_numbers) {
            p.push(ValidationError::DuplicateElemNumber {
                number,
                first,
                second,
            });
        }
        for (kind, list) in [
            (
                "block",
                self.blocks.iter().map(|b| b.id).collect::<Vec<_>>(),
            ),
            ("side set", self.side_sets.iter().map(|s| s.id).collect()),
            ("node set", self.node_sets.iter().map(|s| s.id).collect()),
        ] {
            if let Some((id, _, _)) = first_duplicate(&list) {
                p.push(ValidationError::DuplicateId { kind, id });
            }
        }
        self.check_sets(&mut p);
        self.check_elements(&mut p);
        p.finish()
    }

    fn check_lengths(&self, p: &mut Problems) -> bool {
        let mut ok = true;
        let mut bad = |what: String| {
            p.push(ValidationError::Inconsistent { what });
            ok = false;
        };
        if self.node_numbers.len() != self.coords.len() {
            bad(format!(
                "{} node numbers for {} nodes",
                self.node_numbers.len(),
                self.coords.len()
            ));
        }
        let mut next = 0usize;
        for b in &self.blocks {
            let n = b.topology.node_count();
            if b.connectivity.len() % n != 0 {
                bad(format!(
                    "{}: {} connectivity entries is not a multiple of {n}",
                    b.sierra_name(),
                    b.connectivity.len()
                ));
            }
            if b.first_elem.index() != next {
                bad(format!(
                    "{} starts at element index {}, expected {next}",
                    b.sierra_name(),
                    b.first_elem.index()
                ));
            }
            next = b.first_elem.index() + b.len();
        }
        if next != self.elem_numbers.len() {
            bad(format!(
                "the blocks hold {next} elements but there are {} element numbers",
                self.elem_numbers.len()
            ));
        }
        ok
    }

    fn check_sets(&self, p: &mut Problems) {
        let num_elems = self.num_elems();
        for ss in &self.side_sets {
            for (k, s) in ss.sides.iter().enumerate() {
                if s.elem.index() >= num_elems {
                    p.push(ValidationError::SideSetElement {
                        side_set: ss.sierra_name(),
                        entry: k + 1,
                        index: s.elem.index(),
                        num_elems,
                    });
                    continue;
                }
                let block = &self.blocks[self.block_of(s.elem)];
                let max = block.topology.sides().len();
                if s.side == 0 || s.side as usize > max {
                    p.push(ValidationError::SideSetSide {
                        side_set: ss.sierra_name(),
                        entry: k + 1,
                        elem: self.elem_numbers[s.elem.index()],
                        block: block.sierra_name(),
                        topology: block.topology,
                        side: s.side,
                        max,
                    });
                }
            }
        }
        let num_nodes = self.num_nodes();
        for ns in &self.node_sets {
            for (k, n) in ns.nodes.iter().enumerate() {
                if n.index() >= num_nodes {
                    p.push(ValidationError::NodeSetNode {
                        node_set: ns.sierra_name(),
                        entry: k + 1,
                        index: n.index(),
                        num_nodes,
                    });
                }
            }
        }
    }

    fn check_elements(&self, p: &mut Problems) {
        // Most meshes have no bad element: the blocks are scanned on the thread pool
        // first, and only a block with a problem is gone through again in order, to
        // report its first ones.
        for block in &self.blocks {
            use rayon::prelude::*;
            let npe = block.topology.node_count();
            let corners = corner_table(block.topology, self.dim);
            let fault = |nodes: &[NodeId]| self.element_fault(nodes, corners);
            let bad = (block.connectivity.par_chunks_exact(npe))
                .with_min_len(4096)
                .any(|nodes| fault(nodes).is_some());
            if !bad {
                continue;
            }
            for (k, nodes) in block.connectivity.chunks_exact(npe).enumerate() {
                let elem = self.elem_numbers[block.first_elem.index() + k];
                match fault(nodes) {
                    None => {}
                    Some(Fault::Dangling(local)) => p.push(ValidationError::DanglingNode {
                        block: block.sierra_name(),
                        elem,
                        local: local + 1,
                        index: nodes[local].index(),
                        num_nodes: self.num_nodes(),
                    }),
                    Some(Fault::Corner(problem)) => {
                        p.push(problem.into_error(block.sierra_name(), elem))
                    }
                }
            }
        }
    }

    /// What is wrong with the element of `nodes` (its block's `corners`), if anything: a
    /// node past the mesh's, or a corner whose determinant is not positive.
    fn element_fault(&self, nodes: &[NodeId], corners: Option<Corners>) -> Option<Fault> {
        if let Some(local) = nodes.iter().position(|n| n.index() >= self.num_nodes()) {
            return Some(Fault::Dangling(local));
        }
        // No corner table (shells, bars, 2-D elements in a 3-D mesh): nothing to read.
        let corners = corners?;
        let mut x = [[0.0f64; 3]; 8];
        for (xi, n) in x.iter_mut().zip(nodes) {
            *xi = self.coords[n.index()];
        }
        check_corners(&x[..nodes.len()], corners, self.dim).map(Fault::Corner)
    }
}

/// What [`Mesh::element_fault`] finds.
enum Fault {
    /// The element's local node (0-based) is not a node of the mesh.
    Dangling(usize),
    Corner(CornerProblem),
}

/// Corners to check: `(corner, [a, b, c])` — the edge vectors from `corner` to `a`, `b`
/// (and `c` in 3-D) form a positive determinant for a correctly ordered element.
type Corners = &'static [(u8, [u8; 3])];

const HEX8_CORNERS: Corners = &[
    (0, [1, 3, 4]),
    (1, [2, 0, 5]),
    (2, [3, 1, 6]),
    (3, [0, 2, 7]),
    (4, [7, 5, 0]),
    (5, [4, 6, 1]),
    (6, [5, 7, 2]),
    (7, [6, 4, 3]),
];
const TET4_CORNERS: Corners = &[(0, [1, 2, 3])];
const WEDGE6_CORNERS: Corners = &[
    (0, [1, 2, 3]),
    (1, [2, 0, 4]),
    (2, [0, 1, 5]),
    (3, [5, 4, 0]),
    (4, [3, 5, 1]),
    (5, [4, 3, 2]),
];
const PYRAMID5_CORNERS: Corners = &[
    (0, [1, 3, 4]),
    (1, [2, 0, 4]),
    (2, [3, 1, 4]),
    (3, [0, 2, 4]),
];
const QUAD4_CORNERS: Corners = &[
    (0, [1, 3, 0]),
    (1, [2, 0, 0]),
    (2, [3, 1, 0]),
    (3, [0, 2, 0]),
];
const TRI3_CORNERS: Corners = &[(0, [1, 2, 0])];

fn corner_table(t: Topology, dim: usize) -> Option<Corners> {
    match t {
        Topology::Hex8 => Some(HEX8_CORNERS),
        Topology::Tet4 => Some(TET4_CORNERS),
        Topology::Wedge6 => Some(WEDGE6_CORNERS),
        Topology::Pyramid5 => Some(PYRAMID5_CORNERS),
        Topology::Quad4 if dim == 2 => Some(QUAD4_CORNERS),
        Topology::Tri3 if dim == 2 => Some(TRI3_CORNERS),
        _ => None,
    }
}

struct CornerProblem {
    inverted: bool,
    all_negative: bool,
    local: usize,
    det: f64,
    size: f64,
}

impl CornerProblem {
    fn into_error(self, block: String, elem: i64) -> ValidationError {
        if self.inverted {
            let (cause, help) = if self.all_negative {
                (
                    "its node order is mirrored",
                    "reorder its nodes (swap the top and bottom faces, or two nodes of a tet) or regenerate the mesh",
                )
            } else {
                (
                    "its corners have Jacobians of both signs, so the element is tangled or folded",
                    "move the misplaced node or remesh the region; smoothing can untangle it",
                )
            };
            ValidationError::Inverted {
                block,
                elem,
                local: self.local,
                det: self.det,
                cause,
                help,
            }
        } else {
            ValidationError::Degenerate {
                block,
                elem,
                local: self.local,
                det: self.det,
                size: self.size,
            }
        }
    }
}

/// Corner Jacobians of one element; `None` when all are clearly positive.
fn check_corners(x: &[[f64; 3]], corners: Corners, dim: usize) -> Option<CornerProblem> {
    let mut lo = x[0];
    let mut hi = x[0];
    for p in x {
        for d in 0..3 {
            lo[d] = lo[d].min(p[d]);
            hi[d] = hi[d].max(p[d]);
        }
    }
    let h = (0..3).map(|d| hi[d] - lo[d]).fold(0.0, f64::max);
    let tol = DEGENERATE_REL * if dim == 2 { h * h } else { h * h * h };
    let mut worst = (0usize, f64::INFINITY);
    let mut negatives = 0;
    for &(c, [a, b, e]) in corners {
        let o = x[c as usize];
        let u = sub(x[a as usize], o);
        let v = sub(x[b as usize], o);
        let det = if dim == 2 {
            u[0] * v[1] - u[1] * v[0]
        } else {
            let w = sub(x[e as usize], o);
            u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0])
                + u[2] * (v[0] * w[1] - v[1] * w[0])
        };
        if det < -tol {
            negatives += 1;
        }
        if det < worst.1 {
            worst = (c as usize, det);
        }
    }
    if worst.1 > tol {
        return None;
    }
    Some(CornerProblem {
        inverted: negatives > 0,
        all_negative: negatives == corners.len(),
        local: worst.0 + 1,
        det: worst.1,
        size: h,
    })
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// The first repeated value and its two 1-based positions. Already increasing input (the
/// common case: 1..n or a sorted map) is recognised in one pass without allocating.
fn first_duplicate(v: &[i64]) -> Option<(i64, usize, usize)> {
    if v.windows(2).all(|w| w[0] < w[1]) {
        return None;
    }
    let mut sorted: Vec<(i64, usize)> = v.iter().copied().zip(1..).collect();
    sorted.sort_unstable();
    sorted
        .windows(2)
        .find(|w| w[0].0 == w[1].0)
        .map(|w| (w[0].0, w[0].1, w[1].1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{Side, SideSet};

    const UNIT_HEX: [[f64; 3]; 8] = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];

    fn one_element(topology: Topology, coords: &[[f64; 3]], order: &[u32]) -> Mesh {
        let mut m = Mesh {
            dim: 3,
            coords: coords.to_vec(),
            node_numbers: (1..=coords.len() as i64).collect(),
            ..Mesh::default()
        };
        m.push_block(
            2,
            "",
            topology,
            order.iter().map(|&i| NodeId(i)).collect(),
            Some(vec![17]),
        );
        m
    }

    #[test]
    fn unit_hex_passes() {
        let m = one_element(Topology::Hex8, &UNIT_HEX, &[0, 1, 2, 3, 4, 5, 6, 7]);
        assert_eq!(m.validate(), Ok(()));
    }

    #[test]
    fn mirrored_hex_is_inverted_and_named() {
        // Top and bottom faces swapped: every corner Jacobian is -1.
        let m = one_element(Topology::Hex8, &UNIT_HEX, &[4, 5, 6, 7, 0, 1, 2, 3]);
        let err = m.validate().unwrap_err();
        match &err {
            ValidationError::Inverted {
                elem, block, det, ..
            } => {
                assert_eq!(*elem, 17);
                assert_eq!(block, "block_2");
                assert!((det + 1.0).abs() < 1e-12, "det {det}");
            }
            other => panic!("expected Inverted, got {other:?}"),
        }
        let msg = err.to_string();
        assert!(msg.contains("element 17 in block_2 is inverted"), "{msg}");
        assert!(msg.contains("mirrored"), "{msg}");
    }

    #[test]
    fn tangled_hex_is_inverted_with_mixed_signs() {
        // Node 6 pulled through the opposite face: some corners positive, some negative.
        let mut c = UNIT_HEX;
        c[6] = [-0.5, -0.5, -0.5];
        let m = one_element(Topology::Hex8, &c, &[0, 1, 2, 3, 4, 5, 6, 7]);
        let msg = m.validate().unwrap_err().to_string();
        assert!(msg.contains("tangled"), "{msg}");
    }

    #[test]
    fn tets_by_sign_of_volume() {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ];
        assert_eq!(
            one_element(Topology::Tet4, &c, &[0, 1, 2, 3]).validate(),
            Ok(())
        );
        let err = one_element(Topology::Tet4, &c, &[0, 2, 1, 3])
            .validate()
            .unwrap_err();
        assert!(
            matches!(err, ValidationError::Inverted { elem: 17, .. }),
            "{err}"
        );
        // Four coplanar nodes: zero volume.
        let flat = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let err = one_element(Topology::Tet4, &flat, &[0, 1, 2, 3])
            .validate()
            .unwrap_err();
        assert!(
            matches!(err, ValidationError::Degenerate { elem: 17, .. }),
            "{err}"
        );
    }

    #[test]
    fn wedge_and_pyramid_reference_elements_pass() {
        let w = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 0.0, 1.0],
            [0.0, 1.0, 1.0],
        ];
        assert_eq!(
            one_element(Topology::Wedge6, &w, &[0, 1, 2, 3, 4, 5]).validate(),
            Ok(())
        );
        assert!(
            one_element(Topology::Wedge6, &w, &[3, 4, 5, 0, 1, 2])
                .validate()
                .is_err()
        );
        let p = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.5, 0.5, 1.0],
        ];
        assert_eq!(
            one_element(Topology::Pyramid5, &p, &[0, 1, 2, 3, 4]).validate(),
            Ok(())
        );
        assert!(
            one_element(Topology::Pyramid5, &p, &[0, 3, 2, 1, 4])
                .validate()
                .is_err()
        );
    }

    #[test]
    fn quads_in_2d_by_signed_area() {
        let c = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ];
        let mut m = one_element(Topology::Quad4, &c, &[0, 1, 2, 3]);
        m.dim = 2;
        assert_eq!(m.validate(), Ok(()));
        let mut m = one_element(Topology::Quad4, &c, &[0, 3, 2, 1]);
        m.dim = 2;
        assert!(matches!(
            m.validate(),
            Err(ValidationError::Inverted { .. })
        ));
    }

    #[test]
    fn duplicate_block_ids_and_element_numbers() {
        let mut m = one_element(Topology::Hex8, &UNIT_HEX, &[0, 1, 2, 3, 4, 5, 6, 7]);
        m.push_block(
            2,
            "again",
            Topology::Hex8,
            (0..8).map(NodeId).collect(),
            Some(vec![17]),
        );
        let msg = m.validate().unwrap_err().to_string();
        assert!(msg.contains("block id 2 is used twice"), "{msg}");
        assert!(
            msg.contains("element number 17 is used by more than one element"),
            "{msg}"
        );
    }

    #[test]
    fn bad_references_and_duplicates_are_collected() {
        let mut m = one_element(Topology::Hex8, &UNIT_HEX, &[0, 1, 2, 3, 4, 5, 6, 9]);
        m.node_numbers[3] = 1;
        m.side_sets.push(SideSet {
            id: 1,
            name: String::new(),
            sides: vec![
                Side {
                    elem: crate::mesh::ElemId(0),
                    side: 7,
                },
                Side {
                    elem: crate::mesh::ElemId(5),
                    side: 1,
                },
            ],
        });
        let err = m.validate().unwrap_err();
        let ValidationError::Several { problems, total } = &err else {
            panic!("expected several problems, got {err}");
        };
        assert_eq!(*total, 4, "{err}");
        assert_eq!(problems.len(), 4);
        let msg = err.to_string();
        for want in [
            "node number 1 is used by more than one node",
            "local node 8 refers to node index 9",
            "names side 7",
            "element index 5 does not exist",
        ] {
            assert!(msg.contains(want), "missing `{want}` in:\n{msg}");
        }
    }
}
