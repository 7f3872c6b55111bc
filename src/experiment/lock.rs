//! One writer per results directory: `DIR/.lock` holds the process id of the sweep writing
//! there. A second sweep into the same directory (two `--resume` at once, two shards given the
//! same `--out`) is refused rather than left to duplicate runs. A lock whose process is gone
//! (after `kill -9`) is stale and taken over; where `/proc` does not exist the owner cannot be
//! checked and a leftover lock is taken over too.

use std::fs::OpenOptions;
use std::io::Write;
use std::path::{Path, PathBuf};

use super::ExperimentError;

/// File name of the lock in a results directory.
pub const LOCK_FILE: &str = ".lock";

/// A held lock, released when dropped.
#[derive(Debug)]
pub struct DirLock {
    path: PathBuf,
}

fn alive(pid: u32) -> bool {
    Path::new("/proc/self").exists() && Path::new(&format!("/proc/{pid}")).exists()
}

impl DirLock {
    /// Takes the lock of `dir` (which must exist).
    pub fn acquire(dir: &Path) -> Result<DirLock, ExperimentError> {
        let path = dir.join(LOCK_FILE);
        let me = std::process::id();
        for _ in 0..2 {
            match OpenOptions::new().write(true).create_new(true).open(&path) {
                Ok(mut f) => {
                    f.write_all(format!("{me}\n").as_bytes())
                        .map_err(|e| ExperimentError::io(&path, e))?;
                    return Ok(DirLock { path });
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let owner = std::fs::read_to_string(&path)
                        .ok()
                        .and_then(|s| s.trim().parse::<u32>().ok());
                    if let Some(pid) = owner {
                        if pid != me && alive(pid) {
                            return Err(ExperimentError::Busy {
                                dir: dir.to_path_buf(),
                                pid,
                            });
                        }
                    }
                    // Stale (or unreadable, half-written) lock: remove and retry once.
                    let _ = std::fs::remove_file(&path);
                }
                Err(e) => return Err(ExperimentError::io(&path, e)),
            }
        }
        Err(ExperimentError::Busy {
            dir: dir.to_path_buf(),
            pid: 0,
        })
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn second_lock_is_refused_and_stale_lock_taken_over() {
        let dir = tempfile::tempdir().unwrap();
        let lock = DirLock::acquire(dir.path()).unwrap();
        // Held by a live process other than us: pid 1 always exists on Linux.
        drop(lock);
        if Path::new("/proc/1").exists() {
            std::fs::write(dir.path().join(LOCK_FILE), "1\n").unwrap();
            let err = DirLock::acquire(dir.path()).unwrap_err();
            assert!(matches!(err, ExperimentError::Busy { pid: 1, .. }), "{err}");
        }
        // A dead owner: a pid above the kernel's maximum.
        std::fs::write(dir.path().join(LOCK_FILE), "4294967\n").unwrap();
        let lock = DirLock::acquire(dir.path()).unwrap();
        let held = std::fs::read_to_string(dir.path().join(LOCK_FILE)).unwrap();
        assert_eq!(held.trim(), std::process::id().to_string());
        drop(lock);
        assert!(!dir.path().join(LOCK_FILE).exists());
    }
}
