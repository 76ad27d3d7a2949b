//! Interface forms of the flux-type enforcements, evaluated at contact points and
//! assembled into the host's system.
//!
//! Model problem (DESIGN.md): side A (Ω_A) and side B (Ω_B) meet on Γ; `[u] = u_A − u_B`,
//! the flux from A to B is `q = −k ∇u·n`. With `{k∂u} = w_A k_A ∇u_A·n_A − w_B k_B
//! ∇u_B·n_B` (each side's own outward normal, so periodic images need no special
//! case; `w_A + w_B = 1`), every model here is one bilinear form
//!
//! ```text
//! B_Γ(u, v) = ∫ P [u][v] − θ ({k∂u}[v] + [u]{k∂v}) − S {k∂u}{k∂v}
//! ```
//!
//! with coefficients per model:
//!
//! | model | P | θ | S |
//! |---|---|---|---|
//! | `Contact_Resistance`, `Conductance` | h | 0 | 0 |
//! | `Dash` (mortar penalty) | β_D k_eff / h_e | 0 | 0 |
//! | `Gap_Conductance` (Robin–Nitsche) | hα/(h+α) | h/(h+α) | 1/(h+α) |
//! | `Tied_<field>` (weighted Nitsche) | α | 1 | 0 |
//! | `Tied_Ip_<field>` (interior penalty) | α_ip | 1 | 0 |
//!
//! The Robin–Nitsche row is the interface form of Juntunen & Stenberg (2009): it follows
//! from the consistent identity `q = ([u] + γ{q})/(ε + γ)` with `ε = 1/h`, `γ = 1/α`,
//! symmetrised by the consistent term `(γ/(ε+γ))([u] − ε{q}){q(v)}`. It is the resistance
//! form as h → 0 and tied Nitsche as h → ∞, and stable for every h in between.
//! Weights and penalty (Annavarapu et al. 2012): `w_A = k_B/(k_A+k_B)`, `w_B =
//! k_A/(k_A+k_B)` and `α = β k_eff / h_e` with `k_eff = 2k_A k_B/(k_A+k_B)` and `h_e` the
//! smaller of the two elements' volume-to-face-area ratios, so high conductivity
//! contrast stays robust; `Tied_Ip` uses `w = ½` and `α_ip = β (k_A+k_B)/2 / h_e`.
//!
//! An `Offset Temperature` ΔT replaces `[u]` by `[u] − ΔT` (a prescribed jump).
//!
//! **Node-to-face form** (node surfaces: contact node sets, `Contact Type = node`). A
//! side-A node i paired with side-B face coordinates ξ_B is one point of weight A_i, its
//! tributary area `∫ N_i dA` over the faces around it: the same form with the jump
//! `[u] = u_i − u_B(ξ_B)` (side A's basis is the node's own dof, value 1), the flux
//! average side B's alone (`w_A = 0`, `w_B = 1`) and the penalty `α = β k_B / h_e,B`. The
//! P, θ, S of every model above apply unchanged. Since `Σ_i A_i = |Γ_A|`, a constant flux
//! crosses with exactly the heat of the face form; conservation holds as below (side A's
//! row is `A_i q`, side B's rows sum to `−A_i q`). It is a collocation of the jump at side
//! A's nodes, so a linear field with a normal flux crosses exactly when side B's traces
//! are linear on side A's faces (matching or nested meshes), not on arbitrary
//! non-matching ones: the one-pass node-to-segment limitation.
//!
//! **Conductivity of the temperature.** The local vectors are made once per search with
//! each block's k at a probe temperature (`conductivity`). A conductivity that changes
//! with T ([`InterfaceForm::conductivity_of_t`]) changes the weights, the flux average
//! and α at each point: the flux average is only consistent (`{k∂u} = q` for the exact
//! field) with k at the point's own temperatures, else the form transmits `k0/k(T)`
//! times the flux and the tie converges at first order. So each evaluation takes k_A =
//! k(T_A) and k_B = k(T_B) at the point and scales the made vectors: with the weights
//! above every flux entry carries `κ = k_A k_B/(k_A+k_B)` and `α ∝ κ`, so both scale by
//! `κ/κ0`; `Tied_Ip` scales side A's entries by `k_A/k_A0`, side B's by `k_B/k_B0` and α
//! by `(k_A+k_B)/(k_A0+k_B0)`; a node point scales by `k_B/k_B0`. The Jacobian carries
//! the derivatives of the three scales through T_A and T_B (P, θ, S through α).
//!
//! Heat accounting: with `v = 1` on all of side A (0 on B), the form gives the heat
//! leaving side A, `∫ P([u] − ΔT) − θ{k∂u}`; with `v = 1` on side B, minus the same. So
//! the heat through each side is read off the assembled interface residual, and their
//! sum is zero to round-off for every model here.
//!
//! Layout: [`InterfacePoints`] holds the geometry of one pairing (made once per search)
//! and evaluates the form at a field, into dense blocks ([`InterfacePoints::evaluate`])
//! or straight into an assembler ([`InterfacePoints::evaluate_into`]); `side` evaluates
//! one side of the interface at a point ([`side_eval`]).

#![allow(clippy::needless_range_loop)] // index loops mirror the formulas' subscripts

use crate::assembly::{Assembler, AssemblyError, DofMap, ExtraSlot, FieldId};
use crate::fem::MAX_NODES;
use crate::mesh::{Mesh, Topology};
use crate::search::pairing::{ContactPoint, SurfaceGeometry};
use crate::vec3::dot;

mod coefficients;
mod pattern;
mod points;
mod side;

pub use coefficients::RESISTANCE_LIMIT;
use coefficients::{Scale, alpha_derivatives, coefficients};
use side::FaceElement;
pub use side::{SideEval, side_eval};

/// Default Nitsche penalty factor β in `α = β k_eff / h_e`: well above the inverse-
/// estimate constant of trilinear and linear elements with `h_e` = volume / face area
/// (coercivity needs β > 2 C_I with C_I ≲ 4 for these elements).
pub const DEFAULT_BETA: f64 = 20.0;

/// Which interface form.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Form {
    /// `P = h`: contact resistance, conductance, and mortar penalty ties (Dash).
    Conductance,
    /// Robin–Nitsche gap conductance.
    GapConductance,
    /// Weighted symmetric Nitsche tie.
    TiedNitsche,
    /// Symmetric interior-penalty tie (arithmetic weights).
    TiedInteriorPenalty,
    /// Penalty tie `P = β k_eff / h_e` (Dash: β is the Dash Penalty Factor).
    Penalty,
}

/// The conductance at one point and its derivatives (for Newton).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct HValue {
    pub h: f64,
    pub dh_dtemp_a: f64,
    pub dh_dtemp_b: f64,
    /// dh/dV_A and dh/dV_B: an electrical contact conductance that sees the voltages
    /// (`Contact Gap Voltage`); 0 for every other.
    pub dh_dvolt_a: f64,
    pub dh_dvolt_b: f64,
}

/// What the conductance may depend on at a point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HInput {
    pub gap: f64,
    pub temp_a: f64,
    pub temp_b: f64,
    /// The voltages on side A and at the projection on side B, at an electrical
    /// contact; 0 at a thermal one.
    pub volt_a: f64,
    pub volt_b: f64,
    pub x: [f64; 3],
    /// Index of the point in the pairing's point list (for per-point data such as a
    /// nodal contact pressure).
    pub point: usize,
}

/// The fields an interface couples: side A's and side B's (`Side B Variable b To a`
/// ties a side-B field to a different side-A field). A single field converts into the
/// pair of itself.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FieldPair {
    pub a: FieldId,
    pub b: FieldId,
}

impl From<FieldId> for FieldPair {
    fn from(f: FieldId) -> Self {
        FieldPair { a: f, b: f }
    }
}

/// A conductance law at a point: h and its derivatives, or why it failed.
/// Called serially (interface terms are assembled on one thread), so a Lua model may
/// back it.
pub type HFn<'a> = dyn Fn(&HInput) -> Result<HValue, String> + 'a;

/// One interaction's enforcement, ready to assemble.
pub struct InterfaceForm<'a> {
    pub form: Form,
    /// The conductance (for `Conductance`/`GapConductance`); a penalty for Dash goes here
    /// too, as a constant.
    pub h: &'a HFn<'a>,
    /// Prescribed jump ΔT (`Offset Temperature`).
    pub offset: f64,
    /// β of the Nitsche penalty, times the interaction's penalty scale.
    pub beta: f64,
    /// Conductivity of each block (by block index).
    pub conductivity: &'a [f64],
    /// k(T) per block, when the Nitsche forms weigh the flux with the conductivity at
    /// each point's temperatures (module docs, "Conductivity of the temperature");
    /// `None`: `conductivity` as given. The form's field must be the temperature.
    pub conductivity_of_t: Option<&'a ConductivityLaw<'a>>,
    /// The temperature field, when it is not the form's own (a species interface or a
    /// voltage tie): `conductivity_of_t` (D(T), σ(T)) and the conductance `h` then take
    /// its values at the point, and their derivatives stay out of the Jacobian, whose
    /// columns are the form's field (Newton lags them by one iteration; the converged
    /// answer is the consistent one).
    pub temperature_field: Option<FieldId>,
}

/// k and dk/dT of block `b` at the temperature `t` and the point `x`.
pub type ConductivityLaw<'a> =
    dyn Fn(usize, f64, [f64; 3]) -> Result<(f64, f64), String> + Sync + 'a;

/// Why an interface could not be set up.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InterfaceError {
    #[error("element {number}: a contact point could not be placed in it (Jacobian {det:.3e})")]
    BadElement { number: i64, det: f64 },
    #[error("element {number} has topology {topology:?}, which carries no shape functions")]
    NoShapes { number: i64, topology: Topology },
    #[error("node {number} of element {elem} has no `{field}` dof")]
    NoDof {
        number: i64,
        elem: i64,
        field: String,
    },
    #[error("conductance at point ({x:.6}, {y:.6}, {z:.6}) of side-A face (element {elem}, side {side}): {message}", x = at[0], y = at[1], z = at[2])]
    Conductance {
        at: [f64; 3],
        elem: i64,
        side: u8,
        message: String,
    },
    #[error("conductance at side-A node {node} ({x:.6}, {y:.6}, {z:.6}): {message}", x = at[0], y = at[1], z = at[2])]
    ConductanceAtNode {
        at: [f64; 3],
        node: i64,
        message: String,
    },
    #[error("node {number} of node surface `{surface}` has no `{field}` dof")]
    NoNodeDof {
        number: i64,
        surface: String,
        field: String,
    },
    #[error(transparent)]
    Assembly(#[from] AssemblyError),
}

/// Trace shape functions of a Tri3 (`len` 3) or Quad4 face at face coordinates `xi`,
/// Exodus node order (the fourth value is 0 for a triangle): the search's own.
pub(crate) use crate::search::pairing::face_shapes as face_shape_values;

/// The dof of `field` at side-A node `node` of surface `surface` (node-to-face points).
pub(crate) fn node_dof(
    mesh: &Mesh,
    dofs: &DofMap,
    field: FieldId,
    node: crate::mesh::NodeId,
    surface: &str,
) -> Result<u32, InterfaceError> {
    dofs.dof(field, node)
        .map(|d| d.0)
        .ok_or_else(|| InterfaceError::NoNodeDof {
            number: mesh.node_number(node),
            surface: surface.to_string(),
            field: dofs.field_name(field).to_string(),
        })
}

/// Per-point local vectors: jump and flux-average of each local basis function (side
/// A's dofs first, then side B's), and their values for the current field.
#[derive(Clone, Copy, Debug)]
struct Local {
    /// Entries in use: `na` of side A, then side B's.
    len: usize,
    dofs: [u32; 2 * MAX_NODES],
    /// `J_i`: the jump of basis function i (`N_A,i` or `−N_B,i`).
    jump: [f64; 2 * MAX_NODES],
    /// `F_i`: the weighted flux average `{k∂N_i}`.
    flux: [f64; 2 * MAX_NODES],
    /// Indices of side A's dofs in `dofs` are `0..na`.
    na: usize,
    alpha: f64,
}

impl Local {
    fn new(na: usize, alpha: f64) -> Self {
        Local {
            len: 0,
            dofs: [0; 2 * MAX_NODES],
            jump: [0.0; 2 * MAX_NODES],
            flux: [0.0; 2 * MAX_NODES],
            na,
            alpha,
        }
    }

    fn push(&mut self, dof: u32, jump: f64, flux: f64) {
        self.dofs[self.len] = dof;
        self.jump[self.len] = jump;
        self.flux[self.len] = flux;
        self.len += 1;
    }

    fn dofs(&self) -> &[u32] {
        &self.dofs[..self.len]
    }
}

fn local(a: &SideEval, b: &SideEval, form: Form, beta: f64) -> Local {
    let (ka, kb) = (a.k, b.k);
    let (wa, wb) = match form {
        Form::TiedInteriorPenalty => (0.5, 0.5),
        _ => (kb / (ka + kb), ka / (ka + kb)),
    };
    let h_e = a.h_e.min(b.h_e).max(f64::MIN_POSITIVE);
    let k_eff = match form {
        Form::TiedInteriorPenalty => 0.5 * (ka + kb),
        _ => 2.0 * ka * kb / (ka + kb),
    };
    let mut l = Local::new(a.len, beta * k_eff / h_e);
    for i in 0..a.len {
        l.push(a.dofs[i], a.n[i], wa * ka * dot(a.grad[i], a.normal));
    }
    for i in 0..b.len {
        l.push(b.dofs[i], -b.n[i], -wb * kb * dot(b.grad[i], b.normal));
    }
    l
}

/// The local vectors of a node point (node-to-face form): side A is the node's single
/// dof with value 1, so `[u] = u_node − u_B(ξ_B)`; the flux average is side B's flux
/// alone (`w_A = 0`, `w_B = 1`: the flux is continuous and side A has no face at the
/// point), and the penalty length is side B's, `α = β k_B / h_e,B` (`Tied_Ip`: the same;
/// there is no side-A element to average with).
fn local_node(dof: u32, b: &SideEval, beta: f64) -> Local {
    let mut l = Local::new(1, beta * b.k / b.h_e.max(f64::MIN_POSITIVE));
    l.push(dof, 1.0, 0.0);
    for i in 0..b.len {
        l.push(b.dofs[i], -b.n[i], -b.k * dot(b.grad[i], b.normal));
    }
    l
}

/// One point's values at a field: see [`InterfacePoints::at_point`].
struct PointEval<'a> {
    jump: &'a [f64],
    /// The flux entries as made (at the conductivities `k0`); `scale` scales them.
    flux: &'a [f64],
    /// `[u] − ΔT` and `{k∂u}` at the point (scaled).
    jump_u: f64,
    flux_u: f64,
    /// Side A's and side B's parts of `{k∂u}` before scaling.
    flux_parts: [f64; 2],
    hv: HValue,
    temp_a: f64,
    temp_b: f64,
    scale: Scale,
}

/// Where the entries of an interaction's blocks go in an [`Assembler`]: see
/// [`InterfacePoints::scatter`].
#[derive(Clone, Debug, Default)]
pub struct Scatter {
    slots: Vec<ExtraSlot>,
}

/// The assembled interface terms of one interaction: for each pair of elements
/// (A, B) met by some point, a dense block over their dofs, and a right-hand side.
#[derive(Clone, Debug, Default)]
pub struct InterfaceSystem {
    /// Dense blocks keyed by (element A, element B), or (node A, element B) for node
    /// points: (dofs, row-major matrix).
    pub blocks: Vec<(Vec<u32>, Vec<f64>)>,
    /// (dof, value) right-hand-side contributions.
    pub rhs: Vec<(u32, f64)>,
    /// The interface residual `B_Γ(u, ·) − ℓ_Γ(·)` at the given field, by dof.
    pub residual: Vec<(u32, f64)>,
    /// Dofs of side A (for heat accounting).
    pub side_a_dofs: Vec<u32>,
    pub side_b_dofs: Vec<u32>,
}

/// Evaluate the interface form of one interaction at the field `u` (global dof vector):
/// the Jacobian blocks (exact, including dh/dT), the residual and, for linear models,
/// the right-hand side of `K u = f`. Builds an [`InterfacePoints`] and evaluates it once;
/// callers that evaluate repeatedly (Newton, time steps) keep the [`InterfacePoints`].
#[allow(clippy::too_many_arguments)]
pub fn interface_terms(
    mesh: &Mesh,
    dofs: &DofMap,
    fields: impl Into<FieldPair>,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    points: &[ContactPoint],
    form: &InterfaceForm<'_>,
    u: &[f64],
) -> Result<InterfaceSystem, InterfaceError> {
    InterfacePoints::new(mesh, dofs, fields, a, b, points, form)?.evaluate(form, u)
}

/// The geometric part of one interaction's interface form, evaluated once per search:
/// at every matched face point the jump and flux-average of each local basis function,
/// the weight and the penalty. What changes between evaluations — the field, and h
/// through it — is applied by [`InterfacePoints::evaluate`] in a few flops per entry.
///
/// Points are grouped by their element pair (side A, side B) — or, for node points, by
/// (side-A node, side-B element) — the dense blocks of [`InterfaceSystem`], face groups
/// first, each kind in key order; within a group they keep the pairing's order, so sums
/// run in the same order at every evaluation.
#[derive(Clone, Debug, Default)]
pub struct InterfacePoints {
    /// The groups' dof lists, concatenated (`group_dofs[g]..group_dofs[g+1]`).
    dofs: Vec<u32>,
    /// With [`InterfaceForm::temperature_field`]: the temperature dof at the node of
    /// each entry of `dofs` (empty otherwise).
    t_dofs: Vec<u32>,
    group_dofs: Vec<usize>,
    /// The groups' points (`group_points[g]..group_points[g+1]` into `points`).
    group_points: Vec<usize>,
    points: Vec<CachedPoint>,
    /// Per point, its jump then flux entries (`2 nl` values from `CachedPoint::at`).
    values: Vec<f64>,
    /// Every dof met, sorted, and each group entry's position in it.
    touched: Vec<u32>,
    position: Vec<u32>,
    side_a_dofs: Vec<u32>,
    side_b_dofs: Vec<u32>,
}

#[derive(Clone, Copy, Debug)]
struct CachedPoint {
    /// Index in the pairing's point list.
    index: u32,
    /// Side-A element (its number) and side, for messages; for a node point (`side` 0)
    /// `elem` is the node's number.
    elem: i64,
    side: u8,
    na: u32,
    at: u32,
    weight: f64,
    gap: f64,
    x: [f64; 3],
    alpha: f64,
    /// The blocks of the side-A element (of the node's side-B element for a node point)
    /// and the side-B element, and the conductivities the local vectors were made with.
    blocks: [u32; 2],
    k0: [f64; 2],
}

impl CachedPoint {
    /// A place holder, overwritten before it is read.
    const EMPTY: CachedPoint = CachedPoint {
        index: 0,
        elem: 0,
        side: 0,
        na: 0,
        at: 0,
        weight: 0.0,
        gap: 0.0,
        x: [0.0; 3],
        alpha: 0.0,
        blocks: [0; 2],
        k0: [0.0; 2],
    };
}

impl InterfacePoints {
    /// Number of element-pair groups (dense blocks).
    pub fn groups(&self) -> usize {
        self.group_points.len().saturating_sub(1)
    }

    /// Number of matched points with a weight (face points and node points).
    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The temperature dofs of group `g`, parallel to [`Self::group`], when the models
    /// see the temperature of another field.
    fn group_t_dofs(&self, g: usize) -> Option<&[u32]> {
        (!self.t_dofs.is_empty()).then(|| &self.t_dofs[self.group_dofs[g]..self.group_dofs[g + 1]])
    }

    /// The dofs of group `g` (side A's element, then side B's): the rows and columns
    /// of the `g`-th block [`Self::for_each_block`] gives, without evaluating anything.
    pub fn group(&self, g: usize) -> &[u32] {
        &self.dofs[self.group_dofs[g]..self.group_dofs[g + 1]]
    }

    /// The local vectors of point `p` (of a group with `dofs`), the jump and
    /// flux-average of the field there, and h.
    fn at_point(
        &self,
        (g, p): (usize, &CachedPoint),
        form: &InterfaceForm<'_>,
        u: &[f64],
    ) -> Result<PointEval<'_>, InterfaceError> {
        let dofs = self.group(g);
        let nl = dofs.len();
        let at = p.at as usize;
        let jump = &self.values[at..at + nl];
        let flux = &self.values[at + nl..at + 2 * nl];
        let value = |v: &[f64]| -> f64 { (0..nl).map(|i| v[i] * u[dofs[i] as usize]).sum() };
        let jump_u = value(jump) - form.offset;
        let na = p.na as usize;
        let part =
            |r: std::ops::Range<usize>| -> f64 { r.map(|i| flux[i] * u[dofs[i] as usize]).sum() };
        let flux_parts = [part(0..na), part(na..nl)];
        let temp_a: f64 = (0..na).map(|i| jump[i] * u[dofs[i] as usize]).sum();
        let temp_b = temp_a - (jump_u + form.offset);
        // The temperatures the models see: the form's own field's, or those of the
        // temperature field beside it (T_A = Σ_A N T, T_B = Σ_B N T), whose derivatives
        // lie outside the form's columns and are left to Newton's next iteration.
        let foreign = self.group_t_dofs(g).map(|t| {
            let at = |i: usize| {
                if t[i] == u32::MAX {
                    0.0
                } else {
                    u[t[i] as usize]
                }
            };
            let value = |r: std::ops::Range<usize>| -> f64 { r.map(|i| jump[i] * at(i)).sum() };
            (value(0..na), -value(na..nl))
        });
        let (seen_a, seen_b) = foreign.unwrap_or((temp_a, temp_b));
        let mut scale = self.scale(p, form, seen_a, seen_b)?;
        scale.varies &= foreign.is_none();
        let flux_u = scale.flux[0] * flux_parts[0] + scale.flux[1] * flux_parts[1];
        let hv = match form.form {
            Form::Conductance | Form::GapConductance => {
                let hv = (form.h)(&HInput {
                    gap: p.gap,
                    temp_a: seen_a,
                    temp_b: seen_b,
                    volt_a: 0.0,
                    volt_b: 0.0,
                    x: p.x,
                    point: p.index as usize,
                })
                .map_err(|message| point_error(p, message))?;
                match foreign {
                    Some(_) => HValue {
                        dh_dtemp_a: 0.0,
                        dh_dtemp_b: 0.0,
                        ..hv
                    },
                    None => hv,
                }
            }
            _ => HValue::default(),
        };
        Ok(PointEval {
            jump,
            flux,
            jump_u,
            flux_u,
            flux_parts,
            hv,
            temp_a,
            temp_b,
            scale,
        })
    }

    /// The heat flux from side A to side B at every point of the pairing the cache was
    /// made from (`count` points; `None` where a point is not matched, or is a node point
    /// without tributary area): `q = P([u] − ΔT) − θ{k∂u}`.
    pub fn point_flux(
        &self,
        form: &InterfaceForm<'_>,
        u: &[f64],
        count: usize,
    ) -> Result<Vec<Option<PointFlux>>, InterfaceError> {
        let mut out = vec![None; count];
        for g in 0..self.groups() {
            for p in &self.points[self.group_points[g]..self.group_points[g + 1]] {
                let e = self.at_point((g, p), form, u)?;
                let ([cp, ct, _], _) = coefficients(form.form, e.hv.h, p.alpha * e.scale.alpha);
                out[p.index as usize] = Some(PointFlux {
                    q: cp * e.jump_u - ct * e.flux_u,
                    temp_a: e.temp_a,
                    temp_b: e.temp_b,
                });
            }
        }
        Ok(out)
    }

    /// The form at the field `u`: Jacobian blocks (exact, including dh/dT), residual,
    /// and the right-hand side of the offset terms.
    pub fn evaluate(
        &self,
        form: &InterfaceForm<'_>,
        u: &[f64],
    ) -> Result<InterfaceSystem, InterfaceError> {
        let mut blocks = Vec::with_capacity(self.groups());
        let mut system = self.for_each_block(form, u, |dofs, m| {
            blocks.push((dofs.to_vec(), m.to_vec()));
        })?;
        system.blocks = blocks;
        Ok(system)
    }

    /// As [`Self::evaluate`], but each block is added into `asm` through `scatter` (made
    /// by [`Self::scatter`], its couplings numbered from `first` in `asm`) as soon as it
    /// is made, instead of being kept: the values are refreshed in place, with no allocation per block. The
    /// returned system carries the residual, right-hand side and heat accounting, and no
    /// blocks. Adds the same
    /// values in the same order as `evaluate` followed by
    /// [`InterfaceSystem::add_scattered`].
    pub fn evaluate_into(
        &self,
        form: &InterfaceForm<'_>,
        u: &[f64],
        asm: &mut Assembler<'_>,
        scatter: &Scatter,
        first: usize,
    ) -> Result<InterfaceSystem, InterfaceError> {
        let mut at = 0;
        let system = self.for_each_block(form, u, |_, m| {
            asm.add_at_all(&scatter.slots[at..at + m.len()], m, first);
            at += m.len();
        })?;
        debug_assert_eq!(at, scatter.slots.len(), "a scatter of other points");
        Ok(system)
    }

    /// The form at `u`, block by block: `block(dofs, matrix)` for each group in order,
    /// the matrix row-major over the group's dofs; returns the system without blocks.
    /// A caller with a matrix of its own (the embedding's CSR) adds each block where
    /// it goes without keeping it.
    pub fn for_each_block(
        &self,
        form: &InterfaceForm<'_>,
        u: &[f64],
        block: impl FnMut(&[u32], &[f64]),
    ) -> Result<InterfaceSystem, InterfaceError> {
        self.walk::<true>(form, u, block)
    }

    /// The residual, right-hand side and heat accounting of the form at `u`, without
    /// the Jacobian: what a caller that wants only the heat needs. The same bits as
    /// [`Self::evaluate`]'s residual (the same sums in the same order).
    pub fn residual(
        &self,
        form: &InterfaceForm<'_>,
        u: &[f64],
    ) -> Result<InterfaceSystem, InterfaceError> {
        self.walk::<false>(form, u, |_, _| {})
    }

    /// [`Self::for_each_block`], the blocks made only when `BLOCKS`.
    fn walk<const BLOCKS: bool>(
        &self,
        form: &InterfaceForm<'_>,
        u: &[f64],
        mut block: impl FnMut(&[u32], &[f64]),
    ) -> Result<InterfaceSystem, InterfaceError> {
        let mut residual = vec![0.0; self.touched.len()];
        let mut rhs = vec![0.0; self.touched.len()];
        let mut dh = [0.0; 2 * MAX_NODES];
        let mut m = [0.0; 4 * MAX_NODES * MAX_NODES];
        // The symmetric points' sum, its upper triangle only (row-major like `m`).
        let mut sym = [0.0; 4 * MAX_NODES * MAX_NODES];
        for g in 0..self.groups() {
            let dofs = self.group(g);
            let position = &self.position[self.group_dofs[g]..self.group_dofs[g + 1]];
            let nl = dofs.len();
            let m = &mut m[..nl * nl];
            let sym = &mut sym[..nl * nl];
            sym.fill(0.0);
            // `m` is zeroed when a point first needs its full rows (a nonlinear or
            // k(T) point); a group of symmetric points writes it once, from `sym`.
            let mut full = false;
            for p in &self.points[self.group_points[g]..self.group_points[g + 1]] {
                let PointEval {
                    jump,
                    flux: flux0,
                    jump_u,
                    flux_u,
                    flux_parts,
                    hv,
                    scale,
                    ..
                } = self.at_point((g, p), form, u)?;
                let na = p.na as usize;
                let alpha = p.alpha * scale.alpha;
                let ([cp, ct, cs], [dp, dt, ds]) = coefficients(form.form, hv.h, alpha);
                let w = p.weight;
                // The flux entries at the point's conductivities.
                let mut scaled = [0.0; 2 * MAX_NODES];
                for j in 0..nl {
                    scaled[j] = flux0[j] * scale.flux[usize::from(j >= na)];
                }
                let flux = &scaled[..nl];
                // With k(T): the derivatives of the three scales by u_j (T_A = Σ_A N u,
                // T_B = Σ_B N u), and ∂r_i/∂scale below.
                let mut dscale = [[0.0; 2 * MAX_NODES]; 3];
                if scale.varies {
                    for (c, d) in dscale.iter_mut().enumerate() {
                        for j in 0..nl {
                            d[j] = if j < na {
                                scale.d[c][0] * jump[j]
                            } else {
                                -scale.d[c][1] * jump[j]
                            };
                        }
                    }
                }
                let [da_p, da_t, da_s] = alpha_derivatives(form.form, hv.h, alpha);
                // dh/du_j: T_A = Σ_A N u, T_B = Σ_B N u (jump entries of B are −N).
                let nonlinear = hv.dh_dtemp_a != 0.0 || hv.dh_dtemp_b != 0.0;
                for j in 0..nl {
                    dh[j] = if j < na {
                        hv.dh_dtemp_a * jump[j]
                    } else {
                        -hv.dh_dtemp_b * jump[j]
                    };
                }
                // The entry P J_i J_j − θ (F_i J_j + J_i F_j) − S F_i F_j regrouped as
                // J_i A_j − F_i B_j with A = P J − θ F and B = θ J + S F: two products
                // per entry, in loops over j that vectorise.
                let (mut a, mut b) = ([0.0; 2 * MAX_NODES], [0.0; 2 * MAX_NODES]);
                for j in 0..nl {
                    a[j] = cp * jump[j] - ct * flux[j];
                    b[j] = ct * jump[j] + cs * flux[j];
                }
                let (a, b, dh) = (&a[..nl], &b[..nl], &dh[..nl]);
                for i in 0..nl {
                    let (ji, fi) = (jump[i], flux[i]);
                    // Residual r_i = w [P J_i [u]' − θ (F_i [u]' + J_i F(u)) − S F_i F(u)].
                    let r_p = ji * jump_u;
                    let r_t = -(fi * jump_u + ji * flux_u);
                    let r_s = -fi * flux_u;
                    let k = position[i] as usize;
                    residual[k] += w * (cp * r_p + ct * r_t + cs * r_s);
                    // Right-hand side of the linear form (the offset terms).
                    rhs[k] += w * form.offset * (cp * ji - ct * fi);
                    if !BLOCKS {
                        continue;
                    }
                    let (wj, wf) = (w * ji, w * fi);
                    if !nonlinear && !scale.varies {
                        // A symmetric entry (h and k fixed at this point): its upper
                        // triangle, mirrored once the group is summed.
                        let row = &mut sym[i * nl..(i + 1) * nl];
                        for j in i..nl {
                            row[j] += wj * a[j] - wf * b[j];
                        }
                        continue;
                    }
                    if !full {
                        m.fill(0.0);
                        full = true;
                    }
                    let row = &mut m[i * nl..(i + 1) * nl];
                    if nonlinear {
                        let wd = w * (dp * r_p + dt * r_t + ds * r_s);
                        for j in 0..nl {
                            row[j] += wj * a[j] - wf * b[j] + wd * dh[j];
                        }
                    } else {
                        for j in 0..nl {
                            row[j] += wj * a[j] - wf * b[j];
                        }
                    }
                    if scale.varies {
                        // ∂r_i/∂(flux scale of side A, of side B, α scale).
                        let own = |side: usize| {
                            if usize::from(i >= na) == side {
                                flux0[i]
                            } else {
                                0.0
                            }
                        };
                        let g = |side: usize| {
                            let (f0, part) = (own(side), flux_parts[side]);
                            -ct * (f0 * jump_u + ji * part) - cs * (f0 * flux_u + fi * part)
                        };
                        let g_alpha = p.alpha
                            * (da_p * ji * jump_u
                                - da_t * (fi * jump_u + ji * flux_u)
                                - da_s * fi * flux_u);
                        let (ga, gb, gal) = (w * g(0), w * g(1), w * g_alpha);
                        for j in 0..nl {
                            row[j] += ga * dscale[0][j] + gb * dscale[1][j] + gal * dscale[2][j];
                        }
                    }
                }
            }
            if !BLOCKS {
                continue;
            }
            // The symmetric part into both triangles: a block of symmetric points alone
            // is symmetric bit for bit, so is the matrix it is added into. (Written as
            // `0.0 + v` where `m` was not zeroed: the same bits as adding to zero.)
            if full {
                for i in 0..nl {
                    for j in i..nl {
                        let v = sym[i * nl + j];
                        m[i * nl + j] += v;
                        if j != i {
                            m[j * nl + i] += v;
                        }
                    }
                }
            } else {
                for i in 0..nl {
                    for j in i..nl {
                        let v = 0.0 + sym[i * nl + j];
                        m[i * nl + j] = v;
                        m[j * nl + i] = v;
                    }
                }
            }
            block(dofs, m);
        }
        let pairs =
            |v: Vec<f64>| -> Vec<(u32, f64)> { self.touched.iter().copied().zip(v).collect() };
        Ok(InterfaceSystem {
            blocks: Vec::new(),
            rhs: pairs(rhs),
            residual: pairs(residual),
            side_a_dofs: self.side_a_dofs.clone(),
            side_b_dofs: self.side_b_dofs.clone(),
        })
    }
}

/// An error of the models at point `p` (a node point names its node).
fn point_error(p: &CachedPoint, message: String) -> InterfaceError {
    match p.side {
        0 => InterfaceError::ConductanceAtNode {
            at: p.x,
            node: p.elem,
            message,
        },
        side => InterfaceError::Conductance {
            at: p.x,
            elem: p.elem,
            side,
            message,
        },
    }
}

impl InterfaceSystem {
    /// Add the blocks of a system evaluated from the [`InterfacePoints`] that made
    /// `scatter`, its couplings numbered from `first` in the assembler.
    pub fn add_scattered(&self, asm: &mut Assembler<'_>, scatter: &Scatter, first: usize) {
        let mut at = 0;
        for (_, m) in &self.blocks {
            asm.add_at_all(&scatter.slots[at..at + m.len()], m, first);
            at += m.len();
        }
        debug_assert_eq!(at, scatter.slots.len(), "a scatter of other points");
    }

    /// Heat leaving side A and side B through Γ, read off the interface residual.
    pub fn heat(&self) -> (f64, f64) {
        let sum = |set: &[u32]| -> f64 {
            self.residual
                .iter()
                .filter(|(d, _)| set.binary_search(d).is_ok())
                .map(|(_, v)| v)
                .sum()
        };
        (sum(&self.side_a_dofs), sum(&self.side_b_dofs))
    }
}

/// The interface heat flux at one matched contact point, and the two temperatures it
/// was computed from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PointFlux {
    /// Heat flux from side A to side B (W/m²): `q = P([u] − ΔT) − θ{k∂u}`.
    pub q: f64,
    /// Side A's temperature at the point.
    pub temp_a: f64,
    /// Side B's temperature at the projection (`T_A − [u]`).
    pub temp_b: f64,
}

/// The heat flux from side A to side B at each of `points` (`None` for points that are
/// not matched and for node points without tributary area): `q = P([u] − ΔT) − θ{k∂u}`
/// with the coefficients of [`InterfaceForm::form`] at the point's h.
///
/// This is the integrand of the heat leaving side A (module docs, "Heat accounting"):
/// the side-A rows of the residual sum to `Σ w (P([u] − ΔT) − θ{k∂u} − S{k∂u}·ΣF_A)`,
/// where `ΣF_A = w_A k_A ∇(Σ N_A)·n = 0` (partition of unity), so `Σ w q` over the
/// points equals [`InterfaceSystem::heat`]'s side-A value to round-off.
#[allow(clippy::too_many_arguments)]
pub fn point_flux(
    mesh: &Mesh,
    dofs: &DofMap,
    fields: impl Into<FieldPair>,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    points: &[ContactPoint],
    form: &InterfaceForm<'_>,
    u: &[f64],
) -> Result<Vec<Option<PointFlux>>, InterfaceError> {
    InterfacePoints::new(mesh, dofs, fields, a, b, points, form)?.point_flux(form, u, points.len())
}

#[cfg(test)]
mod tests;
