//! Element topologies and their local side numbering, exactly as in Exodus II.
//!
//! Local node numbers and side numbers are 1-based in files and in messages, 0-based
//! in the tables below. A solid's side lists its nodes counter-clockwise seen from
//! outside, so the right-hand normal of the side points out of the element.

use serde::Serialize;

/// Element topology by shape and node count.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum Topology {
    Hex8,
    Tet4,
    Wedge6,
    Pyramid5,
    /// 2-D solid quadrilateral (its sides are edges).
    Quad4,
    /// 2-D solid triangle (its sides are edges).
    Tri3,
    /// Quadrilateral shell: side 1 is the top (right-hand normal), side 2 the bottom.
    Shell4,
    /// Triangular shell: side 1 top, side 2 bottom.
    Shell3,
    /// Two-node beam or truss; it has no faces.
    Bar2,
}

/// The shape of one side of an element.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
pub enum FaceShape {
    Line2,
    Tri3,
    Quad4,
}

impl FaceShape {
    pub fn node_count(self) -> usize {
        match self {
            FaceShape::Line2 => 2,
            FaceShape::Tri3 => 3,
            FaceShape::Quad4 => 4,
        }
    }
}

const HEX8_SIDES: [&[u8]; 6] = [
    &[0, 1, 5, 4],
    &[1, 2, 6, 5],
    &[2, 3, 7, 6],
    &[0, 4, 7, 3],
    &[0, 3, 2, 1],
    &[4, 5, 6, 7],
];
const TET4_SIDES: [&[u8]; 4] = [&[0, 1, 3], &[1, 2, 3], &[0, 3, 2], &[0, 2, 1]];
const WEDGE6_SIDES: [&[u8]; 5] = [
    &[0, 1, 4, 3],
    &[1, 2, 5, 4],
    &[0, 3, 5, 2],
    &[0, 2, 1],
    &[3, 4, 5],
];
const PYRAMID5_SIDES: [&[u8]; 5] = [
    &[0, 1, 4],
    &[1, 2, 4],
    &[2, 3, 4],
    &[0, 4, 3],
    &[0, 3, 2, 1],
];
const QUAD4_SIDES: [&[u8]; 4] = [&[0, 1], &[1, 2], &[2, 3], &[3, 0]];
const TRI3_SIDES: [&[u8]; 3] = [&[0, 1], &[1, 2], &[2, 0]];
const SHELL4_SIDES: [&[u8]; 6] = [
    &[0, 1, 2, 3],
    &[0, 3, 2, 1],
    &[0, 1],
    &[1, 2],
    &[2, 3],
    &[3, 0],
];
const SHELL3_SIDES: [&[u8]; 5] = [&[0, 1, 2], &[0, 2, 1], &[0, 1], &[1, 2], &[2, 0]];

impl Topology {
    pub fn node_count(self) -> usize {
        match self {
            Topology::Hex8 => 8,
            Topology::Tet4 => 4,
            Topology::Wedge6 => 6,
            Topology::Pyramid5 => 5,
            Topology::Quad4 | Topology::Shell4 => 4,
            Topology::Tri3 | Topology::Shell3 => 3,
            Topology::Bar2 => 2,
        }
    }

    /// Spatial dimension of the element itself (3 for solids, 2 for shells and 2-D solids).
    pub fn parametric_dim(self) -> usize {
        match self {
            Topology::Hex8 | Topology::Tet4 | Topology::Wedge6 | Topology::Pyramid5 => 3,
            Topology::Quad4 | Topology::Tri3 | Topology::Shell4 | Topology::Shell3 => 2,
            Topology::Bar2 => 1,
        }
    }

    /// True for elements whose sides bound a region (3-D solids, and 2-D solids in a 2-D mesh).
    pub fn is_solid(self) -> bool {
        !matches!(self, Topology::Shell4 | Topology::Shell3 | Topology::Bar2)
    }

    pub fn is_shell(self) -> bool {
        matches!(self, Topology::Shell4 | Topology::Shell3)
    }

    /// Local node lists of every side, in Exodus side order (side `s` is entry `s - 1`).
    pub fn sides(self) -> &'static [&'static [u8]] {
        match self {
            Topology::Hex8 => &HEX8_SIDES,
            Topology::Tet4 => &TET4_SIDES,
            Topology::Wedge6 => &WEDGE6_SIDES,
            Topology::Pyramid5 => &PYRAMID5_SIDES,
            Topology::Quad4 => &QUAD4_SIDES,
            Topology::Tri3 => &TRI3_SIDES,
            Topology::Shell4 => &SHELL4_SIDES,
            Topology::Shell3 => &SHELL3_SIDES,
            Topology::Bar2 => &[],
        }
    }

    /// Number of sides that are faces of a contact surface: every side of a solid, the
    /// two faces (top, bottom) of a shell, none of a beam.
    pub fn face_side_count(self) -> usize {
        match self {
            Topology::Shell4 | Topology::Shell3 => 2,
            other => other.sides().len(),
        }
    }

    pub fn side_shape(self, side: usize) -> FaceShape {
        match self.sides()[side].len() {
            2 => FaceShape::Line2,
            3 => FaceShape::Tri3,
            _ => FaceShape::Quad4,
        }
    }

    /// Recognise an Exodus `elem_type` attribute or a Gmsh element type name.
    /// Exodus spellings vary (`HEX8`, `HEX`, `hex8`, `HEXAHEDRON`, `SHELL4`, `QUAD4`…);
    /// `dim` resolves QUAD/TRI, which are shells in a 3-D mesh and solids in a 2-D one.
    pub fn from_exodus_name(name: &str, nodes_per_elem: usize, dim: usize) -> Option<Topology> {
        let upper = name.trim().to_ascii_uppercase();
        let stem: String = upper
            .chars()
            .take_while(|c| c.is_ascii_alphabetic())
            .collect();
        let t = match (stem.as_str(), nodes_per_elem) {
            ("HEX" | "HEXAHEDRON", 8) => Topology::Hex8,
            ("TET" | "TETRA" | "TETRAHEDRON", 4) => Topology::Tet4,
            ("WEDGE" | "PRISM", 6) => Topology::Wedge6,
            ("PYRAMID" | "PYRA", 5) => Topology::Pyramid5,
            ("SHELL", 4) => Topology::Shell4,
            ("SHELL", 3) | ("TRISHELL", 3) => Topology::Shell3,
            ("QUAD", 4) if dim == 2 => Topology::Quad4,
            ("QUAD", 4) => Topology::Shell4,
            ("TRI" | "TRIANGLE", 3) if dim == 2 => Topology::Tri3,
            ("TRI" | "TRIANGLE", 3) => Topology::Shell3,
            ("BAR" | "BEAM" | "TRUSS" | "EDGE" | "LINE", 2) => Topology::Bar2,
            _ => return None,
        };
        Some(t)
    }

    /// The name Exodus writers use for this topology.
    pub fn exodus_name(self) -> &'static str {
        match self {
            Topology::Hex8 => "HEX8",
            Topology::Tet4 => "TETRA4",
            Topology::Wedge6 => "WEDGE6",
            Topology::Pyramid5 => "PYRAMID5",
            Topology::Quad4 => "QUAD4",
            Topology::Tri3 => "TRI3",
            Topology::Shell4 => "SHELL4",
            Topology::Shell3 => "SHELL3",
            Topology::Bar2 => "BAR2",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every node of a solid appears in exactly as many sides as the element has faces
    /// meeting at that corner, and every edge is shared by exactly two sides with
    /// opposite orientation: the sides close the element and all point the same way.
    #[test]
    fn solid_sides_close_with_consistent_orientation() {
        for t in [
            Topology::Hex8,
            Topology::Tet4,
            Topology::Wedge6,
            Topology::Pyramid5,
        ] {
            let mut edges = std::collections::HashMap::<(u8, u8), i32>::new();
            for side in t.sides() {
                for k in 0..side.len() {
                    let (a, b) = (side[k], side[(k + 1) % side.len()]);
                    *edges.entry((a, b)).or_default() += 1;
                }
            }
            for (&(a, b), &n) in &edges {
                assert_eq!(n, 1, "{t:?}: directed edge {a}-{b} used {n} times");
                assert_eq!(
                    edges.get(&(b, a)),
                    Some(&1),
                    "{t:?}: edge {a}-{b} has no twin"
                );
            }
        }
    }

    #[test]
    fn names_resolve_by_dimension() {
        assert_eq!(
            Topology::from_exodus_name("HEX8", 8, 3),
            Some(Topology::Hex8)
        );
        assert_eq!(
            Topology::from_exodus_name("hex", 8, 3),
            Some(Topology::Hex8)
        );
        assert_eq!(
            Topology::from_exodus_name("QUAD4", 4, 2),
            Some(Topology::Quad4)
        );
        assert_eq!(
            Topology::from_exodus_name("QUAD4", 4, 3),
            Some(Topology::Shell4)
        );
        assert_eq!(
            Topology::from_exodus_name("TETRA", 4, 3),
            Some(Topology::Tet4)
        );
        assert_eq!(Topology::from_exodus_name("TETRA10", 10, 3), None);
    }
}
