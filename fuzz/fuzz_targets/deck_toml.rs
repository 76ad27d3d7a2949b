//! The TOML twin of the deck: serde into the spec, the key locator and the shared
//! semantic checks.
#![no_main]

use std::sync::Arc;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let (_deck, diags) = seam::deck::parse_toml(&Arc::from("fuzz.toml"), &text);
    for d in diags.0.iter() {
        seam_fuzz::assert_says_something(&d.message);
    }
});
