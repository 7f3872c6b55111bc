//! Build identity for the sweeps' manifests: `QUADRECOMB_BUILD` is the git commit this
//! binary was built from, with `+modified` when tracked sources differ from it, or
//! `unknown` outside a git checkout (a crate from a registry or a tarball). A sweep records
//! it, so that timings are never compared across builds unawares.

use std::path::Path;
use std::process::Command;

fn main() {
    // `--no-optional-locks`: `git status` must not refresh the index, whose change would
    // make the next build run this script (and rebuild the crate) again, and so on.
    let git = |args: &[&str]| {
        Command::new("git")
            .arg("--no-optional-locks")
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    // Rebuilt when the sources or the checked-out commit change (not on every file of the
    // package, such as a sweep's results). Staging changes nothing that counts: a staged
    // change is a modification as an unstaged one is, until the commit moves the branch.
    for path in ["src", "shaders", "Cargo.toml", "Cargo.lock", "build.rs"] {
        println!("cargo:rerun-if-changed={path}");
    }
    if let Some(dir) = git(&["rev-parse", "--git-dir"]) {
        let dir = Path::new(&dir);
        // The branch's ref may be only in packed-refs until a commit writes it loose under
        // refs/heads, which is watched as a directory.
        let mut watched = vec![
            dir.join("HEAD"),
            dir.join("packed-refs"),
            dir.join("refs").join("heads"),
        ];
        if let Some(head) = git(&["symbolic-ref", "-q", "HEAD"]) {
            watched.push(dir.join(head));
        }
        // A path that does not exist would make every build stale (a fresh clone has no
        // packed-refs, say).
        for path in watched.iter().filter(|p| p.exists()) {
            println!("cargo:rerun-if-changed={}", path.display());
        }
    }
    let build = match git(&["rev-parse", "--short=12", "HEAD"]) {
        Some(commit) => {
            let sources = ["src", "shaders", "Cargo.toml", "Cargo.lock", "build.rs"];
            let mut args = vec!["status", "--porcelain", "--untracked-files=no", "--"];
            args.extend(sources);
            let modified = git(&args).is_none_or(|s| !s.is_empty());
            format!("{commit}{}", if modified { "+modified" } else { "" })
        }
        None => "unknown".to_string(),
    };
    println!("cargo:rustc-env=QUADRECOMB_BUILD={build}");
}
