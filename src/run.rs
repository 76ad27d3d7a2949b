//! `seam run`: a heat-transfer problem file (TOML) solved end to end — mesh, materials,
//! boundary conditions, sources, the Sierra contact definition, the steady solve, the
//! results (`.vtu`) and a summary.
//!
//! Entry point: [`run`]. Field by field:
//!
//! ```toml
//! [mesh]
//! file = "two_blocks.exo"            # Exodus II or Gmsh 4.1, relative to this file
//! [[material]]
//! blocks = ["block_1", "block_2"]
//! conductivity = 1.0                 # W/m/K
//! [[bc]]
//! kind = "temperature"               # temperature | flux | convection
//! surfaces = ["surface_1"]           # side sets (or node sets, for temperature)
//! value = "1 + x + 2*y - 3*z"        # a number or a Lua expression of x, y, z, t
//! ambient = 300.0                    # convection only: T∞ (value is then h)
//! [[source]]                         # optional volumetric source (W/m³)
//! blocks = ["block_1"]
//! value = "0"
//! [contact]
//! file = "contact.i"                 # Sierra-syntax contact definition(s)
//! integration = "segments"           # segments (exact, default) | quadrature
//! order = 5
//! [solve]
//! kind = "steady"
//! tolerance = 1e-10
//! max_iterations = 20
//! [output]
//! dir = "out"
//! ```
//!
//! A flux or convection value given as a Lua expression is evaluated at each face's
//! centroid; temperature values at the nodes; sources at the nodes and interpolated
//! (each exact for the linear fields of a patch test). The time `t` is 0 in a steady
//! solve.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::deck::{self, LoadedDeck};
use crate::diag::{Diagnostic, Diagnostics, SourceMap, did_you_mean};
use crate::enforce::conductance::{self, ConductanceModel, PointState};
use crate::enforce::interface::{DEFAULT_BETA, Form, HFn, HInput, HValue, InterfaceForm};
use crate::enforce::model::{ConductanceLaw, resolve as resolve_model};
use crate::heat::steady::{ContactTerm, SteadyProblem, SteadySolution, TieTerm, solve_steady};
use crate::heat::{FaceBc, Material};
use crate::interaction;
use std::collections::HashSet;

use crate::mesh::{self, Mesh, NodeId, Side};
use crate::output::vtu::write_vtu;
use crate::script::{Limits, Sandbox};
use crate::search::pairing::{Integration, PointStatus};
use crate::search::scene::{Pairing, search_definition};
use crate::surface;

/// A number or a Lua expression.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    Number(f64),
    Expr(String),
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
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    pub file: PathBuf,
}

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub blocks: Vec<String>,
    pub conductivity: Value,
    #[serde(default)]
    pub rho_c: Option<f64>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BcKind {
    Temperature,
    Flux,
    Convection,
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
    #[serde(default = "steady")]
    pub kind: String,
    #[serde(default = "default_tolerance")]
    pub tolerance: f64,
    #[serde(default = "default_iterations")]
    pub max_iterations: usize,
    /// `direct` (sparse Cholesky/LU, default) or `amg` (CG with algebraic multigrid, for
    /// large symmetric problems).
    #[serde(default)]
    pub linear_solver: Option<String>,
}

impl Default for SolveSpec {
    fn default() -> Self {
        SolveSpec {
            kind: steady(),
            tolerance: default_tolerance(),
            max_iterations: default_iterations(),
            linear_solver: None,
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
}

/// One interaction's line in the summary.
#[derive(Clone, Debug, Serialize)]
pub struct InteractionHeat {
    pub side_a: String,
    pub side_b: String,
    pub model: String,
    pub heat_side_a: f64,
    pub heat_side_b: f64,
    pub imbalance: f64,
}

#[derive(Clone, Copy, Debug, Default, Serialize)]
pub struct Timing {
    pub surfaces_s: f64,
    pub search_s: f64,
    pub assembly_s: f64,
    pub factor_s: f64,
    pub solve_s: f64,
    pub total_s: f64,
}

/// The `--json` summary (an interface: keys are stable).
#[derive(Clone, Debug, Serialize)]
pub struct Summary {
    pub dofs: usize,
    pub newton_iterations: usize,
    pub converged: bool,
    pub interactions: Vec<InteractionHeat>,
    pub timing: Timing,
    pub output: Option<PathBuf>,
}

/// What went wrong: bad input (diagnostics) or a solve that failed.
#[derive(Debug)]
pub enum RunError {
    Input(Diagnostics, SourceMap),
    Solve(String),
}

/// Everything a run made, for callers that want more than the summary.
pub struct RunResult {
    pub summary: Summary,
    pub mesh: Mesh,
    pub solution: SteadySolution,
    pub warnings: Diagnostics,
    pub sources: SourceMap,
}

fn input_error(code: &'static str, message: String, help: &str) -> RunError {
    let mut d = Diagnostics::default();
    d.push(Diagnostic::error(code, message).help(help));
    RunError::Input(d, SourceMap::default())
}

/// Solve the problem in `path`.
pub fn run(path: &Path) -> Result<RunResult, RunError> {
    let start = Instant::now();
    let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
    let text = std::fs::read_to_string(path).map_err(|e| {
        input_error(
            "E0700",
            format!("cannot read problem file {}: {e}", path.display()),
            "check the path",
        )
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
        && ls != "direct"
        && ls != "amg"
    {
        return Err(input_error(
            "E0708",
            format!("unknown linear solver `{ls}`"),
            "use linear_solver = \"direct\" or \"amg\"",
        ));
    }
    if problem.solve.kind != "steady" {
        return Err(input_error(
            "E0900",
            format!(
                "`[solve] kind = \"{}\"` is recognised but not carried out by this version of seam",
                problem.solve.kind
            ),
            "use kind = \"steady\"",
        ));
    }
    let mesh = mesh::read(&dir.join(&problem.mesh.file))
        .map_err(|e| input_error("E0400", e.to_string(), "check [mesh] file"))?;
    let mut diags = Diagnostics::default();
    let mut sandbox = None;
    let materials = materials(&problem, &mesh, &mut diags);
    let dirichlet = dirichlet(&problem, &mesh, &mut sandbox, &mut diags);
    let mut face_bcs = face_bcs(&problem, &mesh, &mut sandbox, &mut diags);
    let source = nodal_source(&problem, &mesh, &mut diags);
    if diags.has_errors() {
        return Err(RunError::Input(diags, SourceMap::default()));
    }

    // Contact: surfaces, interactions, search, enforcement per interaction.
    let mut timing = Timing::default();
    let mut loaded = LoadedDeck::default();
    let mut pairings: Vec<Pairing> = Vec::new();
    let mut choices = Vec::new();
    if let Some(c) = &problem.contact {
        let deck_path = dir.join(&c.file);
        loaded = deck::load(&deck_path);
        if loaded.diagnostics.has_errors() {
            return Err(RunError::Input(loaded.diagnostics, loaded.sources));
        }
        let integration = match c.integration.as_deref() {
            None | Some("segments") => Integration::Segments {
                order: c.order.unwrap_or(5),
            },
            Some("quadrature") => Integration::Quadrature {
                order: c.order.unwrap_or(2),
            },
            Some(other) => {
                return Err(input_error(
                    "E0702",
                    format!("unknown integration `{other}`"),
                    "use \"segments\" or \"quadrature\"",
                ));
            }
        };
        let deck_dir = deck_path.parent().unwrap_or(Path::new(".")).to_path_buf();
        for def in &loaded.deck.contact_definitions {
            let t = Instant::now();
            let set = surface::build(&mesh, def, &loaded.sources);
            timing.surfaces_s += t.elapsed().as_secs_f64();
            diags.extend(set.diagnostics.clone());
            let (list, d) = interaction::resolve(def, &set, mesh.dim, &loaded.sources);
            diags.extend(d);
            if diags.has_errors() {
                continue;
            }
            let t = Instant::now();
            let scene = search_definition(
                &mesh,
                def,
                &set,
                &list,
                &deck_dir,
                &loaded.sources,
                integration,
            );
            timing.search_s += t.elapsed().as_secs_f64();
            diags.extend(scene.diagnostics);
            for p in scene.pairings {
                // The interaction's enforcement: by name, or the only block there is.
                let named = list
                    .iter()
                    .find(|i| i.side_a_name == p.side_a && i.side_b_name == p.side_b)
                    .and_then(|i| i.enforcement.clone());
                let enf = match &named {
                    Some(n) => def
                        .enforcements
                        .iter()
                        .find(|e| e.name.as_deref() == Some(n.as_str())),
                    None => def.enforcements.first(),
                };
                let Some(enf) = enf else {
                    diags.push(
                        Diagnostic::error(
                            "E0426",
                            format!("interaction {} / {} has no enforcement", p.side_a, p.side_b),
                        )
                        .at(Some(def.at.clone()))
                        .help("add a `begin Enforcement` block with `Enforcement for Energy = …`"),
                    );
                    continue;
                };
                match resolve_model(enf) {
                    Ok(choice) => {
                        let tied = matches!(
                            choice.form,
                            Form::TiedNitsche | Form::TiedInteriorPenalty | Form::Penalty
                        );
                        if tied && p.result.stats.matched == 0 {
                            diags.push(
                                Diagnostic::error(
                                    "E0427",
                                    format!("`{}` ties {} / {}, but the two surfaces do not overlap anywhere", choice.name, p.side_a, p.side_b),
                                )
                                .at(Some(enf.at.clone()))
                                .help("check the surfaces of the interaction; `seam search` shows why points did not pair"),
                            );
                            continue;
                        }
                        let scale = list
                            .iter()
                            .find(|i| i.side_a_name == p.side_a && i.side_b_name == p.side_b)
                            .map_or(1.0, |i| i.penalty_scale);
                        let model: Option<Box<dyn ConductanceModel>> = match choice.conductance {
                            Some(ConductanceLaw::Constant(h)) => Some(Box::new(
                                conductance::Constant::new(h).expect("h checked non-negative"),
                            )),
                            Some(ConductanceLaw::Coefficient) => {
                                let (m, d) =
                                    conductance::from_properties(enf, &deck_dir, &loaded.sources);
                                diags.extend(d);
                                if m.is_none() {
                                    continue;
                                }
                                m
                            }
                            Some(ConductanceLaw::Plugin) => {
                                let loaded_plugin =
                                    crate::plugin::PluginSpec::from_enforcement(enf, &deck_dir)
                                        .and_then(|spec| spec.load())
                                        .map_err(|e| e.to_string())
                                        .and_then(|pl| {
                                            conductance::PluginConductance::new(pl)
                                                .map(|c| c.on_surfaces(&p.side_a, &p.side_b))
                                                .map_err(|e| e.to_string())
                                        });
                                match loaded_plugin {
                                    Ok(c) => {
                                        if let Some(notice) = c.plugin().derivative_notice() {
                                            diags.push(
                                                Diagnostic::warning("W0502", notice)
                                                    .at(Some(enf.at.clone()))
                                                    .help("a plugin that returns its own derivatives (PROVIDES_DERIVATIVES) saves those calls"),
                                            );
                                        }
                                        Some(Box::new(c) as Box<dyn ConductanceModel>)
                                    }
                                    Err(e) => {
                                        diags.push(
                                            Diagnostic::error("E0500", e)
                                                .at(Some(enf.at.clone()))
                                                .help("`seam check-plugin LIB` loads and probes a plugin on its own"),
                                        );
                                        continue;
                                    }
                                }
                            }
                            None => None,
                        };
                        choices.push((choice, scale, model));
                        pairings.push(p);
                    }
                    Err(ds) => ds.into_iter().for_each(|d| diags.push(d)),
                }
            }
        }
    }
    if diags.has_errors() {
        return Err(RunError::Input(diags, loaded.sources));
    }

    // Aria masks ordinary flux and convection conditions on faces in contact: a side-A
    // face with matched points, or a side-B face some point paired with. A condition
    // with `no_coverage_flux = true` stays.
    let mut in_contact: HashSet<Side> = HashSet::new();
    for p in &pairings {
        if p.periodic {
            continue;
        }
        for q in p
            .result
            .points
            .iter()
            .filter(|q| q.status == PointStatus::Matched)
        {
            if q.a_face != u32::MAX {
                in_contact.insert(p.side_a_geometry.faces[q.a_face as usize].side);
            }
            in_contact.insert(p.side_b_geometry.faces[q.b_face as usize].side);
        }
    }
    let before = face_bcs.len();
    face_bcs.retain(|(bc, keep)| *keep || !in_contact.contains(&bc_side(bc)));
    let masked = before - face_bcs.len();
    if masked > 0 {
        diags.push(
            Diagnostic::warning(
                "W0701",
                format!("{masked} face condition(s) on faces in contact are masked (Aria's rule)"),
            )
            .help("set `no_coverage_flux = true` in the [[bc]] to keep a condition on faces in contact"),
        );
    }
    let face_bcs: Vec<FaceBc> = face_bcs.into_iter().map(|(bc, _)| bc).collect();
    let conductivity: Vec<f64> = materials.iter().map(|m| m.conductivity).collect();
    // Each conductance model seen by the interface forms: the point's gap and
    // temperatures and the enforcement's contact pressure in, h and dh/dT out.
    // Per interaction: the points a model failed at, with the reason (quarantine).
    type Quarantined = std::cell::RefCell<Vec<([f64; 3], String)>>;
    let quarantined: Vec<Quarantined> = choices.iter().map(|_| Default::default()).collect();
    let h_fns: Vec<Box<HFn<'_>>> = choices
        .iter()
        .zip(&quarantined)
        .zip(&pairings)
        .map(|(((choice, _, model), log), pairing)| {
            let pressure = choice.pressure;
            let quarantine = choice.quarantine;
            let label = format!(
                "interaction {} / {} ({})",
                pairing.side_a, pairing.side_b, choice.name
            );
            let f = move |p: &HInput| -> Result<HValue, String> {
                let Some(m) = model else {
                    return Ok(HValue::default());
                };
                let state = PointState {
                    gap: p.gap,
                    pressure,
                    temp_a: p.temp_a,
                    temp_b: p.temp_b,
                    x: p.x,
                    time: 0.0,
                };
                let c = match m.evaluate(&state) {
                    Ok(c) => c,
                    // Quarantine: the point contributes nothing; it is reported after the
                    // run. Each Newton step evaluates it again, so keep it once.
                    Err(e) if quarantine => {
                        let mut log = log.borrow_mut();
                        if !log.iter().any(|(x, _)| *x == p.x) {
                            log.push((p.x, e.to_string()));
                        }
                        return Ok(HValue::default());
                    }
                    Err(e) => {
                        return Err(format!(
                            "{label}: {e} (add `Quarantine Faulty Points` to the enforcement to skip such points)"
                        ));
                    }
                };
                Ok(HValue {
                    h: c.h,
                    dh_dtemp_a: c.dh_dtemp_a,
                    dh_dtemp_b: c.dh_dtemp_b,
                })
            };
            Box::new(f) as Box<HFn<'_>>
        })
        .collect();
    let contact: Vec<ContactTerm<'_>> = pairings
        .iter()
        .zip(&choices)
        .zip(&h_fns)
        .filter(|((_, (c, _, _)), _)| !c.mortar)
        .map(|((p, (c, scale, model)), h)| ContactTerm {
            side_a: &p.side_a_geometry,
            side_b: &p.side_b_geometry,
            points: &p.result.points,
            form: InterfaceForm {
                form: c.form,
                h: h.as_ref(),
                offset: c.offset,
                beta: c.penalty_factor.unwrap_or(DEFAULT_BETA) * scale,
                conductivity: &conductivity,
            },
            // A constant conductance keeps the system linear and symmetric.
            linear: model.as_ref().is_none_or(|m| m.name() == "constant"),
        })
        .collect();
    let ties: Vec<TieTerm<'_>> = pairings
        .iter()
        .zip(&choices)
        .filter(|(_, (c, _, _))| c.mortar)
        .map(|(p, (c, _, _))| TieTerm {
            side_a: &p.side_a_geometry,
            side_b: &p.side_b_geometry,
            points: &p.result.points,
            offset: c.offset,
            multipliers: if c.dual {
                crate::enforce::mortar::Multipliers::Dual
            } else {
                crate::enforce::mortar::Multipliers::Standard
            },
        })
        .collect();
    let source_fn = source
        .as_ref()
        .map(|s| s as &(dyn Fn([f64; 3]) -> f64 + Sync));
    let steady = SteadyProblem {
        mesh: &mesh,
        materials: &materials,
        source: source_fn,
        dirichlet: &dirichlet,
        face_bcs: &face_bcs,
        contact,
        ties,
        iterative: problem.solve.linear_solver.as_deref() == Some("amg"),
        tolerance: problem.solve.tolerance,
        max_iterations: problem.solve.max_iterations,
    };
    let solution = solve_steady(&steady).map_err(|e| RunError::Solve(e.to_string()))?;
    for ((p, (c, _, _)), log) in pairings.iter().zip(&choices).zip(&quarantined) {
        let log = log.borrow();
        if let Some((x, first)) = log.first() {
            diags.push(
                Diagnostic::warning(
                    "W0501",
                    format!(
                        "interaction {} / {} ({}): {} point(s) quarantined; the first at ({:.6}, {:.6}, {:.6}): {first}",
                        p.side_a, p.side_b, c.name, log.len(), x[0], x[1], x[2]
                    ),
                )
                .help("the conductance model failed there; those points carry no heat"),
            );
        }
    }
    timing.assembly_s = solution.timing.assembly_s;
    timing.factor_s = solution.timing.factor_s;
    timing.solve_s = solution.timing.solve_s;

    let output = match &problem.output.dir {
        Some(d) => {
            let out_dir = dir.join(d);
            std::fs::create_dir_all(&out_dir).map_err(|e| {
                RunError::Solve(format!("cannot create {}: {e}", out_dir.display()))
            })?;
            let file = out_dir.join("temperature.vtu");
            write_vtu(&file, &mesh, &[("temperature", &solution.temperature)])
                .map_err(|e| RunError::Solve(format!("cannot write {}: {e}", file.display())))?;
            Some(file)
        }
        None => None,
    };
    // Heat per pairing, in pairing order: flux-type terms and ties were solved apart.
    let (mut flux_heat, mut tie_heat) = (solution.heat.iter(), solution.tie_heat.iter());
    let heats: Vec<(f64, f64)> = choices
        .iter()
        .map(|(c, _, _)| {
            let next = if c.mortar {
                tie_heat.next()
            } else {
                flux_heat.next()
            };
            next.copied().unwrap_or((0.0, 0.0))
        })
        .collect();
    for (t, cps) in solution.crosspoints.iter().enumerate() {
        if !cps.is_empty() {
            let numbers: Vec<String> = cps
                .iter()
                .take(10)
                .map(|n| mesh.node_number(*n).to_string())
                .collect();
            diags.push(
                Diagnostic::warning(
                    "W0430",
                    format!(
                        "tie #{}: {} side-A node(s) already constrained (Dirichlet data or an earlier tie) get no multiplier: {}{}",
                        t + 1,
                        cps.len(),
                        numbers.join(", "),
                        if cps.len() > 10 { ", …" } else { "" }
                    ),
                )
                .help("a crosspoint keeps its Dirichlet value (or its first tie); this keeps the system non-singular"),
            );
        }
    }
    let interactions = pairings
        .iter()
        .zip(&choices)
        .zip(&heats)
        .map(|((p, (c, _, _)), &(a, b))| InteractionHeat {
            side_a: p.side_a.clone(),
            side_b: p.side_b.clone(),
            model: c.name.clone(),
            heat_side_a: a,
            heat_side_b: b,
            imbalance: a + b,
        })
        .collect();
    timing.total_s = start.elapsed().as_secs_f64();
    let summary = Summary {
        dofs: solution.dofs.len(),
        newton_iterations: solution.newton_iterations,
        converged: solution.converged,
        interactions,
        timing,
        output,
    };
    Ok(RunResult {
        summary,
        mesh,
        solution,
        warnings: diags,
        sources: loaded.sources,
    })
}

fn block_index(mesh: &Mesh, name: &str, diags: &mut Diagnostics, what: &str) -> Option<usize> {
    let found = mesh.find_block(name);
    if found.is_none() {
        let names: Vec<String> = mesh.blocks.iter().map(|b| b.sierra_name()).collect();
        let help = did_you_mean(name, names.iter().map(String::as_str)).map_or_else(
            || format!("the blocks are: {}", names.join(", ")),
            |s| format!("did you mean `{s}`?"),
        );
        diags
            .push(Diagnostic::error("E0703", format!("{what}: unknown block `{name}`")).help(help));
    }
    found
}

fn materials(p: &Problem, mesh: &Mesh, diags: &mut Diagnostics) -> Vec<Material> {
    let mut out: Vec<Option<Material>> = vec![None; mesh.blocks.len()];
    for m in &p.material {
        let k = match &m.conductivity {
            Value::Number(k) if *k > 0.0 && k.is_finite() => *k,
            Value::Number(k) => {
                diags.push(
                    Diagnostic::error("E0704", format!("conductivity must be positive, found {k}"))
                        .help("give k in W/m/K"),
                );
                continue;
            }
            Value::Expr(e) => {
                diags.push(
                    Diagnostic::error("E0900", format!("conductivity as a Lua expression of T (`{e}`) is recognised but not carried out by this version of seam"))
                        .help("give a number meanwhile"),
                );
                continue;
            }
        };
        for b in &m.blocks {
            if let Some(i) = block_index(mesh, b, diags, "[[material]]") {
                out[i] = Some(Material {
                    conductivity: k,
                    rho_c: m.rho_c.unwrap_or(1.0),
                });
            }
        }
    }
    let mut result = Vec::with_capacity(out.len());
    for (i, m) in out.into_iter().enumerate() {
        match m {
            Some(m) => result.push(m),
            None => {
                if mesh.blocks[i].topology.is_solid() {
                    diags.push(
                        Diagnostic::error(
                            "E0705",
                            format!("block {} has no material", mesh.blocks[i].sierra_name()),
                        )
                        .help("add it to the `blocks` of a [[material]]"),
                    );
                }
                result.push(Material {
                    conductivity: 1.0,
                    rho_c: 1.0,
                });
            }
        }
    }
    result
}

/// Evaluate a value at a point: numbers directly, expressions in a sandbox shared by the
/// run (built on first use).
fn evaluate(
    v: &Value,
    x: [f64; 3],
    sandbox: &mut Option<Sandbox>,
    chunk: &str,
) -> Result<f64, String> {
    match v {
        Value::Number(n) => Ok(*n),
        Value::Expr(e) => {
            if sandbox.is_none() {
                *sandbox = Some(Sandbox::new(Limits::default()).map_err(|e| e.to_string())?);
            }
            let s = sandbox.as_mut().expect("just built");
            // Compile each expression once per run: the sandbox keeps them by text.
            let f = match s.cached(e) {
                Some(f) => f,
                None => {
                    let f = s
                        .expression(chunk, e, &["x", "y", "z", "t"])
                        .map_err(|e| e.to_string())?;
                    s.cache(e, f.clone());
                    f
                }
            };
            s.call(&f, &[x[0], x[1], x[2], 0.0])
                .map_err(|e| e.to_string())
        }
    }
}

fn dirichlet(
    p: &Problem,
    mesh: &Mesh,
    sandbox: &mut Option<Sandbox>,
    diags: &mut Diagnostics,
) -> Vec<(NodeId, f64)> {
    let mut out = Vec::new();
    for bc in p.bc.iter().filter(|b| b.kind == BcKind::Temperature) {
        let mut nodes = Vec::new();
        for s in &bc.surfaces {
            if let Some(i) = mesh.find_side_set(s) {
                for &side in &mesh.side_sets[i].sides {
                    nodes.extend(mesh.side_nodes(side));
                }
            } else if let Some(i) = mesh.find_node_set(s) {
                nodes.extend_from_slice(&mesh.node_sets[i].nodes);
            } else {
                diags.push(
                    Diagnostic::error(
                        "E0706",
                        format!("[[bc]]: unknown side set or node set `{s}`"),
                    )
                    .help("bc surfaces name side sets (surface_<id> or their names) or node sets"),
                );
            }
        }
        nodes.sort_unstable();
        nodes.dedup();
        for n in nodes {
            match evaluate(&bc.value, mesh.coords[n.index()], sandbox, "[[bc]] value") {
                Ok(v) => out.push((n, v)),
                Err(e) => {
                    diags.push(
                        Diagnostic::error("E0707", format!("[[bc]] value: {e}"))
                            .help("a number or a Lua expression of x, y, z, t"),
                    );
                    return out;
                }
            }
        }
    }
    out
}

fn bc_side(bc: &FaceBc) -> Side {
    match *bc {
        FaceBc::Flux { side, .. } | FaceBc::Convection { side, .. } => side,
    }
}

/// Every face condition, with whether it opts out of masking on faces in contact.
fn face_bcs(
    p: &Problem,
    mesh: &Mesh,
    sandbox: &mut Option<Sandbox>,
    diags: &mut Diagnostics,
) -> Vec<(FaceBc, bool)> {
    let mut out = Vec::new();
    for bc in p.bc.iter().filter(|b| b.kind != BcKind::Temperature) {
        for s in &bc.surfaces {
            let Some(i) = mesh.find_side_set(s) else {
                diags.push(
                    Diagnostic::error("E0706", format!("[[bc]]: unknown side set `{s}`"))
                        .help("flux and convection conditions act on side sets"),
                );
                continue;
            };
            for &side in &mesh.side_sets[i].sides {
                let nodes: Vec<_> = mesh.side_nodes(side).collect();
                let mut c = [0.0; 3];
                for n in &nodes {
                    for (cd, xd) in c.iter_mut().zip(mesh.coords[n.index()]) {
                        *cd += xd / nodes.len() as f64;
                    }
                }
                let v = match evaluate(&bc.value, c, sandbox, "[[bc]] value") {
                    Ok(v) => v,
                    Err(e) => {
                        diags.push(
                            Diagnostic::error("E0707", format!("[[bc]] value: {e}"))
                                .help("a number or a Lua expression of x, y, z, t"),
                        );
                        return out;
                    }
                };
                let face = match bc.kind {
                    BcKind::Flux => FaceBc::Flux { side, q: v },
                    _ => FaceBc::Convection {
                        side,
                        h: v,
                        t_inf: bc.ambient.unwrap_or(0.0),
                    },
                };
                out.push((face, bc.no_coverage_flux));
            }
        }
    }
    out
}

/// The volumetric source: one number over every block (a Lua expression or a source on
/// some blocks only is reported as not carried out yet).
fn nodal_source(
    p: &Problem,
    mesh: &Mesh,
    diags: &mut Diagnostics,
) -> Option<impl Fn([f64; 3]) -> f64 + Sync + use<>> {
    let mut constant = None;
    for s in &p.source {
        for b in &s.blocks {
            block_index(mesh, b, diags, "[[source]]");
        }
        match &s.value {
            Value::Number(q) => constant = Some(*q),
            Value::Expr(e) => match e.trim().parse::<f64>() {
                Ok(q) => constant = Some(q),
                Err(_) => diags.push(
                    Diagnostic::error("E0900", format!("a source given as a Lua expression (`{e}`) is recognised but not carried out by this version of seam"))
                        .help("give a number (W/m³) meanwhile"),
                ),
            },
        }
    }
    let partial =
        p.source.len() > 1 || p.source.iter().any(|s| s.blocks.len() != mesh.blocks.len());
    if partial && constant.is_some_and(|q| q != 0.0) {
        {
            diags.push(
                Diagnostic::error("E0900", "a source on some blocks only is recognised but not carried out by this version of seam")
                    .help("give one [[source]] over every block meanwhile"),
            );
        }
    }
    constant.filter(|q| *q != 0.0).map(|q| move |_: [f64; 3]| q)
}
