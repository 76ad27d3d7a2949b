//! `seam.Embedding`: interactions, search and the interface terms at a host field.
//!
//! Fields `u` are indexed by host dof; their length is the size of the matrices
//! returned. Residual and Jacobian follow `R(u) = K u − F`: the host adds `residual` to
//! its residual and `jacobian` to `∂R/∂u`; for a linear model `residual = jacobian @ u −
//! load`, so a host that assembles `K u = F` once adds `jacobian` to K and `load` to F.
//! Heat is in W, leaving side A and leaving side B (their sum is 0 to round-off).

use std::path::Path;

use pyo3::prelude::*;
use pyo3::types::PyDict;

use seam::embed::{self, EmbedError, Interaction, Model, Multipliers, Periodic};
use seam::search::SearchSettings;

use crate::array;
use crate::callback::{self, Raised};
use crate::error::{OrPy, argument, to_py};

/// Heat through one interaction (W): leaving side A and leaving side B.
#[pyclass(module = "seam", frozen, get_all)]
#[derive(Clone, Copy)]
pub struct Heat {
    pub side_a: f64,
    pub side_b: f64,
}

#[pymethods]
impl Heat {
    fn __repr__(&self) -> String {
        format!("Heat(side_a={:e}, side_b={:e})", self.side_a, self.side_b)
    }
}

pub fn heat_list(heat: &[Option<embed::Heat>]) -> Vec<Option<Heat>> {
    heat.iter()
        .map(|h| {
            h.map(|h| Heat {
                side_a: h.side_a,
                side_b: h.side_b,
            })
        })
        .collect()
}

/// A periodic map `x ↦ x + offset` (m).
#[pyclass(module = "seam", frozen, get_all)]
#[derive(Clone)]
pub struct Rectangular {
    pub offset: (f64, f64, f64),
}

#[pymethods]
impl Rectangular {
    #[new]
    fn new(offset: (f64, f64, f64)) -> Self {
        Rectangular { offset }
    }
}

/// A periodic turn by ``angle`` degrees (right-hand rule) about the line through
/// ``center`` along ``axis``; an N-fold turn must close up after N turns.
#[pyclass(module = "seam", frozen, get_all)]
#[derive(Clone)]
pub struct Cylindrical {
    pub axis: (f64, f64, f64),
    pub center: (f64, f64, f64),
    pub angle: f64,
}

#[pymethods]
impl Cylindrical {
    #[new]
    fn new(axis: (f64, f64, f64), center: (f64, f64, f64), angle: f64) -> Self {
        Cylindrical {
            axis,
            center,
            angle,
        }
    }
}

/// The rigid map taking side A's centroid and mean normal onto side B's (normals
/// opposed when ``invert_normals``).
#[pyclass(module = "seam", frozen, get_all)]
#[derive(Clone)]
pub struct AlignSurface {
    pub invert_normals: bool,
}

#[pymethods]
impl AlignSurface {
    #[new]
    #[pyo3(signature = (invert_normals=true))]
    fn new(invert_normals: bool) -> Self {
        AlignSurface { invert_normals }
    }
}

/// A map written in Lua: each component an expression in x, y, z, or
/// ``file.lua:function`` under the working directory; without ``z``, z is kept.
#[pyclass(module = "seam", frozen, get_all)]
#[derive(Clone)]
pub struct Mapped {
    pub x: String,
    pub y: String,
    pub z: Option<String>,
}

#[pymethods]
impl Mapped {
    #[new]
    #[pyo3(signature = (x, y, z=None))]
    fn new(x: String, y: String, z: Option<String>) -> Self {
        Mapped { x, y, z }
    }
}

fn periodic(map: &Bound<'_, PyAny>) -> PyResult<Periodic> {
    let t = |v: (f64, f64, f64)| [v.0, v.1, v.2];
    if let Ok(m) = map.cast::<Rectangular>() {
        return Ok(Periodic::Rectangular {
            offset: t(m.get().offset),
        });
    }
    if let Ok(m) = map.cast::<Cylindrical>() {
        let m = m.get();
        return Ok(Periodic::Cylindrical {
            axis: t(m.axis),
            center: t(m.center),
            angle: m.angle,
        });
    }
    if let Ok(m) = map.cast::<AlignSurface>() {
        return Ok(Periodic::AlignSurface {
            invert_normals: m.get().invert_normals,
        });
    }
    if let Ok(m) = map.cast::<Mapped>() {
        let m = m.get();
        return Ok(Periodic::Mapped {
            x: m.x.clone(),
            y: m.y.clone(),
            z: m.z.clone(),
        });
    }
    Err(argument(
        "periodic is not a periodic map",
        "give seam.Rectangular, seam.Cylindrical, seam.AlignSurface or seam.Mapped",
    ))
}

/// Search settings from a dict of `SearchSettings` field names.
fn search_settings(d: &Bound<'_, PyDict>) -> PyResult<SearchSettings> {
    let mut s = SearchSettings::defaults(3);
    for (key, value) in d.iter() {
        let key: String = key.extract()?;
        let real = || -> PyResult<f64> { value.extract::<f64>() };
        match key.as_str() {
            "normal_tolerance" => s.normal_tolerance = value.extract::<Option<f64>>()?,
            "tangential_tolerance" => s.tangential_tolerance = real()?,
            "buffer_factor" => s.buffer_factor = real()?,
            "field_factor" => s.field_factor = real()?,
            "normal_check_angle" => s.normal_check_angle = real()?,
            "opposed_normal_threshold_angle" => s.opposed_normal_threshold_angle = real()?,
            "cull_opposed_normals" => s.cull_opposed_normals = value.extract::<bool>()?,
            _ => {
                return Err(argument(
                    format!("unknown search setting `{key}`"),
                    "the settings are normal_tolerance, tangential_tolerance, buffer_factor, field_factor, normal_check_angle, opposed_normal_threshold_angle, cull_opposed_normals",
                ));
            }
        }
    }
    Ok(s)
}

/// The interface terms at one field ([`Embedding::contributions`]).
#[pyclass(module = "seam", frozen, get_all)]
pub struct Contributions {
    /// ∂R/∂u, (n, n) scipy.sparse.csr_matrix.
    pub jacobian: Py<PyAny>,
    /// R(u), dense, length n.
    pub residual: Py<PyAny>,
    /// The right-hand side of linear models (offset terms), dense, length n.
    pub load: Py<PyAny>,
    /// Per interaction, in the order added; None for mortar ties.
    pub heat: Vec<Option<Heat>>,
}

/// The interface terms at one field with the Jacobian on a pattern kept between calls
/// ([`Embedding::evaluate`]).
#[pyclass(module = "seam", frozen, get_all)]
pub struct Evaluation {
    pub jacobian: Py<PyAny>,
    pub residual: Py<PyAny>,
    pub load: Py<PyAny>,
    pub heat: Vec<Option<Heat>>,
    /// Counts the patterns built: it changes only after a search or a move.
    pub pattern: u64,
}

/// seam inside a host: its mesh and numbering, its interactions and their search.
/// Made by :meth:`Builder.build`; used from the thread that made it.
#[pyclass(module = "seam", unsendable)]
pub struct Embedding {
    pub(crate) inner: embed::Embedding,
    /// One slot per Python conductance function: the exception it raised.
    raised: Vec<Raised>,
}

impl Embedding {
    pub fn new(inner: embed::Embedding) -> Self {
        Embedding {
            inner,
            raised: Vec::new(),
        }
    }

    /// seam's result, or its error as an exception whose `__cause__` is the exception a
    /// Python conductance function raised on the way.
    pub(crate) fn run<T>(
        &self,
        py: Python<'_>,
        f: impl FnOnce(&embed::Embedding) -> Result<T, EmbedError>,
    ) -> PyResult<T> {
        self.clear_raised();
        let r = f(&self.inner);
        self.finish(py, r)
    }

    fn clear_raised(&self) {
        for slot in &self.raised {
            if let Ok(mut s) = slot.lock() {
                *s = None;
            }
        }
    }

    fn finish<T>(&self, py: Python<'_>, r: Result<T, EmbedError>) -> PyResult<T> {
        r.map_err(|e| {
            let err = to_py(e);
            let cause = self
                .raised
                .iter()
                .find_map(|slot| slot.lock().ok().and_then(|mut s| s.take()));
            if let Some(cause) = cause {
                err.set_cause(py, Some(cause));
            }
            err
        })
    }
}

#[pymethods]
impl Embedding {
    /// Add an interaction built in code; returns its index.
    ///
    /// ``model``: ``"conductance"`` (q = h [u] on side A, contact resistance),
    /// ``"gap_conductance"`` (Robin–Nitsche, stable for any h in [0, inf]),
    /// ``"tied_nitsche"`` (weighted symmetric Nitsche, no extra unknowns) or
    /// ``"tied_mortar"`` (constraint rows from :meth:`constraints`; ``multipliers``
    /// ``"standard"`` or ``"dual"``). ``h`` in W/m²/K. ``conductance``: a function of a
    /// :class:`PointState` returning h or ``(h, dh_dtemp_a, dh_dtemp_b)`` instead of the
    /// constant ``h`` (say ``depends_on_temperature=False`` only if h does not change
    /// with T). ``offset``: a prescribed jump u_A − u_B (K). ``penalty_factor``: the
    /// Nitsche β. ``periodic``: pair side A's image under a map with side B.
    /// ``search``: a dict of search settings (normal_tolerance, tangential_tolerance,
    /// buffer_factor, field_factor, normal_check_angle, opposed_normal_threshold_angle,
    /// cull_opposed_normals). ``allow_unpaired``: a search that pairs nothing is no
    /// error. ``quarantine``: a point where the conductance fails carries no heat and
    /// is listed by :meth:`quarantined` instead of failing the evaluation.
    #[pyo3(signature = (side_a, side_b, model, *, h=0.0, multipliers="standard", conductance=None,
        depends_on_temperature=true, offset=0.0, penalty_factor=None, periodic=None, search=None,
        allow_unpaired=false, quarantine=false))]
    #[allow(clippy::too_many_arguments)]
    fn add_interaction(
        &mut self,
        side_a: &str,
        side_b: &str,
        model: &str,
        h: f64,
        multipliers: &str,
        conductance: Option<Py<PyAny>>,
        depends_on_temperature: bool,
        offset: f64,
        penalty_factor: Option<f64>,
        periodic: Option<&Bound<'_, PyAny>>,
        search: Option<&Bound<'_, PyDict>>,
        allow_unpaired: bool,
        quarantine: bool,
    ) -> PyResult<usize> {
        let multipliers = match multipliers.to_ascii_lowercase().as_str() {
            "standard" => Multipliers::Standard,
            "dual" => Multipliers::Dual,
            _ => {
                return Err(argument(
                    format!("unknown multipliers `{multipliers}`"),
                    "give \"standard\" or \"dual\"",
                ));
            }
        };
        let model = match model.to_ascii_lowercase().as_str() {
            "conductance" => Model::Conductance { h },
            "gap_conductance" => Model::GapConductance { h },
            "tied_nitsche" => Model::TiedNitsche,
            "tied_mortar" => Model::TiedMortar { multipliers },
            _ => {
                return Err(argument(
                    format!("unknown model `{model}`"),
                    "give \"conductance\", \"gap_conductance\", \"tied_nitsche\" or \"tied_mortar\"",
                ));
            }
        };
        let mut i = Interaction::new(side_a, side_b, model).offset(offset);
        if let Some(beta) = penalty_factor {
            i = i.penalty_factor(beta);
        }
        if let Some(map) = periodic {
            i = i.periodic(self::periodic(map)?);
        }
        if let Some(d) = search {
            i = i.search_settings(search_settings(d)?);
        }
        if allow_unpaired {
            i = i.allow_unpaired();
        }
        if quarantine {
            i = i.quarantine();
        }
        let mut slot = None;
        if let Some(f) = conductance {
            let raised = Raised::default();
            i = i.conductance(callback::model(f, depends_on_temperature, raised.clone()));
            slot = Some(raised);
        }
        let index = self.inner.add_interaction(i).py_err()?;
        self.raised.extend(slot);
        Ok(index)
    }

    /// Add the interactions of a Sierra contact deck given as text (``name`` labels its
    /// messages; relative paths in it are taken from the working directory); returns
    /// their indices. Its ``Contact Surface … Contains`` lines name the builder's
    /// surfaces or blocks.
    #[pyo3(signature = (text, name="deck"))]
    fn add_deck(&mut self, text: &str, name: &str) -> PyResult<Vec<usize>> {
        self.inner.add_deck(name, text).py_err()
    }

    /// Add the interactions of a deck file (Sierra syntax or ``.toml``); relative paths
    /// in it are taken from its folder.
    fn add_deck_file(&mut self, path: std::path::PathBuf) -> PyResult<Vec<usize>> {
        self.inner.add_deck_file(Path::new(&path)).py_err()
    }

    /// Pair every interaction's side-A points with side-B faces anew (a full search).
    fn search(&mut self) -> PyResult<()> {
        self.inner.search().py_err()
    }

    /// The nodes moved (an (n, 3) array): keep the pairing, place its points on the moved
    /// faces, measure gaps anew.
    fn move_nodes(&mut self, coords: &Bound<'_, PyAny>) -> PyResult<()> {
        let c = array::points(coords, "coords")?;
        self.inner.move_nodes(&c).py_err()
    }

    /// The host's time (s) that conductance models and plugins see.
    #[getter]
    fn get_time(&self) -> f64 {
        self.inner.time()
    }

    #[setter]
    fn set_time(&mut self, t: f64) -> PyResult<()> {
        self.inner.set_time(t).py_err()
    }

    fn __len__(&self) -> usize {
        self.inner.len()
    }

    /// The surface names (side A, side B) of interaction ``i``.
    fn surfaces(&self, i: usize) -> PyResult<(String, String)> {
        self.inner
            .surfaces(i)
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .ok_or_else(|| no_interaction(i, self.inner.len()))
    }

    /// Let interaction ``i`` (every interaction with None) pair nothing without
    /// ``NothingPairedError``.
    #[pyo3(signature = (i, allow=true))]
    fn allow_unpaired(&mut self, i: Option<usize>, allow: bool) -> PyResult<()> {
        self.inner.allow_unpaired(i, allow).py_err()
    }

    /// Switch interaction ``i`` on or off: off, it adds no terms and 0 W (the CSR
    /// pattern of :meth:`evaluate` is kept).
    fn set_active(&mut self, i: usize, on: bool) -> PyResult<()> {
        self.inner.set_active(i, on).py_err()
    }

    fn is_active(&self, i: usize) -> bool {
        self.inner.is_active(i)
    }

    /// The contact pressure (Pa) at each point of interaction ``i``, in the order of
    /// :meth:`point_fields`; None goes back to the enforcement's.
    fn set_point_pressures(
        &mut self,
        i: usize,
        pressures: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<()> {
        let p = pressures.map(|p| array::f64s(p, "pressures")).transpose()?;
        self.inner.set_point_pressures(i, p).py_err()
    }

    fn set_quarantine(&mut self, i: usize, on: bool) -> PyResult<()> {
        self.inner.set_quarantine(i, on).py_err()
    }

    /// The points of interaction ``i`` quarantined so far: (position, why) pairs.
    fn quarantined(&self, i: usize) -> Vec<((f64, f64, f64), String)> {
        self.inner
            .quarantined(i)
            .into_iter()
            .map(|q| ((q.x[0], q.x[1], q.x[2]), q.message))
            .collect()
    }

    /// Whether every interaction's terms are linear in the field.
    fn is_linear(&self) -> bool {
        self.inner.is_linear()
    }

    /// The interface terms of every flux interaction at the host's field ``u``: the
    /// Jacobian (exact, dh/dT included) as an (n, n) csr_matrix, residual and load as
    /// dense arrays of length n = len(u), the heat per interaction.
    fn contributions(&self, py: Python<'_>, u: &Bound<'_, PyAny>) -> PyResult<Contributions> {
        let u = array::f64s(u, "u")?;
        let n = u.len();
        let c = self.run(py, |e| e.contributions(&u))?;
        Ok(Contributions {
            jacobian: array::csr_from_triplets(py, (n, n), c.jacobian.into_iter())?,
            residual: array::dense(py, n, &c.residual),
            load: array::dense(py, n, &c.load),
            heat: heat_list(&c.heat),
        })
    }

    /// As :meth:`contributions`, with the Jacobian on a pattern that holds every entry
    /// the interface can fill (zeros included) and stays the same until the next search
    /// or move — ``pattern`` counts the patterns made, so a host keeps its symbolic
    /// factorisation while it does not change.
    fn evaluate(&mut self, py: Python<'_>, u: &Bound<'_, PyAny>) -> PyResult<Evaluation> {
        let u = array::f64s(u, "u")?;
        self.clear_raised();
        let r = self.inner.evaluate(&u).cloned();
        let e = self.finish(py, r)?;
        let n = e.jacobian.n;
        Ok(Evaluation {
            jacobian: array::csr(
                py,
                (n, n),
                e.jacobian.row_offsets,
                e.jacobian.columns,
                e.jacobian.values,
            )?,
            residual: array::array(py, e.residual),
            load: array::array(py, e.load),
            heat: heat_list(&e.heat),
            pattern: e.pattern,
        })
    }

    /// Heat (W) through every interaction at the host's field ``u``; None for mortar
    /// ties (their heat comes from the multipliers).
    fn heat(&self, py: Python<'_>, u: &Bound<'_, PyAny>) -> PyResult<Vec<Option<Heat>>> {
        let u = array::f64s(u, "u")?;
        let h = self.run(py, |e| e.heat(&u))?;
        Ok(heat_list(&h))
    }

    /// Heat (W) through interaction ``i`` at the host's field ``u``.
    fn heat_of(&self, py: Python<'_>, i: usize, u: &Bound<'_, PyAny>) -> PyResult<Option<Heat>> {
        let u = array::f64s(u, "u")?;
        let h = self.run(py, |e| e.heat_of(i, &u))?;
        Ok(heat_list(&[h])[0])
    }

    fn __repr__(&self) -> String {
        format!("Embedding({} interactions)", self.inner.len())
    }
}

pub fn no_interaction(i: usize, count: usize) -> PyErr {
    argument(
        format!("no interaction {i}, there are {count}"),
        "interaction indices are 0-based, in the order they were added",
    )
}
