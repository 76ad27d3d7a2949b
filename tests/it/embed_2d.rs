//! The embedding API in 2-D (`seam::embed`, `libseam` + `seam.h`): Quad4/Tri3 blocks,
//! edge face sets and the axisymmetric flag, from a Rust host and a C host against
//! `seam run`, and the 2-D input it refuses. Tolerances as in `embed.rs`.

use seam::embed::{EmbedError, Embedding, Interaction, Model, Topology};

use crate::embed::{TOLERANCE, example, printed, relative, run_c_host};
use crate::scratch;

/// The embedding in 2-D, axisymmetric, from Rust and from C: two concentric cylinders as
/// their (r, z) section (Quad4 blocks, 8 × 6 cells inside r = 1 and 12 × 9 outside, meshed
/// apart), a gap conductance h = 3 at r = 1 given as edge face sets (C) or side sets
/// (Rust), 400 K on r = 0.5 and 300 K on r = 2. Each host assembles its own
/// axisymmetric conduction (the C host its own bilinear quad, the Rust host seam's
/// kernel on `Basis::for_measure`) and seam's interface terms, and solves. Both heats
/// equal `seam run`'s on the same section (`[mesh] axisymmetric = true`) to the
/// module's tolerance, and the logarithmic solution to the discretisation error (1e-3).
#[test]
fn embed_2d_axisymmetric_hosts_match_seam_run() {
    use seam::fem::{Basis, Measure};
    use seam::mesh::generate::{self, RectSpec};
    let mesh = generate::rectangles(
        &[
            RectSpec::quad([0.5, 0.0], [1.0, 0.5], [8, 6], 1).with_side_sets([1, 3, 0, 0]),
            RectSpec::quad([1.0, 0.0], [2.0, 0.5], [12, 9], 2).with_side_sets([4, 2, 0, 0]),
        ],
        false,
    );
    let k_of = |block: &str| if block == "block_1" { 2.0 } else { 5.0 };
    let exact = std::f64::consts::TAU * 0.5 * 100.0
        / ((1.0f64 / 0.5).ln() / 2.0 + 1.0 / 3.0 + 2.0f64.ln() / 5.0);
    // seam run.
    let tmp = scratch("embed-axisymmetric-host");
    let dir = tmp.path();
    crate::twod::write_mesh(&dir.join("mesh.exo"), &mesh);
    let problem = crate::twod::problem_text(
        "mesh.exo",
        true,
        &[("block_1", 2.0), ("block_2", 5.0)],
        &[("surface_1", "400"), ("surface_2", "300")],
        "",
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    let deck = crate::twod::pair_deck(
        "contact surface a contains surface_3",
        "surface_4",
        "",
        "enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = 3",
    );
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    let reference = match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => r.summary.interactions[0].heat_side_a,
        Err(e) => panic!("seam run failed: {e:?}"),
    };
    // Rust host.
    let dof = example::host_dofs(&mesh);
    let mut builder = Embedding::builder(&mesh.coords);
    for block in &mesh.blocks {
        let conn: Vec<usize> = block.connectivity.iter().map(|n| n.index()).collect();
        builder = builder.block(
            &block.sierra_name(),
            block.topology,
            &conn,
            k_of(&block.sierra_name()),
        );
    }
    for set in &mesh.side_sets {
        let sides: Vec<(usize, u8)> = set.sides.iter().map(|s| (s.elem.index(), s.side)).collect();
        builder = builder.side_set(&set.sierra_name(), &sides);
    }
    let mut embedding = builder.dofs(&dof).axisymmetric(true).build().unwrap();
    embedding
        .add_interaction(Interaction::new(
            "surface_3",
            "surface_4",
            Model::GapConductance { h: 3.0 },
        ))
        .unwrap();
    embedding.search().unwrap();
    let n = mesh.num_nodes();
    let mut k = vec![0.0; n * n];
    for block in &mesh.blocks {
        let basis = Basis::for_measure(block.topology, Measure::Axisymmetric).unwrap();
        let nn = block.topology.node_count();
        for e in 0..block.len() {
            let nodes = block.elem_nodes(e);
            let x: Vec<[f64; 3]> = nodes.iter().map(|n| mesh.coords[n.index()]).collect();
            let mut ke = vec![0.0; nn * nn];
            let k_block = k_of(&block.sierra_name());
            seam::heat::kernel::conductivity(&basis, &x, |_| k_block, &mut ke).unwrap();
            for (a, na) in nodes.iter().enumerate() {
                for (b, nb) in nodes.iter().enumerate() {
                    k[dof[na.index()] * n + dof[nb.index()]] += ke[a * nn + b];
                }
            }
        }
    }
    let fixed =
        example::dirichlet_on(&mesh, &dof, &[("surface_1", 400.0), ("surface_2", 300.0)]).unwrap();
    let (u, _) = example::newton(&embedding, &k, &fixed).unwrap();
    let rust = embedding.contributions(&u).unwrap().heat[0].unwrap().side_a;
    // C host.
    let stdout = run_c_host("axisymmetric.c");
    let c = printed(&stdout, "interface heat: side A ");
    let logarithmic = printed(&stdout, "logarithmic solution: ")[0];
    println!(
        "axisymmetric cylinders: seam run {reference:.15e} W, Rust host {rust:.15e} W ({:.1e}), C host {:.15e} W ({:.1e}); logarithmic {exact:.15e} W ({:.1e})",
        relative(rust, reference),
        c[0],
        relative(c[0], reference),
        relative(reference, exact)
    );
    assert!(
        (logarithmic - exact).abs() <= 1e-12 * exact,
        "{logarithmic} vs {exact}"
    );
    assert!(
        relative(rust, reference) <= TOLERANCE,
        "{rust} vs {reference}"
    );
    assert!(
        relative(c[0], reference) <= TOLERANCE,
        "{} vs {reference}",
        c[0]
    );
    assert!(relative(-c[1], reference) <= TOLERANCE);
    assert!(relative(reference, exact) <= 1e-3, "{reference} vs {exact}");
}

/// 2-D input the embedding refuses, each naming the cause: a 2-D block beside a 3-D one,
/// a node of a 2-D mesh off the xy plane, an edge face set whose nodes are no side, and
/// an axisymmetric mesh with a node at x < 0.
#[test]
fn embed_2d_bad_input_says_where() {
    let square = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ];
    let quad = [0, 1, 2, 3];
    let message = |r: Result<Embedding, EmbedError>| match r {
        Ok(_) => panic!("accepted bad input"),
        Err(e) => e.to_string(),
    };
    let hex: Vec<usize> = (0..8).collect();
    let mut cube = square.to_vec();
    cube.extend(square.iter().map(|p| [p[0], p[1], 1.0]));
    let m = message(
        Embedding::builder(&cube)
            .block("plate", Topology::Quad4, &quad, 1.0)
            .block("brick", Topology::Hex8, &hex, 1.0)
            .dofs(&hex)
            .build(),
    );
    assert!(
        m.contains("block `brick` has topology Hex8") && m.contains("2-D solids"),
        "{m}"
    );
    let mut lifted = square;
    lifted[2][2] = 0.5;
    let m = message(
        Embedding::builder(&lifted)
            .block("plate", Topology::Quad4, &quad, 1.0)
            .dofs(&quad)
            .build(),
    );
    assert!(m.contains("node 2 of a 2-D mesh lies at z = 0.5"), "{m}");
    let m = message(
        Embedding::builder(&square)
            .block("plate", Topology::Quad4, &quad, 1.0)
            .face_set("diagonal", &[[0, 2]])
            .dofs(&quad)
            .build(),
    );
    assert!(
        m.contains("surface `diagonal`, face 0: nodes [0, 2] are no side"),
        "{m}"
    );
    let left = square.map(|p| [p[0] - 0.5, p[1], 0.0]);
    let m = message(
        Embedding::builder(&left)
            .block("plate", Topology::Quad4, &quad, 1.0)
            .dofs(&quad)
            .axisymmetric(true)
            .build(),
    );
    assert!(m.contains("x = -0.5"), "{m}");
    // The edges themselves are accepted, in either direction.
    let ok = Embedding::builder(&square)
        .block("plate", Topology::Quad4, &quad, 1.0)
        .face_set("top", &[[3, 2]])
        .face_set("bottom", &[[0, 1]])
        .dofs(&quad)
        .build();
    assert!(ok.is_ok(), "{:?}", ok.err());
}
