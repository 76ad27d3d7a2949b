//! Splitting a surface into subsets: `Subset … With Normal` and `Auto Subset`.
//!
//! `Subset n With Normal v`: faces of the parent whose unit normal n̂ has n̂·v̂ > 0.45
//! (about 63°) move to `<parent>_<n>`; subsets are taken in deck order, a face goes to
//! the first that matches.
//!
//! `Auto Subset n [Number Of Subsets k] [Angle a]` (a defaults to 60°, k to ⌊360/a⌋):
//! starting from the parent's lowest face not yet grouped, a group grows over faces
//! sharing an edge (a node in 2-D) whose normals differ from the seed face's normal by
//! less than `a`. Groups are numbered in the order of their lowest face, which names
//! them `<parent>_<n>_auto_<k>`; groups beyond the k-th stay in the parent, with a
//! warning. Comparing with the seed rather than with the neighbour keeps a group's
//! normals within `a` of each other's seed even on a finely faceted curved surface.

use std::collections::{HashMap, VecDeque};

use super::Builder;
use crate::deck::spec::SurfaceBlock;
use crate::diag::{Diagnostic, Loc};
use crate::mesh::NodeId;
use crate::surface::geometry::dot;
use crate::surface::{ContactSurface, SurfaceFace, face_normal};

/// Threshold on n̂·v̂ for `Subset … With Normal` (Sierra/SM).
const SUBSET_NORMAL_DOT: f64 = 0.45;
const DEFAULT_AUTO_ANGLE_DEG: f64 = 60.0;

pub(super) fn apply(
    b: &mut Builder<'_>,
    parent: ContactSurface,
    index: usize,
    sb: &SurfaceBlock,
    names: &mut HashMap<String, Loc>,
) {
    if parent.faces.is_empty() {
        return;
    }
    let mut remaining = parent.faces.clone();
    let mut made: Vec<(String, Vec<SurfaceFace>, String, Loc)> = Vec::new();
    for sub in &sb.subsets {
        let len = dot(sub.normal, sub.normal).sqrt();
        if len == 0.0 {
            continue; // the deck checks reject a zero normal
        }
        let v = sub.normal.map(|c| c / len);
        let (taken, kept): (Vec<SurfaceFace>, Vec<SurfaceFace>) = remaining
            .into_iter()
            .partition(|f| dot(face_normal(b.mesh, f.side), v) > SUBSET_NORMAL_DOT);
        remaining = kept;
        let name = format!("{}_{}", parent.name, sub.name.to_ascii_lowercase());
        if taken.is_empty() {
            b.diags.push(
                Diagnostic::warning(
                    "W0305",
                    format!(
                        "subset `{}` of contact surface `{}` matches no face (normal {} {} {})",
                        sub.name, parent.name, sub.normal[0], sub.normal[1], sub.normal[2]
                    ),
                )
                .at(Some(sub.at.clone()))
                .help("a face joins when its unit normal has a dot product > 0.45 with the given direction"),
            );
        }
        let origin = format!("subset of {} with normal", parent.name);
        made.push((name, taken, origin, sub.at.clone()));
    }
    if let Some(auto) = &sb.auto_subset {
        let angle = auto.angle.unwrap_or(DEFAULT_AUTO_ANGLE_DEG);
        if angle > 0.0 {
            let wanted = auto
                .number_of_subsets
                .map_or((360.0 / angle).floor() as usize, |n| n as usize);
            let groups = group_by_normal(b, &remaining, angle);
            let total = groups.len();
            let mut keep = Vec::new();
            for (k, group) in groups.into_iter().enumerate() {
                if k < wanted {
                    let name = format!(
                        "{}_{}_auto_{}",
                        parent.name,
                        auto.name.to_ascii_lowercase(),
                        k + 1
                    );
                    let origin = format!("auto subset of {}", parent.name);
                    made.push((name, group, origin, auto.at.clone()));
                } else {
                    keep.extend(group);
                }
            }
            if total > wanted {
                b.diags.push(
                    Diagnostic::warning(
                        "W0304",
                        format!(
                            "auto subset `{}` of contact surface `{}` found {total} groups but {wanted} were asked for; the faces of the other {} stay in `{}`",
                            auto.name,
                            parent.name,
                            total - wanted,
                            parent.name
                        ),
                    )
                    .at(Some(auto.at.clone()))
                    .help(format!("raise `Number Of Subsets` to {total} or widen `Angle` to group them")),
                );
            }
            keep.sort_by_key(|f| f.side);
            remaining = keep;
        }
    }
    if made.is_empty() {
        return;
    }
    if remaining.is_empty() {
        b.diags.push(
            Diagnostic::warning(
                "W0306",
                format!(
                    "every face of contact surface `{}` moved into its subsets; `{}` itself is empty",
                    parent.name, parent.name
                ),
            )
            .at(Some(sb.at.clone()))
            .help("refer to the subsets by name in interactions"),
        );
    }
    recount_origins(&mut b.surfaces[index], remaining);
    for (name, faces, origin, at) in made {
        if let Some(first) = names.get(&name) {
            b.diags.push(
                Diagnostic::error(
                    "E0304",
                    format!("contact surface `{name}` is defined twice (first at {first})"),
                )
                .at(Some(at))
                .help(
                    "subset names are `<surface>_<subset>`: rename the subset or the other surface",
                ),
            );
            continue;
        }
        names.insert(name.clone(), at);
        let new_index = b.surfaces.len() as u32;
        let mut faces = faces;
        for f in &mut faces {
            b.face_owner.insert(f.side, new_index);
            f.origin = 0;
        }
        let count = faces.len();
        b.surfaces.push(ContactSurface {
            name,
            kind: super::SurfaceKind::Faces,
            faces,
            tributary: Vec::new(),
            nodes: Vec::new(),
            origins: vec![(origin, count)],
            parent: Some(parent.name.clone()),
        });
    }
}

/// Give `surface` the faces it keeps, and count its origins again over them.
fn recount_origins(surface: &mut ContactSurface, mut faces: Vec<SurfaceFace>) {
    let mut counts = vec![0usize; surface.origins.len()];
    for f in &faces {
        counts[f.origin as usize] += 1;
    }
    let mut remap = vec![0u32; counts.len()];
    let mut origins = Vec::new();
    for (i, (name, _)) in surface.origins.drain(..).enumerate() {
        if counts[i] > 0 {
            remap[i] = origins.len() as u32;
            origins.push((name, counts[i]));
        }
    }
    for f in &mut faces {
        f.origin = remap[f.origin as usize];
    }
    surface.origins = origins;
    surface.faces = faces;
}

/// Groups of edge-connected faces whose normals lie within `angle_deg` of their seed's.
fn group_by_normal(
    b: &Builder<'_>,
    faces: &[SurfaceFace],
    angle_deg: f64,
) -> Vec<Vec<SurfaceFace>> {
    let mesh = b.mesh;
    let cos_limit = angle_deg.to_radians().cos();
    let normals: Vec<[f64; 3]> = faces.iter().map(|f| face_normal(mesh, f.side)).collect();
    // Connection keys: edges (sorted node pairs) of faces, nodes of 2-D edge faces.
    let mut by_key: HashMap<(NodeId, NodeId), Vec<usize>> = HashMap::new();
    for (i, f) in faces.iter().enumerate() {
        let nodes: Vec<NodeId> = mesh.side_nodes(f.side).collect();
        if nodes.len() == 2 {
            for &n in &nodes {
                by_key.entry((n, n)).or_default().push(i);
            }
        } else {
            for k in 0..nodes.len() {
                let (p, q) = (nodes[k], nodes[(k + 1) % nodes.len()]);
                by_key.entry((p.min(q), p.max(q))).or_default().push(i);
            }
        }
    }
    let mut group_of = vec![usize::MAX; faces.len()];
    let mut groups = Vec::new();
    for seed in 0..faces.len() {
        if group_of[seed] != usize::MAX {
            continue;
        }
        let g = groups.len();
        let mut members = vec![seed];
        group_of[seed] = g;
        let mut queue = VecDeque::from([seed]);
        while let Some(i) = queue.pop_front() {
            let nodes: Vec<NodeId> = mesh.side_nodes(faces[i].side).collect();
            let keys: Vec<(NodeId, NodeId)> = if nodes.len() == 2 {
                nodes.iter().map(|&n| (n, n)).collect()
            } else {
                (0..nodes.len())
                    .map(|k| {
                        let (p, q) = (nodes[k], nodes[(k + 1) % nodes.len()]);
                        (p.min(q), p.max(q))
                    })
                    .collect()
            };
            for key in keys {
                for &j in &by_key[&key] {
                    // "Differ by less than the angle": strictly inside the cone.
                    if group_of[j] == usize::MAX && dot(normals[j], normals[seed]) > cos_limit {
                        group_of[j] = g;
                        members.push(j);
                        queue.push_back(j);
                    }
                }
            }
        }
        members.sort_unstable();
        groups.push(members.into_iter().map(|i| faces[i]).collect());
    }
    groups
}
