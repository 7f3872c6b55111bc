//! One writer per results directory: a sweep holds an exclusive advisory lock of the
//! operating system on `DIR/.lock` (`flock(2)`; `File::try_lock` off Unix) for as long as it
//! runs. A second sweep into the same directory (two `--resume` at once, two shards given the
//! same `--out`) is refused rather than left to interleave its records. The kernel releases
//! the lock when its process ends, however it ends (`kill -9` included), so a stale lock
//! cannot exist: a leftover `.lock` file, whatever it holds, is simply locked again. The file
//! holds the holder's process id, for messages only.

use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, Write};
use std::path::{Path, PathBuf};

use super::ExperimentError;

/// File name of the lock in a results directory.
pub const LOCK_FILE: &str = ".lock";

/// A held lock, released when dropped (or when the process ends).
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
    /// The locked file: the lock lives as long as this open file.
    _file: File,
}

impl DirLock {
    /// Takes the lock of `dir` (which must exist), or fails at once with
    /// [`ExperimentError::Busy`] when another process holds it.
    pub fn acquire(dir: &Path) -> Result<DirLock, ExperimentError> {
        let path = dir.join(LOCK_FILE);
        let io = |e| ExperimentError::io(&path, e);
        // A holder that finishes removes the file it locked; one that opened that file just
        // before locks a file no longer in the directory and must try again on the new one.
        for _ in 0..100 {
            if let Ok(meta) = std::fs::symlink_metadata(&path)
                && !meta.is_file()
            {
                return Err(ExperimentError::Invalid(format!(
                    "{}: is {}, not a sweep's lock file; remove it (no sweep uses it)",
                    path.display(),
                    crate::mesh::file_kind(&meta)
                )));
            }
            let mut file = OpenOptions::new()
                .read(true)
                .write(true)
                .create(true)
                .truncate(false)
                .open(&path)
                .map_err(io)?;
            match try_lock(&file) {
                Ok(true) => {}
                Ok(false) => {
                    let mut text = String::new();
                    let _ = file.read_to_string(&mut text);
                    return Err(ExperimentError::Busy {
                        dir: dir.to_path_buf(),
                        pid: text.trim().parse().ok(),
                    });
                }
                Err(e) => return Err(io(e)),
            }
            if !still_at(&file, &path) {
                continue;
            }
            // The process id is for messages; the lock holds without it (a full disk).
            let me = std::process::id();
            let _ = file
                .set_len(0)
                .and_then(|()| file.rewind())
                .and_then(|()| file.write_all(format!("{me}\n").as_bytes()));
            return Ok(DirLock { path, _file: file });
        }
        Err(ExperimentError::Busy {
            dir: dir.to_path_buf(),
            pid: None,
        })
    }
}

/// Takes an exclusive lock on `file` without waiting: `Ok(false)` when another open file
/// holds it.
#[cfg(unix)]
fn try_lock(file: &File) -> std::io::Result<bool> {
    use rustix::fs::{FlockOperation, flock};
    match flock(file, FlockOperation::NonBlockingLockExclusive) {
        Ok(()) => Ok(true),
        Err(e) if e == rustix::io::Errno::WOULDBLOCK => Ok(false),
        Err(e) => Err(e.into()),
    }
}

#[cfg(not(unix))]
#[allow(clippy::incompatible_msrv)] // File::try_lock is Rust 1.89; Unix builds do not use it.
fn try_lock(file: &File) -> std::io::Result<bool> {
    match file.try_lock() {
        Ok(()) => Ok(true),
        Err(std::fs::TryLockError::WouldBlock) => Ok(false),
        Err(std::fs::TryLockError::Error(e)) => Err(e),
    }
}

/// Whether `path` still names the open `file` (it was not removed or replaced meanwhile).
fn still_at(file: &File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (file.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (file, path);
        true
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        // Removed while still locked (the file closes after this), so that nobody locks a
        // file that is about to disappear without noticing (see `acquire`).
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_lock_is_refused_and_a_leftover_file_is_no_lock() {
        let dir = tempfile::tempdir().unwrap();
        let lock = DirLock::acquire(dir.path()).unwrap();
        let held = std::fs::read_to_string(dir.path().join(LOCK_FILE)).unwrap();
        assert_eq!(held.trim(), std::process::id().to_string());
        // A second open file description is refused even within one process.
        let err = DirLock::acquire(dir.path()).unwrap_err();
        let me = std::process::id();
        assert!(
            matches!(err, ExperimentError::Busy { pid: Some(p), .. } if p == me),
            "{err}"
        );
        assert!(err.to_string().contains(&format!("process {me}")), "{err}");
        drop(lock);
        assert!(!dir.path().join(LOCK_FILE).exists());
        // Files left by a PID-file lock (a reused pid, pid 1, an empty file) hold nothing.
        for text in ["1\n", "", "4294967\n", "junk"] {
            std::fs::write(dir.path().join(LOCK_FILE), text).unwrap();
            drop(DirLock::acquire(dir.path()).unwrap());
        }
    }

    #[test]
    fn a_lock_that_is_a_directory_is_named() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join(LOCK_FILE)).unwrap();
        let err = DirLock::acquire(dir.path()).unwrap_err().to_string();
        assert!(
            err.contains(".lock: is a directory, not a sweep's lock file"),
            "{err}"
        );
    }
}
