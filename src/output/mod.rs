//! Results for people and viewers.
//!
//! - [`exodus::ExodusWriter`]: Exodus II (netCDF 64-bit offset), the mesh with nodal and
//!   element variables over time, appended step by step; read back by
//!   [`crate::mesh::exodus`], ParaView, meshio and the SEACAS tools.
//! - [`vtu::write_vtu`], [`vtu::write_vtu_cells`]: VTK XML unstructured grids (`.vtu`)
//!   with point and cell data; [`vtu::PvdSeries`] collects them into a ParaView time
//!   series (`.pvd`).
//! - [`plot::Plot`]: line plots as SVG and PNG (residual histories, temperatures along a
//!   line), laid out by `plotters`, for a look without ParaView.

pub mod exodus;
mod netcdf;
pub mod plot;
pub mod vtu;
