//! The deck: Sierra-syntax contact input (`begin Contact Definition … end`) and its TOML
//! twin, both lowered to the typed [`spec::Deck`].
//!
//! Entry points: [`load`] (by extension), [`parse_sierra`], [`parse_toml`]. Every
//! problem found is collected as a [`Diagnostic`] with a code,
//! file:line:column and a help line; parsing never stops at the first error and never
//! panics.
//!
//! The Sierra front end runs in stages: [`lexer`] (tokens with line and column), a
//! `begin … end` tree (`tree`), lowering to the spec (`sierra`), then the semantic
//! checks of [`check`], which the TOML front end shares. Every keyword comes from the
//! [`registry`]; [`reference_markdown`] generates the deck reference from it. The
//! diagnostic codes are listed in [`codes`].
//!
//! A Sierra-syntax file is either a contact deck (only `begin contact definition`
//! blocks at the top level, anything else an error) or a whole Sierra input file
//! (`begin sierra … begin procedure … begin aria region … begin contact definition`):
//! from the latter every contact definition is read wherever it sits, and the other
//! blocks are named in one W0103 warning.

pub mod check;
pub mod codes;
pub mod lexer;
pub mod registry;
mod sierra;
pub mod spec;
mod toml_locs;
mod tree;

#[cfg(test)]
mod tests;

pub use registry::reference_markdown;
pub use tree::{MAX_NESTING, UNCLOSED_SHOWN};

use std::path::Path;
use std::sync::Arc;

use crate::diag::{
    Diagnostic, Diagnostics, Loc, MAX_DECK_BYTES, ReadError, SourceMap, file_label, read_text,
};

pub use spec::Deck;

/// A deck as read from a file: the spec, every diagnostic, and the source text for
/// rendering them.
#[derive(Debug, Default)]
pub struct LoadedDeck {
    pub deck: Deck,
    pub diagnostics: Diagnostics,
    pub sources: SourceMap,
}

/// Read a deck file: `.toml` is TOML, anything else Sierra syntax. At most
/// [`MAX_DECK_BYTES`] are read (a contact deck or a whole Sierra input file alike).
pub fn load(path: &Path) -> LoadedDeck {
    load_at_most(path, MAX_DECK_BYTES)
}

/// As [`load`], reading at most `limit` bytes: a larger file (or a device that does not
/// end) is error E0003, text that is not UTF-8 error E0004 at its line and column.
pub fn load_at_most(path: &Path, limit: u64) -> LoadedDeck {
    let file = file_label(path);
    let mut out = LoadedDeck::default();
    let text = match read_text(path, "deck file", limit) {
        Ok(t) => t,
        Err(e) => {
            out.diagnostics.push(read_error(&e, &mut out.sources));
            return out;
        }
    };
    out.sources.add(&file, &text);
    let is_toml = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    let (deck, diags) = if is_toml {
        parse_toml(&file, &text)
    } else {
        parse_sierra(&file, &text)
    };
    out.deck = deck;
    out.diagnostics.extend(diags);
    out
}

/// The diagnostic of an input file that could not be read (E0001, E0003, E0004); for
/// text that is not UTF-8 the text (bad bytes replaced) goes to `sources`, so the caret
/// shows the line.
pub fn read_error(e: &ReadError, sources: &mut SourceMap) -> Diagnostic {
    let code = match e {
        ReadError::TooLarge { .. } => codes::TOO_LARGE,
        ReadError::NotUtf8 { .. } => codes::NOT_UTF8,
        _ => codes::CANNOT_READ,
    };
    if let (Some(at), Some(text)) = (e.loc(), e.lossy_text()) {
        sources.add(&at.file, text);
    }
    Diagnostic::error(code, e.to_string())
        .at(e.loc())
        .help(e.help())
}

/// Parse Sierra-syntax text. `file` is the name used in diagnostics.
///
/// ```
/// use std::sync::Arc;
/// let text = "begin contact definition\n  contact surface top contains block_1\nend\n";
/// let (deck, diags) = seam::deck::parse_sierra(&Arc::from("deck.i"), text);
/// assert!(diags.is_empty());
/// assert_eq!(deck.contact_definitions.len(), 1);
/// ```
pub fn parse_sierra(file: &Arc<str>, text: &str) -> (Deck, Diagnostics) {
    let (lines, mut diags) = lexer::lex(file, text);
    let (items, tree_diags) = tree::build(file, lines);
    let (deck, locs, lower_diags, contact_lines) = sierra::lower(file, &items);
    // In a Sierra input file, a quoted string left open on a skipped line is not contact
    // input's business (it ends at its line either way).
    if let Some(ranges) = contact_lines {
        diags.0.retain(|d| {
            d.loc
                .as_ref()
                .is_none_or(|l| ranges.iter().any(|&(a, b)| (a..=b).contains(&l.line)))
        });
    }
    diags.extend(tree_diags);
    diags.extend(lower_diags);
    diags.extend(check::check(&deck, &locs));
    sort_by_place(&mut diags);
    (deck, diags)
}

/// The semantic checks alone, for a [`Deck`] built in code or edited after parsing;
/// diagnostics carry no location but name the definition and item.
pub fn check_deck(deck: &Deck) -> Diagnostics {
    check::check(deck, &check::Locs::default())
}

/// Parse the TOML form: the same spec through serde, then the same semantic checks.
/// On a TOML error the deck is empty and the one diagnostic points at the error.
pub fn parse_toml(file: &Arc<str>, text: &str) -> (Deck, Diagnostics) {
    let mut diags = Diagnostics::default();
    match ::toml::from_str::<Deck>(text) {
        Ok(mut deck) => {
            let locs = toml_locs::locate(file, text, &mut deck);
            diags.extend(check::check(&deck, &locs));
            sort_by_place(&mut diags);
            (deck, diags)
        }
        Err(e) => {
            let at = e.span().map(|r| byte_span_loc(file, text, r));
            let message = e.message().trim().replace('\n', "; ");
            diags.push(
                Diagnostic::error(codes::TOML_ERROR, format!("TOML: {message}"))
                    .at(at)
                    .help("TOML keys are the snake_case forms of the deck phrases; see the deck reference"),
            );
            (Deck::default(), diags)
        }
    }
}

/// Order diagnostics as an analyst reads the file: by line and column, unlocated last;
/// the sort is stable, so diagnostics at one place keep the order they were found in.
fn sort_by_place(diags: &mut Diagnostics) {
    diags.0.sort_by_key(|d| {
        d.loc
            .as_ref()
            .map_or((u32::MAX, u32::MAX), |l| (l.line, l.col))
    });
}

/// The 1-based line and character column of a byte range (clamped to its first line).
pub(crate) fn byte_span_loc(file: &Arc<str>, text: &str, r: std::ops::Range<usize>) -> Loc {
    let start = floor_char_boundary(text, r.start.min(text.len()));
    let end = floor_char_boundary(text, r.end.min(text.len()).max(start));
    let before = text.get(..start).unwrap_or_default();
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = before.get(line_start..).unwrap_or_default().chars().count() + 1;
    let span = text.get(start..end).unwrap_or_default();
    let len = span.split('\n').next().unwrap_or_default().chars().count();
    let n = |x: usize| u32::try_from(x).unwrap_or(u32::MAX);
    Loc::new(file, n(line), n(col), n(len.max(1)))
}

fn floor_char_boundary(text: &str, mut i: usize) -> usize {
    while i > 0 && !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}
