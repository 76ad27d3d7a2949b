//! `seam check` as a pre-flight: a deck it passes does not fail when `seam run` starts,
//! and what `seam run` refuses, `seam check` refuses with the same code. Also which
//! enforcement block applies when a definition has several.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use seam::run::RunError;
use tempfile::TempDir;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scratch folder with the bundled two-block mesh in it.
fn scratch(name: &str) -> TempDir {
    let d = crate::scratch(&format!("preflight-{name}"));
    std::fs::copy(
        root().join("examples/two_blocks/two_blocks.exo"),
        d.path().join("two_blocks.exo"),
    )
    .unwrap();
    d
}

fn seam(dir: &Path, args: &[&str]) -> (Option<i32>, String) {
    let out: Output = Command::new(env!("CARGO_BIN_EXE_seam"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("seam runs");
    let text =
        String::from_utf8_lossy(&out.stderr).into_owned() + &String::from_utf8_lossy(&out.stdout);
    (out.status.code(), text)
}

/// The base (k = 16, z ∈ [0, 1]) at 300 K below, the lid (k = 200, z ∈ [1, 1.5]) at
/// 400 K on top, insulated sides, the interface as the deck says.
fn problem(dir: &Path, deck: &str, lid_value: &str) -> PathBuf {
    std::fs::write(dir.join("deck.i"), deck).unwrap();
    let text = format!(
        r#"[mesh]
file = "two_blocks.exo"
[[material]]
blocks = ["base"]
conductivity = 16.0
[[material]]
blocks = ["lid"]
conductivity = 200.0
[[bc]]
kind = "temperature"
surfaces = ["base_bottom"]
value = 300.0
[[bc]]
kind = "temperature"
surfaces = ["lid_top"]
value = {lid_value}
[contact]
file = "deck.i"
"#
    );
    let p = dir.join("problem.toml");
    std::fs::write(&p, text).unwrap();
    p
}

fn deck(enforcements: &str, interaction_extra: &str) -> String {
    format!(
        "begin contact definition\n  contact surface a contains base_top\n  contact surface b contains lid_bottom\n  begin interaction\n    side a a\n    side b b\n{interaction_extra}  end\n{enforcements}end\n"
    )
}

/// The heat through the series base – resistance h – lid: ΔT over the three resistances.
fn series_heat(h: f64) -> f64 {
    100.0 / (1.0 / 16.0 + 1.0 / h + 0.5 / 200.0)
}

#[test]
fn check_refuses_what_run_refuses_with_the_same_code() {
    let cases = [
        (
            "negative_coefficient",
            "  begin enforcement gap\n    enforcement for energy = gap_conductance\n    gap conductance coefficient = constant h = -5\n  end\n",
            "E0605",
        ),
        (
            "lua_syntax",
            "  begin enforcement gap\n    enforcement for energy = gap_conductance\n    gap conductance coefficient = lua \"100 + * temp_a\"\n  end\n",
            "E0607",
        ),
        (
            "plugin_without_library",
            "  begin enforcement gap\n    enforcement for energy = plugin\n  end\n",
            "E0500",
        ),
        (
            "plugin_missing_file",
            "  begin enforcement gap\n    enforcement for energy = plugin library = \"no_such_plugin.so\"\n  end\n",
            "E0500",
        ),
    ];
    for (name, enforcement, code) in cases {
        let tmp = scratch(name);
        let dir = tmp.path();
        problem(dir, &deck(enforcement, ""), "400.0");
        let (exit, text) = seam(dir, &["check", "deck.i"]);
        assert_eq!(exit, Some(2), "{name}: seam check passed:\n{text}");
        assert!(text.contains(code), "{name}: check lacks {code}:\n{text}");
        let (exit, text) = seam(dir, &["check", "deck.i", "--mesh", "two_blocks.exo"]);
        assert_eq!(exit, Some(2), "{name}: seam check --mesh passed:\n{text}");
        assert!(text.contains(code), "{name}: check --mesh lacks {code}");
        let (exit, text) = seam(dir, &["run", "problem.toml"]);
        assert_eq!(exit, Some(2), "{name}: seam run did not refuse:\n{text}");
        assert!(text.contains(code), "{name}: run lacks {code}:\n{text}");
    }
}

#[test]
fn check_with_a_problem_runs_the_problem_file_checks() {
    let tmp = scratch("problem");
    let dir = tmp.path();
    let good =
        "  begin enforcement\n    enforcement for energy = contact_resistance h = 5\n  end\n";
    problem(dir, &deck(good, ""), "\"400 + nonsense(\"");
    // The deck alone is fine; the problem file's Lua boundary value is not.
    let (exit, text) = seam(dir, &["check", "deck.i"]);
    assert_eq!(exit, Some(0), "{text}");
    let (exit, text) = seam(dir, &["check", "deck.i", "--problem", "problem.toml"]);
    assert_eq!(exit, Some(2), "{text}");
    assert!(text.contains("E0707"), "{text}");
    let (exit, _) = seam(dir, &["run", "problem.toml"]);
    assert_eq!(exit, Some(2));

    let p = problem(dir, &deck(good, ""), "400.0");
    let (exit, text) = seam(dir, &["check", "deck.i", "--problem", "problem.toml"]);
    assert_eq!(exit, Some(0), "{text}");
    assert!(text.contains("problem ready to run"), "{text}");
    // The pre-flight writes nothing.
    assert!(!dir.join("out").exists());
    assert!(seam::run::check(&p).is_ok());
    let r = seam::run::run(&p).unwrap_or_else(|e| panic!("{e:?}"));
    // Heat flows from the hot lid (side B) into the base (side A).
    let heat = -r.summary.interactions[0].heat_side_a;
    assert!(
        (heat - series_heat(5.0)).abs() <= 1e-9 * series_heat(5.0),
        "heat {heat}, exact {}",
        series_heat(5.0)
    );
}

const TWO_BLOCKS: &str = "  begin enforcement low\n    enforcement for energy = contact_resistance h = 5\n  end\n  begin enforcement high\n    enforcement for energy = contact_resistance h = 500\n  end\n";

#[test]
fn two_energy_blocks_need_an_interaction_to_name_one() {
    let tmp = scratch("two_blocks");
    let dir = tmp.path();
    let p = problem(dir, &deck(TWO_BLOCKS, ""), "400.0");
    let (exit, text) = seam(dir, &["check", "deck.i"]);
    assert_eq!(exit, Some(2), "{text}");
    assert!(text.contains("E0429"), "{text}");
    match seam::run::run(&p) {
        Err(RunError::Input(d, _)) => assert!(d.errors().any(|d| d.code == "E0429"), "{d:?}"),
        Err(e) => panic!("{e:?}"),
        Ok(_) => panic!("two Energy blocks, none named, ran"),
    }
    // Named, each block applies with its own conductance.
    for (name, h) in [("low", 5.0), ("high", 500.0)] {
        let p = problem(
            dir,
            &deck(TWO_BLOCKS, &format!("    enforcement = {name}\n")),
            "400.0",
        );
        let (exit, text) = seam(dir, &["check", "deck.i"]);
        assert_eq!(exit, Some(0), "{text}");
        let r = seam::run::run(&p).unwrap_or_else(|e| panic!("{e:?}"));
        // Heat flows from the hot lid (side B) into the base (side A).
        let heat = -r.summary.interactions[0].heat_side_a;
        let exact = series_heat(h);
        assert!(
            (heat - exact).abs() <= 1e-9 * exact,
            "{name}: heat {heat}, exact {exact}"
        );
    }
}

#[test]
fn update_search_on_a_fixed_mesh_warns_that_it_does_nothing() {
    let tmp = scratch("update_search");
    let dir = tmp.path();
    let d = deck(
        "  begin enforcement\n    enforcement for energy = contact_resistance h = 5\n  end\n",
        "",
    )
    .replace(
        "begin contact definition\n",
        "begin contact definition\n  update search every 3 steps\n",
    );
    let elfen = d.replace(
        "  update search every 3 steps\n",
        "  begin search options\n    Global_update_frequency = 3\n  end\n",
    );
    for text in [d, elfen] {
        let p = problem(dir, &text, "400.0");
        let r = seam::run::run(&p).unwrap_or_else(|e| panic!("{e:?}"));
        let w: Vec<_> = r
            .warnings
            .warnings()
            .filter(|w| w.code == "W0703")
            .collect();
        assert_eq!(w.len(), 1, "{text}\n{:?}", r.warnings);
        assert!(w[0].message.contains("no effect"), "{}", w[0].message);
    }
}

#[test]
fn an_interaction_that_pairs_nothing_says_why() {
    let enforcement =
        "  begin enforcement\n    enforcement for energy = contact_resistance h = 5\n  end\n";
    let cases = [
        // The base's bottom and the lid's top are 1.5 apart.
        ("apart", "base_bottom", "lid_top", "the surfaces are apart"),
        ("same", "base_top", "base_top", "the same surface"),
    ];
    for (name, a, b, why) in cases {
        let tmp = scratch(name);
        let dir = tmp.path();
        let d = deck(enforcement, "")
            .replace("contains base_top", &format!("contains {a}"))
            .replace("contains lid_bottom", &format!("contains {b}"));
        let d = if a == b {
            d.replace("side b b", "side b a")
        } else {
            d
        };
        let p = problem(dir, &d, "400.0");
        let r = seam::run::run(&p).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        let w: Vec<_> = r
            .warnings
            .warnings()
            .filter(|w| w.code == "W0428")
            .collect();
        assert_eq!(w.len(), 1, "{name}: {:?}", r.warnings);
        assert!(w[0].message.contains(why), "{name}: {}", w[0].message);
        assert_eq!(r.summary.interactions[0].heat_side_a, 0.0);
        let (exit, text) = seam(dir, &["check", "deck.i", "--mesh", "two_blocks.exo"]);
        assert_eq!(exit, Some(0), "{text}");
        assert!(text.contains("W0428"), "{name}: {text}");
    }
}

/// Runs the two-block problem with `[[bc]]`, `[[material]]` and `[initial]` text of its
/// own (and the h = 5 resistance), returning the exit code and what seam printed.
fn run_problem(name: &str, body: &str) -> (Option<i32>, String) {
    let tmp = scratch(name);
    let dir = tmp.path();
    std::fs::write(
        dir.join("deck.i"),
        deck(
            "  begin enforcement\n    enforcement for energy = contact_resistance h = 5\n  end\n",
            "",
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("problem.toml"),
        format!("[mesh]\nfile = \"two_blocks.exo\"\n{body}[contact]\nfile = \"deck.i\"\n"),
    )
    .unwrap();
    let (check, text) = seam(dir, &["check", "deck.i", "--problem", "problem.toml"]);
    let (run, run_text) = seam(dir, &["run", "problem.toml"]);
    assert_eq!(
        check, run,
        "{name}: check and run disagree:\n{text}\n---\n{run_text}"
    );
    (run, run_text)
}

const MATERIALS: &str = "[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 16.0\n";

fn bc(kind: &str, surface: &str, value: &str, extra: &str) -> String {
    format!("[[bc]]\nkind = \"{kind}\"\nsurfaces = [\"{surface}\"]\nvalue = {value}\n{extra}")
}

#[test]
fn numbers_out_of_range_are_refused_with_the_range() {
    let cold = bc("temperature", "base_bottom", "300.0", "");
    let cases = [
        (
            "dirichlet_huge",
            format!(
                "{MATERIALS}{cold}{}",
                bc("temperature", "lid_top", "1e308", "")
            ),
            "within ±1e12 K",
        ),
        (
            "dirichlet_inf",
            format!(
                "{MATERIALS}{cold}{}",
                bc("temperature", "lid_top", "inf", "")
            ),
            "within ±1e12 K",
        ),
        (
            "dirichlet_nan",
            format!(
                "{MATERIALS}{cold}{}",
                bc("temperature", "lid_top", "nan", "")
            ),
            "within ±1e12 K",
        ),
        (
            "dirichlet_lua",
            format!(
                "{MATERIALS}{cold}{}",
                bc("temperature", "lid_top", "\"1e6 * 1e7\"", "")
            ),
            "within ±1e12 K",
        ),
        (
            "flux_huge",
            format!("{MATERIALS}{cold}{}", bc("flux", "lid_top", "1e200", "")),
            "within ±1e100 W/m²",
        ),
        (
            "convection_negative",
            format!(
                "{MATERIALS}{cold}{}",
                bc("convection", "lid_top", "-1.0", "ambient = 300.0\n")
            ),
            "[0, 1e100] W/m²K",
        ),
        (
            "ambient_inf",
            format!(
                "{MATERIALS}{cold}{}",
                bc("convection", "lid_top", "10.0", "ambient = inf\n")
            ),
            "within ±1e12 K",
        ),
        (
            "conductivity_huge",
            format!("[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 1e200\n{cold}"),
            "at most 1e100",
        ),
        (
            "initial_huge",
            format!("{MATERIALS}{cold}[initial]\ntemperature = 1e13\n"),
            "within ±1e12 K",
        ),
    ];
    for (name, body, range) in cases {
        let (code, text) = run_problem(name, &body);
        assert_eq!(code, Some(2), "{name}:\n{text}");
        assert!(text.contains(range), "{name}: no range in\n{text}");
    }
}

#[test]
fn a_steady_problem_with_a_floating_part_is_named_before_the_solve() {
    // No condition at all; only fluxes; the lid held but the base joined to nothing.
    let flux = |s: &str, q: &str| bc("flux", s, q, "");
    let cases = [
        ("no_condition", MATERIALS.to_string(), "blocks base, lid"),
        (
            "only_fluxes",
            format!(
                "{MATERIALS}{}{}",
                flux("base_bottom", "100.0"),
                flux("lid_top", "-100.0")
            ),
            "blocks base, lid",
        ),
    ];
    for (name, body, blocks) in cases {
        let (code, text) = run_problem(name, &body);
        assert_eq!(code, Some(2), "{name}:\n{text}");
        assert!(text.contains("E0715"), "{name}:\n{text}");
        assert!(
            text.contains(&format!("block(s) {}", &blocks[7..])),
            "{name}:\n{text}"
        );
    }
    // The same with the contact resistance but the interface apart: the base floats.
    let tmp = scratch("base_floats");
    let dir = tmp.path();
    std::fs::write(
        dir.join("deck.i"),
        deck(
            "  begin enforcement\n    enforcement for energy = contact_resistance h = 5\n  end\n",
            "",
        )
        .replace("contains base_top", "contains base_bottom"),
    )
    .unwrap();
    std::fs::write(
        dir.join("problem.toml"),
        format!(
            "[mesh]\nfile = \"two_blocks.exo\"\n{MATERIALS}{}{}[contact]\nfile = \"deck.i\"\n",
            bc("temperature", "lid_top", "400.0", ""),
            flux("base_bottom", "10.0")
        ),
    )
    .unwrap();
    let (code, text) = seam(dir, &["run", "problem.toml"]);
    assert_eq!(code, Some(2), "{text}");
    assert!(text.contains("block(s) base meet no"), "{text}");
    // A transient problem has its heat capacity: it runs.
    let (code, text) = run_problem(
        "transient_no_condition",
        "[[material]]\nblocks = [\"base\", \"lid\"]\nconductivity = 16.0\nrho_c = 1e6\n[initial]\ntemperature = 300.0\n[solve]\nkind = \"transient\"\ndt = 1.0\nend_time = 2.0\n",
    );
    assert_eq!(code, Some(0), "{text}");
}

/// The heat from the lid into the base with these enforcement lines.
fn heat_with(name: &str, enforcement: &str) -> f64 {
    let tmp = scratch(name);
    let dir = tmp.path();
    let p = problem(
        dir,
        &deck(&format!("  begin enforcement\n{enforcement}  end\n"), ""),
        "400.0",
    );
    let r = seam::run::run(&p).unwrap_or_else(|e| panic!("{name}: {e:?}"));
    assert!(r.summary.converged, "{name}");
    -r.summary.interactions[0].heat_side_a
}

const CMY: &str = "    enforcement for energy = gap_conductance\n    gap conductance coefficient = CMY K_A = 16 K_B = 200 Slope = 0.1 Roughness = 1e-6 Hardness = 3e9\n";

#[test]
fn contact_surface_pressure_reaches_a_pressure_dependent_conductance() {
    // CMY: h = 1.25 k_s (m/σ)(p/H)^0.95, k_s = 2·16·200/216; the field is linear, so the
    // Robin–Nitsche form gives the series heat exactly.
    let k_s = 2.0 * 16.0 * 200.0 / 216.0;
    let h = 1.25 * k_s * (0.1 / 1e-6) * (5e5f64 / 3e9).powf(0.95);
    let exact = series_heat(h);
    for (name, line) in [
        ("contact_pressure", "    contact pressure = 5e5\n"),
        (
            "surface_pressure_value",
            "    contact surface pressure = constant value = 5e5\n",
        ),
        (
            "surface_pressure_constant",
            "    Contact Surface Pressure = Constant 5e5\n",
        ),
    ] {
        let heat = heat_with(name, &format!("{CMY}{line}"));
        println!(
            "{name}: heat {heat}, exact {exact}, rel err {:.1e}",
            (heat - exact).abs() / exact
        );
        assert!(
            (heat - exact).abs() <= 1e-9 * exact,
            "{name}: heat {heat}, exact {exact}"
        );
    }
    // No pressure: CMY gives h = 0, and nothing crosses.
    let none = heat_with("no_pressure", CMY);
    assert!(none.abs() <= 1e-9 * exact, "{none}");
}

#[test]
fn offset_temperature_takes_effect_in_both_forms() {
    // T_A − T_B = ΔT + q/h at the interface: the heat from the lid is (100 + ΔT)/R.
    let r = 1.0 / 16.0 + 1.0 / 5.0 + 0.5 / 200.0;
    for (name, line) in [
        ("offset_number", "    offset temperature = 20\n"),
        (
            "offset_model",
            "    Offset Temperature = Constant Value = 20\n",
        ),
    ] {
        let heat = heat_with(
            name,
            &format!("    enforcement for energy = contact_resistance h = 5\n{line}"),
        );
        let exact = 120.0 / r;
        println!(
            "{name}: heat {heat}, exact {exact}, rel err {:.1e}",
            (heat - exact).abs() / exact
        );
        assert!(
            (heat - exact).abs() <= 1e-9 * exact,
            "{name}: heat {heat}, exact {exact}"
        );
    }
}

#[test]
fn contact_gap_temperature_decides_what_a_conductance_sees() {
    let gap = |expr: &str, seen: &str| {
        format!(
            "    enforcement for energy = gap_conductance\n    gap conductance coefficient = lua \"{expr}\"\n{seen}"
        )
    };
    let side_a = "    contact gap temperature = side_a\n";
    // h(T_B) seeing side A is h(T_A); seeing the mean, h(T_A) is h((T_A + T_B)/2).
    let pairs = [
        ("b_as_a", gap("0.05*temp_b", side_a), gap("0.05*temp_a", "")),
        (
            "a_as_b",
            gap("0.05*temp_a", "    Contact Gap Temperature = Side B\n"),
            gap("0.05*temp_b", ""),
        ),
        (
            "mean",
            gap("0.05*temp_a", "    contact gap temperature = mean\n"),
            gap("0.025*(temp_a + temp_b)", ""),
        ),
    ];
    for (name, seen, plain) in pairs {
        let a = heat_with(&format!("{name}_seen"), &seen);
        let b = heat_with(&format!("{name}_plain"), &plain);
        println!(
            "{name}: seen {a}, plain {b}, rel diff {:.1e}",
            (a - b).abs() / b
        );
        assert!((a - b).abs() <= 1e-9 * b, "{name}: {a} vs {b}");
    }
    // And it changes the answer: T_A and T_B differ by tens of kelvin at this h.
    let a = heat_with("differs_a", &gap("0.05*temp_a", ""));
    let b = heat_with("differs_b", &gap("0.05*temp_b", ""));
    println!("h(T_A) {a} against h(T_B) {b}");
    assert!((a - b).abs() > 1e-3 * a, "{a} vs {b}");
}
