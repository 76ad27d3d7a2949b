//! Problem files through `seam::run::check`: everything a run validates before it solves
//! (the TOML, the mesh, materials, conditions, the contact scene). The problem sits
//! beside a copy of the two-block example's mesh and decks, so inputs that name them
//! reach past the file's own checks.
#![no_main]

use std::sync::Once;

use libfuzzer_sys::fuzz_target;

const BESIDE: [(&str, &[u8]); 3] = [
    (
        "two_blocks.exo",
        include_bytes!("../../examples/two_blocks/two_blocks.exo"),
    ),
    (
        "contact_run.i",
        include_bytes!("../../examples/two_blocks/contact_run.i"),
    ),
    (
        "contact.i",
        include_bytes!("../../examples/two_blocks/contact.i"),
    ),
];

fuzz_target!(|data: &[u8]| {
    static SETUP: Once = Once::new();
    SETUP.call_once(|| {
        for (name, bytes) in BESIDE {
            seam_fuzz::write(name, bytes);
        }
    });
    let path = seam_fuzz::write("problem.toml", data);
    match seam::run::check(&path) {
        Ok(_) => {}
        Err(seam::run::RunError::Input(diags, _)) => {
            assert!(diags.has_errors(), "refused with no error diagnostic");
            for d in diags.0.iter() {
                seam_fuzz::assert_says_something(&d.message);
            }
        }
        Err(seam::run::RunError::Solve(message)) => seam_fuzz::assert_says_something(&message),
    }
});
