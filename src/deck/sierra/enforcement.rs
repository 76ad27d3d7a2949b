//! `begin Enforcement`: the model lines, material-model (property) lines and their
//! arguments.

use std::collections::HashSet;

use crate::deck::codes;
use crate::deck::lexer::Token;
use crate::deck::registry;
use crate::deck::spec::*;
use crate::deck::tree::{Block, Item};
use crate::diag::{Diagnostic, Loc, did_you_mean};

use super::{Cur, ENF, Lower, Matched, value_text};

impl Lower {
    pub(super) fn enforcement(&mut self, d: usize, k: usize, b: &Block) -> Enforcement {
        let mut e = Enforcement {
            name: self.block_name(b),
            at: self.line_loc(&b.head),
            ..Default::default()
        };
        let mut seen = HashSet::new();
        // The first pressure line: its phrase and line, for `contact pressure` and
        // `contact surface pressure` in one block.
        let mut pressure_from: Option<(&'static str, u32)> = None;
        for item in &b.items {
            let line = match item {
                Item::Block(sub) => {
                    self.misplaced(sub, ENF);
                    continue;
                }
                Item::Line(line) => line,
            };
            let mut c = match self.command(ENF, line) {
                Matched::Command(c) => c,
                Matched::Reported => continue,
            };
            let at = self.line_loc(line);
            if let registry::Status::Refused(_) = c.cmd.status {
                // Kept as a property line: the semantic check refuses it, for both forms.
                let p = self.property(&mut c);
                e.properties.push(p);
                continue;
            }
            match c.cmd.key {
                "model" => {
                    let eq = self.name(&mut c, "an equation name");
                    let Some((equation, eq_at)) = eq else {
                        continue;
                    };
                    c.skip_sep();
                    let Some((model, _)) = self.name(&mut c, "a model name") else {
                        continue;
                    };
                    let m = e.models.len();
                    self.locs
                        .set(format!("{d}.enforcement.{k}.model.{m}.equation"), eq_at);
                    let (args, arg_locs) = self.args(&c, c.rest());
                    for (a, l) in arg_locs.into_iter().enumerate() {
                        self.locs
                            .set(format!("{d}.enforcement.{k}.model.{m}.arg.{a}"), l);
                    }
                    c.pos = line.tokens.len();
                    e.models.push(EnforcementModel {
                        equation,
                        model,
                        args,
                        at,
                    });
                }
                "gap_conductance_coefficient" => {
                    let p = self.property(&mut c);
                    e.properties.push(p);
                }
                "integer_data" => {
                    c.skip_sep();
                    while c.peek().is_some() {
                        let before = c.pos;
                        if let Some((v, _)) = self.integer(&mut c, "integers") {
                            e.integer_data.push(v);
                        }
                        c.pass_reported(before);
                    }
                }
                "real_data" => {
                    c.skip_sep();
                    while c.peek().is_some() {
                        let before = c.pos;
                        if let Some((v, _)) = self.number(&mut c, "numbers") {
                            e.real_data.push(v);
                        }
                        c.pass_reported(before);
                    }
                }
                "side_b_variable" | "slave_variable" => {
                    if c.cmd.key == "slave_variable" {
                        self.push(
                            Diagnostic::warning(
                                codes::DEPRECATED_ALIAS,
                                "`slave variable` is a deprecated name for `side b variable`",
                            )
                            .at(self.span(line.tokens.get(..c.n).unwrap_or_default()))
                            .help("write `side b variable <side B variable> to <side A variable>`"),
                        );
                    }
                    self.once_as(&mut seen, "side_b_variable", &c);
                    c.skip_sep();
                    let Some((side_b, _)) = self.name(&mut c, "a side B variable") else {
                        continue;
                    };
                    if !self.keyword(&mut c, "to") {
                        continue;
                    }
                    let Some((side_a, _)) = self.name(&mut c, "a side A variable") else {
                        continue;
                    };
                    e.side_b_variable = Some(VariableMap { side_b, side_a });
                }
                "quarantine_faulty_points" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    e.quarantine_faulty_points = if c.peek().is_some() {
                        self.switch(&mut c).unwrap_or(false)
                    } else {
                        true
                    };
                }
                "dash_penalty_factor" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, v_at)) = self.number(&mut c, "a number") {
                        e.dash_penalty_factor = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.dash_penalty_factor"), v_at);
                    }
                }
                "offset_voltage" => {
                    self.once(&mut seen, &c);
                    if let Some((v, v_at)) = self.constant_value(&mut c, "a voltage difference") {
                        e.offset_voltage = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.offset_voltage"), v_at);
                    }
                }
                "joule_fraction_side_a" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, v_at)) = self.number(&mut c, "a fraction in [0, 1]") {
                        e.joule_fraction_side_a = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.joule_fraction_side_a"), v_at);
                    }
                }
                "offset_species" => {
                    self.once(&mut seen, &c);
                    if let Some((v, v_at)) =
                        self.constant_value(&mut c, "a concentration difference")
                    {
                        e.offset_species = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.offset_species"), v_at);
                    }
                }
                "partition_coefficient" => {
                    self.once(&mut seen, &c);
                    if let Some((v, v_at)) = self.constant_value(&mut c, "a partition coefficient")
                    {
                        e.partition_coefficient = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.partition_coefficient"), v_at);
                    }
                }
                "offset_temperature" => {
                    self.once(&mut seen, &c);
                    if let Some((v, v_at)) = self.constant_value(&mut c, "a temperature difference")
                    {
                        e.offset_temperature = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.offset_temperature"), v_at);
                    }
                }
                "contact_pressure" => {
                    let phrase = c.cmd.phrase;
                    match pressure_from {
                        Some((first, first_line)) if first != phrase => {
                            self.push(
                                Diagnostic::error(
                                    codes::TWO_PRESSURES,
                                    format!(
                                        "`{phrase}` and `{first}` in one enforcement block"
                                    ),
                                )
                                .at(self.span(line.tokens.get(..c.n).unwrap_or_default()))
                                .help(format!(
                                    "both set the contact pressure; `{first}` is on line {first_line}: keep one"
                                )),
                            );
                            continue;
                        }
                        Some(_) => {
                            self.once_as(&mut seen, "contact_pressure", &c);
                        }
                        None => {
                            seen.insert("contact_pressure");
                            pressure_from = Some((phrase, line.line));
                        }
                    }
                    if let Some((v, v_at)) = self.constant_value(&mut c, "a pressure") {
                        e.contact_pressure = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.contact_pressure"), v_at);
                    }
                }
                "contact_gap_temperature" | "contact_gap_voltage" => {
                    self.once(&mut seen, &c);
                    let voltage = c.cmd.key == "contact_gap_voltage";
                    let choice = self.gap_choice(&mut c, voltage);
                    match voltage {
                        true => e.contact_gap_voltage = choice,
                        false => e.contact_gap_temperature = choice,
                    }
                }
                "plugin_isolation" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    let rest = c.rest();
                    c.pos = line.tokens.len();
                    let value = rest
                        .iter()
                        .map(|t| t.lower.as_str())
                        .collect::<Vec<_>>()
                        .join(" ");
                    match value.as_str() {
                        "process" => e.plugin_isolation = PluginIsolation::Process,
                        "none" => e.plugin_isolation = PluginIsolation::None,
                        _ if rest.is_empty() => self.missing(&c, "`process` or `none`"),
                        _ => {
                            let hint = did_you_mean(&value, ["process", "none"])
                                .map(|s| format!("did you mean `{s}`? "))
                                .unwrap_or_default();
                            self.push(
                                Diagnostic::error(
                                    codes::BAD_CHOICE,
                                    format!("unknown plugin isolation `{value}`"),
                                )
                                .at(self.span(rest))
                                .help(format!(
                                    "{hint}the choices are `process` (the plugin in a worker process) and `none` (in seam's process)"
                                )),
                            );
                        }
                    }
                }
                "contact_pressure_variable" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, _)) = self.name(&mut c, "a nodal field name") {
                        e.contact_pressure_variable = Some(v);
                    }
                }
                "use_toggle_block" => {
                    self.once(&mut seen, &c);
                    c.skip_sep();
                    if let Some((v, at)) = self.name(&mut c, "a toggle block name") {
                        e.use_toggle_block = Some(v);
                        self.locs
                            .set(format!("{d}.enforcement.{k}.use_toggle_block"), at);
                        if c.peek().is_some() {
                            e.toggle_element_blocks = self.names(&mut c, "element block names");
                        }
                    }
                }
                _ => {}
            }
            self.finish(&c);
        }
        e
    }

    /// `= [constant [value =]] <number>`: the material-model form `Constant Value = v`
    /// and the plain `= v`.
    /// The value of a `Contact Gap Temperature` (or, `voltage`, `Contact Gap Voltage`)
    /// line: `side_a`, `side_b`, `mean` (`average`), or `[constant [value =]] <v>`.
    fn gap_choice(&mut self, c: &mut Cur, voltage: bool) -> Option<GapTemperature> {
        let what = if voltage { "voltage" } else { "temperature" };
        c.skip_sep();
        if c.peek()
            .is_some_and(|t| t.lower == "constant" || t.lower.parse::<f64>().is_ok())
        {
            let fixed = self.constant_value(c, &format!("a {what}"));
            return fixed.map(|(v, _)| GapTemperature::Constant(v));
        }
        let rest = c.rest();
        c.pos = c.line.tokens.len();
        let words: Vec<String> = rest.iter().map(|t| t.lower.replace('_', " ")).collect();
        let value = words.join(" ");
        match value.as_str() {
            "side a" => return Some(GapTemperature::SideA),
            "side b" => return Some(GapTemperature::SideB),
            "mean" | "average" | "avg" => return Some(GapTemperature::Mean),
            _ => {}
        }
        if rest.is_empty() {
            self.missing(c, "`side_a`, `side_b`, `mean` or `constant value = <v>`");
            return None;
        }
        let hint = did_you_mean(&value, ["side a", "side b", "mean"])
            .map(|s| format!("did you mean `{}`? ", s.replace(' ', "_")))
            .unwrap_or_default();
        self.push(
            Diagnostic::error(
                codes::BAD_CHOICE,
                format!("unknown contact gap {what} `{value}`"),
            )
            .at(self.span(rest))
            .help(format!(
                "{hint}the choices are `side_a`, `side_b`, `mean` and `constant value = <v>` (the {what} a {what}-dependent conductance sees)"
            )),
        );
        None
    }

    pub(super) fn constant_value(&mut self, c: &mut Cur, what: &str) -> Option<(f64, Loc)> {
        c.skip_sep();
        if c.peek()
            .is_some_and(|t| t.is_word() && t.lower == "constant")
        {
            c.pos += 1;
            if c.peek().is_some_and(|t| t.is_word() && t.lower == "value") {
                c.pos += 1;
            }
            c.skip_sep();
        }
        self.number(c, what)
    }

    /// A material-model line: `<property> [=] <model> [args…]`, the property named by
    /// the command's key.
    pub(super) fn property(&mut self, c: &mut Cur) -> PropertyModel {
        let line = c.line;
        c.skip_sep();
        let model = match c.peek().filter(|t| !t.is_sep()) {
            Some(t) => {
                c.pos += 1;
                t.lower.clone()
            }
            None => {
                if c.cmd.status == registry::Status::Implemented {
                    self.missing(c, "a model after `=`");
                }
                String::new()
            }
        };
        let (args, _) = self.args(c, c.rest());
        c.pos = line.tokens.len();
        PropertyModel {
            property: c.cmd.key.to_string(),
            model,
            args,
            at: self.line_loc(line),
        }
    }

    /// Model arguments: `key = value` pairs and bare words, with where each was written
    /// (its key, or the bare word).
    pub(super) fn args(&mut self, c: &Cur, toks: &[Token]) -> (Vec<Arg>, Vec<Loc>) {
        let mut out = Vec::new();
        let mut locs = Vec::new();
        let mut i = 0;
        while let Some(t) = toks.get(i) {
            if t.is_sep() {
                self.push(
                    Diagnostic::error(
                        codes::MISSING_ARGUMENT,
                        format!("`{}` has `{}` with no key before it", c.phrase(), t.text),
                    )
                    .at(Some(t.loc(&self.file)))
                    .help("write arguments as `key = value` or as single words"),
                );
                i += 1;
            } else if toks.get(i + 1).is_some_and(Token::is_sep) {
                match toks.get(i + 2).filter(|v| !v.is_sep()) {
                    Some(v) => {
                        out.push(Arg {
                            key: t.lower.clone(),
                            value: value_text(v),
                        });
                        locs.push(t.loc(&self.file));
                        i += 3;
                    }
                    None => {
                        let at = toks.get(i + 1).map(|s| s.loc(&self.file));
                        self.push(
                            Diagnostic::error(
                                codes::MISSING_ARGUMENT,
                                format!("argument `{}` of `{}` has no value", t.text, c.phrase()),
                            )
                            .at(at)
                            .help(format!("write `{} = <value>`", t.text)),
                        );
                        i += 2;
                    }
                }
            } else {
                out.push(Arg {
                    key: String::new(),
                    value: value_text(t),
                });
                locs.push(t.loc(&self.file));
                i += 1;
            }
        }
        (out, locs)
    }
}
