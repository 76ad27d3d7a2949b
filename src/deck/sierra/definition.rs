//! `begin Contact Definition`: its blocks and lines, control assignments and periodic
//! conditions.

use std::collections::HashSet;

use crate::deck::codes;
use crate::deck::lexer::Token;
use crate::deck::spec::*;
use crate::deck::tree::{Block, Item};
use crate::diag::{Diagnostic, Loc, did_you_mean};

use super::{CD, CS, Cur, DEF, ENF, INT, Lower, Matched, SO, is_toggle_block, parse_number};

impl Lower {
    pub(super) fn definition(&mut self, d: usize, b: &Block) -> ContactDefinition {
        let mut cd = ContactDefinition {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        for item in &b.items {
            match item {
                Item::Block(sub) => self.definition_block(d, &mut cd, sub),
                Item::Line(line) => {
                    if let Matched::Command(mut c) = self.command(CD, line) {
                        self.definition_line(d, &mut cd, &mut c, &mut seen);
                        self.finish(&c);
                    }
                }
            }
        }
        cd
    }

    pub(super) fn definition_block(&mut self, d: usize, cd: &mut ContactDefinition, sub: &Block) {
        let Some(spec) = sub.spec else {
            if is_toggle_block(sub) {
                self.toggle_block(sub, None);
            } else {
                self.unknown_tree(sub);
            }
            return;
        };
        if spec.parent != CD {
            self.misplaced(sub, CD);
            return;
        }
        let twice = |what: &str, l: &mut Lower| {
            l.push(
                Diagnostic::error(
                    codes::DUPLICATE_BLOCK,
                    format!("a second `begin {what}` in one contact definition"),
                )
                .at(l.span(sub.type_tokens()))
                .help("merge the two blocks into one"),
            );
        };
        match spec.key {
            ENF => {
                let k = cd.enforcements.len();
                let e = self.enforcement(d, k, sub);
                cd.enforcements.push(e);
            }
            INT => {
                let i = cd.interactions.len();
                let x = self.interaction(d, i, sub);
                cd.interactions.push(x);
            }
            DEF => {
                let x = self.defaults(d, sub);
                if cd.interaction_defaults.is_some() {
                    twice(spec.phrase, self);
                } else {
                    cd.interaction_defaults = Some(x);
                }
            }
            SO => {
                let x = self.search_options(d, sub);
                if cd.search_options.is_some() {
                    twice(spec.phrase, self);
                } else {
                    cd.search_options = Some(x);
                }
            }
            CS => {
                let s = cd.surfaces.len();
                let x = self.surface_block(d, s, sub);
                cd.surfaces.push(SurfaceDef::Block(x));
            }
            _ => self.misplaced(sub, CD),
        }
    }

    pub(super) fn definition_line(
        &mut self,
        d: usize,
        cd: &mut ContactDefinition,
        c: &mut Cur,
        seen: &mut HashSet<&'static str>,
    ) {
        let at = self.line_loc(c.line);
        match c.cmd.key {
            "contact_surface" | "contact_node_set" => {
                let Some((name, name_at)) = self.name(c, "a surface name") else {
                    return;
                };
                // Without `contains`, the mesh entity of the surface's own name.
                let contains = if c.peek().is_none() {
                    vec![name.clone()]
                } else {
                    if !self.keyword(c, "contains") {
                        return;
                    }
                    c.skip_sep();
                    self.names(c, "the names it contains")
                };
                self.locs
                    .set(format!("{d}.surface.{}.name", cd.surfaces.len()), name_at);
                cd.surfaces.push(if c.cmd.key == "contact_surface" {
                    SurfaceDef::Contains { name, contains, at }
                } else {
                    SurfaceDef::NodeSet { name, contains, at }
                });
            }
            "skin_all_blocks" => {
                c.skip_sep();
                // Alone, or with `exclude` only, as the Aria manual writes it: on.
                let on = match c.peek() {
                    None => true,
                    Some(t) if t.is_word() && t.lower == "exclude" => true,
                    Some(_) => match self.switch(c) {
                        Some(on) => on,
                        None => return,
                    },
                };
                let mut exclude = Vec::new();
                if c.peek().is_some_and(|t| t.lower == "exclude") {
                    c.pos += 1;
                    c.skip_sep();
                    exclude = self.names(c, "the blocks to exclude");
                }
                if on {
                    cd.surfaces.push(SurfaceDef::SkinAllBlocks { exclude, at });
                }
            }
            "restrict_contact_to_subdomain" => {
                self.once(seen, c);
                if !(self.keyword(c, "defined")
                    && self.keyword(c, "by")
                    && self.keyword(c, "radius"))
                {
                    return;
                }
                c.skip_sep();
                let Some((radius, radius_at)) = self.number(c, "a radius") else {
                    return;
                };
                self.locs.set(
                    format!("{d}.restrict_contact_to_subdomain.radius"),
                    radius_at,
                );
                if !(self.keyword(c, "and") && self.keyword(c, "point")) {
                    return;
                }
                c.skip_sep();
                let (p, p_at) = self.numbers(c, "a coordinate");
                if let Some(l) = &p_at {
                    self.locs.set(
                        format!("{d}.restrict_contact_to_subdomain.point"),
                        l.clone(),
                    );
                }
                match <[f64; 3]>::try_from(p.as_slice()) {
                    Ok(point) => {
                        cd.restrict_contact_to_subdomain = Some(Subdomain { radius, point })
                    }
                    Err(_) if p_at.is_none() => self.missing(c, "a point `x y z`"),
                    Err(_) => self.push(
                        Diagnostic::error(
                            codes::VALUE_COUNT,
                            format!("the subdomain point needs 3 coordinates, found {}", p.len()),
                        )
                        .at(p_at)
                        .help(c.usage()),
                    ),
                }
            }
            "visualize_contact" => {
                self.once(seen, c);
                c.skip_sep();
                cd.visualize_contact = if c.peek().is_some() {
                    self.switch(c).unwrap_or(false)
                } else {
                    true
                };
            }
            "output_rule" => {
                self.once(seen, c);
                c.skip_sep();
                let rest = c.rest();
                c.pos = c.line.tokens.len();
                let words: Vec<String> = rest.iter().map(|t| t.lower.replace('_', " ")).collect();
                let value = words.join(" ");
                let rule = match value.as_str() {
                    "none" => Some(OutputRule::None),
                    "summary" => Some(OutputRule::Summary),
                    "verbose" => Some(OutputRule::Verbose),
                    "more verbose" => Some(OutputRule::MoreVerbose),
                    _ => None,
                };
                match rule {
                    Some(r) => cd.output_rule = Some(r),
                    None if rest.is_empty() => self.missing(c, "a rule"),
                    None => {
                        let choices = ["none", "summary", "verbose", "more verbose"];
                        let hint = did_you_mean(&value, choices)
                            .map(|s| format!("did you mean `{s}`? "))
                            .unwrap_or_default();
                        self.push(
                            Diagnostic::error(
                                codes::OUTPUT_RULE,
                                format!("unknown output rule `{value}`"),
                            )
                            .at(self.span(rest))
                            .help(format!(
                                "{hint}the rules are `none`, `summary`, `verbose`, `more verbose`"
                            )),
                        );
                    }
                }
            }
            "update_search_every_n_steps" => {
                self.once(seen, c);
                c.skip_sep();
                if let Some((n, n_at)) = self.count(c, "a whole number of steps") {
                    cd.update_search_every_n_steps = Some(n);
                    self.locs
                        .set(format!("{d}.update_search_every_n_steps"), n_at);
                }
                if c.peek()
                    .is_some_and(|t| t.lower == "steps" || t.lower == "step")
                {
                    c.pos += 1;
                }
            }
            "opposed_normal_threshold_angle" => {
                self.once(seen, c);
                c.skip_sep();
                if let Some((a, a_at)) = self.number(c, "an angle in degrees") {
                    cd.opposed_normal_threshold_angle = Some(a);
                    self.locs
                        .set(format!("{d}.opposed_normal_threshold_angle"), a_at);
                }
            }
            "disable_opposed_normal_interaction_culling" => {
                self.once(seen, c);
                cd.disable_opposed_normal_interaction_culling = true;
            }
            "scale_penalty" | "initial_overclosure" => {
                let k = cd.control_assignments.len();
                if let Some((x, value_at)) = self.control_assignment(c, at) {
                    if let Some(l) = value_at {
                        self.locs
                            .set(format!("{d}.control_assignment.{k}.factor"), l);
                    }
                    cd.control_assignments.push(x);
                }
            }
            "periodicity" => {
                let p = cd.periodicity.len();
                if let Some(x) = self.periodicity(d, p, c) {
                    cd.periodicity.push(x);
                }
            }
            _ => {}
        }
    }

    /// `<phrase> [for s1 [with s2]] = value`.
    pub(super) fn control_assignment(
        &mut self,
        c: &mut Cur,
        at: Loc,
    ) -> Option<(ControlAssignment, Option<Loc>)> {
        let mut surface_1 = None;
        let mut surface_2 = None;
        if c.peek().is_some_and(|t| t.is_word() && t.lower == "for") {
            c.pos += 1;
            surface_1 = Some(self.name(c, "a surface name")?.0);
            if c.peek().is_some_and(|t| t.is_word() && t.lower == "with") {
                c.pos += 1;
                surface_2 = Some(self.name(c, "a second surface name")?.0);
            }
        }
        if !c.peek().is_some_and(Token::is_sep) {
            self.missing(c, "`=` and a value");
            return None;
        }
        c.skip_sep();
        let mut value_at = None;
        let control = if c.cmd.key == "scale_penalty" {
            let (factor, f_at) = self.number(c, "a penalty scale factor")?;
            value_at = Some(f_at);
            Control::ScalePenalty { factor }
        } else {
            let rest: Vec<String> = c.rest().iter().map(|t| t.lower.clone()).collect();
            let treatment = match rest.join(" ").as_str() {
                "adjust nodes" | "adjust" => Overclosure::AdjustNodes,
                "store offsets" | "store offset" | "offsets" => Overclosure::StoreOffsets,
                other => {
                    let hint = did_you_mean(other, ["adjust nodes", "store offsets"])
                        .map(|s| format!("did you mean `{s}`? "))
                        .unwrap_or_default();
                    self.push(
                        Diagnostic::error(
                            codes::BAD_CHOICE,
                            format!("unknown overclosure treatment `{other}`"),
                        )
                        .at(self.span(c.rest()))
                        .help(format!(
                            "{hint}the choices are `adjust nodes` and `store offsets`"
                        )),
                    );
                    c.pos = c.line.tokens.len();
                    return None;
                }
            };
            c.pos = c.line.tokens.len();
            Control::InitialOverclosure { treatment }
        };
        Some((
            ControlAssignment {
                surface_1,
                surface_2,
                control,
                at,
            },
            value_at,
        ))
    }

    pub(super) fn periodicity(&mut self, d: usize, p: usize, c: &mut Cur) -> Option<Periodicity> {
        let at = self.line_loc(c.line);
        let (surface, _) = self.name(c, "a surface name")?;
        c.skip_sep();
        let kinds = ["rectangular", "cylindrical", "align_surface", "mapped"];
        let Some(kind_tok) = c.peek().filter(|t| !t.is_sep()) else {
            self.missing(
                c,
                "a transform (`rectangular`, `cylindrical`, `align_surface` or `mapped`)",
            );
            return None;
        };
        c.pos += 1;
        let kind = kind_tok.lower.as_str();
        let usage = match kind {
            "rectangular" => "rectangular offset = <dx> <dy> [<dz>]",
            "cylindrical" => {
                "cylindrical axis = <a1> <a2> [<a3>] center = <c1> <c2> [<c3>] angle = <degrees>"
            }
            "align_surface" => "align_surface destination = <surface> [invert_normals = 0|1]",
            _ => "mapped [x_map = <f>] [y_map = <g>] [z_map = <h>]",
        };
        let usage = format!("write `periodicity for {surface} {usage}`");
        let allowed: &[&str] = match kind {
            "rectangular" => &["offset"],
            "cylindrical" => &["axis", "center", "angle"],
            "align_surface" => &["destination", "invert_normals"],
            "mapped" => &["x_map", "y_map", "z_map"],
            _ => {
                let hint = did_you_mean(kind, kinds)
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                self.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("unknown periodicity transform `{}`", kind_tok.text),
                    )
                    .at(Some(kind_tok.loc(&self.file)))
                    .help(format!(
                        "{hint}the transforms are `rectangular`, `cylindrical`, `align_surface`, `mapped`"
                    )),
                );
                c.pos = c.line.tokens.len();
                return None;
            }
        };
        // `key = values…` groups: a key is a word followed by a separator.
        let rest = c.rest();
        c.pos = c.line.tokens.len();
        let mut groups: Vec<(&Token, Vec<&Token>)> = Vec::new();
        let mut i = 0;
        let mut ok = true;
        while let Some(t) = rest.get(i) {
            let keyed = rest.get(i + 1).is_some_and(Token::is_sep) && !t.is_sep();
            if keyed {
                groups.push((t, Vec::new()));
                i += 2;
            } else if let (Some(g), false) = (groups.last_mut(), t.is_sep()) {
                g.1.push(t);
                i += 1;
            } else {
                self.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("unexpected `{}` in the `{kind}` periodicity", t.text),
                    )
                    .at(Some(t.loc(&self.file)))
                    .help(usage.clone()),
                );
                ok = false;
                i += 1;
            }
        }
        let mut nums = |l: &mut Lower, key: &str| -> Option<Vec<f64>> {
            if !allowed.contains(&key) {
                return None; // reported below as not a part of this transform
            }
            let (_, vals) = groups.iter().find(|(k, _)| k.lower == key)?;
            let mut v = Vec::new();
            for t in vals {
                match parse_number(&t.text).filter(|_| t.is_word()) {
                    Some(x) => v.push(x),
                    None => {
                        l.not_a_number(c, t, &format!("numbers after `{key} =`"));
                        ok = false;
                    }
                }
            }
            let toks: Vec<Token> = vals.iter().map(|t| (*t).clone()).collect();
            if let Some(at) = l.span(&toks) {
                l.locs.set(format!("{d}.periodicity.{p}.{key}"), at);
            }
            Some(v)
        };
        let offset = nums(self, "offset");
        let axis = nums(self, "axis");
        let center = nums(self, "center");
        let angle = nums(self, "angle");
        let text = |key: &str| -> Option<String> {
            let (_, vals) = groups.iter().find(|(k, _)| k.lower == key)?;
            let words: Vec<&str> = vals.iter().map(|t| t.text.as_str()).collect();
            Some(words.join(" "))
        };
        for (k, _) in &groups {
            if !allowed.contains(&k.lower.as_str()) {
                let hint = did_you_mean(&k.lower, allowed.iter().copied())
                    .map(|s| format!("did you mean `{s}`? "))
                    .unwrap_or_default();
                let list: Vec<String> = allowed.iter().map(|a| format!("`{a}`")).collect();
                self.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("`{}` is not a part of the `{kind}` periodicity", k.text),
                    )
                    .at(Some(k.loc(&self.file)))
                    .help(format!(
                        "{hint}the `{kind}` periodicity takes {}",
                        list.join(", ")
                    )),
                );
                ok = false;
            }
        }
        let need = |l: &mut Lower, key: &str, present: bool| {
            if !present {
                l.push(
                    Diagnostic::error(
                        codes::PERIODICITY,
                        format!("the `{kind}` periodicity needs `{key} = …`"),
                    )
                    .at(Some(kind_tok.loc(&l.file)))
                    .help(usage.clone()),
                );
            }
            present
        };
        let transform = match kind {
            "rectangular" => {
                need(self, "offset", offset.is_some()).then_some(())?;
                PeriodicTransform::Rectangular {
                    offset: offset.unwrap_or_default(),
                }
            }
            "cylindrical" => {
                let all = need(self, "axis", axis.is_some())
                    & need(self, "center", center.is_some())
                    & need(self, "angle", angle.is_some());
                all.then_some(())?;
                let angle = angle.unwrap_or_default();
                let Some(&a) = angle.first().filter(|_| angle.len() == 1) else {
                    self.push(
                        Diagnostic::error(
                            codes::VALUE_COUNT,
                            format!("`angle` takes one value, found {}", angle.len()),
                        )
                        .at(self.locs.get(&format!("{d}.periodicity.{p}.angle")))
                        .help("write the rotation angle in degrees, e.g. `angle = 90`"),
                    );
                    return None;
                };
                PeriodicTransform::Cylindrical {
                    axis: axis.unwrap_or_default(),
                    center: center.unwrap_or_default(),
                    angle: a,
                }
            }
            "align_surface" => {
                let dest = text("destination");
                need(self, "destination", dest.is_some()).then_some(())?;
                let invert = match text("invert_normals").map(|s| s.to_lowercase()) {
                    None => true,
                    Some(v) => match v.as_str() {
                        "1" | "on" | "true" | "yes" => true,
                        "0" | "off" | "false" | "no" => false,
                        _ => {
                            self.push(
                                Diagnostic::error(
                                    codes::ON_OFF,
                                    format!("`invert_normals` is 0 or 1, not `{v}`"),
                                )
                                .at(groups
                                    .iter()
                                    .find(|(k, _)| k.lower == "invert_normals")
                                    .and_then(|(k, vals)| vals.first().copied().or(Some(*k)))
                                    .map(|t| t.loc(&self.file)))
                                .help("write `invert_normals = 0` to keep the normals as they are"),
                            );
                            return None;
                        }
                    },
                };
                PeriodicTransform::AlignSurface {
                    destination: dest.unwrap_or_default().to_lowercase(),
                    invert_normals: invert,
                }
            }
            _ => PeriodicTransform::Mapped {
                // A map left out is the identity (Aria manual: "functions that are not
                // specified default to a trivial mapping").
                x_map: text("x_map").unwrap_or_else(|| "x".to_string()),
                y_map: text("y_map").unwrap_or_else(|| "y".to_string()),
                z_map: text("z_map"),
            },
        };
        ok.then_some(Periodicity {
            surface,
            transform,
            at,
        })
    }
}
