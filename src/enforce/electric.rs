//! Electrical contacts: the voltage interface `j = h_e(T_A, T_B, g) ([V] − ΔV)` between
//! two faces, `[V] = V_A − V_B`, and the Joule heat `h_e ([V] − ΔV)²` per unit area it
//! releases into the temperatures of the two sides (the share `f_A` to side A, the rest to
//! side B, each spread by its face's shape functions), with every Jacobian block: V–V,
//! V–T through h_e(T), T–V and T–T through the heat. The solver that owns the two fields
//! is [`crate::heat::electric`].
//!
//! Conventions: the points are the matched face points of a pairing; each point's dofs
//! are its faces' temperature dofs then their voltage dofs; currents are A, heats W.

// Index loops mirror the subscripts of the formulas they implement.
#![allow(clippy::needless_range_loop)]

use crate::assembly::{Assembler, DofMap, FieldId};
use crate::enforce::interface::{HFn, HInput};
use crate::mesh::{Mesh, NodeId};
use crate::search::pairing::{ContactPoint, SurfaceGeometry, face_shapes};

/// One matched point of an electrical contact: the nodes of the two faces with the
/// point's jump coefficients (`+N_A` on side A's nodes, `−N_B` on side B's), weight,
/// gap and position.
#[derive(Clone, Copy, Debug)]
struct JoulePoint {
    nodes: [NodeId; 8],
    s: [f64; 8],
    na: u8,
    len: u8,
    weight: f64,
    gap: f64,
    x: [f64; 3],
    /// Index in the pairing's point list.
    index: u32,
}

/// An electrical contact between two surfaces: the voltage interface (a conductance
/// form, `j = h_e([V] − ΔV)`) and the Joule heat it releases, with every Jacobian block
/// (V–V, V–T through h_e(T), T–V and T–T through the heat). Built from a pairing's
/// matched points; its dofs are taken from the problem's [`DofMap`] by [`Self::bind`].
#[derive(Clone, Debug)]
pub struct ElectricContact {
    points: Vec<JoulePoint>,
    /// Runs of consecutive points on the same two faces (`start..end` into `points`):
    /// one Jacobian block and one set of pattern couplings each.
    groups: Vec<std::ops::Range<usize>>,
    /// Voltage offset ΔV (`Offset Voltage`), V.
    pub offset: f64,
    /// The share of the contact's Joule heat given to side A (0.5 by default).
    pub fraction_a: f64,
    /// Per point: its T dofs then its V dofs (after [`Self::bind`]).
    dofs: Vec<[u32; 16]>,
}

/// What one evaluation of an electrical contact carries across it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ContactPower {
    /// Current from side A to side B, A.
    pub current: f64,
    /// Joule heat released at the contact, W.
    pub joule: f64,
}

impl ElectricContact {
    /// The matched face points of a pairing (node points are not electrical contacts
    /// yet: a node surface on side A is refused).
    pub fn new(
        a: &SurfaceGeometry,
        b: &SurfaceGeometry,
        points: &[ContactPoint],
        offset: f64,
        fraction_a: f64,
    ) -> Result<ElectricContact, String> {
        if !(0.0..=1.0).contains(&fraction_a) {
            return Err(format!(
                "the share of the contact's Joule heat given to side A is {fraction_a}; give a value in [0, 1]"
            ));
        }
        let mut out = Vec::new();
        for (index, p) in points.iter().enumerate() {
            let Some(kb) = p.matched_b_face() else {
                continue;
            };
            let Some((ka, _)) = p.matched_faces() else {
                return Err(format!(
                    "surface {} is a node surface: an electrical contact needs faces on side A",
                    a.name
                ));
            };
            let (fa, fb) = (&a.faces[ka], &b.faces[kb]);
            let (la, lb) = (fa.len as usize, fb.len as usize);
            let (wa, wb) = (face_shapes(la, p.xi_a), face_shapes(lb, p.xi_b));
            let mut jp = JoulePoint {
                nodes: [NodeId(0); 8],
                s: [0.0; 8],
                na: la as u8,
                len: (la + lb) as u8,
                weight: p.weight,
                gap: p.gap - p.offset,
                x: p.x,
                index: index as u32,
            };
            for k in 0..la {
                jp.nodes[k] = fa.nodes[k];
                jp.s[k] = wa[k];
            }
            for k in 0..lb {
                jp.nodes[la + k] = fb.nodes[k];
                jp.s[la + k] = -wb[k];
            }
            out.push(jp);
        }
        let mut groups: Vec<std::ops::Range<usize>> = Vec::new();
        for (k, p) in out.iter().enumerate() {
            match groups.last_mut() {
                Some(g) if out[g.start].nodes == p.nodes && out[g.start].len == p.len => {
                    g.end = k + 1
                }
                _ => groups.push(k..k + 1),
            }
        }
        Ok(ElectricContact {
            points: out,
            groups,
            offset,
            fraction_a,
            dofs: Vec::new(),
        })
    }

    /// Number of matched points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Take each point's T and V dofs from `dofs`; a node without one is an error that
    /// names it.
    pub fn bind(
        &mut self,
        mesh: &Mesh,
        dofs: &DofMap,
        t: FieldId,
        v: FieldId,
    ) -> Result<(), String> {
        self.dofs.clear();
        for p in &self.points {
            let mut d = [0u32; 16];
            for k in 0..p.len as usize {
                let node = p.nodes[k];
                let missing = |f| {
                    format!(
                        "node {} of an electrical contact carries no {}: give its block an electrical_conductivity",
                        mesh.node_number(node),
                        dofs.field_name(f)
                    )
                };
                d[k] = dofs.dof(t, node).ok_or_else(|| missing(t))?.0;
                d[8 + k] = dofs.dof(v, node).ok_or_else(|| missing(v))?.0;
            }
            self.dofs.push(d);
        }
        Ok(())
    }

    /// Each group's `2 len` dofs (T then V), for the pattern: every pair among them.
    pub fn couplings(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for g in &self.groups {
            let (list, n) = point_dofs(&self.points[g.start], &self.dofs[g.start]);
            let list = &list[..n];
            for i in 0..list.len() {
                for j in i + 1..list.len() {
                    out.push((list[i] as usize, list[j] as usize));
                }
            }
        }
        out
    }

    /// Add the residual into `r` and the Jacobian into `asm` (its couplings numbered
    /// from `first`, as [`Self::couplings`] listed them; diagonals directly) at `u`,
    /// with the contact conductance `h` (temperatures in its input: the thermal ones at
    /// the point, each side's).
    pub fn assemble(
        &self,
        u: &[f64],
        h: &HFn<'_>,
        r: &mut [f64],
        asm: &mut Assembler<'_>,
        first: usize,
    ) -> Result<ContactPower, String> {
        let mut k = first;
        self.evaluate(u, h, r, |list, m| {
            let n = list.len();
            for i in 0..n {
                asm.add_diagonal(list[i] as usize, m[i * n + i]);
                for c in i + 1..n {
                    asm.add_coupling(k, m[i * n + c], m[c * n + i]);
                    k += 1;
                }
            }
        })
    }

    /// The residual (added into `r`) and each group's Jacobian block (its points summed),
    /// handed to `block(dofs, matrix)` (row-major over the group's dofs: its T dofs, then
    /// its V dofs), at `u`; returns the current and Joule heat.
    pub fn evaluate(
        &self,
        u: &[f64],
        h: &HFn<'_>,
        r: &mut [f64],
        mut block: impl FnMut(&[u32], &[f64]),
    ) -> Result<ContactPower, String> {
        let mut power = ContactPower::default();
        let mut m = [0.0; 256];
        for g in &self.groups {
            let (list, n) = point_dofs(&self.points[g.start], &self.dofs[g.start]);
            m[..n * n].fill(0.0);
            for (p, d) in self.points[g.clone()].iter().zip(&self.dofs[g.clone()]) {
                self.add_point((p, d), u, h, r, &mut m[..n * n], &mut power)?;
            }
            block(&list[..n], &m[..n * n]);
        }
        Ok(power)
    }

    /// One point `p` (dofs `d`) at `u`: its residual into `r`, its Jacobian block added
    /// into `m` (the group's, `2 len × 2 len`), its current and heat into `power`.
    fn add_point(
        &self,
        (p, d): (&JoulePoint, &[u32; 16]),
        u: &[f64],
        h: &HFn<'_>,
        r: &mut [f64],
        m: &mut [f64],
        power: &mut ContactPower,
    ) -> Result<(), String> {
        let (len, na) = (p.len as usize, p.na as usize);
        let n = 2 * len;
        let (mut ta, mut tb, mut va, mut vb) = (0.0, 0.0, 0.0, 0.0);
        for i in 0..len {
            let (tv, vv) = (u[d[i] as usize], u[d[8 + i] as usize]);
            if i < na {
                ta += p.s[i] * tv;
                va += p.s[i] * vv;
            } else {
                tb -= p.s[i] * tv;
                vb -= p.s[i] * vv;
            }
        }
        let jump = va - vb - self.offset;
        let hv = h(&HInput {
            gap: p.gap,
            temp_a: ta,
            temp_b: tb,
            volt_a: va,
            volt_b: vb,
            x: p.x,
            point: p.index as usize,
        })?;
        let derivatives = [hv.dh_dtemp_a, hv.dh_dtemp_b, hv.dh_dvolt_a, hv.dh_dvolt_b];
        if !(hv.h.is_finite() && derivatives.iter().all(|d| d.is_finite())) {
            return Err(format!(
                "the electrical contact conductance is not finite at ({:.6}, {:.6}, {:.6}): h = {}",
                p.x[0], p.x[1], p.x[2], hv.h
            ));
        }
        let w = p.weight;
        let j = hv.h * jump;
        power.current += w * j;
        let q = hv.h * jump * jump;
        power.joule += w * q;
        // dh/dT_i and dh/dV_i through T_A, V_A (side A's nodes) or T_B, V_B (side
        // B's), and the share of the heat row i gets.
        let dh = |i: usize| {
            if i < na {
                hv.dh_dtemp_a * p.s[i]
            } else {
                -hv.dh_dtemp_b * p.s[i]
            }
        };
        let dhv = |i: usize| {
            if i < na {
                hv.dh_dvolt_a * p.s[i]
            } else {
                -hv.dh_dvolt_b * p.s[i]
            }
        };
        let share = |i: usize| {
            if i < na {
                self.fraction_a * p.s[i]
            } else {
                -(1.0 - self.fraction_a) * p.s[i]
            }
        };
        // Local order: T dofs 0..len, V dofs len..2 len.
        for i in 0..len {
            // Voltage rows: w h [V] s_i.
            r[d[8 + i] as usize] += w * j * p.s[i];
            // Temperature rows: −share_i w h [V]².
            r[d[i] as usize] -= share(i) * w * q;
            for c in 0..len {
                // V row: V column (directly and through h), T column (through h).
                m[(len + i) * n + len + c] += w * (hv.h * p.s[c] + jump * dhv(c)) * p.s[i];
                m[(len + i) * n + c] += w * jump * p.s[i] * dh(c);
                // T row: V column (directly and through h), T column (through h).
                m[i * n + len + c] -= share(i) * w * (2.0 * j * p.s[c] + jump * jump * dhv(c));
                m[i * n + c] -= share(i) * w * jump * jump * dh(c);
            }
        }
        Ok(())
    }
}

/// A point's dofs in local order, its T dofs then its V dofs, and their count.
fn point_dofs(p: &JoulePoint, d: &[u32; 16]) -> ([u32; 16], usize) {
    let len = p.len as usize;
    let mut out = [0u32; 16];
    out[..len].copy_from_slice(&d[..len]);
    out[len..2 * len].copy_from_slice(&d[8..8 + len]);
    (out, 2 * len)
}
