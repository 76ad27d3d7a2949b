use super::{Contributions, EmbedError, Embedding, Enforcement, Heat, Law, argument};
use std::cell::Cell;

use crate::enforce::conductance::{ConductanceError, ConductanceModel, PointState};
use crate::enforce::interface::{HInput, HValue, InterfaceForm, InterfacePoints};

impl Embedding {
    /// The interface terms of every flux-type interaction at the host's field `u` (by
    /// host dof): residual, Jacobian (exact, including dh/dT) and heat.
    pub fn contributions(&self, u: &[f64]) -> Result<Contributions, EmbedError> {
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
        let mut out = Contributions::default();
        for p in &self.pairs {
            let result = Self::searched(p)?;
            let Enforcement::Flux {
                form,
                law,
                offset,
                beta,
            } = &p.enforcement
            else {
                out.heat.push(None);
                continue;
            };
            // A plugin's fault, kept to tell a plugin failure or cutback request from
            // the other failures once the interface terms stop at it.
            let fault: Cell<Option<ConductanceError>> = Cell::new(None);
            let h = |x: &HInput| -> Result<HValue, String> {
                let (model, pressure): (&dyn ConductanceModel, f64) = match law {
                    Law::Constant(h) => {
                        return Ok(HValue {
                            h: *h,
                            ..HValue::default()
                        });
                    }
                    Law::Model(m, pressure) => (m.as_ref(), *pressure),
                    Law::Plugin(m, pressure) => (m.as_ref(), *pressure),
                };
                let state = PointState {
                    gap: x.gap,
                    pressure,
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
                    }),
                    Err(e) => {
                        let message = e.to_string();
                        if matches!(law, Law::Plugin(..)) {
                            fault.set(Some(e));
                        }
                        Err(message)
                    }
                }
            };
            let form = InterfaceForm {
                form: *form,
                h: &h,
                offset: *offset,
                beta: *beta,
                conductivity: &self.conductivity,
            };
            let points = match p.points.get() {
                Some(points) => points,
                None => {
                    let made = InterfacePoints::new(
                        &self.mesh,
                        &self.dofs,
                        self.field,
                        &p.a,
                        &p.b,
                        &result.points,
                        &form,
                    )
                    .map_err(|source| EmbedError::Enforcement {
                        side_a: p.side_a.name.clone(),
                        side_b: p.side_b.name.clone(),
                        source,
                    })?;
                    p.points.get_or_init(|| made)
                }
            };
            let s = points.evaluate(&form, &local).map_err(|source| {
                let (side_a, side_b) = (p.side_a.name.clone(), p.side_b.name.clone());
                match fault.take() {
                    Some(ConductanceError::Cutback { factor, .. }) => EmbedError::Cutback {
                        side_a,
                        side_b,
                        factor,
                        message: source.to_string(),
                    },
                    Some(_) => EmbedError::Plugin {
                        side_a,
                        side_b,
                        message: source.to_string(),
                    },
                    None => EmbedError::Enforcement {
                        side_a,
                        side_b,
                        source,
                    },
                }
            })?;
            let host = |d: u32| self.host_dof[d as usize];
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
}
