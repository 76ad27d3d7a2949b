//! Unit tests of the interface evaluation: the regrouped blocks against the form
//! written entry by entry, and the couplings, scatter slots and in-place evaluation
//! against the plain additions.

use super::*;
use crate::assembly::Pattern;
use crate::mesh::generate::{self, BoxSpec};
use crate::search::SearchSettings;
use crate::search::pairing::{Integration, SearchResult, Searcher};

/// A 4 × 4-face slab under a 3 × 3-face one (non-matching, slightly tilted so the
/// normals and gradients are not axis-aligned), with a temperature-dependent h.
fn scene() -> (Mesh, DofMap, InterfacePoints, Vec<f64>) {
    let mut mesh = slabs([4, 2], [3, 2], [0.5, 1.0]);
    for p in &mut mesh.coords {
        p[2] += 0.1 * p[0] - 0.05 * p[1];
    }
    let (a, b, r, dofs) = paired(&mesh);
    let field = dofs.field("temperature").unwrap();
    let points = InterfacePoints::new(&mesh, &dofs, field, &a, &b, &r.points, &form(&H)).unwrap();
    let u = (0..dofs.len()).map(|d| 300.0 + (d % 7) as f64).collect();
    (mesh, dofs, points, u)
}

/// A slab over the unit square, `lower[0]` cells a side and `lower[1]` through its
/// height up to `z[0]`, with side set 1 on its top, under another of `upper` cells up to
/// `z[1]` with side set 2 on its bottom.
fn slabs(lower: [usize; 2], upper: [usize; 2], z: [f64; 2]) -> Mesh {
    let ([n, nz], [m, mz]) = (lower, upper);
    generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, z[0]], [n, n, nz], 1)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0, 0.0, z[0]], [1.0, 1.0, z[1]], [m, m, mz], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    )
}

/// The slabs' faces paired by 2 × 2 Gauss points of side A, and the temperature dofs.
fn paired(mesh: &Mesh) -> (SurfaceGeometry, SurfaceGeometry, SearchResult, DofMap) {
    let a = SurfaceGeometry::from_side_set(mesh, 0).unwrap();
    let b = SurfaceGeometry::from_side_set(mesh, 1).unwrap();
    let settings = SearchSettings::defaults(3);
    let r = Searcher::new(&b, &settings).search_points(
        &a,
        &b,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    let dofs = DofMap::new(mesh, &[("temperature", &[0, 1])]).unwrap();
    (a, b, r, dofs)
}

static H: fn(&HInput) -> Result<HValue, String> = |p| {
    Ok(HValue {
        h: 50.0 + 0.1 * p.temp_a + 0.2 * p.temp_b,
        dh_dtemp_a: 0.1,
        dh_dtemp_b: 0.2,
        ..HValue::default()
    })
};

fn form<'a>(h: &'a HFn<'a>) -> InterfaceForm<'a> {
    InterfaceForm {
        form: Form::GapConductance,
        h,
        offset: 0.5,
        beta: DEFAULT_BETA,
        conductivity: &[16.0, 200.0],
        conductivity_of_t: None,
        temperature_field: None,
    }
}

/// The blocks of `evaluate` against the form written entry by entry,
/// `w [P J_i J_j − θ (F_i J_j + J_i F_j) − S F_i F_j + (∂r_i/∂h) ∂h/∂u_j]`: equal to
/// round-off (1e-14 of the block's largest entry; the evaluation regroups the terms).
#[test]
fn evaluated_blocks_are_the_form() {
    let (_, _, points, u) = scene();
    let f = form(&H);
    let system = points.evaluate(&f, &u).unwrap();
    assert!(points.groups() > 9);
    for (g, (dofs, m)) in system.blocks.iter().enumerate() {
        let nl = dofs.len();
        let mut want = vec![0.0; nl * nl];
        for p in &points.points[points.group_points[g]..points.group_points[g + 1]] {
            let e = points.at_point((g, p), &f, &u).unwrap();
            let ([cp, ct, cs], [dp, dt, ds]) = coefficients(f.form, e.hv.h, p.alpha);
            for i in 0..nl {
                let (ji, fi) = (e.jump[i], e.flux[i]);
                let dr =
                    dp * ji * e.jump_u - dt * (fi * e.jump_u + ji * e.flux_u) - ds * fi * e.flux_u;
                for j in 0..nl {
                    let (jj, fj) = (e.jump[j], e.flux[j]);
                    let dh = if j < p.na as usize {
                        e.hv.dh_dtemp_a * jj
                    } else {
                        -e.hv.dh_dtemp_b * jj
                    };
                    let lin = cp * ji * jj - ct * (fi * jj + ji * fj) - cs * fi * fj;
                    want[i * nl + j] += p.weight * (lin + dr * dh);
                }
            }
        }
        let big = want.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        for (k, (v, w)) in m.iter().zip(&want).enumerate() {
            assert!(
                (v - w).abs() <= 1e-14 * big,
                "group {g} entry {k}: {v} vs {w}"
            );
        }
    }
}

/// The couplings are every pair of dofs met in a group, sorted and without repeats;
/// adding through the scatter slots gives the matrix that adding each entry with
/// `add_coupling`/`add_diagonal` gives, and `evaluate_into` gives the same bits and
/// the same residual.
#[test]
fn couplings_and_scatter_place_every_entry() {
    let (mesh, dofs, points, u) = scene();
    let mut want = Vec::new();
    for g in 0..points.groups() {
        let d = points.group(g);
        for a in 0..d.len() {
            for b in a + 1..d.len() {
                if d[a] != d[b] {
                    want.push((d[a].min(d[b]) as usize, d[a].max(d[b]) as usize));
                }
            }
        }
    }
    want.sort_unstable();
    want.dedup();
    let couplings = points.couplings();
    assert_eq!(couplings, want);
    let mut pattern = Pattern::new(&mesh, &dofs);
    pattern.add_couplings(&[(0, 1), (1, 2)]).unwrap();
    let first = pattern.add_couplings(&couplings).unwrap().start;
    pattern.build().unwrap();
    let system = points.evaluate(&form(&H), &u).unwrap();
    // Slots counted from this list's start, placed at `first` when added.
    let scatter = points.scatter(&couplings, 0);
    let mut fast = Assembler::new(&pattern);
    system.add_scattered(&mut fast, &scatter, first);
    let mut slow = Assembler::new(&pattern);
    for (d, m) in &system.blocks {
        let nl = d.len();
        for a in 0..nl {
            for b in 0..nl {
                let (i, j, v) = (d[a] as usize, d[b] as usize, m[a * nl + b]);
                if i == j {
                    slow.add_diagonal(i, v);
                } else {
                    let k = first + couplings.binary_search(&(i.min(j), i.max(j))).unwrap();
                    let (vij, vji) = if i < j { (v, 0.0) } else { (0.0, v) };
                    slow.add_coupling(k, vij, vji);
                }
            }
        }
    }
    let mut into = Assembler::new(&pattern);
    let direct = points
        .evaluate_into(&form(&H), &u, &mut into, &scatter, first)
        .unwrap();
    assert!(direct.blocks.is_empty());
    assert_eq!(direct.residual, system.residual);
    assert_eq!(direct.rhs, system.rhs);
    let (fast, slow, into) = (
        fast.matrix().unwrap(),
        slow.matrix().unwrap(),
        into.matrix().unwrap(),
    );
    assert!(fast.val().iter().any(|v| *v != 0.0));
    assert_eq!(fast.val(), slow.val());
    let bits = |m: &faer::sparse::SparseColMat<usize, f64>| -> Vec<u64> {
        m.val().iter().map(|v| v.to_bits()).collect()
    };
    assert_eq!(bits(&into), bits(&fast));
}

/// Built on one thread and on two, an interface of several runs of groups (36 864
/// points, more than two runs of `RUN`) gives the same points, values and groups; and
/// the layout is that of one pass in group order: every matched point once, groups of
/// increasing elements holding their points in pairing order, each point's jump and
/// flux entries right after the previous point's.
#[test]
fn points_made_in_runs_do_not_depend_on_the_thread_count() {
    let mesh = slabs([96, 1], [83, 1], [0.1, 0.2]);
    let (a, b, r, dofs) = paired(&mesh);
    let field = dofs.field("temperature").unwrap();
    let make = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            InterfacePoints::new(&mesh, &dofs, field, &a, &b, &r.points, &form(&H)).unwrap()
        })
    };
    let one = make(1);
    assert!(one.len() > 2 * points::RUN, "{} points", one.len());
    assert_eq!(format!("{one:?}"), format!("{:?}", make(2)));

    let matched = r
        .points
        .iter()
        .filter(|p| p.matched_b_face().is_some())
        .count();
    assert_eq!(one.points.len(), matched);
    let mut seen = vec![false; r.points.len()];
    let mut at = 0;
    let mut last_pair = None;
    for g in 0..one.groups() {
        let group = &one.points[one.group_points[g]..one.group_points[g + 1]];
        let nl = one.group(g).len();
        let (ka, _) = r.points[group[0].index as usize].matched_faces().unwrap();
        let kb = r.points[group[0].index as usize].matched_b_face().unwrap();
        let pair = (a.faces[ka].side.elem.0, b.faces[kb].side.elem.0);
        assert!(
            last_pair < Some(pair),
            "group {g}: {pair:?} after {last_pair:?}"
        );
        last_pair = Some(pair);
        for (k, p) in group.iter().enumerate() {
            assert!(
                k == 0 || group[k - 1].index < p.index,
                "group {g} out of order"
            );
            assert!(!std::mem::replace(&mut seen[p.index as usize], true));
            assert_eq!(p.at as usize, at, "group {g} point {k}");
            at += 2 * nl;
        }
    }
    assert_eq!(at, one.values.len());
}

/// The residual alone (what a heat query reads) is `evaluate`'s residual and
/// right-hand side bit for bit, and so is the heat; with a nonlinear h and an offset,
/// so that every term of the residual is in play.
#[test]
fn residual_alone_is_the_evaluated_residual() {
    let (_, _, points, u) = scene();
    let f = form(&H);
    let whole = points.evaluate(&f, &u).unwrap();
    let alone = points.residual(&f, &u).unwrap();
    assert!(alone.blocks.is_empty());
    assert!(whole.residual.iter().any(|&(_, v)| v != 0.0));
    let bits = |v: &[(u32, f64)]| v.iter().map(|&(d, x)| (d, x.to_bits())).collect::<Vec<_>>();
    assert_eq!(bits(&alone.residual), bits(&whole.residual));
    assert_eq!(bits(&alone.rhs), bits(&whole.rhs));
    assert_eq!(alone.heat(), whole.heat());
}
