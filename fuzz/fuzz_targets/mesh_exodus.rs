//! Exodus II meshes (netCDF classic, 64-bit offset, CDF-5, netCDF-4/HDF5) through
//! `seam::mesh::read`: the reader and the validation after it.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let path = seam_fuzz::write("mesh.exo", data);
    if let Err(e) = seam::mesh::read(&path) {
        seam_fuzz::assert_says_something(&e.to_string());
    }
});
