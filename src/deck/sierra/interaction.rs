//! `begin Interaction`, `begin Interaction Defaults` and `begin Search Options`, and the
//! line commands of a block.

use std::collections::HashSet;

use crate::deck::spec::*;
use crate::deck::tree::{Block, Item};

use super::{Cur, DEF, INT, Lower, Matched, SO};

impl Lower {
    /// The recognised line commands of block `b` (of type `key`), in order; sub-blocks
    /// that may not appear there and unrecognised lines are reported on the way.
    pub(super) fn commands<'b>(&mut self, b: &'b Block, key: &'static str) -> Vec<Cur<'b>> {
        let mut out = Vec::new();
        for item in &b.items {
            match item {
                Item::Block(sub) => self.misplaced(sub, key),
                Item::Line(line) => {
                    if let Matched::Command(c) = self.command(key, line) {
                        out.push(c);
                    }
                }
            }
        }
        out
    }

    pub(super) fn interaction(&mut self, d: usize, i: usize, b: &Block) -> Interaction {
        let mut x = Interaction {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for mut c in self.commands(b, INT) {
            c.skip_sep();
            match c.cmd.key {
                "side_a" => x.side_a.extend(self.names(&mut c, "surface names")),
                "side_b" => x.side_b.extend(self.names(&mut c, "surface names")),
                "surfaces" => x.surfaces.extend(self.names(&mut c, "surface names")),
                "normal_tolerance" => {
                    self.once(&mut seen, &c);
                    if let Some((v, at)) = self.number(&mut c, "a distance") {
                        x.normal_tolerance = Some(v);
                        self.locs
                            .set(format!("{d}.interaction.{i}.normal_tolerance"), at);
                    }
                }
                "enforcement" => {
                    self.once(&mut seen, &c);
                    if let Some((v, at)) = self.name(&mut c, "an enforcement name") {
                        x.enforcement = Some(v);
                        self.locs
                            .set(format!("{d}.interaction.{i}.enforcement"), at);
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        x
    }

    pub(super) fn defaults(&mut self, d: usize, b: &Block) -> InteractionDefaults {
        self.block_name(b);
        let mut x = InteractionDefaults {
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for mut c in self.commands(b, DEF) {
            c.skip_sep();
            match c.cmd.key {
                "general_contact" => {
                    self.once(&mut seen, &c);
                    x.general_contact = self.flag(&mut c);
                }
                "self_contact" => {
                    self.once(&mut seen, &c);
                    x.self_contact = self.flag(&mut c);
                }
                "surfaces" => x.surfaces.extend(self.names(&mut c, "surface names")),
                "enforcement" => {
                    self.once(&mut seen, &c);
                    if let Some((v, at)) = self.name(&mut c, "an enforcement name") {
                        x.enforcement = Some(v);
                        self.locs
                            .set(format!("{d}.interaction_defaults.enforcement"), at);
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        x
    }

    pub(super) fn search_options(&mut self, d: usize, b: &Block) -> SearchOptions {
        let mut x = SearchOptions {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for mut c in self.commands(b, SO) {
            c.skip_sep();
            self.once(&mut seen, &c);
            let key = c.cmd.key;
            match key {
                "self_contact" => x.self_contact = self.flag(&mut c),
                "search_update_frequency" => {
                    x.search_update_frequency =
                        self.count(&mut c, "a whole number of steps")
                            .map(|(n, at)| {
                                self.locs.set(format!("{d}.search_options.{key}"), at);
                                n
                            });
                }
                _ => {
                    let what = if key.ends_with("angle") {
                        "an angle in degrees"
                    } else if key.ends_with("tolerance") {
                        "a distance"
                    } else {
                        "a number"
                    };
                    if let Some((v, at)) = self.number(&mut c, what) {
                        let slot = match key {
                            "normal_tolerance" => &mut x.normal_tolerance,
                            "tangential_tolerance" => &mut x.tangential_tolerance,
                            "buffer_factor" => &mut x.buffer_factor,
                            "field_factor" => &mut x.field_factor,
                            _ => &mut x.normal_check_angle,
                        };
                        *slot = Some(v);
                        self.locs.set(format!("{d}.search_options.{key}"), at);
                    }
                }
            }
            self.finish(&c);
        }
        x
    }
}
