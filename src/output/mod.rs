//! Writing a file whole or not at all: every file quadrecomb writes (meshes, manifests,
//! summaries, the optimum cache, reports and figures) goes through [`write_atomic`].
//!
//! The content goes to a temporary file created exclusively, under a random name, in the
//! target's own directory (so nobody can plant a link at a predictable name and make the
//! write land elsewhere), reaches the disk, and is renamed over the target. A failed write
//! (a full disk) leaves the earlier file as it was and removes the temporary. A temporary left
//! by a killed process is removed by the next write of the same file (module `stale`).

use std::io::{self, Write};
use std::path::{Path, PathBuf};

mod stale;

/// Creates and removes the temporary file [`write_atomic`] would write `path` through (in the
/// same directory, named after the file): checks before the work that the directory takes it
/// and that the name is not too long for the file system.
pub fn check_temporary(path: &Path) -> io::Result<()> {
    let target = resolve(path);
    let (dir, name) = dir_and_name(&target);
    let prefix = stale::prefix(name);
    tempfile::Builder::new()
        .prefix(&prefix)
        .suffix(".tmp")
        .tempfile_in(dir)
        .map(drop)
}

/// The directory `target` is in (`.` for a bare name) and its file name.
fn dir_and_name(target: &Path) -> (&Path, &std::ffi::OsStr) {
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = target
        .file_name()
        .unwrap_or_else(|| std::ffi::OsStr::new("output"));
    (dir, name)
}

/// Writes the bytes produced by `fill` to `path` atomically.
///
/// A symbolic link at `path` is followed: the file it points to is replaced (or created, when
/// the link dangles), not the link.
/// An existing file keeps its permissions; a new one gets the usual `0666 & !umask`. An
/// existing directory, FIFO, socket or device at `path` is refused (replacing a device node
/// with a regular file is never what was meant). Errors do not name `path`: callers add it.
pub fn write_atomic(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> io::Result<()>,
) -> io::Result<()> {
    let target = resolve(path);
    let existing = match std::fs::metadata(&target) {
        Ok(meta) if meta.is_file() => Some(meta.permissions()),
        Ok(meta) => {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "exists and is {}, not a regular file: refusing to replace it",
                    crate::mesh::file_kind(&meta)
                ),
            ));
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => None,
        Err(e) => return Err(e),
    };
    let (dir, name) = dir_and_name(&target);
    stale::remove_stale(dir, name);
    let prefix = stale::prefix(name);
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    if existing.is_none() {
        use std::os::unix::fs::PermissionsExt;
        // Masked by the umask at creation, as for any new file.
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    // Dropping `tmp` on any error below removes the temporary.
    let tmp = builder.tempfile_in(dir)?;
    let mut w = io::BufWriter::new(tmp);
    fill(&mut w)?;
    w.flush()?;
    let tmp = w.into_inner().map_err(|e| e.into_error())?;
    if let Some(perm) = existing {
        tmp.as_file().set_permissions(perm)?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(&target).map_err(|e| e.error)?;
    Ok(())
}

/// [`write_atomic`] of bytes held in memory.
pub fn write_bytes(path: &Path, bytes: &[u8]) -> io::Result<()> {
    write_atomic(path, |w| w.write_all(bytes))
}

/// The file a path names once its symbolic links are followed: for a path that does not
/// exist yet, the path itself, or, for a link that leads to no file (yet), the file it would
/// create, as a shell's `>` does (its directory may not exist: creating the temporary then
/// fails). A loop of links ends after 40 steps, on a link: creating beside it fails or
/// replaces it.
pub fn resolve(path: &Path) -> PathBuf {
    if let Ok(p) = std::fs::canonicalize(path) {
        return p;
    }
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        let Ok(target) = std::fs::read_link(&p) else {
            break;
        };
        p = match p.parent() {
            Some(dir) if target.is_relative() => dir.join(target),
            _ => target,
        };
    }
    p
}

/// For a symbolic link at `path` that leads to a place where no file can be made (its
/// directory missing, or a loop of links), the place it leads to; `None` for anything else,
/// a link to an existing file or to a file that can be created included. A write through
/// such a link fails, so commands check their outputs with this before the work.
pub fn dead_end_link(path: &Path) -> Option<PathBuf> {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link || std::fs::metadata(path).is_ok() {
        return None;
    }
    // Dangling: fine when the file it names can be made (resolve ends on a link only in a
    // loop).
    let target = resolve(path);
    let dir_ok = target
        .parent()
        .is_none_or(|p| p.as_os_str().is_empty() || p.is_dir());
    let loops = std::fs::symlink_metadata(&target).is_ok_and(|m| m.is_symlink());
    (!dir_ok || loops).then_some(target)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn leftovers(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp"))
            .collect()
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_removes_its_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("report.md");
        write_bytes(&path, b"good report\n").unwrap();
        let err = write_atomic(&path, |w| {
            w.write_all(b"half a rep")?;
            Err(io::Error::other("disk full"))
        })
        .unwrap_err();
        assert_eq!(err.to_string(), "disk full");
        assert_eq!(std::fs::read(&path).unwrap(), b"good report\n");
        assert!(
            leftovers(dir.path()).is_empty(),
            "{:?}",
            leftovers(dir.path())
        );
    }

    #[cfg(unix)]
    #[test]
    fn links_are_followed_modes_kept_and_special_files_refused() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.msh");
        std::fs::write(&real, "old").unwrap();
        std::fs::set_permissions(&real, std::fs::Permissions::from_mode(0o640)).unwrap();
        let link = dir.path().join("link.msh");
        std::os::unix::fs::symlink(&real, &link).unwrap();
        write_bytes(&link, b"new").unwrap();
        assert_eq!(std::fs::read(&real).unwrap(), b"new");
        assert!(std::fs::symlink_metadata(&link).unwrap().is_symlink());
        let mode = std::fs::metadata(&real).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);

        let fifo = dir.path().join("fifo.msh");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let err = write_bytes(&fifo, b"x").unwrap_err().to_string();
            assert!(err.contains("a FIFO"), "{err}");
            use std::os::unix::fs::FileTypeExt;
            assert!(
                std::fs::symlink_metadata(&fifo)
                    .unwrap()
                    .file_type()
                    .is_fifo()
            );
        }
        let err = write_bytes(Path::new("/dev/null"), b"x").unwrap_err();
        assert!(err.to_string().contains("character device"), "{err}");
        assert!(leftovers(dir.path()).is_empty());
    }
}
