//! The linear solver `seam run` picks by itself (`[solve] linear_solver = "auto"`, the
//! default) and the reason it reports: Cholesky below the size threshold, AMG-CG at or
//! above it for a symmetric positive definite system, LDLᵀ whenever multipliers make the
//! system indefinite; `direct` and `amg` still override. The threshold is lowered with
//! the `[solve] auto_threshold` field so that a small scene crosses it.
//!
//! A steady AMG-CG solve stops at ‖b − Ax‖ ≤ 1e-13 ‖b‖
//! (`seam::heat::steady::STEADY_AMG_TOLERANCE`), time steps at 1e-11
//! (`seam::heat::steady::AMG_TOLERANCE`); on the electronics scene (1 043 unknowns, several AMG levels, about 30 CG iterations; a
//! silicon die under an aluminium sink through a pressure-dependent contact conductance,
//! convection outside) that leaves the temperature and the interface heat
//! within 1e-8 relative of the Cholesky answer: they agree to about 1e-13, so the bound
//! keeps five orders of margin for other machines' round-off while still failing if CG
//! stopped at a loose tolerance.

use std::path::{Path, PathBuf};
use std::process::Command;

use seam::run::{RunError, RunResult};
use tempfile::TempDir;

/// Agreement of AMG-CG and Cholesky answers (see the module comment).
const AGREE: f64 = 1e-8;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A copy of `examples/two_blocks` whose `[solve]` table gets `extra` (TOML lines): the
/// scratch folder holding it and its problem file.
fn two_blocks_with(tag: &str, extra: &str) -> (TempDir, PathBuf) {
    scene_with("two_blocks", tag, extra)
}

/// A copy of `examples/<scene>` whose `[solve]` table gets `extra` (TOML lines): the
/// scratch folder holding it and its problem file.
fn scene_with(scene: &str, tag: &str, extra: &str) -> (TempDir, PathBuf) {
    scene_file_with(scene, "problem.toml", tag, extra)
}

/// As [`scene_with`], for the scene's problem file `file`.
fn scene_file_with(scene: &str, file: &str, tag: &str, extra: &str) -> (TempDir, PathBuf) {
    let dir = crate::examples::copy_scene_as(scene, tag);
    let path = dir.path().join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("[solve]\n"), "the scene has a [solve] table");
    std::fs::write(
        &path,
        text.replace("[solve]\n", &format!("[solve]\n{extra}\n")),
    )
    .unwrap();
    (dir, path)
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

fn max_abs(v: &[f64]) -> f64 {
    v.iter()
        .filter(|x| x.is_finite())
        .fold(0.0f64, |m, x| m.max(x.abs()))
}

#[test]
fn auto_factors_a_small_problem() {
    let (_scene, problem) = two_blocks_with("auto-small", "");
    let r = run(&problem);
    let ls = &r.summary.linear_solver;
    assert_eq!(ls.name, "Cholesky");
    assert!(
        ls.reason.starts_with("auto: ")
            && ls.reason.contains("unknowns")
            && ls.reason.contains("Cholesky"),
        "{}",
        ls.reason
    );
    assert_eq!(ls.iterations, 0);
    assert!(ls.iterations_per_solve.is_empty());
}

#[test]
fn auto_uses_amg_above_the_threshold_and_agrees_with_cholesky() {
    let (_direct_scene, problem) = scene_with(
        "electronics",
        "auto-direct",
        "linear_solver = \"direct\"\nauto_threshold = 1",
    );
    let direct = run(&problem);
    let d = &direct.summary.linear_solver;
    assert_eq!(d.name, "Cholesky");
    assert_eq!(d.reason, "requested by linear_solver");

    let (_amg_scene, problem) = scene_with("electronics", "auto-amg", "auto_threshold = 1");
    let amg = run(&problem);
    let a = &amg.summary.linear_solver;
    assert_eq!(a.name, "AMG-CG");
    assert!(
        a.reason.starts_with("auto: ") && a.reason.contains("symmetric positive definite"),
        "{}",
        a.reason
    );
    // More than one CG iteration: the hierarchy has several levels (one iteration would
    // mean the coarse direct solve did all the work).
    assert!(a.iterations > 1, "{a:?}");
    assert_eq!(a.iterations, a.iterations_per_solve.iter().sum::<usize>());

    // Same answer to AGREE, relative to the largest temperature and interface heat.
    let (ta, td) = (&amg.solution.temperature, &direct.solution.temperature);
    assert_eq!(ta.len(), td.len());
    let scale = max_abs(td);
    for (k, (x, y)) in ta.iter().zip(td).enumerate() {
        if y.is_finite() {
            assert!(
                (x - y).abs() <= AGREE * scale,
                "node {k}: AMG {x} vs Cholesky {y}"
            );
        }
    }
    let (ia, id) = (&amg.summary.interactions, &direct.summary.interactions);
    assert_eq!(ia.len(), id.len());
    assert!(!id.is_empty());
    for (x, y) in ia.iter().zip(id) {
        let q = y.heat_side_a.abs().max(y.heat_side_b.abs());
        assert!(q > 0.0);
        assert!(
            (x.heat_side_a - y.heat_side_a).abs() <= AGREE * q,
            "{} vs {}",
            x.heat_side_a,
            y.heat_side_a
        );
        assert!(
            (x.heat_side_b - y.heat_side_b).abs() <= AGREE * q,
            "{} vs {}",
            x.heat_side_b,
            y.heat_side_b
        );
    }
}

#[test]
fn amg_can_be_requested_on_a_small_problem() {
    let (_scene, problem) = two_blocks_with("request-amg", "linear_solver = \"amg\"");
    let r = run(&problem);
    let ls = &r.summary.linear_solver;
    assert_eq!(ls.name, "AMG-CG");
    assert_eq!(ls.reason, "requested by linear_solver");
    assert!(ls.iterations > 0);
}

/// The verification case `tests/cases/<case>` run from a scratch folder, its paths made
/// absolute, no output, with `solve` (key, value) set in its `[solve]` table.
fn run_case_with(case: &str, tag: &str, solve: &[(&str, toml::Value)]) -> RunResult {
    run_case_edited(case, tag, |table| {
        let table_solve = table["solve"].as_table_mut().unwrap();
        for (key, value) in solve {
            table_solve.insert((*key).into(), value.clone());
        }
    })
}

/// [`run_case_with`] with the problem table changed by `edit` instead.
fn run_case_edited(case: &str, tag: &str, edit: impl FnOnce(&mut toml::Table)) -> RunResult {
    let case = root().join("tests/cases").join(case);
    let mut table: toml::Table =
        toml::from_str(&std::fs::read_to_string(case.join("problem.toml")).unwrap()).unwrap();
    let abs =
        |p: &toml::Value| toml::Value::String(case.join(p.as_str().unwrap()).display().to_string());
    let mesh = table["mesh"].as_table_mut().unwrap();
    mesh["file"] = abs(&mesh["file"]);
    let contact = table["contact"].as_table_mut().unwrap();
    contact["file"] = abs(&contact["file"]);
    edit(&mut table);
    table.remove("output");
    let dir = crate::scratch(tag);
    let path = dir.path().join("problem.toml");
    std::fs::write(&path, toml::to_string(&table).unwrap()).unwrap();
    run(&path)
}

#[test]
fn multipliers_keep_the_direct_saddle_point_solver() {
    // The standard Lagrange-multiplier tie of the verification case above a threshold
    // of one unknown: still LDLᵀ.
    let one = ("auto_threshold", toml::Value::Integer(1));
    let r = run_case_with("two_slab_mortar_lagrange", "auto-lagrange", &[one]);
    let ls = &r.summary.linear_solver;
    assert_eq!(ls.name, "LDLᵀ");
    assert!(
        ls.reason.starts_with("auto: ") && ls.reason.contains("indefinite"),
        "{}",
        ls.reason
    );
}

/// A dual mortar tie is condensed to a symmetric positive definite system, which the
/// automatic choice solves like any other: by AMG-CG from the threshold (a
/// factorisation of it at 1.16 M unknowns took minutes), by Cholesky below it. Both
/// give the case's exact T = z/1.5 and its heat, and the same multipliers.
#[test]
fn dual_ties_are_condensed_and_solved_by_amg_above_the_threshold() {
    let case = "two_slab_mortar_dual";
    let one = ("auto_threshold", toml::Value::Integer(1));
    let amg = run_case_with(case, "auto-dual-amg", &[one]);
    let direct = run_case_with(case, "auto-dual-direct", &[]);
    let (ls, ld) = (&amg.summary.linear_solver, &direct.summary.linear_solver);
    assert_eq!((ls.name.as_str(), ld.name.as_str()), ("AMG-CG", "Cholesky"));
    for reason in [&ls.reason, &ld.reason] {
        assert!(
            reason.starts_with("auto: ")
                && reason.contains("dual mortar ties condensed to a symmetric positive definite"),
            "{reason}"
        );
    }
    assert!(ls.iterations > 0);
    for r in [&amg, &direct] {
        let z = |k: usize| r.mesh.coords[k][2];
        for (k, t) in r.solution.temperature.iter().enumerate() {
            assert!(
                (t - z(k) / 1.5).abs() < 1e-12,
                "node {k}: {t} against {}",
                z(k) / 1.5
            );
        }
        let heat = r.summary.interactions[0].heat_side_a;
        assert!((heat + 1.0 / 1.5).abs() < 1e-12, "{heat}");
    }
    // The multipliers, after the temperatures in both.
    let (ua, ud) = (&amg.solution.u, &direct.solution.u);
    assert_eq!(ua.len(), ud.len());
    let n = amg.solution.temperature.len();
    assert!(ua.len() > n, "no multipliers");
    for (k, (x, y)) in ua.iter().zip(ud).enumerate().skip(n) {
        assert!(
            (x - y).abs() < 1e-10 * max_abs(&ud[n..]),
            "multiplier {}: {x} against {y}",
            k - n
        );
    }
}

/// The dual tie's slabs as a transient run (BDF2, from a field off the tie's
/// constraints): its steps condensed and solved by AMG-CG above the threshold, saddle
/// points factored below it — the same temperatures and tie heat at every step's end.
#[test]
fn transient_dual_ties_are_condensed_above_the_threshold_and_agree_with_ldlt() {
    let transient = |threshold: i64| {
        move |table: &mut toml::Table| {
            let solve: toml::Table = toml::from_str(&format!(
                "kind = \"transient\"\nscheme = \"bdf2\"\ndt = 0.05\nend_time = 0.5\n\
                 tolerance = 1e-10\nauto_threshold = {threshold}"
            ))
            .unwrap();
            table.insert("solve".into(), solve.into());
            let initial: toml::Table = toml::from_str("temperature = \"0.3*x*x + 0.5*z\"").unwrap();
            table.insert("initial".into(), initial.into());
            for m in table["material"].as_array_mut().unwrap() {
                let m = m.as_table_mut().unwrap();
                m.insert("density".into(), toml::Value::Float(1.0));
                m.insert("specific_heat".into(), toml::Value::Float(1.0));
            }
        }
    };
    let case = "two_slab_mortar_dual";
    let amg = run_case_edited(case, "transient-dual-amg", transient(1));
    let direct = run_case_edited(case, "transient-dual-direct", transient(1_000_000));
    assert_eq!(amg.summary.linear_solver.name, "AMG-CG");
    assert_eq!(direct.summary.linear_solver.name, "direct");
    assert_eq!(amg.history.len(), direct.history.len());
    assert!(amg.history.len() >= 10);
    for (a, d) in amg.history.iter().zip(&direct.history) {
        let q = d.heat[0].0.abs().max(1e-3);
        assert!(
            (a.heat[0].0 - d.heat[0].0).abs() <= AGREE * q,
            "t = {}: tie heat {} against {}",
            a.time,
            a.heat[0].0,
            d.heat[0].0
        );
    }
    agree_with_cholesky(&amg, &direct);
    let (ua, ud) = (&amg.solution.u, &direct.solution.u);
    let n = amg.solution.temperature.len();
    for (k, (x, y)) in ua.iter().zip(ud).enumerate().skip(n) {
        assert!(
            (x - y).abs() < AGREE * max_abs(&ud[n..]),
            "multiplier {}: {x} against {y}",
            k - n
        );
    }
}

#[test]
fn the_json_summary_and_the_text_name_the_solver() {
    let (_scene, path) = two_blocks_with("auto-json", "auto_threshold = 1");
    let seam = |json: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_seam"));
        c.arg("run").arg(&path);
        if json {
            c.arg("--json");
        }
        let out = c.output().expect("seam runs");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let v: serde_json::Value = serde_json::from_str(&seam(true)).expect("one JSON object");
    let ls = &v["linear_solver"];
    assert_eq!(ls["name"], "AMG-CG");
    assert!(ls["reason"].as_str().unwrap().starts_with("auto: "));
    assert!(ls["iterations"].as_u64().unwrap() > 0);
    assert!(ls["iterations_per_solve"].is_array());
    // The keys that were there before stay.
    for key in [
        "dofs",
        "newton_iterations",
        "converged",
        "interactions",
        "timing",
    ] {
        assert!(v.get(key).is_some(), "{key} missing");
    }
    let text = seam(false);
    assert!(text.contains("linear solver: AMG-CG (auto: "), "{text}");
    assert!(text.contains("CG iterations"), "{text}");
}

#[test]
fn transient_steps_use_amg_above_the_threshold_and_agree_with_cholesky() {
    // The electronics warm-up (80 BDF2 steps, linear): every step system is symmetric
    // positive definite, so above the threshold each step is one AMG-CG solve, never a
    // factorisation; the hierarchy is kept while the matrix is unchanged.
    let file = "transient.toml";
    let (_direct_scene, problem) = scene_file_with(
        "electronics",
        file,
        "transient-direct",
        "linear_solver = \"direct\"\nauto_threshold = 1",
    );
    let direct = run(&problem);
    assert_eq!(direct.summary.linear_solver.name, "direct");
    let (_amg_scene, problem) =
        scene_file_with("electronics", file, "transient-amg", "auto_threshold = 1");
    let amg = run(&problem);
    let a = &amg.summary.linear_solver;
    assert_eq!(a.name, "AMG-CG");
    assert!(a.reason.starts_with("auto: "), "{}", a.reason);
    let steps = amg.summary.transient.as_ref().unwrap().steps;
    assert_eq!(a.iterations_per_solve.len(), steps);
    // A step may take no iteration at all: its start, the predictor moved within the
    // span of the earlier steps' solutions, can meet the stopping test already.
    assert!(a.iterations_per_solve.iter().sum::<usize>() > 0, "{a:?}");
    // `steps.csv` carries each step's Krylov iterations (one Newton iteration a step).
    let csv = std::fs::read_to_string(_amg_scene.path().join("out/steps.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let column = header
        .iter()
        .position(|h| *h == "krylov_iterations")
        .unwrap();
    let per_step: Vec<usize> = lines
        .map(|l| l.split(',').nth(column).unwrap().parse().unwrap())
        .collect();
    assert_eq!(per_step, a.iterations_per_solve);
    // Two matrices in the run (BDF1's, then BDF2's): each served once (a set-up, or a
    // refresh when the diagonal moved little), every other step finds its matrix.
    let served = a.hierarchy_setups.unwrap() + a.hierarchy_refreshes.unwrap();
    assert_eq!(served, 2, "{a:?}");
    agree_with_cholesky(&amg, &direct);
}

/// Temperatures and interface heat of an AMG-CG run within [`AGREE`] of a Cholesky run's.
fn agree_with_cholesky(amg: &RunResult, direct: &RunResult) {
    let (ta, td) = (&amg.solution.temperature, &direct.solution.temperature);
    let scale = max_abs(td);
    for (k, (x, y)) in ta.iter().zip(td).enumerate() {
        if y.is_finite() {
            assert!(
                (x - y).abs() <= AGREE * scale,
                "node {k}: AMG {x} vs Cholesky {y}"
            );
        }
    }
    for (x, y) in amg
        .summary
        .interactions
        .iter()
        .zip(&direct.summary.interactions)
    {
        let q = y.heat_side_a.abs().max(y.heat_side_b.abs());
        assert!((x.heat_side_a - y.heat_side_a).abs() <= AGREE * q);
        assert!((x.heat_side_b - y.heat_side_b).abs() <= AGREE * q);
    }
}

/// A linear step by AMG-CG takes its right-hand side from an assembly at the held
/// values with every other temperature zero. With held temperatures (the sink's
/// cooled faces at 303.15 K, 10 K above the start) the elements at the held nodes
/// carry them into that right-hand side: the run agrees with Cholesky's as the
/// electronics warm-up without held temperatures does, and the held nodes keep their
/// value.
#[test]
fn transient_steps_by_amg_with_held_temperatures_agree_with_cholesky() {
    let file = "transient.toml";
    let held = |dir: &TempDir| {
        let path = dir.path().join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let convection =
            "kind = \"convection\"\nsurfaces = [\"sink_cooled\"]\nvalue = 40.0\nambient = 293.15\n";
        assert!(text.contains(convection), "the scene's cooled faces");
        let text = text.replace(
            convection,
            "kind = \"temperature\"\nsurfaces = [\"sink_cooled\"]\nvalue = 303.15\n",
        );
        std::fs::write(&path, text).unwrap();
    };
    let (direct_scene, problem) = scene_file_with(
        "electronics",
        file,
        "held-direct",
        "linear_solver = \"direct\"\nauto_threshold = 1",
    );
    held(&direct_scene);
    let direct = run(&problem);
    let (amg_scene, problem) =
        scene_file_with("electronics", file, "held-amg", "auto_threshold = 1");
    held(&amg_scene);
    let amg = run(&problem);
    assert_eq!(amg.summary.linear_solver.name, "AMG-CG");
    agree_with_cholesky(&amg, &direct);
    // The held value is kept, and the field moved away from the start.
    let t = &amg.solution.temperature;
    let at_held = t.iter().filter(|&&v| (v - 303.15).abs() < 1e-9).count();
    assert!(at_held > 0, "no node at the held 303.15 K");
    let max = t
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(f64::MIN, f64::max);
    assert!(
        max > 303.15 + 1.0,
        "the die heats above the held sink: max {max}"
    );
}

/// A face condition that changes in time reaches every AMG step: the die's flux as a
/// table in time (on, then off from t = 100 s) gives the Cholesky run's temperatures
/// and heat. (A linear step assembles its right-hand side at the same
/// field each step, and an unchanged condition lets it keep the element loop's part.)
#[test]
fn transient_amg_steps_follow_a_flux_that_changes_in_time() {
    let file = "transient.toml";
    let switched = |dir: &TempDir| {
        let path = dir.path().join(file);
        let text = std::fs::read_to_string(&path).unwrap();
        let flux = "kind = \"flux\"\nsurfaces = [\"chip_bottom\"]\nvalue = 1e5\n";
        assert!(text.contains(flux), "the die's flux");
        let table = "{ table = [[0.0, 1e5], [99.0, 1e5], [100.0, 0.0]] }";
        let text = text.replace(
            flux,
            &format!("kind = \"flux\"\nsurfaces = [\"chip_bottom\"]\nvalue = {table}\n"),
        );
        std::fs::write(&path, text.replace("end_time = 400.0", "end_time = 150.0")).unwrap();
    };
    let (direct_scene, problem) = scene_file_with(
        "electronics",
        file,
        "switched-direct",
        "linear_solver = \"direct\"\nauto_threshold = 1",
    );
    switched(&direct_scene);
    let direct = run(&problem);
    let (amg_scene, problem) =
        scene_file_with("electronics", file, "switched-amg", "auto_threshold = 1");
    switched(&amg_scene);
    let amg = run(&problem);
    assert_eq!(amg.summary.linear_solver.name, "AMG-CG");
    agree_with_cholesky(&amg, &direct);
    // With its flux off the die has cooled to the sink within milliseconds: nearly no
    // heat crosses the interface at the end (10 W while it was on).
    let heat = amg.summary.interactions[0].heat_side_a;
    assert!(heat.abs() < 0.1, "{heat}");
}

#[test]
fn nonlinear_steps_use_gmres_with_a_kept_hierarchy_and_agree_with_lu() {
    // The two blocks with a conductivity k(T) in the base: the Newton Jacobian is
    // unsymmetric (dk/dT ∇T). Above the threshold it is solved by GMRES preconditioned by
    // AMG, the hierarchy kept across Newton iterations (refreshed with each Jacobian's
    // values), never by LU; the answer is LU's.
    let k_of_t = |text: String| {
        text.replace(
            "conductivity = 16.0",
            "conductivity = \"16*(1 + 0.004*(T - 300))\"",
        )
    };
    let scene = |tag: &str, extra: &str| {
        let (dir, path) = two_blocks_with(tag, extra);
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.contains("conductivity = 16.0"),
            "the base's conductivity"
        );
        std::fs::write(&path, k_of_t(text)).unwrap();
        (dir, path)
    };
    let (_d, problem) = scene("kT-direct", "linear_solver = \"direct\"");
    let direct = run(&problem);
    assert_eq!(direct.summary.linear_solver.name, "direct");
    assert!(direct.summary.newton_iterations >= 3, "a nonlinear problem");
    let (_g, problem) = scene("kT-gmres", "auto_threshold = 1");
    let gmres = run(&problem);
    let g = &gmres.summary.linear_solver;
    assert_eq!(g.name, "GMRES", "{g:?}");
    assert!(g.reason.starts_with("auto: "), "{}", g.reason);
    assert!(g.reason.contains("unsymmetric"), "{}", g.reason);
    assert!(g.iterations_per_solve.iter().all(|&k| k > 0), "{g:?}");
    let (setups, refreshes) = (g.hierarchy_setups.unwrap(), g.hierarchy_refreshes.unwrap());
    // Every Jacobian but the first few served by the kept hierarchy.
    let solves = gmres.summary.newton_iterations;
    assert_eq!(setups + refreshes, solves, "{g:?}");
    assert!(refreshes >= 1 && setups < solves, "{g:?}");
    let (tg, td) = (&gmres.solution.temperature, &direct.solution.temperature);
    let scale = max_abs(td);
    for (k, (x, y)) in tg.iter().zip(td).enumerate() {
        if y.is_finite() {
            assert!(
                (x - y).abs() <= AGREE * scale,
                "node {k}: GMRES {x} vs LU {y}"
            );
        }
    }
    let (x, y) = (
        &gmres.summary.interactions[0],
        &direct.summary.interactions[0],
    );
    let q = y.heat_side_a.abs();
    assert!(
        (x.heat_side_a - y.heat_side_a).abs() <= AGREE * q,
        "{x:?} vs {y:?}"
    );
}
