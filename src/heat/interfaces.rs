//! The interface terms as seam's own solvers take them. The solvers see a problem's
//! interfaces only through [`Interfaces`]: `seam run` hands them its contact through the
//! public embedding API (`seam::embed`), as an external host would, and a caller that
//! built its pairings itself hands [`ContactTerm`]s and [`TieTerm`]s ([`Terms`]).

use std::collections::HashSet;

use crate::assembly::{Assembler, DofMap};
use crate::enforce::interface::{FieldPair, InterfaceForm, InterfacePoints, Scatter};
use crate::enforce::mortar::{Multipliers, mortar_tie};
use crate::mesh::{Mesh, NodeId};
use crate::search::pairing::{ContactPoint, SurfaceGeometry};

/// One enforced interface: a pairing and its form.
pub struct ContactTerm<'a> {
    pub side_a: &'a SurfaceGeometry,
    pub side_b: &'a SurfaceGeometry,
    pub points: &'a [ContactPoint],
    pub form: InterfaceForm<'a>,
    /// The conductance does not depend on the field (the system stays linear and
    /// symmetric).
    pub linear: bool,
}

/// One Lagrange-multiplier mortar tie (`Tied` with `Side B Variable`).
pub struct TieTerm<'a> {
    pub side_a: &'a SurfaceGeometry,
    pub side_b: &'a SurfaceGeometry,
    pub points: &'a [ContactPoint],
    /// Prescribed jump `a − b` (`Offset Temperature`).
    pub offset: f64,
    pub multipliers: Multipliers,
}

/// Why the interface terms could not be evaluated.
#[derive(Clone, Debug)]
pub enum InterfaceFailure {
    /// A conductance model asks for a smaller step: the step is retried.
    Cutback(String),
    Failed(String),
}

impl std::fmt::Display for InterfaceFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            InterfaceFailure::Cutback(m) | InterfaceFailure::Failed(m) => f.write_str(m),
        }
    }
}

/// The constraint rows `C u = g` of one mortar tie, in the solver's dofs.
#[derive(Clone, Debug, Default)]
pub struct TieRows {
    /// The dof of each multiplier's side-A node, in multiplier order.
    pub own: Vec<usize>,
    /// `(multiplier k, dof j, C_kj)`.
    pub entries: Vec<(usize, usize, f64)>,
    /// `g_k = ΔT ∫ψ_k`.
    pub rhs: Vec<f64>,
    /// Side-A nodes without a multiplier (fixed, or in an earlier tie): crosspoints.
    pub crosspoints: Vec<NodeId>,
    pub side_a_dofs: Vec<usize>,
    pub side_b_dofs: Vec<usize>,
    pub dual: bool,
}

impl TieRows {
    /// Heat leaving side A and side B for multipliers `lambda`.
    pub fn heat(&self, lambda: &[f64]) -> (f64, f64) {
        crate::enforce::mortar::tie_heat(
            self.entries.iter().copied(),
            lambda,
            &self.side_a_dofs,
            &self.side_b_dofs,
        )
    }
}

/// A problem's interfaces as its solver asks for them. Flux-type terms come first
/// (their heats, in order), then the ties.
pub trait Interfaces {
    /// Number of flux-type terms.
    fn flux_count(&self) -> usize;
    /// Every flux term is linear in the field: a constant, symmetric Jacobian.
    fn is_linear(&self) -> bool;
    /// The ties' rows, in tie order (made once per solve).
    fn ties(&self) -> Result<Vec<TieRows>, String>;
    /// Whether tie `k` is switched on at time `t`.
    fn tie_on(&self, k: usize, t: f64) -> bool;
    /// Whether flux term `k` is switched on at time `t` (a toggle): a solver that keeps
    /// its matrix from step to step sets it again when a term switches.
    fn flux_on(&self, k: usize, t: f64) -> bool {
        let _ = (k, t);
        true
    }
    /// The dof pairs `(i, j)`, `i ≤ j`, the flux terms fill (each makes `(i, j)` and
    /// `(j, i)`), at a first state `u` and time `t`; fixed for the solve.
    fn couplings(&self, u: &[f64], t: f64) -> Result<Vec<(usize, usize)>, InterfaceFailure>;
    /// At `u` and `t`: the residual added to `r`, the Jacobian added to the coupling
    /// slots of `asm` from `first` (in the order of [`Self::couplings`]), and the heat
    /// leaving side A and side B of each flux term (0 while switched off).
    fn assemble(
        &self,
        u: &[f64],
        t: f64,
        r: &mut [f64],
        asm: &mut Assembler<'_>,
        first: usize,
    ) -> Result<Vec<(f64, f64)>, InterfaceFailure>;
    /// [`Self::assemble`] without the Jacobian, for a solver that keeps its matrix (every
    /// flux term linear, [`Self::is_linear`]): the residual added to `r` and the heats,
    /// the same values. `None` where the interfaces only assemble both.
    fn residual(
        &self,
        u: &[f64],
        t: f64,
        r: &mut [f64],
    ) -> Result<Option<Vec<(f64, f64)>>, InterfaceFailure> {
        let _ = (u, t, r);
        Ok(None)
    }
    /// The heat of each flux term at `u` and `t`.
    fn heat(&self, u: &[f64], t: f64) -> Result<Vec<(f64, f64)>, InterfaceFailure>;
    /// Before step `step` (1 = the first) is solved at time `t`, from the state `u`:
    /// interfaces whose surfaces move are placed at `t` (and searched anew when their
    /// schedule says so). True when their couplings changed, so the solver makes its
    /// pattern again ([`Self::couplings`]); interfaces that do not move keep them.
    fn advance(&self, u: &[f64], t: f64, step: u64) -> Result<bool, InterfaceFailure> {
        let _ = (u, t, step);
        Ok(false)
    }
    /// From now on evaluate only the points `owns` accepts (by side-A element or
    /// node; `None`: all again): a rank of a distributed solve assembling the points it
    /// owns, so that each enters once over the ranks. Interfaces that cannot say so.
    fn own_points(
        &self,
        owns: Option<&dyn Fn(Option<crate::mesh::ElemId>, Option<NodeId>) -> bool>,
    ) -> Result<(), InterfaceFailure> {
        let _ = owns;
        Err(InterfaceFailure::Failed(
            "these interfaces cannot be evaluated point by point per rank".into(),
        ))
    }
    /// This rank's share of the ties' rows ([`Self::own_points`] set): those of the
    /// points it evaluates, each tie's multipliers on the side-A nodes `carries(tie,
    /// node)` accepts (the whole tie's). Summed over the ranks they are [`Self::ties`].
    fn own_ties(&self, carries: &dyn Fn(usize, NodeId) -> bool) -> Result<Vec<TieRows>, String> {
        let _ = carries;
        Err("these interfaces cannot make their ties' rows per rank".into())
    }
    /// The problem's electrical contacts as the last [`Self::advance`] left their
    /// surfaces (moved, searched anew or made again by element death), in the problem's
    /// order; `None` while they are as the problem gave them.
    fn electric_contacts(
        &self,
    ) -> Result<Option<Vec<crate::enforce::electric::ElectricContact>>, InterfaceFailure> {
        Ok(None)
    }
}

/// The interfaces of pairings a caller built itself: one field, always on.
pub struct Terms<'a> {
    contact: &'a [ContactTerm<'a>],
    /// The geometry at each contact term's points, and where its blocks go.
    points: Vec<InterfacePoints>,
    scatters: std::cell::RefCell<Vec<Scatter>>,
    ties: Vec<TieRows>,
}

impl<'a> Terms<'a> {
    /// The terms over `dofs` (field `field`), the ties' multipliers on side-A nodes
    /// not in `fixed` (Dirichlet data) nor in an earlier tie.
    pub fn new(
        mesh: &Mesh,
        dofs: &DofMap,
        field: FieldPair,
        (contact, ties): (&'a [ContactTerm<'a>], &[TieTerm<'_>]),
        fixed: HashSet<NodeId>,
        conductivity: &[f64],
    ) -> Result<Self, String> {
        let points = contact
            .iter()
            .map(|c| {
                InterfacePoints::new(mesh, dofs, field, c.side_a, c.side_b, c.points, &c.form)
                    .map_err(|e| e.to_string())
            })
            .collect::<Result<_, _>>()?;
        let mut constrained = fixed;
        let ties = ties
            .iter()
            .map(|t| {
                let tie = mortar_tie(
                    mesh,
                    dofs,
                    field,
                    t.side_a,
                    t.side_b,
                    t.points,
                    conductivity,
                    &mut constrained,
                    t.multipliers,
                )
                .map_err(|e| e.to_string())?;
                let own = tie
                    .nodes
                    .iter()
                    .map(|&n| dofs.dof(field.a, n).map_or(usize::MAX, |d| d.index()))
                    .collect();
                Ok(TieRows {
                    own,
                    entries: tie
                        .entries
                        .iter()
                        .map(|&(k, d, c)| (k as usize, d as usize, c))
                        .collect(),
                    rhs: tie.psi_integral.iter().map(|w| t.offset * w).collect(),
                    crosspoints: tie.crosspoints,
                    side_a_dofs: tie.side_a_dofs.iter().map(|&d| d as usize).collect(),
                    side_b_dofs: tie.side_b_dofs.iter().map(|&d| d as usize).collect(),
                    dual: t.multipliers == Multipliers::Dual,
                })
            })
            .collect::<Result<_, String>>()?;
        Ok(Terms {
            contact,
            points,
            scatters: Default::default(),
            ties,
        })
    }
}

impl Interfaces for Terms<'_> {
    fn flux_count(&self) -> usize {
        self.contact.len()
    }

    fn is_linear(&self) -> bool {
        self.contact.iter().all(|c| c.linear)
    }

    fn ties(&self) -> Result<Vec<TieRows>, String> {
        Ok(self.ties.clone())
    }

    fn tie_on(&self, _: usize, _: f64) -> bool {
        true
    }

    fn couplings(&self, _: &[f64], _: f64) -> Result<Vec<(usize, usize)>, InterfaceFailure> {
        let mut out = Vec::new();
        let mut scatters = Vec::with_capacity(self.points.len());
        for points in &self.points {
            let cp = points.couplings();
            scatters.push(points.scatter(&cp, out.len()));
            out.extend(cp);
        }
        *self.scatters.borrow_mut() = scatters;
        Ok(out)
    }

    fn assemble(
        &self,
        u: &[f64],
        _: f64,
        r: &mut [f64],
        asm: &mut Assembler<'_>,
        first: usize,
    ) -> Result<Vec<(f64, f64)>, InterfaceFailure> {
        let scatters = self.scatters.borrow();
        let mut heat = Vec::with_capacity(self.contact.len());
        for ((c, points), scatter) in self.contact.iter().zip(&self.points).zip(scatters.iter()) {
            let s = points
                .evaluate_into(&c.form, u, asm, scatter, first)
                .map_err(|e| InterfaceFailure::Failed(e.to_string()))?;
            for &(d, v) in &s.residual {
                r[d as usize] += v;
            }
            heat.push(s.heat());
        }
        Ok(heat)
    }

    fn heat(&self, u: &[f64], _: f64) -> Result<Vec<(f64, f64)>, InterfaceFailure> {
        self.contact
            .iter()
            .zip(&self.points)
            .map(|(c, points)| {
                points
                    .evaluate(&c.form, u)
                    .map(|s| s.heat())
                    .map_err(|e| InterfaceFailure::Failed(e.to_string()))
            })
            .collect()
    }
}
