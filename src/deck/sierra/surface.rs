//! `begin Contact Surface`: a surface block with its subsets and automatic subsets.

use std::collections::HashSet;

use crate::deck::codes;
use crate::deck::spec::*;
use crate::deck::tree::Block;
use crate::diag::{Diagnostic, did_you_mean};

use super::{CS, Lower, value_text};

impl Lower {
    pub(super) fn surface_block(&mut self, d: usize, s: usize, b: &Block) -> SurfaceBlock {
        let mut x = SurfaceBlock {
            name: self.block_name(b).unwrap_or_default(),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        if let Some(t) = b.name.first() {
            self.locs
                .set(format!("{d}.surface.{s}.name"), t.loc(&self.file));
        }
        let mut seen = HashSet::new();
        for mut c in self.commands(b, CS) {
            let line = c.line;
            let at = self.line_loc(line);
            match c.cmd.key {
                "include_all_blocks" => {
                    self.once(&mut seen, &c);
                    x.include_all_blocks = true;
                }
                "block" | "surface" | "assembly" | "remove_block" | "remove_surface" => {
                    c.skip_sep();
                    let what = if c.cmd.key.ends_with("block") {
                        "block names"
                    } else if c.cmd.key == "assembly" {
                        "assembly names"
                    } else {
                        "side set names"
                    };
                    let first = c.pos;
                    let v = self.names(&mut c, what);
                    for t in c.line.tokens.get(first..c.pos).unwrap_or_default() {
                        if !t.is_sep() {
                            x.name_locs.push((value_text(t), t.loc(&self.file)));
                        }
                    }
                    let list = match c.cmd.key {
                        "block" => &mut x.blocks,
                        "surface" => &mut x.side_sets,
                        "assembly" => &mut x.assemblies,
                        "remove_block" => &mut x.remove_blocks,
                        _ => &mut x.remove_surfaces,
                    };
                    list.extend(v);
                }
                "element" => {
                    c.skip_sep();
                    if c.peek().is_none() {
                        self.missing(&c, "element numbers");
                    }
                    while c.peek().is_some() {
                        let before = c.pos;
                        if let Some((v, l)) = self.integer(&mut c, "element numbers (integers)") {
                            x.elements.push(v);
                            x.name_locs.push((v.to_string(), l));
                        }
                        c.pass_reported(before);
                    }
                }
                "subset" => {
                    let k = x.subsets.len();
                    let Some((name, _)) = self.name(&mut c, "a subset name") else {
                        continue;
                    };
                    if !(self.keyword(&mut c, "with") && self.keyword(&mut c, "normal")) {
                        continue;
                    }
                    c.skip_sep();
                    let (v, v_at) = self.numbers(&mut c, "a normal component");
                    match <[f64; 3]>::try_from(v.as_slice()) {
                        Ok(normal) => {
                            if let Some(a) = v_at {
                                self.locs
                                    .set(format!("{d}.surface.{s}.subset.{k}.normal"), a);
                            }
                            x.subsets.push(Subset { name, normal, at });
                        }
                        Err(_) if v_at.is_none() => self.missing(&c, "a normal `nx ny nz`"),
                        Err(_) => self.push(
                            Diagnostic::error(
                                codes::VALUE_COUNT,
                                format!("a subset normal needs 3 components, found {}", v.len()),
                            )
                            .at(v_at)
                            .help(c.usage()),
                        ),
                    }
                }
                "auto_subset" => {
                    if x.auto_subset.is_some() {
                        let n = c.n;
                        self.push(
                            Diagnostic::error(
                                codes::SECOND_AUTO_SUBSET,
                                format!("a second `auto subset` in contact surface `{}`", x.name),
                            )
                            .at(self.span(line.tokens.get(..n).unwrap_or_default()))
                            .help("one `auto subset` line per contact surface; use `number of subsets` to get more"),
                        );
                        continue;
                    }
                    let Some((name, _)) = self.name(&mut c, "a subset name") else {
                        continue;
                    };
                    let mut a = AutoSubset {
                        name,
                        number_of_subsets: None,
                        angle: None,
                        at,
                    };
                    while let Some(t) = c.peek() {
                        match t.lower.as_str() {
                            "number" => {
                                c.pos += 1;
                                if !(self.keyword(&mut c, "of") && self.keyword(&mut c, "subsets"))
                                {
                                    break;
                                }
                                c.skip_sep();
                                match self.count(&mut c, "a whole number of subsets") {
                                    Some((n, l)) => {
                                        a.number_of_subsets = Some(n);
                                        self.locs.set(
                                            format!(
                                                "{d}.surface.{s}.auto_subset.number_of_subsets"
                                            ),
                                            l,
                                        );
                                    }
                                    None => break,
                                }
                            }
                            "angle" => {
                                c.pos += 1;
                                c.skip_sep();
                                match self.number(&mut c, "an angle in degrees") {
                                    Some((v, l)) => {
                                        a.angle = Some(v);
                                        self.locs
                                            .set(format!("{d}.surface.{s}.auto_subset.angle"), l);
                                    }
                                    None => break,
                                }
                            }
                            _ => break,
                        }
                    }
                    x.auto_subset = Some(a);
                }
                "contact_type" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some(t) = c.bump() {
                        match t.lower.as_str() {
                            // Sierra/SM's `standard` (its default) is seam's face contact.
                            "face" | "standard" => x.contact_type = ContactType::Face,
                            "node" => x.contact_type = ContactType::Node,
                            "smooth" => self.push(
                                Diagnostic::error(
                                    codes::CONTACT_TYPE,
                                    "seam does not smooth contact surfaces (`contact type = smooth`)",
                                )
                                .at(Some(t.loc(&self.file)))
                                .help("write `contact type = standard` (or `face`): seam pairs the mesh's own faces"),
                            ),
                            other => {
                                let hint = did_you_mean(other, ["face", "node"])
                                    .map(|s| format!("did you mean `{s}`? "))
                                    .unwrap_or_default();
                                self.push(
                                    Diagnostic::error(
                                        codes::CONTACT_TYPE,
                                        format!("unknown contact type `{}`", t.text),
                                    )
                                    .at(Some(t.loc(&self.file)))
                                    .help(format!(
                                        "{hint}write `contact type = face` or `contact type = node`"
                                    )),
                                );
                            }
                        }
                    } else {
                        self.missing(&c, "`face` or `node`");
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        x
    }
}
