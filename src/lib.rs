//! seam: interface enforcement for implicit finite-element multiphysics codes.
//!
//! The data flow, one module per arrow: [`deck`] (Sierra syntax or TOML → typed spec),
//! [`mesh`] (Exodus II, Gmsh, generators), [`surface`] (contact surfaces by the Sierra
//! rules), [`plugin`] (user enforcement models loaded as shared libraries). Diagnostics shared by all of them live in [`diag`].
//!
//! Layers depend only downward: [`fem`] (reference elements, the one Gauss rule) at the
//! bottom; [`search`], [`enforce`] and [`plugin`] over typed settings of their own, never
//! a deck; [`scene`] above them, which lowers the typed deck spec to those settings
//! ([`surface`] still reads its surface definitions from the spec itself); the hosts
//! ([`embed`], [`run`], the binary) on top.

pub mod assembly;
pub mod capi;
pub mod deck;
pub mod diag;
pub mod embed;
pub mod enforce;
pub mod error;
pub mod fem;
pub mod heat;
pub mod mesh;
pub mod output;
pub mod periodic;
pub mod plugin;
pub mod run;
pub mod scene;
pub mod script;
pub mod search;
pub mod solve;
pub mod surface;
pub(crate) mod vec3;

pub use error::{Error, Result};
