//! VTK XML unstructured grid (`.vtu`) writer: the mesh's solid blocks with point data,
//! readable by ParaView and meshio.
//!
//! Entry point: [`write_vtu`]. ASCII format (small files stay inspectable; ParaView
//! reads it as fast as it needs for the sizes seam writes in one piece). Cell types by
//! topology: Hex8 12, Tet4 10, Wedge6 13, Pyramid5 14, Quad4 9 (shells too), Tri3 5,
//! Bar2 3; the node orders of Exodus and VTK coincide for these linear cells.

use std::fmt::Write as _;
use std::path::Path;

use crate::mesh::{Mesh, Topology};

fn vtk_type(t: Topology) -> u8 {
    match t {
        Topology::Hex8 => 12,
        Topology::Tet4 => 10,
        Topology::Wedge6 => 13,
        Topology::Pyramid5 => 14,
        Topology::Quad4 | Topology::Shell4 => 9,
        Topology::Tri3 | Topology::Shell3 => 5,
        Topology::Bar2 => 3,
    }
}

/// Write `mesh` with nodal fields `(name, values)` (one value per node; NaN for nodes
/// without a value) to `path`.
pub fn write_vtu(path: &Path, mesh: &Mesh, fields: &[(&str, &[f64])]) -> std::io::Result<()> {
    let cells: usize = mesh.blocks.iter().map(|b| b.len()).sum();
    let mut s = String::with_capacity(64 * mesh.num_nodes() + 64 * cells);
    s.push_str("<?xml version=\"1.0\"?>\n");
    s.push_str("<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n");
    s.push_str("<UnstructuredGrid>\n");
    let _ = writeln!(
        s,
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{cells}\">",
        mesh.num_nodes()
    );
    s.push_str("<PointData>\n");
    for (name, values) in fields {
        let _ = writeln!(
            s,
            "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
        );
        for v in values.iter() {
            let _ = writeln!(s, "{v:e}");
        }
        s.push_str("</DataArray>\n");
    }
    s.push_str("</PointData>\n<Points>\n");
    s.push_str("<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n");
    for p in &mesh.coords {
        let _ = writeln!(s, "{:e} {:e} {:e}", p[0], p[1], p[2]);
    }
    s.push_str("</DataArray>\n</Points>\n<Cells>\n");
    s.push_str("<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for b in &mesh.blocks {
        for k in 0..b.len() {
            let nodes: Vec<String> = b.elem_nodes(k).iter().map(|n| n.0.to_string()).collect();
            s.push_str(&nodes.join(" "));
            s.push('\n');
        }
    }
    s.push_str("</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    let mut off = 0;
    for b in &mesh.blocks {
        for _ in 0..b.len() {
            off += b.topology.node_count();
            let _ = writeln!(s, "{off}");
        }
    }
    s.push_str("</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for b in &mesh.blocks {
        let t = vtk_type(b.topology);
        for _ in 0..b.len() {
            let _ = writeln!(s, "{t}");
        }
    }
    s.push_str("</DataArray>\n</Cells>\n");
    // The block of each cell, so ParaView can threshold by block.
    s.push_str("<CellData>\n<DataArray type=\"Int64\" Name=\"block_id\" format=\"ascii\">\n");
    for b in &mesh.blocks {
        for _ in 0..b.len() {
            let _ = writeln!(s, "{}", b.id);
        }
    }
    s.push_str("</DataArray>\n</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    std::fs::write(path, s)
}
