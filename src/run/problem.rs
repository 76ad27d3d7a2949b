//! The problem file of `seam run` (TOML, the fields in `docs/run.md`): its typed form,
//! read and checked at the top level ([`ProblemFile::read`]), the time controls of
//! `[solve]` ([`time_spec`]) and where a value sits in the text, for diagnostics.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use super::{RunError, RunOptions, input_error};
use crate::deck;
use crate::diag::{Diagnostic, Diagnostics, SourceMap};
use crate::heat::transient::{self, Scheme};
use crate::mesh::{self, Mesh};

/// A number, a Lua expression, or a piecewise-linear table `{ table = [[s, v], …] }`
/// (in time t for boundary values, in temperature T for material laws).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    Number(f64),
    Expr(String),
    Table { table: Vec<(f64, f64)> },
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Problem {
    pub mesh: MeshSpec,
    #[serde(default)]
    pub material: Vec<MaterialSpec>,
    #[serde(default)]
    pub bc: Vec<BcSpec>,
    #[serde(default)]
    pub source: Vec<SourceSpec>,
    #[serde(default)]
    pub contact: Option<ContactSpec>,
    #[serde(default)]
    pub solve: SolveSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Initial temperature of a transient run (and the first guess of a nonlinear
    /// steady one).
    #[serde(default)]
    pub initial: Option<InitialSpec>,
    /// Continue from a checkpoint.
    #[serde(default)]
    pub restart: Option<RestartSpec>,
    /// Named on/off schedules for `Use Toggle Block`.
    #[serde(default)]
    pub toggle: Vec<ToggleSpec>,
    /// Named nodal fields (e.g. a contact pressure for `Contact Pressure Variable`).
    #[serde(default)]
    pub nodal_field: Vec<NodalFieldSpec>,
    /// A nodal displacement field that moves the contact surfaces in time.
    #[serde(default)]
    pub displacement: Option<DisplacementSpec>,
    /// Element death in time.
    #[serde(default)]
    pub death: Vec<DeathSpec>,
}

/// `[[death]]`: blocks or elements that die at a time. From then on they add nothing,
/// the nodes no live element holds keep their values, and the contact surfaces are
/// made again: a skinned block gains the faces the death exposes, a side-set surface
/// loses the faces of dead elements (the Sierra rule).
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DeathSpec {
    /// Element blocks (names, or `block_<id>`) whose elements die.
    #[serde(default)]
    pub blocks: Vec<String>,
    /// Elements that die, by their numbers in the mesh file (Exodus element ids, Gmsh
    /// element tags).
    #[serde(default)]
    pub elements: Vec<i64>,
    /// The time from which they are dead (s): a step ending at or after it is solved
    /// without them.
    pub time: f64,
}

/// `[displacement]`: the nodes' displacement u(X, t) (m), from Lua expressions or from
/// the nodal variables of an Exodus II result read over time. It moves the contact
/// surfaces (gaps, projections, overlaps); conduction stays on the mesh as read.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DisplacementSpec {
    /// One value per coordinate (two in a 2-D mesh): a number or a Lua expression of x,
    /// y, z (the node's place in the mesh as read) and t. Either this or `file`.
    #[serde(default)]
    pub value: Option<Vec<Value>>,
    /// An Exodus II result on the run's mesh (relative to the problem file) whose nodal
    /// variables hold the displacement at its stored times, interpolated linearly in
    /// between and held at the first and last stored times outside them.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// The nodal variables of `file`, one per coordinate (default `DISPLX`, `DISPLY`
    /// and, in 3-D, `DISPLZ`).
    #[serde(default)]
    pub variables: Option<Vec<String>>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialSpec {
    /// A number or a Lua expression of x, y, z.
    pub temperature: Value,
    /// The initial concentration of a species (mol/m³; 0 when not given): a number or a
    /// Lua expression of x, y, z.
    #[serde(default)]
    pub species: Option<Value>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RestartSpec {
    /// A checkpoint written by an earlier run (relative to the problem file).
    pub file: PathBuf,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ToggleSpec {
    pub name: String,
    /// Closed time intervals `[[t0, t1], …]` in which the enforcement is on.
    pub on: Vec<(f64, f64)>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NodalFieldSpec {
    pub name: String,
    /// A number or a Lua expression of x, y, z, t, evaluated at the nodes once, at the
    /// start time of the run. Either this or `file`.
    #[serde(default)]
    pub value: Option<Value>,
    /// An Exodus II file (relative to the problem file) on the run's mesh whose nodal
    /// variable `variable` holds the field.
    #[serde(default)]
    pub file: Option<PathBuf>,
    /// The nodal variable in `file` (default: `name`).
    #[serde(default)]
    pub variable: Option<String>,
    /// The stored time to read (default: the last step).
    #[serde(default)]
    pub time: Option<f64>,
    /// Or the step to read, 1 = the first stored.
    #[serde(default)]
    pub step: Option<usize>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    pub file: PathBuf,
    /// A 2-D mesh read as the section of a body of revolution: x is the radius r ≥ 0, y
    /// the axial coordinate; integrals, heats and fluxes are per full revolution.
    #[serde(default)]
    pub axisymmetric: bool,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub blocks: Vec<String>,
    /// k: a number, a Lua expression of T (and x, y, z, t), or a table in T.
    pub conductivity: Value,
    /// ρ (kg/m³): a number.
    #[serde(default)]
    pub density: Option<f64>,
    /// c_p (J/kg/K): a number, a Lua expression of T, or a table in T.
    #[serde(default)]
    pub specific_heat: Option<Value>,
    /// ρc_p (J/m³/K) in one number, instead of density and specific_heat.
    #[serde(default)]
    pub rho_c: Option<f64>,
    /// The name of the field these blocks carry (`temperature` by default); two
    /// fields are joined by `Side B Variable b To a`.
    #[serde(default)]
    pub field: Option<String>,
    /// σ (S/m): a number, a Lua expression of T (and x, y, z, t), or a table in T. Gives
    /// the blocks a `voltage` field, with its Joule heat σ|∇V|² in the temperature.
    #[serde(default)]
    pub electrical_conductivity: Option<Value>,
    /// D (m²/s): a number, a Lua expression of T (and x, y, z, t), or a table in T.
    /// Gives the blocks a `species` field (a concentration, mol/m³).
    #[serde(default)]
    pub diffusivity: Option<Value>,
    /// φ, the factor of ∂c/∂t in the species equation (default 1: c per unit volume of
    /// the body; the porosity for c per unit pore volume).
    #[serde(default)]
    pub species_capacity: Option<f64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BcKind {
    Temperature,
    Flux,
    Convection,
    /// εσ(T⁴ − T∞⁴): `value` is the emissivity ε, `ambient` T∞.
    Radiation,
    /// A nodal voltage (V), on blocks with an `electrical_conductivity`.
    Voltage,
    /// A current density into the body (A/m²) on faces of blocks with an
    /// `electrical_conductivity`.
    Current,
    /// A nodal concentration (mol/m³), on blocks with a `diffusivity`.
    Species,
    /// A species flux into the body (mol/m²/s) on faces of blocks with a `diffusivity`.
    SpeciesFlux,
}

/// Largest temperature (K) a problem file may give: far beyond any physical one, and
/// small enough that radiation's T⁴ and the squares of residuals stay finite.
pub const MAX_TEMPERATURE: f64 = 1e12;

/// Largest size of the other numbers a problem file gives (fluxes, coefficients,
/// sources, material properties): the product of two stays finite.
pub const MAX_MAGNITUDE: f64 = 1e100;

impl BcKind {
    /// Whether `v` is a value this kind of condition accepts; if not, the range it does.
    pub fn accepts(self, v: f64) -> Result<(), &'static str> {
        let (ok, range) = match self {
            BcKind::Temperature => (
                v.abs() <= MAX_TEMPERATURE,
                "a temperature is finite and within ±1e12 K",
            ),
            BcKind::Flux => (
                v.abs() <= MAX_MAGNITUDE,
                "a heat flux is finite and within ±1e100 W/m²",
            ),
            BcKind::Convection => (
                (0.0..=MAX_MAGNITUDE).contains(&v),
                "a heat-transfer coefficient is in [0, 1e100] W/m²K",
            ),
            BcKind::Radiation => (v > 0.0 && v <= 1.0, "an emissivity is in (0, 1]"),
            BcKind::Voltage => (
                v.abs() <= MAX_MAGNITUDE,
                "a voltage is finite and within ±1e100 V",
            ),
            BcKind::Current => (
                v.abs() <= MAX_MAGNITUDE,
                "a current density is finite and within ±1e100 A/m²",
            ),
            BcKind::Species => (
                (0.0..=MAX_MAGNITUDE).contains(&v),
                "a concentration is in [0, 1e100] mol/m³",
            ),
            BcKind::SpeciesFlux => (
                v.abs() <= MAX_MAGNITUDE,
                "a species flux is finite and within ±1e100 mol/m²/s",
            ),
        };
        if ok { Ok(()) } else { Err(range) }
    }

    /// The name as the problem file writes it.
    pub fn name(self) -> &'static str {
        match self {
            BcKind::Temperature => "temperature",
            BcKind::Flux => "flux",
            BcKind::Convection => "convection",
            BcKind::Radiation => "radiation",
            BcKind::Voltage => "voltage",
            BcKind::Current => "current",
            BcKind::Species => "species",
            BcKind::SpeciesFlux => "species_flux",
        }
    }
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BcSpec {
    pub kind: BcKind,
    pub surfaces: Vec<String>,
    pub value: Value,
    #[serde(default)]
    pub ambient: Option<f64>,
    /// Keep this flux or convection on faces in contact too (Aria's `no_coverage_flux`);
    /// by default it is masked there.
    #[serde(default)]
    pub no_coverage_flux: bool,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SourceSpec {
    pub blocks: Vec<String>,
    /// Q (W/m³): a number, a Lua expression of x, y, z, t and T (the local temperature),
    /// or a table in t.
    pub value: Value,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub file: PathBuf,
    #[serde(default)]
    pub integration: Option<String>,
    #[serde(default)]
    pub order: Option<usize>,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolveSpec {
    /// `steady` or `transient`.
    #[serde(default = "steady")]
    pub kind: String,
    /// `backward_euler` or `bdf2` (transient).
    #[serde(default)]
    pub scheme: Option<String>,
    /// The (first) time step.
    #[serde(default)]
    pub dt: Option<f64>,
    #[serde(default)]
    pub start_time: Option<f64>,
    #[serde(default)]
    pub end_time: Option<f64>,
    /// Adapt the step to keep the local error below `time_tolerance`.
    #[serde(default)]
    pub adaptive: bool,
    /// Local error per step, K (adaptive steps; default 1e-2).
    #[serde(default)]
    pub time_tolerance: Option<f64>,
    #[serde(default)]
    pub dt_min: Option<f64>,
    #[serde(default)]
    pub dt_max: Option<f64>,
    /// Time at which a steady problem's data are evaluated (default 0).
    #[serde(default)]
    pub time: Option<f64>,
    /// Sequential factorisations, so runs and restarts repeat bit for bit (default
    /// true; false lets the factorisation use every core).
    #[serde(default)]
    pub reproducible: Option<bool>,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    #[serde(default = "default_iterations")]
    pub max_iterations: usize,
    /// `auto` (the default: AMG-preconditioned CG for symmetric positive definite systems
    /// of at least `auto_threshold` unknowns, a direct factorisation otherwise), `direct`
    /// (sparse Cholesky, LDLᵀ or LU) or `amg` (CG with algebraic multigrid).
    #[serde(default)]
    pub linear_solver: Option<String>,
    /// The size from which `auto` picks AMG-CG (default
    /// [`AUTO_AMG_THRESHOLD`](crate::heat::steady::AUTO_AMG_THRESHOLD)); for tests and
    /// for machines where the crossover lies elsewhere.
    #[serde(default)]
    pub auto_threshold: Option<usize>,
}

impl Default for SolveSpec {
    fn default() -> Self {
        SolveSpec {
            kind: steady(),
            scheme: None,
            dt: None,
            start_time: None,
            end_time: None,
            adaptive: false,
            time_tolerance: None,
            dt_min: None,
            dt_max: None,
            time: None,
            reproducible: None,
            tolerance: default_tolerance(),
            max_iterations: default_iterations(),
            linear_solver: None,
            auto_threshold: None,
        }
    }
}

fn steady() -> String {
    "steady".into()
}
fn default_tolerance() -> f64 {
    1e-10
}
fn default_iterations() -> usize {
    20
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    #[serde(default)]
    pub dir: Option<PathBuf>,
    /// Write the fields every this many steps (and always the last step).
    #[serde(default)]
    pub every: Option<usize>,
    /// Write a checkpoint every this many steps (`checkpoint_<step>.seam`); the last
    /// step's is always written as `checkpoint.seam`.
    #[serde(default)]
    pub checkpoint_every: Option<usize>,
    /// How `.vtu` files store their arrays: `auto` (the default: decimal text up to
    /// [`AUTO_BINARY_POINTS`] points, base64 binary above), `ascii` or `binary`.
    #[serde(default)]
    pub vtu_format: VtuFormat,
}

/// The storage of a `.vtu` file's arrays.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum VtuFormat {
    #[default]
    Auto,
    Ascii,
    Binary,
}

/// Above this many points `vtu_format = "auto"` writes base64 binary: decimal text of a
/// million-node field is three times the bytes and most of the time of a run's output.
pub const AUTO_BINARY_POINTS: usize = 100_000;

impl OutputSpec {
    /// The encoding of a `.vtu` of `points` points.
    pub fn vtu_encoding(&self, points: usize) -> crate::output::vtu::VtuEncoding {
        use crate::output::vtu::VtuEncoding;
        match self.vtu_format {
            VtuFormat::Ascii => VtuEncoding::Ascii,
            VtuFormat::Binary => VtuEncoding::Base64,
            VtuFormat::Auto if points > AUTO_BINARY_POINTS => VtuEncoding::Base64,
            VtuFormat::Auto => VtuEncoding::Ascii,
        }
    }
}

/// A problem file read: its typed form, its text (for diagnostics), its folder (the
/// files it names are relative to it) and whether it asks for a transient solve.
pub(super) struct ProblemFile {
    pub problem: Problem,
    pub text: ProblemText,
    pub dir: PathBuf,
    pub transient: bool,
}

impl ProblemFile {
    /// Read `path` and check what needs nothing else: the TOML against the fields, the
    /// linear solver and the solve kind. Each failure is an input error.
    pub(super) fn read(path: &Path) -> Result<ProblemFile, RunError> {
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        // Bounded (a device or a mesh given by mistake is refused), UTF-8, BOM dropped.
        let text = crate::diag::read_text(path, "problem file", crate::diag::MAX_DECK_BYTES)
            .map_err(|e| {
                let mut sources = SourceMap::default();
                let mut d = crate::deck::read_error(&e, &mut sources);
                if d.code == crate::deck::codes::CANNOT_READ {
                    d.code = "E0700";
                }
                RunError::Input(Diagnostics(vec![d]), sources)
            })?;
        let problem: Problem = toml::from_str(&text).map_err(|e| {
            let file = crate::diag::file_label(path);
            let mut sources = SourceMap::default();
            sources.add(&file, &text);
            let loc = e.span().map(|r| {
                let before = &text[..r.start.min(text.len())];
                let line = before.matches('\n').count() as u32 + 1;
                let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) as u32 + 1;
                crate::diag::Loc::new(&file, line, col, (r.end - r.start).max(1) as u32)
            });
            let mut d = Diagnostics::default();
            d.push(
                Diagnostic::error("E0701", e.message().to_string())
                    .at(loc)
                    .help("see the problem-file fields in docs/run.md"),
            );
            RunError::Input(d, sources)
        })?;
        if let Some(ls) = problem.solve.linear_solver.as_deref()
            && ls != "auto"
            && ls != "direct"
            && ls != "amg"
        {
            return Err(input_error(
                "E0708",
                format!("unknown linear solver `{ls}`"),
                "use linear_solver = \"auto\" (the default), \"direct\" or \"amg\"",
            ));
        }
        let transient = match problem.solve.kind.as_str() {
            "steady" => false,
            "transient" => true,
            other => {
                return Err(input_error(
                    "E0709",
                    format!("unknown solve kind `{other}`"),
                    "use kind = \"steady\" or \"transient\"",
                ));
            }
        };
        let text = ProblemText {
            file: crate::diag::file_label(path),
            text,
        };
        Ok(ProblemFile {
            problem,
            text,
            dir,
            transient,
        })
    }

    /// The problem's mesh (`[mesh] file`), read as `[mesh] axisymmetric` says, and the
    /// seconds reading it took.
    pub(super) fn read_mesh(&self, options: &RunOptions) -> Result<(Mesh, f64), RunError> {
        let clock = Instant::now();
        options.phase("reading the mesh");
        let mut mesh = mesh::read(&self.dir.join(&self.problem.mesh.file))
            .map_err(|e| input_error("E0400", e.to_string(), "check [mesh] file"))?;
        if self.problem.mesh.axisymmetric
            && let Err(e) = mesh.set_axisymmetric()
        {
            let at = self.text.loc_in_table("mesh", "axisymmetric");
            let message = format!(
                "`axisymmetric = true`, {}: {e}",
                self.problem.mesh.file.display()
            );
            let mut d = Diagnostics::default();
            d.push(Diagnostic::error(e.code(), message).at(at).help(e.help()));
            return Err(RunError::Input(d, self.text.sources()));
        }
        Ok((mesh, clock.elapsed().as_secs_f64()))
    }
}

/// The problem file's text, for the line and column of a value in a diagnostic.
pub(super) struct ProblemText {
    pub file: std::sync::Arc<str>,
    pub text: String,
}

impl ProblemText {
    /// Where `key` of entry `k` of the array of tables `array` sits (the entry itself
    /// when it has no `key`).
    pub(super) fn loc(&self, array: &str, k: usize, key: &str) -> Option<crate::diag::Loc> {
        use toml::{Spanned, de::DeTable, de::DeValue};
        fn find<'a, 'i>(t: &'a DeTable<'i>, name: &str) -> Option<&'a Spanned<DeValue<'i>>> {
            t.iter().find(|(n, _)| n.get_ref() == name).map(|(_, v)| v)
        }
        let root = DeTable::parse(&self.text).ok()?;
        let entry = find(root.get_ref(), array)?.get_ref().as_array()?.get(k)?;
        let node = entry.get_ref().as_table().and_then(|t| find(t, key));
        let span = node.unwrap_or(entry).span();
        Some(deck::byte_span_loc(&self.file, &self.text, span))
    }

    /// Where `key` of the table `table` sits (the table's header when it has no `key`).
    pub(super) fn loc_in_table(&self, table: &str, key: &str) -> Option<crate::diag::Loc> {
        use toml::de::DeTable;
        let root = DeTable::parse(&self.text).ok()?;
        let (_, entry) = root.get_ref().iter().find(|(n, _)| n.get_ref() == table)?;
        let node = entry
            .get_ref()
            .as_table()
            .and_then(|t| t.iter().find(|(n, _)| n.get_ref() == key).map(|(_, v)| v));
        let span = node.unwrap_or(entry).span();
        Some(deck::byte_span_loc(&self.file, &self.text, span))
    }

    pub(super) fn sources(&self) -> SourceMap {
        let mut s = SourceMap::default();
        s.add(&self.file, &self.text);
        s
    }
}

/// The time controls of `[solve]`, checked.
pub(super) struct TimeSpec {
    pub start: f64,
    pub end: f64,
    pub dt: f64,
    pub dt_min: f64,
    pub scheme: Scheme,
    pub adaptive: Option<transient::Adaptive>,
}

pub(super) fn time_spec(p: &Problem, transient: bool, diags: &mut Diagnostics) -> TimeSpec {
    let s = &p.solve;
    let start = s.start_time.or(s.time).unwrap_or(0.0);
    let mut spec = TimeSpec {
        start,
        end: start,
        dt: 1.0,
        dt_min: 0.0,
        scheme: Scheme::BackwardEuler,
        adaptive: None,
    };
    if !transient {
        return spec;
    }
    let mut err =
        |m: String, help: &str| diags.push(Diagnostic::error("E0710", m).help(help.to_string()));
    spec.scheme = match s.scheme.as_deref() {
        None | Some("bdf2") => Scheme::Bdf2,
        Some("backward_euler") => Scheme::BackwardEuler,
        Some(other) => {
            err(
                format!("unknown time scheme `{other}`"),
                "use scheme = \"backward_euler\" or \"bdf2\"",
            );
            Scheme::Bdf2
        }
    };
    match (s.dt, s.end_time) {
        (Some(dt), Some(end)) if dt > 0.0 && dt.is_finite() && end > start => {
            spec.dt = dt;
            spec.end = end;
        }
        (Some(dt), Some(end)) => err(
            format!(
                "[solve]: need dt > 0 and end_time > start_time, found dt = {dt}, end_time = {end}, start = {start}"
            ),
            "set dt and end_time in [solve]",
        ),
        _ => err(
            "a transient run needs `dt` and `end_time` in [solve]".into(),
            "e.g. dt = 0.1, end_time = 10",
        ),
    }
    if p.initial.is_none() && p.restart.is_none() {
        err(
            "a transient run needs an initial temperature".into(),
            "add [initial] temperature = 293.15 (a number or a Lua expression of x, y, z)",
        );
    }
    spec.dt_min = s.dt_min.unwrap_or(spec.dt * 1e-6);
    if s.adaptive {
        spec.adaptive = Some(transient::Adaptive {
            tolerance: s.time_tolerance.unwrap_or(1e-2),
            dt_min: spec.dt_min,
            dt_max: s.dt_max.unwrap_or(spec.end - spec.start),
        });
    }
    spec
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::vtu::VtuEncoding;

    #[test]
    fn vtu_format_auto_switches_to_binary_above_the_threshold() {
        let spec = |text: &str| -> OutputSpec { toml::from_str(text).unwrap() };
        let auto = spec("");
        assert_eq!(auto.vtu_encoding(AUTO_BINARY_POINTS), VtuEncoding::Ascii);
        assert_eq!(
            auto.vtu_encoding(AUTO_BINARY_POINTS + 1),
            VtuEncoding::Base64
        );
        assert_eq!(
            spec("vtu_format = \"binary\"").vtu_encoding(8),
            VtuEncoding::Base64
        );
        assert_eq!(
            spec("vtu_format = \"ascii\"").vtu_encoding(10 * AUTO_BINARY_POINTS),
            VtuEncoding::Ascii
        );
        assert!(toml::from_str::<OutputSpec>("vtu_format = \"hex\"").is_err());
    }
}
