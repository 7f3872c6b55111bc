//! Errors at the command line's edge: the exit code of an error, and its message, where a
//! library error that names a value is worded with the flag that sets it.
//!
//! | code | meaning |
//! |------|---------|
//! | 0 | success |
//! | 1 | any other failure (a file the system cannot read or write, no GPU, a bug) |
//! | 2 | usage error: an unknown flag or a value it refuses (clap), a value out of range |
//! | 3 | bad input: a mesh file unreadable or invalid, a results directory whose files are corrupt or do not form one sweep |
//! | 4 | the results directory cannot be used: it holds other runs or another configuration, another sweep, merge or report is writing it, or it is not a directory or lies under a file |
//! | 5 | out of memory ([`super::oom`]; the GPU's too: [`GpuError::OutOfMemory`]) |
//! | 130 | interrupted (Ctrl-C, SIGTERM or SIGHUP) |

use std::error::Error;

use quadrecomb::internals::experiment::ExperimentError;
use quadrecomb::internals::gpu::GpuError;
use quadrecomb::internals::report::ReportError;

use super::UsageError;

/// Any other failure.
pub const EXIT_FAILURE: u8 = 1;
/// A usage error (clap's own code for its errors).
pub const EXIT_USAGE: u8 = 2;
/// An input file (mesh, results) is unreadable or invalid.
pub const EXIT_BAD_INPUT: u8 = 3;
/// The results directory cannot be used as asked.
pub const EXIT_RESULTS_DIR: u8 = 4;
/// Out of memory.
pub const EXIT_OUT_OF_MEMORY: u8 = 5;
/// Interrupted by Ctrl-C (128 + SIGINT, as shells report it).
pub const EXIT_INTERRUPTED: u8 = 130;

/// The exit code of an error: that of the outermost cause that has one, else
/// [`EXIT_FAILURE`].
pub fn exit_code(err: &anyhow::Error) -> u8 {
    err.chain().find_map(code).unwrap_or(EXIT_FAILURE)
}

/// A results directory the command cannot use as given, worded by the command with the
/// user's own path (exit code [`EXIT_RESULTS_DIR`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UnusableResultsDir(pub String);

/// Refuses, before any work, a results directory `--out DIR` that cannot be one: `dir` is a
/// file, or lies under a file (`--out f/sub` named the internal `f/sub/optimum-cache` when
/// the sweep failed to create it). Names the user's path and the file in the way.
pub fn check_results_dir(dir: &std::path::Path) -> anyhow::Result<()> {
    // A symbolic link on the way that leads nowhere (dangling, or a loop): nothing can be
    // made there, and the sweep would find out only after loading and calibrating.
    for a in dir.ancestors().filter(|a| !a.as_os_str().is_empty()) {
        let is_link = std::fs::symlink_metadata(a).is_ok_and(|m| m.file_type().is_symlink());
        if is_link && let Err(e) = std::fs::metadata(a) {
            return Err(UnusableResultsDir(format!(
                "--out {}: {} is a symbolic link that leads nowhere ({e}); choose another --out \
                 or fix the link",
                dir.display(),
                a.display()
            ))
            .into());
        }
    }
    // A file the sweep writes that is a symbolic link to a place where no file can be made
    // (its directory missing, a loop): the write goes through the link, so it would fail
    // after every run.
    for name in quadrecomb::internals::experiment::engine::SWEEP_FILES {
        let path = dir.join(name);
        if let Some(target) = quadrecomb::internals::output::dead_end_link(&path) {
            return Err(UnusableResultsDir(format!(
                "--out {}: {} is a symbolic link to {}, where no file can be made; fix or \
                 remove the link",
                dir.display(),
                path.display(),
                target.display()
            ))
            .into());
        }
    }
    // The report's figures go in DIR/figures: a file there would stop it after every run.
    let figures = dir.join("figures");
    if let Ok(meta) = std::fs::metadata(&figures)
        && !meta.is_dir()
    {
        return Err(UnusableResultsDir(format!(
            "--out {}: {} is {}, where the report writes its figures directory; rename or \
             remove it",
            dir.display(),
            figures.display(),
            quadrecomb::internals::mesh::file_kind(&meta)
        ))
        .into());
    }
    let existing = dir
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .find_map(|a| std::fs::metadata(a).ok().map(|m| (a, m)));
    match existing {
        Some((a, meta)) if !meta.is_dir() => {
            let kind = quadrecomb::internals::mesh::file_kind(&meta).to_string();
            if a == dir {
                return Err(ExperimentError::NotADirectory {
                    dir: dir.to_path_buf(),
                    kind,
                }
                .into());
            }
            Err(UnusableResultsDir(format!(
                "--out {}: {} is {kind}, not a directory, so no results directory can be made \
                 under it; choose another --out",
                dir.display(),
                a.display()
            ))
            .into())
        }
        _ => Ok(()),
    }
}

/// The code one cause decides, if it decides one.
fn code(e: &(dyn Error + 'static)) -> Option<u8> {
    if e.is::<UsageError>() {
        return Some(EXIT_USAGE);
    }
    if e.is::<super::InputError>() {
        return Some(EXIT_BAD_INPUT);
    }
    if e.is::<UnusableResultsDir>() {
        return Some(EXIT_RESULTS_DIR);
    }
    if e.is::<quadrecomb::internals::mesh::ReadError>()
        || e.is::<quadrecomb::internals::mesh::MeshError>()
    {
        return Some(EXIT_BAD_INPUT);
    }
    if let Some(GpuError::OutOfMemory(_)) = e.downcast_ref::<GpuError>() {
        return Some(EXIT_OUT_OF_MEMORY);
    }
    if let Some(e) = e.downcast_ref::<ExperimentError>() {
        return experiment_code(e);
    }
    if let Some(quadrecomb::internals::finish::FinishError::Sheet(_)) = e.downcast_ref() {
        // The mesh has a component sheet refinement cannot make all-quad.
        return Some(EXIT_BAD_INPUT);
    }
    match e.downcast_ref::<ReportError>()? {
        ReportError::NotResults { .. } | ReportError::NoRuns { .. } => Some(EXIT_BAD_INPUT),
        ReportError::NoSuchPicture(..) | ReportError::NoSuchBaseline(..) => Some(EXIT_USAGE),
        // Transparent: the inner error is not in the chain.
        ReportError::Results(inner) => experiment_code(inner),
        _ => None,
    }
}

fn experiment_code(e: &ExperimentError) -> Option<u8> {
    use ExperimentError as E;
    match e {
        E::Invalid(_) => Some(EXIT_USAGE),
        E::Corrupt { .. }
        | E::Mesh { .. }
        | E::ForeignRecords { .. }
        | E::Merge(_)
        | E::TornPart { .. }
        | E::Finish { .. }
        | E::OptimumContradicted { .. } => Some(EXIT_BAD_INPUT),
        E::Mismatch { .. }
        | E::Extendable { .. }
        | E::AlreadyExists { .. }
        | E::MergeTargetNotEmpty { .. }
        | E::ForeignFiles { .. }
        | E::NotADirectory { .. }
        | E::Busy { .. } => Some(EXIT_RESULTS_DIR),
        // I/O, GPU and run failures: decided by their cause, else a failure.
        _ => None,
    }
}

/// The error and its causes on one line, `a: b: c`, skipping a cause whose message its parent
/// already ends with (typed errors often print their source in their own message too).
pub fn describe(err: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in err.chain() {
        let msg = flag_wording(cause).unwrap_or_else(|| cause.to_string());
        if out.ends_with(&msg) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&msg);
    }
    out
}

/// A library error's message with the flags that fix it, where its own names only values.
fn flag_wording(e: &(dyn Error + 'static)) -> Option<String> {
    if let Some(GpuError::NoAdapter) = e.downcast_ref::<GpuError>() {
        return Some(
            "no Vulkan adapter found (install a GPU driver or lavapipe, Debian package \
             mesa-vulkan-drivers, or use --backend cpu)"
                .into(),
        );
    }
    if let Some(e @ GpuError::OutOfMemory(_)) = e.downcast_ref::<GpuError>() {
        return Some(format!(
            "{e}; --backend cpu computes the qualities on the CPU (the kernel's f32 twin)"
        ));
    }
    use ExperimentError as E;
    Some(match e.downcast_ref::<ExperimentError>()? {
        e @ E::AlreadyExists { .. } => format!(
            "{e}; pass --resume to continue that sweep, --overwrite to replace it, or choose \
             another --out"
        ),
        e @ E::Extendable { .. } => format!(
            "{e}; pass --extend to add the new configurations to it, or choose another --out"
        ),
        e @ E::MergeTargetNotEmpty { .. } => {
            format!("{e}: choose another --out or remove that one")
        }
        e @ E::ForeignFiles { .. } => format!("{e}; choose another --out or move them"),
        e @ E::Busy { .. } => {
            format!("{e}; wait for it or stop it (or give a sweep or merge another --out)")
        }
        E::NotADirectory { dir, kind } => format!(
            "--out {}: is {kind}, not a directory (results go into a directory)",
            dir.display()
        ),
        E::TornPart { path } => format!(
            "{} ends with a torn line (the sweep was interrupted): run `quadrecomb sweep \
             --resume` there first",
            path.display()
        ),
        E::OptimumContradicted { run, why } => format!(
            "run {run}: {why}: the optimum recorded for its mesh is wrong (an edited optimum \
             cache?); run again with --overwrite"
        ),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::PathBuf;

    fn code_of(e: ExperimentError) -> u8 {
        exit_code(&anyhow::Error::new(e).context("running the sweep"))
    }

    #[test]
    fn each_kind_of_error_has_its_code() {
        let dir = PathBuf::from("d");
        assert_eq!(code_of(ExperimentError::Invalid("x".into())), EXIT_USAGE);
        assert_eq!(code_of(ExperimentError::Merge("x".into())), EXIT_BAD_INPUT);
        assert_eq!(
            code_of(ExperimentError::Busy {
                dir: dir.clone(),
                pid: None
            }),
            EXIT_RESULTS_DIR
        );
        assert_eq!(code_of(ExperimentError::Run("x".into())), EXIT_FAILURE);
        assert_eq!(
            code_of(ExperimentError::Io {
                path: dir.clone(),
                source: std::io::Error::other("x")
            }),
            EXIT_FAILURE
        );
        let extendable = ExperimentError::Extendable {
            dir: dir.clone(),
            message: "horizons [1, 2, 3] vs [1, 2]".into(),
        };
        let e = anyhow::Error::new(extendable);
        assert_eq!(exit_code(&e), EXIT_RESULTS_DIR);
        assert!(
            describe(&e).ends_with(
                "pass --extend to add the new configurations to it, or choose another --out"
            ),
            "{}",
            describe(&e)
        );
        let report = ReportError::Results(ExperimentError::AlreadyExists { dir, records: 1 });
        assert_eq!(exit_code(&report.into()), EXIT_RESULTS_DIR);
        assert_eq!(exit_code(&UsageError("x".into()).into()), EXIT_USAGE);
    }

    #[test]
    fn library_errors_are_worded_with_flags() {
        let e = anyhow::Error::new(ExperimentError::AlreadyExists {
            dir: PathBuf::from("d"),
            records: 3,
        });
        assert_eq!(
            describe(&e),
            "d: already holds 3 run(s) of a sweep; pass --resume to continue that sweep, \
             --overwrite to replace it, or choose another --out"
        );
        let e = anyhow::Error::new(ExperimentError::Gpu(GpuError::NoAdapter));
        assert!(
            describe(&e).starts_with("computing quad qualities: no Vulkan adapter found")
                && describe(&e).ends_with("or use --backend cpu)"),
            "{}",
            describe(&e)
        );
    }

    #[test]
    fn gpu_out_of_memory_is_exit_5_and_names_the_way_out() {
        let oom = GpuError::OutOfMemory("uploading 9 candidates (wgpu: Out of Memory)".into());
        let e = anyhow::Error::new(ExperimentError::Gpu(oom));
        assert_eq!(exit_code(&e), EXIT_OUT_OF_MEMORY);
        assert_eq!(
            describe(&e),
            "computing quad qualities: out of GPU memory while uploading 9 candidates (wgpu: \
             Out of Memory); --backend cpu computes the qualities on the CPU (the kernel's f32 \
             twin)"
        );
        let other = GpuError::Device("running the quality kernel: lost".into());
        let e = anyhow::Error::new(ExperimentError::Gpu(other));
        assert_eq!(exit_code(&e), EXIT_FAILURE);
    }
}
