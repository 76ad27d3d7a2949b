//! Verification cases kept as data: `tests/cases/<name>/` holds a problem file, its
//! contact deck and `case.toml` with the requirement it checks, the tolerance and the
//! reason for it. Each case is run through `seam::run::run` and checked against the
//! exact field (a Lua-free expression evaluated here) and for conservation.

use std::path::Path;

use serde::Deserialize;

#[derive(Deserialize)]
struct Case {
    requirement: String,
    reason: String,
    /// The exact nodal field, as an expression in x, y, z (evaluated here by a tiny
    /// evaluator for `a + b*x + c*y + d*z` forms).
    expect_field: Option<String>,
    tolerance: f64,
    conservation: Option<f64>,
    /// The heat leaving side A of the (single) interaction, checked to `tolerance`
    /// relative.
    expect_heat_side_a: Option<f64>,
}

/// Coefficients (c0, cx, cy, cz) of an affine expression like `1 + x + 2*y - 3*z`.
fn affine(expr: &str) -> [f64; 4] {
    let mut c = [0.0; 4];
    let cleaned = expr.replace(' ', "").replace('-', "+-");
    for term in cleaned.split('+').filter(|t| !t.is_empty()) {
        let (coef, var) = match term.split_once('*') {
            Some((a, v)) => (a.parse::<f64>().expect("coefficient"), v),
            None if term.ends_with(['x', 'y', 'z']) => {
                let (a, v) = term.split_at(term.len() - 1);
                let a = match a {
                    "" => 1.0,
                    "-" => -1.0,
                    a => a.parse().expect("coefficient"),
                };
                (a, v)
            }
            None => (term.parse::<f64>().expect("constant"), ""),
        };
        let k = match var {
            "" => 0,
            "x" => 1,
            "y" => 2,
            "z" => 3,
            other => panic!("unsupported variable {other}"),
        };
        c[k] += coef;
    }
    c
}

#[test]
fn affine_parser_reads_the_case_fields() {
    assert_eq!(affine("1 + x + 2*y - 3*z"), [1.0, 1.0, 2.0, -3.0]);
    assert_eq!(affine("-z"), [0.0, 0.0, 0.0, -1.0]);
}

#[test]
fn verification_cases_meet_their_requirements() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cases");
    let mut dirs: Vec<_> = std::fs::read_dir(&root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.sort();
    let mut ran = 0;
    for dir in dirs.iter().filter(|d| d.join("case.toml").is_file()) {
        let case: Case =
            toml::from_str(&std::fs::read_to_string(dir.join("case.toml")).unwrap()).unwrap();
        assert!(!case.requirement.is_empty() && !case.reason.is_empty());
        let r = match seam::run::run(&dir.join("problem.toml")) {
            Ok(r) => r,
            Err(seam::run::RunError::Input(d, s)) => panic!("{}: {}", dir.display(), d.render(&s)),
            Err(seam::run::RunError::Solve(e)) => panic!("{}: {e}", dir.display()),
        };
        assert!(r.summary.converged, "{}", dir.display());
        if let Some(f) = &case.expect_field {
            let c = affine(f);
            let mut worst: f64 = 0.0;
            let mut scale: f64 = 0.0;
            for (i, p) in r.mesh.coords.iter().enumerate() {
                let exact = c[0] + c[1] * p[0] + c[2] * p[1] + c[3] * p[2];
                worst = worst.max((r.solution.temperature[i] - exact).abs());
                scale = scale.max(exact.abs());
            }
            assert!(
                worst <= case.tolerance * scale,
                "{}: {}\n  worst nodal error {worst:e} > {} × {scale}",
                dir.display(),
                case.requirement,
                case.tolerance
            );
        }
        if let Some(q) = case.expect_heat_side_a {
            let got = r.summary.interactions[0].heat_side_a;
            assert!(
                (got - q).abs() <= case.tolerance * q.abs(),
                "{}: {}\n  heat {got} vs {q}",
                dir.display(),
                case.requirement
            );
        }
        if let Some(tol) = case.conservation {
            for i in &r.summary.interactions {
                let heat = i.heat_side_a.abs().max(i.heat_side_b.abs());
                assert!(
                    i.imbalance.abs() <= tol * heat,
                    "{}: imbalance {} of {heat}",
                    dir.display(),
                    i.imbalance
                );
            }
        }
        ran += 1;
    }
    assert!(ran >= 4, "only {ran} cases found");
}

/// Aria masks ordinary face conditions on faces in contact: a convection condition on
/// the base's top, which the lid covers, changes nothing — unless it opts out with
/// `no_coverage_flux = true`.
#[test]
fn face_conditions_on_faces_in_contact_are_masked_unless_asked() {
    let tmp = crate::scratch("cases-mask");
    let dir = tmp.path();
    let mesh = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks/two_blocks.exo");
    std::fs::write(
        dir.join("contact.i"),
        "begin contact definition\n contact surface lid_face contains lid_bottom\n contact surface base_face contains base_top\n\
         begin interaction\n side a base_face\n side b lid_face\n end\n begin enforcement\n  enforcement for energy = tied_temperature\n end\nend\n",
    )
    .unwrap();
    let run = |extra: &str| {
        std::fs::write(
            dir.join("problem.toml"),
            format!(
                "[mesh]\nfile = {:?}\n[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1.0\n\
                 [[bc]]\nkind = \"temperature\"\nsurfaces = [\"base_bottom\"]\nvalue = 0\n\
                 [[bc]]\nkind = \"temperature\"\nsurfaces = [\"lid_top\"]\nvalue = 1\n{extra}\
                 [contact]\nfile = \"contact.i\"\n",
                mesh.to_str().unwrap()
            ),
        )
        .unwrap();
        match seam::run::run(&dir.join("problem.toml")) {
            Ok(r) => (
                r.solution.temperature,
                r.warnings.0.iter().map(|d| d.code).collect::<Vec<_>>(),
            ),
            Err(seam::run::RunError::Input(d, s)) => panic!("{}", d.render(&s)),
            Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
        }
    };
    let convection =
        "[[bc]]\nkind = \"convection\"\nsurfaces = [\"base_top\"]\nvalue = 50.0\nambient = 5.0\n";
    let (plain, _) = run("");
    let (masked, codes) = run(convection);
    let (kept, _) = run(&format!("{convection}no_coverage_flux = true\n"));
    let diff = |a: &[f64], b: &[f64]| {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    };
    // Equal up to round-off: the factorisation runs in parallel and may sum in another
    // order from one run to the next (differences of a few 1e-15 are seen).
    assert!(
        diff(&plain, &masked) < 1e-12,
        "a masked condition changes nothing"
    );
    assert!(codes.contains(&"W0701"), "{codes:?}");
    assert!(
        diff(&plain, &kept) > 0.1,
        "an unmasked hot convection heats the interface"
    );
}
