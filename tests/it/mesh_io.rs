//! Mesh readers and validation against the fixtures written by
//! `tests/fixtures/make_fixtures.py` (expected values in `tests/fixtures/expected.json`).

use std::path::PathBuf;

use seam::mesh::{self, Mesh};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(name)
}

#[test]
fn smoke() {
    let m: Mesh = mesh::exodus::read(&fixture("two_hex_classic.exo")).unwrap();
    eprintln!(
        "{} {} {:?}",
        m.num_nodes(),
        m.num_elems(),
        m.blocks
            .iter()
            .map(|b| (b.id, &b.name, b.len()))
            .collect::<Vec<_>>()
    );
}
