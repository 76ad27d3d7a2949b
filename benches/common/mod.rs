//! What the benchmarks share: the error of a nodal field against an exact solution.

use seam::heat::error_norms;
use seam::mesh::Mesh;

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
