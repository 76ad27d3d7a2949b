//! The fields `seam run` writes beyond the temperature: the heat flux −k∇T per element,
//! the contact fields per face (`contact.vtu`, nodal variables in `results.exo`) as
//! `Visualize Contact` and `Output Rule` ask, and `interface_heat.csv` split by
//! mechanism for a summed conductance.

use std::path::Path;

use seam::mesh::generate::{self, BoxSpec};
use seam::mesh::{self, Mesh};
use seam::output::exodus::ExodusWriter;
use seam::run::{RunError, RunResult};
use tempfile::TempDir;

use crate::scratch;

fn write_mesh(path: &Path, m: &Mesh) {
    ExodusWriter::create(path, m, &[], &[])
        .unwrap()
        .finish()
        .unwrap();
}

fn run(problem: &Path) -> RunResult {
    match seam::run::run(problem) {
        Ok(r) => r,
        Err(RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(RunError::Solve(e)) => panic!("{e}"),
    }
}

/// The values of the ASCII `DataArray` called `name` in a `.vtu` `seam run` wrote.
pub(crate) fn vtu_array(xml: &str, name: &str) -> Vec<f64> {
    let tag = format!("Name=\"{name}\"");
    let at = xml
        .find(&tag)
        .unwrap_or_else(|| panic!("no array {name} in the file"));
    let body = &xml[at + xml[at..].find('>').unwrap() + 1..];
    let body = &body[..body.find("</DataArray>").unwrap()];
    body.split_ascii_whitespace()
        .map(|t| t.parse().unwrap())
        .collect()
}

/// `interface_heat.csv` as rows of (step, mechanism, heat_side_a, heat_side_b,
/// imbalance), after checking its header.
fn heat_rows(path: &Path) -> Vec<(usize, String, f64, f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some("step,time,side_a,side_b,mechanism,heat_side_a,heat_side_b,imbalance")
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            assert_eq!(f.len(), 8, "{l}");
            (
                f[0].parse().unwrap(),
                f[4].to_string(),
                f[5].parse().unwrap(),
                f[6].parse().unwrap(),
                f[7].parse().unwrap(),
            )
        })
        .collect()
}

/// An element variable of `results.exo` at step `step`, blocks concatenated.
fn element_variable(path: &Path, m: &Mesh, var: usize, step: usize) -> Vec<f64> {
    let nc = netcdf_reader::NcFile::open(path).unwrap();
    let mut out = Vec::new();
    for b in 0..m.blocks.len() {
        let v = nc
            .read_variable::<f64>(&format!("vals_elem_var{var}eb{}", b + 1))
            .unwrap();
        let n = m.blocks[b].len();
        let v: Vec<f64> = v.iter().copied().collect();
        out.extend_from_slice(&v[step * n..(step + 1) * n]);
    }
    out
}

/// 1-D conduction through two conforming blocks, x ∈ [0, 1] with k = 2 and x ∈ [1, 3]
/// with k = 8 (hexes 0.5 m wide), T = 300 K at x = 0 and 500 K at x = 3, insulated
/// elsewhere: the exact temperature is piecewise linear and the flux is
/// q = −ΔT / (L₁/k₁ + L₂/k₂) = −266.67 W/m² along x in every element, 0 across. The
/// linear solve reproduces the field to round-off and the centroid gradient of a hex
/// is exact for a linear field, so each element's flux must match to 1e-10 relative
/// (round-off of ~1e-13 K differentiated over 0.5 m is ~1e-12 of q), in
/// `temperature.vtu` and in `results.exo`; the conductivity used is each block's own.
#[test]
fn run_heat_flux_is_k_dt_over_l_on_a_linear_field() {
    let tmp = scratch("run-fields-heat-flux");
    let dir = tmp.path();
    let m = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 1.0], [2, 2, 2], 1)
                .with_side_sets([1, 0, 0, 0, 0, 0]),
            BoxSpec::hex([1.0, 0.0, 0.0], [3.0, 1.0, 1.0], [4, 2, 2], 2)
                .with_side_sets([0, 2, 0, 0, 0, 0]),
        ],
        true,
    );
    write_mesh(&dir.join("bar.exo"), &m);
    std::fs::write(
        dir.join("problem.toml"),
        "[mesh]\nfile = \"bar.exo\"\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = 2.0\n\
         [[material]]\nblocks = [\"block_2\"]\nconductivity = 8.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = 300.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_2\"]\nvalue = 500.0\n\
         [output]\ndir = \"out\"\n",
    )
    .unwrap();
    run(&dir.join("problem.toml"));
    let q = -200.0 / (1.0 / 2.0 + 2.0 / 8.0);
    let xml = std::fs::read_to_string(dir.join("out/temperature.vtu")).unwrap();
    assert!(xml.contains("Name=\"heat_flux\" NumberOfComponents=\"3\""));
    let v = vtu_array(&xml, "heat_flux");
    assert_eq!(v.len(), 3 * m.num_elems());
    let exo = dir.join("out/results.exo");
    let (x, y, z) = (
        element_variable(&exo, &m, 1, 0),
        element_variable(&exo, &m, 2, 0),
        element_variable(&exo, &m, 3, 0),
    );
    let mut worst = 0.0f64;
    for e in 0..m.num_elems() {
        for (got, want) in [
            (v[3 * e], q),
            (v[3 * e + 1], 0.0),
            (v[3 * e + 2], 0.0),
            (x[e], q),
            (y[e], 0.0),
            (z[e], 0.0),
        ] {
            worst = worst.max((got - want).abs() / q.abs());
        }
    }
    eprintln!("heat flux: q = {q} W/m², worst element error {worst:.1e} of q");
    assert!(worst < 1e-10, "worst {worst:e}");
}

/// Copy the two-block example (mesh, problem, contact deck) into `dir`.
fn two_blocks(dir: &Path) {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks");
    for f in ["two_blocks.exo", "problem.toml", "contact_run.i"] {
        std::fs::copy(src.join(f), dir.join(f)).unwrap();
    }
}

/// The contact fields of the two-block example (a gap conductance across a
/// non-matching interface, `Visualize Contact`, `Output Rule = verbose`): the interface
/// flux of each side-A face times its matched area sums to the interface heat of
/// `interface_heat.csv` to 1e-10 relative (both integrate the same point fluxes; only
/// the summation order differs), and so do the side-B faces' (the same points, grouped
/// by side-B face). Every face of either side is fully overlapped: fraction 1 to 1e-12
/// (the clipped overlap areas of a face add up to its area to round-off), gap 0 to
/// 1e-12 m (the blocks touch). `results.exo` carries the fields on the side-A nodes and
/// 0 elsewhere. With `SEAM_PYTHON` set, meshio reads the output and finds every array.
#[test]
fn run_contact_flux_sums_to_the_interface_heat() {
    let tmp = scratch("run-fields-two-blocks");
    let dir = tmp.path();
    two_blocks(dir);
    let r = run(&dir.join("problem.toml"));
    let out = dir.join("out");
    let rows = heat_rows(&out.join("interface_heat.csv"));
    assert_eq!(rows.len(), 1, "{rows:?}");
    let (step, mechanism, heat, heat_b, _) = rows[0].clone();
    assert_eq!((step, mechanism.as_str()), (0, "gap_conductance"));
    assert_eq!(heat, r.summary.interactions[0].heat_side_a);
    assert_eq!(heat_b, r.summary.interactions[0].heat_side_b);

    let xml = std::fs::read_to_string(out.join("contact.vtu")).unwrap();
    let side = vtu_array(&xml, "side");
    let flux = vtu_array(&xml, "interface_flux");
    let area = vtu_array(&xml, "contact_area");
    let fraction = vtu_array(&xml, "contact_fraction");
    let gap = vtu_array(&xml, "contact_gap");
    assert!(vtu_array(&xml, "interaction").iter().all(|&k| k == 1.0));
    // 6×6 base faces (side A) and 4×4 lid faces (side B).
    assert_eq!(side.iter().filter(|&&s| s == 0.0).count(), 36);
    assert_eq!(side.iter().filter(|&&s| s == 1.0).count(), 16);
    for s in [0.0, 1.0] {
        let sum: f64 = (0..side.len())
            .filter(|&k| side[k] == s)
            .map(|k| flux[k] * area[k])
            .sum();
        let rel = (sum - heat).abs() / heat.abs();
        eprintln!("side {s}: Σ flux × area = {sum:e} W, heat {heat:e} W, difference {rel:.1e}");
        assert!(rel < 1e-10, "side {s}: {sum} vs {heat}");
    }
    assert!(
        fraction.iter().all(|f| (f - 1.0).abs() < 1e-12),
        "{fraction:?}"
    );
    assert!(gap.iter().all(|g| g.abs() < 1e-12), "{gap:?}");

    let exo = out.join("results.exo");
    // The interface heat per side is a global variable of results.exo, one value per step.
    let i = &r.summary.interactions[0];
    for (side, want) in [("a", i.heat_side_a), ("b", i.heat_side_b)] {
        let name = format!("heat_side_{side}:{}/{}", i.side_a, i.side_b);
        let got = mesh::exodus::read_global_variable(&exo, &name).unwrap();
        assert_eq!(got, vec![want], "{name}");
    }
    let nodal = |name: &str| mesh::exodus::read_nodal_variable(&exo, name, 0).unwrap();
    let (f, q) = (nodal("contact_fraction"), nodal("interface_flux"));
    let m = &r.mesh;
    let base_top = m.find_side_set("base_top").unwrap();
    let mut on_a: Vec<usize> = m.side_sets[base_top]
        .sides
        .iter()
        .flat_map(|&s| m.side_nodes(s).map(|n| n.index()))
        .collect();
    on_a.sort_unstable();
    on_a.dedup();
    let mean = heat; // over an interface of area 1 m²
    for i in 0..m.num_nodes() {
        if on_a.binary_search(&i).is_ok() {
            assert!((f[i] - 1.0).abs() < 1e-12, "node {i}: fraction {}", f[i]);
            assert!(
                (q[i] - mean).abs() < 1e-9 * mean.abs(),
                "node {i}: flux {}",
                q[i]
            );
        } else {
            assert_eq!((f[i], q[i]), (0.0, 0.0), "node {i} is on no side-A face");
        }
    }

    if let Ok(python) = std::env::var("SEAM_PYTHON") {
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/python/check_results.py");
        let o = std::process::Command::new(python)
            .arg(&script)
            .args(["--expect-heat-flux", "--expect-contact"])
            .arg(&out)
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&o.stdout);
        assert!(
            o.status.success(),
            "{text}{}",
            String::from_utf8_lossy(&o.stderr)
        );
        assert!(
            text.contains("1 contact file(s), 52 contact faces"),
            "{text}"
        );
    } else {
        eprintln!(
            "SEAM_PYTHON not set: skipping the meshio check of {}",
            out.display()
        );
    }
}

/// Block 1, [0, 2] × [0, 1] × [0, 1] in 4 × 2 × 2 hexes, under block 2,
/// [0, 1.25] × [0, 1] × [1, 2] in 2 × 2 × 2, meshed apart: the base's top (side A) has
/// faces 0.5 wide in x, the second block stops at x = 1.25. Side sets: 1 base top,
/// 2 cover bottom, 3 base bottom, 4 cover top.
fn short_cover(dir: &Path) -> Mesh {
    let m = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [2.0, 1.0, 1.0], [4, 2, 2], 1)
                .with_side_sets([0, 0, 0, 0, 3, 1]),
            BoxSpec::hex([0.0, 0.0, 1.0], [1.25, 1.0, 2.0], [2, 2, 2], 2)
                .with_side_sets([0, 0, 0, 0, 2, 4]),
        ],
        false,
    );
    write_mesh(&dir.join("short.exo"), &m);
    m
}

const SHORT_PROBLEM: &str = "[mesh]\nfile = \"short.exo\"\n\
    [[material]]\nblocks = [\"block_1\", \"block_2\"]\nconductivity = 10.0\n\
    [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_3\"]\nvalue = 300.0\n\
    [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 400.0\n\
    [contact]\nfile = \"contact.i\"\n[output]\ndir = \"out\"\n";

/// The contact deck of the short cover with `lines` added to the definition.
fn short_deck(lines: &str) -> String {
    format!(
        "begin contact definition joint
  contact surface base contains surface_1
  contact surface cover contains surface_2
{lines}
  begin interaction
    side a base
    side b cover
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 1000
  end
end
"
    )
}

/// Run the short cover with the contact-definition `lines`; the scratch folder it ran
/// in (the output in its `out/`).
fn run_short(name: &str, lines: &str) -> (TempDir, RunResult) {
    let tmp = scratch(&format!("run-fields-{name}"));
    let dir = tmp.path();
    short_cover(dir);
    std::fs::write(dir.join("contact.i"), short_deck(lines)).unwrap();
    std::fs::write(dir.join("problem.toml"), SHORT_PROBLEM).unwrap();
    let r = run(&dir.join("problem.toml"));
    (tmp, r)
}

/// Contact fraction on the short cover: the side-A faces whose x-extent lies under the
/// cover ([0, 0.5], [0.5, 1]) are fully overlapped, fraction 1; the face [1, 1.5] is
/// half under it, 0.5; the face [1.5, 2] is outside, 0 (no gap, no flux). Segment
/// integration clips the overlap exactly, so each fraction holds to 1e-12. The face
/// fluxes still integrate to the interface heat (1e-10 relative).
#[test]
fn run_contact_fraction_is_below_one_on_a_face_partly_outside() {
    let (dir, r) = run_short("short", "  visualize contact");
    let out = dir.path().join("out");
    let xml = std::fs::read_to_string(out.join("contact.vtu")).unwrap();
    let fraction = vtu_array(&xml, "contact_fraction");
    let flux = vtu_array(&xml, "interface_flux");
    let area = vtu_array(&xml, "contact_area");
    let side = vtu_array(&xml, "side");
    assert!(side.iter().all(|&s| s == 0.0), "summary: side-A faces only");
    assert_eq!(fraction.len(), 8, "4 × 2 side-A faces");
    // The faces' x-centres, from the cells' points.
    let points = vtu_array(&xml, "temperature").len();
    let xyz = {
        let at = xml.find("<Points>").unwrap();
        let body = &xml[at..];
        let body = &body[body.find('>').unwrap() + 1..];
        let body = &body[body.find('>').unwrap() + 1..];
        let body = &body[..body.find("</DataArray>").unwrap()];
        body.split_ascii_whitespace()
            .map(|t| t.parse::<f64>().unwrap())
            .collect::<Vec<_>>()
    };
    assert_eq!(xyz.len(), 3 * points);
    let conn = vtu_array_untyped(&xml, "connectivity");
    let mut seen = Vec::new();
    for (k, f) in fraction.iter().enumerate() {
        let xc: f64 = conn[4 * k..4 * k + 4]
            .iter()
            .map(|&i| xyz[3 * i as usize])
            .sum::<f64>()
            / 4.0;
        let want = match xc {
            x if x < 1.0 => 1.0,
            x if x < 1.5 => 0.5,
            _ => 0.0,
        };
        seen.push((xc, *f));
        assert!(
            (f - want).abs() < 1e-12,
            "face at x = {xc}: fraction {f}, want {want}"
        );
        if want == 0.0 {
            assert_eq!((flux[k], area[k]), (0.0, 0.0));
        }
    }
    eprintln!("short cover: (x-centre, contact_fraction) {seen:?}");
    let heat = r.summary.interactions[0].heat_side_a;
    let sum: f64 = flux.iter().zip(&area).map(|(q, a)| q * a).sum();
    assert!((sum - heat).abs() < 1e-10 * heat.abs(), "{sum} vs {heat}");
}

/// Like [`vtu_array`], for the unnamed-type integer arrays (connectivity).
fn vtu_array_untyped(xml: &str, name: &str) -> Vec<i64> {
    vtu_array(xml, name).iter().map(|&v| v as i64).collect()
}

/// `Output Rule` decides what a definition's contact output holds (with `Visualize
/// Contact`): nothing without `Visualize Contact` or with `none` (then with warning
/// W0702), the side-A faces with `summary`, both sides with `verbose`, and every point
/// in `contact_points.vtu` with `more verbose`. The Exodus file has the contact
/// variables exactly when `contact.vtu` is written.
#[test]
fn run_output_rule_decides_the_contact_output() {
    let has_contact_vars = |out: &Path| {
        mesh::exodus::read_nodal_variable(&out.join("results.exo"), "contact_gap", 0).is_ok()
    };
    // (lines, contact.vtu?, side-B faces?, points file?, warning?)
    for (name, lines, faces, side_b, points, warned) in [
        ("plain", "", false, false, false, false),
        (
            "none",
            "  visualize contact\n  output rule = none",
            false,
            false,
            false,
            true,
        ),
        (
            "summary",
            "  visualize contact\n  output rule = summary",
            true,
            false,
            false,
            false,
        ),
        (
            "verbose",
            "  visualize contact\n  output rule = verbose",
            true,
            true,
            false,
            false,
        ),
        (
            "more",
            "  visualize contact\n  output rule = more verbose",
            true,
            true,
            true,
            false,
        ),
        (
            "rule_only",
            "  output rule = more verbose",
            false,
            false,
            false,
            false,
        ),
    ] {
        let (dir, r) = run_short(&format!("rule-{name}"), lines);
        let out = dir.path().join("out");
        assert_eq!(out.join("contact.vtu").exists(), faces, "{name}");
        assert_eq!(has_contact_vars(&out), faces, "{name}");
        assert_eq!(out.join("contact_points.vtu").exists(), points, "{name}");
        let codes: Vec<&str> = r.warnings.warnings().map(|d| d.code).collect();
        assert_eq!(codes.contains(&"W0702"), warned, "{name}: {codes:?}");
        if faces {
            let xml = std::fs::read_to_string(out.join("contact.vtu")).unwrap();
            let side = vtu_array(&xml, "side");
            // 8 faces on side A; the cover's bottom has 2 × 2.
            assert_eq!(side.len(), if side_b { 8 + 4 } else { 8 }, "{name}");
        }
        if points {
            let xml = std::fs::read_to_string(out.join("contact_points.vtu")).unwrap();
            let status = vtu_array(&xml, "status");
            let weight = vtu_array(&xml, "weight");
            assert!(status.contains(&0.0), "{name}: matched points");
            let matched: f64 = status
                .iter()
                .zip(&weight)
                .filter(|(s, _)| **s == 0.0)
                .map(|(_, w)| w)
                .sum();
            // The overlap is 1.25 × 1 m².
            assert!(
                (matched - 1.25).abs() < 1e-12,
                "{name}: matched weight {matched}"
            );
        }
    }
}

/// A gap conductance of two mechanisms, `Constant H = 300` and `Table Of Gap = 0 200
/// 1 100` (h = 200 at the example's zero gap): `interface_heat.csv` has a row for each
/// mechanism and a `total` row with the interaction's heat. The mechanisms carry 3/5
/// and 2/5 of it at every point, so their rows hold 0.6 and 0.4 of the total to 1e-12,
/// and add up to it to 1e-12 (both integrate the same point fluxes); each mechanism
/// row balances (heat_side_b = −heat_side_a). Steady (one row set, step 0) and
/// transient (one per step, with `contact_<step>.vtu` in `contact.pvd` on the same
/// steps as the temperature).
#[test]
fn run_interface_heat_splits_a_summed_conductance_by_mechanism() {
    let tmp = scratch("run-fields-mechanisms");
    let dir = tmp.path();
    two_blocks(dir);
    let deck = std::fs::read_to_string(dir.join("contact_run.i"))
        .unwrap()
        .replace(
            "gap conductance coefficient = constant h = 500",
            "gap conductance coefficient = constant h = 300\n    gap conductance coefficient = table of gap = 0 200 1 100",
        );
    assert!(deck.contains("table of gap"));
    std::fs::write(dir.join("contact_run.i"), deck).unwrap();
    let problem = std::fs::read_to_string(dir.join("problem.toml")).unwrap();
    let transient = problem.replace(
        "[solve]\nkind = \"steady\"",
        "[initial]\ntemperature = 300.0\n[solve]\nkind = \"transient\"\nscheme = \"backward_euler\"\ndt = 0.05\nend_time = 0.1",
    ) + "every = 1\n";
    std::fs::write(dir.join("transient.toml"), transient).unwrap();
    for (file, steps) in [("problem.toml", vec![0]), ("transient.toml", vec![1, 2])] {
        run(&dir.join(file));
        let out = dir.join("out");
        let rows = heat_rows(&out.join("interface_heat.csv"));
        assert_eq!(rows.len(), 3 * steps.len(), "{file}: {rows:?}");
        for (chunk, step) in rows.chunks(3).zip(&steps) {
            let names: Vec<&str> = chunk.iter().map(|r| r.1.as_str()).collect();
            assert_eq!(names, ["constant", "table of gap", "total"], "{file}");
            assert!(chunk.iter().all(|r| r.0 == *step), "{file}: {chunk:?}");
            let total = chunk[2].2;
            assert!(total.abs() > 1.0, "{file}: some heat crosses");
            let (c, t) = (chunk[0].2 / total, chunk[1].2 / total);
            eprintln!(
                "{file} step {step}: total {total:e} W, shares {c} and {t}, sum − total {:.1e}",
                (chunk[0].2 + chunk[1].2 - total) / total
            );
            assert!(
                (c - 0.6).abs() < 1e-12 && (t - 0.4).abs() < 1e-12,
                "{file}: {c}, {t}"
            );
            assert!((chunk[0].2 + chunk[1].2 - total).abs() < 1e-12 * total.abs());
            for r in &chunk[..2] {
                assert_eq!((r.3, r.4), (-r.2, 0.0), "{file}: mechanism rows balance");
            }
        }
        if file == "transient.toml" {
            for s in [1, 2] {
                for f in [
                    format!("temperature_{s:05}.vtu"),
                    format!("contact_{s:05}.vtu"),
                ] {
                    assert!(out.join(&f).exists(), "{f} missing");
                }
            }
            let pvd = std::fs::read_to_string(out.join("contact.pvd")).unwrap();
            assert_eq!(pvd.matches("<DataSet").count(), 2, "{pvd}");
        }
    }
}

/// A Lagrange-multiplier tie's interface flux is its multiplier field λ_h at the points:
/// the heat leaving side A is Σ (Cᵀλ) over side A's dofs = Σ w λ_h, so Σ
/// interface_flux × contact_area over the side-A faces equals the tie's heat to 1e-10
/// relative (summation order only). Checked for standard multipliers (saddle point),
/// dual ones (condensed in the steady solve, recovered afterwards) and a transient run
/// (the general solver), each on the two-block example.
#[test]
fn run_tie_flux_is_the_multiplier_and_sums_to_the_heat() {
    for (name, multipliers, solve) in [
        ("standard", "standard", ""),
        ("dual", "dual", ""),
        (
            "transient",
            "standard",
            "[initial]\ntemperature = 300.0\n[solve]\nkind = \"transient\"\ndt = 0.1\nend_time = 0.2\n",
        ),
    ] {
        let tmp = scratch(&format!("run-fields-tie-{name}"));
        let dir = tmp.path();
        two_blocks(dir);
        let deck = format!(
            "begin contact definition tie
  contact surface interface_base contains base_top
  contact surface interface_lid contains lid_bottom
  visualize contact
  begin interaction
    side a interface_base
    side b interface_lid
  end
  begin enforcement
    enforcement for energy = tied multipliers = {multipliers}
    side b variable temperature to temperature
  end
end
"
        );
        std::fs::write(dir.join("contact_run.i"), deck).unwrap();
        let problem = format!(
            "[mesh]\nfile = \"two_blocks.exo\"\n\
             [[material]]\nblocks = [\"base\"]\nconductivity = 16.0\nrho_c = 16.0\n\
             [[material]]\nblocks = [\"lid\"]\nconductivity = 200.0\nrho_c = 100.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 300.0\n\
             [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 400.0\n\
             [contact]\nfile = \"contact_run.i\"\n[output]\ndir = \"out\"\n{solve}"
        );
        std::fs::write(dir.join("problem.toml"), problem).unwrap();
        let r = run(&dir.join("problem.toml"));
        let heat = r.summary.interactions[0].heat_side_a;
        let xml = std::fs::read_to_string(dir.join("out/contact.vtu")).unwrap();
        let (side, flux, area) = (
            vtu_array(&xml, "side"),
            vtu_array(&xml, "interface_flux"),
            vtu_array(&xml, "contact_area"),
        );
        let sum: f64 = (0..side.len())
            .filter(|&k| side[k] == 0.0)
            .map(|k| flux[k] * area[k])
            .sum();
        let rel = (sum - heat).abs() / heat.abs();
        eprintln!("{name}: Σ flux × area = {sum:e} W, tie heat {heat:e} W, difference {rel:.1e}");
        assert!(heat.abs() > 1.0, "{name}: heat must cross ({heat})");
        assert!(flux.iter().all(|q| q.is_finite()), "{name}: {flux:?}");
        assert!(rel < 1e-10, "{name}: {sum} vs {heat}");
    }
}
