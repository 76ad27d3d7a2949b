//! `seam.Builder`: the host's mesh and numbering, checked by `build()`.

use pyo3::prelude::*;

use seam::embed::{EmbeddingBuilder, Integration, Topology};

use crate::array;
use crate::embedding::Embedding;
use crate::error::{OrPy, argument};

/// The host's arrays: node coordinates, element blocks, interface surfaces, its dof
/// number of each node and its Dirichlet nodes. Each method returns the builder, so
/// calls chain; ``build()`` checks everything and makes the :class:`Embedding`.
///
/// Conventions: node indices are 0-based rows of ``coords``; elements are numbered
/// block after block from 0, in the order the blocks were given; local sides are
/// 1-based in Exodus II order (Hex8 side 5 is the face of nodes 0 3 2 1, side 6 that of
/// 4 5 6 7; docs/embedding.md has every topology). Element nodes are in Exodus II order
/// too: a Hex8 lists its bottom face counter-clockwise seen from above, then the top
/// face above it — an element given in another order is reported as inverted.
#[pyclass(module = "seam")]
pub struct Builder {
    inner: Option<EmbeddingBuilder>,
}

impl Builder {
    fn update(&mut self, f: impl FnOnce(EmbeddingBuilder) -> EmbeddingBuilder) -> PyResult<()> {
        let b = self
            .inner
            .take()
            .ok_or_else(|| argument("the builder is empty", "make a new seam.Builder"))?;
        self.inner = Some(f(b));
        Ok(())
    }
}

/// A topology by name, case-insensitive.
fn topology(name: &str) -> PyResult<Topology> {
    match name.to_ascii_lowercase().as_str() {
        "hex8" | "hex" => Ok(Topology::Hex8),
        "tet4" | "tet" | "tetra" => Ok(Topology::Tet4),
        "wedge6" | "wedge" => Ok(Topology::Wedge6),
        "pyramid5" | "pyramid" => Ok(Topology::Pyramid5),
        _ => Err(argument(
            format!("unknown topology `{name}`"),
            "give \"hex8\", \"tet4\", \"wedge6\" or \"pyramid5\"",
        )),
    }
}

#[pymethods]
impl Builder {
    /// Start from the node coordinates, an (n, 3) array in m.
    #[new]
    fn new(coords: &Bound<'_, PyAny>) -> PyResult<Self> {
        let coords = array::points(coords, "coords")?;
        Ok(Builder {
            inner: Some(seam::embed::Embedding::builder(&coords)),
        })
    }

    /// An element block: ``topology`` is ``"hex8"``, ``"tet4"``, ``"wedge6"`` or
    /// ``"pyramid5"``; ``connectivity`` an (m, nodes per element) array of node indices
    /// in Exodus II order; ``conductivity`` (W/m/K) weighs the Nitsche forms.
    fn block<'py>(
        mut slf: PyRefMut<'py, Self>,
        name: &str,
        topology: &str,
        connectivity: &Bound<'py, PyAny>,
        conductivity: f64,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let t = self::topology(topology)?;
        let what = format!("connectivity of block `{name}`");
        let (conn, _) = array::index_rows(connectivity, &[t.node_count()], &what)?;
        slf.update(|b| b.block(name, t, &conn, conductivity))?;
        Ok(slf)
    }

    /// A surface of faces given as (element, side): ``elements`` 0-based (block after
    /// block), ``sides`` 1-based in Exodus II order; or one (m, 2) array as
    /// ``elements`` with ``sides`` left out.
    #[pyo3(signature = (name, elements, sides=None))]
    fn side_set<'py>(
        mut slf: PyRefMut<'py, Self>,
        name: &str,
        elements: &Bound<'py, PyAny>,
        sides: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let what = format!("surface `{name}`");
        let pairs: Vec<(usize, i64)> = match sides {
            Some(s) => {
                let e = array::indices(elements, &format!("elements of {what}"))?;
                let s = array::i64s(s, &format!("sides of {what}"))?;
                if e.len() != s.len() {
                    return Err(argument(
                        format!("{what}: {} elements and {} sides", e.len(), s.len()),
                        "give one side per element",
                    ));
                }
                e.into_iter().zip(s).collect()
            }
            None => {
                let (v, _) = array::index_rows(elements, &[2], &format!("{what} (element, side)"))?;
                v.chunks_exact(2).map(|p| (p[0], p[1] as i64)).collect()
            }
        };
        let sides = pairs
            .into_iter()
            .map(|(e, s)| {
                u8::try_from(s).map(|s| (e, s)).map_err(|_| {
                    argument(
                        format!("{what}: element {e} has no side {s}"),
                        "local sides are 1-based, Exodus order (1 to 6 for a Hex8)",
                    )
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        slf.update(|b| b.side_set(name, &sides))?;
        Ok(slf)
    }

    /// A surface of faces given by their corner nodes, an (m, 3) or (m, 4) array (any
    /// order, any rotation): each must be a side of exactly one element, whose outward
    /// normal it takes.
    fn face_set<'py>(
        mut slf: PyRefMut<'py, Self>,
        name: &str,
        faces: &Bound<'py, PyAny>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let (v, c) = array::index_rows(faces, &[3, 4], &format!("faces of surface `{name}`"))?;
        let faces: Vec<&[usize]> = v.chunks_exact(c).collect();
        slf.update(|b| b.face_set(name, &faces))?;
        Ok(slf)
    }

    /// The host's dof number of every node (length n); a negative number: the node has
    /// no temperature dof (it must belong to no block).
    fn dofs<'py>(
        mut slf: PyRefMut<'py, Self>,
        dofs: &Bound<'py, PyAny>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let d: Vec<Option<usize>> = array::i64s(dofs, "dofs")?
            .into_iter()
            .map(|d| usize::try_from(d).ok())
            .collect();
        slf.update(|b| b.partial_dofs(&d))?;
        Ok(slf)
    }

    /// Nodes whose value the host prescribes (Dirichlet): mortar ties give them no
    /// multiplier.
    fn fixed_nodes<'py>(
        mut slf: PyRefMut<'py, Self>,
        nodes: &Bound<'py, PyAny>,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let n = array::indices(nodes, "fixed_nodes")?;
        slf.update(|b| b.fixed_nodes(&n))?;
        Ok(slf)
    }

    /// How side-A points are placed: ``"segments"`` (default; the points of the overlap
    /// polygons of side-A and side-B faces, exact for polynomials of degree ``order``,
    /// default 5) or ``"quadrature"`` (Gauss points of side-A faces, projected; faster,
    /// not exact on non-matching meshes).
    #[pyo3(signature = (kind, order=5))]
    fn integration<'py>(
        mut slf: PyRefMut<'py, Self>,
        kind: &str,
        order: usize,
    ) -> PyResult<PyRefMut<'py, Self>> {
        let integration = match kind.to_ascii_lowercase().as_str() {
            "segments" => Integration::Segments { order },
            "quadrature" => Integration::Quadrature { order },
            _ => {
                return Err(argument(
                    format!("unknown integration `{kind}`"),
                    "give \"segments\" or \"quadrature\"",
                ));
            }
        };
        if order == 0 {
            return Err(argument(
                "integration order 0",
                "give an order of 1 or more",
            ));
        }
        slf.update(|b| b.integration(integration))?;
        Ok(slf)
    }

    /// Check every array (indices in range, valid elements, faces that are element
    /// sides, a dof for every block node) and make the embedding.
    fn build(&self) -> PyResult<Embedding> {
        let b = self
            .inner
            .clone()
            .ok_or_else(|| argument("the builder is empty", "make a new seam.Builder"))?;
        Ok(Embedding::new(b.build().py_err()?))
    }
}
