//! Bad inputs that need the whole command: a case directory `tests/bad/<case>/` with an
//! `args` file (the `seam` command line, run from the case directory) and the expected
//! `expected.stderr` and `expected.code`. `SEAM_BLESS=1` rewrites the expectations.

use std::path::Path;
use std::process::Command;

#[test]
fn bad_command_lines_give_their_snapshot_diagnostics() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad");
    let bless = std::env::var_os("SEAM_BLESS").is_some();
    let mut cases: Vec<_> = std::fs::read_dir(&root)
        .expect("tests/bad exists")
        .map(|e| e.expect("readable dir entry").path())
        .filter(|p| p.join("args").is_file())
        .collect();
    cases.sort();
    assert!(
        !cases.is_empty(),
        "no command-line cases found under {}",
        root.display()
    );
    let mut failures = Vec::new();
    for case in &cases {
        let args = std::fs::read_to_string(case.join("args")).expect("args readable");
        let out = Command::new(env!("CARGO_BIN_EXE_seam"))
            .env_remove("CLICOLOR_FORCE") // the snapshots are the plain text
            .args(args.split_whitespace())
            .current_dir(case)
            .output()
            .expect("seam runs");
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        let code = out.status.code().map_or("signal".into(), |c| c.to_string());
        let (err_file, code_file) = (case.join("expected.stderr"), case.join("expected.code"));
        if bless {
            std::fs::write(&err_file, &stderr).expect("write snapshot");
            std::fs::write(&code_file, format!("{code}\n")).expect("write snapshot");
            continue;
        }
        let want_err = std::fs::read_to_string(&err_file).unwrap_or_default();
        let want_code = std::fs::read_to_string(&code_file).unwrap_or_default();
        if stderr != want_err || code != want_code.trim() {
            failures.push(format!(
                "{}: exit {code} (want {}), stderr:\n{stderr}\n--- want:\n{want_err}",
                case.display(),
                want_code.trim()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}
