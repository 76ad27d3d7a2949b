//! The Lua front end: the input is run as a map file in a sandbox (then `fx`, `fy`, `fz`
//! are called if it defined them), and its first three lines are compiled as the
//! `x_map`, `y_map`, `z_map` of a `mapped` periodicity and applied to a point and a
//! vector. The sandbox's instruction and memory limits must end every runaway.
#![no_main]

use libfuzzer_sys::fuzz_target;
use seam::periodic::{LuaMap, MapSource, PeriodicMap};
use seam::script::{Limits, Sandbox};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);

    let sandbox = Sandbox::new(Limits::default()).expect("a sandbox");
    if sandbox.run_source("fuzz.lua", &text).is_ok() {
        for name in ["fx", "fy", "fz"] {
            if let Ok(f) = sandbox.function(name, "fuzz.lua") {
                let _ = sandbox.call(&f, &[0.25, -1.5, 3.0]);
            }
        }
    }

    let mut lines = text.lines().map(MapSource::parse);
    let maps: [Option<MapSource>; 3] = std::array::from_fn(|_| lines.next());
    let refs = [maps[0].as_ref(), maps[1].as_ref(), maps[2].as_ref()];
    match LuaMap::new(refs, seam_fuzz::scratch(), "fuzz.i:1", 1.0) {
        Ok(mut map) => {
            if map.map_point([0.25, -1.5, 3.0]).is_ok() {
                let _ = map.map_vector([0.25, -1.5, 3.0], [1.0, 0.0, 0.0]);
            }
        }
        Err(e) => seam_fuzz::assert_says_something(&e.to_string()),
    }
});
