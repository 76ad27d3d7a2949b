//! The embedding API a host lives with, tested as a host uses it (only `seam::embed`):
//! point and face fields against `seam run`'s contact output on the same scene, the
//! coverage calls and the pairs-nothing error, the CSR Jacobian against the triplets
//! and finite differences with its pattern kept, conductances from host closures, the
//! heat of a state the host names, and the validator naming the real cause.
//!
//! Tolerances: fields and heats compare the same discrete quantities computed through
//! two paths (the host's dense Newton vs `seam run`'s sparse solve), so they agree to
//! the solves' round-off times the condition number (~1e-12 relative here); 1e-9 leaves
//! room and still catches a wrong point order, face or form. Finite differences: central,
//! step 1e-4 K on a quadratic-in-T conductance, truncation ~1e-8 relative; 1e-6 asserted.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use seam::embed::{
    Conductance, EmbedError, Embedding, FnConductance, Interaction, Model, PointState, Topology,
    UnpairedReason,
};
use tempfile::TempDir;

use crate::scratch;

use crate::embed::example;

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks")
}

/// `seam run` on the two-block problem with `deck`, in a scratch folder whose `out/`
/// receives the output; returns that folder.
pub(crate) fn seam_run_with_output(name: &str, deck: &str) -> TempDir {
    let tmp = scratch(&format!("embed-api-{name}"));
    let dir = tmp.path();
    let problem = std::fs::read_to_string(scene().join("problem.toml")).unwrap();
    let mesh = scene().join("two_blocks.exo");
    let problem = problem.replace(
        "file = \"two_blocks.exo\"",
        &format!("file = {:?}", mesh.display().to_string()),
    );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    std::fs::write(dir.join("contact_run.i"), deck).unwrap();
    if let Err(e) = seam::run::run(&dir.join("problem.toml")) {
        panic!("seam run failed: {e:?}");
    }
    tmp
}

fn vtu(path: &Path, name: &str) -> Vec<f64> {
    crate::run_fields::vtu_array(&std::fs::read_to_string(path).unwrap(), name)
}

/// The two-block scene as a host solves it: the embedding (deck `contact_run.i`) and
/// the converged field.
pub(crate) fn host_solution(deck: &str) -> (Embedding, Vec<f64>) {
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    seam.add_deck("contact_run.i", deck).unwrap();
    seam.search().unwrap();
    let k = example::conduction(&mesh, &dof).unwrap();
    let fixed = example::dirichlet(&mesh, &dof).unwrap();
    let (u, _) = example::newton(&seam, &k, &fixed).unwrap();
    (seam, u)
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(1e-300);
    a.iter()
        .zip(b)
        .map(|(x, y)| {
            if x.is_nan() && y.is_nan() {
                0.0
            } else {
                (x - y).abs() / scale
            }
        })
        .fold(0.0, f64::max)
}

#[test]
fn embed_point_and_face_fields_match_seam_run() {
    let deck = std::fs::read_to_string(scene().join("contact_run.i"))
        .unwrap()
        .replace("output rule = verbose", "output rule = more verbose");
    let run = seam_run_with_output("fields", &deck);
    let out = run.path().join("out");
    let (seam, u) = host_solution(&deck);

    // Per point, in the pairing's order: flux (NaN where unpaired in the file) and gap.
    let points = seam.point_fields(0, &u).unwrap();
    let file_flux = vtu(&out.join("contact_points.vtu"), "interface_flux");
    let file_weight = vtu(&out.join("contact_points.vtu"), "weight");
    let host_flux: Vec<f64> = points
        .iter()
        .map(|p| if p.paired { p.flux } else { f64::NAN })
        .collect();
    let host_weight: Vec<f64> = points.iter().map(|p| p.weight).collect();
    let (df, dw) = (
        largest_difference(&file_flux, &host_flux),
        largest_difference(&file_weight, &host_weight),
    );
    println!(
        "{} points: flux {df:.2e}, weight {dw:.2e} (relative to the largest)",
        points.len()
    );
    assert!(df <= 1e-9 && dw <= 1e-12, "{df:.3e} {dw:.3e}");
    // Σ w q is the heat leaving side A.
    let heat = seam.heat(&u).unwrap()[0].unwrap();
    let sum: f64 = points
        .iter()
        .filter(|p| p.paired)
        .map(|p| p.weight * p.flux)
        .sum();
    assert!(
        (sum - heat.side_a).abs() <= 1e-9 * heat.side_a.abs(),
        "{sum} {}",
        heat.side_a
    );

    // Per face, side A then side B (`Output Rule = more verbose` writes both).
    let faces = seam.face_fields(0, &u, true).unwrap();
    let contact = out.join("contact.vtu");
    for (name, host) in [
        (
            "interface_flux",
            faces.iter().map(|f| f.flux).collect::<Vec<_>>(),
        ),
        ("contact_gap", faces.iter().map(|f| f.gap).collect()),
        (
            "contact_fraction",
            faces.iter().map(|f| f.fraction).collect(),
        ),
        (
            "contact_area",
            faces.iter().map(|f| f.paired_area).collect(),
        ),
    ] {
        let d = largest_difference(&vtu(&contact, name), &host);
        println!("faces {name}: {d:.2e}");
        assert!(d <= 1e-9, "{name}: {d:.3e}");
    }

    // Coverage: the lid covers the base's top exactly, at zero gap.
    let c = seam.coverage(0).unwrap();
    assert_eq!(c.paired_points, c.points);
    assert!(c.unpaired.is_empty());
    assert!(
        (c.area - 1.0).abs() < 1e-12 && (c.paired_area - 1.0).abs() < 1e-12,
        "{c:?}"
    );
    let (lo, hi) = c.gap_range.unwrap();
    assert!(lo.abs() < 1e-12 && hi.abs() < 1e-12, "{lo} {hi}");
}

/// Side A is the base's bottom, side B the lid's top: half a metre apart, facing away.
#[test]
fn embed_nothing_paired_is_an_error_with_its_reasons() {
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    seam.add_interaction(Interaction::new(
        "base_top",
        "lid_top",
        Model::GapConductance { h: 500.0 },
    ))
    .unwrap();
    let err = seam.search().unwrap_err();
    assert!(matches!(err, EmbedError::NothingPaired { .. }), "{err}");
    let text = err.to_string();
    assert!(text.contains("base_top / lid_top paired nothing"), "{text}");
    // Allowed: it stands, and the coverage says what happened point by point.
    seam.allow_unpaired(Some(0), true).unwrap();
    seam.search().unwrap();
    let c = seam.coverage(0).unwrap();
    assert_eq!(c.paired_points, 0);
    assert_eq!(c.paired_area, 0.0);
    assert_eq!(c.gap_range, None);
    assert_eq!(c.unpaired.len(), c.points);
    assert!(
        c.unpaired
            .iter()
            .all(|u| u.reason != UnpairedReason::OutsideSubdomain)
    );
    let u = vec![300.0; mesh.num_nodes()];
    assert_eq!(seam.heat(&u).unwrap()[0].unwrap().side_a, 0.0);
    // Built in code with allow_unpaired() from the start, the same.
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    seam.add_interaction(
        Interaction::new("base_top", "lid_top", Model::GapConductance { h: 500.0 })
            .allow_unpaired(),
    )
    .unwrap();
    seam.search().unwrap();
    // A deck interaction that pairs nothing is refused the same way.
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    let deck = std::fs::read_to_string(scene().join("contact_run.i"))
        .unwrap()
        .replace("contains base_top", "contains base_bottom");
    seam.add_deck("apart.i", &deck).unwrap();
    let err = seam.search().unwrap_err();
    assert!(matches!(err, EmbedError::NothingPaired { .. }), "{err}");
}

/// h = 500 + 0.01 (T_A − 250)² + 0.02 (T_B − 250)²: depends on both temperatures.
fn quadratic_h() -> Arc<FnConductance<impl Fn(&PointState) -> Result<Conductance, String>>> {
    Arc::new(FnConductance::new("quadratic", true, |s: &PointState| {
        let (a, b) = (s.temp_a - 250.0, s.temp_b - 250.0);
        Ok(Conductance {
            h: 500.0 + 0.01 * a * a + 0.02 * b * b,
            dh_dtemp_a: 0.02 * a,
            dh_dtemp_b: 0.04 * b,
            ..Conductance::default()
        })
    }))
}

fn two_blocks(interaction: Interaction) -> (Embedding, usize) {
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    seam.add_interaction(interaction).unwrap();
    seam.search().unwrap();
    (seam, mesh.num_nodes())
}

/// A field that varies over the interface (so every term and derivative is exercised).
fn field(n: usize, shift: f64) -> Vec<f64> {
    (0..n)
        .map(|i| 300.0 + shift + 37.0 * ((i as f64) * 0.7).sin())
        .collect()
}

#[test]
fn embed_csr_jacobian_matches_triplets_and_differences_and_keeps_its_pattern() {
    let (mut seam, n) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(quadratic_h()),
    );
    let u1 = field(n, 0.0);
    let dense = |triplets: &[(usize, usize, f64)]| {
        let mut m = vec![0.0; n * n];
        for &(i, j, v) in triplets {
            m[i * n + j] += v;
        }
        m
    };
    let reference = dense(&seam.contributions(&u1).unwrap().jacobian);
    let residual_ref = {
        let mut r = vec![0.0; n];
        for (d, v) in seam.contributions(&u1).unwrap().residual {
            r[d] += v;
        }
        r
    };
    let (pattern, columns_at, nnz) = {
        let e = seam.evaluate(&u1).unwrap();
        let j = &e.jacobian;
        let mut worst = 0.0f64;
        for i in 0..n {
            for jj in 0..n {
                worst = worst.max((j.get(i, jj) - reference[i * n + jj]).abs());
            }
        }
        let scale = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(worst <= 1e-13 * scale, "CSR vs triplets: {worst:.3e}");
        assert!(largest_difference(&residual_ref, &e.residual) <= 1e-14);
        // No duplicates, sorted rows.
        for i in 0..n {
            let row = &j.columns[j.row_offsets[i]..j.row_offsets[i + 1]];
            assert!(row.windows(2).all(|w| w[0] < w[1]));
        }
        (e.pattern, j.columns.as_ptr(), j.columns.len())
    };
    // Refreshed in place at another state: same pattern, same arrays, new values.
    let u2 = field(n, 40.0);
    let before = seam.evaluation().unwrap().jacobian.values.clone();
    let e = seam.evaluate(&u2).unwrap();
    assert_eq!(e.pattern, pattern);
    assert_eq!(e.jacobian.columns.as_ptr(), columns_at);
    assert_eq!(e.jacobian.columns.len(), nnz);
    assert_ne!(
        e.jacobian.values, before,
        "h depends on T: the values change"
    );
    // The Jacobian is the derivative of the residual (central differences).
    let j2 = e.jacobian.clone();
    let step = 1e-4;
    let mut worst = 0.0f64;
    let mut scale = 0.0f64;
    let interface: Vec<usize> = (0..n).filter(|&c| j2.get(c, c) != 0.0).collect();
    for &c in interface.iter().step_by(7) {
        let mut plus = u2.clone();
        plus[c] += step;
        let mut minus = u2.clone();
        minus[c] -= step;
        let rp = seam.evaluate(&plus).unwrap().residual.clone();
        let rm = seam.evaluate(&minus).unwrap().residual.clone();
        for r in 0..n {
            let fd = (rp[r] - rm[r]) / (2.0 * step);
            worst = worst.max((fd - j2.get(r, c)).abs());
            scale = scale.max(j2.get(r, c).abs());
        }
    }
    println!(
        "CSR Jacobian vs central differences: {:.2e} relative",
        worst / scale
    );
    assert!(worst <= 1e-6 * scale, "{worst:.3e} of {scale:.3e}");
    // A new search makes a new pattern.
    seam.search().unwrap();
    assert_eq!(seam.evaluate(&u1).unwrap().pattern, pattern + 1);
}

/// The residual alone is the evaluation's, bit for bit, added onto what the vector
/// held, with the same heats; an interaction switched off adds nothing.
#[test]
fn embed_residual_alone_is_the_evaluated_residual() {
    let (mut seam, n) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(quadratic_h()),
    );
    let u = field(n, 0.0);
    let (residual, heat) = {
        let e = seam.evaluate(&u).unwrap();
        (e.residual.clone(), e.heat.clone())
    };
    assert!(residual.iter().any(|&v| v != 0.0));
    let mut r = vec![0.0; n];
    assert_eq!(seam.residual_into(&u, &mut r).unwrap(), heat);
    assert!(
        r.iter()
            .zip(&residual)
            .all(|(a, b)| a.to_bits() == b.to_bits()),
        "the residual alone differs from the evaluated one"
    );
    // Added onto the vector's values.
    let mut shifted = vec![1.0; n];
    seam.residual_into(&u, &mut shifted).unwrap();
    assert!(shifted.iter().zip(&residual).all(|(a, b)| *a == 1.0 + b));
    // Too short a vector is refused.
    let error = seam.residual_into(&u, &mut vec![0.0; n - 1]).unwrap_err();
    assert!(
        error.to_string().contains("as long as the field"),
        "{error}"
    );
    seam.set_active(0, false).unwrap();
    let mut off = vec![0.0; n];
    let heat = seam.residual_into(&u, &mut off).unwrap();
    assert!(off.iter().all(|&v| v == 0.0));
    assert_eq!(heat[0].unwrap().side_a, 0.0);
}

#[test]
fn embed_closure_conductance_matches_the_constant_model() {
    let (constant, n) = two_blocks(Interaction::new(
        "base_top",
        "lid_bottom",
        Model::GapConductance { h: 500.0 },
    ));
    let closure = Arc::new(FnConductance::new("500", false, |_: &PointState| {
        Ok(Conductance {
            h: 500.0,
            ..Conductance::default()
        })
    }));
    let (with_closure, _) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(closure),
    );
    let u = field(n, 0.0);
    let (a, b) = (
        constant.heat(&u).unwrap()[0].unwrap(),
        with_closure.heat(&u).unwrap()[0].unwrap(),
    );
    assert!(
        (a.side_a - b.side_a).abs() <= 1e-12 * a.side_a.abs(),
        "{a:?} {b:?}"
    );
    // A closure that fails names the point.
    let failing = Arc::new(FnConductance::new("failing", true, |s: &PointState| {
        if s.x[0] > 0.5 {
            Err("no data past x = 0.5".into())
        } else {
            Ok(Conductance::default())
        }
    }));
    let (broken, _) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::Conductance { h: 0.0 })
            .conductance(failing),
    );
    let err = broken.heat(&u).unwrap_err().to_string();
    assert!(
        err.contains("no data past x = 0.5") && err.contains("element"),
        "{err}"
    );
}

/// `heat(u)` is the heat at the state passed, not at the last evaluation.
#[test]
fn embed_heat_is_for_the_state_passed() {
    let (mut seam, n) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(quadratic_h()),
    );
    let (u1, u2) = (field(n, 0.0), field(n, 25.0));
    let at_u1 = seam.evaluate(&u1).unwrap().heat[0].unwrap();
    let at_u2 = seam.heat(&u2).unwrap()[0].unwrap();
    assert_eq!(seam.contributions(&u2).unwrap().heat[0].unwrap(), at_u2);
    assert_ne!(at_u1, at_u2);
    assert_eq!(seam.evaluation().unwrap().heat[0].unwrap(), at_u1);
}

/// One hex with the host's own node order (the top face first): the element is
/// inverted, and that is what the host is told — not that its faces are no sides.
#[test]
fn embed_validator_names_the_real_cause_first() {
    let coords: Vec<[f64; 3]> = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [0.0, 1.0, 1.0],
    ];
    let host_order = [4, 5, 6, 7, 0, 1, 2, 3];
    let dofs: Vec<usize> = (0..8).collect();
    let err = Embedding::builder(&coords)
        .block("b", Topology::Hex8, &host_order, 1.0)
        .face_set("top", &[[4, 5, 6, 7]])
        .face_set("odd", &[[0, 1, 6, 7]])
        .dofs(&dofs)
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(
        err.contains("inverted") && err.contains("element 0"),
        "{err}"
    );
    // A node out of range is named as such.
    let err = Embedding::builder(&coords)
        .block("b", Topology::Hex8, &[0, 1, 2, 3, 4, 5, 6, 8], 1.0)
        .dofs(&dofs)
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("node 8 does not exist"), "{err}");
    // A 0-based side is told to be one.
    let err = Embedding::builder(&coords)
        .block("b", Topology::Hex8, &dofs, 1.0)
        .side_set("s", &[(0, 0)])
        .dofs(&dofs)
        .build()
        .err()
        .unwrap()
        .to_string();
    assert!(err.contains("1-based"), "{err}");
}

/// The header's table of node order and sides is the one seam uses.
#[test]
fn embed_header_side_table_is_seams() {
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("include/seam.h"))
            .unwrap();
    for (name, topology) in [
        ("SEAM_HEX8", Topology::Hex8),
        ("SEAM_TET4", Topology::Tet4),
        ("SEAM_WEDGE6", Topology::Wedge6),
        ("SEAM_PYRAMID5", Topology::Pyramid5),
        ("SEAM_QUAD4", Topology::Quad4),
        ("SEAM_TRI3", Topology::Tri3),
    ] {
        let at = text.find(&format!(" *   {name} ")).expect(name);
        let block: String = text[at..]
            .lines()
            .skip(1)
            .take_while(|l| !l.contains(" *   SEAM_") && !l.contains("An element whose"))
            .collect::<Vec<_>>()
            .join(" ");
        let block = text[at..].lines().next().unwrap().to_string() + " " + &block;
        for s in 1..=topology.face_side_count() {
            let nodes: Vec<String> = topology.sides()[s - 1]
                .iter()
                .map(|n| n.to_string())
                .collect();
            let want = format!("side {s}: {}", nodes.join(" "));
            assert!(block.contains(&want), "{name}: `{want}` not in `{block}`");
        }
    }
}

/// The embedding reads a deck through the same scene as `seam run`: a `Side B
/// Variable` naming a field the host does not have is the same error (E0428) through
/// both doors, where the embedding once accepted it; and a deck line an embedding
/// cannot honour (`Use Toggle Block`, times of `seam run`'s problem file) is refused.
#[test]
fn embed_reads_a_deck_as_seam_run_does() {
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let deck = std::fs::read_to_string(scene().join("contact_run.i")).unwrap();
    let wrong_field = deck.replace(
        "enforcement for energy = gap_conductance",
        "enforcement for energy = tied\n    side b variable temprature to temperature",
    );
    let mut seam = example::embedding(&mesh, &dof).build().unwrap();
    let err = seam
        .add_deck("wrong.i", &wrong_field)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("E0428") && err.contains("did you mean `temperature`"),
        "{err}"
    );
    let tmp = scratch("embed-api-field");
    let dir = tmp.path();
    let problem = std::fs::read_to_string(scene().join("problem.toml"))
        .unwrap()
        .replace(
            "file = \"two_blocks.exo\"",
            &format!(
                "file = {:?}",
                scene().join("two_blocks.exo").display().to_string()
            ),
        );
    std::fs::write(dir.join("problem.toml"), problem).unwrap();
    std::fs::write(dir.join("contact_run.i"), &wrong_field).unwrap();
    match seam::run::check(&dir.join("problem.toml")) {
        Err(seam::run::RunError::Input(d, _)) => {
            assert!(d.0.iter().any(|x| x.code == "E0428"), "{d:?}")
        }
        Ok(c) => assert!(c.diagnostics.0.iter().any(|x| x.code == "E0428")),
        Err(e) => panic!("{e:?}"),
    }
    let toggled = deck.replace(
        "gap conductance coefficient = constant h = 500",
        "gap conductance coefficient = constant h = 500\n    use toggle block on_off",
    );
    let err = seam
        .add_deck("toggled.i", &toggled)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("E0430") && err.contains("Use Toggle Block"),
        "{err}"
    );
    assert!(seam.is_empty(), "nothing added on an error");
    // A voltage block: `seam run` solves it with the temperature; an embedding joins one
    // field, so it refuses the block rather than leave it out.
    let electrical = deck.replace(
        "  begin interaction",
        "  begin enforcement electrical\n    enforcement for voltage = gap_conductance\n    gap conductance coefficient = constant h = 1e8\n  end\n  begin interaction",
    );
    assert_ne!(electrical, deck);
    let err = seam
        .add_deck("electrical.i", &electrical)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("E0430") && err.contains("Enforcement for Voltage"),
        "{err}"
    );
    assert!(seam.is_empty(), "nothing added on an error");
}

/// h = 800 where x ≤ 0.5, and a model that fails past x = 0.5 (`fail`) or gives 0 there.
fn half_model(
    fail: bool,
) -> Arc<FnConductance<impl Fn(&PointState) -> Result<Conductance, String>>> {
    Arc::new(FnConductance::new("half", true, move |s: &PointState| {
        if s.x[0] > 0.5 {
            return if fail {
                Err("no data past x = 0.5".into())
            } else {
                Ok(Conductance::default())
            };
        }
        Ok(Conductance {
            h: 800.0,
            ..Conductance::default()
        })
    }))
}

/// A quarantined point contributes exactly what h = 0 would, is listed once with its
/// place and reason however often it is evaluated, and without quarantine the same
/// model is an error.
#[test]
fn embed_quarantine_skips_failing_points_and_lists_them() {
    let interaction = |fail| {
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(half_model(fail))
    };
    let (quarantined, n) = two_blocks(interaction(true).quarantine());
    let (zero_there, _) = two_blocks(interaction(false));
    let u = field(n, 0.0);
    let (q, z) = (
        quarantined.contributions(&u).unwrap(),
        zero_there.contributions(&u).unwrap(),
    );
    let (hq, hz) = (q.heat[0].unwrap(), z.heat[0].unwrap());
    assert!(hz.side_a.abs() > 1.0, "the interface carries heat: {hz:?}");
    assert!(
        (hq.side_a - hz.side_a).abs() <= 1e-12 * hz.side_a.abs(),
        "{hq:?} vs {hz:?}"
    );
    assert_eq!(q.jacobian, z.jacobian);
    let listed = quarantined.quarantined(0);
    assert!(!listed.is_empty());
    assert!(
        listed
            .iter()
            .all(|p| p.x[0] > 0.5 && p.message.contains("no data past"))
    );
    // Evaluated again: each place kept once.
    quarantined.contributions(&u).unwrap();
    assert_eq!(quarantined.quarantined(0).len(), listed.len());
    // The points failing are the points of the model's region: every one is listed.
    let past: usize = zero_there
        .point_fields(0, &u)
        .unwrap()
        .iter()
        .filter(|p| p.x[0] > 0.5 && p.paired)
        .count();
    assert_eq!(listed.len(), past);
    let (strict, _) = two_blocks(interaction(true));
    assert!(strict.contributions(&u).is_err());
    assert!(strict.quarantined(0).is_empty());
}

/// `Quarantine Faulty Points` in a deck is honoured by an embedding (it was refused
/// before the embedding could report the points): a Lua coefficient that is NaN past
/// x = 0.5 stops the evaluation without the line and is quarantined there with it.
#[test]
fn embed_deck_quarantine_is_honoured() {
    let deck = std::fs::read_to_string(scene().join("contact_run.i")).unwrap();
    let line = "gap conductance coefficient = constant h = 500\n";
    assert!(deck.contains(line));
    let failing = "gap conductance coefficient = lua \"x > 0.5 and 0/0 or 500\"\n";
    let mesh = seam::mesh::read(&scene().join("two_blocks.exo")).unwrap();
    let dof = example::host_dofs(&mesh);
    let u = field(mesh.num_nodes(), 0.0);
    let embedding = |text: &str| {
        let mut seam = example::embedding(&mesh, &dof).build().unwrap();
        seam.add_deck("contact_run.i", text).unwrap();
        seam.search().unwrap();
        seam
    };
    let strict = embedding(&deck.replace(line, failing));
    assert!(strict.contributions(&u).is_err());
    let quarantined =
        embedding(&deck.replace(line, &format!("{failing}    Quarantine Faulty Points\n")));
    assert!(quarantined.contributions(&u).is_ok());
    let kept = quarantined.quarantined(0);
    assert!(!kept.is_empty());
    assert!(kept.iter().all(|q| q.x[0] > 0.5), "{kept:?}");
}

/// Switched off, a flux interaction adds nothing and reports 0 W; the CSR pattern
/// survives off and on, and the values come back.
#[test]
fn embed_set_active_switches_terms_and_keeps_the_pattern() {
    let (mut seam, n) = two_blocks(Interaction::new(
        "base_top",
        "lid_bottom",
        Model::GapConductance { h: 500.0 },
    ));
    let u = field(n, 0.0);
    let (pattern, values) = {
        let e = seam.evaluate(&u).unwrap();
        assert!(e.heat[0].unwrap().side_a.abs() > 1.0);
        (e.pattern, e.jacobian.values.clone())
    };
    seam.set_active(0, false).unwrap();
    assert!(!seam.is_active(0));
    {
        let e = seam.evaluate(&u).unwrap();
        assert_eq!(e.pattern, pattern);
        assert!(e.jacobian.values.iter().all(|&v| v == 0.0));
        assert!(e.residual.iter().all(|&v| v == 0.0));
        assert_eq!(e.heat[0], Some(seam::embed::Heat::default()));
    }
    let c = seam.contributions(&u).unwrap();
    assert!(c.jacobian.is_empty() && c.residual.is_empty());
    assert_eq!(
        seam.heat(&u).unwrap()[0],
        Some(seam::embed::Heat::default())
    );
    seam.set_active(0, true).unwrap();
    let e = seam.evaluate(&u).unwrap();
    assert_eq!(e.pattern, pattern);
    assert_eq!(e.jacobian.values, values);
    // Off before the first evaluation: the pattern is still the whole interface's.
    let (mut late, _) = two_blocks(Interaction::new(
        "base_top",
        "lid_bottom",
        Model::GapConductance { h: 500.0 },
    ));
    late.set_active(0, false).unwrap();
    let nnz = late.evaluate(&u).unwrap().jacobian.columns.len();
    assert_eq!(nnz, values.len());
    assert!(late.set_active(3, true).is_err());
}

/// Point pressures reach the model: h = 1e-3 p with p set per point equals the constant
/// model at the same h, and a pressure list of the wrong length or sign is refused.
#[test]
fn embed_point_pressures_reach_the_model() {
    let by_pressure = Arc::new(FnConductance::new("h(p)", false, |s: &PointState| {
        Ok(Conductance {
            h: 1e-3 * s.pressure,
            ..Conductance::default()
        })
    }));
    let (mut seam, n) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(by_pressure),
    );
    let (constant, _) = two_blocks(Interaction::new(
        "base_top",
        "lid_bottom",
        Model::GapConductance { h: 700.0 },
    ));
    let u = field(n, 0.0);
    let zero = |seam: &Embedding| seam.heat(&u).unwrap()[0].unwrap().side_a.abs() <= 1e-9;
    assert!(zero(&seam), "no pressure: h = 0");
    let points = seam.coverage(0).unwrap().points;
    seam.set_point_pressures(0, Some(vec![7e5; points]))
        .unwrap();
    let (a, b) = (
        seam.heat(&u).unwrap()[0].unwrap(),
        constant.heat(&u).unwrap()[0].unwrap(),
    );
    assert!(
        (a.side_a - b.side_a).abs() <= 1e-12 * b.side_a.abs(),
        "{a:?} {b:?}"
    );
    assert!(
        seam.set_point_pressures(0, Some(vec![1.0; points + 1]))
            .is_err()
    );
    let mut negative = vec![7e5; points];
    negative[points / 2] = -1.0;
    assert!(seam.set_point_pressures(0, Some(negative)).is_err());
    // A search pairs new points and drops the pressures.
    seam.search().unwrap();
    assert!(zero(&seam));
}

/// A model's request for a smaller step is `Cutback` whatever the model (not only a
/// plugin's), with the factor it asked for.
#[test]
fn embed_cutback_from_any_model() {
    struct Shrink;
    impl seam::embed::ConductanceModel for Shrink {
        fn name(&self) -> String {
            "shrink".into()
        }
        fn evaluate(&self, s: &PointState) -> Result<Conductance, seam::embed::ConductanceError> {
            Err(seam::embed::ConductanceError::Cutback {
                model: "shrink".into(),
                state: *s,
                factor: 0.25,
                message: "too fast".into(),
            })
        }
        fn depends_on_temperature(&self) -> bool {
            true
        }
    }
    let (seam, n) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(Arc::new(Shrink))
            .quarantine(),
    );
    let err = seam.contributions(&field(n, 0.0)).unwrap_err();
    assert!(
        matches!(err, EmbedError::Cutback { factor, .. } if factor == 0.25),
        "{err}"
    );
    assert!(
        seam.quarantined(0).is_empty(),
        "a cutback is no faulty point"
    );
    assert!(!seam.is_linear());
}

/// With the `sprs` feature the Jacobian comes as an `sprs` matrix: the CSR one holds the
/// same entries as the embedding's own, and the triplets summed equal it.
#[cfg(feature = "sprs")]
#[test]
fn embed_jacobian_as_sprs_matches_the_csr_and_the_triplets() {
    let (mut seam, n) = two_blocks(
        Interaction::new("base_top", "lid_bottom", Model::GapConductance { h: 0.0 })
            .conductance(quadratic_h()),
    );
    let u = field(n, 0.0);
    let from_triplets = seam.contributions(&u).unwrap().jacobian_sprs(n);
    let csr = seam.evaluate(&u).unwrap().jacobian.clone();
    let from_csr = csr.to_sprs();
    assert_eq!(from_csr.shape(), (n, n));
    assert_eq!(from_csr.nnz(), csr.values.len());
    let scale = csr.values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mut checked = 0;
    for (v, (i, j)) in from_csr.iter() {
        assert_eq!(*v, csr.get(i, j));
        let t = from_triplets.get(i, j).copied().unwrap_or(0.0);
        assert!(
            (t - v).abs() <= 1e-12 * scale,
            "({i}, {j}): {t} against {v}"
        );
        checked += 1;
    }
    assert!(checked > 0);
    assert!(from_triplets.nnz() <= from_csr.nnz());
}

/// `evaluate` at the field of the last evaluation gives its values again only while
/// nothing else they depend on changed: each of a point pressure, a switch, a move of
/// the field and (for a model of the time) the time reaches the values at once, and
/// going back gives the first values bit for bit. (The CMY model of the deck sees the
/// pressure and not the time; the Lua one sees the time.)
#[test]
fn embed_evaluate_again_follows_every_change_of_its_inputs() {
    let deck = |h: &str| {
        format!(
            "begin contact definition again
  contact surface a contains base_top
  contact surface b contains lid_bottom
  begin interaction
    side a a
    side b b
  end
  begin enforcement
    enforcement for energy = gap_conductance
    gap conductance coefficient = {h}
    contact pressure = 5e5
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
        seam.add_deck("again.i", &deck(h)).unwrap();
        seam.search().unwrap();
        seam
    };
    let values = |seam: &mut Embedding, u: &[f64]| -> (Vec<f64>, Vec<f64>) {
        let e = seam.evaluate(u).unwrap();
        (e.jacobian.values.clone(), e.residual.clone())
    };
    let (u, moved) = (field(n, 0.0), field(n, 5.0));
    let mut cmy = build("cmy k_a = 150 k_b = 200 slope = 0.1 roughness = 1e-6 hardness = 1e9");
    let first = values(&mut cmy, &u);
    assert!(first.1.iter().any(|&r| r != 0.0));
    assert_eq!(values(&mut cmy, &u), first, "the same inputs");
    // Another field, then back.
    assert_ne!(values(&mut cmy, &moved).1, first.1);
    assert_eq!(values(&mut cmy, &u), first);
    // Twice the pressure: the values of the CMY model at 1 MPa, as a deck says it.
    let points = cmy.coverage(0).unwrap().points;
    cmy.set_point_pressures(0, Some(vec![1e6; points])).unwrap();
    let pressed = values(&mut cmy, &u);
    assert_ne!(pressed, first);
    let mut at_1mpa = build("cmy k_a = 150 k_b = 200 slope = 0.1 roughness = 1e-6 hardness = 1e9");
    at_1mpa
        .set_point_pressures(0, Some(vec![1e6; points]))
        .unwrap();
    assert_eq!(values(&mut at_1mpa, &u), pressed);
    cmy.set_point_pressures(0, None).unwrap();
    assert_eq!(values(&mut cmy, &u), first, "the deck's pressure again");
    // Switched off: no terms; on again: the first values.
    cmy.set_active(0, false).unwrap();
    assert!(values(&mut cmy, &u).0.iter().all(|&v| v == 0.0));
    cmy.set_active(0, true).unwrap();
    assert_eq!(values(&mut cmy, &u), first);
    // A model of the time is evaluated again at another time; CMY need not be.
    cmy.set_time(7.0).unwrap();
    assert_eq!(values(&mut cmy, &u), first);
    let mut clocked = build("lua \"100 * (1 + t)\"");
    let at_0 = values(&mut clocked, &u);
    clocked.set_time(2.0).unwrap();
    let at_2 = values(&mut clocked, &u);
    assert_ne!(at_2, at_0);
    // h = 300 at t = 2: the constant model's values, to round-off.
    let constant = values(&mut build("constant h = 300"), &u);
    let scale = constant.1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let off = (at_2.1.iter().zip(&constant.1)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    assert!(off <= 1e-12 * scale, "{off} of {scale}");
}
