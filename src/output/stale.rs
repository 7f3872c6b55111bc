//! The temporaries' names, and the removal of those a killed writer left behind.
//!
//! [`write_atomic`](super::write_atomic) names each temporary after its target and its
//! writer: `.NAME.PID@HOST-ID.XXXXXX.tmp`, where `PID` is the writing process, `HOST` this
//! machine's host name (letters, digits, `-` and `_`, at most 32) and `ID` 8 hex digits
//! that tell its process-id space apart (a hash of the host name, the boot's id and the PID
//! namespace: another machine, a reboot or a container gives another `ID`). A target name
//! longer than [`LONG_NAME`] bytes is shortened in `NAME` to its first [`KEPT`] bytes, `~` and
//! a hash of the whole name, so that every temporary's name fits in 255 bytes.
//!
//! A process killed before its rename (`kill -9`, a power cut) leaves its temporary behind.
//! The next write of the same target removes the temporaries of that target whose writer
//! had this `HOST-ID` (so its process ids are this process's to ask about) and no longer
//! exists, once they have not been modified for [`STALE_AFTER`]. A temporary of a live
//! process (stopped ones included), of another machine, boot or PID namespace, of another
//! target, or without a tag (written before the tag) is never touched.

use std::ffi::{OsStr, OsString};
use std::path::Path;
use std::sync::OnceLock;
use std::time::{Duration, SystemTime};

/// How long a dead writer's temporary must have been left unmodified before it is removed:
/// not needed for safety (the identity makes the process check sound) but a margin against
/// anything it did not foresee.
pub(super) const STALE_AFTER: Duration = Duration::from_secs(60);

/// Target names up to this many bytes are kept whole in their temporaries' names.
const LONG_NAME: usize = 180;
/// Bytes of a longer target name kept, before `~` and its hash.
const KEPT: usize = 150;

/// The start of every temporary of a file named `name`: `.NAME.`, `NAME` shortened when long.
fn head(name: &OsStr) -> Vec<u8> {
    let bytes = name_bytes(name);
    let mut head = vec![b'.'];
    if bytes.len() <= LONG_NAME {
        head.extend_from_slice(&bytes);
    } else {
        head.extend_from_slice(&bytes[..KEPT]);
        head.extend_from_slice(format!("~{:016x}", fnv1a(&[&bytes])).as_bytes());
    }
    head.push(b'.');
    head
}

/// The prefix of this process's temporaries of a file named `name`: `.NAME.PID@HOST-ID.`, or
/// `.NAME.` where no host name can be had.
pub(super) fn prefix(name: &OsStr) -> OsString {
    let mut p = head(name);
    if let Some(id) = identity() {
        p.extend_from_slice(format!("{}@{id}.", std::process::id()).as_bytes());
    }
    from_bytes(p)
}

/// Removes from `dir` the stale temporaries of the file `name` (see the module's doc) and
/// returns how many. Errors are ignored: a temporary that cannot be listed or removed stays,
/// and the write goes on.
pub(super) fn remove_stale(dir: &Path, name: &OsStr) -> usize {
    let (Some(id), Ok(entries)) = (identity(), std::fs::read_dir(dir)) else {
        return 0;
    };
    let own = std::process::id();
    let head = head(name);
    let now = SystemTime::now();
    let mut removed = 0;
    for entry in entries.flatten() {
        let file_name = name_bytes(&entry.file_name());
        let Some(pid) = file_name
            .strip_prefix(head.as_slice())
            .and_then(|rest| std::str::from_utf8(rest).ok())
            .and_then(|rest| writer(rest, id))
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
/// (`PID@HOST-ID.XXXXXX.tmp`), when its `HOST-ID` is `id`; None for any other name.
fn writer(rest: &str, id: &str) -> Option<u32> {
    let (tag, random) = rest.strip_suffix(".tmp")?.rsplit_once('.')?;
    if random.len() != 6 || !random.bytes().all(|b| b.is_ascii_alphanumeric()) {
        return None;
    }
    let (pid, theirs) = tag.split_once('@')?;
    if theirs != id || pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    pid.parse().ok()
}

/// `HOST-ID` of this process (see the module's doc), or None where there is no host name.
fn identity() -> Option<&'static str> {
    static ID: OnceLock<Option<String>> = OnceLock::new();
    ID.get_or_init(|| {
        let raw = raw_host().filter(|h| !h.is_empty())?;
        let host: String = String::from_utf8_lossy(&raw)
            .chars()
            .take(32)
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        let read = |p: &str| std::fs::read(p).unwrap_or_default();
        let ns = std::fs::read_link("/proc/self/ns/pid")
            .map(|p| name_bytes(p.as_os_str()))
            .unwrap_or_default();
        let hash = fnv1a(&[&raw, &read("/proc/sys/kernel/random/boot_id"), &ns]);
        Some(format!("{host}-{:08x}", hash as u32 ^ (hash >> 32) as u32))
    })
    .as_deref()
}

/// 64-bit FNV-1a of the parts, each followed by a 0 byte: stable across runs and builds.
fn fnv1a(parts: &[&[u8]]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for part in parts {
        for &b in part.iter().chain(&[0u8]) {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0100_0000_01b3);
        }
    }
    h
}

#[cfg(unix)]
fn name_bytes(name: &OsStr) -> Vec<u8> {
    use std::os::unix::ffi::OsStrExt;
    name.as_bytes().to_vec()
}

#[cfg(not(unix))]
fn name_bytes(name: &OsStr) -> Vec<u8> {
    name.to_string_lossy().into_owned().into_bytes()
}

#[cfg(unix)]
fn from_bytes(bytes: Vec<u8>) -> OsString {
    use std::os::unix::ffi::OsStringExt;
    OsString::from_vec(bytes)
}

#[cfg(not(unix))]
fn from_bytes(bytes: Vec<u8>) -> OsString {
    OsString::from(String::from_utf8_lossy(&bytes).into_owned())
}

#[cfg(unix)]
#[allow(unsafe_code)] // gethostname: std has no host name
fn raw_host() -> Option<Vec<u8>> {
    let mut buf = [0u8; 256];
    // SAFETY: the buffer is valid for its length; gethostname writes at most that many bytes.
    let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
    if r != 0 {
        return None;
    }
    let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
    Some(buf[..end].to_vec())
}

#[cfg(not(unix))]
fn raw_host() -> Option<Vec<u8>> {
    None
}

/// Whether a process `pid` exists in this PID namespace (signal 0 checks without sending;
/// a stopped process exists). A pid that is no single process's (0, or beyond `pid_t`)
/// reads as alive: nothing is removed for it.
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
    use std::os::unix::ffi::OsStrExt;

    /// A process id that existed and is gone: a child that has exited and been reaped.
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        pid
    }

    fn plant(dir: &Path, name: impl AsRef<OsStr>, age: Duration) {
        let f = File::create(dir.join(name.as_ref())).unwrap();
        f.set_modified(SystemTime::now() - age).unwrap();
    }

    #[test]
    fn only_a_dead_local_writers_idle_temporary_of_the_same_file_is_removed() {
        let dir = tempfile::tempdir().unwrap();
        let id = identity().expect("a host name");
        let dead = dead_pid();
        let mut live = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let old = STALE_AFTER + Duration::from_secs(60);
        let stale = format!(".report.md.{dead}@{id}.a1B2c3.tmp");
        let (host, hash) = id.rsplit_once('-').unwrap();
        let kept = [
            // A live writer's, however old.
            format!(".report.md.{}@{id}.a1B2c3.tmp", live.id()),
            // Another machine's, boot's or PID namespace's (same host name, other id).
            format!(
                ".report.md.{dead}@{host}-{:08x}.a1B2c3.tmp",
                u32::from_str_radix(hash, 16).unwrap() ^ 1
            ),
            format!(".report.md.{dead}@{id}x.a1B2c3.tmp"),
            // Another target's.
            format!(".report.html.{dead}@{id}.a1B2c3.tmp"),
            // Not tagged (written before the tag).
            ".report.md.a1B2c3.tmp".to_string(),
            // Not a temporary's name.
            format!(".report.md.{dead}@{id}.a1B2c3.tmp.bak"),
            format!(".report.md.{dead}@{id}.a1B2.tmp"),
        ];
        plant(dir.path(), &stale, old);
        for k in &kept {
            plant(dir.path(), k, old);
        }
        // A dead writer's temporary, modified lately.
        let recent = format!(".report.md.{dead}@{id}.x9Y8z7.tmp");
        plant(dir.path(), &recent, Duration::from_secs(1));
        // A link with a stale name is not followed nor removed.
        let target = dir.path().join("precious");
        std::fs::write(&target, "keep").unwrap();
        let link = format!(".report.md.{dead}@{id}.L1nk00.tmp");
        std::os::unix::fs::symlink(&target, dir.path().join(&link)).unwrap();

        assert_eq!(remove_stale(dir.path(), OsStr::new("report.md")), 1);
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
    fn names_are_compared_as_bytes() {
        // `a\xff.msh` and `a\u{fffd}.msh` read alike when made lossy: their temporaries do not.
        let dir = tempfile::tempdir().unwrap();
        let id = identity().unwrap();
        let dead = dead_pid();
        let other = format!(".a\u{fffd}.msh.{dead}@{id}.abcdef.tmp");
        plant(dir.path(), &other, STALE_AFTER * 2);
        let mut ours = b".a\xff.msh.".to_vec();
        ours.extend_from_slice(format!("{dead}@{id}.abcdef.tmp").as_bytes());
        let ours = OsStr::from_bytes(&ours);
        plant(dir.path(), ours, STALE_AFTER * 2);
        assert_eq!(remove_stale(dir.path(), OsStr::from_bytes(b"a\xff.msh")), 1);
        assert!(dir.path().join(&other).exists());
        assert!(!dir.path().join(ours).exists());
    }

    #[test]
    fn the_next_write_of_the_file_removes_a_killed_writers_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.msh");
        let stale = format!(".out.msh.{}@{}.Qw3rty.tmp", dead_pid(), identity().unwrap());
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
    fn the_tag_names_this_process_and_long_names_are_shortened() {
        let id = identity().unwrap();
        let (host, hash) = id.rsplit_once('-').unwrap();
        assert!(
            host.len() <= 32 && !host.contains(['@', '.', '/']),
            "{host}"
        );
        assert!(hash.len() == 8 && hash.bytes().all(|b| b.is_ascii_hexdigit()));
        let tag = format!("{}@{id}", std::process::id());
        assert_eq!(
            prefix(OsStr::new("a.msh")),
            OsString::from(format!(".a.msh.{tag}."))
        );
        let rest = format!("{tag}.Ab12Cd.tmp");
        assert_eq!(writer(&rest, id), Some(std::process::id()));
        assert_eq!(writer(&rest, "elsewhere-00000000"), None);
        // The longest names still give temporaries of at most 255 bytes, distinct per name,
        // and a write of such a file works and cleans up after a killed writer.
        let (a, b) = ("x".repeat(255 - 4) + ".msh", "x".repeat(254 - 4) + "y.msh");
        let (pa, pb) = (prefix(OsStr::new(&a)), prefix(OsStr::new(&b)));
        assert_ne!(pa, pb);
        for p in [&pa, &pb] {
            assert!(p.len() + 6 + 4 <= 255, "{}", p.len());
        }
        let dir = tempfile::tempdir().unwrap();
        let mut stale = head(OsStr::new(&a));
        stale.extend_from_slice(format!("{}@{id}.zzzzzz.tmp", dead_pid()).as_bytes());
        let stale = from_bytes(stale);
        plant(dir.path(), &stale, STALE_AFTER * 2);
        super::super::write_bytes(&dir.path().join(&a), b"long").unwrap();
        assert!(!dir.path().join(&stale).exists());
        assert_eq!(std::fs::read(dir.path().join(&a)).unwrap(), b"long");
    }
}
