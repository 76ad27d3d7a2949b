//! [`InterfacePoints::new`]: the geometry of an interaction's matched points, grouped
//! by element pair, evaluated once per search.

use super::*;

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
        // The element behind each face, made when a point first meets the face (so a
        // failure is reported at the same point as if every point made its own).
        let mut face_a: Vec<Option<FaceElement>> = vec![None; a.faces.len()];
        let mut face_b: Vec<Option<FaceElement>> = vec![None; b.faces.len()];
        let face_element = |cache: &mut Vec<Option<FaceElement>>, k: usize, field, side| {
            *cache[k]
                .get_or_insert_with(|| FaceElement::new(mesh, dofs, field, side, form.conductivity))
        };
        // Every point's group key, in pairing order, read from the faces it paired
        // (the key keeps face points (0, element A, element B) apart from node points
        // (1, node, element B)); then sorted, stably, so points of a group keep their
        // order. Nothing is evaluated yet: each point is evaluated once, in group order,
        // straight into its place.
        let mut keys: Vec<((u8, u32, u32), u32)> = Vec::with_capacity(points.len());
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
        keys.sort_by_key(|e| e.0);
        // The temperature dofs of each point's nodes, when the models see the
        // temperature of another field.
        let foreign = form.temperature_field;
        let t_dof = |node: crate::mesh::NodeId| {
            foreign
                .and_then(|t| dofs.dof(t, node))
                .map_or(u32::MAX, |d| d.0)
        };
        // One point's cached part, local vectors and (with a foreign temperature) the
        // temperature dofs of its nodes.
        let mut evaluate =
            |index: usize| -> Result<(CachedPoint, Local, Vec<u32>), InterfaceError> {
                let p = &points[index];
                let k_b = p.matched_b_face().expect("keyed");
                let eb = face_element(&mut face_b, k_b, fields.b, b.faces[k_b].side)
                    .eval(mesh, dofs, p.xi_b)?;
                let block_b = mesh.block_of(eb.elem);
                let mut t_dofs = Vec::new();
                let (l, elem, side, (block_a, k_a)) = if let Some((a_node, _)) = p.matched_node() {
                    let (node, _) = a.nodes[a_node];
                    let dof = node_dof(mesh, dofs, fields.a, node, &a.name)?;
                    let l = local_node(dof, &eb, form.beta);
                    if foreign.is_some() {
                        let b_nodes = mesh.elem_nodes(eb.elem).iter().map(|&n| t_dof(n));
                        t_dofs = std::iter::once(t_dof(node)).chain(b_nodes).collect();
                    }
                    (l, mesh.node_number(node), 0, (block_b, eb.k))
                } else {
                    let (k_a, _) = p.matched_faces().expect("keyed");
                    let fa = &a.faces[k_a];
                    let ea = face_element(&mut face_a, k_a, fields.a, fa.side)
                        .eval(mesh, dofs, p.xi_a)?;
                    let l = local(&ea, &eb, form.form, form.beta);
                    if foreign.is_some() {
                        let nodes =
                            (mesh.elem_nodes(ea.elem).iter()).chain(mesh.elem_nodes(eb.elem));
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
        let mut out = InterfacePoints {
            group_dofs: vec![0],
            group_points: vec![0],
            points: Vec::with_capacity(keys.len()),
            ..Default::default()
        };
        // Each point's jump and flux entries, one per node of its two elements (one
        // for a node point's side A): reserved at once, the largest array here.
        let entries = |&((kind, a, b), _): &((u8, u32, u32), u32)| {
            let nodes = |e: u32| mesh.elem_nodes(crate::mesh::ElemId(e)).len();
            2 * (if kind == 1 { 1 } else { nodes(a) } + nodes(b))
        };
        out.values.reserve_exact(keys.iter().map(entries).sum());
        // Which side(s) each dof is met on: bit 1 side A, bit 2 side B.
        let mut sides = vec![0u8; dofs.len()];
        let mut last_key = None;
        // The failure of the first point in pairing order that fails, as evaluating in
        // pairing order would report.
        let mut failed: Option<(u32, InterfaceError)> = None;
        for (key, index) in keys {
            let (point, l, t_dofs) = match evaluate(index as usize) {
                Ok(v) => v,
                Err(e) => {
                    if failed.as_ref().is_none_or(|(i, _)| index < *i) {
                        failed = Some((index, e));
                    }
                    continue;
                }
            };
            if failed.is_some() {
                continue;
            }
            if last_key != Some(key) {
                if last_key.is_some() {
                    out.group_dofs.push(out.dofs.len());
                    out.group_points.push(out.points.len());
                }
                out.dofs.extend_from_slice(l.dofs());
                out.t_dofs.extend_from_slice(&t_dofs);
                last_key = Some(key);
            }
            let at = out.values.len() as u32;
            out.values.extend_from_slice(&l.jump[..l.len]);
            out.values.extend_from_slice(&l.flux[..l.len]);
            for (k, &d) in l.dofs().iter().enumerate() {
                sides[d as usize] |= if k < l.na { 1 } else { 2 };
            }
            out.points.push(CachedPoint { at, ..point });
        }
        if let Some((_, e)) = failed {
            return Err(e);
        }
        drop((face_a, face_b));
        if last_key.is_some() {
            out.group_dofs.push(out.dofs.len());
            out.group_points.push(out.points.len());
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
