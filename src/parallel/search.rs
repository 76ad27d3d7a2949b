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
//! 4. each rank searches its side-A points against its faces and those it received
//!    (numbered in serial order, so ties go to the same face as in serial);
//! 5. the points are gathered on every rank in the serial order (`MPI_Allgatherv`): the
//!    rest of a run (the interface terms) is still evaluated over the whole interface.
//!
//! Ownership: a face belongs to the rank of its element, a node point to its node's owner
//! (the lowest rank among its elements), as in the solve's layout. The bytes each rank
//! sent and received in steps 1–3, and in the gather of step 5, are logged by rank 0
//! (`-v`) and kept for the benchmark ([`last_volume`]).

use std::cell::Cell;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

use crate::mesh::{ElemId, Mesh, NodeId, Side};
use crate::search::SearchSettings;
use crate::search::bvh::{Aabb, Bvh};
use crate::search::pairing::{
    ContactPoint, Extent, FaceGeom, Integration, PointStatus, SearchResult, Searcher, Sphere,
    SurfaceGeometry, max_face_size, tally,
};

use super::layout::{NO_PART, element_parts, node_owners};
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
/// [`Searcher::search`] gives), whole on every rank. Every rank must call it with the
/// same (replicated) arguments, in a distributed run.
pub fn search_pair(
    mesh: &Mesh,
    a: &SurfaceGeometry,
    b: &SurfaceGeometry,
    settings: &SearchSettings,
    integration: Integration,
    subdomain: Option<Sphere>,
) -> Result<SearchResult, String> {
    let world = session::comm();
    let (rank, size) = (world.rank() as usize, world.size() as usize);
    let blocks: Vec<usize> = (0..mesh.blocks.len())
        .filter(|&k| mesh.blocks[k].topology.is_solid())
        .collect();
    let started = std::time::Instant::now();
    let part = element_parts(mesh, &blocks)?;
    let partitioned = started.elapsed().as_secs_f64();
    let face_owner = |f: &FaceGeom| match part.get(f.side.elem.index()) {
        Some(&p) if p != NO_PART => p as usize,
        _ => 0,
    };
    let mut volume = Volume::default();

    // 1. Side B's extent.
    let mine: Vec<usize> = (0..b.faces.len())
        .filter(|&j| face_owner(&b.faces[j]) == rank)
        .collect();
    let sizes: Vec<f64> = mine.iter().map(|&j| b.faces[j].size()).collect();
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
    debug_assert!(count == 0 || max_face_size(b) == largest);

    // 2. Top boxes of the side-B faces of every rank.
    let boxes: Vec<Aabb> = mine
        .iter()
        .map(|&j| Aabb::from_points(b.faces[j].coords()).inflate(extent.margin))
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
    let a_faces: Vec<usize> = (0..a.faces.len())
        .filter(|&f| face_owner(&a.faces[f]) == rank)
        .collect();
    let owner = node_owners(mesh, &blocks, &part);
    let a_nodes: Vec<usize> = (0..a.nodes.len())
        .filter(|&k| {
            let o = owner.get(a.nodes[k].0.index()).copied().unwrap_or(NO_PART);
            (if o == NO_PART { 0 } else { o as usize }) == rank
        })
        .collect();
    let queries: Vec<Aabb> = a_faces
        .iter()
        .map(|&f| Aabb::from_points(a.faces[f].coords()))
        .chain(a_nodes.iter().map(|&k| Aabb::from_point(a.nodes[k].1)))
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
            tree.query(&q, |k| hits.push(mine[k]));
        }
        hits.sort_unstable();
        hits.dedup();
        for &j in &hits {
            encode_face(j, &b.faces[j], &mut answers[r]);
        }
    }
    let received = exchange(&world, &answers, &mut volume);

    // 4. The search of this rank's points, over its side-B faces and those received, in
    //    serial order.
    let mut near: Vec<(usize, FaceGeom)> = mine.iter().map(|&j| (j, b.faces[j])).collect();
    for buf in &received {
        for c in buf.chunks_exact(FACE_LEN) {
            near.push(decode_face(c)?);
        }
    }
    near.sort_unstable_by_key(|(j, _)| *j);
    near.dedup_by_key(|(j, _)| *j);
    volume.faces_received = (near.len() - mine.len()) as u64;
    let b_local = SurfaceGeometry {
        name: b.name.clone(),
        faces: near.iter().map(|(_, f)| *f).collect(),
        nodes: Vec::new(),
        node_area: Vec::new(),
        node_normal: Vec::new(),
        tributary: Vec::new(),
        axisymmetric: b.axisymmetric,
    };
    let a_local = SurfaceGeometry {
        name: a.name.clone(),
        faces: a_faces.iter().map(|&f| a.faces[f]).collect(),
        nodes: a_nodes.iter().map(|&k| a.nodes[k]).collect(),
        node_area: a_nodes
            .iter()
            .map(|&k| a.node_area.get(k).copied().unwrap_or(0.0))
            .collect(),
        node_normal: a_nodes
            .iter()
            .map(|&k| a.node_normal.get(k).copied().unwrap_or([0.0; 3]))
            .collect(),
        tributary: Vec::new(),
        axisymmetric: a.axisymmetric,
    };
    // With no side-B face near, every point comes out unmatched, as in serial.
    let local = Searcher::with_extent(&b_local, extent).search(
        &a_local,
        &b_local,
        settings,
        integration,
        subdomain,
    );

    let searched = started.elapsed().as_secs_f64();
    // 5. Every rank's points in serial numbering, gathered whole.
    let mut record = Vec::with_capacity(local.points.len() * POINT_LEN + a_faces.len() * 3);
    for p in &local.points {
        let a_face = p.a_face.map(|f| a_faces[f as usize]);
        let a_node = p.a_node.map(|k| a_nodes[k as usize]);
        let b_face = p.b_face.map(|j| near[j as usize].0);
        encode_point(p, a_face, a_node, b_face, &mut record);
    }
    let mut fractions = Vec::with_capacity(a_faces.len() * 2);
    for (k, &f) in a_faces.iter().enumerate() {
        fractions.extend_from_slice(&[f as f64, local.contact_fraction[k]]);
    }
    let points = gather(&world, &record, &mut volume);
    let per_face = gather(&world, &fractions, &mut volume);
    let mut order: Vec<(usize, usize)> = points
        .chunks_exact(POINT_LEN)
        .enumerate()
        .map(|(k, c)| (point_key(c, a.faces.len()), k))
        .collect();
    // Stable: the points of one face come from one rank, in the serial order.
    order.sort_by_key(|&(key, _)| key);
    let mut result = SearchResult {
        points: order
            .iter()
            .map(|&(_, k)| decode_point(&points[k * POINT_LEN..(k + 1) * POINT_LEN]))
            .collect(),
        contact_fraction: vec![0.0; a.faces.len()],
        ..SearchResult::default()
    };
    for c in per_face.chunks_exact(2) {
        result.contact_fraction[c[0] as usize] = c[1];
    }
    // The covered area: the ranks' sums added (the serial sum up to round-off).
    world.all_reduce_into(
        &local.stats.overlap_area,
        &mut result.stats.overlap_area,
        SystemOperation::sum(),
    );
    result.stats.side_a_area = a.area();
    tally(&mut result);
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
    Ok(result)
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

/// Every rank's `mine`, concatenated in rank order on every rank, counted.
fn gather(world: &SimpleCommunicator, mine: &[f64], volume: &mut Volume) -> Vec<f64> {
    let all = session::gather_all(world, mine);
    let others = world.size() as usize - 1;
    volume.gather_sent += (mine.len() * 8 * others) as u64;
    volume.gather_received += ((all.len() - mine.len()) * 8) as u64;
    all
}

/// Numbers per side-B face sent: serial index, element, side, node count, 4 node ids,
/// 4 × 3 coordinates (160 bytes). Ids up to 2⁵³ are exact in an f64.
const FACE_LEN: usize = 20;

fn encode_face(j: usize, f: &FaceGeom, out: &mut Vec<f64>) {
    out.extend_from_slice(&[
        j as f64,
        f.side.elem.0 as f64,
        f.side.side as f64,
        f.len as f64,
    ]);
    out.extend(f.nodes.iter().map(|n| n.0 as f64));
    out.extend(f.x.iter().flatten());
}

fn decode_face(c: &[f64]) -> Result<(usize, FaceGeom), String> {
    let len = c[3] as u8;
    if !(2..=4).contains(&len) {
        return Err(format!(
            "distributed search: a side-B face with {len} nodes was received (2 to 4 expected)"
        ));
    }
    let node = |k: usize| NodeId(c[4 + k] as u32);
    let x = |k: usize| [c[8 + 3 * k], c[9 + 3 * k], c[10 + 3 * k]];
    Ok((
        c[0] as usize,
        FaceGeom {
            side: Side {
                elem: ElemId(c[1] as u32),
                side: c[2] as u8,
            },
            len,
            nodes: [node(0), node(1), node(2), node(3)],
            x: [x(0), x(1), x(2), x(3)],
        },
    ))
}

/// Numbers per point gathered: side-A face, side-A node, side-B face (−1 for none),
/// status, ξ_A, x, weight, ξ_B, gap, offset, side-A normal, side-B normal.
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
    a_face: Option<usize>,
    a_node: Option<usize>,
    b_face: Option<usize>,
    out: &mut Vec<f64>,
) {
    let id = |i: Option<usize>| i.map_or(-1.0, |i| i as f64);
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

fn decode_point(c: &[f64]) -> ContactPoint {
    let id = |v: f64| (v >= 0.0).then_some(v as u32);
    let v3 = |k: usize| [c[k], c[k + 1], c[k + 2]];
    ContactPoint {
        a_face: id(c[0]),
        a_node: id(c[1]),
        b_face: id(c[2]),
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

/// Where a gathered point goes in the serial order: face points by their face, then
/// node points by their node.
fn point_key(c: &[f64], faces: usize) -> usize {
    if c[0] >= 0.0 {
        c[0] as usize
    } else {
        faces + c[1].max(0.0) as usize
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
