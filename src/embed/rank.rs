//! The embedding on MPI, one handle per rank: a host that runs on several ranks hands
//! each rank's local part of its mesh — nodes with their global ids and the host's
//! global dof numbers, its elements, the interface faces of the elements it owns — and
//! gets back, on each rank, the interface terms of that rank's own side-A points in the
//! host's global dof numbers. Summed over the ranks (PETSc's `ADD_VALUES`), they are the
//! serial embedding's terms; the heats come summed over the ranks on every rank.
//!
//! Entry point: [`EmbeddingBuilder::build_on_ranks`] (the builder holds the rank's local
//! part, its `dofs` the host's global dof of each local node), then
//! [`RankEmbedding::add_interaction`], [`RankEmbedding::search`] and
//! [`RankEmbedding::contributions`] at the host's local field. These (and the build) are
//! collective over the communicator: each rank calls them, in the same order, with the
//! same interactions (the accessors are local); an error on one rank is an error on every rank
//! ([`EmbedError::OtherRank`] on the others), so no rank is left waiting.
//!
//! ```no_run
//! use seam::embed::{Embedding, Interaction, Model, Topology};
//! # fn host(world: mpi::topology::SimpleCommunicator) -> Result<(), seam::embed::EmbedError> {
//! # let (coords, conn_a, conn_b, right, left, global_id, global_dof, u_local):
//! #   (Vec<[f64; 3]>, Vec<usize>, Vec<usize>, Vec<(usize, u8)>, Vec<(usize, u8)>,
//! #    Vec<u64>, Vec<usize>, Vec<f64>) = Default::default();
//! // This rank's part: its nodes (owned and ghost), its elements, its interface faces.
//! let mut seam = Embedding::builder(&coords)
//!     .block("a", Topology::Hex8, &conn_a, 2.0) // every rank: the same blocks …
//!     .block("b", Topology::Hex8, &conn_b, 5.0)
//!     .side_set("right", &right) // … and surfaces, empty where it has none
//!     .side_set("left", &left)
//!     .dofs(&global_dof) // the host's global dof of each local node
//!     .build_on_ranks(world, &global_id)?;
//! seam.add_interaction(Interaction::new("right", "left", Model::GapConductance { h: 50.0 }))?;
//! seam.search()?;
//! let c = seam.contributions(&u_local)?; // this rank's points, global dofs
//! for &(row, col, v) in &c.jacobian { /* MatSetValue(A, row, col, v, ADD_VALUES) */ }
//! let total = c.heat[0].unwrap().side_a; // summed over the ranks
//! # Ok(()) }
//! ```
//!
//! What is communicated (docs/parallel.md, "The embedding on MPI"): at the build, the
//! interface — every rank's interface faces with their elements' nodes, coordinates and
//! global dofs, not the rest of the volume mesh — gathered on every rank
//! (`MPI_Allgatherv`); at each evaluation, the field at those nodes (`MPI_Allgatherv`)
//! and the heats (`MPI_Allreduce`). Every rank then searches the whole interface with
//! the serial search (the same pairing on every rank, so pairs whose faces sit on
//! different ranks pair exactly as in serial), and evaluates only the points of the
//! faces it gave ([`Embedding::own_points`]).
//!
//! Between evaluations the host sets the time, switches interactions on and off,
//! quarantines failing points and lets interactions stand unpaired as on one process
//! ([`RankEmbedding::set_time`], [`RankEmbedding::set_active`],
//! [`RankEmbedding::set_quarantine`], [`RankEmbedding::allow_unpaired`]); these are
//! collective, and arguments that differ between ranks are refused on every rank. Each
//! rank lists the points it quarantined ([`RankEmbedding::quarantined`]).
//!
//! Mortar ties give their constraint rows by [`RankEmbedding::constraints`]: each rank
//! the rows (and, for dual multipliers, the condensed rows) of the multipliers whose
//! side-A node it owns, in the host's global dofs, each with its index in the whole tie.
//!
//! Ownership: a face belongs to the rank that gives it, and must be given by one rank
//! only (the owner of its element); a node point of a node surface belongs to the lowest
//! rank among the elements around it. Node ownership is otherwise the host's business:
//! entries come at any global dof and the host adds them where they belong.

mod csr;
mod state;

pub use csr::RankEvaluation;

use std::collections::HashMap;

use mpi::collective::SystemOperation;
use mpi::datatype::PartitionMut;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

use super::{
    Contributions, EmbedError, Embedding, EmbeddingBuilder, FaceValues, Heat, HostFace,
    Interaction, PointValues, TieConstraints, argument, mesh_error,
};
use crate::mesh::{ElemId, NodeId};

/// One rank's embedding in a host that runs on MPI (see the module docs).
pub struct RankEmbedding {
    comm: SimpleCommunicator,
    rank: usize,
    /// The whole interface (every rank's interface faces and their elements), with
    /// seam's node `k` at inner dof `k`.
    inner: Embedding,
    /// The host's global dof of each inner node.
    global_dof: Vec<usize>,
    /// This rank's local nodes whose values it sends at each evaluation, in order.
    sent: Vec<usize>,
    /// Each inner node's value: its position in the gathered values.
    value_at: Vec<usize>,
    /// The local nodes the host gave.
    local_nodes: usize,
    /// The rank that gave each inner element.
    origin: Vec<usize>,
    /// Each inner element's index in the builder of the rank that gave it (its
    /// `HostFace` element there).
    host_elem: Vec<usize>,
    /// The rank owning each inner node's point (node surfaces): the lowest around it.
    node_owner: Vec<usize>,
    /// Over all ranks, the side-A points whose side-B face another rank gave.
    across: usize,
    /// The last [`RankEmbedding::evaluate`], with its map from the inner CSR.
    evaluation: Option<RankEvaluation>,
}

/// One of this rank's own side-A points ([`RankEmbedding::point_fields`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RankPoint {
    /// Its index in the interaction's point order (the serial embedding's).
    pub point: usize,
    /// Its values; `side_a` is an element of this rank's builder, `side_b` one of
    /// `side_b_rank`'s.
    pub values: PointValues,
    /// The rank whose element `values.side_b` is (`None` where it paired nothing).
    pub side_b_rank: Option<usize>,
}

/// One mortar tie's rows on one rank ([`RankEmbedding::constraints`]).
#[derive(Clone, Debug)]
pub struct RankTie {
    /// The rows of this rank's multipliers, numbered 0.. in `index`'s order, in the
    /// host's global dofs ([`TieConstraints`]; its `heat` is this rank's share, and
    /// its `dual_multipliers_at` takes the residual at this rank's multipliers' dofs).
    pub rows: TieConstraints,
    /// Each of this rank's multipliers' index in the whole tie (ascending).
    pub index: Vec<usize>,
    /// The whole tie's multipliers, over every rank.
    pub total: usize,
}

/// `MPI_Comm_dup` of the host's communicator: seam's messages never meet the host's.
/// An MPI not (or no longer) running, `MPI_COMM_NULL` or a communicator MPI refuses to
/// duplicate is an error, not an abort.
///
/// # Safety
/// `comm` must be `MPI_COMM_NULL` or a communicator of this process's MPI.
pub unsafe fn duplicate(comm: mpi::ffi::MPI_Comm) -> Result<SimpleCommunicator, EmbedError> {
    use mpi::ffi;
    let (mut up, mut down) = (0, 0);
    // SAFETY: both may be called at any time, before MPI_Init and after MPI_Finalize.
    unsafe {
        ffi::MPI_Initialized(&mut up);
        ffi::MPI_Finalized(&mut down);
    }
    if up == 0 || down != 0 {
        return Err(argument(
            "MPI is not running".into(),
            "call MPI_Init (or PetscInitialize) before seam and MPI_Finalize after freeing seam's handles",
        ));
    }
    // SAFETY: a constant of the MPI library.
    if comm == unsafe { ffi::RSMPI_COMM_NULL } {
        return Err(argument(
            "the communicator is MPI_COMM_NULL".into(),
            "pass the communicator the host's ranks share (e.g. PETSC_COMM_WORLD)",
        ));
    }
    let mut dup = std::mem::MaybeUninit::uninit();
    // SAFETY: the caller passes a communicator of this MPI; MPI_Comm_dup writes `dup`
    // when it succeeds. MPI's own error handler on `comm` may still abort on a bad one.
    let status = unsafe { ffi::MPI_Comm_dup(comm, dup.as_mut_ptr()) };
    if status != 0 {
        return Err(argument(
            format!("MPI_Comm_dup failed on the host's communicator (MPI error {status})"),
            "pass a valid communicator of the host's ranks",
        ));
    }
    // SAFETY: written by the successful MPI_Comm_dup; seam owns (and frees) the copy.
    Ok(unsafe { <SimpleCommunicator as mpi::raw::FromRaw>::from_raw(dup.assume_init()) })
}

/// An error on some rank becomes an error on every rank: the lowest failing rank's own
/// error there, [`EmbedError::OtherRank`] naming it elsewhere.
pub(crate) fn agree<T>(
    comm: &SimpleCommunicator,
    r: Result<T, EmbedError>,
) -> Result<T, EmbedError> {
    let (rank, size) = (comm.rank(), comm.size());
    let mine = if r.is_err() { rank } else { size };
    let mut first = size;
    comm.all_reduce_into(&mine, &mut first, SystemOperation::min());
    match r {
        Err(e) => Err(e),
        Ok(_) if first < size => Err(EmbedError::OtherRank {
            rank: first as usize,
        }),
        ok => ok,
    }
}

/// Every rank's `mine`, one vector per rank, on every rank (`MPI_Allgather` of the
/// counts, then `MPI_Allgatherv`).
fn gather_parts<T>(comm: &SimpleCommunicator, mine: &[T]) -> Vec<Vec<T>>
where
    T: mpi::datatype::Equivalence + Copy + Default,
{
    let mut counts = vec![0i32; comm.size() as usize];
    comm.all_gather_into(&(mine.len() as i32), &mut counts[..]);
    let starts: Vec<i32> = counts
        .iter()
        .scan(0, |s, &n| {
            *s += n;
            Some(*s - n)
        })
        .collect();
    let mut all = vec![T::default(); counts.iter().sum::<i32>() as usize];
    {
        let mut got = PartitionMut::new(&mut all[..], &counts[..], &starts[..]);
        comm.all_gather_varcount_into(mine, &mut got);
    }
    counts
        .iter()
        .zip(&starts)
        .map(|(&n, &s)| all[s as usize..(s + n) as usize].to_vec())
        .collect()
}

/// What every rank must give alike — blocks (name, topology, conductivity), surface
/// names, integration, axisymmetry — as one number (FNV-1a of its text).
fn signature(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// One rank's share of the interface: its faces' elements, their nodes, the faces.
struct Share {
    /// `[n_nodes, n_elems, n_faces]`, then per node `[global id, global dof]`, per
    /// element `[block, its index in this rank's builder, its nodes as positions in this
    /// share's node list …]`, per face
    /// `[surface, element (position in this share), side]`.
    ids: Vec<u64>,
    /// The coordinates of the nodes, xyz each.
    coords: Vec<f64>,
    /// The local nodes, in the share's order.
    nodes: Vec<usize>,
}

impl EmbeddingBuilder {
    /// The embedding of this rank's part of a host on MPI (collective over `comm`): the
    /// builder holds the rank's local nodes (owned and ghost), its elements and the
    /// interface faces of the elements it owns (each face on one rank only), with
    /// [`Self::dofs`] the host's global dof of each local node; `global_ids` gives each
    /// local node's global id. Every rank gives the same blocks (names, topologies,
    /// conductivities; a block may have no elements here) and surfaces (names; a surface
    /// may have no faces here), in the same order.
    pub fn build_on_ranks(
        self,
        comm: SimpleCommunicator,
        global_ids: &[u64],
    ) -> Result<RankEmbedding, EmbedError> {
        let (integration, axisymmetric) = (self.integration, self.axisymmetric);
        // The fixed nodes by global id (a node fixed on any rank is fixed).
        let fixed: Vec<u64> = (self.fixed.iter())
            .filter_map(|&f| global_ids.get(f).copied())
            .collect();
        let local = agree(&comm, self.local_share(global_ids));
        let (local, share) = local?;
        let rank = comm.rank() as usize;

        // Every rank's blocks and surfaces alike.
        let mut text = format!("{integration:?} {axisymmetric}");
        for (b, block) in local.mesh.blocks.iter().enumerate() {
            text += &format!(
                "|{} {:?} {:e}",
                block.name, block.topology, local.conductivity[b]
            );
        }
        for s in &local.mesh.side_sets {
            text += &format!("|{}", s.name);
        }
        let mut signatures = vec![0u64; comm.size() as usize];
        comm.all_gather_into(&signature(&text), &mut signatures[..]);
        if let Some(r) = signatures.iter().position(|&s| s != signatures[0]) {
            return Err(mesh_error(
                format!(
                    "rank {r} gives other blocks or surfaces than rank 0 (names, topologies, conductivities or order), or another integration"
                ),
                "give every rank the same blocks and surfaces in the same order, empty where the rank has none",
            ));
        }

        let ids = gather_parts(&comm, &share.ids);
        let coords = gather_parts(&comm, &share.coords);
        let whole = Interface::assemble(&local, &ids, &coords)?;

        let mut builder = Embedding::builder(&whole.coords)
            .integration(integration)
            .axisymmetric(axisymmetric)
            .dofs(&(0..whole.coords.len()).collect::<Vec<_>>());
        for (b, block) in local.mesh.blocks.iter().enumerate() {
            builder = builder.block(
                &block.name,
                block.topology,
                &whole.connectivity[b],
                local.conductivity[b],
            );
        }
        for (s, set) in local.mesh.side_sets.iter().enumerate() {
            builder = builder.side_set(&set.name, &whole.faces[s]);
        }
        let mut inner = builder.build()?;
        inner.mesh.node_numbers = whole.global_id.iter().map(|&g| g as i64).collect();
        let fixed: std::collections::HashSet<u64> =
            gather_parts(&comm, &fixed).into_iter().flatten().collect();
        inner.fixed = (0..whole.global_id.len())
            .filter(|&i| fixed.contains(&whole.global_id[i]))
            .map(|i| NodeId(i as u32))
            .collect();
        let mut node_owner = vec![usize::MAX; whole.coords.len()];
        for (e, &r) in whole.origin.iter().enumerate() {
            for n in inner.mesh.elem_nodes(ElemId(e as u32)) {
                node_owner[n.index()] = node_owner[n.index()].min(r);
            }
        }
        Ok(RankEmbedding {
            comm,
            rank,
            inner,
            global_dof: whole.global_dof,
            sent: share.nodes,
            value_at: whole.value_at,
            local_nodes: local.mesh.coords.len(),
            origin: whole.origin,
            host_elem: whole.host_elem,
            node_owner,
            across: 0,
            evaluation: None,
        })
    }

    /// This rank's part checked as a serial embedding, and its share of the interface.
    fn local_share(self, global_ids: &[u64]) -> Result<(Embedding, Share), EmbedError> {
        let n = self.coords.len();
        if global_ids.len() != n {
            return Err(mesh_error(
                format!("{} global ids for {n} local nodes", global_ids.len()),
                "pass one global id per local node, in node order",
            ));
        }
        let host_dofs = self.dofs.clone().unwrap_or_default();
        let local = self.build()?;
        let mesh = &local.mesh;
        // The elements of this rank's faces, and their nodes, in first-seen order.
        let mut elem_at: HashMap<ElemId, usize> = HashMap::new();
        let mut node_at: HashMap<usize, usize> = HashMap::new();
        let (mut elems, mut nodes, mut faces) = (Vec::new(), Vec::new(), Vec::new());
        for (s, set) in mesh.side_sets.iter().enumerate() {
            for side in &set.sides {
                let e = *elem_at.entry(side.elem).or_insert_with(|| {
                    elems.push(side.elem);
                    elems.len() - 1
                });
                faces.extend_from_slice(&[s as u64, e as u64, u64::from(side.side)]);
            }
        }
        let mut elem_ids = Vec::new();
        for &e in &elems {
            elem_ids.extend_from_slice(&[mesh.block_of(e) as u64, u64::from(e.0)]);
            for node in mesh.elem_nodes(e) {
                let k = *node_at.entry(node.index()).or_insert_with(|| {
                    nodes.push(node.index());
                    nodes.len() - 1
                });
                elem_ids.push(k as u64);
            }
        }
        let mut ids = vec![
            nodes.len() as u64,
            elems.len() as u64,
            faces.len() as u64 / 3,
        ];
        let mut coords = Vec::with_capacity(nodes.len() * 3);
        for &k in &nodes {
            // Every node of a block has a dof (the local build checked it).
            let dof = host_dofs.get(k).copied().flatten().unwrap_or(0);
            ids.extend_from_slice(&[global_ids[k], dof as u64]);
            coords.extend_from_slice(&mesh.coords[k]);
        }
        ids.extend(elem_ids);
        ids.extend(faces);
        Ok((local, Share { ids, coords, nodes }))
    }
}

/// The whole interface, made alike on every rank from every rank's share.
struct Interface {
    coords: Vec<[f64; 3]>,
    global_id: Vec<u64>,
    global_dof: Vec<usize>,
    /// Per block, the connectivity by inner node.
    connectivity: Vec<Vec<usize>>,
    /// Per surface, (inner element, side).
    faces: Vec<Vec<(usize, u8)>>,
    /// The rank that gave each inner element.
    origin: Vec<usize>,
    /// Each inner element's index in its rank's builder.
    host_elem: Vec<usize>,
    value_at: Vec<usize>,
}

impl Interface {
    fn assemble(
        local: &Embedding,
        ids: &[Vec<u64>],
        coords: &[Vec<f64>],
    ) -> Result<Self, EmbedError> {
        let mesh = &local.mesh;
        let corrupt = |r: usize| {
            mesh_error(
                format!("the interface received from rank {r} is cut short"),
                "every rank must call seam with the same library and arguments of the same kind",
            )
        };
        let mut whole = Interface {
            coords: Vec::new(),
            global_id: Vec::new(),
            global_dof: Vec::new(),
            connectivity: vec![Vec::new(); mesh.blocks.len()],
            faces: vec![Vec::new(); mesh.side_sets.len()],
            origin: Vec::new(),
            host_elem: Vec::new(),
            value_at: Vec::new(),
        };
        let mut inner_of: HashMap<u64, usize> = HashMap::new();
        // Per block, the elements in (rank, order): (rank, index there, inner nodes).
        let mut per_block: Vec<Vec<(usize, usize, Vec<usize>)>> =
            vec![Vec::new(); mesh.blocks.len()];
        // Per rank, each of its elements' (block, position in the block).
        let mut placed: Vec<Vec<(usize, usize)>> = Vec::with_capacity(ids.len());
        let mut by_nodes: HashMap<Vec<u64>, usize> = HashMap::new();
        // Per surface, (block, position in the block, side).
        let mut raw_faces: Vec<Vec<(usize, usize, u8)>> = vec![Vec::new(); mesh.side_sets.len()];
        let mut sent = 0;
        for (r, (ids, xyz)) in ids.iter().zip(coords).enumerate() {
            let [n_nodes, n_elems, n_faces] = match ids.get(..3) {
                Some(&[a, b, c]) => [a as usize, b as usize, c as usize],
                _ => return Err(corrupt(r)),
            };
            if xyz.len() != 3 * n_nodes || ids.len() < 3 + 2 * n_nodes + 3 * n_faces {
                return Err(corrupt(r));
            }
            let mut mine = Vec::with_capacity(n_nodes);
            for k in 0..n_nodes {
                let (gid, dof) = (ids[3 + 2 * k], ids[4 + 2 * k] as usize);
                let x = [xyz[3 * k], xyz[3 * k + 1], xyz[3 * k + 2]];
                let i = *inner_of.entry(gid).or_insert_with(|| {
                    whole.coords.push(x);
                    whole.global_id.push(gid);
                    whole.global_dof.push(dof);
                    whole.value_at.push(sent + k);
                    whole.coords.len() - 1
                });
                if whole.global_dof[i] != dof {
                    return Err(mesh_error(
                        format!(
                            "global node {gid} has dof {} on one rank and {dof} on rank {r}",
                            whole.global_dof[i]
                        ),
                        "give a node the same global dof on every rank that holds it",
                    ));
                }
                mine.push(i);
            }
            sent += n_nodes;
            let mut at = 3 + 2 * n_nodes;
            let mut elems = Vec::with_capacity(n_elems);
            for e in 0..n_elems {
                let block = *ids.get(at).ok_or_else(|| corrupt(r))? as usize;
                let Some(b) = mesh.blocks.get(block) else {
                    return Err(corrupt(r));
                };
                let nn = b.topology.node_count();
                let host = *ids.get(at + 1).ok_or_else(|| corrupt(r))? as usize;
                let conn = ids.get(at + 2..at + 2 + nn).ok_or_else(|| corrupt(r))?;
                let inner: Vec<usize> = conn
                    .iter()
                    .map(|&k| mine.get(k as usize).copied().ok_or_else(|| corrupt(r)))
                    .collect::<Result<_, _>>()?;
                let mut key: Vec<u64> = inner.iter().map(|&i| whole.global_id[i]).collect();
                key.sort_unstable();
                if let Some(&other) = by_nodes.get(&key) {
                    return Err(mesh_error(
                        format!(
                            "the element of global nodes {key:?} carries interface faces on rank {other} and on rank {r} (its element {e} there)"
                        ),
                        "give each interface face on one rank only: the rank that owns its element",
                    ));
                }
                by_nodes.insert(key, r);
                elems.push((block, per_block[block].len()));
                per_block[block].push((r, host, inner));
                at += 2 + nn;
            }
            placed.push(elems);
            let faces = ids.get(at..at + 3 * n_faces).ok_or_else(|| corrupt(r))?;
            for f in faces.chunks_exact(3) {
                let (s, e, side) = (f[0] as usize, f[1] as usize, f[2] as u8);
                let (Some(list), Some(&(b, k))) = (raw_faces.get_mut(s), placed[r].get(e)) else {
                    return Err(corrupt(r));
                };
                list.push((b, k, side));
            }
        }
        // Inner elements block after block; a face's (block, position) becomes its number.
        let mut first = Vec::with_capacity(per_block.len());
        for (b, elems) in per_block.into_iter().enumerate() {
            first.push(whole.origin.len());
            for (r, host, nodes) in elems {
                whole.origin.push(r);
                whole.host_elem.push(host);
                whole.connectivity[b].extend(nodes);
            }
        }
        for (list, raw) in whole.faces.iter_mut().zip(raw_faces) {
            list.extend(raw.into_iter().map(|(b, k, side)| (first[b] + k, side)));
        }
        Ok(whole)
    }
}

impl RankEmbedding {
    /// The serial embedding of the whole interface this rank holds (for inspection).
    pub fn interface(&self) -> &Embedding {
        &self.inner
    }

    /// Add an interaction (collective: every rank adds the same ones in the same order).
    /// A mortar tie gives its rows by [`Self::constraints`].
    pub fn add_interaction(&mut self, i: Interaction) -> Result<usize, EmbedError> {
        let r = self.inner.add_interaction(i);
        agree(&self.comm, r)
    }

    /// The interactions of a contact deck (collective), as [`Embedding::add_deck`]: the
    /// same deck on every rank.
    pub fn add_deck(&mut self, name: &str, text: &str) -> Result<Vec<usize>, EmbedError> {
        let r = self.inner.add_deck(name, text);
        agree(&self.comm, r)
    }

    /// The interactions of a deck file (collective), as [`Embedding::add_deck_file`]:
    /// every rank reads the same file (relative paths in it from its folder), so it must
    /// be readable from every rank; a rank that cannot read it fails every rank.
    pub fn add_deck_file(&mut self, path: &std::path::Path) -> Result<Vec<usize>, EmbedError> {
        let r = self.inner.add_deck_file(path);
        agree(&self.comm, r)
    }

    /// The rows of every mortar tie that belong to this rank (collective), in
    /// interaction order: the multipliers whose side-A node this rank owns (the lowest
    /// rank among the interface elements around it), in the host's global dofs. Each
    /// multiplier is on one rank only, so the ranks' rows together are the serial
    /// embedding's [`Embedding::constraints`]; each rank has `index`, every multiplier's
    /// place in the whole tie, to number the host's multiplier unknowns. A dual tie's
    /// condensed rows come the same way; `crosspoints` are the owned side-A nodes left
    /// without a multiplier, by global id. A fixed node ([`EmbeddingBuilder::fixed_nodes`])
    /// given on any rank is fixed for all.
    pub fn constraints(&self) -> Result<Vec<RankTie>, EmbedError> {
        let ties = agree(&self.comm, self.inner.constraints())?;
        let mine = |n: usize| self.node_owner.get(n) == Some(&self.rank);
        let dof = |d: usize| self.global_dof[d];
        let node = |n: usize| self.inner.mesh.node_numbers[n] as usize;
        Ok(ties
            .iter()
            .map(|t| {
                let (rows, index) = t.restricted(&mine, &dof, &node);
                RankTie {
                    rows,
                    index,
                    total: t.multiplier_dofs.len(),
                }
            })
            .collect())
    }

    /// Its communicator (seam's duplicate of the host's).
    pub(crate) fn comm(&self) -> &SimpleCommunicator {
        &self.comm
    }

    /// Heat (W) through a tie for this rank's multipliers `lambda` (one per entry of
    /// `rows.multiplier_dofs`, `rows` a [`RankTie`]'s), summed over the ranks
    /// (collective).
    pub fn tie_heat(&self, rows: &TieConstraints, lambda: &[f64]) -> Result<Heat, EmbedError> {
        let own = agree(&self.comm, rows.heat(lambda))?;
        let mut summed = [0.0; 2];
        self.comm.all_reduce_into(
            &[own.side_a, own.side_b][..],
            &mut summed[..],
            SystemOperation::sum(),
        );
        Ok(Heat {
            side_a: summed[0],
            side_b: summed[1],
        })
    }

    /// Heat (W) through a condensed dual tie from the host's residual `K u − F` without
    /// the tie, at this rank's multipliers' dofs (`residual_at`, in `rows`' order; `rows`
    /// a [`RankTie`]'s), summed over the ranks (collective): the multipliers of
    /// [`TieConstraints::dual_multipliers_at`] through [`Self::tie_heat`]. The rank form
    /// of the serial `dual_multipliers` then `heat`.
    pub fn dual_tie_heat(
        &self,
        rows: &TieConstraints,
        residual_at: &[f64],
    ) -> Result<Heat, EmbedError> {
        let lambda = agree(&self.comm, rows.dual_multipliers_at(residual_at))?;
        self.tie_heat(rows, &lambda)
    }

    /// The values at this rank's own side-A points of flux interaction `i` at the host's
    /// field (collective; `u_local` as for [`Self::contributions`]): each point's index
    /// in the interaction's point order (the serial [`Embedding::point_fields`] order)
    /// with its values, its faces named as the ranks that gave them name them (side A's
    /// is this rank's own element; side B's is `side_b_rank`'s). A point is its side-A
    /// face's rank's (or, on a node surface, its node's owner's), so the ranks' lists
    /// together are the serial list, each point once.
    pub fn point_fields(&self, i: usize, u_local: &[f64]) -> Result<Vec<RankPoint>, EmbedError> {
        let u = self.whole_field(u_local)?;
        let values = agree(&self.comm, self.inner.point_fields(i, &u))?;
        Ok(self.own_points_of(i, &values))
    }

    /// The values at this rank's own side-A points of a mortar tie for this rank's
    /// multipliers `lambda` (`rows` a [`RankTie`]'s; one value per entry of its
    /// `multiplier_dofs`: the host's unknowns, or those of
    /// [`TieConstraints::dual_multipliers_at`] for a condensed dual tie), as
    /// [`Self::point_fields`] gives them (collective). The multiplier field at a point
    /// takes the multipliers of its face's nodes, which other ranks may own: each rank's
    /// share of the field at every point is summed over the ranks (16 B per point).
    pub fn tie_point_fields(
        &self,
        rows: &TieConstraints,
        lambda: &[f64],
    ) -> Result<Vec<RankPoint>, EmbedError> {
        let field = self.tie_field(rows, lambda)?;
        let values = agree(
            &self.comm,
            self.inner.tie_point_values(rows.interaction, &field),
        )?;
        Ok(self.own_points_of(rows.interaction, &values))
    }

    /// Per face of a mortar tie for this rank's multipliers `lambda` (as
    /// [`Self::tie_point_fields`]), the faces this rank gave, as [`Self::face_fields`]
    /// gives them (collective).
    pub fn tie_face_fields(
        &self,
        rows: &TieConstraints,
        lambda: &[f64],
        side_b: bool,
    ) -> Result<Vec<FaceValues>, EmbedError> {
        let field = self.tie_field(rows, lambda)?;
        let faces = agree(
            &self.comm,
            self.inner.tie_face_values(rows.interaction, &field, side_b),
        )?;
        Ok(self.own_faces_of(faces))
    }

    /// The multiplier field of a tie at every point of its pairing (`None` where it has
    /// no multiplier), from each rank's multipliers `lambda` for its `rows` (collective;
    /// a `lambda` of another length than the rows' multipliers is refused on every
    /// rank): each rank's part `Σ ψ_k λ_k` over its own multipliers, summed.
    fn tie_field(
        &self,
        rows: &TieConstraints,
        lambda: &[f64],
    ) -> Result<Vec<Option<f64>>, EmbedError> {
        let mine = agree(&self.comm, self.inner.tie_field(rows, lambda))?;
        // Per point its part of the field and whether this rank has a multiplier there.
        let parts: Vec<f64> = (mine.iter())
            .flat_map(|m| [m.unwrap_or(0.0), f64::from(u8::from(m.is_some()))])
            .collect();
        let mut summed = vec![0.0; parts.len()];
        self.comm
            .all_reduce_into(&parts[..], &mut summed[..], SystemOperation::sum());
        Ok(summed
            .chunks_exact(2)
            .map(|s| (s[1] > 0.0).then_some(s[0]))
            .collect())
    }

    /// Per face of flux interaction `i` at the host's field (collective; `u_local` as
    /// for [`Self::contributions`]): the faces this rank gave (side A's, then side B's
    /// with `side_b`), named by this rank's elements, with the serial
    /// [`Embedding::face_fields`]' values: every point's flux is summed from the rank
    /// that owns it (8 B per point), so a face whose points sit on several ranks has
    /// them all. The ranks' faces together are the serial list, each face once.
    pub fn face_fields(
        &self,
        i: usize,
        u_local: &[f64],
        side_b: bool,
    ) -> Result<Vec<FaceValues>, EmbedError> {
        let u = self.whole_field(u_local)?;
        let own = agree(&self.comm, self.inner.point_flux(i, &u))?;
        let mine: Vec<f64> = own.iter().map(|f| f.map_or(0.0, |f| f.q)).collect();
        let mut every = vec![0.0; mine.len()];
        self.comm
            .all_reduce_into(&mine[..], &mut every[..], SystemOperation::sum());
        let p = &self.inner.pairs[i];
        let points = &Embedding::searched(p)?.points;
        let faces = super::face_values(&p.a, &p.b, points, |k| Some(every[k]), side_b);
        Ok(self.own_faces_of(faces))
    }

    /// The faces of `faces` this rank gave, named by its elements.
    fn own_faces_of(&self, faces: Vec<FaceValues>) -> Vec<FaceValues> {
        (faces.into_iter())
            .filter(|f| self.origin[f.face.element] == self.rank)
            .map(|f| FaceValues {
                face: HostFace {
                    element: self.host_elem[f.face.element],
                    ..f.face
                },
                ..f
            })
            .collect()
    }

    /// This rank's own points of interaction `i` among `values` (every point's, in
    /// point order), their faces named by the ranks that gave them.
    fn own_points_of(&self, i: usize, values: &[PointValues]) -> Vec<RankPoint> {
        let kept = self.inner.pairs[i].kept.as_deref().unwrap_or_default();
        let rename = |f: HostFace| HostFace {
            element: self.host_elem[f.element],
            ..f
        };
        kept.iter()
            .map(|&k| {
                let v = values[k];
                RankPoint {
                    point: k,
                    side_b_rank: v.side_b.map(|f| self.origin[f.element]),
                    values: PointValues {
                        side_a: v.side_a.map(rename),
                        side_b: v.side_b.map(rename),
                        ..v
                    },
                }
            })
            .collect()
    }

    /// Number of interactions.
    pub fn len(&self) -> usize {
        self.inner.len()
    }

    pub fn is_empty(&self) -> bool {
        self.inner.is_empty()
    }

    /// Pair every interaction anew (collective): every rank searches the whole interface
    /// as the serial embedding does and keeps its own side-A points.
    pub fn search(&mut self) -> Result<(), EmbedError> {
        let r = self.inner.search();
        agree(&self.comm, r)?;
        self.keep_own_points();
        let mut mine = 0u64;
        for p in &self.inner.pairs {
            let (Some(result), Some(kept)) = (&p.result, &p.kept) else {
                continue;
            };
            for &k in kept {
                let b = result.points[k]
                    .b_face
                    .map(|f| p.b.faces[f as usize].side.elem);
                if b.is_some_and(|e| self.origin[e.index()] != self.rank) {
                    mine += 1;
                }
            }
        }
        let mut all = 0u64;
        self.comm
            .all_reduce_into(&mine, &mut all, SystemOperation::sum());
        self.across = all as usize;
        Ok(())
    }

    /// The nodes moved (collective): each rank gives the new coordinates of its local
    /// nodes (owned and ghost, in the builder's node order; current at least at its
    /// interface faces' elements' nodes). Every pairing is kept and its points placed
    /// again on the moved faces, gaps measured anew, as the serial
    /// [`Embedding::move_nodes`]; [`Self::search`] pairs anew.
    pub fn move_nodes(&mut self, coords_local: &[[f64; 3]]) -> Result<(), EmbedError> {
        let check = if coords_local.len() != self.local_nodes {
            Err(argument(
                format!(
                    "{} coordinates for {} local nodes",
                    coords_local.len(),
                    self.local_nodes
                ),
                "pass every local node's new coordinates (owned and ghost), in the builder's node order",
            ))
        } else if let Some(&k) =
            (self.sent.iter()).find(|&&k| coords_local[k].iter().any(|c| !c.is_finite()))
        {
            Err(argument(
                format!(
                    "local node {k} moved to a non-finite position {:?}",
                    coords_local[k]
                ),
                "check the host's displacement field",
            ))
        } else {
            Ok(())
        };
        agree(&self.comm, check)?;
        let mine: Vec<f64> = (self.sent.iter()).flat_map(|&k| coords_local[k]).collect();
        let all = self.whole(&mine, 3);
        let coords: Vec<[f64; 3]> = all.chunks_exact(3).map(|x| [x[0], x[1], x[2]]).collect();
        let moved = self.inner.move_nodes(&coords);
        // A move forgets which points are whose, even one that failed part of the way
        // (a rank must never go on evaluating every point).
        self.keep_own_points();
        agree(&self.comm, moved)
    }

    /// Evaluate only this rank's own side-A points: those of the faces it gave, and on
    /// a node surface those of the nodes it owns.
    fn keep_own_points(&mut self) {
        let (rank, origin, owner) = (self.rank, &self.origin, &self.node_owner);
        let owns = |e: Option<ElemId>, n: Option<NodeId>| match (e, n) {
            (Some(e), _) => origin.get(e.index()) == Some(&rank),
            (None, Some(n)) => owner.get(n.index()) == Some(&rank),
            (None, None) => false,
        };
        self.inner.own_points(Some(&owns));
    }

    /// What the last search of interaction `i` paired, over every rank: every rank
    /// holds the whole pairing, so this is the serial [`Embedding::coverage`] and the
    /// same on every rank (local).
    pub fn coverage(&self, i: usize) -> Result<super::Coverage, EmbedError> {
        self.inner.coverage(i)
    }

    /// Over all ranks, the side-A points (of the last search) paired with a side-B face
    /// that another rank gave: the pairs that straddle ranks.
    pub fn points_across(&self) -> usize {
        self.across
    }

    /// The interface terms of this rank's own side-A points at the host's field
    /// (collective): `u_local` holds the value at each local node (owned and ghost, in
    /// the builder's node order), current at least at the nodes of this rank's
    /// interface faces' elements. Residual, Jacobian and load come in the host's global
    /// dof numbers, for this rank to add (with `ADD_VALUES`: they may fall in other
    /// ranks' rows); `heat` is summed over the ranks, the same on every rank.
    pub fn contributions(&self, u_local: &[f64]) -> Result<Contributions, EmbedError> {
        let u = self.whole_field(u_local)?;
        let mut c = agree(&self.comm, self.inner.contributions(&u))?;
        let dof = |k: usize| self.global_dof[k];
        for (d, _) in c.residual.iter_mut().chain(c.load.iter_mut()) {
            *d = dof(*d);
        }
        for (i, j, _) in &mut c.jacobian {
            (*i, *j) = (dof(*i), dof(*j));
        }
        self.sum_heat(&mut c.heat);
        Ok(c)
    }

    /// Each interaction's heat (this rank's share) summed over the ranks (collective).
    fn sum_heat(&self, heat: &mut [Option<Heat>]) {
        let local: Vec<f64> = (heat.iter())
            .flat_map(|h| h.map_or([0.0; 2], |h| [h.side_a, h.side_b]))
            .collect();
        let mut summed = vec![0.0; local.len()];
        self.comm
            .all_reduce_into(&local[..], &mut summed[..], SystemOperation::sum());
        for (h, s) in heat.iter_mut().zip(summed.chunks_exact(2)) {
            if let Some(h) = h {
                *h = Heat {
                    side_a: s[0],
                    side_b: s[1],
                };
            }
        }
    }

    /// The field at every inner node from each rank's local values (collective): the
    /// values this rank's interface needs, checked on every rank first (a wrong length
    /// or a value that is not finite is refused everywhere).
    fn whole_field(&self, u_local: &[f64]) -> Result<Vec<f64>, EmbedError> {
        let check = if u_local.len() != self.local_nodes {
            Err(argument(
                format!(
                    "the local field has {} entries for {} local nodes",
                    u_local.len(),
                    self.local_nodes
                ),
                "pass the value at every local node (owned and ghost), in the builder's node order",
            ))
        } else if let Some(&k) = self.sent.iter().find(|&&k| !u_local[k].is_finite()) {
            Err(argument(
                format!(
                    "the local field is not finite at local node {k} ({})",
                    u_local[k]
                ),
                "check the host's solve and its update of ghost values",
            ))
        } else {
            Ok(())
        };
        agree(&self.comm, check)?;
        let mine: Vec<f64> = self.sent.iter().map(|&k| u_local[k]).collect();
        Ok(self.whole(&mine, 1))
    }

    /// Per inner node, its `width` values from the ranks that hold it, each rank giving
    /// `width` values per node it sends (collective).
    fn whole(&self, mine: &[f64], width: usize) -> Vec<f64> {
        let all = gather_parts(&self.comm, mine).concat();
        (self.value_at.iter())
            .flat_map(|&k| all[k * width..(k + 1) * width].iter().copied())
            .collect()
    }
}
