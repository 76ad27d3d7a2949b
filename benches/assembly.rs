//! Benchmark: the assembly kernels, per element and per contact point (plain `main`,
//! `cargo bench --bench assembly`; release profile). Run it on one thread for the
//! per-core figures: `RAYON_NUM_THREADS=1 cargo bench --bench assembly`.
//!
//! Cases:
//! - Hex8 conduction on a smoothly distorted `c³`-cell cube (c = 60, 216 000 elements;
//!   `-- large` for c = 100, 1 000 000): the conductivity kernel alone (element
//!   coordinates gathered, `Ke` computed into a stack array, element after element),
//!   the nonlinear kernel of the transient solver (`R` and `J` at a temperature, k
//!   constant, so dk/dT = 0 as for a linear law), `assemble_conduction` into a kept pattern (kernels writing their slots),
//!   and the slot sum into the CSC values, into a new matrix (`Assembler::matrix`) or
//!   the kept one (`Assembler::refresh_matrix`);
//! - interface terms of a gap conductance (constant h) on a non-matching planar
//!   interface, 2 × 2 Gauss points per side-A face (250 × 250 side-A faces under
//!   225 × 225 side-B faces, 250 000 points; `-- large` for 500 × 500 under 450 × 450,
//!   1 000 000): the geometry once per search (`InterfacePoints::new`), the evaluation
//!   at a field (`InterfacePoints::evaluate`), the addition into an assembler
//!   (`InterfaceSystem::add_scattered`), the two fused (`InterfacePoints::evaluate_into`,
//!   values refreshed in place), and `interface_terms` (geometry + evaluation);
//!   also the set-up a search brings, the couplings and their slots.
//!
//! Times are medians of `SEAM_BENCH_REPS` repetitions (default 5), per element or per
//! matched point, in process CPU time (on one thread the work's own time, less moved
//! by other work on a shared machine than the wall clock). Next to the times, errors that say the work was right: for the
//! conduction matrix `max |K·1| / max |K|` (a conduction matrix annihilates constants)
//! and `|K·x − F|`-type consistency is left to the tests; for the interface the heat
//! imbalance `|Q_A + Q_B|` relative to `|Q_A|` at a field with a jump.

use std::hint::black_box;

use seam::assembly::{Assembler, DofMap, Pattern};
use seam::enforce::interface::{
    DEFAULT_BETA, Form, HInput, HValue, InterfaceForm, InterfacePoints, interface_terms,
};
use seam::heat::{Basis, Material, TEMPERATURE, assemble_conduction, kernel};
use seam::mesh::generate::{self, BoxSpec, single_box};
use seam::mesh::{Mesh, NodeId, Topology};
use seam::search::SearchSettings;
use seam::search::pairing::{Integration, PointStatus, Searcher, SurfaceGeometry};

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU time of the whole process, in seconds: on a machine shared with other work it
/// moves less than the wall clock (the process is charged only while it runs).
fn cpu_seconds() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `clock_gettime` writes one `timespec` through a valid pointer.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut t) };
    assert_eq!(rc, 0, "clock_gettime");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// Median of `reps` timings of `f`, in seconds of process CPU time (one thread: the
/// work's own time).
fn timed(reps: usize, mut f: impl FnMut()) -> f64 {
    median(
        (0..reps)
            .map(|_| {
                let t = cpu_seconds();
                f();
                cpu_seconds() - t
            })
            .collect(),
    )
}

/// A `c³`-cell unit cube with its interior nodes moved by a smooth map, so that no
/// element is a parallelepiped (the kernels then do their general work).
fn distorted_cube(c: usize) -> Mesh {
    let mut mesh = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [c, c, c], 1));
    let h = 1.0 / c as f64;
    for p in &mut mesh.coords {
        let s = |v: f64| (std::f64::consts::PI * v).sin();
        let bump = 0.2 * h * s(p[0]) * s(p[1]) * s(p[2]);
        p[0] += bump;
        p[1] -= 0.7 * bump;
        p[2] += 0.4 * bump;
    }
    mesh
}

fn conduction(c: usize, reps: usize) {
    let mesh = distorted_cube(c);
    let ne = mesh.num_elems();
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
    let basis = Basis::standard(Topology::Hex8).unwrap();
    let block = &mesh.blocks[0];
    let coords = |k: usize| {
        let mut x = [[0.0; 3]; 8];
        for (a, n) in block.elem_nodes(k).iter().enumerate() {
            x[a] = mesh.coords[n.index()];
        }
        x
    };
    let t_kernel = timed(reps, || {
        let mut ke = [0.0; 64];
        for k in 0..ne {
            ke.fill(0.0);
            kernel::conductivity(&basis, &coords(k), |_| 1.0, &mut ke).unwrap();
            black_box(&ke);
        }
    });
    let t_nonlinear = timed(reps, || {
        let (mut re, mut je) = ([0.0; 8], [0.0; 64]);
        let t = [300.0, 301.0, 302.0, 303.0, 304.0, 305.0, 306.0, 307.0];
        for k in 0..ne {
            re.fill(0.0);
            je.fill(0.0);
            kernel::conduction_residual_jacobian(
                &basis,
                &coords(k),
                &t,
                |_, _| (1.0, 0.0),
                &mut re,
                &mut je,
            )
            .unwrap();
            black_box((&re, &je));
        }
    });
    let t0 = cpu_seconds();
    let mut pattern = Pattern::new(&mesh, &dofs);
    pattern.build().unwrap();
    let t_pattern = cpu_seconds() - t0;
    let mat = [Material {
        conductivity: 2.0,
        rho_c: 1.0,
    }];
    let mut asm = Assembler::new(&pattern);
    let t_assemble = timed(reps, || {
        assemble_conduction(&mut asm, &mesh, &dofs, &mat, None, &[]).unwrap();
    });
    let mut a = None;
    let t_sum = timed(reps, || a = Some(asm.matrix().unwrap()));
    let mut a = a.unwrap();
    let t_refresh = timed(reps, || asm.refresh_matrix(&mut a).unwrap());
    // Row sums of a conduction matrix vanish: max |K·1| against the largest entry.
    let mut ones = vec![0.0; a.nrows()];
    let (sym, vals) = (a.symbolic(), a.val());
    for j in 0..a.ncols() {
        for p in sym.col_range(j) {
            ones[sym.row_idx()[p]] += vals[p];
        }
    }
    let big = vals.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let row_sum = ones.iter().fold(0.0f64, |m, v| m.max(v.abs())) / big;
    let us = |t: f64| t * 1e6 / ne as f64;
    println!(
        "Hex8 conduction, {c}³ = {ne} elements, {} unknowns",
        dofs.len()
    );
    println!("| phase | median s | µs per element |");
    println!("|---|---:|---:|");
    for (phase, t) in [
        ("conductivity kernel alone", t_kernel),
        ("nonlinear kernel (R and J) alone", t_nonlinear),
        ("assemble_conduction (kernels into slots)", t_assemble),
        ("slot sum into a new CSC matrix (Assembler::matrix)", t_sum),
        (
            "slot sum into the kept matrix (Assembler::refresh_matrix)",
            t_refresh,
        ),
        ("pattern build (once)", t_pattern),
    ] {
        println!("| {phase} | {t:.4} | {:.3} |", us(t));
    }
    println!(
        "max |K·1| / max |K| = {row_sum:.1e} ({:.1}M stored entries)",
        a.compute_nnz() as f64 / 1e6
    );
}

fn interface(n: usize, reps: usize) {
    let m = n * 9 / 10;
    let mesh = generate::boxes(
        &[
            BoxSpec::hex([0.0; 3], [1.0, 1.0, 0.01], [n, n, 1], 1)
                .with_side_sets([0, 0, 0, 0, 0, 1]),
            BoxSpec::hex([0.0, 0.0, 0.01], [1.0, 1.0, 0.02], [m, m, 1], 2)
                .with_side_sets([0, 0, 0, 0, 2, 0]),
        ],
        false,
    );
    let a = SurfaceGeometry::from_side_set(&mesh, 0).unwrap();
    let b = SurfaceGeometry::from_side_set(&mesh, 1).unwrap();
    let settings = SearchSettings::defaults(3);
    let r = Searcher::new(&b, &settings).search_points(
        &a,
        &b,
        &settings,
        Integration::Quadrature { order: 2 },
        None,
    );
    let matched = r
        .points
        .iter()
        .filter(|p| p.status == PointStatus::Matched)
        .count();
    let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0, 1])]).unwrap();
    let field = dofs.field(TEMPERATURE).unwrap();
    // A field with a gradient and a jump of 1 across the interface (side B's nodes up).
    let mut on_b = vec![false; mesh.num_nodes()];
    for n in &mesh.blocks[1].connectivity {
        on_b[n.index()] = true;
    }
    let mut u = vec![0.0; dofs.len()];
    for (i, (p, &b)) in mesh.coords.iter().zip(&on_b).enumerate() {
        let jump = if b { 1.0 } else { 0.0 };
        let d = dofs.dof(field, NodeId(i as u32)).unwrap();
        u[d.index()] = 300.0 + 10.0 * p[0] - 5.0 * p[1] + 100.0 * p[2] + jump;
    }
    let k = [16.0, 200.0];
    let h = |_: &HInput| {
        Ok(HValue {
            h: 1e4,
            ..HValue::default()
        })
    };
    let form = InterfaceForm {
        form: Form::GapConductance,
        h: &h,
        offset: 0.0,
        beta: DEFAULT_BETA,
        conductivity: &k,
        conductivity_of_t: None,
        temperature_field: None,
    };
    let mut points = None;
    let t_new = timed(reps, || {
        points = Some(InterfacePoints::new(&mesh, &dofs, field, &a, &b, &r.points, &form).unwrap())
    });
    let points = points.unwrap();
    let mut system = None;
    let t_eval = timed(reps, || system = Some(points.evaluate(&form, &u).unwrap()));
    let system = system.unwrap();
    let mut pattern = Pattern::new(&mesh, &dofs);
    let mut couplings = Vec::new();
    let t_couplings = timed(reps, || couplings = points.couplings());
    let first = pattern.add_couplings(&couplings).unwrap().start;
    pattern.build().unwrap();
    let mut scatter = None;
    let t_scatter = timed(reps, || scatter = Some(points.scatter(&couplings, 0)));
    let scatter = scatter.unwrap();
    let mut asm = Assembler::new(&pattern);
    let t_add = timed(reps, || {
        asm.reset_couplings();
        system.add_scattered(&mut asm, &scatter, first);
    });
    let mut direct = None;
    let t_into = timed(reps, || {
        asm.reset_couplings();
        direct = Some(
            points
                .evaluate_into(&form, &u, &mut asm, &scatter, first)
                .unwrap(),
        );
    });
    let direct = direct.unwrap();
    let t_terms = timed(reps.min(3), || {
        black_box(interface_terms(&mesh, &dofs, field, &a, &b, &r.points, &form, &u).unwrap());
    });
    let (qa, qb) = system.heat();
    assert_eq!(direct.heat(), (qa, qb));
    let us = |t: f64| t * 1e6 / matched as f64;
    println!(
        "Interface terms, gap conductance h = 1e4, {n}² side-A faces under {m}², {matched} points in {} element pairs",
        points.groups()
    );
    println!("| phase | median s | µs per point |");
    println!("|---|---:|---:|");
    for (phase, t) in [
        ("geometry, once per search (InterfacePoints::new)", t_new),
        ("couplings, once per search", t_couplings),
        ("scatter slots, once per search", t_scatter),
        ("evaluation at a field (evaluate)", t_eval),
        ("addition into the assembler (add_scattered)", t_add),
        ("evaluation + addition", t_eval + t_add),
        ("evaluation into the assembler (evaluate_into)", t_into),
        ("interface_terms (geometry + evaluation)", t_terms),
    ] {
        println!("| {phase} | {t:.4} | {:.3} |", us(t));
    }
    println!(
        "heat leaving A {qa:.6e}, imbalance |Q_A + Q_B| / |Q_A| = {:.1e}",
        (qa + qb).abs() / qa.abs()
    );
}

fn main() {
    let large = std::env::args().any(|a| a == "large");
    let reps = std::env::var("SEAM_BENCH_REPS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    eprintln!("rayon threads: {}", rayon::current_num_threads());
    let (c, n) = if large { (100, 500) } else { (60, 250) };
    // `SEAM_BENCH_ONLY=conduction` or `=interface` runs one part (for profiling).
    let only = std::env::var("SEAM_BENCH_ONLY").unwrap_or_default();
    if only != "interface" {
        conduction(c, reps);
        println!();
    }
    if only != "conduction" {
        interface(n, reps);
    }
}
