//! Diagnostics: what went wrong, where, and how to fix it.
//!
//! Every diagnostic has a stable code (`E…` errors, `W…` warnings), a message, an
//! optional location (file, 1-based line and column, length of the offending text) and
//! a help line. [`Diagnostics::render`] prints them rustc-style with the source line and
//! a caret, from the sources registered in a [`SourceMap`]. Codes are an interface:
//! tests and users match on them, so a code is never reused for another meaning.

use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

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

    /// Render every diagnostic, rustc-style:
    ///
    /// ```text
    /// error[E0103]: unknown keyword `contact surfce` in `begin contact definition`
    ///   --> deck.i:4:3
    ///    |
    ///  4 |   Contact Surfce top Contains block_1
    ///    |   ^^^^^^^^^^^^^^
    ///    = help: did you mean `contact surface`?
    /// ```
    pub fn render(&self, sources: &SourceMap) -> String {
        let mut out = String::new();
        for d in &self.0 {
            render_one(d, sources, &mut out);
        }
        out
    }
}

fn render_one(d: &Diagnostic, sources: &SourceMap, out: &mut String) {
    let kind = match d.severity {
        Severity::Error => "error",
        Severity::Warning => "warning",
    };
    let _ = writeln!(out, "{kind}[{}]: {}", d.code, d.message);
    if let Some(loc) = &d.loc {
        let _ = writeln!(out, "  --> {loc}");
        if let Some(text) = sources.line(&loc.file, loc.line) {
            let num = loc.line.to_string();
            let pad = " ".repeat(num.len());
            let text = text.replace('\t', " ");
            let caret_at = text
                .char_indices()
                .nth(loc.col.saturating_sub(1) as usize)
                .map(|(i, _)| text[..i].chars().count())
                .unwrap_or(text.chars().count());
            let _ = writeln!(out, " {pad} |");
            let _ = writeln!(out, " {num} | {text}");
            let _ = writeln!(
                out,
                " {pad} | {}{}",
                " ".repeat(caret_at),
                "^".repeat(loc.len.max(1) as usize)
            );
        }
    }
    if let Some(help) = &d.help {
        let _ = writeln!(out, "  = help: {help}");
    }
}

/// The display name of a file in messages: as given by the user, so it can be pasted.
pub fn file_label(path: &Path) -> Arc<str> {
    Arc::from(path.to_string_lossy().as_ref())
}

/// Levenshtein distance, for did-you-mean suggestions.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
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
        assert_eq!(lines[1], "  --> deck.i:2:3");
        assert_eq!(lines[3], " 2 |   Contact Surfce top");
        assert_eq!(lines[4], "   |   ^^^^^^^^^^^^^^");
    }

    #[test]
    fn suggestions_need_closeness() {
        let c = ["contact surface", "skin all blocks"];
        assert_eq!(did_you_mean("contact surfce", c), Some("contact surface"));
        assert_eq!(did_you_mean("gravity", c), None);
    }
}
