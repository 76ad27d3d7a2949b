//! A Rust host that owns its mesh, its dof numbering and its matrix, and takes only the
//! interface terms from seam (`seam::embed`).
//!
//! The scene is `examples/two_blocks` (base k = 16 with its bottom at 300 K, lid k = 200
//! with its top at 400 K, gap conductance h = 500 between `base_top` and `lid_bottom`,
//! from `contact_run.i`). The host reads the mesh (here with seam's reader, standing in
//! for its own), numbers its unknowns its own way (backwards), assembles trilinear
//! conduction into a dense matrix with seam's public kernels, adds seam's residual and
//! Jacobian, takes Newton steps with its own dense solver, and prints the heat.
//!
//! `cargo run --example embed` (optionally with the scene's folder as argument).

use std::error::Error;
use std::path::{Path, PathBuf};

use seam::embed::{Embedding, EmbeddingBuilder, Heat};
use seam::fem::Basis;
use seam::heat::kernel::conductivity;
use seam::mesh::Mesh;

/// The host's answer: the interface heat, and how many Newton steps it took.
pub struct Outcome {
    pub heat: Heat,
    pub newton_steps: usize,
}

/// The scene's conductivity by block name.
pub fn conductivity_of(block: &str) -> f64 {
    if block == "base" { 16.0 } else { 200.0 }
}

/// The host's own numbering: node i is unknown n - 1 - i.
pub fn host_dofs(mesh: &Mesh) -> Vec<usize> {
    let n = mesh.num_nodes();
    (0..n).map(|i| n - 1 - i).collect()
}

/// Hand the mesh over as plain arrays: blocks, and the side sets as (element, side).
pub fn embedding(mesh: &Mesh, dof: &[usize]) -> EmbeddingBuilder {
    embedding_with(mesh, dof, conductivity_of)
}

/// As [`embedding`], with the conductivity `k(block name)` of another scene.
pub fn embedding_with(mesh: &Mesh, dof: &[usize], k: impl Fn(&str) -> f64) -> EmbeddingBuilder {
    let mut builder = Embedding::builder(&mesh.coords);
    for block in &mesh.blocks {
        let conn: Vec<usize> = block.connectivity.iter().map(|n| n.index()).collect();
        builder = builder.block(&block.name, block.topology, &conn, k(&block.name));
    }
    for set in &mesh.side_sets {
        let sides: Vec<(usize, u8)> = set.sides.iter().map(|s| (s.elem.index(), s.side)).collect();
        builder = builder.side_set(&set.name, &sides);
    }
    builder.dofs(dof)
}

/// Conduction of every block, dense (row-major), in host numbering.
pub fn conduction(mesh: &Mesh, dof: &[usize]) -> Result<Vec<f64>, Box<dyn Error>> {
    conduction_with(mesh, dof, conductivity_of)
}

/// As [`conduction`], with the conductivity `k(block name)` of another scene.
pub fn conduction_with(
    mesh: &Mesh,
    dof: &[usize],
    k_of: impl Fn(&str) -> f64,
) -> Result<Vec<f64>, Box<dyn Error>> {
    let n = mesh.num_nodes();
    let mut k = vec![0.0; n * n];
    for block in &mesh.blocks {
        let basis = Basis::standard(block.topology).ok_or("no shape functions")?;
        let nn = block.topology.node_count();
        for e in 0..block.len() {
            let nodes = block.elem_nodes(e);
            let x: Vec<[f64; 3]> = nodes.iter().map(|n| mesh.coords[n.index()]).collect();
            let mut ke = vec![0.0; nn * nn];
            conductivity(&basis, &x, |_| k_of(&block.name), &mut ke)
                .map_err(|b| format!("element {e} of block {}: det J = {:e}", block.name, b.det))?;
            for (a, na) in nodes.iter().enumerate() {
                for (b, nb) in nodes.iter().enumerate() {
                    k[dof[na.index()] * n + dof[nb.index()]] += ke[a * nn + b];
                }
            }
        }
    }
    Ok(k)
}

/// The prescribed value of each host unknown: base bottom 300 K, lid top 400 K.
pub fn dirichlet(mesh: &Mesh, dof: &[usize]) -> Result<Vec<Option<f64>>, Box<dyn Error>> {
    dirichlet_on(mesh, dof, &[("base_bottom", 300.0), ("lid_top", 400.0)])
}

/// The prescribed value of each host unknown from (side set, value) pairs.
pub fn dirichlet_on(
    mesh: &Mesh,
    dof: &[usize],
    sets: &[(&str, f64)],
) -> Result<Vec<Option<f64>>, Box<dyn Error>> {
    let mut fixed = vec![None; mesh.num_nodes()];
    for &(set, value) in sets {
        let s = mesh.find_side_set(set).ok_or("missing side set")?;
        for &side in &mesh.side_sets[s].sides {
            for node in mesh.side_nodes(side) {
                fixed[dof[node.index()]] = Some(value);
            }
        }
    }
    Ok(fixed)
}

/// Solve the two-block scene in `dir` as a host would.
pub fn solve(dir: &Path) -> Result<Outcome, Box<dyn Error>> {
    let mesh = seam::mesh::read(&dir.join("two_blocks.exo"))?;
    let dof = host_dofs(&mesh);
    let mut seam = embedding(&mesh, &dof).build()?;
    seam.add_deck_file(&dir.join("contact_run.i"))?;
    seam.search()?;
    let k = conduction(&mesh, &dof)?;
    let fixed = dirichlet(&mesh, &dof)?;
    let (u, newton_steps) = newton(&seam, &k, &fixed)?;
    let heat = seam.contributions(&u)?.heat[0].ok_or("not a flux-type interaction")?;
    Ok(Outcome { heat, newton_steps })
}

/// The host's Newton iteration on `K u + R_Γ(u) = 0` with the unknowns `fixed` held
/// (K dense, row-major, in host numbering): J = K + J_Γ; stops when a step moves no
/// unknown by more than 1e-9 K (a constant h is linear: the second step only confirms).
/// Returns the field and the number of steps.
pub fn newton(
    seam: &Embedding,
    k: &[f64],
    fixed: &[Option<f64>],
) -> Result<(Vec<f64>, usize), Box<dyn Error>> {
    let n = fixed.len();
    let mut u: Vec<f64> = fixed.iter().map(|f| f.unwrap_or(0.0)).collect();
    for step in 1..=10 {
        let c = seam.contributions(&u)?;
        let mut j = k.to_vec();
        let mut r = vec![0.0; n];
        for row in 0..n {
            r[row] = (0..n).map(|col| k[row * n + col] * u[col]).sum();
        }
        for &(d, v) in &c.residual {
            r[d] += v;
        }
        for &(row, col, v) in &c.jacobian {
            j[row * n + col] += v;
        }
        // Fixed unknowns do not move: identity rows, zero residual.
        for (d, f) in fixed.iter().enumerate() {
            if f.is_some() {
                j[d * n..(d + 1) * n].fill(0.0);
                j[d * n + d] = 1.0;
                r[d] = 0.0;
            }
        }
        let du = solve_dense(j, r.iter().map(|x| -x).collect(), n)?;
        let largest = du.iter().fold(0.0f64, |m, d| m.max(d.abs()));
        for (x, d) in u.iter_mut().zip(du) {
            *x += d;
        }
        if largest <= 1e-9 {
            return Ok((u, step));
        }
    }
    Err("Newton did not converge in 10 steps".into())
}

/// Gaussian elimination with partial pivoting (the host's own linear solver).
pub fn solve_dense(mut a: Vec<f64>, mut b: Vec<f64>, n: usize) -> Result<Vec<f64>, Box<dyn Error>> {
    for c in 0..n {
        let p = (c..n)
            .max_by(|&x, &y| a[x * n + c].abs().total_cmp(&a[y * n + c].abs()))
            .ok_or("empty system")?;
        if a[p * n + c] == 0.0 {
            return Err(format!("singular matrix at column {c}").into());
        }
        if p != c {
            for k in 0..n {
                a.swap(c * n + k, p * n + k);
            }
            b.swap(c, p);
        }
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            if f != 0.0 {
                for k in c..n {
                    a[r * n + k] -= f * a[c * n + k];
                }
                b[r] -= f * b[c];
            }
        }
    }
    for c in (0..n).rev() {
        let s: f64 = (c + 1..n).map(|k| a[c * n + k] * b[k]).sum();
        b[c] = (b[c] - s) / a[c * n + c];
    }
    Ok(b)
}

fn main() {
    let dir = std::env::args().nth(1).map_or_else(
        || PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/two_blocks"),
        PathBuf::from,
    );
    match solve(&dir) {
        Ok(o) => println!(
            "interface heat: side A {:.17e} W, side B {:.17e} W ({} Newton step(s))",
            o.heat.side_a, o.heat.side_b, o.newton_steps
        ),
        Err(e) => {
            eprintln!("error: {e}");
            std::process::exit(1);
        }
    }
}
