//! Loading a mesh from a path or a built-in name. The format is detected from the content
//! (`$MeshFormat` header, version, file type), never from the file's extension.

use super::{Mesh, ReadError, builtin, msh, order, suite};
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

/// Finds the bytes of `spec`: an existing file path first, then a built-in name or a suite
/// member (`suite:NAME`, [`suite::PREFIX`]).
pub fn source(spec: &str) -> Result<Source, ReadError> {
    let path = Path::new(spec);
    if spec.is_empty() {
        // Named '' in the message, which would otherwise start with a bare colon.
        return Err(ReadError::Io {
            path: PathBuf::from("''"),
            source: std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "an empty mesh name: give a .msh file or a built-in mesh (borouchaki, sphere)",
            ),
        });
    }
    if !path.exists() {
        match suite::parse_spec(spec) {
            Some(Ok(member)) => {
                return Ok(Source {
                    path: path.to_path_buf(),
                    builtin: true,
                    bytes: member.bytes(),
                });
            }
            Some(Err(name)) => {
                return Err(ReadError::UnknownSuiteMember {
                    name: name.to_string(),
                    names: suite::member_names(),
                });
            }
            None => {
                // (The built-in members, sphere and borouchaki, load by their plain names.)
                let member = suite::member(spec).filter(|_| builtin::bytes(spec).is_none());
                if let Some(member) = member {
                    return Err(ReadError::Io {
                        path: path.to_path_buf(),
                        source: std::io::Error::new(
                            std::io::ErrorKind::NotFound,
                            format!(
                                "no such file; the benchmark suite's mesh of that name is {}",
                                suite::spec(member)
                            ),
                        ),
                    });
                }
            }
        }
    }
    if !path.exists() {
        if let Some(bytes) = builtin::bytes(spec) {
            return Ok(Source {
                path: path.to_path_buf(),
                builtin: true,
                bytes: Cow::Borrowed(bytes),
            });
        }
        // A bare word (no directory, no extension) was most likely meant as a name.
        if !spec.contains(['/', '.', '\\']) && !spec.is_empty() {
            return Err(ReadError::Io {
                path: path.to_path_buf(),
                source: std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    format!(
                        "no such file, nor a built-in mesh ({}) or a benchmark suite's mesh \
                         (suite:NAME, listed by `quadrecomb suite list`)",
                        builtin::NAMES.join(", ")
                    ),
                ),
            });
        }
    }
    let bytes = read_file(path)?;
    Ok(Source {
        path: path.to_path_buf(),
        builtin: false,
        bytes: Cow::Owned(bytes),
    })
}

/// Bytes read before the format is known.
const SNIFF_BYTES: usize = 64 * 1024;

/// Reads a mesh file: only a regular file (a FIFO without a writer blocked forever,
/// `/dev/zero` was read for gigabytes), and only as many bytes as it had when opened; the
/// rest is read only once its first bytes look like a MSH file (a 2 GB file of zeros was
/// read whole before being called an unknown format).
pub fn read_file(path: &Path) -> Result<Vec<u8>, ReadError> {
    use std::io::Read;
    let io = |source| ReadError::Io {
        path: path.to_path_buf(),
        source,
    };
    let not_regular = |meta: &std::fs::Metadata| {
        io(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!(
                "is {}, not a mesh file (only regular files are read)",
                file_kind(meta)
            ),
        ))
    };
    // Checked before opening: opening a FIFO waits for a writer.
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    let file = std::fs::File::open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(not_regular(&meta));
    }
    let len = meta.len();
    let mut reader = file.take(len);
    let mut bytes = Vec::new();
    (&mut reader)
        .take(SNIFF_BYTES as u64)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    let eof = (bytes.len() as u64) < SNIFF_BYTES as u64 || bytes.len() as u64 == len;
    let head = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    if let Some(start) = head.iter().position(|c| !c.is_ascii_whitespace()) {
        let known = head.len() - start >= b"$MeshFormat".len() || eof;
        if known && !msh::is_msh(head) {
            return Err(ReadError::unknown_format(path, &bytes));
        }
    }
    // Exactly the file's size: `read_to_end` doubles its buffer as it goes, which left the
    // buffer up to twice the file (84 bytes per triangle for a 48-byte-per-triangle strip).
    let rest = usize::try_from(len)
        .unwrap_or(usize::MAX)
        .saturating_sub(bytes.len());
    bytes.reserve_exact(rest);
    reader.read_to_end(&mut bytes).map_err(io)?;
    Ok(bytes)
}

impl Source {
    /// Parses and validates the mesh, its elements in spatial order ([`order::spatial`]: the
    /// searches run faster on it; node and element tags are kept). The file's bytes are
    /// freed as soon as they are parsed, before the spatial order and the topology are built
    /// (they were the largest part of the load's peak memory: the whole file, alive until
    /// the mesh was done).
    pub fn into_mesh(self) -> Result<Mesh, ReadError> {
        let Source { path, bytes, .. } = self;
        let mut file = msh::parse(&path, &bytes)?;
        drop(bytes);
        order::spatial(&mut file.data);
        file.into_mesh(&path)
    }
}

/// Loads a mesh given as a file path or the name of a built-in case (see
/// [`builtin::NAMES`]). A path that exists wins over a built-in of the same name.
pub fn load(spec: &str) -> Result<Mesh, ReadError> {
    source(spec)?.into_mesh()
}

/// What a file is, for messages: "a directory", "a FIFO (named pipe)", ...
pub fn file_kind(meta: &std::fs::Metadata) -> &'static str {
    let t = meta.file_type();
    if t.is_dir() {
        return "a directory";
    }
    if t.is_file() {
        return "a regular file";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if t.is_fifo() {
            return "a FIFO (named pipe)";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_char_device() {
            return "a character device";
        }
        if t.is_block_device() {
            return "a block device";
        }
    }
    "not a regular file"
}
