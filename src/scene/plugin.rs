//! From a deck's plugin enforcement to a plugin to load ([`PluginSpec`]) and to a
//! conductance model ([`PluginConductance`]).
//!
//! Entry points: [`plugin_spec`] and [`plugin_conductance`]. A relative `Library` path
//! is taken relative to the deck's directory; `Plugin Isolation` becomes the plugin's
//! [`Isolation`].

use std::path::{Path, PathBuf};

use crate::deck::spec::{Enforcement, PluginIsolation};
use crate::enforce::conductance::{PluginConductance, PluginLoadError};
use crate::plugin::{Isolation, PluginData, PluginError, PluginSpec};

/// The plugin of `enforcement`'s first `plugin` model, or an error saying what is
/// missing. A relative `Library` path is taken relative to `deck_dir`.
pub fn plugin_spec(enforcement: &Enforcement, deck_dir: &Path) -> Result<PluginSpec, PluginError> {
    let name = enforcement.name.as_deref().unwrap_or("(unnamed)");
    let model = enforcement
        .models
        .iter()
        .find(|m| m.model.eq_ignore_ascii_case("plugin"))
        .ok_or_else(|| PluginError::Spec(format!("enforcement {name} has no `Plugin` model")))?;
    let arg = |key: &str| {
        model
            .args
            .iter()
            .find(|a| a.key.eq_ignore_ascii_case(key))
            .map(|a| a.value.trim().trim_matches('"').to_owned())
            .filter(|v| !v.is_empty())
    };
    let library = arg("library").ok_or_else(|| {
        PluginError::Spec(format!(
            "enforcement {name}: `Enforcement for {} = Plugin` needs `Library = \"path/libmodel.so\"`",
            model.equation
        ))
    })?;
    let library = PathBuf::from(library);
    let path = if library.is_absolute() {
        library
    } else {
        deck_dir.join(library)
    };
    Ok(PluginSpec {
        path,
        data: PluginData {
            model: arg("model"),
            integer_data: enforcement.integer_data.clone(),
            real_data: enforcement.real_data.clone(),
        },
        isolation: isolation(enforcement.plugin_isolation),
    })
}

/// The plugin of the deck's `Enforcement for Energy = Plugin Library = "…" Model = …`
/// with the block's `Integer Data` / `Real Data` (a relative library path is taken
/// from `deck_dir`), loaded as a conductance model and told the interaction's surfaces.
pub fn plugin_conductance(
    enforcement: &Enforcement,
    deck_dir: &Path,
    surface_a: &str,
    surface_b: &str,
) -> Result<PluginConductance, PluginLoadError> {
    PluginConductance::load(&plugin_spec(enforcement, deck_dir)?, surface_a, surface_b)
}

/// Where the deck says a plugin runs.
pub fn isolation(i: PluginIsolation) -> Isolation {
    match i {
        PluginIsolation::None => Isolation::None,
        PluginIsolation::Process => Isolation::Process,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::deck::spec::{Arg, EnforcementModel};

    fn arg(key: &str, value: &str) -> Arg {
        Arg {
            key: key.into(),
            value: value.into(),
        }
    }

    #[test]
    fn library_is_resolved_against_the_deck_directory() {
        let e = Enforcement {
            name: Some("gap".into()),
            models: vec![EnforcementModel {
                equation: "energy".into(),
                model: "plugin".into(),
                args: vec![arg("library", "lib/libm.so"), arg("model", "cmy")],
                at: Default::default(),
            }],
            integer_data: vec![4],
            real_data: vec![1.5],
            ..Enforcement::default()
        };
        let s = plugin_spec(&e, Path::new("/decks/a")).unwrap();
        assert_eq!(s.path, PathBuf::from("/decks/a/lib/libm.so"));
        assert_eq!(s.data.model.as_deref(), Some("cmy"));
        assert_eq!(
            (s.data.integer_data, s.data.real_data),
            (vec![4], vec![1.5])
        );
        let mut no_lib = e.clone();
        no_lib.models[0].args.remove(0);
        let err = plugin_spec(&no_lib, Path::new(".")).unwrap_err();
        assert!(err.to_string().contains("needs `Library"), "{err}");
    }
}
