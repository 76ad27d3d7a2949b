//! What a search paired and what the interface carries, point by point and face by
//! face: [`Embedding::coverage`] (points and area paired, the unpaired points and why,
//! the gap range), [`Embedding::point_fields`] and [`Embedding::face_fields`] (flux,
//! gap, contact fraction) of flux interactions at a host field, and the same of mortar
//! ties from their multipliers ([`Embedding::tie_point_fields`],
//! [`Embedding::tie_face_fields`]).
//!
//! Faces are named as the host gave them: element index (0-based, block after block)
//! and 1-based local side. Fluxes are W/m² from side A to side B.

use super::{EmbedError, Embedding, TieConstraints, argument};

use crate::enforce::interface::PointFlux;
use crate::search::pairing::{ContactPoint, PointStatus, SearchStats, SurfaceGeometry};

/// Why a side-A point found no partner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum UnpairedReason {
    /// No side-B face within reach of the point.
    NoFace,
    /// A face had the point inside, but farther along the normal than the tolerance.
    TooFar,
    /// A face had the point inside, but its normal was not opposed enough.
    NormalsNotOpposed,
    /// Outside the `Restrict Contact To Subdomain` sphere.
    OutsideSubdomain,
}

/// One side-A point the search did not pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Unpaired {
    /// Its index among the interaction's points (as in [`Embedding::point_fields`]).
    pub point: usize,
    pub x: [f64; 3],
    pub reason: UnpairedReason,
}

/// What the search of one interaction paired ([`Embedding::coverage`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Coverage {
    /// Side-A integration points (or nodes, for a node surface).
    pub points: usize,
    pub paired_points: usize,
    /// Side A's area (m²) and the part of it paired with side B.
    pub area: f64,
    pub paired_area: f64,
    /// Every unpaired point with its reason.
    pub unpaired: Vec<Unpaired>,
    /// Smallest and largest gap over the paired points (m, positive open); `None` when
    /// nothing paired.
    pub gap_range: Option<(f64, f64)>,
}

/// A face as the host names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct HostFace {
    /// 0-based element index, numbered block after block.
    pub element: usize,
    /// 1-based local side, Exodus II order.
    pub side: u8,
}

/// One side-A point's values at a field ([`Embedding::point_fields`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointValues {
    pub x: [f64; 3],
    /// Integration weight (m²): the point's share of side A's area.
    pub weight: f64,
    pub paired: bool,
    /// The side-A face it lies on (`None` for a node of a node surface).
    pub side_a: Option<HostFace>,
    /// The side-B face it paired with.
    pub side_b: Option<HostFace>,
    /// Signed gap (m), positive open; 0 where not paired.
    pub gap: f64,
    /// Heat flux from side A to side B (W/m²); 0 where not paired. For a mortar tie
    /// this is the multiplier field λ_h at the point.
    pub flux: f64,
    /// Side A's temperature and side B's at the projection (NaN where not known: an
    /// unpaired point, a mortar tie).
    pub temp_a: f64,
    pub temp_b: f64,
    /// Mortar ties: the multiplier field λ_h = Σ ψ_k λ_k at the point (standard or
    /// dual multipliers, whichever the tie has); `None` for flux interactions and for
    /// points without a multiplier.
    pub multiplier: Option<f64>,
}

/// One face's values at a field ([`Embedding::face_fields`]): means over its paired
/// points weighted by their weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FaceValues {
    pub face: HostFace,
    /// 0 for a side-A face, 1 for a side-B face.
    pub side: u8,
    /// The face's area (m², as searched).
    pub area: f64,
    /// Its paired area (m²) and that over its area, in [0, 1].
    pub paired_area: f64,
    pub fraction: f64,
    /// Mean gap (m) and mean flux from A to B (W/m²) over the paired area; 0 with none.
    pub gap: f64,
    pub flux: f64,
}

fn host_face(geometry: &SurfaceGeometry, k: u32) -> Option<HostFace> {
    geometry.faces.get(k as usize).map(|f| HostFace {
        element: f.side.elem.0 as usize,
        side: f.side.side,
    })
}

/// The unpaired points of a pairing with their reasons.
fn unpaired(points: &[ContactPoint]) -> Vec<Unpaired> {
    points
        .iter()
        .enumerate()
        .filter_map(|(k, p)| {
            let reason = match p.status {
                PointStatus::Matched => return None,
                PointStatus::Unmatched => UnpairedReason::NoFace,
                PointStatus::RejectedDistance => UnpairedReason::TooFar,
                PointStatus::RejectedAngle => UnpairedReason::NormalsNotOpposed,
                PointStatus::RejectedSubdomain => UnpairedReason::OutsideSubdomain,
            };
            Some(Unpaired {
                point: k,
                x: p.x,
                reason,
            })
        })
        .collect()
}

impl Coverage {
    fn of(stats: &SearchStats, points: &[ContactPoint]) -> Coverage {
        Coverage {
            points: stats.points,
            paired_points: stats.matched,
            area: stats.side_a_area,
            paired_area: stats.overlap_area,
            unpaired: unpaired(points),
            gap_range: stats.gap_min.zip(stats.gap_max),
        }
    }
}

/// Per face of `a` (and of `b` with `side_b`) the weighted means of its paired points'
/// gap and flux (`flux[k]`, the flux at point k, `None` where there is none): the one
/// aggregation behind [`Embedding::face_fields`] and `seam run`'s contact output.
pub(crate) fn face_values(
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    points: &[ContactPoint],
    flux: impl Fn(usize) -> Option<f64>,
    side_b: bool,
) -> Vec<FaceValues> {
    #[derive(Clone, Copy, Default)]
    struct Sums {
        weight: f64,
        gap: f64,
        flux: f64,
    }
    let mut on_a = vec![Sums::default(); a.faces.len()];
    let mut on_b = vec![Sums::default(); b.faces.len()];
    for (k, p) in points.iter().enumerate() {
        let Some((fa, fb)) = p.matched_faces() else {
            continue;
        };
        let q = flux(k).unwrap_or(0.0);
        for s in [&mut on_a[fa], &mut on_b[fb]] {
            s.weight += p.weight;
            s.gap += p.weight * p.gap;
            s.flux += p.weight * q;
        }
    }
    let mut out = Vec::with_capacity(on_a.len() + if side_b { on_b.len() } else { 0 });
    let mut push = |geometry: &SurfaceGeometry, sums: &[Sums], side: u8| {
        for (f, s) in geometry.faces.iter().zip(sums) {
            // Per revolution in an axisymmetric model, as the points' weights are.
            let area = f.measure(geometry.axisymmetric);
            let paired = s.weight > 0.0;
            out.push(FaceValues {
                face: HostFace {
                    element: f.side.elem.0 as usize,
                    side: f.side.side,
                },
                side,
                area,
                paired_area: s.weight,
                // Σw of a fully covered flat face is its area up to round-off; clamp.
                fraction: if area > 0.0 {
                    (s.weight / area).clamp(0.0, 1.0)
                } else {
                    0.0
                },
                gap: if paired { s.gap / s.weight } else { 0.0 },
                flux: if paired { s.flux / s.weight } else { 0.0 },
            });
        }
    };
    push(a, &on_a, 0);
    if side_b {
        push(b, &on_b, 1);
    }
    out
}

impl Embedding {
    fn pair_at(&self, i: usize) -> Result<&super::Pair, EmbedError> {
        self.pairs.get(i).ok_or_else(|| {
            argument(
                format!("no interaction {i}, there are {}", self.pairs.len()),
                "interaction indices are 0-based, in the order they were added",
            )
        })
    }

    /// What the last search of interaction `i` paired.
    pub fn coverage(&self, i: usize) -> Result<Coverage, EmbedError> {
        let p = self.pair_at(i)?;
        let r = Self::searched(p)?;
        Ok(Coverage::of(&r.stats, &r.points))
    }

    /// The values at every side-A point of flux interaction `i` at the host's field `u`
    /// (by host dof), in the interaction's point order. A mortar tie is refused: its
    /// fields come from its multipliers ([`Self::tie_point_fields`]).
    pub fn point_fields(&self, i: usize, u: &[f64]) -> Result<Vec<PointValues>, EmbedError> {
        let (p, fluxes) = self.point_fluxes(i, u)?;
        let points = &Self::searched(p)?.points;
        Ok(points
            .iter()
            .zip(&fluxes)
            .map(|(q, f)| point_values(p, q, *f, None))
            .collect())
    }

    /// The flux at each point of flux interaction `i` at the host's field `u` (`None`
    /// where it paired nothing), with the temperatures the model saw.
    pub(crate) fn point_flux(
        &self,
        i: usize,
        u: &[f64],
    ) -> Result<Vec<Option<PointFlux>>, EmbedError> {
        Ok(self.point_fluxes(i, u)?.1)
    }

    /// Flux interaction `i` and the flux at each of its points at the host's field `u`.
    fn point_fluxes(
        &self,
        i: usize,
        u: &[f64],
    ) -> Result<(&super::Pair, Vec<Option<PointFlux>>), EmbedError> {
        let p = self.pair_at(i)?;
        let local = self.local_field(u)?;
        let count = Self::searched(p)?.points.len();
        // With points kept (a rank's own), the cache numbers them in `kept`'s order.
        let cached = p.kept.as_ref().map_or(count, Vec::len);
        let fluxes = self
            .with_form(p, |cache, form| cache.point_flux(form, &local, cached))?
            .ok_or_else(|| tie_refused(p))?;
        let Some(kept) = &p.kept else {
            return Ok((p, fluxes));
        };
        let mut out = vec![None; count];
        for (&k, f) in kept.iter().zip(fluxes) {
            out[k] = f;
        }
        Ok((p, out))
    }

    /// Per face of flux interaction `i` at the host's field `u`: side A's faces, then
    /// side B's with `side_b`.
    pub fn face_fields(
        &self,
        i: usize,
        u: &[f64],
        side_b: bool,
    ) -> Result<Vec<FaceValues>, EmbedError> {
        let (p, fluxes) = self.point_fluxes(i, u)?;
        let points = &Self::searched(p)?.points;
        Ok(face_values(
            &p.a,
            &p.b,
            points,
            |k| fluxes[k].map(|f| f.q),
            side_b,
        ))
    }

    /// The values at every side-A point of a mortar tie for its multipliers `lambda`
    /// (one per multiplier: the host's unknowns for standard multipliers, or
    /// [`TieConstraints::dual_multipliers`] for a condensed dual tie).
    pub fn tie_point_fields(
        &self,
        tie: &TieConstraints,
        lambda: &[f64],
    ) -> Result<Vec<PointValues>, EmbedError> {
        self.tie_point_values(tie.interaction, &self.tie_field(tie, lambda)?)
    }

    /// Per face of a mortar tie for its multipliers `lambda` (see
    /// [`Self::tie_point_fields`]): side A's faces, then side B's with `side_b`.
    pub fn tie_face_fields(
        &self,
        tie: &TieConstraints,
        lambda: &[f64],
        side_b: bool,
    ) -> Result<Vec<FaceValues>, EmbedError> {
        self.tie_face_values(tie.interaction, &self.tie_field(tie, lambda)?, side_b)
    }

    /// The multiplier field of `tie` for `lambda` at each point of its pairing (`None`
    /// where it has no multiplier).
    pub(crate) fn tie_field(
        &self,
        tie: &TieConstraints,
        lambda: &[f64],
    ) -> Result<Vec<Option<f64>>, EmbedError> {
        let p = self.pair_at(tie.interaction)?;
        tie.multiplier_field(lambda, Self::searched(p)?.points.len())
    }

    /// The point values of the tie of interaction `i` for its multiplier `field` (one
    /// per point).
    pub(crate) fn tie_point_values(
        &self,
        i: usize,
        field: &[Option<f64>],
    ) -> Result<Vec<PointValues>, EmbedError> {
        let p = self.pair_at(i)?;
        let points = &Self::searched(p)?.points;
        Ok(points
            .iter()
            .zip(field)
            .map(|(q, m)| {
                let flux = m.map(|m| PointFlux {
                    q: m,
                    temp_a: f64::NAN,
                    temp_b: f64::NAN,
                });
                point_values(p, q, flux, *m)
            })
            .collect())
    }

    /// The face values of the tie of interaction `i` for its multiplier `field`.
    pub(crate) fn tie_face_values(
        &self,
        i: usize,
        field: &[Option<f64>],
        side_b: bool,
    ) -> Result<Vec<FaceValues>, EmbedError> {
        let p = self.pair_at(i)?;
        let points = &Self::searched(p)?.points;
        Ok(face_values(&p.a, &p.b, points, |k| field[k], side_b))
    }
}

fn tie_refused(p: &super::Pair) -> EmbedError {
    argument(
        format!(
            "interaction {} / {} is a mortar tie: its flux is its multiplier field",
            p.side_a.name, p.side_b.name
        ),
        "use tie_point_fields / tie_face_fields with the tie's multipliers",
    )
}

fn point_values(
    p: &super::Pair,
    q: &ContactPoint,
    flux: Option<PointFlux>,
    multiplier: Option<f64>,
) -> PointValues {
    let paired = q.status == PointStatus::Matched;
    PointValues {
        x: q.x,
        weight: q.weight,
        paired,
        side_a: q.a_face.and_then(|k| host_face(&p.a, k)),
        side_b: q.matched_b_face().and_then(|k| host_face(&p.b, k as u32)),
        gap: if paired { q.gap } else { 0.0 },
        flux: flux.map_or(0.0, |f| f.q),
        temp_a: flux.map_or(f64::NAN, |f| f.temp_a),
        temp_b: flux.map_or(f64::NAN, |f| f.temp_b),
        multiplier,
    }
}
