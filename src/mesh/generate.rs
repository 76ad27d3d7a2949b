//! Mesh generators for tests, examples and benchmarks: structured boxes (Hex8 or Tet4),
//! annular cylinder sectors, and stacks of boxes as several blocks — merged into one
//! conforming mesh or kept apart (non-matching parts, as contact needs); in 2-D the
//! same with rectangles ([`rectangles`], Quad4 or Tri3) and annular sectors in the xy
//! plane ([`ring`]).
//!
//! Side sets of a box are numbered by face: `xmin, xmax, ymin, ymax, zmin, zmax`
//! (for a cylinder sector: `inner, outer, theta_start, theta_end, zmin, zmax`); of a
//! rectangle by edge: `xmin, xmax, ymin, ymax` (of a 2-D ring sector: `inner, outer,
//! theta_start, theta_end`).

use std::collections::HashMap;

use super::{ElemId, Mesh, NodeId, Side, SideSet, Topology};

/// Element type of a generated solid.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SolidKind {
    Hex8,
    /// Six tets per hex cell (Kuhn subdivision; conforming across cells).
    Tet4,
}

/// One structured box of a generated mesh.
#[derive(Clone, Debug)]
pub struct BoxSpec {
    pub min: [f64; 3],
    pub max: [f64; 3],
    pub cells: [usize; 3],
    pub kind: SolidKind,
    /// Block id; the block name is left empty so Sierra calls it `block_<id>`.
    pub block_id: i64,
    /// Side-set ids for the six faces (`xmin, xmax, ymin, ymax, zmin, zmax`); 0 = none.
    pub side_sets: [i64; 6],
}

impl BoxSpec {
    pub fn hex(min: [f64; 3], max: [f64; 3], cells: [usize; 3], block_id: i64) -> Self {
        BoxSpec {
            min,
            max,
            cells,
            kind: SolidKind::Hex8,
            block_id,
            side_sets: [0; 6],
        }
    }

    pub fn tet(min: [f64; 3], max: [f64; 3], cells: [usize; 3], block_id: i64) -> Self {
        BoxSpec {
            kind: SolidKind::Tet4,
            ..BoxSpec::hex(min, max, cells, block_id)
        }
    }

    pub fn with_side_sets(mut self, ids: [i64; 6]) -> Self {
        self.side_sets = ids;
        self
    }
}

/// Element type of a generated 2-D mesh.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlaneKind {
    Quad4,
    /// Two triangles per quadrilateral cell, split along the diagonal from its first
    /// corner (conforming across cells).
    Tri3,
}

/// One structured rectangle of a generated 2-D mesh (z = 0).
#[derive(Clone, Debug)]
pub struct RectSpec {
    pub min: [f64; 2],
    pub max: [f64; 2],
    pub cells: [usize; 2],
    pub kind: PlaneKind,
    /// Block id; the block name is left empty so Sierra calls it `block_<id>`.
    pub block_id: i64,
    /// Side-set ids for the four edges (`xmin, xmax, ymin, ymax`); 0 = none.
    pub side_sets: [i64; 4],
}

impl RectSpec {
    pub fn quad(min: [f64; 2], max: [f64; 2], cells: [usize; 2], block_id: i64) -> Self {
        RectSpec {
            min,
            max,
            cells,
            kind: PlaneKind::Quad4,
            block_id,
            side_sets: [0; 4],
        }
    }

    pub fn tri(min: [f64; 2], max: [f64; 2], cells: [usize; 2], block_id: i64) -> Self {
        RectSpec {
            kind: PlaneKind::Tri3,
            ..RectSpec::quad(min, max, cells, block_id)
        }
    }

    pub fn with_side_sets(mut self, ids: [i64; 4]) -> Self {
        self.side_sets = ids;
        self
    }
}

/// Several rectangles as a 2-D mesh, one block each (blocks with equal ids are merged
/// into one block); with `merge`, nodes at the same position are shared.
pub fn rectangles(specs: &[RectSpec], merge: bool) -> Mesh {
    let mut b = Builder::new(2, merge);
    for spec in specs {
        let [nx, ny] = spec.cells;
        let (lo, hi) = (spec.min, spec.max);
        let place =
            move |i: usize, j: usize| [lerp(lo[0], hi[0], i, nx), lerp(lo[1], hi[1], j, ny), 0.0];
        b.add_plane(spec.cells, place, spec.kind, spec.block_id, spec.side_sets);
    }
    b.finish()
}

/// A 2-D annular sector in the xy plane: radii `r_in..r_out`, angles `0..angle_deg`
/// about the origin, `cells = [radial, circumferential]`. A full ring (`angle_deg =
/// 360`) closes up with shared nodes. Side sets `inner, outer, theta_start, theta_end`.
pub fn ring(
    r_in: f64,
    r_out: f64,
    angle_deg: f64,
    cells: [usize; 2],
    kind: PlaneKind,
    block_id: i64,
    side_sets: [i64; 4],
) -> Mesh {
    let mut b = Builder::new(2, true);
    let full = (angle_deg - 360.0).abs() < 1e-9;
    let [nr, nt] = cells;
    let place = |i: usize, j: usize| -> [f64; 3] {
        let r = r_in + (r_out - r_in) * i as f64 / nr as f64;
        let j = if full && j == nt { 0 } else { j };
        let t = (angle_deg * j as f64 / nt as f64).to_radians();
        [r * t.cos(), r * t.sin(), 0.0]
    };
    b.add_plane(cells, place, kind, block_id, side_sets);
    b.finish()
}

/// The unit cube `[0,1]³` as one Hex8 element in block 1.
pub fn unit_hex() -> Mesh {
    boxes(&[BoxSpec::hex([0.0; 3], [1.0; 3], [1, 1, 1], 1)], false)
}

/// A single structured box.
pub fn single_box(spec: BoxSpec) -> Mesh {
    boxes(&[spec], false)
}

/// Several boxes, one block each (blocks with equal ids are merged into one block).
/// With `merge`, nodes at the same position are shared, giving a conforming mesh;
/// without, every box has its own nodes (parts meshed apart).
pub fn boxes(specs: &[BoxSpec], merge: bool) -> Mesh {
    let mut b = Builder::new(3, merge);
    for spec in specs {
        b.add_box(spec);
    }
    b.finish()
}

/// An annular sector: radii `r_in..r_out`, angles `0..angle_deg` about the z axis,
/// heights `z0..z1`, Hex8 cells. `cells = [radial, circumferential, axial]`.
/// A full ring (`angle_deg = 360`) closes up with shared nodes.
pub fn annulus(
    r_in: f64,
    r_out: f64,
    angle_deg: f64,
    z: [f64; 2],
    cells: [usize; 3],
    block_id: i64,
    side_sets: [i64; 6],
) -> Mesh {
    let mut b = Builder::new(3, true);
    let full = (angle_deg - 360.0).abs() < 1e-9;
    let [nr, nt, nz] = cells;
    let place = |i: usize, j: usize, k: usize| -> [f64; 3] {
        let r = r_in + (r_out - r_in) * i as f64 / nr as f64;
        let j = if full && j == nt { 0 } else { j };
        let t = (angle_deg * j as f64 / nt as f64).to_radians();
        let zz = z[0] + (z[1] - z[0]) * k as f64 / nz as f64;
        [r * t.cos(), r * t.sin(), zz]
    };
    b.add_structured(cells, place, SolidKind::Hex8, block_id, side_sets);
    b.finish()
}

/// Incremental construction shared by all generators.
struct Builder {
    mesh: Mesh,
    merge: bool,
    positions: HashMap<[u64; 3], NodeId>,
    /// Side sets as (id, block index, sides with block-local element positions).
    side_sets: Vec<(i64, usize, Vec<Side>)>,
    blocks: Vec<(i64, Topology, Vec<NodeId>)>,
}

impl Builder {
    fn new(dim: usize, merge: bool) -> Self {
        Builder {
            mesh: Mesh {
                dim,
                ..Mesh::default()
            },
            merge,
            positions: HashMap::new(),
            side_sets: Vec::new(),
            blocks: Vec::new(),
        }
    }

    fn node(&mut self, p: [f64; 3]) -> NodeId {
        // Merging compares exact bit patterns after adding 0.0 (which turns -0.0 into
        // +0.0): generated grid points that coincide are computed by the same formula.
        let key = [
            (p[0] + 0.0).to_bits(),
            (p[1] + 0.0).to_bits(),
            (p[2] + 0.0).to_bits(),
        ];
        if self.merge
            && let Some(&n) = self.positions.get(&key)
        {
            return n;
        }
        let n = NodeId(self.mesh.coords.len() as u32);
        self.mesh.coords.push(p);
        self.mesh.node_numbers.push(n.0 as i64 + 1);
        if self.merge {
            self.positions.insert(key, n);
        }
        n
    }

    fn add_box(&mut self, spec: &BoxSpec) {
        let [nx, ny, nz] = spec.cells;
        let (lo, hi) = (spec.min, spec.max);
        let place = move |i: usize, j: usize, k: usize| {
            [
                lerp(lo[0], hi[0], i, nx),
                lerp(lo[1], hi[1], j, ny),
                lerp(lo[2], hi[2], k, nz),
            ]
        };
        self.add_structured(spec.cells, place, spec.kind, spec.block_id, spec.side_sets);
    }

    /// A structured grid of `cells` whose node `(i, j, k)` sits at `place(i, j, k)`.
    fn add_structured(
        &mut self,
        cells: [usize; 3],
        place: impl Fn(usize, usize, usize) -> [f64; 3],
        kind: SolidKind,
        block_id: i64,
        side_sets: [i64; 6],
    ) {
        let [nx, ny, nz] = cells;
        let mut ids = Vec::with_capacity((nx + 1) * (ny + 1) * (nz + 1));
        for k in 0..=nz {
            for j in 0..=ny {
                for i in 0..=nx {
                    ids.push(self.node(place(i, j, k)));
                }
            }
        }
        let at = |i: usize, j: usize, k: usize| ids[i + (nx + 1) * (j + (ny + 1) * k)];
        let block = match self.blocks.iter().position(|b| b.0 == block_id) {
            Some(b) => b,
            None => {
                let topology = match kind {
                    SolidKind::Hex8 => Topology::Hex8,
                    SolidKind::Tet4 => Topology::Tet4,
                };
                self.blocks.push((block_id, topology, Vec::new()));
                self.blocks.len() - 1
            }
        };
        // Element positions are local to the block until `finish` numbers them.
        let mut face_sides: [Vec<(usize, u8)>; 6] = Default::default();
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let c = [
                        at(i, j, k),
                        at(i + 1, j, k),
                        at(i + 1, j + 1, k),
                        at(i, j + 1, k),
                        at(i, j, k + 1),
                        at(i + 1, j, k + 1),
                        at(i + 1, j + 1, k + 1),
                        at(i, j + 1, k + 1),
                    ];
                    let conn = &mut self.blocks[block].2;
                    let on = [
                        i == 0,
                        i == nx - 1,
                        j == 0,
                        j == ny - 1,
                        k == 0,
                        k == nz - 1,
                    ];
                    match kind {
                        SolidKind::Hex8 => {
                            let e = conn.len() / 8;
                            conn.extend_from_slice(&c);
                            // Exodus hex sides facing -x, +x, -y, +y, -z, +z.
                            const HEX_SIDE: [u8; 6] = [4, 2, 1, 3, 5, 6];
                            for f in 0..6 {
                                if on[f] {
                                    face_sides[f].push((e, HEX_SIDE[f]));
                                }
                            }
                        }
                        SolidKind::Tet4 => {
                            for tet in KUHN_TETS {
                                let e = conn.len() / 4;
                                let t = tet.map(|l| c[l]);
                                conn.extend_from_slice(&t);
                                for (f, side) in tet_cell_faces(&tet) {
                                    if on[f] {
                                        face_sides[f].push((e, side));
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        for f in 0..6 {
            if side_sets[f] != 0 {
                let sides = face_sides[f]
                    .iter()
                    .map(|&(e, side)| Side {
                        elem: ElemId(e as u32),
                        side,
                    })
                    .collect();
                // Positions are block-local; `finish` shifts them once blocks are numbered.
                self.side_sets.push((side_sets[f], block, sides));
            }
        }
    }

    /// A structured 2-D grid of `cells` whose node `(i, j)` sits at `place(i, j)`;
    /// Quad4 cells, or each split into two Tri3 along its diagonal 0–2.
    fn add_plane(
        &mut self,
        cells: [usize; 2],
        place: impl Fn(usize, usize) -> [f64; 3],
        kind: PlaneKind,
        block_id: i64,
        side_sets: [i64; 4],
    ) {
        let [nx, ny] = cells;
        let mut ids = Vec::with_capacity((nx + 1) * (ny + 1));
        for j in 0..=ny {
            for i in 0..=nx {
                ids.push(self.node(place(i, j)));
            }
        }
        let at = |i: usize, j: usize| ids[i + (nx + 1) * j];
        let topology = match kind {
            PlaneKind::Quad4 => Topology::Quad4,
            PlaneKind::Tri3 => Topology::Tri3,
        };
        let block = match self.blocks.iter().position(|b| b.0 == block_id) {
            Some(b) => b,
            None => {
                self.blocks.push((block_id, topology, Vec::new()));
                self.blocks.len() - 1
            }
        };
        let mut edge_sides: [Vec<(usize, u8)>; 4] = Default::default();
        for j in 0..ny {
            for i in 0..nx {
                let c = [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)];
                let on = [i == 0, i == nx - 1, j == 0, j == ny - 1];
                let conn = &mut self.blocks[block].2;
                // (element, edge of the cell: xmin, xmax, ymin, ymax, Exodus side).
                let mut sides: Vec<(usize, usize, u8)> = Vec::with_capacity(4);
                match kind {
                    PlaneKind::Quad4 => {
                        let e = conn.len() / 4;
                        conn.extend_from_slice(&c);
                        // Exodus quad sides: 1 (0-1) −y, 2 (1-2) +x, 3 (2-3) +y, 4 (3-0) −x.
                        sides.extend([(e, 0, 4), (e, 1, 2), (e, 2, 1), (e, 3, 3)]);
                    }
                    PlaneKind::Tri3 => {
                        let e = conn.len() / 3;
                        conn.extend_from_slice(&[c[0], c[1], c[2], c[0], c[2], c[3]]);
                        // (0, 1, 2): side 1 −y, side 2 +x; (0, 2, 3): side 2 +y, side 3 −x.
                        sides.extend([(e, 2, 1), (e, 1, 2), (e + 1, 3, 2), (e + 1, 0, 3)]);
                    }
                }
                for (e, edge, side) in sides {
                    if on[edge] {
                        edge_sides[edge].push((e, side));
                    }
                }
            }
        }
        for f in 0..4 {
            if side_sets[f] != 0 {
                let sides = edge_sides[f]
                    .iter()
                    .map(|&(e, side)| Side {
                        elem: ElemId(e as u32),
                        side,
                    })
                    .collect();
                self.side_sets.push((side_sets[f], block, sides));
            }
        }
    }

    fn finish(mut self) -> Mesh {
        let mut first = Vec::with_capacity(self.blocks.len());
        for (id, topology, conn) in std::mem::take(&mut self.blocks) {
            first.push(self.mesh.elem_numbers.len() as u32);
            self.mesh.push_block(id, "", topology, conn, None);
        }
        for (id, block, sides) in self.side_sets {
            let shift = first[block];
            let sides = sides.into_iter().map(|s| Side {
                elem: ElemId(s.elem.0 + shift),
                side: s.side,
            });
            match self.mesh.side_sets.iter_mut().find(|s| s.id == id) {
                Some(set) => set.sides.extend(sides),
                None => self.mesh.side_sets.push(SideSet {
                    id,
                    name: String::new(),
                    sides: sides.collect(),
                }),
            }
        }
        self.mesh
    }
}

fn lerp(a: f64, b: f64, i: usize, n: usize) -> f64 {
    // Exact at both ends, so boxes that share a face produce bit-identical coordinates.
    if i == n {
        b
    } else {
        a + (b - a) * i as f64 / n as f64
    }
}

/// Kuhn subdivision of a hex cell (local corners as in Exodus Hex8) into six tets that
/// all share the diagonal 0–6; positive orientation.
const KUHN_TETS: [[usize; 4]; 6] = [
    [0, 1, 2, 6],
    [0, 2, 3, 6],
    [0, 3, 7, 6],
    [0, 7, 4, 6],
    [0, 4, 5, 6],
    [0, 5, 1, 6],
];

/// Corners of the six faces of a hex cell, in the order `-x, +x, -y, +y, -z, +z`.
const CELL_FACES: [[usize; 4]; 6] = [
    [0, 3, 7, 4],
    [1, 2, 6, 5],
    [0, 1, 5, 4],
    [3, 2, 6, 7],
    [0, 1, 2, 3],
    [4, 5, 6, 7],
];

/// The sides of a Kuhn tet that lie on faces of its hex cell: (cell face, Exodus tet side).
fn tet_cell_faces(tet: &[usize; 4]) -> impl Iterator<Item = (usize, u8)> + '_ {
    Topology::Tet4
        .sides()
        .iter()
        .enumerate()
        .filter_map(move |(s, side)| {
            let corners = side.iter().map(|&l| tet[l as usize]);
            let face = CELL_FACES
                .iter()
                .position(|f| corners.clone().all(|c| f.contains(&c)))?;
            Some((face, s as u8 + 1))
        })
}

/// Two meshes side by side in one, each keeping its own nodes (parts meshed apart):
/// `b`'s nodes, elements, blocks and side sets follow `a`'s, with node and element
/// numbers continued after `a`'s largest.
pub fn disjoint_union(a: &Mesh, b: &Mesh) -> Mesh {
    let mut m = a.clone();
    let shift = m.coords.len() as u32;
    let eshift = m.num_elems() as u32;
    m.coords.extend_from_slice(&b.coords);
    let nmax = m.node_numbers.iter().copied().max().unwrap_or(0);
    m.node_numbers
        .extend(b.node_numbers.iter().map(|n| n + nmax));
    let emax = m.elem_numbers.iter().copied().max().unwrap_or(0);
    for blk in &b.blocks {
        let conn = blk
            .connectivity
            .iter()
            .map(|n| NodeId(n.0 + shift))
            .collect();
        let numbers = blk.elems().map(|e| b.elem_number(e) + emax).collect();
        m.push_block(blk.id, blk.name.clone(), blk.topology, conn, Some(numbers));
        if let Some(last) = m.blocks.last_mut() {
            last.thickness = blk.thickness;
        }
    }
    for ss in &b.side_sets {
        let mut ss = ss.clone();
        for s in &mut ss.sides {
            s.elem = ElemId(s.elem.0 + eshift);
        }
        m.side_sets.push(ss);
    }
    for ns in &b.node_sets {
        let mut ns = ns.clone();
        for n in &mut ns.nodes {
            *n = NodeId(n.0 + shift);
        }
        m.node_sets.push(ns);
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit outward normal of a 2-D side: its direction turned clockwise by 90°.
    fn outward(m: &Mesh, side: Side) -> [f64; 2] {
        let n: Vec<[f64; 3]> = m.side_nodes(side).map(|n| m.coords[n.index()]).collect();
        let (dx, dy) = (n[1][0] - n[0][0], n[1][1] - n[0][1]);
        let l = dx.hypot(dy);
        [dy / l, -dx / l]
    }

    /// Rectangles of Quad4 and Tri3: valid (counter-clockwise) elements, every edge of a
    /// side set on its edge of the rectangle with the outward normal, the whole edge
    /// covered (lengths sum to the side), and the element count of the kind.
    #[test]
    fn rectangles_are_valid_with_their_edge_sets() {
        for (kind, per_cell) in [(PlaneKind::Quad4, 1), (PlaneKind::Tri3, 2)] {
            let m = rectangles(
                &[RectSpec {
                    kind,
                    ..RectSpec::quad([1.0, 2.0], [3.0, 3.5], [4, 3], 7)
                }
                .with_side_sets([1, 2, 3, 4])],
                false,
            );
            m.validate().unwrap();
            assert_eq!((m.dim, m.num_elems()), (2, 12 * per_cell));
            let expect = [
                (1, [-1.0, 0.0], 1.5),
                (2, [1.0, 0.0], 1.5),
                (3, [0.0, -1.0], 2.0),
                (4, [0.0, 1.0], 2.0),
            ];
            for (id, normal, length) in expect {
                let set = m.side_sets.iter().find(|s| s.id == id).unwrap();
                let mut total = 0.0;
                for &side in &set.sides {
                    let n = outward(&m, side);
                    assert!((n[0] - normal[0]).abs() < 1e-12 && (n[1] - normal[1]).abs() < 1e-12);
                    let x: Vec<[f64; 3]> =
                        m.side_nodes(side).map(|n| m.coords[n.index()]).collect();
                    total += (x[1][0] - x[0][0]).hypot(x[1][1] - x[0][1]);
                }
                assert!((total - length).abs() < 1e-12, "{kind:?} set {id}: {total}");
            }
        }
    }

    /// A full 2-D ring closes (no node twice at θ = 0); a sector's edge sets face out.
    #[test]
    fn rings_close_and_face_out() {
        let full = ring(1.0, 2.0, 360.0, [2, 8], PlaneKind::Quad4, 1, [1, 2, 0, 0]);
        full.validate().unwrap();
        assert_eq!(full.num_nodes(), 3 * 8);
        let sector = ring(1.0, 2.0, 90.0, [2, 4], PlaneKind::Tri3, 1, [1, 2, 3, 4]);
        sector.validate().unwrap();
        for (id, outward_radially) in [(1, -1.0), (2, 1.0)] {
            let set = sector.side_sets.iter().find(|s| s.id == id).unwrap();
            for &side in &set.sides {
                let c: Vec<[f64; 3]> = sector
                    .side_nodes(side)
                    .map(|n| sector.coords[n.index()])
                    .collect();
                let mid = [0.5 * (c[0][0] + c[1][0]), 0.5 * (c[0][1] + c[1][1])];
                let n = outward(&sector, side);
                assert!(outward_radially * (n[0] * mid[0] + n[1] * mid[1]) > 0.0);
            }
        }
    }
}
