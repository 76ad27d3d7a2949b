//! A plugin to load: its library, its data and where it runs.

use std::path::PathBuf;

use super::{Isolation, Plugin, PluginData, PluginError};

/// A plugin to load: in a deck, `Enforcement for Energy = Plugin Library =
/// "path/libmodel.so" Model = name` with the block's `Integer Data` / `Real Data`, which
/// the scene makes into this.
#[derive(Clone, Debug, PartialEq)]
pub struct PluginSpec {
    /// The library (a deck's relative path is resolved against the deck's directory).
    pub path: PathBuf,
    pub data: PluginData,
    /// `Plugin Isolation`: in seam's process (default) or in a worker process.
    pub isolation: Isolation,
}

impl PluginSpec {
    /// Load the library and create the instance, in this process or in a worker.
    pub fn load(&self) -> Result<Plugin, PluginError> {
        Plugin::load_with_isolation(&self.path, &self.data, self.isolation)
    }
}
