//! Bad decks as files, each with the diagnostics it must produce.
//!
//! Every directory under `tests/bad/` that holds a `deck.i` or `deck.toml` and no `args`
//! file (those are command-line cases) is one case: the deck is parsed with the file
//! label `deck.i` / `deck.toml` and the rendered diagnostics must equal
//! `expected.stderr`. Run with `SEAM_BLESS=1` to rewrite the expected files after a
//! deliberate change, then read every changed file before committing it.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use seam::deck::{parse_sierra, parse_toml};
use seam::diag::SourceMap;

fn cases() -> Vec<(PathBuf, &'static str)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad");
    let mut out = Vec::new();
    let entries = std::fs::read_dir(&root).expect("tests/bad exists");
    for entry in entries {
        let dir = entry.expect("readable directory entry").path();
        if !dir.is_dir() || dir.join("args").exists() {
            continue;
        }
        for name in ["deck.i", "deck.toml"] {
            if dir.join(name).exists() {
                out.push((dir.clone(), name));
            }
        }
    }
    out.sort();
    out
}

fn render(dir: &Path, name: &'static str) -> String {
    let text = std::fs::read_to_string(dir.join(name)).expect("deck is readable");
    let file: Arc<str> = Arc::from(name);
    let (_, diags) = if name.ends_with(".toml") {
        parse_toml(&file, &text)
    } else {
        parse_sierra(&file, &text)
    };
    assert!(
        !diags.is_empty(),
        "{}: a bad deck produced no diagnostics",
        dir.display()
    );
    let mut sources = SourceMap::default();
    sources.add(&file, &text);
    diags.render(&sources)
}

#[test]
fn bad_decks_match_their_snapshots() {
    let bless = std::env::var_os("SEAM_BLESS").is_some_and(|v| v == "1");
    let cases = cases();
    assert!(
        cases.len() >= 10,
        "expected the bad-deck cases, found {}",
        cases.len()
    );
    let mut failures = Vec::new();
    for (dir, name) in cases {
        let got = render(&dir, name);
        let path = dir.join("expected.stderr");
        if bless {
            std::fs::write(&path, &got).expect("expected.stderr is writable");
            continue;
        }
        let want = std::fs::read_to_string(&path).unwrap_or_default();
        if got != want {
            failures.push(format!(
                "--- {} ---\nexpected:\n{want}\ngot:\n{got}",
                dir.display()
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "{} snapshot(s) differ (SEAM_BLESS=1 rewrites them):\n{}",
        failures.len(),
        failures.join("\n")
    );
}
