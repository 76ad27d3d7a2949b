//! Stage two of the Sierra front end: lines → a tree of `begin … end` blocks that still
//! carries every token's location. Nothing here knows what a command means.
//!
//! Entry point: [`build`]. A `begin` line's type phrase is matched against the registry's
//! block phrases (longest match); the rest of the line is the block's name. An `end` line
//! may repeat the type and/or the name, and must then match (else E0102, and the block
//! is closed all the same). Blocks still open at the end of the file are reported at
//! their `begin` line (E0101): the outermost [`UNCLOSED_SHOWN`] one by one, the others in
//! one diagnostic at the innermost. Blocks nest at most [`MAX_NESTING`] deep: a `begin`
//! deeper than that is E0114, and it and everything up to its `end` are skipped (so a
//! file of 100 000 `begin` lines neither overflows the stack nor reports 100 000
//! errors). A block of unknown type keeps its E0105 diagnostic in
//! [`Block::unknown`] instead of reporting it: whether it is an error depends on where it
//! sits (in a whole Sierra input file, blocks outside contact definitions are skipped).

use std::sync::Arc;

use crate::diag::{Diagnostic, Diagnostics, did_you_mean};

use super::codes;
use super::lexer::{Line, Token, span};
use super::registry::{self, BlockSpec};

#[derive(Debug)]
pub enum Item {
    Line(Line),
    Block(Block),
}

#[derive(Debug)]
pub struct Block {
    /// `None` when the type phrase is unknown (already reported).
    pub spec: Option<&'static BlockSpec>,
    /// The `begin` line.
    pub head: Line,
    /// Tokens of the `begin` line after the type phrase.
    pub name: Vec<Token>,
    pub items: Vec<Item>,
    /// For a block of unknown type, the diagnostic to report if it is in contact input.
    pub unknown: Option<Diagnostic>,
    /// The line of its `end` (`u32::MAX` if it is never closed).
    pub end_line: u32,
}

impl Block {
    /// The tokens of the type phrase (after `begin`).
    pub fn type_tokens(&self) -> &[Token] {
        let n = self.head.tokens.len().saturating_sub(self.name.len());
        self.head.tokens.get(1..n).unwrap_or_default()
    }

    /// The block name, lower case, when exactly one name token was given.
    #[cfg(test)]
    pub fn name_lower(&self) -> Option<String> {
        match self.name.as_slice() {
            [t] => Some(t.lower.clone()),
            _ => None,
        }
    }
}

/// How deep blocks may nest. A contact deck nests three deep (`contact definition`,
/// `contact surface`, a toggle block), a whole Sierra input file about eight (`sierra`,
/// `procedure`, `region`, …); 64 leaves room for any real file and bounds the recursion
/// of the stages after this one.
pub const MAX_NESTING: usize = 64;

/// How many unclosed blocks are reported one by one (outermost first); the rest are
/// counted in one more diagnostic. One missing `end` leaves the outermost open blocks
/// unclosed, so those are the ones to show.
pub const UNCLOSED_SHOWN: usize = 3;

/// The file's top level.
pub fn build(file: &Arc<str>, lines: Vec<Line>) -> (Vec<Item>, Diagnostics) {
    let mut diags = Diagnostics::default();
    let mut top: Vec<Item> = Vec::new();
    let mut stack: Vec<Block> = Vec::new();
    // `begin` lines open inside a block nested too deep: skipped with all they hold.
    let mut skipped = 0usize;
    // Blocks skipped that were never closed.
    let mut skipped_total = 0usize;
    for line in lines {
        // `end time = 10` is a line of a Sierra input file, not the end of a block.
        let first = line
            .tokens
            .first()
            .filter(|_| !line.tokens.iter().any(Token::is_sep))
            .map(|t| t.lower.as_str());
        let keyword = line.tokens.first().is_some_and(Token::is_word);
        match first {
            Some("begin") if keyword && (skipped > 0 || stack.len() >= MAX_NESTING) => {
                if skipped == 0 {
                    diags.push(
                        Diagnostic::error(
                            codes::TOO_DEEP,
                            format!(
                                "blocks nested more than {MAX_NESTING} deep: this block and everything in it is skipped"
                            ),
                        )
                        .at(span(file, &line.tokens))
                        .help(format!(
                            "a contact deck nests blocks three deep and a whole Sierra input file about eight; check that every `begin` has its `end` (seam reads at most {MAX_NESTING} levels)"
                        )),
                    );
                }
                skipped += 1;
                skipped_total += 1;
            }
            Some("end") if keyword && skipped > 0 => {
                skipped -= 1;
                skipped_total -= 1;
            }
            _ if skipped > 0 => {}
            Some("begin") if keyword => {
                stack.push(open(file, line));
            }
            Some("end") if keyword => match stack.pop() {
                Some(mut block) => {
                    check_end(file, &block, &line, &mut diags);
                    block.end_line = line.line;
                    push(&mut stack, &mut top, Item::Block(block));
                }
                None => diags.push(
                    Diagnostic::error(codes::STRAY_END, "`end` with no open block")
                        .at(span(file, &line.tokens))
                        .help("remove this line, or add the `begin` it was meant to close"),
                ),
            },
            _ => push(&mut stack, &mut top, Item::Line(line)),
        }
    }
    // Report unclosed blocks outermost first, and keep their contents.
    let unclosed = stack.len() + skipped_total;
    for block in stack.iter().take(if unclosed > UNCLOSED_SHOWN + 1 {
        UNCLOSED_SHOWN
    } else {
        unclosed
    }) {
        let what = describe(block);
        diags.push(
            Diagnostic::error(codes::UNCLOSED_BLOCK, format!("`{what}` is never closed"))
                .at(span(file, &block.head.tokens))
                .help(format!(
                    "add `end` (or `end {}`) after the last line of this block",
                    block.spec.map_or("", |s| s.phrase)
                )),
        );
    }
    if let (Some(last), true) = (stack.last(), unclosed > UNCLOSED_SHOWN + 1) {
        let rest = unclosed - UNCLOSED_SHOWN;
        let from = stack
            .get(UNCLOSED_SHOWN)
            .map_or(last.head.line, |b| b.head.line);
        let deeper = if skipped_total > 0 {
            format!(" ({skipped_total} of them nested too deep to read)")
        } else {
            String::new()
        };
        diags.push(
            Diagnostic::error(
                codes::UNCLOSED_BLOCK,
                format!(
                    "{rest} more blocks opened from line {from} on are never closed{deeper}; the innermost read is `{}`",
                    describe(last)
                ),
            )
            .at(span(file, &last.head.tokens))
            .help("every `begin` needs its `end`; a file of `begin` lines with no `end` is probably not a deck"),
        );
    }
    while let Some(block) = stack.pop() {
        push(&mut stack, &mut top, Item::Block(block));
    }
    (top, diags)
}

fn push(stack: &mut [Block], top: &mut Vec<Item>, item: Item) {
    match stack.last_mut() {
        Some(b) => b.items.push(item),
        None => top.push(item),
    }
}

/// `begin contact surface top` as written, in lower case.
fn describe(block: &Block) -> String {
    let words: Vec<&str> = block.head.tokens.iter().map(|t| t.lower.as_str()).collect();
    words.join(" ")
}

fn open(file: &Arc<str>, head: Line) -> Block {
    let mut unknown = None;
    let rest = head.tokens.get(1..).unwrap_or_default();
    let words: Vec<&str> = rest
        .iter()
        .take_while(|t| t.is_word())
        .map(|t| t.lower.as_str())
        .collect();
    let spec = registry::match_block(&words);
    let name: Vec<Token> = match spec {
        Some(s) => rest
            .get(registry::word_count(s.phrase)..)
            .unwrap_or_default()
            .to_vec(),
        None => {
            let all: Vec<&str> = registry::BLOCKS.iter().map(|b| b.phrase).collect();
            // With a suggestion, blame only the words it replaces (the rest is the name).
            let suggestion = registry::suggest(&words, &all);
            let n = suggestion.map_or(words.len(), |(_, k)| k);
            let written = words.get(..n).unwrap_or_default().join(" ");
            let hint = suggestion
                .map(|(p, _)| p)
                .or_else(|| did_you_mean(&written, all.iter().copied()))
                .map(|p| format!("did you mean `begin {p}`? "))
                .unwrap_or_default();
            let blamed = match n {
                0 => rest,
                _ => rest.get(..n).unwrap_or(rest),
            };
            let list: Vec<String> = all.iter().map(|p| format!("`{p}`")).collect();
            let message = if rest.is_empty() {
                "`begin` without a block type".to_string()
            } else {
                format!("unknown block type `{written}`")
            };
            unknown = Some(
                Diagnostic::error(codes::UNKNOWN_BLOCK, message)
                    .at(span(
                        file,
                        if rest.is_empty() {
                            &head.tokens
                        } else {
                            blamed
                        },
                    ))
                    .help(format!("{hint}block types are {}", list.join(", "))),
            );
            Vec::new()
        }
    };
    Block {
        spec,
        head,
        name,
        items: Vec::new(),
        unknown,
        end_line: u32::MAX,
    }
}

fn check_end(file: &Arc<str>, block: &Block, end: &Line, diags: &mut Diagnostics) {
    let rest = end.tokens.get(1..).unwrap_or_default();
    if rest.is_empty() {
        return;
    }
    let Some(spec) = block.spec else {
        return; // unknown type already reported; do not pile on
    };
    let written: Vec<&str> = rest.iter().map(|t| t.lower.as_str()).collect();
    let written = written.join(" ");
    let name: Vec<&str> = block.name.iter().map(|t| t.lower.as_str()).collect();
    let full = if name.is_empty() {
        spec.phrase.to_string()
    } else {
        format!("{} {}", spec.phrase, name.join(" "))
    };
    if written == spec.phrase || written == full {
        return;
    }
    let mut forms = vec!["`end`".to_string(), format!("`end {}`", spec.phrase)];
    if full != spec.phrase {
        forms.push(format!("`end {full}`"));
    }
    diags.push(
        Diagnostic::error(
            codes::MISMATCHED_END,
            format!(
                "`end {written}` does not match `begin {full}` opened on line {}",
                block.head.line
            ),
        )
        .at(span(file, rest))
        .help(format!("close this block with {}", forms.join(" or "))),
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deck::lexer::lex;

    fn tree(src: &str) -> (Vec<Item>, Diagnostics) {
        let file: Arc<str> = Arc::from("t.i");
        let (lines, _) = lex(&file, src);
        build(&file, lines)
    }

    #[test]
    fn nests_blocks_and_keeps_names() {
        let (top, d) = tree(
            "begin contact definition CD\n begin contact surface Top\n block = b1\n end contact surface top\nend",
        );
        assert!(d.is_empty(), "{d:?}");
        let [Item::Block(cd)] = top.as_slice() else {
            panic!("expected one block, got {top:?}")
        };
        assert_eq!(cd.spec.map(|s| s.key), Some("contact_definition"));
        assert_eq!(cd.name_lower().as_deref(), Some("cd"));
        let [Item::Block(cs)] = cd.items.as_slice() else {
            panic!("expected one sub-block")
        };
        assert_eq!(cs.spec.map(|s| s.key), Some("contact_surface"));
        assert_eq!(cs.name_lower().as_deref(), Some("top"));
        assert_eq!(cs.items.len(), 1);
    }

    #[test]
    fn begin_and_end_with_a_separator_are_lines() {
        let (top, d) = tree("begin time control\n end time = 10\n begin = 0\nend\n");
        assert!(d.is_empty(), "{d:?}");
        let [Item::Block(b)] = top.as_slice() else {
            panic!("expected one block, got {top:?}")
        };
        assert_eq!(b.items.len(), 2);
        assert!(b.items.iter().all(|i| matches!(i, Item::Line(_))));
    }

    #[test]
    fn mismatched_end_points_at_end_line() {
        let (_, d) = tree("begin interaction a\nend interaction b\n");
        assert_eq!(d.len(), 1);
        assert_eq!(d.0[0].code, codes::MISMATCHED_END);
        let loc = d.0[0].loc.clone().unwrap_or_default();
        assert_eq!((loc.line, loc.col, loc.len), (2, 5, 13));
    }

    #[test]
    fn unclosed_points_at_begin_line() {
        let (top, d) = tree("begin contact definition\n begin enforcement e\n");
        let lines: Vec<u32> =
            d.0.iter()
                .filter_map(|x| x.loc.as_ref().map(|l| l.line))
                .collect();
        assert_eq!(lines, [1, 2]);
        assert!(d.0.iter().all(|x| x.code == codes::UNCLOSED_BLOCK));
        assert_eq!(top.len(), 1);
    }

    #[test]
    fn many_unclosed_blocks_are_reported_in_a_few_lines() {
        let src = "begin contact definition\n".repeat(10_000);
        let (top, d) = tree(&src);
        let codes: Vec<&str> = d.0.iter().map(|x| x.code).collect();
        // One E0114 at the first block too deep, the three outermost unclosed blocks,
        // one count of the rest.
        assert_eq!(codes.iter().filter(|&&c| c == codes::TOO_DEEP).count(), 1);
        assert_eq!(
            codes
                .iter()
                .filter(|&&c| c == codes::UNCLOSED_BLOCK)
                .count(),
            UNCLOSED_SHOWN + 1
        );
        let last = d.0.iter().rfind(|x| x.code == codes::UNCLOSED_BLOCK);
        let message = last.map(|x| x.message.clone()).unwrap_or_default();
        assert!(
            message.starts_with("9997 more blocks opened from line 4 on are never closed"),
            "{message}"
        );
        assert_eq!(top.len(), 1);
    }

    #[test]
    fn nesting_is_bounded_and_the_deep_part_skipped() {
        let deep = MAX_NESTING + 5;
        let mut src = "begin contact definition\n".repeat(deep);
        src += &"end\n".repeat(deep);
        src += "begin contact definition after\nend\n";
        let (top, d) = tree(&src);
        let codes: Vec<&str> = d.0.iter().map(|x| x.code).collect();
        assert_eq!(codes, [codes::TOO_DEEP]);
        let at = d.0[0].loc.as_ref().map(|l| l.line);
        assert_eq!(at, Some(MAX_NESTING as u32 + 1));
        // The deep part is gone, the rest of the file is read.
        assert_eq!(top.len(), 2);
        let mut depth = 0;
        let mut items = &top;
        while let Some(Item::Block(b)) = items.first() {
            depth += 1;
            items = &b.items;
        }
        assert_eq!(depth, MAX_NESTING);
    }

    #[test]
    fn four_unclosed_blocks_are_each_reported() {
        let (_, d) = tree(&"begin contact definition\n".repeat(UNCLOSED_SHOWN + 1));
        assert_eq!(d.len(), UNCLOSED_SHOWN + 1);
        assert!(d.0.iter().all(|x| x.message.ends_with("is never closed")));
    }

    #[test]
    fn stray_end_and_unknown_block() {
        let (top, d) = tree("end\nbegin contact defnition\nend\n");
        let codes: Vec<&str> = d.0.iter().map(|x| x.code).collect();
        assert_eq!(codes, [codes::STRAY_END]);
        let [Item::Block(b)] = top.as_slice() else {
            panic!("expected one block, got {top:?}")
        };
        let unknown = b.unknown.as_ref().map(|x| (x.code, x.help.clone()));
        assert_eq!(unknown.as_ref().map(|x| x.0), Some(codes::UNKNOWN_BLOCK));
        assert!(
            unknown
                .and_then(|x| x.1)
                .as_deref()
                .unwrap_or("")
                .contains("did you mean `begin contact definition`")
        );
    }
}
