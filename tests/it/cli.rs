//! The `seam` command line on the bundled example and on fixtures: output formats,
//! exit codes, the TOML twin, element death.

use std::path::PathBuf;
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn seam(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_seam"))
        .env_remove("CLICOLOR_FORCE")
        .args(args)
        .current_dir(root())
        .output()
        .expect("seam runs")
}

fn json(out: &Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "exit {:?}: {}",
        out.status.code(),
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("stdout is one JSON object")
}

const EXAMPLE_MESH: &str = "examples/two_blocks/two_blocks.exo";

fn surface<'a>(report: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    report["surfaces"]
        .as_array()
        .expect("surfaces is an array")
        .iter()
        .find(|s| s["name"] == name)
        .unwrap_or_else(|| panic!("no surface {name} in {report}"))
}

/// The example's mesh: base is 6×6×6 hexes on the unit cube, lid 4×4×3 on
/// [0,1]²×[1,1.5] (see examples/two_blocks/make_mesh.py), so every count below follows
/// from the grid sizes.
#[test]
fn example_surfaces_as_json() {
    let r = json(&seam(&[
        "surfaces",
        "examples/two_blocks/contact.i",
        "--mesh",
        EXAMPLE_MESH,
        "--json",
    ]));
    let expect = [
        ("interface_base", 36, 1.0),
        ("interface_lid", 16, 1.0),
        ("lid_outside", 4 * 4 * 3, 2.0),
        ("lid_outside_top", 16, 1.0),
        ("base", 6 * 36 - 36, 5.0),
    ];
    assert_eq!(r["surfaces"].as_array().unwrap().len(), expect.len());
    for (name, faces, area) in expect {
        let s = surface(&r, name);
        assert_eq!(s["kind"], "faces");
        assert_eq!(s["faces"], faces, "{name}");
        let a = s["area"].as_f64().unwrap();
        assert!((a - area).abs() < 1e-12, "{name}: area {a}");
    }
    // Nodes: 7×7 on the base's top; the lid's top 5×5 less its rim, owned by lid_outside.
    assert_eq!(surface(&r, "interface_base")["nodes"], 49);
    assert_eq!(surface(&r, "lid_outside_top")["nodes"], 9);
    let codes: Vec<&str> = r["warnings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|w| w["code"].as_str().unwrap())
        .collect();
    assert_eq!(codes, ["W0301"]);
}

#[test]
fn toml_twin_gives_the_same_surfaces() {
    let a = json(&seam(&[
        "surfaces",
        "examples/two_blocks/contact.i",
        "--mesh",
        EXAMPLE_MESH,
        "--json",
    ]));
    let b = json(&seam(&[
        "surfaces",
        "examples/two_blocks/contact.toml",
        "--mesh",
        EXAMPLE_MESH,
        "--json",
    ]));
    assert_eq!(a, b);
}

#[test]
fn table_lists_every_surface() {
    let out = seam(&[
        "surfaces",
        "examples/two_blocks/contact.i",
        "--mesh",
        EXAMPLE_MESH,
    ]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert!(lines[0].starts_with("surface"), "{text}");
    assert_eq!(lines.len(), 6, "{text}");
    assert!(
        lines[5].starts_with("base ") && lines[5].contains("180"),
        "{text}"
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("warning[W0301]"));
}

/// Element 8 is the base's cell (i, j, k) = (1, 1, 0): on the bottom plane, not on an
/// edge. Dead, it takes its one bottom face away and exposes five neighbours' sides.
#[test]
fn dead_elements_expose_faces() {
    let run = |extra: &[&str]| {
        let mut args = vec![
            "surfaces",
            "examples/two_blocks/contact.i",
            "--mesh",
            EXAMPLE_MESH,
            "--json",
        ];
        args.extend_from_slice(extra);
        json(&seam(&args))
    };
    let (alive, dead) = (run(&[]), run(&["--dead", "8"]));
    assert_eq!(surface(&alive, "base")["faces"], 180);
    assert_eq!(surface(&dead, "base")["faces"], 180 - 1 + 5);
    let area = surface(&dead, "base")["area"].as_f64().unwrap();
    assert!((area - (5.0 + 4.0 / 36.0)).abs() < 1e-12, "{area}");
}

#[test]
fn bad_dead_list_is_a_usage_error() {
    let out = seam(&[
        "surfaces",
        "examples/two_blocks/contact.i",
        "--mesh",
        EXAMPLE_MESH,
        "--dead",
        "5-x",
    ]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`5-x`"));
}

#[test]
fn check_passes_the_example_and_a_deck_with_a_toggle() {
    let out = seam(&[
        "check",
        "examples/two_blocks/contact.i",
        "--mesh",
        EXAMPLE_MESH,
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("5 contact surface(s)"));

    let dir = crate::scratch("cli-toggle");
    let deck = dir.path().join("deck.i");
    std::fs::write(
        &deck,
        "begin contact definition\n  skin all blocks = on\n  begin enforcement\n    enforcement for energy = tied_temperature\n    use toggle block = warm_up\n  end\nend\n",
    )
    .unwrap();
    // A toggle is resolved by `seam run` against the problem file's [[toggle]]s: the
    // deck alone is fine.
    let out = seam(&["check", deck.to_str().unwrap()]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let out = seam(&["surfaces", deck.to_str().unwrap(), "--mesh", EXAMPLE_MESH]);
    assert_eq!(out.status.code(), Some(0));
    assert!(!String::from_utf8_lossy(&out.stderr).contains("W0900"));
}

/// The Gmsh fixture is two unit cubes stacked and meshed conformingly (blocks `lower`
/// and `upper`, side set `interface` at z = 1): with both skinned, the shared square is
/// interior, so each skin has area 5, and the side set still gives the interface.
#[test]
fn gmsh_meshes_work_end_to_end() {
    let dir = crate::scratch("cli-gmsh");
    let deck = dir.path().join("deck.i");
    std::fs::write(
        &deck,
        "begin contact definition\n  contact surface iface contains interface\n  skin all blocks = on\nend\n",
    )
    .unwrap();
    let mut reports = Vec::new();
    for mesh in ["box_hex_ascii.msh", "box_hex_binary.msh"] {
        let mesh = root().join("tests/fixtures").join(mesh);
        let r = json(&seam(&[
            "surfaces",
            deck.to_str().unwrap(),
            "--mesh",
            mesh.to_str().unwrap(),
            "--json",
        ]));
        for (name, area) in [("iface", 1.0), ("lower", 5.0), ("upper", 5.0)] {
            let a = surface(&r, name)["area"].as_f64().unwrap();
            assert!((a - area).abs() < 1e-12, "{name}: {a}");
        }
        reports.push(r);
    }
    assert_eq!(
        reports[0], reports[1],
        "ASCII and binary give the same surfaces"
    );
}

/// The bundled run: 1-D through the two blocks (insulated sides), so the heat through the
/// interface is q = 100 / (1/16 + 1/500 + 0.5/200) per unit area, and JSON keys are there.
#[test]
fn example_run_gives_the_series_resistance_heat() {
    let out = seam(&["run", "examples/two_blocks/problem.toml", "--json"]);
    let r = json(&out);
    for key in ["dofs", "newton_iterations", "interactions", "timing"] {
        assert!(r.get(key).is_some(), "missing {key}: {r}");
    }
    for key in [
        "surfaces_s",
        "search_s",
        "assembly_s",
        "factor_s",
        "solve_s",
        "total_s",
    ] {
        assert!(r["timing"].get(key).is_some(), "missing timing.{key}");
    }
    let i = &r["interactions"][0];
    let q = 100.0 / (1.0 / 16.0 + 1.0 / 500.0 + 0.5 / 200.0);
    let a = i["heat_side_a"].as_f64().unwrap();
    assert!(
        (a + q).abs() < 1e-9 * q,
        "heat out of the base {a}, expected {}",
        -q
    );
    assert!(i["imbalance"].as_f64().unwrap().abs() < 1e-12 * q);
    assert!(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("examples/two_blocks/out/temperature.vtu")
            .is_file()
    );
}

/// `seam example` lists the bundled scenes and writes one out of the binary into a
/// folder, which then runs as the source tree's scene does (the same heat, to the bit),
/// and refuses to overwrite it a second time; an unknown name is a usage error.
#[test]
fn example_writes_a_bundled_scene_that_runs() {
    let list = seam(&["example"]);
    assert!(list.status.success());
    let text = String::from_utf8_lossy(&list.stdout);
    assert!(
        text.contains("two_blocks") && text.contains("busbar_joint"),
        "{text}"
    );
    // A folder that does not exist yet, inside a scratch folder: `seam example` makes it.
    let tmp = crate::scratch("cli-example");
    let dir = tmp.path().join("two_blocks");
    let d = dir.to_str().unwrap();
    let wrote = seam(&["example", "two_blocks", "--dir", d]);
    assert!(
        wrote.status.success(),
        "{}",
        String::from_utf8_lossy(&wrote.stderr)
    );
    let problem = dir.join("problem.toml");
    let copied = json(&seam(&["run", problem.to_str().unwrap(), "--json"]));
    let tree = json(&seam(&[
        "run",
        "examples/two_blocks/problem.toml",
        "--json",
    ]));
    assert_eq!(copied["interactions"], tree["interactions"]);
    let again = seam(&["example", "two_blocks", "--dir", d]);
    assert_eq!(again.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&again.stderr).contains("exists already"));
    // Every bundled scene carries the files its problem file names.
    let busbar = dir.join("busbar");
    let b = busbar.to_str().unwrap();
    assert!(
        seam(&["example", "busbar_joint", "--dir", b])
            .status
            .success()
    );
    let run = json(&seam(&[
        "run",
        busbar.join("problem.toml").to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(run["electrical_contacts"][0]["side_a"], "a_joint");
    let unknown = seam(&["example", "three_blocks", "--dir", d]);
    assert_eq!(unknown.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&unknown.stderr).contains("busbar_joint"));
}

/// `--threads N` before or after the subcommand: the same answer on one thread and on
/// two; zero threads is a usage error.
#[test]
fn threads_option_sets_the_pool_and_not_the_answer() {
    let scene = "examples/two_blocks/problem.toml";
    let one = json(&seam(&["--threads", "1", "run", scene, "--json"]));
    let two = json(&seam(&["run", scene, "--json", "--threads", "2"]));
    assert_eq!(one["interactions"], two["interactions"]);
    let zero = seam(&["--threads", "0", "run", scene]);
    assert_eq!(zero.status.code(), Some(2));
}

/// `--json` on every subcommand that takes it: a failure is one JSON object on stdout,
/// `{"ok": false, "diagnostics": [{severity, code, message, loc, help}]}`, with the exit
/// code of the text mode; `seam check --json` reports counts and diagnostics when it
/// passes too.
#[test]
fn json_mode_reports_diagnostics_as_json() {
    let parse = |out: &Output| -> serde_json::Value {
        serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stdout)))
    };
    let ok = seam(&["check", "examples/two_blocks/contact.i", "--json"]);
    assert_eq!(ok.status.code(), Some(0));
    let report = parse(&ok);
    assert_eq!(report["ok"], true);
    assert_eq!(report["errors"], 0);
    let bad = seam(&["check", "tests/bad/refused_equation/deck.i", "--json"]);
    assert_eq!(bad.status.code(), Some(2));
    let report = parse(&bad);
    assert_eq!(report["ok"], false);
    let d = &report["diagnostics"][0];
    assert_eq!(d["code"], "E0219", "{report}");
    assert_eq!(d["severity"], "error");
    assert_eq!(d["loc"]["line"], 4, "{report}");
    let missing = seam(&[
        "search",
        "examples/two_blocks/contact.i",
        "--mesh",
        "no/such/mesh.exo",
        "--json",
    ]);
    assert_eq!(missing.status.code(), Some(2));
    assert_eq!(parse(&missing)["diagnostics"][0]["code"], "E0400");
    let run = seam(&["run", "no/such/problem.toml", "--json"]);
    assert_eq!(run.status.code(), Some(2));
    assert_eq!(parse(&run)["ok"], false);
    assert!(
        run.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

/// `-v` shows the library's log records (its phases; `-vv` each solve),
/// `-q` leaves standard error empty on a clean run, and the default shows no records;
/// `-v` with `-q` is a usage error.
#[test]
fn verbose_and_quiet_choose_what_reaches_stderr() {
    let scene = "examples/two_blocks/problem.toml";
    let stderr = |args: &[&str]| {
        let out = seam(args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stderr).to_string()
    };
    let verbose = stderr(&["-v", "run", scene]);
    assert!(
        verbose.contains("seam[INFO] seam::run: mesh read: 443 nodes"),
        "{verbose}"
    );
    assert!(!verbose.contains("DEBUG"), "{verbose}");
    let debug = stderr(&["run", scene, "-vv"]);
    assert!(
        debug.contains("seam[DEBUG]") && debug.contains("linear steady solve of 443 unknowns"),
        "{debug}"
    );
    assert!(!stderr(&["run", scene]).contains("seam[INFO]"));
    assert_eq!(stderr(&["-q", "run", scene]), "");
    assert_eq!(seam(&["-v", "-q", "run", scene]).status.code(), Some(2));
}
