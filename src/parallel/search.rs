//! The contact search on MPI, after DTK and ArborX: each rank searches the side-A points
//! of the faces of its own elements against the side-B faces of its own elements and
//! the side-B faces other ranks send it, with the serial search kernels
//! ([`Searcher::with_extent`]), so that the pairing is the serial one — pairs whose two
//! faces sit on different ranks, periodic images and Lua maps (side A arrives already
//! mapped) included.
//!
//! One search, per pair of surfaces ([`search_pair`]):
//! 1. side B's extent (mean and largest face size) by `MPI_Allreduce`, so every rank
//!    inflates boxes as the serial search does;
//! 2. each rank's side-B faces grouped, in their BVH's leaf order, into at most
//!    [`TOP_BOXES`] boxes, exchanged by `MPI_Allgather`;
//! 3. each rank sends the boxes of its side-A faces (and node points) to the ranks whose
//!    boxes they meet, and answers the boxes it gets with its side-B faces whose search
//!    boxes meet them (`MPI_Alltoallv`, twice);
//! 4. each rank searches its side-A points against its faces and those it received, in
//!    the whole mesh's numbers (faces in serial order, so ties go to the same face as in
//!    serial);
//! 5. the points: when every rank holds the whole mesh (`seam search`, the general
//!    solver), gathered on every rank in the serial order (`MPI_Allgatherv`); when the
//!    mesh is distributed ([`super::part`]), gathered on rank 0 alone (`MPI_Gatherv`: it
//!    writes the outputs), which sends every rank the whole pairing's statistics, and each
//!    other rank keeps its own points — with the side-B faces they paired with, whose
//!    elements it asks of their owners when it holds them neither as its own nor as
//!    ghosts (contact partners, `MPI_Alltoallv` twice).
//!
//! Ownership: a face belongs to the rank of its element, a node point to its node's owner
//! (the lowest rank among its elements), as in the solve's layout. The bytes each rank
//! sent and received in steps 1–3 (and the contact partners), and in the gather of step
//! 5, are logged by rank 0 (`-v`) and kept for the benchmark ([`last_volume`]).

use std::cell::Cell;
use std::collections::HashMap;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives, Root};

use crate::mesh::{ElemId, Mesh, NodeId, Side};
use crate::search::bvh::{Aabb, Bvh};
use crate::search::pairing::{
    ContactPoint, Extent, FaceGeom, Integration, PointStatus, SearchResult, SearchStats, Searcher,
    Sphere, SurfaceGeometry, max_face_size, tally,
};
use crate::search::{Overclosure, SearchSettings};

use super::part::{self, Part};
use super::session;

/// Boxes each rank publishes for its side-B faces: enough to follow a curved or
/// L-shaped share of a surface, few enough that the all-gather stays small
/// (48 B × 8 per rank).
pub const TOP_BOXES: usize = 8;

/// Bytes one rank sent to and received from the other ranks in one search (the payload
/// of the collectives, as if each went straight to every rank it reaches).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Volume {
    /// Steps 1–3: extent, top boxes, query boxes and candidate faces.
    pub search_sent: u64,
    pub search_received: u64,
    /// Step 5: the points gathered whole on every rank.
    pub gather_sent: u64,
    pub gather_received: u64,
    /// Side-B faces received as candidates.
    pub faces_received: u64,
}

thread_local! {
    static LAST: Cell<Option<Volume>> = const { Cell::new(None) };
}

/// This rank's volume in the last distributed search.
pub fn last_volume() -> Option<Volume> {
    LAST.with(Cell::get)
}

/// `a`'s points paired with `b`'s faces over the MPI world (the pairing the serial
/// [`Searcher::search`] gives), whole on every rank of a run whose ranks hold the whole
/// mesh; on a run whose mesh is distributed, whole on rank 0 and each other rank's own
/// points elsewhere (see [`search`]). Every rank must call it, with its own surfaces.
pub fn search_pair(
    mesh: &Mesh,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    settings: &SearchSettings,
    integration: Integration,
    subdomain: Option<Sphere>,
) -> Result<SearchResult, String> {
    search(mesh, a, b, settings, integration, subdomain, None).map(|f| f.result)
}

/// What a distributed search gives a rank.
pub(crate) struct Found {
    /// The pairing: whole (every point, in serial order, indices into `a` and `b`) on
    /// every rank of a run that holds the whole mesh, and on rank 0 of a run whose mesh
    /// is distributed; on the other ranks of such a run, this rank's own points (indices
    /// into its `a` and into [`Found::side_b`]). The statistics are the whole pairing's
    /// everywhere.
    pub result: SearchResult,
    /// On a rank other than 0 of a run whose mesh is distributed: the side-B faces its
    /// points paired with (its own and other ranks'), in its local numbers — the faces of
    /// contact partners whose elements it was sent ([`part::add_remote`]).
    pub side_b: Option<SurfaceGeometry>,
}

/// Where a side-B face near this rank's points came from.
#[derive(Clone, Copy)]
enum From {
    /// This rank's face `j` of `b`.
    Own(usize),
    /// Sent by this rank.
    Rank(usize),
}

/// As [`search_pair`], the matched points' overclosure treated with `overclosure` (before
/// the statistics are made), and on a run whose mesh is distributed each rank other than
/// 0 keeping its own points, with the side-B faces they paired with
/// ([`Found::side_b`]).
pub(crate) fn search(
    mesh: &Mesh,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    settings: &SearchSettings,
    integration: Integration,
    subdomain: Option<Sphere>,
    overclosure: Option<Overclosure>,
) -> Result<Found, String> {
    let world = session::comm();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let started = std::time::Instant::now();
    part::ensure(mesh)?;
    let partitioned = started.elapsed().as_secs_f64();
    let mut volume = Volume::default();
    // This rank's faces and node points, in global numbers (the search runs on those, so
    // that faces and nodes of different ranks compare as in serial).
    let own = part::with(|p| Own::of(p, a, b)).ok_or("no partition")?;
    let distributed = own.distributed;

    // 1. Side B's extent.
    let sizes: Vec<f64> = own.b.iter().map(|(_, f)| f.size()).collect();
    let (mut sum, mut count, mut largest) = (0.0, 0u64, 0.0);
    world.all_reduce_into(&sizes.iter().sum::<f64>(), &mut sum, SystemOperation::sum());
    world.all_reduce_into(&(sizes.len() as u64), &mut count, SystemOperation::sum());
    world.all_reduce_into(
        &sizes.iter().copied().fold(0.0, f64::max),
        &mut largest,
        SystemOperation::max(),
    );
    let others = size as u64 - 1;
    volume.search_sent += 24 * others;
    volume.search_received += 24 * others;
    let mean = if count == 0 { 0.0 } else { sum / count as f64 };
    let extent = Extent::of(mean, largest, settings);
    debug_assert!(count == 0 || distributed || max_face_size(b) == largest);

    // 2. Top boxes of the side-B faces of every rank.
    let boxes: Vec<Aabb> = own
        .b
        .iter()
        .map(|(_, f)| Aabb::from_points(f.coords()).inflate(extent.margin))
        .collect();
    let tree = Bvh::build(&boxes);
    let top = top_boxes(&tree, &boxes);
    let mut all_top = vec![0.0; size * TOP_BOXES * 6];
    world.all_gather_into(&top[..], &mut all_top[..]);
    volume.search_sent += (top.len() * 8) as u64 * others;
    volume.search_received += ((all_top.len() - top.len()) * 8) as u64;
    let rank_boxes = |r: usize| {
        all_top[r * TOP_BOXES * 6..(r + 1) * TOP_BOXES * 6]
            .chunks_exact(6)
            .map(|c| Aabb {
                min: [c[0], c[1], c[2]],
                max: [c[3], c[4], c[5]],
            })
    };

    // 3. Query boxes of this rank's side-A faces and node points, to the ranks they
    //    meet; candidate faces back.
    let queries: Vec<Aabb> = own
        .a
        .iter()
        .map(|(_, f)| Aabb::from_points(f.coords()))
        .chain(own.nodes.iter().map(|(_, (_, x))| Aabb::from_point(*x)))
        .map(|q| q.inflate(slack(&q, extent.margin)))
        .collect();
    let mut to_rank: Vec<Vec<f64>> = vec![Vec::new(); size];
    for (r, out) in to_rank.iter_mut().enumerate() {
        if r == rank {
            continue;
        }
        for q in &queries {
            if rank_boxes(r).any(|t| t.intersects(q)) {
                out.extend_from_slice(&[q.min[0], q.min[1], q.min[2], q.max[0], q.max[1]]);
                out.push(q.max[2]);
            }
        }
    }
    let asked = exchange(&world, &to_rank, &mut volume);
    let mut answers: Vec<Vec<f64>> = vec![Vec::new(); size];
    let mut hits = Vec::new();
    for (r, boxes_of_r) in asked.iter().enumerate() {
        hits.clear();
        for c in boxes_of_r.chunks_exact(6) {
            let q = Aabb {
                min: [c[0], c[1], c[2]],
                max: [c[3], c[4], c[5]],
            };
            tree.query(&q, |k| hits.push(k));
        }
        hits.sort_unstable();
        hits.dedup();
        for &k in &hits {
            encode_face(&own.b[k].1, &mut answers[r]);
        }
    }
    let received = exchange(&world, &answers, &mut volume);

    // 4. The search of this rank's points, over its side-B faces and those received, in
    //    serial order ((element, side) of the whole mesh).
    let mut near: Vec<(u64, FaceGeom, From)> = own
        .b
        .iter()
        .map(|&(j, f)| (face_key(&f), f, From::Own(j)))
        .collect();
    for (r, buf) in received.iter().enumerate() {
        for c in buf.chunks_exact(FACE_LEN) {
            let f = decode_face(c)?;
            near.push((face_key(&f), f, From::Rank(r)));
        }
    }
    near.sort_unstable_by_key(|&(key, _, _)| key);
    near.dedup_by_key(|(key, _, _)| *key);
    volume.faces_received = (near.len() - own.b.len()) as u64;
    let b_local = SurfaceGeometry {
        name: b.name.clone(),
        faces: near.iter().map(|(_, f, _)| *f).collect(),
        nodes: Vec::new(),
        node_area: Vec::new(),
        node_normal: Vec::new(),
        tributary: Vec::new(),
        axisymmetric: b.axisymmetric,
    };
    let a_local = SurfaceGeometry {
        name: a.name.clone(),
        faces: own.a.iter().map(|(_, f)| *f).collect(),
        nodes: own.nodes.iter().map(|(_, n)| *n).collect(),
        node_area: own
            .nodes
            .iter()
            .map(|&(k, _)| a.node_area.get(k).copied().unwrap_or(0.0))
            .collect(),
        node_normal: own
            .nodes
            .iter()
            .map(|&(k, _)| a.node_normal.get(k).copied().unwrap_or([0.0; 3]))
            .collect(),
        tributary: Vec::new(),
        axisymmetric: a.axisymmetric,
    };
    // With no side-B face near, every point comes out unmatched, as in serial.
    let mut local = Searcher::with_extent(&b_local, extent).search(
        &a_local,
        &b_local,
        settings,
        integration,
        subdomain,
    );
    if let Some(treatment) = overclosure {
        local.treat_overclosure(treatment);
    }
    drop(b_local);
    let searched = started.elapsed().as_secs_f64();

    // 5. The points: gathered whole in serial order, on every rank or on rank 0; the
    //    other ranks of a distributed mesh keep theirs.
    let mut record = Vec::with_capacity(local.points.len() * POINT_LEN);
    for p in local.points.iter() {
        let a_face = p.a_face.map(|f| face_key(&own.a[f as usize].1));
        let a_node = p.a_node.map(|k| own.nodes[k as usize].1.0.0 as u64);
        let b_face = p.b_face.map(|j| near[j as usize].0);
        encode_point(p, a_face, a_node, b_face, &mut record);
    }
    let mut fractions = Vec::with_capacity(own.a.len() * 2);
    for (k, (_, f)) in own.a.iter().enumerate() {
        fractions.extend_from_slice(&[face_key(f) as f64, local.contact_fraction[k]]);
    }
    let root = !distributed || rank == 0;
    let points = gather(&world, &record, !distributed, &mut volume);
    let per_face = gather(&world, &fractions, !distributed, &mut volume);
    let mut overlap = 0.0;
    world.all_reduce_into(
        &local.stats.overlap_area,
        &mut overlap,
        SystemOperation::sum(),
    );
    let mut whole = SearchResult::default();
    if root {
        whole = assemble_whole(&points, &per_face, a, b)?;
        // The covered area: the ranks' sums added (the serial sum up to round-off).
        whole.stats.overlap_area = overlap;
        whole.stats.side_a_area = a.area();
        tally(&mut whole);
    }
    let (result, side_b) = if distributed {
        // Every rank takes rank 0's statistics of the whole pairing.
        let stats = broadcast_stats(&world, &whole.stats);
        // Collective: rank 0, which holds every element, asks for none.
        let fetched = fetch_partners(&world, mesh, &near, &local, &mut volume)?;
        if rank == 0 {
            (whole, None)
        } else {
            own_result(&own, local, &near, fetched, (a, b), stats)?
        }
    } else {
        (whole, None)
    };
    if rank == 0 {
        // Rank 0's wall time: the partition (made at the run's first search, kept for
        // the solve), the search proper, the gather.
        log::info!(
            "distributed search {} / {} on rank 0: partition {partitioned:.3} s, search {:.3} s, gather {:.3} s",
            a.name,
            b.name,
            searched - partitioned,
            started.elapsed().as_secs_f64() - searched
        );
    }
    log_volume(&world, &volume, &a.name, &b.name);
    LAST.with(|l| l.set(Some(volume)));
    Ok(Found { result, side_b })
}

/// This rank's share of a search, in global numbers: its side-A faces (by index into
/// `a`), its node points (by index into `a`'s nodes), its side-B faces (by index into
/// `b`).
struct Own {
    distributed: bool,
    a: Vec<(usize, FaceGeom)>,
    nodes: Vec<(usize, (NodeId, [f64; 3]))>,
    b: Vec<(usize, FaceGeom)>,
}

impl Own {
    fn of(p: &Part, a: &SurfaceGeometry, b: &SurfaceGeometry) -> Own {
        let mine = |f: &FaceGeom| p.elem_rank(f.side.elem) == p.rank;
        Own {
            distributed: p.distributed,
            a: (a.faces.iter().enumerate())
                .filter(|(_, f)| mine(f))
                .map(|(k, f)| (k, global_face(p, f)))
                .collect(),
            nodes: (a.nodes.iter().enumerate())
                .filter(|(_, (n, _))| p.node_rank(*n) == p.rank)
                .map(|(k, &(n, x))| (k, (NodeId(p.node_global[n.index()]), x)))
                .collect(),
            b: (b.faces.iter().enumerate())
                .filter(|(_, f)| mine(f))
                .map(|(j, f)| (j, global_face(p, f)))
                .collect(),
        }
    }
}

/// `f` in the whole mesh's numbers.
fn global_face(p: &Part, f: &FaceGeom) -> FaceGeom {
    let mut g = *f;
    g.side.elem = ElemId(p.elem_global[f.side.elem.index()]);
    for k in 0..f.len as usize {
        g.nodes[k] = NodeId(p.node_global[f.nodes[k].index()]);
    }
    g
}

/// A face's place in serial order: (element, side) of the whole mesh (sides are 1 to 6).
fn face_key(f: &FaceGeom) -> u64 {
    ((f.side.elem.0 as u64) << 4) | f.side.side as u64
}

/// The whole pairing from every rank's points and contact fractions (keyed by global
/// face and node), in serial order: indices into `a` and `b`, which are the whole
/// surfaces.
fn assemble_whole(
    points: &[f64],
    per_face: &[f64],
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
) -> Result<SearchResult, String> {
    let index = |faces: &[FaceGeom]| -> HashMap<u64, usize> {
        faces
            .iter()
            .enumerate()
            .map(|(k, f)| (face_key(f), k))
            .collect()
    };
    let (a_index, b_index) = (index(&a.faces), index(&b.faces));
    let node_index: HashMap<u64, usize> = (a.nodes.iter().enumerate())
        .map(|(k, (n, _))| (n.0 as u64, k))
        .collect();
    let unknown =
        |what: &str| format!("distributed search: a point names a {what} this rank does not hold");
    let mut decoded = Vec::with_capacity(points.len() / POINT_LEN);
    for c in points.chunks_exact(POINT_LEN) {
        let id = |v: f64| (v >= 0.0).then_some(v as u64);
        let a_face = match id(c[0]) {
            Some(k) => Some(*a_index.get(&k).ok_or_else(|| unknown("side-A face"))?),
            None => None,
        };
        let a_node = match id(c[1]) {
            Some(k) => Some(*node_index.get(&k).ok_or_else(|| unknown("side-A node"))?),
            None => None,
        };
        let b_face = match id(c[2]) {
            Some(k) => Some(*b_index.get(&k).ok_or_else(|| unknown("side-B face"))?),
            None => None,
        };
        let key = a_face.unwrap_or(a.faces.len() + a_node.unwrap_or(0));
        decoded.push((key, decode_point(c, a_face, a_node, b_face)));
    }
    // Stable: the points of one face come from one rank, in the serial order.
    decoded.sort_by_key(|&(key, _)| key);
    let mut result = SearchResult {
        points: std::sync::Arc::new(decoded.into_iter().map(|(_, p)| p).collect()),
        contact_fraction: vec![0.0; a.faces.len()],
        ..SearchResult::default()
    };
    for c in per_face.chunks_exact(2) {
        if let Some(&k) = a_index.get(&(c[0] as u64)) {
            result.contact_fraction[k] = c[1];
        }
    }
    Ok(result)
}

/// Rank 0's statistics on every rank.
fn broadcast_stats(world: &SimpleCommunicator, s: &SearchStats) -> SearchStats {
    let mut v = [
        s.points as f64,
        s.matched as f64,
        s.unmatched as f64,
        s.rejected_distance as f64,
        s.rejected_angle as f64,
        s.rejected_subdomain as f64,
        s.overlap_area,
        s.side_a_area,
        s.gap_min.unwrap_or(f64::NAN),
        s.gap_max.unwrap_or(f64::NAN),
    ];
    world.process_at_rank(0).broadcast_into(&mut v[..]);
    let gap = |x: f64| (!x.is_nan()).then_some(x);
    SearchStats {
        points: v[0] as usize,
        matched: v[1] as usize,
        unmatched: v[2] as usize,
        rejected_distance: v[3] as usize,
        rejected_angle: v[4] as usize,
        rejected_subdomain: v[5] as usize,
        overlap_area: v[6],
        side_a_area: v[7],
        gap_min: gap(v[8]),
        gap_max: gap(v[9]),
    }
}

/// The elements `asks[r]` (global numbers) asked of each rank `r`, which it owns, as
/// they come back (collective).
fn fetch_partners_collective(
    world: &SimpleCommunicator,
    mesh: &Mesh,
    asks: Vec<Vec<u32>>,
    volume: &mut Volume,
) -> Result<Vec<part::RemoteElem>, String> {
    let requests: Vec<Vec<f64>> = asks
        .iter()
        .map(|list| list.iter().map(|&g| g as f64).collect())
        .collect();
    let asked = exchange(world, &requests, volume);
    let mut answers: Vec<Vec<f64>> = vec![Vec::new(); asked.len()];
    for (r, list) in asked.iter().enumerate() {
        let mut elems = Vec::with_capacity(list.len());
        for &g in list {
            let e = part::with(|p| p.local_elem(g as u32)).flatten().ok_or_else(|| {
                format!("distributed search: rank {r} asked for element {g}, which this rank does not hold")
            })?;
            elems.push(e);
        }
        for e in part::remote_elems(mesh, &elems) {
            answers[r].extend_from_slice(&[
                e.global as f64,
                e.block as f64,
                e.number as f64,
                e.nodes.len() as f64,
            ]);
            for &(g, x, number, petsc) in &e.nodes {
                answers[r].extend_from_slice(&[g as f64, x[0], x[1], x[2], number as f64]);
                answers[r].push(petsc as f64);
            }
        }
    }
    let got = exchange(world, &answers, volume);
    let mut out = Vec::new();
    for (owner, buf) in got.iter().enumerate() {
        let mut at = 0;
        while at + 4 <= buf.len() {
            let nn = buf[at + 3] as usize;
            let end = at + 4 + 6 * nn;
            if nn > crate::fem::MAX_NODES || end > buf.len() {
                return Err("distributed search: a contact partner was received cut short".into());
            }
            out.push(part::RemoteElem {
                global: buf[at] as u32,
                owner: owner as u32,
                block: buf[at + 1] as u32,
                number: buf[at + 2] as i64,
                nodes: buf[at + 4..end]
                    .chunks_exact(6)
                    .map(|c| {
                        (
                            c[0] as u32,
                            [c[1], c[2], c[3]],
                            c[4] as i64,
                            c[5] as super::petsc::PetscInt,
                        )
                    })
                    .collect(),
            });
            at = end;
        }
    }
    Ok(out)
}

/// The elements of the side-B faces that other ranks sent and this rank's points paired
/// with: per such face (by `near` index) its local element — a ghost, or a contact
/// partner asked of the rank that sent the face (its owner) and appended to this rank's
/// part. Collective over the ranks of a distributed mesh.
fn fetch_partners(
    world: &SimpleCommunicator,
    mesh: &Mesh,
    near: &[(u64, FaceGeom, From)],
    local: &SearchResult,
    volume: &mut Volume,
) -> Result<HashMap<usize, ElemId>, String> {
    let mut used: Vec<usize> = local
        .points
        .iter()
        .filter_map(|p| p.b_face)
        .map(|j| j as usize)
        .collect();
    used.sort_unstable();
    used.dedup();
    let size = world.size() as usize;
    let mut asks: Vec<Vec<u32>> = vec![Vec::new(); size];
    let mut out = HashMap::new();
    for &j in &used {
        let (_, f, from) = &near[j];
        match from {
            From::Own(_) => {}
            From::Rank(r) => match part::with(|p| p.local_elem(f.side.elem.0)).flatten() {
                Some(e) => {
                    out.insert(j, e);
                }
                None => asks[*r].push(f.side.elem.0),
            },
        }
    }
    asks.iter_mut().for_each(|a| a.dedup());
    let fetched = fetch_partners_collective(world, mesh, asks, volume)?;
    let locals = part::add_remote(&fetched);
    let at: HashMap<u32, ElemId> = fetched.iter().map(|e| e.global).zip(locals).collect();
    for &j in &used {
        if let (From::Rank(_), None) = (near[j].2, out.get(&j)) {
            let e = at.get(&near[j].1.side.elem.0).copied().ok_or_else(|| {
                "distributed search: a side-B element asked for did not come".to_string()
            })?;
            out.insert(j, e);
        }
    }
    Ok(out)
}

/// A rank's own points (other than rank 0 of a distributed mesh), in its local numbers:
/// indices into `a` (its own faces and nodes) and into the side-B faces they paired with.
fn own_result(
    own: &Own,
    local: SearchResult,
    near: &[(u64, FaceGeom, From)],
    fetched: HashMap<usize, ElemId>,
    (a, b): (&SurfaceGeometry, &SurfaceGeometry),
    stats: SearchStats,
) -> Result<(SearchResult, Option<SurfaceGeometry>), String> {
    let mut used: Vec<usize> = local
        .points
        .iter()
        .filter_map(|p| p.b_face)
        .map(|j| j as usize)
        .collect();
    used.sort_unstable();
    used.dedup();
    let mut side_b = SurfaceGeometry {
        name: b.name.clone(),
        axisymmetric: b.axisymmetric,
        ..SurfaceGeometry::default()
    };
    let mut position = HashMap::with_capacity(used.len());
    for &j in &used {
        let (_, f, from) = &near[j];
        let face = match from {
            From::Own(k) => b.faces[*k],
            From::Rank(_) => {
                let elem = *fetched
                    .get(&j)
                    .ok_or("distributed search: a side-B face without its element")?;
                let mut g = *f;
                g.side.elem = elem;
                for k in 0..f.len as usize {
                    g.nodes[k] = part::with(|p| p.local_node(f.nodes[k].0))
                        .flatten()
                        .ok_or("distributed search: a side-B node this rank was not sent")?;
                }
                g
            }
        };
        position.insert(j, side_b.faces.len() as u32);
        side_b.faces.push(face);
    }
    let mut contact_fraction = vec![0.0; a.faces.len()];
    for (k, &(i, _)) in own.a.iter().enumerate() {
        contact_fraction[i] = local.contact_fraction[k];
    }
    let points: Vec<_> = std::sync::Arc::unwrap_or_clone(local.points)
        .into_iter()
        .map(|mut p| {
            p.a_face = p.a_face.map(|f| own.a[f as usize].0 as u32);
            p.a_node = p.a_node.map(|k| own.nodes[k as usize].0 as u32);
            p.b_face = p.b_face.map(|j| position[&(j as usize)]);
            p
        })
        .collect();
    Ok((
        SearchResult {
            points: std::sync::Arc::new(points),
            stats,
            contact_fraction,
        },
        Some(side_b),
    ))
}

/// A query box grown by far more than the rounding of the kernels' own box tests (see
/// the side-B candidates of `search::pairing`), so that a face the serial search would
/// look at is always sent.
fn slack(q: &Aabb, margin: f64) -> f64 {
    let size = q
        .min
        .iter()
        .chain(&q.max)
        .fold(0.0f64, |s, v| s.max(v.abs()));
    1e-9 * (size + margin)
}

/// Up to [`TOP_BOXES`] boxes holding `boxes` (this rank's side-B search boxes): runs of
/// the tree's leaf order, which is spatially coherent; empty boxes pad the rest. As six
/// numbers each (min, max).
fn top_boxes(tree: &Bvh, boxes: &[Aabb]) -> Vec<f64> {
    let order: Vec<usize> = tree.item_order().collect();
    let per = order.len().div_ceil(TOP_BOXES).max(1);
    let mut top = Vec::with_capacity(TOP_BOXES * 6);
    for k in 0..TOP_BOXES {
        let run = order.get(k * per..((k + 1) * per).min(order.len()));
        let bounds = run
            .unwrap_or(&[])
            .iter()
            .fold(Aabb::EMPTY, |u, &i| u.union(&boxes[i]));
        top.extend_from_slice(&bounds.min);
        top.extend_from_slice(&bounds.max);
    }
    top
}

/// Send `out[r]` to rank `r` and return what each rank sent here (`MPI_Alltoall` of the
/// counts, then `MPI_Alltoallv`), counting the bytes.
fn exchange(world: &SimpleCommunicator, out: &[Vec<f64>], volume: &mut Volume) -> Vec<Vec<f64>> {
    let got = session::exchange(world, out);
    // The counts to and from the other ranks, and the numbers (none to itself).
    let others = (out.len() - 1) * 4;
    volume.search_sent += (out.iter().map(Vec::len).sum::<usize>() * 8 + others) as u64;
    volume.search_received += (got.iter().map(Vec::len).sum::<usize>() * 8 + others) as u64;
    got
}

/// Every rank's `mine`, concatenated in rank order, on every rank (`everywhere`) or on
/// rank 0 alone (the others get nothing back), counted.
fn gather(
    world: &SimpleCommunicator,
    mine: &[f64],
    everywhere: bool,
    volume: &mut Volume,
) -> Vec<f64> {
    let others = world.size() as usize - 1;
    if everywhere {
        let all = session::gather_all(world, mine);
        volume.gather_sent += (mine.len() * 8 * others) as u64;
        volume.gather_received += ((all.len() - mine.len()) * 8) as u64;
        return all;
    }
    let all = session::gather_root(world, mine);
    if world.rank() == 0 {
        volume.gather_received += ((all.len() - mine.len()) * 8) as u64;
    } else {
        volume.gather_sent += (mine.len() * 8) as u64;
    }
    all
}

/// Numbers per side-B face sent: element, side, node count, 4 node ids (of the whole
/// mesh), 4 × 3 coordinates (152 bytes). Ids up to 2⁵³ are exact in an f64.
const FACE_LEN: usize = 19;

fn encode_face(f: &FaceGeom, out: &mut Vec<f64>) {
    out.extend_from_slice(&[f.side.elem.0 as f64, f.side.side as f64, f.len as f64]);
    out.extend(f.nodes.iter().map(|n| n.0 as f64));
    out.extend(f.x.iter().flatten());
}

fn decode_face(c: &[f64]) -> Result<FaceGeom, String> {
    let len = c[2] as u8;
    if !(2..=4).contains(&len) {
        return Err(format!(
            "distributed search: a side-B face with {len} nodes was received (2 to 4 expected)"
        ));
    }
    let node = |k: usize| NodeId(c[3 + k] as u32);
    let x = |k: usize| [c[7 + 3 * k], c[8 + 3 * k], c[9 + 3 * k]];
    Ok(FaceGeom {
        side: Side {
            elem: ElemId(c[0] as u32),
            side: c[1] as u8,
        },
        len,
        nodes: [node(0), node(1), node(2), node(3)],
        x: [x(0), x(1), x(2), x(3)],
    })
}

/// Numbers per point gathered: side-A face (its key, [`face_key`]), side-A node (global),
/// side-B face (its key) — −1 for none — status, ξ_A, x, weight, ξ_B, gap, offset,
/// side-A normal, side-B normal.
const POINT_LEN: usize = 20;

const STATUSES: [PointStatus; 5] = [
    PointStatus::Matched,
    PointStatus::Unmatched,
    PointStatus::RejectedDistance,
    PointStatus::RejectedAngle,
    PointStatus::RejectedSubdomain,
];

fn encode_point(
    p: &ContactPoint,
    a_face: Option<u64>,
    a_node: Option<u64>,
    b_face: Option<u64>,
    out: &mut Vec<f64>,
) {
    let id = |i: Option<u64>| i.map_or(-1.0, |i| i as f64);
    let status = STATUSES.iter().position(|&s| s == p.status).unwrap_or(1);
    out.extend_from_slice(&[id(a_face), id(a_node), id(b_face), status as f64]);
    out.extend_from_slice(&p.xi_a);
    out.extend_from_slice(&p.x);
    out.push(p.weight);
    out.extend_from_slice(&p.xi_b);
    out.extend_from_slice(&[p.gap, p.offset]);
    out.extend_from_slice(&p.normal_a);
    out.extend_from_slice(&p.normal_b);
}

/// A gathered point, with its ids as the rank assembling the pairing numbers them.
fn decode_point(
    c: &[f64],
    a_face: Option<usize>,
    a_node: Option<usize>,
    b_face: Option<usize>,
) -> ContactPoint {
    let v3 = |k: usize| [c[k], c[k + 1], c[k + 2]];
    ContactPoint {
        a_face: a_face.map(|k| k as u32),
        a_node: a_node.map(|k| k as u32),
        b_face: b_face.map(|k| k as u32),
        status: STATUSES[(c[3] as usize).min(STATUSES.len() - 1)],
        xi_a: [c[4], c[5]],
        x: v3(6),
        weight: c[9],
        xi_b: [c[10], c[11]],
        gap: c[12],
        offset: c[13],
        normal_a: v3(14),
        normal_b: v3(17),
    }
}

/// Rank 0 logs every rank's bytes of this search.
fn log_volume(world: &SimpleCommunicator, v: &Volume, a: &str, b: &str) {
    let mine = [
        v.search_sent,
        v.search_received,
        v.gather_sent,
        v.gather_received,
        v.faces_received,
    ];
    let mut all = vec![0u64; mine.len() * world.size() as usize];
    world.all_gather_into(&mine[..], &mut all[..]);
    if world.rank() == 0 {
        let per: Vec<String> = all
            .chunks_exact(mine.len())
            .enumerate()
            .map(|(r, c)| {
                format!(
                    "rank {r}: search {} B sent / {} B received ({} candidate faces), gather {} B / {} B",
                    c[0], c[1], c[4], c[2], c[3]
                )
            })
            .collect();
        log::info!("distributed search {a} / {b}: {}", per.join("; "));
    }
}
