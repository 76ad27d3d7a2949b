//! Benchmark: contact surfaces of a 100×100×100 hex block (1 M elements) with
//! `Skin All Blocks` plus a side set over one face, on one thread.
//!
//! Run: `cargo bench --bench surfaces` (add `-- 50` for a 50³ block). Prints the median
//! of 5 builds and the peak resident memory (VmHWM) before and after building, so the
//! surfaces' own share can be told from the mesh's.

use std::time::Instant;

use seam::deck::spec::{ContactDefinition, SurfaceDef};
use seam::diag::{Loc, SourceMap};
use seam::mesh::generate::{self, BoxSpec};
use seam::scene::surfaces;

fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn main() {
    let n: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(100);
    let t = Instant::now();
    let mesh = generate::single_box(
        BoxSpec::hex([0.0; 3], [1.0; 3], [n, n, n], 1).with_side_sets([0, 0, 0, 0, 1, 0]),
    );
    let gen_s = t.elapsed().as_secs_f64();
    let mesh_peak = peak_rss_mb();
    let def = ContactDefinition {
        surfaces: vec![
            SurfaceDef::SkinAllBlocks {
                exclude: vec![],
                at: Loc::default(),
            },
            SurfaceDef::Contains {
                name: "bottom".into(),
                contains: vec!["surface_1".into()],
                at: Loc::default(),
            },
        ],
        ..ContactDefinition::default()
    };
    let sources = SourceMap::default();
    let mut times = Vec::new();
    let mut faces = 0;
    for _ in 0..5 {
        let t = Instant::now();
        let set = surfaces::build(&mesh, &def, &sources);
        times.push(t.elapsed().as_secs_f64());
        faces = set.surfaces.iter().map(|s| s.faces.len()).sum::<usize>();
        std::hint::black_box(&set);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "surfaces benchmark: {n}x{n}x{n} Hex8 = {} elements, {} nodes",
        mesh.num_elems(),
        mesh.num_nodes()
    );
    println!("  mesh generation            {gen_s:.3} s");
    println!(
        "  build surfaces (median/5)  {:.3} s   (min {:.3}, max {:.3})",
        times[2], times[0], times[4]
    );
    println!(
        "  faces in surfaces          {faces} (expected {})",
        6 * n * n
    );
    if let (Some(m), Some(p)) = (mesh_peak, peak_rss_mb()) {
        println!("  peak RSS after mesh        {m:.0} MB");
        println!(
            "  peak RSS after surfaces    {p:.0} MB (surfaces add {:.0} MB)",
            p - m
        );
    }
}
