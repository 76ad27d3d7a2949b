//! The interface terms of flux-type interactions at a host field: residual, Jacobian and
//! heat, as triplets ([`Embedding::contributions`]) or for a state the host names
//! ([`Embedding::heat`]). Every entry point goes through [`Embedding::with_form`], which
//! turns the interaction's law into the h the interface form sees and a model's fault
//! into the matching [`EmbedError`].

use super::{
    Contributions, EmbedError, Embedding, Enforcement, Heat, Law, Pair, Quarantined, argument,
};
use std::cell::Cell;

use crate::mesh::{ElemId, NodeId};

use crate::enforce::conductance::{ConductanceError, ConductanceModel, PointState};
use crate::enforce::interface::{
    ConductivityLaw, HInput, HValue, InterfaceError, InterfaceForm, InterfacePoints,
    InterfaceSystem,
};

impl Embedding {
    /// The host's field `u` (by host dof) in seam's numbering, checked: long enough and
    /// finite.
    pub(super) fn local_field(&self, u: &[f64]) -> Result<Vec<f64>, EmbedError> {
        let mut local = vec![0.0; self.dofs.len()];
        for (d, &h) in self.host_dof.iter().enumerate() {
            local[d] = *u.get(h).ok_or_else(|| {
                argument(
                    format!("the field has {} entries, dof {h} is needed", u.len()),
                    "pass the host's whole field vector, indexed by host dof",
                )
            })?;
        }
        if let Some(k) = u.iter().position(|v| !v.is_finite()) {
            return Err(argument(
                format!("the field is not finite at dof {k} ({})", u[k]),
                "check the host's solve",
            ));
        }
        Ok(local)
    }

    /// Run `f` with the interface form of flux interaction `p` and its points (made at
    /// the first call after a search or move): `None` for a tie. A conductance model's
    /// failure becomes [`EmbedError::Plugin`] or [`EmbedError::Cutback`] for plugins,
    /// [`EmbedError::Enforcement`] otherwise.
    pub(super) fn with_form<R>(
        &self,
        p: &Pair,
        f: impl FnOnce(&InterfacePoints, &InterfaceForm<'_>) -> Result<R, InterfaceError>,
    ) -> Result<Option<R>, EmbedError> {
        let result = Self::searched(p)?;
        let Enforcement::Flux {
            form,
            law,
            offset,
            beta,
        } = &p.enforcement
        else {
            return Ok(None);
        };
        // A model's fault, kept to tell a plugin failure or a cutback request from the
        // other failures once the interface terms stop at it.
        let fault: Cell<Option<ConductanceError>> = Cell::new(None);
        let h = |x: &HInput| -> Result<HValue, String> {
            let (model, pressure): (&dyn ConductanceModel, f64) = match law {
                Law::Constant(h) => {
                    return Ok(HValue {
                        h: *h,
                        ..HValue::default()
                    });
                }
                Law::Model {
                    model, pressure, ..
                } => (model.as_ref(), *pressure),
                Law::Host(m) => (m.as_ref(), 0.0),
            };
            let state = PointState {
                gap: x.gap,
                pressure: p.pressures.as_ref().map_or(pressure, |v| {
                    v[p.kept.as_ref().map_or(x.point, |kept| kept[x.point])]
                }),
                temp_a: x.temp_a,
                temp_b: x.temp_b,
                x: x.x,
                time: self.time,
            };
            match model.evaluate(&state) {
                Ok(c) => Ok(HValue {
                    h: c.h,
                    dh_dtemp_a: c.dh_dtemp_a,
                    dh_dtemp_b: c.dh_dtemp_b,
                    ..HValue::default()
                }),
                // Quarantined: the point contributes nothing; each Newton step meets it
                // again, so it is kept once.
                Err(e) if p.quarantine && !e.is_cutback() => {
                    let mut kept = p.quarantined.lock().unwrap_or_else(|e| e.into_inner());
                    if !kept.iter().any(|q| q.x == x.x) {
                        kept.push(Quarantined {
                            x: x.x,
                            message: e.to_string(),
                        });
                    }
                    Ok(HValue::default())
                }
                Err(e) => {
                    let message = e.to_string();
                    fault.set(Some(e));
                    Err(message)
                }
            }
        };
        // k(T) at the embedding's time, for the temperature's interactions (a species
        // interface or voltage tie has a coefficient of its own).
        let time = self.time;
        let (k_law, temperature_field) = match &p.coefficient {
            None => (self.conductivity_law.as_deref(), None),
            Some(_) => (p.coefficient_law.as_deref(), p.temperature_field),
        };
        let k_of_t = k_law.map(|law| move |b: usize, t: f64, x: [f64; 3]| law(b, t, x, time));
        let form = InterfaceForm {
            form: *form,
            h: &h,
            offset: *offset,
            beta: *beta,
            conductivity: p.coefficient(&self.conductivity),
            conductivity_of_t: k_of_t.as_ref().map(|l| l as &ConductivityLaw<'_>),
            temperature_field,
        };
        let named = |source| EmbedError::Enforcement {
            side_a: p.side_a.name.clone(),
            side_b: p.side_b.name.clone(),
            source,
        };
        let points = match p.points.get() {
            Some(points) => points,
            None => {
                let kept: Vec<_>;
                let searched = match &p.kept {
                    Some(k) => {
                        kept = k.iter().map(|&k| result.points[k]).collect();
                        &kept
                    }
                    None => &result.points,
                };
                let made = InterfacePoints::new(
                    &self.mesh, &self.dofs, p.fields, &p.a, &p.b, searched, &form,
                )
                .map_err(named)?;
                p.points.get_or_init(|| made)
            }
        };
        f(points, &form).map(Some).map_err(|source| {
            let (side_a, side_b) = (p.side_a.name.clone(), p.side_b.name.clone());
            let plugin = matches!(law, Law::Model { plugin: true, .. });
            match fault.take() {
                Some(ConductanceError::Cutback { factor, .. }) => EmbedError::Cutback {
                    side_a,
                    side_b,
                    factor,
                    message: source.to_string(),
                },
                Some(_) if plugin => EmbedError::Plugin {
                    side_a,
                    side_b,
                    message: source.to_string(),
                },
                _ => named(source),
            }
        })
    }

    /// Evaluate only the points `owns` accepts — by their side-A face's element, or
    /// their side-A node — from now until the next search or `own_points(None)`: a
    /// rank of a distributed run assembling the points it owns, so that every point
    /// enters once over the ranks. Residual, Jacobian and heat are then this process's
    /// share.
    pub fn own_points(&mut self, owns: Option<&dyn Fn(Option<ElemId>, Option<NodeId>) -> bool>) {
        for p in &mut self.pairs {
            p.kept = match (owns, &p.result) {
                (Some(owns), Some(r)) => Some(
                    (0..r.points.len())
                        .filter(|&k| {
                            let q = &r.points[k];
                            let elem = q.a_face.map(|f| p.a.faces[f as usize].side.elem);
                            let node = q
                                .a_node
                                .and_then(|n| p.a.nodes.get(n as usize))
                                .map(|n| n.0);
                            owns(elem, node)
                        })
                        .collect(),
                ),
                _ => None,
            };
            p.points = std::sync::OnceLock::new();
        }
        if let Some(e) = &mut self.evaluation {
            e.outdate();
        }
    }

    /// The interface system of flux interaction `p` at seam's field `local`.
    pub(super) fn system(
        &self,
        p: &Pair,
        local: &[f64],
    ) -> Result<Option<InterfaceSystem>, EmbedError> {
        self.with_form(p, |points, form| points.evaluate(form, local))
    }

    /// The heat of flux interaction `p` at seam's field `local`: 0 while it is switched
    /// off, `None` for a tie.
    fn pair_heat(&self, p: &Pair, local: &[f64]) -> Result<Option<Heat>, EmbedError> {
        if !p.active {
            return Ok(p.is_flux().then(Heat::default));
        }
        let residual = self.with_form(p, |points, form| points.residual(form, local))?;
        Ok(residual.map(|s| {
            let (side_a, side_b) = s.heat();
            Heat { side_a, side_b }
        }))
    }

    /// The interface terms of every flux-type interaction at the host's field `u` (by
    /// host dof): residual, Jacobian (exact, including dh/dT) and heat, as triplets. A
    /// host that assembles at every Newton step into a matrix of fixed pattern is better
    /// served by [`Self::evaluate`] (CSR, refreshed in place).
    pub fn contributions(&self, u: &[f64]) -> Result<Contributions, EmbedError> {
        let local = self.local_field(u)?;
        let mut out = Contributions::default();
        let host = |d: u32| self.host_dof[d as usize];
        for p in &self.pairs {
            if !p.active {
                out.heat.push(p.is_flux().then(Heat::default));
                continue;
            }
            let Some(s) = self.system(p, &local)? else {
                out.heat.push(None);
                continue;
            };
            for (dofs, m) in &s.blocks {
                let n = dofs.len();
                for (r, &i) in dofs.iter().enumerate() {
                    for (c, &j) in dofs.iter().enumerate() {
                        let v = m[r * n + c];
                        if v != 0.0 {
                            out.jacobian.push((host(i), host(j), v));
                        }
                    }
                }
            }
            out.residual
                .extend(s.residual.iter().map(|&(d, v)| (host(d), v)));
            out.load.extend(
                s.rhs
                    .iter()
                    .filter(|x| x.1 != 0.0)
                    .map(|&(d, v)| (host(d), v)),
            );
            let (a, b) = s.heat();
            out.heat.push(Some(Heat {
                side_a: a,
                side_b: b,
            }));
        }
        Ok(out)
    }

    /// Heat (W) leaving each side of interaction `i` at the host's field `u` (by host
    /// dof), whatever was evaluated before: `None` for a mortar tie.
    pub fn heat_of(&self, i: usize, u: &[f64]) -> Result<Option<Heat>, EmbedError> {
        let p = self.pairs.get(i).ok_or_else(|| {
            argument(
                format!("no interaction {i}, there are {}", self.pairs.len()),
                "interaction indices are 0-based, in the order they were added",
            )
        })?;
        let local = self.local_field(u)?;
        self.pair_heat(p, &local)
    }

    /// Heat (W) leaving each side of every interaction at the host's field `u` (by host
    /// dof), whatever was evaluated before: `None` for mortar ties (their heat comes
    /// from the multipliers, [`super::TieConstraints::heat`]).
    pub fn heat(&self, u: &[f64]) -> Result<Vec<Option<Heat>>, EmbedError> {
        let local = self.local_field(u)?;
        self.pairs
            .iter()
            .map(|p| self.pair_heat(p, &local))
            .collect()
    }
}
