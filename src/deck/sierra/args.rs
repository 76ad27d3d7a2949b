//! The argument readers of a command line: words, numbers, names, switches, each
//! reporting rather than guessing when a value is missing or malformed.

use std::collections::HashSet;

use crate::deck::codes;
use crate::deck::lexer::Token;
use crate::diag::{Diagnostic, Loc, did_you_mean};

use super::{Cur, Lower, parse_number, value_text};

impl Lower {
    pub(super) fn missing(&mut self, c: &Cur, what: &str) {
        let at = match c.peek() {
            Some(t) => Some(t.loc(&self.file)),
            None => self.end_of(c.line),
        };
        let found = match c.peek() {
            Some(t) => format!(", found `{}`", t.text),
            None => String::new(),
        };
        self.push(
            Diagnostic::error(
                codes::MISSING_ARGUMENT,
                format!("`{}` expects {what}{found}", c.phrase()),
            )
            .at(at)
            .help(c.usage()),
        );
    }

    /// Consume the word `w` (lower case) or report it missing.
    pub(super) fn keyword(&mut self, c: &mut Cur, w: &str) -> bool {
        if c.peek().is_some_and(|t| t.is_word() && t.lower == w) {
            c.pos += 1;
            true
        } else {
            self.missing(c, &format!("`{w}`"));
            false
        }
    }

    pub(super) fn not_a_number(&mut self, c: &Cur, t: &Token, what: &str) {
        self.push(
            Diagnostic::error(
                codes::NOT_A_NUMBER,
                format!("`{}` expects {what}, found `{}`", c.phrase(), t.text),
            )
            .at(Some(t.loc(&self.file)))
            .help(c.usage()),
        );
    }

    /// The next token as a number; `what` says what kind (for example `a distance`).
    pub(super) fn number(&mut self, c: &mut Cur, what: &str) -> Option<(f64, Loc)> {
        match c.peek() {
            Some(t) if !t.is_sep() => {
                c.pos += 1;
                match parse_number(&t.text) {
                    Some(v) if t.is_word() => Some((v, t.loc(&self.file))),
                    _ => {
                        self.not_a_number(c, t, what);
                        None
                    }
                }
            }
            _ => {
                self.missing(c, what);
                None
            }
        }
    }

    pub(super) fn integer(&mut self, c: &mut Cur, what: &str) -> Option<(i64, Loc)> {
        match c.peek() {
            Some(t) if !t.is_sep() => {
                c.pos += 1;
                match t.text.parse::<i64>() {
                    Ok(v) if t.is_word() => Some((v, t.loc(&self.file))),
                    _ => {
                        self.not_a_number(c, t, what);
                        None
                    }
                }
            }
            _ => {
                self.missing(c, what);
                None
            }
        }
    }

    pub(super) fn count(&mut self, c: &mut Cur, what: &str) -> Option<(u32, Loc)> {
        let (v, at) = self.integer(c, what)?;
        match u32::try_from(v) {
            Ok(n) => Some((n, at)),
            Err(_) => {
                self.push(
                    Diagnostic::error(
                        codes::NOT_A_NUMBER,
                        format!("`{}` expects {what}, found `{v}`", c.phrase()),
                    )
                    .at(Some(at))
                    .help(c.usage()),
                );
                None
            }
        }
    }

    /// Every remaining token as a number; the span they cover.
    pub(super) fn numbers(&mut self, c: &mut Cur, what: &str) -> (Vec<f64>, Option<Loc>) {
        let start = c.pos;
        let mut v = Vec::new();
        while c.peek().is_some_and(|t| !t.is_sep()) {
            if let Some((x, _)) = self.number(c, what) {
                v.push(x);
            }
        }
        let at = self.span(c.line.tokens.get(start..c.pos).unwrap_or_default());
        (v, at)
    }

    pub(super) fn name(&mut self, c: &mut Cur, what: &str) -> Option<(String, Loc)> {
        match c.peek() {
            Some(t) if !t.is_sep() => {
                c.pos += 1;
                Some((value_text(t), t.loc(&self.file)))
            }
            _ => {
                self.missing(c, what);
                None
            }
        }
    }

    /// All remaining tokens as names; at least one.
    pub(super) fn names(&mut self, c: &mut Cur, what: &str) -> Vec<String> {
        let mut v = Vec::new();
        while let Some(t) = c.peek() {
            if t.is_sep() {
                break;
            }
            c.pos += 1;
            v.push(value_text(t));
        }
        if v.is_empty() {
            self.missing(c, what);
        }
        v
    }

    pub(super) fn switch(&mut self, c: &mut Cur) -> Option<bool> {
        let t = c.peek();
        let Some(t) = t.filter(|t| !t.is_sep()) else {
            self.missing(c, "`on` or `off`");
            return None;
        };
        c.pos += 1;
        match t.lower.as_str() {
            "on" | "true" | "yes" | "1" => Some(true),
            "off" | "false" | "no" | "0" => Some(false),
            other => {
                let hint = did_you_mean(other, ["on", "off"])
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                self.push(
                    Diagnostic::error(
                        codes::ON_OFF,
                        format!("`{}` is on or off, not `{}`", c.phrase(), t.text),
                    )
                    .at(Some(t.loc(&self.file)))
                    .help(format!("{hint}write `on` or `off`")),
                );
                None
            }
        }
    }

    /// An on/off switch that may be left out, as the manual's syntax lines do: alone
    /// it means on.
    pub(super) fn flag(&mut self, c: &mut Cur) -> Option<bool> {
        match c.peek() {
            None => Some(true),
            Some(_) => self.switch(c),
        }
    }

    /// Report anything left on the line.
    pub(super) fn finish(&mut self, c: &Cur) {
        let rest = c.rest();
        if rest.is_empty() {
            return;
        }
        let words: Vec<&str> = rest.iter().map(|t| t.text.as_str()).collect();
        self.push(
            Diagnostic::error(
                codes::EXTRA_WORDS,
                format!(
                    "unexpected `{}` at the end of `{}`",
                    words.join(" "),
                    c.phrase()
                ),
            )
            .at(self.span(rest))
            .help(c.usage()),
        );
    }

    /// Warn when a single-valued command repeats.
    pub(super) fn once(&mut self, seen: &mut HashSet<&'static str>, c: &Cur) {
        self.once_as(seen, c.cmd.key, c);
    }

    /// As [`Self::once`], counting `c` under `key` (so an alias and its canonical phrase
    /// count as the same command).
    pub(super) fn once_as(&mut self, seen: &mut HashSet<&'static str>, key: &'static str, c: &Cur) {
        if !seen.insert(key) {
            self.push(
                Diagnostic::warning(
                    codes::REPEATED_COMMAND,
                    format!("`{}` is given more than once in this block", c.phrase()),
                )
                .at(self.span(c.line.tokens.get(..c.n).unwrap_or_default()))
                .help("only the last one counts; remove the others"),
            );
        }
    }
}
