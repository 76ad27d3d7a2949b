//! `seam._seam`: the Python face of seam's embedding API ([`seam::embed`]).
//!
//! Entry points: [`builder::Builder`] takes the host's arrays (nodes, element blocks,
//! surfaces, dof numbers) and builds an [`embedding::Embedding`]; its methods add
//! interactions, search them and give the interface terms as numpy arrays and
//! scipy.sparse matrices in the host's dof numbers.
//!
//! Conventions are seam's (docs/embedding.md): 0-based node, element and dof indices,
//! elements numbered block after block, 1-based Exodus II local sides, SI units (m, K,
//! W, W/m/K, W/m²/K). Every failure is a `seam.SeamError` subclass whose `code` is the
//! status a C host gets for it (`SEAM_ERR_*` in include/seam.h).

use pyo3::prelude::*;

mod array;
mod builder;
mod callback;
mod embedding;
mod error;
mod fields;
mod ties;

#[pymodule]
fn _seam(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    error::register(m)?;
    m.add_class::<builder::Builder>()?;
    m.add_class::<embedding::Embedding>()?;
    m.add_class::<embedding::Heat>()?;
    m.add_class::<embedding::Contributions>()?;
    m.add_class::<embedding::Evaluation>()?;
    m.add_class::<callback::PointState>()?;
    m.add_class::<embedding::Rectangular>()?;
    m.add_class::<embedding::Cylindrical>()?;
    m.add_class::<embedding::AlignSurface>()?;
    m.add_class::<embedding::Mapped>()?;
    m.add_class::<fields::Coverage>()?;
    m.add_class::<fields::PointFields>()?;
    m.add_class::<fields::FaceFields>()?;
    m.add_class::<ties::TieConstraints>()?;
    Ok(())
}
