//! What a user expects of a well-kept command: diagnostics coloured on a terminal only
//! (`NO_COLOR`, `CLICOLOR_FORCE` and `--color` honoured), and `--help` texts that
//! document every flag.

use std::path::PathBuf;
use std::process::{Command, Output};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `seam ARGS` from the repository root with the colour variables of `env` alone set
/// (the caller's own `NO_COLOR`/`CLICOLOR*` removed first).
fn seam_with(env: &[(&str, &str)], args: &[&str]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_seam"));
    for var in ["NO_COLOR", "CLICOLOR", "CLICOLOR_FORCE"] {
        cmd.env_remove(var);
    }
    cmd.envs(env.iter().copied())
        .args(args)
        .current_dir(root())
        .output()
        .expect("seam runs")
}

const BAD_DECK: &str = "tests/bad/misspelt_keyword/deck.i";
const ESC: char = '\x1b';

/// The bad deck's diagnostics with the colour settings `env` and `flags`: (stderr,
/// whether it holds ANSI escapes). The words must not depend on the colour.
fn check_bad_deck(env: &[(&str, &str)], flags: &[&str]) -> (String, bool) {
    let mut args = vec!["check", BAD_DECK];
    args.extend_from_slice(flags);
    let out = seam_with(env, &args);
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8(out.stderr).expect("UTF-8 stderr");
    let coloured = stderr.contains(ESC);
    let plain = strip_ansi(&stderr);
    assert!(
        plain.contains("error[E0103]: unknown keyword `contact surfce`")
            && plain.contains(" --> tests/bad/misspelt_keyword/deck.i:2:3")
            && plain.contains("= help: did you mean `contact surface`?"),
        "{plain}"
    );
    (stderr, coloured)
}

/// `text` without its ANSI SGR sequences (`ESC [ … m`).
fn strip_ansi(text: &str) -> String {
    let mut out = String::new();
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == ESC {
            for d in chars.by_ref() {
                if d == 'm' {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

#[test]
fn diagnostics_are_coloured_only_when_asked_or_on_a_terminal() {
    // A pipe: plain text, as the snapshot tests see it.
    let (plain, coloured) = check_bad_deck(&[], &[]);
    assert!(!coloured, "{plain:?}");
    // Forced by the environment or by the flag: ANSI codes, the same words.
    let (forced, coloured) = check_bad_deck(&[("CLICOLOR_FORCE", "1")], &[]);
    assert!(coloured, "{forced:?}");
    assert_eq!(strip_ansi(&forced), plain);
    assert!(check_bad_deck(&[], &["--color", "always"]).1);
    // NO_COLOR wins over CLICOLOR_FORCE; `--color never` over both.
    assert!(!check_bad_deck(&[("NO_COLOR", "1"), ("CLICOLOR_FORCE", "1")], &[]).1);
    assert!(!check_bad_deck(&[("CLICOLOR_FORCE", "1")], &["--color", "never"]).1);
    // An explicit `--color always` is the user's word for this run, over NO_COLOR.
    assert!(check_bad_deck(&[("NO_COLOR", "1")], &["--color", "always"]).1);
    // JSON is never coloured.
    let out = seam_with(&[("CLICOLOR_FORCE", "1")], &["check", BAD_DECK, "--json"]);
    assert!(!String::from_utf8_lossy(&out.stdout).contains(ESC));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    assert_eq!(report["diagnostics"][0]["code"], "E0103");
}
