//! Result writers: Exodus II written by seam and read back by the independent netCDF
//! reader (`mesh::read`, `netcdf-reader`), VTU/PVD files parsed back, PNG plots decoded
//! with the `png` crate. With `SEAM_PYTHON` set to a Python that has meshio, the sample
//! outputs are also checked by `tests/python/check_results.py`.

use std::io::ErrorKind;
use std::path::{Path, PathBuf};

use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{self, Mesh, NodeId, NodeSet, Topology};
use seam::output::exodus::ExodusWriter;

use crate::scratch;

/// A hex box and a tet box meshed apart, with named blocks, side sets and node sets
/// (one of them empty, as the Exodus library writes a "NULL" set).
fn two_part_mesh() -> Mesh {
    let hex = generate::single_box(
        BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.5], [3, 2, 2], 1).with_side_sets([1, 2, 0, 0, 5, 6]),
    );
    let tet = generate::single_box(
        BoxSpec::tet([0.0, 0.0, 0.5], [1.0, 1.0, 1.0], [2, 2, 1], 2)
            .with_side_sets([0, 0, 13, 0, 15, 16]),
    );
    let mut m = generate::disjoint_union(&hex, &tet);
    m.blocks[0].name = "base".into();
    m.blocks[1].name = "lid_with_a_rather_long_name_of_40_chars".into();
    m.side_sets[0].name = "base_xmin".into();
    m.node_sets.push(NodeSet {
        id: 7,
        name: "corner".into(),
        nodes: vec![NodeId(0), NodeId(5), NodeId(m.num_nodes() as u32 - 1)],
    });
    m.node_sets.push(NodeSet {
        id: 9,
        name: "nothing".into(),
        nodes: Vec::new(),
    });
    m
}

/// Values that differ in every bit pattern from node to node and step to step.
fn nodal_values(m: &Mesh, step: usize, var: usize) -> Vec<f64> {
    m.coords
        .iter()
        .map(|p| (p[0] * 3.1 + p[1] * 1.7 - p[2]).sin() * (step as f64 + 1.3) + var as f64 / 3.0)
        .collect()
}

fn element_values(m: &Mesh, step: usize) -> Vec<f64> {
    (0..m.num_elems())
        .map(|e| (e as f64 * 0.37 + step as f64).cos() / 7.0)
        .collect()
}

fn assert_same_mesh(a: &Mesh, b: &Mesh) {
    assert_eq!(a.dim, b.dim);
    assert_eq!(a.coords, b.coords, "coordinates");
    assert_eq!(a.node_numbers, b.node_numbers);
    assert_eq!(a.elem_numbers, b.elem_numbers);
    assert_eq!(a.blocks.len(), b.blocks.len());
    for (x, y) in a.blocks.iter().zip(&b.blocks) {
        assert_eq!(x.id, y.id);
        assert_eq!(x.name, y.name);
        assert_eq!(x.topology, y.topology);
        assert_eq!(x.connectivity, y.connectivity, "block {}", x.id);
        assert_eq!(x.first_elem, y.first_elem);
    }
    assert_eq!(a.side_sets.len(), b.side_sets.len());
    for (x, y) in a.side_sets.iter().zip(&b.side_sets) {
        assert_eq!((x.id, &x.name, &x.sides), (y.id, &y.name, &y.sides));
    }
    assert_eq!(a.node_sets.len(), b.node_sets.len());
    for (x, y) in a.node_sets.iter().zip(&b.node_sets) {
        assert_eq!((x.id, &x.name, &x.nodes), (y.id, &y.name, &y.nodes));
    }
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn output_exodus_round_trip_mesh_times_and_variables() {
    let m = two_part_mesh();
    let dir = scratch("output-exodus");
    let path = dir.path().join("two_parts.exo");
    let times = [0.0, 0.25, 1.0 / 3.0];
    let mut w = ExodusWriter::create(&path, &m, &["temperature", "flux_x"], &["source"]).unwrap();
    for (s, &t) in times.iter().enumerate() {
        let (a, b, e) = (
            nodal_values(&m, s, 0),
            nodal_values(&m, s, 1),
            element_values(&m, s),
        );
        w.write_step(t, &[&a, &b], &[&e]).unwrap();
    }
    w.finish().unwrap();

    let back = mesh::read(&path).unwrap();
    assert_same_mesh(&m, &back);
    assert_eq!(
        bits(&mesh::exodus::read_times(&path).unwrap()),
        bits(&times)
    );
    for s in 0..times.len() {
        for (k, name) in ["temperature", "flux_x"].iter().enumerate() {
            let v = mesh::exodus::read_nodal_variable(&path, name, s).unwrap();
            assert_eq!(bits(&v), bits(&nodal_values(&m, s, k)), "{name} step {s}");
        }
    }
    // Element variables by block, as any Exodus reader sees them.
    let nc = netcdf_reader::NcFile::open(&path).unwrap();
    let tab = nc.read_variable::<i32>("elem_var_tab").unwrap();
    assert_eq!(tab.iter().copied().collect::<Vec<_>>(), vec![1, 1]);
    let all = nc.read_variable::<f64>("vals_elem_var1eb2").unwrap();
    let n2 = m.blocks[1].len();
    assert_eq!(all.shape(), &[times.len(), n2]);
    let all: Vec<f64> = all.iter().copied().collect();
    let first = m.blocks[1].first_elem.index();
    for s in 0..times.len() {
        let want = &element_values(&m, s)[first..first + n2];
        let got = &all[s * n2..(s + 1) * n2];
        assert_eq!(bits(got), bits(want), "source, block 2, step {s}");
    }
}

/// Every step is readable as soon as it is written, and a writer dropped without
/// `finish` (a killed run) leaves the steps so far.
#[test]
fn output_exodus_is_readable_after_every_step() {
    let m = generate::single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [2, 2, 2], 4));
    let dir = scratch("output-exodus");
    let path = dir.path().join("steps.exo");
    let mut w = ExodusWriter::create(&path, &m, &["temperature"], &[]).unwrap();
    assert!(mesh::exodus::read_times(&path).unwrap().is_empty());
    assert_same_mesh(&m, &mesh::read(&path).unwrap());
    for s in 0..4 {
        let t = nodal_values(&m, s, 0);
        w.write_step(10.0 * s as f64, &[&t], &[]).unwrap();
        assert_eq!(mesh::exodus::read_times(&path).unwrap().len(), s + 1);
        let back = mesh::exodus::read_nodal_variable(&path, "temperature", s).unwrap();
        assert_eq!(bits(&back), bits(&t));
    }
    drop(w);
    assert_eq!(
        mesh::exodus::read_times(&path).unwrap(),
        vec![0.0, 10.0, 20.0, 30.0]
    );
}

#[test]
fn output_exodus_refuses_wrong_lengths_and_names() {
    let m = generate::unit_hex();
    let dir = scratch("output-exodus");
    let path = dir.path().join("bad.exo");
    let mut w = ExodusWriter::create(&path, &m, &["temperature"], &["q"]).unwrap();
    let e = w.write_step(0.0, &[&[1.0; 7]], &[&[0.0]]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidInput);
    let msg = e.to_string();
    assert!(
        msg.contains("`temperature`") && msg.contains("7") && msg.contains("expected 8"),
        "{msg}"
    );
    let e = w.write_step(0.0, &[&[1.0; 8]], &[&[0.0, 1.0]]).unwrap_err();
    assert!(
        e.to_string().contains("`q`") && e.to_string().contains("expected 1"),
        "{e}"
    );
    let e = w.write_step(0.0, &[&[1.0; 8]], &[]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidInput);
    // Nothing of the refused steps counts.
    assert!(mesh::exodus::read_times(&path).unwrap().is_empty());
    w.write_step(2.5, &[&[1.0; 8]], &[&[3.0]]).unwrap();
    w.finish().unwrap();

    let e = mesh::exodus::read_nodal_variable(&path, "temprature", 0).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("`temprature`") && msg.contains("`temperature`"),
        "{msg}"
    );
    let e = mesh::exodus::read_nodal_variable(&path, "temperature", 1).unwrap_err();
    assert!(e.to_string().contains("holds 1 step"), "{e}");

    let e = ExodusWriter::create(&path, &m, &["t", "t"], &[]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidInput);
    assert!(
        w_again(&path, &m)
            .write_step(f64::NAN, &[&[1.0; 8]], &[&[3.0]])
            .is_err()
    );
    let mut broken = generate::unit_hex();
    broken.node_sets.push(NodeSet {
        id: 3,
        name: String::new(),
        nodes: vec![NodeId(8)],
    });
    let e = ExodusWriter::create(&path, &broken, &[], &[]).unwrap_err();
    assert!(
        e.to_string().contains("node set 3 refers to node index 8"),
        "{e}"
    );
    let mut big = generate::unit_hex();
    big.blocks[0].id = 1 << 40;
    let e = ExodusWriter::create(&path, &big, &[], &[]).unwrap_err();
    assert!(e.to_string().contains("block id"), "{e}");
}

#[test]
fn output_exodus_global_variables_per_step() {
    let m = generate::unit_hex();
    let dir = scratch("output-exodus");
    let path = dir.path().join("globals.exo");
    let mut w = ExodusWriter::create_with_globals(
        &path,
        &m,
        &["temperature"],
        &[],
        &["heat_in", "heat_out"],
    )
    .unwrap();
    let t = [1.0; 8];
    let e = w.write_step(0.0, &[&t], &[]).unwrap_err();
    assert!(e.to_string().contains("heat_in, heat_out"), "{e}");
    let steps = [[1.5, -1.25], [2.0, -2.0 / 3.0]];
    for (s, g) in steps.iter().enumerate() {
        w.write_step_with_globals(s as f64, &[&t], &[], g).unwrap();
    }
    w.finish().unwrap();
    let nc = netcdf_reader::NcFile::open(&path).unwrap();
    let names = nc.read_variable_as_strings("name_glo_var").unwrap();
    let names: Vec<&str> = names.iter().map(|n| n.trim_end_matches('\0')).collect();
    assert_eq!(names, ["heat_in", "heat_out"]);
    let vals = nc.read_variable::<f64>("vals_glo_var").unwrap();
    assert_eq!(vals.shape(), &[2, 2]);
    let flat: Vec<f64> = vals.iter().copied().collect();
    assert_eq!(bits(&flat), bits(&steps.concat()));
    // The nodal values after the globals in each record are intact.
    let back = mesh::exodus::read_nodal_variable(&path, "temperature", 1).unwrap();
    assert_eq!(back, t);
}

/// A shell block keeps its thickness (`attribN` named `thickness`) through the file.
#[test]
fn output_exodus_round_trip_shell_thickness() {
    let mut m = generate::unit_hex();
    let top: Vec<NodeId> = m.blocks[0].elem_nodes(0)[4..].to_vec();
    m.push_block(20, "skin", Topology::Shell4, top, None);
    m.blocks[1].thickness = Some(0.0125);
    let dir = scratch("output-exodus");
    let path = dir.path().join("shell.exo");
    ExodusWriter::create(&path, &m, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
    let back = mesh::read(&path).unwrap();
    assert_same_mesh(&m, &back);
    assert_eq!(back.blocks[1].thickness, Some(0.0125));
    assert_eq!(back.blocks[0].thickness, None);
}

/// A 2-D mesh of quads and triangles (num_dim 2, no `coordz`) with a shell-free layout.
#[test]
fn output_exodus_round_trip_2d() {
    let mut m = Mesh {
        dim: 2,
        coords: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 0.5, 0.0],
        ],
        node_numbers: vec![10, 20, 30, 40, 50],
        ..Mesh::default()
    };
    m.push_block(3, "quads", Topology::Quad4, ids(&[0, 1, 2, 3]), None);
    m.push_block(8, "", Topology::Tri3, ids(&[1, 4, 2]), None);
    let dir = scratch("output-exodus");
    let path = dir.path().join("flat.exo");
    let mut w = ExodusWriter::create(&path, &m, &["u"], &[]).unwrap();
    w.write_step(1.0, &[&[1.0, 2.0, 3.0, 4.0, f64::NAN]], &[])
        .unwrap();
    w.finish().unwrap();
    assert_same_mesh(&m, &mesh::read(&path).unwrap());
    let u = mesh::exodus::read_nodal_variable(&path, "U", 0).unwrap();
    assert_eq!(&u[..4], &[1.0, 2.0, 3.0, 4.0]);
    assert!(u[4].is_nan());
}

fn w_again(path: &Path, m: &Mesh) -> ExodusWriter {
    ExodusWriter::create(path, m, &["temperature"], &["q"]).unwrap()
}

fn ids(v: &[u32]) -> Vec<NodeId> {
    v.iter().map(|&n| NodeId(n)).collect()
}

// ---------------------------------------------------------------- VTU and PVD

/// The text of the `DataArray` named `name` (or, for `None`, the first one without a
/// name), its `format` and its `type` attribute.
fn data_array<'a>(xml: &'a str, name: Option<&str>) -> (&'a str, &'a str, &'a str) {
    let mut rest = xml;
    while let Some(at) = rest.find("<DataArray ") {
        let tag_end = at + rest[at..].find('>').unwrap();
        let tag = &rest[at..tag_end];
        let body_end = tag_end + rest[tag_end..].find("</DataArray>").unwrap();
        let attr = |key: &str| {
            tag.find(&format!(" {key}=\"")).map(|p| {
                let from = p + key.len() + 3;
                &tag[from..from + tag[from..].find('"').unwrap()]
            })
        };
        if attr("Name") == name {
            return (
                rest[tag_end + 1..body_end].trim(),
                attr("format").unwrap(),
                attr("type").unwrap(),
            );
        }
        rest = &rest[body_end..];
    }
    panic!("no DataArray {name:?}");
}

/// Decode standard base64 (test-side, independent of the writer's encoder).
fn base64_decode(s: &str) -> Vec<u8> {
    let value = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("bad base64 character {c}"),
    };
    let clean: Vec<u8> = s.bytes().filter(|c| !c.is_ascii_whitespace()).collect();
    let mut out = Vec::new();
    for quad in clean.chunks(4) {
        let pad = quad.iter().filter(|&&c| c == b'=').count();
        let mut n = 0u32;
        for &c in quad {
            n = n << 6 | if c == b'=' { 0 } else { u32::from(value(c)) };
        }
        out.extend_from_slice(&n.to_be_bytes()[1..4 - pad]);
    }
    out
}

/// The values of a data array as f64 (Float64, Int64, Int32 or UInt8), either encoding.
fn decode(xml: &str, name: Option<&str>) -> Vec<f64> {
    let (body, format, ty) = data_array(xml, name);
    if format == "ascii" {
        return body
            .split_ascii_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
    }
    assert_eq!(format, "binary");
    let bytes = base64_decode(body);
    let n = u64::from_le_bytes(bytes[..8].try_into().unwrap()) as usize;
    assert_eq!(n, bytes.len() - 8, "byte count header of {name:?}");
    let size = match ty {
        "Float64" | "Int64" => 8,
        "Int32" => 4,
        "UInt8" => 1,
        other => panic!("unexpected type {other}"),
    };
    bytes[8..]
        .chunks(size)
        .map(|c| match ty {
            "Float64" => f64::from_le_bytes(c.try_into().unwrap()),
            "Int64" => i64::from_le_bytes(c.try_into().unwrap()) as f64,
            "Int32" => f64::from(i32::from_le_bytes(c.try_into().unwrap())),
            _ => f64::from(c[0]),
        })
        .collect()
}

/// Cell `k` of a parsed file: its VTK type and nodes.
fn cells(xml: &str) -> Vec<(u8, Vec<u32>)> {
    let conn = decode(xml, Some("connectivity"));
    let offsets = decode(xml, Some("offsets"));
    let types = decode(xml, Some("types"));
    let mut start = 0;
    offsets
        .iter()
        .zip(&types)
        .map(|(&end, &t)| {
            let nodes = conn[start..end as usize]
                .iter()
                .map(|&n| n as u32)
                .collect();
            start = end as usize;
            (t as u8, nodes)
        })
        .collect()
}

#[test]
fn output_vtu_cell_data_follows_element_order_in_both_encodings() {
    use seam::mesh::ElemId;
    use seam::output::vtu::{write_vtu, write_vtu_cells};
    let m = two_part_mesh();
    let tmp = scratch("output-vtu");
    let dir = tmp.path();
    let t = nodal_values(&m, 2, 0);
    let index: Vec<f64> = (0..m.num_elems()).map(|e| e as f64).collect();
    let src = element_values(&m, 1);
    write_vtu_cells(
        &dir.join("cells.vtu"),
        &m,
        &[("temperature", &t)],
        &[("index", &index), ("source", &src)],
    )
    .unwrap();
    write_vtu(&dir.join("points.vtu"), &m, &[("temperature", &t)]).unwrap();
    let binary = std::fs::read_to_string(dir.join("cells.vtu")).unwrap();
    let ascii = std::fs::read_to_string(dir.join("points.vtu")).unwrap();
    for xml in [&binary, &ascii] {
        assert!(xml.contains(&format!(
            "NumberOfPoints=\"{}\" NumberOfCells=\"{}\"",
            m.num_nodes(),
            m.num_elems()
        )));
        let c = cells(xml);
        assert_eq!(c.len(), m.num_elems());
        for (k, (ty, nodes)) in c.iter().enumerate() {
            let want: Vec<u32> = m.elem_nodes(ElemId(k as u32)).iter().map(|n| n.0).collect();
            assert_eq!(nodes, &want, "cell {k}");
            let expect_ty = match m.topology(ElemId(k as u32)) {
                Topology::Hex8 => 12,
                Topology::Tet4 => 10,
                other => panic!("unexpected {other:?}"),
            };
            assert_eq!(*ty, expect_ty, "cell {k}");
        }
        let xyz: Vec<f64> = m.coords.iter().flatten().copied().collect();
        assert_eq!(bits(&decode(xml, None)), bits(&xyz), "points");
        assert_eq!(bits(&decode(xml, Some("temperature"))), bits(&t));
        let blocks = decode(xml, Some("block_id"));
        assert_eq!(blocks[0], 1.0);
        assert_eq!(blocks[m.num_elems() - 1], 2.0);
    }
    assert_eq!(decode(&binary, Some("index")), index);
    assert_eq!(bits(&decode(&binary, Some("source"))), bits(&src));
    // Base64 of computed doubles is shorter than their round-trip decimal text.
    let (b, a) = (
        data_array(&binary, Some("temperature")).0.len(),
        data_array(&ascii, Some("temperature")).0.len(),
    );
    assert!(2 * b < a + a / 4, "temperature: {b} vs {a} bytes");
}

/// A vector cell array keeps its three components per cell (interleaved, as VTK stores
/// them) in both encodings; a polygon grid of its own gets its points, cells (vertex,
/// line, triangle, quad), integer and real cell arrays back; wrong shapes are refused.
#[test]
fn output_vtu_vectors_and_polygon_grids_read_back() {
    use seam::output::vtu::{Array, VtuEncoding, write_vtu_arrays, write_vtu_polygons};
    let m = two_part_mesh();
    let tmp = scratch("output-vtu");
    let dir = tmp.path();
    let t = nodal_values(&m, 0, 0);
    let q: Vec<f64> = (0..3 * m.num_elems())
        .map(|i| (i as f64 * 0.3).sin())
        .collect();
    for (name, enc) in [
        ("vec_a.vtu", VtuEncoding::Ascii),
        ("vec_b.vtu", VtuEncoding::Base64),
    ] {
        write_vtu_arrays(
            &dir.join(name),
            &m,
            &[Array::scalar("temperature", &t)],
            &[Array::vector("heat_flux", &q)],
            enc,
        )
        .unwrap();
        let xml = std::fs::read_to_string(dir.join(name)).unwrap();
        assert!(
            xml.contains("Name=\"heat_flux\" NumberOfComponents=\"3\""),
            "{name}"
        );
        assert_eq!(bits(&decode(&xml, Some("heat_flux"))), bits(&q), "{name}");
        assert_eq!(bits(&decode(&xml, Some("temperature"))), bits(&t), "{name}");
        assert_eq!(cells(&xml).len(), m.num_elems());
    }
    let e = write_vtu_arrays(
        &dir.join("bad.vtu"),
        &m,
        &[],
        &[Array::vector("heat_flux", &q[..3])],
        VtuEncoding::Ascii,
    )
    .unwrap_err();
    assert!(e.to_string().contains("3 per element"), "{e}");

    let points = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.5],
    ];
    let polygons = vec![vec![0, 1, 2, 3], vec![0, 1, 2], vec![2, 3], vec![1]];
    let ids = [7i64, 8, 9, 10];
    let gap = [0.5, -1e-300, f64::NAN, 3.0];
    let path = dir.join("polygons.vtu");
    write_vtu_polygons(
        &path,
        &points,
        &polygons,
        &[Array::scalar("temperature", &[1.0, 2.0, 3.0, 4.0])],
        &[("interaction", &ids)],
        &[Array::scalar("contact_gap", &gap)],
        VtuEncoding::Ascii,
    )
    .unwrap();
    let xml = std::fs::read_to_string(&path).unwrap();
    assert!(xml.contains("NumberOfPoints=\"4\" NumberOfCells=\"4\""));
    assert!(!xml.contains("block_id"), "a grid of its own has no blocks");
    let got = cells(&xml);
    let want: Vec<(u8, Vec<u32>)> = vec![
        (9, vec![0, 1, 2, 3]),
        (5, vec![0, 1, 2]),
        (3, vec![2, 3]),
        (1, vec![1]),
    ];
    assert_eq!(got, want);
    assert_eq!(decode(&xml, Some("interaction")), vec![7.0, 8.0, 9.0, 10.0]);
    assert_eq!(bits(&decode(&xml, Some("contact_gap"))), bits(&gap));
    let xyz: Vec<f64> = points.iter().flatten().copied().collect();
    assert_eq!(decode(&xml, None), xyz);
    for (polys, what) in [
        (vec![vec![0, 1, 2, 3, 0]], "5 points"),
        (vec![vec![0, 1, 9]], "names point 9"),
    ] {
        let e = write_vtu_polygons(&path, &points, &polys, &[], &[], &[], VtuEncoding::Ascii)
            .unwrap_err();
        assert!(e.to_string().contains(what), "{e}");
    }
    let e = write_vtu_polygons(
        &path,
        &points,
        &polygons,
        &[],
        &[("interaction", &ids[..2])],
        &[],
        VtuEncoding::Ascii,
    )
    .unwrap_err();
    assert!(e.to_string().contains("`interaction` has 2 values"), "{e}");
}

#[test]
fn output_vtu_refuses_wrong_lengths() {
    use seam::output::vtu::write_vtu_cells;
    let m = generate::unit_hex();
    let dir = scratch("output-vtu");
    let path = dir.path().join("bad.vtu");
    let e = write_vtu_cells(&path, &m, &[("temperature", &[0.0; 5])], &[]).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidInput);
    assert!(
        e.to_string()
            .contains("`temperature` has 5 values, expected 8"),
        "{e}"
    );
    let e = write_vtu_cells(&path, &m, &[], &[("q", &[0.0; 2])]).unwrap_err();
    assert!(
        e.to_string().contains("`q` has 2 values, expected 1"),
        "{e}"
    );
}

#[test]
fn output_pvd_is_a_complete_series_after_every_add() {
    use seam::output::vtu::{PvdSeries, write_vtu};
    let m = generate::unit_hex();
    let tmp = scratch("output-pvd");
    let dir = tmp.path();
    std::fs::create_dir_all(dir.join("steps")).unwrap();
    let mut series = PvdSeries::new(&dir.join("run.pvd"));
    let times = [0.0, 0.5, 1.25];
    for (k, &time) in times.iter().enumerate() {
        let rel = PathBuf::from(format!("steps/t{k}.vtu"));
        write_vtu(&dir.join(&rel), &m, &[("temperature", &[time; 8])]).unwrap();
        // Alternate relative and absolute paths: both must be listed relative.
        let given = if k % 2 == 0 {
            rel.clone()
        } else {
            dir.join(&rel)
        };
        series.add(time, &given).unwrap();
        let pvd = std::fs::read_to_string(dir.join("run.pvd")).unwrap();
        assert!(pvd.trim_end().ends_with("</VTKFile>"));
        let listed: Vec<(f64, String)> = pvd
            .lines()
            .filter(|l| l.starts_with("<DataSet"))
            .map(|l| {
                let get = |key: &str| {
                    let from = l.find(&format!("{key}=\"")).unwrap() + key.len() + 2;
                    l[from..from + l[from..].find('"').unwrap()].to_string()
                };
                (get("timestep").parse().unwrap(), get("file"))
            })
            .collect();
        assert_eq!(listed.len(), k + 1);
        for (j, (t, f)) in listed.iter().enumerate() {
            assert_eq!(*t, times[j]);
            assert_eq!(f, &format!("steps/t{j}.vtu"));
            assert!(dir.join(f).is_file());
        }
    }
    assert!(series.add(f64::NAN, Path::new("x.vtu")).is_err());
}

// ---------------------------------------------------------------- PNG plots

/// Decode a PNG written by `Plot::write_png` into (width, height, RGB rows).
fn decode_png(path: &Path) -> (usize, usize, Vec<u8>) {
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    assert_eq!(info.bit_depth, png::BitDepth::Eight);
    buf.truncate(info.buffer_size());
    (info.width as usize, info.height as usize, buf)
}

/// Pixels `(x, y)` of colour `c`.
fn pixels_of(w: usize, rgb: &[u8], c: [u8; 3]) -> Vec<(usize, usize)> {
    rgb.chunks(3)
        .enumerate()
        .filter(|(_, p)| *p == c)
        .map(|(i, _)| (i % w, i / w))
        .collect()
}

#[test]
fn output_plot_draws_known_lines_where_they_belong() {
    use seam::output::plot::{Plot, Series, series_colour};
    // No labels, so no legend covers the lines.
    let diagonal = Series {
        label: String::new(),
        points: (0..=10).map(|k| (k as f64, k as f64)).collect(),
    };
    let level = Series {
        label: String::new(),
        points: vec![(0.0, 5.0), (10.0, 5.0)],
    };
    let plot = Plot {
        title: "Two lines (test)".into(),
        x_label: "x".into(),
        y_label: "T [K]".into(),
        log_y: false,
        series: vec![diagonal, level],
    };
    let dir = scratch("output-plot");
    let path = dir.path().join("lines.png");
    plot.write_png(&path).unwrap();
    let (w, h, rgb) = decode_png(&path);
    assert_eq!((w, h), (960, 640));
    assert_ne!(series_colour(0), series_colour(1));

    // The level line: one 2-pixel band of rows spanning the plot area.
    let flat: Vec<_> = pixels_of(w, &rgb, series_colour(1));
    let band_row = {
        let mut rows = std::collections::BTreeMap::<usize, usize>::new();
        for &(_, y) in &flat {
            *rows.entry(y).or_default() += 1;
        }
        *rows.iter().max_by_key(|(_, n)| **n).unwrap().0
    };
    let band: Vec<usize> = flat
        .iter()
        .filter(|(_, y)| y.abs_diff(band_row) <= 1)
        .map(|&(x, _)| x)
        .collect();
    let (x0, x1) = (*band.iter().min().unwrap(), *band.iter().max().unwrap());
    assert!(x1 - x0 > w / 2, "level line spans {x0}..{x1}");

    // The diagonal: over the same columns, its row falls linearly from bottom to top
    // and crosses the level line half way (x = 5 where y = 5).
    let diag: Vec<(usize, usize)> = pixels_of(w, &rgb, series_colour(0))
        .into_iter()
        .filter(|&(x, _)| x >= x0 && x <= x1)
        .collect();
    let row_at = |col: usize| -> Option<f64> {
        let ys: Vec<usize> = diag.iter().filter(|p| p.0 == col).map(|p| p.1).collect();
        (!ys.is_empty()).then(|| ys.iter().sum::<usize>() as f64 / ys.len() as f64)
    };
    let first = row_at(x0 + 2).expect("diagonal at the left end");
    let last = row_at(x1 - 2).expect("diagonal at the right end");
    assert!(
        first > last + (h / 3) as f64,
        "diagonal rows {first} → {last}"
    );
    let slope = (last - first) / ((x1 - 2) - (x0 + 2)) as f64;
    for col in (x0 + 2..x1 - 2).step_by(37) {
        // Away from the crossing, where the level line's pixels cover the diagonal's.
        if col.abs_diff((x0 + x1) / 2) < 6 {
            continue;
        }
        let want = first + slope * (col - x0 - 2) as f64;
        let got = row_at(col).unwrap_or_else(|| panic!("no diagonal pixel in column {col}"));
        assert!(
            (got - want).abs() <= 2.0,
            "column {col}: row {got}, expected {want}"
        );
    }
    let mid = (x0 + x1) as f64 / 2.0;
    let crossing = first + slope * (mid - (x0 + 2) as f64);
    assert!(
        (crossing - band_row as f64).abs() <= 3.0,
        "crossing at {crossing}, level at {band_row}"
    );
}

#[test]
fn output_plot_gives_each_series_its_colour_and_copes_with_awkward_data() {
    use seam::output::plot::{Plot, Series, series_colour};
    let tmp = scratch("output-plot");
    let dir = tmp.path();
    // Five series: constant data, a single point, NaN and infinity inside, negative
    // values on a log axis; every one must show in its own colour.
    let series = vec![
        Series {
            label: "constant".into(),
            points: vec![(0.0, 1.0), (1.0, 1.0), (2.0, 1.0)],
        },
        Series {
            label: "one point".into(),
            points: vec![(1.0, 1e-2)],
        },
        Series {
            label: "gaps".into(),
            points: vec![
                (0.0, 1e-4),
                (0.5, f64::NAN),
                (1.0, 1e-3),
                (1.5, f64::INFINITY),
                (2.0, 1e-1),
            ],
        },
        Series {
            label: "sign changes".into(),
            points: vec![(0.0, 1e-5), (1.0, -1.0), (1.5, 0.0), (2.0, 1e-2)],
        },
        Series {
            label: "residual 95% (°C)".into(),
            points: (0..20)
                .map(|k| (k as f64 / 10.0, 10f64.powi(-k / 3)))
                .collect(),
        },
    ];
    let plot = Plot {
        title: "Residuals".into(),
        x_label: "iteration".into(),
        y_label: "norm".into(),
        log_y: true,
        series,
    };
    let path = dir.join("awkward.png");
    plot.write_png(&path).unwrap();
    let (w, _, rgb) = decode_png(&path);
    for k in 0..5 {
        let n = pixels_of(w, &rgb, series_colour(k)).len();
        // More than the legend swatch (25 × 2 pixels) alone.
        assert!(n > 60, "series {k} has {n} pixels of its colour");
        for j in 0..k {
            assert_ne!(series_colour(j), series_colour(k));
        }
    }
    // Constant data on a linear axis draws a flat line inside the frame.
    let flat = Plot {
        log_y: false,
        series: vec![Series {
            label: String::new(),
            points: vec![(0.0, 300.0), (1.0, 300.0)],
        }],
        ..Plot::default()
    };
    flat.write_png(&dir.join("flat.png")).unwrap();
    let (w, _, rgb) = decode_png(&dir.join("flat.png"));
    let px = pixels_of(w, &rgb, series_colour(0));
    let rows: std::collections::BTreeSet<usize> = px.iter().map(|p| p.1).collect();
    // One band: a 2-pixel stroke whose edges fall inside pixels covers three rows.
    assert!(
        px.len() > 500 && rows.len() <= 3 && rows.last().unwrap() - rows.first().unwrap() <= 2,
        "{} pixels in rows {rows:?}",
        px.len()
    );
}

/// The SVG twin keeps its text as text (title, axis labels with units, legend) and
/// draws each series in its colour; the PNG of the same plot is its picture.
#[test]
fn output_plot_svg_keeps_text_as_text() {
    use seam::output::plot::{Plot, Series, series_colour};
    let tmp = scratch("output-plot");
    let dir = tmp.path();
    let plot = Plot {
        title: "Heat out of side A".into(),
        x_label: "time t (s)".into(),
        y_label: "heat (W)".into(),
        log_y: false,
        series: vec![Series {
            label: "a / b (gap_conductance)".into(),
            points: (0..20).map(|k| (k as f64, 10.0 - 0.5f64.powi(k))).collect(),
        }],
    };
    let path = dir.join("heat.svg");
    plot.write_svg(&path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    for text in [
        "Heat out of side A",
        "time t (s)",
        "heat (W)",
        "a / b (gap_conductance)",
    ] {
        assert!(
            svg.contains(&format!(">\n{text}\n</text>")),
            "no text `{text}`"
        );
    }
    let [r, g, b] = series_colour(0);
    assert!(
        svg.contains(&format!("#{r:02X}{g:02X}{b:02X}")),
        "no series colour"
    );
    let none = Plot::default();
    assert!(none.write_svg(&dir.join("never.svg")).is_err());
}

#[test]
fn output_plot_refuses_what_it_cannot_draw() {
    use seam::output::plot::{Plot, Series};
    let dir = scratch("output-plot");
    let path = dir.path().join("never.png");
    let none = Plot {
        title: "empty".into(),
        ..Plot::default()
    };
    let e = none.write_png(&path).unwrap_err();
    assert_eq!(e.kind(), ErrorKind::InvalidInput);
    assert!(e.to_string().contains("no series"), "{e}");
    let pointless = Plot {
        series: vec![Series {
            label: "T".into(),
            points: vec![],
        }],
        ..Plot::default()
    };
    let e = pointless.write_png(&path).unwrap_err();
    assert!(
        e.to_string().contains("`T`") && e.to_string().contains("no points"),
        "{e}"
    );
    let negative = Plot {
        log_y: true,
        series: vec![Series {
            label: "r".into(),
            points: vec![(0.0, -1.0), (1.0, f64::NAN)],
        }],
        ..Plot::default()
    };
    let e = negative.write_png(&path).unwrap_err();
    assert!(e.to_string().contains("y > 0"), "{e}");
    assert!(!path.exists());
}

// ---------------------------------------------------------------- all formats together

/// Write what a transient `seam run` writes: a `.vtu` per step listed by a `.pvd`, one
/// Exodus file with every step, and a plot.
fn write_sample(dir: &Path, m: &Mesh, steps: usize, poison: bool) {
    use seam::output::plot::{Plot, Series};
    use seam::output::vtu::{PvdSeries, write_vtu_cells};
    std::fs::create_dir_all(dir).unwrap();
    let mut exo = ExodusWriter::create(
        &dir.join("results.exo"),
        m,
        &["temperature", "flux_z"],
        &["heat_source"],
    )
    .unwrap();
    let mut pvd = PvdSeries::new(&dir.join("results.pvd"));
    let mut peak = Vec::new();
    for s in 0..steps {
        let time = 0.5 * s as f64;
        let mut t: Vec<f64> = nodal_values(m, s, 0)
            .iter()
            .map(|v| 300.0 + 10.0 * v)
            .collect();
        if poison && s + 1 == steps {
            t[0] = f64::NAN;
        }
        let q = nodal_values(m, s, 1);
        let src = element_values(m, s);
        let name = format!("results_{s:04}.vtu");
        write_vtu_cells(
            &dir.join(&name),
            m,
            &[("temperature", &t), ("flux_z", &q)],
            &[("heat_source", &src)],
        )
        .unwrap();
        pvd.add(time, Path::new(&name)).unwrap();
        exo.write_step(time, &[&t, &q], &[&src]).unwrap();
        peak.push((time, t.iter().copied().fold(f64::NEG_INFINITY, f64::max)));
    }
    exo.finish().unwrap();
    let plot = Plot {
        title: "Peak temperature".into(),
        x_label: "time (s)".into(),
        y_label: "T (K)".into(),
        log_y: false,
        series: vec![Series {
            label: "max T".into(),
            points: peak,
        }],
    };
    plot.write_png(&dir.join("temperature.png")).unwrap();
}

/// Runs `tests/python/check_results.py` on `dir` with `python`; (exit code, stdout).
fn python_check(python: &str, dir: &Path) -> (i32, String) {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/check_results.py");
    let out = std::process::Command::new(python)
        .arg(&script)
        .arg(dir)
        .output()
        .unwrap_or_else(|e| panic!("cannot run SEAM_PYTHON={python}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    (out.status.code().unwrap_or(-1), format!("{stdout}{stderr}"))
}

/// The sample outputs agree with each other (node counts, temperatures, times) as seam's
/// own readers see them; with `SEAM_PYTHON` set, meshio must agree too and must reject
/// a sample with a NaN temperature or with mismatched meshes.
#[test]
fn output_sample_results_pass_the_python_check() {
    let m = two_part_mesh();
    let tmp = scratch("output-sample");
    let root = tmp.path();
    let good = root.join("good");
    write_sample(&good, &m, 3, false);
    let exo = good.join("results.exo");
    assert_eq!(mesh::exodus::read_times(&exo).unwrap(), vec![0.0, 0.5, 1.0]);
    let last = mesh::exodus::read_nodal_variable(&exo, "temperature", 2).unwrap();
    let vtu = std::fs::read_to_string(good.join("results_0002.vtu")).unwrap();
    assert_eq!(bits(&decode(&vtu, Some("temperature"))), bits(&last));

    let Ok(python) = std::env::var("SEAM_PYTHON") else {
        eprintln!(
            "SEAM_PYTHON not set: skipping the meshio check of {}",
            good.display()
        );
        return;
    };
    let (code, out) = python_check(&python, &good);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.starts_with("ok: 3 vtu, 1 pvd (3 steps), 1 exodus (3 steps)"),
        "{out}"
    );

    let nan = root.join("nan");
    write_sample(&nan, &m, 2, true);
    let (code, out) = python_check(&python, &nan);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("not finite"), "{out}");

    let mixed = root.join("mixed");
    write_sample(&mixed, &m, 1, false);
    let other = generate::unit_hex();
    seam::output::vtu::write_vtu(
        &mixed.join("extra.vtu"),
        &other,
        &[("temperature", &[1.0; 8])],
    )
    .unwrap();
    let (code, out) = python_check(&python, &mixed);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("node counts differ"), "{out}");
}

/// Size and speed of the writers on a 10⁶-element hex box (1 030 301 nodes): run with
/// `cargo test --release --test it output_large -- --ignored --nocapture`.
#[test]
#[ignore = "timing report, seconds to minutes"]
fn output_large_mesh_write_times() {
    use std::time::Instant;
    let t0 = Instant::now();
    let m = generate::single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [100, 100, 100], 1));
    eprintln!(
        "mesh: {} nodes, {:.2} s",
        m.num_nodes(),
        t0.elapsed().as_secs_f64()
    );
    let tmp = scratch("output-large");
    let dir = tmp.path();
    let path = dir.join("large.exo");
    let t = nodal_values(&m, 0, 0);
    let t0 = Instant::now();
    let mut w = ExodusWriter::create(&path, &m, &["temperature"], &[]).unwrap();
    let create = t0.elapsed().as_secs_f64();
    let size0 = std::fs::metadata(&path).unwrap().len() as f64 / 1e6;
    let t0 = Instant::now();
    for s in 0..5 {
        w.write_step(s as f64, &[&t], &[]).unwrap();
    }
    let step = t0.elapsed().as_secs_f64() / 5.0;
    w.finish().unwrap();
    let size1 = std::fs::metadata(&path).unwrap().len() as f64 / 1e6;
    eprintln!(
        "exodus: create {create:.2} s ({size0:.1} MB), step {step:.3} s ({:.1} MB each)",
        (size1 - size0) / 5.0
    );
    let t0 = Instant::now();
    let back = mesh::exodus::read_nodal_variable(&path, "temperature", 4).unwrap();
    eprintln!("exodus: read one step {:.3} s", t0.elapsed().as_secs_f64());
    assert_eq!(bits(&back), bits(&t));
    let t0 = Instant::now();
    seam::output::vtu::write_vtu_cells(&dir.join("large.vtu"), &m, &[("temperature", &t)], &[])
        .unwrap();
    let vtu_mb = std::fs::metadata(dir.join("large.vtu")).unwrap().len() as f64 / 1e6;
    eprintln!(
        "vtu (base64): {:.2} s, {vtu_mb:.1} MB",
        t0.elapsed().as_secs_f64()
    );
    let t0 = Instant::now();
    seam::output::vtu::write_vtu(&dir.join("large_ascii.vtu"), &m, &[("temperature", &t)]).unwrap();
    let ascii_mb = std::fs::metadata(dir.join("large_ascii.vtu"))
        .unwrap()
        .len() as f64
        / 1e6;
    eprintln!(
        "vtu (ascii): {:.2} s, {ascii_mb:.1} MB",
        t0.elapsed().as_secs_f64()
    );
}
