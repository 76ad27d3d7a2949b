use super::*;

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_new(
    coords: *const f64,
    n_nodes: usize,
    out_builder: *mut *mut SeamBuilder,
) -> c_int {
    guard(|| {
        let xyz = unsafe { slice(coords, n_nodes.saturating_mul(3), "coords") }?;
        let points: Vec<[f64; 3]> = xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let b = Box::new(SeamBuilder(Some(Embedding::builder(&points))));
        unsafe { out(out_builder, Box::into_raw(b), "out_builder") }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_free(builder: *mut SeamBuilder) {
    if !builder.is_null() {
        // SAFETY: made by Box::into_raw in seam_builder_new and freed once (module Safety).
        let _ = catch_unwind(AssertUnwindSafe(|| drop(unsafe { Box::from_raw(builder) })));
    }
}

fn topology(code: c_int) -> Result<Topology, Failure> {
    Ok(match code {
        1 => Topology::Hex8,
        2 => Topology::Tet4,
        3 => Topology::Wedge6,
        4 => Topology::Pyramid5,
        5 => Topology::Quad4,
        6 => Topology::Tri3,
        other => {
            return Err(bad(
                format!("unknown topology code {other}"),
                "use SEAM_HEX8, SEAM_TET4, SEAM_WEDGE6 or SEAM_PYRAMID5 (3-D), SEAM_QUAD4 or SEAM_TRI3 (2-D)",
            ));
        }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_add_block(
    builder: *mut SeamBuilder,
    name: *const c_char,
    topology_code: c_int,
    connectivity: *const i64,
    n_elems: usize,
    conductivity: f64,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let name = unsafe { text(name, "name") }?;
        let t = topology(topology_code)?;
        let conn = unsafe {
            slice(
                connectivity,
                n_elems.saturating_mul(t.node_count()),
                "connectivity",
            )
        }?;
        let conn = conn
            .iter()
            .map(|&v| index(v, "connectivity node"))
            .collect::<Result<Vec<_>, _>>()?;
        b.update(|x| x.block(name, t, &conn, conductivity));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_add_side_set(
    builder: *mut SeamBuilder,
    name: *const c_char,
    elems: *const i64,
    sides: *const c_int,
    n_faces: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let name = unsafe { text(name, "name") }?;
        let elems = unsafe { slice(elems, n_faces, "elems") }?;
        let sides = unsafe { slice(sides, n_faces, "sides") }?;
        let list = elems
            .iter()
            .zip(sides)
            .map(|(&e, &s)| {
                let side = u8::try_from(s)
                    .map_err(|_| bad(format!("side {s} is out of range"), "sides are 1 to 6"))?;
                Ok((index(e, "element")?, side))
            })
            .collect::<Result<Vec<_>, Failure>>()?;
        b.update(|x| x.side_set(name, &list));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_add_face_set(
    builder: *mut SeamBuilder,
    name: *const c_char,
    face_nodes: *const i64,
    nodes_per_face: usize,
    n_faces: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let name = unsafe { text(name, "name") }?;
        if !matches!(nodes_per_face, 2..=4) {
            return Err(bad(
                format!("nodes_per_face = {nodes_per_face}"),
                "faces are triangles (3) or quadrilaterals (4), or in a 2-D mesh edges (2)",
            ));
        }
        let nodes = unsafe {
            slice(
                face_nodes,
                n_faces.saturating_mul(nodes_per_face),
                "face_nodes",
            )
        }?;
        let faces = nodes
            .chunks_exact(nodes_per_face)
            .map(|f| f.iter().map(|&v| index(v, "face node")).collect())
            .collect::<Result<Vec<Vec<usize>>, _>>()?;
        b.update(|x| x.face_set(name, &faces));
        Ok(())
    })
}

/// `dofs[node]` is the host's dof of each node; a negative value means none.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_dofs(
    builder: *mut SeamBuilder,
    dofs: *const i64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let dofs = unsafe { slice(dofs, n_nodes, "dofs") }?;
        let list: Vec<Option<usize>> = dofs.iter().map(|&d| usize::try_from(d).ok()).collect();
        b.update(|x| x.partial_dofs(&list));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_fixed_nodes(
    builder: *mut SeamBuilder,
    nodes: *const i64,
    n: usize,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let nodes = unsafe { slice(nodes, n, "nodes") }?
            .iter()
            .map(|&v| index(v, "fixed node"))
            .collect::<Result<Vec<_>, _>>()?;
        b.update(|x| x.fixed_nodes(&nodes));
        Ok(())
    })
}

/// `kind` 0: mortar segments, 1: Gauss quadrature on side A; `order` the rule's order,
/// 1 to [`crate::search::pairing::MAX_ORDER`].
/// `on` non-zero: the (2-D) mesh is axisymmetric, x the radius
/// ([`crate::embed::EmbeddingBuilder::axisymmetric`]).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_axisymmetric(
    builder: *mut SeamBuilder,
    on: c_int,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        b.update(|x| x.axisymmetric(on != 0));
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_builder_set_integration(
    builder: *mut SeamBuilder,
    kind: c_int,
    order: c_int,
) -> c_int {
    guard(|| {
        let b = unsafe { handle(builder, "builder") }?;
        let order = usize::try_from(order)
            .ok()
            .filter(|o| (1..=crate::search::pairing::MAX_ORDER).contains(o))
            .ok_or_else(|| bad(format!("order {order}"), "give an order of 1 to 20"))?;
        let integration = match kind {
            0 => Integration::Segments { order },
            1 => Integration::Quadrature { order },
            other => {
                return Err(bad(
                    format!("unknown integration kind {other}"),
                    "use SEAM_SEGMENTS or SEAM_QUADRATURE",
                ));
            }
        };
        b.update(|x| x.integration(integration));
        Ok(())
    })
}

/// Check the builder's arrays and make an embedding. The builder is left as it was
/// (free it with `seam_builder_free`).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_embedding_new(
    builder: *const SeamBuilder,
    out_embedding: *mut *mut SeamEmbedding,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let b = unsafe { builder.as_ref() }.ok_or_else(|| null("builder"))?;
        let inner =
            b.0.clone()
                .ok_or_else(|| bad("the builder is unusable".into(), "make a new one"))?
                .build()?;
        let e = Box::new(SeamEmbedding {
            inner,
            buffers: Default::default(),
            evaluated: None,
            rows: None,
            cutback: None,
        });
        unsafe { out(out_embedding, Box::into_raw(e), "out_embedding") }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_embedding_free(embedding: *mut SeamEmbedding) {
    if !embedding.is_null() {
        // SAFETY: made by Box::into_raw in seam_embedding_new, freed once (module Safety).
        let _ = catch_unwind(AssertUnwindSafe(|| {
            drop(unsafe { Box::from_raw(embedding) })
        }));
    }
}
