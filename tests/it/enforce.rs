//! Enforcement verified on non-matching meshes: patch tests to round-off, the two-slab
//! solution with a jump q/h for every h, conservation.

use seam::enforce::interface::{DEFAULT_BETA, Form, HInput, HValue, InterfaceForm};
use seam::heat::Material;
use seam::heat::steady::{ContactTerm, SteadyProblem, solve_steady};
use seam::mesh::generate::{self, BoxSpec, SolidKind};
use seam::mesh::{Mesh, NodeId};
use seam::search::SearchSettings;
use seam::search::pairing::{Integration, Searcher, SurfaceGeometry};

/// Block 1 on [0,1]²×[0,1] (n1 cells a side), block 2 on [0,1]²×[1,2] (n2), meshed
/// apart; side set 1 = top of block 1, 2 = bottom of block 2.
fn slabs(n1: usize, n2: usize, kind: SolidKind) -> Mesh {
    let b = |min, max, n, id| BoxSpec {
        kind,
        ..BoxSpec::hex(min, max, [n, n, n], id)
    };
    generate::boxes(
        &[
            b([0.0; 3], [1.0; 3], n1, 1).with_side_sets([0, 0, 0, 0, 0, 1]),
            b([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], n2, 2).with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    )
}

fn geometry(mesh: &Mesh, set: usize) -> SurfaceGeometry {
    SurfaceGeometry::from_side_set(mesh, set).unwrap()
}

struct Setup {
    mesh: Mesh,
    a: SurfaceGeometry,
    b: SurfaceGeometry,
    points: Vec<seam::search::pairing::ContactPoint>,
}

fn setup(n1: usize, n2: usize, kind: SolidKind) -> Setup {
    let mesh = slabs(n1, n2, kind);
    let (a, b) = (geometry(&mesh, 0), geometry(&mesh, 1));
    let settings = SearchSettings::defaults(3);
    // Degree 5 on the overlap polygons: exact for the products of (bi)linear traces.
    let r = Searcher::new(&b, &settings).search(
        &a,
        &b,
        &settings,
        Integration::Segments { order: 5 },
        None,
    );
    assert_eq!(r.stats.matched, r.stats.points);
    Setup {
        mesh,
        a,
        b,
        points: std::sync::Arc::unwrap_or_clone(r.points),
    }
}

fn solve(
    s: &Setup,
    form: Form,
    h: f64,
    k: [f64; 2],
    dirichlet: &[(NodeId, f64)],
) -> seam::heat::steady::SteadySolution {
    let materials = [
        Material {
            conductivity: k[0],
            rho_c: 1.0,
        },
        Material {
            conductivity: k[1],
            rho_c: 1.0,
        },
    ];
    let hf = move |_: &HInput| {
        Ok(HValue {
            h,
            ..HValue::default()
        })
    };
    let problem = SteadyProblem {
        mesh: &s.mesh,
        materials: &materials,
        source: None,
        block_source: None,
        dirichlet,
        face_bcs: &[],
        ties: vec![],
        contact: vec![ContactTerm {
            side_a: &s.a,
            side_b: &s.b,
            points: &s.points,
            form: InterfaceForm {
                form,
                h: &hf,
                offset: 0.0,
                beta: DEFAULT_BETA,
                conductivity: &k,
                conductivity_of_t: None,
                temperature_field: None,
            },
            linear: true,
        }],
        interfaces: None,
        reproducible: true,
        iterative: false,
        tolerance: 1e-13,
        max_iterations: 3,
    };
    let sol = solve_steady(&problem).unwrap();
    assert!(sol.converged, "{:?}", sol.residual_history);
    sol
}

fn linear_field(p: [f64; 3]) -> f64 {
    1.0 + p[0] + 2.0 * p[1] - 3.0 * p[2]
}

/// Patch test: T = 1 + x + 2y − 3z on the outer boundary of two non-matching blocks
/// (3:2 hexes, 7:3 tets) is reproduced at every node to 1e-12 relative by the tied
/// forms — consistency plus exact (segment) integration leave no other error.
#[test]
fn linear_field_crosses_non_matching_ties_exactly() {
    for (n1, n2, kind) in [
        (3, 2, SolidKind::Hex8),
        (7, 3, SolidKind::Hex8),
        (3, 2, SolidKind::Tet4),
    ] {
        let s = setup(n1, n2, kind);
        let on_boundary = |p: [f64; 3]| {
            p[0] == 0.0 || p[0] == 1.0 || p[1] == 0.0 || p[1] == 1.0 || p[2] == 0.0 || p[2] == 2.0
        };
        let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
            .filter(|&i| on_boundary(s.mesh.coords[i]))
            .map(|i| (NodeId(i as u32), linear_field(s.mesh.coords[i])))
            .collect();
        for form in [
            Form::TiedNitsche,
            Form::TiedInteriorPenalty,
            Form::GapConductance,
        ] {
            let h = if form == Form::GapConductance {
                1e12
            } else {
                0.0
            };
            let sol = solve(&s, form, h, [1.0, 1.0], &dirichlet);
            let worst = (0..s.mesh.num_nodes())
                .map(|i| (sol.temperature[i] - linear_field(s.mesh.coords[i])).abs())
                .fold(0.0, f64::max);
            // Relative to the field's size (|T| ≤ 6 here). Gap conductance at h = 1e12
            // keeps a jump q/h ≈ 3e-12 and a penalty-sized condition number, hence 1e-10.
            let tol = if form == Form::GapConductance {
                1e-10
            } else {
                1e-12
            };
            assert!(
                worst < tol * 6.0,
                "{n1}:{n2} {kind:?} {form:?}: worst nodal error {worst:e}"
            );
        }
    }
}

/// Two slabs, T = 0 at z = 0 and T = 1 at z = 2, insulated sides: the exact solution is
/// linear in each slab, with flux q = 1/(1/k_A + 1/h + 1/k_B) (downwards, from B into
/// A) and a jump q/h at z = 1; the heat read off the interface residual is q through
/// each side, with opposite signs to round-off.
#[test]
fn two_slab_jump_is_exact_for_every_conductance() {
    let s = setup(3, 2, SolidKind::Hex8);
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter_map(|i| {
            let z = s.mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then(|| (NodeId(i as u32), z / 2.0))
        })
        .collect();
    let first_b = 4 * 4 * 4;
    for form in [Form::Conductance, Form::GapConductance] {
        for h in [1e-6, 1.0, 10.0, 1e6, 1e12] {
            for k in [[1.0, 1.0], [1.0, 5.0]] {
                if form == Form::Conductance && h > 1e6 {
                    continue; // a pure penalty at 1e12 loses 12 digits to conditioning
                }
                let sol = solve(&s, form, h, k, &dirichlet);
                let q = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
                let exact = |i: usize| {
                    let z = s.mesh.coords[i][2];
                    if i < first_b {
                        q * z / k[0]
                    } else {
                        1.0 - q * (2.0 - z) / k[1]
                    }
                };
                let worst = (0..s.mesh.num_nodes())
                    .map(|i| (sol.temperature[i] - exact(i)).abs())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-11, "{form:?} h={h} k={k:?}: worst {worst:e}");
                // Heat flows from the hot top (B) into A: side A *loses* −q.
                let (qa, qb) = sol.heat[0];
                assert!(
                    (qa + q).abs() < 1e-10 * q,
                    "{form:?} h={h}: heat {qa} vs {}",
                    -q
                );
                assert!(
                    (qa + qb).abs() <= 1e-12 * qa.abs().max(1e-300),
                    "imbalance {}",
                    qa + qb
                );
            }
        }
    }
}

/// The flux at each contact point (`point_flux`) on the two slabs: for the resistance,
/// Robin–Nitsche and tied forms it is the exact −q (from A to B) at every point, to
/// 1e-9 of q (the solution is exact to round-off, and the flux average differentiates
/// it on 1/3-size cells) plus 1e-14·h for the resistance form, whose q = h [u]
/// multiplies the round-off of the jump by h; for every form, Dash included, Σ w q over
/// the points is the heat read off the interface residual to 1e-12 relative (the two
/// differ only by the side-A flux-average rows, which sum to w_A k_A ∇(Σ N)·n = 0).
#[test]
fn point_flux_is_the_exact_flux_and_sums_to_the_heat() {
    use seam::enforce::interface::point_flux;
    let s = setup(3, 2, SolidKind::Hex8);
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter_map(|i| {
            let z = s.mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then(|| (NodeId(i as u32), z / 2.0))
        })
        .collect();
    let k = [1.0, 5.0];
    for (form, h) in [
        (Form::Conductance, 1.0),
        (Form::Conductance, 1e6),
        (Form::GapConductance, 1.0),
        (Form::GapConductance, 1e6),
        (Form::TiedNitsche, f64::INFINITY),
        (Form::TiedInteriorPenalty, f64::INFINITY),
        (Form::Penalty, f64::NAN),
    ] {
        let sol = solve(&s, form, if h.is_nan() { 1.0 } else { h }, k, &dirichlet);
        let hf = move |_: &HInput| {
            Ok(HValue {
                h: if h.is_nan() { 1.0 } else { h },
                ..HValue::default()
            })
        };
        let f = InterfaceForm {
            form,
            h: &hf,
            offset: 0.0,
            beta: DEFAULT_BETA,
            conductivity: &k,
            conductivity_of_t: None,
            temperature_field: None,
        };
        let field = sol.dofs.field("temperature").unwrap();
        let q = point_flux(&s.mesh, &sol.dofs, field, &s.a, &s.b, &s.points, &f, &sol.u).unwrap();
        assert_eq!(q.len(), s.points.len());
        let exact = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
        let (mut sum, mut worst) = (0.0, 0.0f64);
        for (p, v) in s.points.iter().zip(&q) {
            let v = v.expect("every point is matched");
            sum += p.weight * v.q;
            if !h.is_nan() {
                worst = worst.max((v.q + exact).abs() / exact);
            }
            if !h.is_nan() {
                let tol = if form == Form::Conductance {
                    1e-9 + 1e-14 * h
                } else {
                    1e-9
                };
                assert!(
                    (v.q + exact).abs() < tol * exact,
                    "{form:?} h={h}: q {} vs {}",
                    v.q,
                    -exact
                );
                // The temperatures either side of z = 1: T_A = q/k_A, T_B = 1 − q/k_B.
                assert!((v.temp_a - exact / k[0]).abs() < 1e-10, "{form:?}: T_A");
                assert!(
                    (v.temp_b - (1.0 - exact / k[1])).abs() < 1e-10,
                    "{form:?}: T_B"
                );
            }
        }
        let heat = sol.heat[0].0;
        eprintln!(
            "{form:?} h={h}: worst point error {worst:.1e} of q, Σ w q − heat = {:.1e} of heat",
            (sum - heat).abs() / heat.abs()
        );
        assert!(
            (sum - heat).abs() <= 1e-12 * heat.abs(),
            "{form:?} h={h}: Σ w q = {sum} vs heat {heat}"
        );
    }
}

/// Two concentric rings meshed apart, 3:2 around (inner 16m facets, outer 24m), 2m cells
/// through each wall, one layer of height 0.2: inner ring r ∈ [0.5, 1] (side A, its
/// outer face is side set 1), outer ring r ∈ [1, 1.5] (side B, inner face side set 2).
fn rings(m: usize) -> Setup {
    let a = generate::annulus(
        0.5,
        1.0,
        360.0,
        [0.0, 0.2],
        [2 * m, 16 * m, 1],
        1,
        [0, 1, 0, 0, 0, 0],
    );
    let b = generate::annulus(
        1.0,
        1.5,
        360.0,
        [0.0, 0.2],
        [2 * m, 24 * m, 1],
        2,
        [2, 0, 0, 0, 0, 0],
    );
    let mesh = generate::disjoint_union(&a, &b);
    let (ga, gb) = (geometry(&mesh, 0), geometry(&mesh, 1));
    let settings = SearchSettings::defaults(3);
    let r = Searcher::new(&gb, &settings).search(
        &ga,
        &gb,
        &settings,
        Integration::Segments { order: 5 },
        None,
    );
    assert_eq!(r.stats.matched, r.stats.points, "{:?}", r.stats);
    Setup {
        mesh,
        a: ga,
        b: gb,
        points: std::sync::Arc::unwrap_or_clone(r.points),
    }
}

/// The exact radial solution: T(0.5) = 0, T(1.5) = 1, T = c + d ln r in each ring with
/// k_A d_A = k_B d_B = q and a jump q/h at r = 1 (h = ∞ for ties).
fn ring_exact(k: [f64; 2], h: f64) -> impl Fn([f64; 3], bool) -> (f64, [f64; 3]) {
    let (l2, l15) = (2f64.ln(), 1.5f64.ln());
    let q = 1.0 / (l2 / k[0] + l15 / k[1] + 1.0 / h);
    move |p: [f64; 3], inner: bool| {
        let r2 = p[0] * p[0] + p[1] * p[1];
        let r = r2.sqrt();
        let d = if inner { q / k[0] } else { q / k[1] };
        let t = if inner {
            d * (r / 0.5).ln()
        } else {
            1.0 - d * (1.5 / r).ln()
        };
        (t, [d * p[0] / r2, d * p[1] / r2, 0.0])
    }
}

/// Solve on rings m = 1, 2, 4 with `solve_ring` (given the setup and the exact
/// Dirichlet data on r = 0.5 and r = 1.5) and check L2 rate 2 ± 0.1 and H1 rate 1 ± 0.1.
fn check_ring_rates(
    label: &str,
    k: [f64; 2],
    h: f64,
    solve_ring: impl Fn(&Setup, &[(NodeId, f64)]) -> seam::heat::steady::SteadySolution,
) {
    let exact = ring_exact(k, h);
    let mut errors = Vec::new();
    for m in [1, 2, 4] {
        let s = rings(m);
        let n_a = s.mesh.elem_nodes(s.mesh.blocks[1].first_elem)[0].index(); // ring B's first node
        let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
            .filter_map(|i| {
                let p = s.mesh.coords[i];
                let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
                ((r - 0.5).abs() < 1e-12 || (r - 1.5).abs() < 1e-12)
                    .then(|| (NodeId(i as u32), exact(p, i < n_a).0))
            })
            .collect();
        let sol = solve_ring(&s, &dirichlet);
        let mut e = (0.0, 0.0);
        for (blk, inner) in [(0usize, true), (1usize, false)] {
            let f = |p: [f64; 3]| exact(p, inner).0;
            let g = |p: [f64; 3]| exact(p, inner).1;
            let n = seam::heat::error_norms(&s.mesh, &[blk], &sol.temperature, &f, &g, 4).unwrap();
            e.0 += n.l2 * n.l2;
            e.1 += n.h1 * n.h1;
        }
        errors.push((e.0.sqrt(), e.1.sqrt()));
    }
    for w in errors.windows(2) {
        let (l2, h1) = ((w[0].0 / w[1].0).log2(), (w[0].1 / w[1].1).log2());
        eprintln!("{label}: L2 rate {l2:.3}, H1 rate {h1:.3}");
        assert!(
            (l2 - 2.0).abs() <= 0.1,
            "{label}: L2 rate {l2:.3} ({errors:?})"
        );
        assert!(
            (h1 - 1.0).abs() <= 0.1,
            "{label}: H1 rate {h1:.3} ({errors:?})"
        );
    }
}

/// Convergence across a curved non-matching interface with mortar ties (standard and
/// dual multipliers): L2 rate 2 ± 0.1, H1 rate 1 ± 0.1.
#[test]
fn curved_interface_converges_with_mortar_ties() {
    use seam::enforce::mortar::Multipliers;
    use seam::heat::steady::TieTerm;
    let k = [1.0, 3.0];
    for multipliers in [Multipliers::Standard, Multipliers::Dual] {
        check_ring_rates(
            &format!("{multipliers:?} mortar"),
            k,
            f64::INFINITY,
            |s, dirichlet| {
                let materials = [
                    Material {
                        conductivity: k[0],
                        rho_c: 1.0,
                    },
                    Material {
                        conductivity: k[1],
                        rho_c: 1.0,
                    },
                ];
                solve_steady(&SteadyProblem {
                    mesh: &s.mesh,
                    materials: &materials,
                    source: None,
                    block_source: None,
                    dirichlet,
                    face_bcs: &[],
                    contact: vec![],
                    ties: vec![TieTerm {
                        side_a: &s.a,
                        side_b: &s.b,
                        points: &s.points,
                        offset: 0.0,
                        multipliers,
                    }],
                    interfaces: None,
                    reproducible: true,
                    iterative: false,
                    tolerance: 1e-13,
                    max_iterations: 3,
                })
                .unwrap()
            },
        );
    }
}

/// Convergence across a curved non-matching interface: L2 rate 2 ± 0.1 and H1 rate
/// 1 ± 0.1 over three meshes, for every flux-type model.
#[test]
fn curved_interface_converges_at_optimal_rates() {
    let k = [1.0, 3.0];
    for (form, h) in [
        (Form::TiedNitsche, f64::INFINITY),
        (Form::TiedInteriorPenalty, f64::INFINITY),
        (Form::GapConductance, 10.0),
        (Form::Conductance, 10.0),
    ] {
        let hh = if h.is_finite() { h } else { 0.0 };
        check_ring_rates(&format!("{form:?}"), k, h, |s, dirichlet| {
            solve(s, form, hh, k, dirichlet)
        });
    }
}

/// Robustness: on the two slabs, h from 1e-8 to 1e12 and k_B/k_A from 1 to 1e8. The
/// exact solution is piecewise linear, so any error is round-off amplified by the
/// conditioning: it must stay finite and below 1e-6 of the temperature scale (1).
#[test]
fn gap_conductance_is_robust_over_h_and_conductivity_contrast() {
    let s = setup(3, 2, SolidKind::Hex8);
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter_map(|i| {
            let z = s.mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then(|| (NodeId(i as u32), z / 2.0))
        })
        .collect();
    let first_b = 4 * 4 * 4;
    let mut worst_all: f64 = 0.0;
    for h in [1e-8, 1e-4, 1.0, 1e4, 1e8, 1e12] {
        for ratio in [1.0, 1e2, 1e4, 1e8] {
            let k = [1.0, ratio];
            let sol = solve(&s, Form::GapConductance, h, k, &dirichlet);
            let q = 1.0 / (1.0 / k[0] + 1.0 / h + 1.0 / k[1]);
            for i in 0..s.mesh.num_nodes() {
                let z = s.mesh.coords[i][2];
                let exact = if i < first_b {
                    q * z / k[0]
                } else {
                    1.0 - q * (2.0 - z) / k[1]
                };
                let e = (sol.temperature[i] - exact).abs();
                assert!(
                    e.is_finite() && e < 1e-6,
                    "h={h} k_B/k_A={ratio}: error {e:e} at node {i}"
                );
                worst_all = worst_all.max(e);
            }
            let (qa, qb) = sol.heat[0];
            assert!(
                (qa + qb).abs() <= 1e-12 * qa.abs().max(f64::MIN_POSITIVE) + 1e-300,
                "h={h} ratio={ratio}"
            );
        }
    }
    eprintln!("worst nodal error over the sweep: {worst_all:e}");
}

/// The interface Jacobian, with a temperature-dependent conductance h = h₀(1 + γ T̄),
/// agrees with central differences of the interface residual to 1e-6 relative.
#[test]
fn interface_jacobian_matches_finite_differences() {
    let (h0, gamma) = (5.0, 0.3);
    let hf = move |p: &HInput| {
        let tm = 0.5 * (p.temp_a + p.temp_b);
        Ok(HValue {
            h: h0 * (1.0 + gamma * tm),
            dh_dtemp_a: 0.5 * h0 * gamma,
            dh_dtemp_b: 0.5 * h0 * gamma,
            ..HValue::default()
        })
    };
    for form in [Form::Conductance, Form::GapConductance] {
        assert_interface_jacobian(form, &hf, None);
    }
}

/// With a conductivity that changes with the temperature, k_1 = 2 (1 + 0.3 T) and k_2 =
/// 0.7 (1 + 0.5 T + 0.1 T²), every form weighs its flux and penalty with k at the
/// point's temperatures: the Jacobian, with those derivatives, agrees with central
/// differences for every form — the ties, Dash, a conductance below and above the
/// resistance limit (h = 5(1 + 0.3 T̄) and 1e5) and the Robin–Nitsche gap conductance.
#[test]
fn interface_jacobian_with_a_conductivity_of_t_matches_finite_differences() {
    let law = |b: usize, t: f64, _x: [f64; 3]| -> Result<(f64, f64), String> {
        Ok(match b {
            0 => (2.0 * (1.0 + 0.3 * t), 0.6),
            _ => (0.7 * (1.0 + 0.5 * t + 0.1 * t * t), 0.7 * (0.5 + 0.2 * t)),
        })
    };
    let varying = |p: &HInput| {
        let tm = 0.5 * (p.temp_a + p.temp_b);
        Ok(HValue {
            h: 5.0 * (1.0 + 0.3 * tm),
            dh_dtemp_a: 0.75,
            dh_dtemp_b: 0.75,
            ..HValue::default()
        })
    };
    let stiff = |_: &HInput| {
        Ok(HValue {
            h: 1e5,
            ..HValue::default()
        })
    };
    for form in [Form::TiedNitsche, Form::TiedInteriorPenalty, Form::Penalty] {
        assert_interface_jacobian(form, &stiff, Some(&law));
    }
    for form in [Form::Conductance, Form::GapConductance] {
        assert_interface_jacobian(form, &varying, Some(&law));
        assert_interface_jacobian(form, &stiff, Some(&law));
    }
}

/// The interface Jacobian of `form` (conductance `hf`, conductivities 2 and 0.7 or
/// `k_of_t`) on the two-slab setup against central differences of its residual, at a
/// smooth non-trivial field, to 1e-6 relative.
fn assert_interface_jacobian(
    form: Form,
    hf: &(dyn Fn(&HInput) -> Result<HValue, String> + Sync),
    k_of_t: Option<&seam::enforce::interface::ConductivityLaw<'_>>,
) {
    use seam::assembly::DofMap;
    use seam::enforce::interface::interface_terms;
    let s = setup(3, 2, SolidKind::Hex8);
    let dofs = DofMap::new(&s.mesh, &[("temperature", &[0, 1])]).unwrap();
    let field = dofs.field("temperature").unwrap();
    let k = [2.0, 0.7];
    // A smooth, non-trivial field.
    let u: Vec<f64> = (0..dofs.len())
        .map(|i| {
            let p = s.mesh.coords[i];
            1.0 + 0.3 * p[0] - 0.2 * p[1] * p[1] + 0.5 * p[2] + 0.1 * (3.0 * p[0]).sin()
        })
        .collect();
    let f = InterfaceForm {
        form,
        h: hf,
        offset: 0.1,
        beta: DEFAULT_BETA,
        conductivity: &k,
        conductivity_of_t: k_of_t,
        temperature_field: None,
    };
    let t = interface_terms(&s.mesh, &dofs, field, &s.a, &s.b, &s.points, &f, &u).unwrap();
    let residual = |u: &[f64]| {
        let t = interface_terms(&s.mesh, &dofs, field, &s.a, &s.b, &s.points, &f, u).unwrap();
        let mut r = vec![0.0; u.len()];
        for (d, v) in t.residual {
            r[d as usize] += v;
        }
        r
    };
    // The assembled Jacobian, dense (small problem).
    let n = dofs.len();
    let mut jac = vec![0.0; n * n];
    for (ds, m) in &t.blocks {
        let l = ds.len();
        for a in 0..l {
            for c in 0..l {
                jac[ds[a] as usize * n + ds[c] as usize] += m[a * l + c];
            }
        }
    }
    let mut checked = 0;
    // The central differences' round-off is about ε/δ ≈ 2e-10 of the residual, whose
    // size is the largest entry's: entries are held to 1e-6 of themselves, with a floor
    // of 1e-3 of the largest (1e-3 when all are smaller than 1).
    let largest = jac.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    for j in t.side_a_dofs.iter().chain(&t.side_b_dofs).step_by(3) {
        let j = *j as usize;
        let eps = 1e-6;
        let (mut up, mut dn) = (u.clone(), u.clone());
        up[j] += eps;
        dn[j] -= eps;
        let (rp, rm) = (residual(&up), residual(&dn));
        for i in 0..n {
            let fd = (rp[i] - rm[i]) / (2.0 * eps);
            let an = jac[i * n + j];
            let scale = an.abs().max(fd.abs()).max(1e-3 * largest);
            assert!(
                (fd - an).abs() <= 1e-6 * scale,
                "{form:?} (k(T): {}) J[{i}][{j}]: analytic {an} vs FD {fd}",
                k_of_t.is_some()
            );
        }
        checked += 1;
    }
    assert!(checked > 10);
}

/// A gas-gap conductance k_g / max(g, g_min) across gaps of 1e-12, 0 and −1e-9 (a slight
/// overlap): the results are finite and approach the tied solution, differing from it by
/// the jump q/h with h = k_g / g_min.
#[test]
fn tiny_zero_and_negative_gaps_approach_the_tie() {
    use seam::enforce::conductance::{ConductanceModel, GasGap, PointState};
    let gas = GasGap::new(0.025).unwrap();
    for gap in [1e-12, 0.0, -1e-9] {
        let mut mesh = slabs(3, 2, SolidKind::Hex8);
        let first_b = 4 * 4 * 4;
        for p in &mut mesh.coords[first_b..] {
            p[2] += gap;
        }
        let (a, b) = (geometry(&mesh, 0), geometry(&mesh, 1));
        let settings = SearchSettings::defaults(3);
        let r = Searcher::new(&b, &settings).search(
            &a,
            &b,
            &settings,
            Integration::Segments { order: 5 },
            None,
        );
        assert_eq!(r.stats.matched, r.stats.points, "gap {gap}");
        let s = Setup {
            mesh,
            a,
            b,
            points: std::sync::Arc::unwrap_or_clone(r.points),
        };
        let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
            .filter_map(|i| {
                let z = s.mesh.coords[i][2];
                (z == 0.0 || (z - 2.0 - gap).abs() < 1e-15)
                    .then_some((NodeId(i as u32), if z == 0.0 { 0.0 } else { 1.0 }))
            })
            .collect();
        let materials = [Material {
            conductivity: 1.0,
            rho_c: 1.0,
        }; 2];
        let hf = |p: &HInput| {
            let c = gas
                .evaluate(&PointState {
                    gap: p.gap,
                    pressure: 0.0,
                    temp_a: p.temp_a,
                    temp_b: p.temp_b,
                    x: p.x,
                    time: 0.0,
                })
                .map_err(|e| e.to_string())?;
            Ok(HValue {
                h: c.h,
                dh_dtemp_a: c.dh_dtemp_a,
                dh_dtemp_b: c.dh_dtemp_b,
                ..HValue::default()
            })
        };
        let k = [1.0, 1.0];
        let sol = solve_steady(&SteadyProblem {
            mesh: &s.mesh,
            materials: &materials,
            source: None,
            block_source: None,
            dirichlet: &dirichlet,
            face_bcs: &[],
            ties: vec![],
            contact: vec![ContactTerm {
                side_a: &s.a,
                side_b: &s.b,
                points: &s.points,
                form: InterfaceForm {
                    form: Form::GapConductance,
                    h: &hf,
                    offset: 0.0,
                    beta: DEFAULT_BETA,
                    conductivity: &k,
                    conductivity_of_t: None,
                    temperature_field: None,
                },
                linear: false,
            }],
            interfaces: None,
            reproducible: true,
            iterative: false,
            tolerance: 1e-12,
            max_iterations: 10,
        })
        .unwrap();
        assert!(
            sol.converged && sol.temperature.iter().all(|t| t.is_finite()),
            "gap {gap}"
        );
        // Tied: T = z/2 (up to the tiny shift of block B); the jump q/h is 0.5 / 25000.
        let h = 0.025 / 1e-6;
        let q = 1.0 / (1.0 + 1.0 / h + 1.0);
        for (i, t) in sol.temperature.iter().enumerate() {
            let z = s.mesh.coords[i][2];
            let tied = if i < first_b {
                z / 2.0
            } else {
                (z - gap) / 2.0
            };
            assert!(
                (t - tied).abs() <= q / h + 1e-9,
                "gap {gap}: node {i} T {t} vs tied {tied}"
            );
        }
    }
}

/// The mortar tie with Lagrange multipliers, standard (saddle point) and dual (condensed
/// to an SPD system), passes the linear patch test on hex 3:2, hex 7:3 and tet 3:2
/// non-matching meshes, with every outer node Dirichlet (so the interface rim is all
/// crosspoints).
#[test]
fn mortar_lagrange_tie_passes_the_patch_test() {
    use seam::enforce::mortar::Multipliers;
    use seam::heat::steady::TieTerm;
    for multipliers in [Multipliers::Standard, Multipliers::Dual] {
        for (n1, n2, kind) in [
            (3, 2, SolidKind::Hex8),
            (7, 3, SolidKind::Hex8),
            (3, 2, SolidKind::Tet4),
        ] {
            let s = setup(n1, n2, kind);
            let on_boundary = |p: [f64; 3]| {
                p[0] == 0.0
                    || p[0] == 1.0
                    || p[1] == 0.0
                    || p[1] == 1.0
                    || p[2] == 0.0
                    || p[2] == 2.0
            };
            let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
                .filter(|&i| on_boundary(s.mesh.coords[i]))
                .map(|i| (NodeId(i as u32), linear_field(s.mesh.coords[i])))
                .collect();
            let materials = [Material {
                conductivity: 1.0,
                rho_c: 1.0,
            }; 2];
            let sol = solve_steady(&SteadyProblem {
                mesh: &s.mesh,
                materials: &materials,
                source: None,
                block_source: None,
                dirichlet: &dirichlet,
                face_bcs: &[],
                contact: vec![],
                ties: vec![TieTerm {
                    side_a: &s.a,
                    side_b: &s.b,
                    points: &s.points,
                    offset: 0.0,
                    multipliers,
                }],
                interfaces: None,
                reproducible: true,
                iterative: false,
                tolerance: 1e-13,
                max_iterations: 3,
            })
            .unwrap();
            assert!(
                !sol.crosspoints[0].is_empty(),
                "the rim nodes are crosspoints"
            );
            let worst = (0..s.mesh.num_nodes())
                .map(|i| (sol.temperature[i] - linear_field(s.mesh.coords[i])).abs())
                .fold(0.0, f64::max);
            assert!(
                // 1e-12 relative to the field's size: |1 + x + 2y − 3z| ≤ 6 on the slabs.
                worst < 1e-12 * 6.0,
                "{multipliers:?} {n1}:{n2} {kind:?}: worst {worst:e}"
            );
            let (qa, qb) = sol.tie_heat[0];
            assert!(
                (qa + qb).abs() <= 1e-12 * qa.abs(),
                "{multipliers:?}: heat {qa} {qb}"
            );
        }
    }
}

/// Dash is a penalty tie: on the two slabs it leaves the jump q/P with
/// P = β_D k_eff / h_e (here h_e = 1/3, the smaller cell, and k_eff = 1), i.e. an error
/// it predicts; the temperatures match the two-slab solution with that conductance.
#[test]
fn dash_penalty_error_is_the_predicted_one() {
    let s = setup(3, 2, SolidKind::Hex8);
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter_map(|i| {
            let z = s.mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then_some((NodeId(i as u32), z / 2.0))
        })
        .collect();
    let first_b = 4 * 4 * 4;
    for factor in [10.0, 1e3, 1e6] {
        let materials = [Material {
            conductivity: 1.0,
            rho_c: 1.0,
        }; 2];
        let hf = |_: &HInput| Ok(HValue::default());
        let k = [1.0, 1.0];
        let sol = solve_steady(&SteadyProblem {
            mesh: &s.mesh,
            materials: &materials,
            source: None,
            block_source: None,
            dirichlet: &dirichlet,
            face_bcs: &[],
            ties: vec![],
            contact: vec![ContactTerm {
                side_a: &s.a,
                side_b: &s.b,
                points: &s.points,
                form: InterfaceForm {
                    form: Form::Penalty,
                    h: &hf,
                    offset: 0.0,
                    beta: factor,
                    conductivity: &k,
                    conductivity_of_t: None,
                    temperature_field: None,
                },
                linear: true,
            }],
            interfaces: None,
            reproducible: true,
            iterative: false,
            tolerance: 1e-13,
            max_iterations: 3,
        })
        .unwrap();
        let p = factor * 1.0 / (1.0 / 3.0);
        let q = 1.0 / (1.0 + 1.0 / p + 1.0);
        for i in 0..s.mesh.num_nodes() {
            let z = s.mesh.coords[i][2];
            let predicted = if i < first_b {
                q * z
            } else {
                1.0 - q * (2.0 - z)
            };
            assert!(
                (sol.temperature[i] - predicted).abs() < 1e-10,
                "factor {factor}: node {i}"
            );
        }
    }
}

/// Crosspoints: an interface tie (z = 1) meets Dirichlet faces (y = 0, 1; z = 0, 2) and
/// periodic faces (x = 0 ↔ x = 1 in both blocks), all tied with standard multipliers.
/// Nodes shared by two constraints are found and reported, the system solves, and a
/// field periodic in x (T = 1 + 2y − 3z) is reproduced to round-off.
#[test]
fn crosspoints_of_a_tie_with_dirichlet_and_periodic_faces() {
    use seam::enforce::mortar::Multipliers;
    use seam::heat::steady::TieTerm;
    use std::sync::Arc;
    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0; 3], [3, 3, 3], 1).with_side_sets([1, 2, 0, 0, 0, 3]),
            BoxSpec::hex([0.0, 0.0, 1.0], [1.0, 1.0, 2.0], [2, 2, 2], 2)
                .with_side_sets([4, 5, 0, 0, 6, 0]),
        ],
        false,
    );
    let deck = "begin contact definition
      contact surface a_top contains surface_3
      contact surface b_bottom contains surface_6
      contact surface a_left contains surface_1
      contact surface a_right contains surface_2
      contact surface b_left contains surface_4
      contact surface b_right contains surface_5
      begin interaction
        side a a_top
        side b b_bottom
      end
      periodicity for a_left = rectangular offset = 1 0 0
      periodicity for b_left = rectangular offset = 1 0 0
    end";
    let (d, diags) = seam::deck::parse_sierra(&Arc::from("deck.i"), deck);
    assert!(!diags.has_errors(), "{diags:?}");
    let def = &d.contact_definitions[0];
    let sources = seam::diag::SourceMap::default();
    let set = seam::scene::surfaces::build(&mesh, def, &sources);
    let (list, _) = seam::scene::interaction::resolve(def, &set, 3, &sources);
    let scene = seam::scene::search::search_definition(
        &mesh,
        def,
        &set,
        &list,
        std::path::Path::new("."),
        &sources,
        Integration::Segments { order: 5 },
    );
    assert!(!scene.diagnostics.has_errors(), "{:?}", scene.diagnostics);
    let names: Vec<(String, String)> = scene
        .pairings
        .iter()
        .map(|p| (p.side_a.clone(), p.side_b.clone()))
        .collect();
    assert_eq!(
        names,
        [
            ("a_top".into(), "b_bottom".into()),
            ("a_left".into(), "a_right".into()),
            ("b_left".into(), "b_right".into())
        ]
    );
    let field = |p: [f64; 3]| 1.0 + 2.0 * p[1] - 3.0 * p[2];
    let dirichlet: Vec<(NodeId, f64)> = (0..mesh.num_nodes())
        .filter(|&i| {
            let p = mesh.coords[i];
            p[1] == 0.0 || p[1] == 1.0 || p[2] == 0.0 || p[2] == 2.0
        })
        .map(|i| (NodeId(i as u32), field(mesh.coords[i])))
        .collect();
    let materials = [Material {
        conductivity: 1.0,
        rho_c: 1.0,
    }; 2];
    let ties = scene
        .pairings
        .iter()
        .map(|p| TieTerm {
            side_a: &p.side_a_geometry,
            side_b: &p.side_b_geometry,
            points: &p.result.points,
            offset: 0.0,
            multipliers: Multipliers::Standard,
        })
        .collect();
    let sol = solve_steady(&SteadyProblem {
        mesh: &mesh,
        materials: &materials,
        source: None,
        block_source: None,
        dirichlet: &dirichlet,
        face_bcs: &[],
        contact: vec![],
        ties,
        interfaces: None,
        reproducible: true,
        iterative: false,
        tolerance: 1e-13,
        max_iterations: 3,
    })
    .unwrap();
    // The periodic ties' side-A nodes on z = 1 belong to the interface tie already.
    for t in 1..3 {
        assert!(
            sol.crosspoints[t]
                .iter()
                .any(|n| (mesh.coords[n.index()][2] - 1.0).abs() < 1e-12),
            "tie {t}: no crosspoint with the interface tie"
        );
    }
    let worst = (0..mesh.num_nodes())
        .map(|i| (sol.temperature[i] - field(mesh.coords[i])).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-11, "worst nodal error {worst:e}");
}

/// The iterative path (AMG-preconditioned CG) gives the direct solution of a tied
/// non-matching problem to its tolerance.
#[test]
fn amg_cg_path_matches_the_direct_solve() {
    let s = setup(7, 3, SolidKind::Hex8);
    let on_boundary = |p: [f64; 3]| p[2] == 0.0 || p[2] == 2.0 || p[0] == 0.0;
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter(|&i| on_boundary(s.mesh.coords[i]))
        .map(|i| {
            (
                NodeId(i as u32),
                (3.0 * s.mesh.coords[i][0]).sin() + s.mesh.coords[i][2],
            )
        })
        .collect();
    let materials = [
        Material {
            conductivity: 1.0,
            rho_c: 1.0,
        },
        Material {
            conductivity: 4.0,
            rho_c: 1.0,
        },
    ];
    let hf = |_: &HInput| {
        Ok(HValue {
            h: 7.0,
            ..HValue::default()
        })
    };
    let k = [1.0, 4.0];
    let solve_with = |iterative: bool| {
        solve_steady(&SteadyProblem {
            mesh: &s.mesh,
            materials: &materials,
            source: None,
            block_source: None,
            dirichlet: &dirichlet,
            face_bcs: &[],
            ties: vec![],
            contact: vec![ContactTerm {
                side_a: &s.a,
                side_b: &s.b,
                points: &s.points,
                form: InterfaceForm {
                    form: Form::GapConductance,
                    h: &hf,
                    offset: 0.0,
                    beta: DEFAULT_BETA,
                    conductivity: &k,
                    conductivity_of_t: None,
                    temperature_field: None,
                },
                linear: true,
            }],
            interfaces: None,
            reproducible: true,
            iterative,
            tolerance: 1e-12,
            max_iterations: 5,
        })
        .unwrap()
    };
    let (direct, amg) = (solve_with(false), solve_with(true));
    assert!(amg.converged);
    let worst = direct
        .temperature
        .iter()
        .zip(&amg.temperature)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(worst < 1e-8, "AMG-CG differs from Cholesky by {worst:e}");
}

/// A temperature-dependent gap conductance makes the Newton Jacobian unsymmetric: with
/// `iterative` (the size `seam run` calls large) the steady Newton solves it by
/// AMG-preconditioned GMRES, its hierarchy kept across the iterations, and reaches LU's
/// answer.
#[test]
fn an_unsymmetric_newton_jacobian_at_scale_is_solved_by_gmres_as_by_lu() {
    use seam::heat::steady::LinearMethod;
    let s = setup(12, 8, SolidKind::Hex8);
    let dirichlet: Vec<(NodeId, f64)> = (0..s.mesh.num_nodes())
        .filter_map(|i| {
            let z = s.mesh.coords[i][2];
            (z == 0.0 || z == 2.0).then_some((NodeId(i as u32), if z == 0.0 { 0.0 } else { 1.0 }))
        })
        .collect();
    let materials = [Material {
        conductivity: 1.0,
        rho_c: 1.0,
    }; 2];
    // h = 2 (1 + T_A + T_B²): strongly nonlinear, and unsymmetric in its derivatives.
    let hf = |p: &HInput| {
        Ok(HValue {
            h: 2.0 * (1.0 + p.temp_a + p.temp_b * p.temp_b),
            dh_dtemp_a: 2.0,
            dh_dtemp_b: 4.0 * p.temp_b,
            ..HValue::default()
        })
    };
    let k = [1.0, 1.0];
    let solve = |iterative: bool| {
        solve_steady(&SteadyProblem {
            mesh: &s.mesh,
            materials: &materials,
            source: None,
            block_source: None,
            dirichlet: &dirichlet,
            face_bcs: &[],
            ties: vec![],
            contact: vec![ContactTerm {
                side_a: &s.a,
                side_b: &s.b,
                points: &s.points,
                form: InterfaceForm {
                    form: Form::GapConductance,
                    h: &hf,
                    offset: 0.0,
                    beta: DEFAULT_BETA,
                    conductivity: &k,
                    conductivity_of_t: None,
                    temperature_field: None,
                },
                linear: false,
            }],
            interfaces: None,
            reproducible: true,
            iterative,
            tolerance: 1e-10,
            max_iterations: 20,
        })
        .unwrap()
    };
    let (lu, gmres) = (solve(false), solve(true));
    assert!(lu.converged && gmres.converged);
    assert_eq!(lu.linear.method, Some(LinearMethod::Lu));
    assert_eq!(gmres.linear.method, Some(LinearMethod::Gmres));
    assert!(gmres.newton_iterations >= 3, "a nonlinear problem");
    let setups = gmres.linear.hierarchy_setups.unwrap();
    assert!(setups < gmres.newton_iterations, "{:?}", gmres.linear);
    assert_eq!(
        setups + gmres.linear.hierarchy_refreshes,
        gmres.newton_iterations
    );
    for (i, (x, y)) in gmres.temperature.iter().zip(&lu.temperature).enumerate() {
        assert!((x - y).abs() <= 1e-8, "node {i}: GMRES {x} vs LU {y}");
    }
    let (qg, ql) = (gmres.heat[0], lu.heat[0]);
    assert!((qg.0 - ql.0).abs() <= 1e-8 * ql.0.abs(), "{qg:?} vs {ql:?}");
}
