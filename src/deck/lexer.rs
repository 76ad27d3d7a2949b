//! Stage one of the Sierra front end: text → lines of tokens, each with line and column.
//!
//! Entry point: [`lex`]. Conventions: `#` and `$` start a comment that runs to the end of
//! the line unless inside a quoted string; spaces, tabs and commas only separate tokens;
//! `=` and the bare words `is` and `are` are all the same separator token
//! ([`Kind::Sep`]); a quoted string `"…"` is one token whose text keeps its case.
//! Columns are 1-based and counted in characters, as [`Loc`] expects.

use std::sync::Arc;

use crate::diag::{Diagnostic, Diagnostics, Loc};

use super::codes;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A bare word: keyword, name or number.
    Word,
    /// A quoted string, quotes removed.
    Str,
    /// `=`, `is` or `are`.
    Sep,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Token {
    pub kind: Kind,
    /// The text as written (without quotes for strings).
    pub text: String,
    /// Lower case of `text`, for keyword matching.
    pub lower: String,
    pub line: u32,
    pub col: u32,
    /// Length in characters as written, quotes included.
    pub len: u32,
}

impl Token {
    pub fn loc(&self, file: &Arc<str>) -> Loc {
        Loc::new(file, self.line, self.col, self.len)
    }

    pub fn is_word(&self) -> bool {
        self.kind == Kind::Word
    }

    pub fn is_sep(&self) -> bool {
        self.kind == Kind::Sep
    }
}

/// One non-empty source line, comments removed.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    pub line: u32,
    pub tokens: Vec<Token>,
}

/// The span from the first to the last of `tokens` (all on one line), or `None` if empty.
pub fn span(file: &Arc<str>, tokens: &[Token]) -> Option<Loc> {
    let first = tokens.first()?;
    let last = tokens.last()?;
    let end = last.col.saturating_add(last.len);
    Some(Loc::new(
        file,
        first.line,
        first.col,
        end.saturating_sub(first.col),
    ))
}

fn is_space(c: char) -> bool {
    c == ' ' || c == '\t' || c == ',' || c == '\r' || c.is_whitespace()
}

fn ends_word(c: char) -> bool {
    is_space(c) || c == '=' || c == '"' || c == '#' || c == '$'
}

/// Split `text` into lines of tokens; blank and comment-only lines are dropped.
pub fn lex(file: &Arc<str>, text: &str) -> (Vec<Line>, Diagnostics) {
    let mut lines = Vec::new();
    let mut diags = Diagnostics::default();
    for (i, src) in text.split('\n').enumerate() {
        let line_no = u32::try_from(i + 1).unwrap_or(u32::MAX);
        let tokens = lex_line(file, line_no, src, &mut diags);
        if !tokens.is_empty() {
            lines.push(Line {
                line: line_no,
                tokens,
            });
        }
    }
    (lines, diags)
}

fn lex_line(file: &Arc<str>, line: u32, src: &str, diags: &mut Diagnostics) -> Vec<Token> {
    let chars: Vec<char> = src.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    let col = |i: usize| u32::try_from(i + 1).unwrap_or(u32::MAX);
    let len = |a: usize, b: usize| u32::try_from(b.saturating_sub(a)).unwrap_or(u32::MAX);
    while let Some(&c) = chars.get(i) {
        if is_space(c) {
            i += 1;
        } else if c == '#' || c == '$' {
            break;
        } else if c == '=' {
            tokens.push(Token {
                kind: Kind::Sep,
                text: "=".into(),
                lower: "=".into(),
                line,
                col: col(i),
                len: 1,
            });
            i += 1;
        } else if c == '"' {
            let start = i;
            i += 1;
            let body_start = i;
            while chars.get(i).is_some_and(|&c| c != '"') {
                i += 1;
            }
            let body: String = chars
                .get(body_start..i)
                .unwrap_or_default()
                .iter()
                .collect();
            if chars.get(i).is_none() {
                diags.push(
                    Diagnostic::error(codes::UNTERMINATED_STRING, "quoted string is not closed")
                        .at(Some(Loc::new(file, line, col(start), len(start, i))))
                        .help("add the closing `\"` on the same line"),
                );
            } else {
                i += 1;
            }
            tokens.push(Token {
                kind: Kind::Str,
                lower: body.to_lowercase(),
                text: body,
                line,
                col: col(start),
                len: len(start, i),
            });
        } else {
            let start = i;
            while chars.get(i).is_some_and(|&c| !ends_word(c)) {
                i += 1;
            }
            let text: String = chars.get(start..i).unwrap_or_default().iter().collect();
            let lower = text.to_lowercase();
            let kind = if lower == "is" || lower == "are" {
                Kind::Sep
            } else {
                Kind::Word
            };
            tokens.push(Token {
                kind,
                text,
                lower,
                line,
                col: col(start),
                len: len(start, i),
            });
        }
    }
    tokens
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(src: &str) -> (Vec<Line>, Diagnostics) {
        lex(&Arc::from("t.i"), src)
    }

    #[test]
    fn separators_comments_and_columns() {
        let (lines, d) =
            toks("  Normal Tolerance is 0.1, # note\n\n$ all comment\nA\tare  \"Lib.SO # x\"");
        assert!(d.is_empty());
        assert_eq!(lines.len(), 2);
        let l = &lines[0];
        assert_eq!(l.line, 1);
        let kinds: Vec<Kind> = l.tokens.iter().map(|t| t.kind).collect();
        assert_eq!(kinds, [Kind::Word, Kind::Word, Kind::Sep, Kind::Word]);
        assert_eq!((l.tokens[0].col, l.tokens[0].len), (3, 6));
        assert_eq!(l.tokens[3].text, "0.1");
        let l = &lines[1];
        assert_eq!(l.line, 4);
        assert_eq!(l.tokens[1].kind, Kind::Sep);
        assert_eq!(l.tokens[2].kind, Kind::Str);
        assert_eq!(l.tokens[2].text, "Lib.SO # x");
        assert_eq!((l.tokens[2].col, l.tokens[2].len), (8, 12));
    }

    #[test]
    fn equals_needs_no_spaces() {
        let (lines, _) = toks("a=b$c");
        let texts: Vec<&str> = lines[0].tokens.iter().map(|t| t.text.as_str()).collect();
        assert_eq!(texts, ["a", "=", "b"]);
    }

    #[test]
    fn unterminated_string_is_reported_with_its_column() {
        let (lines, d) = toks("x = \"abc");
        assert_eq!(d.len(), 1);
        assert_eq!(d.0[0].code, codes::UNTERMINATED_STRING);
        assert_eq!(d.0[0].loc.as_ref().map(|l| l.col), Some(5));
        assert_eq!(lines[0].tokens[2].text, "abc");
    }
}
