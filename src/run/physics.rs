//! The physics of a run, from the problem file on the mesh: per block its material laws
//! and field, the boundary conditions (Dirichlet nodes, face sites and their values at a
//! time), the volumetric sources, the initial temperature and the time controls of
//! `[solve]`. [`Physics::new`] checks them all into the diagnostics; the values are
//! evaluated at a time by [`Physics::loads_at`].
//!
//! Values are numbers, tables in t (T for material laws) or Lua expressions evaluated in one
//! sandbox shared by the run: flux and convection values at each face's centroid,
//! temperatures at the nodes, sources at the quadrature points.

use crate::diag::{Diagnostic, Diagnostics, did_you_mean};
use crate::heat::law::Law;
use crate::heat::transient::{BlockLaws, Loads};
use crate::heat::{FaceBc, Material, TEMPERATURE};
use crate::mesh::{Mesh, NodeId, Side};
use crate::script::{Limits, Sandbox};

use super::nodal_field::check_nodal_fields;
use super::problem::{
    BcKind, MAX_MAGNITUDE, Problem, ProblemFile, ProblemText, TimeSpec, Value, time_spec,
};
use super::species::Species;
use super::{RunError, input_error};

/// The physics of a run on its mesh, checked.
pub(super) struct Physics<'a> {
    pub problem: &'a Problem,
    pub mesh: &'a Mesh,
    pub transient: bool,
    pub materials: Materials,
    /// The fields of the problem, sorted, each once.
    pub field_names: Vec<String>,
    /// The nodes of the temperature conditions, with the condition.
    pub dirichlet: Vec<(NodeId, usize)>,
    /// The nodes of the voltage conditions, with the condition.
    pub voltage: Vec<(NodeId, usize)>,
    /// The face conditions (flux, convection, radiation), before evaluation.
    pub face_sites: Vec<FaceSite>,
    pub time: TimeSpec,
    /// The source per block.
    pub block_source: Vec<Law>,
    /// The temperature at which laws are tried and Nitsche weights taken.
    pub probe: f64,
    /// The sandbox of the run's boundary and initial expressions.
    pub sandbox: SharedSandbox,
    /// The species: its materials, conditions and solubility scales.
    pub species: Species,
}

impl<'a> Physics<'a> {
    /// Materials, conditions, time controls and sources of `file` on `mesh`, every
    /// problem found going to `diags` (in that order).
    pub(super) fn new(file: &'a ProblemFile, mesh: &'a Mesh, diags: &mut Diagnostics) -> Self {
        let problem = &file.problem;
        let probe = match problem.initial.as_ref().map(|i| &i.temperature) {
            Some(Value::Number(t)) => *t,
            _ => 300.0,
        };
        let materials = materials(problem, mesh, probe, diags);
        check_bcs(problem, diags);
        let dirichlet = nodal_condition_nodes(problem, mesh, BcKind::Temperature, diags);
        let voltage = nodal_condition_nodes(problem, mesh, BcKind::Voltage, diags);
        check_electric(problem, &file.text, &materials, &voltage, diags);
        let (diffusivity, capacity) = super::species::materials(problem, mesh, probe, diags);
        let species = Species {
            dirichlet: nodal_condition_nodes(problem, mesh, BcKind::Species, diags),
            scale: vec![1.0; mesh.blocks.len()],
            node_scale: vec![1.0; mesh.num_nodes()],
            diffusivity,
            capacity,
        };
        super::species::check_conditions(problem, &file.text, &species, file.transient, diags);
        let face_sites = face_sites(problem, mesh, diags);
        let time = time_spec(problem, file.transient, diags);
        let block_source = block_sources(problem, mesh, &file.text, probe, time.start, diags);
        check_nodal_fields(problem, &file.text, diags);
        let mut field_names: Vec<String> = materials.fields.clone();
        field_names.sort();
        field_names.dedup();
        Physics {
            problem,
            mesh,
            transient: file.transient,
            materials,
            field_names,
            dirichlet,
            voltage,
            face_sites,
            time,
            block_source,
            probe,
            sandbox: Default::default(),
            species,
        }
    }

    /// Boundary data at the start: every expression is tried once here, so a bad one
    /// is an input error, not a failure in the middle of a run.
    pub(super) fn try_start(&self) -> Result<(), RunError> {
        match self.loads_at(self.time.start) {
            Ok(_) => Ok(()),
            Err(e) => Err(input_error(
                "E0707",
                e,
                "a number, a table [[t, v], …] or a Lua expression of x, y, z, t",
            )),
        }
    }

    /// The boundary data at time t.
    pub(super) fn loads_at(&self, t: f64) -> Result<Loads, String> {
        let mut loads = loads_at(
            self.problem,
            self.mesh,
            (&self.dirichlet, &self.voltage, &self.species.dirichlet),
            &self.face_sites,
            &self.sandbox,
            t,
        )?;
        // The species unknown is c/S (the solubility scale of the node's blocks).
        for (n, c) in &mut loads.species {
            *c = super::species::scaled(*c, *n, &self.species);
        }
        Ok(loads)
    }

    /// The initial state, checked here (transient runs start from it; a steady run with
    /// `[initial]` takes it as its first guess).
    pub(super) fn initial_state(&self) -> Result<Option<Vec<f64>>, RunError> {
        match (&self.problem.initial, self.transient) {
            (Some(_), _) | (None, true) => Some(self.initial_values()).transpose(),
            (None, false) => Ok(None),
        }
    }

    /// Initial nodal temperatures at the start time.
    pub(super) fn initial_values(&self) -> Result<Vec<f64>, RunError> {
        initial_values(
            self.problem,
            self.mesh,
            &self.dirichlet,
            &self.sandbox,
            self.time.start,
        )
    }

    /// Whether no block's source depends on the temperature: the linear steady solver
    /// takes the sources as functions of x at the start, one per block.
    pub(super) fn source_of_x_only(&self) -> bool {
        !self.block_source.iter().any(Law::uses_temperature)
    }

    /// The sources per block as functions of x at the start, for the linear steady
    /// solver (which takes them when none depends on T: [`Self::source_of_x_only`]):
    /// `None` on a block whose source is a constant 0. A point where one fails is kept
    /// in `failed` and reported after the solve.
    pub(super) fn sources_of_x<'s>(
        &'s self,
        failed: &'s std::sync::Mutex<Option<String>>,
    ) -> Vec<Option<SourceOfX<'s>>> {
        (self.block_source.iter())
            .map(|q| {
                (*q != Law::Constant(0.0))
                    .then(|| Box::new(q.source_of_x(self.time.start, failed)) as Box<_>)
            })
            .collect()
    }

    /// The species interfaces of `contact` on the species blocks: each side carries a
    /// species, the blocks' solubility scales follow from the partition coefficients,
    /// and each side A has one scale; problems go to `diags`.
    pub(super) fn resolve_species(
        &mut self,
        contact: &super::contact::RunContact,
        diags: &mut Diagnostics,
    ) {
        let (mesh, entries) = (self.mesh, &contact.species);
        super::species::check_interfaces(mesh, &self.species, entries, diags);
        if diags.has_errors() {
            return;
        }
        self.species.resolve_scale(mesh, entries, diags);
        for e in entries {
            if let Err(m) = self.species.side_a_scale(mesh, e) {
                diags.push(
                    Diagnostic::error("E0432", format!("species interface: {m}"))
                        .at(Some(e.at.clone()))
                        .help("split side A into one surface per block of its own solubility"),
                );
            }
        }
    }

    /// One conductivity per block, for the Nitsche weights: the law at the probe
    /// temperature and the start time.
    pub(super) fn conductivity(&self) -> Vec<f64> {
        self.materials
            .laws
            .iter()
            .map(|l| {
                l.conductivity
                    .eval(self.probe, [0.0; 3], self.time.start)
                    .map_or(1.0, |v| v.0)
            })
            .collect()
    }
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

/// The materials of the blocks: per block its laws and its field name.
pub(super) struct Materials {
    pub laws: Vec<BlockLaws>,
    pub fields: Vec<String>,
    /// Per block its electrical conductivity σ(T), if it carries a voltage.
    pub sigma: Vec<Option<Law>>,
}

impl Materials {
    /// Whether some block carries a voltage: a thermal–electrical problem.
    pub(super) fn electric(&self) -> bool {
        self.sigma.iter().any(Option::is_some)
    }
}

impl Materials {
    /// Constant k and ρc per block, for the linear steady solver.
    pub(super) fn constant(&self) -> Option<Vec<Material>> {
        self.laws
            .iter()
            .map(|l| match (&l.conductivity, &l.capacity) {
                (Law::Constant(k), Law::Constant(c)) => Some(Material {
                    conductivity: *k,
                    rho_c: *c,
                }),
                _ => None,
            })
            .collect()
    }
}

/// A material value as a law of T: numbers, Lua expressions of T (x, y, z, t), tables
/// in T; checked positive at `probe` (a Lua law only where it can be evaluated).
pub(super) fn law(v: &Value, what: &str, probe: f64, diags: &mut Diagnostics) -> Option<Law> {
    let law = match v {
        Value::Number(k) => Law::Constant(*k),
        Value::Expr(e) => match e.trim().parse::<f64>() {
            Ok(k) => Law::Constant(k),
            Err(_) => Law::Lua {
                expr: e.clone(),
                chunk: what.to_string(),
            },
        },
        Value::Table { table } => match Law::table(table.clone()) {
            Ok(l) => l,
            Err(m) => {
                diags.push(
                    Diagnostic::error("E0704", format!("{what}: {m}"))
                        .help("a table is [[T, value], …] with T increasing"),
                );
                return None;
            }
        },
    };
    let bad = |v: f64| !(v > 0.0 && v <= MAX_MAGNITUDE);
    let problem = match &law {
        Law::Constant(k) if bad(*k) => {
            Some(format!("must be positive and at most 1e100, found {k}"))
        }
        Law::Table(p) => p.iter().find(|q| bad(q.1)).map(|q| {
            format!(
                "must be positive and at most 1e100, found {} at T = {}",
                q.1, q.0
            )
        }),
        Law::Lua { .. } => match law.eval(probe, [0.0; 3], 0.0) {
            Err(e) => Some(e),
            Ok((k, _)) if bad(k) => Some(format!(
                "must be positive and at most 1e100, found {k} at T = {probe}"
            )),
            Ok(_) => None,
        },
        _ => None,
    };
    if let Some(m) = problem {
        diags.push(
            Diagnostic::error("E0704", format!("{what} {m}"))
                .help("k in W/m/K, ρ in kg/m³, c_p in J/kg/K, D in m²/s: positive numbers up to 1e100, tables or Lua expressions of T"),
        );
        return None;
    }
    Some(law)
}

fn materials(p: &Problem, mesh: &Mesh, probe: f64, diags: &mut Diagnostics) -> Materials {
    let mut out: Vec<Option<(BlockLaws, String)>> = vec![None; mesh.blocks.len()];
    let mut sigma: Vec<Option<Law>> = vec![None; mesh.blocks.len()];
    for (i, m) in p.material.iter().enumerate() {
        let what = format!("[[material]] #{} conductivity", i + 1);
        let Some(k) = law(&m.conductivity, &what, probe, diags) else {
            continue;
        };
        let s = match &m.electrical_conductivity {
            Some(v) => {
                let what = format!("[[material]] #{} electrical_conductivity", i + 1);
                match law(v, &what, probe, diags) {
                    Some(s) => Some(s),
                    None => continue,
                }
            }
            None => None,
        };
        let capacity = match (&m.density, &m.specific_heat, m.rho_c) {
            (_, _, Some(_)) if m.density.is_some() || m.specific_heat.is_some() => {
                diags.push(
                    Diagnostic::error(
                        "E0704",
                        format!(
                            "[[material]] #{}: rho_c and density/specific_heat both given",
                            i + 1
                        ),
                    )
                    .help("give either rho_c, or density and specific_heat"),
                );
                continue;
            }
            (_, _, Some(rc)) => law(
                &Value::Number(rc),
                &format!("[[material]] #{} rho_c", i + 1),
                probe,
                diags,
            ),
            (Some(rho), Some(cp), None) => {
                let cp = law(
                    cp,
                    &format!("[[material]] #{} specific_heat", i + 1),
                    probe,
                    diags,
                );
                let rho_ok = *rho > 0.0 && *rho <= MAX_MAGNITUDE;
                if !rho_ok {
                    diags.push(
                        Diagnostic::error(
                            "E0704",
                            format!(
                                "[[material]] #{} density must be positive and at most 1e100, found {rho}",
                                i + 1
                            ),
                        )
                        .help("ρ in kg/m³"),
                    );
                }
                cp.filter(|_| rho_ok).map(|cp| scale_law(cp, *rho))
            }
            (None, None, None) => Some(Law::Constant(1.0)),
            _ => {
                diags.push(
                    Diagnostic::error(
                        "E0704",
                        format!(
                            "[[material]] #{}: density and specific_heat go together",
                            i + 1
                        ),
                    )
                    .help("give both (or rho_c)"),
                );
                continue;
            }
        };
        let Some(capacity) = capacity else { continue };
        let field = m
            .field
            .clone()
            .unwrap_or_else(|| TEMPERATURE.to_string())
            .to_ascii_lowercase();
        for b in &m.blocks {
            if let Some(i) = block_index(mesh, b, diags, "[[material]]") {
                sigma[i] = s.clone();
                out[i] = Some((
                    BlockLaws {
                        conductivity: k.clone(),
                        capacity: capacity.clone(),
                    },
                    field.clone(),
                ));
            }
        }
    }
    let mut laws = Vec::with_capacity(out.len());
    let mut fields = Vec::with_capacity(out.len());
    for (i, m) in out.into_iter().enumerate() {
        match m {
            Some((l, f)) => {
                laws.push(l);
                fields.push(f);
            }
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
                laws.push(BlockLaws {
                    conductivity: Law::Constant(1.0),
                    capacity: Law::Constant(1.0),
                });
                fields.push(TEMPERATURE.to_string());
            }
        }
    }
    Materials {
        laws,
        fields,
        sigma,
    }
}

/// A voltage needs blocks with an electrical conductivity, and those blocks a voltage
/// condition somewhere (else the potential floats).
fn check_electric(
    p: &Problem,
    at: &ProblemText,
    materials: &Materials,
    voltage: &[(NodeId, usize)],
    diags: &mut Diagnostics,
) {
    let electric_bcs: Vec<usize> = (p.bc.iter().enumerate())
        .filter(|(_, b)| matches!(b.kind, BcKind::Voltage | BcKind::Current))
        .map(|(k, _)| k)
        .collect();
    if !materials.electric() {
        if let Some(&k) = electric_bcs.first() {
            diags.push(
                Diagnostic::error(
                    "E0706",
                    format!(
                        "[[bc]] #{}: a {} condition, but no block carries a voltage",
                        k + 1,
                        p.bc[k].kind.name()
                    ),
                )
                .at(at.loc("bc", k, "kind"))
                .help("give the conducting blocks' [[material]] an electrical_conductivity (S/m)"),
            );
        }
        return;
    }
    if voltage.is_empty() {
        diags.push(
            Diagnostic::error(
                "E0706",
                "blocks carry a voltage, but no [[bc]] of kind \"voltage\" fixes it anywhere: the potential would float",
            )
            .at(p
                .material
                .iter()
                .position(|m| m.electrical_conductivity.is_some())
                .and_then(|i| at.loc("material", i, "electrical_conductivity")))
            .help("add a [[bc]] with kind = \"voltage\" (say value = 0 on the grounded face)"),
        );
    }
}

/// ρ·c_p(T) from c_p(T) (and any law times a constant).
pub(super) fn scale_law(cp: Law, rho: f64) -> Law {
    match cp {
        Law::Constant(c) => Law::Constant(rho * c),
        Law::Table(p) => Law::Table(p.into_iter().map(|(t, v)| (t, rho * v)).collect()),
        Law::Lua { expr, chunk } => Law::Lua {
            expr: format!("{rho:e} * ({expr})"),
            chunk,
        },
        Law::TimeTable(p) => Law::TimeTable(p.into_iter().map(|(t, v)| (t, rho * v)).collect()),
    }
}

/// The sandbox of the run's boundary and initial expressions.
pub(super) type SharedSandbox = std::cell::RefCell<Option<Sandbox>>;

/// Evaluate a value at a point and time: numbers directly, tables in t, expressions in
/// a sandbox shared by the run (built on first use, each expression compiled once).
pub(super) fn evaluate(
    v: &Value,
    x: [f64; 3],
    t: f64,
    sandbox: &SharedSandbox,
    chunk: &str,
) -> Result<f64, String> {
    match v {
        Value::Number(n) => Ok(*n),
        Value::Table { table } => {
            let law = Law::table(table.clone())?;
            law.eval(t, x, t).map(|(v, _)| v)
        }
        Value::Expr(e) => {
            let mut slot = sandbox.borrow_mut();
            if slot.is_none() {
                *slot = Some(Sandbox::new(Limits::default()).map_err(|e| e.to_string())?);
            }
            let s = slot.as_mut().expect("just built");
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
            s.call(&f, &[x[0], x[1], x[2], t])
                .map_err(|e| e.to_string())
        }
    }
}

/// `v`, the value of `[[bc]]` #k at `x` and time `t`, if its kind accepts it.
fn in_range(kind: BcKind, v: f64, k: usize, x: [f64; 3], t: f64) -> Result<(), String> {
    kind.accepts(v).map_err(|range| {
        format!(
            "[[bc]] #{} value is {v:e} at ({}, {}, {}), t = {t}: {range}",
            k + 1,
            x[0],
            x[1],
            x[2]
        )
    })
}

/// The fields of each `[[bc]]` that go with its kind: `ambient` for convection and
/// radiation only (never taken as 0 K), an emissivity in (0, 1].
fn check_bcs(p: &Problem, diags: &mut Diagnostics) {
    for (k, bc) in p.bc.iter().enumerate() {
        let exchange = matches!(bc.kind, BcKind::Convection | BcKind::Radiation);
        if exchange && bc.ambient.is_none() {
            diags.push(
                Diagnostic::error(
                    "E0706",
                    format!(
                        "[[bc]] #{}: {} needs `ambient` (T∞, K)",
                        k + 1,
                        bc.kind.name()
                    ),
                )
                .help("add ambient = 293.15 (say): it is not taken as 0 K"),
            );
        }
        if let Some(a) = bc.ambient
            && BcKind::Temperature.accepts(a).is_err()
        {
            diags.push(
                Diagnostic::error(
                    "E0706",
                    format!("[[bc]] #{}: ambient {a:e} is out of range", k + 1),
                )
                .help("a temperature is finite and within ±1e12 K"),
            );
        }
        if !exchange && bc.ambient.is_some() {
            diags.push(
                Diagnostic::error(
                    "E0706",
                    format!(
                        "[[bc]] #{}: `ambient` belongs to convection and radiation, not {}",
                        k + 1,
                        bc.kind.name()
                    ),
                )
                .help("remove `ambient`, or make the condition a convection or radiation"),
            );
        }
        if bc.kind == BcKind::Radiation
            && let Value::Number(e) = bc.value
            && !(e > 0.0 && e <= 1.0)
        {
            diags.push(
                Diagnostic::error(
                    "E0706",
                    format!("[[bc]] #{}: emissivity {e} is not in (0, 1]", k + 1),
                )
                .help("for radiation, `value` is the emissivity ε"),
            );
        }
    }
}

/// The nodes of each nodal condition of `kind` (temperature or voltage), with the
/// condition.
fn nodal_condition_nodes(
    p: &Problem,
    mesh: &Mesh,
    kind: BcKind,
    diags: &mut Diagnostics,
) -> Vec<(NodeId, usize)> {
    let mut out = Vec::new();
    for (k, bc) in p.bc.iter().enumerate().filter(|(_, b)| b.kind == kind) {
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
        out.extend(nodes.into_iter().map(|n| (n, k)));
    }
    // A node in two conditions keeps the later one.
    out.sort_by_key(|&(n, k)| (n, std::cmp::Reverse(k)));
    out.dedup_by_key(|&mut (n, _)| n);
    out
}

/// One face condition before evaluation: its side, condition index, face centroid and
/// whether it opts out of masking on faces in contact.
#[derive(Clone, Copy, Debug)]
pub(super) struct FaceSite {
    pub side: Side,
    pub bc: usize,
    pub centroid: [f64; 3],
    pub keep: bool,
}

fn face_sites(p: &Problem, mesh: &Mesh, diags: &mut Diagnostics) -> Vec<FaceSite> {
    let mut out = Vec::new();
    for (k, bc) in p.bc.iter().enumerate().filter(|(_, b)| {
        !matches!(
            b.kind,
            BcKind::Temperature | BcKind::Voltage | BcKind::Species
        )
    }) {
        for s in &bc.surfaces {
            let Some(i) = mesh.find_side_set(s) else {
                diags.push(
                    Diagnostic::error("E0706", format!("[[bc]]: unknown side set `{s}`")).help(
                        "flux, convection, radiation, current and species_flux conditions act on side sets",
                    ),
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
                out.push(FaceSite {
                    side,
                    bc: k,
                    centroid: c,
                    keep: bc.no_coverage_flux,
                });
            }
        }
    }
    out
}

/// A node of a nodal condition, with the condition's index.
type NodalSite = (NodeId, usize);

/// The boundary data at time t.
fn loads_at(
    p: &Problem,
    mesh: &Mesh,
    (dirichlet, voltage, species): (&[NodalSite], &[NodalSite], &[NodalSite]),
    faces: &[FaceSite],
    sandbox: &SharedSandbox,
    t: f64,
) -> Result<Loads, String> {
    let mut out = Loads::default();
    for (nodes, kind) in [
        (dirichlet, BcKind::Temperature),
        (voltage, BcKind::Voltage),
        (species, BcKind::Species),
    ] {
        for &(n, k) in nodes {
            let v = evaluate(
                &p.bc[k].value,
                mesh.coords[n.index()],
                t,
                sandbox,
                "[[bc]] value",
            )
            .map_err(|e| format!("[[bc]] #{} value: {e}", k + 1))?;
            in_range(kind, v, k, mesh.coords[n.index()], t)?;
            match kind {
                BcKind::Voltage => out.voltage.push((n, v)),
                BcKind::Species => out.species.push((n, v)),
                _ => out.dirichlet.push((n, v)),
            }
        }
    }
    for f in faces {
        let bc = &p.bc[f.bc];
        let v = evaluate(&bc.value, f.centroid, t, sandbox, "[[bc]] value")
            .map_err(|e| format!("[[bc]] #{} value: {e}", f.bc + 1))?;
        in_range(bc.kind, v, f.bc, f.centroid, t)?;
        let t_inf = bc.ambient.unwrap_or(0.0);
        if bc.kind == BcKind::Current {
            out.currents.push((f.side, v));
            continue;
        }
        if bc.kind == BcKind::SpeciesFlux {
            out.species_fluxes.push((f.side, v));
            continue;
        }
        out.faces.push(match bc.kind {
            BcKind::Flux => FaceBc::Flux { side: f.side, q: v },
            BcKind::Radiation => FaceBc::Radiation {
                side: f.side,
                emissivity: v,
                t_inf,
            },
            _ => FaceBc::Convection {
                side: f.side,
                h: v,
                t_inf,
            },
        });
    }
    Ok(out)
}

/// The volumetric source per block, Q(T, x, t) in W/m³ (0 where none is given): a
/// number, a Lua expression of x, y, z, t and T, or a table in t. Each block may be
/// named once over all `[[source]]`s. A value is tried once, at the first node of its
/// first block, at temperature `probe` and time `time`: a bad expression is an input
/// error at its line, not a failure in the middle of a run.
fn block_sources(
    p: &Problem,
    mesh: &Mesh,
    at: &ProblemText,
    probe: f64,
    time: f64,
    diags: &mut Diagnostics,
) -> Vec<Law> {
    let mut out = vec![Law::Constant(0.0); mesh.blocks.len()];
    let mut given = vec![false; mesh.blocks.len()];
    for (k, s) in p.source.iter().enumerate() {
        let loc = at.loc("source", k, "value");
        let law = match &s.value {
            Value::Number(q) => Ok(Law::Constant(*q)),
            Value::Expr(e) => Ok(e.trim().parse().map_or_else(
                |_| Law::Lua {
                    expr: e.clone(),
                    chunk: format!("[[source]] #{} value", k + 1),
                },
                Law::Constant,
            )),
            Value::Table { table } => Law::table(table.clone()).map(|l| match l {
                Law::Table(points) => Law::TimeTable(points),
                other => other,
            }),
        };
        let mut blocks = Vec::new();
        for b in &s.blocks {
            if let Some(i) = block_index(mesh, b, diags, "[[source]]") {
                if given[i] {
                    diags.push(
                        Diagnostic::error(
                            "E0714",
                            format!("[[source]]: block `{b}` is given a source twice"),
                        )
                        .help("name each block in one [[source]] only"),
                    );
                }
                given[i] = true;
                blocks.push(i);
            }
        }
        let x = blocks
            .first()
            .filter(|&&b| !mesh.blocks[b].is_empty())
            .map_or([0.0; 3], |&b| {
                mesh.coords[mesh.elem_nodes(mesh.blocks[b].first_elem)[0].index()]
            });
        let tried = law.and_then(|l| match l.eval(probe, x, time) {
            Ok((q, dq)) if q.abs() <= MAX_MAGNITUDE && dq.is_finite() => Ok(l),
            Ok((q, _)) => Err(format!(
                "Q = {q} at ({}, {}, {}), T = {probe}, t = {time}",
                x[0], x[1], x[2]
            )),
            // The first line: a Lua stack trace says nothing about a one-line expression.
            Err(e) => Err(e.lines().next().unwrap_or_default().to_string()),
        });
        match tried {
            Ok(law) => blocks.iter().for_each(|&i| out[i] = law.clone()),
            Err(m) => diags.push(
                Diagnostic::error("E0714", format!("[[source]] #{}: {m}", k + 1))
                    .at(loc)
                    .help("Q (W/m³, finite and within ±1e100) is a number, a Lua expression of x, y, z, t and T (the local temperature), or { table = [[t, Q], …] } with t increasing"),
            ),
        }
    }
    out
}

/// A source as a function of x at one time (W/m³), for the linear steady solver.
pub(super) type SourceOfX<'s> = Box<dyn Fn([f64; 3]) -> f64 + Sync + 's>;

/// Initial nodal temperatures: `[initial] temperature`, else (a steady nonlinear
/// solve's first guess) the mean of the Dirichlet values, else 0.
fn initial_values(
    p: &Problem,
    mesh: &Mesh,
    dirichlet: &[(NodeId, usize)],
    sandbox: &SharedSandbox,
    time: f64,
) -> Result<Vec<f64>, RunError> {
    match &p.initial {
        Some(init) => mesh
            .coords
            .iter()
            .map(|x| {
                let v = evaluate(
                    &init.temperature,
                    *x,
                    time,
                    sandbox,
                    "[initial] temperature",
                )?;
                BcKind::Temperature
                    .accepts(v)
                    .map_err(|range| format!("{v:e} at ({}, {}, {}): {range}", x[0], x[1], x[2]))?;
                Ok(v)
            })
            .collect::<Result<Vec<f64>, String>>()
            .map_err(|e| {
                input_error(
                    "E0707",
                    format!("[initial] temperature: {e}"),
                    "a number or a Lua expression of x, y, z",
                )
            }),
        None => {
            let mut sum = 0.0;
            for &(n, k) in dirichlet {
                sum += evaluate(
                    &p.bc[k].value,
                    mesh.coords[n.index()],
                    time,
                    sandbox,
                    "[[bc]] value",
                )
                .unwrap_or(0.0);
            }
            let mean = if dirichlet.is_empty() {
                0.0
            } else {
                sum / dirichlet.len() as f64
            };
            Ok(vec![mean; mesh.num_nodes()])
        }
    }
}
