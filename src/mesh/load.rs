//! Loading a mesh from a path or a built-in name. The format is detected from the content
//! (`$MeshFormat` header, version, file type), never from the file's extension.

use super::{Mesh, ReadError, builtin, msh, order};
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// The bytes of a mesh given on the command line, and the name errors use for it.
#[derive(Debug)]
pub struct Source {
    /// The path, or the built-in name.
    pub path: PathBuf,
    /// True for a built-in mesh.
    pub builtin: bool,
    /// The file's content.
    pub bytes: Cow<'static, [u8]>,
}

/// Finds the bytes of `spec`: an existing file path first, then a built-in name.
pub fn source(spec: &str) -> Result<Source, ReadError> {
    let path = Path::new(spec);
    if !path.exists() {
        if let Some(bytes) = builtin::bytes(spec) {
            return Ok(Source {
                path: path.to_path_buf(),
                builtin: true,
                bytes: Cow::Borrowed(bytes),
            });
        }
    }
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(Source {
        path: path.to_path_buf(),
        builtin: false,
        bytes: Cow::Owned(bytes),
    })
}

impl Source {
    /// Parses and validates the mesh, its elements in spatial order ([`order::spatial`]: the
    /// searches run faster on it; node and element tags are kept).
    pub fn mesh(&self) -> Result<Mesh, ReadError> {
        let mut file = msh::parse(&self.path, &self.bytes)?;
        order::spatial(&mut file.data);
        file.into_mesh(&self.path)
    }
}

/// Loads a mesh given as a file path or the name of a built-in case (see
/// [`builtin::NAMES`]). A path that exists wins over a built-in of the same name.
pub fn load(spec: &str) -> Result<Mesh, ReadError> {
    source(spec)?.mesh()
}
