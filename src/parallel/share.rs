//! What rank 0 works out on the whole mesh and the ranks holding parts of it get their
//! share of ([`super::part`]): the contact surfaces of a definition ([`surfaces`]: rank
//! 0 builds them by the Sierra rules, whose ownership and skinning need the whole mesh,
//! and sends each rank the faces of its own elements, its own nodes and the tributary
//! faces around them), and which faces are in contact ([`faces_in_contact`]: each rank
//! tells the owners of the faces its points touched).

use std::collections::HashSet;

use mpi::collective::SystemOperation;
use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, CommunicatorCollectives};

use crate::diag::Diagnostic;
use crate::mesh::{Mesh, NodeId, Side};
use crate::surface::{ContactSurface, SurfaceFace, SurfaceKind, SurfaceSet};

use super::part::{self, Part};
use super::{session, wire};

/// The surfaces of one contact definition on a distributed mesh: rank 0 builds them
/// (`build`, on the whole mesh) and sends each other rank its share, which it returns
/// (no diagnostics: rank 0 reports them). A rank that cannot read its share makes rank
/// 0's set carry an error (E0904), so the run stops at its next check.
pub(super) fn surfaces(mesh: &Mesh, build: impl FnOnce() -> SurfaceSet) -> SurfaceSet {
    let world = session::comm();
    if world.rank() == 0 {
        let mut set = build();
        let size = world.size() as usize;
        for r in 1..size {
            let bytes = part::with(|p| encode_share(p, mesh, &set, r)).unwrap_or_default();
            wire::send_bytes(&world, r, &bytes);
        }
        if let Err(r) = all_ok(&world, true) {
            set.diagnostics.push(
                Diagnostic::error(
                    "E0904",
                    format!("the contact surfaces could not be sent to rank {r}"),
                )
                .help("run without mpirun (serially); docs/parallel.md lists what is distributed"),
            );
        }
        return set;
    }
    let bytes = wire::receive_bytes(&world);
    let share = part::with(|p| decode_share(p, &bytes)).unwrap_or_else(|| Err("no part".into()));
    let _ = all_ok(&world, share.is_ok());
    share.unwrap_or_default()
}

/// Whether every rank is `ok` (collective): the lowest rank that is not, otherwise.
pub(super) fn all_ok(world: &SimpleCommunicator, ok: bool) -> Result<(), usize> {
    let mine: u64 = if ok { u64::MAX } else { world.rank() as u64 };
    let mut first = 0u64;
    world.all_reduce_into(&mine, &mut first, SystemOperation::min());
    if first == u64::MAX {
        Ok(())
    } else {
        Err(first as usize)
    }
}

/// Rank `r`'s share of `set` (rank 0's, the whole mesh), in global numbers: per surface
/// its name, kind, parent and origins, the faces of `r`'s elements, the nodes `r` owns,
/// and the tributary faces with a node `r` owns.
fn encode_share(p: &Part, mesh: &Mesh, set: &SurfaceSet, r: usize) -> Vec<u8> {
    let mut w = Vec::new();
    let u64 = |w: &mut Vec<u8>, v: u64| w.extend_from_slice(&v.to_le_bytes());
    let str = |w: &mut Vec<u8>, s: &str| {
        w.extend_from_slice(&(s.len() as u64).to_le_bytes());
        w.extend_from_slice(s.as_bytes());
    };
    u64(&mut w, set.surfaces.len() as u64);
    for s in &set.surfaces {
        str(&mut w, &s.name);
        u64(&mut w, (s.kind == SurfaceKind::Nodes) as u64);
        u64(&mut w, s.parent.is_some() as u64);
        str(&mut w, s.parent.as_deref().unwrap_or(""));
        u64(&mut w, s.origins.len() as u64);
        for (o, count) in &s.origins {
            str(&mut w, o);
            u64(&mut w, *count as u64);
        }
        let faces: Vec<&SurfaceFace> = s
            .faces
            .iter()
            .filter(|f| p.elem_rank(f.side.elem) == r)
            .collect();
        u64(&mut w, faces.len() as u64);
        for f in faces {
            u64(&mut w, p.elem_global[f.side.elem.index()] as u64);
            u64(&mut w, f.side.side as u64);
            w.extend_from_slice(&f.loft.to_le_bytes());
            u64(&mut w, f.origin as u64);
        }
        let owned = |n: NodeId| p.node_rank(n) == r;
        let nodes: Vec<NodeId> = s.nodes.iter().copied().filter(|&n| owned(n)).collect();
        u64(&mut w, nodes.len() as u64);
        for n in nodes {
            u64(&mut w, p.node_global[n.index()] as u64);
        }
        let tributary: Vec<Side> = s
            .tributary
            .iter()
            .copied()
            .filter(|&side| mesh.side_nodes(side).any(owned))
            .collect();
        u64(&mut w, tributary.len() as u64);
        for side in tributary {
            u64(&mut w, p.elem_global[side.elem.index()] as u64);
            u64(&mut w, side.side as u64);
        }
    }
    w
}

/// The surfaces rank 0 sent, in this rank's local numbers.
fn decode_share(p: &Part, b: &[u8]) -> Result<SurfaceSet, String> {
    let mut r = Bytes { b, at: 0 };
    let mut out = SurfaceSet::default();
    for _ in 0..r.count(1)? {
        let name = r.str()?;
        let kind = if r.u64()? != 0 {
            SurfaceKind::Nodes
        } else {
            SurfaceKind::Faces
        };
        let has_parent = r.u64()? != 0;
        let parent = r.str()?;
        let mut origins = Vec::new();
        for _ in 0..r.count(16)? {
            let o = r.str()?;
            origins.push((o, r.u64()? as usize));
        }
        let elem = |g: u64| {
            p.local_elem(g as u32)
                .ok_or_else(|| format!("contact surface `{name}`: element {g} is not held here"))
        };
        let mut faces = Vec::new();
        for _ in 0..r.count(32)? {
            let e = elem(r.u64()?)?;
            let side = r.u64()? as u8;
            let loft = r.f64()?;
            let origin = r.u64()? as u32;
            faces.push(SurfaceFace {
                side: Side { elem: e, side },
                loft,
                origin,
            });
        }
        let mut nodes = Vec::new();
        for _ in 0..r.count(8)? {
            let g = r.u64()?;
            nodes.push(
                p.local_node(g as u32).ok_or_else(|| {
                    format!("contact surface `{name}`: node {g} is not held here")
                })?,
            );
        }
        let mut tributary = Vec::new();
        for _ in 0..r.count(16)? {
            let e = elem(r.u64()?)?;
            tributary.push(Side {
                elem: e,
                side: r.u64()? as u8,
            });
        }
        out.surfaces.push(ContactSurface {
            name,
            kind,
            faces,
            tributary,
            nodes,
            origins,
            parent: has_parent.then_some(parent),
        });
    }
    Ok(out)
}

/// A reader of the bytes [`encode_share`] wrote.
struct Bytes<'a> {
    b: &'a [u8],
    at: usize,
}

impl Bytes<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.b.len());
        let end = end.ok_or("the contact surfaces received are cut short")?;
        let out = &self.b[self.at..end];
        self.at = end;
        Ok(out)
    }
    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    /// A count of items of at least `each` bytes that the rest can hold.
    fn count(&mut self, each: usize) -> Result<usize, String> {
        let n = self.u64()? as usize;
        if n.saturating_mul(each) > self.b.len() - self.at {
            return Err("the contact surfaces received are cut short".into());
        }
        Ok(n)
    }
    fn str(&mut self) -> Result<String, String> {
        let n = self.count(1)?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|e| e.to_string())
    }
}

/// `local` (the faces this rank's points touched, in its local numbers, contact partners'
/// included) with the faces of this rank's elements that other ranks' points touched:
/// each rank sends the faces it touched of other ranks' elements to their owners
/// (`MPI_Alltoallv`). Collective over the ranks of a distributed mesh.
pub(super) fn faces_in_contact(local: HashSet<Side>) -> HashSet<Side> {
    let world = session::comm();
    let size = world.size() as usize;
    let rank = world.rank() as usize;
    let out: Vec<Vec<u64>> = part::with(|p| {
        let mut out = vec![Vec::new(); size];
        for s in &local {
            let owner = p.elem_rank(s.elem);
            if owner != rank && s.elem.index() < p.elem_global.len() {
                let g = p.elem_global[s.elem.index()] as u64;
                out[owner].push((g << 4) | s.side as u64);
            }
        }
        out.iter_mut().for_each(|v| v.sort_unstable());
        out
    })
    .unwrap_or_else(|| vec![Vec::new(); size]);
    let got = session::exchange(&world, &out);
    let mut all = local;
    part::with(|p| {
        for key in got.into_iter().flatten() {
            if let Some(elem) = p.local_elem((key >> 4) as u32) {
                all.insert(Side {
                    elem,
                    side: (key & 15) as u8,
                });
            }
        }
    });
    all
}
