//! Generated documentation stays in step with the code that generates it.

use std::path::Path;

/// `docs/deck.md` is the keyword registry's reference; `SEAM_BLESS=1` regenerates it.
#[test]
fn deck_reference_matches_the_registry() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/deck.md");
    let generated = seam::deck::reference_markdown();
    if std::env::var_os("SEAM_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write docs/deck.md");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "docs/deck.md is out of date with the keyword registry: run `SEAM_BLESS=1 cargo test --test it docs`"
    );
}

/// Every `.rs` file under `src/<dir>`, with its text.
fn sources(dir: &str) -> Vec<(std::path::PathBuf, String)> {
    fn walk(dir: &Path, out: &mut Vec<(std::path::PathBuf, String)>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                let text = std::fs::read_to_string(&path).unwrap();
                out.push((path, text));
            }
        }
    }
    let mut out = Vec::new();
    walk(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(dir),
        &mut out,
    );
    out
}

/// The layers of docs/architecture.md point only down: `search`, `enforce` and `plugin`
/// never read the deck; `enforce` never reaches the host (`heat`, `run`, `embed`) or the
/// scene above it; `fem` and `mesh` stand on nothing of the contact pipeline.
#[test]
fn layers_point_only_down() {
    let rules: [(&str, &[&str]); 6] = [
        (
            "search",
            &[
                "crate::deck",
                "crate::scene",
                "crate::embed",
                "crate::run",
                "crate::heat",
            ],
        ),
        (
            "enforce",
            &[
                "crate::deck",
                "crate::scene",
                "crate::embed",
                "crate::run",
                "crate::heat",
            ],
        ),
        (
            "plugin",
            &[
                "crate::deck",
                "crate::scene",
                "crate::embed",
                "crate::run",
                "crate::heat",
            ],
        ),
        (
            "fem",
            &[
                "crate::deck",
                "crate::search",
                "crate::enforce",
                "crate::heat",
                "crate::scene",
            ],
        ),
        (
            "surface",
            &[
                "crate::deck",
                "crate::scene",
                "crate::search",
                "crate::enforce",
                "crate::embed",
                "crate::run",
                "crate::heat",
            ],
        ),
        ("scene", &["crate::embed", "crate::run", "crate::heat"]),
    ];
    let mut found = Vec::new();
    for (dir, forbidden) in rules {
        for (path, text) in sources(dir) {
            for (n, line) in text.lines().enumerate() {
                let code = line.split("//").next().unwrap_or("");
                for f in forbidden {
                    if code.contains(f) {
                        found.push(format!("{}:{}: {}", path.display(), n + 1, line.trim()));
                    }
                }
            }
        }
    }
    assert!(
        found.is_empty(),
        "imports that point up:\n{}",
        found.join("\n")
    );
}

/// The scene is the one reader of the typed deck spec: nothing else in `src/` names
/// `deck::spec` or walks a deck's enforcement blocks.
#[test]
fn only_the_scene_reads_the_deck_spec() {
    let mut found = Vec::new();
    for (path, text) in sources("") {
        let inside = ["deck", "scene"]
            .iter()
            .any(|d| path.starts_with(Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(d)));
        if inside {
            continue;
        }
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or("");
            if code.contains("deck::spec") || code.contains(".enforcements") {
                found.push(format!("{}:{}: {}", path.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "deck spec read outside the scene:\n{}",
        found.join("\n")
    );
}

/// No source file over 1000 lines, and `lib.rs` declares every top-level module.
#[test]
fn source_files_stay_small_and_lib_lists_every_module() {
    let mut long = Vec::new();
    for (path, text) in sources("") {
        let lines = text.lines().count();
        if lines > 1000 {
            long.push(format!("{} ({lines} lines)", path.display()));
        }
    }
    assert!(long.is_empty(), "files over 1000 lines: {long:?}");
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let lib = std::fs::read_to_string(src.join("lib.rs")).unwrap();
    // The binary's own modules (`src/cli/`) are declared by main.rs, not the library.
    let main = std::fs::read_to_string(src.join("main.rs")).unwrap();
    for entry in std::fs::read_dir(&src).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if name == "lib"
            || name == "main"
            || (path.is_file() && path.extension().is_none_or(|e| e != "rs"))
            || main.contains(&format!("mod {name};"))
        {
            continue;
        }
        assert!(
            lib.contains(&format!("mod {name};")),
            "src/lib.rs does not declare `{name}`"
        );
    }
}
