//! The bytes of what rank 0 sends the ranks holding parts of a distributed mesh
//! ([`super::part`], [`super::share`]): a little-endian writer and reader, a mesh's
//! encoding, and messages of any length (MPI counts are 32-bit: sent in chunks).

use mpi::topology::SimpleCommunicator;
use mpi::traits::{Communicator, Destination, Source};

use crate::mesh::{Block, ElemId, Mesh, NodeId, NodeSet, Side, SideSet, Topology};

/// Bytes per message (MPI counts are 32-bit).
const CHUNK: usize = 1 << 30;

/// Send `bytes` to rank `to`: its length, then chunks of at most [`CHUNK`].
pub(super) fn send_bytes(world: &SimpleCommunicator, to: usize, bytes: &[u8]) {
    let p = world.process_at_rank(to as i32);
    p.send(&(bytes.len() as u64));
    for chunk in bytes.chunks(CHUNK) {
        p.send(chunk);
    }
}

/// What rank 0 sent with [`send_bytes`].
pub(super) fn receive_bytes(world: &SimpleCommunicator) -> Vec<u8> {
    let root = world.process_at_rank(0);
    let (len, _) = root.receive::<u64>();
    let mut out = Vec::with_capacity(len as usize);
    while out.len() < len as usize {
        let (chunk, _) = root.receive_vec::<u8>();
        if chunk.is_empty() {
            break;
        }
        out.extend_from_slice(&chunk);
    }
    out
}

#[derive(Default)]
pub(super) struct Writer(pub Vec<u8>);

impl Writer {
    pub(super) fn u64(&mut self, v: u64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(super) fn f64(&mut self, v: f64) {
        self.0.extend_from_slice(&v.to_le_bytes());
    }
    pub(super) fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.0.extend_from_slice(s.as_bytes());
    }
    pub(super) fn u32s(&mut self, v: &[u32]) {
        self.u64(v.len() as u64);
        v.iter()
            .for_each(|x| self.0.extend_from_slice(&x.to_le_bytes()));
    }
    pub(super) fn i32s(&mut self, v: &[i32]) {
        self.u64(v.len() as u64);
        v.iter()
            .for_each(|x| self.0.extend_from_slice(&x.to_le_bytes()));
    }
    pub(super) fn i64s(&mut self, v: &[i64]) {
        self.u64(v.len() as u64);
        v.iter()
            .for_each(|x| self.0.extend_from_slice(&x.to_le_bytes()));
    }
    pub(super) fn u64s(&mut self, v: &[u64]) {
        self.u64(v.len() as u64);
        v.iter()
            .for_each(|x| self.0.extend_from_slice(&x.to_le_bytes()));
    }
    pub(super) fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        v.iter()
            .for_each(|x| self.0.extend_from_slice(&x.to_le_bytes()));
    }
}

pub(super) struct Reader<'a> {
    pub b: &'a [u8],
    pub at: usize,
}

impl Reader<'_> {
    pub(super) fn take(&mut self, n: usize) -> Result<&[u8], String> {
        let end = self.at.checked_add(n).filter(|&e| e <= self.b.len());
        let end = end.ok_or("the local mesh received is cut short")?;
        let out = &self.b[self.at..end];
        self.at = end;
        Ok(out)
    }
    pub(super) fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    pub(super) fn f64(&mut self) -> Result<f64, String> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    pub(super) fn len(&mut self, each: usize) -> Result<usize, String> {
        let n = self.u64()? as usize;
        if n.saturating_mul(each) > self.b.len() - self.at {
            return Err("the local mesh received is cut short".into());
        }
        Ok(n)
    }
    pub(super) fn str(&mut self) -> Result<String, String> {
        let n = self.len(1)?;
        String::from_utf8(self.take(n)?.to_vec()).map_err(|e| e.to_string())
    }
    pub(super) fn u32s(&mut self) -> Result<Vec<u32>, String> {
        let n = self.len(4)?;
        let b = self.take(4 * n)?;
        Ok(b.chunks_exact(4)
            .map(|c| u32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }
    pub(super) fn i32s(&mut self) -> Result<Vec<i32>, String> {
        let n = self.len(4)?;
        let b = self.take(4 * n)?;
        Ok(b.chunks_exact(4)
            .map(|c| i32::from_le_bytes(c.try_into().expect("4 bytes")))
            .collect())
    }
    pub(super) fn i64s(&mut self) -> Result<Vec<i64>, String> {
        let n = self.len(8)?;
        let b = self.take(8 * n)?;
        Ok(b.chunks_exact(8)
            .map(|c| i64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect())
    }
    pub(super) fn u64s(&mut self) -> Result<Vec<u64>, String> {
        let n = self.len(8)?;
        let b = self.take(8 * n)?;
        Ok(b.chunks_exact(8)
            .map(|c| u64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect())
    }
    pub(super) fn f64s(&mut self) -> Result<Vec<f64>, String> {
        let n = self.len(8)?;
        let b = self.take(8 * n)?;
        Ok(b.chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
            .collect())
    }
}

const TOPOLOGIES: [Topology; 9] = [
    Topology::Hex8,
    Topology::Tet4,
    Topology::Wedge6,
    Topology::Pyramid5,
    Topology::Quad4,
    Topology::Tri3,
    Topology::Shell4,
    Topology::Shell3,
    Topology::Bar2,
];

pub(super) fn encode_mesh(m: &Mesh, w: &mut Writer) {
    w.u64(m.dim as u64);
    w.u64(m.axisymmetric as u64);
    w.str(
        &m.source
            .as_ref()
            .map_or(String::new(), |p| p.display().to_string()),
    );
    w.f64s(m.coords.as_flattened());
    w.i64s(&m.node_numbers);
    w.i64s(&m.elem_numbers);
    w.u64(m.blocks.len() as u64);
    for b in &m.blocks {
        w.u64(b.id as u64);
        w.str(&b.name);
        let t = TOPOLOGIES
            .iter()
            .position(|&t| t == b.topology)
            .unwrap_or(0);
        w.u64(t as u64);
        w.u32s(&b.connectivity.iter().map(|n| n.0).collect::<Vec<_>>());
        w.u64(b.first_elem.0 as u64);
        w.u64(b.thickness.is_some() as u64);
        w.f64(b.thickness.unwrap_or(0.0));
    }
    w.u64(m.side_sets.len() as u64);
    for s in &m.side_sets {
        w.u64(s.id as u64);
        w.str(&s.name);
        w.u32s(&s.sides.iter().map(|x| x.elem.0).collect::<Vec<_>>());
        w.u32s(&s.sides.iter().map(|x| x.side as u32).collect::<Vec<_>>());
    }
    w.u64(m.node_sets.len() as u64);
    for s in &m.node_sets {
        w.u64(s.id as u64);
        w.str(&s.name);
        w.u32s(&s.nodes.iter().map(|n| n.0).collect::<Vec<_>>());
    }
    w.u64(m.assemblies.len() as u64);
    for a in &m.assemblies {
        w.u64(a.id as u64);
        w.str(&a.name);
        w.u64(match a.kind {
            crate::mesh::AssemblyKind::Blocks => 0,
            crate::mesh::AssemblyKind::SideSets => 1,
            crate::mesh::AssemblyKind::Assemblies => 2,
        });
        w.i64s(&a.members);
    }
}

pub(super) fn decode_mesh(r: &mut Reader<'_>) -> Result<Mesh, String> {
    let dim = r.u64()? as usize;
    let axisymmetric = r.u64()? != 0;
    let source = r.str()?;
    let flat = r.f64s()?;
    let coords: Vec<[f64; 3]> = flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
    let node_numbers = r.i64s()?;
    let elem_numbers = r.i64s()?;
    let nodes = coords.len();
    let bad = || "the local mesh received refers to a node or element it lacks".to_string();
    let mut blocks = Vec::new();
    for _ in 0..r.len(1)? {
        let id = r.u64()? as i64;
        let name = r.str()?;
        let topology = *TOPOLOGIES.get(r.u64()? as usize).ok_or_else(bad)?;
        let connectivity: Vec<NodeId> = r.u32s()?.into_iter().map(NodeId).collect();
        if connectivity.iter().any(|n| n.index() >= nodes)
            || !connectivity.len().is_multiple_of(topology.node_count())
        {
            return Err(bad());
        }
        let first_elem = ElemId(r.u64()? as u32);
        let has_thickness = r.u64()? != 0;
        let thickness = r.f64()?;
        blocks.push(Block {
            id,
            name,
            topology,
            connectivity,
            first_elem,
            thickness: has_thickness.then_some(thickness),
        });
    }
    let elems: usize = blocks.iter().map(Block::len).sum();
    if elems != elem_numbers.len() || node_numbers.len() != nodes {
        return Err(bad());
    }
    let mut side_sets = Vec::new();
    for _ in 0..r.len(1)? {
        let id = r.u64()? as i64;
        let name = r.str()?;
        let e = r.u32s()?;
        let s = r.u32s()?;
        if e.len() != s.len() || e.iter().any(|&e| e as usize >= elems) {
            return Err(bad());
        }
        let sides = e
            .into_iter()
            .zip(s)
            .map(|(e, s)| Side {
                elem: ElemId(e),
                side: s as u8,
            })
            .collect();
        side_sets.push(SideSet { id, name, sides });
    }
    let mut node_sets = Vec::new();
    for _ in 0..r.len(1)? {
        let id = r.u64()? as i64;
        let name = r.str()?;
        let list: Vec<NodeId> = r.u32s()?.into_iter().map(NodeId).collect();
        if list.iter().any(|n| n.index() >= nodes) {
            return Err(bad());
        }
        node_sets.push(NodeSet {
            id,
            name,
            nodes: list,
        });
    }
    let mut assemblies = Vec::new();
    for _ in 0..r.len(1)? {
        let id = r.u64()? as i64;
        let name = r.str()?;
        let kind = match r.u64()? {
            0 => crate::mesh::AssemblyKind::Blocks,
            1 => crate::mesh::AssemblyKind::SideSets,
            _ => crate::mesh::AssemblyKind::Assemblies,
        };
        let members = r.i64s()?;
        assemblies.push(crate::mesh::Assembly {
            id,
            name,
            kind,
            members,
        });
    }
    Ok(Mesh {
        dim,
        coords,
        node_numbers,
        elem_numbers,
        blocks,
        side_sets,
        node_sets,
        assemblies,
        source: (!source.is_empty()).then(|| source.into()),
        axisymmetric,
    })
}
