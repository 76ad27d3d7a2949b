//! A conductivity that changes with the temperature across a tie: two bars in series,
//! meshed apart (non-matching), k_i(T) = k_i0 (1 + 0.01 (T − 300)), held at 300 K and
//! 500 K at their ends. The Kirchhoff transform u(T) = (T − 300) + 0.005 (T − 300)² is
//! linear in each bar, so the 1-D solution is known in closed form. The ties must
//! converge to it at second order or better — which holds only if the Nitsche forms
//! weigh the interface flux with k at the temperature there, not at a probe temperature
//! (first-order errors of 0.17, 0.10, 0.05 K on 2, 4, 8 cells that way).

use seam::mesh::Mesh;
use seam::run::RunResult;

use crate::species::{L, L1};

const K0: [f64; 2] = [5.0, 2.0];

/// The bars with `n` and `n + 1` cells across.
fn bars(n: usize) -> Mesh {
    crate::species::bars([n, n + 1], [2 * n, 3 * n])
}

/// The Kirchhoff transform of k(T)/k0 and its inverse.
fn kirchhoff(t: f64) -> f64 {
    (t - 300.0) + 0.005 * (t - 300.0).powi(2)
}
fn temperature(u: f64) -> f64 {
    300.0 + (-1.0 + (1.0 + 0.02 * u).sqrt()) / 0.01
}

/// The closed form: the heat flux q (W/m², in −z) and T(z).
fn closed_form() -> (f64, impl Fn(f64) -> f64) {
    // q = k10 (u(Ti) − u(300))/L1 = k20 (u(500) − u(Ti))/L2: u(Ti) from the two.
    let l2 = L - L1;
    let (a, b) = (K0[0] / L1, K0[1] / l2);
    let ui = (a * kirchhoff(300.0) + b * kirchhoff(500.0)) / (a + b);
    let q = a * (ui - kirchhoff(300.0));
    let t = move |z: f64| match z <= L1 {
        true => temperature(kirchhoff(300.0) + q * z / K0[0]),
        false => temperature(kirchhoff(500.0) - q * (L - z) / K0[1]),
    };
    (q, t)
}

/// The bars under `enforcement` (its lines), k(T) per block, 300 K and 500 K at the ends.
fn run(name: &str, mesh: &Mesh, enforcement: &str) -> RunResult {
    let deck = format!(
        "begin contact definition bars\n contact surface a contains surface_2\n contact surface b contains surface_3\n\
         begin interaction\n  side a a\n  side b b\n end\n\
         begin enforcement thermal\n{enforcement}\n end\nend\n"
    );
    let problem = "[mesh]\nfile = \"bars.exo\"\n\
         [[material]]\nblocks = [\"block_1\"]\nconductivity = \"5 * (1 + 0.01 * (T - 300))\"\n\
         [[material]]\nblocks = [\"block_2\"]\nconductivity = \"2 * (1 + 0.01 * (T - 300))\"\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_1\"]\nvalue = 300.0\n\
         [[bc]]\nkind = \"temperature\"\nsurfaces = [\"surface_4\"]\nvalue = 500.0\n\
         [contact]\nfile = \"contact.i\"\n\
         [solve]\nkind = \"steady\"\ntolerance = 1e-12\n";
    crate::species::run_case(&format!("k-of-t-{name}"), mesh, &deck, problem)
}

#[test]
fn every_tie_holds_a_temperature_dependent_conductivity() {
    let (q, exact) = closed_form();
    // The mortar tie is nodally exact; the Nitsche forms use the elements' flux at the
    // interface, which for a T that is not linear in the element differs from the exact
    // flux at second order: their error must fall at least 3.5× per halving (or be at
    // round-off already), from a small start (they were first order, 0.17 K at 2 cells,
    // with k at a probe temperature).
    let cases = [
        ("nitsche", "  enforcement for energy = tied_temperature"),
        (
            "interior-penalty",
            "  enforcement for energy = tied_ip_temperature",
        ),
        (
            "mortar",
            "  enforcement for energy = tied\n  side b variable temperature to temperature",
        ),
        (
            "near-tie-conductance",
            "  enforcement for energy = gap_conductance\n  gap conductance coefficient = constant h = 1e13",
        ),
        (
            "dash",
            "  enforcement for energy = dash\n  dash penalty factor = 1e8",
        ),
    ];
    for (name, enforcement) in cases {
        let mut errors = Vec::new();
        for n in [2, 4] {
            let r = run(&format!("{name}-{n}"), &bars(n), enforcement);
            let t = &r.solution.temperature;
            let worst = (r.mesh.coords.iter().zip(t))
                .filter(|(x, _)| (x[2] - L1).abs() > 1e-12)
                .map(|(x, v)| (v - exact(x[2])).abs())
                .fold(0.0f64, f64::max);
            let heat = r.summary.interactions[0].heat_side_b;
            eprintln!(
                "k(T) {name}, {n} cells: worst {worst:.2e} K, heat {heat:.12} (closed form {q:.12}), {} Newton",
                r.solution.newton_iterations
            );
            assert!(
                (heat - q).abs() <= 1e-7 * q,
                "{name}, {n} cells: heat {heat} against {q}"
            );
            assert!(
                r.solution.newton_iterations <= 8,
                "{name}: Newton took {}",
                r.solution.newton_iterations
            );
            errors.push(worst);
        }
        match name {
            "mortar" => assert!(errors[1] <= 1e-9, "{name}: {errors:?}"),
            // A penalty: its jump q/α (1e-7 K at a factor 1e8) bounds it.
            "dash" => assert!(errors.iter().all(|&e| e <= 1e-6), "{name}: {errors:?}"),
            _ => assert!(
                errors[0] <= 1e-5 && (errors[1] <= errors[0] / 3.5 || errors[1] <= 1e-11),
                "{name}: nodal errors {errors:?} K at 2 and 4 cells"
            ),
        }
    }
}
