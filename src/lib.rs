//! seam: interface enforcement for implicit finite-element multiphysics codes.
//!
//! The modules, bottom to top (docs/architecture.md has the map, the data flow and
//! where to add a model, a mesh format or an equation); each uses only those below it:
//!
//! - [`fem`]: reference elements, shape functions, the one Gauss–Legendre rule;
//! - foundations: [`mesh`] (Exodus II, Gmsh, generators, validation), [`deck`] (Sierra
//!   syntax or TOML → typed spec), [`script`] (sandboxed Lua), [`periodic`] (maps),
//!   [`solve`] (sparse direct and AMG-CG), [`assembly`] (dofs and sparse patterns),
//!   [`output`] (Exodus, VTU, plots), [`diag`] (diagnostics), [`logging`] (the `log`
//!   records the library writes instead of printing);
//! - [`surface`]: contact surfaces by the Sierra rules;
//! - [`search`]: contact search over typed settings (BVH, projection, mortar segments);
//! - [`enforce`]: interface forms and conductance models at contact points;
//! - [`plugin`]: user models loaded as C-ABI shared libraries;
//! - [`scene`]: the one consumer of the deck spec — a contact definition resolved on a
//!   mesh into surfaces, interactions, searches and enforcements;
//! - hosts: [`embed`] (the public host API) and [`capi`] (its C face), [`heat`] (seam's
//!   conduction solvers, which take interfaces through [`heat::interfaces::Interfaces`])
//!   and [`run`] (`seam run`, itself a host of [`embed`]), which [`parallel`] runs on
//!   MPI and PETSc (`--features mpi`); the binary's CLI on top;
//! - [`error`]: [`Error`], wrapping every module's own error.
//!
//! Below them all, two crate-private helpers: `vec3` (3-vectors as arrays) and `slices`
//! (an array cut into pieces that threads fill in place).

pub mod assembly;
pub mod capi;
pub mod deck;
pub mod diag;
pub mod embed;
pub mod enforce;
pub mod error;
pub mod fem;
pub mod heat;
pub mod logging;
pub mod mesh;
pub mod output;
pub mod parallel;
pub mod periodic;
pub mod plugin;
pub mod run;
pub mod scene;
pub mod script;
pub mod search;
pub(crate) mod slices;
pub mod solve;
pub mod surface;
pub(crate) mod vec3;

pub use error::{Error, Result};
