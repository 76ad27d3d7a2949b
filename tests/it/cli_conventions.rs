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

/// Every subcommand's flags, as its `--help` must list them (the global ones too).
const FLAGS: &[(&str, &[&str])] = &[
    (
        "surfaces",
        &["--mesh", "--json", "--dead", "--axisymmetric"],
    ),
    (
        "search",
        &[
            "--mesh",
            "--json",
            "--segments",
            "--order",
            "--axisymmetric",
            "--points",
        ],
    ),
    ("run", &["--json", "--restart"]),
    (
        "check-plugin",
        &["--real", "--integer", "--isolate", "--json"],
    ),
    ("example", &["--dir"]),
    (
        "check",
        &["--mesh", "--problem", "--axisymmetric", "--json"],
    ),
];
const GLOBAL: &[&str] = &["--threads", "--verbose", "--quiet", "--color", "--help"];

/// The option lines of a `--help` text: (flag, its description), the description being
/// the rest of the line (`-h`) or the lines indented under it (`--help`).
fn options(help: &str) -> Vec<(String, String)> {
    let mut out: Vec<(String, String)> = Vec::new();
    for line in help.lines() {
        let t = line.trim_start();
        let indent = line.len() - t.len();
        if (2..=6).contains(&indent) && t.starts_with('-') {
            let flag = t
                .split([' ', ',', '.', '<', '['])
                .find(|w| w.starts_with("--"))
                .unwrap_or_default()
                .to_string();
            let rest = t.split_once("  ").map_or("", |(_, r)| r.trim()).to_string();
            out.push((flag, rest));
        } else if indent > 6
            && let Some(last) = out.last_mut()
        {
            last.1.push(' ');
            last.1.push_str(t);
        }
    }
    out
}

#[test]
fn every_subcommand_help_documents_each_flag() {
    let top = seam_with(&[], &["--help"]);
    assert_eq!(top.status.code(), Some(0));
    let top = String::from_utf8(top.stdout).expect("UTF-8 help");
    // The exit codes, the plugin fault's 3 among them, and the environment.
    for want in [
        "Exit codes:",
        "  0  ok",
        "  1  ran but failed",
        "  2  bad input or usage",
        "  3  plugin fault",
        "RAYON_NUM_THREADS",
        "NO_COLOR",
        "CLICOLOR_FORCE",
    ] {
        assert!(top.contains(want), "`seam --help` lacks `{want}`:\n{top}");
    }
    let listed: Vec<&str> = top
        .split("Commands:")
        .nth(1)
        .and_then(|s| s.split("\n\n").next())
        .unwrap_or_default()
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    let known: Vec<&str> = FLAGS.iter().map(|(c, _)| *c).collect();
    assert_eq!(listed, known, "the subcommands `seam --help` lists");
    for (sub, flags) in FLAGS {
        for args in [vec![*sub, "--help"], vec!["help", *sub]] {
            let out = seam_with(&[], &args);
            assert_eq!(out.status.code(), Some(0), "seam {args:?}");
            let help = String::from_utf8(out.stdout).expect("UTF-8 help");
            let opts = options(&help);
            for flag in flags.iter().chain(GLOBAL) {
                let Some((_, text)) = opts.iter().find(|(f, _)| f == flag) else {
                    panic!("`seam {sub} --help` does not list {flag}:\n{help}");
                };
                assert!(
                    text.len() > 10,
                    "`seam {sub} --help`: {flag} has no description"
                );
            }
            // No flag the list above does not know of, each with its description.
            for (flag, text) in &opts {
                assert!(
                    flags.contains(&flag.as_str()) || GLOBAL.contains(&flag.as_str()),
                    "`seam {sub} --help` lists {flag}, unknown to this test"
                );
                assert!(!text.is_empty(), "{flag}");
            }
            // --threads names the variable that does the same.
            assert!(help.contains("RAYON_NUM_THREADS"), "seam {sub} --help");
        }
    }
    // The run's own help gives its exit codes, 3 for a plugin fault among them.
    let run = String::from_utf8(seam_with(&[], &["run", "--help"]).stdout).unwrap();
    assert!(run.contains("3 on a plugin fault"), "{run}");
}
