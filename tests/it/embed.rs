//! The embedding APIs (`seam::embed`, `libseam` + `seam.h`) against `seam run` on the
//! same scene, their Jacobian against finite differences, and their error paths.
//!
//! Tolerance of the heat comparisons: 1e-9 relative. The hosts assemble the same
//! discrete equations as `seam run` but in other orders (own numbering, dense
//! Gaussian elimination instead of sparse Cholesky, a mesh generated in C), so the
//! answers differ by round-off amplified by the condition number of the system
//! (~1e4 here): ~1e-12 relative; 1e-9 leaves room for that and still catches any
//! modelling difference (a wrong dof mapping, a missed face or a changed form moves
//! the heat by percents).

use std::path::{Path, PathBuf};
use std::process::Command;

use seam::embed::{EmbedError, Embedding, Interaction, Model, Multipliers, Periodic, Topology};

use crate::scratch;

#[path = "../../examples/embed.rs"]
#[allow(dead_code)]
pub(crate) mod example;

pub(crate) const TOLERANCE: f64 = 1e-9;

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks")
}

/// `seam run` on the two-block problem with the contact deck `deck` (text), written
/// to a scratch folder without output; returns (heat side A, heat side B).
fn seam_run(name: &str, deck: &str) -> (f64, f64) {
    let tmp = scratch(&format!("embed-{name}"));
    let dir = tmp.path();
    let problem = std::fs::read_to_string(scene().join("problem.toml")).unwrap();
    let mesh = scene().join("two_blocks.exo");
    let problem = problem
        .replace(
            "file = \"two_blocks.exo\"",
            &format!("file = {:?}", mesh.display().to_string()),
        )
        .replace("file = \"contact_run.i\"", "file = \"contact.i\"")
        .replace("[output]\ndir = \"out\"", "");
    assert!(
        !problem.contains("out\""),
        "the reference run must write nothing"
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    std::fs::write(dir.join("contact.i"), deck).unwrap();
    let result = match seam::run::run(&dir.join("problem.toml")) {
        Ok(r) => r,
        Err(e) => panic!("seam run failed: {e:?}"),
    };
    let i = &result.summary.interactions[0];
    (i.heat_side_a, i.heat_side_b)
}

pub(crate) fn relative(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn embed_rust_example_matches_seam_run() {
    let deck = std::fs::read_to_string(scene().join("contact_run.i")).unwrap();
    let (reference, _) = seam_run("rust", &deck);
    let outcome = example::solve(&scene()).unwrap();
    let err = relative(outcome.heat.side_a, reference);
    println!(
        "embed example {:.15e} W, seam run {reference:.15e} W: relative difference {err:.2e}",
        outcome.heat.side_a
    );
    assert!(err <= TOLERANCE, "{err:.3e}");
    // The lid (400 K) heats the base (300 K): heat leaving side A (the base) is negative.
    assert!(reference < 0.0, "{reference}");
    // A constant h is linear: one Newton step solves, the second confirms.
    assert_eq!(outcome.newton_steps, 2);
}

/// Where cargo put libseam: `cargo test` builds the cdylib next to this test binary in
/// target/<profile>/deps/; `cargo build` puts it in target/<profile>/.
fn library_dir(file: &str) -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    [deps, deps.parent().unwrap()]
        .into_iter()
        .find(|d| d.join(file).exists())
        .unwrap_or_else(|| panic!("{file} is in neither {} nor its parent: seam is built as a cdylib (Cargo.toml [lib] crate-type)", deps.display()))
        .to_path_buf()
}

/// Compile `examples/c_host/<source>` against libseam with the CI flags and run it;
/// returns its standard output (the run must succeed).
pub(crate) fn run_c_host(source: &str) -> String {
    let lib = library_dir(if cfg!(target_os = "macos") {
        "libseam.dylib"
    } else {
        "libseam.so"
    });
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = scratch(&format!("embed-{source}"));
    let out = tmp.path().join("host");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let build = Command::new(&cc)
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-I"])
        .arg(root.join("include"))
        .arg(root.join("examples/c_host").join(source))
        .arg("-L")
        .arg(&lib)
        .arg("-lseam")
        .arg(format!("-Wl,-rpath,{}", lib.display()))
        .arg("-lm")
        .arg("-o")
        .arg(&out)
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{cc}`: {e}"));
    assert!(
        build.status.success(),
        "{}",
        String::from_utf8_lossy(&build.stderr)
    );
    // cargo's LD_LIBRARY_PATH for tests also names target/<profile>, where an older
    // libseam.so from `cargo build` may sit; it outranks the rpath, so pin it here.
    let run = Command::new(&out)
        .env("LD_LIBRARY_PATH", &lib)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&run.stdout).into_owned();
    assert!(
        run.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&run.stderr)
    );
    stdout
}

/// The numbers after `prefix` on the line of `stdout` that starts with it.
pub(crate) fn printed(stdout: &str, prefix: &str) -> Vec<f64> {
    stdout
        .lines()
        .find_map(|l| l.strip_prefix(prefix))
        .map(|rest| {
            rest.split(|c: char| c == ',' || c.is_whitespace())
                .filter_map(|w| w.parse().ok())
                .collect()
        })
        .unwrap_or_else(|| panic!("no `{prefix}` line in:\n{stdout}"))
}

#[test]
fn embed_c_host_matches_seam_run() {
    let stdout = run_c_host("main.c");
    // The misspelt surface came back as SEAM_ERR_ARGUMENT with a suggestion.
    assert!(
        stdout.contains("expected error 4: unknown surface `base_topp`")
            && stdout.contains("did you mean `base_top`?"),
        "{stdout}"
    );
    let heat = printed(&stdout, "interface heat: side A ");
    let deck = std::fs::read_to_string(scene().join("contact_run.i")).unwrap();
    let (reference, reference_b) = seam_run("c-reference", &deck);
    let (a, b) = (heat[0], heat[1]);
    println!(
        "C host {a:.15e} W, seam run {reference:.15e} W: {:.2e}",
        relative(a, reference)
    );
    assert!(relative(a, reference) <= TOLERANCE, "{a} vs {reference}");
    assert!(
        relative(b, reference_b) <= TOLERANCE,
        "{b} vs {reference_b}"
    );
    c_host_fields(&stdout, a);
    // Its dual mortar tie, condensed in C, against seam run's dual solve.
    let dual = printed(&stdout, "dual tie heat: side A ");
    let (reference, _) = seam_run("c-dual", &tie_deck("dual"));
    println!(
        "C host dual tie {:.15e} W, seam run {reference:.15e} W: {:.2e}",
        dual[0],
        relative(dual[0], reference)
    );
    assert!(relative(dual[0], reference) <= TOLERANCE);
    assert!(relative(-dual[1], reference) <= TOLERANCE);
    let field = printed(&stdout, "dual tie multiplier field: ");
    assert!(
        field[0] > 0.0 && relative(field[1], dual[0]) <= TOLERANCE,
        "{field:?}"
    );
}

/// The C host's coverage, point and face fields, CSR, callbacks and pairs-nothing error
/// (examples/c_host/main.c) at its solution, whose interface heat is `heat`.
fn c_host_fields(stdout: &str, heat: f64) {
    let coverage = printed(stdout, "coverage: ");
    assert_eq!(coverage[0], coverage[1], "every point paired: {coverage:?}");
    assert!((coverage[2] - 1.0).abs() < 1e-12 && (coverage[3] - 1.0).abs() < 1e-12);
    // Per point: the Rust host on the Exodus mesh of the same scene (whose points match
    // `seam run`'s, embed_api.rs) by position; the C mesh is generated in C.
    let deck = std::fs::read_to_string(scene().join("contact_run.i")).unwrap();
    let (seam, u) = crate::embed_api::host_solution(&deck);
    let key = |x: [f64; 3]| x.map(|v| (v * 1e9).round() as i64);
    let rust: std::collections::HashMap<_, _> = seam
        .point_fields(0, &u)
        .unwrap()
        .into_iter()
        .map(|p| (key(p.x), p))
        .collect();
    let mut compared = 0;
    let mut worst = 0.0f64;
    for line in stdout
        .lines()
        .filter(|l| l.starts_with("point ") && !l.starts_with("point flux"))
    {
        let v: Vec<f64> = line[6..]
            .split_whitespace()
            .map(|t| t.parse().unwrap())
            .collect();
        let p = rust
            .get(&key([v[0], v[1], v[2]]))
            .unwrap_or_else(|| panic!("no Rust point at {v:?}"));
        assert_eq!(v[3] != 0.0, p.paired);
        worst = worst.max((v[4] - p.flux).abs() / heat.abs());
        compared += 1;
    }
    println!("C point fields: {compared} points, largest flux difference {worst:.2e} of |Q|");
    assert_eq!(compared, rust.len());
    assert!(worst <= TOLERANCE, "{worst:.3e}");
    let sum = printed(stdout, "point flux sum: ")[0];
    assert!(relative(sum, heat) <= TOLERANCE, "{sum} {heat}");
    // The scene is one-dimensional: every face carries heat/area over all of it.
    let faces: Vec<Vec<f64>> = stdout
        .lines()
        .filter(|l| l.starts_with("face "))
        .map(|l| {
            l[5..]
                .split_whitespace()
                .map(|t| t.parse().unwrap())
                .collect()
        })
        .collect();
    assert_eq!(
        faces.len(),
        36 + 16,
        "the base's 6 × 6 top faces and the lid's 4 × 4"
    );
    for f in &faces {
        assert!(relative(f[1], heat) <= TOLERANCE, "{f:?}");
        assert!((f[2] - 1.0).abs() < 1e-12, "{f:?}");
    }
    assert!(relative(printed(stdout, "heat at u/2: ")[0], 0.5 * heat) <= TOLERANCE);
    let csr = printed(stdout, "csr: ");
    assert!(
        csr[3] == 0.0 && csr[4] == 1.0,
        "CSR = triplets, pattern kept: {csr:?}"
    );
    assert!(relative(printed(stdout, "callback heat: ")[0], heat) <= 1e-12);
    assert!(
        stdout.contains("expected callback failure 6: ")
            && stdout.contains("the callback returned 7"),
        "{stdout}"
    );
    // Quarantine, switching off and point pressures through C.
    let q = printed(stdout, "quarantine: ");
    assert!(q[0] != 0.0 && q[1] > 0.0 && q[1] == q[2], "{stdout}");
    assert!(
        stdout.contains("first reason: conductance model"),
        "{stdout}"
    );
    let off = printed(stdout, "switched off: ");
    assert!(off[0] == 0.0 && off[1] == 4.0, "{stdout}");
    assert!(
        stdout.contains(
            "expected nothing paired 10: interaction base_top / lid_bottom paired nothing"
        ),
        "{stdout}"
    );
    let apart = printed(stdout, "apart: ");
    assert!(
        apart[0] == 0.0 && apart[2] > 0.99 && apart[3] == 0.0,
        "{apart:?}"
    );
}

/// The multiplier field λ_h of a tie at every point, from the host's multipliers,
/// against the per-point flux `seam run` writes for the same tie (`contact_points.vtu`,
/// same mesh and deck, so the same points in the same order); Σ w λ_h is the heat.
fn tie_fields_match_seam_run(
    seam: &Embedding,
    tie: &seam::embed::TieConstraints,
    lambda: &[f64],
    deck: &str,
    name: &str,
) {
    let visual = deck.replacen(
        "  begin interaction",
        "  visualize contact\n  output rule = more verbose\n  begin interaction",
        1,
    );
    let run = crate::embed_api::seam_run_with_output(name, &visual);
    let out = run.path().join("out");
    let xml = std::fs::read_to_string(out.join("contact_points.vtu")).unwrap();
    let file = crate::run_fields::vtu_array(&xml, "interface_flux");
    let points = seam.tie_point_fields(tie, lambda).unwrap();
    assert_eq!(points.len(), file.len());
    let scale = file
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for (p, f) in points.iter().zip(&file) {
        assert_eq!(p.multiplier.is_some(), f.is_finite(), "{p:?} {f}");
        if let Some(m) = p.multiplier {
            assert_eq!(m, p.flux);
            worst = worst.max((m - f).abs() / scale);
        }
    }
    println!(
        "{name} tie: λ_h at {} points, largest difference {worst:.2e}",
        points.len()
    );
    assert!(worst <= TOLERANCE, "{worst:.3e}");
    let heat = tie.heat(lambda).unwrap();
    let sum: f64 = points
        .iter()
        .filter_map(|p| p.multiplier.map(|m| m * p.weight))
        .sum();
    assert!(
        relative(sum, heat.side_a) <= TOLERANCE,
        "{sum} {}",
        heat.side_a
    );
}

/// The two-block interface tied by mortar with `multipliers` (`dual` or `standard`).
fn tie_deck(multipliers: &str) -> String {
    format!(
        "begin contact definition tie
  contact surface interface_base contains base_top
  contact surface interface_lid contains lid_bottom
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
    )
}

/// Dual mortar through the condensed rows: a host without multipliers substitutes
/// `u_A = g + Σ c u` and solves the reduced SPD system; its heat (from its residual)
/// matches `seam run`'s saddle-free dual solve.
#[test]
fn embed_dual_mortar_rows_match_seam_run() {
    let deck = tie_deck("dual");
    let (reference, _) = seam_run("dual", &deck);
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let n = mesh.num_nodes();
    let dof = example::host_dofs(&mesh);
    let fixed = example::dirichlet(&mesh, &dof).unwrap();
    let fixed_nodes: Vec<usize> = (0..n).filter(|&i| fixed[dof[i]].is_some()).collect();
    let mut seam = example::embedding(&mesh, &dof)
        .fixed_nodes(&fixed_nodes)
        .build()
        .unwrap();
    seam.add_deck("tie.i", &deck).unwrap();
    seam.search().unwrap();
    let ties = seam.constraints().unwrap();
    assert_eq!(ties.len(), 1);
    let rows = &ties[0].condensed;
    // One row per base_top node: a 7 × 7 grid.
    assert_eq!(rows.len(), 49);

    // Reduce K u = 0 (no sources) by u = T ũ + g, then impose the Dirichlet data.
    let k = example::conduction(&mesh, &dof).unwrap();
    let mut a = k.clone();
    let mut f = vec![0.0; n];
    for r in rows {
        for row in 0..n {
            f[row] -= k[row * n + r.dof] * r.constant;
        }
    }
    for r in rows {
        for &(j, c) in &r.terms {
            f[j] += c * f[r.dof];
            for col in 0..n {
                a[j * n + col] += c * a[r.dof * n + col];
            }
        }
    }
    for r in rows {
        for &(j, c) in &r.terms {
            for row in 0..n {
                a[row * n + j] += c * a[row * n + r.dof];
            }
        }
    }
    let condensed: Vec<usize> = rows.iter().map(|r| r.dof).collect();
    for &d in &condensed {
        for i in 0..n {
            a[d * n + i] = 0.0;
            a[i * n + d] = 0.0;
        }
        a[d * n + d] = 1.0;
        f[d] = 0.0;
    }
    for (d, value) in fixed.iter().enumerate() {
        if let Some(g) = value {
            for row in 0..n {
                f[row] -= a[row * n + d] * g;
                a[row * n + d] = 0.0;
            }
            a[d * n..(d + 1) * n].fill(0.0);
            a[d * n + d] = 1.0;
        }
    }
    for (d, value) in fixed.iter().enumerate() {
        if let Some(g) = value {
            f[d] = *g;
        }
    }
    let mut u = example::solve_dense(a, f, n).unwrap();
    for r in rows {
        u[r.dof] = r.constant + r.terms.iter().map(|&(j, c)| c * u[j]).sum::<f64>();
    }
    // The host's own residual K u − F (F = 0) gives the multipliers and the heat.
    let residual: Vec<f64> = (0..n)
        .map(|row| (0..n).map(|col| k[row * n + col] * u[col]).sum())
        .collect();
    let lambda = ties[0].dual_multipliers(&residual).unwrap();
    let heat = ties[0].heat(&lambda).unwrap();
    tie_fields_match_seam_run(&seam, &ties[0], &lambda, &deck, "dual");
    let err = relative(heat.side_a, reference);
    println!(
        "dual rows {:.15e} W, seam run {reference:.15e} W: {err:.2e}",
        heat.side_a
    );
    assert!(err <= TOLERANCE, "{err:.3e}");
    assert!(relative(-heat.side_b, reference) <= TOLERANCE);
}

/// Standard multipliers: a host that carries them solves `[K Cᵀ; C 0] [u; λ] = [F; g]`
/// with seam's rows (here densely, with pivoting) and gets `seam run`'s heat from λ.
#[test]
fn embed_standard_mortar_rows_match_seam_run() {
    let deck = tie_deck("standard");
    let (reference, _) = seam_run("standard", &deck);
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let n = mesh.num_nodes();
    let dof = example::host_dofs(&mesh);
    let fixed = example::dirichlet(&mesh, &dof).unwrap();
    let fixed_nodes: Vec<usize> = (0..n).filter(|&i| fixed[dof[i]].is_some()).collect();
    let mut seam = example::embedding(&mesh, &dof)
        .fixed_nodes(&fixed_nodes)
        .build()
        .unwrap();
    seam.add_deck("tie.i", &deck).unwrap();
    seam.search().unwrap();
    let ties = seam.constraints().unwrap();
    let tie = &ties[0];
    assert!(
        tie.condensed.is_empty(),
        "standard multipliers are not condensed"
    );
    let m = tie.multiplier_dofs.len();
    let size = n + m;
    let k = example::conduction(&mesh, &dof).unwrap();
    let mut a = vec![0.0; size * size];
    for row in 0..n {
        a[row * size..row * size + n].copy_from_slice(&k[row * n..(row + 1) * n]);
    }
    for &(mult, j, c) in &tie.entries {
        a[(n + mult) * size + j] += c;
        a[j * size + n + mult] += c;
    }
    let mut f = vec![0.0; size];
    f[n..].copy_from_slice(&tie.rhs);
    for (d, value) in fixed.iter().enumerate() {
        if let Some(g) = value {
            for row in 0..size {
                f[row] -= a[row * size + d] * g;
                a[row * size + d] = 0.0;
            }
            a[d * size..(d + 1) * size].fill(0.0);
            a[d * size + d] = 1.0;
        }
    }
    for (d, value) in fixed.iter().enumerate() {
        if let Some(g) = value {
            f[d] = *g;
        }
    }
    let x = example::solve_dense(a, f, size).unwrap();
    let heat = tie.heat(&x[n..]).unwrap();
    tie_fields_match_seam_run(&seam, tie, &x[n..], &deck, "standard");
    let err = relative(heat.side_a, reference);
    println!(
        "standard rows {:.15e} W, seam run {reference:.15e} W: {err:.2e}",
        heat.side_a
    );
    assert!(err <= TOLERANCE, "{err:.3e}");
    // A host that condensed standard multipliers has nothing to read them from.
    assert!(tie.dual_multipliers(&vec![0.0; n]).is_err());
}

/// The Jacobian in host numbering is the derivative of the residual in host
/// numbering: central differences of a temperature-dependent (radiation) conductance,
/// step 1e-3 K on a ~350 K field (truncation ~1e-6 × h'' relative, round-off ~1e-13 /
/// 1e-3), agree to 1e-6 relative of the largest entry.
#[test]
fn embed_jacobian_matches_finite_differences() {
    let deck = "begin contact definition rad
  contact surface a contains base_top
  contact surface b contains lid_bottom
  begin interaction
    side a a
    side b b
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = radiation emissivity_a = 0.8 emissivity_b = 0.6
  end
end
";
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let n = mesh.num_nodes();
    let dof = example::host_dofs(&mesh);
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    seam.add_deck("rad.i", deck).unwrap();
    seam.search().unwrap();
    // A field that varies over the interface: T = 300 + 50 z + 10 x y.
    let mut u = vec![0.0; n];
    for (i, x) in mesh.coords.iter().enumerate() {
        u[dof[i]] = 300.0 + 50.0 * x[2] + 10.0 * x[0] * x[1];
    }
    let c = seam.contributions(&u).unwrap();
    let mut jac = vec![0.0; n * n];
    for &(i, j, v) in &c.jacobian {
        jac[i * n + j] += v;
    }
    let dense_residual = |u: &[f64]| {
        let mut r = vec![0.0; n];
        for (d, v) in seam.contributions(u).unwrap().residual {
            r[d] += v;
        }
        r
    };
    let scale = jac.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    let step = 1e-3;
    let mut worst = 0.0f64;
    let columns: Vec<usize> = c.jacobian.iter().map(|t| t.1).step_by(97).collect();
    assert!(columns.len() > 10);
    for &col in &columns {
        let (mut up, mut down) = (u.clone(), u.clone());
        up[col] += step;
        down[col] -= step;
        let (rp, rm) = (dense_residual(&up), dense_residual(&down));
        for row in 0..n {
            let fd = (rp[row] - rm[row]) / (2.0 * step);
            worst = worst.max((fd - jac[row * n + col]).abs() / scale);
        }
    }
    assert!(worst <= 1e-6, "{worst:.3e}");
    // The model really is nonlinear here: the Jacobian differs from the one at a
    // uniform shift of the field.
    let shifted: Vec<f64> = u.iter().map(|x| x + 100.0).collect();
    let c2 = seam.contributions(&shifted).unwrap();
    assert_ne!(c.jacobian, c2.jacobian);
}

/// Programmatic interactions and face lists: the same gap conductance built in code on
/// faces given by their nodes gives the heat of the deck on side sets.
#[test]
fn embed_face_lists_and_code_match_deck_and_side_sets() {
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let mut u = vec![0.0; mesh.num_nodes()];
    for (i, x) in mesh.coords.iter().enumerate() {
        u[dof[i]] = 300.0 + 60.0 * x[2] - 5.0 * x[0];
    }
    let mut by_deck = example::embedding(&mesh, &dof).build().unwrap();
    by_deck
        .add_deck_file(&scene().join("contact_run.i"))
        .unwrap();
    by_deck.search().unwrap();
    let expected = by_deck.contributions(&u).unwrap().heat[0].unwrap();

    let faces = |set: &str| -> Vec<Vec<usize>> {
        let s = mesh.find_side_set(set).unwrap();
        mesh.side_sets[s]
            .sides
            .iter()
            // Reversed node order: orientation comes from the element, not the list.
            .map(|&side| {
                let mut nodes: Vec<usize> = mesh.side_nodes(side).map(|n| n.index()).collect();
                nodes.reverse();
                nodes
            })
            .collect()
    };
    let mut builder = Embedding::builder(&mesh.coords);
    for block in &mesh.blocks {
        let conn: Vec<usize> = block.connectivity.iter().map(|n| n.index()).collect();
        builder = builder.block(
            &block.name,
            block.topology,
            &conn,
            example::conductivity_of(&block.name),
        );
    }
    let mut by_code = builder
        .face_set("top", &faces("base_top"))
        .face_set("bottom", &faces("lid_bottom"))
        .dofs(&dof)
        .build()
        .unwrap();
    by_code
        .add_interaction(Interaction::new(
            "top",
            "bottom",
            Model::GapConductance { h: 500.0 },
        ))
        .unwrap();
    by_code.search().unwrap();
    let got = by_code.contributions(&u).unwrap().heat[0].unwrap();
    assert!(relative(got.side_a, expected.side_a) <= 1e-12);
    assert!(relative(got.side_b, expected.side_b) <= 1e-12);
    assert!(expected.side_a.abs() > 1.0);
}

/// Moving the lid up keeps the pairing and measures the opened gap; a new search pairs
/// the same points again.
#[test]
fn embed_move_nodes_updates_gaps() {
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    seam.add_interaction(Interaction::new(
        "base_top",
        "lid_bottom",
        Model::Conductance { h: 500.0 },
    ))
    .unwrap();
    seam.search().unwrap();
    let before = seam.search_stats(0).unwrap().clone();
    assert!(before.gap_max.unwrap().abs() < 1e-12, "{before:?}");
    let lid = mesh.find_block("lid").unwrap();
    let mut lid_nodes: Vec<usize> = mesh.blocks[lid]
        .connectivity
        .iter()
        .map(|n| n.index())
        .collect();
    lid_nodes.sort_unstable();
    lid_nodes.dedup();
    let mut moved = mesh.coords.clone();
    for n in lid_nodes {
        moved[n][2] += 1e-3;
    }
    seam.move_nodes(&moved).unwrap();
    let after = seam.search_stats(0).unwrap();
    assert_eq!(after.matched, before.matched);
    let g = after.gap_max.unwrap();
    assert!((g - 1e-3).abs() < 1e-12, "{g}");
    seam.search().unwrap();
    assert_eq!(seam.search_stats(0).unwrap().matched, before.matched);
}

#[test]
fn embed_bad_input_is_an_error_that_says_where() {
    let coords = [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let conn: Vec<usize> = (0..8).collect();
    let message = |r: Result<Embedding, EmbedError>| match r {
        Ok(_) => panic!("accepted bad input"),
        Err(e) => e.to_string(),
    };
    // A node index past the end.
    let mut bad = conn.clone();
    bad[3] = 8;
    let m = message(
        Embedding::builder(&coords)
            .block("b", Topology::Hex8, &bad, 1.0)
            .dofs(&conn)
            .build(),
    );
    assert!(
        m.contains("element 0 (local node 4): node 8 does not exist") && m.contains("help:"),
        "{m}"
    );
    // A face that is no side of any element.
    let m = message(
        Embedding::builder(&coords)
            .block("b", Topology::Hex8, &conn, 1.0)
            .face_set("top", &[[0, 1, 6, 7]])
            .dofs(&conn)
            .build(),
    );
    assert!(
        m.contains("surface `top`, face 0") && m.contains("no side"),
        "{m}"
    );
    // Missing dofs, then a short field.
    let m = message(
        Embedding::builder(&coords)
            .block("b", Topology::Hex8, &conn, 1.0)
            .build(),
    );
    assert!(m.contains("no dof numbers"), "{m}");
    let mut e = Embedding::builder(&coords)
        .block("b", Topology::Hex8, &conn, 1.0)
        .face_set("top", &[[4, 5, 6, 7]])
        .side_set("bottom", &[(0, 5)])
        .dofs(&conn)
        .build()
        .unwrap();
    let err = e
        .add_interaction(Interaction::new("topp", "bottom", Model::TiedNitsche))
        .unwrap_err();
    assert!(err.to_string().contains("did you mean `top`?"), "{err}");
    let err = e
        .add_interaction(Interaction::new(
            "top",
            "bottom",
            Model::GapConductance { h: -1.0 },
        ))
        .unwrap_err();
    assert!(err.to_string().contains("h = -1"), "{err}");
    e.add_interaction(Interaction::new(
        "top",
        "bottom",
        Model::TiedMortar {
            multipliers: Multipliers::Dual,
        },
    ))
    .unwrap();
    let err = e.contributions(&[0.0; 8]).unwrap_err();
    assert!(matches!(err, EmbedError::Order { .. }), "{err}");
    // Top and bottom of one element face apart, a unit away: nothing to tie.
    let err = e.search().unwrap_err();
    assert!(err.to_string().contains("do not overlap anywhere"), "{err}");
    let mut e = Embedding::builder(&coords)
        .block("b", Topology::Hex8, &conn, 1.0)
        .face_set("top", &[[4, 5, 6, 7]])
        .side_set("bottom", &[(0, 5)])
        .dofs(&conn)
        .build()
        .unwrap();
    e.add_interaction(Interaction::new(
        "top",
        "bottom",
        Model::Conductance { h: 1.0 },
    ))
    .unwrap();
    // A flux interaction that pairs nothing is an error that says why, unless allowed.
    let err = e.search().unwrap_err();
    assert!(matches!(err, EmbedError::NothingPaired { .. }), "{err}");
    assert!(err.to_string().contains("surfaces are apart"), "{err}");
    e.allow_unpaired(Some(0), true).unwrap();
    e.search().unwrap();
    assert_eq!(e.coverage(0).unwrap().paired_points, 0);
    let err = e.contributions(&[0.0; 3]).unwrap_err();
    assert!(err.to_string().contains("dof 3 is needed"), "{err}");
    let err = e.add_deck("bad.i", "begin contact definition\n  frobnicate\nend\n");
    assert!(matches!(err, Err(EmbedError::Deck(_))), "{err:?}");
}

/// The C API's boundary: null pointers, unknown codes and a panic-free failure path,
/// called through the Rust declarations of the same functions.
#[test]
fn embed_c_api_reports_errors_by_code() {
    use seam::capi::*;
    use std::ffi::CStr;
    let last = || {
        unsafe { CStr::from_ptr(seam_last_error()) }
            .to_string_lossy()
            .into_owned()
    };
    let mut b = std::ptr::null_mut();
    let status = unsafe { seam_builder_new(std::ptr::null(), 3, &mut b) };
    assert_eq!(status, SeamStatus::NullArgument as i32);
    assert!(last().contains("coords is null"), "{}", last());
    let coords = [0.0f64; 24];
    assert_eq!(unsafe { seam_builder_new(coords.as_ptr(), 8, &mut b) }, 0);
    let conn: Vec<i64> = (0..8).collect();
    let name = c"b";
    let status = unsafe { seam_builder_add_block(b, name.as_ptr(), 99, conn.as_ptr(), 1, 1.0) };
    assert_eq!(status, SeamStatus::Argument as i32);
    assert!(last().contains("unknown topology code 99"), "{}", last());
    // All nodes at the origin: the element is degenerate, a mesh error, not a crash.
    assert_eq!(
        unsafe { seam_builder_add_block(b, name.as_ptr(), 1, conn.as_ptr(), 1, 1.0) },
        0
    );
    assert_eq!(unsafe { seam_builder_set_dofs(b, conn.as_ptr(), 8) }, 0);
    let mut e = std::ptr::null_mut();
    let status = unsafe { seam_embedding_new(b, &mut e) };
    assert_eq!(status, SeamStatus::Mesh as i32, "{}", last());
    assert!(e.is_null());
    assert!(last().contains("degenerate"), "{}", last());
    unsafe { seam_builder_free(b) };
    let status = unsafe { seam_search(std::ptr::null_mut()) };
    assert_eq!(status, SeamStatus::NullArgument as i32);
}

/// Every function the C API exports is declared in `include/seam.h` and every
/// declaration is exported, with the same number of parameters.
#[test]
fn embed_header_declares_the_exported_functions() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<_> = std::fs::read_dir(root.join("src/capi"))
        .unwrap()
        .map(|f| f.unwrap().path())
        .collect();
    files.sort();
    let source: String = files
        .iter()
        .map(|f| std::fs::read_to_string(f).unwrap())
        .collect();
    let text = std::fs::read_to_string(root.join("include/seam.h")).unwrap();
    // Declarations only: drop the comments (their usage lines name the functions too).
    let mut header = String::new();
    let mut rest = text.as_str();
    while let Some(open) = rest.find("/*") {
        header.push_str(&rest[..open]);
        rest = rest[open..]
            .find("*/")
            .map_or("", |close| &rest[open + close + 2..]);
    }
    header.push_str(rest);
    // name → parameter count, from `extern "C" fn name(a: A, b: B) -> R`.
    let arity = |text: &str, open: usize| -> usize {
        let close = open + text[open..].find(')').unwrap();
        let inside = text[open + 1..close].trim();
        if inside.is_empty() || inside == "void" {
            0
        } else {
            inside.split(',').filter(|p| !p.trim().is_empty()).count()
        }
    };
    let mut exported = Vec::new();
    for (at, _) in source.match_indices("extern \"C\" fn seam_") {
        let start = at + "extern \"C\" fn ".len();
        let open = start + source[start..].find('(').unwrap();
        let name = &source[start..open];
        exported.push((name.to_string(), arity(&source, open)));
    }
    let mut declared = Vec::new();
    for (at, _) in header
        .match_indices(" seam_")
        .chain(header.match_indices("*seam_"))
    {
        let start = at + 1;
        let Some(len) = header[start..].find(|c: char| !(c.is_alphanumeric() || c == '_')) else {
            continue;
        };
        let name = &header[start..start + len];
        if header[start + len..].starts_with('(') {
            declared.push((name.to_string(), arity(&header, start + len)));
        }
    }
    exported.sort();
    declared.sort();
    declared.dedup();
    assert!(exported.len() >= 20, "{exported:?}");
    assert_eq!(exported, declared);
}

/// `seam run` on `examples/<scene>/<problem>` as it stands, except that the mesh and the
/// contact deck are read in place (absolute paths) and nothing is written; the deck's
/// folder may be another copy of the scene (a plugin library built next to it).
pub(crate) fn run_scene(scene: &Path, deck_dir: &Path, problem: &str) -> seam::run::RunResult {
    run_scene_with(scene, deck_dir, problem, None)
}

/// As [`run_scene`], writing the output into `out`.
fn run_scene_into(scene: &Path, deck_dir: &Path, problem: &str, out: &Path) {
    run_scene_with(scene, deck_dir, problem, Some(out));
}

fn run_scene_with(
    scene: &Path,
    deck_dir: &Path,
    problem: &str,
    out: Option<&Path>,
) -> seam::run::RunResult {
    let text = std::fs::read_to_string(scene.join(problem)).unwrap();
    let mut table: toml::Table = toml::from_str(&text).unwrap();
    for (key, folder) in [("mesh", scene), ("contact", deck_dir)] {
        if let Some(section) = table.get_mut(key).and_then(toml::Value::as_table_mut) {
            let file = section["file"].as_str().unwrap().to_string();
            section.insert(
                "file".into(),
                folder.join(file).display().to_string().into(),
            );
        }
    }
    table.remove("output");
    if let Some(out) = out {
        let mut section = toml::Table::new();
        section.insert("dir".into(), out.display().to_string().into());
        table.insert("output".into(), section.into());
    }
    let dir = scratch(&format!("embed-run-{problem}"));
    let name = deck_dir.file_name().unwrap().to_string_lossy().into_owned();
    let path = dir.path().join(format!("{name}-{problem}"));
    std::fs::write(&path, toml::to_string(&table).unwrap()).unwrap();
    let result = match seam::run::run(&path) {
        Ok(r) => r,
        Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
        Err(seam::run::RunError::Solve(e)) => panic!("seam run failed: {e}"),
    };
    assert!(result.summary.converged);
    result
}

fn turbine() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/turbine_sector")
}

/// The turbine-sector problem as a host assembles it (problem.toml restated): k = 20,
/// the rim's flux q(θ) = 5e4 (1 + 0.5 cos(12θ − 1)) evaluated at each face's centroid
/// (as `seam run` evaluates an expression), the bore's convection h = 2000 to 300 K,
/// with seam's public element kernels; then the tie's rows `C u = g` from `tie`, and
/// `[K Cᵀ; C 0] [u; λ] = [F; g]` solved densely with pivoting. Returns the temperature
/// by node and the tie's heat from λ.
fn turbine_host(
    mesh: &seam::mesh::Mesh,
    dof: &[usize],
    tie: &seam::embed::TieConstraints,
) -> (Vec<f64>, seam::embed::Heat, Vec<f64>) {
    use seam::heat::kernel::{face_convection, face_flux};
    let n = mesh.num_nodes();
    let m = tie.multiplier_dofs.len();
    let size = n + m;
    let k = example::conduction_with(mesh, dof, |_| 20.0).unwrap();
    let mut a = vec![0.0; size * size];
    for row in 0..n {
        a[row * size..row * size + n].copy_from_slice(&k[row * n..(row + 1) * n]);
    }
    let mut f = vec![0.0; size];
    let side_set = |name: &str| &mesh.side_sets[mesh.find_side_set(name).unwrap()].sides;
    for (set, convection) in [("rim", false), ("bore", true)] {
        for &side in side_set(set) {
            let topology = mesh.topology(side.elem);
            let nodes = mesh.elem_nodes(side.elem);
            let x: Vec<[f64; 3]> = nodes.iter().map(|v| mesh.coords[v.index()]).collect();
            let nn = nodes.len();
            let (mut ke, mut fe) = (vec![0.0; nn * nn], vec![0.0; nn]);
            if convection {
                face_convection(topology, &x, side.side, 2000.0, 300.0, &mut ke, &mut fe);
            } else {
                let corners: Vec<[f64; 3]> = mesh
                    .side_nodes(side)
                    .map(|v| mesh.coords[v.index()])
                    .collect();
                let c = corners.iter().fold([0.0; 3], |c, p| {
                    std::array::from_fn(|d| c[d] + p[d] / corners.len() as f64)
                });
                let q = 5e4 * (1.0 + 0.5 * (12.0 * c[1].atan2(c[0]) - 1.0).cos());
                face_flux(topology, &x, side.side, |_| q, &mut fe);
            }
            for (i, vi) in nodes.iter().enumerate() {
                f[dof[vi.index()]] += fe[i];
                for (j, vj) in nodes.iter().enumerate() {
                    a[dof[vi.index()] * size + dof[vj.index()]] += ke[i * nn + j];
                }
            }
        }
    }
    for &(mult, j, c) in &tie.entries {
        a[(n + mult) * size + j] += c;
        a[j * size + n + mult] += c;
    }
    f[n..].copy_from_slice(&tie.rhs);
    let x = example::solve_dense(a, f, size).unwrap();
    let heat = tie.heat(&x[n..]).unwrap();
    ((0..n).map(|i| x[dof[i]]).collect(), heat, x[n..].to_vec())
}

fn relative_spread(a: &[f64], b: &[f64]) -> f64 {
    let worst = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max);
    let (lo, hi) = b
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    worst / (hi - lo)
}

/// The turbine sector's cylindrical periodicity through the embedding API — from its
/// deck, and built in code — gives `seam run`'s temperatures and cut heat.
///
/// The host assembles the same discrete equations as `seam run` (the same kernels and
/// the same tie rows) but solves them densely with partial pivoting instead of a sparse
/// saddle-point factorisation: what differs is round-off amplified by the conditioning
/// of the saddle-point system. 1e-10 relative (of the heat; of the temperature spread
/// node by node) leaves room for that, while a missed face, a wrong image or a dof
/// mapped wrong moves the answers by percents.
#[test]
fn embed_turbine_sector_periodic_tie_matches_seam_run() {
    let _turn = crate::TURBINE_RUNS
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let reference = run_scene(&turbine(), &turbine(), "problem.toml");
    let cut = &reference.summary.interactions[0];
    let mesh = seam::mesh::read(&turbine().join("sector.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let builder = || {
        example::embedding_with(&mesh, &dof, |_| 20.0)
            .build()
            .unwrap()
    };

    let mut by_deck = builder();
    assert_eq!(
        by_deck
            .add_deck_file(&turbine().join("contact.i"))
            .unwrap()
            .len(),
        1
    );
    assert_eq!(by_deck.surfaces(0), Some(("start", "end")));
    by_deck.search().unwrap();
    let ties = by_deck.constraints().unwrap();
    assert_eq!(ties.len(), 1);
    // One multiplier per node of cut_start: 7 radii × 3 heights.
    assert_eq!(ties[0].multiplier_dofs.len(), 21);
    let (temperature, heat, lambda) = turbine_host(&mesh, &dof, &ties[0]);
    let t_err = relative_spread(&temperature, &reference.solution.temperature);
    let q_err = relative(heat.side_a, cut.heat_side_a);
    println!(
        "turbine sector by deck: cut heat {:.15e} W, seam run {:.15e} W: {q_err:.2e}; temperatures {t_err:.2e} of the spread",
        heat.side_a, cut.heat_side_a
    );
    assert!(q_err <= 1e-10, "{q_err:.3e}");
    assert!(relative(heat.side_b, cut.heat_side_b) <= 1e-10);
    assert!(t_err <= 1e-10, "{t_err:.3e}");
    // Heat crosses the cut (the load is not symmetric within the sector).
    assert!(heat.side_a.abs() > 1.0, "{}", heat.side_a);
    // The multiplier field on the periodic image, point by point, against `seam run`'s
    // contact_points.vtu of the same deck.
    let deck_tmp = scratch("embed-turbine-points-deck");
    let deck_dir = deck_tmp.path();
    let deck = std::fs::read_to_string(turbine().join("contact.i")).unwrap();
    std::fs::write(
        deck_dir.join("contact.i"),
        deck.replacen(
            "  periodicity for",
            "  visualize contact\n  output rule = more verbose\n  periodicity for",
            1,
        ),
    )
    .unwrap();
    let out = scratch("embed-turbine-points");
    run_scene_into(&turbine(), deck_dir, "problem.toml", out.path());
    let xml = std::fs::read_to_string(out.path().join("contact_points.vtu")).unwrap();
    let file = crate::run_fields::vtu_array(&xml, "interface_flux");
    let points = by_deck.tie_point_fields(&ties[0], &lambda).unwrap();
    assert_eq!(points.len(), file.len());
    let scale = file
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let mut worst = 0.0f64;
    for (p, f) in points.iter().zip(&file) {
        assert_eq!(p.multiplier.is_some(), f.is_finite(), "{p:?} {f}");
        if let Some(m) = p.multiplier {
            worst = worst.max((m - f).abs() / scale);
        }
    }
    println!(
        "turbine sector: λ_h at {} points, largest difference {worst:.2e}",
        points.len()
    );
    assert!(worst <= 1e-9, "{worst:.3e}");

    // The same periodicity built in code, on the side sets themselves.
    let mut by_code = builder();
    by_code
        .add_interaction(
            Interaction::new(
                "cut_start",
                "cut_end",
                Model::TiedMortar {
                    multipliers: Multipliers::Standard,
                },
            )
            .periodic(Periodic::Cylindrical {
                axis: [0.0, 0.0, 1.0],
                center: [0.0; 3],
                angle: 30.0,
            }),
        )
        .unwrap();
    by_code.search().unwrap();
    let code_ties = by_code.constraints().unwrap();
    assert_eq!(code_ties[0].entries, ties[0].entries);
    let (_, code_heat, _) = turbine_host(&mesh, &dof, &code_ties[0]);
    assert_eq!(code_heat, heat);

    // Moving every node by a rigid turn about the axis keeps the sector periodic: the
    // image is remade from the moved cut and the pairing keeps its gaps at zero.
    let (s, c) = 10f64.to_radians().sin_cos();
    let turned: Vec<[f64; 3]> = mesh
        .coords
        .iter()
        .map(|p| [c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])
        .collect();
    by_code.move_nodes(&turned).unwrap();
    let stats = by_code.search_stats(0).unwrap();
    assert!(
        stats.gap_max.unwrap().abs() < 1e-12 && stats.gap_min.unwrap().abs() < 1e-12,
        "{stats:?}"
    );

    // A wrong angle is refused in code as in a deck: the image misses side B.
    let mut wrong = builder();
    let err = wrong
        .add_interaction(
            Interaction::new("cut_start", "cut_end", Model::TiedNitsche).periodic(
                Periodic::Cylindrical {
                    axis: [0.0, 0.0, 1.0],
                    center: [0.0; 3],
                    angle: 20.0,
                },
            ),
        )
        .unwrap_err();
    assert!(
        err.to_string()
            .contains("its image does not land on `cut_end`"),
        "{err}"
    );

    // A map that collapses the cut onto one point is refused before any landing check.
    let mut collapsing = builder();
    let err = collapsing
        .add_interaction(
            Interaction::new("cut_start", "cut_end", Model::TiedNitsche).periodic(
                Periodic::Mapped {
                    x: "0".into(),
                    y: "0".into(),
                    z: Some("0".into()),
                },
            ),
        )
        .unwrap_err();
    assert!(
        err.to_string().contains("the map is not one-to-one"),
        "{err}"
    );
    assert!(!err.to_string().contains("does not land"), "{err}");
}

/// The plugin-conductance scene through the embedding API: the deck's C table plugin
/// (built next to a copy of the deck, as `seam run` finds it) loaded by `add_deck_file`
/// with its Real Data, the host's Newton solve, against `seam run`'s interface heat.
///
/// Both solve the same discrete equations by Newton to a converged field (the plugin's
/// h = 5500 W/m²K does not depend on the temperatures): the difference is round-off in
/// the solves, 1e-10 relative leaves two orders above it.
#[test]
fn embed_plugin_conductance_matches_seam_run() {
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/plugin_conductance");
    let deck_tmp = crate::examples::copy_scene_as("plugin_conductance", "embed-plugin");
    let deck_dir = deck_tmp.path();
    crate::examples::compile_c_table(deck_dir);
    let reference = run_scene(&scene, deck_dir, "problem.toml");
    let i = &reference.summary.interactions[0];

    let mesh = seam::mesh::read(&scene.join("plugin_conductance.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let k = |block: &str| if block == "base" { 16.0 } else { 200.0 };
    let mut seam = example::embedding_with(&mesh, &dof, k).build().unwrap();
    seam.add_deck_file(&deck_dir.join("contact.i")).unwrap();
    seam.search().unwrap();
    let conduction = example::conduction_with(&mesh, &dof, k).unwrap();
    let fixed = example::dirichlet_on(&mesh, &dof, &[("base_bottom", 350.0), ("cover_top", 300.0)])
        .unwrap();
    let (u, steps) = example::newton(&seam, &conduction, &fixed).unwrap();
    let heat = seam.contributions(&u).unwrap().heat[0].unwrap();
    let err = relative(heat.side_a, i.heat_side_a);
    println!(
        "plugin conductance: embedding {:.15e} W, seam run {:.15e} W: {err:.2e} ({steps} Newton steps)",
        heat.side_a, i.heat_side_a
    );
    assert!(err <= 1e-10, "{err:.3e}");
    assert!(relative(heat.side_b, i.heat_side_b) <= 1e-10);
    // The base (350 K) heats the cover: heat leaves side A.
    assert!(heat.side_a > 0.0);
    // Point by point, the plugin's flux against `seam run`'s contact_points.vtu.
    let deck = std::fs::read_to_string(deck_dir.join("contact.i")).unwrap();
    std::fs::write(
        deck_dir.join("contact.i"),
        deck.replacen(
            "  begin interaction",
            "  visualize contact\n  output rule = more verbose\n  begin interaction",
            1,
        ),
    )
    .unwrap();
    let out = scratch("embed-plugin-points");
    run_scene_into(&scene, deck_dir, "problem.toml", out.path());
    let xml = std::fs::read_to_string(out.path().join("contact_points.vtu")).unwrap();
    let file = crate::run_fields::vtu_array(&xml, "interface_flux");
    let points = seam.point_fields(0, &u).unwrap();
    assert_eq!(points.len(), file.len());
    let scale = file
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f64, |m, v| m.max(v.abs()));
    let worst = points
        .iter()
        .zip(&file)
        .map(|(p, f)| {
            assert_eq!(p.paired, f.is_finite());
            if p.paired {
                (p.flux - f).abs() / scale
            } else {
                0.0
            }
        })
        .fold(0.0, f64::max);
    println!(
        "plugin conductance: {} points, largest flux difference {worst:.2e}",
        points.len()
    );
    assert!(worst <= 1e-9, "{worst:.3e}");
}

/// Compile the faulty test plugin with FAULT_<fault> (faults strike points with contact
/// pressure ≥ 100) into this module's own folder; returns its path.
fn faulty_plugin(fault: &str) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("embed-plugins");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!(
        "{}faulty_{}{}",
        std::env::consts::DLL_PREFIX,
        fault.to_lowercase(),
        std::env::consts::DLL_SUFFIX
    ));
    // A private name, then a rename: a library already mapped keeps its inode.
    let partial = dir.join(format!("{fault}.{}.partial", std::process::id()));
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let status = Command::new(&cc)
        .args([
            "-std=c99", "-Wall", "-Wextra", "-Werror", "-O2", "-shared", "-fPIC", "-I",
        ])
        .arg(root.join("plugins/include"))
        .arg(format!("-DFAULT_{fault}"))
        .arg(root.join("plugins/tests/faulty/faulty.c"))
        .arg("-o")
        .arg(&partial)
        .arg("-lm")
        .status()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{cc}`: {e}"));
    assert!(
        status.success(),
        "compiling the FAULT_{fault} plugin failed"
    );
    std::fs::rename(&partial, &out).unwrap();
    out
}

/// The two-block interface with the plugin `library` as its conductance, at contact
/// pressure `pressure`.
fn plugin_deck(library: &Path, pressure: f64) -> String {
    format!(
        "begin contact definition plugged
  contact surface a contains base_top
  contact surface b contains lid_bottom
  begin interaction
    side a a
    side b b
  end
  begin enforcement
    enforcement for energy = plugin library = {library:?}
    contact pressure = {pressure}
  end
end
",
        library = library.display().to_string()
    )
}

/// A plugin's error and its cutback request come back from `contributions` as their
/// own errors, naming the plugin and the point, and through the C API as
/// SEAM_ERR_PLUGIN and SEAM_CUTBACK with the plugin's suggested factor; a library that
/// is not there is SEAM_ERR_PLUGIN when the deck is added.
#[test]
fn embed_plugin_faults_and_cutbacks_are_reported() {
    use seam::capi::*;
    use std::ffi::{CStr, CString};
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let u = vec![300.0; mesh.num_nodes()];
    let (error, cutback) = (faulty_plugin("ERROR"), faulty_plugin("CUTBACK"));

    // Rust: below the faults' pressure the plugin answers h = 1; above, it fails.
    let evaluate = |library: &Path, pressure: f64| {
        let mut seam = example::embedding(&mesh, &dof).build().unwrap();
        seam.add_deck("plugged.i", &plugin_deck(library, pressure))
            .unwrap();
        seam.search().unwrap();
        seam.contributions(&u)
    };
    assert!(evaluate(&error, 50.0).is_ok());
    match evaluate(&error, 1000.0) {
        Err(e @ EmbedError::Plugin { .. }) => {
            let m = e.to_string();
            for needle in [
                "interaction a / b",
                "plugin faulty",
                "side-A face (element",
                "pressure 1000 is beyond the measured range",
                "seam check-plugin",
            ] {
                assert!(m.contains(needle), "`{needle}` missing from: {m}");
            }
        }
        other => panic!("expected a plugin error, got {other:?}"),
    }
    match evaluate(&cutback, 1000.0) {
        Err(EmbedError::Cutback {
            factor, message, ..
        }) => {
            assert_eq!(factor, 0.25);
            assert!(
                message.contains("coating creep increment too large"),
                "{message}"
            );
        }
        other => panic!("expected a cutback, got {other:?}"),
    }

    // C: the same through seam.h's functions.
    let last = || {
        unsafe { CStr::from_ptr(seam_last_error()) }
            .to_string_lossy()
            .into_owned()
    };
    let coords: Vec<f64> = mesh.coords.iter().flatten().copied().collect();
    let dofs: Vec<i64> = dof.iter().map(|&d| d as i64).collect();
    let mut b = std::ptr::null_mut();
    assert_eq!(
        unsafe { seam_builder_new(coords.as_ptr(), mesh.num_nodes(), &mut b) },
        0
    );
    for block in &mesh.blocks {
        let conn: Vec<i64> = block.connectivity.iter().map(|v| v.0 as i64).collect();
        let name = CString::new(block.name.as_str()).unwrap();
        let k = example::conductivity_of(&block.name);
        let status =
            unsafe { seam_builder_add_block(b, name.as_ptr(), 1, conn.as_ptr(), block.len(), k) };
        assert_eq!(status, 0, "{}", last());
    }
    for set in &mesh.side_sets {
        let elems: Vec<i64> = set.sides.iter().map(|s| s.elem.0 as i64).collect();
        let sides: Vec<i32> = set.sides.iter().map(|s| i32::from(s.side)).collect();
        let name = CString::new(set.name.as_str()).unwrap();
        let status = unsafe {
            seam_builder_add_side_set(
                b,
                name.as_ptr(),
                elems.as_ptr(),
                sides.as_ptr(),
                elems.len(),
            )
        };
        assert_eq!(status, 0, "{}", last());
    }
    assert_eq!(
        unsafe { seam_builder_set_dofs(b, dofs.as_ptr(), dofs.len()) },
        0
    );
    let c_evaluate = |deck: &str| -> (i32, String, Option<f64>) {
        let mut e = std::ptr::null_mut();
        assert_eq!(unsafe { seam_embedding_new(b, &mut e) }, 0, "{}", last());
        let text = CString::new(deck).unwrap();
        let mut status =
            unsafe { seam_add_deck(e, text.as_ptr(), std::ptr::null(), std::ptr::null_mut()) };
        if status == 0 {
            assert_eq!(unsafe { seam_search(e) }, 0, "{}", last());
            status = unsafe { seam_evaluate(e, u.as_ptr(), u.len()) };
        }
        let message = last();
        let mut factor = f64::NAN;
        let factor = (unsafe { seam_cutback_factor(e, &mut factor) } == 0).then_some(factor);
        unsafe { seam_embedding_free(e) };
        (status, message, factor)
    };
    let (status, message, factor) = c_evaluate(&plugin_deck(&error, 1000.0));
    assert_eq!(status, SeamStatus::Plugin as i32, "{message}");
    assert_eq!(status, 8, "SEAM_ERR_PLUGIN in seam.h");
    assert!(message.contains("plugin faulty"), "{message}");
    assert_eq!(factor, None);
    let (status, message, factor) = c_evaluate(&plugin_deck(&cutback, 1000.0));
    assert_eq!(status, SeamStatus::Cutback as i32, "{message}");
    assert_eq!(status, 9, "SEAM_CUTBACK in seam.h");
    assert!(message.contains("plugin faulty"), "{message}");
    assert_eq!(factor, Some(0.25));
    let missing = error.with_file_name("libnot_there.so");
    let (status, message, _) = c_evaluate(&plugin_deck(&missing, 1000.0));
    assert_eq!(status, SeamStatus::Plugin as i32, "{message}");
    assert!(
        message.contains("libnot_there.so") && message.contains("does not exist"),
        "{message}"
    );
    unsafe { seam_builder_free(b) };
}

/// The C host of the turbine sector (`examples/c_host/sector.c`): its own mesh (the
/// grid of make_meshes.py, generated in C), its own assembly, and the cylindrical
/// periodicity from `seam_add_periodic_interaction`, against `seam run` on the scene.
///
/// Tolerance 1e-9 relative (the module's): the C host's coordinates come from its own
/// trigonometry and powers (an ulp from numpy's in the mesh file) and it solves densely,
/// so round-off differs; a wrong map, face or dof would move the heat by percents.
#[test]
fn embed_c_sector_host_matches_seam_run() {
    let _turn = crate::TURBINE_RUNS
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    let stdout = run_c_host("sector.c");
    assert!(
        stdout.contains("expected error 4: periodic interaction cut_start / cut_end: its image does not land on `cut_end`"),
        "{stdout}"
    );
    let reference = run_scene(&turbine(), &turbine(), "problem.toml");
    let cut = &reference.summary.interactions[0];
    let heat = printed(&stdout, "periodic tie heat: side A ");
    let range = printed(&stdout, "temperature: min ");
    let t = &reference.solution.temperature;
    let (lo, hi) = t
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    println!(
        "C sector host: cut heat {:.15e} W, seam run {:.15e} W: {:.2e}; lowest and highest temperatures off by {:.2e} and {:.2e} of the spread",
        heat[0],
        cut.heat_side_a,
        relative(heat[0], cut.heat_side_a),
        (range[0] - lo).abs() / (hi - lo),
        (range[1] - hi).abs() / (hi - lo)
    );
    assert!(relative(heat[0], cut.heat_side_a) <= TOLERANCE);
    assert!(relative(heat[1], cut.heat_side_b) <= TOLERANCE);
    assert!((range[0] - lo).abs() <= TOLERANCE * (hi - lo));
    assert!((range[1] - hi).abs() <= TOLERANCE * (hi - lo));
}

/// The host's clock reaches the conductance: with `h = 100 (1 + t)`, the residual at
/// t = 2 equals that of a constant h = 300 (to round-off: the same forms at the same h),
/// and differs from the residual at t = 0; a non-finite time is refused with a message
/// that says what to pass.
#[test]
fn embed_set_time_reaches_time_dependent_conductances() {
    let deck = |h: &str| {
        format!(
            "begin contact definition clock
  contact surface a contains base_top
  contact surface b contains lid_bottom
  begin interaction
    side a a
    side b b
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = {h}
  end
end
"
        )
    };
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let n = mesh.num_nodes();
    let dof = example::host_dofs(&mesh);
    let build = |h: &str| {
        let mut seam = example::embedding(&mesh, &dof).build().unwrap();
        seam.add_deck("clock.i", &deck(h)).unwrap();
        seam.search().unwrap();
        seam
    };
    let mut clocked = build("lua \"100 * (1 + t)\"");
    let constant = build("constant h = 300");
    // A field with a jump across the interface: 300 K below z = 1, 400 K above.
    let mut u = vec![0.0; n];
    for (i, x) in mesh.coords.iter().enumerate() {
        u[dof[i]] = if x[2] > 1.0 - 1e-9 { 400.0 } else { 300.0 };
    }
    let residual = |seam: &seam::embed::Embedding| -> Vec<f64> {
        let mut r = vec![0.0; n];
        for (d, v) in seam.contributions(&u).unwrap().residual {
            r[d] += v;
        }
        r
    };
    let diff = |a: &[f64], b: &[f64]| {
        let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale
    };
    assert_eq!(clocked.time(), 0.0);
    let target = residual(&constant);
    let at_0 = diff(&residual(&clocked), &target);
    clocked.set_time(2.0).unwrap();
    let at_2 = diff(&residual(&clocked), &target);
    println!("against h = 300: t = 0 off by {at_0:.3e}, t = 2 off by {at_2:.3e} (relative)");
    assert!(at_0 > 1e-2, "{at_0}");
    assert!(at_2 <= 1e-12, "{at_2}");
    let e = clocked.set_time(f64::NAN).unwrap_err().to_string();
    assert!(e.contains("not finite"), "{e}");
}
