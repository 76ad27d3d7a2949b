//! [`Error`]: every error seam's library returns, one variant per module that can fail,
//! each keeping its module's own error (with its context: the surface, interaction,
//! element, file or plugin) so `?` carries it up unchanged and a caller can match on
//! where it came from.

use crate::diag::{Diagnostics, SourceMap};

/// Any error of seam's library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An input file that is not readable text (`diag::read_text`).
    #[error(transparent)]
    Read(#[from] crate::diag::ReadError),
    /// A deck or problem file with errors: its rendered diagnostics (file:line:col,
    /// code, caret, help).
    #[error("{0}")]
    Input(String),
    #[error(transparent)]
    Mesh(#[from] crate::mesh::MeshError),
    #[error(transparent)]
    Validation(#[from] crate::mesh::ValidationError),
    #[error(transparent)]
    Script(#[from] crate::script::ScriptError),
    #[error(transparent)]
    Map(#[from] crate::periodic::MapError),
    #[error(transparent)]
    Search(#[from] crate::search::pairing::SearchError),
    #[error(transparent)]
    Interface(#[from] crate::enforce::interface::InterfaceError),
    #[error(transparent)]
    Conductance(#[from] crate::enforce::conductance::ConductanceError),
    #[error(transparent)]
    Plugin(#[from] crate::plugin::PluginError),
    #[error(transparent)]
    Assembly(#[from] crate::assembly::AssemblyError),
    #[error(transparent)]
    Solve(#[from] crate::solve::SolveError),
    #[error(transparent)]
    Heat(#[from] crate::heat::HeatError),
    #[error(transparent)]
    Embed(#[from] crate::embed::EmbedError),
    /// `seam run` failed after its input was accepted (no convergence, a failing
    /// model): the message says where.
    #[error("{0}")]
    Run(String),
}

impl Error {
    /// Diagnostics of an input file, rendered with their sources.
    pub fn input(diagnostics: &Diagnostics, sources: &SourceMap) -> Error {
        Error::Input(diagnostics.render(sources))
    }
}

impl From<crate::run::RunError> for Error {
    fn from(e: crate::run::RunError) -> Error {
        match e {
            crate::run::RunError::Input(d, s) => Error::input(&d, &s),
            crate::run::RunError::Solve(m) => Error::Run(m),
        }
    }
}

/// `Result` with seam's [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    /// A module's error keeps its message through `?` into `seam::Error`.
    #[test]
    fn module_errors_convert_with_their_message() {
        fn embed_fails() -> Result<()> {
            let e = crate::embed::Embedding::builder(&[]).build();
            e?;
            Ok(())
        }
        let err = embed_fails().unwrap_err();
        assert!(matches!(err, Error::Embed(_)), "{err:?}");
        assert!(err.to_string().contains("no nodes"), "{err}");
        let run = Error::from(crate::run::RunError::Solve(
            "no convergence at t = 3".into(),
        ));
        assert_eq!(run.to_string(), "no convergence at t = 3");
    }
}
