//! Benchmark: read and validate a large mesh file.
//!
//! Make one with `python3 tests/fixtures/make_fixtures.py --large /tmp/big.exo 100`
//! (a 100³ hex block; `.msh` paths give Gmsh), then
//! `cargo bench --bench mesh_read -- /tmp/big.exo`. Prints the median of 3 reads.

use std::path::PathBuf;
use std::time::Instant;

use seam::mesh;

fn main() {
    let Some(path) = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .map(PathBuf::from)
    else {
        println!("mesh_read: give a mesh path (see the file's header for how to make one)");
        return;
    };
    let read = |p: &PathBuf| {
        if p.extension().is_some_and(|e| e == "msh") {
            mesh::gmsh::read(p)
        } else {
            mesh::exodus::read(p)
        }
    };
    let mut reads = Vec::new();
    let mut validates = Vec::new();
    let mut last = None;
    for _ in 0..3 {
        let t = Instant::now();
        let m = match read(&path) {
            Ok(m) => m,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(2);
            }
        };
        reads.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        if let Err(e) = m.validate() {
            eprintln!("{e}");
            std::process::exit(2);
        }
        validates.push(t.elapsed().as_secs_f64());
        last = Some(m);
    }
    reads.sort_by(f64::total_cmp);
    validates.sort_by(f64::total_cmp);
    let m = last.expect("three reads ran");
    println!(
        "{}: {} nodes, {} elements: read {:.3} s, validate {:.3} s (medians of 3)",
        path.display(),
        m.num_nodes(),
        m.num_elems(),
        reads[1],
        validates[1]
    );
}
