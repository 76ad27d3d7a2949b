//! The finite-element core against independent truth: exact linear fields (patch
//! test), manufactured solutions (convergence rates), finite differences (Jacobian),
//! a dense reference solve, a hand-eliminated constraint system, and properties of the
//! algebra (symmetry, determinism, fill, multigrid scaling).

// Dense reference algebra reads best with the subscripts of the formulas.
#![allow(clippy::needless_range_loop)]

use faer::sparse::SparseColMat;
use seam::assembly::{Assembler, DofMap, Pattern};
use seam::heat::{self, Basis, FaceBc, Material, TEMPERATURE, kernel};
use seam::mesh::generate::{BoxSpec, single_box};
use seam::mesh::{Mesh, NodeId, Side, Topology};
use seam::solve::{
    AmgCg, AmgOptions, Cholesky, LinearSolver, Lu, Ordering, SaddleLdlt, SolveError,
    apply_dirichlet, laplacian_7pt, relative_residual,
};

/// xorshift64*: a deterministic, dependency-free pseudo-random stream in [0, 1).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Nodes on the boundary of the box `[lo, hi]` (by their generated coordinates).
fn boundary_nodes(mesh: &Mesh, lo: [f64; 3], hi: [f64; 3]) -> Vec<NodeId> {
    (0..mesh.num_nodes())
        .filter(|&i| {
            let p = mesh.coords[i];
            (0..3).any(|d| p[d] == lo[d] || p[d] == hi[d])
        })
        .map(|i| NodeId(i as u32))
        .collect()
}

/// Move interior nodes by up to `amount·h` in each direction (elements stay valid for
/// the amounts used here; an inverted element would be reported by the assembly).
fn distort(mesh: &mut Mesh, lo: [f64; 3], hi: [f64; 3], h: f64, amount: f64, seed: u64) {
    let boundary: std::collections::HashSet<_> = boundary_nodes(mesh, lo, hi).into_iter().collect();
    let mut rng = Rng(seed);
    for i in 0..mesh.num_nodes() {
        if !boundary.contains(&NodeId(i as u32)) {
            for d in 0..3 {
                mesh.coords[i][d] += amount * h * (2.0 * rng.next() - 1.0);
            }
        }
    }
}

/// A box of Wedge6 elements: every hex cell split into two prisms along the diagonal
/// 0–2 of its bottom face (bottom triangles counter-clockwise seen from +z).
fn wedge_box(lo: [f64; 3], hi: [f64; 3], cells: [usize; 3]) -> Mesh {
    let hex = single_box(BoxSpec::hex(lo, hi, cells, 1));
    let mut mesh = Mesh {
        dim: 3,
        coords: hex.coords.clone(),
        node_numbers: hex.node_numbers.clone(),
        ..Mesh::default()
    };
    let mut conn = Vec::new();
    let block = &hex.blocks[0];
    for k in 0..block.len() {
        let c = block.elem_nodes(k);
        conn.extend_from_slice(&[c[0], c[1], c[2], c[4], c[5], c[6]]);
        conn.extend_from_slice(&[c[0], c[2], c[3], c[4], c[6], c[7]]);
    }
    mesh.push_block(1, "", Topology::Wedge6, conn, None);
    mesh
}

/// A box of Pyramid5 elements: every hex cell split into six pyramids, one per face,
/// with a new node at the cell centre as their common apex. Hex sides are listed
/// counter-clockwise from outside, pyramid bases counter-clockwise seen from the apex
/// (inside), so each base is the hex side reversed.
fn pyramid_box(lo: [f64; 3], hi: [f64; 3], cells: [usize; 3]) -> Mesh {
    let hex = single_box(BoxSpec::hex(lo, hi, cells, 1));
    let mut mesh = Mesh {
        dim: 3,
        coords: hex.coords.clone(),
        node_numbers: hex.node_numbers.clone(),
        ..Mesh::default()
    };
    let mut conn = Vec::new();
    let block = &hex.blocks[0];
    for k in 0..block.len() {
        let c = block.elem_nodes(k);
        let mut centre = [0.0; 3];
        for n in c {
            for d in 0..3 {
                centre[d] += mesh.coords[n.index()][d] / 8.0;
            }
        }
        let apex = NodeId(mesh.coords.len() as u32);
        mesh.coords.push(centre);
        mesh.node_numbers.push(apex.0 as i64 + 1);
        for side in Topology::Hex8.sides() {
            let q: Vec<NodeId> = side.iter().map(|&l| c[l as usize]).collect();
            conn.extend_from_slice(&[q[0], q[3], q[2], q[1], apex]);
        }
    }
    mesh.push_block(1, "", Topology::Pyramid5, conn, None);
    mesh
}

/// A 2-D mesh of `[0,1]²` with `n × n` Quad4 cells, or each cell split into two Tri3.
fn plane_mesh(n: usize, tri: bool) -> Mesh {
    let mut mesh = Mesh {
        dim: 2,
        ..Mesh::default()
    };
    for j in 0..=n {
        for i in 0..=n {
            mesh.coords
                .push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
            mesh.node_numbers.push(mesh.coords.len() as i64);
        }
    }
    let id = |i: usize, j: usize| NodeId((i + (n + 1) * j) as u32);
    let mut conn = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if tri {
                conn.extend_from_slice(&[q[0], q[1], q[2], q[0], q[2], q[3]]);
            } else {
                conn.extend_from_slice(&q);
            }
        }
    }
    let topo = if tri { Topology::Tri3 } else { Topology::Quad4 };
    mesh.push_block(1, "", topo, conn, None);
    mesh
}

fn unit_material(blocks: usize, k: f64) -> Vec<Material> {
    vec![
        Material {
            conductivity: k,
            rho_c: 1.0,
        };
        blocks
    ]
}

fn max_abs(v: impl Iterator<Item = f64>) -> f64 {
    v.fold(0.0, |m, x| m.max(x.abs()))
}

/// Solve a steady problem with Cholesky + METIS and return nodal temperatures.
fn solve_steady(
    mesh: &Mesh,
    k: f64,
    source: Option<&(dyn Fn([f64; 3]) -> f64 + Sync)>,
    dirichlet: &[(NodeId, f64)],
    faces: &[FaceBc],
) -> Vec<f64> {
    let blocks: Vec<usize> = (0..mesh.blocks.len()).collect();
    let dofs = DofMap::new(mesh, &[(TEMPERATURE, &blocks)]).unwrap();
    let sys = heat::steady_conduction(
        mesh,
        &dofs,
        &unit_material(mesh.blocks.len(), k),
        source,
        dirichlet,
        faces,
    )
    .unwrap();
    let mut x = sys.rhs.clone();
    let mut chol = Cholesky::new(Ordering::Metis);
    chol.factor(&sys.matrix).unwrap();
    chol.solve(&mut x).unwrap();
    dofs.nodal_values(dofs.field(TEMPERATURE).unwrap(), &x)
}

/// Patch test: T = 1 + x + 2y − 3z solves −∇·(k∇T) = 0 exactly and lies in every
/// element's space, so the discrete solution with boundary data from T must equal T
/// at every node to round-off — on distorted meshes too. 1e-12 relative to max|T|
/// leaves room for the condition number (~1e3 here) times machine epsilon.
#[test]
fn patch_test_reproduces_linear_field_on_distorted_meshes() {
    let exact = |p: [f64; 3]| 1.0 + p[0] + 2.0 * p[1] - 3.0 * p[2];
    let (lo, hi) = ([0.0, 0.0, 0.0], [1.0, 1.2, 0.8]);
    let cells = [5, 6, 4];
    let h = 0.2;
    let meshes = [
        ("hex8", single_box(BoxSpec::hex(lo, hi, cells, 1)), 0.2),
        ("tet4", single_box(BoxSpec::tet(lo, hi, cells, 1)), 0.1),
        ("wedge6", wedge_box(lo, hi, cells), 0.15),
        ("pyramid5", pyramid_box(lo, hi, cells), 0.1),
    ];
    for (name, mut mesh, amount) in meshes {
        let before = mesh.coords.clone();
        distort(&mut mesh, lo, hi, h, amount, 0x9E37_79B9_7F4A_7C15);
        assert_ne!(
            before, mesh.coords,
            "{name}: the mesh must actually be distorted"
        );
        let bc: Vec<(NodeId, f64)> = boundary_nodes(&mesh, lo, hi)
            .into_iter()
            .map(|n| (n, exact(mesh.coords[n.index()])))
            .collect();
        let t = solve_steady(&mesh, 2.5, None, &bc, &[]);
        let scale = max_abs(mesh.coords.iter().map(|&p| exact(p)));
        let err = max_abs(t.iter().zip(&mesh.coords).map(|(t, &p)| t - exact(p)));
        assert!(err <= 1e-12 * scale, "{name}: max nodal error {err:.3e}");
    }
}

/// The 2-D patch test: T = 1 + x + 2y on distorted Quad4 and Tri3 meshes of the unit
/// square (per unit depth), Dirichlet data on the boundary; same tolerance and reason
/// as in 3-D.
#[test]
fn patch_test_in_two_dimensions() {
    let exact = |p: [f64; 3]| 1.0 + p[0] + 2.0 * p[1];
    for tri in [false, true] {
        let mut mesh = plane_mesh(6, tri);
        let on_boundary = |p: [f64; 3]| p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0;
        let mut rng = Rng(11);
        for p in mesh.coords.iter_mut() {
            if !on_boundary(*p) {
                p[0] += 0.25 / 6.0 * (2.0 * rng.next() - 1.0);
                p[1] += 0.25 / 6.0 * (2.0 * rng.next() - 1.0);
            }
        }
        let bc: Vec<(NodeId, f64)> = (0..mesh.num_nodes())
            .filter(|&i| on_boundary(mesh.coords[i]))
            .map(|i| (NodeId(i as u32), exact(mesh.coords[i])))
            .collect();
        let t = solve_steady(&mesh, 1.3, None, &bc, &[]);
        let err = max_abs(t.iter().zip(&mesh.coords).map(|(t, &p)| t - exact(p)));
        assert!(err <= 1e-12 * 4.0, "tri = {tri}: max nodal error {err:.3e}");
        // A source term breaks linearity: the test can fail.
        let q = |_: [f64; 3]| 1.0;
        let t = solve_steady(&mesh, 1.3, Some(&q), &bc, &[]);
        let err = max_abs(t.iter().zip(&mesh.coords).map(|(t, &p)| t - exact(p)));
        assert!(err > 1e-4, "tri = {tri}: a source must change the field");
    }
}

/// Patch test with Neumann data: T = 1 + x + 2y − 3z with its exact heat flux into the
/// body, q = k∇T·n (n outward), on the faces x = 0 and x = 1, Dirichlet data elsewhere.
/// The face integrals ∫ q N are exact for constant q, so the nodal values are again
/// exact to round-off; flipping the flux sign must break it.
#[test]
fn patch_test_with_flux_faces() {
    let k = 3.0;
    let exact = |p: [f64; 3]| 1.0 + p[0] + 2.0 * p[1] - 3.0 * p[2];
    let (lo, hi) = ([0.0; 3], [1.0; 3]);
    let mesh = single_box(BoxSpec::hex(lo, hi, [4, 4, 4], 1).with_side_sets([1, 2, 0, 0, 0, 0]));
    // Heat flux into the body through a face with outward normal n: q = k ∇T·n.
    // ∇T = (1, 2, −3): at x = 0 (n = −x) q = −k, at x = 1 (n = +x) q = +k.
    let mut faces = Vec::new();
    for (set, q) in [(1, -k), (2, k)] {
        let s = mesh.side_sets.iter().find(|s| s.id == set).unwrap();
        faces.extend(s.sides.iter().map(|&side: &Side| FaceBc::Flux { side, q }));
    }
    let bc: Vec<(NodeId, f64)> = boundary_nodes(&mesh, lo, hi)
        .into_iter()
        .filter(|n| {
            // Nodes of the y and z faces (edges shared with the x faces included).
            let p = mesh.coords[n.index()];
            (1..3).any(|d| p[d] == 0.0 || p[d] == 1.0)
        })
        .map(|n| (n, exact(mesh.coords[n.index()])))
        .collect();
    let t = solve_steady(&mesh, k, None, &bc, &faces);
    let err = max_abs(t.iter().zip(&mesh.coords).map(|(t, &p)| t - exact(p)));
    assert!(err <= 1e-12 * 4.0, "max nodal error {err:.3e}");
    // With the flux sign flipped the field is wrong: the test can fail.
    let flipped: Vec<FaceBc> = faces
        .iter()
        .map(|f| match *f {
            FaceBc::Flux { side, q } => FaceBc::Flux { side, q: -q },
            other => other,
        })
        .collect();
    let t = solve_steady(&mesh, k, None, &bc, &flipped);
    let err = max_abs(t.iter().zip(&mesh.coords).map(|(t, &p)| t - exact(p)));
    assert!(err > 1e-3, "flipped flux should break the patch test");
}

/// Convergence on T = sin πx sin πy sin πz, Q = 3π²kT, T = 0 on ∂[0,1]³, hex meshes
/// with h = 1/8, 1/16, 1/32: Q1 elements give ‖e‖_L2 = O(h²), |e|_H1 = O(h). The rates
/// are computed from the errors, not compared with stored numbers; ±0.1 because at
/// these sizes the asymptotic regime holds to about a percent.
#[test]
fn manufactured_solution_converges_at_optimal_rates() {
    use std::f64::consts::PI;
    let k = 1.7;
    let exact = |p: [f64; 3]| (PI * p[0]).sin() * (PI * p[1]).sin() * (PI * p[2]).sin();
    let grad = |p: [f64; 3]| {
        let (s, c) = (p.map(|x| (PI * x).sin()), p.map(|x| (PI * x).cos()));
        [
            PI * c[0] * s[1] * s[2],
            PI * s[0] * c[1] * s[2],
            PI * s[0] * s[1] * c[2],
        ]
    };
    let q = move |p: [f64; 3]| 3.0 * PI * PI * k * exact(p);
    let mut errs = Vec::new();
    for n in [8, 16, 32] {
        let (lo, hi) = ([0.0; 3], [1.0; 3]);
        let mesh = single_box(BoxSpec::hex(lo, hi, [n, n, n], 1));
        let bc: Vec<(NodeId, f64)> = boundary_nodes(&mesh, lo, hi)
            .into_iter()
            .map(|n| (n, 0.0))
            .collect();
        let t = solve_steady(&mesh, k, Some(&q), &bc, &[]);
        let e = heat::error_norms(&mesh, &[0], &t, &exact, &grad, 6).unwrap();
        errs.push(e);
    }
    for w in errs.windows(2) {
        let l2_rate = (w[0].l2 / w[1].l2).log2();
        let h1_rate = (w[0].h1 / w[1].h1).log2();
        assert!(
            (l2_rate - 2.0).abs() <= 0.1,
            "L2 rate {l2_rate:.3} ({errs:?})"
        );
        assert!(
            (h1_rate - 1.0).abs() <= 0.1,
            "H1 rate {h1_rate:.3} ({errs:?})"
        );
    }
}

/// The exact Jacobian of R(T) = ∫ k(T)∇N·∇T against central differences of R along a
/// random direction v: ‖J v − (R(T+εv) − R(T−εv))/2ε‖ ≤ 1e-6 ‖J v‖. For k linear in T,
/// R is quadratic and the central difference is exact but for round-off
/// (≈ ε_mach/ε = 1e-10); for k = k0·exp(βT) the truncation error is O(ε²) ≈ 1e-12.
#[test]
fn nonlinear_jacobian_matches_finite_differences() {
    let (lo, hi) = ([0.0; 3], [1.0; 3]);
    for (topo, mut mesh) in [
        ("hex8", single_box(BoxSpec::hex(lo, hi, [3, 3, 3], 1))),
        ("tet4", single_box(BoxSpec::tet(lo, hi, [2, 2, 2], 1))),
        ("wedge6", wedge_box(lo, hi, [2, 2, 2])),
        ("pyramid5", pyramid_box(lo, hi, [2, 2, 2])),
    ] {
        distort(&mut mesh, lo, hi, 1.0 / 3.0, 0.1, 7);
        let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
        let mut pattern = Pattern::new(&mesh, &dofs);
        pattern.build().unwrap();
        let (k0, beta) = (2.0, 0.3);
        let linear = move |t: f64, _x: [f64; 3]| (k0 * (1.0 + beta * t), k0 * beta);
        let expo =
            move |t: f64, _x: [f64; 3]| (k0 * (beta * t).exp(), k0 * beta * (beta * t).exp());
        let src = |p: [f64; 3]| 1.0 + p[0];
        let mut rng = Rng(42);
        let t: Vec<f64> = (0..dofs.len()).map(|_| 1.0 + rng.next()).collect();
        let v: Vec<f64> = (0..dofs.len()).map(|_| rng.next() - 0.5).collect();
        for (kname, kf) in [
            (
                "linear",
                &linear as &(dyn Fn(f64, [f64; 3]) -> (f64, f64) + Sync),
            ),
            ("exp", &expo),
        ] {
            let r = |t: &[f64]| {
                heat::nonlinear_residual_jacobian(&mesh, &dofs, &pattern, kf, Some(&src), t)
                    .unwrap()
            };
            let (_, j) = r(&t);
            let mut jv = vec![0.0; t.len()];
            seam::solve::spmv(&j, &v, &mut jv);
            let eps = 1e-6;
            let tp: Vec<f64> = t.iter().zip(&v).map(|(t, v)| t + eps * v).collect();
            let tm: Vec<f64> = t.iter().zip(&v).map(|(t, v)| t - eps * v).collect();
            let (rp, _) = r(&tp);
            let (rm, _) = r(&tm);
            let diff: f64 = jv
                .iter()
                .zip(rp.iter().zip(&rm))
                .map(|(jv, (p, m))| (jv - (p - m) / (2.0 * eps)).powi(2))
                .sum::<f64>()
                .sqrt();
            let size = jv.iter().map(|x| x * x).sum::<f64>().sqrt();
            assert!(
                diff <= 1e-6 * size,
                "{topo}/{kname}: |Jv − FD| = {diff:.3e}, |Jv| = {size:.3e}"
            );
        }
    }
}

/// Newton on k(T) = k0(1 + βT) with T = 1 on x = 0 and T = 2 on x = 1: in 1-D the
/// Kirchhoff transform Φ = k0(T + βT²/2) is linear in x, and the Q1 solution of this
/// problem is exact at the nodes (each x-layer of nodes is a 1-D linear-element
/// problem with nodally exact solutions). Newton converges quadratically.
#[test]
fn newton_solves_nonlinear_conduction() {
    let (lo, hi) = ([0.0; 3], [1.0; 3]);
    let mesh = single_box(BoxSpec::hex(lo, hi, [6, 2, 2], 1));
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
    let field = dofs.field(TEMPERATURE).unwrap();
    let mut pattern = Pattern::new(&mesh, &dofs);
    pattern.build().unwrap();
    let (k0, beta) = (1.0, 0.5);
    let k = move |t: f64, _x: [f64; 3]| (k0 * (1.0 + beta * t), k0 * beta);
    let bc_nodes: Vec<(NodeId, f64)> = (0..mesh.num_nodes())
        .filter_map(|i| {
            let x = mesh.coords[i][0];
            (x == 0.0 || x == 1.0).then_some((NodeId(i as u32), if x == 0.0 { 1.0 } else { 2.0 }))
        })
        .collect();
    let bcs = heat::dirichlet_dofs(&mesh, &dofs, field, &bc_nodes).unwrap();
    let report = heat::newton(
        |t| {
            let (mut r, mut j) =
                heat::nonlinear_residual_jacobian(&mesh, &dofs, &pattern, &k, None, t)?;
            heat::fix_dirichlet_rows(&mut r, &mut j, t, &bcs);
            Ok((r, j))
        },
        vec![1.5; dofs.len()],
        1e-12,
        20,
    )
    .unwrap();
    assert!(report.converged, "{:?}", report.residual_history);
    assert!(report.iterations <= 7, "{:?}", report.residual_history);
    let phi = |t: f64| k0 * (t + beta * t * t / 2.0);
    let (p0, p1) = (phi(1.0), phi(2.0));
    let t = dofs.nodal_values(field, &report.x);
    for (i, p) in mesh.coords.iter().enumerate() {
        let target = p0 + (p1 - p0) * p[0];
        let exact = (-1.0 + (1.0 + 2.0 * beta * target / k0).sqrt()) / beta;
        assert!(
            (t[i] - exact).abs() < 1e-10,
            "node {i}: {} vs {exact}",
            t[i]
        );
    }
}

/// Dense Gaussian elimination with partial pivoting: an independent reference.
fn dense_solve(mut a: Vec<Vec<f64>>, mut b: Vec<f64>) -> Vec<f64> {
    let n = b.len();
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        for r in c + 1..n {
            let f = a[r][c] / a[c][c];
            if f != 0.0 {
                for k in c..n {
                    a[r][k] -= f * a[c][k];
                }
                b[r] -= f * b[c];
            }
        }
    }
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| a[c][k] * b[k]).sum();
        b[c] = (b[c] - s) / a[c][c];
    }
    b
}

fn to_dense(a: &SparseColMat<usize, f64>) -> Vec<Vec<f64>> {
    let mut d = vec![vec![0.0; a.ncols()]; a.nrows()];
    let s = a.symbolic();
    for j in 0..a.ncols() {
        for p in s.col_range(j) {
            d[s.row_idx()[p]][j] += a.val()[p];
        }
    }
    d
}

/// A small heat system with Dirichlet data, convection and a source.
fn small_system(n: usize) -> (SparseColMat<usize, f64>, Vec<f64>) {
    let (lo, hi) = ([0.0; 3], [1.0; 3]);
    let mut mesh =
        single_box(BoxSpec::hex(lo, hi, [n, n, n], 1).with_side_sets([0, 0, 0, 0, 0, 6]));
    distort(&mut mesh, lo, hi, 1.0 / n as f64, 0.15, 3);
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
    let top = mesh.side_sets.iter().find(|s| s.id == 6).unwrap();
    let faces: Vec<FaceBc> = top
        .sides
        .iter()
        .map(|&side| FaceBc::Convection {
            side,
            h: 10.0,
            t_inf: 300.0,
        })
        .collect();
    let bc: Vec<(NodeId, f64)> = (0..mesh.num_nodes())
        .filter(|&i| mesh.coords[i][2] == 0.0)
        .map(|i| (NodeId(i as u32), 350.0))
        .collect();
    let q = |p: [f64; 3]| 1e3 * p[0];
    let sys = heat::steady_conduction(&mesh, &dofs, &unit_material(1, 5.0), Some(&q), &bc, &faces)
        .unwrap();
    (sys.matrix, sys.rhs)
}

/// Cholesky (METIS and AMD) and faer LU agree with dense elimination to 1e-12
/// relative (condition number of this system ≈ 1e3, so round-off stays below 1e-13).
#[test]
fn cholesky_matches_dense_reference() {
    let (a, b) = small_system(5);
    let reference = dense_solve(to_dense(&a), b.clone());
    let scale = max_abs(reference.iter().copied());
    let solvers: Vec<(&str, Box<dyn LinearSolver>)> = vec![
        ("cholesky-metis", Box::new(Cholesky::new(Ordering::Metis))),
        ("cholesky-amd", Box::new(Cholesky::new(Ordering::Amd))),
        ("lu", Box::new(Lu::new())),
    ];
    for (name, mut s) in solvers {
        let mut x = b.clone();
        s.factor(&a).unwrap();
        s.solve(&mut x).unwrap();
        let err = max_abs(x.iter().zip(&reference).map(|(x, r)| x - r));
        assert!(err <= 1e-12 * scale, "{name}: {err:.3e}");
    }
}

/// A second factorisation of a matrix with the same pattern reuses the symbolic
/// analysis; a new pattern triggers a new one.
#[test]
fn cholesky_keeps_symbolic_analysis_while_pattern_holds() {
    let (a, b) = small_system(4);
    let mut chol = Cholesky::new(Ordering::Metis);
    chol.factor(&a).unwrap();
    assert!(chol.uses_metis());
    let mut scaled = a.clone();
    scaled.val_mut().iter_mut().for_each(|v| *v *= 2.0);
    chol.factor(&scaled).unwrap();
    assert_eq!(chol.symbolic_count, 1);
    let mut x = b.clone();
    chol.solve(&mut x).unwrap();
    assert!(relative_residual(&scaled, &x, &b) < 1e-13);
    chol.factor(&laplacian_7pt(5)).unwrap();
    assert_eq!(chol.symbolic_count, 2);
}

/// Errors say where: a negative diagonal at row r fails exactly at pivot r (earlier
/// pivots see only the SPD part; Schur complements only lower the diagonal), a NaN
/// entry is named by row and column.
#[test]
fn factorisation_errors_name_the_row() {
    // 6³ factorises simplicially, 24³ supernodally in faer: both report paths.
    for (n, r) in [(6, 100), (24, 5000)] {
        for ordering in [Ordering::Metis, Ordering::Amd] {
            let mut a = laplacian_7pt(n);
            let p = s_entry(&a, r, r).unwrap();
            a.val_mut()[p] = -1.0;
            let mut chol = Cholesky::new(ordering);
            let err = chol.factor(&a).unwrap_err();
            assert!(
                matches!(err, SolveError::NotPositiveDefinite { row } if row == r),
                "n = {n}, {ordering:?}: {err}"
            );
            assert_eq!(chol.is_supernodal(), n == 24, "n = {n}, {ordering:?}");
        }
    }
    let mut a = laplacian_7pt(4);
    let q = s_entry(&a, 7, 3).unwrap();
    a.val_mut()[q] = f64::NAN;
    let err = Cholesky::new(Ordering::Amd).factor(&a).unwrap_err();
    assert!(
        matches!(err, SolveError::NonFinite { row: 7, col: 3, .. }),
        "{err}"
    );
}

fn s_entry(a: &SparseColMat<usize, f64>, row: usize, col: usize) -> Option<usize> {
    let s = a.symbolic();
    s.col_range(col).find(|&p| s.row_idx()[p] == row)
}

/// METIS nested dissection fills less than AMD on a 3-D grid (20³ 7-point Laplacian):
/// the separator structure of ND is what makes 3-D factorisation affordable.
#[test]
fn metis_fill_is_at_most_amd_fill() {
    let a = laplacian_7pt(20);
    let mut metis = Cholesky::new(Ordering::Metis);
    metis.factor(&a).unwrap();
    assert!(metis.uses_metis());
    let mut amd = Cholesky::new(Ordering::Amd);
    amd.factor(&a).unwrap();
    assert!(
        metis.factor_nnz() <= amd.factor_nnz(),
        "METIS {} > AMD {}",
        metis.factor_nnz(),
        amd.factor_nnz()
    );
}

/// Saddle-point system [K Cᵀ; C 0] for two boxes meshed apart and tied: every node of
/// the upper box's bottom face (side A) equals 0.6·(its twin) + 0.4·(the twin's +x
/// neighbour, or −x at the edge) on the lower box's top face. Assembled through the
/// DOF map's extra dofs and pattern couplings, solved by LDLᵀ with refinement, and
/// compared with the constraint eliminated by hand (u = T ū, Tᵀ K T ū = Tᵀ f, dense).
#[test]
fn saddle_ldlt_matches_eliminated_solution() {
    saddle_ldlt_against_elimination(1.0, 1.0, true);
}

/// The same tie badly scaled, as a mortar tie is: conductivities 1e3 times larger and
/// constraint rows 1e-4 times smaller (C scales with the face areas), so that the
/// multipliers' Schur pivots sit near 1e-11 of K's diagonal, far below the
/// regularisation δ = 1e-8 of it. Unscaled (the scaling disabled by hand), the
/// refinement stopped above 1e-10 and the solve fell back to LU; the factorisation of
/// the scaled matrix solves it as the well-scaled one, without the fallback.
#[test]
fn saddle_ldlt_solves_a_badly_scaled_tie() {
    saddle_ldlt_against_elimination(1e3, 1e-4, true);
}

/// A factorisation that cannot be refined: a regularisation δ of 1e6 (its default is
/// 1e-8) replaces every pivot of the scaled matrix (each near ±1) by ±1e6, so the
/// refinement gains almost nothing in its 5 steps, and the solve falls back to LU: the
/// answer is the eliminated one all the same.
#[test]
fn saddle_ldlt_falls_back_to_lu_when_refinement_fails() {
    saddle_ldlt_against_elimination(1.0, 1.0, false);
}

/// [`saddle_ldlt_matches_eliminated_solution`] with conductivities times `k_scale` and
/// the constraint rows times `c_scale`; `refinable` false spoils the factorisation (δ
/// of 1e6: it must then fall back to LU).
fn saddle_ldlt_against_elimination(k_scale: f64, c_scale: f64, refinable: bool) {
    let cells = [3, 3, 3];
    let mut mesh = seam::mesh::generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], cells, 1),
            BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], cells, 2),
        ],
        false,
    );
    mesh.node_numbers = (1..=mesh.num_nodes() as i64).collect();
    let mut dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0, 1])]).unwrap();
    let field = dofs.field(TEMPERATURE).unwrap();
    // Side A: nodes of block 2 at z = 1; masters: nodes of block 1 at z = 1.
    let on_block = |b: usize| -> Vec<NodeId> {
        let mut v: Vec<NodeId> = mesh.blocks[b].connectivity.clone();
        v.sort();
        v.dedup();
        v
    };
    let lower: Vec<NodeId> = on_block(0)
        .into_iter()
        .filter(|n| mesh.coords[n.index()][2] == 1.0)
        .collect();
    let upper: Vec<NodeId> = on_block(1)
        .into_iter()
        .filter(|n| mesh.coords[n.index()][2] == 1.0)
        .collect();
    let find = |x: f64, y: f64| {
        *lower
            .iter()
            .find(|n| {
                let p = mesh.coords[n.index()];
                (p[0] - x).abs() < 1e-12 && (p[1] - y).abs() < 1e-12
            })
            .unwrap()
    };
    let h = 1.0 / cells[0] as f64;
    let ties: Vec<(usize, [(usize, f64); 2])> = upper
        .iter()
        .map(|&s| {
            let p = mesh.coords[s.index()];
            let twin = find(p[0], p[1]);
            let nx = if p[0] + h <= 1.0 + 1e-12 {
                p[0] + h
            } else {
                p[0] - h
            };
            let other = find(nx, p[1]);
            let d = |n: NodeId| dofs.dof(field, n).unwrap().index();
            (d(s), [(d(twin), 0.6), (d(other), 0.4)])
        })
        .collect();
    let n_primal = dofs.len();
    let lambdas = dofs.add_extra(ties.len());
    let mut pattern = Pattern::new(&mesh, &dofs);
    let mut pairs = Vec::new();
    for (k, (s, m)) in ties.iter().enumerate() {
        let l = lambdas.start + k;
        pairs.push((l, *s));
        pairs.push((l, m[0].0));
        pairs.push((l, m[1].0));
    }
    pattern.add_couplings(&pairs).unwrap();
    pattern.build().unwrap();
    let mut asm = Assembler::new(&pattern);
    let rule = Basis::standard(Topology::Hex8).unwrap();
    let kcond = [k_scale, 4.0 * k_scale];
    asm.elements(&mesh, None, |e, ke, fe| {
        let x: Vec<[f64; 3]> = mesh
            .elem_nodes(e)
            .iter()
            .map(|n| mesh.coords[n.index()])
            .collect();
        let b = mesh.block_of(e);
        kernel::conductivity(&rule, &x, |_| kcond[b], ke).unwrap();
        kernel::source(&rule, &x, |p| 10.0 * p[0], fe).unwrap();
    });
    for (k, (_, m)) in ties.iter().enumerate() {
        // Row λ_k: u_s − 0.6 u_m0 − 0.4 u_m1 = 0 (and the symmetric column).
        let c = c_scale;
        asm.add_coupling(3 * k, c, c);
        asm.add_coupling(3 * k + 1, -c * m[0].1, -c * m[0].1);
        asm.add_coupling(3 * k + 2, -c * m[1].1, -c * m[1].1);
    }
    let mut a = asm.matrix().unwrap();
    let mut b = asm.rhs();
    let bc: Vec<(usize, f64)> = (0..mesh.num_nodes())
        .filter_map(|i| {
            let z = mesh.coords[i][2];
            let d = dofs.dof(field, NodeId(i as u32))?.index();
            (z == 0.0)
                .then_some((d, 0.0))
                .or((z == 2.0).then_some((d, 1.0)))
        })
        .collect();
    apply_dirichlet(&mut a, &mut b, &bc).unwrap();
    let mut ldlt = SaddleLdlt::with_primal(n_primal, dofs.len(), Ordering::Metis);
    if !refinable {
        ldlt.delta = 1e6;
    }
    ldlt.factor(&a).unwrap();
    let mut x = b.clone();
    let report = ldlt.solve(&mut x).unwrap();
    assert!(report.residual <= 1e-13, "{report:?}");
    assert_eq!(
        ldlt.fell_back(),
        !refinable,
        "the scaled factorisation solves without LU, a spoilt one with it"
    );

    // Reference: eliminate the slaves. T maps the free (non-slave) primal dofs to all.
    let is_slave: std::collections::HashMap<usize, [(usize, f64); 2]> =
        ties.iter().cloned().collect();
    let free: Vec<usize> = (0..n_primal)
        .filter(|d| !is_slave.contains_key(d))
        .collect();
    let col_of: std::collections::HashMap<usize, usize> =
        free.iter().enumerate().map(|(c, &d)| (d, c)).collect();
    let mut t = vec![vec![0.0; free.len()]; n_primal];
    for d in 0..n_primal {
        match is_slave.get(&d) {
            Some(m) => {
                for (md, w) in m {
                    t[d][col_of[md]] += w;
                }
            }
            None => t[d][col_of[&d]] = 1.0,
        }
    }
    // K and f of the primal block (Dirichlet already eliminated; no slave is fixed).
    let kd = to_dense(&a);
    let nf = free.len();
    let mut kr = vec![vec![0.0; nf]; nf];
    let mut fr = vec![0.0; nf];
    for i in 0..n_primal {
        for (c, tc) in t[i].iter().enumerate() {
            if *tc != 0.0 {
                fr[c] += tc * b[i];
            }
        }
        for j in 0..n_primal {
            if kd[i][j] == 0.0 {
                continue;
            }
            for (ci, ti) in t[i].iter().enumerate().filter(|(_, v)| **v != 0.0) {
                for (cj, tj) in t[j].iter().enumerate().filter(|(_, v)| **v != 0.0) {
                    kr[ci][cj] += ti * kd[i][j] * tj;
                }
            }
        }
    }
    let ur = dense_solve(kr, fr);
    let u: Vec<f64> = (0..n_primal)
        .map(|i| t[i].iter().zip(&ur).map(|(a, b)| a * b).sum())
        .collect();
    let scale = max_abs(u.iter().copied());
    let err = max_abs(u.iter().zip(&x[..n_primal]).map(|(a, b)| a - b));
    assert!(err <= 1e-12 * scale, "LDLᵀ vs eliminated: {err:.3e}");
    // The constraint holds in the LDLᵀ solution.
    for (s, m) in &ties {
        let jump = x[*s] - m[0].1 * x[m[0].0] - m[1].1 * x[m[1].0];
        assert!(jump.abs() <= 1e-12 * scale);
    }
}

/// Smoothed-aggregation AMG keeps the CG iteration count nearly flat under refinement:
/// from 20³ to 40³ unknowns (h halved) it must grow by less than 1.5× (Jacobi-PCG
/// would double, since its count grows like 1/h).
#[test]
fn amg_cg_iterations_are_nearly_mesh_independent() {
    let mut counts = Vec::new();
    for n in [20, 40] {
        let a = laplacian_7pt(n);
        let mut amg = AmgCg::new(AmgOptions::default());
        amg.factor(&a).unwrap();
        let h = amg.hierarchy();
        assert!(h.rows.len() >= 2, "{h:?}");
        let b: Vec<f64> = (0..a.nrows()).map(|i| 1.0 + (i % 7) as f64).collect();
        let mut x = b.clone();
        let rep = amg.solve(&mut x).unwrap();
        assert!(relative_residual(&a, &x, &b) <= 1e-8 * 1.01, "{rep:?}");
        counts.push(rep.iterations);
    }
    assert!(
        (counts[1] as f64) < 1.5 * counts[0] as f64,
        "iterations 20³ → 40³: {counts:?}"
    );
}

/// AMG-CG on a heat system with Dirichlet rows (which join no aggregate) agrees with
/// Cholesky to the CG tolerance.
#[test]
fn amg_cg_agrees_with_cholesky_on_heat_system() {
    let (a, b) = small_system(8);
    let mut reference = b.clone();
    let mut chol = Cholesky::new(Ordering::Metis);
    chol.factor(&a).unwrap();
    chol.solve(&mut reference).unwrap();
    for smoother in [
        seam::solve::Smoother::SymmetricGaussSeidel,
        seam::solve::Smoother::Jacobi,
    ] {
        let mut amg = AmgCg::new(AmgOptions {
            smoother,
            tolerance: 1e-12,
            coarse_size: 50,
            ..AmgOptions::default()
        });
        amg.factor(&a).unwrap();
        // A real hierarchy: the Q1 couplings must count as strong.
        assert!(amg.hierarchy().rows.len() >= 2, "{:?}", amg.hierarchy());
        let mut x = b.clone();
        amg.solve(&mut x).unwrap();
        let err = max_abs(x.iter().zip(&reference).map(|(x, r)| x - r));
        assert!(
            err <= 1e-8 * max_abs(reference.iter().copied()),
            "{smoother:?}: {err:.3e}"
        );
    }
}

/// Assembly with 1 and 2 rayon threads gives bit-identical matrices and vectors.
#[test]
fn assembly_is_bit_identical_across_thread_counts() {
    let assemble = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| small_system(14))
    };
    let (a1, b1) = assemble(1);
    let (a2, b2) = assemble(2);
    assert_eq!(a1.symbolic().col_ptr(), a2.symbolic().col_ptr());
    assert_eq!(a1.symbolic().row_idx(), a2.symbolic().row_idx());
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(a1.val()), bits(a2.val()));
    assert_eq!(bits(&b1), bits(&b2));
}

/// Dirichlet elimination keeps the matrix symmetric (exactly: entries are only zeroed
/// or set to 1), puts the data on fixed rows of the solution, and agrees with solving
/// the reduced system of free dofs (dense reference).
#[test]
fn dirichlet_elimination_keeps_symmetry() {
    let mesh = single_box(BoxSpec::tet([0.0; 3], [1.0; 3], [3, 3, 3], 1));
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
    let q = |_: [f64; 3]| 1.0;
    let free_sys =
        heat::steady_conduction(&mesh, &dofs, &unit_material(1, 1.0), Some(&q), &[], &[]).unwrap();
    let bcs: Vec<(usize, f64)> = (0..dofs.len())
        .filter(|d| d % 5 == 0)
        .map(|d| (d, d as f64 * 0.1))
        .collect();
    let (mut a, mut b) = (free_sys.matrix.clone(), free_sys.rhs.clone());
    apply_dirichlet(&mut a, &mut b, &bcs).unwrap();
    let d = to_dense(&a);
    for i in 0..d.len() {
        for j in 0..d.len() {
            assert_eq!(d[i][j].to_bits(), d[j][i].to_bits(), "({i}, {j})");
        }
    }
    let mut x = b.clone();
    let mut chol = Cholesky::new(Ordering::Metis);
    chol.factor(&a).unwrap();
    chol.solve(&mut x).unwrap();
    for &(k, g) in &bcs {
        assert!((x[k] - g).abs() <= 1e-14 * g.abs().max(1.0));
    }
    // Reduced reference: K_ff u_f = f_f − K_fc g.
    let k0 = to_dense(&free_sys.matrix);
    let fixed: std::collections::HashMap<usize, f64> = bcs.iter().cloned().collect();
    let free: Vec<usize> = (0..dofs.len()).filter(|d| !fixed.contains_key(d)).collect();
    let kr: Vec<Vec<f64>> = free
        .iter()
        .map(|&i| free.iter().map(|&j| k0[i][j]).collect())
        .collect();
    let fr: Vec<f64> = free
        .iter()
        .map(|&i| free_sys.rhs[i] - fixed.iter().map(|(&c, g)| k0[i][c] * g).sum::<f64>())
        .collect();
    let ur = dense_solve(kr, fr);
    let err = max_abs(free.iter().zip(&ur).map(|(&i, u)| x[i] - u));
    assert!(err <= 1e-12 * max_abs(ur.iter().copied()), "{err:.3e}");
}

/// Values-only reassembly on a kept pattern gives the same matrix as a fresh one.
#[test]
fn values_only_reassembly_matches_fresh_assembly() {
    let mesh = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [4, 4, 4], 1));
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
    let mut pattern = Pattern::new(&mesh, &dofs);
    pattern.build().unwrap();
    let rule = Basis::standard(Topology::Hex8).unwrap();
    let (mesh_ref, rule_ref) = (&mesh, &rule);
    let kernel_k = move |k: f64| {
        move |e: seam::mesh::ElemId, ke: &mut [f64], _fe: &mut [f64]| {
            let x: Vec<[f64; 3]> = mesh_ref
                .elem_nodes(e)
                .iter()
                .map(|n| mesh_ref.coords[n.index()])
                .collect();
            kernel::conductivity(rule_ref, &x, |_| k, ke).unwrap();
        }
    };
    let mut asm = Assembler::new(&pattern);
    asm.elements(&mesh, None, kernel_k(1.0));
    let first = asm.matrix().unwrap();
    asm.elements(&mesh, None, kernel_k(2.0));
    let second = asm.matrix().unwrap();
    assert_eq!(first.symbolic().row_idx(), second.symbolic().row_idx());
    for (a, b) in first.val().iter().zip(second.val()) {
        assert_eq!(2.0 * a, *b);
    }
    // Row sums of a conductivity matrix vanish (constants are in its kernel).
    let mut y = vec![0.0; dofs.len()];
    seam::solve::spmv(&second, &vec![1.0; dofs.len()], &mut y);
    assert!(max_abs(y.into_iter()) < 1e-13);
    assert_eq!(pattern.nnz(), second.val().len());
}

/// The pattern and slot sums agree with faer's own triplet assembly of the same
/// entries (structure exactly, values to round-off: only the summation order
/// differs), on a two-field, two-block mesh with extra dofs and couplings.
#[test]
fn assembly_matches_faer_triplets() {
    use faer::sparse::Triplet;
    let mesh = seam::mesh::generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [3, 2, 2], 1),
            BoxSpec::tet([1.0, 0.0, 0.0], [2.0, 1.0, 1.0], [2, 2, 2], 2),
        ],
        true,
    );
    let mut dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0, 1]), ("voltage", &[1])]).unwrap();
    let extra = dofs.add_extra(3);
    let mut pattern = Pattern::new(&mesh, &dofs);
    let couplings = [
        (extra.start, 0),
        (extra.start + 1, 5),
        (extra.start + 2, 40),
        (3, 60),
    ];
    pattern.add_couplings(&couplings).unwrap();
    pattern.build().unwrap();
    let mut asm = Assembler::new(&pattern);
    // Element "matrices" with distinct, non-symmetric values that depend on the element.
    asm.elements(&mesh, None, |e, ke, fe| {
        for (k, v) in ke.iter_mut().enumerate() {
            *v = 1.0 + e.0 as f64 * 0.01 + k as f64 * 1e-3;
        }
        fe.iter_mut().for_each(|f| *f = 1.0);
    });
    for k in 0..couplings.len() {
        asm.add_coupling(k, 2.0 + k as f64, -1.0 - k as f64);
    }
    for d in extra.clone() {
        asm.add_diagonal(d, -0.5);
    }
    let a = asm.matrix().unwrap();
    let mut triplets = Vec::new();
    let mut buf = Vec::new();
    for e in 0..mesh.num_elems() {
        let e = seam::mesh::ElemId(e as u32);
        dofs.elem_dofs(&mesh, e, &mut buf);
        let ne = buf.len();
        for (a, &r) in buf.iter().enumerate() {
            for (b, &c) in buf.iter().enumerate() {
                let v = 1.0 + e.0 as f64 * 0.01 + (a * ne + b) as f64 * 1e-3;
                triplets.push(Triplet::new(r as usize, c as usize, v));
            }
        }
    }
    for (k, &(i, j)) in couplings.iter().enumerate() {
        triplets.push(Triplet::new(i, j, 2.0 + k as f64));
        triplets.push(Triplet::new(j, i, -1.0 - k as f64));
    }
    for d in 0..dofs.len() {
        let v = if extra.contains(&d) { -0.5 } else { 0.0 };
        triplets.push(Triplet::new(d, d, v));
    }
    let b = SparseColMat::try_new_from_triplets(dofs.len(), dofs.len(), &triplets).unwrap();
    assert_eq!(a.symbolic().col_ptr(), b.symbolic().col_ptr());
    assert_eq!(a.symbolic().row_idx(), b.symbolic().row_idx());
    for (x, y) in a.val().iter().zip(b.val()) {
        assert!((x - y).abs() <= 1e-14 * y.abs().max(1.0), "{x} vs {y}");
    }
    // Hex block elements carry one field (8 dofs), tet block elements two (8 dofs).
    assert_eq!(dofs.elem_dof_count(&mesh, 0), 8);
    assert_eq!(dofs.elem_dof_count(&mesh, 1), 8);
}

/// Convection (Robin) faces against the exact 1-D solution: T(0) = T₀, −kT′(1) =
/// h(T(1) − T∞), insulated elsewhere, gives the linear T = T₀ + s·x with
/// s = h(T∞ − T₀)/(k + h). Linear fields are reproduced exactly, so the nodal values
/// match to round-off, on Hex8 and Tet4 (whose x = 1 sides are triangles).
#[test]
fn convection_faces_reproduce_exact_robin_solution() {
    let (k, h, t0, t_inf) = (2.0, 5.0, 400.0, 300.0);
    let s = h * (t_inf - t0) / (k + h);
    for spec in [
        BoxSpec::hex([0.0; 3], [1.0, 0.5, 0.5], [4, 2, 2], 1),
        BoxSpec::tet([0.0; 3], [1.0, 0.5, 0.5], [4, 2, 2], 1),
    ] {
        let mesh = single_box(spec.with_side_sets([0, 2, 0, 0, 0, 0]));
        let right = mesh.side_sets.iter().find(|s| s.id == 2).unwrap();
        let faces: Vec<FaceBc> = right
            .sides
            .iter()
            .map(|&side| FaceBc::Convection { side, h, t_inf })
            .collect();
        let bc: Vec<(NodeId, f64)> = (0..mesh.num_nodes())
            .filter(|&i| mesh.coords[i][0] == 0.0)
            .map(|i| (NodeId(i as u32), t0))
            .collect();
        let t = solve_steady(&mesh, k, None, &bc, &faces);
        let err = max_abs(t.iter().zip(&mesh.coords).map(|(t, p)| t - (t0 + s * p[0])));
        assert!(
            err <= 1e-12 * t0,
            "{:?}: {err:.3e}",
            mesh.blocks[0].topology
        );
    }
}
