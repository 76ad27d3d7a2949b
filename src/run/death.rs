//! `[[death]]`: blocks or elements that die at a time, checked on the mesh into one
//! death time per element.

use std::collections::HashSet;

use crate::diag::{Diagnostic, Diagnostics, did_you_mean};
use crate::mesh::{ElemId, Mesh};

use super::problem::{DeathSpec, ProblemText};

/// The death of a run's elements.
pub(super) struct Death {
    /// Per mesh element the time from which it is dead (∞: never).
    pub times: Vec<f64>,
}

impl Death {
    /// The `[[death]]` entries on `mesh`, or `None` without any; errors (`E0732`) at
    /// their line.
    pub(super) fn new(
        specs: &[DeathSpec],
        mesh: &Mesh,
        transient: bool,
        text: &ProblemText,
        diags: &mut Diagnostics,
    ) -> Option<Death> {
        if specs.is_empty() {
            return None;
        }
        let mut times = vec![f64::INFINITY; mesh.num_elems()];
        let numbers: std::collections::HashMap<i64, usize> = (mesh.elem_numbers.iter())
            .enumerate()
            .map(|(k, &n)| (n, k))
            .collect();
        let mut fine = true;
        for (k, d) in specs.iter().enumerate() {
            let mut error = |key: &str, message: String, help: String| {
                fine = false;
                diags.push(
                    Diagnostic::error("E0732", format!("[[death]] #{}: {message}", k + 1))
                        .at(text.loc("death", k, key))
                        .help(help),
                );
            };
            if !transient {
                error(
                    "time",
                    "element death needs a transient run".into(),
                    "give [solve] kind = \"transient\", or remove the [[death]]".into(),
                );
                continue;
            }
            if !d.time.is_finite() {
                error(
                    "time",
                    format!("time = {} is not a finite time", d.time),
                    "give the time in s from which the elements are dead".into(),
                );
                continue;
            }
            if d.blocks.is_empty() && d.elements.is_empty() {
                error(
                    "",
                    "names no blocks and no elements".into(),
                    "give blocks = [\"name\"] or elements = [number, …]".into(),
                );
                continue;
            }
            let mut dying: Vec<usize> = Vec::new();
            for name in &d.blocks {
                match mesh.find_block(name) {
                    Some(b) => dying.extend(mesh.blocks[b].elems().map(|e| e.index())),
                    None => {
                        let names: Vec<String> =
                            mesh.blocks.iter().map(|b| b.sierra_name()).collect();
                        error(
                            "blocks",
                            format!("no block `{name}` in the mesh"),
                            match did_you_mean(name, names.iter().map(String::as_str)) {
                                Some(close) => format!("did you mean `{close}`?"),
                                None => format!("the blocks are {}", names.join(", ")),
                            },
                        );
                    }
                }
            }
            for &n in &d.elements {
                match numbers.get(&n) {
                    Some(&e) => dying.push(e),
                    None => error(
                        "elements",
                        format!("no element numbered {n} in the mesh"),
                        "give the elements by their numbers in the mesh file".into(),
                    ),
                }
            }
            for e in dying {
                times[e] = times[e].min(d.time);
            }
        }
        fine.then_some(Death { times })
    }

    /// The elements dead at `t`.
    pub(super) fn dead_at(&self, t: f64) -> HashSet<ElemId> {
        (self.times.iter().enumerate())
            .filter(|(_, td)| **td <= t)
            .map(|(e, _)| ElemId(e as u32))
            .collect()
    }
}
