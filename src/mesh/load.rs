//! Loading a mesh from a path or a built-in name.

use super::{Mesh, ReadError};

/// Loads a mesh given as a file path or the name of a built-in case.
pub fn load(spec: &str) -> Result<Mesh, ReadError> {
    Err(ReadError::UnknownFormat {
        path: spec.into(),
        builtins: super::builtin::NAMES.join(", "),
    })
}
