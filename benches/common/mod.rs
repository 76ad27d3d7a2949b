//! What the benchmarks share: the error of a nodal field against an exact solution, and
//! the curved interface of the search benchmarks. (Each benchmark uses some of it.)
#![allow(dead_code)]

use seam::heat::error_norms;
use seam::mesh::Mesh;
use seam::mesh::generate;

/// Two rings meshed apart: the outer face of the inner one (side set 1, side A, about
/// `faces` faces, n_θ × n_z) inside the inner face of the outer one (side set 2, side B,
/// 0.9 n_θ × 1.1 n_z faces).
pub fn rings(faces: usize) -> Mesh {
    let nz = ((faces as f64 / 8.0).sqrt()).round().max(1.0) as usize;
    let nt = faces / nz;
    let ring = |r: [f64; 2], cells, id, sets| {
        generate::annulus(r[0], r[1], 360.0, [0.0, 1.0], cells, id, sets)
    };
    let a = ring([0.9, 1.0], [1, nt, nz], 1, [0, 1, 0, 0, 0, 0]);
    let b = ring(
        [1.0, 1.1],
        [1, nt * 9 / 10, nz * 10 / 9 + 1],
        2,
        [2, 0, 0, 0, 0, 0],
    );
    generate::disjoint_union(&a, &b)
}

/// The L2 norm (degree-4 rule) and the largest nodal value of `t − exact` over every
/// block of `mesh`.
pub fn errors(
    mesh: &Mesh,
    t: &[f64],
    exact: fn([f64; 3]) -> f64,
    grad: fn([f64; 3]) -> [f64; 3],
) -> (f64, f64) {
    let blocks: Vec<usize> = (0..mesh.blocks.len()).collect();
    let n = error_norms(mesh, &blocks, t, &exact, &grad, 4).unwrap();
    let max = (0..mesh.num_nodes())
        .map(|i| (t[i] - exact(mesh.coords[i])).abs())
        .fold(0.0, f64::max);
    (n.l2, max)
}
