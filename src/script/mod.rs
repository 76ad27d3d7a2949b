//! Sandboxed Lua for user maps and expressions.
//!
//! Entry point: [`Sandbox`]. One sandbox per definition and thread (Lua states are not
//! shared between threads). A sandbox offers only the `math`, `string` and `table`
//! libraries: no `io`, `os`, `package`/`require`, `debug`, `load`, `loadstring`,
//! `dofile`, `loadfile`, `collectgarbage`, `string.dump` or `print`, and none of the
//! pattern functions `string.find`, `match`, `gmatch`, `gsub`: they run in C, out of the
//! instruction budget's reach, and a backtracking pattern such as `('a*'):rep(8)..'b'`
//! against a few hundred characters runs for hours. Chunks are loaded
//! as text only (precompiled bytecode is refused). Memory is capped, and every call runs
//! under an instruction budget, so a runaway loop or a memory bomb ends with a clear
//! error instead of hanging or exhausting the host.
//!
//! Expressions are compiled once into functions ([`Sandbox::expression`]) and then
//! called per point ([`Sandbox::call`]); a scalar call costs a few hundred nanoseconds.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use mlua::chunk::ChunkMode;
use mlua::{HookTriggers, Lua, LuaOptions, StdLib, Value, VmState};

/// Resource limits of one sandbox.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Bytes the Lua heap may hold.
    pub memory_bytes: usize,
    /// Instructions one call (or one file load) may execute.
    pub instructions: u64,
}

impl Default for Limits {
    /// 16 MiB and 10⁷ instructions: a periodic map or a conductance expression needs a
    /// few hundred instructions and a few kilobytes; these are four orders above that.
    fn default() -> Self {
        Limits {
            memory_bytes: 16 << 20,
            instructions: 10_000_000,
        }
    }
}

/// How often the instruction hook runs; the budget is checked at this granularity.
const HOOK_EVERY: u32 = 1000;

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ScriptError {
    #[error("Lua syntax error in {chunk}: {message}")]
    Syntax { chunk: String, message: String },
    #[error("Lua error in {chunk}: {message}")]
    Runtime { chunk: String, message: String },
    #[error("Lua code in {chunk} ran past its budget of {limit} instructions (a runaway loop?)")]
    Budget { chunk: String, limit: u64 },
    #[error("Lua code in {chunk} ran past its memory limit of {limit} bytes")]
    Memory { chunk: String, limit: usize },
    #[error("`{name}` is not a Lua function defined in {chunk}")]
    NotAFunction { chunk: String, name: String },
    #[error("Lua function {name} returned {got} instead of a finite number")]
    NotANumber { name: String, got: String },
    #[error("cannot read Lua file {path}: {message}")]
    Io { path: String, message: String },
    /// A Lua file too large ([`crate::diag::MAX_LUA_BYTES`]) or not UTF-8.
    #[error(transparent)]
    Read(Box<crate::diag::ReadError>),
    #[error("Lua function {name} returned {got}; it must return exactly one finite number")]
    NotOneValue { name: String, got: String },
}

/// A compiled Lua function with the name used in messages.
#[derive(Clone, Debug)]
pub struct ScriptFn {
    f: mlua::Function,
    pub name: String,
}

/// One sandboxed Lua state.
pub struct Sandbox {
    lua: Lua,
    /// Compiled expressions by their text, for callers that evaluate one many times.
    compiled: std::collections::HashMap<String, ScriptFn>,
    used: Arc<AtomicU64>,
    exceeded: Arc<AtomicBool>,
    limits: Limits,
}

impl Sandbox {
    pub fn new(limits: Limits) -> Result<Sandbox, ScriptError> {
        let setup = |e: mlua::Error| ScriptError::Runtime {
            chunk: "sandbox set-up".into(),
            message: e.to_string(),
        };
        let lua = Lua::new_with(
            StdLib::MATH | StdLib::STRING | StdLib::TABLE,
            LuaOptions::default(),
        )
        .map_err(setup)?;
        let globals = lua.globals();
        for name in [
            "load",
            "loadstring",
            "dofile",
            "loadfile",
            "require",
            "collectgarbage",
            "print",
        ] {
            globals.set(name, Value::Nil).map_err(setup)?;
        }
        let string: mlua::Table = globals.get("string").map_err(setup)?;
        // Pattern matching runs in C, where the instruction hook never fires.
        for name in ["dump", "find", "match", "gmatch", "gsub"] {
            string.set(name, Value::Nil).map_err(setup)?;
        }
        lua.set_memory_limit(limits.memory_bytes).map_err(setup)?;
        let used = Arc::new(AtomicU64::new(0));
        let exceeded = Arc::new(AtomicBool::new(false));
        let (u, x, budget) = (used.clone(), exceeded.clone(), limits.instructions);
        lua.set_hook(
            HookTriggers::new().every_nth_instruction(HOOK_EVERY),
            move |_, _| {
                if u.fetch_add(HOOK_EVERY as u64, Ordering::Relaxed) + HOOK_EVERY as u64 > budget {
                    x.store(true, Ordering::Relaxed);
                    Err(mlua::Error::runtime("instruction budget exceeded"))
                } else {
                    Ok(VmState::Continue)
                }
            },
        )
        .map_err(setup)?;
        Ok(Sandbox {
            lua,
            compiled: std::collections::HashMap::new(),
            used,
            exceeded,
            limits,
        })
    }

    fn reset_budget(&self) {
        self.used.store(0, Ordering::Relaxed);
        self.exceeded.store(false, Ordering::Relaxed);
    }

    fn classify(&self, chunk: &str, e: mlua::Error) -> ScriptError {
        if self.exceeded.load(Ordering::Relaxed) {
            return ScriptError::Budget {
                chunk: chunk.into(),
                limit: self.limits.instructions,
            };
        }
        match innermost(&e) {
            mlua::Error::SyntaxError { message, .. } => ScriptError::Syntax {
                chunk: chunk.into(),
                message: message.clone(),
            },
            mlua::Error::MemoryError(_) => ScriptError::Memory {
                chunk: chunk.into(),
                limit: self.limits.memory_bytes,
            },
            mlua::Error::RuntimeError(m) => ScriptError::Runtime {
                chunk: chunk.into(),
                message: m.clone(),
            },
            other => ScriptError::Runtime {
                chunk: chunk.into(),
                message: other.to_string(),
            },
        }
    }

    /// Run a chunk of Lua source (typically defining functions). `chunk` names it in
    /// messages, e.g. the file path; Lua's own line numbers refer to `text`.
    pub fn run_source(&self, chunk: &str, text: &str) -> Result<(), ScriptError> {
        self.reset_budget();
        self.lua
            .load(text)
            .set_name(format!("@{chunk}"))
            .set_mode(ChunkMode::Text)
            .exec()
            .map_err(|e| self.classify(chunk, e))
    }

    /// Run a Lua file, read with [`read_lua_file`].
    pub fn run_file(&self, path: &Path) -> Result<(), ScriptError> {
        let text = read_lua_file(path)?;
        self.run_source(&path.display().to_string(), &text)
    }

    /// A global function defined by an earlier chunk.
    pub fn function(&self, name: &str, chunk: &str) -> Result<ScriptFn, ScriptError> {
        match self.lua.globals().get::<Value>(name) {
            Ok(Value::Function(f)) => Ok(ScriptFn {
                f,
                name: format!("{name} ({chunk})"),
            }),
            _ => Err(ScriptError::NotAFunction {
                chunk: chunk.into(),
                name: name.into(),
            }),
        }
    }

    /// Compile an expression in the given parameters, e.g. `("x + 2*y", ["x","y","z"])`.
    /// `chunk` names it in messages (e.g. `deck.i:12`).
    pub fn expression(
        &self,
        chunk: &str,
        expr: &str,
        params: &[&str],
    ) -> Result<ScriptFn, ScriptError> {
        // No parentheses around `expr`: they would keep the first of several values and
        // hide an expression that returns two (`math.modf(x)`, `x, y`), which
        // [`Sandbox::call`] refuses. The newline keeps a trailing `--` comment from
        // swallowing the `end`.
        let source = format!("return function({}) return {expr}\nend", params.join(", "));
        self.reset_budget();
        let f: mlua::Function = self
            .lua
            .load(source)
            .set_name(format!("={chunk}"))
            .set_mode(ChunkMode::Text)
            .eval()
            .map_err(|e| self.classify(chunk, e))?;
        Ok(ScriptFn {
            f,
            name: format!("`{expr}` ({chunk})"),
        })
    }

    /// A function compiled earlier and kept with [`Sandbox::cache`].
    pub fn cached(&self, text: &str) -> Option<ScriptFn> {
        self.compiled.get(text).cloned()
    }

    /// Keep a compiled function under its source text.
    pub fn cache(&mut self, text: &str, f: ScriptFn) {
        self.compiled.insert(text.to_string(), f);
    }

    /// Call a function with numeric arguments; it must return exactly one finite number
    /// (none, two or more are [`ScriptError::NotOneValue`], naming what came back).
    pub fn call(&self, f: &ScriptFn, args: &[f64]) -> Result<f64, ScriptError> {
        self.reset_budget();
        // Five numbers (a law's `T, x, y, z, t`) pushed as a tuple: no list made per call.
        let values: mlua::MultiValue = match *args {
            [a, b, c, d, e] => f.f.call((a, b, c, d, e)),
            _ => f.f.call(mlua::Variadic::from_iter(args.iter().copied())),
        }
        .map_err(|e| self.classify(&f.name, e))?;
        if values.len() != 1 {
            let shown: Vec<String> = values.iter().take(4).map(describe).collect();
            let more = if values.len() > 4 { ", …" } else { "" };
            let got = match values.len() {
                0 => "no value".to_string(),
                n => format!("{n} values ({}{more})", shown.join(", ")),
            };
            return Err(ScriptError::NotOneValue {
                name: f.name.clone(),
                got,
            });
        }
        let v = values.into_iter().next().unwrap_or(Value::Nil);
        match v {
            Value::Number(x) if x.is_finite() => Ok(x),
            Value::Integer(i) => Ok(i as f64),
            other => Err(ScriptError::NotANumber {
                name: f.name.clone(),
                got: describe(&other),
            }),
        }
    }
}

/// The text of a Lua file: at most [`crate::diag::MAX_LUA_BYTES`], UTF-8, a leading
/// byte-order mark dropped. For every reader of Lua files, so all share the bound.
pub fn read_lua_file(path: &Path) -> Result<String, ScriptError> {
    crate::diag::read_text(path, "Lua file", crate::diag::MAX_LUA_BYTES).map_err(|e| match e {
        crate::diag::ReadError::Io { path, message, .. } => ScriptError::Io { path, message },
        other => ScriptError::Read(Box::new(other)),
    })
}

fn describe(v: &Value) -> String {
    match v {
        Value::Number(x) => format!("{x}"),
        Value::Integer(i) => format!("{i}"),
        Value::String(s) => format!("the string {:?}", s.to_string_lossy()),
        Value::Nil => "nil".into(),
        other => other.type_name().to_string(),
    }
}

/// mlua wraps errors raised inside callbacks; the cause is what the user needs.
fn innermost(e: &mlua::Error) -> &mlua::Error {
    match e {
        mlua::Error::CallbackError { cause, .. } => innermost(cause),
        mlua::Error::WithContext { cause, .. } => innermost(cause),
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sandbox() -> Sandbox {
        Sandbox::new(Limits::default()).unwrap()
    }

    #[test]
    fn expressions_evaluate() {
        let s = sandbox();
        let f = s
            .expression("t", "x + 2*y - 3*z + math.sin(0)", &["x", "y", "z"])
            .unwrap();
        assert_eq!(s.call(&f, &[1.0, 2.0, 3.0]).unwrap(), 1.0 + 4.0 - 9.0);
    }

    #[test]
    fn escapes_are_refused() {
        let s = sandbox();
        for (code, needle) in [
            ("os.execute('true')", "os"),
            ("io.open('/etc/passwd')", "io"),
            ("require('x')", "require"),
            ("load('return 1')", "load"),
            ("dofile('/etc/passwd')", "dofile"),
            ("string.dump(function() end)", "dump"),
        ] {
            let err = s.run_source("escape.lua", code).unwrap_err();
            let msg = err.to_string();
            assert!(matches!(err, ScriptError::Runtime { .. }), "{code}: {msg}");
            assert!(msg.contains(needle), "{code}: {msg}");
        }
    }

    #[test]
    fn pattern_matching_is_not_offered() {
        // With `string.find` this backtracks for hours inside one C call.
        let s = sandbox();
        let code = "return string.find(string.rep('a', 400), string.rep('a*', 8) .. 'b')";
        let start = std::time::Instant::now();
        for (code, needle) in [
            (code, "find"),
            ("return ('x'):match('x')", "match"),
            ("return ('x'):gsub('x', 'y')", "gsub"),
            ("return string.gmatch('x', 'x')", "gmatch"),
        ] {
            let err = s.run_source("pattern.lua", code).unwrap_err();
            let msg = err.to_string();
            assert!(matches!(err, ScriptError::Runtime { .. }), "{code}: {msg}");
            assert!(msg.contains(needle), "{code}: {msg}");
        }
        assert!(start.elapsed() < std::time::Duration::from_secs(5));
        // The rest of the string library stays.
        let f = s
            .expression("len", "string.len(string.rep('ab', 3))", &[])
            .unwrap();
        assert_eq!(s.call(&f, &[]).unwrap(), 6.0);
    }

    #[test]
    fn runaway_loop_hits_the_budget() {
        let s = Sandbox::new(Limits {
            instructions: 100_000,
            ..Limits::default()
        })
        .unwrap();
        let err = s.run_source("loop.lua", "while true do end").unwrap_err();
        assert!(
            matches!(err, ScriptError::Budget { limit: 100_000, .. }),
            "{err}"
        );
        // The budget is per call: the sandbox stays usable.
        let f = s.expression("after", "1 + 1", &[]).unwrap();
        assert_eq!(s.call(&f, &[]).unwrap(), 2.0);
    }

    #[test]
    fn memory_bomb_hits_the_limit() {
        let s = Sandbox::new(Limits {
            memory_bytes: 4 << 20,
            instructions: u64::MAX / 2,
        })
        .unwrap();
        let err = s
            .run_source("bomb.lua", "local t = {} for i = 1, 1e9 do t[i] = i end")
            .unwrap_err();
        assert!(matches!(err, ScriptError::Memory { .. }), "{err}");
        let err = s
            .run_source("rep.lua", "local s = string.rep('x', 64 * 1024 * 1024)")
            .unwrap_err();
        assert!(matches!(err, ScriptError::Memory { .. }), "{err}");
    }

    #[test]
    fn syntax_errors_give_the_line() {
        let s = sandbox();
        let err = s
            .run_source("maps/twist.lua", "function f(x)\n  return x +\nend\n")
            .unwrap_err();
        let msg = err.to_string();
        assert!(matches!(err, ScriptError::Syntax { .. }), "{msg}");
        assert!(msg.contains("maps/twist.lua:3:"), "{msg}");
    }

    #[test]
    fn bytecode_is_refused() {
        let s = sandbox();
        let err = s.run_source("bin.lua", "\x1bLua\x54\x00").unwrap_err();
        assert!(err.to_string().contains("binary"), "{err}");
    }

    #[test]
    fn one_value_exactly() {
        let s = sandbox();
        for (expr, want) in [
            ("x, y", "returned 2 values (1, 2)"),
            ("math.modf(x + 0.5)", "returned 2 values (1, 0.5)"),
            ("x -- a comment", ""),
        ] {
            let f = s.expression("deck.i:3", expr, &["x", "y"]).unwrap();
            match s.call(&f, &[1.0, 2.0]) {
                Ok(v) => assert!(want.is_empty() && v == 1.0, "{expr}: {v}"),
                Err(e) => {
                    let msg = e.to_string();
                    assert!(matches!(e, ScriptError::NotOneValue { .. }), "{msg}");
                    assert!(msg.contains(want) && msg.contains(expr), "{expr}: {msg}");
                }
            }
        }
        s.run_source(
            "maps.lua",
            "function two(x) return x, x end function none(x) end",
        )
        .unwrap();
        let f = s.function("two", "maps.lua").unwrap();
        let msg = s.call(&f, &[3.0]).unwrap_err().to_string();
        assert!(
            msg.contains("two (maps.lua) returned 2 values (3, 3)"),
            "{msg}"
        );
        let f = s.function("none", "maps.lua").unwrap();
        let msg = s.call(&f, &[3.0]).unwrap_err().to_string();
        assert!(msg.contains("none (maps.lua) returned no value"), "{msg}");
    }

    #[test]
    fn lua_files_are_bounded() {
        let dir = std::env::temp_dir().join(format!("seam-lua-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let bom = dir.join("bom.lua");
        std::fs::write(&bom, "\u{feff}function f(x) return 2*x end\n").unwrap();
        let s = sandbox();
        s.run_file(&bom).unwrap();
        let f = s.function("f", "bom.lua").unwrap();
        assert_eq!(s.call(&f, &[2.0]).unwrap(), 4.0);
        let bad = dir.join("latin1.lua");
        std::fs::write(&bad, b"-- caf\xe9\nfunction f(x) return x end\n").unwrap();
        let msg = s.run_file(&bad).unwrap_err().to_string();
        assert!(
            msg.contains("not UTF-8") && msg.contains("line 1, column 7"),
            "{msg}"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn non_numbers_are_errors() {
        let s = sandbox();
        let f = s.expression("t", "x > 0 and 'yes' or nil", &["x"]).unwrap();
        assert!(matches!(
            s.call(&f, &[1.0]),
            Err(ScriptError::NotANumber { .. })
        ));
        let f = s.expression("t", "x / 0", &["x"]).unwrap();
        assert!(matches!(
            s.call(&f, &[1.0]),
            Err(ScriptError::NotANumber { .. })
        ));
    }
}
