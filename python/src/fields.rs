//! What a search paired and what the interface carries, point by point and face by
//! face, as numpy arrays (one entry per point or face).
//!
//! Faces are named as the host gave them: element index (0-based, block after block)
//! and 1-based local side; −1 where a point has no such face. Fluxes are W/m² from
//! side A to side B, gaps m (positive open).

use pyo3::prelude::*;

use seam::embed::{self, FaceValues, PointValues, UnpairedReason};

use crate::array::{self, array, points_array};
use crate::embedding::Embedding;
use crate::ties::TieConstraints;

/// What the last search of one interaction paired ([`Embedding::coverage`]).
#[pyclass(module = "seam", frozen, get_all)]
pub struct Coverage {
    /// Side-A integration points, and how many paired.
    pub points: usize,
    pub paired_points: usize,
    /// Side A's area (m²) and the part paired with side B.
    pub area: f64,
    pub paired_area: f64,
    /// The unpaired points: their indices (as in point_fields), positions (m, 3) and
    /// reasons: "no_face" (no side-B face within reach), "too_far" (farther along the
    /// normal than the tolerance), "normals_not_opposed", "outside_subdomain".
    pub unpaired_points: Py<PyAny>,
    pub unpaired_x: Py<PyAny>,
    pub unpaired_reasons: Vec<&'static str>,
    /// Smallest and largest gap over the paired points (m); None when nothing paired.
    pub gap_range: Option<(f64, f64)>,
}

#[pymethods]
impl Coverage {
    fn __repr__(&self) -> String {
        format!(
            "Coverage(points={}, paired_points={}, area={:e}, paired_area={:e}, gap_range={:?})",
            self.points, self.paired_points, self.area, self.paired_area, self.gap_range
        )
    }
}

fn reason(r: UnpairedReason) -> &'static str {
    match r {
        UnpairedReason::NoFace => "no_face",
        UnpairedReason::TooFar => "too_far",
        UnpairedReason::NormalsNotOpposed => "normals_not_opposed",
        UnpairedReason::OutsideSubdomain => "outside_subdomain",
    }
}

/// Per side-A point of an interaction ([`Embedding::point_fields`]).
#[pyclass(module = "seam", frozen, get_all)]
pub struct PointFields {
    /// Positions (m), (m, 3).
    pub x: Py<PyAny>,
    /// Integration weights (m²): each point's share of side A's area.
    pub weight: Py<PyAny>,
    pub paired: Py<PyAny>,
    /// The side-A face each point lies on and the side-B face it paired with: element
    /// and 1-based side, −1 where there is none.
    pub side_a_element: Py<PyAny>,
    pub side_a_side: Py<PyAny>,
    pub side_b_element: Py<PyAny>,
    pub side_b_side: Py<PyAny>,
    /// Gap (m, positive open) and flux from A to B (W/m²); 0 where not paired.
    pub gap: Py<PyAny>,
    pub flux: Py<PyAny>,
    /// Side A's temperature and side B's at the projection; NaN where not known.
    pub temp_a: Py<PyAny>,
    pub temp_b: Py<PyAny>,
    /// Mortar ties: the multiplier field at each point (NaN where none).
    pub multiplier: Py<PyAny>,
}

fn face_index(f: Option<embed::HostFace>) -> (i64, i64) {
    f.map_or((-1, -1), |f| (f.element as i64, i64::from(f.side)))
}

fn point_fields(py: Python<'_>, v: &[PointValues]) -> PyResult<PointFields> {
    let col = |f: &dyn Fn(&PointValues) -> f64| array(py, v.iter().map(f).collect());
    let int = |f: &dyn Fn(&PointValues) -> i64| array(py, v.iter().map(f).collect());
    let x: Vec<[f64; 3]> = v.iter().map(|p| p.x).collect();
    Ok(PointFields {
        x: points_array(py, &x)?,
        weight: col(&|p| p.weight),
        paired: array(py, v.iter().map(|p| p.paired).collect()),
        side_a_element: int(&|p| face_index(p.side_a).0),
        side_a_side: int(&|p| face_index(p.side_a).1),
        side_b_element: int(&|p| face_index(p.side_b).0),
        side_b_side: int(&|p| face_index(p.side_b).1),
        gap: col(&|p| p.gap),
        flux: col(&|p| p.flux),
        temp_a: col(&|p| p.temp_a),
        temp_b: col(&|p| p.temp_b),
        multiplier: col(&|p| p.multiplier.unwrap_or(f64::NAN)),
    })
}

/// Per face of an interaction ([`Embedding::face_fields`]): side A's faces, then side
/// B's if asked for.
#[pyclass(module = "seam", frozen, get_all)]
pub struct FaceFields {
    /// The face: element (0-based) and 1-based side.
    pub element: Py<PyAny>,
    pub side: Py<PyAny>,
    /// 0 for a side-A face, 1 for a side-B face.
    pub surface: Py<PyAny>,
    /// Area (m²), paired area (m²) and their ratio in [0, 1].
    pub area: Py<PyAny>,
    pub paired_area: Py<PyAny>,
    pub fraction: Py<PyAny>,
    /// Mean gap (m) and mean flux from A to B (W/m²) over the paired area; 0 with none.
    pub gap: Py<PyAny>,
    pub flux: Py<PyAny>,
}

fn face_fields(py: Python<'_>, v: &[FaceValues]) -> FaceFields {
    let col = |f: &dyn Fn(&FaceValues) -> f64| array(py, v.iter().map(f).collect());
    let int = |f: &dyn Fn(&FaceValues) -> i64| array(py, v.iter().map(f).collect());
    FaceFields {
        element: int(&|f| f.face.element as i64),
        side: int(&|f| i64::from(f.face.side)),
        surface: int(&|f| i64::from(f.side)),
        area: col(&|f| f.area),
        paired_area: col(&|f| f.paired_area),
        fraction: col(&|f| f.fraction),
        gap: col(&|f| f.gap),
        flux: col(&|f| f.flux),
    }
}

#[pymethods]
impl Embedding {
    /// What the last search of interaction ``i`` paired.
    fn coverage(&self, py: Python<'_>, i: usize) -> PyResult<Coverage> {
        let c = self.run(py, |e| e.coverage(i))?;
        let x: Vec<[f64; 3]> = c.unpaired.iter().map(|u| u.x).collect();
        Ok(Coverage {
            points: c.points,
            paired_points: c.paired_points,
            area: c.area,
            paired_area: c.paired_area,
            unpaired_points: array(py, c.unpaired.iter().map(|u| u.point as i64).collect()),
            unpaired_x: points_array(py, &x)?,
            unpaired_reasons: c.unpaired.iter().map(|u| reason(u.reason)).collect(),
            gap_range: c.gap_range,
        })
    }

    /// The values at every side-A point of flux interaction ``i`` at the host's field
    /// ``u``, in the interaction's point order (a mortar tie: :meth:`tie_point_fields`).
    fn point_fields(
        &self,
        py: Python<'_>,
        i: usize,
        u: &Bound<'_, PyAny>,
    ) -> PyResult<PointFields> {
        let u = array::f64s(u, "u")?;
        let v = self.run(py, |e| e.point_fields(i, &u))?;
        point_fields(py, &v)
    }

    /// Per face of flux interaction ``i`` at the host's field ``u``: side A's faces, then
    /// side B's with ``side_b``.
    #[pyo3(signature = (i, u, side_b=false))]
    fn face_fields(
        &self,
        py: Python<'_>,
        i: usize,
        u: &Bound<'_, PyAny>,
        side_b: bool,
    ) -> PyResult<FaceFields> {
        let u = array::f64s(u, "u")?;
        let v = self.run(py, |e| e.face_fields(i, &u, side_b))?;
        Ok(face_fields(py, &v))
    }

    /// The values at every side-A point of a mortar tie for its multipliers ``lam`` (one
    /// per multiplier: the host's unknowns, or :meth:`TieConstraints.dual_multipliers`).
    fn tie_point_fields(
        &self,
        py: Python<'_>,
        tie: &TieConstraints,
        lam: &Bound<'_, PyAny>,
    ) -> PyResult<PointFields> {
        let lam = array::f64s(lam, "lam")?;
        let v = self.run(py, |e| e.tie_point_fields(&tie.inner, &lam))?;
        point_fields(py, &v)
    }

    /// Per face of a mortar tie for its multipliers ``lam``.
    #[pyo3(signature = (tie, lam, side_b=false))]
    fn tie_face_fields(
        &self,
        py: Python<'_>,
        tie: &TieConstraints,
        lam: &Bound<'_, PyAny>,
        side_b: bool,
    ) -> PyResult<FaceFields> {
        let lam = array::f64s(lam, "lam")?;
        let v = self.run(py, |e| e.tie_face_fields(&tie.inner, &lam, side_b))?;
        Ok(face_fields(py, &v))
    }
}
