//! Sierra-syntax decks: the lexer, the `begin … end` tree, lowering and the semantic
//! checks. Any text must give a deck and diagnostics, never a panic.
#![no_main]

use std::sync::Arc;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let (_deck, diags) = seam::deck::parse_sierra(&Arc::from("fuzz.i"), &text);
    for d in diags.0.iter() {
        seam_fuzz::assert_says_something(&d.message);
    }
});
