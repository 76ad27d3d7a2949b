//! Stage two of the Sierra front end: lines → a tree of `begin … end` blocks that still
//! carries every token's location. Nothing here knows what a command means.
//!
//! Entry point: [`build`]. A `begin` line's type phrase is matched against the registry's
//! block phrases (longest match); the rest of the line is the block's name. An `end` line
//! may repeat the type and/or the name, and must then match (else E0102, and the block
//! is closed all the same). Blocks still open at the end of the file are reported at
//! their `begin` line (E0101). Blocks nest at most [`MAX_DEPTH`] deep: a deeper `begin`
//! is E0106 and is skipped with everything up to its `end`, so no input can make the
//! later stages recurse without bound.

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

/// How deep blocks may nest. Sierra's contact blocks nest three deep; the bound keeps
/// the recursive lowering (and dropping) of the tree within any thread's stack.
pub const MAX_DEPTH: usize = 32;

/// The file's top level.
pub fn build(file: &Arc<str>, lines: Vec<Line>) -> (Vec<Item>, Diagnostics) {
    let mut diags = Diagnostics::default();
    let mut top: Vec<Item> = Vec::new();
    let mut stack: Vec<Block> = Vec::new();
    // `begin` lines past MAX_DEPTH still open, whose contents are skipped.
    let mut too_deep = 0usize;
    for line in lines {
        let first = line.tokens.first().map(|t| t.lower.as_str());
        let keyword = line.tokens.first().is_some_and(Token::is_word);
        if too_deep > 0 {
            match first {
                Some("begin") if keyword => too_deep += 1,
                Some("end") if keyword => too_deep -= 1,
                _ => {}
            }
            continue;
        }
        match first {
            Some("begin") if keyword && stack.len() >= MAX_DEPTH => {
                too_deep = 1;
                diags.push(
                    Diagnostic::error(
                        codes::MISPLACED_BLOCK,
                        format!("block nested more than {MAX_DEPTH} deep"),
                    )
                    .at(span(file, &line.tokens))
                    .help("close the blocks above with `end`; this block and everything in it up to its `end` are skipped"),
                );
            }
            Some("begin") if keyword => {
                stack.push(open(file, line, &mut diags));
            }
            Some("end") if keyword => match stack.pop() {
                Some(block) => {
                    check_end(file, &block, &line, &mut diags);
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
    for block in &stack {
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

fn open(file: &Arc<str>, head: Line, diags: &mut Diagnostics) -> Block {
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
            diags.push(
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
    fn stray_end_and_unknown_block() {
        let (_, d) = tree("end\nbegin contact defnition\nend\n");
        let codes: Vec<&str> = d.0.iter().map(|x| x.code).collect();
        assert_eq!(codes, [codes::STRAY_END, codes::UNKNOWN_BLOCK]);
        assert!(
            d.0[1]
                .help
                .as_deref()
                .unwrap_or("")
                .contains("did you mean `begin contact definition`")
        );
    }

    #[test]
    fn nesting_past_the_bound_is_one_error_and_skipped() {
        let n = 100_000;
        let src = format!(
            "begin contact definition\n{}{}begin contact surface top\nend\nend\n",
            "begin interaction a\n".repeat(n),
            "end\n".repeat(n),
        );
        let (top, d) = tree(&src);
        assert_eq!(d.len(), 1, "{d:?}");
        assert_eq!(d.0[0].code, codes::MISPLACED_BLOCK);
        assert_eq!(
            d.0[0].loc.as_ref().map(|l| l.line),
            Some(MAX_DEPTH as u32 + 1)
        );
        fn depth(items: &[Item]) -> usize {
            items
                .iter()
                .map(|i| match i {
                    Item::Block(b) => 1 + depth(&b.items),
                    Item::Line(_) => 0,
                })
                .max()
                .unwrap_or(0)
        }
        assert_eq!(depth(&top), MAX_DEPTH);
        // The block after the skipped ones is read again.
        let [Item::Block(cd)] = top.as_slice() else {
            panic!("expected one block")
        };
        assert!(
            matches!(cd.items.last(), Some(Item::Block(b)) if b.name_lower().as_deref() == Some("top"))
        );
    }
}
