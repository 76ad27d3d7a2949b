//! Result writers: Exodus II written by seam and read back by the independent netCDF
//! reader (`mesh::read`, `netcdf-reader`), VTU/PVD files parsed back, PNG plots decoded
//! with the `png` crate. With `SEAM_PYTHON` set to a Python that has meshio, the sample
//! outputs are also checked by `tests/python/check_results.py`.

use std::io::ErrorKind;
use std::path::PathBuf;

use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{self, Mesh, NodeId, NodeSet, Topology};
use seam::output::exodus::ExodusWriter;

fn out_dir(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

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
    let path = out_dir("output-exodus").join("two_parts.exo");
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
    let path = out_dir("output-exodus").join("steps.exo");
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
    let path = out_dir("output-exodus").join("bad.exo");
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
    let mut big = generate::unit_hex();
    big.blocks[0].id = 1 << 40;
    let e = ExodusWriter::create(&path, &big, &[], &[]).unwrap_err();
    assert!(e.to_string().contains("block id"), "{e}");
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
    let path = out_dir("output-exodus").join("flat.exo");
    let mut w = ExodusWriter::create(&path, &m, &["u"], &[]).unwrap();
    w.write_step(1.0, &[&[1.0, 2.0, 3.0, 4.0, f64::NAN]], &[])
        .unwrap();
    w.finish().unwrap();
    assert_same_mesh(&m, &mesh::read(&path).unwrap());
    let u = mesh::exodus::read_nodal_variable(&path, "U", 0).unwrap();
    assert_eq!(&u[..4], &[1.0, 2.0, 3.0, 4.0]);
    assert!(u[4].is_nan());
}

fn ids(v: &[u32]) -> Vec<NodeId> {
    v.iter().map(|&n| NodeId(n)).collect()
}
