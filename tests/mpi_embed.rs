//! The embedding on MPI (`seam::embed::RankEmbedding`, `seam_rank_*` in `seam.h`): the C
//! host on PETSc (`examples/c_host/mpi_petsc.c`) under `mpirun -n 1, 2, 3, 4` against
//! the same problem through the serial embedding, and both against the 1-D answer
//! (needs OpenMPI and Debian's petsc-dev); run by `.ci/run`: `cargo test --features mpi
//! --test mpi_embed`.

#![cfg(feature = "mpi")]

use std::path::{Path, PathBuf};
use std::process::Command;

use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{ElemId, Mesh};

/// Largest difference allowed, relative to the largest |value|: the serial path solves
/// by dense Gaussian elimination, the distributed one by MUMPS LU over an MPIAIJ matrix
/// whose entries were summed in another order, which on 172 unknowns leaves round-off of
/// 1e-14–1e-13 relative; 1e-9 keeps orders of margin and still fails a rank's terms
/// dropped or counted twice (they move T by kelvins).
const REL: f64 = 1e-9;

/// The host's problem (mpi_petsc.c): k_a = 2 and k_b = 5 W/m/K over unit lengths,
/// h = 50 W/m²/K, 400 K at x = 0 and 300 K at x = 2, a unit cross-section.
const KA: f64 = 2.0;
const KB: f64 = 5.0;
const H: f64 = 50.0;
const T_LEFT: f64 = 400.0;
const T_RIGHT: f64 = 300.0;

/// What the host prints on rank 0.
struct Printed {
    /// `tie dual`: the largest difference between the solved multipliers and those
    /// recovered from the host's residual.
    recovered: Option<f64>,
    /// `tie dual`: the tie's heat from the host's residual (`seam_rank_dual_tie_heat`).
    dual_heat: Option<[f64; 2]>,
    /// The gap conductance on ranks: the flux times the weight summed over every rank's
    /// own contact points (`seam_rank_point_fields`), and the count of points.
    point_fields: Option<(f64, usize)>,
    /// The same from the faces' mean flux (`seam_rank_face_fields`): over side A's
    /// faces, over side B's, and the count of faces.
    face_fields: Option<(f64, f64, usize)>,
    /// The gap conductance's coverage on rank 0 (`seam_rank_coverage`): side-A points,
    /// paired points, paired area.
    coverage: Option<(usize, usize, f64)>,
    /// Every rank saw a null field on the last rank refused (1), none left waiting.
    refused: Option<f64>,
    /// Every rank saw a time that differs on the last rank refused (1; on one rank,
    /// `seam_rank_set_time` took it).
    time_refused: Option<f64>,
    /// Points quarantined over every rank and on rank 0 (`seam_rank_quarantined`).
    quarantined: Option<f64>,
    /// The interface terms through `seam_rank_evaluate_csr` against the triplets: the
    /// largest difference of the matrices and of the loads over the ranks, and the count
    /// of CSR entries over the ranks.
    csr: Option<(f64, f64, usize)>,
    ranks: usize,
    across: usize,
    heat: [f64; 2],
    x: Vec<f64>,
    temperature: Vec<f64>,
}

/// The folder of `libseam.so` this test binary was built with.
fn library_dir() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    [deps, deps.parent().unwrap()]
        .into_iter()
        .find(|d| d.join("libseam.so").exists())
        .unwrap_or_else(|| panic!("libseam.so is in neither {} nor its parent", deps.display()))
        .to_path_buf()
}

/// `mpicc` with the CI's warning flags, against PETSc (pkg-config) and libseam.
fn build_host(dir: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = library_dir();
    let pkg = |what: &str| -> Vec<String> {
        let out = Command::new("pkg-config")
            .args([what, "PETSc"])
            .output()
            .expect("pkg-config (petsc-dev)");
        assert!(out.status.success(), "pkg-config {what} PETSc failed");
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .map(String::from)
            .collect()
    };
    let host = dir.join("mpi_petsc");
    let build = Command::new("mpicc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2"])
        .args(pkg("--cflags"))
        .arg("-I")
        .arg(root.join("include"))
        .arg(root.join("examples/c_host/mpi_petsc.c"))
        .arg("-L")
        .arg(&lib)
        .arg("-lseam")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .args(pkg("--libs"))
        .arg("-lm")
        .arg("-o")
        .arg(&host)
        .output()
        .expect("mpicc (libopenmpi-dev)");
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    host
}

/// The host under `mpirun -n ranks` in `mode` (`serial`: the serial embedding, one
/// rank; `tie`: a mortar tie with multipliers; `tie dual`: dual ones).
fn run(host: &Path, ranks: usize, mode: &[&str]) -> Printed {
    let mut cmd = Command::new("timeout");
    cmd.args(["300", "mpirun", "--oversubscribe", "-n", &ranks.to_string()])
        .arg(host)
        .args(mode)
        .env("LD_LIBRARY_PATH", library_dir())
        .env("RAYON_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1");
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{stdout}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    let numbers = |prefix: &str| -> Vec<f64> {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .unwrap_or_else(|| panic!("no `{prefix}` line in:\n{stdout}"))
            .split_whitespace()
            .map(|w| w.parse().unwrap())
            .collect()
    };
    let heat = numbers("heat:");
    let optional = |prefix: &str| -> Option<Vec<f64>> {
        stdout
            .lines()
            .find_map(|l| l.strip_prefix(prefix))
            .map(|v| v.split_whitespace().map(|w| w.parse().unwrap()).collect())
    };
    Printed {
        recovered: optional("dual multipliers from the residual:").map(|v| v[0]),
        dual_heat: optional("dual heat from the residual:").map(|v| [v[0], v[1]]),
        point_fields: optional("point fields:").map(|v| (v[0], v[1] as usize)),
        face_fields: optional("face fields:").map(|v| (v[0], v[1], v[2] as usize)),
        coverage: optional("coverage:").map(|v| (v[0] as usize, v[1] as usize, v[2])),
        refused: optional("bad argument refused on every rank:").map(|v| v[0]),
        time_refused: optional("differing times refused on every rank:").map(|v| v[0]),
        quarantined: optional("quarantined:").map(|v| v[0]),
        csr: optional("csr against triplets:").map(|v| (v[0], v[1], v[2] as usize)),
        ranks: numbers("ranks:")[0] as usize,
        across: numbers("points across ranks:")[0] as usize,
        heat: [heat[0], heat[1]],
        x: numbers("x:"),
        temperature: numbers("temperature:"),
    }
}

/// Largest |a − b|.
fn difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

/// The heat through the three resistances in series (unit lengths and cross-section).
fn heat_exact() -> f64 {
    heat_through(1.0 / H)
}

/// The heat with an interface resistance `r` (0: tied).
fn heat_through(r: f64) -> f64 {
    (T_LEFT - T_RIGHT) / (1.0 / KA + r + 1.0 / KB)
}

/// Brick a's nodes come first: (3 + 1) × (4 + 1) × (4 + 1) of them.
const NODES_A: usize = 100;

/// The 1-D answer at every node, T linear in each brick (which trilinear elements and a
/// consistent interface form reproduce exactly); a's and b's nodes at x = 1 differ by
/// the jump q/h.
fn exact_temperatures(x: &[f64]) -> Vec<f64> {
    exact_temperatures_through(x, 1.0 / H)
}

/// [`exact_temperatures`] with an interface resistance `r` (0: tied, T continuous).
fn exact_temperatures_through(x: &[f64], r: f64) -> Vec<f64> {
    let q = heat_through(r);
    x.iter()
        .enumerate()
        .map(|(k, &x)| {
            if k < NODES_A {
                T_LEFT - q * x / KA
            } else {
                T_RIGHT + q * (2.0 - x) / KB
            }
        })
        .collect()
}

#[test]
fn petsc_host_equals_the_serial_embedding_and_the_1d_answer_on_1_to_4_ranks() {
    let tmp = tempfile::Builder::new()
        .prefix("mpi-embed-")
        .tempdir_in(env!("CARGO_TARGET_TMPDIR"))
        .unwrap();
    let host = build_host(tmp.path());

    let serial = run(&host, 1, &["serial"]);
    let t_scale = serial
        .temperature
        .iter()
        .fold(0.0f64, |m, t| m.max(t.abs()));
    let q = heat_exact();
    let dt = difference(&serial.temperature, &exact_temperatures(&serial.x));
    eprintln!(
        "serial embedding against the 1-D answer: max |ΔT| {dt:.2e} K, heat {:.12} / {:.12} W (exact {q:.12})",
        serial.heat[0], serial.heat[1]
    );
    assert!(dt <= REL * t_scale, "serial T off the 1-D answer by {dt:e}");
    assert!((serial.heat[0] - q).abs() <= REL * q);
    assert!((serial.heat[0] + serial.heat[1]).abs() <= REL * q);

    let (mut points, mut faces) = (None, None);
    for n in 1..=4 {
        let par = run(&host, n, &[]);
        assert_eq!(par.ranks, n);
        let dt = difference(&serial.temperature, &par.temperature);
        let dq = difference(&serial.heat, &par.heat);
        // Each rank's own points' flux: together every point once, their heat the
        // interface's.
        let (q_points, count) = par.point_fields.expect("the host prints its point fields");
        let dq_points = (q_points - par.heat[0]).abs();
        eprintln!(
            "mpirun -n {n}: max |ΔT| {dt:.2e} K (of {t_scale:.0}), max |Δheat| {dq:.2e} W (of {q:.3}), points paired across ranks {}; Σ q w over the ranks' {count} points off the heat by {dq_points:.2e} W",
            par.across
        );
        assert!(dt <= REL * t_scale, "T differs by {dt:e} on {n} ranks");
        assert!(dq <= REL * q, "heat differs by {dq:e} on {n} ranks");
        assert!(
            dq_points <= REL * q,
            "point fields' heat off by {dq_points:e} on {n} ranks"
        );
        assert!(count > 0);
        assert_eq!(
            *points.get_or_insert(count),
            count,
            "every point once on {n} ranks"
        );
        assert_eq!(
            par.refused,
            Some(1.0),
            "a null field on the last of {n} ranks"
        );
        assert_eq!(
            par.time_refused,
            Some(1.0),
            "times that differ on {n} ranks"
        );
        assert_eq!(
            par.quarantined,
            Some(0.0),
            "a constant model quarantines nothing"
        );
        let (dm, dv, nnz) = par.csr.expect("the host compares the CSR form");
        eprintln!(
            "mpirun -n {n}: CSR against triplets {dm:.1e} (matrix), {dv:.1e} (load), {nnz} entries over the ranks"
        );
        assert!(
            dm <= 1e-10 && dv <= 1e-10 && nnz > 0,
            "CSR against triplets: {dm:e} {dv:e} {nnz}"
        );
        // Every point paired, over the whole unit face, on every rank count.
        let (all_points, paired, area) = par.coverage.expect("the host prints its coverage");
        assert_eq!(
            (all_points, paired),
            (count, count),
            "coverage on {n} ranks"
        );
        assert!(
            (area - 1.0).abs() <= 1e-12,
            "paired area {area} on {n} ranks"
        );
        let (on_a, on_b, n_faces) = par.face_fields.expect("the host prints its face fields");
        let dq_faces = (on_a - par.heat[0]).abs().max((on_b - par.heat[0]).abs());
        eprintln!(
            "mpirun -n {n}: Σ flux × paired area over the ranks' {n_faces} faces off the heat by {dq_faces:.2e} W"
        );
        assert!(
            dq_faces <= REL * q,
            "face fields' heat off by {dq_faces:e} on {n} ranks"
        );
        assert_eq!(
            *faces.get_or_insert(n_faces),
            n_faces,
            "every face once on {n} ranks"
        );
        if n > 1 {
            assert!(
                par.across > 0,
                "the partition should cut the interface on {n} ranks"
            );
        }
    }
}

/// The PETSc host with a mortar tie instead of the gap conductance, standard and dual
/// multipliers, under `mpirun -n 1..4`: each rank adds the rows `C u = g` of the
/// multipliers it owns, numbered by their place in the whole tie, and the solve of
/// `[K Cᵀ; C 0]` gives the 1-D answer of a perfect contact — T continuous, linear in each
/// brick, 100 / (1/2 + 1/5) W — which the mortar tie reproduces exactly. With dual
/// multipliers the host also recovers them from its residual without the tie
/// (`seam_rank_dual_multipliers`), as a host that condensed the tie would.
#[test]
fn petsc_host_with_a_mortar_tie_gives_the_1d_answer_on_1_to_4_ranks() {
    let tmp = tempfile::Builder::new()
        .prefix("mpi-embed-tie-")
        .tempdir_in(env!("CARGO_TARGET_TMPDIR"))
        .unwrap();
    let host = build_host(tmp.path());
    let q = heat_through(0.0);
    for (n, mode) in (1..=4).flat_map(|n| [(n, &["tie"][..]), (n, &["tie", "dual"][..])]) {
        let par = run(&host, n, mode);
        assert_eq!(par.ranks, n);
        let dual = mode.len() == 2;
        if dual {
            // λ = −r/D from the residual without the tie: the solved multipliers (of
            // the order of the flux, 142.857 W/m²).
            let dl = par
                .recovered
                .expect("the dual host prints its multipliers' check");
            eprintln!("mpirun -n {n} (dual): multipliers from the residual off by {dl:.2e}");
            assert!(
                dl <= REL * q,
                "dual multipliers from the residual off by {dl:e}"
            );
            let [ra, rb] = par.dual_heat.expect("the dual host prints its heat");
            let dq = (ra - q).abs().max((rb + q).abs());
            eprintln!("mpirun -n {n} (dual): heat from the residual off by {dq:.2e} W");
            assert!(dq <= REL * q, "dual heat from the residual off by {dq:e}");
        }
        // The multiplier field at every rank's own points, weighted: the heat.
        let (q_points, count) = par
            .point_fields
            .expect("the tie host prints its point fields");
        let dq_points = (q_points - q).abs();
        eprintln!(
            "mpirun -n {n} ({}): Σ λ_h w over the ranks' {count} points off by {dq_points:.2e} W",
            mode.join(" ")
        );
        assert!(
            dq_points <= REL * q,
            "the multiplier field's heat off by {dq_points:e}"
        );
        let exact = exact_temperatures_through(&par.x, 0.0);
        let t_scale = exact.iter().fold(0.0f64, |m, t| m.max(t.abs()));
        let dt = difference(&exact, &par.temperature);
        let dq = (par.heat[0] - q).abs().max((par.heat[1] + q).abs());
        eprintln!(
            "mpirun -n {n} ({}): max |ΔT| {dt:.2e} K (of {t_scale:.0}), max |Δheat| {dq:.2e} W (of {q:.3}), points paired across ranks {}",
            mode.join(" "),
            par.across
        );
        assert!(
            dt <= REL * t_scale,
            "T off the 1-D answer by {dt:e} on {n} ranks"
        );
        assert!(dq <= REL * q, "heat off by {dq:e} on {n} ranks");
    }
}

/// Set in the processes `mpirun` starts for [`rank_terms_sum_to_the_serial_terms`].
const CHILD: &str = "SEAM_MPI_EMBED_CHILD";

/// The two bricks of mpi_petsc.c (a: 3 × 4 × 4 hexahedra on [0,1]³, b: 2 × 5 × 3 on
/// [1,2] × [0,1]², meshed apart), by seam's generator, with the side sets of the
/// interfaces: 1 a's x = 1, 2 b's x = 1, 3 a's y = 0, 4 a's y = 1.
fn bricks() -> Mesh {
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [3, 4, 4], 1).with_side_sets([0, 1, 3, 4, 0, 0]),
            BoxSpec::hex([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], [2, 5, 3], 2)
                .with_side_sets([2, 0, 0, 0, 0, 0]),
        ],
        false,
    )
}

/// The pressure scale of the setters' test model (Pa): h doubles at P0.
const P0: f64 = 1e6;

/// The host's names of side sets 1 to 4.
const SURFACES: [&str; 4] = ["right", "left", "front", "back"];

/// A field that is not linear, so the residuals are not those of a linear field.
fn field(x: [f64; 3]) -> f64 {
    300.0 + 40.0 * x[0] + 7.0 * (3.0 * x[1]).sin() + 5.0 * x[2] * x[2]
}

/// The host's global dof of global node `g`: a permutation of the nodes (172 and 7 are
/// coprime), so that dof and node numbers differ.
fn dof_of(g: usize, nodes: usize) -> usize {
    (g * 7) % nodes
}

fn interactions() -> Vec<seam::embed::Interaction> {
    use seam::embed::{Interaction, Model, Periodic};
    vec![
        Interaction::new("right", "left", Model::GapConductance { h: H }).offset(3.0),
        Interaction::new("front", "back", Model::TiedNitsche).periodic(Periodic::Rectangular {
            offset: [0.0, 1.0, 0.0],
        }),
    ]
}

/// An embedding builder of elements `elems` of the bricks (their two blocks, the four
/// surfaces), with the local nodes in first-seen order (returned by global number).
fn builder_of(m: &Mesh, elems: &[usize]) -> (seam::embed::EmbeddingBuilder, Vec<usize>) {
    use seam::embed::{Embedding, Topology};
    let mut local_of = vec![usize::MAX; m.coords.len()];
    let mut nodes = Vec::new();
    let mut conn = [Vec::new(), Vec::new()];
    // Local elements are numbered block after block.
    let (mut local_elem, mut next) = (vec![usize::MAX; m.num_elems()], 0);
    for (blk, conn) in conn.iter_mut().enumerate() {
        for &e in elems
            .iter()
            .filter(|&&e| m.block_of(ElemId(e as u32)) == blk)
        {
            for g in m.elem_nodes(ElemId(e as u32)).iter().map(|n| n.index()) {
                if local_of[g] == usize::MAX {
                    local_of[g] = nodes.len();
                    nodes.push(g);
                }
                conn.push(local_of[g]);
            }
            local_elem[e] = next;
            next += 1;
        }
    }
    let coords: Vec<[f64; 3]> = nodes.iter().map(|&g| m.coords[g]).collect();
    let dofs: Vec<usize> = nodes.iter().map(|&g| dof_of(g, m.coords.len())).collect();
    let mut b = Embedding::builder(&coords)
        .block("a", Topology::Hex8, &conn[0], KA)
        .block("b", Topology::Hex8, &conn[1], KB)
        .dofs(&dofs);
    for (k, name) in SURFACES.iter().enumerate() {
        let set = m.side_sets.iter().find(|s| s.id == k as i64 + 1).unwrap();
        let sides: Vec<(usize, u8)> = set
            .sides
            .iter()
            .filter(|s| local_elem[s.elem.index()] != usize::MAX)
            .map(|s| (local_elem[s.elem.index()], s.side))
            .collect();
        b = b.side_set(name, &sides);
    }
    (b, nodes)
}

/// Dense `n × n` Jacobian and residual and load vectors of `c`.
fn dense(c: &seam::embed::Contributions, n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n + 2 * n];
    for &(i, j, v) in &c.jacobian {
        out[i * n + j] += v;
    }
    for &(d, v) in &c.residual {
        out[n * n + d] += v;
    }
    for &(d, v) in &c.load {
        out[n * n + n + d] += v;
    }
    out
}

/// Under `mpirun -n 1..4`: each rank builds the embedding of its slab of elements
/// (`RankEmbedding`), a gap conductance with an offset across the non-matching x = 1 and
/// a periodic Nitsche tie of a's y = 0 and y = 1 faces, evaluates at a curved field; the
/// ranks' Jacobians, residuals and loads summed equal the serial embedding's, and the
/// heats too. Then a rank that gives a wrong count of global ids fails with its own
/// error, and every other rank with `OtherRank` naming it (none hangs).
#[test]
fn rank_terms_sum_to_the_serial_terms() {
    if std::env::var_os(CHILD).is_some() {
        return rank_terms_child();
    }
    for (n, text) in on_1_to_4_ranks("rank_terms_sum_to_the_serial_terms", "rank terms:") {
        if let Some(points) = text
            .lines()
            .find_map(|l| l.find("rank point fields:").map(|k| &l[k..]))
        {
            eprintln!("mpirun -n {n}: {points}");
        }
        if let Some(moved) = text
            .lines()
            .find_map(|l| l.find("rank move:").map(|k| &l[k..]))
        {
            eprintln!("mpirun -n {n}: {moved}");
        }
        assert_eq!(
            text.matches("refused on every rank").count(),
            4 * n,
            "every rank saw the bad input refused:\n{text}"
        );
    }
}

/// This test binary's test `name` under `mpirun -n n` (with [`CHILD`] set), which must
/// succeed within 5 minutes (a rank that fails while the others wait in a collective
/// would otherwise hang the suite); its stdout and stderr.
fn child_on(n: usize, name: &str) -> String {
    let mut cmd = Command::new("timeout");
    cmd.args(["300", "mpirun", "--oversubscribe", "-n", &n.to_string()])
        .arg(std::env::current_exe().unwrap())
        .args(["--exact", name, "--nocapture", "--test-threads=1"])
        .env(CHILD, "1")
        .env("RAYON_NUM_THREADS", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1");
    let out = cmd.output().expect("mpirun");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{n} ranks:\n{text}");
    text
}

/// Test `name` under `mpirun -n 1..4` ([`child_on`]): per rank count its output, after
/// printing the line that `prefix` starts (rank 0's summary; libtest prints the test's
/// name first, on the same line).
fn on_1_to_4_ranks(name: &str, prefix: &str) -> Vec<(usize, String)> {
    (1..=4)
        .map(|n| {
            let text = child_on(n, name);
            let line = text
                .lines()
                .find_map(|l| l.find(prefix).map(|k| &l[k..]))
                .unwrap_or_else(|| panic!("no `{prefix}` line on {n} ranks:\n{text}"));
            eprintln!("mpirun -n {n}: {line}");
            (n, text)
        })
        .collect()
}

/// The host field `f` by dof: the value at the node whose dof is each d.
fn by_dof(m: &Mesh, f: impl Fn([f64; 3]) -> f64) -> Vec<f64> {
    let n = m.coords.len();
    (0..n)
        .map(|d| f(m.coords[(0..n).find(|&g| dof_of(g, n) == d).unwrap()]))
        .collect()
}

/// The serial embedding of all of `m` and this rank's embedding of its slab of elements,
/// each with `interactions()` added and searched, and the rank's local nodes (by global
/// number).
fn serial_and_rank(
    world: &mpi::topology::SimpleCommunicator,
    m: &Mesh,
    interactions: impl Fn() -> Vec<seam::embed::Interaction>,
) -> (
    seam::embed::Embedding,
    seam::embed::RankEmbedding,
    Vec<usize>,
) {
    use mpi::traits::Communicator;
    let (rank, size, n_elems) = (world.rank() as usize, world.size() as usize, m.num_elems());
    let all: Vec<usize> = (0..n_elems).collect();
    let mut serial = builder_of(m, &all).0.build().expect("serial build");
    for i in interactions() {
        serial.add_interaction(i).expect("serial interaction");
    }
    serial.search().expect("serial search");
    let mine: Vec<usize> = (n_elems * rank / size..n_elems * (rank + 1) / size).collect();
    let (b, nodes) = builder_of(m, &mine);
    let gids: Vec<u64> = nodes.iter().map(|&g| g as u64).collect();
    let mut e = b
        .build_on_ranks(world.duplicate(), &gids)
        .expect("rank build");
    for i in interactions() {
        e.add_interaction(i).expect("rank interaction");
    }
    e.search().expect("rank search");
    (serial, e, nodes)
}

fn rank_terms_child() {
    use mpi::traits::{Communicator, CommunicatorCollectives};
    let universe = mpi::initialize().expect("MPI");
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let m = bricks();
    let (n_nodes, n_elems) = (m.coords.len(), m.num_elems());
    let u = by_dof(&m, field);

    // The serial embedding of the whole mesh.
    let all: Vec<usize> = (0..n_elems).collect();
    let mut serial = builder_of(&m, &all).0.build().expect("serial build");
    for i in interactions() {
        serial.add_interaction(i).expect("serial interaction");
    }
    serial.search().expect("serial search");
    let want = serial.contributions(&u).expect("serial terms");

    // This rank's slab of elements.
    let mine: Vec<usize> = (n_elems * rank / size..n_elems * (rank + 1) / size).collect();
    let (b, nodes) = builder_of(&m, &mine);
    let gids: Vec<u64> = nodes.iter().map(|&g| g as u64).collect();
    let mut e = b
        .clone()
        .build_on_ranks(world.duplicate(), &gids)
        .expect("rank build");
    for i in interactions() {
        e.add_interaction(i).expect("rank interaction");
    }
    e.search().expect("rank search");
    let u_local: Vec<f64> = nodes.iter().map(|&g| field(m.coords[g])).collect();
    let got = e.contributions(&u_local).expect("rank terms");
    let (diff, scale, heat_diff) = summed_difference(&world, &want, &got, n_nodes);
    let heat_scale = want.heat[0].unwrap().side_a.abs();
    if rank == 0 {
        println!(
            "rank terms: max |Δ| of the summed Jacobian, residual and load {diff:.2e} (of {scale:.3e}), max |Δheat| {heat_diff:.2e} W (of {heat_scale:.3e}), points paired across ranks {}",
            e.points_across()
        );
    }
    assert!(diff <= 1e-12 * scale, "terms differ by {diff:e}");
    assert!(
        heat_diff <= 1e-12 * heat_scale,
        "heat differs by {heat_diff:e}"
    );
    if size > 1 {
        assert!(e.points_across() > 0, "pairs straddle ranks");
    }

    // Each rank's own points' values, the gap conductance's and the periodic tie's: the
    // serial embedding's at the same places, and every point on exactly one rank.
    let mut point_diff = 0.0f64;
    for i in 0..2 {
        let whole = serial.point_fields(i, &u).expect("serial point fields");
        let own = e.point_fields(i, &u_local).expect("rank point fields");
        point_diff = point_diff.max(own_points_are_the_serial_ones(
            &world,
            n_elems,
            &whole,
            &own,
            &format!("interaction {i}"),
        ));
        assert!(whole.iter().any(|p| p.paired));
        // The pairing's coverage: the whole interaction's, on every rank.
        let (c, w) = (e.coverage(i).unwrap(), serial.coverage(i).unwrap());
        assert_eq!(
            (c.points, c.paired_points, c.unpaired.len()),
            (w.points, w.paired_points, w.unpaired.len()),
            "interaction {i}: coverage"
        );
        assert!(
            (c.area - w.area).abs() <= 1e-12 * w.area
                && (c.paired_area - w.paired_area).abs() <= 1e-12 * w.area,
            "interaction {i}: {c:?} against {w:?}"
        );
        let whole = serial.face_fields(i, &u, true).expect("serial face fields");
        let own = e.face_fields(i, &u_local, true).expect("rank face fields");
        point_diff = point_diff.max(own_faces_are_the_serial_ones(
            &world,
            n_elems,
            &whole,
            &own,
            &format!("interaction {i}"),
        ));
    }
    if rank == 0 {
        println!(
            "rank point fields: largest flux difference, at points and faces, {point_diff:.1e} of the largest flux"
        );
    }

    // Brick a stretched by 2 % in y (its faces' areas change), brick b stretched by
    // 10 % in x, slid by 0.05 in y and drawn back by 0.01 (its gradients change), on
    // every rank and in the serial embedding: the pairings kept, the points placed
    // again, the terms again the serial ones (and not those before the move).
    let moved = |g: usize| {
        let x = m.coords[g];
        if g >= NODES_A {
            [1.01 + 1.1 * (x[0] - 1.0), x[1] + 0.05, x[2]]
        } else {
            [x[0], 1.02 * x[1], x[2]]
        }
    };
    let serial_nodes = builder_of(&m, &all).1;
    let moved_serial: Vec<[f64; 3]> = serial_nodes.iter().map(|&g| moved(g)).collect();
    serial.move_nodes(&moved_serial).expect("serial move");
    let want_moved = serial
        .contributions(&u)
        .expect("serial terms after the move");
    let moved_local: Vec<[f64; 3]> = nodes.iter().map(|&g| moved(g)).collect();
    e.move_nodes(&moved_local).expect("rank move");
    let got_moved = e
        .contributions(&u_local)
        .expect("rank terms after the move");
    let (moved_diff, _, dq_moved) = summed_difference(&world, &want_moved, &got_moved, n_nodes);
    let (serial_moved, serial_dense) = (dense(&want_moved, n_nodes), dense(&want, n_nodes));
    let moved_by =
        (serial_moved.iter().zip(&serial_dense)).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
    if rank == 0 {
        println!(
            "rank move: max |Δ| of the summed terms after the move {moved_diff:.2e} (the move changed them by {moved_by:.2e}), |Δheat| {dq_moved:.2e} W"
        );
    }
    assert!(
        moved_diff <= 1e-12 * scale,
        "terms after the move differ by {moved_diff:e}"
    );
    assert!(moved_by > 1e-3 * scale, "the move changes the terms");
    assert!(
        dq_moved <= 1e-12 * heat_scale,
        "heat after the move differs by {dq_moved:e}"
    );

    // The same interface from a deck: the same heat as the serial embedding's deck; a
    // deck with a mortar tie is taken (its rows: `rank_tie_rows_are_the_serial_rows`).
    let deck = |enforcement: &str| {
        format!(
            "begin contact definition bricks\n  contact surface ra contains right\n  contact surface lb contains left\n  begin interaction\n    side a ra\n    side b lb\n  end\n  begin enforcement\n{enforcement}  end\nend\n"
        )
    };
    let gap = deck(
        "    enforcement for energy = gap_conductance\n    gap conductance coefficient = constant h = 50\n",
    );
    let mut serial = builder_of(&m, &all).0.build().unwrap();
    serial.add_deck("bricks.i", &gap).expect("serial deck");
    serial.search().unwrap();
    let want = serial.heat(&u).unwrap()[0].unwrap();
    let mut e = b.clone().build_on_ranks(world.duplicate(), &gids).unwrap();
    let tie =
        deck("    enforcement for energy = tied\n    side b variable temperature to temperature\n");
    assert_eq!(e.add_deck("tied.i", &tie).expect("tie deck"), vec![0]);
    assert_eq!(e.add_deck("bricks.i", &gap).expect("rank deck"), vec![1]);
    e.search().unwrap();
    let got = e.contributions(&u_local).unwrap().heat[1].unwrap();
    assert!(
        (want.side_a - got.side_a).abs() <= 1e-12 * want.side_a.abs(),
        "deck heat {} against serial {}",
        got.side_a,
        want.side_a
    );

    // The same deck from a file every rank reads: the same heat; a file the last rank
    // cannot read fails every rank.
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("mpi-embed-deck-{size}"));
    if rank == 0 {
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("bricks.i"), &gap).unwrap();
    }
    world.barrier();
    let mut from_file = b.clone().build_on_ranks(world.duplicate(), &gids).unwrap();
    let added = from_file.add_deck_file(&dir.join("bricks.i"));
    assert_eq!(added.expect("deck file"), vec![0]);
    from_file.search().unwrap();
    let got = from_file.contributions(&u_local).unwrap().heat[0].unwrap();
    assert!(
        (want.side_a - got.side_a).abs() <= 1e-12 * want.side_a.abs(),
        "deck file heat {} against serial {}",
        got.side_a,
        want.side_a
    );
    let unreadable = dir.join(if rank == size - 1 {
        "missing.i"
    } else {
        "bricks.i"
    });
    refused_everywhere(
        rank,
        size - 1,
        from_file.add_deck_file(&unreadable).map(|_| ()),
        "missing.i",
    );

    // The last rank gives a non-finite field at one of its interface nodes, then one
    // global id too few: it fails each time, the others hear of it.
    let last = size - 1;
    let mut bad_u = u_local.clone();
    if rank == last {
        let k = (0..nodes.len())
            .find(|&k| m.coords[nodes[k]][0] == 1.0)
            .expect("an interface node");
        bad_u[k] = f64::NAN;
    }
    refused_everywhere(
        rank,
        last,
        e.contributions(&bad_u).map(|_| ()),
        "not finite",
    );
    let short_coords = &moved_local[..moved_local.len() - usize::from(rank == last)];
    refused_everywhere(rank, last, e.move_nodes(short_coords), "coordinates for");
    let short = if rank == last {
        &gids[..gids.len() - 1]
    } else {
        &gids[..]
    };
    let built = b.build_on_ranks(world.duplicate(), short);
    refused_everywhere(rank, last, built.map(|_| ()), "global ids for");
    world.barrier();
}

/// Each of this rank's points `own` (of a slab partition of `n_elems` elements) against
/// the serial embedding's point `whole[point]`: the same place, weight and faces (a
/// rank's builder numbers its slab's elements from 0, so rank r's element k is the
/// serial element r's first + k), the flux, temperatures and multiplier within 1e-12 of
/// the largest flux; and over the ranks, every point once. Returns the largest flux
/// difference relative to the largest flux.
fn own_points_are_the_serial_ones(
    world: &mpi::topology::SimpleCommunicator,
    n_elems: usize,
    whole: &[seam::embed::PointValues],
    own: &[seam::embed::RankPoint],
    what: &str,
) -> f64 {
    use mpi::traits::Communicator;
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let q_scale = whole.iter().fold(0.0f64, |m, p| m.max(p.flux.abs()));
    let close = |a: f64, b: f64| a.is_nan() && b.is_nan() || (a - b).abs() <= 1e-12 * q_scale;
    let global = |r: usize, f: Option<seam::embed::HostFace>| {
        f.map(|f| (n_elems * r / size + f.element, f.side))
    };
    let mut count = vec![0.0; whole.len()];
    let mut worst = 0.0f64;
    for p in own {
        let (k, v) = (p.point, &p.values);
        let w = &whole[k];
        count[k] += 1.0;
        assert_eq!(
            (v.x, v.weight, v.paired, v.gap),
            (w.x, w.weight, w.paired, w.gap),
            "{what}, point {k}"
        );
        let b_rank = p.side_b_rank.unwrap_or(usize::MAX);
        assert_eq!(
            (global(rank, v.side_a), global(b_rank, v.side_b)),
            (global(0, w.side_a), global(0, w.side_b)),
            "{what}, point {k}: the faces"
        );
        let multiplier = |m: Option<f64>| m.unwrap_or(f64::NAN);
        assert!(
            close(v.flux, w.flux)
                && close(v.temp_a, w.temp_a)
                && close(v.temp_b, w.temp_b)
                && close(multiplier(v.multiplier), multiplier(w.multiplier)),
            "{what}, point {k}: {v:?} against {w:?}"
        );
        worst = worst.max((v.flux - w.flux).abs() / q_scale);
    }
    each_once(world, &count, &format!("{what}: every point"));
    worst
}

/// This rank's faces `own` against the serial embedding's `whole` (matched by the face's
/// serial element, side and surface side; rank r's element k is the serial element r's
/// first + k): every value within 1e-12 of the largest flux, and over the ranks, every
/// serial face once. Returns the largest flux difference relative to the largest flux.
fn own_faces_are_the_serial_ones(
    world: &mpi::topology::SimpleCommunicator,
    n_elems: usize,
    whole: &[seam::embed::FaceValues],
    own: &[seam::embed::FaceValues],
    what: &str,
) -> f64 {
    use mpi::traits::Communicator;
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let at: std::collections::HashMap<(usize, u8, u8), usize> = (whole.iter().enumerate())
        .map(|(j, f)| ((f.face.element, f.face.side, f.side), j))
        .collect();
    let q_scale = whole.iter().fold(0.0f64, |m, f| m.max(f.flux.abs()));
    let mut count = vec![0.0; whole.len()];
    let mut worst = 0.0f64;
    for f in own {
        let key = (n_elems * rank / size + f.face.element, f.face.side, f.side);
        let j = *at
            .get(&key)
            .unwrap_or_else(|| panic!("{what}: face {key:?} is not the serial embedding's"));
        let w = &whole[j];
        count[j] += 1.0;
        let near = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-12 * scale;
        assert!(
            near(f.area, w.area, w.area)
                && near(f.paired_area, w.paired_area, w.area)
                && near(f.fraction, w.fraction, 1.0)
                && near(f.gap, w.gap, 1.0)
                && near(f.flux, w.flux, q_scale),
            "{what}, face {key:?}: {f:?} against {w:?}"
        );
        worst = worst.max((f.flux - w.flux).abs() / q_scale);
    }
    each_once(world, &count, &format!("{what}: every face"));
    assert!(whole.iter().any(|f| f.paired_area > 0.0));
    worst
}

/// The ranks' terms `got` summed against the serial `want` (`n` dofs): the largest
/// difference of the dense Jacobian, residual and load, their largest magnitude, and
/// the largest difference of the heats (which come summed over the ranks already).
fn summed_difference(
    world: &mpi::topology::SimpleCommunicator,
    want: &seam::embed::Contributions,
    got: &seam::embed::Contributions,
    n: usize,
) -> (f64, f64, f64) {
    use mpi::traits::CommunicatorCollectives;
    let mine = dense(got, n);
    let mut summed = vec![0.0; mine.len()];
    world.all_reduce_into(
        &mine[..],
        &mut summed[..],
        mpi::collective::SystemOperation::sum(),
    );
    let serial = dense(want, n);
    let scale = serial.iter().fold(0.0f64, |s, v| s.max(v.abs()));
    let diff = (serial.iter().zip(&summed)).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
    let mut heat_diff = 0.0f64;
    assert_eq!(want.heat.len(), got.heat.len());
    for (w, g) in want.heat.iter().zip(&got.heat) {
        let (w, g) = (w.unwrap_or_default(), g.unwrap_or_default());
        heat_diff = heat_diff
            .max((w.side_a - g.side_a).abs())
            .max((w.side_b - g.side_b).abs());
    }
    (diff, scale, heat_diff)
}

/// Dense `n × n` Jacobian and residual and load vectors of a rank's CSR evaluation.
fn dense_csr(e: &seam::embed::RankEvaluation, n: usize) -> Vec<f64> {
    let mut out = vec![0.0; n * n + 2 * n];
    for (r, &row) in e.rows.iter().enumerate() {
        for k in e.row_offsets[r]..e.row_offsets[r + 1] {
            out[row * n + e.columns[k]] += e.values[k];
        }
        out[n * n + row] += e.residual[r];
        out[n * n + n + row] += e.load[r];
    }
    out
}

/// Under `mpirun -n 1..4`: each rank's CSR evaluation (`RankEmbedding::evaluate`) of the
/// bricks' gap conductance and periodic tie, summed over the ranks, is the serial
/// embedding's CSR evaluation, with the heats; its rows are sorted and its columns sorted
/// within each row; a second evaluation at another field keeps the rows, columns and
/// pattern number and refreshes the values; a move makes a new pattern.
#[test]
fn rank_csr_sums_to_the_serial_csr() {
    if std::env::var_os(CHILD).is_some() {
        return rank_csr_child();
    }
    on_1_to_4_ranks("rank_csr_sums_to_the_serial_csr", "rank csr:");
}

fn rank_csr_child() {
    use mpi::traits::{Communicator, CommunicatorCollectives};
    let universe = mpi::initialize().expect("MPI");
    let world = universe.world();
    let rank = world.rank() as usize;
    let m = bricks();
    let n = m.coords.len();
    let other = |x: [f64; 3]| field(x) + 30.0 * x[1] * x[2];
    let (mut serial, mut e, nodes) = serial_and_rank(&world, &m, interactions);
    let summed = |got: &seam::embed::RankEvaluation| {
        let mine = dense_csr(got, n);
        let mut all = vec![0.0; mine.len()];
        world.all_reduce_into(
            &mine[..],
            &mut all[..],
            mpi::collective::SystemOperation::sum(),
        );
        all
    };
    let serial_dense = |ev: &seam::embed::Evaluation| {
        let mut out = vec![0.0; n * n + 2 * n];
        for i in 0..n {
            for k in ev.jacobian.row_offsets[i]..ev.jacobian.row_offsets[i + 1] {
                out[i * n + ev.jacobian.columns[k]] += ev.jacobian.values[k];
            }
            out[n * n + i] = ev.residual[i];
            out[n * n + n + i] = ev.load[i];
        }
        out
    };
    let mut worst = 0.0f64;
    let mut first = None;
    for f in [&field as &dyn Fn([f64; 3]) -> f64, &other] {
        let (u, u_local) = (
            by_dof(&m, f),
            nodes.iter().map(|&g| f(m.coords[g])).collect::<Vec<_>>(),
        );
        let want = serial.evaluate(&u).expect("serial csr").clone();
        let got = e.evaluate(&u_local).expect("rank csr").clone();
        assert!(got.rows.is_sorted() && got.rows.windows(2).all(|w| w[0] < w[1]));
        for r in 0..got.rows.len() {
            let cols = &got.columns[got.row_offsets[r]..got.row_offsets[r + 1]];
            assert!(cols.windows(2).all(|w| w[0] < w[1]), "row {r}'s columns");
        }
        let (w, g) = (serial_dense(&want), summed(&got));
        let scale = w.iter().fold(0.0f64, |s, v| s.max(v.abs()));
        let diff = (w.iter().zip(&g)).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
        assert!(
            diff <= 1e-12 * scale,
            "the CSR terms differ by {diff:e} (of {scale:e})"
        );
        worst = worst.max(diff / scale);
        let (hw, hg) = (want.heat[0].unwrap(), got.heat[0].unwrap());
        assert!(
            (hw.side_a - hg.side_a).abs() <= 1e-12 * hw.side_a.abs(),
            "{hw:?} {hg:?}"
        );
        // The second field: the same rows, columns and pattern, other values.
        match &first {
            None => first = Some(got),
            Some(f) => {
                assert_eq!(
                    (&f.rows, &f.row_offsets, &f.columns),
                    (&got.rows, &got.row_offsets, &got.columns)
                );
                assert_eq!(f.pattern, got.pattern);
                assert!(
                    f.residual != got.residual || got.rows.is_empty(),
                    "values refreshed"
                );
            }
        }
    }
    let before = first.unwrap().pattern;
    let local: Vec<[f64; 3]> = nodes.iter().map(|&g| m.coords[g]).collect();
    e.move_nodes(&local).expect("rank move");
    let u_local: Vec<f64> = nodes.iter().map(|&g| field(m.coords[g])).collect();
    let after = e.evaluate(&u_local).expect("rank csr after a move").pattern;
    assert_ne!(after, before, "a move makes a new pattern");
    if rank == 0 {
        println!(
            "rank csr: summed over the ranks, max |Δ| from the serial CSR {worst:.1e} of the largest entry, at two fields; rows on rank 0 {}",
            e.evaluation().unwrap().rows.len()
        );
    }
}

/// Under `mpirun -n 1..4`: the per-rank setters against the serial embedding's, on the
/// bricks' gap conductance with a host model whose h grows with the time and fails where
/// y < 0.3 from t = 1 on. At t = 2 with quarantine on, the ranks' summed terms and heat
/// are the serial ones (and not those at t = 0); the points the ranks quarantined are
/// the serial ones, each on one rank; switched off, the interaction adds nothing on any
/// rank, as serially. A time that differs between ranks is refused on every rank.
#[test]
fn rank_setters_equal_the_serial_ones() {
    if std::env::var_os(CHILD).is_some() {
        return rank_setters_child();
    }
    for (n, text) in on_1_to_4_ranks("rank_setters_equal_the_serial_ones", "rank setters:") {
        if n > 1 {
            assert_eq!(
                text.matches("refused on every rank (set_time)").count(),
                n,
                "every rank refused the times that differ:\n{text}"
            );
        }
    }
}

fn rank_setters_child() {
    use mpi::traits::{Communicator, CommunicatorCollectives};
    use seam::embed::{Conductance, FnConductance, Interaction, Model};
    use std::sync::Arc;
    let universe = mpi::initialize().expect("MPI");
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let m = bricks();
    let n_nodes = m.coords.len();
    let u = by_dof(&m, field);
    let model = || {
        let h = FnConductance::new("h of t", false, |s: &seam::embed::PointState| {
            if s.time >= 1.0 && s.x[1] < 0.3 {
                return Err(format!("no data below y = 0.3 at t = {}", s.time));
            }
            Ok(Conductance {
                h: H * (1.0 + s.time) * (1.0 + s.pressure / P0),
                ..Conductance::default()
            })
        });
        Interaction::new("right", "left", Model::GapConductance { h: H })
            .conductance(Arc::new(h))
            .quarantine()
    };
    let (mut serial, mut e, nodes) = serial_and_rank(&world, &m, || vec![model()]);
    let at_zero = serial.contributions(&u).expect("serial terms at t = 0");
    serial.set_time(2.0).expect("serial time");
    let want = serial.contributions(&u).expect("serial terms at t = 2");
    let kept = serial.quarantined(0);

    let u_local: Vec<f64> = nodes.iter().map(|&g| field(m.coords[g])).collect();
    e.set_time(2.0).expect("rank time");
    assert_eq!(e.time(), 2.0);
    let got = e.contributions(&u_local).expect("rank terms at t = 2");
    let (diff, scale, heat_diff) = summed_difference(&world, &want, &got, n_nodes);
    let heat = want.heat[0].unwrap().side_a;
    let heat_then = at_zero.heat[0].unwrap().side_a;
    assert!(
        (heat - heat_then).abs() > 0.2 * heat_then.abs(),
        "h depends on t: {heat} W at t = 2 against {heat_then} at t = 0"
    );
    assert!(diff <= 1e-12 * scale, "terms at t = 2 differ by {diff:e}");
    assert!(
        heat_diff <= 1e-12 * heat.abs(),
        "heat differs by {heat_diff:e}"
    );

    // The quarantined points: the serial ones, each on one rank.
    assert!(!kept.is_empty(), "the model failed somewhere");
    let own = e.quarantined(0);
    assert_eq!(
        e.quarantined_count(0),
        kept.len(),
        "quarantined over the ranks"
    );
    let count: Vec<f64> = (kept.iter())
        .map(|q| f64::from(u8::from(own.iter().any(|o| o.x == q.x))))
        .collect();
    each_once(&world, &count, "a quarantined point");
    assert!(
        own.iter().all(|o| o.message.contains("below y = 0.3")),
        "{own:?}"
    );

    // Pressures at the points, from their positions: each rank gives its own points'.
    let pressure = |x: [f64; 3]| P0 * (0.5 + x[1] + x[2] * x[2]);
    let whole: Vec<f64> = (serial.point_fields(0, &u).expect("serial points").iter())
        .map(|p| pressure(p.x))
        .collect();
    serial
        .set_point_pressures(0, Some(whole))
        .expect("serial pressures");
    let own: Vec<f64> = (e.point_fields(0, &u_local).expect("rank points").iter())
        .map(|p| pressure(p.values.x))
        .collect();
    e.set_point_pressures(0, Some(&own))
        .expect("rank pressures");
    let (want_p, got_p) = (
        serial
            .contributions(&u)
            .expect("serial terms with pressures"),
        e.contributions(&u_local)
            .expect("rank terms with pressures"),
    );
    let (diff_p, scale_p, heat_diff_p) = summed_difference(&world, &want_p, &got_p, n_nodes);
    let heat_p = want_p.heat[0].unwrap().side_a;
    assert!(
        (heat_p - heat).abs() > 0.2 * heat.abs(),
        "h depends on the pressure: {heat_p} W against {heat} W without"
    );
    assert!(
        diff_p <= 1e-12 * scale_p,
        "terms with pressures differ by {diff_p:e}"
    );
    assert!(
        heat_diff_p <= 1e-12 * heat_p.abs(),
        "heat with pressures differs by {heat_diff_p:e}"
    );
    // One pressure short on the last rank that owns points: refused on every rank.
    let owner = if own.is_empty() { 0 } else { rank + 1 };
    let mut last_owner = 0;
    world.all_reduce_into(
        &owner,
        &mut last_owner,
        mpi::collective::SystemOperation::max(),
    );
    let short = match rank + 1 == last_owner {
        true => &own[..own.len() - 1],
        false => &own[..],
    };
    let r = e.set_point_pressures(0, Some(short));
    assert!(
        r.is_err(),
        "rank {rank}: one pressure short on rank {} accepted",
        last_owner - 1
    );

    // Switched off: nothing on any rank, as serially.
    serial.set_active(0, false).expect("serial off");
    e.set_active(0, false).expect("rank off");
    assert!(!e.is_active(0));
    let (want_off, got_off) = (
        serial.contributions(&u).expect("serial off terms"),
        e.contributions(&u_local).expect("rank off terms"),
    );
    let (diff_off, _, heat_off) = summed_difference(&world, &want_off, &got_off, n_nodes);
    assert!(got_off.jacobian.iter().all(|t| t.2 == 0.0) && diff_off == 0.0 && heat_off == 0.0);
    if rank == 0 {
        println!(
            "rank setters: at t = 2 max |Δ| of the summed terms {diff:.2e} (of {scale:.3e}), max |Δheat| {heat_diff:.2e} W of {heat:.4e} (at t = 0: {heat_then:.4e}), {} points quarantined as serially; with point pressures {diff_p:.2e} (of {scale_p:.3e}) and {heat_diff_p:.2e} W of {heat_p:.4e}; switched off: 0 W",
            kept.len()
        );
    }

    // Times that differ between ranks: refused on every rank, none left waiting.
    if size > 1 {
        let t = if rank + 1 == size { 3.0 } else { 2.0 };
        match e.set_time(t) {
            Err(err) => assert!(err.to_string().contains("different arguments"), "{err}"),
            Ok(()) => panic!("rank {rank}: times that differ accepted"),
        }
        println!("rank {rank}: refused on every rank (set_time)");
    }
}

/// `count` (this rank's count of each item) summed over the ranks is 1 for every item.
fn each_once(world: &mpi::topology::SimpleCommunicator, count: &[f64], what: &str) {
    use mpi::traits::CommunicatorCollectives;
    let mut counted = vec![0.0; count.len()];
    world.all_reduce_into(
        count,
        &mut counted[..],
        mpi::collective::SystemOperation::sum(),
    );
    assert!(counted.iter().all(|&c| c == 1.0), "{what} on one rank");
}

/// `r` failed on rank `last` with a message holding `what`, and on every other rank
/// with `OtherRank` naming `last`; each rank says so once.
fn refused_everywhere(
    rank: usize,
    last: usize,
    r: Result<(), seam::embed::EmbedError>,
    what: &str,
) {
    use seam::embed::EmbedError;
    match r {
        Err(EmbedError::OtherRank { rank: r }) if rank != last => assert_eq!(r, last),
        Err(e) if rank == last => assert!(e.to_string().contains(what), "{e}"),
        other => panic!("rank {rank}: expected a refusal ({what}), got {other:?}"),
    }
    println!("rank {rank}: refused on every rank ({what})");
}

/// Under `mpirun -n 1..4`: a mortar tie of a's x = 1 face (side A, 4 × 4 faces) to b's
/// (5 × 3), with a's nodes on the edge y = 0 of it fixed (each rank fixing those it
/// holds, so the crosspoints lie across the slabs' boundaries), standard and dual
/// multipliers. Each multiplier's row comes from one rank only, and the ranks' rows
/// together (by the multiplier's side-A dof) are the serial embedding's: `C`, `g`, the
/// dual tie's condensed rows, the crosspoints, and the heat for the same multipliers.
#[test]
fn rank_tie_rows_are_the_serial_rows() {
    if std::env::var_os(CHILD).is_some() {
        return rank_ties_child();
    }
    for n in 1..=4 {
        let text = child_on(n, "rank_tie_rows_are_the_serial_rows");
        let line = text
            .lines()
            .find_map(|l| l.find("rank ties:").map(|k| &l[k..]))
            .unwrap_or_else(|| panic!("no summary line on {n} ranks:\n{text}"));
        eprintln!("mpirun -n {n}: {line}");
        assert_eq!(
            text.matches("refused on every rank").count(),
            3 * n,
            "every rank saw the short multipliers refused, for both ties, and the dual tie's short residual:\n{text}"
        );
    }
}

fn rank_ties_child() {
    use mpi::collective::SystemOperation;
    use mpi::traits::{Communicator, CommunicatorCollectives};
    use seam::embed::{Interaction, Model, Multipliers};
    let universe = mpi::initialize().expect("MPI");
    let world = universe.world();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let m = bricks();
    let (n_nodes, n_elems) = (m.coords.len(), m.num_elems());
    // Brick a's nodes come first (the generator numbers box by box).
    let fixed = |g: usize| g < NODES_A && m.coords[g][0] == 1.0 && m.coords[g][1] == 0.0;
    let all: Vec<usize> = (0..n_elems).collect();
    let mine: Vec<usize> = (n_elems * rank / size..n_elems * (rank + 1) / size).collect();
    let sum = |v: &[f64]| {
        let mut out = vec![0.0; v.len()];
        world.all_reduce_into(v, &mut out[..], SystemOperation::sum());
        out
    };
    let mut report = String::new();
    for multipliers in [Multipliers::Standard, Multipliers::Dual] {
        let tie = || Interaction::new("right", "left", Model::TiedMortar { multipliers });
        let (b, serial_nodes) = builder_of(&m, &all);
        let local_fixed: Vec<usize> = (0..serial_nodes.len())
            .filter(|&k| fixed(serial_nodes[k]))
            .collect();
        let mut serial = b.fixed_nodes(&local_fixed).build().expect("serial build");
        serial.add_interaction(tie()).unwrap();
        serial.search().unwrap();
        let want = serial.constraints().expect("serial rows").remove(0);

        let (b, nodes) = builder_of(&m, &mine);
        let local_fixed: Vec<usize> = (0..nodes.len()).filter(|&k| fixed(nodes[k])).collect();
        let gids: Vec<u64> = nodes.iter().map(|&g| g as u64).collect();
        let mut e = (b.fixed_nodes(&local_fixed))
            .build_on_ranks(world.duplicate(), &gids)
            .expect("rank build");
        assert_eq!(e.add_interaction(tie()).unwrap(), 0);
        e.search().unwrap();
        let got = e.constraints().expect("rank rows").remove(0);
        assert_eq!(
            got.total,
            want.multiplier_dofs.len(),
            "multipliers in the tie"
        );
        assert_eq!(got.index.len(), got.rows.multiplier_dofs.len());

        // Rows by the multiplier's side-A dof: [C row (n), g, count, condensed constant,
        // condensed row (n), condensed count].
        let width = 2 * n_nodes + 4;
        let dense = |t: &seam::embed::TieConstraints| {
            let mut out = vec![0.0; n_nodes * width];
            for (k, &d) in t.multiplier_dofs.iter().enumerate() {
                out[d * width + n_nodes] = t.rhs[k];
                out[d * width + n_nodes + 1] += 1.0;
            }
            for &(k, j, c) in &t.entries {
                out[t.multiplier_dofs[k] * width + j] += c;
            }
            for c in &t.condensed {
                let row = &mut out[c.dof * width..(c.dof + 1) * width];
                row[n_nodes + 2] = c.constant;
                row[2 * n_nodes + 3] += 1.0;
                for &(j, v) in &c.terms {
                    row[n_nodes + 3 + j] += v;
                }
            }
            out
        };
        let summed = sum(&dense(&got.rows));
        let serial_dense = dense(&want);
        // The scale of the entries of C and of the condensed rows, not of the counts.
        let scale = (serial_dense.chunks(width))
            .flat_map(|row| {
                row[..n_nodes]
                    .iter()
                    .chain(&row[n_nodes + 3..2 * n_nodes + 3])
            })
            .fold(0.0f64, |s, v| s.max(v.abs()));
        let diff =
            (serial_dense.iter().zip(&summed)).fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
        assert!(
            diff <= 1e-12 * scale,
            "{multipliers:?}: rows differ by {diff:e}"
        );
        // (The counts are in the rows: a multiplier or condensed row on two ranks
        // would count 2.)
        if multipliers == Multipliers::Dual {
            assert_eq!(want.condensed.len(), want.multiplier_dofs.len());
        }

        // The crosspoints, by global node.
        let mut cross = vec![0.0; n_nodes];
        for &g in &got.rows.crosspoints {
            cross[g] += 1.0;
        }
        let cross = sum(&cross);
        let mut want_cross = vec![0.0; n_nodes];
        for &k in &want.crosspoints {
            want_cross[serial_nodes[k]] += 1.0;
        }
        assert!(
            !want.crosspoints.is_empty(),
            "the fixed edge makes crosspoints"
        );
        assert_eq!(cross, want_cross, "{multipliers:?}: crosspoints");

        // The heat for multipliers λ(dof) = 1 + dof / 100.
        let lambda = |dofs: &[usize]| dofs.iter().map(|&d| 1.0 + d as f64 / 100.0).collect();
        let lambda_serial: Vec<f64> = lambda(&want.multiplier_dofs);
        let heat_serial = want.heat(&lambda_serial).unwrap();
        let lambda_rank: Vec<f64> = lambda(&got.rows.multiplier_dofs);
        let heat = e.tie_heat(&got.rows, &lambda_rank).unwrap();
        // The lowest rank owning multipliers gives one too few: refused there, and on
        // every other rank, none left waiting in the sum.
        let mine = if got.index.is_empty() { size } else { rank };
        let mut bad = size;
        world.all_reduce_into(&mine, &mut bad, SystemOperation::min());
        let short = &lambda_rank[..lambda_rank.len() - usize::from(rank == bad)];
        refused_everywhere(
            rank,
            bad,
            e.tie_heat(&got.rows, short).map(|_| ()),
            "multipliers given",
        );
        let dq = (heat.side_a - heat_serial.side_a)
            .abs()
            .max((heat.side_b - heat_serial.side_b).abs());
        assert!(
            dq <= 1e-12 * heat_serial.side_a.abs(),
            "{multipliers:?}: heat {dq:e}"
        );
        // The multiplier field at each rank's own points: its faces' multipliers come
        // from whichever ranks own them.
        let whole = serial.tie_point_fields(&want, &lambda_serial).unwrap();
        let own = e.tie_point_fields(&got.rows, &lambda_rank).unwrap();
        let field_diff = own_points_are_the_serial_ones(
            &world,
            n_elems,
            &whole,
            &own,
            &format!("{multipliers:?}"),
        );
        assert!(whole.iter().any(|p| p.multiplier.is_some()));
        let whole = serial.tie_face_fields(&want, &lambda_serial, true).unwrap();
        let own = e.tie_face_fields(&got.rows, &lambda_rank, true).unwrap();
        let field_diff = field_diff.max(own_faces_are_the_serial_ones(
            &world,
            n_elems,
            &whole,
            &own,
            &format!("{multipliers:?} faces"),
        ));
        report += &format!(
            " {multipliers:?}: {} multipliers, max |Δ| of the rows {diff:.1e} (of {scale:.2e}), |Δheat| {dq:.1e} W (of {:.3e}), multiplier field at the points {field_diff:.1e};",
            got.total,
            heat_serial.side_a.abs()
        );
        if multipliers == Multipliers::Dual {
            // A host that condensed the tie: its multipliers from its residual
            // r(dof) = sin(dof) (any vector), the serial from the whole of it, each rank
            // from its value at its own multipliers' dofs.
            let r = |d: usize| (d as f64).sin();
            let whole: Vec<f64> = (0..n_nodes).map(r).collect();
            let lambda_serial = want.dual_multipliers(&whole).unwrap();
            let at: Vec<f64> = got.rows.multiplier_dofs.iter().map(|&d| r(d)).collect();
            let lambda_rank = got.rows.dual_multipliers_at(&at).unwrap();
            let mut by_dof = vec![0.0; n_nodes];
            for (&d, l) in got.rows.multiplier_dofs.iter().zip(&lambda_rank) {
                by_dof[d] += l;
            }
            let by_dof = sum(&by_dof);
            let dl = (want.multiplier_dofs.iter().zip(&lambda_serial))
                .fold(0.0f64, |m, (&d, l)| m.max((by_dof[d] - l).abs()));
            assert!(dl <= 1e-12, "dual multipliers differ by {dl:e}");
            let (q_serial, q_rank) = (
                want.heat(&lambda_serial).unwrap().side_a,
                e.tie_heat(&got.rows, &lambda_rank).unwrap().side_a,
            );
            assert!(
                (q_serial - q_rank).abs() <= 1e-12 * q_serial.abs().max(1.0),
                "heat from the dual multipliers {q_rank} against {q_serial}"
            );
            // The heat straight from the residual; a residual one value short on the
            // rank refused above is refused on every rank.
            let from_residual = e.dual_tie_heat(&got.rows, &at).unwrap();
            let want_q = want.heat(&lambda_serial).unwrap();
            let dq = (from_residual.side_a - want_q.side_a)
                .abs()
                .max((from_residual.side_b - want_q.side_b).abs());
            assert!(
                dq <= 1e-12 * want_q.side_a.abs().max(1.0),
                "dual heat from the residual off by {dq:e}"
            );
            let short = &at[..at.len() - usize::from(rank == bad)];
            refused_everywhere(
                rank,
                bad,
                e.dual_tie_heat(&got.rows, short).map(|_| ()),
                "residual values given",
            );
            report += &format!(
                " dual multipliers from the residual: max |Δλ| {dl:.1e}, |Δheat| {dq:.1e} W;"
            );
        }
        if size > 1 {
            assert!(e.points_across() > 0, "pairs straddle ranks");
        }
    }
    if rank == 0 {
        println!("rank ties:{report}");
    }
    world.barrier();
}
