//! Contact surfaces built from a mesh by the Sierra rules: the surface commands of a
//! contact definition, read from the deck spec, made into [`crate::surface`]'s types.
//!
//! Entry point: [`build`] (or [`build_with_dead`] for element death). Input: the mesh and
//! one [`ContactDefinition`]; output: a [`SurfaceSet`] — the surfaces in deck order and
//! every warning or error found on the way.
//!
//! The rules, in the order they apply:
//! 1. *Inclusion.* Every element of a block named by any surface command (or listed by
//!    `Element =`) is included in the definition; dead elements never are.
//! 2. *Skinning.* A block contributes its exterior sides: sides no other included
//!    element shares (see the `skin` module). Shells contribute top and bottom, lofted by half
//!    their thickness; a solid side under an equivalenced shell is sandwiched.
//! 3. *Side sets* contribute their sides, exterior or not (a dead element's sides drop
//!    out). *Node sets* make node surfaces, whose nodes take their tributary area from
//!    the exterior faces of the mesh that lie wholly in the sets (`Contact Type = node`:
//!    from the surface's own faces); a node on no such face is reported (W0308).
//! 4. *Ownership.* A face (or node) belongs to at most one surface: the first command in
//!    the deck that includes it. Later commands skip it with a warning naming both
//!    surfaces and the count. `Skin All Blocks` makes one surface per block, named after
//!    the block, at its own place in the deck order.
//! 5. *Restriction.* With `Restrict Contact To Subdomain`, only faces whose centroid (and
//!    nodes) lie inside the sphere take part.
//! 6. *Subsets.* `Subset n With Normal v` moves faces with `n̂·v̂ > 0.45` into `<s>_<n>`;
//!    `Auto Subset` groups connected faces of similar normal into `<s>_<n>_auto_<k>`.
//!
//! Faces are ordered by (element, side) everywhere, which is what "lowest face id"
//! means in messages: element number first, then local side.

mod subset;

use std::collections::{BTreeMap, HashMap, HashSet};

use crate::deck::spec::{ContactDefinition, ContactType, SurfaceBlock, SurfaceDef};
use crate::diag::{Diagnostic, Diagnostics, Loc, SourceMap, did_you_mean};
use crate::mesh::{ElemId, Mesh, NodeId, Side, Topology};
use crate::surface::geometry::{self, Vec3, centroid};
use crate::surface::{ContactSurface, SurfaceFace, SurfaceKind, SurfaceSet, skin};

/// Build the contact surfaces of one definition.
pub fn build(mesh: &Mesh, def: &ContactDefinition, sources: &SourceMap) -> SurfaceSet {
    build_with_dead(mesh, def, sources, &HashSet::new())
}

/// Build as if the `dead` elements (dense ids) never existed: skinned surfaces gain the
/// faces their death exposes; side-set surfaces only lose faces.
pub fn build_with_dead(
    mesh: &Mesh,
    def: &ContactDefinition,
    sources: &SourceMap,
    dead: &HashSet<ElemId>,
) -> SurfaceSet {
    let mut b = Builder {
        mesh,
        sources,
        dead,
        diags: Diagnostics::default(),
        face_owner: HashMap::new(),
        node_owner: vec![u32::MAX; mesh.num_nodes()],
        surfaces: Vec::new(),
        exterior_by_elem: Vec::new(),
        mesh_skin: None,
    };
    b.run(def);
    SurfaceSet {
        surfaces: b.surfaces,
        diagnostics: b.diags,
    }
}

struct Builder<'a> {
    mesh: &'a Mesh,
    sources: &'a SourceMap,
    dead: &'a HashSet<ElemId>,
    diags: Diagnostics,
    /// Face → index of the owning surface.
    face_owner: HashMap<Side, u32>,
    /// Node → index of the owning surface (`u32::MAX`: none).
    node_owner: Vec<u32>,
    surfaces: Vec<ContactSurface>,
    /// Exterior sides grouped by element: `exterior_by_elem[e]` is a bit mask of sides.
    exterior_by_elem: Vec<u8>,
    /// The exterior sides of the whole mesh (every live element), made on first need by
    /// a contact node set.
    mesh_skin: Option<Vec<Side>>,
}

/// Faces gathered for one surface, with where each came from.
#[derive(Default)]
struct Gathered {
    faces: Vec<(Side, String)>,
    nodes: Vec<(NodeId, String)>,
}

impl<'a> Builder<'a> {
    fn run(&mut self, def: &ContactDefinition) {
        let included = self.included_elements(def);
        let exterior = skin::exterior_sides(self.mesh, &included);
        self.exterior_by_elem = vec![0; self.mesh.num_elems()];
        for s in &exterior {
            self.exterior_by_elem[s.elem.index()] |= 1 << (s.side - 1);
        }
        let mut names: HashMap<String, Loc> = HashMap::new();
        for cmd in &def.surfaces {
            match cmd {
                SurfaceDef::Contains { name, contains, at } => {
                    let before = self.error_count();
                    let g = self.gather_contains(name, contains, at);
                    let named_wrong = self.error_count() > before;
                    self.claim(name, SurfaceKind::Faces, g, at, &mut names, named_wrong);
                }
                SurfaceDef::NodeSet { name, contains, at } => {
                    let before = self.error_count();
                    let g = self.gather_node_sets(contains, at);
                    let named_wrong = self.error_count() > before;
                    let members: HashSet<NodeId> = g.nodes.iter().map(|n| n.0).collect();
                    let first = self.surfaces.len();
                    self.claim(name, SurfaceKind::Nodes, g, at, &mut names, named_wrong);
                    if first < self.surfaces.len() {
                        self.surfaces[first].tributary = self.tributary_faces(&members);
                        self.warn_isolated_nodes(first, at);
                    }
                }
                SurfaceDef::SkinAllBlocks { exclude, at } => {
                    let excluded = self.resolve_blocks(exclude, at);
                    for (b, block) in self.mesh.blocks.iter().enumerate() {
                        if excluded.contains(&b) {
                            continue;
                        }
                        if block.topology == Topology::Bar2 {
                            self.warn_beam(b, at);
                            continue;
                        }
                        let mut g = Gathered::default();
                        self.skin_block(b, &mut g);
                        self.claim(
                            &block.sierra_name(),
                            SurfaceKind::Faces,
                            g,
                            at,
                            &mut names,
                            false,
                        );
                    }
                }
                SurfaceDef::Block(sb) => {
                    let before = self.error_count();
                    let g = self.gather_block(sb);
                    let named_wrong = self.error_count() > before;
                    let first = self.surfaces.len();
                    self.claim(
                        &sb.name,
                        SurfaceKind::Faces,
                        g,
                        &sb.at,
                        &mut names,
                        named_wrong,
                    );
                    if sb.contact_type == ContactType::Node && first < self.surfaces.len() {
                        self.make_node_surface(first);
                        self.warn_isolated_nodes(first, &sb.at);
                    }
                    if let Some(parent) = self.surfaces.get(first).cloned() {
                        subset::apply(self, parent, first, sb, &mut names);
                    }
                }
            }
        }
        if let Some(sphere) = &def.restrict_contact_to_subdomain {
            self.restrict(sphere.point, sphere.radius, &def.at);
        }
        self.assign_nodes();
    }

    /// The exterior faces of the whole mesh (less dead elements) whose nodes all lie in
    /// `members`: the faces a contact node set's nodes take their area and normal from.
    /// Of coincident faces (a shell's top and bottom) the first is kept, so an area is
    /// never counted twice.
    fn tributary_faces(&mut self, members: &HashSet<NodeId>) -> Vec<Side> {
        if self.mesh_skin.is_none() {
            let alive: Vec<bool> = (0..self.mesh.num_elems())
                .map(|e| !self.dead.contains(&ElemId(e as u32)))
                .collect();
            self.mesh_skin = Some(skin::exterior_sides(self.mesh, &alive));
        }
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        for &side in self.mesh_skin.as_deref().unwrap_or_default() {
            let mut key: Vec<NodeId> = self.mesh.side_nodes(side).collect();
            // Faces in 3-D (a shell's edges give no area), edges in 2-D.
            let too_small = key.len() < 3 && self.mesh.dim == 3;
            if too_small || !key.iter().all(|n| members.contains(n)) {
                continue;
            }
            key.sort_unstable();
            if seen.insert(key) {
                out.push(side);
            }
        }
        out
    }

    /// Warn about the nodes of node surface `i` that lie on no tributary face: they have
    /// no area and carry no heat, which an analyst should hear about rather than find out.
    fn warn_isolated_nodes(&mut self, i: usize, at: &Loc) {
        let s = &self.surfaces[i];
        let on_face: HashSet<NodeId> = s
            .tributary
            .iter()
            .flat_map(|&side| self.mesh.side_nodes(side))
            .collect();
        let isolated: Vec<NodeId> = s
            .nodes
            .iter()
            .copied()
            .filter(|n| !on_face.contains(n))
            .collect();
        let Some(&first) = isolated.first() else {
            return;
        };
        let message = format!(
            "{} of the {} nodes of node surface `{}` (node {} first) lie on no exterior face whose nodes all belong to the surface: they have no tributary area and carry no heat",
            isolated.len(),
            s.nodes.len(),
            s.name,
            self.mesh.node_number(first)
        );
        self.diags.push(
            Diagnostic::warning("W0308", message)
                .at(Some(at.clone()))
                .help("a node takes its area from the faces around it; name the node set of whole faces, or use a face surface"),
        );
    }

    /// Elements included in the definition: blocks named anywhere, all blocks for
    /// `Skin All Blocks`/`Include All Blocks` (less exclusions), elements listed.
    fn included_elements(&mut self, def: &ContactDefinition) -> Vec<bool> {
        let mut blocks = vec![false; self.mesh.blocks.len()];
        let mut included = vec![false; self.mesh.num_elems()];
        let quiet = Loc::default();
        for cmd in &def.surfaces {
            match cmd {
                SurfaceDef::Contains { contains, .. } => {
                    for name in contains {
                        if let Some(b) = self.mesh.find_block(name) {
                            blocks[b] = true;
                        } else if let Some(a) = self.mesh.find_assembly(name) {
                            for b in self.assembly_blocks(a) {
                                blocks[b] = true;
                            }
                        }
                    }
                }
                SurfaceDef::NodeSet { .. } => {}
                SurfaceDef::SkinAllBlocks { exclude, .. } => {
                    let excluded: HashSet<usize> = exclude
                        .iter()
                        .filter_map(|n| self.mesh.find_block(n))
                        .collect();
                    for (b, flag) in blocks.iter_mut().enumerate() {
                        *flag |= !excluded.contains(&b);
                    }
                }
                SurfaceDef::Block(sb) => {
                    if sb.include_all_blocks {
                        blocks.iter_mut().for_each(|f| *f = true);
                    }
                    for name in &sb.blocks {
                        if let Some(b) = self.mesh.find_block(name) {
                            blocks[b] = true;
                        }
                    }
                    for name in &sb.assemblies {
                        if let Some(a) = self.mesh.find_assembly(name) {
                            for b in self.assembly_blocks(a) {
                                blocks[b] = true;
                            }
                        }
                    }
                    for e in self.resolve_elements(&sb.elements, &|_| quiet.clone(), false) {
                        included[e.index()] = true;
                    }
                }
            }
        }
        for (b, block) in self.mesh.blocks.iter().enumerate() {
            if blocks[b] {
                for e in block.elems() {
                    included[e.index()] = true;
                }
            }
        }
        for e in self.dead {
            if let Some(flag) = included.get_mut(e.index()) {
                *flag = false;
            }
        }
        included
    }

    /// Blocks named by an assembly, following nested assemblies.
    fn assembly_blocks(&self, a: usize) -> Vec<usize> {
        self.assembly_members(a, crate::mesh::AssemblyKind::Blocks, |m, id| {
            m.blocks.iter().position(|b| b.id == id)
        })
    }

    fn assembly_side_sets(&self, a: usize) -> Vec<usize> {
        self.assembly_members(a, crate::mesh::AssemblyKind::SideSets, |m, id| {
            m.side_sets.iter().position(|s| s.id == id)
        })
    }

    fn assembly_members(
        &self,
        a: usize,
        kind: crate::mesh::AssemblyKind,
        find: impl Fn(&Mesh, i64) -> Option<usize> + Copy,
    ) -> Vec<usize> {
        let mut out = Vec::new();
        let mut stack = vec![a];
        let mut seen = HashSet::new();
        while let Some(a) = stack.pop() {
            if !seen.insert(a) {
                continue;
            }
            let asm = &self.mesh.assemblies[a];
            for &id in &asm.members {
                if asm.kind == kind {
                    out.extend(find(self.mesh, id));
                } else if asm.kind == crate::mesh::AssemblyKind::Assemblies {
                    stack.extend(self.mesh.assemblies.iter().position(|x| x.id == id));
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    fn skin_block(&self, b: usize, g: &mut Gathered) {
        let block = &self.mesh.blocks[b];
        let origin = format!("skin of {}", block.sierra_name());
        for e in block.elems() {
            let mask = self.exterior_by_elem[e.index()];
            if mask == 0 {
                continue;
            }
            for s in 0..8u8 {
                if mask & (1 << s) != 0 {
                    g.faces.push((
                        Side {
                            elem: e,
                            side: s + 1,
                        },
                        origin.clone(),
                    ));
                }
            }
        }
    }

    fn add_side_set(&mut self, ss: usize, at: &Loc, g: &mut Gathered) {
        let set = &self.mesh.side_sets[ss];
        let origin = format!("side set {}", set.sierra_name());
        for &side in &set.sides {
            if self.dead.contains(&side.elem) {
                continue;
            }
            let t = self.mesh.topology(side.elem);
            if t.is_shell() && side.side > 2 {
                self.diags.push(
                    Diagnostic::error(
                        "E0306",
                        format!(
                            "side set {} holds edge {} of shell element {}: shell-edge contact is not supported",
                            set.sierra_name(),
                            side.side,
                            self.mesh.elem_number(side.elem)
                        ),
                    )
                    .at(Some(at.clone()))
                    .help("use the shell's faces (sides 1 and 2) or skin the shell block instead"),
                );
                return;
            }
            if t == Topology::Bar2 {
                continue;
            }
            g.faces.push((side, origin.clone()));
        }
    }

    fn gather_contains(&mut self, surface: &str, items: &[String], at: &Loc) -> Gathered {
        let mut g = Gathered::default();
        for name in items {
            if let Some(b) = self.mesh.find_block(name) {
                if self.mesh.blocks[b].topology == Topology::Bar2 {
                    self.warn_beam(b, at);
                }
                self.skin_block(b, &mut g);
            } else if let Some(ss) = self.mesh.find_side_set(name) {
                self.add_side_set(ss, at, &mut g);
            } else if let Some(a) = self.mesh.find_assembly(name) {
                for b in self.assembly_blocks(a) {
                    self.skin_block(b, &mut g);
                }
                for ss in self.assembly_side_sets(a) {
                    self.add_side_set(ss, at, &mut g);
                }
            } else if self.mesh.find_node_set(name).is_some() {
                self.diags.push(
                    Diagnostic::error(
                        "E0302",
                        format!("`{name}` in contact surface `{surface}` is a node set, not a block or side set"),
                    )
                    .at(Some(self.sources.narrow(at, name)))
                    .help(format!("node sets make node surfaces: write `Contact Node Set {surface} Contains {name}`")),
                );
            } else {
                self.unknown_name(name, "block, side set or assembly", at, Names::FaceSources);
            }
        }
        g
    }

    fn gather_node_sets(&mut self, items: &[String], at: &Loc) -> Gathered {
        let mut g = Gathered::default();
        for name in items {
            match self.mesh.find_node_set(name) {
                Some(ns) => {
                    let set = &self.mesh.node_sets[ns];
                    let origin = format!("node set {}", set.sierra_name());
                    g.nodes
                        .extend(set.nodes.iter().map(|&n| (n, origin.clone())));
                }
                None => self.unknown_name(name, "node set", at, Names::NodeSets),
            }
        }
        g
    }

    fn gather_block(&mut self, sb: &SurfaceBlock) -> Gathered {
        let mut g = Gathered::default();
        let at = &sb.at;
        if sb.include_all_blocks {
            for b in 0..self.mesh.blocks.len() {
                self.skin_block(b, &mut g);
            }
        }
        for b in self.resolve_blocks_in(sb, &sb.blocks) {
            self.skin_block(b, &mut g);
        }
        for e in self.resolve_elements_in(sb) {
            let mask = self.exterior_by_elem[e.index()];
            let origin = format!("element {}", self.mesh.elem_number(e));
            for s in 0..8u8 {
                if mask & (1 << s) != 0 {
                    g.faces.push((
                        Side {
                            elem: e,
                            side: s + 1,
                        },
                        origin.clone(),
                    ));
                }
            }
        }
        for name in &sb.side_sets {
            match self.mesh.find_side_set(name) {
                Some(ss) => self.add_side_set(ss, at, &mut g),
                None => self.unknown_name(name, "side set", sb.loc_of(name), Names::SideSets),
            }
        }
        for name in &sb.assemblies {
            match self.mesh.find_assembly(name) {
                Some(a) => {
                    for b in self.assembly_blocks(a) {
                        self.skin_block(b, &mut g);
                    }
                    for ss in self.assembly_side_sets(a) {
                        self.add_side_set(ss, at, &mut g);
                    }
                }
                None => self.unknown_name(name, "assembly", sb.loc_of(name), Names::Assemblies),
            }
        }
        let removed_blocks: HashSet<usize> = self
            .resolve_blocks_in(sb, &sb.remove_blocks)
            .into_iter()
            .collect();
        let mut removed_sides = HashSet::new();
        for name in &sb.remove_surfaces {
            match self.mesh.find_side_set(name) {
                Some(ss) => removed_sides.extend(self.mesh.side_sets[ss].sides.iter().copied()),
                None => self.unknown_name(name, "side set", sb.loc_of(name), Names::SideSets),
            }
        }
        g.faces.retain(|(side, _)| {
            !removed_sides.contains(side)
                && !removed_blocks.contains(&self.mesh.block_of(side.elem))
        });
        g
    }

    /// Blocks named in a surface block, each error pointing at the name.
    fn resolve_blocks_in(&mut self, sb: &SurfaceBlock, names: &[String]) -> Vec<usize> {
        let mut out = Vec::new();
        for name in names {
            match self.mesh.find_block(name) {
                Some(b) => out.push(b),
                None => self.unknown_name(name, "block", sb.loc_of(name), Names::Blocks),
            }
        }
        out
    }

    fn resolve_elements_in(&mut self, sb: &SurfaceBlock) -> Vec<ElemId> {
        self.resolve_elements(&sb.elements, &|n| sb.loc_of(&n.to_string()).clone(), true)
    }

    fn resolve_blocks(&mut self, names: &[String], at: &Loc) -> Vec<usize> {
        let mut out = Vec::new();
        for name in names {
            match self.mesh.find_block(name) {
                Some(b) => out.push(b),
                None => self.unknown_name(name, "block", at, Names::Blocks),
            }
        }
        out
    }

    fn resolve_elements(
        &mut self,
        numbers: &[i64],
        at: &dyn Fn(i64) -> Loc,
        report: bool,
    ) -> Vec<ElemId> {
        if numbers.is_empty() {
            return Vec::new();
        }
        let index: HashMap<i64, u32> = self
            .mesh
            .elem_numbers
            .iter()
            .enumerate()
            .map(|(i, &n)| (n, i as u32))
            .collect();
        let mut out = Vec::new();
        for &n in numbers {
            match index.get(&n) {
                Some(&e) if !self.dead.contains(&ElemId(e)) => out.push(ElemId(e)),
                Some(_) => {}
                None if report => self.diags.push(
                    Diagnostic::error("E0305", format!("element {n} does not exist in the mesh"))
                        .at(Some(at(n)))
                        .help("`Element =` takes element numbers as in the mesh file (its element number map)"),
                ),
                None => {}
            }
        }
        out
    }

    fn error_count(&self) -> usize {
        self.diags.errors().count()
    }

    fn warn_beam(&mut self, b: usize, at: &Loc) {
        self.diags.push(
            Diagnostic::warning(
                "W0303",
                format!(
                    "block {} holds beam elements, which have no faces: it adds nothing to contact surfaces",
                    self.mesh.blocks[b].sierra_name()
                ),
            )
            .at(Some(at.clone()))
            .help("exclude beam blocks (`Exclude` on Skin All Blocks) to silence this"),
        );
    }

    fn unknown_name(&mut self, name: &str, what: &str, at: &Loc, pool: Names) {
        let candidates = self.names(pool);
        let mut d = Diagnostic::error("E0301", format!("unknown {what} `{name}`"))
            .at(Some(self.sources.narrow(at, name)));
        d = match did_you_mean(name, candidates.iter().map(String::as_str)) {
            Some(s) => d.help(format!("did you mean `{s}`?")),
            None if candidates.is_empty() => d.help(format!("the mesh has no {what}s")),
            None => d.help(format!("the mesh has: {}", list_names(&candidates))),
        };
        self.diags.push(d);
    }

    fn names(&self, pool: Names) -> Vec<String> {
        let m = self.mesh;
        let blocks = || m.blocks.iter().map(|b| b.sierra_name());
        let side_sets = || m.side_sets.iter().map(|s| s.sierra_name());
        let assemblies = || m.assemblies.iter().map(|a| a.name.to_ascii_lowercase());
        match pool {
            Names::Blocks => blocks().collect(),
            Names::SideSets => side_sets().collect(),
            Names::NodeSets => m.node_sets.iter().map(|s| s.sierra_name()).collect(),
            Names::Assemblies => assemblies().collect(),
            Names::FaceSources => blocks().chain(side_sets()).chain(assemblies()).collect(),
        }
    }

    /// Turn gathered faces into a surface, honouring ownership, and append it.
    fn claim(
        &mut self,
        name: &str,
        kind: SurfaceKind,
        g: Gathered,
        at: &Loc,
        names: &mut HashMap<String, Loc>,
        named_wrong: bool,
    ) {
        let name = name.to_ascii_lowercase();
        if let Some(first) = names.get(&name) {
            let where_first = if first.is_unknown() {
                String::new()
            } else {
                format!(" (first at {first})")
            };
            self.diags.push(
                Diagnostic::error("E0304", format!("contact surface `{name}` is defined twice{where_first}"))
                    .at(Some(at.clone()))
                    .help("give each surface its own name; `Skin All Blocks` names its surfaces after the blocks"),
            );
            return;
        }
        names.insert(name.clone(), at.clone());
        let index = self.surfaces.len() as u32;
        let candidates = !g.faces.is_empty() || !g.nodes.is_empty();
        let mut skipped: BTreeMap<u32, usize> = BTreeMap::new();
        let mut origins: Vec<(String, usize)> = Vec::new();
        let mut faces = Vec::new();
        let mut nodes = Vec::new();
        let mut seen = HashSet::new();
        let bump = |origins: &mut Vec<(String, usize)>, o: String| -> u32 {
            match origins.iter().position(|x| x.0 == o) {
                Some(i) => {
                    origins[i].1 += 1;
                    i as u32
                }
                None => {
                    origins.push((o, 1));
                    origins.len() as u32 - 1
                }
            }
        };
        for (side, origin) in g.faces {
            if !seen.insert(side) {
                continue;
            }
            match self.face_owner.get(&side) {
                Some(&owner) => *skipped.entry(owner).or_default() += 1,
                None => {
                    self.face_owner.insert(side, index);
                    let loft = self.loft(side);
                    let origin = bump(&mut origins, origin);
                    faces.push(SurfaceFace { side, loft, origin });
                }
            }
        }
        for (node, origin) in g.nodes {
            let owner = &mut self.node_owner[node.index()];
            if *owner == index {
                continue;
            }
            if *owner != u32::MAX {
                *skipped.entry(*owner).or_default() += 1;
                continue;
            }
            *owner = index;
            nodes.push(node);
            bump(&mut origins, origin);
        }
        faces.sort_by_key(|f| f.side);
        nodes.sort_unstable();
        let unit = if kind == SurfaceKind::Faces {
            "faces"
        } else {
            "nodes"
        };
        for (&owner, &count) in &skipped {
            let owner_name = &self.surfaces[owner as usize].name;
            self.diags.push(
                Diagnostic::warning(
                    "W0301",
                    format!("{count} {unit} of contact surface `{name}` already belong to `{owner_name}`, defined earlier; they stay with `{owner_name}`"),
                )
                .at(Some(at.clone()))
                .help("a face or node belongs to the first surface that includes it; reorder the definitions to change the owner"),
            );
        }
        let empty = faces.is_empty() && nodes.is_empty();
        if empty && candidates {
            self.diags.push(
                Diagnostic::warning("W0302", format!("contact surface `{name}` is empty: every one of its {unit} belongs to an earlier surface"))
                    .at(Some(at.clone()))
                    .help("this is the ownership rule at work; drop the definition or move it earlier"),
            );
        } else if empty && !named_wrong {
            // (When a name in the command was wrong, that error already explains it.)
            self.diags.push(
                Diagnostic::error("E0303", format!("contact surface `{name}` is empty"))
                    .at(Some(at.clone()))
                    .help("its blocks have no exterior faces, or its side sets/node sets are empty (or hold only dead elements); check the names it contains"),
            );
        }
        self.surfaces.push(ContactSurface {
            name,
            kind,
            faces,
            tributary: Vec::new(),
            nodes,
            origins,
            parent: None,
        });
    }

    /// Half the shell thickness along the face normal, for shell faces.
    fn loft(&self, side: Side) -> f64 {
        let block = &self.mesh.blocks[self.mesh.block_of(side.elem)];
        match (block.topology.is_shell(), block.thickness) {
            (true, Some(t)) => 0.5 * t,
            _ => 0.0,
        }
    }

    fn make_node_surface(&mut self, i: usize) {
        let s = &mut self.surfaces[i];
        if s.kind == SurfaceKind::Nodes {
            return;
        }
        let mut nodes: Vec<NodeId> = s
            .faces
            .iter()
            .flat_map(|f| self.mesh.side_nodes(f.side))
            .collect();
        nodes.sort_unstable();
        nodes.dedup();
        for f in s.faces.drain(..) {
            self.face_owner.remove(&f.side);
            s.tributary.push(f.side);
        }
        let index = i as u32;
        nodes.retain(|n| {
            let owner = &mut self.node_owner[n.index()];
            if *owner == u32::MAX || *owner == index {
                *owner = index;
                true
            } else {
                false
            }
        });
        s.nodes = nodes;
        s.kind = SurfaceKind::Nodes;
    }

    fn restrict(&mut self, point: [f64; 3], radius: f64, at: &Loc) {
        let inside = |p: Vec3| {
            let d = geometry::sub(p, point);
            geometry::dot(d, d) <= radius * radius
        };
        let mesh = self.mesh;
        for s in &mut self.surfaces {
            let before = s.faces.len() + s.nodes.len();
            s.faces.retain(|f| {
                let nodes: Vec<NodeId> = mesh.side_nodes(f.side).collect();
                inside(centroid(mesh, &nodes))
            });
            if s.kind == SurfaceKind::Nodes {
                s.nodes.retain(|n| inside(mesh.coords[n.index()]));
            }
            if before > 0 && s.faces.is_empty() && s.nodes.is_empty() {
                self.diags.push(
                    Diagnostic::warning("W0307", format!("contact surface `{}` lies wholly outside the subdomain sphere and takes no part", s.name))
                        .at(Some(at.clone()))
                        .help("check `Restrict Contact To Subdomain Defined By Radius … And Point …`"),
                );
            }
        }
    }

    /// Give every node of a face surface to the first surface (in order) that has it.
    fn assign_nodes(&mut self) {
        // Face surfaces share nodes among themselves only; node surfaces have their own
        // ownership, settled as they were claimed.
        let mut owner_of = vec![u32::MAX; self.mesh.num_nodes()];
        for (i, s) in self.surfaces.iter_mut().enumerate() {
            if s.kind != SurfaceKind::Faces {
                continue;
            }
            let mut nodes: Vec<NodeId> = s
                .faces
                .iter()
                .flat_map(|f| self.mesh.side_nodes(f.side))
                .collect();
            nodes.sort_unstable();
            nodes.dedup();
            let index = i as u32;
            nodes.retain(|n| {
                let owner = &mut owner_of[n.index()];
                if *owner == u32::MAX {
                    *owner = index;
                }
                *owner == index
            });
            s.nodes = nodes;
        }
    }
}

#[derive(Clone, Copy)]
enum Names {
    Blocks,
    SideSets,
    NodeSets,
    Assemblies,
    FaceSources,
}

fn list_names(names: &[String]) -> String {
    const SHOWN: usize = 12;
    let mut s = names
        .iter()
        .take(SHOWN)
        .map(|n| format!("`{n}`"))
        .collect::<Vec<_>>()
        .join(", ");
    if names.len() > SHOWN {
        s.push_str(&format!(" and {} more", names.len() - SHOWN));
    }
    s
}
