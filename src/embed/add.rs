use super::{
    EmbedError, Embedding, Enforcement, Image, Interaction, Law, Model, Overclosure, Pair,
    Periodic, argument,
};
use std::path::Path;

use crate::diag::did_you_mean;
use crate::enforce::interface::Form;
use crate::mesh::Mesh;
use crate::search::SearchSettings;
use crate::search::pairing::{Sphere, SurfaceGeometry};
use crate::search::periodic::{
    PeriodicError, PeriodicTransform, check_closure, landing, periodic_map,
};
use crate::surface::{ContactSurface, SurfaceFace, SurfaceKind};

impl Embedding {
    /// The mesh seam built from the host's arrays (for inspection and output).
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    fn surface(&self, name: &str) -> Result<ContactSurface, EmbedError> {
        let Some(set) = self.mesh.find_side_set(name) else {
            let names: Vec<String> = self.mesh.side_sets.iter().map(|s| s.name.clone()).collect();
            let help = did_you_mean(name, names.iter().map(String::as_str)).map_or_else(
                || format!("the surfaces are: {}", names.join(", ")),
                |s| format!("did you mean `{s}`?"),
            );
            return Err(EmbedError::UnknownSurface {
                name: name.into(),
                help,
            });
        };
        let ss = &self.mesh.side_sets[set];
        Ok(ContactSurface {
            name: ss.sierra_name(),
            kind: SurfaceKind::Faces,
            faces: ss
                .sides
                .iter()
                .map(|&side| SurfaceFace {
                    side,
                    loft: 0.0,
                    origin: 0,
                })
                .collect(),
            tributary: Vec::new(),
            nodes: Vec::new(),
            origins: vec![(format!("surface {}", ss.name), ss.sides.len())],
            parent: None,
        })
    }

    fn geometry(&self, s: &ContactSurface) -> Result<SurfaceGeometry, EmbedError> {
        SurfaceGeometry::from_surface(&self.mesh, s, &self.mesh.coords)
            .map_err(|e| argument(e.to_string(), "interfaces are searched in 3-D"))
    }

    pub(super) fn pair(
        &self,
        side_a: ContactSurface,
        side_b: ContactSurface,
        settings: SearchSettings,
        overclosure: Overclosure,
        subdomain: Option<Sphere>,
        enforcement: Enforcement,
    ) -> Result<Pair, EmbedError> {
        let (a, b) = (self.geometry(&side_a)?, self.geometry(&side_b)?);
        Ok(Pair::new(
            side_a,
            side_b,
            (a, b),
            settings,
            Some(overclosure),
            subdomain,
            None,
            enforcement,
            self.field.into(),
        ))
    }

    /// A periodic pair built in code: side A's image under `periodic`, checked to land
    /// on side B (the checks of a deck's periodicity: an N-fold turn closes up, the
    /// worst image node is within 5 % of B's mean face size).
    fn periodic_pair(
        &self,
        side_a: ContactSurface,
        side_b: ContactSurface,
        settings: SearchSettings,
        periodic: &Periodic,
        enforcement: Enforcement,
    ) -> Result<Pair, EmbedError> {
        let label = format!("periodic interaction {} / {}", side_a.name, side_b.name);
        let fail = |e: &dyn std::fmt::Display, help: &str| argument(format!("{label}: {e}"), help);
        let (source, b) = (self.geometry(&side_a)?, self.geometry(&side_b)?);
        let transform = periodic.transform(&side_b.name);
        let model_size = self.mesh.model_size();
        let axisymmetric = "in an axisymmetric model a periodicity repeats along the axis (y): a translation by (0, dy)";
        if self.mesh.axisymmetric && matches!(transform, PeriodicTransform::Cylindrical { .. }) {
            return Err(fail(
                &PeriodicError::CylindricalInAxisymmetric,
                axisymmetric,
            ));
        }
        check_closure(&transform, &source, model_size).map_err(|e| {
            fail(
                &e,
                "give the angle to full precision (e.g. 360/7 as 51.428571428571431)",
            )
        })?;
        let mut map = periodic_map(
            &transform,
            &source,
            Some(&b),
            Path::new("."),
            &label,
            model_size,
        )
        .map_err(|e| {
            let help = match e {
                PeriodicError::ZeroAxis => "give a non-zero axis",
                PeriodicError::NoMeanNormal => "`AlignSurface` needs two roughly planar surfaces",
                _ => {
                    "fix the Lua map: each component is an expression in x, y, z or `file.lua:function` (under the working directory)"
                }
            };
            fail(&e, help)
        })?;
        let name = format!("{}_image", side_a.name);
        let a = source
            .mapped(map.as_mut(), &name)
            .map_err(|e| fail(&e, "the map failed while mapping side A's nodes"))?;
        crate::search::periodic::check_axisymmetric(&transform, &source, &a, model_size, |n| {
            self.mesh.node_number(n)
        })
        .map_err(|e| fail(&e, axisymmetric))?;
        if let Some(fold) =
            crate::search::periodic::check_one_to_one(&source, &a, |n| self.mesh.node_number(n))
        {
            return Err(fail(
                &PeriodicError::Folds(Box::new(fold)),
                "a periodic map carries each node to its own place on side B; check the map",
            ));
        }
        landing(&a, &b).check(&side_b.name).map_err(|e| {
            fail(
                &e,
                "the map must carry side A exactly onto side B; check the offset, axis, centre, angle or map",
            )
        })?;
        Ok(Pair::new(
            side_a,
            side_b,
            (a, b),
            settings,
            None,
            None,
            Some(Image { map, name }),
            enforcement,
            self.field.into(),
        ))
    }

    /// Add an interaction built in code; returns its index.
    pub fn add_interaction(&mut self, i: Interaction) -> Result<usize, EmbedError> {
        let check = |what: &str, v: f64, allow_inf: bool| {
            if v.is_nan() || v < 0.0 || (v.is_infinite() && !allow_inf) {
                Err(argument(
                    format!("{what} = {v} on interaction {} / {}", i.side_a, i.side_b),
                    "give a non-negative number",
                ))
            } else {
                Ok(())
            }
        };
        let enforcement = match i.model {
            Model::Conductance { h } | Model::GapConductance { h } => {
                let gap = matches!(i.model, Model::GapConductance { .. });
                // h = ∞ is the tied limit of the Robin–Nitsche form only.
                check("h", h, gap)?;
                check("penalty factor", i.beta, false)?;
                Enforcement::Flux {
                    form: if gap {
                        Form::GapConductance
                    } else {
                        Form::Conductance
                    },
                    law: match &i.conductance {
                        Some(m) => Law::Host(m.clone()),
                        None => Law::Constant(h),
                    },
                    offset: i.offset,
                    beta: i.beta,
                }
            }
            Model::TiedMortar { .. } | Model::TiedNitsche if i.conductance.is_some() => {
                return Err(argument(
                    format!(
                        "interaction {} / {}: a conductance model on a tie",
                        i.side_a, i.side_b
                    ),
                    "give the model to Model::Conductance or Model::GapConductance",
                ));
            }
            Model::TiedNitsche => {
                check("penalty factor", i.beta, false)?;
                Enforcement::Flux {
                    form: Form::TiedNitsche,
                    law: Law::Constant(0.0),
                    offset: i.offset,
                    beta: i.beta,
                }
            }
            Model::TiedMortar { multipliers } => Enforcement::Tie {
                multipliers,
                offset: i.offset,
            },
        };
        if !i.offset.is_finite() {
            return Err(argument(
                format!(
                    "offset {} on interaction {} / {}",
                    i.offset, i.side_a, i.side_b
                ),
                "give a finite temperature jump",
            ));
        }
        let (a, b) = (self.surface(&i.side_a)?, self.surface(&i.side_b)?);
        let settings = i.settings.unwrap_or_else(|| SearchSettings::defaults(3));
        let mut pair = match &i.periodic {
            None => self.pair(a, b, settings, Overclosure::StoreOffsets, None, enforcement)?,
            Some(periodic) => self.periodic_pair(a, b, settings, periodic, enforcement)?,
        };
        pair.allow_unpaired = i.allow_unpaired;
        pair.quarantine = i.quarantine;
        self.pairs.push(pair);
        Ok(self.pairs.len() - 1)
    }
}
