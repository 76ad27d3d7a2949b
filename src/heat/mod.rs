//! Heat conduction on the host mesh: element kernels for `Hex8`, `Tet4`, `Wedge6`,
//! `Pyramid5` (3-D) and `Quad4`, `Tri3` (2-D), global assembly of a steady linear
//! problem, error norms against an exact solution, and a nonlinear (k(T)) residual with
//! its exact Jacobian plus a small Newton driver.
//!
//! Entry points: [`steady_conduction`] (K and F with Dirichlet conditions eliminated),
//! [`error_norms`], [`nonlinear_residual_jacobian`], [`newton`]; the kernels in
//! [`kernel`]; shape functions, quadrature rules and the isoparametric map come from
//! [`crate::fem`].
//!
//! Conventions: the temperature field is the [`DofMap`] field named
//! [`TEMPERATURE`]; a prescribed face flux `q` is heat flowing *into* the body
//! (W/m²), so `−k∇T·n = −q` with n the outward normal; convection adds
//! `h (T − T∞)` leaving the body. Conductivity is constant per block in the linear
//! problem and a closure `k(T, x) → (k, dk/dT)` in the nonlinear one.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

pub(crate) mod dual;
pub mod electric;
pub mod interfaces;
pub mod kernel;
pub mod law;
pub(crate) mod nonlinear;
pub mod species;
pub mod steady;
pub mod transient;

use std::sync::Mutex;

use faer::sparse::SparseColMat;
use rayon::prelude::*;

use crate::assembly::{Assembler, AssemblyError, DofMap, FieldId, Pattern};
use crate::mesh::{ElemId, Mesh, NodeId, Side};
use crate::solve::{LinearSolver, Lu, SolveError, apply_dirichlet};

use crate::fem::{BadJacobian, MAX_NODES, Measure};

pub use crate::fem::{Basis, QuadratureRule};

/// Name of the temperature field in a [`DofMap`].
pub const TEMPERATURE: &str = "temperature";

/// Errors of the heat host.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum HeatError {
    #[error("the dof map has no `{TEMPERATURE}` field")]
    NoTemperatureField,
    #[error(
        "element {number} (block {block}) has a non-positive Jacobian determinant {det:.3e} at reference point {point:?}\n  help: the element is inverted or degenerate; check its node order"
    )]
    BadJacobian {
        number: i64,
        block: i64,
        det: f64,
        point: [f64; 3],
    },
    #[error("block {block} has topology {topology:?}, which heat conduction does not handle")]
    UnsupportedTopology {
        block: i64,
        topology: crate::mesh::Topology,
    },
    #[error("{count} materials given for {blocks} blocks")]
    MaterialCount { count: usize, blocks: usize },
    #[error("{count} block sources given for {blocks} blocks")]
    SourceCount { count: usize, blocks: usize },
    #[error("Dirichlet node {0} carries no temperature dof")]
    DirichletOffField(i64),
    #[error("side {side} of element {number} is not a side of that element")]
    BadSide { number: i64, side: u8 },
    #[error("contact: {0}")]
    Contact(String),
    #[error(
        "a radiation condition is nonlinear: the linear steady assembly cannot take it\n  help: solve with seam::heat::transient (seam run does so by itself)"
    )]
    NonlinearFace,
    #[error("material of block {block}: {message}")]
    Material { block: i64, message: String },
    #[error("source of block {block}: {message}")]
    Source { block: i64, message: String },
    #[error("{0}")]
    Step(String),
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
    #[error(transparent)]
    Solve(#[from] SolveError),
}

/// Material of one block (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Thermal conductivity k (W/m/K).
    pub conductivity: f64,
    /// Density × specific heat ρc (J/m³/K), for transient capacity.
    pub rho_c: f64,
}

/// A boundary condition on one element side.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaceBc {
    /// Heat flux `q` into the body (W/m²).
    Flux { side: Side, q: f64 },
    /// Convection `h (T − T∞)` out of the body.
    Convection { side: Side, h: f64, t_inf: f64 },
    /// Radiation to ambient `εσ(T⁴ − T∞⁴)` out of the body (nonlinear: solved by
    /// [`transient`], refused by the linear assembly).
    Radiation {
        side: Side,
        emissivity: f64,
        t_inf: f64,
    },
}

/// The Stefan–Boltzmann constant σ (W/m²/K⁴, CODATA 2018, exact in SI).
pub const STEFAN_BOLTZMANN: f64 = 5.670374419e-8;

impl FaceBc {
    /// The element side the condition acts on.
    pub fn side(&self) -> Side {
        match *self {
            FaceBc::Flux { side, .. }
            | FaceBc::Convection { side, .. }
            | FaceBc::Radiation { side, .. } => side,
        }
    }

    /// Heat leaving the body per area at face temperature `t`, and its derivative.
    pub fn outflow(&self, t: f64) -> (f64, f64) {
        match *self {
            FaceBc::Flux { q, .. } => (-q, 0.0),
            FaceBc::Convection { h, t_inf, .. } => (h * (t - t_inf), h),
            FaceBc::Radiation {
                emissivity, t_inf, ..
            } => {
                let es = emissivity * STEFAN_BOLTZMANN;
                (es * (t.powi(4) - t_inf.powi(4)), 4.0 * es * t.powi(3))
            }
        }
    }
}

/// An assembled linear system with the pattern it was built on (keep it for
/// values-only reassembly).
pub struct LinearSystem {
    pub pattern: Pattern,
    pub matrix: SparseColMat<usize, f64>,
    pub rhs: Vec<f64>,
}

pub type SourceFn<'a> = &'a (dyn Fn([f64; 3]) -> f64 + Sync);

fn temperature(dofs: &DofMap) -> Result<FieldId, HeatError> {
    dofs.field(TEMPERATURE).ok_or(HeatError::NoTemperatureField)
}

/// The entries of a list of element sides (face conditions, currents, fluxes) by
/// element: each element's indices into the list, found by two reads, for the element
/// kernels of the steady and the transient assemblies. (A binary
/// search of the list sorted by element took 38 % of the element loop's time on the
/// 1.17 M-hex electronics warm-up with its element matrices kept: a cache miss at
/// most of its 18 levels for the 2.6e5 faces of the sink's convection.)
pub(crate) struct ByElement {
    /// The list's indices, element by element (in list order within one).
    indices: Vec<u32>,
    /// Where element `e`'s run starts in `indices` (`n_elems + 1` of them; none for an
    /// empty list).
    start: Vec<u32>,
}

impl ByElement {
    /// The list `sides` by element; a side that is not one of `mesh`'s is an error.
    pub(crate) fn new(mesh: &Mesh, sides: &[Side]) -> Result<Self, HeatError> {
        if sides.is_empty() {
            return Ok(ByElement {
                indices: Vec::new(),
                start: Vec::new(),
            });
        }
        let n_elems = mesh.num_elems();
        let mut start = vec![0u32; n_elems + 1];
        for s in sides {
            if s.elem.index() >= n_elems
                || s.side == 0
                || s.side as usize > mesh.topology(s.elem).sides().len()
            {
                return Err(HeatError::BadSide {
                    number: mesh.elem_numbers.get(s.elem.index()).copied().unwrap_or(-1),
                    side: s.side,
                });
            }
            start[s.elem.index() + 1] += 1;
        }
        for i in 0..n_elems {
            start[i + 1] += start[i];
        }
        let mut next = start.clone();
        let mut indices = vec![0u32; sides.len()];
        for (k, s) in sides.iter().enumerate() {
            let at = &mut next[s.elem.index()];
            indices[*at as usize] = k as u32;
            *at += 1;
        }
        Ok(ByElement { indices, start })
    }

    /// The list's indices of element `e`'s entries, in list order.
    pub(crate) fn of(&self, e: ElemId) -> impl Iterator<Item = usize> + '_ {
        let run = match self.start.get(e.index()..e.index() + 2) {
            Some(&[a, b]) => a as usize..b as usize,
            _ => 0..0,
        };
        self.indices[run].iter().map(|&k| k as usize)
    }
}

/// Coordinates of an element's nodes.
fn elem_coords(mesh: &Mesh, elem: ElemId, out: &mut [[f64; 3]; MAX_NODES]) -> usize {
    let nodes = mesh.elem_nodes(elem);
    for (k, n) in nodes.iter().enumerate() {
        out[k] = mesh.coords[n.index()];
    }
    nodes.len()
}

/// Collects the first failing element (lowest id, so the report does not depend on
/// thread scheduling).
struct FirstError(Mutex<Option<(u32, HeatError)>>);

impl FirstError {
    fn new() -> Self {
        FirstError(Mutex::new(None))
    }
    fn record(&self, elem: ElemId, e: HeatError) {
        let mut g = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if g.as_ref().is_none_or(|(k, _)| elem.0 < *k) {
            *g = Some((elem.0, e));
        }
    }
    fn into_result(self) -> Result<(), HeatError> {
        match self.0.into_inner().unwrap_or_else(|p| p.into_inner()) {
            Some((_, e)) => Err(e),
            None => Ok(()),
        }
    }
}

fn bad_jacobian(mesh: &Mesh, elem: ElemId, b: BadJacobian) -> HeatError {
    let (block, _) = mesh.locate(elem);
    HeatError::BadJacobian {
        number: mesh.elem_number(elem),
        block: block.id,
        det: b.det,
        point: b.point,
    }
}

/// Standard bases of the temperature blocks (per revolution in an axisymmetric mesh),
/// checking every block is a solid.
fn block_rules(
    mesh: &Mesh,
    dofs: &DofMap,
    field: FieldId,
) -> Result<Vec<Option<Basis>>, HeatError> {
    let mut rules = vec![None; mesh.blocks.len()];
    for &b in dofs.field_blocks(field) {
        let block = &mesh.blocks[b];
        let measure = Measure::of(mesh.axisymmetric);
        rules[b] = Some(Basis::for_measure(block.topology, measure).ok_or(
            HeatError::UnsupportedTopology {
                block: block.id,
                topology: block.topology,
            },
        )?);
    }
    Ok(rules)
}

/// Assemble the steady linear conduction problem `K T = F`:
/// `K = Σ_e ∫ k ∇N·∇N + Σ_conv ∫ h N N`, `F = Σ_e ∫ Q N + Σ_flux ∫ q N + Σ_conv ∫ h T∞ N`,
/// then eliminate the Dirichlet conditions symmetrically ([`apply_dirichlet`]).
/// `materials[b]` is the material of `mesh.blocks[b]`. The temperature field must be
/// the only field on its blocks (the element slot holds one field).
pub fn steady_conduction(
    mesh: &Mesh,
    dofs: &DofMap,
    materials: &[Material],
    source: Option<SourceFn<'_>>,
    dirichlet: &[(NodeId, f64)],
    flux_bcs: &[FaceBc],
) -> Result<LinearSystem, HeatError> {
    let field = temperature(dofs)?;
    let mut pattern = Pattern::new(mesh, dofs);
    pattern.build()?;
    let mut asm = Assembler::new(&pattern);
    assemble_conduction(&mut asm, mesh, dofs, materials, source, flux_bcs)?;
    let mut matrix = asm.matrix()?;
    let mut rhs = asm.rhs();
    let bcs = dirichlet_dofs(mesh, dofs, field, dirichlet)?;
    apply_dirichlet(&mut matrix, &mut rhs, &bcs)?;
    drop(asm);
    Ok(LinearSystem {
        pattern,
        matrix,
        rhs,
    })
}

/// Fill the element slots of `asm` with the linear conduction terms (conductivity,
/// source, face flux and convection) of every temperature block; Dirichlet conditions
/// are left to the caller, so other terms (contact) can be added first.
pub fn assemble_conduction(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    materials: &[Material],
    source: Option<SourceFn<'_>>,
    flux_bcs: &[FaceBc],
) -> Result<(), HeatError> {
    conduction_with(asm, mesh, dofs, materials, |_| source, flux_bcs)
}

/// [`assemble_conduction`] with a source per block: `sources[b]` heats
/// `mesh.blocks[b]` (`None`: no source there).
pub fn assemble_conduction_by_block(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    materials: &[Material],
    sources: &[Option<SourceFn<'_>>],
    flux_bcs: &[FaceBc],
) -> Result<(), HeatError> {
    if sources.len() != mesh.blocks.len() {
        return Err(HeatError::SourceCount {
            count: sources.len(),
            blocks: mesh.blocks.len(),
        });
    }
    conduction_with(asm, mesh, dofs, materials, |b| sources[b], flux_bcs)
}

/// The conduction terms with block `b`'s source `source_of(b)`.
fn conduction_with<'s>(
    asm: &mut Assembler<'_>,
    mesh: &Mesh,
    dofs: &DofMap,
    materials: &[Material],
    source_of: impl Fn(usize) -> Option<SourceFn<'s>> + Sync,
    flux_bcs: &[FaceBc],
) -> Result<(), HeatError> {
    let field = temperature(dofs)?;
    if materials.len() != mesh.blocks.len() {
        return Err(HeatError::MaterialCount {
            count: materials.len(),
            blocks: mesh.blocks.len(),
        });
    }
    let rules = block_rules(mesh, dofs, field)?;
    let measure = Measure::of(mesh.axisymmetric);
    // Face conditions by element so each element kernel finds its own.
    let sides: Vec<Side> = flux_bcs.iter().map(FaceBc::side).collect();
    let faces = ByElement::new(mesh, &sides)?;
    let errors = FirstError::new();
    asm.elements(mesh, Some(dofs.field_blocks(field)), |e, ke, fe| {
        let (block, _) = mesh.locate(e);
        let b = mesh.block_of(e);
        let topo = block.topology;
        let rule = rules[b].as_ref().expect("rule of a temperature block");
        let mut x = [[0.0; 3]; MAX_NODES];
        let nn = elem_coords(mesh, e, &mut x);
        let x = &x[..nn];
        let k = materials[b].conductivity;
        if let Err(bad) = kernel::conductivity_uniform(rule, x, k, ke) {
            errors.record(e, bad_jacobian(mesh, e, bad));
            return;
        }
        if let Some(q) = source_of(b)
            && let Err(bad) = kernel::source(rule, x, q, fe)
        {
            errors.record(e, bad_jacobian(mesh, e, bad));
            return;
        }
        for k in faces.of(e) {
            match flux_bcs[k] {
                FaceBc::Flux { side, q } => {
                    kernel::face_flux_with(measure, topo, x, side.side, |_| q, fe)
                }
                FaceBc::Convection { side, h, t_inf } => {
                    kernel::face_convection_with(measure, topo, x, side.side, h, t_inf, ke, fe)
                }
                FaceBc::Radiation { .. } => {
                    errors.record(e, HeatError::NonlinearFace);
                    return;
                }
            }
        }
    });
    errors.into_result()?;
    asm.check_finite(mesh)?;
    Ok(())
}

/// `(dof, value)` pairs of nodal Dirichlet data on the temperature field.
pub fn dirichlet_dofs(
    mesh: &Mesh,
    dofs: &DofMap,
    field: FieldId,
    dirichlet: &[(NodeId, f64)],
) -> Result<Vec<(usize, f64)>, HeatError> {
    dirichlet
        .iter()
        .map(|&(n, v)| {
            dofs.dof(field, n)
                .map(|d| (d.index(), v))
                .ok_or(HeatError::DirichletOffField(
                    mesh.node_numbers.get(n.index()).copied().unwrap_or(-1),
                ))
        })
        .collect()
}

/// L2 norm and H1 seminorm of the error of a nodal field.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ErrorNorms {
    /// ‖T_h − T‖_{L2}
    pub l2: f64,
    /// |T_h − T|_{H1} = ‖∇T_h − ∇T‖_{L2}
    pub h1: f64,
}

/// Error of the finite-element field with nodal values `nodal` (indexed by node)
/// against `exact` and its gradient, over the given blocks, by a quadrature rule of
/// degree `degree` on every element (take it well above 2 — the integrand is not
/// polynomial; 6 makes the quadrature error negligible next to O(h²) on test meshes).
pub fn error_norms(
    mesh: &Mesh,
    blocks: &[usize],
    nodal: &[f64],
    exact: &(dyn Fn([f64; 3]) -> f64 + Sync),
    exact_grad: &(dyn Fn([f64; 3]) -> [f64; 3] + Sync),
    degree: usize,
) -> Result<ErrorNorms, HeatError> {
    let mut parts = Vec::new();
    for &b in blocks {
        let block = &mesh.blocks[b];
        let rule = QuadratureRule::with_degree(block.topology, degree).ok_or(
            HeatError::UnsupportedTopology {
                block: block.id,
                topology: block.topology,
            },
        )?;
        let basis = Basis::new(block.topology, rule).with_measure(Measure::of(mesh.axisymmetric));
        let per: Vec<Result<(f64, f64), HeatError>> = (0..block.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|k| {
                let e = ElemId(block.first_elem.0 + k as u32);
                let nodes = block.elem_nodes(k);
                let mut x = [[0.0; 3]; MAX_NODES];
                for (i, n) in nodes.iter().enumerate() {
                    x[i] = mesh.coords[n.index()];
                }
                let (mut l2, mut h1) = (0.0, 0.0);
                for q in 0..basis.len() {
                    let pv = basis
                        .eval(q, &x[..nodes.len()])
                        .map_err(|bad| bad_jacobian(mesh, e, bad))?;
                    let mut th = 0.0;
                    let mut gh = [0.0; 3];
                    for (a, n) in nodes.iter().enumerate() {
                        let v = nodal[n.index()];
                        th += pv.n[a] * v;
                        for i in 0..3 {
                            gh[i] += pv.grad[a][i] * v;
                        }
                    }
                    let g = exact_grad(pv.x);
                    l2 += (th - exact(pv.x)).powi(2) * pv.jxw;
                    h1 += (0..block.topology.parametric_dim())
                        .map(|i| (gh[i] - g[i]).powi(2))
                        .sum::<f64>()
                        * pv.jxw;
                }
                Ok((l2, h1))
            })
            .collect();
        parts.extend(per);
    }
    let (mut l2, mut h1) = (0.0, 0.0);
    for p in parts {
        let (a, b) = p?;
        l2 += a;
        h1 += b;
    }
    Ok(ErrorNorms {
        l2: l2.sqrt(),
        h1: h1.sqrt(),
    })
}

/// Residual and exact Jacobian of nonlinear steady conduction,
/// `R(T) = ∫ k(T) ∇N·∇T − ∫ Q N`, `J = ∂R/∂T` (including the dk/dT term), on
/// `pattern` (built from `dofs`). `t` is the dof vector; no Dirichlet conditions are
/// applied (see [`fix_dirichlet_rows`]).
pub fn nonlinear_residual_jacobian(
    mesh: &Mesh,
    dofs: &DofMap,
    pattern: &Pattern,
    conductivity: &(dyn Fn(f64, [f64; 3]) -> (f64, f64) + Sync),
    source: Option<SourceFn<'_>>,
    t: &[f64],
) -> Result<(Vec<f64>, SparseColMat<usize, f64>), HeatError> {
    let mut asm = Assembler::new(pattern);
    let k = |_: usize, temp: f64, x: [f64; 3]| Ok(conductivity(temp, x));
    let q = |_: usize, rule: &Basis, x: &[[f64; 3]], _: &[f64], re: &mut [f64], _: &mut [f64]| {
        if let Some(q) = source {
            let mut f = [0.0; MAX_NODES];
            kernel::source(rule, x, q, &mut f).map_err(nonlinear::ElementFailure::Jacobian)?;
            re.iter_mut().zip(&f).for_each(|(r, f)| *r -= f);
        }
        Ok(())
    };
    nonlinear::assemble_at(&mut asm, mesh, dofs, (k, q), &[], t)?;
    // The assembly's loads are −R.
    let r = asm.rhs().iter().map(|v| -v).collect();
    Ok((r, asm.matrix()?))
}

/// Impose Dirichlet data on a Newton system: `R_k = T_k − g_k` and row `k` of the
/// Jacobian becomes `e_kᵀ` (columns are left alone: the Jacobian is not symmetric
/// anyway once dk/dT enters).
pub fn fix_dirichlet_rows(
    residual: &mut [f64],
    jacobian: &mut SparseColMat<usize, f64>,
    t: &[f64],
    bcs: &[(usize, f64)],
) {
    let mut fixed = vec![false; residual.len()];
    for &(d, g) in bcs {
        fixed[d] = true;
        residual[d] = t[d] - g;
    }
    let (sym, vals) = jacobian.parts_mut();
    for j in 0..sym.ncols() {
        for p in sym.col_range(j) {
            let i = sym.row_idx()[p];
            if fixed[i] {
                vals[p] = if i == j { 1.0 } else { 0.0 };
            }
        }
    }
}

/// What a Newton solve did.
#[derive(Clone, Debug)]
pub struct NewtonReport {
    pub x: Vec<f64>,
    pub iterations: usize,
    /// ‖R‖₂ at every iterate, the initial guess first.
    pub residual_history: Vec<f64>,
    pub converged: bool,
}

/// Newton's method `x ← x − J(x)⁻¹ R(x)` with sparse LU (symbolic analysis kept across
/// iterations), until `‖R‖₂ ≤ tol · max(1, ‖R(x₀)‖₂)` or `max_it` iterations.
pub fn newton<F>(
    mut residual_and_jacobian: F,
    x0: Vec<f64>,
    tol: f64,
    max_it: usize,
) -> Result<NewtonReport, HeatError>
where
    F: FnMut(&[f64]) -> Result<(Vec<f64>, SparseColMat<usize, f64>), HeatError>,
{
    let mut x = x0;
    let mut lu = Lu::new();
    let mut history = Vec::new();
    let mut target = None;
    for it in 0..=max_it {
        let (mut r, j) = residual_and_jacobian(&x)?;
        let rn = r.iter().map(|v| v * v).sum::<f64>().sqrt();
        history.push(rn);
        let target = *target.get_or_insert(tol * rn.max(1.0));
        if rn <= target {
            return Ok(NewtonReport {
                x,
                iterations: it,
                residual_history: history,
                converged: true,
            });
        }
        if it == max_it {
            break;
        }
        lu.factor(&j)?;
        lu.solve(&mut r)?;
        x.iter_mut().zip(&r).for_each(|(x, d)| *x -= d);
    }
    Ok(NewtonReport {
        x,
        iterations: max_it,
        residual_history: history,
        converged: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::generate::{BoxSpec, single_box};

    /// Each element finds its own entries, in list order, and no other; a side number
    /// the element does not have, or an element the mesh does not have, is refused
    /// with the element's number.
    #[test]
    fn sides_by_element_find_their_own_entries_and_refuse_bad_sides() {
        let mesh = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [3, 2, 1], 1));
        let side = |e: u32, s: u8| Side {
            elem: ElemId(e),
            side: s,
        };
        let sides = [side(4, 2), side(0, 5), side(4, 6), side(2, 1), side(4, 1)];
        let by = ByElement::new(&mesh, &sides).unwrap();
        let of = |e: u32| by.of(ElemId(e)).collect::<Vec<usize>>();
        assert_eq!(of(4), [0, 2, 4]);
        assert_eq!(of(0), [1]);
        assert_eq!(of(2), [3]);
        for e in [1, 3, 5] {
            assert!(of(e).is_empty(), "element {e}");
        }
        assert!(
            ByElement::new(&mesh, &[])
                .unwrap()
                .of(ElemId(3))
                .next()
                .is_none()
        );
        for bad in [side(1, 7), side(1, 0), side(6, 1)] {
            match ByElement::new(&mesh, &[side(0, 1), bad]) {
                Err(HeatError::BadSide { number, side }) => {
                    let want = mesh
                        .elem_numbers
                        .get(bad.elem.index())
                        .copied()
                        .unwrap_or(-1);
                    assert_eq!((number, side), (want, bad.side));
                }
                other => panic!("{bad:?}: {:?}", other.map(|_| ())),
            }
        }
    }

    /// Volumes of generated Hex8 and Tet4 meshes add up to the box volume (1e-13
    /// relative: sums of a few thousand positive terms).
    #[test]
    fn element_volumes_add_up_to_the_box() {
        for spec in [
            BoxSpec::hex([0.0, -1.0, 2.0], [2.0, 0.5, 3.0], [4, 3, 5], 1),
            BoxSpec::tet([0.0, -1.0, 2.0], [2.0, 0.5, 3.0], [4, 3, 5], 1),
        ] {
            let mesh = single_box(spec);
            let block = &mesh.blocks[0];
            let basis = Basis::standard(block.topology).unwrap();
            let mut v = 0.0;
            for k in 0..block.len() {
                let x: Vec<[f64; 3]> = block
                    .elem_nodes(k)
                    .iter()
                    .map(|n| mesh.coords[n.index()])
                    .collect();
                v += kernel::measure(&basis, &x).unwrap();
            }
            assert!((v - 3.0).abs() < 1e-13 * 3.0, "{:?}: {v}", block.topology);
        }
    }

    /// Reference-cell volumes of every topology (the map is the identity): 8, 1/6, 1,
    /// 4/3, 4, 1/2.
    #[test]
    fn reference_cells_have_their_volumes() {
        use crate::mesh::Topology::*;
        for (t, v) in [
            (Hex8, 8.0),
            (Tet4, 1.0 / 6.0),
            (Wedge6, 1.0),
            (Pyramid5, 4.0 / 3.0),
            (Quad4, 4.0),
            (Tri3, 0.5),
        ] {
            let x = crate::fem::shape::reference_nodes(t).unwrap();
            let m = kernel::measure(&Basis::standard(t).unwrap(), x).unwrap();
            assert!((m - v).abs() < 1e-14, "{t:?}: {m}");
        }
    }

    /// Capacity: the consistent matrix sums to ρc·V (partition of unity, twice), the
    /// lumped one is its row sums on the diagonal, and both are symmetric positive.
    /// Checked on a distorted element of every topology (1e-13 relative).
    #[test]
    fn capacity_matrices_are_consistent() {
        use crate::mesh::Topology::*;
        for t in [Hex8, Tet4, Wedge6, Pyramid5, Quad4, Tri3] {
            let nn = t.node_count();
            let x: Vec<[f64; 3]> = crate::fem::shape::reference_nodes(t)
                .unwrap()
                .iter()
                .enumerate()
                .map(|(a, p)| {
                    let w = 0.05 * ((a * 37 % 11) as f64 / 11.0 - 0.5);
                    let z = if t.parametric_dim() == 3 {
                        p[2] - w
                    } else {
                        0.0
                    };
                    [1.3 * p[0] + w, 0.7 * p[1] + 0.2 * p[0], z]
                })
                .collect();
            let basis = Basis::standard(t).unwrap();
            let v = kernel::measure(&basis, &x).unwrap();
            let (mut mc, mut ml) = (vec![0.0; nn * nn], vec![0.0; nn * nn]);
            kernel::capacity_consistent(&basis, &x, 2.0, &mut mc).unwrap();
            kernel::capacity_lumped(&basis, &x, 2.0, &mut ml).unwrap();
            let total: f64 = mc.iter().sum();
            assert!(
                (total - 2.0 * v).abs() < 1e-13 * v,
                "{t:?}: {total} vs {}",
                2.0 * v
            );
            for a in 0..nn {
                let row: f64 = mc[a * nn..(a + 1) * nn].iter().sum();
                assert!((ml[a * nn + a] - row).abs() < 1e-14, "{t:?} row {a}");
                assert!(ml[a * nn + a] > 0.0, "{t:?}: lumped mass {a} not positive");
                for b in 0..nn {
                    assert_eq!(mc[a * nn + b], mc[b * nn + a]);
                }
            }
        }
    }

    /// An inverted element is an error naming the element, not a panic or a NaN.
    #[test]
    fn inverted_element_is_reported() {
        let mut mesh = single_box(BoxSpec::hex([0.0; 3], [1.0; 3], [2, 1, 1], 1));
        // Swap the bottom and top layers of element 2 (number 2): det J < 0.
        let c = &mut mesh.blocks[0].connectivity;
        let (bottom, top) = c[8..16].split_at_mut(4);
        bottom.swap_with_slice(top);
        let dofs = DofMap::new(&mesh, &[(TEMPERATURE, &[0])]).unwrap();
        let mat = [Material {
            conductivity: 1.0,
            rho_c: 1.0,
        }];
        let err = steady_conduction(&mesh, &dofs, &mat, None, &[], &[])
            .err()
            .unwrap();
        assert!(
            matches!(err, HeatError::BadJacobian { number: 2, .. }),
            "{err}"
        );
    }

    /// Flux and convection face kernels: ∫ q N over a unit square face sums to q·area,
    /// and the convection matrix sums to h·area (partition of unity on the face).
    #[test]
    fn face_integrals_sum_to_area() {
        let x = crate::fem::shape::reference_nodes(crate::mesh::Topology::Hex8).unwrap();
        for side in 1..=6u8 {
            let mut fe = [0.0; 8];
            kernel::face_flux(crate::mesh::Topology::Hex8, x, side, |_| 2.5, &mut fe);
            assert!((fe.iter().sum::<f64>() - 10.0).abs() < 1e-13);
            let (mut ke, mut fc) = ([0.0; 64], [0.0; 8]);
            kernel::face_convection(
                crate::mesh::Topology::Hex8,
                x,
                side,
                3.0,
                2.0,
                &mut ke,
                &mut fc,
            );
            assert!((ke.iter().sum::<f64>() - 12.0).abs() < 1e-13);
            assert!((fc.iter().sum::<f64>() - 24.0).abs() < 1e-13);
        }
    }
}
