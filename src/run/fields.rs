//! What `seam run` derives from a solved state for its results, beyond the nodal
//! temperature: the heat flux −k∇T per element, the contact fields per face of the
//! enforced interactions, and the heat of each mechanism of a summed conductance.
//!
//! Entry points: [`element_heat_flux`], [`contact_faces`] (and [`ContactFields::nodal`]
//! for the side-A nodes) as [`crate::scene::ContactView`] asks, [`mechanism_heat`] with
//! [`mechanism_names`]; [`Derived`] holds what the run derives from one state.
//!
//! Conventions: the interface flux is the heat flux from side A to side B (W/m²), the
//! integrand of the heat leaving side A ([`crate::enforce::interface::point_flux`]);
//! gaps are the search's signed normal gaps (m, > 0 open); a face's matched area is the
//! sum of the weights of its matched points (segments integration: the clipped overlap
//! area, exact for flat faces).

use crate::enforce::conductance::{ConductanceModel, PointState};
use crate::enforce::interface::PointFlux;
use crate::fem::shape::reference_nodes;
use crate::fem::{MAX_NODES, eval_point};
use crate::heat::law::Law;
use crate::heat::transient::BlockLaws;
use crate::mesh::{Mesh, NodeId};
use crate::search::scene::Pairing;

/// −k∇T at the centroid of every element, x, y, z interleaved, in dense element order
/// (W/m²). k is the block's conductivity law at the centroid temperature, position and
/// `time`. Elements without shape functions (shells, beams) or with a node without a
/// temperature get NaN. The gradient of trilinear and linear elements at the centroid
/// is exact for a temperature linear in space, so a 1-D linear field gives q = k ΔT / L
/// in every element to round-off.
pub(super) fn element_heat_flux(
    mesh: &Mesh,
    laws: &[BlockLaws],
    temperature: &[f64],
    time: f64,
) -> Result<Vec<f64>, String> {
    let law = |b: usize| Some(&laws[b].conductivity);
    element_flux(
        mesh,
        law,
        temperature,
        temperature,
        time,
        ("heat flux", "conductivity"),
    )
}

/// −σ∇V at the centroid of every element (A/m²), as [`element_heat_flux`] with the
/// block's electrical conductivity at the centroid temperature; NaN in blocks without a
/// voltage.
pub(super) fn element_current_density(
    mesh: &Mesh,
    sigma: &[Option<Law>],
    temperature: &[f64],
    voltage: &[f64],
    time: f64,
) -> Result<Vec<f64>, String> {
    let law = |b: usize| sigma[b].as_ref();
    element_flux(
        mesh,
        law,
        temperature,
        voltage,
        time,
        ("current density", "electrical conductivity"),
    )
}

/// −c∇p at the centroid of every element for a potential `p` and a coefficient law
/// `coefficient(block)` of the centroid temperature (NaN where either is missing).
fn element_flux<'l>(
    mesh: &Mesh,
    coefficient: impl Fn(usize) -> Option<&'l Law>,
    temperature: &[f64],
    potential: &[f64],
    time: f64,
    (what, law_name): (&str, &str),
) -> Result<Vec<f64>, String> {
    let mut out = Vec::with_capacity(3 * mesh.num_elems());
    for (b, block) in mesh.blocks.iter().enumerate() {
        let (Some(reference), Some(law)) = (reference_nodes(block.topology), coefficient(b)) else {
            out.extend(std::iter::repeat_n(f64::NAN, 3 * block.len()));
            continue;
        };
        let mut center = [0.0; 3];
        for r in reference {
            for d in 0..3 {
                center[d] += r[d] / reference.len() as f64;
            }
        }
        for k in 0..block.len() {
            let nodes = block.elem_nodes(k);
            let mut coords = [[0.0; 3]; MAX_NODES];
            let mut t = [0.0; MAX_NODES];
            let mut p = [0.0; MAX_NODES];
            for (a, n) in nodes.iter().enumerate() {
                coords[a] = mesh.coords[n.index()];
                t[a] = temperature.get(n.index()).copied().unwrap_or(f64::NAN);
                p[a] = potential.get(n.index()).copied().unwrap_or(f64::NAN);
            }
            let nn = nodes.len();
            if t[..nn].iter().chain(&p[..nn]).any(|v| !v.is_finite()) {
                out.extend([f64::NAN; 3]);
                continue;
            }
            let elem = block.first_elem.0 as usize + k;
            let pv = eval_point(block.topology, &coords[..nn], center, 1.0).map_err(|e| {
                format!(
                    "{what}: element {} is inverted at its centroid (det J = {:.3e})",
                    mesh.elem_numbers
                        .get(elem)
                        .copied()
                        .unwrap_or(elem as i64 + 1),
                    e.det
                )
            })?;
            let mut tc = 0.0;
            let mut grad = [0.0; 3];
            for (((n, g), t), p) in pv.n.iter().zip(&pv.grad).zip(&t).zip(&p).take(nn) {
                tc += n * t;
                for (gd, dn) in grad.iter_mut().zip(g) {
                    *gd += dn * p;
                }
            }
            let (c, _) = law
                .eval(tc, pv.x, time)
                .map_err(|e| format!("{what}: {law_name} of block {}: {e}", block.sierra_name()))?;
            out.extend(grad.map(|g| -c * g + 0.0));
        }
    }
    Ok(out)
}

/// One face of the contact output.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct ContactFace {
    pub nodes: [NodeId; 4],
    pub len: u8,
    /// The interaction, 1-based in the run's order (the order of `interface_heat.csv`
    /// rows and of the `--json` interactions).
    pub interaction: u32,
    /// 0 for a side-A face, 1 for a side-B face.
    pub side: u8,
    /// Area-weighted mean gap over the matched points (m); 0 with none.
    pub gap: f64,
    /// Matched area / face area, in [0, 1].
    pub fraction: f64,
    /// Matched area (m²).
    pub area: f64,
    /// The face's area (m², as searched).
    pub face_area: f64,
    /// Mean heat flux from side A to side B over the matched area (W/m²); 0 with no
    /// matched point, NaN for an interaction whose point fluxes were not derived.
    pub flux: f64,
}

/// The contact output of one state: faces and, for Exodus, their values on the side-A
/// nodes.
#[derive(Clone, Debug, Default)]
pub(super) struct ContactFields {
    pub faces: Vec<ContactFace>,
}

/// The faces of one interaction (`interaction`, 1-based) with their fields: side A's
/// always, side B's with `side_b`. `fluxes` holds each point's flux (from
/// [`crate::enforce::interface::point_flux`]), or is `None` for an interaction without
/// per-point flux.
pub(super) fn contact_faces(
    pairing: &Pairing,
    interaction: u32,
    fluxes: Option<&[Option<PointFlux>]>,
    side_b: bool,
    out: &mut ContactFields,
) {
    // The aggregation of the embedding API's face fields (one implementation).
    let (a, b) = (&pairing.side_a_geometry, &pairing.side_b_geometry);
    let values = crate::embed::face_values(
        a,
        b,
        &pairing.result.points,
        |k| {
            fluxes
                .and_then(|f| f.get(k).copied().flatten())
                .map(|f| f.q)
        },
        side_b,
    );
    let geometry = a
        .faces
        .iter()
        .chain(if side_b { &b.faces[..] } else { &[] });
    for (f, v) in geometry.zip(values) {
        out.faces.push(ContactFace {
            nodes: f.nodes,
            len: f.len,
            interaction,
            side: v.side,
            gap: v.gap,
            fraction: v.fraction,
            area: v.paired_area,
            face_area: v.area,
            flux: if fluxes.is_some() { v.flux } else { f64::NAN },
        });
    }
}

impl ContactFields {
    /// The side-A faces' fields on their nodes, for a nodal Exodus variable: per node,
    /// `contact_gap` and `interface_flux` are means over its faces weighted by matched
    /// area, `contact_fraction` is its faces' matched area over their area; 0 on nodes
    /// of no side-A face (and NaN fluxes count as 0). Returns (gap, fraction, flux).
    pub(super) fn nodal(&self, mesh: &Mesh) -> [Vec<f64>; 3] {
        let n = mesh.num_nodes();
        let (mut area, mut matched, mut gap, mut flux) =
            (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for f in self.faces.iter().filter(|f| f.side == 0) {
            for node in &f.nodes[..f.len as usize] {
                let i = node.index();
                area[i] += f.face_area;
                matched[i] += f.area;
                gap[i] += f.area * f.gap;
                if f.flux.is_finite() {
                    flux[i] += f.area * f.flux;
                }
            }
        }
        let ratio = |num: &[f64], den: &[f64]| -> Vec<f64> {
            num.iter()
                .zip(den)
                .map(|(a, b)| if *b > 0.0 { a / b } else { 0.0 })
                .collect()
        };
        [
            ratio(&gap, &matched),
            ratio(&matched, &area)
                .into_iter()
                .map(|v| v.min(1.0))
                .collect(),
            ratio(&flux, &matched),
        ]
    }
}

/// The labels of a summed model's mechanisms, for `interface_heat.csv`: each part's
/// name, with `#k` (1-based) added to names that occur more than once. Empty for a
/// model that is not a sum.
pub(super) fn mechanism_names(model: &dyn ConductanceModel) -> Vec<String> {
    let names: Vec<String> = model.mechanisms().iter().map(|m| m.name()).collect();
    names
        .iter()
        .enumerate()
        .map(|(k, n)| {
            if names.iter().filter(|m| *m == n).count() > 1 {
                format!("{n}#{}", k + 1)
            } else {
                n.clone()
            }
        })
        .collect()
}

/// The heat each mechanism of a summed conductance carries out of side A (W): the
/// point flux q split in proportion to the mechanisms' h at the point's state,
/// `Q_i = Σ w q h_i / Σ_j h_j`. A mechanism's h in the flux is exact for the resistance
/// form (q = h [u]) and, for the Robin–Nitsche form, q = h j* with the consistent jump
/// j* = (α[u] − {k∂u})/(h + α), so each mechanism's share is h_i j* in both, and the
/// shares add up to the interaction's heat. A point where any mechanism fails (a
/// quarantined point) or where h is 0 contributes to no mechanism.
pub(super) fn mechanism_heat(
    model: &dyn ConductanceModel,
    pairing: &Pairing,
    fluxes: &[Option<PointFlux>],
    pressure: impl Fn(usize) -> f64,
    time: f64,
) -> Vec<f64> {
    let parts = model.mechanisms();
    let mut out = vec![0.0; parts.len()];
    let mut h = vec![0.0; parts.len()];
    for (k, (p, f)) in pairing.result.points.iter().zip(fluxes).enumerate() {
        let Some(f) = f else { continue };
        let state = PointState {
            gap: p.gap - p.offset,
            pressure: pressure(k),
            temp_a: f.temp_a,
            temp_b: f.temp_b,
            x: p.x,
            time,
        };
        let mut ok = true;
        for (hi, part) in h.iter_mut().zip(parts) {
            match part.value(&state) {
                Ok(v) => *hi = v,
                Err(_) => ok = false,
            }
        }
        let total: f64 = h.iter().sum();
        if !ok || total <= 0.0 {
            continue;
        }
        for (o, hi) in out.iter_mut().zip(&h) {
            *o += p.weight * f.q * hi / total;
        }
    }
    out
}

/// The points of one interaction for `contact_points.vtu`: its 1-based index, its
/// pairing and the flux at its points (if known).
pub(super) type PointsOf<'a> = (u32, &'a Pairing, Option<&'a [Option<PointFlux>]>);

/// What a solved state gives beyond its temperature, per interaction (in the run's
/// order): the flux at each point (`None` where not asked for; a multiplier tie's is its
/// multiplier field, [`crate::enforce::mortar::MortarTie::point_flux`])
/// and the heat of each mechanism of a summed conductance (empty otherwise).
#[derive(Debug, Default)]
pub(super) struct Derived {
    pub fluxes: Vec<Option<Vec<Option<PointFlux>>>>,
    pub mechanisms: Vec<Vec<f64>>,
}
