//! Diagnostics: what went wrong, where, and how to fix it.
//!
//! Every diagnostic has a stable code (`E…` errors, `W…` warnings), a message, an
//! optional location (file, 1-based line and column, length of the offending text) and
//! a help line. [`Diagnostics::render`] prints them rustc-style with the source line and
//! a caret, from the sources registered in a [`SourceMap`], laid out by the
//! `annotate-snippets` crate (rustc's own renderer); [`Diagnostics::render_styled`] adds
//! colour for a terminal. Codes are an interface:
//! tests and users match on them, so a code is never reused for another meaning.
//! A render prints at most [`MAX_RENDERED`] diagnostics and then one line counting the
//! rest: past that many, the first ones are what to fix.
//!
//! Input text is read through [`read_text`]: bounded in size (so a device such as
//! `/dev/zero`, a FIFO or a mesh given by mistake cannot make seam read without end),
//! UTF-8 or an error at the line and column of the first bad byte, a leading byte-order
//! mark dropped. The bounds are [`MAX_DECK_BYTES`] (decks, whole Sierra input files,
//! problem files) and [`MAX_LUA_BYTES`] (Lua files).

use std::collections::HashMap;
use std::fmt::Write as _;
use std::io::Read as _;
use std::path::Path;
use std::sync::Arc;

use annotate_snippets::{Group, Renderer};
use serde::Serialize;

#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Warning,
    Error,
}

/// A place in a source file. Lines and columns are 1-based; `len` is in characters.
#[derive(Clone, Debug, PartialEq, Eq, Default, Serialize)]
pub struct Loc {
    pub file: Arc<str>,
    pub line: u32,
    pub col: u32,
    pub len: u32,
}

impl Loc {
    pub fn new(file: &Arc<str>, line: u32, col: u32, len: u32) -> Self {
        Loc {
            file: file.clone(),
            line,
            col,
            len,
        }
    }

    /// True for the default (unknown) location.
    pub fn is_unknown(&self) -> bool {
        self.line == 0
    }
}

impl std::fmt::Display for Loc {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.col)
    }
}

#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Diagnostic {
    pub severity: Severity,
    pub code: &'static str,
    pub message: String,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub loc: Option<Loc>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub help: Option<String>,
}

impl Diagnostic {
    pub fn error(code: &'static str, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            code,
            message: message.into(),
            loc: None,
            help: None,
        }
    }

    pub fn warning(code: &'static str, message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(code, message)
        }
    }

    pub fn at(mut self, loc: Option<Loc>) -> Self {
        self.loc = loc.filter(|l| !l.is_unknown());
        self
    }

    pub fn help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }
}

/// The text of every file diagnostics may point into, by the name used in [`Loc::file`].
#[derive(Clone, Debug, Default)]
pub struct SourceMap {
    files: HashMap<Arc<str>, Arc<str>>,
}

impl SourceMap {
    pub fn add(&mut self, name: &Arc<str>, text: &str) {
        self.files.insert(name.clone(), Arc::from(text));
    }

    pub fn line(&self, file: &str, line: u32) -> Option<&str> {
        let text = self.files.get(file)?;
        text.lines().nth(line.checked_sub(1)? as usize)
    }
}

/// A collection of diagnostics from one run: all of them are reported, not just the first.
#[derive(Clone, Debug, Default, Serialize)]
#[serde(transparent)]
pub struct Diagnostics(pub Vec<Diagnostic>);

impl Diagnostics {
    pub fn push(&mut self, d: Diagnostic) {
        self.0.push(d);
    }

    pub fn extend(&mut self, other: Diagnostics) {
        self.0.extend(other.0);
    }

    pub fn has_errors(&self) -> bool {
        self.0.iter().any(Diagnostic::is_error)
    }

    pub fn errors(&self) -> impl Iterator<Item = &Diagnostic> {
        self.0.iter().filter(|d| d.is_error())
    }

    pub fn warnings(&self) -> impl Iterator<Item = &Diagnostic> {
        self.0.iter().filter(|d| !d.is_error())
    }

    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// Render the diagnostics as plain text, rustc-style, the first [`MAX_RENDERED`] of
    /// them and then one line counting the rest (see [`Diagnostics::render_at_most`]):
    ///
    /// ```text
    /// error[E0103]: unknown keyword `contact surfce` in `begin contact definition`
    ///  --> deck.i:4:3
    ///   |
    /// 4 |   Contact Surfce top Contains block_1
    ///   |   ^^^^^^^^^^^^^^
    ///   |
    ///   = help: did you mean `contact surface`?
    /// ```
    pub fn render(&self, sources: &SourceMap) -> String {
        self.render_at_most(sources, MAX_RENDERED)
    }

    /// The same text as [`Diagnostics::render`] with ANSI colour codes (severity, code,
    /// gutter and caret), for a terminal; a caller decides whether its stream wants them.
    pub fn render_styled(&self, sources: &SourceMap) -> String {
        self.render_with(sources, MAX_RENDERED, &Renderer::styled())
    }

    /// Render the first `max` diagnostics, then, if some are left, one line:
    /// `note: 9950 more diagnostics not shown (9950 errors); the first 50 are above`.
    pub fn render_at_most(&self, sources: &SourceMap, max: usize) -> String {
        self.render_with(sources, max, &Renderer::plain())
    }

    fn render_with(&self, sources: &SourceMap, max: usize, renderer: &Renderer) -> String {
        let renderer = renderer.clone().term_width(LINE_SHOWN);
        let mut out = String::new();
        for d in self.0.iter().take(max) {
            render_one(d, sources, &renderer, &mut out);
        }
        let rest = self.0.get(max..).unwrap_or_default();
        if !rest.is_empty() {
            let errors = rest.iter().filter(|d| d.is_error()).count();
            let warnings = rest.len() - errors;
            let mut kinds = Vec::new();
            if errors > 0 {
                kinds.push(plural(errors, "error"));
            }
            if warnings > 0 {
                kinds.push(plural(warnings, "warning"));
            }
            let note = format!(
                "{} more diagnostic{} not shown ({}); the first {max} are above",
                rest.len(),
                if rest.len() == 1 { "" } else { "s" },
                kinds.join(", ")
            );
            let title = annotate_snippets::Level::NOTE.primary_title(note);
            let _ = writeln!(out, "{}", renderer.render(&[Group::with_title(title)]));
        }
        out
    }
}

/// How many diagnostics one render prints before it only counts the rest: enough for
/// every problem of a real deck (the bad-deck snapshots hold at most a dozen), few
/// enough that a runaway input (10 000 bad lines) does not bury the first, which is
/// usually the cause of the others.
pub const MAX_RENDERED: usize = 50;

/// The width a diagnostic is laid out for: a source line longer than this is shown
/// as a window around the caret, with `...` where it is cut.
const LINE_SHOWN: usize = 160;

fn plural(n: usize, what: &str) -> String {
    format!("{n} {what}{}", if n == 1 { "" } else { "s" })
}

fn render_one(d: &Diagnostic, sources: &SourceMap, renderer: &Renderer, out: &mut String) {
    use annotate_snippets::{AnnotationKind, Level, Origin, Snippet};
    let level = match d.severity {
        Severity::Error => Level::ERROR,
        Severity::Warning => Level::WARNING,
    };
    // A message that carries its own help lines (an error's text from a layer that has
    // no help field, such as the mesh readers' `…\n  help: …`) shows them as help lines.
    let mut parts = d.message.split("\n  help: ");
    let title = parts.next().unwrap_or_default();
    let mut group = Group::with_title(level.primary_title(title).id(d.code));
    if let Some(loc) = &d.loc {
        group = match sources.line(&loc.file, loc.line) {
            Some(text) => {
                // The caret: `len` characters from `col`, kept on the line (a place past
                // its end is shown at the end), at least one character wide.
                let byte = |chars: usize| {
                    text.char_indices()
                        .nth(chars)
                        .map_or(text.len(), |(i, _)| i)
                };
                let at = loc.col.saturating_sub(1) as usize;
                let start = byte(at);
                let end = byte(at + loc.len.max(1) as usize);
                group.element(
                    Snippet::source(text)
                        .line_start(loc.line as usize)
                        .path(&*loc.file)
                        .annotation(AnnotationKind::Primary.span(start..end)),
                )
            }
            None => group.element(
                Origin::path(&*loc.file)
                    .line(loc.line as usize)
                    .char_column(loc.col as usize),
            ),
        };
    }
    for help in parts.chain(d.help.as_deref()) {
        group = group.element(Level::HELP.message(help));
    }
    out.push_str(&renderer.render(&[group]));
    out.push('\n');
}

/// The display name of a file in messages: as given by the user, so it can be pasted.
pub fn file_label(path: &Path) -> Arc<str> {
    Arc::from(path.to_string_lossy().as_ref())
}

/// The most bytes seam reads from a contact deck, a whole Sierra input file or a problem
/// file: 64 MiB. A contact deck is a few kilobytes and a whole Sierra input file of a
/// large model a few megabytes; 64 MiB is ten times the largest of those and still
/// parses in seconds, while a mesh, a results file or a device given by mistake is
/// refused before seam holds it in memory.
pub const MAX_DECK_BYTES: u64 = 64 << 20;

/// The most bytes seam reads from a Lua file (`file.lua:function` maps and
/// expressions): 16 MiB, the Lua sandbox's own memory limit — a larger file could not be
/// loaded by it anyway. A map or conductance function is a few hundred bytes; a file
/// holding a large table of data stays well under this.
pub const MAX_LUA_BYTES: u64 = 16 << 20;

/// Why an input file could not be read as text.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    #[error("cannot read {what} {path}: {message}")]
    Io {
        what: &'static str,
        path: String,
        message: String,
    },
    #[error("{what} {path} {}; seam reads at most {} from a {what}", size_text(*.size, *.limit), bytes_text(*.limit))]
    TooLarge {
        what: &'static str,
        path: String,
        /// The size on disk; `None` when the file has none (a device, a FIFO) or grew
        /// while read: it then gave more than `limit` bytes.
        size: Option<u64>,
        limit: u64,
    },
    #[error("{what} {path} is not UTF-8 text: byte 0x{byte:02x} at line {}, column {}", .at.line, .at.col)]
    NotUtf8 {
        what: &'static str,
        path: String,
        byte: u8,
        /// Where the first byte that is not UTF-8 sits (the column counts the
        /// characters before it on its line).
        at: Loc,
        /// The text with bad bytes replaced by U+FFFD, to show the line.
        lossy: String,
    },
}

impl ReadError {
    /// What to do about it, for a help line.
    pub fn help(&self) -> String {
        match self {
            ReadError::Io { .. } => "check the path and that the file is readable".into(),
            ReadError::TooLarge { what, limit, .. } => {
                let usual = if *limit >= MAX_DECK_BYTES {
                    "a contact deck is a few kilobytes, a whole Sierra input file a few megabytes"
                } else {
                    "a Lua map or conductance function is a few hundred bytes"
                };
                format!(
                    "{usual}: check that the path names the {what} and not a mesh, a results file or a device; the limit keeps a wrong path from making seam read without end"
                )
            }
            ReadError::NotUtf8 { .. } => "save the file as UTF-8 (plain ASCII is UTF-8); a file in Latin-1 or UTF-16, or a binary file, is not".into(),
        }
    }

    /// The place to point at (for text that is not UTF-8).
    pub fn loc(&self) -> Option<Loc> {
        match self {
            ReadError::NotUtf8 { at, .. } => Some(at.clone()),
            _ => None,
        }
    }

    /// The text to show the place in (for text that is not UTF-8).
    pub fn lossy_text(&self) -> Option<&str> {
        match self {
            ReadError::NotUtf8 { lossy, .. } => Some(lossy),
            _ => None,
        }
    }
}

fn bytes_text(n: u64) -> String {
    const MIB: u64 = 1 << 20;
    if n >= MIB && n.is_multiple_of(MIB) {
        format!("{} MiB ({n} bytes)", n / MIB)
    } else if n >= MIB {
        format!("{:.1} MiB ({n} bytes)", n as f64 / MIB as f64)
    } else {
        format!("{n} bytes")
    }
}

fn size_text(size: Option<u64>, limit: u64) -> String {
    match size {
        Some(n) => format!("is {}", bytes_text(n)),
        None => {
            format!("gave more than {limit} bytes (it has no size on disk, or grew while read)")
        }
    }
}

/// Read the file `path` as text, at most `limit` bytes: its size on disk is checked
/// first, and the read itself stops one byte past `limit`, so a device or a FIFO that
/// never ends is refused as well. A leading UTF-8 byte-order mark is dropped. `what`
/// names the kind of file in messages (`deck file`, `problem file`, `Lua file`).
pub fn read_text(path: &Path, what: &'static str, limit: u64) -> Result<String, ReadError> {
    let label = path.display().to_string();
    let io = |e: std::io::Error| ReadError::Io {
        what,
        path: label.clone(),
        message: e.to_string(),
    };
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if meta.is_dir() {
        return Err(ReadError::Io {
            what,
            path: label,
            message: "it is a directory".into(),
        });
    }
    if meta.is_file() && meta.len() > limit {
        return Err(ReadError::TooLarge {
            what,
            path: label,
            size: Some(meta.len()),
            limit,
        });
    }
    let mut bytes = Vec::new();
    file.take(limit.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > limit {
        return Err(ReadError::TooLarge {
            what,
            path: label,
            size: None,
            limit,
        });
    }
    text_from_bytes(bytes, &label, what)
}

/// `bytes` as text: UTF-8 with a leading byte-order mark dropped, else the error at the
/// line and column of the first bad byte.
pub fn text_from_bytes(
    mut bytes: Vec<u8>,
    path: &str,
    what: &'static str,
) -> Result<String, ReadError> {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let good = e.utf8_error().valid_up_to();
        let before = std::str::from_utf8(&bytes[..good]).unwrap_or_default();
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        let n = |x: usize| u32::try_from(x).unwrap_or(u32::MAX);
        let file: Arc<str> = Arc::from(path);
        ReadError::NotUtf8 {
            what,
            path: path.to_string(),
            byte: bytes.get(good).copied().unwrap_or_default(),
            at: Loc::new(&file, n(line), n(col), 1),
            lossy: String::from_utf8_lossy(bytes).into_owned(),
        }
    })
}

/// Levenshtein distance (in characters), for did-you-mean suggestions.
pub fn edit_distance(a: &str, b: &str) -> usize {
    strsim::levenshtein(a, b)
}

/// The candidate closest to `word`, if it is close enough to be a plausible misspelling
/// (at most a third of the word's length in edits, and at least one).
pub fn did_you_mean<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let word = word.to_ascii_lowercase();
    let limit = (word.chars().count() / 3).max(1);
    candidates
        .into_iter()
        .map(|c| (edit_distance(&word, &c.to_ascii_lowercase()), c))
        .filter(|&(d, _)| d <= limit)
        .min_by_key(|&(d, _)| d)
        .map(|(_, c)| c)
}

impl SourceMap {
    /// Narrow `loc` to the first case-insensitive occurrence of `word` as a whole word,
    /// on its line at or after its column, or else on the lines below it up to the
    /// `end` of the block it opens — so a caret can point at one name in a list. Returns
    /// `loc` unchanged when the word is not found.
    pub fn narrow(&self, loc: &Loc, word: &str) -> Loc {
        let word = word.to_ascii_lowercase();
        for (k, line_no) in (loc.line..loc.line.saturating_add(200)).enumerate() {
            let Some(line) = self.line(&loc.file, line_no) else {
                break;
            };
            let lower = line.to_ascii_lowercase();
            if k > 0 && lower.trim_start().starts_with("end") {
                break;
            }
            let start = if k == 0 {
                line.char_indices()
                    .nth(loc.col.saturating_sub(1) as usize)
                    .map_or(0, |(i, _)| i)
            } else {
                0
            };
            if let Some(at) = find_word(&lower, &word, start) {
                return Loc {
                    line: line_no,
                    col: lower[..at].chars().count() as u32 + 1,
                    len: word.chars().count() as u32,
                    ..loc.clone()
                };
            }
        }
        loc.clone()
    }
}

/// Byte offset of `word` in `text` at or after `from`, not inside a longer name.
fn find_word(text: &str, word: &str, from: usize) -> Option<usize> {
    let is_name = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.';
    let mut pos = from;
    while let Some(off) = text.get(pos..)?.find(word) {
        let at = pos + off;
        let before = text[..at].chars().next_back();
        let after = text[at + word.len()..].chars().next();
        if !before.is_some_and(is_name) && !after.is_some_and(is_name) {
            return Some(at);
        }
        pos = at + word.len().max(1);
    }
    None
}

#[cfg(test)]
mod tests {

    #[test]
    fn edit_distance_counts_characters_and_suggests_near_words() {
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("ΔT", "dT"), 1);
        assert_eq!(edit_distance("", "abc"), 3);
        let names = ["gap_conductance", "conductance", "contact_resistance"];
        assert_eq!(
            did_you_mean("gap_conductence", names),
            Some("gap_conductance")
        );
        assert_eq!(
            did_you_mean("GAP_CONDUCTANCE", names),
            Some("gap_conductance")
        );
        assert_eq!(did_you_mean("radiation", names), None);
    }

    use super::*;

    #[test]
    fn caret_points_at_the_column() {
        let file: Arc<str> = Arc::from("deck.i");
        let mut sources = SourceMap::default();
        sources.add(&file, "begin x\n  Contact Surfce top\nend\n");
        let mut ds = Diagnostics::default();
        ds.push(
            Diagnostic::error("E0103", "unknown keyword")
                .at(Some(Loc::new(&file, 2, 3, 14)))
                .help("did you mean `contact surface`?"),
        );
        let text = ds.render(&sources);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "error[E0103]: unknown keyword");
        assert_eq!(lines[1], " --> deck.i:2:3");
        assert_eq!(lines[3], "2 |   Contact Surfce top");
        assert_eq!(lines[4], "  |   ^^^^^^^^^^^^^^");
        assert_eq!(lines[6], "  = help: did you mean `contact surface`?");
        assert!(!text.contains('\x1b'), "{text}");
        // Styled: the same words, with ANSI colour codes around them.
        let styled = ds.render_styled(&sources);
        assert!(styled.contains("\x1b["), "{styled:?}");
        assert!(styled.contains("E0103") && styled.contains("Contact Surfce top"));
    }

    #[test]
    fn a_place_without_its_text_or_past_the_line_end_is_still_shown() {
        let file: Arc<str> = Arc::from("deck.i");
        let mut sources = SourceMap::default();
        sources.add(&file, "end\n");
        let ds = Diagnostics(vec![
            Diagnostic::warning("W0102", "past the end").at(Some(Loc::new(&file, 1, 9, 2))),
            Diagnostic::error("E0103", "no text").at(Some(Loc::new(&file, 7, 4, 1))),
        ]);
        let text = ds.render(&sources);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "warning[W0102]: past the end");
        assert_eq!(lines[1], " --> deck.i:1:4");
        assert_eq!(lines[3], "1 | end");
        assert_eq!(lines[4], "  |    ^");
        assert_eq!(lines[5], "error[E0103]: no text");
        assert_eq!(lines[6], "--> deck.i:7:4");
    }

    #[test]
    fn long_lines_are_shown_around_the_caret() {
        let file: Arc<str> = Arc::from("deck.i");
        let mut sources = SourceMap::default();
        let line = format!("{}BAD{}", "x".repeat(1000), "y".repeat(1000));
        sources.add(&file, &line);
        let ds = Diagnostics(vec![
            Diagnostic::error("E0103", "bad").at(Some(Loc::new(&file, 1, 1001, 3))),
        ]);
        let text = ds.render(&sources);
        let lines: Vec<&str> = text.lines().collect();
        assert!(lines[3].chars().count() < LINE_SHOWN + 10, "{}", lines[3]);
        let at = lines[3].find("BAD").map(|b| lines[3][..b].chars().count());
        assert_eq!(lines[4].find('^'), at);
        assert_eq!(lines[4].matches('^').count(), 3);
    }

    #[test]
    fn renders_are_capped_with_a_count_of_the_rest() {
        let mut ds = Diagnostics::default();
        for i in 0..60 {
            ds.push(Diagnostic::error("E0103", format!("problem {i}")));
        }
        ds.push(Diagnostic::warning("W0102", "late"));
        let text = ds.render(&SourceMap::default());
        let heads = text.lines().filter(|l| l.starts_with("error[")).count();
        assert_eq!(heads, MAX_RENDERED);
        assert!(!text.contains("problem 50"), "{text}");
        let last = text.lines().last().unwrap_or_default();
        assert_eq!(
            last,
            "note: 11 more diagnostics not shown (10 errors, 1 warning); the first 50 are above"
        );
        // At the cap exactly: no count line.
        ds.0.truncate(MAX_RENDERED);
        assert!(!ds.render(&SourceMap::default()).contains("note:"));
    }

    fn scratch(name: &str, bytes: &[u8]) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("seam-diag-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    }

    #[test]
    fn reads_are_bounded() {
        let path = scratch("big.i", &[b'x'; 1000]);
        let e = read_text(&path, "deck file", 999).unwrap_err();
        assert!(
            matches!(
                e,
                ReadError::TooLarge {
                    size: Some(1000),
                    limit: 999,
                    ..
                }
            ),
            "{e}"
        );
        let msg = e.to_string();
        assert!(
            msg.ends_with("is 1000 bytes; seam reads at most 999 bytes from a deck file"),
            "{msg}"
        );
        assert_eq!(read_text(&path, "deck file", 1000).unwrap().len(), 1000);
    }

    #[cfg(unix)]
    #[test]
    fn a_device_that_never_ends_is_refused() {
        let t = std::time::Instant::now();
        let e = read_text(Path::new("/dev/zero"), "deck file", 1 << 20).unwrap_err();
        assert!(matches!(e, ReadError::TooLarge { size: None, .. }), "{e}");
        assert!(
            e.to_string()
                .contains("/dev/zero gave more than 1048576 bytes (it has no size"),
            "{e}"
        );
        assert!(t.elapsed().as_secs() < 10);
    }

    #[test]
    fn byte_order_mark_is_dropped_and_bad_bytes_located() {
        let path = scratch("bom.i", "\u{feff}begin x\nend\n".as_bytes());
        assert_eq!(
            read_text(&path, "deck file", 100).unwrap(),
            "begin x\nend\n"
        );
        let path = scratch("latin1.i", b"begin x\n  name = caf\xe9\nend\n");
        let e = read_text(&path, "deck file", 100).unwrap_err();
        let at = e.loc().unwrap();
        assert_eq!((at.line, at.col), (2, 13));
        assert!(
            e.to_string()
                .ends_with("is not UTF-8 text: byte 0xe9 at line 2, column 13"),
            "{e}"
        );
        assert_eq!(
            e.lossy_text().and_then(|t| t.lines().nth(1)),
            Some("  name = caf\u{fffd}")
        );
        let e = read_text(&path.with_file_name("absent.i"), "deck file", 100).unwrap_err();
        assert!(matches!(e, ReadError::Io { .. }), "{e}");
    }

    #[test]
    fn suggestions_need_closeness() {
        let c = ["contact surface", "skin all blocks"];
        assert_eq!(did_you_mean("contact surfce", c), Some("contact surface"));
        assert_eq!(did_you_mean("gravity", c), None);
    }
}
