//! `Gap Conductance Coefficient = <model> <args>` lines of an enforcement, turned into
//! one conductance model of [`crate::enforce::conductance`] (several lines add up into
//! a [`Sum`]), with diagnostics `E06xx` that point into the line.
//!
//! Spellings (case-insensitive apart from quoted strings; `[…]` optional):
//! - `Constant H = 10`
//! - `Gas_Gap K = 0.025 [Beta = 0.001 T0 = 300] [Min_Gap = 1e-6] [Max_Gap = 1e6]
//!   [Min_Gap_Order = 0|1]`
//! - `Radiation Emissivity_A = 0.8 Emissivity_B = 0.6`
//! - `CMY K_A = 16 K_B = 200 Slope = 0.1 Roughness = 1e-6 Hardness = 3e9`
//!   (alias `Cooper_Mikic_Yovanovich`)
//! - `Table [Of] Gap|Pressure|Temperature = x0 h0 x1 h1 …`
//! - `Lua "expression"` or `Lua File = "file.lua" Function = name`
//! - `Plugin Library = "lib.so" [Model = name]` (with the enforcement's Integer/Real
//!   Data)

use std::path::Path;

use super::enforcement::seen_temperature;
use crate::deck::spec::{Enforcement, PropertyModel};
use crate::diag::{Diagnostic, Diagnostics, Loc, SourceMap, did_you_mean};
use crate::enforce::conductance::{
    Cmy, ConductanceError, ConductanceModel, Constant, DEFAULT_MAX_GAP, DEFAULT_MIN_GAP, GasGap,
    LuaConductance, MinGapOrder, PluginConductance, Radiation, Sum, Table, TableVariable,
};
use crate::plugin::{Plugin, PluginData};
use crate::script::{Limits, ScriptError};

/// The diagnostic codes of conductance lines (stable: never reused).
pub mod codes {
    /// The model after `=` is not one seam knows.
    pub const UNKNOWN_MODEL: &str = "E0601";
    /// A required parameter is missing.
    pub const MISSING_PARAMETER: &str = "E0602";
    /// A parameter the model does not take (or a stray word).
    pub const UNKNOWN_PARAMETER: &str = "E0603";
    /// A value that is not a number.
    pub const NOT_A_NUMBER: &str = "E0604";
    /// A value out of its range (negative conductance, emissivity outside (0, 1], …).
    pub const OUT_OF_RANGE: &str = "E0605";
    /// A table with an odd count or abscissae that do not increase strictly.
    pub const BAD_TABLE: &str = "E0606";
    /// A Lua expression or file that does not compile or lacks its function.
    pub const LUA: &str = "E0607";
    /// A plugin that cannot be loaded or does not return a conductance.
    pub const PLUGIN: &str = "E0608";
    /// The same parameter given twice on one line.
    pub const DUPLICATE_PARAMETER: &str = "E0609";
}

/// The property key of the lines read here.
pub const PROPERTY: &str = "gap_conductance_coefficient";

/// Model names as written (lower case), canonical first.
const MODELS: [&str; 7] = [
    "constant",
    "gas_gap",
    "radiation",
    "cmy",
    "table",
    "lua",
    "plugin",
];

/// The enforcement's conductance coefficient: `None` if it has no
/// `Gap Conductance Coefficient` line or any line is wrong (then the diagnostics say
/// why, all of them). Relative file names (Lua files, plugin libraries) are taken
/// relative to `deck_dir`; `sources` places the carets.
pub fn from_properties(
    enforcement: &Enforcement,
    deck_dir: &Path,
    sources: &SourceMap,
) -> (Option<Box<dyn ConductanceModel>>, Diagnostics) {
    let mut cx = Cx {
        sources,
        deck_dir,
        enforcement,
        diags: Diagnostics::default(),
    };
    let seen = seen_temperature(enforcement);
    let mut parts = Vec::new();
    let mut failed = false;
    for p in enforcement
        .properties
        .iter()
        .filter(|p| p.property == PROPERTY)
    {
        match cx.line(p) {
            Some(m) => parts.push(seen.wrap(m)),
            None => failed = true,
        }
    }
    let model: Option<Box<dyn ConductanceModel>> = if failed || parts.is_empty() {
        None
    } else if parts.len() == 1 {
        parts.pop()
    } else {
        Some(Box::new(Sum::new(parts)))
    };
    (model, cx.diags)
}

struct Cx<'a> {
    sources: &'a SourceMap,
    deck_dir: &'a Path,
    enforcement: &'a Enforcement,
    diags: Diagnostics,
}

/// One line being read: its model's location and its `key = value` arguments.
struct Line<'a> {
    p: &'a PropertyModel,
    model: &'static str,
    model_loc: Loc,
}

impl Cx<'_> {
    /// The location of the model word: after the line's `=`, so a model name that
    /// also occurs among the property words is not mistaken.
    fn model_loc(&self, p: &PropertyModel) -> Loc {
        let at = &p.at;
        let Some(text) = self.sources.line(&at.file, at.line) else {
            return at.clone();
        };
        let start = text
            .char_indices()
            .nth(at.col.saturating_sub(1) as usize)
            .map_or(0, |(i, _)| i);
        let Some(eq) = text[start..].find('=').map(|i| start + i) else {
            return at.clone();
        };
        let from = Loc {
            col: text[..eq].chars().count() as u32 + 1,
            len: 1,
            ..at.clone()
        };
        self.sources.narrow(&from, &p.model)
    }

    /// The location of `key` (after the model word), else the model's.
    fn key_loc(&self, l: &Line, key: &str) -> Loc {
        self.sources.narrow(&l.model_loc, key)
    }

    /// The location of `value` after `key`.
    fn value_loc(&self, l: &Line, key: &str, value: &str) -> Loc {
        self.sources.narrow(&self.key_loc(l, key), value)
    }

    fn error(&mut self, code: &'static str, loc: Loc, message: String, help: String) {
        self.diags
            .push(Diagnostic::error(code, message).at(Some(loc)).help(help));
    }

    fn line(&mut self, p: &PropertyModel) -> Option<Box<dyn ConductanceModel>> {
        let model_loc = self.model_loc(p);
        let name = p.model.to_ascii_lowercase();
        let canonical = match name.as_str() {
            "cooper_mikic_yovanovich" => "cmy",
            other => MODELS.iter().copied().find(|m| *m == other).unwrap_or(""),
        };
        if canonical.is_empty() {
            let help = match did_you_mean(&name, MODELS) {
                Some(m) => format!("did you mean `{m}`?"),
                None => format!("the models are {}", list(&MODELS)),
            };
            self.error(
                codes::UNKNOWN_MODEL,
                model_loc,
                format!("unknown gap conductance model `{}`", p.model),
                help,
            );
            return None;
        }
        let l = Line {
            p,
            model: canonical,
            model_loc,
        };
        match canonical {
            "constant" => self.constant(&l),
            "gas_gap" => self.gas_gap(&l),
            "radiation" => self.radiation(&l),
            "cmy" => self.cmy(&l),
            "table" => self.table(&l),
            "lua" => self.lua(&l),
            _ => self.plugin(&l),
        }
    }

    /// The `key = value` arguments, each key allowed and given once; `None` after
    /// reporting a stray word, an unknown or a repeated key.
    fn keyed<'a>(&mut self, l: &Line<'a>, allowed: &[&str]) -> Option<Vec<(&'a str, &'a str)>> {
        let mut out: Vec<(&str, &str)> = Vec::new();
        let mut ok = true;
        for a in &l.p.args {
            if a.key.is_empty() {
                let loc = self.sources.narrow(&l.model_loc, &a.value);
                self.error(
                    codes::UNKNOWN_PARAMETER,
                    loc,
                    format!(
                        "`{}` takes `key = value` parameters, not the word `{}`",
                        l.model, a.value
                    ),
                    format!("its parameters are {}", list(allowed)),
                );
                ok = false;
            } else if !allowed.contains(&a.key.as_str()) {
                let loc = self.key_loc(l, &a.key);
                let help = match did_you_mean(&a.key, allowed.iter().copied()) {
                    Some(m) => format!("did you mean `{m}`? The parameters are {}", list(allowed)),
                    None => format!("the parameters are {}", list(allowed)),
                };
                self.error(
                    codes::UNKNOWN_PARAMETER,
                    loc,
                    format!("`{}` has no parameter `{}`", l.model, a.key),
                    help,
                );
                ok = false;
            } else if out.iter().any(|(k, _)| *k == a.key) {
                let first = self.key_loc(l, &a.key);
                let loc = self.sources.narrow(
                    &Loc {
                        col: first.col + first.len,
                        ..first
                    },
                    &a.key,
                );
                self.error(
                    codes::DUPLICATE_PARAMETER,
                    loc,
                    format!("`{}` is given twice", a.key),
                    "keep one value".into(),
                );
                ok = false;
            } else {
                out.push((a.key.as_str(), a.value.as_str()));
            }
        }
        ok.then_some(out)
    }

    /// A number parameter; `default` None means required. `Err(())` after reporting.
    fn number(
        &mut self,
        l: &Line,
        args: &[(&str, &str)],
        key: &str,
        default: Option<f64>,
        ok: impl Fn(f64) -> bool,
        rule: &str,
    ) -> Result<f64, ()> {
        let Some(&(_, text)) = args.iter().find(|(k, _)| *k == key) else {
            return default.ok_or_else(|| {
                self.error(
                    codes::MISSING_PARAMETER,
                    l.model_loc.clone(),
                    format!("`{}` needs `{key} = <value>`", l.model),
                    format!("write e.g. `{}`", example(l.model)),
                );
            });
        };
        let Ok(v) = text.parse::<f64>() else {
            let loc = self.value_loc(l, key, text);
            self.error(
                codes::NOT_A_NUMBER,
                loc,
                format!("`{key}` of `{}` must be a number, not `{text}`", l.model),
                format!("write `{key} = <number>`"),
            );
            return Err(());
        };
        if !(v.is_finite() && ok(v)) {
            let loc = self.value_loc(l, key, text);
            self.error(
                codes::OUT_OF_RANGE,
                loc,
                format!("`{key}` of `{}` is {text}, but it must be {rule}", l.model),
                format!("give `{key}` a value {rule}"),
            );
            return Err(());
        }
        Ok(v)
    }

    /// A model the deck layer has checked; a remaining constructor error (a rule that
    /// spans parameters, e.g. max_gap > min_gap) is reported at the model.
    fn built<M: ConductanceModel + 'static>(
        &mut self,
        l: &Line,
        m: Result<M, ConductanceError>,
    ) -> Option<Box<dyn ConductanceModel>> {
        match m {
            Ok(m) => Some(Box::new(m)),
            Err(e) => {
                self.error(
                    codes::OUT_OF_RANGE,
                    l.model_loc.clone(),
                    e.to_string(),
                    format!("write e.g. `{}`", example(l.model)),
                );
                None
            }
        }
    }

    fn constant(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let args = self.keyed(l, &["h"])?;
        // `h = inf`: a perfect joint (the interface forms take their tied limit).
        if args
            .iter()
            .any(|(k, v)| *k == "h" && v.parse::<f64>() == Ok(f64::INFINITY))
        {
            return self.built(l, Constant::new(f64::INFINITY));
        }
        let h = self
            .number(
                l,
                &args,
                "h",
                None,
                |h| h >= 0.0,
                "≥ 0 (a conductance in W/m²K; inf for a perfect joint)",
            )
            .ok()?;
        self.built(l, Constant::new(h))
    }

    fn gas_gap(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let keys = ["k", "beta", "t0", "min_gap", "max_gap", "min_gap_order"];
        let args = self.keyed(l, &keys)?;
        let k = self.number(l, &args, "k", None, |k| k >= 0.0, "≥ 0 (W/m·K)");
        let beta = self.number(l, &args, "beta", Some(0.0), |_| true, "finite");
        let t0 = self.number(l, &args, "t0", Some(0.0), |_| true, "finite");
        let gmin = self.number(
            l,
            &args,
            "min_gap",
            Some(DEFAULT_MIN_GAP),
            |g| g > 0.0,
            "> 0 (m)",
        );
        let gmax = self.number(
            l,
            &args,
            "max_gap",
            Some(DEFAULT_MAX_GAP),
            |g| g > 0.0,
            "> 0 (m)",
        );
        let order = self.number(
            l,
            &args,
            "min_gap_order",
            Some(0.0),
            |o| o == 0.0 || o == 1.0,
            "0 or 1",
        );
        let (k, beta, t0, gmin, gmax, order) = (
            k.ok()?,
            beta.ok()?,
            t0.ok()?,
            gmin.ok()?,
            gmax.ok()?,
            order.ok()?,
        );
        let order = if order == 1.0 {
            MinGapOrder::One
        } else {
            MinGapOrder::Zero
        };
        self.built(l, GasGap::with(k, beta, t0, gmin, gmax, order))
    }

    fn radiation(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let args = self.keyed(l, &["emissivity_a", "emissivity_b"])?;
        let in_range = |e: f64| e > 0.0 && e <= 1.0;
        let a = self.number(l, &args, "emissivity_a", None, in_range, "in (0, 1]");
        let b = self.number(l, &args, "emissivity_b", None, in_range, "in (0, 1]");
        let (a, b) = (a.ok()?, b.ok()?);
        self.built(l, Radiation::new(a, b))
    }

    fn cmy(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let keys = ["k_a", "k_b", "slope", "roughness", "hardness"];
        let args = self.keyed(l, &keys)?;
        let mut v = [0.0; 5];
        let mut ok = true;
        for (slot, key) in v.iter_mut().zip(keys) {
            match self.number(l, &args, key, None, |x| x > 0.0, "> 0") {
                Ok(x) => *slot = x,
                Err(()) => ok = false,
            }
        }
        if !ok {
            return None;
        }
        self.built(l, Cmy::new(v[0], v[1], v[2], v[3], v[4]))
    }

    fn table(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let vars = ["gap", "pressure", "temperature"];
        let mut args = l.p.args.iter().peekable();
        args.next_if(|a| a.key.is_empty() && a.value == "of");
        let head = args.next();
        let variable = match head.map(|a| a.key.as_str()) {
            Some("gap") => TableVariable::Gap,
            Some("pressure") => TableVariable::Pressure,
            Some("temperature") => TableVariable::Temperature,
            _ => {
                let (loc, what) = match head {
                    Some(a) => {
                        let w = if a.key.is_empty() { &a.value } else { &a.key };
                        (self.sources.narrow(&l.model_loc, w), format!("`{w}`"))
                    }
                    None => (l.model_loc.clone(), "nothing".to_string()),
                };
                let help = match head.and_then(|a| {
                    let w = if a.key.is_empty() { &a.value } else { &a.key };
                    did_you_mean(w, vars)
                }) {
                    Some(m) => format!("did you mean `{m}`? Write `table of {m} = x0 h0 x1 h1 …`"),
                    None => "write `table of gap|pressure|temperature = x0 h0 x1 h1 …`".into(),
                };
                self.error(
                    codes::MISSING_PARAMETER,
                    loc,
                    format!("`table` must say what it tabulates, found {what}"),
                    help,
                );
                return None;
            }
        };
        let head = head.expect("matched above");
        let key = head.key.as_str();
        let mut texts = vec![head.value.as_str()];
        for a in args {
            if !a.key.is_empty() {
                let loc = self.key_loc(l, &a.key);
                self.error(
                    codes::UNKNOWN_PARAMETER,
                    loc,
                    format!(
                        "`table of {key}` takes only numbers after `=`, not `{} =`",
                        a.key
                    ),
                    "write `table of <variable> = x0 h0 x1 h1 …`".into(),
                );
                return None;
            }
            texts.push(a.value.as_str());
        }
        let mut numbers = Vec::with_capacity(texts.len());
        let mut ok = true;
        for t in &texts {
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => numbers.push(v),
                _ => {
                    let loc = self.value_loc(l, key, t);
                    self.error(
                        codes::NOT_A_NUMBER,
                        loc,
                        format!("table entry `{t}` is not a number"),
                        "write the table as numbers `x0 h0 x1 h1 …`".into(),
                    );
                    ok = false;
                }
            }
        }
        if !ok {
            return None;
        }
        if numbers.len() % 2 != 0 {
            self.error(
                codes::BAD_TABLE,
                self.key_loc(l, key),
                format!(
                    "`table of {key}` has {} numbers; it needs pairs `{key} h`",
                    numbers.len()
                ),
                "give an h for every abscissa".into(),
            );
            return None;
        }
        let points: Vec<(f64, f64)> = numbers.chunks(2).map(|c| (c[0], c[1])).collect();
        // Carets on the offending entries: search the line left to right, pair by pair.
        let mut cursor = self.key_loc(l, key);
        for (i, &(x, h)) in points.iter().enumerate() {
            let x_loc = self.sources.narrow(&next(&cursor), texts[2 * i]);
            let h_loc = self.sources.narrow(&next(&x_loc), texts[2 * i + 1]);
            if i > 0 && x <= points[i - 1].0 {
                self.error(
                    codes::BAD_TABLE,
                    x_loc,
                    format!(
                        "`table of {key}`: {key} values must increase strictly, but {} follows {}",
                        texts[2 * i],
                        texts[2 * i - 2]
                    ),
                    format!("list the pairs in increasing {key}, each {key} once"),
                );
                return None;
            }
            if h < 0.0 {
                self.error(
                    codes::OUT_OF_RANGE,
                    h_loc,
                    format!(
                        "`table of {key}`: conductance {} is negative",
                        texts[2 * i + 1]
                    ),
                    "a conductance must be ≥ 0 (W/m²K)".into(),
                );
                return None;
            }
            cursor = h_loc;
        }
        self.built(l, Table::new(variable, &points))
    }

    fn lua(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let args = &l.p.args;
        let at = &l.p.at;
        if let [a] = args.as_slice()
            && a.key.is_empty()
        {
            let chunk = format!("{}:{}", at.file, at.line);
            return match LuaConductance::expression(&chunk, &a.value) {
                Ok(m) => Some(Box::new(m)),
                Err(e) => {
                    let message = script_message(e);
                    self.error(
                        codes::LUA,
                        self.sources.narrow(&l.model_loc, "lua"),
                        format!("gap conductance: {message}"),
                        "write a Lua expression in gap, temp_a, temp_b (or T_A, T_B), pressure, x, y, z, t".into(),
                    );
                    None
                }
            };
        }
        let keyed = self.keyed(l, &["file", "function"])?;
        let file = keyed.iter().find(|(k, _)| *k == "file").map(|kv| kv.1);
        let function = keyed.iter().find(|(k, _)| *k == "function").map(|kv| kv.1);
        let (Some(file), Some(function)) = (file, function) else {
            self.error(
                codes::MISSING_PARAMETER,
                l.model_loc.clone(),
                "`lua` needs a quoted expression, or `file = …` and `function = …`".into(),
                "write `lua \"100 + 0.1*temp_a\"` or `lua file = \"h.lua\" function = h`".into(),
            );
            return None;
        };
        let path = self.deck_dir.join(file);
        // Bounded and BOM-aware, like every Lua file seam reads.
        let text = match crate::script::read_lua_file(&path) {
            Ok(t) => t,
            Err(e) => {
                self.error(
                    codes::LUA,
                    self.value_loc(l, "file", file),
                    format!("cannot read Lua file {file}: {e}"),
                    "the path is relative to the deck's directory".into(),
                );
                return None;
            }
        };
        match LuaConductance::source_with(file, &text, function, Limits::default()) {
            Ok(m) => Some(Box::new(m)),
            Err(e) => {
                self.error(
                    codes::LUA,
                    self.value_loc(l, "file", file),
                    format!("gap conductance: {}", script_message(e)),
                    format!("fix {file}; it must define a global function `{function}(gap, temp_a, temp_b, pressure, x, y, z, t)`"),
                );
                None
            }
        }
    }

    fn plugin(&mut self, l: &Line) -> Option<Box<dyn ConductanceModel>> {
        let args = self.keyed(l, &["library", "model"])?;
        let Some(&(_, library)) = args.iter().find(|(k, _)| *k == "library") else {
            self.error(
                codes::MISSING_PARAMETER,
                l.model_loc.clone(),
                "`plugin` needs `library = \"…\"`".into(),
                format!("write e.g. `{}`", example("plugin")),
            );
            return None;
        };
        let model = args
            .iter()
            .find(|(k, _)| *k == "model")
            .map(|kv| kv.1.to_string());
        let data = PluginData {
            model,
            integer_data: self.enforcement.integer_data.clone(),
            real_data: self.enforcement.real_data.clone(),
        };
        let loaded = Plugin::load_with(&self.deck_dir.join(library), &data)
            .map_err(|e| e.to_string())
            .and_then(|p| PluginConductance::new(p).map_err(|e| e.to_string()));
        match loaded {
            Ok(m) => Some(Box::new(m)),
            Err(message) => {
                self.error(
                    codes::PLUGIN,
                    self.value_loc(l, "library", library),
                    format!("gap conductance: {message}"),
                    "the library must be a seam plugin that returns conductance (no RETURNS_FLUX, no state); `seam check-plugin` tests it".into(),
                );
                None
            }
        }
    }
}

/// A script error for a diagnostic: Lua's own syntax message already starts with the
/// chunk and line (`deck.i:4:1:`, `h.lua:3:`), so the sandbox's `in <chunk>` is dropped.
fn script_message(e: ScriptError) -> String {
    match e {
        ScriptError::Syntax { message, .. } => format!("Lua syntax error: {message}"),
        other => other.to_string(),
    }
}

/// The column just after `loc`, to search for the next word.
fn next(loc: &Loc) -> Loc {
    Loc {
        col: loc.col + loc.len,
        len: 1,
        ..loc.clone()
    }
}

fn list(names: &[&str]) -> String {
    let v: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    v.join(", ")
}

/// A complete example line per model, for help texts.
fn example(model: &str) -> &'static str {
    match model {
        "constant" => "gap conductance coefficient = constant h = 10",
        "gas_gap" => "gap conductance coefficient = gas_gap k = 0.025 min_gap = 1e-6",
        "radiation" => {
            "gap conductance coefficient = radiation emissivity_a = 0.8 emissivity_b = 0.6"
        }
        "cmy" => {
            "gap conductance coefficient = cmy k_a = 16 k_b = 200 slope = 0.1 roughness = 1e-6 hardness = 3e9"
        }
        "table" => "gap conductance coefficient = table of gap = 0 1000 1e-3 100",
        "lua" => "gap conductance coefficient = lua \"100 + 0.1*temp_a\"",
        _ => "gap conductance coefficient = plugin library = \"libmy_h.so\"",
    }
}
