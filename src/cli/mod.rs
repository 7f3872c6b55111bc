//! Subcommands, one module each: `Args` (clap derive) and `run(args)`.

/// `println!` that ignores a closed stdout (`quadrecomb ... | head -1`): a reader that
/// stopped reading must not turn a finished run into a panic (exit 101) or cut a sweep short
/// before its report. Any other failure (a full disk under `> out.json`) is kept for the end:
/// the command finishes, then says it and exits 1 ([`stdout_failure`]). Defined before the
/// submodules so that they all see it.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout(), $($arg)*) {
            $crate::cli::stdout_failed(e);
        }
    }};
}

/// The first failure to write stdout other than a closed pipe.
static STDOUT_FAILURE: std::sync::OnceLock<String> = std::sync::OnceLock::new();

/// Keeps `e` unless it is a closed pipe (see `outln!`).
pub fn stdout_failed(e: std::io::Error) {
    if e.kind() != std::io::ErrorKind::BrokenPipe {
        let _ = STDOUT_FAILURE.set(e.to_string());
    }
}

/// Flushes stdout and returns the first failure to write it other than a closed pipe: what
/// the command printed is incomplete, which its exit code must say.
pub fn stdout_failure() -> Option<String> {
    use std::io::Write as _;
    if let Err(e) = std::io::stdout().flush() {
        stdout_failed(e);
    }
    STDOUT_FAILURE.get().cloned()
}

/// `eprintln!` that ignores a closed stderr (`quadrecomb sweep ... 2>&1 | head -1`), for the
/// same reason as `outln!`: notes and progress are not worth the run.
macro_rules! noteln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr(), $($arg)*);
    }};
}

mod bench;
mod completions;
mod errors;
mod finish_report;
mod generate;
mod info;
mod merge;
pub mod oom;
mod optimum;
mod progress_bar;
mod recombine;
mod replay;
mod report;
mod suite;
mod sweep;
mod sweep_progress;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use std::process::ExitCode;

pub use errors::{describe, exit_code};

#[derive(Debug, Parser)]
#[command(name = "quadrecomb", version, about, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Print a mesh's size, topology and candidate quad qualities.
    Info(info::Args),
    /// Generate a procedural mesh (jittered grid, icosphere, strip, spiral, maze, lattice) of any size.
    Generate(generate::Args),
    /// Recombine a mesh's triangles into quads with one policy.
    Recombine(recombine::Args),
    /// Compute the exact optimum (maximum-weight matching, "Blossom-quad").
    Optimum(optimum::Args),
    /// Run a seeded horizon sweep (the paper's experiment) into a results directory.
    Sweep(sweep::Args),
    /// Merge sharded sweep results (or a sweep and its extension) into one directory.
    Merge(merge::Args),
    /// Write tables, figures and statistical comparisons for a results directory.
    Report(report::Args),
    /// Re-run a recorded run of a results directory, check it, and write it as .msh/.vtu (-o: only when the replay reproduces the record).
    Replay(replay::Args),
    /// Print benchmark figures.
    Bench(bench::Args),
    /// The benchmark suite's meshes (`suite list`), named suite:NAME anywhere a mesh is taken.
    Suite(suite::Args),
    /// Print a shell completion script (bash, zsh, fish) on stdout.
    Completions(completions::Args),
}

/// The command line's parser, where every option's value may be a negative number: `--runs -1`
/// gets the option's own message ("invalid digit", "must be at least 1") rather than clap's
/// "unexpected argument '-1'", which reads as a misspelt flag (numbers clap does not know as
/// numbers: [`join_negative_numbers`]).
fn command() -> clap::Command {
    fn negative_values(cmd: clap::Command) -> clap::Command {
        cmd.mut_args(|a| {
            if a.get_action().takes_values() {
                a.allow_negative_numbers(true)
            } else {
                a
            }
        })
        .mut_subcommands(negative_values)
    }
    negative_values(Cli::command())
}

/// `args` with a negative number after a long option that takes a value joined to it
/// (`--min-eta -1e-300` becomes `--min-eta=-1e-300`): clap reads `-1` and `-0.5` as
/// numbers but `-1e-300`, `-.5` and `-inf` as flags ("unexpected argument '-1'"). Only
/// tokens that parse as numbers are joined, and only after an option of the subcommand at
/// hand that takes values, so a missing value before a flag is still reported as one.
fn join_negative_numbers(
    cmd: &clap::Command,
    args: impl IntoIterator<Item = std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    let mut out = Vec::new();
    let mut cur = cmd;
    let mut args = args.into_iter().peekable();
    if let Some(program) = args.next() {
        out.push(program);
    }
    while let Some(arg) = args.next() {
        let Some(text) = arg.to_str() else {
            out.push(arg);
            continue;
        };
        if text == "--" {
            out.push(arg);
            out.extend(args);
            break;
        }
        if let Some(name) = text.strip_prefix("--").filter(|n| !n.contains('=')) {
            let takes_value = cur
                .get_arguments()
                .any(|a| a.get_long() == Some(name) && a.get_action().takes_values());
            let number = args
                .peek()
                .and_then(|next| next.to_str())
                .filter(|next| next.starts_with('-') && next.parse::<f64>().is_ok())
                .map(str::to_owned);
            if let (true, Some(number)) = (takes_value, number) {
                args.next();
                out.push(format!("{text}={number}").into());
                continue;
            }
        } else if !text.starts_with('-')
            && let Some(sub) = cur.find_subcommand(text)
        {
            cur = sub;
        }
        out.push(arg);
    }
    out
}

/// Parses the command line and runs the subcommand.
pub fn run() -> anyhow::Result<ExitCode> {
    let mut cmd = command();
    // clap's own message names no argument.
    if let Some(arg) = std::env::args_os().skip(1).find(|a| a.to_str().is_none()) {
        return Err(UsageError(format!(
            "the argument {arg:?} is not valid UTF-8: meshes, paths and names are recorded as \
             text (JSON, CSV, .msh); rename the file, or link to it under a UTF-8 name"
        ))
        .into());
    }
    let args = join_negative_numbers(&cmd, std::env::args_os());
    let matches = cmd
        .try_get_matches_from_mut(args)
        .unwrap_or_else(|e| e.exit());
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.format(&mut cmd).exit());
    match cli.command {
        Command::Info(args) => info::run(args),
        Command::Generate(args) => generate::run(args),
        Command::Recombine(args) => recombine::run(args),
        Command::Optimum(args) => optimum::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Merge(args) => merge::run(args),
        Command::Report(args) => report::run(args),
        Command::Replay(args) => replay::run(args),
        Command::Bench(args) => bench::run(args),
        Command::Suite(args) => suite::run(args),
        Command::Completions(args) => completions::run(args, command()),
    }
}

/// Which pairs may be merged: the flags of every command that recombines.
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct RuleArgs {
    /// Make no quad with eta below E (in [0, 1]). Quads with eta = 0 (a corner angle >= 180
    /// degrees: not strictly convex, or folded) are never made unless --allow-invalid.
    #[arg(
        long,
        value_name = "E",
        default_value_t = 0.0,
        allow_negative_numbers = true
    )]
    min_eta: f64,
    /// Every pair of neighbouring triangles is an action, eta-0 quads included (reward 0):
    /// the paper as written, under which results before the valid-quad rule were made.
    #[arg(long, conflicts_with = "min_eta")]
    allow_invalid: bool,
}

impl RuleArgs {
    /// The rule, or a usage error naming the flag.
    pub fn rule(&self) -> Result<quadrecomb::internals::quality::Rule, UsageError> {
        quadrecomb::internals::quality::Rule::new(self.min_eta, self.allow_invalid)
            .map_err(|e| UsageError(format!("--min-eta: {e}")))
    }

    /// The flags that give this rule again (for a child process).
    pub fn flags(&self) -> Vec<String> {
        if self.allow_invalid {
            vec!["--allow-invalid".into()]
        } else {
            vec!["--min-eta".into(), format!("{:?}", self.min_eta)]
        }
    }
}

/// Adds the element-quality fields and the rule to a `--json` object (the record's names).
pub fn add_element_fields(
    v: &mut serde_json::Value,
    e: &quadrecomb::internals::quality::ElementQuality,
    rule: quadrecomb::internals::quality::Rule,
) {
    v["worst_eta"] = serde_json::json!(e.worst);
    v["mean_eta"] = serde_json::json!(e.mean);
    v["quads_eta_below_0_1"] = serde_json::json!(e.below_0_1);
    v["quads_eta_below_0_3"] = serde_json::json!(e.below_0_3);
    v["min_eta"] = serde_json::json!(rule.min_eta());
    v["allow_invalid"] = serde_json::json!(rule.allows_invalid());
}

/// The text output's line for a mesh's input quads, when it has any: the figures that
/// follow are of its triangles alone.
pub fn print_input_quads(mesh: &quadrecomb::internals::mesh::Mesh) {
    if !mesh.quads.is_empty() {
        outln!(
            "input quads     {} (kept as they are; the figures below are of the triangles)",
            mesh.quads.len()
        );
    }
}

/// The element-quality lines of the text output.
pub fn print_element_lines(
    e: &quadrecomb::internals::quality::ElementQuality,
    rule: quadrecomb::internals::quality::Rule,
) {
    if let (Some(worst), Some(mean)) = (e.worst, e.mean) {
        outln!("quad eta        worst {worst:.4}, mean {mean:.4}");
        outln!(
            "poor quads      {} with eta < 0.1, {} with eta < 0.3",
            e.below_0_1,
            e.below_0_3
        );
    }
    outln!("rule            {rule}");
}

/// `-o` and `--vtu-ascii`: where a command writes its mesh, and how.
#[derive(Debug, clap::Args)]
pub struct MeshOutputArgs {
    /// Write the resulting mesh (quads and leftover triangles): .msh (MSH 4.1 ASCII) or .vtu.
    #[arg(short = 'o', long)]
    pub output: Option<std::path::PathBuf>,
    /// Write a .vtu's data arrays as text instead of zlib-compressed binary (VTK's own
    /// default); a .msh is MSH 4.1 ASCII either way.
    #[arg(long, requires = "output")]
    pub vtu_ascii: bool,
}

/// An error in the command line's arguments that clap does not see (a value out of range,
/// values that contradict each other, an output path that cannot be written): a usage error,
/// exit code 2 ([`errors::EXIT_USAGE`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct UsageError(pub String);

/// An input file the command was pointed at that it cannot use (a results directory without
/// records, a mesh that changed since the sweep), worded by the CLI: exit code 3
/// ([`errors::EXIT_BAD_INPUT`]).
#[derive(Debug, thiserror::Error)]
#[error("{0}")]
pub struct InputError(pub String);

/// Checks before any work that an output path names a `.msh` or `.vtu` file (any case) in
/// a directory that exists, so that a long run does not end on a path it cannot write.
pub fn check_mesh_output(path: Option<&std::path::Path>) -> Result<(), UsageError> {
    match path {
        Some(p) if output_kind(p).is_none() => Err(UsageError(format!(
            "output {}: expected a .msh or .vtu file name",
            p.display()
        ))),
        Some(p) => check_output_place(p),
        None => Ok(()),
    }
}

/// The part of [`check_mesh_output`] that does not look at the extension: `path` names a
/// file (not a directory, no trailing slash) in a directory that exists and takes a new file
/// (tried by creating and removing a temporary one, as the atomic writer will).
pub fn check_output_place(p: &std::path::Path) -> Result<(), UsageError> {
    let bad = |why: String| Err(UsageError(format!("output {}: {why}", p.display())));
    if p.is_dir() || p.as_os_str().to_string_lossy().ends_with('/') {
        return bad("names a directory, not a file".into());
    }
    // A FIFO, socket or device there is refused before the work, not after it; so is a
    // path the system cannot look at (a loop of symbolic links).
    match std::fs::metadata(p) {
        Ok(meta) if !meta.is_file() => {
            return bad(format!(
                "exists and is {}, not a regular file: refusing to replace it",
                quadrecomb::internals::mesh::file_kind(&meta)
            ));
        }
        #[cfg(unix)]
        Err(e) if e.raw_os_error() == Some(libc::ELOOP) => {
            return bad(format!("cannot be written: {e}"));
        }
        // Looked up, a name longer than the file system takes fails as it would be written.
        #[cfg(unix)]
        Err(e) if e.raw_os_error() == Some(libc::ENAMETOOLONG) => {
            return bad(format!(
                "the file name is too long for the file system ({e})"
            ));
        }
        _ => {}
    }
    // Through a symbolic link that leads to no file, the file the link names is created
    // (as the writer does): its directory is the one that must take it.
    let target = quadrecomb::internals::output::resolve(p);
    let via = if std::fs::symlink_metadata(p).is_ok_and(|m| m.is_symlink()) {
        format!(" (the symbolic link leads to {})", target.display())
    } else {
        String::new()
    };
    if target.as_os_str().to_string_lossy().ends_with('/') {
        return bad(format!("names a directory, not a file{via}"));
    }
    let dir = target.parent().filter(|d| !d.as_os_str().is_empty());
    match dir {
        Some(d) if d.exists() && !d.is_dir() => {
            bad(format!("{} is not a directory{via}", d.display()))
        }
        Some(d) if !d.exists() => bad(format!("directory {} does not exist{via}", d.display())),
        _ => {
            let d = dir.unwrap_or(std::path::Path::new("."));
            // The temporary file the output is written through, named as it will be.
            match quadrecomb::internals::output::check_temporary(p) {
                Ok(()) => Ok(()),
                Err(e) => bad(format!(
                    "directory {} does not take a new file ({e}){via}; choose another -o",
                    d.display()
                )),
            }
        }
    }
}

/// Refuses an output that is the input mesh file itself, however it is spelled (`./in.msh`,
/// a symbolic or hard link): the same file by device and inode. Writing it would destroy the
/// input.
pub fn check_not_input(output: Option<&std::path::Path>, input: &str) -> Result<(), UsageError> {
    check_not_same(
        output,
        std::path::Path::new(input),
        &format!("the input mesh {input}"),
    )
}

/// Refuses an output that is (after links) the existing file `other`, which it would
/// overwrite; `what` names `other` in the message.
pub fn check_not_same(
    output: Option<&std::path::Path>,
    other: &std::path::Path,
    what: &str,
) -> Result<(), UsageError> {
    let Some(out) = output else {
        return Ok(());
    };
    let (Ok(a), Ok(b)) = (std::fs::metadata(out), std::fs::metadata(other)) else {
        return Ok(());
    };
    #[cfg(unix)]
    let same = {
        use std::os::unix::fs::MetadataExt;
        a.dev() == b.dev() && a.ino() == b.ino()
    };
    #[cfg(not(unix))]
    let same = std::fs::canonicalize(out).ok() == std::fs::canonicalize(other).ok();
    if same {
        return Err(UsageError(format!(
            "output {} is {what}: refusing to overwrite it; choose another -o",
            out.display()
        )));
    }
    Ok(())
}

/// `Some(true)` for a `.vtu` path, `Some(false)` for `.msh`, `None` otherwise (any case).
fn output_kind(path: &std::path::Path) -> Option<bool> {
    let ext = path.extension()?;
    if ext.eq_ignore_ascii_case("vtu") {
        Some(true)
    } else if ext.eq_ignore_ascii_case("msh") {
        Some(false)
    } else {
        None
    }
}

/// Writes a recombined mesh as VTU (`.vtu`) or MSH 4.1 ASCII (`.msh`), through a temporary
/// file in the same directory renamed over `path`, so that a failed or interrupted write
/// never leaves a partial mesh behind.
pub fn write_mesh_output(
    path: &std::path::Path,
    mesh: &quadrecomb::internals::mesh::Mesh,
    rec: &quadrecomb::internals::mesh::Recombined,
    vtu_ascii: bool,
) -> anyhow::Result<()> {
    use quadrecomb::internals::mesh::vtu::Encoding;
    let vtu = output_kind(path) == Some(true);
    let encoding = if vtu_ascii {
        Encoding::Ascii
    } else {
        Encoding::Binary
    };
    if let (false, Some(model)) = (vtu, &mesh.model)
        && let Some(note) = model.not_written_note(mesh)
    {
        noteln!("warning: {}: {note}", path.display());
    }
    if vtu_ascii && !vtu {
        noteln!(
            "note: --vtu-ascii is ignored: {} is a .msh, MSH 4.1 ASCII either way",
            path.display()
        );
    }
    // Only `--allow-invalid` lets these through; the file does not say so.
    let flat = rec.quad_eta.iter().filter(|&&eta| eta <= 0.0).count();
    if flat > 0 {
        noteln!(
            "warning: {}: {flat} of its {} quads have eta 0 (a corner of pi or more: not \
             strictly convex), as --allow-invalid allows; a finite-element solver rejects them",
            path.display(),
            rec.quads.len()
        );
    }
    quadrecomb::internals::output::write_atomic(path, |mut w| {
        if vtu {
            quadrecomb::internals::mesh::vtu::write_to(&mut w, mesh, rec, encoding)
        } else {
            quadrecomb::internals::mesh::msh::write_to(&mut w, mesh, rec)
        }
    })
    // A failure of the system (disk full, the directory gone), not of the command line:
    // exit 1, as for any file the system cannot write (the arguments were checked before the
    // work, `check_output_place`); a FIFO or device put at `path` since is refused as there.
    .map_err(|e| {
        let msg = format!(
            "cannot write output {} (through a temporary file beside it): {e}",
            path.display()
        );
        if e.kind() == std::io::ErrorKind::InvalidInput {
            UsageError(msg).into()
        } else {
            anyhow::anyhow!(msg)
        }
    })
}
