//! Stage three of the Sierra front end: the block tree → the typed [`Deck`].
//!
//! Entry point: [`lower`]. Each line is matched to a registry command (longest phrase);
//! its arguments are read with a small cursor that reports, rather than guesses, when a
//! word or number is missing or malformed. Semantic checks that the TOML form needs too
//! live in [`super::check`]; lowering records the exact location of each value it reads
//! in a [`Locs`] table so those checks can point at the offending token.
//!
//! Conventions: bare words are stored lower case, quoted strings as written; numbers
//! accept a Fortran `d` exponent (`1.5d3`); names after a command are single tokens;
//! a command's phrase may be spelled with `_` for spaces (ELFEN's `Buffer_factor`);
//! the `=` that Aria's syntax lines leave out is optional.
//!
//! A whole Sierra input file is recognised by its top level (see `is_sierra_file`):
//! its contact definitions are lowered as in a contact deck, its other blocks and lines
//! skipped and named in one W0103 warning. A region-level `begin toggle block` is
//! refused (E0226) when an enforcement uses it, and in a contact deck.
//!
//! Enforcement material-model lines: `gap conductance coefficient` stays a property
//! line (read by the conductance module); `contact surface pressure`, `offset
//! temperature` and `contact gap temperature` are lowered into their own fields; the
//! other models of Aria's list are kept as property lines that [`super::check`]
//! refuses, so the TOML form is refused the same way.

use std::collections::HashSet;
use std::sync::Arc;

use crate::diag::{Diagnostic, Diagnostics, Loc, did_you_mean};

use super::check::Locs;
use super::codes;
use super::lexer::{Line, Token, span};
use super::registry::{self, CommandSpec};
use super::spec::*;
use super::tree::{Block, Item};

const CD: &str = "contact_definition";
const ENF: &str = "enforcement";
const INT: &str = "interaction";
const DEF: &str = "interaction_defaults";
const SO: &str = "search_options";
const CS: &str = "contact_surface";

/// The lines a deck's contact input spans: `None` for a contact deck (all of it), the
/// `begin … end` line ranges of its contact definitions for a Sierra input file.
pub type ContactLines = Option<Vec<(u32, u32)>>;

/// Lower the top level of a file: a contact deck, or a whole Sierra input file (see
/// [`is_sierra_file`]) from which only the contact definitions are read.
pub fn lower(file: &Arc<str>, items: &[Item]) -> (Deck, Locs, Diagnostics, ContactLines) {
    let mut l = Lower {
        file: file.clone(),
        diags: Diagnostics::default(),
        locs: Locs::default(),
    };
    let mut deck = Deck::default();
    if is_sierra_file(items) {
        let mut skipped = Skipped::default();
        l.sierra_items(items, &mut deck, &mut skipped);
        l.report_skipped(items, &deck, &skipped);
        return (deck, l.locs, l.diags, Some(skipped.read));
    }
    for item in items {
        match item {
            Item::Block(b) => match b.spec {
                None if is_toggle_block(b) => l.toggle_block(b, None),
                None => l.unknown_tree(b),
                Some(s) if s.key == CD => {
                    let d = deck.contact_definitions.len();
                    let def = l.definition(d, b);
                    deck.contact_definitions.push(def);
                }
                Some(_) => l.misplaced(b, registry::TOP),
            },
            Item::Line(line) => l.top_line(line),
        }
    }
    (deck, l.locs, l.diags, None)
}

/// A whole Sierra input file rather than a contact deck: it has a top-level block of a
/// type seam does not know that is `begin sierra` or holds a contact definition
/// (`begin procedure … begin aria region … begin contact definition`).
fn is_sierra_file(items: &[Item]) -> bool {
    items.iter().any(|i| match i {
        Item::Block(b) if b.spec.is_none() => {
            b.type_tokens().first().is_some_and(|t| t.lower == "sierra") || holds_definition(b)
        }
        _ => false,
    })
}

/// Does a contact definition sit in `b`, directly or inside blocks of unknown type?
fn holds_definition(b: &Block) -> bool {
    b.items.iter().any(|i| match i {
        Item::Block(s) => match s.spec {
            Some(spec) => spec.key == CD,
            None => holds_definition(s),
        },
        Item::Line(_) => false,
    })
}

/// `begin toggle block <name>`: Aria's region-level toggle.
fn is_toggle_block(b: &Block) -> bool {
    let words: Vec<&str> = b.type_tokens().iter().map(|t| t.lower.as_str()).collect();
    words.starts_with(&["toggle", "block"])
}

/// `begin` and the words after it, lower case: `finite element model mesh1`.
fn block_title(b: &Block) -> String {
    let words: Vec<String> = b.head.tokens.iter().skip(1).map(value_text).collect();
    words.join(" ")
}

/// What a Sierra input file held besides contact definitions.
#[derive(Default)]
struct Skipped {
    /// Titles of the skipped blocks (outermost only), in file order.
    blocks: Vec<String>,
    /// Lines outside every contact definition.
    lines: usize,
    /// Toggle blocks: name (lower case) and `begin` line.
    toggles: Vec<(String, Loc)>,
    /// The `begin` and `end` lines of the contact definitions read.
    read: Vec<(u32, u32)>,
}

/// What a line turned out to be.
enum Matched<'a> {
    Command(Cur<'a>),
    /// Not usable here; a diagnostic has been pushed.
    Reported,
}

/// Arguments of one command line, read left to right.
struct Cur<'a> {
    cmd: &'static CommandSpec,
    line: &'a Line,
    /// Index of the next unread token.
    pos: usize,
    /// Number of tokens the command phrase took.
    n: usize,
}

impl<'a> Cur<'a> {
    fn peek(&self) -> Option<&'a Token> {
        self.line.tokens.get(self.pos)
    }

    fn bump(&mut self) -> Option<&'a Token> {
        let t = self.line.tokens.get(self.pos);
        if t.is_some() {
            self.pos += 1;
        }
        t
    }

    fn skip_sep(&mut self) {
        if self.peek().is_some_and(Token::is_sep) {
            self.pos += 1;
        }
    }

    /// In a list of values: a token the reader refused without consuming (a stray
    /// separator, already reported) is passed over, so the list's loop always ends.
    fn pass_reported(&mut self, before: usize) {
        if self.pos == before {
            self.pos += 1;
        }
    }

    fn rest(&self) -> &'a [Token] {
        self.line.tokens.get(self.pos..).unwrap_or_default()
    }

    fn phrase(&self) -> &'static str {
        self.cmd.phrase
    }

    fn usage(&self) -> String {
        if self.cmd.args.is_empty() {
            format!("write `{}` alone", self.cmd.phrase)
        } else {
            format!("write `{} {}`", self.cmd.phrase, self.cmd.args)
        }
    }
}

/// A number as Sierra writes it: `1.5`, `2e-3`, `1.5d3`; finite only.
pub fn parse_number(s: &str) -> Option<f64> {
    let v: f64 = s
        .parse()
        .ok()
        .or_else(|| s.replace(['d', 'D'], "e").parse().ok())?;
    v.is_finite().then_some(v)
}

fn value_text(t: &Token) -> String {
    match t.kind {
        super::lexer::Kind::Str => t.text.clone(),
        _ => t.lower.clone(),
    }
}

struct Lower {
    file: Arc<str>,
    diags: Diagnostics,
    locs: Locs,
}

impl Lower {
    fn span(&self, tokens: &[Token]) -> Option<Loc> {
        span(&self.file, tokens)
    }

    fn line_loc(&self, line: &Line) -> Loc {
        self.span(&line.tokens).unwrap_or_default()
    }

    /// Just past the last token of the line, for "missing …" messages.
    fn end_of(&self, line: &Line) -> Option<Loc> {
        let last = line.tokens.last()?;
        Some(Loc::new(
            &self.file,
            last.line,
            last.col.saturating_add(last.len).saturating_add(1),
            1,
        ))
    }

    fn push(&mut self, d: Diagnostic) {
        self.diags.push(d);
    }

    // ----- structure -----

    /// Report the unknown block types in `b` and below (a block that is not read).
    fn unknown_tree(&mut self, b: &Block) {
        if let Some(d) = &b.unknown {
            self.push(d.clone());
        }
        for item in &b.items {
            if let Item::Block(sub) = item {
                self.unknown_tree(sub);
            }
        }
    }

    /// A `begin toggle block`: in a contact deck an error; in a Sierra input file noted,
    /// and an error only if an enforcement uses it (see [`Self::report_skipped`]).
    fn toggle_block(&mut self, b: &Block, skipped: Option<&mut Skipped>) {
        let name = b.head.tokens.get(3).map(value_text).unwrap_or_default();
        match skipped {
            Some(s) => {
                s.blocks.push(block_title(b));
                s.toggles.push((name, self.line_loc(&b.head)));
            }
            None => self.push(
                Diagnostic::error(
                    codes::TOGGLE_BLOCK,
                    format!("seam cannot read the schedule of `begin toggle block {name}`"),
                )
                .at(self.span(b.type_tokens()))
                .help(format!(
                    "remove the block and give the schedule in the problem file: `[[toggle]]` with `name = \"{name}\"` and `on = [[t0, t1]]`; `use toggle block {name}` in an enforcement then follows it"
                )),
            ),
        }
    }

    /// The items of a Sierra input file (or of a block in it): contact definitions are
    /// read, blocks holding one are entered, everything else is skipped.
    fn sierra_items(&mut self, items: &[Item], deck: &mut Deck, skipped: &mut Skipped) {
        for item in items {
            let b = match item {
                Item::Line(_) => {
                    skipped.lines += 1;
                    continue;
                }
                Item::Block(b) => b,
            };
            match b.spec {
                Some(s) if s.key == CD => {
                    let d = deck.contact_definitions.len();
                    let def = self.definition(d, b);
                    deck.contact_definitions.push(def);
                    skipped.read.push((b.head.line, b.end_line));
                }
                Some(_) => skipped.blocks.push(block_title(b)),
                None if is_toggle_block(b) => self.toggle_block(b, Some(skipped)),
                None if holds_definition(b) => self.sierra_items(&b.items, deck, skipped),
                None => {
                    // A misspelt contact definition is reported, not skipped.
                    let words: Vec<&str> = b
                        .type_tokens()
                        .iter()
                        .take(2)
                        .map(|t| t.lower.as_str())
                        .collect();
                    if did_you_mean(&words.join(" "), ["contact definition"]).is_some() {
                        self.unknown_tree(b);
                    } else {
                        skipped.blocks.push(block_title(b));
                    }
                }
            }
        }
    }

    /// The one note on what a Sierra input file held besides contact input, and the
    /// toggle blocks that enforcements use but seam cannot read.
    fn report_skipped(&mut self, items: &[Item], deck: &Deck, skipped: &Skipped) {
        for (d, def) in deck.contact_definitions.iter().enumerate() {
            for (k, e) in def.enforcements.iter().enumerate() {
                let Some(name) = &e.use_toggle_block else {
                    continue;
                };
                let Some((_, at)) = skipped.toggles.iter().find(|(t, _)| t == name) else {
                    continue;
                };
                let used = self
                    .locs
                    .get(&format!("{d}.enforcement.{k}.use_toggle_block"))
                    .or_else(|| Some(e.at.clone()));
                self.push(
                    Diagnostic::error(
                        codes::TOGGLE_BLOCK,
                        format!(
                            "toggle block `{name}` (line {}) is used here, but seam cannot read a toggle block's schedule",
                            at.line
                        ),
                    )
                    .at(used)
                    .help(format!(
                        "give the schedule in the problem file (`[[toggle]]` with `name = \"{name}\"` and `on = [[t0, t1]]`) and remove `begin toggle block {name}` from the file given to seam"
                    )),
                );
            }
        }
        if skipped.blocks.is_empty() && skipped.lines == 0 {
            return;
        }
        let n = deck.contact_definitions.len();
        let mut message = format!(
            "read {n} contact definition{} from a Sierra input file; skipped ",
            if n == 1 { "" } else { "s" }
        );
        let b = skipped.blocks.len();
        if b > 0 {
            message.push_str(&format!(
                "{b} block{}: {}",
                if b == 1 { "" } else { "s" },
                skipped.blocks.join(", ")
            ));
        }
        if skipped.lines > 0 {
            message.push_str(&format!(
                "{}{} line{} outside them",
                if b > 0 { ", and " } else { "" },
                skipped.lines,
                if skipped.lines == 1 { "" } else { "s" }
            ));
        }
        let at = items.iter().find_map(|i| match i {
            Item::Block(b) => self.span(&b.head.tokens),
            Item::Line(l) => self.span(&l.tokens),
        });
        self.push(
            Diagnostic::warning(codes::SKIPPED_BLOCKS, message)
                .at(at)
                .help("seam reads the `begin contact definition` blocks only; the rest is other input of the Sierra run"),
        );
    }

    fn top_line(&mut self, line: &Line) {
        let words = leading_words(line);
        if let Some(cmd) = registry::match_command(&words) {
            let n = registry::word_count(cmd.phrase);
            let at = self.span(line.tokens.get(..n).unwrap_or_default());
            let homes = homes(cmd);
            self.push(
                Diagnostic::error(
                    codes::WRONG_BLOCK,
                    format!("`{}` must be inside a block", cmd.phrase),
                )
                .at(at)
                .help(format!("it belongs in {homes}")),
            );
        } else {
            self.push(
                Diagnostic::error(
                    codes::OUTSIDE_BLOCK,
                    "this line is outside every block".to_string(),
                )
                .at(self.span(&line.tokens))
                .help("contact input goes inside `begin contact definition` … `end`"),
            );
        }
    }

    fn misplaced(&mut self, b: &Block, parent: &str) {
        let Some(spec) = b.spec else {
            self.unknown_tree(b);
            return;
        };
        for item in &b.items {
            if let Item::Block(sub) = item {
                self.unknown_tree(sub);
            }
        }
        let here = match registry::block(parent) {
            Some(p) => format!("inside `begin {}`", p.phrase),
            None => "at the top level".to_string(),
        };
        self.push(
            Diagnostic::error(
                codes::MISPLACED_BLOCK,
                format!("`begin {}` may not appear {here}", spec.phrase),
            )
            .at(self.span(b.type_tokens()))
            .help(format!(
                "it belongs {}",
                match registry::block(spec.parent) {
                    Some(p) => format!("inside `begin {}`", p.phrase),
                    None => "at the top level".to_string(),
                }
            )),
        );
    }

    /// Check the block's name against its naming rule; the name, lower case.
    fn block_name(&mut self, b: &Block) -> Option<String> {
        let spec = b.spec?;
        match (spec.naming, b.name.len()) {
            (registry::Naming::Required, 0) => {
                self.push(
                    Diagnostic::error(
                        codes::BLOCK_NAME,
                        format!("`begin {}` needs a name", spec.phrase),
                    )
                    .at(self.span(b.type_tokens()))
                    .help(format!("write `begin {} <name>`", spec.phrase)),
                );
                None
            }
            (registry::Naming::Forbidden, n) if n > 0 => {
                self.push(
                    Diagnostic::error(
                        codes::BLOCK_NAME,
                        format!("`begin {}` takes no name", spec.phrase),
                    )
                    .at(self.span(&b.name))
                    .help(format!("write `begin {}` alone", spec.phrase)),
                );
                None
            }
            (_, n) if n > 1 => {
                self.push(
                    Diagnostic::error(
                        codes::BLOCK_NAME,
                        format!("a `{}` name is one word", spec.phrase),
                    )
                    .at(self.span(&b.name))
                    .help("join the words with `_`, or quote the name"),
                );
                b.name.first().map(value_text)
            }
            _ => b.name.first().map(value_text),
        }
    }

    /// Match a line to a command allowed in `block`; report it otherwise.
    fn command<'a>(&mut self, block: &str, line: &'a Line) -> Matched<'a> {
        let words = leading_words(line);
        // Another block's command is misplaced only if it is the whole of what comes
        // before the first separator (`surface emissivity = …` is no `surface` line).
        let before_sep = line.tokens.iter().position(Token::is_sep);
        let found = registry::match_tokens(&words, block)
            .filter(|(cmd, n)| cmd.blocks.contains(&block) || before_sep.is_none_or(|p| *n >= p));
        if let Some((cmd, n)) = found {
            if cmd.blocks.contains(&block) {
                return Matched::Command(Cur {
                    cmd,
                    line,
                    pos: n,
                    n,
                });
            }
            let at = self.span(line.tokens.get(..n).unwrap_or_default());
            let here = registry::describe_block(block);
            self.push(
                Diagnostic::error(
                    codes::WRONG_BLOCK,
                    format!("`{}` is not allowed in {here}", cmd.phrase),
                )
                .at(at)
                .help(format!("it belongs in {}", homes(cmd))),
            );
            return Matched::Reported;
        }
        if let Some(first) = line.tokens.first().filter(|t| t.is_word())
            && let Some((_, why)) = registry::elfen_refused(&first.lower)
        {
            self.push(
                Diagnostic::error(
                    codes::ELFEN_REFUSED,
                    format!(
                        "`{}` is an ELFEN contact-set parameter with no counterpart in seam",
                        first.text
                    ),
                )
                .at(Some(first.loc(&self.file)))
                .help(format!("in ELFEN it sets {why}; remove the line")),
            );
            return Matched::Reported;
        }
        let allowed = registry::phrases_in(block);
        let mut suggestion = registry::suggest(&words, &allowed);
        // `Buffer_factr = 2`: compare the words of the first token, blame the token.
        if suggestion.is_none()
            && let Some(first) = words.first().filter(|w| w.contains('_'))
        {
            let split: Vec<&str> = first.split('_').filter(|w| !w.is_empty()).collect();
            suggestion = registry::suggest(&split, &allowed)
                .filter(|&(_, k)| k == split.len())
                .map(|(p, _)| (p, 1));
        }
        let n_words = match suggestion {
            Some((_, k)) => k,
            None => words.len().max(1),
        };
        let at = self.span(line.tokens.get(..n_words).unwrap_or_default());
        let written: Vec<&str> = words.iter().take(n_words).copied().collect();
        let written = if written.is_empty() {
            line.tokens
                .first()
                .map(|t| t.text.clone())
                .unwrap_or_default()
        } else {
            written.join(" ")
        };
        let mut help = match suggestion {
            Some((p, _)) => format!("did you mean `{p}`? "),
            None => String::new(),
        };
        help.push_str(&format!(
            "{} accepts {}",
            registry::describe_block(block),
            registry::accepted_in(block)
        ));
        self.push(
            Diagnostic::error(
                codes::UNKNOWN_KEYWORD,
                format!(
                    "unknown keyword `{written}` in {}",
                    registry::describe_block(block)
                ),
            )
            .at(at)
            .help(help),
        );
        Matched::Reported
    }

    // ----- argument readers -----

    fn missing(&mut self, c: &Cur, what: &str) {
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
    fn keyword(&mut self, c: &mut Cur, w: &str) -> bool {
        if c.peek().is_some_and(|t| t.is_word() && t.lower == w) {
            c.pos += 1;
            true
        } else {
            self.missing(c, &format!("`{w}`"));
            false
        }
    }

    fn not_a_number(&mut self, c: &Cur, t: &Token, what: &str) {
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
    fn number(&mut self, c: &mut Cur, what: &str) -> Option<(f64, Loc)> {
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

    fn integer(&mut self, c: &mut Cur, what: &str) -> Option<(i64, Loc)> {
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

    fn count(&mut self, c: &mut Cur, what: &str) -> Option<(u32, Loc)> {
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
    fn numbers(&mut self, c: &mut Cur, what: &str) -> (Vec<f64>, Option<Loc>) {
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

    fn name(&mut self, c: &mut Cur, what: &str) -> Option<(String, Loc)> {
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
    fn names(&mut self, c: &mut Cur, what: &str) -> Vec<String> {
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

    fn switch(&mut self, c: &mut Cur) -> Option<bool> {
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
    fn flag(&mut self, c: &mut Cur) -> Option<bool> {
        match c.peek() {
            None => Some(true),
            Some(_) => self.switch(c),
        }
    }

    /// Report anything left on the line.
    fn finish(&mut self, c: &Cur) {
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
    fn once(&mut self, seen: &mut HashSet<&'static str>, c: &Cur) {
        self.once_as(seen, c.cmd.key, c);
    }

    /// As [`Self::once`], counting `c` under `key` (so an alias and its canonical phrase
    /// count as the same command).
    fn once_as(&mut self, seen: &mut HashSet<&'static str>, key: &'static str, c: &Cur) {
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

    // ----- blocks -----

    fn definition(&mut self, d: usize, b: &Block) -> ContactDefinition {
        let mut cd = ContactDefinition {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for item in &b.items {
            match item {
                Item::Block(sub) => self.definition_block(d, &mut cd, sub),
                Item::Line(line) => {
                    if let Matched::Command(mut c) = self.command(CD, line) {
                        self.definition_line(d, &mut cd, &mut c, &mut seen);
                        self.finish(&c);
                    }
                }
            }
        }
        cd
    }

    fn definition_block(&mut self, d: usize, cd: &mut ContactDefinition, sub: &Block) {
        let Some(spec) = sub.spec else {
            if is_toggle_block(sub) {
                self.toggle_block(sub, None);
            } else {
                self.unknown_tree(sub);
            }
            return;
        };
        if spec.parent != CD {
            self.misplaced(sub, CD);
            return;
        }
        let twice = |what: &str, l: &mut Lower| {
            l.push(
                Diagnostic::error(
                    codes::DUPLICATE_BLOCK,
                    format!("a second `begin {what}` in one contact definition"),
                )
                .at(l.span(sub.type_tokens()))
                .help("merge the two blocks into one"),
            );
        };
        match spec.key {
            ENF => {
                let k = cd.enforcements.len();
                let e = self.enforcement(d, k, sub);
                cd.enforcements.push(e);
            }
            INT => {
                let i = cd.interactions.len();
                let x = self.interaction(d, i, sub);
                cd.interactions.push(x);
            }
            DEF => {
                let x = self.defaults(d, sub);
                if cd.interaction_defaults.is_some() {
                    twice(spec.phrase, self);
                } else {
                    cd.interaction_defaults = Some(x);
                }
            }
            SO => {
                let x = self.search_options(d, sub);
                if cd.search_options.is_some() {
                    twice(spec.phrase, self);
                } else {
                    cd.search_options = Some(x);
                }
            }
            CS => {
                let s = cd.surfaces.len();
                let x = self.surface_block(d, s, sub);
                cd.surfaces.push(SurfaceDef::Block(x));
            }
            _ => self.misplaced(sub, CD),
        }
    }

    fn definition_line(
        &mut self,
        d: usize,
        cd: &mut ContactDefinition,
        c: &mut Cur,
        seen: &mut HashSet<&'static str>,
    ) {
        let at = self.line_loc(c.line);
        match c.cmd.key {
            "contact_surface" | "contact_node_set" => {
                let Some((name, name_at)) = self.name(c, "a surface name") else {
                    return;
                };
                // Without `contains`, the mesh entity of the surface's own name.
                let contains = if c.peek().is_none() {
                    vec![name.clone()]
                } else {
                    if !self.keyword(c, "contains") {
                        return;
                    }
                    c.skip_sep();
                    self.names(c, "the names it contains")
                };
                self.locs
                    .set(format!("{d}.surface.{}.name", cd.surfaces.len()), name_at);
                cd.surfaces.push(if c.cmd.key == "contact_surface" {
                    SurfaceDef::Contains { name, contains, at }
                } else {
                    SurfaceDef::NodeSet { name, contains, at }
                });
            }
            "skin_all_blocks" => {
                c.skip_sep();
                // Alone, or with `exclude` only, as the Aria manual writes it: on.
                let on = match c.peek() {
                    None => true,
                    Some(t) if t.is_word() && t.lower == "exclude" => true,
                    Some(_) => match self.switch(c) {
                        Some(on) => on,
                        None => return,
                    },
                };
                let mut exclude = Vec::new();
                if c.peek().is_some_and(|t| t.lower == "exclude") {
                    c.pos += 1;
                    c.skip_sep();
                    exclude = self.names(c, "the blocks to exclude");
                }
                if on {
                    cd.surfaces.push(SurfaceDef::SkinAllBlocks { exclude, at });
                }
            }
            "restrict_contact_to_subdomain" => {
                self.once(seen, c);
                if !(self.keyword(c, "defined")
                    && self.keyword(c, "by")
                    && self.keyword(c, "radius"))
                {
                    return;
                }
                c.skip_sep();
                let Some((radius, radius_at)) = self.number(c, "a radius") else {
                    return;
                };
                self.locs.set(
                    format!("{d}.restrict_contact_to_subdomain.radius"),
                    radius_at,
                );
                if !(self.keyword(c, "and") && self.keyword(c, "point")) {
                    return;
                }
                c.skip_sep();
                let (p, p_at) = self.numbers(c, "a coordinate");
                if let Some(l) = &p_at {
                    self.locs.set(
                        format!("{d}.restrict_contact_to_subdomain.point"),
                        l.clone(),
                    );
                }
                match <[f64; 3]>::try_from(p.as_slice()) {
                    Ok(point) => {
                        cd.restrict_contact_to_subdomain = Some(Subdomain { radius, point })
                    }
                    Err(_) if p_at.is_none() => self.missing(c, "a point `x y z`"),
                    Err(_) => self.push(
                        Diagnostic::error(
                            codes::VALUE_COUNT,
                            format!("the subdomain point needs 3 coordinates, found {}", p.len()),
                        )
                        .at(p_at)
                        .help(c.usage()),
                    ),
                }
            }
            "visualize_contact" => {
                self.once(seen, c);
                c.skip_sep();
                cd.visualize_contact = if c.peek().is_some() {
                    self.switch(c).unwrap_or(false)
                } else {
                    true
                };
            }
            "output_rule" => {
                self.once(seen, c);
                c.skip_sep();
                let rest = c.rest();
                c.pos = c.line.tokens.len();
                let words: Vec<String> = rest.iter().map(|t| t.lower.replace('_', " ")).collect();
                let value = words.join(" ");
                let rule = match value.as_str() {
                    "none" => Some(OutputRule::None),
                    "summary" => Some(OutputRule::Summary),
                    "verbose" => Some(OutputRule::Verbose),
                    "more verbose" => Some(OutputRule::MoreVerbose),
                    _ => None,
                };
                match rule {
                    Some(r) => cd.output_rule = Some(r),
                    None if rest.is_empty() => self.missing(c, "a rule"),
                    None => {
                        let choices = ["none", "summary", "verbose", "more verbose"];
                        let hint = did_you_mean(&value, choices)
                            .map(|s| format!("did you mean `{s}`? "))
                            .unwrap_or_default();
                        self.push(
                            Diagnostic::error(
                                codes::OUTPUT_RULE,
                                format!("unknown output rule `{value}`"),
                            )
                            .at(self.span(rest))
                            .help(format!(
                                "{hint}the rules are `none`, `summary`, `verbose`, `more verbose`"
                            )),
                        );
                    }
                }
            }
            "update_search_every_n_steps" => {
                self.once(seen, c);
                c.skip_sep();
                if let Some((n, n_at)) = self.count(c, "a whole number of steps") {
                    cd.update_search_every_n_steps = Some(n);
                    self.locs
                        .set(format!("{d}.update_search_every_n_steps"), n_at);
                }
                if c.peek()
                    .is_some_and(|t| t.lower == "steps" || t.lower == "step")
                {
                    c.pos += 1;
                }
            }
            "opposed_normal_threshold_angle" => {
                self.once(seen, c);
                c.skip_sep();
                if let Some((a, a_at)) = self.number(c, "an angle in degrees") {
                    cd.opposed_normal_threshold_angle = Some(a);
                    self.locs
                        .set(format!("{d}.opposed_normal_threshold_angle"), a_at);
                }
            }
            "disable_opposed_normal_interaction_culling" => {
                self.once(seen, c);
                cd.disable_opposed_normal_interaction_culling = true;
            }
            "scale_penalty" | "initial_overclosure" => {
                let k = cd.control_assignments.len();
                if let Some((x, value_at)) = self.control_assignment(c, at) {
                    if let Some(l) = value_at {
                        self.locs
                            .set(format!("{d}.control_assignment.{k}.factor"), l);
                    }
                    cd.control_assignments.push(x);
                }
            }
            "periodicity" => {
                let p = cd.periodicity.len();
                if let Some(x) = self.periodicity(d, p, c) {
                    cd.periodicity.push(x);
                }
            }
            _ => {}
        }
    }

    /// `<phrase> [for s1 [with s2]] = value`.
    fn control_assignment(
        &mut self,
        c: &mut Cur,
        at: Loc,
    ) -> Option<(ControlAssignment, Option<Loc>)> {
        let mut surface_1 = None;
        let mut surface_2 = None;
        if c.peek().is_some_and(|t| t.is_word() && t.lower == "for") {
            c.pos += 1;
            surface_1 = Some(self.name(c, "a surface name")?.0);
            if c.peek().is_some_and(|t| t.is_word() && t.lower == "with") {
                c.pos += 1;
                surface_2 = Some(self.name(c, "a second surface name")?.0);
            }
        }
        if !c.peek().is_some_and(Token::is_sep) {
            self.missing(c, "`=` and a value");
            return None;
        }
        c.skip_sep();
        let mut value_at = None;
        let control = if c.cmd.key == "scale_penalty" {
            let (factor, f_at) = self.number(c, "a penalty scale factor")?;
            value_at = Some(f_at);
            Control::ScalePenalty { factor }
        } else {
            let rest: Vec<String> = c.rest().iter().map(|t| t.lower.clone()).collect();
            let treatment = match rest.join(" ").as_str() {
                "adjust nodes" | "adjust" => Overclosure::AdjustNodes,
                "store offsets" | "store offset" | "offsets" => Overclosure::StoreOffsets,
                other => {
                    let hint = did_you_mean(other, ["adjust nodes", "store offsets"])
                        .map(|s| format!("did you mean `{s}`? "))
                        .unwrap_or_default();
                    self.push(
                        Diagnostic::error(
                            codes::BAD_CHOICE,
                            format!("unknown overclosure treatment `{other}`"),
                        )
                        .at(self.span(c.rest()))
                        .help(format!(
                            "{hint}the choices are `adjust nodes` and `store offsets`"
                        )),
                    );
                    c.pos = c.line.tokens.len();
                    return None;
                }
            };
            c.pos = c.line.tokens.len();
            Control::InitialOverclosure { treatment }
        };
        Some((
            ControlAssignment {
                surface_1,
                surface_2,
                control,
                at,
            },
            value_at,
        ))
    }

    fn periodicity(&mut self, d: usize, p: usize, c: &mut Cur) -> Option<Periodicity> {
        let at = self.line_loc(c.line);
        let (surface, _) = self.name(c, "a surface name")?;
        c.skip_sep();
        let kinds = ["rectangular", "cylindrical", "align_surface", "mapped"];
        let Some(kind_tok) = c.peek().filter(|t| !t.is_sep()) else {
            self.missing(
                c,
                "a transform (`rectangular`, `cylindrical`, `align_surface` or `mapped`)",
            );
            return None;
        };
        c.pos += 1;
        let kind = kind_tok.lower.as_str();
        let usage = match kind {
            "rectangular" => "rectangular offset = <dx> <dy> [<dz>]",
            "cylindrical" => {
                "cylindrical axis = <a1> <a2> [<a3>] center = <c1> <c2> [<c3>] angle = <degrees>"
            }
            "align_surface" => "align_surface destination = <surface> [invert_normals = 0|1]",
            _ => "mapped [x_map = <f>] [y_map = <g>] [z_map = <h>]",
        };
        let usage = format!("write `periodicity for {surface} {usage}`");
        let allowed: &[&str] = match kind {
            "rectangular" => &["offset"],
            "cylindrical" => &["axis", "center", "angle"],
            "align_surface" => &["destination", "invert_normals"],
            "mapped" => &["x_map", "y_map", "z_map"],
            _ => {
                let hint = did_you_mean(kind, kinds)
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                self.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("unknown periodicity transform `{}`", kind_tok.text),
                    )
                    .at(Some(kind_tok.loc(&self.file)))
                    .help(format!(
                        "{hint}the transforms are `rectangular`, `cylindrical`, `align_surface`, `mapped`"
                    )),
                );
                c.pos = c.line.tokens.len();
                return None;
            }
        };
        // `key = values…` groups: a key is a word followed by a separator.
        let rest = c.rest();
        c.pos = c.line.tokens.len();
        let mut groups: Vec<(&Token, Vec<&Token>)> = Vec::new();
        let mut i = 0;
        let mut ok = true;
        while let Some(t) = rest.get(i) {
            let keyed = rest.get(i + 1).is_some_and(Token::is_sep) && !t.is_sep();
            if keyed {
                groups.push((t, Vec::new()));
                i += 2;
            } else if let (Some(g), false) = (groups.last_mut(), t.is_sep()) {
                g.1.push(t);
                i += 1;
            } else {
                self.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("unexpected `{}` in the `{kind}` periodicity", t.text),
                    )
                    .at(Some(t.loc(&self.file)))
                    .help(usage.clone()),
                );
                ok = false;
                i += 1;
            }
        }
        let mut nums = |l: &mut Lower, key: &str| -> Option<Vec<f64>> {
            if !allowed.contains(&key) {
                return None; // reported below as not a part of this transform
            }
            let (_, vals) = groups.iter().find(|(k, _)| k.lower == key)?;
            let mut v = Vec::new();
            for t in vals {
                match parse_number(&t.text).filter(|_| t.is_word()) {
                    Some(x) => v.push(x),
                    None => {
                        l.not_a_number(c, t, &format!("numbers after `{key} =`"));
                        ok = false;
                    }
                }
            }
            let toks: Vec<Token> = vals.iter().map(|t| (*t).clone()).collect();
            if let Some(at) = l.span(&toks) {
                l.locs.set(format!("{d}.periodicity.{p}.{key}"), at);
            }
            Some(v)
        };
        let offset = nums(self, "offset");
        let axis = nums(self, "axis");
        let center = nums(self, "center");
        let angle = nums(self, "angle");
        let text = |key: &str| -> Option<String> {
            let (_, vals) = groups.iter().find(|(k, _)| k.lower == key)?;
            let words: Vec<&str> = vals.iter().map(|t| t.text.as_str()).collect();
            Some(words.join(" "))
        };
        for (k, _) in &groups {
            if !allowed.contains(&k.lower.as_str()) {
                let hint = did_you_mean(&k.lower, allowed.iter().copied())
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                let list: Vec<String> = allowed.iter().map(|a| format!("`{a}`")).collect();
                self.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("`{}` is not a part of the `{kind}` periodicity", k.text),
                    )
                    .at(Some(k.loc(&self.file)))
                    .help(format!(
                        "{hint}the `{kind}` periodicity takes {}",
                        list.join(", ")
                    )),
                );
                ok = false;
            }
        }
        let need = |l: &mut Lower, key: &str, present: bool| {
            if !present {
                l.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("the `{kind}` periodicity needs `{key} = …`"),
                    )
                    .at(Some(kind_tok.loc(&l.file)))
                    .help(usage.clone()),
                );
            }
            present
        };
        let transform = match kind {
            "rectangular" => {
                need(self, "offset", offset.is_some()).then_some(())?;
                PeriodicTransform::Rectangular {
                    offset: offset.unwrap_or_default(),
                }
            }
            "cylindrical" => {
                let all = need(self, "axis", axis.is_some())
                    & need(self, "center", center.is_some())
                    & need(self, "angle", angle.is_some());
                all.then_some(())?;
                let angle = angle.unwrap_or_default();
                let Some(&a) = angle.first().filter(|_| angle.len() == 1) else {
                    self.push(
                        Diagnostic::error(
                            codes::VALUE_COUNT,
                            format!("`angle` takes one value, found {}", angle.len()),
                        )
                        .at(self.locs.get(&format!("{d}.periodicity.{p}.angle")))
                        .help("write the rotation angle in degrees, e.g. `angle = 90`"),
                    );
                    return None;
                };
                PeriodicTransform::Cylindrical {
                    axis: axis.unwrap_or_default(),
                    center: center.unwrap_or_default(),
                    angle: a,
                }
            }
            "align_surface" => {
                let dest = text("destination");
                need(self, "destination", dest.is_some()).then_some(())?;
                let invert = match text("invert_normals").map(|s| s.to_lowercase()) {
                    None => true,
                    Some(v) => match v.as_str() {
                        "1" | "on" | "true" | "yes" => true,
                        "0" | "off" | "false" | "no" => false,
                        _ => {
                            self.push(
                                Diagnostic::error(
                                    codes::ON_OFF,
                                    format!("`invert_normals` is 0 or 1, not `{v}`"),
                                )
                                .at(groups
                                    .iter()
                                    .find(|(k, _)| k.lower == "invert_normals")
                                    .and_then(|(k, vals)| vals.first().copied().or(Some(*k)))
                                    .map(|t| t.loc(&self.file)))
                                .help("write `invert_normals = 0` to keep the normals as they are"),
                            );
                            return None;
                        }
                    },
                };
                PeriodicTransform::AlignSurface {
                    destination: dest.unwrap_or_default().to_lowercase(),
                    invert_normals: invert,
                }
            }
            _ => PeriodicTransform::Mapped {
                // A map left out is the identity (Aria manual: "functions that are not
                // specified default to a trivial mapping").
                x_map: text("x_map").unwrap_or_else(|| "x".to_string()),
                y_map: text("y_map").unwrap_or_else(|| "y".to_string()),
                z_map: text("z_map"),
            },
        };
        ok.then_some(Periodicity {
            surface,
            transform,
            at,
        })
    }

    fn enforcement(&mut self, d: usize, k: usize, b: &Block) -> Enforcement {
        let mut e = Enforcement {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        // The first pressure line: its phrase and line, for `contact pressure` and
        // `contact surface pressure` in one block.
        let mut pressure_from: Option<(&'static str, u32)> = None;
        for item in &b.items {
            let line = match item {
                Item::Block(sub) => {
                    self.misplaced(sub, ENF);
                    continue;
                }
                Item::Line(line) => line,
            };
            let mut c = match self.command(ENF, line) {
                Matched::Command(c) => c,
                Matched::Reported => continue,
            };
            let at = self.line_loc(line);
            if let registry::Status::Refused(_) = c.cmd.status {
                // Kept as a property line: the semantic check refuses it, for both forms.
                let p = self.property(&mut c);
                e.properties.push(p);
                continue;
            }
            match c.cmd.key {
                "model" => {
                    let eq = self.name(&mut c, "an equation name");
                    let Some((equation, eq_at)) = eq else {
                        continue;
                    };
                    c.skip_sep();
                    let Some((model, _)) = self.name(&mut c, "a model name") else {
                        continue;
                    };
                    let m = e.models.len();
                    self.locs
                        .set(format!("{d}.enforcement.{k}.model.{m}.equation"), eq_at);
                    let (args, arg_locs) = self.args(&c, c.rest());
                    for (a, l) in arg_locs.into_iter().enumerate() {
                        self.locs
                            .set(format!("{d}.enforcement.{k}.model.{m}.arg.{a}"), l);
                    }
                    c.pos = line.tokens.len();
                    e.models.push(EnforcementModel {
                        equation,
                        model,
                        args,
                        at,
                    });
                }
                "gap_conductance_coefficient" => {
                    let p = self.property(&mut c);
                    e.properties.push(p);
                }
                "integer_data" => {
                    c.skip_sep();
                    while c.peek().is_some() {
                        let before = c.pos;
                        if let Some((v, _)) = self.integer(&mut c, "integers") {
                            e.integer_data.push(v);
                        }
                        c.pass_reported(before);
                    }
                }
                "real_data" => {
                    c.skip_sep();
                    while c.peek().is_some() {
                        let before = c.pos;
                        if let Some((v, _)) = self.number(&mut c, "numbers") {
                            e.real_data.push(v);
                        }
                        c.pass_reported(before);
                    }
                }
                "side_b_variable" | "slave_variable" => {
                    if c.cmd.key == "slave_variable" {
                        self.push(
                            Diagnostic::warning(
                                codes::DEPRECATED_ALIAS,
                                "`slave variable` is a deprecated name for `side b variable`",
                            )
                            .at(self.span(line.tokens.get(..c.n).unwrap_or_default()))
                            .help("write `side b variable <side B variable> to <side A variable>`"),
                        );
                    }
                    self.once_as(&mut seen, "side_b_variable", &c);
                    c.skip_sep();
                    let Some((side_b, _)) = self.name(&mut c, "a side B variable") else {
                        continue;
                    };
                    if !self.keyword(&mut c, "to") {
                        continue;
                    }
                    let Some((side_a, _)) = self.name(&mut c, "a side A variable") else {
                        continue;
                    };
                    e.side_b_variable = Some(VariableMap { side_b, side_a });
                }
                "quarantine_faulty_points" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    e.quarantine_faulty_points = if c.peek().is_some() {
                        self.switch(&mut c).unwrap_or(false)
                    } else {
                        true
                    };
                }
                "dash_penalty_factor" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, v_at)) = self.number(&mut c, "a number") {
                        e.dash_penalty_factor = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.dash_penalty_factor"), v_at);
                    }
                }
                "offset_temperature" => {
                    self.once(&mut seen, &c);
                    if let Some((v, v_at)) = self.constant_value(&mut c, "a temperature difference")
                    {
                        e.offset_temperature = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.offset_temperature"), v_at);
                    }
                }
                "contact_pressure" => {
                    let phrase = c.cmd.phrase;
                    match pressure_from {
                        Some((first, first_line)) if first != phrase => {
                            self.push(
                                Diagnostic::error(
                                    codes::TWO_PRESSURES,
                                    format!(
                                        "`{phrase}` and `{first}` in one enforcement block"
                                    ),
                                )
                                .at(self.span(line.tokens.get(..c.n).unwrap_or_default()))
                                .help(format!(
                                    "both set the contact pressure; `{first}` is on line {first_line}: keep one"
                                )),
                            );
                            continue;
                        }
                        Some(_) => {
                            self.once_as(&mut seen, "contact_pressure", &c);
                        }
                        None => {
                            seen.insert("contact_pressure");
                            pressure_from = Some((phrase, line.line));
                        }
                    }
                    if let Some((v, v_at)) = self.constant_value(&mut c, "a pressure") {
                        e.contact_pressure = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.contact_pressure"), v_at);
                    }
                }
                "contact_gap_temperature" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    let rest = c.rest();
                    c.pos = line.tokens.len();
                    let words: Vec<String> =
                        rest.iter().map(|t| t.lower.replace('_', " ")).collect();
                    let value = words.join(" ");
                    let choice = match value.as_str() {
                        "side a" => Some(GapTemperature::SideA),
                        "side b" => Some(GapTemperature::SideB),
                        "mean" | "average" | "avg" => Some(GapTemperature::Mean),
                        _ => None,
                    };
                    match choice {
                        Some(g) => e.contact_gap_temperature = Some(g),
                        None if rest.is_empty() => self.missing(&c, "`side_a`, `side_b` or `mean`"),
                        None => {
                            let hint = did_you_mean(&value, ["side a", "side b", "mean"])
                                .map(|s| format!("did you mean `{}`? ", s.replace(' ', "_")))
                                .unwrap_or_default();
                            self.push(
                                Diagnostic::error(
                                    codes::BAD_CHOICE,
                                    format!("unknown contact gap temperature `{value}`"),
                                )
                                .at(self.span(rest))
                                .help(format!(
                                    "{hint}the choices are `side_a`, `side_b` and `mean` (the temperature a temperature-dependent conductance sees)"
                                )),
                            );
                        }
                    }
                }
                "plugin_isolation" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    let rest = c.rest();
                    c.pos = line.tokens.len();
                    let value = rest
                        .iter()
                        .map(|t| t.lower.as_str())
                        .collect::<Vec<_>>()
                        .join(" ");
                    match value.as_str() {
                        "process" => e.plugin_isolation = PluginIsolation::Process,
                        "none" => e.plugin_isolation = PluginIsolation::None,
                        _ if rest.is_empty() => self.missing(&c, "`process` or `none`"),
                        _ => {
                            let hint = did_you_mean(&value, ["process", "none"])
                                .map(|s| format!("did you mean `{s}`? "))
                                .unwrap_or_default();
                            self.push(
                                Diagnostic::error(
                                    codes::BAD_CHOICE,
                                    format!("unknown plugin isolation `{value}`"),
                                )
                                .at(self.span(rest))
                                .help(format!(
                                    "{hint}the choices are `process` (the plugin in a worker process) and `none` (in seam's process)"
                                )),
                            );
                        }
                    }
                }
                "contact_pressure_variable" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, _)) = self.name(&mut c, "a nodal field name") {
                        e.contact_pressure_variable = Some(v);
                    }
                }
                "use_toggle_block" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, at)) = self.name(&mut c, "a toggle block name") {
                        e.use_toggle_block = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.use_toggle_block"), at);
                        if c.peek().is_some() {
                            e.toggle_element_blocks = self.names(&mut c, "element block names");
                        }
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        e
    }

    /// `= [constant [value =]] <number>`: the material-model form `Constant Value = v`
    /// and the plain `= v`.
    fn constant_value(&mut self, c: &mut Cur, what: &str) -> Option<(f64, Loc)> {
        c.skip_sep();
        if c.peek()
            .is_some_and(|t| t.is_word() && t.lower == "constant")
        {
            c.pos += 1;
            if c.peek().is_some_and(|t| t.is_word() && t.lower == "value") {
                c.pos += 1;
            }
            c.skip_sep();
        }
        self.number(c, what)
    }

    /// A material-model line: `<property> [=] <model> [args…]`, the property named by
    /// the command's key.
    fn property(&mut self, c: &mut Cur) -> PropertyModel {
        let line = c.line;
        c.skip_sep();
        let model = match c.peek().filter(|t| !t.is_sep()) {
            Some(t) => {
                c.pos += 1;
                t.lower.clone()
            }
            None => {
                if c.cmd.status == registry::Status::Implemented {
                    self.missing(c, "a model after `=`");
                }
                String::new()
            }
        };
        let (args, _) = self.args(c, c.rest());
        c.pos = line.tokens.len();
        PropertyModel {
            property: c.cmd.key.to_string(),
            model,
            args,
            at: self.line_loc(line),
        }
    }

    /// Model arguments: `key = value` pairs and bare words, with where each was written
    /// (its key, or the bare word).
    fn args(&mut self, c: &Cur, toks: &[Token]) -> (Vec<Arg>, Vec<Loc>) {
        let mut out = Vec::new();
        let mut locs = Vec::new();
        let mut i = 0;
        while let Some(t) = toks.get(i) {
            if t.is_sep() {
                self.push(
                    Diagnostic::error(
                        codes::MISSING_ARGUMENT,
                        format!("`{}` has `{}` with no key before it", c.phrase(), t.text),
                    )
                    .at(Some(t.loc(&self.file)))
                    .help("write arguments as `key = value` or as single words"),
                );
                i += 1;
            } else if toks.get(i + 1).is_some_and(Token::is_sep) {
                match toks.get(i + 2).filter(|v| !v.is_sep()) {
                    Some(v) => {
                        out.push(Arg {
                            key: t.lower.clone(),
                            value: value_text(v),
                        });
                        locs.push(t.loc(&self.file));
                        i += 3;
                    }
                    None => {
                        let at = toks.get(i + 1).map(|s| s.loc(&self.file));
                        self.push(
                            Diagnostic::error(
                                codes::MISSING_ARGUMENT,
                                format!("argument `{}` of `{}` has no value", t.text, c.phrase()),
                            )
                            .at(at)
                            .help(format!("write `{} = <value>`", t.text)),
                        );
                        i += 2;
                    }
                }
            } else {
                out.push(Arg {
                    key: String::new(),
                    value: value_text(t),
                });
                locs.push(t.loc(&self.file));
                i += 1;
            }
        }
        (out, locs)
    }

    /// The recognised line commands of block `b` (of type `key`), in order; sub-blocks
    /// that may not appear there and unrecognised lines are reported on the way.
    fn commands<'b>(&mut self, b: &'b Block, key: &'static str) -> Vec<Cur<'b>> {
        let mut out = Vec::new();
        for item in &b.items {
            match item {
                Item::Block(sub) => self.misplaced(sub, key),
                Item::Line(line) => {
                    if let Matched::Command(c) = self.command(key, line) {
                        out.push(c);
                    }
                }
            }
        }
        out
    }

    fn interaction(&mut self, d: usize, i: usize, b: &Block) -> Interaction {
        let mut x = Interaction {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for mut c in self.commands(b, INT) {
            c.skip_sep();
            match c.cmd.key {
                "side_a" => x.side_a.extend(self.names(&mut c, "surface names")),
                "side_b" => x.side_b.extend(self.names(&mut c, "surface names")),
                "surfaces" => x.surfaces.extend(self.names(&mut c, "surface names")),
                "normal_tolerance" => {
                    self.once(&mut seen, &c);
                    if let Some((v, at)) = self.number(&mut c, "a distance") {
                        x.normal_tolerance = Some(v);
                        self.locs
                            .set(format!("{d}.interaction.{i}.normal_tolerance"), at);
                    }
                }
                "enforcement" => {
                    self.once(&mut seen, &c);
                    if let Some((v, at)) = self.name(&mut c, "an enforcement name") {
                        x.enforcement = Some(v);
                        self.locs
                            .set(format!("{d}.interaction.{i}.enforcement"), at);
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        x
    }

    fn defaults(&mut self, d: usize, b: &Block) -> InteractionDefaults {
        self.block_name(b);
        let mut x = InteractionDefaults {
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for mut c in self.commands(b, DEF) {
            c.skip_sep();
            match c.cmd.key {
                "general_contact" => {
                    self.once(&mut seen, &c);
                    x.general_contact = self.flag(&mut c);
                }
                "self_contact" => {
                    self.once(&mut seen, &c);
                    x.self_contact = self.flag(&mut c);
                }
                "surfaces" => x.surfaces.extend(self.names(&mut c, "surface names")),
                "enforcement" => {
                    self.once(&mut seen, &c);
                    if let Some((v, at)) = self.name(&mut c, "an enforcement name") {
                        x.enforcement = Some(v);
                        self.locs
                            .set(format!("{d}.interaction_defaults.enforcement"), at);
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        x
    }

    fn search_options(&mut self, d: usize, b: &Block) -> SearchOptions {
        let mut x = SearchOptions {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for mut c in self.commands(b, SO) {
            c.skip_sep();
            self.once(&mut seen, &c);
            let key = c.cmd.key;
            match key {
                "self_contact" => x.self_contact = self.flag(&mut c),
                "search_update_frequency" => {
                    x.search_update_frequency =
                        self.count(&mut c, "a whole number of steps")
                            .map(|(n, at)| {
                                self.locs.set(format!("{d}.search_options.{key}"), at);
                                n
                            });
                }
                _ => {
                    let what = if key.ends_with("angle") {
                        "an angle in degrees"
                    } else if key.ends_with("tolerance") {
                        "a distance"
                    } else {
                        "a number"
                    };
                    if let Some((v, at)) = self.number(&mut c, what) {
                        let slot = match key {
                            "normal_tolerance" => &mut x.normal_tolerance,
                            "tangential_tolerance" => &mut x.tangential_tolerance,
                            "buffer_factor" => &mut x.buffer_factor,
                            "field_factor" => &mut x.field_factor,
                            _ => &mut x.normal_check_angle,
                        };
                        *slot = Some(v);
                        self.locs.set(format!("{d}.search_options.{key}"), at);
                    }
                }
            }
            self.finish(&c);
        }
        x
    }

    fn surface_block(&mut self, d: usize, s: usize, b: &Block) -> SurfaceBlock {
        let mut x = SurfaceBlock {
            name: self.block_name(b).unwrap_or_default(),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        if let Some(t) = b.name.first() {
            self.locs
                .set(format!("{d}.surface.{s}.name"), t.loc(&self.file));
        }
        let mut seen = HashSet::new();
        for mut c in self.commands(b, CS) {
            let line = c.line;
            let at = self.line_loc(line);
            match c.cmd.key {
                "include_all_blocks" => {
                    self.once(&mut seen, &c);
                    x.include_all_blocks = true;
                }
                "block" | "surface" | "assembly" | "remove_block" | "remove_surface" => {
                    c.skip_sep();
                    let what = if c.cmd.key.ends_with("block") {
                        "block names"
                    } else if c.cmd.key == "assembly" {
                        "assembly names"
                    } else {
                        "side set names"
                    };
                    let first = c.pos;
                    let v = self.names(&mut c, what);
                    for t in c.line.tokens.get(first..c.pos).unwrap_or_default() {
                        if !t.is_sep() {
                            x.name_locs.push((value_text(t), t.loc(&self.file)));
                        }
                    }
                    let list = match c.cmd.key {
                        "block" => &mut x.blocks,
                        "surface" => &mut x.side_sets,
                        "assembly" => &mut x.assemblies,
                        "remove_block" => &mut x.remove_blocks,
                        _ => &mut x.remove_surfaces,
                    };
                    list.extend(v);
                }
                "element" => {
                    c.skip_sep();
                    if c.peek().is_none() {
                        self.missing(&c, "element numbers");
                    }
                    while c.peek().is_some() {
                        let before = c.pos;
                        if let Some((v, l)) = self.integer(&mut c, "element numbers (integers)") {
                            x.elements.push(v);
                            x.name_locs.push((v.to_string(), l));
                        }
                        c.pass_reported(before);
                    }
                }
                "subset" => {
                    let k = x.subsets.len();
                    let Some((name, _)) = self.name(&mut c, "a subset name") else {
                        continue;
                    };
                    if !(self.keyword(&mut c, "with") && self.keyword(&mut c, "normal")) {
                        continue;
                    }
                    c.skip_sep();
                    let (v, v_at) = self.numbers(&mut c, "a normal component");
                    match <[f64; 3]>::try_from(v.as_slice()) {
                        Ok(normal) => {
                            if let Some(a) = v_at {
                                self.locs
                                    .set(format!("{d}.surface.{s}.subset.{k}.normal"), a);
                            }
                            x.subsets.push(Subset { name, normal, at });
                        }
                        Err(_) if v_at.is_none() => self.missing(&c, "a normal `nx ny nz`"),
                        Err(_) => self.push(
                            Diagnostic::error(
                                codes::VALUE_COUNT,
                                format!("a subset normal needs 3 components, found {}", v.len()),
                            )
                            .at(v_at)
                            .help(c.usage()),
                        ),
                    }
                }
                "auto_subset" => {
                    if x.auto_subset.is_some() {
                        let n = c.n;
                        self.push(
                            Diagnostic::error(
                                codes::SECOND_AUTO_SUBSET,
                                format!("a second `auto subset` in contact surface `{}`", x.name),
                            )
                            .at(self.span(line.tokens.get(..n).unwrap_or_default()))
                            .help("one `auto subset` line per contact surface; use `number of subsets` to get more"),
                        );
                        continue;
                    }
                    let Some((name, _)) = self.name(&mut c, "a subset name") else {
                        continue;
                    };
                    let mut a = AutoSubset {
                        name,
                        number_of_subsets: None,
                        angle: None,
                        at,
                    };
                    while let Some(t) = c.peek() {
                        match t.lower.as_str() {
                            "number" => {
                                c.pos += 1;
                                if !(self.keyword(&mut c, "of") && self.keyword(&mut c, "subsets"))
                                {
                                    break;
                                }
                                c.skip_sep();
                                match self.count(&mut c, "a whole number of subsets") {
                                    Some((n, l)) => {
                                        a.number_of_subsets = Some(n);
                                        self.locs.set(
                                            format!(
                                                "{d}.surface.{s}.auto_subset.number_of_subsets"
                                            ),
                                            l,
                                        );
                                    }
                                    None => break,
                                }
                            }
                            "angle" => {
                                c.pos += 1;
                                c.skip_sep();
                                match self.number(&mut c, "an angle in degrees") {
                                    Some((v, l)) => {
                                        a.angle = Some(v);
                                        self.locs
                                            .set(format!("{d}.surface.{s}.auto_subset.angle"), l);
                                    }
                                    None => break,
                                }
                            }
                            _ => break,
                        }
                    }
                    x.auto_subset = Some(a);
                }
                "contact_type" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some(t) = c.bump() {
                        match t.lower.as_str() {
                            // Sierra/SM's `standard` (its default) is seam's face contact.
                            "face" | "standard" => x.contact_type = ContactType::Face,
                            "node" => x.contact_type = ContactType::Node,
                            "smooth" => self.push(
                                Diagnostic::error(
                                    codes::CONTACT_TYPE,
                                    "seam does not smooth contact surfaces (`contact type = smooth`)",
                                )
                                .at(Some(t.loc(&self.file)))
                                .help("write `contact type = standard` (or `face`): seam pairs the mesh's own faces"),
                            ),
                            other => {
                                let hint = did_you_mean(other, ["face", "node"])
                                    .map(|s| format!("did you mean `{s}`? "))
                                    .unwrap_or_default();
                                self.push(
                                    Diagnostic::error(
                                        codes::CONTACT_TYPE,
                                        format!("unknown contact type `{}`", t.text),
                                    )
                                    .at(Some(t.loc(&self.file)))
                                    .help(format!(
                                        "{hint}write `contact type = face` or `contact type = node`"
                                    )),
                                );
                            }
                        }
                    } else {
                        self.missing(&c, "`face` or `node`");
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        x
    }
}

/// The lower-case words at the start of a line, up to the first non-word token.
fn leading_words(line: &Line) -> Vec<&str> {
    line.tokens
        .iter()
        .take_while(|t| t.is_word())
        .map(|t| t.lower.as_str())
        .collect()
}

/// `begin interaction`, `begin search options` for a command's blocks.
fn homes(cmd: &CommandSpec) -> String {
    let v: Vec<String> = cmd
        .blocks
        .iter()
        .map(|b| registry::describe_block(b))
        .collect();
    v.join(" or ")
}
