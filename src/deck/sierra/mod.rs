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
//!
//! The lowering is one [`Lower`] pass whose methods are spread by block: the argument
//! readers (`args`), `begin Contact Definition` with its control assignments and
//! periodic conditions (`definition`), `begin Enforcement` (`enforcement`), the
//! interaction and search-option blocks (`interaction`) and `begin Contact Surface`
//! (`surface`).

mod args;
mod definition;
mod enforcement;
mod interaction;
mod surface;

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
