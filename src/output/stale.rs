//! Temporaries left behind by a killed writer, removed by the next write of the same file.
//!
//! [`write_atomic`](super::write_atomic) names each temporary after its target, the writing
//! process and its host: `.NAME.PID@HOST.XXXXXX.tmp`. A process killed before its rename
//! (`kill -9`, a power cut) leaves it behind. The next write of the same target removes the
//! temporaries of that target written by a process of this host that no longer exists, once
//! they have not been modified for [`STALE_AFTER`]. A temporary of a live process, of
//! another host (a shared file system), of another target, or without a tag (written before
//! the tag, or a name too long to carry it) is never touched.

use std::path::Path;
use std::sync::OnceLock;
use std::time::{Duration, SystemTime};

/// How long a dead process's temporary must have been left unmodified before it is removed:
/// a margin for a writer this host cannot see (another PID namespace with the same host
/// name), whose temporary keeps being modified while it writes.
pub(super) const STALE_AFTER: Duration = Duration::from_secs(60);

/// The longest file name most file systems take.
const NAME_MAX: usize = 255;

/// This process's tag, `PID@HOST`, or None where it cannot be had (no host name; not unix).
pub(super) fn own_tag() -> Option<&'static str> {
    static TAG: OnceLock<Option<String>> = OnceLock::new();
    TAG.get_or_init(|| host().map(|h| format!("{}@{h}", std::process::id())))
        .as_deref()
}

/// The prefix of this process's temporaries of a file named `name`: `.NAME.PID@HOST.`, or
/// `.NAME.` when there is no tag or the name would be too long for it.
pub(super) fn prefix(name: &str) -> String {
    match own_tag() {
        // tempfile appends 6 random characters, then ".tmp".
        Some(tag) if name.len() + tag.len() + 3 + 6 + 4 <= NAME_MAX => format!(".{name}.{tag}."),
        _ => format!(".{name}."),
    }
}

/// Removes from `dir` the stale temporaries of the file `name` (see the module's doc) and
/// returns how many. Errors are ignored: a temporary that cannot be listed or removed stays,
/// and the write goes on.
pub(super) fn remove_stale(dir: &Path, name: &str) -> usize {
    let (Some(host), Ok(entries)) = (host(), std::fs::read_dir(dir)) else {
        return 0;
    };
    let own = std::process::id();
    let head = format!(".{name}.");
    let now = SystemTime::now();
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = entry.file_name();
        let Some(pid) = file_name
            .to_str()
            .and_then(|f| f.strip_prefix(&head))
            .and_then(|rest| writer(rest, &host))
        else {
            continue;
        };
        if pid == own || alive(pid) {
            continue;
        }
        // Not followed through a link: only a plain file is ours to remove.
        let Ok(meta) = std::fs::symlink_metadata(entry.path()) else {
            continue;
        };
        let idle = meta
            .modified()
            .ok()
            .and_then(|m| now.duration_since(m).ok());
        if meta.is_file()
            && idle.is_some_and(|d| d >= STALE_AFTER)
            && std::fs::remove_file(entry.path()).is_ok()
        {
            removed += 1;
        }
    }
    removed
}

/// The writer's process id of a temporary whose name, after `.NAME.`, is `rest`
/// (`PID@HOST.XXXXXX.tmp`), when it was written on `host`; None for any other name.
fn writer(rest: &str, host: &str) -> Option<u32> {
    let (tag, random) = rest.strip_suffix(".tmp")?.rsplit_once('.')?;
    if random.len() != 6 || !random.bytes().all(|b| b.is_ascii_alphanumeric()) {
        return None;
    }
    let (pid, their_host) = tag.split_once('@')?;
    if their_host != host || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// This machine's host name, reduced to letters, digits and `-` (others read `_`; at most 64
/// bytes), so that it holds no `@`, `.` or `/`.
fn host() -> Option<String> {
    static HOST: OnceLock<Option<String>> = OnceLock::new();
    HOST.get_or_init(raw_host)
        .as_ref()
        .map(|h| {
            h.chars()
                .take(64)
                .map(|c| {
                    if c.is_ascii_alphanumeric() || c == '-' {
                        c
                    } else {
                        '_'
                    }
                })
                .collect::<String>()
        })
        .filter(|h| !h.is_empty())
}

#[cfg(unix)]
#[allow(unsafe_code)] // gethostname: std has no host name
fn raw_host() -> Option<String> {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is valid for its length; gethostname writes at most that many bytes.
    let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if r != 0 {
        return None;
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    Some(String::from_utf8_lossy(&buf[..end]).into_owned())
}

#[cfg(not(unix))]
fn raw_host() -> Option<String> {
    None
}

/// Whether a process `pid` exists on this host (signal 0 checks without sending). A pid that
/// is no single process's (0, or beyond `pid_t`) reads as alive: nothing is removed for it.
#[cfg(unix)]
#[allow(unsafe_code)] // kill(pid, 0): std cannot ask whether a process exists
fn alive(pid: u32) -> bool {
    let Ok(p) = libc::pid_t::try_from(pid) else {
        return true;
    };
    if p <= 0 {
        return true;
    }
    // SAFETY: kill with signal 0 sends nothing; it only checks that the process exists.
    let r = unsafe { libc::kill(p, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

#[cfg(not(unix))]
fn alive(_pid: u32) -> bool {
    true
}

#[cfg(all(test, unix))]
mod tests {
    use super::*;
    use std::fs::File;

    /// A process id that existed and is gone: a child that has exited and been reaped.
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    fn plant(dir: &Path, name: &str, age: Duration) {
        let f = File::create(dir.join(name)).unwrap();
        f.set_modified(SystemTime::now() - age).unwrap();
    }

    #[test]
    fn only_a_dead_local_writers_idle_temporary_of_the_same_file_is_removed() {
        let dir = tempfile::tempdir().unwrap();
        let host = host().expect("a host name");
        let dead = dead_pid();
        let mut live = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let old = STALE_AFTER + Duration::from_secs(60);
        let stale = format!(".report.md.{dead}@{host}.a1B2c3.tmp");
        let kept = [
            // A live writer's, however old.
            format!(".report.md.{}@{host}.a1B2c3.tmp", live.id()),
            // Another host's (a shared file system).
            format!(".report.md.{dead}@{host}x.a1B2c3.tmp"),
            // Another target's.
            format!(".report.html.{dead}@{host}.a1B2c3.tmp"),
            // Not tagged (written before the tag).
            ".report.md.a1B2c3.tmp".to_string(),
            // Not a temporary's name.
            format!(".report.md.{dead}@{host}.a1B2c3.tmp.bak"),
            format!(".report.md.{dead}@{host}.a1B2.tmp"),
        ];
        plant(dir.path(), &stale, old);
        for k in &kept {
            plant(dir.path(), k, old);
        }
        // A dead writer's temporary, modified lately.
        let recent = format!(".report.md.{dead}@{host}.x9Y8z7.tmp");
        plant(dir.path(), &recent, Duration::from_secs(1));
        // A link with a stale name is not followed nor removed.
        let target = dir.path().join("precious");
        std::fs::write(&target, "keep").unwrap();
        let link = format!(".report.md.{dead}@{host}.L1nk00.tmp");
        std::os::unix::fs::symlink(&target, dir.path().join(&link)).unwrap();

        assert_eq!(remove_stale(dir.path(), "report.md"), 1);
        live.kill().unwrap();
        live.wait().unwrap();
        assert!(!dir.path().join(&stale).exists());
        for k in kept.iter().chain([&recent, &link]) {
            assert!(
                std::fs::symlink_metadata(dir.path().join(k)).is_ok(),
                "{k} removed"
            );
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
    }

    #[test]
    fn the_next_write_of_the_file_removes_a_killed_writers_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.msh");
        let stale = format!(
            ".out.msh.{}@{}.Qw3rty.tmp",
            dead_pid(),
            host().expect("a host name")
        );
        plant(dir.path(), &stale, STALE_AFTER + Duration::from_secs(1));
        super::super::write_bytes(&path, b"mesh").unwrap();
        assert!(!dir.path().join(&stale).exists());
        let names: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["out.msh"]);
    }

    #[test]
    fn the_tag_names_this_process_and_a_long_name_goes_without_it() {
        let tag = own_tag().unwrap();
        let (pid, host) = tag.split_once('@').unwrap();
        assert_eq!(pid, std::process::id().to_string());
        assert!(!host.contains(['@', '.', '/']));
        assert_eq!(prefix("a.msh"), format!(".a.msh.{tag}."));
        let long = "x".repeat(240);
        assert_eq!(prefix(&long), format!(".{long}."));
        let rest = format!("{tag}.Ab12Cd.tmp");
        assert_eq!(writer(&rest, host), Some(std::process::id()));
        assert_eq!(writer(&rest, "elsewhere"), None);
    }
}
