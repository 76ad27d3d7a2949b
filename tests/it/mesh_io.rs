//! Mesh readers and validation against the fixtures written by
//! `tests/fixtures/make_fixtures.py`. Expected values come from `expected.json`, which
//! the script computes in Python from the arrays it wrote — independent of seam's code.

use std::path::{Path, PathBuf};

use seam::mesh::{self, Mesh, MeshError, Topology};
use serde_json::Value;

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

fn expected() -> Value {
    let text = std::fs::read_to_string(fixture("expected.json")).expect("expected.json");
    serde_json::from_str(&text).expect("expected.json parses")
}

fn read(name: &str) -> Mesh {
    match mesh::read(&fixture(name)) {
        Ok(m) => m,
        Err(e) => panic!("reading {name}: {e}"),
    }
}

fn node_index(m: &Mesh, number: i64) -> usize {
    m.node_numbers
        .iter()
        .position(|&n| n == number)
        .unwrap_or_else(|| panic!("node number {number} not found"))
}

fn ints(v: &Value) -> Vec<i64> {
    v.as_array()
        .expect("array")
        .iter()
        .map(|x| x.as_i64().expect("integer"))
        .collect()
}

/// Compare a mesh read from an Exodus fixture with the sidecar entry written with it.
fn check_against_sidecar(m: &Mesh, e: &Value) {
    assert_eq!(m.dim as i64, e["dim"].as_i64().unwrap());
    assert_eq!(m.num_nodes() as i64, e["num_nodes"].as_i64().unwrap());
    assert_eq!(m.num_elems() as i64, e["num_elems"].as_i64().unwrap());
    assert_eq!(m.node_numbers, ints(&e["node_numbers"]));
    assert_eq!(m.elem_numbers, ints(&e["elem_numbers"]));
    for (number, xyz) in e["coords"].as_object().unwrap() {
        let k = node_index(m, number.parse().unwrap());
        for d in 0..3 {
            let want = xyz[d].as_f64().unwrap();
            assert_eq!(m.coords[k][d], want, "node {number} coordinate {d}");
        }
    }
    let blocks = e["blocks"].as_array().unwrap();
    assert_eq!(m.blocks.len(), blocks.len());
    for (b, eb) in m.blocks.iter().zip(blocks) {
        assert_eq!(b.id, eb["id"].as_i64().unwrap());
        assert_eq!(b.name, eb["name"].as_str().unwrap());
        assert_eq!(
            b.len() as i64,
            eb["count"].as_i64().unwrap(),
            "block {}",
            b.id
        );
        let npe = b.topology.node_count();
        assert_eq!(
            Topology::from_exodus_name(eb["type"].as_str().unwrap(), npe, m.dim),
            Some(b.topology)
        );
        assert_eq!(b.thickness, eb["thickness"].as_f64(), "block {}", b.id);
    }
    let sets = e["side_sets"].as_array().unwrap();
    assert_eq!(m.side_sets.len(), sets.len());
    for (s, es) in m.side_sets.iter().zip(sets) {
        assert_eq!(s.id, es["id"].as_i64().unwrap());
        assert_eq!(s.name, es["name"].as_str().unwrap());
        let got: Vec<(i64, i64)> = s
            .sides
            .iter()
            .map(|sd| (m.elem_number(sd.elem), sd.side as i64))
            .collect();
        let want: Vec<(i64, i64)> = es["sides"]
            .as_array()
            .unwrap()
            .iter()
            .map(|p| (p[0].as_i64().unwrap(), p[1].as_i64().unwrap()))
            .collect();
        assert_eq!(got, want, "side set {}", s.id);
    }
    let sets = e["node_sets"].as_array().unwrap();
    assert_eq!(m.node_sets.len(), sets.len());
    for (s, es) in m.node_sets.iter().zip(sets) {
        assert_eq!(s.id, es["id"].as_i64().unwrap());
        assert_eq!(s.name, es["name"].as_str().unwrap());
        let got: Vec<i64> = s.nodes.iter().map(|&n| m.node_number(n)).collect();
        assert_eq!(got, ints(&es["nodes"]), "node set {}", s.id);
    }
    let asm = e["assemblies"].as_array().unwrap();
    assert_eq!(m.assemblies.len(), asm.len());
    for (a, ea) in m.assemblies.iter().zip(asm) {
        assert_eq!(a.id, ea["id"].as_i64().unwrap());
        assert_eq!(a.name, ea["name"].as_str().unwrap());
        assert_eq!(a.members, ints(&ea["members"]));
    }
}

/// Two meshes hold the same data. Coordinates agree to `tol` relative to the model size:
/// 0 for the Exodus flavours (same doubles), 1e-15 between Gmsh ASCII (16 significant
/// digits printed) and binary (exact doubles).
fn assert_same(a: &Mesh, b: &Mesh, what: &str, tol: f64) {
    assert_eq!(a.dim, b.dim, "{what}: dim");
    assert_eq!(a.coords.len(), b.coords.len(), "{what}: node count");
    let scale = a.model_size();
    for (k, (p, q)) in a.coords.iter().zip(&b.coords).enumerate() {
        for d in 0..3 {
            assert!(
                (p[d] - q[d]).abs() <= tol * scale,
                "{what}: node {} coordinate {d}: {} vs {}",
                a.node_numbers[k],
                p[d],
                q[d]
            );
        }
    }
    assert_eq!(a.node_numbers, b.node_numbers, "{what}: node numbers");
    assert_eq!(a.elem_numbers, b.elem_numbers, "{what}: element numbers");
    assert_eq!(a.blocks.len(), b.blocks.len(), "{what}: blocks");
    for (x, y) in a.blocks.iter().zip(&b.blocks) {
        assert_eq!(
            (x.id, &x.name, x.topology, &x.connectivity, x.thickness),
            (y.id, &y.name, y.topology, &y.connectivity, y.thickness),
            "{what}: block {}",
            x.id
        );
    }
    for (x, y) in a.side_sets.iter().zip(&b.side_sets) {
        assert_eq!(
            (x.id, &x.name, &x.sides),
            (y.id, &y.name, &y.sides),
            "{what}"
        );
    }
    assert_eq!(a.side_sets.len(), b.side_sets.len(), "{what}: side sets");
    for (x, y) in a.node_sets.iter().zip(&b.node_sets) {
        assert_eq!(
            (x.id, &x.name, &x.nodes),
            (y.id, &y.name, &y.nodes),
            "{what}"
        );
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn det3(a: [f64; 3], b: [f64; 3], c: [f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Signed volume (3-D solids) or area (2-D solids) of every element, computed from the
/// Exodus side tables by the divergence theorem: V = Σ_faces Σ_fan-triangles
/// det(c, p, q)/6 about the element centroid c (area: Σ_edges cross(p - c, q - c)/2).
/// Positive only when the node order read matches the side tables' outward orientation.
fn element_measures(m: &Mesh) -> Vec<(i64, f64)> {
    let mut out = Vec::new();
    for b in &m.blocks {
        if !b.topology.is_solid() {
            continue;
        }
        for (k, nodes) in b
            .connectivity
            .chunks_exact(b.topology.node_count())
            .enumerate()
        {
            let x: Vec<[f64; 3]> = nodes.iter().map(|n| m.coords[n.index()]).collect();
            let mut c = [0.0; 3];
            for p in &x {
                for d in 0..3 {
                    c[d] += p[d] / x.len() as f64;
                }
            }
            let mut v = 0.0;
            for side in b.topology.sides() {
                let f: Vec<[f64; 3]> = side.iter().map(|&l| x[l as usize]).collect();
                if m.dim == 2 {
                    let (p, q) = (sub(f[0], c), sub(f[1], c));
                    v += 0.5 * (p[0] * q[1] - p[1] * q[0]);
                    continue;
                }
                let mut fc = [0.0; 3];
                for p in &f {
                    for d in 0..3 {
                        fc[d] += p[d] / f.len() as f64;
                    }
                }
                for i in 0..f.len() {
                    let (p, q) = (f[i], f[(i + 1) % f.len()]);
                    v += det3(sub(fc, c), sub(p, c), sub(q, c)) / 6.0;
                }
            }
            out.push((m.elem_numbers[b.first_elem.index() + k], v));
        }
    }
    out
}

// ------------------------------------------------------------------------------------
// Exodus

#[test]
fn exodus_flavours_read_identically_and_match_the_sidecar() {
    let e = expected();
    let classic = read("two_hex_classic.exo");
    check_against_sidecar(&classic, &e["two_hex"]);
    for name in ["two_hex_offset64.exo", "two_hex_nc4.exo"] {
        let m = read(name);
        check_against_sidecar(&m, &e["two_hex"]);
        assert_same(&classic, &m, name, 0.0);
    }
    // The older layout (one `coord` array in single precision) reads to the same mesh up
    // to float32 rounding (relative 2^-24 ≈ 6e-8).
    let f32 = read("two_hex_coord_f32.exo");
    assert_same(&classic, &f32, "two_hex_coord_f32.exo", 1e-7);
    // Names fall back to the Sierra defaults where the file gave none.
    assert_eq!(classic.blocks[1].sierra_name(), "block_20");
    assert_eq!(classic.side_sets[1].sierra_name(), "surface_2");
    assert!(classic.find_block("left_block").is_some());
}

#[test]
fn exodus_side_sets_under_the_names_of_earlier_seam_versions_still_read() {
    // ss_elemN/ss_sideN instead of elem_ssN/side_ssN; nothing else differs.
    let legacy = read("legacy_side_set_names.exo");
    check_against_sidecar(&legacy, &expected()["two_hex"]);
    assert_same(&read("two_hex_offset64.exo"), &legacy, "legacy names", 0.0);
}

#[test]
fn exodus_side_sets_lie_on_the_planes_they_were_written_on() {
    // Both side sets were written on the interface z = 1.
    let m = read("two_hex_nc4.exo");
    for s in &m.side_sets {
        assert!(!s.sides.is_empty());
        for &side in &s.sides {
            for n in m.side_nodes(side) {
                assert_eq!(m.coords[n.index()][2], 1.0, "side set {}", s.id);
            }
        }
    }
}

#[test]
fn exodus_other_topologies_match_the_sidecar() {
    let e = expected();
    for name in ["tet_wedge", "quad2d", "shell"] {
        let m = read(&format!("{name}.exo"));
        check_against_sidecar(&m, &e[name]);
    }
    let shell = read("shell.exo");
    assert_eq!(shell.blocks[1].topology, Topology::Shell4);
    assert_eq!(shell.blocks[1].thickness, Some(0.1));
    assert!(shell.blocks[2].is_empty(), "the NULL block is kept");
    // The assembly (assembly_entity100 with _id, _type = element blocks, _name).
    assert_eq!(shell.assemblies.len(), 1);
    let a = &shell.assemblies[0];
    assert_eq!((a.id, a.name.as_str()), (100, "everything"));
    assert!(matches!(a.kind, seam::mesh::AssemblyKind::Blocks));
    assert_eq!(a.members, [1, 2, 3]);
    let tw = read("tet_wedge.exo");
    assert_eq!(tw.blocks[0].topology, Topology::Wedge6);
    assert_eq!(tw.blocks[1].topology, Topology::Tet4);
    assert_eq!(read("quad2d.exo").blocks[0].topology, Topology::Quad4);
}

// ------------------------------------------------------------------------------------
// Exodus files written by the reference Exodus II C library (libexodus), by
// tests/exodus/write_fixtures.c, with reference.json printed from the C program's own
// arrays. `SEAM_EXODUS_REFERENCE_DIR` points the tests at freshly written files (CI
// regenerates them), else the committed copies in tests/fixtures/reference are read.

fn reference_dir() -> PathBuf {
    match std::env::var_os("SEAM_EXODUS_REFERENCE_DIR") {
        Some(d) if !d.is_empty() => PathBuf::from(d),
        _ => fixture("reference"),
    }
}

fn reference() -> Value {
    let path = reference_dir().join("reference.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).expect("reference.json parses")
}

const FLAVOURS: [&str; 3] = ["classic", "offset64", "nc4"];

/// Every count, id, name, coordinate, connectivity entry and side of a mesh against
/// what the C program wrote (positions in the JSON are 1-based, as in the file).
fn check_against_reference(m: &Mesh, e: &Value, file: &str) {
    assert_eq!(m.dim as i64, e["dim"].as_i64().unwrap(), "{file}");
    assert_eq!(
        m.num_nodes() as i64,
        e["num_nodes"].as_i64().unwrap(),
        "{file}"
    );
    assert_eq!(
        m.num_elems() as i64,
        e["num_elems"].as_i64().unwrap(),
        "{file}"
    );
    assert_eq!(
        m.node_numbers,
        ints(&e["node_numbers"]),
        "{file} node_num_map"
    );
    assert_eq!(
        m.elem_numbers,
        ints(&e["elem_numbers"]),
        "{file} elem_num_map"
    );
    let coords = e["coords"].as_array().unwrap();
    for (k, xyz) in coords.iter().enumerate() {
        for d in 0..3 {
            assert_eq!(
                m.coords[k][d],
                xyz[d].as_f64().unwrap(),
                "{file} node {k} axis {d}"
            );
        }
    }
    let blocks = e["blocks"].as_array().unwrap();
    assert_eq!(m.blocks.len(), blocks.len(), "{file}");
    for (b, eb) in m.blocks.iter().zip(blocks) {
        let what = format!("{file} block {}", b.id);
        assert_eq!(b.id, eb["id"].as_i64().unwrap(), "{what}");
        assert_eq!(b.name, eb["name"].as_str().unwrap(), "{what}");
        assert_eq!(b.len() as i64, eb["count"].as_i64().unwrap(), "{what}");
        if !b.is_empty() {
            assert_eq!(
                Topology::from_exodus_name(
                    eb["type"].as_str().unwrap(),
                    eb["nodes_per_elem"].as_u64().unwrap() as usize,
                    m.dim
                ),
                Some(b.topology),
                "{what}"
            );
        }
        let conn: Vec<i64> = b.connectivity.iter().map(|n| n.0 as i64 + 1).collect();
        assert_eq!(conn, ints(&eb["connectivity"]), "{what} connect");
        assert_eq!(b.thickness, eb["thickness"].as_f64(), "{what} attrib");
    }
    let sets = e["side_sets"].as_array().unwrap();
    assert_eq!(m.side_sets.len(), sets.len(), "{file}");
    for (s, es) in m.side_sets.iter().zip(sets) {
        let what = format!("{file} side set {}", s.id);
        assert_eq!(s.id, es["id"].as_i64().unwrap(), "{what}");
        assert_eq!(s.name, es["name"].as_str().unwrap(), "{what}");
        let elems: Vec<i64> = s.sides.iter().map(|x| x.elem.0 as i64 + 1).collect();
        let sides: Vec<i64> = s.sides.iter().map(|x| i64::from(x.side)).collect();
        assert_eq!(elems, ints(&es["elems"]), "{what} elem_ss");
        assert_eq!(sides, ints(&es["sides"]), "{what} side_ss");
    }
    let sets = e["node_sets"].as_array().unwrap();
    assert_eq!(m.node_sets.len(), sets.len(), "{file}");
    for (s, es) in m.node_sets.iter().zip(sets) {
        let what = format!("{file} node set {}", s.id);
        assert_eq!(s.id, es["id"].as_i64().unwrap(), "{what}");
        assert_eq!(s.name, es["name"].as_str().unwrap(), "{what}");
        let nodes: Vec<i64> = s.nodes.iter().map(|n| n.0 as i64 + 1).collect();
        assert_eq!(nodes, ints(&es["nodes"]), "{what} node_ns");
    }
}

#[test]
fn exodus_reference_library_files_read_in_every_flavour_2d_and_3d() {
    let r = reference();
    for key in ["ref3d", "ref2d", "contact2d"] {
        for flavour in FLAVOURS {
            let file = format!("{key}_{flavour}.exo");
            let path = reference_dir().join(&file);
            let m = mesh::read(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
            check_against_reference(&m, &r[key], &file);
        }
    }
    let m = mesh::read(&reference_dir().join("ref3d_classic.exo")).unwrap();
    let topologies: Vec<Topology> = m.blocks.iter().map(|b| b.topology).collect();
    for t in [
        Topology::Hex8,
        Topology::Tet4,
        Topology::Wedge6,
        Topology::Pyramid5,
        Topology::Shell4,
        Topology::Shell3,
        Topology::Bar2,
    ] {
        assert!(
            topologies.contains(&t),
            "{t:?} is in the 3-D reference mesh"
        );
    }
    assert!(
        m.blocks.last().unwrap().is_empty(),
        "the NULL block is kept"
    );
    let m = mesh::read(&reference_dir().join("ref2d_nc4.exo")).unwrap();
    assert_eq!(m.blocks[0].topology, Topology::Quad4);
    assert_eq!(m.blocks[1].topology, Topology::Tri3);
}

#[test]
fn exodus_reference_library_records_and_variables_read_in_every_flavour() {
    let r = reference();
    for key in ["ref3d", "ref2d", "contact2d"] {
        let e = &r[key];
        for flavour in FLAVOURS {
            let file = format!("{key}_{flavour}.exo");
            let path = reference_dir().join(&file);
            let rec = mesh::exodus::read_records(&path).unwrap();
            let qa: Vec<Vec<String>> = rec.qa.iter().map(|q| q.to_vec()).collect();
            let want: Vec<Vec<String>> = e["qa_records"]
                .as_array()
                .unwrap()
                .iter()
                .map(|q| {
                    q.as_array()
                        .unwrap()
                        .iter()
                        .map(|s| s.as_str().unwrap().to_string())
                        .collect()
                })
                .collect();
            assert_eq!(qa, want, "{file} qa_records");
            let info: Vec<&str> = e["info_records"]
                .as_array()
                .unwrap()
                .iter()
                .map(|s| s.as_str().unwrap())
                .collect();
            assert_eq!(rec.info, info, "{file} info_records");

            let times: Vec<f64> = e["times"]
                .as_array()
                .unwrap()
                .iter()
                .map(|t| t.as_f64().unwrap())
                .collect();
            assert_eq!(mesh::exodus::read_times(&path).unwrap(), times, "{file}");
            let heat = mesh::exodus::read_global_variable(&path, "total_heat").unwrap();
            let want: Vec<f64> = e["global_variables"]["total_heat"]
                .as_array()
                .unwrap()
                .iter()
                .map(|v| v.as_f64().unwrap())
                .collect();
            assert_eq!(heat, want, "{file} vals_glo_var");
            for (step, want) in e["nodal_variables"]["temperature"]
                .as_array()
                .unwrap()
                .iter()
                .enumerate()
            {
                let got = mesh::exodus::read_nodal_variable(&path, "temperature", step).unwrap();
                let want: Vec<f64> = want
                    .as_array()
                    .unwrap()
                    .iter()
                    .map(|v| v.as_f64().unwrap())
                    .collect();
                assert_eq!(got, want, "{file} temperature at step {step}");
            }
            // `node_index` holds the 1-based node position, the second nodal variable.
            let idx = mesh::exodus::read_nodal_variable(&path, "node_index", 1).unwrap();
            let n = e["num_nodes"].as_u64().unwrap() as usize;
            assert_eq!(idx, (1..=n).map(|k| k as f64).collect::<Vec<_>>(), "{file}");
            // Element variable: id + k/2 + step (1-based step) where stored; the C
            // program leaves the second block out of the truth table.
            let m = mesh::read(&path).unwrap();
            let flux = mesh::exodus::read_element_variable(&path, "heat_flux_x", 1).unwrap();
            assert_eq!(flux.len(), m.num_elems(), "{file}");
            for (i, b) in m.blocks.iter().enumerate() {
                for k in 0..b.len() {
                    let got = flux[b.first_elem.index() + k];
                    if i == 1 {
                        assert!(got.is_nan(), "{file} block {} is out of elem_var_tab", b.id);
                    } else {
                        assert_eq!(
                            got,
                            b.id as f64 + 0.5 * k as f64 + 2.0,
                            "{file} block {}",
                            b.id
                        );
                    }
                }
            }
            // Side-set variable: -(k + step).
            let first = &e["side_sets"][0];
            let id = first["id"].as_i64().unwrap();
            let count = first["elems"].as_array().unwrap().len();
            let v = mesh::exodus::read_side_set_variable(&path, "side_flux", id, 0)
                .unwrap()
                .expect("stored on the first side set");
            let want: Vec<f64> = (0..count).map(|k| -((k + 1) as f64)).collect();
            assert_eq!(v, want, "{file} vals_sset_var");
            // Node-set variable: 7 (k + step).
            let first = &e["node_sets"][0];
            let id = first["id"].as_i64().unwrap();
            let count = first["nodes"].as_array().unwrap().len();
            let v = mesh::exodus::read_node_set_variable(&path, "node_set_value", id, 1)
                .unwrap()
                .expect("stored on the first node set");
            let want: Vec<f64> = (0..count).map(|k| 7.0 * (k + 2) as f64).collect();
            assert_eq!(v, want, "{file} vals_nset_var");
        }
    }
}

/// seam's writer on the reference meshes (every topology, 2-D and 3-D, empty block and
/// sets, shell thickness): read back by seam, the mesh is still what the C program wrote.
/// With `SEAM_EXODUS_CHECKER` naming the compiled tests/exodus/check_results.c (CI sets
/// it), the Exodus II C library reads each written file too and compares it with the
/// reference file.
#[test]
fn exodus_writer_round_trips_the_reference_meshes() {
    let r = reference();
    let tmp = crate::scratch("exodus-writer");
    let dir = tmp.path();
    for key in ["ref3d", "ref2d", "contact2d"] {
        let input = reference_dir().join(format!("{key}_offset64.exo"));
        let m = mesh::read(&input).unwrap();
        let out = dir.join(format!("{key}_written.exo"));
        let mut w = seam::output::exodus::ExodusWriter::create_with_globals(
            &out,
            &m,
            &["temperature"],
            &["heat_flux_x", "heat_flux_y", "heat_flux_z"],
            &["heat_side_a:one/two", "heat_side_b:one/two"],
        )
        .unwrap();
        let t: Vec<f64> = (0..m.num_nodes()).map(|k| 300.0 + k as f64).collect();
        let q: Vec<f64> = (0..m.num_elems()).map(|k| k as f64).collect();
        for step in 0..2 {
            w.write_step_with_globals(step as f64, &[&t], &[&q, &q, &q], &[-1.5, 1.5])
                .unwrap();
        }
        w.finish().unwrap();
        let back = mesh::read(&out).unwrap();
        check_against_reference(&back, &r[key], &out.display().to_string());
        assert_eq!(mesh::exodus::read_times(&out).unwrap(), [0.0, 1.0]);
        let rec = mesh::exodus::read_records(&out).unwrap();
        assert_eq!(rec.qa.len(), 1);
        assert_eq!(rec.qa[0][0], "seam");
        assert_eq!(
            mesh::exodus::read_global_variable(&out, "heat_side_b:one/two").unwrap(),
            [1.5, 1.5]
        );
        assert_eq!(
            mesh::exodus::read_element_variable(&out, "heat_flux_y", 1).unwrap(),
            q
        );
        if let Some(checker) = std::env::var_os("SEAM_EXODUS_CHECKER") {
            let o = std::process::Command::new(checker)
                .arg(&input)
                .arg(&out)
                .arg(dir.join(format!("{key}.dump")))
                .output()
                .unwrap();
            assert!(
                o.status.success(),
                "{key}: the Exodus II library disagrees:\n{}{}",
                String::from_utf8_lossy(&o.stdout),
                String::from_utf8_lossy(&o.stderr)
            );
            eprintln!("{}", String::from_utf8_lossy(&o.stdout).trim());
        }
    }
}

/// docs/exodus.md names, for every Exodus name, the tests that check it: each must exist.
#[test]
fn exodus_doc_names_tests_that_exist() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let doc = std::fs::read_to_string(root.join("docs/exodus.md")).unwrap();
    let mut named = 0;
    for part in doc.split('`') {
        let Some((module, name)) = part.split_once("::") else {
            continue;
        };
        if name.is_empty() || !module.chars().all(|c| c.is_ascii_lowercase() || c == '_') {
            continue;
        }
        let src = std::fs::read_to_string(root.join(format!("tests/it/{module}.rs")))
            .unwrap_or_else(|e| panic!("docs/exodus.md names `{part}`: tests/it/{module}.rs: {e}"));
        assert!(
            src.contains(&format!("fn {name}(")),
            "docs/exodus.md names `{part}`, which is not a test in tests/it/{module}.rs"
        );
        named += 1;
    }
    assert!(named >= 6, "{named} tests named");
    for c in [
        "tests/exodus/write_fixtures.c",
        "tests/exodus/check_results.c",
    ] {
        assert!(doc.contains(c) && root.join(c).is_file(), "{c}");
    }
}

// ------------------------------------------------------------------------------------
// Gmsh

#[test]
fn gmsh_ascii_and_binary_read_identically() {
    for stem in ["box_hex", "box_tet"] {
        let a = read(&format!("{stem}_ascii.msh"));
        let b = read(&format!("{stem}_binary.msh"));
        assert_same(&a, &b, stem, 1e-15);
    }
}

#[test]
fn gmsh_physical_groups_become_blocks_and_side_sets_on_the_right_planes() {
    let e = expected();
    for stem in ["box_hex", "box_tet"] {
        let m = read(&format!("{stem}_ascii.msh"));
        let x = &e[format!("{stem}.msh").as_str()];
        assert_eq!(m.dim, 3);
        assert_eq!(m.num_nodes() as i64, x["num_nodes"].as_i64().unwrap());
        let vols = x["volumes"].as_array().unwrap();
        assert_eq!(m.blocks.len(), vols.len(), "{stem}");
        for (b, v) in m.blocks.iter().zip(vols) {
            assert_eq!(b.id, v["id"].as_i64().unwrap());
            assert_eq!(b.name, v["name"].as_str().unwrap());
            assert_eq!(b.len() as i64, v["count"].as_i64().unwrap());
        }
        let surfs = x["surfaces"].as_array().unwrap();
        assert_eq!(m.side_sets.len(), surfs.len(), "{stem}");
        for (s, es) in m.side_sets.iter().zip(surfs) {
            assert_eq!(s.id, es["id"].as_i64().unwrap());
            assert_eq!(s.name, es["name"].as_str().unwrap());
            assert_eq!(s.sides.len() as i64, es["count"].as_i64().unwrap());
            let z = es["z"].as_f64().unwrap();
            for &side in &s.sides {
                for n in m.side_nodes(side) {
                    let p = m.coords[n.index()][2];
                    assert!((p - z).abs() < 1e-12, "{stem} {}: node at z={p}", s.name);
                }
            }
        }
        // The interface (z = 1) is taken from one side only, consistently: Gmsh orients
        // the surface, and seam takes the element the surface normal leaves.
        let iface = &m.side_sets[m.find_side_set("interface").unwrap()];
        let blocks: std::collections::BTreeSet<i64> = iface
            .sides
            .iter()
            .map(|s| m.blocks[m.block_of(s.elem)].id)
            .collect();
        assert_eq!(
            blocks.len(),
            1,
            "{stem}: interface sides from blocks {blocks:?}"
        );
    }
}

#[test]
fn gmsh_2d_surfaces_become_blocks_and_curves_side_sets() {
    let e = &expected()["plate2d.msh"];
    let m = read("plate2d.msh");
    assert_eq!(m.dim, 2);
    assert_eq!(m.blocks.len(), 1);
    assert_eq!(m.blocks[0].topology, Topology::Quad4);
    assert_eq!((m.blocks[0].id, m.blocks[0].name.as_str()), (5, "plate"));
    assert_eq!(m.blocks[0].len() as i64, e["quads"].as_i64().unwrap());
    assert_eq!(m.side_sets.len(), 1);
    let s = &m.side_sets[0];
    assert_eq!((s.id, s.name.as_str()), (6, "south"));
    assert_eq!(s.sides.len() as i64, e["south_edges"].as_i64().unwrap());
    for &side in &s.sides {
        for n in m.side_nodes(side) {
            assert_eq!(m.coords[n.index()][1], 0.0);
        }
    }
}

#[test]
fn gmsh_22_is_rejected_with_the_conversion_command() {
    let err = mesh::read(&fixture("box_hex_v22.msh")).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("box_hex_v22.msh"), "{msg}");
    assert!(msg.contains("2.2"), "{msg}");
    assert!(msg.contains("-format msh41"), "{msg}");
}

#[test]
fn gmsh_ascii_errors_give_the_line() {
    let text = std::fs::read_to_string(fixture("box_hex_ascii.msh")).unwrap();
    // Break the first coordinate line of $Nodes: after the section header, the counts,
    // the first block header and the first node tag.
    let lines: Vec<&str> = text.lines().collect();
    let nodes = lines.iter().position(|l| *l == "$Nodes").unwrap();
    let bad_line = nodes + 5; // 1-based line number of that coordinate line
    let mut broken: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
    broken[bad_line - 1] = "0 zero 0".into();
    let dir = crate::scratch("mesh-io-gmsh-line");
    let path = dir.path().join("broken.msh");
    std::fs::write(&path, broken.join("\n")).unwrap();
    let msg = mesh::read(&path).unwrap_err().to_string();
    assert!(msg.contains("broken.msh"), "{msg}");
    assert!(msg.contains(&format!("line {bad_line}")), "{msg}");
    assert!(msg.contains("`zero`"), "{msg}");
}

#[test]
fn exodus_from_meshio_matches_the_gmsh_file_it_was_converted_from() {
    // meshio writes netCDF-4 with int64 connectivity, a combined `coord` array and no
    // ids or names; blocks are numbered 1.. in the order of the Gmsh element blocks.
    let exo = read("meshio_box.exo");
    let msh = read("box_hex_ascii.msh");
    assert_eq!(exo.coords.len(), msh.coords.len());
    for (p, q) in exo.coords.iter().zip(&msh.coords) {
        for d in 0..3 {
            assert!((p[d] - q[d]).abs() < 1e-15, "{p:?} vs {q:?}");
        }
    }
    let exo_conn: Vec<_> = exo
        .blocks
        .iter()
        .flat_map(|b| b.connectivity.clone())
        .collect();
    let msh_conn: Vec<_> = msh
        .blocks
        .iter()
        .flat_map(|b| b.connectivity.clone())
        .collect();
    assert_eq!(exo_conn, msh_conn);
    assert!(exo.blocks.iter().all(|b| b.topology == Topology::Hex8));
}

// ------------------------------------------------------------------------------------
// Every fixture, every element

#[test]
fn every_fixture_element_has_positive_volume() {
    for name in [
        "two_hex_classic.exo",
        "two_hex_offset64.exo",
        "two_hex_nc4.exo",
        "tet_wedge.exo",
        "quad2d.exo",
        "shell.exo",
        "box_hex_ascii.msh",
        "box_hex_binary.msh",
        "box_tet_ascii.msh",
        "box_tet_binary.msh",
        "plate2d.msh",
        "meshio_box.exo",
    ] {
        let m = read(name);
        let measures = element_measures(&m);
        assert!(!measures.is_empty(), "{name}");
        let total: f64 = measures.iter().map(|(_, v)| v).sum();
        for (elem, v) in measures {
            assert!(v > 0.0, "{name}: element {elem} has volume {v}");
        }
        // The solids tile known regions: checks the whole mesh, not just signs.
        let want = match name {
            n if n.starts_with("two_hex") => 1.0 + 0.5,
            "tet_wedge.exo" => 2.0,
            "quad2d.exo" => 6.0,
            "shell.exo" => 1.0,
            n if n.starts_with("box_") || n == "meshio_box.exo" => 2.0,
            "plate2d.msh" => 2.0,
            _ => unreachable!(),
        };
        assert!(
            (total - want).abs() < 1e-9,
            "{name}: total {total}, want {want}"
        );
    }
}

// ------------------------------------------------------------------------------------
// Errors

#[test]
fn missing_file_names_the_path() {
    let err = mesh::read(Path::new("/nonexistent/dir/part.exo")).unwrap_err();
    assert!(matches!(err, MeshError::Open { .. }), "{err}");
    assert!(
        err.to_string().contains("/nonexistent/dir/part.exo"),
        "{err}"
    );
    let err = mesh::read(Path::new("/nonexistent/dir/part.msh")).unwrap_err();
    assert!(matches!(err, MeshError::Open { .. }), "{err}");
}

#[test]
fn truncated_file_is_an_error_naming_the_file() {
    let err = mesh::read(&fixture("truncated.exo")).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, MeshError::Format { .. }), "{msg}");
    assert!(msg.contains("truncated.exo"), "{msg}");
    assert!(msg.contains("the file is truncated"), "{msg}");
}

#[test]
fn unknown_extension_is_refused() {
    let err = mesh::read(Path::new("part.stl")).unwrap_err();
    assert!(matches!(err, MeshError::UnknownFormat { .. }), "{err}");
    let msg = err.to_string();
    assert!(msg.contains("part.stl") && msg.contains("stl"), "{msg}");
}

#[test]
fn inverted_element_is_reported_by_block_and_number() {
    let e = &expected()["inverted"];
    let err = mesh::read(&fixture("inverted.exo")).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, MeshError::Invalid { .. }), "{msg}");
    let elem = e["elem_number"].as_i64().unwrap();
    let block = e["block"].as_str().unwrap();
    assert!(msg.contains("inverted.exo"), "{msg}");
    assert!(
        msg.contains(&format!("element {elem} in {block} is inverted")),
        "{msg}"
    );
    assert!(msg.contains("mirrored"), "{msg}");
    // Reading without validation still works: the file itself is well formed.
    assert!(mesh::exodus::read(&fixture("inverted.exo")).is_ok());
}

#[test]
fn unsupported_element_type_names_block_and_type() {
    let msg = mesh::read(&fixture("hex20.exo")).unwrap_err().to_string();
    assert!(msg.contains("hex20.exo"), "{msg}");
    assert!(
        msg.contains("block 20") && msg.contains("`HEX20` with 20 nodes"),
        "{msg}"
    );
    assert!(msg.contains("seam supports HEX8, TETRA4"), "{msg}");
}

#[test]
fn dangling_connectivity_is_an_error_not_a_panic() {
    let msg = mesh::read(&fixture("dangling.exo"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("dangling.exo"), "{msg}");
    // Element 3 of block 10 (number 104 in elem_num_map), local node 7.
    assert!(
        msg.contains(
            "element 104 in block 10 (`left_block`), local node 7 refers to node position 64"
        ),
        "{msg}"
    );
}

#[test]
fn gmsh_surface_on_no_grouped_volume_is_an_error_naming_it() {
    let msg = mesh::read(&fixture("orphan_surface.msh"))
        .unwrap_err()
        .to_string();
    assert!(msg.contains("orphan_surface.msh"), "{msg}");
    assert!(msg.contains("physical surface 13 (\"top\")"), "{msg}");
    assert!(msg.contains("is not a side of any element"), "{msg}");
}
