//! Hard inputs: each is read correctly or refused with a diagnostic, never read without
//! end, never silently turned into a wrong answer. Files too large or endless (E0003),
//! not UTF-8 (E0004), with a byte-order mark (accepted), thousands of unclosed blocks
//! or bad lines (a capped report), numbers out of range (E0227 and the older codes at
//! their boundaries), Lua that returns several values, periodic maps that collapse or
//! fold a surface (E0326).

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::Arc;
use std::time::{Duration, Instant};

use seam::deck::{self, codes, parse_sierra};
use seam::diag::{MAX_RENDERED, SourceMap};

use crate::scratch;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

const MESH: &str = "examples/two_blocks/two_blocks.exo";

/// `seam` with `args` from the repository root, killed (and the test failed) if it
/// has not finished within 60 s: the point of several tests is that it finishes.
fn seam(args: &[&str]) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_seam"))
        .args(args)
        .current_dir(root())
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("seam starts");
    let start = Instant::now();
    while child.try_wait().expect("seam can be waited on").is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            panic!("seam {args:?} did not finish within 60 s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().expect("seam output")
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn codes_of(text: &str) -> Vec<&'static str> {
    let (_, d) = parse_sierra(&Arc::from("deck.i"), text);
    d.0.iter().map(|x| x.code).collect()
}

// ----- bounded input -----

#[test]
fn a_deck_over_the_limit_is_refused_with_its_size_and_the_limit() {
    let tmp = scratch("hard-input-limit");
    let dir = tmp.path();
    let path = dir.join("big.i");
    let line = "begin contact definition\n  skin all blocks = on\nend\n";
    std::fs::write(&path, line.repeat(100)).unwrap();
    let size = (line.len() * 100) as u64;
    let loaded = deck::load_at_most(&path, size - 1);
    let d = &loaded.diagnostics.0;
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].code, codes::TOO_LARGE);
    let msg = &d[0].message;
    assert!(
        msg.contains(&path.display().to_string())
            && msg.contains(&format!("is {size} bytes"))
            && msg.contains(&format!("at most {} bytes", size - 1)),
        "{msg}"
    );
    assert!(
        d[0].help
            .as_deref()
            .unwrap_or("")
            .contains("check that the path")
    );
    // At the limit exactly, the same file is read.
    let loaded = deck::load_at_most(&path, size);
    assert!(loaded.diagnostics.is_empty(), "{:?}", loaded.diagnostics);
    assert_eq!(loaded.deck.contact_definitions.len(), 100);
}

#[cfg(unix)]
#[test]
fn dev_zero_as_a_deck_stops_at_the_limit() {
    let start = Instant::now();
    let loaded = deck::load(Path::new("/dev/zero"));
    assert_eq!(loaded.diagnostics.0.len(), 1);
    let d = &loaded.diagnostics.0[0];
    assert_eq!(d.code, codes::TOO_LARGE);
    assert!(
        d.message
            .starts_with("deck file /dev/zero gave more than 67108864 bytes (it has no size on disk, or grew while read); seam reads at most 64 MiB"),
        "{}",
        d.message
    );
    assert!(start.elapsed() < Duration::from_secs(30));
    // The command line too: exit 2 (bad input), promptly.
    let out = seam(&["check", "/dev/zero"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).starts_with("error[E0003]: deck file /dev/zero"),
        "{}",
        stderr(&out)
    );
    let out = seam(&["run", "/dev/zero"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).starts_with("error[E0003]: problem file /dev/zero"),
        "{}",
        stderr(&out)
    );
}

#[cfg(unix)]
#[test]
fn a_lua_file_that_never_ends_is_refused() {
    let tmp = scratch("hard-input-lua-zero");
    let dir = tmp.path();
    let link = dir.join("zero.lua");
    std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
    let deck = dir.join("deck.i");
    std::fs::write(
        &deck,
        "begin contact definition\n  contact surface bottom contains base_bottom\n  contact surface top contains base_top\n  periodicity for bottom = mapped x_map = zero.lua:f z_map = \"z + 1\"\nend\n",
    )
    .unwrap();
    let out = seam(&["search", deck.to_str().unwrap(), "--mesh", MESH]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("zero.lua gave more than 16777216 bytes (it has no size on disk, or grew while read); seam reads at most 16 MiB"),
        "{err}"
    );
}

#[test]
fn text_that_is_not_utf8_is_refused_at_its_line_and_column() {
    let tmp = scratch("hard-input-latin1");
    let dir = tmp.path();
    let path = dir.join("deck.i");
    std::fs::write(
        &path,
        b"begin contact definition\n  contact surface caf\xe9 contains block_1\nend\n",
    )
    .unwrap();
    let loaded = deck::load(&path);
    let d = &loaded.diagnostics.0;
    assert_eq!(d.len(), 1, "{d:?}");
    assert_eq!(d[0].code, codes::NOT_UTF8);
    let at = d[0].loc.clone().unwrap_or_default();
    assert_eq!((at.line, at.col), (2, 22));
    let shown = loaded.diagnostics.render(&loaded.sources);
    assert!(
        shown.contains(&format!("--> {}:2:22", path.display()))
            && shown.contains("\n2 |   contact surface caf\u{fffd} contains block_1"),
        "{shown}"
    );
    // The same for a problem file.
    let problem = dir.join("problem.toml");
    std::fs::write(&problem, b"[mesh]\nfile = \"m\xf6.exo\"\n").unwrap();
    match seam::run::check(&problem) {
        Err(seam::run::RunError::Input(d, _)) => {
            assert_eq!(d.0[0].code, codes::NOT_UTF8);
            let at = d.0[0].loc.clone().unwrap_or_default();
            assert_eq!((at.line, at.col), (2, 10));
        }
        Err(seam::run::RunError::Solve(e)) => panic!("expected E0004, got {e}"),
        Ok(_) => panic!("expected E0004, the problem file was read"),
    }
}

#[test]
fn a_byte_order_mark_reads_as_without_it() {
    let tmp = scratch("hard-input-bom");
    let dir = tmp.path();
    let text = std::fs::read_to_string(root().join("examples/two_blocks/contact.i")).unwrap();
    for (name, body) in [
        ("plain.i", text.clone()),
        ("bom.i", format!("\u{feff}{text}")),
    ] {
        std::fs::write(dir.join(name), body).unwrap();
    }
    let plain = deck::load(&dir.join("plain.i"));
    let bom = deck::load(&dir.join("bom.i"));
    assert!(bom.diagnostics.is_empty(), "{:?}", bom.diagnostics);
    assert!(!plain.deck.contact_definitions.is_empty());
    assert_eq!(bom.deck.without_locations(), plain.deck.without_locations());
    // Columns count from after the mark: the first block starts in column 1.
    let first = &bom.deck.contact_definitions[0].at;
    assert_eq!(first.col, plain.deck.contact_definitions[0].at.col);

    // TOML decks and problem files too.
    let toml = std::fs::read_to_string(root().join("examples/two_blocks/contact.toml")).unwrap();
    std::fs::write(dir.join("bom.toml"), format!("\u{feff}{toml}")).unwrap();
    let t = deck::load(&dir.join("bom.toml"));
    assert!(t.diagnostics.is_empty(), "{:?}", t.diagnostics);
    assert!(!t.deck.contact_definitions.is_empty());
    let ex = root().join("examples/two_blocks");
    let problem = std::fs::read_to_string(ex.join("problem.toml"))
        .unwrap()
        .replace(
            "\"two_blocks.exo\"",
            &format!("{:?}", ex.join("two_blocks.exo").display().to_string()),
        )
        .replace(
            "\"contact_run.i\"",
            &format!("{:?}", ex.join("contact_run.i").display().to_string()),
        );
    let path = dir.join("problem.toml");
    std::fs::write(&path, format!("\u{feff}{problem}")).unwrap();
    match seam::run::check(&path) {
        Ok(_) => {}
        Err(seam::run::RunError::Input(d, sources)) => {
            panic!(
                "a problem file with a BOM is refused: {}",
                d.render(&sources)
            )
        }
        Err(seam::run::RunError::Solve(e)) => panic!("{e}"),
    }
}

// ----- capped diagnostics -----

#[test]
fn ten_thousand_unclosed_blocks_give_a_short_report() {
    let tmp = scratch("hard-input-unclosed");
    let dir = tmp.path();
    let path = dir.join("deck.i");
    std::fs::write(&path, "begin contact definition\n".repeat(10_000)).unwrap();
    let out = seam(&["check", path.to_str().unwrap()]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    let errors = err.lines().filter(|l| l.starts_with("error[")).count();
    assert!(errors <= MAX_RENDERED + 1, "{errors} errors:\n{err}");
    assert!(
        err.contains("9997 more blocks opened from line 4 on are never closed"),
        "{err}"
    );
    // Deeper than any real file: one E0114 and nothing from the skipped part.
    assert_eq!(err.matches("error[E0114]").count(), 1, "{err}");
}

#[test]
fn ten_thousand_bad_lines_print_fifty_and_a_count() {
    let mut text = String::from("begin contact definition\n");
    text += &"  frobnicate = 1\n".repeat(10_000);
    text += "end\n";
    let file: Arc<str> = Arc::from("deck.i");
    let (_, d) = parse_sierra(&file, &text);
    assert_eq!(d.len(), 10_000);
    let mut sources = SourceMap::default();
    sources.add(&file, &text);
    let shown = d.render(&sources);
    assert_eq!(
        shown.lines().filter(|l| l.starts_with("error[")).count(),
        MAX_RENDERED
    );
    assert_eq!(
        shown.lines().last(),
        Some("note: 9950 more diagnostics not shown (9950 errors); the first 50 are above")
    );
}

// ----- ranges -----

/// A deck with `line` in the search options of a definition that is otherwise fine.
fn search_option(line: &str) -> String {
    format!(
        "begin contact definition\n  skin all blocks = on\n  begin search options\n    {line}\n  end\nend\n"
    )
}

#[test]
fn search_options_are_checked_at_their_boundaries() {
    for (line, code) in [
        ("normal check angle = 180", None),
        ("normal check angle = 0.001", None),
        ("normal check angle = 180.001", Some(codes::OUT_OF_RANGE)),
        ("normal check angle = 0", Some(codes::OUT_OF_RANGE)),
        ("normal check angle = 720", Some(codes::OUT_OF_RANGE)),
        ("normal check angle = -80", Some(codes::OUT_OF_RANGE)),
        ("field factor = 1e-6", None),
        ("field factor = 0", Some(codes::OUT_OF_RANGE)),
        ("field factor = -3", Some(codes::OUT_OF_RANGE)),
        ("buffer factor = 0", None),
        ("buffer factor = -1e-9", Some(codes::OUT_OF_RANGE)),
        ("tangential tolerance = 0", None),
        ("tangential tolerance = -0.01", Some(codes::OUT_OF_RANGE)),
        ("normal tolerance = 1e-9", None),
        ("normal tolerance = 0", Some(codes::NORMAL_TOLERANCE)),
        ("search update frequency = 1", None),
        ("search update frequency = 0", Some(codes::OUT_OF_RANGE)),
    ] {
        let got = codes_of(&search_option(line));
        assert_eq!(got, code.into_iter().collect::<Vec<_>>(), "{line}");
    }
}

#[test]
fn definition_and_enforcement_numbers_are_checked() {
    let def =
        |line: &str| format!("begin contact definition\n  skin all blocks = on\n  {line}\nend\n");
    for (text, code) in [
        (def("opposed normal threshold angle = 90"), None),
        (def("opposed normal threshold angle = 180"), None),
        (
            def("opposed normal threshold angle = 181"),
            Some(codes::OPPOSED_ANGLE),
        ),
        (def("update search every 1 steps"), None),
        (
            def("update search every 0 steps"),
            Some(codes::OUT_OF_RANGE),
        ),
        (
            def("restrict contact to subdomain defined by radius 0.1 and point 0 0 0"),
            None,
        ),
        (
            def("restrict contact to subdomain defined by radius -1 and point 0 0 0"),
            Some(codes::OUT_OF_RANGE),
        ),
        (def("scale penalty = 0"), Some(codes::NOT_POSITIVE)),
        (
            def(
                "begin enforcement e\n enforcement for energy = dash\n dash penalty factor = 0\n end",
            ),
            Some(codes::OUT_OF_RANGE),
        ),
        (
            def(
                "begin enforcement e\n enforcement for energy = dash\n dash penalty factor = 5\n end",
            ),
            None,
        ),
        (
            def("begin enforcement e\n enforcement for energy = dash\n contact pressure = 0\n end"),
            None,
        ),
        (
            def(
                "begin enforcement e\n enforcement for energy = dash\n contact pressure = -1\n end",
            ),
            Some(codes::OUT_OF_RANGE),
        ),
    ] {
        let got = codes_of(&text);
        assert_eq!(got, code.into_iter().collect::<Vec<_>>(), "{text}");
    }
}

#[test]
fn toml_ranges_refuse_infinities_and_nan() {
    let text = "[[contact_definition]]\n[[contact_definition.surface]]\nkind = \"skin_all_blocks\"\n[contact_definition.search_options]\nfield_factor = inf\nbuffer_factor = nan\nnormal_check_angle = 90.0\n";
    let (_, d) = deck::parse_toml(&Arc::from("deck.toml"), text);
    let got: Vec<(&str, u32)> =
        d.0.iter()
            .map(|x| (x.code, x.loc.as_ref().map_or(0, |l| l.line)))
            .collect();
    assert_eq!(got, [(codes::OUT_OF_RANGE, 5), (codes::OUT_OF_RANGE, 6)]);
}

// ----- Lua and periodic maps -----

/// Search the two-block example with the bottom made periodic by `transform` (Lua files
/// from `files`), in a scratch directory.
fn search_periodic(name: &str, transform: &str, files: &[(&str, &str)]) -> Output {
    let tmp = scratch(&format!("hard-input-{name}"));
    let dir = tmp.path();
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    let deck = dir.join("deck.i");
    std::fs::write(
        &deck,
        format!(
            "begin contact definition\n  contact surface bottom contains base_bottom\n  contact surface top contains base_top\n  periodicity for bottom = {transform}\nend\n"
        ),
    )
    .unwrap();
    seam(&["search", deck.to_str().unwrap(), "--mesh", MESH])
}

#[test]
fn a_lua_map_returning_two_values_is_refused() {
    let out = search_periodic(
        "two-values",
        "mapped x_map = \"math.modf(x)\" z_map = \"z + 1\"",
        &[],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("error[E0321]")
            && err.contains("`math.modf(x)`")
            && err.contains("returned 2 values"),
        "{err}"
    );
    let out = search_periodic(
        "two-values-file",
        "mapped x_map = maps.lua:fx z_map = \"z + 1\"",
        &[("maps.lua", "function fx(x, y, z)\n  return x, y\nend\n")],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("fx (") && err.contains("returned 2 values"),
        "{err}"
    );
}

#[test]
fn collapsing_or_folding_lua_maps_are_refused_and_a_true_map_is_not() {
    // Every node onto one point (the held-out case: it used to pass with 144/144 matched).
    let out = search_periodic(
        "collapse",
        "mapped x_map = maps.lua:half y_map = 0.5 z_map = \"z + 1\"",
        &[("maps.lua", "function half(x, y, z) return 0.5 end\n")],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("error[E0326]: periodicity for `bottom`: the map is not one-to-one: nodes ")
            && err.contains("land at (0.5, 0.5, 1) and (0.5, 0.5, 1)"),
        "{err}"
    );
    assert!(!err.contains("matched") && !String::from_utf8_lossy(&out.stdout).contains("144"));
    // A fold: x and 1 − x land together (the image still covers half the top).
    let out = search_periodic(
        "fold",
        "mapped x_map = \"0.5 - math.abs(x - 0.5)\" z_map = \"z + 1\"",
        &[],
    );
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("error[E0326]"), "{err}");
    // The same translation as a Lua map is one-to-one and searches.
    let out = search_periodic("true-map", "mapped z_map = \"z + 1\"", &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("E0326"));
}
