//! The bundled scenes in `examples/`: each runs as `seam run examples/<scene>/problem.toml`
//! does and is checked against a physics invariant (a reference solution, a periodicity,
//! a heat balance), with its tolerance and the reason for it.
//!
//! Each scene is copied into a scratch folder of its own under `$CARGO_TARGET_TMPDIR`
//! and run there, so the results (`out/`) stay out of the source tree. Heat flows are
//! integrated here from the nodal temperatures, independently of seam's assembly: a
//! 2 × 2 Gauss rule on each bilinear face (exact for h (T − T∞) on the flat faces these
//! meshes have) and a 2 × 2 × 2 rule for element volumes (exact for trilinear hexes).
//!
//! The balances hold to round-off in the discrete problem itself: conduction rows of a
//! conforming element sum to zero, and seam integrates sources, fluxes and convection
//! exactly for these fields, so the heat put in equals the heat taken out up to the
//! Newton tolerance (1e-12 relative in the problem files) and round-off. 1e-9 relative
//! leaves three orders of margin for the conditioning of the solve.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use seam::mesh::{Mesh, NodeId, Side};
use seam::run::{RunError, RunResult};
use tempfile::TempDir;

/// Relative tolerance of every discrete heat balance (see the module comment).
const BALANCE: f64 = 1e-9;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh copy of the files (not the subdirectories) of `examples/<scene>`, in a
/// scratch folder removed when the returned value is dropped.
fn copy_scene(scene: &str) -> TempDir {
    copy_scene_as(scene, scene)
}

/// As [`copy_scene`], into a scratch folder named after `tag` (tests that copy the same
/// scene at the same time each get their own).
pub(crate) fn copy_scene_as(scene: &str, tag: &str) -> TempDir {
    let from = root().join("examples").join(scene);
    let to = crate::scratch(&format!("examples-{tag}"));
    for entry in std::fs::read_dir(&from).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, to.path().join(path.file_name().unwrap())).unwrap();
        }
    }
    to
}

fn run(problem: &Path) -> RunResult {
    match seam::run::run(problem) {
        Ok(r) => {
            assert!(
                r.summary.converged,
                "{} did not converge",
                problem.display()
            );
            r
        }
        Err(RunError::Input(d, s)) => panic!("{}: {}", problem.display(), d.render(&s)),
        Err(RunError::Solve(e)) => panic!("{}: {e}", problem.display()),
    }
}

/// The problem file as plain TOML, for the numbers the checks need.
/// A run by the `seam` binary in its own process: its mesh, its final temperatures
/// (from `results.exo` in `out`) and its `--json` summary.
struct Apart {
    mesh: Mesh,
    temperature: Vec<f64>,
    summary: serde_json::Value,
}

fn run_apart(dir: &Path, problem: &str, out: &str) -> Apart {
    let done = Command::new(env!("CARGO_BIN_EXE_seam"))
        .args(["run", problem, "--json"])
        .current_dir(dir)
        .output()
        .expect("seam runs");
    assert!(
        done.status.success(),
        "{problem}: {}",
        String::from_utf8_lossy(&done.stderr)
    );
    let summary: serde_json::Value = serde_json::from_slice(&done.stdout).unwrap();
    assert_eq!(summary["converged"], true, "{problem}");
    let results = dir.join(out).join("results.exo");
    let steps = seam::mesh::exodus::read_times(&results).unwrap().len();
    Apart {
        mesh: seam::mesh::read(&results).unwrap(),
        temperature: seam::mesh::exodus::read_nodal_variable(&results, "temperature", steps - 1)
            .unwrap(),
        summary,
    }
}

fn problem_table(path: &Path) -> toml::Table {
    toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// The `[[bc]]` on `surface`.
fn bc<'a>(problem: &'a toml::Table, surface: &str) -> &'a toml::Table {
    problem["bc"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_table().unwrap())
        .find(|b| b["surfaces"].as_array().unwrap()[0].as_str() == Some(surface))
        .unwrap_or_else(|| panic!("no [[bc]] on {surface}"))
}

fn number(v: &toml::Value) -> f64 {
    v.as_float()
        .or_else(|| v.as_integer().map(|i| i as f64))
        .unwrap()
}

fn sides<'a>(mesh: &'a Mesh, name: &str) -> &'a [Side] {
    let i = mesh
        .find_side_set(name)
        .unwrap_or_else(|| panic!("no side set {name}"));
    &mesh.side_sets[i].sides
}

fn side_node_set(mesh: &Mesh, name: &str) -> Vec<NodeId> {
    let mut nodes: Vec<NodeId> = sides(mesh, name)
        .iter()
        .flat_map(|&s| mesh.side_nodes(s))
        .collect();
    nodes.sort_unstable();
    nodes.dedup();
    nodes
}

const GAUSS_2: [f64; 2] = [-0.577_350_269_189_625_8, 0.577_350_269_189_625_8];

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn norm(a: [f64; 3]) -> f64 {
    (a[0] * a[0] + a[1] * a[1] + a[2] * a[2]).sqrt()
}

/// ∫ f(x, T) dA over the side sets' quadrilateral faces, T bilinear from the nodes.
fn face_integral(
    mesh: &Mesh,
    temperature: &[f64],
    side_set: &str,
    f: impl Fn([f64; 3], f64) -> f64,
) -> f64 {
    let mut total = 0.0;
    for &side in sides(mesh, side_set) {
        let nodes: Vec<NodeId> = mesh.side_nodes(side).collect();
        assert_eq!(nodes.len(), 4, "quadrilateral faces only");
        let x: Vec<[f64; 3]> = nodes.iter().map(|n| mesh.coords[n.index()]).collect();
        let t: Vec<f64> = nodes.iter().map(|n| temperature[n.index()]).collect();
        for xi in GAUSS_2 {
            for eta in GAUSS_2 {
                // Corners in cyclic order at (ξ, η) = (−,−), (+,−), (+,+), (−,+).
                let sx = [-1.0, 1.0, 1.0, -1.0];
                let sy = [-1.0, -1.0, 1.0, 1.0];
                let (mut p, mut dxi, mut deta, mut tq) = ([0.0; 3], [0.0; 3], [0.0; 3], 0.0);
                for a in 0..4 {
                    let n = 0.25 * (1.0 + sx[a] * xi) * (1.0 + sy[a] * eta);
                    let nxi = 0.25 * sx[a] * (1.0 + sy[a] * eta);
                    let neta = 0.25 * sy[a] * (1.0 + sx[a] * xi);
                    for d in 0..3 {
                        p[d] += n * x[a][d];
                        dxi[d] += nxi * x[a][d];
                        deta[d] += neta * x[a][d];
                    }
                    tq += n * t[a];
                }
                total += f(p, tq) * norm(cross(dxi, deta));
            }
        }
    }
    total
}

/// The area of a side set.
fn area(mesh: &Mesh, side_set: &str) -> f64 {
    face_integral(mesh, &vec![0.0; mesh.num_nodes()], side_set, |_, _| 1.0)
}

/// The volume of a block of Hex8 elements (2 × 2 × 2 Gauss: exact for trilinear maps).
fn volume(mesh: &Mesh, block: &str) -> f64 {
    let b = &mesh.blocks[mesh.find_block(block).unwrap()];
    let corners: [[f64; 3]; 8] = [
        [-1.0, -1.0, -1.0],
        [1.0, -1.0, -1.0],
        [1.0, 1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
        [1.0, -1.0, 1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
    ];
    let n_elems = b.connectivity.len() / 8;
    let mut total = 0.0;
    for e in 0..n_elems {
        let x: Vec<[f64; 3]> = b
            .elem_nodes(e)
            .iter()
            .map(|n| mesh.coords[n.index()])
            .collect();
        for q in GAUSS_2.iter().flat_map(|&a| {
            GAUSS_2
                .iter()
                .flat_map(move |&b| GAUSS_2.iter().map(move |&c| [a, b, c]))
        }) {
            let mut j = [[0.0; 3]; 3];
            for (c, xa) in corners.iter().zip(&x) {
                for r in 0..3 {
                    let mut dn = 0.125 * c[r];
                    for s in (0..3).filter(|&s| s != r) {
                        dn *= 1.0 + c[s] * q[s];
                    }
                    for d in 0..3 {
                        j[r][d] += dn * xa[d];
                    }
                }
            }
            total += dot(j[0], cross(j[1], j[2])).abs();
        }
    }
    total
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Nodes by position (keyed to cells of `1e-9 × scale`), to pair nodes of two meshes or
/// of two faces.
fn locate(coords: &[[f64; 3]], scale: f64) -> HashMap<[i64; 3], usize> {
    let key = |p: &[f64; 3]| p.map(|v| (v / (1e-9 * scale)).round() as i64);
    coords
        .iter()
        .enumerate()
        .map(|(i, p)| (key(p), i))
        .collect()
}

/// The node within about `1e-9 × scale` of `p` in each coordinate (its key's cell or a
/// neighbouring one, so a position near a cell's edge is still found).
fn find(index: &HashMap<[i64; 3], usize>, p: [f64; 3], scale: f64) -> Option<usize> {
    let key = p.map(|v| (v / (1e-9 * scale)).round() as i64);
    (-1..=1)
        .flat_map(|a| (-1..=1).flat_map(move |b| (-1..=1).map(move |c| [a, b, c])))
        .find_map(|d| index.get(&[key[0] + d[0], key[1] + d[1], key[2] + d[2]]))
        .copied()
}

fn spread(t: &[f64]) -> f64 {
    let (lo, hi) = t
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    hi - lo
}

/// Turbine sector: the 1/12 sector with cylindrical periodicity gives the full ring's
/// temperatures node by node, and the rim's heat leaves through the bore.
///
/// The ring mesh is the sector mesh turned 12 times, so the sector's nodes are ring
/// nodes; the cut faces match, and the mortar tie makes their temperatures equal node
/// for node. The sector's equations are then the ring's for its first 30° (the ring's
/// solution is periodic: its load and mesh are), so the two agree to round-off. The
/// tolerance, 1e-9 of the temperature spread, is the balance tolerance's reason again.
/// The load is not symmetric within the sector, so heat crosses the cut faces: a sector
/// with insulated cuts would not reproduce the ring, and this is checked to be the case
/// (the cut carries over 1 % of the rim's heat).
///
/// The two runs are `seam` processes of their own: two runs of this scene at once in one
/// process have disagreed (see `TURBINE_RUNS`), and what this test checks is the physics.
#[test]
fn turbine_sector_equals_the_full_ring() {
    let _turn = crate::TURBINE_RUNS
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let tmp = copy_scene("turbine_sector");
    let dir = tmp.path();
    let sector = run_apart(dir, "problem.toml", "out");
    let ring = run_apart(dir, "ring_problem.toml", "out/ring");
    let problem = problem_table(&dir.join("problem.toml"));

    // Node by node on the sector (positions keyed to 1e-9 of the outer radius).
    let r_out = ring
        .mesh
        .coords
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max);
    let index = locate(&ring.mesh.coords, r_out);
    let t_spread = spread(&ring.temperature);
    let mut worst: f64 = 0.0;
    for (i, p) in sector.mesh.coords.iter().enumerate() {
        let j =
            find(&index, *p, r_out).unwrap_or_else(|| panic!("sector node {p:?} not in the ring"));
        worst = worst.max((sector.temperature[i] - ring.temperature[j]).abs());
    }
    eprintln!(
        "turbine sector vs ring: worst nodal difference {worst:e} K of a {t_spread:.1} K spread"
    );
    assert!(
        worst <= 1e-9 * t_spread,
        "sector and ring differ by {worst:e} K (spread {t_spread} K)"
    );

    // The rim's flux, q(θ) = q0 (1 + 0.5 cos(12θ − 1)); seam evaluates it at each face's
    // centroid, so it is summed here the same way: one value per face times its area.
    let rim = bc(&problem, "rim");
    assert_eq!(
        rim["value"].as_str(),
        Some("5e4 * (1 + 0.5 * math.cos(12 * math.atan(y, x) - 1))"),
        "the check below restates the rim flux"
    );
    let q = |p: [f64; 3]| 5e4 * (1.0 + 0.5 * (12.0 * p[1].atan2(p[0]) - 1.0).cos());
    let rim_heat = |r: &Apart| -> f64 {
        sides(&r.mesh, "rim")
            .iter()
            .map(|&s| {
                let nodes: Vec<[f64; 3]> = r
                    .mesh
                    .side_nodes(s)
                    .map(|n| r.mesh.coords[n.index()])
                    .collect();
                let c = nodes.iter().fold([0.0; 3], |c, p| {
                    [c[0] + p[0] / 4.0, c[1] + p[1] / 4.0, c[2] + p[2] / 4.0]
                });
                let a = 0.5 * norm(cross(sub(nodes[2], nodes[0]), sub(nodes[3], nodes[1])));
                q(c) * a
            })
            .sum()
    };
    let bore = bc(&problem, "bore");
    let (h, t_inf) = (number(&bore["value"]), number(&bore["ambient"]));
    for (name, r, parts) in [("sector", &sector, 12.0), ("ring", &ring, 1.0)] {
        let heat_in = rim_heat(r);
        let heat_out = face_integral(&r.mesh, &r.temperature, "bore", |_, t| h * (t - t_inf));
        eprintln!(
            "turbine {name}: rim {heat_in:.6} W in, bore {heat_out:.6} W out (relative {:e}), ring total {:.6} W",
            (heat_in - heat_out).abs() / heat_in,
            heat_in * parts
        );
        assert!(
            (heat_in - heat_out).abs() <= BALANCE * heat_in,
            "{name}: {heat_in} W in, {heat_out} W out"
        );
    }
    let cut = &sector.summary["interactions"][0];
    let (cut_heat, cut_imbalance) = (
        cut["heat_side_a"].as_f64().unwrap(),
        cut["imbalance"].as_f64().unwrap(),
    );
    assert!(
        cut_heat.abs() > 0.01 * rim_heat(&sector),
        "the cut carries {cut_heat} W: the load should not be symmetric within the sector"
    );
    assert!(cut_imbalance.abs() <= BALANCE * cut_heat.abs());
}

/// Twisted channel: the outlet's temperatures equal the inlet's at the image under the
/// deck's Lua map (a quarter turn about the axis plus a translation by the length), and
/// the heat made in the bar and put through its heated face leaves by convection.
///
/// The section grid is symmetric under the quarter turn, so every outlet node has an
/// inlet node at its image and the mortar tie makes them equal to round-off: 1e-9 of the
/// temperature spread (the balance tolerance's reason). Pairing the outlet with the
/// inlet *without* the turn would miss by a good part of that spread, which is checked,
/// so the twist is what is tested.
#[test]
fn twisted_channel_is_periodic_under_its_lua_map() {
    let tmp = copy_scene("twisted_channel");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    let problem = problem_table(&dir.join("problem.toml"));
    let t = &r.solution.temperature;
    let length = r.mesh.coords.iter().map(|p| p[2]).fold(0.0, f64::max);
    let index = locate(&r.mesh.coords, length);
    let t_spread = spread(t);
    let outlet = side_node_set(&r.mesh, "outlet");
    let (mut worst, mut untwisted): (f64, f64) = (0.0, 0.0);
    for n in &outlet {
        let p = r.mesh.coords[n.index()];
        let image = find(&index, [-p[1], p[0], p[2] - length], length)
            .unwrap_or_else(|| panic!("no inlet node at the image of {p:?}"));
        let straight = find(&index, [p[0], p[1], p[2] - length], length).unwrap();
        worst = worst.max((t[n.index()] - t[image]).abs());
        untwisted = untwisted.max((t[n.index()] - t[straight]).abs());
    }
    eprintln!(
        "twisted channel: {} outlet nodes, worst |T(p) − T(map p)| {worst:e} K (untwisted pairs: {untwisted:.3} K) of a {t_spread:.2} K spread",
        outlet.len()
    );
    assert_eq!(outlet.len(), 49);
    assert!(worst <= 1e-9 * t_spread, "periodicity off by {worst:e} K");
    assert!(untwisted > 0.05 * t_spread, "the twist should matter");

    let source = number(&problem["source"].as_array().unwrap()[0]["value"]);
    let flux = number(&bc(&problem, "heated")["value"]);
    let cooled = bc(&problem, "cooled");
    let (h, t_inf) = (number(&cooled["value"]), number(&cooled["ambient"]));
    let heat_in = source * volume(&r.mesh, "bar") + flux * area(&r.mesh, "heated");
    let heat_out = face_integral(&r.mesh, t, "cooled", |_, t| h * (t - t_inf));
    let cut = &r.summary.interactions[0];
    eprintln!(
        "twisted channel: {heat_in:.9} W in, {heat_out:.9} W out (relative {:e}); {:.6} W through the periodic faces",
        (heat_in - heat_out).abs() / heat_in,
        cut.heat_side_a
    );
    assert!((heat_in - heat_out).abs() <= BALANCE * heat_in);
    assert!(cut.imbalance.abs() <= BALANCE * heat_in);
}

/// The library name the plugin scene's deck asks for, next to the deck.
pub(crate) const PLUGIN_LIBRARY: &str = "libseam_c_table.so";

/// Compile the C example plugin with `$CC` (default `cc`) and the CI flags into `dir`.
pub(crate) fn compile_c_table(dir: &Path) -> PathBuf {
    let out = dir.join(PLUGIN_LIBRARY);
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&compiler)
        .args([
            "-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-shared", "-fPIC",
        ])
        .arg("-I")
        .arg(root().join("plugins/include"))
        .arg(root().join("plugins/examples/c_table/c_table.c"))
        .arg("-o")
        .arg(&out)
        .status()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{compiler}`: {e}"));
    assert!(status.success(), "compiling the c_table plugin failed");
    out
}

/// The numbers after `keyword [=]` on the deck's line that starts with it.
fn deck_numbers(deck: &str, keyword: &str) -> Vec<f64> {
    let line = deck
        .lines()
        .map(str::trim)
        .find(|l| l.to_ascii_lowercase().starts_with(keyword))
        .unwrap_or_else(|| panic!("no `{keyword}` line"));
    line[keyword.len()..]
        .split(|c: char| c.is_whitespace() || c == '=')
        .filter(|w| !w.is_empty())
        .map(|w| w.parse().unwrap())
        .collect()
}

/// A piecewise-linear table (p0 h0 p1 h1 …) read at `p`, flat beyond its ends.
fn table_at(pairs: &[f64], p: f64) -> f64 {
    let points: Vec<(f64, f64)> = pairs.chunks(2).map(|c| (c[0], c[1])).collect();
    if p <= points[0].0 {
        return points[0].1;
    }
    for w in points.windows(2) {
        let ((p0, h0), (p1, h1)) = (w[0], w[1]);
        if p <= p1 {
            return h0 + (h1 - h0) * (p - p0) / (p1 - p0);
        }
    }
    points[points.len() - 1].1
}

/// Plugin conductance: the C table plugin is the interface conductance between two
/// plates with insulated sides, so the problem is one-dimensional: the heat is
/// A ΔT / (L_base/k_base + 1/h + L_cover/k_cover) with h the table's value at the deck's
/// contact pressure (read here from the deck's data), the interface jump is uniform and
/// h A (T_A − T_B) is the interface heat, and sides A and B carry opposite heats.
///
/// The exact field is linear in each plate, which trilinear hexes hold, and the
/// interface integrals are exact on the non-matching faces, so round-off is all that
/// is left: the balance tolerance, 1e-9 relative.
#[test]
fn plugin_conductance_carries_the_series_heat_flow() {
    let tmp = copy_scene("plugin_conductance");
    let dir = tmp.path();
    let deck = std::fs::read_to_string(dir.join("contact.i")).unwrap();
    assert!(deck.contains(&format!("\"{PLUGIN_LIBRARY}\"")));
    compile_c_table(dir);
    let r = run(&dir.join("problem.toml"));
    let problem = problem_table(&dir.join("problem.toml"));

    let h = table_at(
        &deck_numbers(&deck, "real data"),
        deck_numbers(&deck, "contact pressure")[0],
    );
    let k = |block: &str| {
        problem["material"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["blocks"].as_array().unwrap()[0].as_str() == Some(block))
            .map(|m| number(&m["conductivity"]))
            .unwrap()
    };
    let z_range = |block: &str| {
        let b = &r.mesh.blocks[r.mesh.find_block(block).unwrap()];
        b.connectivity
            .iter()
            .map(|n| r.mesh.coords[n.index()][2])
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), z| {
                (lo.min(z), hi.max(z))
            })
    };
    let (base_lo, base_hi) = z_range("base");
    let (cover_lo, cover_hi) = z_range("cover");
    assert_eq!(base_hi, cover_lo, "the plates touch");
    let t_hot = number(&bc(&problem, "base_bottom")["value"]);
    let t_cold = number(&bc(&problem, "cover_top")["value"]);
    let a = area(&r.mesh, "base_top");
    let flux = (t_hot - t_cold)
        / ((base_hi - base_lo) / k("base") + 1.0 / h + (cover_hi - cover_lo) / k("cover"));
    let expected = flux * a;

    let t = &r.solution.temperature;
    let mean =
        |nodes: &[NodeId]| nodes.iter().map(|n| t[n.index()]).sum::<f64>() / nodes.len() as f64;
    let (side_a, side_b) = (
        side_node_set(&r.mesh, "base_top"),
        side_node_set(&r.mesh, "cover_bottom"),
    );
    let jump = mean(&side_a) - mean(&side_b);
    let jump_spread = spread(&side_a.iter().map(|n| t[n.index()]).collect::<Vec<_>>()).max(spread(
        &side_b.iter().map(|n| t[n.index()]).collect::<Vec<_>>(),
    ));
    let i = &r.summary.interactions[0];
    eprintln!(
        "plugin conductance: h = {h} W/m²K, expected {expected:.9} W, side A {:.9} W (relative {:e}), side B {:.9} W, h·A·ΔT {:.9} W (relative {:e}, ΔT = {jump:.6} K)",
        i.heat_side_a,
        (i.heat_side_a - expected).abs() / expected,
        i.heat_side_b,
        h * a * jump,
        (h * a * jump - i.heat_side_a).abs() / expected
    );
    assert!(
        jump_spread <= BALANCE * (t_hot - t_cold),
        "the interface temperatures are uniform"
    );
    assert!((i.heat_side_a - expected).abs() <= BALANCE * expected);
    assert!((h * a * jump - i.heat_side_a).abs() <= BALANCE * expected);
    assert!(i.imbalance.abs() <= BALANCE * expected);
}

/// Electronics: the die's power (the flux on its active face times its area) leaves the
/// heat sink by convection, and all of it crosses the die–sink interface (the die's
/// other faces are insulated). Discrete balances, to the balance tolerance.
#[test]
fn electronics_power_leaves_by_convection() {
    let tmp = copy_scene("electronics");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    let problem = problem_table(&dir.join("problem.toml"));
    let power = number(&bc(&problem, "chip_bottom")["value"]) * area(&r.mesh, "chip_bottom");
    let cooled = bc(&problem, "sink_cooled");
    let (h, t_inf) = (number(&cooled["value"]), number(&cooled["ambient"]));
    let convected = face_integral(&r.mesh, &r.solution.temperature, "sink_cooled", |_, t| {
        h * (t - t_inf)
    });
    let i = &r.summary.interactions[0];
    eprintln!(
        "electronics: {power:.9} W made, {convected:.9} W convected (relative {:e}), {:.9} W across the interface (relative {:e}, imbalance {:e})",
        (convected - power).abs() / power,
        i.heat_side_a,
        (i.heat_side_a - power).abs() / power,
        i.imbalance
    );
    assert!((convected - power).abs() <= BALANCE * power);
    assert!((i.heat_side_a - power).abs() <= BALANCE * power);
    assert!(i.imbalance.abs() <= BALANCE * power);
}

/// `electronics/transient.toml`: the warm-up. Heat crosses the interface in balance at
/// every step (1e-12 relative: the gap conductance is conservative to round-off) and,
/// after the first step, within 2 % of the die's 10 W (the die's capacity, 0.16 J/K,
/// stores a negligible share once it follows the sink). The sink warms with time
/// constant τ ≈ 75 s (its capacity over its convective conductance), so after 400 s ≈
/// 5τ the temperature rise of the hottest node is within 1.5 % of the steady rise
/// (e^-5 = 0.7 %, plus the time error of 5 s BDF2 steps).
#[test]
fn electronics_warms_up_toward_its_steady_state() {
    // Its own copy: the steady test copies (and at its end removes) this scene too.
    let tmp = copy_scene_as("electronics", "electronics-transient");
    let dir = tmp.path();
    let steady = run(&dir.join("problem.toml"));
    let r = run(&dir.join("transient.toml"));
    assert_eq!(r.history.len(), 80);
    for s in &r.history {
        let (a, b) = s.heat[0];
        assert!(
            (a + b).abs() <= 1e-12 * a.abs().max(1.0),
            "step {}: {a} + {b}",
            s.step
        );
        if s.step > 1 {
            assert!((a.abs() - 10.0).abs() < 0.2, "step {}: {a} W", s.step);
        }
    }
    let hottest = |t: &[f64]| t.iter().copied().fold(f64::MIN, f64::max);
    let rise = hottest(&r.solution.temperature) - 293.15;
    let steady_rise = hottest(&steady.solution.temperature) - 293.15;
    assert!(
        rise < steady_rise && rise > 0.985 * steady_rise,
        "rise {rise} K against {steady_rise} K steady"
    );
    for f in [
        "temperature.pvd",
        "results.exo",
        "interface_heat.csv",
        "plots/interface_heat.png",
    ] {
        assert!(dir.join("out").join(f).exists(), "{f} missing");
    }
}

/// Busbar joint: the current entering bar A's end all crosses the bolted contact into
/// bar B (charge conservation across non-matching faces), and the electrical power put
/// in, ∫ j V dA over the end where the current enters (B's end is grounded, V = 0),
/// leaves as heat by convection — the bulk and contact Joule heat included. Discrete
/// balances, to the balance tolerance.
#[test]
fn busbar_joint_power_leaves_as_heat() {
    let tmp = copy_scene("busbar_joint");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    let problem = problem_table(&dir.join("problem.toml"));
    let j0 = number(&bc(&problem, "a_end")["value"]);
    let current = j0 * area(&r.mesh, "a_end");
    let dofs = &r.solution.dofs;
    let voltage = dofs.nodal_values(dofs.field("voltage").unwrap(), &r.solution.u);
    let power = j0 * face_integral(&r.mesh, &voltage, "a_end", |_, v| v);
    let mut out = 0.0;
    let bcs = problem["bc"].as_array().unwrap().iter();
    for b in bcs
        .map(|b| b.as_table().unwrap())
        .filter(|b| b["kind"].as_str() == Some("convection"))
    {
        let (h, t_inf) = (number(&b["value"]), number(&b["ambient"]));
        for s in b["surfaces"].as_array().unwrap() {
            let s = s.as_str().unwrap();
            out += face_integral(&r.mesh, &r.solution.temperature, s, |_, t| h * (t - t_inf));
        }
    }
    let c = &r.summary.electrical_contacts[0];
    eprintln!(
        "busbar: {current:.9} A in, {:.9} A across the joint; {power:.9} W in, {out:.9} W out (relative {:e}); contact Joule heat {:.6} W",
        c.current,
        (out - power).abs() / power,
        c.joule_heat
    );
    assert!((c.current - current).abs() <= BALANCE * current);
    assert!((out - power).abs() <= BALANCE * power);
    assert!(c.joule_heat > 0.0 && c.joule_heat < power);
}

/// The shrink-fitted sleeve (axisymmetric): the field is radial, so it has a closed
/// form — T = T_s(0) − Q r²/(4k₁) in the shaft, a logarithm in the sleeve, the fit's
/// jump (Qc/2)/h_c with h_c the CMY conductance 1.25 k_s (m/σ)(p/H)^0.95 at the deck's
/// numbers, convection at r = b. The heat crossing the fit is what the shaft makes per
/// revolution, Q π c² L, to round-off; the nodal temperatures match the closed form to
/// the discretisation error of the 6 + 4 cells across: below 0.1 K of a 32 K rise (0.07
/// K, on the axis, where linear elements with the weight r are least accurate pointwise;
/// tests/it/axisymmetric.rs shows the axis converging).
#[test]
fn shrink_fit_matches_its_closed_form() {
    let tmp = copy_scene("shrink_fit");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    let (q, c, b, length, k1, k2, h, t_inf) = (2e6, 0.020, 0.035, 0.060, 45.0, 60.0, 500.0, 300.0);
    let k_s = 2.0 * k1 * k2 / (k1 + k2);
    let h_c = 1.25 * k_s * (0.1 / 1e-6) * (5e6f64 / 2e9).powf(0.95);
    let t_b = t_inf + q * c * c / (2.0 * b * h);
    let t_bore = t_b + q * c * c / (2.0 * k2) * (b / c).ln();
    let t_surface = t_bore + q * c / (2.0 * h_c);
    let exact = |block: usize, r: f64| {
        if block == 0 {
            t_surface + q * (c * c - r * r) / (4.0 * k1)
        } else {
            t_bore - q * c * c / (2.0 * k2) * (r / c).ln()
        }
    };
    let m = &r.mesh;
    let shaft = m.find_block("shaft").unwrap();
    let in_shaft: std::collections::HashSet<usize> = m.blocks[shaft]
        .connectivity
        .iter()
        .map(|n| n.index())
        .collect();
    let worst = r
        .solution
        .temperature
        .iter()
        .enumerate()
        .map(|(n, t)| (t - exact(usize::from(!in_shaft.contains(&n)), m.coords[n][0])).abs())
        .fold(0.0, f64::max);
    let made = q * std::f64::consts::PI * c * c * length;
    let i = &r.summary.interactions[0];
    eprintln!(
        "shrink fit: heat across the fit {:.10} W (made {made:.10}), h_c = {h_c:.1} W/m²K, jump {:.4} K, centre {:.4} K, worst nodal error {worst:.2e} K",
        i.heat_side_a,
        t_surface - t_bore,
        exact(0, 0.0)
    );
    assert!((i.heat_side_a - made).abs() <= 1e-12 * made);
    assert!(worst <= 0.1, "worst nodal error {worst}");
}

/// A steady run whose source heats some blocks only (the shrink fit heats its shaft, not
/// its sleeve) takes the linear steady solver, and gives the answer of the general
/// solver, which takes the same run with the source written as a law of T that adds
/// nothing (`+ 0*T`): temperatures within 1e-10 of their spread, heats within 1e-10.
#[test]
fn a_source_in_some_blocks_takes_the_linear_steady_solver() {
    let tmp = copy_scene_as("shrink_fit", "shrink_fit-of-t");
    let dir = tmp.path();
    let linear = run(&dir.join("problem.toml"));
    let text = std::fs::read_to_string(dir.join("problem.toml")).unwrap();
    assert!(text.contains("value = 2e6\n"), "{text}");
    let of_t = text.replace("value = 2e6\n", "value = \"2e6 + 0*T\"\n");
    std::fs::write(dir.join("problem.toml"), of_t).unwrap();
    let general = run(&dir.join("problem.toml"));
    assert_eq!(linear.summary.linear_solver.name, "Cholesky");
    assert_eq!(general.summary.linear_solver.name, "direct");
    let (a, b) = (&linear.solution.temperature, &general.solution.temperature);
    let worst = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= 1e-10 * spread(a),
        "temperatures differ by {worst:e} K"
    );
    let heat = |r: &RunResult| r.summary.interactions[0].heat_side_a;
    let (h1, h2) = (heat(&linear), heat(&general));
    assert!((h1 - h2).abs() <= 1e-10 * h1.abs(), "{h1} W against {h2} W");
}

/// The lid of `opening_gap` is lifted off its base while the base heats it: every step's
/// heat across the gap and the last step's temperatures against a one-dimensional model
/// of the same stack solved here (linear elements along z, lumped capacity, backward
/// Euler, the gas gap h = k / g at each step's gap in the Robin–Nitsche form of
/// `docs/theory.md`). The in-plane meshes of the two parts do not match, but a field
/// that varies along z alone is the 3-D solution, so the two agree to round-off.
#[test]
fn opening_gap_follows_its_one_dimensional_stack() {
    let tmp = copy_scene("opening_gap");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    const MM: f64 = 1e-3;
    let (area, k_air, g0, speed, t_lift) = (0.04 * 0.04, 0.026, 0.01 * MM, 1e-5, 120.0);
    let (k_base, c_base, k_lid, c_lid) = (45.0, 3.611e6, 200.0, 2.43e6);
    let (h_top, t_room, t_plate, dt) = (25.0, 300.0, 400.0, 10.0);
    // Nodes along z: the base's 9 (node 0 held at the plate's temperature), the lid's 6.
    let base: Vec<f64> = (0..9).map(|i| 20.0 * MM * i as f64 / 8.0).collect();
    let lid: Vec<f64> = (0..6).map(|i| (20.0 + 2.0 * i as f64) * MM + g0).collect();
    let n = base.len() + lid.len();
    let top = base.len() - 1;
    let mut mass = vec![0.0; n];
    let mut bars: Vec<(usize, usize, f64)> = Vec::new();
    for (first, z, k, c) in [(0, &base, k_base, c_base), (base.len(), &lid, k_lid, c_lid)] {
        for i in 0..z.len() - 1 {
            let dz = z[i + 1] - z[i];
            mass[first + i] += c * dz / 2.0;
            mass[first + i + 1] += c * dz / 2.0;
            bars.push((first + i, first + i + 1, k / dz));
        }
    }
    let solve = |mut a: Vec<Vec<f64>>, mut b: Vec<f64>| -> Vec<f64> {
        let m = b.len();
        for p in 0..m {
            let (upper, lower) = a.split_at_mut(p + 1);
            let pivot = &upper[p];
            for (i, row) in lower.iter_mut().enumerate() {
                let f = row[p] / pivot[p];
                row[p..]
                    .iter_mut()
                    .zip(&pivot[p..])
                    .for_each(|(r, q)| *r -= f * q);
                b[p + 1 + i] -= f * b[p];
            }
        }
        let mut x = vec![0.0; m];
        for i in (0..m).rev() {
            x[i] = (b[i] - (i + 1..m).map(|j| a[i][j] * x[j]).sum::<f64>()) / a[i][i];
        }
        x
    };
    // The interface's weights and penalty: w_A = k_B / (k_A + k_B), α = β k_eff / h_e
    // with β = 20, k_eff the harmonic mean and h_e the thinner element at the gap.
    let (w_a, w_b) = (k_lid / (k_base + k_lid), k_base / (k_base + k_lid));
    let (dz_a, dz_b) = (base[top] - base[top - 1], lid[1] - lid[0]);
    let alpha = 20.0 * (2.0 * k_base * k_lid / (k_base + k_lid)) / dz_a.min(dz_b);
    // Per node: (index, its jump coefficient, its flux-average coefficient).
    let stencil = [
        (top - 1, 0.0, -w_a * k_base / dz_a),
        (top, 1.0, w_a * k_base / dz_a),
        (base.len(), -1.0, -w_b * k_lid / dz_b),
        (base.len() + 1, 0.0, w_b * k_lid / dz_b),
    ];
    let mut u = vec![t_room; n];
    u[0] = t_plate;
    let mut worst_heat = 0.0f64;
    let mut peak = 0.0f64;
    assert_eq!(r.history.len(), 60);
    for step in &r.history {
        let t = step.time;
        let gap = (lid[0] - base[top]) + speed * f64::max(t - t_lift, 0.0);
        let h = k_air / gap;
        let mut a = vec![vec![0.0; n]; n];
        let mut b: Vec<f64> = (0..n).map(|i| mass[i] / dt * u[i]).collect();
        for i in 0..n {
            a[i][i] = mass[i] / dt;
        }
        for &(i, j, s) in &bars {
            a[i][i] += s;
            a[j][j] += s;
            a[i][j] -= s;
            a[j][i] -= s;
        }
        // The interface row P J J − θ (J F + F J) − S F F: J the jump u_A − u_B, F the
        // weighted flux average w_A k_A ∂u_A/∂n_A − w_B k_B ∂u_B/∂n_B of the two
        // elements at the gap.
        let (pen, theta, stab) = (h * alpha / (h + alpha), h / (h + alpha), 1.0 / (h + alpha));
        for (i, ji, fi) in stencil.iter().copied() {
            for (j, jj, fj) in stencil.iter().copied() {
                a[i][j] += pen * ji * jj - theta * (ji * fj + fi * jj) - stab * fi * fj;
            }
        }
        a[n - 1][n - 1] += h_top;
        b[n - 1] += h_top * t_room;
        // The plate: row 0 held.
        a[0] = vec![0.0; n];
        a[0][0] = 1.0;
        b[0] = t_plate;
        u = solve(a, b);
        // The heat the form carries: q = P [u] − θ {k∂u}.
        let jump: f64 = stencil.iter().map(|&(i, j, _)| j * u[i]).sum();
        let average: f64 = stencil.iter().map(|&(i, _, f)| f * u[i]).sum();
        let heat = (pen * jump - theta * average) * area;
        let (out_a, out_b) = step.heat[0];
        let err = (out_a - heat).abs().max((out_b + heat).abs()) / heat;
        worst_heat = worst_heat.max(err);
        peak = peak.max(heat);
    }
    // The last temperatures at every node, against the stack's at the node's height.
    let m = &r.mesh;
    let lid_block = m.find_block("lid").unwrap();
    let in_lid: std::collections::HashSet<usize> = m.blocks[lid_block]
        .connectivity
        .iter()
        .map(|n| n.index())
        .collect();
    let mut worst_t = 0.0f64;
    for (k, x) in m.coords.iter().enumerate() {
        let (z, first) = if in_lid.contains(&k) {
            (&lid, base.len())
        } else {
            (&base, 0)
        };
        let i = z
            .iter()
            .position(|&zi| (zi - x[2]).abs() < 1e-9)
            .expect("a node on a layer");
        worst_t = worst_t.max((r.solution.temperature[k] - u[first + i]).abs());
    }
    let last = r.history.last().unwrap().heat[0].0;
    let motion = r.summary.motion.unwrap();
    eprintln!(
        "opening gap: heat {peak:.4} W at its peak, {last:.4} W at t = 600 s; against the 1-D stack: heat {worst_heat:.1e} relative, temperatures {worst_t:.1e} K; {motion:?}"
    );
    assert!(worst_heat <= 1e-9, "{worst_heat:e}");
    assert!(worst_t <= 1e-8, "{worst_t:e}");
    // The opening gap cuts the heat by two orders of magnitude.
    assert!(last < 0.01 * peak, "{last} of {peak}");
    // Searched where the run starts and every 5th of 60 steps; refitted in between.
    assert_eq!((motion.searches, motion.refits), (13, 48));
}

/// The spot weld's three contacts carry the 10 kA fed in, and every step balances its
/// energy: the electrical power fed in, ∫ j V dA over the feed, equals the heat stored,
/// Σ mᵢ (Tᵢⁿ⁺¹ − Tᵢⁿ)/Δt with the lumped capacity of each node, plus the heat the
/// cooling water takes, ∫ h (T − T∞) dA — all from `results.exo`, step by step. The
/// steel's σ(T) and the contacts' T-dependent conductances make each step nonlinear; the
/// balance holds to Newton's tolerance. The nugget starts at the faying surface.
#[test]
fn spot_weld_conserves_charge_and_energy_every_step() {
    use seam::mesh::exodus;
    let tmp = copy_scene("spot_weld");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    let problem = problem_table(&dir.join("problem.toml"));
    let j0 = number(&bc(&problem, "feed")["value"]);
    let current = j0 * area(&r.mesh, "feed");
    for c in &r.summary.electrical_contacts {
        assert!(
            (c.current.abs() - current).abs() <= BALANCE * current,
            "{} / {}: {} A of {current}",
            c.side_a,
            c.side_b,
            c.current
        );
    }
    // Lumped capacity: each box-shaped hex gives ρc V / 8 to each of its nodes.
    let m = &r.mesh;
    let materials = problem["material"].as_array().unwrap();
    let mut mass = vec![0.0; m.num_nodes()];
    for mat in materials.iter().map(|t| t.as_table().unwrap()) {
        let rho_c = number(&mat["rho_c"]);
        for name in mat["blocks"].as_array().unwrap() {
            let b = &m.blocks[m.find_block(name.as_str().unwrap()).unwrap()];
            for e in 0..b.len() {
                let nodes = b.elem_nodes(e);
                let (lo, hi) = nodes.iter().fold(
                    ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
                    |(lo, hi), n| {
                        let x = m.coords[n.index()];
                        (
                            std::array::from_fn(|d| lo[d].min(x[d])),
                            std::array::from_fn(|d| hi[d].max(x[d])),
                        )
                    },
                );
                let v: f64 = (0..3).map(|d| hi[d] - lo[d]).product();
                for n in nodes {
                    mass[n.index()] += rho_c * v / 8.0;
                }
            }
        }
    }
    let cooling = problem["bc"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b.as_table().unwrap())
        .find(|b| b["kind"].as_str() == Some("convection"))
        .unwrap();
    let (h, t_inf) = (number(&cooling["value"]), number(&cooling["ambient"]));
    let results = dir.join("out/results.exo");
    let times = exodus::read_times(&results).unwrap();
    assert_eq!(times.len(), 10);
    let mut before = vec![number(&problem["initial"]["temperature"]); m.num_nodes()];
    let mut t_before = 0.0;
    let mut worst = 0.0f64;
    for (k, &t) in times.iter().enumerate() {
        let temperature = exodus::read_nodal_variable(&results, "temperature", k).unwrap();
        let voltage = exodus::read_nodal_variable(&results, "voltage", k).unwrap();
        let dt = t - t_before;
        let stored: f64 = (mass.iter().zip(&temperature).zip(&before))
            .map(|((m, t1), t0)| m * (t1 - t0) / dt)
            .sum();
        let cooled: f64 = ["feed", "ground"]
            .iter()
            .map(|s| face_integral(m, &temperature, s, |_, t| h * (t - t_inf)))
            .sum();
        let power = j0 * face_integral(m, &voltage, "feed", |_, v| v);
        let err = (stored + cooled - power).abs() / power;
        eprintln!(
            "spot weld t = {t:.2}: power {power:.6} W = stored {stored:.6} + cooled {cooled:.6} (relative {err:.1e}), peak {:.1} K",
            temperature.iter().fold(0.0f64, |a, &b| a.max(b))
        );
        worst = worst.max(err);
        before = temperature;
        t_before = t;
    }
    assert!(worst <= 1e-8, "{worst:e}");
    // The hottest node is on the faying surface (z = 1 mm), under the electrodes.
    let hottest = (0..m.num_nodes())
        .max_by(|&a, &b| before[a].total_cmp(&before[b]))
        .unwrap();
    let x = m.coords[hottest];
    assert!((x[2] - 1e-3).abs() < 1e-9, "hottest at {x:?}");
    assert!(
        (7e-3..=13e-3).contains(&x[0]) && (7e-3..=13e-3).contains(&x[1]),
        "{x:?}"
    );
}

/// The hydrogen wall: the steady permeation flux through the coated wall against the
/// 1-D closed form with the Arrhenius diffusivities of the exact temperature (the thermal
/// tie makes T piecewise linear, which the hexes hold to round-off):
/// `j = c_up / (∫_coating dz/D + K ∫_steel dz/D)` per unit area, the integrals by
/// composite Simpson on 4000 intervals (far below the mesh's error). The mesh's D(T)
/// varies across each cell, so the flux is second order, not exact: 16 cells through
/// the coating, where most of the resistance is, give 5e-6 (32 give 1.2e-6), checked
/// within 2e-5. The flux leaving the coating is the flux entering the steel to
/// round-off, whatever the mesh.
#[test]
fn hydrogen_wall_permeation_matches_its_closed_form() {
    let tmp = copy_scene("hydrogen_wall");
    let dir = tmp.path();
    let r = run(&dir.join("problem.toml"));
    let mm = 1e-3;
    let (t_gas, t_vac, k1, k2) = (600.0, 500.0, 20.0, 40.0);
    let (l1, l2) = (0.1 * mm, 2.0 * mm);
    let q = (t_gas - t_vac) / (l1 / k1 + l2 / k2);
    let t_at = |z: f64| {
        if z <= l1 {
            t_gas - q * z / k1
        } else {
            t_gas - q * l1 / k1 - q * (z - l1) / k2
        }
    };
    let d1 = |t: f64| 1e-9 * (-40000.0 / (8.314 * t)).exp();
    let d2 = |t: f64| 7.2e-8 * (-5690.0 / (8.314 * t)).exp();
    let simpson = |a: f64, b: f64, f: &dyn Fn(f64) -> f64| {
        let n = 4000;
        let h = (b - a) / n as f64;
        (0..=n)
            .map(|i| {
                let w = if i == 0 || i == n {
                    1.0
                } else if i % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                w * f(a + i as f64 * h)
            })
            .sum::<f64>()
            * h
            / 3.0
    };
    let i1 = simpson(0.0, l1, &|z| 1.0 / d1(t_at(z)));
    let i2 = simpson(l1, l1 + l2, &|z| 1.0 / d2(t_at(z)));
    let (c_up, k, area) = (1.0, 0.1, mm * mm);
    let exact = c_up * area / (i1 + k * i2);
    let s = &r.summary.species_contacts[0];
    let error = (s.flux_side_a - exact).abs() / exact;
    eprintln!(
        "hydrogen wall: permeation {:.6e} mol/s through 1 mm² (closed form {exact:.6e}, relative {error:.1e}); coating side {:.15e}, steel side {:.15e}; {} Newton iterations",
        s.flux_side_a, s.flux_side_a, s.flux_side_b, r.summary.newton_iterations
    );
    assert!(r.summary.converged);
    assert!(error < 2e-5, "permeation flux off by {error:e}");
    assert!(
        s.imbalance.abs() < 1e-12 * exact,
        "imbalance {}",
        s.imbalance
    );
    // The concentration is written with the temperature.
    let vtu = std::fs::read_to_string(dir.join("out/temperature.vtu")).unwrap();
    assert!(vtu.contains("Name=\"species\""), "no species point data");
}
