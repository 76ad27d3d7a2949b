use super::*;

/// Add an interaction between two named surfaces. `model`: SEAM_CONDUCTANCE and
/// SEAM_GAP_CONDUCTANCE use `h`; SEAM_TIED_NITSCHE, SEAM_TIED_MORTAR and
/// SEAM_TIED_DUAL_MORTAR ignore it. `offset` is a prescribed jump `u_A − u_B`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_interaction(
    embedding: *mut SeamEmbedding,
    side_a: *const c_char,
    side_b: *const c_char,
    model: c_int,
    h: f64,
    offset: f64,
    out_index: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let (a, b) = unsafe { (text(side_a, "side_a")?, text(side_b, "side_b")?) };
        let model = model_of(model, h)?;
        add(e, Interaction::new(a, b, model).offset(offset), out_index)
    })
}

pub(super) fn model_of(code: c_int, h: f64) -> Result<Model, Failure> {
    Ok(match code {
        1 => Model::Conductance { h },
        2 => Model::GapConductance { h },
        3 => Model::TiedNitsche,
        4 => Model::TiedMortar {
            multipliers: Multipliers::Standard,
        },
        5 => Model::TiedMortar {
            multipliers: Multipliers::Dual,
        },
        other => {
            return Err(bad(
                format!("unknown model code {other}"),
                "use one of the SEAM_CONDUCTANCE … SEAM_TIED_DUAL_MORTAR codes of seam.h",
            ));
        }
    })
}

pub(super) fn add(
    e: &mut SeamEmbedding,
    i: Interaction,
    out_index: *mut usize,
) -> Result<(), Failure> {
    let i = e.inner.add_interaction(i)?;
    e.forget_results();
    if !out_index.is_null() {
        unsafe { out(out_index, i, "out_index") }?;
    }
    Ok(())
}

/// The periodic map of `transform` (a SEAM_PERIODIC_* code) from its parameters.
fn periodic_of(transform: c_int, p: &[f64]) -> Result<Periodic, Failure> {
    let count = |want: &[usize], usage: &str| -> Result<(), Failure> {
        if want.contains(&p.len()) {
            Ok(())
        } else {
            Err(bad(
                format!("{} parameters for periodic map {transform}", p.len()),
                usage,
            ))
        }
    };
    Ok(match transform {
        1 => {
            count(&[3], "SEAM_PERIODIC_RECTANGULAR takes the offset: dx dy dz")?;
            Periodic::Rectangular {
                offset: [p[0], p[1], p[2]],
            }
        }
        2 => {
            count(
                &[7],
                "SEAM_PERIODIC_CYLINDRICAL takes axis x y z, center x y z and the angle in degrees",
            )?;
            Periodic::Cylindrical {
                axis: [p[0], p[1], p[2]],
                center: [p[3], p[4], p[5]],
                angle: p[6],
            }
        }
        3 => {
            count(
                &[0, 1],
                "SEAM_PERIODIC_ALIGN_SURFACE takes nothing or invert_normals (1 or 0)",
            )?;
            Periodic::AlignSurface {
                invert_normals: p.first().is_none_or(|&v| v != 0.0),
            }
        }
        other => {
            return Err(bad(
                format!("unknown periodic map code {other}"),
                "use SEAM_PERIODIC_RECTANGULAR, SEAM_PERIODIC_CYLINDRICAL or SEAM_PERIODIC_ALIGN_SURFACE (Lua maps come in a deck: seam_add_deck)",
            ));
        }
    })
}

/// As `seam_add_interaction`, between the image of `side_a` under a periodic map and
/// `side_b`. `transform` is a SEAM_PERIODIC_* code with `n_params` parameters (see
/// seam.h); the image must land on `side_b`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_periodic_interaction(
    embedding: *mut SeamEmbedding,
    side_a: *const c_char,
    side_b: *const c_char,
    model: c_int,
    h: f64,
    offset: f64,
    transform: c_int,
    params: *const f64,
    n_params: usize,
    out_index: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let (a, b) = unsafe { (text(side_a, "side_a")?, text(side_b, "side_b")?) };
        let model = model_of(model, h)?;
        let periodic = periodic_of(transform, unsafe { slice(params, n_params, "params") }?)?;
        let i = Interaction::new(a, b, model)
            .offset(offset)
            .periodic(periodic);
        add(e, i, out_index)
    })
}

/// Add the interactions of a Sierra-syntax contact deck given as text; `name` labels
/// its messages. `out_count` (may be null) receives how many were added.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_deck(
    embedding: *mut SeamEmbedding,
    deck_text: *const c_char,
    name: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let (deck, name) = unsafe { deck_args(deck_text, name) }?;
        let added = e.inner.add_deck(name, deck)?;
        e.forget_results();
        unsafe { optional_out(out_count, added.len()) }
    })
}

/// A deck's text and its label (`"deck"` for a null name).
pub(super) unsafe fn deck_args<'a>(
    deck_text: *const c_char,
    name: *const c_char,
) -> Result<(&'a str, &'a str), Failure> {
    let deck = unsafe { text(deck_text, "deck_text") }?;
    let name = if name.is_null() {
        "deck"
    } else {
        unsafe { text(name, "name") }?
    };
    Ok((deck, name))
}

/// Write `n` to `out_count` (a count or an index) unless it is null.
pub(super) unsafe fn optional_out(out_count: *mut usize, n: usize) -> Result<(), Failure> {
    if out_count.is_null() {
        return Ok(());
    }
    unsafe { out(out_count, n, "out_count") }
}

/// Add the interactions of a deck file (Sierra syntax or `.toml`); relative paths in
/// it (Lua files, plugin libraries) are taken from its folder.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_add_deck_file(
    embedding: *mut SeamEmbedding,
    path: *const c_char,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        let path = unsafe { text(path, "path") }?;
        let added = e.inner.add_deck_file(std::path::Path::new(path))?;
        e.forget_results();
        if !out_count.is_null() {
            unsafe { out(out_count, added.len(), "out_count") }?;
        }
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_interaction_count(
    embedding: *const SeamEmbedding,
    out_count: *mut usize,
) -> c_int {
    guard(|| {
        // SAFETY: a non-null handle came from this library (module Safety).
        let e = unsafe { embedding.as_ref() }.ok_or_else(|| null("embedding"))?;
        unsafe { out(out_count, e.inner.len(), "out_count") }
    })
}

/// Search every interaction anew.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_search(embedding: *mut SeamEmbedding) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.inner.search()?;
        e.forget_results();
        Ok(())
    })
}

/// The host's time for the next `seam_evaluate` (conductance models and plugins that
/// depend on t see it).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_set_time(embedding: *mut SeamEmbedding, time: f64) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.inner.set_time(time)?;
        e.values_changed();
        Ok(())
    })
}

/// `n_nodes` points from the C array `coords` (xyz per node).
pub(super) unsafe fn xyz(coords: *const f64, n_nodes: usize) -> Result<Vec<[f64; 3]>, Failure> {
    let xyz = unsafe { slice(coords, n_nodes.saturating_mul(3), "coords") }?;
    Ok(xyz.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// New coordinates of every node (3 per node): pairings are kept, gaps measured anew.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn seam_move_nodes(
    embedding: *mut SeamEmbedding,
    coords: *const f64,
    n_nodes: usize,
) -> c_int {
    guard(|| {
        let e = unsafe { handle(embedding, "embedding") }?;
        e.inner.move_nodes(&unsafe { xyz(coords, n_nodes) }?)?;
        e.forget_results();
        Ok(())
    })
}
