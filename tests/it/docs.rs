//! Generated documentation stays in step with the code that generates it.

use std::path::Path;

/// `docs/deck.md` is the keyword registry's reference; `SEAM_BLESS=1` regenerates it.
#[test]
fn deck_reference_matches_the_registry() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/deck.md");
    let generated = seam::deck::reference_markdown();
    if std::env::var_os("SEAM_BLESS").is_some() {
        std::fs::write(&path, &generated).expect("write docs/deck.md");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "docs/deck.md is out of date with the keyword registry: run `SEAM_BLESS=1 cargo test --test it docs`"
    );
}
