//! Mesh validation.

use super::Mesh;

#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ValidationError {
    #[error("{0}")]
    Other(String),
}

impl Mesh {
    pub fn validate(&self) -> Result<(), ValidationError> {
        Ok(())
    }
}
