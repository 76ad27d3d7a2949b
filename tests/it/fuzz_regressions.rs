//! Inputs that once crashed or hung a reader, replayed through the same entry points as
//! the fuzz targets in `fuzz/` (see docs/verification.md, "Fuzzing").
//!
//! `tests/fuzz_regressions/<target>/<name>` is one input for the target of that name;
//! `<name>.expect` beside it holds a piece of text the outcome must contain (a diagnostic
//! code, a phrase of the error, or `ok`). Each input runs on its own thread of the
//! default test stack size and must finish within [`LIMIT`] with that outcome: no panic,
//! no stack overflow, no hang.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use seam::periodic::{LuaMap, MapSource, PeriodicMap};
use seam::script::{Limits, Sandbox};
use tempfile::TempDir;

/// Every regression input runs in well under a second in a debug build; a hang is a
/// run of minutes, so a generous bound keeps a loaded CI machine from false alarms.
const LIMIT: Duration = Duration::from_secs(60);

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions")
}

/// A scratch folder for the inputs the readers take as files.
fn scratch(target: &str, name: &str) -> TempDir {
    crate::scratch(&format!("fuzz-{target}-{name}"))
}

fn deck_outcome(diags: &seam::diag::Diagnostics) -> String {
    let errors: Vec<String> = diags
        .0
        .iter()
        .filter(|d| d.is_error())
        .map(|d| format!("{} {}", d.code, d.message))
        .collect();
    if errors.is_empty() {
        "ok".into()
    } else {
        errors.join("\n")
    }
}

fn outcome<E: std::fmt::Display>(r: Result<(), E>) -> String {
    match r {
        Ok(()) => "ok".into(),
        Err(e) => {
            let text = e.to_string();
            assert!(!text.trim().is_empty(), "an error with an empty message");
            text
        }
    }
}

/// What the target of that name does with `data`, as text.
fn replay(target: &str, name: &str, data: &[u8]) -> String {
    let text = String::from_utf8_lossy(data);
    match target {
        "deck_sierra" => deck_outcome(&seam::deck::parse_sierra(&Arc::from("fuzz.i"), &text).1),
        "deck_toml" => deck_outcome(&seam::deck::parse_toml(&Arc::from("fuzz.toml"), &text).1),
        "problem" => {
            let tmp = scratch(target, name);
            let dir = tmp.path();
            let example = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks");
            for file in ["two_blocks.exo", "contact_run.i", "contact.i"] {
                std::fs::copy(example.join(file), dir.join(file)).expect("copy the example");
            }
            let path = dir.join("problem.toml");
            std::fs::write(&path, data).expect("write the problem");
            let r = seam::run::check(&path);
            match r {
                Ok(_) => "ok".into(),
                Err(seam::run::RunError::Input(diags, _)) => deck_outcome(&diags),
                Err(seam::run::RunError::Solve(message)) => message,
            }
        }
        "mesh_exodus" | "mesh_gmsh" => {
            let tmp = scratch(target, name);
            let dir = tmp.path();
            let ext = if target == "mesh_exodus" {
                "exo"
            } else {
                "msh"
            };
            let path = dir.join(format!("mesh.{ext}"));
            std::fs::write(&path, data).expect("write the mesh");
            let r = seam::mesh::read(&path).map(|_| ());
            outcome(r)
        }
        "lua_map" => {
            let sandbox = Sandbox::new(Limits::default()).expect("a sandbox");
            let mut out = vec![outcome(sandbox.run_source("fuzz.lua", &text))];
            if out[0] == "ok" {
                for f in ["fx", "fy", "fz"] {
                    if let Ok(f) = sandbox.function(f, "fuzz.lua") {
                        out.push(outcome(sandbox.call(&f, &[0.25, -1.5, 3.0]).map(|_| ())));
                    }
                }
            }
            let mut lines = text.lines().map(MapSource::parse);
            let maps: [Option<MapSource>; 3] = std::array::from_fn(|_| lines.next());
            let refs = [maps[0].as_ref(), maps[1].as_ref(), maps[2].as_ref()];
            let tmp = scratch(target, name);
            let dir = tmp.path();
            out.push(match LuaMap::new(refs, dir, "fuzz.i:1", 1.0) {
                Ok(mut map) => outcome(
                    map.map_point([0.25, -1.5, 3.0])
                        .and_then(|_| map.map_vector([0.25, -1.5, 3.0], [1.0, 0.0, 0.0]))
                        .map(|_| ()),
                ),
                Err(e) => outcome(Err::<(), _>(e)),
            });
            out.join("\n")
        }
        other => panic!("tests/fuzz_regressions/{other}: no fuzz target of that name"),
    }
}

#[test]
fn fuzz_regressions_end_in_a_clean_outcome() {
    let mut cases: Vec<(String, PathBuf)> = Vec::new();
    for dir in std::fs::read_dir(root()).expect("tests/fuzz_regressions exists") {
        let dir = dir.expect("readable entry").path();
        let target = dir
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("")
            .to_string();
        for file in std::fs::read_dir(&dir).expect("readable target folder") {
            let file = file.expect("readable entry").path();
            if file.extension().is_none_or(|e| e != "expect") {
                cases.push((target.clone(), file));
            }
        }
    }
    cases.sort();
    assert!(!cases.is_empty(), "no regression inputs found");
    for (target, file) in cases {
        let name = file
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("")
            .to_string();
        let expect_path = PathBuf::from(format!("{}.expect", file.display()));
        let expect = std::fs::read_to_string(&expect_path)
            .unwrap_or_else(|_| panic!("{} has no {}", file.display(), expect_path.display()));
        let data = std::fs::read(&file).expect("readable input");
        let (tx, rx) = mpsc::channel();
        let start = Instant::now();
        let (t, n) = (target.clone(), name.clone());
        std::thread::Builder::new()
            .name(format!("{target}/{name}"))
            .spawn(move || {
                let _ = tx.send(replay(&t, &n, &data));
            })
            .expect("spawn");
        let got = match rx.recv_timeout(LIMIT) {
            Ok(got) => got,
            Err(mpsc::RecvTimeoutError::Timeout) => {
                panic!("{target}/{name}: no outcome after {LIMIT:?} (a hang)")
            }
            Err(mpsc::RecvTimeoutError::Disconnected) => {
                panic!("{target}/{name}: the reader panicked (see above)")
            }
        };
        let want = expect.trim();
        assert!(
            got.contains(want),
            "{target}/{name} ({:.2?}): expected an outcome containing `{want}`, got:\n{got}",
            start.elapsed()
        );
    }
}
