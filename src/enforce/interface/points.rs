//! [`InterfacePoints::new`]: the geometry of an interaction's matched points, grouped
//! by element pair, evaluated once per search.

use std::ops::Range;
use std::sync::OnceLock;

use rayon::prelude::*;

use crate::slices::take;

use super::*;

/// A point's group: (0, element A, element B) for a face point, (1, node, element B)
/// for a node point.
type Key = (u8, u32, u32);

/// Points evaluated in parallel per run of whole groups before they are joined (enough
/// runs to share the work among threads; few enough that the joins are cheap).
pub(super) const RUN: usize = 16 * 1024;

impl InterfacePoints {
    /// Evaluate the geometry of every matched point of a pairing: face points with the
    /// face-to-face form, node points (node surfaces) with the node-to-face form (module
    /// docs), each node weighted by its tributary area.
    pub fn new(
        mesh: &Mesh,
        dofs: &DofMap,
        fields: impl Into<FieldPair>,
        a: &SurfaceGeometry,
        b: &SurfaceGeometry,
        points: &[ContactPoint],
        form: &InterfaceForm<'_>,
    ) -> Result<InterfacePoints, InterfaceError> {
        let clock = std::time::Instant::now();
        let fields = fields.into();
        // The element behind each face, made when a point first meets the face, by
        // whichever thread meets it first (each is made the same way from the mesh).
        let face_a: Vec<OnceLock<FaceElement>> = a.faces.iter().map(|_| OnceLock::new()).collect();
        let face_b: Vec<OnceLock<FaceElement>> = b.faces.iter().map(|_| OnceLock::new()).collect();
        let conductivity = form.conductivity;
        let face_element = |cache: &[OnceLock<FaceElement>], k: usize, field, side| {
            *cache[k].get_or_init(|| FaceElement::new(mesh, dofs, field, side, conductivity))
        };
        // Every point's group key, in pairing order, read from the faces it paired
        // (the key keeps face points (0, element A, element B) apart from node points
        // (1, node, element B)); then sorted, stably, so points of a group keep their
        // order. Nothing is evaluated yet: each point is evaluated once, in group order,
        // straight into its place.
        let mut keys: Vec<(Key, u32)> = Vec::with_capacity(points.len());
        for (index, p) in points.iter().enumerate() {
            let Some(k_b) = p.matched_b_face() else {
                continue;
            };
            let elem_b = b.faces[k_b].side.elem.0;
            let key = if let Some((a_node, _)) = p.matched_node() {
                let Some(&(node, _)) = a.nodes.get(a_node) else {
                    continue;
                };
                if p.weight == 0.0 {
                    continue; // no tributary face: reported when the surface was built
                }
                (1u8, node.0, elem_b)
            } else {
                let Some((k_a, _)) = p.matched_faces() else {
                    continue;
                };
                (0u8, a.faces[k_a].side.elem.0, elem_b)
            };
            keys.push((key, index as u32));
        }
        keys.par_sort_by_key(|e| e.0);
        // The temperature dofs of each point's nodes, when the models see the
        // temperature of another field.
        let foreign = form.temperature_field;
        let t_dof = |node: crate::mesh::NodeId| {
            foreign
                .and_then(|t| dofs.dof(t, node))
                .map_or(u32::MAX, |d| d.0)
        };
        let (form_kind, beta) = (form.form, form.beta);
        // One point's cached part, local vectors and (with a foreign temperature) the
        // temperature dofs of its nodes.
        let evaluate = |index: usize| -> Result<(CachedPoint, Local, Vec<u32>), InterfaceError> {
            let p = &points[index];
            let k_b = p.matched_b_face().expect("keyed");
            let eb =
                face_element(&face_b, k_b, fields.b, b.faces[k_b].side).eval(mesh, dofs, p.xi_b)?;
            let block_b = mesh.block_of(eb.elem);
            let mut t_dofs = Vec::new();
            let (l, elem, side, (block_a, k_a)) = if let Some((a_node, _)) = p.matched_node() {
                let (node, _) = a.nodes[a_node];
                let dof = node_dof(mesh, dofs, fields.a, node, &a.name)?;
                let l = local_node(dof, &eb, beta);
                if foreign.is_some() {
                    let b_nodes = mesh.elem_nodes(eb.elem).iter().map(|&n| t_dof(n));
                    t_dofs = std::iter::once(t_dof(node)).chain(b_nodes).collect();
                }
                (l, mesh.node_number(node), 0, (block_b, eb.k))
            } else {
                let (k_a, _) = p.matched_faces().expect("keyed");
                let fa = &a.faces[k_a];
                let ea = face_element(&face_a, k_a, fields.a, fa.side).eval(mesh, dofs, p.xi_a)?;
                let l = local(&ea, &eb, form_kind, beta);
                if foreign.is_some() {
                    let nodes = (mesh.elem_nodes(ea.elem).iter()).chain(mesh.elem_nodes(eb.elem));
                    t_dofs = nodes.map(|&n| t_dof(n)).collect();
                }
                let a_at = (mesh.block_of(ea.elem), ea.k);
                (l, mesh.elem_number(fa.side.elem), fa.side.side, a_at)
            };
            let point = CachedPoint {
                index: index as u32,
                elem,
                side,
                na: l.na as u32,
                at: 0,
                weight: p.weight,
                gap: p.gap - p.offset,
                x: p.x,
                alpha: l.alpha,
                blocks: [block_a as u32, block_b as u32],
                k0: [k_a, eb.k],
            };
            Ok((point, l, t_dofs))
        };
        // Runs of whole groups evaluated in parallel, each straight into its own
        // slices of the arrays, sized beforehand from the keys (a point has one jump
        // and one flux entry per node of its two elements, or of its node and side-B
        // element): the same points, values and groups as one pass in group order,
        // whatever the thread count.
        let nodes = |e: u32| mesh.elem_nodes(crate::mesh::ElemId(e)).len();
        let local_len = |(kind, a, b): Key| if kind == 1 { 1 } else { nodes(a) } + nodes(b);
        let runs: Vec<Run> = group_runs(&keys)
            .into_iter()
            .map(|range| {
                let mut run = Run {
                    keys: &keys[range],
                    ..Run::default()
                };
                run.size.points = run.keys.len();
                for (k, &(key, _)) in run.keys.iter().enumerate() {
                    let len = local_len(key);
                    run.size.values += 2 * len;
                    if k == 0 || run.keys[k - 1].0 != key {
                        run.size.groups += 1;
                        run.size.dofs += len;
                    }
                }
                run
            })
            .collect();
        let total = runs.iter().fold(Size::default(), |t, r| t.plus(&r.size));
        let t_len = if foreign.is_some() { total.dofs } else { 0 };
        let mut out = InterfacePoints {
            dofs: vec![0; total.dofs],
            t_dofs: vec![0; t_len],
            group_dofs: vec![0; total.groups + 1],
            group_points: vec![0; total.groups + 1],
            points: vec![CachedPoint::EMPTY; keys.len()],
            values: vec![0.0; total.values],
            ..Default::default()
        };
        let slices = out.run_slices(&runs, foreign.is_some());
        let first_failure = runs
            .par_iter()
            .zip(slices)
            .filter_map(|(run, to)| {
                let mut failed: Option<(u32, InterfaceError)> = None;
                let (mut g, mut d, mut v) = (0, 0, 0);
                for (k, &(key, index)) in run.keys.iter().enumerate() {
                    let (point, l, t_dofs) = match evaluate(index as usize) {
                        Ok(v) => v,
                        Err(e) => {
                            // The failure of the first point in pairing order that
                            // fails, as evaluating in pairing order would report.
                            if failed.as_ref().is_none_or(|(i, _)| index < *i) {
                                failed = Some((index, e));
                            }
                            continue;
                        }
                    };
                    if failed.is_some() {
                        continue;
                    }
                    let len = l.len;
                    debug_assert_eq!(len, local_len(key), "the sizes made from the keys");
                    if k == 0 || run.keys[k - 1].0 != key {
                        to.group_dofs[g] = to.at.dofs + d;
                        to.group_points[g] = to.at.points + k;
                        to.dofs[d..d + len].copy_from_slice(l.dofs());
                        if !to.t_dofs.is_empty() {
                            to.t_dofs[d..d + len].copy_from_slice(&t_dofs);
                        }
                        g += 1;
                        d += len;
                    }
                    to.values[v..v + len].copy_from_slice(&l.jump[..len]);
                    to.values[v + len..v + 2 * len].copy_from_slice(&l.flux[..len]);
                    to.points[k] = CachedPoint {
                        at: (to.at.values + v) as u32,
                        ..point
                    };
                    v += 2 * len;
                }
                failed
            })
            .min_by_key(|f| f.0);
        drop((face_a, face_b));
        if let Some((_, e)) = first_failure {
            return Err(e);
        }
        out.group_dofs[total.groups] = total.dofs;
        out.group_points[total.groups] = keys.len();
        // Which side(s) each dof is met on: bit 1 side A, bit 2 side B. A group's
        // points share its dofs and the count of side A's.
        let mut sides = vec![0u8; dofs.len()];
        for g in 0..out.groups() {
            let na = out.points[out.group_points[g]].na as usize;
            for (k, &d) in out.group(g).iter().enumerate() {
                sides[d as usize] |= if k < na { 1 } else { 2 };
            }
        }
        // The dofs met, ascending (no sort: a pass over the dof space), and each group
        // entry's position among them.
        let mut position = vec![u32::MAX; dofs.len()];
        for (d, &side) in sides.iter().enumerate() {
            if side != 0 {
                position[d] = out.touched.len() as u32;
                out.touched.push(d as u32);
                if side & 1 != 0 {
                    out.side_a_dofs.push(d as u32);
                }
                if side & 2 != 0 {
                    out.side_b_dofs.push(d as u32);
                }
            }
        }
        out.position = out.dofs.iter().map(|&d| position[d as usize]).collect();
        log::debug!(
            "interface points {} / {}: {} points in {} element pairs, made in {:.3} s",
            a.name,
            b.name,
            out.len(),
            out.groups(),
            clock.elapsed().as_secs_f64()
        );
        Ok(out)
    }
}

/// What one run of groups fills, or where its slices start.
#[derive(Clone, Copy, Default)]
struct Size {
    points: usize,
    values: usize,
    groups: usize,
    dofs: usize,
}

impl Size {
    fn plus(self, o: &Size) -> Size {
        Size {
            points: self.points + o.points,
            values: self.values + o.values,
            groups: self.groups + o.groups,
            dofs: self.dofs + o.dofs,
        }
    }
}

/// A run of whole groups: its keys and what it fills.
#[derive(Default)]
struct Run<'k> {
    keys: &'k [(Key, u32)],
    size: Size,
}

/// A run's slices of the arrays of [`InterfacePoints`], and where they start.
struct RunSlices<'o> {
    at: Size,
    dofs: &'o mut [u32],
    t_dofs: &'o mut [u32],
    group_dofs: &'o mut [usize],
    group_points: &'o mut [usize],
    points: &'o mut [CachedPoint],
    values: &'o mut [f64],
}

/// `keys` (sorted) cut into runs of about [`RUN`] points, each ending where a group
/// does.
fn group_runs(keys: &[(Key, u32)]) -> Vec<Range<usize>> {
    let mut runs = Vec::with_capacity(keys.len() / RUN + 1);
    let mut start = 0;
    while start < keys.len() {
        let mut end = (start + RUN).min(keys.len());
        while end < keys.len() && keys[end].0 == keys[end - 1].0 {
            end += 1;
        }
        runs.push(start..end);
        start = end;
    }
    runs
}

impl InterfacePoints {
    /// The arrays cut into each run's slices, in order (`t_dofs` too when `foreign`).
    fn run_slices(&mut self, runs: &[Run], foreign: bool) -> Vec<RunSlices<'_>> {
        let mut dofs = self.dofs.as_mut_slice();
        let mut t_dofs = self.t_dofs.as_mut_slice();
        let mut group_dofs = self.group_dofs.as_mut_slice();
        let mut group_points = self.group_points.as_mut_slice();
        let mut points = self.points.as_mut_slice();
        let mut values = self.values.as_mut_slice();
        let mut at = Size::default();
        let mut out = Vec::with_capacity(runs.len());
        for run in runs {
            let s = run.size;
            out.push(RunSlices {
                at,
                dofs: take(&mut dofs, s.dofs),
                t_dofs: take(&mut t_dofs, if foreign { s.dofs } else { 0 }),
                group_dofs: take(&mut group_dofs, s.groups),
                group_points: take(&mut group_points, s.groups),
                points: take(&mut points, s.points),
                values: take(&mut values, s.values),
            });
            at = at.plus(&s);
        }
        out
    }
}
